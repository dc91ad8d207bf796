#!/usr/bin/python3
"""Noise-free first-order sideband levels of the three-shaft box (seed 1, 2000 rpm, 2 s, 10 kHz):
ideal gears, 8 um runout alone, ISO grade 6 pitch errors alone, both. Levels of
f_mesh +- f_shaft relative to the mesh line (Hann-windowed DFT at the exact frequencies), in one
counter-bearing and one input-bearing accelerometer. `offgrid`: median level at frequencies
that are no shaft order (the leakage / numerical floor).

Usage: sideband_levels.py GEARDIAG THREE_SHAFT_JSON WORKDIR
"""
import json
import os
import subprocess
import sys

import h5py
import numpy as np

FS = 10000.0
SHAFTS = {"input": 2000 / 60, "counter": 1000 / 60, "output": 500 / 60}
MESHES = {"z1_z2": 600.0, "z3_z4": 300.0}
CHANNELS = ("counter_bearing1_normal_loa_z1_z2", "input_bearing1_normal_loa")


def amp(x, f):
    t = np.arange(len(x)) / FS
    w = np.hanning(len(x))
    return 2 * abs(np.sum(x * w * np.exp(-2j * np.pi * f * t))) / np.sum(w)


def main():
    geardiag, box, work = sys.argv[1:4]
    os.makedirs(work, exist_ok=True)
    print("| gears | channel | mesh | " + " | ".join(f"{s} −1/+1 dB" for s in SHAFTS)
          + " | offgrid dB |")
    print("|---|---|---|" + "---|" * len(SHAFTS) + "---|")
    for grade, runout in ((0, 0), (0, 8), (6, 0), (6, 8)):
        scen = os.path.join(work, "levels.json")
        rec = os.path.join(work, f"levels_g{grade}_r{runout}.h5")
        with open(scen, "w") as f:
            json.dump({"accuracy_grade": grade, "runout_um": runout,
                       "sensors": {"noise_m_per_s2": 0}}, f)
        subprocess.run(["nice", geardiag, "simulate", "--gearbox", box, "--scenario", scen,
                        "--rpm", "2000", "--duration", "2", "--fs", "10000", "--seed", "1",
                        "-o", rec], check=True, capture_output=True)
        with h5py.File(rec) as h:
            for ch in CHANNELS:
                x = h["signals/" + ch][:]
                for mesh, fm in MESHES.items():
                    c = amp(x, fm)
                    db = lambda f: 20 * np.log10(max(amp(x, f), 1e-15 * c) / c)
                    cells = [f"{db(fm - fs):.0f} / {db(fm + fs):.0f}" for fs in SHAFTS.values()]
                    off = np.median([amp(x, fm + d) for d in (3.1, 5.9, 11.3, -4.2, -7.7, -13.9)])
                    print(f"| {'ideal' if grade == 0 else f'grade {grade}'}, runout {runout} µm "
                          f"| {ch} | {mesh} | " + " | ".join(cells)
                          + f" | {20 * np.log10(off / c):.0f} |")


if __name__ == "__main__":
    main()
