"""Design search over piecewise hardware: segments x degree x coefficient bits.

FloPoCo chooses a piecewise evaluator's parameters automatically; this does
the same, certified and explained. For each degree ``d`` the search walks
the segment count ``2**k`` up from 1; at each ``(k, d)`` it fits the table
with generous coefficient bits (``F_hi``) and sizes the hardware
(:func:`chebnorm.hw.piecewise.design_piecewise`): the total certified bound
(approximation + Horner rounding + output rounding) says whether the maximum
error ``E`` is met. At the first ``k`` that meets it (and at ``k + 1``, whose
smaller coefficients may need fewer bits) the coefficient bits are lowered
while ``E`` still holds. Every evaluated point becomes a CSV row; the cost is
first the model estimate (:func:`model_cost`), and Yosys counts cells only on
the Pareto front's points that meet ``E`` (so the search stays bounded: at
most ``len(degrees) * (max_index_bits + 1) + 2 * len(degrees) * 16`` fits).

With ``target`` other than ``"generic"`` (:mod:`chebnorm.hw.targets`) every
point is priced by that target's calibrated model
(:func:`chebnorm.hw.target_model.model_score`), the Pareto front is taken over
(model score, bound), and its meeting points are synthesized on the target
(``synth_xilinx``, ``synth_ice40``), cheapest model first, two at a time --
except those whose model score over
:data:`~chebnorm.hw.target_model.MODEL_SPREAD` (a lower bound of their yosys
score: the model is within that ratio of yosys) is not below the best score
synthesized so far, or a ``bound`` the caller got elsewhere: they cannot
win. The winner is the lowest target score. (On ``generic`` the same pruning
reads the target model's yosys-cell prediction.)

>>> r = search("1/sqrt(x)", ("1", "4"), 10, 10, 2e-3, degrees=(1, 2), synth=False,
...            progress=False, workers=1)
>>> w = r.winner
>>> (w.degree, w.segments, w.total_bound <= 2e-3)
(1, 32, True)
"""

from __future__ import annotations

import io
import math
import threading
from dataclasses import dataclass, replace

from chebnorm.core.parallel import check_scheduler, check_workers, map_ordered
from chebnorm.approx.piecewise_table import MAX_COEF_FRAC_BITS, MAX_PIECEWISE_DEGREE
from chebnorm.approx.piecewise_fit import piecewise_fit
from chebnorm.core.display import field_rows, summary_html, summary_repr
from chebnorm.core.textsafe import csv_cell
from chebnorm.core.numeric import format_up

from .fixed import check_width
from .piecewise import MAX_PW_IN_BITS, MAX_PW_OUT_BITS, PiecewiseDesign, design_piecewise
from .sweep import pareto_png
from .synth_loop import SynthJob, map_synth, pruned_synthesis
from .targets import TargetCost, get_target

# an implementation module of chebnorm.hw: the API is what chebnorm.hw exports
__all__: list[str] = []

#: the columns of the search's CSV (``design_NAME.csv``), in order
COLUMNS = ("degree", "segments", "coef_frac_bits", "acc_frac_bits", "y_frac_bits",
           "rom_bits", "approx_bound", "total_bound", "meets", "model_cost", "yosys_cells",
           "pareto", "winner")
#: the columns a non-generic ``target`` adds to the search CSV
TARGET_COLUMNS = ("target", "target_model", "target_score", "luts", "dsps", "carries", "ffs",
                  "brams")
#: Yosys cells per ROM bit, measured on the 256 x 55-bit ROM of the 1/sqrt example
ROM_CELLS_PER_BIT = 0.15
MAX_SYNTH = 6
#: a worker thread fits one table at a time: the certifier sets python-flint's global
#: precision, which threads of one process (a threaded Dask worker) would share
_FIT_LOCK = threading.Lock()


def model_cost(d: PiecewiseDesign) -> float:
    """Area estimate in Yosys-cell units: ROM bits x :data:`ROM_CELLS_PER_BIT`,
    plus ``a * b`` per ``a x b``-bit multiplier and the width of each adder.

    Parameters
    ----------
    d : PiecewiseDesign
        The design (:func:`chebnorm.hw.piecewise.design_piecewise`).

    Returns
    -------
    float
        ``segments * sum(rom_bits) * ROM_CELLS_PER_BIT`` plus, per Horner step,
        ``acc_bits * t_bits`` (the multiplier) and the step's sum width.

    Examples
    --------
    >>> from chebnorm.approx.piecewise_fit import piecewise_fit
    >>> t = piecewise_fit("1/sqrt(x)", ("1", "4"), 1, segments=2, coef_frac_bits=12)
    >>> round(model_cost(design_piecewise(t, 8, 8)))
    136
    """
    rom = d.table.segment_count * sum(d.rom_bits) * ROM_CELLS_PER_BIT
    n = d.degree
    total, acc_w = rom, d.rom_bits[n] if n > 0 else 0
    for i, (_pw, sw, ow) in enumerate(d.widths):
        total += acc_w * d.t_bits + sw
        acc_w = ow
    return float(total)


