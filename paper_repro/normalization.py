"""Seed 000: efficient normalization methods for Phong shading, compared.

One function per figure or table, written under ``figures/normalization/``.
Errors are those of :mod:`chebnorm.methods` (pixel normals against the exactly
normalized linear interpolant, float64 reference); operation counts come
from running the same kernels on counting scalars (``count_ops``); speeds
come from ``benchmarks/results.json`` when it exists.  Errors are shown in
8-bit shading levels: ``255 |N - R|`` is the largest error of a diffuse
intensity ``L.N`` (``I0 k_d = 1``) over all unit lights.

==========================  ==============================================
function                    what
==========================  ==============================================
``methods_table``           ops, errors (float64/float32), speed per method
``fig_op_counts``           per-pixel operations per method (C9)
``fig_error_vs_angle``      each method's error against the span angle
``fig_error_vs_length``     ... and against the span length (pixels)
``fig_dichotomy_interval``  C4/C5: the fits' errors against psi_max
``fig_angular_drift``       float32/float64 drift of the angular recurrence
==========================  ==============================================
"""

from __future__ import annotations

import math
from functools import lru_cache
from pathlib import Path

import numpy as np

from chebnorm.approx import fit_target
from chebnorm.methods import (METHODS, analyze, angular_drift, count_ops, error_sweep,
                              normalization_ops)

from .benchmarks import load_results
from .paths import paper_dir
from .style import METHOD_STYLE, figure, save_figure, write_csv, write_json, write_text

__all__ = ["JOB", "run", "methods_table", "fig_op_counts", "fig_error_vs_angle",
           "fig_error_vs_length", "fig_dichotomy_interval", "fig_angular_drift",
           "measure_dichotomy", "measure_op_counts", "measure_method_errors",
           "measure_inaccuracy_thresholds", "measure_drift", "measure_midpoint_cost"]

JOB = "seed000_normalization"
CMD = f"chebnorm repro {JOB}"
SEED = "000"
LEVELS = 255.0            # 8-bit shading levels per unit intensity
HALF_LEVEL = 0.5 / LEVELS
SPAN_PSI = math.pi / 4    # the angle the papers' tables are fitted for
SPAN_M = 64
SPEC_N = 32               # the specular exponent shown
OPS = ("add", "mul", "div", "sqrt", "trig", "cmp")
C4_ABS, C4_REL = 5e-4, 0.0012
C5_ABS, C5_REL = 2e-5, 0.00004
C5_COEFFS = (0.681, -0.119, 0.014)   # ascending powers of z
#: the angular recurrence's number formats: (label, dtype, re-anchor period, fixed-point bits)
DRIFT_VARIANTS = (("float64", np.float64, None, None), ("float32", np.float32, None, None),
                  ("float32_reanchor64", np.float32, 64, None), ("Q.16", None, None, 16),
                  ("Q.24", None, None, 24), ("Q.30", None, None, 30))


def _dir(out) -> Path:
    return paper_dir(out, SEED)


# ---------------------------------------------------------------- measures
def _dichotomy_fit(degree: int, psi: float | str, kind: str = "chebyshev", error: str = "abs"):
    psi_s = psi if isinstance(psi, str) else f"{psi:.6f}"
    t = fit_target("dichotomy", degree, psi_max=psi_s, kind=kind, error=error)
    return {"psi_max": psi_s, "interval": list(t.interval), "interval_float": list(t.interval_float),
            "kind": kind, "error": error, "coefficients": list(t.coefficients),
            "max_abs_error": t.max_abs_error, "abs_error_bound": t.abs_error_bound,
            "max_rel_error": t.max_rel_error, "rel_error_bound": t.rel_error_bound}


