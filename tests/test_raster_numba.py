"""The compiled engine (chebnorm.raster.engines.numba) against the numpy reference:
the same bytes, for spans, visibility, span normals and whole images."""

import math

import numpy as np
import pytest

from chebnorm.methods import default_tables, detmath, method_names, span_normals
from chebnorm.raster import get_mesh, render, setup_spans, zbuffer
from chebnorm.raster.engines import resolve_engine
from chebnorm.raster.engines.numba import calibration, frame, kernels, rasterize
from chebnorm.raster.meshes import Mesh
from chebnorm.raster.engines.numba.jit import HAVE_NUMBA

pytestmark = pytest.mark.skipif(not HAVE_NUMBA, reason="numba is not installed "
                                "(the compiled path is optional; CI installs it)")

SIZE = (96, 80)


def _same(a, b):
    a, b = np.asarray(a), np.asarray(b)
    return a.dtype == b.dtype and a.shape == b.shape and a.tobytes() == b.tobytes()


def test_spans_and_zbuffer_identical():
    rng = np.random.default_rng(3)
    T = 300
    xy = rng.random((T, 3, 2)) * [70, 60] - 5   # some off screen, some degenerate rows
    xy[:5, 1, 1] = xy[:5, 0, 1]                 # horizontal edges
    attrs = rng.standard_normal((T, 3, 4))
    a, b = rasterize.fast_setup_spans(xy, attrs, 64, 50), setup_spans(xy, attrs, 64, 50)
    for name in a.__dataclass_fields__:
        assert _same(getattr(a, name), getattr(b, name)), name
    assert _same(rasterize.fast_zbuffer(a, 64 * 50), zbuffer(b.frag_pixel, b.lerp([0])[:, 0], 64 * 50))
    assert a.n_fragments > 1000


def _random_spans(seed, n=400):
    rng = np.random.default_rng(seed)
    nl = rng.standard_normal((n, 3))
    nl /= np.linalg.norm(nl, axis=1, keepdims=True)
    nr = nl + 0.6 * rng.standard_normal((n, 3))
    nr /= np.linalg.norm(nr, axis=1, keepdims=True)
    keep = np.einsum("ij,ij->i", nl, nr) > np.cos(np.pi / 4)
    nl, nr = nl[keep], nr[keep]
    m = rng.integers(1, 70, len(nl))
    dt = 1.0 / (m + rng.random(len(nl)))
    t0 = rng.random(len(nl)) * dt
    cnt = np.maximum(1, np.floor((1.0 - t0) / dt).astype(np.int64))
    return nl, nr, m, dict(t0=t0, dt=dt, count=cnt)


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
@pytest.mark.parametrize("method", method_names())
def test_span_normals_identical(method, dtype):
    nl, nr, m, pos = _random_spans(7)
    for kw in (pos, {}):
        ref = span_normals(method, nl, nr, m, dtype=dtype, **kw)
        got = kernels.fast_span_normals(method, nl, nr, m, dtype=dtype, **kw)
        assert _same(got.normals, ref.normals) and _same(got.offsets, ref.offsets)
        assert _same(got.t, ref.t)
    # exact denominators (tables None) for the table methods
    ref = span_normals(method, nl, nr, m, dtype=dtype, tables={method: None}, **pos)
    got = kernels.fast_span_normals(method, nl, nr, m, dtype=dtype, tables={method: None}, **pos)
    assert _same(got.normals, ref.normals)


def test_span_normals_same_errors():
    nl = np.array([[1.0, 0.0, 0.0]])
    for bad in (np.array([[-1.0, 0.0, 0.0]]), np.array([[2.0, 0.0, 0.0]])):
        with pytest.raises(ValueError) as e1:
            span_normals("dichotomy", nl, bad, [4])
        with pytest.raises(ValueError) as e2:
            kernels.fast_span_normals("dichotomy", nl, bad, [4])
        assert str(e1.value) == str(e2.value)


