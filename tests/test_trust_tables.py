"""Issue 11, items 2 and 3: a table read from a file proves its own claims, and
no text in it (or on the command line) can inject code into C or Verilog.

* Reading (``CoefficientTable.load``/``from_json``/``from_dict``) checks every
  field (the refusal names it) and re-certifies every stated bound; the true
  errors used to judge the tampered tables come from mpmath at 40 digits, not
  from the certifier under test.
* A tampered table is refused by ``export``, ``hw verilog``, ``hw report`` and
  ``hw unit --table`` with exit 2 and one line naming the field.
* Hostile strings in every text field give a refusal naming the field, or a
  header / Verilog file that compiles (gcc -std=c99 -Wall -Wextra -Werror
  -pedantic, iverilog) and whose code, comments removed by the compiler's own
  preprocessor, is exactly that of the clean table: no extra declaration.
* An untouched committed table loads and exports byte-identically to the
  committed header (written by the code before this change).
"""

from __future__ import annotations

import json
import re
import subprocess
from dataclasses import astuple, replace
from pathlib import Path

import mpmath
import pytest

from chebnorm.approx import CoefficientTable, fit
from chebnorm.approx.contract import construction
from chebnorm.approx.table import MAX_TEXT
from chebnorm.cli import main
from conftest import requires_tool, run_cli, run_process, tool_missing
from chebnorm.export import c_header

ROOT = Path(__file__).resolve().parents[1]
COEFFS = ROOT / "figures" / "coefficients"
TABLES = sorted(COEFFS.glob("*.json"))
needs_gcc = requires_tool("gcc")
needs_iverilog = requires_tool("iverilog")
CFLAGS = ["-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic"]
BASE = COEFFS / "dichotomy_d2.json"  # 1/sqrt(z + 2) on [sqrt(2), 2], fixed point at 24 bits


def base() -> dict:
    return json.loads(BASE.read_text())


#: the committed table's first fixed-point integer and stated bound (the messages name them)
_INT0 = base()["fixed_point"]["integers"][0]
_FP_BOUND = f"{base()['fixed_point']['abs_error_bound']:.2e}".replace(".", r"\.").replace("+", r"\+")


# -- an independent reference: the true sup of |p - f| from mpmath -------------

def true_sup(coefficients, kind="abs", points=4001):
    """max over a dense grid plus a golden-section refinement around the best
    point, at 40 digits, of |p - f| or |p/f - 1| for f = 1/sqrt(z + 2) on
    [sqrt(2), 2] (a lower bound of the supremum, accurate to far below the
    differences the tests look at)."""
    with mpmath.workdps(40):
        lo, hi = mpmath.sqrt(2), mpmath.mpf(2)
        cs = [mpmath.mpf(c) for c in coefficients]

        def g(z):
            p = mpmath.polyval(cs[::-1], z)
            f = 1 / mpmath.sqrt(z + 2)
            return abs(p - f) if kind == "abs" else abs(p / f - 1)

        xs = [lo + (hi - lo) * k / (points - 1) for k in range(points)]
        vals = [g(x) for x in xs]
        i = max(range(points), key=lambda k: vals[k])
        a, b = xs[max(i - 1, 0)], xs[min(i + 1, points - 1)]
        best = vals[i]
        for _ in range(60):
            m1, m2 = a + (b - a) * 0.382, a + (b - a) * 0.618
            if g(m1) < g(m2):
                a = m1
            else:
                b = m2
            best = max(best, g(m1), g(m2))
        return float(best)


def numbers(msg):
    return [float(v) for v in re.findall(r"stated (\S+) but .* is (\S+?)(?:;|$)", msg)[0]]


# -- 1. reading: field-level messages -----------------------------------------

def _set(d, path, value):
    *head, last = path
    for key in head:
        d = d[key]
    if value is _DELETE:
        del d[last]
    else:
        d[last] = value


_DELETE = object()

