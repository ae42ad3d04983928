/* tests/test_4_fft.c - unit tests for section 4 of tiledtex.h, second part:
   the radix-2 FFTs (complex, real, 1D and 2D) and the masked
   cross-correlation that hierarchical pattern mapping fits clusters with
   (transforms against a naive DFT, the correlation against a direct sum,
   and a planted offset it must find). Run by run_fft_tests()
   (tests/test_common.c calls it). */
#include "test_common.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ------------------------------------------------------------------------ */
/* Helpers                                                                  */
/* ------------------------------------------------------------------------ */

static double *fft_random(size_t count)
{
    double *v = (double *)malloc(sizeof(double) * (count ? count : 1));
    size_t i;
    for (i = 0; i < count; i++) v[i] = lcg_unit() * 2.0 - 1.0;
    return v;
}

/* The 2D DFT of w x h complex values by its definition, with the angle of
   every term reduced exactly ((k x mod w) / w) and sums in long double. */
static void fft_naive(const double *in, int w, int h, int sign, double *out)
{
    int k, l, x, y;
    for (l = 0; l < h; l++)
        for (k = 0; k < w; k++) {
            long double sr = 0.0L, si = 0.0L;
            for (y = 0; y < h; y++)
                for (x = 0; x < w; x++) {
                    double turn = (double)((long)k * x % w) / w + (double)((long)l * y % h) / h;
                    double a = sign * 6.28318530717958647692 * turn, c = cos(a), s = sin(a);
                    const double *v = in + 2 * ((size_t)w * y + x);
                    sr += (long double)v[0] * c - (long double)v[1] * s;
                    si += (long double)v[0] * s + (long double)v[1] * c;
                }
            out[2 * ((size_t)w * l + k)] = (double)sr;
            out[2 * ((size_t)w * l + k) + 1] = (double)si;
        }
}

/* max |a - b| / max |b| over n doubles (0 when b is all zero and a == b). */
static double fft_rel_error(const double *a, const double *b, size_t n)
{
    double diff = 0.0, scale = 0.0;
    size_t i;
    for (i = 0; i < n; i++) {
        if (fabs(a[i] - b[i]) > diff || a[i] != a[i]) diff = a[i] != a[i] ? HUGE_VAL : fabs(a[i] - b[i]);
        if (fabs(b[i]) > scale) scale = fabs(b[i]);
    }
    return scale > 0.0 ? diff / scale : diff;
}

static tt_fft_plan *fft_plan(int w, int h)
{
    tt_fft_plan *plan = NULL;
    tt_error err;
    tt_result r = tt_fft_plan_create(w, h, NULL, &plan, &err);
    CHECK(r == TT_OK && plan, "plan %d x %d: %s", w, h, r == TT_OK ? "" : err.message);
    return plan;
}

/* ------------------------------------------------------------------------ */
/* Transforms                                                               */
/* ------------------------------------------------------------------------ */

/* 1D sizes 1 .. 1024, both directions, against the definition. */
static void test_fft_naive_1d(void)
{
    int log2n, dir, bad = 0;
    double worst = 0.0;
    lcg_seed(4001);
    for (log2n = 0; log2n <= 10; log2n++) {
        int n = 1 << log2n;
        tt_fft_plan *plan = fft_plan(n, 1);
        double *x = fft_random(2 * (size_t)n), *ref = (double *)malloc(sizeof(double) * 2 * n);
        double *y = (double *)malloc(sizeof(double) * 2 * n);
        for (dir = -1; dir <= 1 && plan; dir += 2) {
            double e;
            tt_error err;
            memcpy(y, x, sizeof(double) * 2 * n);
            fft_naive(x, n, 1, dir, ref);
            if (tt_fft_c2c(plan, y, n, 1, dir, &err) != TT_OK) {
                bad++;
                DETAIL("n = %d: %s", n, err.message);
                continue;
            }
            e = fft_rel_error(y, ref, 2 * (size_t)n);
            if (e > worst) worst = e;
            if (!(e <= 1e-12) && bad++ == 0) DETAIL("n = %d direction %d: relative error %g", n, dir, e);
        }
        free(x);
        free(y);
        free(ref);
        tt_fft_plan_free(plan);
    }
    CHECK(bad == 0, "1D sizes 1..1024 match the naive DFT within 1e-12 (worst %g, %d bad)", worst, bad);
}

/* 2D, square and not, against the definition (also as a column: width 1). */
static void test_fft_naive_2d(void)
{
    static const int sizes[][2] = {{1, 1}, {2, 1}, {1, 2}, {1, 16}, {2, 2}, {4, 2}, {2, 8}, {8, 4},
                                   {16, 16}, {64, 32}, {32, 64}, {4, 64}, {64, 2}, {128, 8}};
    int s, dir, bad = 0;
    double worst = 0.0;
    lcg_seed(4002);
    for (s = 0; s < (int)(sizeof sizes / sizeof sizes[0]); s++) {
        int w = sizes[s][0], h = sizes[s][1];
        size_t n = 2 * (size_t)w * h;
        tt_fft_plan *plan = fft_plan(w, h);
        double *x = fft_random(n), *ref = (double *)malloc(sizeof(double) * n), *y = (double *)malloc(sizeof(double) * n);
        for (dir = -1; dir <= 1 && plan; dir += 2) {
            double e;
            memcpy(y, x, sizeof(double) * n);
            fft_naive(x, w, h, dir, ref);
            if (tt_fft_c2c(plan, y, w, h, dir, NULL) != TT_OK) {
                bad++;
                continue;
            }
            e = fft_rel_error(y, ref, n);
            if (e > worst) worst = e;
            if (!(e <= 1e-12) && bad++ == 0) DETAIL("%d x %d direction %d: relative error %g", w, h, dir, e);
        }
        free(x);
        free(y);
        free(ref);
        tt_fft_plan_free(plan);
    }
    CHECK(bad == 0, "2D sizes up to 64 x 32 (and 128 x 8) match the naive DFT within 1e-12 (worst %g, %d bad)", worst,
          bad);
}

/* inverse(forward(x)) = w h x (the inverse is unnormalised), Parseval and
   linearity, on a larger non-square array. */
static void test_fft_identities(void)
{
    int w = 256, h = 64;
    size_t n = 2 * (size_t)w * h, i;
    tt_fft_plan *plan = fft_plan(w, h);
    double *x = fft_random(n), *y = fft_random(n), *fx = (double *)malloc(sizeof(double) * n);
    double *fy = (double *)malloc(sizeof(double) * n), *fz = (double *)malloc(sizeof(double) * n);
    double energy = 0.0, spectrum_energy = 0.0, diff = 0.0, a = 0.75, b = -1.5;
    if (!plan) return;
    lcg_seed(4003);
    memcpy(fx, x, sizeof(double) * n);
    memcpy(fy, y, sizeof(double) * n);
    for (i = 0; i < n; i++) fz[i] = a * x[i] + b * y[i];
    CHECK(tt_fft_c2c(plan, fx, w, h, TT_FFT_FORWARD, NULL) == TT_OK, "forward");
    CHECK(tt_fft_c2c(plan, fy, w, h, TT_FFT_FORWARD, NULL) == TT_OK, "forward");
    CHECK(tt_fft_c2c(plan, fz, w, h, TT_FFT_FORWARD, NULL) == TT_OK, "forward");
    for (i = 0; i < n; i++) {
        double d = fabs(fz[i] - (a * fx[i] + b * fy[i]));
        if (d > diff) diff = d;
        energy += x[i] * x[i];
        spectrum_energy += fx[i] * fx[i];
    }
    CHECK(diff <= 1e-12 * sqrt((double)w * h), "linearity: F(a x + b y) = a F(x) + b F(y) (max difference %g)", diff);
    spectrum_energy /= (double)w * h;
    CHECK(fabs(spectrum_energy - energy) <= 1e-12 * energy, "Parseval: sum |x|^2 = %.17g, sum |X|^2 / (w h) = %.17g",
          energy, spectrum_energy);
    CHECK(tt_fft_c2c(plan, fx, w, h, TT_FFT_INVERSE, NULL) == TT_OK, "inverse");
    diff = 0.0;
    for (i = 0; i < n; i++)
        if (fabs(fx[i] / ((double)w * h) - x[i]) > diff) diff = fabs(fx[i] / ((double)w * h) - x[i]);
    CHECK(diff <= 1e-14, "inverse(forward(x)) = w h x, unnormalised (max difference %g after dividing)", diff);
    /* The forward transform of a unit impulse at (1, 0) is e^(-2 pi i k / w):
       the sign convention. */
    memset(fx, 0, sizeof(double) * n);
    fx[2] = 1.0;
    tt_fft_c2c(plan, fx, w, h, TT_FFT_FORWARD, NULL);
    CHECK(near(fx[2], cos(6.28318530717958647692 / w), 1e-15) && near(fx[3], -sin(6.28318530717958647692 / w), 1e-15),
          "forward is e^(-2 pi i k x / w): bin 1 of an impulse at x = 1 is (%.17g, %.17g)", fx[2], fx[3]);
    free(x);
    free(y);
    free(fx);
    free(fy);
    free(fz);
    tt_fft_plan_free(plan);
}