CASES = [("teapot", "phong", m) for m in method_names()] + [
    ("sphere", "phong", "exact"), ("torus", "phong", "dichotomy"), ("teapot", "gouraud", None),
    ("teapot", "adaptive", "newton"), ("torus", "split-gouraud", None),
    ("sphere", "bump", "quadratic"), ("teapot", "bump", "exact")]


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
@pytest.mark.parametrize("mesh,mode,method", CASES)
def test_render_identical(mesh, mode, method, dtype):
    m = get_mesh(mesh, None if mesh == "teapot" else 12)
    ref = render(m, mode, method, size=SIZE, dtype=dtype, engine="numpy")
    got = render(m, mode, method, size=SIZE, dtype=dtype, engine="numba")
    assert _same(got.image, ref.image) and _same(got.mask, ref.mask)
    assert got.fragments == ref.fragments and got.stats == ref.stats
    for name in ("triangle", "normal_length"):
        a, b = getattr(got, name), getattr(ref, name)
        assert (a is None and b is None) or _same(a, b)
    # the triangle map is int32 (meshes.MAX_FACES), -1 on the background, a face elsewhere
    if ref.triangle is not None:
        assert ref.triangle.dtype == np.int32
        assert (ref.triangle[~ref.mask] == -1).all()
        assert ((ref.triangle[ref.mask] >= 0) & (ref.triangle[ref.mask] < len(m.faces))).all()


def test_engine_names():
    assert resolve_engine("auto") == "numba"
    with pytest.raises(ValueError, match="accepted: auto, numpy, numba"):
        render("sphere", size=(8, 8), tess=4, engine="gpu")


def test_render_identical_other_lighting():
    from chebnorm.raster import Lighting

    for light in (Lighting(half_vector="triangle", shininess=7.3, ka=0.0),
                  Lighting(I0=3.0, light=(0.2, -1.0, 0.5), kd=0.9, ks=0.8)):
        ref = render("teapot", "phong", "lyon", size=SIZE, lighting=light, engine="numpy")
        got = render("teapot", "phong", "lyon", size=SIZE, lighting=light, engine="numba")
        assert _same(got.image, ref.image) and _same(got.normal_length, ref.normal_length)
        assert _same(got.triangle, ref.triangle)


# ------------------------------------------------- fused phong (engines.numba.frame)
import raster_oracles  # noqa: E402


def test_fused_spans_identical():
    rng = np.random.default_rng(5)
    T = 400
    xy = rng.random((T, 3, 2)) * [70, 60] - 5
    xy[:5, 1, 1] = xy[:5, 0, 1]
    attrs = rng.standard_normal((T, 3, 7))
    ref = setup_spans(xy, attrs, 64, 50)
    got = raster_oracles.spans(xy, attrs, 64, 50)
    for name in ("tri", "row", "x0", "count", "m", "t0", "dt", "left", "right"):
        assert _same(getattr(got, name), getattr(ref, name)), name
    # the row buckets list every span once, in span order within a row
    assert _same(np.sort(got.by_row), np.arange(len(ref.count)))
    for r in range(50):
        ids = got.by_row[got.row_start[r]:got.row_start[r + 1]]
        assert (ref.row[ids] == r).all() and (np.diff(ids) > 0).all()


def test_row_spans_are_spans_renumbered_by_row(monkeypatch):
    rng = np.random.default_rng(6)
    T = 500
    xy = rng.random((T, 3, 2)) * [70, 60] - 5
    xy[:5, 1, 1] = xy[:5, 0, 1]
    attrs = rng.standard_normal((T, 3, 7))
    ref = raster_oracles.spans(xy, attrs, 64, 50)
    for threads in (1, 2, 3):
        monkeypatch.setattr(raster_oracles, "threads", lambda: threads)
        got = raster_oracles.row_spans(xy, attrs, 64, 50)
        old = np.lexsort((got.row, got.tri))     # the spans() numbering
        for name in ("tri", "row", "x0", "count", "m", "t0", "dt", "left", "right"):
            assert _same(getattr(got, name)[old], getattr(ref, name)), name
        assert _same(got.row_start, ref.row_start)
        assert _same(got.by_row, np.arange(len(ref.count)))
        # row r holds ref's row-r spans, in span order
        assert _same(np.argsort(old), ref.by_row)


def test_det_matches_detmath():
    from chebnorm.methods import detmath

    rng = np.random.default_rng(11)
    for name, lo, hi in (("sin", -4, 4), ("cos", -4, 4), ("arccos", -1.1, 1.1)):
        for dtype in (np.float32, np.float64):
            x = rng.uniform(lo, hi, 200_000).astype(dtype)
            x[:4] = [0.0, -0.0, 1.0, -1.0]
            with np.errstate(invalid="ignore"):
                assert _same(calibration.det(name, x), getattr(detmath, name)(x)), (name, dtype)


