"""The spectral functions against scipy (same definitions: the tolerances are float round-off of
two FFT implementations, 1e-9 relative to the largest value) and against analytic cases."""
import numpy as np
import pytest
import scipy.signal
import scipy.stats

import geardiag

FS = 5000.0
RNG = np.random.default_rng(1)
NOISE = RNG.standard_normal(20000)


def test_welch_equals_scipy():
    # Same definition (periodic Hann, half overlap, constant detrend, one-sided density).
    for nperseg, detrend in ((256, "constant"), (1024, "linear"), (300, False)):
        f, p = geardiag.welch(NOISE, FS, nperseg=nperseg, detrend=detrend)
        fs_, ps_ = scipy.signal.welch(NOISE, FS, nperseg=nperseg, detrend=detrend)
        np.testing.assert_allclose(f, fs_, rtol=0, atol=1e-9 * FS)
        np.testing.assert_allclose(p, ps_, rtol=0, atol=1e-9 * ps_.max())
    # 'spectrum' scaling with overlap and nfft given.
    f, p = geardiag.welch(NOISE, FS, nperseg=512, noverlap=128, nfft=1024, scaling="spectrum",
                          window="hamming")
    fs_, ps_ = scipy.signal.welch(NOISE, FS, nperseg=512, noverlap=128, nfft=1024,
                                  scaling="spectrum", window="hamming")
    np.testing.assert_allclose(p, ps_, rtol=0, atol=1e-9 * ps_.max())


def test_envelope_equals_scipy_hilbert():
    t = np.arange(8192) / FS
    x = (1 + 0.5 * np.cos(2 * np.pi * 30 * t)) * np.sin(2 * np.pi * 800 * t) + 0.1 * NOISE[:8192]
    e = geardiag.envelope(x)
    np.testing.assert_allclose(e, np.abs(scipy.signal.hilbert(x)), rtol=0, atol=1e-9 * e.max())


def test_spectrum_reads_sine_amplitude():
    n = 10000
    t = np.arange(n) / FS
    # 125.25 Hz: a quarter bin off the grid (0.5 Hz bins); the flat-top window reads the
    # amplitude within its 0.01 dB flatness (HFT95: 0.0044 dB = 0.05 %).
    x = 2.5 * np.sin(2 * np.pi * 125.25 * t + 0.3)
    f, a = geardiag.spectrum(x, FS)
    k = np.argmax(a)
    assert abs(f[k] - 125.25) <= 0.5
    assert a[k] == pytest.approx(2.5, rel=1e-3)
    # Hann against numpy with scipy's periodic Hann: 2|X_k| / sum(w).
    f, a = geardiag.spectrum(NOISE, FS, window="hann")
    w = scipy.signal.get_window("hann", NOISE.size)
    ref = 2 * np.abs(np.fft.rfft(NOISE * w)) / w.sum()
    np.testing.assert_allclose(a[1:-1], ref[1:-1], rtol=0, atol=1e-9 * ref.max())
    f, r = geardiag.spectrum(x, FS, scaling="rms")
    assert r.max() == pytest.approx(2.5 / np.sqrt(2), rel=1e-3)


def test_envelope_spectrum_reads_modulation():
    # AM: carrier 1 kHz, 40 Hz modulation of depth 0.5 -> envelope 1 + 0.5 cos: the 40 Hz line
    # reads 0.5 (peak), bin-centred (4 s record: 0.25 Hz bins); the band keeps both sidebands.
    t = np.arange(20000) / FS
    x = (1 + 0.5 * np.cos(2 * np.pi * 40 * t)) * np.sin(2 * np.pi * 1000 * t)
    f, a = geardiag.envelope_spectrum(x, FS, band=(700, 1300))
    k = np.argmin(np.abs(f - 40))
    assert a[k] == pytest.approx(0.5, rel=1e-2)  # 1 %: the band-pass filter's ripple
    assert np.argmax(a[f > 5]) + np.count_nonzero(f <= 5) == k


def test_kurtogram_finds_the_resonance_band():
    # Impacts every 100 ms ringing at 1.8 kHz in Gaussian noise: the selected band holds 1.8 kHz.
    n = 32768
    x = 0.3 * RNG.standard_normal(n)
    ring = np.exp(-np.arange(200) / 25.0) * np.sin(2 * np.pi * 1800 * np.arange(200) / FS)
    for start in range(0, n - 200, 500):
        x[start:start + 200] += ring
    k = geardiag.kurtogram(x, FS, max_level=5)
    assert k["low_hz"] <= 1800 <= k["high_hz"]
    assert k["kurtosis"] > 1
    assert [lv["kurtosis"].size for lv in k["levels"]][:3] == [1, 2, 3]


def test_arrays_are_not_copied_out():
    f, p = geardiag.welch(NOISE, FS)
    # The array is a view on the C++ vector (owned through a capsule), not a numpy-owned copy.
    assert not p.flags.owndata and p.base is not None


def test_bad_input_is_input_error():
    with pytest.raises(geardiag.InputError, match="nperseg"):
        geardiag.welch(NOISE, FS, nperseg=4)
    with pytest.raises(geardiag.InputError, match="window"):
        geardiag.spectrum(NOISE, FS, window="nope")
    with pytest.raises(ValueError, match="1-D"):
        geardiag.envelope(np.zeros((4, 4)))
