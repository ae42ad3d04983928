/* tests/test_4_numerics.c - unit tests for section 4 of tiledtex.h: sparse
   matrices and conjugate gradients. Run by run_numerics_tests()
   (tests/test_common.c calls it). */
#include "test_common.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ------------------------------------------------------------------------ */
/* 4. Numerics (sparse matrices, conjugate gradients)                       */
/* ------------------------------------------------------------------------ */

/* Random triplets in a rows x cols matrix: unsorted, with duplicates (about a
   third repeat an earlier position), and some rows left empty. */
static tt_triplet *cg_random_triplets(int rows, int cols, int count)
{
    tt_triplet *t = (tt_triplet *)malloc(sizeof(tt_triplet) * (size_t)(count > 0 ? count : 1));
    int k, skip = rows > 2 ? lcg_below(rows) : -1;   /* one row stays empty */
    for (k = 0; k < count; k++) {
        if (k > 0 && lcg_below(3) == 0) {
            t[k] = t[lcg_below(k)];
        } else {
            do t[k].row = lcg_below(rows);
            while (t[k].row == skip);
            t[k].col = lcg_below(cols);
        }
        t[k].value = lcg_unit() * 4.0 - 2.0;
    }
    return t;
}

/* The matrix as dense rows x cols, adding the triplets in input order. */
static double *cg_dense_from_triplets(int rows, int cols, const tt_triplet *t, int count, char *used)
{
    double *d = (double *)calloc((size_t)rows * cols + 1, sizeof(double));
    int k;
    for (k = 0; k < count; k++) {
        d[(size_t)t[k].row * cols + t[k].col] += t[k].value;
        if (used) used[(size_t)t[k].row * cols + t[k].col] = 1;
    }
    return d;
}

/* Every stored entry matches the dense matrix bit for bit, the pattern is
   exactly the named positions, columns strictly increase in a row. */
static int cg_matches_dense(const tt_sparse_matrix *m, const double *d, const char *used, int rows, int cols)
{
    int i, k, bad = 0, named = 0;
    if (m->rows != rows || m->cols != cols || m->row_start[0] != 0 || m->row_start[rows] != m->nnz) return -1;
    for (i = 0; i < rows * cols; i++) named += used[i];
    if (named != m->nnz) bad++;
    for (i = 0; i < rows; i++) {
        if (m->row_start[i + 1] < m->row_start[i]) bad++;
        for (k = m->row_start[i]; k < m->row_start[i + 1]; k++) {
            int c = m->col[k];
            if (c < 0 || c >= cols || (k > m->row_start[i] && c <= m->col[k - 1])) { bad++; continue; }
            if (!used[(size_t)i * cols + c] || m->value[k] != d[(size_t)i * cols + c]) bad++;
        }
    }
    return bad;
}

static void test_cg_triplets(void)
{
    counter cnt;
    tt_allocator al = make_allocator(&cnt, -1);
    int trial, bad_trials = 0, bad_free = 0;
    lcg_seed(401);
    for (trial = 0; trial < 300; trial++) {
        int rows = 1 + lcg_below(trial < 100 ? 6 : 40), cols = 1 + lcg_below(trial < 100 ? 6 : 40);
        int count = lcg_below(3 * rows * cols / 2 + 2), bad;
        tt_triplet *t = cg_random_triplets(rows, cols, count);
        char *used = (char *)calloc((size_t)rows * cols, 1);
        double *d = cg_dense_from_triplets(rows, cols, t, count, used);
        tt_sparse_matrix *m = NULL;
        tt_error err;
        tt_result r = tt_sparse_from_triplets(rows, cols, t, count, &al, &m, &err);
        if (r != TT_OK || !m) bad = 1000;
        else {
            bad = cg_matches_dense(m, d, used, rows, cols);
            if (cnt.live != 4) bad++;   /* the struct and its three arrays */
        }
        if (bad && !bad_trials)
            DETAIL("trial %d: %d x %d from %d triplets: result %d, %d bad entries, %ld live (%s)", trial, rows, cols,
                   count, r, bad, cnt.live, err.message);
        if (bad) bad_trials++;
        tt_sparse_matrix_free(m);
        if (cnt.live != 0) bad_free++;
        free(t);
        free(used);
        free(d);
    }
    CHECK(bad_trials == 0, "CSR from random triplets differs from the dense sum in %d of 300 trials", bad_trials);
    CHECK(bad_free == 0, "tt_sparse_matrix_free left allocations live in %d of 300 trials", bad_free);
    CHECK(cnt.live == 0 && cnt.bad_frees == 0, "triplets: %ld allocations leaked, %ld bad frees", cnt.live,
          cnt.bad_frees);
    {
        /* A hand-checked case: unsorted input, a duplicate, an empty row 1, a
           zero sum that stays in the pattern. */
        static const tt_triplet t[] = {{2, 3, 1.0}, {0, 2, 5.0}, {2, 0, 2.0}, {0, 0, 1.5}, {2, 3, 0.25},
                                       {0, 1, 4.0}, {0, 1, -4.0}};
        static const int rs[] = {0, 3, 3, 5}, cl[] = {0, 1, 2, 0, 3};
        static const double vl[] = {1.5, 0.0, 5.0, 2.0, 1.25};
        tt_sparse_matrix *m = NULL;
        int k, same = 1;
        tt_result r = tt_sparse_from_triplets(3, 4, t, 7, NULL, &m, NULL);
        CHECK(r == TT_OK && m && m->rows == 3 && m->cols == 4 && m->nnz == 5, "3x4 example: result %d, nnz %d", r,
              m ? m->nnz : -1);
        if (r == TT_OK && m && m->nnz == 5) {
            for (k = 0; k < 4; k++) same &= m->row_start[k] == rs[k];
            for (k = 0; k < 5; k++) same &= m->col[k] == cl[k] && m->value[k] == vl[k];
            CHECK(same, "3x4 example: row_start/col/value differ from the hand-made CSR");
        }
        tt_sparse_matrix_free(m);
        tt_sparse_matrix_free(NULL);   /* allowed */
    }
    {
        /* No triplets; a 0 x 0 matrix; NULL triplets with count 0. */
        tt_sparse_matrix *m = NULL;
        tt_result r = tt_sparse_from_triplets(4, 2, NULL, 0, &al, &m, NULL);
        CHECK(r == TT_OK && m && m->nnz == 0 && m->rows == 4 && m->row_start && m->row_start[4] == 0,
              "4x2 from no triplets: result %d", r);
        tt_sparse_matrix_free(m);
        m = NULL;
        r = tt_sparse_from_triplets(0, 0, NULL, 0, &al, &m, NULL);
        CHECK(r == TT_OK && m && m->nnz == 0 && m->rows == 0 && m->row_start && m->row_start[0] == 0,
              "0x0 matrix: result %d", r);
        tt_sparse_matrix_free(m);
        CHECK(cnt.live == 0, "empty matrices: %ld allocations leaked", cnt.live);
    }
}

static void cg_expect_triplet_error(int rows, int cols, const tt_triplet *t, int count, tt_result code, int row,
                                    int col, int index, const char *what)
{
    counter cnt;
    tt_allocator al = make_allocator(&cnt, -1);
    tt_sparse_matrix *m = (tt_sparse_matrix *)&m;   /* must become NULL */
    tt_error err;
    tt_result r;
    memset(&err, 0x5a, sizeof err);
    r = tt_sparse_from_triplets(rows, cols, t, count, &al, &m, &err);
    CHECK(r == code && err.result == code, "%s: expected %d, got %d (err.result %d)", what, code, r, err.result);
    CHECK(m == NULL, "%s: *out_matrix should be NULL on failure", what);
    if (r == TT_OK && m) tt_sparse_matrix_free(m);
    CHECK(cnt.calls == 0 && cnt.live == 0, "%s: %ld allocations made, %ld live; none expected", what, cnt.calls,
          cnt.live);
    CHECK(err.message[0] != '\0' && memchr(err.message, '\0', sizeof err.message) != NULL, "%s: empty message",
          what);
    if (row != -2)
        CHECK(err.row == row && err.column == col && err.vertex == -1 && err.other_vertex == -1,
              "%s: row/column expected %d/%d, got %d/%d (vertex %d/%d should be -1)", what, row, col, err.row,
              err.column, err.vertex, err.other_vertex);
    if (index >= 0) {
        CHECK(err.item == index, "%s: error->item expected triplet %d, got %d", what, index, err.item);
        CHECK(msg_has_number(err.message, index), "%s: message should name triplet %d: %s", what, index,
              err.message);
    }
    m = (tt_sparse_matrix *)&m;
    r = tt_sparse_from_triplets(rows, cols, t, count, &al, &m, NULL);
    CHECK(r == code && m == NULL, "%s with error == NULL: expected %d, got %d", what, code, r);
}

