# Threshold and rates of the wear indicator from study.py's rows (README: "Wear indicator against the baseline"): tuned on
# 29/47 seeds 1-6 (largest healthy growth + 3 dB, rounded up), reported on 29/47 seeds 7-12 and
# 23/41 seeds 1-6.
import json, sys, numpy as np
rows = [json.loads(l) for f in sys.argv[1:] for l in open(f)]
key = "mean_db"
def sets(pred):
    return [r for r in rows if pred(r)]
tune = sets(lambda r: r["case"] == "29_47" and r["seed"] <= 6)
report = sets(lambda r: not (r["case"] == "29_47" and r["seed"] <= 6))
def summary(rs, name):
    neg = np.array([r[key] for r in rs if r["kind"] != "worn"])
    print(f"{name}: healthy {len(neg)}: {key} min {neg.min():.2f} median {np.median(neg):.2f} max {neg.max():.2f}")
    for d in sorted({r["depth_um"] for r in rs if r["kind"] == "worn"}):
        pos = np.array([r[key] for r in rs if r["kind"] == "worn" and r["depth_um"] == d])
        print(f"  worn {d} um ({len(pos)}): min {pos.min():.2f} median {np.median(pos):.2f} max {pos.max():.2f}")
    return neg
neg_t = summary(tune, "tune (29/47 seeds 1-6)")
for kind in ("healthy_same_gears_torque_1.1", "healthy_other_gears"):
    v = [r[key] for r in rows if r["kind"] == kind]
    print(kind, "all:", " ".join(f"{x:.2f}" for x in sorted(v)))
# threshold: largest healthy growth on the tuning set + 3 dB margin
thr = float(np.ceil(neg_t.max() + 3.0))
print("threshold", thr)
def rates(rs, name):
    neg = [r for r in rs if r["kind"] != "worn"]
    wrong = sum(r[key] > thr for r in neg)
    print(f"{name}: healthy {len(neg)}: wrong (flagged) {wrong}, right (silent) {len(neg) - wrong}")
    for d in sorted({r["depth_um"] for r in rs if r["kind"] == "worn"}):
        pos = [r for r in rs if r["kind"] == "worn" and r["depth_um"] == d]
        right = sum(r[key] > thr for r in pos)
        print(f"  worn {d} um: right {right}/{len(pos)}, silent {len(pos) - right}")
rates(tune, "tune")
for c in ("29_47", "23_41"):
    rates([r for r in report if r["case"] == c], f"report {c}")
summary(report, "report")
# ROC AUC per depth on the report set
neg = np.array([r[key] for r in report if r["kind"] != "worn"])
for d in sorted({r["depth_um"] for r in report if r["kind"] == "worn"}):
    pos = np.array([r[key] for r in report if r["kind"] == "worn" and r["depth_um"] == d])
    auc = np.mean([(p > n) + 0.5 * (p == n) for p in pos for n in neg])
    print(f"report AUC worn {d} um vs healthy: {auc:.3f}")
