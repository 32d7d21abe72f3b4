"""``chebnorm render-sweep``: render a grid of meshes x shading modes x methods x
sizes, each against its reference render, into one CSV of error metrics."""

from __future__ import annotations

import re

from .common import ETA_THRESHOLD, Q_THRESHOLD, add_lighting_options, refuse_unused
from .parallel_options import add_parallel_args, parallel_kwargs
from .vocab import BUMP_VARIANTS, MESH_NAMES, SHADING_MODES

#: the CSV and the image folder inside ``-o DIR``
CSV_NAME = "render_sweep.csv"
#: the folder of the images inside ``-o DIR``
IMAGE_FOLDER = "render_sweep_images"


def register(sub) -> None:
    """Add the ``chebnorm render-sweep`` subcommand.

    Parameters
    ----------
    sub : argparse._SubParsersAction
        The subparsers of the ``chebnorm`` parser (from
        ``argparse.ArgumentParser.add_subparsers``); the new parser's ``func``
        default is :func:`run`.
    """
    p = sub.add_parser("render-sweep", help="render a grid of cases and measure their errors",
                       description="Render every mesh x tessellation x size x shininess x "
                       "shading x method (x bump variant) and compare each with its reference "
                       "render (default phong:exact; bump:full for bump): one sorted CSV of "
                       "max/mean 8-bit error, pixels off, PSNR, SSIM, FLIP; the same bytes "
                       "whatever --workers or --scheduler runs it.")
    p.add_argument("--meshes", nargs="+", default=["teapot", "sphere"], metavar="MESH",
                   help=f"{'|'.join(MESH_NAMES)} or .obj/.ply/.stl paths (default teapot sphere)")
    p.add_argument("--shadings", nargs="+", default=["phong"], metavar="MODE",
                   help=f"{'|'.join(SHADING_MODES)} (default phong)")
    p.add_argument("--methods", nargs="+", default=None, metavar="METHOD",
                   help="normalization methods of phong/adaptive/bump (default: every "
                   "registered one; see chebnorm methods)")
    p.add_argument("--sizes", nargs="+", default=["256"], metavar="W[xH]",
                   help="image sizes, W (square) or WxH, 1..16384 (default 256)")
    p.add_argument("--tess", nargs="+", type=int, default=None, metavar="K",
                   help="tessellation levels of the generated meshes (default: each mesh's own)")
    p.add_argument("--shininess", nargs="+", type=float, default=[32.0], metavar="N",
                   help="specular exponents, >= 1 (default 32)")
    p.add_argument("--bumps", nargs="+", default=None, metavar="VARIANT",
                   help=f"bump variants of the bump cases: {'|'.join(BUMP_VARIANTS)} "
                   "(default full)")
    p.add_argument("--reference", default=None, metavar="MODE[:METHOD]",
                   help="reference render of every case (default phong:exact; bump:full for "
                   "bump cases), as chebnorm render")
    add_lighting_options(p, "as chebnorm render (every engine gives the same bytes)")
    p.add_argument("--images", action="store_true",
                   help=f"also write each image and its error map as PNG into "
                   f"DIR/{IMAGE_FOLDER}/ (NAME.png, NAME_error.png; NAME: the CSV's name column)")
    p.add_argument("-o", "--output", metavar="DIR", required=True,
                   help=f"folder for {CSV_NAME} (created when the first case finishes)")
    add_parallel_args(p)
    p.set_defaults(func=run)


def parse_size(text: str) -> tuple[int, int]:
    """``"W"`` (a square) or ``"WxH"`` as ``(W, H)``; the range is checked by the sweep.

    Parameters
    ----------
    text : str
        One or two decimal integers of at most 6 digits, ``"W"`` or ``"WxH"``
        (``x`` or ``X``, surrounding spaces allowed).

    Returns
    -------
    tuple of int
        ``(W, H)``.

    Raises
    ------
    ValueError
        When ``text`` is not of that form, naming the accepted range.

    >>> parse_size("128"), parse_size("320x200")
    ((128, 128), (320, 200))
    """
    from chebnorm.raster.studies import MAX_SIZE

    m = re.fullmatch(r"\s*([0-9]{1,6})\s*(?:[xX]\s*([0-9]{1,6})\s*)?", text)
    w, h = (0, 0) if m is None else (int(m.group(1)), int(m.group(m.lastindex)))
    if not (1 <= w <= MAX_SIZE and 1 <= h <= MAX_SIZE):
        raise ValueError(f"size {text!r}: expected W or WxH, integers in [1, {MAX_SIZE}]")
    return w, h


