"""The paper reproduction (``chebnorm repro``'s registered jobs).

* two runs into two temporary folders write byte-identical CSV, JSON and
  caption files (and, with the fixed SVG hash salt and no dates, PNG/SVG);
* every figure has its PNG, SVG, caption and CSV;
* the claims ledger has C1-C13, each with an allowed verdict, a measured
  figure and a command; findings are present;
* the committed ledger and data under figures/ match a fresh run (the
  "fresh clone" acceptance test), for the jobs that need no benchmark file.
"""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

import pytest

import paper_repro
from paper_repro import claims as ledger_mod
from paper_repro.paths import PAPERS

#: the checkout these tests run from (the committed outputs live here)
REPO = Path(__file__).resolve().parents[1]
FIGURES = REPO / "figures"
CLAIMS_JSON = REPO / "paper_repro" / "claims.json"

JOBS = sorted(paper_repro.REGISTRY)


def _run_all(out: Path) -> list[Path]:
    written = []
    for name in JOBS:
        written += paper_repro.REGISTRY[name](out)
    return written


def _hashes(root: Path, suffixes=None) -> dict[str, str]:
    return {str(p.relative_to(root)): hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(root.rglob("*")) if p.is_file()
            and (suffixes is None or p.suffix in suffixes)}


@pytest.fixture(scope="module")
def two_runs(tmp_path_factory):
    a, b = tmp_path_factory.mktemp("repro_a"), tmp_path_factory.mktemp("repro_b")
    wa = _run_all(a)
    # the second run must not reuse the first one's in-process caches
    for mod in (paper_repro.criterion, paper_repro.normalization, paper_repro.highlight,
                paper_repro.bump):
        for obj in vars(mod).values():
            if hasattr(obj, "cache_clear"):
                obj.cache_clear()
    wb = _run_all(b)
    return a, b, wa, wb


def test_registry_names_and_order():
    assert JOBS[-1] == ledger_mod.JOB, "the ledger must run last (jobs run in sorted order)"
    assert set(JOBS) >= {"seed000_normalization", "seed001_bump", "seed002_highlight",
                         "seed003_criterion", "zz_claims"}


def test_jobs_return_the_files_they_wrote(two_runs):
    a, _, wa, _ = two_runs
    assert wa and all(Path(p).is_file() for p in wa)
    assert {Path(p).resolve() for p in wa} == {p.resolve() for p in a.rglob("*") if p.is_file()}


def test_two_runs_are_byte_identical(two_runs):
    a, b, _, _ = two_runs
    ha, hb = _hashes(a), _hashes(b)
    assert ha.keys() == hb.keys()
    differ = [k for k in ha if ha[k] != hb[k]]
    assert not differ, f"files differ between two runs: {differ}"


def test_every_figure_has_png_svg_caption_and_csv(two_runs):
    a, _, _, _ = two_runs
    pngs = sorted(a.rglob("*.png"))
    assert len(pngs) >= 15
    for png in pngs:
        for ext in (".svg", ".txt", ".csv"):
            assert png.with_suffix(ext).is_file(), f"{png.name} has no {ext}"
        caption = png.with_suffix(".txt").read_text()
        assert "seed 00" in caption.lower(), f"{png.name}: caption names no seed figure"
        head = png.with_suffix(".csv").read_text().splitlines()[0]
        assert head.startswith("# "), f"{png.name}: CSV has no caption header"
    for seed, folder in PAPERS.items():
        assert (a / folder).is_dir(), f"no output folder for seed {seed}"


def test_csv_floats_use_the_fixed_format(two_runs):
    a, _, _, _ = two_runs
    text = (a / "criterion" / "fig2_delta_d.csv").read_text().splitlines()
    row = [r for r in text if not r.startswith("#")][1 + 40]  # phi = 40 * pi/360
    assert row.split(",")[0] == "%.10g" % (40 * 3.141592653589793 / 2 / 180)


