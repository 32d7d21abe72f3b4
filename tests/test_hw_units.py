"""Tests of chebnorm.hw.units: the normalization units' netlists, printed in
Verilog and VHDL, bit-for-bit against the Python kernels (iverilog, ghdl, and
the netlist evaluated in Python), yosys cell counts, kernels, errors and CLI."""

from __future__ import annotations

import json
import math
from dataclasses import astuple

import numpy as np
import pytest

from chebnorm.approx import fit_target
from chebnorm.hw import design_horner
from chebnorm.hw.datapaths import (dichotomy_next_z, eta_criterion, forward_difference,
                                   forward_difference_codes, forward_difference_setup,
                                   quadratic_midpoint)
from chebnorm.hw.report import write_outputs
from chebnorm.hw.units import (UNIT_KINDS, analyze_unit, design_unit, unit_outputs,
                               unit_vectors)
from chebnorm.core.tools import which
from chebnorm.hw.hdl.netlist import evaluate
from chebnorm.hw.run_verilog import simulate
from chebnorm.hw.run_vhdl import simulate_vhdl
from conftest import requires_tool, run_cli

no_iverilog = requires_tool("iverilog")
no_yosys = requires_tool("yosys")

#: small widths keep simulation and synthesis fast; the structure is the same
SMALL = dict(frac_bits=6, in_bits=8, out_bits=8)


def small(kind, **kw):
    args = SMALL | kw
    if kind in ("classic", "stepper"):
        args.pop("in_bits"), args.pop("out_bits")
    return design_unit(kind, **args)


@pytest.fixture(scope="module")
def d16():
    return design_horner(fit_target("dichotomy", 2), 16, 16, coef_bits=20)


class TestKernels:
    def test_next_z_is_nearest_sqrt(self, d16):
        k = np.arange(d16.valid_codes[0], d16.valid_codes[1] + 1, 7)
        zn = dichotomy_next_z(k, d16)
        fx, k0 = d16.x_format.frac_bits, d16.x_format.offset_code
        exact = np.array([math.sqrt(2 + (k0 + int(c)) / 2 ** fx) * 2 ** fx - k0 for c in k])
        assert np.all(np.abs(zn - exact) <= 0.5 + 1e-6)
        assert np.all((zn >= d16.valid_codes[0]) & (zn <= d16.valid_codes[1]))  # stays valid

    def test_stepper_codes_equal_float_forward_difference(self):
        rng = np.random.default_rng(0)
        f = 12
        G, P, Q = (rng.integers(-2 ** 13, 2 ** 13, (20, 3)) for _ in range(3))
        for log_m, guard in [(4, 8), (6, 8), (3, 0), (2, 10)]:
            m = 1 << log_m
            codes = forward_difference_codes(*forward_difference_setup(G, P, Q, log_m, guard), m)
            ref = forward_difference(G / 2 ** f, P / 2 ** f, Q / 2 ** f, m, f, guard)
            assert np.array_equal(codes, ref * 2.0 ** (f + guard))

    def test_quadratic_through_three_points(self):
        d = design_horner(fit_target("midpoint", 2), 12, 12, coef_bits=16)
        rng = np.random.default_rng(1)
        f = 12
        a = rng.normal(size=(200, 3))
        a /= np.linalg.norm(a, axis=1, keepdims=True)
        b = a + 0.3 * rng.normal(size=a.shape)
        b /= np.linalg.norm(b, axis=1, keepdims=True)
        nl, nr = np.rint(a * 2 ** f).astype(np.int64), np.rint(b * 2 ** f).astype(np.int64)
        G, P, Q, nc = quadratic_midpoint(nl, nr, d, f)
        assert np.array_equal(Q, nl) and np.array_equal(G + P + Q, nr)
        assert np.array_equal(G + 2 * P + 4 * Q, 4 * nc)  # N(1/2) = Nc exactly
        # inside the table's interval (angle <= pi/4) the midpoint is unit length within
        # the evaluator's error and the roundings; outside, the input code saturates
        inside = np.sum(a * b, axis=1) >= math.cos(math.pi / 4) + 1e-3
        assert inside.sum() > 100
        assert np.max(np.abs(np.linalg.norm(nc[inside], axis=1) / 2 ** f - 1)) < 2e-3

    def test_eta_matches_formula(self):
        d = design_horner(fit_target("eta_term", 2), 12, 16, coef_bits=20)
        rng = np.random.default_rng(2)
        f = 14
        v = rng.normal(size=(3, 300, 3))
        v /= np.linalg.norm(v, axis=2, keepdims=True)
        v[1] = v[0] + 0.4 * v[1]
        v[2] = v[0] + 0.4 * v[2]
        v /= np.linalg.norm(v, axis=2, keepdims=True)
        codes = np.rint(v * 2 ** f).astype(np.int64)
        eta = eta_criterion(*codes, d, f) / 2 ** d.y_format.frac_bits
        c = [np.sum(v[i] * v[j], axis=1) for i, j in ((0, 1), (1, 2), (0, 2))]
        ok = np.all(np.stack(c) >= 0, axis=0)  # the table covers N_i.N_j in [0, 1]
        ref = 3 - sum(np.sqrt(2 * (1 + x)) / 2 for x in c)
        # three quadratic fits (~3e-3 each) and the rounding of the dot products
        assert np.max(np.abs(eta - ref)[ok]) < 1.2e-2


