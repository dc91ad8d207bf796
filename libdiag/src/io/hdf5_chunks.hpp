// Internal to libdiag's HDF5 reader: a channel's samples decoded chunk by chunk by geardiag
// itself (diag/io/hdf5_inflate.hpp).
#pragma once

#include <hdf5.h>

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string>

namespace diag {

// The last chunk read_chunks_direct decoded (inflated; still shuffled when the shuffle applies),
// so that blocks shorter than a chunk, or straddling two, decode each chunk once (what HDF5's
// chunk cache did for H5Dread). One per RecordingReader; used under the reader's own
// serialisation (HDF5 calls are one at a time anyway).
struct DecodedChunk {
  std::string dataset;  // "" when nothing is held
  std::uint64_t start = 0;
  bool shuffled = false;
  std::unique_ptr<unsigned char[]> bytes, stored;  // the chunk; scratch for its stored bytes
  std::size_t bytes_capacity = 0, stored_capacity = 0;
};

namespace hdf5_detail {

// Samples [offset, offset + out.size()) of the 1-D dataset `ds` (named `what` in the file
// `where`) into `out`, decoded from its chunks' stored bytes, when `ds` is a chunked IEEE float64
// little-endian dataset whose filters are shuffle and/or deflate. Returns false, having read
// nothing, for any other dataset (the caller reads it with H5Dread). A chunk found damaged (not
// stored, larger than a chunk can be stored, a stream that does not inflate to the chunk's size,
// a raw chunk of the wrong size) is an InputError naming file, dataset and chunk: never handed to
// H5Dread, which would take it (a short chunk read as uninitialised memory).
bool read_chunks_direct(hid_t ds, const std::string& where, const std::string& what,
                        std::uint64_t offset, std::span<double> out, DecodedChunk& cache);

// Whether RecordingReader copies the samples its survey child decoded (tests turn it off:
// hdf5_set_read_path).
bool reuse_survey();

}  // namespace hdf5_detail
}  // namespace diag