def test_calibrated_orders_reproduce_numpy():
    orders = calibration.calibrated()
    assert orders is not None  # on the machines chebnorm is tested on
    rng = np.random.default_rng(2)
    N, H = rng.standard_normal((999, 3)), rng.standard_normal((999, 3))
    assert _same(calibration.dots(N, np.broadcast_to(H[0], N.shape).copy(), orders[0]), N @ H[0])
    assert _same(calibration.dots(N, H, orders[1]), np.einsum("...k,...k->...", N, H))
    assert _same(np.sqrt(calibration.dots(N, N, orders[2])), np.linalg.norm(N, axis=1))


def _spy(monkeypatch, name):
    calls = []
    real = getattr(frame, name)

    def spy(*args, **kw):
        out = real(*args, **kw)
        calls.append(out)
        return out
    monkeypatch.setattr(frame, name, spy)
    return calls


def _check_identical(mesh, method, size, dtype=np.float64, lighting=None, tables=None):
    ref = render(mesh, "phong", method, size=size, dtype=dtype, lighting=lighting, engine="numpy",
                 tables=tables)
    got = render(mesh, "phong", method, size=size, dtype=dtype, lighting=lighting, engine="numba",
                 tables=tables)
    for name in ("image", "mask", "triangle", "normal_length"):
        assert _same(getattr(got, name), getattr(ref, name)), (method, name)
    assert got.fragments == ref.fragments and got.stats == ref.stats
    return got


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
@pytest.mark.parametrize("method", method_names())
def test_fused_phong_identical_larger_frame(method, dtype, monkeypatch):
    # a frame that follows another of its kind assumes that frame's table and draws once;
    # the first of a process may draw twice, so the test makes its own predecessor (the
    # tests share a process in any order, one per xdist worker)
    render(get_mesh("teapot"), "phong", method, size=(256, 200), dtype=dtype, engine="numba")
    calls = _spy(monkeypatch, "phong")
    _check_identical(get_mesh("teapot"), method, (256, 200), dtype)
    assert len(calls) == 1 and calls[0] is not None   # the fused path drew it


def test_fused_slerp_float32_rounding_fixup(monkeypatch):
    # sines whose float32 rounding is in doubt (about 3 in 100 000) go to detmath
    fix = _spy(monkeypatch, "_slerp_fixup")
    _check_identical(get_mesh("teapot"), "slerp", (640, 640), np.float32)
    assert len(fix) == 1


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
@pytest.mark.parametrize("method", method_names())
def test_fused_phong_image_only_identical(method, dtype, monkeypatch):
    # extra_maps=False: the reference's image and mask, no triangle or |N| map; a map the
    # frame does not fill is never written (its pool memory keeps what was there)
    calls = _spy(monkeypatch, "phong")
    ref = render("teapot", "phong", method, size=(256, 200), dtype=dtype, engine="numpy")
    got = render("teapot", "phong", method, size=(256, 200), dtype=dtype, engine="numba",
                 extra_maps=False)
    assert calls and calls[-1] is not None   # the fused path drew it (after a warm-up)
    assert _same(got.image, ref.image) and _same(got.mask, ref.mask), method
    assert got.triangle is None and got.normal_length is None
    assert got.fragments == ref.fragments and got.stats == ref.stats
    # a full frame after an image-only one (the pool's maps) is whole again
    _check_identical(get_mesh("teapot"), method, (256, 200), dtype)


def test_fused_slerp_float32_image_only_fixup(monkeypatch):
    # the hard float32 sines are marked in the triangle map even when it is not returned
    fix = _spy(monkeypatch, "_slerp_fixup")
    ref = render("teapot", "phong", "slerp", size=(640, 640), dtype=np.float32, engine="numpy")
    got = render("teapot", "phong", "slerp", size=(640, 640), dtype=np.float32,
                 engine="numba", extra_maps=False)
    assert len(fix) == 1
    assert _same(got.image, ref.image) and _same(got.mask, ref.mask)


def test_image_only_numpy_engine_and_bad_value():
    ref = render("sphere", "phong", "exact", size=SIZE, tess=8, engine="numpy")
    got = render("sphere", "phong", "exact", size=SIZE, tess=8, engine="numpy",
                 extra_maps=False)
    assert _same(got.image, ref.image) and got.triangle is None and got.normal_length is None
    with pytest.raises(ValueError, match="extra_maps"):
        render("sphere", "phong", "exact", size=SIZE, tess=8, extra_maps="no")


