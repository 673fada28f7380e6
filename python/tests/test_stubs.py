"""The type stubs match the module: mypy's stubtest compares every public name, signature and class of
polydem/__init__.pyi with what the compiled module exposes."""

import subprocess
import sys


def test_stubs_match_the_module():
    done = subprocess.run(
        [sys.executable, "-m", "mypy.stubtest", "polydem"], capture_output=True, text=True, cwd="/"
    )
    assert done.returncode == 0, f"stubtest found differences:\n{done.stdout}\n{done.stderr}"
