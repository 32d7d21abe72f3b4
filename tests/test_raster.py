"""Tests of chebnorm.raster: meshes, spans, shading modes, metrics, CLI."""

from __future__ import annotations

import json
import os

import numpy as np
import pytest

from chebnorm.raster import (Lighting, Mesh, bump_comparison, compare, error_map_rgb, eta_study,
                             get_mesh, render, setup_spans, split_gouraud_study, write_png, zbuffer)
from chebnorm.raster import meshes as M
from conftest import run_cli

SMALL = (64, 64)


@pytest.fixture(scope="module")
def teapot512():
    return get_mesh("teapot")


@pytest.fixture(scope="module")
def teapot_ref(teapot512):
    return render(teapot512, "phong", "exact", size=(512, 512))


# ------------------------------------------------------------------ meshes
class TestMeshes:
    @pytest.mark.parametrize("name", ["teapot", "sphere", "icosphere", "torus", "square"])
    def test_unit_normals_and_winding(self, name):
        m = get_mesh(name)
        assert np.allclose(np.linalg.norm(m.normals, axis=1), 1, atol=1e-12)
        # faces wound so that the geometric normal agrees with the vertex normals
        agree = np.einsum("fk,fk->f", m.face_normals(), m.normals[m.faces].sum(axis=1))
        assert (agree > 0).all()

    def test_teapot_normals_outward(self):
        m = M.teapot(6)
        # the body: normals point away from the z axis at mid height
        r = np.hypot(*m.positions[:, :2].T)
        body = (np.abs(m.positions[:, 2] - 1.2) < 0.3) & (r > 1.8) & (r < 2.01) \
            & (np.abs(m.positions[:, 1]) > 0.8)  # away from the spout and the handle
        radial = m.positions[body, :2] / np.hypot(*m.positions[body, :2].T)[:, None]
        assert (np.einsum("ik,ik->i", m.normals[body, :2], radial) > 0.5).all()
        # P_u x P_v agrees with the normal (bump frames)
        cr = np.cross(m.P_u, m.P_v)
        assert (np.einsum("ik,ik->i", cr, m.normals) > 0).all()

    def test_tessellation_level(self):
        assert len(M.uv_sphere(8).faces) < len(M.uv_sphere(16).faces)
        assert len(M.teapot(4).faces) < len(M.teapot(8).faces)

    def test_crease_normals_split_cube(self):
        import trimesh
        cube = trimesh.creation.box()
        p, n, f = M.crease_normals(cube.vertices, cube.faces, np.radians(30))
        assert len(p) == 24  # each corner split into three face normals
        axis = np.abs(n).max(axis=1)
        assert np.allclose(axis, 1)
        p, n, f = M.crease_normals(cube.vertices, cube.faces, np.radians(100))
        assert len(p) == 8 and np.allclose(np.abs(n), 1 / np.sqrt(3))

    def test_load_mesh_file(self, tmp_path):
        import trimesh
        path = tmp_path / "ico.obj"
        trimesh.creation.icosphere(2).export(path)
        m = get_mesh(str(path))
        r = render(m, "phong", "exact", size=SMALL)
        assert r.pixels > 1000

    def test_raises(self, tmp_path, monkeypatch):
        with pytest.raises(ValueError, match="unknown mesh 'cube'"):
            get_mesh("cube")
        with pytest.raises(ValueError, match="does not exist"):
            get_mesh(str(tmp_path / "missing.obj"))
        with pytest.raises(ValueError, match="tessellation level"):
            get_mesh("sphere", 0)
        pos = np.array([[0.0, 0, 0], [1, 0, 0], [2, 0, 0], [0, 1, 0]])
        nrm = np.tile([0.0, 0, 1], (4, 1))
        with pytest.raises(ValueError, match="triangle 0 .* degenerate"):
            Mesh("bad", pos, nrm, [[0, 1, 2], [0, 1, 3]])
        nrm_nan = nrm.copy()
        nrm_nan[3] = np.nan
        with pytest.raises(ValueError, match="vertex normal 3 is not finite"):
            Mesh("bad", pos, nrm_nan, [[0, 1, 3]])
        with pytest.raises(ValueError, match="length"):
            Mesh("bad", pos, 2 * nrm, [[0, 1, 3]])
        # the triangle map is int32: a mesh with more faces than it can index is refused
        # (MAX_FACES lowered here: 2**31 faces would not fit in memory)
        import chebnorm.raster.meshes as meshes
        monkeypatch.setattr(meshes, "MAX_FACES", 1)
        with pytest.raises(ValueError, match="at most 1 faces .* int32.* got 2"):
            Mesh("big", pos, nrm, [[0, 1, 3], [1, 2, 3]])
        monkeypatch.undo()
        bad_file = tmp_path / "flat.obj"
        bad_file.write_text("v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n")
        with pytest.raises(ValueError, match="degenerate|no triangles"):
            get_mesh(str(bad_file))


