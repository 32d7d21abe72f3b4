"""Design-space sweep: degree x coefficient bits x datapath bits -> measured
error (output LSBs, 8-bit shading levels) against area (Yosys cells), with a
Pareto plot and a deterministic CSV.

The shading error of a design is ``255 * max |y / f - 1|`` over every valid
input code: the largest change, in levels of an 8-bit output, of an
intensity ``I <= 1`` whose normal is scaled by ``y`` instead of ``f``.
"""

from __future__ import annotations

import io
from dataclasses import dataclass

from chebnorm.approx import fit_target, get_target
from chebnorm.core.parallel import check_scheduler, check_workers, map_ordered
from chebnorm.core.display import field_rows, summary_html, summary_repr
from chebnorm.core.numeric import format_down, format_up
from chebnorm.core.tools import which

from .budget import error_budget, measure
from .datapaths import horner_block
from .fixed import check_width
from .horner import MAX_FRAC_BITS, design_horner, max_coef_bits
from .hdl.verilog import verilog_module
from .run_verilog import synthesize_text

# an implementation module of chebnorm.hw: the API is what chebnorm.hw exports
__all__: list[str] = []

#: polynomial degrees a :func:`sweep` tries by default
DEFAULT_DEGREES = (1, 2, 3, 4)
#: coefficient fractional bits a :func:`sweep` tries by default
DEFAULT_COEF_BITS = (10, 14, 18)
#: accumulator fractional bits a :func:`sweep` tries by default (degree 2 and up)
DEFAULT_ACC_BITS = (14, 18)
#: the shading-error goal: half a level of an 8-bit intensity (``meets_half_level``, the dashed
#: line of the plot)
HALF_LEVEL = 0.5

COLUMNS = ("degree", "coef_bits", "acc_bits", "in_bits", "out_bits", "y_frac_bits",
           "max_error", "max_error_lsb", "budget", "budget_lsb", "shading_levels",
           "yosys_cells", "area_fa", "pareto", "meets_half_level")


@dataclass(frozen=True)
class SweepPoint:
    """One design of the sweep: its widths, its exhaustively measured error
    (``max_error``; in output LSBs, ``max_error_lsb``; in 8-bit shading
    levels, ``shading_levels``), its certified budget and its area (yosys
    cells when yosys ran, else the full-adder estimate ``area_fa``);
    ``pareto`` marks the designs no other beats on both error and area.

    Attributes
    ----------
    degree : int
        Polynomial degree, 1 to 4.
    coef_bits : int
        Fractional bits of the coefficients.
    acc_bits : int or None
        Fractional bits of the accumulators; None for degree 1 (no accumulator).
    in_bits, out_bits : int
        Input and output code widths.
    y_frac_bits : int
        Fractional bits of the output.
    max_error : float
        ``max |y - f|`` measured over every valid input code.
    max_error_lsb : float
        ``max_error`` in output LSBs.
    budget : float
        The certified bound of ``|y - f|`` (:class:`~chebnorm.hw.budget.ErrorBudget`).
    budget_lsb : float
        ``budget`` in output LSBs.
    shading_levels : float
        ``255 * max |y / f - 1|``: the worst change of an 8-bit intensity.
    yosys_cells : int or None
        Yosys's cell count; None when yosys did not run.
    area_fa : float
        The full-adder-equivalent area estimate (:class:`~chebnorm.hw.cost.Cost`).
    pareto : bool, default False
        True when no other point of the sweep has both less area and less error.

    Examples
    --------
    >>> s = sweep("dichotomy", degrees=(1,), coef_bits=(10,), in_bits=8, out_bits=8, synth=False,
    ...           workers=1, progress=False)
    >>> p = s.points[0]
    >>> p.degree, p.coef_bits, p.max_error <= p.budget, p.area == p.area_fa
    (1, 10, True, True)
    """

    degree: int
    coef_bits: int
    acc_bits: int | None
    in_bits: int
    out_bits: int
    y_frac_bits: int
    max_error: float
    max_error_lsb: float
    budget: float
    budget_lsb: float
    shading_levels: float
    yosys_cells: int | None
    area_fa: float
    pareto: bool = False

    def _summary(self) -> list[tuple[str, object]]:
        return [("degree", self.degree), ("coef_bits", self.coef_bits),
                ("acc_bits", self.acc_bits), ("max_error", self.max_error),
                ("budget", self.budget), ("area_fa", self.area_fa), ("pareto", self.pareto)]

    _display_rows = field_rows
    __repr__ = summary_repr
    _repr_html_ = summary_html

    @property
    def area(self) -> float:
        """Yosys cells when available, otherwise the FA estimate."""
        return float(self.yosys_cells) if self.yosys_cells is not None else self.area_fa

    @property
    def meets_half_level(self) -> bool:
        """True when the shading error is at most half an 8-bit level."""
        return self.shading_levels <= HALF_LEVEL

    def row(self) -> list[str]:
        """The CSV cells of this point, in the order of ``COLUMNS``."""
        # the measured maximum rounded down, the certified budget up (at the digits shown)
        return [str(self.degree), str(self.coef_bits),
                "" if self.acc_bits is None else str(self.acc_bits), str(self.in_bits),
                str(self.out_bits), str(self.y_frac_bits), format_down(self.max_error, ".6e"),
                format_down(self.max_error_lsb, ".4f"), format_up(self.budget, ".6e"),
                format_up(self.budget_lsb, ".4f"),
                f"{format_down(self.shading_levels, '.6f')}",
                "" if self.yosys_cells is None else str(self.yosys_cells),
                f"{self.area_fa:.1f}", str(int(self.pareto)), str(int(self.meets_half_level))]


