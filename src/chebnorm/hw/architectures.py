"""The architectures ``chebnorm design`` chooses among, priced on one target.

Besides the one-width piecewise evaluator of :mod:`chebnorm.hw.piecewise_search`
(the Pareto search), three architectures compete for the same accuracy:

* ``piecewise-sized`` -- the piecewise ROM + Horner evaluator with a width per
  coefficient, ``t`` truncated per step and truncated products
  (:func:`chebnorm.hw.piecewise.design_piecewise` with ``widths="auto"``),
  certified per segment in exact interval arithmetic; multipliers
  ``truncated`` on LUT targets, ``full`` where a DSP takes them (xc7);
* ``multipartite`` -- a table-and-add evaluator with no multiplier
  (:func:`chebnorm.hw.multipartite.design_multipartite`), certified over every
  input code;
* ``table`` -- one ROM entry per input code, correctly rounded where proved
  (:func:`chebnorm.hw.plain_table.design_plain_table`); built only when its
  ROM is at most :data:`MAX_TABLE_ROM_BITS` bits (else it cannot win: it is
  reported with its ROM size).

Every candidate is synthesized on the target
(:func:`chebnorm.hw.targets.synthesize_target`) and the lowest score wins.
Accuracy is one of: ``max_error`` (certified ``<= E``), faithful (certified
``< 1`` unit of the output's last place) or correctly rounded (every code
equal to the proved rounding of ``f``: only a plain table is built for it,
the other architectures err by up to one unit and are reported as such).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from chebnorm.approx.piecewise_fit import piecewise_fit
from chebnorm.approx.piecewise_table import MAX_COEF_FRAC_BITS

from chebnorm.core.display import summary_html, summary_repr
from chebnorm.core.parallel import map_ordered
from chebnorm.core.numeric import check_int, format_down, format_up

from .design_base import Design
from .multipartite import design_multipartite
from .piecewise import design_piecewise
from .piecewise_search import SearchResult, synthesis_queue, synthesize_point, with_costs
from .plain_table import design_plain_table
from .synth_loop import SynthJob, map_synth, pruned_synthesis
from .targets import get_target, synthesize_target
from ._docfrag import hw_doc

# an implementation module of chebnorm.hw: the API is what chebnorm.hw exports
__all__: list[str] = []

#: the accuracy specs ``design`` takes
ACCURACIES = ("max-error", "faithful", "correctly-rounded")
#: a plain table larger than this many ROM bits is not built (2^16 codes x 18 bits is
#: 1.2 Mbit: 16k yosys cells, 7k LUT on xc7 -- it cannot win against a multipartite)
MAX_TABLE_ROM_BITS = 1 << 18
#: per (architecture, target): ``(logic, rom)``, the ratios by which a candidate's
#: synthesized score may fall below the two parts of its model score: pruning takes
#: ``(model - rom_part) / logic + rom_part / rom`` as the candidate's lower bound
#: (:func:`prune_lower`; ``python benchmarks/bench_design_targets.py --calibrate``)
PRUNE_SPREAD = {
    # every candidate the sized walk and the multipartite search built for 1/sqrt(1+3x)
    # at 10, 12 and 16 bits and sin(x) at 14 bits (faithful, x in [0, 1)), synthesized
    # (benchmarks/prune_calibration.json): the pair that keeps the lower bound under
    # yosys / 1.1 on every row (10 % headroom) with the largest mean bound; exp(x) at 14
    # bits, added after, moved no pair. Yosys maps the multipliers and adders close to
    # the model (logic 1.0-1.27; 1.6-2.2 on xc7-nodsp, where it shares LUTs between the
    # ROM's decoding and the multipliers) and compresses large ROMs of smooth data far
    # below it (a 1024-segment degree-1 ROM of sin: 1.8x on xc7)
    ("piecewise-sized", "generic"): (1.17, 2.1), ("multipartite", "generic"): (1.05, 1.6),
    ("piecewise-sized", "xc7"): (1.12, 4.8), ("multipartite", "xc7"): (1.0, 1.0),
    ("piecewise-sized", "xc7-nodsp"): (1.59, 4.3), ("multipartite", "xc7-nodsp"): (2.17, 1.3),
    ("piecewise-sized", "ice40"): (1.27, 1.9), ("multipartite", "ice40"): (1.0, 2.0),
    # a plain table's ROM compresses up to 4.5x in yosys (2^14 x 14 bits of sin: model
    # 3608 LUT on xc7 for 2247; 2^16 x 16 bits: model 115,867 cells, yosys 15,986): never
    # pruned
    ("table", "generic"): (math.inf, math.inf), ("table", "xc7"): (math.inf, math.inf),
    ("table", "xc7-nodsp"): (math.inf, math.inf), ("table", "ice40"): (math.inf, math.inf),
}


@dataclass(frozen=True)
class Candidate:
    """One architecture's best design for the spec, with its target figures.

    Attributes
    ----------
    architecture : str
        ``piecewise-sized``, ``multipartite`` or ``table``.
    description : str
        Its parameters in one line.
    design : Design or None
        The design (None when it was not built: see ``note``).
    error : float or None
        Its certified maximum error ``|y - f(x)|``.
    ulp : float or None
        One unit of its output's last place.
    cost : TargetCost or None
        Its synthesis on the target.
    note : str
        Why it was not built, cannot meet the spec or was not synthesized
        (empty otherwise).
    model : float or None
        Its score by the target's calibrated model
        (:func:`chebnorm.hw.target_model.model_score`).
    model_rom : float or None
        The ROM part of ``model`` (:func:`chebnorm.hw.target_model.model_parts`).

    Examples
    --------
    >>> Candidate("table", "2^24 entries", note="not built").line()
    'table: 2^24 entries -- not built'
    """

    architecture: str
    description: str
    design: Design | None = None
    error: float | None = None
    ulp: float | None = None
    cost: object = None
    note: str = ""
    model: float | None = None
    model_rom: float | None = None

    def _summary(self) -> list[tuple[str, object]]:
        return [("architecture", self.architecture), ("description", self.description),
                ("error", self.error), ("score", None if self.cost is None else self.cost.score),
                ("model", self.model), ("note", self.note)]

    def _display_rows(self) -> list[tuple[str, object]]:
        return self._summary() + [("ulp", self.ulp), ("model_rom", self.model_rom),
                                  ("cost", self.cost), ("design", type(self.design).__name__)]

    __repr__ = summary_repr
    _repr_html_ = summary_html

    @property
    def verilog(self) -> str:
        """The candidate's Verilog module (its top is ``design.module_name``)."""
        return self.design.verilog()

    def line(self) -> str:
        """One line: the architecture, its parameters, cost and error."""
        if self.design is None:
            return f"{self.architecture}: {self.description} -- {self.note}"
        cost = (self.cost.line() if self.cost is not None else
                f"not synthesized ({self.note})" if self.note else "not synthesized")
        return (f"{self.architecture}: {self.description}: {cost}; certified error "
                f"{format_up(self.error, '.4e')} ({format_up(self.error / self.ulp, '.3f')} ulp)")


