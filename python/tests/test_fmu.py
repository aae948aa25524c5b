"""The FMI 2.0 co-simulation FMU (fmu/, built by `bash fmu/build.sh` into target/vehsim.fmu),
checked by a real importer, FMPy: its validation, a simulation equal to `vehsim run` of the same
spec, external inputs equal to vehsim.Simulation's, and bad parameters and inputs answered with
an FMI error status and a logged message (the host process carries on).

python/test.sh builds the FMU and sets VEHSIM_FMU (and VEHSIM_REQUIRE_CLI=1: a missing FMU then
fails instead of skipping).
"""

import csv
import ctypes
import os
from pathlib import Path

import numpy as np
import pytest

import vehsim

fmpy = pytest.importorskip("fmpy")
from fmpy.validation import validate_fmu  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
FMU = Path(os.environ.get("VEHSIM_FMU", ROOT / "target" / "vehsim.fmu"))
STATE = ["x_m", "y_m", "yaw_rad", "vx_mps", "vy_mps", "yaw_rate_radps", "omega_front_radps", "omega_rear_radps"]


@pytest.fixture(scope="module")
def fmu():
    if not FMU.is_file():
        msg = f"{FMU} is not built (bash fmu/build.sh); set VEHSIM_FMU to use another"
        if os.environ.get("VEHSIM_REQUIRE_CLI") == "1":
            pytest.fail(msg)
        pytest.skip(msg)
    return str(FMU)


@pytest.fixture(autouse=True)
def _in_root(root, monkeypatch):
    monkeypatch.chdir(root)


class Log:
    """An FMPy logger that keeps the FMU's messages."""

    def __init__(self):
        self.lines = []

    def __call__(self, env, instance, status, category, message):
        self.lines.append((status, category.decode(), message.decode()))

    def text(self):
        return "\n".join(m for _, _, m in self.lines)


def test_fmpy_validates_the_fmu(fmu):
    assert validate_fmu(fmu) == []
    md = fmpy.read_model_description(fmu)
    assert md.fmiVersion == "2.0" and md.coSimulation.modelIdentifier == "vehsim"
    names = {v.name: v for v in md.modelVariables}
    assert names["steer_cmd_rad"].causality == "input" and names["mu"].causality == "parameter"
    outputs = [v.name for v in md.modelVariables if v.causality == "output"]
    assert outputs == vehsim.OBSERVATION[1:]


