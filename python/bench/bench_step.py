"""Benchmark of vehsim.Simulation: Python-level steps per second on one core.

    python python/bench/bench_step.py [--spec maneuvers/dlc.toml] [--repeats 5] [--external]

Steps the spec from its start to its end, one `step()` call per step (each returns the
observation vector), and reports the median and best steps per second over the repeats, and the
process CPU time per step. --external drives steer and torque from Python (a fixed input array
passed at every step) instead of the spec's driver and speed controller. Run from the project
root with the package installed (python/test.sh builds it into python/target/venv).
"""

import argparse
import os
import statistics
import time


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--spec", default="maneuvers/dlc.toml")
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--external", action="store_true")
    args = ap.parse_args()
    import numpy as np

    import vehsim

    ext = ["steer", "torque"] if args.external else []
    sim = vehsim.Simulation(args.spec, external=ext)
    u = np.array([0.0, 300.0, 0.0]) if args.external else None
    print(f"load average before: {os.getloadavg()[0]:.2f}")
    rates, cpu = [], []
    for _ in range(args.repeats):
        sim.reset()
        n = 0
        t0, c0 = time.perf_counter(), time.process_time()
        while not sim.done:
            sim.step(u)
            n += 1
        dt, dc = time.perf_counter() - t0, time.process_time() - c0
        rates.append(n / dt)
        cpu.append(dc / n)
    print(
        f"{args.spec} ({'external inputs' if ext else 'spec driver'}): {n} steps of {sim.step_s} s; "
        f"median {statistics.median(rates):,.0f} steps/s, best {max(rates):,.0f} steps/s, "
        f"CPU {1e6 * statistics.median(cpu):.2f} us/step"
    )
    print(f"load average after: {os.getloadavg()[0]:.2f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
