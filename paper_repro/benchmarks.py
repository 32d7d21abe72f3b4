"""Read ``benchmarks/results.json`` (written by ``python benchmarks/run.py``,
issue 6) for the speed claims; absent file -> ``None``, so a later run
picks the numbers up without code changes."""

from __future__ import annotations

import json
from functools import lru_cache
from pathlib import Path

from .paths import BENCHMARK_RESULTS

__all__ = ["load_results", "MISSING"]

MISSING = "benchmarks/results.json not generated yet (run: python benchmarks/run.py)"


@lru_cache(maxsize=None)
def _load(path: str):
    p = Path(path)
    if not p.is_file():
        return None
    return json.loads(p.read_text(encoding="utf-8"))


def load_results(path: Path | None = None):
    """The parsed results, or ``None`` when the file does not exist."""
    return _load(str(path or BENCHMARK_RESULTS))
