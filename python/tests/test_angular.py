"""TSA, order spectrum and indicators against numpy/scipy and analytic cases."""
import numpy as np
import pytest
import scipy.stats

import geardiag

FS = 8192.0
SPR = 256          # samples per revolution: an integer number at 32 rev/s
REVS = 40


def shaft_record(noise=0.0, seed=3):
    rng = np.random.default_rng(seed)
    n = REVS * SPR
    theta = np.arange(n) / SPR  # revolutions; constant 32 rev/s
    x = 1.5 * np.sin(2 * np.pi * 7 * theta) + 0.4 * np.cos(2 * np.pi * 20 * theta)
    pulses = np.arange(REVS + 1) * SPR / FS
    return x + noise * rng.standard_normal(n), pulses


def test_tsa_equals_numpy_average():
    # Whole samples per revolution at constant speed: the resampled TSA of a band-limited signal
    # is the plain average of the revolutions (the sinc kernel interpolates on the grid);
    # tolerance 2e-3 of the amplitude for the kernel's band edge and the record ends.
    clean, pulses = shaft_record()
    r = geardiag.tsa(clean, FS, pulses, samples_per_rev=SPR, mesh_orders=[20])
    assert r["samples_per_rev"] == SPR and r["revolutions"] >= REVS - 2
    first = int(round(r["first_rev"]))
    rev = clean[first * SPR:(first + r["revolutions"]) * SPR].reshape(-1, SPR).mean(axis=0)
    np.testing.assert_allclose(r["tsa"], rev, rtol=0, atol=2e-3 * 1.5)
    # regular (shaft order 1 and mesh order 20) + residual = TSA; the difference removes order 20.
    np.testing.assert_allclose(r["regular"] + r["residual"], r["tsa"], atol=1e-9)
    spec = np.abs(np.fft.rfft(r["difference"])) * 2 / SPR
    assert spec[20] < 1e-9 and spec[7] == pytest.approx(1.5, abs=0.01)
    # White noise of RMS 0.3 averages down as 1/sqrt(N): the error's RMS stays within
    # [0.5, 1.3] x 0.3/sqrt(N) (the kernel's anti-alias band keeps ~90 % of the noise band; the
    # RMS of 256 samples of the mean scatters by ~5 %).
    noisy, _ = shaft_record(noise=0.3)
    t = geardiag.tsa(noisy, FS, pulses, samples_per_rev=SPR)
    err = np.sqrt(np.mean((t["tsa"] - r["tsa"]) ** 2))
    expect = 0.3 / np.sqrt(t["revolutions"])
    assert 0.5 * expect < err < 1.3 * expect, (err, expect)


def test_order_spectrum_reads_order_amplitudes():
    x, pulses = shaft_record()
    order, amp = geardiag.order_spectrum(x, FS, pulses, samples_per_rev=SPR)
    for q, a in ((7, 1.5), (20, 0.4)):
        k = np.argmin(np.abs(order - q))
        assert amp[k] == pytest.approx(a, rel=1e-3)  # Hann exact on a line; kernel 1e-3


def test_indicators_equal_scipy_moments():
    x = np.random.default_rng(5).standard_normal(5000) ** 3
    d = geardiag.indicators(x)
    assert d["rms"] == pytest.approx(np.sqrt(np.mean(x**2)), rel=1e-12)
    assert d["kurtosis"] == pytest.approx(scipy.stats.kurtosis(x, fisher=False), rel=1e-10)
    assert d["skewness"] == pytest.approx(scipy.stats.skew(x), rel=1e-10)
    assert d["crest_factor"] == pytest.approx(np.abs(x).max() / d["rms"], rel=1e-12)


def test_gear_indicators_on_a_tsa():
    # A TSA with a local fault (one tooth's worth of bump): FM4 is the normalised kurtosis of
    # the difference signal the tsa() call returns for the same mesh orders.
    theta = np.arange(1024) / 1024
    rev = np.sin(2 * np.pi * 30 * theta) + 0.2 * np.sin(2 * np.pi * 60 * theta)
    rev += 0.3 * np.exp(-((theta - 0.4) / 0.01) ** 2)
    d = geardiag.indicators(rev, mesh_order=30)
    pulses = np.arange(21) * 1024 / FS
    t = geardiag.tsa(np.tile(rev, 20), FS, pulses, samples_per_rev=1024, mesh_orders=[30])
    assert d["fm4"] == pytest.approx(scipy.stats.kurtosis(t["difference"], fisher=False),
                                     rel=1e-3)
    assert d["fm4"] > 3.5  # the bump stands out of a Gaussian's 3
    for key in ("fm0", "m6a", "m8a", "na4", "er", "ser", "slf", "si"):
        assert np.isfinite(d[key]), key
