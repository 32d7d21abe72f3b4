"""Python interop (issue 31): fit from callables and sympy, tables to numpy and
sympy, Python-speaking errors, the callable export module, result displays."""

from __future__ import annotations

import math
import warnings
from fractions import Fraction

import numpy as np
import pytest
import sympy as sp

import chebnorm as cn
from chebnorm.cli import main

EPS = np.finfo(np.float64).eps


# ------------------------------------------------------------------ fit from callables
def test_fit_from_a_ufunc_is_the_string_fit():
    a, b = cn.fit(np.exp, (0, 1), 5), cn.fit("exp(x)", (0, 1), 5)
    assert a.coefficients == b.coefficients
    assert a.abs_error_bound == b.abs_error_bound and a.rel_error_bound == b.rel_error_bound
    assert a.expression == b.expression == "exp(x)"


@pytest.mark.parametrize("fn", [
    lambda z: 1 / np.sqrt(2 + z),
    lambda z: np.power(2 + z, -0.5),
    lambda z: 1 / math.sqrt(2 + z),
    lambda z: (2 + z) ** -0.5,
    lambda z: 1 / sp.sqrt(2 + z),
])
def test_fit_from_callables_and_sympy_with_a_symbol(fn):
    z = sp.Symbol("z")
    ref = cn.fit("1/sqrt(2+z)", ("sqrt(2)", "2"), 2, var="z", kind="minimax")
    for expr in (fn, 1 / sp.sqrt(2 + z)):   # a callable, and a sympy expression
        t = cn.fit(expr, ("sqrt(2)", "2"), 2, var=z, kind="minimax")
        assert t.variable == "z" and t.coefficients == ref.coefficients
        assert t.abs_error_bound == ref.abs_error_bound


def test_math_and_numpy_functions_trace_to_sympy():
    from chebnorm.approx.trace import trace_callable

    x = sp.Symbol("x")
    assert trace_callable(lambda t: math.exp(t) * np.sin(t) + np.log1p(t), x) == \
        sp.exp(x) * sp.sin(x) + sp.log(1 + x)
    assert trace_callable(np.cbrt, x) == sp.root(x, 3)
    assert trace_callable(math.sqrt, x) == sp.sqrt(x) and trace_callable(sp.exp, x) == sp.exp(x)
    # numpy scalars and 0-d arrays are numbers at their exact values
    assert trace_callable(lambda t: t * np.array(2.0) + np.float32(0.1) * t ** 2 + np.int64(3),
                          x) == 2 * x + sp.Rational(*float(np.float32(0.1)).as_integer_ratio()) \
        * x ** 2 + 3
    # a float is the double the callable computes with: np.pi is not pi
    traced = trace_callable(lambda t: np.sin(np.pi * t), x)
    assert not traced.has(sp.pi) and traced == sp.sin(sp.Rational(*math.pi.as_integer_ratio()) * x)


@pytest.mark.parametrize("fn", [
    lambda t: t if t > 0 else -t,               # a branch
    lambda t: np.where(t > 0, t, 0),            # not a ufunc
    lambda t: math.floor(t) + 1,                # a math function without a rule
    lambda t: np.floor(t),                      # a ufunc without a rule
    np.add,                                     # two arguments
    lambda t: "text",                           # not an expression
])
def test_untraceable_callables_are_refused_naming_the_alternative(fn):
    with pytest.raises(ValueError, match="cannot be traced.*pass a string such as 'exp\\(x\\)' or "
                                         "a sympy expression"):
        cn.fit(fn, (0, 1), 2)


def test_var_must_be_a_string_or_symbol():
    with pytest.raises(ValueError, match="var of type int is not accepted.*sympy Symbol"):
        cn.fit("exp(x)", (0, 1), 2, var=3)


def test_piecewise_fit_from_a_callable():
    a = cn.fit(lambda x: 1 / np.sqrt(x), ("1", "4"), 1, segments=4, coef_frac_bits=16)
    b = cn.fit("1/sqrt(x)", ("1", "4"), 1, segments=4, coef_frac_bits=16)
    assert a.segments == b.segments and a.abs_error_bound == b.abs_error_bound


