"""``chebnorm repro [NAME ...]``: the main job.

Regenerates every output under the output folder (``-o``, default
``./figures``): the coefficient tables and C headers of every registered
target (job ``coefficients``, part of the library), and every job that the
paper reproduction registers through the ``chebnorm.repro`` entry point (the
library does not import it by name). Each job writes its files atomically,
so an interrupted run keeps every file that was finished. The jobs are
independent: ``--workers N`` runs them on local processes (default: the core
count), ``--scheduler ADDRESS`` on a Dask scheduler; each job writes the same
files whatever runs it.

Where things are is given or taken from the current directory, never from
where chebnorm is installed: ``--ledger-dir`` (default: ``./paper_repro``
when the output is ``./figures`` and ``./paper_repro/`` exists, else
``<output>/claims``) and ``--bench-results`` (default
``./benchmarks/results.json`` when it exists).

``<output>/provenance.json`` records the versions of the numeric dependencies
that wrote the outputs; when the installed ones differ from those recorded
there, one line on stderr names them (the bytes may then differ).
"""

from __future__ import annotations

import json
import sys
import time
from importlib.metadata import PackageNotFoundError, entry_points, version
from pathlib import Path

from .parallel_options import add_parallel_args, parallel_kwargs

#: fractional bits of the fixed-point part of the exported tables
EXPORT_FRAC_BITS = 24
#: the distributions whose versions can change the bytes ``chebnorm repro`` writes
NUMERIC_DEPENDENCIES = ("numpy", "scipy", "mpmath", "sympy", "python-flint", "matplotlib",
                        "kiwisolver", "Pillow", "scikit-image", "trimesh", "flip-evaluator")
#: the file in the output folder that records the versions of NUMERIC_DEPENDENCIES
PROVENANCE = "provenance.json"


def export_coefficients(out: Path, **_options) -> list[Path]:
    """Every registered target at each of its degrees: JSON table and C header.

    Parameters
    ----------
    out : pathlib.Path
        The repro output folder; the files go into ``out / "coefficients"``
        (created if missing).
    **_options
        The job options every repro job receives (``bench_results``,
        ``ledger_dir``), unused here.

    Returns
    -------
    list of pathlib.Path
        The files written, two per target and degree.
    """
    from chebnorm.approx import TARGETS, fit_target, target_names
    from chebnorm.core.files import write_atomic
    from chebnorm.export import export_with_proofs, json_text

    folder = out / "coefficients"
    folder.mkdir(parents=True, exist_ok=True)
    written = []
    for name in target_names():
        for degree in TARGETS[name].degrees:
            table = fit_target(name, degree, coef_frac_bits=EXPORT_FRAC_BITS)
            cmd = "chebnorm repro coefficients"
            write_atomic(folder / f"{table.name}.json", json_text(table, cmd))
            written.append(folder / f"{table.name}.json")
            # the header and a Gappa proof of each of its evaluation bounds
            files = export_with_proofs(table, "c", folder / f"chebnorm_{table.name}.h", cmd)
            written += [folder / name for name in files]
    return written


def jobs() -> dict:
    """All jobs by name: the library's own, then the registered ones.

    Returns
    -------
    dict of str to callable
        Job name -> function ``(out, **options) -> list of paths``: the built-in
        ``coefficients`` job, then those of the ``chebnorm.repro`` entry points,
        sorted by entry point and by name.

    Raises
    ------
    ValueError
        When two entry points register the same job name.
    """
    found = {"coefficients": export_coefficients}
    for ep in sorted(entry_points(group="chebnorm.repro"), key=lambda e: e.name):
        registry = ep.load()
        for name in sorted(registry):
            if name in found:
                raise ValueError(f"repro job {name!r} is registered twice")
            found[name] = registry[name]
    return found


def installed_versions() -> dict[str, str]:
    """Installed version of each of :data:`NUMERIC_DEPENDENCIES` ("not installed" when missing).

    Returns
    -------
    dict of str to str
        Distribution name -> installed version string.

    >>> v = installed_versions(); v["numpy"] == __import__("numpy").__version__
    True
    """
    out = {}
    for name in NUMERIC_DEPENDENCIES:
        try:
            out[name] = version(name)
        except PackageNotFoundError:
            out[name] = "not installed"
    return out


def version_differences(recorded: dict, installed: dict) -> list[str]:
    """``name installed (recorded X)`` for each name whose versions differ, sorted by name.

    Parameters
    ----------
    recorded : dict of str to str
        The versions recorded by an earlier run (name -> version).
    installed : dict of str to str
        The versions installed now (:func:`installed_versions`).

    Returns
    -------
    list of str
        One phrase per name whose versions differ ("not installed" or
        "nothing" standing for a missing side), sorted case-insensitively.

    >>> version_differences({"numpy": "2.4.6", "scipy": "1.16.0"}, {"numpy": "2.3.0", "scipy": "1.16.0"})
    ['numpy 2.3.0 (recorded 2.4.6)']
    """
    return [f"{k} {installed.get(k, 'not installed')} (recorded {recorded.get(k, 'nothing')})"
            for k in sorted(set(recorded) | set(installed), key=str.lower)
            if recorded.get(k) != installed.get(k)]