@dataclass(frozen=True)
class DesignPoint:
    """One candidate of the design search: a uniform piecewise table's degree,
    segment count and widths, its certified error (approximation and total,
    rounding included), whether it meets the requested error, and its cost
    (yosys cells when synthesized, else the model's estimate).

    Attributes
    ----------
    degree : int
        The polynomial degree per segment, 0..8.
    segments : int
        The segment count ``2**k``.
    coef_frac_bits : int
        Fraction bits of the fitted coefficients, 0..48.
    acc_frac_bits : int
        Fraction bits of the Horner accumulator.
    y_frac_bits : int
        Fraction bits of the output.
    rom_bits : int
        The coefficient ROM's size in bits.
    approx_bound : float
        The certified approximation error (coefficients as quantized).
    total_bound : float
        The certified total error: approximation, Horner rounding and output
        rounding.
    meets : bool
        ``total_bound <= max_error``.
    model_cost : float
        The area estimate in Yosys cells (:func:`model_cost`).
    yosys_cells : int or None, default None
        Yosys' cell count, when synthesized on ``generic``.
    pareto : bool, default False
        On the Pareto front of (cost, ``total_bound``).
    target_model : float or None, default None
        The target's model score (:func:`chebnorm.hw.target_model.model_score`;
        a non-generic target only).
    target_cost : TargetCost or None, default None
        Yosys on the target, when synthesized (a non-generic target only).
    """

    degree: int
    segments: int
    coef_frac_bits: int
    acc_frac_bits: int
    y_frac_bits: int
    rom_bits: int
    approx_bound: float
    total_bound: float
    meets: bool
    model_cost: float
    yosys_cells: int | None = None
    pareto: bool = False
    target_model: float | None = None   # the target's model score (non-generic target)
    target_cost: TargetCost | None = None   # yosys on the target (non-generic target)

    def _summary(self) -> list[tuple[str, object]]:
        return [("degree", self.degree), ("segments", self.segments),
                ("coef_frac_bits", self.coef_frac_bits), ("total_bound", self.total_bound),
                ("meets", self.meets), ("cost", self.cost)]

    _display_rows = field_rows
    __repr__ = summary_repr
    _repr_html_ = summary_html

    @property
    def cost(self) -> float:
        if self.target_model is not None:
            return self.target_cost.score if self.target_cost is not None else self.target_model
        return float(self.yosys_cells) if self.yosys_cells is not None else self.model_cost

    def describe(self) -> str:
        cells = (f"{self.yosys_cells} yosys cells" if self.yosys_cells is not None
                 else f"~{self.model_cost:.0f} cells (model)")
        if self.target_cost is not None:
            cells = self.target_cost.line()
        elif self.target_model is not None:
            cells = f"~{self.target_model:.0f} LUT equivalents (model)"
        return (f"degree {self.degree}, {self.segments} segments, {self.coef_frac_bits} "
                f"coefficient bits (ROM {self.rom_bits} bits): {cells}, certified error "
                f"<= {format_up(self.total_bound, '.4e')}")


