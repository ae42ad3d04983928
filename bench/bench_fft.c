/* bench_fft.c - FFT figures for tiledtex.h (section 4): the transforms and
   the masked correlation that hierarchical pattern mapping fits with.

   Prints, as bench/bench.c does (`name value unit`, nothing else on stdout):
       fft2d_512 <ms> ms               tt_fft_c2c forward + inverse, in place, complex
       fft2d_512_median <ms> ms        double, 512 x 512: minimum and median of 31
       fft2d_256 <ms> ms               repetitions after a warm-up; the same at 256
       fft2d_256_median <ms> ms
       xcorr_512_3ch <ms> ms           one tt_xcorr_masked fit against a cached 3-channel
       xcorr_512_3ch_median <ms> ms    512 x 512 texture (4 real forward transforms, 1
                                       inverse, the products and the argmin)
       correlate_512_19rot <ms> ms     one tt_xcorr_masked_best fit of a ring-shaped band
                                       (16 texels around a disc of radius 150) against
                                       19 cached 3-channel 512 x 512 textures, as
                                       hierarchical pattern mapping makes: median of 9
       correlate_512_19rot_naive <ms> ms  the same fit as 19 tt_xcorr_masked calls (the
                                       forward transforms redone per texture): median of 9
       correlate_256_19rot <ms> ms     the tt_xcorr_masked_best fit at 256 x 256 (disc
                                       radius 75)
   Built with -DBENCH_FFTW and -lfftw3 (the Makefile does so when Debian's
   libfftw3-dev is installed), it also times the same operation through
   FFTW's FFTW_MEASURE plans, interleaved with ours in the same process
   (each repetition runs ours, then FFTW's; planning is excluded):
       fftw_measure_2d_512 <ms> ms, fftw_measure_2d_512_median <ms> ms,
       fft2d_512_over_fftw <ratio> x   (minimum over minimum; the target is 3 or below)
   and the same at 256. Each repetition restores the input first (outside
   the timing; our inverse is unnormalised). The largest difference between
   the two forward transforms goes to stderr.

       cc -O2 -std=c99 -I. bench/bench_fft.c -o bench_fft -lm
       cc -O2 -std=c99 -I. -DBENCH_FFTW bench/bench_fft.c -o bench_fft_fftw -lfftw3 -lm */
#define _POSIX_C_SOURCE 199309L
#define TILEDTEX_IMPLEMENTATION
#include "tiledtex.h"
#include "bench_clock.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#ifdef BENCH_FFTW
#include <fftw3.h>
#endif

#define REPS 31

#define BEST_REPS 9   /* the 19-texture fits take up to 0.2 s each */

/* Sorts ms[0 .. count-1]; the minimum is then ms[0]. */
static double median_of(double *ms, int count)
{
    qsort(ms, (size_t)count, sizeof ms[0], bench_cmp_double);
    return ms[count / 2];
}

static double median(double *ms) { return median_of(ms, REPS); }

static unsigned long long g_state = 12345;
static double random_unit(void)
{
    g_state = g_state * 6364136223846793005ull + 1442695040888963407ull;
    return (double)(g_state >> 11) / 9007199254740992.0 - 0.5;
}

