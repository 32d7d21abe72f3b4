"""Every docstring example in the library runs and gives what it shows."""

from __future__ import annotations

import doctest
import importlib
import inspect
import pkgutil
import sys

import pytest

import chebnorm

MODULES = sorted(m.name for m in pkgutil.walk_packages(chebnorm.__path__, "chebnorm.")
                 if not m.name.endswith("__main__"))


@pytest.mark.parametrize("name", MODULES)
def test_docstring_examples(name):
    module = importlib.import_module(name)
    result = doctest.testmod(module, optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
    assert result.failed == 0


# ------------------------------------------------ every public callable shows an example
#: the modules whose public callables must carry a runnable example (``>>>``)
EXAMPLE_PACKAGES = ("chebnorm.symbolic", "chebnorm.export", "chebnorm.hw", "chebnorm.methods")
EXAMPLE_MODULES = ("chebnorm.approx.expr", "chebnorm.core.files", "chebnorm.core.textsafe",
                   "chebnorm.core.parallel", "chebnorm.approx.method_registry",
                   "chebnorm.approx.targets")
#: a design-space search whose smallest run takes minutes; its types have examples elsewhere
EXAMPLE_SKIPPED_MODULES = ("chebnorm.hw.piecewise_search",)

_TOOL = "runs an external tool (iverilog, yosys, ghdl, glslangValidator) the suite skips without"
_RESULT = "made only by a run of an external tool (simulate / synthesize)"
#: public callables without an example, and why (keep this short)
EXAMPLE_EXEMPT = {
    "chebnorm.hw.run_verilog.simulate": _TOOL,
    "chebnorm.hw.run_verilog.synthesize": _TOOL,
    "chebnorm.hw.targets.synthesize_target": _TOOL,
    "chebnorm.hw.targets.fmax_ice40": _TOOL + " (and nextpnr-ice40)",
    "chebnorm.hw.run_verilog.SimResult": _RESULT,
    "chebnorm.hw.run_verilog.SynthResult": _RESULT,
}


def example_modules() -> list[str]:
    names = list(EXAMPLE_MODULES)
    for pkg in EXAMPLE_PACKAGES:
        names.append(pkg)
        names += [m.name for m in pkgutil.walk_packages(importlib.import_module(pkg).__path__,
                                                        pkg + ".")]
    return sorted(n for n in names if n not in EXAMPLE_SKIPPED_MODULES
                  and not any(p.startswith("_") for p in n.split(".")))


def _exports(module) -> list[str]:
    """The module's ``__all__``, or without one the functions and classes it defines
    whose names do not start with ``_``."""
    if hasattr(module, "__all__"):
        return list(module.__all__)
    return [n for n, v in vars(module).items() if not n.startswith("_")
            and (inspect.isfunction(v) or inspect.isclass(v)) and v.__module__ == module.__name__]


def _own_callables(module) -> list[str]:
    """Public callables defined in ``module``, by their names there: those its own
    exports name, and those the ``__all__`` of a package above it exports (its stage's
    API, which an implementation module's empty ``__all__`` leaves to the stage).
    Re-exports are checked in the module that defines them."""
    objects = [getattr(module, n) for n in _exports(module)]
    parts = module.__name__.split(".")
    for i in range(1, len(parts)):
        pkg = sys.modules.get(".".join(parts[:i]))
        objects += [getattr(pkg, n) for n in getattr(pkg, "__all__", ())]
    names = []
    for obj in objects:
        if callable(obj) and not inspect.ismodule(obj) \
                and getattr(obj, "__module__", None) == module.__name__ \
                and vars(module).get(getattr(obj, "__name__", None)) is obj and obj.__name__ not in names:
            names.append(obj.__name__)
    return names


@pytest.mark.parametrize("name", example_modules())
def test_public_callables_have_examples(name):
    """Each public callable's docstring holds an example that the doctest run
    above collects (a ``>>>`` doctest does not find would not count)."""
    module = importlib.import_module(name)
    collected = {t.name for t in doctest.DocTestFinder().find(module) if t.examples}
    missing = [n for n in _own_callables(module) if f"{name}.{n}" not in collected
               and f"{name}.{n}" not in EXAMPLE_EXEMPT]
    assert missing == [], f"{name}: public callables without a runnable example: {missing}"


def test_example_exemptions_are_current():
    """An exempt name still exists, is public, and still has no example."""
    for qual, reason in EXAMPLE_EXEMPT.items():
        mod_name, _, attr = qual.rpartition(".")
        module = importlib.import_module(mod_name)
        assert attr in _own_callables(module) and reason
        collected = {t.name for t in doctest.DocTestFinder().find(module) if t.examples}
        assert qual not in collected, f"{qual} has an example now: drop its exemption"


def test_example_check_sees_a_missing_example():
    """The check above fails on a public function without an example."""
    import types

    module = types.ModuleType("chebnorm_fake_module")
    exec("__all__ = ['f', 'g']\n"
         "def f():\n    '''Has one.\n\n    >>> f()\n    1\n    '''\n    return 1\n"
         "def g():\n    '''Has none.'''\n", module.__dict__)
    collected = {t.name for t in doctest.DocTestFinder().find(module) if t.examples}
    missing = [n for n in _own_callables(module) if f"{module.__name__}.{n}" not in collected]
    assert missing == ["g"]


def test_example_check_sees_a_stage_name_its_module_does_not_export(monkeypatch):
    """An implementation module exports nothing (``__all__ = []``); a function its stage
    exports is checked there all the same, and a helper neither exports is not."""
    import types

    stage = types.ModuleType("chebnorm_fake_stage")
    module = types.ModuleType("chebnorm_fake_stage.impl")
    exec("__all__ = []\n"
         "def f():\n    '''Exported by the stage, no example.'''\n"
         "def helper():\n    '''Used by the stage's modules only.'''\n", module.__dict__)
    stage.__all__ = ["f"]
    stage.f = module.f
    monkeypatch.setitem(sys.modules, stage.__name__, stage)
    monkeypatch.setitem(sys.modules, module.__name__, module)
    collected = {t.name for t in doctest.DocTestFinder().find(module) if t.examples}
    missing = [n for n in _own_callables(module) if f"{module.__name__}.{n}" not in collected]
    assert missing == ["f"]
