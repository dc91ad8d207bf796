"""geardiag: gear and bearing vibration diagnostics, from Python.

The same C++ libraries as the ``geardiag`` command (simulator, detectors, recording I/O), bound
with pybind11 (the compiled part is ``geardiag._geardiag``). Arrays are numpy float64: inputs are
read in place when they are C-contiguous float64 (converted once otherwise), results own the C++
buffer (no copy). Long calls release the GIL. Bad input raises :class:`InputError` (a
``ValueError``) naming the file, field and reason, as the command line does.

Functions (see each docstring and docs/python.md):
  read_recording, write_recording, Recording, Signal, Gearbox,
  welch, spectrum, envelope, envelope_spectrum, kurtogram, tsa, order_spectrum, indicators,
  analyze, simulate, simulate_kinematic, attribute, pulse_times
"""

import json as _json
import os as _os

import numpy as _np

from . import _geardiag as _g
from ._geardiag import Gearbox, InputError

__all__ = [
    "InputError", "Gearbox", "Signal", "Recording", "read_recording", "write_recording",
    "welch", "spectrum", "envelope", "envelope_spectrum", "kurtogram", "tsa", "order_spectrum",
    "indicators", "analyze", "simulate", "simulate_kinematic", "attribute", "pulse_times",
]

_SIGNAL_FIELDS = ("name", "fs_hz", "unit", "direction", "location", "role", "shaft", "mesh", "ppr")


class Signal(_np.ndarray):
    """A channel: a 1-D float64 numpy array with what it measures as attributes.

    Attributes (the channel contract, libdiag/include/diag/io/recording.hpp): ``name``,
    ``fs_hz`` (sampling rate [Hz]), ``unit``, ``role`` ("vibration", "tacho", "angle", "speed",
    "force", "displacement", "other"), ``direction``, ``location``, ``shaft``, ``mesh``, ``ppr``
    (tacho pulses per revolution). ``t`` is the time axis [s].
    """

    def __new__(cls, samples, fs_hz, name="", unit="", role="vibration", direction="",
                location="", shaft="", mesh="", ppr=0):
        obj = _np.asarray(samples, dtype=_np.float64).view(cls)
        obj.name, obj.fs_hz, obj.unit, obj.role = name, float(fs_hz), unit, role
        obj.direction, obj.location, obj.shaft, obj.mesh, obj.ppr = (
            direction, location, shaft, mesh, int(ppr))
        return obj

    def __array_finalize__(self, obj):
        for f in _SIGNAL_FIELDS:
            setattr(self, f, getattr(obj, f, "" if f not in ("fs_hz", "ppr") else 0))
        if not getattr(self, "role", ""):
            self.role = "vibration"

    @property
    def t(self):
        """Time of each sample [s]."""
        return _np.arange(self.shape[0]) / self.fs_hz

    def _to_dict(self):
        d = {f: getattr(self, f) for f in _SIGNAL_FIELDS}
        d["samples"] = _np.ascontiguousarray(self.view(_np.ndarray))
        return d


def _signal_from(d):
    fields = {k: d[k] for k in _SIGNAL_FIELDS}
    return Signal(d["samples"], **fields)


