"""A sweep split into shards and run on an executor: a Dask ``distributed.Client`` or any
``concurrent.futures.Executor``.

Shard K of N holds the runs whose index mod N is K - 1, the parts ``vehsim run --shard K/N``
writes. Each shard runs as one task (``_run_shard``) that loads the spec where it runs, executes
its runs and returns their raw records with the batch digest it computed (SHA-256 over the vehsim
version, the spec as parsed with its overrides and the vehicle, tyre and ``.tir`` files; the
digest ``vehsim merge`` compares). The caller loads the spec first, so bad input is refused
before anything is submitted, and accepts the parts only when every shard finished, reported the
caller's digest and returned exactly its runs: the records are then put back in run order, the
same records a local :func:`vehsim.sweep` returns, to the bit. Anything else raises
:class:`ShardError` naming the shard, where it ran and what failed; nothing partial is returned.

Paths are resolved where the shards run: a relative spec path (and the relative paths inside a
dict spec) against the worker's working directory, so workers need the project's files at the
same place (a shared file system); a worker that reads other files is caught by the digest.
"""

from __future__ import annotations

import concurrent.futures
import os
import socket
from typing import Any, Dict, Iterator, List, Optional, Tuple

from . import _vehsim


class ShardError(RuntimeError):
    """A shard of a distributed sweep failed, ran another batch or came back incomplete.

    ``shard`` is (K, N); ``where`` names the worker (Dask address, or host and process id) when
    known. No result is returned for the sweep: every shard must finish for the sweep to finish.
    """

    def __init__(self, shard: Tuple[int, int], where: Optional[str], what: str):
        k, n = shard
        place = f" on {where}" if where else ""
        super().__init__(f"vehsim.sweep: shard {k} of {n}{place} {what}; no result was returned (every shard must finish)")
        self.shard = shard
        self.where = where


def _where() -> str:
    """This process as a worker: the Dask worker's address when inside one, else host and pid."""
    try:
        from distributed import get_worker

        return f"Dask worker {get_worker().address}"
    except Exception:  # not inside a Dask worker, or distributed is not installed
        return f"host {socket.gethostname()} pid {os.getpid()}"


def _run_shard(args: Dict[str, Any], k: int, n: int, jobs: Optional[int], timeseries: bool) -> Dict[str, Any]:
    """The task one worker runs: shard ``k`` of ``n`` of the sweep ``args`` (native arguments).

    Never raises: an error comes back as ``error`` (its type and message), so the caller can
    name the shard and the worker whatever the executor does with exceptions.
    """
    where = _where()
    try:
        records, interrupt, digest = _vehsim.sweep_spec(**args, jobs=jobs, keep_timeseries=timeseries, shard=(k, n))
    except BaseException as e:  # noqa: BLE001 - reported to the caller with the shard's name
        # relative paths resolve against the worker's working directory: name it
        return {"where": where, "error": f"{type(e).__name__}: {e} (working directory there: {os.getcwd()})"}
    if interrupt is not None:
        return {"where": where, "error": f"interrupted on the worker ({type(interrupt).__name__})"}
    return {"where": where, "error": None, "digest": digest, "records": records}


def is_dask_client(executor: Any) -> bool:
    """True for a ``distributed.Client`` (recognised without importing distributed)."""
    return type(executor).__module__.split(".")[0] == "distributed" and hasattr(executor, "nthreads")


def _dask_threads(client: Any) -> int:
    """Worker threads of a running Dask client's cluster; a closed client or an empty cluster is
    a ValueError saying so (tasks submitted to a cluster without workers would wait forever)."""
    status = str(getattr(client, "status", "unknown"))
    if status != "running":
        raise ValueError(f"executor: the Dask client is {status!r}, not running; connect a new Client to the cluster")
    try:
        threads = client.nthreads()
    except Exception as e:  # the scheduler is gone
        raise ValueError(f"executor: the Dask client cannot reach its scheduler ({type(e).__name__}: {e})") from None
    if not threads:
        addr = getattr(getattr(client, "scheduler", None), "address", "?")
        raise ValueError(
            f"executor: the Dask cluster (scheduler {addr}) has no workers; start workers or wait for them "
            f"(client.wait_for_workers(n)) before sweeping"
        )
    return sum(threads.values())