class TestUnits:
    @no_iverilog
    @pytest.mark.parametrize("kind", UNIT_KINDS)
    def test_bit_for_bit(self, kind, tmp_path):
        unit = small(kind)
        write_outputs(tmp_path, unit_outputs(unit, count=300, seed=1))
        res = simulate(tmp_path, unit)
        assert res.passed and res.mismatches == 0 and res.vectors >= 300, res.line

    @requires_tool("ghdl")
    @pytest.mark.parametrize("kind", UNIT_KINDS)
    def test_vhdl_bit_for_bit(self, kind, tmp_path):
        unit = small(kind)
        write_outputs(tmp_path, unit_outputs(unit, count=300, seed=1))
        res = simulate_vhdl(tmp_path, unit)
        assert res.passed and res.mismatches == 0 and res.vectors >= 300, res.line

    @requires_tool("ghdl")
    @pytest.mark.parametrize("kind", ["classic", "stepper"])
    def test_vhdl_bench_detects_a_wrong_vector(self, kind, tmp_path):
        unit = small(kind)
        files = unit_outputs(unit, count=100)
        name = f"{unit.module_name}.hex"
        lines = files[name].splitlines(keepends=True)
        last = lines[20][-2]
        lines[20] = lines[20][:-2] + ("1" if last != "1" else "0") + "\n"
        files[name] = "".join(lines)
        write_outputs(tmp_path, files)
        res = simulate_vhdl(tmp_path, unit)
        assert not res.passed and res.mismatches == 1, res.line

    @pytest.mark.slow
    @requires_tool("ghdl")
    @pytest.mark.parametrize("rounding", ["trunc", "rne"])
    def test_classic_exhaustive_vhdl(self, rounding, tmp_path):
        unit = design_unit("classic", frac_bits=3, comp_bits=5, rounding=rounding)
        write_outputs(tmp_path, unit_outputs(unit))
        res = simulate_vhdl(tmp_path, unit)
        assert res.passed and res.vectors == 2 ** 15 and res.mismatches == 0, res.line

    @pytest.mark.parametrize("kind", ["classic", "dichotomy", "eta", "quadratic"])
    def test_netlist_evaluates_as_the_model(self, kind):
        """The unit's netlist, evaluated node by node in Python, equals the
        bit-accurate kernel on a few hundred random rows (every port's bits)."""
        unit = small(kind, rounding="rne") if kind == "classic" else small(kind)
        spec = unit.spec
        top, *others = spec.modules(unit, version="", command=None)
        rows = unit_vectors(unit, count=100, seed=5)
        n = len(rows[unit.inputs[0].name])
        pick = np.random.default_rng(5).choice(n, size=min(n, 300), replace=False)
        want = unit.evaluate({k: v[pick] for k, v in rows.items()})
        for j, i in enumerate(pick):
            ins = {p.name: int(rows[p.name][i]) & ((1 << p.bits) - 1) for p in unit.inputs}
            got = evaluate(top, inputs=ins, modules={m.name: m for m in others})
            for p in unit.outputs:
                assert got[p.name] == int(want[p.name][j]) & ((1 << p.bits) - 1), (p.name, ins)

    @no_iverilog
    @pytest.mark.parametrize("rounding", ["trunc", "rne"])
    def test_classic_exhaustive(self, rounding, tmp_path):
        unit = design_unit("classic", frac_bits=3, comp_bits=5, rounding=rounding)
        rows = unit_vectors(unit)
        assert len(rows["n_x"]) == 2 ** 15  # every input code
        write_outputs(tmp_path, unit_outputs(unit))
        res = simulate(tmp_path, unit)
        assert res.passed and res.vectors == 2 ** 15, res.line

    @no_iverilog
    def test_dichotomy_realistic_widths(self, tmp_path):
        unit = design_unit("dichotomy", frac_bits=14, in_bits=16, out_bits=16, coef_bits=20)
        write_outputs(tmp_path, unit_outputs(unit, count=1500))
        assert simulate(tmp_path, unit).passed

    @no_iverilog
    @pytest.mark.parametrize("kind", ["dichotomy", "stepper"])
    def test_bench_detects_a_wrong_vector(self, kind, tmp_path):
        unit = small(kind)
        files = unit_outputs(unit, count=100)
        name = f"{unit.module_name}.hex"
        lines = files[name].splitlines(keepends=True)
        last = lines[20][-2]  # lowest hex digit: the last output's low bits
        lines[20] = lines[20][:-2] + ("1" if last != "1" else "0") + "\n"
        files[name] = "".join(lines)
        write_outputs(tmp_path, files)
        res = simulate(tmp_path, unit)
        assert not res.passed and res.mismatches >= 1

    def test_vectors_are_seeded(self):
        u = small("eta")
        a, b = unit_outputs(u, count=50, seed=3), unit_outputs(u, count=50, seed=3)
        assert a == b
        assert unit_outputs(u, count=50, seed=4) != a

    def test_module_text(self):
        files = unit_outputs(small("classic"), count=10)
        text = files["chebnorm_classic_unit.v"]
        # printed at the generated widths: no parameters, concrete ports, one module
        assert "parameter" not in text and text.count("endmodule") == 1
        assert "    output wire [7:0] u_x," in text and "    input  wire [7:0] n_x," in text
        assert "        u_x : out std_logic_vector(7 downto 0);" in files[
            "chebnorm_classic_unit.vhd"]
        files = unit_outputs(small("dichotomy"), count=10)
        text = files["chebnorm_dichotomy_unit.v"]
        assert "module chebnorm_dichotomy_d2 #(" in text
        assert "    chebnorm_dichotomy_d2 poly (.x(z_s_v), .y(y));" in text
        vhd = files["chebnorm_dichotomy_unit.vhd"]
        assert "    poly : entity work.chebnorm_dichotomy_d2 port map (x => z_s_v, y => y);" in vhd
        # the evaluator's entity comes first: VHDL analyses it before the unit names it
        assert vhd.index("entity chebnorm_dichotomy_d2 is") < vhd.index(
            "entity chebnorm_dichotomy_unit is")

    @pytest.mark.parametrize("kw, msg", [
        (dict(kind="cordic"), "unit 'cordic' is unknown; accepted: dichotomy, classic"),
        (dict(frac_bits=0), "^frac_bits = 0 is out of range; accepted: 1 <= frac_bits <= 26"),
        (dict(frac_bits=-4), "^frac_bits = -4 is out of range"),
        (dict(comp_bits=1), "accepted: 2 <= comp_bits <= 28"),
        (dict(comp_bits=29), "accepted: 2 <= comp_bits <= 28"),
        (dict(kind="classic", rounding="up"), "rounding 'up' is unknown"),
        (dict(kind="stepper", log_m=11), "accepted: 0 <= log_m <= 10"),
        (dict(kind="stepper", guard=-1), "accepted: 0 <= guard <= 24"),
        (dict(in_bits=0), ": in_bits = 0 is out of range"),
        (dict(coef_bits=33), "accepted: 1 <= coef_bits <= 31"),
        (dict(kind="classic", frac_bits=26, comp_bits=28), None),
    ])
    def test_raises(self, kw, msg):
        args = dict(kind="dichotomy", frac_bits=10) | kw
        if msg is None:
            design_unit(**args)  # the widest accepted widths still fit the int64 model
            return
        with pytest.raises(ValueError, match=msg):
            design_unit(**args)

    @no_yosys
    def test_yosys_cells_beside_model_area(self):
        reps = [analyze_unit(small(k, frac_bits=4, in_bits=6, out_bits=6)) for k in
                ("classic", "stepper")]
        for r in reps:
            d = r.as_dict()
            assert d["yosys_cells"] > 50 and d["area_fa"] > 0
            assert "yosys cells" in r.lines()[0]