def _recorded_versions(out: Path) -> dict | None:
    try:
        data = json.loads((out / PROVENANCE).read_text(encoding="utf-8"))
        versions = data["versions"]
        return versions if isinstance(versions, dict) else None
    except (OSError, ValueError, KeyError, TypeError):
        return None


def register(sub) -> None:
    """Add the ``chebnorm repro`` subcommand.

    Parameters
    ----------
    sub : argparse._SubParsersAction
        The subparsers of the ``chebnorm`` parser (from
        ``argparse.ArgumentParser.add_subparsers``); the new parser's ``func``
        default is :func:`run`.
    """
    p = sub.add_parser("repro", help="regenerate every figure, table, ledger and coefficient header",
                       description=__doc__.splitlines()[0])
    p.add_argument("names", nargs="*", metavar="NAME", help="jobs to run (default: all); see --list")
    p.add_argument("-o", "--output", default="figures",
                   help="output folder (default ./figures, in the current directory)")
    p.add_argument("--ledger-dir", default=None, metavar="DIR",
                   help="folder of the claims ledger CLAIMS.md / claims.json (default ./paper_repro "
                        "when the output is ./figures and ./paper_repro exists, else OUTPUT/claims)")
    p.add_argument("--bench-results", default=None, metavar="FILE",
                   help="benchmark results read for the speed claims (default "
                        "./benchmarks/results.json when it exists; without it they read n/a)")
    p.add_argument("--list", action="store_true", help="list the jobs and exit")
    add_parallel_args(p)
    p.set_defaults(func=run)


def _run_job(item) -> int:
    """Run the repro job ``name`` into ``out`` (on a worker); the number of files written.

    A render's first compile on an empty numba cache is announced by a
    :class:`~chebnorm.raster.engines.numba.jit.NumbaCompileWarning` (for one
    ``render`` call that takes seconds for no visible reason); repro's progress
    bar and its closing line already show the time, and each worker process would
    print the note again inside the bar, so it is not issued here. Every other
    warning (chebnorm's own among them) passes."""
    import warnings

    from chebnorm.raster.engines.numba.jit import NumbaCompileWarning

    name, out, bench, ledger_dir = item
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", category=NumbaCompileWarning)
        return len(jobs()[name](Path(out), bench_results=bench, ledger_dir=ledger_dir) or [])


def run(args) -> int:
    """Run ``chebnorm repro``: run the selected repro jobs (all by default;
    ``--list`` only prints their names) into the folder ``-o``, and record the
    installed numeric versions beside them.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line of ``chebnorm repro`` (the options its
        :func:`register` declares; ``args.argv``, set by :func:`chebnorm.cli.main`,
        is the command quoted in provenance banners).

    Returns
    -------
    int
        The exit status: 0 on success.

    Raises
    ------
    ValueError
        On an unknown job name, a ``--bench-results`` that is not a file, or a bad
        ``--workers``/``--scheduler`` (:func:`chebnorm.cli.main` prints it as one line
        on stderr and exits with status 2).
    """
    from chebnorm.core.files import write_atomic
    from chebnorm.core.parallel import check_scheduler, check_workers, map_ordered

    available = jobs()
    if args.list:
        for name in available:
            print(name)
        return 0
    unknown = [n for n in args.names if n not in available]
    if unknown:
        raise ValueError(f"unknown repro job(s) {', '.join(unknown)}; accepted: {', '.join(available)}")
    bench = args.bench_results
    if bench is not None and not Path(bench).is_file():
        raise ValueError(f"--bench-results {bench!r} is not a file; accepted: the results.json "
                         f"written by `python benchmarks/run.py`")
    selected = args.names or list(available)
    check_workers(args.workers)
    check_scheduler(args.scheduler)
    out = Path(args.output)
    out.mkdir(parents=True, exist_ok=True)
    installed = installed_versions()
    recorded = _recorded_versions(out)
    if recorded is not None:
        diff = version_differences(recorded, installed)
        if diff:
            print(f"chebnorm repro: versions differ from {out / PROVENANCE}, so bytes may differ: "
                  + ", ".join(diff), file=sys.stderr)
    start = time.perf_counter()
    count = sum(map_ordered(_run_job, [(name, str(out), bench, args.ledger_dir)
                                       for name in selected],
                            progress=True, desc="chebnorm repro", **parallel_kwargs(args)))
    write_atomic(out / PROVENANCE, json.dumps({"command": "chebnorm repro", "versions": installed},
                                              sort_keys=True, indent=2) + "\n")
    count += 1
    print(f"chebnorm repro: {len(selected)} job(s), {count} file(s) under {out}/ "
          f"in {time.perf_counter() - start:.1f} s")
    return 0
