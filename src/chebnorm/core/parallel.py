"""``map_ordered``: the one way chebnorm runs embarrassingly parallel jobs.

A job is a list of independent items and a function of one item.  The items run
serially (``workers=1``), on local worker processes (``workers=N``, default the
number of cores this process may use) or on a Dask distributed scheduler
(``scheduler="tcp://host:8786"``, needs the ``chebnorm[cluster]`` extra).  The
results come back in the order of the items, whatever order they finish in, so a
job's output has the same bytes for every worker count and scheduler.

``on_result(index, result)`` is called in the calling process as each item
finishes (in finishing order): a job that writes one file per item writes it
there, and an interrupted run (Ctrl-C) keeps every item finished so far.

The function and the items must be picklable for ``workers > 1`` and for a
scheduler (a module-level function, plain data).  Local worker processes are
started with ``spawn`` (no fork of a threaded parent).
"""

from __future__ import annotations

import os
from typing import Callable, Iterable

from .progress import progress_bar


def default_workers() -> int:
    """The number of cores this process may run on.

    Returns
    -------
    int
        ``len(os.sched_getaffinity(0))`` where available, else ``os.cpu_count()`` (at least 1).

    Examples
    --------
    >>> default_workers() >= 1
    True
    """
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # pragma: no cover - not Linux
        return max(1, os.cpu_count() or 1)


def check_workers(workers) -> int:
    """``workers`` as an int >= 1 (None: :func:`default_workers`).

    Parameters
    ----------
    workers : int or None
        Local worker processes.

    Returns
    -------
    int
        The count to use.

    Raises
    ------
    ValueError
        Naming ``workers`` when it is not an integer >= 1.

    Examples
    --------
    >>> check_workers(2), check_workers(None) >= 1
    (2, True)
    """
    if workers is None:
        return default_workers()
    if isinstance(workers, bool) or not isinstance(workers, int) or workers < 1:
        raise ValueError(f"workers = {workers!r}; accepted: an integer >= 1")
    return workers


def check_scheduler(scheduler) -> None:
    """Raise ``ValueError`` unless ``scheduler`` is None, a non-empty address string or a
    ``distributed.Client``; and unless dask.distributed is importable when one is given.

    Parameters
    ----------
    scheduler : str or distributed.Client or None
        The scheduler to check.

    Raises
    ------
    ValueError
        Naming ``scheduler`` and what is accepted.

    Examples
    --------
    >>> check_scheduler(None)
    """
    if scheduler is None:
        return
    if isinstance(scheduler, str):
        if not scheduler.strip():
            raise ValueError("scheduler address is empty; accepted: host:port or tcp://host:port")
    try:
        import distributed
    except ImportError:
        raise ValueError("a Dask scheduler needs dask.distributed; install it with "
                         "pip install 'chebnorm[cluster]'") from None
    if not isinstance(scheduler, (str, distributed.Client)):
        raise ValueError(f"scheduler is a {type(scheduler).__name__}; accepted: an address "
                         "string or a distributed.Client")