class TestCLI:
    @no_iverilog
    def test_unit_writes_and_passes(self, tmp_path, capsys):
        code, out, _ = astuple(run_cli(["hw", "unit", "quadratic", "--vector-frac-bits", "6",
                                        "--in-bits", "8", "--out-bits", "8", "--vectors", "200",
                                        "-o", str(tmp_path), "--simulate"]))
        assert code == 0 and "PASS:" in out and " 0 mismatches" in out
        verdicts = [ln for ln in out.splitlines() if ln.startswith("PASS:")]
        # GHDL too, when installed; each verdict names its simulator
        assert [ln.rsplit(" [", 1)[-1] for ln in verdicts] == \
            ["Icarus Verilog]"] + (["GHDL]"] if which("ghdl") else [])
        # only what the command wrote: GHDL's work library stays out of the folder
        names = sorted(p.name for p in tmp_path.iterdir())
        assert names == ["chebnorm_quadratic_unit.hex", "chebnorm_quadratic_unit.v",
                         "chebnorm_quadratic_unit.vhd", "chebnorm_quadratic_unit_report.json",
                         "tb_chebnorm_quadratic_unit.v", "tb_chebnorm_quadratic_unit.vhd"]

    def test_report_with_units(self, tmp_path, capsys):
        t = tmp_path / "t.json"
        fit_target("dichotomy", 2).save(t)
        code, out, _ = astuple(run_cli(["hw", "report", str(t), "--in-bits", "8",
                                        "--out-bits", "8", "--coef-frac-bits", "12", "--json",
                                        "--no-gappa", "--no-synth", "--unit", "dichotomy",
                                        "--unit", "classic", "--vector-frac-bits", "6"]))
        assert code == 0
        units = json.loads(out)["units"]
        assert [u["unit"] for u in units] == ["dichotomy", "classic"]
        assert all(u["area_fa"] > 0 and "yosys_cells" in u for u in units)

    @pytest.mark.parametrize("extra, msg", [
        (["classic", "--vector-frac-bits", "0"], "--vector-frac-bits = 0 is out of range"),
        (["eta", "--comp-bits", "40"], "accepted: 2 <= --comp-bits <= 28"),
        (["dichotomy", "--in-bits", "-1"], "--in-bits = -1"),
        (["dichotomy", "--coef-frac-bits", "40"], "accepted: 1 <= --coef-frac-bits <= 31"),
        (["stepper", "--log-m", "12"], "accepted: 0 <= --log-m <= 10"),
    ])
    def test_errors_leave_nothing(self, tmp_path, capsys, extra, msg):
        out = tmp_path / "out"
        out.mkdir()
        code, _, err = astuple(run_cli(["hw", "unit", *extra, "-o", str(out)]))
        assert code == 2 and msg in err and err.count("\n") == 1
        assert list(out.iterdir()) == []

    def test_report_unknown_unit(self, tmp_path, capsys):
        t = tmp_path / "t.json"
        fit_target("dichotomy", 2).save(t)
        code, _, err = astuple(run_cli(["hw", "report", str(t), "--in-bits", "8",
                                        "--out-bits", "8", "--coef-frac-bits", "12",
                                        "--unit", "cordic"]))
        assert code == 2 and "unit 'cordic' is unknown" in err


