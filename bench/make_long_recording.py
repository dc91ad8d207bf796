#!/usr/bin/env python3
"""Writes a long geardiag recording block by block (for bench/analyze_memory.sh).

Takes a short simulated recording (geardiag simulate) and tiles 8 of its vibration channels and
its input tacho up to the requested size: the samples are the simulation's, repeated (a seam at
every repetition; the file tests memory and throughput, not the diagnosis). Written chunked
(65536 samples, like diag::write_recording) without compression, one block at a time, so the
writer holds one block, never the file.

Usage: make_long_recording.py SHORT.h5 OUT.h5 BYTES [CHANNELS]   (BYTES of vibration samples)
"""
import sys

import h5py
import numpy as np

CHANNELS = 8  # vibration channels (the 4th argument overrides)


def main():
    src_path, out_path, nbytes = sys.argv[1], sys.argv[2], int(float(sys.argv[3]))
    channels = int(sys.argv[4]) if len(sys.argv) > 4 else CHANNELS
    with h5py.File(src_path, "r") as src, h5py.File(out_path, "w") as out:
        for k, v in src.attrs.items():
            out.attrs[k] = v
        out.create_dataset("gearbox", data=src["gearbox"][()])
        names = [n for n in src["signals"] if src["signals"][n].attrs["role"] == "vibration"]
        picked = [("signals", n) for n in names[:channels]] + [("tacho", "input")]
        per_channel = nbytes // 8 // channels
        for group, name in picked:
            s = src[group][name]
            block = s[()]
            d = out.create_dataset(f"{group}/{name}", shape=(per_channel,), dtype="f8",
                                   chunks=(65536,))
            for k, v in s.attrs.items():
                d.attrs[k] = v
            for start in range(0, per_channel, block.size):
                n = min(block.size, per_channel - start)
                d[start:start + n] = block[:n]
        print(f"{out_path}: {len(picked)} channels ({channels} vibration + tacho) x {per_channel} "
              f"samples = {len(picked) * per_channel * 8 / 1e9:.2f} GB of samples")


if __name__ == "__main__":
    main()