static void test_cg_triplet_errors(void)
{
    tt_triplet t[4] = {{0, 0, 1.0}, {1, 1, 2.0}, {2, 2, 3.0}, {1, 0, 0.5}};
    t[2].row = 3;
    cg_expect_triplet_error(3, 3, t, 4, TT_ERROR_INDEX_OUT_OF_RANGE, 3, 2, 2, "row == rows");
    t[2].row = -1;
    cg_expect_triplet_error(3, 3, t, 4, TT_ERROR_INDEX_OUT_OF_RANGE, -1, 2, 2, "row -1");
    t[2].row = 2;
    t[3].col = 7;
    cg_expect_triplet_error(3, 3, t, 4, TT_ERROR_INDEX_OUT_OF_RANGE, 1, 7, 3, "column 7 of 3");
    t[3].col = 0;
    t[1].value = NAN;
    cg_expect_triplet_error(3, 3, t, 4, TT_ERROR_NON_FINITE, 1, 1, 1, "NaN value");
    t[1].value = -INFINITY;
    cg_expect_triplet_error(3, 3, t, 4, TT_ERROR_NON_FINITE, 1, 1, 1, "-inf value");
    t[1].value = 2.0;
    cg_expect_triplet_error(-1, 3, t, 4, TT_ERROR_INVALID_ARGUMENT, -2, -2, -1, "rows -1");
    cg_expect_triplet_error(3, 3, t, -4, TT_ERROR_INVALID_ARGUMENT, -2, -2, -1, "ntriplets -4");
    cg_expect_triplet_error(3, 3, NULL, 4, TT_ERROR_INVALID_ARGUMENT, -2, -2, -1, "triplets NULL");
    CHECK(tt_sparse_from_triplets(3, 3, t, 4, NULL, NULL, NULL) == TT_ERROR_INVALID_ARGUMENT, "matrix NULL");
}

static void test_cg_multiply(void)
{
    int trial, bad = 0;
    lcg_seed(402);
    for (trial = 0; trial < 200; trial++) {
        int rows = 1 + lcg_below(30), cols = 1 + lcg_below(30), count = lcg_below(rows * cols + 1), i, j;
        tt_triplet *t = cg_random_triplets(rows, cols, count);
        double *d = cg_dense_from_triplets(rows, cols, t, count, NULL);
        double *x = (double *)malloc(sizeof(double) * (size_t)cols);
        double *y = (double *)malloc(sizeof(double) * (size_t)rows);
        tt_sparse_matrix *m = NULL;
        for (j = 0; j < cols; j++) x[j] = lcg_unit() * 2.0 - 1.0;
        if (tt_sparse_from_triplets(rows, cols, t, count, NULL, &m, NULL) != TT_OK ||
            tt_sparse_multiply(m, x, y, NULL) != TT_OK) {
            bad++;
        } else {
            for (i = 0; i < rows; i++) {
                double want = 0.0, scale = 0.0;
                for (j = 0; j < cols; j++) {
                    want += d[(size_t)i * cols + j] * x[j];
                    scale += fabs(d[(size_t)i * cols + j] * x[j]);
                }
                if (!near(y[i], want, 1e-14 * (scale + 1e-300) * cols)) {
                    if (!bad) DETAIL("trial %d row %d: y %.17g, dense %.17g", trial, i, y[i], want);
                    bad++;
                }
            }
        }
        tt_sparse_matrix_free(m);
        free(t);
        free(d);
        free(x);
        free(y);
    }
    CHECK(bad == 0, "tt_sparse_multiply differs from the dense product in %d rows", bad);
    {
        /* A CSR filled by hand, unsorted with a repeated column (they add up). */
        int rs[3] = {0, 3, 4}, cl[4] = {2, 0, 2, 1};
        double vl[4] = {1.0, 2.0, 10.0, -1.0}, x[3] = {1.0, 2.0, 3.0}, y[2] = {0, 0};
        tt_sparse_matrix m;
        memset(&m, 0, sizeof m);
        m.rows = 2;
        m.cols = 3;
        m.nnz = 4;
        m.row_start = rs;
        m.col = cl;
        m.value = vl;
        CHECK(tt_sparse_multiply(&m, x, y, NULL) == TT_OK && y[0] == 35.0 && y[1] == -2.0,
              "hand-made CSR: expected 35, -2, got %g, %g", y[0], y[1]);
        CHECK(tt_sparse_multiply(&m, x, x, NULL) == TT_ERROR_INVALID_ARGUMENT, "x == y must be refused");
        CHECK(tt_sparse_multiply(NULL, x, y, NULL) == TT_ERROR_INVALID_ARGUMENT, "A NULL must be refused");
        CHECK(tt_sparse_multiply(&m, NULL, y, NULL) == TT_ERROR_INVALID_ARGUMENT, "x NULL must be refused");
    }
}

/* Dense Cholesky solve of the n x n SPD matrix a (overwritten by its factor):
   x = a^-1 b. Returns 0 when a is not positive definite. */
static int cg_dense_cholesky_solve(double *a, int n, const double *b, double *x)
{
    int i, j, k;
    for (j = 0; j < n; j++) {
        double s = a[(size_t)j * n + j];
        for (k = 0; k < j; k++) s -= a[(size_t)j * n + k] * a[(size_t)j * n + k];
        if (!(s > 0.0)) return 0;
        a[(size_t)j * n + j] = sqrt(s);
        for (i = j + 1; i < n; i++) {
            double t = a[(size_t)i * n + j];
            for (k = 0; k < j; k++) t -= a[(size_t)i * n + k] * a[(size_t)j * n + k];
            a[(size_t)i * n + j] = t / a[(size_t)j * n + j];
        }
    }
    for (i = 0; i < n; i++) {   /* L y = b */
        double s = b[i];
        for (k = 0; k < i; k++) s -= a[(size_t)i * n + k] * x[k];
        x[i] = s / a[(size_t)i * n + i];
    }
    for (i = n - 1; i >= 0; i--) {   /* L^T x = y */
        double s = x[i];
        for (k = i + 1; k < n; k++) s -= a[(size_t)k * n + i] * x[k];
        x[i] = s / a[(size_t)i * n + i];
    }
    return 1;
}

/* A sparse SPD matrix as triplets: a weighted graph Laplacian (a random tree
   plus n random edges, weights 0.1..10) + a positive diagonal, + two sparse
   rank-one terms v v^T with mixed signs, all scaled as D A D with D spread
   over 1e-2..1e2 (so the Jacobi preconditioner has something to undo).
   Triplets repeat positions (duplicates are summed). Returns the count. */
static int cg_random_spd(int n, tt_triplet *t, int capacity)
{
    double *scale = (double *)malloc(sizeof(double) * (size_t)n);
    int count = 0, i, e, k;
#define CG_ADD(i_, j_, v_)                                          \
    do {                                                            \
        if (count < capacity) {                                     \
            t[count].row = (i_);                                    \
            t[count].col = (j_);                                    \
            t[count].value = (v_) * scale[i_] * scale[j_];          \
            count++;                                                \
        }                                                           \
    } while (0)
    for (i = 0; i < n; i++) scale[i] = pow(10.0, lcg_unit() * 4.0 - 2.0);
    for (i = 0; i < n; i++) CG_ADD(i, i, 0.01 + lcg_unit());
    for (e = 0; e < 2 * n - 1; e++) {
        int a = e < n - 1 ? e + 1 : lcg_below(n), b = e < n - 1 ? lcg_below(e + 1) : lcg_below(n);
        double w = 0.1 + 9.9 * lcg_unit();
        if (a == b) continue;
        CG_ADD(a, a, w);
        CG_ADD(b, b, w);
        CG_ADD(a, b, -w);
        CG_ADD(b, a, -w);
    }
    for (k = 0; k < 2 && n >= 3; k++) {
        int idx[3];
        double v[3];
        int p, q;
        idx[0] = lcg_below(n);
        do idx[1] = lcg_below(n);
        while (idx[1] == idx[0]);
        do idx[2] = lcg_below(n);
        while (idx[2] == idx[0] || idx[2] == idx[1]);
        for (p = 0; p < 3; p++) v[p] = lcg_unit() * 4.0 - 2.0;
        for (p = 0; p < 3; p++)
            for (q = 0; q < 3; q++) CG_ADD(idx[p], idx[q], v[p] * v[q]);
    }
#undef CG_ADD
    free(scale);
    return count;
}

/* |b - A x| / |b| in long double from a dense matrix. */
static double cg_dense_relres(const double *d, int n, const double *b, const double *x)
{
    long double rr = 0.0L, bb = 0.0L;
    int i, j;
    for (i = 0; i < n; i++) {
        long double s = b[i];
        for (j = 0; j < n; j++) s -= (long double)d[(size_t)i * n + j] * x[j];
        rr += s * s;
        bb += (long double)b[i] * b[i];
    }
    return bb > 0.0L ? (double)sqrtl(rr / bb) : (double)sqrtl(rr);
}

