"""autobal from Python: simulate a scene, run a study, read the design tables.

Each call runs the autobal library's own code (the code behind the ``study``
command), not a subprocess::

    import autobal
    run = autobal.simulate("scenes/three_balls.toml")
    run.t, run.r, run.angles, run.bearing_x  # NumPy arrays
    run.metrics["settling_revs"]  # the same numbers as `study simulate --json`
    study = autobal.run_study("studies/three_balls.toml", threads=2, overwrite=True)
    study.summary, study.decision.text

Bad input raises :class:`InputError` with the message the command line
prints and the dotted key it names (``error.key``).
"""

from __future__ import annotations

import json
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Iterable, Mapping, Optional, Union

import numpy as np
import polars as pl

from . import _native

__all__ = ["InputError", "Run", "Study", "Decision", "simulate", "run_study", "design", "version"]

Source = Union[str, os.PathLike, Mapping[str, Any]]


class InputError(ValueError):
    """Bad input, as the ``study`` command's exit-2 errors: ``str(error)``
    is the same message, ``error.key`` the dotted key it names (or None)."""

    def __init__(self, message: str, key: Optional[str] = None):
        super().__init__(message)
        self.key = key


def _native_call(function, *args, **kwargs):
    """Call into the library, raising :class:`InputError` for bad input."""
    try:
        return function(*args, **kwargs)
    except _native.InputError as error:
        message, key = error.args
        raise InputError(message, key) from None


def _text_of(source: Source, what: str) -> tuple[str, str]:
    """The TOML text of `source` and the name messages use for it: a path
    to a file, a TOML string, or a dict (as the file's tables)."""
    if isinstance(source, Mapping):
        return _toml_of(source), f"<{what} dict>"
    if isinstance(source, os.PathLike) or (isinstance(source, str) and "\n" not in source and "=" not in source):
        path = Path(source)
        try:
            return path.read_text(encoding="utf-8"), str(source)
        except OSError as error:
            raise InputError(f"cannot read {source}: {error.strerror}", None) from None
    return str(source), f"<{what} string>"


def _key(key: Any) -> str:
    """A TOML key: bare where TOML allows it, quoted otherwise."""
    text = str(key)
    return text if text and all(c.isascii() and (c.isalnum() or c in "_-") for c in text) else json.dumps(text)


def _toml_of(table: Mapping[str, Any], prefix: str = "") -> str:
    """A dict as TOML text: plain keys first, then each sub-table, then
    arrays of tables (`[[cargo]]`)."""
    lines, tables, arrays = [], [], []
    for key, value in table.items():
        if isinstance(value, Mapping):
            tables.append((key, value))
        elif isinstance(value, (list, tuple)) and value and all(isinstance(v, Mapping) for v in value):
            arrays.append((key, value))
        else:
            lines.append(f"{_key(key)} = {_toml_value(value)}")
    out = "\n".join(lines) + ("\n" if lines else "")
    for key, value in tables:
        name = f"{prefix}{_key(key)}"
        out += f"\n[{name}]\n" + _toml_of(value, name + ".")
    for key, values in arrays:
        name = f"{prefix}{_key(key)}"
        for value in values:
            out += f"\n[[{name}]]\n" + _toml_of(value, name + ".")
    return out


def _toml_value(value: Any) -> str:
    """One TOML value (numbers, strings, booleans, arrays, inline tables)."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (int, float, np.integer, np.floating)):
        number = float(value) if isinstance(value, (float, np.floating)) else int(value)
        if isinstance(number, float):
            if number != number or number in (float("inf"), float("-inf")):
                return {"inf": "inf", "-inf": "-inf"}.get(repr(number), "nan")
            return repr(number)
        return str(number)
    if isinstance(value, str):
        return json.dumps(value)
    if isinstance(value, Mapping):
        return "{ " + ", ".join(f"{_key(k)} = {_toml_value(v)}" for k, v in value.items()) + " }"
    if isinstance(value, (list, tuple, np.ndarray)):
        return "[" + ", ".join(_toml_value(v) for v in value) + "]"
    raise InputError(f"{value!r}: not a TOML value (numbers, strings, booleans, lists, dicts)", None)


@dataclass(frozen=True)
class Run:
    """One simulated run: the sampled time history as NumPy arrays (empty
    without ``series``) and every metric as ``study simulate --json`` prints it."""

    t: np.ndarray
    """Sample times (s)."""
    x: np.ndarray
    """Rotor coordinate x (m): the shaft centre, or the centre of mass on two supports."""
    y: np.ndarray
    """Rotor coordinate y (m)."""
    r: np.ndarray
    """Vibration r (m), the watched planes' largest whirl."""
    eps: np.ndarray
    """Balancing error ε."""
    angles: np.ndarray
    """Each weight's angle relative to the rotor (rad), one row per weight."""
    bearing_x: np.ndarray
    """Each bearing's displacement x (m), one row per bearing in support
    order: rotors with bearings of their own (two supports); no rows otherwise."""
    bearing_y: np.ndarray
    """Each bearing's displacement y (m)."""
    metrics: dict
    """The run's metrics (settling time, residual, bearing orbits where the rotor has bearings…)."""
    metrics_json: str
    """The metrics as the JSON text ``study simulate --json`` prints."""


