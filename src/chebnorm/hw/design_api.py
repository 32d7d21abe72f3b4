"""``design()``: the cheapest certified hardware evaluator of a function, from
Python (``chebnorm design`` is its command-line front).

The decisions of a design live here: the one-width piecewise Pareto search
(:mod:`chebnorm.hw.piecewise_search`), the other architectures (sized piecewise,
multipartite, plain table; :mod:`chebnorm.hw.architectures`) synthesized in one pruned
queue with it, the winner by its score on the device (:mod:`chebnorm.hw.targets`), its
pipelining to a clock (:mod:`chebnorm.hw.pipeline`), or, with ``index="exponent"``, the
exponent-indexed ``1/sqrt`` of :mod:`chebnorm.hw.exponent`. The result holds every
candidate, the text the command prints (:meth:`DesignResult.lines`) and the
files it writes (:meth:`DesignResult.files`).

The module is named ``design_api`` because :mod:`chebnorm.hw.units.design`
already holds the units' ``design`` module.
"""

from __future__ import annotations

import keyword
import math
import shlex
import warnings
from dataclasses import dataclass, field, replace

from chebnorm.approx.piecewise_table import MAX_PIECEWISE_DEGREE
from chebnorm.core.numeric import check_int, format_up
from chebnorm.core.textsafe import csv_cell, design_name, identifier
from chebnorm.exceptions import ToolTimeout

from .targets import get_target

# an implementation module of chebnorm.hw: the API is what chebnorm.hw exports
__all__: list[str] = []

#: the accuracies a design meets, as the result names them
ACCURACIES = ("max-error", "faithful", "correctly-rounded")
#: the ways an input code picks its segment
INDEXES = ("uniform", "exponent")
#: the architectures ``architecture=`` (``--architecture``) may restrict a design to
ARCHITECTURES = ("piecewise", "piecewise-sized", "multipartite", "table")


@dataclass(frozen=True)
class Winner:
    """The winning design of :func:`design`.

    Attributes
    ----------
    architecture : str
        ``"piecewise"`` (the one-width search), ``"piecewise-sized"``,
        ``"multipartite"``, ``"table"`` or ``"exponent"``.
    description : str
        One line describing it (segments, degree, widths).
    design : object
        The design object (a :class:`~chebnorm.hw.piecewise.PiecewiseDesign`,
        :class:`~chebnorm.hw.multipartite.MultipartiteDesign`, ...); with
        ``frequency``, the pipelined design.
    score : float or None
        Its cost on the device (LUT equivalents on xc7/ice40, yosys cells on
        generic, the model's estimate without synthesis; with ``frequency``, the
        pipelined design's as it was timed, its registers counted: on ice40 the
        module between input and output registers, where yosys may fold a
        register into a ROM's block RAM); None when not priced.
    error : float or None
        Its certified bound on ``|y - f(x)|`` (the mantissa's for ``exponent``).

    Examples
    --------
    >>> from chebnorm.hw import design
    >>> w = design("1/sqrt(x)", ("1", "4"), in_bits=6, out_bits=6, max_error="2^-4",
    ...            synth=False, workers=1).winner
    >>> w.architecture, w.error <= 2 ** -4, w.design.module_name == "chebnorm_" + w.design.name
    ('piecewise', True, True)
    """

    architecture: str
    description: str
    design: object
    score: float | None
    error: float | None


@dataclass(frozen=True)
class DesignResult:
    """What :func:`design` found: the winner, every candidate, the search.

    Attributes
    ----------
    name : str
        The module name (given, or made from the spec).
    device : str
        The device priced on (``generic``, ``xc7``, ``xc7-nodsp``, ``ice40``).
    accuracy : str
        ``"max-error"``, ``"faithful"`` or ``"correctly-rounded"``.
    winner : Winner
        The cheapest design meeting the accuracy.
    candidates : tuple
        Every other architecture tried: :class:`~chebnorm.hw.architectures.Candidate`
        objects (with their cost, or the note saying why they lost), or for
        ``index="exponent"`` ``(ExponentDesign, TargetCost or None)`` pairs, one
        per degree that met the accuracy.
    search : chebnorm.hw.piecewise_search.SearchResult or None
        The one-width piecewise Pareto search (None for a correctly rounded
        spec and for ``index="exponent"``).
    pipeline : chebnorm.hw.pipeline.PipelineResult or None
        The pipelining to ``frequency`` (None without it).
    notes : tuple of str
        Why some degrees gave no design (``index="exponent"``).
    _lines : tuple of str
        Internal: what :meth:`lines` returns.
    _data : dict
        Internal: the files computed by :func:`design` and the default command.
    _hdl : str
        Internal: the winner's HDL files to print in :meth:`files` (``""``: none,
        ``"architecture"``, ``"exponent"``).
    lsb : int or None
        The output's last place is ``2^lsb`` (FloPoCo's ``lsbOut``): the one
        stated (``lsb=``), else the one every architecture was built at (the
        smallest the range of ``f`` lets ``out_bits`` hold); None for
        ``index="exponent"`` (a mantissa and a shift).
    out_bits : int or None
        The output code width (stated, or derived from ``lsb`` and the range
        of ``f``).
    timings : tuple
        With ``frequency``: per architecture that meets the accuracy,
        ``(architecture, description, PipelineResult, score)``, each pipelined for
        the frequency, ``score`` that of the netlist timed (on ice40 the module
        between input and output registers); the winner is the cheapest reaching
        the frequency, else the fastest. Empty without ``frequency``.

    Examples
    --------
    >>> from chebnorm.hw import design
    >>> r = design("1/sqrt(x)", ("1", "4"), in_bits=6, out_bits=6, max_error="2^-4",
    ...            synth=False, workers=1)
    >>> r.accuracy, r.device, r.search is not None, r.pipeline is None
    ('max-error', 'generic', True, True)
    >>> r.lines()[-1].startswith("reproduce: chebnorm fit '1/sqrt(x)'")
    True
    """

    name: str
    device: str
    accuracy: str
    winner: Winner
    candidates: tuple
    search: object
    pipeline: object
    notes: tuple = ()
    _lines: tuple = field(default=(), repr=False)
    _data: dict = field(default_factory=dict, repr=False, compare=False)
    _hdl: str = field(default="", repr=False)
    timings: tuple = ()
    lsb: int | None = None
    out_bits: int | None = None

    def lines(self) -> list[str]:
        """The text ``chebnorm design`` prints after the paths of its files.

        Returns
        -------
        list of str
            The winner and why it wins, its figures on the device, the other
            candidates and why they lose, and (one-width winner) the commands
            that reproduce it.
        """
        return list(self._lines)

    def files(self, command: str | None = None, version: str | None = None) -> dict:
        """The files ``chebnorm design`` writes, by name.

        Parameters
        ----------
        command : str, optional
            The command quoted in the HDL files' provenance banners (default:
            the ``chebnorm design`` command of this spec).
        version : str, optional
            The chebnorm version in the banners (default: the installed one).

        Returns
        -------
        dict of str to (str or bytes)
            ``design_NAME.csv`` / ``.png`` (the one-width search),
            ``design_NAME_architectures.csv``, and when another architecture
            wins (or the one-width winner is pipelined for ``frequency``) its ``.v``
            and ``.vhd`` (with benches and vectors for
            ``index="exponent"``); sorted by name.
        """
        files = dict(self._data.get("static", {}))
        if self._hdl:
            command = self._data["command"] if command is None else str(command)
            version = _version() if version is None else str(version)
            files.update(_hdl_files(self._hdl, self.winner.design, version, command))
        return dict(sorted(files.items()))

    def __repr__(self) -> str:
        return (f"DesignResult(name={self.name!r}, device={self.device!r}, "
                f"winner={self.winner.architecture}: {self.winner.description!r}, "
                f"score={self.winner.score}, candidates={len(self.candidates)})")