@dataclass(frozen=True)
class SweepResult:
    """All points of a sweep of one target (see :func:`sweep`), with
    ``area_source`` saying whether areas are yosys cells or estimates.

    Attributes
    ----------
    target : str
        The target swept (a name of :func:`chebnorm.approx.targets.get_target`).
    points : tuple of SweepPoint
        Every design, sorted by degree, coefficient bits, accumulator bits.
    area_source : {"yosys", "estimate"}
        Whether ``area`` is yosys's cell count or the full-adder estimate.

    Examples
    --------
    >>> s = sweep("dichotomy", degrees=(1, 2), coef_bits=(10, 14), acc_bits=(14,), in_bits=8,
    ...           out_bits=8, synth=False, workers=1, progress=False)
    >>> len(s.points), s.area_source, s.csv().splitlines()[0].split(",")[:3]
    (4, 'estimate', ['degree', 'coef_bits', 'acc_bits'])
    """

    target: str
    points: tuple[SweepPoint, ...]
    area_source: str

    def _summary(self) -> list[tuple[str, object]]:
        return [("target", self.target), ("points", len(self.points)),
                ("pareto", sum(p.pareto for p in self.points)),
                ("area_source", self.area_source)]

    _display_rows = field_rows
    __repr__ = summary_repr
    _repr_html_ = summary_html

    @property
    def cheapest(self) -> SweepPoint | None:
        """The smallest-area design whose shading error is at most half a level."""
        ok = [p for p in self.points if p.meets_half_level]
        return min(ok, key=lambda p: (p.area, p.max_error, p.degree, p.coef_bits,
                                      p.acc_bits or 0)) if ok else None

    def csv(self) -> str:
        """The points as CSV text (a header line, then one row per point)."""
        out = io.StringIO()
        out.write(",".join(COLUMNS) + "\n")
        for p in self.points:
            out.write(",".join(p.row()) + "\n")
        return out.getvalue()

    def plot_png(self) -> bytes:
        """The Pareto plot (matplotlib, Agg), as PNG bytes."""
        return pareto_png(
            self.points, lambda p: p.area, lambda p: p.shading_levels,
            hline=(HALF_LEVEL, "half a level (8-bit)"),
            best=(self.cheapest, "cheapest under half a level"),
            xlabel="Yosys cells" if self.area_source == "yosys" else "area estimate (FA)",
            ylabel="max shading error (8-bit levels)", title=f"{self.target}: error against area")


