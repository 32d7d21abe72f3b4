"""Run an exported evaluator over every input of its interval and compare it
with the bound its text states.

:func:`verify` prints a table in a format (or takes the text as shipped),
reads the stated bounds *from what the compiler builds of that text* (the C
header's ``_EVAL_ERROR_BOUND``, ``_F_EVAL_ERROR_BOUND``, ``_Q_EVAL_ERROR_BOUND``,
``_QUANT..._EVAL_ERROR_BOUND`` macros, each printed exactly by a probe compiled
into the same library, ``%La``; the shaders' ``CHEBNORM_NAME_EVAL_ERROR_BOUND``
constant returned by a probe shader on the driver), never from the last
textual definition, runs each evaluator the text defines on every input and
reports the measured ``max |evaluator(x) - f(x)|`` beside the stated bound
(:class:`VerifyResult`). A variant whose bound or inputs cannot be read from
the compiled object is ``unchecked`` (a failure). The text is compiled and
loaded into this process (or run on the GPU driver): code in it runs, so a
``source`` must be trusted code. What runs, per format:

* ``c`` of a coefficient table: the header compiled by ``gcc`` into a
  shared library (called through ``ctypes``, results straight into numpy
  arrays), twice: ``-O2 -ffp-contract=off`` (``unfused``: every ``a * x + c``
  two roundings) and ``-O2 -march=native -ffp-contract=fast`` (``fused``:
  the compiler may contract to FMA). Variants: ``double``, ``double-fused``,
  ``float``, ``float-fused``, and the integer ``fixed`` evaluator (input
  codes ``x_q = x 2^F``) or the ``quant``/``quant-f`` evaluators of a table
  that has them. The double evaluator is run on every float32 of the
  interval, promoted to double (a subset of its inputs: it says so);
* ``c`` of a piecewise table: ``double`` and ``double-fused``, over every
  input code ``k`` (uniform tables) or every float32 of ``[lo, hi)``
  (exponent tables), promoted to double;
* ``glsl``: a compute shader on the OpenGL driver (Mesa's llvmpipe here,
  :func:`chebnorm.export.gpu.glsl_runner`), in dispatches of ``2^20``;
* ``wgsl``: a compute pipeline through ``wgpu`` (Mesa's lavapipe here);
* ``hlsl``: no runtime here: validated by ``glslangValidator``'s HLSL
  front end only, reported as skipped with that reason.

The reference
-------------
``f`` is evaluated in float64 (:mod:`chebnorm.approx.expr`'s numpy
compiler, the C library's functions) at every input, and the ``K`` largest
errors (and 256 inputs evenly spread) are recomputed with Arb at 128 bits,
exactly up to ``1e-30``: ``measured_max`` is the Arb value at the worst
input, so it is attained. ``ref_error`` is the largest ``|f64(x) - f(x)|``
seen over those points (an estimate of the float64 reference's error, about
``1e-16 |f|``, not a proof), and ``upper = max(measured_max, e_K + ref_error)``
(``e_K``: the ``K``-th largest float64-reference error) bounds the true
maximum over every input as far as that estimate holds. A variant passes
when ``upper <= stated_bound``.
"""

from __future__ import annotations

import ctypes
import html
import math
import re
import tempfile
import time
from dataclasses import asdict, dataclass, field
from fractions import Fraction
from pathlib import Path

import numpy as np

from chebnorm.approx import CoefficientTable
from chebnorm.approx.piecewise_table import PiecewiseTable
from chebnorm.core.numeric import arb_precision, float_down, float_up, format_down, format_up
from chebnorm.core.textsafe import identifier
from chebnorm.core.progress import progress_bar
from chebnorm.core.tools import require, run_tool, which
from chebnorm.exceptions import ToolMissing
from chebnorm.core.display import field_rows, summary_html, summary_repr

# an implementation module of chebnorm.export: the API is what chebnorm.export exports
__all__: list[str] = []

#: the formats :func:`verify` runs (or reports as skipped)
VERIFY_FORMATS = ("c", "glsl", "wgsl", "hlsl")
#: the variants of each format (the C ones that a table's header defines)
VARIANTS = {"c": ("double", "double-fused", "float", "float-fused", "fixed", "quant",
                  "quant-fused", "quant-f", "quant-f-fused"),
            "glsl": ("llvmpipe",), "wgsl": ("lavapipe",), "hlsl": ("glslang",)}
#: the most inputs ``inputs="all"`` runs per variant (larger sets: give a count)
MAX_INPUTS = 2 ** 31
_CHUNK = 2 ** 22
_TOP = 64
_SPREAD = 256
_PREC = 128

_UNFUSED = ("-O2", "-ffp-contract=off")
_FUSED = ("-O2", "-march=native", "-ffp-contract=fast")


