"""Running the validation suite (``cargo validate``) from Python and reading its summary rows.

The suite needs a source checkout: its cases read ``reference/`` and ``scenes/`` and are built from the
``validation/`` crate with cargo. An installed wheel does not carry them; ``validate`` then says so.
"""

from __future__ import annotations

import csv
import os
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import Dict, List, Optional, Sequence, Union

_StrPath = Union[str, "os.PathLike[str]"]


def find_checkout(start: Optional[_StrPath] = None) -> Path:
    """The polydem source checkout at or above ``start`` (default: the current directory): the first
    directory that holds ``validation/Cargo.toml``, ``reference/`` and ``scenes/``. Raises
    ``FileNotFoundError`` saying what is missing when there is none."""
    here = Path(start if start is not None else os.getcwd()).resolve()
    for d in (here, *here.parents):
        if (d / "validation" / "Cargo.toml").is_file() and (d / "reference").is_dir() and (d / "scenes").is_dir():
            return d
    raise FileNotFoundError(
        f"no polydem source checkout at or above {here}: the validation suite needs one "
        "(its validation/, reference/ and scenes/ directories); "
        "clone it and pass checkout=PATH or run from inside it"
    )


def _rows(summary: Path, cases: Optional[Sequence[str]]) -> List[Dict[str, object]]:
    rows: List[Dict[str, object]] = []
    with open(summary, newline="") as f:
        for r in csv.DictReader(f):
            if cases and r["case"] not in cases:
                continue
            rows.append(
                {
                    "case": r["case"],
                    "metric": r["metric"],
                    "value": float(r["value"]),
                    "target": r["target"],
                    "unit": r["unit"],
                    "pass": r["pass"] == "true",
                }
            )
    return rows


def validate(
    cases: Optional[Sequence[str]] = None,
    profile: str = "quick",
    *,
    checkout: Optional[_StrPath] = None,
    out: Optional[_StrPath] = None,
    build_profile: str = "release",
    quiet: bool = False,
) -> List[Dict[str, object]]:
    """Runs validation cases (default: the default run, as ``cargo validate``) in the ``profile``
    ("quick" or "full") and returns their rows of ``summary.csv`` as dicts: ``case``, ``metric``,
    ``value`` (float), ``target`` (text, e.g. ``"<= 1.000000e-10"``), ``unit`` and ``pass`` (bool).

    The suite is built with cargo's ``build_profile`` ("release" shares the build of ``cargo test
    --release``; ``cargo validate`` itself uses "speed") in the checkout found by ``find_checkout``.
    Reports are written to ``out`` (default: a temporary directory, so the checkout's committed
    ``reports/`` stay as they are). The suite's output goes to standard error unless ``quiet``. A failing
    row is returned with ``pass`` False; ``RuntimeError`` (with the end of the suite's output) is raised
    only when the suite produced no rows for the cases asked (an unknown case, a build error)."""
    if profile not in ("quick", "full"):
        raise ValueError(f'profile: expected "quick" or "full", got {profile!r}')
    root = find_checkout(checkout)
    cases = list(cases) if cases is not None else None
    with tempfile.TemporaryDirectory(prefix="polydem-validate-") as tmp:
        reports = Path(out) if out is not None else Path(tmp)
        command = ["cargo", "run", "--quiet", "--profile", build_profile, "-p", "polydem-validation",
                   "--bin", "validate", "--", f"--{profile}", "--out", str(reports), *(cases or [])]
        done = subprocess.run(command, cwd=root, stdin=subprocess.DEVNULL,
                              stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        if not quiet:
            sys.stderr.write(done.stdout)
        summary = reports / "summary.csv"
        rows = _rows(summary, cases) if summary.is_file() else []
        if not rows:
            tail = "\n".join(done.stdout.splitlines()[-20:])
            raise RuntimeError(
                f"the validation suite gave no rows (exit status {done.returncode}): {' '.join(command)}\n{tail}"
            )
        return rows
