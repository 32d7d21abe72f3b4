"""Seed 003: the normalization criterion eta (skipping normalization on small triangles).

One function per figure; each writes ``<stem>.png``, ``.svg``, ``.txt`` (the
caption) and ``.csv`` (the data) under ``figures/criterion/`` and returns the
paths.  The numbers the claims ledger needs come from the ``measure_*``
functions (cached, so a full ``chebnorm repro`` computes each once).

=====================  ===================================================
function               reproduces
=====================  ===================================================
``fig1_chord_arc``     Fig. 1: the chord (linear interpolation) against the arc
``fig2_delta_d``       Fig. 2: ``delta_d(phi) = 1 - cos(phi/2)`` (claim C1)
``fig3_linear_fit``    Fig. 3: errors of the linear Chebyshev fit of ``g`` (C3)
``fig4_quadratic_fit`` Fig. 4: the same, quadratic (C3)
``fig5_delta_s``       Fig. 5: ``delta_s(phi, n) = 1 - cos(phi/2)^n`` (C2)
``eta_tightness``      beyond the paper: eta against the true interior error
=====================  ===================================================
"""

from __future__ import annotations

import math
from functools import lru_cache
from pathlib import Path

import numpy as np
from matplotlib.ticker import FixedLocator, FormatStrFormatter, NullLocator

import mpmath
import sympy as sp

from chebnorm.approx import certify, fit_target, parse_function
from chebnorm.methods import detmath
from chebnorm.symbolic import delta_d, delta_s, eta, midpoint_normal, norm2_linear_np

from .paths import paper_dir
from .style import figure, save_figure, write_csv, write_json

__all__ = ["JOB", "run", "fig1_chord_arc", "fig2_delta_d", "fig3_linear_fit",
           "fig4_quadratic_fit", "fig5_delta_s", "eta_tightness", "measure_c1",
           "phi_at_delta_s", "measure_eta_fits", "measure_eta_tightness",
           "interior_min_norm", "interior_min_norm_grid", "measure_eta_readings",
           "eta_readings_table", "truncated_chebyshev_series", "READINGS"]

JOB = "seed003_criterion"
CMD = f"chebnorm repro {JOB}"
SEED = "003"
#: C1's angle and bound
C1_PHI, C1_BOUND = 0.2, 0.005
#: C2's level of the specular error and exponents
C2_LEVEL = 0.01
C2_EXPONENTS = tuple(range(1, 129))
#: eta tightness: half-angles (degrees) of the cones the vertex normals are drawn from
ETA_CAPS_DEG = (2.5, 5.0, 10.0, 20.0, 40.0)
ETA_PER_CAP = 400
ETA_RNG_SEED = 3


def _dir(out) -> Path:
    return paper_dir(out, SEED)


# --------------------------------------------------------------- measures
def measure_c1() -> dict:
    """``delta_d`` at C1's angle."""
    value = float(delta_d(C1_PHI))
    return {"phi_rad": C1_PHI, "phi_deg": math.degrees(C1_PHI), "delta_d": value,
            "bound": C1_BOUND, "holds": value <= C1_BOUND}


def phi_at_delta_s(n, level: float = C2_LEVEL):
    """The angle (radians) at which ``delta_s(phi, n) = level``:
    ``phi = 2 arccos((1 - level)^(1/n))`` (inverse of seed 003's formula)."""
    n = np.asarray(n, dtype=float)
    base = np.array([math.pow(1.0 - level, 1.0 / v) for v in n.ravel().tolist()]).reshape(n.shape)
    return 2.0 * detmath.arccos(base)


@lru_cache(maxsize=None)
def measure_eta_fits() -> dict:
    """The degree-1 and degree-2 Chebyshev fits of ``g(x) = sqrt(2(1+x))/2`` on
    [0, 1] (target ``eta_term``), as dicts of coefficients and certified errors."""
    out = {}
    for degree in (1, 2):
        t = fit_target("eta_term", degree)
        out[degree] = {
            "name": t.name, "kind": t.kind, "interval": list(t.interval),
            "coefficients": list(t.coefficients),
            "max_abs_error": t.max_abs_error, "max_abs_at": t.max_abs_at,
            "abs_error_bound": t.abs_error_bound,
            "max_rel_error": t.max_rel_error, "max_rel_at": t.max_rel_at,
            "rel_error_bound": t.rel_error_bound,
            "command": f"chebnorm fit \"sqrt(2*(1+x))/2\" --var x --interval 0 1 --degree {degree}",
        }
    return out