@pytest.mark.parametrize("lighting", [dict(shininess=2.0), dict(shininess=1.0, ka=0.0),
                                      dict(half_vector="triangle", shininess=2.0),
                                      dict(I0=2.5, light=(0.3, 1.0, -0.2), ks=0.9)])
def test_fused_phong_identical_lighting(lighting):
    from chebnorm.raster import Lighting

    for method in ("exact", "angular", "dichotomy"):
        _check_identical(get_mesh("torus", 12), method, SIZE, lighting=Lighting(**lighting))


@pytest.mark.parametrize("size", [(1, 1), (2, 1), (3, 3), (5, 4)])
def test_fused_phong_tiny_frames(size):
    for method in ("exact", "none", "quadratic"):
        _check_identical(get_mesh("sphere", 8), method, size)


@pytest.mark.parametrize("dtype", [np.float64, np.int32, np.bool_])
def test_stream_row_is_slice_assignment(dtype):
    """The frame's rows streamed to its maps (non-temporal stores on the 16-byte aligned
    middle, plain ones at both ends): every dtype of the maps, every start offset and
    length around the 16-byte blocks, an unaligned view as the destination; nothing
    outside the row is touched."""
    rng = np.random.default_rng(30)
    big = np.zeros(300 * 8 + 64, np.uint8)
    for shift in (0, 1, 8):           # the destination's base address mod 16 varies
        raw = big[shift:shift + 300 * np.dtype(dtype).itemsize]
        dst = raw.view(dtype) if raw.ctypes.data % np.dtype(dtype).itemsize == 0 else None
        if dst is None:
            continue
        for start in (0, 1, 3, 7, 16, 33):
            for n in (0, 1, 2, 5, 15, 16, 17, 31, 64, 100, 250):
                if start + n > len(dst):
                    continue
                src = rng.integers(-9, 9, n + 3).astype(dtype)    # longer than n
                before = dst.copy()
                frame._stream_row(dst, start, src, n)     # (a thread sees its own stores)
                want = before.copy()
                want[start:start + n] = src[:n]
                assert _same(dst, want), (shift, start, n)


def _sliver():
    """A strip of triangles far thinner than a pixel: at 31 x 31 it covers three pixels,
    each span one pixel wide."""
    xs = np.linspace(-1.0, 1.0, 11)
    pos = np.array([[x, y, 0.0] for x in xs for y in (-0.004, 0.004)])
    nrm = np.array([[np.sin(0.5 * x), 25.0 * y, np.cos(0.5 * x)] for x, y, _ in pos])
    nrm /= np.linalg.norm(nrm, axis=1)[:, None]
    faces = []
    for i in range(10):
        a, b, c, d = 2 * i, 2 * i + 1, 2 * i + 2, 2 * i + 3
        faces += [[a, b, c], [b, d, c], [a, c, b], [b, c, d]]
    return Mesh("sliver", pos, nrm, np.array(faces, np.int64))


@pytest.mark.parametrize("method", ["slerp", "angular"])
def test_fused_rows_slerp_angular(method, monkeypatch):
    # float64 slerp and angular are drawn row by row (spans, set-up and all) ...
    rows = _spy(monkeypatch, "_phong_rows")
    _check_identical(get_mesh("teapot"), method, (256, 200))
    assert rows and rows[-1] is not None     # (the first render's warm-up frame first)
    # ... and where angular's assumptions about the whole frame fail (every span one
    # pixel wide: no second pixel to start the recurrence from), the rows give the frame
    # up and the frame-sized spans draw it, the same bytes
    rows.clear()
    got = _check_identical(_sliver(), method, (31, 31))
    assert got.mask.sum() >= 2 and got.mask.sum(axis=1).max() == 1
    assert len(rows) == 1 and (rows[0] is None) == (method == "angular")


