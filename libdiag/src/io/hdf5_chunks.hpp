// Internal to libdiag's HDF5 reader: a channel's samples decoded chunk by chunk by geardiag
// itself (diag/io/hdf5_inflate.hpp).
#pragma once

#include <hdf5.h>

#include <cstdint>
#include <span>

namespace diag::hdf5_detail {

// Samples [offset, offset + out.size()) of the 1-D dataset `ds` into `out`, decoded from its
// chunks' stored bytes, when `ds` is a chunked IEEE float64 little-endian dataset whose filters
// are shuffle and/or deflate. Returns false for any other dataset and for anything unexpected on
// the way (a chunk not stored, a stream that does not inflate to the chunk's size): the caller
// then reads `out` again with H5Dread, whose errors name the damage as before.
bool read_chunks_direct(hid_t ds, std::uint64_t offset, std::span<double> out);

// Whether RecordingReader copies the samples its survey child decoded (tests turn it off:
// hdf5_set_read_path).
bool reuse_survey();

}  // namespace diag::hdf5_detail
