"""Build and run the C kernels of ``benchmarks/c`` (``kernels.h``, ``harness.c``).

:func:`build` writes the two fitted polynomials as C headers with
:func:`chebnorm.export.c.c_header` (``chebnorm_dichotomy_d2.h``,
``chebnorm_midpoint_d2.h``; nothing typed in by hand) and compiles the harness
with gcc or clang. :func:`evaluate` runs one kernel on spans and returns its outputs;
:func:`bench` times kernels side by side (interleaved rounds) and returns
nanoseconds per pixel per round.

Kernels (C name -> what it computes; ``PY_METHOD`` names the Python
``span_normals`` method it mirrors):

* ``classic`` linear then ``N / sqrtf(N.N)`` (3 div) -- the paper's classic, Python ``exact``;
* ``rsqrt_mul`` linear then ``1/sqrtf(N.N)`` and 3 mul (baseline);
* ``sse_rsqrt`` linear then ``_mm_rsqrt_ss`` + one Newton step (the hardware limit; x86 only);
* ``none``, ``newton``, ``lyon``, ``slerp``, ``dichotomy``, ``quadratic``, ``angular`` as in Python;
* ``angular_direct`` ``N_a cos(t psi) + N_k sin(t psi)`` per pixel (C8's reference; the slerp points);
* ``midpoint_classic`` / ``midpoint_poly``: the span midpoint alone, per span (C7, part 1);
* ``phong_n``, ``phong_nlh``, ``bump``: per-pixel shading, one float per pixel (C13);
* ``avx2_<name>``: explicit 8-lane AVX2 versions of classic, rsqrt + Newton, none, newton,
  lyon, quadratic and dichotomy (built where the compiler targets AVX2, see :data:`AVX2`);
* ``store_floor``: no kernel, a memset of the bytes the normal kernels store (the floor).

Used by ``benchmarks/run.py`` and ``tests/test_bench_kernels.py``; it is not a
library module (chebnorm never imports it).
"""

from __future__ import annotations

import os
import shutil
import subprocess
import tempfile
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
C_DIR = HERE / "c"

#: the timing configurations: the AVX2 kernels are built in the two native ones and
#: reported, from the no-errno build, as a fourth configuration "AVX2"
CONFIGS = {"O2": ["-O2"], "O3-native": ["-O3", "-march=native"],
           "O3-native-no-errno": ["-O3", "-march=native", "-fno-math-errno"]}
#: the build whose avx2_* kernels make the "AVX2" configuration
AVX2_BUILD = "O3-native-no-errno"
#: the compilers every configuration is built with (a compiler artifact must not settle a claim)
COMPILERS = ("gcc", "clang")
#: the strict flags of the smoke test
STRICT = ["-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic", "-O2"]

def method_kernels() -> dict:
    """C kernel -> the registered method it implements (the registry's ``c_kernel``)."""
    from chebnorm.methods import registered_methods

    return {m.c_kernel: m.name for m in registered_methods() if m.c_kernel}


#: the C kernels that are no registered method: baselines of the classic
#: normalization and the direct angular interpolation (C8), with the Python
#: method whose output each approximates
BASELINES = {"rsqrt_mul": "exact", "sse_rsqrt": "exact", "angular_direct": "slerp"}
_METHODS_C = method_kernels()
#: AVX2 kernel -> the scalar kernel it vectorizes (same method, same operations per pixel)
AVX2 = {"avx2_classic": "classic", "avx2_rsqrt_newton": "sse_rsqrt", "avx2_none": "none",
        "avx2_newton": "newton", "avx2_lyon": "lyon", "avx2_quadratic": "quadratic",
        "avx2_dichotomy": "dichotomy"}
#: C kernel -> Python span_normals method it mirrors (None: no Python twin)
PY_METHOD = {**_METHODS_C, **BASELINES, "midpoint_classic": None, "midpoint_poly": None,
             "phong_n": None, "phong_nlh": None, "bump": None, "store_floor": None}
