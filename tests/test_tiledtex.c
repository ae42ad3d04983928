/* Unit tests for tiledtex.h. Plain C99, no framework, deterministic.
   Built and run by tests/run.sh (with ASan + UBSan). Prints one line per
   failed check and, last, "N passed, M failed". Does not read any file. */
#define TILEDTEX_IMPLEMENTATION
#include "tiledtex.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ------------------------------------------------------------------------ */
/* Framework                                                                */
/* ------------------------------------------------------------------------ */

static int g_passed, g_failed;
static const char *g_test = "";

static void check_report(int ok, const char *file, int line, const char *what, const char *fmt, ...)
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

/* CHECK(cond, fmt, ...): fmt says what was expected and what came out. */
#define CHECK(cond, ...) check_report((cond) ? 1 : 0, __FILE__, __LINE__, #cond, __VA_ARGS__)
/* DETAIL(fmt, ...): the first offending case of a loop whose CHECK counts
   the offenders; printed, not counted. */
#define DETAIL(...) check_detail(__FILE__, __LINE__, __VA_ARGS__)
#define RUN(fn) do { g_test = #fn; fn(); } while (0)

static void check_detail(const char *file, int line, const char *fmt, ...)
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

typedef struct counter {
    long live;          /* allocations not yet freed */
    long calls;         /* alloc calls so far */
    long fail_at;       /* fail the alloc call with this index (0-based); -1 = never */
    long failures;      /* how many calls were failed */
    long bad_frees;     /* frees of pointers we did not hand out */
    size_t live_bytes;
} counter;

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

static tt_allocator make_allocator(counter *c, long fail_at)
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
/* Small helpers                                                            */
/* ------------------------------------------------------------------------ */

static int near(double a, double b, double tol) { return fabs(a - b) <= tol; }

static unsigned long long g_lcg = 1;
static void lcg_seed(unsigned long long s) { g_lcg = s * 2862933555777941757ull + 3037000493ull; }
static unsigned lcg_next(void)
{
    g_lcg = g_lcg * 6364136223846793005ull + 1442695040888963407ull;
    return (unsigned)(g_lcg >> 33);
}
static int lcg_below(int n) { return (int)(lcg_next() % (unsigned)n); }
static double lcg_unit(void) { return (double)lcg_next() / 2147483648.0; }

/* ------------------------------------------------------------------------ */
/* 1. RNG                                                                   */
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

/* ------------------------------------------------------------------------ */
/* Hand-made meshes                                                         */
/* ------------------------------------------------------------------------ */

typedef struct tmesh {
    float *pos;
    int nv, cap_v;
    int *idx;
    int nc, cap_c;
    int *sizes;
    int nf, cap_f;
} tmesh;

static void tm_free(tmesh *m)
{
    free(m->pos);
    free(m->idx);
    free(m->sizes);
    memset(m, 0, sizeof *m);
}

static int tm_vert(tmesh *m, double x, double y, double z)
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

static void tm_face(tmesh *m, int n, const int *v)
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

static void tm_tri(tmesh *m, int a, int b, int c) { int v[3]; v[0] = a; v[1] = b; v[2] = c; tm_face(m, 3, v); }
static void tm_quad(tmesh *m, int a, int b, int c, int d)
{
    int v[4];
    v[0] = a; v[1] = b; v[2] = c; v[3] = d;
    tm_face(m, 4, v);
}

static tt_mesh_desc tm_desc(const tmesh *m)
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

/* Regular tetrahedron-ish: 4 vertices, 4 triangles, outward CCW. */
static void make_tetra(tmesh *m, double ox)
{
    int a = tm_vert(m, ox + 0, 0, 0), b = tm_vert(m, ox + 1, 0, 0), c = tm_vert(m, ox + 0, 1, 0),
        d = tm_vert(m, ox + 0, 0, 1);
    tm_tri(m, a, c, b);
    tm_tri(m, a, b, d);
    tm_tri(m, a, d, c);
    tm_tri(m, b, c, d);
}

/* Boundary quads of a set of unit voxels (filled[x + nx*(y + ny*z)]), on
   the lattice (nx+1)(ny+1)(nz+1); outward CCW. Used lattice points only. */
static void make_voxels(tmesh *m, int nx, int ny, int nz, const unsigned char *filled, double ox)
{
    int *lat = (int *)malloc(sizeof(int) * (size_t)(nx + 1) * (ny + 1) * (nz + 1));
    int x, y, z, i, dir;
    /* corner offsets per direction: +x, -x, +y, -y, +z, -z */
    static const int off[6][4][3] = {
        {{1, 0, 0}, {1, 1, 0}, {1, 1, 1}, {1, 0, 1}},
        {{0, 0, 0}, {0, 0, 1}, {0, 1, 1}, {0, 1, 0}},
        {{0, 1, 0}, {0, 1, 1}, {1, 1, 1}, {1, 1, 0}},
        {{0, 0, 0}, {1, 0, 0}, {1, 0, 1}, {0, 0, 1}},
        {{0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}},
        {{0, 0, 0}, {0, 1, 0}, {1, 1, 0}, {1, 0, 0}}};
    static const int nb[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    for (i = 0; i < (nx + 1) * (ny + 1) * (nz + 1); i++) lat[i] = -1;
    for (z = 0; z < nz; z++)
        for (y = 0; y < ny; y++)
            for (x = 0; x < nx; x++) {
                if (!filled[x + nx * (y + ny * z)]) continue;
                for (dir = 0; dir < 6; dir++) {
                    int X = x + nb[dir][0], Y = y + nb[dir][1], Z = z + nb[dir][2], v[4];
                    if (X >= 0 && Y >= 0 && Z >= 0 && X < nx && Y < ny && Z < nz && filled[X + nx * (Y + ny * Z)])
                        continue;
                    for (i = 0; i < 4; i++) {
                        int px = x + off[dir][i][0], py = y + off[dir][i][1], pz = z + off[dir][i][2];
                        int li = px + (nx + 1) * (py + (ny + 1) * pz);
                        if (lat[li] < 0) lat[li] = tm_vert(m, ox + px, py, pz);
                        v[i] = lat[li];
                    }
                    tm_face(m, 4, v);
                }
            }
    free(lat);
}

static void make_cube(tmesh *m, double ox)
{
    unsigned char one = 1;
    make_voxels(m, 1, 1, 1, &one, ox);
}

/* 3 x 5 x 1 slab with holes at (1,1) and (1,3): a genus-2 polycube. */
static void make_genus2(tmesh *m)
{
    unsigned char f[15];
    int i;
    for (i = 0; i < 15; i++) f[i] = 1;
    f[1 + 3 * 1] = 0;
    f[1 + 3 * 3] = 0;
    make_voxels(m, 3, 5, 1, f, 0.0);
}

/* nu x nv quads on a torus (nu, nv >= 3). Quad (i,j) is face j*nu + i. */
static void make_torus(tmesh *m, int nu, int nv, double R, double r)
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
static void make_grid(tmesh *m, int nx, int ny)
{
    int i, j, base = m->nv;
    for (j = 0; j <= ny; j++)
        for (i = 0; i <= nx; i++) tm_vert(m, i, j, 0);
    for (j = 0; j < ny; j++)
        for (i = 0; i < nx; i++)
            tm_quad(m, base + j * (nx + 1) + i, base + j * (nx + 1) + i + 1, base + (j + 1) * (nx + 1) + i + 1,
                    base + (j + 1) * (nx + 1) + i);
}

/* A closed mesh of mixed polygon sizes: a pentagonal prism (2 pentagons,
   5 quads) and, beside it, a square pyramid (1 quad, 4 triangles). */
static void make_mixed(tmesh *m)
{
    const double pi = 3.14159265358979323846;
    int bot[5], top[5], i, v[5], p[5];
    for (i = 0; i < 5; i++) {
        double a = 2 * pi * i / 5;
        bot[i] = tm_vert(m, cos(a), sin(a), 0);
        top[i] = tm_vert(m, cos(a), sin(a), 1);
    }
    for (i = 0; i < 5; i++) v[i] = top[i];
    tm_face(m, 5, v);                                     /* top, CCW from +z */
    for (i = 0; i < 5; i++) v[i] = bot[4 - i];
    tm_face(m, 5, v);                                     /* bottom, CCW from -z */
    for (i = 0; i < 5; i++) tm_quad(m, bot[i], bot[(i + 1) % 5], top[(i + 1) % 5], top[i]);
    p[0] = tm_vert(m, 5, 0, 0);
    p[1] = tm_vert(m, 6, 0, 0);
    p[2] = tm_vert(m, 6, 1, 0);
    p[3] = tm_vert(m, 5, 1, 0);
    p[4] = tm_vert(m, 5.5, 0.5, 1);
    tm_quad(m, p[0], p[3], p[2], p[1]);                   /* base, seen from below */
    for (i = 0; i < 4; i++) tm_tri(m, p[i], p[(i + 1) % 4], p[4]);
}

/* Build with an optional counting allocator; returns the result. */
static tt_result build(const tmesh *m, unsigned flags, tt_mesh **out, tt_error *err)
{
    tt_mesh_desc d = tm_desc(m);
    d.flags = flags;
    return tt_mesh_build(&d, out, err);
}

/* Half-edges without a reversed partner anywhere (a naive O(n^2) count). */
static int count_boundary_naive(const tmesh *m)
{
    int f, c, g, c2, start = 0, n = 0, s2;
    for (f = 0; f < m->nf; f++) {
        for (c = start; c < start + m->sizes[f]; c++) {
            int a = m->idx[c], b = m->idx[c + 1 < start + m->sizes[f] ? c + 1 : start], found = 0;
            for (g = 0, s2 = 0; g < m->nf && !found; s2 += m->sizes[g], g++)
                for (c2 = s2; c2 < s2 + m->sizes[g]; c2++) {
                    int a2 = m->idx[c2], b2 = m->idx[c2 + 1 < s2 + m->sizes[g] ? c2 + 1 : s2];
                    if (a2 == b && b2 == a) { found = 1; break; }
                }
            n += !found;
        }
        start += m->sizes[f];
    }
    return n;
}

/* Structural invariants of a built mesh against its description (each kind
   of violation is one check). */
static void check_structure(const tt_mesh *mesh, const tmesh *m, const char *name)
{
    int c, f, v, bad_twin = 0, bad_rev = 0, bad_face = 0, bad_vc = 0, bad_vb = 0, bad_cv = 0, nboundary = 0;
    CHECK(mesh->nverts == m->nv && mesh->nfaces == m->nf && mesh->ncorners == m->nc,
          "%s: counts: expected %d/%d/%d, got %d/%d/%d", name, m->nv, m->nf, m->nc, mesh->nverts, mesh->nfaces,
          mesh->ncorners);
    for (f = 0, c = 0; f < m->nf; f++) {
        if (mesh->face_start[f] != c) bad_face++;
        c += m->sizes[f];
    }
    if (mesh->face_start[m->nf] != m->nc) bad_face++;
    for (f = 0; f < m->nf; f++)
        for (c = mesh->face_start[f]; c < mesh->face_start[f + 1]; c++)
            if (mesh->corner_face[c] != f) bad_face++;
    for (c = 0; c < m->nc; c++) {
        int t = mesh->twin[c];
        if (mesh->corner_vert[c] != m->idx[c]) bad_cv++;
        if (t < 0) { nboundary++; continue; }
        if (t >= m->nc || mesh->twin[t] != c || t == c) { bad_twin++; continue; }
        /* reversed: twin's origin is my destination and vice versa */
        if (mesh->corner_vert[t] != mesh->corner_vert[tt_mesh_next(mesh, c)] ||
            mesh->corner_vert[tt_mesh_next(mesh, t)] != mesh->corner_vert[c])
            bad_rev++;
    }
    for (v = 0; v < m->nv; v++) {
        int vc = mesh->vert_corner[v], has_boundary = 0, used = 0;
        for (c = 0; c < m->nc; c++)
            if (m->idx[c] == v) {
                used = 1;
                if (mesh->twin[c] < 0) has_boundary = 1;
            }
        if (!used) { if (vc != -1) bad_vc++; continue; }
        if (vc < 0 || vc >= m->nc || mesh->corner_vert[vc] != v) { bad_vc++; continue; }
        if (has_boundary && mesh->twin[vc] >= 0) bad_vb++;
    }
    /* next/prev are inverse and stay in the face */
    for (c = 0; c < m->nc; c++) {
        int n = tt_mesh_next(mesh, c);
        if (tt_mesh_prev(mesh, n) != c || mesh->corner_face[n] != mesh->corner_face[c]) bad_face++;
    }
    CHECK(bad_face == 0, "%s: face_start/corner_face/next/prev inconsistent in %d places", name, bad_face);
    CHECK(bad_cv == 0, "%s: corner_vert differs from the index buffer in %d corners", name, bad_cv);
    CHECK(bad_twin == 0, "%s: %d twins not mutual", name, bad_twin);
    CHECK(bad_rev == 0, "%s: %d twins not reversed", name, bad_rev);
    CHECK(bad_vc == 0, "%s: %d vert_corner entries not an outgoing half-edge of their vertex", name, bad_vc);
    CHECK(bad_vb == 0, "%s: %d boundary vertices whose vert_corner is not a boundary half-edge", name, bad_vb);
    if (mesh->repaired_edges == 0)   /* repairs cut edges open on purpose */
        CHECK(nboundary == count_boundary_naive(m), "%s: %d boundary half-edges, the naive count is %d", name,
              nboundary, count_boundary_naive(m));
}

static int count_boundary(const tt_mesh *mesh)
{
    int c, n = 0;
    for (c = 0; c < mesh->ncorners; c++) n += mesh->twin[c] < 0;
    return n;
}

static void test_builder_valid(void)
{
    tmesh m;
    tt_mesh *mesh;
    tt_error err;
    tt_result r;
    counter cnt;
    tt_mesh_desc d;

    memset(&m, 0, sizeof m);
    make_tetra(&m, 0);
    r = build(&m, 0, &mesh, &err);
    CHECK(r == TT_OK, "tetrahedron: expected TT_OK, got %d (%s)", r, err.message);
    if (r == TT_OK) {
        check_structure(mesh, &m, "tetrahedron");
        CHECK(count_boundary(mesh) == 0, "tetrahedron is closed, got %d boundary half-edges", count_boundary(mesh));
        CHECK(mesh->min_face_size == 3 && mesh->max_face_size == 3, "tetrahedron face sizes %d..%d",
              mesh->min_face_size, mesh->max_face_size);
        CHECK(mesh->repaired_edges == 0, "strict build repaired %d edges", mesh->repaired_edges);
        CHECK(mesh->pos != m.pos, "positions should be copied without TT_MESH_BORROW_POSITIONS");
        CHECK(err.result == TT_OK && err.face == -1 && err.vertex == -1, "error cleared on success");
        tt_mesh_free(mesh);
    }
    tm_free(&m);

    make_cube(&m, 0);
    r = build(&m, 0, &mesh, &err);
    CHECK(r == TT_OK, "cube: expected TT_OK, got %d (%s)", r, err.message);
    if (r == TT_OK) {
        check_structure(mesh, &m, "cube");
        CHECK(count_boundary(mesh) == 0, "cube is closed, got %d boundary half-edges", count_boundary(mesh));
        tt_mesh_free(mesh);
    }
    /* The same cube through fixed_face_size = 4 and a counting allocator. */
    {
        tt_allocator al = make_allocator(&cnt, -1);
        d = tm_desc(&m);
        d.face_sizes = NULL;
        d.fixed_face_size = 4;
        d.allocator = al;
        r = tt_mesh_build(&d, &mesh, &err);
        CHECK(r == TT_OK, "cube (fixed size 4): got %d", r);
        if (r == TT_OK) {
            check_structure(mesh, &m, "cube fixed");
            CHECK(cnt.live > 0, "the mesh should be allocated through the given allocator");
            tt_mesh_free(mesh);
        }
        CHECK(cnt.live == 0 && cnt.bad_frees == 0, "cube: %ld allocations leaked, %ld bad frees", cnt.live,
              cnt.bad_frees);
    }
    /* TT_MESH_BORROW_POSITIONS */
    r = build(&m, TT_MESH_BORROW_POSITIONS, &mesh, &err);
    CHECK(r == TT_OK, "cube borrowed: got %d", r);
    if (r == TT_OK) {
        CHECK(mesh->pos == m.pos, "TT_MESH_BORROW_POSITIONS: mesh->pos should be desc.positions");
        tt_mesh_free(mesh);
    }
    tm_free(&m);

    /* Open square of two triangles */
    tm_vert(&m, 0, 0, 0); tm_vert(&m, 1, 0, 0); tm_vert(&m, 1, 1, 0); tm_vert(&m, 0, 1, 0);
    tm_tri(&m, 0, 1, 2);
    tm_tri(&m, 0, 2, 3);
    r = build(&m, 0, &mesh, &err);
    CHECK(r == TT_OK, "open square: got %d (%s)", r, err.message);
    if (r == TT_OK) {
        check_structure(mesh, &m, "open square");
        CHECK(count_boundary(mesh) == 4, "open square: expected 4 boundary half-edges, got %d", count_boundary(mesh));
        CHECK(mesh->twin[2] == 3 && mesh->twin[3] == 2, "open square: diagonal 2-0 / 0-2 should pair corners 2,3; got %d %d",
              mesh->twin[2], mesh->twin[3]);
        tt_mesh_free(mesh);
    }
    tm_free(&m);

    make_mixed(&m);
    r = build(&m, 0, &mesh, &err);
    CHECK(r == TT_OK, "mixed: got %d (%s)", r, err.message);
    if (r == TT_OK) {
        check_structure(mesh, &m, "mixed");
        CHECK(count_boundary(mesh) == 0, "mixed is closed, got %d boundary half-edges", count_boundary(mesh));
        CHECK(mesh->min_face_size == 3 && mesh->max_face_size == 5, "mixed face sizes: expected 3..5, got %d..%d",
              mesh->min_face_size, mesh->max_face_size);
        tt_mesh_free(mesh);
    }
    tm_free(&m);

    /* An unused vertex is allowed and gets vert_corner -1; a grid with
       boundary and the genus-2 polycube pass the invariants too. */
    make_grid(&m, 3, 2);
    tm_vert(&m, 9, 9, 9);
    r = build(&m, 0, &mesh, &err);
    CHECK(r == TT_OK, "grid + unused vertex: got %d (%s)", r, err.message);
    if (r == TT_OK) {
        check_structure(mesh, &m, "grid");
        CHECK(mesh->vert_corner[m.nv - 1] == -1, "unused vertex: vert_corner should be -1, got %d",
              mesh->vert_corner[m.nv - 1]);
        tt_mesh_free(mesh);
    }
    tm_free(&m);
    make_genus2(&m);
    r = build(&m, 0, &mesh, &err);
    CHECK(r == TT_OK, "genus-2 polycube: got %d (%s)", r, err.message);
    if (r == TT_OK) {
        check_structure(mesh, &m, "genus2");
        tt_mesh_free(mesh);
    }
    tm_free(&m);

    /* A large polygon (> 16 corners takes the stamping path). */
    {
        int i, v[40];
        for (i = 0; i < 40; i++) v[i] = tm_vert(&m, cos(i * 0.15707963), sin(i * 0.15707963), 0);
        tm_face(&m, 40, v);
        r = build(&m, 0, &mesh, &err);
        CHECK(r == TT_OK, "40-gon: got %d (%s)", r, err.message);
        if (r == TT_OK) {
            check_structure(mesh, &m, "40-gon");
            tt_mesh_free(mesh);
        }
        tm_free(&m);
    }
}

/* Does `msg` contain the decimal number n as a whole token? */
static int msg_has_number(const char *msg, int n)
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

/* Naive reference for edge problems: the smallest corner of any edge used
   twice in one direction; sets *code. Returns -1 when there is none. */
static int naive_first_edge_problem(const tmesh *m, tt_result *code, int *va, int *vb)
{
    int *start = (int *)malloc(sizeof(int) * (size_t)(m->nf + 1));
    int f, c, c2, best = -1;
    start[0] = 0;
    for (f = 0; f < m->nf; f++) start[f + 1] = start[f] + m->sizes[f];
    for (f = 0; f < m->nf; f++)
        for (c = start[f]; c < start[f + 1]; c++) {
            int a = m->idx[c], b = m->idx[c + 1 < start[f + 1] ? c + 1 : start[f]], p = 0, q = 0, g, lowest = m->nc;
            for (g = 0; g < m->nf; g++)
                for (c2 = start[g]; c2 < start[g + 1]; c2++) {
                    int a2 = m->idx[c2], b2 = m->idx[c2 + 1 < start[g + 1] ? c2 + 1 : start[g]];
                    if (a2 == a && b2 == b) { p++; if (c2 < lowest) lowest = c2; }
                    if (a2 == b && b2 == a) { q++; if (c2 < lowest) lowest = c2; }
                }
            if ((p > 1 || q > 1) && (best < 0 || lowest < best)) {
                best = lowest;
                *code = p + q > 2 ? TT_ERROR_NON_MANIFOLD_EDGE : TT_ERROR_INCONSISTENT_ORIENTATION;
                *va = a;
                *vb = b;
            }
        }
    free(start);
    return best;
}

static int face_of_corner(const tmesh *m, int corner)
{
    int f, c = 0;
    for (f = 0; f < m->nf; f++) {
        if (corner < c + m->sizes[f]) return f;
        c += m->sizes[f];
    }
    return -1;
}

/* Build m strictly and expect `code` with the given fields (-2 = don't care). */
static void expect_build_error(const tmesh *m, tt_result code, int face, int corner, int vertex, const char *what)
{
    tt_mesh *mesh = (tt_mesh *)&mesh;   /* must become NULL */
    tt_error err;
    counter cnt;
    tt_mesh_desc d = tm_desc(m);
    tt_result r;
    memset(&err, 0x55, sizeof err);
    d.allocator = make_allocator(&cnt, -1);
    r = tt_mesh_build(&d, &mesh, &err);
    CHECK(r == code, "%s: expected result %d, got %d (%s)", what, code, r, err.message);
    CHECK(mesh == NULL, "%s: *out_mesh should be NULL on failure", what);
    CHECK(err.result == code, "%s: err.result expected %d, got %d", what, code, err.result);
    if (face != -2) CHECK(err.face == face, "%s: err.face expected %d, got %d", what, face, err.face);
    if (corner != -2) CHECK(err.corner == corner, "%s: err.corner expected %d, got %d", what, corner, err.corner);
    if (vertex != -2) CHECK(err.vertex == vertex, "%s: err.vertex expected %d, got %d", what, vertex, err.vertex);
    CHECK(err.message[0] != '\0' && memchr(err.message, '\0', sizeof err.message) != NULL,
          "%s: the message should be a non-empty string", what);
    if (face >= 0 || vertex >= 0)
        CHECK((face >= 0 && msg_has_number(err.message, face)) || (vertex >= 0 && msg_has_number(err.message, vertex)),
              "%s: message should name face %d or vertex %d: \"%s\"", what, face, vertex, err.message);
    CHECK(cnt.live == 0 && cnt.bad_frees == 0, "%s: %ld allocations leaked on the error path", what, cnt.live);
    if (r == TT_OK) tt_mesh_free(mesh);
    /* The NULL error pointer is accepted too. */
    mesh = (tt_mesh *)&mesh;
    r = tt_mesh_build(&d, &mesh, NULL);
    CHECK(r == code && mesh == NULL, "%s with error == NULL: expected %d, got %d", what, code, r);
    if (r == TT_OK && mesh) tt_mesh_free(mesh);
    CHECK(cnt.live == 0, "%s (error NULL): %ld allocations leaked", what, cnt.live);
}

/* Build permissively: expect success, repaired_edges in [min_repaired, ...]. */
static void expect_permissive(const tmesh *m, int min_repaired, const char *what)
{
    tt_mesh *mesh = NULL;
    tt_error err;
    counter cnt;
    tt_mesh_desc d = tm_desc(m);
    tt_result r;
    d.flags = TT_MESH_PERMISSIVE;
    d.allocator = make_allocator(&cnt, -1);
    r = tt_mesh_build(&d, &mesh, &err);
    CHECK(r == TT_OK, "%s (permissive): expected TT_OK, got %d (%s)", what, r, err.message);
    if (r == TT_OK) {
        tt_mesh_stats st;
        CHECK(mesh->repaired_edges >= min_repaired, "%s (permissive): repaired_edges expected >= %d, got %d", what,
              min_repaired, mesh->repaired_edges);
        CHECK((mesh->flags & TT_MESH_PERMISSIVE) != 0, "%s: mesh->flags should keep TT_MESH_PERMISSIVE", what);
        check_structure(mesh, m, what);
        CHECK(tt_mesh_compute_stats(mesh, &st) == TT_OK, "%s: stats on a permissive mesh", what);
        tt_mesh_free(mesh);
    }
    CHECK(cnt.live == 0, "%s (permissive): %ld allocations leaked", what, cnt.live);
}

static void test_builder_errors(void)
{
    tmesh m;
    tt_mesh *mesh;
    tt_error err;
    tt_result r;
    tt_mesh_desc d;
    memset(&m, 0, sizeof m);

    /* NULLs and bad counts */
    make_tetra(&m, 0);
    d = tm_desc(&m);
    r = tt_mesh_build(&d, NULL, &err);
    CHECK(r == TT_ERROR_INVALID_ARGUMENT, "out_mesh NULL: expected %d, got %d", TT_ERROR_INVALID_ARGUMENT, r);
    mesh = (tt_mesh *)&mesh;
    r = tt_mesh_build(NULL, &mesh, &err);
    CHECK(r == TT_ERROR_INVALID_ARGUMENT && mesh == NULL, "desc NULL: expected %d, got %d", TT_ERROR_INVALID_ARGUMENT, r);
    d.indices = NULL;
    r = tt_mesh_build(&d, &mesh, &err);
    CHECK(r == TT_ERROR_INVALID_ARGUMENT && mesh == NULL, "indices NULL: got %d", r);
    d = tm_desc(&m);
    d.positions = NULL;
    r = tt_mesh_build(&d, &mesh, &err);
    CHECK(r == TT_ERROR_INVALID_ARGUMENT && mesh == NULL, "positions NULL: got %d", r);
    d = tm_desc(&m);
    d.nverts = -1;
    r = tt_mesh_build(&d, &mesh, &err);
    CHECK(r == TT_ERROR_INVALID_ARGUMENT && mesh == NULL, "nverts -1: got %d", r);
    d = tm_desc(&m);
    d.nfaces = -3;
    r = tt_mesh_build(&d, &mesh, &err);
    CHECK(r == TT_ERROR_INVALID_ARGUMENT && mesh == NULL, "nfaces -3: got %d", r);
    d = tm_desc(&m);
    d.face_sizes = NULL;
    d.fixed_face_size = 2;
    r = tt_mesh_build(&d, &mesh, &err);
    CHECK(r == TT_ERROR_FACE_TOO_SMALL && mesh == NULL, "fixed_face_size 2: expected %d, got %d",
          TT_ERROR_FACE_TOO_SMALL, r);
    /* fixed_face_size 0 means triangles */
    d = tm_desc(&m);
    d.face_sizes = NULL;
    d.fixed_face_size = 0;
    r = tt_mesh_build(&d, &mesh, &err);
    CHECK(r == TT_OK, "fixed_face_size 0 (= 3) on a tetrahedron: got %d (%s)", r, err.message);
    if (r == TT_OK) tt_mesh_free(mesh);

    /* empty mesh */
    {
        tmesh e = m;
        e.nf = 0;
        expect_build_error(&e, TT_ERROR_EMPTY_MESH, -1, -1, -1, "empty mesh");
    }
    /* index out of range: negative, and too big */
    m.idx[5] = -1;
    expect_build_error(&m, TT_ERROR_INDEX_OUT_OF_RANGE, 1, 5, -1, "negative index");
    m.idx[5] = 3;
    m.idx[7] = 4;
    expect_build_error(&m, TT_ERROR_INDEX_OUT_OF_RANGE, 2, 7, 4, "index too big");
    m.idx[7] = 3;
    /* face with 2 corners */
    m.sizes[1] = 2;
    expect_build_error(&m, TT_ERROR_FACE_TOO_SMALL, 1, 3, -2, "face_sizes entry 2");
    m.sizes[1] = 3;
    /* repeated vertex: face 2 = (a, d, a) */
    {
        int keep = m.idx[8];
        m.idx[8] = m.idx[6];
        expect_build_error(&m, TT_ERROR_REPEATED_VERTEX, 2, 8, m.idx[6], "repeated vertex");
        m.idx[8] = keep;
    }
    /* NaN and infinite coordinates */
    {
        float keep = m.pos[3 * 2 + 1];
        m.pos[3 * 2 + 1] = (float)NAN;
        expect_build_error(&m, TT_ERROR_NON_FINITE, -1, -2, 2, "NaN coordinate");
        m.pos[3 * 2 + 1] = keep;
        keep = m.pos[3 * 3 + 2];
        m.pos[3 * 3 + 2] = -(float)INFINITY;
        expect_build_error(&m, TT_ERROR_NON_FINITE, -1, -2, 3, "-inf coordinate");
        m.pos[3 * 3 + 2] = (float)INFINITY;
        expect_build_error(&m, TT_ERROR_NON_FINITE, -1, -2, 3, "+inf coordinate");
        m.pos[3 * 3 + 2] = keep;
    }
    /* The untouched tetrahedron still builds (the edits were undone). */
    r = build(&m, 0, &mesh, &err);
    CHECK(r == TT_OK, "restored tetrahedron: got %d (%s)", r, err.message);
    if (r == TT_OK) tt_mesh_free(mesh);
    tm_free(&m);

    /* zero-area face: 3 collinear points (an open mesh of one good and one flat face) */
    tm_vert(&m, 0, 0, 0); tm_vert(&m, 1, 0, 0); tm_vert(&m, 0, 1, 0);
    tm_vert(&m, 2, 0, 0); tm_vert(&m, 3, 0, 0);
    tm_tri(&m, 0, 1, 2);
    tm_tri(&m, 1, 3, 4);
    expect_build_error(&m, TT_ERROR_ZERO_AREA_FACE, 1, 3, -2, "zero-area face");
    expect_permissive(&m, 0, "zero-area face");
    tm_free(&m);

    /* non-manifold edge: 3 triangles on edge 0-1 */
    {
        int va = -1, vb = -1, first;
        tt_result code = TT_OK;
        tm_vert(&m, 0, 0, 0); tm_vert(&m, 1, 0, 0); tm_vert(&m, 0.5, 1, 0);
        tm_vert(&m, 0.5, -1, 0); tm_vert(&m, 0.5, 0, 1);
        tm_tri(&m, 0, 1, 2);
        tm_tri(&m, 1, 0, 3);
        tm_tri(&m, 0, 1, 4);
        first = naive_first_edge_problem(&m, &code, &va, &vb);
        CHECK(first == 0 && code == TT_ERROR_NON_MANIFOLD_EDGE, "naive reference: corner %d code %d", first, code);
        expect_build_error(&m, TT_ERROR_NON_MANIFOLD_EDGE, 0, 0, -2, "non-manifold edge");
        r = build(&m, 0, &mesh, &err);
        if (r == TT_OK) tt_mesh_free(mesh);
        CHECK((err.vertex == 0 && err.other_vertex == 1) || (err.vertex == 1 && err.other_vertex == 0),
              "non-manifold edge: vertices expected 0 and 1, got %d and %d", err.vertex, err.other_vertex);
        expect_permissive(&m, 1, "non-manifold edge");
        tm_free(&m);

        /* The same three triangles with the lone reverse half-edge first:
           the first problem in index-buffer order is corner 0 of face 0. */
        tm_vert(&m, 0, 0, 0); tm_vert(&m, 1, 0, 0); tm_vert(&m, 0.5, 1, 0);
        tm_vert(&m, 0.5, -1, 0); tm_vert(&m, 0.5, 0, 1);
        tm_tri(&m, 1, 0, 3);
        tm_tri(&m, 0, 1, 2);
        tm_tri(&m, 0, 1, 4);
        first = naive_first_edge_problem(&m, &code, &va, &vb);
        expect_build_error(&m, TT_ERROR_NON_MANIFOLD_EDGE, face_of_corner(&m, first), first, -2,
                           "non-manifold edge (reverse half-edge first)");
        tm_free(&m);
    }

    /* inconsistent orientation: one face of a cube flipped */
    {
        int f, flip = 3, va = -1, vb = -1, first;
        tt_result code = TT_OK;
        for (f = 0; f < 6; f++) {
            int i, *q;
            make_cube(&m, 0);
            flip = f;
            q = m.idx + 4 * flip;
            for (i = 0; i < 2; i++) { int t = q[i]; q[i] = q[3 - i]; q[3 - i] = t; }
            first = naive_first_edge_problem(&m, &code, &va, &vb);
            CHECK(code == TT_ERROR_INCONSISTENT_ORIENTATION, "naive reference code %d", code);
            expect_build_error(&m, TT_ERROR_INCONSISTENT_ORIENTATION, face_of_corner(&m, first), first, -2,
                               "cube with a flipped face");
            r = build(&m, 0, &mesh, &err);
            if (r == TT_OK) tt_mesh_free(mesh);
            CHECK((err.vertex == va && err.other_vertex == vb) || (err.vertex == vb && err.other_vertex == va),
                  "flipped face %d: edge expected %d-%d, got %d-%d", f, va, vb, err.vertex, err.other_vertex);
            CHECK(msg_has_number(err.message, face_of_corner(&m, first)),
                  "flipped face %d: message should name face %d: \"%s\"", f, face_of_corner(&m, first), err.message);
            if (f == 0) expect_permissive(&m, 4, "cube with a flipped face");
            tm_free(&m);
        }
    }

    /* non-manifold vertex: two tetrahedra sharing only vertex 0 */
    {
        int ok_corner;
        make_tetra(&m, 0);
        tm_vert(&m, -1, 0, 0); tm_vert(&m, 0, -1, 0); tm_vert(&m, 0, 0, -1);
        tm_tri(&m, 0, 4, 5);
        tm_tri(&m, 0, 6, 4);
        tm_tri(&m, 0, 5, 6);
        tm_tri(&m, 4, 6, 5);
        r = build(&m, 0, &mesh, &err);
        if (r == TT_OK) tt_mesh_free(mesh);
        CHECK(r == TT_ERROR_NON_MANIFOLD_VERTEX, "two tetrahedra at a vertex: expected %d, got %d (%s)",
              TT_ERROR_NON_MANIFOLD_VERTEX, r, err.message);
        CHECK(err.vertex == 0, "non-manifold vertex: expected vertex 0, got %d", err.vertex);
        ok_corner = err.corner >= 0 && err.corner < m.nc && m.idx[err.corner] == 0 &&
                    face_of_corner(&m, err.corner) == err.face;
        CHECK(ok_corner, "non-manifold vertex: corner %d / face %d should be a corner of vertex 0 in that face",
              err.corner, err.face);
        expect_build_error(&m, TT_ERROR_NON_MANIFOLD_VERTEX, -2, -2, 0, "non-manifold vertex");
        expect_permissive(&m, 0, "non-manifold vertex");
        r = build(&m, TT_MESH_PERMISSIVE, &mesh, &err);
        if (r == TT_OK) {
            tt_mesh_stats st;
            tt_mesh_compute_stats(mesh, &st);
            CHECK(st.nonmanifold_vertices == 1, "permissive: nonmanifold_vertices expected 1, got %d",
                  st.nonmanifold_vertices);
            CHECK(st.components == 2, "two tetrahedra at a vertex: components expected 2, got %d", st.components);
            CHECK(st.genus == 0, "two tetrahedra at a vertex: genus expected 0, got %d", st.genus);
            tt_mesh_free(mesh);
        }
        tm_free(&m);
    }

    /* permissive repeated vertex: a degenerate edge becomes a boundary */
    {
        make_tetra(&m, 0);
        tm_vert(&m, 3, 3, 3);
        tm_vert(&m, 4, 3, 3);
        tm_tri(&m, 4, 5, 4);
        expect_build_error(&m, TT_ERROR_REPEATED_VERTEX, 4, 14, 4, "repeated vertex (extra face)");
        expect_permissive(&m, 1, "repeated vertex");
        tm_free(&m);
    }
    /* repeated vertex in a large face (stamping path, > 16 corners) */
    {
        int i, v[20];
        for (i = 0; i < 20; i++) v[i] = tm_vert(&m, cos(i * 0.314159), sin(i * 0.314159), 0);
        v[17] = v[3];
        tm_face(&m, 20, v);
        expect_build_error(&m, TT_ERROR_REPEATED_VERTEX, 0, 17, 3, "repeated vertex in a 20-gon");
        tm_free(&m);
    }
}

/* Run `call` with allocation k failing for k = 0, 1, ... until it succeeds:
   every run must give TT_OK or TT_ERROR_OUT_OF_MEMORY and leak nothing. */
typedef tt_result (*oom_call)(void *ctx, const tt_allocator *allocator);

/* The allocator and counter every OOM sweep uses. Objects built through it
   before a sweep (meshes whose own allocator is this one) stay live: a run
   must leave `live` where it found it. */
static counter g_oom_counter;
static tt_allocator g_oom_allocator;

static void oom_reset(void) { g_oom_allocator = make_allocator(&g_oom_counter, -1); }

static void oom_sweep(const char *what, oom_call call, void *ctx, tt_result expected_final)
{
    int k, bad_result = 0, leaks = 0, bad_frees = 0, nsteps = 0;
    tt_result r = TT_ERROR_OUT_OF_MEMORY, first_bad = TT_OK;
    counter *cnt = &g_oom_counter;
    for (k = 0; k < 100000; k++) {
        long live0 = cnt->live, bad0 = cnt->bad_frees;
        cnt->calls = 0;
        cnt->failures = 0;
        cnt->fail_at = k;
        r = call(ctx, &g_oom_allocator);
        nsteps++;
        if (cnt->live != live0) leaks++;
        if (cnt->bad_frees != bad0) bad_frees++;
        if (cnt->failures == 0) break;   /* allocation k was never reached: the run is complete */
        if (r != TT_ERROR_OUT_OF_MEMORY) { if (!bad_result) first_bad = r; bad_result++; }
    }
    cnt->fail_at = -1;
    CHECK(r == expected_final, "%s: after %d allocation-failure runs, expected final result %d, got %d", what, nsteps,
          expected_final, r);
    CHECK(bad_result == 0, "%s: %d runs with a failed allocation did not return TT_ERROR_OUT_OF_MEMORY (first: %d)",
          what, bad_result, first_bad);
    CHECK(leaks == 0 && bad_frees == 0, "%s: %d runs leaked, %d freed foreign pointers", what, leaks, bad_frees);
    CHECK(nsteps > 1, "%s: expected at least one allocation, got %d runs", what, nsteps);
}

typedef struct build_ctx {
    const tmesh *m;
    unsigned flags;
} build_ctx;

static tt_result oom_build(void *ctx, const tt_allocator *al)
{
    build_ctx *b = (build_ctx *)ctx;
    tt_mesh_desc d = tm_desc(b->m);
    tt_mesh *mesh = (tt_mesh *)&mesh;
    tt_error err;
    tt_result r;
    d.flags = b->flags;
    d.allocator = *al;
    r = tt_mesh_build(&d, &mesh, &err);
    if (r == TT_OK) tt_mesh_free(mesh);
    else if (mesh != NULL) return TT_RESULT_MAX_ENUM;   /* must be NULL on failure */
    if (r != TT_OK && err.result != r) return TT_RESULT_MAX_ENUM;
    return r;
}

static void test_builder_oom(void)
{
    tmesh m;
    build_ctx b;
    memset(&m, 0, sizeof m);
    oom_reset();
    b.m = &m;
    b.flags = 0;
    make_tetra(&m, 0);
    oom_sweep("tt_mesh_build(tetrahedron)", oom_build, &b, TT_OK);
    tm_free(&m);
    make_mixed(&m);
    oom_sweep("tt_mesh_build(mixed)", oom_build, &b, TT_OK);
    b.flags = TT_MESH_BORROW_POSITIONS;
    oom_sweep("tt_mesh_build(mixed, borrowed)", oom_build, &b, TT_OK);
    b.flags = 0;
    tm_free(&m);
    {
        int i, v[40];
        for (i = 0; i < 40; i++) v[i] = tm_vert(&m, cos(i * 0.15707963), sin(i * 0.15707963), 0);
        tm_face(&m, 40, v);
        oom_sweep("tt_mesh_build(40-gon)", oom_build, &b, TT_OK);
        tm_free(&m);
    }
    /* An invalid mesh: every run is OOM or the validation error, never a leak. */
    make_cube(&m, 0);
    { int t = m.idx[0]; m.idx[0] = m.idx[2]; m.idx[2] = t; }
    oom_sweep("tt_mesh_build(flipped cube)", oom_build, &b, TT_ERROR_INCONSISTENT_ORIENTATION);
    b.flags = TT_MESH_PERMISSIVE;
    oom_sweep("tt_mesh_build(flipped cube, permissive)", oom_build, &b, TT_OK);
    tm_free(&m);
}

/* ------------------------------------------------------------------------ */
/* 2b. Mesh queries                                                         */
/* ------------------------------------------------------------------------ */

/* Naive valence: distinct neighbours over all faces. */
static int naive_valence(const tt_mesh *mesh, int v, int *scratch)
{
    int c, n = 0, i;
    for (c = 0; c < mesh->ncorners; c++) {
        int a = mesh->corner_vert[c], b = mesh->corner_vert[tt_mesh_next(mesh, c)], other = -1, dup = 0;
        if (a == v) other = b;
        else if (b == v) other = a;
        if (other < 0) continue;
        for (i = 0; i < n; i++) if (scratch[i] == other) dup = 1;
        if (!dup) scratch[n++] = other;
    }
    return n;
}

static int uf_find(int *parent, int x)
{
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
}

typedef struct expect_stats {
    int used, edges, boundary_edges, loops, components, chi, genus, min_val, max_val;
} expect_stats;

static void check_queries(const tmesh *m, const expect_stats *e, const char *name)
{
    tt_mesh *mesh;
    tt_error err;
    tt_mesh_stats st;
    tt_result r;
    counter cnt;
    tt_mesh_desc d = tm_desc(m);
    d.allocator = make_allocator(&cnt, -1);
    r = tt_mesh_build(&d, &mesh, &err);
    CHECK(r == TT_OK, "%s: build failed: %d (%s)", name, r, err.message);
    if (r != TT_OK) return;
    r = tt_mesh_compute_stats(mesh, &st);
    CHECK(r == TT_OK, "%s: compute_stats returned %d", name, r);
    CHECK(st.used_vertices == e->used, "%s: used_vertices expected %d, got %d", name, e->used, st.used_vertices);
    CHECK(st.edges == e->edges, "%s: edges expected %d, got %d", name, e->edges, st.edges);
    CHECK(st.boundary_edges == e->boundary_edges, "%s: boundary_edges expected %d, got %d", name, e->boundary_edges,
          st.boundary_edges);
    CHECK(st.boundary_loops == e->loops, "%s: boundary_loops expected %d, got %d", name, e->loops, st.boundary_loops);
    CHECK(st.components == e->components, "%s: components expected %d, got %d", name, e->components, st.components);
    CHECK(st.euler_characteristic == e->chi, "%s: chi expected %d, got %d", name, e->chi, st.euler_characteristic);
    CHECK(st.genus == e->genus, "%s: genus expected %d, got %d", name, e->genus, st.genus);
    CHECK(st.min_valence == e->min_val && st.max_valence == e->max_val, "%s: valence expected %d..%d, got %d..%d",
          name, e->min_val, e->max_val, st.min_valence, st.max_valence);
    CHECK(st.nonmanifold_vertices == 0, "%s: nonmanifold_vertices expected 0, got %d", name, st.nonmanifold_vertices);

    /* valence against the naive count; histogram against naive valences */
    {
        int *scratch = (int *)malloc(sizeof(int) * (size_t)mesh->ncorners * 2 + 8);
        int *naive = (int *)calloc((size_t)mesh->nverts + 1, sizeof(int));
        int hist[64], nhist[64], v, bad = 0, total = 0, nb;
        for (v = 0; v < mesh->nverts; v++) {
            naive[v] = naive_valence(mesh, v, scratch);
            if (tt_mesh_valence(mesh, v) != naive[v]) {
                if (!bad) DETAIL("%s: tt_mesh_valence(%d) expected %d, got %d", name, v, naive[v],
                                tt_mesh_valence(mesh, v));
                bad++;
            }
        }
        CHECK(bad == 0, "%s: %d vertices with a wrong valence", name, bad);
        CHECK(tt_mesh_valence(mesh, -1) == 0 && tt_mesh_valence(mesh, mesh->nverts) == 0,
              "%s: valence of an out-of-range vertex should be 0", name);
        for (nb = 1; nb <= 64; nb = nb < 8 ? nb + 1 : nb * 2) {
            int k;
            memset(nhist, 0, sizeof nhist);
            for (v = 0; v < mesh->nverts; v++)
                if (mesh->vert_corner[v] >= 0) nhist[naive[v] < nb - 1 ? naive[v] : nb - 1]++;
            for (k = 0; k < 64; k++) hist[k] = -7;
            r = tt_mesh_valence_histogram(mesh, hist, nb);
            bad = 0;
            total = 0;
            for (k = 0; k < nb; k++) { bad += hist[k] != nhist[k]; total += hist[k]; }
            for (k = nb; k < 64; k++) bad += hist[k] != -7;   /* no write past nbins */
            CHECK(r == TT_OK && bad == 0 && total == st.used_vertices,
                  "%s: valence histogram with %d bins: %d bins differ from the naive one (total %d, used %d)", name, nb,
                  bad, total, st.used_vertices);
        }
        CHECK(tt_mesh_valence_histogram(mesh, hist, 0) == TT_ERROR_INVALID_ARGUMENT,
              "%s: histogram with 0 bins should be rejected", name);
        CHECK(tt_mesh_valence_histogram(NULL, hist, 4) == TT_ERROR_INVALID_ARGUMENT &&
                  tt_mesh_valence_histogram(mesh, NULL, 4) == TT_ERROR_INVALID_ARGUMENT,
              "%s: histogram with NULL should be rejected", name);
        free(scratch);
        free(naive);
    }

    /* components: naive union-find over shared edges, numbered by first face */
    {
        int *comp = (int *)malloc(sizeof(int) * (size_t)mesh->nfaces);
        int *parent = (int *)malloc(sizeof(int) * (size_t)mesh->nfaces);
        int *label = (int *)malloc(sizeof(int) * (size_t)mesh->nfaces);
        int n = -1, f, c, c2, next = 0, bad = 0;
        for (f = 0; f < mesh->nfaces; f++) { parent[f] = f; label[f] = -1; }
        for (c = 0; c < mesh->ncorners; c++)
            for (c2 = c + 1; c2 < mesh->ncorners; c2++) {
                int a = mesh->corner_vert[c], b = mesh->corner_vert[tt_mesh_next(mesh, c)];
                int a2 = mesh->corner_vert[c2], b2 = mesh->corner_vert[tt_mesh_next(mesh, c2)];
                if (a == b2 && b == a2) {
                    int x = uf_find(parent, mesh->corner_face[c]), y = uf_find(parent, mesh->corner_face[c2]);
                    if (x != y) parent[x] = y;
                }
            }
        r = tt_mesh_components(mesh, comp, &n);
        CHECK(r == TT_OK && n == e->components, "%s: tt_mesh_components: expected %d, got %d (result %d)", name,
              e->components, n, r);
        for (f = 0; f < mesh->nfaces; f++) {
            int root = uf_find(parent, f);
            if (label[root] < 0) label[root] = next++;
            if (comp[f] != label[root]) bad++;
        }
        CHECK(bad == 0 && next == n, "%s: %d faces with a component id other than the naive one", name, bad);
        CHECK(tt_mesh_components(mesh, NULL, &n) == TT_ERROR_INVALID_ARGUMENT, "%s: components(NULL)", name);
        free(comp);
        free(parent);
        free(label);
    }

    /* boundary loops: ids, count, and each boundary half-edge's successor
       (the boundary half-edge leaving its end vertex) is in the same loop */
    {
        int *loop = (int *)malloc(sizeof(int) * (size_t)mesh->ncorners);
        int n = -1, c, c2, bad = 0, nb = 0, *seen;
        r = tt_mesh_boundary_loops(mesh, loop, &n);
        CHECK(r == TT_OK && n == e->loops, "%s: tt_mesh_boundary_loops: expected %d loops, got %d (result %d)", name,
              e->loops, n, r);
        seen = (int *)calloc((size_t)(n > 0 ? n : 1), sizeof(int));
        for (c = 0; c < mesh->ncorners; c++) {
            if (mesh->twin[c] >= 0) { bad += loop[c] != -1; continue; }
            nb++;
            if (loop[c] < 0 || loop[c] >= n) { bad++; continue; }
            seen[loop[c]] = 1;
            for (c2 = 0; c2 < mesh->ncorners; c2++)
                if (mesh->twin[c2] < 0 && mesh->corner_vert[c2] == mesh->corner_vert[tt_mesh_next(mesh, c)] &&
                    loop[c2] != loop[c])
                    bad++;
        }
        for (c = 0; c < n; c++) bad += !seen[c];
        CHECK(bad == 0, "%s: %d inconsistencies in the boundary loop ids", name, bad);
        CHECK(nb == st.boundary_edges, "%s: boundary half-edges %d vs stats %d", name, nb, st.boundary_edges);
        free(loop);
        free(seen);
    }
    CHECK(tt_mesh_compute_stats(NULL, &st) == TT_ERROR_INVALID_ARGUMENT &&
              tt_mesh_compute_stats(mesh, NULL) == TT_ERROR_INVALID_ARGUMENT,
          "%s: compute_stats with NULL should be rejected", name);
    tt_mesh_free(mesh);
    CHECK(cnt.live == 0, "%s: %ld allocations leaked by the queries", name, cnt.live);
}

static void test_queries(void)
{
    tmesh m;
    expect_stats e;
    memset(&m, 0, sizeof m);

    make_tetra(&m, 0);
    e.used = 4; e.edges = 6; e.boundary_edges = 0; e.loops = 0; e.components = 1; e.chi = 2; e.genus = 0;
    e.min_val = 3; e.max_val = 3;
    check_queries(&m, &e, "tetrahedron");
    tm_free(&m);

    make_torus(&m, 8, 6, 3.0, 1.0);
    e.used = 48; e.edges = 96; e.boundary_edges = 0; e.loops = 0; e.components = 1; e.chi = 0; e.genus = 1;
    e.min_val = 4; e.max_val = 4;
    check_queries(&m, &e, "torus 8x6");
    tm_free(&m);

    /* genus 2: 3x5 slab of voxels with two holes. 13 voxels; lattice 4x6x2
       all used = 48 vertices; F = 2*13 top/bottom + side walls. */
    make_genus2(&m);
    e.used = 48; e.boundary_edges = 0; e.loops = 0; e.components = 1; e.chi = -2; e.genus = 2;
    e.edges = 48 + m.nf + 2;   /* V - E + F = -2 */
    e.min_val = 3; e.max_val = 5;
    check_queries(&m, &e, "genus-2 polycube");
    tm_free(&m);

    make_grid(&m, 4, 3);
    e.used = 20; e.edges = 31; e.boundary_edges = 14; e.loops = 1; e.components = 1; e.chi = 1; e.genus = 0;
    e.min_val = 2; e.max_val = 4;
    check_queries(&m, &e, "open grid 4x3");
    tm_free(&m);

    /* annulus: 5x5 grid without its centre quad: 2 loops, chi 0, genus 0 */
    {
        tmesh g;
        int f;
        memset(&g, 0, sizeof g);
        make_grid(&g, 5, 5);
        for (f = 0; f < 36; f++) tm_vert(&m, g.pos[3 * f], g.pos[3 * f + 1], g.pos[3 * f + 2]);
        for (f = 0; f < g.nf; f++)
            if (f != 12) tm_face(&m, 4, g.idx + 4 * f);
        tm_free(&g);
        e.used = 36; e.edges = 60 - 0; e.boundary_edges = 24; e.loops = 2; e.components = 1; e.chi = 0; e.genus = 0;
        e.min_val = 2; e.max_val = 4;
        check_queries(&m, &e, "annulus");
        tm_free(&m);
    }

    make_cube(&m, 0);
    make_cube(&m, 3);
    e.used = 16; e.edges = 24; e.boundary_edges = 0; e.loops = 0; e.components = 2; e.chi = 4; e.genus = 0;
    e.min_val = 3; e.max_val = 3;
    check_queries(&m, &e, "two cubes");
    tm_free(&m);

    make_mixed(&m);
    e.used = 15; e.edges = 23; e.boundary_edges = 0; e.loops = 0; e.components = 2; e.chi = 4; e.genus = 0;
    e.min_val = 3; e.max_val = 4;
    check_queries(&m, &e, "prism + pyramid");
    tm_free(&m);

    /* two tori and a grid: genus 2, 3 components, 1 loop */
    make_torus(&m, 5, 4, 3.0, 1.0);
    make_torus(&m, 3, 3, 3.0, 1.0);
    make_grid(&m, 1, 1);
    e.used = 20 + 9 + 4; e.edges = 40 + 18 + 4; e.boundary_edges = 4; e.loops = 1; e.components = 3;
    e.chi = 0 + 0 + 1; e.genus = 2; e.min_val = 2; e.max_val = 4;
    check_queries(&m, &e, "two tori and a quad");
    tm_free(&m);
}

typedef struct mesh_ctx {
    tt_mesh *mesh;
    tt_subdivision scheme;
} mesh_ctx;

static tt_result oom_stats(void *ctx, const tt_allocator *al)
{
    tt_mesh_stats st;
    (void)al;   /* the mesh was built with it */
    return tt_mesh_compute_stats(((mesh_ctx *)ctx)->mesh, &st);
}

static tt_result oom_quad(void *ctx, const tt_allocator *al)
{
    mesh_ctx *q = (mesh_ctx *)ctx;
    tt_mesh *out = (tt_mesh *)&out;
    tt_error err;
    tt_result r = tt_mesh_quadrangulate(q->mesh, q->scheme, &out, &err);
    (void)al;
    if (r == TT_OK) tt_mesh_free(out);
    else if (out != NULL) return TT_RESULT_MAX_ENUM;
    return r;
}

static void test_queries_oom(void)
{
    tmesh m;
    tt_mesh_desc d;
    mesh_ctx q;
    tt_result r;
    memset(&m, 0, sizeof m);
    oom_reset();
    make_grid(&m, 3, 2);
    make_torus(&m, 4, 3, 3.0, 1.0);
    tm_tri(&m, 0, 1, 5);   /* the grid's first row gets a triangle below: mixed sizes */
    {
        /* fix the triangle's orientation: grid face 0 is 0,1,5,4 so edge 0->1
           is used; a face below must use 1->0 */
        int *t = m.idx + m.nc - 3;
        t[0] = 1; t[1] = 0; t[2] = tm_vert(&m, 0.5, -1, 0);
    }
    d = tm_desc(&m);
    d.allocator = g_oom_allocator;
    r = tt_mesh_build(&d, &q.mesh, NULL);
    CHECK(r == TT_OK, "oom mesh: build got %d", r);
    if (r != TT_OK) { tm_free(&m); return; }
    oom_sweep("tt_mesh_compute_stats", oom_stats, &q, TT_OK);
    q.scheme = TT_SUBDIVIDE_LINEAR;
    oom_sweep("tt_mesh_quadrangulate(linear)", oom_quad, &q, TT_OK);
    q.scheme = TT_SUBDIVIDE_CATMULL_CLARK;
    oom_sweep("tt_mesh_quadrangulate(Catmull-Clark)", oom_quad, &q, TT_OK);
    tt_mesh_free(q.mesh);
    CHECK(g_oom_counter.live == 0, "oom mesh: %ld allocations leaked", g_oom_counter.live);
    tm_free(&m);
}

/* ------------------------------------------------------------------------ */
/* 2c. Quadrangulation                                                      */
/* ------------------------------------------------------------------------ */

static int count_edges(const tt_mesh *mesh)
{
    int c, n = 0;
    for (c = 0; c < mesh->ncorners; c++) n += mesh->twin[c] < 0 || c < mesh->twin[c];
    return n;
}

static int vec_near(const float *a, const double *b, double tol)
{
    return near(a[0], b[0], tol) && near(a[1], b[1], tol) && near(a[2], b[2], tol);
}

/* One linear step on `mesh`: counts, layout, positions; returns the result. */
static tt_mesh *check_quad_step(const tt_mesh *mesh, tt_subdivision scheme, const char *name)
{
    tt_mesh *out = NULL;
    tt_error err;
    tt_result r = tt_mesh_quadrangulate(mesh, scheme, &out, &err);
    int E = count_edges(mesh), c, f, bad_quad = 0, bad_v0 = 0, bad_pos = 0, bad_face = 0, bad_edge = 0;
    CHECK(r == TT_OK, "%s: quadrangulate returned %d (%s)", name, r, err.message);
    if (r != TT_OK) return NULL;
    CHECK(out->nverts == mesh->nverts + E + mesh->nfaces, "%s: V' expected V+E+F = %d+%d+%d, got %d", name,
          mesh->nverts, E, mesh->nfaces, out->nverts);
    CHECK(out->nfaces == mesh->ncorners, "%s: F' expected %d (one quad per corner), got %d", name, mesh->ncorners,
          out->nfaces);
    CHECK(out->ncorners == 4 * mesh->ncorners, "%s: corners expected %d, got %d", name, 4 * mesh->ncorners,
          out->ncorners);
    CHECK(out->min_face_size == 4 && out->max_face_size == 4, "%s: face sizes %d..%d, expected quads", name,
          out->min_face_size, out->max_face_size);
    CHECK(out->flags == (mesh->flags & ~(unsigned)TT_MESH_BORROW_POSITIONS), "%s: flags expected 0x%x, got 0x%x",
          name, mesh->flags & ~(unsigned)TT_MESH_BORROW_POSITIONS, out->flags);
    for (f = 0; f < out->nfaces; f++) bad_quad += out->face_start[f + 1] - out->face_start[f] != 4;
    /* quad c (c = old corner i of face f): corner 0 = old vertex of c; corner 1
       = point of the edge of half-edge c; corner 2 = face point; corner 3 =
       point of the edge of the previous half-edge. */
    for (f = 0; f < mesh->nfaces; f++) {
        int first = mesh->face_start[f], end = mesh->face_start[f + 1], n = end - first, k;
        double centroid[3] = {0, 0, 0};
        for (c = first; c < end; c++)
            for (k = 0; k < 3; k++) centroid[k] += mesh->pos[3 * mesh->corner_vert[c] + k] / n;
        for (c = first; c < end; c++) {
            const int *q = out->corner_vert + 4 * c;
            int prev = tt_mesh_prev(mesh, c), next = tt_mesh_next(mesh, c);
            const float *a = mesh->pos + 3 * mesh->corner_vert[c], *b = mesh->pos + 3 * mesh->corner_vert[next];
            const float *p0 = mesh->pos + 3 * mesh->corner_vert[prev];
            double mid[3], midp[3];
            for (k = 0; k < 3; k++) {
                mid[k] = 0.5 * ((double)a[k] + b[k]);
                midp[k] = 0.5 * ((double)p0[k] + a[k]);
            }
            if (q[0] != mesh->corner_vert[c]) bad_v0++;
            if (q[2] != mesh->nverts + E + f) bad_face++;
            if (q[1] < mesh->nverts || q[1] >= mesh->nverts + E || q[3] < mesh->nverts || q[3] >= mesh->nverts + E)
                bad_edge++;
            if (scheme == TT_SUBDIVIDE_LINEAR) {
                double old[3];
                for (k = 0; k < 3; k++) old[k] = a[k];
                if (!vec_near(out->pos + 3 * q[0], old, 0.0)) bad_pos++;
                if (!vec_near(out->pos + 3 * q[1], mid, 1e-6)) bad_pos++;
                if (!vec_near(out->pos + 3 * q[3], midp, 1e-6)) bad_pos++;
            }
            if (!vec_near(out->pos + 3 * q[2], centroid, 1e-5)) bad_pos++;
        }
    }
    /* edge points are numbered in order of their first half-edge */
    {
        int next_id = 0, bad_order = 0;
        for (c = 0; c < mesh->ncorners; c++) {
            int t = mesh->twin[c];
            if (t >= 0 && t < c) {
                if (out->corner_vert[4 * c + 1] != out->corner_vert[4 * t + 1]) bad_order++;
                continue;
            }
            if (out->corner_vert[4 * c + 1] != mesh->nverts + next_id++) bad_order++;
        }
        CHECK(bad_order == 0, "%s: %d edge points not numbered by first half-edge", name, bad_order);
    }
    CHECK(bad_quad == 0, "%s: %d faces are not quads", name, bad_quad);
    CHECK(bad_v0 == 0, "%s: %d quads whose corner 0 is not the old vertex", name, bad_v0);
    CHECK(bad_face == 0, "%s: %d quads whose corner 2 is not their face point", name, bad_face);
    CHECK(bad_edge == 0, "%s: %d quads whose corners 1/3 are not edge points", name, bad_edge);
    CHECK(bad_pos == 0, "%s: %d new positions differ from midpoints / centroids / old positions", name, bad_pos);
    return out;
}

static void check_topology_kept(const tt_mesh *a, const tt_mesh *b, const char *name)
{
    tt_mesh_stats sa, sb;
    CHECK(tt_mesh_compute_stats(a, &sa) == TT_OK && tt_mesh_compute_stats(b, &sb) == TT_OK, "%s: stats", name);
    CHECK(sa.euler_characteristic == sb.euler_characteristic && sa.genus == sb.genus &&
              sa.components == sb.components && sa.boundary_loops == sb.boundary_loops &&
              2 * sa.boundary_edges == sb.boundary_edges,
          "%s: chi/genus/components/loops/boundary: %d/%d/%d/%d/%d before, %d/%d/%d/%d/%d after", name,
          sa.euler_characteristic, sa.genus, sa.components, sa.boundary_loops, sa.boundary_edges,
          sb.euler_characteristic, sb.genus, sb.components, sb.boundary_loops, sb.boundary_edges);
}

/* Quadrangulation builds its output's topology directly from the input's.
   Rebuild the same index buffer with the validating builder (a permissive one
   for a permissive input) and demand the same twins, and vert_corner entries
   that leave the right vertex and are boundaries exactly where one exists. */
static void check_direct_topology(const tt_mesh *q, const char *name)
{
    tt_mesh_desc d;
    tt_mesh *rebuilt = NULL;
    tt_error err;
    int c, v, bad_twin = 0, bad_vc = 0;
    memset(&d, 0, sizeof d);
    d.positions = q->pos;
    d.nverts = q->nverts;
    d.indices = q->corner_vert;
    d.nfaces = q->nfaces;
    d.fixed_face_size = 4;
    d.flags = TT_MESH_PERMISSIVE;   /* zero-area quads are possible in the output */
    if (tt_mesh_build(&d, &rebuilt, &err) != TT_OK) {
        CHECK(0, "%s: rebuilding the quadrangulation failed: %s", name, err.message);
        return;
    }
    for (c = 0; c < q->ncorners; c++) {
        if (q->twin[c] != rebuilt->twin[c]) bad_twin++;
        if (q->corner_face[c] != c / 4) bad_twin++;
    }
    for (v = 0; v < q->nverts; v++) {
        int h = q->vert_corner[v], want_boundary = rebuilt->vert_corner[v] >= 0 && rebuilt->twin[rebuilt->vert_corner[v]] < 0;
        if (h < 0 || q->corner_vert[h] != v || ((q->twin[h] < 0) != want_boundary)) bad_vc++;
    }
    CHECK(bad_twin == 0, "%s: %d twins / corner faces differ from a validated rebuild", name, bad_twin);
    CHECK(bad_vc == 0, "%s: %d vert_corner entries wrong", name, bad_vc);
    tt_mesh_free(rebuilt);
}

static void test_quadrangulate_direct(void)
{
    tmesh m;
    tt_mesh *mesh, *q;
    tt_error err;
    int which;
    memset(&m, 0, sizeof m);
    for (which = 0; which < 4; which++) {
        const char *name = which == 0 ? "mixed" : which == 1 ? "open grid" : which == 2 ? "genus-2" : "torus";
        if (which == 0) make_mixed(&m);
        if (which == 1) make_grid(&m, 4, 3);
        if (which == 2) make_genus2(&m);
        if (which == 3) make_torus(&m, 6, 5, 3.0, 1.0);
        if (build(&m, 0, &mesh, &err) == TT_OK) {
            if (tt_mesh_quadrangulate(mesh, TT_SUBDIVIDE_CATMULL_CLARK, &q, &err) == TT_OK) {
                check_direct_topology(q, name);
                tt_mesh_free(q);
            } else {
                CHECK(0, "%s: quadrangulate failed: %s", name, err.message);
            }
            tt_mesh_free(mesh);
        } else {
            CHECK(0, "%s: build failed: %s", name, err.message);
        }
        tm_free(&m);
    }
    /* A permissive mesh: three triangles on one edge (cut open) still
       quadrangulates into a consistent mesh. */
    tm_tri(&m, tm_vert(&m, 0, 0, 0), tm_vert(&m, 1, 0, 0), tm_vert(&m, 0, 1, 0));
    tm_tri(&m, 1, 0, tm_vert(&m, 0, -1, 0));
    tm_tri(&m, 0, 1, tm_vert(&m, 0, 0, 1));
    if (build(&m, TT_MESH_PERMISSIVE, &mesh, &err) == TT_OK) {
        CHECK(tt_mesh_quadrangulate(mesh, TT_SUBDIVIDE_LINEAR, &q, &err) == TT_OK, "permissive: %s", err.message);
        if (q) { check_direct_topology(q, "permissive"); tt_mesh_free(q); }
        tt_mesh_free(mesh);
    }
    tm_free(&m);
    /* A valid hexagon whose last four corners are distinct vertices at one
       point: its quads there have zero area, and quadrangulating must still
       succeed (it validated the input, not its own output). */
    {
        float p[18] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 1, 1, 0, 1, 1, 0, 1, 1, 0};
        int idx[6] = {0, 1, 2, 3, 4, 5};
        tt_mesh_desc d;
        memset(&d, 0, sizeof d);
        d.positions = p; d.nverts = 6; d.indices = idx; d.nfaces = 1; d.fixed_face_size = 6;
        if (tt_mesh_build(&d, &mesh, &err) == TT_OK) {
            tt_result r = tt_mesh_quadrangulate(mesh, TT_SUBDIVIDE_LINEAR, &q, &err);
            CHECK(r == TT_OK && q && q->nfaces == 6, "hexagon with coincident corners: result %d (%s)", r, err.message);
            tt_mesh_free(q);
            tt_mesh_free(mesh);
        } else {
            CHECK(0, "hexagon with coincident corners should build: %s", err.message);
        }
    }
    /* An empty face names no corner (there is none). */
    {
        float p[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
        int idx[3] = {0, 1, 2}, sizes[2] = {3, 0};
        tt_mesh_desc d;
        memset(&d, 0, sizeof d);
        d.positions = p; d.nverts = 3; d.indices = idx; d.face_sizes = sizes; d.nfaces = 2;
        CHECK(tt_mesh_build(&d, &mesh, &err) == TT_ERROR_FACE_TOO_SMALL && err.face == 1 && err.corner == -1,
              "empty face: face %d corner %d", err.face, err.corner);
    }
}

static void test_quadrangulate(void)
{
    tmesh m;
    tt_mesh *mesh, *q1, *q2;
    tt_error err;
    tt_result r;
    int which;
    memset(&m, 0, sizeof m);
    for (which = 0; which < 5; which++) {
        const char *name = which == 0 ? "tetrahedron" : which == 1 ? "mixed" : which == 2 ? "open grid"
                         : which == 3 ? "genus-2" : "torus";
        int s;
        if (which == 0) make_tetra(&m, 0);
        if (which == 1) make_mixed(&m);
        if (which == 2) { make_grid(&m, 3, 2); tm_tri(&m, 1, 0, tm_vert(&m, 0.5, -1, 0)); }
        if (which == 3) make_genus2(&m);
        if (which == 4) make_torus(&m, 5, 4, 3.0, 1.0);
        r = build(&m, 0, &mesh, &err);
        CHECK(r == TT_OK, "%s: build %d", name, r);
        if (r != TT_OK) { tm_free(&m); continue; }
        for (s = 0; s < 2; s++) {
            tt_subdivision scheme = s ? TT_SUBDIVIDE_CATMULL_CLARK : TT_SUBDIVIDE_LINEAR;
            q1 = check_quad_step(mesh, scheme, name);
            if (!q1) continue;
            q2 = check_quad_step(q1, scheme, name);   /* twice */
            check_topology_kept(mesh, q1, name);
            if (q2) {
                check_topology_kept(q1, q2, name);
                tt_mesh_free(q2);
            }
            tt_mesh_free(q1);
        }
        tt_mesh_free(mesh);
        tm_free(&m);
    }

    /* Catmull-Clark on a unit cube, by hand: the corner vertex at the origin
       has n = 3 faces with centroids (.5,.5,0), (.5,0,.5), (0,.5,.5), so
       Q = (1/3,1/3,1/3); its 3 edge midpoints average R = (1/6,1/6,1/6); S is
       the origin: (Q + 2R + (n-3)S)/n = (2/9, 2/9, 2/9). The edge point of
       (0,0,0)-(1,0,0) averages its ends and the centroids of faces z=0 and y=0:
       (0.5, 0.125, 0.125). The face point of z = 0 is (0.5, 0.5, 0). */
    make_cube(&m, 0);
    r = build(&m, 0, &mesh, &err);
    CHECK(r == TT_OK, "cube build %d", r);
    if (r == TT_OK) {
        r = tt_mesh_quadrangulate(mesh, TT_SUBDIVIDE_CATMULL_CLARK, &q1, &err);
        CHECK(r == TT_OK, "cube: Catmull-Clark returned %d", r);
        if (r == TT_OK) {
            int v, c, bad = 0, found_edge = 0;
            double expect_corner = 2.0 / 9.0;
            for (v = 0; v < mesh->nverts; v++) {
                double e[3];
                int k;
                for (k = 0; k < 3; k++)
                    e[k] = mesh->pos[3 * v + k] == 0.0f ? expect_corner : 1.0 - expect_corner;
                if (!vec_near(q1->pos + 3 * v, e, 1e-6)) {
                    if (!bad)
                        DETAIL("cube vertex %d (%g,%g,%g): expected (%g,%g,%g), got (%g,%g,%g)", v, mesh->pos[3 * v],
                              mesh->pos[3 * v + 1], mesh->pos[3 * v + 2], e[0], e[1], e[2], q1->pos[3 * v],
                              q1->pos[3 * v + 1], q1->pos[3 * v + 2]);
                    bad++;
                }
            }
            CHECK(bad == 0, "Catmull-Clark cube: %d of 8 corners not at 2/9 (or 7/9)", bad);
            for (c = 0; c < mesh->ncorners; c++) {
                const float *a = mesh->pos + 3 * mesh->corner_vert[c];
                const float *b = mesh->pos + 3 * mesh->corner_vert[tt_mesh_next(mesh, c)];
                if (a[0] == 0 && a[1] == 0 && a[2] == 0 && b[0] == 1 && b[1] == 0 && b[2] == 0) {
                    double e[3] = {0.5, 0.125, 0.125};
                    found_edge = 1;
                    CHECK(vec_near(q1->pos + 3 * q1->corner_vert[4 * c + 1], e, 1e-6),
                          "Catmull-Clark edge point of (0,0,0)-(1,0,0): expected (0.5,0.125,0.125), got (%g,%g,%g)",
                          q1->pos[3 * q1->corner_vert[4 * c + 1]], q1->pos[3 * q1->corner_vert[4 * c + 1] + 1],
                          q1->pos[3 * q1->corner_vert[4 * c + 1] + 2]);
                }
            }
            CHECK(found_edge, "the cube should have a half-edge (0,0,0)->(1,0,0)");
            tt_mesh_free(q1);
        }
        tt_mesh_free(mesh);
    }
    tm_free(&m);

    /* Catmull-Clark on an open grid: an interior vertex of a flat grid stays
       put, a boundary vertex with two boundary edges goes to 3/4 S + 1/8 of
       its boundary neighbours (= stays on a straight boundary), and edge
       points on the boundary are midpoints. */
    make_grid(&m, 3, 3);
    m.pos[3 * 1 + 1] = 0.5f;   /* lift boundary vertex (1,0) to y = .5: 3/4*.5 = .375 */
    r = build(&m, 0, &mesh, &err);
    if (r == TT_OK) {
        r = tt_mesh_quadrangulate(mesh, TT_SUBDIVIDE_CATMULL_CLARK, &q1, &err);
        CHECK(r == TT_OK, "grid CC %d", r);
        if (r == TT_OK) {
            double e5[3] = {1, 1, 0}, e1[3] = {1, 0.375, 0}, e0[3] = {0.125, 0.1875, 0};
            /* vertex 5 = (1,1): interior, flat, regular, but its neighbour (1,0)
               moved: Q and R change. Check only the boundary rules here. */
            (void)e5;
            CHECK(vec_near(q1->pos + 3, e1, 1e-6), "CC boundary vertex (1,.5): expected (1,.375,0), got (%g,%g,%g)",
                  q1->pos[3], q1->pos[4], q1->pos[5]);
            /* the grid corner (0,0) has 2 boundary edges, to (1,.5) and (0,1):
               3/4 (0,0) + 1/8 (1,.5) + 1/8 (0,1) = (.125, .1875) */
            CHECK(vec_near(q1->pos, e0, 1e-6), "CC grid corner: expected (0.125,0.1875,0), got (%g,%g,%g)",
                  q1->pos[0], q1->pos[1], q1->pos[2]);
            tt_mesh_free(q1);
        }
        tt_mesh_free(mesh);
    }
    tm_free(&m);

    /* bad arguments */
    make_tetra(&m, 0);
    r = build(&m, 0, &mesh, &err);
    if (r == TT_OK) {
        q1 = (tt_mesh *)&q1;
        CHECK(tt_mesh_quadrangulate(mesh, (tt_subdivision)7, &q1, &err) == TT_ERROR_INVALID_ARGUMENT && q1 == NULL,
              "unknown scheme should be rejected with *out NULL");
        CHECK(tt_mesh_quadrangulate(mesh, TT_SUBDIVIDE_LINEAR, NULL, &err) == TT_ERROR_INVALID_ARGUMENT,
              "out_mesh NULL should be rejected");
        CHECK(tt_mesh_quadrangulate(NULL, TT_SUBDIVIDE_LINEAR, &q1, &err) == TT_ERROR_INVALID_ARGUMENT && q1 == NULL,
              "mesh NULL should be rejected");
        tt_mesh_free(mesh);
    }
    tm_free(&m);
    tt_mesh_free(NULL);   /* allowed */
}

/* ------------------------------------------------------------------------ */
/* 3. Image                                                                 */
/* ------------------------------------------------------------------------ */

static float *px(const tt_image *im, int x, int y) { return im->pixels + ((size_t)y * im->width + x) * 4; }

static void fill_random(tt_image *im, unsigned seed)
{
    size_t i, n = (size_t)im->width * im->height * 4;
    lcg_seed(seed);
    for (i = 0; i < n; i++) im->pixels[i] = (float)lcg_unit();
}

static void test_image_basics(void)
{
    tt_image im;
    counter cnt;
    tt_allocator al = make_allocator(&cnt, -1);
    int ch, x, y, k, bad;
    unsigned char data[7 * 5 * 4 + 64], back[7 * 5 * 4];

    /* create: sizes */
    CHECK(tt_image_create(&im, 0, 5, NULL) == TT_ERROR_INVALID_ARGUMENT && im.pixels == NULL, "width 0 rejected");
    CHECK(tt_image_create(&im, 5, 0, NULL) == TT_ERROR_INVALID_ARGUMENT && im.pixels == NULL, "height 0 rejected");
    CHECK(tt_image_create(&im, -3, 5, NULL) == TT_ERROR_INVALID_ARGUMENT && im.pixels == NULL, "width -3 rejected");
    CHECK(tt_image_create(&im, 5, -1, NULL) == TT_ERROR_INVALID_ARGUMENT && im.pixels == NULL, "height -1 rejected");
    CHECK(tt_image_create(&im, TT_MAX_IMAGE_SIZE + 1, 1, NULL) == TT_ERROR_TOO_LARGE && im.pixels == NULL,
          "width TT_MAX_IMAGE_SIZE+1 should be TT_ERROR_TOO_LARGE");
    CHECK(tt_image_create(&im, 1, TT_MAX_IMAGE_SIZE + 1, NULL) == TT_ERROR_TOO_LARGE && im.pixels == NULL,
          "height TT_MAX_IMAGE_SIZE+1 should be TT_ERROR_TOO_LARGE");
    CHECK(tt_image_create(NULL, 4, 4, NULL) == TT_ERROR_INVALID_ARGUMENT, "image NULL rejected");
    CHECK(tt_image_create(&im, TT_MAX_IMAGE_SIZE, 1, &al) == TT_OK && im.width == TT_MAX_IMAGE_SIZE,
          "TT_MAX_IMAGE_SIZE x 1 is allowed");
    tt_image_free(&im);
    {
        counter fc;
        tt_allocator fail = make_allocator(&fc, 0);
        CHECK(tt_image_create(&im, 4, 4, &fail) == TT_ERROR_OUT_OF_MEMORY && im.pixels == NULL && fc.live == 0,
              "tt_image_create with a failing allocator: clean TT_ERROR_OUT_OF_MEMORY");
    }
    CHECK(tt_image_create(&im, 3, 2, &al) == TT_OK, "create 3x2");
    bad = 0;
    for (k = 0; k < 3 * 2 * 4; k++) bad += im.pixels[k] != 0.0f;
    CHECK(bad == 0 && im.width == 3 && im.height == 2, "a new image is zero-filled, %d non-zero values", bad);
    tt_image_free(&im);
    CHECK(im.pixels == NULL && im.width == 0, "tt_image_free resets the image");
    tt_image_free(&im);   /* twice is harmless */
    tt_image_free(NULL);

    /* from_bytes / to_rgba8 round trip, 1..4 channels, tight and padded stride */
    for (ch = 1; ch <= 4; ch++) {
        int stride_pad;
        for (stride_pad = 0; stride_pad <= 5; stride_pad += 5) {
            int stride = stride_pad ? 7 * ch + stride_pad : 0, rs = 7 * ch + stride_pad;
            lcg_seed(ch * 10 + stride_pad);
            for (k = 0; k < (int)sizeof data; k++) data[k] = (unsigned char)lcg_below(256);
            data[0] = 0;
            data[1] = 255;
            CHECK(tt_image_from_bytes(&im, data, 7, 5, ch, stride, &al) == TT_OK, "from_bytes ch %d", ch);
            memset(back, 0x11, sizeof back);
            tt_image_to_rgba8(&im, back);
            bad = 0;
            for (y = 0; y < 5; y++)
                for (x = 0; x < 7; x++) {
                    const unsigned char *p = data + y * rs + x * ch, *q = back + (y * 7 + x) * 4;
                    const float *f = px(&im, x, y);
                    unsigned char e[4];
                    if (ch <= 2) { e[0] = e[1] = e[2] = p[0]; e[3] = ch == 2 ? p[1] : 255; }
                    else { e[0] = p[0]; e[1] = p[1]; e[2] = p[2]; e[3] = ch == 4 ? p[3] : 255; }
                    for (k = 0; k < 4; k++) {
                        if (q[k] != e[k]) bad++;
                        if (!near(f[k], e[k] / 255.0, 1e-7)) bad++;
                    }
                }
            CHECK(bad == 0, "round trip with %d channels, stride %d: %d values differ", ch, stride, bad);
            tt_image_free(&im);
        }
    }
    CHECK(tt_image_from_bytes(&im, data, 7, 5, 0, 0, &al) == TT_ERROR_INVALID_ARGUMENT, "0 channels rejected");
    CHECK(tt_image_from_bytes(&im, data, 7, 5, 5, 0, &al) == TT_ERROR_INVALID_ARGUMENT, "5 channels rejected");
    CHECK(tt_image_from_bytes(&im, data, 7, 5, 3, 20, &al) == TT_ERROR_INVALID_ARGUMENT,
          "stride smaller than width*channels rejected");
    CHECK(tt_image_from_bytes(&im, NULL, 7, 5, 3, 0, &al) == TT_ERROR_INVALID_ARGUMENT, "data NULL rejected");
    CHECK(tt_image_from_bytes(&im, data, 0, 5, 3, 0, &al) == TT_ERROR_INVALID_ARGUMENT, "width 0 rejected");
    /* to_rgba8 rounds and clamps */
    CHECK(tt_image_create(&im, 2, 1, &al) == TT_OK, "create 2x1");
    im.pixels[0] = -0.5f; im.pixels[1] = 1.5f; im.pixels[2] = 0.5f; im.pixels[3] = (float)NAN;
    im.pixels[4] = 0.2f / 255.0f; im.pixels[5] = 0.6f / 255.0f; im.pixels[6] = 254.6f / 255.0f; im.pixels[7] = 1.0f;
    tt_image_to_rgba8(&im, back);
    CHECK(back[0] == 0 && back[1] == 255 && back[2] == 128 && back[3] == 0 && back[4] == 0 && back[5] == 1 &&
              back[6] == 255 && back[7] == 255,
          "to_rgba8 clamp/round: got %d %d %d %d %d %d %d %d", back[0], back[1], back[2], back[3], back[4], back[5],
          back[6], back[7]);
    tt_image_free(&im);

    /* bilinear */
    CHECK(tt_image_create(&im, 5, 4, &al) == TT_OK, "create 5x4");
    fill_random(&im, 77);
    {
        int bad_centre = 0, bad_half = 0, bad_clamp = 0;
        float s[4];
        for (y = 0; y < 4; y++)
            for (x = 0; x < 5; x++) {
                tt_image_sample_bilinear(&im, x + 0.5f, y + 0.5f, s);
                if (memcmp(s, px(&im, x, y), sizeof s) != 0) bad_centre++;
                if (x + 1 < 5) {
                    tt_image_sample_bilinear(&im, x + 1.0f, y + 0.5f, s);
                    for (k = 0; k < 4; k++)
                        if (!near(s[k], 0.5 * (px(&im, x, y)[k] + px(&im, x + 1, y)[k]), 1e-6)) bad_half++;
                }
                if (y + 1 < 4) {
                    tt_image_sample_bilinear(&im, x + 0.5f, y + 1.0f, s);
                    for (k = 0; k < 4; k++)
                        if (!near(s[k], 0.5 * (px(&im, x, y)[k] + px(&im, x, y + 1)[k]), 1e-6)) bad_half++;
                }
                if (x + 1 < 5 && y + 1 < 4) {
                    tt_image_sample_bilinear(&im, x + 1.0f, y + 1.0f, s);
                    for (k = 0; k < 4; k++)
                        if (!near(s[k], 0.25 * (px(&im, x, y)[k] + px(&im, x + 1, y)[k] + px(&im, x, y + 1)[k] +
                                                px(&im, x + 1, y + 1)[k]), 1e-6))
                            bad_half++;
                }
            }
        CHECK(bad_centre == 0, "bilinear at texel centres: %d texels differ", bad_centre);
        CHECK(bad_half == 0, "bilinear halfway: %d values differ from the average", bad_half);
        tt_image_sample_bilinear(&im, -10.0f, -3.0f, s);
        bad_clamp += memcmp(s, px(&im, 0, 0), sizeof s) != 0;
        tt_image_sample_bilinear(&im, 100.0f, 50.0f, s);
        bad_clamp += memcmp(s, px(&im, 4, 3), sizeof s) != 0;
        tt_image_sample_bilinear(&im, 0.1f, 2.5f, s);   /* left of the first centre: clamps in x */
        bad_clamp += memcmp(s, px(&im, 0, 2), sizeof s) != 0;
        tt_image_sample_bilinear(&im, 3.5f, 3.9f, s);   /* below the last centre */
        bad_clamp += memcmp(s, px(&im, 3, 3), sizeof s) != 0;
        CHECK(bad_clamp == 0, "bilinear clamps outside the image: %d cases wrong", bad_clamp);
        /* far outside: still the nearest edge texel */
        tt_image_sample_bilinear(&im, -1e30f, 1e30f, s);
        CHECK(memcmp(s, px(&im, 0, 3), sizeof s) == 0,
              "bilinear at (-1e30, 1e30) should clamp to the bottom-left texel (0,3): got %g, texel (0,3) %g, (0,0) %g",
              s[0], px(&im, 0, 3)[0], px(&im, 0, 0)[0]);
        tt_image_sample_bilinear(&im, 3e9f, 2.5f, s);
        CHECK(memcmp(s, px(&im, 4, 2), sizeof s) == 0,
              "bilinear at (3e9, 2.5) should clamp to the right texel (4,2): got %g, texel (4,2) %g, (0,2) %g", s[0],
              px(&im, 4, 2)[0], px(&im, 0, 2)[0]);
        tt_image_sample_bilinear(&im, (float)NAN, 1.0f, s);   /* must not crash */
        CHECK(s[0] == s[0], "bilinear at NaN should return a number");
    }
    tt_image_free(&im);
    CHECK(cnt.live == 0, "image basics: %ld allocations leaked", cnt.live);
}

/* Naive one-step counter-clockwise turn: (x, y) of a W x H image goes to
   (y, W-1-x) of an H x W image. */
static void naive_rotate(int turns, int w, int h, int x, int y, int *ox, int *oy)
{
    int t = ((turns % 4) + 4) % 4, i;
    for (i = 0; i < t; i++) {
        int nx = y, ny = w - 1 - x, tmp = w;
        x = nx;
        y = ny;
        w = h;
        h = tmp;
    }
    *ox = x;
    *oy = y;
}

static void test_rotate(void)
{
    tt_image src, dst;
    counter cnt;
    tt_allocator al = make_allocator(&cnt, -1);
    int turns, x, y, W = 7, H = 4;
    CHECK(tt_image_create(&src, W, H, &al) == TT_OK, "create");
    fill_random(&src, 3);
    for (turns = -5; turns <= 7; turns++) {
        int bad_coords = 0, bad_pixels = 0, odd = (((turns % 4) + 4) % 4) & 1;
        tt_result r;
        for (y = -2; y < H + 2; y++)
            for (x = -2; x < W + 2; x++) {
                int ax, ay, bx, by;
                tt_rotate_coords(turns, W, H, x, y, &ax, &ay);
                naive_rotate(turns, W, H, x, y, &bx, &by);
                if (ax != bx || ay != by) bad_coords++;
            }
        CHECK(bad_coords == 0, "tt_rotate_coords(%d) differs from the naive rotation at %d points", turns, bad_coords);
        r = tt_image_rotate90(&src, turns, &dst, &al);
        CHECK(r == TT_OK, "rotate90(%d) returned %d", turns, r);
        if (r != TT_OK) continue;
        CHECK(dst.width == (odd ? H : W) && dst.height == (odd ? W : H), "rotate90(%d): size %dx%d", turns, dst.width,
              dst.height);
        for (y = 0; y < H; y++)
            for (x = 0; x < W; x++) {
                int bx, by;
                naive_rotate(turns, W, H, x, y, &bx, &by);
                if (memcmp(px(&dst, bx, by), px(&src, x, y), 4 * sizeof(float)) != 0) bad_pixels++;
            }
        CHECK(bad_pixels == 0, "tt_image_rotate90(%d): %d pixels differ from the naive rotation", turns, bad_pixels);
        if (turns == 1) {
            /* one CCW turn: top-left goes to bottom-left; top-right to top-left */
            CHECK(memcmp(px(&dst, 0, dst.height - 1), px(&src, 0, 0), 16) == 0,
                  "one CCW turn should send the top-left pixel to the bottom-left");
            CHECK(memcmp(px(&dst, 0, 0), px(&src, W - 1, 0), 16) == 0,
                  "one CCW turn should send the top-right pixel to the top-left");
        }
        if (turns % 4 == 0)
            CHECK(memcmp(dst.pixels, src.pixels, sizeof(float) * 4 * W * H) == 0, "rotate90(%d) is the identity",
                  turns);
        tt_image_free(&dst);
    }
    /* composition: 1 turn then 3 turns = identity */
    {
        tt_image a, b;
        if (tt_image_rotate90(&src, 1, &a, &al) == TT_OK) {
            if (tt_image_rotate90(&a, 3, &b, &al) == TT_OK) {
                CHECK(b.width == W && memcmp(b.pixels, src.pixels, sizeof(float) * 4 * W * H) == 0,
                      "1 + 3 quarter turns should be the identity");
                tt_image_free(&b);
            }
            tt_image_free(&a);
        }
    }
    CHECK(tt_image_rotate90(&src, 1, &src, &al) == TT_ERROR_INVALID_ARGUMENT, "rotating in place is rejected");
    CHECK(tt_image_rotate90(NULL, 1, &dst, &al) == TT_ERROR_INVALID_ARGUMENT, "src NULL rejected");
    tt_image_free(&src);
    CHECK(cnt.live == 0, "rotate: %ld allocations leaked", cnt.live);
}

static void test_over_downsample(void)
{
    tt_image a, b, c, d;
    counter cnt;
    tt_allocator al = make_allocator(&cnt, -1);
    int x, y, k, bad;
    float dst[4] = {0.3f, 0.6f, 0.9f, 0.8f}, keep[4], src[4];

    memcpy(keep, dst, sizeof dst);
    src[0] = src[1] = src[2] = src[3] = 0.0f;
    tt_rgba_over(dst, src);
    CHECK(memcmp(dst, keep, sizeof dst) == 0, "over with alpha 0 leaves dst exactly");
    src[0] = 0.123f; src[1] = 0.456f; src[2] = 0.789f; src[3] = 1.0f;
    tt_rgba_over(dst, src);
    CHECK(memcmp(dst, src, sizeof dst) == 0, "over with alpha 1 gives src exactly: got %g %g %g %g", dst[0], dst[1],
          dst[2], dst[3]);
    memcpy(dst, keep, sizeof dst);
    src[0] = 0.1f; src[1] = 0.2f; src[2] = 0.3f; src[3] = 0.5f;
    tt_rgba_over(dst, src);
    bad = 0;
    for (k = 0; k < 4; k++) bad += !near(dst[k], src[k] + 0.5 * keep[k], 1e-6);
    CHECK(bad == 0, "over with alpha .5: expected src + .5 dst, %d channels differ", bad);

    CHECK(tt_image_create(&a, 6, 4, &al) == TT_OK && tt_image_create(&b, 6, 4, &al) == TT_OK, "create");
    fill_random(&a, 11);
    fill_random(&b, 12);
    for (y = 0; y < 4; y++)
        for (x = 0; x < 6; x++) {
            float *p = px(&b, x, y);
            int kind = (x + y) % 3;
            p[3] = kind == 0 ? 0.0f : kind == 1 ? 1.0f : 0.5f;
            if (kind == 0) p[0] = p[1] = p[2] = 0.0f;
            for (k = 0; k < 3; k++) p[k] *= p[3];   /* premultiplied */
        }
    CHECK(tt_image_create(&c, 6, 4, &al) == TT_OK, "create");
    memcpy(c.pixels, a.pixels, sizeof(float) * 4 * 24);
    CHECK(tt_image_over(&a, &b) == TT_OK, "tt_image_over");
    bad = 0;
    for (y = 0; y < 4; y++)
        for (x = 0; x < 6; x++) {
            const float *s = px(&b, x, y), *o = px(&c, x, y), *r = px(&a, x, y);
            for (k = 0; k < 4; k++) {
                if (s[3] == 0.0f) bad += r[k] != o[k];
                else if (s[3] == 1.0f) bad += r[k] != s[k];
                else bad += !near(r[k], s[k] + (1.0 - s[3]) * o[k], 1e-6);
            }
        }
    CHECK(bad == 0, "tt_image_over: %d values differ from the formula", bad);
    tt_image_free(&c);
    CHECK(tt_image_create(&c, 5, 4, &al) == TT_OK, "create");
    CHECK(tt_image_over(&a, &c) == TT_ERROR_INVALID_ARGUMENT, "over with different sizes rejected");
    CHECK(tt_image_over(NULL, &c) == TT_ERROR_INVALID_ARGUMENT, "over NULL rejected");
    tt_image_free(&c);

    /* downsample against a naive box */
    CHECK(tt_image_downsample2(&a, &d, &al) == TT_OK, "downsample 6x4");
    CHECK(d.width == 3 && d.height == 2, "downsample size %dx%d", d.width, d.height);
    bad = 0;
    for (y = 0; y < 2; y++)
        for (x = 0; x < 3; x++)
            for (k = 0; k < 4; k++) {
                double e = (px(&a, 2 * x, 2 * y)[k] + px(&a, 2 * x + 1, 2 * y)[k] + px(&a, 2 * x, 2 * y + 1)[k] +
                            px(&a, 2 * x + 1, 2 * y + 1)[k]) / 4.0;
                bad += !near(px(&d, x, y)[k], e, 1e-6);
            }
    CHECK(bad == 0, "downsample2: %d values differ from the naive box", bad);
    tt_image_free(&d);
    CHECK(tt_image_create(&c, 5, 4, &al) == TT_OK, "create");
    CHECK(tt_image_downsample2(&c, &d, &al) == TT_ERROR_INVALID_ARGUMENT && d.pixels == NULL, "odd width rejected");
    tt_image_free(&c);
    CHECK(tt_image_create(&c, 4, 3, &al) == TT_OK, "create");
    CHECK(tt_image_downsample2(&c, &d, &al) == TT_ERROR_INVALID_ARGUMENT && d.pixels == NULL, "odd height rejected");
    tt_image_free(&c);
    CHECK(tt_image_create(&c, 2, 2, &al) == TT_OK, "create");
    CHECK(tt_image_downsample2(&c, &d, &al) == TT_OK && d.width == 1 && d.height == 1, "2x2 -> 1x1");
    tt_image_free(&d);
    CHECK(tt_image_downsample2(&c, &c, &al) == TT_ERROR_INVALID_ARGUMENT, "in place rejected");
    tt_image_free(&c);
    tt_image_free(&a);
    tt_image_free(&b);
    CHECK(cnt.live == 0, "over/downsample: %ld allocations leaked", cnt.live);
}

/* Brute force over all paths; ties: smallest last row, then smallest row
   one column earlier, and so on (what "ties go to the smaller row" gives
   when each step prefers the smaller row). */
static int brute_cut(const float *cost, int w, int h, const int *lo, const int *hi, int *best_path, double *best_cost)
{
    int path[8], x, found = 0;
    for (x = 0; x < w; x++) path[x] = 0;
    for (;;) {
        int ok = 1;
        double sum = 0.0;
        for (x = 0; x < w && ok; x++) {
            if (path[x] < lo[x] || path[x] > hi[x]) ok = 0;
            if (x > 0 && abs(path[x] - path[x - 1]) > 1) ok = 0;
        }
        if (ok) {
            for (x = 0; x < w; x++) sum += cost[path[x] * w + x];
            if (!found || sum < *best_cost) {
                found = 1;
                *best_cost = sum;
                memcpy(best_path, path, sizeof(int) * (size_t)w);
            } else if (sum == *best_cost) {
                /* compare from the last column */
                for (x = w - 1; x >= 0; x--) {
                    if (path[x] != best_path[x]) {
                        if (path[x] < best_path[x]) memcpy(best_path, path, sizeof(int) * (size_t)w);
                        break;
                    }
                }
            }
        }
        for (x = 0; x < w; x++) {
            if (++path[x] < h) break;
            path[x] = 0;
        }
        if (x == w) break;
    }
    return found;
}

static void test_min_error_cut(void)
{
    int trial, bad_cost = 0, bad_path = 0, bad_valid = 0, bad_result = 0, nvalid = 0, ninvalid = 0;
    counter cnt;
    tt_allocator al = make_allocator(&cnt, -1);
    lcg_seed(2024);
    for (trial = 0; trial < 3000; trial++) {
        int w = 1 + lcg_below(6), h = 1 + lcg_below(5), x, lo[8], hi[8], path[8], best[8], found;
        float cost[64];
        double best_cost = 0.0, got = 0.0;
        tt_result r;
        int integer = trial % 2;   /* integer costs: many ties */
        for (x = 0; x < w * h; x++) cost[x] = integer ? (float)lcg_below(3) : (float)lcg_unit();
        for (x = 0; x < w; x++) {
            int a = lcg_below(h), b = lcg_below(h);
            if (trial % 3 == 0) { a = 0; b = h - 1; }
            lo[x] = a < b ? a : b;
            hi[x] = a < b ? b : a;
        }
        found = brute_cut(cost, w, h, lo, hi, best, &best_cost);
        for (x = 0; x < 8; x++) path[x] = -99;
        r = tt_min_error_cut(cost, w, h, lo, hi, path, &al);
        if (!found) {
            ninvalid++;
            if (r != TT_ERROR_INVALID_ARGUMENT) bad_result++;
            continue;
        }
        nvalid++;
        if (r != TT_OK) { bad_result++; continue; }
        for (x = 0; x < w; x++) {
            if (path[x] < lo[x] || path[x] > hi[x] || (x > 0 && abs(path[x] - path[x - 1]) > 1)) { bad_valid++; break; }
            got += cost[path[x] * w + x];
        }
        if (got != best_cost) bad_cost++;
        else if (memcmp(path, best, sizeof(int) * (size_t)w) != 0) bad_path++;
    }
    CHECK(bad_result == 0, "min_error_cut: %d results differ (expected OK when a path exists, INVALID_ARGUMENT otherwise)",
          bad_result);
    CHECK(bad_valid == 0, "min_error_cut: %d paths leave their range or jump more than one row", bad_valid);
    CHECK(bad_cost == 0, "min_error_cut: %d paths are not of minimal cost", bad_cost);
    CHECK(bad_path == 0, "min_error_cut: %d tied paths differ from the smaller-row choice", bad_path);
    CHECK(nvalid > 1000 && ninvalid > 100, "min_error_cut sampling: %d valid, %d invalid cases", nvalid, ninvalid);
    {
        float cost[4] = {1, 2, 3, 4};
        int lo[2] = {0, 0}, hi[2] = {1, 1}, path[2], badlo[2] = {1, 0}, badhi[2] = {0, 5}, hi01[2] = {0, 1};
        CHECK(tt_min_error_cut(cost, 2, 2, badlo, hi01, path, &al) == TT_ERROR_INVALID_ARGUMENT, "lo > hi rejected");
        CHECK(tt_min_error_cut(cost, 2, 2, lo, badhi, path, &al) == TT_ERROR_INVALID_ARGUMENT, "hi >= height rejected");
        CHECK(tt_min_error_cut(NULL, 2, 2, lo, hi, path, &al) == TT_ERROR_INVALID_ARGUMENT, "cost NULL rejected");
        CHECK(tt_min_error_cut(cost, 0, 2, lo, hi, path, &al) == TT_ERROR_INVALID_ARGUMENT, "width 0 rejected");
        CHECK(tt_min_error_cut(cost, 2, 2, lo, hi, path, NULL) == TT_OK && path[0] == 0 && path[1] == 0,
              "default allocator: path %d %d", path[0], path[1]);
        {
            counter fc;
            tt_allocator fail;
            int k;
            for (k = 0; k < 2; k++) {
                fail = make_allocator(&fc, k);
                CHECK(tt_min_error_cut(cost, 2, 2, lo, hi, path, &fail) == TT_ERROR_OUT_OF_MEMORY && fc.live == 0,
                      "min_error_cut with allocation %d failing: clean TT_ERROR_OUT_OF_MEMORY", k);
            }
        }
    }
    CHECK(cnt.live == 0, "min_error_cut: %ld allocations leaked", cnt.live);
}

/* ------------------------------------------------------------------------ */
/* 5. Raster                                                                */
/* ------------------------------------------------------------------------ */

#define RW 48
#define RH 36

typedef struct raster_rec {
    int hits[RH][RW];
    float bary[RH][RW][3];
    int out_of_grid;
    int bad_sum;
} raster_rec;

static void raster_cb(int x, int y, const float b[3], void *user)
{
    raster_rec *r = (raster_rec *)user;
    if (x < 0 || y < 0 || x >= RW || y >= RH) { r->out_of_grid++; return; }
    r->hits[y][x]++;
    memcpy(r->bary[y][x], b, sizeof(float) * 3);
    if (!near((double)b[0] + b[1] + b[2], 1.0, 1e-5)) r->bad_sum++;
}

/* Naive: signed distances of (px,py) to the 3 edges, positive inside for
   either winding; returns the smallest; +inside / -outside. */
static double naive_inside(const float *t, double px_, double py_)
{
    double area = ((double)t[2] - t[0]) * ((double)t[5] - t[1]) - ((double)t[4] - t[0]) * ((double)t[3] - t[1]);
    double sgn = area > 0 ? 1.0 : -1.0, best = 1e300;
    int i;
    for (i = 0; i < 3; i++) {
        double ax = t[2 * i], ay = t[2 * i + 1], bx = t[2 * ((i + 1) % 3)], by = t[2 * ((i + 1) % 3) + 1];
        double len = sqrt((bx - ax) * (bx - ax) + (by - ay) * (by - ay));
        double e = ((bx - ax) * (py_ - ay) - (by - ay) * (px_ - ax)) * sgn / (len > 0 ? len : 1);
        if (e < best) best = e;
    }
    return best;
}

static void raster_compare(const float *t, double margin, int *bad_cover, int *bad_bary, int *bad_other)
{
    static raster_rec rec;
    int x, y;
    memset(&rec, 0, sizeof rec);
    tt_raster_triangle(t, RW, RH, raster_cb, &rec);
    *bad_other += rec.out_of_grid + rec.bad_sum;
    for (y = 0; y < RH; y++)
        for (x = 0; x < RW; x++) {
            double d = naive_inside(t, x + 0.5, y + 0.5);
            if (rec.hits[y][x] > 1) (*bad_other)++;
            if (fabs(d) > margin && (d > 0) != (rec.hits[y][x] == 1)) (*bad_cover)++;
            if (rec.hits[y][x]) {
                const float *b = rec.bary[y][x];
                double qx = b[0] * t[0] + b[1] * t[2] + b[2] * t[4], qy = b[0] * t[1] + b[1] * t[3] + b[2] * t[5];
                if (!near(qx, x + 0.5, 2e-3) || !near(qy, y + 0.5, 2e-3)) (*bad_bary)++;
                if (b[0] < -1e-3 || b[1] < -1e-3 || b[2] < -1e-3) (*bad_bary)++;
            }
        }
}

static void test_raster_random(void)
{
    int trial, bad_cover = 0, bad_bary = 0, bad_other = 0, bad_wind = 0;
    static raster_rec r1, r2;
    lcg_seed(555);
    for (trial = 0; trial < 600; trial++) {
        float t[6], u[6];
        int i, x, y;
        for (i = 0; i < 6; i++) {
            double lo = -6.0, hi = (i % 2 ? RH : RW) + 6.0, v = lo + (hi - lo) * lcg_unit();
            /* half the triangles on the 1/256 grid, where the rasteriser's
               snapping changes nothing (margin 1e-3 px); half arbitrary, where
               snapping moves an edge by up to ~0.003 px (margin 6e-3 px) */
            t[i] = trial % 2 ? (float)(floor(v * 256.0) / 256.0) : (float)v;
        }
        raster_compare(t, trial % 2 ? 1e-3 : 6e-3, &bad_cover, &bad_bary, &bad_other);
        /* the other winding: same pixels, weights follow their vertices */
        u[0] = t[0]; u[1] = t[1]; u[2] = t[4]; u[3] = t[5]; u[4] = t[2]; u[5] = t[3];
        memset(&r1, 0, sizeof r1);
        memset(&r2, 0, sizeof r2);
        tt_raster_triangle(t, RW, RH, raster_cb, &r1);
        tt_raster_triangle(u, RW, RH, raster_cb, &r2);
        for (y = 0; y < RH; y++)
            for (x = 0; x < RW; x++) {
                if (r1.hits[y][x] != r2.hits[y][x]) bad_wind++;
                else if (r1.hits[y][x] &&
                         (!near(r1.bary[y][x][0], r2.bary[y][x][0], 1e-5) ||
                          !near(r1.bary[y][x][1], r2.bary[y][x][2], 1e-5) ||
                          !near(r1.bary[y][x][2], r2.bary[y][x][1], 1e-5)))
                    bad_wind++;
            }
    }
    CHECK(bad_cover == 0, "raster: %d pixel centres differ from the naive point-in-triangle test", bad_cover);
    CHECK(bad_bary == 0, "raster: %d barycentrics do not reproduce the pixel centre", bad_bary);
    CHECK(bad_other == 0, "raster: %d pixels outside the grid, hit twice, or weights not summing to 1", bad_other);
    CHECK(bad_wind == 0, "raster: %d pixels differ between the two windings", bad_wind);
    {
        /* degenerate and NULL inputs draw nothing and do not crash */
        float flat[6] = {1, 1, 5, 5, 9, 9}, nan_t[6] = {1, 1, 5, 1, 1, 5};
        static raster_rec rr;
        memset(&rr, 0, sizeof rr);
        tt_raster_triangle(flat, RW, RH, raster_cb, &rr);
        nan_t[3] = (float)NAN;
        tt_raster_triangle(nan_t, RW, RH, raster_cb, &rr);
        tt_raster_triangle(NULL, RW, RH, raster_cb, &rr);
        tt_raster_triangle(flat, 0, RH, raster_cb, &rr);
        {
            int x, y, n = 0;
            for (y = 0; y < RH; y++) for (x = 0; x < RW; x++) n += rr.hits[y][x];
            CHECK(n == 0, "degenerate / NaN triangles should draw nothing, drew %d", n);
        }
    }
}

/* Rasterise a set of triangles; every pixel whose centre is inside the union
   (by `inside`) must be hit exactly once, no pixel twice. */
static void raster_cover(const float *tris, int ntris, int (*inside)(double, double, const void *), const void *ctx,
                         const char *what)
{
    static raster_rec rec;
    int i, x, y, twice = 0, gaps = 0, extra = 0;
    memset(&rec, 0, sizeof rec);
    for (i = 0; i < ntris; i++) tt_raster_triangle(tris + 6 * i, RW, RH, raster_cb, &rec);
    for (y = 0; y < RH; y++)
        for (x = 0; x < RW; x++) {
            int in = inside(x + 0.5, y + 0.5, ctx);
            if (rec.hits[y][x] > 1) twice++;
            if (in == 1 && rec.hits[y][x] == 0) gaps++;
            if (in == 0 && rec.hits[y][x] != 0) extra++;
        }
    CHECK(twice == 0 && gaps == 0 && extra == 0 && rec.out_of_grid == 0,
          "%s: %d pixels hit twice, %d gaps, %d outside hits, %d off-grid", what, twice, gaps, extra, rec.out_of_grid);
}

static int inside_everything(double x, double y, const void *ctx) { (void)x; (void)y; (void)ctx; return 1; }

typedef struct poly_ctx {
    const float *pts;
    int n;
} poly_ctx;

/* 1 inside the convex polygon, 0 outside, 2 within 1e-3 of its boundary. */
static int inside_convex(double x, double y, const void *ctx)
{
    const poly_ctx *p = (const poly_ctx *)ctx;
    int i;
    double best = 1e300;
    for (i = 0; i < p->n; i++) {
        double ax = p->pts[2 * i], ay = p->pts[2 * i + 1];
        double bx = p->pts[2 * ((i + 1) % p->n)], by = p->pts[2 * ((i + 1) % p->n) + 1];
        double len = sqrt((bx - ax) * (bx - ax) + (by - ay) * (by - ay));
        double e = ((bx - ax) * (y - ay) - (by - ay) * (x - ax)) / len;
        if (e < best) best = e;
    }
    if (fabs(best) < 1e-3) return 2;
    return best > 0 ? 1 : 0;
}

static void test_raster_cover(void)
{
    static float tris[6 * 4096];
    int n, i, j, k, variant;
    const double pi = 3.14159265358979323846;
    /* fans around a point: centre at a pixel centre, at a pixel corner, and
       at an arbitrary place; rim points at pixel centres / corners / anywhere */
    for (variant = 0; variant < 6; variant++) {
        float pts[2 * 64];
        int npts = variant < 3 ? 12 : 7;
        double cx = variant % 3 == 0 ? 20.5 : variant % 3 == 1 ? 20.0 : 20.3137, cy = variant % 3 == 0 ? 17.5
                                                                                   : variant % 3 == 1 ? 18.0 : 16.871;
        poly_ctx pc;
        char what[96];
        for (i = 0; i < npts; i++) {
            double a = 2 * pi * i / npts + 0.01 * variant, rx = cx + 14 * cos(a), ry = cy + 14 * sin(a);
            if (variant % 3 == 0) { rx = floor(rx) + 0.5; ry = floor(ry) + 0.5; }
            if (variant % 3 == 1) { rx = floor(rx + 0.5); ry = floor(ry + 0.5); }
            pts[2 * i] = (float)rx;
            pts[2 * i + 1] = (float)ry;
        }
        /* pts go counter-clockwise in a y-up frame = clockwise on screen; the
           convex test needs consistent winding: reverse when negative. */
        {
            double area = 0;
            for (i = 0; i < npts; i++)
                area += pts[2 * i] * pts[2 * ((i + 1) % npts) + 1] - pts[2 * ((i + 1) % npts)] * pts[2 * i + 1];
            if (area < 0)
                for (i = 0; i < npts / 2; i++)
                    for (k = 0; k < 2; k++) {
                        float t = pts[2 * i + k];
                        pts[2 * i + k] = pts[2 * (npts - 1 - i) + k];
                        pts[2 * (npts - 1 - i) + k] = t;
                    }
        }
        n = 0;
        for (i = 0; i < npts; i++) {
            float *t = tris + 6 * n++;
            t[0] = (float)cx; t[1] = (float)cy;
            /* alternate windings inside the fan */
            if (i % 2) { t[2] = pts[2 * i]; t[3] = pts[2 * i + 1]; t[4] = pts[2 * ((i + 1) % npts)]; t[5] = pts[2 * ((i + 1) % npts) + 1]; }
            else { t[4] = pts[2 * i]; t[5] = pts[2 * i + 1]; t[2] = pts[2 * ((i + 1) % npts)]; t[3] = pts[2 * ((i + 1) % npts) + 1]; }
        }
        pc.pts = pts;
        pc.n = npts;
        sprintf(what, "fan variant %d (centre %.4g,%.4g)", variant, cx, cy);
        raster_cover(tris, n, inside_convex, &pc, what);
    }
    /* grids of quads split in two, covering [0,RW] x [0,RH] exactly: lines at
       pixel corners (spacing 4), at pixel centres (spacing 3, offset .5),
       at half pixels (spacing 2.5), and jittered interior vertices */
    for (variant = 0; variant < 8; variant++) {
        float gx[64], gy[64];
        int nx, ny, diag = variant & 1;
        int kind = variant / 2;
        char what[96];
        lcg_seed(100 + variant);
        if (kind == 0) { nx = RW / 4; ny = RH / 4; for (i = 0; i <= nx; i++) gx[i] = 4.0f * i; for (j = 0; j <= ny; j++) gy[j] = 4.0f * j; }
        else if (kind == 1) {
            nx = 0; gx[nx++] = 0; for (i = 0; 0.5 + 3 * i < RW; i++) gx[nx++] = 0.5f + 3.0f * i; gx[nx] = RW;
            ny = 0; gy[ny++] = 0; for (j = 0; 0.5 + 3 * j < RH; j++) gy[ny++] = 0.5f + 3.0f * j; gy[ny] = RH;
        } else if (kind == 2) {
            nx = 0; for (i = 0; 2.5 * i < RW; i++) gx[nx++] = 2.5f * i; gx[nx] = RW;
            ny = 0; for (j = 0; 2.5 * j < RH; j++) gy[ny++] = 2.5f * j; gy[ny] = RH;
        } else { nx = 9; ny = 7; for (i = 0; i <= nx; i++) gx[i] = (float)RW * i / nx; for (j = 0; j <= ny; j++) gy[j] = (float)RH * j / ny; }
        n = 0;
        {
            /* vertex positions, jittered inside for kind 3 */
            static float vx[64][64], vy[64][64];
            for (j = 0; j <= ny; j++)
                for (i = 0; i <= nx; i++) {
                    vx[j][i] = gx[i];
                    vy[j][i] = gy[j];
                    if (kind == 3 && i > 0 && i < nx && j > 0 && j < ny) {
                        vx[j][i] += (float)((lcg_unit() - 0.5) * 2.0);
                        vy[j][i] += (float)((lcg_unit() - 0.5) * 2.0);
                    }
                }
            for (j = 0; j < ny; j++)
                for (i = 0; i < nx; i++) {
                    float a[2], b[2], c[2], d[2], *t;
                    a[0] = vx[j][i]; a[1] = vy[j][i];
                    b[0] = vx[j][i + 1]; b[1] = vy[j][i + 1];
                    c[0] = vx[j + 1][i + 1]; c[1] = vy[j + 1][i + 1];
                    d[0] = vx[j + 1][i]; d[1] = vy[j + 1][i];
                    t = tris + 6 * n++;
                    if (!diag) { t[0] = a[0]; t[1] = a[1]; t[2] = b[0]; t[3] = b[1]; t[4] = c[0]; t[5] = c[1]; }
                    else { t[0] = a[0]; t[1] = a[1]; t[2] = b[0]; t[3] = b[1]; t[4] = d[0]; t[5] = d[1]; }
                    t = tris + 6 * n++;
                    if (!diag) { t[0] = a[0]; t[1] = a[1]; t[2] = d[0]; t[3] = d[1]; t[4] = c[0]; t[5] = c[1]; }
                    else { t[0] = b[0]; t[1] = b[1]; t[2] = d[0]; t[3] = d[1]; t[4] = c[0]; t[5] = c[1]; }
                }
        }
        sprintf(what, "grid kind %d diagonal %d (%dx%d quads)", kind, diag, nx, ny);
        raster_cover(tris, n, inside_everything, NULL, what);
    }
}

/* ------------------------------------------------------------------------ */
/* 6. Tiled textures: layout, boundaries, UVs                               */
/* ------------------------------------------------------------------------ */

static tt_tile_layout make_layout(int colors, int size, int gutter)
{
    tt_tile_layout l;
    l.colors = colors;
    l.tile_size = size;
    l.gutter = gutter;
    return l;
}

static void test_layout(void)
{
    tt_tile_layout in, out;
    tt_error err;
    tt_result r;
    in = make_layout(0, 0, 0);
    r = tt_tile_layout_resolve(&in, &out, &err);
    CHECK(r == TT_OK && out.colors == 1 && out.tile_size == TT_DEFAULT_TILE_SIZE && out.gutter == 0,
          "zeros resolve to defaults: got %d colors, %d size, %d gutter (result %d)", out.colors, out.tile_size,
          out.gutter, r);
    CHECK(tt_tile_layout_tiles_per_side(&out) == 4 && tt_tile_layout_tile_count(&out) == 16 &&
              tt_tile_layout_atlas_size(&out) == 4 * 128,
          "default layout: T %d, count %d, W %d", tt_tile_layout_tiles_per_side(&out), tt_tile_layout_tile_count(&out),
          tt_tile_layout_atlas_size(&out));
    /* Resolving is idempotent: a resolved layout passed back in stays as it is
       (a gutter of 0 means none, never "the default"). */
    {
        tt_tile_layout again;
        memset(&again, 0, sizeof again);
        in = make_layout(2, 32, TT_RECOMMENDED_GUTTER);
        r = tt_tile_layout_resolve(&in, &out, &err);
        CHECK(r == TT_OK && tt_tile_layout_resolve(&out, &again, &err) == TT_OK && again.colors == out.colors &&
                  again.tile_size == out.tile_size && again.gutter == out.gutter,
              "resolve(resolve(L)) == resolve(L): got %d/%d/%d vs %d/%d/%d", again.colors, again.tile_size,
              again.gutter, out.colors, out.tile_size, out.gutter);
        in = make_layout(1, 32, 0);
        r = tt_tile_layout_resolve(&in, &out, &err);
        CHECK(r == TT_OK && tt_tile_layout_resolve(&out, &again, &err) == TT_OK && again.gutter == 0,
              "no gutter stays no gutter: %d", again.gutter);
    }
    in = make_layout(2, 32, TT_NO_GUTTER);
    r = tt_tile_layout_resolve(&in, &out, &err);
    CHECK(r == TT_OK && out.gutter == 0 && tt_tile_layout_tiles_per_side(&out) == 16 &&
              tt_tile_layout_atlas_size(&out) == 512 && tt_tile_layout_tile_count(&out) == 256,
          "n=2, S=32, no gutter: gutter %d, T %d, W %d", out.gutter, tt_tile_layout_tiles_per_side(&out),
          tt_tile_layout_atlas_size(&out));
    in = make_layout(-1, 32, 4);
    CHECK(tt_tile_layout_resolve(&in, &out, &err) == TT_ERROR_INVALID_ARGUMENT && err.message[0],
          "colors -1 rejected with a message");
    in = make_layout(TT_MAX_COLORS + 1, 32, 4);
    CHECK(tt_tile_layout_resolve(&in, &out, &err) == TT_ERROR_INVALID_ARGUMENT, "colors TT_MAX_COLORS+1 rejected");
    in = make_layout(TT_MAX_COLORS, 4, TT_NO_GUTTER);
    CHECK(tt_tile_layout_resolve(&in, &out, &err) == TT_ERROR_TOO_LARGE, "TT_MAX_COLORS colors: atlas too large");
    in = make_layout(1, 3, 4);
    r = tt_tile_layout_resolve(&in, &out, &err);
    CHECK(r == TT_ERROR_INVALID_ARGUMENT, "tile size 3 (below the minimum 4) should be TT_ERROR_INVALID_ARGUMENT "
          "(%d), got %d (%s)", TT_ERROR_INVALID_ARGUMENT, r, err.message);
    in = make_layout(1, -5, 4);
    CHECK(tt_tile_layout_resolve(&in, &out, &err) == TT_ERROR_INVALID_ARGUMENT, "tile size -5 rejected");
    in = make_layout(1, 40000, 4);
    CHECK(tt_tile_layout_resolve(&in, &out, &err) == TT_ERROR_TOO_LARGE, "tile size 40000: TT_ERROR_TOO_LARGE");
    in = make_layout(2, 2048, 4);   /* 16 * 2056 = 32896 > 32768 */
    r = tt_tile_layout_resolve(&in, &out, &err);
    CHECK(r == TT_ERROR_TOO_LARGE, "n=2, S=2048: atlas 32896 > TT_MAX_IMAGE_SIZE: expected %d, got %d",
          TT_ERROR_TOO_LARGE, r);
    in = make_layout(2, 2040, 4);   /* 16 * 2048 = 32768: allowed */
    CHECK(tt_tile_layout_resolve(&in, &out, &err) == TT_OK, "n=2, S=2040, g=4: atlas exactly TT_MAX_IMAGE_SIZE");
    in = make_layout(1, 32, 33);
    CHECK(tt_tile_layout_resolve(&in, &out, &err) == TT_ERROR_INVALID_ARGUMENT, "gutter > tile size rejected");
    in = make_layout(1, 32, -2);
    CHECK(tt_tile_layout_resolve(&in, &out, &err) == TT_ERROR_INVALID_ARGUMENT, "gutter -2 rejected");
    CHECK(tt_tile_layout_resolve(NULL, &out, &err) == TT_ERROR_INVALID_ARGUMENT, "NULL layout rejected");
}

static void test_tile_uv_index(void)
{
    /* Hand-computed for n = 1, S = 32: no gutter (C = 32, W = 128) and gutter
       4 (C = 40, W = 160). {e0,e1,e2,e3, corner, u*W, v*W} */
    static const int table_g0[][7] = {
        {0, 0, 0, 0, 0, 0, 0},    {0, 0, 0, 0, 1, 32, 0},   {0, 0, 0, 0, 2, 32, 32},  {0, 0, 0, 0, 3, 0, 32},
        {1, 0, 1, 1, 0, 64, 96},  {1, 0, 1, 1, 1, 96, 96},  {1, 0, 1, 1, 2, 96, 128}, {1, 0, 1, 1, 3, 64, 128},
        {0, 1, 1, 0, 0, 32, 64},  {0, 1, 1, 0, 2, 64, 96},  {1, 1, 1, 1, 2, 128, 128}, {1, 1, 0, 1, 3, 96, 64}};
    static const int table_g4[][7] = {
        {0, 0, 0, 0, 0, 4, 4},    {0, 0, 0, 0, 1, 36, 4},   {0, 0, 0, 0, 2, 36, 36},  {0, 0, 0, 0, 3, 4, 36},
        {1, 0, 1, 1, 0, 84, 124}, {1, 0, 1, 1, 1, 116, 124}, {1, 0, 1, 1, 2, 116, 156}, {1, 0, 1, 1, 3, 84, 156},
        {0, 1, 1, 0, 0, 44, 84},  {0, 1, 1, 0, 2, 76, 116}, {1, 1, 1, 1, 2, 156, 156}, {1, 1, 0, 1, 3, 124, 76}};
    int g, i, n;
    for (g = 0; g < 2; g++) {
        tt_tile_layout in = make_layout(1, 32, g ? 4 : TT_NO_GUTTER), l;
        const int(*table)[7] = g ? table_g4 : table_g0;
        double W = g ? 160.0 : 128.0;
        int bad = 0;
        tt_tile_layout_resolve(&in, &l, NULL);
        for (i = 0; i < 12; i++) {
            uint8_t t[4];
            float uv[2];
            t[0] = (uint8_t)table[i][0]; t[1] = (uint8_t)table[i][1]; t[2] = (uint8_t)table[i][2]; t[3] = (uint8_t)table[i][3];
            tt_tile_corner_uv(&l, t, table[i][4], uv);
            if (uv[0] != (float)(table[i][5] / W) || uv[1] != (float)(table[i][6] / W)) {
                if (!bad)
                    DETAIL("corner uv (gutter %d) types %d%d%d%d corner %d: expected (%g,%g), got (%g,%g)", l.gutter,
                          t[0], t[1], t[2], t[3], table[i][4], table[i][5] / W, table[i][6] / W, uv[0] * W, uv[1] * W);
                bad++;
            }
        }
        CHECK(bad == 0, "tt_tile_corner_uv (gutter %d): %d entries differ from the hand table", l.gutter, bad);
        /* The same layout as the user writes it (TT_NO_GUTTER, not resolved):
           tt_assign_uvs resolves it, so tt_tile_corner_uv should agree. */
        bad = 0;
        for (i = 0; i < 12; i++) {
            uint8_t t[4];
            float uv[2];
            t[0] = (uint8_t)table[i][0]; t[1] = (uint8_t)table[i][1]; t[2] = (uint8_t)table[i][2]; t[3] = (uint8_t)table[i][3];
            tt_tile_corner_uv(&in, t, table[i][4], uv);
            if (uv[0] != (float)(table[i][5] / W) || uv[1] != (float)(table[i][6] / W)) {
                if (!bad)
                    DETAIL("corner uv, unresolved layout {1, 32, %d}: types %d%d%d%d corner %d: expected (%g,%g)/W, "
                          "got (%g,%g)/W", in.gutter, t[0], t[1], t[2], t[3], table[i][4], (double)table[i][5],
                          (double)table[i][6], uv[0] * W, uv[1] * W);
                bad++;
            }
        }
        CHECK(bad == 0, "tt_tile_corner_uv with the unresolved layout (gutter %d): %d entries differ", in.gutter, bad);
    }
    {
        /* tt_tile_index with colors 0 (= 1 everywhere else) */
        tt_tile_layout in = make_layout(0, 0, 0);
        uint8_t t[4] = {1, 0, 1, 1};
        CHECK(tt_tile_index(&in, t) == 3 * 4 + 2, "tt_tile_index with colors 0 (= 1): types 1011: expected 14, got %d",
              tt_tile_index(&in, t));
    }
    {
        static const tt_result codes[] = {TT_OK, TT_CANCELLED, TT_ERROR_INVALID_ARGUMENT, TT_ERROR_OUT_OF_MEMORY,
                                          TT_ERROR_TOO_LARGE, TT_ERROR_EMPTY_MESH, TT_ERROR_INDEX_OUT_OF_RANGE,
                                          TT_ERROR_FACE_TOO_SMALL, TT_ERROR_REPEATED_VERTEX, TT_ERROR_NON_FINITE,
                                          TT_ERROR_ZERO_AREA_FACE, TT_ERROR_NON_MANIFOLD_EDGE,
                                          TT_ERROR_INCONSISTENT_ORIENTATION, TT_ERROR_NON_MANIFOLD_VERTEX,
                                          TT_ERROR_NOT_QUAD_MESH, TT_ERROR_IMAGE_TOO_SMALL, TT_ERROR_NOT_CONVERGED,
                                          TT_ERROR_NOT_POSITIVE_DEFINITE};
        int a, b, bad = 0, n = (int)(sizeof codes / sizeof codes[0]);
        const char *unknown = tt_result_string((tt_result)-99);
        for (a = 0; a < n; a++) {
            const char *sa = tt_result_string(codes[a]);
            if (!sa || !sa[0] || strcmp(sa, unknown) == 0) bad++;
            for (b = 0; b < a; b++) if (strcmp(sa, tt_result_string(codes[b])) == 0) bad++;
        }
        CHECK(bad == 0 && unknown && unknown[0], "tt_result_string: %d codes without a distinct sentence", bad);
    }
    /* the formula, n = 1..3, all type combinations; tile index bijective */
    for (n = 1; n <= 3; n++) {
        int gi;
        for (gi = 0; gi < 2; gi++) {
            tt_tile_layout in = make_layout(n, 16, gi ? 3 : TT_NO_GUTTER), l;
            int base = 2 * n, T = base * base, S = 16, gg, C, bad_uv = 0, bad_idx = 0, e0, e1, e2, e3, k;
            double W;
            char *seen = (char *)calloc((size_t)T * T, 1);
            tt_tile_layout_resolve(&in, &l, NULL);
            gg = l.gutter;
            C = S + 2 * gg;
            W = (double)T * C;
            for (e0 = 0; e0 < base; e0++)
                for (e1 = 0; e1 < base; e1++)
                    for (e2 = 0; e2 < base; e2++)
                        for (e3 = 0; e3 < base; e3++) {
                            uint8_t t[4];
                            int col = base * e0 + e1, row = base * e2 + e3, idx;
                            t[0] = (uint8_t)e0; t[1] = (uint8_t)e1; t[2] = (uint8_t)e2; t[3] = (uint8_t)e3;
                            idx = tt_tile_index(&l, t);
                            if (idx != row * T + col || idx < 0 || idx >= T * T || seen[idx]) bad_idx++;
                            else seen[idx] = 1;
                            for (k = 0; k < 4; k++) {
                                float uv[2];
                                int j = ((k + 1) % 4) / 2;
                                double u = (col * C + gg + j * S) / W, v = (row * C + gg + (k / 2) * S) / W;
                                tt_tile_corner_uv(&l, t, k, uv);
                                if (!near(uv[0], u, 1e-7) || !near(uv[1], v, 1e-7)) bad_uv++;
                            }
                        }
            CHECK(bad_idx == 0, "tt_tile_index n=%d: %d wrong or repeated indices", n, bad_idx);
            CHECK(bad_uv == 0, "tt_tile_corner_uv n=%d gutter %d: %d corners differ from the formula", n, gg, bad_uv);
            free(seen);
        }
    }
}

static void check_boundaries(const tt_mesh *mesh, int n, const char *name)
{
    uint8_t *a = (uint8_t *)malloc((size_t)mesh->ncorners), *b = (uint8_t *)malloc((size_t)mesh->ncorners);
    tt_tile_layout l = make_layout(n, 32, 4);
    int c, bad_pair = 0, bad_range = 0, differ = 0, *used = (int *)calloc((size_t)2 * n, sizeof(int));
    tt_result r;
    memset(a, 0xee, (size_t)mesh->ncorners);
    r = tt_assign_boundaries(mesh, &l, 1234, a);
    CHECK(r == TT_OK, "%s n=%d: assign_boundaries returned %d", name, n, r);
    for (c = 0; c < mesh->ncorners; c++) {
        int t = mesh->twin[c];
        if (a[c] >= 2 * n) { bad_range++; continue; }
        used[a[c]]++;
        if (t >= 0 && (a[t] != (a[c] ^ 1))) bad_pair++;
    }
    CHECK(bad_range == 0, "%s n=%d: %d types outside 0..2n-1", name, n, bad_range);
    CHECK(bad_pair == 0, "%s n=%d: %d twin pairs whose types are not t and t^1", name, n, bad_pair);
    if (mesh->ncorners >= 200 * n) {
        int k, unused = 0;
        for (k = 0; k < 2 * n; k++) unused += used[k] == 0;
        CHECK(unused == 0, "%s n=%d: %d of %d types never used", name, n, unused, 2 * n);
    }
    tt_assign_boundaries(mesh, &l, 1234, b);
    CHECK(memcmp(a, b, (size_t)mesh->ncorners) == 0, "%s n=%d: same seed should give the same types", name, n);
    tt_assign_boundaries(mesh, &l, 1235, b);
    for (c = 0; c < mesh->ncorners; c++) differ += a[c] != b[c];
    CHECK(differ > 0, "%s n=%d: seeds 1234 and 1235 gave identical types", name, n);
    free(a);
    free(b);
    free(used);
}

static void test_boundaries_uvs(void)
{
    tmesh m;
    tt_mesh *torus = NULL, *grid = NULL, *tet = NULL, *mixed = NULL;
    tt_error err;
    int n;
    memset(&m, 0, sizeof m);
    make_torus(&m, 24, 16, 3, 1);
    CHECK(build(&m, 0, &torus, &err) == TT_OK, "torus build");
    tm_free(&m);
    make_grid(&m, 6, 5);
    CHECK(build(&m, 0, &grid, &err) == TT_OK, "grid build");
    tm_free(&m);
    make_tetra(&m, 0);
    CHECK(build(&m, 0, &tet, &err) == TT_OK, "tetra build");
    tm_free(&m);
    make_grid(&m, 3, 2);
    tm_tri(&m, 1, 0, tm_vert(&m, 0.5, -1, 0));   /* face 6 is a triangle */
    CHECK(build(&m, 0, &mixed, &err) == TT_OK, "grid+triangle build");
    tm_free(&m);
    if (!torus || !grid || !tet || !mixed) return;

    for (n = 1; n <= 4; n++) {
        check_boundaries(torus, n, "torus");
        check_boundaries(grid, n, "open grid");
        check_boundaries(tet, n, "tetrahedron");
    }
    {
        uint8_t types[64];
        tt_tile_layout l = make_layout(0, 0, 0);
        CHECK(tt_assign_boundaries(tet, &l, 1, types) == TT_OK, "colors 0 (= 1) accepted");
        CHECK(tt_assign_boundaries(tet, NULL, 1, types) == TT_OK, "layout NULL (= 1 color) accepted");
        l.colors = -1;
        CHECK(tt_assign_boundaries(tet, &l, 1, types) == TT_ERROR_INVALID_ARGUMENT, "colors -1 rejected");
        l.colors = TT_MAX_COLORS + 1;
        CHECK(tt_assign_boundaries(tet, &l, 1, types) == TT_ERROR_INVALID_ARGUMENT, "colors TT_MAX_COLORS+1 rejected");
        l.colors = TT_MAX_COLORS;
        CHECK(tt_assign_boundaries(tet, &l, 1, types) == TT_OK, "colors TT_MAX_COLORS accepted by assign_boundaries");
        CHECK(tt_assign_boundaries(NULL, &l, 1, types) == TT_ERROR_INVALID_ARGUMENT, "mesh NULL rejected");
        CHECK(tt_assign_boundaries(tet, &l, 1, NULL) == TT_ERROR_INVALID_ARGUMENT, "types NULL rejected");
    }

    /* assign_uvs: not quads */
    {
        uint8_t types[64];
        float uv[128];
        tt_tile_layout l = make_layout(1, 32, 4);
        tt_result r;
        tt_assign_boundaries(tet, &l, 1, types);
        r = tt_assign_uvs(tet, &l, types, uv, &err);
        CHECK(r == TT_ERROR_NOT_QUAD_MESH && err.face == 0 && msg_has_number(err.message, 0),
              "tetrahedron: expected TT_ERROR_NOT_QUAD_MESH naming face 0, got %d face %d \"%s\"", r, err.face,
              err.message);
        tt_assign_boundaries(mixed, &l, 1, types);
        r = tt_assign_uvs(mixed, &l, types, uv, &err);
        CHECK(r == TT_ERROR_NOT_QUAD_MESH && err.face == 6 && err.corner == 24 && msg_has_number(err.message, 6),
              "grid + triangle: expected TT_ERROR_NOT_QUAD_MESH naming face 6 (corner 24), got %d face %d corner %d \"%s\"",
              r, err.face, err.corner, err.message);
        {
            int counts[16];
            CHECK(tt_tile_histogram(mixed, &l, types, counts) == TT_ERROR_NOT_QUAD_MESH,
                  "tile histogram on a mesh with a triangle: TT_ERROR_NOT_QUAD_MESH");
        }
        CHECK(tt_assign_uvs(NULL, &l, types, uv, &err) == TT_ERROR_INVALID_ARGUMENT, "assign_uvs mesh NULL");
        CHECK(tt_assign_uvs(grid, NULL, types, uv, &err) == TT_ERROR_INVALID_ARGUMENT, "assign_uvs layout NULL");
        CHECK(tt_assign_uvs(grid, &l, NULL, uv, &err) == TT_ERROR_INVALID_ARGUMENT, "assign_uvs types NULL");
        CHECK(tt_assign_uvs(grid, &l, types, NULL, &err) == TT_ERROR_INVALID_ARGUMENT, "assign_uvs uv NULL");
    }
    /* assign_uvs output = tt_tile_corner_uv per corner, n = 1..3, gutter or not */
    for (n = 1; n <= 3; n++) {
        int gi;
        for (gi = 0; gi < 2; gi++) {
            tt_tile_layout l = make_layout(n, 16, gi ? 2 : TT_NO_GUTTER), res;
            uint8_t *types = (uint8_t *)malloc((size_t)torus->ncorners);
            float *uv = (float *)malloc(sizeof(float) * 2 * (size_t)torus->ncorners);
            int f, i, bad = 0;
            tt_result r;
            tt_tile_layout_resolve(&l, &res, NULL);
            tt_assign_boundaries(torus, &l, 77 + (uint64_t)n, types);
            r = tt_assign_uvs(torus, &l, types, uv, &err);
            CHECK(r == TT_OK, "assign_uvs n=%d: %d (%s)", n, r, err.message);
            for (f = 0; f < torus->nfaces && r == TT_OK; f++)
                for (i = 0; i < 4; i++) {
                    float e[2];
                    tt_tile_corner_uv(&res, types + 4 * f, i, e);
                    if (uv[8 * f + 2 * i] != e[0] || uv[8 * f + 2 * i + 1] != e[1]) bad++;
                }
            CHECK(bad == 0, "assign_uvs n=%d gutter %d: %d corners differ from tt_tile_corner_uv", n, res.gutter, bad);
            /* a type out of range is rejected and named */
            types[13] = (uint8_t)(2 * n);
            r = tt_assign_uvs(torus, &l, types, uv, &err);
            CHECK(r == TT_ERROR_INVALID_ARGUMENT && err.corner == 13 && err.face == 3,
                  "type %d at corner 13 (n=%d): expected TT_ERROR_INVALID_ARGUMENT at corner 13 face 3, got %d %d %d",
                  2 * n, n, r, err.corner, err.face);
            free(types);
            free(uv);
        }
    }
    tt_mesh_free(torus);
    tt_mesh_free(grid);
    tt_mesh_free(tet);
    tt_mesh_free(mixed);
}

/* ------------------------------------------------------------------------ */
/* 6b. Tile-set synthesis                                                   */
/* ------------------------------------------------------------------------ */

/* Random-noise RGB source, opaque. */
static void make_noise(tt_image *im, int w, int h, unsigned seed)
{
    int i;
    tt_image_create(im, w, h, NULL);
    lcg_seed(seed);
    for (i = 0; i < w * h; i++) {
        im->pixels[4 * i] = (float)lcg_unit();
        im->pixels[4 * i + 1] = (float)lcg_unit();
        im->pixels[4 * i + 2] = (float)lcg_unit();
        im->pixels[4 * i + 3] = 1.0f;
    }
}

/* Smooth waves plus a little noise: a texture with structure at every scale. */
/* Photograph-like: value noise at 6, 13 and 29 texel scales plus grain. A row
   of it looks different from its own mirror image, as rows of real textures
   do, so tiles that do not belong together show (the seam test shuffles). */
static void make_value_noise(tt_image *im, int w, int h, unsigned seed)
{
    static const int scales[3] = {6, 13, 29};
    static const double weights[3] = {0.12, 0.16, 0.2};
    float lattice[3][64][64];
    int x, y, k, s;
    tt_image_create(im, w, h, NULL);
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

typedef struct synth_view {
    const tt_tileset *set;
    const tt_image *src;
    int n, S, g, C, T;
} synth_view;

/* Atlas texel of tile t at tile coordinates (tx, ty) (may reach into the gutter). */
static const float *tile_texel(const synth_view *v, int t, int tx, int ty)
{
    int col = t % v->T, row = t / v->T;
    return px(&v->set->levels[0], col * v->C + v->g + tx, (v->T - 1 - row) * v->C + v->g + ty);
}

/* Side frame (x, d) of side `side` -> tile texel. */
static const float *side_texel(const synth_view *v, int t, int side, int x, int d)
{
    int tx, ty;
    tt_rotate_coords(side, v->S, v->S, x, v->S - 1 - d, &tx, &ty);
    return tile_texel(v, t, tx, ty);
}

/* The edge sample of type `type` at side frame (x, d), from the source. */
static const float *edge_sample(const synth_view *v, int type, int x, int d)
{
    const tt_rect *w = &v->set->edge_windows[type >> 1];
    if ((type & 1) == 0) return px(v->src, w->x + x, w->y + v->S - 1 - d);
    return px(v->src, w->x + v->S - 1 - x, w->y + v->S + d);
}

static int rgb_equal(const float *a, const float *b) { return a[0] == b[0] && a[1] == b[1] && a[2] == b[2]; }

static void tile_types(const synth_view *v, int t, int types[4])
{
    int base = 2 * v->n, col = t % v->T, row = t / v->T;
    types[0] = col / base;
    types[1] = col % base;
    types[2] = row / base;
    types[3] = row % base;
}

static void check_tileset(const tt_tileset *set, const tt_image *src, int feather, const char *name)
{
    synth_view v;
    int t, side, x, d, k, bad_edge = 0, bad_gutter = 0, bad_cont = 0, bad_alpha = 0, bad_bg = 0,
        bad_win = 0, ncont = 0, L;
    v.set = set;
    v.src = src;
    v.n = set->layout.colors;
    v.S = set->layout.tile_size;
    v.g = set->layout.gutter;
    v.C = v.S + 2 * v.g;
    v.T = 4 * v.n * v.n;
    CHECK(set->levels[0].width == v.T * v.C && set->levels[0].height == v.T * v.C, "%s: atlas %dx%d, expected %d",
          name, set->levels[0].width, set->levels[0].height, v.T * v.C);
    if (set->levels[0].width != v.T * v.C) return;
    for (k = 0; k < v.n; k++) {
        const tt_rect *w = &set->edge_windows[k];
        if (w->w != v.S || w->h != 2 * v.S || w->x < 0 || w->y < 0 || w->x + v.S > src->width ||
            w->y + 2 * v.S > src->height)
            bad_win++;
    }
    CHECK(bad_win == 0, "%s: %d edge windows not S x 2S inside the source", name, bad_win);
    if (bad_win) return;
    lcg_seed(31337);
    for (t = 0; t < v.T * v.T; t++) {
        int types[4];
        const tt_rect *bg = &set->background_windows[t];
        tile_types(&v, t, types);
        /* every atlas texel of the cell is opaque */
        for (d = -v.g; d < v.S + v.g; d++)
            for (x = -v.g; x < v.S + v.g; x++) bad_alpha += tile_texel(&v, t, x, d)[3] != 1.0f;
        for (side = 0; side < 4; side++) {
            int tb, sb, typesb[4];
            /* the edge row: all texels but the two corners are the sample */
            for (x = 1; x < v.S - 1; x++)
                if (!rgb_equal(side_texel(&v, t, side, x, 0), edge_sample(&v, types[side], x, 0))) bad_edge++;
            /* the gutter rows continue it across the edge */
            for (d = -v.g; d < 0; d++)
                for (x = 0; x < v.S; x++)
                    if (!rgb_equal(side_texel(&v, t, side, x, d), edge_sample(&v, types[side], x, d))) bad_gutter++;
            /* a tile with the complementary type on some side: A's gutter at
               d = -1-k is B's row k, with x' = S-1-x, wherever B's row is
               the sample alone (row 0 but its corners; deeper rows away from
               the corners by more than the feather) */
            do {
                tb = lcg_below(v.T * v.T);
                sb = lcg_below(4);
                tile_types(&v, tb, typesb);
            } while (typesb[sb] != (types[side] ^ 1));
            for (k = 0; k < (v.g > 0 ? v.g : 1); k++)
                for (x = 0; x < v.S; x++) {
                    int xb = v.S - 1 - x, wedge = xb < v.S - 1 - xb ? xb : v.S - 1 - xb;
                    const float *a, *b;
                    if (k == 0 ? (xb == 0 || xb == v.S - 1) : wedge < k + feather) continue;
                    a = v.g > 0 ? side_texel(&v, t, side, x, -1 - k) : edge_sample(&v, types[side], x, -1 - k);
                    b = side_texel(&v, tb, sb, xb, k);
                    ncont++;
                    if (!rgb_equal(a, b)) bad_cont++;
                }
        }
        /* the middle of the tile is its background window */
        if (bg->w != v.S || bg->h != v.S || bg->x < 0 || bg->y < 0 || bg->x + v.S > src->width ||
            bg->y + v.S > src->height)
            bad_bg++;
        else if (!rgb_equal(tile_texel(&v, t, v.S / 2, v.S / 2), px(src, bg->x + v.S / 2, bg->y + v.S / 2)))
            bad_bg++;
    }
    CHECK(bad_edge == 0, "%s: %d edge-row texels differ from the edge sample", name, bad_edge);
    CHECK(bad_gutter == 0, "%s: %d gutter texels do not continue the edge sample", name, bad_gutter);
    CHECK(bad_cont == 0 && ncont > 0, "%s: %d of %d texels discontinuous across complementary edges", name, bad_cont,
          ncont);
    CHECK(bad_alpha == 0, "%s: %d atlas texels not opaque", name, bad_alpha);
    CHECK(bad_bg == 0, "%s: %d tiles whose centre is not their background window", name, bad_bg);

    /* mip levels: count, seamless count, each the box-downsample of the last */
    {
        int expect_levels = 1, expect_seamless = 0, bad_mip = 0;
        while (expect_levels < TT_MAX_MIP_LEVELS && (v.C >> (expect_levels - 1)) % 2 == 0) expect_levels++;
        while (expect_seamless < expect_levels && (v.g >> expect_seamless) >= 1) expect_seamless++;
        CHECK(set->nlevels == expect_levels, "%s: nlevels expected %d (cell %d), got %d", name, expect_levels, v.C,
              set->nlevels);
        CHECK(set->seamless_levels == expect_seamless, "%s: seamless_levels expected %d (gutter %d), got %d", name,
              expect_seamless, v.g, set->seamless_levels);
        for (L = 1; L < set->nlevels; L++) {
            const tt_image *a = &set->levels[L - 1], *b = &set->levels[L];
            int y;
            if (b->width * 2 != a->width || b->height * 2 != a->height) { bad_mip++; continue; }
            for (y = 0; y < b->height; y++)
                for (x = 0; x < b->width; x++)
                    for (k = 0; k < 4; k++) {
                        double e = (px(a, 2 * x, 2 * y)[k] + px(a, 2 * x + 1, 2 * y)[k] + px(a, 2 * x, 2 * y + 1)[k] +
                                    px(a, 2 * x + 1, 2 * y + 1)[k]) / 4.0;
                        if (!near(px(b, x, y)[k], e, 1e-6)) bad_mip++;
                    }
        }
        CHECK(bad_mip == 0, "%s: %d mip texels differ from the box-downsample of the previous level", name, bad_mip);
    }
}

static void test_synthesis(void)
{
    tt_image src;
    int n, gi;
    make_noise(&src, 96, 192, 42);
    for (n = 1; n <= 2; n++)
        for (gi = 0; gi < 2; gi++) {
            tt_synth_options opt;
            tt_tileset *set = NULL, *again = NULL, *other = NULL;
            tt_error err;
            tt_result r;
            counter cnt;
            char name[64];
            memset(&opt, 0, sizeof opt);
            opt.layout = make_layout(n, 32, gi ? 4 : TT_NO_GUTTER);
            opt.seed = 7;
            opt.allocator = make_allocator(&cnt, -1);
            sprintf(name, "noise n=%d gutter %d", n, gi ? 4 : 0);
            r = tt_synthesize_tiles(&src, &opt, &set, &err);
            CHECK(r == TT_OK, "%s: synthesize returned %d (%s)", name, r, err.message);
            if (r != TT_OK) continue;
            check_tileset(set, &src, 2, name);
            r = tt_synthesize_tiles(&src, &opt, &again, &err);
            CHECK(r == TT_OK && again->levels[0].width == set->levels[0].width &&
                      memcmp(again->levels[0].pixels, set->levels[0].pixels,
                             sizeof(float) * 4 * (size_t)set->levels[0].width * set->levels[0].height) == 0,
                  "%s: same seed should give a byte-identical atlas", name);
            opt.seed = 8;
            r = tt_synthesize_tiles(&src, &opt, &other, &err);
            CHECK(r == TT_OK && other->levels[0].width == set->levels[0].width &&
                      memcmp(other->levels[0].pixels, set->levels[0].pixels,
                             sizeof(float) * 4 * (size_t)set->levels[0].width * set->levels[0].height) != 0,
                  "%s: seeds 7 and 8 should give different atlases", name);
            tt_tileset_free(set);
            tt_tileset_free(again);
            tt_tileset_free(other);
            CHECK(cnt.live == 0 && cnt.bad_frees == 0, "%s: %ld allocations leaked", name, cnt.live);
        }
    /* Given edge windows, a background region, a larger feather, S = 64 */
    {
        tt_synth_options opt;
        tt_tileset *set = NULL;
        tt_error err;
        tt_rect windows[2];
        tt_result r;
        memset(&opt, 0, sizeof opt);
        opt.layout = make_layout(2, 24, 3);
        windows[0].x = 5; windows[0].y = 9; windows[0].w = windows[0].h = 0;
        windows[1].x = 96 - 24; windows[1].y = 192 - 48; windows[1].w = windows[1].h = 0;
        opt.edge_windows = windows;
        opt.background.x = 10; opt.background.y = 20; opt.background.w = 40; opt.background.h = 50;
        opt.feather = 4;
        opt.seed = 3;
        r = tt_synthesize_tiles(&src, &opt, &set, &err);
        CHECK(r == TT_OK, "given windows: synthesize returned %d (%s)", r, err.message);
        if (r == TT_OK) {
            int t, bad = 0;
            CHECK(set->edge_windows[0].x == 5 && set->edge_windows[0].y == 9 && set->edge_windows[1].x == 72 &&
                      set->edge_windows[1].y == 144 && set->edge_windows[0].w == 24 && set->edge_windows[1].h == 48,
                  "the given edge windows should be used as they are");
            for (t = 0; t < tt_tile_layout_tile_count(&set->layout); t++) {
                const tt_rect *b = &set->background_windows[t];
                if (b->x < 10 || b->y < 20 || b->x + 24 > 50 || b->y + 24 > 70) bad++;
            }
            CHECK(bad == 0, "%d background windows outside the background region", bad);
            check_tileset(set, &src, 4, "given windows, feather 4, n=2, S=24, g=3");
            tt_tileset_free(set);
        }
        memset(&opt, 0, sizeof opt);
        opt.layout = make_layout(1, 64, 8);
        r = tt_synthesize_tiles(&src, &opt, &set, &err);
        CHECK(r == TT_OK, "S=64: %d (%s)", r, err.message);
        if (r == TT_OK) {
            check_tileset(set, &src, 4, "n=1, S=64, g=8");
            tt_tileset_free(set);
        }
    }
    tt_image_free(&src);
}

/* ------------------------------------------------------------------------ */
/* 6c. Quality measures                                                     */
/* ------------------------------------------------------------------------ */

static void check_histogram(int grid, int n, double tolerance)
{
    tmesh m;
    tt_mesh *mesh = NULL;
    tt_error err;
    tt_tile_layout l = make_layout(n, 16, 2);
    uint8_t *types;
    int *counts, ntiles = (2 * n) * (2 * n) * (2 * n) * (2 * n), t, lo = 1 << 30, hi = 0, sum = 0, unused = 0;
    double expected;
    tt_result r;
    memset(&m, 0, sizeof m);
    make_torus(&m, grid, grid, 10.0, 3.0);
    r = build(&m, 0, &mesh, &err);
    tm_free(&m);
    CHECK(r == TT_OK, "histogram torus build %d", r);
    if (r != TT_OK) return;
    types = (uint8_t *)malloc((size_t)mesh->ncorners);
    counts = (int *)malloc(sizeof(int) * (size_t)ntiles);
    tt_assign_boundaries(mesh, &l, 2025, types);
    r = tt_tile_histogram(mesh, &l, types, counts);
    CHECK(r == TT_OK, "tt_tile_histogram returned %d", r);
    expected = (double)mesh->nfaces / ntiles;
    for (t = 0; t < ntiles; t++) {
        if (counts[t] < lo) lo = counts[t];
        if (counts[t] > hi) hi = counts[t];
        unused += counts[t] == 0;
        sum += counts[t];
    }
    CHECK(sum == mesh->nfaces, "histogram n=%d: counts sum to %d, expected %d faces", n, sum, mesh->nfaces);
    CHECK(unused == 0, "histogram n=%d on %dx%d: %d of %d tiles unused", n, grid, grid, unused, ntiles);
    CHECK(lo >= expected * (1 - tolerance) && hi <= expected * (1 + tolerance),
          "histogram n=%d on %dx%d: counts %d..%d, expected %.0f +- %.0f%%", n, grid, grid, lo, hi, expected,
          100 * tolerance);
    /* against a naive count by tt_tile_index */
    {
        int *naive = (int *)calloc((size_t)ntiles, sizeof(int)), f, bad = 0;
        tt_tile_layout res;
        tt_tile_layout_resolve(&l, &res, NULL);
        for (f = 0; f < mesh->nfaces; f++) naive[tt_tile_index(&res, types + 4 * f)]++;
        for (t = 0; t < ntiles; t++) bad += naive[t] != counts[t];
        CHECK(bad == 0, "histogram n=%d: %d bins differ from the naive count", n, bad);
        free(naive);
    }
    types[5] = (uint8_t)(2 * n);
    CHECK(tt_tile_histogram(mesh, &l, types, counts) == TT_ERROR_INVALID_ARGUMENT, "histogram: type out of range");
    CHECK(tt_tile_histogram(NULL, &l, types, counts) == TT_ERROR_INVALID_ARGUMENT, "histogram: mesh NULL");
    free(types);
    free(counts);
    tt_mesh_free(mesh);
}

static void test_histogram(void)
{
    check_histogram(200, 1, 0.20);
    check_histogram(400, 2, 0.25);
}

static void test_seams(void)
{
    tmesh m;
    tt_mesh *mesh = NULL;
    tt_error err;
    tt_image src;
    tt_synth_options opt;
    tt_tileset *set = NULL;
    uint8_t *types;
    float *uv, *shuffled;
    tt_seam_report rep, rep2;
    tt_result r;
    int f, n;
    memset(&m, 0, sizeof m);
    make_torus(&m, 32, 24, 3.0, 1.0);
    r = build(&m, 0, &mesh, &err);
    tm_free(&m);
    CHECK(r == TT_OK, "seam torus build %d", r);
    if (r != TT_OK) return;
    make_value_noise(&src, 160, 256, 9);
    types = (uint8_t *)malloc((size_t)mesh->ncorners);
    uv = (float *)malloc(sizeof(float) * 2 * (size_t)mesh->ncorners);
    shuffled = (float *)malloc(sizeof(float) * 2 * (size_t)mesh->ncorners);
    for (n = 1; n <= 2; n++) {
        memset(&opt, 0, sizeof opt);
        opt.layout = make_layout(n, 32, 4);
        opt.seed = 11;
        r = tt_synthesize_tiles(&src, &opt, &set, &err);
        CHECK(r == TT_OK, "seams n=%d: synthesize %d (%s)", n, r, err.message);
        if (r != TT_OK) continue;
        tt_assign_boundaries(mesh, &opt.layout, 5, types);
        r = tt_assign_uvs(mesh, &opt.layout, types, uv, &err);
        CHECK(r == TT_OK, "seams: assign_uvs %d", r);
        r = tt_measure_seams(mesh, uv, &set->levels[0], 99, &rep);
        CHECK(r == TT_OK, "tt_measure_seams returned %d", r);
        CHECK(rep.edges_measured == 2 * mesh->nfaces, "seams: edges_measured expected %d, got %d", 2 * mesh->nfaces,
              rep.edges_measured);
        CHECK(rep.score <= 0.05, "seams n=%d: score %.4f > 0.05 (seam %.4f, same face %.4f, unrelated %.4f)", n,
              rep.score, rep.seam, rep.same_face, rep.unrelated);
        /* same seed, same report */
        tt_measure_seams(mesh, uv, &set->levels[0], 99, &rep2);
        CHECK(rep.score == rep2.score && rep.seam == rep2.seam, "seams: the same seed should give the same report");
        /* shuffle the faces' tiles: permute the 8-float UV blocks */
        {
            int *perm = (int *)malloc(sizeof(int) * (size_t)mesh->nfaces);
            lcg_seed(77);
            for (f = 0; f < mesh->nfaces; f++) perm[f] = f;
            for (f = mesh->nfaces - 1; f > 0; f--) {
                int j = lcg_below(f + 1), t = perm[f];
                perm[f] = perm[j];
                perm[j] = t;
            }
            for (f = 0; f < mesh->nfaces; f++) memcpy(shuffled + 8 * f, uv + 8 * perm[f], 8 * sizeof(float));
            free(perm);
        }
        r = tt_measure_seams(mesh, shuffled, &set->levels[0], 99, &rep2);
        /* With n = 2 a shuffled edge keeps complementary types (and so stays
           seamless) with probability 1/4 and otherwise mostly shows two
           different windows: the score must rise to >= 0.6. With n = 1 half
           the shuffled edges still match by type, and a mismatched one shows
           the same window row twice, mirrored (x against S-1-x: close
           together near the middle of the edge, so similar in a smooth
           texture), so the ceiling is lower: require a clear rise only. */
        if (n == 2)
            CHECK(r == TT_OK && rep2.score >= 0.6,
                  "seams n=%d shuffled: score %.4f < 0.6 (seam %.4f, same face %.4f, unrelated %.4f): the measure "
                  "should see mismatched tiles", n, rep2.score, rep2.seam, rep2.same_face, rep2.unrelated);
        else
            CHECK(r == TT_OK && rep2.score >= 0.15 && rep2.score >= rep.score + 0.2,
                  "seams n=%d shuffled: score %.4f (unshuffled %.4f; seam %.4f, same face %.4f, unrelated %.4f): "
                  "expected >= 0.15 and >= unshuffled + 0.2", n, rep2.score, rep.score, rep2.seam, rep2.same_face,
                  rep2.unrelated);
        tt_tileset_free(set);
        set = NULL;
    }
    CHECK(tt_measure_seams(NULL, uv, &src, 1, &rep) == TT_ERROR_INVALID_ARGUMENT &&
              tt_measure_seams(mesh, NULL, &src, 1, &rep) == TT_ERROR_INVALID_ARGUMENT &&
              tt_measure_seams(mesh, uv, NULL, 1, &rep) == TT_ERROR_INVALID_ARGUMENT &&
              tt_measure_seams(mesh, uv, &src, 1, NULL) == TT_ERROR_INVALID_ARGUMENT,
          "tt_measure_seams with NULL arguments should be rejected");
    free(types);
    free(uv);
    free(shuffled);
    tt_image_free(&src);
    tt_mesh_free(mesh);
}

static void test_stretch(void)
{
    tmesh m;
    tt_mesh *mesh = NULL;
    tt_error err;
    tt_tile_layout l = make_layout(1, 32, 4);
    uint8_t types[64];
    float uv[128], st[16];
    tt_result r;
    int f, bad = 0;
    memset(&m, 0, sizeof m);
    make_grid(&m, 3, 2);
    r = build(&m, 0, &mesh, &err);
    if (r == TT_OK) {
        tt_assign_boundaries(mesh, &l, 1, types);
        tt_assign_uvs(mesh, &l, types, uv, &err);
        CHECK(tt_face_stretch(mesh, uv, st) == TT_OK, "face_stretch");
        for (f = 0; f < mesh->nfaces; f++) bad += !near(st[f], 1.0, 1e-5);
        CHECK(bad == 0, "unit squares on square tiles: %d faces with stretch != 1 (face 0: %g)", bad, st[0]);
        tt_mesh_free(mesh);
    }
    /* 2:1 rectangles */
    for (f = 0; f < m.nv; f++) m.pos[3 * f] *= 2.0f;
    r = build(&m, 0, &mesh, &err);
    if (r == TT_OK) {
        tt_assign_boundaries(mesh, &l, 1, types);
        tt_assign_uvs(mesh, &l, types, uv, &err);
        CHECK(tt_face_stretch(mesh, uv, st) == TT_OK, "face_stretch");
        bad = 0;
        for (f = 0; f < mesh->nfaces; f++) bad += !near(st[f], 2.0, 1e-5);
        CHECK(bad == 0, "2:1 rectangles on square tiles: %d faces with stretch != 2 (face 0: %g)", bad, st[0]);
        /* a face whose UVs collapse is infinitely stretched */
        for (f = 0; f < 4; f++) { uv[2 * f] = 0.5f; uv[2 * f + 1] = 0.5f; }
        tt_face_stretch(mesh, uv, st);
        CHECK(isinf(st[0]) && st[0] > 0, "collapsed UVs: stretch expected +inf, got %g", st[0]);
        CHECK(tt_face_stretch(NULL, uv, st) == TT_ERROR_INVALID_ARGUMENT, "face_stretch mesh NULL");
        tt_mesh_free(mesh);
    }
    tm_free(&m);
    /* a right triangle with legs 1 and 3 mapped to legs of equal length: 3 */
    tm_vert(&m, 0, 0, 0); tm_vert(&m, 1, 0, 0); tm_vert(&m, 0, 3, 0);
    tm_tri(&m, 0, 1, 2);
    r = build(&m, 0, &mesh, &err);
    if (r == TT_OK) {
        float tuv[6] = {0, 0, 0.1f, 0, 0, 0.1f};
        tt_face_stretch(mesh, tuv, st);
        CHECK(near(st[0], 3.0, 1e-4), "triangle 1 x 3 on a 1 x 1 UV triangle: stretch expected 3, got %g", st[0]);
        tt_mesh_free(mesh);
    }
    tm_free(&m);
}

static int g_progress_calls;
static float g_progress_last;
static int g_progress_monotone;
static int cancel_at_3(float fraction, void *user)
{
    (void)user;
    if (fraction < g_progress_last || fraction < 0.0f || fraction > 1.0f) g_progress_monotone = 0;
    g_progress_last = fraction;
    return ++g_progress_calls >= 3;
}
static int never_cancel(float fraction, void *user)
{
    (void)user;
    if (fraction < g_progress_last || fraction < 0.0f || fraction > 1.0f) g_progress_monotone = 0;
    g_progress_last = fraction;
    g_progress_calls++;
    return 0;
}

static void expect_synth_error(const tt_image *src, const tt_synth_options *opt, tt_result code, const char *what)
{
    tt_synth_options o = *opt;
    tt_tileset *set = (tt_tileset *)&set;
    tt_error err;
    counter cnt;
    tt_result r;
    o.allocator = make_allocator(&cnt, -1);
    err.message[0] = '\0';
    r = tt_synthesize_tiles(src, &o, &set, &err);
    CHECK(r == code && set == NULL && err.result == code && err.message[0] != '\0',
          "%s: expected %d with *out NULL and a message, got %d (%s)", what, code, r, err.message);
    if (r == TT_OK && set) tt_tileset_free(set);
    CHECK(cnt.live == 0, "%s: %ld allocations leaked", what, cnt.live);
}

static void test_synth_errors(void)
{
    tt_image src, small;
    tt_synth_options opt;
    tt_tileset *set = NULL;
    tt_error err;
    tt_result r;
    tt_rect win;
    make_noise(&src, 64, 128, 5);
    memset(&opt, 0, sizeof opt);
    opt.layout = make_layout(1, 16, 2);

    r = tt_synthesize_tiles(&src, &opt, NULL, &err);
    CHECK(r == TT_ERROR_INVALID_ARGUMENT, "out NULL: got %d", r);
    expect_synth_error(NULL, &opt, TT_ERROR_INVALID_ARGUMENT, "source NULL");
    {
        tt_image empty;
        memset(&empty, 0, sizeof empty);
        expect_synth_error(&empty, &opt, TT_ERROR_INVALID_ARGUMENT, "empty source");
    }
    opt.layout.colors = -1;
    expect_synth_error(&src, &opt, TT_ERROR_INVALID_ARGUMENT, "colors -1");
    opt.layout.colors = TT_MAX_COLORS + 1;
    expect_synth_error(&src, &opt, TT_ERROR_INVALID_ARGUMENT, "colors TT_MAX_COLORS+1");
    opt.layout.colors = 0;
    {
        counter cnt;
        opt.allocator = make_allocator(&cnt, -1);
        r = tt_synthesize_tiles(&src, &opt, &set, &err);
        CHECK(r == TT_OK && set->layout.colors == 1 && set->layout.tile_size == 16 && set->layout.gutter == 2,
              "colors 0 means 1: got %d, colors %d", r, r == TT_OK ? set->layout.colors : -1);
        if (r == TT_OK) tt_tileset_free(set);
        CHECK(cnt.live == 0, "colors 0: leak");
        memset(&opt.allocator, 0, sizeof opt.allocator);
    }
    opt.layout.colors = 1;
    opt.layout.tile_size = 3;
    {
        counter cnt;
        tt_synth_options o = opt;
        o.allocator = make_allocator(&cnt, -1);
        set = (tt_tileset *)&set;
        r = tt_synthesize_tiles(&src, &o, &set, &err);
        if (r == TT_OK) tt_tileset_free(set);
        CHECK((r == TT_ERROR_INVALID_ARGUMENT || r == TT_ERROR_TOO_LARGE) && set == NULL && cnt.live == 0,
              "tile size 3 rejected, got %d", r);
    }
    opt.layout.tile_size = 40000;
    expect_synth_error(&src, &opt, TT_ERROR_TOO_LARGE, "tile size 40000");
    opt.layout = make_layout(2, 2048, 4);
    expect_synth_error(&src, &opt, TT_ERROR_TOO_LARGE, "n=2, S=2048: atlas over TT_MAX_IMAGE_SIZE");
    opt.layout = make_layout(1, 65, 2);
    expect_synth_error(&src, &opt, TT_ERROR_IMAGE_TOO_SMALL, "S=65 on a 64x128 image (too narrow)");
    make_noise(&small, 64, 95, 1);
    opt.layout = make_layout(1, 48, 2);
    expect_synth_error(&small, &opt, TT_ERROR_IMAGE_TOO_SMALL, "S=48 on a 64x95 image: fits S x S but not S x 2S");
    tt_image_free(&small);
    make_noise(&small, 16, 31, 1);
    opt.layout = make_layout(1, 16, 2);
    expect_synth_error(&small, &opt, TT_ERROR_IMAGE_TOO_SMALL, "16x31 image for S=16");
    tt_image_free(&small);
    make_noise(&small, 16, 32, 1);
    {
        counter cnt;
        tt_synth_options o = opt;
        o.allocator = make_allocator(&cnt, -1);
        r = tt_synthesize_tiles(&small, &o, &set, &err);
        CHECK(r == TT_OK, "16x32 image for S=16 (exactly S x 2S) should work, got %d (%s)", r, err.message);
        if (r == TT_OK) tt_tileset_free(set);
        CHECK(cnt.live == 0, "16x32: leak");
    }
    tt_image_free(&small);

    /* edge windows outside the image */
    opt.layout = make_layout(1, 16, 2);
    opt.edge_windows = &win;
    win.w = win.h = 0;
    win.x = 64 - 16 + 1; win.y = 0;
    expect_synth_error(&src, &opt, TT_ERROR_INVALID_ARGUMENT, "edge window one texel too far right");
    win.x = 0; win.y = 128 - 32 + 1;
    expect_synth_error(&src, &opt, TT_ERROR_INVALID_ARGUMENT, "edge window one texel too low");
    win.x = -1; win.y = 0;
    expect_synth_error(&src, &opt, TT_ERROR_INVALID_ARGUMENT, "edge window at x = -1");
    win.x = 64 - 16; win.y = 128 - 32;
    {
        counter cnt;
        tt_synth_options o = opt;
        o.allocator = make_allocator(&cnt, -1);
        r = tt_synthesize_tiles(&src, &o, &set, &err);
        CHECK(r == TT_OK, "edge window at the bottom-right limit should fit, got %d (%s)", r, err.message);
        if (r == TT_OK) tt_tileset_free(set);
    }
    opt.edge_windows = NULL;
    /* background region */
    opt.background.x = 60; opt.background.y = 0; opt.background.w = 16; opt.background.h = 16;
    expect_synth_error(&src, &opt, TT_ERROR_INVALID_ARGUMENT, "background region outside the image");
    opt.background.x = 0; opt.background.w = 15;
    expect_synth_error(&src, &opt, TT_ERROR_IMAGE_TOO_SMALL, "background region narrower than a tile");
    memset(&opt.background, 0, sizeof opt.background);
    /* feather too wide */
    opt.feather = 16 / 4 + 2;
    expect_synth_error(&src, &opt, TT_ERROR_INVALID_ARGUMENT, "feather wider than S/4+1");
    opt.feather = 0;

    /* progress: monotone in (0,1], ends at 1; cancelling cleans up */
    {
        counter cnt;
        tt_synth_options o = opt;
        o.allocator = make_allocator(&cnt, -1);
        o.progress = never_cancel;
        g_progress_calls = 0;
        g_progress_last = 0.0f;
        g_progress_monotone = 1;
        r = tt_synthesize_tiles(&src, &o, &set, &err);
        CHECK(r == TT_OK && g_progress_calls > 0 && g_progress_monotone && g_progress_last == 1.0f,
              "progress: %d calls, monotone %d, last %g", g_progress_calls, g_progress_monotone, g_progress_last);
        if (r == TT_OK) tt_tileset_free(set);
        o.progress = cancel_at_3;
        g_progress_calls = 0;
        g_progress_last = 0.0f;
        set = (tt_tileset *)&set;
        r = tt_synthesize_tiles(&src, &o, &set, &err);
        if (r == TT_OK) tt_tileset_free(set);
        CHECK(r == TT_CANCELLED && set == NULL && err.result == TT_CANCELLED && g_progress_calls == 3,
              "cancel at the 3rd progress call: expected TT_CANCELLED after 3 calls, got %d after %d", r,
              g_progress_calls);
        CHECK(cnt.live == 0 && cnt.bad_frees == 0, "cancelled synthesis leaked %ld allocations", cnt.live);
    }
    /* NULL options: defaults (n = 1, S = 128) need a 128 x 256 source */
    set = (tt_tileset *)&set;
    r = tt_synthesize_tiles(&src, NULL, &set, &err);
    if (r == TT_OK) tt_tileset_free(set);
    CHECK(r == TT_ERROR_IMAGE_TOO_SMALL && set == NULL, "NULL options on a 64x128 image: expected %d, got %d",
          TT_ERROR_IMAGE_TOO_SMALL, r);
    tt_tileset_free(NULL);
    tt_image_free(&src);
}

typedef struct synth_ctx {
    const tt_image *src;
    tt_synth_options opt;
} synth_ctx;

static tt_result oom_synth(void *ctx, const tt_allocator *al)
{
    synth_ctx *s = (synth_ctx *)ctx;
    tt_synth_options o = s->opt;
    tt_tileset *set = (tt_tileset *)&set;
    tt_error err;
    tt_result r;
    o.allocator = *al;
    r = tt_synthesize_tiles(s->src, &o, &set, &err);
    if (r == TT_OK) tt_tileset_free(set);
    else if (set != NULL || err.result != r) return TT_RESULT_MAX_ENUM;
    return r;
}

static void test_synth_oom(void)
{
    tt_image src;
    synth_ctx s;
    make_noise(&src, 24, 48, 8);
    oom_reset();
    memset(&s, 0, sizeof s);
    s.src = &src;
    s.opt.layout = make_layout(1, 8, 2);
    oom_sweep("tt_synthesize_tiles(n=1, S=8)", oom_synth, &s, TT_OK);
    s.opt.layout = make_layout(2, 4, TT_NO_GUTTER);
    s.opt.seed = 3;
    oom_sweep("tt_synthesize_tiles(n=2, S=4)", oom_synth, &s, TT_OK);
    tt_image_free(&src);
}

/* ------------------------------------------------------------------------ */
/* 4. Numerics: sparse matrices and conjugate gradients                     */
/* ------------------------------------------------------------------------ */

/* ------------------------------------------------------------------------ */
/* 4. Numerics                                                              */
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
    int trial, bad_trials = 0;
    lcg_seed(401);
    for (trial = 0; trial < 300; trial++) {
        int rows = 1 + lcg_below(trial < 100 ? 6 : 40), cols = 1 + lcg_below(trial < 100 ? 6 : 40);
        int count = lcg_below(3 * rows * cols / 2 + 2), bad;
        tt_triplet *t = cg_random_triplets(rows, cols, count);
        char *used = (char *)calloc((size_t)rows * cols, 1);
        double *d = cg_dense_from_triplets(rows, cols, t, count, used);
        tt_sparse_matrix m;
        tt_error err;
        tt_result r = tt_sparse_from_triplets(&m, rows, cols, t, count, &al, &err);
        if (r != TT_OK) bad = 1000;
        else {
            bad = cg_matches_dense(&m, d, used, rows, cols);
            if (cnt.live != 3) bad++;
        }
        if (bad && !bad_trials)
            DETAIL("trial %d: %d x %d from %d triplets: result %d, %d bad entries (%s)", trial, rows, cols, count, r,
                   bad, err.message);
        if (bad) bad_trials++;
        if (r == TT_OK) tt_sparse_free(&m);
        CHECK(m.row_start == NULL && m.col == NULL && m.value == NULL && m.nnz == 0,
              "tt_sparse_free zeroes the struct");
        free(t);
        free(used);
        free(d);
    }
    CHECK(bad_trials == 0, "CSR from random triplets differs from the dense sum in %d of 300 trials", bad_trials);
    CHECK(cnt.live == 0 && cnt.bad_frees == 0, "triplets: %ld allocations leaked, %ld bad frees", cnt.live,
          cnt.bad_frees);
    {
        /* A hand-checked case: unsorted input, a duplicate, an empty row 1, a
           zero sum that stays in the pattern. */
        static const tt_triplet t[] = {{2, 3, 1.0}, {0, 2, 5.0}, {2, 0, 2.0}, {0, 0, 1.5}, {2, 3, 0.25},
                                       {0, 1, 4.0}, {0, 1, -4.0}};
        static const int rs[] = {0, 3, 3, 5}, cl[] = {0, 1, 2, 0, 3};
        static const double vl[] = {1.5, 0.0, 5.0, 2.0, 1.25};
        tt_sparse_matrix m;
        int k, same = 1;
        tt_result r = tt_sparse_from_triplets(&m, 3, 4, t, 7, NULL, NULL);
        CHECK(r == TT_OK && m.rows == 3 && m.cols == 4 && m.nnz == 5, "3x4 example: result %d, %d x %d, nnz %d", r,
              m.rows, m.cols, m.nnz);
        if (r == TT_OK && m.nnz == 5) {
            for (k = 0; k < 4; k++) same &= m.row_start[k] == rs[k];
            for (k = 0; k < 5; k++) same &= m.col[k] == cl[k] && m.value[k] == vl[k];
            CHECK(same, "3x4 example: row_start/col/value differ from the hand-made CSR");
        }
        tt_sparse_free(&m);
        tt_sparse_free(&m);   /* twice is harmless */
        tt_sparse_free(NULL);
    }
    {
        /* No triplets; a 0 x 0 matrix; NULL triplets with count 0. */
        tt_sparse_matrix m;
        tt_result r = tt_sparse_from_triplets(&m, 4, 2, NULL, 0, &al, NULL);
        CHECK(r == TT_OK && m.nnz == 0 && m.rows == 4 && m.row_start && m.row_start[4] == 0,
              "4x2 from no triplets: result %d, nnz %d", r, m.nnz);
        tt_sparse_free(&m);
        r = tt_sparse_from_triplets(&m, 0, 0, NULL, 0, &al, NULL);
        CHECK(r == TT_OK && m.nnz == 0 && m.rows == 0 && m.row_start && m.row_start[0] == 0,
              "0x0 matrix: result %d", r);
        tt_sparse_free(&m);
        CHECK(cnt.live == 0, "empty matrices: %ld allocations leaked", cnt.live);
    }
}

static void cg_expect_triplet_error(int rows, int cols, const tt_triplet *t, int count, tt_result code, int row,
                                    int col, int index, const char *what)
{
    counter cnt;
    tt_allocator al = make_allocator(&cnt, -1);
    tt_sparse_matrix m;
    tt_error err;
    tt_result r;
    memset(&m, 0x5a, sizeof m);
    r = tt_sparse_from_triplets(&m, rows, cols, t, count, &al, &err);
    CHECK(r == code && err.result == code, "%s: expected %d, got %d (err.result %d)", what, code, r, err.result);
    CHECK(m.row_start == NULL && m.col == NULL && m.value == NULL && m.rows == 0 && m.nnz == 0,
          "%s: the matrix should be zeroed on failure", what);
    CHECK(cnt.calls == 0 && cnt.live == 0, "%s: %ld allocations made, %ld live; none expected", what, cnt.calls,
          cnt.live);
    CHECK(err.message[0] != '\0', "%s: empty message", what);
    if (row != -2) CHECK(err.vertex == row && err.other_vertex == col, "%s: row/col expected %d/%d, got %d/%d", what,
                         row, col, err.vertex, err.other_vertex);
    if (index >= 0) CHECK(msg_has_number(err.message, index), "%s: message should name triplet %d: %s", what, index,
                          err.message);
    r = tt_sparse_from_triplets(&m, rows, cols, t, count, &al, NULL);
    CHECK(r == code, "%s with error == NULL: expected %d, got %d", what, code, r);
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
    CHECK(tt_sparse_from_triplets(NULL, 3, 3, t, 4, NULL, NULL) == TT_ERROR_INVALID_ARGUMENT, "matrix NULL");
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
        tt_sparse_matrix m;
        for (j = 0; j < cols; j++) x[j] = lcg_unit() * 2.0 - 1.0;
        if (tt_sparse_from_triplets(&m, rows, cols, t, count, NULL, NULL) != TT_OK ||
            tt_sparse_multiply(&m, x, y) != TT_OK) {
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
        tt_sparse_free(&m);
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
        CHECK(tt_sparse_multiply(&m, x, y) == TT_OK && y[0] == 35.0 && y[1] == -2.0,
              "hand-made CSR: expected 35, -2, got %g, %g", y[0], y[1]);
        CHECK(tt_sparse_multiply(&m, x, x) == TT_ERROR_INVALID_ARGUMENT, "x == y must be refused");
        CHECK(tt_sparse_multiply(NULL, x, y) == TT_ERROR_INVALID_ARGUMENT, "A NULL must be refused");
        CHECK(tt_sparse_multiply(&m, NULL, y) == TT_ERROR_INVALID_ARGUMENT, "x NULL must be refused");
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
        tt_sparse_matrix m;
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
        } else if (tt_sparse_from_triplets(&m, n, n, t, count, &al, NULL) != TT_OK) {
            bad_result++;
        } else {
            memset(&opt, 0, sizeof opt);
            /* 1e-12 is near what double arithmetic can confirm for these
               matrices: without the final check against a recomputed b - A x,
               the drift of the updated residual shows here. */
            opt.tolerance = 1e-12;
            opt.max_iterations = 20 * n + 100;
            opt.allocator = al;
            r = tt_cg_solve(&m, b, x, &opt, &rep, &err);
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
            tt_sparse_free(&m);
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
static tt_sparse_matrix cg_grid_matrix(int w, int h, double shift)
{
    tt_triplet *t = (tt_triplet *)malloc(sizeof(tt_triplet) * (size_t)w * h * 9);
    int x, y, count = 0;
    tt_sparse_matrix m;
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
    if (tt_sparse_from_triplets(&m, w * h, w * h, t, count, NULL, NULL) != TT_OK) memset(&m, 0, sizeof m);
    free(t);
    return m;
}

/* |b - A x| / |b| through tt_sparse_multiply. */
static double cg_relres(const tt_sparse_matrix *m, const double *b, const double *x)
{
    double *ax = (double *)malloc(sizeof(double) * (size_t)m->rows + 1), rr = 0.0, bb = 0.0;
    int i;
    tt_sparse_multiply(m, x, ax);
    for (i = 0; i < m->rows; i++) {
        rr += (b[i] - ax[i]) * (b[i] - ax[i]);
        bb += b[i] * b[i];
    }
    free(ax);
    return sqrt(rr / bb);
}

static void test_cg_grid(void)
{
    const int w = 40, h = 30, n = w * h;
    tt_sparse_matrix m = cg_grid_matrix(w, h, 1.0);
    double *xs = (double *)malloc(sizeof(double) * n), *b = (double *)malloc(sizeof(double) * n);
    double *x = (double *)calloc((size_t)n, sizeof(double)), maxerr = 0.0;
    tt_cg_report rep;
    tt_error err;
    tt_result r;
    int i, iterations;
    counter cnt;
    tt_cg_options opt;
    memset(&opt, 0, sizeof opt);
    opt.allocator = make_allocator(&cnt, -1);
    CHECK(m.rows == n && m.nnz == n + 2 * ((w - 1) * h + w * (h - 1)), "grid matrix: %d rows, %d entries", m.rows,
          m.nnz);
    lcg_seed(404);
    for (i = 0; i < n; i++) xs[i] = sin(0.1 * (i % w)) * cos(0.13 * (i / w)) + 0.1 * lcg_unit();
    tt_sparse_multiply(&m, xs, b);

    /* Laplacian + identity: condition number < 9, default options. */
    r = tt_cg_solve(&m, b, x, &opt, &rep, &err);
    for (i = 0; i < n; i++) maxerr = fmax(maxerr, fabs(x[i] - xs[i]));
    CHECK(r == TT_OK && rep.converged && err.result == TT_OK, "grid: expected TT_OK, got %d (%s)", r, err.message);
    CHECK(rep.residual <= 1e-8 && near(rep.residual, cg_relres(&m, b, x), 1e-12),
          "grid: report residual %g, recomputed %g (tolerance 1e-8)", rep.residual, cg_relres(&m, b, x));
    CHECK(rep.iterations > 5 && rep.iterations < 60, "grid: %d steps for a condition number below 9", rep.iterations);
    CHECK(maxerr < 1e-7, "grid: |x - x*|_inf = %g", maxerr);
    CHECK(cnt.live == 0 && cnt.calls == 1, "grid: %ld allocation calls (1 expected), %ld live", cnt.calls, cnt.live);
    iterations = rep.iterations;

    /* Warm start from the solution just found: done in 0 or 1 step. */
    r = tt_cg_solve(&m, b, x, &opt, &rep, &err);
    CHECK(r == TT_OK && rep.iterations <= 1 && rep.converged, "warm start from the solution: %d, %d steps", r,
          rep.iterations);
    /* Warm start from the exact x*: b = A x* up to rounding, so 0 steps. */
    memcpy(x, xs, sizeof(double) * n);
    r = tt_cg_solve(&m, b, x, &opt, &rep, &err);
    CHECK(r == TT_OK && rep.iterations <= 1 && rep.converged, "warm start from x*: %d, %d steps", r, rep.iterations);

    /* A tighter tolerance takes more steps and gets closer. */
    memset(x, 0, sizeof(double) * n);
    opt.tolerance = 1e-13;
    r = tt_cg_solve(&m, b, x, &opt, &rep, NULL);
    CHECK(r == TT_OK && rep.iterations > iterations && rep.residual <= 1e-13,
          "tolerance 1e-13: result %d, %d steps (1e-8 took %d), residual %g", r, rep.iterations, iterations,
          rep.residual);

    /* The iteration cap. */
    memset(x, 0, sizeof(double) * n);
    opt.tolerance = 0.0;
    opt.max_iterations = 3;
    r = tt_cg_solve(&m, b, x, &opt, &rep, &err);
    CHECK(r == TT_ERROR_NOT_CONVERGED && err.result == r, "cap of 3 steps: expected %d, got %d",
          TT_ERROR_NOT_CONVERGED, r);
    CHECK(rep.iterations == 3 && !rep.converged && rep.residual > 1e-8 && rep.residual < 1.0 &&
              near(rep.residual, cg_relres(&m, b, x), 1e-12),
          "cap of 3 steps: report {%d, %g, %d}, recomputed residual %g", rep.iterations, rep.residual, rep.converged,
          cg_relres(&m, b, x));
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
    r = tt_cg_solve(&m, b, x, &opt, &rep, &err);
    for (i = 0; i < n && x[i] == 0.0; i++) continue;
    CHECK(r == TT_OK && i == n && rep.iterations == 0 && rep.converged && rep.residual == 0.0,
          "b = 0: result %d, %d of %d zeros, %d steps", r, i, n, rep.iterations);

    /* A pure Laplacian (no shift) plus one pinned row is still SPD but badly
       conditioned: the default cap (2n) is enough with Jacobi. */
    tt_sparse_free(&m);
    m = cg_grid_matrix(w, h, 0.0);
    m.value[0] += 1.0;   /* A[0][0] is the first entry of row 0: pin vertex 0 */
    tt_sparse_multiply(&m, xs, b);
    memset(x, 0, sizeof(double) * n);
    r = tt_cg_solve(&m, b, x, NULL, &rep, &err);
    maxerr = 0.0;
    for (i = 0; i < n; i++) maxerr = fmax(maxerr, fabs(x[i] - xs[i]));
    CHECK(r == TT_OK && rep.residual <= 1e-8 && maxerr < 1e-3,
          "pinned Laplacian: result %d, %d steps, residual %g, |x - x*| %g (%s)", r, rep.iterations, rep.residual,
          maxerr, err.message);
    tt_sparse_free(&m);
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
    tt_sparse_matrix m = cg_grid_matrix(w, h, 0.01);
    double *b = (double *)malloc(sizeof(double) * n), *x = (double *)calloc((size_t)n, sizeof(double));
    cg_progress_log log;
    tt_cg_options opt;
    tt_cg_report rep;
    tt_error err;
    tt_result r;
    counter cnt;
    int i;
    for (i = 0; i < n; i++) b[i] = (double)(i % 7) - 3.0;
    memset(&opt, 0, sizeof opt);
    memset(&log, 0, sizeof log);
    opt.progress = cg_progress;
    opt.progress_user_data = &log;
    opt.allocator = make_allocator(&cnt, -1);
    r = tt_cg_solve(&m, b, x, &opt, &rep, &err);
    CHECK(r == TT_OK && log.calls == rep.iterations, "progress: result %d, %d calls for %d steps", r, log.calls,
          rep.iterations);
    CHECK(log.decreasing == 0 && log.out_of_range == 0 && log.last > 0.5f,
          "progress: %d decreases, %d outside [0,1], last %g", log.decreasing, log.out_of_range, log.last);
    memset(&log, 0, sizeof log);
    memset(x, 0, sizeof(double) * n);
    log.cancel_at = 5;
    r = tt_cg_solve(&m, b, x, &opt, &rep, &err);
    CHECK(r == TT_CANCELLED && err.result == TT_CANCELLED && rep.iterations == 4 && !rep.converged &&
              rep.residual > 0.0 && rep.residual < 1.0,
          "cancel at the 5th call: result %d, %d steps, residual %g", r, rep.iterations, rep.residual);
    CHECK(cnt.live == 0, "cancel: %ld allocations leaked", cnt.live);
    tt_sparse_free(&m);
    free(b);
    free(x);
}

/* tt_cg_solve must fail with `code`, name `row` (-2: do not check), leave x
   alone when `untouched`, and leak nothing. */
static void cg_expect_solve_error(const tt_sparse_matrix *m, const double *b, double *x, const tt_cg_options *o,
                                  tt_result code, int row, int untouched, const char *what)
{
    counter cnt;
    tt_cg_options opt;
    tt_cg_report rep;
    tt_error err;
    tt_result r;
    double keep[8];
    int n = m && m->rows > 0 && m->rows <= 8 ? m->rows : 0, i, same = 1;
    if (o) opt = *o;
    else memset(&opt, 0, sizeof opt);
    opt.allocator = make_allocator(&cnt, -1);
    if (x && n) memcpy(keep, x, sizeof(double) * n);
    memset(&rep, 0x5a, sizeof rep);
    r = tt_cg_solve(m, b, x, &opt, &rep, &err);
    CHECK(r == code && err.result == code, "%s: expected %d, got %d (%s)", what, code, r, err.message);
    CHECK(err.message[0] != '\0', "%s: empty message", what);
    if (row != -2) CHECK(err.vertex == row && msg_has_number(err.message, row), "%s: should name row %d: vertex %d, %s",
                         what, row, err.vertex, err.message);
    if (untouched && x && n) {
        for (i = 0; i < n; i++) same &= x[i] == keep[i];
        CHECK(same, "%s: x should be left as it was", what);
    }
    CHECK(!rep.converged && rep.iterations >= 0 && rep.iterations < 100, "%s: report {%d, %g, %d}", what,
          rep.iterations, rep.residual, rep.converged);
    CHECK(cnt.live == 0 && cnt.bad_frees == 0, "%s: %ld allocations leaked", what, cnt.live);
    r = tt_cg_solve(m, b, x, &opt, NULL, NULL);
    CHECK(r == code, "%s with report and error NULL: expected %d, got %d", what, code, r);
    if (x && n) memcpy(x, keep, sizeof(double) * n);
}

static tt_sparse_matrix cg_small(int rows, int cols, const double *dense)
{
    tt_triplet t[64];
    int i, j, count = 0;
    tt_sparse_matrix m;
    for (i = 0; i < rows; i++)
        for (j = 0; j < cols; j++)
            if (dense[i * cols + j] != 0.0) {
                t[count].row = i;
                t[count].col = j;
                t[count].value = dense[i * cols + j];
                count++;
            }
    if (tt_sparse_from_triplets(&m, rows, cols, t, count, NULL, NULL) != TT_OK) memset(&m, 0, sizeof m);
    return m;
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
    tt_sparse_matrix m = cg_small(3, 3, spd), bad;
    tt_cg_options opt;
    memset(&opt, 0, sizeof opt);

    cg_expect_solve_error(NULL, b, x, NULL, TT_ERROR_INVALID_ARGUMENT, -2, 1, "A NULL");
    cg_expect_solve_error(&m, NULL, x, NULL, TT_ERROR_INVALID_ARGUMENT, -2, 1, "b NULL");
    cg_expect_solve_error(&m, b, NULL, NULL, TT_ERROR_INVALID_ARGUMENT, -2, 1, "x NULL");
    cg_expect_solve_error(&m, b, b, NULL, TT_ERROR_INVALID_ARGUMENT, -2, 1, "b == x");
    opt.tolerance = -1.0;
    cg_expect_solve_error(&m, b, x, &opt, TT_ERROR_INVALID_ARGUMENT, -2, 1, "tolerance -1");
    opt.tolerance = NAN;
    cg_expect_solve_error(&m, b, x, &opt, TT_ERROR_INVALID_ARGUMENT, -2, 1, "tolerance NaN");
    opt.tolerance = 0.0;
    opt.max_iterations = -1;
    cg_expect_solve_error(&m, b, x, &opt, TT_ERROR_INVALID_ARGUMENT, -2, 1, "max_iterations -1");

    bad = cg_small(3, 4, rect);
    cg_expect_solve_error(&bad, b, x, NULL, TT_ERROR_INVALID_ARGUMENT, -2, 1, "3 x 4 matrix");
    tt_sparse_free(&bad);
    bad = cg_small(3, 3, zero_diag);
    cg_expect_solve_error(&bad, b, x, NULL, TT_ERROR_NOT_POSITIVE_DEFINITE, 1, 1, "zero (missing) diagonal in row 1");
    tt_sparse_free(&bad);
    bad = cg_small(3, 3, neg_diag);
    cg_expect_solve_error(&bad, b, x, NULL, TT_ERROR_NOT_POSITIVE_DEFINITE, 2, 1, "negative diagonal in row 2");
    tt_sparse_free(&bad);
    bad = cg_small(3, 3, empty_row);
    cg_expect_solve_error(&bad, b, x, NULL, TT_ERROR_NOT_POSITIVE_DEFINITE, 2, 1, "empty row 2");
    tt_sparse_free(&bad);
    {
        /* An explicit zero on the diagonal (kept in the pattern). */
        tt_triplet t[4] = {{0, 0, 1.0}, {1, 1, 1.0}, {1, 1, -1.0}, {2, 2, 1.0}};
        tt_sparse_from_triplets(&bad, 3, 3, t, 4, NULL, NULL);
        cg_expect_solve_error(&bad, b, x, NULL, TT_ERROR_NOT_POSITIVE_DEFINITE, 1, 1, "diagonal summing to 0");
        tt_sparse_free(&bad);
    }

    /* NaN or infinity in A (changed in place), b, x. */
    m.value[3] = NAN;   /* row 1: entries (1,0) (1,1) (1,2) start at 2 */
    cg_expect_solve_error(&m, b, x, NULL, TT_ERROR_NON_FINITE, 1, 1, "NaN in A");
    m.value[3] = 3.0;
    b[2] = NAN;
    cg_expect_solve_error(&m, b, x, NULL, TT_ERROR_NON_FINITE, 2, 1, "NaN in b");
    b[2] = INFINITY;
    cg_expect_solve_error(&m, b, x, NULL, TT_ERROR_NON_FINITE, 2, 1, "inf in b");
    b[2] = 3.0;
    x[1] = -INFINITY;
    cg_expect_solve_error(&m, b, x, NULL, TT_ERROR_NON_FINITE, 1, 1, "-inf in the initial guess");
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
            CHECK(tt_cg_solve(&h, b2, x2, NULL, &rep, NULL) == TT_OK && near(x2[0], 1.0, 1e-9) &&
                      near(x2[1], 1.0, 1e-9) && rep.iterations <= 2,
                  "unsorted CSR with repeated columns: x = %g %g in %d steps", x2[0], x2[1], rep.iterations);
        }
    }

    /* Positive diagonal but indefinite: breakdown at step 1 (p . A p = -12). */
    bad = cg_small(2, 2, indefinite);
    b[1] = 0.0;
    x[0] = x[1] = 0.0;
    cg_expect_solve_error(&bad, b, x, NULL, TT_ERROR_NOT_POSITIVE_DEFINITE, -2, 0, "indefinite 2 x 2");
    tt_sparse_free(&bad);
    b[1] = 2.0;

    {
        /* 0 x 0 and 1 x 1 systems. */
        tt_sparse_matrix e;
        tt_cg_report rep;
        double one = 4.0, sol = 0.0;
        tt_sparse_from_triplets(&e, 0, 0, NULL, 0, NULL, NULL);
        CHECK(tt_cg_solve(&e, b, x, NULL, &rep, NULL) == TT_OK && rep.converged && rep.iterations == 0,
              "0 x 0 system: should succeed at once");
        tt_sparse_free(&e);
        e = cg_small(1, 1, &one);
        CHECK(tt_cg_solve(&e, b, &sol, NULL, &rep, NULL) == TT_OK && near(sol, 0.25, 1e-15) && rep.iterations == 1,
              "1 x 1: 4 x = 1 gave %g in %d steps", sol, rep.iterations);
        tt_sparse_free(&e);
    }
    tt_sparse_free(&m);
}

typedef struct cg_oom_ctx {
    const tt_triplet *t;
    int n, count;
    const double *b;
} cg_oom_ctx;

static tt_result cg_oom_triplets(void *ctx, const tt_allocator *al)
{
    cg_oom_ctx *c = (cg_oom_ctx *)ctx;
    tt_sparse_matrix m;
    tt_error err;
    tt_result r = tt_sparse_from_triplets(&m, c->n, c->n, c->t, c->count, al, &err);
    if (r == TT_OK) tt_sparse_free(&m);
    else if (m.row_start || m.col || m.value || err.result != r) return TT_RESULT_MAX_ENUM;
    return r;
}

static tt_result cg_oom_solve(void *ctx, const tt_allocator *al)
{
    cg_oom_ctx *c = (cg_oom_ctx *)ctx;
    tt_sparse_matrix m;
    tt_cg_options opt;
    tt_error err;
    tt_result r;
    double x[64];
    memset(x, 0, sizeof x);
    if (tt_sparse_from_triplets(&m, c->n, c->n, c->t, c->count, NULL, NULL) != TT_OK) return TT_RESULT_MAX_ENUM;
    memset(&opt, 0, sizeof opt);
    opt.allocator = *al;
    r = tt_cg_solve(&m, c->b, x, &opt, NULL, &err);
    if (r != TT_OK && err.result != r) r = TT_RESULT_MAX_ENUM;
    tt_sparse_free(&m);
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
    oom_reset();
    oom_sweep("tt_sparse_from_triplets(40 x 40)", cg_oom_triplets, &c, TT_OK);
    oom_sweep("tt_cg_solve(40 x 40)", cg_oom_solve, &c, TT_OK);
    for (i = 0; i < 64; i++) b[i] = 0.0;
    oom_sweep("tt_cg_solve(b = 0)", cg_oom_solve, &c, TT_OK);
}

/* ------------------------------------------------------------------------ */
/* 7. Lapped textures: the tangent field                                    */
/* ------------------------------------------------------------------------ */

/* ------------------------------------------------------------------------ */
/* 7. Lapped textures: tangent field                                        */
/* ------------------------------------------------------------------------ */

/* Latitude-longitude sphere, poles on the z axis: triangles at the poles,
   quads between; outward CCW. */
static void make_field_sphere(tmesh *m, int nlat, int nlon, double radius)
{
    const double pi = 3.14159265358979323846;
    int i, j, north, south, base;
    north = tm_vert(m, 0, 0, radius);
    base = m->nv;
    for (j = 1; j < nlat; j++)
        for (i = 0; i < nlon; i++) {
            double t = pi * j / nlat, p = 2 * pi * i / nlon;
            tm_vert(m, radius * sin(t) * cos(p), radius * sin(t) * sin(p), radius * cos(t));
        }
    south = tm_vert(m, 0, 0, -radius);
    for (i = 0; i < nlon; i++) tm_tri(m, north, base + i, base + (i + 1) % nlon);
    for (j = 0; j + 1 < nlat - 1; j++)
        for (i = 0; i < nlon; i++) {
            int i1 = (i + 1) % nlon;
            tm_quad(m, base + j * nlon + i, base + (j + 1) * nlon + i, base + (j + 1) * nlon + i1, base + j * nlon + i1);
        }
    for (i = 0; i < nlon; i++)
        tm_tri(m, base + (nlat - 2) * nlon + i, south, base + (nlat - 2) * nlon + (i + 1) % nlon);
}

static double fv_dot(const float *a, const float *b) { return (double)a[0] * b[0] + (double)a[1] * b[1] + (double)a[2] * b[2]; }
static double fv_len(const float *a) { return sqrt(fv_dot(a, a)); }

/* Angle between a and b (radians); pi/2 if either is zero. */
static double fv_angle(const double *a, const double *b)
{
    double la = sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]), lb = sqrt(b[0] * b[0] + b[1] * b[1] + b[2] * b[2]);
    double c;
    if (la == 0.0 || lb == 0.0) return 1.5707963267948966;
    c = (a[0] * b[0] + a[1] * b[1] + a[2] * b[2]) / (la * lb);
    return acos(c > 1.0 ? 1.0 : (c < -1.0 ? -1.0 : c));
}

/* Largest angle between the vectors of two faces sharing an edge, the
   neighbour's projected on the face's plane. */
static double field_max_neighbour_angle(const tt_mesh *mesh, const float *v)
{
    double worst = 0.0;
    int c;
    for (c = 0; c < mesh->ncorners; c++) {
        int f = mesh->corner_face[c], g, k;
        float n[3];
        double a[3], b[3], d, ang;
        if (mesh->twin[c] < 0) continue;
        g = mesh->corner_face[mesh->twin[c]];
        tt_face_normal(mesh, f, n);
        d = fv_dot(v + 3 * g, n);
        for (k = 0; k < 3; k++) { a[k] = v[3 * f + k]; b[k] = v[3 * g + k] - d * n[k]; }
        ang = fv_angle(a, b);
        if (ang > worst) worst = ang;
    }
    return worst;
}

/* Half-edges across which the field turns by more than `limit` radians. */
static int field_rough_edges(const tt_mesh *mesh, const float *v, double limit)
{
    int c, count = 0;
    for (c = 0; c < mesh->ncorners; c++) {
        int f = mesh->corner_face[c], g, k;
        float n[3];
        double a[3], b[3], d;
        if (mesh->twin[c] < 0) continue;
        g = mesh->corner_face[mesh->twin[c]];
        tt_face_normal(mesh, f, n);
        d = fv_dot(v + 3 * g, n);
        for (k = 0; k < 3; k++) { a[k] = v[3 * f + k]; b[k] = v[3 * g + k] - d * n[k]; }
        if (fv_angle(a, b) > limit) count++;
    }
    return count;
}

/* Every vector in its face's plane with length `len` (relative tolerances);
   counts offenders and reports the first. */
static void check_field_plane_length(const tt_mesh *mesh, const float *v, double len, const char *what)
{
    int f, off_plane = 0, bad_len = 0;
    for (f = 0; f < mesh->nfaces; f++) {
        float n[3];
        double l = fv_len(v + 3 * f), d;
        tt_face_normal(mesh, f, n);
        d = fv_dot(v + 3 * f, n);
        if (!(fabs(d) <= 1e-5 * (len >= 0 ? len : l))) {
            if (!off_plane) DETAIL("%s: face %d: |v.n| = %g for |v| = %g", what, f, fabs(d), l);
            off_plane++;
        }
        if (len >= 0 && !near(l, len, 1e-5 * len)) {
            if (!bad_len) DETAIL("%s: face %d: length %.9g, expected %.9g", what, f, l, len);
            bad_len++;
        }
    }
    CHECK(off_plane == 0, "%s: %d of %d vectors leave their face's plane", what, off_plane, mesh->nfaces);
    CHECK(bad_len == 0, "%s: %d of %d vectors do not have length %g", what, bad_len, mesh->nfaces, len);
}

/* Faces not perpendicular to `up` must point along up projected on the face.
   Returns how many faces were perpendicular (left to propagation). */
static int check_field_up(const tt_mesh *mesh, int first_face, const float *v, const float up_in[3], const char *what)
{
    double up[3], lu;
    int f, k, bad = 0, perpendicular = 0;
    for (k = 0; k < 3; k++) up[k] = up_in[k];
    lu = sqrt(up[0] * up[0] + up[1] * up[1] + up[2] * up[2]);
    for (k = 0; k < 3; k++) up[k] /= lu;
    for (f = first_face; f < mesh->nfaces; f++) {
        float n[3];
        double p[3], d, a[3], ang;
        tt_face_normal(mesh, f, n);
        d = up[0] * n[0] + up[1] * n[1] + up[2] * n[2];
        for (k = 0; k < 3; k++) { p[k] = up[k] - d * n[k]; a[k] = v[3 * f + k]; }
        if (sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]) < TT_FIELD_PERPENDICULAR + 1e-4) { perpendicular++; continue; }
        ang = fv_angle(a, p);
        if (!(ang < 1e-4)) {
            if (!bad) DETAIL("%s: face %d is %g rad from projected up", what, f, ang);
            bad++;
        }
    }
    CHECK(bad == 0, "%s: %d faces do not point along the projected up vector", what, bad);
    return perpendicular;
}

static void test_field_default(void)
{
    tmesh m;
    tt_mesh *mesh = NULL;
    tt_field_options opt;
    tt_error err;
    float *v;
    int perpendicular, f;
    double diag;

    /* Sphere, up = +y (default): the caps around +-y are perpendicular. */
    memset(&m, 0, sizeof m);
    make_field_sphere(&m, 24, 32, 2.0);
    CHECK(build(&m, 0, &mesh, &err) == TT_OK, "sphere builds: %s", err.message);
    v = (float *)malloc(sizeof(float) * 3 * (size_t)mesh->nfaces);
    memset(&opt, 0, sizeof opt);
    opt.scale = 0.5f;
    CHECK(tt_tangent_field(mesh, &opt, v, &err) == TT_OK, "sphere field: %s", err.message);
    CHECK(err.result == TT_OK && err.face == -1, "success clears the error (result %d face %d)", err.result, err.face);
    check_field_plane_length(mesh, v, 0.5, "sphere, up = default");
    {
        const float up[3] = {0, 1, 0};
        perpendicular = check_field_up(mesh, 0, v, up, "sphere, up = default");
    }
    CHECK(perpendicular > 0, "sphere: expected some faces perpendicular to +y, got %d", perpendicular);
    /* Default scale: 0.1 of the bounding-box diagonal (4 sqrt 3 for r = 2: the poles and equator reach +-2). */
    {
        float lo[3] = {1e30f, 1e30f, 1e30f}, hi[3] = {-1e30f, -1e30f, -1e30f};
        int i, k;
        for (i = 0; i < m.nv; i++)
            for (k = 0; k < 3; k++) {
                if (m.pos[3 * i + k] < lo[k]) lo[k] = m.pos[3 * i + k];
                if (m.pos[3 * i + k] > hi[k]) hi[k] = m.pos[3 * i + k];
            }
        diag = sqrt((double)(hi[0] - lo[0]) * (hi[0] - lo[0]) + (double)(hi[1] - lo[1]) * (hi[1] - lo[1]) +
                    (double)(hi[2] - lo[2]) * (hi[2] - lo[2]));
    }
    CHECK(tt_tangent_field(mesh, NULL, v, &err) == TT_OK, "NULL options: %s", err.message);
    check_field_plane_length(mesh, v, TT_DEFAULT_FIELD_SCALE * diag, "sphere, NULL options (default scale)");
    /* A tilted up vector, not unit length: only its direction counts. */
    opt.up[0] = 0.6f; opt.up[1] = 2.0f; opt.up[2] = -0.9f;
    CHECK(tt_tangent_field(mesh, &opt, v, &err) == TT_OK, "tilted up: %s", err.message);
    check_field_plane_length(mesh, v, 0.5, "sphere, tilted up");
    perpendicular = check_field_up(mesh, 0, v, opt.up, "sphere, tilted up");
    CHECK(perpendicular > 0, "sphere, tilted up: expected perpendicular faces, got %d", perpendicular);
    free(v);
    tt_mesh_free(mesh);
    tm_free(&m);

    /* Torus around z with up = +z: the top and bottom bands are perpendicular. */
    memset(&m, 0, sizeof m);
    make_torus(&m, 32, 16, 3.0, 1.0);
    CHECK(build(&m, 0, &mesh, &err) == TT_OK, "torus builds: %s", err.message);
    v = (float *)malloc(sizeof(float) * 3 * (size_t)mesh->nfaces);
    memset(&opt, 0, sizeof opt);
    opt.up[2] = 1.0f;
    opt.scale = 0.25f;
    CHECK(tt_tangent_field(mesh, &opt, v, &err) == TT_OK, "torus field: %s", err.message);
    check_field_plane_length(mesh, v, 0.25, "torus, up = +z");
    perpendicular = check_field_up(mesh, 0, v, opt.up, "torus, up = +z");
    CHECK(perpendicular > 0, "torus: expected perpendicular faces, got %d", perpendicular);
    /* Projected up flips across the top and bottom rings (both sides point
       at the ring), so only most edges are smooth; the flips are the field's. */
    CHECK(field_rough_edges(mesh, v, 0.5) <= 2 * 2 * 32, "torus: %d half-edges turn by more than 0.5 rad",
          field_rough_edges(mesh, v, 0.5));
    free(v);
    tt_mesh_free(mesh);
    tm_free(&m);

    /* Open grid in z = 0, up = +y: every face points exactly along +y. */
    memset(&m, 0, sizeof m);
    make_grid(&m, 6, 4);
    CHECK(build(&m, 0, &mesh, &err) == TT_OK, "grid builds: %s", err.message);
    v = (float *)malloc(sizeof(float) * 3 * (size_t)mesh->nfaces);
    memset(&opt, 0, sizeof opt);
    opt.scale = 2.0f;
    CHECK(tt_tangent_field(mesh, &opt, v, &err) == TT_OK, "grid field: %s", err.message);
    for (f = 0; f < mesh->nfaces; f++)
        if (v[3 * f] != 0.0f || v[3 * f + 1] != 2.0f || v[3 * f + 2] != 0.0f) break;
    CHECK(f == mesh->nfaces, "grid, up = +y: face %d is (%g, %g, %g), expected (0, 2, 0)", f,
          f < mesh->nfaces ? v[3 * f] : 0.0, f < mesh->nfaces ? v[3 * f + 1] : 0.0, f < mesh->nfaces ? v[3 * f + 2] : 0.0);
    {
        float n[3];
        tt_face_normal(mesh, 0, n);
        CHECK(n[0] == 0.0f && n[1] == 0.0f && n[2] == 1.0f, "tt_face_normal of the grid: (%g, %g, %g)", n[0], n[1], n[2]);
    }
    free(v);
    tt_mesh_free(mesh);
    tm_free(&m);
}

/* Surfaces facing up: no face has a usable projection, so everything comes
   from the seed face's first edge, carried breadth-first. */
static void test_field_fallback(void)
{
    tmesh m;
    tt_mesh *mesh = NULL;
    tt_field_options opt;
    tt_error err;
    float *v, *w;
    int f, i, j, bad = 0;

    /* Flat grid facing up: every face gets face 0's first edge, +x. */
    memset(&m, 0, sizeof m);
    make_grid(&m, 7, 5);
    CHECK(build(&m, 0, &mesh, &err) == TT_OK, "grid builds: %s", err.message);
    v = (float *)malloc(sizeof(float) * 3 * (size_t)mesh->nfaces);
    memset(&opt, 0, sizeof opt);
    opt.up[2] = 1.0f;
    opt.scale = 1.0f;
    CHECK(tt_tangent_field(mesh, &opt, v, &err) == TT_OK, "flat grid facing up: %s", err.message);
    for (f = 0; f < mesh->nfaces; f++)
        if (!near(v[3 * f], 1.0, 1e-6) || !near(v[3 * f + 1], 0.0, 1e-6) || !near(v[3 * f + 2], 0.0, 1e-6)) bad++;
    CHECK(bad == 0, "flat grid facing up: %d faces not (1, 0, 0) (face 0's first edge)", bad);
    free(v);
    tt_mesh_free(mesh);
    tm_free(&m);

    /* A gentle dome facing up (normals within ~8 degrees of +z, under the 11.5 of TT_FIELD_PERPENDICULAR): propagation
       must stay tangent, keep the scale and vary slowly. */
    memset(&m, 0, sizeof m);
    for (j = 0; j <= 12; j++)
        for (i = 0; i <= 12; i++) {
            double x = (i - 6) / 6.0, y = (j - 6) / 6.0;
            tm_vert(&m, x, y, -0.05 * (x * x + y * y));
        }
    for (j = 0; j < 12; j++)
        for (i = 0; i < 12; i++) {
            int a = j * 13 + i;
            if ((i + j) % 2) tm_quad(&m, a, a + 1, a + 14, a + 13);
            else { tm_tri(&m, a, a + 1, a + 14); tm_tri(&m, a, a + 14, a + 13); }
        }
    CHECK(build(&m, 0, &mesh, &err) == TT_OK, "dome builds: %s", err.message);
    v = (float *)malloc(sizeof(float) * 3 * (size_t)mesh->nfaces);
    w = (float *)malloc(sizeof(float) * 3 * (size_t)mesh->nfaces);
    CHECK(tt_tangent_field(mesh, &opt, v, &err) == TT_OK, "dome facing up: %s", err.message);
    check_field_plane_length(mesh, v, 1.0, "dome facing up");
    CHECK(field_max_neighbour_angle(mesh, v) < 0.05, "dome facing up: neighbouring vectors differ by %g rad",
          field_max_neighbour_angle(mesh, v));
    /* Determinism: the same call gives the same bits. */
    CHECK(tt_tangent_field(mesh, &opt, w, &err) == TT_OK, "dome again: %s", err.message);
    CHECK(memcmp(v, w, sizeof(float) * 3 * (size_t)mesh->nfaces) == 0, "two identical calls differ");
    free(v);
    free(w);
    tt_mesh_free(mesh);
    tm_free(&m);

    /* Two components: a grid facing up (fallback) and a torus (up works),
       plus a zero-area triangle in a permissive mesh: it gets (0, 0, 0). */
    memset(&m, 0, sizeof m);
    make_grid(&m, 3, 3);
    make_torus(&m, 12, 8, 3.0, 1.0);
    {
        int a = tm_vert(&m, 10, 0, 0), b = tm_vert(&m, 11, 0, 0), c = tm_vert(&m, 12, 0, 0);
        tm_tri(&m, a, b, c);
    }
    CHECK(build(&m, TT_MESH_PERMISSIVE, &mesh, &err) == TT_OK, "grid + torus + sliver builds: %s", err.message);
    v = (float *)malloc(sizeof(float) * 3 * (size_t)mesh->nfaces);
    CHECK(tt_tangent_field(mesh, &opt, v, &err) == TT_OK, "grid + torus + sliver: %s", err.message);
    f = mesh->nfaces - 1;
    CHECK(v[3 * f] == 0.0f && v[3 * f + 1] == 0.0f && v[3 * f + 2] == 0.0f, "zero-area face: (%g, %g, %g)", v[3 * f],
          v[3 * f + 1], v[3 * f + 2]);
    {
        float n[3];
        tt_face_normal(mesh, f, n);
        CHECK(n[0] == 0.0f && n[1] == 0.0f && n[2] == 0.0f, "tt_face_normal of a zero-area face: (%g, %g, %g)", n[0],
              n[1], n[2]);
    }
    bad = 0;
    for (f = 0; f < 9; f++)
        if (!near(v[3 * f], 1.0, 1e-6) || !near(v[3 * f + 1], 0.0, 1e-6) || !near(v[3 * f + 2], 0.0, 1e-6)) bad++;
    CHECK(bad == 0, "grid beside a torus: %d faces not (1, 0, 0)", bad);
    bad = 0;
    for (f = 9; f < mesh->nfaces - 1; f++)
        if (!near(fv_len(v + 3 * f), 1.0, 1e-5)) bad++;
    CHECK(bad == 0, "torus beside a grid: %d faces without unit length", bad);
    free(v);
    tt_mesh_free(mesh);
    tm_free(&m);
}

static void test_field_constraints(void)
{
    tmesh m;
    tt_mesh *mesh = NULL;
    tt_field_options opt;
    tt_field_constraint con[3];
    tt_error err;
    float *v;
    int f, k, bad = 0;
    double lmin = 1e30, lmax = 0.0;

    /* One constraint on a flat grid: parallel transport is the identity, so
       every face gets the constraint's vector. */
    memset(&m, 0, sizeof m);
    make_grid(&m, 8, 8);
    CHECK(build(&m, 0, &mesh, &err) == TT_OK, "grid builds: %s", err.message);
    v = (float *)malloc(sizeof(float) * 3 * (size_t)mesh->nfaces);
    memset(&opt, 0, sizeof opt);
    memset(con, 0, sizeof con);
    con[0].face = 27;
    con[0].vector[0] = 0.3f; con[0].vector[1] = 0.4f; con[0].vector[2] = 5.0f;   /* z is projected away */
    opt.constraints = con;
    opt.nconstraints = 1;
    CHECK(tt_tangent_field(mesh, &opt, v, &err) == TT_OK, "grid, one constraint: %s", err.message);
    {
        /* Direction from the projection (0.6, 0.8, 0), length |vector| (the scale). */
        double l = sqrt(0.3 * 0.3 + 0.4 * 0.4 + 5.0 * 5.0);
        for (f = 0; f < mesh->nfaces; f++)
            if (!near(v[3 * f], 0.6 * l, 1e-5) || !near(v[3 * f + 1], 0.8 * l, 1e-5) || !near(v[3 * f + 2], 0.0, 1e-6))
                bad++;
        CHECK(bad == 0, "grid, one constraint: %d faces differ from (0.6, 0.8, 0) * %g", bad, l);
    }
    free(v);
    tt_mesh_free(mesh);
    tm_free(&m);

    /* Torus: three constraints of different directions and lengths. */
    memset(&m, 0, sizeof m);
    make_torus(&m, 48, 16, 3.0, 1.0);
    CHECK(build(&m, 0, &mesh, &err) == TT_OK, "torus builds: %s", err.message);
    v = (float *)malloc(sizeof(float) * 3 * (size_t)mesh->nfaces);
    memset(con, 0, sizeof con);
    con[0].face = 0;                       /* outer equator at angle 0: tangent plane y, z */
    con[0].vector[2] = 0.2f;
    con[1].face = 16;                      /* a third of the way round */
    con[1].vector[0] = -0.866f * 0.4f; con[1].vector[1] = 0.5f * 0.4f;   /* along the ring */
    con[2].face = 32 + 8 * 48;             /* inner side, two thirds round */
    con[2].vector[2] = -0.3f;
    con[2].sigma = 1.0f;
    con[2].weight = 2.0f;
    opt.constraints = con;
    opt.nconstraints = 3;
    CHECK(tt_tangent_field(mesh, &opt, v, &err) == TT_OK, "torus, constraints: %s", err.message);
    check_field_plane_length(mesh, v, -1.0, "torus, constraints (plane only)");
    for (k = 0; k < 3; k++) {
        float n[3];
        double c[3], d, a[3];
        int g = con[k].face, j;
        tt_face_normal(mesh, g, n);
        d = fv_dot(con[k].vector, n);
        for (j = 0; j < 3; j++) { c[j] = con[k].vector[j] - d * n[j]; a[j] = v[3 * g + j]; }
        CHECK(fv_angle(a, c) < 1e-5 && near(fv_len(v + 3 * g), fv_len(con[k].vector), 1e-6),
              "constraint %d on face %d: got (%g, %g, %g), expected (%g, %g, %g) projected", k, g, v[3 * g],
              v[3 * g + 1], v[3 * g + 2], con[k].vector[0], con[k].vector[1], con[k].vector[2]);
    }
    for (f = 0; f < mesh->nfaces; f++) {
        double l = fv_len(v + 3 * f);
        if (l < lmin) lmin = l;
        if (l > lmax) lmax = l;
    }
    CHECK(lmin >= 0.2 - 1e-6 && lmax <= 0.4 + 1e-6 && lmax - lmin > 0.1,
          "torus, constraints: lengths in [%g, %g], expected within [0.2, 0.4] and varying", lmin, lmax);
    /* Transport along each constraint's Dijkstra tree has a cut locus where paths round
       a handle meet with different holonomy: a few rough edges there, smooth elsewhere. */
    CHECK(field_rough_edges(mesh, v, 0.5) < mesh->ncorners / 10, "torus, constraints: %d of %d half-edges turn by more than 0.5 rad",
          field_rough_edges(mesh, v, 0.5), mesh->ncorners);
    /* Faces next to a constrained face stay close to it (smooth interpolation). */
    {
        int g = con[1].face, c;
        double worst = 0.0;
        for (c = mesh->face_start[g]; c < mesh->face_start[g + 1]; c++) {
            int h = mesh->corner_face[mesh->twin[c]], j;
            double a[3], b[3];
            for (j = 0; j < 3; j++) { a[j] = v[3 * g + j]; b[j] = v[3 * h + j]; }
            if (fv_angle(a, b) > worst) worst = fv_angle(a, b);
        }
        CHECK(worst < 0.3, "neighbours of constraint 1 turn by %g rad", worst);
    }
    free(v);
    tt_mesh_free(mesh);
    tm_free(&m);

    /* Two components: the constraint's component follows it, the other one
       (unreachable) falls back to the default rule. */
    memset(&m, 0, sizeof m);
    make_grid(&m, 3, 3);
    make_torus(&m, 12, 8, 3.0, 1.0);
    CHECK(build(&m, 0, &mesh, &err) == TT_OK, "grid + torus builds: %s", err.message);
    v = (float *)malloc(sizeof(float) * 3 * (size_t)mesh->nfaces);
    memset(con, 0, sizeof con);
    con[0].face = 4;
    con[0].vector[0] = 0.5f;
    opt.constraints = con;
    opt.nconstraints = 1;
    opt.scale = 0.7f;
    CHECK(tt_tangent_field(mesh, &opt, v, &err) == TT_OK, "grid + torus, constraint: %s", err.message);
    bad = 0;
    for (f = 0; f < 9; f++)
        if (!near(v[3 * f], 0.5, 1e-6) || !near(v[3 * f + 1], 0.0, 1e-6) || !near(v[3 * f + 2], 0.0, 1e-6)) bad++;
    CHECK(bad == 0, "constrained grid: %d faces differ from (0.5, 0, 0)", bad);
    {
        int perpendicular;
        const float up[3] = {0, 1, 0};
        bad = 0;
        for (f = 9; f < mesh->nfaces; f++)
            if (!near(fv_len(v + 3 * f), 0.7, 1e-5)) bad++;
        CHECK(bad == 0, "unconstrained torus: %d faces without the scale 0.7", bad);
        perpendicular = check_field_up(mesh, 9, v, up, "grid + torus, torus part");
        (void)perpendicular;
    }
    free(v);
    tt_mesh_free(mesh);
    tm_free(&m);
}

static void test_field_errors(void)
{
    tmesh m, md;
    tt_mesh *mesh = NULL, *dmesh = NULL;
    tt_field_options opt;
    tt_field_constraint con[2];
    tt_error err;
    float v[3 * 64];
    float nan_f;
    {
        uint32_t bits = 0x7fc00000u;   /* a quiet NaN, whatever the compiler flags */
        memcpy(&nan_f, &bits, sizeof nan_f);
    }
    memset(&m, 0, sizeof m);
    make_grid(&m, 4, 4);
    CHECK(build(&m, 0, &mesh, &err) == TT_OK, "grid builds: %s", err.message);

#define FIELD_EXPECT(call, code, face_expected, what)                                                           \
    do {                                                                                                        \
        tt_result r_ = (call);                                                                                  \
        CHECK(r_ == (code) && err.result == (code) && (face_expected == -2 || err.face == face_expected) &&    \
                  err.message[0] != '\0',                                                                       \
              "%s: expected %d (face %d), got %d (face %d): %s", what, (int)(code), face_expected, (int)r_,   \
              err.face, err.message);                                                                          \
    } while (0)

    memset(&opt, 0, sizeof opt);
    FIELD_EXPECT(tt_tangent_field(NULL, &opt, v, &err), TT_ERROR_INVALID_ARGUMENT, -1, "NULL mesh");
    FIELD_EXPECT(tt_tangent_field(mesh, &opt, NULL, &err), TT_ERROR_INVALID_ARGUMENT, -1, "NULL output");
    CHECK(tt_tangent_field(NULL, &opt, v, NULL) == TT_ERROR_INVALID_ARGUMENT, "NULL error pointer is allowed");
    opt.up[0] = nan_f;
    FIELD_EXPECT(tt_tangent_field(mesh, &opt, v, &err), TT_ERROR_INVALID_ARGUMENT, -1, "NaN up");
    opt.up[0] = 1e-45f;   /* denormal: non-zero, still a direction */
    CHECK(tt_tangent_field(mesh, &opt, v, &err) == TT_OK, "tiny up is a direction: %s", err.message);
    opt.up[0] = 0.0f;
    opt.scale = -1.0f;
    FIELD_EXPECT(tt_tangent_field(mesh, &opt, v, &err), TT_ERROR_INVALID_ARGUMENT, -1, "negative scale");
    opt.scale = 1.0f / 0.0f;
    FIELD_EXPECT(tt_tangent_field(mesh, &opt, v, &err), TT_ERROR_INVALID_ARGUMENT, -1, "infinite scale");
    opt.scale = 0.0f;
    opt.sigma = nan_f;
    FIELD_EXPECT(tt_tangent_field(mesh, &opt, v, &err), TT_ERROR_INVALID_ARGUMENT, -1, "NaN sigma");
    opt.sigma = 0.0f;
    opt.nconstraints = -1;
    FIELD_EXPECT(tt_tangent_field(mesh, &opt, v, &err), TT_ERROR_INVALID_ARGUMENT, -1, "negative nconstraints");
    opt.nconstraints = 1;
    FIELD_EXPECT(tt_tangent_field(mesh, &opt, v, &err), TT_ERROR_INVALID_ARGUMENT, -1, "NULL constraints");

    memset(con, 0, sizeof con);
    con[0].face = 3; con[0].vector[0] = 1.0f;
    con[1].face = 16; con[1].vector[1] = 1.0f;
    opt.constraints = con;
    opt.nconstraints = 2;
    FIELD_EXPECT(tt_tangent_field(mesh, &opt, v, &err), TT_ERROR_INDEX_OUT_OF_RANGE, 16, "face == nfaces");
    CHECK(msg_has_number(err.message, 16) && msg_has_number(err.message, 1) && strstr(err.message, "constraint"),
          "the message names constraint 1 and face 16: %s", err.message);
    con[1].face = -1;
    FIELD_EXPECT(tt_tangent_field(mesh, &opt, v, &err), TT_ERROR_INDEX_OUT_OF_RANGE, -1, "face -1");
    con[1].face = 5;
    con[1].vector[1] = 0.0f;
    FIELD_EXPECT(tt_tangent_field(mesh, &opt, v, &err), TT_ERROR_INVALID_ARGUMENT, 5, "zero vector");
    CHECK(strstr(err.message, "constraint 1") != NULL, "the message names constraint 1: %s", err.message);
    con[1].vector[2] = 1.0f;   /* along the grid's normal */
    FIELD_EXPECT(tt_tangent_field(mesh, &opt, v, &err), TT_ERROR_INVALID_ARGUMENT, 5, "perpendicular vector");
    con[1].vector[2] = 0.0f;
    con[1].vector[1] = nan_f;
    FIELD_EXPECT(tt_tangent_field(mesh, &opt, v, &err), TT_ERROR_NON_FINITE, 5, "NaN vector");
    con[1].vector[1] = 1.0f / 0.0f;
    FIELD_EXPECT(tt_tangent_field(mesh, &opt, v, &err), TT_ERROR_NON_FINITE, 5, "infinite vector");
    con[1].vector[1] = 1.0f;
    con[1].weight = -1.0f;
    FIELD_EXPECT(tt_tangent_field(mesh, &opt, v, &err), TT_ERROR_INVALID_ARGUMENT, 5, "negative weight");
    con[1].weight = 0.0f;
    con[1].sigma = -2.0f;
    FIELD_EXPECT(tt_tangent_field(mesh, &opt, v, &err), TT_ERROR_INVALID_ARGUMENT, 5, "negative sigma");
    con[1].sigma = 0.0f;
    CHECK(tt_tangent_field(mesh, &opt, v, &err) == TT_OK, "valid constraints: %s", err.message);

    /* A constraint on a zero-area face (permissive mesh). */
    memset(&md, 0, sizeof md);
    make_grid(&md, 2, 1);
    {
        int a = tm_vert(&md, 5, 0, 0), b = tm_vert(&md, 6, 0, 0), c = tm_vert(&md, 7, 0, 0);
        tm_tri(&md, a, b, c);
    }
    CHECK(build(&md, TT_MESH_PERMISSIVE, &dmesh, &err) == TT_OK, "sliver mesh builds: %s", err.message);
    con[0].face = 2;
    opt.nconstraints = 1;
    FIELD_EXPECT(tt_tangent_field(dmesh, &opt, v, &err), TT_ERROR_ZERO_AREA_FACE, 2, "constraint on a zero-area face");
#undef FIELD_EXPECT
    tt_mesh_free(dmesh);
    tm_free(&md);
    tt_mesh_free(mesh);
    tm_free(&m);
}

typedef struct field_oom_ctx {
    const tt_mesh *mesh;
    const tt_field_constraint *constraints;
    int nconstraints;
    float up[3];
    float *out;
} field_oom_ctx;

static tt_result field_oom_call(void *ctx, const tt_allocator *al)
{
    field_oom_ctx *c = (field_oom_ctx *)ctx;
    tt_field_options opt;
    tt_error err;
    tt_result r;
    memset(&opt, 0, sizeof opt);
    memcpy(opt.up, c->up, sizeof opt.up);
    opt.constraints = c->constraints;
    opt.nconstraints = c->nconstraints;
    opt.allocator = *al;
    r = tt_tangent_field(c->mesh, &opt, c->out, &err);
    if (err.result != r) return TT_RESULT_MAX_ENUM;
    return r;
}

static void test_field_oom(void)
{
    tmesh m;
    tt_mesh *mesh = NULL;
    tt_error err;
    field_oom_ctx c;
    tt_field_constraint con[2];
    float *v;
    memset(&m, 0, sizeof m);
    make_torus(&m, 10, 6, 3.0, 1.0);
    make_grid(&m, 3, 2);
    CHECK(build(&m, 0, &mesh, &err) == TT_OK, "torus + grid builds: %s", err.message);
    v = (float *)malloc(sizeof(float) * 3 * (size_t)mesh->nfaces);
    memset(con, 0, sizeof con);
    con[0].face = 0; con[0].vector[2] = 1.0f;
    con[1].face = 30; con[1].vector[2] = -1.0f;
    oom_reset();
    memset(&c, 0, sizeof c);
    c.mesh = mesh;
    c.out = v;
    c.up[2] = 1.0f;
    oom_sweep("tt_tangent_field(default, up = +z)", field_oom_call, &c, TT_OK);
    c.constraints = con;
    c.nconstraints = 2;
    oom_sweep("tt_tangent_field(2 constraints)", field_oom_call, &c, TT_OK);
    con[1].face = 1000;
    oom_sweep("tt_tangent_field(bad constraint)", field_oom_call, &c, TT_ERROR_INDEX_OUT_OF_RANGE);
    free(v);
    tt_mesh_free(mesh);
    tm_free(&m);
}

/* ------------------------------------------------------------------------ */
/* 7. Lapped textures: texture patches                                      */
/* ------------------------------------------------------------------------ */

/* ------------------------------------------------------------------------ */
/* 7b. Texture patches                                                      */
/* ------------------------------------------------------------------------ */

/* A smooth, opaque RGB test source. */
static void patch_source(tt_image *img, int w, int h)
{
    int x, y;
    tt_image_create(img, w, h, NULL);
    for (y = 0; y < h; y++)
        for (x = 0; x < w; x++) {
            float *p = img->pixels + 4 * (y * w + x);
            p[0] = 0.2f + 0.6f * (float)x / (float)w;
            p[1] = 0.3f + 0.5f * (float)y / (float)h;
            p[2] = 0.7f;
            p[3] = 1.0f;
        }
}

/* Brute force: distance from texel (x, y)'s centre to the nearest texel centre
   outside the binary shape (alpha >= 0.5 of in), the image's surroundings
   counting as outside; 0 for texels outside. */
static double patch_brute_depth(const unsigned char *in, int w, int h, int x, int y)
{
    int i, j;
    double best;
    if (!in[y * w + x]) return 0.0;
    best = x + 1;
    if (w - x < best) best = w - x;
    if (y + 1 < best) best = y + 1;
    if (h - y < best) best = h - y;
    for (j = 0; j < h; j++)
        for (i = 0; i < w; i++)
            if (!in[j * w + i]) {
                double d = sqrt((double)((i - x) * (i - x) + (j - y) * (j - y)));
                if (d < best) best = d;
            }
    return best;
}

/* Checks alpha against the brute-force distance transform of `in`. */
static void patch_check_ramp(const tt_image *patch, const unsigned char *in, float falloff, const char *what)
{
    int x, y, bad = 0, w = patch->width, h = patch->height;
    double worst = 0.0;
    for (y = 0; y < h; y++)
        for (x = 0; x < w; x++) {
            double d = patch_brute_depth(in, w, h, x, y);
            double want = d > 0.0 ? (d - 0.5) / falloff : 0.0;
            double got = patch->pixels[4 * (y * w + x) + 3];
            if (want > 1.0) want = 1.0;
            if (want < 0.0) want = 0.0;
            if (fabs(got - want) > 1e-4) {
                if (!bad) DETAIL("%s: texel (%d, %d): alpha %g, want %g (depth %g)", what, x, y, got, want, d);
                bad++;
            }
            if (fabs(got - want) > worst) worst = fabs(got - want);
        }
    CHECK(bad == 0, "%s: alpha = clamp((depth - 0.5) / falloff) everywhere: %d texels off (worst %g)", what, bad,
          worst);
}

static void test_patch_splotch(void)
{
    tt_image src, patch;
    tt_patch_options opt;
    tt_error err;
    int w = 96, h = 80, x, y, inside = 0, half = 0, border_bad = 0, deep_bad = 0, pm_bad = 0, contour_bad = 0;
    unsigned char *in = (unsigned char *)malloc((size_t)(w * h));
    patch_source(&src, w, h);
    memset(&opt, 0, sizeof opt);
    opt.seed = 7;
    CHECK(tt_make_texture_patch(&src, NULL, &opt, &patch, &err) == TT_OK, "splotch: ok (%s)", err.message);
    CHECK(patch.width == w && patch.height == h && patch.pixels, "splotch: %d x %d patch", patch.width, patch.height);
    if (patch.pixels) {
        for (y = 0; y < h; y++)
            for (x = 0; x < w; x++) {
                const float *p = patch.pixels + 4 * (y * w + x), *s = src.pixels + 4 * (y * w + x);
                in[y * w + x] = (unsigned char)(p[3] > 0.0f);
                inside += p[3] > 0.0f;
                half += p[3] >= 0.5f;
                if ((x == 0 || y == 0 || x == w - 1 || y == h - 1) && p[3] != 0.0f) border_bad++;
                if (p[0] != s[0] * p[3] || p[1] != s[1] * p[3] || p[2] != s[2] * p[3]) pm_bad++;
            }
        /* The inside of the binary shape is exactly where alpha > 0 (depth >= 1). */
        CHECK(inside >= 0.60 * w * h && inside <= 0.75 * w * h, "splotch covers 60-75%% of the image: %.1f%%",
              100.0 * inside / (w * h));
        CHECK(half >= 0.55 * w * h && half <= 0.75 * w * h, "alpha >= 0.5 on 55-75%% of the image: %.1f%%",
              100.0 * half / (w * h));
        CHECK(border_bad == 0, "alpha is 0 on the image border: %d texels are not", border_bad);
        CHECK(pm_bad == 0, "premultiplied exactly: %d texels differ", pm_bad);
        /* Deep inside (the centre region) alpha is 1. */
        for (y = h / 2 - 10; y < h / 2 + 10; y++)
            for (x = w / 2 - 10; x < w / 2 + 10; x++) deep_bad += patch.pixels[4 * (y * w + x) + 3] != 1.0f;
        CHECK(deep_bad == 0, "alpha is 1 in the centre: %d texels are not", deep_bad);
        /* The 0.5 contour lies falloff/2 texels inside the shape's edge: every
           texel with alpha >= 0.5 is at least 2 texels from an outside centre,
           every one with 0 < alpha < 0.5 at most 2 (falloff 3: depth 0.5 + 1.5). */
        for (y = 0; y < h; y++)
            for (x = 0; x < w; x++) {
                float a = patch.pixels[4 * (y * w + x) + 3];
                double d = patch_brute_depth(in, w, h, x, y);
                if (a >= 0.5f && d < 2.0 - 1e-6) contour_bad++;
                if (a > 0.0f && a < 0.5f && d > 2.0 + 1e-6) contour_bad++;
            }
        CHECK(contour_bad == 0, "the 0.5 contour is falloff/2 = 1.5 texels inside the edge: %d texels off",
              contour_bad);
        patch_check_ramp(&patch, in, 3.0f, "splotch, falloff 3");
    }
    tt_image_free(&patch);
    /* A wider falloff is honoured too. */
    opt.falloff = 6.5f;
    CHECK(tt_make_texture_patch(&src, NULL, &opt, &patch, &err) == TT_OK, "falloff 6.5: ok (%s)", err.message);
    if (patch.pixels) {
        int ramp = 0;
        for (y = 0; y < h; y++)
            for (x = 0; x < w; x++) {
                float a = patch.pixels[4 * (y * w + x) + 3];
                in[y * w + x] = (unsigned char)(a > 0.0f);
                if ((x < 6 || y < 6 || x >= w - 6 || y >= h - 6) && a != 0.0f) border_bad++;
                ramp += a > 0.0f && a < 1.0f;
            }
        CHECK(border_bad == 0, "falloff 6.5: margin of 6.5 texels is transparent: %d texels are not", border_bad);
        CHECK(ramp > 6 * 150, "falloff 6.5: a wide ramp (%d texels between 0 and 1)", ramp);
        patch_check_ramp(&patch, in, 6.5f, "splotch, falloff 6.5");
    }
    tt_image_free(&patch);
    tt_image_free(&src);
    free(in);
}

static void test_patch_seeds(void)
{
    tt_image src, a, b, c;
    tt_patch_options opt;
    int w = 64, h = 64, seed, differ = 0, min_cov = w * h, max_cov = 0;
    size_t i;
    patch_source(&src, w, h);
    memset(&opt, 0, sizeof opt);
    opt.seed = 123;
    CHECK(tt_make_texture_patch(&src, NULL, &opt, &a, NULL) == TT_OK, "seed 123: ok");
    CHECK(tt_make_texture_patch(&src, NULL, &opt, &b, NULL) == TT_OK, "seed 123 again: ok");
    opt.seed = 124;
    CHECK(tt_make_texture_patch(&src, NULL, &opt, &c, NULL) == TT_OK, "seed 124: ok");
    if (a.pixels && b.pixels && c.pixels) {
        CHECK(memcmp(a.pixels, b.pixels, sizeof(float) * 4 * (size_t)(w * h)) == 0, "same seed, same patch");
        for (i = 0; i < (size_t)(w * h); i++) differ += (a.pixels[4 * i + 3] > 0.0f) != (c.pixels[4 * i + 3] > 0.0f);
        CHECK(differ > 20, "seeds 123 and 124 give different shapes: %d texels differ", differ);
    }
    tt_image_free(&a);
    tt_image_free(&b);
    tt_image_free(&c);
    /* Coverage holds over many seeds, and at the roughest setting. */
    for (seed = 0; seed < 40; seed++) {
        int cov = 0;
        opt.seed = (uint64_t)seed * 0x9e3779b97f4a7c15ull;
        opt.roughness = seed < 20 ? 0.0f : 0.6f;
        if (tt_make_texture_patch(&src, NULL, &opt, &a, NULL) != TT_OK) { cov = -1; }
        else {
            for (i = 0; i < (size_t)(w * h); i++) cov += a.pixels[4 * i + 3] > 0.0f;
            tt_image_free(&a);
        }
        if (cov < min_cov) min_cov = cov;
        if (cov > max_cov) max_cov = cov;
    }
    CHECK(min_cov >= 0.60 * w * h && max_cov <= 0.75 * w * h, "40 seeds: coverage %.1f%% .. %.1f%%",
          100.0 * min_cov / (w * h), 100.0 * max_cov / (w * h));
    tt_image_free(&src);
}

static void test_patch_masks(void)
{
    tt_image src, mask, patch;
    tt_error err;
    int w = 40, h = 30, x, y, bad = 0;
    unsigned char *in = (unsigned char *)malloc((size_t)(w * h));
    patch_source(&src, w, h);
    tt_image_create(&mask, w, h, NULL);
    /* Grey mask (opaque): a rectangle of grey 0.6 plus a stray 0.4 texel (outside). */
    for (y = 0; y < h; y++)
        for (x = 0; x < w; x++) {
            float *p = mask.pixels + 4 * (y * w + x);
            float g = (x >= 5 && x < 35 && y >= 4 && y < 26) ? 0.6f : 0.0f;
            if (x == 1 && y == 1) g = 0.4f;
            p[0] = p[1] = p[2] = g;
            p[3] = 1.0f;
            in[y * w + x] = (unsigned char)(g >= 0.5f);
        }
    CHECK(tt_make_texture_patch(&src, &mask, NULL, &patch, &err) == TT_OK, "grey mask: ok (%s)", err.message);
    if (patch.pixels) {
        patch_check_ramp(&patch, in, 3.0f, "grey mask");
        CHECK(patch.pixels[4 * (15 * w + 20) + 3] == 1.0f, "grey mask: centre alpha 1, got %g",
              patch.pixels[4 * (15 * w + 20) + 3]);
        CHECK(patch.pixels[4 * (4 * w + 20) + 3] > 0.16f && patch.pixels[4 * (4 * w + 20) + 3] < 0.17f,
              "grey mask: edge texel alpha 0.5/3, got %g", patch.pixels[4 * (4 * w + 20) + 3]);
    }
    tt_image_free(&patch);
    /* Mask alpha (not all 1): alpha is used, the grey ignored. */
    for (y = 0; y < h; y++)
        for (x = 0; x < w; x++) {
            float *p = mask.pixels + 4 * (y * w + x);
            int inside = (x - 20) * (x - 20) + (y - 15) * (y - 15) <= 100;
            p[0] = p[1] = p[2] = 1.0f - (float)inside;   /* grey says the opposite */
            p[3] = inside ? 0.75f : 0.25f;
            in[y * w + x] = (unsigned char)inside;
        }
    CHECK(tt_make_texture_patch(&src, &mask, NULL, &patch, &err) == TT_OK, "alpha mask: ok (%s)", err.message);
    if (patch.pixels) patch_check_ramp(&patch, in, 3.0f, "alpha mask");
    tt_image_free(&patch);
    /* Source alpha takes precedence over the mask: a band x in [10, 30). */
    for (y = 0; y < h; y++)
        for (x = 0; x < w; x++) {
            src.pixels[4 * (y * w + x) + 3] = (x >= 10 && x < 30) ? 1.0f : 0.0f;
            in[y * w + x] = (unsigned char)(x >= 10 && x < 30);
        }
    CHECK(tt_make_texture_patch(&src, &mask, NULL, &patch, &err) == TT_OK, "source alpha: ok (%s)", err.message);
    if (patch.pixels) {
        patch_check_ramp(&patch, in, 3.0f, "source alpha over mask");
        for (y = 0; y < h; y++)
            for (x = 0; x < w; x++) {
                const float *p = patch.pixels + 4 * (y * w + x), *s = src.pixels + 4 * (y * w + x);
                if (p[0] != s[0] * p[3] || p[1] != s[1] * p[3] || p[2] != s[2] * p[3]) bad++;
            }
        CHECK(bad == 0, "source alpha: premultiplied exactly, %d texels differ", bad);
    }
    tt_image_free(&patch);
    /* A fully opaque grey mask still fades out at the image border. */
    for (y = 0; y < h * w * 4; y++) mask.pixels[y] = 1.0f;
    for (y = 0; y < h * w; y++) { src.pixels[4 * y + 3] = 1.0f; in[y] = 1; }
    CHECK(tt_make_texture_patch(&src, &mask, NULL, &patch, &err) == TT_OK, "full mask: ok (%s)", err.message);
    if (patch.pixels) patch_check_ramp(&patch, in, 3.0f, "full mask");
    tt_image_free(&patch);
    tt_image_free(&mask);
    tt_image_free(&src);
    free(in);
}

static void test_patch_errors(void)
{
    tt_image src, mask, patch, empty;
    tt_patch_options opt;
    tt_error err;
    float nan_value = (float)tt__not_a_number();
    patch_source(&src, 32, 32);
    memset(&empty, 0, sizeof empty);
    memset(&opt, 0, sizeof opt);
    CHECK(tt_make_texture_patch(NULL, NULL, NULL, &patch, &err) == TT_ERROR_INVALID_ARGUMENT, "NULL source");
    CHECK(tt_make_texture_patch(&empty, NULL, NULL, &patch, &err) == TT_ERROR_INVALID_ARGUMENT, "empty source");
    CHECK(tt_make_texture_patch(&src, NULL, NULL, NULL, &err) == TT_ERROR_INVALID_ARGUMENT, "NULL patch");
    tt_image_create(&mask, 31, 32, NULL);
    CHECK(tt_make_texture_patch(&src, &mask, NULL, &patch, &err) == TT_ERROR_INVALID_ARGUMENT, "mask size");
    CHECK(strstr(err.message, "31 x 32") && strstr(err.message, "32 x 32"), "size message: %s", err.message);
    CHECK(patch.pixels == NULL && patch.width == 0, "patch left empty on error");
    tt_image_free(&mask);
    tt_image_create(&mask, 32, 32, NULL);   /* all zero: transparent black */
    CHECK(tt_make_texture_patch(&src, &mask, NULL, &patch, &err) == TT_ERROR_INVALID_ARGUMENT, "empty mask");
    CHECK(strstr(err.message, "the mask has no opaque pixel") != NULL, "empty mask message: %s", err.message);
    CHECK(err.result == TT_ERROR_INVALID_ARGUMENT, "err.result set: %d", err.result);
    mask.pixels[3] = nan_value;
    CHECK(tt_make_texture_patch(&src, &mask, NULL, &patch, &err) == TT_ERROR_NON_FINITE, "NaN mask: %s", err.message);
    tt_image_free(&mask);
    opt.falloff = -1.0f;
    CHECK(tt_make_texture_patch(&src, NULL, &opt, &patch, &err) == TT_ERROR_INVALID_ARGUMENT, "negative falloff");
    CHECK(strstr(err.message, "negative") != NULL, "negative falloff message: %s", err.message);
    opt.falloff = 15.0f;
    CHECK(tt_make_texture_patch(&src, NULL, &opt, &patch, &err) == TT_ERROR_INVALID_ARGUMENT, "falloff 15 on 32: %s",
          err.message);
    opt.falloff = 10.0f;   /* room for a splotch, but it is not 10 texels deep */
    CHECK(tt_make_texture_patch(&src, NULL, &opt, &patch, &err) == TT_ERROR_INVALID_ARGUMENT, "falloff 10 on 32: %s",
          err.message);
    CHECK(strstr(err.message, "no opaque texel") != NULL, "falloff 10 message: %s", err.message);
    opt.falloff = tt__infinity();
    CHECK(tt_make_texture_patch(&src, NULL, &opt, &patch, &err) == TT_ERROR_NON_FINITE, "infinite falloff");
    opt.falloff = nan_value;
    CHECK(tt_make_texture_patch(&src, NULL, &opt, &patch, &err) == TT_ERROR_NON_FINITE, "NaN falloff");
    opt.falloff = 0.0f;
    opt.roughness = nan_value;
    CHECK(tt_make_texture_patch(&src, NULL, &opt, &patch, &err) == TT_ERROR_NON_FINITE, "NaN roughness");
    opt.roughness = 1.0f;
    CHECK(tt_make_texture_patch(&src, NULL, &opt, &patch, &err) == TT_ERROR_INVALID_ARGUMENT, "roughness 1");
    opt.roughness = -0.5f;
    CHECK(tt_make_texture_patch(&src, NULL, &opt, &patch, &err) == TT_ERROR_INVALID_ARGUMENT, "roughness -0.5");
    opt.roughness = 0.0f;
    src.pixels[4 * 33 + 1] = nan_value;
    CHECK(tt_make_texture_patch(&src, NULL, &opt, &patch, &err) == TT_ERROR_NON_FINITE, "NaN source");
    CHECK(strstr(err.message, "(1, 1)") != NULL, "NaN source names the texel: %s", err.message);
    CHECK(patch.pixels == NULL, "patch left empty on error");
    tt_image_free(&src);
}

typedef struct patch_oom_ctx {
    const tt_image *source, *mask;
    uint64_t seed;
} patch_oom_ctx;

static tt_result patch_oom_call(void *ctx, const tt_allocator *al)
{
    patch_oom_ctx *c = (patch_oom_ctx *)ctx;
    tt_patch_options opt;
    tt_image patch;
    tt_error err;
    tt_result r;
    memset(&opt, 0, sizeof opt);
    opt.seed = c->seed;
    opt.allocator = *al;
    r = tt_make_texture_patch(c->source, c->mask, &opt, &patch, &err);
    if (r != TT_OK && (patch.pixels != NULL || err.result != r)) return TT_RESULT_MAX_ENUM;
    tt_image_free(&patch);
    return r;
}

static void test_patch_oom(void)
{
    tt_image src, mask;
    patch_oom_ctx c;
    int i;
    patch_source(&src, 24, 20);
    tt_image_create(&mask, 24, 20, NULL);
    for (i = 0; i < 24 * 20; i++) mask.pixels[4 * i + 3] = (i % 24 > 4 && i % 24 < 20) ? 1.0f : 0.0f;
    oom_reset();
    c.source = &src;
    c.mask = NULL;
    c.seed = 3;
    oom_sweep("tt_make_texture_patch(splotch)", patch_oom_call, &c, TT_OK);
    c.mask = &mask;
    oom_sweep("tt_make_texture_patch(mask)", patch_oom_call, &c, TT_OK);
    memset(mask.pixels, 0, sizeof(float) * 4 * 24 * 20);
    oom_sweep("tt_make_texture_patch(empty mask)", patch_oom_call, &c, TT_ERROR_INVALID_ARGUMENT);
    tt_image_free(&mask);
    tt_image_free(&src);
}

/* ------------------------------------------------------------------------ */
/* Lapped textures: the paste loop                                           */
/* ------------------------------------------------------------------------ */

/* The mesh with every polygon split into a fan of triangles. */
static void tm_triangulate(const tmesh *in, tmesh *out)
{
    int f, c = 0, i;
    memset(out, 0, sizeof *out);
    for (i = 0; i < in->nv; i++) tm_vert(out, in->pos[3 * i], in->pos[3 * i + 1], in->pos[3 * i + 2]);
    for (f = 0; f < in->nf; f++) {
        for (i = 1; i + 1 < in->sizes[f]; i++) tm_tri(out, in->idx[c], in->idx[c + i], in->idx[c + i + 1]);
        c += in->sizes[f];
    }
}

/* The test shapes of the lapped tests, all triangles: a sphere (closed), a
   wavy open sheet, two spheres (two components), a torus (genus 1). */
static void make_lapped_shape(tmesh *out, int which)
{
    tmesh m;
    int i;
    memset(&m, 0, sizeof m);
    if (which == 0) make_field_sphere(&m, 12, 16, 1.0);
    else if (which == 1) {
        make_grid(&m, 16, 12);
        for (i = 0; i < m.nv; i++) m.pos[3 * i + 2] = (float)(0.8 * sin(0.35 * m.pos[3 * i]));
    } else if (which == 2) {
        make_field_sphere(&m, 8, 10, 1.0);
        make_field_sphere(&m, 8, 10, 0.5);
        for (i = m.nv / 2; i < m.nv; i++) m.pos[3 * i] += 3.0f;
    } else make_torus(&m, 24, 10, 2.0, 0.7);
    tm_triangulate(&m, out);
    tm_free(&m);
}

static const char *const LAPPED_SHAPE_NAMES[4] = {"sphere", "open sheet", "two spheres", "torus"};

/* A texture patch from value noise with a seeded splotch. */
static void lapped_patch(tt_image *patch, int size, unsigned seed)
{
    tt_image src;
    tt_patch_options po;
    tt_error err;
    make_value_noise(&src, size, size, seed);
    memset(&po, 0, sizeof po);
    po.seed = seed;
    memset(patch, 0, sizeof *patch);
    tt_make_texture_patch(&src, NULL, &po, patch, &err);
    tt_image_free(&src);
}

/* Composite alpha of every entry of face f at barycentric point w, the
   pastes drawn in order with "over", recomputed from the output alone. */
static double lapped_alpha_at(const tt_lapped *lapped, const tt_image *patches, int f, const double w[3])
{
    double alpha = 0.0;
    int p, e;
    for (p = 0; p < lapped->npastes; p++)
        for (e = lapped->pastes[p].first; e < lapped->pastes[p].first + lapped->pastes[p].nfaces; e++) {
            const float *uv = lapped->uv + 6 * (size_t)e;
            const tt_image *im = &patches[lapped->pastes[p].patch];
            float rgba[4];
            double u, v;
            if (lapped->faces[e] != f) continue;
            u = w[0] * uv[0] + w[1] * uv[2] + w[2] * uv[4];
            v = w[0] * uv[1] + w[1] * uv[3] + w[2] * uv[5];
            tt_image_sample_bilinear(im, (float)(u * im->width), (float)((1.0 - v) * im->height), rgba);
            alpha = rgba[3] + alpha * (1.0 - rgba[3]);
        }
    return alpha;
}

/* Angle error (degrees) of entry e: T_f pushed through the entry's UV map,
   against (0, 1); and the length of the image. Independent of the library. */
static void lapped_entry_error(const tt_mesh *mesh, const float *field, const tt_lapped *lapped, int e,
                               double *angle, double *length)
{
    int f = lapped->faces[e], k;
    const float *p0 = mesh->pos + 3 * mesh->corner_vert[3 * f], *p1 = mesh->pos + 3 * mesh->corner_vert[3 * f + 1];
    const float *p2 = mesh->pos + 3 * mesh->corner_vert[3 * f + 2], *uv = lapped->uv + 6 * (size_t)e;
    double e1[3], e2[3], t[3], g11 = 0, g12 = 0, g22 = 0, r1 = 0, r2 = 0, det, a, b, pu, pv;
    for (k = 0; k < 3; k++) {
        e1[k] = (double)p1[k] - p0[k];
        e2[k] = (double)p2[k] - p0[k];
        t[k] = field[3 * f + k];
        g11 += e1[k] * e1[k]; g12 += e1[k] * e2[k]; g22 += e2[k] * e2[k];
        r1 += e1[k] * t[k]; r2 += e2[k] * t[k];
    }
    det = g11 * g22 - g12 * g12;
    a = (g22 * r1 - g12 * r2) / det;
    b = (g11 * r2 - g12 * r1) / det;
    pu = a * (uv[2] - uv[0]) + b * (uv[4] - uv[0]);
    pv = a * (uv[3] - uv[1]) + b * (uv[5] - uv[1]);
    *length = sqrt(pu * pu + pv * pv);
    *angle = fabs(atan2(pu, pv)) * 180.0 / 3.14159265358979323846;
}

static int lapped_run(const tmesh *m, int isotropic, uint64_t seed, float scale, tt_mesh **mesh, float **field,
                      tt_image *patch, tt_lapped *out)
{
    tt_mesh_desc d = tm_desc(m);
    tt_field_options fo;
    tt_lapped_options lo;
    tt_error err;
    tt_result r;
    *mesh = NULL;
    *field = NULL;
    memset(out, 0, sizeof *out);
    if (tt_mesh_build(&d, mesh, &err) != TT_OK) return -1;
    *field = (float *)malloc(sizeof(float) * 3 * (size_t)(*mesh)->nfaces);
    memset(&fo, 0, sizeof fo);
    fo.scale = scale;
    if (tt_tangent_field(*mesh, &fo, *field, &err) != TT_OK) return -1;
    memset(&lo, 0, sizeof lo);
    lo.seed = seed;
    lo.isotropic = isotropic;
    r = tt_lapped_paste(*mesh, *field, patch, 1, &lo, out, &err);
    CHECK(r == TT_OK, "tt_lapped_paste: %d %s", r, err.message);
    return r == TT_OK ? 0 : -1;
}

static void test_lapped_cover(void)
{
    tt_image patch;
    int shape, iso;
    lapped_patch(&patch, 64, 5);
    for (shape = 0; shape < 4; shape++)
        for (iso = 0; iso < 2; iso++) {
            tmesh m;
            tt_mesh *mesh;
            float *field;
            tt_lapped lapped;
            double angle_sum = 0.0, worst_alpha = 1.0;
            int f, e, p, missing = 0, bad_points = 0, points = 0, bad_entries = 0, order_ok = 1;
            char *seen;
            make_lapped_shape(&m, shape);
            if (lapped_run(&m, iso, 11, 0.0f, &mesh, &field, &patch, &lapped) != 0) {
                tt_mesh_free(mesh);
                free(field);
                tm_free(&m);
                continue;
            }
            seen = (char *)calloc((size_t)mesh->nfaces, 1);
            for (p = 0; p < lapped.npastes; p++) {
                order_ok &= lapped.pastes[p].first == (p ? lapped.pastes[p - 1].first + lapped.pastes[p - 1].nfaces : 0);
                order_ok &= lapped.pastes[p].nfaces > 0 && lapped.pastes[p].patch == 0;
            }
            CHECK(order_ok && lapped.npastes > 0, "%s: pastes are not consecutive runs of entries",
                  LAPPED_SHAPE_NAMES[shape]);
            CHECK(lapped.npastes == 0 ||
                      lapped.pastes[lapped.npastes - 1].first + lapped.pastes[lapped.npastes - 1].nfaces ==
                          lapped.nentries,
                  "%s: the pastes do not account for every entry", LAPPED_SHAPE_NAMES[shape]);
            for (e = 0; e < lapped.nentries; e++) {
                double angle, length;
                int k;
                if (lapped.faces[e] < 0 || lapped.faces[e] >= mesh->nfaces) { bad_entries++; continue; }
                seen[lapped.faces[e]] = 1;
                for (k = 0; k < 6; k++) bad_entries += !isfinite(lapped.uv[6 * e + k]);
                lapped_entry_error(mesh, field, &lapped, e, &angle, &length);
                angle_sum += angle;
            }
            for (f = 0; f < mesh->nfaces; f++) missing += !seen[f];
            CHECK(bad_entries == 0, "%s: %d entries with a bad face or UV", LAPPED_SHAPE_NAMES[shape], bad_entries);
            CHECK(missing == 0, "%s (isotropic %d): %d faces in no paste", LAPPED_SHAPE_NAMES[shape], iso, missing);
            CHECK(lapped.coverage == 1.0, "%s: coverage %g", LAPPED_SHAPE_NAMES[shape], lapped.coverage);
            CHECK(near(lapped.mean_overdraw, (double)lapped.nentries / mesh->nfaces, 1e-12),
                  "%s: mean overdraw %g != entries / faces", LAPPED_SHAPE_NAMES[shape], lapped.mean_overdraw);
            CHECK(lapped.mean_overdraw >= 1.0 && lapped.mean_overdraw < 12.0, "%s: overdraw %g",
                  LAPPED_SHAPE_NAMES[shape], lapped.mean_overdraw);
            /* Coverage seen from the output alone: random points of every
               face, every paste composited in order, are opaque. */
            lcg_seed(77);
            for (f = 0; f < mesh->nfaces; f++) {
                int s;
                for (s = 0; s < 12; s++) {
                    double w[3], a = lcg_unit(), b = lcg_unit(), alpha;
                    if (a + b > 1.0) { a = 1.0 - a; b = 1.0 - b; }
                    w[0] = 1.0 - a - b; w[1] = a; w[2] = b;
                    alpha = lapped_alpha_at(&lapped, &patch, f, w);
                    points++;
                    if (alpha < 0.98) bad_points++;
                    if (alpha < worst_alpha) worst_alpha = alpha;
                }
            }
            CHECK(bad_points <= points / 500, "%s (isotropic %d): %d of %d random points are not opaque (worst alpha %g)",
                  LAPPED_SHAPE_NAMES[shape], iso, bad_points, points, worst_alpha);
            if (!iso && lapped.nentries > 0) {
                CHECK(near(angle_sum / lapped.nentries, lapped.mean_angle_error, 1e-3),
                      "%s: reported mean angle %g, measured from the UVs %g", LAPPED_SHAPE_NAMES[shape],
                      lapped.mean_angle_error, angle_sum / lapped.nentries);
                CHECK(lapped.mean_angle_error <= 8.0, "%s: mean angle error %g deg", LAPPED_SHAPE_NAMES[shape],
                      lapped.mean_angle_error);
            }
            CHECK(lapped.median_scale_error <= 0.1, "%s (isotropic %d): median scale error %g",
                  LAPPED_SHAPE_NAMES[shape], iso, lapped.median_scale_error);
            free(seen);
            tt_lapped_free(&lapped);
            tt_mesh_free(mesh);
            free(field);
            tm_free(&m);
        }
    tt_image_free(&patch);
}

/* A flat sheet with a constant field: the optimum maps every face exactly
   (phi(S) = (1,0), phi(T) = (0,1)), so the error is 0 up to rounding. */
static void test_lapped_plane(void)
{
    tmesh g, m;
    tt_mesh *mesh;
    float *field;
    tt_image patch;
    tt_lapped lapped;
    int e;
    double worst = 0.0, worst_len = 0.0;
    memset(&g, 0, sizeof g);
    make_grid(&g, 20, 20);
    tm_triangulate(&g, &m);
    lapped_patch(&patch, 48, 9);
    if (lapped_run(&m, 0, 3, 4.0f, &mesh, &field, &patch, &lapped) == 0) {
        for (e = 0; e < lapped.nentries; e++) {
            double angle, length;
            lapped_entry_error(mesh, field, &lapped, e, &angle, &length);
            if (angle > worst) worst = angle;
            if (fabs(length - 1.0) > worst_len) worst_len = fabs(length - 1.0);
        }
        CHECK(worst < 1e-3 && worst_len < 1e-4, "plane: worst angle %g deg, worst scale error %g", worst, worst_len);
        CHECK(lapped.mean_angle_error < 1e-3 && lapped.median_scale_error < 1e-4, "plane: reported %g deg, %g",
              lapped.mean_angle_error, lapped.median_scale_error);
        /* a 20 x 20 sheet with 4-unit patches needs a few dozen pastes */
        CHECK(lapped.npastes >= 20 && lapped.npastes <= 400, "plane: %d pastes", lapped.npastes);
    }
    tt_lapped_free(&lapped);
    tt_mesh_free(mesh);
    free(field);
    tm_free(&m);
    tm_free(&g);
    tt_image_free(&patch);
}

static void test_lapped_determinism(void)
{
    tmesh m;
    tt_mesh *mesh[3];
    float *field[3];
    tt_image patch;
    tt_lapped out[3];
    int i, same, differ;
    make_lapped_shape(&m, 3);
    lapped_patch(&patch, 48, 2);
    for (i = 0; i < 3; i++) lapped_run(&m, 0, i == 2 ? 8 : 7, 0.0f, &mesh[i], &field[i], &patch, &out[i]);
    same = out[0].nentries == out[1].nentries && out[0].npastes == out[1].npastes &&
           memcmp(out[0].faces, out[1].faces, sizeof(int) * (size_t)out[0].nentries) == 0 &&
           memcmp(out[0].uv, out[1].uv, sizeof(float) * 6 * (size_t)out[0].nentries) == 0;
    differ = out[0].nentries != out[2].nentries ||
             memcmp(out[0].uv, out[2].uv, sizeof(float) * 6 * (size_t)(out[0].nentries < out[2].nentries ? out[0].nentries : out[2].nentries)) != 0;
    CHECK(same, "the same seed gave different pastes");
    CHECK(differ, "different seeds gave the same pastes");
    for (i = 0; i < 3; i++) {
        tt_lapped_free(&out[i]);
        tt_mesh_free(mesh[i]);
        free(field[i]);
    }
    tm_free(&m);
    tt_image_free(&patch);
}

/* Several texture patches: each paste picks one at random, all get used,
   and the mesh is covered with the right patch's alpha. */
static void test_lapped_patches(void)
{
    tmesh m;
    tt_mesh *mesh;
    tt_mesh_desc d;
    tt_field_options fo;
    tt_lapped_options lo;
    tt_lapped out;
    tt_error err;
    tt_image patches[3];
    float *field;
    int used[3] = {0, 0, 0}, p, f, bad = 0;
    tt_result r;
    make_lapped_shape(&m, 0);
    d = tm_desc(&m);
    tt_mesh_build(&d, &mesh, &err);
    field = (float *)malloc(sizeof(float) * 3 * (size_t)mesh->nfaces);
    memset(&fo, 0, sizeof fo);
    tt_tangent_field(mesh, &fo, field, &err);
    lapped_patch(&patches[0], 48, 1);
    lapped_patch(&patches[1], 64, 2);
    lapped_patch(&patches[2], 40, 3);
    memset(&lo, 0, sizeof lo);
    lo.seed = 5;
    r = tt_lapped_paste(mesh, field, patches, 3, &lo, &out, &err);
    CHECK(r == TT_OK, "three patches: %d %s", r, err.message);
    for (p = 0; p < out.npastes; p++)
        if (out.pastes[p].patch >= 0 && out.pastes[p].patch < 3) used[out.pastes[p].patch]++;
        else bad++;
    CHECK(bad == 0 && used[0] > 0 && used[1] > 0 && used[2] > 0, "patches used %d %d %d, %d out of range", used[0],
          used[1], used[2], bad);
    for (f = 0; f < mesh->nfaces; f++) {
        double w[3] = {1.0 / 3.0, 1.0 / 3.0, 1.0 / 3.0};
        if (lapped_alpha_at(&out, patches, f, w) < 0.98) bad++;
    }
    CHECK(bad == 0, "three patches: %d face centres not opaque", bad);
    tt_lapped_free(&out);
    for (p = 0; p < 3; p++) tt_image_free(&patches[p]);
    tt_mesh_free(mesh);
    free(field);
    tm_free(&m);
}

typedef struct lapped_progress {
    int calls, cancel_at;
    float last;
    int decreasing;
} lapped_progress;

static int lapped_progress_fn(float fraction, void *user_data)
{
    lapped_progress *p = (lapped_progress *)user_data;
    if (fraction < p->last || fraction > 1.0f) p->decreasing = 1;
    p->last = fraction;
    return ++p->calls == p->cancel_at;
}

static void test_lapped_errors(void)
{
    tmesh m, q;
    tt_mesh *mesh = NULL, *quads = NULL;
    tt_mesh_desc d;
    float *field;
    tt_image patch, empty, clear;
    tt_lapped out;
    tt_lapped_options lo;
    tt_field_options fo;
    tt_error err;
    tt_result r;
    lapped_progress prog;
    make_lapped_shape(&m, 0);
    d = tm_desc(&m);
    tt_mesh_build(&d, &mesh, &err);
    field = (float *)malloc(sizeof(float) * 3 * (size_t)mesh->nfaces);
    memset(&fo, 0, sizeof fo);
    tt_tangent_field(mesh, &fo, field, &err);
    lapped_patch(&patch, 32, 1);
    memset(&empty, 0, sizeof empty);
    tt_image_create(&clear, 16, 16, NULL);
    memset(&lo, 0, sizeof lo);

    CHECK(tt_lapped_paste(NULL, field, &patch, 1, NULL, &out, &err) == TT_ERROR_INVALID_ARGUMENT, "NULL mesh");
    CHECK(tt_lapped_paste(mesh, NULL, &patch, 1, NULL, &out, &err) == TT_ERROR_INVALID_ARGUMENT, "NULL field");
    CHECK(tt_lapped_paste(mesh, field, &patch, 0, NULL, &out, &err) == TT_ERROR_INVALID_ARGUMENT, "no patches");
    CHECK(tt_lapped_paste(mesh, field, &empty, 1, NULL, &out, &err) == TT_ERROR_INVALID_ARGUMENT &&
              out.pastes == NULL, "empty patch");
    r = tt_lapped_paste(mesh, field, &clear, 1, NULL, &out, &err);
    CHECK(r == TT_ERROR_INVALID_ARGUMENT && strstr(err.message, "no opaque") != NULL,
          "transparent patch: %d %s", r, err.message);
    lo.max_pastes = -1;
    CHECK(tt_lapped_paste(mesh, field, &patch, 1, &lo, &out, &err) == TT_ERROR_INVALID_ARGUMENT, "max_pastes < 0");

    /* field vectors: zero, NaN, perpendicular to the face */
    {
        float saved[3];
        memcpy(saved, field + 3 * 5, sizeof saved);
        field[15] = field[16] = field[17] = 0.0f;
        r = tt_lapped_paste(mesh, field, &patch, 1, NULL, &out, &err);
        CHECK(r == TT_ERROR_INVALID_ARGUMENT && err.face == 5 && strstr(err.message, "zero length"),
              "zero field vector: %d %d %s", r, err.face, err.message);
        field[16] = NAN;
        r = tt_lapped_paste(mesh, field, &patch, 1, NULL, &out, &err);
        CHECK(r == TT_ERROR_NON_FINITE && err.face == 5, "NaN field vector: %d %s", r, err.message);
        tt_face_normal(mesh, 5, field + 15);
        r = tt_lapped_paste(mesh, field, &patch, 1, NULL, &out, &err);
        CHECK(r == TT_ERROR_INVALID_ARGUMENT && err.face == 5 && strstr(err.message, "perpendicular"),
              "normal as field vector: %d %s", r, err.message);
        memcpy(field + 15, saved, sizeof saved);
    }
    /* a patch larger than the mesh, and one so small it would take forever */
    {
        float *big = (float *)malloc(sizeof(float) * 3 * (size_t)mesh->nfaces);
        fo.scale = 5.0f;
        tt_tangent_field(mesh, &fo, big, &err);
        r = tt_lapped_paste(mesh, big, &patch, 1, NULL, &out, &err);
        CHECK(r == TT_ERROR_INVALID_ARGUMENT && strstr(err.message, "larger than the mesh"),
              "patch larger than the mesh: %d %s", r, err.message);
        fo.scale = 1e-4f;
        tt_tangent_field(mesh, &fo, big, &err);
        r = tt_lapped_paste(mesh, big, &patch, 1, NULL, &out, &err);
        CHECK(r == TT_ERROR_TOO_LARGE && strstr(err.message, "pastes"), "tiny patches: %d %s", r, err.message);
        free(big);
    }
    /* progress after every paste, never decreasing, ending at 1 */
    lo.max_pastes = 0;
    memset(&prog, 0, sizeof prog);
    prog.cancel_at = -1;
    lo.progress = lapped_progress_fn;
    lo.progress_user_data = &prog;
    r = tt_lapped_paste(mesh, field, &patch, 1, &lo, &out, &err);
    CHECK(r == TT_OK && prog.calls >= out.npastes && !prog.decreasing && prog.last == 1.0f,
          "progress: %d calls for %d pastes, last %g, decreasing %d", prog.calls, out.npastes, prog.last,
          prog.decreasing);
    tt_lapped_free(&out);
    /* one paste short of what it takes */
    lo.max_pastes = prog.calls - 1;
    r = tt_lapped_paste(mesh, field, &patch, 1, &lo, &out, &err);
    CHECK(r == TT_ERROR_NOT_CONVERGED && out.pastes == NULL && strstr(err.message, "uncovered"),
          "max_pastes %d: %d %s", lo.max_pastes, r, err.message);
    lo.max_pastes = 0;
    memset(&prog, 0, sizeof prog);
    prog.cancel_at = 3;
    r = tt_lapped_paste(mesh, field, &patch, 1, &lo, &out, &err);
    CHECK(r == TT_CANCELLED && prog.calls == 3 && out.pastes == NULL, "cancel: %d after %d calls", r, prog.calls);

    /* not triangles */
    memset(&q, 0, sizeof q);
    make_grid(&q, 3, 3);
    d = tm_desc(&q);
    tt_mesh_build(&d, &quads, &err);
    {
        float *qf = (float *)malloc(sizeof(float) * 3 * (size_t)quads->nfaces);
        tt_tangent_field(quads, &fo, qf, &err);
        r = tt_lapped_paste(quads, qf, &patch, 1, NULL, &out, &err);
        CHECK(r == TT_ERROR_INVALID_ARGUMENT && err.face == 0 && strstr(err.message, "triangle"),
              "quads: %d %s", r, err.message);
        free(qf);
    }
    tt_mesh_free(quads);
    tm_free(&q);

    /* a zero-area face (permissive mesh) */
    {
        tmesh z;
        tt_mesh *zm = NULL;
        float zf[9] = {0, 1, 0, 0, 1, 0, 0, 1, 0};
        memset(&z, 0, sizeof z);
        tm_vert(&z, 0, 0, 0); tm_vert(&z, 1, 0, 0); tm_vert(&z, 0, 1, 0); tm_vert(&z, 2, 0, 0);
        tm_tri(&z, 0, 1, 2);
        tm_tri(&z, 1, 0, 3);
        d = tm_desc(&z);
        d.nfaces = 2;
        d.flags = TT_MESH_PERMISSIVE;
        if (tt_mesh_build(&d, &zm, &err) == TT_OK) {
            r = tt_lapped_paste(zm, zf, &patch, 1, NULL, &out, &err);
            CHECK(r == TT_ERROR_ZERO_AREA_FACE && err.face == 1, "zero-area face: %d %s", r, err.message);
        }
        tt_mesh_free(zm);
        tm_free(&z);
    }
    tt_image_free(&clear);
    tt_image_free(&patch);
    tt_mesh_free(mesh);
    free(field);
    tm_free(&m);
}

typedef struct lapped_oom_ctx {
    const tt_mesh *mesh;
    const float *field;
    const tt_image *patch;
    int isotropic;
} lapped_oom_ctx;

static tt_result lapped_oom_call(void *ctx, const tt_allocator *al)
{
    lapped_oom_ctx *c = (lapped_oom_ctx *)ctx;
    tt_lapped_options lo;
    tt_lapped out;
    tt_error err;
    tt_result r;
    memset(&lo, 0, sizeof lo);
    lo.allocator = *al;
    lo.isotropic = c->isotropic;
    r = tt_lapped_paste(c->mesh, c->field, c->patch, 1, &lo, &out, &err);
    if (r != TT_OK && (out.pastes != NULL || err.result != r)) return TT_RESULT_MAX_ENUM;
    tt_lapped_free(&out);
    return r;
}

static void test_lapped_oom(void)
{
    tmesh m;
    tt_mesh *mesh;
    tt_mesh_desc d;
    tt_field_options fo;
    tt_error err;
    float *field;
    tt_image patch;
    lapped_oom_ctx c;
    memset(&m, 0, sizeof m);
    make_field_sphere(&m, 5, 6, 1.0);
    {
        tmesh t;
        tm_triangulate(&m, &t);
        tm_free(&m);
        m = t;
    }
    d = tm_desc(&m);
    tt_mesh_build(&d, &mesh, &err);
    field = (float *)malloc(sizeof(float) * 3 * (size_t)mesh->nfaces);
    memset(&fo, 0, sizeof fo);
    fo.scale = 2.0f;
    tt_tangent_field(mesh, &fo, field, &err);
    lapped_patch(&patch, 32, 4);
    oom_reset();
    c.mesh = mesh;
    c.field = field;
    c.patch = &patch;
    c.isotropic = 0;
    oom_sweep("tt_lapped_paste", lapped_oom_call, &c, TT_OK);
    c.isotropic = 1;
    oom_sweep("tt_lapped_paste(isotropic)", lapped_oom_call, &c, TT_OK);
    tt_image_free(&patch);
    tt_mesh_free(mesh);
    free(field);
    tm_free(&m);
}

/* ------------------------------------------------------------------------ */
/* Patch hulls (Sec. 3.3, Fig. 4)                                            */
/* ------------------------------------------------------------------------ */

/* A transparent w x h image. */
static tt_image hull_image(int w, int h)
{
    tt_image img;
    tt_result r = tt_image_create(&img, w, h, NULL);
    CHECK(r == TT_OK, "tt_image_create(%d, %d): %d", w, h, (int)r);
    return img;
}

static void hull_set_alpha(tt_image *img, int i, int j, float a)
{
    if (i < 0 || j < 0 || i >= img->width || j >= img->height) return;
    img->pixels[4 * (j * img->width + i) + 3] = a;
}

static float hull_alpha(const tt_image *img, int i, int j) { return img->pixels[4 * (j * img->width + i) + 3]; }

static void hull_disc(tt_image *img, double cx, double cy, double r, float a)
{
    int i, j;
    for (j = 0; j < img->height; j++)
        for (i = 0; i < img->width; i++) {
            double dx = i + 0.5 - cx, dy = j + 0.5 - cy;
            if (dx * dx + dy * dy <= r * r) hull_set_alpha(img, i, j, a);
        }
}

static void hull_rect(tt_image *img, int i0, int j0, int i1, int j1)
{
    int i, j;
    for (j = j0; j < j1; j++)
        for (i = i0; i < i1; i++) hull_set_alpha(img, i, j, 1.0f);
}

/* 4-connected random growth from the centre: one irregular component. */
static void hull_blob(tt_image *img, int cells)
{
    int n = 1, k;
    int *list = (int *)malloc(sizeof(int) * (size_t)(cells + 1));
    list[0] = (img->height / 2) * img->width + img->width / 2;
    hull_set_alpha(img, img->width / 2, img->height / 2, 1.0f);
    for (k = 0; k < cells * 20 && n < cells; k++) {
        int c = list[lcg_below(n)], d = lcg_below(4);
        int i = c % img->width + (d == 0) - (d == 1), j = c / img->width + (d == 2) - (d == 3);
        if (i < 0 || j < 0 || i >= img->width || j >= img->height || hull_alpha(img, i, j) > 0.0f) continue;
        hull_set_alpha(img, i, j, 0.5f);
        list[n++] = j * img->width + i;
    }
    free(list);
}

/* Keep only the texels 8-connected to the centre (the splotch itself, not
   the specks its ragged rim throws off). */
static void hull_keep_centre(tt_image *img)
{
    int w = img->width, h = img->height, top = 0, k;
    unsigned char *seen = (unsigned char *)calloc((size_t)(w * h), 1);
    int *stack = (int *)malloc(sizeof(int) * (size_t)(w * h));
    stack[top++] = (h / 2) * w + w / 2;
    seen[stack[0]] = 1;
    while (top > 0) {
        int c = stack[--top], i = c % w, j = c / w, di, dj;
        for (dj = -1; dj <= 1; dj++)
            for (di = -1; di <= 1; di++) {
                int ni = i + di, nj = j + dj;
                if (ni < 0 || nj < 0 || ni >= w || nj >= h || seen[nj * w + ni] || !(hull_alpha(img, ni, nj) > 0.0f))
                    continue;
                seen[nj * w + ni] = 1;
                stack[top++] = nj * w + ni;
            }
    }
    for (k = 0; k < w * h; k++)
        if (!seen[k]) img->pixels[4 * k + 3] = 0.0f;
    free(seen);
    free(stack);
}

/* A splotch: radius varying with angle plus a ragged rim; speckled keeps
   the specks the rim throws off (several components). */
static void hull_splotch(tt_image *img, double rough, int speckled)
{
    int i, j;
    double cx = img->width * 0.5, cy = img->height * 0.5, base = 0.38 * img->width;
    double ph1 = 6.283 * lcg_unit(), ph2 = 6.283 * lcg_unit(), ph3 = 6.283 * lcg_unit();
    for (j = 0; j < img->height; j++)
        for (i = 0; i < img->width; i++) {
            double dx = i + 0.5 - cx, dy = j + 0.5 - cy, t = atan2(dy, dx);
            double r = base * (1.0 + 0.12 * sin(3 * t + ph1) + 0.06 * sin(7 * t + ph2) + 0.03 * sin(17 * t + ph3));
            r += rough * (lcg_unit() - 0.5);
            if (dx * dx + dy * dy <= r * r)
                hull_set_alpha(img, i, j, 1.0f - (float)sqrt(dx * dx + dy * dy) / (float)(r + 1));
        }
    if (!speckled) hull_keep_centre(img);
}

static double hull_polygon_area(const float *xy, int n)
{
    double a = 0.0;
    int k;
    for (k = 0; k < n; k++) {
        const float *p = xy + 2 * k, *q = xy + 2 * ((k + 1) % n);
        a += (double)p[0] * q[1] - (double)q[0] * p[1];
    }
    return 0.5 * a;
}

/* Closed segments ab and cd share a point. */
static int hull_segments_meet(const double *a, const double *b, const double *c, const double *d)
{
    double o1 = tt__orient2(a[0], a[1], b[0], b[1], c[0], c[1]), o2 = tt__orient2(a[0], a[1], b[0], b[1], d[0], d[1]);
    double o3 = tt__orient2(c[0], c[1], d[0], d[1], a[0], a[1]), o4 = tt__orient2(c[0], c[1], d[0], d[1], b[0], b[1]);
    if (((o1 > 0 && o2 < 0) || (o1 < 0 && o2 > 0)) && ((o3 > 0 && o4 < 0) || (o3 < 0 && o4 > 0))) return 1;
    return tt__point_on_segment(c[0], c[1], a[0], a[1], b[0], b[1]) ||
           tt__point_on_segment(d[0], d[1], a[0], a[1], b[0], b[1]) ||
           tt__point_on_segment(a[0], a[1], c[0], c[1], d[0], d[1]) ||
           tt__point_on_segment(b[0], b[1], c[0], c[1], d[0], d[1]);
}

/* Simple: no two non-adjacent edges meet, adjacent ones share only their
   common vertex, no repeated consecutive vertex. */
static int hull_is_simple(const float *xy, int n)
{
    int i, j;
    for (i = 0; i < n; i++) {
        double a[2], b[2];
        a[0] = xy[2 * i]; a[1] = xy[2 * i + 1];
        b[0] = xy[2 * ((i + 1) % n)]; b[1] = xy[2 * ((i + 1) % n) + 1];
        if (a[0] == b[0] && a[1] == b[1]) return 0;
        for (j = i + 1; j < n; j++) {
            double c[2], d[2];
            c[0] = xy[2 * j]; c[1] = xy[2 * j + 1];
            d[0] = xy[2 * ((j + 1) % n)]; d[1] = xy[2 * ((j + 1) % n) + 1];
            if (j == i + 1) {
                /* shares b == c: the far ends must not lie on the other edge */
                if (tt__point_on_segment(d[0], d[1], a[0], a[1], b[0], b[1]) ||
                    tt__point_on_segment(a[0], a[1], c[0], c[1], d[0], d[1]))
                    return 0;
            } else if ((j + 1) % n == i) {
                if (tt__point_on_segment(c[0], c[1], a[0], a[1], b[0], b[1]) ||
                    tt__point_on_segment(b[0], b[1], c[0], c[1], d[0], d[1]))
                    return 0;
            } else if (hull_segments_meet(a, b, c, d)) {
                return 0;
            }
        }
    }
    return 1;
}

/* Inside the polygon (winding number) or within eps of its boundary. */
static int hull_inside_or_near(double x, double y, const float *xy, int n, double eps)
{
    int k, winding = 0;
    for (k = 0; k < n; k++) {
        const float *a = xy + 2 * k, *b = xy + 2 * ((k + 1) % n);
        double o = tt__orient2(a[0], a[1], b[0], b[1], x, y);
        if (tt__point_segment_distance(x, y, a[0], a[1], b[0], b[1]) <= eps) return 1;
        if (a[1] <= y && b[1] > y && o > 0.0) winding++;
        else if (a[1] > y && b[1] <= y && o < 0.0) winding--;
    }
    return winding != 0;
}

/* Area of the convex hull of the nonzero texel squares (unit square). */
static double hull_convex_area(const tt_image *img)
{
    double *xs, *ys, area = 0.0;
    int n, k;
    if (tt__hull_convex(img, NULL, &xs, &ys, &n) != TT_OK) return -1.0;
    for (k = 0; k < n; k++) area += xs[k] * ys[(k + 1) % n] - xs[(k + 1) % n] * ys[k];
    free(xs);
    free(ys);
    return 0.5 * area / ((double)img->width * img->height);
}

static double hull_mask_area(const tt_image *img)
{
    int i, j, c = 0;
    for (j = 0; j < img->height; j++)
        for (i = 0; i < img->width; i++) c += hull_alpha(img, i, j) > 0.0f;
    return (double)c / ((double)img->width * img->height);
}

/* tt__patch_hull of img with a vertex budget: OK, 3..max vertices, simple,
   counter-clockwise and containing every texel with alpha > 0 (all four
   corners of its square, in the unit square with v up). Returns the area. */
static double hull_check(const tt_image *img, int max_vertices, const char *name)
{
    float *xy = NULL;
    int n = 0, i, j, covered = 1, bad_i = -1, bad_j = -1;
    double area;
    tt_result r = tt__patch_hull(img, max_vertices, NULL, &xy, &n);
    CHECK(r == TT_OK, "%s, max %d vertices: result %d", name, max_vertices, (int)r);
    if (r != TT_OK) return 0.0;
    CHECK(n >= 3 && n <= max_vertices, "%s: %d vertices for max %d", name, n, max_vertices);
    CHECK(hull_is_simple(xy, n), "%s, max %d: polygon not simple", name, max_vertices);
    area = hull_polygon_area(xy, n);
    CHECK(area > 0.0, "%s, max %d: counter-clockwise (positive signed area), got %g", name, max_vertices, area);
    for (j = 0; j < img->height && covered; j++)
        for (i = 0; i < img->width && covered; i++) {
            double x0 = (double)i / img->width, x1 = (double)(i + 1) / img->width;
            double y0 = 1.0 - (double)(j + 1) / img->height, y1 = 1.0 - (double)j / img->height;
            if (!(hull_alpha(img, i, j) > 0.0f)) continue;
            if (!hull_inside_or_near(x0, y0, xy, n, 1e-6) || !hull_inside_or_near(x1, y0, xy, n, 1e-6) ||
                !hull_inside_or_near(x0, y1, xy, n, 1e-6) || !hull_inside_or_near(x1, y1, xy, n, 1e-6)) {
                covered = 0;
                bad_i = i;
                bad_j = j;
            }
        }
    CHECK(covered, "%s, max %d: texel (%d, %d) not inside the hull", name, max_vertices, bad_i, bad_j);
    free(xy);
    return area;
}

static void hull_check_budgets(const tt_image *img, const char *name)
{
    static const int budgets[4] = {3, 4, 8, 32};
    int b;
    for (b = 0; b < 4; b++) hull_check(img, budgets[b], name);
}

static void test_hull_shapes(void)
{
    char name[64];
    int s;
    tt_image img;
    lcg_seed(1234);

    img = hull_image(64, 64); hull_disc(&img, 32, 32, 25, 1.0f); hull_check_budgets(&img, "disc"); tt_image_free(&img);
    img = hull_image(40, 30); hull_rect(&img, 5, 5, 15, 25); hull_rect(&img, 5, 18, 35, 25);
    hull_check_budgets(&img, "L"); tt_image_free(&img);
    img = hull_image(50, 50); hull_disc(&img, 25, 25, 20, 1.0f); hull_disc(&img, 25, 25, 10, 0.0f);
    hull_check_budgets(&img, "ring"); tt_image_free(&img);
    img = hull_image(50, 50); hull_disc(&img, 25, 25, 20, 1.0f); hull_disc(&img, 25, 25, 10, 0.0f);
    hull_disc(&img, 25, 25, 4, 1.0f); hull_check_budgets(&img, "ring with island"); tt_image_free(&img);
    img = hull_image(60, 40); hull_disc(&img, 12, 12, 8, 1.0f); hull_disc(&img, 45, 28, 9, 1.0f);
    hull_check_budgets(&img, "two blobs"); tt_image_free(&img);
    img = hull_image(32, 32); hull_rect(&img, 0, 0, 32, 32); hull_check_budgets(&img, "full square"); tt_image_free(&img);
    img = hull_image(1, 1); hull_set_alpha(&img, 0, 0, 1.0f); hull_check_budgets(&img, "1x1"); tt_image_free(&img);
    img = hull_image(9, 7); hull_set_alpha(&img, 4, 2, 0.1f); hull_check_budgets(&img, "single texel");
    tt_image_free(&img);
    img = hull_image(40, 40);
    for (s = 3; s < 37; s++) hull_set_alpha(&img, s, s, 1.0f);
    hull_check_budgets(&img, "diagonal"); tt_image_free(&img);
    img = hull_image(40, 40);
    for (s = 3; s < 37; s++) hull_set_alpha(&img, s, 39 - s, 1.0f);
    hull_check_budgets(&img, "anti-diagonal"); tt_image_free(&img);
    img = hull_image(40, 40);
    for (s = 0; s < 40; s++) hull_set_alpha(&img, s, (s * 7) % 40 < 20 ? s / 2 : 39 - s / 3, 1.0f);
    hull_check_budgets(&img, "scattered line"); tt_image_free(&img);
    img = hull_image(1, 37); hull_rect(&img, 0, 3, 1, 30); hull_check_budgets(&img, "1xN"); tt_image_free(&img);
    img = hull_image(37, 1); hull_rect(&img, 3, 0, 30, 1); hull_check_budgets(&img, "Nx1"); tt_image_free(&img);
    img = hull_image(1, 37); hull_rect(&img, 0, 3, 1, 10); hull_rect(&img, 0, 20, 1, 30);
    hull_check_budgets(&img, "1xN split"); tt_image_free(&img);
    img = hull_image(16, 16);
    for (s = 0; s < 256; s++)
        if (((s % 16) + (s / 16)) % 2 == 0) hull_set_alpha(&img, s % 16, s / 16, 1.0f);
    hull_check_budgets(&img, "checkerboard"); tt_image_free(&img);
    img = hull_image(60, 40); /* comb: deep narrow slots */
    hull_rect(&img, 2, 30, 58, 36);
    for (s = 2; s < 58; s += 4) hull_rect(&img, s, 3, s + 2, 30);
    hull_check_budgets(&img, "comb"); tt_image_free(&img);
    img = hull_image(64, 64); /* square spiral, one texel wide with one-texel gaps */
    {
        int x = 31, y = 31, len = 1, d = 0, k, step;
        for (k = 0; k < 58; k++) {
            for (step = 0; step < len; step++) {
                hull_set_alpha(&img, x, y, 1.0f);
                x += d == 0 ? 1 : (d == 2 ? -1 : 0);
                y += d == 1 ? 1 : (d == 3 ? -1 : 0);
            }
            d = (d + 1) & 3;
            if (k % 2 == 1) len += 2;
        }
    }
    hull_check_budgets(&img, "spiral"); tt_image_free(&img);

    for (s = 0; s < 40; s++) {
        int w = 8 + lcg_below(90), h = 8 + lcg_below(90);
        img = hull_image(w, h);
        hull_blob(&img, 1 + lcg_below(w * h / 3));
        sprintf(name, "blob %d (%dx%d)", s, w, h);
        hull_check_budgets(&img, name);
        tt_image_free(&img);
    }
    for (s = 0; s < 10; s++) {
        int k;
        img = hull_image(30, 30);
        for (k = 0; k < 900; k++)
            if (lcg_unit() < 0.3) hull_set_alpha(&img, k % 30, k / 30, 1.0f);
        sprintf(name, "noise %d", s);
        hull_check_budgets(&img, name);
        tt_image_free(&img);
    }
    for (s = 0; s < 6; s++) {
        img = hull_image(128, 128);
        hull_splotch(&img, s * 3.0, 0);
        sprintf(name, "splotch %d", s);
        hull_check_budgets(&img, name);
        tt_image_free(&img);
        img = hull_image(128, 128);
        hull_splotch(&img, s * 3.0, 1);
        sprintf(name, "speckled splotch %d", s);
        hull_check_budgets(&img, name);
        tt_image_free(&img);
    }
}

/* Large splotches (smooth, ragged, speckled) at 32 vertices. */
static void test_hull_large(void)
{
    static const char *const names[3] = {"smooth 512 splotch", "ragged 512 splotch", "speckled 512 splotch"};
    int kind;
    lcg_seed(77);
    for (kind = 0; kind < 3; kind++) {
        tt_image img = hull_image(512, 512);
        hull_splotch(&img, kind ? 24.0 : 0.0, kind == 2);
        hull_check(&img, 32, names[kind]);
        tt_image_free(&img);
    }
}

static void test_hull_area(void)
{
    tt_image img = hull_image(256, 256);
    double disc, convex, a32, a8;
    hull_disc(&img, 128, 128, 100, 1.0f);
    disc = 3.14159265358979 * 100.0 * 100.0 / (256.0 * 256.0);
    convex = hull_convex_area(&img);
    CHECK(convex > disc, "convex hull of the disc: area %g above the disc's %g", convex, disc);
    a32 = hull_check(&img, 32, "disc r=100");
    a8 = hull_check(&img, 8, "disc r=100");
    CHECK(a32 <= 1.3 * disc, "32-gon area %g within 1.3 x the disc's %g", a32, disc);
    CHECK(a32 <= 1.1 * convex, "32-gon area %g within 1.1 x the convex hull's %g", a32, convex);
    CHECK(a8 <= 1.3 * convex, "8-gon area %g within 1.3 x the convex hull's %g", a8, convex);
    tt_image_free(&img);

    img = hull_image(32, 32);
    hull_rect(&img, 4, 6, 20, 30);
    a32 = hull_check(&img, 4, "rectangle");
    CHECK(fabs(a32 - hull_mask_area(&img)) < 1e-6, "rectangle: hull is the rectangle, area %g vs %g", a32,
          hull_mask_area(&img));
    tt_image_free(&img);

    img = hull_image(64, 64);
    hull_rect(&img, 4, 4, 20, 60); hull_rect(&img, 4, 44, 60, 60);
    a32 = hull_check(&img, 32, "L exact");
    CHECK(a32 < 1.01 * hull_mask_area(&img), "L: hull area %g vs mask %g (should stay non-convex)", a32,
          hull_mask_area(&img));
    tt_image_free(&img);
}

/* Distance between segment ab and the polygon's boundary (0 if they meet). */
static double hull_segment_distance(const double *a, const double *b, const float *xy, int n)
{
    double best = 1e300;
    int k;
    for (k = 0; k < n; k++) {
        const float *c = xy + 2 * k, *d = xy + 2 * ((k + 1) % n);
        double dist[4];
        int i;
        if (tt__segments_near(a[0], a[1], b[0], b[1], c[0], c[1], d[0], d[1], 0.0)) return 0.0;
        dist[0] = tt__point_segment_distance(c[0], c[1], a[0], a[1], b[0], b[1]);
        dist[1] = tt__point_segment_distance(d[0], d[1], a[0], a[1], b[0], b[1]);
        dist[2] = tt__point_segment_distance(a[0], a[1], c[0], c[1], d[0], d[1]);
        dist[3] = tt__point_segment_distance(b[0], b[1], c[0], c[1], d[0], d[1]);
        for (i = 0; i < 4; i++)
            if (dist[i] < best) best = dist[i];
    }
    return best;
}

/* tt__segment_meets_polygon against dense sampling of the segment: every
   sampled hit must be reported; a reported hit the sampling missed must be a
   grazing one (the segment within one sample spacing of the boundary). */
static void test_hull_segment(void)
{
    int shape, trial, mismatches = 0, ntests = 0;
    lcg_seed(99);
    for (shape = 0; shape < 12; shape++) {
        tt_image img = hull_image(48, 48);
        float *xy;
        int n;
        if (shape % 3 == 0) hull_disc(&img, 24, 24, 18, 1.0f);
        else if (shape % 3 == 1) { hull_rect(&img, 4, 4, 14, 44); hull_rect(&img, 4, 34, 44, 44); }
        else hull_blob(&img, 600);
        if (tt__patch_hull(&img, shape < 6 ? 32 : 8, NULL, &xy, &n) != TT_OK) {
            CHECK(0, "shape %d: hull for the segment test", shape);
            tt_image_free(&img);
            continue;
        }
        for (trial = 0; trial < 250; trial++) {
            float a[2], b[2];
            double da[2], db[2];
            int got, ref = 0, s, samples = 2000;
            if (trial % 10 == 0) { /* from a hull vertex */
                int v = lcg_below(n);
                a[0] = xy[2 * v]; a[1] = xy[2 * v + 1];
            } else {
                a[0] = (float)(-0.2 + 1.4 * lcg_unit()); a[1] = (float)(-0.2 + 1.4 * lcg_unit());
            }
            if (trial % 4 == 0) { /* short */
                b[0] = a[0] + (float)(0.1 * (lcg_unit() - 0.5)); b[1] = a[1] + (float)(0.1 * (lcg_unit() - 0.5));
            } else {
                b[0] = (float)(-0.2 + 1.4 * lcg_unit()); b[1] = (float)(-0.2 + 1.4 * lcg_unit());
            }
            da[0] = a[0]; da[1] = a[1]; db[0] = b[0]; db[1] = b[1];
            got = tt__segment_meets_polygon(a, b, xy, n);
            for (s = 0; s <= samples && !ref; s++) {
                double t = (double)s / samples;
                ref = hull_inside_or_near(da[0] + t * (db[0] - da[0]), da[1] + t * (db[1] - da[1]), xy, n, 0.0);
            }
            ntests++;
            if (ref && !got) {
                if (!mismatches) DETAIL("shape %d: (%g, %g)-(%g, %g) meets the hull, not reported", shape, da[0],
                                        da[1], db[0], db[1]);
                mismatches++;
            }
            if (!ref && got) {
                double len = sqrt((db[0] - da[0]) * (db[0] - da[0]) + (db[1] - da[1]) * (db[1] - da[1]));
                if (hull_segment_distance(da, db, xy, n) > len / samples + 1e-9) {
                    if (!mismatches) DETAIL("shape %d: (%g, %g)-(%g, %g) reported, but misses the hull", shape,
                                            da[0], da[1], db[0], db[1]);
                    mismatches++;
                }
            }
        }
        free(xy);
        tt_image_free(&img);
    }
    CHECK(mismatches == 0 && ntests == 3000, "%d of %d random segments disagree with sampling", mismatches, ntests);

    {
        /* unit square, hand-made cases */
        const float sq[8] = {0, 0, 1, 0, 1, 1, 0, 1};
        float a[2], b[2];
        a[0] = 0.2f; a[1] = 0.2f; b[0] = 0.4f; b[1] = 0.6f;
        CHECK(tt__segment_meets_polygon(a, b, sq, 4) == 1, "segment inside");
        a[0] = -1; a[1] = 0.5f; b[0] = 2; b[1] = 0.5f;
        CHECK(tt__segment_meets_polygon(a, b, sq, 4) == 1, "segment through");
        a[0] = -1; a[1] = 2; b[0] = 2; b[1] = 2;
        CHECK(tt__segment_meets_polygon(a, b, sq, 4) == 0, "segment above");
        a[0] = -1; a[1] = 1; b[0] = 2; b[1] = 1;
        CHECK(tt__segment_meets_polygon(a, b, sq, 4) == 1, "segment along the top edge");
        a[0] = 1; a[1] = 2; b[0] = 2; b[1] = 1;
        CHECK(tt__segment_meets_polygon(a, b, sq, 4) == 0, "segment near the corner");
        a[0] = 0; a[1] = 2; b[0] = 2; b[1] = 0;
        CHECK(tt__segment_meets_polygon(a, b, sq, 4) == 1, "segment touching the corner");
        a[0] = 1; a[1] = 1; b[0] = 1; b[1] = 1;
        CHECK(tt__segment_meets_polygon(a, b, sq, 4) == 1, "a point on the corner");
        a[0] = 1.5f; a[1] = 0.5f; b[0] = 1.5f; b[1] = 0.5f;
        CHECK(tt__segment_meets_polygon(a, b, sq, 4) == 0, "a point outside");
    }
}

static void test_hull_errors(void)
{
    tt_image img = hull_image(8, 8);
    float *xy = (float *)&img; /* must be reset to NULL on failure */
    int n = 5;
    CHECK(tt__patch_hull(&img, 32, NULL, &xy, &n) == TT_ERROR_INVALID_ARGUMENT, "transparent patch refused");
    CHECK(xy == NULL && n == 0, "outputs reset on failure: %p, %d", (void *)xy, n);
    hull_set_alpha(&img, 3, 3, 1.0f);
    CHECK(tt__patch_hull(&img, 2, NULL, &xy, &n) == TT_ERROR_INVALID_ARGUMENT, "max_vertices 2 refused");
    CHECK(tt__patch_hull(NULL, 32, NULL, &xy, &n) == TT_ERROR_INVALID_ARGUMENT, "NULL patch refused");
    CHECK(tt__patch_hull(&img, 32, NULL, NULL, &n) == TT_ERROR_INVALID_ARGUMENT, "NULL out refused");
    hull_set_alpha(&img, 3, 3, -1.0f);
    CHECK(tt__patch_hull(&img, 32, NULL, &xy, &n) == TT_ERROR_INVALID_ARGUMENT, "negative alpha only refused");
    tt_image_free(&img);
}

typedef struct hull_oom_ctx {
    const tt_image *img;
    int max_vertices;
} hull_oom_ctx;

static tt_result hull_oom_call(void *ctx, const tt_allocator *al)
{
    hull_oom_ctx *c = (hull_oom_ctx *)ctx;
    float *xy = (float *)ctx;
    int n = -1;
    tt_result r = tt__patch_hull(c->img, c->max_vertices, al, &xy, &n);
    if (r != TT_OK) return xy == NULL && n == 0 ? r : TT_RESULT_MAX_ENUM;   /* outputs reset on failure */
    if (!xy || n < 3 || n > c->max_vertices) r = TT_RESULT_MAX_ENUM;
    tt__free(al, xy);
    return r;
}

static void test_hull_oom(void)
{
    tt_image img;
    hull_oom_ctx c;
    int s;
    oom_reset();
    lcg_seed(5);
    img = hull_image(64, 64);
    hull_blob(&img, 900);
    c.img = &img;
    c.max_vertices = 32;
    oom_sweep("tt__patch_hull(blob, contour)", hull_oom_call, &c, TT_OK);
    tt_image_free(&img);

    img = hull_image(40, 40);
    hull_disc(&img, 10, 10, 6, 1.0f); hull_disc(&img, 30, 28, 7, 1.0f);
    c.img = &img;
    c.max_vertices = 8;
    oom_sweep("tt__patch_hull(two blobs, convex)", hull_oom_call, &c, TT_OK);
    tt_image_free(&img);

    img = hull_image(16, 16);
    hull_rect(&img, 2, 2, 14, 14);
    c.img = &img;
    c.max_vertices = 3;
    oom_sweep("tt__patch_hull(square to triangle, bounding)", hull_oom_call, &c, TT_OK);
    tt_image_free(&img);

    img = hull_image(200, 200); /* long straight sides plus fine detail: the edge grid grows */
    hull_rect(&img, 10, 10, 190, 190);
    for (s = 12; s < 188; s += 3) hull_set_alpha(&img, s, 9, 1.0f);
    for (s = 12; s < 188; s += 5) hull_set_alpha(&img, 190, s, 1.0f);
    c.img = &img;
    c.max_vertices = 4;
    oom_sweep("tt__patch_hull(square with teeth)", hull_oom_call, &c, TT_OK);
    tt_image_free(&img);

    img = hull_image(60, 40); /* comb: the edge grid's node pool grows */
    hull_rect(&img, 2, 30, 58, 36);
    for (s = 2; s < 58; s += 4) hull_rect(&img, s, 3, s + 2, 30);
    c.img = &img;
    c.max_vertices = 8;
    oom_sweep("tt__patch_hull(comb)", hull_oom_call, &c, TT_OK);
    tt_image_free(&img);

    img = hull_image(8, 8);   /* transparent: refused before any allocation */
    c.img = &img;
    c.max_vertices = 8;
    CHECK(hull_oom_call(&c, &g_oom_allocator) == TT_ERROR_INVALID_ARGUMENT && g_oom_counter.live == 0,
          "transparent patch refused, nothing allocated");
    tt_image_free(&img);
    CHECK(g_oom_counter.live == 0 && g_oom_counter.bad_frees == 0, "hull sweeps: %ld blocks live, %ld bad frees",
          g_oom_counter.live, g_oom_counter.bad_frees);
}

/* ------------------------------------------------------------------------ */
/* Lapped textures: measuring, atlas packing, baking (Sec. 4)                */
/* ------------------------------------------------------------------------ */

/* Build a tmesh (optionally with an allocator). */
static tt_mesh *bake_build(const tmesh *m, const tt_allocator *al)
{
    tt_mesh_desc d = tm_desc(m);
    tt_mesh *mesh = NULL;
    tt_error err;
    tt_result r;
    if (al) d.allocator = *al;
    r = tt_mesh_build(&d, &mesh, &err);
    CHECK(r == TT_OK, "test mesh builds: %s", err.message);
    return mesh;
}

/* An nx x ny grid of unit squares over [0, nx] x [0, ny] in z = 0, each
   split into the CCW triangles (a, b, c), (a, c, d) (faces 2q, 2q + 1 of
   square q); `jitter` moves interior vertices by up to jitter / 2. */
static tt_mesh *bake_grid(int nx, int ny, double jitter, const tt_allocator *al)
{
    tmesh q, t;
    tt_mesh *mesh;
    int i, j;
    memset(&q, 0, sizeof q);
    make_grid(&q, nx, ny);
    for (j = 1; j < ny; j++)
        for (i = 1; i < nx; i++) {
            float *p = q.pos + 3 * (j * (nx + 1) + i);
            p[0] = (float)(i + jitter * (lcg_unit() - 0.5));
            p[1] = (float)(j + jitter * (lcg_unit() - 0.5));
        }
    tm_triangulate(&q, &t);
    mesh = bake_build(&t, al);
    tm_free(&q);
    tm_free(&t);
    return mesh;
}

/* One quad: every function here wants triangles. */
static tt_mesh *bake_quad(void)
{
    tmesh q;
    tt_mesh *mesh;
    memset(&q, 0, sizeof q);
    make_grid(&q, 1, 1);
    mesh = bake_build(&q, NULL);
    tm_free(&q);
    return mesh;
}

/* Triangles (0,1,2), (1,3,2), (1,4,3) over (0,0) (1,0) (0,1) (1,1) (2,0)
   and, with six vertices, (2,1); the first `nfaces` of them. */
static tt_mesh *bake_three(int nverts, int nfaces)
{
    static const float p[18] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0, 2, 0, 0, 2, 1, 0};
    tmesh m;
    tt_mesh *mesh;
    int i;
    memset(&m, 0, sizeof m);
    for (i = 0; i < nverts; i++) tm_vert(&m, p[3 * i], p[3 * i + 1], p[3 * i + 2]);
    tm_tri(&m, 0, 1, 2);
    if (nfaces > 1) tm_tri(&m, 1, 3, 2);
    if (nfaces > 2) tm_tri(&m, 1, 4, 3);
    mesh = bake_build(&m, NULL);
    tm_free(&m);
    return mesh;
}

/* A tt_lapped over arrays from malloc, grown one paste / entry at a time. */
typedef struct lb_builder {
    tt_lapped l;
    int cap_pastes, cap_entries;
} lb_builder;

static void lb_init(lb_builder *b) { memset(b, 0, sizeof *b); }

static void lb_free(lb_builder *b)
{
    free(b->l.pastes);
    free(b->l.faces);
    free(b->l.uv);
    memset(b, 0, sizeof *b);
}

static void lb_begin(lb_builder *b, int patch)
{
    if (b->l.npastes == b->cap_pastes) {
        b->cap_pastes = b->cap_pastes ? 2 * b->cap_pastes : 8;
        b->l.pastes = (tt_paste *)realloc(b->l.pastes, sizeof(tt_paste) * (size_t)b->cap_pastes);
    }
    b->l.pastes[b->l.npastes].patch = patch;
    b->l.pastes[b->l.npastes].first = b->l.nentries;
    b->l.pastes[b->l.npastes].nfaces = 0;
    b->l.npastes++;
}

static void lb_add(lb_builder *b, int face, const float uv[6])
{
    if (b->l.nentries == b->cap_entries) {
        b->cap_entries = b->cap_entries ? 2 * b->cap_entries : 64;
        b->l.faces = (int *)realloc(b->l.faces, sizeof(int) * (size_t)b->cap_entries);
        b->l.uv = (float *)realloc(b->l.uv, sizeof(float) * 6 * (size_t)b->cap_entries);
    }
    b->l.faces[b->l.nentries] = face;
    memcpy(b->l.uv + 6 * (size_t)b->l.nentries, uv, 6 * sizeof(float));
    b->l.nentries++;
    b->l.pastes[b->l.npastes - 1].nfaces++;
}

/* Paste UVs of face f by an affine map of its positions: uv = M (x, y) + o. */
static void bake_affine_uv(const tt_mesh *mesh, int f, const double m[4], const double o[2], float uv[6])
{
    int k;
    for (k = 0; k < 3; k++) {
        const float *p = mesh->pos + 3 * mesh->corner_vert[mesh->face_start[f] + k];
        uv[2 * k] = (float)(m[0] * p[0] + m[1] * p[1] + o[0]);
        uv[2 * k + 1] = (float)(m[2] * p[0] + m[3] * p[1] + o[1]);
    }
}

/* A new paste of every face with the map uv = m (x, y) + o. */
static void lb_paste_all(lb_builder *b, const tt_mesh *mesh, int patch, const double m[4], const double o[2])
{
    int f;
    float uv[6];
    lb_begin(b, patch);
    for (f = 0; f < mesh->nfaces; f++) {
        bake_affine_uv(mesh, f, m, o, uv);
        lb_add(b, f, uv);
    }
}

/* A constant image, premultiplied colour (r, g, b) * a. */
static tt_image bake_constant(int w, int h, float r, float g, float b, float a)
{
    tt_image img;
    int i;
    tt_image_create(&img, w, h, NULL);
    for (i = 0; i < w * h; i++) {
        img.pixels[4 * i] = r * a;
        img.pixels[4 * i + 1] = g * a;
        img.pixels[4 * i + 2] = b * a;
        img.pixels[4 * i + 3] = a;
    }
    return img;
}

/* The same vector (x, y, 0) on every face (malloc). */
static float *bake_face_vectors(const tt_mesh *mesh, float x, float y)
{
    float *v = (float *)malloc(sizeof(float) * 3 * (size_t)mesh->nfaces);
    int f;
    for (f = 0; f < mesh->nfaces; f++) {
        v[3 * f] = x;
        v[3 * f + 1] = y;
        v[3 * f + 2] = 0.0f;
    }
    return v;
}

/* ---- tt_lapped_measure ---- */

static void test_lapped_measure(void)
{
    tt_mesh *mesh;
    float *fv, uv[6];
    lb_builder b;
    tt_lapped_report rep;
    double pi = 3.14159265358979323846, a = 10.0 * pi / 180.0, s = 1.2;
    double rot[4], id[4] = {1, 0, 0, 1}, o[2] = {0.3, -0.2};
    int f;
    lcg_seed(11);
    mesh = bake_grid(4, 3, 0.4, NULL);
    fv = bake_face_vectors(mesh, 0.0f, 1.0f);
    rot[0] = s * cos(a); rot[1] = -s * sin(a); rot[2] = s * sin(a); rot[3] = s * cos(a);

    /* Rotation by 10 degrees and scale 1.2 on every face. */
    lb_init(&b);
    lb_paste_all(&b, mesh, 0, rot, o);
    CHECK(tt_lapped_measure(mesh, fv, &b.l, &rep) == TT_OK, "rotated paste: ok");
    CHECK(fabs(rep.mean_angle_error - 10.0) < 1e-4, "rotated paste: angle 10, got %.8f", rep.mean_angle_error);
    CHECK(fabs(rep.median_scale_error - 0.2) < 1e-4, "rotated paste: scale error 0.2, got %.8f",
          rep.median_scale_error);
    CHECK(fabs(rep.mean_overdraw - 1.0) < 1e-12, "rotated paste: overdraw 1, got %g", rep.mean_overdraw);
    CHECK(rep.uncovered_faces == 0, "rotated paste: no uncovered faces, got %d", rep.uncovered_faces);

    /* A face vector of length 2 along x maps to rotated (2.4, ...): 80 degrees off up. */
    {
        float *fx = bake_face_vectors(mesh, 2.0f, 0.0f);
        CHECK(tt_lapped_measure(mesh, fx, &b.l, &rep) == TT_OK, "x field: ok");
        CHECK(fabs(rep.mean_angle_error - 80.0) < 1e-4, "x field: angle 80, got %.8f", rep.mean_angle_error);
        CHECK(fabs(rep.median_scale_error - 1.4) < 1e-4, "x field: scale error 1.4, got %.8f",
              rep.median_scale_error);
        free(fx);
    }
    lb_free(&b);

    /* Identity, over only some faces, one face twice: overdraw and uncovered. */
    lb_init(&b);
    lb_begin(&b, 0);
    for (f = 0; f < mesh->nfaces - 5; f++) {
        bake_affine_uv(mesh, f, id, o, uv);
        lb_add(&b, f, uv);
    }
    bake_affine_uv(mesh, 0, id, o, uv);
    lb_add(&b, 0, uv);
    CHECK(tt_lapped_measure(mesh, fv, &b.l, &rep) == TT_OK, "partial paste: ok");
    CHECK(fabs(rep.mean_angle_error) < 1e-4, "partial paste: angle 0, got %g", rep.mean_angle_error);
    CHECK(fabs(rep.median_scale_error) < 1e-5, "partial paste: scale error 0, got %g", rep.median_scale_error);
    CHECK(rep.uncovered_faces == 5, "partial paste: 5 uncovered, got %d", rep.uncovered_faces);
    CHECK(fabs(rep.mean_overdraw - (double)(mesh->nfaces - 4) / mesh->nfaces) < 1e-12,
          "partial paste: overdraw %d / %d, got %g", mesh->nfaces - 4, mesh->nfaces, rep.mean_overdraw);
    lb_free(&b);

    /* Exact median of an even count: scales 2.0, 1.1, 1.6, 1.3 -> errors
       1 .1 .6 .3, median (0.3 + 0.6) / 2; then odd counts. */
    {
        double scales[4] = {2.0, 1.1, 1.6, 1.3}, m[4];
        int i;
        lb_init(&b);
        lb_begin(&b, 0);
        for (i = 0; i < 4; i++) {
            m[0] = scales[i]; m[1] = 0; m[2] = 0; m[3] = scales[i];
            bake_affine_uv(mesh, i, m, o, uv);
            lb_add(&b, i, uv);
        }
        CHECK(tt_lapped_measure(mesh, fv, &b.l, &rep) == TT_OK, "4 scales: ok");
        CHECK(fabs(rep.median_scale_error - 0.45) < 1e-5, "4 scales: median 0.45, got %.8f", rep.median_scale_error);
        /* Odd count: add scale 1 (error 0): sorted 0 .1 .3 .6 1 -> 0.3. */
        bake_affine_uv(mesh, 4, id, o, uv);
        lb_add(&b, 4, uv);
        CHECK(tt_lapped_measure(mesh, fv, &b.l, &rep) == TT_OK, "5 scales: ok");
        CHECK(fabs(rep.median_scale_error - 0.3) < 1e-5, "5 scales: median 0.3, got %.8f", rep.median_scale_error);
        /* Degenerate UVs (all corners one point): phi(T) = 0 counts 180
           degrees and scale error 1. */
        for (i = 0; i < 6; i++) uv[i] = 0.5f;
        lb_add(&b, 5, uv);
        CHECK(tt_lapped_measure(mesh, fv, &b.l, &rep) == TT_OK, "degenerate entry: ok");
        CHECK(fabs(rep.mean_angle_error - 30.0) < 1e-4, "degenerate entry: angle (5 * 0 + 180) / 6 = 30, got %g",
              rep.mean_angle_error);
        CHECK(fabs(rep.median_scale_error - 0.45) < 1e-5,
              "degenerate entry: errors 0 .1 .3 .6 1 1, median 0.45, got %g", rep.median_scale_error);
        lb_free(&b);
    }

    /* No entries: errors 0, every face uncovered. */
    lb_init(&b);
    CHECK(tt_lapped_measure(mesh, fv, &b.l, &rep) == TT_OK, "no entries: ok");
    CHECK(rep.mean_angle_error == 0.0 && rep.median_scale_error == 0.0 && rep.mean_overdraw == 0.0 &&
              rep.uncovered_faces == mesh->nfaces,
          "no entries: zeros and %d uncovered, got %g %g %g %d", mesh->nfaces, rep.mean_angle_error,
          rep.median_scale_error, rep.mean_overdraw, rep.uncovered_faces);
    free(fv);
    tt_mesh_free(mesh);
}

static void test_lapped_measure_errors(void)
{
    tt_mesh *mesh, *qm;
    float *fv, uv[6], qv[3] = {0, 1, 0};
    lb_builder b;
    tt_lapped_report rep;
    double id[4] = {1, 0, 0, 1}, o[2] = {0, 0};
    int i;
    lcg_seed(12);
    mesh = bake_grid(4, 3, 0.4, NULL);
    fv = bake_face_vectors(mesh, 0.0f, 1.0f);
    lb_init(&b);
    lb_begin(&b, 0);
    for (i = 0; i < 4; i++) {
        bake_affine_uv(mesh, i, id, o, uv);
        lb_add(&b, i, uv);
    }
    CHECK(tt_lapped_measure(mesh, fv, &b.l, &rep) == TT_OK, "valid input: ok");
    CHECK(tt_lapped_measure(NULL, fv, &b.l, &rep) == TT_ERROR_INVALID_ARGUMENT, "NULL mesh refused");
    CHECK(tt_lapped_measure(mesh, NULL, &b.l, &rep) == TT_ERROR_INVALID_ARGUMENT, "NULL vectors refused");
    CHECK(tt_lapped_measure(mesh, fv, NULL, &rep) == TT_ERROR_INVALID_ARGUMENT, "NULL lapped refused");
    CHECK(tt_lapped_measure(mesh, fv, &b.l, NULL) == TT_ERROR_INVALID_ARGUMENT, "NULL report refused");
    b.l.faces[2] = mesh->nfaces;
    CHECK(tt_lapped_measure(mesh, fv, &b.l, &rep) == TT_ERROR_INDEX_OUT_OF_RANGE, "face nfaces out of range");
    b.l.faces[2] = -1;
    CHECK(tt_lapped_measure(mesh, fv, &b.l, &rep) == TT_ERROR_INDEX_OUT_OF_RANGE, "face -1 out of range");
    b.l.faces[2] = 2;
    b.l.uv[7] = (float)tt__not_a_number();
    CHECK(tt_lapped_measure(mesh, fv, &b.l, &rep) == TT_ERROR_NON_FINITE, "NaN paste uv refused");
    b.l.uv[7] = 0.0f;
    fv[3 * 3 + 1] = tt__infinity();
    CHECK(tt_lapped_measure(mesh, fv, &b.l, &rep) == TT_ERROR_NON_FINITE, "infinite face vector refused");
    fv[3 * 3 + 1] = 1.0f;
    b.l.nentries = -1;
    CHECK(tt_lapped_measure(mesh, fv, &b.l, &rep) == TT_ERROR_INVALID_ARGUMENT, "nentries -1 refused");
    b.l.nentries = 4;
    CHECK(tt_lapped_measure(mesh, fv, &b.l, &rep) == TT_OK, "restored input: ok");
    lb_free(&b);

    qm = bake_quad();
    lb_init(&b);
    CHECK(tt_lapped_measure(qm, qv, &b.l, &rep) == TT_ERROR_INVALID_ARGUMENT, "quad mesh refused");
    tt_mesh_free(qm);
    free(fv);
    tt_mesh_free(mesh);
}

typedef struct measure_oom_ctx {
    const tt_mesh *mesh;      /* built with the sweep's allocator */
    const float *fv;
    const tt_lapped *lapped;
} measure_oom_ctx;

static tt_result measure_oom_call(void *ctx, const tt_allocator *al)
{
    measure_oom_ctx *c = (measure_oom_ctx *)ctx;
    tt_lapped_report rep;
    (void)al;   /* tt_lapped_measure allocates from the mesh's allocator: the same one */
    return tt_lapped_measure(c->mesh, c->fv, c->lapped, &rep);
}

static void test_lapped_measure_oom(void)
{
    tt_mesh *mesh;
    float *fv;
    lb_builder b;
    measure_oom_ctx c;
    double id[4] = {1, 0, 0, 1}, o[2] = {0.3, -0.2};
    oom_reset();
    mesh = bake_grid(3, 3, 0.0, &g_oom_allocator);
    if (!mesh) return;
    fv = bake_face_vectors(mesh, 0.0f, 1.0f);
    lb_init(&b);
    lb_paste_all(&b, mesh, 0, id, o);
    c.mesh = mesh;
    c.fv = fv;
    c.lapped = &b.l;
    oom_sweep("tt_lapped_measure", measure_oom_call, &c, TT_OK);
    CHECK(g_oom_counter.calls == 2, "tt_lapped_measure: 2 allocations, got %ld", g_oom_counter.calls);
    tt_mesh_free(mesh);
    CHECK(g_oom_counter.live == 0 && g_oom_counter.bad_frees == 0, "all freed (%ld live, %ld bad frees)",
          g_oom_counter.live, g_oom_counter.bad_frees);
    lb_free(&b);
    free(fv);
}

/* ---- tt_atlas_pack_pairs ---- */

typedef struct bake_count {
    int *count;
    int width;
    int overlaps;
} bake_count;

static void bake_count_texel(int x, int y, const float bary[3], void *user)
{
    bake_count *cb = (bake_count *)user;
    (void)bary;
    if (++cb->count[y * cb->width + x] > 1) cb->overlaps++;
}

/* Distance (texels) from (qx, qy) to the triangle x, y (0 inside). */
static double bake_triangle_distance(const double *x, const double *y, double qx, double qy)
{
    double area2 = tt__orient2(x[0], y[0], x[1], y[1], x[2], y[2]), best = 1e300;
    int i, inside = 1;
    for (i = 0; i < 3; i++) {
        int j = (i + 1) % 3;
        double d = tt__point_segment_distance(qx, qy, x[i], y[i], x[j], y[j]);
        if (tt__orient2(x[i], y[i], x[j], y[j], qx, qy) * area2 < 0) inside = 0;
        if (d < best) best = d;
    }
    return inside ? 0.0 : best;
}

/* Texel centres within `gutter` of each atlas triangle, counted per
   triangle: the number of texels counted more than once. */
static int bake_gutter_overlaps(const tt_mesh *mesh, const float *uv, int size, int gutter)
{
    int *count = (int *)calloc((size_t)size * size, sizeof(int));
    int f, over = 0;
    for (f = 0; f < mesh->nfaces; f++) {
        double x[3], y[3], lo_x = 1e30, hi_x = -1e30, lo_y = 1e30, hi_y = -1e30;
        int k, i, j;
        for (k = 0; k < 3; k++) {
            int c = mesh->face_start[f] + k;
            x[k] = uv[2 * c] * (double)size;
            y[k] = (1.0 - uv[2 * c + 1]) * (double)size;
            lo_x = fmin(lo_x, x[k]); hi_x = fmax(hi_x, x[k]);
            lo_y = fmin(lo_y, y[k]); hi_y = fmax(hi_y, y[k]);
        }
        for (j = (int)floor(lo_y - gutter - 1); j <= (int)ceil(hi_y + gutter + 1); j++)
            for (i = (int)floor(lo_x - gutter - 1); i <= (int)ceil(hi_x + gutter + 1); i++) {
                if (i < 0 || j < 0 || i >= size || j >= size) continue;
                if (bake_triangle_distance(x, y, i + 0.5, j + 0.5) <= gutter + 1e-3)
                    if (++count[j * size + i] > 1) over++;
            }
    }
    free(count);
    return over;
}

/* UVs outside [0, 1] (or NaN) among the first n floats. */
static int bake_uv_outside(const float *uv, int n)
{
    int c, bad = 0;
    for (c = 0; c < n; c++) bad += !(uv[c] >= 0.0f && uv[c] <= 1.0f);
    return bad;
}

/* Jittered grids: the size the TOO_SMALL message suggests is the smallest
   that works; at it and above, UVs in [0, 1], gutters disjoint, orientation
   kept, rasters disjoint. */
static void test_atlas_pack_pairs(void)
{
    static const int sizes[3][3] = {{5, 2, 4}, {7, 3, 0}, {33, 4, 4}};   /* grid nx, ny, gutter */
    const char *key = "smallest size that works is ";
    int t;
    tt_error err;
    lcg_seed(21);
    for (t = 0; t < 3; t++) {
        tt_mesh *mesh = bake_grid(sizes[t][0], sizes[t][1], 0.5, NULL);
        int gutter = sizes[t][2], size = 0, bad = 0, f, s2;
        float *uv = (float *)malloc(sizeof(float) * 2 * (size_t)mesh->ncorners);
        tt_result r = tt_atlas_pack_pairs(mesh, 8, gutter, uv, &err);
        const char *hint;
        CHECK(r == TT_ERROR_IMAGE_TOO_SMALL, "grid %d: 8 texels too small, got %d", t, (int)r);
        hint = strstr(err.message, key);
        CHECK(hint != NULL, "grid %d: message suggests a size: %s", t, err.message);
        if (hint) size = atoi(hint + strlen(key));
        CHECK(tt_atlas_pack_pairs(mesh, size, gutter, uv, &err) == TT_OK,
              "grid %d: suggested size %d works: %s", t, size, err.message);
        CHECK(tt_atlas_pack_pairs(mesh, size - 1, gutter, uv, &err) == TT_ERROR_IMAGE_TOO_SMALL,
              "grid %d: size %d - 1 does not", t, size);
        CHECK(tt_atlas_pack_pairs(mesh, size, gutter, uv, &err) == TT_OK, "grid %d: size %d again", t, size);
        bad = bake_uv_outside(uv, 2 * mesh->ncorners);
        CHECK(bad == 0, "grid %d: %d UVs outside [0,1]", t, bad);
        bad = bake_gutter_overlaps(mesh, uv, size, gutter);
        CHECK(bad == 0, "grid %d: gutters disjoint at the smallest size, %d texels shared", t, bad);
        /* Orientation kept (CCW in UV, v up) and area positive. */
        bad = 0;
        for (f = 0; f < mesh->nfaces; f++) {
            const float *a = uv + 6 * f;
            double area = ((double)a[2] - a[0]) * ((double)a[5] - a[1]) - ((double)a[4] - a[0]) * ((double)a[3] - a[1]);
            if (!(area > 0)) bad++;
        }
        CHECK(bad == 0, "grid %d: %d faces flipped or empty", t, bad);
        /* A larger size too, and the rasters of the triangles are disjoint. */
        s2 = size * 2 + 3;
        CHECK(tt_atlas_pack_pairs(mesh, s2, gutter, uv, &err) == TT_OK, "grid %d: size %d", t, s2);
        bad = bake_gutter_overlaps(mesh, uv, s2, gutter);
        CHECK(bad == 0, "grid %d: gutters disjoint at size %d, %d texels shared", t, s2, bad);
        {
            bake_count cb;
            cb.width = s2;
            cb.overlaps = 0;
            cb.count = (int *)calloc((size_t)s2 * s2, sizeof(int));
            for (f = 0; f < mesh->nfaces; f++) {
                float xy[6];
                int k;
                for (k = 0; k < 3; k++) {
                    xy[2 * k] = uv[6 * f + 2 * k] * (float)s2;
                    xy[2 * k + 1] = (1.0f - uv[6 * f + 2 * k + 1]) * (float)s2;
                }
                tt_raster_triangle(xy, s2, s2, bake_count_texel, &cb);
            }
            CHECK(cb.overlaps == 0, "grid %d: raster overlaps %d", t, cb.overlaps);
            free(cb.count);
        }
        free(uv);
        tt_mesh_free(mesh);
    }
}

/* Odd triangle counts: three, and one. */
static void test_atlas_pack_odd(void)
{
    tt_mesh *m3 = bake_three(5, 3);
    float uv[18];
    tt_error err;
    int bad;
    CHECK(tt_atlas_pack_pairs(m3, 64, 2, uv, &err) == TT_OK, "3 triangles: %s", err.message);
    bad = bake_uv_outside(uv, 18);
    CHECK(bad == 0, "3 triangles: %d UVs outside [0,1]", bad);
    bad = bake_gutter_overlaps(m3, uv, 64, 2);
    CHECK(bad == 0, "3 triangles: gutters disjoint, %d texels shared", bad);
    /* The largest angle becomes the right angle: face 0's corner 0 (the right
       angle at (0,0)) sits at its cell's lower-left, (2, 30) texels. */
    CHECK(fabs(uv[0] * 64 - 2.0) < 1e-4 && fabs((1 - uv[1]) * 64 - 30.0) < 1e-4,
          "corner 0 at (2, 30) texels, got (%g, %g)", uv[0] * 64, (1 - uv[1]) * 64);
    tt_mesh_free(m3);
    m3 = bake_three(5, 1);
    CHECK(tt_atlas_pack_pairs(m3, 4, 0, uv, &err) == TT_OK, "one triangle in 4 texels: %s", err.message);
    CHECK(tt_atlas_pack_pairs(m3, 3, 0, uv, &err) == TT_ERROR_IMAGE_TOO_SMALL, "one triangle: 3 texels too small");
    tt_mesh_free(m3);
}

static void test_atlas_pack_errors(void)
{
    tt_mesh *mesh = bake_grid(2, 2, 0.0, NULL), *qm;
    float uv[48];
    tt_error err;
    CHECK(tt_atlas_pack_pairs(NULL, 64, 1, uv, &err) == TT_ERROR_INVALID_ARGUMENT, "NULL mesh refused");
    CHECK(tt_atlas_pack_pairs(mesh, 64, 1, NULL, &err) == TT_ERROR_INVALID_ARGUMENT, "NULL uv refused");
    CHECK(tt_atlas_pack_pairs(mesh, 0, 1, uv, &err) == TT_ERROR_INVALID_ARGUMENT, "size 0 refused");
    CHECK(tt_atlas_pack_pairs(mesh, TT_MAX_IMAGE_SIZE + 1, 1, uv, &err) == TT_ERROR_INVALID_ARGUMENT,
          "size above TT_MAX_IMAGE_SIZE refused");
    CHECK(tt_atlas_pack_pairs(mesh, 64, -1, uv, &err) == TT_ERROR_INVALID_ARGUMENT, "negative gutter refused");
    CHECK(tt_atlas_pack_pairs(mesh, 64, 20000, uv, &err) == TT_ERROR_IMAGE_TOO_SMALL && strstr(err.message, "above"),
          "huge gutter: too small, above the limit: %s", err.message);
    tt_mesh_free(mesh);
    qm = bake_quad();
    CHECK(tt_atlas_pack_pairs(qm, 64, 1, uv, &err) == TT_ERROR_INVALID_ARGUMENT && err.face == 0,
          "quads refused, face 0 named: %s", err.message);
    tt_mesh_free(qm);
}

/* ---- tt_lapped_bake ---- */

/* Atlas UVs of a mesh in [0,1]^2 (the unit square grid cell) scaled into [lo, hi]^2. */
static void bake_square_uvs(const tt_mesh *mesh, double lo, double hi, float *uv)
{
    int c;
    for (c = 0; c < mesh->ncorners; c++) {
        const float *p = mesh->pos + 3 * mesh->corner_vert[c];
        uv[2 * c] = (float)(lo + (hi - lo) * p[0]);
        uv[2 * c + 1] = (float)(lo + (hi - lo) * p[1]);
    }
}

typedef struct bake_mask {
    unsigned char *mask;
    int width;
} bake_mask;

static void bake_mark_texel(int x, int y, const float bary[3], void *user)
{
    bake_mask *m = (bake_mask *)user;
    (void)bary;
    m->mask[y * m->width + x] = 1;
}

/* 1 for the texels tt_raster_triangle gives the atlas triangles (calloc). */
static unsigned char *bake_raster_mask(const tt_mesh *mesh, const float *uv, int w, int h)
{
    bake_mask m;
    int f, k;
    m.mask = (unsigned char *)calloc((size_t)w * h, 1);
    m.width = w;
    for (f = 0; f < mesh->nfaces; f++) {
        float xy[6];
        for (k = 0; k < 3; k++) {
            int c = mesh->face_start[f] + k;
            xy[2 * k] = uv[2 * c] * (float)w;
            xy[2 * k + 1] = (1.0f - uv[2 * c + 1]) * (float)h;
        }
        tt_raster_triangle(xy, w, h, bake_mark_texel, &m);
    }
    return m.mask;
}

/* Texels of the atlas not within 1e-6 of straight colour (r, g, b, a);
   a negative component is not compared. */
static int bake_count_off(const tt_image *atlas, const unsigned char *only, double r, double g, double b, double a)
{
    const double want[4] = {r, g, b, a};
    int i, k, bad = 0;
    for (i = 0; i < atlas->width * atlas->height; i++) {
        const float *p = atlas->pixels + 4 * i;
        int off = 0;
        if (only && !only[i]) continue;
        for (k = 0; k < 4; k++) off |= want[k] >= 0.0 && !(fabs(p[k] - want[k]) < 1e-6);
        bad += off;
    }
    return bad;
}

static void test_lapped_bake_constant(void)
{
    tt_mesh *mesh = bake_grid(1, 1, 0.0, NULL);
    float uv[12];
    double id[4] = {1, 0, 0, 1}, zero[2] = {0, 0};
    tt_image patches[2], atlas;
    lb_builder b;
    tt_error err;
    unsigned char *inside;
    int i, bad, ninside = 0;
    patches[0] = bake_constant(16, 16, 1, 0, 0, 1);
    patches[1] = bake_constant(8, 8, 0, 0, 1, 0.5f);
    bake_square_uvs(mesh, 0.25, 0.75, uv);
    lb_init(&b);
    lb_paste_all(&b, mesh, 0, id, zero);
    tt_image_create(&atlas, 40, 32, NULL);
    CHECK(tt_lapped_bake(mesh, &b.l, patches, 2, uv, 2, &atlas, &err) == TT_OK, "red: %s", err.message);
    inside = bake_raster_mask(mesh, uv, 40, 32);
    for (i = 0; i < 40 * 32; i++) ninside += inside[i];
    CHECK(ninside > 200, "triangles cover %d texels", ninside);
    bad = bake_count_off(&atlas, inside, 1, 0, 0, 1);
    CHECK(bad == 0, "red: %d texels inside the triangles not opaque red", bad);
    bad = bake_count_off(&atlas, NULL, 1, 0, 0, 1);
    CHECK(bad == 0, "red: %d texels anywhere not red after the fill", bad);

    /* A second paste, half-transparent blue over red: straight colour is the
       premultiplied "over" divided by alpha: (0.5, 0, 0.5), alpha 1. */
    lb_paste_all(&b, mesh, 1, id, zero);
    CHECK(tt_lapped_bake(mesh, &b.l, patches, 2, uv, 2, &atlas, &err) == TT_OK, "blue over red: %s", err.message);
    bad = bake_count_off(&atlas, NULL, 0.5, 0, 0.5, 1);
    CHECK(bad == 0, "%d texels differ from blue (alpha 0.5) over red", bad);

    /* Only the blue paste: alpha 0.5, straight colour pure blue. */
    b.l.pastes[0].nfaces = 0;
    CHECK(tt_lapped_bake(mesh, &b.l, patches, 2, uv, 0, &atlas, &err) == TT_OK, "blue only: %s", err.message);
    bad = bake_count_off(&atlas, NULL, 0, -1, 1, 0.5);
    CHECK(bad == 0, "%d texels not straight blue with alpha 0.5", bad);

    /* No pastes at all: transparent black everywhere, still OK. */
    b.l.npastes = 0;
    CHECK(tt_lapped_bake(mesh, &b.l, patches, 2, uv, 1, &atlas, &err) == TT_OK, "no pastes: %s", err.message);
    bad = bake_count_off(&atlas, NULL, 0, 0, 0, 0);
    CHECK(bad == 0, "no pastes: %d texels not transparent black", bad);
    free(inside);
    lb_free(&b);
    tt_image_free(&atlas);
    tt_image_free(&patches[0]);
    tt_image_free(&patches[1]);
    tt_mesh_free(mesh);
}

/* A smooth colour ramp patch: r = x / w, g = y / h, b = 0.5, opaque. */
static tt_image bake_ramp(int w, int h)
{
    tt_image img;
    int x, y;
    tt_image_create(&img, w, h, NULL);
    for (y = 0; y < h; y++)
        for (x = 0; x < w; x++) {
            float *p = img.pixels + 4 * (y * w + x);
            p[0] = (x + 0.5f) / w;
            p[1] = (y + 0.5f) / h;
            p[2] = 0.5f;
            p[3] = 1.0f;
        }
    return img;
}

/* One triangle pasted into the middle of a ramp patch: texels of the
   triangle and of its gutter hold the (extrapolated) composite, not a copy
   of the nearest inside texel; texels beyond the gutter are filled opaque. */
static void test_lapped_bake_gutter(void)
{
    float uv[6] = {0.3f, 0.3f, 0.7f, 0.35f, 0.32f, 0.72f};
    float puv[6] = {0.3f, 0.3f, 0.6f, 0.3f, 0.3f, 0.6f};
    tt_mesh *mesh = bake_three(3, 1);
    tt_image ramp = bake_ramp(64, 64), atlas;
    lb_builder b;
    tt_error err;
    unsigned char *inside;
    int W = 50, H = 60, x, y, k, ngutter = 0, bad = 0, gutter = 3, nfar = 0, badfar = 0;
    double maxdiff = 0, X[3], Y[3], area2;
    lb_init(&b);
    lb_begin(&b, 0);
    lb_add(&b, 0, puv);
    tt_image_create(&atlas, W, H, NULL);
    CHECK(tt_lapped_bake(mesh, &b.l, &ramp, 1, uv, gutter, &atlas, &err) == TT_OK, "bake: %s", err.message);
    inside = bake_raster_mask(mesh, uv, W, H);
    for (k = 0; k < 3; k++) { X[k] = uv[2 * k] * W; Y[k] = (1.0 - uv[2 * k + 1]) * H; }
    area2 = (X[1] - X[0]) * (Y[2] - Y[0]) - (X[2] - X[0]) * (Y[1] - Y[0]);
    for (y = 0; y < H; y++)
        for (x = 0; x < W; x++) {
            double qx = x + 0.5, qy = y + 0.5, w0, w1, w2, u, v, d = bake_triangle_distance(X, Y, qx, qy);
            float want[4];
            const float *got = atlas.pixels + 4 * (y * W + x);
            w0 = ((X[1] - qx) * (Y[2] - qy) - (X[2] - qx) * (Y[1] - qy)) / area2;
            w1 = ((X[2] - qx) * (Y[0] - qy) - (X[0] - qx) * (Y[2] - qy)) / area2;
            w2 = 1 - w0 - w1;
            u = w0 * puv[0] + w1 * puv[2] + w2 * puv[4];
            v = w0 * puv[1] + w1 * puv[3] + w2 * puv[5];
            tt_image_sample_bilinear(&ramp, (float)(u * 64), (float)((1 - v) * 64), want);
            if (inside[y * W + x] || d <= gutter - 1e-3) {
                double diff = 0;
                for (k = 0; k < 4; k++) diff = fmax(diff, fabs(got[k] - want[k]));
                if (!inside[y * W + x] && d > 0.5) ngutter++;
                if (diff > 1e-5) bad++;
                if (diff > maxdiff) maxdiff = diff;
            } else if (d > gutter + 1.5) {
                /* Beyond the gutter: a copy of a written texel. */
                nfar++;
                badfar += got[3] != 1.0f;
            }
        }
    CHECK(ngutter > 50, "gutter texels tested: %d", ngutter);
    CHECK(bad == 0, "%d texels in the triangle or its gutter differ from the extrapolated composite, max %g", bad,
          maxdiff);
    CHECK(nfar > 100 && badfar == 0, "texels beyond the gutter filled opaque (%d of %d bad)", badfar, nfar);
    free(inside);
    lb_free(&b);
    tt_image_free(&atlas);
    tt_image_free(&ramp);
    tt_mesh_free(mesh);
}

static tt_image bake_checker(int w, int h, int square)
{
    tt_image img;
    int x, y;
    tt_image_create(&img, w, h, NULL);
    for (y = 0; y < h; y++)
        for (x = 0; x < w; x++) {
            float *p = img.pixels + 4 * (y * w + x);
            int on = ((x / square) + (y / square)) & 1;
            p[0] = on ? 0.9f : 0.1f;
            p[1] = on ? 0.2f : 0.7f;
            p[2] = (float)x / (float)w;
            p[3] = 1.0f;
        }
    return img;
}

/* Mean RGB difference between the atlas (through the atlas UVs) and the
   patch (through face f's paste UVs, entry f) at barycentric point w. */
static double bake_seam_diff(const tt_mesh *mesh, const tt_lapped *l, const float *uv, const tt_image *atlas,
                             const tt_image *patch, int f, const double w[3])
{
    double au = 0, av = 0, pu = 0, pv = 0, diff = 0;
    float a[4], p[4];
    int k;
    for (k = 0; k < 3; k++) {
        int c = mesh->face_start[f] + k;
        au += w[k] * uv[2 * c];
        av += w[k] * uv[2 * c + 1];
        pu += w[k] * l->uv[6 * f + 2 * k];
        pv += w[k] * l->uv[6 * f + 2 * k + 1];
    }
    tt_image_sample_bilinear(atlas, (float)(au * atlas->width), (float)((1 - av) * atlas->height), a);
    tt_image_sample_bilinear(patch, (float)(pu * patch->width), (float)((1 - pv) * patch->height), p);
    for (k = 0; k < 3; k++) diff += fabs(a[k] - p[k]) / 3;
    return diff;
}

/* "No chart seams": the baked atlas read through the atlas UVs matches the
   patch read through the paste UVs, everywhere and right at the edges; the
   gutter does better at the edges than no gutter. */
static void test_lapped_bake_seams(void)
{
    tt_mesh *mesh;
    float *uv;
    tt_image checker = bake_checker(64, 64, 8), atlas;
    lb_builder b;
    tt_error err;
    double m[4] = {1.0 / 8, 0, 0, 1.0 / 8}, o[2] = {0, 0}, sum_all = 0, sum_edge = 0, sum_nogutter = 0;
    int size = 512, n_all = 0, n_edge = 0, ne = 0, i;
    lcg_seed(7);
    mesh = bake_grid(8, 8, 0.6, NULL);
    uv = (float *)malloc(sizeof(float) * 2 * (size_t)mesh->ncorners);
    CHECK(tt_atlas_pack_pairs(mesh, size, 2, uv, &err) == TT_OK, "pack: %s", err.message);
    lb_init(&b);
    lb_paste_all(&b, mesh, 0, m, o);
    tt_image_create(&atlas, size, size, NULL);
    CHECK(tt_lapped_bake(mesh, &b.l, &checker, 1, uv, 2, &atlas, &err) == TT_OK, "bake: %s", err.message);
    for (i = 0; i < 20000; i++) {
        int f = lcg_below(mesh->nfaces);
        double r1 = lcg_unit(), r2 = lcg_unit(), w[3], diff;
        if (r1 + r2 > 1) { r1 = 1 - r1; r2 = 1 - r2; }
        w[0] = 1 - r1 - r2; w[1] = r1; w[2] = r2;
        /* Half of the points hug an edge: push one weight to almost 0. */
        if (i & 1) {
            double s;
            w[i % 3] = 0.002 * lcg_unit();
            s = w[0] + w[1] + w[2];
            w[0] /= s; w[1] /= s; w[2] /= s;
        }
        diff = bake_seam_diff(mesh, &b.l, uv, &atlas, &checker, f, w);
        sum_all += diff;
        n_all++;
        if (fmin(w[0], fmin(w[1], w[2])) < 0.01) { sum_edge += diff; n_edge++; }
    }
    CHECK(sum_all / n_all < 0.02, "mean abs difference %g", sum_all / n_all);
    CHECK(n_edge > 5000 && sum_edge / n_edge < 0.02, "near edges: mean abs difference %g over %d",
          n_edge ? sum_edge / n_edge : -1.0, n_edge);
    /* Without gutters the same edge samples read the fill's copies: the
       gutter must do better than that. */
    CHECK(tt_lapped_bake(mesh, &b.l, &checker, 1, uv, 0, &atlas, &err) == TT_OK, "bake without gutter: %s",
          err.message);
    lcg_seed(99);
    for (i = 0; i < 10000; i++) {
        int f = lcg_below(mesh->nfaces);
        double w[3], r;
        w[0] = 0.002 * lcg_unit();
        r = lcg_unit();
        w[1] = (1 - w[0]) * r;
        w[2] = 1 - w[0] - w[1];
        sum_nogutter += bake_seam_diff(mesh, &b.l, uv, &atlas, &checker, f, w);
        ne++;
    }
    sum_nogutter /= ne;
    CHECK(n_edge > 0 && sum_nogutter >= sum_edge / n_edge, "gutter helps at edges: %g with, %g without",
          n_edge ? sum_edge / n_edge : -1.0, sum_nogutter);
    free(uv);
    lb_free(&b);
    tt_image_free(&atlas);
    tt_image_free(&checker);
    tt_mesh_free(mesh);
}

/* Two faces with the same atlas triangle: the later face's pastes win. */
static void test_lapped_bake_order(void)
{
    float uv[12] = {0.1f, 0.1f, 0.9f, 0.1f, 0.9f, 0.9f, 0.1f, 0.1f, 0.9f, 0.1f, 0.9f, 0.9f};
    float puv[6] = {0, 0, 1, 0, 1, 1};
    tt_mesh *mesh = bake_grid(1, 1, 0.0, NULL);
    tt_image patches[2], atlas;
    lb_builder b;
    tt_error err;
    const float *p;
    patches[0] = bake_constant(4, 4, 1, 0, 0, 1);
    patches[1] = bake_constant(4, 4, 0, 1, 0, 1);
    lb_init(&b);
    lb_begin(&b, 1);
    lb_add(&b, 1, puv);     /* green on face 1 */
    lb_begin(&b, 0);
    lb_add(&b, 0, puv);     /* red on face 0, pasted later, but face 1 is drawn later */
    tt_image_create(&atlas, 20, 20, NULL);
    CHECK(tt_lapped_bake(mesh, &b.l, patches, 2, uv, 1, &atlas, &err) == TT_OK, "bake: %s", err.message);
    p = atlas.pixels + 4 * (12 * 20 + 14);
    CHECK(p[1] == 1.0f && p[0] == 0.0f, "face 1 (green) wins, got %g %g %g", p[0], p[1], p[2]);
    lb_free(&b);
    tt_image_free(&atlas);
    tt_image_free(&patches[0]);
    tt_image_free(&patches[1]);
    tt_mesh_free(mesh);
}

static void test_lapped_bake_errors(void)
{
    tt_mesh *mesh = bake_grid(1, 1, 0.0, NULL), *qm;
    float uv[12], quv[8] = {0, 0, 1, 0, 1, 1, 0, 1};
    double id[4] = {1, 0, 0, 1}, zero[2] = {0, 0};
    tt_image red = bake_constant(4, 4, 1, 0, 0, 1), atlas, empty;
    lb_builder b;
    tt_error err;
    bake_square_uvs(mesh, 0.1, 0.9, uv);
    lb_init(&b);
    lb_paste_all(&b, mesh, 0, id, zero);
    tt_image_create(&atlas, 16, 16, NULL);
    memset(&empty, 0, sizeof empty);

    CHECK(tt_lapped_bake(NULL, &b.l, &red, 1, uv, 1, &atlas, &err) == TT_ERROR_INVALID_ARGUMENT, "NULL mesh");
    CHECK(tt_lapped_bake(mesh, NULL, &red, 1, uv, 1, &atlas, &err) == TT_ERROR_INVALID_ARGUMENT, "NULL lapped");
    CHECK(tt_lapped_bake(mesh, &b.l, NULL, 1, uv, 1, &atlas, &err) == TT_ERROR_INVALID_ARGUMENT, "NULL patches");
    CHECK(tt_lapped_bake(mesh, &b.l, &red, 1, NULL, 1, &atlas, &err) == TT_ERROR_INVALID_ARGUMENT, "NULL uv");
    CHECK(tt_lapped_bake(mesh, &b.l, &red, 1, uv, 1, NULL, &err) == TT_ERROR_INVALID_ARGUMENT, "NULL atlas");
    CHECK(tt_lapped_bake(mesh, &b.l, &red, 1, uv, 1, &empty, &err) == TT_ERROR_INVALID_ARGUMENT, "empty atlas");
    CHECK(tt_lapped_bake(mesh, &b.l, &red, 0, uv, 1, &atlas, &err) == TT_ERROR_INVALID_ARGUMENT, "npatches 0");
    CHECK(tt_lapped_bake(mesh, &b.l, &empty, 1, uv, 1, &atlas, &err) == TT_ERROR_INVALID_ARGUMENT, "empty patch");
    CHECK(tt_lapped_bake(mesh, &b.l, &red, 1, uv, -1, &atlas, &err) == TT_ERROR_INVALID_ARGUMENT, "gutter -1");

    b.l.pastes[0].patch = 1;
    CHECK(tt_lapped_bake(mesh, &b.l, &red, 1, uv, 1, &atlas, &err) == TT_ERROR_INDEX_OUT_OF_RANGE,
          "patch out of range: %s", err.message);
    b.l.pastes[0].patch = -1;
    CHECK(tt_lapped_bake(mesh, &b.l, &red, 1, uv, 1, &atlas, &err) == TT_ERROR_INDEX_OUT_OF_RANGE, "patch -1");
    b.l.pastes[0].patch = 0;
    b.l.pastes[0].nfaces = 3;
    CHECK(tt_lapped_bake(mesh, &b.l, &red, 1, uv, 1, &atlas, &err) == TT_ERROR_INDEX_OUT_OF_RANGE,
          "entries out of range: %s", err.message);
    b.l.pastes[0].nfaces = 2;
    b.l.faces[1] = 2;
    CHECK(tt_lapped_bake(mesh, &b.l, &red, 1, uv, 1, &atlas, &err) == TT_ERROR_INDEX_OUT_OF_RANGE && err.face == 2,
          "face out of range, named: %s", err.message);
    b.l.faces[1] = 1;
    b.l.uv[3] = (float)tt__not_a_number();
    CHECK(tt_lapped_bake(mesh, &b.l, &red, 1, uv, 1, &atlas, &err) == TT_ERROR_NON_FINITE && err.face == 0,
          "NaN paste uv, face named: %s", err.message);
    b.l.uv[3] = 0.0f;
    uv[7] = tt__infinity();
    CHECK(tt_lapped_bake(mesh, &b.l, &red, 1, uv, 1, &atlas, &err) == TT_ERROR_NON_FINITE && err.corner == 3,
          "infinite atlas uv, corner named: %s", err.message);
    bake_square_uvs(mesh, 0.1, 0.9, uv);
    CHECK(tt_lapped_bake(mesh, &b.l, &red, 1, uv, 1, &atlas, &err) == TT_OK, "fixed: %s", err.message);
    b.l.nentries = -1;
    CHECK(tt_lapped_bake(mesh, &b.l, &red, 1, uv, 1, &atlas, &err) == TT_ERROR_INVALID_ARGUMENT, "nentries -1");
    b.l.nentries = 2;
    lb_free(&b);

    qm = bake_quad();
    lb_init(&b);
    CHECK(tt_lapped_bake(qm, &b.l, &red, 1, quv, 1, &atlas, &err) == TT_ERROR_INVALID_ARGUMENT && err.face == 0,
          "quads refused, face 0 named: %s", err.message);
    tt_mesh_free(qm);
    tt_image_free(&atlas);
    tt_image_free(&red);
    tt_mesh_free(mesh);
}

typedef struct bake_oom_ctx {
    const tt_mesh *mesh;      /* built with the sweep's allocator */
    const tt_lapped *lapped;
    const tt_image *patch;
    const float *uv;
    tt_image *atlas;
} bake_oom_ctx;

static tt_result bake_oom_call(void *ctx, const tt_allocator *al)
{
    bake_oom_ctx *c = (bake_oom_ctx *)ctx;
    tt_error err;
    tt_result r;
    int i, n = 4 * c->atlas->width * c->atlas->height;
    (void)al;   /* tt_lapped_bake allocates from the mesh's allocator: the same one */
    for (i = 0; i < n; i++) c->atlas->pixels[i] = 0.25f;
    r = tt_lapped_bake(c->mesh, c->lapped, c->patch, 1, c->uv, 1, c->atlas, &err);
    if (r != TT_OK) {
        if (err.result != r) return TT_RESULT_MAX_ENUM;
        for (i = 0; i < n; i++)   /* all memory is taken before the atlas is touched */
            if (c->atlas->pixels[i] != 0.25f) return TT_RESULT_MAX_ENUM;
    }
    return r;
}

static void test_lapped_bake_oom(void)
{
    tt_mesh *mesh;
    float uv[2 * 3 * 32];
    double m[4] = {0.25, 0, 0, 0.25}, zero[2] = {0, 0};
    tt_image red = bake_constant(4, 4, 1, 0, 0, 1), atlas;
    lb_builder b;
    bake_oom_ctx c;
    tt_error err;
    lcg_seed(31);
    oom_reset();
    mesh = bake_grid(4, 4, 0.3, &g_oom_allocator);
    if (!mesh) return;
    CHECK(tt_atlas_pack_pairs(mesh, 64, 1, uv, &err) == TT_OK, "pack: %s", err.message);
    lb_init(&b);
    lb_paste_all(&b, mesh, 0, m, zero);
    tt_image_create(&atlas, 64, 64, NULL);
    c.mesh = mesh;
    c.lapped = &b.l;
    c.patch = &red;
    c.uv = uv;
    c.atlas = &atlas;
    oom_sweep("tt_lapped_bake", bake_oom_call, &c, TT_OK);
    CHECK(g_oom_counter.calls == 5, "tt_lapped_bake: 5 allocations, got %ld", g_oom_counter.calls);
    tt_mesh_free(mesh);
    CHECK(g_oom_counter.live == 0 && g_oom_counter.bad_frees == 0, "all freed (%ld live, %ld bad frees)",
          g_oom_counter.live, g_oom_counter.bad_frees);
    lb_free(&b);
    tt_image_free(&atlas);
    tt_image_free(&red);
}

/* A sliver far thinner than a texel, a degenerate triangle and one with UVs
   far outside the atlas: no crash; without pastes the big one leaves the
   atlas transparent, with one it is red everywhere. */
static void test_lapped_bake_thin(void)
{
    float uv[18] = {0.1f, 0.1f, 0.9f, 0.9f, 0.1f, 0.1000001f,
                    0.5f, 0.5f, 0.5f, 0.5f, 0.5f, 0.5f,
                    -3000.0f, -3000.0f, 3000.0f, -3000.0f, 0.0f, 3000.0f};
    float puv[6] = {0, 0, 1, 0, 0, 1};
    tt_mesh *mesh = bake_three(6, 3);
    tt_image red = bake_constant(4, 4, 1, 0, 0, 1), atlas;
    lb_builder b;
    tt_error err;
    int i, bad = 0;
    lb_init(&b);
    lb_begin(&b, 0);
    lb_add(&b, 0, puv);
    lb_add(&b, 1, puv);
    tt_image_create(&atlas, 32, 32, NULL);
    CHECK(tt_lapped_bake(mesh, &b.l, &red, 1, uv, 4, &atlas, &err) == TT_OK, "bake: %s", err.message);
    for (i = 0; i < 32 * 32 * 4; i++) bad += atlas.pixels[i] != 0.0f;
    CHECK(bad == 0, "face 2 without pastes covers the atlas: transparent (%d values off)", bad);
    lb_add(&b, 2, puv);
    CHECK(tt_lapped_bake(mesh, &b.l, &red, 1, uv, 4, &atlas, &err) == TT_OK, "bake: %s", err.message);
    bad = 0;
    for (i = 0; i < 32 * 32; i++) bad += atlas.pixels[4 * i] != 1.0f || atlas.pixels[4 * i + 3] != 1.0f;
    CHECK(bad == 0, "face 2 pasted red: all red (%d texels off)", bad);
    lb_free(&b);
    tt_image_free(&atlas);
    tt_image_free(&red);
    tt_mesh_free(mesh);
}

/* ------------------------------------------------------------------------ */
/* main                                                                     */
/* ------------------------------------------------------------------------ */

int main(void)
{
    RUN(test_rng);
    RUN(test_builder_valid);
    RUN(test_builder_errors);
    RUN(test_builder_oom);
    RUN(test_queries);
    RUN(test_queries_oom);
    RUN(test_quadrangulate);
    RUN(test_quadrangulate_direct);
    RUN(test_image_basics);
    RUN(test_rotate);
    RUN(test_over_downsample);
    RUN(test_min_error_cut);
    RUN(test_cg_triplets);
    RUN(test_cg_triplet_errors);
    RUN(test_cg_multiply);
    RUN(test_cg_random_spd);
    RUN(test_cg_grid);
    RUN(test_cg_progress);
    RUN(test_cg_errors);
    RUN(test_cg_oom);
    RUN(test_field_default);
    RUN(test_field_fallback);
    RUN(test_field_constraints);
    RUN(test_field_errors);
    RUN(test_field_oom);
    RUN(test_patch_splotch);
    RUN(test_patch_seeds);
    RUN(test_patch_masks);
    RUN(test_patch_errors);
    RUN(test_patch_oom);
    RUN(test_lapped_plane);
    RUN(test_lapped_cover);
    RUN(test_lapped_determinism);
    RUN(test_lapped_patches);
    RUN(test_lapped_errors);
    RUN(test_lapped_oom);
    RUN(test_hull_shapes);
    RUN(test_hull_large);
    RUN(test_hull_area);
    RUN(test_hull_segment);
    RUN(test_hull_errors);
    RUN(test_hull_oom);
    RUN(test_lapped_measure);
    RUN(test_lapped_measure_errors);
    RUN(test_lapped_measure_oom);
    RUN(test_atlas_pack_pairs);
    RUN(test_atlas_pack_odd);
    RUN(test_atlas_pack_errors);
    RUN(test_lapped_bake_constant);
    RUN(test_lapped_bake_gutter);
    RUN(test_lapped_bake_seams);
    RUN(test_lapped_bake_order);
    RUN(test_lapped_bake_errors);
    RUN(test_lapped_bake_oom);
    RUN(test_lapped_bake_thin);
    RUN(test_raster_random);
    RUN(test_raster_cover);
    RUN(test_layout);
    RUN(test_tile_uv_index);
    RUN(test_boundaries_uvs);
    RUN(test_synthesis);
    RUN(test_histogram);
    RUN(test_seams);
    RUN(test_stretch);
    RUN(test_synth_errors);
    RUN(test_synth_oom);
    printf("%d passed, %d failed\n", g_passed, g_failed);
    return g_failed ? 1 : 0;
}
