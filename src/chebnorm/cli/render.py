"""``chebnorm render``: render a mesh with one shading mode and measure its
error against a reference render (default: Phong, ``exact``, float64)."""

from __future__ import annotations

import os
import time

from .common import (ETA_THRESHOLD, Q_THRESHOLD, add_lighting_options, help_when_printed,
                     print_json, refuse_unused)
from .vocab import BUMP_VARIANTS, MESH_NAMES, SHADING_MODES


def register(sub) -> None:
    """Add the ``chebnorm render`` subcommand.

    Parameters
    ----------
    sub : argparse._SubParsersAction
        The subparsers of the ``chebnorm`` parser (from
        ``argparse.ArgumentParser.add_subparsers``); the new parser's ``func``
        default is :func:`run`.
    """
    p = sub.add_parser("render", help="render a mesh and measure the shading error",
                       description="Render a mesh with a shading mode and compare it with a "
                       "reference render (default phong:exact): max/mean error in 8-bit levels, "
                       "pixels off by >= 1 level, PSNR, SSIM, FLIP.")
    p.add_argument("--mesh", default="teapot",
                   help=f"{'|'.join(MESH_NAMES)} or an .obj/.ply/.stl path (default teapot)")
    p.add_argument("--shading", default="phong", help=f"{'|'.join(SHADING_MODES)} (default phong)")
    method = p.add_argument("--method", default=None,
                            help="normalization method for phong/adaptive/bump: a registered "
                            "method (default exact; checked by render)")
    help_when_printed(p, method, _method_help)
    p.add_argument("--size", nargs=2, type=int, default=(512, 512), metavar=("W", "H"),
                   help="image size in pixels (default 512 512)")
    p.add_argument("--tess", type=int, default=None, help="tessellation level (mesh default)")
    p.add_argument("--crease-angle", type=float, default=None, metavar="DEG",
                   help="mesh files: compute vertex normals, kept apart across edges sharper "
                   f"than DEG degrees ({CREASE_RANGE[0]:g}..{CREASE_RANGE[1]:g}); default: an "
                   "OBJ file's own vn normals, else 30")
    p.add_argument("--shininess", type=float, default=32.0, help="specular exponent n (default 32)")
    p.add_argument("--bump", default=None, help=f"bump variant: {'|'.join(BUMP_VARIANTS)} "
                   "(default full)")
    p.add_argument("--reference", default=None, metavar="MODE[:METHOD]",
                   help="reference render (default phong:exact; for bump, bump:full — the "
                   "METHOD slot of bump is its variant)")
    p.add_argument("--out", metavar="IMAGE.png", help="write the 8-bit image; the extension "
                   "names the format: .png, .jpg/.jpeg (quality 95), .tif/.tiff, .bmp")
    p.add_argument("--error-map", metavar="ERR.png", help="write a heat map of |error| "
                   "(formats as --out)")
    p.add_argument("--json", action="store_true", help="print metrics and mode report as JSON")
    add_lighting_options(p, "numba: the compiled path (same image bytes); numpy: the "
                         "reference; auto (default): numba when installed")
    p.set_defaults(func=run)


#: accepted --crease-angle, degrees
CREASE_RANGE = (0.0, 180.0)


def _method_help() -> str:
    from chebnorm.raster import available_methods  # the registry, which a caller may extend

    return (f"normalization method for phong/adaptive/bump: {'|'.join(available_methods())} "
            f"(default exact; checked by render)")


def _crease_radians(deg):
    import math

    if deg is None:
        return None
    if not (CREASE_RANGE[0] <= deg <= CREASE_RANGE[1]):  # also refuses nan
        raise ValueError(f"--crease-angle {deg!r}: expected degrees in "
                         f"[{CREASE_RANGE[0]:g}, {CREASE_RANGE[1]:g}]")
    return math.radians(deg)


def parse_reference(text, shading):
    """The ``--reference`` option of ``render`` and ``render-sweep``: None, or a
    ``MODE[:METHOD]`` text checked against the shading modes (ValueError naming
    the option and the accepted values otherwise).

    Parameters
    ----------
    text : str or None
        The option's value, ``MODE`` or ``MODE:METHOD``; None for the default
        reference (exact Phong, or exact bump mapping when ``shading`` is bump).
    shading : str
        The ``--shading`` of the render being measured.

    Returns
    -------
    tuple of str
        ``(mode, method, bump_method)``: the reference shading mode, its
        normalization method (default ``"exact"``) and, for ``bump``, the bump
        method (default ``"full"``).

    Raises
    ------
    ValueError
        When ``MODE`` is not one of :data:`chebnorm.raster.SHADING_MODES`.
    """
    from chebnorm.raster import SHADING_MODES

    if text is None:
        return ("bump", "exact", "full") if shading == "bump" else ("phong", "exact", "full")
    mode, _, rest = text.partition(":")
    if mode not in SHADING_MODES:
        raise ValueError(f"--reference {text!r}: unknown mode {mode!r}; accepted: "
                         f"{', '.join(SHADING_MODES)}")
    if mode == "bump":
        return mode, "exact", rest or "full"
    return mode, rest or "exact", "full"


