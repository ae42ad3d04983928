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

void run_common_tests(void)
{
    RUN(test_rng);
}