FIELD_CASES = [
    # (path in the JSON object, new value, regex the message must match)
    (("coefficients", 2), "abc", r"^coefficients\[2\]: expected a finite number, got 'abc'$"),
    (("coefficients", 0), None, r"^coefficients\[0\]: expected a finite number, got null$"),
    (("coefficients", 1), True, r"^coefficients\[1\]: expected a finite number, got true$"),
    (("coefficients", 1), 10 ** 400, r"^coefficients\[1\]: expected a finite number"),
    (("coefficients",), "0.5", r"^coefficients: expected an array of numbers, got '0.5'$"),
    (("coefficients",), [0.5, 0.1], r"^coefficients: 2 numbers for degree 2; expected "
                                    r"degree \+ 1 = 3$"),
    (("degree",), 3, r"^coefficients: 3 numbers for degree 3"),
    (("degree",), 2.0, r"^degree: expected an integer in 0\.\.30, got 2\.0$"),
    (("degree",), True, r"^degree: expected an integer in 0\.\.30, got true$"),
    (("degree",), 31, r"^degree: expected an integer in 0\.\.30, got 31$"),
    (("degree",), _DELETE, r"^degree: missing"),
    (("name",), _DELETE, r"^name: missing"),
    (("surprise",), 1, r"^surprise: unknown field; accepted: abs_error_bound, "),
    (("schema_version",), 2, r"^schema_version: schema version 2 is not supported; accepted: 1$"),
    (("schema_version",), True, r"^schema_version: schema version true is not supported"),
    (("schema_version",), "1", r"^schema_version: schema version '1' is not supported"),
    (("interval",), ["2", "sqrt(2)"], r"^interval: \[2, sqrt\(2\)\] is empty or reversed; "
                                      r"accepted: interval\[0\] < interval\[1\]$"),
    (("interval",), ["2", "2"], r"^interval: \[2, 2\] is empty or reversed"),
    (("interval",), ["sqrt(2)"], r"^interval: expected an array of 2 strings"),
    (("interval", 0), 1.5, r"^interval\[0\]: expected a string, got 1\.5$"),
    (("interval", 1), "", r"^interval\[1\]: expected a non-empty string, got ''$"),
    (("interval", 1), "2" + " " * 1000, r"^interval\[1\]: 1001 characters; accepted: at most 1000$"),
    (("interval_float", 0), 1.4, r"^interval_float\[0\]: 1\.4 is not interval\[0\] = sqrt\(2\) "
                                 r"rounded to a double; accepted: 1\.4142135623730951$"),
    (("interval_float", 1), float("inf"), r"^interval_float\[1\]: expected a finite number, got inf$"),
    (("interval_float",), [1.5], r"^interval_float: expected an array of 2 numbers"),
    (("expression",), "z" * 1001, r"^expression: 1001 characters; accepted: at most 1000$"),
    (("expression",), 7, r"^expression: expected a string, got 7$"),
    (("expression",), "1/sqrt(z + 2) + y", r"^expression: .*unknown variable"),
    (("name",), "dichotomy d2", r"^name: 'dichotomy d2' is not an identifier: expected "
                                r"\[A-Za-z_\]\[A-Za-z0-9_\]\*, at most 63 characters$"),
    (("name",), "a" * 64, r"^name: 'a+' is not an identifier"),
    (("variable",), "z\n", r"^variable: 'z\\n' is not an identifier"),
    (("kind",), "remez", r"^kind: expected one of 'chebyshev', 'minimax', got 'remez'$"),
    (("error_kind",), "max", r"^error_kind: expected one of 'abs', 'rel', got 'max'$"),
    (("abs_error_bound",), -1, r"^abs_error_bound: expected a finite number >= 0, got -1$"),
    (("abs_error_bound",), float("nan"), r"^abs_error_bound: expected a finite number >= 0, "
                                         r"got nan$"),
    (("abs_error_bound",), float("inf"), r"^abs_error_bound: expected a finite number >= 0"),
    (("abs_error_bound",), "1e-3", r"^abs_error_bound: expected a finite number >= 0, "
                                   r"got '1e-3'$"),
    (("abs_error_bound",), None, r"^abs_error_bound: expected a finite number >= 0, got null$"),
    (("rel_error_bound",), -0.5, r"^rel_error_bound: expected a finite number >= 0 or null"),
    (("rel_error_bound",), None, r"^max_rel_error, max_rel_at: must be null exactly when "
                                 r"rel_error_bound is null$"),
    (("max_abs_error",), float("nan"), r"^max_abs_error: expected a finite number >= 0"),
    (("max_abs_error",), 1.0, r"^max_abs_error: the located maximum 1\.00e\+00 exceeds "
                              r"abs_error_bound = 2\.16e-05$"),
    (("max_abs_at",), 3.0, r"^max_abs_at: z = 3\.0 lies outside the interval \[sqrt\(2\), 2\]$"),
    (("max_rel_at",), 1.0, r"^max_rel_at: z = 1\.0 lies outside the interval"),
    (("provenance",), [], r"^provenance: expected an object of strings, got an array of 0$"),
    (("provenance", "command"), 5, r"^provenance\.command: expected a string, got 5$"),
    (("provenance", "command"), "x" * 1001, r"^provenance\.command: 1001 characters"),
    (("provenance", "k" * 65), "v", r"^provenance key 'k+': 65 characters; accepted: at most 64$"),
    (("fixed_point",), 3, r"^fixed_point: expected a JSON object, got 3$"),
    (("fixed_point", "integers", 1), 1.5, r"^fixed_point\.integers\[1\]: expected an integer, "
                                          r"got 1\.5$"),
    (("fixed_point", "integers", 1), "7", r"^fixed_point\.integers\[1\]: expected an integer, "
                                          r"got '7'$"),
    (("fixed_point", "integers", 1), 2 ** 40, r"^fixed_point\.word_bits: 32 bits cannot hold "
                                              r"fixed_point\.integers\[1\] = 1099511627776 "
                                              r"\(two's complement\); accepted: word_bits >= 42$"),
    (("fixed_point", "integers"), [1, 2], r"^fixed_point\.integers: 2 integers for degree 2; "
                                          r"expected degree \+ 1 = 3$"),
    (("fixed_point", "word_bits"), 16, r"^fixed_point\.word_bits: 16 bits cannot hold "
                                       rf"fixed_point\.integers\[0\] = {_INT0} \(two's "
                                       rf"complement\); accepted: word_bits >= {_INT0.bit_length() + 1}$"),
    (("fixed_point", "word_bits"), 64, r"^fixed_point\.word_bits: expected an integer in 2\.\.53, "
                                       r"got 64$"),
    (("fixed_point", "frac_bits"), -1, r"^fixed_point\.frac_bits: expected an integer in "
                                       r"0\.\.1074, got -1$"),
    (("fixed_point", "frac_bits"), 24.0, r"^fixed_point\.frac_bits: expected an integer"),
    (("fixed_point", "method"), "magic", r"^fixed_point\.method: expected one of 'rounded', "
                                         r"'reoptimized', 'lattice', got 'magic'$"),
    (("fixed_point", "abs_error_bound"), -1, r"^fixed_point\.abs_error_bound: expected a "
                                             r"finite number >= 0, got -1$"),
    (("fixed_point", "max_rel_error"), None, r"^fixed_point\.max_rel_error: must be null exactly "
                                             r"when fixed_point\.rel_error_bound is null$"),
    (("fixed_point", "extra"), 0, r"^fixed_point\.extra: unknown field"),
    (("fixed_point", "method"), _DELETE, r"^fixed_point\.method: missing"),
]


