"""Gymnasium environments over :class:`vehsim.Simulation` (optional: ``pip install gymnasium``).

Two tasks on ice, the agent steering and the spec's speed controller holding the speed:

* ``LaneChangeEnv`` (id ``vehsim/LaneChange-v0``): the ISO 3888-2 severe lane change of
  ``maneuvers/dlc.toml`` (10 m/s held, mu 0.15), with the Pacejka tyre unless ``tyre_model``
  says otherwise (the spec's linear tyre does not saturate, so friction would not matter).
* ``ConstantRadiusEnv`` (id ``vehsim/ConstantRadius-v0``): the ISO 4138 40 m circle of
  ``maneuvers/constant_radius_40m_left_ice.toml`` (4-DOF model, Pacejka tyre, speed stepped up
  until the car leaves the circle or the manoeuvre ends).

Spec paths are relative to the current directory (the project root) unless given in full.

Action (Box(-1, 1, (1,), float32)): the front road-wheel steer angle as a fraction of
``max_steer_rad`` (default 0.1 rad, about 6 degrees; positive left), held for one decision
period (``decision_period_s``, default 0.05 s, a whole number of the spec's integration steps).

Observation (Box(-hi, hi, (8,), float32), hi = [1e4, 1e4, 1e3, 100, 100, 50, steer lock, 1e4]):
``[x_m, y_m, yaw_rad, vx_mps, vy_mps, yaw_rate_radps, steer_rad, path_error_m]`` (ISO 8855 ground frame; ``path_error_m`` is the
signed lateral deviation of the centre of gravity from the manoeuvre's reference path, 0 where
the manoeuvre has none yet).

Reward per decision: the distance travelled over ``vx * decision_period_s`` (about 1 while the car
moves; vx at the decision's start, at least 1 m/s), minus ``(path_error_m / 1 m)^2``; a cone strike costs 10 and a spin-out or
leaving the path 100. Termination: a cone strike (lane change), spin-out, leaving the path
(|path_error_m| > ``max_path_error_m``, default 3 m; on the circle also the manoeuvre's own
left-path rule), or the manoeuvre completed. Truncation: the spec's time limit
(``duration_s``) reached.

``reset(seed=...)`` seeds ``self.np_random``; with ``mu_range=(lo, hi)`` each episode draws the
surface friction uniformly from it (domain randomisation), else the spec's mu is used and the
episodes are identical for identical actions.
"""

from __future__ import annotations

from typing import Any, Dict, Optional, Sequence, Tuple

import numpy as np

try:
    import gymnasium
    from gymnasium import spaces
except ImportError as e:  # pragma: no cover - depends on the environment
    raise ImportError("vehsim.gym needs gymnasium: pip install gymnasium") from e

from .simulation import OBSERVATION, Simulation

#: The observation's channels, in order.
OBS_NAMES = ("x_m", "y_m", "yaw_rad", "vx_mps", "vy_mps", "yaw_rate_radps", "steer_rad", "path_error_m")
_IDX = np.array([OBSERVATION.index(n) for n in OBS_NAMES])
_X, _PATH = OBS_NAMES.index("x_m"), OBS_NAMES.index("path_error_m")


