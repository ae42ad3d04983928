/* tests/test_common.c - the shared part of the unit tests of tiledtex.h
   (declared in tests/test_common.h), the one file that compiles the
   implementation, and main(). Built with tests/test_[1-7]_*.c into one
   program by tests/run.sh (with ASan + UBSan). Prints one line per failed
   check and, last, "N passed, M failed". Does not read any file. */
#define TILEDTEX_IMPLEMENTATION
#define _POSIX_C_SOURCE 200809L   /* POSIX threads under -std=c99, for g_thread_executor */
#include "tiledtex.h"

#include "test_common.h"

#include <math.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ------------------------------------------------------------------------ */
/* Framework                                                                */
/* ------------------------------------------------------------------------ */

int g_passed, g_failed;
const char *g_test = "";

void check_report(int ok, const char *file, int line, const char *what, const char *fmt, ...)
{
    va_list args;
    if (ok) { g_passed++; return; }
    g_failed++;
    printf("%s:%d: FAIL in %s: %s: ", file, line, g_test, what);
    va_start(args, fmt);
    vprintf(fmt, args);
    va_end(args);
    printf("\n");
    fflush(stdout);
}

void check_detail(const char *file, int line, const char *fmt, ...)
{
    va_list args;
    printf("%s:%d: detail in %s: ", file, line, g_test);
    va_start(args, fmt);
    vprintf(fmt, args);
    va_end(args);
    printf("\n");
}

/* ------------------------------------------------------------------------ */
/* Counting and failing allocators                                          */
/* ------------------------------------------------------------------------ */

typedef union header {
    size_t size;
    long double ld;
    void *p;
    long long ll;
    double d;
} header;

#define MAGIC 0x7474u

static void *counting_alloc(size_t size, void *user_data)
{
    counter *c = (counter *)user_data;
    header *h;
    long call = c->calls++;
    if (c->fail_at >= 0 && call == c->fail_at) { c->failures++; return NULL; }
    h = (header *)malloc(sizeof(header) * 2 + size);
    if (!h) return NULL;
    h[0].size = size;
    h[1].size = MAGIC;
    c->live++;
    c->live_bytes += size;
    return h + 2;
}

static void counting_free(void *ptr, void *user_data)
{
    counter *c = (counter *)user_data;
    header *h;
    if (!ptr) return;
    h = (header *)ptr - 2;
    if (h[1].size != MAGIC) { c->bad_frees++; return; }
    h[1].size = 0;
    c->live--;
    c->live_bytes -= h[0].size;
    free(h);
}

tt_allocator make_allocator(counter *c, long fail_at)
{
    tt_allocator a;
    memset(c, 0, sizeof *c);
    c->fail_at = fail_at;
    a.alloc = counting_alloc;
    a.free = counting_free;
    a.user_data = c;
    return a;
}

/* ------------------------------------------------------------------------ */
/* Allocation-failure sweep                                                 */
/* ------------------------------------------------------------------------ */

counter g_oom_counter;
tt_allocator g_oom_allocator;

void oom_reset(void) { g_oom_allocator = make_allocator(&g_oom_counter, -1); }

static void sweep(const char *what, oom_call call, void *ctx, tt_result expected_final, int check_error)
{
    int k, bad_result = 0, leaks = 0, bad_frees = 0, unfilled = 0, nsteps = 0;
    tt_result r = TT_ERROR_OUT_OF_MEMORY, first_bad = TT_OK;
    counter *cnt = &g_oom_counter;
    tt_error error;
    for (k = 0; k < 100000; k++) {
        long live0 = cnt->live, bad0 = cnt->bad_frees;
        cnt->calls = 0;
        cnt->failures = 0;
        cnt->fail_at = k;
        memset(&error, 0x5a, sizeof error);   /* an unfilled error keeps this */
        r = call(ctx, &g_oom_allocator, &error);
        nsteps++;
        if (cnt->live != live0) leaks++;
        if (cnt->bad_frees != bad0) bad_frees++;
        if (cnt->failures == 0) break;   /* allocation k was never reached: the run is complete */
        if (r != TT_ERROR_OUT_OF_MEMORY) { if (!bad_result) first_bad = r; bad_result++; }
        else if (check_error && (error.result != r || !memchr(error.message, 0, sizeof error.message) ||
                                 strlen(error.message) < 8 || error.message[0] == 0x5a)) {
            if (!unfilled) DETAIL("%s: allocation %d failed, the error was not filled", what, k);
            unfilled++;
        }
    }
    cnt->fail_at = -1;
    CHECK(r == expected_final, "%s: after %d allocation-failure runs, expected final result %d, got %d", what, nsteps,
          expected_final, r);
    CHECK(bad_result == 0, "%s: %d runs with a failed allocation did not return TT_ERROR_OUT_OF_MEMORY (first: %d)",
          what, bad_result, first_bad);
    CHECK(unfilled == 0, "%s: %d runs returned TT_ERROR_OUT_OF_MEMORY with the tt_error unfilled", what, unfilled);
    CHECK(leaks == 0 && bad_frees == 0, "%s: %d runs leaked, %d freed foreign pointers", what, leaks, bad_frees);
    CHECK(nsteps > 1, "%s: expected at least one allocation, got %d runs", what, nsteps);
}