@lru_cache(maxsize=None)
def measure_dichotomy() -> dict:
    """C4, C5 and the interval they need: ``1/sqrt(2+z)`` on ``[2 cos psi_max, 2]``.

    * the fits at psi_max = pi/4 (the interval C5's numbers are those of),
      Chebyshev and minimax (abs and rel);
    * the largest psi_max (bisection to 1e-5 rad, Chebyshev fits, certified
      errors) at which degree 1 meets both ``abs <= 5e-4`` and ``rel <= 0.12 %``;
    * the consistency bound: ``f = 1/sqrt(2+z) >= 1/2`` for ``z <= 2``, so
      ``rel <= 2 abs`` on every dichotomy interval; ``abs <= 5e-4`` then forces
      ``rel <= 0.1 %``, below the paper's 0.12 %.
    """
    at45 = {f"d{d}_{kind}_{err}": _dichotomy_fit(d, "pi/4", kind, err)
            for d in (1, 2) for kind, err in (("chebyshev", "abs"), ("minimax", "abs"),
                                              ("minimax", "rel"))}

    def ok(psi):
        f = _dichotomy_fit(1, psi)
        return f["abs_error_bound"] <= C4_ABS and f["rel_error_bound"] <= C4_REL

    lo, hi = 0.5, math.pi / 4        # ok(lo) holds, ok(pi/4) does not
    assert ok(lo) and not ok(hi)
    while hi - lo > 1e-5:
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if ok(mid) else (lo, mid)
    best = _dichotomy_fit(1, lo)
    sweep = []
    for deg in (1, 2):
        for psi_deg in range(5, 91, 5):
            f = _dichotomy_fit(deg, math.radians(psi_deg))
            sweep.append((deg, psi_deg, f["max_abs_error"], f["abs_error_bound"],
                          f["max_rel_error"], f["rel_error_bound"]))
    return {"at_pi_4": at45, "c4_psi_max_rad": lo, "c4_psi_max_deg": math.degrees(lo),
            "c4_fit_at_psi_max": best, "rel_over_abs_bound": 2.0,
            "rel_max_given_abs_5e-4": 2.0 * C4_ABS, "sweep": sweep}


@lru_cache(maxsize=None)
def measure_op_counts() -> dict:
    """Normalization alone (C9) and whole span methods per pixel/per span (``m = 64``)."""
    norm = {m: {"ops": dict(normalization_ops(m).ops), "pow2": normalization_ops(m).pow2}
            for m in ("exact", "newton", "lyon")}
    spans = {}
    for m in METHODS:
        c = count_ops(m, SPAN_M)
        spans[m] = {"per_pixel": {k: float(v) for k, v in c.per_pixel.items()},
                    "per_span": {k: float(v) for k, v in c.per_span.items()},
                    "pow2_per_pixel": float(c.pow2_per_pixel)}
    return {"normalization": norm, "span_m": SPAN_M, "span": spans}


@lru_cache(maxsize=None)
def measure_method_errors() -> dict:
    """Every method on one span of ``pi/4`` and 64 pixels, float64 and float32."""
    out = {}
    for m in METHODS:
        for dt in (np.float64, np.float32):
            r = analyze(m, SPAN_PSI, SPAN_M, dt)
            out[f"{m}/{np.dtype(dt).name}"] = {
                "length": r.max_length_error, "angle_rad": r.max_angle_error,
                "angle_slerp_rad": r.max_angle_error_slerp, "vector": r.max_vector_error,
                "vector_levels": LEVELS * r.max_vector_error,
                "diffuse": r.diffuse_error, "specular_n32": r.specular_error(SPEC_N),
                "specular_n32_levels": LEVELS * r.specular_error(SPEC_N)}
    return out


def _threshold(method: str, quantity: str, level: float) -> float:
    """Smallest span angle (rad, to 1e-4) at which ``method``'s error passes ``level``."""
    def err(psi):
        r = analyze(method, psi, SPAN_M)
        return r.max_vector_error if quantity == "vector" else r.specular_error(SPEC_N)
    lo, hi = 1e-3, math.pi / 2
    if err(hi) <= level:
        return float("inf")
    while hi - lo > 1e-4:
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if err(mid) > level else (mid, hi)
    return hi