def _sized_chain(item) -> list:
    """One degree of the sized search (run by ``map_ordered`` on a worker): the
    sized designs at ``2**k`` segments for ``k = k0 .. k0 + 3`` that meet the
    error, with their target model scores and ROM parts
    (``[(k, design, model, model_rom)]``). The walk ends early at a ``k`` whose
    lower bound (:func:`prune_lower`) still exceeds the best model score so far: a
    larger ROM no longer pays for itself (the model alone is too rough to stop
    at the first rise: on ``xc7-nodsp`` the cheapest degree-2 design has 256
    segments, after a rise at 128)."""
    from .target_model import model_parts

    expr, interval, in_bits, out_bits, degree, k0, max_error, var, name, target, fy = item
    mult = "full" if get_target(target).name == "xc7" else "truncated"
    f_hi = out_bits + 10 if max_error is None else math.ceil(-math.log2(max_error)) + 10
    found: list = []
    for k in range(k0, min(k0 + 3, in_bits - 2) + 1):
        t = piecewise_fit(expr, interval, degree, segments=2 ** k,
                          coef_frac_bits=min(f_hi, MAX_COEF_FRAC_BITS), centered=degree > 0,
                          var=var, name=name)
        try:
            d = design_piecewise(t, in_bits, out_bits, widths="auto", max_error=max_error,
                                 multipliers=mult, out_frac_bits=fy)
        except ValueError:  # not reachable at this segment count
            continue
        model, rom = model_parts(d.features(), target)
        if found and prune_lower("piecewise-sized", target, model, rom) > min(
                m for _, _, m, _ in found):
            break   # even at the model's spread, costlier than a smaller k
        found.append((k, d, model, rom))
    return found