static void test_cg_random_spd(void)
{
    int n, bad_result = 0, bad_x = 0, bad_res = 0, bad_report = 0;
    double worst_err = 0.0;
    counter cnt;
    tt_allocator al = make_allocator(&cnt, -1);
    lcg_seed(403);
    for (n = 1; n <= 200; n++) {
        int cap = 30 * n + 20, count, i;
        tt_triplet *t = (tt_triplet *)malloc(sizeof(tt_triplet) * (size_t)cap);
        double *d, *chol, *b = (double *)malloc(sizeof(double) * (size_t)n);
        double *x = (double *)calloc((size_t)n, sizeof(double)), *xr = (double *)malloc(sizeof(double) * (size_t)n);
        double err_num = 0.0, err_den = 0.0, relres;
        tt_sparse_matrix *m = NULL;
        tt_cg_options opt;
        tt_cg_report rep;
        tt_error err;
        tt_result r;
        count = cg_random_spd(n, t, cap);
        d = cg_dense_from_triplets(n, n, t, count, NULL);
        chol = (double *)malloc(sizeof(double) * (size_t)n * n);
        memcpy(chol, d, sizeof(double) * (size_t)n * n);
        for (i = 0; i < n; i++) b[i] = lcg_unit() * 2.0 - 1.0;
        if (!cg_dense_cholesky_solve(chol, n, b, xr)) {
            DETAIL("n = %d: the test matrix is not SPD (generator bug)", n);
            bad_result++;
        } else if (tt_sparse_from_triplets(n, n, t, count, &al, &m, NULL) != TT_OK) {
            bad_result++;
        } else {
            memset(&opt, 0, sizeof opt);
            /* 1e-12 is near what double arithmetic can confirm for these
               matrices: without the final check against a recomputed b - A x,
               the drift of the updated residual shows here. */
            opt.tolerance = 1e-12;
            opt.max_iterations = 20 * n + 100;
            r = tt_cg_solve(m, b, &opt, &al, x, &rep, &err);
            relres = cg_dense_relres(d, n, b, x);
            for (i = 0; i < n; i++) {
                err_num = fmax(err_num, fabs(x[i] - xr[i]));
                err_den = fmax(err_den, fabs(xr[i]));
            }
            if (r != TT_OK || !rep.converged) {
                if (!bad_result) DETAIL("n = %d: result %d after %d steps, residual %g: %s", n, r, rep.iterations,
                                        rep.residual, err.message);
                bad_result++;
            }
            if (relres > 2e-12) {
                if (!bad_res) DETAIL("n = %d: true relative residual %g > 2e-12", n, relres);
                bad_res++;
            }
            /* the report's residual is computed in double: rounding ~1e-13 here */
            if (!(rep.residual <= 1e-12) || fabs(rep.residual - relres) > 1e-12) {
                if (!bad_report) DETAIL("n = %d: report residual %g, recomputed %g", n, rep.residual, relres);
                bad_report++;
            }
            if (err_num > 1e-7 * err_den) {
                if (!bad_x) DETAIL("n = %d: |x - x_cholesky|_inf = %g, |x|_inf = %g", n, err_num, err_den);
                bad_x++;
            }
            if (err_num / err_den > worst_err) worst_err = err_num / err_den;
            tt_sparse_matrix_free(m);
        }
        free(t);
        free(d);
        free(chol);
        free(b);
        free(x);
        free(xr);
    }
    CHECK(bad_result == 0, "CG on random SPD matrices n = 1..200: %d did not converge", bad_result);
    CHECK(bad_res == 0, "CG on random SPD matrices: %d true residuals above twice the tolerance 1e-12", bad_res);
    CHECK(bad_report == 0, "CG: %d reports whose residual is not the recomputed one", bad_report);
    CHECK(bad_x == 0, "CG vs dense Cholesky: %d solutions off by more than 1e-7 relative (worst %g)", bad_x,
          worst_err);
    CHECK(cnt.live == 0 && cnt.bad_frees == 0, "random SPD: %ld allocations leaked", cnt.live);
}

/* The 5-point Laplacian of a w x h grid (Neumann: interior and boundary rows
   alike sum to zero) plus `shift` on the diagonal, as triplets. */
static tt_sparse_matrix *cg_grid_matrix(int w, int h, double shift)
{
    tt_triplet *t = (tt_triplet *)malloc(sizeof(tt_triplet) * (size_t)w * h * 9);
    int x, y, count = 0;
    tt_sparse_matrix *m = NULL;
    for (y = 0; y < h; y++)
        for (x = 0; x < w; x++) {
            int v = y * w + x, k;
            static const int dx[4] = {1, -1, 0, 0}, dy[4] = {0, 0, 1, -1};
            t[count].row = v;
            t[count].col = v;
            t[count].value = shift;
            count++;
            for (k = 0; k < 4; k++) {
                int nx = x + dx[k], ny = y + dy[k];
                if (nx < 0 || ny < 0 || nx >= w || ny >= h) continue;
                t[count].row = v;
                t[count].col = v;
                t[count].value = 1.0;
                count++;
                t[count].row = v;
                t[count].col = ny * w + nx;
                t[count].value = -1.0;
                count++;
            }
        }
    if (tt_sparse_from_triplets(w * h, w * h, t, count, NULL, &m, NULL) != TT_OK) m = NULL;
    free(t);
    return m;
}

/* |b - A x| / |b| through tt_sparse_multiply. */
static double cg_relres(const tt_sparse_matrix *m, const double *b, const double *x)
{
    double *ax = (double *)malloc(sizeof(double) * (size_t)m->rows + 1), rr = 0.0, bb = 0.0;
    int i;
    tt_sparse_multiply(m, x, ax, NULL);
    for (i = 0; i < m->rows; i++) {
        rr += (b[i] - ax[i]) * (b[i] - ax[i]);
        bb += b[i] * b[i];
    }
    free(ax);
    return sqrt(rr / bb);
}

static tt_sparse_matrix *cg_small(int rows, int cols, const double *dense);

/* Incomplete Cholesky: on a grid Laplacian with every fourth row of cells
   squeezed (strong and weak couplings, as slivers give), the same solution
   as Jacobi in far fewer steps; the factor against a dense reference
   (L L^T equals A on A's pattern); a breakdown falls back to Jacobi; bad
   requests refused. */
static void test_cg_incomplete_cholesky(void)
{
    const int w = 30, h = 30, n = w * h;
    tt_triplet *t = (tt_triplet *)malloc(sizeof(tt_triplet) * (size_t)n * 9);
    tt_sparse_matrix *m = NULL;
    double *b = (double *)malloc(sizeof(double) * n), *xj = (double *)calloc((size_t)n, sizeof(double));
    double *xi = (double *)calloc((size_t)n, sizeof(double)), diff = 0.0, scale = 0.0;
    tt_cg_options opt;
    tt_cg_report rj, ri;
    tt_error err;
    int x, y, i, count = 0;
    for (y = 0; y < h; y++)
        for (x = 0; x < w; x++) {
            int v = y * w + x, k;
            static const int dx[4] = {1, -1, 0, 0}, dy[4] = {0, 0, 1, -1};
            t[count].row = t[count].col = v;
            t[count++].value = 1e-3;
            for (k = 0; k < 4; k++) {
                int nx = x + dx[k], ny = y + dy[k];
                double c = dy[k] != 0 && (y % 4 == 0 || ny % 4 == 0) && (dy[k] > 0 ? y % 4 == 0 : ny % 4 == 0) ? 400.0
                                                                                                                : 1.0;
                if (nx < 0 || ny < 0 || nx >= w || ny >= h) continue;
                t[count].row = t[count].col = v;
                t[count++].value = c;
                t[count].row = v;
                t[count].col = ny * w + nx;
                t[count++].value = -c;
            }
        }
    CHECK(tt_sparse_from_triplets(n, n, t, count, NULL, &m, &err) == TT_OK, "grid: %s", err.message);
    lcg_seed(9);
    for (i = 0; i < n; i++) b[i] = lcg_unit() - 0.5;
    memset(&opt, 0, sizeof opt);
    opt.tolerance = 1e-10;
    opt.max_iterations = 20000;
    CHECK(m && tt_cg_solve(m, b, &opt, NULL, xj, &rj, &err) == TT_OK, "Jacobi: %s", err.message);
    opt.preconditioner = TT_CG_INCOMPLETE_CHOLESKY;
    CHECK(m && tt_cg_solve(m, b, &opt, NULL, xi, &ri, &err) == TT_OK, "incomplete Cholesky: %s", err.message);
    for (i = 0; i < n; i++) {
        diff = fmax(diff, fabs(xi[i] - xj[i]));
        scale = fmax(scale, fabs(xj[i]));
    }
    CHECK(ri.preconditioner == TT_CG_INCOMPLETE_CHOLESKY && rj.preconditioner == TT_CG_JACOBI && diff <= 1e-6 * scale &&
              ri.iterations * 3 <= rj.iterations,
          "incomplete Cholesky: %d steps against Jacobi's %d, solutions %g apart (of %g), preconditioners %d and %d",
          ri.iterations, rj.iterations, diff, scale, ri.preconditioner, rj.preconditioner);
    printf("     incomplete Cholesky on a squeezed 30 x 30 grid: %d steps, Jacobi %d\n", ri.iterations, rj.iterations);
    /* The factor against a dense reference: L L^T = A on A's lower pattern. */
    if (m) {
        ic0_check_result check = internal_ic0_check(m);
        CHECK(check.made == 1 && check.worst <= 1e-9, "L L^T against A on its pattern: made %d, worst %g", check.made,
              check.worst);
    }
    /* Kershaw's matrix: positive definite, yet IC(0) meets a negative pivot (-5 at row 3): the solve falls back to
       Jacobi, says so, and still solves. */
    {
        static const double kershaw[16] = {3, -2, 0, 2, -2, 3, -2, 0, 0, -2, 3, -2, 2, 0, -2, 3};
        tt_sparse_matrix *k = cg_small(4, 4, kershaw);
        double kb[4] = {1, 2, 3, 4}, kx[4] = {0, 0, 0, 0};
        tt_cg_report kr;
        opt.preconditioner = TT_CG_INCOMPLETE_CHOLESKY;
        CHECK(k && internal_ic0_check(k).made == 0, "Kershaw's matrix: IC(0) breaks down");
        CHECK(k && tt_cg_solve(k, kb, &opt, NULL, kx, &kr, &err) == TT_OK && kr.preconditioner == TT_CG_JACOBI &&
                  cg_relres(k, kb, kx) <= 1e-9,
              "Kershaw's matrix: solved with Jacobi instead (%s; preconditioner %d, residual %g)", err.message,
              kr.preconditioner, k ? cg_relres(k, kb, kx) : -1.0);
        tt_sparse_matrix_free(k);
    }
    /* Refusals: an unknown preconditioner; columns that do not increase. */
    opt.preconditioner = 2;
    CHECK(m && tt_cg_solve(m, b, &opt, NULL, xi, NULL, &err) == TT_ERROR_INVALID_ARGUMENT &&
              strstr(err.message, "preconditioner") != NULL,
          "preconditioner 2: invalid (%s)", err.message);
    if (m && m->row_start[1] >= 2) {
        /* Row 0's first two entries swapped: the same matrix, its columns out of order. */
        int swap = m->col[0];
        double value = m->value[0];
        m->col[0] = m->col[1];
        m->value[0] = m->value[1];
        m->col[1] = swap;
        m->value[1] = value;
        opt.preconditioner = TT_CG_INCOMPLETE_CHOLESKY;
        CHECK(tt_cg_solve(m, b, &opt, NULL, xi, NULL, &err) == TT_ERROR_INVALID_ARGUMENT && err.row == 0,
              "columns out of order: invalid, naming row 0 (%s, row %d)", err.message, err.row);
        opt.preconditioner = TT_CG_JACOBI;
        CHECK(tt_cg_solve(m, b, &opt, NULL, xi, NULL, &err) == TT_OK, "columns out of order: fine for Jacobi (%s)",
              err.message);
    }
    tt_sparse_matrix_free(m);
    free(t);
    free(b);
    free(xj);
    free(xi);
}