@pytest.mark.parametrize("path,value,match", FIELD_CASES,
                         ids=[f"{'.'.join(map(str, p))}={str(v)[:12]!r}" for p, v, _ in FIELD_CASES])
def test_field_level_messages(path, value, match):
    d = base()
    _set(d, path, value)
    with pytest.raises(ValueError) as exc:
        CoefficientTable.from_dict(d)
    assert re.search(match, str(exc.value)), str(exc.value)


@pytest.mark.parametrize("text,match", [
    ("[]", "must be a JSON object, got an array of 0"),
    ("{", "not valid JSON"),
    ("[" * 100_000 + "]" * 100_000, "not valid JSON"),  # too deep for the parser: no RecursionError
    ('{"coefficients": [' + "9" * 5000 + "]}", "not valid JSON"),  # too many digits
])
def test_malformed_json(text, match):
    with pytest.raises(ValueError, match=re.escape(match)):
        CoefficientTable.from_json(text)


def test_json_nan_literal_is_refused():
    text, n = re.subn(r'^  "abs_error_bound": [^,]+,$', '  "abs_error_bound": NaN,',
                      BASE.read_text(), flags=re.M)
    assert n == 1 and "NaN" in text
    with pytest.raises(ValueError, match=r"^abs_error_bound: expected a finite number >= 0, got nan$"):
        CoefficientTable.from_json(text)