def _build_item(item):
    """One parallel item of :func:`architecture_candidates`: a degree's sized
    chain, or the multipartite design."""
    if item[0] == "sized":
        return _sized_chain(item[1:])
    expr, interval, in_bits, out_bits, e, var, name, fy = item[1:]
    try:
        return design_multipartite(expr, interval, in_bits, out_bits, max_error=e,
                                   faithful=e is None, var=var, name=name, out_frac_bits=fy)
    except ValueError as exc:   # one line of the report: the other architectures compete
        return str(exc).splitlines()[0] if str(exc) else type(exc).__name__


def _synth_item(item):
    """Yosys on one candidate, with the target's delay model (the winner's
    timing line reads it: no second synthesis); on xc7 the mapped netlist
    instead, the sta model running on the winner's alone
    (:func:`chebnorm.hw.targets.sta_from_netlist`)."""
    verilog, top, target = item
    if get_target(target).timing == "sta":   # the sta model later, on the winner's netlist
        return synthesize_target(verilog, top, target, netlist=True)
    return synthesize_target(verilog, top, target, timing=True)


def _cheapest_per_degree(cands: list[Candidate]) -> list[Candidate]:
    """Per degree, the sized candidate of the lowest synthesized score (or, none
    synthesized, of the lowest model score)."""
    best: dict[int, tuple] = {}
    for c in cands:
        d = c.design
        key = (c.cost is None, c.cost.score if c.cost is not None else c.model, d.index_bits)
        old = best.get(d.degree)
        if old is None or key < old[0]:
            best[d.degree] = (key, c)
    return [best[k][1] for k in sorted(best)]


@hw_doc
def prune_spread(architecture: str, target: str) -> tuple[float, float]:
    """The ratios by which a candidate's synthesized score may fall below the
    logic and the ROM parts of its model score (:data:`PRUNE_SPREAD`; an
    architecture without its own measurement gets the target's
    :data:`~chebnorm.hw.target_model.MODEL_SPREAD` for both).

    Parameters
    ----------
    architecture : str
        ``"piecewise-sized"``, ``"multipartite"`` or ``"table"``; any other name
        has no measurement of its own.
    %(target)s

    Returns
    -------
    tuple of float
        ``(logic, rom)``, each at least 1 (``math.inf`` for a plain table:
        never pruned).

    Raises
    ------
    ValueError
        ``target`` is not a known target.

    Examples
    --------
    >>> prune_spread("piecewise-sized", "xc7")
    (1.12, 4.8)
    """
    from .target_model import MODEL_SPREAD

    t = get_target(target).name
    logic, rom = PRUNE_SPREAD.get((architecture, t), (MODEL_SPREAD[t], MODEL_SPREAD[t]))
    return max(1.0, logic), max(1.0, rom)


def prune_lower(architecture: str, target: str, model: float,
                model_rom: float | None = None) -> float:
    """A candidate's lower bound of its synthesized score, from its model score
    and the ROM part of it: ``(model - model_rom) / logic + model_rom / rom``
    with :func:`prune_spread`'s ratios.

    Parameters
    ----------
    architecture, target : str
        As in :func:`prune_spread`.
    model : float
        The candidate's model score (:func:`chebnorm.hw.target_model.model_score`).
    model_rom : float, optional
        Its ROM part (:func:`chebnorm.hw.target_model.model_parts`); None: the
        whole score divided by the larger ratio.

    Returns
    -------
    float
        The lower bound (0 for a plain table).

    Raises
    ------
    ValueError
        ``target`` is not a known target.

    Examples
    --------
    >>> round(prune_lower("piecewise-sized", "xc7", 600.0, 48.0), 2)   # 552 / 1.12 + 48 / 4.8
    502.86
    """
    logic, rom = prune_spread(architecture, target)
    if model_rom is None:
        return model / max(logic, rom)
    r = min(max(float(model_rom), 0.0), model)
    return (model - r) / logic + r / rom


