"""Held-out benchmark: ``chebnorm design`` against FloPoCo built from its public source,
on specs that chebnorm's search was never tuned on.

    python benchmarks/bench_flopoco.py --flopoco-src DIR [--devices generic xc7-nodsp ...]
                                       [--spec exp log2 ...] [--tool chebnorm flopoco] [--force]
    python benchmarks/bench_flopoco.py --flopoco BINARY ...
    python benchmarks/bench_flopoco.py --markdown [--json FILE] [--write-docs]

For each spec of :data:`SPECS` (a function on an interval, 16-bit input code,
faithful output of a stated LSB -- FloPoCo's ``lsbOut``):

* FloPoCo: ``FixFunctionByPiecewisePoly`` with ``d=1, 2, 3``,
  ``FixFunctionByMultipartiteTable`` and ``FixFunctionByTable`` (only up to
  :data:`TABLE_BITS` ROM bits: 12-bit inputs), combinational (``frequency=1``: "Not pipelined"; ``plainVHDL=1``, which this FloPoCo
  requires for the Horner evaluator), the function in FloPoCo's
  terms (on [0, 1): ``1/x`` on [1, 2) is ``f="1/(1+x)"``). The VHDL is
  converted to Verilog by ``ghdl --synth --out=verilog`` (GHDL's own
  synthesis, ``-fsynopsys`` for FloPoCo's ``std_logic_arith``) after its
  tables are rewritten as constant arrays (:func:`rom_arrays`: GHDL turns a
  ``with ... select`` table into comparators that yosys does not see as a
  ROM), its products given their operands' widths again
  (:func:`narrow_products`) and flattened (:func:`flatten_verilog`), so both
  tools' designs go through the same yosys flows; the Icarus simulation of
  that Verilog must give the codes GHDL gives for FloPoCo's own VHDL
  (``same_codes_as_icarus``).
* chebnorm: ``chebnorm design EXPR --interval LO HI --in-bits 16 --out-bits N
  --faithful --target T`` for each device ``T``; the winner's Verilog is
  synthesized again here by the same flow as FloPoCo's. The LSB the winner
  chose (its banner, ``y: ... value = (c + k) / 2^F``) is compared with the
  spec's: a different LSB is recorded as ``lsb_match: false``, not hidden.

Every design of both tools is simulated by Icarus Verilog over every input
code (the Verilog that yosys synthesizes; FloPoCo's VHDL also in GHDL,
``sim_ghdl``) and compared with an mpmath reference (60 bits): ``errors`` counts the codes whose output is off by
>= 1 unit of the spec's LSB (faithful: 0), ``max_err_ulp`` is the largest
error in units of the spec's LSB.

Devices (:mod:`chebnorm.hw.targets`): ``generic`` (yosys cells), ``xc7``
(LUT + 264.2 per DSP48E1 score), ``xc7-nodsp`` (LUTs, no DSP) and ``ice40``:
the module between input and output registers (the same
``chebnorm.hw.targets.register_wrapper`` for both tools, so a ROM may go to
block RAM), ``synth_ice40`` then ``nextpnr-ice40 --hx8k --package ct256
--seed 1``: its ``ICESTORM_LC`` and ``ICESTORM_RAM`` counts and Fmax; the
ice40 score is ``LC + 240 * RAM`` (an HX8K has 7680 LCs and 32 RAM4K).

Output: ``benchmarks/flopoco_results.json`` (``--json``; sorted keys), written
after every design; a rerun skips what is there unless ``--force``.
``--markdown`` prints the docs table from the JSON (no run); ``--write-docs``
puts it into docs/flopoco.md (tests/test_bench_flopoco.py checks they agree).

Building FloPoCo (``--flopoco-src DIR``: a FloPoCo 4.1/5.0 source tree, e.g.
a clone of a GitHub mirror such as ``hyf6661669/FloPoCo`` at commit
``b786213b``): built by cmake into ``~/.cache/chebnorm/flopoco-<id>``
(``<id>``: the tree's ``SOURCE_COMMIT`` file or git commit, else a hash of
its CMakeLists.txt), reused when the binary is there. Build fixes are applied
to a copy of the tree, both outside the operators measured:
``src/ConstMult/tscm_solutions.cpp`` (a 2^21-entry table that only
``IntConstMultShiftAddOptTernary`` reads; absent from mirrors that drop
large blobs) is stubbed when missing, that operator's ``pagsuite``
includes are put under its own ``HAVE_PAGLIB`` guard, and two ScaLP-only
methods of ``TilingAndCompressionOptILP.cpp`` under ``HAVE_SCALP`` (PAGSuite,
WCPG and ScaLP are optional and not needed). Debian/Ubuntu packages::

    apt-get install cmake g++ flex bison libgmp-dev libmpfr-dev libmpfi-dev \\
        libsollya-dev libboost-dev libxml2-dev ghdl iverilog yosys nextpnr-ice40
"""

from __future__ import annotations

import argparse
import hashlib
import json
import os
import platform
import re
import shutil
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

HERE = Path(__file__).resolve().parent
DEFAULT_JSON = HERE / "flopoco_results.json"
DEVICES = ("generic", "xc7-nodsp", "xc7", "ice40")
FLOPOCO_DESIGNS = ("pp1", "pp2", "pp3", "multipartite", "table")
#: the VHDL -> Verilog steps of this version (a row of an older one is measured again)
CONVERSION = "ghdl-synth, tables as descending arrays, narrowed products, flattened"
#: the largest FixFunctionByTable built, in ROM bits (chebnorm design's plain-table
#: limit: a 16-bit table of 2^16 entries is not synthesized in useful time)
TABLE_BITS = 1 << 18
#: ice40 score: LUT equivalents of one RAM4K (HX8K: 7680 LCs, 32 RAM4K)
ICE40_RAM_LC = 7680 / 32