def test_load_names_the_file_and_limits_its_size(tmp_path):
    p = tmp_path / "t.json"
    d = base()
    d["degree"] = "2"
    p.write_text(json.dumps(d))
    with pytest.raises(ValueError, match=r"^coefficient table '.*t\.json': degree: expected an "
                                         r"integer in 0\.\.30, got '2'$"):
        CoefficientTable.load(p)
    p.write_bytes(b" " * (2 ** 20 + 1))
    with pytest.raises(ValueError, match=r"is larger than 1048576 bytes"):
        CoefficientTable.load(p)
    p.write_bytes(b'{"name": "\xff"}')
    with pytest.raises(ValueError, match=r"is not UTF-8 text"):
        CoefficientTable.load(p)


# -- 2. reading: the stated bounds must be proved -------------------------------

def test_untouched_committed_tables_load_unchanged():
    assert TABLES, "no committed tables under figures/coefficients"
    for path in TABLES:
        t = CoefficientTable.load(path)
        assert t.to_json() == path.read_text(), path.name
        assert t.verify() == t


def test_a_changed_coefficient_is_refused():
    """The issue's example: one coefficient + 1e-3 makes the stated bound false."""
    d = base()
    d["coefficients"][1] += 1e-3
    truth = true_sup(d["coefficients"])
    assert truth > d["abs_error_bound"]  # the tamper really breaks the claim
    with pytest.raises(ValueError) as exc:
        CoefficientTable.from_dict(d)
    msg = str(exc.value)
    assert msg.startswith("abs_error_bound: stated 2.16e-05 but the coefficients' certified error is ")
    stated, certified = numbers(msg)
    # printed with at least 3 significant digits: within half a unit of the third
    assert stated < truth and certified >= truth * (1 - 0.005)
    assert "|p - f| reaches" in msg


@pytest.mark.parametrize("factor", [0.5, 1 - 2 ** -30])
@pytest.mark.parametrize("field,kind", [("abs_error_bound", "abs"), ("rel_error_bound", "rel")])
def test_a_bound_below_the_true_error_is_refused(field, kind, factor):
    d = base()
    truth = true_sup(d["coefficients"], kind)
    d[field] = truth * factor
    d[f"max_{kind}_error"] = min(d[f"max_{kind}_error"], d[field])  # only the bound is wrong
    with pytest.raises(ValueError, match=rf"^{field}: stated \S+ but the coefficients' certified "
                                         rf"{'relative ' if kind == 'rel' else ''}error is "):
        CoefficientTable.from_dict(d)


@pytest.mark.parametrize("field,kind", [("abs_error_bound", "abs"), ("rel_error_bound", "rel")])
def test_a_looser_true_bound_is_accepted(field, kind):
    """Stated bounds above the true sup pass, even between the sup and the
    first certification's bound (shown by re-certifying more tightly)."""
    d = base()
    truth = true_sup(d["coefficients"], kind)
    for stated in (d[field] * 2, d[field], (truth + d[field]) / 2, truth * (1 + 2 ** -30)):
        assert stated >= truth
        d[field] = stated
        assert getattr(CoefficientTable.from_dict(d), field) == stated


def test_tampered_fixed_point_is_refused():
    d = base()
    fp = d["fixed_point"]
    scale = 2.0 ** -fp["frac_bits"]
    fp["integers"][0] += 2 ** 12  # + 2.4e-4 on the constant term
    truth = true_sup([q * scale for q in fp["integers"]])
    assert truth > fp["abs_error_bound"]
    with pytest.raises(ValueError, match=rf"^fixed_point\.abs_error_bound: stated {_FP_BOUND} but "
                                         r"the fixed-point coefficients' certified error is "
                                         r"(\S+)") as exc:
        CoefficientTable.from_dict(d)
    # the printed certified error (3 significant digits) is the true supremum's
    printed = float(re.search(r"certified error is ([0-9.e+-]+\d)", str(exc.value)).group(1))
    assert abs(printed - truth) <= 5e-3 * truth
    d = base()
    d["fixed_point"]["rel_error_bound"] = d["fixed_point"]["max_rel_error"] = 1e-6
    with pytest.raises(ValueError, match=r"^fixed_point\.rel_error_bound: stated 1\.00e-06 but "):
        CoefficientTable.from_dict(d)


