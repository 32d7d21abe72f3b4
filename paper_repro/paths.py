"""The one place that knows where the reproduction writes (showyourwork's ``paths.py``).

``chebnorm repro`` hands every job the output root (``figures/`` by default,
``-o DIR`` otherwise); each paper writes into its own folder under it.
"""

from __future__ import annotations

from pathlib import Path

__all__ = ["ROOT", "FIGURES", "PAPERS", "CLAIMS_MD", "CLAIMS_JSON", "BENCHMARK_RESULTS",
           "paper_dir"]

#: the repository (the parent of this package)
ROOT = Path(__file__).resolve().parent.parent
#: the default output root of ``chebnorm repro``
FIGURES = ROOT / "figures"
#: paper (seed) -> its folder under the output root, named by topic
PAPERS = {
    "000": "normalization",  # efficient normalization methods, compared
    "001": "bump",        # bump mapping on the Phong pipeline
    "002": "highlight",   # highlight detection for Gouraud shading
    "003": "criterion",   # the normalization criterion eta
}
#: the claims ledger (kept beside the code that generates it, not under figures/)
CLAIMS_MD = Path(__file__).resolve().parent / "CLAIMS.md"
CLAIMS_JSON = Path(__file__).resolve().parent / "claims.json"
#: the speed measurements written by ``python benchmarks/run.py`` (issue 6)
BENCHMARK_RESULTS = ROOT / "benchmarks" / "results.json"


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
