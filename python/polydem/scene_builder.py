"""Scenes built in Python: rows of ``[[body]]`` tables from per-body columns.

A scene dict has the shape of the scene file (``docs/scene-format.md``); ``Scene.from_dict`` reads it
through the engine's scene builder. ``bodies`` turns columns (numpy arrays with one row per body) into the
list of body tables the dict holds under ``"body"``.
"""

from __future__ import annotations

from typing import Any, Dict, List, Sequence, Union

import numpy as np


def bodies(name: Union[str, Sequence[str]], count: Union[int, None] = None, **fields: Any) -> List[Dict[str, Any]]:
    """Body tables from columns. ``name`` is a list of N names, or a prefix (then ``count`` = N gives
    the names ``prefix0`` … ``prefixN-1``). Every other keyword is a field of ``[[body]]``: a **list or
    numpy array** is a column, one entry (or row, for a vector) per body, whose first axis must have
    length N; anything else — a string, a number, a bool or a **tuple** (a vector) — is the same for every
    body. ``bodies("grain", count=len(x), shape="rock", material="granite", position=x)`` gives N tables.
    Raises ``ValueError`` naming the field whose column has the wrong length."""
    if isinstance(name, str):
        if count is None:
            raise ValueError("name: a prefix needs count= (the number of bodies)")
        names = [f"{name}{i}" for i in range(count)]
    else:
        names = list(name)
        if count is not None and count != len(names):
            raise ValueError(f"count: {count}, but {len(names)} names were given")
    n = len(names)
    columns: Dict[str, Any] = {}
    constants: Dict[str, Any] = {}
    for key, value in fields.items():
        if isinstance(value, (list, np.ndarray)):
            column = np.asarray(value) if isinstance(value, np.ndarray) else value
            if len(column) != n:
                raise ValueError(f"{key}: a column of {len(column)} entries for {n} bodies")
            columns[key] = column
        elif value is not None:
            constants[key] = list(value) if isinstance(value, tuple) else value
    rows = []
    for i, body_name in enumerate(names):
        row: Dict[str, Any] = {"name": body_name}
        row.update(constants)
        for key, column in columns.items():
            entry = column[i]
            row[key] = entry.tolist() if isinstance(entry, np.ndarray) else entry
        rows.append(row)
    return rows
