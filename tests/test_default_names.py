"""Tables named by default after their fit, so the exports of different fits
coexist in one build: two headers in one C file, two Verilog modules in one
yosys run."""

import subprocess

import pytest

import chebnorm as cn
from chebnorm.core.textsafe import default_name, identifier


@pytest.fixture(scope="module")
def tables():
    return cn.fit("1/sqrt(x)", (1, 4), 3), cn.fit("sin(x)", (0, 1), 5)


def test_names(tables):
    assert [t.name for t in tables] == ["rsqrt_1_4_d3", "sin_0_1_d5"]


@pytest.mark.parametrize("expr, interval, degree, segments, want", [
    ("1/sqrt(x)", ("1", "4"), 3, None, "rsqrt_1_4_d3"),
    ("1/sqrt(z + 2)", ("sqrt(2)", "2"), 2, None, "rsqrt_z_2_sqrt_2_2_d2"),
    ("sin(x)", ("-pi/4", "pi/4"), 7, None, "sin_mpi_4_pi_4_d7"),
    ("x", ("0", "1"), 1, None, "x_0_1_d1"),
    ("5", ("1", "2"), 0, None, "f5_1_2_d0"),
    ("1/x", ("1", "2"), 4, 16, "rx_1_2_d4_s16"),
    ("log(x + 1)/x", ("0.5", "1e-3"), 3, None, "log_x_1_x_0p5_1em3_d3"),
])
def test_default_name_cases(expr, interval, degree, segments, want):
    assert default_name(expr, interval, degree, segments=segments) == want


def test_long_names_are_cut_with_a_hash_and_stay_distinct():
    a = default_name("sin(x)*" * 20 + "x", ("0", "1"), 3)
    b = default_name("sin(x)*" * 20 + "x", ("0", "2"), 3)
    assert a != b and len(a) <= 63 and len(b) <= 63 and identifier(a) == a


@pytest.mark.requires_tool("gcc")
def test_two_default_headers_in_one_c_file(tables, tmp_path):
    """Issue 44's acceptance: both headers included, both evaluators called,
    gcc -Wall -Werror."""
    for t in tables:
        (tmp_path / f"{t.name}.h").write_text(cn.export(t, "c"), encoding="utf-8")
    (tmp_path / "main.c").write_text(
        '#include <stdio.h>\n#include "rsqrt_1_4_d3.h"\n#include "sin_0_1_d5.h"\n'
        'int main(void) { printf("%.6f %.6f\\n", chebnorm_rsqrt_1_4_d3(2.0), '
        'chebnorm_sin_0_1_d5(0.5)); return 0; }\n', encoding="utf-8")
    subprocess.run(["gcc", "-std=c99", "-Wall", "-Werror", "-pedantic", "main.c", "-o", "main",
                    "-lm"], cwd=tmp_path, check=True, capture_output=True, text=True)
    out = subprocess.run([str(tmp_path / "main")], capture_output=True, text=True, check=True)
    r, s = map(float, out.stdout.split())
    # each within its table's certified bound (plus the 6 printed decimals)
    assert abs(r - 2 ** -0.5) <= tables[0].abs_error_bound + 5e-7
    assert abs(s - 0.479425538604203) <= tables[1].abs_error_bound + 5e-7


@pytest.mark.requires_tool("yosys")
def test_two_default_modules_in_one_yosys_run(tables, tmp_path):
    files = []
    for t in tables:
        q = cn.quantize(t, 16)
        path = tmp_path / f"{t.name}.v"
        path.write_text(cn.export(q, "verilog", in_bits=12, out_bits=12), encoding="utf-8")
        files.append(str(path))
    done = subprocess.run(["yosys", "-q", "-p", "hierarchy; proc; stat", *files],
                          cwd=tmp_path, capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
