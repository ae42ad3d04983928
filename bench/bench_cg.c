/* bench_cg.c - conjugate-gradient figure for tiledtex.h (section 4).

   Prints, as bench/bench.c does (`name value unit`, nothing else on stdout):
       cg_laplacian_100k <ms> ms
       cg_laplacian_100k <steps> iterations
   The system is bench_cg_problem.h's: the uniform graph Laplacian of a
   316 x 316 triangulated grid with its four corners pinned (99,856 unknowns,
   ~7 entries a row), b = A x* for a known x*, x0 = 0, tolerance 1e-8 relative,
   cap 2n steps. The time is tt_cg_solve alone (the matrix is built once),
   median of 5 runs after one warm-up run, monotonic clock. The spread of the
   runs, the residual and the error against x* go to stderr.

   The peer is bench_cg_eigen.cpp (Eigen's ConjugateGradient with its
   diagonal preconditioner on the same numbers), built only where Eigen is
   installed; this program never needs it.

       cc -O2 -std=c99 -I. bench_cg.c -o bench_cg -lm && ./bench_cg */
#define _POSIX_C_SOURCE 199309L
#define TILEDTEX_IMPLEMENTATION
#include "tiledtex.h"
#include "bench_clock.h"
#include "bench_cg_problem.h"

#include <stdio.h>
#include <string.h>
#include <time.h>

#define RUNS 5

int main(void)
{
    int n = bench_cg_size(), count, i, run, iterations = 0;
    bench_cg_entry *e = (bench_cg_entry *)malloc(sizeof(bench_cg_entry) * (size_t)bench_cg_capacity());
    tt_triplet *t;
    double *xs = (double *)malloc(sizeof(double) * (size_t)n), *b = (double *)malloc(sizeof(double) * (size_t)n);
    double *x = (double *)malloc(sizeof(double) * (size_t)n), ms[RUNS + 1], err = 0.0;
    tt_sparse_matrix *A = NULL;
    tt_cg_options opt;
    tt_cg_report rep;
    tt_error error;
    tt_result r;
    if (!e || !xs || !b || !x) {
        fprintf(stderr, "bench_cg: out of memory\n");
        return 1;
    }
    count = bench_cg_triplets(e);
    bench_cg_solution(xs);
    bench_cg_rhs(e, count, xs, b);
    t = (tt_triplet *)malloc(sizeof(tt_triplet) * (size_t)count);
    if (!t) return 1;
    for (i = 0; i < count; i++) {
        t[i].row = e[i].row;
        t[i].col = e[i].col;
        t[i].value = e[i].value;
    }
    r = tt_sparse_from_triplets(n, n, t, count, NULL, &A, &error);
    if (r != TT_OK) {
        fprintf(stderr, "bench_cg: tt_sparse_from_triplets: %s\n", error.message);
        return 1;
    }
    memset(&opt, 0, sizeof opt);
    opt.tolerance = 1e-8;
    opt.max_iterations = 2 * n;
    for (run = 0; run <= RUNS; run++) {   /* run 0 warms up */
        double start;
        memset(x, 0, sizeof(double) * (size_t)n);
        start = bench_now_ms();
        r = tt_cg_solve(A, b, &opt, NULL, x, &rep, &error);
        ms[run] = bench_now_ms() - start;
        if (r != TT_OK) {
            fprintf(stderr, "bench_cg: tt_cg_solve: %s\n", error.message);
            return 1;
        }
        if (run > 0 && rep.iterations != iterations) fprintf(stderr, "bench_cg: iterations vary between runs\n");
        iterations = rep.iterations;
    }
    for (i = 0; i < n; i++)
        if (fabs(x[i] - xs[i]) > err) err = fabs(x[i] - xs[i]);
    qsort(ms + 1, RUNS, sizeof ms[0], bench_cmp_double);
    printf("cg_laplacian_100k %.1f ms\n", ms[1 + RUNS / 2]);
    printf("cg_laplacian_100k %d iterations\n", iterations);
    fprintf(stderr, "bench_cg: %d unknowns, %d entries; runs %.1f..%.1f ms (warm-up %.1f); %.3f ms a step; "
            "residual %.3g; |x - x*|_inf %.3g\n", n, A->nnz, ms[1], ms[RUNS], ms[0], ms[1 + RUNS / 2] / iterations,
            rep.residual, err);
    tt_sparse_matrix_free(A);
    free(e);
    free(t);
    free(xs);
    free(b);
    free(x);
    return 0;
}
