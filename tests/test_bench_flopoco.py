"""benchmarks/bench_flopoco.py's pure parts: the spec table (chebnorm's and
FloPoCo's expressions are the same function as the mpmath reference), the
error count, the banner parser, the build fixes and the JSON -> Markdown table.
No FloPoCo, no yosys."""

from __future__ import annotations

import sys
from fractions import Fraction
from pathlib import Path

import mpmath
import pytest
import sympy

BENCH = Path(__file__).resolve().parents[1] / "benchmarks"
sys.path.insert(0, str(BENCH))
import bench_flopoco as bf  # noqa: E402


@pytest.mark.parametrize("spec", bf.SPECS, ids=lambda s: s.name)
def test_spec_expressions_agree_with_the_reference(spec):
    """chebnorm's sympy EXPR of x on [lo, hi), FloPoCo's Sollya f of t on [0, 1)
    (x = lo + (hi - lo) t) and the mpmath reference agree to 1e-25 at 7 points."""
    x, t = sympy.symbols("x t")
    ours = sympy.sympify(spec.expr, locals={"x": x})
    flo = sympy.sympify(spec.flopoco_f.replace("^", "**"),
                        locals={"x": t, "log2": lambda a: sympy.log(a, 2)})
    ctx = mpmath.MPContext()
    ctx.prec = 100
    for num in (0, 1, 3, 7, 10, 13, 15):
        tv = sympy.Rational(num, 16)
        xv = spec.lo + (spec.hi - spec.lo) * tv
        ref = bf.REFERENCES[spec.mp](ctx, ctx.mpf(xv.p) / xv.q)
        assert abs(sympy.N(ours.subs(x, xv), 40) - sympy.Float(str(ref), 40)) < 1e-25
        assert abs(sympy.N(flo.subs(t, tv), 40) - sympy.Float(str(ref), 40)) < 1e-25


@pytest.mark.parametrize("spec", bf.SPECS, ids=lambda s: s.name)
def test_spec_output_fits_its_width(spec):
    """chebnorm's --out-bits can hold the spec's LSB over f's range: f over the
    codes (with an offset, as chebnorm's banner allows) leaves a faithful output
    code in range at both ends: floor(f max) - ceil(f min) < 2^out_bits in units
    of the LSB (log2(1+x) at 2^-16 reaches 65535.28: 65535 is faithful)."""
    ctx = mpmath.MPContext()
    ctx.prec = 60
    fn = bf.REFERENCES[spec.mp]
    last = ctx.mpf(spec.hi) - ctx.mpf(spec.hi - spec.lo) / 2 ** spec.in_bits
    ends = sorted([fn(ctx, ctx.mpf(spec.lo)), fn(ctx, last)])   # every f here is monotone
    units = [e / ctx.mpf(2) ** spec.lsb_out for e in ends]
    assert ctx.floor(units[1]) - ctx.ceil(units[0]) < 2 ** spec.out_bits
    assert 12 <= spec.in_bits <= 20


def test_count_errors_counts_codes_off_by_one_ulp():
    """The correctly rounded 2^x on 4 bits has 0 errors; moving one code by one
    LSB below its lower faithful neighbour makes an error of >= 1 ulp there only."""
    spec = bf.Spec("t", "2**x", 0, 1, 4, -6, 8, "2^x", "exp2")
    codes = [int(mpmath.nint(mpmath.power(2, mpmath.mpf(k) / 16) * 64)) for k in range(16)]
    ok = bf.count_errors(spec, codes, lambda c: Fraction(c, 64))
    assert ok["errors"] == 0 and ok["codes"] == 16 and ok["max_err_ulp"] <= 0.5
    codes[5] = int(mpmath.floor(mpmath.power(2, mpmath.mpf(5) / 16) * 64)) - 1
    bad = bf.count_errors(spec, codes, lambda c: Fraction(c, 64))
    assert bad["errors"] == 1 and 1 < bad["max_err_ulp"] < 2
    codes[5] += 1                         # the other faithful neighbour: no error
    assert bf.count_errors(spec, codes, lambda c: Fraction(c, 64))["errors"] == 0
    codes[5] = None                       # an x/z output is an error too
    assert bf.count_errors(spec, codes, lambda c: Fraction(c, 64))["errors"] == 1