@lru_cache(maxsize=None)
def measure_inaccuracy_thresholds() -> dict:
    """C10: for newton and lyon (and ``none`` for scale), the span angle above
    which the error passes half an 8-bit level, diffuse (``|N - R|``) and
    specular (``n = 32``); and their errors at pi/4 in levels."""
    out = {}
    errs = measure_method_errors()
    for m in ("none", "newton", "lyon"):
        out[m] = {"diffuse_half_level_rad": _threshold(m, "vector", HALF_LEVEL),
                  "specular_n32_half_level_rad": _threshold(m, "specular", HALF_LEVEL),
                  "vector_levels_at_pi_4": errs[f"{m}/float64"]["vector_levels"],
                  "specular_n32_levels_at_pi_4": errs[f"{m}/float64"]["specular_n32_levels"]}
        for k in ("diffuse_half_level_rad", "specular_n32_half_level_rad"):
            out[m][k.replace("_rad", "_deg")] = math.degrees(out[m][k])
    return out


@lru_cache(maxsize=None)
def measure_drift() -> dict:
    """The angular recurrence over 512 pixels at pi/4 in each of :data:`DRIFT_VARIANTS`."""
    out = {}
    for label, dt, re, fb in DRIFT_VARIANTS:
        d = angular_drift(math.pi / 4, 512, dt, reanchor=re, frac_bits=fb)
        out[label] = {"max_length_error": d.max_length_error, "max_angle_error_rad": d.max_angle_error,
                      "final_length_error": d.final_length_error,
                      "final_angle_error_rad": d.final_angle_error,
                      "ops_per_pixel": {k: float(v) for k, v in d.ops.per_pixel.items()},
                      "t": d.t, "length_error": d.length_error, "angle_error": d.angle_error}
    return out


# ------------------------------------------------------------------ figures
#: benchmark kernel of each method (benchmarks/run.py's names)
_BENCH_KERNEL = {"exact": "classic"}
BENCH_CONFIGS = ("O2", "O3-native")


def _speed(method: str, config: str):
    """Median speed-up over classic normalization on the frame's spans
    (``configs.<config>.kernels.mesh.<kernel>.speedup_vs_classic.median`` of
    benchmarks/results.json), or None when not measured."""
    res = load_results()
    try:
        k = _BENCH_KERNEL.get(method, method)
        return float(res["configs"][config]["kernels"]["mesh"][k]["speedup_vs_classic"]["median"])
    except (KeyError, TypeError, ValueError):
        return None