def test_vanishing_function_has_no_relative_bound():
    t = fit("x**3", ("0", "1"), 2)  # f vanishes at 0: no relative bound
    assert t.rel_error_bound is None and t.max_rel_error is None and t.max_rel_at is None
    assert CoefficientTable.from_json(t.to_json()) == t
    d = json.loads(t.to_json())
    d["rel_error_bound"] = d["max_rel_error"] = d["max_rel_at"] = 0.0
    with pytest.raises(ValueError, match=r"^rel_error_bound: the coefficients' certified relative "
                                         r"error cannot be certified: p/f - 1 .*not finite"):
        CoefficientTable.from_dict(d)


def test_python_tables_can_be_verified():
    t = CoefficientTable.load(BASE)
    with pytest.raises(ValueError, match=r"^abs_error_bound: stated"):
        replace(t, coefficients=(t.coefficients[0] + 1e-3, *t.coefficients[1:])).verify()


# -- 3. tampered tables through every command that reads one ------------------

TAMPERS = {
    "coefficient+1e-3": (lambda d: d["coefficients"].__setitem__(1, d["coefficients"][1] + 1e-3),
                         r"abs_error_bound: stated 2\.16e-05 but the coefficients' certified error"),
    "bound=-1": (lambda d: d.__setitem__("abs_error_bound", -1),
                 r"abs_error_bound: expected a finite number >= 0, got -1"),
    "bound=NaN": (lambda d: d.__setitem__("abs_error_bound", float("nan")),
                  r"abs_error_bound: expected a finite number >= 0, got nan"),
    "bound too small": (lambda d: (d.__setitem__("abs_error_bound", 1.5e-5),
                                   d.__setitem__("max_abs_error", 1.5e-5)),
                        r"abs_error_bound: stated 1\.50e-05 but the coefficients' certified error"),
    "integer changed": (lambda d: d["fixed_point"]["integers"].__setitem__(
                            0, d["fixed_point"]["integers"][0] + 4096),
                        rf"fixed_point\.abs_error_bound: stated {_FP_BOUND} but the fixed-point "
                        r"coefficients' certified error"),
}

COMMANDS = {
    "export": lambda t, o: ["export", t, "--format", "c", "-o", o / "t.h"],
    "hw verilog": lambda t, o: ["hw", "verilog", t, "--in-bits", "8", "--out-bits", "8", "-o", o],
    "hw report": lambda t, o: ["hw", "report", t, "--in-bits", "8", "--out-bits", "8",
                               "--no-synth", "--no-gappa"],
    "hw unit --table": lambda t, o: ["hw", "unit", "dichotomy", "--table", t, "--in-bits", "8",
                                     "--out-bits", "8", "--vector-frac-bits", "6", "--vectors", "50",
                                     "-o", o],
}


@pytest.mark.parametrize("tamper", sorted(TAMPERS))
@pytest.mark.parametrize("command", sorted(COMMANDS))
def test_tampered_tables_are_refused_by_every_command(tmp_path, capsys, command, tamper):
    change, match = TAMPERS[tamper]
    d = base()
    change(d)
    table = tmp_path / "t.json"
    table.write_text(json.dumps(d, allow_nan=True))
    out = tmp_path / "out"
    out.mkdir()
    code, stdout, err = astuple(run_cli(COMMANDS[command](table, out)))
    assert code == 2, (stdout, err)
    assert err.count("\n") == 1 and err.startswith("chebnorm: error: coefficient table "), err
    assert re.search(rf"t\.json': {match}", err), err
    assert list(out.iterdir()) == [] and stdout == ""


@pytest.mark.parametrize("command", sorted(COMMANDS))
def test_untampered_table_passes_every_command(tmp_path, capsys, command):
    out = tmp_path / "out"
    out.mkdir()
    code, _, err = astuple(run_cli(COMMANDS[command](BASE, out)))
    assert code == 0, err


def test_refusal_from_a_spawned_cli_is_one_line(tmp_path):
    d = base()
    d["coefficients"][1] += 1e-3
    table = tmp_path / "t.json"
    table.write_text(json.dumps(d))
    # a child process, as the name says: what a shell user sees on stderr, Python
    # warnings and tracebacks included, is the point
    proc = run_process("export", table, "-o", tmp_path / "t.h")
    assert proc.returncode == 2 and proc.stdout == ""
    assert proc.stderr.count("\n") == 1 and "Traceback" not in proc.stderr
    assert "abs_error_bound: stated 2.16e-05 but the coefficients' certified error is" in proc.stderr
    assert not (tmp_path / "t.h").exists()


