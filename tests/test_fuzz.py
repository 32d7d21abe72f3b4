"""Property-based fuzzing (issue 26): expressions, table JSON and CLI arguments.

Asserted for every input: never a traceback (the CLI runs in-process and
returns 0 or 2; 2 comes with exactly one line on stderr), never exit 0 with an
output that cannot be read back, and never a stated bound below the true error
(a table the CLI accepts is checked against a dense sample of ``|p - f|``
evaluated at 40 digits with mpmath).

Fixed seed (``derandomize=True``) and fixed budgets, so CI runs the same
inputs each time: 400 expressions through the reader, 40 through ``fit``,
300 mutations of a real table (each through ``export`` in one of four
formats), 300 command lines; 1040 inputs in all, about 30 s on one core.
"""

from __future__ import annotations

import json
from dataclasses import astuple
from pathlib import Path

import mpmath
import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings, strategies as st

from chebnorm.approx import CoefficientTable
from chebnorm.approx.expr import parse_function, read_expression
from conftest import run_cli

FUZZ = dict(derandomize=True, deadline=None, database=None,
            suppress_health_check=list(HealthCheck))


def check_status(status: int, err: str) -> None:
    assert status in (0, 2), (status, err)
    assert "Traceback" not in err
    if status == 2:
        lines = [ln for ln in err.splitlines() if ln.strip()
                 and not ln.startswith("chebnorm: warning:")]
        assert len(lines) == 1 and lines[0].startswith(("chebnorm: error: ", "usage:")), err


def true_errors(table: CoefficientTable, coefficients, points: int = 401) -> tuple[float, float]:
    """``max |p - f|`` and ``max |p/f - 1|`` over a dense grid with the
    endpoints, evaluated at 40 digits (the coefficients are exact doubles)."""
    f = parse_function(table.expression, table.variable).mpmath
    lo, hi = table.interval_float
    worst_abs, worst_rel = mpmath.mpf(0), mpmath.mpf(0)
    with mpmath.workdps(40):
        for x in np.linspace(lo, hi, points):
            xm = mpmath.mpf(float(x))
            p = mpmath.mpf(0)
            for c in reversed(coefficients):
                p = p * xm + mpmath.mpf(c)
            fx = f(xm)
            worst_abs = max(worst_abs, abs(p - fx))
            if fx != 0:
                worst_rel = max(worst_rel, abs(p / fx - 1))
    return float(worst_abs), float(worst_rel)


def check_bound(table: CoefficientTable) -> None:
    """Every bound the table states covers the sampled true error (the 40-digit
    evaluation's own error is far below one part in 1e12 of any bound)."""
    parts = [(table.coefficients, table.abs_error_bound, table.rel_error_bound)]
    if table.fixed_point is not None:
        fp = table.fixed_point
        parts.append((fp.coefficients, fp.abs_error_bound, fp.rel_error_bound))
    for coefficients, abs_bound, rel_bound in parts:
        err_abs, err_rel = true_errors(table, coefficients)
        assert err_abs <= abs_bound * (1 + 1e-12), (table.name, err_abs, abs_bound)
        if rel_bound is not None:
            assert err_rel <= rel_bound * (1 + 1e-12), (table.name, err_rel, rel_bound)


# ---------------------------------------------------------------- expressions
_NUMBERS = st.sampled_from(["2", "0.5", "1e-3", "3", "0x10", "0b1", "1_000", "1e400", "9" * 40,
                            ".5", "5.", "1j", "0", "-1", "10**-300", "1e-300"])
_ATOMS = st.one_of(_NUMBERS, st.sampled_from(["x", "x", "pi", "E", "y", "__import__",
                                              "True", "None", "'s'", "x.real"]))
_FUNCS = st.sampled_from(["sqrt", "exp", "log", "sin", "cos", "atan", "gamma", "Abs", "erf",
                          "tanh", "acos", "eval", "print"])
_OPS = st.sampled_from(["+", "-", "*", "/", "**", "^", "%", "//", "<", "&", " ", ","])


@st.composite
def expressions(draw, depth=3):
    if depth == 0 or draw(st.integers(0, 3)) == 0:
        return draw(_ATOMS)
    kind = draw(st.integers(0, 4))
    if kind == 0:
        return f"{draw(_FUNCS)}({draw(expressions(depth - 1))})"
    if kind == 1:
        return f"log({draw(expressions(depth - 1))}, {draw(_NUMBERS)})"
    if kind == 2:
        return f"-({draw(expressions(depth - 1))})"
    if kind == 3:  # raw noise
        return draw(st.text(alphabet="x0123456789+-*/^()._,eE ijab\n\u00e9", max_size=12))
    return f"{draw(expressions(depth - 1))}{draw(_OPS)}{draw(expressions(depth - 1))}"