@hw_doc
def synthesize_candidates(cands, target: str, *, bound: float | None = None,
                          prune: bool = True, workers: int | None = 1,
                          scheduler=None) -> list[Candidate]:
    """Synthesize the built candidates on ``target``, pruned by the model.

    Parameters
    ----------
    cands : list of Candidate
        As :func:`architecture_candidates` builds them (``model`` set).
    %(target)s
    bound : float, optional
        A score already synthesized elsewhere (the one-width search's winner):
        a candidate that cannot beat it is not synthesized.
    prune : bool
        False: synthesize every built candidate.
    workers, scheduler
        Parallel yosys runs (:func:`chebnorm.hw.piecewise_search.map_synth`).

    Returns
    -------
    list of Candidate
        In the order given; a candidate whose model lower bound
        :func:`prune_lower` is not below the best synthesized score
        (``bound`` or a candidate's) keeps ``cost`` None and says so in
        ``note``. Candidates are synthesized cheapest model first,
        :data:`~chebnorm.hw.synth_loop.SYNTH_ROUND` at a time (whatever
        ``workers``: the same ones are synthesized), so the best score found prunes the rest: a pruned candidate
        would have scored at least its lower bound, never less than the best.

    Examples
    --------
    >>> synthesize_candidates([Candidate("table", "none", note="not built")], "generic")[0].note
    'not built'
    """
    from chebnorm.core.parallel import check_workers

    workers = check_workers(workers)
    out = list(cands)

    def lower(c):
        return -math.inf if c.model is None else prune_lower(c.architecture, target, c.model,
                                                             c.model_rom)

    jobs = [SynthJob((c.model is None, c.model or 0.0, i), lower(c), i)
            for i, c in enumerate(out) if c.design is not None]
    run = pruned_synthesis(
        jobs, lambda batch: map_synth(_synth_item, [(out[j.key].verilog,
                                                     out[j.key].design.module_name, target)
                                                    for j in batch],
                                      workers=workers, scheduler=scheduler),
        score=lambda j, cost: cost.score, bound=bound, prune=prune)
    for i, cost in run.costs.items():
        out[i] = _with_cost(out[i], cost)
    for j in run.skipped:
        c = out[j.key]
        out[j.key] = _skipped(c, format_down(j.lower, '.1f'), run.best)
    return out


def _with_cost(c: Candidate, cost) -> Candidate:
    return Candidate(c.architecture, c.description, c.design, c.error, c.ulp, cost, c.note,
                     c.model, c.model_rom)


def _skipped(c: Candidate, low: str, best: float) -> Candidate:
    """``c`` not synthesized: its lower bound ``low`` (formatted) cannot beat ``best``."""
    rom = "" if c.model_rom is None else f" (ROM part {c.model_rom:.1f})"
    return Candidate(c.architecture, c.description, c.design, c.error, c.ulp, None,
                     f"model {c.model:.1f}{rom}: lower bound {low} >= best "
                     f"synthesized {best:.1f}: cannot win", c.model, c.model_rom)


def _synth_job(item):
    """One yosys run of :func:`synthesize_with_search`: a candidate or a search point."""
    kind, payload = item
    return _synth_item(payload) if kind == "arch" else synthesize_point(payload)


