"""The package's public surface is narrow: each stage's ``__init__`` is its API, the
implementation modules export nothing through ``__all__``, and the sum of the
``__all__`` lists of ``src/chebnorm`` stays at most :data:`MAX_EXPORTS`.

Narrowing must not cost users a name: the stage ``__all__`` lists are the ones
users had (:data:`CONTRACT`), and every ``chebnorm.X.Y`` / ``cn.X.Y`` / ``from
chebnorm.X import Y`` that the README, the manual (``docs/``), the notebooks and
the ``figures/`` and ``paper_repro/`` scripts use still resolves. Those names are
collected from the files (``ast`` for code, a pattern for prose), not listed by
hand, so a page that starts using a name is checked at once.
"""

from __future__ import annotations

import ast
import importlib
import inspect
import json
import pkgutil
import re
from pathlib import Path

import pytest

import chebnorm

ROOT = Path(__file__).resolve().parent.parent
SRC = ROOT / "src" / "chebnorm"

#: the most names the package's ``__all__`` lists may hold together (issue 45)
MAX_EXPORTS = 350

#: The users' contract: the ``__all__`` of the facade, of :mod:`chebnorm.exceptions` and
#: of every package ``__init__``, as they were when the implementation modules stopped
#: exporting names. Copied on purpose: a change here is a change of the public API.
CONTRACT = {
    'chebnorm': ('__version__', 'LAYERS', 'fit', 'quantize', 'certify', 'fit_target', 'CoefficientTable',
                 'FixedPoint', 'PiecewiseTable', 'load_table', 'FitWarning', 'ChebnormDeprecationWarning',
                 'target', 'target_names', 'span_normals', 'method_names', 'render', 'compare',
                 'RenderComparison', 'correctly_rounded', 'exceptions', 'core', 'symbolic', 'approx',
                 'export', 'methods', 'hw', 'raster', 'cr'),
    'chebnorm.approx': ('CoefficientTable', 'FixedPoint', 'Quantized', 'COEF_FORMATS', 'SCHEMA_VERSION', 'fit',
                        'quantize', 'warnings_of', 'FitWarning', 'MAX_DEGREE', 'Certificate', 'certify',
                        'Function1D', 'read_expression', 'parse_function', 'parse_number', 'Target', 'TARGETS',
                        'get_target', 'target_names', 'fit_target', 'Table', 'ErrorBounds', 'PiecewiseTable',
                        'PiecewiseSegment', 'piecewise_fit', 'load_table', 'table_from_json'),
    'chebnorm.cli': ('main', 'build_parser', 'UsageError'),
    'chebnorm.core': ('clib', 'deprecation', 'detlinalg', 'files', 'numeric', 'parallel', 'progress', 'textsafe',
                      'tools'),
    'chebnorm.exceptions': ('FitWarning', 'ChebnormDeprecationWarning', 'FrequencyWarning',
                            'NumbaCompileWarning', 'UndefinedError', 'SegmentError', 'WriteError', 'UsageError',
                            'ToolMissing', 'ToolFailed', 'ToolTimeout', 'FrameUnsupported'),
    'chebnorm.export': ('FORMATS', 'TABLE_FORMATS', 'HDL_FORMATS', 'EXPORT_FORMATS', 'PIECEWISE_FORMATS',
                        'HDL_OPTIONS', 'formats_for', 'options_for', 'c_header', 'json_text', 'export_text',
                        'export_table', 'hdl_export', 'horner_rounding_bound', 'glsl_source', 'wgsl_source',
                        'hlsl_source', 'shader_source', 'float32_eval_bound', 'piecewise_c_header',
                        'DEFAULT_C_IN_BITS', 'export_with_proofs'),
    'chebnorm.hw': ('QFormat', 'shift_round', 'fit_bits', 'HornerDesign', 'design_horner', 'ErrorBudget',
                    'Measurement', 'error_budget', 'measure', 'gappa_script', 'gappa_bound', 'verilog_module',
                    'verilog_testbench', 'vector_file', 'simulate', 'synthesize', 'module_text',
                    'testbench_text', 'hdl_text', 'hdl_files', 'SimResult', 'SynthResult', 'Cost', 'Block',
                    'horner_block', 'classic_unit', 'dichotomy_unit', 'quadratic_midpoint_unit',
                    'forward_difference_stepper', 'eta_unit', 'phong_pipeline', 'bump_pipeline',
                    'classic_normalize', 'dichotomy_midpoint', 'dichotomy_next_z', 'quadratic_midpoint',
                    'eta_criterion', 'forward_difference', 'forward_difference_setup',
                    'forward_difference_codes', 'UNIT_KINDS', 'UnitDesign', 'UnitReport', 'design_unit',
                    'unit_outputs', 'unit_verilog', 'analyze_unit', 'UNITS', 'UnitKind', 'get_unit',
                    'unit_names', 'HardwareReport', 'analyze', 'verilog_outputs', 'write_outputs', 'SweepPoint',
                    'SweepResult', 'sweep', 'MultipartiteDesign', 'OffsetTable', 'design_multipartite',
                    'multipartite_candidates', 'PlainTableDesign', 'design_plain_table', 'table_module',
                    'table_files', 'simulate_table', 'TargetCost', 'synthesize_target', 'fmax_ice40',
                    'Candidate', 'architecture_candidates', 'FrequencyWarning', 'PipelineResult',
                    'pipeline_to_frequency', 'ExponentDesign', 'design_exponent', 'simulate_exponent', 'design',
                    'DesignResult', 'Winner', 'Design', 'ARCHITECTURES', 'architecture'),
    'chebnorm.hw.hdl': ('LANGUAGES', 'SUFFIX', 'check_language', 'is_piecewise', 'module_text', 'testbench_text',
                        'hdl_text', 'hdl_files', 'banner_facts', 'comment_lines', 'module_name',
                        'pipelined_name', 'vector_file'),
    'chebnorm.hw.units': ('UNIT_KINDS', 'UNIT_TARGETS', 'UNITS', 'UnitKind', 'get_unit', 'unit_names',
                          'register', 'table_matches', 'Port', 'UnitDesign', 'UnitReport', 'design_unit',
                          'unit_vectors', 'unit_verilog', 'unit_testbench', 'unit_vector_file', 'unit_outputs',
                          'analyze_unit', 'MAX_COMP_BITS', 'MAX_UNIT_FRAC_BITS'),
    'chebnorm.methods': ('METHODS', 'method_names', 'get_method', 'register', 'unregister', 'MethodSpec',
                         'TableSpec', 'registered_methods', 'method_kernel', 'method_kernels', 'table_methods',
                         'unit_tables', 'SpanNormals', 'span_normals', 'default_tables', 'UNIT_TOL',
                         'ANTIPARALLEL_TOL', 'OP_KINDS', 'OpCounts', 'count_ops', 'NormalizationCounts',
                         'normalization_ops', 'PAPER_COUNTS', 'MethodReport', 'analyze', 'ErrorSweep',
                         'error_sweep', 'DriftReport', 'angular_drift', 'length_error_bound', 'N_SPECULAR',
                         'reference_normals', 'slerp_normals'),
    'chebnorm.raster': ('render', 'compare', 'error_map_rgb', 'write_image', 'write_png', 'IMAGE_FORMATS',
                        'to_8bit', 'RenderResult', 'ImageMetrics', 'Lighting', 'HeightMap', 'SHADING_MODES',
                        'BUMP_VARIANTS', 'available_methods', 'get_span_normals', 'Mesh', 'MESH_NAMES',
                        'get_mesh', 'uv_sphere', 'icosphere', 'torus', 'square', 'teapot', 'load_mesh',
                        'crease_normals', 'Camera', 'Spans', 'default_camera', 'fit_camera', 'project',
                        'setup_spans', 'zbuffer', 'eta_study', 'EtaLevel', 'split_gouraud_study',
                        'SplitGouraudStudy', 'bump_comparison', 'BumpCase', 'write_bump_figures', 'render_sweep',
                        'render_sweep_cases', 'RenderCase', 'RenderSweepRow', 'RenderSweep',
                        'RENDER_SWEEP_COLUMNS', 'RenderComparison', 'render_html', 'png_data_uri'),
    'chebnorm.cr': ('correctly_rounded',),
    'chebnorm.raster.engines': ('ENGINES', 'HAVE_NUMBA', 'Engine', 'FrameUnsupported', 'resolve_engine',
                                'get_engine'),
    'chebnorm.raster.engines.numba': ('NumbaEngine',),
    'chebnorm.symbolic': ('symbols', 'UNIT_RTOL', 'DOT_ATOL', 'GRAM_ATOL', 'EdgeHighlight',
                          'QuadraticCoefficients', 'norm2_linear_expr', 'norm2_linear_np', 'midpoint_norm2_expr',
                          'midpoint_scale_expr', 'midpoint_normal', 'linear_argmin_expr', 'min_norm_linear_expr',
                          'delta_d_expr', 'delta_d', 'delta_s_expr', 'delta_s', 'edge_bound_expr', 'eta_expr',
                          'eta', 'quadratic_coefficients_expr', 'quadratic_coefficients', 'edge_cosine_expr',
                          'edge_highlight_expr', 'edge_highlight', 'edge_highlight_unclipped',
                          'bump_coefficients_expr', 'bump_coefficients_seed_expr',
                          'bump_coefficients_square_expr', 'bump_coefficients', 'bump_coefficients_square')
}