void oom_sweep(const char *what, oom_call call, void *ctx, tt_result expected_final)
{
    sweep(what, call, ctx, expected_final, 1);
}

void oom_sweep_internal(const char *what, oom_call call, void *ctx, tt_result expected_final)
{
    sweep(what, call, ctx, expected_final, 0);
}

/* ------------------------------------------------------------------------ */
/* Small helpers                                                            */
/* ------------------------------------------------------------------------ */

int near(double a, double b, double tol) { return fabs(a - b) <= tol; }

static unsigned long long g_lcg = 1;

void lcg_seed(unsigned long long s) { g_lcg = s * 2862933555777941757ull + 3037000493ull; }
unsigned lcg_next(void)
{
    g_lcg = g_lcg * 6364136223846793005ull + 1442695040888963407ull;
    return (unsigned)(g_lcg >> 33);
}
int lcg_below(int n) { return (int)(lcg_next() % (unsigned)n); }
double lcg_unit(void) { return (double)lcg_next() / 2147483648.0; }

void hostile_order(double *values, int n, int pattern)
{
    int i;
    for (i = 0; i < n; i++) {
        switch (pattern) {
        case 0: values[i] = lcg_unit(); break;
        case 1: values[i] = (double)(int)(4.0 * lcg_unit()); break;
        case 2: values[i] = i; break;
        case 3: values[i] = n - i; break;
        case 4: values[i] = 1.5; break;
        default: values[i] = i < n / 2 ? i : n - i; break;
        }
    }
}

int msg_has_number(const char *msg, int n)
{
    char buf[32];
    const char *p = msg;
    size_t len;
    sprintf(buf, "%d", n);
    len = strlen(buf);
    while ((p = strstr(p, buf)) != NULL) {
        int before_ok = p == msg || !(p[-1] >= '0' && p[-1] <= '9') || n < 0;
        int after_ok = !(p[len] >= '0' && p[len] <= '9');
        if (before_ok && after_ok) return 1;
        p++;
    }
    return 0;
}

/* ------------------------------------------------------------------------ */
/* Hand-made meshes                                                         */
/* ------------------------------------------------------------------------ */

void tm_free(tmesh *m)
{
    free(m->pos);
    free(m->idx);
    free(m->sizes);
    memset(m, 0, sizeof *m);
}

int tm_vert(tmesh *m, double x, double y, double z)
{
    if (m->nv == m->cap_v) {
        m->cap_v = m->cap_v ? 2 * m->cap_v : 16;
        m->pos = (float *)realloc(m->pos, sizeof(float) * 3 * (size_t)m->cap_v);
    }
    m->pos[3 * m->nv] = (float)x;
    m->pos[3 * m->nv + 1] = (float)y;
    m->pos[3 * m->nv + 2] = (float)z;
    return m->nv++;
}

void tm_face(tmesh *m, int n, const int *v)
{
    int i;
    if (m->nf == m->cap_f) {
        m->cap_f = m->cap_f ? 2 * m->cap_f : 16;
        m->sizes = (int *)realloc(m->sizes, sizeof(int) * (size_t)m->cap_f);
    }
    while (m->nc + n > m->cap_c) {
        m->cap_c = m->cap_c ? 2 * m->cap_c : 64;
        m->idx = (int *)realloc(m->idx, sizeof(int) * (size_t)m->cap_c);
    }
    for (i = 0; i < n; i++) m->idx[m->nc + i] = v[i];
    m->nc += n;
    m->sizes[m->nf++] = n;
}