class Recording:
    """What a rig (or the simulator) recorded.

    ``signals`` and ``tachos``: dicts channel name -> :class:`Signal`; ``gearbox``: the stored
    description as a :class:`Gearbox` (None when absent); ``gearbox_json``; ``truth``: the
    simulator's ground truth as a dict, checked and in its one layout
    (diag/io/truth.hpp; None for measurements); ``metadata`` (root attributes);
    ``speed_rpm`` (the input speed recorded with the data, 0 when unknown); ``notes``;
    ``roles_stated``.
    """

    def __init__(self, signals=None, tachos=None, gearbox_json="", truth_json="", metadata=None,
                 speed_rpm=0.0, notes=None, roles_stated=True, warnings=None):
        def as_dict(v):
            if v is None:
                return {}
            if isinstance(v, dict):
                return dict(v)
            return {s.name: s for s in v}
        self.signals = as_dict(signals)
        self.tachos = as_dict(tachos)
        self.gearbox_json = gearbox_json or ""
        self.truth_json = truth_json or ""
        self.metadata = dict(metadata or {})
        self.speed_rpm = float(speed_rpm)
        self.notes = list(notes or [])
        self.roles_stated = bool(roles_stated)
        self.warnings = list(warnings or [])

    @property
    def gearbox(self):
        return Gearbox.from_json(_json.loads(self.gearbox_json)) if self.gearbox_json else None

    @property
    def truth(self):
        # Typed and checked by the library (diag/io/truth.hpp): one layout, the fault vocabulary's
        # names; an older file's layout is read too.
        return _g.parse_truth(self.truth_json) if self.truth_json else None

    @classmethod
    def _from_dict(cls, d):
        return cls(signals=[_signal_from(s) for s in d["signals"]],
                   tachos=[_signal_from(s) for s in d["tachos"]],
                   gearbox_json=d["gearbox_json"], truth_json=d["truth_json"],
                   metadata=d["metadata"], speed_rpm=d["speed_rpm"], notes=d["notes"],
                   roles_stated=d["roles_stated"], warnings=d.get("warnings"))

    def _to_dict(self):
        def sig(name, s):
            if not isinstance(s, Signal):
                raise InputError(f"recording: channel {name}: not a geardiag.Signal")
            d = s._to_dict()
            d["name"] = d["name"] or name
            return d
        return {"signals": [sig(n, s) for n, s in self.signals.items()],
                "tachos": [sig(n, s) for n, s in self.tachos.items()],
                "gearbox_json": self.gearbox_json, "truth_json": self.truth_json,
                "metadata": {str(k): str(v) for k, v in self.metadata.items()},
                "speed_rpm": self.speed_rpm, "notes": self.notes,
                "roles_stated": self.roles_stated}

    def __repr__(self):
        chans = ", ".join(f"{n} ({s.role}, {s.fs_hz:g} Hz, {s.shape[0]} samples)"
                          for n, s in self.signals.items())
        return f"Recording(signals: {chans}; tachos: {list(self.tachos)})"


def read_recording(path, fs_hz=None):
    """Reads a geardiag HDF5 recording, or imports a CSV / WAV / MAT measurement (``fs_hz``
    for CSV without a time column and for MAT), as ``geardiag analyze`` does."""
    return Recording._from_dict(_g.read_recording(_os.fspath(path), fs_hz))


def write_recording(path, recording):
    """Writes a :class:`Recording` as a geardiag HDF5 file (atomically: a temporary file renamed
    into place)."""
    _g.write_recording(_os.fspath(path), recording._to_dict())


def _x(x):
    return _np.ascontiguousarray(_np.asarray(x, dtype=_np.float64).view(_np.ndarray))


def welch(x, fs_hz, nperseg=256, noverlap=None, nfft=None, window="hann", detrend="constant",
          scaling="density"):
    """Welch PSD (scipy.signal.welch's conventions: periodic window, one-sided, half overlap by
    default). Returns (frequency_hz, psd) with psd in x-units^2/Hz ('density') or x-units^2
    ('spectrum')."""
    return _g.welch(_x(x), fs_hz, nperseg, -1 if noverlap is None else noverlap, nfft or 0,
                    window, detrend or "none", scaling)


def spectrum(x, fs_hz, window="flattop", scaling="peak", nfft=None, remove_mean=False):
    """One-sided amplitude spectrum: a sine of amplitude A on a line reads A ('peak') or
    A/sqrt(2) ('rms'). Returns (frequency_hz, amplitude)."""
    return _g.spectrum(_x(x), fs_hz, window, scaling, nfft or 0, remove_mean)


def envelope(x):
    """|analytic signal| (Hilbert envelope), as scipy.signal.hilbert's magnitude."""
    return _g.envelope(_x(x))