/* The strip-mined column pass equals transforming each column on its own
   (gathered, a 1D plan, scattered back) after the same row pass, for
   widths below, at and above the strip of 32 columns. */
static void test_fft_strips(void)
{
    static const int sizes[][2] = {{2, 16}, {8, 32}, {32, 8}, {64, 64}, {128, 16}, {4, 512}};
    int s, bad = 0;
    double worst = 0.0;
    lcg_seed(4004);
    for (s = 0; s < (int)(sizeof sizes / sizeof sizes[0]); s++) {
        int w = sizes[s][0], h = sizes[s][1], x, y;
        size_t n = 2 * (size_t)w * h;
        tt_fft_plan *plan = fft_plan(w, h), *rows = fft_plan(w, 1), *cols = fft_plan(h, 1);
        double *data = fft_random(n), *ref = (double *)malloc(sizeof(double) * n);
        double *column = (double *)malloc(sizeof(double) * 2 * h), e;
        if (!plan || !rows || !cols) return;
        memcpy(ref, data, sizeof(double) * n);
        for (y = 0; y < h; y++) tt_fft_c2c(rows, ref + 2 * (size_t)w * y, w, 1, TT_FFT_FORWARD, NULL);
        for (x = 0; x < w; x++) {
            for (y = 0; y < h; y++) {
                column[2 * y] = ref[2 * ((size_t)w * y + x)];
                column[2 * y + 1] = ref[2 * ((size_t)w * y + x) + 1];
            }
            tt_fft_c2c(cols, column, h, 1, TT_FFT_FORWARD, NULL);
            for (y = 0; y < h; y++) {
                ref[2 * ((size_t)w * y + x)] = column[2 * y];
                ref[2 * ((size_t)w * y + x) + 1] = column[2 * y + 1];
            }
        }
        tt_fft_c2c(plan, data, w, h, TT_FFT_FORWARD, NULL);
        e = fft_rel_error(data, ref, n);
        if (e > worst) worst = e;
        if (!(e <= 1e-15) && bad++ == 0) DETAIL("%d x %d: strips differ from per-column transforms by %g", w, h, e);
        free(data);
        free(ref);
        free(column);
        tt_fft_plan_free(plan);
        tt_fft_plan_free(rows);
        tt_fft_plan_free(cols);
    }
    CHECK(bad == 0, "the strip-mined column pass equals per-column 1D transforms (worst %g, %d bad)", worst, bad);
}

/* r2c equals the left half (bins 0 .. w/2) of the complex transform of the
   real data; c2r(r2c(x)) = w h x. */
static void test_fft_real(void)
{
    static const int sizes[][2] = {{1, 1}, {2, 1}, {1, 4}, {2, 2}, {4, 1}, {8, 1}, {1024, 1}, {64, 32},
                                   {32, 64}, {256, 8}, {2, 64}, {128, 128}};
    int s, bad_r2c = 0, bad_c2r = 0;
    double worst_r2c = 0.0, worst_c2r = 0.0;
    lcg_seed(4005);
    for (s = 0; s < (int)(sizeof sizes / sizeof sizes[0]); s++) {
        int w = sizes[s][0], h = sizes[s][1], half = w / 2 + 1, x, y;
        size_t n = (size_t)w * h, i;
        tt_fft_plan *plan = fft_plan(w, h);
        double *real = fft_random(n), *cplx = (double *)calloc(2 * n, sizeof(double));
        double *spectrum = (double *)malloc(sizeof(double) * 2 * (size_t)half * h), *back = fft_random(n);
        double scale = 0.0, diff = 0.0;
        tt_error err;
        if (!plan) return;
        for (i = 0; i < n; i++) cplx[2 * i] = real[i];
        tt_fft_c2c(plan, cplx, w, h, TT_FFT_FORWARD, NULL);
        if (tt_fft_r2c(plan, real, w, h, spectrum, &err) != TT_OK) {
            bad_r2c++;
            DETAIL("r2c %d x %d: %s", w, h, err.message);
        }
        for (y = 0; y < h; y++)
            for (x = 0; x < half; x++) {
                const double *a = spectrum + 2 * ((size_t)half * y + x), *b = cplx + 2 * ((size_t)w * y + x);
                if (fabs(a[0] - b[0]) > diff) diff = fabs(a[0] - b[0]);
                if (fabs(a[1] - b[1]) > diff) diff = fabs(a[1] - b[1]);
            }
        for (i = 0; i < 2 * n; i++)
            if (fabs(cplx[i]) > scale) scale = fabs(cplx[i]);
        if (diff / scale > worst_r2c) worst_r2c = diff / scale;
        if (!(diff <= 1e-13 * scale) && bad_r2c++ == 0) DETAIL("r2c %d x %d differs from c2c by %g", w, h, diff / scale);
        if (tt_fft_c2r(plan, spectrum, w, h, back, &err) != TT_OK) {
            bad_c2r++;
            DETAIL("c2r %d x %d: %s", w, h, err.message);
        }
        diff = 0.0;
        for (i = 0; i < n; i++)
            if (fabs(back[i] / (double)n - real[i]) > diff) diff = fabs(back[i] / (double)n - real[i]);
        if (diff > worst_c2r) worst_c2r = diff;
        if (!(diff <= 1e-14) && bad_c2r++ == 0) DETAIL("c2r(r2c(x)) / (w h) - x for %d x %d: %g", w, h, diff);
        free(real);
        free(cplx);
        free(spectrum);
        free(back);
        tt_fft_plan_free(plan);
    }
    CHECK(bad_r2c == 0, "r2c equals the complex transform's bins 0 .. w/2 (worst relative %g, %d bad)", worst_r2c,
          bad_r2c);
    CHECK(bad_c2r == 0, "c2r(r2c(x)) = w h x (worst %g, %d bad)", worst_c2r, bad_c2r);
}

/* The plan is read-only: transforms leave its tables as they were. */
static void test_fft_plan_read_only(void)
{
    tt_fft_plan *plan = fft_plan(64, 16), copy;
    double *data, *spectrum;
    int same;
    if (!plan) return;
    copy = *plan;
    copy.twiddles = (double *)malloc(sizeof(double) * 6 * 31);
    memcpy(copy.twiddles, plan->twiddles, sizeof(double) * 6 * 31);
    data = fft_random(2 * 64 * 16);
    spectrum = (double *)malloc(sizeof(double) * 2 * 33 * 16);
    tt_fft_c2c(plan, data, 64, 16, TT_FFT_FORWARD, NULL);
    tt_fft_c2c(plan, data, 64, 16, TT_FFT_INVERSE, NULL);
    tt_fft_r2c(plan, data, 64, 16, spectrum, NULL);
    tt_fft_c2r(plan, spectrum, 64, 16, data, NULL);
    same = memcmp(copy.twiddles, plan->twiddles, sizeof(double) * 6 * 31) == 0 && copy.width == plan->width &&
           copy.height == plan->height && copy.bit_reverse == plan->bit_reverse;
    CHECK(same, "the transforms leave the plan unchanged");
    CHECK(plan->twiddles[0] == 1.0 && plan->twiddles[1] == 0.0, "the first twiddle is exactly 1 (%g, %g)",
          plan->twiddles[0], plan->twiddles[1]);
    free(copy.twiddles);
    free(data);
    free(spectrum);
    tt_fft_plan_free(plan);
}

static void fft_free_only(void *ptr, void *user_data)
{
    (void)user_data;
    free(ptr);
}