void tm_tri(tmesh *m, int a, int b, int c) { int v[3]; v[0] = a; v[1] = b; v[2] = c; tm_face(m, 3, v); }
void tm_quad(tmesh *m, int a, int b, int c, int d)
{
    int v[4];
    v[0] = a; v[1] = b; v[2] = c; v[3] = d;
    tm_face(m, 4, v);
}

tt_mesh_desc tm_desc(const tmesh *m)
{
    tt_mesh_desc d;
    memset(&d, 0, sizeof d);
    d.positions = m->pos;
    d.nverts = m->nv;
    d.indices = m->idx;
    d.face_sizes = m->sizes;
    d.nfaces = m->nf;
    return d;
}

void make_tetra(tmesh *m, double ox)
{
    int a = tm_vert(m, ox + 0, 0, 0), b = tm_vert(m, ox + 1, 0, 0), c = tm_vert(m, ox + 0, 1, 0),
        d = tm_vert(m, ox + 0, 0, 1);
    tm_tri(m, a, c, b);
    tm_tri(m, a, b, d);
    tm_tri(m, a, d, c);
    tm_tri(m, b, c, d);
}

void make_torus(tmesh *m, int nu, int nv, double R, double r)
{
    int i, j, base = m->nv;
    const double pi = 3.14159265358979323846;
    for (j = 0; j < nv; j++)
        for (i = 0; i < nu; i++) {
            double a = 2 * pi * i / nu, b = 2 * pi * j / nv;
            tm_vert(m, (R + r * cos(b)) * cos(a), (R + r * cos(b)) * sin(a), r * sin(b));
        }
    for (j = 0; j < nv; j++)
        for (i = 0; i < nu; i++) {
            int i1 = (i + 1) % nu, j1 = (j + 1) % nv;
            tm_quad(m, base + j * nu + i, base + j * nu + i1, base + j1 * nu + i1, base + j1 * nu + i);
        }
}

/* Open nx x ny grid of unit quads in the plane z = 0. */
void make_grid(tmesh *m, int nx, int ny)
{
    int i, j, base = m->nv;
    for (j = 0; j <= ny; j++)
        for (i = 0; i <= nx; i++) tm_vert(m, i, j, 0);
    for (j = 0; j < ny; j++)
        for (i = 0; i < nx; i++)
            tm_quad(m, base + j * (nx + 1) + i, base + j * (nx + 1) + i + 1, base + (j + 1) * (nx + 1) + i + 1,
                    base + (j + 1) * (nx + 1) + i);
}

tt_result build(const tmesh *m, unsigned flags, tt_mesh **out, tt_error *err)
{
    tt_mesh_desc d = tm_desc(m);
    d.flags = flags;
    return tt_mesh_build(&d, NULL, out, err);
}

/* ------------------------------------------------------------------------ */
/* Images                                                                   */
/* ------------------------------------------------------------------------ */

float *px(const tt_image *im, int x, int y) { return im->pixels + ((size_t)y * im->width + x) * 4; }

void make_value_noise(tt_image **out, int w, int h, unsigned seed)
{
    static const int scales[3] = {6, 13, 29};
    static const double weights[3] = {0.12, 0.16, 0.2};
    float lattice[3][64][64];
    int x, y, k, s;
    tt_image *im;
    tt_result r = tt_image_create(w, h, NULL, out, NULL);
    if (r != TT_OK) {
        CHECK(0, "make_value_noise: tt_image_create(%d, %d) returned %d", w, h, r);
        return;
    }
    im = *out;
    lcg_seed(seed);
    for (s = 0; s < 3; s++)
        for (y = 0; y < 64; y++)
            for (x = 0; x < 64; x++) lattice[s][y][x] = (float)lcg_unit() - 0.5f;
    for (y = 0; y < h; y++)
        for (x = 0; x < w; x++) {
            float *p = px(im, x, y);
            double a = 0.0;
            for (s = 0; s < 3; s++) {
                double fx = (double)x / scales[s], fy = (double)y / scales[s];
                int ix = (int)fx, iy = (int)fy;
                double tx = fx - ix, ty = fy - iy;
                double top = lattice[s][iy % 64][ix % 64] * (1 - tx) + lattice[s][iy % 64][(ix + 1) % 64] * tx;
                double bottom = lattice[s][(iy + 1) % 64][ix % 64] * (1 - tx) + lattice[s][(iy + 1) % 64][(ix + 1) % 64] * tx;
                a += weights[s] * (top * (1 - ty) + bottom * ty);
            }
            for (k = 0; k < 3; k++) p[k] = (float)(0.5 + a * (1.0 - 0.25 * k) + (lcg_unit() - 0.5) * 0.03);
            p[3] = 1.0f;
        }
}

