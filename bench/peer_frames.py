#!/usr/bin/python3
"""Peer figure for the whole-log analysis (docs/performance.md): a scipy script doing, on the same
frames of the same recording, the work every analysis tool does on each vibration channel of each
frame, against `geardiag analyze --threads 1` on that recording, in one run on one core:

  moments   mean, RMS, peak, crest factor, scipy.stats.skew, scipy.stats.kurtosis
  welch     scipy.signal.welch (Hann, 4096 samples, half overlap, density)
  envelope  a 4th-order Butterworth band-pass (sosfiltfilt) over 0.2-0.45 of the sampling rate,
            scipy.signal.hilbert, |.|, the envelope's amplitude spectrum (rfft)

geardiag does far more per frame (angle resampling and TSA per shaft, kurtogram, sidebands,
bearing families, the damaged-shaft locator); the script is the floor a user's own pipeline
starts from. The frames are geardiag's own (`examined.frame_s` of its JSON). CPU time = user +
sys of each process (os.times for the script's children, resource for itself).

Usage: /usr/bin/python3 bench/peer_frames.py RECORDING.h5 [--geardiag build/geardiag] [--repeat R]
Run it under `taskset -c 0`.
"""
import argparse
import json
import math
import os
import resource
import subprocess
import tempfile
import time

for var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(var, "1")

import h5py  # noqa: E402
import numpy as np  # noqa: E402
import scipy  # noqa: E402
import scipy.fft  # noqa: E402
import scipy.signal  # noqa: E402
import scipy.stats  # noqa: E402


def self_cpu():
    r = resource.getrusage(resource.RUSAGE_SELF)
    return r.ru_utime + r.ru_stime


def geardiag_cpu(exe, path, repeat):
    """Least CPU time (user + sys) of `analyze --threads 1`, and its JSON report."""
    best, report = math.inf, None
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "report.json")
        for _ in range(repeat):
            before = os.times()
            subprocess.run([exe, "analyze", path, "--threads", "1", "--json", out], check=True,
                           stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            after = os.times()
            cpu = (after.children_user - before.children_user
                   + after.children_system - before.children_system)
            best = min(best, cpu)
            with open(out) as fh:
                report = json.load(fh)
    return best, report


def vibration_channels(f):
    return [name for name, ds in f["signals"].items()
            if ds.attrs.get("role", b"vibration") in (b"vibration", "vibration")]


def analyse_frame(x, fs):
    mean = x.mean()
    rms = math.sqrt(float(np.dot(x, x)) / x.size)
    peak = float(np.max(np.abs(x)))
    stats = (mean, rms, peak, peak / rms if rms > 0 else 0.0,
             scipy.stats.skew(x), scipy.stats.kurtosis(x, fisher=False))
    psd = scipy.signal.welch(x, fs=fs, window="hann", nperseg=4096, noverlap=2048,
                             detrend="constant", scaling="density")[1]
    sos = scipy.signal.butter(4, [0.2 * fs, 0.45 * fs], btype="bandpass", fs=fs, output="sos")
    band = scipy.signal.sosfiltfilt(sos, x)
    env = np.abs(scipy.signal.hilbert(band))
    env_spectrum = np.abs(scipy.fft.rfft(env - env.mean())) / env.size
    return sum(stats) + float(psd.sum()) + float(env_spectrum.sum())


def recording_samples(path):
    with h5py.File(path, "r") as f:
        return sum(ds.shape[0] for ds in f["signals"].values())


def scipy_cpu(path, frame_s, repeat):
    best, samples = math.inf, 0
    for _ in range(repeat):
        start = self_cpu()
        samples = 0
        with h5py.File(path, "r") as f:
            for name in vibration_channels(f):
                ds = f["signals"][name]
                fs = float(ds.attrs["fs_hz"])
                step = max(1, int(round(frame_s * fs)))
                for begin in range(0, ds.shape[0], step):
                    x = ds[begin:begin + step]
                    analyse_frame(x, fs)
                    samples += x.size
        best = min(best, self_cpu() - start)
    return best, samples


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("recording")
    ap.add_argument("--geardiag", default="build/geardiag")
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    g_cpu, report = geardiag_cpu(args.geardiag, args.recording, args.repeat)
    examined = report["examined"]
    frame_s = examined.get("frame_s") or examined["duration_s"]
    s_cpu, samples = scipy_cpu(args.recording, frame_s, args.repeat)
    every = recording_samples(args.recording)
    print(f"machine: {os.cpu_count()} cores; {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())};"
          f" scipy {scipy.__version__}, numpy {np.__version__}")
    print(f"{args.recording}: {samples / 1e6:.1f} M vibration samples in {examined['frames']}"
          f" frames of {frame_s:g} s; CPU time, least of {args.repeat}:")
    print(f"  geardiag analyze --threads 1: {g_cpu:7.2f} s  {samples / g_cpu / 1e6:6.2f} M vibration"
          f" samples/s ({every / g_cpu / 1e6:.2f} M/s counting all {every / 1e6:.1f} M samples of"
          f" the recording's channels)")
    print(f"  scipy moments + welch + envelope: {s_cpu:7.2f} s  {samples / s_cpu / 1e6:6.2f} M"
          f" samples/s")
    print(f"  geardiag / scipy samples per second: {s_cpu / g_cpu:.2f}x")


if __name__ == "__main__":
    main()
