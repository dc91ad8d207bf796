#!/usr/bin/env python3
"""The false-alarm rates of a history's wear threshold (docs/cli/batch.md, "Wear against the
reference's own spread"), by Monte Carlo under its model: a mesh's growth in dB is a recording's
level less a level the reference fixes, the levels independent Gaussians of one (unknown)
scatter sigma. With the n reference values' mean m and standard deviation s, the threshold is
    m + t_{n-1}(1 - alpha) * s * sqrt(1 + 1/n)        (the spread floor of 0.1 dB left out)
and a healthy recording exceeds it with probability alpha exactly; two successive healthy
recordings (one event: both read against the same m and s) do so together more often than
alpha^2. Prints, per n, the single and the pair rate and the median threshold in sigmas.

    python3 docs/wear_indicator/history_threshold.py
"""
import numpy as np
from scipy import stats

ALPHA = 0.01
N = 400_000
rng = np.random.default_rng(1)
print("n  single    pair      median threshold / sigma")
for n in (3, 4, 5, 6, 8, 12):
    ref = rng.standard_normal((N, n))
    m, s = ref.mean(axis=1), ref.std(axis=1, ddof=1)
    threshold = m + stats.t.ppf(1 - ALPHA, n - 1) * s * np.sqrt(1 + 1 / n)
    x1, x2 = rng.standard_normal(N), rng.standard_normal(N)
    single = (x1 > threshold).mean()
    pair = ((x1 > threshold) & (x2 > threshold)).mean()
    print(f"{n:<2} {single:.4f}    {pair:.5f}   {np.median(threshold):.2f}")