@dataclass(frozen=True)
class Spec:
    """One benchmark spec: ``f`` on ``[lo, hi)``, an ``in_bits`` input code,
    faithful output of LSB ``2^lsb_out``.

    ``expr`` is chebnorm's (sympy) expression of ``x``; ``flopoco_f`` is the
    same function in FloPoCo's (Sollya) syntax of ``x`` in [0, 1), where the
    code ``k`` stands for ``x = k / 2^in_bits``; ``mp`` names the mpmath
    reference of ``x`` on ``[lo, hi)`` (a key of :data:`REFERENCES`); ``out_bits`` is
    chebnorm's ``--out-bits``.
    """

    name: str
    expr: str
    lo: int
    hi: int
    in_bits: int
    lsb_out: int
    out_bits: int
    flopoco_f: str
    mp: str


#: the held-out specs; the last is FloPoCo's own example, the anchor
SPECS = (
    Spec("exp", "exp(x)", 0, 1, 16, -15, 16, "exp(x)", "exp"),
    Spec("log2", "log(1+x, 2)", 0, 1, 16, -16, 16, "log2(1+x)", "log2"),
    Spec("sin", "sin(pi/2*x)", 0, 1, 16, -16, 16, "sin(pi/2*x)", "sin"),
    Spec("exp2", "2**x", 0, 1, 16, -16, 16, "2^x", "exp2"),
    Spec("atan", "atan(x)", 0, 1, 16, -16, 16, "atan(x)", "atan"),
    Spec("recip", "1/x", 1, 2, 16, -16, 16, "1/(1+x)", "recip"),
    Spec("rsqrt3", "1/sqrt(1+3*x)", 0, 1, 16, -16, 16, "1/sqrt(1+3*x)", "rsqrt3"),
    Spec("exp2_12", "2**x", 0, 1, 12, -12, 12, "2^x", "exp2"),
    Spec("exp2_20", "2**x", 0, 1, 20, -20, 20, "2^x", "exp2"),
)
#: the mpmath references, ``(ctx, x) -> f(x)`` (a fixed table: no expression is evaluated)
REFERENCES = {
    "exp": lambda c, x: c.exp(x),
    "log2": lambda c, x: c.log(1 + x) / c.log(2),
    "sin": lambda c, x: c.sin(c.pi / 2 * x),
    "exp2": lambda c, x: c.power(2, x),
    "atan": lambda c, x: c.atan(x),
    "recip": lambda c, x: 1 / x,
    "rsqrt3": lambda c, x: 1 / c.sqrt(1 + 3 * x),
}
SPEC_BY_NAME = {s.name: s for s in SPECS}


def reference(spec: Spec, prec: int = 60) -> list:
    """``f(lo + (hi - lo) k / 2^in_bits)`` for every code ``k``, as mpmath numbers."""
    import mpmath

    ctx = mpmath.MPContext()
    ctx.prec = prec
    fn = REFERENCES[spec.mp]
    n = 1 << spec.in_bits
    return [fn(ctx, ctx.mpf(spec.lo) + ctx.mpf(spec.hi - spec.lo) * k / n) for k in range(n)]


def count_errors(spec: Spec, codes, value_of) -> dict:
    """Codes off by >= 1 unit of ``2^lsb_out`` from the reference; ``value_of(c)``
    maps an output code to its value (an exact rational as a Fraction)."""
    import mpmath

    ref = reference(spec)
    ulp = mpmath.mpf(2) ** spec.lsb_out
    worst, bad = mpmath.mpf(0), 0
    for k, c in enumerate(codes):
        if c is None:
            bad += 1
            continue
        v = value_of(c)
        e = abs(mpmath.mpf(v.numerator) / v.denominator - ref[k]) / ulp
        if e >= 1:
            bad += 1
        worst = max(worst, e)
    return {"codes": len(codes), "errors": bad, "max_err_ulp": round(float(worst), 4)}


# ----------------------------------------------------------------------------- tools

def _run(argv, cwd=None, timeout=3600, env=None) -> subprocess.CompletedProcess:
    return subprocess.run(argv, cwd=cwd, capture_output=True, text=True, timeout=timeout,
                          stdin=subprocess.DEVNULL, env=env)


def tool_versions() -> dict:
    """First version line of each external tool used."""
    out = {}
    for name, argv in (("yosys", ["yosys", "-V"]), ("ghdl", ["ghdl", "--version"]),
                       ("iverilog", ["iverilog", "-V"]),
                       ("nextpnr-ice40", ["nextpnr-ice40", "--version"])):
        try:
            p = _run(argv, timeout=60)
            text = (p.stdout or p.stderr).strip().splitlines()
            out[name] = text[0] if text else "?"
        except (OSError, subprocess.SubprocessError):
            out[name] = "missing"
    return out


def _source_id(src: Path) -> str:
    f = src / "SOURCE_COMMIT"
    if f.exists():
        return f.read_text().strip()[:40]
    try:
        p = _run(["git", "-C", str(src), "rev-parse", "HEAD"], timeout=60)
        if p.returncode == 0:
            return p.stdout.strip()
    except OSError:
        pass
    return "cm" + hashlib.sha256((src / "CMakeLists.txt").read_bytes()).hexdigest()[:12]