def test_fused_rows_quadratic_table_assumed_then_checked(monkeypatch):
    # the quadratic's table is chosen by every span of the frame: the rows assume the
    # table of the last frame of that kind (the default one the first time) and check it
    # once every span is known; a wrong guess draws the frame again with the frame-sized
    # spans (the same bytes and stats as numpy, tables widened or not)
    monkeypatch.setattr(frame, "_TABLE_GUESS", {})
    rows = _spy(monkeypatch, "_phong_rows")
    got = _check_identical(get_mesh("teapot"), "quadratic", (256, 200))
    assert got.stats["table_psi_max"] == "9*pi/32"     # wider than the default pi/4
    assert rows[-1] is None                             # so the guess failed
    rows.clear()
    _check_identical(get_mesh("teapot"), "quadratic", (256, 200))
    assert len(rows) == 1 and rows[0] is not None       # the second frame: rows
    rows.clear()
    got = _check_identical(get_mesh("teapot"), "quadratic", (320, 240))
    assert "table_psi_max" not in got.stats and len(rows) == 1 and rows[0] is not None
    # a caller's table is the rows' table
    tables = default_tables(psi_max="10*pi/32")
    rows.clear()
    _check_identical(get_mesh("teapot"), "quadratic", (256, 200), tables=tables)
    assert rows and rows[-1] is not None    # (after the warm-up frame of that kind)


def test_span_level_libm_is_span_levels():
    # the dichotomy depth of the spans ends_part leaves to the reference (1/dt near a
    # power of two, the cosine near a depth threshold), compiled with the C library's
    # log2 and acos, against the reference's span_levels, span by span
    from chebnorm.methods.spans import PICK_TOL, span_levels
    from chebnorm.raster.engines.numba.setup import levels_calibrated, span_level_libm
    rng = np.random.default_rng(7)
    ulps = 1.0 + np.arange(-40, 41) * 2.0 ** -52
    width = np.concatenate([(2.0 ** np.arange(0, 11)[:, None] * ulps).ravel(),
                            (2.0 ** np.arange(0, 11)[:, None] * (1 + rng.uniform(-2e-6, 2e-6, 200))).ravel(),
                            rng.uniform(0.5, 300.0, 5_000)])
    dt = 1.0 / width
    t0 = rng.uniform(0.0, 1.0, dt.size) * dt * rng.integers(0, 2, dt.size)
    count = np.maximum(1, np.minimum(np.floor(width), 12).astype(np.int64))
    theta = 2.0 * math.acos(1.0 - PICK_TOL) * 2.0 ** rng.integers(0, 6, dt.size)
    cos = np.cos(theta) * (1.0 + rng.uniform(-3e-6, 3e-6, dt.size))
    cos[::2] = rng.uniform(-0.5, 1.0, cos[::2].size)
    ref = span_levels(dt, t0, count, cos)
    got = np.array([span_level_libm(a, b, n, c) for a, b, n, c in zip(dt, t0, count, cos)])
    assert (got == ref).all()
    assert levels_calibrated()
    # 1/dt not a finite normal number: left to the reference's own function, which the
    # rows call from compiled code (objmode) for those
    assert span_level_libm(1e-320, 0.0, 1, 1.0) == -1
    with np.errstate(all="ignore"):    # (the reference's 1/1e-320 overflows)
        for args in [(1e-320, 0.0, 1, 1.0), (0.25, 0.1, 3, 0.9), (dt[5], t0[5], count[5], cos[5])]:
            ref = int(span_levels(*[np.array([a]) for a in args])[0])
            assert frame._reference_level(*args) == ref


def test_fused_rows_dichotomy(monkeypatch):
    # the dichotomy drawn row by row: its table and its depths off the dyadic grid
    # assumed, checked once the rows are done; the same bytes as numpy
    rows = _spy(monkeypatch, "_phong_rows")
    _check_identical(get_mesh("teapot"), "dichotomy", (256, 200))
    rows.clear()
    _check_identical(get_mesh("teapot"), "dichotomy", (256, 200))
    assert len(rows) == 1 and rows[0] is not None
    # a depth the rows assumed off the dyadic grid whose pixels all turn out on it (made
    # so by clearing what the rows found): the rows give the frame up, the frame-sized
    # spans draw it
    real = frame.run_with_caller

    def run(jobs):
        out = real(jobs)
        if jobs[0][0] is frame._frame_rows:
            for _, args in jobs:
                args[-2][1, :] = False     # offs[q] (then stop): no pixel of any depth off its grid
        return out
    monkeypatch.setattr(frame, "run_with_caller", run)
    rows.clear()
    _check_identical(get_mesh("teapot"), "dichotomy", (256, 200))
    assert len(rows) == 1 and rows[0] is None


