/*
 * harness.c -- times the span kernels of kernels.h, or runs one of them on a
 * span file and writes its outputs (for the accuracy figures and the tests).
 *
 *   harness list
 *       one line per kernel: name, floats per pixel, per-span flag
 *   harness eval KERNEL SPANS.bin OUT.bin
 *       run KERNEL on every span, write the float32 outputs
 *   harness bench SPANS.bin REPS WARMUP TARGET_MS KERNEL...
 *       WARMUP + REPS rounds; in each round every kernel runs PASSES times
 *       over all spans, the kernels in an order rotated every round
 *       (interleaved, so slow drifts of the machine hit every kernel alike).
 *       Each kernel's PASSES is set so that its window takes about TARGET_MS.
 *       Prints "time ROUND KERNEL CPU_NS WALL_NS ITEMS" per round and kernel
 *       (warm-up rounds are not printed) and "checksum VALUE".
 *       The kernel "store_floor" is no kernel: it stores the same bytes the
 *       normal kernels write (3 floats per pixel) with memset, the machine's
 *       store-bandwidth floor for them.
 *
 * Span file: int64 S, then S records of 8 float32 (nl, nr, t0, dt) and
 * S int32 counts. Each kernel writes the whole frame: span s at its pixel
 * offset in one output array (as a renderer fills its buffer), so every
 * kernel stores the same bytes as store_floor. Timing: CPU time of the thread
 * (CLOCK_THREAD_CPUTIME_ID: time the thread was descheduled on the shared
 * machine does not count) and wall time (CLOCK_MONOTONIC). Nothing but the
 * kernel calls is inside a timed window; the checksum reads the outputs
 * after each window so that no kernel's work can be optimized away.
 */
#define _POSIX_C_SOURCE 199309L

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "kernels.h"

typedef void (*kernel_fn)(const span_t *, float *restrict);
typedef void (*bench_fn)(const span_t *, long, const long *, int, float *);

static double clock_ns(clockid_t id)
{
    struct timespec ts;
    clock_gettime(id, &ts);
    return (double)ts.tv_sec * 1e9 + (double)ts.tv_nsec;
}

#if defined(__GNUC__)
#define BARRIER() __asm__ __volatile__("" ::: "memory")
#else
#define BARRIER() ((void)0)
#endif

/* one function per kernel, so the kernel is called directly (and may be
 * inlined) rather than through a pointer; off[s] is where span s writes, in
 * floats (the barrier keeps one pass from being merged with the next) */
#define BENCH(NAME)                                                                \
    static void bench_##NAME(const span_t *sp, long S, const long *off, int passes, \
                             float *out)                                           \
    {                                                                              \
        for (int p = 0; p < passes; ++p) {                                         \
            for (long s = 0; s < S; ++s)                                           \
                k_##NAME(&sp[s], out + off[s]);                                    \
            BARRIER();                                                             \
        }                                                                          \
    }

BENCH(classic)
BENCH(rsqrt_mul)
#if BENCH_HAVE_SSE
BENCH(sse_rsqrt)
#endif
BENCH(none)
BENCH(newton)
BENCH(lyon)
BENCH(slerp)
BENCH(dichotomy)
BENCH(quadratic)
BENCH(angular)
BENCH(angular_direct)
BENCH(midpoint_classic)
BENCH(midpoint_poly)
BENCH(phong_n)
BENCH(phong_nlh)
BENCH(bump)
#if BENCH_HAVE_AVX2
BENCH(avx2_classic)
BENCH(avx2_rsqrt_newton)
BENCH(avx2_none)
BENCH(avx2_newton)
BENCH(avx2_lyon)
BENCH(avx2_quadratic)
BENCH(avx2_dichotomy)
#endif

/* the store floor: the bytes of the whole frame's normals, stored by memset */
static size_t floor_bytes;
static void k_store_floor(const span_t *s, float *restrict out)
{
    memset(out, 0x3f, (size_t)s->count * 3 * sizeof(float));
}
static void bench_store_floor(const span_t *sp, long S, const long *off, int passes, float *out)
{
    (void)sp; (void)S; (void)off;
    for (int p = 0; p < passes; ++p) {
        memset(out, 0x3f + (p & 1), floor_bytes);
        BARRIER();
    }
}

typedef struct {
    const char *name;
    kernel_fn kernel;
    bench_fn bench;
    int width;        /* floats written per pixel */
    int per_span;     /* 1: one output per span (midpoint kernels), not per pixel */
} entry_t;

#define ENTRY(NAME, WIDTH, PER_SPAN) {#NAME, k_##NAME, bench_##NAME, WIDTH, PER_SPAN}

