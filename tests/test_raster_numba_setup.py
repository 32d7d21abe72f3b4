"""The compiled set-up of the fused phong frame (chebnorm.raster.engines.numba.setup) against the
numpy reference it replaces: check_span_input on the unit span ends, auto_tables'
widest angle, the per-method span set-up (bit for bit), the same errors through render,
and the remembered default camera."""

import importlib
import math
from types import SimpleNamespace

import numpy as np
import pytest

from chebnorm.methods import get_method, method_names
from chebnorm.methods import kernels as K
from chebnorm.methods.spans import PICK_TOL, check_span_input
from chebnorm.raster import Mesh, get_mesh, render
from chebnorm.raster.engines import get_engine
from chebnorm.raster.engines.base import auto_tables, dot
from chebnorm.raster.engines.numba.jit import HAVE_NUMBA

pytestmark = pytest.mark.skipif(not HAVE_NUMBA, reason="numba is not installed "
                                "(the compiled path is optional; CI installs it)")

import raster_oracles  # noqa: E402

from chebnorm.raster.engines.numba import calibration, frame, kernels, rasterize, setup  # noqa: E402
from chebnorm.raster.engines.numba import workspace  # noqa: E402
from chebnorm.raster.meshes import unit as _unit  # noqa: E402
from chebnorm.raster.scanline import fit_camera  # noqa: E402

R = importlib.import_module("chebnorm.raster.render")
SPAN_METHODS = [m for m in method_names() if m != "none"]


def _same(a, b):
    a, b = np.asarray(a), np.asarray(b)
    return a.dtype == b.dtype and a.shape == b.shape and a.tobytes() == b.tobytes()


def _outcome(fn):
    try:
        return fn()
    except (ValueError, TypeError) as exc:
        return f"{type(exc).__name__}: {exc}"


def _reference(spec, sp, tables, dtype, diff):
    """What the fused frame computed before its compiled set-up: numpy, the reference functions."""
    cols = [1, 2, 3]
    nl, nr = _unit(sp.left[:, cols]), _unit(sp.right[:, cols])
    dmin = np.min(dot(nl, nr))
    inp = check_span_input(spec, nl, nr, sp.m, t0=sp.t0, dt=sp.dt, count=sp.count, tables=tables,
                           dtype=dtype)
    A = np.ascontiguousarray(inp.n_left.astype(inp.dtype).T)
    B = np.ascontiguousarray(inp.n_right.astype(inp.dtype).T)
    if diff:
        B = np.ascontiguousarray(np.stack(K.vsub(tuple(B), tuple(A))))
    return dict(dmin=dmin, cos=inp.cosines, dtype=inp.dtype, coeffs=inp.coefficients,
                levels=inp.levels, A=A, B=B, start_left=bool((inp.t0 == 0).all()),
                count_max=int(inp.count.max()))


def _compiled(spec, sp, tables, dtype, diff):
    ends, dmin = setup.widest_dot(sp, spec, dtype, diff)
    dt, coeffs, levels, A, B, start_left, count_max = setup.span_input(
        spec, sp, tables, dtype, ends, diff)
    return dict(dmin=dmin, cos=ends.cos, dtype=dt, coeffs=coeffs, levels=levels, A=A, B=B,
                start_left=start_left, count_max=count_max)


def _check_same(spec, sp, tables, dtype):
    diff = frame.MODES[id(K.__dict__[spec.name.upper()])] <= 3
    ref = _outcome(lambda: _reference(spec, sp, tables, dtype, diff))
    got = _outcome(lambda: _compiled(spec, sp, tables, dtype, diff))
    if isinstance(ref, str):
        assert got == ref
        return False
    assert isinstance(got, dict), got
    assert got["dtype"] is ref["dtype"] and got["coeffs"] == ref["coeffs"]
    assert got["start_left"] == ref["start_left"] and got["count_max"] == ref["count_max"]
    for name in ("dmin", "cos", "A", "B"):
        assert _same(got[name], ref[name]), name
    assert (got["levels"] is None and ref["levels"] is None) or _same(got["levels"],
                                                                      ref["levels"])
    return True


