"""Run the exported shader functions on a real driver, and validate them.

Three checks of the text :mod:`chebnorm.export.shader` prints, each through
an external tool that is optional (the functions raise
:class:`ToolMissing`, a :class:`RuntimeError`, naming what to install):

* :func:`glslang_validate` -- ``glslangValidator`` (Debian ``glslang-tools``)
  compiles a GLSL 4.30 or ES 3.10 compute shader around the function, or the
  HLSL one through glslang's HLSL front end (``-D``);
* :func:`glsl_evaluate` -- the GLSL function in an OpenGL 4.3 compute shader
  through ``moderngl`` on a headless EGL context (Mesa's llvmpipe here);
* :func:`wgsl_evaluate` -- the WGSL function in a compute pipeline through
  ``wgpu`` (which validates the module with naga first; Mesa's lavapipe
  here).

The evaluators return float32 arrays: the driver's values, bit for bit.
:func:`float32_inputs` picks the inputs: every float32 of the table's
interval, or ``2^20`` of them evenly spread when there are more.
"""

from __future__ import annotations

import tempfile
from pathlib import Path

import numpy as np

from chebnorm.approx import CoefficientTable
from chebnorm.core.textsafe import identifier
from chebnorm.exceptions import ToolMissing

from .shader import interval32, shader_source
from chebnorm.core.tools import require, run_tool

# an implementation module of chebnorm.export: the API is what chebnorm.export exports
__all__: list[str] = []

#: The most inputs :func:`float32_inputs` returns by default (and the batch size
#: of :func:`glsl_runner`): ``2**20``.
MAX_SAMPLES = 2 ** 20
_GROUP = 64


def float32_inputs(table: CoefficientTable, max_samples: int = MAX_SAMPLES) -> np.ndarray:
    """Every float32 in the table's interval (rounded inward), sorted; when
    there are more than ``max_samples``, that many, taken evenly from the
    union of ``max_samples`` evenly spaced in value and ``max_samples`` evenly
    spaced in float32 order (which reaches the tiny magnitudes near a zero
    endpoint), both ends kept.

    Parameters
    ----------
    table : CoefficientTable
        The table; its interval is rounded inward to float32
        (:func:`chebnorm.export.shader.interval32`).
    max_samples : int, optional
        The most inputs returned, ``>= 2``. Default :data:`MAX_SAMPLES`
        (``2**20``).

    Returns
    -------
    numpy.ndarray
        A sorted float32 array of distinct inputs, every one in the table's
        interval, at most ``max_samples`` of them.

    Examples
    --------
    >>> from chebnorm.approx import fit
    >>> t = fit("1/x", ("1", "1 + 2**-20"), 1)
    >>> float32_inputs(t).size  # 2^-20 / 2^-23 steps, both ends
    9
    """
    lo, hi = interval32(table)
    a = _ordered(np.float32(lo))
    b = _ordered(np.float32(hi))
    if b - a + 1 <= max_samples:
        return _from_ordered(np.arange(a, b + 1, dtype=np.int64))
    by_order = _from_ordered(np.round(np.linspace(a, b, max_samples)).astype(np.int64))
    by_value = np.clip(np.linspace(lo, hi, max_samples).astype(np.float32),
                       np.float32(lo), np.float32(hi))
    both = np.unique(np.concatenate([by_order, by_value]))
    pick = np.round(np.linspace(0, both.size - 1, max_samples)).astype(np.int64)
    return both[np.unique(pick)]


def _ordered(f: np.float32) -> int:
    """Integer key monotone in the float32 value (sign-magnitude to two's complement)."""
    bits = int(np.array(f, dtype=np.float32).view(np.int32))
    return bits if bits >= 0 else -(bits & 0x7FFFFFFF)


def _from_ordered(keys: np.ndarray) -> np.ndarray:
    keys = np.asarray(keys, dtype=np.int64)
    bits = np.where(keys >= 0, keys, (-keys) | 0x80000000).astype(np.uint32)
    return bits.view(np.float32)


