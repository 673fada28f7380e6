"""Shared fixtures: the repository root (for scenes/) and the `polydem` command line (for references
computed by the Rust side)."""

import os
import pathlib
import subprocess

import pytest

REPO = pathlib.Path(__file__).resolve().parents[2]


@pytest.fixture(scope="session")
def repo() -> pathlib.Path:
    return REPO


@pytest.fixture(scope="session")
def polydem_bin() -> pathlib.Path:
    """The `polydem` binary: $POLYDEM_BIN, else target/release/polydem (built by python/run_tests.sh).
    A missing binary fails the tests that need it: their reference cannot be computed otherwise."""
    path = pathlib.Path(os.environ.get("POLYDEM_BIN", REPO / "target" / "release" / "polydem"))
    if not path.is_file():
        pytest.fail(
            f"the polydem binary is needed for the Rust reference and is missing at {path} "
            "(build it with `cargo build --release -p polydem-cli` or set POLYDEM_BIN)"
        )
    return path


def run(cmd, **kwargs) -> subprocess.CompletedProcess:
    """Runs a command, failing the test with its output when it fails."""
    done = subprocess.run(cmd, capture_output=True, text=True, **kwargs)
    if done.returncode != 0:
        pytest.fail(f"{cmd} exited with {done.returncode}\nstdout:\n{done.stdout}\nstderr:\n{done.stderr}")
    return done