@hw_doc
def synthesize_with_search(cands, result, target: str, *, workers: int | None = None,
                           scheduler=None):
    """Synthesize the built candidates and the one-width search's front in one
    pruned queue: every job (a candidate, or a meeting point of the search's
    Pareto front, :func:`~chebnorm.hw.piecewise_search.synthesis_queue`) in
    order of its lower bound (:func:`prune_lower`; a search point's model
    over ``MODEL_SPREAD``), :data:`~chebnorm.hw.synth_loop.SYNTH_ROUND`
    at a time; a job whose lower bound is not below the best score
    synthesized so far is skipped (it cannot win). The first round takes
    candidates only, so the search may still be running then (``result`` a
    future); its points join the queue from the second round. The same jobs
    run whatever ``workers`` and however long the search takes (each round
    is fixed before it starts), so the result is deterministic.

    Parameters
    ----------
    cands : list of Candidate
        As :func:`build_candidates` returns them.
    result : SearchResult or concurrent.futures.Future
        The one-width search with ``synth=False``
        (:func:`chebnorm.hw.piecewise_search.search`), or a future of it
        (waited for after the first round).
    %(target)s
    workers, scheduler
        Parallel yosys runs (:func:`chebnorm.hw.piecewise_search.map_synth`).

    Returns
    -------
    tuple of (list of Candidate, SearchResult)
        The candidates with their costs (a skipped one keeps ``cost`` None and
        says why in ``note``) and the search result with its points' costs
        and winner (:func:`chebnorm.hw.piecewise_search.with_costs`).

    Raises
    ------
    ValueError
        ``target`` is unknown, or yosys is missing or fails.

    Examples
    --------
    Nothing built and no point meeting the error: nothing to synthesize.

    >>> from chebnorm.hw.piecewise_search import search
    >>> r = search("1/sqrt(x)", ("1", "4"), 6, 6, 1e-9, degrees=(1,), max_index_bits=2,
    ...            synth=False, progress=False, workers=1)
    >>> cands, res = synthesize_with_search([Candidate("table", "none", note="not built")],
    ...                                     r, "generic")
    >>> cands[0].note, res.winner is None
    ('not built', True)
    """
    from chebnorm.core.parallel import check_workers

    t = get_target(target).name
    workers = check_workers(workers)
    out = list(cands)
    jobs = []
    for i, c in enumerate(out):
        if c.design is not None:
            low = (prune_lower(c.architecture, t, c.model, c.model_rom) if c.model is not None
                   else -math.inf)
            jobs.append(SynthJob((low, 0, i), low, ("arch", i)))
    searched = [result]

    def later():   # the search's points, from round two (the search may still be running)
        if not isinstance(searched[0], SearchResult):   # a future of it
            searched[0] = searched[0].result()
        return [SynthJob((low, 1, key), low, ("point", key))
                for key, low in synthesis_queue(searched[0])]

    def synthesize(batch):
        items = [("arch", (out[j.key[1]].verilog, out[j.key[1]].design.module_name, t))
                 if j.key[0] == "arch" else ("point", (searched[0].designs[j.key[1]], t))
                 for j in batch]
        return map_synth(_synth_job, items, workers=workers, scheduler=scheduler)

    run = pruned_synthesis(jobs, synthesize, later=later,
                           score=lambda j, cost: (float(cost) if j.key[0] == "point"
                                                  and t == "generic" else cost.score))
    costs = {}
    for (kind, i), cost in run.costs.items():
        if kind == "arch":
            out[i] = _with_cost(out[i], cost)
        else:
            costs[i] = cost
    for j in run.skipped:
        low, (kind, i) = j.lower, j.key
        if kind == "arch":   # a lower bound: printed rounded down
            out[i] = _skipped(out[i], format_down(low, '.1f'), run.best)
    return out, with_costs(searched[0], costs)


def architecture_candidates(expr, interval, in_bits: int, out_bits: int, *, accuracy: str,
                            max_error=None, degrees=(1, 2, 3), k_start=None, var: str = "x",
                            name: str = "design", target: str = "generic",
                            synth: bool = True, bound: float | None = None, prune: bool = True,
                            workers: int | None = 1, scheduler=None) -> list[Candidate]:
    """The other architectures' best designs for the spec (module docstring).

    ``k_start`` maps a degree to the index bits at which the sized search
    starts (it walks up at most three more, :func:`_sized_chain`).
    ``accuracy``: one of :data:`ACCURACIES`; ``max_error`` its bound for
    ``"max-error"``. With ``synth``, the built candidates go through
    :func:`synthesize_candidates` (``bound``, ``prune``, ``workers``,
    ``scheduler``: as there); the sized search's degrees and the multipartite
    design are built in parallel on ``workers`` too. Every candidate carries
    its model score on ``target``.

    Parameters
    ----------
    expr : str or sympy.Expr
        The function ``f`` of ``var`` to evaluate.
    interval : tuple of (str or number)
        ``(a, b)``, the input range ``[a, b)``.
    in_bits, out_bits : int
        Input and output widths in bits.
    accuracy : str
        One of :data:`ACCURACIES`.
    max_error : float, optional
        The certified bound ``E`` for ``accuracy="max-error"`` (ignored
        otherwise).
    degrees : tuple of int, default (1, 2, 3)
        The degrees the sized piecewise search tries (only those in ``k_start``).
    k_start : dict of int to int, optional
        Degree to the index bits at which its sized search starts; a degree
        missing here is not searched (None: no sized candidate).
    var : str, default "x"
        The variable of ``expr``.
    name : str, default "design"
        The prefix of the candidates' module names.
    target : str, default "generic"
        A target name (:func:`chebnorm.hw.targets.target_names`).
    synth : bool, default True
        Synthesize the built candidates (:func:`synthesize_candidates`).
    bound : float, optional
        A score already synthesized elsewhere (as in :func:`synthesize_candidates`).
    prune : bool, default True
        Skip the synthesis of candidates that cannot win by the model.
    workers : int or None, default 1
        Parallel workers (:func:`chebnorm.core.parallel.check_workers`).
    scheduler : object, optional
        A shared scheduler for the parallel runs
        (:func:`chebnorm.core.parallel.map_ordered`).

    Returns
    -------
    list of Candidate
        The sized piecewise candidates (the cheapest per degree), the
        multipartite one (when ``in_bits <= 20``) and the plain table, each
        with ``design`` None and a ``note`` when not built.

    Raises
    ------
    ValueError
        ``accuracy`` is not one of :data:`ACCURACIES`, ``target`` is unknown,
        or the designers refuse the spec (widths, interval, expression).

    Examples
    --------
    >>> cs = architecture_candidates("1/sqrt(1+3*x)", ("0", "1"), 6, 6,
    ...                              accuracy="correctly-rounded", synth=False)
    >>> [(c.architecture, c.design is not None) for c in cs]
    [('piecewise-sized', False), ('multipartite', False), ('table', True)]
    >>> cs[-1].error <= cs[-1].ulp / 2
    True
    """
    out = build_candidates(expr, interval, in_bits, out_bits, accuracy=accuracy,
                           max_error=max_error, degrees=degrees, k_start=k_start, var=var,
                           name=name, target=target, workers=workers, scheduler=scheduler)
    if synth:
        out = synthesize_candidates(out, target, bound=bound, prune=prune, workers=workers,
                                    scheduler=scheduler)
    return cheapest_candidates(out)