#: per language: the buffers before the exported function and the entry point
#: after it (``$FN``: the function's name, ``$GROUP``: the work-group size)
_KERNELS = {
    "glsl": (["layout(local_size_x = $GROUP) in;",
              "layout(std430, binding = 0) readonly buffer Xs { float xs[]; };",
              "layout(std430, binding = 1) writeonly buffer Ys { float ys[]; };"],
             ["void main()", "{",
              "    uint i = gl_GlobalInvocationID.x;",
              "    if (i < uint(xs.length())) ys[i] = $FN(xs[i]);",
              "}"]),
    "wgsl": (["@group(0) @binding(0) var<storage, read> xs: array<f32>;",
              "@group(0) @binding(1) var<storage, read_write> ys: array<f32>;"],
             ["@compute @workgroup_size($GROUP)",
              "fn main(@builtin(global_invocation_id) id: vec3<u32>) {",
              "    let i = id.x;",
              "    if (i < arrayLength(&xs)) { ys[i] = $FN(xs[i]); }",
              "}"]),
    "hlsl": (["StructuredBuffer<float> xs : register(t0);",
              "RWStructuredBuffer<float> ys : register(u0);"],
             ["[numthreads($GROUP, 1, 1)]",
              "void main(uint3 id : SV_DispatchThreadID)",
              "{",
              "    ys[id.x] = $FN(xs[id.x]);",
              "}"]),
}


def compute_shader_source(table: CoefficientTable, language: str, *, es: bool = False) -> str:
    """A compute shader that maps ``xs[i]`` to ``ys[i] = chebnorm_NAME(xs[i])``
    around the exported function (GLSL 4.30, or ES 3.10 with ``es``; WGSL; HLSL).

    Parameters
    ----------
    table : CoefficientTable
        A table the shader exporters accept (plain powers of ``x``, an
        identifier for a name).
    language : {"glsl", "wgsl", "hlsl"}
        The shading language.
    es : bool, optional
        For GLSL: ``#version 310 es`` with ``precision highp float``
        instead of ``#version 430``. Default False.

    Returns
    -------
    str
        The compute shader's source: buffer ``xs`` (binding 0) in, ``ys``
        (binding 1) out, 64 invocations per work group.

    Raises
    ------
    ValueError
        As :func:`chebnorm.export.shader.shader_source`: an unknown
        language or a table it refuses.

    Examples
    --------
    >>> from chebnorm.approx import fit_target
    >>> src = compute_shader_source(fit_target("dichotomy", 1), "wgsl")
    >>> print(src.splitlines()[-2])
        if (i < arrayLength(&xs)) { ys[i] = chebnorm_dichotomy_d1(xs[i]); }
    >>> compute_shader_source(fit_target("dichotomy", 1), "glsl", es=True).splitlines()[0]
    '#version 310 es'
    """
    fn = f"chebnorm_{identifier(table.name, field='table.name')}"
    return compute_shader_around(shader_source(table, language), fn, language, es=es)


def compute_shader_around(body: str, fn: str, language: str, *, es: bool = False) -> str:
    """The compute shader of :func:`compute_shader_source` around a given
    function text ``body`` defining ``fn`` (e.g. an exported file as shipped).

    Parameters
    ----------
    body : str
        Shader text that defines a function ``fn`` taking and returning one
        32-bit float; inserted verbatim.
    fn : str
        The function's name, called once per input.
    language : {"glsl", "wgsl", "hlsl"}
        The language of ``body``.
    es : bool, optional
        For GLSL: ``#version 310 es`` instead of ``#version 430``. Default
        False.

    Returns
    -------
    str
        The compute shader's source.

    Raises
    ------
    ValueError
        When ``language`` is not one of the three.

    Examples
    --------
    >>> src = compute_shader_around("float f(float x) { return x; }", "f", "glsl")
    >>> src.splitlines()[0], "ys[i] = f(xs[i]);" in src
    ('#version 430', True)
    """
    if language not in _KERNELS:
        raise ValueError(f"unknown shader language {language!r}; accepted: glsl, wgsl, hlsl")
    head = (["#version 310 es", "precision highp float;"] if es else ["#version 430"]) \
        if language == "glsl" else []
    buffers, main = ([line.replace("$FN", fn).replace("$GROUP", str(_GROUP)) for line in part]
                     for part in _KERNELS[language])
    return "\n".join(head + buffers + ["", body] + main + [""])


