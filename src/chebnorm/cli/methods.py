"""``chebnorm methods``: errors and operation counts of every registered method on one span."""

from __future__ import annotations

import math

from .common import print_json

_KEYS = ("add", "mul", "div", "sqrt", "trig", "cmp")

#: the largest span angle ``--angle`` takes, radians: every method needs end normals
#: with ``1 + cos PSI > chebnorm.methods.ANTIPARALLEL_TOL`` (1e-6, so PSI < 3.14018)
MAX_ANGLE = 3.14


def register(sub) -> None:
    """Add the ``chebnorm methods`` subcommand.

    Parameters
    ----------
    sub : argparse._SubParsersAction
        The subparsers of the ``chebnorm`` parser (from
        ``argparse.ArgumentParser.add_subparsers``); the new parser's ``func``
        default is :func:`run`.
    """
    p = sub.add_parser("methods", help="errors and operation counts of the normalization methods",
                       description="Run every normalization method of seed 000 on one span of "
                       "angle PSI and length M; print its largest length and angle errors and "
                       "its operation counts (measured by running the kernel on a counting type).")
    p.add_argument("--angle", type=float, required=True, metavar="PSI",
                   help=f"angle between the end normals, radians, 0 <= PSI <= {MAX_ANGLE}")
    p.add_argument("--span", type=int, required=True, metavar="M", help="span length in pixels, 1..65536")
    p.add_argument("--dtype", default="float64", help="float64 (default) or float32")
    p.add_argument("--drift", action="store_true",
                   help="also show the float32/float64 drift of the angular recurrence over M pixels")
    p.add_argument("--json", action="store_true", help="print JSON on stdout")
    p.set_defaults(func=run)


def _ops(d: dict) -> dict:
    return {k: d[k] for k in _KEYS}


def run(args) -> int:
    """Run ``chebnorm methods``: the length and angle errors and the
    operation counts of every normalization method over one span
    (:func:`chebnorm.methods.analyze`), and with ``--drift`` the angular
    recurrence's drift in float32 and float64.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line of ``chebnorm methods`` (the options its
        :func:`register` declares; ``args.argv``, set by :func:`chebnorm.cli.main`,
        is the command quoted in provenance banners).

    Returns
    -------
    int
        The exit status: always 0.

    Raises
    ------
    ValueError
        When ``--dtype`` is not float32 or float64, or ``--angle`` is not in
        ``[0, MAX_ANGLE]`` radians (:func:`chebnorm.cli.main` prints it as one
        line on stderr and exits with status 2).
    """
    import numpy as np

    from chebnorm.core.numeric import format_down

    from chebnorm.methods import analyze, angular_drift, method_names

    if args.dtype not in ("float32", "float64"):
        raise ValueError(f"dtype {args.dtype!r} is not supported; accepted: float32, float64")
    if not (math.isfinite(args.angle) and 0 <= args.angle <= MAX_ANGLE):
        raise ValueError(f"--angle {args.angle!r} is out of range; accepted: 0 <= PSI <= "
                         f"{MAX_ANGLE} radians (end normals further from antiparallel than "
                         f"1 + cos PSI > 1e-06, which every method needs)")
    dtype = np.dtype(args.dtype).type
    reports = [analyze(m, args.angle, args.span, dtype) for m in method_names()]
    drift = None
    if args.drift:
        drift = {dt: angular_drift(args.angle, args.span, np.dtype(dt).type) for dt in ("float32", "float64")}
    if args.json:
        out = {"angle": args.angle, "span": args.span, "dtype": args.dtype, "methods": [
            {"name": r.method, "ops_per_pixel": _ops(r.ops.per_pixel), "ops_per_span": _ops(r.ops.per_span),
             "max_length_error": r.max_length_error, "max_angle_error": r.max_angle_error,
             "max_angle_error_slerp": r.max_angle_error_slerp, "diffuse_error": r.diffuse_error,
             "specular_error_n32": r.specular_error(32)} for r in reports]}
        if drift:
            out["angular_drift"] = {dt: {"max_length_error": d.max_length_error,
                                         "max_angle_error": d.max_angle_error} for dt, d in drift.items()}
        print_json(out)
        return 0
    print(f"span angle {args.angle:.9g} rad, {args.span} pixels, {args.dtype}; errors against the "
          f"exactly normalized linear interpolant (angle vs slerp in brackets)")
    print(f"{'method':10s} {'max ||N|-1|':>12s} {'max angle':>10s} {'(vs slerp)':>10s}  "
          f"per pixel (add mul div sqrt trig cmp) | per span")
    for r in reports:
        pp = " ".join(f"{r.ops.per_pixel[k]:g}" for k in _KEYS)
        ps = " ".join(f"{r.ops.per_span[k]:g}" for k in _KEYS)
        print(f"{r.method:10s} {format_down(r.max_length_error, '12.4e')} "
              f"{format_down(r.max_angle_error, '10.3e')} "
              f"{format_down(r.max_angle_error_slerp, '10.3e')}  {pp:>22s} | {ps}")
    if drift:
        for dt, d in drift.items():
            print(f"angular recurrence drift, {dt}: max ||N|-1| = "
                  f"{format_down(d.max_length_error, '.3e')}, "
                  f"max angle vs slerp = {format_down(d.max_angle_error, '.3e')} rad")
    return 0
