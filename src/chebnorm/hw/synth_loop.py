"""The one pruned synthesis loop: every yosys run of ``chebnorm design`` (the
candidates of :mod:`chebnorm.hw.architectures`, the points of the one-width
search of :mod:`chebnorm.hw.piecewise_search`, or both in one queue) goes
through :func:`pruned_synthesis`.

A job is queued with a lower bound of its synthesized score (its model score
over the model's spread). Jobs run in queue order, :data:`SYNTH_ROUND` at a
time; a job whose lower bound is not below the best score synthesized so far
(or a ``bound`` found elsewhere) is skipped: it cannot win. Each round is
fixed before it starts, so the jobs run, and the outputs, do not depend on
the worker count.

>>> jobs = [SynthJob((3.0,), 3.0, "c"), SynthJob((1.0,), 1.0, "a"), SynthJob((2.0,), 2.0, "b")]
>>> run = pruned_synthesis(jobs, lambda batch: [2.5 * j.lower for j in batch],
...                        score=lambda job, cost: cost)
>>> run.costs, [j.key for j in run.skipped], run.best
({'a': 2.5, 'b': 5.0}, ['c'], 2.5)
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from chebnorm.core.parallel import check_workers, map_ordered

# an implementation module of chebnorm.hw: the API is what chebnorm.hw exports
__all__: list[str] = []

#: jobs synthesized per round of the pruned synthesis (fixed, so the jobs
#: synthesized, and the CSV, do not depend on the worker count)
SYNTH_ROUND = 2


@dataclass(frozen=True)
class SynthJob:
    """One synthesis the queue may run.

    Attributes
    ----------
    order : tuple
        Its place in the queue (ascending; ties must not occur).
    lower : float
        A lower bound of its synthesized score (``-math.inf``: never skipped
        by the bound).
    key : object
        What the caller knows it by (hashable).

    Examples
    --------
    >>> SynthJob((0.0, 1), 0.0, ("point", 3)).key
    ('point', 3)
    """

    order: tuple
    lower: float
    key: object


@dataclass(frozen=True)
class PrunedRun:
    """What :func:`pruned_synthesis` ran and skipped.

    Attributes
    ----------
    costs : dict
        ``job.key`` -> the synthesis result, for the jobs run, in the order run.
    best : float
        The best score synthesized (or the ``bound`` given, if lower; ``inf``
        when nothing ran and there was no bound).
    skipped : list of SynthJob
        The jobs not run, in queue order.

    Examples
    --------
    >>> PrunedRun({}, math.inf, []).best
    inf
    """

    costs: dict
    best: float
    skipped: list


def pruned_synthesis(jobs, synthesize, *, score, bound: float | None = None,
                     prune: bool = True, first: bool = False, later=None) -> PrunedRun:
    """Run ``jobs`` in queue order, :data:`SYNTH_ROUND` at a time, skipping those
    that cannot win (module docstring).

    Parameters
    ----------
    jobs : iterable of SynthJob
        The queue (any order: sorted by ``order``).
    synthesize : callable
        ``synthesize(batch)`` -> one result per job of ``batch`` (a list of at
        most :data:`SYNTH_ROUND` jobs), in order; it runs them in parallel
        (:func:`map_synth`).
    score : callable
        ``score(job, result)`` -> the float the best is kept on.
    bound : float, optional
        A score synthesized elsewhere: a job must beat it too.
    prune : bool, default True
        False: run every job (still in order, by rounds).
    first : bool, default False
        When no job of the first round can beat ``bound``, run the first job
        anyway (a search that must synthesize its cheapest point).
    later : callable, optional
        ``later()`` -> more jobs, joining the queue from the second round (a
        search still running while the first round is synthesized).

    Returns
    -------
    PrunedRun
        The results, the best score and the skipped jobs.

    Examples
    --------
    Nothing beats the bound: nothing runs, unless ``first``.

    >>> jobs = [SynthJob((1.0,), 1.0, "a")]
    >>> pruned_synthesis(jobs, lambda b: [1.0], score=lambda j, c: c, bound=0.5).costs
    {}
    >>> pruned_synthesis(jobs, lambda b: [1.0], score=lambda j, c: c, bound=0.5,
    ...                  first=True).costs
    {'a': 1.0}
    """
    todo = sorted(jobs, key=lambda j: j.order)
    best = math.inf if bound is None else float(bound)
    costs: dict = {}
    merged, rounds = later is None, 0
    while True:
        if rounds >= 1 and not merged:   # the later jobs join from round two
            todo = sorted(todo + list(later()), key=lambda j: j.order)
            merged = True
        rounds += 1
        run = [j for j in todo if not prune or j.lower < best][:SYNTH_ROUND]
        if first and not costs and not run:   # the cheapest job always
            run = todo[:1]
        if not run:
            if merged:
                break
            continue
        for j, cost in zip(run, synthesize(run)):
            costs[j.key] = cost
            best = min(best, score(j, cost))
        done = {j.key for j in run}
        todo = [j for j in todo if j.key not in done]
    return PrunedRun(costs, best, todo)


def map_synth(fn, items, *, workers: int | None = None, scheduler=None, progress=False,
              desc: str | None = None) -> list:
    """``[fn(x) for x in items]`` for yosys runs: on a Dask ``scheduler`` through
    :func:`chebnorm.core.parallel.map_ordered`, else on ``workers`` threads of
    this process (a yosys run is a child process: threads run them side by
    side without starting a Python worker per batch).

    Parameters
    ----------
    fn : callable
        A function of one item (thread-safe: it writes only its own files).
    items : iterable
    workers : int, optional
        Threads (default: the core count).
    scheduler, progress, desc
        As :func:`~chebnorm.core.parallel.map_ordered` (``progress`` and
        ``desc`` only with a scheduler).

    Returns
    -------
    list
        The results in the order of ``items``.

    Examples
    --------
    >>> map_synth(abs, [-1, 2, -3], workers=2)
    [1, 2, 3]
    """
    items = list(items)
    if scheduler is not None:
        return map_ordered(fn, items, scheduler=scheduler, progress=progress, desc=desc)
    workers = check_workers(workers)
    if workers == 1 or len(items) <= 1:
        return [fn(x) for x in items]
    from concurrent.futures import ThreadPoolExecutor

    with ThreadPoolExecutor(max_workers=min(workers, len(items))) as pool:
        return list(pool.map(fn, items))
