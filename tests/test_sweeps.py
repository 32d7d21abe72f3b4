"""Scale-out of the design search and the render sweep: the same output bytes with
``--workers 1``, ``--workers 2`` and a Dask ``distributed.LocalCluster`` (2 worker
processes); the render sweep's rows against an independent computation, its bad
input, and an interrupted sweep keeping its finished rows."""

from __future__ import annotations

import numpy as np
import pytest

from chebnorm.cli import main
from conftest import run_process

DESIGN = ["design", "1/sqrt(x)", "--interval", "1", "4", "--in-bits", "8", "--out-bits", "8",
          "--max-error", "1e-2", "--degrees", "1", "2", "--max-segments", "2^4", "--no-synth"]
PIECEWISE_SWEEP = ["hw", "sweep", "--segments", "2^1", "2^2", "--degrees", "1", "2",
                   "--coef-frac-bits", "8", "--in-bits", "6", "--out-bits", "6"]
RENDER = ["render-sweep", "--meshes", "sphere", "torus", "--shadings", "phong", "gouraud",
          "bump", "--methods", "exact", "none", "dichotomy", "--sizes", "48", "40x32",
          "--bumps", "full", "square"]


def _files(folder):
    """``{relative path: bytes}`` of every file under ``folder``."""
    return {str(p.relative_to(folder)): p.read_bytes() for p in sorted(folder.rglob("*"))
            if p.is_file()}


@pytest.fixture(scope="module")
def cluster():
    """A Dask LocalCluster of 2 single-threaded worker processes."""
    distributed = pytest.importorskip("distributed", reason="dask.distributed is not installed "
                                      "(pip install 'chebnorm[cluster]')")
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  protocol="tcp://", dashboard_address=None) as c:
        yield c.scheduler_address


# ------------------------------------------------------------------ design
@pytest.mark.slow
@pytest.mark.parametrize("argv, outputs", [
    (DESIGN, ("design_rsqrt_1_4_i8_o8_e_0p01.csv", "design_rsqrt_1_4_i8_o8_e_0p01.png")),
    (PIECEWISE_SWEEP, ("sweep_piecewise.csv", "sweep_piecewise.png")),
], ids=["design", "hw-sweep-segments"])
def test_design_same_bytes_for_any_workers(tmp_path, cluster, argv, outputs):
    runs = {"1": ["--workers", "1"], "2": ["--workers", "2"], "dask": ["--scheduler", cluster]}
    # each run a fresh process, as from a shell: the runs compared for equal bytes share
    # no caches and no hash seed (in this process they would share both)
    for name, extra in runs.items():
        r = run_process(*argv, *extra, "-o", str(tmp_path / name), cwd=tmp_path)
        assert r.returncode == 0, r.stderr
    serial = _files(tmp_path / "1")
    assert sorted(serial) == sorted(outputs)
    assert _files(tmp_path / "2") == serial and _files(tmp_path / "dask") == serial
    rows = serial[outputs[0]].decode().splitlines()
    assert len(rows) > 4
    if argv is PIECEWISE_SWEEP:
        assert len(rows) == 1 + 2 * 2   # every grid point: 2 degrees x 2 segment counts


def test_design_search_library_matches_serial():
    """The library call with a worker pool gives the points, winner and designs of the
    serial call (the designs come back from the workers intact)."""
    from chebnorm.hw.piecewise_search import search

    kw = dict(degrees=(1, 2), max_index_bits=3, synth=False, progress=False)
    a = search("1/sqrt(x)", ("1", "4"), 8, 8, 1e-2, workers=1, **kw)
    b = search("1/sqrt(x)", ("1", "4"), 8, 8, 1e-2, workers=2, **kw)
    assert a.points == b.points and a.winner == b.winner and a.csv() == b.csv()
    assert sorted(a.designs) == sorted(b.designs)
    for key, d in a.designs.items():
        assert d.measure() == b.designs[key].measure()


# ----------------------------------------------------------- render sweep
@pytest.mark.slow
def test_render_sweep_same_bytes_for_any_workers(tmp_path, cluster):
    runs = {"1": ["--workers", "1"], "2": ["--workers", "2"], "dask": ["--scheduler", cluster]}
    # each run a fresh process, as from a shell: the runs compared for equal bytes share
    # no caches and no hash seed (in this process they would share both)
    for name, extra in runs.items():
        r = run_process(*RENDER, "--images", *extra, "-o", str(tmp_path / name), cwd=tmp_path)
        assert r.returncode == 0, r.stderr
    serial = _files(tmp_path / "1")
    assert _files(tmp_path / "2") == serial and _files(tmp_path / "dask") == serial
    rows = serial["render_sweep.csv"].decode().splitlines()
    # 2 meshes x 2 sizes x (gouraud once + phong x 3 methods + bump x 3 methods x 2 variants)
    assert len(rows) == 1 + 2 * 2 * (1 + 3 + 6)
    assert len(serial) == 1 + 2 * (len(rows) - 1)  # the CSV, an image and an error map per row


