"""``vehsim.Simulation``: one run of a manoeuvre spec, stepped from Python.

The engine is the one ``vehsim run`` uses: with no external input, stepping a spec to its end
gives the run ``vehsim.run`` returns, bit for bit. The caller may drive either channel itself:

* ``"steer"``: the front road-wheel steer angle, rad, positive left (ISO 8855), within the
  vehicle's lock ``|steer| <= limits["steer_max_rad"]``; the spec's driver is then ignored;
* ``"steer_rate"`` (instead of ``"steer"``): the steer rate, rad/s, within
  ``limits["steer_rate_max_radps"]``; the angle ramps from its value when the rate is set,
  exactly at every integration stage, and stops at the lock;
* ``"torque"``: the total drive and brake torque at the wheels, N m, each in
  ``[0, limits[...]]``, split by the vehicle's drive layout and brake balance; the spec's speed
  controller is then ignored.

External inputs are held over every step until set again. Inputs of the wrong shape, NaN or
beyond the limits raise ValueError and change nothing; stepping a finished run raises
RuntimeError (``reset()`` starts again).
"""

from __future__ import annotations

from typing import Any, Dict, List, Mapping, Optional, Sequence, Union

import numpy as np

from . import _vehsim

#: Names of the observation's values, units in the names (the columns of timeseries.csv).
OBSERVATION: List[str] = list(_vehsim.OBSERVATION)
#: The observation as a NumPy structured dtype: one float64 field per name.
OBSERVATION_DTYPE = np.dtype([(n, np.float64) for n in OBSERVATION])

_CHANNELS = {
    "steer": ("steer_rad",),
    "steer_rate": ("steer_rate_radps",),
    "torque": ("drive_torque_nm", "brake_torque_nm"),
}