def _version() -> str:
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("chebnorm")
    except PackageNotFoundError:
        return "0.0.0+unknown"


def _hdl_files(kind: str, d, version: str, command: str) -> dict:
    files = {f"{d.module_name}.v": d.verilog(version=version, command=command),
             f"{d.module_name}.vhd": d.vhdl(version=version, command=command)}
    if kind == "exponent":   # its benches too (the exponent command's own outputs)
        for lang in ("verilog", "vhdl"):
            for fname, text in d.hdl_files(lang).items():
                if fname.startswith("tb_") or fname.endswith(".hex"):
                    files[fname] = text
    return files


@dataclass(frozen=True)
class _Spec:
    expr: str
    interval: tuple
    in_bits: int
    out_bits: int
    max_error: float | None
    accuracy: str
    device: str
    frequency: float | None
    degrees: tuple
    max_index_bits: int
    max_segments: object
    index: str
    var: str
    name: str
    synth: bool
    workers: int | None
    scheduler: object
    lsb: int | None = None          # the output's last place 2^lsb (None: exponent index)
    lsb_stated: bool = False        # given by the caller (the command says --lsb)
    f_range: tuple = ()             # (min, max) of f over the input codes
    architecture: str | None = None  # only this architecture (None: every one)
    simulate: bool = False          # the winner simulated over every code

    @property
    def frac_bits(self) -> int | None:
        """y's fractional bits: ``-lsb``."""
        return None if self.lsb is None else -self.lsb

    def format_phrase(self) -> str:
        """The output format every candidate was built at, in words."""
        if self.lsb is None:
            return ""
        lo, hi = self.f_range
        how = "stated" if self.lsb_stated else f"the finest {self.out_bits} bits hold"
        return (f"output LSB 2^{self.lsb} (y = k / 2^{-self.lsb} + offset, {self.out_bits} "
                f"bits, f in [{lo:.6g}, {hi:.6g}]; {how})")

    def parallel(self) -> dict:
        return {"workers": self.workers, "scheduler": self.scheduler}

    def command(self) -> str:
        """The ``chebnorm design`` command of this spec."""
        words = ["chebnorm", "design", self.expr, "--var", self.var, "--interval",
                 *self.interval, "--in-bits", self.in_bits, "--out-bits", self.out_bits]
        if self.lsb_stated:
            words += ["--lsb", self.lsb]
        words += (["--max-error", repr(self.max_error)] if self.accuracy == "max-error"
                  else [f"--{self.accuracy}"])
        words += ["--degrees", *self.degrees, "--target", self.device, "--index", self.index,
                  "--name", self.name]
        if self.max_segments is not None:
            words += ["--max-segments", self.max_segments]
        if self.frequency is not None:
            words += ["--frequency", repr(self.frequency)]
        if not self.synth:
            words.append("--no-synth")
        if self.architecture is not None:
            words += ["--architecture", self.architecture]
        if self.simulate:
            words.append("--simulate")
        return " ".join(shlex.quote(str(w)) for w in words + ["-o", "DIR"])


