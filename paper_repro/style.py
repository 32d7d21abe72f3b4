"""One figure style for the whole reproduction, and deterministic writers.

* Figures are drawn on the Agg canvas (no display, no pyplot: importing
  this module selects no backend and changes no global state), with one
  rcParams set (:data:`RC`) applied inside :func:`figure` and
  :func:`save_figure` only.
* :func:`save_figure` writes ``<stem>.png``, ``<stem>.svg`` and the caption
  ``<stem>.txt``; PNG and SVG carry no date or software version. matplotlib
  names clip paths, markers and images by a hash of their full-precision
  coordinates (a last-bit difference in a layout computation renames them),
  so :func:`stable_svg_ids` renumbers those ids in order of first use.
* :func:`write_csv` writes the figure's data with a ``#`` header (caption,
  producing command, notes), rows in the order given (the callers give them
  sorted); :func:`fmt` is the one number format of every CSV cell and JSON
  value: integers as integers, floats with :data:`FLOAT_FORMAT` (10
  significant digits, more than any figure reads; the numbers themselves are
  made machine-independent where they are computed, see
  :mod:`chebnorm.methods.detmath`).

Every file goes through :func:`chebnorm.core.files.write_atomic` (temporary
file, then rename).
"""

from __future__ import annotations

import io
import json
import math
import re
from contextlib import contextmanager
from pathlib import Path
from typing import Iterable, Sequence

import matplotlib
import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from chebnorm.core.files import write_atomic

__all__ = ["RC", "FLOAT_FORMAT", "figure", "save_figure", "stable_svg_ids", "write_csv",
           "write_json", "write_text", "fmt", "COLORS", "METHOD_STYLE", "ERROR_MAP", "ERROR_CMAP",
           "error_map", "error_maps_of"]

#: the float format of every CSV cell
FLOAT_FORMAT = "%.10g"
#: a colour-blind-safe cycle (Okabe-Ito)
COLORS = ("#0072B2", "#D55E00", "#009E73", "#CC79A7", "#E69F00", "#56B4E9", "#F0E442", "#000000")
#: per span method: (colour, marker), distinct in colour for colour-blind readers and, through
#: the marker, in greyscale (Okabe-Ito colours; the line style is left to encode the number format)
METHOD_STYLE = {
    "none": ("#000000", "o"), "newton": ("#0072B2", "s"), "lyon": ("#D55E00", "^"),
    "slerp": ("#009E73", "D"), "dichotomy": ("#CC79A7", "v"), "quadratic": ("#E69F00", "P"),
    "quadratic_exact_midpoint": ("#7F7F7F", "X"), "angular": ("#56B4E9", "*"),
}
#: the label of every axes that shows an error map (the tests find them by it)
ERROR_MAP = "error map"
#: error maps: perceptually uniform, dark = no error, readable in greyscale
ERROR_CMAP = "magma"
RC = {
    "figure.figsize": (6.4, 4.2),
    "figure.dpi": 100,
    "savefig.dpi": 120,
    "font.size": 9,
    "axes.titlesize": 9,
    "axes.labelsize": 9,
    "legend.fontsize": 8,
    "axes.grid": True,
    "grid.alpha": 0.3,
    "axes.prop_cycle": matplotlib.cycler(color=COLORS),
    "lines.linewidth": 1.4,
    "svg.hashsalt": "chebnorm-repro",
    "svg.fonttype": "path",
    "path.simplify": False,
    "image.cmap": "viridis",
}


@contextmanager
def figure(nrows: int = 1, ncols: int = 1, **kwargs):
    """``fig, axes`` in the reproduction's style; closed on exit."""
    with matplotlib.rc_context(RC):
        fig = Figure(figsize=kwargs.pop("figsize", RC["figure.figsize"]),
                     layout=kwargs.pop("layout", "constrained"))
        FigureCanvasAgg(fig)
        axes = fig.subplots(nrows, ncols, **kwargs)
        yield fig, axes


def error_map(fig, ax, diff, vmax: float, title: str):
    """Draw ``|diff|`` (8-bit levels) on ``ax`` from 0 to ``vmax`` (one scale for the whole
    figure) with its own colour bar in 8-bit levels; the axes is labelled :data:`ERROR_MAP`."""
    im = ax.imshow(np.abs(np.asarray(diff, dtype=float)), interpolation="nearest", cmap=ERROR_CMAP,
                   vmin=0.0, vmax=float(vmax))
    ax.set_title(title, fontsize=8)
    ax.set_axis_off()
    ax.set_label(ERROR_MAP)
    bar = fig.colorbar(im, ax=ax, shrink=0.85, pad=0.02)
    bar.set_label("8-bit levels", fontsize=7)
    bar.ax.tick_params(labelsize=7)
    return im


