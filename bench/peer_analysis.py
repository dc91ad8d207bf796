#!/usr/bin/python3
"""Peer figures for bench/analysis_bench.cpp: scipy/numpy on the same length and parameters
(10^7 samples of Gaussian noise, fixed seed; Welch nperseg 4096, noverlap 2048, Hann, constant
detrend, density), timed on one core (CPU time, best of --repeat runs):

  moments   the statistics BM_Moments computes: mean, variance, scipy.stats.skew,
            scipy.stats.kurtosis (fisher=False, population), min, max, RMS, crest factor
  welch     scipy.signal.welch
  both      welch + moments (BM_WelchAndMomentsChunked's work)

With --cpp-json FILE (Google Benchmark JSON output of bench_analysis) it prints the C++/scipy
samples-per-second ratios too.

Usage: /usr/bin/python3 bench/peer_analysis.py [--samples N] [--repeat R] [--cpp-json FILE]
Run it under `taskset -c 0` with OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 MKL_NUM_THREADS=1.
"""
import argparse
import json
import math
import os
import time

for var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(var, "1")

import numpy as np  # noqa: E402
import scipy  # noqa: E402
import scipy.signal  # noqa: E402
import scipy.stats  # noqa: E402


def statistics(x):
    mean = x.mean()
    var = x.var()
    skew = scipy.stats.skew(x)
    kurt = scipy.stats.kurtosis(x, fisher=False)
    lo, hi = x.min(), x.max()
    rms = math.sqrt(float(np.dot(x, x)) / x.size)
    crest = max(abs(lo), abs(hi)) / rms
    return mean + var + skew + kurt + rms + crest + (hi - lo)


def welch(x):
    return scipy.signal.welch(x, fs=1.0, window="hann", nperseg=4096, noverlap=2048,
                              detrend="constant", scaling="density")


def best_cpu(fn, repeat):
    best = math.inf
    for _ in range(repeat):
        c0 = time.process_time()
        fn()
        best = min(best, time.process_time() - c0)
    return best


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--samples", type=int, default=10_000_000)
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--cpp-json", help="Google Benchmark JSON of bench_analysis")
    args = ap.parse_args()
    x = np.random.default_rng(20240601).standard_normal(args.samples)
    n = args.samples
    cpu = {
        "moments": best_cpu(lambda: statistics(x), args.repeat),
        "welch": best_cpu(lambda: welch(x), args.repeat),
        "both": best_cpu(lambda: (welch(x), statistics(x)), args.repeat),
    }
    print(f"scipy {scipy.__version__} numpy {np.__version__}, {n} samples, CPU time, best of"
          f" {args.repeat}:")
    for k, v in cpu.items():
        print(f"  {k:8s} {v * 1e3:8.1f} ms  {n / v / 1e6:8.1f} M samples/s")
    if args.cpp_json:
        with open(args.cpp_json) as fh:
            runs = {b["name"].split("/")[0]: b for b in json.load(fh)["benchmarks"]
                    if b.get("run_type", "iteration") == "iteration"}
        pairs = [("BM_Moments", "moments"), ("BM_MomentAccumulator", "moments"),
                 ("BM_WelchPsd", "welch"), ("BM_WelchAndMomentsChunked", "both")]
        print("C++ (items_per_second from CPU time) / scipy, same machine, same run:")
        for cname, pname in pairs:
            if cname in runs:
                c = runs[cname]["items_per_second"]
                print(f"  {cname:26s} {c / 1e6:8.1f} M samples/s vs scipy {pname:8s}"
                      f" {n / cpu[pname] / 1e6:8.1f}: {c * cpu[pname] / n:6.1f}x")


if __name__ == "__main__":
    main()
