/*
 * kernels.h -- the normalization methods of seed 000 as scalar float32 span
 * kernels in C99, plus the baselines and the shading kernels of claim C13.
 *
 * Every kernel computes the pixels of one scan-line span: end normals nl, nr
 * (unit), pixel positions t = t0 + j dt, j = 0 .. count-1, and writes three
 * floats per pixel to out (one float per pixel for the shading kernels).
 * The operations follow chebnorm.methods.kernels one for one (same order,
 * same constants), so the outputs agree with
 * chebnorm.methods.span_normals(..., dtype=np.float32) to a few ulps per
 * operation; tests/test_bench_kernels.py checks that.
 *
 * The two fitted polynomials come from chebnorm's exported headers, generated
 * at build time by benchmarks/ckernels.py with chebnorm.export.c_header:
 *   chebnorm_dichotomy_d2_f(z) ~ 1/sqrt(2 + z)      (dichotomy, method 4)
 *   chebnorm_midpoint_d2_f(x)  ~ 1/sqrt(2 (1 + x))  (quadratic, method 5)
 * Nothing here types a coefficient in by hand.
 *
 * These kernels do not validate their input (span_normals does, in Python).
 */
#ifndef CHEBNORM_BENCH_KERNELS_H
#define CHEBNORM_BENCH_KERNELS_H

#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "chebnorm_dichotomy_d2.h"
#include "chebnorm_midpoint_d2.h"

#if defined(__SSE__)
#include <xmmintrin.h>
#define BENCH_HAVE_SSE 1
#else
#define BENCH_HAVE_SSE 0
#endif

typedef struct {
    float nl[3];
    float nr[3];
    float t0;
    float dt;
    int count;
} span_t;

/* guard of divisions by sin(psi) for parallel end normals (kernels.TINY) */
#define BENCH_TINY 1e-30f
/* deepest dichotomy tree the kernel holds (span_normals.MAX_LEVELS is 20) */
#define BENCH_MAX_LEVELS 16