static void test_cg_grid(void)
{
    const int w = 40, h = 30, n = w * h;
    tt_sparse_matrix *m = cg_grid_matrix(w, h, 1.0);
    double *xs = (double *)malloc(sizeof(double) * n), *b = (double *)malloc(sizeof(double) * n);
    double *x = (double *)calloc((size_t)n, sizeof(double)), maxerr = 0.0;
    tt_cg_report rep;
    tt_error err;
    tt_result r;
    int i, iterations;
    counter cnt;
    tt_cg_options opt;
    tt_allocator al = make_allocator(&cnt, -1);
    memset(&opt, 0, sizeof opt);
    if (!m) { CHECK(0, "grid matrix"); free(xs); free(b); free(x); return; }
    CHECK(m->rows == n && m->nnz == n + 2 * ((w - 1) * h + w * (h - 1)), "grid matrix: %d rows, %d entries", m->rows,
          m->nnz);
    lcg_seed(404);
    for (i = 0; i < n; i++) xs[i] = sin(0.1 * (i % w)) * cos(0.13 * (i / w)) + 0.1 * lcg_unit();
    tt_sparse_multiply(m, xs, b, NULL);

    /* Laplacian + identity: condition number < 9, default options. */
    r = tt_cg_solve(m, b, &opt, &al, x, &rep, &err);
    for (i = 0; i < n; i++) maxerr = fmax(maxerr, fabs(x[i] - xs[i]));
    CHECK(r == TT_OK && rep.converged && err.result == TT_OK, "grid: expected TT_OK, got %d (%s)", r, err.message);
    CHECK(rep.residual <= 1e-8 && near(rep.residual, cg_relres(m, b, x), 1e-12),
          "grid: report residual %g, recomputed %g (tolerance 1e-8)", rep.residual, cg_relres(m, b, x));
    CHECK(rep.iterations > 5 && rep.iterations < 60, "grid: %d steps for a condition number below 9", rep.iterations);
    CHECK(maxerr < 1e-7, "grid: |x - x*|_inf = %g", maxerr);
    CHECK(cnt.live == 0 && cnt.calls == 1, "grid: %ld allocation calls (1 expected), %ld live", cnt.calls, cnt.live);
    iterations = rep.iterations;

    /* Warm start from the solution just found: done in 0 or 1 step. */
    r = tt_cg_solve(m, b, &opt, &al, x, &rep, &err);
    CHECK(r == TT_OK && rep.iterations <= 1 && rep.converged, "warm start from the solution: %d, %d steps", r,
          rep.iterations);
    /* Warm start from the exact x*: b = A x* up to rounding, so 0 steps. */
    memcpy(x, xs, sizeof(double) * n);
    r = tt_cg_solve(m, b, &opt, &al, x, &rep, &err);
    CHECK(r == TT_OK && rep.iterations <= 1 && rep.converged, "warm start from x*: %d, %d steps", r, rep.iterations);

    /* A tighter tolerance takes more steps and gets closer. */
    memset(x, 0, sizeof(double) * n);
    opt.tolerance = 1e-13;
    r = tt_cg_solve(m, b, &opt, &al, x, &rep, NULL);
    CHECK(r == TT_OK && rep.iterations > iterations && rep.residual <= 1e-13,
          "tolerance 1e-13: result %d, %d steps (1e-8 took %d), residual %g", r, rep.iterations, iterations,
          rep.residual);

    /* The iteration cap. */
    memset(x, 0, sizeof(double) * n);
    opt.tolerance = 0.0;
    opt.max_iterations = 3;
    r = tt_cg_solve(m, b, &opt, &al, x, &rep, &err);
    CHECK(r == TT_ERROR_NOT_CONVERGED && err.result == r, "cap of 3 steps: expected %d, got %d",
          TT_ERROR_NOT_CONVERGED, r);
    CHECK(rep.iterations == 3 && !rep.converged && rep.residual > 1e-8 && rep.residual < 1.0 &&
              near(rep.residual, cg_relres(m, b, x), 1e-12),
          "cap of 3 steps: report {%d, %g, %d}, recomputed residual %g", rep.iterations, rep.residual, rep.converged,
          cg_relres(m, b, x));
    CHECK(msg_has_number(err.message, 3), "cap message should say 3 steps: %s", err.message);
    CHECK(strcmp(tt_result_string(TT_ERROR_NOT_CONVERGED), tt_result_string((tt_result)-99)) != 0 &&
              strcmp(tt_result_string(TT_ERROR_NOT_POSITIVE_DEFINITE), tt_result_string((tt_result)-99)) != 0 &&
              strcmp(tt_result_string(TT_ERROR_NOT_CONVERGED),
                     tt_result_string(TT_ERROR_NOT_POSITIVE_DEFINITE)) != 0,
          "the two numerics codes need their own sentences");
    CHECK(cnt.live == 0, "grid: %ld allocations leaked", cnt.live);

    /* b = 0: x = 0 at once, whatever x was. */
    for (i = 0; i < n; i++) {
        x[i] = 5.0;
        b[i] = 0.0;
    }
    opt.max_iterations = 0;
    r = tt_cg_solve(m, b, &opt, &al, x, &rep, &err);
    for (i = 0; i < n && x[i] == 0.0; i++) continue;
    CHECK(r == TT_OK && i == n && rep.iterations == 0 && rep.converged && rep.residual == 0.0,
          "b = 0: result %d, %d of %d zeros, %d steps", r, i, n, rep.iterations);

    /* A pure Laplacian (no shift) plus one pinned row is still SPD but badly
       conditioned: the default cap (2n) is enough with Jacobi. */
    tt_sparse_matrix_free(m);
    m = cg_grid_matrix(w, h, 0.0);
    if (!m) { CHECK(0, "grid matrix"); free(xs); free(b); free(x); return; }
    m->value[0] += 1.0;   /* A[0][0] is the first entry of row 0: pin vertex 0 */
    tt_sparse_multiply(m, xs, b, NULL);
    memset(x, 0, sizeof(double) * n);
    r = tt_cg_solve(m, b, NULL, NULL, x, &rep, &err);
    maxerr = 0.0;
    for (i = 0; i < n; i++) maxerr = fmax(maxerr, fabs(x[i] - xs[i]));
    CHECK(r == TT_OK && rep.residual <= 1e-8 && maxerr < 1e-3,
          "pinned Laplacian: result %d, %d steps, residual %g, |x - x*| %g (%s)", r, rep.iterations, rep.residual,
          maxerr, err.message);
    tt_sparse_matrix_free(m);
    free(xs);
    free(b);
    free(x);
}

typedef struct cg_progress_log {
    int calls, cancel_at, decreasing, out_of_range;
    float last;
} cg_progress_log;

static int cg_progress(float fraction, void *user_data)
{
    cg_progress_log *log = (cg_progress_log *)user_data;
    if (fraction < log->last) log->decreasing++;
    if (!(fraction >= 0.0f && fraction <= 1.0f)) log->out_of_range++;
    log->last = fraction;
    log->calls++;
    return log->cancel_at > 0 && log->calls >= log->cancel_at;
}