@dataclass(frozen=True)
class SearchResult:
    """What ``chebnorm design`` found: every candidate evaluated (``points``),
    the cheapest one that meets ``max_error`` (``winner``, or None), and where
    the costs came from (``cost_source``: yosys or the model); ``csv()`` gives
    the Pareto table that the command writes.

    Attributes
    ----------
    expression : str
        The function searched, as text.
    interval : tuple of (str, str)
        ``(a, b)`` as text.
    in_bits, out_bits : int
        Input and output widths in bits.
    max_error : float
        The requested bound ``E`` (for :func:`grid` without one: the largest
        total bound of the points).
    points : tuple of DesignPoint
        Every point evaluated, sorted by ``(degree, k, coef_frac_bits)``.
    winner : DesignPoint or None
        The cheapest point meeting ``max_error`` (None: none meets it).
    cost_source : str
        ``"model estimate"``, ``"yosys cells"`` or ``"yosys synth_..."`` (the
        target's synthesis command).
    designs : dict
        ``(degree, k, coef_frac_bits)`` to the point's
        :class:`~chebnorm.hw.piecewise.PiecewiseDesign`.
    target : str, default "generic"
        The canonical target name.
    """

    expression: str
    interval: tuple[str, str]
    in_bits: int
    out_bits: int
    max_error: float
    points: tuple[DesignPoint, ...]
    winner: DesignPoint | None
    cost_source: str
    designs: dict
    target: str = "generic"

    def _summary(self) -> list[tuple[str, object]]:
        w = self.winner
        return [("expression", self.expression), ("target", self.target),
                ("max_error", self.max_error), ("points", len(self.points)),
                ("winner", None if w is None else
                 f"degree {w.degree}, {w.segments} segments, {w.coef_frac_bits} bits"),
                ("cost_source", self.cost_source)]

    def _display_rows(self) -> list[tuple[str, object]]:
        return self._summary() + [("interval", self.interval), ("in_bits", self.in_bits),
                                  ("out_bits", self.out_bits),
                                  ("designs", f"{len(self.designs)} piecewise designs"),
                                  ("winner (full)", self.winner)]

    __repr__ = summary_repr
    _repr_html_ = summary_html

    def csv(self) -> str:
        """The CSV of every point (:data:`COLUMNS`; a non-generic target adds
        :data:`TARGET_COLUMNS`)."""
        out = io.StringIO()
        extra = self.target != "generic"
        out.write(",".join(COLUMNS + (TARGET_COLUMNS if extra else ())) + "\n")
        for p in self.points:
            row = [p.degree, p.segments, p.coef_frac_bits, p.acc_frac_bits, p.y_frac_bits,
                   p.rom_bits, format_up(p.approx_bound, '.6e'),
                   format_up(p.total_bound, '.6e'), int(p.meets),
                   f"{p.model_cost:.1f}", "" if p.yosys_cells is None else p.yosys_cells,
                   int(p.pareto), int(p is self.winner)]
            if extra:
                c = p.target_cost
                row += [self.target, f"{p.target_model:.1f}"] + (
                    ["", "", "", "", "", ""] if c is None else
                    [f"{c.score:.1f}", c.luts, c.dsps, c.carries, c.ffs, c.brams])
            out.write(",".join(csv_cell(str(v)) for v in row) + "\n")
        return out.getvalue()

    def explain(self) -> list[str]:
        """Why the winner wins: its cost and bound, and the best alternative per degree."""
        if self.winner is None:
            return [f"no design meets max error {self.max_error:.4e}; closest: "
                    + min(self.points, key=lambda p: p.total_bound).describe()]
        w = self.winner
        lines = [f"winner: {w.describe()} <= max error {self.max_error:.4e} "
                 f"(cost by {self.cost_source})"]
        for deg in sorted({p.degree for p in self.points}):
            ok = [p for p in self.points if p.degree == deg and p.meets]
            if not ok:
                best = min((p for p in self.points if p.degree == deg),
                           key=lambda p: p.total_bound)
                lines.append(f"  degree {deg}: no design meets the bound up to {best.segments} "
                             f"segments (best {format_up(best.total_bound, '.4e')})")
                continue
            b = min(ok, key=lambda p: (p.cost, p.total_bound))
            if b is w:
                continue
            # compare like with like: yosys cells when both were synthesized, else the model
            if self.target != "generic":
                both = b.target_cost is not None and w.target_cost is not None
                diff = (b.target_cost.score - w.target_cost.score if both
                        else b.target_model - w.target_model)
                unit = f"{self.target} {'score' if both else 'model score'}"
            elif b.yosys_cells is not None and w.yosys_cells is not None:
                diff, unit = b.yosys_cells - w.yosys_cells, "yosys cells"
            else:
                diff, unit = b.model_cost - w.model_cost, "model cells"
            lines.append(f"  degree {deg}: best is {b.describe()} -- costlier by "
                         f"{diff:.0f} {unit}: ROM {b.rom_bits} vs {w.rom_bits} bits, "
                         f"{b.degree} vs {w.degree} multiply-adds")
        return lines

    def plot_png(self, winner: str = "winner", note: str | None = None) -> bytes:
        """The Pareto plot of the search (cost against certified error), as PNG bytes:
        the model's cost of every point, and what synthesis measured where it ran.

        Parameters
        ----------
        winner : str, optional
            The label of the circled point (``"best one-width design"`` when
            another architecture won).
        note : str, optional
            A second title line (which design won, when it is not on this plot).

        Returns
        -------
        bytes
            The PNG file.
        """
        generic = self.target == "generic"
        if generic:
            measured = lambda p: None if p.yosys_cells is None else float(p.yosys_cells)  # noqa: E731
        else:
            measured = lambda p: None if p.target_cost is None else p.target_cost.score  # noqa: E731
        title = f"piecewise designs, {self.in_bits}-bit in / {self.out_bits}-bit out"
        return pareto_png(
            self.points, (lambda p: p.model_cost) if generic else (lambda p: p.target_model),
            lambda p: p.total_bound,
            hline=(self.max_error, "max error"), best=(self.winner, winner),
            xlabel="cost: model (dots), Yosys cells (crosses)" if generic else
            f"{self.target} score, LUT equivalents: model (dots), synthesized (crosses)",
            ylabel="certified max |y - f(x)|",
            title=title if note is None else f"{title}\n{note}", xlog=True, measured=measured)