class Simulation:
    """A steppable run of a single-run manoeuvre spec (a TOML path or a dict; keyword
    overrides as in :func:`vehsim.run`).

    Args:
        spec: the manoeuvre spec.
        external: the channels the caller drives: ``()`` (default: the spec's driver and speed
            controller), ``"steer"`` or ``"steer_rate"``, ``"torque"``, or a sequence of them.

    Attributes:
        input_names: the external inputs in the order :meth:`step` takes them as a sequence.
        state_names: names of the model's state components (:attr:`state`).
        step_s, control_period_s, duration_s: integration step, controller sample period and
            time limit, s.
        limits: dict ``steer_max_rad``, ``drive_torque_max_nm``, ``brake_torque_max_nm``.
    """

    def __init__(self, spec: Any, *, external: Union[str, Sequence[str]] = (), **overrides: Any):
        from . import _spec_args  # the package's spec conversion (path or dict, overrides)

        if isinstance(external, str):
            external = (external,)
        external = tuple(external)
        unknown = [c for c in external if c not in _CHANNELS]
        if unknown:
            raise ValueError(f"external: unknown channel {unknown[0]!r}; allowed: 'steer', 'steer_rate', 'torque'")
        self.external = tuple(c for c in _CHANNELS if c in external)
        self._native = _vehsim.NativeSimulation(
            **_spec_args(spec, overrides),
            steer_external="steer" in external,
            steer_rate_external="steer_rate" in external,
            torque_external="torque" in external,
        )
        self.input_names: List[str] = [n for c in self.external for n in _CHANNELS[c]]
        self.state_names: List[str] = list(self._native.state_names)
        n = self._native
        self.step_s: float = n.step_s
        self.control_period_s: float = n.control_period_s
        self.duration_s: float = n.duration_s
        steer, drive, brake, rate = n.limits
        self.limits: Dict[str, float] = {
            "steer_max_rad": steer,
            "steer_rate_max_radps": rate,
            "drive_torque_max_nm": drive,
            "brake_torque_max_nm": brake,
        }
        self.name: str = n.name
        self.maneuver: str = n.maneuver
        self.mu: float = n.mu
        self.surface_temperature_c: float = n.surface_temperature_c
        self.seed: Optional[int] = None

    def __repr__(self) -> str:
        return (
            f"Simulation({self.name!r}, t = {self.t_s:.3f} s, external={list(self.external)}, "
            f"end_reason={self.end_reason!r})"
        )

    def reset(self, seed: Optional[int] = None) -> np.ndarray:
        """Start again from the manoeuvre's start (external inputs back to zero) and return the
        observation. The engine has no randomness: ``seed`` is only kept (``self.seed``) for
        callers that draw their own random numbers (the Gymnasium environment does)."""
        self._native.reset()
        self.seed = seed
        return self._native.observation()

    def step(self, inputs: Any = None, n: int = 1) -> np.ndarray:
        """Set the external inputs (if given), advance ``n`` steps (fewer if the run ends) and
        return the observation (a float64 vector in the order of :data:`OBSERVATION`).

        ``inputs``: None (keep the inputs in force), a mapping with any of ``steer_rad`` (or
        ``steer_rate_radps``), ``drive_torque_nm``, ``brake_torque_nm``, or a sequence / 1-D array
        in the order of :attr:`input_names`.
        """
        if inputs is not None:
            self.set_inputs(inputs)
        if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 1:
            raise ValueError(f"n: {n!r} is not allowed; expected a whole number of steps >= 1")
        self._native.step(int(n))
        return self._native.observation()

    def set_inputs(self, inputs: Any) -> None:
        """Set the external inputs (see :meth:`step`) for the coming steps."""
        if isinstance(inputs, Mapping):
            unknown = [k for k in inputs if k not in self.input_names]
            if unknown:
                raise ValueError(
                    f"inputs: {unknown[0]!r} is not an external input of this simulation; "
                    f"allowed: {self.input_names or 'none (created without external=...)'}"
                )
            values = {k: _number(k, v) for k, v in inputs.items()}
        else:
            arr = np.asarray(inputs, dtype=np.float64) if not isinstance(inputs, (str, bytes)) else None
            if arr is None or arr.shape != (len(self.input_names),):
                shape = "a str" if arr is None else f"shape {arr.shape}"
                raise ValueError(
                    f"inputs: expected {len(self.input_names)} values ({', '.join(self.input_names) or 'none'}), "
                    f"got {shape}"
                )
            values = dict(zip(self.input_names, (float(v) for v in arr)))
        self._native.set_inputs(**values)

    def run(self, inputs: Any = None) -> np.ndarray:
        """Step to the run's end (holding the inputs) and return the final observation."""
        if inputs is not None:
            self.set_inputs(inputs)
        while self._native.end_reason is None:
            self._native.step(1 << 20)
        return self._native.observation()

    @property
    def observation(self) -> np.ndarray:
        """The observation now as a 0-d structured array: ``obs["yaw_rate_radps"]``."""
        return self._native.observation().view(OBSERVATION_DTYPE).reshape(())

    @property
    def state(self) -> np.ndarray:
        """The model's state vector now (a copy; names in :attr:`state_names`)."""
        return self._native.state()

    @property
    def inputs(self) -> Dict[str, float]:
        """The external inputs in force (only the channels the caller drives)."""
        steer, drive, brake, rate = self._native.inputs
        values = {"steer_rad": steer, "drive_torque_nm": drive, "brake_torque_nm": brake, "steer_rate_radps": rate}
        return {k: values[k] for k in self.input_names}

    t_s = property(lambda self: self._native.t_s, doc="time now, s")
    steps = property(lambda self: self._native.steps, doc="steps taken")
    max_steps = property(lambda self: self._native.max_steps, doc="steps the time limit allows")
    end_reason = property(
        lambda self: self._native.end_reason,
        doc="why the run ended (completed, duration, spin_out, diverged, left_path), None while it runs",
    )
    done = property(lambda self: self._native.end_reason is not None, doc="True once the run has ended")
    cones_hit = property(lambda self: self._native.cones_hit, doc="gate boundaries struck so far (ISO 3888-2)")
    passed = property(lambda self: self._native.passed, doc="the manoeuvre's verdict so far, None without a rule")
    wheelbase_m = property(lambda self: self._native.wheelbase_m)

    @property
    def events(self) -> List[Dict[str, Any]]:
        """Events so far: dicts with ``t_s``, ``kind`` (``cone_strike``, ``spin_out``, ...) and
        ``detail``."""
        return list(self._native.events())


def _number(name: str, v: Any) -> float:
    if isinstance(v, bool) or v is None:
        raise ValueError(f"inputs: {name} = {v!r} is not a number")
    try:
        return float(v)
    except (TypeError, ValueError):
        raise ValueError(f"inputs: {name} = {v!r:.40} is not a number") from None