/* ------------------------------------------------------------------------ */
/* Internal functions of the implementation the tests call                  */
/* ------------------------------------------------------------------------ */

void internal_free(const tt_allocator *allocator, void *ptr) { tt__free(allocator, ptr); }
int internal_polycube_voxelize(const tt_mesh *mesh, const double origin[3], double h, const int dims[3],
                               unsigned char *mark)
{
    return tt__polycube_voxelize(mesh, origin, h, dims, tt__polycube_tie(mesh, h), mark);
}
int internal_polycube_mask_is_disc(int mask) { return tt__polycube_mask_is_disc(mask); }
int internal_polycube_relax(const tt_polycube *polycube, const tt_mesh *model, tt_surface_point *points)
{
    return tt__polycube_relax(polycube, model, points, NULL, NULL, NULL, NULL);
}
int internal_polycube_reseat_calls(const tt_polycube *polycube, const tt_mesh *model, tt_surface_point *points,
                                   unsigned char *moved, const tt_allocator *allocator, int ncalls, int nudged,
                                   double *spent)
{
    tt_polycube_edges *edges = NULL;
    tt__reseat_memory memory;
    int n = 0, call;
    memset(&memory, 0, sizeof memory);
    memory.stayed = (unsigned char *)calloc((size_t)model->nverts, 1);
    memory.seen = (tt_surface_point *)malloc(sizeof(tt_surface_point) * (size_t)model->nverts);
    if (!memory.stayed || !memory.seen) n = -1;
    else if (tt_polycube_trace_edges(polycube, model, points, model->nverts, NULL, allocator, &edges, NULL) != TT_OK)
        n = -2;
    for (call = 0; call < ncalls && n >= 0; call++) {
        const double before = memory.spent;
        int moves;
        if (call == ncalls - 1 && nudged >= 0)
            points[nudged].s = points[nudged].s < 0.5f ? points[nudged].s + 0.001f : points[nudged].s - 0.001f;
        moves = tt__polycube_reseat(polycube, model, edges, TT_POLYCUBE_EDGE_DEFAULT_QUADS, points, moved, &memory,
                                    allocator);
        n = moves < 0 ? -1 : n + moves;
        if (spent) spent[call] = memory.spent - before;
    }
    tt_polycube_edges_free(edges);
    free(memory.stayed);
    free(memory.seen);
    return n;
}
ic0_check_result internal_ic0_check(const tt_sparse_matrix *A)
{
    ic0_check_result result;
    tt__ic0 F;
    int bad = -1, i, k;
    result.worst = 0.0;
    result.made = tt__ic0_factor(A, NULL, &F, &bad);
    if (result.made != 1) return result;
    for (i = 0; i < A->rows; i++)
        for (k = A->row_start[i]; k < A->row_start[i + 1]; k++) {
            const int c = A->col[k];
            double product = 0.0, scale = 0.0;
            int a, b, d;
            if (c > i) continue;
            for (a = F.start[i]; a < F.start[i + 1]; a++)
                for (b = F.start[c]; b < F.start[c + 1]; b++)
                    if (F.col[a] == F.col[b]) product += F.value[a] * F.value[b];
            for (d = A->row_start[i]; d < A->row_start[i + 1]; d++)
                if (A->col[d] == i) scale = fabs(A->value[d]);
            if (fabs(product - A->value[k]) / scale > result.worst) result.worst = fabs(product - A->value[k]) / scale;
        }
    tt__free(NULL, F.start);
    tt__free(NULL, F.col);
    tt__free(NULL, F.value);
    return result;
}
int internal_relax_kernel_centre(const double (*ring)[2], int ntriangles, double centre[2])
{
    return tt__relax_kernel_centre(ring, ntriangles, centre);
}
/* A star of n triangles (x, ring[i][0], ring[i][1]) with the given shapes; 0 when a shape has no area. */
static int make_untangle_star(int n, const double (*ring)[2][2], const double (*shape)[2][2], tt__untangle_star *star)
{
    int i;
    star->n = n;
    for (i = 0; i < n; i++) {
        memcpy(star->ring[i], ring[i], sizeof star->ring[i]);
        if (!tt__untangle_star_shape(star, i, shape[i])) return 0;
    }
    return 1;
}
double internal_untangle_energy(int n, const double (*ring)[2][2], const double (*shape)[2][2], const double x[2],
                                double delta2, double density, double gradient[2], double hessian[3], int *folded)
{
    tt__untangle_star star;
    if (!make_untangle_star(n, ring, shape, &star)) return -1.0;
    return tt__untangle_energy(&star, x, delta2, density, gradient, hessian, folded);
}
void internal_untangle_descend(int n, const double (*ring)[2][2], const double (*shape)[2][2], const double x[2],
                               double reach, double delta2, double density, int strict, double kept[2])
{
    tt__untangle_star star;
    if (!make_untangle_star(n, ring, shape, &star)) {
        kept[0] = kept[1] = -1.0;
        return;
    }
    tt__untangle_descend(&star, x, reach, delta2, density, strict, kept);
}
void internal_remesh_ring_centroid(const tt_mesh *q, int first, int count, int ring, double out[3])
{
    tt__remesh_ring_centroid(q, first, count, ring, out);
}
static const tt__pair_field *internal_pair_field_to(const internal_pair_field *field, tt__pair_field *out)
{
    if (!field || !field->up) return NULL;
    out->up = field->up;
    out->weight = field->weight;
    out->n = field->n;
    return out;
}
int internal_remesh_quadrangulate_polygon(const float *pos, const internal_pair_field *field, const int *poly, int n,
                                          const unsigned char *joined, const unsigned char *needy, double *cost,
                                          int *out)
{
    int choice[TT__PAIR_MAX_CORNERS * TT__PAIR_MAX_CORNERS];
    double table[TT__PAIR_MAX_CORNERS * TT__PAIR_MAX_CORNERS];
    tt__pair_field f;
    int found = tt__remesh_quadrangulate_polygon(pos, internal_pair_field_to(field, &f), poly, n, joined, needy, table,
                                                 choice, out);
    *cost = table[n - 1];
    return found;
}
double internal_remesh_quad_cost(const float *pos, const internal_pair_field *field, const int quad[4])
{
    tt__pair_field f;
    return tt__remesh_quad_cost(pos, quad, internal_pair_field_to(field, &f));
}
int internal_mapping_merge(tt_polycube_mapping *mapping, const tt_mesh *mesh, double tolerance, int keep_shape)
{
    return tt__mapping_merge(mapping, mesh, tolerance, keep_shape, NULL);
}
void internal_split_vertex_data(const tt_mesh *mesh, const int source[3], const double weight[3], float position[3],
                                float weight_out[3])
{
    tt__split_vertex_data(mesh, source, weight, position, weight_out);
}
int internal_polycube_smooth(const tt_polycube *polycube, const tt_mesh *model, tt_surface_point *points,
                             const tt_executor *executor, const tt_allocator *allocator, int *held)
{
    return tt__polycube_smooth(polycube, model, points, executor, allocator, held, NULL);
}
int internal_polycube_mask_critical(int mask) { return tt__polycube_mask_critical(mask, NULL, NULL); }
int internal_hpm_relax_classes(const tt_mesh *mesh, int *vmark, int *verts, int n, int *class_end)
{
    tt__hpm S;
    int largest, *count = (int *)malloc(sizeof(int) * (size_t)mesh->nverts), nclasses;
    memset(&S, 0, sizeof S);
    S.mesh = mesh;
    S.vmark = vmark;
    S.ring_room = count ? tt__hpm_ring_room(mesh, count) : 0;
    S.ring = (int *)malloc(sizeof(int) * (size_t)S.ring_room);
    nclasses = S.ring ? tt__hpm_relax_classes(&S, verts, n, class_end, &largest) : 0;
    free(count);
    free(S.ring);
    return nclasses;
}
uint64_t internal_xcorr_direct(int w, int h, int channels, const float *texture, int count, const int *x,
                               const int *y, const double *weight, const double *values, int lo, int hi, int *best,
                               double *best_e)
{
    tt__xcorr_terms terms;
    int *span = (int *)malloc(sizeof(int) * 2 * (size_t)h), row;
    float *rows = (float *)malloc(sizeof(float) * (size_t)w * h);
    double energy = 0;
    uint64_t found = 1;
    int i, c;
    *best = -1;
    *best_e = 0;
    for (i = 0; i < count; i++)
        for (c = 0; c < channels; c++) energy += weight[i] * values[i * channels + c] * values[i * channels + c];
    terms.count = count;
    terms.channels = channels;
    terms.x = x;
    terms.y = y;
    terms.weight = weight;
    terms.values = values;
    terms.energy = energy;
    if (span && rows) {
        for (row = 0; row < h; row++) {
            span[2 * row] = lo;
            span[2 * row + 1] = hi;
        }
        found = tt__xcorr_direct(w, h, texture, &terms, span, NULL, 0, h, rows, best, best_e);
    }
    free(span);
    free(rows);
    return found;
}
float internal_infinity(void) { return tt__infinity(); }
double internal_not_a_number(void) { return tt__not_a_number(); }
double internal_median(double *values, int count) { return tt__median(values, count); }

