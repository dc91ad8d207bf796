"""Recordings, gearbox, simulation, analysis and attribution against the C++ command line (the
same libraries: the results must be identical, tolerance 0) and against the truth."""
import json
import subprocess

import h5py
import numpy as np
import pytest
import scipy.signal

import geardiag
from conftest import EXE, SHARED_DATA, SIM_GEARBOX, SIM_SCENARIO, THREE_SHAFT


def test_gearbox_derived_quantities():
    gb = geardiag.Gearbox.from_json(THREE_SHAFT)
    assert gb.summary() == geardiag.Gearbox.from_json(json.loads(THREE_SHAFT.read_text())).summary()
    shafts = {s["name"]: s for s in gb.shafts}
    # 30 rpm input, 18 -> 36 and 18 -> 36: the counter at 15 rpm, the output at 7.5 rpm.
    assert shafts["input"]["speed_rpm"] == pytest.approx(30)
    assert shafts["counter"]["speed_rpm"] == pytest.approx(15)
    assert shafts["output"]["speed_hz"] == pytest.approx(7.5 / 60)
    meshes = {m["name"]: m for m in gb.meshes}
    assert meshes["z1_z2"]["frequency_hz"] == pytest.approx(18 * 0.5)
    assert meshes["z3_z4"]["frequency_hz"] == pytest.approx(18 * 0.25)
    # Recurrence period T_i = u_total / u_i input revolutions (seed 003 eq. 5 corrected).
    periods = {g["name"]: g["recurrence_period_input_rev"] for g in gb.gears}
    assert periods == pytest.approx({"z1": 1, "z2": 2, "z3": 2, "z4": 4})
    assert gb.total_ratio == pytest.approx(4)


def test_recording_round_trip_and_h5py(sim_recording, sim_file):
    rec = geardiag.read_recording(sim_file)
    assert set(rec.signals) == set(sim_recording.signals)
    for name, s in sim_recording.signals.items():
        r = rec.signals[name]
        np.testing.assert_array_equal(r, s)
        assert (r.fs_hz, r.unit, r.role, r.shaft, r.mesh) == (s.fs_hz, s.unit, s.role, s.shaft,
                                                              s.mesh)
    assert rec.truth == sim_recording.truth and rec.truth is not None
    assert rec.gearbox.summary() == sim_recording.gearbox.summary()
    with h5py.File(sim_file, "r") as f:
        name = next(iter(rec.signals))
        np.testing.assert_array_equal(f["signals"][name][()], rec.signals[name])
        assert f["signals"][name].attrs["fs_hz"] == rec.signals[name].fs_hz
    # Zero-copy out: the samples are a view on the C++ buffer.
    assert not np.asarray(rec.signals[name]).flags.owndata


def test_simulation_is_deterministic_and_has_roles(sim_recording):
    again = geardiag.simulate(SIM_GEARBOX, {"duration_s": 0.2, "fs_hz": 10000.0}, seed=7)
    once = geardiag.simulate(SIM_GEARBOX, {"duration_s": 0.2, "fs_hz": 10000.0}, seed=7)
    for n in once.signals:
        np.testing.assert_array_equal(once.signals[n], again.signals[n])
    roles = {s.role for s in sim_recording.signals.values()}
    assert "vibration" in roles and sim_recording.tachos
    fault = sim_recording.truth["defects"][0]
    assert (fault["gear"], fault["shaft"], fault["type"]) == ("z2", "counter", "crack")
    assert sim_recording.truth["input_speed_rpm_min"] == 1500


def test_bad_input_names_file_and_field():
    with pytest.raises(geardiag.InputError, match=r"gears\[0\]\.teeth: must be a positive"):
        geardiag.Gearbox.from_json({"name": "x", "shafts": [{"name": "a"}],
                                    "gears": [{"name": "z1", "shaft": "a", "teeth": -3}]})
    with pytest.raises(geardiag.InputError, match="/nonexistent.h5: no such file"):
        geardiag.read_recording("/nonexistent.h5")
    with pytest.raises(geardiag.InputError, match="unknown option 'bogus'"):
        geardiag.analyze("/nonexistent.h5", bogus=1)


