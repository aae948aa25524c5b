"""Side-by-side timing of one case in vehsim and in CommonRoad's single-track drift model (STD).

Run by scripts/bench_commonroad.sh inside a throwaway virtual environment holding
commonroad-vehicle-models from PyPI; this file never imports vehsim (the vehsim side is the
`vehsim bench` command, the engine's own timer: simulation only, no files written).

The case, in both programs: the sedan of vehicles/sedan.toml on the SRTT tyre's Magic Formula
(vehicles/tyres/srtt_p225_60r16.tir) on ice of mu 0.15; a sine steer of 10 degrees road-wheel
amplitude, one period over 10 s, starting at once; speed held at 10 m/s; 10 s simulated.
- vehsim: `vehsim bench maneuvers/sine_steer.toml --tyre-model pacejka` (the spec's single-track
  model with wheel spin, combined-slip Magic Formula scaled to the ice as the tyre file says:
  LMUX/LMUY x 0.15, slip stiffnesses x 0.15^0.5; RK4 at the spec's 10 ms; a speed controller
  drives the front wheels).
- CommonRoad: vehicle_dynamics_std (single track with front and rear wheel spin and its
  combined-slip Magic Formula) with the sedan's mass, yaw inertia, axle distances, CG height,
  rolling radius, wheel inertia (both wheels of an axle: 2 x 1.2 kg m^2), front drive and brake
  share 0.68, steering limits; its tyre coefficients set from the same .tir with the same ice
  scaling (peak mu_x = 1.2 x 0.15, mu_y = 1.0 x 0.15; K_x/F_z = 22 x 0.15^0.5; K_y/F_z at the
  static front tyre load with PKY2, x 0.15^0.5; combined-slip RBX/RBY/RC/RE; offsets 0);
  what its reduced formula lacks (load dependence of the peak, drag and rolling resistance) is
  left out. Inputs: steering rate d(delta)/dt of the same sine (exact at every RK4 stage) and a
  longitudinal acceleration 2 s^-1 x (10 m/s - v) held over each step. Classic RK4 at 1 ms, in
  pure Python as the package ships it (its parameters are the plain dataclass
  parameters_vehicle2() returns).

Timing: interleaved pairs; each pair is one `vehsim bench --runs R` (its median run) and one
CommonRoad run. The ratio of each pair is CommonRoad's time over vehsim's; the median over the
pairs is reported, with the ranges of both sides. A line before the timing prints both runs'
peak |yaw rate| and final speed: the same case, two models (they are not expected to agree
closely: CommonRoad's tyre has one load-independent peak per axle, vehsim's two tyres per axle
with load-dependent peaks, and vehsim has drag and rolling resistance).
"""

import argparse
import csv
import importlib.metadata
import json
import math
import os
import statistics
import subprocess
import sys
import tempfile
import time

from vehiclemodels.init_std import init_std
from vehiclemodels.parameters_vehicle2 import parameters_vehicle2
from vehiclemodels.vehicle_dynamics_std import vehicle_dynamics_std

MU = 0.15  # surface friction of the spec's ice
SPEED = 10.0  # m/s, held
AMPLITUDE = math.radians(10.0)  # road-wheel steer amplitude, rad
PERIOD = 10.0  # s
DURATION = 10.0  # s
STIFFNESS_MU_EXPONENT = 0.5  # the tyre file's slip-stiffness scaling on ice
SPEED_GAIN = 2.0  # 1/s, the CommonRoad side's speed controller


def tir_coefficients(path):
    """The numeric entries of a .tir file: NAME -> float."""
    out = {}
    with open(path) as f:
        for line in f:
            parts = line.split("$")[0].split("=")
            if len(parts) == 2:
                try:
                    out[parts[0].strip().upper()] = float(parts[1].strip().strip("'"))
                except ValueError:
                    pass
    return out