def test_parse_output_format():
    assert bf.parse_output_format(
        "// y: unsigned 16-bit code k, value = (32768 + k) / 2^15\n") == (32768, 15)
    assert bf.parse_output_format("// y: unsigned 16-bit code k, value = k / 2^16\n") == (0, 16)
    assert bf.parse_output_format("module m; endmodule") is None


def test_patch_tree_stubs_and_guards_once(tmp_path):
    cm = tmp_path / "src" / "ConstMult"
    cm.mkdir(parents=True)
    (cm / "tscm_solutions.hpp").write_text("extern int nofs[2097152][2];\n")
    (cm / "IntConstMultShiftAddOptTernary.cpp").write_text(
        '#include "tscm_solutions.hpp"\n#include "pagsuite/a.hpp"\n\n'
        '#include "pagsuite/b.h"\n#include <algorithm>\n')
    done = bf._patch_tree(tmp_path)
    assert len(done) == 2
    text = (cm / "IntConstMultShiftAddOptTernary.cpp").read_text()
    assert text.index("#if defined(HAVE_PAGLIB)") < text.index("pagsuite/a.hpp") < \
        text.index("pagsuite/b.h") < text.index("#endif") < text.index("<algorithm>")
    assert "int nofs[2097152][2]" in (cm / "tscm_solutions.cpp").read_text()
    assert bf._patch_tree(tmp_path) == []          # a second pass changes nothing


def test_flopoco_argv():
    spec = bf.SPEC_BY_NAME["recip"]
    argv = bf.flopoco_argv(spec, "pp2", "n")
    assert argv[:4] == ["frequency=1", "plainVHDL=1", "name=n", "outputFile=n.vhdl"]
    assert argv[4:] == ["FixFunctionByPiecewisePoly", "f=1/(1+x)", "lsbIn=-16", "lsbOut=-16",
                        "d=2"]
    assert bf.flopoco_argv(spec, "multipartite", "n")[4] == "FixFunctionByMultipartiteTable"
    with pytest.raises(ValueError, match="accepted"):
        bf.flopoco_argv(spec, "pp9x", "n")


def _doc():
    flo = {"pp1": {"sim": {"errors": 0}, "devices": {"generic": {"cells": 1000},
                                                     "xc7-nodsp": {"luts": 300}}},
           "pp2": {"sim": {"errors": 0}, "devices": {"generic": {"cells": 1500},
                                                     "xc7-nodsp": {"luts": 250}}},
           # the smallest, but not faithful: never the best
           "table": {"sim": {"errors": 3}, "devices": {"generic": {"cells": 10}}}}
    ch = {"generic": {"figures": {"cells": 700}, "sim": {"errors": 0}, "lsb_out": -15,
                      "lsb_match": True},
          "xc7-nodsp": {"figures": {"luts": 225}, "sim": {"errors": 0}, "lsb_out": -15,
                        "lsb_match": True}}
    return {"meta": {"flopoco_repo": "github:o/r", "flopoco_commit": "abcdef1234567890"},
            "specs": {"exp": {"spec": {"expr": "exp(x)", "interval": [0, 1], "in_bits": 16,
                                       "lsb_out": -15}, "flopoco": flo, "chebnorm": ch}}}


def test_best_flopoco_skips_unfaithful_designs():
    e = _doc()["specs"]["exp"]
    assert bf.best_flopoco(e, "generic") == (1000, "pp1")
    assert bf.best_flopoco(e, "xc7-nodsp") == (250, "pp2")
    assert bf.best_flopoco(e, "xc7") is None


def test_markdown_ratios_and_misses():
    md = bf.markdown(_doc())
    rows = [ln for ln in md.splitlines() if ln.startswith("| exp")]
    assert len(rows) == 2
    assert "| 700 |" in rows[0] and "1000 (pp1)" in rows[0] and "| 0.70 | yes | 70.00 |" in rows[0]
    assert "table: 10 but 3 codes off" in rows[0]       # shown, never the reference
    assert "codes off" not in rows[1]
    assert "225" in rows[1] and "250 (pp2)" in rows[1] and "| 0.90 | **no** | 0.90 |" in rows[1]
    assert "misses of 0.8x: exp/xc7-nodsp." in md and "abcdef123456" in md
    doc = _doc()
    doc["specs"]["exp"]["chebnorm"]["generic"]["lsb_match"] = False
    md = bf.markdown(doc)
    assert "2^-15 (mismatch)" in md and "exp/generic" in md       # a ratio at another LSB fails
    doc["specs"]["exp"]["chebnorm"]["xc7-nodsp"] = {"error": "chebnorm design: exit 2"}
    md = bf.markdown(doc)
    assert "error: chebnorm design: exit 2 |" in md and "exp/generic, exp/xc7-nodsp." in md