def cheapest_candidates(cands) -> list[Candidate]:
    """``cands`` with, of the sized piecewise ones, only the cheapest per degree
    (lowest synthesized score, else lowest model score).

    Parameters
    ----------
    cands : list of Candidate
        As :func:`build_candidates` or :func:`synthesize_candidates` return them.

    Returns
    -------
    list of Candidate
        ``cands`` in their order, the sized piecewise candidates other than
        each degree's cheapest left out (unbuilt ones are kept).

    Examples
    --------
    >>> cheapest_candidates([Candidate("table", "none", note="not built")])[0].architecture
    'table'
    """
    sized = [c for c in cands if c.architecture == "piecewise-sized" and c.design is not None]
    keep = set(map(id, _cheapest_per_degree(sized)))
    return [c for c in cands if c.architecture != "piecewise-sized" or c.design is None
            or id(c) in keep]


def build_candidates(expr, interval, in_bits: int, out_bits: int, *, accuracy: str,
                     max_error=None, degrees=(1, 2, 3), k_start=None, var: str = "x",
                     name: str = "design", target: str = "generic", workers: int | None = 1,
                     scheduler=None, out_frac_bits: int | None = None) -> list[Candidate]:
    """Every candidate of :func:`architecture_candidates` (all the sized ones the
    walk built, not only the cheapest per degree), built and priced by the
    model, not synthesized: :func:`synthesize_candidates` and
    :func:`cheapest_candidates` finish them.

    Parameters
    ----------
    expr, interval, in_bits, out_bits, accuracy, max_error, degrees, k_start, var, name, target
        As in :func:`architecture_candidates`.
    workers : int or None, default 1
        Parallel workers for the sized chains and the multipartite design.
    scheduler : object, optional
        A shared scheduler (:func:`chebnorm.core.parallel.map_ordered`).
    out_frac_bits : int, optional
        Every candidate's output at this many fractional bits (last place
        ``2^-out_frac_bits``, -60..60), so that all are compared at one output
        format; default: each designer's own, the most that fit ``out_bits``.

    Returns
    -------
    list of Candidate
        Every sized design the walk built, the multipartite design (when
        ``in_bits <= 20``) and the plain table (built when its ROM is at most
        :data:`MAX_TABLE_ROM_BITS` bits), each with its ``model`` score;
        ``cost`` is None.

    Raises
    ------
    ValueError
        ``accuracy`` is not one of :data:`ACCURACIES`, ``target`` is unknown,
        or the designers refuse the spec.

    Examples
    --------
    >>> cs = build_candidates("1/sqrt(1+3*x)", ("0", "1"), 6, 6, accuracy="faithful",
    ...                       k_start={1: 2})
    >>> sorted({c.architecture for c in cs}), all(c.model > 0 for c in cs if c.design)
    (['multipartite', 'piecewise-sized', 'table'], True)
    """
    if accuracy not in ACCURACIES:
        raise ValueError(f"accuracy {accuracy!r}; accepted: {', '.join(ACCURACIES)}")
    if out_frac_bits is not None:
        out_frac_bits = check_int(out_frac_bits, "out_frac_bits", -60, 60)
    return _build_candidates(expr, interval, in_bits, out_bits, accuracy, max_error, degrees,
                             dict(k_start or {}), var, name, get_target(target).name, workers,
                             scheduler, out_frac_bits)


