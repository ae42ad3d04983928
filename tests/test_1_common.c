/* tests/test_1_common.c - unit tests for section 1 of tiledtex.h: results,
   errors, allocators and the RNG. Run by run_common_tests()
   (tests/test_common.c calls it). */
#include "test_common.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ------------------------------------------------------------------------ */
/* 1. Common (results, errors, allocators, RNG)                             */
/* ------------------------------------------------------------------------ */

static int median_compare(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

/* tt__median (a selection, with a heapsort when the pivots keep missing)
   against the middle of a sorted copy: random values, many repeats, sorted,
   reversed, all equal and an organ pipe (patterns that defeat naive
   pivots), odd and even counts from 1 to 3001. */
static void test_median(void)
{
    int pattern, n, i, bad = 0, checked = 0;
    for (pattern = 0; pattern < 6; pattern++)
        for (n = 1; n <= 3001; n = n < 20 ? n + 1 : 2 * n + 1) {
            double *v = (double *)malloc(sizeof(double) * (size_t)n), *sorted, want, got;
            sorted = (double *)malloc(sizeof(double) * (size_t)n);
            lcg_seed(17u + (unsigned)n);
            hostile_order(v, n, pattern);
            for (i = 0; i < n; i++) sorted[i] = v[i];
            qsort(sorted, (size_t)n, sizeof(double), median_compare);
            want = n % 2 ? sorted[n / 2] : 0.5 * (sorted[n / 2 - 1] + sorted[n / 2]);
            got = internal_median(v, n);
            bad += got != want;
            checked++;
            free(v);
            free(sorted);
        }
    CHECK(bad == 0, "median: %d of %d arrays off the sorted middle", bad, checked);
    CHECK(internal_median(NULL, 0) == 0.0, "median of nothing is 0");
}

static void test_rng(void)
{
    /* The reference PCG32 demo (pcg32_srandom_r(&rng, 42u, 54u)) prints these. */
    static const uint32_t golden[6] = {0xa15c02b7u, 0x7b47f409u, 0xba1d3330u, 0x83d2f293u, 0xbfa4784bu, 0xcbed606eu};
    tt_rng a, b, c;
    int i, same = 1, differ = 0, below_bad = 0, float_bad = 0;
    uint32_t got;
    tt_rng_seed(&a, 42, 54);
    for (i = 0; i < 6; i++) {
        got = tt_rng_next(&a);
        CHECK(got == golden[i], "value %d of seed 42 stream 54: expected 0x%08x, got 0x%08x", i,
              (unsigned)golden[i], (unsigned)got);
    }
    tt_rng_seed(&a, 12345, 7);
    tt_rng_seed(&b, 12345, 7);
    tt_rng_seed(&c, 12345, 8);
    for (i = 0; i < 1000; i++) {
        uint32_t x = tt_rng_next(&a), y = tt_rng_next(&b), z = tt_rng_next(&c);
        if (x != y) same = 0;
        if (x != z) differ++;
    }
    CHECK(same, "same seed and stream should give the same sequence");
    CHECK(differ > 990, "streams 7 and 8 should differ almost everywhere, %d of 1000 differ", differ);
    tt_rng_seed(&a, 1, 7);
    tt_rng_seed(&b, 2, 7);
    differ = 0;
    for (i = 0; i < 1000; i++) differ += tt_rng_next(&a) != tt_rng_next(&b);
    CHECK(differ > 990, "seeds 1 and 2 should differ almost everywhere, %d of 1000 differ", differ);

    /* tt_rng_below: range, and chi-square for a few bounds. */
    {
        static const uint32_t bounds[] = {1, 2, 3, 7, 10, 100, 1000};
        int bi;
        for (bi = 0; bi < (int)(sizeof bounds / sizeof bounds[0]); bi++) {
            uint32_t bound = bounds[bi];
            long counts[1000];
            long n = 200 * (long)bound;
            double chi2 = 0.0, expected = 200.0, limit;
            long k;
            memset(counts, 0, sizeof counts);
            tt_rng_seed(&a, 99 + bi, 3);
            for (k = 0; k < n; k++) {
                uint32_t r = tt_rng_below(&a, bound);
                if (r >= bound) below_bad++;
                else counts[r]++;
            }
            for (k = 0; k < (long)bound; k++) chi2 += (counts[k] - expected) * (counts[k] - expected) / expected;
            /* dof = bound-1; mean dof, sd sqrt(2 dof): allow mean + 6 sd + 10. */
            limit = (bound - 1) + 6.0 * sqrt(2.0 * (bound - 1)) + 10.0;
            CHECK(chi2 <= limit, "tt_rng_below(%u): chi-square %.1f exceeds %.1f", (unsigned)bound, chi2, limit);
        }
        CHECK(below_bad == 0, "tt_rng_below returned a value >= bound %d times", below_bad);
        CHECK(tt_rng_below(&a, 0) == 0, "tt_rng_below(0) should be 0");
        /* A bound near 2^32 still in range. */
        below_bad = 0;
        for (i = 0; i < 1000; i++) if (tt_rng_below(&a, 0xfffffff0u) >= 0xfffffff0u) below_bad++;
        CHECK(below_bad == 0, "tt_rng_below(0xfffffff0) out of range %d times", below_bad);
    }
    /* tt_rng_float in [0,1), mean about 1/2, buckets roughly even. */
    {
        double sum = 0.0, chi2 = 0.0;
        long buckets[16];
        int n = 64000;
        memset(buckets, 0, sizeof buckets);
        tt_rng_seed(&a, 5, 5);
        for (i = 0; i < n; i++) {
            float f = tt_rng_float(&a);
            if (!(f >= 0.0f && f < 1.0f)) float_bad++;
            else buckets[(int)(f * 16.0f)]++;
            sum += f;
        }
        for (i = 0; i < 16; i++) chi2 += (buckets[i] - n / 16.0) * (buckets[i] - n / 16.0) / (n / 16.0);
        CHECK(float_bad == 0, "tt_rng_float outside [0,1) %d times", float_bad);
        CHECK(near(sum / n, 0.5, 0.01), "tt_rng_float mean: expected 0.5, got %f", sum / n);
        CHECK(chi2 < 60.0, "tt_rng_float buckets: chi-square %.1f for 15 dof", chi2);
        /* The largest output is below 1 (24-bit grid). */
        a.state = 0; a.increment = 1;
        {
            float f = tt_rng_float(&a);   /* any value: only its range matters */
            CHECK(f >= 0.0f && f < 1.0f, "tt_rng_float out of range: %f", f);
        }
    }
}

static void test_version(void)
{
    int major = -1, minor = -1, patch = -1;
    const char *v = tt_version(&major, &minor, &patch);
    char expect[32];
    CHECK(v != NULL && strcmp(v, TILEDTEX_VERSION_STRING) == 0, "tt_version: expected \"%s\", got \"%s\"",
          TILEDTEX_VERSION_STRING, v ? v : "(null)");
    CHECK(major == TILEDTEX_VERSION_MAJOR && minor == TILEDTEX_VERSION_MINOR && patch == TILEDTEX_VERSION_PATCH,
          "tt_version numbers: expected %d.%d.%d, got %d.%d.%d", TILEDTEX_VERSION_MAJOR, TILEDTEX_VERSION_MINOR,
          TILEDTEX_VERSION_PATCH, major, minor, patch);
    sprintf(expect, "%d.%d.%d", TILEDTEX_VERSION_MAJOR, TILEDTEX_VERSION_MINOR, TILEDTEX_VERSION_PATCH);
    CHECK(strcmp(expect, TILEDTEX_VERSION_STRING) == 0 && strcmp(TILEDTEX_VERSION_STRING, "0.3.0") == 0,
          "TILEDTEX_VERSION_STRING \"%s\" should be the numbers \"%s\" (0.3.0)", TILEDTEX_VERSION_STRING, expect);
    /* Each pointer may be NULL. */
    major = -1;
    CHECK(tt_version(NULL, NULL, NULL) == v && tt_version(&major, NULL, NULL) == v && major == TILEDTEX_VERSION_MAJOR,
          "tt_version with NULL pointers");
}

static void test_result_strings(void)
{
    /* Every code from TT_OK down to the last one, TT_ERROR_NOT_FLAT. */
    const char *s[20];
    const char *unknown = tt_result_string((tt_result)-99);
    int i, j, empty = 0, same = 0, generic = 0;
    CHECK(TT_ERROR_NOT_FLAT == -19, "TT_ERROR_NOT_FLAT is the last code, -19 (got %d)", (int)TT_ERROR_NOT_FLAT);
    for (i = 0; i < 20; i++) {
        s[i] = tt_result_string((tt_result)-i);
        if (!s[i] || !s[i][0]) { empty++; continue; }
        if (strcmp(s[i], unknown) == 0) {
            if (!generic) DETAIL("result %d has the sentence for unknown codes: \"%s\"", -i, s[i]);
            generic++;
        }
    }
    CHECK(empty == 0, "%d result codes have an empty or NULL sentence", empty);
    CHECK(generic == 0, "%d result codes have no sentence of their own", generic);
    for (i = 0; i < 20; i++)
        for (j = i + 1; j < 20; j++)
            if (s[i] && s[j] && strcmp(s[i], s[j]) == 0) {
                if (!same) DETAIL("results %d and %d share the sentence \"%s\"", -i, -j, s[i]);
                same++;
            }
    CHECK(same == 0, "%d pairs of result codes share a sentence", same);
    CHECK(s[19] && strcmp(s[19], tt_result_string(TT_ERROR_NOT_FLAT)) == 0 && strlen(s[19]) > 5,
          "TT_ERROR_NOT_FLAT: \"%s\"", s[19] ? s[19] : "(null)");
    CHECK(unknown && unknown[0] && tt_result_string(TT_RESULT_MAX_ENUM) && tt_result_string((tt_result)1),
          "unknown codes still get a sentence");
}

/* An allocator with only one of its two functions is refused, with a
   message, by every allocating function; a NULL allocator means malloc. */
static void *only_alloc(size_t size, void *user_data)
{
    (void)user_data;
    return malloc(size);
}
static void only_free(void *ptr, void *user_data)
{
    (void)user_data;
    free(ptr);
}

static int bad_allocator_refused(tt_result r, const tt_error *err, const char *what, const char *which)
{
    int ok = r == TT_ERROR_INVALID_ARGUMENT && err->result == TT_ERROR_INVALID_ARGUMENT && err->message[0] != '\0';
    CHECK(ok, "%s with an allocator that has only %s: expected %d with a message, got %d (\"%s\")", what, which,
          TT_ERROR_INVALID_ARGUMENT, r, err->message);
    return ok;
}

static void test_half_allocators(void)
{
    static const float pos[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    static const int idx[3] = {0, 1, 2};
    static const tt_triplet t[3] = {{0, 0, 4.0}, {1, 1, 2.0}, {0, 1, 1.0}};
    static const tt_triplet ts[4] = {{0, 0, 4.0}, {1, 1, 3.0}, {0, 1, 1.0}, {1, 0, 1.0}};
    double b[2] = {1.0, 2.0}, x[2];
    tt_allocator halves[2];
    tt_mesh_desc d;
    tt_error err;
    int h;
    memset(&d, 0, sizeof d);
    d.positions = pos;
    d.nverts = 3;
    d.indices = idx;
    d.nfaces = 1;
    memset(halves, 0, sizeof halves);
    halves[0].alloc = only_alloc;
    halves[1].free = only_free;
    for (h = 0; h < 2; h++) {
        const char *which = h ? "free" : "alloc";
        const tt_allocator *al = &halves[h];
        tt_mesh *mesh = (tt_mesh *)&mesh;
        tt_image *im = (tt_image *)&im;
        tt_sparse_matrix *m = (tt_sparse_matrix *)&m;
        tt_sparse_matrix *A = NULL;
        tt_result r;
        memset(&err, 0, sizeof err);
        r = tt_mesh_build(&d, al, &mesh, &err);
        if (bad_allocator_refused(r, &err, "tt_mesh_build", which))
            CHECK(mesh == NULL, "tt_mesh_build with a half allocator: *out_mesh should be NULL");
        if (r == TT_OK && mesh) tt_mesh_free(mesh);
        memset(&err, 0, sizeof err);
        r = tt_image_create(4, 4, al, &im, &err);
        if (bad_allocator_refused(r, &err, "tt_image_create", which))
            CHECK(im == NULL, "tt_image_create with a half allocator: *out_image should be NULL");
        if (r == TT_OK && im) tt_image_free(im);
        memset(&err, 0, sizeof err);
        r = tt_sparse_from_triplets(2, 2, t, 3, al, &m, &err);
        if (bad_allocator_refused(r, &err, "tt_sparse_from_triplets", which))
            CHECK(m == NULL, "tt_sparse_from_triplets with a half allocator: *out_matrix should be NULL");
        if (r == TT_OK && m) tt_sparse_matrix_free(m);
        if (tt_sparse_from_triplets(2, 2, ts, 4, NULL, &A, NULL) == TT_OK) {
            x[0] = x[1] = 0.25;
            memset(&err, 0, sizeof err);
            r = tt_cg_solve(A, b, NULL, al, x, NULL, &err);
            if (bad_allocator_refused(r, &err, "tt_cg_solve", which))
                CHECK(x[0] == 0.25 && x[1] == 0.25, "tt_cg_solve with a half allocator should leave x alone");
            tt_sparse_matrix_free(A);
        } else {
            CHECK(0, "2 x 2 SPD matrix with the default allocator");
        }
    }
    /* NULL: TT_MALLOC / TT_FREE. */
    {
        tt_mesh *mesh = NULL;
        tt_image *im = NULL;
        tt_sparse_matrix *A = NULL;
        tt_cg_report rep;
        tt_result r1 = tt_mesh_build(&d, NULL, &mesh, &err);
        tt_result r2 = tt_image_create(4, 4, NULL, &im, &err);
        tt_result r3 = tt_sparse_from_triplets(2, 2, ts, 4, NULL, &A, &err), r4 = TT_RESULT_MAX_ENUM;
        x[0] = x[1] = 0.0;
        if (A) r4 = tt_cg_solve(A, b, NULL, NULL, x, &rep, &err);
        /* [[4,1],[1,3]] x = [1,2]: x = (1/11, 7/11) */
        CHECK(r1 == TT_OK && mesh && r2 == TT_OK && im && r3 == TT_OK && A && r4 == TT_OK &&
                  near(x[0], 1.0 / 11.0, 1e-9) && near(x[1], 7.0 / 11.0, 1e-9),
              "NULL allocator: results %d %d %d %d, x = %g %g", r1, r2, r3, r4, x[0], x[1]);
        CHECK(!im || (im->allocator.alloc == NULL && im->allocator.free == NULL),
              "an image made with the NULL allocator remembers a zeroed allocator");
        tt_mesh_free(mesh);
        tt_image_free(im);
        tt_sparse_matrix_free(A);
    }
    /* Both set, user_data passed through: the counting allocator. */
    {
        counter cnt;
        tt_allocator al = make_allocator(&cnt, -1);
        tt_image *im = NULL;
        CHECK(tt_image_create(2, 2, &al, &im, NULL) == TT_OK && cnt.calls == 1 && cnt.live == 1,
              "a full allocator is used: %ld calls", cnt.calls);
        tt_image_free(im);
        CHECK(cnt.live == 0 && cnt.bad_frees == 0, "and frees through it: %ld live", cnt.live);
    }
}

void run_common_tests(void)
{
    RUN(test_rng);
    RUN(test_median);
    RUN(test_version);
    RUN(test_result_strings);
    RUN(test_half_allocators);
}
