#!/usr/bin/python3
"""False-alarm / detection study of `geardiag analyze` (no baseline) gear findings.

Healthy grid: 3 gearboxes x accuracy_grade {0 (ideal), 5, 7} x runout_um {0, 8} x seeds 1-4,
plus a paired control (grade 6, runout 8, seeds 1-3: the same gears as the faulty runs).
Faulty grid: the same gearboxes, grade 6, runout 8, a chip (size_mm 1.2) or a root crack
(depth_mm 1.5) on tooth 5 of one gear per shaft, seeds 1-3.
Every run: sensor noise 3 m/s^2, 2 s at 10 kHz, 2000 rpm input, `--seed S` (replaces the
scenario's gear seed and noise seed). One process at a time, under `nice`.

Usage: study.py GEARDIAG TESTDATA_GEARBOX_DIR WORKDIR  -> WORKDIR/results.jsonl + tables on stdout
"""
import json
import os
import subprocess
import sys
from collections import defaultdict

GEARBOXES = {
    # file: {shaft: gear carrying the fault}
    "three_shaft.json": {"input": "z1", "counter": "z3", "output": "z4"},
    "two_stage_17_44_21_50.json": {"input": "p1", "counter": "p2", "output": "w2"},
    "two_stage_23_41_19_53.json": {"input": "p1", "counter": "p2", "output": "w2"},
}
FAULTS = {
    "chip": {"type": "chip", "size_mm": 1.2},
    "crack": {"type": "crack", "depth_mm": 1.5},
}
GEAR_KINDS = ("gear_sidebands", "gear_damage")


def run(geardiag, box_path, scenario, seed, work):
    scen = os.path.join(work, "scenario.json")
    rec = os.path.join(work, "rec.h5")
    with open(scen, "w") as f:
        json.dump(scenario, f)
    sim = subprocess.run(
        ["nice", geardiag, "simulate", "--gearbox", box_path, "--scenario", scen,
         "--rpm", "2000", "--duration", "2", "--fs", "10000", "--seed", str(seed), "-o", rec],
        capture_output=True, text=True)
    if sim.returncode != 0:
        return {"error": "simulate: " + sim.stderr.strip()[-300:]}
    ana = subprocess.run(["nice", geardiag, "analyze", rec, "--json", "-"],
                         capture_output=True, text=True)
    if ana.returncode != 0:
        return {"error": "analyze: " + ana.stderr.strip()[-300:]}
    report = json.loads(ana.stdout)
    findings = []
    for fd in report["findings"]:
        ev = fd.get("evidence", {})
        findings.append({k: fd.get(k) for k in ("kind", "fault", "shaft", "gears", "confidence")}
                        | {k: ev.get(k) for k in ("channels_pointing", "channels_analysed",
                                                  "score_db", "mean_line_db", "score", "snr")
                           if k in ev})
    return {"findings": findings,
            "locator_status": report.get("gear_damage", {}).get("status")}


