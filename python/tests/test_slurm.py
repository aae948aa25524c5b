"""The README's Slurm recipe run for real: a single-node Slurm (scripts/slurm_single_node.sh:
munged, slurmctld and slurmd from the distribution's packages, installed with apt-get when
missing) runs scripts/slurm_sweep.sh, a 2-task ``sbatch --wait`` job array of ``vehsim run
--shard K/2`` followed by ``vehsim merge``; the merged folder must hold the bytes of a local
``vehsim run``. A task that dies must be named with its exit code and leave nothing merged.

python/test.sh (CI) sets VEHSIM_REQUIRE_SLURM=1: there a cluster that cannot start fails the
test with the reason; run by hand without it (not root, no Slurm), the tests skip with the reason.
"""

import os
import shutil
import subprocess
import tempfile
from pathlib import Path

import pytest

from conftest import ROOT

SPEC = "maneuvers/dlc_sweep.toml"
START = ROOT / "scripts" / "slurm_single_node.sh"
SWEEP = ROOT / "scripts" / "slurm_sweep.sh"


@pytest.fixture(scope="module")
def slurm():
    """Environment for Slurm's commands pointing at a throwaway single-node cluster; the daemons
    are stopped and the folder removed when the module's tests end, however they end. (Its own
    folder under the system's temporary folder: munged needs every folder above its socket open
    to all, which pytest's tmp_path is not.)"""
    d = Path(tempfile.mkdtemp(prefix="vehsim-slurm-"))
    r = subprocess.run(["bash", str(START), "start", str(d)], capture_output=True, text=True)
    try:
        if r.returncode != 0:
            msg = f"a single-node Slurm cannot start here: {r.stderr.strip()}"
            if os.environ.get("VEHSIM_REQUIRE_SLURM") == "1":
                pytest.fail(msg)
            pytest.skip(msg + " (python/test.sh sets VEHSIM_REQUIRE_SLURM=1 and fails instead)")
        yield {**os.environ, "SLURM_CONF": str(d / "slurm.conf")}
    finally:
        subprocess.run(["bash", str(START), "stop", str(d)], capture_output=True, text=True)
        shutil.rmtree(d, ignore_errors=True)


@pytest.fixture(scope="module")
def vehsim_bin():
    exe = Path(os.environ.get("VEHSIM_BIN", ROOT / "target" / "release" / "vehsim"))
    if not exe.is_file():
        msg = f"the vehsim binary {exe} is not built (cargo build --release)"
        if os.environ.get("VEHSIM_REQUIRE_CLI") == "1":
            pytest.fail(msg)
        pytest.skip(msg)
    return exe


def files(folder: Path):
    """Every file under ``folder``: relative path -> bytes."""
    return {p.relative_to(folder).as_posix(): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


def test_slurm_array_recipe_merges_to_the_bytes_of_a_local_run(slurm, vehsim_bin, tmp_path):
    out = tmp_path / "cluster"
    env = {**slurm, "VEHSIM_BIN": str(vehsim_bin)}
    r = subprocess.run(["bash", str(SWEEP), SPEC, "2", str(out)], cwd=ROOT, env=env, capture_output=True, text=True)
    assert r.returncode == 0, f"slurm_sweep.sh exited {r.returncode}: {r.stderr}"
    assert "merged 2 shards" in r.stdout
    # both shards were written by Slurm array tasks (one output file each)
    logs = sorted(p.name for p in (out / "slurm").iterdir())
    assert len(logs) == 2 and logs[0].endswith("_1.out") and logs[1].endswith("_2.out"), logs
    assert (out / "dlc_sweep.shard-1-of-2" / "shard.json").is_file()
    assert (out / "dlc_sweep.shard-2-of-2" / "shard.json").is_file()
    local = tmp_path / "local"
    r = subprocess.run([str(vehsim_bin), "run", SPEC, "--quiet", "--out", str(local)], cwd=ROOT, capture_output=True)
    assert r.returncode == 0, r.stderr
    merged, ref = files(out / "dlc_sweep"), files(local / "dlc_sweep")
    assert sorted(merged) == sorted(ref)
    assert len(ref) > 6 * 2 and "summary.csv" in ref and "run_0005/timeseries.csv" in ref
    different = [name for name in ref if merged[name] != ref[name]]
    assert not different, f"files differ from the local run: {different}"


def test_slurm_task_that_dies_is_named_and_nothing_is_merged(slurm, vehsim_bin, tmp_path):
    # vehsim, except in array task 2, which is killed as a node's out-of-memory killer would
    wrapper = tmp_path / "vehsim-task2-killed"
    wrapper.write_text(
        "#!/bin/sh\n"
        'if [ "${SLURM_ARRAY_TASK_ID:-}" = 2 ]; then echo "task 2 killed" >&2; kill -9 $$; fi\n'
        f'exec "{vehsim_bin}" "$@"\n'
    )
    wrapper.chmod(0o755)
    out = tmp_path / "cluster"
    env = {**slurm, "VEHSIM_BIN": str(wrapper)}
    r = subprocess.run(["bash", str(SWEEP), SPEC, "2", str(out)], cwd=ROOT, env=env, capture_output=True, text=True)
    assert r.returncode == 1, r.stderr
    assert "nothing merged" in r.stderr
    assert "task 2 (shard 2/2): FAILED, exit code 137" in r.stderr, r.stderr
    assert "task 1 (shard" not in r.stderr
    assert "task 2 killed" in r.stderr  # the task's own output, quoted
    assert (out / "dlc_sweep.shard-1-of-2").is_dir() and not (out / "dlc_sweep").exists()
    # merging what is there by hand is refused too, and writes nothing
    r = subprocess.run(
        [str(vehsim_bin), "merge", str(out / "dlc_sweep.shard-1-of-2")], cwd=ROOT, capture_output=True, text=True
    )
    assert r.returncode == 2
    assert "incomplete: shard(s) 2 of 2 missing" in r.stderr
    assert sorted(p.name for p in out.iterdir()) == ["dlc_sweep.shard-1-of-2", "slurm"]