def glslang_validate(source: str, language: str, timeout: float = 120) -> str:
    """Compile a compute shader with ``glslangValidator``; returns its output,
    raises :class:`ValueError` with the messages when it does not compile.

    Parameters
    ----------
    source : str
        The compute shader (:func:`compute_shader_source`).
    language : {"glsl", "hlsl"}
        GLSL (``shader.comp``) or HLSL (glslang's HLSL front end, ``-D``,
        entry point ``main``, compiled to SPIR-V).
    timeout : float, optional
        Seconds before the compiler is stopped
        (:class:`chebnorm.exceptions.ToolTimeout`, a ``ValueError``).
        Default 120.

    Returns
    -------
    str
        The compiler's standard output.

    Raises
    ------
    ToolMissing
        When ``glslangValidator`` is not on ``PATH``.
    ValueError
        When ``language`` is neither glsl nor hlsl, or the shader does not
        compile (the messages, up to 600 characters).
    """
    exe = require("glslangValidator", "the shader check")
    if language not in ("glsl", "hlsl"):
        raise ValueError(f"glslangValidator checks glsl or hlsl, not {language!r}")
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / ("shader.comp" if language == "glsl" else "shader.hlsl")
        path.write_text(source, encoding="utf-8")
        cmd = [exe, str(path)] if language == "glsl" else \
            [exe, "-D", "-e", "main", "-S", "comp", "-V", "-o", str(Path(tmp) / "cs.spv"),
             str(path)]
        proc = run_tool(cmd, tool="glslangValidator", timeout=timeout)
    if proc.returncode != 0:
        raise ValueError(f"glslangValidator rejected the {language} shader: "
                         f"{' '.join((proc.stdout + proc.stderr).split())[:600]}")
    return proc.stdout


_CONTEXT = None


def gl_context():
    """A shared headless OpenGL 4.3+ context (moderngl, EGL).

    Created on the first call and reused by every later one.

    Returns
    -------
    moderngl.Context
        The standalone EGL context (Mesa's llvmpipe here).

    Raises
    ------
    ToolMissing
        When ``moderngl`` is not installed or no OpenGL 4.3 context can be
        created.
    """
    global _CONTEXT
    if _CONTEXT is None:
        try:
            import moderngl
        except ImportError as exc:
            raise ToolMissing("moderngl is not installed; accepted: pip install "
                              "'chebnorm[gpu]'") from exc
        try:
            _CONTEXT = moderngl.create_standalone_context(backend="egl", require=430)
        except Exception as exc:  # the driver's own error types
            raise ToolMissing(f"no headless OpenGL 4.3 context ({exc}); accepted: Mesa's "
                              f"EGL and llvmpipe (apt-get install libegl-mesa0 "
                              f"libgl1-mesa-dri)") from exc
    return _CONTEXT