def envelope_spectrum(x, fs_hz, band=None, window="rectangular", scaling="peak"):
    """Spectrum of the envelope of x band-passed to ``band`` = (low_hz, high_hz) (None: the whole
    band). Returns (frequency_hz, amplitude)."""
    lo, hi = band if band is not None else (0.0, 0.0)
    return _g.envelope_spectrum(_x(x), fs_hz, lo, hi, window, scaling)


def kurtogram(x, fs_hz, max_level=6):
    """Antoni's fast kurtogram: dict with ``levels`` (level, bandwidth_hz, kurtosis per band),
    the selected band (centre_hz, bandwidth_hz, low_hz, high_hz, level, kurtosis)."""
    return _g.kurtogram(_x(x), fs_hz, max_level)


def pulse_times(tacho, threshold=None):
    """Rising-edge times [s] of a pulse-train :class:`Signal` (threshold halfway between its
    extremes by default), for :func:`tsa` and :func:`order_spectrum`."""
    v = _np.asarray(tacho, dtype=_np.float64)
    thr = 0.5 * (v.min() + v.max()) if threshold is None else threshold
    above = v > thr
    idx = _np.flatnonzero(~above[:-1] & above[1:]) + 1
    # Linear interpolation of the crossing between samples idx-1 and idx.
    frac = (thr - v[idx - 1]) / (v[idx] - v[idx - 1])
    return (idx - 1 + frac) / tacho.fs_hz


def tsa(x, fs_hz, pulse_times_s, samples_per_rev=1024, min_revolutions=10, pulses_per_rev=1,
        mesh_orders=None):
    """Time-synchronous average over one revolution from tacho pulse times. With
    ``mesh_orders`` (teeth of the shaft's gears) also its regular, residual and difference
    signals. Returns a dict (tsa, revolutions, samples_per_rev, first_rev, ...)."""
    return _g.tsa(_x(x), fs_hz, _x(pulse_times_s), samples_per_rev, min_revolutions,
                  pulses_per_rev, None if mesh_orders is None else list(mesh_orders))


def order_spectrum(x, fs_hz, pulse_times_s, samples_per_rev=256, pulses_per_rev=1,
                   segment_revs=0, overlap=0.5, window="hann"):
    """Order spectrum of x resampled at uniform shaft angles. Returns (order, amplitude)."""
    return _g.order_spectrum(_x(x), fs_hz, _x(pulse_times_s), samples_per_rev, pulses_per_rev,
                             segment_revs, overlap, window)


def indicators(x, mesh_order=0, mesh_orders=None, mesh_harmonics=3, ser_sidebands=6):
    """Condition indicators as a dict: rms, peak, peak_to_peak, crest_factor, kurtosis (3 for
    Gaussian), skewness; with ``mesh_order`` (teeth of the monitored gear) x is one revolution of
    a TSA and the gear metrics FM0, FM4, M6A, M8A, NA4, ER, SER, SLF, SI are added (lower-case
    keys)."""
    return _g.indicators(_x(x), mesh_order, None if mesh_orders is None else list(mesh_orders),
                         mesh_harmonics, ser_sidebands)


def _nest_curves(flat):
    """{"channels/a1/psd": group} -> {"channels": {"a1": {"psd": group}}}; a group is a dict of
    its columns (numpy arrays) plus "units", "attrs" and "description"."""
    out = {}
    for path, g in flat.items():
        node = out
        parts = path.split("/")
        for p in parts[:-1]:
            node = node.setdefault(p, {})
        group = dict(g["columns"])
        group["units"] = g["units"]
        group["attrs"] = g["attrs"]
        group["description"] = g["description"]
        node.setdefault(parts[-1], {}).update(group)
    return out