double internal_weighted_percentile(const double *values, const double *weights, int count, double fraction)
{
    tt__weighted *items = (tt__weighted *)malloc(sizeof(tt__weighted) * (size_t)count);
    double result = tt__not_a_number();
    int i;
    if (!items) return result;
    for (i = 0; i < count; i++) {
        items[i].value = values[i];
        items[i].weight = weights[i];
    }
    tt__weighted_percentiles(items, count, &fraction, 1, &result);
    free(items);
    return result;
}

double internal_orient2(double ax, double ay, double bx, double by, double cx, double cy)
{
    return tt__orient2(ax, ay, bx, by, cx, cy);
}
double internal_point_segment_distance(double px_, double py_, double ax, double ay, double bx, double by)
{
    return tt__point_segment_distance(px_, py_, ax, ay, bx, by);
}
int internal_point_on_segment(double px_, double py_, double ax, double ay, double bx, double by)
{
    return tt__point_on_segment(px_, py_, ax, ay, bx, by);
}
int internal_segments_near(double ax, double ay, double bx, double by, double cx, double cy, double dx, double dy,
                           double eps)
{
    return tt__segments_near(ax, ay, bx, by, cx, cy, dx, dy, eps);
}
int internal_segment_meets_polygon(const float a[2], const float b[2], const float *xy, int count)
{
    return tt__segment_meets_polygon(a, b, xy, count);
}
tt_result internal_hull_convex(const tt_image *patch, const tt_allocator *allocator, double **out_x, double **out_y,
                               int *out_n)
{
    return tt__hull_convex(patch, allocator, out_x, out_y, out_n);
}
tt_result internal_patch_hull(const tt_image *patch, int max_vertices, const tt_allocator *allocator, float **out_xy,
                              int *out_count)
{
    return tt__patch_hull(patch, max_vertices, allocator, out_xy, out_count);
}

