"""Image-error metrics against a reference render, error heat maps, and
atomic image writing (PNG, JPEG, TIFF, BMP by file extension).

All metrics are computed on the 8-bit images (``round(255 I)``), so "0
error" means identical 8-bit output.  Over the *covered* pixels (the union of
both masks): ``max_abs_8bit``, ``pixels_off_1`` (pixels off by one level or
more), ``mean_abs_8bit``, ``psnr`` (dB, peak 255; ``None`` for identical
images, whose PSNR is infinite), ``flip`` (mean FLIP error, LDR, default 67
pixels per degree).  ``ssim`` is scikit-image's structural similarity over the
whole image with an explicit ``data_range=255``.
"""

from __future__ import annotations

import math
import os
from dataclasses import asdict, dataclass

import numpy as np

from chebnorm.core.display import summary_html

# an implementation module of chebnorm.raster: the API is what chebnorm.raster exports
__all__: list[str] = []


@dataclass(frozen=True)
class ImageMetrics:
    """Errors of a frame against a reference, on 8-bit images, over the
    covered pixels (see the module docstring): largest and mean absolute
    difference in levels, pixels off by one level or more, PSNR (``None``
    when identical), SSIM, mean FLIP (``None`` when not computed:
    ``compare(..., flip=False)``), and the number of covered pixels.

    Attributes
    ----------
    max_abs_8bit : int
        Largest absolute difference in 8-bit levels.
    pixels_off_1 : int
        Covered pixels that differ by one level or more.
    mean_abs_8bit : float
        Mean absolute difference in levels.
    psnr : float or None
        Peak signal-to-noise ratio in dB (None when the images are identical).
    ssim : float
        Structural similarity (1 for identical images).
    flip : float or None
        Mean FLIP error (None when not computed).
    pixels : int
        Covered pixels (either frame's mask).
    """

    max_abs_8bit: int
    pixels_off_1: int
    mean_abs_8bit: float
    psnr: float | None
    ssim: float
    flip: float | None
    pixels: int

    def _display_rows(self) -> list[tuple[str, object]]:
        return [(k, ("n/a (identical)" if k == "psnr" else "not computed") if v is None else v)
                for k, v in asdict(self).items()]

    _repr_html_ = summary_html

    def to_dict(self) -> dict:
        """The fields as a plain dict (for JSON)."""
        return asdict(self)


class ImageFrame:
    """A rendered frame as :func:`compare` takes it whole: its 8-bit image ``image8``
    and its coverage ``mask`` (both (H, W)).  :class:`chebnorm.raster.RenderResult` is
    the one kind; this base class lets the metrics recognize it without importing
    the renderer."""

    __slots__ = ()


def to_8bit(image) -> np.ndarray:
    """Intensities in ``[0, 1]`` to 8-bit levels, ``round(255 I)`` after
    clipping.

    Parameters
    ----------
    image : numpy.ndarray
        Intensities (float; clipped to ``[0, 1]``).

    Returns
    -------
    numpy.ndarray
        uint8 levels.

    Examples
    --------
    >>> to_8bit([-0.5, 0.0, 0.5, 1.0, 2.0]).tolist()
    [0, 0, 128, 255, 255]
    """
    return np.round(np.clip(image, 0.0, 1.0) * 255.0).astype(np.uint8)


def _as_8bit(x):
    if isinstance(x, ImageFrame):
        return x.image8, x.mask
    a = np.asarray(x)
    if a.dtype != np.uint8 and (a.dtype.kind not in "biuf" or a.ndim != 2):
        raise ValueError(f"image of type {type(x).__name__} (dtype {a.dtype}, shape {a.shape}) "
                         f"is not accepted; accepted: a RenderResult, or a 2-D array of numbers "
                         f"in [0, 1] or of uint8")
    if a.dtype != np.uint8:
        a = to_8bit(a)
    return a, np.ones(a.shape, dtype=bool)