static void test_fft_errors(void)
{
    tt_fft_plan *plan = (tt_fft_plan *)&plan, *good;
    tt_error err;
    double data[2 * 8 * 4], spectrum[2 * 5 * 4];
    tt_allocator half_allocator;
    int i;
    CHECK(tt_fft_plan_create(500, 4, NULL, &plan, &err) == TT_ERROR_INVALID_ARGUMENT && plan == NULL &&
              strstr(err.message, "512") && strstr(err.message, "500"),
          "width 500: invalid, the message names 512 (%s)", err.message);
    CHECK(tt_fft_plan_create(4, 300, NULL, &plan, &err) == TT_ERROR_INVALID_ARGUMENT &&
              strstr(err.message, "256") && strstr(err.message, "512"),
          "height 300: the nearest is 256, pad to 512 (%s)", err.message);
    CHECK(tt_fft_plan_create(0, 4, NULL, &plan, &err) == TT_ERROR_INVALID_ARGUMENT, "width 0 (%s)", err.message);
    CHECK(tt_fft_plan_create(4, -8, NULL, &plan, &err) == TT_ERROR_INVALID_ARGUMENT, "height -8 (%s)", err.message);
    CHECK(tt_fft_plan_create(65536, 1, NULL, &plan, &err) == TT_ERROR_TOO_LARGE &&
              strstr(err.message, "32768"),
          "width 65536 is above the limit (%s)", err.message);
    CHECK(tt_fft_plan_create(4, 4, NULL, NULL, &err) == TT_ERROR_INVALID_ARGUMENT, "out NULL (%s)", err.message);
    memset(&half_allocator, 0, sizeof half_allocator);
    half_allocator.free = fft_free_only;
    CHECK(tt_fft_plan_create(4, 4, &half_allocator, &plan, &err) == TT_ERROR_INVALID_ARGUMENT && plan == NULL,
          "an allocator with free only (%s)", err.message);
    good = fft_plan(8, 4);
    if (!good) return;
    for (i = 0; i < 2 * 8 * 4; i++) data[i] = i;
    CHECK(tt_fft_c2c(NULL, data, 8, 4, TT_FFT_FORWARD, &err) == TT_ERROR_INVALID_ARGUMENT, "plan NULL (%s)",
          err.message);
    CHECK(tt_fft_c2c(good, NULL, 8, 4, TT_FFT_FORWARD, &err) == TT_ERROR_INVALID_ARGUMENT, "data NULL (%s)",
          err.message);
    CHECK(tt_fft_c2c(good, data, 8, 4, 0, &err) == TT_ERROR_INVALID_ARGUMENT && msg_has_number(err.message, 0),
          "direction 0 (%s)", err.message);
    CHECK(tt_fft_c2c(good, data, 8, 4, 2, &err) == TT_ERROR_INVALID_ARGUMENT, "direction 2 (%s)", err.message);
    CHECK(tt_fft_c2c(good, data, 4, 8, TT_FFT_FORWARD, &err) == TT_ERROR_INVALID_ARGUMENT &&
              msg_has_number(err.message, 8),
          "4 x 8 data with an 8 x 4 plan (%s)", err.message);
    CHECK(data[5] == 5.0, "data untouched by refused calls");
    CHECK(tt_fft_r2c(good, data, 16, 4, spectrum, &err) == TT_ERROR_INVALID_ARGUMENT, "r2c size mismatch (%s)",
          err.message);
    CHECK(tt_fft_r2c(good, data, 8, 4, NULL, &err) == TT_ERROR_INVALID_ARGUMENT, "r2c spectrum NULL (%s)",
          err.message);
    CHECK(tt_fft_c2r(good, spectrum, 8, 2, data, &err) == TT_ERROR_INVALID_ARGUMENT, "c2r size mismatch (%s)",
          err.message);
    CHECK(tt_fft_c2r(good, NULL, 8, 4, data, &err) == TT_ERROR_INVALID_ARGUMENT, "c2r spectrum NULL (%s)",
          err.message);
    /* Non-finite data and overflow come out as TT_ERROR_NON_FINITE. */
    data[13] = internal_not_a_number();
    CHECK(tt_fft_c2c(good, data, 8, 4, TT_FFT_FORWARD, &err) == TT_ERROR_NON_FINITE && err.result == TT_ERROR_NON_FINITE,
          "a NaN in the data (%s)", err.message);
    for (i = 0; i < 2 * 8 * 4; i++) data[i] = i % 3 ? 1e308 : 1.0;
    CHECK(tt_fft_c2c(good, data, 8, 4, TT_FFT_FORWARD, &err) == TT_ERROR_NON_FINITE, "values that overflow (%s)",
          err.message);
    for (i = 0; i < 8 * 4; i++) data[i] = 1.0;
    data[7] = (double)internal_infinity();
    CHECK(tt_fft_r2c(good, data, 8, 4, spectrum, &err) == TT_ERROR_NON_FINITE, "r2c of an infinity (%s)", err.message);
    for (i = 0; i < 2 * 5 * 4; i++) spectrum[i] = 1.0;
    spectrum[9] = internal_not_a_number();   /* the imaginary part of bin w/2: ignored, as documented */
    CHECK(tt_fft_c2r(good, spectrum, 8, 4, data, &err) == TT_OK, "c2r ignores bin w/2's imaginary part (%s)",
          err.message);
    for (i = 0; i < 2 * 5 * 4; i++) spectrum[i] = 1.0;
    spectrum[12] = internal_not_a_number();
    CHECK(tt_fft_c2r(good, spectrum, 8, 4, data, &err) == TT_ERROR_NON_FINITE, "c2r of a NaN (%s)", err.message);
    for (i = 0; i < 2 * 8 * 4; i++) data[i] = 1.0;
    CHECK(tt_fft_c2c(good, data, 8, 4, TT_FFT_INVERSE, &err) == TT_OK && err.result == TT_OK && data[0] == 32.0,
          "success clears the error (%s)", err.message);
    tt_fft_plan_free(good);
    tt_fft_plan_free(NULL);
}

/* ------------------------------------------------------------------------ */
/* Masked correlation                                                       */
/* ------------------------------------------------------------------------ */

/* E(ox, oy) by its definition. */
static double xc_direct(const double *t, const double *mask, const double *values, int w, int h, int channels,
                        int ox, int oy)
{
    long double e = 0.0L;
    int x, y, c;
    size_t plane = (size_t)w * h;
    for (y = 0; y < h; y++)
        for (x = 0; x < w; x++) {
            double j = mask[(size_t)w * y + x];
            if (j == 0.0) continue;
            for (c = 0; c < channels; c++) {
                double d = values[plane * c + (size_t)w * y + x] -
                           t[plane * c + (size_t)w * ((y + oy) % h) + (x + ox) % w];
                e += (long double)j * d * d;
            }
        }
    return (double)e;
}

typedef struct xc_case {
    int w, h, channels;
    double *t, *mask, *values, *work, *map;
    tt_xcorr_texture *tex;
} xc_case;

static int xc_open(xc_case *k, int w, int h, int channels)
{
    size_t n = (size_t)w * h * channels;
    tt_error err;
    memset(k, 0, sizeof *k);
    k->w = w;
    k->h = h;
    k->channels = channels;
    k->t = fft_random(n);
    k->mask = (double *)calloc((size_t)w * h, sizeof(double));
    k->values = fft_random(n);
    k->map = (double *)malloc(sizeof(double) * (size_t)w * h);
    CHECK(tt_xcorr_texture_create(w, h, channels, k->t, NULL, &k->tex, &err) == TT_OK, "texture %d x %d x %d: %s", w,
          h, channels, err.message);
    if (!k->tex) return 0;
    k->work = (double *)malloc(sizeof(double) * k->tex->work_size);
    return 1;
}

static void xc_close(xc_case *k)
{
    free(k->t);
    free(k->mask);
    free(k->values);
    free(k->work);
    free(k->map);
    tt_xcorr_texture_free(k->tex);
}

/* Eq. (2) equals the direct masked sum at 16 random offsets, for a binary
   and a soft mask, and the match is the map's smallest entry. */
static void test_xcorr_direct(void)
{
    xc_case k;
    int soft, i, bad = 0, x, y;
    double worst = 0.0;
    lcg_seed(4101);
    if (!xc_open(&k, 32, 16, 3)) return;
    for (soft = 0; soft <= 1; soft++) {
        tt_xcorr_match m;
        tt_error err;
        double low = HUGE_VAL;
        int at = -1;
        for (i = 0; i < k.w * k.h; i++) k.mask[i] = lcg_below(3) == 0 ? (soft ? lcg_unit() : 1.0) : 0.0;
        CHECK(tt_xcorr_masked(k.tex, k.mask, k.values, NULL, k.work, k.map, &m, &err) == TT_OK, "%s", err.message);
        for (i = 0; i < 16; i++) {
            int ox = lcg_below(k.w), oy = lcg_below(k.h);
            double direct = xc_direct(k.t, k.mask, k.values, k.w, k.h, k.channels, ox, oy);
            double got = k.map[k.w * oy + ox], e = fabs(got - direct) / direct;
            if (e > worst) worst = e;
            if (!(e <= 1e-12) && bad++ == 0)
                DETAIL("%s mask, offset (%d, %d): E = %.17g, direct %.17g", soft ? "soft" : "binary", ox, oy, got,
                       direct);
        }
        for (y = 0; y < k.h; y++)
            for (x = 0; x < k.w; x++)
                if (k.map[k.w * y + x] < low) {
                    low = k.map[k.w * y + x];
                    at = k.w * y + x;
                }
        CHECK(m.x == at % k.w && m.y == at / k.w && m.e == low, "the match (%d, %d) is the map's minimum (%d, %d)", m.x,
              m.y, at % k.w, at / k.w);
    }
    CHECK(bad == 0, "E by FFT equals the direct masked sum at 16 random offsets within 1e-12 (worst %g)", worst);
    xc_close(&k);
}