# ------------------------------------------------------------------ the size of the surface
def all_sizes(root: Path = SRC) -> dict[str, int]:
    """Module path (relative to ``root``) -> the length of its ``__all__`` (ast, module
    level: ``__all__ = [...]``, ``__all__: list[str] = [...]``, ``__all__ += [...]``).
    A ``__all__`` that is not a literal list or tuple raises: it could not be counted."""
    sizes = {}
    for path in sorted(root.rglob("*.py")):
        tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
        n = 0
        for node in tree.body:
            if isinstance(node, (ast.Assign, ast.AnnAssign, ast.AugAssign)):
                targets = node.targets if isinstance(node, ast.Assign) else [node.target]
                if not any(isinstance(t, ast.Name) and t.id == "__all__" for t in targets):
                    continue
                try:
                    value = ast.literal_eval(node.value)
                except ValueError as exc:
                    raise AssertionError(f"{path}:{node.lineno}: __all__ is not a literal") from exc
                n = n + len(value) if isinstance(node, ast.AugAssign) else len(value)
        if n:
            sizes[str(path.relative_to(root))] = n
    return sizes


def test_the_package_exports_at_most_350_names():
    sizes = all_sizes()
    total = sum(sizes.values())
    biggest = sorted(sizes.items(), key=lambda kv: -kv[1])[:10]
    assert total <= MAX_EXPORTS, f"{total} names in __all__ lists; largest: {biggest}"
    # the stage __init__ lists alone are most of the budget: the count sees them
    assert sizes["hw/__init__.py"] == len(CONTRACT["chebnorm.hw"])


