"""The compiled render path (chebnorm.raster.fast, numba) against the numpy reference:
the same bytes, for spans, visibility, span normals and whole images."""

import numpy as np
import pytest

from chebnorm.methods import method_names, span_normals
from chebnorm.raster import get_mesh, render, setup_spans, zbuffer
from chebnorm.raster import fast

pytestmark = pytest.mark.skipif(not fast.HAVE_NUMBA, reason="numba is not installed "
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
    a, b = fast.fast_setup_spans(xy, attrs, 64, 50), setup_spans(xy, attrs, 64, 50)
    for name in a.__dataclass_fields__:
        assert _same(getattr(a, name), getattr(b, name)), name
    assert _same(fast.fast_zbuffer(a, 64 * 50), zbuffer(b.frag_pixel, b.lerp([0])[:, 0], 64 * 50))
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
        got = fast.fast_span_normals(method, nl, nr, m, dtype=dtype, **kw)
        assert _same(got.normals, ref.normals) and _same(got.offsets, ref.offsets)
        assert _same(got.t, ref.t)
    # exact denominators (tables None) for the table methods
    ref = span_normals(method, nl, nr, m, dtype=dtype, tables={method: None}, **pos)
    got = fast.fast_span_normals(method, nl, nr, m, dtype=dtype, tables={method: None}, **pos)
    assert _same(got.normals, ref.normals)


def test_span_normals_same_errors():
    nl = np.array([[1.0, 0.0, 0.0]])
    for bad in (np.array([[-1.0, 0.0, 0.0]]), np.array([[2.0, 0.0, 0.0]])):
        with pytest.raises(ValueError) as e1:
            span_normals("dichotomy", nl, bad, [4])
        with pytest.raises(ValueError) as e2:
            fast.fast_span_normals("dichotomy", nl, bad, [4])
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


def test_engine_names():
    assert fast.resolve_engine("auto") == "numba"
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
