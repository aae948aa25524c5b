"""vehsim.gym: the Gymnasium environments pass Gymnasium's own checker and end episodes as
documented (cone strike, leaving the path, time limit), deterministically for a seed."""

import subprocess
import sys

import numpy as np
import pytest

gymnasium = pytest.importorskip("gymnasium")
from gymnasium.utils.env_checker import check_env  # noqa: E402

import vehsim.gym as vg  # noqa: E402


@pytest.fixture(autouse=True)
def _in_root(root, monkeypatch):
    monkeypatch.chdir(root)


@pytest.mark.parametrize("cls", [vg.LaneChangeEnv, vg.ConstantRadiusEnv])
def test_check_env_passes(cls):
    check_env(cls(), skip_render_check=True)
    check_env(cls(mu_range=(0.1, 0.2)), skip_render_check=True)


@pytest.mark.parametrize("env_id", ["vehsim/LaneChange-v0", "vehsim/ConstantRadius-v0"])
def test_registered_ids_make_the_environments(env_id):
    env = gymnasium.make(env_id)
    obs, info = env.reset(seed=0)
    assert env.observation_space.contains(obs) and info["t_s"] == 0.0


def rollout(env, seed, policy):
    obs, info = env.reset(seed=seed)
    out = [obs]
    while True:
        obs, r, term, trunc, info = env.step(policy(obs))
        out.append(obs)
        if term or trunc:
            return np.array(out), term, trunc, info


def test_same_seed_same_episode_and_mu_drawn_within_the_range():
    env = vg.LaneChangeEnv(mu_range=(0.12, 0.18))
    f = vg.PathFollower(env)
    a = rollout(env, 7, f)
    f.reset()
    b = rollout(env, 7, f)
    np.testing.assert_array_equal(a[0], b[0])
    mus = {env.reset(seed=s)[1]["mu"] for s in range(5)}
    assert len(mus) == 5 and all(0.12 <= m <= 0.18 for m in mus)


def test_steering_hard_left_leaves_the_path_and_terminates():
    # the car starts 30 m before the course: full left steer takes it off the path before the cones
    env = vg.LaneChangeEnv()
    obs, term, trunc, info = rollout(env, 0, lambda o: np.array([1.0], dtype=np.float32))
    assert term and not trunc
    assert abs(obs[-1, 7]) > env.max_path_error_m and obs[-1, 0] < 0.0
    # positive action steers left: the car moved to +y
    assert obs[-1, 1] > obs[0, 1] + env.max_path_error_m


def test_the_scripted_follower_enters_the_course():
    # without preview it strikes a cone at the last lane today; a cone or the course's end
    # terminates the episode, inside the course (x > 0)
    env = vg.LaneChangeEnv()
    obs, term, trunc, info = rollout(env, 0, vg.PathFollower(env))
    assert term and not trunc and obs[-1, 0] > 0.0
    assert info["cones_hit"] >= 1 or info["end_reason"] == "completed"


def test_leaving_the_circle_terminates_and_the_time_limit_truncates():
    env = vg.ConstantRadiusEnv()
    _, term, trunc, info = rollout(env, 0, lambda o: np.array([-1.0], dtype=np.float32))
    assert term and not trunc and info["end_reason"] in ("left_path", "spin_out", None)
    env = vg.ConstantRadiusEnv(duration_s=5.0)
    f = vg.PathFollower(env)
    obs, term, trunc, info = rollout(env, 0, f)
    assert trunc and not term and info["end_reason"] == "duration" and info["t_s"] == pytest.approx(5.0)
    assert np.abs(obs[:, 7]).max() < env.max_path_error_m


def test_bad_actions_and_arguments():
    env = vg.LaneChangeEnv()
    env.reset(seed=0)
    for bad in ([np.nan], [0.1, 0.2], "left"):
        with pytest.raises(ValueError, match="action: expected one finite number"):
            env.step(bad)
    with pytest.raises(ValueError, match="decision_period_s: 0.013 is not allowed"):
        vg.LaneChangeEnv(decision_period_s=0.013)
    with pytest.raises(ValueError, match=r"max_steer_rad: 2.0 is not allowed; expected \(0, 0.61\] rad"):
        vg.LaneChangeEnv(max_steer_rad=2.0)
    with pytest.raises(ValueError, match="mu_range"):
        vg.LaneChangeEnv(mu_range=(0.2, 0.1))
    env = vg.ConstantRadiusEnv(duration_s=0.1)
    rollout(env, 0, lambda o: np.zeros(1, dtype=np.float32))
    with pytest.raises(RuntimeError, match="call reset"):
        env.step(np.zeros(1, dtype=np.float32))


def test_example_runs_a_random_and_a_scripted_policy(root):
    r = subprocess.run(
        [sys.executable, "python/examples/gym_policies.py", "--episodes", "1"],
        cwd=root,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert r.returncode == 0, r.stderr
    means = [line for line in r.stdout.splitlines() if "mean return" in line]
    assert len(means) == 4
    # the scripted follower does better than random steering on both tasks
    ret = {(l.split()[0], l.split()[1]): float(l.split()[-1]) for l in means}
    for task in ("vehsim/LaneChange-v0", "vehsim/ConstantRadius-v0"):
        assert ret[(task, "scripted")] > ret[(task, "random")]