def test_the_count_can_fail(tmp_path):
    (tmp_path / "a.py").write_text("__all__ = ['x', 'y']\n__all__ += ['z']\n")
    (tmp_path / "b.py").write_text("__all__: list[str] = ['u']\n")
    (tmp_path / "c.py").write_text("__all__: list[str] = []\n")
    assert all_sizes(tmp_path) == {"a.py": 3, "b.py": 1}
    (tmp_path / "d.py").write_text("__all__ = sorted(globals())\n")
    with pytest.raises(AssertionError, match="not a literal"):
        all_sizes(tmp_path)


@pytest.mark.parametrize("module", sorted(CONTRACT))
def test_stage_exports_are_unchanged(module):
    mod = importlib.import_module(module)
    assert tuple(mod.__all__) == CONTRACT[module]
    missing = [name for name in mod.__all__ if not hasattr(mod, name)]
    assert missing == []


def test_every_package_init_is_in_the_contract():
    """A new stage or subpackage joins the contract (and the count) deliberately."""
    packages = {".".join(p.relative_to(SRC.parent).parent.parts) for p in SRC.rglob("__init__.py")}
    assert packages | {"chebnorm.exceptions"} == set(CONTRACT)


# ------------------------------------------------------------------ the names users use
#: the files users read or run: their names of the package must resolve
USER_FILES = ("README.md", "docs/*.md", "docs/**/*.md", "docs/*.rst", "notebooks/*.ipynb",
              "figures/**/*.py", "paper_repro/*.py")