def _refuse_unused(args) -> None:
    """Options that do nothing with this --shading (or mesh) are refused, not ignored."""
    from chebnorm.raster import MESH_NAMES

    if args.shading in ("gouraud", "split-gouraud"):
        refuse_unused(args, "with --shading phong, adaptive or bump", **{"--method": "method"})
    if args.shading != "bump":
        refuse_unused(args, "with --shading bump", **{"--bump": "bump"})
    if args.shading != "adaptive":
        refuse_unused(args, "with --shading adaptive", **{"--eta-threshold": "eta_threshold"})
    if args.shading != "split-gouraud":
        refuse_unused(args, "with --shading split-gouraud", **{"--q": "q"})
    if os.fspath(args.mesh) not in MESH_NAMES:
        refuse_unused(args, f"to a generated mesh ({', '.join(MESH_NAMES)})", **{"--tess": "tess"})


def _refuse_clobber(args) -> None:
    """Refuse ``--out`` and ``--error-map`` naming one file (also through a symbolic
    link or another spelling), and an output that is the ``--mesh`` file."""
    from chebnorm.core.files import WriteError, refuse_inputs

    if args.out and args.error_map and (
            os.path.realpath(args.out) == os.path.realpath(args.error_map)
            or _samefile(args.out, args.error_map)):
        raise WriteError(f"--out {str(args.out)!r:.200} and --error-map "
                         f"{str(args.error_map)!r:.200} are the same file; accepted: two "
                         f"different files")
    mesh_file = None if os.fspath(args.mesh) in MESH_NAMES else args.mesh
    refuse_inputs({"--out": args.out or None, "--error-map": args.error_map or None},
                  {"--mesh": mesh_file})


def _samefile(a, b) -> bool:
    try:
        return os.path.samefile(a, b)
    except OSError:
        return False


def run(args) -> int:
    """Run ``chebnorm render``: render a mesh with the chosen shading and
    normalization, measure its error against the reference, and write the
    image (``--out``) and the error heat map (``--error-map``) when asked.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line of ``chebnorm render`` (the options its
        :func:`register` declares; ``args.argv``, set by :func:`chebnorm.cli.main`,
        is the command quoted in provenance banners).

    Returns
    -------
    int
        The exit status: 0 on success.

    Raises
    ------
    ValueError
        On a bad option (an unknown ``--reference`` mode, a ``--crease-angle`` out of
        range, an option that does nothing with this ``--shading``)
        (:func:`chebnorm.cli.main` prints it as one line on stderr and exits with status
        2).
    """
    import numpy as np

    from chebnorm.core.files import check_writable, write_all
    from chebnorm.raster import Lighting, compare, error_map_rgb, get_mesh, render
    from chebnorm.raster.metrics import image_bytes, image_format

    t_start = time.perf_counter()
    _refuse_unused(args)
    ref_mode, ref_method, ref_bump = parse_reference(args.reference, args.shading)
    for option, path in (("--out", args.out), ("--error-map", args.error_map)):
        if path:
            try:
                image_format(path)
            except ValueError as exc:
                raise ValueError(f"{option}: {exc}") from None
    _refuse_clobber(args)
    check_writable(p for p in (args.out, args.error_map) if p)  # before the renders, not after
    lighting = Lighting(shininess=args.shininess, half_vector=args.half_vector)
    mesh = get_mesh(args.mesh, args.tess, _crease_radians(args.crease_angle))
    common = dict(size=tuple(args.size), lighting=lighting, engine=args.engine,
                  eta_threshold=ETA_THRESHOLD if args.eta_threshold is None
                  else args.eta_threshold, q=Q_THRESHOLD if args.q is None else args.q)
    result = render(mesh, args.shading, args.method or "exact", bump=args.bump or "full",
                    **common)
    reference = render(mesh, ref_mode, ref_method, bump=ref_bump, dtype=np.float64, **common)
    metrics, diff = compare(result, reference)
    # everything validated and computed: now write the outputs, both or neither
    outputs = ([(args.out, image_bytes(result.image8, image_format(args.out)))] if args.out else [])
    if args.error_map:
        outputs.append((args.error_map, image_bytes(error_map_rgb(diff), image_format(args.error_map))))
    write_all(outputs)
    report = metrics.to_dict()
    report.update({
        "seconds": result.seconds,
        "seconds_total": time.perf_counter() - t_start,
        "mesh": result.mesh, "shading": result.shading, "method": result.method,
        "reference": f"{ref_mode}:{ref_bump if ref_mode == 'bump' else ref_method}",
        "size": list(args.size), "triangles": result.triangles, "fragments": result.fragments,
    })
    report.update(result.stats)
    if args.json:
        print_json(report)
    else:
        psnr = "inf" if metrics.psnr is None else f"{metrics.psnr:.2f}"
        print(f"{result.mesh} {result.shading}{':' + result.method if result.method else ''} vs "
              f"{report['reference']}: max {metrics.max_abs_8bit} levels, "
              f"{metrics.pixels_off_1}/{metrics.pixels} pixels off >= 1, mean "
              f"{metrics.mean_abs_8bit:.4f}, PSNR {psnr} dB, SSIM {metrics.ssim:.5f}, "
              f"FLIP {metrics.flip:.5f}, {result.seconds:.3f} s")
        for key, value in result.stats.items():
            print(f"  {key}: {value}")
    return 0