def _patch_tree(tree: Path) -> list[str]:
    """The two build fixes of the module docstring; returns what was done."""
    done = []
    tscm = tree / "src" / "ConstMult" / "tscm_solutions.cpp"
    if (tscm.parent / "tscm_solutions.hpp").exists() and \
            (not tscm.exists() or tscm.stat().st_size == 0):
        tscm.write_text("// stub: the table of IntConstMultShiftAddOptTernary only (absent "
                        "from the mirror)\n#include \"tscm_solutions.hpp\"\n"
                        "int nofs[2097152][2] = {};\n")
        done.append("stubbed src/ConstMult/tscm_solutions.cpp")
    tern = tree / "src" / "ConstMult" / "IntConstMultShiftAddOptTernary.cpp"
    if tern.exists():
        s = tern.read_text()
        guard = "#if defined(HAVE_PAGLIB) && defined(HAVE_OSCM)\n"
        m = re.search(r'(?:#include "pagsuite/[^"]+"\s*\n\s*)+', s)
        if m and not s[:m.start()].endswith(guard):
            s = s[:m.start()] + guard + m.group(0) + "#endif\n" + s[m.end():]
            tern.write_text(s)
            done.append("guarded pagsuite includes of IntConstMultShiftAddOptTernary.cpp")
    ilp = tree / "src" / "IntMult" / "TilingAndCompressionOptILP.cpp"
    if ilp.exists():
        s = ilp.read_text()
        for sig in ("void TilingAndCompressionOptILP::parseTilingSolution(",
                    "void TilingAndCompressionOptILP::writeSolutionFile(ScaLP::"):
            i = s.find(sig)
            if i < 0 or s[:i].rstrip(" ").endswith("#ifdef HAVE_SCALP\n"):
                continue
            i = s.rfind("\n", 0, i) + 1
            j = s.find("\n    }\n", i)
            if j < 0:
                continue
            j += len("\n    }\n")
            s = s[:i] + "#ifdef HAVE_SCALP\n" + s[i:j] + "#endif\n" + s[j:]
            done.append(f"guarded {sig.split('::')[1].split('(')[0]} of "
                        f"TilingAndCompressionOptILP.cpp (ScaLP only)")
        ilp.write_text(s)
    return done


def build_flopoco(src: Path, cache: Path | None = None, jobs: int = 2) -> tuple[Path, dict]:
    """Build (or reuse) FloPoCo from source tree ``src``; returns the binary and
    ``{"source_id", "patches", "build_s"}``."""
    src = src.resolve()
    sid = _source_id(src)
    cache = cache or Path.home() / ".cache" / "chebnorm" / f"flopoco-{sid[:12]}"
    binary = cache / "build" / "flopoco"
    info = {"source_id": sid, "cache": str(cache)}
    if binary.exists():
        meta = cache / "build_info.json"
        if meta.exists():
            info.update(json.loads(meta.read_text()))
        return binary, info
    tree = cache / "src"
    if tree.exists():
        shutil.rmtree(tree)
    shutil.copytree(src, tree, symlinks=True)
    info["patches"] = _patch_tree(tree)
    build = cache / "build"
    build.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    for argv in (["nice", "-n", "10", "cmake", str(tree)],
                 ["nice", "-n", "10", "make", f"-j{jobs}", "flopoco"]):
        p = _run(argv, cwd=build, timeout=4 * 3600)
        if p.returncode != 0:
            raise SystemExit(f"FloPoCo build failed ({' '.join(argv[3:])}): "
                             f"{(p.stdout + p.stderr).strip().splitlines()[-5:]}")
    info["build_s"] = round(time.perf_counter() - t0, 1)
    (cache / "build_info.json").write_text(json.dumps(info, sort_keys=True))
    return binary, info


# ----------------------------------------------------------------------------- FloPoCo

def flopoco_argv(spec: Spec, design: str, name: str) -> list[str]:
    """FloPoCo's command line (after the binary) for one design of ``spec``."""
    if design not in FLOPOCO_DESIGNS:
        raise ValueError(f"design {design!r}; accepted: {', '.join(FLOPOCO_DESIGNS)}")
    common = [f"f={spec.flopoco_f}", f"lsbIn={-spec.in_bits}", f"lsbOut={spec.lsb_out}"]
    if design.startswith("pp"):
        op = ["FixFunctionByPiecewisePoly", *common, f"d={design[2:]}"]
    elif design == "multipartite":
        op = ["FixFunctionByMultipartiteTable", *common, "signedIn=false"]
    else:
        op = ["FixFunctionByTable", *common, "signedIn=false"]
    return ["frequency=1", "plainVHDL=1", f"name={name}", f"outputFile={name}.vhdl", *op]


_WITH = re.compile(r'with\s+(\w+)\s+select\s+(\w+)\s*<=\s*\n'
                   r'((?:\s*"[01]+"\s+when\s+"[01]+",\s*\n)+)'
                   r'\s*"[-01]+"\s+when\s+others\s*;')


def rom_arrays(vhdl: str) -> tuple[str, int]:
    """FloPoCo's tables (``with X select Y0 <= "..." when "...", ...``) rewritten
    as a constant array read ``Y0 <= ROM(conv_integer(X))``, the same values.

    GHDL's synthesis turns a ``with ... select`` of 2^k constants into 2^k
    comparators and a one-hot multiplexer, which yosys does not recognise as a
    ROM (FloPoCo's 256 x 31 exp table: 4641 generic cells, against 882 for
    the same table as a Verilog ``case``); an indexed constant array comes
    out as a ROM, as chebnorm's ``case`` tables do. The range is descending:
    GHDL stores an ascending one reversed and reads it at ``2^k - 1 - X``, a
    subtraction between the input register and the ROM that keeps yosys from
    putting the ROM in block RAM (ice40). Returns the text and the
    number of tables rewritten (an address missing from a table reads 0,
    FloPoCo's ``others`` being a don't-care).
    """
    out, n, pos = [], 0, 0
    for m in _WITH.finditer(vhdl):
        addr, dst, body = m.group(1), m.group(2), m.group(3)
        rows = re.findall(r'"([01]+)"\s+when\s+"([01]+)"', body)
        aw, dw = len(rows[0][1]), len(rows[0][0])
        # the architecture's declarative part: the last "begin" before the table
        b = vhdl.rfind("\nbegin", pos, m.start())
        if b < 0:
            continue
        n += 1
        name = f"rom_{n}"
        items = ",\n".join(f'  {int(a, 2)} => "{d}"' for d, a in rows)
        decl = (f"\ntype {name}_t is array({2 ** aw - 1} downto 0) of std_logic_vector({dw - 1} "
                f"downto 0);\nconstant {name} : {name}_t := (\n{items},\n  others => "
                f"(others => '0'));")
        out.append(vhdl[pos:b] + decl + vhdl[b:m.start()])
        out.append(f"{dst} <= {name}(conv_integer({addr}));")
        pos = m.end()
    out.append(vhdl[pos:])
    return "".join(out), n