_FENCE = re.compile(r"^(`{3,}|~{3,})[ \t]*(\{code-cell\}[^\n]*|python3?|py|pycon|ipython3?)[ \t]*\n(.*?)^\1",
                    re.M | re.S)
#: a dotted name in prose or in code that ast cannot read (``cn.fit``, ``chebnorm.hw.design``)
_DOTTED = re.compile(r"(?<![\w./\"'-])(?:chebnorm|cn)(?:\.[A-Za-z_]\w*)+")
_FROM = re.compile(r"from\s+(chebnorm(?:\.\w+)*)\s+import\s+(\([^)]*\)|[^\n#]+)")


def _strip_prompts(code: str) -> str:
    lines = code.splitlines()
    if any(line.lstrip().startswith(">>>") for line in lines):
        lines = [line.lstrip()[4:] for line in lines if line.lstrip().startswith((">>>", "..."))]
    return "\n".join(line for line in lines if not line.lstrip().startswith(("%", "!")))


def _from_code(code: str) -> set[str]:
    """Dotted names of the package a piece of Python uses: what ``from chebnorm... import``
    brings in, and every attribute chain read through a name bound to the package or one
    of its modules (``import chebnorm as cn``, ``import chebnorm.hw as hw``)."""
    try:
        tree = ast.parse(_strip_prompts(code))
    except SyntaxError:
        return _from_prose(code)
    bound = {"cn": "chebnorm"}  # the manual's spelling, also where the import is out of view
    found: set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for a in node.names:
                if a.name.split(".")[0] == "chebnorm":
                    found.add(a.name)
                    bound[a.asname or "chebnorm"] = a.name if a.asname else "chebnorm"
        elif isinstance(node, ast.ImportFrom) and not node.level and (node.module or "").split(".")[0] == "chebnorm":
            for a in node.names:
                found.add(f"{node.module}.{a.name}")
                bound[a.asname or a.name] = f"{node.module}.{a.name}"
    for node in ast.walk(tree):
        if isinstance(node, ast.Attribute):
            parts = []
            inner = node
            while isinstance(inner, ast.Attribute):
                parts.append(inner.attr)
                inner = inner.value
            if isinstance(inner, ast.Name) and inner.id in bound:
                found.add(".".join([bound[inner.id], *reversed(parts)]))
    return found


def _from_prose(text: str) -> set[str]:
    found = {m.group(0).replace("cn.", "chebnorm.", 1) if m.group(0).startswith("cn.") else m.group(0)
             for m in _DOTTED.finditer(text)}
    for module, names in _FROM.findall(text):
        for name in names.strip("()").replace("\n", " ").split(","):
            name = name.split(" as ")[0].strip()
            if name.isidentifier():
                found.add(f"{module}.{name}")
    return {name.rstrip(".") for name in found}


def _from_markdown(text: str) -> set[str]:
    found = set()
    for match in _FENCE.finditer(text):
        found |= _from_code(match.group(3))
    prose = _FENCE.sub("", text)
    prose = re.sub(r"https?://\S+", "", prose)
    return found | _from_prose(prose)


def names_used(path: Path) -> set[str]:
    """Every dotted name of the package that the file ``path`` uses."""
    text = path.read_text(encoding="utf-8")
    if path.suffix == ".py":
        return _from_code(text)
    if path.suffix == ".ipynb":
        found = set()
        for cell in json.loads(text)["cells"]:
            source = "".join(cell["source"])
            found |= _from_code(source) if cell["cell_type"] == "code" else _from_markdown(source)
        return found
    return _from_markdown(text)


def resolve(dotted: str):
    """The object ``dotted`` names, as Python finds it: attributes from :mod:`chebnorm`
    down (``chebnorm.raster.render`` is the function the stage exports), importing a
    submodule where the attribute is one not imported yet; else, as ``from ... import``
    and the manual's module paths read it, the longest module prefix that imports and
    attributes below it (``chebnorm.raster.render.Lighting``)."""
    parts = dotted.split(".")
    try:
        obj = importlib.import_module(parts[0])
        for part in parts[1:]:
            if hasattr(obj, part):
                obj = getattr(obj, part)
            elif inspect.ismodule(obj):
                obj = importlib.import_module(f"{obj.__name__}.{part}")
            else:
                raise AttributeError(f"{dotted}: no {part!r}")
        return obj
    except (ImportError, AttributeError) as exc:
        for i in range(len(parts) - 1, 1, -1):
            try:
                obj = importlib.import_module(".".join(parts[:i]))
            except ImportError:
                continue
            for part in parts[i:]:
                if not hasattr(obj, part):
                    raise exc
                obj = getattr(obj, part)
            return obj
        raise


