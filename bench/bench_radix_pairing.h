/* bench_radix_pairing.h - the yardstick of the build benchmark: twins paired by
   sorting edge keys, nothing validated. Valid C99 and C++.

   Half-edge c of a face_size-gon mesh runs from idx[c] to the next corner of
   its face. Its key packs (smaller end, larger end, corner) into 64 bits,
   vbits + vbits + cbits of them (vbits = bits of nverts - 1, cbits = bits of
   ncorners - 1); the keys are made in corner order, and all digit histograms
   counted, in one pass; then a stable LSD radix sort on the 2 * vbits key
   bits only (about 11-bit digits, passes whose digit is the same for every key
   skipped), so within an edge the corners stay in order; then one scan: a run
   of exactly two equal edges is a twin pair, anything else is left -1. No
   check of direction, range, fans or geometry: a plain, fast reference for
   "pair the twins of this index buffer" that a validating builder should stay
   close to. The time includes allocating the twin array and the scratch. */
#ifndef BENCH_RADIX_PAIRING_H
#define BENCH_RADIX_PAIRING_H

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

static int bench_radix_bits(uint32_t x)
{
    int b = 0;
    while (x) { b++; x >>= 1; }
    return b;
}

/* A malloc'd twin array of face_size * nfaces ints, or NULL (out of memory, or
   the keys do not fit in 64 bits). */
static int *bench_radix_pairing(const int *idx, int nfaces, int face_size, int nverts)
{
    enum { MAX_PASSES = 6 };
    int n = nfaces * face_size, vbits = bench_radix_bits((uint32_t)(nverts > 1 ? nverts - 1 : 1));
    int cbits = bench_radix_bits((uint32_t)(n > 1 ? n - 1 : 1)), keybits = 2 * vbits, passes, digit, p, f, i;
    uint32_t (*hist)[2048];
    uint64_t *a, *b, *t, cmask = ((uint64_t)1 << cbits) - 1;
    int *twin;
    if (keybits + cbits > 64) return NULL;
    passes = (keybits + 10) / 11;
    if (passes > MAX_PASSES) return NULL;
    digit = (keybits + passes - 1) / passes;
    twin = (int *)malloc(sizeof(int) * (size_t)n);
    a = (uint64_t *)malloc(sizeof(uint64_t) * (size_t)n);
    b = (uint64_t *)malloc(sizeof(uint64_t) * (size_t)n);
    hist = (uint32_t(*)[2048])calloc(MAX_PASSES, sizeof *hist);
    if (!twin || !a || !b || !hist) {
        free(twin); free(a); free(b); free(hist);
        return NULL;
    }
    for (f = 0, i = 0; f < nfaces; f++, i += face_size) {
        int k;
        for (k = 0; k < face_size; k++) {
            uint32_t u = (uint32_t)idx[i + k], v = (uint32_t)idx[i + (k + 1 < face_size ? k + 1 : 0)];
            uint64_t key = u < v ? ((uint64_t)u << vbits) | v : ((uint64_t)v << vbits) | u;
            a[i + k] = (key << cbits) | (uint64_t)(i + k);
            for (p = 0; p < passes; p++) hist[p][(key >> (p * digit)) & ((1u << digit) - 1)]++;
        }
    }
    for (p = 0; p < passes; p++) {
        uint32_t sum = 0, *h = hist[p];
        int shift = cbits + p * digit, d;
        if (h[(a[0] >> shift) & ((1u << digit) - 1)] == (uint32_t)n) continue;   /* one digit: nothing to do */
        for (d = 0; d < (1 << digit); d++) { uint32_t c = h[d]; h[d] = sum; sum += c; }
        for (i = 0; i < n; i++) b[h[(a[i] >> shift) & ((1u << digit) - 1)]++] = a[i];
        t = a; a = b; b = t;
    }
    for (i = 0; i < n;) {
        uint64_t edge = a[i] >> cbits;
        int end = i + 1;
        while (end < n && (a[end] >> cbits) == edge) end++;
        if (end - i == 2) {
            int c0 = (int)(a[i] & cmask), c1 = (int)(a[i + 1] & cmask);
            twin[c0] = c1;
            twin[c1] = c0;
        } else {
            for (; i < end; i++) twin[a[i] & cmask] = -1;
        }
        i = end;
    }
    free(a);
    free(b);
    free(hist);
    return twin;
}

#endif