# -- 4. byte-identical exports of untouched tables -------------------------------

@pytest.mark.parametrize("path", TABLES, ids=[p.stem for p in TABLES])
def test_committed_tables_export_byte_identically(tmp_path, capsys, path):
    """The committed headers and their Gappa proofs were written by ``chebnorm
    repro coefficients`` (``export_with_proofs``); loading (now verified) and
    exporting reproduces them: through the library with the same command, and
    through ``chebnorm export --proof`` up to the one line that records its own
    command."""
    from chebnorm.export import export_with_proofs

    t = CoefficientTable.load(path)
    stem = f"chebnorm_{t.name}"
    committed = (COEFFS / f"{stem}.h").read_text()
    (tmp_path / "lib").mkdir()
    lib = export_with_proofs(t, "c", tmp_path / "lib" / f"{stem}.h", "chebnorm repro coefficients")
    assert lib[f"{stem}.h"] == committed
    assert len(lib) > 1   # the header and at least one proof
    for fname, text in lib.items():
        assert (COEFFS / fname).read_text() == text, fname
    out = tmp_path / "cli" / f"{stem}.h"
    out.parent.mkdir()
    code, _, err = astuple(run_cli(["export", path, "--format", "c", "--proof", "-o", out]))
    assert code == 0, err
    written = out.read_text()
    assert f" * Command: chebnorm export {path} --format c --proof -o {out}\n" in written
    assert re.sub(r"(?m)^ \* Command: .*$", "", written) == \
        re.sub(r"(?m)^ \* Command: .*$", "", committed)
    assert sorted(p.name for p in out.parent.iterdir()) == sorted(lib)
    code, _, err = astuple(run_cli(["export", path, "--format", "json", "-o", tmp_path / "x.json"]))
    assert code == 0 and (tmp_path / "x.json").read_text() == path.read_text()


# -- 5. injection through every text field ----------------------------------------

HOSTILE = [
    "1/sqrt(x) */ int injected = 1; /*",
    "*/ int injected = 1; /*",
    "x\nint injected = 1;",
    "x\r\nint injected = 1;",
    "x */\n#define injected 1\n/*",
    "a b",
    "evil\\",
    "evil \\\nint injected = 1;",
    "x ??/",
    "*??/\n/ int injected = 1;",
    "x\u2028int injected = 1;",
    "x\u2029int injected = 1;",
    "x\x85int injected = 1;",
    "`define injected 1",
    "x\n`define injected 1\nmodule injected; endmodule",
    "\"); $finish; //",
    "\x00",
    "\u00e9t\u00e9",
    "//",
    "/*",
    "x" * 5000,
]

# (field path, a valid value it can be appended to, the field as the message names it)
TEXT_FIELDS = [
    (("name",), "dichotomy_d2", "name"),
    (("expression",), "1/sqrt(z + 2)", "expression"),
    (("variable",), "z", "variable"),
    (("interval", 0), "sqrt(2)", "interval[0]"),
    (("interval", 1), "2", "interval[1]"),
    (("kind",), "chebyshev", "kind"),
    (("error_kind",), "abs", "error_kind"),
    (("fixed_point", "method"), "lattice", "fixed_point.method"),
    (("provenance", "command"), "chebnorm repro coefficients", "provenance.command"),
    (("provenance", "numpy"), "2.4.6", "provenance.numpy"),
]


def strip_c_comments(path: Path) -> str:
    """The header as gcc sees it with comments removed (trigraphs, line splices
    and all), directives kept: the code, and nothing but the code."""
    proc = subprocess.run(["gcc", "-std=c99", "-trigraphs", "-fpreprocessed", "-dD", "-E", "-P",
                           "-x", "c", str(path)], capture_output=True, text=True, check=True)
    return "\n".join(line.rstrip() for line in proc.stdout.splitlines() if line.strip())


def compile_c(tmp: Path, header: Path) -> None:
    main_c = tmp / "main.c"
    main_c.write_text(f'#include "{header.name}"\nint main(void) {{ return 0; }}\n')
    proc = subprocess.run(["gcc", *CFLAGS, "-c", "-o", str(tmp / "main.o"), str(main_c)],
                          cwd=header.parent, capture_output=True, text=True)
    assert proc.returncode == 0 and proc.stderr == "", proc.stderr