static inline float dot3(const float a[3], const float b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static inline float pixel_t(const span_t *s, int j)
{
    return s->t0 + (float)j * s->dt;
}

/* ------------------------------------------------ linear interpolation + normalizer */
/* N(t) = N_l + t (N_r - N_l): 3 mul, 3 add per pixel, the difference once per span. */
#define LINEAR_KERNEL(NAME, NORMALIZE)                                          \
    static inline void NAME(const span_t *s, float *restrict out)              \
    {                                                                           \
        const float a0 = s->nl[0], a1 = s->nl[1], a2 = s->nl[2];                \
        const float d0 = s->nr[0] - a0, d1 = s->nr[1] - a1, d2 = s->nr[2] - a2; \
        for (int j = 0; j < s->count; ++j) {                                    \
            const float t = pixel_t(s, j);                                      \
            float n0 = a0 + t * d0, n1 = a1 + t * d1, n2 = a2 + t * d2;         \
            NORMALIZE                                                           \
            out[3 * j] = n0;                                                    \
            out[3 * j + 1] = n1;                                                \
            out[3 * j + 2] = n2;                                                \
        }                                                                       \
    }

/* classic N / sqrt(N.N): 3 mul, 2 add, 1 sqrt, 3 div (the paper's count) */
#define NORM_CLASSIC                                   \
    {                                                  \
        const float r = sqrtf(n0 * n0 + n1 * n1 + n2 * n2); \
        n0 = n0 / r; n1 = n1 / r; n2 = n2 / r;         \
    }
/* 1/sqrtf once, then three multiplications */
#define NORM_RSQRT                                            \
    {                                                         \
        const float r = 1.0f / sqrtf(n0 * n0 + n1 * n1 + n2 * n2); \
        n0 = n0 * r; n1 = n1 * r; n2 = n2 * r;                \
    }
/* method 1: one Newton-Raphson step from 1, N (3 - N.N) * 0.5 */
#define NORM_NEWTON                                              \
    {                                                            \
        const float sc = (3.0f - (n0 * n0 + n1 * n1 + n2 * n2)) * 0.5f; \
        n0 = n0 * sc; n1 = n1 * sc; n2 = n2 * sc;                \
    }
/* method 2: Lyon, N (15 - 10 x + 3 x^2)/8 with the 1/8 folded in (Horner) */
#define NORM_LYON                                                \
    {                                                            \
        const float x = n0 * n0 + n1 * n1 + n2 * n2;             \
        const float sc = (x * 0.375f - 1.25f) * x + 1.875f;      \
        n0 = n0 * sc; n1 = n1 * sc; n2 = n2 * sc;                \
    }
#define NORM_NONE {}

LINEAR_KERNEL(k_classic, NORM_CLASSIC)
LINEAR_KERNEL(k_rsqrt_mul, NORM_RSQRT)
LINEAR_KERNEL(k_none, NORM_NONE)
LINEAR_KERNEL(k_newton, NORM_NEWTON)
LINEAR_KERNEL(k_lyon, NORM_LYON)

#if BENCH_HAVE_SSE
/* the hardware limit: rsqrtss (12-bit estimate) and one Newton step
 * r' = r (1.5 - 0.5 x r^2), then three multiplications */
#define NORM_SSE                                                          \
    {                                                                     \
        const float x = n0 * n0 + n1 * n1 + n2 * n2;                      \
        float r = _mm_cvtss_f32(_mm_rsqrt_ss(_mm_set_ss(x)));             \
        r = r * (1.5f - 0.5f * x * r * r);                                \
        n0 = n0 * r; n1 = n1 * r; n2 = n2 * r;                            \
    }
LINEAR_KERNEL(k_sse_rsqrt, NORM_SSE)
#endif

/* ------------------------------------------------------------ slerp, method 3 */
static inline void k_slerp(const span_t *s, float *restrict out)
{
    const float c = fminf(dot3(s->nl, s->nr), 1.0f);
    const float psi = fmaxf(acosf(c), BENCH_TINY);
    const float inv = 1.0f / sinf(psi);
    for (int j = 0; j < s->count; ++j) {
        const float t = pixel_t(s, j);
        const float wa = sinf((1.0f - t) * psi) * inv;
        const float wb = sinf(t * psi) * inv;
        for (int k = 0; k < 3; ++k)
            out[3 * j + k] = s->nl[k] * wa + s->nr[k] * wb;
    }
}

/* -------------------------------------------- spherical-angular, method 6 */
/* shared set-up: N_k = (N_b - c N_a)/sqrt(1 - c^2), psi = acos c */
#define ANGULAR_SETUP                                                   \
    const float c = fminf(dot3(s->nl, s->nr), 1.0f);                    \
    const float psi = acosf(c);                                         \
    const float inv_w = 1.0f / fmaxf(sqrtf(1.0f - c * c), BENCH_TINY);  \
    float nk[3];                                                        \
    for (int k = 0; k < 3; ++k)                                         \
        nk[k] = (s->nr[k] - s->nl[k] * c) * inv_w;

/* the recurrence N_{j+1} = 2 cos(phi) N_j - N_{j-1}, phi = psi dt: 3 mul, 3 add per pixel */
static inline void k_angular(const span_t *s, float *restrict out)
{
    ANGULAR_SETUP
    const float phi = psi * s->dt;
    const float cp = cosf(phi), sp = sinf(phi);
    const float k2 = cp * 2.0f;
    const float ang = s->t0 * psi;
    const float ca = cosf(ang), sa = sinf(ang);
    float p0[3], p1[3];
    for (int k = 0; k < 3; ++k) {
        const float q0 = nk[k] * ca - s->nl[k] * sa;
        p0[k] = s->nl[k] * ca + nk[k] * sa;
        p1[k] = p0[k] * cp + q0 * sp;
    }
    for (int k = 0; k < 3; ++k)
        out[k] = p0[k];
    if (s->count < 2)
        return;
    for (int k = 0; k < 3; ++k)
        out[3 + k] = p1[k];
    float a0 = p0[0], a1 = p0[1], a2 = p0[2], b0 = p1[0], b1 = p1[1], b2 = p1[2];
    for (int j = 2; j < s->count; ++j) {
        const float c0 = b0 * k2 - a0, c1 = b1 * k2 - a1, c2 = b2 * k2 - a2;
        a0 = b0; a1 = b1; a2 = b2;
        b0 = c0; b1 = c1; b2 = c2;
        out[3 * j] = b0;
        out[3 * j + 1] = b1;
        out[3 * j + 2] = b2;
    }
}

/* direct angular interpolation, N(t) = N_a cos(t psi) + N_k sin(t psi) at every
 * pixel (what the recurrence replaces; claim C8) */
static inline void k_angular_direct(const span_t *s, float *restrict out)
{
    ANGULAR_SETUP
    for (int j = 0; j < s->count; ++j) {
        const float a = pixel_t(s, j) * psi;
        const float ca = cosf(a), sa = sinf(a);
        for (int k = 0; k < 3; ++k)
            out[3 * j + k] = s->nl[k] * ca + nk[k] * sa;
    }
}

/* ------------------------------------------------------ quadratic, method 5 */
/* N(t) = G t^2 + P t + Q through N_l, N_c, N_r; N_c = (N_l + N_r) p(N_l.N_r);
 * forward differences, 6 add per pixel, not normalized. */
static inline void k_quadratic(const span_t *s, float *restrict out)
{
    const float x = dot3(s->nl, s->nr);
    const float r = chebnorm_midpoint_d2_f(x);
    const float t0 = s->t0, dt = s->dt;
    const float h2 = dt * dt;
    float v[3], d1[3], d2[3];
    for (int k = 0; k < 3; ++k) {
        const float sk = s->nl[k] + s->nr[k];
        const float nc4 = (sk * r) * 4.0f;
        const float g = sk * 2.0f - nc4;
        const float p = (nc4 - s->nl[k] * 2.0f) - sk;
        d2[k] = g * (h2 * 2.0f);
        v[k] = s->nl[k] + (p + g * t0) * t0;
        d1[k] = p * dt + g * ((t0 * dt) * 2.0f + h2);
    }
    float v0 = v[0], v1 = v[1], v2 = v[2];
    float e0 = d1[0], e1 = d1[1], e2 = d1[2];
    const float f0 = d2[0], f1 = d2[1], f2 = d2[2];
    for (int j = 0; j < s->count; ++j) {
        out[3 * j] = v0;
        out[3 * j + 1] = v1;
        out[3 * j + 2] = v2;
        v0 += e0; v1 += e1; v2 += e2;
        e0 += f0; e1 += f1; e2 += f2;
    }
}

/* ------------------------------------------------------ dichotomy, method 4 */
/* Written as a performance engineer would, with the nodes and pixels
 * span_normals' float32 kernel computes (same midpoints, same depth, same picks):
 *
 * - depth from the float's bits: the smallest L >= 0 with 2^-L <= dt is minus the
 *   binary exponent of dt (dt in [2^e, 2^(e+1)) gives L = -e); the pixels are on
 *   the dyadic grid of depth L exactly when dt's mantissa bits are zero (dt 2^L = 1)
 *   and t0 2^L is an integer;
 * - off the grid the depth is raised until the node angle psi / 2^L is at most
 *   theta_max = 2 acos(1 - PICK_TOL) (span_normals' _levels). Instead of psi = acos c
 *   the kernel compares c = N_l.N_r with the constants cos(2^n theta_max),
 *   n = 0..6, evaluated at compile time by the double-angle formula from
 *   cos(theta_max) = 2 (1 - PICK_TOL)^2 - 1 (2^7 theta_max > pi: 7 levels always do);
 * - 2^L is built from its bits: no acosf, no ldexpf, no other libm call per span;
 * - only the nodes the pixels need are computed: the pixels cover node indices
 *   ka..kb, and a level of half-stride h computes only the midpoints in
 *   [ka rounded down, kb rounded up] to multiples of h (their ancestors);
 * - a pixel is snapped to its node by u = t0 2^L + j (dt 2^L) (exact power-of-two
 *   scalings of the Python kernel's t 2^L), k = (int)u, f = u - k: no division;
 *   node n + 1 repeats N_r, so the pixel at t = 1 needs no clamp of k + 1;
 * - on x86 a node is one SSE register (below), so a node is stored and read back
 *   with one instruction of the same width (store forwarding never stalls). */
#define BENCH_PICK_TOL 0x1p-12

#define DICH_COS0 (2.0 * (1.0 - BENCH_PICK_TOL) * (1.0 - BENCH_PICK_TOL) - 1.0)
#define DICH_DBL(c) (2.0 * (c) * (c) - 1.0)
#define DICH_COS1 DICH_DBL(DICH_COS0)
#define DICH_COS2 DICH_DBL(DICH_COS1)
#define DICH_COS3 DICH_DBL(DICH_COS2)
#define DICH_COS4 DICH_DBL(DICH_COS3)
#define DICH_COS5 DICH_DBL(DICH_COS4)
#define DICH_COS6 DICH_DBL(DICH_COS5)
/* cos(2^n theta_max): a span needs n + 1 levels when N_l.N_r is below entry n */
static const float DICH_NEED_COS[7] = {
    (float)DICH_COS0, (float)DICH_COS1, (float)DICH_COS2, (float)DICH_COS3,
    (float)DICH_COS4, (float)DICH_COS5, (float)DICH_COS6};

static inline uint32_t float_bits(float x)
{
    uint32_t u;
    memcpy(&u, &x, sizeof u);
    return u;
}

/* 2^k for 0 <= k <= 127, from its bits */
static inline float pow2f(int k)
{
    const uint32_t u = (uint32_t)(127 + k) << 23;
    float x;
    memcpy(&x, &u, sizeof x);
    return x;
}

/* depth L as span_normals' _levels (dt > 0, pixels in [0, 1]) and whether the
 * pixels lie on the dyadic grid of depth L */
static inline int dichotomy_levels(const span_t *s, int *on_grid)
{
    const uint32_t b = float_bits(s->dt);
    const int e = (int)((b >> 23) & 0xffu) - 127;
    int L = e < 0 ? -e : 0;
    if (L > BENCH_MAX_LEVELS)
        L = BENCH_MAX_LEVELS;
    const float g0 = s->t0 * pow2f(L);
    *on_grid = g0 == (float)(int32_t)g0
               && (s->count < 2 || ((b & 0x7fffffu) == 0 && e <= 0 && -e <= BENCH_MAX_LEVELS));
    if (!*on_grid) {
        const float c = dot3(s->nl, s->nr);
        int need = 0;
        for (int n = 0; n < 7; ++n)
            need += c < DICH_NEED_COS[n];
        if (need > L)
            L = need;
    }
    return L;
}

#if BENCH_HAVE_SSE
/* x86: a node is one __m128 (x, y, z, 0), so the tree's stores and the picks'
 * loads have the same width (a store read back by a wider load stalls the
 * store forwarding); the same operations, one rounding each, as the portable
 * version below. The pixel is stored as 2 + 1 floats (no write past the span). */
typedef __m128 dnode_t;
#define DNODE_SET(v) _mm_setr_ps((v)[0], (v)[1], (v)[2], 0.0f)
#define DNODE_MID(a, b, r) _mm_mul_ps(_mm_add_ps(a, b), _mm_set1_ps(r))
#define DNODE_PICK(a, b, f) _mm_add_ps(a, _mm_mul_ps(_mm_set1_ps(f), _mm_sub_ps(b, a)))
static inline void dnode_store(float *out, dnode_t v)
{
    _mm_storel_pi((__m64 *)out, v);
    _mm_store_ss(out + 2, _mm_movehl_ps(v, v));
}
#else
typedef struct { float v[3]; } dnode_t;
static inline dnode_t dnode_set(const float *v)
{
    dnode_t d = {{v[0], v[1], v[2]}};
    return d;
}
static inline dnode_t dnode_mid(dnode_t a, dnode_t b, float r)
{
    dnode_t d = {{(a.v[0] + b.v[0]) * r, (a.v[1] + b.v[1]) * r, (a.v[2] + b.v[2]) * r}};
    return d;
}
static inline dnode_t dnode_pick(dnode_t a, dnode_t b, float f)
{
    dnode_t d = {{a.v[0] + f * (b.v[0] - a.v[0]), a.v[1] + f * (b.v[1] - a.v[1]),
                  a.v[2] + f * (b.v[2] - a.v[2])}};
    return d;
}
static inline void dnode_store(float *out, dnode_t d)
{
    out[0] = d.v[0];
    out[1] = d.v[1];
    out[2] = d.v[2];
}
#define DNODE_SET(v) dnode_set(v)
#define DNODE_MID(a, b, r) dnode_mid(a, b, r)
#define DNODE_PICK(a, b, f) dnode_pick(a, b, f)
#endif

static inline void k_dichotomy(const span_t *s, float *restrict out)
{
    /* nodes 0 .. n, and node n + 1 = N_r so that a pixel at u = n needs no clamp */
    static dnode_t node[(1 << BENCH_MAX_LEVELS) + 2];
    int on_grid;
    const int L = dichotomy_levels(s, &on_grid);
    const int n = 1 << L;
    const float scale = pow2f(L);
    const float g0 = s->t0 * scale, g1 = s->dt * scale;
    /* node indices the pixels read: ka .. kb */
    int ka = (int)g0, kb;
    if (on_grid)
        kb = ka + s->count - 1;
    else
        kb = (int)(g0 + (float)(s->count - 1) * g1) + 2; /* one node of slack for rounding */
    if (ka > n) ka = n;
    if (kb > n) kb = n;
    node[0] = DNODE_SET(s->nl);
    node[n] = node[n + 1] = DNODE_SET(s->nr);
    /* each level: r = p(z) ~ 1/sqrt(2 + z), midpoints (N1 + N2) r, z' = (2 + z) r */
    float z = dot3(s->nl, s->nr) * 2.0f;
    if (L <= 3) { /* the short spans of a mesh: the whole tree, unrolled (no loop branches) */
        const dnode_t a = node[0], b = node[n];
        const float r0 = chebnorm_dichotomy_d2_f(z);
        if (L == 1) {
            node[1] = DNODE_MID(a, b, r0);
        } else if (L >= 2) {
            const float z1 = (z + 2.0f) * r0, r1 = chebnorm_dichotomy_d2_f(z1);
            const dnode_t m = DNODE_MID(a, b, r0);
            if (L == 2) {
                node[1] = DNODE_MID(a, m, r1);
                node[2] = m;
                node[3] = DNODE_MID(m, b, r1);
            } else {
                const float z2 = (z1 + 2.0f) * r1, r2 = chebnorm_dichotomy_d2_f(z2);
                const dnode_t q1 = DNODE_MID(a, m, r1), q3 = DNODE_MID(m, b, r1);
                node[1] = DNODE_MID(a, q1, r2);
                node[2] = q1;
                node[3] = DNODE_MID(q1, m, r2);
                node[4] = m;
                node[5] = DNODE_MID(m, q3, r2);
                node[6] = q3;
                node[7] = DNODE_MID(q3, b, r2);
            }
        }
    } else for (int h = n >> 1; h >= 1; h >>= 1) {
        const float sz = z + 2.0f;
        const float r = chebnorm_dichotomy_d2_f(z);
        if (h > 1)
            z = sz * r;
        const int lo = ka & ~(h - 1);
        int hi = (kb + h - 1) & ~(h - 1);
        if (hi > n) hi = n;
        for (int i = (lo & h) ? lo : lo + h; i <= hi; i += 2 * h)
            node[i] = DNODE_MID(node[i - h], node[i + h], r);
    }
    if (on_grid) { /* pixel j is node ka + j */
        for (int j = 0; j < s->count; ++j)
            dnode_store(out + 3 * j, node[ka + j]);
        return;
    }
    /* off the grid: a linear pick between the two nodes around the pixel
     * (u >= 0, so truncation is floor; u <= n up to rounding, so k0 <= n) */
    float jf = 0.0f;
    for (int j = 0; j < s->count; ++j, jf += 1.0f) {
        const float u = g0 + jf * g1;
        int k0 = (int)u;
        const float f = u - (float)k0;
        if (k0 > n) k0 = n;
        dnode_store(out + 3 * j, DNODE_PICK(node[k0], node[k0 + 1], f));
    }
}

/* ------------------------------------------- midpoint alone (claim C7, part 1) */
/* classic: normalize N_l + N_r: 3 add, 3 mul, 2 add, 1 sqrt, 3 div */
static inline void k_midpoint_classic(const span_t *s, float *restrict out)
{
    const float s0 = s->nl[0] + s->nr[0], s1 = s->nl[1] + s->nr[1], s2 = s->nl[2] + s->nr[2];
    const float r = sqrtf(s0 * s0 + s1 * s1 + s2 * s2);
    out[0] = s0 / r;
    out[1] = s1 / r;
    out[2] = s2 / r;
}

/* seed 000, method 5: (N_l + N_r) p(N_l.N_r), p from the exported midpoint table */
static inline void k_midpoint_poly(const span_t *s, float *restrict out)
{
    const float r = chebnorm_midpoint_d2_f(dot3(s->nl, s->nr));
    out[0] = (s->nl[0] + s->nr[0]) * r;
    out[1] = (s->nl[1] + s->nr[1]) * r;
    out[2] = (s->nl[2] + s->nr[2]) * r;
}

/* ------------------------------------------------ shading kernels (claim C13) */
/* Blinn-Phong I = kd max(N.L, 0) + ks max(N.H, 0)^32 (5 squarings); one float per pixel */
#define SHADE_KD 0.6f
#define SHADE_KS 0.3f
static inline float shade(float n0, float n1, float n2, const float L[3], const float H[3])
{
    const float nl = fmaxf(n0 * L[0] + n1 * L[1] + n2 * L[2], 0.0f);
    float h = fmaxf(n0 * H[0] + n1 * H[1] + n2 * H[2], 0.0f);
    h *= h; h *= h; h *= h; h *= h; h *= h;
    return SHADE_KD * nl + SHADE_KS * h;
}

#define CLASSIC3(v0, v1, v2)                                  \
    {                                                         \
        const float r_ = sqrtf(v0 * v0 + v1 * v1 + v2 * v2);  \
        v0 = v0 / r_; v1 = v1 / r_; v2 = v2 / r_;             \
    }

/* fixed light and half vector of the shading kernels (directional light, far viewer) */
static const float SHADE_L[3] = {0.48f, 0.36f, 0.8f};
static const float SHADE_H[3] = {0.0f, 0.6f, 0.8f};

/* span-end tangent-space L and H, and texture coordinates, derived from the span
 * (any smooth values do for timing: they cost the same as real ones) */
static inline void light_ends(const span_t *s, float Ll[3], float Lr[3], float Hl[3], float Hr[3])
{
    for (int k = 0; k < 3; ++k) {
        Ll[k] = 0.5f * s->nl[(k + 1) % 3] + 0.5f * SHADE_L[k];
        Lr[k] = 0.5f * s->nr[(k + 1) % 3] + 0.5f * SHADE_L[k];
        Hl[k] = 0.5f * s->nl[(k + 2) % 3] + 0.5f * SHADE_H[k];
        Hr[k] = 0.5f * s->nr[(k + 2) % 3] + 0.5f * SHADE_H[k];
    }
}

/* Phong, directional light and far viewer: interpolate and normalize N only */
static inline void k_phong_n(const span_t *s, float *restrict out)
{
    const float a0 = s->nl[0], a1 = s->nl[1], a2 = s->nl[2];
    const float d0 = s->nr[0] - a0, d1 = s->nr[1] - a1, d2 = s->nr[2] - a2;
    for (int j = 0; j < s->count; ++j) {
        const float t = pixel_t(s, j);
        float n0 = a0 + t * d0, n1 = a1 + t * d1, n2 = a2 + t * d2;
        CLASSIC3(n0, n1, n2)
        out[j] = shade(n0, n1, n2, SHADE_L, SHADE_H);
    }
}

/* Phong as in the hardware model's pipeline: interpolate N, L, H; normalize all three */
static inline void k_phong_nlh(const span_t *s, float *restrict out)
{
    float Ll[3], Lr[3], Hl[3], Hr[3];
    light_ends(s, Ll, Lr, Hl, Hr);
    for (int j = 0; j < s->count; ++j) {
        const float t = pixel_t(s, j);
        float n0 = s->nl[0] + t * (s->nr[0] - s->nl[0]);
        float n1 = s->nl[1] + t * (s->nr[1] - s->nl[1]);
        float n2 = s->nl[2] + t * (s->nr[2] - s->nl[2]);
        float L[3], H[3];
        for (int k = 0; k < 3; ++k) {
            L[k] = Ll[k] + t * (Lr[k] - Ll[k]);
            H[k] = Hl[k] + t * (Hr[k] - Hl[k]);
        }
        CLASSIC3(n0, n1, n2)
        CLASSIC3(L[0], L[1], L[2])
        CLASSIC3(H[0], H[1], H[2])
        out[j] = shade(n0, n1, n2, L, H);
    }
}

/* bump-map texture: unit perturbed normals [-F_u/k, -F_v/k, 1]/|.| of the
 * square-patch simplification (seed 001), BUMP_TEX x BUMP_TEX texels */
#define BUMP_TEX 256
static float bump_texture[BUMP_TEX * BUMP_TEX * 3];

static inline void bump_texture_init(void)
{
    const float two_pi = 6.28318530717958647692f, amp = 0.01f, freq = 8.0f;
    for (int iv = 0; iv < BUMP_TEX; ++iv)
        for (int iu = 0; iu < BUMP_TEX; ++iu) {
            const float u = (iu + 0.5f) / BUMP_TEX, v = (iv + 0.5f) / BUMP_TEX;
            const float a = two_pi * freq * u, b = two_pi * freq * v;
            const float fu = amp * two_pi * freq * cosf(a) * sinf(b);
            const float fv = amp * two_pi * freq * sinf(a) * cosf(b);
            const float r = 1.0f / sqrtf(fu * fu + fv * fv + 1.0f);
            float *T = bump_texture + 3 * (iv * BUMP_TEX + iu);
            T[0] = -fu * r;
            T[1] = -fv * r;
            T[2] = r;
        }
}

/* bump mapping on the Phong pipeline (seed 001): interpolate tangent-space L, H
 * and (u, v); normalize L and H; the perturbed normal is a texture fetch */
static inline void k_bump(const span_t *s, float *restrict out)
{
    float Ll[3], Lr[3], Hl[3], Hr[3];
    light_ends(s, Ll, Lr, Hl, Hr);
    const float ul = s->nl[0] * 0.5f + 0.5f, ur = s->nr[0] * 0.5f + 0.5f;
    const float vl = s->nl[1] * 0.5f + 0.5f, vr = s->nr[1] * 0.5f + 0.5f;
    for (int j = 0; j < s->count; ++j) {
        const float t = pixel_t(s, j);
        float L[3], H[3];
        for (int k = 0; k < 3; ++k) {
            L[k] = Ll[k] + t * (Lr[k] - Ll[k]);
            H[k] = Hl[k] + t * (Hr[k] - Hl[k]);
        }
        const float u = ul + t * (ur - ul), v = vl + t * (vr - vl);
        const int iu = (int)(u * (float)BUMP_TEX) & (BUMP_TEX - 1);
        const int iv = (int)(v * (float)BUMP_TEX) & (BUMP_TEX - 1);
        const float *T = bump_texture + 3 * (iv * BUMP_TEX + iu);
        CLASSIC3(L[0], L[1], L[2])
        CLASSIC3(H[0], H[1], H[2])
        out[j] = shade(T[0], T[1], T[2], L, H);
    }
}

/* ---------------------------------------------------- AVX2 variants (8 lanes) */
/* Explicit 8-lane versions of classic, rsqrt + Newton, none and the paper's
 * Newton, Lyon, quadratic and dichotomy methods, lanes = 8 consecutive pixels of a span.
 * Built where the compiler targets AVX2 (-march=native on an AVX2 CPU). Same
 * operations per pixel as the scalar kernels; the quadratic steps its forward
 * differences 8 pixels at a time (lane l starts at pixel l: same 6 add per pixel,
 * fewer accumulated roundings). The three component vectors are interleaved
 * to x y z x y z ... with in-lane permutes and blends. A span's last group
 * is stored whole (8 pixels): OUT MUST HAVE ROOM FOR 7 PIXELS PAST THE SPAN,
 * as a SIMD renderer pads its scan-line buffer; those slots hold scratch (the
 * harness writes the spans of a frame in order, so the next span overwrites
 * them). Masked stores (vmaskmovps) would keep the strict bound but cost more
 * than the whole kernel on short spans (measured on AMD Zen 3). */
#if defined(__AVX2__)
#include <immintrin.h>
#define BENCH_HAVE_AVX2 1

/* store 8 pixels of the components x, y, z, interleaved x y z x y z ... */
static inline void store3x8(float *out, __m256 x, __m256 y, __m256 z)
{
    const __m256 xr = _mm256_permute_ps(x, _MM_SHUFFLE(1, 2, 3, 0)); /* x0 x3 x2 x1 */
    const __m256 yr = _mm256_permute_ps(y, _MM_SHUFFLE(2, 3, 0, 1)); /* y1 y0 y3 y2 */
    const __m256 zr = _mm256_permute_ps(z, _MM_SHUFFLE(3, 0, 1, 2)); /* z2 z1 z0 z3 */
    const __m256 a = _mm256_blend_ps(_mm256_blend_ps(xr, yr, 0x22), zr, 0x44); /* x0 y0 z0 x1 */
    const __m256 b = _mm256_blend_ps(_mm256_blend_ps(yr, zr, 0x22), xr, 0x44); /* y1 z1 x2 y2 */
    const __m256 c = _mm256_blend_ps(_mm256_blend_ps(zr, xr, 0x22), yr, 0x44); /* z2 x3 y3 z3 */
    _mm256_storeu_ps(out, _mm256_permute2f128_ps(a, b, 0x20));
    _mm256_storeu_ps(out + 8, _mm256_permute2f128_ps(c, a, 0x30));
    _mm256_storeu_ps(out + 16, _mm256_permute2f128_ps(b, c, 0x31));
}

#define AVX2_LINEAR_KERNEL(NAME, NORMALIZE)                                           \
    static inline void NAME(const span_t *s, float *restrict out)                    \
    {                                                                                 \
        const __m256 a0 = _mm256_set1_ps(s->nl[0]), a1 = _mm256_set1_ps(s->nl[1]);   \
        const __m256 a2 = _mm256_set1_ps(s->nl[2]);                                   \
        const __m256 d0 = _mm256_set1_ps(s->nr[0] - s->nl[0]);                        \
        const __m256 d1 = _mm256_set1_ps(s->nr[1] - s->nl[1]);                        \
        const __m256 d2 = _mm256_set1_ps(s->nr[2] - s->nl[2]);                        \
        const __m256 iota = _mm256_setr_ps(0, 1, 2, 3, 4, 5, 6, 7);                   \
        const __m256 t0 = _mm256_set1_ps(s->t0), dt = _mm256_set1_ps(s->dt);         \
        for (int j = 0; j < s->count; j += 8) {                                       \
            const __m256 jj = _mm256_add_ps(_mm256_set1_ps((float)j), iota);          \
            const __m256 t = _mm256_add_ps(t0, _mm256_mul_ps(jj, dt));                \
            __m256 n0 = _mm256_add_ps(a0, _mm256_mul_ps(t, d0));                      \
            __m256 n1 = _mm256_add_ps(a1, _mm256_mul_ps(t, d1));                      \
            __m256 n2 = _mm256_add_ps(a2, _mm256_mul_ps(t, d2));                      \
            NORMALIZE                                                                 \
            store3x8(out + 3 * j, n0, n1, n2);                                         \
        }                                                                             \
    }

#define AVX2_DOT(n0, n1, n2) \
    _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(n0, n0), _mm256_mul_ps(n1, n1)), _mm256_mul_ps(n2, n2))