def design(expr, interval, *, in_bits: int, out_bits: int | None = None, max_error=None,
           faithful: bool = False, correctly_rounded: bool = False, device: str = "generic",
           frequency=None, degrees=(1, 2, 3), max_segments=None, index: str = "uniform",
           var: str = "x", name: str | None = None, synth: bool = True,
           workers: int | None = None, scheduler=None, lsb: int | None = None,
           architecture: str | None = None, simulate: bool = False) -> DesignResult:
    """The cheapest certified hardware evaluator of ``expr`` meeting an accuracy.

    Exactly what ``chebnorm design`` computes (it parses its flags and calls this):
    the one-width piecewise Pareto search and, with synthesis, the sized
    piecewise, multipartite and plain-table architectures, priced on ``device``;
    the cheapest wins. With ``frequency``, every architecture meeting the accuracy
    is pipelined to that clock (:func:`~chebnorm.hw.pipeline.pipeline_to_frequency`)
    and the cheapest pipelined design reaching it wins (registers counted; when none
    does, the fastest, with a warning naming it); the winner's pipelined RTL is
    simulated cycle by cycle over every input code.

    Every candidate is built at one output format, so that they are compared at
    the same format and accuracy: the output's last place is ``2^lsb``
    (FloPoCo's ``lsbOut``) when ``lsb`` is given, else ``2^-F`` with ``F`` the
    most fractional bits at which the range of ``f`` over the input codes has
    ``out_bits``-bit codes (with an offset). ``faithful`` and ``max_error`` are
    relative to that format; the result's ``lsb`` and the winner line say it.
    An architecture that finds no design meeting the accuracy is one line of
    the report; the others still compete.

    Parameters
    ----------
    expr : str
        The function, in sympy syntax (e.g. ``"1/sqrt(x)"``).
    interval : (lo, hi)
        Rational endpoints (numbers or text such as ``"2^-8"``): input code
        ``k`` of ``in_bits`` maps onto ``[lo, hi)``.
    in_bits : int
        Input code width, 2..20 (4..20 with ``index="exponent"``).
    out_bits : int, optional
        Output code width, 1..32. At least one of ``out_bits`` and ``lsb`` is
        given; with ``lsb`` alone it is derived from the range of ``f``, with
        both it is checked to hold that range at ``2^lsb``.
    max_error : float or str, optional
        Certified bound on ``|y - f(x)|``, a finite number > 0 (text such as
        ``"2^-16"`` is read exactly). Exactly one of ``max_error``,
        ``faithful`` and ``correctly_rounded`` is given.
    faithful : bool, default False
        Certified ``|y - f(x)| < 1`` unit of the output's last place.
    correctly_rounded : bool, default False
        Every output code the proved rounding of ``f`` (a plain table).
    device : str, default "generic"
        The FPGA priced on: ``generic`` (yosys cells), ``xc7``, ``xc7-nodsp``
        or ``ice40`` (the command's ``--target``).
    frequency : float, optional
        Clock in MHz (finite, > 0): pipeline every architecture until the device's
        Fmax reaches it and choose the winner by its pipelined cost (ice40, xc7,
        xc7-nodsp, with synthesis; ``index="uniform"``).
        A shortfall is a :class:`~chebnorm.hw.pipeline.FrequencyWarning`.
    degrees : sequence of int, default (1, 2, 3)
        Polynomial degrees tried, 0..the piecewise maximum (1..3 with
        ``index="exponent"``).
    max_segments : int or str, optional
        Largest segment count tried: a power of two ``2^0 .. 2^min(12, in_bits - 1)``
        (``16`` or ``"2^4"``); default ``2^8``, or ``2^(in_bits - 1)`` when
        ``in_bits <= 8``.
    index : {"uniform", "exponent"}, default "uniform"
        ``uniform``: the code's top bits pick the segment; ``exponent``:
        ``1/sqrt(x)`` on ``[2^-m, 1]`` indexed by a leading-zero count
        (:mod:`chebnorm.hw.exponent`).
    var : str, default "x"
        The variable of ``expr``.
    name : str, optional
        The module name (an identifier); default: made from the spec
        (:func:`chebnorm.core.textsafe.design_name`).
    synth : bool, default True
        Synthesize with yosys; False prices by the model only (with
        ``index="uniform"``: ``max_error`` only, no ``frequency``).
    workers : int, optional
        Local worker processes (default: the core count; 1 in this process).
    scheduler : str, optional
        A Dask distributed scheduler address (overrides ``workers``).
    lsb : int, optional
        The output's last place is ``2^lsb`` for every architecture (-60..60;
        the command's ``--lsb``); ``index="uniform"`` only (the exponent
        index outputs a mantissa and a shift).
    architecture : str, optional
        Only this architecture: ``"piecewise"`` (the one-width search),
        ``"piecewise-sized"``, ``"multipartite"`` or ``"table"`` (the
        reproduce line of a winner names it); default: every one.
    simulate : bool, default False
        Simulate the winner's Verilog over every input code in Icarus Verilog
        against its bit-accurate model and measure its error against the
        rigorous reference of ``f`` (a line of the report; ValueError when
        they disagree).

    Returns
    -------
    DesignResult
        The winner, every candidate, the one-width search, the pipelining, the
        printed lines and the files.

    Raises
    ------
    ValueError
        An argument out of its accepted range (the message names it), or no
        design meets the accuracy asked.

    Examples
    --------
    >>> from chebnorm.hw import design
    >>> r = design("1/sqrt(x)", ("1", "4"), in_bits=8, out_bits=8, max_error="2^-6",
    ...            synth=False, workers=1)
    >>> r.winner.architecture, r.winner.error <= 2 ** -6
    ('piecewise', True)
    >>> sorted(r.files())
    ['design_rsqrt_1_4_i8_o8_e_2_m6.csv', 'design_rsqrt_1_4_i8_o8_e_2_m6.png']
    """
    spec = _check(expr, interval, in_bits, out_bits, max_error, faithful, correctly_rounded,
                  device, frequency, degrees, max_segments, index, var, name, synth, workers,
                  scheduler, lsb, architecture, simulate)
    if spec.index == "exponent":
        res = _design_exponent(spec)
        d = res.winner.design
        lines = list(res.lines())
        if spec.simulate:
            lines.insert(1, _simulate(spec, d, -d.frac_bits, "mantissa "))
        again = replace(spec, degrees=(d.degree,), simulate=True).command()
        return replace(res, _lines=(*lines, f"reproduce: {again}"), out_bits=spec.out_bits)
    res = _design_uniform(spec)
    lines = list(res.lines())
    k = next((i for i, t in enumerate(lines) if t.startswith("winner")), 0)
    lines[k] += f"; {spec.format_phrase()}"
    if spec.simulate:
        lines.insert(k + 1, _simulate(spec, res.winner.design, spec.lsb))
    return replace(res, _lines=tuple(lines), lsb=spec.lsb, out_bits=spec.out_bits)


def _check(expr, interval, in_bits, out_bits, max_error, faithful, correctly_rounded, device,
           frequency, degrees, max_segments, index, var, name, synth, workers,
           scheduler, lsb=None, architecture=None, simulate=False) -> _Spec:
    """Every argument of :func:`design`, checked; the spec."""
    from chebnorm.core.parallel import check_scheduler, check_workers

    if not isinstance(expr, str) or not expr.strip():
        raise ValueError(f"expr {str(expr)[:40]!r}: accepted: a function of {var!r} as text, "
                         f"e.g. '1/sqrt(x)'")
    if isinstance(interval, (str, bytes)) or not hasattr(interval, "__iter__") or \
            len(tuple(interval)) != 2:
        raise ValueError(f"interval {str(interval)[:40]!r}: accepted: two endpoints (lo, hi)")
    interval = tuple(str(v) for v in interval)
    if not isinstance(var, str) or not var.isascii() or not var.isidentifier() or \
            keyword.iskeyword(var) or var.startswith("_"):
        raise ValueError(f"var {str(var)[:40]!r} is not accepted; accepted: an ASCII "
                         f"identifier such as x or z, not a keyword, function or constant "
                         f"name and not starting with '_'")
    in_bits = check_int(in_bits, "in_bits", 2, 20)
    if out_bits is None and lsb is None:
        raise ValueError("give out_bits=N (the output width) or lsb=L (its last place 2^L), "
                         "or both")
    if out_bits is not None:
        out_bits = check_int(out_bits, "out_bits", 1, 32)
    if lsb is not None:
        lsb = check_int(lsb, "lsb", -60, 60)
    if architecture is not None and architecture not in ARCHITECTURES:
        raise ValueError(f"architecture {str(architecture)[:40]!r}: accepted: "
                         f"{', '.join(map(repr, ARCHITECTURES))}")
    for flag, value in (("faithful", faithful), ("correctly_rounded", correctly_rounded),
                        ("synth", synth), ("simulate", simulate)):
        if not isinstance(value, bool):
            raise ValueError(f"{flag} {str(value)[:40]!r}: accepted: True or False")
    if (max_error is not None) + faithful + correctly_rounded != 1:
        raise ValueError("give exactly one of max_error=E, faithful=True and "
                         "correctly_rounded=True")
    accuracy = ("faithful" if faithful else "correctly-rounded" if correctly_rounded
                else "max-error")
    if max_error is not None:
        max_error = _max_error(max_error)
    if index not in INDEXES:
        raise ValueError(f"index {str(index)[:40]!r}: accepted: 'uniform' or 'exponent'")
    try:
        device = get_target(device).name
    except ValueError as exc:   # get_target says 'target': the function is the target here
        raise ValueError(str(exc).replace("target ", "device ", 1)) from None
    if isinstance(degrees, (str, bytes)) or not hasattr(degrees, "__iter__") or \
            not list(degrees):
        raise ValueError(f"degrees {str(degrees)[:40]!r}: accepted: a non-empty sequence of "
                         f"int, e.g. (1, 2, 3)")
    degrees = tuple(check_int(d, "degrees", 0, MAX_PIECEWISE_DEGREE) for d in degrees)
    top = min(12, in_bits - 1)
    if max_segments is None:
        max_index_bits = min(8, top)
    else:
        from chebnorm.approx.piecewise_table import parse_segments

        try:
            max_index_bits = parse_segments(max_segments)
        except ValueError:
            max_index_bits = -1
        if not 0 <= max_index_bits <= top:
            raise ValueError(f"max_segments {str(max_segments)[:40]}: with in_bits {in_bits} "
                             f"accepted: 2^0 .. 2^{top} (at most half the input codes, and "
                             f"2^12)")
    if index == "exponent" and (lsb is not None or architecture is not None):
        raise ValueError(f"{'lsb' if lsb is not None else 'architecture'}: not available "
                         f"with index='exponent' (its output is a mantissa and a shift: its "
                         f"last place moves with the shift); accepted: "
                         f"{'lsb' if lsb is not None else 'architecture'}=None, or "
                         f"index='uniform'")
    if frequency is not None and index == "exponent":   # never silently ignored
        raise ValueError(f"frequency {str(frequency)[:40]}: not available with "
                         f"index='exponent' (its winner is written combinational); accepted: "
                         f"frequency=None, or index='uniform'")
    if frequency is not None:
        frequency = _frequency(frequency, device, synth)
    if accuracy != "max-error" and not synth and index == "uniform":
        raise ValueError(f"{_python(accuracy)} compares architectures by synthesis; accepted: "
                         f"synth=True (or max_error=E with synth=False)")
    workers = None if workers is None else check_workers(workers)
    check_scheduler(scheduler)
    if architecture not in (None, "piecewise") and not synth:
        raise ValueError(f"architecture {architecture!r} is priced by synthesis: not "
                         f"available with synth=False; accepted: synth=True")
    if architecture == "piecewise" and accuracy == "correctly-rounded":
        raise ValueError("architecture 'piecewise' is faithful at best; accepted with "
                         "correctly_rounded=True: architecture 'table' or None")
    f_range, stated = (), lsb is not None
    if index == "uniform":
        out_bits, lsb, f_range = _output_format(expr, interval, in_bits, var, out_bits, lsb)
    if name is None:
        tags = (["faithful"] if faithful else ["cr"] if correctly_rounded else
                ["e", _error_tag(max_error)])
        if index == "exponent":
            tags.append("lz")
        if stated:
            tags.insert(0, f"lsb{'m' if lsb < 0 else ''}{abs(lsb)}")
        name = design_name(expr, interval, in_bits, out_bits, var=var, tags=tags)
    name = identifier(name, field="name")
    return _Spec(expr, interval, in_bits, out_bits, max_error, accuracy, device, frequency,
                 degrees, max_index_bits, max_segments, index, var, name, synth, workers,
                 scheduler, lsb, stated, f_range, architecture, simulate)