def error_maps_of(fig) -> list:
    """The axes of ``fig`` drawn by :func:`error_map`, each with its image (``(ax, image)``)."""
    return [(ax, ax.images[0]) for ax in fig.axes if ax.get_label() == ERROR_MAP and ax.images]


def write_text(path: Path, text: str) -> Path:
    write_atomic(path, text)
    return Path(path)


#: the ids matplotlib's SVG writer derives from a hash: clip paths (p), markers (m), images (i)
_HASHED_ID = re.compile(r"\b[pmi][0-9a-f]{10}\b")


def stable_svg_ids(svg: str) -> str:
    """Rename matplotlib's hashed SVG ids to ``<letter><serial>`` in order of first use.

    >>> stable_svg_ids('<use xlink:href="#m0123abcdef"/><path id="m0123abcdef"/>')
    '<use xlink:href="#m0000000001"/><path id="m0000000001"/>'
    """
    defined = set(re.findall(r'id="([pmi][0-9a-f]{10})"', svg))
    names: dict[str, str] = {}
    for match in _HASHED_ID.finditer(svg):
        tok = match.group(0)
        if tok in defined and tok not in names:
            names[tok] = f"{tok[0]}{len(names) + 1:010d}"
    return _HASHED_ID.sub(lambda m: names.get(m.group(0), m.group(0)), svg)


def save_figure(fig, folder: Path, stem: str, caption: str) -> list[Path]:
    """Write ``fig`` as ``folder/stem.png`` and ``.svg`` (deterministic bytes)
    and its caption as ``folder/stem.txt``; return the three paths."""
    folder = Path(folder)
    written = []
    with matplotlib.rc_context(RC):
        for ext, meta in (("png", {"Software": None}),
                          ("svg", {"Date": None, "Creator": None})):
            buf = io.BytesIO()
            fig.savefig(buf, format=ext, metadata=meta, bbox_inches="tight")
            data = buf.getvalue()
            if ext == "svg":
                data = stable_svg_ids(data.decode("utf-8")).encode("utf-8")
            path = folder / f"{stem}.{ext}"
            write_atomic(path, data)
            written.append(path)
    written.append(write_text(folder / f"{stem}.txt", caption.strip() + "\n"))
    return written


def fmt(value) -> str:
    """One CSV cell: integers as integers, :data:`FLOAT_FORMAT` for floats, ``str`` for the
    rest ("nan"/"inf" spelled so).

    >>> fmt(3), fmt(0.1 + 0.2), fmt(float("nan")), fmt("a,b")
    ('3', '0.3', 'nan', '"a,b"')
    """
    if isinstance(value, (bool, np.bool_)):
        return "1" if value else "0"
    if isinstance(value, (int, np.integer)):
        return str(int(value))
    if isinstance(value, (float, np.floating)):
        v = float(value)
        if math.isnan(v):
            return "nan"
        if math.isinf(v):
            return "inf" if v > 0 else "-inf"
        return FLOAT_FORMAT % v
    text = str(value)
    if any(ch in text for ch in ",\n\""):
        text = '"' + text.replace('"', '""') + '"'
    return text


def write_csv(folder: Path, stem: str, columns: Sequence[str], rows: Iterable[Sequence],
              caption: str, command: str, notes: Sequence[str] = ()) -> Path:
    """Write ``folder/stem.csv``: ``#`` comment lines (caption, command, notes),
    then the header and the rows, in the order given."""
    lines = [f"# {line}" for line in caption.strip().splitlines()]
    lines.append(f"# command: {command}")
    lines += [f"# {n}" for n in notes]
    lines.append(",".join(columns))
    for row in rows:
        if len(row) != len(columns):
            raise ValueError(f"{stem}.csv: row {row!r} has {len(row)} cells; expected {len(columns)}")
        lines.append(",".join(fmt(v) for v in row))
    path = Path(folder) / f"{stem}.csv"
    write_atomic(path, "\n".join(lines) + "\n")
    return path


def _jsonable(obj):
    if isinstance(obj, dict):
        return {str(k): _jsonable(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_jsonable(v) for v in obj]
    if isinstance(obj, (np.integer,)):
        return int(obj)
    if isinstance(obj, (float, np.floating)):
        v = float(obj)
        return float(FLOAT_FORMAT % v) if math.isfinite(v) else str(v)
    if isinstance(obj, np.bool_):
        return bool(obj)
    return obj


def write_json(path: Path, data) -> Path:
    """Sorted keys, floats rounded to ``%.10g``, two-space indent, final newline."""
    write_atomic(path, json.dumps(_jsonable(data), sort_keys=True, indent=2, ensure_ascii=False) + "\n")
    return Path(path)