ETA_EXPR = "sqrt(2*(1+x))/2"
#: the three readings of seed 003's "expand each term of (1) in a Chebyshev polynomial"
READINGS = ("series", "interpolation", "minimax")


def truncated_chebyshev_series(degree: int, dps: int = 40) -> list[float]:
    """The degree-``degree`` truncation of the Chebyshev series of ``g(x) = sqrt(2(1+x))/2`` on
    [0, 1] (``x = (t + 1)/2``), ``sum_k c_k T_k(t)`` with
    ``c_k = (2/pi) int_0^pi g((cos u + 1)/2) cos(k u) du`` (``c_0`` halved), as coefficients
    in ascending powers of ``x`` (mpmath quadrature at ``dps`` digits).

    >>> [round(c, 6) for c in truncated_chebyshev_series(1)]
    [0.713941, 0.291811]
    """
    with mpmath.workdps(dps):
        g = lambda u: mpmath.sqrt(2 * (1 + (mpmath.cos(u) + 1) / 2)) / 2  # noqa: E731
        ck = [2 / mpmath.pi * mpmath.quad(lambda u, k=k: g(u) * mpmath.cos(k * u), [0, mpmath.pi])
              for k in range(degree + 1)]
        ck[0] /= 2
        # T_k(t) in powers of t, then t = 2x - 1
        t_pows = [[mpmath.mpf(0)] * (degree + 1) for _ in range(degree + 1)]
        t_pows[0][0] = mpmath.mpf(1)
        if degree >= 1:
            t_pows[1][1] = mpmath.mpf(1)
        for k in range(2, degree + 1):
            for j in range(degree + 1):
                t_pows[k][j] = (2 * t_pows[k - 1][j - 1] if j else 0) - t_pows[k - 2][j]
        in_t = [sum(ck[k] * t_pows[k][j] for k in range(degree + 1)) for j in range(degree + 1)]
        in_x = [mpmath.mpf(0)] * (degree + 1)
        for j, a in enumerate(in_t):          # a (2x - 1)^j
            for i in range(j + 1):
                in_x[i] += a * mpmath.binomial(j, i) * mpmath.mpf(2) ** i * (-1) ** (j - i)
        return [float(c) for c in in_x]


def _error_shape(coeffs) -> dict:
    """Where p - g has its extrema and zeros on [0, 1] (a dense grid): what a plotted error
    curve of the reading looks like."""
    x = np.linspace(0.0, 1.0, 20001)
    e = np.polynomial.polynomial.polyval(x, coeffs) - np.sqrt(2.0 * (1.0 + x)) / 2.0
    pos = e > 0
    zeros = x[:-1][pos[:-1] != pos[1:]]
    return {"error_at_0": float(e[0]), "error_at_1": float(e[-1]),
            "zeros": [float(z) for z in zeros],
            "endpoint_over_max": max(abs(e[0]), abs(e[-1])) / float(np.abs(e).max())}


@lru_cache(maxsize=None)
def measure_eta_readings() -> dict:
    """Claim C3: for degrees 1 and 2, the three readings of "a Chebyshev polynomial" of
    ``g(x) = sqrt(2(1+x))/2`` on [0, 1] - the truncated Chebyshev series, interpolation at the
    Chebyshev nodes (chebnorm's ``eta_term`` target) and the minimax (Remez) fit - with their
    coefficients, certified abs and rel errors and the shape of their error curves."""
    fn = parse_function(ETA_EXPR, "x")
    out = {}
    for degree in (1, 2):
        for reading in READINGS:
            if reading == "series":
                c = truncated_chebyshev_series(degree)
            else:
                t = fit_target("eta_term", degree, kind="chebyshev" if reading == "interpolation"
                               else "minimax")
                c = [float(v) for v in t.coefficients]
            ca = certify(fn, c, sp.Integer(0), sp.Integer(1), "abs")
            cr = certify(fn, c, sp.Integer(0), sp.Integer(1), "rel")
            out[f"d{degree}_{reading}"] = {"degree": degree, "reading": reading, "coefficients": c,
                                           "max_abs_error": ca.maximum, "abs_error_bound": ca.bound,
                                           "max_rel_error": cr.maximum, "rel_error_bound": cr.bound,
                                           **_error_shape(c)}
    return out