def _teapot_spans(size, per_pixel_h=True):
    mesh = get_mesh("teapot")
    st = get_engine("numba").setup(mesh, None, size, True)
    attrs = st.attrs if per_pixel_h else np.ascontiguousarray(st.attrs[..., :4])
    return raster_oracles.row_spans(st.xy, attrs, *size)


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_teapot_setup_values_identical(dtype):
    sp = _teapot_spans((720, 600))
    for method in SPAN_METHODS:
        spec = get_method(method)
        stats = {}
        tables = auto_tables(spec, sp, [[1, 2, 3]], None, stats)   # wide spout spans
        for tb in (tables, {method: None}) if spec.table is not None else (None,):
            assert _check_same(spec, sp, tb, dtype), method
        if tables is not None:
            # the default table does not cover the spout: the same error
            assert not _check_same(spec, sp, None, dtype)


def _edge_spans(seed, S=3000, kc=7):
    """Random spans and the cases where the compiled pass hands values to numpy:
    steps 2**-k (on the dyadic grid) and within 1e-13 of one, pixels on the grid and
    1e-10 / 1e-8 off it, end-normal angles at and around theta_max 2**n (the depth
    thresholds of _levels)."""
    rng = np.random.default_rng(seed)
    nl = rng.standard_normal((S, 3))
    nl /= np.linalg.norm(nl, axis=1, keepdims=True)
    nr = nl + 0.5 * rng.standard_normal((S, 3))
    nr /= np.linalg.norm(nr, axis=1, keepdims=True)
    m = rng.integers(1, 80, S)
    dt = 1.0 / (m + rng.random(S))
    t0 = rng.random(S) * dt
    k = rng.integers(0, 9, S)
    g = S // 6
    dt[:g] = 2.0 ** -k[:g]                                   # on the grid
    t0[:g] = 0.0
    dt[g:2 * g] = 2.0 ** -k[g:2 * g] * (1 + rng.choice([-1e-13, 1e-13, 3e-7], g))
    t0[g:2 * g] = rng.choice([0.0, 1e-10, 1e-8], g) * dt[g:2 * g]
    theta = 2.0 * math.acos(1.0 - PICK_TOL)
    n = rng.integers(0, 7, g)
    ang = theta * 2.0 ** n * (1 + rng.choice([0.0, -1e-15, 1e-15, -1e-9, 1e-9, 1e-5], g))
    ang = np.minimum(ang, 3.0)
    e1 = np.zeros((g, 3))
    e1[:, 0] = 1
    e2 = np.zeros((g, 3))
    e2[:, 0], e2[:, 1] = np.cos(ang), np.sin(ang)
    nl[2 * g:3 * g], nr[2 * g:3 * g] = e1, e2
    count = np.maximum(1, np.floor((1.0 - t0) / dt + 1e-9).astype(np.int64))
    count[:g] = np.round(1.0 / dt[:g]).astype(np.int64) + 1
    m = np.maximum(1, np.ceil(1.0 / dt)).astype(np.int64)
    left = rng.standard_normal((S, kc))
    right = rng.standard_normal((S, kc))
    # ends of any length (render normalizes them): _unit sees them, not unit vectors
    left[:, 1:4] = nl * rng.uniform(0.5, 2.0, (S, 1))
    right[:, 1:4] = nr * rng.uniform(0.5, 2.0, (S, 1))
    return SimpleNamespace(left=left, right=right, m=m, t0=t0, dt=dt, count=count)


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
@pytest.mark.parametrize("method", SPAN_METHODS)
def test_edge_spans_values_identical(method, dtype):
    spec = get_method(method)
    for seed, kc in ((1, 7), (2, 4)):
        sp = _edge_spans(seed, kc=kc)
        assert _check_same(spec, sp, {method: None} if spec.table is not None else None,
                           dtype)
        if spec.table is not None:   # angles beyond the default table: the same error
            assert not _check_same(spec, sp, None, dtype)
    if method == "dichotomy":   # the thresholds of _levels were met
        ends, _ = setup.widest_dot(_edge_spans(1), spec, dtype, False)
        assert ends.hard.sum() > 100