static void test_cg_progress(void)
{
    const int w = 20, h = 20, n = w * h;
    tt_sparse_matrix *m = cg_grid_matrix(w, h, 0.01);
    double *b = (double *)malloc(sizeof(double) * n), *x = (double *)calloc((size_t)n, sizeof(double));
    cg_progress_log log;
    tt_cg_options opt;
    tt_cg_report rep;
    tt_error err;
    tt_result r;
    counter cnt;
    tt_allocator al = make_allocator(&cnt, -1);
    int i;
    if (!m) { CHECK(0, "grid matrix"); free(b); free(x); return; }
    for (i = 0; i < n; i++) b[i] = (double)(i % 7) - 3.0;
    memset(&opt, 0, sizeof opt);
    memset(&log, 0, sizeof log);
    opt.progress = cg_progress;
    opt.progress_user_data = &log;
    r = tt_cg_solve(m, b, &opt, &al, x, &rep, &err);
    CHECK(r == TT_OK && log.calls == rep.iterations, "progress: result %d, %d calls for %d steps", r, log.calls,
          rep.iterations);
    CHECK(log.decreasing == 0 && log.out_of_range == 0 && log.last > 0.5f,
          "progress: %d decreases, %d outside [0,1], last %g", log.decreasing, log.out_of_range, log.last);
    memset(&log, 0, sizeof log);
    memset(x, 0, sizeof(double) * n);
    log.cancel_at = 5;
    r = tt_cg_solve(m, b, &opt, &al, x, &rep, &err);
    CHECK(r == TT_CANCELLED && err.result == TT_CANCELLED && rep.iterations == 4 && !rep.converged &&
              rep.residual > 0.0 && rep.residual < 1.0,
          "cancel at the 5th call: result %d, %d steps, residual %g", r, rep.iterations, rep.residual);
    CHECK(cnt.live == 0, "cancel: %ld allocations leaked", cnt.live);
    tt_sparse_matrix_free(m);
    free(b);
    free(x);
}

/* tt_cg_solve must fail with `code`, name `row` (-2: do not check), leave x
   alone when `untouched`, and leak nothing. */
static void cg_expect_solve_error(const tt_sparse_matrix *m, const double *b, double *x, const tt_cg_options *o,
                                  tt_result code, int row, int untouched, const char *what)
{
    counter cnt;
    tt_allocator al = make_allocator(&cnt, -1);
    tt_cg_options opt;
    tt_cg_report rep;
    tt_error err;
    tt_result r;
    double keep[8];
    int n = m && m->rows > 0 && m->rows <= 8 ? m->rows : 0, i, same = 1;
    if (o) opt = *o;
    else memset(&opt, 0, sizeof opt);
    if (x && n) memcpy(keep, x, sizeof(double) * n);
    memset(&rep, 0x5a, sizeof rep);
    r = tt_cg_solve(m, b, &opt, &al, x, &rep, &err);
    CHECK(r == code && err.result == code, "%s: expected %d, got %d (%s)", what, code, r, err.message);
    CHECK(err.message[0] != '\0', "%s: empty message", what);
    if (row != -2)
        CHECK(err.row == row && err.vertex == -1 && msg_has_number(err.message, row),
              "%s: should name row %d in error->row (not vertex): row %d, vertex %d, %s", what, row, err.row,
              err.vertex, err.message);
    if (untouched && x && n) {
        for (i = 0; i < n; i++) same &= x[i] == keep[i];
        CHECK(same, "%s: x should be left as it was", what);
    }
    CHECK(!rep.converged && rep.iterations >= 0 && rep.iterations < 100, "%s: report {%d, %g, %d}", what,
          rep.iterations, rep.residual, rep.converged);
    CHECK(cnt.live == 0 && cnt.bad_frees == 0, "%s: %ld allocations leaked", what, cnt.live);
    r = tt_cg_solve(m, b, &opt, &al, x, NULL, NULL);
    CHECK(r == code, "%s with report and error NULL: expected %d, got %d", what, code, r);
    if (x && n) memcpy(x, keep, sizeof(double) * n);
}

static tt_sparse_matrix *cg_small(int rows, int cols, const double *dense)
{
    tt_triplet t[64];
    int i, j, count = 0;
    tt_sparse_matrix *m = NULL;
    for (i = 0; i < rows; i++)
        for (j = 0; j < cols; j++)
            if (dense[i * cols + j] != 0.0) {
                t[count].row = i;
                t[count].col = j;
                t[count].value = dense[i * cols + j];
                count++;
            }
    if (tt_sparse_from_triplets(rows, cols, t, count, NULL, &m, NULL) != TT_OK) m = NULL;
    return m;
}

/* A caller-filled matrix whose row_start rises past nnz and then falls
   ({0, 3, 2}, nnz 2): refused before any entry is read (the arrays hold
   exactly nnz entries, so ASan sees a read past them). */
static void test_cg_row_start_past_entries(void)
{
    tt_sparse_matrix A;
    double b[2] = {1, 1}, x[2] = {0, 0};
    int *row_start = (int *)malloc(3 * sizeof(int)), *col = (int *)malloc(2 * sizeof(int));
    double *value = (double *)malloc(2 * sizeof(double));
    tt_error err;
    tt_result r;
    if (!row_start || !col || !value) { CHECK(0, "malloc"); free(row_start); free(col); free(value); return; }
    row_start[0] = 0; row_start[1] = 3; row_start[2] = 2;
    col[0] = 0; col[1] = 1;
    value[0] = 2.0; value[1] = 2.0;
    memset(&A, 0, sizeof A);
    A.rows = A.cols = 2;
    A.nnz = 2;
    A.row_start = row_start;
    A.col = col;
    A.value = value;
    r = tt_cg_solve(&A, b, NULL, NULL, x, NULL, &err);
    CHECK(r == TT_ERROR_INVALID_ARGUMENT && err.row == 1 && strstr(err.message, "decreases at row 1"),
          "row_start {0, 3, 2}: %d at row %d (\"%s\")", r, err.row, err.message);
    free(row_start);
    free(col);
    free(value);
}