# ------------------------------------------------------------------- spans
class TestSpans:
    def test_coverage_of_a_square_is_exact(self):
        # two triangles covering [8, 24) x [8, 24): 256 pixels, each exactly once
        xy = np.array([[[8, 8], [24, 8], [24, 24]], [[8, 8], [24, 24], [8, 24]]], float)
        attrs = np.ones((2, 3, 1))
        sp = setup_spans(xy, attrs, 32, 32)
        assert sp.n_fragments == 256
        assert len(np.unique(sp.frag_pixel)) == 256
        assert (sp.t0 >= 0).all() and (sp.frag_t >= 0).all() and (sp.frag_t <= 1).all()

    def test_attributes_are_linear(self):
        xy = np.array([[[1.3, 2.7], [30.1, 5.2], [12.4, 28.9]]])
        # attribute = screen x + 2 screen y at each corner: linear, so exact at every pixel
        a = (xy[..., 0] + 2 * xy[..., 1])[..., None]
        sp = setup_spans(xy, a, 32, 32)
        col, row = sp.frag_pixel % 32 + 0.5, sp.frag_pixel // 32 + 0.5
        assert np.allclose(sp.lerp([0])[:, 0], col + 2 * row, atol=1e-9)

    def test_zbuffer_nearest_wins_and_ties_first(self):
        pix = np.array([5, 5, 5, 7])
        inv_w = np.array([0.1, 0.3, 0.3, 0.2])
        assert zbuffer(pix, inv_w, 10).tolist() == [1, 3]


# ------------------------------------------------------------------- modes
class TestModes:
    @pytest.mark.parametrize("mode", ["gouraud", "phong", "adaptive", "split-gouraud", "bump"])
    def test_teapot_512_every_mode(self, teapot512, teapot_ref, mode):
        r = render(teapot512, mode, "exact", size=(512, 512))
        assert r.image.shape == (512, 512) and r.pixels > 60000
        assert np.isfinite(r.image).all()
        if mode != "bump":
            assert (r.mask == teapot_ref.mask).all()  # same geometry, same coverage

    def test_phong_exact_against_itself(self, teapot512, teapot_ref):
        m, diff = compare(render(teapot512, "phong", "exact", size=(512, 512)), teapot_ref)
        assert m.max_abs_8bit == 0 and m.pixels_off_1 == 0 and m.psnr is None
        assert m.ssim == 1.0 and m.flip == 0.0 and not diff.any()

    def test_quadratic_degree2_within_one_level(self, teapot512, teapot_ref):
        from chebnorm.raster import available_methods
        if "quadratic" not in available_methods():
            pytest.skip("chebnorm.methods not available")
        r = render(teapot512, "phong", "quadratic", size=(512, 512))
        m, _ = compare(r, teapot_ref, flip=False)
        assert "table_psi_max" not in r.stats  # the default degree-2 table covers every span
        assert m.max_abs_8bit <= 1

    def test_deterministic(self):
        a = render("torus", "split-gouraud", size=SMALL, tess=5)
        b = render("torus", "split-gouraud", size=SMALL, tess=5)
        assert np.array_equal(a.image, b.image) and a.stats == b.stats

    def test_none_error_grows_with_coarseness_and_eta_bounds_it(self):
        levels = eta_study((4, 8, 16), size=(96, 96))
        errs = [lv.metrics["mean_abs_8bit"] for lv in levels]
        assert errs[0] > errs[1] > errs[2] > 0
        maxs = [lv.metrics["max_abs_8bit"] for lv in levels]
        assert maxs[0] > maxs[1] > maxs[2]
        for lv in levels:
            # each triangle's worst relative diffuse error 1 - |N| is within its eta
            assert lv.bound_holds, lv.to_dict()
            assert 0.3 < lv.tightness <= 1.0

    def test_adaptive_reports_skips(self):
        r = render("sphere", "adaptive", "exact", size=SMALL, tess=24, eta_threshold=0.01)
        s = r.stats
        assert 0 < s["triangles_skipped_fraction"] <= 1 and 0 < s["pixels_skipped_fraction"] <= 1
        r0 = render("sphere", "adaptive", "exact", size=SMALL, tess=24, eta_threshold=0.0)
        assert r0.stats["triangles_skipped"] == 0
        ref = render("sphere", "phong", "exact", size=SMALL, tess=24)
        assert compare(r0, ref, flip=False)[0].max_abs_8bit == 0

    def test_split_gouraud_closer_to_phong(self):
        s = split_gouraud_study(tess=6, shininess=64, size=(128, 128))
        assert s.split_stats["extra_vertices"] > 0
        assert s.closer_to_phong, s.to_dict()

    def test_bump_square_agrees_on_flat_square_not_elsewhere(self):
        cases = {c.mesh: c for c in bump_comparison(size=(96, 96))}
        assert cases["square"].square_vs_full["max_abs_8bit"] == 0
        assert cases["sphere"].square_vs_full["max_abs_8bit"] > 1
        assert cases["torus"].square_vs_full["max_abs_8bit"] > 1

    def test_raises(self):
        with pytest.raises(ValueError, match="unknown shading mode 'flat'"):
            render("sphere", "flat", size=SMALL)
        with pytest.raises(ValueError, match="unknown method 'fast'"):
            render("sphere", "phong", "fast", size=SMALL)
        with pytest.raises(ValueError, match="size"):
            render("sphere", "phong", size=(0, 64))
        with pytest.raises(ValueError, match="bump variant"):
            render("sphere", "bump", bump="cubic", size=SMALL)
        with pytest.raises(ValueError, match="parametrized"):
            render("icosphere", "bump", size=SMALL)
        with pytest.raises(ValueError, match="shininess"):
            render("sphere", lighting=Lighting(shininess=float("nan")), size=SMALL)