_SEXT = re.compile(r"assign (\w+) = \{(?:\{\d+\{(\w+)\[\d+\]\}\}|(\w+)\[\d+\]), (\w+)\}; // sext")
_UEXT = re.compile(r"assign (\w+) = \{\d+'b0+, (\w+)\}; // uext")
_MUL = re.compile(r"assign (\w+) = (\w+) \* (\w+); // ([su])mul")


def narrow_products(verilog: str) -> tuple[str, int]:
    """GHDL's Verilog of a VHDL ``signed``/``unsigned`` product: both operands
    sign- (zero-) extended to the product's width, then an unsigned ``*`` of
    that width, which yosys cannot narrow (FloPoCo's 8 x 10-bit signed product
    becomes an 18 x 18 one). Rewritten as ``$signed(a) * $signed(b)`` (or
    ``a * b``) of the operands before extension: the same value in the
    product's width (Verilog extends signed operands of a signed product by
    their sign). Returns the text and the number of products rewritten."""
    ext = {}
    for m in _SEXT.finditer(verilog):
        src = m.group(4)
        if (m.group(2) or m.group(3)) == src:
            ext[m.group(1)] = ("s", src)
    for m in _UEXT.finditer(verilog):
        ext[m.group(1)] = ("u", m.group(2))
    n = 0

    def repl(m):
        nonlocal n
        a, b, kind = ext.get(m.group(2)), ext.get(m.group(3)), m.group(4)
        if not a or not b or a[0] != kind or b[0] != kind:
            return m.group(0)
        n += 1
        if kind == "s":
            return f"assign {m.group(1)} = $signed({a[1]}) * $signed({b[1]}); // smul"
        return f"assign {m.group(1)} = {a[1]} * {b[1]}; // umul"

    return _MUL.sub(repl, verilog), n


def vhdl_to_verilog(vhdl: Path, top: str, workdir: Path) -> str:
    """GHDL's synthesis of entity ``top`` printed as Verilog."""
    flags = ["-fsynopsys", "--std=08", f"--workdir={workdir}"]
    p = _run(["ghdl", "-a", *flags, str(vhdl)], cwd=workdir, timeout=1800)
    if p.returncode != 0:
        flags[1] = "--std=93c"
        p = _run(["ghdl", "-a", *flags, str(vhdl)], cwd=workdir, timeout=1800)
    if p.returncode != 0:
        raise RuntimeError("ghdl -a: " + " | ".join(p.stderr.strip().splitlines()[:3]))
    p = _run(["ghdl", "--synth", *flags, "--out=verilog", top], cwd=workdir, timeout=3600)
    if p.returncode != 0:
        raise RuntimeError("ghdl --synth: " + " | ".join(p.stderr.strip().splitlines()[:3]))
    return p.stdout


def flopoco_design(binary: Path, spec: Spec, design: str, workdir: Path) -> dict:
    """Generate one FloPoCo design; returns its Verilog, top, widths and log lines."""
    name = f"flo_{spec.name}_{design}"
    t0 = time.perf_counter()
    p = _run([str(binary), *flopoco_argv(spec, design, name)], cwd=workdir, timeout=3600)
    gen = round(time.perf_counter() - t0, 2)
    vhdl = workdir / f"{name}.vhdl"
    if p.returncode != 0 or not vhdl.exists():
        raise RuntimeError("flopoco: " + " | ".join((p.stdout + p.stderr).strip()
                                                    .splitlines()[-3:]))
    text, tables = rom_arrays(vhdl.read_text())
    rom = workdir / f"{name}_rom.vhdl"
    rom.write_text(text)
    conv = workdir / "ghdl"
    conv.mkdir()
    verilog, products = narrow_products(vhdl_to_verilog(rom, name, conv))
    verilog = flatten_verilog(verilog, name, conv)
    return {"verilog": verilog, "top": name, "gen_s": gen, "tables_as_arrays": tables,
            "products_narrowed": products,
            "command": "flopoco " + " ".join(flopoco_argv(spec, design, name)),
            "log": [ln for ln in (p.stdout + p.stderr).splitlines()
                    if "error" in ln.lower() or "msbOut" in ln or "degree" in ln.lower()][:6]}


def flatten_verilog(verilog: str, top: str, workdir: Path) -> str:
    """One module ``top`` of a design of several (yosys ``hierarchy; proc; flatten``,
    written back as Verilog): yosys' generic ``synth`` counts the top module's
    own cells only, so a hierarchical design (FloPoCo's: table, evaluator and
    top) is flattened first; a single-module design is returned unchanged."""
    if len(re.findall(r"^\s*module\s", verilog, re.M)) <= 1:
        return verilog
    (workdir / "hier.v").write_text(verilog)
    p = _run(["yosys", "-q", "-p", f"read_verilog hier.v; hierarchy -top {top}; proc; flatten; "
              f"opt_clean; write_verilog -noattr flat.v"], cwd=workdir, timeout=1800)
    if p.returncode != 0:
        raise RuntimeError("yosys flatten: " + p.stderr.strip()[-300:])
    return (workdir / "flat.v").read_text()


# ----------------------------------------------------------------------------- simulation

