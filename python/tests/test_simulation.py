"""vehsim.Simulation: stepping a run from Python.

References: vehsim.run of the same spec (the engine is the same; the trajectory must be equal to
the bit), the kinematic (low-speed) limit of steady cornering, mirror symmetry, and determinism.
"""

import numpy as np
import pytest

import vehsim

DLC = "maneuvers/dlc.toml"
SINE = "maneuvers/sine_steer.toml"

# Observation columns that are functions of the state alone: equal to the run's rows to the bit.
TRAJECTORY = [
    "t_s",
    "x_m",
    "y_m",
    "yaw_rad",
    "vx_mps",
    "vy_mps",
    "yaw_rate_radps",
    "sideslip_rad",
    "kappa_front",
    "kappa_rear",
    "omega_front_radps",
    "omega_rear_radps",
    "roll_rad",
    "fz_fl_n",
    "fz_fr_n",
    "fz_rl_n",
    "fz_rr_n",
]


@pytest.fixture(autouse=True)
def _in_root(root, monkeypatch):
    monkeypatch.chdir(root)


def stepped(sim, every):
    """Observations at the run's recorded instants (every `every` steps) up to the run's end."""
    rows = [sim.reset()]
    while not sim.done:
        rows.append(sim.step(n=every))
    return np.array(rows)


@pytest.mark.parametrize("spec", [DLC, "maneuvers/dlc_roll4dof.toml", "maneuvers/quickstart_dlc_ice.toml"])
def test_a_lane_change_stepped_with_the_specs_driver_equals_run(spec):
    r = vehsim.run(spec)
    sim = vehsim.Simulation(spec)
    every = round((r["t_s"][1] - r["t_s"][0]) / sim.step_s)
    obs = stepped(sim, every)
    assert sim.end_reason == r.summary["end_reason"] == "completed"
    assert sim.cones_hit == r.summary["cones_hit"] and sim.passed == r.summary["passed"]
    assert r["t_s"][-1] > 10.0  # a lane change of more than 10 s of simulated time
    # the run records its last row at the end of the last step; so does the stepped run
    assert obs.shape[0] == len(r["t_s"])
    for name in TRAJECTORY:
        i = vehsim.OBSERVATION.index(name)
        np.testing.assert_array_equal(obs[:, i], r[name], err_msg=name)
    assert sim.steps == r.summary["steps"]


def test_observation_names_and_structured_view():
    sim = vehsim.Simulation(DLC)
    assert vehsim.OBSERVATION == vehsim.TIMESERIES_COLUMNS
    v = sim.step()
    o = sim.observation
    assert o.dtype.names == tuple(vehsim.OBSERVATION)
    assert o["t_s"] == sim.t_s == sim.step_s
    assert o["vx_mps"] == v[vehsim.OBSERVATION.index("vx_mps")]
    assert sim.state.shape == (len(sim.state_names),)


def test_reset_repeats_the_run_exactly():
    sim = vehsim.Simulation(DLC, external="steer")
    sim.reset(seed=3)
    a = [sim.step([0.02 * np.sin(k / 30.0)]) for k in range(300)]
    sim.reset(seed=4)
    b = [sim.step([0.02 * np.sin(k / 30.0)]) for k in range(300)]
    np.testing.assert_array_equal(np.array(a), np.array(b))
    assert sim.seed == 4


def test_external_steer_mirrors_and_reaches_the_kinematic_limit_at_low_speed():
    # At 3 m/s on a linear tyre the slip angles are tiny: the steady yaw rate tends to V delta / L.
    delta = 0.03
    rates = []
    for sign in (1.0, -1.0):
        sim = vehsim.Simulation(SINE, external="steer", maneuver__speed_mps=3.0, duration_s=20.0)
        sim.step([sign * delta])
        last = sim.run()
        rates.append(last)
    i = vehsim.OBSERVATION.index
    left, right = rates
    np.testing.assert_allclose(right[i("yaw_rate_radps")], -left[i("yaw_rate_radps")], rtol=0, atol=1e-12)
    np.testing.assert_allclose(right[i("y_m")], -left[i("y_m")], rtol=0, atol=1e-9)
    v = left[i("vx_mps")]
    kinematic = v * delta / vehsim.Simulation(SINE).wheelbase_m
    assert left[i("yaw_rate_radps")] == pytest.approx(kinematic, rel=0.02)
    assert left[i("steer_rad")] == delta