def analyze(source, gearbox=None, fs_hz=None, rpm=0.0, channel_map=None, tachos=(),
            baseline=(), gear_baseline=None, max_samples=None, frame_seconds=None, html=False,
            **options):
    """The analysis of ``geardiag analyze`` (the same library call, the same result): ``source``
    is a path (HDF5 recording, or CSV / WAV / MAT with ``fs_hz``) or a :class:`Recording`;
    ``gearbox`` a :class:`Gearbox`, a JSON path or a dict (default: the recording's own).
    ``rpm``, ``channel_map`` (a file) and ``tachos`` ("CHANNEL=SHAFT[:PPR]") are the CLI's
    --rpm, --channels and --tacho; ``baseline`` (paths or Recordings: healthy recordings of the
    same machine), ``gear_baseline`` (a healthy recording of the same gears, or several: each
    shaft is compared with the one that explains it best),
    ``max_samples`` (an opt-in limit: only the first part is examined, the rest reported as not
    examined; default: every sample) and ``frame_seconds`` (the frames of a long recording at
    most this long; default: as long as memory allows) its --baseline, --gear-baseline,
    --max-samples and --frame-seconds. ``options``: the AnalyzeOptions fields
    (welch_nperseg, kurtogram_max_level, tsa_min_revolutions, tacho_pulses_per_rev,
    mesh_harmonics, sidebands, peaks_reported, threads, plot_points, envelope_plot_max_hz,
    nominal_time_s, speed_from_vibration, timing).

    Returns the JSON report as a dict (the same keys as ``--json``) plus ``"curves"``: every
    curve of the report as numpy arrays (the groups of ``--curves``, nested by path: e.g.
    ``r["curves"]["channels"]["DE"]["envelope_spectrum"]["amplitude"]``) and, with
    ``html=True``, ``"html"``: the self-contained HTML report of ``--html`` as text.
    """
    def _input(src):
        return src._to_dict() if isinstance(src, Recording) else _os.fspath(src)

    if isinstance(gearbox, (str, _os.PathLike)):
        gearbox = Gearbox.from_json(gearbox)
    if isinstance(baseline, (str, _os.PathLike, Recording)):
        baseline = [baseline]
    if gear_baseline is None:
        gear_baseline = []
    elif isinstance(gear_baseline, (str, _os.PathLike, Recording)):
        gear_baseline = [gear_baseline]
    report, curves = _g.analyze(_input(source), gearbox, fs_hz, float(rpm),
                                _os.fspath(channel_map) if channel_map else "", list(tachos),
                                [_input(b) for b in baseline],
                                [_input(b) for b in gear_baseline],
                                max_samples, frame_seconds, bool(html), options)
    report["curves"] = _nest_curves(curves)
    return report


def simulate(gearbox, scenario=None, duration_s=None, fs_hz=None, seed=None):
    """The dynamic simulator (``geardiag simulate``): ``scenario`` is a dict or a JSON path in
    the scenario form of docs/formats.md (None: the defaults). Returns a :class:`Recording`
    with the ground truth (``.truth``) and the simulator's warnings (``.warnings``)."""
    return Recording._from_dict(_g.simulate(gearbox, scenario, duration_s, fs_hz, seed))


def simulate_kinematic(gearbox, step_rad=0.001, revolutions=0.0, runout_output_rad=0.0,
                       mesh_te_output_rad=0.0, noise_output_rad=0.0, noise_input_rad=0.0,
                       encoder_counts_per_rev=0, seed=1):
    """The kinematic simulator (``geardiag simulate --mode kinematic``): input and output shaft
    angles of a gearbox with the description's tooth defects. Returns a :class:`Recording` with
    channels input_angle_rad, output_angle_rad, transmission_error_rad and the truth."""
    return Recording._from_dict(_g.simulate_kinematic(
        gearbox, step_rad, revolutions, runout_output_rad, mesh_te_output_rad, noise_output_rad,
        noise_input_rad, encoder_counts_per_rev, seed))


def attribute(input_angle, output_angle, gearbox, **options):
    """Which gear carries a defect, from the input and output shaft angles [rad] (``geardiag
    attribute``; seed 003). Returns the ``--json`` dict (status, findings, ...). ``options``: the
    AttributionOptions fields (threshold_sigma, period_tolerance, min_coverage, ...)."""
    if isinstance(gearbox, (str, _os.PathLike, dict)):
        gearbox = Gearbox.from_json(gearbox)
    return _g.attribute(_x(input_angle), _x(output_angle), gearbox, options)