tt_result internal_amg_solve2(const tt_sparse_matrix *A, const double *b, double *x, double tolerance,
                              int max_iterations, const tt_allocator *allocator, int *levels, int *iterations)
{
    tt__amg G;
    tt_result r = tt__amg_setup(&G, A, allocator);
    *levels = 0;
    *iterations = 0;
    if (r != TT_OK) return r;
    *levels = G.nlevels;
    r = tt__amg_solve2(&G, b, x, tolerance, max_iterations, iterations);
    tt__amg_free(&G);
    return r;
}

tt_result internal_lapped_align(const tt_mesh *mesh, const float *field, const int *faces, int nfaces, int seed_face,
                                const double seed_weight[3], const float anchor[2], double *uv, int *unknowns,
                                int *steps)
{
    tt__lapper L;
    const int nf = mesh->nfaces, nv = mesh->nverts;
    tt_result r = TT_ERROR_OUT_OF_MEMORY;
    int i, k;
    memset(&L, 0, sizeof L);
    L.mesh = mesh;
    L.field = field;
    L.vert_uv = uv;
    L.normal = (double *)calloc(3 * (size_t)nf, sizeof(double));
    L.tangent = (double *)calloc(3 * (size_t)nf, sizeof(double));
    L.axis_weights = (float *)calloc(6 * (size_t)nf, sizeof(float));
    L.area = (float *)calloc((size_t)nf, sizeof(float));
    L.patch_faces = (int *)malloc(sizeof(int) * (size_t)nf);
    L.patch_corners = (int *)malloc(sizeof(int) * 3 * (size_t)nf);
    L.patch_verts = (int *)malloc(sizeof(int) * (size_t)nv);
    L.vert_local = (int *)malloc(sizeof(int) * (size_t)nv);
    L.vert_stamp = (int *)malloc(sizeof(int) * (size_t)nv);
    L.row_start = (int *)malloc(sizeof(int) * ((size_t)nv + 1));
    L.row_fill = (int *)malloc(sizeof(int) * (size_t)nv);
    L.column_mark = (int *)malloc(sizeof(int) * (size_t)nv);
    L.solve = (double *)malloc(sizeof(double) * 4 * (size_t)nv);
    if (L.normal && L.tangent && L.axis_weights && L.area && L.patch_faces && L.patch_corners && L.patch_verts &&
        L.vert_local &&
        L.vert_stamp && L.row_start && L.row_fill && L.column_mark && L.solve) {
        for (i = 0; i < nv; i++) L.vert_stamp[i] = -1;
        for (i = 0; i < nfaces; i++) {
            const int f = faces[i];
            double *n = L.normal + 3 * (size_t)f, v[3], e1[3], e2[3], cross[3];
            tt__face_normal_d(mesh, f, n);
            for (k = 0; k < 3; k++) v[k] = field[3 * (size_t)f + k];
            tt__project3(v, n, L.tangent + 3 * (size_t)f);
            tt__sub3f(tt__corner_pos(mesh, 3 * f + 1), tt__corner_pos(mesh, 3 * f), e1);
            tt__sub3f(tt__corner_pos(mesh, 3 * f + 2), tt__corner_pos(mesh, 3 * f), e2);
            tt__cross3(e1, e2, cross);
            L.area[f] = (float)(0.5 * tt__length3(cross));
            tt__face_axes(&L, f);
            for (k = 0; k < 3; k++)
                if (L.vert_stamp[mesh->corner_vert[3 * f + k]] != 0) tt__map_vertex(&L, mesh->corner_vert[3 * f + k], 0);
            tt__add_patch_face(&L, f);
        }
        r = tt__optimize_patch(&L, seed_face, seed_weight, anchor);
    }
    *unknowns = L.npatch_verts;
    *steps = L.solve_steps;
    free(L.normal);
    free(L.tangent);
    free(L.axis_weights);
    free(L.area);
    free(L.patch_faces);
    free(L.patch_corners);
    free(L.patch_verts);
    free(L.vert_local);
    free(L.vert_stamp);
    free(L.row_start);
    free(L.row_fill);
    free(L.column_mark);
    free(L.solve);
    tt__free(NULL, L.columns);
    tt__free(NULL, L.values);
    return r;
}

