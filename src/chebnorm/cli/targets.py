"""``chebnorm targets``: the registry of named approximation targets."""

from __future__ import annotations

from .common import print_json


def register(sub) -> None:
    """Add the ``chebnorm targets`` subcommand.

    Parameters
    ----------
    sub : argparse._SubParsersAction
        The subparsers of the ``chebnorm`` parser (from
        ``argparse.ArgumentParser.add_subparsers``); the new parser's ``func``
        default is :func:`run`.
    """
    p = sub.add_parser("targets", help="list the registered approximation targets")
    p.add_argument("--psi-max", default="pi/4", help="largest span angle in radians (default pi/4)")
    p.add_argument("--json", action="store_true")
    p.set_defaults(func=run)


def run(args) -> int:
    """Run ``chebnorm targets``: list the registered approximation targets
    (name, expression, variable, interval at ``--psi-max``, degrees, kind,
    meaning), as text or with ``--json`` as JSON.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line of ``chebnorm targets`` (the options its
        :func:`register` declares; ``args.argv``, set by :func:`chebnorm.cli.main`,
        is the command quoted in provenance banners).

    Returns
    -------
    int
        The exit status: always 0.

    Raises
    ------
    ValueError
        When ``--psi-max`` is not a readable angle in the target's range
        (:func:`chebnorm.cli.main` prints it as one line on stderr and exits with status
        2).
    """
    from chebnorm.approx import TARGETS, target_names

    rows = []
    for name in target_names():
        t = TARGETS[name]
        lo, hi = t.interval(args.psi_max)
        rows.append({"name": name, "expression": t.expression, "variable": t.variable,
                     "interval": [lo, hi], "degrees": list(t.degrees), "kind": t.kind,
                     "meaning": t.meaning})
    if args.json:
        print_json(rows)
    else:
        for r in rows:
            print(f"{r['name']:10s} {r['expression']:18s} {r['variable']} in [{r['interval'][0]}, "
                  f"{r['interval'][1]}]  degrees {r['degrees']} ({r['kind']}): {r['meaning']}")
    return 0