def test_external_torque_accelerates_and_brakes():
    sim = vehsim.Simulation(SINE, external="torque")
    i = vehsim.OBSERVATION.index
    v0 = sim.reset()[i("vx_mps")]
    up = sim.step({"drive_torque_nm": 400.0}, n=100)
    assert up[i("vx_mps")] > v0 and up[i("drive_torque_nm")] == 400.0 and up[i("brake_torque_nm")] == 0.0
    down = sim.step({"drive_torque_nm": 0.0, "brake_torque_nm": 1500.0}, n=100)
    assert down[i("vx_mps")] < up[i("vx_mps")]
    assert sim.inputs == {"drive_torque_nm": 0.0, "brake_torque_nm": 1500.0}


@pytest.mark.parametrize(
    "inputs, match",
    [
        ([0.0, 0.0], r"expected 3 values \(steer_rad, drive_torque_nm, brake_torque_nm\), got shape \(2,\)"),
        ([[0.0, 0.0, 0.0]], r"got shape \(1, 3\)"),
        ([np.nan, 0.0, 0.0], r"steer_rad = NaN is not allowed; expected a finite number in \[-0\.61, 0\.61\] rad"),
        ([0.7, 0.0, 0.0], r"steer_rad = 0\.7 is not allowed"),
        ([0.0, -1.0, 0.0], r"drive_torque_nm = -1 is not allowed; expected a finite number in \[0, 3500\] N m"),
        ([0.0, 0.0, 1e300], r"brake_torque_nm = 1e300 is not allowed"),
        ({"steer": 0.1}, r"'steer' is not an external input"),
        ({"steer_rad": None}, r"steer_rad = None is not a number"),
        ("0.1", r"got a str"),
    ],
)
def test_bad_inputs_raise_value_error_and_change_nothing(inputs, match):
    sim = vehsim.Simulation(DLC, external=["steer", "torque"])
    sim.step([0.01, 10.0, 0.0])
    before = sim.inputs
    with pytest.raises(ValueError, match=match):
        sim.step(inputs)
    assert sim.inputs == before and sim.steps == 1


def test_misuse_raises_clear_errors():
    sim = vehsim.Simulation(DLC)
    with pytest.raises(ValueError, match="not an external input of this simulation; allowed: none"):
        sim.step({"steer_rad": 0.1})
    with pytest.raises(ValueError, match="unknown channel 'brake'"):
        vehsim.Simulation(DLC, external="brake")
    with pytest.raises(ValueError, match="use vehsim.sweep|a Simulation steps one run"):
        vehsim.Simulation("maneuvers/dlc_sweep.toml")
    with pytest.raises(ValueError, match=r"n: 0 is not allowed"):
        sim.step(n=0)
    sim.run()
    assert sim.done and sim.end_reason == "completed"
    with pytest.raises(RuntimeError, match=r"the simulation has ended \(completed at t = .* call reset\(\)"):
        sim.step()
    sim.reset()
    assert not sim.done and sim.t_s == 0.0


def test_a_spin_out_ends_the_run_with_its_event():
    # power oversteer: steer and 1000 N m at the rear wheels of the RWD sedan on ice at 10 m/s
    sim = vehsim.Simulation(SINE, external=["steer", "torque"], tyre_model="pacejka", vehicle="../vehicles/sedan_rwd.toml")
    sim.step([0.1, 1000.0, 0.0])
    sim.run()
    assert sim.end_reason == "spin_out"
    assert any(e["kind"] == "spin_out" for e in sim.events)


def test_a_steer_rate_ramps_the_angle_and_stops_at_the_lock():
    sim = vehsim.Simulation(SINE, external="steer_rate", maneuver__speed_mps=3.0)
    assert sim.input_names == ["steer_rate_radps"]
    i = vehsim.OBSERVATION.index
    rate = 0.2
    o = sim.step([rate], n=50)
    t1 = sim.t_s
    assert o[i("steer_rad")] == pytest.approx(rate * t1, abs=1e-15)
    o = sim.step([-rate], n=25)  # back down from where it was: continuous
    assert o[i("steer_rad")] == pytest.approx(rate * t1 - rate * (sim.t_s - t1), abs=1e-15)
    lock = sim.limits["steer_max_rad"]
    o = sim.step([sim.limits["steer_rate_max_radps"]], n=round(2 * lock / sim.limits["steer_rate_max_radps"] / sim.step_s))
    assert o[i("steer_rad")] == lock
    with pytest.raises(ValueError, match=r"steer_rate_radps = .* is not allowed; expected a finite number in \[.*\] rad/s"):
        sim.step([1.5 * sim.limits["steer_rate_max_radps"]])
    with pytest.raises(ValueError, match="'steer' and 'steer_rate' exclude each other"):
        vehsim.Simulation(SINE, external=["steer", "steer_rate"])
