"""Shared fixtures: one short simulated recording of the three-shaft box (written once per run),
the CLI's outputs on it, and the paths of the checkout."""
import json
import os
import pathlib
import subprocess

import pytest

import geardiag

SOURCE = pathlib.Path(os.environ.get("GEARDIAG_SOURCE_DIR",
                                     pathlib.Path(__file__).resolve().parents[2]))
EXE = os.environ.get("GEARDIAG_EXE", str(SOURCE / "build" / "geardiag"))
# The measured data and the test data: GEARDIAG_SHARED_DATA and GEARDIAG_TESTDATA when set (as
# for the C++ tests), else the checkout's.
SHARED_DATA = pathlib.Path(os.environ.get("GEARDIAG_SHARED_DATA")
                           or SOURCE / ".." / "shared" / "data")
TESTDATA = pathlib.Path(os.environ.get("GEARDIAG_TESTDATA") or SOURCE / "testdata")
THREE_SHAFT = TESTDATA / "gearbox" / "three_shaft.json"

# A faster box than the file's 30 rpm (the attribution demo's speed): 1500 rpm gives 25 input
# revolutions in 1 s: the TSA of the input and counter shafts (the output turns 6 times: its TSA
# is skipped with a note, as analyze does).
SIM_GEARBOX = dict(json.loads(THREE_SHAFT.read_text()),
                   input={"shaft": "input", "speed_rpm": 1500.0, "torque_nm": 50.0})
SIM_SCENARIO = {"duration_s": 1.0, "fs_hz": 10000.0, "sensors": {"noise_m_per_s2": 0.5},
                "faults": [{"gear": "z2", "tooth": 7, "type": "crack", "depth_mm": 1.5}]}


@pytest.fixture(scope="session")
def sim_recording():
    return geardiag.simulate(geardiag.Gearbox.from_json(SIM_GEARBOX), SIM_SCENARIO, seed=7)


@pytest.fixture(scope="session")
def sim_file(tmp_path_factory, sim_recording):
    path = tmp_path_factory.mktemp("sim") / "sim.h5"
    geardiag.write_recording(path, sim_recording)
    return path


@pytest.fixture(scope="session")
def cli_outputs(sim_file):
    """`geardiag analyze --json --curves --html` on the simulated file."""
    d = sim_file.parent
    out = {"json": d / "report.json", "curves": d / "curves.h5", "html": d / "report.html"}
    subprocess.run([EXE, "analyze", str(sim_file), "--json", str(out["json"]), "--curves",
                    str(out["curves"]), "--html", str(out["html"])], check=True,
                   stdout=subprocess.DEVNULL)
    return out