def test_bad_span_values_same_errors():
    spec = get_method("exact")
    base = _edge_spans(3, S=50)
    for field, idx, value in (("left", (4, 1), np.nan), ("right", (7, 2), np.inf),
                              ("dt", 5, -0.5), ("dt", 6, np.inf), ("t0", 9, -1e-6),
                              ("t0", 9, 0.99), ("count", 3, 0), ("m", 2, 0)):
        sp = SimpleNamespace(**{k: np.array(v) for k, v in vars(base).items()})
        getattr(sp, field)[idx] = value
        if field == "left":
            sp.left[idx[0], 1:4] = 0.0     # a zero end normal
        with np.errstate(all="ignore"):
            assert not _check_same(spec, sp, None, np.float64), (field, value)
    # antiparallel ends
    sp = SimpleNamespace(**{k: np.array(v) for k, v in vars(base).items()})
    sp.right[8, 1:4] = -sp.left[8, 1:4]
    assert not _check_same(spec, sp, None, np.float64)


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_method_setup_identical(dtype):
    """slerp, quadratic, angular set-up against the kernels' numpy set-up with DetOps;
    200 000 spans: in float32 some sines, cosines and arc cosines are rounding cases
    that go back to numpy."""
    rng = np.random.default_rng(17)
    S = 200_000
    nl = rng.standard_normal((S, 3))
    nl /= np.linalg.norm(nl, axis=1, keepdims=True)
    nr = nl + 0.4 * rng.standard_normal((S, 3))
    nr /= np.linalg.norm(nr, axis=1, keepdims=True)
    nr[:10] = nl[:10]                      # parallel ends: psi = TINY
    A = np.ascontiguousarray(nl.astype(dtype).T)
    B = np.ascontiguousarray(nr.astype(dtype).T)
    dt = (1.0 / rng.uniform(1, 60, S)).astype(dtype)
    t0 = (rng.random(S) * dt).astype(dtype)
    ops = calibration.DetOps(dtype)
    a, b = tuple(A), tuple(B)
    ref = K.SLERP.setup(ops, a, b)
    got = setup.method_setup(4, A, B, None, None, None, False, 5, ops)
    assert _same(got[0], ref["psi"]) and _same(got[1], ref["inv"])
    for start_left in (False, True):
        t = np.zeros(S, dtype) if start_left else t0
        for coeffs in (None, (0.7, -0.12, 0.014)):
            ref = kernels.quadratic_setup(ops, a, b, t, dt, coeffs, start_left)
            got = setup.method_setup(5, A, B, t, dt, coeffs, start_left, 5, ops)
            assert all(_same(g, r) for g, r in zip(got, ref))
        for n in (1, 2, 7):
            ref = kernels.angular_setup(ops, a, b, t, dt, n, start_left)
            got = setup.method_setup(6, A, B, t, dt, None, start_left, n, ops)
            assert all(_same(g, r) for g, r in zip(got, ref))


# ----------------------------------------------------------- errors through render
_POS = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]])
_QUADS = {
    # vertex normals flipping across a triangle: a zero or antiparallel span end
    "flip": np.array([[0, 0, 1.0], [0, 0, -1.0], [0, 0, 1.0], [0, 0, -1.0]]),
    "side": np.array([[1.0, 0, 0], [-1.0, 0, 0], [1.0, 0, 0], [-1.0, 0, 0]]),
}


@pytest.mark.parametrize("size", [(16, 16), (5, 5), (9, 9)])
@pytest.mark.parametrize("quad", sorted(_QUADS))
def test_bad_meshes_same_errors_through_render(quad, size):
    from chebnorm.raster.scanline import Camera

    mesh = Mesh("bad", _POS, _QUADS[quad], np.array([[0, 1, 2], [1, 3, 2]]))
    cam = Camera((0.5, 0.5, 3.0), (0.5, 0.5, 0.0), (0.0, 1.0, 0.0))
    errors = 0
    for method in method_names():
        for dtype in (np.float32, np.float64):
            kw = dict(size=size, cull=False, camera=cam, dtype=dtype)
            with np.errstate(all="ignore"):
                ref = _outcome(lambda: render(mesh, "phong", method, engine="numpy", **kw))
                got = _outcome(lambda: render(mesh, "phong", method, engine="numba", **kw))
            if isinstance(ref, str):
                errors += 1
                assert got == ref, method
            else:
                assert _same(got.image, ref.image), method
    assert errors >= 2 * (len(method_names()) - 1)   # every method but none refuses