def strip_verilog_comments(text: str) -> str:
    """Verilog text without its comments (``//`` to end of line, ``/* */``),
    strings kept; a backquote or a line break inside a comment is dropped with
    the comment, which is what the Verilog preprocessor does."""
    out, i, n = [], 0, len(text)
    while i < n:
        if text.startswith("//", i):
            j = text.find("\n", i)
            i = n if j < 0 else j
        elif text.startswith("/*", i):
            j = text.find("*/", i + 2)
            assert j >= 0, "unterminated block comment"
            i = j + 2
        elif text[i] == '"':
            j = i + 1
            while text[j] != '"':
                j += 2 if text[j] == "\\" else 1
            out.append(text[i:j + 1])
            i = j + 1
        else:
            out.append(text[i])
            i += 1
    return "\n".join(line.rstrip() for line in "".join(out).splitlines() if line.strip())


@pytest.fixture(scope="module")
def clean(tmp_path_factory):
    """Code of the clean table's header and Verilog (comments removed)."""
    tmp = tmp_path_factory.mktemp("clean")
    assert main(["export", str(BASE), "-o", str(tmp / "chebnorm_dichotomy_d2.h")]) == 0
    assert main(["hw", "verilog", str(BASE), "--in-bits", "8", "--out-bits", "8",
                 "-o", str(tmp)]) == 0
    have_gcc = tool_missing("gcc") is None
    c = strip_c_comments(tmp / "chebnorm_dichotomy_d2.h") if have_gcc else None
    v = strip_verilog_comments((tmp / "chebnorm_dichotomy_d2.v").read_text())
    tb = strip_verilog_comments((tmp / "tb_chebnorm_dichotomy_d2.v").read_text())
    return c, v, tb


def _check_outcome(code, err, field, produced):
    if code == 2:
        assert err.count("\n") == 1, err
        named = err.split(".json': ", 1)[-1]
        top = re.split(r"[.\[]", field)[0]
        assert named.startswith(top), err
        assert not produced, produced
        return False
    assert code == 0, err
    return True


@requires_tool("gcc", "iverilog")  # one marker: the hook reads the closest only
@pytest.mark.parametrize("path,valid,field", TEXT_FIELDS, ids=[f[2] for f in TEXT_FIELDS])
def test_injection_in_every_text_field(tmp_path, capsys, clean, path, valid, field):
    c_ref, v_ref, tb_ref = clean
    accepted = 0
    for k, hostile in enumerate(HOSTILE):
        for value in (hostile, valid + hostile):
            case = tmp_path / f"case{k}_{len(value) > len(hostile)}"
            case.mkdir()
            d = base()
            _set(d, path, value)
            table = case / "t.json"
            table.write_text(json.dumps(d))
            header = case / "chebnorm_dichotomy_d2.h"
            code, _, err = astuple(run_cli(["export", table, "-o", header]))
            if _check_outcome(code, err, field, header.exists()):
                accepted += 1
                compile_c(case, header)
                assert strip_c_comments(header) == c_ref
            vdir = case / "v"
            vdir.mkdir()
            code, _, err = astuple(run_cli(["hw", "verilog", table, "--in-bits", "8",
                                            "--out-bits", "8", "-o", vdir, "--simulate"]))
            if _check_outcome(code, err, field, list(vdir.iterdir())):
                assert strip_verilog_comments((vdir / "chebnorm_dichotomy_d2.v").read_text()) == v_ref
                assert strip_verilog_comments(
                    (vdir / "tb_chebnorm_dichotomy_d2.v").read_text()) == tb_ref
    if field.startswith("provenance"):  # free text: accepted up to its length limit, inert
        assert accepted == sum(len(v) <= MAX_TEXT for h in HOSTILE for v in (h, valid + h))


def _hostile_table():
    """A table whose every text field is hostile, built past the constructor's
    checks (which refuse it): the printers alone must keep it inert."""
    t = CoefficientTable.load(BASE)
    bad = "1/sqrt(x) */ int injected = 1; /* \\\n??/\u2028`define injected 1\n\");"
    with construction("unchecked"):
        return replace(t, expression=bad, variable=bad, interval=(bad, bad), kind=bad,
                       error_kind=bad, fixed_point=replace(t.fixed_point, method=bad),
                       provenance={"command": bad}), bad