def _output_format(expr, interval, in_bits, var, out_bits, lsb):
    """``(out_bits, lsb, (min f, max f))``: the output format every architecture is
    built at. The range of ``f`` over the input codes (its float64 midpoints, as
    the table and multipartite designers read it) needs the codes
    ``floor(min f 2^F) .. ceil(max f 2^F)`` at ``F = -lsb`` fractional bits: with
    ``lsb`` alone their width is ``out_bits``, with both it is checked; with
    ``out_bits`` alone ``F`` is the most that fit."""
    from .exhaustive import reference

    ref = reference(expr, interval, in_bits, var)
    lo, hi = float(ref.mid.min()), float(ref.mid.max())

    def codes(f: int) -> int:
        return math.ceil(hi * 2.0 ** f) - math.floor(lo * 2.0 ** f)

    if lsb is None:
        f = next((f for f in range(60, -61, -1) if codes(f) <= 2 ** out_bits - 1), None)
        if f is None:
            raise ValueError(f"out_bits {out_bits}: f spans [{lo:.6g}, {hi:.6g}], which no "
                             f"last place 2^-60 .. 2^60 holds; accepted: more out_bits")
        return out_bits, -f, (lo, hi)
    need = max(1, codes(-lsb).bit_length())
    if out_bits is None:
        if need > 32:
            least = next(L for L in range(lsb, 61) if codes(-L).bit_length() <= 32)
            raise ValueError(f"lsb {lsb}: f spans [{lo:.6g}, {hi:.6g}], which needs {need} "
                             f"output bits at 2^{lsb}; accepted: lsb >= {least} (at most 32 "
                             f"bits)")
        return need, lsb, (lo, hi)
    if need > out_bits:
        fits = next((L for L in range(lsb, 61) if codes(-L) <= 2 ** out_bits - 1), None)
        raise ValueError(f"out_bits {out_bits}: f spans [{lo:.6g}, {hi:.6g}], which needs "
                         f"{need} bits at lsb {lsb} (codes {math.floor(lo * 2.0 ** -lsb)} .. "
                         f"{math.ceil(hi * 2.0 ** -lsb)}); accepted: out_bits >= {need}, or "
                         f"lsb >= {fits} with out_bits {out_bits}, or out_bits omitted (derived)")
    return out_bits, lsb, (lo, hi)


def _python(accuracy: str) -> str:
    return {"faithful": "faithful=True", "correctly-rounded": "correctly_rounded=True"}.get(
        accuracy, "max_error=E")


def _max_error(value) -> float:
    """``max_error`` as a finite float > 0 (text such as ``2^-16`` read exactly)."""
    from chebnorm.approx import parse_number

    v = math.nan
    if not isinstance(value, bool):
        try:
            v = float(parse_number(str(value).replace("^", "**")))
        except (ValueError, TypeError, OverflowError):
            v = math.nan
    if not (math.isfinite(v) and v > 0):
        raise ValueError(f"max_error {str(value)[:40]!r}: accepted: a finite number > 0, e.g. "
                         f"1e-5 or 2^-16")
    return v


def _error_tag(e: float) -> str:
    """The name's tag of ``max_error``, by value: ``2^-6`` and 0.015625 name one design."""
    m, k = math.frexp(e)
    return f"2^{k - 1}" if m == 0.5 else repr(e)


def _frequency(value, device: str, synth: bool) -> float:
    """``frequency`` in MHz, checked with the device and synthesis."""
    from .pipeline import check_frequency

    if not str(value).isascii():   # float() reads other scripts' digits
        raise ValueError(f"frequency {str(value)[:40]!r}: accepted: a finite number of MHz "
                         f"> 0 in ASCII digits, e.g. 100")
    freq = check_frequency(value, "frequency")
    if device == "generic" or not synth:
        raise ValueError(f"frequency {value} needs an FPGA's timing; accepted: device ice40, "
                         f"xc7 or xc7-nodsp, with synth=True")
    return freq


# --- index="uniform": the one-width search and the other architectures -------------------