static void test_cg_errors(void)
{
    static const double spd[9] = {4, 1, 0, 1, 3, 1, 0, 1, 2};
    static const double rect[12] = {4, 1, 0, 0, 1, 3, 1, 0, 0, 1, 2, 0};
    static const double zero_diag[9] = {4, 1, 0, 1, 0, 1, 0, 1, 2};
    static const double neg_diag[9] = {4, 1, 0, 1, 3, 1, 0, 1, -2};
    static const double empty_row[9] = {4, 0, 0, 0, 3, 0, 0, 0, 0};
    static const double indefinite[4] = {1, 2, 2, 1};
    double b[3] = {1, 2, 3}, x[3] = {0.5, 0.25, 0.125};
    tt_sparse_matrix *m = cg_small(3, 3, spd), *bad;
    tt_cg_options opt;
    memset(&opt, 0, sizeof opt);
    if (!m) { CHECK(0, "cg_small(spd)"); return; }

    cg_expect_solve_error(NULL, b, x, NULL, TT_ERROR_INVALID_ARGUMENT, -2, 1, "A NULL");
    cg_expect_solve_error(m, NULL, x, NULL, TT_ERROR_INVALID_ARGUMENT, -2, 1, "b NULL");
    cg_expect_solve_error(m, b, NULL, NULL, TT_ERROR_INVALID_ARGUMENT, -2, 1, "x NULL");
    cg_expect_solve_error(m, b, b, NULL, TT_ERROR_INVALID_ARGUMENT, -2, 1, "b == x");
    opt.tolerance = -1.0;
    cg_expect_solve_error(m, b, x, &opt, TT_ERROR_INVALID_ARGUMENT, -2, 1, "tolerance -1");
    opt.tolerance = NAN;
    cg_expect_solve_error(m, b, x, &opt, TT_ERROR_INVALID_ARGUMENT, -2, 1, "tolerance NaN");
    opt.tolerance = 0.0;
    opt.max_iterations = -1;
    cg_expect_solve_error(m, b, x, &opt, TT_ERROR_INVALID_ARGUMENT, -2, 1, "max_iterations -1");

    bad = cg_small(3, 4, rect);
    cg_expect_solve_error(bad, b, x, NULL, TT_ERROR_INVALID_ARGUMENT, -2, 1, "3 x 4 matrix");
    tt_sparse_matrix_free(bad);
    bad = cg_small(3, 3, zero_diag);
    cg_expect_solve_error(bad, b, x, NULL, TT_ERROR_NOT_POSITIVE_DEFINITE, 1, 1, "zero (missing) diagonal in row 1");
    tt_sparse_matrix_free(bad);
    bad = cg_small(3, 3, neg_diag);
    cg_expect_solve_error(bad, b, x, NULL, TT_ERROR_NOT_POSITIVE_DEFINITE, 2, 1, "negative diagonal in row 2");
    tt_sparse_matrix_free(bad);
    bad = cg_small(3, 3, empty_row);
    cg_expect_solve_error(bad, b, x, NULL, TT_ERROR_NOT_POSITIVE_DEFINITE, 2, 1, "empty row 2");
    tt_sparse_matrix_free(bad);
    {
        /* An explicit zero on the diagonal (kept in the pattern). */
        tt_triplet t[4] = {{0, 0, 1.0}, {1, 1, 1.0}, {1, 1, -1.0}, {2, 2, 1.0}};
        bad = NULL;
        tt_sparse_from_triplets(3, 3, t, 4, NULL, &bad, NULL);
        cg_expect_solve_error(bad, b, x, NULL, TT_ERROR_NOT_POSITIVE_DEFINITE, 1, 1, "diagonal summing to 0");
        tt_sparse_matrix_free(bad);
    }

    /* NaN or infinity in A (changed in place), b, x. */
    m->value[3] = NAN;   /* row 1: entries (1,0) (1,1) (1,2) start at 2 */
    cg_expect_solve_error(m, b, x, NULL, TT_ERROR_NON_FINITE, 1, 1, "NaN in A");
    m->value[3] = 3.0;
    b[2] = NAN;
    cg_expect_solve_error(m, b, x, NULL, TT_ERROR_NON_FINITE, 2, 1, "NaN in b");
    b[2] = INFINITY;
    cg_expect_solve_error(m, b, x, NULL, TT_ERROR_NON_FINITE, 2, 1, "inf in b");
    b[2] = 3.0;
    x[1] = -INFINITY;
    cg_expect_solve_error(m, b, x, NULL, TT_ERROR_NON_FINITE, 1, 1, "-inf in the initial guess");
    x[1] = 0.25;

    {
        /* Hand-made CSR with a column out of range, and a broken row_start. */
        int rs[4] = {0, 1, 2, 3}, cl[3] = {0, 3, 2};
        double vl[3] = {1, 1, 1};
        tt_sparse_matrix h;
        memset(&h, 0, sizeof h);
        h.rows = h.cols = 3;
        h.nnz = 3;
        h.row_start = rs;
        h.col = cl;
        h.value = vl;
        cg_expect_solve_error(&h, b, x, NULL, TT_ERROR_INDEX_OUT_OF_RANGE, 1, 1, "column 3 in a 3 x 3 CSR");
        cl[1] = 1;
        rs[1] = 2;
        rs[2] = 1;
        cg_expect_solve_error(&h, b, x, NULL, TT_ERROR_INVALID_ARGUMENT, 1, 1, "row_start decreasing");
        rs[1] = 1;
        rs[2] = 2;
        h.nnz = 2;
        cg_expect_solve_error(&h, b, x, NULL, TT_ERROR_INVALID_ARGUMENT, -2, 1, "nnz != row_start[rows]");
        h.nnz = 3;
        {
            /* unsorted and repeated columns are fine: diagonal 3 + (-1) = 2 */
            int rs2[3] = {0, 3, 5}, cl2[5] = {1, 0, 0, 1, 0};
            double vl2[5] = {1.0, 3.0, -1.0, 3.0, 1.0}, b2[2] = {3.0, 4.0}, x2[2] = {0, 0};
            tt_cg_report rep;
            memset(&rep, 0, sizeof rep);
            h.rows = h.cols = 2;
            h.nnz = 5;
            h.row_start = rs2;
            h.col = cl2;
            h.value = vl2;
            /* [[2,1],[1,3]] x = [3,4]  ->  x = [1, 1] */
            CHECK(tt_cg_solve(&h, b2, NULL, NULL, x2, &rep, NULL) == TT_OK && near(x2[0], 1.0, 1e-9) &&
                      near(x2[1], 1.0, 1e-9) && rep.iterations <= 2,
                  "unsorted CSR with repeated columns: x = %g %g in %d steps", x2[0], x2[1], rep.iterations);
        }
    }

    /* Positive diagonal but indefinite: breakdown at step 1 (p . A p = -12). */
    bad = cg_small(2, 2, indefinite);
    b[1] = 0.0;
    x[0] = x[1] = 0.0;
    cg_expect_solve_error(bad, b, x, NULL, TT_ERROR_NOT_POSITIVE_DEFINITE, -2, 0, "indefinite 2 x 2");
    tt_sparse_matrix_free(bad);
    b[1] = 2.0;

    {
        /* 0 x 0 and 1 x 1 systems. */
        tt_sparse_matrix *e = NULL;
        tt_cg_report rep;
        double one = 4.0, sol = 0.0;
        tt_sparse_from_triplets(0, 0, NULL, 0, NULL, &e, NULL);
        CHECK(e && tt_cg_solve(e, b, NULL, NULL, x, &rep, NULL) == TT_OK && rep.converged && rep.iterations == 0,
              "0 x 0 system: should succeed at once");
        tt_sparse_matrix_free(e);
        e = cg_small(1, 1, &one);
        CHECK(e && tt_cg_solve(e, b, NULL, NULL, &sol, &rep, NULL) == TT_OK && near(sol, 0.25, 1e-15) &&
                  rep.iterations == 1,
              "1 x 1: 4 x = 1 gave %g in %d steps", sol, rep.iterations);
        tt_sparse_matrix_free(e);
    }
    tt_sparse_matrix_free(m);
}

typedef struct cg_oom_ctx {
    const tt_triplet *t;
    int n, count;
    const double *b;
    int preconditioner;
} cg_oom_ctx;

static tt_result cg_oom_triplets(void *ctx, const tt_allocator *al, tt_error *error)
{
    cg_oom_ctx *c = (cg_oom_ctx *)ctx;
    tt_sparse_matrix *m = (tt_sparse_matrix *)&m;
    tt_result r = tt_sparse_from_triplets(c->n, c->n, c->t, c->count, al, &m, error);
    if (r == TT_OK) tt_sparse_matrix_free(m);
    else if (m != NULL || error->result != r) return TT_RESULT_MAX_ENUM;
    return r;
}

static tt_result cg_oom_solve(void *ctx, const tt_allocator *al, tt_error *error)
{
    cg_oom_ctx *c = (cg_oom_ctx *)ctx;
    tt_sparse_matrix *m = NULL;
    tt_result r;
    double x[64];
    memset(x, 0, sizeof x);
    if (tt_sparse_from_triplets(c->n, c->n, c->t, c->count, NULL, &m, NULL) != TT_OK) return TT_RESULT_MAX_ENUM;
    {
        tt_cg_options opt;
        memset(&opt, 0, sizeof opt);
        opt.preconditioner = c->preconditioner;
        r = tt_cg_solve(m, c->b, &opt, al, x, NULL, error);
    }
    if (r != TT_OK && error->result != r) r = TT_RESULT_MAX_ENUM;
    tt_sparse_matrix_free(m);
    return r;
}

static void test_cg_oom(void)
{
    tt_triplet t[2000];
    double b[64];
    cg_oom_ctx c;
    int i;
    lcg_seed(405);
    c.n = 40;
    c.count = cg_random_spd(c.n, t, 2000);
    c.t = t;
    for (i = 0; i < 64; i++) b[i] = lcg_unit();
    c.b = b;
    c.preconditioner = TT_CG_JACOBI;
    oom_reset();
    oom_sweep("tt_sparse_from_triplets(40 x 40)", cg_oom_triplets, &c, TT_OK);
    oom_sweep("tt_cg_solve(40 x 40)", cg_oom_solve, &c, TT_OK);
    c.preconditioner = TT_CG_INCOMPLETE_CHOLESKY;
    oom_sweep("tt_cg_solve(40 x 40, incomplete Cholesky)", cg_oom_solve, &c, TT_OK);
    c.preconditioner = TT_CG_JACOBI;
    for (i = 0; i < 64; i++) b[i] = 0.0;
    oom_sweep("tt_cg_solve(b = 0)", cg_oom_solve, &c, TT_OK);
}

/* ------------------------------------------------------------------------ */
/* Multigrid-preconditioned conjugate gradients (private, section 4)        */
/* ------------------------------------------------------------------------ */

/* The 5-point Laplacian of a w x h grid, Neumann, every fourth row of cells
   squeezed (couplings `squeeze` times stronger across them: strong and weak
   connections, as slivers give), plus `shift` on the diagonal. */
static tt_sparse_matrix *amg_grid(int w, int h, double squeeze, double shift)
{
    tt_triplet *t = (tt_triplet *)malloc(sizeof(tt_triplet) * (size_t)w * h * 9);
    tt_sparse_matrix *m = NULL;
    int x, y, count = 0;
    for (y = 0; y < h; y++)
        for (x = 0; x < w; x++) {
            static const int dx[4] = {1, -1, 0, 0}, dy[4] = {0, 0, 1, -1};
            int v = y * w + x, k;
            t[count].row = t[count].col = v;
            t[count++].value = shift;
            for (k = 0; k < 4; k++) {
                int nx = x + dx[k], ny = y + dy[k];
                double c = dy[k] != 0 && (dy[k] > 0 ? y % 4 == 0 : ny % 4 == 0) ? squeeze : 1.0;
                if (nx < 0 || ny < 0 || nx >= w || ny >= h) continue;
                t[count].row = t[count].col = v;
                t[count++].value = c;
                t[count].row = v;
                t[count].col = ny * w + nx;
                t[count++].value = -c;
            }
        }
    if (tt_sparse_from_triplets(w * h, w * h, t, count, NULL, &m, NULL) != TT_OK) m = NULL;
    free(t);
    return m;
}

/* Two right-hand sides on grid Laplacians from 32 x 32 to 128 x 128 (the
   Neumann Laplacian with a small shift, as the lapped alignment's seed
   penalty leaves it nearly singular; plain and squeezed): the solutions
   match tt_cg_solve's (tolerance 1e-11) within what the tolerance allows,
   and the steps do not grow with the size; an exact zero right-hand side
   gives x = 0; a step cap gives TT_ERROR_NOT_CONVERGED with the last
   iterate; a zero diagonal is refused. */
