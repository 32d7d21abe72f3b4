"""``chebnorm verify`` reads the stated bounds from what the compiler builds,
never from the last textual ``#define`` (issue 43), and a variant it cannot
check is a failure (exit 1 with the reason), not a skip with exit 0.

Independent check: the value each forged header or shader really states is
written here as a number (``1e-9``), and the measured error of the unchanged
evaluator (about 1.03e-7) is far above it."""

from __future__ import annotations

import re
from dataclasses import astuple

import numpy as np
import pytest

from chebnorm.approx import fit
from chebnorm.export import export_text
from chebnorm.export.verify import verify
from conftest import requires_tool, run_cli

needs_gcc = requires_tool("gcc")
BOUND = "CHEBNORM_RSC_F_EVAL_ERROR_BOUND"


@pytest.fixture(scope="module")
def table():
    return fit("1/sqrt(x)", ("1", "1 + 2**-10"), 2, name="rsc", coef_frac_bits=24)


@pytest.fixture(scope="module")
def table_file(table, tmp_path_factory):
    path = tmp_path_factory.mktemp("verify_compiled") / "rsc.json"
    path.write_text(table.to_json(), encoding="utf-8")
    return path


def _with_bound(header: str, value: str, tail: str = "") -> str:
    original = re.search(rf"^#define {BOUND} .*$", header, re.M).group(0)
    changed = header.replace(original, f"#define {BOUND} {value}", 1)
    return changed + tail.replace("ORIGINAL", original)


def _cli(table_file, tmp_path, text, *args, name="src.h"):
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return astuple(run_cli("verify", table_file, "--source", path, *args))


@needs_gcc
@pytest.mark.parametrize("tail", ["#if 0\nORIGINAL\n#endif\n",
                                  "/* the old value:\nORIGINAL\n*/\n".replace("ORIGINAL", "XX")])
def test_the_compiled_bound_is_checked_not_a_dead_define(table, table_file, tmp_path, tail):
    header = export_text(table, "c")
    if "XX" in tail:  # a comment cannot hold the original line (it has comments): its value
        value = re.search(rf"^#define {BOUND} (\S+)", header, re.M).group(1)
        tail = tail.replace("XX", f"#define {BOUND} {value}")
    forged = _with_bound(header, "1e-9", tail)
    (v,) = verify(table, "c", variant="float", source=forged).variants
    assert v.stated_bound == pytest.approx(1e-9, rel=1e-15) and v.stated_bound <= 1e-9
    assert v.passed is False and v.measured_max > 1e-7
    status, out, err = _cli(table_file, tmp_path, forged, "--variant", "float")
    assert status == 1 and err.count("\n") == 1 and "exceeded" in err and BOUND in err
    assert "EXCEEDS" in out


@needs_gcc
def test_a_bound_written_as_an_expression_is_evaluated(table, table_file, tmp_path):
    forged = _with_bound(export_text(table, "c"), "(2e-9 / 2 + 0 * sizeof(int))")
    (v,) = verify(table, "c", variant="float", source=forged).variants
    assert v.unchecked is None and v.skipped is None
    assert v.stated_bound == pytest.approx(1e-9, rel=1e-15) and v.passed is False
    status, _, err = _cli(table_file, tmp_path, forged, "--variant", "float")
    assert status == 1 and "exceeded" in err


@needs_gcc
def test_a_true_bound_as_an_expression_passes(table, table_file, tmp_path):
    header = export_text(table, "c")
    value = float.fromhex(re.search(rf"^#define {BOUND} (\S+)", header, re.M).group(1))
    forged = _with_bound(header, f"({(2 * value).hex()} / 2)")
    status, out, err = _cli(table_file, tmp_path, forged, "--variant", "float",
                            "--variant", "float-fused")
    assert status == 0 and err == "" and out.count(" ok") == 2


