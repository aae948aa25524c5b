"""Yaw rate of the sine-steer run on ice (maneuvers/sine_steer.toml: 10 deg road-wheel sine over
10 s at 10 m/s, mu 0.15, -3 degC) with two tyre models, drawn with matplotlib.

    python python/examples/yaw_rate_two_tyres.py [--out yaw_rate.png] [--models linear pacejka]

Run from the project root (the spec's paths are relative to it). Needs matplotlib.
"""

import argparse
import sys
from pathlib import Path

import vehsim

ROOT = Path(__file__).resolve().parents[2]


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default="yaw_rate_two_tyres.png", help="image file (PNG, SVG or PDF)")
    ap.add_argument("--models", nargs=2, default=["linear", "pacejka"], choices=vehsim.TYRE_MODELS)
    args = ap.parse_args()
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("this example needs matplotlib: pip install matplotlib", file=sys.stderr)
        return 2
    fig, ax = plt.subplots(figsize=(8, 4.5))
    runs = [vehsim.run(ROOT / "maneuvers" / "sine_steer.toml", tyre_model=m) for m in args.models]
    for model, r in zip(args.models, runs):
        s = r.summary
        label = f"{model} tyre (peak {s['peak_yaw_rate_radps']:.3f} rad/s)"
        ax.plot(r["t_s"], r["yaw_rate_radps"], label=label)
    ax2 = ax.twinx()
    ax2.plot(runs[0]["t_s"], runs[0]["steer_rad"], color="0.6", linestyle=":")
    ax2.set_ylabel("road-wheel angle, dotted (rad)")
    ax.set_xlabel("time (s)")
    ax.set_ylabel("yaw rate (rad/s)")
    ax.set_title("Sine steer on ice: 10 m/s, mu 0.15, 10 deg amplitude")
    ax.grid(True, alpha=0.3)
    ax.legend(loc="lower left")
    fig.tight_layout()
    fig.savefig(args.out, dpi=120)
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