def _design_uniform(spec: _Spec) -> DesignResult:
    if not spec.synth:
        others, res = [], _search(spec, spec.max_error)
    else:
        others, res = _synth_both(spec)
        if res is None:   # correctly rounded, or one other architecture asked
            return _other_wins(spec, others, None, {})
    if res.winner is None:   # the one-width search met nothing: the others compete
        files = {f"design_{spec.name}.csv": res.csv()} if res.points else {}
        if _best_other(others) is None:
            raise ValueError(_no_design(spec, res, others))
        return _other_wins(spec, others, res, files)
    files = {f"design_{spec.name}.csv": res.csv(), f"design_{spec.name}.png": res.plot_png()}
    synthesized = res.winner.target_cost is not None or res.winner.yosys_cells is not None
    best, timed = _best_other(others), None
    if spec.frequency is not None:   # every architecture pipelined: the cheapest at the clock
        timed = _time_all(spec, others, res)
        best = timed.candidate
        other_wins = best is not None
    else:
        other_wins = best is not None and (best.cost.score < _score(res.winner) or not synthesized)
    if other_wins:
        # the plot shows the one-width search: say that another architecture won
        score = best.cost.score if timed is None else timed.score
        files[f"design_{spec.name}.png"] = res.plot_png(
            winner="best one-width piecewise",
            note=f"winner: {best.architecture}, score {score:.1f} (not on this plot)")
        return _other_wins(spec, others, res, files, timed)
    d = _winner_design(res)
    # the winner's place and route may fail (too large for the device): before writing
    figures = _winner_figures(res, d) if res.winner.target_cost is not None and \
        spec.frequency is None else []
    if others:
        files[f"design_{spec.name}_architectures.csv"] = _architectures_csv(others, res, None)
    piped = None
    if spec.frequency is not None:  # pipelined at the ROM, multiply and add boundaries
        figures, piped = _pipelined(spec, d, timed)
    w = res.winner
    lines = [*res.explain(), *figures]
    for c in others:
        lines.append(f"  {c.line()}" + (_lost(spec) if c.cost is not None else ""))
    fit = ["chebnorm", "fit", spec.expr, "--var", spec.var, "--interval", *spec.interval,
           "--degree", w.degree, "--segments", w.segments, "--kind", "minimax",
           "--coef-frac-bits", w.coef_frac_bits, "-o", "T.json"]
    verilog = ["chebnorm", "hw", "verilog", "T.json", "--in-bits", spec.in_bits, "--out-bits",
               spec.out_bits, "--y-frac-bits", w.y_frac_bits, "-o", "DIR", "--simulate"]
    lines.append(f"reproduce: {_words(fit)} && {_words(verilog)}")
    winner = Winner("piecewise", w.describe(), d if piped is None else piped.design,
                    _score(w) if timed is None else timed.score, w.total_bound)
    # a pipelined one-width winner writes its clocked RTL (the reproduce line is combinational)
    hdl = "architecture" if piped is not None and piped.latency > 0 else ""
    return DesignResult(spec.name, spec.device, spec.accuracy, winner, tuple(others), res,
                        piped, (), tuple(lines), {"static": files, "command": spec.command()},
                        hdl, () if timed is None else timed.timings)


def _words(words) -> str:
    return " ".join(shlex.quote(str(w)) for w in words)


def _reproduce(spec: _Spec, best) -> str:
    """The command that rebuilds ``best`` (a candidate of another architecture than
    the one-width search) alone and simulates it over every input code."""
    degrees = (best.design.degree,) if best.architecture == "piecewise-sized" else spec.degrees
    return replace(spec, degrees=degrees, architecture=best.architecture, simulate=True,
                   lsb_stated=True).command()


def _search_failure(res) -> str:
    """The one-width search's failure, in one line."""
    if not res.points:
        return "no design: no polynomial's range fits the output format"
    best = min(res.points, key=lambda p: p.total_bound)
    return (f"no design meets max_error {res.max_error:.4g}: the smallest certified error "
            f"reached is {format_up(best.total_bound, '.4g')} (degree {best.degree}, "
            f"{best.segments} segments, {best.coef_frac_bits} coefficient bits)")


def _no_design(spec: _Spec, res, others) -> str:
    """Why no architecture meets the accuracy: each one's line."""
    why = ([] if res is None else [f"piecewise (one width): {_search_failure(res)}"]) + [
        c.line() for c in others]
    return (f"no architecture meets the accuracy asked at {spec.format_phrase()} ("
            + "; ".join(why) + "); accepted: a larger max_error, more max_segments, degrees, "
            "out_bits or a larger lsb" + (", or faithful=True / max_error=E instead of "
                                          "correctly_rounded=True"
                                          if spec.accuracy == "correctly-rounded" else ""))


def _simulate(spec: _Spec, d, lsb: int, what: str = "") -> str:
    """The winner ``d``'s Verilog simulated over every input code in Icarus Verilog
    against its bit-accurate model, and the model's error measured over every code
    against the rigorous reference of ``f`` (``what``: "mantissa " for the exponent
    index, whose error is its mantissa's, last place ``2^lsb``): one line
    (ValueError when either fails)."""
    from .pipeline import verify_pipelined

    sim = verify_pipelined(d)
    if not sim.passed:
        raise ValueError(f"internal: the Verilog of {d.module_name} disagrees with its "
                         f"bit-accurate model ({sim.line}); nothing written")
    m = d.measure()   # the tables' measure is the rigorous upper bound over every code
    err = float(m["max_error"] if "max_error" in m else m["upper"])
    ulp = 2.0 ** lsb
    if spec.accuracy == "max-error":
        ok = err <= spec.max_error
    else:
        ok = err < (ulp / 2 if spec.accuracy == "correctly-rounded" else ulp) or \
            spec.accuracy == "correctly-rounded" and err <= ulp / 2
    if not ok:
        raise ValueError(f"internal: {d.module_name} errs by {format_up(err, '.6g')} over the input codes, "
                         f"beyond its accuracy ({spec.accuracy}, LSB 2^{lsb}); nothing "
                         f"written")
    return (f"simulation (Icarus Verilog, every code): {sim.line}; measured max {what}|y - f| "
            f"{format_up(err, '.4e')} ({format_up(err / ulp, '.4f')} ulp of 2^{lsb})")