def eta_readings_table(out) -> list[Path]:
    """The three readings of claim C3 side by side (one CSV)."""
    folder = _dir(out)
    r = measure_eta_readings()
    caption = ("Seed 003, Figs. 3-4 (claim C3): three readings of 'a Chebyshev polynomial' of "
               "g(x) = sqrt(2(1+x))/2 on [0, 1] - the truncated Chebyshev series, interpolation at "
               "the Chebyshev nodes (the eta_term table) and the minimax fit - with certified errors "
               "and where each error curve crosses zero.")
    rows = []
    for key in sorted(r, key=lambda k: (r[k]["degree"], READINGS.index(r[k]["reading"]))):
        e = r[key]
        c = list(e["coefficients"]) + [float("nan")] * (3 - len(e["coefficients"]))
        rows.append((e["degree"], e["reading"], *c, e["max_abs_error"], e["abs_error_bound"],
                     e["max_rel_error"], e["rel_error_bound"], e["error_at_0"], e["error_at_1"],
                     " ".join(f"{z:.4f}" for z in e["zeros"])))
    return [write_csv(folder, "eta_readings",
                      ("degree", "reading", "c0", "c1", "c2", "max_abs_error", "abs_error_bound",
                       "max_rel_error", "rel_error_bound", "error_at_0", "error_at_1", "zeros"),
                      rows, caption, CMD, ["coefficients in ascending powers of x; nan = absent; "
                                           "error = p - g"])]


def _table(degree: int):
    return fit_target("eta_term", degree)


# ------------------------------------------- the true interior error of a triangle
def interior_min_norm(na, nb, nc) -> np.ndarray:
    """``min |w_a N_A + w_b N_B + w_c N_C|`` over the barycentric simplex, exactly.

    ``|N(w)|^2 = w^T G w`` with ``G`` the Gram matrix of the unit normals is
    convex, so its minimum over the simplex is the interior stationary point
    ``w = G^-1 1 / (1^T G^-1 1)`` (value ``1 / 1^T G^-1 1``) when all its
    weights are positive, and otherwise the smallest edge minimum, which for
    unit end normals is at the edge midpoint: ``(1 + c_ij)/2``.
    Inputs are ``(..., 3)`` unit vectors (not checked).
    """
    na, nb, nc = (np.asarray(v, dtype=float) for v in (na, nb, nc))

    def dot(x, y):  # summed x, y, z in this order (not BLAS: its order differs by CPU)
        return x[..., 0] * y[..., 0] + x[..., 1] * y[..., 1] + x[..., 2] * y[..., 2]

    # 1 - |N|^2 for each edge midpoint, and inside: N(w) = N_C + w_a D_a + w_b D_b with
    # D_i = N_i - N_C (short vectors, so the 2x2 system below is well scaled), whose
    # stationary point solves [[D_a.D_a, D_a.D_b], [D_a.D_b, D_b.D_b]] w = -(D.N_C); there
    # 1 - |N|^2 = (1 - |N_C|^2) - (D.N_C).w
    edge_deficit = np.maximum.reduce([(1 - dot(na, nb)) / 2, (1 - dot(nb, nc)) / 2,
                                      (1 - dot(na, nc)) / 2])
    da, db = na - nc, nb - nc
    aa, ab, bb = dot(da, da), dot(da, db), dot(db, db)
    ba, bb_ = dot(da, nc), dot(db, nc)
    det = aa * bb - ab * ab
    ok = det > 1e-12 * aa * bb     # the two edges from N_C not parallel
    safe = np.where(ok, det, 1.0)
    wa = (-ba * bb + bb_ * ab) / safe
    wb = (-bb_ * aa + ba * ab) / safe
    interior = ok & (wa > 0) & (wb > 0) & (wa + wb < 1)
    deficit = np.where(interior, (1 - dot(nc, nc)) - (ba * wa + bb_ * wb), edge_deficit)
    m2 = 1.0 - np.maximum(deficit, edge_deficit)
    edge = 1.0 - edge_deficit
    return np.sqrt(np.minimum(m2, edge))