def main():
    geardiag, boxdir, work = sys.argv[1:4]
    os.makedirs(work, exist_ok=True)
    out = open(os.path.join(work, "results.jsonl"), "w")
    rows = []

    def record(row):
        rows.append(row)
        out.write(json.dumps(row) + "\n")
        out.flush()
        print(row["box"], row["cond"], row["seed"],
              row.get("error") or [(f["kind"], f["shaft"]) for f in row["findings"]],
              file=sys.stderr, flush=True)

    noise = {"noise_m_per_s2": 3}
    for box in GEARBOXES:
        bp = os.path.join(boxdir, box)
        for grade in (0, 5, 7):
            for runout in (0, 8):
                for seed in (1, 2, 3, 4):
                    scen = {"accuracy_grade": grade, "runout_um": runout, "sensors": noise}
                    r = run(geardiag, bp, scen, seed, work)
                    record({"box": box, "set": "healthy", "cond": f"g{grade} r{runout}",
                            "grade": grade, "runout": runout, "seed": seed} | r)
        for seed in (1, 2, 3):
            scen = {"accuracy_grade": 6, "runout_um": 8, "sensors": noise}
            r = run(geardiag, bp, scen, seed, work)
            record({"box": box, "set": "control", "cond": "g6 r8", "grade": 6, "runout": 8,
                    "seed": seed} | r)
        for fname, fault in FAULTS.items():
            for shaft, gear in GEARBOXES[box].items():
                for seed in (1, 2, 3):
                    scen = {"accuracy_grade": 6, "runout_um": 8, "sensors": noise,
                            "faults": [{"gear": gear, "tooth": 5} | fault]}
                    r = run(geardiag, bp, scen, seed, work)
                    record({"box": box, "set": "faulty", "cond": f"{fname} {gear}",
                            "fault": fname, "fault_shaft": shaft, "gear": gear,
                            "grade": 6, "runout": 8, "seed": seed} | r)
    out.close()
    summarize(rows)