def compare(test, reference, *, flip: bool = True) -> tuple[ImageMetrics, np.ndarray]:
    """Metrics of ``test`` against ``reference`` (RenderResults or images in
    ``[0, 1]`` / uint8) and the signed difference ``test - reference`` in
    8-bit levels, shape ``(H, W)``.

    Parameters
    ----------
    test : RenderResult or numpy.ndarray
        The frame judged: a render, or an image in ``[0, 1]`` or uint8.
    reference : RenderResult or numpy.ndarray
        The frame compared with, of the same size.
    flip : bool, optional
        Compute the FLIP metric (slower).

    Returns
    -------
    metrics : ImageMetrics
        The error figures.
    diff : numpy.ndarray
        ``test - reference`` in 8-bit levels, int, shape ``(H, W)``.

    Raises
    ------
    ValueError
        For images of different sizes or values out of range.

    See Also
    --------
    chebnorm.render : the frames compared.
    chebnorm.raster.RenderComparison : both frames and the error map, displayed.
    ImageMetrics : the figures returned.

    Notes
    -----
    Both frames are taken to 8-bit levels :math:`a, b \\in \\{0, \\dots, 255\\}`
    and compared on the pixels :math:`M` either covers, with
    :math:`d = a - b`:

    .. math::

        \\mathrm{max\\_abs} = \\max_M |d|, \\qquad
        \\mathrm{MSE} = \\frac{1}{|M|}\\sum_M d^2, \\qquad
        \\mathrm{PSNR} = 10 \\log_{10}\\frac{255^2}{\\mathrm{MSE}}

    (``psnr`` None when the frames agree); ``ssim`` is the structural
    similarity [1]_ over the whole frame (7-pixel window) and ``flip`` the
    mean FLIP error [2]_ over :math:`M` (None unless ``flip``; 0 when the
    frames agree).

    References
    ----------
    .. [1] Z. Wang, A. C. Bovik, H. R. Sheikh, E. P. Simoncelli, "Image
       quality assessment: from error visibility to structural similarity",
       IEEE Transactions on Image Processing 13(4), 2004.
    .. [2] P. Andersson, J. Nilsson, T. Akenine-Moller, M. Oskarsson,
       K. Astrom, M. D. Fairchild, "FLIP: a difference evaluator for
       alternating images", Proceedings of the ACM on Computer Graphics and
       Interactive Techniques 3(2), 2020.

    Examples
    --------
    >>> import numpy as np
    >>> m, d = compare(np.zeros((8, 8)), np.zeros((8, 8)), flip=False)
    >>> m.max_abs_8bit, m.psnr, m.flip
    (0, None, None)
    """
    from skimage.metrics import structural_similarity

    a, ma = _as_8bit(test)
    b, mb = _as_8bit(reference)
    if a.shape != b.shape:
        raise ValueError(f"cannot compare images of shapes {a.shape} and {b.shape}")
    mask = ma | mb
    diff = a.astype(np.int64) - b.astype(np.int64)
    ad = np.abs(diff)[mask]
    n = int(mask.sum())
    mse = float(np.mean(ad.astype(float) ** 2)) if n else 0.0
    psnr = None if mse == 0 else 10 * math.log10(255.0 ** 2 / float(mse))
    win = min(7, *a.shape)
    win -= 1 - win % 2
    ssim = float(structural_similarity(a, b, data_range=255, win_size=max(win, 1))) if win >= 3 else \
        float(a.tobytes() == b.tobytes())
    flip_mean = 0.0 if flip else None   # not computed: None, never a FLIP of 0
    if flip and n and ad.max() > 0:
        import flip_evaluator

        ref = np.repeat((b.astype(np.float32) / 255.0)[..., None], 3, axis=2)
        tst = np.repeat((a.astype(np.float32) / 255.0)[..., None], 3, axis=2)
        fmap, _, _ = flip_evaluator.evaluate(ref, tst, "LDR", applyMagma=False)
        fmap = np.asarray(fmap, dtype=float)
        fmap = fmap.reshape(a.shape) if fmap.size == a.size else fmap.reshape(*a.shape, -1)[..., 0]
        flip_mean = float(fmap[mask].mean())
    metrics = ImageMetrics(int(ad.max()) if n else 0, int((ad >= 1).sum()),
                           float(ad.mean()) if n else 0.0, psnr, ssim, flip_mean, n)
    return metrics, diff


def error_map_rgb(diff, scale: float | None = None) -> np.ndarray:
    """A heat map (uint8 RGB) of ``|diff|`` in 8-bit levels: black (0) through
    red and yellow to white at ``scale`` levels (default: the largest error,
    at least 1).

    Parameters
    ----------
    diff : numpy.ndarray
        Differences in 8-bit levels, ``(H, W)``.
    scale : float, optional
        The level shown white.

    Returns
    -------
    numpy.ndarray
        uint8 RGB image ``(H, W, 3)``.

    Examples
    --------
    >>> import numpy as np
    >>> error_map_rgb(np.array([[0, -1, 2, 3, 9]]), scale=3).tolist()
    [[[0, 0, 0], [255, 0, 0], [255, 255, 0], [255, 255, 255], [255, 255, 255]]]
    """
    e = np.abs(np.asarray(diff, dtype=float))
    s = float(scale) if scale is not None else max(1.0, float(e.max()))
    x = np.clip(e / s, 0.0, 1.0)
    r = np.clip(3 * x, 0, 1)
    g = np.clip(3 * x - 1, 0, 1)
    b = np.clip(3 * x - 2, 0, 1)
    return np.round(np.stack([r, g, b], -1) * 255).astype(np.uint8)