def methods_table(out) -> list[Path]:
    """The comparison table of seed 000: operations, errors, speed per method."""
    folder = _dir(out)
    ops = measure_op_counts()
    errs = measure_method_errors()
    caption = (f"Seed 000, the methods compared: operations per pixel (and per span) on a span of "
               f"{SPAN_M} pixels, counted by running each kernel on counting scalars; errors on one "
               f"span of pi/4 (45 deg) and {SPAN_M} pixels against the exactly normalized linear "
               f"interpolant R, in 8-bit levels (length error 255 | |N| - 1 |; 255 |N - R|: largest "
               f"diffuse error over all lights; specular n = {SPEC_N} with H along the true normal; "
               "angle to the method's own ideal: R, or the slerp point for slerp/dichotomy/angular); "
               "speed-up over classic normalization (float32 C kernels on a rendered teapot "
               "frame's spans, median, gcc -O2 / -O3 -march=native) from benchmarks/results.json "
               "(nan when not measured).")
    cols = (["method"] + [f"pixel_{k}" for k in OPS] + [f"span_{k}" for k in OPS]
            + ["length_levels_f64", "vector_levels_f64", "vector_levels_f32",
               f"specular_n{SPEC_N}_levels_f64", "angle_own_ideal_f64_rad"]
            + [f"speedup_vs_classic_{c}" for c in BENCH_CONFIGS])
    rows = []
    for m in METHODS:
        o = ops["span"][m]
        e64, e32 = errs[f"{m}/float64"], errs[f"{m}/float32"]
        sp = [_speed(m, c) for c in BENCH_CONFIGS]
        rows.append([m] + [o["per_pixel"][k] for k in OPS] + [o["per_span"][k] for k in OPS]
                    + [LEVELS * e64["length"], e64["vector_levels"], e32["vector_levels"],
                       e64["specular_n32_levels"], min(e64["angle_rad"], e64["angle_slerp_rad"])]
                    + [float("nan") if v is None else v for v in sp])
    paths = [write_csv(folder, "methods_table", cols, rows, caption, CMD)]
    md = ["| method | per pixel (add/mul/div/sqrt/trig) | per span | length err (levels) "
          f"| vs Phong f64 (levels) | f32 | spec n={SPEC_N} (levels) | speed-up ({' / '.join(BENCH_CONFIGS)}) |",
          "|---|---|---|---|---|---|---|---|"]
    for r in rows:
        pp = "/".join(f"{r[1 + i]:g}" for i in range(5))
        ps = "/".join(f"{r[7 + i]:g}" for i in range(5))
        sp = " / ".join("n/a" if math.isnan(v) else f"{v:.2f}x" for v in r[-len(BENCH_CONFIGS):])
        md.append(f"| {r[0]} | {pp} | {ps} | {r[13]:.3g} | {r[14]:.3g} | {r[15]:.3g} "
                  f"| {r[16]:.3g} | {sp} |")
    paths.append(write_text(folder / "methods_table.md", f"{caption}\n\n" + "\n".join(md) + "\n"))
    return paths


def fig_op_counts(out) -> list[Path]:
    """Per-pixel operations of each method, stacked by kind (C9)."""
    folder = _dir(out)
    ops = measure_op_counts()
    caption = (f"Seed 000 (claim C9): operations per pixel of each span method (span of {SPAN_M} "
               "pixels), measured by running the kernels on counting scalars, and of the "
               "normalization step alone (classic N/sqrt(N.N), Newton-Raphson, Lyon).")
    rows = [(m, "span_per_pixel", *[ops["span"][m]["per_pixel"][k] for k in OPS]) for m in METHODS]
    rows += [(m, "normalization_only", *[float(ops["normalization"][m]["ops"][k]) for k in OPS])
             for m in ("exact", "newton", "lyon")]
    paths = [write_csv(folder, "op_counts", ("method", "scope", *OPS), rows, caption, CMD,
                       ["mul includes multiplications by powers of two (shifts in hardware)"])]
    with figure(figsize=(7.0, 3.6)) as (fig, ax):
        x = np.arange(len(METHODS))
        bottom = np.zeros(len(METHODS))
        for k in OPS:
            v = np.array([ops["span"][m]["per_pixel"][k] for m in METHODS])
            if v.any():
                ax.bar(x, v, bottom=bottom, label=k)
                bottom += v
        ax.set_xticks(x, METHODS)
        ax.set_xlabel("method")
        ax.set_ylabel(f"operations per pixel (span of {SPAN_M} px)")
        ax.legend()
        ax.set_title("Seed 000: operations per pixel, counted from the kernels")
        paths += save_figure(fig, folder, "op_counts", caption)
    return paths


#: the lowest error drawn by the error figures (8-bit levels); smaller values sit on it, clipped
PLOT_FLOOR = 1e-7
#: the quadratic method with the exact midpoint normal (N_l + N_r)/|N_l + N_r| instead of the
#: midpoint polynomial: what the polynomial costs
QUAD_EXACT = "quadratic_exact_midpoint"


