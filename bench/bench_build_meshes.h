/* bench_build_meshes.h - the meshes of the half-edge build benchmark, shared by
   bench_build.c (tiledtex and the radix-pairing yardstick) and
   bench_build_cgal.cpp (the CGAL Surface_mesh peer), so that every builder
   gets exactly the same arrays. Valid C99 and C++. Also holds what both
   programs need besides: the clock, the glibc cold/warm switch and the run
   loop.

   Three meshes of about a million faces, all closed, so every half-edge has a
   twin:
     grid      a 1000 x 1000 torus of quads, vertex ids in grid order
               (1M vertices, 1M quads, 4M half-edges);
     shuffled  the same torus with its vertex ids randomly permuted (faces in
               the same order): what vertex order costs;
     soup      an irregular triangle mesh as an STL file gives it: a
               1000 x 500 torus grid, every quad cut along a random diagonal
               (valences 4..8), the triangles written patch by patch (16 x 16
               quads, as a mesher emits them) as a soup of corner positions,
               then welded by exact position with vertex ids in first-seen
               order (500k vertices, 1M triangles, 3M half-edges).
   Generation is deterministic and not timed. */
#ifndef BENCH_BUILD_MESHES_H
#define BENCH_BUILD_MESHES_H

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "bench_clock.h"
#ifdef __GLIBC__
#include <malloc.h>
#endif

typedef struct bench_mesh {
    const char *name;
    int nverts, nfaces, face_size;
    float *pos;     /* 3 * nverts */
    int *idx;       /* face_size * nfaces */
} bench_mesh;

static void *bench_xmalloc(size_t size)
{
    void *p = malloc(size ? size : 1);
    if (!p) {
        fprintf(stderr, "bench: out of memory (%lu bytes)\n", (unsigned long)size);
        exit(1);
    }
    return p;
}