/* The direct masked sums (hierarchical pattern mapping's small bands):
   the offset with the smallest exact E, against every offset's E summed in
   double in the same order, with the terms summed two in one pass over a
   row (neither wraps there) and one at a time (an odd last term, offsets
   that wrap round the texture), on 1 and 3 channels. */
static void test_xcorr_direct_sums(void)
{
    enum { W = 48, H = 24, MAXC = 3, TERMS = 10, REACH = 16 };
    float texture[MAXC * W * H];
    int config, tx[TERMS], ty[TERMS];
    double weight[TERMS], values[TERMS * MAXC];
    lcg_seed(4107);
    for (config = 0; config < 8; config++) {
        int channels = (config & 1) ? 3 : 1, count = (config & 2) ? TERMS : TERMS - 1, wraps = config & 4;
        int lo = wraps ? 0 : 3, hi = wraps ? W - 1 : W - 1 - REACH, i, c, x, y, best = -2, at = -1;
        double best_e = -1, low = HUGE_VAL;
        uint64_t found;
        for (i = 0; i < channels * W * H; i++) texture[i] = (float)lcg_unit();
        for (i = 0; i < count; i++) {
            tx[i] = lcg_below(REACH);
            ty[i] = lcg_below(H);
            weight[i] = 0.1 + lcg_unit();
            for (c = 0; c < channels; c++) values[i * channels + c] = lcg_unit();
        }
        found = internal_xcorr_direct(W, H, channels, texture, count, tx, ty, weight, values, lo, hi, &best, &best_e);
        for (y = 0; y < H; y++)
            for (x = lo; x <= hi; x++) {
                double e = 0;
                for (i = 0; i < count; i++)
                    for (c = 0; c < channels; c++) {
                        double d = values[i * channels + c] -
                                   texture[(size_t)W * H * c + (size_t)W * ((ty[i] + y) % H) + (tx[i] + x) % W];
                        e += weight[i] * d * d;
                    }
                if (e < low) {
                    low = e;
                    at = W * y + x;
                }
            }
        CHECK(found == 0 && best == at && best_e == low,
              "%d channel(s), %d terms, offsets %d..%d: the smallest E at %d (%.17g), the exact sums' at %d (%.17g)",
              channels, count, lo, hi, best, best_e, at, low);
    }
}

/* The values are a crop of T at (x0, y0) under a blob of a mask that
   crosses the image border (toroidal): that offset is found, E < 1e-9, and
   the mirrored offset (-x0, -y0), which the paper's printed formula would
   give, is not. Then restricting the offsets excludes it. */
static void test_xcorr_planted(void)
{
    xc_case k;
    int x, y, c, x0 = 37, y0 = 11, bad = 0, i;
    tt_xcorr_match m;
    tt_error err;
    unsigned char *allowed;
    lcg_seed(4102);
    if (!xc_open(&k, 64, 32, 3)) return;
    for (y = 0; y < k.h; y++)
        for (x = 0; x < k.w; x++) {
            /* An ellipse centred at (4, 3), 7 by 4 texels: wraps in both directions. */
            double dx = ((x + 4) % k.w) - 8.0, dy = ((y + 2) % k.h) - 5.0;
            k.mask[k.w * y + x] = dx * dx / 49.0 + dy * dy / 16.0 <= 1.0 ? 1.0 : 0.0;
            for (c = 0; c < k.channels; c++)
                k.values[(size_t)k.w * k.h * c + k.w * y + x] =
                    k.mask[k.w * y + x] != 0.0 ? k.t[(size_t)k.w * k.h * c + k.w * ((y + y0) % k.h) + (x + x0) % k.w]
                                               : internal_not_a_number();   /* off the mask: never read */
        }
    CHECK(k.mask[k.w * 3 + k.w - 1] == 1.0 && k.mask[k.w * (k.h - 1) + 4] == 1.0 && k.mask[k.w * 16 + 32] == 0.0,
          "the mask crosses the border");
    CHECK(tt_xcorr_masked(k.tex, k.mask, k.values, NULL, k.work, k.map, &m, &err) == TT_OK, "%s", err.message);
    CHECK(m.x == x0 && m.y == y0, "planted offset (%d, %d) found: (%d, %d)", x0, y0, m.x, m.y);
    CHECK(m.e < 1e-9, "E at the planted offset is %g (< 1e-9)", m.e);
    CHECK(!(m.x == k.w - x0 && m.y == k.h - y0) && k.map[k.w * (k.h - y0) + (k.w - x0)] > 1.0,
          "the mirrored offset (%d, %d) is not chosen: E there %g", k.w - x0, k.h - y0,
          k.map[k.w * (k.h - y0) + (k.w - x0)]);
    CHECK(m.mask_sum > 50.0 && m.masked_energy > 0.0, "mask_sum %g, masked_energy %g", m.mask_sum, m.masked_energy);
    for (i = 0; i < k.w * k.h; i++)
        if (!(k.map[i] >= 0.0)) bad++;
    CHECK(bad == 0, "every E is >= 0 and not NaN (%d are not)", bad);
    /* The map is optional; the match alone gives the same answer. */
    {
        tt_xcorr_match m2;
        CHECK(tt_xcorr_masked(k.tex, k.mask, k.values, NULL, k.work, NULL, &m2, &err) == TT_OK &&
                  m2.x == m.x && m2.y == m.y && m2.e == m.e,
              "without out_map: (%d, %d) E %g", m2.x, m2.y, m2.e);
    }
    /* A validity map that excludes the planted offset: the best allowed one. */
    allowed = (unsigned char *)malloc((size_t)k.w * k.h);
    for (i = 0; i < k.w * k.h; i++) allowed[i] = i % k.w < 32;   /* offsets x < 32 only */
    CHECK(tt_xcorr_masked(k.tex, k.mask, k.values, allowed, k.work, k.map, &m, &err) == TT_OK && m.x < 32 &&
              m.e > 1.0,
          "restricted to x < 32: (%d, %d) with E %g", m.x, m.y, m.e);
    memset(allowed, 0, (size_t)k.w * k.h);
    CHECK(tt_xcorr_masked(k.tex, k.mask, k.values, allowed, k.work, k.map, &m, &err) == TT_ERROR_NOT_MEASURED &&
              m.x == -1 && m.y == -1 && k.map[0] >= 0.0,
          "no offset allowed: TT_ERROR_NOT_MEASURED, match -1 (%s)", err.message);
    free(allowed);
    xc_close(&k);
}

/* Also planted in a bounded image: a zero-padded texture with offsets
   restricted to where the mask stays inside, on a 1-channel 128 x 64. */
static void test_xcorr_planted_bounded(void)
{
    xc_case k;
    int x, y, x0 = 70, y0 = 23, tw = 100, th = 50, bw = 20, bh = 12;
    tt_xcorr_match m;
    tt_error err;
    unsigned char *allowed;
    lcg_seed(4103);
    if (!xc_open(&k, 128, 64, 1)) return;
    for (y = 0; y < k.h; y++)
        for (x = 0; x < k.w; x++)
            if (x >= tw || y >= th) k.t[k.w * y + x] = 0.0;   /* the padding */
    tt_xcorr_texture_free(k.tex);
    CHECK(tt_xcorr_texture_create(k.w, k.h, 1, k.t, NULL, &k.tex, &err) == TT_OK, "%s", err.message);
    if (!k.tex) return;
    for (y = 0; y < bh; y++)
        for (x = 0; x < bw; x++)
            if ((x + y) % 3 != 0) {   /* a ragged mask in the box [0, bw) x [0, bh) */
                k.mask[k.w * y + x] = 1.0;
                k.values[k.w * y + x] = k.t[k.w * (y + y0) + x + x0];
            }
    allowed = (unsigned char *)malloc((size_t)k.w * k.h);
    for (y = 0; y < k.h; y++)
        for (x = 0; x < k.w; x++) allowed[k.w * y + x] = x + bw <= tw && y + bh <= th;
    CHECK(tt_xcorr_masked(k.tex, k.mask, k.values, allowed, k.work, k.map, &m, &err) == TT_OK && m.x == x0 &&
              m.y == y0 && m.e < 1e-9,
          "bounded: planted (%d, %d) found at (%d, %d), E %g", x0, y0, m.x, m.y, m.e);
    free(allowed);
    xc_close(&k);
}