@lru_cache(maxsize=None)
def measure_midpoint_cost(psi: float = 0.1) -> dict:
    """The quadratic method (64 px, float64) with the midpoint polynomial against the exact
    midpoint normal at span angle ``psi`` (rad): length and vector errors and their ratios."""
    poly = analyze("quadratic", psi, SPAN_M)
    exact = analyze("quadratic", psi, SPAN_M, tables={"quadratic": None})
    return {"psi_rad": psi, "span_pixels": SPAN_M,
            "length_error_polynomial": poly.max_length_error,
            "length_error_exact_midpoint": exact.max_length_error,
            "length_ratio": poly.max_length_error / exact.max_length_error,
            "vector_error_polynomial": poly.max_vector_error,
            "vector_error_exact_midpoint": exact.max_vector_error,
            "vector_ratio": poly.max_vector_error / exact.max_vector_error}


def fig_error_vs_angle(out) -> list[Path]:
    """Each method's largest error against the span angle (0..45 deg, 64 pixels), with the
    quadratic method's exact-midpoint variant beside it."""
    folder = _dir(out)
    psis = np.radians(np.linspace(1.0, 45.0, 45))
    methods = tuple(m for m in METHODS if m != "exact")
    s = error_sweep(methods, psis, (SPAN_M,), (np.float64, np.float32))
    sx = error_sweep(("quadratic",), psis, (SPAN_M,), (np.float64, np.float32),
                     tables={"quadratic": None})
    mc = measure_midpoint_cost()

    def get(q, m, dt):
        return sx.get(q, "quadratic", dt, m=SPAN_M) if m == QUAD_EXACT else s.get(q, m, dt, m=SPAN_M)
    shown = methods[:methods.index("quadratic") + 1] + (QUAD_EXACT,) + methods[methods.index("quadratic") + 1:]
    caption = (f"Seed 000: each method's largest error on a span of {SPAN_M} pixels against the "
               "angle between its end normals, in 8-bit levels. Left: 255 |N - R| against Phong's "
               "exactly normalized linear interpolant R (the largest diffuse error over all lights; "
               "the slerp family - slerp, dichotomy, angular - spaces normals evenly in angle and so "
               "differs from R by a parametrization term ~psi^3/40 even when exact). Right: the "
               "length error 255 | |N| - 1 |. float64 solid, float32 dotted; colour and marker "
               "name the method; the table methods use the degree-2 tables fitted for "
               "psi_max = pi/4. The quadratic method's midpoint normal comes from a polynomial "
               "fitted on [cos(max(psi, pi/4)), 1]; quadratic_exact_midpoint uses the exact "
               f"(N_l + N_r)/|N_l + N_r| instead: at psi = {mc['psi_rad']:g} rad the polynomial's "
               f"length error is {mc['length_ratio']:.0f}x the exact midpoint's. Dashed: half a "
               f"level. Values below {PLOT_FLOOR:g} levels are drawn on the shaded floor (clipped).")
    rows = []
    for m in shown:
        for dt in ("float64", "float32"):
            v = get("vector_error", m, dt)
            sp = get("specular_error", m, dt)[:, SPEC_N - 1]
            ln = get("length_error", m, dt)
            rows += [(m, dt, float(p), math.degrees(p), float(a), float(c), float(b))
                     for p, a, c, b in zip(psis, v, ln, sp)]
    paths = [write_csv(folder, "error_vs_angle", ("method", "dtype", "psi_rad", "psi_deg",
                                                  "vector_error", "length_error",
                                                  f"specular_n{SPEC_N}_error"),
                       rows, caption, CMD)]
    from matplotlib.lines import Line2D
    with figure(1, 2, figsize=(10.0, 4.6)) as (fig, (a1, a2)):
        for ax, q in ((a1, "vector_error"), (a2, "length_error")):
            for m in shown:
                color, marker = METHOD_STYLE[m]
                for dt, ls in (("float64", "-"), ("float32", ":")):
                    v = np.maximum(LEVELS * get(q, m, dt), PLOT_FLOOR)
                    ax.plot(np.degrees(psis), v, ls=ls, color=color, marker=marker, ms=4,
                            markevery=(3 if dt == "float64" else 6, 8),
                            mfc=color if dt == "float64" else "none", label=None)
            ax.axhline(0.5, color="0.4", ls="--", lw=1)
            ax.axhspan(PLOT_FLOOR / 3, PLOT_FLOOR, color="0.85", lw=0)
            ax.text(44.5, PLOT_FLOOR * 0.55, f"floor: below {PLOT_FLOOR:g}, clipped", ha="right",
                    va="center", fontsize=7, color="0.3")
            ax.set_yscale("log")
            ax.set_ylim(PLOT_FLOOR / 3, 100)
            ax.set_xlim(0, 46)
            ax.set_xlabel("angle psi between the span's end normals (deg)")
        a1.set_ylabel("255 |N - R|, against Phong (8-bit levels)")
        a2.set_ylabel("255 | |N| - 1 |, length error (8-bit levels)")
        keys = [Line2D([], [], color=METHOD_STYLE[m][0], marker=METHOD_STYLE[m][1], ms=5, label=m)
                for m in shown]
        keys += [Line2D([], [], color="0.2", ls="-", label="float64"),
                 Line2D([], [], color="0.2", ls=":", mfc="none", label="float32"),
                 Line2D([], [], color="0.4", ls="--", lw=1, label="half a level")]
        fig.legend(handles=keys, loc="outside right center", fontsize=7)
        fig.suptitle(f"Seed 000: error against span angle ({SPAN_M} px): which methods stay under "
                     "half an 8-bit level (dashed), in float64 and float32")
        paths += save_figure(fig, folder, "error_vs_angle", caption)
    return paths