static uint64_t bench_splitmix64(uint64_t *s)
{
    uint64_t z = (*s += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

/* Point (i, j) of an nu x nv torus grid (indices wrap). */
static void bench_torus_point(int i, int j, int nu, int nv, float *p)
{
    const double R = 1.0, r = 0.35, two_pi = 6.283185307179586;
    double u, v, ring;
    i = ((i % nu) + nu) % nu;
    j = ((j % nv) + nv) % nv;
    u = two_pi * i / nu;
    v = two_pi * j / nv;
    ring = R + r * cos(v);
    p[0] = (float)(ring * cos(u));
    p[1] = (float)(ring * sin(u));
    p[2] = (float)(r * sin(v));
}

/* n x n quads; quad (i, j) is (i,j) (i+1,j) (i+1,j+1) (i,j+1), outward. */
static void bench_mesh_grid(bench_mesh *m, int n)
{
    int i, j;
    m->name = "grid";
    m->nverts = n * n;
    m->nfaces = n * n;
    m->face_size = 4;
    m->pos = (float *)bench_xmalloc(sizeof(float) * 3 * (size_t)m->nverts);
    m->idx = (int *)bench_xmalloc(sizeof(int) * 4 * (size_t)m->nfaces);
    for (i = 0; i < n; ++i)
        for (j = 0; j < n; ++j) bench_torus_point(i, j, n, n, m->pos + 3 * ((size_t)i * n + j));
    for (i = 0; i < n; ++i)
        for (j = 0; j < n; ++j) {
            int i1 = (i + 1) % n, j1 = (j + 1) % n, *q = m->idx + 4 * ((size_t)i * n + j);
            q[0] = i * n + j;
            q[1] = i1 * n + j;
            q[2] = i1 * n + j1;
            q[3] = i * n + j1;
        }
}

/* src with vertex ids renamed by a random permutation (faces unchanged). */
static void bench_mesh_shuffled(const bench_mesh *src, bench_mesh *dst, uint64_t seed)
{
    int *perm = (int *)bench_xmalloc(sizeof(int) * (size_t)src->nverts);
    int v, c, ncorners = src->face_size * src->nfaces;
    for (v = 0; v < src->nverts; ++v) perm[v] = v;
    for (v = src->nverts - 1; v > 0; --v) {
        int k = (int)(bench_splitmix64(&seed) % (uint64_t)(v + 1)), t = perm[v];
        perm[v] = perm[k];
        perm[k] = t;
    }
    *dst = *src;
    dst->name = "shuffled";
    dst->pos = (float *)bench_xmalloc(sizeof(float) * 3 * (size_t)src->nverts);
    dst->idx = (int *)bench_xmalloc(sizeof(int) * (size_t)ncorners);
    for (v = 0; v < src->nverts; ++v) memcpy(dst->pos + 3 * (size_t)perm[v], src->pos + 3 * (size_t)v, 3 * sizeof(float));
    for (c = 0; c < ncorners; ++c) dst->idx[c] = perm[src->idx[c]];
    free(perm);
}

/* The welded STL: see the top of the file. */
static void bench_mesh_soup(bench_mesh *m, int nu, int nv, int patch, uint64_t seed)
{
    size_t ntris = 2 * (size_t)nu * nv, t = 0, slots = 1, s;
    float *soup = (float *)bench_xmalloc(sizeof(float) * 9 * ntris);
    int *slot, pi, pj, i, j, k, nverts = 0;
    /* The STL: patches of patch x patch quads, quads row by row inside. */
    for (pi = 0; pi < nu; pi += patch)
        for (pj = 0; pj < nv; pj += patch)
            for (i = pi; i < pi + patch && i < nu; ++i)
                for (j = pj; j < pj + patch && j < nv; ++j) {
                    float q[4][3];
                    int d = (int)(bench_splitmix64(&seed) & 1);
                    bench_torus_point(i, j, nu, nv, q[0]);
                    bench_torus_point(i + 1, j, nu, nv, q[1]);
                    bench_torus_point(i + 1, j + 1, nu, nv, q[2]);
                    bench_torus_point(i, j + 1, nu, nv, q[3]);
                    for (k = 0; k < 6; ++k) {
                        /* d = 0: (0 1 2) (0 2 3); d = 1: (0 1 3) (1 2 3) */
                        static const int split[2][6] = {{0, 1, 2, 0, 2, 3}, {0, 1, 3, 1, 2, 3}};
                        memcpy(soup + 9 * t + 3 * (k % 3), q[split[d][k]], 3 * sizeof(float));
                        if (k % 3 == 2) t++;
                    }
                }
    /* Weld by exact bit pattern, ids in first-seen order (open addressing). */
    while (slots < 6 * ntris / 2) slots <<= 1;
    slot = (int *)bench_xmalloc(sizeof(int) * slots);
    memset(slot, 0xff, sizeof(int) * slots);
    m->name = "soup";
    m->face_size = 3;
    m->nfaces = (int)ntris;
    m->idx = (int *)bench_xmalloc(sizeof(int) * 3 * ntris);
    m->pos = (float *)bench_xmalloc(sizeof(float) * 3 * 3 * ntris);
    for (t = 0; t < 3 * ntris; ++t) {
        const float *p = soup + 3 * t;
        uint32_t b[3];
        uint64_t h;
        memcpy(b, p, sizeof b);
        h = ((uint64_t)b[0] * 0x9E3779B97F4A7C15ull) ^ ((uint64_t)b[1] * 0xC2B2AE3D27D4EB4Full) ^
            ((uint64_t)b[2] * 0x165667B19E3779F9ull);
        for (s = (size_t)(h ^ (h >> 29)) & (slots - 1);; s = (s + 1) & (slots - 1)) {
            if (slot[s] < 0) {
                slot[s] = nverts;
                memcpy(m->pos + 3 * (size_t)nverts, p, 3 * sizeof(float));
                nverts++;
                break;
            }
            if (memcmp(m->pos + 3 * (size_t)slot[s], p, 3 * sizeof(float)) == 0) break;
        }
        m->idx[t] = slot[s];
    }
    m->nverts = nverts;
    free(slot);
    free(soup);
}

static void bench_mesh_free(bench_mesh *m)
{
    free(m->pos);
    free(m->idx);
}

/* The three meshes, in the order above. */
#define BENCH_NMESHES 3
static void bench_make_meshes(bench_mesh *m)
{
    bench_mesh_grid(&m[0], 1000);
    bench_mesh_shuffled(&m[0], &m[1], 12345);
    bench_mesh_soup(&m[2], 1000, 500, 16, 777);
}

/* ---- clock, memory state, runs ---------------------------------------------- */

/* Cold: every big block is a fresh mapping (page faults paid in the run).
   Warm: every block comes from the heap (mmap off, so even blocks over
   glibc's 32 MB mmap ceiling) and stays there after free, so a run reuses the
   previous run's pages. glibc only. */
static void bench_malloc_cold(void)
{
#ifdef __GLIBC__
    malloc_trim(0);
    mallopt(M_MMAP_MAX, 65536);
    mallopt(M_MMAP_THRESHOLD, 128 * 1024);
    mallopt(M_TRIM_THRESHOLD, 128 * 1024);
    malloc_trim(0);
#endif
}

static void bench_malloc_warm(void)
{
#ifdef __GLIBC__
    mallopt(M_MMAP_MAX, 0);
    mallopt(M_TRIM_THRESHOLD, 1 << 30);
#endif
}

static double bench_median(double *t, int n)
{
    qsort(t, (size_t)n, sizeof t[0], bench_cmp_double);
    return t[n / 2];
}

#endif