/* |J| = 0: a clear result, no NaN. Ties: the smallest index. */
static void test_xcorr_empty_and_ties(void)
{
    xc_case k;
    tt_xcorr_match m;
    tt_error err;
    int i, bad = 0;
    unsigned char allowed[16 * 8];
    lcg_seed(4104);
    if (!xc_open(&k, 16, 8, 2)) return;
    for (i = 0; i < k.w * k.h; i++) k.map[i] = -7.0;
    CHECK(tt_xcorr_masked(k.tex, k.mask, k.values, NULL, k.work, k.map, &m, &err) == TT_ERROR_NOT_MEASURED &&
              err.result == TT_ERROR_NOT_MEASURED && m.x == -1 && m.y == -1 && m.e == 0.0 && m.mask_sum == 0.0,
          "an all-zero mask: TT_ERROR_NOT_MEASURED (%s), match (%d, %d)", err.message, m.x, m.y);
    for (i = 0; i < k.w * k.h; i++)
        if (k.map[i] != 0.0) bad++;
    CHECK(bad == 0, "an all-zero mask: E = 0 everywhere, no NaN (%d entries are not 0)", bad);
    xc_close(&k);
    /* T = 0 and I = 0: E = 0 exactly at every offset, so the first wins. */
    if (!xc_open(&k, 16, 8, 1)) return;
    memset(k.t, 0, sizeof(double) * 16 * 8);
    tt_xcorr_texture_free(k.tex);
    tt_xcorr_texture_create(16, 8, 1, k.t, NULL, &k.tex, NULL);
    if (!k.tex) return;
    for (i = 0; i < 16 * 8; i++) {
        k.mask[i] = i % 5 == 0;
        k.values[i] = 0.0;
    }
    CHECK(tt_xcorr_masked(k.tex, k.mask, k.values, NULL, k.work, k.map, &m, &err) == TT_OK && m.x == 0 && m.y == 0 &&
              m.e == 0.0,
          "ties everywhere: offset (0, 0), got (%d, %d)", m.x, m.y);
    for (i = 0; i < 16 * 8; i++) allowed[i] = i >= 16 * 3 + 5;
    CHECK(tt_xcorr_masked(k.tex, k.mask, k.values, allowed, k.work, k.map, &m, &err) == TT_OK && m.x == 5 &&
              m.y == 3,
          "ties among the allowed: the first in row-major order (5, 3), got (%d, %d)", m.x, m.y);
    xc_close(&k);
}

static void test_xcorr_errors(void)
{
    xc_case k;
    tt_xcorr_match m;
    tt_error err;
    tt_xcorr_texture *tex = (tt_xcorr_texture *)&tex;
    double t[4] = {1, 2, 3, 4};
    lcg_seed(4105);
    CHECK(tt_xcorr_texture_create(3, 4, 1, t, NULL, &tex, &err) == TT_ERROR_INVALID_ARGUMENT && tex == NULL &&
              strstr(err.message, "4"),
          "width 3 (%s)", err.message);
    CHECK(tt_xcorr_texture_create(2, 2, 0, t, NULL, &tex, &err) == TT_ERROR_INVALID_ARGUMENT, "0 channels (%s)",
          err.message);
    CHECK(tt_xcorr_texture_create(2, 2, 1, NULL, NULL, &tex, &err) == TT_ERROR_INVALID_ARGUMENT, "texture NULL (%s)",
          err.message);
    CHECK(tt_xcorr_texture_create(2, 2, 1, t, NULL, NULL, &err) == TT_ERROR_INVALID_ARGUMENT, "out NULL (%s)",
          err.message);
    t[2] = internal_not_a_number();
    CHECK(tt_xcorr_texture_create(2, 2, 1, t, NULL, &tex, &err) == TT_ERROR_NON_FINITE && err.row == 1 &&
              err.column == 0 && err.item == 0 && tex == NULL,
          "a NaN texel names row 1, column 0 (%s)", err.message);
    t[2] = 1e200;
    CHECK(tt_xcorr_texture_create(2, 2, 1, t, NULL, &tex, &err) == TT_ERROR_NON_FINITE, "a square that overflows (%s)",
          err.message);
    tt_xcorr_texture_free(NULL);
    if (!xc_open(&k, 8, 4, 2)) return;
    k.mask[3] = 1.0;
    CHECK(tt_xcorr_masked(NULL, k.mask, k.values, NULL, k.work, k.map, &m, &err) == TT_ERROR_INVALID_ARGUMENT,
          "texture NULL (%s)", err.message);
    CHECK(tt_xcorr_masked(k.tex, NULL, k.values, NULL, k.work, k.map, &m, &err) == TT_ERROR_INVALID_ARGUMENT,
          "mask NULL (%s)", err.message);
    CHECK(tt_xcorr_masked(k.tex, k.mask, NULL, NULL, k.work, k.map, &m, &err) == TT_ERROR_INVALID_ARGUMENT,
          "values NULL (%s)", err.message);
    CHECK(tt_xcorr_masked(k.tex, k.mask, k.values, NULL, NULL, k.map, &m, &err) == TT_ERROR_INVALID_ARGUMENT,
          "work NULL (%s)", err.message);
    CHECK(tt_xcorr_masked(k.tex, k.mask, k.values, NULL, k.work, NULL, NULL, &err) == TT_ERROR_INVALID_ARGUMENT,
          "both outputs NULL (%s)", err.message);
    k.mask[8 * 2 + 5] = -0.5;
    CHECK(tt_xcorr_masked(k.tex, k.mask, k.values, NULL, k.work, k.map, &m, &err) == TT_ERROR_INVALID_ARGUMENT &&
              err.row == 2 && err.column == 5,
          "a negative weight at row 2, column 5 (%s)", err.message);
    k.mask[8 * 2 + 5] = internal_not_a_number();
    CHECK(tt_xcorr_masked(k.tex, k.mask, k.values, NULL, k.work, k.map, &m, &err) == TT_ERROR_NON_FINITE &&
              err.row == 2 && err.column == 5,
          "a NaN weight (%s)", err.message);
    k.mask[8 * 2 + 5] = 0.0;
    k.values[32 + 3] = (double)internal_infinity();   /* channel 1, row 0, column 3: under the mask */
    CHECK(tt_xcorr_masked(k.tex, k.mask, k.values, NULL, k.work, k.map, &m, &err) == TT_ERROR_NON_FINITE &&
              err.item == 1 && err.row == 0 && err.column == 3,
          "an infinite value under the mask names channel 1 (%s)", err.message);
    k.values[32 + 3] = 0.5;
    k.values[32 + 4] = internal_not_a_number();   /* off the mask: ignored */
    CHECK(tt_xcorr_masked(k.tex, k.mask, k.values, NULL, k.work, k.map, &m, &err) == TT_OK && m.e >= 0.0,
          "a NaN off the mask is ignored (%s)", err.message);
    k.values[3] = 1e200;
    CHECK(tt_xcorr_masked(k.tex, k.mask, k.values, NULL, k.work, k.map, &m, &err) == TT_ERROR_NON_FINITE,
          "values whose squares overflow (%s)", err.message);
    xc_close(&k);
    /* Inputs that pass every check but whose spectra's products overflow
       (J = 1e300 against T^2 = 1e300): an error, never E = 0 from a NaN
       clamped away. */
    {
        double big[8 * 4], wmask[8 * 4], small[8 * 4], work[2 * 5 * 4 * 2], map[8 * 4];
        int i;
        for (i = 0; i < 32; i++) {
            big[i] = 1e150;
            wmask[i] = i == 3 ? 1e300 : 0.0;
            small[i] = 1e-100;
        }
        tex = NULL;
        CHECK(tt_xcorr_texture_create(8, 4, 1, big, NULL, &tex, &err) == TT_OK && tex && tex->work_size <= 80,
              "a texture of 1e150 (%s)", err.message);
        if (!tex) return;
        CHECK(tt_xcorr_masked(tex, wmask, small, NULL, work, map, &m, &err) == TT_ERROR_NON_FINITE,
              "spectra whose products overflow: TT_ERROR_NON_FINITE (%s)", err.message);
        tt_xcorr_texture_free(tex);
    }
}