def _other_wins(spec: _Spec, others, res, files, timed=None) -> DesignResult:
    """Another architecture than the one-width search wins: its HDL beside the CSVs
    (``timed``: every architecture pipelined for the frequency, :func:`_time_all`)."""
    if spec.frequency is not None and timed is None and _best_other(others) is not None:
        timed = _time_all(spec, others, res)
    best = _best_other(others) if timed is None else timed.candidate
    if best is None:
        raise ValueError(_no_design(spec, res, others))
    files = dict(files)
    files[f"design_{spec.name}_architectures.csv"] = _architectures_csv(others, res, best)
    d = best.design
    figures, piped = [], None
    if spec.frequency is not None:
        figures, piped = _pipelined(spec, d, timed)
        d = piped.design
    if not figures and spec.device != "generic":  # may fail: before writing
        from .targets import target_figures

        fig = target_figures(best.verilog, d.module_name, spec.device, cost=best.cost,
                             latency=d.latency)
        figures = [f"winner {fig['line']}", f"timing: {fig['timing']}"]
    lines = [f"winner: {best.line()}", *figures]
    if res is not None and res.winner is None:
        lines.append(f"  piecewise (one width): {_search_failure(res)}")
    elif res is not None:
        w = res.winner
        why = (f"score {_score(w):.1f}, costlier than the winner" if w.target_cost is not None
               or w.yosys_cells is not None else "not synthesized: its model cannot beat the "
               "winner")
        if spec.frequency is not None:
            why = f"score {_score(w):.1f}" + _lost(spec)
        lines.append(f"  piecewise (one width): {w.describe()} -- {why}")
    for c in others:
        if c is not best:
            lines.append(f"  {c.line()}" + (_lost(spec) if c.cost is not None else ""))
    winner = Winner(best.architecture, best.description, d,
                    best.cost.score if timed is None else timed.score, best.error)
    lines.append(f"reproduce: {_reproduce(spec, best)}")
    return DesignResult(spec.name, spec.device, spec.accuracy, winner, tuple(others), res,
                        piped, (), tuple(lines), {"static": files, "command": spec.command()},
                        "architecture", () if timed is None else timed.timings)


@dataclass(frozen=True)
class _Timed:
    """Every architecture pipelined for the frequency (:func:`_time_all`)."""
    candidate: object     # the winning Candidate, None when the one-width design wins
    result: object        # its PipelineResult
    timings: tuple        # (architecture, description, PipelineResult) per architecture
    lines: tuple          # the report of every architecture at the frequency
    shortfall: str        # the warning when none reaches the frequency ("" else)
    score: float          # the winner's score at the clock (_placed_score)


def _time_all(spec: _Spec, others, res) -> _Timed:
    """Pipeline every architecture that meets the accuracy (the one-width search's
    winner and every built candidate) for the frequency on the device
    (:func:`~chebnorm.hw.pipeline.pipeline_to_frequency`): the winner is the
    cheapest pipelined design (its registers counted) among those reaching the
    frequency, else the fastest (the closest), lower score on a tie. An
    architecture the tools cannot time (e.g. too large for the device) is reported
    and left out."""
    from .pipeline import pipeline_to_frequency

    entries = [] if res is None or res.winner is None else [
        ("piecewise (one width)", res.winner.describe(), None, _winner_design(res))]
    for c in others:
        if c.design is not None and (spec.accuracy != "max-error" or c.error is None
                                     or c.error <= spec.max_error):
            entries.append((c.architecture, c.description, c, c.design))
    runs, failed = [], {}
    for i, (arch, desc, _, d) in enumerate(entries):
        try:
            runs.append(pipeline_to_frequency(d, spec.device, spec.frequency, warn=False))
        except ToolTimeout:   # the machine's speed, not the design's: never a changed winner
            raise
        except ValueError as exc:   # a tool's refusal: one line, the others still compete
            runs.append(None)
            failed[i] = str(exc).splitlines()[0][:200] if str(exc) else type(exc).__name__
    timed = [i for i, r in enumerate(runs) if r is not None]
    scores = {i: _placed_score(runs[i], spec.device) for i in timed}
    if not timed:
        raise ValueError(f"no architecture could be timed at {spec.frequency:g} MHz on "
                         f"{spec.device} ("
                         f"{'; '.join(f'{entries[i][0]}: {m}' for i, m in failed.items())}"
                         f"{'' if failed else 'none meets the accuracy'}); "
                         f"accepted: a smaller design (fewer in_bits) or another device")
    met = [i for i in timed if runs[i].met]
    if met:
        k = min(met, key=lambda i: (scores[i], runs[i].latency, i))
    else:
        k = max(timed, key=lambda i: (runs[i].fmax_mhz, -scores[i], -i))
    lines, short = _timing_lines(spec, entries, runs, k, failed, scores), ""
    if not met:
        r, arch = runs[k], entries[k][0]
        best = ", ".join(f"{entries[i][0]}: {runs[i].fmax_mhz:.2f}" for i in timed)
        short = (f"{spec.frequency:g} MHz not reached: the highest is {r.fmax_mhz:.2f} MHz at "
                 f"latency {r.latency}, by {arch}, the closest architecture (highest MHz per "
                 f"architecture: {best}; {r.source})")
    timings = tuple((entries[i][0], entries[i][1], runs[i], scores[i]) for i in timed)
    return _Timed(entries[k][2], runs[k], timings, tuple(lines), short, scores[k])


def _placed_score(run, device: str) -> float:
    """The score of the netlist ``run``'s Fmax was measured on. On ice40 nextpnr
    times the module between input and output registers (:func:`~.targets.fmax_ice40`),
    and yosys may fold those into a ROM's block RAM (a synchronous read): the
    module alone would be priced in LUTs and timed as block RAM, so the wrapped
    netlist is priced, its I/O registers counted (the same ones for every
    architecture of a spec). On xc7 the sta model times the module itself."""
    if device != "ice40":
        return float(run.cost.score)
    from .targets import WRAP, module_ports, register_wrapper, synthesize_target

    d = run.design
    text = d.verilog()
    wrapper = register_wrapper(d.module_name, module_ports(text, d.module_name),
                               clocked=run.latency > 0)
    return float(synthesize_target(text + "\n" + wrapper + "\n", WRAP, device).score)


def _timing_lines(spec: _Spec, entries, runs, k: int, failed: dict, scores: dict) -> list[str]:
    """The report of every architecture at the frequency (``k``: the winner's index;
    ``failed``: index -> why the tools could not time it; ``scores``: index -> the
    placed netlist's score, :func:`_placed_score`)."""
    f = spec.frequency
    placed = (" (ice40: the module between its input and output registers, as nextpnr "
              "placed it)" if spec.device == "ice40" else "")
    lines = [f"at {f:g} MHz on {spec.device}, every architecture pipelined (the cheapest "
             f"reaching {f:g} MHz wins, its registers counted; else the closest); score"
             f"{placed}:"]
    for i, ((arch, desc, _, _), r) in enumerate(zip(entries, runs)):
        if r is None:
            lines.append(f"  {arch}: {desc}: not timed ({failed[i]})")
            continue
        verdict = "reaches" if r.met else "does not reach"
        lines.append(f"  {arch}: {desc}: Fmax {r.fmax_mhz:.2f} MHz at latency {r.latency} "
                     f"({verdict} {f:g} MHz), score {scores[i]:.1f}, {r.extra_ffs} pipeline "
                     f"FFs" + (" -- the winner" if i == k else ""))
    return lines