def test_render_sweep_rows_against_an_independent_computation():
    """Each row's numbers are those of rendering the case and its reference directly
    and differencing the 8-bit images with numpy."""
    from chebnorm.raster import Lighting, render, render_sweep, render_sweep_cases

    cases = render_sweep_cases(("sphere",), ("phong", "adaptive", "split-gouraud"),
                               ("none", "dichotomy"), sizes=[(40, 36)], tess=[6],
                               shininess=[16.0])
    assert len(cases) == 2 + 2 + 1   # split-gouraud has no method: one case
    sweep = render_sweep(cases, workers=1)
    assert [r.case for r in sweep.rows] == sorted(cases, key=lambda c: c.sort_key)
    kw = dict(size=(40, 36), tess=6, lighting=Lighting(shininess=16.0))
    ref = render("sphere", "phong", "exact", **kw)
    for row in sweep.rows:
        img = render("sphere", row.case.shading, row.case.method, **kw)
        covered = img.mask | ref.mask
        diff = np.abs(img.image8.astype(int) - ref.image8.astype(int))[covered]
        m = row.metrics
        assert (m["pixels"], m["max_abs_8bit"], m["pixels_off_1"], m["mean_abs_8bit"]) == \
            (int(covered.sum()), int(diff.max()), int((diff >= 1).sum()), float(diff.mean()))
        mse = float(np.mean(diff.astype(float) ** 2))
        assert m["psnr"] == (None if mse == 0 else pytest.approx(
            10 * np.log10(255.0 ** 2 / mse), rel=1e-12))
        assert row.triangles == img.triangles and row.fragments == img.fragments
    assert max(r.metrics["max_abs_8bit"] for r in sweep.rows) > 0   # not all trivially equal
    line = sweep.csv().splitlines()[1].split(",")
    assert line[:9] == ["sphere", "6", "40", "36", "16", "adaptive", "dichotomy", "",
                        "phong:exact"]


@pytest.mark.parametrize("argv, says", [
    (["--methods", "fast"], "unknown method 'fast'; accepted: exact"),
    (["--meshes", "cube"], "unknown mesh 'cube'; accepted: teapot"),
    (["--meshes", "missing.obj"], "missing.obj"),
    (["--sizes", "0"], "size '0': expected W or WxH, integers in [1, 16384]"),
    (["--sizes", "64x"], "size '64x'"),
    (["--sizes", "20000x8"], "size '20000x8'"),
    (["--shadings", "flat"], "unknown shading mode 'flat'; accepted: gouraud"),
    (["--tess", "0"], "tessellation level"),
    (["--shininess", "0.5"], "shininess must be a finite number >= 1"),
    (["--shadings", "bump", "--meshes", "icosphere"], "needs a parametrized mesh"),
    (["--shadings", "bump", "--bumps", "flat"], "unknown bump variant 'flat'"),
    (["--reference", "phong:fast"], "unknown reference method 'fast'"),
    (["--workers", "0"], "accepted: an integer >= 1"),
    (["--meshes", "sphere", "torus", "--methods"], "expected at least one argument"),
])
def test_render_sweep_bad_input(tmp_path, capsys, argv, says):
    out = tmp_path / "out"
    assert main(["render-sweep", "--sizes", "16", *argv, "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert says in err and err.count("\n") == 1, err
    assert not out.exists()


def test_render_sweep_interrupted_keeps_finished_rows(tmp_path, monkeypatch, capsys):
    import chebnorm.raster.studies as studies

    argv = ["render-sweep", "--meshes", "sphere", "--methods", "exact", "none", "newton",
            "dichotomy", "--sizes", "24", "--workers", "1"]
    assert main([*argv, "-o", str(tmp_path / "full")]) == 0
    full = (tmp_path / "full" / "render_sweep.csv").read_text().splitlines()
    assert len(full) == 1 + 4
    real, calls = studies._render_case, []

    def interrupted(item):
        calls.append(item)
        if len(calls) == 3:
            raise KeyboardInterrupt
        return real(item)

    monkeypatch.setattr(studies, "_render_case", interrupted)
    assert main([*argv, "-o", str(tmp_path / "cut")]) == 130
    assert "interrupted" in capsys.readouterr().err
    assert (tmp_path / "cut" / "render_sweep.csv").read_text().splitlines() == full[:3]


def test_render_sweep_image_names_must_differ(tmp_path, capsys):
    from chebnorm.raster import get_mesh

    m = get_mesh("square", 2)
    for sub in ("a", "b"):
        (tmp_path / sub).mkdir()
        lines = [f"v {float(x)!r} {float(y)!r} {float(z)!r}" for x, y, z in m.positions]
        lines += [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in m.faces]
        (tmp_path / sub / "tile.obj").write_text("\n".join(lines) + "\n")
    argv = ["render-sweep", "--meshes", str(tmp_path / "a" / "tile.obj"),
            str(tmp_path / "b" / "tile.obj"), "--methods", "none", "--sizes", "16",
            "--workers", "1", "-o", str(tmp_path / "out")]
    assert main([*argv, "--images"]) == 2
    assert "two cases would write images named 'tile_16x16_n32_phong_none'" in \
        capsys.readouterr().err
    assert main(argv) == 0   # without images the names may repeat
    rows = (tmp_path / "out" / "render_sweep.csv").read_text().splitlines()
    assert len(rows) == 3 and rows[1].startswith(str(tmp_path / "a" / "tile.obj"))