def simulate(scene: Source, series: bool = True) -> Run:
    """Simulate a scene (a path, a TOML string or a dict of its tables)."""
    text, name = _text_of(scene, "scene")
    out = _native_call(_native.simulate, text, name, series)
    arrays = {k: np.asarray(out.get(k, []), dtype=np.float64) for k in ("t", "x", "y", "r", "eps")}
    rows = {k: np.asarray(out.get(k, []), dtype=np.float64) for k in ("psi", "bearing_x", "bearing_y")}
    return Run(
        angles=rows["psi"],
        bearing_x=rows["bearing_x"],
        bearing_y=rows["bearing_y"],
        metrics=json.loads(out["metrics_json"]),
        metrics_json=out["metrics_json"],
        **arrays,
    )


@dataclass(frozen=True)
class Decision:
    """The study's decision, as summary.parquet records it."""

    criterion: str
    """The ranking criterion, in words."""
    alpha: float
    """α of the verdicts."""
    ranked: list
    """The designs in rank order: design_id, verdict against #1, balances, pareto, left_race."""
    crown: dict
    """What the verdict says of #1 (kind "best", "none_balances" or "alone")."""
    recommendation: dict
    """kind "build" (design_id, part, pareto), "none_balances" or "no_designs"."""
    text: str
    """The verdict, disagreement and recommendation sentences as ``study run`` prints them."""


@dataclass(frozen=True)
class Study:
    """A study's results: the runs and summary (the columns of runs.parquet
    and summary.parquet) and its decision."""

    folder: Path
    """The folder the study wrote."""
    runs: pl.DataFrame
    """One row per run (runs.parquet)."""
    summary: pl.DataFrame
    """One row per design (summary.parquet)."""
    decision: Optional[Decision]
    """The decision (None for a study that only shards)."""


def run_study(
    study: Source,
    threads: Optional[int] = None,
    out: Optional[Union[str, os.PathLike]] = None,
    overwrite: bool = False,
) -> Study:
    """Run a study (a path, a TOML string or a dict) into its folder, or
    into `out`; results already there are refused unless `overwrite`, as
    ``study run`` does. The results do not depend on `threads`."""
    text, name = _text_of(study, "study")
    folder, _runs, decision = _native_call(
        _native.run_study, text, name, threads, None if out is None else str(out), overwrite
    )
    folder = Path(folder)
    decided = json.loads(decision)
    return Study(
        folder=folder,
        runs=pl.read_parquet(folder / "runs.parquet"),
        summary=pl.read_parquet(folder / "summary.parquet"),
        decision=None if decided is None else Decision(**decided),
    )


def design(n: Union[int, Iterable[int]] = range(1, 9), kind: Optional[str] = None, rho: Optional[float] = None) -> pl.DataFrame:
    """The seed papers' design table (``study design``): per weight count n,
    the capacity and the optimal radius ratio ρ (or the values at `rho`),
    for balls, rollers or both (`kind` None)."""
    counts = [int(n)] if isinstance(n, (int, np.integer)) else [int(k) for k in n]
    rows = json.loads(_native_call(_native.design, counts, kind, rho))
    return pl.DataFrame(rows)


def version() -> str:
    """The library build's version line, as ``study --version`` prints it."""
    return _native.version()