def _point(d: PiecewiseDesign) -> DesignPoint:
    b = d.budget()
    return DesignPoint(d.degree, d.table.segment_count, d.table.coef_frac_bits,
                       d.acc_frac_bits, d.y_format.frac_bits,
                       d.table.segment_count * sum(d.rom_bits), d.table.abs_error_bound,
                       b["total"], False, model_cost(d))


def _evaluate_chain(item) -> list:
    """One degree of :func:`search` (run by ``map_ordered`` on a worker): walk the
    segment count ``2**k`` up at ``F_hi`` coefficient bits until the bound is met,
    then lower the coefficient bits at the first meeting ``k`` and at ``k + 1``.
    Returns ``[(key, DesignPoint, PiecewiseDesign)]`` sorted by ``key = (d, k, f)``."""
    expr, interval, d, kmax, f_hi, in_bits, out_bits, max_error, var, name, out_frac = item
    designs: dict[tuple[int, int, int], PiecewiseDesign] = {}
    points: dict[tuple[int, int, int], DesignPoint] = {}
    unfit: set = set()

    def evaluate(k, f) -> bool:
        """Whether the point ``(d, k, f)`` meets ``max_error`` (False, and no point,
        when y's range does not fit the stated output format)."""
        key = (d, k, f)
        if key in unfit:
            return False
        if key not in designs:
            t = piecewise_fit(expr, interval, d, segments=2 ** k, coef_frac_bits=f, var=var,
                              name=name)
            try:
                designs[key] = design_piecewise(t, in_bits, out_bits, out_frac_bits=out_frac)
            except ValueError:
                if out_frac is None:
                    raise
                unfit.add(key)
                return False   # this polynomial's range overflows the stated format
            p = _point(designs[key])
            points[key] = replace(p, meets=p.total_bound <= max_error)
        return points[key].meets

    with _FIT_LOCK:
        first = next((k for k in range(kmax + 1) if evaluate(k, f_hi)), None)
        if first is not None:
            for k in (first, first + 1):
                if k > kmax:
                    continue
                for f in range(f_hi - 1, 0, -1):
                    if not evaluate(k, f):
                        break
                evaluate(k, f_hi)
    return [(key, points[key], designs[key]) for key in sorted(points)]


def _cells(design: PiecewiseDesign) -> int:
    """Yosys' cell count of one design (run by ``map_ordered`` on a worker)."""
    from .piecewise import piecewise_cells

    return piecewise_cells(design).cells


def _check_max_error(max_error) -> float:
    if isinstance(max_error, bool) or not isinstance(max_error, (int, float)) or \
            not math.isfinite(max_error) or max_error <= 0:
        raise ValueError(f"max_error {max_error!r} is not a positive number; accepted: E > 0")
    return float(max_error)


