"""Sweeps on an executor: a real Dask ``distributed.LocalCluster`` of 2 worker processes, and the
standard library's executors. The reference is the local ``vehsim.sweep`` of the same spec:
the summaries (as JSON text and as the pandas table) and every time-series channel must be the
same bytes, whatever the shard count and the threads per shard. Bad input: a closed client, a
cluster without workers, a shut-down executor, workers that read another spec or none, a shard
that does not finish: each raises an error naming what failed, and no result is returned.
"""

import concurrent.futures
import concurrent.futures.process
import json
import os
import shutil
import signal
import threading
import time

import numpy as np
import pytest

import vehsim
from conftest import ROOT

distributed = pytest.importorskip("distributed", reason="distributed is not installed (pip install vehsim[dask])")

SINE = "maneuvers/sine_steer.toml"
GRID = {"surface.mu": [0.1, 0.3], "maneuver.speed_mps": [8.0, 10.0, 12.0]}


@pytest.fixture(autouse=True)
def _in_root(monkeypatch):
    monkeypatch.chdir(ROOT)


@pytest.fixture(scope="module")
def client():
    """A Dask client of a LocalCluster: 2 worker processes of 1 thread, started in the project
    root (their working directory, where relative spec paths resolve)."""
    here = os.getcwd()
    os.chdir(ROOT)
    try:
        cluster = distributed.LocalCluster(
            n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0", silence_logs=40
        )
    finally:
        os.chdir(here)
    c = distributed.Client(cluster)
    yield c
    c.close()
    cluster.close()


def fingerprint(result):
    """The bytes a sweep result is judged by: its summaries as JSON, its pandas table as CSV and
    every run's time series channel by channel."""
    summaries = json.dumps([(r["index"], r["status"], r["params"], r["summary"]) for r in result], sort_keys=True)
    table = result.to_pandas().to_csv()
    series = [
        (r["index"], name, np.ascontiguousarray(a).tobytes())
        for r in result
        if r["result"] is not None
        for name, a in sorted(r["result"].timeseries.items())
    ]
    return summaries, table, series


@pytest.fixture(scope="module")
def local():
    os.chdir(ROOT)
    return vehsim.sweep(SINE, GRID, jobs=2, timeseries=True)


def test_dask_sweep_is_the_local_sweep_to_the_bit(client, local):
    with distributed.get_task_stream(client) as tasks:
        res = vehsim.sweep(SINE, GRID, timeseries=True, executor=client)
    ran = [t for t in tasks.data if t["key"].startswith("_run_shard")]
    # one task per worker thread (2 shards), run in the worker processes
    assert len(ran) == 2 and {t["worker"] for t in ran} <= set(client.nthreads())
    assert [r["index"] for r in res] == list(range(6))
    assert all(r["status"] == "ok" for r in res)
    assert len(res[5]["result"]["t_s"]) > 100
    a, b = fingerprint(res), fingerprint(local)
    assert a[0] == b[0] and a[1] == b[1]
    assert len(a[2]) == 6 * len(vehsim.TIMESERIES_COLUMNS) and a[2] == b[2]


@pytest.mark.parametrize("shards,jobs", [(1, 1), (3, 2), (6, 1), (50, 1)])
def test_dask_results_do_not_depend_on_shard_or_thread_count(client, local, shards, jobs):
    res = vehsim.sweep(SINE, GRID, timeseries=True, executor=client, shards=shards, jobs=jobs)
    assert fingerprint(res) == fingerprint(local)


def test_any_executor_gives_the_local_sweep(local):
    with concurrent.futures.ThreadPoolExecutor(max_workers=2) as ex:
        res = vehsim.sweep(SINE, GRID, timeseries=True, executor=ex, shards=4)
    assert fingerprint(res) == fingerprint(local)
    # a dict spec with an override, summaries only, and an invalid combination kept in place
    spec = {
        "name": "dict_sine",
        "vehicle": "vehicles/sedan.toml",
        "tyre_model": "linear",
        "surface": {"mu": 0.15, "temperature_c": -3.0},
        "maneuver": {"kind": "sine_steer", "speed_mps": 10.0, "steer_amplitude_deg": 10, "period_s": 5.0},
    }
    grid = {"surface.mu": [0.15, -1.0, 0.3]}
    with concurrent.futures.ThreadPoolExecutor(max_workers=2) as ex:
        res = vehsim.sweep(spec, grid, executor=ex, shards=2, duration_s=2.0)
    ref = vehsim.sweep(spec, grid, duration_s=2.0)
    assert [r["status"] for r in res] == ["ok", "invalid", "ok"]
    assert fingerprint(res) == fingerprint(ref)


def test_closed_client_and_cluster_without_workers_are_refused(client):
    closed = distributed.Client(client.scheduler.address)
    closed.close()
    with pytest.raises(ValueError, match="the Dask client is 'closed', not running"):
        vehsim.sweep(SINE, GRID, executor=closed)
    with distributed.LocalCluster(n_workers=0, processes=False, dashboard_address=":0") as empty:
        with distributed.Client(empty) as c:
            t0 = time.perf_counter()
            with pytest.raises(ValueError, match=r"has no workers; start workers or wait for them"):
                vehsim.sweep(SINE, GRID, executor=c)
            assert time.perf_counter() - t0 < 10  # refused, not left waiting for a worker