def fig_error_vs_length(out) -> list[Path]:
    """Each method's largest error against the span length (pi/4)."""
    folder = _dir(out)
    ms = (2, 4, 8, 16, 32, 64, 128, 256, 512, 1024)
    methods = tuple(m for m in METHODS if m != "exact")
    s = error_sweep(methods, [SPAN_PSI], ms, (np.float64, np.float32))
    caption = ("Seed 000: each method's largest error on a span of pi/4 (45 deg) against the span "
               "length in pixels, in 8-bit levels (255 |N - R|); float64 solid, float32 dotted. "
               "Only the recurrences (angular, quadratic forward differences) depend on the length "
               "through accumulated rounding.")
    rows = []
    for m in methods:
        for dt in ("float64", "float32"):
            v = s.get("vector_error", m, dt)[0]
            rows += [(m, dt, mm, float(e)) for mm, e in zip(ms, v)]
    paths = [write_csv(folder, "error_vs_length", ("method", "dtype", "pixels", "vector_error"),
                       rows, caption, CMD)]
    with figure(figsize=(7.0, 4.4)) as (fig, ax):
        for i, m in enumerate(methods):
            for dt, ls in (("float64", "-o"), ("float32", ":x")):
                v = np.maximum(LEVELS * s.get("vector_error", m, dt)[0], 1e-7)
                ax.plot(ms, v, ls, ms=3, color=f"C{i}", label=m if dt == "float64" else None)
        ax.axhline(0.5, color="0.4", ls="--", lw=1)
        ax.set_xscale("log", base=2)
        ax.set_yscale("log")
        ax.set_ylim(1e-7, 100)
        ax.set_xlabel("span length (pixels)")
        ax.set_ylabel("largest error (8-bit levels)")
        ax.legend(ncol=2)
        ax.set_title("Seed 000: error against span length (psi = 45 deg)")
        paths += save_figure(fig, folder, "error_vs_length", caption)
    return paths