/* ------------------------------------------------------------------------ */
/* tt_xcorr_masked_best: several cached textures at once                    */
/* ------------------------------------------------------------------------ */

#define XB_MAX 6

/* ntextures textures of one size (random, or copies of `copy_of` when it is
   not NULL), made through a counting allocator, so a test can see that
   correlating against them allocates nothing; a mask, values, work space
   for both functions. */
typedef struct xb_set {
    int w, h, channels, n;
    double *t[XB_MAX], *mask, *values, *work;
    tt_xcorr_texture *tex[XB_MAX];
    counter cnt;
    tt_allocator al;
} xb_set;

static int xb_open(xb_set *s, int w, int h, int channels, int n, const double *copy_of)
{
    size_t count = (size_t)w * h * channels, need;
    tt_error err;
    int k, ok = 1;
    memset(s, 0, sizeof *s);
    s->w = w;
    s->h = h;
    s->channels = channels;
    s->n = n;
    s->al = make_allocator(&s->cnt, -1);
    for (k = 0; k < n; k++) {
        s->t[k] = fft_random(count);
        if (copy_of) memcpy(s->t[k], copy_of, sizeof(double) * count);
        if (tt_xcorr_texture_create(w, h, channels, s->t[k], &s->al, &s->tex[k], &err) != TT_OK) ok = 0;
    }
    CHECK(ok, "%d textures %d x %d x %d: %s", n, w, h, channels, ok ? "" : err.message);
    if (!ok) return 0;
    s->mask = (double *)calloc((size_t)w * h, sizeof(double));
    s->values = fft_random(count);
    need = s->tex[0]->best_work_size > s->tex[0]->work_size ? s->tex[0]->best_work_size : s->tex[0]->work_size;
    s->work = (double *)malloc(sizeof(double) * need);
    return 1;
}

static void xb_close(xb_set *s)
{
    int k;
    for (k = 0; k < s->n; k++) {
        tt_xcorr_texture_free(s->tex[k]);
        free(s->t[k]);
    }
    CHECK(s->cnt.live == 0 && s->cnt.bad_frees == 0, "the textures freed all they held (%ld live)", s->cnt.live);
    free(s->mask);
    free(s->values);
    free(s->work);
}

/* The reference: tt_xcorr_masked per texture, the smallest E kept, an
   earlier texture kept on an exact tie. Returns TT_OK, NOT_MEASURED when
   no texture gave a match, or the first other error. */
static tt_result xb_reference(xb_set *s, const unsigned char *const *allowed, tt_xcorr_match *best, int *best_k)
{
    int k, found = 0;
    *best_k = -1;
    for (k = 0; k < s->n; k++) {
        tt_xcorr_match m;
        tt_result r = tt_xcorr_masked(s->tex[k], s->mask, s->values, allowed ? allowed[k] : NULL, s->work, NULL, &m,
                                      NULL);
        if (r == TT_ERROR_NOT_MEASURED) continue;
        if (r != TT_OK) return r;
        if (!found || m.e < best->e) {
            *best = m;
            *best_k = k;
            found = 1;
        }
    }
    return found ? TT_OK : TT_ERROR_NOT_MEASURED;
}

/* Runs both and compares them bit for bit; returns 1 when they agree. */
static int xb_agree(xb_set *s, const unsigned char *const *allowed, const char *what)
{
    tt_xcorr_match want, got;
    int want_k, got_k;
    tt_error err;
    tt_result r_want;
    memset(&want, 0, sizeof want);
    memset(&got, 0, sizeof got);
    r_want = xb_reference(s, allowed, &want, &want_k);
    tt_result r_got;
    long calls = s->cnt.calls;
    r_got = tt_xcorr_masked_best((const tt_xcorr_texture *const *)s->tex, s->n, s->mask, s->values, allowed, s->work,
                                 &got, &got_k, &err);
    if (s->cnt.calls != calls) {
        DETAIL("%s: %ld allocations", what, s->cnt.calls - calls);
        return 0;
    }
    if (r_got != r_want || got_k != want_k ||
        (r_got == TT_OK && (got.x != want.x || got.y != want.y || got.e != want.e || got.mask_sum != want.mask_sum ||
                            got.masked_energy != want.masked_energy))) {
        DETAIL("%s: %d x %d x %d, %d textures: best %d texture %d (%d, %d) E %.17g; reference %d texture %d (%d, %d) "
               "E %.17g (%s)",
               what, s->w, s->h, s->channels, s->n, r_got, got_k, got.x, got.y, got.e, r_want, want_k, want.x,
               want.y, want.e, err.message);
        return 0;
    }
    return 1;
}

/* Random textures, masks and allowed maps, square and not, 1 and 3
   channels: the same answer as tt_xcorr_masked texture by texture, bit for
   bit, and E there is the direct masked sum. */
static void test_xcorr_best_reference(void)
{
    static const int sizes[][4] = {{32, 16, 3, 5}, {16, 32, 1, 4}, {32, 32, 3, 3}, {8, 4, 1, 6}, {64, 8, 3, 1}};
    int si, trial, cases = 0, bad = 0, bad_direct = 0;
    lcg_seed(4107);
    for (si = 0; si < (int)(sizeof sizes / sizeof sizes[0]); si++)
        for (trial = 0; trial < 6; trial++) {
            xb_set s;
            unsigned char *maps;
            const unsigned char *allowed[XB_MAX];
            int i, k, plane, soft = trial % 2, mode = trial / 2;
            char what[96];
            if (!xb_open(&s, sizes[si][0], sizes[si][1], sizes[si][2], sizes[si][3], NULL)) return;
            plane = s.w * s.h;
            maps = (unsigned char *)malloc((size_t)plane * s.n);
            for (i = 0; i < plane; i++)
                s.mask[i] = lcg_below(3) == 0 ? (soft ? lcg_unit() : 1.0) : 0.0;
            s.mask[lcg_below(plane)] = 1.0;   /* never all zero */
            /* mode 0: no allowed maps; 1: random ones, some textures free;
               2: sparse random ones, texture 0's all zero. */
            for (k = 0; k < s.n; k++) {
                for (i = 0; i < plane; i++) maps[plane * k + i] = (unsigned char)(lcg_below(mode == 2 ? 10 : 2) == 0);
                if (mode == 2 && k == 0) memset(maps, 0, (size_t)plane);
                allowed[k] = mode == 1 && k % 2 == 1 ? NULL : maps + plane * k;
            }
            sprintf(what, "size %d, trial %d", si, trial);
            if (!xb_agree(&s, mode == 0 ? NULL : allowed, what)) bad++;
            cases++;
            {
                tt_xcorr_match m;
                int best_k, only_texture_excluded = s.n == 1 && mode == 2;
                double direct;
                tt_result r = tt_xcorr_masked_best((const tt_xcorr_texture *const *)s.tex, s.n, s.mask, s.values,
                                                   mode == 0 ? NULL : allowed, s.work, &m, &best_k, NULL);
                if (r == TT_OK) {
                    direct = xc_direct(s.t[best_k], s.mask, s.values, s.w, s.h, s.channels, m.x, m.y);
                    if (!(fabs(m.e - direct) <= 1e-12 * direct) && bad_direct++ == 0)
                        DETAIL("%s: E %.17g, direct %.17g", what, m.e, direct);
                } else if (!(only_texture_excluded && r == TT_ERROR_NOT_MEASURED) && bad_direct++ == 0)
                    DETAIL("%s: no match (%d)", what, r);
            }
            free(maps);
            xb_close(&s);
        }
    CHECK(bad == 0, "tt_xcorr_masked_best equals tt_xcorr_masked per texture, bit for bit, in %d of %d cases",
          cases - bad, cases);
    CHECK(bad_direct == 0, "E of the best match equals the direct masked sum within 1e-12 (%d do not)", bad_direct);
}