def default_shards(executor: Any) -> int:
    """Shards when not given: one per Dask worker thread, else the executor's workers (its
    ``_max_workers``, as ThreadPoolExecutor and ProcessPoolExecutor keep it), else one per core."""
    if is_dask_client(executor):
        return _dask_threads(executor)
    n = getattr(executor, "_max_workers", None)
    return n if isinstance(n, int) and n > 0 else (os.cpu_count() or 1)


def check_count(name: str, value: Any) -> int:
    """A whole number >= 1 (``shards``, ``jobs``), or a ValueError naming the argument."""
    if isinstance(value, bool) or not isinstance(value, int) or value < 1:
        raise ValueError(f"{name}: {value!r:.40} is not allowed; expected a whole number >= 1")
    return value


def _submit(executor: Any, k: int, n: int, task: tuple) -> Any:
    """Submit shard ``k``; an executor that refuses it (shut down, closed) is a ShardError."""
    try:
        if is_dask_client(executor):
            return executor.submit(_run_shard, *task, pure=False)
        return executor.submit(_run_shard, *task)
    except RuntimeError as e:
        raise ShardError((k, n), None, f"was refused by the executor {type(executor).__name__} ({e})") from None


def _cancel(futures: List[Any]) -> None:
    for f in futures:
        try:
            f.cancel()
        except Exception:  # a future of a closed client: nothing left to cancel
            pass


def _collect(k: int, n: int, future: Any, digest: str, total: int) -> List[Dict[str, Any]]:
    """Shard ``k``'s records after checking the part: it finished, ran this batch and returned
    exactly its runs."""
    try:
        part = future.result()
    except KeyboardInterrupt:
        raise
    except BaseException as e:  # noqa: BLE001 - the worker died, the task was lost or cancelled
        raise ShardError((k, n), None, f"did not finish: {type(e).__name__}: {e}") from None
    where = part.get("where")
    if part.get("error"):
        raise ShardError((k, n), where, f"failed: {part['error']}")
    if part["digest"] != digest:
        raise ShardError(
            (k, n),
            where,
            "ran another batch: the spec, the vehicle, tyre or .tir files it read there, or its vehsim version, "
            f"differ from this process's (batch digest {part['digest'][:12]}... there, {digest[:12]}... here)",
        )
    got = [r["index"] for r in part["records"]]
    want = list(range(k - 1, total, n))
    if got != want:
        raise ShardError((k, n), where, f"returned runs {got[:8]} where runs {want[:8]} (of {len(want)}) were expected")
    return part["records"]


def run_shards(
    args: Dict[str, Any], executor: Any, shards: int, jobs: Optional[int], timeseries: bool
) -> List[Dict[str, Any]]:
    """Run the sweep ``args`` as ``shards`` tasks on ``executor`` and return the raw records of
    every run in run order. Ctrl-C cancels the shards not finished and raises KeyboardInterrupt."""
    digest, total, _name = _vehsim.batch_identity(**args)
    n = min(shards, total)
    futures: List[Any] = []
    try:
        for k in range(1, n + 1):
            futures.append(_submit(executor, k, n, (args, k, n, jobs, timeseries)))
        records: List[Optional[Dict[str, Any]]] = [None] * total
        shard_of = {id(f): k for k, f in enumerate(futures, start=1)}
        # as they finish, so that a failed shard stops the sweep at once
        for f in _as_completed(executor, futures):
            k = shard_of[id(f)]
            for r in _collect(k, n, f, digest, total):
                records[r["index"]] = r
    except BaseException:
        _cancel(futures)
        raise
    return records  # type: ignore[return-value]  # every index filled: _collect checked each part


def _as_completed(executor: Any, futures: List[Any]) -> Iterator[Any]:
    """The futures in the order they finish (Dask's own iterator for a Dask client's futures)."""
    if is_dask_client(executor):
        from distributed import as_completed

        return iter(as_completed(futures))
    return concurrent.futures.as_completed(futures)