@dataclass(frozen=True)
class VariantResult:
    """One evaluator's exhaustive check (see the module docstring).

    ``measured_max``/``argmax``/``upper``/``ref_error`` are None for a
    variant that did not run: ``skipped`` gives the reason when this machine
    lacks what runs it (a tool, a driver, a runtime), ``unchecked`` when the
    text defines the evaluator but its stated bound or its inputs cannot be
    read from the compiled object (undefined, not a number): a failure.

    Attributes
    ----------
    format : str
        The format run, one of :data:`VERIFY_FORMATS`.
    variant : str
        The variant, one of ``VARIANTS[format]`` (``"float-fused"``, ...).
    evaluator : str
        The evaluator's name in the text (``chebnorm_NAME_f``, ...).
    bound_name : str
        The macro or constant that states its bound.
    stated_bound : float or None
        That bound as the compiler sees it (C: the macro's value printed
        exactly from the compiled object, rounded down to a double; shaders:
        the constant as the shader computes it); None when it cannot be read.
    measured_max : float or None
        ``max |evaluator(x) - f(x)|`` over the inputs, ``f`` in Arb at 128
        bits at the worst input (so the maximum is attained there).
    argmax : float or None
        The input where ``measured_max`` is attained.
    upper : float or None
        ``max(measured_max, e_K + ref_error)``: a bound of the true maximum
        over every input as far as the float64 reference's error estimate
        holds (module docstring). The variant passes when
        ``upper <= stated_bound``.
    ref_error : float or None
        The largest ``|f64(x) - f(x)|`` seen at the Arb-checked points.
    count : int
        The number of inputs run (``>= 0``).
    inputs : str
        Which inputs, in words (``"every float32 in [LO, HI]"``, a count
        spread evenly, ...).
    seconds : float
        Wall time of the run (compiling included).
    skipped : str or None, default None
        Why the variant did not run on this machine (a missing tool, driver
        or runtime); None when it ran.
    notes : tuple of str, default ()
        Remarks on the run (e.g. whether the target has FMA for a fused
        build, the GPU driver used).
    unchecked : str or None, default None
        Why the variant, defined by the text, could not be checked (its
        stated bound or an input macro is undefined or not a number in the
        compiled object): ``passed`` is then False.

    Examples
    --------
    >>> r = VariantResult("c", "float", "chebnorm_t_f", "CHEBNORM_T_F_EVAL_ERROR_BOUND", 2e-6,
    ...                   1e-6, 0.5, 1e-6, 1e-22, 10, "every float32", 0.1)
    >>> r.passed, r.ratio
    (True, 0.5)
    """

    format: str
    variant: str
    evaluator: str
    bound_name: str
    stated_bound: float | None
    measured_max: float | None
    argmax: float | None
    upper: float | None
    ref_error: float | None
    count: int
    inputs: str
    seconds: float
    skipped: str | None = None
    notes: tuple[str, ...] = field(default=())
    unchecked: str | None = None

    def _summary(self) -> list[tuple[str, object]]:
        if self.unchecked is not None:
            return [("format", self.format), ("variant", self.variant),
                    ("unchecked", self.unchecked)]
        if self.skipped is not None:
            return [("format", self.format), ("variant", self.variant),
                    ("skipped", self.skipped)]
        return [("format", self.format), ("variant", self.variant),
                ("measured_max", self.measured_max), ("stated_bound", self.stated_bound),
                ("argmax", self.argmax), ("count", self.count)]

    _display_rows = field_rows
    __repr__ = summary_repr
    _repr_html_ = summary_html

    @property
    def ratio(self) -> float | None:
        """``measured_max / stated_bound`` (None when skipped)."""
        if self.measured_max is None or not self.stated_bound:
            return None
        return self.measured_max / self.stated_bound

    @property
    def passed(self) -> bool | None:
        """True when the bound holds (``upper <= stated_bound``), False when it
        is exceeded or the variant could not be checked (``unchecked``), None
        when skipped."""
        if self.unchecked is not None:
            return False
        if self.skipped is not None or self.upper is None or self.stated_bound is None:
            return None
        return bool(self.upper <= self.stated_bound)

    def line(self) -> str:
        """One line of text: variant, measured, stated, ratio, inputs, seconds."""
        head = f"{self.format} {self.variant:<14}"
        if self.unchecked is not None:
            return f"{head} NOT CHECKED: {self.unchecked}"
        if self.skipped is not None:
            return f"{head} skipped: {self.skipped}"
        verdict = "ok" if self.passed else "EXCEEDS the stated bound"
        return (f"{head} max {format_down(self.measured_max, '.4e')} at x = {self.argmax!r}  "
                f"stated "
                f"{format_up(self.stated_bound, '.4e')}  ratio {self.ratio:.3f}  {self.count} "
                f"inputs  "
                f"{self.seconds:.2f} s  {verdict}")


@dataclass(frozen=True)
class VerifyResult:
    """The result of :func:`verify`: one :class:`VariantResult` per variant.

    Attributes
    ----------
    table : str
        The table's name.
    format : str
        The format verified, one of :data:`VERIFY_FORMATS`.
    variants : tuple of VariantResult
        One per variant run or skipped, in ``VARIANTS[format]`` order.

    Examples
    --------
    >>> VerifyResult("t", "c", ()).passed
    True
    """

    table: str
    format: str
    variants: tuple[VariantResult, ...]

    @property
    def passed(self) -> bool:
        """False when some variant exceeds its stated bound or could not be
        checked (``unchecked``); variants skipped for want of a tool or
        driver do not count (see :attr:`complete`)."""
        return all(v.passed is not False for v in self.variants)

    @property
    def complete(self) -> bool:
        """True when every variant ran (none skipped, none unchecked)."""
        return all(v.skipped is None and v.unchecked is None for v in self.variants)

    @property
    def not_run(self) -> tuple[VariantResult, ...]:
        """The variants that did not run (skipped or unchecked), with their reasons."""
        return tuple(v for v in self.variants if v.skipped is not None or v.unchecked is not None)

    @property
    def exceeded(self) -> tuple[VariantResult, ...]:
        """The variants whose stated bound the measurement exceeds."""
        return tuple(v for v in self.variants if v.passed is False and v.unchecked is None)

    def to_dict(self) -> dict:
        """Plain data (for JSON), variants in order, with ``ratio`` and ``passed``."""
        rows = []
        for v in self.variants:
            d = {k: (repr(x) if isinstance(x, float) and not math.isfinite(x) else x)
                 for k, x in asdict(v).items()}
            d["notes"] = list(v.notes)
            d["ratio"], d["passed"] = v.ratio, v.passed
            rows.append(d)
        return {"table": self.table, "format": self.format, "passed": self.passed,
                "variants": rows}

    def markdown(self) -> str:
        """A Markdown table: evaluator, measured maximum, stated bound, ratio, inputs."""
        out = ["| evaluator | variant | measured max | stated bound | ratio | inputs |",
               "|---|---|---|---|---|---|"]
        for v in self.variants:
            if v.skipped is not None or v.unchecked is not None:
                why = f"skipped: {v.skipped}" if v.unchecked is None else \
                    f"NOT CHECKED: {v.unchecked}"
                out.append(f"| `{v.evaluator}` | {v.format} {v.variant} | {why} | | | |")
                continue
            out.append(f"| `{v.evaluator}` | {v.format} {v.variant} | "
                       f"{format_down(v.measured_max, '.3e')} | "
                       f"{format_up(v.stated_bound, '.3e')} | {v.ratio:.3f} | {v.count} |")
        return "\n".join(out) + "\n"

    def __str__(self) -> str:
        return "\n".join([f"verify {self.table} --format {self.format}"]
                         + [f"  {v.line()}" for v in self.variants])

    def __repr__(self) -> str:
        return str(self)

    def _repr_html_(self) -> str:
        rows = []
        for v in self.variants:
            cells = ([v.format + " " + v.variant, v.evaluator, "NOT CHECKED: " + v.unchecked, "",
                      "", "", "NOT CHECKED"] if v.unchecked is not None else
                     [v.format + " " + v.variant, v.evaluator, "skipped: " + v.skipped, "", "",
                      "", ""] if v.skipped is not None else
                     [v.format + " " + v.variant, v.evaluator,
                      format_down(v.measured_max, '.4e'),
                      f"{format_up(v.stated_bound, '.4e')}", f"{v.ratio:.3f}", str(v.count),
                      "ok" if v.passed else "EXCEEDS"])
            rows.append("<tr>" + "".join(f"<td>{html.escape(c)}</td>" for c in cells) + "</tr>")
        head = "".join(f"<th>{h}</th>" for h in ("variant", "evaluator", "measured max",
                                                  "stated bound", "ratio", "inputs", ""))
        return (f"<table><caption>verify {html.escape(self.table)} ({self.format})</caption>"
                f"<tr>{head}</tr>{''.join(rows)}</table>")