static void test_amg_grid(void)
{
    static const int sides[3] = {32, 64, 128};
    int squeezed, level, steps[2][3] = {{0, 0, 0}, {0, 0, 0}}, levels = 0;
    for (squeezed = 0; squeezed < 2; squeezed++)
        for (level = 0; level < 3; level++) {
            const int side = sides[level], n = side * side;
            tt_sparse_matrix *m = amg_grid(side, side, squeezed ? 400.0 : 1.0, 1e-2);
            double *b = (double *)malloc(sizeof(double) * 2 * (size_t)n), *x = (double *)calloc(2 * (size_t)n, 8);
            double *one = (double *)malloc(sizeof(double) * (size_t)n), *ref = (double *)calloc((size_t)n, 8);
            double worst = 0.0, scale = 0.0;
            tt_cg_options cg;
            tt_result r;
            int i, c;
            if (!m) {
                CHECK(0, "amg grid %d: the matrix", side);
                free(b); free(x); free(one); free(ref);
                continue;
            }
            lcg_seed(77u + (unsigned)level);
            for (i = 0; i < 2 * n; i++) b[i] = lcg_unit() - 0.5;
            r = internal_amg_solve2(m, b, x, 1e-8, 100, NULL, &levels, &steps[squeezed][level]);
            CHECK(r == TT_OK && levels >= 2, "amg grid %d%s: %d, %d levels", side, squeezed ? " squeezed" : "", (int)r,
                  levels);
            memset(&cg, 0, sizeof cg);
            cg.tolerance = 1e-11;
            cg.max_iterations = 100000;
            cg.preconditioner = TT_CG_INCOMPLETE_CHOLESKY;
            for (c = 0; c < 2; c++) {
                for (i = 0; i < n; i++) one[i] = b[2 * i + c];
                memset(ref, 0, sizeof(double) * (size_t)n);
                CHECK(tt_cg_solve(m, one, &cg, NULL, ref, NULL, NULL) == TT_OK, "amg grid %d: the reference", side);
                for (i = 0; i < n; i++) {
                    worst = fmax(worst, fabs(x[2 * i + c] - ref[i]));
                    scale = fmax(scale, fabs(ref[i]));
                }
            }
            /* relative residual 1e-8 and a condition number up to 3e5 (the squeezed grid): 3e-3 of the solution's
               size at most */
            CHECK(worst <= 3e-3 * scale, "amg grid %d%s: |x - x_ref| up to %g of %g", side, squeezed ? " squeezed" : "",
                  worst, scale);
            tt_sparse_matrix_free(m);
            free(b); free(x); free(one); free(ref);
        }
    for (squeezed = 0; squeezed < 2; squeezed++)
        CHECK(steps[squeezed][0] > 0 && steps[squeezed][2] <= steps[squeezed][0] + 4 && steps[squeezed][2] <= 30,
              "amg grid%s: %d, %d, %d steps for 1k, 4k, 16k unknowns (want no growth: at most 4 more, and at most 30)",
              squeezed ? " squeezed" : "", steps[squeezed][0], steps[squeezed][1], steps[squeezed][2]);
    printf("     multigrid CG to 1e-8 on 32^2 / 64^2 / 128^2 grids: %d / %d / %d steps (squeezed rows: %d / %d / %d)\n",
           steps[0][0], steps[0][1], steps[0][2], steps[1][0], steps[1][1], steps[1][2]);
    {
        tt_sparse_matrix *m = amg_grid(40, 40, 1.0, 1e-4);
        double b[2 * 1600], x[2 * 1600], first;
        int i, got, lv;
        tt_result r;
        lcg_seed(5);
        for (i = 0; i < 1600; i++) {
            b[2 * i] = 0.0;
            b[2 * i + 1] = lcg_unit() - 0.5;
            x[2 * i] = x[2 * i + 1] = 1.0;
        }
        r = internal_amg_solve2(m, b, x, 1e-8, 100, NULL, &lv, &got);
        for (i = 0, first = 0.0; i < 1600; i++) first = fmax(first, fabs(x[2 * i]));
        CHECK(r == TT_OK && first == 0.0, "amg: b = 0 in the first column gives x = 0 there: %d, |x| up to %g", (int)r,
              first);
        for (i = 0; i < 2 * 1600; i++) x[i] = 0.0;
        for (i = 0; i < 1600; i++) b[2 * i] = b[2 * i + 1];
        r = internal_amg_solve2(m, b, x, 1e-14, 1, NULL, &lv, &got);
        for (i = 0, first = 0.0; i < 1600; i++) first = fmax(first, fabs(x[2 * i]));
        CHECK(r == TT_ERROR_NOT_CONVERGED && got == 1 && first > 0.0,
              "amg: one step allowed: %d after %d steps (want TT_ERROR_NOT_CONVERGED after 1, x moved: %g)", (int)r, got,
              first);
        /* A zero diagonal: not positive definite. */
        for (i = 0; i < m->row_start[1]; i++)
            if (m->col[i] == 0) m->value[i] = 0.0;
        r = internal_amg_solve2(m, b, x, 1e-8, 100, NULL, &lv, &got);
        CHECK(r == TT_ERROR_NOT_POSITIVE_DEFINITE, "amg: a zero diagonal: %d (want TT_ERROR_NOT_POSITIVE_DEFINITE)",
              (int)r);
        tt_sparse_matrix_free(m);
    }
}

typedef struct amg_oom_ctx {
    const tt_sparse_matrix *m;
    const double *b;
} amg_oom_ctx;

static tt_result amg_oom_call(void *ctx, const tt_allocator *al, tt_error *error)
{
    amg_oom_ctx *c = (amg_oom_ctx *)ctx;
    (void)error;   /* a private helper: it returns a code, no tt_error */
    double x[2 * 900];
    int levels, steps;
    memset(x, 0, sizeof x);
    return internal_amg_solve2(c->m, c->b, x, 1e-8, 100, al, &levels, &steps);
}

/* Every allocation of the hierarchy and the solve failing in turn:
   TT_ERROR_OUT_OF_MEMORY, nothing leaked. */
static void test_amg_oom(void)
{
    amg_oom_ctx c;
    tt_sparse_matrix *m = amg_grid(30, 30, 400.0, 1e-4);
    double b[2 * 900];
    int i;
    lcg_seed(6);
    for (i = 0; i < 2 * 900; i++) b[i] = lcg_unit() - 0.5;
    c.m = m;
    c.b = b;
    oom_reset();
    if (m) oom_sweep_internal("multigrid CG (30 x 30)", amg_oom_call, &c, TT_OK);
    tt_sparse_matrix_free(m);
}

/* ------------------------------------------------------------------------ */
/* Hostile right-hand sides and entries (the cases)                 */
/* ------------------------------------------------------------------------ */

/* Solve A x = b (A dense n x n, SPD) with tt_cg_solve from x = 0 and with
   the dense Cholesky reference; returns max |x - x_ref| / max |x_ref| (or
   -1 when the solve did not converge) and fills *rep. */
static double cg_solve_vs_dense(const double *dense, int n, const double *b, double *x, tt_cg_report *rep,
                                tt_result *result, double *ref)
{
    double *chol = (double *)malloc(sizeof(double) * (size_t)n * n), num = 0.0, den = 0.0;
    tt_sparse_matrix *m = cg_small(n, n, dense);
    int i;
    memcpy(chol, dense, sizeof(double) * (size_t)n * n);
    *result = TT_RESULT_MAX_ENUM;
    memset(rep, 0, sizeof *rep);
    if (!m || !cg_dense_cholesky_solve(chol, n, b, ref)) {
        free(chol);
        tt_sparse_matrix_free(m);
        return -2.0;
    }
    memset(x, 0, sizeof(double) * (size_t)n);
    *result = tt_cg_solve(m, b, NULL, NULL, x, rep, NULL);
    for (i = 0; i < n; i++) {
        num = fmax(num, fabs(x[i] - ref[i]));
        den = fmax(den, fabs(ref[i]));
    }
    free(chol);
    tt_sparse_matrix_free(m);
    return den > 0.0 ? num / den : num;
}