def search(expr, interval, in_bits: int, out_bits: int, max_error: float, *,
           degrees=(1, 2, 3), max_index_bits: int = 8, var: str = "x", synth: bool = True,
           progress: bool = True, name: str = "design", workers: int | None = None,
           scheduler=None, target: str = "generic", bound: float | None = None,
           out_frac_bits: int | None = None) -> SearchResult:
    """Cheapest certified piecewise design meeting ``max_error`` (module docstring);
    ``target`` (:func:`chebnorm.hw.targets.target_names`) prices the points by that
    target's model and synthesizes the front's meeting points on it.

    The front's meeting points are synthesized cheapest model first,
    :data:`~chebnorm.hw.synth_loop.SYNTH_ROUND` at a time; a point whose model lower bound (its
    :func:`~chebnorm.hw.target_model.model_score` over
    :data:`~chebnorm.hw.target_model.MODEL_SPREAD`) is not below the best
    score synthesized so far, or ``bound`` (a score synthesized elsewhere,
    e.g. another architecture's), is not synthesized: it cannot win
    (:func:`synthesize_search`). Without ``bound`` the cheapest point by the
    model is always synthesized; when ``bound`` rules out every point, none
    is, and the winner is the cheapest by the model (not synthesized).

    Each degree's walk is one parallel item, and so is each Yosys run: they run
    on ``workers`` local processes (default: the core count; 1: here) or on a
    Dask ``scheduler`` (:func:`chebnorm.core.parallel.map_ordered`). The
    candidates evaluated, and so the result and its CSV, do not depend on which.

    Parameters
    ----------
    expr : str or sympy.Expr
        The function ``f`` of ``var``.
    interval : tuple of (str or number)
        ``(a, b)``, the input range.
    in_bits : int
        Input width, 2..20 (:data:`~chebnorm.hw.piecewise.MAX_PW_IN_BITS`).
    out_bits : int
        Output width, 1..32 (:data:`~chebnorm.hw.piecewise.MAX_PW_OUT_BITS`).
    max_error : float
        The certified total error ``E`` to meet, finite and > 0.
    degrees : iterable of int, default (1, 2, 3)
        The degrees to search, each 0..8; not empty.
    max_index_bits : int, default 8
        The largest ``k`` (``2**k`` segments) walked, 0..min(12, in_bits - 1).
    var : str, default "x"
        The variable of ``expr``.
    synth : bool, default True
        Synthesize the front's meeting points with Yosys (when installed;
        else the model's costs stand).
    progress : bool, default True
        Show a progress bar.
    name : str, default "design"
        The tables' and modules' name.
    workers : int or None, default None
        Local worker processes (None: the core count; 1: in this process).
    scheduler : object, optional
        A Dask scheduler address or client (:func:`chebnorm.core.parallel.map_ordered`).
    target : str, default "generic"
        A target name (:func:`chebnorm.hw.targets.target_names`).
    bound : float, optional
        A score synthesized elsewhere: points that cannot beat it are not
        synthesized.
    out_frac_bits : int, optional
        Every design's output at this many fractional bits (last place
        ``2^-out_frac_bits``; -60..60, checked to fit ``out_bits``); a point
        whose range does not fit is left out. Default: each design the most
        that fit ``out_bits``.

    Returns
    -------
    SearchResult
        Every point evaluated, the winner (None when no point meets
        ``max_error``) and the designs.

    Raises
    ------
    ValueError
        A width, degree or ``max_index_bits`` out of its range, ``degrees``
        empty, ``max_error`` not a positive finite number, an unknown
        ``target`` or ``workers``/``scheduler`` refused, or a bad expression
        or interval (from the first fit).

    Examples
    --------
    >>> r = search("1/sqrt(x)", ("1", "4"), 8, 8, 1e-2, degrees=(1, 2), max_index_bits=4,
    ...            synth=False, progress=False, workers=1)
    >>> r.winner.degree, r.winner.segments, r.winner.total_bound <= 1e-2
    (1, 16, True)
    """
    in_bits = check_width(in_bits, "in_bits", 2, MAX_PW_IN_BITS)
    out_bits = check_width(out_bits, "out_bits", 1, MAX_PW_OUT_BITS)
    max_error = _check_max_error(max_error)
    degrees = tuple(sorted({check_width(d, "degree", 0, MAX_PIECEWISE_DEGREE) for d in degrees}))
    if not degrees:
        raise ValueError("degrees: empty; accepted: one or more of 0..8")
    target = get_target(target).name
    kmax = check_width(max_index_bits, "max_index_bits", 0, min(12, in_bits - 1))
    workers = check_workers(workers)
    check_scheduler(scheduler)
    f_hi = min(MAX_COEF_FRAC_BITS, max(4, math.ceil(-math.log2(max_error)) + 6))
    # the first fit reports a bad expression or interval as it is (one clear error), here
    with _FIT_LOCK:
        piecewise_fit(expr, interval, degrees[0], segments=1, coef_frac_bits=f_hi, var=var,
                      name=name)
    if out_frac_bits is not None:
        out_frac_bits = check_width(out_frac_bits, "out_frac_bits", -60, 60)
    items = [(expr, interval, d, kmax, f_hi, in_bits, out_bits, max_error, var, name,
              out_frac_bits) for d in degrees]
    par = dict(workers=workers, scheduler=scheduler, progress=progress)
    designs: dict[tuple[int, int, int], PiecewiseDesign] = {}
    points: dict[tuple[int, int, int], DesignPoint] = {}
    for chain in map_ordered(_evaluate_chain, items, desc="design search", **par):
        for key, p, des in chain:
            points[key], designs[key] = p, des
    keys = sorted(points)
    if target != "generic":
        from .target_model import model_score, piecewise_features

        for key in keys:
            points[key] = replace(points[key], target_model=model_score(
                piecewise_features(designs[key]), target))
        mc = lambda p: p.target_model  # noqa: E731
    else:
        mc = lambda p: p.model_cost  # noqa: E731
    # Pareto front over (model cost, total bound)
    front = set()
    for key in keys:
        p = points[key]
        dominated = any(mc(q) <= mc(p) and q.total_bound <= p.total_bound
                        and (mc(q), q.total_bound) != (mc(p), p.total_bound)
                        for q in points.values())
        if not dominated:
            front.add(key)
    for key in front:
        points[key] = replace(points[key], pareto=True)
    meeting = sorted((k for k in keys if points[k].meets), key=lambda k: mc(points[k]))
    winner = min((points[k] for k in meeting),
                 key=lambda p: (p.cost, p.total_bound, p.degree, p.segments), default=None)
    res = SearchResult(str(expr), tuple(str(v) for v in interval), in_bits, out_bits,
                       max_error, tuple(points[k] for k in keys), winner, "model estimate",
                       {k: designs[k] for k in keys}, target)
    if synth and meeting:
        from chebnorm.core.tools import which

        if which("yosys") is not None:
            res = synthesize_search(res, bound=bound, workers=workers, scheduler=scheduler,
                                    progress=progress)
    return res