class VehsimEnv(gymnasium.Env):
    """Steering on ice over a vehsim manoeuvre spec (see the module docs)."""

    metadata = {"render_modes": []}

    def __init__(
        self,
        spec: Any,
        *,
        decision_period_s: float = 0.05,
        max_steer_rad: float = 0.1,
        max_path_error_m: float = 3.0,
        mu_range: Optional[Sequence[float]] = None,
        terminate_on_cone: bool = True,
        **overrides: Any,
    ):
        self._spec = spec
        self._overrides = dict(overrides)
        self._sim = Simulation(spec, external="steer", **overrides)
        n = decision_period_s / self._sim.step_s
        if not (np.isfinite(n) and n >= 0.5 and abs(n - round(n)) < 1e-6):
            raise ValueError(
                f"decision_period_s: {decision_period_s!r} is not allowed; expected a whole number "
                f"(>= 1) of the spec's step {self._sim.step_s} s"
            )
        self._every = int(round(n))
        self.decision_period_s = self._every * self._sim.step_s
        lock = self._sim.limits["steer_max_rad"]
        if not (0.0 < max_steer_rad <= lock):
            raise ValueError(f"max_steer_rad: {max_steer_rad!r} is not allowed; expected (0, {lock}] rad")
        self.max_steer_rad = float(max_steer_rad)
        self.max_path_error_m = float(max_path_error_m)
        if mu_range is not None:
            lo, hi = (float(v) for v in mu_range)
            if not (0.0 < lo <= hi <= 3.0):
                raise ValueError(f"mu_range: {mu_range!r} is not allowed; expected 0 < lo <= hi <= 3")
            mu_range = (lo, hi)
        self.mu_range = mu_range
        self.terminate_on_cone = terminate_on_cone
        self.action_space = spaces.Box(-1.0, 1.0, shape=(1,), dtype=np.float32)
        # generous physical bounds (positions within 10 km, yaw within 1000 rad of the start)
        hi = np.array([1e4, 1e4, 1e3, 100.0, 100.0, 50.0, lock, 1e4], dtype=np.float32)
        self.observation_space = spaces.Box(-hi, hi, dtype=np.float32)
        self._last: np.ndarray = np.zeros(len(OBSERVATION))
        self._cones = 0

    @property
    def simulation(self) -> Simulation:
        """The simulation being stepped (read its events, time, state)."""
        return self._sim

    def _obs(self, full: np.ndarray) -> np.ndarray:
        o = full[_IDX].astype(np.float32)
        if not np.isfinite(o[_PATH]):
            o[_PATH] = 0.0
        # within the space even after a divergence (which ends the episode)
        return np.clip(np.nan_to_num(o), self.observation_space.low, self.observation_space.high)

    def reset(self, *, seed: Optional[int] = None, options: Optional[Dict[str, Any]] = None):
        super().reset(seed=seed)
        if self.mu_range is not None:
            mu = float(self.np_random.uniform(*self.mu_range))
            self._sim = Simulation(self._spec, external="steer", **{**self._overrides, "surface__mu": mu})
        self._last = self._sim.reset(seed=seed)
        self._cones = 0
        return self._obs(self._last), self._info()

    def _info(self) -> Dict[str, Any]:
        return {
            "t_s": self._sim.t_s,
            "cones_hit": self._sim.cones_hit,
            "end_reason": self._sim.end_reason,
            "mu": self._sim.mu,
        }

    def step(self, action: Any) -> Tuple[np.ndarray, float, bool, bool, Dict[str, Any]]:
        try:
            a = np.asarray(action, dtype=np.float64).reshape(-1)
        except (TypeError, ValueError):
            a = np.array([np.nan])
        if a.shape != (1,) or not np.isfinite(a[0]):
            raise ValueError(f"action: expected one finite number in [-1, 1], got {action!r:.60}")
        steer = float(np.clip(a[0], -1.0, 1.0)) * self.max_steer_rad
        if self._sim.done:
            raise RuntimeError("step() after the episode ended; call reset()")
        before = self._last
        full = self._sim.step({"steer_rad": steer}, n=self._every)
        self._last = full
        obs = self._obs(full)
        i = OBSERVATION.index
        speed = max(float(before[i("vx_mps")]), 1.0)
        travelled = np.hypot(full[i("x_m")] - before[i("x_m")], full[i("y_m")] - before[i("y_m")])
        reward = travelled / (speed * self.decision_period_s)
        reward -= float(obs[_PATH]) ** 2
        terminated = False
        end = self._sim.end_reason
        new_cones = self._sim.cones_hit - self._cones
        self._cones = self._sim.cones_hit
        if new_cones > 0:
            reward -= 10.0 * new_cones
            terminated = self.terminate_on_cone
        if end in ("spin_out", "diverged", "left_path") or abs(obs[_PATH]) > self.max_path_error_m:
            reward -= 100.0
            terminated = True
        elif end == "completed":
            terminated = True
        truncated = end == "duration" and not terminated
        return obs, float(reward), bool(terminated), bool(truncated), self._info()


class LaneChangeEnv(VehsimEnv):
    """ISO 3888-2 severe lane change on ice (``maneuvers/dlc.toml`` by default)."""

    def __init__(self, spec: Any = "maneuvers/dlc.toml", **kwargs: Any):
        kwargs.setdefault("tyre_model", "pacejka")
        super().__init__(spec, **kwargs)


class ConstantRadiusEnv(VehsimEnv):
    """ISO 4138 constant radius on ice (``maneuvers/constant_radius_40m_left_ice.toml``)."""

    def __init__(self, spec: Any = "maneuvers/constant_radius_40m_left_ice.toml", **kwargs: Any):
        kwargs.setdefault("terminate_on_cone", False)
        super().__init__(spec, **kwargs)


class PathFollower:
    """A scripted baseline policy for the examples and tests: steer against the observation's
    path error, proportional plus derivative (no preview: on ice it reaches the lane change's
    last lane late and strikes a cone there, while the spec's own preview driver passes).

    ``steer_rad = -(kp * e + kd * de/dt)``, e the path error in m, clipped to the action range.
    """

    def __init__(self, env: VehsimEnv, kp: float = 0.2, kd: float = 0.1):
        self.env, self.kp, self.kd = env, kp, kd
        self._prev: Optional[float] = None

    def reset(self) -> None:
        self._prev = None

    def __call__(self, obs: np.ndarray) -> np.ndarray:
        e = float(obs[_PATH])
        de = 0.0 if self._prev is None else (e - self._prev) / self.env.decision_period_s
        self._prev = e
        steer = -(self.kp * e + self.kd * de)
        return np.array([np.clip(steer / self.env.max_steer_rad, -1.0, 1.0)], dtype=np.float32)


for _id, _cls in (("vehsim/LaneChange-v0", LaneChangeEnv), ("vehsim/ConstantRadius-v0", ConstantRadiusEnv)):
    if _id not in gymnasium.registry:
        gymnasium.register(id=_id, entry_point=f"{__name__}:{_cls.__name__}")