static const entry_t KERNELS[] = {
    ENTRY(classic, 3, 0),
    ENTRY(rsqrt_mul, 3, 0),
#if BENCH_HAVE_SSE
    ENTRY(sse_rsqrt, 3, 0),
#endif
    ENTRY(none, 3, 0),
    ENTRY(newton, 3, 0),
    ENTRY(lyon, 3, 0),
    ENTRY(slerp, 3, 0),
    ENTRY(dichotomy, 3, 0),
    ENTRY(quadratic, 3, 0),
    ENTRY(angular, 3, 0),
    ENTRY(angular_direct, 3, 0),
    ENTRY(midpoint_classic, 3, 1),
    ENTRY(midpoint_poly, 3, 1),
    ENTRY(phong_n, 1, 0),
    ENTRY(phong_nlh, 1, 0),
    ENTRY(bump, 1, 0),
#if BENCH_HAVE_AVX2
    ENTRY(avx2_classic, 3, 0),
    ENTRY(avx2_rsqrt_newton, 3, 0),
    ENTRY(avx2_none, 3, 0),
    ENTRY(avx2_newton, 3, 0),
    ENTRY(avx2_lyon, 3, 0),
    ENTRY(avx2_quadratic, 3, 0),
    ENTRY(avx2_dichotomy, 3, 0),
#endif
    ENTRY(store_floor, 3, 0),
};
#define N_KERNELS ((int)(sizeof KERNELS / sizeof KERNELS[0]))

static const entry_t *find(const char *name)
{
    for (int i = 0; i < N_KERNELS; ++i)
        if (strcmp(KERNELS[i].name, name) == 0)
            return &KERNELS[i];
    return NULL;
}

static span_t *read_spans(const char *path, long *n_spans, long *max_count, long *pixels)
{
    FILE *f = fopen(path, "rb");
    if (!f) {
        fprintf(stderr, "harness: cannot open %s\n", path);
        return NULL;
    }
    int64_t s64;
    if (fread(&s64, sizeof s64, 1, f) != 1 || s64 < 1) {
        fprintf(stderr, "harness: %s: bad header\n", path);
        fclose(f);
        return NULL;
    }
    const long S = (long)s64;
    float *rec = malloc((size_t)S * 8 * sizeof(float));
    int32_t *cnt = malloc((size_t)S * sizeof(int32_t));
    span_t *sp = malloc((size_t)S * sizeof(span_t));
    if (!rec || !cnt || !sp || fread(rec, sizeof(float), (size_t)S * 8, f) != (size_t)S * 8
        || fread(cnt, sizeof(int32_t), (size_t)S, f) != (size_t)S) {
        fprintf(stderr, "harness: %s: truncated (%ld spans announced)\n", path, S);
        free(rec); free(cnt); free(sp); fclose(f);
        return NULL;
    }
    fclose(f);
    *max_count = 1;
    *pixels = 0;
    for (long s = 0; s < S; ++s) {
        for (int k = 0; k < 3; ++k) {
            sp[s].nl[k] = rec[8 * s + k];
            sp[s].nr[k] = rec[8 * s + 3 + k];
        }
        sp[s].t0 = rec[8 * s + 6];
        sp[s].dt = rec[8 * s + 7];
        sp[s].count = cnt[s] < 1 ? 1 : cnt[s];
        if (sp[s].count > *max_count)
            *max_count = sp[s].count;
        *pixels += sp[s].count;
    }
    free(rec);
    free(cnt);
    *n_spans = S;
    return sp;
}

static int cmd_eval(const char *name, const char *in, const char *outp)
{
    const entry_t *e = find(name);
    if (!e) {
        fprintf(stderr, "harness: unknown kernel %s\n", name);
        return 2;
    }
    long S, maxc, pixels;
    span_t *sp = read_spans(in, &S, &maxc, &pixels);
    if (!sp)
        return 2;
    /* 8 pixels of slack: the AVX2 kernels store whole groups of 8 */
    float *buf = malloc((size_t)(maxc + 8) * 3 * sizeof(float));
    FILE *f = fopen(outp, "wb");
    if (!buf || !f) {
        fprintf(stderr, "harness: cannot write %s\n", outp);
        free(buf); free(sp);
        if (f) fclose(f);
        return 2;
    }
    for (long s = 0; s < S; ++s) {
        e->kernel(&sp[s], buf);
        const size_t n = (size_t)e->width * (size_t)(e->per_span ? 1 : sp[s].count);
        if (fwrite(buf, sizeof(float), n, f) != n) {
            fprintf(stderr, "harness: write error on %s\n", outp);
            fclose(f); free(buf); free(sp);
            return 2;
        }
    }
    fclose(f);
    free(buf);
    free(sp);
    return 0;
}