static int bench_size(int n)
{
    size_t count = 2 * (size_t)n * n, i;
    double *input = (double *)malloc(sizeof(double) * count), *ours = (double *)malloc(sizeof(double) * count);
    double ms[REPS], start, med;
    tt_fft_plan *plan = NULL;
    tt_error err;
    int rep;
#ifdef BENCH_FFTW
    fftw_complex *buf = (fftw_complex *)fftw_malloc(sizeof(fftw_complex) * (size_t)n * n);
    fftw_plan forward, inverse;
    double peer[REPS], peer_med, diff = 0.0, scale = 0.0;
#endif
    if (!input || !ours) return 1;
    for (i = 0; i < count; i++) input[i] = random_unit();
    if (tt_fft_plan_create(n, n, NULL, &plan, &err) != TT_OK) {
        fprintf(stderr, "bench_fft: %s\n", err.message);
        return 1;
    }
#ifdef BENCH_FFTW
    start = bench_now_ms();
    forward = fftw_plan_dft_2d(n, n, buf, buf, FFTW_FORWARD, FFTW_MEASURE);
    inverse = fftw_plan_dft_2d(n, n, buf, buf, FFTW_BACKWARD, FFTW_MEASURE);
    fprintf(stderr, "bench_fft: FFTW_MEASURE planning at %d x %d took %.0f ms (not timed)\n", n, n, bench_now_ms() - start);
    /* The two forward transforms agree? */
    memcpy(ours, input, sizeof(double) * count);
    memcpy(buf, input, sizeof(double) * count);
    tt_fft_c2c(plan, ours, n, n, TT_FFT_FORWARD, NULL);
    fftw_execute(forward);
    for (i = 0; i < count; i++) {
        double d = ours[i] - ((double *)buf)[i];
        if (d < 0) d = -d;
        if (d > diff) diff = d;
        if (ours[i] > scale) scale = ours[i];
        if (-ours[i] > scale) scale = -ours[i];
    }
    fprintf(stderr, "bench_fft: %d x %d forward, ours against FFTW: max difference %.3g relative\n", n, n,
            diff / scale);
#endif
    for (rep = -1; rep < REPS; rep++) {   /* rep -1 warms up */
        memcpy(ours, input, sizeof(double) * count);
        start = bench_now_ms();
        if (tt_fft_c2c(plan, ours, n, n, TT_FFT_FORWARD, &err) != TT_OK ||
            tt_fft_c2c(plan, ours, n, n, TT_FFT_INVERSE, &err) != TT_OK) {
            fprintf(stderr, "bench_fft: %s\n", err.message);
            return 1;
        }
        if (rep >= 0) ms[rep] = bench_now_ms() - start;
#ifdef BENCH_FFTW
        memcpy(buf, input, sizeof(double) * count);
        start = bench_now_ms();
        fftw_execute(forward);
        fftw_execute(inverse);
        if (rep >= 0) peer[rep] = bench_now_ms() - start;
#endif
    }
    if (ours[7] / ((double)n * n) - input[7] > 1e-12 || ours[7] / ((double)n * n) - input[7] < -1e-12) {
        fprintf(stderr, "bench_fft: the round trip is wrong\n");
        return 1;
    }
    med = median(ms);
    printf("fft2d_%d %.3f ms\n", n, ms[0]);
    printf("fft2d_%d_median %.3f ms\n", n, med);
#ifdef BENCH_FFTW
    peer_med = median(peer);
    printf("fftw_measure_2d_%d %.3f ms\n", n, peer[0]);
    printf("fftw_measure_2d_%d_median %.3f ms\n", n, peer_med);
    printf("fft2d_%d_over_fftw %.2f x\n", n, ms[0] / peer[0]);
    fprintf(stderr, "bench_fft: %d x %d: median over median %.2f x\n", n, n, med / peer_med);
    fftw_destroy_plan(forward);
    fftw_destroy_plan(inverse);
    fftw_free(buf);
#endif
    tt_fft_plan_free(plan);
    free(input);
    free(ours);
    return 0;
}

/* One fit of a ragged 200 x 120 mask against a 3-channel 512 x 512 texture. */
static int bench_xcorr(int n)
{
    size_t plane = (size_t)n * n, i;
    double *t = (double *)malloc(sizeof(double) * 3 * plane), *values = (double *)malloc(sizeof(double) * 3 * plane);
    double *mask = (double *)calloc(plane, sizeof(double)), *work, *map = (double *)malloc(sizeof(double) * plane);
    double ms[REPS], start;
    tt_xcorr_texture *tex = NULL;
    tt_xcorr_match match;
    tt_error err;
    int rep, x, y, c;
    if (!t || !values || !mask || !map) return 1;
    for (i = 0; i < 3 * plane; i++) t[i] = random_unit();
    for (y = 0; y < 120; y++)
        for (x = 0; x < 200; x++)
            if ((x * 7 + y * 3) % 5 != 0) {
                mask[(size_t)n * y + x] = 1.0;
                for (c = 0; c < 3; c++)
                    values[plane * c + (size_t)n * y + x] = t[plane * c + (size_t)n * (y + 77) + x + 123];
            }
    if (tt_xcorr_texture_create(n, n, 3, t, NULL, &tex, &err) != TT_OK) {
        fprintf(stderr, "bench_fft: %s\n", err.message);
        return 1;
    }
    work = (double *)malloc(sizeof(double) * tex->work_size);
    if (!work) return 1;
    for (rep = -1; rep < REPS; rep++) {
        start = bench_now_ms();
        if (tt_xcorr_masked(tex, mask, values, NULL, work, map, &match, &err) != TT_OK) {
            fprintf(stderr, "bench_fft: %s\n", err.message);
            return 1;
        }
        if (rep >= 0) ms[rep] = bench_now_ms() - start;
    }
    if (match.x != 123 || match.y != 77) {
        fprintf(stderr, "bench_fft: the planted offset (123, 77) came out as (%d, %d)\n", match.x, match.y);
        return 1;
    }
    fprintf(stderr, "bench_fft: xcorr %d x %d x 3: planted (123, 77) found, E there %.3g\n", n, n, match.e);
    start = median(ms);
    printf("xcorr_%d_3ch %.3f ms\n", n, ms[0]);
    printf("xcorr_%d_3ch_median %.3f ms\n", n, start);
    tt_xcorr_texture_free(tex);
    free(t);
    free(values);
    free(mask);
    free(work);
    free(map);
    return 0;
}