/* Exact ties across textures: the smallest (texture, y, x) wins. */
static void test_xcorr_best_ties(void)
{
    xb_set s;
    tt_xcorr_match m, one;
    tt_error err;
    int k = -7, i, plane;
    unsigned char *maps;
    const unsigned char *allowed[3];
    lcg_seed(4108);
    {
        double *same = fft_random(32 * 16 * 3);
        int ok = xb_open(&s, 32, 16, 3, 3, same);
        free(same);
        if (!ok) return;
    }
    plane = s.w * s.h;
    for (i = 0; i < plane; i++) s.mask[i] = lcg_below(4) == 0 ? 1.0 : 0.0;
    CHECK(tt_xcorr_masked_best((const tt_xcorr_texture *const *)s.tex, 3, s.mask, s.values, NULL, s.work, &m, &k,
                               &err) == TT_OK && k == 0,
          "three identical textures: texture 0 wins the tie (got %d: %s)", k, err.message);
    CHECK(tt_xcorr_masked(s.tex[0], s.mask, s.values, NULL, s.work, NULL, &one, &err) == TT_OK && one.x == m.x &&
              one.y == m.y && one.e == m.e,
          "at texture 0's own best (%d, %d), E %.17g (alone: (%d, %d), %.17g)", m.x, m.y, m.e, one.x, one.y, one.e);
    maps = (unsigned char *)malloc((size_t)plane * 3);
    memset(maps, 0, (size_t)plane * 3);
    allowed[0] = maps;   /* texture 0: nothing allowed */
    allowed[1] = NULL;
    allowed[2] = NULL;
    CHECK(tt_xcorr_masked_best((const tt_xcorr_texture *const *)s.tex, 3, s.mask, s.values, allowed, s.work, &m, &k,
                               &err) == TT_OK && k == 1 && m.x == one.x && m.y == one.y && m.e == one.e,
          "identical copies, the first excluded: texture 1 wins (got %d at (%d, %d))", k, m.x, m.y);
    memset(maps, 1, (size_t)plane);
    maps[s.w * one.y + one.x] = 0;   /* texture 0: all but its best offset */
    CHECK(tt_xcorr_masked_best((const tt_xcorr_texture *const *)s.tex, 3, s.mask, s.values, allowed, s.work, &m, &k,
                               &err) == TT_OK && k == 1 && m.x == one.x && m.y == one.y,
          "texture 0 without its best offset: texture 1 at (%d, %d) (got %d at (%d, %d))", one.x, one.y, k, m.x, m.y);
    xb_close(&s);
    free(maps);
    /* T = 0 and I = 0: E = 0 at every offset of every texture. Texture 0
       allows only (5, 3), texture 1 every offset: (texture 0, 5, 3) comes
       first in (texture, y, x) order, although texture 1 has (0, 0). */
    {
        double *zero = (double *)calloc(16 * 8, sizeof(double));
        int ok = xb_open(&s, 16, 8, 1, 2, zero);
        free(zero);
        if (!ok) return;
    }
    maps = (unsigned char *)calloc(16 * 8, 1);
    maps[16 * 3 + 5] = 1;
    allowed[0] = maps;
    allowed[1] = NULL;
    for (i = 0; i < 16 * 8; i++) {
        s.mask[i] = i % 5 == 0;
        s.values[i] = 0.0;
    }
    CHECK(tt_xcorr_masked_best((const tt_xcorr_texture *const *)s.tex, 2, s.mask, s.values, allowed, s.work, &m, &k,
                               &err) == TT_OK && k == 0 && m.x == 5 && m.y == 3 && m.e == 0.0,
          "E = 0 everywhere: texture 0 at (5, 3) (got %d at (%d, %d), E %g)", k, m.x, m.y, m.e);
    allowed[0] = NULL;
    CHECK(tt_xcorr_masked_best((const tt_xcorr_texture *const *)s.tex, 2, s.mask, s.values, allowed, s.work, &m, &k,
                               &err) == TT_OK && k == 0 && m.x == 0 && m.y == 0,
          "E = 0 everywhere, all allowed: texture 0 at (0, 0) (got %d at (%d, %d))", k, m.x, m.y);
    free(maps);
    xb_close(&s);
}

/* A crop of texture k at (x0, y0) under a ring-shaped mask that wraps the
   border: texture k, that offset, E about 0. 3 channels and 1. */
static void test_xcorr_best_planted(void)
{
    static const int cases[][6] = {/* w, h, channels, n, k, x0 */ {64, 32, 3, 5, 3, 41}, {32, 64, 1, 4, 0, 9},
                                   {32, 32, 3, 2, 1, 30}};
    int ci;
    lcg_seed(4109);
    for (ci = 0; ci < 3; ci++) {
        xb_set s;
        tt_xcorr_match m;
        tt_error err;
        int w = cases[ci][0], h = cases[ci][1], k = cases[ci][4], x0 = cases[ci][5], y0 = h - 5, best_k = -1;
        int x, y, c;
        size_t plane = (size_t)w * h;
        if (!xb_open(&s, w, h, cases[ci][2], cases[ci][3], NULL)) return;
        for (y = 0; y < h; y++)
            for (x = 0; x < w; x++) {
                /* A ring of radii 4 and 9 around (2, 1): crosses both borders. */
                double dx = (double)((x + w / 2 - 2) % w) - w / 2, dy = (double)((y + h / 2 - 1) % h) - h / 2;
                double r2 = dx * dx + dy * dy;
                s.mask[w * y + x] = r2 >= 16.0 && r2 <= 81.0 ? 1.0 : 0.0;
                for (c = 0; c < s.channels; c++)
                    s.values[plane * c + (size_t)w * y + x] =
                        s.mask[w * y + x] != 0.0 ? s.t[k][plane * c + (size_t)w * ((y + y0) % h) + (x + x0) % w]
                                                 : internal_not_a_number();   /* never read */
            }
        CHECK(tt_xcorr_masked_best((const tt_xcorr_texture *const *)s.tex, s.n, s.mask, s.values, NULL, s.work, &m,
                                   &best_k, &err) == TT_OK &&
                  best_k == k && m.x == x0 && m.y == y0 && m.e < 1e-9 && m.mask_sum > 100.0,
              "%d x %d x %d: the crop of texture %d at (%d, %d) found: texture %d at (%d, %d), E %g (%s)", w, h,
              s.channels, k, x0, y0, best_k, m.x, m.y, m.e, err.message);
        xb_close(&s);
    }
}