def test_analyze_equals_cli(sim_file, cli_outputs):
    r = geardiag.analyze(sim_file)
    curves = r.pop("curves")
    cli = json.loads(cli_outputs["json"].read_text())
    assert r == cli  # same libraries, same options, deterministic: identical
    # The curves are those the CLI writes to --curves (h5py reads them), array for array.
    with h5py.File(cli_outputs["curves"], "r") as f:
        assert f.attrs["format"] == "geardiag-curves"
        n = 0
        for ch, groups in curves["channels"].items():
            for gname in ("psd", "spectrum", "envelope_spectrum", "order_spectrum", "waveform",
                          "kurtogram", "spectrogram"):
                if gname in groups:
                    g = f["channels"][ch][gname]
                    for col in groups[gname]["units"]:
                        np.testing.assert_array_equal(g[col][()], groups[gname][col])
                        assert g[col].attrs["unit"] == groups[gname]["units"][col]
                        n += 1
        assert n > 10
        # The spectrogram: a 2-D dataset [time, frequency] with its axes and units.
        sg = next(iter(f["channels"].values()))["spectrogram"]
        assert sg["psd_db"].shape == (sg["time_s"].size, sg["frequency_hz"].size)
        assert sg["psd_db"].attrs["unit"] == "dB re 1 (m/s^2)^2/Hz"
        assert sg["time_s"].attrs["unit"] == "s" and sg["frequency_hz"].attrs["unit"] == "Hz"
        # TSA signals per shaft with the angle axis.
        tsa = next(iter(f["channels"].values()))["tsa"]
        for shaft in tsa:
            assert set(tsa[shaft]) == {"angle_rev", "tsa", "regular", "residual", "difference"}
        assert "time_s" in f["speed"] or "speed" not in f
    # The kurtogram's selected band is the envelope spectrum's demodulation band.
    ch = next(iter(curves["channels"].values()))
    assert ch["kurtogram"]["attrs"]["selected_low_hz"] == ch["envelope_spectrum"]["attrs"][
        "band_low_hz"]
    assert ch["waveform"]["units"]["value"] == "m/s^2"


def test_analyze_has_every_option_of_the_cli(sim_file, sim_recording, tmp_path):
    """Baselines (paths and Recordings), the gear baseline, --max-samples, the analysis options
    and the HTML report: the same library call as the CLI, the same bytes."""
    healthy = geardiag.simulate(geardiag.Gearbox.from_json(SIM_GEARBOX),
                                dict(SIM_SCENARIO, faults=[]), seed=8)
    healthy_file, other_file = tmp_path / "healthy.h5", tmp_path / "other.h5"
    geardiag.write_recording(healthy_file, healthy)
    geardiag.write_recording(other_file, geardiag.simulate(
        geardiag.Gearbox.from_json(SIM_GEARBOX), dict(SIM_SCENARIO, faults=[]), seed=9))
    out = {"json": tmp_path / "r.json", "html": tmp_path / "r.html"}
    subprocess.run([EXE, "analyze", str(sim_file), "--baseline", str(healthy_file),
                    str(other_file), "--gear-baseline", str(healthy_file), "--max-samples", "0",
                    "--mesh-harmonics", "2", "--sidebands", "3", "--tsa-min-revs", "5",
                    "--threads", "1", "--json", str(out["json"]), "--html", str(out["html"])],
                   check=True, stdout=subprocess.DEVNULL)
    r = geardiag.analyze(sim_file, baseline=[healthy_file, other_file], gear_baseline=healthy_file,
                         max_samples=0, html=True, mesh_harmonics=2, sidebands=3,
                         tsa_min_revolutions=5, threads=1)
    r.pop("curves")
    page = r.pop("html")
    cli = json.loads(out["json"].read_text())
    assert r == cli
    assert "anomaly_score" in cli and "gear_damage" in cli
    assert page == out["html"].read_text()
    # Several gear baselines, as --gear-baseline A B.
    subprocess.run([EXE, "analyze", str(sim_file), "--gear-baseline", str(healthy_file),
                    str(other_file), "--threads", "1", "--json", str(out["json"])], check=True,
                   stdout=subprocess.DEVNULL)
    both = geardiag.analyze(sim_file, gear_baseline=[healthy_file, other_file], threads=1)
    both.pop("curves")
    assert both == json.loads(out["json"].read_text())
    # A baseline given as a Recording in memory is the same baseline.
    m = geardiag.analyze(sim_file, baseline=[healthy, other_file], threads=1)
    assert m["anomaly_score"] == r["anomaly_score"]
    # --max-samples: the first half of each channel, the rest said to be not examined, as the
    # CLI does.
    subprocess.run([EXE, "analyze", str(sim_file), "--max-samples", "5000", "--json",
                    str(out["json"])], check=True, stdout=subprocess.DEVNULL)
    cut = geardiag.analyze(sim_file, max_samples=5000)
    cut.pop("curves")
    assert cut == json.loads(out["json"].read_text())
    assert not cut["examined"]["complete"]
    assert "max_samples" in cut["examined"]["not_examined"][0]
    # --frame-seconds: the frames of the whole-log analysis.
    subprocess.run([EXE, "analyze", str(sim_file), "--frame-seconds", "0.25", "--json",
                    str(out["json"])], check=True, stdout=subprocess.DEVNULL)
    framed = geardiag.analyze(sim_file, frame_seconds=0.25)
    framed.pop("curves")
    assert framed == json.loads(out["json"].read_text())
    assert framed["examined"]["frames"] > 1 and framed["examined"]["complete"]


