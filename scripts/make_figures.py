#!/usr/bin/python3
"""Regenerates the manual's figures (docs/figures/*.svg) from the geardiag binary.

Usage: scripts/make_figures.py [path/to/geardiag]   (default build/geardiag)
Needs /usr/bin/python3 with numpy and h5py (Debian python3-numpy, python3-h5py). Plain SVG, no
plotting library: each figure is a few polylines with axes and a legend.
"""
import json
import os
import subprocess
import sys
import tempfile

import h5py
import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BIN = sys.argv[1] if len(sys.argv) > 1 else os.path.join(ROOT, "build", "geardiag")
OUT = os.path.join(ROOT, "docs", "figures")
PAIR = os.path.join(ROOT, "testdata", "gearbox", "seed000_pair.json")
COLORS = ["#1f77b4", "#d62728", "#2ca02c", "#9467bd"]


def run(*args):
    subprocess.run([BIN, *args], check=True, stdout=subprocess.DEVNULL)


def nice_ticks(lo, hi, n=5):
    span = hi - lo if hi > lo else 1.0
    step = 10 ** np.floor(np.log10(span / n))
    for m in (1, 2, 5, 10):
        if span / (m * step) <= n:
            step *= m
            break
    start = np.ceil(lo / step) * step
    return [start + i * step for i in range(int((hi - start) / step) + 1)]


def svg_plot(path, title, xlabel, ylabel, series, logy=False):
    w, h, l, r, t, b = 640, 360, 70, 20, 30, 50
    xs = np.concatenate([np.asarray(s[1]) for s in series])
    ys = np.concatenate([np.asarray(s[2]) for s in series])
    if logy:
        ys = np.log10(np.maximum(ys, 1e-12))
    x0, x1 = xs.min(), xs.max()
    y0, y1 = ys.min(), ys.max()
    y0, y1 = y0 - 0.05 * (y1 - y0), y1 + 0.05 * (y1 - y0)
    px = lambda x: l + (x - x0) / (x1 - x0) * (w - l - r)
    py = lambda y: h - b - (y - y0) / (y1 - y0) * (h - t - b)
    out = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" font-family="sans-serif" font-size="12">',
           f'<rect width="{w}" height="{h}" fill="white"/>',
           f'<text x="{w/2}" y="18" text-anchor="middle" font-size="14">{title}</text>',
           f'<line x1="{l}" y1="{h-b}" x2="{w-r}" y2="{h-b}" stroke="black"/>',
           f'<line x1="{l}" y1="{t}" x2="{l}" y2="{h-b}" stroke="black"/>',
           f'<text x="{(l+w-r)/2}" y="{h-12}" text-anchor="middle">{xlabel}</text>',
           f'<text x="16" y="{(t+h-b)/2}" text-anchor="middle" transform="rotate(-90 16 {(t+h-b)/2})">{ylabel}</text>']
    for xv in nice_ticks(x0, x1):
        out.append(f'<line x1="{px(xv):.1f}" y1="{h-b}" x2="{px(xv):.1f}" y2="{h-b+5}" stroke="black"/>')
        out.append(f'<text x="{px(xv):.1f}" y="{h-b+18}" text-anchor="middle">{xv:g}</text>')
    for yv in nice_ticks(y0, y1):
        label = f"{10**yv:.3g}" if logy else f"{yv:g}"
        out.append(f'<line x1="{l-5}" y1="{py(yv):.1f}" x2="{l}" y2="{py(yv):.1f}" stroke="black"/>')
        out.append(f'<text x="{l-8}" y="{py(yv)+4:.1f}" text-anchor="end">{label}</text>')
    for i, (name, x, y) in enumerate(series):
        y = np.log10(np.maximum(np.asarray(y), 1e-12)) if logy else np.asarray(y)
        pts = " ".join(f"{px(a):.1f},{py(c):.1f}" for a, c in zip(x, y))
        out.append(f'<polyline fill="none" stroke="{COLORS[i % 4]}" stroke-width="1.5" points="{pts}"/>')
        out.append(f'<rect x="{w-r-170}" y="{t+8+i*16}" width="12" height="3" fill="{COLORS[i % 4]}"/>')
        out.append(f'<text x="{w-r-152}" y="{t+13+i*16}">{name}</text>')
    out.append("</svg>")
    with open(path, "w") as f:
        f.write("\n".join(out) + "\n")