def pareto_png(points, x, y, *, hline, best, xlabel: str, ylabel: str, title: str,
               xlog: bool = False, measured=None) -> bytes:
    """A design sweep's Pareto plot as PNG bytes (matplotlib, Agg, no
    timestamp): ``points`` (each with ``degree`` and ``pareto``) scattered by
    degree at ``(x(p), y(p))`` on a log ``y`` axis (and ``x`` with ``xlog``),
    the front as a step line, ``hline = (value, label)`` dashed and ``best =
    (point or None, label)`` circled.

    >>> from types import SimpleNamespace as P
    >>> pts = [P(degree=1, pareto=True, c=1.0, e=0.1), P(degree=2, pareto=False, c=2.0, e=0.2)]
    >>> png = pareto_png(pts, lambda p: p.c, lambda p: p.e, hline=(0.5, "limit"),
    ...                  best=(pts[0], "best"), xlabel="cost", ylabel="error", title="t")
    >>> png[1:4]
    b'PNG'

    Parameters
    ----------
    points : sequence
        The designs; each has ``degree`` (int) and ``pareto`` (bool) attributes.
    x, y : callable
        Point -> coordinate (``y`` must be > 0: log axis; ``x`` too with ``xlog``).
    hline : tuple of (float, str)
        A dashed horizontal line's value and legend label.
    best : tuple of (object or None, str)
        The point to circle (None: none) and its label.
    xlabel, ylabel, title : str
        Axis labels and the plot title.
    xlog : bool, default False
        Log scale on the ``x`` axis too.
    measured : callable, optional
        Point -> the cost a tool measured in ``x``'s unit (None where not
        synthesized): drawn as crosses beside the model's dots, each joined to
        its point.

    Returns
    -------
    bytes
        The PNG file's bytes, the same for the same input.
    """
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 4.5), dpi=120)
    for deg in sorted({p.degree for p in points}):
        pts = [p for p in points if p.degree == deg]
        ax.scatter([x(p) for p in pts], [y(p) for p in pts], s=18, label=f"degree {deg}")
    front = sorted((p for p in points if p.pareto), key=x)
    ax.step([x(p) for p in front], [y(p) for p in front], where="post",
            color="k", lw=1, label="Pareto front")
    ax.axhline(hline[0], color="r", ls="--", lw=1, label=hline[1])
    if measured is not None:
        got = [(x(p), measured(p), y(p)) for p in points if measured(p) is not None]
        if got:
            for xm, xs, yv in got:
                ax.plot([xm, xs], [yv, yv], color="0.6", lw=0.6)
            ax.scatter([g[1] for g in got], [g[2] for g in got], marker="x", s=30, color="k",
                       label="synthesized (measured)")
    if best[0] is not None:
        ax.scatter([x(best[0])], [y(best[0])], s=90, facecolors="none", edgecolors="r",
                   label=best[1])
    if xlog:
        ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.set_title(title)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    buf = io.BytesIO()
    fig.savefig(buf, format="png", metadata={"Software": None})
    plt.close(fig)
    return buf.getvalue()


def _validate_list(values, name, lo, hi) -> tuple[int, ...]:
    vals = tuple(sorted({check_width(v, name, lo, hi) for v in values}))
    if not vals:
        raise ValueError(f"{name} list is empty; accepted: one or more values in {lo}..{hi}")
    return vals


def _design_point(item) -> SweepPoint:
    """One design of the grid: built, measured over every input code, synthesized
    (run by :func:`map_ordered` on a worker)."""
    target, table, d, c, a, in_bits, out_bits, rounding, use_yosys = item
    design = design_horner(table, in_bits, out_bits, coef_bits=c, acc_bits=a,
                           rounding=rounding, name=f"{target}_d{d}_c{c}_a{a or 0}")
    b, m = error_budget(design), measure(design)
    cells = synthesize_text(verilog_module(design), design.module_name).cells if use_yosys \
        else None
    return SweepPoint(degree=d, coef_bits=c, acc_bits=a, in_bits=in_bits, out_bits=out_bits,
                      y_frac_bits=design.y_format.frac_bits, max_error=m.total,
                      max_error_lsb=m.total_lsb, budget=b.total, budget_lsb=b.total / b.y_lsb,
                      shading_levels=m.shading_levels, yosys_cells=cells,
                      area_fa=horner_block(design).cost.area)