def sedan_parameters(tir_path):
    """CommonRoad parameters of vehicle 2 (BMW 320i) overwritten with the sedan and its tyre."""
    p = parameters_vehicle2()
    p.m, p.I_z, p.a, p.b, p.h_s = 1600.0, 3130.0, 1.09, 1.71, 0.55
    p.R_w, p.I_y_w = 0.328, 2 * 1.2
    p.T_se, p.T_sb = 1.0, 0.68  # front drive; 68 % of the braking on the front axle
    p.steering.max, p.steering.min = 0.61, -0.61
    p.steering.v_max, p.steering.v_min = 1.0, -1.0
    c = tir_coefficients(tir_path)
    k = MU**STIFFNESS_MU_EXPONENT
    fz0 = c["FNOMIN"]
    fz_front = 1600.0 * 9.81 * 1.71 / 2.80 / 2  # static load of one front tyre, N
    ky_front = c["PKY1"] * fz0 * math.sin(2 * math.atan(fz_front / (c["PKY2"] * fz0)))
    t = p.tire
    t.p_cx1, t.p_dx1, t.p_dx3, t.p_ex1 = c["PCX1"], c["PDX1"] * MU, 0.0, c["PEX1"]
    t.p_kx1, t.p_hx1, t.p_vx1 = c["PKX1"] * k, 0.0, 0.0
    t.r_bx1, t.r_bx2, t.r_cx1, t.r_ex1, t.r_hx1 = c["RBX1"], c["RBX2"], c["RCX1"], c["REX1"], 0.0
    t.p_cy1, t.p_dy1, t.p_dy3, t.p_ey1 = c["PCY1"], c["PDY1"] * MU, 0.0, c["PEY1"]
    t.p_ky1, t.p_ky2, t.p_ky3 = ky_front / fz_front * k, 0.0, 0.0
    t.p_hy1, t.p_hy3, t.p_vy1, t.p_vy3 = 0.0, 0.0, 0.0, 0.0
    t.r_by1, t.r_by2, t.r_by3, t.r_cy1, t.r_ey1, t.r_hy1 = c["RBY1"], c["RBY2"], c["RBY3"], c["RCY1"], c["REY1"], 0.0
    t.r_vy1, t.r_vy3, t.r_vy4, t.r_vy5, t.r_vy6 = 0.0, 0.0, 0.0, 0.0, 0.0
    return p


def steer_rate(t):
    """d(delta)/dt of delta = A sin(2 pi t / T), rad/s."""
    w = 2 * math.pi / PERIOD
    return AMPLITUDE * w * math.cos(w * t)


def simulate(p, step):
    """One CommonRoad STD run of the case with classic RK4; returns (peak |yaw rate|, final speed)."""
    x = init_std([0.0, 0.0, 0.0, SPEED, 0.0, 0.0, 0.0], p)
    n = round(DURATION / step)
    peak = 0.0
    f = vehicle_dynamics_std
    for i in range(n):
        t = i * step
        acc = SPEED_GAIN * (SPEED - x[3])
        u0, uh, u1 = [steer_rate(t), acc], [steer_rate(t + step / 2), acc], [steer_rate(t + step), acc]
        k1 = f(list(x), u0, p)
        k2 = f([a + step / 2 * b for a, b in zip(x, k1)], uh, p)
        k3 = f([a + step / 2 * b for a, b in zip(x, k2)], uh, p)
        k4 = f([a + step * b for a, b in zip(x, k3)], u1, p)
        x = [a + step / 6 * (b + 2 * c + 2 * d + e) for a, b, c, d, e in zip(x, k1, k2, k3, k4)]
        peak = max(peak, abs(x[5]))
    return peak, x[3]


def vehsim_version(vehsim):
    return subprocess.run([vehsim, "--version"], capture_output=True, text=True).stdout.strip()


def vehsim_median_ms(vehsim, spec, runs):
    """`vehsim bench`'s median wall time per run, ms (its --tsv line's median_ms column)."""
    cmd = [vehsim, "bench", spec, "--runs", str(runs), "--tsv"]
    out = subprocess.run(cmd, check=True, capture_output=True, text=True).stdout.split("\t")
    return float(out[7])