#define AVX2_SCALE(sc) \
    { n0 = _mm256_mul_ps(n0, sc); n1 = _mm256_mul_ps(n1, sc); n2 = _mm256_mul_ps(n2, sc); }
#define AVX2_NORM_CLASSIC                                        \
    {                                                            \
        const __m256 r = _mm256_sqrt_ps(AVX2_DOT(n0, n1, n2));   \
        n0 = _mm256_div_ps(n0, r);                               \
        n1 = _mm256_div_ps(n1, r);                               \
        n2 = _mm256_div_ps(n2, r);                               \
    }
#define AVX2_NORM_RSQRT_NEWTON                                                        \
    {                                                                                 \
        const __m256 x = AVX2_DOT(n0, n1, n2);                                        \
        __m256 r = _mm256_rsqrt_ps(x);                                                \
        const __m256 hx = _mm256_mul_ps(_mm256_set1_ps(0.5f), x);                     \
        r = _mm256_mul_ps(r, _mm256_sub_ps(_mm256_set1_ps(1.5f),                      \
                                           _mm256_mul_ps(_mm256_mul_ps(hx, r), r)));  \
        AVX2_SCALE(r)                                                                 \
    }
#define AVX2_NORM_NEWTON                                                                    \
    {                                                                                       \
        const __m256 sc = _mm256_mul_ps(_mm256_sub_ps(_mm256_set1_ps(3.0f), AVX2_DOT(n0, n1, n2)), \
                                        _mm256_set1_ps(0.5f));                              \
        AVX2_SCALE(sc)                                                                      \
    }
