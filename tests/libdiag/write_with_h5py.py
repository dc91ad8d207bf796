#!/usr/bin/env python3
"""Writes, with h5py alone, a format-2 recording whose channels use the filter pipelines another
program may write (hdf5_read_test.cpp, H5pyWrittenPipelinesDecodeExactly), and each channel's
samples as raw little-endian float64 in DIR/<channel>.f64 for an exact comparison.

usage: write_with_h5py.py DIR      writes DIR/h5py.h5 and DIR/<channel>.f64

Channels (9999 samples, not a multiple of any chunk length):
  shuffle_gzip    shuffle + gzip 4, chunks of 1000 (what geardiag writes)
  gzip_only       gzip 9, chunks of 777
  shuffle_only    shuffle, chunks of 512
  fletcher        shuffle + gzip 1 + fletcher32 (not decoded by geardiag itself: HDF5 reads it)
  contiguous      no chunks, no filters
  float32         shuffle + gzip 4, stored as float32 (HDF5 converts it)
"""
import os
import sys

import h5py
import numpy as np


def main(out_dir):
    n = 9999
    t = np.arange(n) / 1000.0
    rng = np.random.default_rng(11)
    base = np.sin(2 * np.pi * 37.0 * t) + 0.1 * rng.standard_normal(n)
    channels = {
        "shuffle_gzip": dict(shuffle=True, compression="gzip", compression_opts=4, chunks=(1000,)),
        "gzip_only": dict(compression="gzip", compression_opts=9, chunks=(777,)),
        "shuffle_only": dict(shuffle=True, chunks=(512,)),
        "fletcher": dict(shuffle=True, compression="gzip", compression_opts=1, fletcher32=True,
                         chunks=(1000,)),
        "contiguous": dict(),
        "float32": dict(shuffle=True, compression="gzip", compression_opts=4, chunks=(1000,),
                        dtype="f4"),
    }
    with h5py.File(os.path.join(out_dir, "h5py.h5"), "w", track_order=True) as f:
        f.attrs["format"] = "geardiag-recording"
        f.attrs["format_version"] = np.int32(2)
        group = f.create_group("signals", track_order=True)
        for k, (name, options) in enumerate(channels.items()):
            x = base * (k + 1) + k
            d = group.create_dataset(name, data=x, **options)
            for key, value in [("unit", "m/s^2"), ("direction", ""), ("location", ""),
                               ("role", "vibration"), ("shaft", ""), ("mesh", "")]:
                d.attrs[key] = value
            d.attrs["fs_hz"] = 1000.0
            d.attrs["ppr"] = np.int32(0)
            # What HDF5 stores (float32 rounds), as float64.
            d[...].astype("<f8").tofile(os.path.join(out_dir, name + ".f64"))


if __name__ == "__main__":
    main(sys.argv[1])
