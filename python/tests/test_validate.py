"""The validation suite from Python: the rows of `summary.csv` for the cases run, and a clear error away
from a source checkout."""

import pytest

import polydem


def test_validate_returns_the_rows_of_the_cases_run(repo, tmp_path):
    rows = polydem.validate(["restitution"], checkout=repo, out=tmp_path, quiet=True)
    assert rows and {r["case"] for r in rows} == {"restitution"}, rows[:2]
    failing = [r for r in rows if not r["pass"]]
    assert not failing, f"failing rows: {failing}"
    with open(tmp_path / "summary.csv") as f:
        assert len(f.read().splitlines()) == len(rows) + 1, "one row per line of summary.csv"
    assert all(isinstance(r["value"], float) for r in rows)


def test_validate_refuses_an_unknown_profile_and_a_missing_checkout(tmp_path):
    with pytest.raises(ValueError, match='profile: expected "quick" or "full"'):
        polydem.validate(["restitution"], profile="fast")
    with pytest.raises(FileNotFoundError, match="no polydem source checkout at or above"):
        polydem.find_checkout(tmp_path)