def interior_min_norm_grid(na, nb, nc, steps: int = 48, refine: int = 2) -> np.ndarray:
    """The same minimum found numerically (the independent check): a barycentric
    grid of step ``1/steps``, then ``refine`` rounds of a finer local grid
    around the best point (shrinking by 8 each round)."""
    V = np.stack([np.asarray(v, dtype=float) for v in (na, nb, nc)], axis=-2)  # (T, 3, 3)
    i, j = np.meshgrid(np.arange(steps + 1), np.arange(steps + 1), indexing="ij")
    keep = i + j <= steps
    base = np.stack([i[keep], j[keep]], axis=-1) / steps               # (K, 2) = (w_a, w_b)
    centre = np.full(V.shape[:-2] + (2,), 1.0 / 3.0)
    half = np.full(V.shape[:-2], 1.0)
    best = np.full(V.shape[:-2], np.inf)
    for round_ in range(refine + 1):
        if round_ == 0:
            pts = np.broadcast_to(base, V.shape[:-2] + base.shape)
        else:
            off = (base - base.mean(axis=0)) * 2.0  # centred, span about [-1, 1]
            pts = centre[..., None, :] + half[..., None, None] * off
            pts = np.clip(pts, 0.0, 1.0)
            over = pts.sum(axis=-1) > 1.0
            pts = np.where(over[..., None], pts / pts.sum(axis=-1, keepdims=True), pts)
        w = np.concatenate([pts, 1.0 - pts.sum(axis=-1, keepdims=True)], axis=-1)
        # N = w V summed over the three normals in order (not BLAS, whose order differs by CPU)
        N = (w[..., 0:1] * V[..., None, 0, :] + w[..., 1:2] * V[..., None, 1, :]
             + w[..., 2:3] * V[..., None, 2, :])                       # (T, K, 3)
        norm2 = N[..., 0] * N[..., 0] + N[..., 1] * N[..., 1] + N[..., 2] * N[..., 2]
        k = np.argmin(norm2, axis=-1)
        best = np.minimum(best, np.take_along_axis(norm2, k[..., None], axis=-1)[..., 0])
        centre = np.take_along_axis(pts, k[..., None, None], axis=-2)[..., 0, :]
        half = np.full(V.shape[:-2], (1.0 / steps) * (2.0 / 8.0 ** round_))
    return np.sqrt(best)


def _random_cap(rng, axis, half_angle, count):
    """``count`` unit vectors uniform in the cap of ``half_angle`` around each ``axis``."""
    cos_t = rng.uniform(math.cos(half_angle), 1.0, size=count)
    sin_t = np.sqrt(1.0 - cos_t ** 2)
    az = rng.uniform(0.0, 2.0 * math.pi, size=count)
    helper = np.where(np.abs(axis[:, 0:1]) < 0.9, [[1.0, 0.0, 0.0]], [[0.0, 1.0, 0.0]])
    e1 = np.cross(axis, helper)
    e1 /= np.linalg.norm(e1, axis=-1, keepdims=True)
    e2 = np.cross(axis, e1)
    v = (cos_t[:, None] * axis + (sin_t * detmath.cos(az))[:, None] * e1
         + (sin_t * detmath.sin(az))[:, None] * e2)
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


@lru_cache(maxsize=None)
def measure_eta_tightness() -> dict:
    """eta against the true largest error inside random triangles.

    For each cap half-angle in :data:`ETA_CAPS_DEG`, :data:`ETA_PER_CAP`
    triangles whose three vertex normals are uniform in a cap of that
    half-angle around a uniform random axis (``np.random.default_rng(3)``).
    The true error is ``1 - min |N|`` over the triangle (the relative diffuse
    error of skipping normalization), exact by :func:`interior_min_norm` and
    checked against :func:`interior_min_norm_grid`.
    """
    rng = np.random.default_rng(ETA_RNG_SEED)
    rows = []
    for cap in ETA_CAPS_DEG:
        axis = rng.normal(size=(ETA_PER_CAP, 3))
        axis /= np.linalg.norm(axis, axis=-1, keepdims=True)
        na, nb, nc = (_random_cap(rng, axis, math.radians(cap), ETA_PER_CAP) for _ in range(3))
        e = np.asarray(eta(na, nb, nc), dtype=float)
        exact = interior_min_norm(na, nb, nc)
        grid = interior_min_norm_grid(na, nb, nc)
        cos = [np.clip(np.einsum("ij,ij->i", x, y), -1, 1) for x, y in ((na, nb), (nb, nc), (na, nc))]
        max_edge = np.max([1.0 - np.sqrt((1.0 + c) / 2.0) for c in cos], axis=0)
        max_angle = np.degrees(np.max([detmath.arccos(c) for c in cos], axis=0))
        for k in range(ETA_PER_CAP):
            rows.append((cap, k, float(max_angle[k]), float(e[k]), float(1.0 - exact[k]),
                         float(1.0 - grid[k]), float(max_edge[k])))
    true = np.array([r[4] for r in rows])
    etas = np.array([r[3] for r in rows])
    grid_true = np.array([r[5] for r in rows])
    max_edge = np.array([r[6] for r in rows])
    ratio = etas / true
    per_cap = {}
    for cap in ETA_CAPS_DEG:
        sel = np.array([r[0] == cap for r in rows])
        rr = ratio[sel]
        per_cap[f"{cap:g}"] = {
            "count": int(sel.sum()), "ratio_min": float(rr.min()),
            "ratio_median": float(np.median(rr)), "ratio_max": float(rr.max()),
            "eta_below_true": int(np.sum(etas[sel] < true[sel])),
        }
    return {
        "rows": rows,
        "count": len(rows),
        "caps_deg": list(ETA_CAPS_DEG),
        "rng_seed": ETA_RNG_SEED,
        "eta_below_true": int(np.sum(etas < true)),
        "ratio_min": float(ratio.min()), "ratio_p05": float(np.quantile(ratio, 0.05)),
        "ratio_median": float(np.median(ratio)), "ratio_p95": float(np.quantile(ratio, 0.95)),
        "ratio_max": float(ratio.max()),
        "interior_exceeds_max_edge": int(np.sum(true > max_edge * (1 + 1e-9))),
        "interior_over_max_edge_max": float(np.max(true / max_edge)),
        "grid_minus_exact_max": float(np.max(np.abs(grid_true - true))),
        "grid_below_exact": int(np.sum(grid_true > true + 1e-12)),
        "per_cap": per_cap,
    }