@needs_gcc
def test_printer_alone_keeps_hostile_text_inert(tmp_path, clean):
    t, bad = _hostile_table()
    header = tmp_path / "chebnorm_dichotomy_d2.h"
    header.write_text(c_header(t, command=bad))
    compile_c(tmp_path, header)
    assert strip_c_comments(header) == clean[0]
    assert "injected" in header.read_text()  # the text is there, inert in the comments
    with pytest.raises(ValueError, match=r"^name: 'a\*/b' is not an identifier"):
        with construction("unchecked"):
            t_bad = replace(t, name="a*/b")
        c_header(t_bad)
    with pytest.raises(ValueError, match=r"^fixed_point\.integers\[0\]: 4294967296 does not fit "
                                         r"the header's int32_t"):
        with construction("unchecked"):
            t_bad = replace(t, fixed_point=replace(t.fixed_point, integers=(2 ** 32, 0, 0)))
        c_header(t_bad)


@needs_iverilog
def test_verilog_printer_alone_keeps_hostile_text_inert(tmp_path, clean):
    from chebnorm.hw.horner import design_horner
    from chebnorm.hw.hdl.verilog import (
        verilog_module,
        verilog_pipelined_module,
        verilog_testbench,
    )

    from chebnorm.hw.trust import drafting

    t, bad = _hostile_table()
    d = design_horner(CoefficientTable.load(BASE), 8, 8)
    with pytest.raises(ValueError):   # a design refuses the hostile table
        replace(d, table=t)
    with drafting():   # the printers alone, on a design left unchecked
        hostile = replace(d, table=t)
        text = verilog_module(hostile, version=bad, command=bad)
        pipe = verilog_pipelined_module(hostile, version=bad, command=bad)
    assert strip_verilog_comments(text) == clean[1]
    (tmp_path / "m.v").write_text(text + "\n" + pipe)
    proc = subprocess.run(["iverilog", "-g2005", "-Wall", "-o", str(tmp_path / "a.out"),
                           str(tmp_path / "m.v")], capture_output=True, text=True)
    assert proc.returncode == 0 and proc.stderr == "", proc.stderr
    with pytest.raises(ValueError, match=r"^name: 'x\\n`define' is not an identifier"):
        verilog_module(replace(d, name="x\n`define"))
    with pytest.raises(ValueError, match=r"^vectors \(without \.hex\): "):
        verilog_testbench(d, vectors='a.hex"); $finish; //.hex')


@requires_tool("gcc", "iverilog")  # one marker: the hook reads the closest only
def test_hostile_command_line_is_inert(tmp_path, capsys, clean):
    """The command line (here the table's own file name) reaches the banners."""
    # the full path holds "*/", line breaks, a trigraph, U+2028 and a backslash
    folder = tmp_path / "x *" / "\nint injected = 1;\n`define injected 1\n??"
    folder.mkdir(parents=True)
    table = folder / "* \u2028 \\.json"
    table.write_text(BASE.read_text())
    header = tmp_path / "chebnorm_dichotomy_d2.h"
    code, _, err = astuple(run_cli(["export", table, "-o", header]))
    assert code == 0, err
    compile_c(tmp_path, header)
    assert strip_c_comments(header) == clean[0]
    vdir = tmp_path / "v"
    code, _, err = astuple(run_cli(["hw", "verilog", table, "--in-bits", "8", "--out-bits", "8",
                                    "-o", vdir, "--simulate"]))
    assert code == 0, err
    assert strip_verilog_comments((vdir / "chebnorm_dichotomy_d2.v").read_text()) == clean[1]



@needs_iverilog
def test_unit_banner_keeps_hostile_command_line_inert(tmp_path, capsys):
    def unit_code(table, out):
        code, _, err = astuple(run_cli(["hw", "unit", "dichotomy", "--table", table,
                                        "--in-bits", "8", "--out-bits", "8",
                                        "--vector-frac-bits", "6", "--vectors", "50", "-o", out]))
        assert code == 0, err
        return strip_verilog_comments((out / "chebnorm_dichotomy_unit.v").read_text())

    folder = tmp_path / "x *" / "\n`define injected 1\nmodule injected; endmodule\n"
    folder.mkdir(parents=True)
    table = folder / "t.json"
    table.write_text(BASE.read_text())
    assert unit_code(table, tmp_path / "hostile") == unit_code(BASE, tmp_path / "clean")
