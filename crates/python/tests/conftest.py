"""Shared paths and helpers of the fppm module's tests.

The tests run against the installed module (`crates/python/ci.sh` builds and installs it) and
compare it with the `fppm` command of the same checkout, `target/release/fppm` (or $FPPM_BIN).
Real public scenes are read in place from `../shared/scenes` beside the checkout.
"""

import os
import pathlib
import subprocess

import pytest

REPO = pathlib.Path(__file__).resolve().parents[3]
SHARED = REPO.parent / "shared" / "scenes"
SCENES = REPO / "scenes"


def fppm_bin() -> pathlib.Path:
    """The fppm command built from this checkout; the suite fails (not skips) without it."""
    path = pathlib.Path(os.environ.get("FPPM_BIN", REPO / "target" / "release" / "fppm"))
    if not path.exists():
        pytest.fail(f"{path} is missing: run `cargo build --release -p cli` (ci.sh does)")
    return path


def run_cli(*args: str) -> subprocess.CompletedProcess:
    """Runs the fppm command; fails the test on a non-zero exit, showing stderr."""
    done = subprocess.run(
        [str(fppm_bin()), *args], capture_output=True, text=True, cwd=REPO, check=False
    )
    assert done.returncode == 0, f"fppm {' '.join(args)}: {done.stderr}"
    return done


@pytest.fixture
def cli():
    return run_cli