def simulate(verilog: str, top: str, in_bits: int, workdir: Path) -> tuple[list, int]:
    """Icarus Verilog over every input code: the output codes (None for x/z) and
    the output width. The module's first input of width ``in_bits`` is driven,
    a 1-bit ``clk``/``rst`` input held at 0."""
    from chebnorm.hw.targets import module_ports

    ports = module_ports(verilog, top)
    ins = [(n, w) for n, d, w in ports if d == "input"]
    outs = [(n, w) for n, d, w in ports if d == "output"]
    data = [n for n, w in ins if w == in_bits]
    if len(data) != 1 or len(outs) != 1:
        raise RuntimeError(f"ports of {top}: {ports}; expected one {in_bits}-bit input and "
                           f"one output")
    wo = outs[0][1]
    conns = [f".{n}({'x' if n == data[0] else '1' + chr(39) + 'b0'})" for n, _ in ins]
    conns.append(f".{outs[0][0]}(y)")
    tb = (f"module tb;\n  reg [{in_bits - 1}:0] x; wire [{wo - 1}:0] y; integer k, fd;\n"
          f"  {top} dut ({', '.join(conns)});\n"
          f"  initial begin\n    fd = $fopen(\"out.txt\", \"w\");\n"
          f"    for (k = 0; k < {1 << in_bits}; k = k + 1) begin\n"
          f"      x = k; #1; $fdisplay(fd, \"%b\", y);\n    end\n"
          f"    $fclose(fd); $finish;\n  end\nendmodule\n")
    (workdir / "dut.v").write_text(verilog)
    (workdir / "tb.v").write_text(tb)
    p = _run(["iverilog", "-g2012", "-o", "sim", "-s", "tb", "dut.v", "tb.v"], cwd=workdir,
             timeout=1800)
    if p.returncode != 0:
        raise RuntimeError("iverilog: " + " | ".join(p.stderr.strip().splitlines()[:3]))
    p = _run(["vvp", "-n", "sim"], cwd=workdir, timeout=3600)
    if p.returncode != 0:
        raise RuntimeError("vvp: " + p.stderr.strip()[:200])
    codes = []
    for ln in (workdir / "out.txt").read_text().split():
        codes.append(int(ln, 2) if set(ln) <= {"0", "1"} else None)
    if len(codes) != 1 << in_bits:
        raise RuntimeError(f"simulation printed {len(codes)} codes, not {1 << in_bits}")
    return codes, wo


def simulate_vhdl(vhdl: Path, top: str, in_bits: int, out_bits: int, workdir: Path) -> list:
    """GHDL over every input code of FloPoCo's own VHDL (ports ``clk``, ``X``,
    ``Y``; ``clk`` held at 0): the output codes (None for a non-binary output)."""
    tb = f"""library ieee; use ieee.std_logic_1164.all; use ieee.numeric_std.all;
use std.textio.all;
entity tb_flo is end entity;
architecture s of tb_flo is
  signal clk : std_logic := '0';
  signal x : std_logic_vector({in_bits - 1} downto 0);
  signal y : std_logic_vector({out_bits - 1} downto 0);
begin
  dut: entity work.{top} port map (clk => clk, X => x, Y => y);
  process
    file f : text open write_mode is "out.txt";
    variable l : line;
  begin
    for k in 0 to {(1 << in_bits) - 1} loop
      x <= std_logic_vector(to_unsigned(k, {in_bits})); wait for 1 ns;
      if is_x(y) then write(l, string'("x")); else write(l, to_integer(unsigned(y))); end if;
      writeline(f, l);
    end loop;
    wait;
  end process;
end architecture;
"""
    (workdir / "tb_flo.vhdl").write_text(tb)
    flags = ["-fsynopsys", "--std=08"]
    for argv in (["ghdl", "-a", *flags, str(vhdl), "tb_flo.vhdl"], ["ghdl", "-e", *flags, "tb_flo"],
                 ["ghdl", "-r", *flags, "tb_flo"]):
        p = _run(argv, cwd=workdir, timeout=3600)
        if p.returncode != 0:
            raise RuntimeError(f"{' '.join(argv[:2])}: " + p.stderr.strip()[:300])
    codes = [None if ln == "x" else int(ln) for ln in
             (workdir / "out.txt").read_text().split()]
    if len(codes) != 1 << in_bits:
        raise RuntimeError(f"GHDL printed {len(codes)} codes, not {1 << in_bits}")
    return codes


# ----------------------------------------------------------------------------- synthesis

def ice40_pnr(verilog: str, top: str, workdir: Path, seed: int = 1) -> dict:
    """The module between input and output registers placed and routed on an
    iCE40 HX8K: nextpnr's LC and RAM4K counts, yosys' SB_LUT4 count, Fmax."""
    from chebnorm.hw.targets import WRAP, module_ports, register_wrapper

    ports = module_ports(verilog, top)
    clocked = any(n == "clk" and d == "input" and w == 1 for n, d, w in ports)
    if not clocked:
        ports = [p for p in ports if not (p[0] == "rst" and p[2] == 1)]
    wrapper = register_wrapper(top, ports, clocked=clocked)
    (workdir / "ice.v").write_text(verilog + "\n" + wrapper + "\n")
    p = _run(["yosys", "-q", "-p", f"read_verilog ice.v; synth_ice40 -top {WRAP} -json ice.json;"
              f" tee -q -o stat.json stat -json"], cwd=workdir, timeout=3600)
    if p.returncode != 0:
        raise RuntimeError("yosys synth_ice40: " + p.stderr.strip()[-300:])
    stat = json.loads((workdir / "stat.json").read_text())
    cells = stat.get("design", {}).get("num_cells_by_type", {})
    p = _run(["nextpnr-ice40", "--hx8k", "--package", "ct256", "--json", "ice.json", "--freq",
              "100", "--seed", str(seed), "--timing-allow-fail", "--report", "report.json",
              "-q"], cwd=workdir, timeout=3600)
    if p.returncode != 0:
        raise RuntimeError("nextpnr-ice40: " + p.stderr.strip()[-300:])
    rep = json.loads((workdir / "report.json").read_text())
    util = rep.get("utilization", {})
    lc = util.get("ICESTORM_LC", {}).get("used")
    ram = util.get("ICESTORM_RAM", {}).get("used")
    fmax = min(v["achieved"] for v in rep["fmax"].values()) if rep.get("fmax") else None
    return {"lc": lc, "ram4k": ram, "sb_lut4": cells.get("SB_LUT4", 0),
            "fmax_mhz": round(fmax, 2) if fmax else None,
            "score": round(lc + ICE40_RAM_LC * ram, 1),
            "flow": "register_wrapper, synth_ice40, nextpnr-ice40 --hx8k ct256 seed 1"}