@needs_gcc
@pytest.mark.parametrize("tail,reason", [
    (f"#undef {BOUND}\n", "not defined in the compiled header"),
    (f'#undef {BOUND}\n#define {BOUND} "1e-9"\n', "not a number in C"),
    (f"#undef {BOUND}\n#define {BOUND} (1.0 / 0.0)\n", "not a finite number"),
])
def test_an_unreadable_bound_is_a_failure_not_a_skip(table, table_file, tmp_path, tail, reason):
    forged = export_text(table, "c") + tail
    r = verify(table, "c", variant=("float", "double"), source=forged)
    by = {v.variant: v for v in r.variants}
    assert by["float"].unchecked is not None and reason in by["float"].unchecked
    assert by["float"].passed is False and by["double"].passed is True
    assert r.passed is False and not r.complete and r.exceeded == ()
    assert "NOT CHECKED" in str(r) and "NOT CHECKED" in r.markdown()
    status, out, err = _cli(table_file, tmp_path, forged, "--variant", "float")
    assert status == 1 and err.count("\n") == 1 and "not checked" in err and reason in err
    assert "Traceback" not in err


@needs_gcc
def test_the_interval_is_read_from_the_compiled_header(table, tmp_path):
    header = export_text(table, "c")
    (whole,) = verify(table, "c", variant="float", source=header).variants
    narrowed = header + "#undef CHEBNORM_RSC_HI\n#define CHEBNORM_RSC_HI (1.0 + 0x1p-11)\n"
    (half,) = verify(table, "c", variant="float", source=narrowed).variants
    # every float32 in [1, 1 + 2^-10] is 2^13 + 1 codes; [1, 1 + 2^-11] is 2^12 + 1
    assert (whole.count, half.count) == (2 ** 13 + 1, 2 ** 12 + 1)
    gone = header + "#undef CHEBNORM_RSC_LO\n"
    (v,) = verify(table, "c", variant="float", source=gone).variants
    assert v.unchecked == "CHEBNORM_RSC_LO is not defined in the compiled header"


@needs_gcc
def test_the_fused_build_states_its_own_bound(table):
    """A header may state another bound where the compiler contracts to FMA:
    each build is read separately."""
    header = export_text(table, "c")
    forged = header + (f"#ifdef __FMA__\n#undef {BOUND}\n#define {BOUND} 1e-9\n#endif\n")
    r = verify(table, "c", variant=("float", "float-fused"), source=forged)
    by = {v.variant: v for v in r.variants}
    assert by["float"].passed is True
    if "the target has FMA" in " ".join(by["float-fused"].notes):
        assert by["float-fused"].stated_bound <= 1e-9 and by["float-fused"].passed is False


def test_hlsl_that_nothing_ran_exits_1_with_the_reason(table_file):
    status, out, err = astuple(run_cli("verify", table_file, "--format", "hlsl"))
    assert status == 1 and err.count("\n") == 1
    assert "not checked" in err and ("no HLSL runtime" in err or "glslang" in err)


@pytest.mark.parametrize("fmt", ["glsl", "wgsl"])
def test_shader_constants_are_read_from_the_driver(table, fmt):
    text = export_text(table, fmt)
    name = "CHEBNORM_RSC_EVAL_ERROR_BOUND"
    if fmt == "glsl":
        line = re.search(rf"^const float {name} = .*$", text, re.M).group(0)
        forged = text.replace(line, f"const float {name} = 1e-9;\n#if 0\n{line}\n#endif", 1)
    else:
        line = re.search(rf"^const {name}: f32 = .*$", text, re.M).group(0)
        forged = text.replace(line, f"const {name}: f32 = 2e-9f * 0.5f;\n// {line}", 1)
    (v,) = verify(table, fmt, source=forged).variants
    if v.skipped is not None:
        pytest.skip(f"no {fmt} driver here: {v.skipped}")
    assert v.stated_bound == float(np.float32(1e-9)) and v.passed is False
    (w,) = verify(table, fmt).variants
    assert w.passed is True


def test_docs_say_that_source_is_compiled_and_run():
    from pathlib import Path

    text = (Path(__file__).resolve().parent.parent / "docs" / "cli.md").read_text(
        encoding="utf-8")
    section = text[text.index("## `chebnorm verify`"):]
    section = section[:section.index("\n## ", 4)]
    assert "trusted code only" in section and "compiled and loaded" in section