# ------------------------------------------------------------------ errors speak Python
def test_python_errors_name_arguments_and_the_cli_names_flags(capsys):
    with pytest.raises(ValueError, match=r"set it with var=\)") as exc:
        cn.fit("exp(y)", (0, 1), 2)
    assert "--" not in str(exc.value)
    t = cn.fit("exp(x)", (0, 1), 3)
    with pytest.raises(ValueError, match="coef_frac_bits 40 overflows int32.*accepted: coef_frac_bits <= ") \
            as exc:
        cn.quantize(t, 40)
    assert "frac-bits" not in str(exc.value)
    with pytest.raises(ValueError, match="segment_by exponent needs.*interval=\\('1/4', '4'\\)"):
        cn.fit("1/sqrt(x)", ("1", "3"), 1, segment_by="exponent")
    with pytest.raises(ValueError, match="basis='monomial'"):   # the shaders now take it
        cn.quantize(cn.fit("exp(x)", (0, 1), 2, basis="shifted"), 12)
    # the command line keeps its flags
    assert main(["fit", "exp(y)", "--interval", "0", "1", "--degree", "2"]) == 2
    assert "set it with --var)" in capsys.readouterr().err
    assert main(["fit", "exp(x)", "--interval", "0", "1", "--degree", "3",
                 "--coef-frac-bits", "40"]) == 2
    err = capsys.readouterr().err
    assert "--coef-frac-bits 40 overflows" in err and "accepted: --coef-frac-bits <= " in err
    assert main(["fit", "1/sqrt(x)", "--interval", "1", "3", "--degree", "1",
                 "--segment-by", "exponent"]) == 2
    assert "--interval 1/4 4" in capsys.readouterr().err


# ------------------------------------------------------------------ export
def test_export_formats_lists_the_seven_and_takes_name_and_format():
    assert list(cn.export.FORMATS) == list(cn.export.EXPORT_FORMATS) == [
        "c", "glsl", "hlsl", "json", "verilog", "vhdl", "wgsl"]
    t = cn.fit("exp(x)", (0, 1), 3, name="e")
    glsl = cn.export(t, "glsl", name="myexp")
    assert "float chebnorm_myexp(float x)" in glsl and "chebnorm_e(" not in glsl
    assert glsl == cn.export(cn.fit("exp(x)", (0, 1), 3, name="myexp"), format="glsl")
    assert "module chebnorm_v8" in cn.export(t, "verilog", name="v8", in_bits=8, out_bits=8,
                                             coef_frac_bits=12)
    with pytest.raises(ValueError, match="bogus does nothing with format 'glsl'"):
        cn.export(t, "glsl", bogus=1)
    with pytest.raises(ValueError, match="name: 'a b' is not an identifier"):
        cn.export(t, "c", name="a b")
    with pytest.raises(ValueError, match="no export format given; accepted: .*glsl"):
        cn.export(t)


# ------------------------------------------------------------------ conversions
def _tables():
    return [cn.fit("1/sqrt(2+z)", ("sqrt(2)", "2"), 3, var="z"),
            cn.fit("exp(x)", ("-1", "3"), 9, kind="minimax"),
            cn.fit("sin(x)", ("100", "101"), 8, basis="shifted")]


def _points(table, n=401):
    rng = np.random.default_rng(31)
    lo, hi = table.interval_float
    return np.concatenate([np.linspace(lo, hi, n), rng.uniform(lo, hi, n)])


def _local(table, x):
    return x if table.shift is None else (x - table.shift[0]) / table.shift[1]


def _horner_tol(coeffs, t):
    """|two float64 Horner evaluations of sum c_k t^k| apart, t itself within
    one rounding: 4 (n + 1) eps sum (k + 1) |c_k| |t|^k."""
    n = len(coeffs) - 1
    scale = sum((k + 1) * abs(c) * np.abs(t) ** k for k, c in enumerate(coeffs))
    return 4 * (n + 1) * EPS * scale


@pytest.mark.parametrize("which", [0, 1, 2])
def test_to_polynomial_and_chebyshev_evaluate_as_the_table(which):
    table = _tables()[which]
    x = _points(table)
    own = table(x)
    tol = _horner_tol(table.coefficients, _local(table, x))
    p = table.to_polynomial()
    assert isinstance(p, np.polynomial.Polynomial) and p.symbol == table.variable
    assert np.all(np.abs(p(x) - own) <= tol)
    ch = table.to_chebyshev()
    assert isinstance(ch, np.polynomial.Chebyshev)
    assert tuple(ch.domain) == table.interval_float
    # the Chebyshev coefficients are the exact ones rounded once; Clenshaw's error
    # on [-1, 1] and the rounding of the mapped point are bounded by these sums
    a = np.abs(ch.coef)
    n = len(a) - 1
    u = np.abs(ch.mapparms()[0]) + np.abs(ch.mapparms()[1] * x)
    cheb_tol = 8 * (n + 2) * EPS * (a.sum() + u * sum(k * k * a[k] for k in range(n + 1)))
    assert np.all(np.abs(ch(x) - own) <= tol + cheb_tol)
    # and it is the exact series: the certified error of the table still holds for it
    f = np.exp(x) if which == 1 else None
    if f is not None:
        assert np.all(np.abs(ch(x) - f) <= table.abs_error_bound + cheb_tol + 4 * EPS * f)