def device_figures(verilog: str, top: str, device: str, workdir: Path) -> dict:
    """Area figures of ``top`` on ``device`` (the module docstring's flows)."""
    if device == "ice40":
        return ice40_pnr(verilog, top, workdir)
    from chebnorm.hw.targets import synthesize_target

    c = synthesize_target(verilog, top, device)
    d = {"cells": c.cells, "luts": c.luts, "dsps": c.dsps, "carries": c.carries,
         "muxes": c.muxes, "brams": c.brams, "score": round(c.score, 1)}
    return d


#: the figure compared per device (the issue's acceptance)
FIGURE = {"generic": "cells", "xc7": "score", "xc7-nodsp": "luts", "ice40": "score"}


# ----------------------------------------------------------------------------- chebnorm

_Y_OFF = re.compile(r"//\s*y: .*value = \((-?\d+) \+ k\) / 2\^(-?\d+)")
_Y_PLAIN = re.compile(r"//\s*y: .*value = k / 2\^(-?\d+)")


def parse_output_format(verilog: str) -> tuple[int, int] | None:
    """``(offset, F)`` of chebnorm's banner ``y: ... value = (offset + k) / 2^F``
    (or ``k / 2^F``: offset 0); None when no such line."""
    m = _Y_OFF.search(verilog)
    if m:
        return int(m.group(1)), int(m.group(2))
    m = _Y_PLAIN.search(verilog)
    if m:
        return 0, int(m.group(1))
    return None


def chebnorm_design(spec: Spec, device: str, workdir: Path, workers: int) -> dict:
    """``chebnorm design`` for ``spec`` on ``device``: the winner's Verilog, top,
    summary line and wall time."""
    argv = [sys.executable, "-m", "chebnorm", "design", spec.expr, "--interval", str(spec.lo),
            str(spec.hi), "--in-bits", str(spec.in_bits), "--out-bits", str(spec.out_bits),
            "--faithful", "--target", device, "--workers", str(workers), "-o", str(workdir)]
    t0 = time.perf_counter()
    p = _run(argv, timeout=4 * 3600)
    wall = round(time.perf_counter() - t0, 1)
    if p.returncode != 0:
        raise RuntimeError("chebnorm design: " + " | ".join(p.stderr.strip().splitlines()[-2:]))
    files = sorted(workdir.glob("chebnorm_*.v"))
    files = [f for f in files if not f.name.startswith("tb_")]
    if not files:
        raise RuntimeError(f"chebnorm design wrote no Verilog: {sorted(os.listdir(workdir))}")
    text = "\n".join(f.read_text() for f in files)
    mods = re.findall(r"^module\s+([A-Za-z_]\w*)", text, re.M)
    stems = [f.stem for f in files]
    top = next((m for m in mods if m in stems), mods[-1])
    fmt = parse_output_format(text)
    flat = workdir / "flat"
    flat.mkdir()
    text = flatten_verilog(text, top, flat)
    winner = next((ln for ln in p.stdout.splitlines() if ln.startswith("winner")), "")
    return {"verilog": text, "top": top, "design_s": wall, "winner": winner, "format": fmt,
            "command": "chebnorm design " + " ".join(argv[4:-2])}


# ----------------------------------------------------------------------------- the run

def _load(path: Path) -> dict:
    if path.exists():
        return json.loads(path.read_text())
    return {"specs": {}}


def _merge(old: dict, new: dict) -> dict:
    """``old`` updated by ``new``, recursively (a run of one tool keeps the other's rows)."""
    out = dict(old)
    for k, v in new.items():
        out[k] = _merge(out[k], v) if isinstance(v, dict) and isinstance(out.get(k), dict) \
            else v
    return out


def _save(path: Path, doc: dict, tool: str = "") -> None:
    """Write ``doc``'s rows of ``tool`` (every row when empty) and its ``meta``
    over the file's: two runs, one per tool, may share the file."""
    if tool:
        part = {"meta": doc.get("meta", {}), "specs": {
            name: {"spec": e["spec"], tool: e[tool]}
            for name, e in doc.get("specs", {}).items() if tool in e}}
    else:
        part = doc
    merged = _merge(_load(path), part)
    tmp = path.with_suffix(f".{os.getpid()}.tmp")
    tmp.write_text(json.dumps(merged, sort_keys=True, indent=1) + "\n")
    tmp.replace(path)


def _spec_meta(spec: Spec) -> dict:
    return {"expr": spec.expr, "interval": [spec.lo, spec.hi], "in_bits": spec.in_bits,
            "lsb_out": spec.lsb_out, "out_bits": spec.out_bits, "flopoco_f": spec.flopoco_f}


def run_flopoco(doc, path, binary, spec, designs, devices, force):
    entry = doc["specs"].setdefault(spec.name, {"spec": _spec_meta(spec)})
    flo = entry.setdefault("flopoco", {})
    for design in designs:
        if design == "table" and (1 << spec.in_bits) * spec.out_bits > TABLE_BITS:
            flo[design] = {"skipped": f"a table of 2^{spec.in_bits} entries is over "
                                      f"{TABLE_BITS} bits (chebnorm's own limit)"}
            _save(path, doc, "flopoco")
            continue
        row = flo.get(design, {})
        if row.get("conversion") != CONVERSION:
            row = {}
        todo = [d for d in devices if force or d not in row.get("devices", {})]
        if row and "error" not in row and not todo and not force:
            continue
        with tempfile.TemporaryDirectory() as tmp:
            w = Path(tmp)
            try:
                g = flopoco_design(binary, spec, design, w)
            except (RuntimeError, subprocess.TimeoutExpired) as e:
                flo[design] = {"error": str(e)[:400]}
                _save(path, doc, "flopoco")
                print(f"{spec.name} flopoco {design}: {e}", file=sys.stderr)
                continue
            if force or "sim" not in row:
                simdir = w / "sim"
                simdir.mkdir()
                codes, wo = simulate(g["verilog"], g["top"], spec.in_bits, simdir)
                sim = count_errors(spec, codes, lambda c: _frac(c, spec.lsb_out))
                sim["out_width"] = wo
                row["sim"] = sim
                gdir = w / "ghdl_sim"
                gdir.mkdir()
                try:
                    gcodes = simulate_vhdl(w / f"{g['top']}.vhdl", g["top"], spec.in_bits, wo,
                                           gdir)
                    row["sim_ghdl"] = count_errors(spec, gcodes,
                                                   lambda c: _frac(c, spec.lsb_out))
                    row["sim_ghdl"]["same_codes_as_icarus"] = gcodes == codes
                except RuntimeError as e:
                    row["sim_ghdl"] = {"error": str(e)[:300]}
            row.update({"conversion": CONVERSION,
                        "command": g["command"], "gen_s": g["gen_s"], "top": g["top"],
                        "log": g["log"], "lsb_out": spec.lsb_out,
                        "tables_as_arrays": g["tables_as_arrays"],
                        "products_narrowed": g["products_narrowed"]})
            row.pop("error", None)
            devs = row.setdefault("devices", {})
            for dev in todo:
                d = w / f"syn_{dev}"
                d.mkdir()
                t0 = time.perf_counter()
                try:
                    devs[dev] = device_figures(g["verilog"], g["top"], dev, d)
                except (RuntimeError, ValueError, subprocess.TimeoutExpired) as e:
                    devs[dev] = {"error": str(e)[:400]}
                devs[dev]["synth_s"] = round(time.perf_counter() - t0, 1)
                devs[dev]["load"] = round(os.getloadavg()[0], 2)
                flo[design] = row
                _save(path, doc, "flopoco")
                print(f"{spec.name} flopoco {design} {dev}: {devs[dev]}", file=sys.stderr)
            flo[design] = row
            _save(path, doc, "flopoco")