def test_fused_falls_back_without_calibration(monkeypatch):
    monkeypatch.setattr(frame, "calibrated", lambda: None)
    calls = _spy(monkeypatch, "_frame")
    _check_identical(get_mesh("teapot"), "lyon", SIZE)
    assert not calls


def test_fused_renders_in_a_forked_child():
    import multiprocessing as mp

    render("sphere", "phong", "exact", size=(24, 24), tess=8)   # the parent's thread pool
    ctx = mp.get_context("fork")
    with ctx.Pool(1) as pool:
        child = pool.apply(_render_bytes, ((24, 24),))
    assert child == _render_bytes((24, 24))


def _render_bytes(size):
    return render("sphere", "phong", "exact", size=size, tess=8, engine="numba").image.tobytes()


# ------------------------------------------- the frame's shortcut for b ** n
def _powers(b, sh, fast):
    n = len(b)
    out, hh, ll, ok = np.empty(n), np.empty(n), np.empty(n), np.empty(n, np.bool_)
    calibration.powers(b, float(sh), fast, hh, ll, ok, out, n)
    return out, ok


@pytest.mark.parametrize("n", [3, 5, 7, 32, 64, 100, 255, 1000, 65536])
def test_pow_shortcut_gives_pow_bits(n):
    rng = np.random.default_rng(n)
    b = np.concatenate([rng.random(100_000), 1.0 - rng.random(50_000) * 2.0 ** -30,
                        1.0 + rng.random(20_000) * 0.5, 2.0 ** rng.uniform(-900, -1, 5_000) / n,
                        [0.0, 1.0, 0.5, 2.0 ** -30, np.nan, np.inf, 1e-300]])
    with np.errstate(all="ignore"):
        # the reference renderer's power: the C library's pow (numpy's power loop is
        # SVML on AVX-512 machines, other bits; detmath's own tests check it is pow)
        ref = detmath.power(b, float(n))
        got, ok = _powers(b, n, True)
    assert got.tobytes() == ref.tobytes()
    # the shortcut, not pow, made most of those in its range (about 90 %: the others are
    # within 0.05 ulp of a tie)
    inside = (ref > 2.0 ** -890) & (ref < 2.0 ** 990) & (b > 2.0 ** -890)
    assert inside.sum() > 10_000 and ok[inside].mean() > 0.85


@pytest.mark.parametrize("n", [3, 4, 32, 33, 65536])
def test_pow_shortcut_zero_base_is_pow_without_a_call(n):
    # a clipped N.H is often +-0: the shortcut takes it (ok) and gives pow's signed zero
    # (C99 F.9.4.4: pow(-0, odd n) = -0, pow(-0, even n) = +0), checked against the C
    # library's pow itself
    b = np.array([0.0, -0.0, 0.0, -0.0])
    ref = detmath.power(b, float(n))
    got, ok = _powers(b, n, True)
    assert got.tobytes() == ref.tobytes()
    assert ok.all()
    assert np.signbit(got[1]) == bool(n % 2)


@pytest.mark.parametrize("n", [3, 32, 1000, 65536])
def test_pow_shortcut_near_one_margin_gives_pow_bits(n):
    # b in [exp(-64/n), 1]: the shortcut's margin is 0.48 ulp there (glibc's bound for
    # |n log b| <= 64 is below 0.514 ulp); the band 0.45 .. 0.48 ulp is exercised
    rng = np.random.default_rng(1000 + n)
    b = np.exp(-rng.random(400_000) * 64.0 / n)
    hh, ll = np.empty(len(b)), np.empty(len(b))
    ok, out = np.empty(len(b), np.bool_), np.empty(len(b))
    calibration.powers(b, float(n), True, hh, ll, ok, out, len(b))
    assert out.tobytes() == detmath.power(b, float(n)).tobytes()
    band = ok & (np.abs(ll) > 0.45 * np.spacing(hh))
    assert band.sum() > 1000 and ok.mean() > 0.9