@pytest.mark.parametrize("which", [0, 1, 2])
def test_to_sympy_is_exact(which):
    table = _tables()[which]
    expr = table.to_sympy()
    var = sp.Symbol(table.variable)
    assert expr.free_symbols == {var}
    exact = sp.Poly(sp.expand(expr), var)
    assert all(c.is_Rational for c in exact.all_coeffs())
    for xi in _points(table, 40):
        value = expr.subs(var, sp.Rational(*float(xi).as_integer_ratio()))
        assert value.is_Rational  # exact: no rounding anywhere
        t = _local(table, xi)
        assert abs(float(value) - float(table(xi))) <= _horner_tol(table.coefficients, t)
    if table.shift is None:
        assert [Fraction(int(c.p), int(c.q)) for c in reversed(exact.all_coeffs())] == \
            [Fraction(c) for c in table.coefficients]


def test_quantized_conversions_and_bound():
    t = cn.fit("1/sqrt(2+z)", ("sqrt(2)", 2), 2, var="z")
    q = cn.quantize(t, 14)
    z = sp.Symbol("z")
    assert q.to_sympy(quantized=True) == sum(sp.Integer(m) / 2 ** 14 * z ** k
                                             for k, m in enumerate(q.quantized.mantissas))
    assert list(q.to_polynomial(quantized=True).coef) == list(q.quantized.coefficients)
    # the quantized table's own bound is the obvious attribute
    assert q.error_bound == q.quantized_error_bound == q.quantized.abs_error_bound
    assert q.error_bound > q.abs_error_bound == t.abs_error_bound  # the JSON field keeps its meaning
    assert t.error_bound == t.abs_error_bound and t.quantized_error_bound is None
    with pytest.raises(ValueError, match="quantized=True: table 'rsqrt_z_2_sqrt_2_2_d2' has no quantized part"):
        t.to_sympy(quantized=True)


def test_asarray_gives_the_coefficients_not_an_object():
    t = cn.fit("exp(x)", (0, 1), 4)
    a = np.asarray(t)
    assert a.dtype == np.float64 and a.shape == (5,) and tuple(a) == t.coefficients
    assert np.asarray(t, dtype=np.float32).dtype == np.float32
    pw = cn.fit("1/sqrt(x)", ("1", "4"), 2, segments=8, coef_frac_bits=20)
    b = np.asarray(pw)
    assert b.dtype == np.float64 and b.shape == (8, 3)
    assert [tuple(r) for r in b] == [pw.coefficients(s) for s in range(8)]


@pytest.mark.parametrize("segment_by,centered", [("uniform", False), ("uniform", True),
                                                 ("exponent", False)])
def test_piecewise_to_sympy_evaluates_as_the_table(segment_by, centered):
    pw = cn.fit("1/sqrt(x)", ("1", "4"), 2, segments=4, coef_frac_bits=20, segment_by=segment_by,
                centered=centered)
    expr = pw.to_sympy()
    assert isinstance(expr, sp.Piecewise) and len(expr.args) == pw.segment_count
    var = sp.Symbol(pw.variable)
    ends = [float(pw.segment_bounds(s)[0]) for s in range(1, pw.segment_count)]
    rng = np.random.default_rng(7)
    xs = np.concatenate([np.linspace(1, 4, 101), rng.uniform(1, 4, 100)])
    coeff_sum = max(sum(abs(c) * (j + 1) for j, c in enumerate(pw.coefficients(s)))
                    for s in range(pw.segment_count))
    # float64 locates the segment and its local variable to a few roundings of x / width
    tol = 16 * (pw.degree + 2) * EPS * coeff_sum * (pw.segment_count + 4)
    for xi in xs:
        if any(abs(xi - e) < 1e-9 for e in ends):
            continue  # on a boundary the two sides may pick different segments
        value = expr.subs(var, sp.Rational(*float(xi).as_integer_ratio()))
        assert value.is_Rational and abs(float(value) - float(pw(xi))) <= tol
    assert expr.subs(var, 5) is sp.nan


# ------------------------------------------------------------------ displays
def _check_display(obj, limit=250, named=True):
    text = repr(obj)
    assert len(text) <= limit, f"{type(obj).__name__} repr is {len(text)} characters: {text}"
    assert text.startswith(type(obj).__name__ + "(")
    html = obj._repr_html_()
    assert html.startswith("<") and (type(obj).__name__ in html or not named)