def vehsim_spec(spec, folder):
    """The spec with the Pacejka provider, written into ``folder`` (its vehicle path made absolute)."""
    text = open(spec).read()
    vehicle_dir = os.path.join(os.path.dirname(os.path.abspath(spec)), "")
    assert 'tyre_model = "linear"' in text and 'vehicle = "../' in text, f"{spec}: not the expected sine steer"
    text = text.replace('tyre_model = "linear"', 'tyre_model = "pacejka"').replace('vehicle = "../', f'vehicle = "{vehicle_dir}../')
    text = text.replace('name = "sine_steer_ice"', 'name = "sine_steer_ice_pacejka"')
    path = os.path.join(folder, "sine_steer_ice_pacejka.toml")
    with open(path, "w") as f:
        f.write(text)
    return path


def vehsim_peak(vehsim, spec, folder):
    """The vehsim run's model and step, peak |yaw rate| (rad/s) and final speed (m/s), from its files."""
    subprocess.run([vehsim, "run", spec, "--quiet", "--out", folder], check=True, capture_output=True)
    run = os.path.join(folder, "sine_steer_ice_pacejka")
    summary = json.load(open(os.path.join(run, "summary.json")))
    with open(os.path.join(run, "timeseries.csv")) as f:
        rows = list(csv.DictReader(f))
    how = f"{summary['vehicle_model']} + {summary['tyre_model']}, {summary['integrator']} {summary['step_s'] * 1e3:g} ms"
    return how, summary["peak_yaw_rate_radps"], float(rows[-1]["vx_mps"])


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--vehsim", required=True, help="the vehsim binary")
    ap.add_argument("--spec", required=True, help="maneuvers/sine_steer.toml")
    ap.add_argument("--tir", required=True, help="vehicles/tyres/srtt_p225_60r16.tir")
    ap.add_argument("--pairs", type=int, default=5, help="interleaved pairs (default 5)")
    ap.add_argument("--vehsim-runs", type=int, default=50, help="runs per vehsim bench (default 50)")
    ap.add_argument("--step", type=float, default=1e-3, help="CommonRoad RK4 step, s (default 0.001)")
    a = ap.parse_args()
    params = sedan_parameters(a.tir)
    peak, v_end = simulate(params, a.step)
    print(f"case: {a.spec} with tyre_model pacejka, {DURATION:g} s; versions: {vehsim_version(a.vehsim)}, "
          f"commonroad-vehicle-models {importlib.metadata.version('commonroad-vehicle-models')}, Python {sys.version.split()[0]}")
    print(f"CommonRoad STD, RK4 {a.step * 1e3:g} ms: peak |yaw rate| {peak:.4f} rad/s, final speed {v_end:.3f} m/s")
    with tempfile.TemporaryDirectory(prefix="vehsim-vs-commonroad-") as folder:
        timed_pairs(a, params, folder)


def timed_pairs(a, params, folder):
    """The vehsim run's figures, then the interleaved pairs and their median ratio."""
    spec = vehsim_spec(a.spec, folder)
    how, v_peak, v_vx = vehsim_peak(a.vehsim, spec, folder)
    print(f"vehsim {how}: peak |yaw rate| {v_peak:.4f} rad/s, final speed {v_vx:.3f} m/s")
    rows = []
    for i in range(a.pairs):
        v_ms = vehsim_median_ms(a.vehsim, spec, a.vehsim_runs)
        t0 = time.perf_counter()
        simulate(params, a.step)
        cr_s = time.perf_counter() - t0
        rows.append((v_ms, cr_s))
        print(f"pair {i + 1}: vehsim {v_ms:.3f} ms, CommonRoad {cr_s:.3f} s, ratio {cr_s * 1e3 / v_ms:.0f}x")
        sys.stdout.flush()
    v, c = [r[0] for r in rows], [r[1] for r in rows]
    ratio = statistics.median(cr * 1e3 / vs for vs, cr in rows)
    print(
        f"CommonRoad STD {min(c):.3f}-{max(c):.3f} s vs vehsim {min(v):.3f}-{max(v):.3f} ms per 10 s run: "
        f"median ratio {ratio:.0f}x over {len(rows)} interleaved pairs"
    )


if __name__ == "__main__":
    main()