# ---------------------------------------------------------------- figures
def fig1_chord_arc(out) -> list[Path]:
    """Seed 003, Fig. 1: unit normals on the arc against the chord of linear interpolation."""
    folder = _dir(out)
    phi = math.radians(60.0)
    na = np.array([math.sin(-phi / 2), math.cos(-phi / 2), 0.0])
    nb = np.array([math.sin(phi / 2), math.cos(phi / 2), 0.0])
    t = np.linspace(0.0, 1.0, 41)
    chord = (1 - t)[:, None] * na + t[:, None] * nb
    length = np.sqrt(norm2_linear_np(t, float(na @ nb)))
    arc = chord / length[:, None]
    mid = midpoint_normal(na, nb)
    caption = ("Seed 003, Fig. 1 reproduced: the largest normalization difference. Two unit "
               f"normals N_A, N_B {math.degrees(phi):.0f} deg apart; linear interpolation N(t) runs "
               "along the chord, whose length |N(t)|^2 = 1 - 2t(1-t)(1-cos phi) is smallest at "
               "t = 1/2, where |N(1/2)| = cos(phi/2) and the chord is farthest from the arc.")
    rows = [(float(a), *map(float, c[:2]), float(n), *map(float, r[:2]))
            for a, c, n, r in zip(t, chord, length, arc)]
    paths = [write_csv(folder, "fig1_chord_arc", ("t", "chord_x", "chord_y", "chord_length",
                                                  "arc_x", "arc_y"), rows, caption, CMD,
                       [f"phi = {phi!r} rad; lengths in units of a unit normal"])]
    with figure(figsize=(5.0, 4.2)) as (fig, ax):
        s = np.linspace(-phi / 2 - 0.25, phi / 2 + 0.25, 200)
        ax.plot(np.sin(s), np.cos(s), color="0.75", lw=1, label="unit circle")
        ax.plot(arc[:, 0], arc[:, 1], label="arc: normalized N(t)/|N(t)|")
        ax.plot(chord[:, 0], chord[:, 1], label="chord: linear N(t)")
        for v, name in ((na, "N_A"), (nb, "N_B")):
            ax.annotate("", xy=v[:2], xytext=(0, 0), arrowprops=dict(arrowstyle="->", lw=1.2))
            ax.text(v[0] * 1.05, v[1] * 1.05, name, ha="center")
        m = 0.5 * (na + nb)
        ax.annotate("", xy=m[:2], xytext=(0, 0), arrowprops=dict(arrowstyle="->", color="C1"))
        ax.annotate("", xy=mid[:2], xytext=m[:2], arrowprops=dict(arrowstyle="<->", color="C2"))
        ax.text(0.03, m[1] - 0.1, f"gap 1 - cos(phi/2) = {1 - math.cos(phi / 2):.3f}",
                color="C2", va="center")
        ax.set_aspect("equal")
        ax.set_xlim(-0.75, 0.75)
        ax.set_ylim(-0.05, 1.15)
        ax.set_xlabel("x (units of a unit normal)")
        ax.set_ylabel("y (units of a unit normal)")
        ax.set_title("Seed 003 Fig. 1: chord vs arc (phi = 60 deg)")
        ax.legend(loc="lower left")
        paths += save_figure(fig, folder, "fig1_chord_arc", caption)
    return paths