def _frac(code: int, lsb: int):
    from fractions import Fraction

    return Fraction(code) * Fraction(2) ** lsb


def run_chebnorm(doc, path, spec, devices, force, workers):
    entry = doc["specs"].setdefault(spec.name, {"spec": _spec_meta(spec)})
    ch = entry.setdefault("chebnorm", {})
    for dev in devices:
        if dev in ch and "error" not in ch[dev] and not force:
            continue
        with tempfile.TemporaryDirectory() as tmp:
            w = Path(tmp)
            try:
                g = chebnorm_design(spec, dev, w / "out", workers)
                fmt = g["format"]
                if fmt is None:
                    raise RuntimeError("no 'y: ... value = ...' line in the winner's banner")
                off, frac = fmt
                simdir = w / "sim"
                simdir.mkdir()
                codes, wo = simulate(g["verilog"], g["top"], spec.in_bits, simdir)
                from fractions import Fraction

                sim = count_errors(spec, codes, lambda c: Fraction(off + c, 2 ** frac))
                sim["out_width"] = wo
                row = {"winner": g["winner"], "design_s": g["design_s"], "top": g["top"],
                       "command": g["command"], "lsb_out": -frac, "offset": off,
                       "lsb_match": -frac == spec.lsb_out, "sim": sim,
                       "load": round(os.getloadavg()[0], 2)}
                d = w / "syn"
                d.mkdir()
                t0 = time.perf_counter()
                row["figures"] = device_figures(g["verilog"], g["top"], dev, d)
                row["figures"]["synth_s"] = round(time.perf_counter() - t0, 1)
            except (RuntimeError, ValueError, subprocess.TimeoutExpired) as e:
                row = {"error": str(e)[:400]}
            ch[dev] = row
            _save(path, doc, "chebnorm")
            print(f"{spec.name} chebnorm {dev}: {json.dumps(row)[:300]}", file=sys.stderr)


# ----------------------------------------------------------------------------- the table

def best_flopoco(entry: dict, device: str, faithful: bool = True):
    """``(figure, design)`` of the smallest FloPoCo design on ``device`` -- only
    those with 0 codes off in simulation unless ``faithful`` is false -- (None
    when there is none)."""
    key = FIGURE[device]
    best = None
    for design, row in sorted(entry.get("flopoco", {}).items()):
        fig = row.get("devices", {}).get(device, {}).get(key)
        if fig is None or (faithful and row.get("sim", {}).get("errors", 1) != 0):
            continue
        if best is None or fig < best[0]:
            best = (fig, design)
    return best


def _fmt(v) -> str:
    return f"{v:g}" if isinstance(v, (int, float)) else str(v)