# ---------------------------------------------------------------- stated bounds

_DEFINE = re.compile(r"^#define\s+(\w+)\s+(\S+)", re.M)
_CONST = re.compile(r"(?:const\s+float\s+|const\s+|static\s+const\s+float\s+)(\w+)\s*(?::\s*f32)?"
                    r"\s*=\s*([-+0-9.eE]+)f?\s*;")


def _number(text: str) -> float | None:
    text = text.rstrip("fF") if not text.lower().startswith("0x") else text.rstrip("fF")
    try:
        return float.fromhex(text) if "0x" in text.lower() else float(text)
    except ValueError:
        return None


def stated_bounds(text: str) -> dict[str, float]:
    """Every ``#define NAME value`` and shader constant of an exported text
    whose value is a number (hexadecimal or decimal), by name.

    A textual read, for looking at a file: it does not know ``#if 0``,
    comments or ``#undef``. :func:`verify` never uses it for the bounds it
    checks; those are read from the compiled object.

    Parameters
    ----------
    text : str
        An exported file (C header or shader source).

    Returns
    -------
    dict of str to float
        Name -> value, for every ``#define`` whose first token is a C
        hexadecimal or decimal floating literal (an ``f`` suffix allowed)
        and every GLSL/WGSL/HLSL ``const`` float; other definitions are
        left out. A later definition of a name replaces an earlier one.

    Examples
    --------
    >>> stated_bounds("#define A_EVAL_ERROR_BOUND 0x1p-20 /* 9.5e-07 */\\nconst B: f32 = 2.5e-01f;")
    {'A_EVAL_ERROR_BOUND': 9.5367431640625e-07, 'B': 0.25}
    """
    out = {}
    for name, value in _DEFINE.findall(text):
        v = _number(value)
        if v is not None:
            out[name] = v
    for name, value in _CONST.findall(text):
        v = _number(value)
        if v is not None:
            out[name] = v
    return out


# ---------------------------------------------------------------- inputs


def _ordered(f: float) -> int:
    bits = int(np.array(f, dtype=np.float32).view(np.int32))
    return bits if bits >= 0 else -(bits & 0x7FFFFFFF)


def _ordered_array(values: np.ndarray) -> np.ndarray:
    bits = np.asarray(values, dtype=np.float32).view(np.int32).astype(np.int64)
    return np.where(bits >= 0, bits, -(bits & 0x7FFFFFFF))


def _from_ordered(keys: np.ndarray) -> np.ndarray:
    keys = np.asarray(keys, dtype=np.int64)
    bits = np.where(keys >= 0, keys, (-keys) | 0x80000000).astype(np.uint32)
    return bits.view(np.float32)


def _inward32(lo: float, hi: float) -> tuple[float, float]:
    lo32, hi32 = np.float32(lo), np.float32(hi)
    if float(lo32) < lo:
        lo32 = np.nextafter(lo32, np.float32(np.inf), dtype=np.float32)
    if float(hi32) > hi:
        hi32 = np.nextafter(hi32, np.float32(-np.inf), dtype=np.float32)
    return float(lo32), float(hi32)


@dataclass(frozen=True)
class _Inputs:
    """A set of inputs, produced in chunks: ``kind`` "f32" (float32 by
    ordered key ``a..b``), "int" (integers ``a..b``), or spread (``keys``
    given)."""

    kind: str
    a: int
    b: int
    keys: np.ndarray | None
    text: str

    @property
    def count(self) -> int:
        return int(self.keys.size) if self.keys is not None else self.b - self.a + 1

    def chunks(self):
        if self.keys is not None:
            for s in range(0, self.keys.size, _CHUNK):
                yield self._values(self.keys[s:s + _CHUNK])
            return
        for s in range(self.a, self.b + 1, _CHUNK):
            yield self._values(np.arange(s, min(s + _CHUNK, self.b + 1), dtype=np.int64))

    def _values(self, keys):
        return _from_ordered(keys) if self.kind == "f32" else keys


def _check_inputs(inputs) -> int | None:
    if inputs == "all":
        return None
    if isinstance(inputs, bool) or not isinstance(inputs, (int, np.integer)) or \
            not 2 <= inputs <= MAX_INPUTS:
        raise ValueError(f"inputs = {repr(inputs)[:40]} is not accepted; accepted: 'all' (every "
                         f"input of the interval) or a count 2..{MAX_INPUTS} (evenly spread)")
    return int(inputs)


def _make_inputs(kind: str, a: int, b: int, spread: int | None, what: str) -> _Inputs:
    if b < a:
        raise ValueError(f"the interval holds no {what}; accepted: a table whose interval "
                         f"holds at least one")
    n = b - a + 1
    if spread is None and n > MAX_INPUTS:
        raise ValueError(f"the interval holds {n} inputs ({what}), more than {MAX_INPUTS}; "
                         f"accepted: inputs = a count (evenly spread)")
    if spread is not None and spread < n:
        keys = _sorted_unique(np.round(np.linspace(a, b, spread)).astype(np.int64))
        if kind == "f32":  # half evenly in value too (float32 order crowds near zero)
            lo, hi = _from_ordered(np.array([a, b]))
            by_value = np.clip(np.linspace(float(lo), float(hi), spread).astype(np.float32),
                               lo, hi)
            keys = _sorted_unique(np.sort(np.concatenate([keys, _ordered_array(by_value)]),
                                          kind="stable"))  # two sorted runs: a merge
            keys = keys[_sorted_unique(np.round(np.linspace(0, keys.size - 1, spread)).astype(
                np.int64))]
        return _Inputs(kind, a, b, keys, f"{keys.size} of the {n} inputs ({what}), evenly "
                       f"spread in order and in value")
    return _Inputs(kind, a, b, None, f"every input: {what} ({n})")