PY_METHOD.update({k: PY_METHOD[v] for k, v in AVX2.items()})
#: the pseudo-kernel timing a memset of the normals' bytes
FLOOR = "store_floor"
#: kernels writing a unit-ish normal per pixel (accuracy is measured on these): the
#: classic one first, its baselines, the other methods' kernels, direct angular last
NORMAL_KERNELS = ("classic", "rsqrt_mul", "sse_rsqrt",
                  *[k for k in _METHODS_C if k != "classic"], "angular_direct")
AVX2_KERNELS = tuple(AVX2)
SHADING_KERNELS = ("phong_n", "phong_nlh", "bump")
MIDPOINT_KERNELS = ("midpoint_classic", "midpoint_poly")


class ToolMissing(RuntimeError):
    """A needed external tool (gcc) is not installed."""


def gcc() -> str:
    """Path of gcc (``$CC`` if set), or raise :class:`ToolMissing` with what to do."""
    return compiler("gcc")


def compiler(name="gcc") -> str:
    """Path of compiler ``name`` (``"gcc"`` honours ``$CC``), or raise
    :class:`ToolMissing` with what to do."""
    exe = os.environ.get("CC", "gcc") if name == "gcc" else name
    path = shutil.which(exe)
    if path is None:
        raise ToolMissing(f"{exe} not found on PATH: apt-get install {name} (or set CC) to build "
                          f"the C kernels with it; that part of the benchmark is skipped")
    return path


def tables(psi_max="pi/4"):
    """The degree-2 tables the C kernels use, by target name (``span_normals``'
    defaults, :func:`chebnorm.methods.default_tables`, for ``psi_max``)."""
    from chebnorm.methods import default_tables, table_methods

    specs = table_methods()
    return {specs[m].target: t for m, t in default_tables(psi_max=psi_max).items()}


def write_headers(directory: Path, psi_max="pi/4") -> list[Path]:
    """Export the tables as C headers into ``directory`` with chebnorm's printer."""
    from chebnorm.export.c import c_header

    out = []
    for t in tables(psi_max).values():
        p = Path(directory) / f"chebnorm_{t.name}.h"
        p.write_text(c_header(t, command=f"benchmarks/ckernels.py (psi_max={psi_max})"))
        out.append(p)
    return out


def build(build_dir, flags, *, psi_max="pi/4", name="harness", cc="gcc") -> dict:
    """Write the headers and compile the harness with ``cc flags`` (``cc``: gcc or clang).

    Returns ``{"binary": Path, "command": str, "vectorized": [...], "gcc": version,
    "compiler": name, "version": version}`` (``"gcc"`` holds the version of whichever
    compiler built it, kept for readers of older results); ``vectorized`` lists the
    kernel source lines the compiler reports as loop-vectorized (gcc
    ``-fopt-info-vec-optimized``, clang ``-Rpass=loop-vectorize``), also written to
    ``<name>.vec.txt``. Raises :class:`ToolMissing` without the compiler and
    ``RuntimeError`` with its message when compilation fails."""
    exe = compiler(cc)
    build_dir = Path(build_dir)
    build_dir.mkdir(parents=True, exist_ok=True)
    write_headers(build_dir, psi_max)
    binary = build_dir / name
    cmd = [exe, *flags, f"-I{build_dir}", f"-I{C_DIR}", str(C_DIR / "harness.c"), "-o",
           str(binary), "-lm"]
    info = build_dir / f"{name}.vec.txt"
    is_clang = "clang" in Path(exe).name
    extra = ["-Rpass=loop-vectorize"] if is_clang else [f"-fopt-info-vec-optimized={info}"]
    res = subprocess.run(cmd + extra, capture_output=True, text=True)
    if res.returncode != 0:
        raise RuntimeError(f"{cc} failed ({' '.join(cmd)}):\n{res.stderr}")
    if is_clang:  # remarks "file:line:col: remark: vectorized loop ..." on stderr
        info.write_text("\n".join(line.replace("vectorized loop", "loop vectorized")
                                   for line in res.stderr.splitlines() if "vectorized loop" in line))
    vec = []
    if info.exists():
        vec = sorted({line.split(": ")[0].rsplit("/", 1)[-1] for line in info.read_text().splitlines()
                      if "vectorized" in line and "kernels.h" in line})
    flag = "--version" if is_clang else "-dumpfullversion"
    version = subprocess.run([exe, flag], capture_output=True, text=True).stdout.strip()
    version = version.splitlines()[0] if version else ""
    return {"binary": binary, "command": " ".join([Path(exe).name, *flags, "harness.c", "-lm"]),
            "vectorized": vec, "gcc": version, "compiler": cc, "version": version}