def test_bad_dtype_same_error_through_render():
    for dtype in (np.float16, "float128", "no-such-type"):
        for method in ("exact", "dichotomy"):
            ref = _outcome(lambda: render("sphere", "phong", method, size=(12, 12), tess=6,
                                          dtype=dtype, engine="numpy"))
            got = _outcome(lambda: render("sphere", "phong", method, size=(12, 12), tess=6,
                                          dtype=dtype, engine="numba"))
            assert isinstance(ref, str) and got == ref


def test_default_camera_follows_the_positions():
    """The remembered camera is keyed on the positions' values: moving a vertex in place
    (a mesh's arrays are mutable) gives the camera fitted to the new positions."""
    mesh = get_mesh("sphere", 8)
    size = (40, 30)
    a = render(mesh, "phong", "exact", size=size, engine="numba")
    mesh.positions[0] += [0.0, 0.3, -1.5]     # the pole, out of the bounding box
    b = render(mesh, "phong", "exact", size=size, engine="numba")
    ref = render(mesh, "phong", "exact", size=size, engine="numpy")
    assert _same(b.image, ref.image) and not _same(a.image, b.image)
    cam = fit_camera(mesh.positions, *size)
    assert rasterize.default_camera_of(mesh.positions, *size) == cam


def test_project_identical_and_same_error():
    from chebnorm.raster.scanline import Camera, default_camera, project

    mesh = get_mesh("teapot")
    for size in ((1024, 1024), (37, 91)):
        cam = fit_camera(mesh.positions, *size)
        got, ref = rasterize.project(cam, mesh.positions, *size), project(cam, mesh.positions,
                                                                            *size)
        assert all(_same(g, r) for g, r in zip(got, ref))
    rng = np.random.default_rng(4)
    cam = default_camera((0.0, 0.0, 0.0), 1.0)
    for n in (1, 2, 3, 7, 1000):
        pts = rng.standard_normal((n, 3))
        got, ref = rasterize.project(cam, pts, 64, 48), project(cam, pts, 64, 48)
        assert all(_same(g, r) for g, r in zip(got, ref))
    behind = Camera((0.0, 0.0, 3.0), (0.0, 0.0, 0.0), (0.0, 1.0, 0.0))
    pts = np.array([[0.0, 0.0, 0.0], [0.0, 0.0, 5.0], [1.0, 0.0, 0.0]])
    assert _outcome(lambda: rasterize.project(behind, pts, 8, 8)) == _outcome(
        lambda: project(behind, pts, 8, 8))
    assert "behind the camera" in _outcome(lambda: project(behind, pts, 8, 8))


def test_output_maps_never_shared_with_a_kept_result():
    """Map memory is reused only when the user dropped every view of it: results kept
    (whole, or any one map) are never overwritten by later frames."""
    mesh = get_mesh("torus", 10)
    first = render(mesh, "phong", "exact", size=(48, 40), engine="numba")
    image = first.image.copy()
    tri = first.normal_length      # one map kept, the result dropped
    tri_copy = tri.copy()
    del first
    frames = [render(mesh, "phong", m, size=(48, 40), engine="numba",
                     lighting=R.Lighting(light=(0.3, -1.0, 0.2))) for m in ("lyon", "none")]
    again = render(mesh, "phong", "exact", size=(48, 40), engine="numba")
    assert _same(tri, tri_copy) and _same(again.image, image)
    assert not _same(frames[0].image, frames[1].image)
    ptrs = [r.triangle.base.ctypes.data for r in frames + [again]]
    assert len(set(ptrs)) == len(ptrs)
    assert _reused_after_drop(mesh)


def _reused_after_drop(mesh):
    """A dropped result's memory is the next frame's (outside an assert statement, whose
    rewriting keeps values alive)."""
    r = render(mesh, "phong", "exact", size=(48, 40), engine="numba")
    p = r.normal_length.base.ctypes.data
    del r
    r = render(mesh, "phong", "exact", size=(48, 40), engine="numba")
    return r.normal_length.base.ctypes.data == p


