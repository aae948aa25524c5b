"""vehsim from Python: vehicle-dynamics runs, sweeps, tyre forces, ATIIM patches and discovery.

The native module ``vehsim._vehsim`` wraps the same library the ``vehsim`` command line uses, so
validation, messages and numbers are the command line's. Units are SI throughout; angles are in
radians (ISO 8855 axes: x forward, y left, z up; positive slip angle gives positive lateral force).

Errors: bad input raises ``ValueError`` (a top-level file that does not exist raises
``FileNotFoundError``, an ``OSError``), other I/O failures ``OSError``; the messages name the file,
the key and what is allowed, as the command line prints them.
"""

from __future__ import annotations

import json
import math
import os
import tempfile
from typing import Any, Dict, Iterable, List, Mapping, NamedTuple, Optional, Union

import numpy as np

from . import _vehsim
from . import shards as _shards
from .shards import ShardError

__all__ = [
    "run",
    "sweep",
    "Simulation",
    "OBSERVATION",
    "SweepInterrupted",
    "ShardError",
    "max_jobs",
    "Tyre",
    "TyreForces",
    "atiim",
    "discover",
    "RunResult",
    "SweepResult",
    "TYRE_MODELS",
    "TIMESERIES_COLUMNS",
]

#: Tyre providers accepted by ``Tyre.from_file`` and a spec's ``tyre_model``.
TYRE_MODELS: List[str] = list(_vehsim.TYRE_MODELS)
#: Time-series channels of a run (the columns of the command line's timeseries.csv).
TIMESERIES_COLUMNS: List[str] = list(_vehsim.TIMESERIES_COLUMNS)

Spec = Union[str, "os.PathLike[str]", Mapping[str, Any]]


def _existing(path: Any) -> str:
    """``path`` as a string; a missing file raises FileNotFoundError with the CLI's wording."""
    p = os.fspath(path)
    if not os.path.exists(p):
        raise FileNotFoundError(f"{p}: file not found")
    return p


def _spec_args(spec: Spec, overrides: Mapping[str, Any]) -> Dict[str, Any]:
    """Native arguments for a spec path or dict plus overrides (``a__b=v`` stands for ``a.b = v``)."""
    ov = {k.replace("__", "."): v for k, v in overrides.items()}
    if isinstance(spec, Mapping):
        return {"table": dict(spec), "overrides": ov}
    if isinstance(spec, (str, os.PathLike)):
        return {"path": _existing(spec), "overrides": ov}
    raise TypeError(f"spec must be a path or a dict, not {type(spec).__name__}")


class RunResult:
    """One simulated run.

    Attributes:
        summary: dict with the run's identity and figures, the keys of the command line's
            summary.json (``end_reason``, ``passed``, ``peak_yaw_rate_radps``, ``events``, ...).
        timeseries: dict channel -> 1-D float64 array, units in the names (``t_s``,
            ``yaw_rate_radps``, ...); NaN where the run does not define a value. With the
            vehicle's ``[sensors]`` section, also the logged ``yaw_rate_meas_radps`` and
            ``ay_meas_mps2``, as in the command line's timeseries.csv.
        params: the swept values of this run within a sweep (empty for a single run).
        status: ``ok`` or ``failed`` (diverged or spun out; the result is still complete).
    """

    def __init__(self, raw: Mapping[str, Any]):
        self.summary: Dict[str, Any] = json.loads(raw["summary_json"])
        self.timeseries: Dict[str, np.ndarray] = dict(raw["timeseries"] or {})
        self.params: Dict[str, str] = dict(raw["params"])
        self.status: str = raw["status"]
        self.index: int = raw["index"]

    @property
    def failed(self) -> bool:
        return self.status == "failed"

    def __getitem__(self, channel: str) -> np.ndarray:
        return self.timeseries[channel]

    def __repr__(self) -> str:
        s = self.summary
        return (
            f"RunResult({s['name']!r}, {s['end_reason']} at t = {s['end_time_s']:.2f} s, "
            f"{len(self.timeseries.get('t_s', ()))} rows)"
        )

    def to_pandas(self):
        """The time series as a pandas DataFrame indexed by ``t_s`` (needs pandas)."""
        try:
            import pandas as pd
        except ImportError as e:  # pragma: no cover - depends on the environment
            raise ImportError("RunResult.to_pandas needs pandas: pip install pandas") from e
        df = pd.DataFrame(self.timeseries)
        return df.set_index("t_s") if "t_s" in df else df