@settings(max_examples=400, **FUZZ)
@given(expressions())
def test_reader_never_raises_anything_but_value_error(text):
    try:
        read_expression(text)
        parse_function(text)
    except ValueError:
        pass


@settings(max_examples=40, **FUZZ)
@given(expressions(depth=2), st.sampled_from([("0.5", "2"), ("-1", "1"), ("1", "1e10"),
                                              ("0", "pi")]),
       st.integers(0, 3), st.sampled_from(["chebyshev", "minimax"]))
def test_fit_never_a_traceback_and_bounds_hold(tmp_path_factory, text, interval, degree, kind):
    out = tmp_path_factory.mktemp("fit") / "T.json"
    status, _, err = astuple(run_cli(["fit", text, "--interval", *interval, "--degree", str(degree),
                                      "--kind", kind, "-o", out]))
    check_status(status, err)
    if status == 0:
        check_bound(CoefficientTable.load(out))  # readable, and the bound holds
    else:
        assert not out.exists()


# ---------------------------------------------------------------- table JSON
@pytest.fixture(scope="module")
def real_table(tmp_path_factory) -> dict:
    path = tmp_path_factory.mktemp("real") / "E.json"
    assert run_cli(["fit", "exp(x)", "--interval", "0", "1", "--degree", "3",
                    "--coef-frac-bits", "20", "-o", path]).code == 0
    return json.loads(path.read_text())


_VALUES = st.one_of(
    st.none(), st.booleans(), st.integers(-2 ** 70, 2 ** 70),
    st.floats(allow_nan=False, allow_infinity=False), st.sampled_from([0.0, 1e-30, 1e300, -1.0]),
    st.text(max_size=8), st.sampled_from(["exp(x)", "x", "0x10", "__import__('os')", "1/0"]),
    st.lists(st.floats(-2, 2), max_size=5), st.dictionaries(st.text(max_size=3),
                                                            st.integers(), max_size=2))


def _paths(obj, prefix=()):
    """Every path to a value in a JSON tree."""
    yield prefix
    if isinstance(obj, dict):
        for k, v in obj.items():
            yield from _paths(v, (*prefix, k))
    elif isinstance(obj, list):
        for i, v in enumerate(obj):
            yield from _paths(v, (*prefix, i))


def _numeric(v) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool)


@st.composite
def mutations(draw, table: dict):
    """A real table with one or two changes: half of them scale a number (a
    bound, a coefficient, an endpoint, a bit count), the others delete a key,
    add one, or put a value of another type anywhere."""
    doc = json.loads(json.dumps(table))
    for _ in range(draw(st.sampled_from([1, 1, 1, 2]))):
        paths = [p for p in _paths(doc) if p]
        numeric = [p for p in paths if _numeric(_get(doc, p))]
        scale = numeric and draw(st.booleans())
        path = draw(st.sampled_from(numeric if scale else paths))
        parent = _get(doc, path[:-1])
        if scale:
            factor = draw(st.sampled_from([0, -1, 0.5, 0.999, 1 + 1e-9, 1.5, 2, 1e-20, 1e20]))
            parent[path[-1]] = parent[path[-1]] * factor
            continue
        action = draw(st.integers(0, 2))
        if action == 0 and isinstance(parent, dict):
            del parent[path[-1]]
        elif action == 1 and isinstance(parent, dict):
            parent[draw(st.text(max_size=6))] = draw(_VALUES)
        else:
            parent[path[-1]] = draw(_VALUES)
    return doc


def _get(doc, path):
    for key in path:
        doc = doc[key]
    return doc


def test_table_json_mutations(real_table, tmp_path):
    src = tmp_path / "M.json"
    seen = {"accepted": 0, "refused": 0}

    @settings(max_examples=300, **FUZZ)
    @given(mutations(real_table), st.sampled_from(["c", "json", "glsl", "wgsl"]))
    def one(doc, fmt):
        src.write_text(json.dumps(doc))
        out = tmp_path / f"out.{fmt}"
        out.unlink(missing_ok=True)
        status, _, err = astuple(run_cli(["export", src, "--format", fmt, "-o", out]))
        check_status(status, err)
        if status == 2:
            seen["refused"] += 1
            assert not out.exists()
            return
        seen["accepted"] += 1
        assert out.stat().st_size > 0
        table = CoefficientTable.load(src)  # what export accepted, load accepts
        check_bound(table)
        if fmt == "json":
            check_bound(CoefficientTable.from_dict(json.loads(out.read_text())))
    one()
    assert seen["refused"] > 0  # the mutations do reach the checks


# ---------------------------------------------------------------- CLI arguments
_JUNK = st.sampled_from(["", "-1", "0", "1", "2", "7", "1e3", "nan", "inf", "-inf", "x", "2^3",
                         "99999999999999999999", "0x10", "\u00e9", "--", "-o", "1,2", "None"])