def summarize(rows):
    print("## healthy: recordings with a finding (of 4 seeds; 3 for the g6 r8 control)\n")
    print("| gearbox | grade | runout µm | any gear_sidebands | gear_damage | other kinds "
          "| gear_sidebands findings (shaft: count) |")
    print("|---|---|---|---|---|---|---|")
    tot = defaultdict(lambda: [0, 0])
    for r in rows:
        if r["set"] == "faulty":
            continue
    keyed = defaultdict(list)
    for r in rows:
        if r["set"] != "faulty":
            keyed[(r["box"], r["grade"], r["runout"])].append(r)
    for (box, grade, runout), rs in keyed.items():
        ok = [r for r in rs if "error" not in r]
        sb = sum(any(f["kind"] == "gear_sidebands" for f in r["findings"]) for r in ok)
        gd = sum(any(f["kind"] == "gear_damage" for f in r["findings"]) for r in ok)
        other = sum(any(f["kind"] not in GEAR_KINDS for f in r["findings"]) for r in ok)
        shafts = defaultdict(int)
        for r in ok:
            for f in r["findings"]:
                if f["kind"] == "gear_sidebands":
                    shafts[f["shaft"]] += 1
        err = len(rs) - len(ok)
        print(f"| {box.removesuffix('.json')} | {grade or 'ideal'} | {runout} | {sb}/{len(ok)} "
              f"| {gd}/{len(ok)} | {other}/{len(ok)} | "
              f"{', '.join(f'{k}: {v}' for k, v in sorted(shafts.items())) or '–'}"
              f"{f' ({err} errors)' if err else ''} |")
        tot[(grade, runout)][0] += sb
        tot[(grade, runout)][1] += len(ok)
    print("\n| grade | runout µm | recordings with gear_sidebands (3 gearboxes) |")
    print("|---|---|---|")
    for (grade, runout), (n, d) in sorted(tot.items()):
        print(f"| {grade or 'ideal'} | {runout} | {n}/{d} |")

    print("\n## faulty (grade 6, runout 8 µm): right / silent / wrong, 3 seeds each\n")
    print("right = a gear finding (gear_sidebands or gear_damage) on the faulty shaft; wrong = "
          "gear findings only on other shafts; silent = no gear finding. `+extra`: right runs "
          "that also name another shaft.\n")
    print("| gearbox | fault | gear (shaft) | right | silent | wrong | +extra | gear_damage on the "
          "right shaft | kinds/shafts per seed |")
    print("|---|---|---|---|---|---|---|---|---|")
    cls = defaultdict(lambda: [0, 0, 0, 0])
    for key in dict.fromkeys((r["box"], r["cond"]) for r in rows if r["set"] == "faulty"):
        rs = [r for r in rows if (r["box"], r["cond"]) == key and "error" not in r]
        nerr = sum(1 for r in rows if (r["box"], r["cond"]) == key and "error" in r)
        right = silent = wrong = extra = gd = 0
        per = []
        for r in rs:
            g = [f for f in r["findings"] if f["kind"] in GEAR_KINDS]
            on = [f for f in g if f["shaft"] == r["fault_shaft"]]
            if on:
                right += 1
                extra += any(f["shaft"] != r["fault_shaft"] for f in g)
            elif g:
                wrong += 1
            else:
                silent += 1
            gd += any(f["kind"] == "gear_damage" for f in on)
            per.append("+".join(f"{'SB' if f['kind'] == 'gear_sidebands' else 'GD'}:{f['shaft']}"
                                for f in g) or "none")
        box, cond = key
        fault, gear = cond.split()
        shaft = rs[0]["fault_shaft"] if rs else "?"
        print(f"| {box.removesuffix('.json')} | {fault} | {gear} ({shaft}) | {right} | {silent} "
              f"| {wrong} | {extra} | {gd} | {'; '.join(per)}"
              f"{f' ({nerr} errors)' if nerr else ''} |")
        c = cls[(fault, shaft)]
        c[0] += right; c[1] += silent; c[2] += wrong; c[3] += gd
    print("\n| fault | shaft | right | silent | wrong | of which gear_damage on the right shaft |")
    print("|---|---|---|---|---|---|")
    for (fault, shaft), c in cls.items():
        print(f"| {fault} | {shaft} | {c[0]} | {c[1]} | {c[2]} | {c[3]} |")

    # Same --seed = same gears (pitch errors, runout phases) and noise as the g6 r8 control.
    ctrl = {(r["box"], r["seed"]): r for r in rows if r["set"] == "control" and "error" not in r}
    sig = lambda r: sorted((f["kind"], f["shaft"]) for f in r["findings"])
    paired = [r for r in rows if r["set"] == "faulty" and "error" not in r
              and (r["box"], r["seed"]) in ctrl]
    same = sum(sig(r) == sig(ctrl[(r["box"], r["seed"])]) for r in paired)
    print(f"\nfaulty runs whose findings (kind, shaft) equal the same-seed healthy control's: "
          f"{same}/{len(paired)}")
    chance = defaultdict(lambda: [0, 0, 0])
    for r in paired:
        c = chance[(r["fault"], r["fault_shaft"])]
        c[0] += any(f["shaft"] == r["fault_shaft"] for f in ctrl[(r["box"], r["seed"])]["findings"])
        c[1] += any(f["shaft"] == r["fault_shaft"] and f["kind"] in GEAR_KINDS
                    for f in r["findings"])
        c[2] += 1
    print("\n| fault | shaft | 'right' | same-seed healthy control already names that shaft |")
    print("|---|---|---|---|")
    for (fault, shaft), c in chance.items():
        print(f"| {fault} | {shaft} | {c[1]}/{c[2]} | {c[0]}/{c[2]} |")
    for s in ("healthy", "control", "faulty"):
        v = [f for r in rows if r["set"] == s and "error" not in r for f in r["findings"]
             if f["kind"] == "gear_sidebands"]
        if v:
            frac = sorted(f["channels_pointing"] / f["channels_analysed"] for f in v)
            conf = sorted(f["confidence"] for f in v)
            mld = sorted(f["mean_line_db"] for f in v)
            print(f"{s}: {len(v)} gear_sidebands findings; channels pointing median "
                  f"{frac[len(frac) // 2]:.2f} (range {frac[0]:.2f}-{frac[-1]:.2f}); mean line "
                  f"{mld[len(mld) // 2]:.1f} dB over the floor; confidence median "
                  f"{conf[len(conf) // 2]:.2f} (range {conf[0]:.2f}-{conf[-1]:.2f})")


if __name__ == "__main__":
    if len(sys.argv) == 3 and sys.argv[1] == "--summarize":
        summarize([json.loads(l) for l in open(sys.argv[2])])
    else:
        main()