def map_ordered(fn: Callable, items: Iterable, *, workers: int | None = None, scheduler=None,
                progress: bool = False, desc: str | None = None,
                on_result: Callable | None = None) -> list:
    """``[fn(x) for x in items]``, run on ``workers`` local processes or a Dask scheduler.

    Parameters
    ----------
    fn : callable
        A picklable function of one item (a module-level function).
    items : iterable
        The items; their order is the order of the results.
    workers : int, optional
        Local worker processes (default: the core count); 1 runs in this process.
        Ignored when ``scheduler`` is given.
    scheduler : str or distributed.Client, optional
        A Dask distributed scheduler address (``tcp://host:8786``) or a client.
    progress : bool
        Show a tqdm progress bar labelled ``desc`` on stderr when it is a terminal
        (:func:`chebnorm.core.progress.progress_bar`).
    desc : str, optional
        The progress bar's label.
    on_result : callable, optional
        ``on_result(index, result)``, called here as each item finishes.

    Returns
    -------
    list
        The results, in the order of ``items``.

    Examples
    --------
    >>> import math
    >>> map_ordered(math.sqrt, [4.0, 9.0, 16.0], workers=1)
    [2.0, 3.0, 4.0]
    """
    items = list(items)
    check_scheduler(scheduler)
    workers = check_workers(workers)
    from tqdm import tqdm

    results = [None] * len(items)
    # a bar on a terminal only (core.progress): nothing in a pipe, a log or a test's stream
    bar = progress_bar(len(items), desc or "", unit="item") if progress else \
        tqdm(total=len(items), disable=True)

    def done(i, r):
        results[i] = r
        if on_result is not None:
            on_result(i, r)
        bar.update(1)

    try:
        if scheduler is not None:
            _run_dask(fn, items, scheduler, done)
        elif workers == 1 or len(items) <= 1:
            for i, x in enumerate(items):
                done(i, fn(x))
        else:
            _run_processes(fn, items, min(workers, len(items)), done)
    finally:
        bar.close()
    return results


def _run_processes(fn, items, workers, done):
    import multiprocessing
    from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait

    pool = ProcessPoolExecutor(max_workers=workers, mp_context=multiprocessing.get_context("spawn"),
                               initializer=_worker_ignores_ctrl_c)
    finished_all = False
    try:
        pending = {pool.submit(fn, x): i for i, x in enumerate(items)}
        while pending:
            finished, _ = wait(pending, return_when=FIRST_COMPLETED)
            for fut in sorted(finished, key=pending.get):
                done(pending.pop(fut), fut.result())
        finished_all = True
    finally:
        if finished_all:
            pool.shutdown(wait=True)
        else:
            _stop(pool)


def _worker_ignores_ctrl_c() -> None:
    """A worker's SIGINT does nothing: Ctrl-C in a terminal reaches the whole
    process group, and the parent stops the workers itself (:func:`_stop`); an
    idle worker would otherwise print a ``KeyboardInterrupt`` traceback. A
    Python handler, not ``SIG_IGN``: the programs a worker runs (yosys, a C
    compiler) get the default action back at ``exec`` and stop at Ctrl-C."""
    import signal

    signal.signal(signal.SIGINT, lambda signum, frame: None)


def _stop(pool) -> None:
    """Ctrl-C or an error: drop the queued items and stop the running ones now
    (``shutdown`` alone lets them compute on, and the exit waits for them), then
    reap the workers, so the process exits at once with nothing left running and
    every queue and semaphore released (no resource-tracker warning). A second
    Ctrl-C meanwhile does not cut this short."""
    import signal
    import threading

    # signals are handled in the main thread only; None: a handler not set from Python
    main = threading.current_thread() is threading.main_thread()
    previous = signal.getsignal(signal.SIGINT) if main else None
    if previous is not None:
        signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        processes = list((getattr(pool, "_processes", None) or {}).values())
        pool.shutdown(wait=False, cancel_futures=True)
        for proc in processes:
            proc.terminate()
        for proc in processes:
            proc.join(timeout=5)
    finally:
        if previous is not None:
            signal.signal(signal.SIGINT, previous)


def _run_dask(fn, items, scheduler, done):
    import distributed

    own = not isinstance(scheduler, distributed.Client)
    if own:
        try:
            client = distributed.Client(scheduler, timeout="20s")
        except (OSError, TimeoutError, ValueError) as e:
            raise ValueError(f"cannot reach the Dask scheduler at {scheduler!r}: {e}") from None
    else:
        client = scheduler
    try:
        futures = client.map(fn, items, pure=False)
        index = {f.key: i for i, f in enumerate(futures)}
        try:
            for fut in distributed.as_completed(futures):
                done(index[fut.key], fut.result())
        except BaseException:
            client.cancel(futures)
            raise
    finally:
        if own:
            client.close()
