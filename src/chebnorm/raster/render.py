"""Shading modes on the span rasterizer: ``gouraud``, ``phong`` (any
normalization method), ``adaptive`` (seed 003), ``split-gouraud`` (seed 002)
and ``bump`` (seed 001).

Lighting is Blinn-Phong (the notation of docs/papers.md): ``I = I0 (k_a + k_d max(0, L.N)
+ k_s max(0, H.N)^n)`` with a directional light ``L`` and a viewer at the
camera; ``H = (L+V)/|L+V|`` is computed per pixel (``V`` from the
interpolated position) or once per triangle at its centroid (seed 002).  The
image is the intensity, clipped to ``[0, 1]``; 8-bit images are
``round(255 I)``.

Span-end normals.  The edge-interpolated normals at a span's ends are
normalized exactly (``n / |n|``) before the span interpolator sees them:
every method of seed 000 takes unit end normals.  The method ``none`` is the
exception: it is "normalization skipped" (seed 003), so neither the span
ends nor the pixels are normalized and the pixel normal is the plain
screen-space linear interpolation of the vertex normals.

The per-pixel normals come from :func:`chebnorm.methods.span_normals` (or a
replacement with its signature); the methods are those of the method registry
(:func:`chebnorm.methods.method_names`).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from chebnorm.methods import detmath, get_method, method_names
from chebnorm.methods import span_normals as _span_normals

from . import shading as shading_modes
from .engines import get_engine
from .meshes import get_mesh, unit
from .metrics import ImageFrame, to_8bit
from .scanline import Camera

# an implementation module of chebnorm.raster: the API is what chebnorm.raster exports
__all__: list[str] = []

#: the shading modes of :func:`render`
SHADING_MODES = ("gouraud", "phong", "adaptive", "split-gouraud", "bump")
#: the bump-mapping variants of ``render(..., shading="bump", bump=...)``
BUMP_VARIANTS = ("full", "square", "object")


# ------------------------------------------------------------------ methods
def get_span_normals():
    """The default span interpolator, :func:`chebnorm.methods.span_normals`.

    Returns
    -------
    callable
        :func:`chebnorm.methods.span_normals` (imported on first use).
    """
    return _span_normals


def available_methods() -> tuple[str, ...]:
    """The normalization methods ``render`` accepts: every registered method.

    Returns
    -------
    tuple of str
        The registered methods' names.

    Examples
    --------
    >>> {"exact", "none", "dichotomy"} <= set(available_methods())
    True
    """
    return method_names()


# ----------------------------------------------------------------- lighting
@dataclass(frozen=True)
class Lighting:
    """Blinn-Phong parameters (docs/papers.md): ``I0, k_a, k_d, k_s``, shininess
    ``n``, unit direction ``light`` *toward* the light (world; default: up and
    to the right of the camera), and where ``H`` is computed: ``"pixel"`` or
    ``"triangle"`` (one ``H`` per triangle, at its centroid, as in seed 002).

    Attributes
    ----------
    I0 : float
        Light intensity.
    ka, kd, ks : float
        Ambient, diffuse and specular coefficients.
    shininess : float
        The specular exponent ``n``.
    light : tuple of 3 float, optional
        Unit direction toward the light (world); None: up and to the right of the camera.
    half_vector : str
        ``"pixel"`` or ``"triangle"``.
    """

    I0: float = 1.0
    ka: float = 0.1
    kd: float = 0.6
    ks: float = 0.3
    shininess: float = 32.0
    light: tuple | None = None
    half_vector: str = "pixel"

    def validate(self):
        for name in ("I0", "ka", "kd", "ks"):
            v = getattr(self, name)
            if not (np.isfinite(v) and v >= 0):
                raise ValueError(f"lighting {name} must be a finite number >= 0; got {v!r}")
        if not (np.isfinite(self.shininess) and self.shininess >= 1):
            raise ValueError(f"shininess must be a finite number >= 1; got {self.shininess!r}")
        if self.half_vector not in ("pixel", "triangle"):
            raise ValueError(f"half_vector must be 'pixel' or 'triangle'; got {self.half_vector!r}")
        if self.light is not None:
            v = np.asarray(self.light, float)
            if v.shape != (3,) or not np.isfinite(v).all() or np.linalg.norm(v) == 0:
                raise ValueError(f"light must be a finite nonzero 3-vector; got {self.light!r}")

    def direction(self, camera: Camera) -> np.ndarray:
        if self.light is not None:
            return unit(np.asarray(self.light, float))
        right, up, back = camera.frame()
        return unit(1.6 * back + 1.0 * right + 1.2 * up)

    def intensity(self, ndotl, ndoth):
        # the C library's pow, not numpy's power loop (SVML on AVX-512: other bits)
        return self.I0 * (self.ka + self.kd * np.maximum(ndotl, 0.0)
                          + self.ks * detmath.power(np.maximum(ndoth, 0.0), self.shininess))


@dataclass(frozen=True)
class HeightMap:
    """Procedural height map ``F(u, v) = A sin(2 pi f_u u) sin(2 pi f_v v)``
    with exact ``F_u, F_v`` (seed 001: the height map gives F_u, F_v).

    Attributes
    ----------
    amplitude : float
        ``A``, the height's amplitude.
    frequency : tuple of (int, int)
        ``(f_u, f_v)``, periods over the parameter square.
    """

    amplitude: float = 0.01
    frequency: tuple = (8, 8)

    def derivatives(self, uv):
        fu, fv = self.frequency
        a, b = 2 * np.pi * fu * uv[:, 0], 2 * np.pi * fv * uv[:, 1]
        F_u = self.amplitude * 2 * np.pi * fu * np.cos(a) * np.sin(b)
        F_v = self.amplitude * 2 * np.pi * fv * np.sin(a) * np.cos(b)
        return F_u, F_v


@dataclass
class RenderResult(ImageFrame):
    """A rendered frame: ``image (H, W)`` intensities in ``[0, 1]``
    (background 0), ``mask`` of covered pixels, and what the mode reports in
    ``stats`` (a flat dict of numbers).

    Attributes
    ----------
    image : numpy.ndarray
        Intensities ``(H, W)`` in ``[0, 1]``.
    mask : numpy.ndarray
        Covered pixels, bool ``(H, W)``.
    mesh : str
        The mesh's name.
    shading : str
        The shading mode.
    method : str or None
        The normalization method (None where the mode has none).
    seconds : float
        Wall time of the render (numba's first compile excluded: see
        ``compile_seconds``).
    triangles : int
        Triangles rendered.
    fragments : int
        Fragments shaded.
    stats : dict
        What the mode reports (a flat dict of numbers).
    triangle : numpy.ndarray, optional
        Index of the visible triangle per pixel (int32: a mesh has at most
        :data:`~chebnorm.raster.meshes.MAX_FACES` faces), -1 on background.
    normal_length : numpy.ndarray, optional
        ``|N|`` of the pixel normal before shading (phong, adaptive), NaN on background.
    compile_seconds : float
        Seconds spent compiling (numba, the first render of a kind in this
        process), before the clock of ``seconds`` started.
    """

    image: np.ndarray
    mask: np.ndarray
    mesh: str
    shading: str
    method: str | None
    seconds: float
    triangles: int
    fragments: int
    stats: dict = field(default_factory=dict)
    #: (H, W) int32 index into mesh.faces of the visible triangle, -1 on background
    triangle: np.ndarray | None = None
    #: (H, W) ``|N|`` of the pixel normal before shading (phong, adaptive), NaN on background
    normal_length: np.ndarray | None = None
    #: seconds spent compiling (numba, the first render of a kind in this process),
    #: before the clock of ``seconds`` started
    compile_seconds: float = 0.0

    @property
    def image8(self) -> np.ndarray:
        return to_8bit(self.image)

    def _summary(self) -> list[tuple[str, object]]:
        return [("mesh", self.mesh), ("shading", self.shading), ("method", self.method),
                ("size", tuple(self.image.shape[::-1])), ("triangles", self.triangles),
                ("seconds", self.seconds)]

    def __repr__(self) -> str:
        from chebnorm.core.display import summary_repr

        return summary_repr(self)

    @property
    def pixels(self) -> int:
        return int(self.mask.sum())

    def _repr_html_(self) -> str:
        """Jupyter: the image beside its length-error map and numbers
        (:func:`chebnorm.raster.display.render_html`)."""
        from .display import render_html

        return render_html(self)


def _validate_size(size):
    try:
        w, h = (int(s) for s in size)
    except (TypeError, ValueError):
        raise ValueError(f"size must be two integers (width, height); got {size!r}") from None
    if list(size) != [w, h] or not (1 <= w <= 16384 and 1 <= h <= 16384):
        raise ValueError(f"size must be two integers in [1, 16384]; got {tuple(size)!r}")
    return w, h


# ------------------------------------------------------------------ render
def render(mesh="teapot", shading: str = "phong", method: str | None = "exact", *,
           size=(512, 512), tess: int | None = None, lighting: Lighting | None = None,
           camera: Camera | None = None, tables=None, dtype=np.float64,
           eta_threshold: float = 0.005, q: float = 1.0 / 255.0, bump: str = "full",
           height_map: HeightMap | None = None, k: float | None = None, cull: bool = True,
           span_normals=None, engine: str | None = "auto",
           extra_maps: bool = True) -> RenderResult:
    """Render ``mesh`` (a :class:`Mesh`, a name or a file path) with one
    shading mode.

    ``method``: the normalization method of ``phong`` (and of the normalized
    triangles of ``adaptive``), any registered method (:func:`available_methods`),
    checked here once; ignored by ``gouraud`` and ``split-gouraud``;
    for ``bump`` it normalizes the interpolated tangent-space ``L`` and ``H``.
    ``tables``, ``dtype``: passed to the span interpolator.
    ``eta_threshold``: ``adaptive`` skips normalization on triangles with
    ``eta < eta_threshold`` (seed 003).  ``q``: ``split-gouraud``'s threshold
    on ``I0 k_s (max H.N)^n`` at an edge maximum (seed 002).  ``bump``:
    ``full`` (tangent-space coefficients from ``P_u, P_v``), ``square``
    (``[-F_u/k, -F_v/k, 1]``, ``k`` default the median of ``sqrt|P_u x P_v|``
    over the vertices) or ``object`` (Blinn's perturbed normal in object space,
    L and H in object space).  ``span_normals``: a replacement span
    interpolator (same signature as :func:`chebnorm.methods.span_normals`).
    ``engine``: ``"numpy"`` (the reference, :mod:`chebnorm.raster.engines.numpy`),
    ``"numba"`` (compiled, and for ``phong`` the fused, threaded frame:
    :mod:`chebnorm.raster.engines.numba`; the same image bytes) or ``"auto"`` (numba
    when installed).  ``extra_maps``: ``phong`` and ``adaptive`` also return the
    triangle and ``|N|`` maps (False: only the image and its mask, as a GPU frame
    gives them; ``triangle`` and ``normal_length`` are None and the compiled frame
    neither computes nor writes them: 16 of its 25 bytes per pixel).

    Parameters
    ----------
    mesh : Mesh or str or os.PathLike, optional
        The mesh: a Mesh, a generator's name or a mesh file.
    shading : str, optional
        One of :data:`SHADING_MODES`.
    method : str or None, optional
        The normalization method (see above).
    size : tuple of (int, int), optional
        ``(width, height)`` in pixels.
    tess : int, optional
        Tessellation of a generated mesh.
    lighting : Lighting, optional
        Blinn-Phong parameters.
    camera : Camera, optional
        The view (default: fitted to the mesh).
    tables : dict, optional
        Coefficient tables by method name.
    dtype : numpy dtype, optional
        float32 or float64, the arithmetic of the span interpolator.
    eta_threshold : float, optional
        ``adaptive``'s threshold on ``eta``.
    q : float, optional
        ``split-gouraud``'s threshold.
    bump : str, optional
        The bump variant.
    height_map : HeightMap, optional
        The height map of ``bump``.
    k : float, optional
        The common length of ``P_u``, ``P_v`` for ``bump="square"`` (default: the median of ``sqrt|P_u x P_v|`` over the vertices).
    cull : bool, optional
        Drop back-facing triangles.
    span_normals : callable, optional
        A replacement span interpolator.
    engine : str, optional
        ``"numpy"``, ``"numba"`` or ``"auto"``.
    extra_maps : bool, optional
        Also the triangle and ``|N|`` maps (``phong``, ``adaptive``).

    Returns
    -------
    RenderResult
        The frame, its mask, counts, timing and the mode's statistics.

    Raises
    ------
    ValueError
        For an unknown mesh, mode, method, engine or option, a size out of range,
        or tables that do not cover the spans.

    See Also
    --------
    compare : the error of one frame against another.
    chebnorm.span_normals : the span interpolator of ``method``.
    chebnorm.raster.RenderComparison : two frames side by side with their error map.

    Notes
    -----
    Every covered pixel's intensity is Blinn-Phong's [2]_ [3]_, clipped to
    :math:`[0, 1]`:

    .. math::

        I = I_0 \\left(k_a + k_d \\max(0, N \\cdot L)
            + k_s \\max(0, N \\cdot H)^n\\right),

    with :math:`L` toward the light, :math:`H` the half vector and
    :math:`n` the shininess (:class:`Lighting`). ``phong`` interpolates the
    vertex normals linearly along each scan-line span,
    :math:`N(t) = (1 - t) N_l + t N_r`, and normalizes them with ``method``
    (the papers' methods [1]_, :mod:`chebnorm.methods`); ``gouraud``
    interpolates the vertex intensities instead [4]_; ``adaptive`` skips the
    normalization where the criterion :math:`\\eta` of seed 003 is below
    ``eta_threshold``; ``split-gouraud`` is seed 002's highlight test and
    ``bump`` seed 001's bump mapping [5]_.

    References
    ----------
    .. [1] The four papers chebnorm reproduces (seeds 000 to 003), restated
       with their formulas re-derived in :doc:`/papers`.
    .. [2] B. T. Phong, "Illumination for computer generated pictures",
       Communications of the ACM 18(6), 1975.
    .. [3] J. F. Blinn, "Models of light reflection for computer synthesized
       pictures", Computer Graphics (SIGGRAPH '77) 11(2), 1977.
    .. [4] H. Gouraud, "Continuous shading of curved surfaces", IEEE
       Transactions on Computers C-20(6), 1971.
    .. [5] J. F. Blinn, "Simulation of wrinkled surfaces", Computer Graphics
       (SIGGRAPH '78) 12(3), 1978.

    Examples
    --------
    >>> r = render("sphere", "phong", "exact", size=(32, 32), tess=8)
    >>> r.image.shape, r.pixels > 300
    ((32, 32), True)
    """
    t_start = time.perf_counter()
    compile_seconds = 0.0
    if shading not in SHADING_MODES:
        raise ValueError(f"unknown shading mode {shading!r}; accepted: {', '.join(SHADING_MODES)}")
    w, h = _validate_size(size)
    eng = get_engine(engine)
    lighting = lighting or Lighting()
    lighting.validate()
    spec = None
    if shading in ("phong", "adaptive", "bump"):
        method = method or "exact"
        if span_normals is None or method in method_names():
            spec = get_method(method)  # the one check of the method name
    else:
        method = None
    check_options(shading, bump, eta_threshold, q)
    if not isinstance(extra_maps, (bool, np.bool_)):
        raise ValueError(f"extra_maps must be True or False; got {extra_maps!r}")
    mesh = get_mesh(mesh, tess)
    if span_normals is None:   # a compiling engine compiles on a small frame, before the clock
        compile_seconds = eng.warm_up(
            (shading, method, np.dtype(dtype).name, bump, tables is None),
            lambda: _warm_up(shading, method, engine=eng.name, dtype=dtype, tables=tables,
                             bump=bump, eta_threshold=eta_threshold, q=q, k=k),
            f"the raster engine for {shading}" + (f":{method}" if method else ""))
        t_start += compile_seconds
    if shading == "bump" and not mesh.has_parametrization:
        raise ValueError(f"bump mapping needs a parametrized mesh (uv, P_u, P_v); mesh {mesh.name!r} "
                         "has none; use teapot, sphere, torus or square")
    st = eng.setup(mesh, camera, (w, h), cull)
    st.L = lighting.direction(st.camera)
    if span_normals is None:   # the registry's interpolator, by the engine
        interp = lambda _name, *args, **kw: eng.span_normals(spec, *args, **kw)  # noqa: E731
    else:                      # the caller's gets the method's name
        interp = span_normals
    kw = dict(lighting=lighting, interp=interp, tables=tables, dtype=dtype)
    if shading == "gouraud":
        out = shading_modes.gouraud(eng, st, lighting)
    elif shading == "phong":
        out = shading_modes.phong(eng, st, method, spec, builtin=span_normals is None,
                                  extra_maps=bool(extra_maps), **kw)
    elif shading == "adaptive":
        out = shading_modes.phong(eng, st, method, spec, skip_eta=eta_threshold,
                                  extra_maps=bool(extra_maps), **kw)
    elif shading == "split-gouraud":
        out = shading_modes.split_gouraud(eng, st, lighting, q)
    else:
        out = shading_modes.bump(eng, st, method, spec, bump, height_map or HeightMap(), k,
                                 **kw)
    return RenderResult(out.image, out.mask, mesh.name, shading, method,
                        time.perf_counter() - t_start, int(len(mesh.faces)), int(out.fragments),
                        out.stats, out.triangle, out.normal_length, compile_seconds)


def _warm_up(shading, method, **kw) -> None:
    """Render a small sphere in the mode (compiling the kernels it calls)."""
    render("sphere", shading, method, size=(16, 16), tess=4, **kw)


def check_options(shading, bump, eta_threshold, q):
    """Check ``render``'s mode options: the ``bump`` variant (for ``shading == "bump"``)
    and ``eta_threshold`` and ``q`` (finite numbers >= 0).

    Raises
    ------
    ValueError
        Naming the option and the accepted values.

    Parameters
    ----------
    shading : str
        The shading mode.
    bump : str
        The bump variant: ``full``, ``square`` or ``object``.
    eta_threshold : float
        ``adaptive``'s threshold.
    q : float
        ``split-gouraud``'s threshold.

    Examples
    --------
    >>> check_options("phong", "full", 0.005, 1 / 255)
    """
    if shading == "bump" and bump not in BUMP_VARIANTS:
        raise ValueError(f"unknown bump variant {bump!r}; accepted: {', '.join(BUMP_VARIANTS)}")
    for name, value in (("eta_threshold", eta_threshold), ("q", q)):
        if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)) \
                or not ((isinstance(value, (int, np.integer)) or np.isfinite(value))
                        and value >= 0):
            raise ValueError(f"{name} must be a finite number >= 0; got {value!r}")