/* ------------------------------------------------------------------------ */
/* main                                                                     */
/* ------------------------------------------------------------------------ */

static void reverse_run(int count, tt_task_fn task, void *task_context, void *user_data)
{
    int i;
    (void)user_data;
    for (i = count - 1; i >= 0; i--) task(task_context, i);
}
const tt_executor g_reverse_executor = {reverse_run, NULL};

typedef struct thread_batch {
    pthread_mutex_t lock;
    int next, count;
    tt_task_fn task;
    void *task_context;
} thread_batch;

static void *thread_worker(void *arg)
{
    thread_batch *b = (thread_batch *)arg;
    for (;;) {
        int i;
        pthread_mutex_lock(&b->lock);
        i = b->next < b->count ? b->next++ : -1;
        pthread_mutex_unlock(&b->lock);
        if (i < 0) return NULL;
        b->task(b->task_context, i);
    }
}

/* A second thread for the batch and this one, both taking indices. */
static void thread_run(int count, tt_task_fn task, void *task_context, void *user_data)
{
    thread_batch b;
    pthread_t helper;
    int started;
    (void)user_data;
    pthread_mutex_init(&b.lock, NULL);
    b.next = 0;
    b.count = count;
    b.task = task;
    b.task_context = task_context;
    started = pthread_create(&helper, NULL, thread_worker, &b) == 0;
    thread_worker(&b);
    if (started) pthread_join(helper, NULL);
    pthread_mutex_destroy(&b.lock);
}
const tt_executor g_thread_executor = {thread_run, NULL};