def _inputs(xs) -> tuple[np.ndarray, int]:
    """``xs`` as contiguous float32, and the work groups that cover it."""
    x = np.ascontiguousarray(xs, dtype=np.float32)
    return x, -(-x.size // _GROUP)


def _outputs(raw: bytes, count: int) -> np.ndarray:
    """The first ``count`` float32 of a read-back buffer, as an owned array."""
    return np.frombuffer(raw, dtype=np.float32)[:count].copy()


def glsl_evaluate(table: CoefficientTable, xs) -> np.ndarray:
    """``chebnorm_NAME(x)`` for each float32 ``x`` of ``xs``, computed by the
    exported GLSL in an OpenGL compute shader.

    Parameters
    ----------
    table : CoefficientTable
        A table the shader exporters accept.
    xs : array_like
        The inputs, converted to float32 (any length; in the table's
        interval for the stated bound to apply).

    Returns
    -------
    numpy.ndarray
        The driver's float32 results, bit for bit, one per input.

    Raises
    ------
    ToolMissing
        When no OpenGL 4.3 context is available (:func:`gl_context`).
    ValueError
        When the table cannot be exported to GLSL.
    """
    ctx = gl_context()
    x, groups = _inputs(xs)
    with ctx:  # make the EGL context current again (another API may have switched it)
        prog = ctx.compute_shader(compute_shader_source(table, "glsl"))
        bx = ctx.buffer(x.tobytes())
        by = ctx.buffer(reserve=max(x.nbytes, 4))
        try:
            bx.bind_to_storage_buffer(0)
            by.bind_to_storage_buffer(1)
            prog.run(group_x=groups)
            ctx.finish()
            return _outputs(by.read(), x.size)
        finally:
            bx.release()
            by.release()
            prog.release()


def glsl_runner(source: str, batch: int = MAX_SAMPLES):
    """A function ``run(xs) -> ys`` that evaluates the GLSL compute shader
    ``source`` (as :func:`compute_shader_around` prints it) on float32 inputs,
    compiled once and dispatched in batches of ``batch`` inputs (buffers
    reused), and a ``close()`` that releases the program and buffers.

    Parameters
    ----------
    source : str
        A GLSL compute shader reading ``xs`` (binding 0) and writing ``ys``
        (binding 1).
    batch : int, optional
        Inputs per dispatch, ``>= 1`` (the buffers hold ``4 * batch``
        bytes). Default :data:`MAX_SAMPLES`.

    Returns
    -------
    tuple of (callable, callable)
        ``run(xs) -> numpy.ndarray`` (float32 results, one per input) and
        ``close() -> None``.

    Raises
    ------
    ToolMissing
        When no OpenGL 4.3 context is available (:func:`gl_context`).
    """
    ctx = gl_context()
    batch = int(batch)
    with ctx:
        prog = ctx.compute_shader(source)
        bx = ctx.buffer(reserve=batch * 4)
        by = ctx.buffer(reserve=batch * 4)

    def run(xs) -> np.ndarray:
        x = np.ascontiguousarray(xs, dtype=np.float32)
        out = np.empty_like(x)
        with ctx:
            bx.bind_to_storage_buffer(0)
            by.bind_to_storage_buffer(1)
            for start in range(0, x.size, batch):
                part = x[start:start + batch]
                if part.size < batch:  # xs.length() must be the part's size
                    part = np.concatenate([part, np.full(batch - part.size, part[-1],
                                                         dtype=np.float32)])
                bx.write(part.tobytes())
                prog.run(group_x=-(-batch // _GROUP))
                ctx.finish()
                n = min(batch, x.size - start)
                out[start:start + n] = np.frombuffer(by.read(), dtype=np.float32)[:n]
        return out

    def close() -> None:
        with ctx:
            for obj in (bx, by, prog):
                obj.release()

    return run, close


def wgsl_evaluate(table: CoefficientTable, xs) -> np.ndarray:
    """As :func:`glsl_evaluate`, for the exported WGSL through ``wgpu``.

    Parameters
    ----------
    table : CoefficientTable
        A table the shader exporters accept.
    xs : array_like
        The inputs, converted to float32.

    Returns
    -------
    numpy.ndarray
        The driver's float32 results, bit for bit, one per input.

    Raises
    ------
    ToolMissing
        When ``wgpu`` is not installed or no WebGPU adapter is found.
    ValueError
        When the table cannot be exported to WGSL.
    """
    try:
        import wgpu
        from wgpu.utils.compute import compute_with_buffers
    except ImportError as exc:
        raise ToolMissing("wgpu is not installed; accepted: pip install 'chebnorm[gpu]'") from exc
    x, groups = _inputs(xs)
    try:
        wgpu.utils.get_default_device()
    except Exception as exc:  # the driver's own error types
        raise ToolMissing(f"no WebGPU adapter ({exc}); accepted: Mesa's lavapipe "
                          f"(apt-get install mesa-vulkan-drivers)") from exc
    out = compute_with_buffers({0: x}, {1: (x.size, "f")},
                               compute_shader_source(table, "wgsl"), n=(groups, 1, 1))
    return _outputs(out[1], x.size)