def _build_candidates(expr, interval, in_bits, out_bits, accuracy, max_error, degrees, k_start,
                      var, name, target, workers, scheduler, fy=None) -> list[Candidate]:
    """Every candidate of :func:`architecture_candidates`, built, not synthesized."""
    from .target_model import model_parts, model_score

    e = max_error if accuracy == "max-error" else None
    out: list[Candidate] = []
    rom = (2 ** in_bits) * out_bits
    if accuracy == "correctly-rounded":
        for arch in ("piecewise-sized", "multipartite"):
            out.append(Candidate(arch, "faithful at best", note="errs by up to one unit of the "
                                 "output's last place; a correctly rounded output needs the "
                                 "proved rounding of every code (a plain table)"))
    else:
        items = [("sized", expr, interval, in_bits, out_bits, degree, k_start[degree], e, var,
                  f"{name}_sized_d{degree}", target, fy) for degree in degrees
                 if degree in k_start]
        if in_bits <= 20:
            items.append(("multipartite", expr, interval, in_bits, out_bits, e, var,
                          f"{name}_mp", fy))
        built = map_ordered(_build_item, items, workers=workers, scheduler=scheduler)
        mult = "full" if get_target(target).name == "xc7" else "truncated"
        sized = [(k, d, m, r) for item, res in zip(items, built) if item[0] == "sized"
                 for k, d, m, r in res]
        if not sized:
            out.append(Candidate("piecewise-sized", "no design", note="the sized search met "
                                 "the error at no degree and segment count tried"))
        for k, d, model, model_rom in sized:
            b = d.budget()
            out.append(Candidate("piecewise-sized", f"degree {d.degree}, {2 ** k} centred "
                                 f"segments, ROM {sum(d.rom_bits) << k} bits, {mult} multipliers",
                                 d, float(b["total"]), float(b["y_lsb"]), model=model,
                                 model_rom=model_rom))
        if items and items[-1][0] == "multipartite" and isinstance(built[-1], str):
            out.append(Candidate("multipartite", "no design", note=built[-1]))
        elif items and items[-1][0] == "multipartite":
            m = built[-1]
            model, model_rom = model_parts(m.features(), target)
            out.append(Candidate("multipartite", f"{len(m.offsets)} offset tables, ROM "
                                 f"{m.rom_bits} bits", m, float(m.certificate.upper),
                                 2.0 ** -m.y_format.frac_bits, model=model,
                                 model_rom=model_rom))
    table = None
    if rom <= MAX_TABLE_ROM_BITS:
        try:
            table = design_plain_table(expr, interval, in_bits, out_bits, var=var,
                                       name=f"{name}_table", out_frac_bits=fy)
        except ValueError as exc:
            if fy is None:
                raise
            out.append(Candidate("table", f"{2 ** in_bits} entries", note=f"no design: "
                                 f"{str(exc).splitlines()[0]}"))
    if table is not None:
        p = table
        ok = accuracy != "correctly-rounded" or p.correctly_rounded
        out.append(Candidate("table", f"{2 ** in_bits} entries, ROM {p.rom_bits} bits"
                             + (", correctly rounded (proved)" if p.correctly_rounded else ""),
                             p if ok else None, float(p.certificate.upper),
                             2.0 ** -p.y_format.frac_bits,
                             note="" if ok else f"{p.unproved} codes' rounding not proved",
                             model=model_score(p.features(), target),
                             model_rom=model_parts(p.features(), target)[1]))
    elif rom > MAX_TABLE_ROM_BITS:
        out.append(Candidate("table", f"{2 ** in_bits} entries", note=f"ROM of {rom} bits, over "
                             f"{MAX_TABLE_ROM_BITS}: not built (it cannot win)"))
    return out