def synthesize_search(result: SearchResult, *, bound: float | None = None,
                      workers: int | None = None, scheduler=None,
                      progress: bool = False) -> SearchResult:
    """Synthesize the meeting points of a model-only search's Pareto front on
    its target and choose the winner by synthesis (the last step of
    :func:`search` with ``synth=True``; separate so a caller can overlap the
    search with other synthesis runs and pass their best score as ``bound``).

    Points are synthesized cheapest model first, :data:`~chebnorm.hw.synth_loop.SYNTH_ROUND` at a
    time, skipping a point whose model lower bound (model score over
    :data:`~chebnorm.hw.target_model.MODEL_SPREAD`) is not below the best
    score so far or ``bound``. Without ``bound`` the cheapest point by the
    model is always synthesized; with it, when no point can beat ``bound``,
    none is (the winner is then the cheapest by the model, not synthesized:
    the architecture that set ``bound`` wins).

    Parameters
    ----------
    result : SearchResult
        A :func:`search` result with ``synth=False`` (its points carry the
        Pareto flags and, on an FPGA target, the model scores).
    bound : float, optional
        A score synthesized elsewhere.
    workers, scheduler, progress
        As in :func:`search`.

    Returns
    -------
    SearchResult
        ``result`` with the synthesized points' costs, the winner among the
        synthesized meeting points and ``cost_source`` naming yosys.

    Raises
    ------
    ValueError
        ``result`` is not a SearchResult, yosys fails, or ``workers`` /
        ``scheduler`` is refused.

    Examples
    --------
    >>> r = search("1/sqrt(x)", ("1", "4"), 8, 8, 1e-2, degrees=(1,), max_index_bits=4,
    ...            synth=False, progress=False, workers=1)
    >>> synthesize_search(r, bound=0.0).winner.yosys_cells is None   # nothing beats 0 cells
    True
    """
    if not isinstance(result, SearchResult):
        raise ValueError("result: not a SearchResult; accepted: search(..., synth=False)")
    target = get_target(result.target).name
    workers = check_workers(workers)
    check_scheduler(scheduler)
    keys = sorted(result.designs)
    points = dict(zip(keys, result.points))
    designs = dict(result.designs)
    chosen = [k for k, _ in synthesis_queue(result)]
    if not chosen:
        return result
    par = dict(workers=workers, scheduler=scheduler, progress=progress)
    _synth_pruned(points, designs, chosen, target, bound, par)
    return with_costs(result, {k: (points[k].target_cost if target != "generic" else
                                   points[k].yosys_cells) for k in chosen
                               if points[k].target_cost is not None
                               or points[k].yosys_cells is not None})


def synthesis_queue(result: SearchResult) -> list[tuple[tuple[int, int, int], float]]:
    """The points of a model-only search that synthesis may pick the winner
    from, with their lower bounds: the meeting points of the Pareto front
    (at most ``MAX_SYNTH``, cheapest model first; none on the front: the
    cheapest meeting point), each with its model score over
    :data:`~chebnorm.hw.target_model.MODEL_SPREAD` (a lower bound of its
    synthesized score).

    Parameters
    ----------
    result : SearchResult
        A :func:`search` result with ``synth=False``.

    Returns
    -------
    list of (tuple, float)
        ``((degree, k, coef_frac_bits), lower bound)`` per point, cheapest
        model first (empty when no point meets the error).

    Examples
    --------
    >>> r = search("1/sqrt(x)", ("1", "4"), 8, 8, 1e-2, degrees=(1,), max_index_bits=4,
    ...            synth=False, progress=False, workers=1)
    >>> [k for k, _ in synthesis_queue(r)][0][:2]   # degree 1, 16 segments
    (1, 4)
    """
    from .target_model import MODEL_SPREAD

    target = get_target(result.target).name
    keys = sorted(result.designs)
    points = dict(zip(keys, result.points))
    mc = (lambda p: p.target_model) if target != "generic" else (lambda p: p.model_cost)
    meeting = sorted((k for k in keys if points[k].meets), key=lambda k: (mc(points[k]), k))
    chosen = [k for k in meeting if points[k].pareto][:MAX_SYNTH] or meeting[:1]
    return [(k, mc(points[k]) / MODEL_SPREAD[target]) for k in chosen]