def test_merge_keeps_the_other_tools_rows():
    old = {"specs": {"exp": {"flopoco": {"pp1": 1}}}, "meta": {"a": 1}}
    new = {"specs": {"exp": {"chebnorm": {"generic": 2}}}, "meta": {"b": 2}}
    assert bf._merge(old, new) == {"specs": {"exp": {"flopoco": {"pp1": 1},
                                                     "chebnorm": {"generic": 2}}},
                                   "meta": {"a": 1, "b": 2}}


def test_markdown_cli_without_json_exits_2(tmp_path, capsys):
    assert bf.main(["--markdown", "--json", str(tmp_path / "none.json")]) == 2
    assert "no such file" in capsys.readouterr().err


def test_rom_arrays_keeps_every_entry():
    vhdl = ('architecture arch of T is\nsignal Y0 : std_logic_vector(2 downto 0);\nbegin\n'
            '   with X  select  Y0 <= \n      "101" when "00",\n      "011" when "01",\n'
            '      "110" when "11",\n      "---" when others;\nY <= Y0;\nend architecture;\n')
    text, n = bf.rom_arrays(vhdl)
    assert n == 1
    assert 'constant rom_1 : rom_1_t := (\n  0 => "101",\n  1 => "011",\n  3 => "110",\n' \
        "  others => (others => '0'));" in text
    assert "type rom_1_t is array(3 downto 0) of std_logic_vector(2 downto 0);" in text
    assert text.index("constant rom_1") < text.index("\nbegin") < \
        text.index("Y0 <= rom_1(conv_integer(X));") < text.index("Y <= Y0;")
    assert "select" not in text
    assert bf.rom_arrays("architecture a of b is\nbegin\nend;\n") == \
        ("architecture a of b is\nbegin\nend;\n", 0)


def test_narrow_products_only_for_extended_operands():
    v = ("  assign n1 = {{10{a[7]}}, a}; // sext\n  assign n2 = {b[9], b}; // sext\n"
         "  assign n3 = n1 * n2; // smul\n  assign n4 = {8'b00000000, c}; // uext\n"
         "  assign n5 = n4 * n2; // smul\n  assign n6 = n4 * n4; // umul\n")
    out, n = bf.narrow_products(v)
    assert n == 2
    assert "assign n3 = $signed(a) * $signed(b); // smul" in out
    assert "assign n5 = n4 * n2; // smul" in out          # mixed extension: left alone
    assert "assign n6 = c * c; // umul" in out


def test_docs_table_is_the_committed_json():
    """docs/flopoco.md shows exactly the table of benchmarks/flopoco_results.json."""
    import json

    doc = json.loads(bf.DEFAULT_JSON.read_text(encoding="utf-8"))
    page = bf.DOCS.read_text(encoding="utf-8")
    assert bf.docs_table(page) == bf.markdown(doc) + "\n"


def test_save_writes_only_its_tools_rows(tmp_path):
    """A run of one tool started from an older copy of the file never undoes
    the rows the other tool's run wrote since."""
    import json

    path = tmp_path / "r.json"
    bf._save(path, {"specs": {"exp": {"spec": {}, "flopoco": {"pp1": {"v": 1}}}}})
    stale = json.loads(path.read_text())                       # the chebnorm run's copy
    bf._save(path, {"specs": {"exp": {"spec": {}, "flopoco": {"pp1": {"v": 2}}}}}, "flopoco")
    stale["specs"]["exp"]["chebnorm"] = {"generic": {"w": 3}}
    bf._save(path, stale, "chebnorm")
    got = json.loads(path.read_text())["specs"]["exp"]
    assert got["flopoco"]["pp1"] == {"v": 2} and got["chebnorm"]["generic"] == {"w": 3}