def fig2_delta_d(out) -> list[Path]:
    """Seed 003, Fig. 2: the largest relative diffuse error against the angle (C1)."""
    folder = _dir(out)
    phi = np.linspace(0.0, math.pi / 2, 181)
    d = np.asarray(delta_d(phi))
    c1 = measure_c1()
    caption = ("Seed 003, Fig. 2 reproduced: largest relative error of the diffuse intensity "
               "without normalization, delta_d(phi) = 1 - cos(phi/2), against the angle phi between "
               f"N_A and N_B. Claim C1: at phi = 0.2 rad (11.46 deg) it is {100 * c1['delta_d']:.4f} %, "
               "under 0.5 %.")
    paths = [write_csv(folder, "fig2_delta_d", ("phi_rad", "phi_deg", "delta_d"),
                       [(float(p), math.degrees(p), float(v)) for p, v in zip(phi, d)], caption, CMD)]
    with figure() as (fig, ax):
        ax.plot(phi, 100 * d, label="delta_d = 1 - cos(phi/2)")
        ax.axhline(100 * C1_BOUND, color="0.5", ls="--", lw=1, label="0.5 % (claim C1)")
        ax.axvline(C1_PHI, color="0.5", ls=":", lw=1)
        ax.plot([C1_PHI], [100 * c1["delta_d"]], "o", color="C1",
                label=f"phi = 0.2 rad: {100 * c1['delta_d']:.4f} %")
        ax.set_xlabel("angle phi between N_A and N_B (rad)")
        ax.set_ylabel("largest relative diffuse error delta_d (%)")
        sec = ax.secondary_xaxis("top", functions=(np.degrees, np.radians))
        sec.set_xlabel("phi (deg)")
        ax.set_xlim(0, math.pi / 2)
        ax.set_ylim(0, None)
        ax.set_title("Seed 003 Fig. 2: relative diffuse error without normalization")
        ax.legend()
        paths += save_figure(fig, folder, "fig2_delta_d", caption)
    return paths


def _fig_fit(out, degree: int, figno: int) -> list[Path]:
    folder = _dir(out)
    table = _table(degree)
    x = np.linspace(0.0, 1.0, 501)
    g = np.sqrt(2.0 * (1.0 + x)) / 2.0
    p = table(x)
    err = p - g
    rel = err / g
    word = {1: "linear", 2: "quadratic"}[degree]
    coef = ", ".join(f"{c:.6f}" for c in table.coefficients)
    caption = (f"Seed 003, Fig. {figno} reproduced: absolute error p(x) - g(x) and relative error "
               f"(p - g)/g of the {word} Chebyshev approximation p of one term of eta, "
               f"g(x) = sqrt(2(1+x))/2, on x = N_i.N_j in [0, 1]. Coefficients (ascending powers): "
               f"{coef}; max |p - g| = {table.max_abs_error:.4g} (certified bound "
               f"{table.abs_error_bound:.4g}), max |p/g - 1| = {table.max_rel_error:.4g} "
               f"(bound {table.rel_error_bound:.4g}).")
    stem = f"fig{figno}_{word}_fit"
    paths = [write_csv(folder, stem, ("x", "g", "p", "abs_error", "rel_error"),
                       [tuple(map(float, r)) for r in zip(x, g, p, err, rel)], caption, CMD,
                       [f"table: fit_target('eta_term', {degree}); coefficients {list(table.coefficients)!r}",
                        f"abs_error_bound {table.abs_error_bound!r}; rel_error_bound {table.rel_error_bound!r}"])]
    with figure(1, 2, figsize=(8.0, 3.4)) as (fig, (a1, a2)):
        for ax, y, bound, label in ((a1, err, table.abs_error_bound, "absolute error p - g"),
                                    (a2, 100 * rel, 100 * table.rel_error_bound,
                                     "relative error (p - g)/g (%)")):
            ax.plot(x, y)
            ax.axhline(bound, color="0.5", ls="--", lw=1, label="certified bound")
            ax.axhline(-bound, color="0.5", ls="--", lw=1)
            ax.set_xlabel("x = N_i . N_j (cosine of the edge angle)")
            ax.set_ylabel(label)
            ax.legend(loc="lower center")
        a1.set_title(f"max |p - g| = {table.max_abs_error:.3g}")
        a2.set_title(f"max |p/g - 1| = {100 * table.max_rel_error:.3g} %")
        fig.suptitle(f"Seed 003 Fig. {figno}: errors of the {word} Chebyshev fit of sqrt(2(1+x))/2")
        paths += save_figure(fig, folder, stem, caption)
    return paths