def synthesize_point(item):
    """Yosys on one search point (a :class:`~chebnorm.hw.piecewise.PiecewiseDesign`
    and a target name): generic cells (an int) on ``generic``, else the
    target's :class:`~chebnorm.hw.targets.TargetCost` with its delay model.

    Parameters
    ----------
    item : tuple
        ``(design, target)``.

    Returns
    -------
    int or TargetCost

    Raises
    ------
    ValueError
        Yosys is missing or fails.
    """
    design, target = item
    if get_target(target).name == "generic":
        return _cells(design)
    return _target_cost((design, target))


def with_costs(result: SearchResult, costs: dict) -> SearchResult:
    """``result`` with the synthesized ``costs`` of some of its points and the
    winner chosen among the synthesized meeting points (none synthesized:
    the cheapest meeting point by the model, not synthesized).

    Parameters
    ----------
    result : SearchResult
        A :func:`search` result with ``synth=False``.
    costs : dict
        ``(degree, k, coef_frac_bits)`` to :func:`synthesize_point`'s result.

    Returns
    -------
    SearchResult
        Costs set (``yosys_cells`` on generic, ``target_cost`` otherwise), the
        winner, ``cost_source`` naming yosys.

    Raises
    ------
    ValueError
        A key of ``costs`` is not a point of ``result``.

    Examples
    --------
    >>> r = search("1/sqrt(x)", ("1", "4"), 8, 8, 1e-2, degrees=(1,), max_index_bits=4,
    ...            synth=False, progress=False, workers=1)
    >>> k = synthesis_queue(r)[0][0]
    >>> with_costs(r, {k: 40}).winner.yosys_cells
    40
    """
    target = get_target(result.target).name
    keys = sorted(result.designs)
    points = dict(zip(keys, result.points))
    for k, c in costs.items():
        if k not in points:
            raise ValueError(f"costs: {k!r} is not a point of the search")
        points[k] = (replace(points[k], yosys_cells=int(c)) if target == "generic" else
                     replace(points[k], target_cost=c))
    ordered = tuple(points[k] for k in keys)
    mc = (lambda p: p.target_model) if target != "generic" else (lambda p: p.model_cost)
    meeting = sorted((k for k in keys if points[k].meets), key=lambda k: (mc(points[k]), k))
    if not meeting:
        return replace(result, points=ordered)
    pool = [p for p in ordered if p.meets and (p.yosys_cells is not None
                                               or p.target_cost is not None)]
    if not pool:   # a bound beat every point: the cheapest by the model, not synthesized
        pool = [points[meeting[0]]]
    winner = min(pool, key=lambda p: (p.cost, p.total_bound, p.degree, p.segments))
    cost_source = ("yosys cells" if target == "generic" else
                   f"yosys {get_target(target).synth.split(' -top')[0]}")
    return replace(result, points=ordered, winner=winner, cost_source=cost_source)


def _synth_pruned(points, designs, chosen, target, bound, par) -> int:
    """Synthesize the ``chosen`` keys in rounds of :data:`~chebnorm.hw.synth_loop.SYNTH_ROUND`, cheapest
    target model first, skipping those whose model lower bound cannot beat
    the best score so far (or ``bound``; the first key always runs); update
    ``points``. Returns the number synthesized."""
    from .target_model import MODEL_SPREAD, model_score

    spread = MODEL_SPREAD[target]
    model = {k: model_score(designs[k].features(), target) for k in chosen}
    jobs = [SynthJob((model[k], k), model[k] / spread, k) for k in chosen]

    def synthesize(batch):
        if target == "generic":
            return map_synth(_cells, [designs[j.key] for j in batch], desc="yosys", **par)
        return map_synth(_target_cost, [(designs[j.key], target) for j in batch],
                         desc=f"yosys {target}", **par)

    run = pruned_synthesis(jobs, synthesize, bound=bound, first=bound is None,
                           score=lambda j, c: float(c) if target == "generic" else c.score)
    for key, c in run.costs.items():
        points[key] = (replace(points[key], yosys_cells=c) if target == "generic" else
                       replace(points[key], target_cost=c))
    return len(run.costs)


def _target_cost(item) -> TargetCost:
    """Yosys's mapping of one design on a target, with its delay model (run by
    ``map_ordered`` on a worker)."""
    from .targets import synthesize_target

    design, target = item
    if get_target(target).timing == "sta":   # the sta model later, on the winner's netlist
        return synthesize_target(design.verilog(), design.module_name, target, netlist=True)
    return synthesize_target(design.verilog(), design.module_name, target, timing=True)