def test_result_objects_display_briefly():
    from chebnorm.methods.analysis import analyze, error_sweep

    t = cn.fit("exp(x)", (0, 1), 3)
    q = cn.quantize(t, 12)
    objects = [t, q, q.fixed_point, cn.quantize(t, coef_format="binary32").quantized,
               cn.fit("1/sqrt(x)", ("1", "4"), 1, segments=4), cn.target("dichotomy"),
               cn.hw.report.analyze(cn.fit_target("dichotomy", 1), 8, 8, coef_frac_bits=12,
                                    synth=False, gappa=False),
               analyze("newton", 0.5, 8),
               error_sweep(("none", "exact"), [0.2, 0.4], (8,), (np.float64,)),
               cn.span_normals("exact", [[1.0, 0, 0]], [[0.0, 1, 0]], [4])]
    for obj in objects:
        _check_display(obj)
    assert "quantized_error_bound=" in repr(q)
    # user text is escaped in the HTML
    assert "<script>" not in cn.fit("exp(x)", (0, 1), 1,
                                    command="<script>")._repr_html_()


def test_compare_without_flip_reports_not_computed():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        a = cn.render(shading="phong", size=(24, 24), engine="numpy")
        b = cn.render(shading="gouraud", size=(24, 24), engine="numpy")
    m, _ = cn.compare(b, a, flip=False)
    assert m.flip is None and m.max_abs_8bit > 0   # not computed, not a FLIP of 0.0
    assert "<td style='text-align:left'>not computed</td>" in m._repr_html_()
    view = cn.RenderComparison(b, a, flip=False)
    assert "flip=not computed" in repr(view) and "not computed" in view._repr_html_()
    _check_display(view, named=False)   # images, heat map and metrics
    _check_display(a, named=False)
    assert cn.compare(b, a)[0].flip > 0   # computed when asked


# ------------------------------------------------------------------ numba's first compile
def test_numba_compile_is_announced_once_and_not_timed(monkeypatch):
    pytest.importorskip("numba")
    import time

    import importlib

    render_module = importlib.import_module("chebnorm.raster.render")
    from chebnorm.raster.engines.numba import jit

    from chebnorm.raster.engines import get_engine

    monkeypatch.setattr(get_engine("numba"), "warmed", set())
    monkeypatch.setattr(jit, "_ANNOUNCED", __import__("threading").Event())
    monkeypatch.setattr(jit, "ANNOUNCE_AFTER", 0.0)
    slow = 1.0  # a compile that takes this long (the warm-up made slow on purpose)
    real = render_module._warm_up

    def slow_warm_up(*args, **kw):
        time.sleep(slow)
        real(*args, **kw)

    monkeypatch.setattr(render_module, "_warm_up", slow_warm_up)
    with pytest.warns(jit.NumbaCompileWarning, match="numba is compiling the raster engine "
                                                     "for gouraud"):
        first = cn.render("sphere", "gouraud", size=(16, 16), tess=4, engine="numba")
    assert first.compile_seconds >= slow > first.seconds  # a 16x16 frame takes milliseconds
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        second = cn.render("sphere", "gouraud", size=(16, 16), tess=4, engine="numba")
        cn.render("sphere", "phong", size=(16, 16), tess=4, engine="numba")  # once per process
    assert second.compile_seconds == 0.0
    assert not [w for w in caught if issubclass(w.category, jit.NumbaCompileWarning)]


def test_error_curve_of_a_shifted_table_is_within_its_bound():
    # the curve (and so plot()) evaluated the shifted coefficients in x, not t
    t = cn.fit("exp(x)", ("0", "1"), 4, basis="shifted")
    x, g = t.error_curve(201)
    assert abs(g).max() <= t.abs_error_bound   # was 0.65: the powers of x, not of t
    # at the located maximum (an endpoint here, on the grid) the curve is the table's error
    assert t.max_abs_at in (x[0], x[-1])
    assert abs(g[0 if t.max_abs_at == x[0] else -1]) == pytest.approx(t.max_abs_error, rel=1e-12)


def test_piecewise_c_in_bits_named_as_argument_and_as_flag(tmp_path, capsys):
    pw = cn.fit("1/sqrt(x)", ("1", "4"), 1, segments=4, coef_frac_bits=16)
    with pytest.raises(ValueError, match=r"^in_bits = 1 is out of range; accepted: 2 <= in_bits"):
        cn.export(pw, "c", in_bits=1)
    pw.save(tmp_path / "pw.json")
    assert main(["export", str(tmp_path / "pw.json"), "--format", "c", "--in-bits", "1",
                 "-o", str(tmp_path / "pw.h")]) == 2
    assert "error: --in-bits = 1 is out of range; accepted: 2 <= --in-bits" in \
        capsys.readouterr().err
    assert not (tmp_path / "pw.h").exists()