def test_shut_down_executor_and_bad_arguments_are_refused():
    ex = concurrent.futures.ThreadPoolExecutor(max_workers=1)
    ex.shutdown()
    with pytest.raises(vehsim.ShardError, match=r"shard 1 of 1 was refused by the executor ThreadPoolExecutor"):
        vehsim.sweep(SINE, GRID, executor=ex)
    with concurrent.futures.ThreadPoolExecutor(1) as good:
        for bad in (0, -1, True, 2.5, "2"):
            with pytest.raises(ValueError, match=r"shards: .* is not allowed; expected a whole number >= 1"):
                vehsim.sweep(SINE, GRID, executor=good, shards=bad)
        with pytest.raises(ValueError, match=r"jobs: 0 is not allowed; expected a whole number >= 1"):
            vehsim.sweep(SINE, GRID, executor=good, jobs=0)
    with pytest.raises(ValueError, match="splitting a sweep needs an executor"):
        vehsim.sweep(SINE, GRID, shards=2)
    with pytest.raises(ValueError, match="has no submit"):
        vehsim.sweep(SINE, GRID, executor=object())
    # bad input is refused here, before anything is submitted
    with pytest.raises(ValueError, match="every sweep combination is invalid"):
        vehsim.sweep(SINE, {"surface.mu": [-1.0]}, executor=ex)


def test_workers_that_read_another_spec_or_none_are_named(client, tmp_path, monkeypatch):
    # The client reads maneuvers/sine_steer.toml in tmp_path (another duration); the workers,
    # started in the project root, read the project's file at the same relative path.
    (tmp_path / "maneuvers").mkdir()
    text = (ROOT / SINE).read_text().replace('vehicle = "../vehicles/', f'vehicle = "{ROOT}/vehicles/')
    assert f"{ROOT}/vehicles/" in text
    (tmp_path / SINE).write_text(text.replace("duration_s = 10.0", "duration_s = 3.0", 1))
    (tmp_path / "only_here.toml").write_text(text)
    monkeypatch.chdir(tmp_path)
    with pytest.raises(vehsim.ShardError, match=r"shard [12] of 2 on Dask worker tcp://\S+ ran another batch") as e:
        vehsim.sweep(SINE, GRID, executor=client)
    assert "batch digest" in str(e.value) and "no result was returned" in str(e.value)
    assert e.value.shard[1] == 2
    with pytest.raises(vehsim.ShardError, match=r"failed: ValueError: only_here.toml: file not found") as e:
        vehsim.sweep("only_here.toml", GRID, executor=client)
    assert f"(working directory there: {ROOT})" in str(e.value)
    shutil.rmtree(tmp_path / "maneuvers")


class _LosingExecutor(concurrent.futures.Executor):
    """An executor whose shard 2 is lost (its worker died): its future holds an exception."""

    def __init__(self):
        self.calls = 0

    def submit(self, fn, *args, **kwargs):
        self.calls += 1
        f = concurrent.futures.Future()
        if self.calls == 2:
            f.set_exception(concurrent.futures.process.BrokenProcessPool("a worker process died"))
        else:
            f.set_result(fn(*args, **kwargs))
        return f


def test_a_shard_that_does_not_finish_fails_the_sweep():
    with pytest.raises(vehsim.ShardError, match=r"shard 2 of 3 did not finish: BrokenProcessPool: a worker process died"):
        vehsim.sweep(SINE, GRID, executor=_LosingExecutor(), shards=3)


class _StuckExecutor(concurrent.futures.Executor):
    """Queues every shard and never runs one: the sweep waits until Ctrl-C."""

    def __init__(self):
        self.futures = []

    def submit(self, fn, *args, **kwargs):
        self.futures.append(concurrent.futures.Future())
        return self.futures[-1]


def test_ctrl_c_while_waiting_cancels_the_shards():
    ex = _StuckExecutor()
    ctrl_c = threading.Timer(0.5, os.kill, (os.getpid(), signal.SIGINT))
    ctrl_c.start()
    t0 = time.perf_counter()
    with pytest.raises(KeyboardInterrupt):
        vehsim.sweep(SINE, GRID, executor=ex, shards=3)
    ctrl_c.join()
    assert time.perf_counter() - t0 < 5
    assert len(ex.futures) == 3 and all(f.cancelled() for f in ex.futures)


class _SwappingExecutor(concurrent.futures.ThreadPoolExecutor):
    """Runs shard 2's task where shard 1 was asked for: a part with the right digest and the
    wrong runs."""

    def submit(self, fn, args, k, n, *rest):
        return super().submit(fn, args, 2 if k == 1 else k, n, *rest)


def test_a_shard_with_other_runs_fails_the_sweep():
    with _SwappingExecutor(1) as ex:
        with pytest.raises(vehsim.ShardError, match=r"shard 1 of 3 on .* returned runs \[1, 4\] where runs \[0, 3\]"):
            vehsim.sweep(SINE, GRID, executor=ex, shards=3)