def _grid_point(item) -> tuple[DesignPoint, PiecewiseDesign]:
    """One point of :func:`grid`: fitted, certified, sized and, with ``synth``,
    synthesized (run by ``map_ordered`` on a worker). ``limit`` is the error to
    meet, or None for none."""
    expr, interval, (d, k, f), in_bits, out_bits, limit, var, name, synth = item
    with _FIT_LOCK:
        t = piecewise_fit(expr, interval, d, segments=2 ** k, coef_frac_bits=f, var=var,
                          name=name)
        des = design_piecewise(t, in_bits, out_bits)
    p = _point(des)
    p = replace(p, meets=limit is not None and p.total_bound <= limit)
    if synth:
        p = replace(p, yosys_cells=_cells(des))
    return p, des


def grid(expr, interval, in_bits: int, out_bits: int, *, index_bits=(0, 2, 4, 6, 8),
         degrees=(1, 2, 3), coef_frac_bits=(12, 16, 20), max_error: float | None = None,
         var: str = "x", synth: bool = False, progress: bool = True,
         name: str = "sweep", workers: int | None = None, scheduler=None) -> SearchResult:
    """Every ``(2**k segments, degree, coefficient bits)`` of the grid, fitted,
    certified and sized: the piecewise ``hw sweep`` (no search, no pruning).
    With ``synth`` Yosys counts the cells of every point. ``max_error``
    (optional) marks the points that meet it and picks the cheapest. Each
    point is one parallel item (``workers``, ``scheduler``: as :func:`search`).

    Parameters
    ----------
    expr, interval, in_bits, out_bits
        As in :func:`search` (``in_bits`` 2..20, ``out_bits`` 1..32).
    index_bits : iterable of int, default (0, 2, 4, 6, 8)
        The ``k`` of the ``2**k`` segment counts, each 0..min(12, in_bits - 1).
    degrees : iterable of int, default (1, 2, 3)
        Degrees, each 0..8.
    coef_frac_bits : iterable of int, default (12, 16, 20)
        Coefficient fraction bits, each 0..48.
    max_error : float, optional
        A bound to mark the points that meet it (finite, > 0); None: every
        point meets.
    var : str, default "x"
        The variable of ``expr``.
    synth : bool, default False
        Count every point's cells with Yosys.
    progress : bool, default True
        Show a progress bar.
    name : str, default "sweep"
        The tables' and modules' name.
    workers, scheduler
        As in :func:`search`.

    Returns
    -------
    SearchResult
        Every grid point in ``(degree, k, coef_frac_bits)`` order, the Pareto
        front marked, and the cheapest meeting point as ``winner``.

    Raises
    ------
    ValueError
        A value out of its range, an empty list, ``max_error`` not a positive
        finite number, or a bad expression or interval.

    Examples
    --------
    >>> r = grid("1/sqrt(x)", ("1", "4"), 8, 8, index_bits=(1, 2), degrees=(1,),
    ...          coef_frac_bits=(10,), progress=False, workers=1)
    >>> [(p.segments, p.degree) for p in r.points]
    [(2, 1), (4, 1)]
    """
    in_bits = check_width(in_bits, "in_bits", 2, MAX_PW_IN_BITS)
    out_bits = check_width(out_bits, "out_bits", 1, MAX_PW_OUT_BITS)
    ks = sorted({check_width(k, "index bits k", 0, min(12, in_bits - 1)) for k in index_bits})
    ds = sorted({check_width(d, "degree", 0, MAX_PIECEWISE_DEGREE) for d in degrees})
    fs = sorted({check_width(f, "coef_frac_bits", 0, MAX_COEF_FRAC_BITS) for f in coef_frac_bits})
    if not ks or not ds or not fs:
        raise ValueError("empty sweep list; accepted: at least one segment count, degree and "
                         "coefficient width")
    limit = math.inf if max_error is None else _check_max_error(max_error)
    workers = check_workers(workers)
    check_scheduler(scheduler)
    keys = [(d, k, f) for d in ds for k in ks for f in fs]
    items = [(expr, interval, key, in_bits, out_bits, None if max_error is None else limit,
              var, name, synth) for key in keys]
    done = map_ordered(_grid_point, items, workers=workers, scheduler=scheduler,
                       progress=progress, desc="piecewise sweep")
    points = [p for p, _ in done]
    designs = {key: des for key, (_, des) in zip(keys, done)}
    front = [p for p in points if not any(
        q.cost <= p.cost and q.total_bound <= p.total_bound
        and (q.cost, q.total_bound) != (p.cost, p.total_bound) for q in points)]
    points = [replace(p, pareto=p in front) for p in points]
    ok = [p for p in points if p.meets]
    winner = min(ok, key=lambda p: (p.cost, p.total_bound)) if ok else None
    return SearchResult(str(expr), tuple(str(v) for v in interval), in_bits, out_bits,
                        limit if max_error is not None else max(p.total_bound for p in points),
                        tuple(points), winner, "yosys cells" if synth else "model estimate",
                        designs)
