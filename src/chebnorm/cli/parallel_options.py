"""``--workers N`` and ``--scheduler ADDRESS``: the options of every parallel command
(they map onto :func:`chebnorm.core.parallel.map_ordered`)."""

from __future__ import annotations


def add_parallel_args(p) -> None:
    """Add ``--workers`` and ``--scheduler`` to the argparse parser ``p``.

    Parameters
    ----------
    p : argparse.ArgumentParser
        The subcommand's parser. ``--workers N`` (int, default None: the core
        count; 1 runs in this process) and ``--scheduler ADDRESS`` (a Dask
        scheduler such as ``tcp://host:8786``, default None; overrides
        ``--workers``) are checked by the library call, not here.
    """
    p.add_argument("--workers", type=int, default=None, metavar="N",
                   help="local worker processes (default: the core count; 1: in this process)")
    p.add_argument("--scheduler", default=None, metavar="ADDRESS",
                   help="run on a Dask distributed scheduler, e.g. tcp://host:8786 "
                        "(needs pip install 'chebnorm[cluster]'); overrides --workers")


def parallel_kwargs(args) -> dict:
    """``workers=`` and ``scheduler=`` for the library call, from parsed ``args``.

    Parameters
    ----------
    args : argparse.Namespace
        Parsed arguments of a parser given :func:`add_parallel_args`.

    Returns
    -------
    dict
        ``{"workers": args.workers, "scheduler": args.scheduler}``, the keyword
        arguments of :func:`chebnorm.core.parallel.map_ordered`.
    """
    return {"workers": args.workers, "scheduler": args.scheduler}