def test_analyze_psd_curve_against_scipy(sim_recording):
    # The PSD curve is Welch (nperseg 4096) peak-hold decimated for plotting: its largest value
    # is scipy's largest (1e-9 relative: round-off).
    name, sig = next((n, s) for n, s in sim_recording.signals.items() if s.role == "vibration")
    r = geardiag.analyze(sim_recording)
    psd = r["curves"]["channels"][name]["psd"]
    assert psd["units"]["psd"] == "(m/s^2)^2/Hz"
    f, p = scipy.signal.welch(np.asarray(sig), sig.fs_hz, nperseg=4096)
    assert psd["psd"].max() == pytest.approx(p.max(), rel=1e-9)
    assert r["findings"] is not None


def test_attribute_finds_the_defect():
    gb = json.loads(THREE_SHAFT.read_text())
    gb["defects"] = [{"gear": "z2", "type": "chip", "size_deg": 0.5, "phase_deg": 40}]
    gearbox = geardiag.Gearbox.from_json(gb)
    rec = geardiag.simulate_kinematic(gearbox, step_rad=np.deg2rad(0.05),
                                      noise_output_rad=np.deg2rad(0.001), seed=4)
    r = geardiag.attribute(rec.signals["input_angle_rad"], rec.signals["output_angle_rad"],
                           gearbox)
    truth = rec.truth["defects"][0]
    assert r["status"] == "attributed"
    assert [f["shaft"] for f in r["findings"]] == [truth["shaft"]] == ["counter"]
    assert r["findings"][0]["period_input_rev"] == pytest.approx(truth["period_input_rev"])


@pytest.mark.skipif(not (SHARED_DATA / "cwru-bearing" / "IR007_0.mat").exists(),
                    reason="CWRU data absent")
def test_analyze_cwru_inner_race():
    gb = {"name": "cwru", "shafts": [{"name": "input"}],
          "input": {"shaft": "input", "speed_rpm": 1797},
          "bearings": [{"name": "drive_end", "shaft": "input", "rolling_elements": 9,
                        "pitch_diameter_mm": 39.04, "element_diameter_mm": 7.94,
                        "contact_angle_deg": 0.0}]}
    r = geardiag.analyze(SHARED_DATA / "cwru-bearing" / "IR007_0.mat", gearbox=gb, fs_hz=12000)
    faults = [f["fault"] for f in r["findings"] if f["kind"] == "bearing"]
    assert faults == ["inner_race"]
    # The envelope spectrum the decision read and the lines it counted (--curves' groups): the
    # inner-race family's lines seen, the x axis ending at 1.1 x the highest scored harmonic.
    ch = r["curves"]["channels"]["X105_DE_time"]
    env = ch["bearings"]["drive_end"]["decision_envelope"]
    lines = ch["bearings"]["drive_end"]["decision_lines"]
    labels = lines["attrs"]["labels"].split(";")
    seen = {lab for lab, s in zip(labels, lines["seen"]) if s == 1}
    assert {"BPFI", "2xBPFI", "3xBPFI"} <= seen
    assert env["frequency_hz"][-1] <= 1.1 * lines["expected_hz"].max() + 1e-9
    assert env["frequency_hz"][-1] > lines["expected_hz"].max()
    assert env["attrs"]["band_high_hz"] > env["attrs"]["band_low_hz"] > 0
    assert env["attrs"]["status"] == "inner_race"
    # The spectrogram: a bounded 2-D grid; its first column is scipy's spectrogram (same Hann
    # window, 256-sample segments, 50 % overlap, PSD scaling) of the first span, averaged over
    # the span's segments, in dB (1e-9 dB: round-off).
    sg = ch["spectrogram"]
    assert sg["psd_db"].shape == (sg["time_s"].size, sg["frequency_hz"].size)
    assert sg["time_s"].size == 240 and sg["frequency_hz"].size == 129
    rec = geardiag.read_recording(SHARED_DATA / "cwru-bearing" / "IR007_0.mat", fs_hz=12000)
    x = np.asarray(rec.signals["X105_DE_time"])
    span = x[: x.size // 240]
    f, t, sxx = scipy.signal.spectrogram(span, 12000, window="hann", nperseg=256, noverlap=128,
                                         detrend="constant", scaling="density", mode="psd")
    np.testing.assert_allclose(sg["frequency_hz"], f)
    np.testing.assert_allclose(sg["psd_db"][0], 10 * np.log10(sxx.mean(axis=1)), atol=1e-9)

