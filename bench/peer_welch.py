#!/usr/bin/python3
"""Peer figure for bench/welch_bench.cpp: scipy.signal.welch on the same length and parameters
(10^7 samples of Gaussian noise from numpy with a fixed seed, nperseg 4096, noverlap 2048, Hann,
constant detrend, density), timed on one core. Prints samples/s (best of --repeat runs), so
bench_welch's items_per_second and this figure compare as a ratio in the same run.

Usage: /usr/bin/python3 bench/peer_welch.py [--samples N] [--repeat R]
Run it under `taskset -c 0` (as bench/run.sh does for the C++ benches) and with
OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 MKL_NUM_THREADS=1 so numpy stays on one core.
"""
import argparse
import os
import time

for var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(var, "1")

import numpy as np  # noqa: E402
import scipy  # noqa: E402
import scipy.signal  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--samples", type=int, default=10_000_000)
    ap.add_argument("--repeat", type=int, default=5)
    args = ap.parse_args()
    x = np.random.default_rng(20240601).standard_normal(args.samples)
    best_cpu = best_wall = float("inf")
    for _ in range(args.repeat):
        c0, t0 = time.process_time(), time.perf_counter()
        f, p = scipy.signal.welch(x, fs=1.0, window="hann", nperseg=4096, noverlap=2048,
                                  detrend="constant", scaling="density")
        best_cpu = min(best_cpu, time.process_time() - c0)
        best_wall = min(best_wall, time.perf_counter() - t0)
    # CPU time is what Google Benchmark's items_per_second is computed from.
    print(f"scipy {scipy.__version__} numpy {np.__version__}: scipy.signal.welch "
          f"{args.samples} samples, nperseg 4096, 50 % overlap: cpu {best_cpu * 1e3:.1f} ms, "
          f"wall {best_wall * 1e3:.1f} ms; {args.samples / best_cpu / 1e6:.1f} M samples/s (cpu)")


if __name__ == "__main__":
    main()