class TestPipelined:
    @no_iverilog
    @pytest.mark.parametrize("degree, rounding", [(1, "trunc"), (3, "rne")])
    def test_bit_for_bit_with_latency(self, degree, rounding, tmp_path):
        from chebnorm.hw.report import analyze, verilog_outputs

        r = analyze(fit_target("midpoint", degree), 10, 10, coef_frac_bits=16, rounding=rounding,
                    synth=False, gappa=False)
        files = verilog_outputs(r, pipelined=True)
        name = f"{r.design.module_name}_pipe"
        assert f"parameter LATENCY = {degree}" in files[f"{name}.v"]
        write_outputs(tmp_path, files)
        res = simulate(tmp_path, name)
        assert res.passed and res.vectors == 1024, res.line
        # the bench really accounts for the latency: one cycle off fails
        bench = files[f"tb_{name}.v"].replace(f"localparam LATENCY = {degree};",
                                              f"localparam LATENCY = {degree + 1};")
        (tmp_path / f"tb_{name}.v").write_text(bench)
        assert not simulate(tmp_path, name).passed

    def test_degree_zero_refused(self):
        from chebnorm.hw.hdl.verilog import verilog_pipelined_module

        d = design_horner(fit_target("dichotomy", 1), 8, 8, coef_bits=12)
        from chebnorm.hw.trust import drafting

        with pytest.raises(ValueError, match="integers"):   # not the table's design
            d.__class__(**{**d.__dict__, "integers": d.integers[:1], "stages": ()})
        with drafting():   # the printer's own refusal, on a design left unchecked
            d0 = d.__class__(**{**d.__dict__, "integers": d.integers[:1], "stages": ()})
            with pytest.raises(ValueError, match="accepted: degree >= 1"):
                verilog_pipelined_module(d0)

    @no_iverilog
    def test_cli_pipelined(self, tmp_path, capsys):
        from chebnorm.cli import main

        t = tmp_path / "t.json"
        fit_target("dichotomy", 2).save(t)
        out = tmp_path / "out"
        out.mkdir()
        code = main(["hw", "verilog", str(t), "--in-bits", "10", "--out-bits", "10",
                     "--coef-frac-bits", "16", "-o", str(out), "--simulate", "--pipelined"])
        text = capsys.readouterr().out
        assert code == 0 and text.count("PASS:") == 2 and "latency 2" in text
        assert (out / "chebnorm_dichotomy_d2_pipe.v").exists()