def kernel_names(binary) -> list[str]:
    out = subprocess.run([str(binary), "list"], capture_output=True, text=True, check=True).stdout
    return [line.split()[0] for line in out.splitlines() if line.strip()]


def write_spans(path, nl, nr, t0, dt, count) -> None:
    """The harness's span file: int64 S, S x 8 float32 (nl, nr, t0, dt), S int32 counts."""
    nl = np.asarray(nl, np.float32).reshape(-1, 3)
    nr = np.asarray(nr, np.float32).reshape(-1, 3)
    s = len(nl)
    rec = np.empty((s, 8), np.float32)
    rec[:, 0:3], rec[:, 3:6] = nl, nr
    rec[:, 6] = np.broadcast_to(np.asarray(t0, np.float32), (s,))
    rec[:, 7] = np.broadcast_to(np.asarray(dt, np.float32), (s,))
    cnt = np.broadcast_to(np.asarray(count, np.int32), (s,)).astype(np.int32)
    with open(path, "wb") as fh:
        fh.write(np.int64(s).tobytes())
        fh.write(rec.tobytes())
        fh.write(cnt.tobytes())


def evaluate(binary, kernel, nl, nr, t0, dt, count, width=3, per_span=False) -> np.ndarray:
    """Run ``kernel`` on the spans; returns (P, width) float32 (P = sum of counts,
    or S for the per-span midpoint kernels)."""
    with tempfile.TemporaryDirectory() as tmp:
        spans, out = Path(tmp) / "spans.bin", Path(tmp) / "out.bin"
        write_spans(spans, nl, nr, t0, dt, count)
        res = subprocess.run([str(binary), "eval", kernel, str(spans), str(out)],
                             capture_output=True, text=True)
        if res.returncode != 0:
            raise RuntimeError(f"harness eval {kernel} failed: {res.stderr.strip()}")
        return np.fromfile(out, np.float32).reshape(-1, width)


def bench(binary, spans_file, kernels, *, reps=15, warmup=2, target_ms=50.0) -> dict:
    """Time ``kernels`` side by side over the span file, each in windows of about
    ``target_ms`` of CPU time.

    Returns ``{"passes": n, "pixels": P, "floor_bytes": B, "ns": {kernel: [ns per pixel
    (or per span for the midpoint kernels), thread CPU time, one per round]},
    "wall_ns": {kernel: [the same, wall-clock]}}``."""
    res = subprocess.run([str(binary), "bench", str(spans_file), str(reps), str(warmup),
                          str(target_ms), *kernels], capture_output=True, text=True)
    if res.returncode != 0:
        raise RuntimeError(f"harness bench failed: {res.stderr.strip()}")
    ns: dict[str, list[float]] = {k: [] for k in kernels}
    wall: dict[str, list[float]] = {k: [] for k in kernels}
    head = {}
    for line in res.stdout.splitlines():
        parts = line.split()
        if parts and parts[0] == "time":
            ns[parts[2]].append(float(parts[3]) / float(parts[5]))
            wall[parts[2]].append(float(parts[4]) / float(parts[5]))
        elif parts and parts[0] == "spans":
            head = {"spans": int(parts[1]), "pixels": int(parts[3]), "passes": int(parts[5]),
                    "floor_bytes": int(parts[7])}
    return {**head, "ns": ns, "wall_ns": wall}
