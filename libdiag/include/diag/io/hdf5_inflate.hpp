// How geardiag decodes a recording's channels: the chunks of a float64 dataset compressed by
// HDF5's shuffle and deflate filters (what write_recording writes; h5py's shuffle=True,
// compression="gzip") are decoded by geardiag itself, not by HDF5's filter pipeline.
//
// Reading a deflate-compressed recording was a sixth of `geardiag analyze`'s CPU on a 39-channel
// simulated recording: zlib's inflate and Adler-32, HDF5's byte-at-a-time unshuffle and a copy
// out of its chunk buffer. HDF5 1.10 does not let a program replace its deflate filter
// (H5Zregister with id 1 fails: "unable to modify predefined filters"), so RecordingReader reads
// each chunk's stored bytes with H5Dread_chunk (HDF5 >= 1.10.2, the "direct chunk read"), and
//   - inflates the zlib stream (RFC 1950: deflate, RFC 1951, with an Adler-32 checksum) with
//     libdeflate (E. Biggers, https://github.com/ebiggers/libdeflate; 2-3x zlib's speed) when the
//     build found it (pkg-config libdeflate), else with zlib's inflate. Both give the same bytes
//     and both verify the checksum: a damaged chunk is an InputError naming file and dataset;
//   - undoes the shuffle (HDF5's H5Zshuffle.c: byte k of every element stored together, plane by
//     plane) by an 8 x 8 byte transpose straight into the caller's samples, only for the samples
//     asked for.
// A chunk the writer could not compress is stored raw with its filter mask saying so; the mask is
// honoured. Any other layout, type or filter (fletcher32, szip, big-endian, contiguous, ...) is
// read by H5Dread as before. Writing is HDF5's own: files written are the same bytes.
#pragma once

#include <string>

namespace diag {

// The inflate implementation in use: "libdeflate <version>" or "zlib <version>".
std::string hdf5_inflate_codec();

// Tests only: how RecordingReader reads a channel. Returns whether libdeflate is built in.
struct Hdf5ReadPath {
  bool direct = true;        // false: every channel by H5Dread (HDF5's own pipeline)
  bool zlib = false;         // true: inflate with zlib even when libdeflate is built in
  bool reuse_survey = true;  // false: decode again what the crash guard child decoded
};
bool hdf5_set_read_path(const Hdf5ReadPath& path);

}  // namespace diag
