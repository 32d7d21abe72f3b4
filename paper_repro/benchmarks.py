"""The speed claims' numbers: ``benchmarks/results.json`` (written by
``python benchmarks/run.py``). Which file is read is set per run by
:func:`use_results` (``chebnorm repro --bench-results``; default
:func:`~.paths.bench_results`: ``./benchmarks/results.json`` when it exists);
no file -> ``None``, so a later run picks the numbers up without code changes."""

from __future__ import annotations

import json
from functools import lru_cache
from pathlib import Path

from .paths import bench_results

__all__ = ["load_results", "use_results", "MISSING"]

MISSING = "benchmarks/results.json not generated yet (run: python benchmarks/run.py)"

_current: dict = {"path": None, "set": False}


def use_results(path=None) -> Path | None:
    """Read the results from ``path`` (None: ``./benchmarks/results.json`` if it exists)
    from now on; returns the file that will be read, or None."""
    _current["path"] = bench_results(path)
    _current["set"] = True
    return _current["path"]


@lru_cache(maxsize=None)
def _load(path: str):
    p = Path(path)
    if not p.is_file():
        return None
    return json.loads(p.read_text(encoding="utf-8"))


def load_results(path: Path | None = None):
    """The parsed results (of ``path``, else of the file set by :func:`use_results`,
    else of ``./benchmarks/results.json``), or ``None`` when there is no file."""
    if path is None:
        path = _current["path"] if _current["set"] else bench_results()
    return None if path is None else _load(str(Path(path).resolve()))