def test_unit_rejects_a_table_of_another_function():
    """A unit's evaluator must approximate its own target's function."""
    from chebnorm.approx import fit_target
    from chebnorm.hw.units import design_unit, table_matches

    eta = fit_target("eta_term", 2)
    assert table_matches("eta", eta) and not table_matches("dichotomy", eta)
    with pytest.raises(ValueError, match="unit 'dichotomy' needs 1/sqrt"):
        design_unit("dichotomy", table=eta)


class TestRegistry:
    def test_names_and_targets(self):
        from chebnorm.hw.units import UNIT_TARGETS, UNITS, get_unit, unit_names

        assert unit_names() == UNIT_KINDS == ("dichotomy", "classic", "quadratic", "stepper",
                                              "eta")
        assert {n: k.target for n, k in UNITS.items() if k.target} == UNIT_TARGETS
        assert [n for n in unit_names() if get_unit(n).clocked] == ["stepper"]
        with pytest.raises(ValueError, match="unit 'cordic' is unknown; accepted: dichotomy, "
                                             "classic, quadratic, stepper, eta"):
            get_unit("cordic")

    def test_registry_is_read_only_and_names_unique(self):
        from chebnorm.hw.units import UNITS, get_unit, register

        with pytest.raises(TypeError):
            UNITS["x"] = get_unit("classic")  # type: ignore[index]
        with pytest.raises(ValueError, match="already registered"):
            register(get_unit("classic"))

    @pytest.mark.parametrize("kind", UNIT_KINDS)
    def test_design_through_the_registry(self, kind):
        unit = small(kind)
        assert unit.spec.name == kind and unit.module_name == f"chebnorm_{kind}_unit"
        assert (unit.horner is not None) == (unit.spec.target is not None)

    def test_default_table_is_the_targets_fit(self):
        """Without --table a unit fits its target at degree 2, coefficients out_bits + 4."""
        a = unit_outputs(design_unit("quadratic", frac_bits=6, in_bits=8, out_bits=8), count=20)
        b = unit_outputs(design_unit("quadratic", frac_bits=6, in_bits=8, out_bits=8,
                                     table=fit_target("midpoint", 2), coef_bits=12), count=20)
        assert a == b