def sweep(target: str = "dichotomy", *, degrees=DEFAULT_DEGREES, coef_bits=DEFAULT_COEF_BITS,
          acc_bits=DEFAULT_ACC_BITS, in_bits: int = 12, out_bits: int = 12,
          rounding: str = "rne", psi_max="pi/4", synth: bool = True, workers: int | None = None,
          scheduler=None, progress: bool = True) -> SweepResult:
    """Evaluate every design of the grid exhaustively and (with yosys) synthesize it.

    Degree-1 designs have no intermediate accumulator, so ``acc_bits`` does
    not apply to them (one point per coefficient width).  The designs run on
    ``workers`` local processes (default: the core count) or on a Dask
    ``scheduler`` (:func:`chebnorm.core.parallel.map_ordered`); the result is
    the same whatever runs it.

    Parameters
    ----------
    target : str, default "dichotomy"
        A registered target name (:func:`chebnorm.approx.targets.get_target`).
    degrees : iterable of int, default DEFAULT_DEGREES
        Degrees to fit, each 1 to 4.
    coef_bits : iterable of int, default DEFAULT_COEF_BITS
        Coefficient fractional bits, each 1 to the largest every table's int32
        coefficients allow (:func:`~chebnorm.hw.horner.max_coef_bits`, at most 40).
    acc_bits : iterable of int, default DEFAULT_ACC_BITS
        Accumulator fractional bits, each 1 to 60 (degree 2 and up only).
    in_bits, out_bits : int, default 12
        Input (1 to 20) and output (1 to 32) code widths.
    rounding : {"rne", "trunc"}, default "rne"
        Rounding of every datapath step.
    psi_max : str or float, default "pi/4"
        The target's angle bound (passed to :func:`chebnorm.approx.fit_target`).
    synth : bool, default True
        Run yosys for the cell count when it is installed.
    workers : int or None, default None
        Local worker processes, ``>= 1``; None: the core count.
    scheduler : object or None, default None
        A Dask scheduler (address or client) to run on instead of local processes.
    progress : bool, default True
        Show a progress bar on stderr.

    Returns
    -------
    SweepResult
        Every point with its Pareto mark.

    Raises
    ------
    ValueError
        If the target is unknown or a width, degree, worker count or scheduler is out of
        its range.

    See Also
    --------
    chebnorm.hw.horner.design_horner : one design of the grid.
    chebnorm.hw.piecewise_search.search : the ``chebnorm design`` search of piecewise evaluators.

    Notes
    -----
    A point :math:`p` is on the Pareto front when no other point :math:`q`
    has both :math:`\\mathrm{area}(q) \\le \\mathrm{area}(p)` and
    :math:`\\mathrm{levels}(q) \\le \\mathrm{levels}(p)` with one of the two
    strict, ``levels`` being the measured error in 8-bit shading levels
    (:attr:`SweepPoint.shading_levels`) and ``area`` Yosys' cells, or the
    full-adder estimate without Yosys.

    Examples
    --------
    >>> s = sweep("dichotomy", degrees=(1, 2), coef_bits=(10, 14), acc_bits=(14,), in_bits=8,
    ...           out_bits=8, synth=False, workers=1, progress=False)
    >>> all(p.max_error <= p.budget for p in s.points), any(p.pareto for p in s.points)
    (True, True)
    """
    get_target(target)
    workers = check_workers(workers)
    check_scheduler(scheduler)
    degrees = _validate_list(degrees, "degree", 1, 4)
    coef_bits = _validate_list(coef_bits, "coef_bits", 1, MAX_FRAC_BITS)
    acc_bits = _validate_list(acc_bits, "acc_bits", 1, MAX_FRAC_BITS + 20)
    tables = {d: fit_target(target, d, psi_max=psi_max) for d in degrees}
    # quantize keeps int32 coefficients: the real limit depends on the tables
    coef_bits = _validate_list(coef_bits, "coef_bits", 1,
                               min(max_coef_bits(t) for t in tables.values()))
    grid = [(d, c, a if d >= 2 else None) for d in degrees for c in coef_bits
            for a in (acc_bits if d >= 2 else (None,))]
    use_yosys = synth and which("yosys") is not None
    items = [(target, tables[d], d, c, a, in_bits, out_bits, rounding, use_yosys)
             for d, c, a in grid]
    points = map_ordered(_design_point, items, workers=workers, scheduler=scheduler,
                         progress=progress, desc=f"sweep {target}")
    # Pareto front: no other point is at most as large and at most as wrong, one strictly
    marked = []
    for p in points:
        dominated = any((q.area <= p.area and q.shading_levels <= p.shading_levels)
                        and (q.area < p.area or q.shading_levels < p.shading_levels)
                        for q in points)
        marked.append(SweepPoint(**{**p.__dict__, "pareto": not dominated}))
    marked.sort(key=lambda p: (p.degree, p.coef_bits, p.acc_bits or 0))
    return SweepResult(target=target, points=tuple(marked),
                       area_source="yosys" if use_yosys else "estimate")