def sweep(tmp, gearbox, scenario, a, b, steps, dwell, down, channels):
    sc = os.path.join(tmp, "sc.json")
    with open(sc, "w") as f:
        json.dump(scenario, f)
    js = os.path.join(tmp, "sweep.json")
    args = ["sweep", "--gearbox", gearbox, "--scenario", sc, "--from-rpm", str(a), "--to-rpm", str(b),
            "--steps", str(steps), "--dwell", str(dwell), "--json", js, "--channel", *channels]
    if down:
        args.append("--down")
    run(*args)
    with open(js) as f:
        return json.load(f)


def main():
    os.makedirs(OUT, exist_ok=True)
    with tempfile.TemporaryDirectory() as tmp:
        # Seed result 5: the jump (stiff bearings).
        s = sweep(tmp, PAIR, {"bearing_stiffness_n_per_m": 1e10}, 2000, 4500, 50, 0.03, True,
                  ["pinion_wheel_force"])
        up = [(p["mesh_frequency_hz"], p["pinion_wheel_force"]["peak"] / 1e3) for p in s["up"]]
        dn = [(p["mesh_frequency_hz"], p["pinion_wheel_force"]["peak"] / 1e3) for p in s["down"]]
        svg_plot(os.path.join(OUT, "sweep_jump.svg"),
                 f"Seed pair, 2000 N m: run up vs run down (torsional f_n = {s['mesh_torsional_frequency_hz'][0]:.0f} Hz)",
                 "mesh frequency [Hz]", "peak dynamic mesh force - mean [kN]",
                 [("run up", *zip(*up)), ("run down", *zip(*dn))])
        # Seed result 1: friction on/off.
        series = []
        for name, law in (("no friction", "none"), ("Drozdov friction", "drozdov")):
            s = sweep(tmp, PAIR, {"friction": {"law": law}}, 1000, 4500, 35, 0.02, False, ["pinion_wheel_force"])
            series.append((name, [p["rpm"] for p in s["up"]], [p["pinion_wheel_force"]["peak"] / 1e3 for p in s["up"]]))
        svg_plot(os.path.join(OUT, "friction_force.svg"), "Seed pair: mesh force with and without friction",
                 "input speed [rpm]", "peak dynamic mesh force - mean [kN]", series)
        # Seed result 4: contact ratio.
        series = []
        with open(PAIR) as f:
            base = json.load(f)
        for eps, ha in ((1.2, 0.660), (1.5, 0.841), (1.8, 1.029)):
            gb = json.loads(json.dumps(base))
            for g in gb["gears"]:
                g["addendum_coefficient"] = ha
            path = os.path.join(tmp, f"gb{eps}.json")
            with open(path, "w") as f:
                json.dump(gb, f)
            s = sweep(tmp, path, {"friction": {"law": "constant", "mu": 0.06}}, 1000, 4500, 35, 0.02, False,
                      ["input_bearing1_normal_loa"])
            series.append((f"epsilon = {eps}", [p["rpm"] for p in s["up"]],
                           [p["input_bearing1_normal_loa"]["rms"] for p in s["up"]]))
        svg_plot(os.path.join(OUT, "contact_ratio_normal.svg"),
                 "Seed pair, mu = 0.06: acceleration normal to the LOA", "input speed [rpm]",
                 "RMS [m/s^2]", series, logy=True)
        # Seed result 3: oil temperature, spectrum normal to the LOA.
        series = []
        for temp in (25, 95):
            sc = os.path.join(tmp, "oil.json")
            with open(sc, "w") as f:
                json.dump({"friction": {"law": "xu_kahraman"}, "oil": {"temperature_c": temp}}, f)
            h5 = os.path.join(tmp, f"oil{temp}.h5")
            run("simulate", "--gearbox", PAIR, "--scenario", sc, "--rpm", "1500", "--duration", "0.5",
                "--fs", "20000", "-o", h5)
            with h5py.File(h5, "r") as f:
                x = f["signals/input_bearing1_normal_loa"][:]
            x = x - x.mean()
            win = np.hanning(len(x))
            a = 2 * np.abs(np.fft.rfft(x * win)) / win.sum()
            fz = 49 * 1500 / 60
            freq = np.arange(len(a)) * 20000 / len(x) / fz
            keep = freq <= 6
            series.append((f"oil {temp} degC", freq[keep], a[keep]))
        svg_plot(os.path.join(OUT, "oil_temperature_spectrum.svg"),
                 "Seed pair, Xu-Kahraman friction: spectrum normal to the LOA", "f / f_z",
                 "amplitude [m/s^2]", series, logy=True)


if __name__ == "__main__":
    main()