def test_ledger_has_every_claim_with_a_verdict(two_runs):
    a, _, _, _ = two_runs
    led = json.loads((a / "claims" / "claims.json").read_text())
    ids = [f"C{i}" for i in range(1, 14)]
    assert sorted(led["claims"], key=lambda s: int(s[1:])) == ids
    for cid in ids:
        c = led["claims"][cid]
        assert c["verdict"] in ledger_mod.VERDICTS, (cid, c["verdict"])
        assert c["measured"], cid
        assert c["command"], cid
        assert c["why"], cid
        if c["verdict"] != "not checkable":
            assert c["measured"] != "not measured", cid
    assert {"F1", "F2", "F3"} <= set(led["findings"])
    md = (a / "claims" / "CLAIMS.md").read_text()
    assert all(f"| {cid} |" in md for cid in ids)


def test_ledger_figures(two_runs):
    """The settled figures of the claims that need no benchmark file."""
    a, _, _, _ = two_runs
    c = json.loads((a / "claims" / "claims.json").read_text())["claims"]
    assert c["C1"]["verdict"] == "reproduced" and abs(c["C1"]["data"]["delta_d"] - 0.0049958) < 1e-7
    assert c["C4"]["data"]["at_pi_4"]["max_abs_error"] > 5e-4          # the claim fails at 45 deg
    assert c["C4"]["data"]["fit_at_psi_max"]["abs_error_bound"] <= 5e-4  # ... and holds below
    assert [round(x, 3) for x in c["C5"]["data"]["fit"]["coefficients"]] == [0.681, -0.119, 0.014]
    assert c["C9"]["data"]["exact"]["ops"]["div"] == 3


def test_eta_never_below_the_true_interior_error():
    import numpy as np

    from paper_repro.criterion import interior_min_norm, interior_min_norm_grid
    rng = np.random.default_rng(0)
    v = rng.normal(size=(3, 50, 3)) * 0.2 + np.array([0.0, 0.0, 1.0])
    v /= np.linalg.norm(v, axis=-1, keepdims=True)
    exact = interior_min_norm(*v)
    grid = interior_min_norm_grid(*v)
    assert np.all(grid >= exact - 1e-12)           # the exact minimum is a minimum
    assert np.max(grid - exact) < 1e-6              # and the grid finds it
    # equiangular triangle in the small-angle limit: eta / true = 9/4
    from chebnorm.symbolic import eta
    r = 1e-3
    az = np.radians([0.0, 120.0, 240.0])
    n = np.stack([np.sin(r) * np.cos(az), np.sin(r) * np.sin(az), np.full(3, np.cos(r))], -1)
    ratio = float(eta(n[0], n[1], n[2])) / float(1 - interior_min_norm(n[0], n[1], n[2]))
    assert abs(ratio - 2.25) < 1e-3


@pytest.mark.skipif(not CLAIMS_JSON.is_file(), reason="no committed ledger")
def test_committed_outputs_match_a_fresh_run(two_runs):
    """figures/ and the ledger as committed equal what a fresh run writes (every file:
    data, captions, PNG and SVG)."""
    a, _, _, _ = two_runs
    for folder in PAPERS.values():
        committed = FIGURES / folder
        if not committed.is_dir():
            pytest.skip(f"figures/{folder} not generated")
        fresh, old = _hashes(a / folder), _hashes(committed)
        stale = sorted(k for k in fresh.keys() | old.keys() if fresh.get(k) != old.get(k))
        assert not stale, f"figures/{folder} is stale; run `chebnorm repro`: {stale}"
    fresh = json.loads((a / "claims" / "claims.json").read_text())
    old = json.loads(CLAIMS_JSON.read_text())
    assert fresh == old, "paper_repro/claims.json is stale; run `chebnorm repro`"
    md = (a / "claims" / "CLAIMS.md").read_bytes()
    assert md == (REPO / "paper_repro" / "CLAIMS.md").read_bytes(), \
        "paper_repro/CLAIMS.md is stale; run `chebnorm repro`"