#: image formats :func:`write_image` writes, by file extension (Pillow writes
#: each deterministically: the same array gives the same bytes)
IMAGE_FORMATS = {".png": "PNG", ".jpg": "JPEG", ".jpeg": "JPEG", ".tif": "TIFF",
                 ".tiff": "TIFF", ".bmp": "BMP"}
#: JPEG is lossy: a fixed quality so that outputs are reproducible
JPEG_QUALITY = 95


def image_bytes(array, fmt: str = "PNG") -> bytes:
    """Encode a uint8 image ``(H, W)`` or ``(H, W, 3)`` in ``fmt`` (a value of
    :data:`IMAGE_FORMATS`); JPEG at quality :data:`JPEG_QUALITY`.

    Parameters
    ----------
    array : numpy.ndarray
        uint8 image ``(H, W)`` or ``(H, W, 3)``.
    fmt : str, optional
        The format name.

    Returns
    -------
    bytes
        The encoded file.

    Raises
    ------
    ValueError
        For an unknown format or an image that is not uint8 of those shapes.

    Examples
    --------
    >>> image_bytes(np.zeros((2, 2), np.uint8))[:4]
    b'\\x89PNG'
    """
    import io

    from PIL import Image

    a = np.asarray(array)
    if a.dtype != np.uint8 or a.ndim not in (2, 3) or (a.ndim == 3 and a.shape[2] != 3):
        raise ValueError(f"an image must be a uint8 (H, W) or (H, W, 3) array; got {a.dtype} {a.shape}")
    if fmt not in set(IMAGE_FORMATS.values()):
        raise ValueError(f"unknown image format {fmt!r}; accepted: "
                         f"{', '.join(sorted(set(IMAGE_FORMATS.values())))}")
    buf = io.BytesIO()
    options = {"quality": JPEG_QUALITY} if fmt == "JPEG" else {}
    Image.fromarray(a).save(buf, format=fmt, **options)
    return buf.getvalue()


def image_format(path) -> str:
    """The image format a file name asks for, from its extension; refuses an
    extension outside :data:`IMAGE_FORMATS` (naming the accepted set).

    Parameters
    ----------
    path : str or os.PathLike
        A file name.

    Returns
    -------
    str
        The format name (``"PNG"``, ``"JPEG"``, ...).

    Raises
    ------
    ValueError
        For an extension outside :data:`IMAGE_FORMATS`.

    Examples
    --------
    >>> image_format("out.JPG")
    'JPEG'
    """
    ext = os.path.splitext(os.fspath(path))[1].lower()
    if ext not in IMAGE_FORMATS:
        raise ValueError(f"cannot write image {os.fspath(path)!r}: unknown extension {ext or '(none)'!r}; "
                         f"accepted: {', '.join(IMAGE_FORMATS)}")
    return IMAGE_FORMATS[ext]


def write_image(path, array) -> None:
    """Write a uint8 image ``(H, W)`` or ``(H, W, 3)`` in the format its
    extension names (:data:`IMAGE_FORMATS`), atomically and with mode 0644
    (:func:`chebnorm.core.files.write_atomic`).

    Parameters
    ----------
    path : str or os.PathLike
        The destination; its extension names the format.
    array : numpy.ndarray
        uint8 image ``(H, W)`` or ``(H, W, 3)``.

    Raises
    ------
    ValueError
        For an extension that is not accepted, or a bad image.
    chebnorm.core.files.WriteError
        When the file cannot be written.
    """
    from chebnorm.core.files import write_atomic

    data = image_bytes(array, image_format(path))
    write_atomic(path, data)


def write_png(path, array) -> None:
    """:func:`write_image` for a ``.png`` path (refuses any other extension,
    so a PNG never hides behind another name).

    Parameters
    ----------
    path : str or os.PathLike
        The destination; its extension names the format.
    array : numpy.ndarray
        uint8 image ``(H, W)`` or ``(H, W, 3)``.

    Raises
    ------
    ValueError
        For an extension that is not accepted, or a bad image.
    chebnorm.core.files.WriteError
        When the file cannot be written.
    """
    if image_format(path) != "PNG":
        raise ValueError(f"write_png writes PNG; {os.fspath(path)!r} names another format "
                         "(use write_image)")
    write_image(path, array)
