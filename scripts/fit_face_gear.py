#!/usr/bin/env python3
"""The fit of the seed-002 face-gear pair's two missing parameters on the paper's Fig. 10 alone.

The paper (Feng et al., seed 002) gives neither the inertias nor the static transmission error's
amplitude. Both are fitted here on one figure, the bifurcation diagram at 12 N m with 10x the mesh
stiffness (Fig. 10), as its text states it: period-1 below 7 500 rpm, period-2 then chaos in
7 500-9 500 rpm, period-1 again near 9 500-10 000, period-2 and chaos in 10 000-16 500 rpm,
period-1 above. The window 2 860-3 740 rpm is left out: it is a superharmonic resonance of the
third mesh harmonic, which the analytic stiffness table does not have (docs/face-gear.md).

Parameters: a common factor c on both inertias of the shipped description (the bare gears' ratio
is kept) and a factor on the static TE of both flanks (`static_te_scale`). Objective: the share
of 157 speeds of 500-20 000 rpm (the window left out) whose label, period-1 or not, is the
paper's. Coarse grid, then a fine one around the best; the best point of the fine grid wins.
Fig. 7's resonance, the rated point and Fig. 11 are then predictions (tests/simulator/
face_gear_test.cpp).

    scripts/fit_face_gear.py build/geardiag testdata/gearbox/seed002_face_gear.json

prints the share per grid point; the description's factors are relative to the file given.
"""
import json
import os
import subprocess
import sys
import tempfile


def paper_label(rpm):
    """Fig. 10 of the paper, as its text gives it: 'p1', 'x' (period-2 or chaos) or None."""
    if 2860 <= rpm <= 3740:
        return None  # the superharmonic window the analytic table cannot give
    if 7500 <= rpm < 9500 or 10000 <= rpm < 16500:
        return "x"
    return "p1"


def share(geardiag, description, c, te, tmp, steps=157):
    d = json.loads(json.dumps(description))
    fp = d["face_gear_pair"]
    fp["pinion_inertia_kg_m2"] *= c
    fp["gear_inertia_kg_m2"] *= c
    if isinstance(fp.get("stiffness_table"), str) and fp["stiffness_table"] != "analytic":
        raise SystemExit("fit_face_gear: the fit is of the analytic table")
    gb, sc, out = (os.path.join(tmp, n) for n in ("gb.json", "sc.json", "b.json"))
    json.dump(d, open(gb, "w"))
    json.dump({"stiffness_scale": 10, "static_te_scale": te}, open(sc, "w"))
    subprocess.run([geardiag, "bifurcation", "--gearbox", gb, "--scenario", sc, "--torque", "12",
                    "--from-rpm", "500", "--to-rpm", "20000", "--steps", str(steps),
                    "--transient", "200", "--periods", "60", "--json", out],
                   check=True, capture_output=True)
    b = json.load(open(out))
    hits = total = 0
    for rpm, cls in zip(b["speeds_rpm"], b["class"]):
        want = paper_label(rpm)
        if want is None:
            continue
        total += 1
        hits += ("p1" if cls == "period-1" else "x") == want
    return hits / total


def main():
    if len(sys.argv) != 3:
        raise SystemExit(__doc__)
    geardiag, path = sys.argv[1], sys.argv[2]
    description = json.load(open(path))
    with tempfile.TemporaryDirectory() as tmp:
        coarse = [(c, te) for c in (0.8, 0.9, 1.0, 1.1, 1.2, 1.3, 1.4, 1.5, 1.6)
                  for te in (0.5, 0.75, 1.0, 1.5, 2.0)]
        scores = {}
        for c, te in coarse:
            scores[(c, te)] = share(geardiag, description, c, te, tmp)
            print(f"coarse  inertia x{c:<6} static TE x{te:<5} {scores[(c, te)]:.3f}", flush=True)
        c0, te0 = max(scores, key=lambda k: (scores[k], -abs(k[0] - 1), -abs(k[1] - 1)))
        fine = {}
        for c in (c0 - 0.05, c0 - 0.025, c0, c0 + 0.025, c0 + 0.05):
            for te in (te0 - 0.1, te0 - 0.05, te0, te0 + 0.05, te0 + 0.1):
                if c <= 0 or te <= 0:
                    continue
                fine[(c, te)] = share(geardiag, description, c, te, tmp)
                print(f"fine    inertia x{c:<6.3f} static TE x{te:<5.2f} {fine[(c, te)]:.3f}",
                      flush=True)
        best = max(fine, key=lambda k: (fine[k], -abs(k[0] - 1), -abs(k[1] - 1)))
        print(f"best: inertia x{best[0]:.3f}, static TE x{best[1]:.2f}: "
              f"{fine[best]:.3f} of the speeds labelled as the paper's Fig. 10")


if __name__ == "__main__":
    main()