def _sorted_unique(keys: np.ndarray) -> np.ndarray:
    """The distinct values of a sorted array (``np.unique`` without its hash or sort)."""
    if keys.size == 0:
        return keys
    return keys[np.concatenate([[True], keys[1:] != keys[:-1]])]


def _float32_set(lo: float, hi: float, spread, what="float32 in [LO, HI]") -> _Inputs:
    lo32, hi32 = _inward32(lo, hi)
    return _make_inputs("f32", _ordered(lo32), _ordered(hi32), spread, what)


# ---------------------------------------------------------------- the reference


def _arb_of(x) -> object:
    from flint import arb

    if isinstance(x, arb):
        return x
    if isinstance(x, Fraction):
        return arb(x.numerator) / x.denominator
    return arb(float(x))


def _fraction(a) -> Fraction:
    """An arb's midpoint, exactly."""
    m, e = a.mid().man_exp()
    m, e = int(m), int(e)
    return Fraction(m) * Fraction(2) ** e


def _arb_error(fn, x, y) -> tuple[Fraction, Fraction]:
    """(|y - f(x)| upper bound, |f64(x) - f(x)| upper bound) with Arb."""
    from flint import arb

    fx = fn.arb(_arb_of(x))
    err = abs(arb(float(y)) - fx)
    return _fraction(err.upper()), fx


