"""Run a random and a scripted steering policy through vehsim's Gymnasium environments and print
their returns (nothing is trained).

    python python/examples/gym_policies.py [--episodes 3] [--seed 0]

Run from the project root (the environments read maneuvers/*.toml relative to it); needs
gymnasium (pip install gymnasium). The random policy steers uniformly in the action range; the
scripted one (vehsim.gym.PathFollower) steers against the path error.
"""

import argparse

import numpy as np


def episode(env, policy, seed):
    obs, info = env.reset(seed=seed)
    ret, steps = 0.0, 0
    while True:
        obs, reward, terminated, truncated, info = env.step(policy(obs))
        ret += reward
        steps += 1
        if terminated or truncated:
            return ret, steps, info


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--episodes", type=int, default=3)
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args()
    import gymnasium

    import vehsim.gym  # noqa: F401  (registers vehsim/LaneChange-v0 and vehsim/ConstantRadius-v0)

    for env_id in ("vehsim/LaneChange-v0", "vehsim/ConstantRadius-v0"):
        env = gymnasium.make(env_id, mu_range=(0.12, 0.18)).unwrapped
        env.action_space.seed(args.seed)
        follower = vehsim.gym.PathFollower(env)

        def scripted(obs):
            return follower(obs)

        for name, policy in (("random", lambda obs: env.action_space.sample()), ("scripted", scripted)):
            returns = []
            for k in range(args.episodes):
                follower.reset()
                ret, steps, info = episode(env, policy, args.seed + k)
                returns.append(ret)
                print(
                    f"{env_id:26s} {name:8s} episode {k}: return {ret:8.1f} over {steps:4d} decisions, "
                    f"t = {info['t_s']:6.2f} s, mu {info['mu']:.3f}, cones {info['cones_hit']}, "
                    f"end {info['end_reason'] or 'terminated by the env'}"
                )
            print(f"{env_id:26s} {name:8s} mean return {np.mean(returns):8.1f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