class TestHostileText:
    """Text a user controls (paths in the command line, a table's expression or
    name) reaches the unit's Verilog and VHDL only as inert comment text."""

    EVIL = 'x\nmodule injected; initial $display("INJECTED"); endmodule\n'

    @no_iverilog
    def test_no_injected_statement(self, tmp_path, capsys):
        import re

        from chebnorm.cli import main

        table = fit_target("dichotomy", 2, coef_frac_bits=18).to_dict()
        folder = tmp_path / self.EVIL
        folder.mkdir()
        # an expression carrying a comment-closer is refused when the table is read
        hostile = dict(table, expression="1/sqrt(2 + z)\n# */ module injected2; endmodule /*")
        (folder / "h.json").write_text(json.dumps(hostile))
        assert main(["hw", "unit", "dichotomy", "--table", str(folder / "h.json"), "--in-bits",
                     "10", "--out-bits", "10", "-o", str(tmp_path / "h")]) == 2
        assert "expression" in capsys.readouterr().err
        # the hostile folder name reaches the banner through the command line
        (folder / "t.json").write_text(json.dumps(table))
        out = f"{tmp_path / self.EVIL}//out"  # '//' so an unescaped newline would comment the rest
        code = main(["hw", "unit", "dichotomy", "--table", f"{folder}//t.json", "--in-bits", "10",
                     "--out-bits", "10", "--vectors", "60", "-o", out, "--simulate"])
        text = capsys.readouterr().out
        assert code == 0 and "PASS:" in text and "INJECTED" not in text.split("PASS:")[1]
        for f in (tmp_path / self.EVIL / "out").glob("*.v"):
            lines = f.read_text().splitlines()
            assert all(ln.startswith("//") for ln in lines if "injected" in ln), f.name
            modules = re.findall(r"^\s*module\s+(\w+)", "\n".join(lines), re.M)
            assert modules and all(m.startswith(("chebnorm_", "tb_chebnorm_")) for m in modules)
        for f in (tmp_path / self.EVIL / "out").glob("*.vhd"):
            lines = f.read_text().splitlines()
            assert all(ln.startswith("--") for ln in lines if "injected" in ln), f.name
            entities = re.findall(r"^entity\s+(\w+)\s+is", "\n".join(lines), re.M)
            assert entities and all(e.startswith(("chebnorm_", "tb_chebnorm_"))
                                    for e in entities)
        banner = (tmp_path / self.EVIL / "out" / "chebnorm_dichotomy_unit.v").read_text()
        assert '// Command: chebnorm hw unit dichotomy --table ' in banner
        assert '_module injected; initial $display("INJECTED"); endmodule_' in banner
        vhd = (tmp_path / self.EVIL / "out" / "chebnorm_dichotomy_unit.vhd").read_text()
        assert '-- Command: chebnorm hw unit dichotomy --table ' in vhd

    @pytest.mark.parametrize("name", ["d2; initial $finish", "a\nb", "x" * 64])
    def test_hostile_table_name_refused(self, tmp_path, capsys, name):
        from chebnorm.cli import main

        table = fit_target("dichotomy", 2, coef_frac_bits=18).to_dict()
        table["name"] = name
        (tmp_path / "t.json").write_text(json.dumps(table))
        out = tmp_path / "out"
        code = main(["hw", "unit", "dichotomy", "--table", str(tmp_path / "t.json"), "-o",
                     str(out)])
        err = capsys.readouterr().err
        assert code == 2 and err.count("\n") == 1 and "identifier" in err
        assert not out.exists()