def _opt(flag, values):
    return st.tuples(st.just(flag), st.one_of(st.sampled_from(values), _JUNK))


_COMMANDS = {
    "fit": ([st.just(("exp(x)",)), st.just(("--interval", "0", "1")),
             st.tuples(st.just("--degree"), st.sampled_from(["0", "2", "31", "-1", "x"]))],
            [_opt("--kind", ["minimax", "chebyshev", "remez"]), _opt("--error", ["abs", "rel"]),
             _opt("--coef-frac-bits", ["8", "2000", "8,8,8", "40"]),
             _opt("--coef-format", ["binary32", "fixed", "binary8"]),
             _opt("--monomials", ["0,2", "1", "5"]), _opt("--segments", ["2^2", "3", "2^40"]),
             _opt("--basis", ["shifted", "monomial"]), _opt("--name", ["t", "a b", ""]),
             _opt("--var", ["x", "y", "pi"]), st.just(("--fix-constant",)),
             st.just(("--centered",)), st.just(("--json",))]),
    "methods": ([_opt("--angle", ["0.5", "3.2", "-0.1"]),
                 _opt("--span", ["8", "64", "0", "100000000"])],
                [_opt("--dtype", ["float32", "float16"]), st.just(("--json",)),
                 st.just(("--drift",))]),
    "targets": ([], [_opt("--psi-max", ["pi/4", "2", "-1", "pi"]), st.just(("--json",))]),
    "render": ([st.just(("--size", "16", "16")), st.just(("--engine", "numpy")),
                st.just(("--mesh", "sphere"))],
               [_opt("--shading", ["phong", "gouraud", "adaptive", "split-gouraud", "bump"]),
                _opt("--method", ["exact", "newton", "nope"]), _opt("--tess", ["4", "0"]),
                _opt("--eta-threshold", ["0.1", "-1"]), _opt("--q", ["0.01", "-1"]),
                _opt("--bump", ["square", "full"]), _opt("--shininess", ["8", "0", "-2"]),
                _opt("--reference", ["phong:newton", "bump", "x:y"]),
                _opt("--half-vector", ["triangle", "pixel"]),
                _opt("--crease-angle", ["30", "400"])]),
    "export": ([st.just(("{table}",))],
               [_opt("--format", ["c", "json", "glsl", "hlsl", "wgsl", "pdf"]),
                _opt("--in-bits", ["8", "0"]), _opt("--out-bits", ["8", "40"]),
                _opt("--rounding", ["rne", "trunc", "up"]), _opt("--acc-bits", ["10", "-3"])]),
    "hw report": ([st.just(("{table}",)), st.just(("--no-synth", "--no-gappa")),
                   _opt("--in-bits", ["6", "0", "21"]), _opt("--out-bits", ["6", "33"])],
                  [_opt("--coef-frac-bits", ["12", "60"]), _opt("--acc-bits", ["12", "0"]),
                   _opt("--rounding", ["trunc", "rne", "x"]), _opt("--log-m", ["3", "11"]),
                   _opt("--unit", ["classic", "nope"]), _opt("--x-frac-bits", ["4", "99"]),
                   st.just(("--json",))]),
}


@st.composite
def command_lines(draw):
    name = draw(st.sampled_from(sorted(_COMMANDS)))
    required, optional = _COMMANDS[name]
    argv = name.split()
    for strat in required:
        if draw(st.integers(0, 9)) > 0:  # mostly present
            argv += list(draw(strat))
    for strat in draw(st.lists(st.sampled_from(optional), max_size=3)):
        argv += list(draw(strat))
    return argv


@pytest.fixture(scope="module")
def small_table(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("small") / "T.json"
    assert run_cli(["fit", "1/sqrt(2+z)", "--var", "z", "--interval", "sqrt(2)", "2",
                    "--degree", "2", "--coef-frac-bits", "14", "-o", path]).code == 0
    return path


def test_command_lines(small_table, tmp_path):
    counts = {0: 0, 2: 0}

    @settings(max_examples=300, **FUZZ)
    @given(command_lines())
    def one(argv):
        argv = [a.replace("{table}", str(small_table)) for a in argv]
        out = tmp_path / "o.txt"
        out.unlink(missing_ok=True)
        if argv[0] in ("fit", "export"):
            argv += ["-o", out]
        status, stdout, err = astuple(run_cli(argv))
        check_status(status, err)
        counts[status] += 1
        if status == 0 and "--json" in argv and not ("-o" in argv and argv[0] == "export"):
            json.loads(stdout)  # what --json printed is JSON
        if status == 0 and argv[0] == "fit":
            table = (CoefficientTable.load(out) if "--segments" not in argv
                     and "--centered" not in argv else None)
            if table is not None:
                check_bound(table)
        if status == 2 and argv[0] in ("fit", "export"):
            assert not out.exists()
    one()
    assert counts[0] > 0 and counts[2] > 0

