"""Rich display of renders in Jupyter: a frame beside its error map and its
metrics, as self-contained HTML (PNG images inlined as base64).

A :class:`RenderResult` shows itself (``_repr_html_``): its image, the map of
the pixel normals' length error ``| |N| - 1 |`` when the mode has one
(``phong``, ``adaptive``), and what the mode reports. A
:class:`RenderComparison` shows a frame against a reference: both images, the
heat map of ``|test - reference|`` in 8-bit levels and the
:class:`ImageMetrics`.

Every text shown (mesh names come from files) is HTML-escaped.

>>> from chebnorm.raster import render
>>> ref = render("sphere", "phong", "exact", size=(24, 24), tess=6)
>>> view = RenderComparison(render("sphere", "gouraud", size=(24, 24), tess=6), ref)
>>> view.metrics.max_abs_8bit > 0, "data:image/png;base64," in view._repr_html_()
(True, True)
"""

from __future__ import annotations

import base64
import io
from dataclasses import dataclass, field
from html import escape

import numpy as np

from .metrics import ImageFrame, ImageMetrics, compare, error_map_rgb

# an implementation module of chebnorm.raster: the API is what chebnorm.raster exports
__all__: list[str] = []


def png_data_uri(array) -> str:
    """A ``data:image/png;base64,...`` URI of a uint8 ``(H, W)`` or
    ``(H, W, 3)`` image.

    Parameters
    ----------
    array : numpy.ndarray
        uint8 image, ``(H, W)`` or ``(H, W, 3)``.

    Returns
    -------
    str
        The PNG encoded as a data URI, for an ``<img src=...>``.

    Examples
    --------
    >>> png_data_uri(np.zeros((2, 2), dtype=np.uint8)).startswith("data:image/png;base64,")
    True
    """
    from PIL import Image

    a = np.asarray(array)
    if a.dtype != np.uint8 or a.ndim not in (2, 3):
        raise ValueError(f"png_data_uri needs a uint8 (H, W) or (H, W, 3) array; got {a.dtype} {a.shape}")
    buf = io.BytesIO()
    Image.fromarray(a).save(buf, format="PNG")
    return "data:image/png;base64," + base64.b64encode(buf.getvalue()).decode("ascii")


def _figure(title: str, array, caption: str = "") -> str:
    h, w = np.asarray(array).shape[:2]
    scale = max(1, 256 // max(h, w))
    return (f"<figure style='display:inline-block;margin:4px;text-align:center'>"
            f"<img src='{png_data_uri(array)}' width='{w * scale}' height='{h * scale}' "
            f"style='image-rendering:pixelated' alt='{escape(title)}'/>"
            f"<figcaption>{escape(title)}<br/><small>{escape(caption)}</small></figcaption></figure>")


def _rows(pairs) -> str:
    return "".join(f"<tr><th style='text-align:left'>{escape(str(k))}</th>"
                   f"<td style='text-align:left'>{escape(_fmt(v))}</td></tr>" for k, v in pairs)


def _fmt(v) -> str:
    if isinstance(v, float):
        return f"{v:.6g}"
    return str(v)


def _describe(r: ImageFrame) -> str:
    return f"{r.mesh}, {r.shading}" + (f" ({r.method})" if r.method else "")


#: the smallest error the length-error map's white stands for: 2^-20, far below what
#: changes an 8-bit shading level (1/255), so pure rounding noise maps to black
LENGTH_SCALE_FLOOR = 2.0 ** -20


def render_html(result: ImageFrame) -> str:
    """The HTML shown for a :class:`RenderResult`: image, length-error map
    (when the mode has pixel normals) and the render's numbers.

    Parameters
    ----------
    result : RenderResult
        The frame.

    Returns
    -------
    str
        HTML with the images inlined as data URIs (no file, no network).

    Examples
    --------
    >>> from chebnorm.raster import render
    >>> "length error" in render_html(render("sphere", "phong", "newton", size=(16, 16), tess=6))
    True
    """
    parts = [_figure(_describe(result), result.image8, f"{result.image.shape[1]}x{result.image.shape[0]}")]
    nl = result.normal_length
    if nl is not None and np.isfinite(nl).any():
        err = np.where(np.isfinite(nl), np.abs(nl - 1.0), 0.0)
        worst = float(err.max())
        # white is the largest error, but never below LENGTH_SCALE_FLOOR: rounding noise
        # (2e-16 for an exact normalization) stays black instead of filling the scale
        scale = max(worst, LENGTH_SCALE_FLOOR)
        parts.append(_figure("| |N| - 1 | (length error)", error_map_rgb(err / scale * 255.0, 255.0),
                             f"black 0, white {scale:.3g}; largest {worst:.3g}"))
    rows = [("mesh", result.mesh), ("shading", result.shading), ("method", result.method),
            ("triangles", result.triangles), ("fragments", result.fragments),
            ("covered pixels", result.pixels), ("seconds", result.seconds)]
    rows += sorted(result.stats.items())
    return "<div>" + "".join(parts) + f"<table>{_rows(rows)}</table></div>"


@dataclass
class RenderComparison:
    """A frame against a reference: shown (in Jupyter) as both images, the
    heat map of ``|test - reference|`` in 8-bit levels (black 0, white the
    largest error) and the :class:`ImageMetrics` of :func:`compare`.

    ``flip``: compute the FLIP metric too (slower). See the module example.

    Parameters
    ----------
    test : RenderResult or ImageFrame
        The frame judged.
    reference : RenderResult or ImageFrame
        The frame it is compared with (same size).
    flip : bool, optional
        Compute the FLIP metric too (slower).
    """

    test: ImageFrame
    reference: ImageFrame
    flip: bool = True
    metrics: ImageMetrics = field(init=False)
    diff: np.ndarray = field(init=False, repr=False)

    def __post_init__(self):
        self.metrics, self.diff = compare(self.test, self.reference, flip=self.flip)

    def __repr__(self) -> str:
        def frame(r):
            return f"{getattr(r, 'mesh', '?')} {getattr(r, 'shading', '?')}" + (
                f":{r.method}" if getattr(r, "method", None) else "")

        m = self.metrics
        return (f"RenderComparison(test={frame(self.test)!r}, reference="
                f"{frame(self.reference)!r}, max_abs_8bit={m.max_abs_8bit}, "
                f"psnr={m.psnr if m.psnr is None else round(m.psnr, 3)}, "
                f"flip={'not computed' if m.flip is None else round(m.flip, 6)})")

    def _repr_html_(self) -> str:
        worst = int(np.abs(self.diff).max()) if self.diff.size else 0
        parts = [_figure(_describe(self.test), self.test.image8, "test"),
                 _figure(_describe(self.reference), self.reference.image8, "reference"),
                 _figure("|test - reference|", error_map_rgb(self.diff), f"white = {max(worst, 1)} levels")]
        rows = [(k, ("not computed" if k == "flip" else "n/a (identical)") if v is None else v)
                for k, v in self.metrics.to_dict().items()]
        return "<div>" + "".join(parts) + f"<table>{_rows(rows)}</table></div>"