def markdown(doc: dict) -> str:
    """The docs table: per spec and device, chebnorm's winner, the best FloPoCo
    design and their ratio (``<= 0.8``: the issue's acceptance)."""
    lines = ["| spec | device (figure) | chebnorm winner | its LSB | best FloPoCo | ratio | <= 0.8x "
             "| ratio to smallest FloPoCo, faithful or not |",
             "|---|---|---|---|---|---|---|---|"]
    misses = []
    order = [s.name for s in SPECS]
    for name in sorted(doc.get("specs", {}), key=lambda n: (order.index(n) if n in order
                                                             else len(order), n)):
        entry = doc["specs"][name]
        sp = entry.get("spec", {})
        label = (f"{name}: `{sp.get('expr')}` on [{sp.get('interval', ['?', '?'])[0]}, "
                 f"{sp.get('interval', ['?', '?'])[1]}), {sp.get('in_bits')} bits, "
                 f"LSB 2^{sp.get('lsb_out')}")
        for dev in DEVICES:
            ch = entry.get("chebnorm", {}).get(dev)
            best = best_flopoco(entry, dev)
            if ch is None and best is None:
                continue
            fig = FIGURE[dev]
            cval = ch.get("figures", {}).get(fig) if ch and "error" not in ch else None
            cerr = ch.get("sim", {}).get("errors") if ch and "sim" in ch else None
            ctext = "not run" if ch is None else (f"error: {ch['error'][:60]}" if "error" in ch
                                                  else _fmt(cval))
            if dev == "ice40" and ch and "figures" in ch:
                f = ch["figures"]
                ctext = f"{_fmt(f['score'])} ({f['lc']} LC + {f['ram4k']} RAM4K, " \
                        f"{f['fmax_mhz']} MHz)"
            if cerr:
                ctext += f", {cerr} codes off"
            lsb = "" if not ch or "lsb_out" not in ch else \
                f"2^{ch['lsb_out']}" + ("" if ch["lsb_match"] else " (mismatch)")
            any_best = best_flopoco(entry, dev, faithful=False)
            note = ""
            if any_best and (best is None or any_best[0] < best[0]):
                errs = entry["flopoco"][any_best[1]]["sim"]["errors"]
                note = f"; {any_best[1]}: {_fmt(any_best[0])} but {errs} codes off"
            if best is None:
                btext, ratio, ok = ("none faithful" if any_best else "not run") + note, "", ""
                if any_best:
                    misses.append(f"{name}/{dev}")
            else:
                row = entry["flopoco"][best[1]]["devices"][dev]
                btext = f"{_fmt(best[0])} ({best[1]})"
                if dev == "ice40":
                    btext = f"{_fmt(best[0])} ({best[1]}: {row['lc']} LC + {row['ram4k']} " \
                            f"RAM4K, {row['fmax_mhz']} MHz)"
                btext += note
                if cval is not None:
                    r = cval / best[0]
                    ratio = f"{r:.2f}"
                    good = r <= 0.8 and not cerr and ch.get("lsb_match")
                    ok = "yes" if good else "**no**"
                    if not good:
                        misses.append(f"{name}/{dev}")
                elif ch is not None:          # chebnorm gave no design: a miss
                    ratio, ok = "", "**no**"
                    misses.append(f"{name}/{dev}")
                else:
                    ratio, ok = "", ""
            any_ratio = f"{cval / any_best[0]:.2f}" if any_best and cval is not None else ""
            lines.append(f"| {label} | {dev} ({fig}) | {ctext} | {lsb} | {btext} | {ratio} "
                         f"| {ok} | {any_ratio} |")
    meta = doc.get("meta", {})
    lines.append("")
    lines.append(f"FloPoCo: {meta.get('flopoco_repo', '?')} at "
                 f"{str(meta.get('flopoco_commit', '?'))[:12]}; misses of 0.8x: "
                 f"{', '.join(misses) if misses else 'none'}.")
    return "\n".join(lines)


DOCS = HERE.parent / "docs" / "flopoco.md"
MARKS = ("<!-- flopoco-table -->\n", "<!-- /flopoco-table -->\n")


def docs_table(page: str) -> str:
    """The table between the page's markers."""
    i, j = page.index(MARKS[0]) + len(MARKS[0]), page.index(MARKS[1])
    return page[i:j]


def write_docs(doc: dict, page: Path = DOCS) -> None:
    """Put :func:`markdown` of ``doc`` between the markers of ``page``."""
    text = page.read_text(encoding="utf-8")
    old = docs_table(text)
    i = text.index(MARKS[0]) + len(MARKS[0])
    page.write_text(text[:i] + markdown(doc) + "\n" + text[i + len(old):], encoding="utf-8")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--flopoco-src", type=Path, help="FloPoCo source tree to build (cached)")
    ap.add_argument("--flopoco", type=Path, help="a built flopoco binary")
    ap.add_argument("--flopoco-repo", default="github:hyf6661669/FloPoCo",
                    help="where the source came from (recorded in the JSON)")
    ap.add_argument("--flopoco-commit", default="",
                    help="the commit --flopoco was built from (recorded in the JSON)")
    ap.add_argument("--json", type=Path, default=DEFAULT_JSON)
    ap.add_argument("--spec", nargs="+", default=[s.name for s in SPECS[:7]],
                    choices=[s.name for s in SPECS])
    ap.add_argument("--devices", nargs="+", default=list(DEVICES[:2]), choices=DEVICES)
    ap.add_argument("--designs", nargs="+", default=list(FLOPOCO_DESIGNS),
                    choices=FLOPOCO_DESIGNS)
    ap.add_argument("--tool", nargs="+", default=["flopoco", "chebnorm"],
                    choices=["flopoco", "chebnorm"])
    ap.add_argument("--workers", type=int, default=1, help="chebnorm design --workers")
    ap.add_argument("--force", action="store_true", help="measure again what the JSON has")
    ap.add_argument("--markdown", action="store_true", help="print the docs table (no run)")
    ap.add_argument("--write-docs", action="store_true",
                    help="with --markdown: also write it into docs/flopoco.md")
    a = ap.parse_args(argv)
    if a.markdown:
        if not a.json.exists():
            print(f"--json {a.json}: no such file", file=sys.stderr)
            return 2
        doc = json.loads(a.json.read_text())
        print(markdown(doc))
        if a.write_docs:
            write_docs(doc)
        return 0
    doc = _load(a.json)
    meta = doc.setdefault("meta", {})
    meta.update({"tools": tool_versions(), "machine": platform.machine(),
                 "cpus": os.cpu_count(), "load_at_start": round(os.getloadavg()[0], 2)})
    if "flopoco" in a.tool:
        if a.flopoco:
            binary = a.flopoco
            meta["flopoco_build"] = {"binary": str(binary)}
            meta["flopoco_commit"] = a.flopoco_commit or meta.get("flopoco_commit", "?")
        elif a.flopoco_src:
            binary, info = build_flopoco(a.flopoco_src)
            meta["flopoco_build"] = info
            meta["flopoco_commit"] = info["source_id"]
        else:
            print("--flopoco or --flopoco-src: needed to run FloPoCo (or --tool chebnorm)",
                  file=sys.stderr)
            return 2
        meta["flopoco_repo"] = a.flopoco_repo
    _save(a.json, {"meta": meta})
    for name in a.spec:
        spec = SPEC_BY_NAME[name]
        if "flopoco" in a.tool:
            run_flopoco(doc, a.json, binary, spec, a.designs, a.devices, a.force)
        if "chebnorm" in a.tool:
            run_chebnorm(doc, a.json, spec, a.devices, a.force, a.workers)
    meta["load_at_end"] = round(os.getloadavg()[0], 2)
    _save(a.json, {"meta": meta})
    print(markdown(doc))
    return 0


if __name__ == "__main__":
    sys.exit(main())