def fig3_linear_fit(out) -> list[Path]:
    """Seed 003, Fig. 3: errors of the linear fit of an eta term (C3)."""
    return _fig_fit(out, 1, 3)


def fig4_quadratic_fit(out) -> list[Path]:
    """Seed 003, Fig. 4: errors of the quadratic fit of an eta term (C3)."""
    return _fig_fit(out, 2, 4)


def eta_fit_table(out) -> list[Path]:
    """Both fits' coefficients and certified errors (claim C3) as one CSV."""
    folder = _dir(out)
    fits = measure_eta_fits()
    caption = ("Seed 003, Figs. 3-4 (claim C3): Chebyshev fits of g(x) = sqrt(2(1+x))/2 on [0, 1]; "
               "eta ~ 3 - [p(N_A.N_B) + p(N_B.N_C) + p(N_A.N_C)].")
    rows = []
    for degree, f in sorted(fits.items()):
        c = list(f["coefficients"]) + [float("nan")] * (3 - len(f["coefficients"]))
        rows.append((degree, *c, f["max_abs_error"], f["abs_error_bound"], f["max_rel_error"],
                     f["rel_error_bound"]))
    return [write_csv(folder, "eta_fit_coefficients",
                      ("degree", "c0", "c1", "c2", "max_abs_error", "abs_error_bound",
                       "max_rel_error", "rel_error_bound"), rows, caption, CMD,
                      ["coefficients in ascending powers of x; nan = absent"])]


def fig5_delta_s(out) -> list[Path]:
    """Seed 003, Fig. 5: the largest relative specular error over ``n`` and ``phi`` (C2)."""
    folder = _dir(out)
    phi = np.linspace(0.0, 0.5, 101)
    ns = (1, 2, 4, 8, 16, 32, 64, 128)
    grid = np.asarray(delta_s(phi[None, :], np.array(ns, dtype=float)[:, None]))
    caption = ("Seed 003, Fig. 5 reproduced: largest relative error of the specular intensity "
               "without normalization, delta_s(phi, n) = 1 - cos(phi/2)^n, against the angle phi "
               "between N_A and N_B for specular exponents n = 1..128; right: the angle at which it "
               "reaches 1 % (claim C2), phi = 2 arccos(0.99^(1/n)).")
    rows = [(n, float(p), float(v)) for n, line in zip(ns, grid) for p, v in zip(phi, line)]
    paths = [write_csv(folder, "fig5_delta_s", ("n", "phi_rad", "delta_s"), rows, caption, CMD)]
    nn = np.array(C2_EXPONENTS)
    p1 = phi_at_delta_s(nn)
    paths.append(write_csv(folder, "fig5_phi_at_1_percent", ("n", "phi_rad", "phi_deg"),
                           [(int(n), float(p), math.degrees(p)) for n, p in zip(nn, p1)],
                           caption, CMD, ["phi at which delta_s(phi, n) = 1 %"]))
    with figure(1, 2, figsize=(9.0, 3.8)) as (fig, (a1, a2)):
        phi_deg = np.degrees(phi)
        for n, line in zip(ns, grid):
            a1.plot(phi_deg, 100 * line, label=f"n = {n}")
        a1.axhline(1.0, color="0.5", ls="--", lw=1, label="1 %")
        a1.set_yscale("log")
        a1.set_ylim(1e-3, 100)
        a1.set_xlim(0, float(phi_deg[-1]))
        a1.set_xlabel("angle phi between N_A and N_B (deg)")
        a1.set_ylabel("largest relative specular error delta_s (%)")
        a1.legend(ncol=3, fontsize=7)
        a2.plot(nn, np.degrees(p1), color="C0", label="phi_1%(n) = 2 arccos(0.99^(1/n))")
        pts = [i for i, n in enumerate(nn) if n in ns]
        a2.plot(nn[pts], np.degrees(p1[pts]), "o", color="#D55E00", ms=4,
                label="computed points (n = 1, 2, 4, ..., 128)")
        for i in pts:
            a2.annotate(f"{math.degrees(p1[i]):.2f}", (nn[i], math.degrees(p1[i])), fontsize=6,
                        textcoords="offset points", xytext=(4, 3))
        a2.set_xscale("log", base=2)
        a2.set_yscale("log")
        a2.xaxis.set_major_locator(FixedLocator([1, 2, 4, 8, 16, 32, 64, 128]))
        a2.xaxis.set_major_formatter(FormatStrFormatter("%g"))
        a2.xaxis.set_minor_locator(NullLocator())
        a2.yaxis.set_major_locator(FixedLocator([1, 1.5, 2, 3, 4, 6, 10, 16]))
        a2.yaxis.set_major_formatter(FormatStrFormatter("%g"))
        a2.yaxis.set_minor_locator(NullLocator())
        a2.set_ylim(1.2, 20)
        a2.set_xlabel("specular exponent n")
        a2.set_ylabel("phi where delta_s = 1 % (deg)")
        a2.legend(fontsize=7)
        fig.suptitle("Seed 003 Fig. 5: without normalization the specular error passes 1 % at "
                     "16 deg for n = 1 but below 3 deg for n >= 32")
        paths += save_figure(fig, folder, "fig5_delta_s", caption)
    return paths