#define AVX2_NORM_LYON                                                                      \
    {                                                                                       \
        const __m256 x = AVX2_DOT(n0, n1, n2);                                              \
        const __m256 sc = _mm256_add_ps(                                                    \
            _mm256_mul_ps(_mm256_sub_ps(_mm256_mul_ps(x, _mm256_set1_ps(0.375f)),           \
                                        _mm256_set1_ps(1.25f)), x),                          \
            _mm256_set1_ps(1.875f));                                                        \
        AVX2_SCALE(sc)                                                                      \
    }

AVX2_LINEAR_KERNEL(k_avx2_classic, AVX2_NORM_CLASSIC)
AVX2_LINEAR_KERNEL(k_avx2_rsqrt_newton, AVX2_NORM_RSQRT_NEWTON)
AVX2_LINEAR_KERNEL(k_avx2_none, {})
AVX2_LINEAR_KERNEL(k_avx2_newton, AVX2_NORM_NEWTON)
AVX2_LINEAR_KERNEL(k_avx2_lyon, AVX2_NORM_LYON)

/* method 5 with forward differences of step 8 dt, lane l at pixel j + l:
 * v_l = N_l + (P + G t_l) t_l, e_l = P H + G (2 t_l H + H^2), f = 2 G H^2 (H = 8 dt) */
