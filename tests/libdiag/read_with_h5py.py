#!/usr/bin/env python3
"""Reads a recording written by recording_io_test.cpp (H5pyReadsTheRecordingWithoutGeardiag)
with h5py alone and asserts its content, so that the file format stays readable without geardiag.

usage: read_with_h5py.py FILE     exit 0 when every check passes

A missing h5py is a failure, not a skip: scripts/install-deps installs python3-h5py.
"""
import json
import sys

import h5py
import numpy as np


def check(condition, what):
    if not condition:
        print(f"read_with_h5py.py: FAILED: {what}", file=sys.stderr)
        sys.exit(1)


def main(path):
    with h5py.File(path, "r") as f:
        # Root attributes: strings must come back as str (variable-length UTF-8), not bytes.
        check(f.attrs["format"] == "geardiag-recording", f"format = {f.attrs['format']!r}")
        check(int(f.attrs["format_version"]) == 2, "format_version == 2")
        check(isinstance(f.attrs["creator"], str), "creator is a str")
        check(f.attrs["creator"].startswith("geardiag "), f"creator = {f.attrs['creator']!r}")
        check(isinstance(f.attrs["git_revision"], str), "git_revision is a str")
        check(f.attrs["source"] == "h5py test", f"metadata source = {f.attrs['source']!r}")

        d = f["signals/accel"]
        check(d.dtype == np.float64, f"dtype = {d.dtype}")
        check(d.shape == (1000,), f"shape = {d.shape}")
        check(d.chunks is not None, "dataset is chunked")
        check(d.compression == "gzip", f"compression = {d.compression}")
        check(np.array_equal(d[()], 0.5 * np.arange(1000)), "samples == 0.5 * arange(1000)")
        check(d[10:13].tolist() == [5.0, 5.5, 6.0], "slice [10:13]")
        check(isinstance(d.attrs["fs_hz"], (float, np.floating)), "fs_hz is a float")
        check(float(d.attrs["fs_hz"]) == 1000.0, f"fs_hz = {d.attrs['fs_hz']!r}")
        check(d.attrs["unit"] == "m/s^2", f"unit = {d.attrs['unit']!r}")
        check(d.attrs["direction"] == "along_loa", f"direction = {d.attrs['direction']!r}")
        check(d.attrs["location"] == "bearing_1", f"location = {d.attrs['location']!r}")
        check(d.attrs["role"] == "vibration", f"role = {d.attrs['role']!r}")
        check(isinstance(d.attrs["shaft"], str), "shaft is a str")
        check(int(d.attrs["ppr"]) == 0, f"ppr = {d.attrs['ppr']!r}")

        t = f["tacho/input"]
        check(t[()].tolist() == [0.0, 1.0, 0.0, 1.0], "tacho samples")
        check(t.attrs["direction"] == "tacho", f"tacho direction = {t.attrs['direction']!r}")
        check(t.attrs["role"] == "tacho", f"tacho role = {t.attrs['role']!r}")
        check(int(t.attrs["ppr"]) >= 1, f"tacho ppr = {t.attrs['ppr']!r}")

        gearbox = f["gearbox"].asstr()[()]
        check(json.loads(gearbox) == {"name": "h5py-check"}, f"/gearbox = {gearbox!r}")
        truth = f["truth"].asstr()[()]
        check(json.loads(truth) == {"defects": []}, f"/truth = {truth!r}")
    print("read_with_h5py.py: ok")
    return 0


if __name__ == "__main__":
    if len(sys.argv) != 2:
        print(__doc__, file=sys.stderr)
        sys.exit(2)
    sys.exit(main(sys.argv[1]))