/* floats of the frame before each span's output, for a kernel of this width */
static long *offsets(const span_t *sp, long S, const entry_t *e)
{
    long *off = malloc((size_t)S * sizeof *off);
    long acc = 0;
    if (!off)
        return NULL;
    for (long s = 0; s < S; ++s) {
        off[s] = acc;
        acc += (long)e->width * (e->per_span ? 1 : sp[s].count);
    }
    return off;
}

static double window(const entry_t *e, const span_t *sp, long S, const long *off, int passes,
                     float *out, double *wall)
{
    const double w0 = clock_ns(CLOCK_MONOTONIC), c0 = clock_ns(CLOCK_THREAD_CPUTIME_ID);
    e->bench(sp, S, off, passes, out);
    const double c1 = clock_ns(CLOCK_THREAD_CPUTIME_ID), w1 = clock_ns(CLOCK_MONOTONIC);
    *wall = w1 - w0;
    return c1 - c0;
}

static int cmd_bench(int argc, char **argv)
{
    const char *in = argv[0];
    const int reps = atoi(argv[1]), warmup = atoi(argv[2]);
    const double target_ns = atof(argv[3]) * 1e6;
    const int nk = argc - 4;
    const entry_t **ks = malloc((size_t)nk * sizeof *ks);
    long **offs = calloc((size_t)nk, sizeof *offs);
    int *passes = calloc((size_t)nk, sizeof *passes);
    if (!ks || !offs || !passes || reps < 1 || warmup < 0 || nk < 1) {
        fprintf(stderr, "harness: bench needs SPANS REPS WARMUP TARGET_MS KERNEL...\n");
        free(ks); free(offs); free(passes);
        return 2;
    }
    for (int i = 0; i < nk; ++i) {
        ks[i] = find(argv[4 + i]);
        if (!ks[i]) {
            fprintf(stderr, "harness: unknown kernel %s\n", argv[4 + i]);
            free(ks); free(offs); free(passes);
            return 2;
        }
    }
    long S, maxc, pixels;
    span_t *sp = read_spans(in, &S, &maxc, &pixels);
    if (!sp) {
        free(ks); free(offs); free(passes);
        return 2;
    }
    /* the frame: 3 floats per pixel, plus 24 floats of slack for 8-lane stores */
    const size_t frame = (size_t)pixels * 3 + (size_t)S * 3 + 24;
    float *out = malloc(frame * sizeof(float));
    floor_bytes = (size_t)pixels * 3 * sizeof(float);
    double chk = 0.0, wall;
    for (int i = 0; i < nk; ++i)
        offs[i] = offsets(sp, S, ks[i]);
    memset(out, 0, frame * sizeof(float));
    /* calibrate each kernel: passes so that its window takes about target_ns */
    for (int i = 0; i < nk; ++i) {
        double one = window(ks[i], sp, S, offs[i], 1, out, &wall);
        if (one < target_ns / 64) /* too short to calibrate on: time 16 passes */
            one = window(ks[i], sp, S, offs[i], 16, out, &wall) / 16;
        passes[i] = one > 0 ? (int)(target_ns / one + 0.5) : 1;
        if (passes[i] < 1)
            passes[i] = 1;
    }
    printf("spans %ld pixels %ld passes %d floor_bytes %zu\n", S, pixels, passes[0], floor_bytes);
    for (int r = 0; r < warmup + reps; ++r) {
        for (int q = 0; q < nk; ++q) {
            const int i = (q + r) % nk;
            const entry_t *e = ks[i];
            const double ns = window(e, sp, S, offs[i], passes[i], out, &wall);
            for (size_t x = 0; x < frame; x += 97)
                chk += out[x];
            if (r >= warmup)
                printf("time %d %s %.0f %.0f %ld\n", r - warmup, e->name, ns, wall,
                       (long)passes[i] * (e->per_span ? S : pixels));
        }
    }
    printf("checksum %.9g\n", chk);
    for (int i = 0; i < nk; ++i)
        free(offs[i]);
    free(out); free(sp); free(ks); free(offs); free(passes);
    return 0;
}

int main(int argc, char **argv)
{
    bump_texture_init();
    if (argc >= 2 && strcmp(argv[1], "list") == 0) {
        for (int i = 0; i < N_KERNELS; ++i)
            printf("%s %d %d\n", KERNELS[i].name, KERNELS[i].width, KERNELS[i].per_span);
        return 0;
    }
    if (argc == 5 && strcmp(argv[1], "eval") == 0)
        return cmd_eval(argv[2], argv[3], argv[4]);
    if (argc >= 7 && strcmp(argv[1], "bench") == 0)
        return cmd_bench(argc - 2, argv + 2);
    fprintf(stderr, "usage: harness list | eval KERNEL SPANS OUT | "
                    "bench SPANS REPS WARMUP TARGET_MS KERNEL...\n");
    return 2;
}
