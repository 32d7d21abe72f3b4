"""binary32 1/sqrt correctly rounded to nearest with float32 arithmetic only.

The generated C uses ``float`` and nothing wider: exponent halving on the
input's encoding, a degree-4 polynomial start, two Newton steps and an exact
midpoint test (the sign of ``1 - m h**2`` for the two midpoints ``h`` around
the candidate, as a sum of error-free float products summed exactly by
Shewchuk's Grow-Expansion). docs/correctly_rounded.md has the proof."""

from __future__ import annotations

__all__: list[str] = []

#: degree-4 start for 1/sqrt(m) on [1, 4) (float32, ascending powers); its
#: relative error is below 2.2e-3 (a Lawson-weighted fit, rounded to float32)
START = tuple(float.fromhex(h) for h in ("0x1.bfbe14p+0", "-0x1.1f7f8cp+0", "0x1.d506f0p-2",
                                         "-0x1.7f2232p-4", "0x1.e6f29cp-8"))

_FMA_PRIMS = """/* p + *lo == a * b exactly (fused multiply-add: the error of a product is a float) */
static inline float cr_two_prod(float a, float b, float *lo)
{
    float p = a * b;
    *lo = fmaf(a, b, -p);
    return p;
}
"""

_DEKKER_PRIMS = """/* Veltkamp's split: hi + lo == a, hi and lo of at most 12 significant bits */
static inline void cr_split(float a, float *hi, float *lo)
{
    float c = 4097.0f * a;  /* 2**12 + 1 */
    float h = c - (c - a);
    *hi = h;
    *lo = a - h;
}

/* p + *lo == a * b exactly (Dekker's product: the partial products of 12-bit halves are exact) */
static inline float cr_two_prod(float a, float b, float *lo)
{
    float p = a * b, ah, al, bh, bl;
    cr_split(a, &ah, &al);
    cr_split(b, &bh, &bl);
    *lo = ((ah * bh - p) + ah * bl + al * bh) + al * bl;
    return p;
}
"""

_COMMON = """/* s + *lo == a + b exactly (Knuth's TwoSum, round to nearest) */
static inline float cr_two_sum(float a, float b, float *lo)
{
    float s = a + b;
    float bb = s - a;
    *lo = (a - (s - bb)) + (b - bb);
    return s;
}

/* The sign (-1, 0, 1) of t[0] + ... + t[n-1] computed exactly: Shewchuk's
   Grow-Expansion keeps e[0..k) a nonoverlapping expansion of the running sum,
   ordered by increasing magnitude (zeros anywhere); the sign of such an
   expansion is that of its most significant nonzero component. */
static int cr_sign_of_sum(const float *t, int n)
{
    float e[8];
    int k = 0;
    for (int i = 0; i < n; i++) {
        float q = t[i];
        for (int j = 0; j < k; j++) {
            float lo;
            q = cr_two_sum(q, e[j], &lo);
            e[j] = lo;
        }
        e[k++] = q;
    }
    for (int j = k - 1; j >= 0; j--)
        if (e[j] != 0.0f)
            return e[j] > 0.0f ? 1 : -1;
    return 0;
}
"""

_NEWTON_FMA = """    float y = fmaf(fmaf(fmaf(fmaf({c4}, m, {c3}), m, {c2}), m, {c1}), m, {c0});
    /* Newton step 1: y <- y + y (1 - m y^2) / 2 */
    float e = fmaf(-m, y * y, 1.0f);
    y = fmaf(0.5f * y, e, y);
    /* Newton step 2 with the residual from the exact square y^2 = t + tl */
    float tl, t = cr_two_prod(y, y, &tl);
    e = fmaf(-m, t, 1.0f);
    e = fmaf(-m, tl, e);
"""

_NEWTON_DEKKER = """    float y = (((({c4} * m + {c3}) * m + {c2}) * m + {c1}) * m) + {c0};
    /* Newton step 1: y <- y + y (1 - m y^2) / 2 */
    float e = 1.0f - m * (y * y);
    y = y + (0.5f * y) * e;
    /* Newton step 2 with the residual from the exact products y^2 = t + tl, m t = q + ql */
    float tl, t = cr_two_prod(y, y, &tl);
    float ql, q = cr_two_prod(m, t, &ql);
    e = ((1.0f - q) - ql) - m * tl;
"""

