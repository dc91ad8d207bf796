#!/usr/bin/env python3
"""Seed inputs for the libFuzzer targets (fuzz/run.sh): one folder per target.

Valid small files of each kind (made here with numpy, scipy, h5py and the standard library),
testdata/ (recordings, gearbox descriptions), and, with --geardiag BIN, the bad-input corpus of
tests/corpus/bad_inputs.py sorted by extension. usage: make_seeds.py OUT_DIR [--geardiag BIN]
"""
import argparse
import gzip
import json
import os
import shutil
import struct
import subprocess
import sys

import h5py
import numpy as np
import scipy.io

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("out")
    ap.add_argument("--geardiag")
    args = ap.parse_args()
    d = {t: os.path.join(args.out, t) for t in
         ["csv", "csv_gz", "wav", "mat", "hdf5", "face_gear_table", "gearbox_json", "scenario_json",
          "channel_map"]}
    for p in d.values():
        os.makedirs(p, exist_ok=True)

    csv = "time,a,b\n" + "".join(f"{i / 1000:.6f},{np.sin(0.1 * i):.6g},{i}\n" for i in range(40))
    open(os.path.join(d["csv"], "time.csv"), "w").write(csv)
    open(os.path.join(d["csv"], "no_header.csv"), "w").write("1;2\n3;4\n5;6\n")
    open(os.path.join(d["csv"], "tabs.csv"), "w").write("x\ty\n\"1\"\t2\r\n3\t4\r\n")
    open(os.path.join(d["csv_gz"], "time.csv.gz"), "wb").write(gzip.compress(csv.encode(), mtime=0))

    for ch, bits in [(1, 16), (2, 16)]:
        data = (np.sin(np.arange(200) * 0.1) * 3000).astype("<i2").repeat(ch).tobytes()
        fmt = struct.pack("<HHIIHH", 1, ch, 8000, 8000 * 2 * ch, 2 * ch, bits)
        body = b"WAVE" + b"fmt " + struct.pack("<I", 16) + fmt + b"data" + struct.pack("<I", len(data)) + data
        open(os.path.join(d["wav"], f"pcm{ch}.wav"), "wb").write(b"RIFF" + struct.pack("<I", len(body)) + body)

    x = np.sin(np.arange(300) * 0.01)
    scipy.io.savemat(os.path.join(d["mat"], "v5.mat"), {"X1_DE_time": x.reshape(-1, 1), "X1RPM": np.array([[1797.0]])})
    scipy.io.savemat(os.path.join(d["mat"], "v5z.mat"), {"a": x, "n": np.int16([1, 2, 3])}, do_compression=True)
    scipy.io.savemat(os.path.join(d["mat"], "v4.mat"), {"a": x.reshape(-1, 1)}, format="4")

    with h5py.File(os.path.join(d["hdf5"], "small.h5"), "w", libver=("v108", "v108"), track_order=True) as f:
        f.attrs["format"] = "geardiag-recording"
        f.attrs["format_version"] = np.int32(2)
        f.attrs["roles_stated"] = np.int32(1)
        f.attrs["input_speed_rpm"] = 1500.0
        for g, name, role, ppr in [("signals", "acc", "vibration", 0), ("tacho", "input", "tacho", 1)]:
            ds = f.create_group(g).create_dataset(name, data=np.sin(np.arange(64) * 0.3), chunks=(16,),
                                                  compression="gzip", shuffle=True)
            for k, v in [("unit", "m/s^2"), ("direction", ""), ("location", "b1"), ("role", role),
                         ("shaft", "input" if ppr else ""), ("mesh", "")]:
                ds.attrs[k] = v
            ds.attrs["fs_hz"] = 1000.0
            ds.attrs["ppr"] = np.int32(ppr)
        f.create_dataset("gearbox", data=json.dumps({"name": "x"}), dtype=h5py.string_dtype())
    shutil.copy(os.path.join(ROOT, "testdata/recordings/format1_three_shaft.h5"), d["hdf5"])

    # Face-gear stiffness tables: the CSV layout and the HDF5 layout (sim/facegear/description.hpp),
    # 24 angles over the 24-degree mesh period of 15 teeth, two loads.
    rows = ["flank,angle_deg,load_nm,stiffness_nm_per_rad,e0_urad"]
    for flank in ("drive", "coast"):
        for i in range(24):
            for load in (10.0, 300.0):
                rows.append(f"{flank},{i:.1f},{load},{9e5 * (1 + 0.05 * np.cos(0.26 * i)):.6g},"
                            f"{10 * np.sin(0.26 * i):.6g}")
    open(os.path.join(d["face_gear_table"], "table.csv"), "w").write("\n".join(rows) + "\n")
    angles = np.arange(24.0)
    k = 9e5 * np.ones((24, 2))
    with h5py.File(os.path.join(d["face_gear_table"], "table.h5"), "w", libver=("v108", "v108")) as f:
        f["angle_deg"] = angles
        f["load_nm"] = np.array([10.0, 300.0])
        for flank in ("drive", "coast"):
            f[f"{flank}/stiffness_nm_per_rad"] = k
            f[f"{flank}/e0_urad"] = 10 * np.sin(0.26 * angles)

    for name in os.listdir(os.path.join(ROOT, "testdata/gearbox")):
        shutil.copy(os.path.join(ROOT, "testdata/gearbox", name), d["gearbox_json"])
    json.dump({"speed_rpm": 1500, "duration_s": 1.0, "seed": 3}, open(os.path.join(d["scenario_json"], "s.json"), "w"))
    json.dump({}, open(os.path.join(d["scenario_json"], "empty.json"), "w"))
    json.dump({"channels": [{"name": "a", "role": "vibration", "unit": "g", "direction": "vertical"},
                            {"name": "t", "role": "tacho", "shaft": "input", "ppr": 2}]},
              open(os.path.join(d["channel_map"], "map.json"), "w"))

    if args.geardiag:
        corpus = os.path.join(args.out, "_corpus")
        subprocess.run([sys.executable, os.path.join(ROOT, "tests/corpus/bad_inputs.py"), "--geardiag",
                        args.geardiag, "--dir", corpus, "--generate-only"], check=True, stdout=subprocess.DEVNULL)
        for name in os.listdir(os.path.join(corpus, "inputs")):
            src = os.path.join(corpus, "inputs", name)
            if not os.path.isfile(src) or os.path.islink(src):
                continue
            target = ("face_gear_table" if name.startswith("fg_")
                      else "csv_gz" if name.endswith(".csv.gz") else "csv" if name.endswith(".csv")
                      else "wav" if name.endswith(".wav") else "mat" if name.endswith(".mat")
                      else "hdf5" if name.endswith(".h5") else "channel_map" if name.startswith("map_") else None)
            if target:
                shutil.copy(src, d[target])
        shutil.rmtree(corpus)


if __name__ == "__main__":
    main()
