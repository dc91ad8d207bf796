#!/usr/bin/env python3
"""Writes a long CSV log block by block (for bench/analyze_memory.sh).

Takes a short simulated recording (geardiag simulate) and tiles 8 of its vibration channels,
with a time column, up to the requested size of text: the samples are the simulation's, repeated
(the file tests memory and throughput, not the diagnosis). Values are printed with 7 significant
digits, as a data logger writes them. Written one block at a time: the writer holds one block.

Usage: make_long_csv.py SHORT.h5 OUT.csv BYTES [CHANNELS]   (BYTES of text, about)
"""
import sys

import h5py
import numpy as np

CHANNELS = 8  # vibration channels (the 4th argument overrides)


def main():
    src_path, out_path, nbytes = sys.argv[1], sys.argv[2], int(float(sys.argv[3]))
    channels = int(sys.argv[4]) if len(sys.argv) > 4 else CHANNELS
    with h5py.File(src_path, "r") as src, open(out_path, "w") as out:
        names = [n for n in src["signals"] if src["signals"][n].attrs["role"] == "vibration"]
        names = names[:channels]
        fs = float(src["signals"][names[0]].attrs["fs_hz"])
        block = np.stack([src["signals"][n][()] for n in names], axis=1)
        out.write(",".join(["time"] + names) + "\n")
        written, row = 0, 0
        while written < nbytes:
            t = (row + np.arange(block.shape[0])) / fs
            text = "\n".join(
                f"{ti:.7f}," + ",".join(f"{v:.7g}" for v in r) for ti, r in zip(t, block)) + "\n"
            out.write(text)
            written += len(text)
            row += block.shape[0]
        print(f"{out_path}: {channels} channels x {row} rows = {written / 1e9:.2f} GB of text")


if __name__ == "__main__":
    main()