def test_pow_shortcut_is_correctly_rounded_where_taken():
    # independent of the C library: exact rational powers
    from fractions import Fraction

    rng = np.random.default_rng(4)
    for n in (3, 32, 1000):
        b = rng.random(400)
        got, ok = _powers(b, n, True)
        for x, y, k in zip(b, got, ok):
            if not k:
                continue
            exact = Fraction(float(x)) ** n
            ulp = Fraction(np.spacing(y))
            # 0.48 ulp where |n log b| <= 64 (glibc's pow is within 0.514 ulp there),
            # else 0.45 (its 0.54 ulp bound)
            near = n * abs(math.log(x)) <= 64.0
            margin = Fraction(48, 100) if near else Fraction(45, 100)
            assert abs(Fraction(float(y)) - exact) <= margin * ulp + ulp / 2 ** 40


def _trig(kind, x):
    n = len(x)
    out, ok = np.empty(n), np.empty(n, np.bool_)
    calibration.trig64(kind, np.ascontiguousarray(x, np.float64), out, ok, np.empty((5, n)), n)
    return out, ok


@pytest.mark.parametrize("kind", [0, 1])
def test_trig_shortcut_gives_libm_bits(kind):
    # the float64 reference is math.sin / math.cos (detmath); other arguments than the
    # calibration's, and ones the shortcut hands to the library
    import math

    rng = np.random.default_rng(77 + kind)
    x = np.concatenate([rng.random(400_000) * 1.5, rng.random(100_000) * 2.0 ** -7,
                        2.0 ** rng.uniform(-60, 0, 50_000), np.arange(97) / 64 + 2.0 ** -50,
                        np.arange(1, 97) / 64 - 2.0 ** -50, rng.uniform(1.5, 3.2, 1000),
                        [0.0, -0.0, 2.0 ** -600, -0.3, 1.5, np.nan, np.inf, -np.inf]])
    fn = math.sin if kind == 0 else math.cos
    ref = np.fromiter((fn(v) if math.isfinite(v) else math.nan for v in x.tolist()), float,
                      len(x))
    got, ok = _trig(kind, x)
    nan = np.isnan(ref)
    assert (np.isnan(got) == nan).all() and got[~nan].tobytes() == ref[~nan].tobytes()
    # most of the range is the shortcut's (about 88 %: the rest is within 0.06 ulp of a tie)
    inside = (x >= 2.0 ** -500) & (x <= 1.5)
    assert ok[inside].mean() > 0.8 and not ok[~inside].any()


def test_trig_shortcut_is_correctly_rounded_where_taken():
    # independent of the C library: mpmath at 200 bits
    import mpmath
    from fractions import Fraction

    rng = np.random.default_rng(5)
    x = np.concatenate([rng.random(300) * 1.5, rng.random(100) * 2.0 ** -8])
    for kind, fn in ((0, mpmath.sin), (1, mpmath.cos)):
        got, ok = _trig(kind, x)
        with mpmath.workprec(200):
            for v, y, k in zip(x, got, ok):
                if not k:
                    continue
                exact = fn(mpmath.mpf(float(v)))
                ulp = Fraction(np.spacing(y))
                m, e = exact.man_exp
                err = abs(Fraction(float(y)) - Fraction(int(m)) * Fraction(2) ** int(e))
                assert err <= Fraction(44, 100) * ulp + ulp / 2 ** 10


def _sin_small(x):
    n = len(x)
    out, ok = np.empty(n), np.empty(n, np.bool_)
    calibration.sin_small(np.ascontiguousarray(x, np.float64), out, ok, n)
    return out, ok


def test_sin_small_gives_libm_bits():
    # the float64 reference is math.sin (detmath): other arguments than the calibration's,
    # the range's edges, powers of two, and arguments the shortcut hands to the library
    import math

    rng = np.random.default_rng(91)
    edges = np.array([0.126, 2.0 ** -26, 2.0 ** -27] + [2.0 ** -k for k in range(2, 60)])
    x = np.concatenate([rng.random(500_000) * 0.126, rng.random(200_000) * 2.0 ** -5,
                        2.0 ** rng.uniform(-70, -2.9, 100_000), rng.uniform(0.126, 1.5, 5000),
                        (edges[:, None] * (1.0 + np.arange(-16, 17) * 2.0 ** -52)).ravel(),
                        [0.0, -0.0, 2.0 ** -600, -0.01, np.nan, np.inf, -np.inf]])
    ref = np.fromiter((math.sin(v) if math.isfinite(v) else math.nan for v in x.tolist()),
                      float, len(x))
    got, ok = _sin_small(x)
    nan = np.isnan(ref)
    assert (np.isnan(got) == nan).all() and got[~nan].tobytes() == ref[~nan].tobytes()
    # nearly all of [0, 0.126) is the shortcut's; nothing outside it
    inside = (x >= 2.0 ** -500) & (x < 0.126)
    assert ok[inside].mean() > 0.97 and not ok[~inside].any()