# ----------------------------------------------------------------- metrics
class TestMetrics:
    def test_known_difference(self):
        a = np.zeros((16, 16), np.uint8)
        b = a.copy()
        b[3, 4] = 10
        m, d = compare(a, b)
        assert m.max_abs_8bit == 10 and m.pixels_off_1 == 1 and d[3, 4] == -10
        assert m.psnr == pytest.approx(10 * np.log10(255 ** 2 / (100 / 256)))
        assert 0 < m.ssim < 1 and m.flip > 0

    def test_error_map_and_atomic_write(self, tmp_path):
        rgb = error_map_rgb(np.array([[0, 5], [10, -10]]))
        assert rgb.shape == (2, 2, 3) and rgb[0, 0].tolist() == [0, 0, 0]
        assert rgb[1, 0].tolist() == [255, 255, 255]
        p = tmp_path / "e.png"
        write_png(p, rgb)
        assert p.exists() and not [f for f in os.listdir(tmp_path) if f.startswith(".tmp")]
        with pytest.raises(ValueError, match="does not exist"):
            write_png(tmp_path / "no" / "e.png", rgb)


# --------------------------------------------------------------------- CLI
class TestCLI:
    def test_json_and_images(self, tmp_path, capsys):
        out, err = tmp_path / "img.png", tmp_path / "err.png"
        r = run_cli("render", "--mesh", "sphere", "--tess", "8", "--shading", "gouraud",
                    "--size", "48", "40", "--out", str(out), "--error-map", str(err), "--json")
        assert r.code == 0, r.err
        d = json.loads(r.out)
        for key in ("max_abs_8bit", "pixels_off_1", "mean_abs_8bit", "psnr", "ssim", "flip",
                    "pixels", "seconds", "vertices_shaded"):
            assert key in d
        from PIL import Image
        assert Image.open(out).size == (48, 40) and Image.open(err).mode == "RGB"

    def test_reference_option(self, capsys):
        r = run_cli("render", "--mesh", "sphere", "--tess", "8", "--shading", "gouraud",
                    "--size", "32", "32", "--reference", "gouraud", "--json")
        assert r.code == 0 and json.loads(r.out)["max_abs_8bit"] == 0

    @pytest.mark.parametrize("argv, message", [
        (["--mesh", "cube"], "unknown mesh"),
        (["--shading", "flat"], "unknown shading mode"),
        (["--method", "fast"], "unknown method"),
        (["--size", "0", "32"], "size"),
        (["--mesh", "/nonexistent/x.obj"], "does not exist"),
        (["--reference", "flat:exact"], "unknown mode"),
    ])
    def test_errors_exit_2_one_line_no_image(self, tmp_path, capsys, argv, message):
        out = tmp_path / "img.png"
        r = run_cli("render", "--size", "32", "32", "--mesh", "sphere", *argv, "--out", str(out))
        rc, err = r.code, r.err
        assert rc == 2 and message in err and err.count("\n") == 1
        assert not out.exists()


def test_render_is_a_front_end():
    """render.py validates, picks an engine once (engines.get_engine) and dispatches the
    mode: it imports no engine module and compares nothing with an engine's name."""
    import ast
    import importlib
    import inspect

    R = importlib.import_module("chebnorm.raster.render")   # the module, not the function
    tree = ast.parse(inspect.getsource(R))
    imported = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            base = "chebnorm.raster" if node.level == 1 else ""
            mod = ".".join(p for p in (base, node.module or "") if p)
            imported.update(f"{mod}.{a.name}" for a in node.names)
        elif isinstance(node, ast.Import):
            imported.update(a.name for a in node.names)
    assert "chebnorm.raster.engines.get_engine" in imported
    assert not [m for m in imported if m.startswith("chebnorm.raster.engines.")
                and m != "chebnorm.raster.engines.get_engine"], imported
    names = {"numba", "numpy", "fast", "fused"}
    for node in ast.walk(tree):
        if isinstance(node, ast.Compare):
            consts = {c.value for c in ast.walk(node) if isinstance(c, ast.Constant)}
            assert not consts & names, ast.unparse(node)