def _lost(spec: _Spec) -> str:
    """Why a synthesized candidate lost, after its combinational line."""
    if spec.frequency is None:
        return " -- costlier than the winner"
    return f" -- combinational figures (pipelined for {spec.frequency:g} MHz: above)"


def _pipelined(spec: _Spec, d, timed=None):
    """Pipeline ``d`` to the frequency (:mod:`.pipeline`; ``timed``: already done for
    every architecture by :func:`_time_all`) and simulate the pipelined RTL over
    every code (Icarus Verilog; GHDL too for its VHDL): (figure lines, the
    :class:`~chebnorm.hw.pipeline.PipelineResult`). A shortfall is one
    :class:`~chebnorm.hw.pipeline.FrequencyWarning`."""
    from .pipeline import FrequencyWarning, cut_names, pipeline_to_frequency, verify_pipelined

    res = pipeline_to_frequency(d, spec.device, spec.frequency, warn=False) if timed is None \
        else timed.result
    p = res.design
    tried = [f"{st.latency}: {st.fmax_mhz:.2f}"
             + (f" (after {', '.join(cut_names(d, st.cuts))})" if st.cuts else "")
             for st in res.steps]
    lines = [f"timing: {res.line()}", f"measured (latency: Fmax MHz): {', '.join(tried)}"]
    if timed is not None:
        if spec.device == "ice40":
            lines.append(f"priced as timed (the module between its input and output registers, "
                         f"as nextpnr placed it): score {timed.score:.1f}")
        lines += timed.lines
    if res.latency > 0:
        sim = verify_pipelined(p)
        if not sim.passed:
            raise ValueError(f"internal: the pipelined RTL of {p.module_name} disagrees with the "
                             f"bit-accurate model ({sim.line}); nothing written")
        lines.append(f"cycle-accurate simulation (Icarus Verilog, every code): {sim.line}")
        vhdl = _verify_vhdl(p)
        if vhdl is not None:
            lines.append(f"cycle-accurate simulation (GHDL, every code): {vhdl}")
    if not res.met:
        warnings.warn(res.shortfall() if timed is None else timed.shortfall, FrequencyWarning,
                      stacklevel=4)
    return lines, res


def _verify_vhdl(d):
    """GHDL's verdict on the pipelined VHDL over every code (None without GHDL)."""
    import tempfile
    from pathlib import Path

    from chebnorm.core.tools import which

    if which("ghdl") is None:
        return None
    from .pipeline import design_files
    from .run_vhdl import simulate_vhdl

    with tempfile.TemporaryDirectory() as tmp:
        for fname, text in design_files(d, "vhdl").items():
            (Path(tmp) / fname).write_text(text, encoding="utf-8")
        res = simulate_vhdl(tmp, d)
    if not res.passed:
        raise ValueError(f"internal: the pipelined VHDL of {d.module_name} disagrees with the "
                         f"bit-accurate model ({res.line}); nothing written")
    return res.line


def _winner_design(res):
    """The one-width search's winning design."""
    return next(res.designs[k] for k, p in zip(sorted(res.designs), res.points)
                if p is res.winner)


def _winner_figures(res, d) -> list[str]:
    """The one-width winner's mapping and timing on the search's device."""
    from .targets import target_figures

    fig = target_figures(d.verilog(), d.module_name, res.target,
                         cost=res.winner.target_cost)
    return [f"winner {fig['line']}", f"timing: {fig['timing']}"]


def _search(spec: _Spec, max_error, synth=None, workers=None, strict=True):
    """The one-width piecewise Pareto search (:mod:`.piecewise_search`); ``synth``
    False for the model only; ``workers``: instead of the spec's; ``strict``:
    ValueError when no point meets ``max_error`` (else the result, winner None)."""
    from .piecewise_search import search

    parallel = spec.parallel() if workers is None else {"workers": workers, "scheduler": None}
    res = search(spec.expr, spec.interval, spec.in_bits, spec.out_bits, max_error,
                 degrees=spec.degrees, max_index_bits=spec.max_index_bits, var=spec.var,
                 synth=spec.synth if synth is None else synth, name=spec.name,
                 target=spec.device, out_frac_bits=spec.frac_bits, **parallel)
    if res.winner is None and not res.points:
        raise ValueError(f"no design meets max_error {max_error:.4g}: no polynomial's range "
                         f"fits {spec.format_phrase()}; accepted: more out_bits or a larger "
                         f"lsb")
    if res.winner is None and strict:  # one line, exit 2, nothing written (docs/cli.md)
        best = min(res.points, key=lambda p: p.total_bound)
        raise ValueError(f"no design meets max_error {max_error:.4g}: the smallest "
                         f"certified error reached is {format_up(best.total_bound, '.4g')} "
                         f"(degree {best.degree}, "
                         f"{best.segments} segments, {best.coef_frac_bits} coefficient bits); "
                         f"accepted: a larger max_error, or more max_segments, degrees "
                         f"or out_bits")
    return res


def _synth_both(spec: _Spec):
    """The other architectures and the one-width search, built and evaluated,
    then synthesized in one queue in order of their lower bounds, each skipped
    once it cannot beat the best score so far
    (:func:`~chebnorm.hw.architectures.synthesize_with_search`).
    Returns ``(others, result)`` (``result`` None for a correctly rounded spec)."""
    from concurrent.futures import ThreadPoolExecutor

    from chebnorm.core.tools import which

    from .architectures import (build_candidates, cheapest_candidates, synthesize_candidates,
                                synthesize_with_search)

    degrees = sorted(set(spec.degrees))
    # the sized search starts where a one-width design of each degree first meets the
    # error (a cheap model-only walk); four index bits below it when unknown
    built = build_candidates(spec.expr, spec.interval, spec.in_bits, spec.out_bits,
                             accuracy=spec.accuracy, max_error=spec.max_error, degrees=degrees,
                             k_start={d: max(0, min(spec.in_bits - 2, 3 + 2 * (3 - d)))
                                      for d in degrees},
                             var=spec.var, name=spec.name, target=spec.device,
                             out_frac_bits=spec.frac_bits, **spec.parallel())
    built = [_meets(spec, c) for c in built
             if spec.architecture in (None, c.architecture)]
    if spec.accuracy == "correctly-rounded" or which("yosys") is None or \
            spec.architecture not in (None, "piecewise"):
        # yosys missing: each candidate's error, one line
        others = cheapest_candidates(synthesize_candidates(built, spec.device,
                                                           **spec.parallel()))
        if spec.accuracy == "correctly-rounded" or spec.architecture is not None:
            return others, None
    max_error = spec.max_error
    if spec.accuracy == "faithful":  # the piecewise search's bound must stay below one ulp
        max_error = math.nextafter(2.0 ** spec.lsb, 0.0)
    # the search evaluates its points here, in one thread (no worker start-up to pay),
    # while yosys maps the first round of candidates; its points join from round two
    with ThreadPoolExecutor(max_workers=1) as pool:
        job = pool.submit(_search, spec, max_error, synth=False, workers=1, strict=False)
        try:
            others, res = synthesize_with_search(built, job, spec.device, **spec.parallel())
        finally:
            job.cancel()
    return cheapest_candidates(others), res