/* The fit of hierarchical pattern mapping: a band of 16 texels around a
   disc of radius 150 n / 512 against 19 cached 3-channel n x n textures
   (random, standing in for the turned copies of one image), the values a
   crop of texture 11 at (201, 45) so that the answer can be checked. Times
   tt_xcorr_masked_best, and with `naive` also 19 tt_xcorr_masked calls
   keeping the best, in the same run. */
#define BEST_TEXTURES 19
static int bench_xcorr_best(int n, int naive)
{
    size_t plane = (size_t)n * n, i;
    double *t = (double *)malloc(sizeof(double) * 3 * plane), *values = (double *)malloc(sizeof(double) * 3 * plane);
    double *mask = (double *)calloc(plane, sizeof(double)), *work = NULL;
    double ms[BEST_REPS], ms_naive[BEST_REPS], start, radius = 150.0 * n / 512, band = 16.0;
    tt_xcorr_texture *tex[BEST_TEXTURES] = {NULL};
    tt_xcorr_match match;
    tt_error err;
    int rep, x, y, c, k, best_k = -1, planted = 11, x0 = 201 % n, y0 = 45;
    if (!t || !values || !mask) return 1;
    for (k = 0; k < BEST_TEXTURES; k++) {
        for (i = 0; i < 3 * plane; i++) t[i] = random_unit();
        if (k == planted)
            for (y = 0; y < n; y++)
                for (x = 0; x < n; x++) {
                    double dx = x - n / 2 + 0.5, dy = y - n / 2 + 0.5, r = sqrt(dx * dx + dy * dy);
                    if (r < radius || r > radius + band) continue;
                    mask[(size_t)n * y + x] = 1.0;
                    for (c = 0; c < 3; c++)
                        values[plane * c + (size_t)n * y + x] =
                            t[plane * c + (size_t)n * ((y + y0) % n) + (x + x0) % n];
                }
        if (tt_xcorr_texture_create(n, n, 3, t, NULL, &tex[k], &err) != TT_OK) {
            fprintf(stderr, "bench_fft: %s\n", err.message);
            return 1;
        }
    }
    work = (double *)malloc(sizeof(double) * tex[0]->best_work_size);
    if (!work) return 1;
    for (rep = -1; rep < BEST_REPS; rep++) {   /* rep -1 warms up */
        start = bench_now_ms();
        if (tt_xcorr_masked_best((const tt_xcorr_texture *const *)tex, BEST_TEXTURES, mask, values, NULL, work,
                                 &match, &best_k, &err) != TT_OK) {
            fprintf(stderr, "bench_fft: %s\n", err.message);
            return 1;
        }
        if (rep >= 0) ms[rep] = bench_now_ms() - start;
        if (!naive) continue;
        start = bench_now_ms();
        {
            tt_xcorr_match m, best;
            int which = -1;
            for (k = 0; k < BEST_TEXTURES; k++) {
                if (tt_xcorr_masked(tex[k], mask, values, NULL, work, NULL, &m, &err) != TT_OK) {
                    fprintf(stderr, "bench_fft: %s\n", err.message);
                    return 1;
                }
                if (which < 0 || m.e < best.e) {
                    best = m;
                    which = k;
                }
            }
            if (rep >= 0) ms_naive[rep] = bench_now_ms() - start;
            if (which != best_k || best.x != match.x || best.y != match.y || best.e != match.e) {
                fprintf(stderr, "bench_fft: 19 tt_xcorr_masked calls disagree with tt_xcorr_masked_best\n");
                return 1;
            }
        }
    }
    if (best_k != planted || match.x != x0 || match.y != y0) {
        fprintf(stderr, "bench_fft: the planted crop (texture %d at (%d, %d)) came out as texture %d at (%d, %d)\n",
                planted, x0, y0, best_k, match.x, match.y);
        return 1;
    }
    fprintf(stderr, "bench_fft: correlate %d x %d x 3 against %d textures: planted crop found, E there %.3g\n", n,
            n, BEST_TEXTURES, match.e);
    printf("correlate_%d_19rot %.3f ms\n", n, median_of(ms, BEST_REPS));
    if (naive) printf("correlate_%d_19rot_naive %.3f ms\n", n, median_of(ms_naive, BEST_REPS));
    for (k = 0; k < BEST_TEXTURES; k++) tt_xcorr_texture_free(tex[k]);
    free(t);
    free(values);
    free(mask);
    free(work);
    return 0;
}

int main(void)
{
    if (bench_size(512) || bench_size(256) || bench_xcorr(512) || bench_xcorr_best(512, 1) ||
        bench_xcorr_best(256, 0))
        return 1;
    return 0;
}