def fig_dichotomy_interval(out) -> list[Path]:
    """C4/C5: errors of the degree-1 and -2 dichotomy fits against psi_max."""
    folder = _dir(out)
    d = measure_dichotomy()
    caption = ("Seed 000, method 4 (claims C4, C5): certified largest absolute and relative errors "
               "of the Chebyshev fits of 1/sqrt(2+z) on z in [2 cos psi_max, 2] against psi_max, "
               "with the paper's figures (dashed). Degree 1 meets abs <= 5e-4 and rel <= 0.12 % "
               f"only for psi_max <= {d['c4_psi_max_deg']:.3f} deg; at 45 deg its abs is "
               f"{d['at_pi_4']['d1_chebyshev_abs']['max_abs_error']:.3g}.")
    paths = [write_csv(folder, "dichotomy_interval",
                       ("degree", "psi_max_deg", "max_abs_error", "abs_error_bound",
                        "max_rel_error", "rel_error_bound"), d["sweep"], caption, CMD)]
    sweep = np.array(d["sweep"], dtype=float)
    with figure(1, 2, figsize=(8.6, 3.6)) as (fig, (a1, a2)):
        for i, deg in enumerate((1, 2)):
            sel = sweep[:, 0] == deg
            a1.plot(sweep[sel, 1], sweep[sel, 3], "-o", ms=3, color=f"C{i}", label=f"degree {deg}")
            a2.plot(sweep[sel, 1], 100 * sweep[sel, 5], "-o", ms=3, color=f"C{i}",
                    label=f"degree {deg}")
        for ax, (v1, v2) in ((a1, (C4_ABS, C5_ABS)), (a2, (100 * C4_REL, 100 * C5_REL))):
            ax.axhline(v1, color="C0", ls="--", lw=1)
            ax.axhline(v2, color="C1", ls="--", lw=1)
            ax.axvline(45, color="0.5", ls=":", lw=1)
            ax.axvline(d["c4_psi_max_deg"], color="C0", ls=":", lw=1)
            ax.set_yscale("log")
            ax.set_xlabel("psi_max, largest angle between end normals (deg)")
            ax.legend()
        a1.set_ylabel("certified max |p - f|")
        a2.set_ylabel("certified max |p/f - 1| (%)")
        fig.suptitle("Seed 000 dichotomy: fit errors against the interval (dashed: paper's claims)")
        paths += save_figure(fig, folder, "dichotomy_interval", caption)
    summary = {k: v for k, v in d.items() if k != "sweep"}
    summary["command"] = CMD
    paths.append(write_json(folder / "dichotomy_interval_summary.json", summary))
    return paths


def fig_angular_drift(out) -> list[Path]:
    """The spherical-angular recurrence's drift along a 512-pixel span at pi/4."""
    folder = _dir(out)
    d = measure_drift()
    caption = ("Seed 000, method 6: drift of the spherical-angular recurrence "
               "N(t+1) = 2 cos(phi) N(t) - N(t-1) along a 512-pixel span of pi/4, as the length "
               "error | |N| - 1 | and the angle to the exact slerp point, in float64, float32, "
               "float32 restarted from the closed form every 64 pixels, and fixed point with 16, 24 "
               "and 30 fractional bits (2 cos(phi) and each product rounded to F bits).")
    rows = []
    for label, *_ in DRIFT_VARIANTS:
        r = d[label]
        rows += [(label, float(t), float(a), float(b))
                 for t, a, b in zip(r["t"], r["length_error"], r["angle_error"])]
    paths = [write_csv(folder, "angular_drift", ("variant", "t", "length_error", "angle_error_rad"),
                       rows, caption, CMD)]
    with figure(figsize=(7.0, 4.0)) as (fig, ax):
        for i, (label, *_) in enumerate(DRIFT_VARIANTS):
            r = d[label]
            ax.plot(r["t"] * 512, np.maximum(r["angle_error"], 1e-17), color=f"C{i}", label=label)
        ax.set_yscale("log")
        ax.set_xlabel("pixel along the span")
        ax.set_ylabel("angle to the exact slerp normal (rad)")
        ax.legend()
        ax.set_title("Seed 000: angular recurrence drift (psi = 45 deg, 512 px)")
        paths += save_figure(fig, folder, "angular_drift", caption)
    return paths


FIGURES = (methods_table, fig_op_counts, fig_error_vs_angle, fig_error_vs_length,
           fig_dichotomy_interval, fig_angular_drift)


def run(out) -> list[Path]:
    """The seed 000 job."""
    paths = []
    for f in FIGURES:
        paths += f(out)
    return paths
