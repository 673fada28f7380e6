#!/usr/bin/env bash
# Builds the polydem Python package and runs its tests, non-interactively, from any directory:
#   1. a virtual environment under target/python-venv (created once, reused);
#   2. `pip install ./python[test]`: maturin builds the extension in release; pytest and mypy (for
#      stubtest) come along;
#   3. the `polydem` binary, from which the tests take their Rust references (`polydem run`,
#      `polydem contact`);
#   4. pytest over python/tests (extra arguments are passed to pytest).
# PYTHON chooses the interpreter that creates the environment (default: python3, 3.9 or newer).
set -euo pipefail

repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$repo"
venv="$repo/target/python-venv"

if [ ! -x "$venv/bin/python" ]; then
    "${PYTHON:-python3}" -m venv "$venv"
fi
export PIP_DISABLE_PIP_VERSION_CHECK=1 PIP_NO_INPUT=1 PIP_ROOT_USER_ACTION=ignore
"$venv/bin/python" -m pip install --quiet "./python[test]"
cargo build --release --quiet -p polydem-cli

# Run from the repository root, where no `polydem/` directory shadows the installed package.
POLYDEM_BIN="$repo/target/release/polydem" exec "$venv/bin/python" -m pytest -q python/tests "$@"