static void test_xcorr_best_errors(void)
{
    xb_set s, other;
    tt_xcorr_match m;
    tt_error err;
    int k, i;
    long calls;
    const tt_xcorr_texture *tex[3];
    unsigned char zero[8 * 4];
    const unsigned char *allowed[3];
    lcg_seed(4110);
    if (!xb_open(&s, 8, 4, 2, 3, NULL)) return;
    for (i = 0; i < 3; i++) tex[i] = s.tex[i];
    s.mask[3] = 1.0;
    calls = s.cnt.calls;
#define XB_CALL(textures, n, mask, values, allowed_, work, out, which) \
    (k = 7, m.x = 7, tt_xcorr_masked_best(textures, n, mask, values, allowed_, work, out, which, &err))
#define XB_UNSET (k == -1 && m.x == -1 && m.y == -1)
    CHECK(XB_CALL(tex, 3, s.mask, s.values, NULL, s.work, &m, &k) == TT_OK && err.result == TT_OK && k >= 0,
          "the valid call (%s)", err.message);
    CHECK(XB_CALL(NULL, 3, s.mask, s.values, NULL, s.work, &m, &k) == TT_ERROR_INVALID_ARGUMENT && XB_UNSET &&
              strstr(err.message, "textures"),
          "textures NULL (%s)", err.message);
    CHECK(XB_CALL(tex, 3, NULL, s.values, NULL, s.work, &m, &k) == TT_ERROR_INVALID_ARGUMENT && XB_UNSET &&
              strstr(err.message, "mask"),
          "mask NULL (%s)", err.message);
    CHECK(XB_CALL(tex, 3, s.mask, NULL, NULL, s.work, &m, &k) == TT_ERROR_INVALID_ARGUMENT && XB_UNSET &&
              strstr(err.message, "values is NULL"),
          "values NULL (%s)", err.message);
    CHECK(XB_CALL(tex, 3, s.mask, s.values, NULL, NULL, &m, &k) == TT_ERROR_INVALID_ARGUMENT && XB_UNSET &&
              strstr(err.message, "work is NULL"),
          "work NULL (%s)", err.message);
    CHECK(XB_CALL(tex, 3, s.mask, s.values, NULL, s.work, NULL, &k) == TT_ERROR_INVALID_ARGUMENT && k == -1 &&
              strstr(err.message, "out_match is NULL"),
          "out_match NULL (%s)", err.message);
    CHECK(XB_CALL(tex, 3, s.mask, s.values, NULL, s.work, &m, NULL) == TT_ERROR_INVALID_ARGUMENT && m.x == -1 &&
              strstr(err.message, "out_texture is NULL"),
          "out_texture NULL (%s)", err.message);
    CHECK(XB_CALL(tex, 0, s.mask, s.values, NULL, s.work, &m, &k) == TT_ERROR_INVALID_ARGUMENT && XB_UNSET &&
              msg_has_number(err.message, 0),
          "no textures (%s)", err.message);
    CHECK(XB_CALL(tex, -2, s.mask, s.values, NULL, s.work, &m, &k) == TT_ERROR_INVALID_ARGUMENT && XB_UNSET,
          "-2 textures (%s)", err.message);
    tex[1] = NULL;
    CHECK(XB_CALL(tex, 3, s.mask, s.values, NULL, s.work, &m, &k) == TT_ERROR_INVALID_ARGUMENT && XB_UNSET &&
              err.item == 1,
          "texture 1 NULL names item 1 (%s)", err.message);
    tex[1] = s.tex[1];
    /* Textures unlike texture 0: another size, another channel count. */
    if (!xb_open(&other, 8, 8, 2, 1, NULL)) return;
    tex[2] = other.tex[0];
    CHECK(XB_CALL(tex, 3, s.mask, s.values, NULL, s.work, &m, &k) == TT_ERROR_INVALID_ARGUMENT && XB_UNSET &&
              err.item == 2 && msg_has_number(err.message, 2),
          "texture 2 of another height (%s)", err.message);
    xb_close(&other);
    if (!xb_open(&other, 8, 4, 3, 1, NULL)) return;
    tex[1] = other.tex[0];
    tex[2] = other.tex[0];
    CHECK(XB_CALL(tex, 3, s.mask, s.values, NULL, s.work, &m, &k) == TT_ERROR_INVALID_ARGUMENT && XB_UNSET &&
              err.item == 1,
          "textures 1 and 2 of 3 channels: texture 1 is named (%s)", err.message);
    xb_close(&other);
    tex[1] = s.tex[1];
    tex[2] = s.tex[2];
    /* The mask and the values: as tt_xcorr_masked. */
    s.mask[8 * 2 + 5] = -0.5;
    CHECK(XB_CALL(tex, 3, s.mask, s.values, NULL, s.work, &m, &k) == TT_ERROR_INVALID_ARGUMENT && XB_UNSET &&
              err.row == 2 && err.column == 5,
          "a negative weight at row 2, column 5 (%s)", err.message);
    s.mask[8 * 2 + 5] = internal_not_a_number();
    CHECK(XB_CALL(tex, 3, s.mask, s.values, NULL, s.work, &m, &k) == TT_ERROR_NON_FINITE && XB_UNSET &&
              err.row == 2 && err.column == 5,
          "a NaN weight (%s)", err.message);
    s.mask[8 * 2 + 5] = 0.0;
    s.values[32 + 3] = (double)internal_infinity();   /* channel 1, row 0, column 3: under the mask */
    CHECK(XB_CALL(tex, 3, s.mask, s.values, NULL, s.work, &m, &k) == TT_ERROR_NON_FINITE && XB_UNSET &&
              err.item == 1 && err.row == 0 && err.column == 3,
          "an infinite value under the mask names channel 1 (%s)", err.message);
    s.values[32 + 3] = 0.5;
    /* Nothing to measure. */
    memset(zero, 0, sizeof zero);
    allowed[0] = allowed[1] = allowed[2] = zero;
    CHECK(XB_CALL(tex, 3, s.mask, s.values, allowed, s.work, &m, &k) == TT_ERROR_NOT_MEASURED && XB_UNSET &&
              m.e == 0.0 && m.mask_sum == 1.0 && err.result == TT_ERROR_NOT_MEASURED,
          "no offset of any texture allowed: TT_ERROR_NOT_MEASURED (%s)", err.message);
    s.mask[3] = 0.0;
    CHECK(XB_CALL(tex, 3, s.mask, s.values, NULL, s.work, &m, &k) == TT_ERROR_NOT_MEASURED && XB_UNSET &&
              m.e == 0.0 && m.mask_sum == 0.0 && m.masked_energy == 0.0,
          "an all-zero mask: TT_ERROR_NOT_MEASURED, match {-1, -1, 0, 0, 0} (%s)", err.message);
    CHECK(s.cnt.calls == calls, "no call allocated (%ld allocations)", s.cnt.calls - calls);
    xb_close(&s);
    /* Spectra whose products overflow, for texture 1 only (J = 1e300 against
       T^2 = 1e300): TT_ERROR_NON_FINITE naming it, never E = 0 from a NaN
       clamped away. */
    {
        double big[8 * 4], wmask[8 * 4], small[8 * 4], work[3 * 2 * 5 * 4];   /* (channels + 2) half spectra of 2 (8 / 2 + 1) x 4 doubles */
        tt_xcorr_texture *pair[2] = {NULL, NULL};
        for (i = 0; i < 32; i++) {
            big[i] = 1e150;
            wmask[i] = i == 3 ? 1e300 : 0.0;
            small[i] = 1e-100;
        }
        CHECK(tt_xcorr_texture_create(8, 4, 1, small, NULL, &pair[0], &err) == TT_OK &&
                  tt_xcorr_texture_create(8, 4, 1, big, NULL, &pair[1], &err) == TT_OK &&
                  pair[1]->best_work_size <= 3 * 2 * 5 * 4,
              "textures of 1e-100 and 1e150 (%s)", err.message);
        if (pair[0] && pair[1])
            CHECK(XB_CALL((const tt_xcorr_texture *const *)pair, 2, wmask, small, NULL, work, &m, &k) ==
                          TT_ERROR_NON_FINITE &&
                      XB_UNSET && err.item == 1,
                  "spectra whose products overflow with texture 1: TT_ERROR_NON_FINITE naming it (%s)", err.message);
        tt_xcorr_texture_free(pair[0]);
        tt_xcorr_texture_free(pair[1]);
    }
#undef XB_CALL
#undef XB_UNSET
}

typedef struct fft_oom_ctx {
    int w, h, channels;
    const double *t;
} fft_oom_ctx;

static tt_result fft_oom_plan(void *ctx, const tt_allocator *al, tt_error *error)
{
    fft_oom_ctx *c = (fft_oom_ctx *)ctx;
    tt_fft_plan *plan = (tt_fft_plan *)&plan;
    tt_result r = tt_fft_plan_create(c->w, c->h, al, &plan, error);
    if (r == TT_OK) tt_fft_plan_free(plan);
    else if (plan != NULL || error->result != r) return TT_RESULT_MAX_ENUM;
    return r;
}

static tt_result fft_oom_texture(void *ctx, const tt_allocator *al, tt_error *error)
{
    fft_oom_ctx *c = (fft_oom_ctx *)ctx;
    tt_xcorr_texture *tex = (tt_xcorr_texture *)&tex;
    tt_result r = tt_xcorr_texture_create(c->w, c->h, c->channels, c->t, al, &tex, error);
    if (r == TT_OK) tt_xcorr_texture_free(tex);
    else if (tex != NULL || error->result != r) return TT_RESULT_MAX_ENUM;
    return r;
}

static void test_fft_oom(void)
{
    fft_oom_ctx c;
    double *t;
    lcg_seed(4106);
    t = fft_random(3 * 32 * 16);
    c.w = 32;
    c.h = 16;
    c.channels = 3;
    c.t = t;
    oom_reset();
    oom_sweep("tt_fft_plan_create(32 x 16)", fft_oom_plan, &c, TT_OK);
    c.w = c.h = 1;
    oom_sweep("tt_fft_plan_create(1 x 1)", fft_oom_plan, &c, TT_OK);
    c.w = 32;
    c.h = 16;
    oom_sweep("tt_xcorr_texture_create(32 x 16 x 3)", fft_oom_texture, &c, TT_OK);
    free(t);
}

void run_fft_tests(void)
{
    RUN(test_fft_naive_1d);
    RUN(test_fft_naive_2d);
    RUN(test_fft_identities);
    RUN(test_fft_strips);
    RUN(test_fft_real);
    RUN(test_fft_plan_read_only);
    RUN(test_fft_errors);
    RUN(test_xcorr_direct);
    RUN(test_xcorr_direct_sums);
    RUN(test_xcorr_planted);
    RUN(test_xcorr_planted_bounded);
    RUN(test_xcorr_empty_and_ties);
    RUN(test_xcorr_errors);
    RUN(test_xcorr_best_reference);
    RUN(test_xcorr_best_ties);
    RUN(test_xcorr_best_planted);
    RUN(test_xcorr_best_errors);
    RUN(test_fft_oom);
}