/* Tile sets for the tests of turned tiles (tt_upright_atlas). */
void make_upright_sets(const tt_image *photo, tt_synth_options so, tt_tileset *sets[TT_TILESET_KINDS])
{
    static const int plain_sides[TT_TILESET_KINDS - 1] = {0, 1 << 1, 1 << 3};
    int k;
    so.upright = 1;
    so.edge_windows = sets[TT_TILESET_PLAIN]->edge_windows;
    for (k = TT_TILESET_UPRIGHT; k < TT_TILESET_KINDS; k++) {
        so.plain_sides = plain_sides[k - TT_TILESET_UPRIGHT];
        sets[k] = NULL;
        if (tt_synthesize_tiles(photo, &so, NULL, &sets[k], NULL) != TT_OK) sets[k] = NULL;
    }
}

/* Whether a comma-separated list of section names holds this one. */
static int section_listed(const char *list, const char *name)
{
    const char *p;
    size_t len = strlen(name);
    for (p = list; *p;) {
        const char *end = strchr(p, ',');
        size_t n = end ? (size_t)(end - p) : strlen(p);
        if (n == len && strncmp(p, name, len) == 0) return 1;
        p += n;
        if (*p == ',') p++;
    }
    return 0;
}

/* TT_TEST_ONLY=hpm,polycube runs only those sections (names as below): a
   quick loop while working on one section. TT_TEST_SKIP=lapped runs all but
   those: tests/run.sh runs the program twice at once, one of each, so that
   every section runs exactly once. `make test` runs them all. */
static int section_selected(const char *name)
{
    const char *only = getenv("TT_TEST_ONLY"), *skip = getenv("TT_TEST_SKIP");
    if (skip && *skip && section_listed(skip, name)) return 0;
    return !only || !*only || section_listed(only, name);
}

int main(void)
{
    static const struct { const char *name; void (*run)(void); } sections[] = {
        {"common", run_common_tests}, {"mesh", run_mesh_tests}, {"image", run_image_tests},
        {"numerics", run_numerics_tests}, {"fft", run_fft_tests}, {"raster", run_raster_tests},
        {"tiled", run_tiled_tests}, {"synthesis", run_tiled_synthesis_tests},
        {"lapped", run_lapped_tests}, {"hpm", run_hpm_tests}, {"polycube", run_polycube_tests},
        {"contract", run_contract_tests}};
    static const char *const lists[] = {"TT_TEST_ONLY", "TT_TEST_SKIP"};
    size_t i, k, n = sizeof sections / sizeof sections[0];
    /* A misspelt name would quietly run nothing, or everything. */
    for (k = 0; k < 2; k++) {
        const char *list = getenv(lists[k]), *p;
        for (p = list ? list : ""; *p;) {
            size_t len = strcspn(p, ",");
            for (i = 0; i < n; i++)
                if (strlen(sections[i].name) == len && strncmp(p, sections[i].name, len) == 0) break;
            if (i == n) {
                printf("%s names no section '%.*s'\n0 passed, 1 failed\n", lists[k], (int)len, p);
                return 1;
            }
            p += len;
            if (*p == ',') p++;
        }
    }
    for (i = 0; i < n; i++)
        if (section_selected(sections[i].name)) sections[i].run();
    printf("%d passed, %d failed\n", g_passed, g_failed);
    return g_failed ? 1 : 0;
}