static inline void k_avx2_quadratic(const span_t *s, float *restrict out)
{
    const float x = dot3(s->nl, s->nr);
    const float r = chebnorm_midpoint_d2_f(x);
    const __m256 iota = _mm256_setr_ps(0, 1, 2, 3, 4, 5, 6, 7);
    const __m256 t = _mm256_add_ps(_mm256_set1_ps(s->t0), _mm256_mul_ps(iota, _mm256_set1_ps(s->dt)));
    const float H = 8.0f * s->dt;
    const __m256 Hv = _mm256_set1_ps(H), H2 = _mm256_set1_ps(H * H);
    const __m256 tH2 = _mm256_add_ps(_mm256_mul_ps(_mm256_mul_ps(t, Hv), _mm256_set1_ps(2.0f)), H2);
    __m256 v[3], e[3], f[3];
    for (int k = 0; k < 3; ++k) {
        const float sk = s->nl[k] + s->nr[k];
        const float nc4 = (sk * r) * 4.0f;
        const __m256 g = _mm256_set1_ps(sk * 2.0f - nc4);
        const __m256 p = _mm256_set1_ps((nc4 - s->nl[k] * 2.0f) - sk);
        f[k] = _mm256_mul_ps(g, _mm256_set1_ps(H * H * 2.0f));
        v[k] = _mm256_add_ps(_mm256_set1_ps(s->nl[k]),
                             _mm256_mul_ps(_mm256_add_ps(p, _mm256_mul_ps(g, t)), t));
        e[k] = _mm256_add_ps(_mm256_mul_ps(p, Hv), _mm256_mul_ps(g, tH2));
    }
    for (int j = 0; j < s->count; j += 8) {
        store3x8(out + 3 * j, v[0], v[1], v[2]);
        for (int k = 0; k < 3; ++k) {
            v[k] = _mm256_add_ps(v[k], e[k]);
            e[k] = _mm256_add_ps(e[k], f[k]);
        }
    }
}
/* method 4, 8 lanes: the same tree level by level in structure-of-arrays form.
 * A level's new midpoints (N_k + N_{k+1}) r are 8 consecutive pairs of the
 * previous level's nodes (two overlapping loads), interleaved with those nodes
 * by unpack and permute into the next level; the nodes, their depth, the z
 * recurrence and the picks are those of k_dichotomy (identical roundings).
 * Pixels on the grid are loaded 8 at a time, pixels off it are gathered
 * (k = (int)u, f = u - k, both nodes of 8 pixels by vgatherdps). Small trees and
 * spans that read few of their nodes (the restricted node range pays there)
 * take the scalar kernel: this is the kernel "at its best" on every span. */