def run(spec: Spec, **overrides: Any) -> RunResult:
    """Simulate one manoeuvre spec (a TOML path, or a dict of the same keys) and return its result.

    Keyword arguments override spec keys; a double underscore stands for the dot of a nested key
    (``surface__mu=0.1`` sets ``[surface] mu``), and ``**{"surface.mu": 0.1}`` works too. Paths
    inside a dict spec resolve against the current directory. Nothing is written to disk. A spec
    with a ``[sweep]`` table is refused: use :func:`sweep`.
    """
    return RunResult(_vehsim.run_spec(**_spec_args(spec, overrides)))


class SweepResult(list):
    """The runs of a sweep in run order: dicts with ``index``, ``params`` (key -> value text),
    ``status`` (``ok``, ``failed`` or ``invalid``), ``message`` (why a run is invalid),
    ``summary`` (dict, None when invalid) and ``result`` (a RunResult with the time series when
    ``timeseries=True``, else None)."""

    def to_pandas(self):
        """One row per run: index, status, swept values, the scalar summary figures (needs pandas)."""
        try:
            import pandas as pd
        except ImportError as e:  # pragma: no cover - depends on the environment
            raise ImportError("SweepResult.to_pandas needs pandas: pip install pandas") from e
        rows = []
        for r in self:
            row = {"index": r["index"], "status": r["status"], **r["params"], "message": r["message"]}
            for k, v in (r["summary"] or {}).items():
                if v is None or isinstance(v, (bool, int, float, str)):
                    row[k] = v
            rows.append(row)
        return pd.DataFrame(rows).set_index("index")


def sweep(
    spec: Spec,
    grid: Optional[Mapping[str, Iterable[Any]]] = None,
    *,
    jobs: Optional[int] = None,
    timeseries: bool = False,
    executor: Any = None,
    shards: Optional[int] = None,
    **overrides: Any,
) -> SweepResult:
    """Run every combination of a sweep in parallel (GIL released) and return them in run order.

    The sweep is the spec's ``[sweep]`` table (dotted key -> list of values, the last key varying
    fastest), replaced by ``grid`` when given. ``jobs``: worker threads (default all cores);
    results are identical whatever the thread count. ``jobs`` is bounded as the command line
    bounds ``--jobs``: 1 to :func:`max_jobs` (4 per core); anything else raises ValueError. An
    invalid combination is kept with status ``invalid`` and its message; a spec whose every
    combination is invalid raises ValueError.

    ``executor``: a Dask ``distributed.Client`` or any ``concurrent.futures.Executor`` to run the
    sweep on, split into ``shards`` parts (default: one per Dask worker thread, or per executor
    worker; at most one per run), each part running on ``jobs`` threads (default 1 there). The
    spec is loaded here first (bad input raises before anything is submitted) and again where each
    part runs, against that process's working directory, so workers need the same files at the
    same paths. The result is the local sweep's, to the bit, whatever the shard count. A closed
    Dask client or one without workers raises ValueError; a shard that fails, reads other files
    or another vehsim, or comes back incomplete raises :class:`ShardError` naming the shard and
    its worker, and nothing is returned. Ctrl-C cancels the shards and raises KeyboardInterrupt.

    Ctrl-C stops a local sweep within a second: the runs in progress are abandoned and
    :class:`SweepInterrupted` (a KeyboardInterrupt) is raised, its ``results`` holding every run
    that finished (the rest with status ``interrupted``).
    """
    args = _spec_args(spec, overrides)
    if grid is not None:
        if not isinstance(grid, Mapping):
            raise ValueError(f"grid: expected a dict of key -> list of values, not a {type(grid).__name__}")
        args["overrides"]["sweep"] = {k.replace("__", "."): _grid_values(k, v) for k, v in grid.items()}
    records, interrupt = _sweep_records(args, jobs, timeseries, executor, shards)
    out = SweepResult()
    for raw in records:
        summary = json.loads(raw["summary_json"]) if raw["summary_json"] else None
        out.append(
            {
                "index": raw["index"],
                "params": dict(raw["params"]),
                "status": raw["status"],
                "message": raw["message"],
                "summary": summary,
                "result": RunResult(raw) if raw["timeseries"] is not None else None,
            }
        )
    if interrupt is not None:
        done = sum(r["status"] != "interrupted" for r in out)
        if isinstance(interrupt, KeyboardInterrupt):
            raise SweepInterrupted(out, done, len(out)) from None
        raise interrupt
    return out


