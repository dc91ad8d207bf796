"""Writes the package test's inputs: a pure tone as CSV (with a time column, so that the file
alone gives the sampling rate) and as a 16-bit mono WAV. The tones sit exactly on a Welch bin
(nperseg 256): f = 32 fs / 256, so the PSD's largest bin is the tone's.

usage: make_tones.py OUTDIR  ->  OUTDIR/tone_125hz.csv (fs 1000 Hz), OUTDIR/tone_1000hz.wav
(fs 8000 Hz)"""
import math
import pathlib
import struct
import sys
import wave

out = pathlib.Path(sys.argv[1])
out.mkdir(parents=True, exist_ok=True)

fs, f, n = 1000.0, 125.0, 2048
with open(out / "tone_125hz.csv", "w") as csv:
    csv.write("time_s,tone\n")
    for i in range(n):
        csv.write(f"{i / fs:.6f},{math.sin(2 * math.pi * f * i / fs):.9f}\n")

fs, f, n = 8000, 1000.0, 4096
with wave.open(str(out / "tone_1000hz.wav"), "wb") as wav:
    wav.setnchannels(1)
    wav.setsampwidth(2)
    wav.setframerate(fs)
    wav.writeframes(b"".join(
        struct.pack("<h", round(16000 * math.sin(2 * math.pi * f * i / fs))) for i in range(n)))