#define AVX2_DICH_MIN_NODES 64
static inline void k_avx2_dichotomy(const span_t *s, float *restrict out)
{
    enum { CAP = (1 << BENCH_MAX_LEVELS) + 1 + 24 };
    static float buf[2][3][CAP];
    int on_grid;
    const int L = dichotomy_levels(s, &on_grid);
    const int n = 1 << L;
    if (n < AVX2_DICH_MIN_NODES || 2 * s->count < n) {
        k_dichotomy(s, out);
        return;
    }
    float *P[3] = {buf[0][0], buf[0][1], buf[0][2]};
    float *Q[3] = {buf[1][0], buf[1][1], buf[1][2]};
    for (int k = 0; k < 3; ++k) {
        P[k][0] = s->nl[k];
        P[k][1] = s->nr[k];
    }
    float z = dot3(s->nl, s->nr) * 2.0f;
    for (int c = 2, h = n >> 1; h >= 1; c = 2 * c - 1, h >>= 1) { /* c nodes -> 2c - 1 */
        const float sz = z + 2.0f;
        const float r = chebnorm_dichotomy_d2_f(z);
        if (h > 1)
            z = sz * r;
        const __m256 rv = _mm256_set1_ps(r);
        if (h == 1 && on_grid && s->t0 == 0.0f && s->count == n + 1) {
            /* a whole span on the grid: the last level goes straight to the pixels */
            for (int i = 0; i < c - 1; i += 8) {
                __m256 lo8[3], hi8[3];
                for (int k = 0; k < 3; ++k) {
                    const __m256 a = _mm256_loadu_ps(P[k] + i), b = _mm256_loadu_ps(P[k] + i + 1);
                    const __m256 m = _mm256_mul_ps(_mm256_add_ps(a, b), rv);
                    const __m256 lo = _mm256_unpacklo_ps(a, m), hi = _mm256_unpackhi_ps(a, m);
                    lo8[k] = _mm256_permute2f128_ps(lo, hi, 0x20);
                    hi8[k] = _mm256_permute2f128_ps(lo, hi, 0x31);
                }
                store3x8(out + 6 * i, lo8[0], lo8[1], lo8[2]);
                store3x8(out + 6 * i + 24, hi8[0], hi8[1], hi8[2]);
            }
            for (int k = 0; k < 3; ++k) /* pixel n (c - 1 = n / 2 is a multiple of 8) */
                out[3 * n + k] = s->nr[k];
            return;
        }
        for (int k = 0; k < 3; ++k) {
            const float *p = P[k];
            float *q = Q[k];
            for (int i = 0; i < c - 1; i += 8) {
                const __m256 a = _mm256_loadu_ps(p + i), b = _mm256_loadu_ps(p + i + 1);
                const __m256 m = _mm256_mul_ps(_mm256_add_ps(a, b), rv);
                const __m256 lo = _mm256_unpacklo_ps(a, m), hi = _mm256_unpackhi_ps(a, m);
                _mm256_storeu_ps(q + 2 * i, _mm256_permute2f128_ps(lo, hi, 0x20));
                _mm256_storeu_ps(q + 2 * i + 8, _mm256_permute2f128_ps(lo, hi, 0x31));
            }
            q[2 * (c - 1)] = p[c - 1];
            Q[k] = P[k];
            P[k] = q;
        }
    }
    const float scale = pow2f(L);
    const float g0 = s->t0 * scale, g1 = s->dt * scale;
    if (on_grid) { /* pixel j is node ka + j */
        const int ka = (int)g0;
        for (int j = 0; j < s->count; j += 8)
            store3x8(out + 3 * j, _mm256_loadu_ps(P[0] + ka + j), _mm256_loadu_ps(P[1] + ka + j),
                     _mm256_loadu_ps(P[2] + ka + j));
        return;
    }
    const __m256 iota = _mm256_setr_ps(0, 1, 2, 3, 4, 5, 6, 7);
    const __m256 g0v = _mm256_set1_ps(g0), g1v = _mm256_set1_ps(g1);
    const __m256i nv = _mm256_set1_epi32(n), one = _mm256_set1_epi32(1);
    for (int j = 0; j < s->count; j += 8) {
        const __m256 u = _mm256_add_ps(g0v, _mm256_mul_ps(_mm256_add_ps(_mm256_set1_ps((float)j), iota), g1v));
        const __m256i k0 = _mm256_cvttps_epi32(u);
        const __m256 f = _mm256_sub_ps(u, _mm256_cvtepi32_ps(k0));
        const __m256i ka = _mm256_min_epi32(k0, nv);
        const __m256i kb = _mm256_min_epi32(_mm256_add_epi32(ka, one), nv);
        __m256 o[3];
        for (int k = 0; k < 3; ++k) {
            const __m256 A = _mm256_i32gather_ps(P[k], ka, 4), B = _mm256_i32gather_ps(P[k], kb, 4);
            o[k] = _mm256_add_ps(A, _mm256_mul_ps(f, _mm256_sub_ps(B, A)));
        }
        store3x8(out + 3 * j, o[0], o[1], o[2]);
    }
}
#else
#define BENCH_HAVE_AVX2 0
#endif

#endif /* CHEBNORM_BENCH_KERNELS_H */