def run(args) -> int:
    """Run ``chebnorm render-sweep``: render a grid of cases (meshes x
    methods x sizes) into the folder ``-o``, with a CSV of the measured errors.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line of ``chebnorm render-sweep`` (the options its
        :func:`register` declares; ``args.argv``, set by :func:`chebnorm.cli.main`,
        is the command quoted in provenance banners).

    Returns
    -------
    int
        The exit status: 0 on success.

    Raises
    ------
    ValueError
        When the output exists and is not a folder, a size is malformed, two cases would
        write the same image name, or an option is out of range
        (:func:`chebnorm.cli.main` prints it as one line on stderr and exits with status
        2).
    """
    from pathlib import Path

    from chebnorm.core.files import make_folder, write_atomic
    from chebnorm.raster import RenderSweep, render_sweep, render_sweep_cases

    from .render import parse_reference

    out = Path(args.output)
    if out.exists() and not out.is_dir():
        raise ValueError(f"output {args.output!r} exists and is not a folder; accepted: a folder "
                         "(created if missing)")
    shadings = set(args.shadings)
    if not shadings & {"phong", "adaptive", "bump"}:
        refuse_unused(args, "with --shadings phong, adaptive or bump", **{"--methods": "methods"})
    if "bump" not in shadings:
        refuse_unused(args, "with --shadings bump", **{"--bumps": "bumps"})
    if "adaptive" not in shadings:
        refuse_unused(args, "with --shadings adaptive", **{"--eta-threshold": "eta_threshold"})
    if "split-gouraud" not in shadings:
        refuse_unused(args, "with --shadings split-gouraud", **{"--q": "q"})
    reference = None if args.reference is None else parse_reference(args.reference, "phong")
    cases = render_sweep_cases(args.meshes, args.shadings, args.methods,
                               [parse_size(s) for s in args.sizes],
                               [None] if args.tess is None else args.tess, args.shininess,
                               args.bumps or ["full"], reference)
    names = [c.name for c in cases]
    if args.images and len(set(names)) < len(names):
        twice = sorted({n for n in names if names.count(n) > 1})[0]
        raise ValueError(f"two cases would write images named {twice!r} (meshes with the same "
                         "file name?); accepted: distinct names, or no --images")
    finished: dict = {}

    def keep(index, row):
        """Write each finished case at once: an interrupted sweep keeps its rows."""
        make_folder(out)
        if args.images:
            folder = make_folder(out / IMAGE_FOLDER)
            write_atomic(folder / f"{row.case.name}.png", row.image_png)
            write_atomic(folder / f"{row.case.name}_error.png", row.error_png)
        finished[index] = row
        write_atomic(out / CSV_NAME, RenderSweep(tuple(finished[i] for i in sorted(finished)))
                     .csv())

    sweep = render_sweep(cases, half_vector=args.half_vector,
                         eta_threshold=ETA_THRESHOLD if args.eta_threshold is None
                         else args.eta_threshold, q=Q_THRESHOLD if args.q is None else args.q,
                         engine=args.engine, images=args.images, progress=True,
                         on_row=keep, **parallel_kwargs(args))
    write_atomic(out / CSV_NAME, sweep.csv())  # the same bytes as the last partial write
    print(out / CSV_NAME)
    if args.images:
        print(out / IMAGE_FOLDER)
    worst = max(sweep.rows, key=lambda r: (r.metrics["max_abs_8bit"], r.metrics["mean_abs_8bit"]))
    print(f"{len(sweep.rows)} cases; largest error: {worst.metrics['max_abs_8bit']} levels "
          f"({worst.case.name} vs {worst.case.reference_text})")
    return 0
