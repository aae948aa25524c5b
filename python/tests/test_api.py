"""API-level tests of the vehsim Python package: run, sweep, tyre arrays, ATIIM, discover, bad input.

References are independent of the package: the command line's own files (summary.json,
timeseries.csv, the tyre-curve and drawbar CSVs) for the same inputs, closed forms (the linear
tyre), symmetries (mirrored steering) and conservation (the pressure map integrates to the load).
"""

import csv
import json
import math
import threading
import time
from pathlib import Path

import numpy as np
import pytest

import vehsim

SINE = "maneuvers/sine_steer.toml"
TYRE_FILE = "vehicles/tyres/srtt_p225_60r16.toml"
SCENARIO = "scenarios/atiim/srtt_4kN_free_rolling.toml"


@pytest.fixture(autouse=True)
def _in_root(root, monkeypatch):
    monkeypatch.chdir(root)


def read_csv(path: Path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


# ---------------------------------------------------------------------------------------------
# run


def test_run_matches_the_command_line_to_the_bit(cli, tmp_path):
    cli("run", SINE, "--out", tmp_path, "--quiet")
    folder = tmp_path / "sine_steer_ice"
    r = vehsim.run(SINE)
    ref = json.loads((folder / "summary.json").read_text())
    assert r.summary == ref
    rows = read_csv(folder / "timeseries.csv")
    assert list(rows[0].keys()) == vehsim.TIMESERIES_COLUMNS == list(r.timeseries)
    for name in vehsim.TIMESERIES_COLUMNS:
        want = np.array([float(row[name]) if row[name] != "" else np.nan for row in rows])
        got = r[name]
        assert got.dtype == np.float64 and got.shape == want.shape
        np.testing.assert_array_equal(got, want, err_msg=name)
    assert r.status == "ok" and not r.failed


def test_run_mirrored_steering_mirrors_the_response():
    left = vehsim.run(SINE)
    right = vehsim.run(SINE, maneuver__steer_amplitude_deg=-10.0)
    np.testing.assert_allclose(right["yaw_rate_radps"], -left["yaw_rate_radps"], rtol=0, atol=1e-12)
    np.testing.assert_allclose(right["y_m"], -left["y_m"], rtol=0, atol=1e-9)
    np.testing.assert_allclose(right["vx_mps"], left["vx_mps"], rtol=0, atol=1e-12)
    assert right.summary["peak_yaw_rate_radps"] == pytest.approx(left.summary["peak_yaw_rate_radps"], abs=1e-12)


def test_run_logs_the_sensors_of_the_vehicle(root, tmp_path):
    # a vehicle with [sensors] (as `vehsim discover` writes it): the run also returns the logged
    # channels, as the command line's timeseries.csv does; without latency and mounting offset
    # they are the true ones plus the biases
    text = (root / "vehicles/sedan.toml").read_text()
    tyre = (root / "vehicles/tyres/srtt_p225_60r16.toml").as_posix()
    text = text.replace('tyre = "tyres/srtt_p225_60r16.toml"', f'tyre = "{tyre}"')
    vehicle = tmp_path / "instrumented.toml"
    vehicle.write_text(text + "\n[sensors]\nbias_yaw_rate_radps = 0.01\nbias_ay_mps2 = -0.2\n")
    plain = vehsim.run(SINE)
    r = vehsim.run(SINE, vehicle=str(vehicle))
    assert "yaw_rate_meas_radps" not in plain.timeseries
    np.testing.assert_array_equal(r["yaw_rate_radps"], plain["yaw_rate_radps"])
    np.testing.assert_allclose(r["yaw_rate_meas_radps"], r["yaw_rate_radps"] + 0.01, rtol=0, atol=1e-15)
    np.testing.assert_allclose(r["ay_meas_mps2"], r["ay_mps2"] - 0.2, rtol=0, atol=1e-14)


def test_run_lateral_acceleration_stays_within_the_friction_limit():
    # the SRTT Magic Formula peaks at 1.2 x the surface mu (the tyre file's LMUY scaling), so on
    # mu 0.15 the car cannot corner harder than 0.18 g; the unsaturated linear tyre can
    r = vehsim.run(SINE, tyre_model="pacejka")
    limit = 1.2 * 0.15 * 9.81
    assert 0.5 * limit < r.summary["peak_ay_mps2"] <= 1.02 * limit
    assert np.nanmax(np.abs(r["ay_mps2"])) == pytest.approx(r.summary["peak_ay_mps2"], rel=0.02)
    assert vehsim.run(SINE).summary["peak_ay_mps2"] > 2 * limit


def test_run_overrides_and_dict_spec_agree_with_the_file(root):
    a = vehsim.run(SINE, surface__mu=np.float64(0.3), **{"maneuver.period_s": 5.0})
    spec = {
        "name": "sine_steer_ice",
        "vehicle": str(root / "vehicles" / "sedan.toml"),
        "tyre_model": "linear",
        "duration_s": 10.0,
        "surface": {"mu": 0.3, "temperature_c": -3.0},
        "maneuver": {"kind": "sine_steer", "speed_mps": 10.0, "steer_amplitude_deg": 10, "period_s": 5.0},
    }
    b = vehsim.run(spec)
    assert a.summary["mu"] == b.summary["mu"] == 0.3
    for name in ("t_s", "yaw_rate_radps", "ay_mps2", "steer_rad"):
        np.testing.assert_array_equal(a[name], b[name])
    base = vehsim.run(SINE)
    assert not np.array_equal(a["yaw_rate_radps"], base["yaw_rate_radps"])


def test_run_to_pandas():
    pd = pytest.importorskip("pandas", reason="pandas is not installed; RunResult.to_pandas is optional")
    r = vehsim.run(SINE)
    df = r.to_pandas()
    assert isinstance(df, pd.DataFrame) and df.index.name == "t_s"
    np.testing.assert_array_equal(df["yaw_rate_radps"].to_numpy(), r["yaw_rate_radps"])


# ---------------------------------------------------------------------------------------------
# sweep

GRID = {"surface.mu": [0.1, 0.3], "maneuver.speed_mps": [8.0, 10.0, 12.0]}


def test_sweep_order_threads_and_single_runs_agree():
    one = vehsim.sweep(SINE, GRID, jobs=1)
    two = vehsim.sweep(SINE, GRID, jobs=2, timeseries=True)
    assert [r["index"] for r in one] == list(range(6))
    # the last key varies fastest
    assert [(r["params"]["surface.mu"], r["params"]["maneuver.speed_mps"]) for r in one] == [
        ("0.1", "8.0"), ("0.1", "10.0"), ("0.1", "12.0"), ("0.3", "8.0"), ("0.3", "10.0"), ("0.3", "12.0")
    ]
    assert [r["summary"] for r in one] == [r["summary"] for r in two]
    assert all(r["status"] == "ok" and r["result"] is None for r in one)
    single = vehsim.run(SINE, surface__mu=0.3, maneuver__speed_mps=12.0)
    assert two[5]["summary"]["params"] == {"surface.mu": "0.3", "maneuver.speed_mps": "12.0"}
    assert {**two[5]["summary"], "params": {}} == single.summary
    np.testing.assert_array_equal(two[5]["result"]["yaw_rate_radps"], single["yaw_rate_radps"])


def test_sweep_summaries_match_the_command_line(cli, tmp_path):
    cli("run", "maneuvers/dlc_sweep.toml", "--out", tmp_path, "--quiet")
    res = vehsim.sweep("maneuvers/dlc_sweep.toml", jobs=2)
    assert len(res) == 6
    for r in res:
        ref = json.loads((tmp_path / "dlc_sweep" / f"run_{r['index']:04d}" / "summary.json").read_text())
        assert r["summary"] == ref


def test_sweep_keeps_invalid_combinations_and_refuses_all_invalid():
    res = vehsim.sweep(SINE, {"surface.mu": [0.15, -1.0]})
    assert [r["status"] for r in res] == ["ok", "invalid"]
    assert "surface.mu" in res[1]["message"] and res[1]["summary"] is None
    with pytest.raises(ValueError, match="jobs"):
        vehsim.sweep(SINE, {"surface.mu": [0.15]}, jobs=0)
    np_grid = vehsim.sweep(SINE, {"surface.mu": np.array([0.15, 0.3])})
    assert [r["params"]["surface.mu"] for r in np_grid] == ["0.15", "0.3"]
    with pytest.raises(ValueError, match="every sweep combination is invalid"):
        vehsim.sweep(SINE, {"surface.mu": [-1.0, 5.0]})
    pd = pytest.importorskip("pandas", reason="pandas is not installed; SweepResult.to_pandas is optional")
    df = res.to_pandas()
    assert list(df["status"]) == ["ok", "invalid"] and isinstance(df, pd.DataFrame)


def test_sweep_releases_the_gil():
    """While a sweep runs in another thread, this thread keeps running Python code."""
    # 64 runs: long enough (about 1 s) to tell, however fast the engine gets within reason
    grid = {
        "surface.mu": [0.1, 0.125, 0.15, 0.175, 0.2, 0.25, 0.3, 0.35],
        "maneuver.speed_mps": [7.0, 7.5, 8.0, 8.5, 9.0, 10.0, 11.0, 12.0],
    }
    done = threading.Event()
    t0 = time.perf_counter()
    worker = threading.Thread(target=lambda: (vehsim.sweep(SINE, grid, jobs=1, duration_s=120.0), done.set()))
    worker.start()
    ticks, last, gap = 0, time.perf_counter(), 0.0
    while not done.is_set():
        now = time.perf_counter()
        gap, last, ticks = max(gap, now - last), now, ticks + 1
    worker.join()
    elapsed = time.perf_counter() - t0
    assert elapsed > 0.2, "the sweep is too short to tell"
    # holding the GIL would stall this loop for (nearly) the whole sweep
    assert gap < 0.5 * elapsed, (gap, elapsed)
    assert ticks > 100


def test_run_refuses_a_sweep_spec():
    with pytest.raises(ValueError, match="use vehsim.sweep"):
        vehsim.run("maneuvers/dlc_sweep.toml")


# ---------------------------------------------------------------------------------------------
# tyre


def test_tyre_arrays_match_the_command_line_curves(cli, tmp_path):
    cli("tyre", "scenarios/tyre/tyre_curves.toml", "--out", tmp_path)
    folder = tmp_path / "tyre_curves"
    tyres = {}
    checked = 0
    for fname, slip in (("fx_vs_slip_ratio.csv", "kappa"), ("fy_vs_slip_angle.csv", "alpha_rad")):
        rows = read_csv(folder / fname)
        groups = {}
        for row in rows:
            groups.setdefault((row["provider"], row["fz_n"], row["delta_t_k"], row["mu_surface"]), []).append(row)
        for (provider, fz, dt, mu), g in groups.items():
            t = tyres.setdefault(provider, vehsim.Tyre.from_file(TYRE_FILE, provider))
            s = np.array([float(r[slip]) for r in g])
            zero = np.zeros_like(s)
            kappa, alpha = (s, zero) if slip == "kappa" else (zero, s)
            f = t.forces(float(fz), kappa, alpha, mu=float(mu), surface_temp=-3.0, contact_temp=-3.0 + float(dt))
            for col, got in (("fx_n", f.fx), ("fy_n", f.fy), ("mz_nm", f.mz)):
                np.testing.assert_array_equal(got, [float(r[col]) for r in g], err_msg=f"{provider} {dt} {col}")
            checked += 1
    assert checked >= 2 * 5


def test_linear_tyre_closed_form_and_broadcasting():
    t = vehsim.Tyre.from_file(TYRE_FILE, "linear")
    fz = np.array([[1000.0], [4000.0], [6000.0]])
    alpha = np.linspace(-0.1, 0.1, 5)[None, :]
    f = t.forces(fz, 0.0, alpha, mu=0.15)
    assert f.fy.shape == (3, 5)
    # the file's [linear] section: C = 69000 N/rad at the nominal load, load exponent 0.8
    want = 69000.0 * (fz / t.nominal_load_n) ** 0.8 * alpha
    np.testing.assert_allclose(f.fy, want, rtol=1e-12, atol=1e-9)
    np.testing.assert_array_equal(f.fx, 0.0)
    # element by element the same as scalar calls
    assert f.fy[1, 3] == t.forces(4000.0, 0.0, float(alpha[0, 3]), mu=0.15).fy


@pytest.mark.parametrize("provider", vehsim.TYRE_MODELS)
def test_every_provider_zero_force_at_zero_load_and_bounded(provider):
    t = vehsim.Tyre.from_file(TYRE_FILE, provider)
    assert t.provider == provider
    kappa = np.linspace(-0.5, 0.5, 11)
    f0 = t.forces(0.0, kappa, 0.05, mu=0.15, contact_temp=0.0)
    np.testing.assert_array_equal(f0.fx, 0.0)
    np.testing.assert_array_equal(f0.fy, 0.0)
    f = t.forces(4000.0, kappa, 0.05, mu=0.15)
    assert np.all(np.isfinite(f.fx)) and np.all(np.isfinite(f.fy))
    if provider != "linear":  # the file's linear tyre is unsaturated (no friction limit)
        # on mu 0.15 ice every saturating provider stays far below 0.5 Fz
        assert np.all(np.hypot(f.fx, f.fy) < 0.5 * 4000.0)


def test_thermal_provider_loses_grip_with_contact_temperature():
    t = vehsim.Tyre.from_file(TYRE_FILE, "atiim_pacejka")
    rise = np.array([0.0, 2.0, 4.0])
    f = t.forces(4000.0, 0.1, 0.0, mu=0.15, surface_temp=-3.0, contact_temp=-3.0 + rise)
    assert f.fx[0] > f.fx[1] > f.fx[2] > 0


# ---------------------------------------------------------------------------------------------
# ATIIM patch


def test_atiim_matches_the_command_line(cli, tmp_path):
    cli("atiim", SCENARIO, "--out", tmp_path)
    folder = tmp_path / "srtt_4kN_free_rolling"
    ref = json.loads((folder / "summary.json").read_text())
    d = vehsim.atiim(SCENARIO)
    assert d["summary"] == ref["summary"]
    p = d["maps"]["pressure_pa"]
    assert p.shape == (ref["grid"]["rows"], ref["grid"]["cols"])
    # conservation: the pressure map carries the load
    load = p.sum() * d["pixel_length_m"] * d["pixel_width_m"]
    assert load == pytest.approx(d["summary"]["load_n"], rel=1e-12)
    assert d["maps"]["rise_k"].max() == pytest.approx(d["summary"]["max_rise_k"], rel=1e-12)
    rows = read_csv(folder / "drawbar.csv")
    np.testing.assert_allclose(d["drawbar"]["drawbar_coeff"], [float(r["drawbar_coeff"]) for r in rows], atol=5e-6)
    np.testing.assert_allclose(d["drawbar"]["slip_ratio"], [float(r["slip_ratio"]) for r in rows], atol=5e-5)


def test_atiim_overrides_change_the_operating_point():
    locked = vehsim.atiim(SCENARIO, operating__slip_ratio=-1.0)
    assert locked["operating"]["roll_speed_mps"] == 0.0
    assert locked["summary"]["max_rise_k"] > vehsim.atiim(SCENARIO)["summary"]["max_rise_k"]


# ---------------------------------------------------------------------------------------------
# discover


def test_discover_names_the_hidden_effect(cli, tmp_path):
    cli("synth", "--effect", "tyre_relaxation", "--out", tmp_path / "runs")
    runs = sorted((tmp_path / "runs").glob("0[1-4]_*.csv"))
    assert len(runs) == 4
    report = vehsim.discover("vehicles/sedan.toml", runs, out=tmp_path / "out")
    assert report["verdict"] == "explained", report["verdict"]
    assert report["named_effects"][0].startswith("tyre_relaxation")
    (p,) = report["steps"][0]["params"]
    assert p["name"] == "relaxation_length_y_m" and p["value"] == pytest.approx(1.2, rel=0.1)
    assert report["final_rmse"]["heldout"]["yaw_rate_radps"] < report["baseline_rmse"]["heldout"]["yaw_rate_radps"]
    assert json.loads((tmp_path / "out" / "report.json").read_text())["verdict"] == report["verdict"]
    assert isinstance(report["notices"], list)


# ---------------------------------------------------------------------------------------------
# bad input: exceptions with the command line's messages, never a crash


def test_bad_spec_values_raise_value_error_naming_the_key():
    with pytest.raises(ValueError, match=r"sine_steer\.toml: .*surface\.mu.*-1"):
        vehsim.run(SINE, surface__mu=-1.0)
    with pytest.raises(ValueError, match="unknown field"):
        vehsim.run(SINE, surface__friction=0.2)
    with pytest.raises(ValueError, match="<spec dict>"):
        vehsim.run({"name": "x"})
    with pytest.raises(ValueError, match="has no spec form"):
        vehsim.run(SINE, surface__mu=object())
    with pytest.raises(TypeError):
        vehsim.run(42)


def test_missing_files_raise_os_errors():
    with pytest.raises(FileNotFoundError, match="nope.toml: file not found"):
        vehsim.run("nope.toml")
    with pytest.raises(OSError):
        vehsim.Tyre.from_file("nope.toml", "linear")
    # a file named inside a spec is the spec's fault: bad input
    with pytest.raises(ValueError, match="file not found"):
        vehsim.run(SINE, vehicle="missing_vehicle.toml")


def test_io_failure_is_an_os_error(tmp_path, cli):
    cli("synth", "--effect", "none", "--out", tmp_path / "runs")
    blocker = tmp_path / "file"
    blocker.write_text("not a folder")
    runs = sorted((tmp_path / "runs").glob("0[1-2]_*.csv"))
    with pytest.raises(OSError):
        vehsim.discover("vehicles/sedan.toml", runs, out=blocker / "out")


def test_bad_tyre_input():
    with pytest.raises(ValueError, match="unknown tyre model 'magic'.*allowed: linear"):
        vehsim.Tyre.from_file(TYRE_FILE, "magic")
    t = vehsim.Tyre.from_file(TYRE_FILE, "pacejka")
    kappa = np.zeros(10)
    kappa[7] = math.nan
    with pytest.raises(ValueError, match=r"key 'kappa\[7\]'.*NaN.*\[-1, 10\]"):
        t.forces(4000.0, kappa, 0.0)
    with pytest.raises(ValueError, match=r"fz\[0\]"):
        t.forces(-1.0, 0.0, 0.0)
    with pytest.raises(ValueError, match=r"alpha\[1\]"):
        t.forces(4000.0, 0.0, [0.0, 2.0])
    with pytest.raises(ValueError, match="broadcast"):
        t.forces(np.ones(3), np.ones(4), 0.0)


def test_bad_atiim_input():
    with pytest.raises(ValueError, match=r"srtt_4kN_free_rolling\.toml: key 'operating\.slip_ratio'.*\[-1, 2\]"):
        vehsim.atiim(SCENARIO, operating__slip_ratio=5.0)
    with pytest.raises(ValueError, match=r"(?s)<spec dict>.*missing key .pressure."):
        vehsim.atiim({"name": "x", "operating": {"speed_mps": 1.0, "slip_ratio": 0.0, "ice_temp_c": -5.0}})


def test_bad_discover_input(tmp_path):
    bad = tmp_path / "bad.csv"
    bad.write_text("t,steer,vx,yaw_rate\n0,0,10,0\n1,0,10,0\n")
    with pytest.raises(ValueError, match=r"bad\.csv.*ay"):
        vehsim.discover("vehicles/sedan.toml", [bad])
    with pytest.raises(ValueError, match="not a tyre provider"):
        vehsim.discover("vehicles/sedan.toml", [bad], tyre_model="magic")
    with pytest.raises(FileNotFoundError):
        vehsim.discover("vehicles/sedan.toml", [tmp_path / "none.csv"])


# ---------------------------------------------------------------------------------------------
# the example script


def test_example_plots_yaw_rate(root, tmp_path, monkeypatch):
    pytest.importorskip("matplotlib", reason="matplotlib is not installed; the example needs it")
    import runpy
    import sys

    out = tmp_path / "yaw.png"
    monkeypatch.setattr(sys, "argv", ["yaw_rate_two_tyres.py", "--out", str(out)])
    with pytest.raises(SystemExit) as e:
        runpy.run_path(str(root / "python" / "examples" / "yaw_rate_two_tyres.py"), run_name="__main__")
    assert e.value.code == 0
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