_BODY = """
/* 1/sqrt(m) rounded to nearest for m in (1, 4): a result in [0.5, 1 - 2^-24] */
static float cr_rsqrt_reduced(float m)
{{
{newton}    /* y + g = yn + d exactly; |1/sqrt(m) - (y + g)| < 2^-33 (docs: the error analysis),
       so |d| <= 2^-25 - 2^-32 proves |1/sqrt(m) - yn| < u/2 = 2^-25: yn is the rounding */
    float g = (0.5f * y) * e;
    float d, yn = cr_two_sum(y, g, &d);
    y = yn;
    if (y >= 0.5f && y <= 0x1.fffffep-1f && fabsf(d) <= 0x1.fcp-26f) return y;
    /* the correctly rounded result lies in [0.5, 1 - 2^-24], where the ulp is u = 2^-24 */
    if (y > 0x1.fffffep-1f) y = 0x1.fffffep-1f;
    if (y < 0.5f) y = 0.5f;
    /* exact: m y = a + al, a y = b + bl, al y = c + cl, so m y^2 = b + bl + c + cl */
    float al, a = cr_two_prod(m, y, &al);
    float bl, b = cr_two_prod(a, y, &bl);
    float cl, c = cr_two_prod(al, y, &cl);
    /* m (y +- u/2)^2 = m y^2 +- u (a + al) + m u^2/4; u a, u al and m u^2/4 are
       exact (scaling by powers of two, far from the underflow threshold) */
    float s[8] = {{1.0f, -b, -bl, -c, -cl, 0.0f, 0.0f, -0x1p-50f * m}};
    if (y < 0x1.fffffep-1f) {{
        s[5] = -0x1p-24f * a;
        s[6] = -0x1p-24f * al;
        /* 1 - m h^2 > 0 with h = y + u/2: 1/sqrt(m) lies above the upper midpoint */
        if (cr_sign_of_sum(s, 8) > 0) return y + 0x1p-24f;
    }}
    if (y > 0.5f) {{
        s[5] = 0x1p-24f * a;
        s[6] = 0x1p-24f * al;
        /* 1 - m h^2 < 0 with h = y - u/2: 1/sqrt(m) lies below the lower midpoint */
        if (cr_sign_of_sum(s, 8) < 0) return y - 0x1p-24f;
    }}
    return y;
}}

float {name}(float x)
{{
    uint32_t b;
    memcpy(&b, &x, sizeof b);
    if ((b & 0x7fffffffu) > 0x7f800000u) return x + x;      /* NaN: quiet NaN */
    if ((b & 0x7fffffffu) == 0u) return 1.0f / x;          /* +-0: +-inf (division by zero) */
    if (b >> 31) return (x - x) / (x - x);                 /* x < 0: NaN (invalid) */
    if (b == 0x7f800000u) return 0.0f;                     /* +inf: +0 */
    int bias = 0;
    if (b < 0x00800000u) {{                                 /* subnormal: x 2^24 is normal, exact */
        float xs = x * 0x1p24f;
        memcpy(&b, &xs, sizeof b);
        bias = 24;
    }}
    /* x = f 2^E, f in [1, 2); E = 2k + odd; m = f 2^odd in [1, 4); 1/sqrt(x) = 2^-k / sqrt(m) */
    int E = (int)(b >> 23) - 127 - bias;
    int odd = E & 1;
    int k = (E - odd) / 2;
    uint32_t mb = (b & 0x007fffffu) | (0x3f800000u + ((uint32_t)odd << 23));
    uint32_t sb = (uint32_t)(127 - k) << 23;                /* 2^-k, k in -75..63: normal */
    float m, scale;
    memcpy(&m, &mb, sizeof m);
    memcpy(&scale, &sb, sizeof scale);
    if (mb == 0x3f800000u) return scale;                    /* x = 4^k: exact */
    return cr_rsqrt_reduced(m) * scale;                     /* exact: the result is normal */
}}
"""


def _float_literal(c: float) -> str:
    """A C float literal of ``c`` (a float32 value): hexadecimal, exact."""
    import struct

    if struct.unpack("<f", struct.pack("<f", c))[0] != c:
        raise ValueError(f"coefficient {c!r} is not a float32 value")
    h = float(c).hex()  # -0x1.bfbe140000000p+0
    mant, exp = h.split("p")
    return f"{mant.rstrip('0').rstrip('.')}p{exp}f"


def c_files(c_name: str, banner: str, fma: bool = True) -> dict:
    """The C source and header of the float-only correctly rounded 1/sqrt."""
    prims = _FMA_PRIMS if fma else _DEKKER_PRIMS
    lits = {f"c{i}": _float_literal(c) for i, c in enumerate(START)}
    newton = (_NEWTON_FMA if fma else _NEWTON_DEKKER).format(**lits)
    src = "\n".join([
        banner,
        "#include <float.h>",
        "#include <math.h>",
        "#include <stdint.h>",
        "#include <string.h>",
        f'#include "{c_name}.h"',
        "",
        "#if !defined(FLT_EVAL_METHOD) || FLT_EVAL_METHOD != 0",
        "#error \"float expressions must be evaluated in float (FLT_EVAL_METHOD 0)\"",
        "#endif",
        "",
        prims,
        _COMMON,
        _BODY.format(newton=newton, name=c_name),
    ])
    src = src.replace("\n\n\n", "\n\n")
    hdr = (f"{banner}\n#ifndef {c_name.upper()}_H\n#define {c_name.upper()}_H\n"
           f"/* 1/sqrt(x) correctly rounded to nearest (ties to even) on every float input;\n"
           f"   the caller's rounding mode must be round-to-nearest. */\n"
           f"float {c_name}(float x);\n#endif\n")
    return {f"{c_name}.c": src, f"{c_name}.h": hdr}