static void test_cg_hostile_rhs(void)
{
    static const double a2[4] = {4, 1, 1, 3};
    static const double a5[25] = {10, 1, 0, 2, 0,  1, 8, 1, 0, 0,  0, 1, 6, 1, 1,  2, 0, 1, 9, 3,  0, 0, 1, 3, 7};
    double x[5], ref[5], b[5], rel;
    tt_cg_report rep;
    tt_result r;
    int i, k;

    /* b = (1e155, 1): |b|^2 overflows double without scaling. */
    b[0] = 1e155;
    b[1] = 1.0;
    rel = cg_solve_vs_dense(a2, 2, b, x, &rep, &r, ref);
    CHECK(r == TT_OK && rep.converged && rep.iterations > 0 && rel >= 0.0 && rel <= 1e-8 && x[0] != 0.0,
          "b = (1e155, 1): result %d, %d steps, x = (%g, %g), reference (%g, %g), relative error %g", r,
          rep.iterations, x[0], x[1], ref[0], ref[1], rel);
    /* the same on 5 unknowns, mixed signs and sizes */
    b[0] = 1e155; b[1] = 1.0; b[2] = -3e154; b[3] = 1e-10; b[4] = 7e153;
    rel = cg_solve_vs_dense(a5, 5, b, x, &rep, &r, ref);
    CHECK(r == TT_OK && rep.converged && rel >= 0.0 && rel <= 1e-7,
          "b = (1e155, 1, -3e154, 1e-10, 7e153): result %d, %d steps, relative error %g", r, rep.iterations, rel);
    /* near the top of the double range: b_i = 1e300 */
    for (i = 0; i < 5; i++) b[i] = (i % 2 ? -1e300 : 1e300);
    rel = cg_solve_vs_dense(a5, 5, b, x, &rep, &r, ref);
    CHECK(r == TT_OK && rep.converged && rel >= 0.0 && rel <= 1e-7, "b = +-1e300: result %d, relative error %g", r,
          rel);

    /* All |b_i| below 1e-162: |b|^2 underflows to 0 without scaling, and
       x = 0 would look converged. x must be the reference times 1e-200. */
    for (k = 0; k < 2; k++) {
        const double *a = k ? a5 : a2;
        int n = k ? 5 : 2;
        double normal[5] = {1.0, -2.0, 0.5, 3.0, -1.25}, xn[5], refn[5], worst = 0.0, top = 0.0;
        tt_result rn;
        tt_cg_report repn;
        cg_solve_vs_dense(a, n, normal, xn, &repn, &rn, refn);
        for (i = 0; i < n; i++) b[i] = normal[i] * 1e-200;
        cg_solve_vs_dense(a, n, b, x, &rep, &r, ref);
        for (i = 0; i < n; i++) {
            worst = fmax(worst, fabs(x[i] - refn[i] * 1e-200));
            top = fmax(top, fabs(refn[i] * 1e-200));
        }
        CHECK(rn == TT_OK && r == TT_OK && rep.converged && rep.iterations > 0 && top > 0.0 && worst <= 1e-6 * top,
              "%d x %d, b = 1e-200 * normal b: result %d, %d steps, converged %d, x[0] = %g (expected %g), "
              "max error %g of %g", n, n, r, rep.iterations, rep.converged, x[0], refn[0] * 1e-200, worst, top);
    }
    /* denormal b: 1e-310 */
    b[0] = 1e-310;
    b[1] = -4e-310;
    rel = cg_solve_vs_dense(a2, 2, b, x, &rep, &r, ref);
    CHECK(r == TT_OK && rep.converged && rep.iterations > 0 && x[0] != 0.0,
          "subnormal b = (1e-310, -4e-310): result %d, %d steps, x = (%g, %g), reference (%g, %g)", r, rep.iterations,
          x[0], x[1], ref[0], ref[1]);

    /* b = 0: x = 0 exactly, at once, from any start. */
    {
        tt_sparse_matrix *m = cg_small(5, 5, a5);
        double zero[5] = {0, 0, 0, 0, -0.0};
        for (i = 0; i < 5; i++) x[i] = 1.0 + i;
        r = m ? tt_cg_solve(m, zero, NULL, NULL, x, &rep, NULL) : TT_RESULT_MAX_ENUM;
        for (i = 0; i < 5 && x[i] == 0.0; i++) continue;
        CHECK(r == TT_OK && i == 5 && rep.converged && rep.iterations == 0 && rep.residual == 0.0,
              "b = 0: result %d, %d of 5 zeros, %d steps", r, i, rep.iterations);
        tt_sparse_matrix_free(m);
    }
}

/* Finite triplets of one entry whose sum overflows: TT_ERROR_NON_FINITE
   naming the entry (row, column) and the triplet (item), *out NULL, no leak. */
static void test_cg_triplet_overflow(void)
{
    tt_triplet t[5] = {{0, 0, 1.0}, {1, 2, 1e308}, {2, 2, 5.0}, {1, 0, 2.0}, {1, 2, 1e308}};
    counter cnt;
    tt_allocator al = make_allocator(&cnt, -1);
    tt_sparse_matrix *m = (tt_sparse_matrix *)&m;
    tt_error err;
    tt_result r;
    int sign;
    for (sign = 0; sign < 2; sign++) {
        t[1].value = t[4].value = sign ? -1e308 : 1e308;
        memset(&err, 0x5a, sizeof err);
        m = (tt_sparse_matrix *)&m;
        r = tt_sparse_from_triplets(3, 3, t, 5, &al, &m, &err);
        CHECK(r == TT_ERROR_NON_FINITE && err.result == r && m == NULL,
              "%s1e308 twice on entry (1, 2): expected TT_ERROR_NON_FINITE and *out NULL, got %d", sign ? "-" : "", r);
        CHECK(err.row == 1 && err.column == 2 && err.vertex == -1 && err.other_vertex == -1,
              "overflowing entry: row/column expected 1/2, got %d/%d (vertex %d, other_vertex %d)", err.row,
              err.column, err.vertex, err.other_vertex);
        CHECK(err.item == 4 || err.item == 1, "overflowing entry: item should name triplet 4 (or 1), got %d",
              err.item);
        CHECK(err.message[0] != '\0' && msg_has_number(err.message, 1) && msg_has_number(err.message, 2),
              "overflowing entry: the message should name row 1 and column 2: %s", err.message);
        CHECK(cnt.live == 0 && cnt.bad_frees == 0, "overflowing entry: %ld allocations leaked", cnt.live);
    }
    /* Large but finite sums are fine: 1e308 + (-1e308) = 0 stays in the pattern. */
    t[1].value = 1e308;
    t[4].value = -1e308;
    m = NULL;
    r = tt_sparse_from_triplets(3, 3, t, 5, &al, &m, &err);
    CHECK(r == TT_OK && m && m->nnz == 4, "1e308 - 1e308: result %d, nnz %d", r, m ? m->nnz : -1);
    tt_sparse_matrix_free(m);
    CHECK(cnt.live == 0, "triplet overflow: %ld allocations leaked", cnt.live);
}

typedef struct overflow_ctx {
    const tt_triplet *t;
    int count;
} overflow_ctx;

static tt_result cg_oom_overflow(void *ctx, const tt_allocator *al, tt_error *error)
{
    overflow_ctx *c = (overflow_ctx *)ctx;
    tt_sparse_matrix *m = (tt_sparse_matrix *)&m;
    tt_result r = tt_sparse_from_triplets(3, 3, c->t, c->count, al, &m, error);
    if (r == TT_OK) tt_sparse_matrix_free(m);
    else if (m != NULL || error->result != r) return TT_RESULT_MAX_ENUM;
    return r;
}

/* Errors about matrix entries come in error->row / column, not in vertex. */
static void test_cg_entry_errors(void)
{
    static const double spd[9] = {4, 1, 0, 1, 3, 1, 0, 1, 2};
    tt_sparse_matrix *m = cg_small(3, 3, spd);
    double b[3] = {1, 2, 3}, x[3] = {0, 0, 0};
    tt_error err;
    if (!m) { CHECK(0, "cg_small"); return; }
    m->value[4] = INFINITY;   /* row 1: (1,0) (1,1) (1,2) are entries 2, 3, 4 */
    CHECK(tt_cg_solve(m, b, NULL, NULL, x, NULL, &err) == TT_ERROR_NON_FINITE && err.row == 1 && err.column == 2 &&
              err.vertex == -1 && err.other_vertex == -1 && err.face == -1,
          "inf at (1, 2): row %d, column %d, vertex %d, other_vertex %d", err.row, err.column, err.vertex,
          err.other_vertex);
    m->value[4] = 1.0;
    m->value[6] = -2.0;   /* A[2][2]: row 2 is entries 5 (2,1) and 6 (2,2) */
    CHECK(tt_cg_solve(m, b, NULL, NULL, x, NULL, &err) == TT_ERROR_NOT_POSITIVE_DEFINITE && err.row == 2 &&
              err.vertex == -1,
          "negative diagonal in row 2: row %d, column %d, vertex %d", err.row, err.column, err.vertex);
    m->value[6] = 2.0;
    b[1] = NAN;
    CHECK(tt_cg_solve(m, b, NULL, NULL, x, NULL, &err) == TT_ERROR_NON_FINITE && err.row == 1 && err.vertex == -1,
          "NaN in b[1]: row %d, vertex %d", err.row, err.vertex);
    b[1] = 2.0;
    {
        tt_triplet t[2] = {{0, 0, 1.0}, {0, 3, 1.0}};
        tt_sparse_matrix *out = (tt_sparse_matrix *)&out;
        CHECK(tt_sparse_from_triplets(3, 3, t, 2, NULL, &out, &err) == TT_ERROR_INDEX_OUT_OF_RANGE && out == NULL &&
                  err.row == 0 && err.column == 3 && err.item == 1 && err.vertex == -1 && err.other_vertex == -1,
              "triplet 1 at (0, 3) of a 3 x 3: row %d, column %d, item %d, vertex %d", err.row, err.column, err.item,
              err.vertex);
    }
    {
        overflow_ctx c;
        static const tt_triplet t[5] = {{0, 0, 1.0}, {1, 2, 1e308}, {2, 2, 5.0}, {1, 0, 2.0}, {1, 2, 1e308}};
        c.t = t;
        c.count = 5;
        oom_reset();
        oom_sweep("tt_sparse_from_triplets(overflowing entry)", cg_oom_overflow, &c, TT_ERROR_NON_FINITE);
    }
    tt_sparse_matrix_free(m);
}

void run_numerics_tests(void)
{
    RUN(test_cg_triplets);
    RUN(test_cg_row_start_past_entries);
    RUN(test_cg_triplet_errors);
    RUN(test_cg_multiply);
    RUN(test_cg_random_spd);
    RUN(test_cg_grid);
    RUN(test_cg_incomplete_cholesky);
    RUN(test_cg_progress);
    RUN(test_cg_errors);
    RUN(test_cg_oom);
    RUN(test_amg_grid);
    RUN(test_amg_oom);
    RUN(test_cg_hostile_rhs);
    RUN(test_cg_triplet_overflow);
    RUN(test_cg_entry_errors);
}
