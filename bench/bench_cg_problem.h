/* bench_cg_problem.h - the linear system of the CG benchmark, shared by
   bench_cg.c (tiledtex) and bench_cg_eigen.cpp (the Eigen peer) so that both
   solve exactly the same numbers. Valid C99 and C++.

   The mesh: a BENCH_CG_SIDE x BENCH_CG_SIDE grid of vertices (316 x 316 =
   99,856 unknowns), every square split into two triangles along the same
   diagonal, so an interior vertex has 6 neighbours. The matrix is that
   triangle mesh's uniform graph Laplacian, L[i][i] = degree, L[i][j] = -1 per
   edge, with the four corner vertices pinned softly (+1 on their diagonal, a
   positional constraint as in Praun et al. Sec. 3.4): symmetric positive
   definite, badly conditioned (about side^2), 7 entries per interior row.
   It is emitted as triplets with every edge contributing its four entries
   (duplicates on the diagonal), as a mesh assembler would.

   The right-hand side is b = A x* for a known x*: a smooth bump plus a little
   deterministic noise; the solve starts from x = 0. */
#ifndef BENCH_CG_PROBLEM_H
#define BENCH_CG_PROBLEM_H

#include <math.h>
#include <stdint.h>
#include <stdlib.h>

#define BENCH_CG_SIDE 316

typedef struct bench_cg_entry {
    int row, col;
    double value;
} bench_cg_entry;

/* Unknowns of the benchmark system. */
static int bench_cg_size(void) { return BENCH_CG_SIDE * BENCH_CG_SIDE; }

/* Room for the triplets: at most 3 edges per vertex, 4 entries per edge,
   plus the 4 corner pins. */
static int bench_cg_capacity(void) { return 12 * BENCH_CG_SIDE * BENCH_CG_SIDE + 4; }

/* Fills e (bench_cg_capacity() entries) and returns how many it used. */
static int bench_cg_triplets(bench_cg_entry *e)
{
    const int s = BENCH_CG_SIDE;
    int x, y, k, count = 0;
    for (y = 0; y < s; y++)
        for (x = 0; x < s; x++) {
            /* Edges to the right, up, and the square's diagonal (x+1, y+1). */
            static const int dx[3] = {1, 0, 1}, dy[3] = {0, 1, 1};
            int v = y * s + x;
            for (k = 0; k < 3; k++) {
                int nx = x + dx[k], ny = y + dy[k], w;
                if (nx >= s || ny >= s) continue;
                w = ny * s + nx;
                e[count].row = v; e[count].col = v; e[count].value = 1.0; count++;
                e[count].row = w; e[count].col = w; e[count].value = 1.0; count++;
                e[count].row = v; e[count].col = w; e[count].value = -1.0; count++;
                e[count].row = w; e[count].col = v; e[count].value = -1.0; count++;
            }
        }
    {
        const int corners[4] = {0, s - 1, s * (s - 1), s * s - 1};
        for (k = 0; k < 4; k++) {
            e[count].row = corners[k]; e[count].col = corners[k]; e[count].value = 1.0; count++;
        }
    }
    return count;
}

/* The known solution x*: a bump over the grid plus noise in [-0.05, 0.05). */
static void bench_cg_solution(double *xs)
{
    const int s = BENCH_CG_SIDE;
    uint64_t state = 0x243f6a8885a308d3ull;
    int x, y;
    for (y = 0; y < s; y++)
        for (x = 0; x < s; x++) {
            double u = (double)x / (s - 1), v = (double)y / (s - 1);
            state = state * 6364136223846793005ull + 1442695040888963407ull;
            xs[y * s + x] = sin(3.0 * u) * cos(2.0 * v) + 0.1 * ((double)(state >> 11) / 9007199254740992.0 - 0.5);
        }
}

/* b = A x* straight from the triplets (the same sum for both programs). */
static void bench_cg_rhs(const bench_cg_entry *e, int count, const double *xs, double *b)
{
    int i, n = bench_cg_size();
    for (i = 0; i < n; i++) b[i] = 0.0;
    for (i = 0; i < count; i++) b[e[i].row] += e[i].value * xs[e[i].col];
}

#endif