def _user_names() -> dict[str, list[str]]:
    """Dotted name -> the files that use it."""
    where: dict[str, list[str]] = {}
    files = sorted({p for pattern in USER_FILES for p in ROOT.glob(pattern)})
    for path in files:
        for name in names_used(path):
            where.setdefault(name, []).append(str(path.relative_to(ROOT)))
    return dict(sorted(where.items()))


USER_NAMES = _user_names()


@pytest.mark.parametrize("dotted", sorted(USER_NAMES))
def test_every_name_users_read_resolves(dotted):
    try:
        resolve(dotted)
    except (ImportError, AttributeError) as exc:
        pytest.fail(f"{dotted} (used in {', '.join(USER_NAMES[dotted])}) does not resolve: {exc}")


def test_the_collection_reads_every_kind_of_file():
    """Names come from the README, the manual, the notebooks and the scripts, and
    they go below the facade (the stage names are what narrowing could break)."""
    sources = {f.split("/")[0] for files in USER_NAMES.values() for f in files}
    assert {"README.md", "docs", "notebooks", "paper_repro", "figures"} <= sources
    assert sum(name.count(".") >= 2 for name in USER_NAMES) > 20


def test_the_collection_and_resolution_can_fail():
    code = ("import chebnorm as cn\nimport chebnorm.hw as hw\nfrom chebnorm.approx import fit as f, Table\n"
            "from chebnorm import symbolic\nx = hw.design(cn.export.c_header, symbolic.eta_expr)\n")
    assert _from_code(code) == {
        "chebnorm", "chebnorm.hw", "chebnorm.approx.fit", "chebnorm.approx.Table", "chebnorm.symbolic",
        "chebnorm.hw.design", "chebnorm.export", "chebnorm.export.c_header", "chebnorm.symbolic.eta_expr"}
    text = ("Call ``cn.hw.design`` or `chebnorm.core.files`; see https://x.org/chebnorm.y.\n"
            'The JSON has `"kind": "chebnorm.piecewise_table"`.\n'
            "```python\n>>> from chebnorm.raster import (render,\n...     compare)\n```\n")
    assert _from_markdown(text) == {"chebnorm.hw.design", "chebnorm.core.files", "chebnorm.raster.render",
                                    "chebnorm.raster.compare"}
    assert resolve("chebnorm.core.files") is importlib.import_module("chebnorm.core.files")
    # the stage's function shadows its module: an import statement still finds the module
    assert resolve("chebnorm.raster.render") is chebnorm.raster.render
    assert resolve("chebnorm.raster.render.Lighting") is chebnorm.raster.Lighting
    for bad in ("chebnorm.hw.no_such_name", "chebnorm.no_such_stage", "chebnorm.fit.no_such_attribute",
                "chebnorm.raster.render.no_such_name"):
        with pytest.raises((ImportError, AttributeError)):
            resolve(bad)


# ------------------------------------------------------------------ names that left __all__
def _defined_public(mod) -> list[str]:
    return [n for n, v in vars(mod).items() if not n.startswith("_")
            and (inspect.isfunction(v) or inspect.isclass(v)) and v.__module__ == mod.__name__]


@pytest.mark.parametrize("modname", sorted(
    m.name for m in pkgutil.walk_packages(chebnorm.__path__, "chebnorm.")
    if not any(p.startswith("_") for p in m.name.split("."))))
def test_names_outside_all_keep_their_docstrings(modname):
    """A function or class without a leading ``_`` that left ``__all__`` is no longer held
    to full numpydoc (tests/test_docstrings.py), but it keeps a docstring."""
    mod = importlib.import_module(modname)
    bare = [n for n in _defined_public(mod) if not (inspect.getdoc(getattr(mod, n)) or "").strip()
            or (inspect.isclass(getattr(mod, n)) and inspect.getdoc(getattr(mod, n)).startswith(f"{n}("))]
    assert bare == [], f"{modname}: no docstring on {bare}"
