"""The command line's parsers import no stage, and the words they use are the library's."""

from __future__ import annotations

import subprocess
import sys

import pytest

from chebnorm.cli import vocab


def test_every_copy_is_the_library_value():
    import chebnorm.approx as approx
    import chebnorm.export as export
    import chebnorm.export.verify as verify
    import chebnorm.hw.units as units
    import chebnorm.raster as raster

    library = {"COEF_FORMATS": approx.COEF_FORMATS, "MAX_DEGREE": approx.MAX_DEGREE,
               "EXPORT_FORMATS": export.EXPORT_FORMATS, "VERIFY_FORMATS": verify.VERIFY_FORMATS,
               "VARIANTS": verify.VARIANTS, "MAX_INPUTS": verify.MAX_INPUTS,
               "UNIT_NAMES": units.unit_names(),
               "MESH_NAMES": raster.MESH_NAMES, "SHADING_MODES": raster.SHADING_MODES,
               "BUMP_VARIANTS": raster.BUMP_VARIANTS}
    assert sorted(library) == sorted(vocab.__all__)
    for name, value in library.items():
        assert getattr(vocab, name) == value, name


# the process is the point: the test's own process has every stage loaded already
_PROBE = """
import sys
import chebnorm.cli as cli
cli.build_parser()
stages = ("approx", "core", "export", "hw", "methods", "raster", "symbolic")
heavy = ("numpy", "scipy", "sympy", "mpmath", "flint", "numba", "matplotlib")
loaded = sorted(m for m in sys.modules
                if m.split(".")[0] in heavy or m.split(".")[:2] in [["chebnorm", s] for s in stages])
print(",".join(loaded))
"""


def test_the_parsers_load_no_stage():
    out = subprocess.run([sys.executable, "-c", _PROBE], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == ""


@pytest.mark.parametrize("argv", [["--help"], ["--version"], ["fit", "--help"],
                                  ["hw", "report", "--help"], ["render-sweep", "--help"],
                                  ["design", "--help"], ["verify", "--help"]])
def test_help_loads_no_stage(argv):
    code = ("import sys, chebnorm.cli as cli\n"
            "try:\n    cli.main(sys.argv[1:])\nexcept SystemExit:\n    pass\n"
            "heavy = ('numpy', 'sympy', 'numba', 'flint', 'chebnorm.approx', 'chebnorm.raster')\n"
            "print(','.join(sorted(m for m in sys.modules if m.startswith(heavy))), file=sys.stderr)\n")
    out = subprocess.run([sys.executable, "-c", code, *argv], capture_output=True, text=True)
    assert out.returncode == 0
    assert out.stdout.strip(), "the help or the version was printed"
    assert out.stderr.strip() == ""


def test_helps_naming_registries_are_filled_in_when_printed():
    """``render --help`` names the registered methods, ``hw unit --help`` the units'
    targets: read from the registries when the help is printed."""
    from chebnorm.hw.units import UNIT_TARGETS
    from chebnorm.raster import available_methods
    from conftest import run_cli

    out = run_cli("render", "--help").out  # argparse may wrap the list inside a name
    assert "|".join(available_methods()) in "".join(out.split())
    out = " ".join(run_cli("hw", "unit", "--help").out.split())
    assert all(t in out for t in UNIT_TARGETS.values())


def test_methods_max_angle_is_below_the_antiparallel_limit():
    import math

    from chebnorm.cli.methods import MAX_ANGLE
    from chebnorm.methods import ANTIPARALLEL_TOL

    assert 1 + math.cos(MAX_ANGLE) > ANTIPARALLEL_TOL
    assert math.acos(ANTIPARALLEL_TOL - 1) - MAX_ANGLE < 1e-2   # not needlessly small


def test_methods_angle_near_pi_is_refused_naming_the_flag():
    from quiet_cli import run_cli_quiet

    code, out, err = run_cli_quiet("methods", "--angle", "3.14159265358979", "--span", "8")
    assert code == 2 and out == ""
    assert err.count("\n") == 1 and "--angle" in err and "0 <= PSI <= 3.14" in err


def test_a_top_level_usage_error_names_the_program_once():
    from quiet_cli import run_cli_quiet

    code, out, err = run_cli_quiet("targets", "--bogus")   # an unknown option, top level
    assert code == 2 and err.count("chebnorm:") == 1 and "--bogus" in err, err
    code, out, err = run_cli_quiet("fit", "x", "--interval", "0", "1", "--degree", "1", "--bogus")
    assert code == 2 and err.startswith("chebnorm: error:") and "--bogus" in err