class _Tracker:
    """The running maximum and the ``_TOP`` largest errors over the chunks."""

    def __init__(self):
        self.err = np.empty(0)
        self.x = np.empty(0)
        self.y = np.empty(0)
        self.f = np.empty(0)
        self.key = np.empty(0, dtype=np.int64)
        self.spread = []

    def add(self, key, x64, y64, f64):
        with np.errstate(invalid="ignore"):
            e = np.abs(y64 - f64)
        e = np.where(np.isfinite(e), e, np.inf)  # a non-finite output is an infinite error
        k = min(_TOP, e.size)
        idx = np.argpartition(-e, k - 1)[:k]
        self.err = np.concatenate([self.err, e[idx]])
        self.x = np.concatenate([self.x, x64[idx]])
        self.y = np.concatenate([self.y, y64[idx]])
        self.f = np.concatenate([self.f, f64[idx]])
        self.key = np.concatenate([self.key, np.asarray(key)[idx]])
        keep = np.argsort(-self.err, kind="stable")[:_TOP + 1]
        self.err, self.x, self.y = self.err[keep], self.x[keep], self.y[keep]
        self.f, self.key = self.f[keep], self.key[keep]
        step = max(1, e.size // 16)
        for i in range(0, e.size, step):
            self.spread.append((np.asarray(key)[i], x64[i], y64[i], f64[i]))


def _finish(tracker: _Tracker, fn, exact_x) -> tuple[float, float, float, float]:
    """(measured_max, argmax, upper, ref_error) from the tracked candidates."""
    with arb_precision(_PREC):
        best, best_x = Fraction(-1), None
        ref = Fraction(0)
        top = min(_TOP, tracker.err.size)
        if not np.all(np.isfinite(tracker.err[:top])):
            i = int(np.argmax(~np.isfinite(tracker.err)))
            return math.inf, float(tracker.x[i]), math.inf, 0.0
        for i in range(top):
            e, fx = _arb_error(fn, exact_x(tracker.key[i], tracker.x[i]), tracker.y[i])
            ref = max(ref, _fraction(abs(fx - float(tracker.f[i])).upper()))
            if e > best:
                best, best_x = e, float(tracker.x[i])
        pick = np.linspace(0, len(tracker.spread) - 1, min(_SPREAD, len(tracker.spread)))
        for i in np.unique(np.round(pick).astype(int)):
            key, x, _, f64 = tracker.spread[i]
            fx = fn.arb(_arb_of(exact_x(key, x)))
            ref = max(ref, _fraction(abs(fx - float(f64)).upper()))
    ref_error = float_up(ref)
    rest = float(tracker.err[top]) if tracker.err.size > top else 0.0
    upper = max(float_up(best), float_up(Fraction(rest) + Fraction(ref_error)))
    return float(best), best_x, upper, ref_error


# ---------------------------------------------------------------- running a variant


def _run(fn, evaluate, inputs: _Inputs, to_x64, to_y64, exact_x, what: str = "evaluator"):
    """Evaluate every chunk, track the errors; (measured, argmax, upper, ref, seconds).
    A progress bar names ``what`` on a terminal."""
    fn.numpy, fn.arb  # compiled before the clock starts (cached)
    t0 = time.perf_counter()
    tracker = _Tracker()
    with progress_bar(inputs.count, f"chebnorm verify: {what}", unit="input") as bar:
        for vals in inputs.chunks():
            y = evaluate(vals)
            x64 = to_x64(vals)
            with np.errstate(all="ignore"):
                f64 = fn.numpy(x64)
            tracker.add(vals.view(np.int32).astype(np.int64) if inputs.kind == "f32" else vals,
                        x64, to_y64(y), f64)
            bar.update(len(vals))
    measured, argmax, upper, ref = _finish(tracker, fn, exact_x)
    return measured, argmax, upper, ref, time.perf_counter() - t0


def _f32_exact(key, x):
    return float(x)


# ---------------------------------------------------------------- C

_EVALUATOR = re.compile(r"static inline (double|float|int64_t) (chebnorm_\w+)\("
                        r"(double|float|int64_t|uint32_t) \w+\)")
_CTYPES = {"double": (ctypes.c_double, np.float64), "float": (ctypes.c_float, np.float32),
           "int64_t": (ctypes.c_int64, np.int64), "uint32_t": (ctypes.c_uint32, np.uint32)}


class _CLibrary:
    """The header compiled with a wrapper per evaluator: ``NAME_array(x, y, n)``,
    and a probe per macro of ``macros``: ``chebnorm_verify_probe_I(buf, n)``
    prints the macro's value as the compiler sees it (``%La``, exact), or
    returns -1 when the macro is not defined at the end of the header."""

    def __init__(self, header: str, evaluators, flags, tmp: Path, tag: str, macros=()):
        gcc = require("gcc", "the C check")  # ToolMissing: the C variants are skipped
        base = [header, "#include <stddef.h>", "#include <stdio.h>"]
        for ret, name, arg in evaluators:
            base.append(f"void {name}_array(const {arg} *x, {ret} *y, ptrdiff_t n) "
                        f"{{ for (ptrdiff_t i = 0; i < n; ++i) y[i] = {name}(x[i]); }}")
        self.macros = tuple(macros)
        probes = {m: [f"int chebnorm_verify_probe_{i}(char *buf, int n) {{", f"#ifdef {m}",
                      f"  return snprintf(buf, (size_t) n, \"%La\", (long double) ({m}));",
                      "#else", "  return -1;", "#endif", "}"] for i, m in enumerate(self.macros)}
        self.bad: dict[str, str] = {}
        lib = tmp / f"verify_{tag}.so"

        def build(lines, *extra):
            src = tmp / f"verify_{tag}.c"
            src.write_text("\n".join(lines) + "\n", encoding="utf-8")
            out = ["-fsyntax-only"] if extra else ["-fPIC", "-shared", "-o", str(lib)]
            proc = run_tool([gcc, *flags, "-std=c99", *out, str(src), "-lm"], tool="gcc",
                            timeout=300)
            return proc.returncode == 0, " ".join(proc.stderr.replace(str(src), "header.c")
                                                  .split())[:300]

        ok, err = build(base + [x for m in self.macros for x in probes[m]])
        if not ok:  # the header itself, or a macro that is no number (a probe)
            ok, err = build(base)
            if not ok:
                raise _CompileError(f"gcc {' '.join(flags)} failed: {err}")
            for m in self.macros:
                good, why = build(base + probes[m], "syntax")
                if not good:
                    self.bad[m] = f"{m} is not a number in C (gcc: {why[:200]})"
            ok, err = build(base + [x for m in self.macros if m not in self.bad
                                    for x in probes[m]])
            if not ok:
                raise _CompileError(f"gcc {' '.join(flags)} failed: {err}")
        self.lib = ctypes.CDLL(str(lib))

    def value(self, macro: str) -> Fraction | None:
        """The value of ``macro`` in the compiled object, exactly (None when
        the header leaves it undefined); a value that is not a finite number
        raises :class:`_Unchecked`."""
        if macro in self.bad:
            raise _Unchecked(self.bad[macro])
        f = getattr(self.lib, f"chebnorm_verify_probe_{self.macros.index(macro)}")
        f.restype = ctypes.c_int
        f.argtypes = [ctypes.c_char_p, ctypes.c_int]
        buf = ctypes.create_string_buffer(128)
        if f(buf, 128) < 0:
            return None
        text = buf.value.decode("ascii", "replace")
        value = _hex_fraction(text)
        if value is None:
            raise _Unchecked(f"{macro} is {text} in the compiled header, not a finite number")
        return value

    def evaluator(self, ret: str, name: str, arg: str):
        f = getattr(self.lib, f"{name}_array")
        f.restype = None
        f.argtypes = [ctypes.c_void_p, ctypes.c_void_p, ctypes.c_ssize_t]

        def run(x):
            x = np.ascontiguousarray(x, dtype=_CTYPES[arg][1])
            y = np.empty(x.size, dtype=_CTYPES[ret][1])
            f(x.ctypes.data, y.ctypes.data, x.size)
            return y
        return run


class _Skip(Exception):
    """A variant that cannot run here (the reason in the message)."""


#: a variant that cannot run here: the compiler refused it, or the compiler is missing
_SKIPPED = (_Skip, ToolMissing)


class _Unchecked(Exception):
    """A variant the text defines but whose stated bound or inputs cannot be
    read from the compiled object (the reason in the message): a failure."""


_HEXFLOAT = re.compile(r"([-+]?)0x([0-9a-f]*)(?:\.([0-9a-f]*))?p([-+]?[0-9]+)", re.I)


def _hex_fraction(text: str) -> Fraction | None:
    """The exact value of a C ``%a``/``%La`` output, None when not finite."""
    m = _HEXFLOAT.fullmatch(text.strip())
    if m is None or not (m.group(2) or m.group(3)):
        return None
    digits = (m.group(2) or "") + (m.group(3) or "")
    value = Fraction(int(digits, 16), 16 ** len(m.group(3) or "")) * Fraction(2) ** int(m.group(4))
    return -value if m.group(1) == "-" else value


class _CompileError(_Skip):
    """The C text does not compile (bad input for the unfused build; the
    fused one's ``-march=native`` may be what the compiler refuses)."""


def c_evaluate(text: str, name: str, xs, *, fused: bool = False) -> np.ndarray:
    """The outputs of the evaluator ``name`` that the C ``text`` defines, at
    each input of ``xs``, compiled as :func:`verify` compiles it (``fused``:
    ``-O2 -march=native -ffp-contract=fast``, else ``-O2 -ffp-contract=off``).

    Parameters
    ----------
    text : str
        A C header (``chebnorm export --format c``).
    name : str
        One of its ``static inline`` evaluators, e.g. ``"chebnorm_t_f"``.
    xs : array_like
        Inputs, converted to the evaluator's argument type.
    fused : bool
        Which build.

    Returns
    -------
    numpy.ndarray
        In the evaluator's return type.

    Examples
    --------
    >>> from chebnorm.approx import fit
    >>> from chebnorm.export import c_header
    >>> h = c_header(fit("1/x", ("1", "2"), 2, name="inv"))
    >>> y = c_evaluate(h, "chebnorm_inv_f", [1.0, 1.5])
    >>> y.dtype, bool(abs(y[1] - 1 / 1.5) < 1e-2)
    (dtype('float32'), True)
    """
    found = {m[1]: (m[0], m[2]) for m in _EVALUATOR.findall(text)}
    if name not in found:
        raise ValueError(f"name = {str(name)[:60]!r} is not an evaluator of the text; accepted: "
                         f"{', '.join(sorted(found)) or 'none found'}")
    ret, arg = found[name]
    with tempfile.TemporaryDirectory(prefix="chebnorm-verify-") as tmp:
        try:
            lib = _CLibrary(text, [(ret, name, arg)], _FUSED if fused else _UNFUSED, Path(tmp),
                            "one")
        except _Skip as exc:
            raise RuntimeError(str(exc)) from None
        return lib.evaluator(ret, name, arg)(np.asarray(xs))


def _fused_note() -> str:
    gcc = which("gcc")
    if gcc is None:
        return ""
    proc = run_tool([gcc, "-march=native", "-dM", "-E", "-x", "c", "/dev/null"], tool="gcc",
                    timeout=60)
    return ("the target has FMA (__FMA__)" if "__FMA__" in proc.stdout else
            "no FMA on this target: the fused build cannot contract")


def _c_variants(table: CoefficientTable, text: str, spread) -> list[tuple]:
    """(variant, ret, name, arg, bound macro, fused) of a coefficient table's header."""
    name = identifier(table.name, field="table.name")
    fn, macro = f"chebnorm_{name}", f"CHEBNORM_{name.upper()}"
    found = {m[1]: (m[0], m[2]) for m in _EVALUATOR.findall(text)}
    plan = []
    for suffix, variant, bound in (("", "double", "_EVAL_ERROR_BOUND"),
                                   ("_f", "float", "_F_EVAL_ERROR_BOUND"),
                                   ("_q_eval", "fixed", "_Q_EVAL_ERROR_BOUND"),
                                   ("_quant", "quant", "_QUANT_EVAL_ERROR_BOUND"),
                                   ("_quant_f", "quant-f", "_QUANT_F_EVAL_ERROR_BOUND")):
        if fn + suffix not in found:
            continue
        ret, arg = found[fn + suffix]
        plan.append((variant, ret, fn + suffix, arg, macro + bound, False))
        if variant != "fixed":
            plan.append((variant + "-fused", ret, fn + suffix, arg, macro + bound, True))
    return plan


def _c_coefficient(table: CoefficientTable, text: str, spread, wanted) -> list[VariantResult]:
    from chebnorm.approx.expr import parse_function

    fn = parse_function(table.expression, table.variable)
    name = identifier(table.name, field="table.name")
    macro = f"CHEBNORM_{name.upper()}"
    _require_defines(text, (macro + "_LO", macro + "_HI"), f"table {table.name!r}")
    plan = [p for p in _c_variants(table, text, spread) if wanted is None or p[0] in wanted]
    return _run_c(plan, text, fn, (macro + "_LO", macro + "_HI", macro + "_FRAC_BITS"),
                  lambda p, values: _c_inputs(p, values, macro, spread))


def _require_defines(text: str, names, what: str) -> None:
    """Refuse a text that does not even mention the macros (not a chebnorm
    header); their values are read from the compiled object."""
    defined = {m[0] for m in _DEFINE.findall(text)}
    if not all(n in defined for n in names):
        raise ValueError(f"the C text defines no {' and '.join(names)}; accepted: a header "
                         f"that chebnorm export printed for {what}")


def _macro_value(values, macro: str, integer: bool = False):
    """A macro's value as compiled (a Fraction), or :class:`_Unchecked`."""
    v = values.get(macro)
    if isinstance(v, _Unchecked):
        raise v
    if v is None:
        raise _Unchecked(f"{macro} is not defined in the compiled header")
    if integer and (v.denominator != 1 or not 0 <= v <= 64):
        raise _Unchecked(f"{macro} is {float(v)!r} in the compiled header; accepted: an "
                         f"integer 0..64")
    return int(v) if integer else v


def _interval_of(values, macro: str) -> tuple[float, float]:
    """[LO, HI] as compiled, rounded inward to doubles."""
    lo, hi = _macro_value(values, macro + "_LO"), _macro_value(values, macro + "_HI")
    return float_up(lo), float_down(hi)


def _c_inputs(p, values, macro, spread):
    """(inputs, to_x64, to_y64, exact_x, note) of one C evaluator."""
    variant, ret, _, arg = p[:4]
    lo, hi = _interval_of(values, macro)
    if arg == "int64_t":  # the fixed-point evaluator: every code x_q in [LO, HI] * 2^F
        frac = _macro_value(values, macro + "_FRAC_BITS", integer=True)
        a = math.ceil(Fraction(lo) * 2 ** frac)
        b = math.floor(Fraction(hi) * 2 ** frac)
        scale = 2.0 ** -frac
        return (_make_inputs("int", a, b, spread, f"code x_q = x 2^{frac} in [LO, HI]"),
                lambda q: q.astype(np.float64) * scale,
                lambda y: y.astype(np.float64) * scale,
                lambda key, x: Fraction(int(key), 2 ** frac), "")
    note = ("a double evaluator run on the float32 inputs only (promoted to double)"
            if arg == "double" else "")
    return (_float32_set(lo, hi, spread), lambda v: v.astype(np.float64),
            lambda y: y.astype(np.float64), _f32_exact, note)


def _probe_all(lib, macros) -> dict:
    """Macro -> value (Fraction, None when undefined, or the _Unchecked reason)."""
    out = {}
    for m in macros:
        try:
            out[m] = lib.value(m)
        except _Unchecked as exc:
            out[m] = exc
    return out


def _run_c(plan, text, fn, macros, inputs_of) -> list[VariantResult]:
    """Compile ``text`` (unfused and, for fused variants, fused), read every
    macro of ``macros`` and every stated bound from each compiled object, and
    run each variant of ``plan``."""
    results = []
    macros = tuple(dict.fromkeys([*macros, *(p[4] for p in plan)]))
    with tempfile.TemporaryDirectory(prefix="chebnorm-verify-") as tmp:
        libs = {}
        evaluators = sorted({(p[1], p[2], p[3]) for p in plan})
        for fused in sorted({False} | {p[5] for p in plan}):
            try:
                libs[fused] = _CLibrary(text, evaluators, _FUSED if fused else _UNFUSED,
                                        Path(tmp), "fused" if fused else "unfused", macros)
            except _CompileError as exc:
                if not fused:
                    raise ValueError(f"source: the C text does not compile: {exc}") from None
                libs[fused] = exc
            except _SKIPPED as exc:
                libs[fused] = exc
        base = libs[False]
        values = {} if isinstance(base, _SKIPPED) else _probe_all(base, macros)
        fma = _fused_note() if any(p[5] for p in plan) else ""
        for p in plan:
            variant, ret, name, arg, bound_name, fused = p
            flags = " ".join(_FUSED if fused else _UNFUSED)
            stated = None
            try:
                lib = libs[fused]
                if isinstance(lib, _SKIPPED):
                    raise lib
                stated = float_down(_macro_value(_probe_all(lib, (bound_name,)), bound_name))
                t0 = time.perf_counter()
                inputs, to_x, to_y, exact, note = inputs_of(p, values)
                m, at, up, ref, _ = _run(fn, lib.evaluator(ret, name, arg), inputs, to_x,
                                         to_y, exact, what=f"{name} ({variant})")
                sec = time.perf_counter() - t0  # inputs, evaluation and reference
            except _SKIPPED as exc:
                results.append(VariantResult("c", variant, name, bound_name, stated, None, None,
                                             None, None, 0, "", 0.0, skipped=str(exc)))
                continue
            except _Unchecked as exc:
                results.append(VariantResult("c", variant, name, bound_name, stated, None, None,
                                             None, None, 0, "", 0.0, unchecked=str(exc)))
                continue
            notes = tuple(n for n in (f"gcc {flags}", fma if fused else "", note) if n)
            results.append(VariantResult("c", variant, name, bound_name, stated, m, at, up, ref,
                                         inputs.count, inputs.text, sec, notes=notes))
    return results


def _c_piecewise(table: PiecewiseTable, text: str, spread, wanted) -> list[VariantResult]:
    from chebnorm.approx.expr import enclose, parse_function

    fn = parse_function(table.expression, table.variable)
    name = identifier(table.name, field="table.name")
    macro, cname = f"CHEBNORM_{name.upper()}", f"chebnorm_{name}"
    found = {m[1]: (m[0], m[2]) for m in _EVALUATOR.findall(text)}
    if cname not in found:
        raise ValueError(f"the C text defines no {cname}; accepted: a header that chebnorm "
                         f"export printed for table {table.name!r}")
    ret, arg = found[cname]
    plan = [(v, ret, cname, arg, macro + "_EVAL_ERROR_BOUND", v.endswith("fused"))
            for v in ("double", "double-fused") if wanted is None or v in wanted]
    lo_s, hi_s = float(table.lo), float(table.hi)

    def inputs_of(p, values):
        if arg == "uint32_t":
            bits = _macro_value(values, macro + "_IN_BITS", integer=True)
            if not 1 <= bits <= 32:
                raise _Unchecked(f"{macro}_IN_BITS is {bits} in the compiled header; accepted: "
                                 f"1..32")
            scale = (hi_s - lo_s) * 2.0 ** -bits
            with arb_precision(_PREC):
                lo_a, width = enclose(table.lo, _PREC), enclose(table.hi - table.lo, _PREC)

            def exact(key, x):
                return lo_a + width * int(key) / 2 ** bits
            return (_make_inputs("int", 0, 2 ** bits - 1, spread, f"input code k ({bits} bits)"),
                    lambda k: lo_s + k.astype(np.float64) * scale, lambda y: y,
                    exact, "x = lo + (hi - lo) k / 2^IN_BITS")
        hi_open = float(np.nextafter(np.float32(hi_s), np.float32(-np.inf)))
        return (_float32_set(lo_s, hi_open, spread, "float32 in [lo, hi)"),
                lambda v: v.astype(np.float64), lambda y: y, _f32_exact,
                "a double evaluator run on the float32 inputs only (promoted to double)")
    return _run_c(plan, text, fn, (macro + "_IN_BITS",), inputs_of)


# ---------------------------------------------------------------- shaders


#: a function the probe shader maps input 0, 1, 2 through: LO, HI, the bound
#: (the constants as the shader computes them, never their text)
_PROBE = {"glsl": ("float chebnorm_verify_probe(float i)\n{{\n    if (i < 0.5) return {lo};\n"
                   "    if (i < 1.5) return {hi};\n    return {bound};\n}}\n"),
          "wgsl": ("fn chebnorm_verify_probe(i: f32) -> f32 {{\n    if (i < 0.5) {{ return {lo}; "
                   "}}\n"
                   "    if (i < 1.5) {{ return {hi}; }}\n    return {bound};\n}}\n")}


def _shader(table: CoefficientTable, fmt: str, text: str, spread) -> list[VariantResult]:
    from chebnorm.approx.expr import parse_function

    from .gpu import compute_shader_around, glslang_validate

    name = identifier(table.name, field="table.name")
    cname, macro = f"chebnorm_{name}", f"CHEBNORM_{name.upper()}"
    bounds = stated_bounds(text)
    bound_name = macro + "_EVAL_ERROR_BOUND"
    # the literals as written (HLSL, which nothing runs here, is reported with them);
    # the shaders that run report the constants as the driver computes them
    stated = None if bounds.get(bound_name) is None else float(np.float32(bounds[bound_name]))
    variant = VARIANTS[fmt][0]
    if not re.search(rf"\b{macro}_LO\b", text) or not re.search(rf"\b{macro}_HI\b", text):
        raise ValueError(f"the {fmt} text defines no {macro}_LO and {macro}_HI; accepted: a "
                         f"shader that chebnorm export printed for table {table.name!r}")

    def skipped(reason, unchecked=False):
        return [VariantResult(fmt, variant, cname, bound_name, stated, None, None, None, None,
                              0, "", 0.0, **{"unchecked" if unchecked else "skipped": reason})]
    source = compute_shader_around(text, cname, fmt)
    if fmt == "hlsl":
        try:
            glslang_validate(source, "hlsl")
            return skipped("no HLSL runtime here: the shader compiles under glslangValidator's "
                           "HLSL front end, nothing ran")
        except ToolMissing as exc:
            return skipped(f"no HLSL runtime here, and {exc}")
    try:
        run, close = _glsl(source) if fmt == "glsl" else (_wgsl(source), lambda: None)
    except ToolMissing as exc:
        return skipped(str(exc))
    except Exception as exc:  # the driver's own compile errors
        raise ValueError(f"source: the {fmt} text does not compile on the driver: "
                         f"{' '.join(str(exc).split())[:300]}") from None
    try:
        try:
            lo, hi, stated = _shader_constants(text, fmt, macro)
        except _Unchecked as exc:
            return skipped(str(exc), unchecked=True)
        fn = parse_function(table.expression, table.variable)
        t0 = time.perf_counter()
        inputs = _float32_set(lo, hi, spread)
        m, at, up, ref, _ = _run(fn, run, inputs, lambda v: v.astype(np.float64),
                                 lambda y: y.astype(np.float64), _f32_exact,
                                 what=f"{fmt} {variant}")
        sec = time.perf_counter() - t0
    except ToolMissing as exc:
        return skipped(str(exc))
    except (ValueError, RuntimeError):
        raise
    except Exception as exc:  # the driver's own errors (WGSL compiles at the first dispatch)
        raise ValueError(f"source: the {fmt} text does not run on the driver: "
                         f"{' '.join(str(exc).split())[:300]}") from None
    finally:
        close()
    note = "OpenGL 4.3 compute shader, dispatches of 2^20" if fmt == "glsl" else \
        "WebGPU compute pipeline, dispatches of 2^20"
    return [VariantResult(fmt, variant, cname, bound_name, stated, m, at, up, ref, inputs.count,
                          inputs.text, sec, notes=(note, _driver(fmt)))]


def _shader_constants(text: str, fmt: str, macro: str) -> tuple[float, float, float]:
    """(LO, HI, EVAL_ERROR_BOUND) as the shader computes them: a probe
    function returning each is compiled with the text and run on the driver;
    a constant that is undefined or no float raises :class:`_Unchecked`."""
    from .gpu import compute_shader_around

    probe = _PROBE[fmt].format(lo=f"{macro}_LO", hi=f"{macro}_HI",
                               bound=f"{macro}_EVAL_ERROR_BOUND")
    source = compute_shader_around(text + "\n" + probe, "chebnorm_verify_probe", fmt)
    close = lambda: None  # noqa: E731
    try:
        run, close = _glsl(source) if fmt == "glsl" else (_wgsl(source), lambda: None)
        got = np.asarray(run(np.array([0.0, 1.0, 2.0], dtype=np.float32)), dtype=np.float32)
    except ToolMissing:
        raise
    except Exception as exc:  # the driver's own compile errors
        raise _Unchecked(f"{macro}_LO, {macro}_HI and {macro}_EVAL_ERROR_BOUND cannot be read "
                         f"as float constants of the compiled shader: "
                         f"{' '.join(str(exc).split())[:200]}") from None
    finally:
        close()
    lo, hi, bound = (float(v) for v in got)
    if not all(math.isfinite(v) for v in (lo, hi, bound)):
        raise _Unchecked(f"the compiled shader's {macro}_LO, _HI, _EVAL_ERROR_BOUND are "
                         f"{lo!r}, {hi!r}, {bound!r}: not finite")
    return lo, hi, bound


def _glsl(source):
    from .gpu import gl_context, glsl_runner

    gl_context()
    return glsl_runner(source)


def _wgsl(source):
    from .gpu import MAX_SAMPLES

    try:
        import wgpu
        from wgpu.utils.compute import compute_with_buffers
    except ImportError as exc:
        raise ToolMissing("wgpu is not installed; accepted: pip install 'chebnorm[gpu]'") from exc
    try:
        wgpu.utils.get_default_device()
    except Exception as exc:  # the driver's own error types
        raise ToolMissing(f"no WebGPU adapter ({exc}); accepted: Mesa's lavapipe "
                          f"(apt-get install mesa-vulkan-drivers)") from exc

    def run(xs):
        x = np.ascontiguousarray(xs, dtype=np.float32)
        out = np.empty_like(x)
        for s in range(0, x.size, MAX_SAMPLES):
            part = x[s:s + MAX_SAMPLES]
            got = compute_with_buffers({0: part}, {1: (part.size, "f")}, source,
                                       n=(-(-part.size // 64), 1, 1))
            out[s:s + part.size] = np.frombuffer(got[1], dtype=np.float32)[:part.size]
        return out
    return run


def _driver(fmt: str) -> str:
    try:
        if fmt == "glsl":
            from .gpu import gl_context

            ctx = gl_context()
            with ctx:
                return f"driver: {ctx.info.get('GL_RENDERER') or '?'}"
        import wgpu

        info = wgpu.utils.get_default_device().adapter.info
        return f"driver: {info.get('device', '?')}"
    except Exception:  # noqa: BLE001 -- a description only
        return "driver: unknown"


# ---------------------------------------------------------------- entry point


def verify(table, fmt: str = "c", *, variant=None, inputs="all", source: str | None = None
           ) -> VerifyResult:
    """Run the evaluators of ``table`` exported in ``fmt`` over every input of
    the interval and compare the measured maximum error with the bound the
    exported text states (module docstring).

    Parameters
    ----------
    table : CoefficientTable or PiecewiseTable
        The table (its expression is the reference ``f``).
    fmt : {"c", "glsl", "wgsl", "hlsl"}
        The exported format (a piecewise table: ``"c"`` only).
    variant : str or sequence of str, optional
        The variants to run (:data:`VARIANTS`; default every one the text defines).
    inputs : "all" or int
        ``"all"``: every input (every float32 of the interval; every code of a
        fixed-point or piecewise evaluator), at most :data:`MAX_INPUTS`; a count:
        that many, evenly spread (float32 inputs: half evenly in float32 order,
        half evenly in value, which reaches tiny magnitudes near a zero).
    source : str, optional
        The exported text to check (a file as shipped); default: printed now by
        :func:`chebnorm.export.export_text`.

    Returns
    -------
    VerifyResult

    Raises
    ------
    ValueError
        An unknown format or variant, bad ``inputs``, or a ``source`` that does
        not define the table's evaluator and interval.

    Examples
    --------
    >>> from chebnorm.approx import fit
    >>> t = fit("1/x", ("1", "1 + 2**-14"), 2, name="inv")
    >>> r = verify(t, "c", variant="float")
    >>> r.passed, r.variants[0].count
    (True, 513)
    """
    if isinstance(table, PiecewiseTable):
        accepted = ("c",)
    elif isinstance(table, CoefficientTable):
        accepted = VERIFY_FORMATS
    else:
        raise ValueError(f"table of type {type(table).__name__} is not accepted; accepted: a "
                         f"CoefficientTable or PiecewiseTable")
    if not isinstance(fmt, str) or fmt not in accepted:
        raise ValueError(f"fmt = {str(fmt)[:40]!r} cannot be verified for this table; accepted: "
                         f"{', '.join(accepted)}")
    wanted = _check_variants(fmt, variant)
    spread = _check_inputs(inputs)
    if source is None:
        from . import export_text

        source = export_text(table, fmt)
    elif not isinstance(source, str):
        raise ValueError(f"source of type {type(source).__name__} is not accepted; accepted: "
                         f"the exported text (str)")
    if fmt == "c":
        rows = (_c_piecewise if isinstance(table, PiecewiseTable) else _c_coefficient)(
            table, source, spread, wanted)
    else:
        rows = _shader(table, fmt, source, spread)
    if wanted is not None:
        missing = sorted(set(wanted) - {r.variant for r in rows})
        if missing:
            raise ValueError(f"variant {', '.join(missing)} is not defined by this {fmt} text; "
                             f"defined: {', '.join(r.variant for r in rows) or 'none'}")
    return VerifyResult(table.name, fmt, tuple(rows))


def _check_variants(fmt: str, variant) -> frozenset | None:
    if variant is None:
        return None
    names = [variant] if isinstance(variant, str) else list(variant)
    for v in names:
        if v not in VARIANTS[fmt]:
            raise ValueError(f"variant = {str(v)[:40]!r} is not a variant of format {fmt!r}; "
                             f"accepted: {', '.join(VARIANTS[fmt])}")
    return frozenset(names)