def _meets(spec: _Spec, c):
    """``c``, or unbuilt with a note when its certified error misses the accuracy
    (a plain table's half ulp above a ``max_error`` below it)."""
    from .architectures import Candidate

    if c.design is None or c.error is None or spec.accuracy != "max-error" or \
            c.error <= spec.max_error:
        return c
    return Candidate(c.architecture, c.description, note=f"certified error "
                     f"{format_up(c.error, '.4e')} > max_error {spec.max_error:.4e}")


def _score(point) -> float:
    """A search point's figure on its device (yosys cells on generic)."""
    if point.target_cost is not None:
        return point.target_cost.score
    return float(point.cost)


def _best_other(others):
    built = [c for c in others if c.design is not None and c.cost is not None]
    return min(built, key=lambda c: (c.cost.score, c.architecture)) if built else None


def _architectures_csv(others, res, winner) -> str:
    import csv as csvmod
    import io

    buf = io.StringIO()
    w = csvmod.writer(buf, lineterminator="\n")
    w.writerow(["architecture", "description", "score", "cells", "luts", "dsps", "carries",
                "brams", "error", "ulp", "lsb", "winner", "note"])
    if res is not None and res.winner is None:
        w.writerow(["piecewise", "no design", "", "", "", "", "", "", "", "", "", 0,
                    csv_cell(_search_failure(res))])
    elif res is not None:
        p = res.winner
        c = p.target_cost
        w.writerow(["piecewise", csv_cell(p.describe()), f"{_score(p):.1f}",
                    "" if c is None else c.cells, "" if c is None else c.luts,
                    "" if c is None else c.dsps, "" if c is None else c.carries,
                    "" if c is None else c.brams, f"{format_up(p.total_bound, '.6e')}",
                    f"{2.0 ** -p.y_frac_bits:.6e}", -p.y_frac_bits, int(winner is None), ""])
    for o in others:
        c = o.cost
        w.writerow([o.architecture, csv_cell(o.description),
                    "" if c is None else f"{c.score:.1f}", "" if c is None else c.cells,
                    "" if c is None else c.luts, "" if c is None else c.dsps,
                    "" if c is None else c.carries, "" if c is None else c.brams,
                    "" if o.error is None else f"{format_up(o.error, '.6e')}",
                    "" if o.ulp is None else f"{o.ulp:.6e}",
                    "" if o.ulp is None else round(math.log2(o.ulp)), int(o is winner),
                    csv_cell(o.note)])
    return buf.getvalue()


# --- index="exponent": 1/sqrt indexed by a leading-zero count ----------------------------

def _design_exponent(spec: _Spec) -> DesignResult:
    """One sized exponent-indexed ``1/sqrt`` per degree, priced on the device; the
    cheapest wins (:mod:`.exponent`)."""
    from .exponent import design_exponent
    from .targets import synthesize_target, target_figures

    if spec.accuracy == "correctly-rounded":
        raise ValueError("correctly_rounded=True: not available with index='exponent' (the "
                         "mantissa is faithful at best); accepted: faithful=True or "
                         "max_error=E")
    degrees = sorted(set(spec.degrees))
    bad = [d for d in degrees if not 1 <= d <= 3]
    if bad:
        raise ValueError(f"degrees {bad[0]}: accepted with index='exponent': 1, 2 or 3")
    mult = "full" if spec.device == "xc7" else "truncated"
    found, notes = [], []
    for degree in degrees:
        try:
            d = design_exponent(spec.expr, spec.interval, spec.in_bits, spec.out_bits,
                                degree=degree, max_error=spec.max_error, multipliers=mult,
                                name=spec.name, var=spec.var)
        except ValueError as exc:
            if degree == degrees[0] and len(degrees) == 1 or "max_error" not in str(exc):
                raise
            notes.append(f"degree {degree}: {exc}")
            continue
        cost = synthesize_target(d.verilog(), d.module_name, spec.device) if spec.synth \
            else None
        found.append((d, cost))
    if not found:
        raise ValueError("no degree meets the accuracy: " + "; ".join(notes)
                         + "; accepted: a larger max_error or more out_bits")

    def score(item):
        d, cost = item
        proxy = sum(d.core.rom_bits) << d.core.index_bits
        return (cost.score if cost is not None else proxy, d.degree)

    best = min(found, key=score)
    d, cost = best
    files = {f"design_{spec.name}_architectures.csv": _exponent_csv(found, best)}
    figures = []
    if cost is not None and spec.device != "generic":  # place and route may fail
        fig = target_figures(d.verilog(), d.module_name, spec.device, cost=cost,
                             latency=d.latency)
        figures = [f"winner {fig['line']}", f"timing: {fig['timing']}"]
    lines = [f"winner: {_exponent_line(d, cost)}", *figures]
    lines += [f"  {_exponent_line(*o)} -- costlier than the winner" for o in found
              if o is not best]
    lines += [f"  {note}" for note in notes]
    winner = Winner("exponent", _exponent_line(d, cost), d,
                    None if cost is None else cost.score, d.budget()["mantissa"])
    others = tuple(o for o in found if o is not best)
    return DesignResult(spec.name, spec.device, spec.accuracy, winner, others, None, None,
                        tuple(notes), tuple(lines), {"static": files, "command": spec.command()},
                        "exponent")


def _exponent_line(d, cost) -> str:
    b = d.budget()
    c = "not synthesized" if cost is None else cost.line()
    return (f"exponent: degree {d.degree}, {d.core.table.segment_count} segments on [1, 4) "
            f"({d.core.table.segment_count // 2} per binade), mantissa {d.mant_bits} bits + "
            f"shift {d.shift_bits} bits: {c}; certified mantissa error "
            f"{format_up(b['mantissa'], '.4e')} "
            f"({format_up(b['mantissa'] * 2.0 ** d.frac_bits, '.3f')} ulp), relative < "
            f"{format_up(b['relative'], '.4e')}")


def _exponent_csv(found, best) -> str:
    import csv as csvmod
    import io

    buf = io.StringIO()
    w = csvmod.writer(buf, lineterminator="\n")
    w.writerow(["architecture", "degree", "segments", "score", "cells", "luts", "dsps",
                "carries", "brams", "mantissa_error", "ulp", "winner"])
    for d, c in found:
        w.writerow(["exponent", d.degree, d.core.table.segment_count,
                    "" if c is None else f"{c.score:.1f}", "" if c is None else c.cells,
                    "" if c is None else c.luts, "" if c is None else c.dsps,
                    "" if c is None else c.carries, "" if c is None else c.brams,
                    format_up(d.budget()['mantissa'], '.6e'),
                    f"{math.ldexp(1.0, -d.frac_bits):.6e}",
                    int(d is best[0])])
    return buf.getvalue()
