# Wear indicator study (README: "Wear indicator against the baseline"): growth [dB] of the worn mesh's harmonics 1-3 on
# every vibration channel (role vibration: what diag::sensor_channels gives) against the median of
# a healthy baseline of the same gears (3 recordings at 0.95, 1.0, 1.05 x the torque), for worn
# pairs (the `wear` fault, depth_um 5..54, Archard) and for healthy-vs-healthy variation: the same
# gears at 1.1 x the torque and at 0.95 and 1.05 x the speed, and other gears of the same ISO 1328
# grade (6, runout 8 um, another seed).
# Run from the checkout's root (1 s at 20 kHz per recording, ~1.5 s of CPU each):
#   /usr/bin/python3 docs/wear_indicator/study.py 1 13 29_47 > s29.jsonl
#   /usr/bin/python3 docs/wear_indicator/study.py 1 7 23_41 > s23.jsonl
#   /usr/bin/python3 docs/wear_indicator/roc.py s29.jsonl s23.jsonl
import json, os, subprocess, sys
import numpy as np, h5py
G = os.environ.get("GEARDIAG", "build/geardiag")
TD = "testdata/gearbox/"
OUT = os.environ.get("STUDY_DIR", "wear_study")
os.makedirs(OUT, exist_ok=True)
CASES = {"29_47": (TD + "single_stage_29_47.json", "pinion_wheel"),
         "23_41": (TD + "two_stage_23_41_19_53.json", "p1_w1")}

def sim(gb, name, seed, torque_scale, depth=None, mesh=None, speed_scale=1.0):
    path = f"{OUT}/{name}.h5"
    if os.path.exists(path):
        return path
    # --seed on the command line: the scenario's seed is overridden by simulate's default (see notes)
    sc = {"accuracy_grade": 6, "runout_um": 8, "duration_s": 1.0, "fs_hz": 20000,
          "torque_nm": json.load(open(gb))["input"]["torque_nm"] * torque_scale,
          "sensors": {"noise_m_per_s2": 0.5},
          "speed": {"rpm": json.load(open(gb))["input"]["speed_rpm"] * speed_scale}}
    if depth:
        sc["faults"] = [{"type": "wear", "mesh": mesh, "depth_um": depth}]
    scp = f"{OUT}/{name}.json"
    json.dump(sc, open(scp, "w"))
    subprocess.run([G, "simulate", "--gearbox", gb, "--scenario", scp, "--seed", str(seed), "-o", path], check=True,
                   stdout=subprocess.DEVNULL)
    return path

GB_OF = {mesh: gb for gb, mesh in CASES.values()}


def harmonics(path, mesh):
    """Amplitudes of mesh harmonics 1..3 on every vibration channel (role), Hann window."""
    f = h5py.File(path, "r")
    tr = json.loads(f["truth"][()])
    # The mesh frequency at the run's speed, from the description: both meshes studied have their
    # driver on the input shaft. (The truth's meshes[].mesh_frequency_hz is at the description's
    # nominal speed, whatever the run's: see the notes.)
    gbj = json.load(open(GB_OF[mesh]))
    driver = next(m["driver"] for m in gbj["meshes"] if m["driver"] + "_" + m["driven"] == mesh)
    z = next(g["teeth"] for g in gbj["gears"] if g["name"] == driver)
    fm = z * tr["input_speed_rpm_min"] / 60.0
    out = {}
    for name, ds in f["signals"].items():
        a = dict(ds.attrs)
        role = a.get("role"); role = role.decode() if isinstance(role, bytes) else role
        if role != "vibration":
            continue
        x = ds[:]; fs = float(a["fs_hz"])
        w = np.hanning(len(x)); X = np.abs(np.fft.rfft((x - x.mean()) * w)) * 2 / w.sum()
        fr = np.fft.rfftfreq(len(x), 1 / fs); df = fr[1]
        amps = []
        for h in (1, 2, 3):
            i = int(round(h * fm / df)); amps.append(X[max(i - 2, 0):i + 3].max())
        out[name] = np.array(amps)
    return out

def growth_db(test, base_list):
    """Mean over channels of 20 log10(rms of harmonics 1-3 / baseline median's)."""
    g = []
    for ch, a in test.items():
        b = np.median(np.array([bl[ch] for bl in base_list]), axis=0)
        g.append(20 * np.log10(np.sqrt(np.sum(a ** 2)) / np.sqrt(np.sum(b ** 2))))
    return float(np.mean(g)), float(np.max(g))

rows = []
seeds = range(int(sys.argv[1]), int(sys.argv[2]))
depths = [5, 10, 20, 40, 54]
for case, (gb, mesh) in [(c, CASES[c]) for c in sys.argv[3].split(",")]:
    for s in seeds:
        base = [harmonics(sim(gb, f"{case}_s{s}_b{k}", s, ts), mesh) for k, ts in enumerate((0.95, 1.0, 1.05))]
        tests = [("healthy_same_gears_torque_1.1", 0, sim(gb, f"{case}_s{s}_h", s, 1.1)),
                 ("healthy_other_gears", 0, sim(gb, f"{case}_s{s}_o", s + 1000, 1.0)),
                 ("healthy_same_gears_speed_0.95", 0, sim(gb, f"{case}_s{s}_v95", s, 1.0, speed_scale=0.95)),
                 ("healthy_same_gears_speed_1.05", 0, sim(gb, f"{case}_s{s}_v105", s, 1.0, speed_scale=1.05))]
        for d in depths:
            tests.append(("worn", d, sim(gb, f"{case}_s{s}_w{d}", s, 1.0, d, mesh)))
        for kind, d, p in tests:
            gm, gx = growth_db(harmonics(p, mesh), base)
            rows.append({"case": case, "seed": s, "kind": kind, "depth_um": d, "mean_db": gm, "max_db": gx})
            print(json.dumps(rows[-1]), flush=True)