def eta_tightness(out) -> list[Path]:
    """Beyond the paper: eta against the true interior maximum error of random triangles."""
    folder = _dir(out)
    m = measure_eta_tightness()
    caption = ("Beyond seed 003: how tight the normalization criterion eta is. For "
               f"{m['count']} random triangles (vertex normals uniform in cones of half-angle "
               f"{', '.join(f'{c:g}' for c in ETA_CAPS_DEG)} deg, rng seed {ETA_RNG_SEED}), eta "
               "against the true largest relative diffuse error inside the triangle, 1 - min |N| "
               "(exact minimum of the convex |N(w)|^2 over the barycentric simplex, checked on a "
               f"refined grid). eta never falls below it ({m['eta_below_true']} exceptions); it "
               f"overestimates by a factor {m['ratio_min']:.3f} to {m['ratio_max']:.3f} "
               f"(median {m['ratio_median']:.3f}).")
    paths = [write_csv(folder, "eta_tightness",
                       ("cap_deg", "index", "max_edge_angle_deg", "eta", "true_max_error",
                        "grid_max_error", "max_edge_term"), m["rows"], caption, CMD,
                       ["true_max_error = 1 - min|N| over the triangle (exact); grid_max_error = "
                        "the same by refined barycentric grid; max_edge_term = largest single edge "
                        "bound 1 - cos(phi_ij/2)"])]
    summary = {k: v for k, v in m.items() if k != "rows"}
    summary["caption"] = caption
    summary["command"] = CMD
    paths.append(write_json(folder / "eta_tightness_summary.json", summary))
    rows = np.array([r[:7] for r in m["rows"]], dtype=float)
    with figure(1, 2, figsize=(8.6, 3.8)) as (fig, (a1, a2)):
        for k, cap in enumerate(ETA_CAPS_DEG):
            sel = rows[:, 0] == cap
            a1.scatter(rows[sel, 4], rows[sel, 3], s=4, color=f"C{k}", label=f"cone {cap:g} deg")
        lo, hi = rows[:, 4].min() * 0.8, rows[:, 3].max() * 1.2
        a1.plot([lo, hi], [lo, hi], color="0.3", lw=1, label="eta = true")
        a1.set_xscale("log")
        a1.set_yscale("log")
        a1.set_xlabel("true largest error inside the triangle, 1 - min|N|")
        a1.set_ylabel("criterion eta")
        a1.legend(fontsize=7, markerscale=2)
        ratio = rows[:, 3] / rows[:, 4]
        a2.hist(ratio, bins=60, color="C0")
        a2.set_xlabel("eta / true largest error")
        a2.set_ylabel("number of triangles")
        a2.set_title(f"min {ratio.min():.3f}, median {np.median(ratio):.3f}, max {ratio.max():.3f}")
        fig.suptitle("Beyond seed 003: eta against the true interior error")
        paths += save_figure(fig, folder, "eta_tightness", caption)
    return paths


FIGURES = (fig1_chord_arc, fig2_delta_d, fig3_linear_fit, fig4_quadratic_fit, eta_fit_table,
           eta_readings_table,
           fig5_delta_s, eta_tightness)


def run(out) -> list[Path]:
    """The seed 003 job: every figure above."""
    paths = []
    for f in FIGURES:
        paths += f(out)
    return paths
