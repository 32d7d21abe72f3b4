"""The one place that knows where the reproduction reads and writes (showyourwork's ``paths.py``).

Nothing here looks at where the code is installed: every location is either
given (``chebnorm repro -o DIR --ledger-dir DIR --bench-results FILE``) or
taken from the current directory, so ``pip install .`` and ``pip install -e .``
behave the same. Run from a checkout of the repository, the defaults are the
committed locations:

==================  ===================================================================
what                default
==================  ===================================================================
output root         ``./figures`` (each paper in its folder under it, :func:`paper_dir`)
claims ledger       ``./paper_repro`` when the output root is ``./figures`` and the
                    current directory has a ``paper_repro/`` folder (a checkout);
                    otherwise ``<output root>/claims`` (:func:`ledger_dir`)
benchmark results   ``./benchmarks/results.json`` when that file exists, else none:
                    the speed figures read "n/a" / "not checkable" (:func:`bench_results`)
==================  ===================================================================
"""

from __future__ import annotations

from pathlib import Path

__all__ = ["PAPERS", "DEFAULT_OUTPUT", "LEDGER_HOME", "DEFAULT_BENCH_RESULTS", "LEDGER_FILES",
           "paper_dir", "ledger_dir", "bench_results"]

#: the default output root, relative to the current directory
DEFAULT_OUTPUT = Path("figures")
#: the ledger's home in a checkout, relative to the current directory
LEDGER_HOME = Path("paper_repro")
#: the speed measurements written by ``python benchmarks/run.py``, relative to the cwd
DEFAULT_BENCH_RESULTS = Path("benchmarks") / "results.json"
#: the ledger's two files
LEDGER_FILES = ("claims.json", "CLAIMS.md")
#: paper (seed) -> its folder under the output root, named by topic
PAPERS = {
    "000": "normalization",  # efficient normalization methods, compared
    "001": "bump",        # bump mapping on the Phong pipeline
    "002": "highlight",   # highlight detection for Gouraud shading
    "003": "criterion",   # the normalization criterion eta
}


def paper_dir(out, seed: str) -> Path:
    """The folder of paper ``seed`` ("000".."003") under the output root ``out``,
    created if missing."""
    try:
        name = PAPERS[seed]
    except KeyError:
        raise ValueError(f"unknown seed {seed!r}; accepted: {', '.join(sorted(PAPERS))}") from None
    folder = Path(out) / name
    folder.mkdir(parents=True, exist_ok=True)
    return folder


def ledger_dir(out, given=None) -> Path:
    """Where the claims ledger goes: ``given`` when not None; ``./paper_repro`` when ``out``
    is ``./figures`` and ``./paper_repro/`` exists; else ``out/claims``."""
    if given is not None:
        return Path(given)
    cwd = Path.cwd()
    if Path(out).resolve() == (cwd / DEFAULT_OUTPUT).resolve() and (cwd / LEDGER_HOME).is_dir():
        return LEDGER_HOME
    return Path(out) / "claims"


def bench_results(given=None) -> Path | None:
    """The benchmark results file: ``given`` (which must exist), else
    ``./benchmarks/results.json`` when it exists, else None."""
    if given is not None:
        p = Path(given)
        if not p.is_file():
            raise ValueError(f"benchmark results {str(p)!r} is not a file; accepted: the "
                             f"results.json written by `python benchmarks/run.py`")
        return p
    return DEFAULT_BENCH_RESULTS if DEFAULT_BENCH_RESULTS.is_file() else None