def test_setup_buffers_kept_and_never_shared_with_a_live_setup():
    """The triangle set-up's arrays are views of kept buffers: a set-up still referenced
    keeps its buffers (a second set-up gets others, its values intact), a dropped one's
    are the next set-up's (no fresh pages: a page fault per 4 KiB), and a frame drawn
    on reused buffers has the reference's bytes."""
    from chebnorm.raster.engines import get_engine

    eng = get_engine("numba")
    mesh = get_mesh("teapot")
    a = eng.setup(mesh, None, (64, 48), True)
    a_attrs = a.attrs.copy()
    b = eng.setup(mesh, None, (96, 80), True)      # another camera: other values
    assert not np.shares_memory(a.attrs, b.attrs) and _same(a.attrs, a_attrs)
    assert all(x.flags.c_contiguous for x in (b.xy, b.inv_w, b.pos, b.nrm, b.attrs))
    assert _setup_reused_after_drop(eng, mesh)
    ref = render(mesh, "phong", "exact", size=(96, 80), engine="numpy")
    for _ in range(2):
        got = render(mesh, "phong", "exact", size=(96, 80), engine="numba")
        assert _same(got.image, ref.image) and _same(got.triangle, ref.triangle)


def _setup_reused_after_drop(eng, mesh):
    """A dropped set-up's buffers are the next one's, views of a kept set (outside an
    assert statement)."""
    st = eng.setup(mesh, None, (64, 48), True)
    kept = [bufs for bufs in workspace._SETUP if st.attrs.base is bufs[2]]
    p = st.attrs.ctypes.data
    del st
    st = eng.setup(mesh, None, (64, 48), True)
    return len(kept) == 1 and st.attrs.base is kept[0][2] and st.attrs.ctypes.data == p


@pytest.mark.parametrize("dtype", [np.float64, np.float32])
@pytest.mark.filterwarnings("ignore::RuntimeWarning")     # the reference on NaN normals
def test_end_pass_on_row_spans(dtype):
    """The end normals' pass (widest_dot, then span_input) on the row spans of random
    triangles, with zero, NaN, infinite and antiparallel vertex normals among them
    (errors as the reference's), of the good ones alone, and of the teapot."""
    rng = np.random.default_rng(11)
    T = 400
    xy = rng.random((T, 3, 2)) * [70, 60] - 5
    attrs = rng.standard_normal((T, 3, 7))
    attrs[:4, 0, 1:4] = 0.0
    attrs[4:6, 1, 2] = np.nan
    attrs[6, 2, 3] = np.inf
    attrs[7:10, 1, 1:4] = -attrs[7:10, 0, 1:4]
    st = get_engine("numba").setup(get_mesh("teapot"), None, (300, 260), True)
    seen = set()
    for args in ((xy, attrs, 64, 50), (xy[10:], attrs[10:], 64, 50),
                 (st.xy, st.attrs, 300, 260)):
        rs = rasterize.row_spans(*args)
        assert len(rs.count) > 1000
        # in (triangle, row) order, the order by which the errors name spans
        o = np.lexsort((rs.row, rs.tri))
        sp = SimpleNamespace(**{k: getattr(rs, k)[o] for k in ("tri", "row", "x0", "count",
                                                              "m", "t0", "dt", "left", "right")})
        for name in ("exact", "lyon", "slerp", "dichotomy", "quadratic"):
            seen.add(_check_same(get_method(name), sp, None, dtype))
    assert seen == {True, False}     # the bad spans fail, the others pass


def test_row_spans_identical():
    """rasterize.row_spans (geometry kept between the passes, workspace arrays) against
    the oracle row_spans: random triangles (off screen, horizontal edges, degenerate rows)
    and the teapot."""
    rng = np.random.default_rng(5)
    T = 600
    xy = rng.random((T, 3, 2)) * [70, 60] - 5
    xy[:5, 1, 1] = xy[:5, 0, 1]
    xy[5:9, 2] = xy[5:9, 0]
    attrs = rng.standard_normal((T, 3, 7))
    st = get_engine("numba").setup(get_mesh("teapot"), None, (300, 260), True)
    work = workspace.Workspace()
    for args in ((xy, attrs, 64, 50), (st.xy, st.attrs, 300, 260), (xy, attrs[..., :4], 64, 50)):
        ref = raster_oracles.row_spans(*args)
        for w in (None, work, work):
            got = rasterize.row_spans(*args, work=w)
            for name in ("tri", "row", "x0", "count", "m", "t0", "dt", "left", "right",
                         "row_start", "by_row"):
                assert _same(getattr(got, name), getattr(ref, name)), name
