/*
 * harness.c -- times the span kernels of kernels.h, or runs one of them on a
 * span file and writes its outputs (for the accuracy figures and the tests).
 *
 *   harness list
 *       one line per kernel: name, floats per pixel
 *   harness eval KERNEL SPANS.bin OUT.bin
 *       run KERNEL on every span, write the float32 outputs
 *   harness bench SPANS.bin REPS WARMUP TARGET_MS KERNEL...
 *       WARMUP + REPS rounds; in each round every kernel runs PASSES times
 *       over all spans, the kernels in an order rotated every round
 *       (interleaved, so slow drifts of the machine hit every kernel alike).
 *       PASSES is set once so that the first kernel takes about TARGET_MS.
 *       Prints "time ROUND KERNEL NANOSECONDS PIXELS" per round and kernel
 *       (warm-up rounds are not printed) and "checksum VALUE".
 *
 * Span file: int64 S, then S records of 8 float32 (nl, nr, t0, dt) and
 * S int32 counts. Timing: clock_gettime(CLOCK_MONOTONIC). The checksum reads
 * an output of every span so that no kernel's work can be optimized away.
 */
#define _POSIX_C_SOURCE 199309L

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "kernels.h"

typedef void (*kernel_fn)(const span_t *, float *restrict);
typedef double (*bench_fn)(const span_t *, long, int, float *, double *);

static double now_ns(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e9 + (double)ts.tv_nsec;
}

/* one timing function per kernel, so the kernel is called directly (and may be
 * inlined) rather than through a pointer */
#define BENCH(NAME, OUTS)                                                             \
    static double bench_##NAME(const span_t *sp, long S, int passes, float *buf,    \
                               double *chk)                                          \
    {                                                                                \
        double acc = 0.0;                                                            \
        const double start = now_ns();                                               \
        for (int p = 0; p < passes; ++p)                                             \
            for (long s = 0; s < S; ++s) {                                           \
                k_##NAME(&sp[s], buf);                                               \
                acc += buf[(unsigned long)(s * 7 + p) % (unsigned long)(OUTS)];             \
            }                                                                        \
        const double stop = now_ns();                                                \
        *chk += acc;                                                                 \
        return stop - start;                                                         \
    }

BENCH(classic, 3 * sp[s].count)
BENCH(rsqrt_mul, 3 * sp[s].count)
#if BENCH_HAVE_SSE
BENCH(sse_rsqrt, 3 * sp[s].count)
#endif
BENCH(none, 3 * sp[s].count)
BENCH(newton, 3 * sp[s].count)
BENCH(lyon, 3 * sp[s].count)
BENCH(slerp, 3 * sp[s].count)
BENCH(dichotomy, 3 * sp[s].count)
BENCH(quadratic, 3 * sp[s].count)
BENCH(angular, 3 * sp[s].count)
BENCH(angular_direct, 3 * sp[s].count)
BENCH(midpoint_classic, 3)
BENCH(midpoint_poly, 3)
BENCH(phong_n, sp[s].count)
BENCH(phong_nlh, sp[s].count)
BENCH(bump, sp[s].count)

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
    float *buf = malloc((size_t)maxc * 3 * sizeof(float));
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

static int cmd_bench(int argc, char **argv)
{
    const char *in = argv[0];
    const int reps = atoi(argv[1]), warmup = atoi(argv[2]);
    const double target_ns = atof(argv[3]) * 1e6;
    const int nk = argc - 4;
    const entry_t **ks = malloc((size_t)nk * sizeof *ks);
    if (!ks || reps < 1 || warmup < 0 || nk < 1) {
        fprintf(stderr, "harness: bench needs SPANS REPS WARMUP TARGET_MS KERNEL...\n");
        free(ks);
        return 2;
    }
    for (int i = 0; i < nk; ++i) {
        ks[i] = find(argv[4 + i]);
        if (!ks[i]) {
            fprintf(stderr, "harness: unknown kernel %s\n", argv[4 + i]);
            free(ks);
            return 2;
        }
    }
    long S, maxc, pixels;
    span_t *sp = read_spans(in, &S, &maxc, &pixels);
    if (!sp) {
        free(ks);
        return 2;
    }
    float *buf = malloc((size_t)maxc * 3 * sizeof(float));
    double chk = 0.0;
    /* calibrate: passes so that the first kernel takes about target_ns */
    double one = ks[0]->bench(sp, S, 1, buf, &chk);
    int passes = one > 0 ? (int)(target_ns / one + 0.5) : 1;
    if (passes < 1)
        passes = 1;
    printf("spans %ld pixels %ld passes %d\n", S, pixels, passes);
    for (int r = 0; r < warmup + reps; ++r) {
        for (int i = 0; i < nk; ++i) {
            const entry_t *e = ks[(i + r) % nk];
            const double ns = e->bench(sp, S, passes, buf, &chk);
            if (r >= warmup)
                printf("time %d %s %.0f %ld\n", r - warmup, e->name, ns,
                       (long)passes * (e->per_span ? S : pixels));
        }
    }
    printf("checksum %.9g\n", chk);
    free(buf);
    free(sp);
    free(ks);
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
