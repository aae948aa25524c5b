"""Shared fixtures: the repository root and the ``vehsim`` command-line binary.

Tests that compare the package with the command line need the binary. ``python/test.sh`` (CI)
builds it and sets VEHSIM_BIN and VEHSIM_REQUIRE_CLI=1, so there they fail rather than skip when
it is missing; run by hand, they look for target/release/vehsim and skip with a message when it
is not built.
"""

import os
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="session")
def root() -> Path:
    return ROOT


@pytest.fixture(scope="session")
def cli():
    """A function running the vehsim binary with arguments; it fails on a non-zero exit."""
    exe = Path(os.environ.get("VEHSIM_BIN", ROOT / "target" / "release" / "vehsim"))
    if not exe.is_file():
        msg = f"the vehsim binary {exe} is not built (cargo build --release); set VEHSIM_BIN to use another"
        if os.environ.get("VEHSIM_REQUIRE_CLI") == "1":
            pytest.fail(msg)
        pytest.skip(msg)

    def call(*args, cwd=ROOT):
        r = subprocess.run([str(exe), *map(str, args)], cwd=cwd, capture_output=True, text=True)
        assert r.returncode == 0, f"vehsim {' '.join(map(str, args))} exited {r.returncode}: {r.stderr}"
        return r

    return call