def test_a_sine_steer_through_fmpy_equals_vehsim_run(fmu, cli, tmp_path):
    cli("run", "maneuvers/sine_steer.toml", "--out", tmp_path, "--quiet")
    with open(tmp_path / "sine_steer_ice" / "timeseries.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    r = fmpy.simulate_fmu(fmu, start_values={"external_steer": False}, stop_time=10.0, output_interval=0.01)
    assert len(r) == len(rows)
    np.testing.assert_allclose(r["time"], [float(x["t_s"]) for x in rows], rtol=0, atol=1e-12)
    for name in STATE:
        ref = np.array([float(x[name]) for x in rows])
        np.testing.assert_allclose(r[name], ref, rtol=0, atol=1e-9, err_msg=name)
    # the steer is the spec's sine: 10 deg amplitude at the road wheel, 10 s period
    assert np.max(np.abs(r["steer_rad"])) == pytest.approx(np.radians(10.0), rel=1e-3)


def test_the_fmu_with_parameters_equals_vehsim_run_with_the_same_overrides(fmu):
    r = fmpy.simulate_fmu(
        fmu,
        start_values={
            "external_steer": False,
            "spec": "maneuvers/dlc.toml",
            "tyre_model": "pacejka",
            "mu": 0.2,
            "surface_temperature_c": -8.0,
        },
        stop_time=8.0,
        output_interval=0.05,
    )
    ref = vehsim.run("maneuvers/dlc.toml", tyre_model="pacejka", surface__mu=0.2, surface__temperature_c=-8.0)
    t = ref["t_s"]
    for k, tk in enumerate(r["time"]):
        j = int(np.argmin(np.abs(t - tk)))
        assert t[j] == pytest.approx(tk, abs=1e-9)
        for name in ("x_m", "y_m", "yaw_rate_radps"):
            assert abs(r[name][k] - ref[name][j]) <= 1e-9, (name, tk)


def test_external_inputs_through_fmpy_equal_vehsim_simulation(fmu):
    dt = 0.02
    times = np.arange(0.0, 6.0 + dt / 2, dt)
    steer = 0.03 * np.sin(2 * np.pi * times / 3.0)
    signals = np.array(
        list(zip(times, steer, np.full_like(times, 200.0))),
        dtype=[("time", np.float64), ("steer_cmd_rad", np.float64), ("drive_torque_cmd_nm", np.float64)],
    )
    r = fmpy.simulate_fmu(
        fmu,
        start_values={"external_steer": True, "external_torque": True},
        input=signals,
        stop_time=6.0,
        output_interval=dt,
    )
    sim = vehsim.Simulation("maneuvers/sine_steer.toml", external=["steer", "torque"])
    n = round(dt / sim.step_s)
    i = vehsim.OBSERVATION.index
    for k in range(len(times) - 1):
        o = sim.step([steer[k], 200.0, 0.0], n=n)
        for name in ("x_m", "y_m", "yaw_rate_radps", "vx_mps"):
            assert abs(r[name][k + 1] - o[i(name)]) <= 1e-9, (name, times[k + 1])
    assert np.max(np.abs(r["yaw_rate_radps"])) > 0.01  # the input steered the car


def test_a_run_that_ends_early_is_discarded_and_terminated(fmu):
    # the lane change completes at about 11 s: FMPy stops there (fmi2Discard + fmi2Terminated)
    log = Log()
    r = fmpy.simulate_fmu(
        fmu,
        start_values={"external_steer": False, "spec": "maneuvers/dlc.toml"},
        stop_time=20.0,
        output_interval=0.1,
        logger=log,
        debug_logging=True,
    )
    assert 10.0 < r["time"][-1] < 12.0
    assert "the run ended (completed)" in log.text()


@pytest.mark.parametrize(
    "start, message",
    [
        ({"spec": "nope.toml"}, r"nope\.toml: file not found"),
        ({"vehicle": "/nonexistent/car.toml"}, r"car\.toml"),
        ({"mu": -1.0}, r"surface\.mu"),
        ({"tyre_model": "magic"}, r"magic"),
        ({"spec": "maneuvers/dlc_sweep.toml"}, r"drop \[sweep\]"),
        ({"steer_cmd_rad": 2.0}, r"steer_rad = 2 is not allowed; expected a finite number in \[-0\.61, 0\.61\] rad"),
        ({"external_torque": True, "brake_torque_cmd_nm": float("nan")}, r"brake_torque_nm = NaN is not allowed"),
    ],
)
def test_bad_parameters_and_inputs_are_fmi_errors_with_a_message(fmu, start, message):
    log = Log()
    with pytest.raises(Exception) as e:
        fmpy.simulate_fmu(fmu, start_values=start, stop_time=1.0, output_interval=0.01, logger=log)
    assert "fmi2Error" in str(e.value) or "status 3" in str(e.value) or e.type.__name__ == "FMICallException"
    assert any(status == 3 for status, _, _ in log.lines)
    import re

    assert re.search(message, log.text()), log.text()


def test_the_c_functions_refuse_bad_calls_without_crashing(fmu, tmp_path):
    folder = fmpy.extract(fmu, str(tmp_path / "fmu"))
    lib = ctypes.CDLL(os.path.join(folder, "binaries", "linux64", "vehsim.so"))
    lib.fmi2Instantiate.restype = ctypes.c_void_p
    lib.fmi2Instantiate.argtypes = [ctypes.c_char_p, ctypes.c_int, ctypes.c_char_p, ctypes.c_char_p, ctypes.c_void_p, ctypes.c_int, ctypes.c_int]
    guid = fmpy.read_model_description(fmu).guid.encode()
    resources = ("file://" + os.path.join(folder, "resources")).encode()
    assert lib.fmi2Instantiate(b"x", 1, b"{wrong}", resources, None, 0, 0) is None
    assert lib.fmi2Instantiate(b"x", 0, guid, resources, None, 0, 0) is None  # model exchange
    c = lib.fmi2Instantiate(b"x", 1, guid, resources, None, 0, 0)
    assert c
    c = ctypes.c_void_p(c)
    lib.fmi2DoStep.argtypes = [ctypes.c_void_p, ctypes.c_double, ctypes.c_double, ctypes.c_int]
    assert lib.fmi2DoStep(None, 0.0, 0.01, 1) == 3  # null instance
    assert lib.fmi2DoStep(c, 0.0, 0.01, 1) == 3  # before initialization
    assert lib.fmi2ExitInitializationMode(c) == 3  # not in initialization mode
    assert lib.fmi2EnterInitializationMode(c) == 0 and lib.fmi2ExitInitializationMode(c) == 0
    assert lib.fmi2DoStep(c, 0.0, float("nan"), 1) == 3
    assert lib.fmi2DoStep(c, 0.0, 0.01, 1) == 0
    lib.fmi2GetReal.argtypes = [ctypes.c_void_p, ctypes.c_void_p, ctypes.c_size_t, ctypes.c_void_p]
    assert lib.fmi2GetReal(c, None, 3, None) == 3  # null arrays
    vr = (ctypes.c_uint * 2)(10, 999)
    out = (ctypes.c_double * 2)()
    assert lib.fmi2GetReal(c, vr, 2, out) == 3  # unknown value reference
    lib.fmi2GetFMUstate.argtypes = [ctypes.c_void_p, ctypes.c_void_p]
    assert lib.fmi2GetFMUstate(c, None) == 3  # not supported
    lib.fmi2FreeInstance.argtypes = [ctypes.c_void_p]
    lib.fmi2FreeInstance(c)
    lib.fmi2FreeInstance(None)
