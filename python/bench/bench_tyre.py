"""Benchmark of the vectorised tyre call: nanoseconds per point of Tyre.forces on arrays of N
points (default 1e5), for every provider of the SRTT tyre file, median of R repeats.

    python python/bench/bench_tyre.py [--points 100000] [--repeats 21] [--threads N]

Inputs: fz uniform in [2, 6] kN, kappa in [-0.3, 0.3], alpha in [-0.2, 0.2] rad (seeded), camber 0,
mu 0.15, ice at -3 degC with a 2 K contact-temperature rise. --threads sets RAYON_NUM_THREADS
(the call splits arrays above 8192 points into parallel chunks). Prints one line per provider:
wall time per point (median and min) and process CPU time per point summed over threads (a
fairer figure on a shared machine), and the load average before and after.
"""

import argparse
import os
import statistics
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--points", type=int, default=100_000)
    ap.add_argument("--repeats", type=int, default=21)
    ap.add_argument("--threads", type=int, default=None)
    args = ap.parse_args()
    if args.threads:
        os.environ["RAYON_NUM_THREADS"] = str(args.threads)
    import numpy as np

    import vehsim

    rng = np.random.default_rng(1)
    n = args.points
    fz = rng.uniform(2000.0, 6000.0, n)
    kappa = rng.uniform(-0.3, 0.3, n)
    alpha = rng.uniform(-0.2, 0.2, n)
    print(f"load average before: {os.getloadavg()[0]:.2f}")
    threads = os.environ.get("RAYON_NUM_THREADS", f"all {os.cpu_count()} cores")
    print(f"Tyre.forces, {n} points, median of {args.repeats}, threads: {threads}")
    for provider in vehsim.TYRE_MODELS:
        t = vehsim.Tyre.from_file(ROOT / "vehicles" / "tyres" / "srtt_p225_60r16.toml", provider)
        t.forces(fz, kappa, alpha, mu=0.15, contact_temp=-1.0)  # warm-up
        wall, cpu = [], []
        for _ in range(args.repeats):
            c0, t0 = time.process_time(), time.perf_counter()
            t.forces(fz, kappa, alpha, mu=0.15, contact_temp=-1.0)
            wall.append(time.perf_counter() - t0)
            cpu.append(time.process_time() - c0)
        per = lambda v: v * 1e9 / n  # noqa: E731
        print(
            f"{provider:16s} wall {per(statistics.median(wall)):7.1f} ns/point (min {per(min(wall)):.1f}), "
            f"CPU {per(statistics.median(cpu)):7.1f} ns/point (min {per(min(cpu)):.1f}, all threads)"
        )
    print(f"load average after: {os.getloadavg()[0]:.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