def _sweep_records(args: Dict[str, Any], jobs: Any, timeseries: bool, executor: Any, shards: Any):
    """The raw records of a sweep in run order and the interruption to raise (or None): run here,
    or in shards on ``executor``."""
    if executor is None:
        if shards is not None:
            raise ValueError("shards: splitting a sweep needs an executor (a Dask Client or a concurrent.futures.Executor)")
        return _vehsim.sweep_spec(**args, jobs=jobs, keep_timeseries=timeseries)[:2]
    if not hasattr(executor, "submit"):
        raise ValueError(
            f"executor: a {type(executor).__name__} has no submit(); expected a Dask Client or a "
            f"concurrent.futures.Executor"
        )
    jobs = 1 if jobs is None else _shards.check_count("jobs", jobs)
    n = _shards.default_shards(executor) if shards is None else _shards.check_count("shards", shards)
    return _shards.run_shards(args, executor, n, jobs, timeseries), None


def max_jobs() -> int:
    """The most worker threads :func:`sweep` accepts: 4 per core, as ``vehsim run --jobs``."""
    return _vehsim.max_jobs()


def _grid_values(key: str, values: Any) -> List[Any]:
    """The values of one swept key as a list; a string or a mapping is not a list of values."""
    if isinstance(values, (str, bytes, Mapping)) or not isinstance(values, Iterable):
        raise ValueError(
            f"grid[{key!r}]: expected a list of values, not a {type(values).__name__} {values!r:.40}"
            f" (a single value is written [value])"
        )
    return list(values)


class SweepInterrupted(KeyboardInterrupt):
    """Ctrl-C during :func:`sweep`: a KeyboardInterrupt that keeps the sweep's finished runs.

    ``results`` is the SweepResult in run order: the runs that finished before the interrupt are
    complete (status ``ok``, ``failed`` or ``invalid``); the others have status ``interrupted``,
    no summary and no result. Nothing is written anywhere, so what is not caught is lost.
    """

    def __init__(self, results: "SweepResult", done: int, total: int):
        super().__init__(f"sweep interrupted: {done} of {total} runs finished; their results are in .results")
        self.results = results


class TyreForces(NamedTuple):
    """Forces on the tyre from the road, wheel axes: fx (N, forward), fy (N, left), mz (N m,
    counter-clockwise seen from above; 0 where the provider has no aligning moment)."""

    fx: np.ndarray
    fy: np.ndarray
    mz: np.ndarray


class Tyre:
    """One provider of a tyre file, evaluated over NumPy arrays (MFeval-style)."""

    def __init__(self, native: Any):
        self._native = native

    @classmethod
    def from_file(cls, path: Union[str, "os.PathLike[str]"], provider: str) -> "Tyre":
        """Read a tyre file (TOML, e.g. vehicles/tyres/srtt_p225_60r16.toml) and build its
        ``provider`` section: one of :data:`TYRE_MODELS`."""
        return cls(_vehsim.NativeTyre.load(_existing(path), provider))

    name = property(lambda self: self._native.name, doc="tyre name from the file")
    provider = property(lambda self: self._native.provider, doc="provider name")
    rolling_radius_m = property(lambda self: self._native.rolling_radius_m)
    unloaded_radius_m = property(lambda self: self._native.unloaded_radius_m)
    nominal_load_n = property(lambda self: self._native.nominal_load_n)
    warnings = property(lambda self: list(self._native.warnings), doc="notes from building it")

    def __repr__(self) -> str:
        return f"Tyre({self._native.path!r}, {self.provider!r})"

    def forces(
        self,
        fz: Any,
        kappa: Any,
        alpha: Any,
        camber: Any = 0.0,
        mu: Any = 1.0,
        contact_temp: Any = None,
        surface_temp: Any = -3.0,
        vx: Any = 10.0,
    ) -> TyreForces:
        """Forces for every element of the broadcast inputs; the outputs have the broadcast shape.

        fz: normal load, N (>= 0). kappa: slip ratio (omega R_e - V_x)/|V_x|, in [-1, 10].
        alpha: slip angle, rad, in [-pi/2, pi/2]. camber: inclination, rad. mu: peak friction of
        the surface (ice 0.05-0.2, dry asphalt about 1). surface_temp: bulk ice temperature, degC.
        contact_temp: contact-patch temperature, degC (default: surface_temp, no rise; the
        ATIIM-modified providers use the rise contact_temp - surface_temp). vx: forward speed of
        the wheel centre, m/s. Values outside these ranges, NaN or infinity raise ValueError
        naming the argument and its flat index.
        """
        if contact_temp is None:
            contact_temp = surface_temp
        names = ("fz", "kappa", "alpha", "camber", "vx", "mu", "surface_temp", "contact_temp")
        values = (fz, kappa, alpha, camber, vx, mu, surface_temp, contact_temp)
        arrays = []
        for name, a in zip(names, values):
            if a is None:
                raise ValueError(f"Tyre.forces: {name} is None; expected a number or an array of numbers")
            try:
                arrays.append(np.asarray(a, dtype=np.float64))
            except (TypeError, ValueError) as e:
                raise ValueError(f"Tyre.forces: {name} is not a number or an array of numbers ({e})") from None
        try:
            shape = np.broadcast_shapes(*(a.shape for a in arrays))
        except ValueError:
            shapes = ", ".join(f"{n} {a.shape}" for n, a in zip(names, arrays))
            raise ValueError(f"Tyre.forces: the inputs do not broadcast together: {shapes}") from None
        size = math.prod(shape)
        if size > MAX_TYRE_POINTS:
            raise MemoryError(
                f"Tyre.forces: {size:.3g} points ({3 * 8 * size / 1e9:.3g} GB of results) is more than the "
                f"{MAX_TYRE_POINTS:.0e} points one call evaluates; split the call"
            )
        out = [np.empty(shape, dtype=np.float64) for _ in range(3)]
        if size == 0:
            return TyreForces(*out)
        # Broadcast inputs are read chunk by chunk in C order, never expanded to the full shape.
        it = np.nditer(
            [*arrays, *out],
            flags=["external_loop", "buffered", "zerosize_ok", "refs_ok"],
            op_flags=[["readonly"]] * 8 + [["writeonly"]] * 3,
            order="C",
            buffersize=_CHUNK,
        )
        offset = 0
        with it:
            for chunk in it:
                ins = [np.ascontiguousarray(c) for c in chunk[:8]]
                fx, fy, mz = self._native.forces(*ins, offset=offset)
                chunk[8][...] = fx
                chunk[9][...] = fy
                chunk[10][...] = mz
                offset += len(fx)
        return TyreForces(*out)


