"""Stage 5: correctly rounded functions of small binary formats, proved on
every input.

:func:`correctly_rounded` generates a C implementation of exp, exp2, log,
log2, sin, cos, tanh, erf, sqrt or 1/sqrt for a format of at most 16 bits
(binary16, bfloat16, or any ``(precision, emin, emax)``): a range reduction
from a small catalogue, then a piecewise polynomial evaluated in binary64
whose result lies, for every input, in the round-to-odd interval of f(x) at
p + 2 bits (an Arb oracle), so that its one final rounding to the format is
correct in all five IEEE 754 rounding modes. Every input is checked by the
exact binary64 simulation of the generated code; the result's ``check()``
compiles the C with gcc and runs it on every input in the four modes C has.

binary32 1/sqrt (``arithmetic="float32"``) is the one 32-bit case: C with
float operations only, correctly rounded to nearest by an exact midpoint
test, checked on all 2^32 inputs by an integer-exact checker.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from ._formats import MODES, Format, parse_format
from ._kernels import FUNCTIONS, NAMES

__all__ = ["correctly_rounded"]  # the result class is reached through it (the export budget)

_LANGS = ("c",)
_ARITHMETICS = ("binary64", "float32")


@dataclass(frozen=True)
class CorrectlyRounded:
    """A generated correctly rounded function: its files and what was checked.

    Attributes
    ----------
    function : str
        The function's name (``exp2``, ``rsqrt`` for 1/sqrt, ...).
    format : str
        The format's name (``binary16``, ``bfloat16``, ``pPeE``).
    c_name : str
        The C function: ``uint16_t c_name(uint16_t x)`` on bit patterns.
    files : dict of str to str
        File name -> text: the C source and its header.
    pieces : dict of str to list of list of float
        Polynomial family -> one coefficient list per piece (binary64,
        ascending powers of the reduced argument).
    figures : dict
        ``inputs`` (every bit pattern), ``wrong`` (wrongly rounded outputs of
        the exact simulation per mode: RNE, RNA, RTZ, RUP, RDN), ``seconds``
        (generation time), ``oracle_seconds``.
    """

    function: str
    format: str
    c_name: str
    files: dict = field(repr=False)
    pieces: dict = field(repr=False)
    figures: dict = field(repr=False)
    _ro: object = field(default=None, repr=False, compare=False)
    _fmt: object = field(default=None, repr=False, compare=False)
    _domain: object = field(default=None, repr=False, compare=False)

    def check(self, source: str | None = None, ranges=None) -> dict:
        """Compile the C (or ``source``, a changed copy of it) with gcc and
        run it on every input in RNE, RTZ, RUP and RDN against the oracle
        (binary32: every float32 input in RNE against an exact integer test).

        Parameters
        ----------
        source : str, optional
            C text to check instead of the generated source.
        ranges : sequence of (int, int), optional
            binary32 only: the half-open ranges of bit patterns to run
            (default: all 2**32).

        Returns
        -------
        dict of str to int
            Wrongly rounded outputs per mode (0 everywhere when correct);
            binary32: ``{"RNE": n}``, and the per-class figures (inputs,
            wrong) and wall time in :attr:`figures` ``["check"]``.
        """
        from ._check import check_c

        src = self.files[f"{self.c_name}.c"] if source is None else source
        if self.format == "binary32":
            from ._check32 import ALL, check_rsqrt32

            got = check_rsqrt32(src, self.files[f"{self.c_name}.h"], self.c_name,
                                ALL if ranges is None else ranges)
            self.figures["check"] = got
            return {"RNE": sum(got[k][1] for k in ("normal", "subnormal", "special"))}
        if ranges is not None:
            raise ValueError("ranges is accepted only for binary32; the 16-bit check runs every "
                             "input")
        return check_c(src, self.files[f"{self.c_name}.h"], self.c_name, self._fmt, self._ro,
                       domain=self._domain)


def correctly_rounded(expr: str, fmt="binary16", *, interval=None, arithmetic: str = "binary64",
                      lang: str = "c", command: str = "", fma: bool | None = None
                      ) -> CorrectlyRounded:
    """Generate a correctly rounded implementation of ``expr`` on ``fmt``.

    Parameters
    ----------
    expr : str
        ``exp``, ``exp2``, ``log``, ``log2``, ``sin``, ``cos``, ``tanh``,
        ``erf``, ``sqrt`` or ``1/sqrt`` (also written with ``(x)``).
    fmt : str or Format, default "binary16"
        ``binary16``, ``bfloat16``, ``"p,emin,emax"`` (at most 16 bits), or
        ``binary32`` (1/sqrt with ``arithmetic="float32"`` only).
    interval : (float, float), optional
        Prove only the finite inputs ``lo <= x <= hi`` (default: every input,
        zeros, infinities and NaN included).
    arithmetic : str, default "binary64"
        The evaluation arithmetic: ``binary64``, or ``float32`` (1/sqrt on
        binary32: the generated C uses ``float`` only and is correctly
        rounded to nearest).
    lang : str, default "c"
        The output language; only ``c`` for now.
    command : str, optional
        The command quoted in the files' provenance.
    fma : bool, optional
        ``arithmetic="float32"`` only: use ``fmaf`` (default True) or, with
        False, Dekker's exact products on Veltkamp's splitting.

    Returns
    -------
    CorrectlyRounded
        The files, pieces and figures; ``figures["wrong"]`` is 0 in every
        mode (else an error is raised).

    Raises
    ------
    ValueError
        On an unknown ``expr``, ``fmt``, ``arithmetic`` or ``lang``.
    ArithmeticError
        When no piecewise polynomial is found (none of the ten functions on
        binary16 or bfloat16).

    Examples
    --------
    >>> r = correctly_rounded("exp2", "binary16")
    >>> r.figures["wrong"]["RUP"]
    0
    """
    from chebnorm import __version__
    from chebnorm.core.textsafe import comment_text

    import numpy as np

    from ._build import build, c_source, domain_mask

    if not isinstance(expr, str) or expr.replace(" ", "") not in NAMES:
        raise ValueError(f"expr {str(expr)[:40]!r} is not accepted; accepted: "
                         f"{', '.join(f if f != 'rsqrt' else '1/sqrt' for f in FUNCTIONS)}")
    if arithmetic not in _ARITHMETICS:
        raise ValueError(f"arithmetic {str(arithmetic)[:40]!r} is not accepted; accepted: binary64, "
                         f"float32 (1/sqrt on binary32)")
    if lang not in _LANGS:
        raise ValueError(f"lang {str(lang)[:40]!r} is not accepted; accepted: c (glsl, wgsl, hlsl "
                         f"are not implemented yet)")
    if fma not in (None, True, False):
        raise ValueError(f"fma {str(fma)[:40]!r} is not accepted; accepted: True or False")
    if arithmetic == "float32" or fmt == "binary32":
        return _rsqrt_binary32(expr, fmt, interval, arithmetic, fma, command)
    if fma is not None:
        raise ValueError("fma is not accepted with arithmetic binary64; accepted: only with "
                         "arithmetic float32")
    f = parse_format(fmt)
    if f.bits > 16:
        raise ValueError(f"fmt of {f.bits} bits is not accepted; accepted: at most 16 bits")
    name = NAMES[expr.replace(" ", "")]
    where = ""
    if interval is not None:
        try:
            lo, hi = (float(v) for v in interval)
        except (TypeError, ValueError):
            raise ValueError("interval is not accepted; accepted: two finite numbers lo <= hi"
                             ) from None
        if not (np.isfinite(lo) and np.isfinite(hi) and lo <= hi):
            raise ValueError(f"interval [{lo!r}, {hi!r}] is not accepted; accepted: two finite "
                             f"numbers lo <= hi")
        if not domain_mask(f.decode(f.all_bits()), (lo, hi)).any():
            raise ValueError(f"interval [{lo!r}, {hi!r}] holds no {f.name} value; accepted: an "
                             f"interval of finite {f.name} values")
        interval = (lo, hi)
        where = f" in [{lo!r}, {hi!r}]"
    kernel, coefs, figures, ro, dom = build(name, f, interval)
    c_name = f"cr_{name}_{f.name}"
    banner = (f"/* {c_name}: {name} correctly rounded on {f.name} (precision {f.precision}, "
              f"exponents {f.emin}..{f.emax}).\n"
              f" * Generated by chebnorm {__version__}"
              + (f": {comment_text(command)}" if command else "") + ".\n"
              f" * Correctly rounded in all five rounding modes on every {f.name} input{where}, "
              f"checked exhaustively.\n"
              f" * Compile with -ffp-contract=off -frounding-math (no FMA contraction).\n */")
    hdr = (f"{banner}\n#ifndef {c_name.upper()}_H\n#define {c_name.upper()}_H\n#include <stdint.h>\n"
           f"/* x and the result are {f.name} bit patterns; the result is {name}(x) rounded in the\n"
           f"   current rounding mode (fegetround), which is left unchanged. */\n"
           f"{f.ctype} {c_name}({f.ctype} x);\n#endif\n")
    src = c_source(kernel, coefs, f, c_name, f"{c_name}.h", banner) + "\n"
    pieces = {k: [[float(c) for c in row] for row in v] for k, v in coefs.items()}
    return CorrectlyRounded(name, f.name, c_name, {f"{c_name}.c": src, f"{c_name}.h": hdr},
                            pieces, figures, ro, f, None if interval is None else dom)


def _rsqrt_binary32(expr, fmt, interval, arithmetic, fma, command) -> CorrectlyRounded:
    """1/sqrt on binary32 with float32 arithmetic only (the one float32 case)."""
    import time

    from chebnorm import __version__
    from chebnorm.core.textsafe import comment_text

    from ._rsqrt32 import START, c_files

    t0 = time.perf_counter()
    is_rsqrt = isinstance(expr, str) and NAMES.get(expr.replace(" ", "")) == "rsqrt"
    if arithmetic != "float32" and not is_rsqrt:
        raise ValueError(f"fmt 'binary32' is not accepted for {str(expr)[:40]!r}; accepted: "
                         f"binary16, bfloat16, 'p,emin,emax' of at most 16 bits (binary32: 1/sqrt "
                         f"with arithmetic float32 only)")
    if not is_rsqrt:
        raise ValueError(f"expr {str(expr)[:40]!r} is not accepted with arithmetic float32; "
                         f"accepted: 1/sqrt")
    if fmt != "binary32":
        raise ValueError(f"fmt {str(fmt)[:40]!r} is not accepted with arithmetic float32; "
                         f"accepted: binary32")
    if arithmetic != "float32":
        raise ValueError(f"arithmetic {str(arithmetic)[:40]!r} is not accepted for binary32; "
                         f"accepted: float32")
    if interval is not None:
        raise ValueError("interval is not accepted for binary32; accepted: none (every float32 "
                         "input)")
    fma = True if fma is None else fma
    c_name = "cr_rsqrt_binary32"
    banner = (f"/* {c_name}: 1/sqrt correctly rounded to nearest on binary32, float arithmetic "
              f"only ({'fmaf' if fma else 'no FMA: Dekker products'}).\n"
              f" * Generated by chebnorm {__version__}"
              + (f": {comment_text(command)}" if command else "") + ".\n"
              " * Correctly rounded to nearest-even on every float input (zeros, subnormals,\n"
              " * infinities and NaN as IEEE 754 says), by an exact midpoint test; checked\n"
              " * exhaustively over all 2^32 inputs by an integer-exact checker.\n"
              " * Compile with -ffp-contract=off -fno-fast-math; call in round-to-nearest.\n */")
    files = c_files(c_name, banner, fma)
    figures = {"inputs": 1 << 32, "wrong": {"RNE": None}, "fma": fma,
               "seconds": time.perf_counter() - t0}
    return CorrectlyRounded("rsqrt", "binary32", c_name, files, {"start": [list(START)]}, figures)


del MODES, Format