def test_sin_small_margin_holds_where_taken():
    # independent of the C library (mpmath at 200 bits): where the shortcut is taken,
    # its value is within (0.5 - 0.004 - 0.3 x**2) ulp of sin x (what the margin argument
    # of calibration.sin_small needs, with room: 0.496 - 3 x**2 and at most 1.34 x**2
    # of its own error)
    import mpmath
    from fractions import Fraction

    rng = np.random.default_rng(6)
    x = np.concatenate([rng.random(400) * 0.126, rng.random(200) * 2.0 ** -6,
                        0.126 - rng.random(100) * 2.0 ** -8])
    got, ok = _sin_small(x)
    with mpmath.workprec(200):
        for v, y, k in zip(x, got, ok):
            if not k:
                continue
            exact = mpmath.sin(mpmath.mpf(float(v)))
            ulp = Fraction(np.spacing(y))
            m, e = exact.man_exp
            err = abs(Fraction(float(y)) - Fraction(int(m)) * Fraction(2) ** int(e))
            xx = Fraction(float(v)) ** 2
            assert err <= (Fraction(496, 1000) - 3 * xx + Fraction(134, 100) * xx) * ulp


def test_trig_calibrated():
    assert calibration.trig_calibrated() == HAVE_NUMBA


def test_pow_calibrated():
    assert calibration.pow_calibrated(32.0) and calibration.pow_calibrated(3.0)
    assert not calibration.pow_calibrated(2.0)       # numpy squares; the frame does too
    assert not calibration.pow_calibrated(32.5) and not calibration.pow_calibrated(1e6)


@pytest.mark.parametrize("shininess", [3.0, 17.0, 32.0, 200.0, 31.9])
def test_fused_phong_identical_shininess(shininess):
    from chebnorm.raster import Lighting

    _check_identical(get_mesh("teapot"), "exact", (160, 128),
                     lighting=Lighting(shininess=shininess))


def test_fused_span_buffers_per_thread():
    # the span arrays are reused between frames, one set per thread: renders running at
    # once in two threads, and frames of growing and shrinking size, draw what they draw
    # alone
    from concurrent.futures import ThreadPoolExecutor

    cases = [("teapot", "exact", (200, 160)), ("torus", "dichotomy", (120, 96)),
             ("sphere", "slerp", (64, 64)), ("teapot", "angular", (260, 240))]
    alone = [render(get_mesh(m, None if m == "teapot" else 12), "phong", meth, size=sz,
                    engine="numpy").image.tobytes() for m, meth, sz in cases]
    def draw(case):
        m, meth, sz = case
        return render(get_mesh(m, None if m == "teapot" else 12), "phong", meth, size=sz,
                      engine="numba").image.tobytes()
    with ThreadPoolExecutor(2) as pool:
        for _ in range(3):
            assert list(pool.map(draw, cases + cases[::-1])) == alone + alone[::-1]


@pytest.mark.parametrize("order", [0, 1, 2])
def test_dot3_select_is_dot3(order):
    """The branch-free dot product of the fused shading loop sums in the order it is
    given, to the bit: against exact rational arithmetic rounded per operation."""
    from fractions import Fraction as Q

    def rnd(q):          # one rounding to the nearest float64
        return Q(float(q))

    rng = np.random.default_rng(30 + order)
    vals = rng.standard_normal((300, 6)) * np.exp2(rng.integers(-30, 30, (300, 6)))
    for a0, a1, a2, b0, b1, b2 in vals:
        A, B = [Q(float(v)) for v in (a0, a1, a2)], [Q(float(v)) for v in (b0, b1, b2)]
        p = [rnd(A[i] * B[i]) for i in range(3)]
        if order == 0:
            want = rnd(rnd(p[0] + p[1]) + p[2])
        elif order == 1:
            want = rnd(rnd(p[0] + p[2]) + p[1])
        else:
            want = rnd(A[2] * B[2] + rnd(A[0] * B[0] + p[1]))
        got = calibration.dot3_select(a0, a1, a2, b0, b1, b2, order)
        assert got == float(want)
        assert got == calibration.dot3(a0, a1, a2, b0, b1, b2, order)