#: Most points one ``Tyre.forces`` call evaluates (its three results take 24 bytes a point:
#: 2.4 GB at this limit); a larger call raises MemoryError before allocating anything.
MAX_TYRE_POINTS = 100_000_000
#: Points handed to the native evaluator at a time.
_CHUNK = 1 << 16


def atiim(scenario: Spec, **overrides: Any) -> Dict[str, Any]:
    """Evaluate an ATIIM contact-patch scenario (a TOML path such as scenarios/atiim/*.toml, or a
    dict) as ``vehsim atiim`` does, writing nothing.

    Overrides as in :func:`run` (``operating__slip_ratio=0.1``). Returns a dict: ``summary``
    (the patch figures: load_n, max_rise_k, wet_fraction, drawbar_coeff, ...), ``operating``,
    ``maps`` (2-D arrays, rows along travel from the leading edge, columns across: pressure_pa,
    rise_k, wet, sliding, film_m, mu_visc, mu, q_*_w_m2), ``drawbar`` (arrays over slip ratio),
    ``pixel_length_m`` and ``pixel_width_m``.
    """
    d = _vehsim.atiim_scenario(**_spec_args(scenario, overrides))
    d["summary"] = json.loads(d.pop("summary_json"))
    return d


def discover(
    vehicle: Union[str, "os.PathLike[str]"],
    runs: Iterable[Union[str, "os.PathLike[str]"]],
    *,
    tyre: Optional[Union[str, "os.PathLike[str]"]] = None,
    tyre_model: str = "pacejka",
    model: str = "bicycle",
    out: Optional[Union[str, "os.PathLike[str]"]] = None,
) -> Dict[str, Any]:
    """Discover effects missing from the baseline model in measured runs (``RUN.csv`` files with
    optional ``RUN.toml`` sidecars) as ``vehsim discover`` does, and return its report.json as a
    dict plus ``notices`` (remarks about the input). The report's folder is written to ``out``
    when given, else to a temporary folder that is removed.
    """
    runs = [_existing(r) for r in runs]
    args = dict(tyre=_existing(tyre) if tyre is not None else None, tyre_model=tyre_model, model=model)
    vehicle = _existing(vehicle)
    if out is not None:
        notices = _vehsim.discover_runs(vehicle, runs, os.fspath(out), **args)
        return _report(os.fspath(out), notices)
    with tempfile.TemporaryDirectory(prefix="vehsim-discover-") as tmp:
        folder = os.path.join(tmp, "out")
        notices = _vehsim.discover_runs(vehicle, runs, folder, **args)
        return _report(folder, notices)


def _report(folder: str, notices: List[str]) -> Dict[str, Any]:
    with open(os.path.join(folder, "report.json"), encoding="utf-8") as f:
        report = json.load(f)
    report["notices"] = list(notices)
    return report


from .simulation import OBSERVATION, OBSERVATION_DTYPE, Simulation  # noqa: E402  (needs _spec_args)
