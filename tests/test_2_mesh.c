/* tests/test_2_mesh.c - unit tests for section 2 of tiledtex.h: the mesh
   builder, queries and quadrangulation. Run by run_mesh_tests()
   (tests/test_common.c calls it). */
#include "test_common.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ------------------------------------------------------------------------ */
/* 2. Mesh: the builder                                                     */
/* ------------------------------------------------------------------------ */

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
        r = tt_mesh_build(&d, &al, &mesh, &err);
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
    tt_allocator al = make_allocator(&cnt, -1);
    tt_result r;
    memset(&err, 0x55, sizeof err);
    r = tt_mesh_build(&d, &al, &mesh, &err);
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
    r = tt_mesh_build(&d, &al, &mesh, NULL);
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
    tt_allocator al = make_allocator(&cnt, -1);
    tt_result r;
    d.flags = TT_MESH_PERMISSIVE;
    r = tt_mesh_build(&d, &al, &mesh, &err);
    CHECK(r == TT_OK, "%s (permissive): expected TT_OK, got %d (%s)", what, r, err.message);
    if (r == TT_OK) {
        tt_mesh_stats st;
        CHECK(mesh->repaired_edges >= min_repaired, "%s (permissive): repaired_edges expected >= %d, got %d", what,
              min_repaired, mesh->repaired_edges);
        CHECK((mesh->flags & TT_MESH_PERMISSIVE) != 0, "%s: mesh->flags should keep TT_MESH_PERMISSIVE", what);
        check_structure(mesh, m, what);
        CHECK(tt_mesh_compute_stats(mesh, &al, &st, NULL) == TT_OK, "%s: stats on a permissive mesh", what);
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
    r = tt_mesh_build(&d, NULL, NULL, &err);
    CHECK(r == TT_ERROR_INVALID_ARGUMENT, "out_mesh NULL: expected %d, got %d", TT_ERROR_INVALID_ARGUMENT, r);
    mesh = (tt_mesh *)&mesh;
    r = tt_mesh_build(NULL, NULL, &mesh, &err);
    CHECK(r == TT_ERROR_INVALID_ARGUMENT && mesh == NULL, "desc NULL: expected %d, got %d", TT_ERROR_INVALID_ARGUMENT, r);
    d.indices = NULL;
    r = tt_mesh_build(&d, NULL, &mesh, &err);
    CHECK(r == TT_ERROR_INVALID_ARGUMENT && mesh == NULL, "indices NULL: got %d", r);
    d = tm_desc(&m);
    d.positions = NULL;
    r = tt_mesh_build(&d, NULL, &mesh, &err);
    CHECK(r == TT_ERROR_INVALID_ARGUMENT && mesh == NULL, "positions NULL: got %d", r);
    d = tm_desc(&m);
    d.nverts = -1;
    r = tt_mesh_build(&d, NULL, &mesh, &err);
    CHECK(r == TT_ERROR_INVALID_ARGUMENT && mesh == NULL, "nverts -1: got %d", r);
    d = tm_desc(&m);
    d.nfaces = -3;
    r = tt_mesh_build(&d, NULL, &mesh, &err);
    CHECK(r == TT_ERROR_INVALID_ARGUMENT && mesh == NULL, "nfaces -3: got %d", r);
    d = tm_desc(&m);
    d.face_sizes = NULL;
    d.fixed_face_size = 2;
    r = tt_mesh_build(&d, NULL, &mesh, &err);
    CHECK(r == TT_ERROR_FACE_TOO_SMALL && mesh == NULL, "fixed_face_size 2: expected %d, got %d",
          TT_ERROR_FACE_TOO_SMALL, r);
    /* fixed_face_size 0 means triangles */
    d = tm_desc(&m);
    d.face_sizes = NULL;
    d.fixed_face_size = 0;
    r = tt_mesh_build(&d, NULL, &mesh, &err);
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
            tt_mesh_compute_stats(mesh, NULL, &st, NULL);
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

typedef struct build_ctx {
    const tmesh *m;
    unsigned flags;
} build_ctx;

static tt_result oom_build(void *ctx, const tt_allocator *al, tt_error *error)
{
    build_ctx *b = (build_ctx *)ctx;
    tt_mesh_desc d = tm_desc(b->m);
    tt_mesh *mesh = (tt_mesh *)&mesh;
    tt_result r;
    d.flags = b->flags;
    r = tt_mesh_build(&d, al, &mesh, error);
    if (r == TT_OK) tt_mesh_free(mesh);
    else if (mesh != NULL) return TT_RESULT_MAX_ENUM;   /* must be NULL on failure */
    if (r != TT_OK && error->result != r) return TT_RESULT_MAX_ENUM;
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
    tt_allocator al = make_allocator(&cnt, -1);
    r = tt_mesh_build(&d, &al, &mesh, &err);
    CHECK(r == TT_OK, "%s: build failed: %d (%s)", name, r, err.message);
    if (r != TT_OK) return;
    r = tt_mesh_compute_stats(mesh, &al, &st, &err);
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
        for (nb = 1; nb <= 64; nb = nb < 8 ? nb + 1 : nb * 2) {
            int k;
            memset(nhist, 0, sizeof nhist);
            for (v = 0; v < mesh->nverts; v++)
                if (mesh->vert_corner[v] >= 0) nhist[naive[v] < nb - 1 ? naive[v] : nb - 1]++;
            for (k = 0; k < 64; k++) hist[k] = -7;
            r = tt_mesh_valence_histogram(mesh, &al, hist, nb, NULL);
            bad = 0;
            total = 0;
            for (k = 0; k < nb; k++) { bad += hist[k] != nhist[k]; total += hist[k]; }
            for (k = nb; k < 64; k++) bad += hist[k] != -7;   /* no write past nbins */
            CHECK(r == TT_OK && bad == 0 && total == st.used_vertices,
                  "%s: valence histogram with %d bins: %d bins differ from the naive one (total %d, used %d)", name, nb,
                  bad, total, st.used_vertices);
        }
        CHECK(tt_mesh_valence_histogram(mesh, &al, hist, 0, NULL) == TT_ERROR_INVALID_ARGUMENT,
              "%s: histogram with 0 bins should be rejected", name);
        CHECK(tt_mesh_valence_histogram(NULL, &al, hist, 4, NULL) == TT_ERROR_INVALID_ARGUMENT &&
                  tt_mesh_valence_histogram(mesh, &al, NULL, 4, NULL) == TT_ERROR_INVALID_ARGUMENT,
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
        r = tt_mesh_components(mesh, &al, comp, &n, NULL);
        CHECK(r == TT_OK && n == e->components, "%s: tt_mesh_components: expected %d, got %d (result %d)", name,
              e->components, n, r);
        for (f = 0; f < mesh->nfaces; f++) {
            int root = uf_find(parent, f);
            if (label[root] < 0) label[root] = next++;
            if (comp[f] != label[root]) bad++;
        }
        CHECK(bad == 0 && next == n, "%s: %d faces with a component id other than the naive one", name, bad);
        CHECK(tt_mesh_components(mesh, &al, NULL, &n, NULL) == TT_ERROR_INVALID_ARGUMENT, "%s: components(NULL)",
              name);
        free(comp);
        free(parent);
        free(label);
    }

    /* boundary loops: ids, count, and each boundary half-edge's successor
       (the boundary half-edge leaving its end vertex) is in the same loop */
    {
        int *loop = (int *)malloc(sizeof(int) * (size_t)mesh->ncorners);
        int n = -1, c, c2, bad = 0, nb = 0, *seen;
        r = tt_mesh_boundary_loops(mesh, loop, &n, NULL);
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
    CHECK(tt_mesh_compute_stats(NULL, &al, &st, NULL) == TT_ERROR_INVALID_ARGUMENT &&
              tt_mesh_compute_stats(mesh, &al, NULL, NULL) == TT_ERROR_INVALID_ARGUMENT,
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

static tt_result oom_stats(void *ctx, const tt_allocator *al, tt_error *error)
{
    tt_mesh_stats st;
    return tt_mesh_compute_stats(((mesh_ctx *)ctx)->mesh, al, &st, error);
}

static tt_result oom_histogram(void *ctx, const tt_allocator *al, tt_error *error)
{
    int hist[6];
    return tt_mesh_valence_histogram(((mesh_ctx *)ctx)->mesh, al, hist, 6, error);
}

static tt_result oom_components(void *ctx, const tt_allocator *al, tt_error *error)
{
    mesh_ctx *q = (mesh_ctx *)ctx;
    int *comp = (int *)malloc(sizeof(int) * (size_t)q->mesh->nfaces), n = -1;
    tt_result r = tt_mesh_components(q->mesh, al, comp, &n, error);
    free(comp);
    if (r == TT_OK && n != 2) return TT_RESULT_MAX_ENUM;   /* the grid part and the torus */
    return r;
}

static tt_result oom_quad(void *ctx, const tt_allocator *al, tt_error *error)
{
    mesh_ctx *q = (mesh_ctx *)ctx;
    tt_mesh *out = (tt_mesh *)&out;
    tt_result r = tt_mesh_quadrangulate(q->mesh, q->scheme, al, &out, error);
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
    r = tt_mesh_build(&d, NULL, &q.mesh, NULL);
    CHECK(r == TT_OK, "oom mesh: build got %d", r);
    if (r != TT_OK) { tm_free(&m); return; }
    oom_sweep("tt_mesh_compute_stats", oom_stats, &q, TT_OK);
    oom_sweep("tt_mesh_valence_histogram", oom_histogram, &q, TT_OK);
    oom_sweep("tt_mesh_components", oom_components, &q, TT_OK);
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
    tt_result r = tt_mesh_quadrangulate(mesh, scheme, NULL, &out, &err);
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
    CHECK(tt_mesh_compute_stats(a, NULL, &sa, NULL) == TT_OK && tt_mesh_compute_stats(b, NULL, &sb, NULL) == TT_OK,
          "%s: stats", name);
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
    if (tt_mesh_build(&d, NULL, &rebuilt, &err) != TT_OK) {
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
            if (tt_mesh_quadrangulate(mesh, TT_SUBDIVIDE_CATMULL_CLARK, NULL, &q, &err) == TT_OK) {
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
        CHECK(tt_mesh_quadrangulate(mesh, TT_SUBDIVIDE_LINEAR, NULL, &q, &err) == TT_OK, "permissive: %s",
              err.message);
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
        if (tt_mesh_build(&d, NULL, &mesh, &err) == TT_OK) {
            tt_result r = tt_mesh_quadrangulate(mesh, TT_SUBDIVIDE_LINEAR, NULL, &q, &err);
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
        CHECK(tt_mesh_build(&d, NULL, &mesh, &err) == TT_ERROR_FACE_TOO_SMALL && err.face == 1 && err.corner == -1,
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
        r = tt_mesh_quadrangulate(mesh, TT_SUBDIVIDE_CATMULL_CLARK, NULL, &q1, &err);
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
        r = tt_mesh_quadrangulate(mesh, TT_SUBDIVIDE_CATMULL_CLARK, NULL, &q1, &err);
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
        CHECK(tt_mesh_quadrangulate(mesh, (tt_subdivision)7, NULL, &q1, &err) == TT_ERROR_INVALID_ARGUMENT &&
                  q1 == NULL,
              "unknown scheme should be rejected with *out NULL");
        CHECK(tt_mesh_quadrangulate(mesh, TT_SUBDIVIDE_LINEAR, NULL, NULL, &err) == TT_ERROR_INVALID_ARGUMENT,
              "out_mesh NULL should be rejected");
        CHECK(tt_mesh_quadrangulate(NULL, TT_SUBDIVIDE_LINEAR, NULL, &q1, &err) == TT_ERROR_INVALID_ARGUMENT &&
                  q1 == NULL,
              "mesh NULL should be rejected");
        tt_mesh_free(mesh);
    }
    tm_free(&m);
    tt_mesh_free(NULL);   /* allowed */
}

/* ------------------------------------------------------------------------ */
/* 2d. The new contract: errors on NULL, the allocator parameter            */
/* ------------------------------------------------------------------------ */

/* A result and the error it filled: the same code, a non-empty sentence. */
static void expect_filled(tt_result r, const tt_error *err, tt_result code, const char *what)
{
    CHECK(r == code && err->result == code && err->message[0] != '\0' &&
              memchr(err->message, '\0', sizeof err->message) != NULL,
          "%s: expected %d with a message, got %d (err.result %d, \"%.60s\")", what, code, r, err->result,
          err->message[0] == 0x55 ? "(not written)" : err->message);
}

static void fresh_error(tt_error *err)
{
    memset(err, 0x55, sizeof *err);
    err->message[0] = '\0';
}

static void test_mesh_null_errors(void)
{
    tmesh m;
    tt_mesh *mesh = NULL, *out;
    tt_mesh_desc d;
    tt_mesh_stats st;
    tt_error err;
    int hist[8], comp[64], loops[64], n;
    memset(&m, 0, sizeof m);
    make_tetra(&m, 0);
    d = tm_desc(&m);
    if (tt_mesh_build(&d, NULL, &mesh, NULL) != TT_OK) { CHECK(0, "tetrahedron build"); tm_free(&m); return; }

    fresh_error(&err);
    expect_filled(tt_mesh_build(NULL, NULL, &out, &err), &err, TT_ERROR_INVALID_ARGUMENT, "tt_mesh_build(desc NULL)");
    fresh_error(&err);
    expect_filled(tt_mesh_build(&d, NULL, NULL, &err), &err, TT_ERROR_INVALID_ARGUMENT, "tt_mesh_build(out NULL)");

    fresh_error(&err);
    expect_filled(tt_mesh_compute_stats(NULL, NULL, &st, &err), &err, TT_ERROR_INVALID_ARGUMENT,
                  "tt_mesh_compute_stats(mesh NULL)");
    fresh_error(&err);
    expect_filled(tt_mesh_compute_stats(mesh, NULL, NULL, &err), &err, TT_ERROR_INVALID_ARGUMENT,
                  "tt_mesh_compute_stats(stats NULL)");

    fresh_error(&err);
    expect_filled(tt_mesh_valence_histogram(NULL, NULL, hist, 8, &err), &err, TT_ERROR_INVALID_ARGUMENT,
                  "tt_mesh_valence_histogram(mesh NULL)");
    fresh_error(&err);
    expect_filled(tt_mesh_valence_histogram(mesh, NULL, NULL, 8, &err), &err, TT_ERROR_INVALID_ARGUMENT,
                  "tt_mesh_valence_histogram(histogram NULL)");
    fresh_error(&err);
    expect_filled(tt_mesh_valence_histogram(mesh, NULL, hist, 0, &err), &err, TT_ERROR_INVALID_ARGUMENT,
                  "tt_mesh_valence_histogram(nbins 0)");

    fresh_error(&err);
    expect_filled(tt_mesh_components(NULL, NULL, comp, &n, &err), &err, TT_ERROR_INVALID_ARGUMENT,
                  "tt_mesh_components(mesh NULL)");
    fresh_error(&err);
    expect_filled(tt_mesh_components(mesh, NULL, NULL, &n, &err), &err, TT_ERROR_INVALID_ARGUMENT,
                  "tt_mesh_components(face_component NULL)");
    fresh_error(&err);
    expect_filled(tt_mesh_components(mesh, NULL, comp, NULL, &err), &err, TT_ERROR_INVALID_ARGUMENT,
                  "tt_mesh_components(ncomponents NULL)");

    fresh_error(&err);
    expect_filled(tt_mesh_boundary_loops(NULL, loops, &n, &err), &err, TT_ERROR_INVALID_ARGUMENT,
                  "tt_mesh_boundary_loops(mesh NULL)");
    fresh_error(&err);
    expect_filled(tt_mesh_boundary_loops(mesh, NULL, &n, &err), &err, TT_ERROR_INVALID_ARGUMENT,
                  "tt_mesh_boundary_loops(corner_loop NULL)");
    fresh_error(&err);
    expect_filled(tt_mesh_boundary_loops(mesh, loops, NULL, &err), &err, TT_ERROR_INVALID_ARGUMENT,
                  "tt_mesh_boundary_loops(nloops NULL)");

    fresh_error(&err);
    out = (tt_mesh *)&out;
    expect_filled(tt_mesh_quadrangulate(NULL, TT_SUBDIVIDE_LINEAR, NULL, &out, &err), &err, TT_ERROR_INVALID_ARGUMENT,
                  "tt_mesh_quadrangulate(mesh NULL)");
    CHECK(out == NULL, "tt_mesh_quadrangulate(mesh NULL): *out_mesh should be NULL");
    fresh_error(&err);
    expect_filled(tt_mesh_quadrangulate(mesh, TT_SUBDIVIDE_LINEAR, NULL, NULL, &err), &err,
                  TT_ERROR_INVALID_ARGUMENT, "tt_mesh_quadrangulate(out NULL)");
    fresh_error(&err);
    expect_filled(tt_mesh_quadrangulate(mesh, (tt_subdivision)9, NULL, &out, &err), &err, TT_ERROR_INVALID_ARGUMENT,
                  "tt_mesh_quadrangulate(scheme 9)");

    /* Success clears the error: result TT_OK, every place -1. */
    fresh_error(&err);
    CHECK(tt_mesh_compute_stats(mesh, NULL, &st, &err) == TT_OK && err.result == TT_OK && err.face == -1 &&
              err.corner == -1 && err.vertex == -1 && err.row == -1 && err.column == -1 && err.item == -1,
          "a successful call resets the error: result %d, face %d, row %d, item %d", err.result, err.face, err.row,
          err.item);
    tt_mesh_free(mesh);
    tm_free(&m);
}

/* The queries take their temporary memory from the allocator they are
   given, not from the one the mesh was built with, and give it all back. */
static void test_mesh_query_allocators(void)
{
    tmesh m;
    tt_mesh *mesh = NULL, *q = NULL;
    counter built, used;
    tt_allocator build_al = make_allocator(&built, -1), al;
    tt_mesh_desc d;
    tt_mesh_stats st;
    int hist[8], *comp, n = 0;
    long built_calls;
    memset(&m, 0, sizeof m);
    make_torus(&m, 6, 5, 3.0, 1.0);
    make_grid(&m, 2, 2);
    d = tm_desc(&m);
    if (tt_mesh_build(&d, &build_al, &mesh, NULL) != TT_OK) { CHECK(0, "build"); tm_free(&m); return; }
    built_calls = built.calls;
    comp = (int *)malloc(sizeof(int) * (size_t)mesh->nfaces);

    al = make_allocator(&used, -1);
    CHECK(tt_mesh_compute_stats(mesh, &al, &st, NULL) == TT_OK && st.components == 2, "stats: components %d",
          st.components);
    CHECK(used.calls > 0 && used.live == 0 && used.bad_frees == 0,
          "tt_mesh_compute_stats: %ld calls to its allocator (> 0 expected), %ld live", used.calls, used.live);

    al = make_allocator(&used, -1);
    CHECK(tt_mesh_components(mesh, &al, comp, &n, NULL) == TT_OK && n == 2, "components: %d", n);
    CHECK(used.calls > 0 && used.live == 0 && used.bad_frees == 0,
          "tt_mesh_components: %ld calls to its allocator (> 0 expected), %ld live", used.calls, used.live);

    al = make_allocator(&used, -1);
    CHECK(tt_mesh_valence_histogram(mesh, &al, hist, 8, NULL) == TT_OK && hist[4] == 30 + 1,
          "histogram: %d vertices of valence 4 (31 expected)", hist[4]);
    CHECK(used.calls > 0 && used.live == 0 && used.bad_frees == 0,
          "tt_mesh_valence_histogram: %ld calls to its allocator (> 0 expected), %ld live", used.calls, used.live);

    /* quadrangulate: the new mesh comes from (and remembers) the allocator given */
    al = make_allocator(&used, -1);
    CHECK(tt_mesh_quadrangulate(mesh, TT_SUBDIVIDE_LINEAR, &al, &q, NULL) == TT_OK && q, "quadrangulate");
    CHECK(used.live > 0, "the quadrangulated mesh should live in the allocator given (%ld live)", used.live);
    tt_mesh_free(q);
    CHECK(used.live == 0 && used.bad_frees == 0, "tt_mesh_free(quadrangulated): %ld live, %ld bad frees", used.live,
          used.bad_frees);
    CHECK(built.calls == built_calls, "the queries used the mesh's own allocator %ld times (none expected)",
          built.calls - built_calls);

    /* a failing allocator: clean TT_ERROR_OUT_OF_MEMORY from each */
    {
        tt_error err;
        tt_result r1, r2, r3;
        al = make_allocator(&used, 0);   /* each call's first allocation fails */
        r1 = tt_mesh_compute_stats(mesh, &al, &st, &err);
        used.calls = 0;
        r2 = tt_mesh_components(mesh, &al, comp, &n, NULL);
        used.calls = 0;
        r3 = tt_mesh_valence_histogram(mesh, &al, hist, 8, NULL);
        CHECK(r1 == TT_ERROR_OUT_OF_MEMORY && r2 == TT_ERROR_OUT_OF_MEMORY && r3 == TT_ERROR_OUT_OF_MEMORY &&
                  used.live == 0 && used.failures == 3,
              "queries with a failing allocator: expected TT_ERROR_OUT_OF_MEMORY, got %d %d %d, %ld live", r1, r2, r3,
              used.live);
    }
    free(comp);
    tt_mesh_free(mesh);
    CHECK(built.live == 0, "mesh: %ld allocations leaked", built.live);
    tm_free(&m);
}

/* ------------------------------------------------------------------------ */
/* Corner normals                                                           */
/* ------------------------------------------------------------------------ */

static double normal_dot(const float *a, const float *b)
{
    return (double)a[0] * b[0] + (double)a[1] * b[1] + (double)a[2] * b[2];
}

typedef struct normals_ctx {
    const tt_mesh *mesh;
    float *out;
} normals_ctx;

static tt_result oom_normals(void *ctx, const tt_allocator *al, tt_error *error)
{
    normals_ctx *c = (normals_ctx *)ctx;
    return tt_corner_normals(c->mesh, 45.0f, al, c->out, error);
}

/* tt_corner_normals against what they must be: a cube keeps its edges at 45
   degrees (each corner its face's normal) and rounds them at 180 (every
   corner the diagonal); a torus is smooth at 60 degrees, every corner of a
   vertex the same and within 2 degrees of the analytic normal; the same
   torus split into triangles gives the same normals (the angle weights);
   an open grid is written at every corner; bad angles are refused. */
static void test_corner_normals(void)
{
    tmesh m, t;
    tt_mesh *cube = NULL, *torus = NULL, *split = NULL, *grid = NULL;
    float *a = NULL, *b = NULL, face[3];
    tt_error err;
    int c, bad = 0, i;
    double worst = 1.0;
    memset(&m, 0, sizeof m);
    make_cube(&m, 0);
    CHECK(build(&m, 0, &cube, &err) == TT_OK, "cube: %s", err.message);
    tm_free(&m);
    memset(&m, 0, sizeof m);
    make_torus(&m, 24, 12, 3.0, 1.0);
    CHECK(build(&m, 0, &torus, &err) == TT_OK, "torus: %s", err.message);
    /* the same torus, each quad split into two triangles */
    memset(&t, 0, sizeof t);
    for (i = 0; i < m.nv; i++) tm_vert(&t, m.pos[3 * i], m.pos[3 * i + 1], m.pos[3 * i + 2]);
    for (i = 0; i < m.nf; i++) {
        const int *q = m.idx + 4 * i;
        tm_tri(&t, q[0], q[1], q[2]);
        tm_tri(&t, q[0], q[2], q[3]);
    }
    CHECK(build(&t, 0, &split, &err) == TT_OK, "split torus: %s", err.message);
    tm_free(&t);
    tm_free(&m);
    memset(&m, 0, sizeof m);
    make_grid(&m, 4, 3);
    CHECK(build(&m, 0, &grid, &err) == TT_OK, "grid: %s", err.message);
    tm_free(&m);
    if (!cube || !torus || !split || !grid) goto done;
    a = (float *)malloc(sizeof(float) * 3 * (size_t)split->ncorners);
    b = (float *)malloc(sizeof(float) * 3 * (size_t)split->ncorners);

    CHECK(tt_corner_normals(cube, 45.0f, NULL, a, &err) == TT_OK, "cube at 45: %s", err.message);
    for (c = 0; c < cube->ncorners; c++) {
        tt_face_normal(cube, cube->corner_face[c], face);
        bad += normal_dot(a + 3 * c, face) < 0.99999;
    }
    CHECK(bad == 0, "cube at 45 degrees: %d corners not their face's normal", bad);
    CHECK(tt_corner_normals(cube, 180.0f, NULL, a, &err) == TT_OK, "cube at 180: %s", err.message);
    for (bad = 0, c = 0; c < cube->ncorners; c++) {
        const float *p = cube->pos + 3 * cube->corner_vert[c];
        float centre[3] = {0.5f, 0.5f, 0.5f}, d[3];
        double length;
        for (i = 0; i < 3; i++) d[i] = p[i] - centre[i];
        length = sqrt(normal_dot(d, d));
        bad += normal_dot(a + 3 * c, d) / length < 0.99999;
    }
    CHECK(bad == 0, "cube at 180 degrees: %d corners off the diagonal through their vertex", bad);

    CHECK(tt_corner_normals(torus, 60.0f, NULL, a, &err) == TT_OK, "torus: %s", err.message);
    for (bad = 0, c = 0; c < torus->ncorners; c++) {
        const float *p = torus->pos + 3 * torus->corner_vert[c];
        /* the analytic normal: from the nearest point of the centre circle */
        double ring = sqrt((double)p[0] * p[0] + (double)p[1] * p[1]), n[3], length, dot;
        float nf[3];
        n[0] = p[0] - 3.0 * p[0] / ring;
        n[1] = p[1] - 3.0 * p[1] / ring;
        n[2] = p[2];
        length = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        for (i = 0; i < 3; i++) nf[i] = (float)(n[i] / length);
        dot = normal_dot(a + 3 * c, nf);
        if (dot < worst) worst = dot;
        bad += normal_dot(a + 3 * c, a + 3 * torus->vert_corner[torus->corner_vert[c]]) < 0.999999;
    }
    CHECK(bad == 0 && worst > cos(2.0 * 3.14159265358979 / 180.0),
          "torus at 60 degrees: %d corners differ from their vertex's other corners; worst angle to the true "
          "normal %.3f degrees (want under 2, the mesh is coarse)", bad, acos(worst < 1.0 ? worst : 1.0) * 180.0 / 3.14159265358979);
    /* split into triangles: per vertex the same normal as the quads give */
    CHECK(tt_corner_normals(split, 60.0f, NULL, b, &err) == TT_OK, "split torus: %s", err.message);
    for (bad = 0, c = 0; c < split->ncorners; c++) {
        int v = split->corner_vert[c];
        bad += normal_dot(b + 3 * c, a + 3 * torus->vert_corner[v]) < 0.999999;
    }
    CHECK(bad == 0, "the torus split into triangles: %d corners differ from the quads' normals", bad);
    /* flat at 0 degrees: each corner its face's normal */
    CHECK(tt_corner_normals(torus, 0.0f, NULL, a, &err) == TT_OK, "torus at 0: %s", err.message);
    for (bad = 0, c = 0; c < torus->ncorners; c++) {
        tt_face_normal(torus, torus->corner_face[c], face);
        bad += normal_dot(a + 3 * c, face) < 0.99999;
    }
    CHECK(bad == 0, "torus at 0 degrees: %d corners not flat", bad);

    /* an open grid: every corner written, all (0, 0, 1) */
    for (c = 0; c < 3 * grid->ncorners; c++) a[c] = -7.0f;
    CHECK(tt_corner_normals(grid, 30.0f, NULL, a, &err) == TT_OK, "grid: %s", err.message);
    for (bad = 0, c = 0; c < grid->ncorners; c++)
        bad += !(fabs(a[3 * c]) < 1e-6 && fabs(a[3 * c + 1]) < 1e-6 && fabs(a[3 * c + 2] - 1.0) < 1e-6);
    CHECK(bad == 0, "open grid: %d corners not (0, 0, 1)", bad);

    /* errors */
    CHECK(tt_corner_normals(NULL, 30.0f, NULL, a, &err) == TT_ERROR_INVALID_ARGUMENT, "NULL mesh refused");
    CHECK(tt_corner_normals(grid, 30.0f, NULL, NULL, &err) == TT_ERROR_INVALID_ARGUMENT, "NULL output refused");
    CHECK(tt_corner_normals(grid, -1.0f, NULL, a, &err) == TT_ERROR_INVALID_ARGUMENT &&
              strstr(err.message, "crease") != NULL, "crease -1 refused: %s", err.message);
    CHECK(tt_corner_normals(grid, 181.0f, NULL, a, NULL) == TT_ERROR_INVALID_ARGUMENT, "crease 181 refused");
    CHECK(tt_corner_normals(grid, (float)NAN, NULL, a, NULL) == TT_ERROR_INVALID_ARGUMENT, "crease NaN refused");
    {
        normals_ctx ctx;
        ctx.mesh = torus;
        ctx.out = a;
        oom_reset();
        oom_sweep("tt_corner_normals", oom_normals, &ctx, TT_OK);
    }
done:
    free(a);
    free(b);
    tt_mesh_free(cube);
    tt_mesh_free(torus);
    tt_mesh_free(split);
    tt_mesh_free(grid);
}

/* ------------------------------------------------------------------------ */
/* 2d. Quadrangulation's sources: per-corner attributes carried through     */
/* ------------------------------------------------------------------------ */

/* The positions of mesh's corners (each its vertex's), 3 floats per corner. */
static float *corner_positions(const tt_mesh *mesh)
{
    float *out = (float *)malloc(sizeof(float) * 3 * (size_t)mesh->ncorners);
    int c;
    for (c = 0; c < mesh->ncorners && out; c++) memcpy(out + 3 * c, mesh->pos + 3 * mesh->corner_vert[c], 3 * sizeof(float));
    return out;
}

/* Each corner's interpolated position (3 per corner) against the position
   of its vertex in `quads`; returns how many differ by more than tol. */
static int count_position_mismatches(const tt_mesh *quads, const float *interpolated, double tol)
{
    int c, k, bad = 0;
    for (c = 0; c < quads->ncorners; c++) {
        const float *p = quads->pos + 3 * quads->corner_vert[c];
        int off = 0;
        for (k = 0; k < 3; k++) off |= !near(interpolated[3 * c + k], p[k], tol);
        if (off && bad++ == 0)
            DETAIL("corner %d: interpolated (%g, %g, %g), its vertex %d is at (%g, %g, %g)", c, interpolated[3 * c],
                   interpolated[3 * c + 1], interpolated[3 * c + 2], quads->corner_vert[c], p[0], p[1], p[2]);
    }
    return bad;
}

/* The structure of one step's sources, checked naively: the rows, the
   weights, each new corner's sources within its own input face; then, by
   applying them, the linear quadrangulation's positions, a per-face value
   kept exactly (creases and seams stay), and random per-vertex values that
   give every corner of a new vertex the same value (per-vertex attributes
   follow too). Returns the sources (or NULL). */
static tt_corner_sources *check_sources_step(const tt_mesh *mesh, const char *name)
{
    tt_corner_sources *s = NULL;
    tt_mesh *linear = NULL, *smooth = NULL;
    tt_error err;
    float *in = NULL, *out = NULL, *vertex_value = NULL;
    int c, j, bad_rows = 0, bad_weights = 0, bad_face = 0, bad_layout = 0, bad_vertex = 0, v, k;
    CHECK(tt_mesh_quadrangulate_sources(mesh, NULL, &s, &err) == TT_OK && s, "%s: sources: %s", name, err.message);
    CHECK(tt_mesh_quadrangulate(mesh, TT_SUBDIVIDE_LINEAR, NULL, &linear, &err) == TT_OK, "%s: linear: %s", name,
          err.message);
    CHECK(tt_mesh_quadrangulate(mesh, TT_SUBDIVIDE_CATMULL_CLARK, NULL, &smooth, &err) == TT_OK, "%s: CC: %s", name,
          err.message);
    if (!s || !linear || !smooth) goto done;
    CHECK(s->ncorners == 4 * mesh->ncorners && s->input_corners == mesh->ncorners &&
              s->ncorners == linear->ncorners,
          "%s: %d new corners from %d (expected %d from %d)", name, s->ncorners, s->input_corners,
          linear->ncorners, mesh->ncorners);
    CHECK(s->source_start[0] == 0 && s->source_start[s->ncorners] == s->nsources, "%s: rows [%d, %d), %d sources",
          name, s->source_start[0], s->source_start[s->ncorners], s->nsources);
    for (c = 0; c < s->ncorners; c++) {
        int input = c / 4, face = mesh->corner_face[input], size = mesh->face_start[face + 1] - mesh->face_start[face];
        int expected = c % 4 == 0 ? 1 : c % 4 == 2 ? size : 2;
        double sum = 0.0;
        if (s->source_start[c + 1] - s->source_start[c] != expected) {
            if (bad_rows++ == 0)
                DETAIL("%s: corner %d has %d sources, expected %d", name, c, s->source_start[c + 1] - s->source_start[c],
                       expected);
            continue;
        }
        for (j = s->source_start[c]; j < s->source_start[c + 1]; j++) {
            sum += s->weights[j];
            bad_weights += !(s->weights[j] > 0.0f && s->weights[j] <= 1.0f);
            bad_face += s->source[j] < 0 || s->source[j] >= mesh->ncorners || mesh->corner_face[s->source[j]] != face;
        }
        bad_weights += !near(sum, 1.0, 1e-6);
        /* A single source of weight 1 is an old vertex: the same vertex in
           either scheme's mesh. */
        if (expected == 1)
            bad_layout += s->source[s->source_start[c]] != input ||
                          linear->corner_vert[c] != mesh->corner_vert[input] ||
                          smooth->corner_vert[c] != mesh->corner_vert[input];
        else
            bad_layout += linear->corner_vert[c] != smooth->corner_vert[c];
    }
    CHECK(bad_rows == 0, "%s: %d corners with the wrong number of sources", name, bad_rows);
    CHECK(bad_weights == 0, "%s: %d weights outside (0, 1] or rows not summing to 1", name, bad_weights);
    CHECK(bad_face == 0, "%s: %d sources outside the new corner's own input face", name, bad_face);
    CHECK(bad_layout == 0, "%s: %d corners disagree with tt_mesh_quadrangulate's layout", name, bad_layout);

    in = corner_positions(mesh);
    out = (float *)malloc(sizeof(float) * 4 * (size_t)s->ncorners);
    if (!in || !out) goto done;
    CHECK(tt_corner_sources_apply(s, 3, in, out, &err) == TT_OK, "%s: apply: %s", name, err.message);
    CHECK(count_position_mismatches(linear, out, 1e-5) == 0, "%s: interpolated corner positions are not the linear "
          "quadrangulation's", name);
    /* a per-face value (a crease, a UV island): every new corner keeps its face's */
    for (c = 0; c < mesh->ncorners; c++) in[c] = (float)(mesh->corner_face[c] * 3 + 1);
    CHECK(tt_corner_sources_apply(s, 1, in, out, &err) == TT_OK, "%s: apply 1: %s", name, err.message);
    for (bad_face = 0, c = 0; c < s->ncorners; c++) bad_face += !near(out[c], in[c / 4], 1e-5);
    CHECK(bad_face == 0, "%s: %d new corners lost their face's value", name, bad_face);
    /* random per-vertex values, 4 components: one value per new vertex */
    free(in);
    in = (float *)malloc(sizeof(float) * 4 * (size_t)mesh->ncorners);
    vertex_value = (float *)malloc(sizeof(float) * 4 * (size_t)mesh->nverts);
    if (!in || !vertex_value) goto done;
    lcg_seed(17);
    for (v = 0; v < 4 * mesh->nverts; v++) vertex_value[v] = (float)lcg_unit();
    for (c = 0; c < mesh->ncorners; c++) memcpy(in + 4 * c, vertex_value + 4 * mesh->corner_vert[c], 4 * sizeof(float));
    CHECK(tt_corner_sources_apply(s, 4, in, out, &err) == TT_OK, "%s: apply 4: %s", name, err.message);
    for (c = 0; c < s->ncorners; c++) {
        int first = linear->vert_corner[linear->corner_vert[c]];
        for (k = 0; k < 4; k++) bad_vertex += !near(out[4 * c + k], out[4 * first + k], 1e-6);
    }
    CHECK(bad_vertex == 0, "%s: %d per-vertex values differ between the corners of one new vertex", name,
          bad_vertex);
    for (bad_vertex = 0, v = 0; v < linear->nverts; v++) bad_vertex += linear->vert_corner[v] < 0;
    CHECK(bad_vertex == 0, "%s: %d new vertices without a corner", name, bad_vertex);
done:
    free(in);
    free(out);
    free(vertex_value);
    tt_mesh_free(linear);
    tt_mesh_free(smooth);
    return s;
}

typedef struct sources_ctx {
    const tt_mesh *mesh;
} sources_ctx;

static tt_result oom_sources(void *ctx, const tt_allocator *al, tt_error *error)
{
    tt_corner_sources *out = (tt_corner_sources *)&out;
    tt_result r = tt_mesh_quadrangulate_sources(((sources_ctx *)ctx)->mesh, al, &out, error);
    if (r == TT_OK) tt_corner_sources_free(out);
    else if (out != NULL) return TT_RESULT_MAX_ENUM;
    return r;
}

/* Quadrangulation's sources on meshes of several face sizes (triangles,
   quads, pentagons, open and closed), then twice in a row: each step's
   sources applied in turn carry the corners' positions to the twice
   linearly quadrangulated mesh. Errors, the allocator, and an
   allocation-failure sweep. */
static void test_quadrangulate_sources(void)
{
    tmesh m;
    tt_mesh *mesh = NULL, *q1 = NULL, *q2 = NULL;
    tt_corner_sources *s1 = NULL, *s2 = NULL, *s = NULL;
    tt_error err;
    int which;
    memset(&m, 0, sizeof m);
    for (which = 0; which < 5; which++) {
        const char *name = which == 0 ? "tetrahedron" : which == 1 ? "mixed" : which == 2 ? "open grid"
                         : which == 3 ? "torus" : "hexagon fan";
        if (which == 0) make_tetra(&m, 0);
        if (which == 1) make_mixed(&m);
        if (which == 2) { make_grid(&m, 3, 2); tm_tri(&m, 1, 0, tm_vert(&m, 0.5, -1, 0)); }
        if (which == 3) make_torus(&m, 5, 4, 3.0, 1.0);
        if (which == 4) {
            /* a hexagon and a triangle on each of its sides */
            int hex[6], i;
            for (i = 0; i < 6; i++) hex[i] = tm_vert(&m, cos(i * 1.0471975511965976), sin(i * 1.0471975511965976), 0.1 * i);
            tm_face(&m, 6, hex);
            for (i = 0; i < 6; i++)
                tm_tri(&m, hex[(i + 1) % 6], hex[i], tm_vert(&m, 2 * cos((i + 0.5) * 1.0471975511965976),
                                                               2 * sin((i + 0.5) * 1.0471975511965976), 0));
        }
        CHECK(build(&m, 0, &mesh, &err) == TT_OK, "%s: build: %s", name, err.message);
        tm_free(&m);
        if (!mesh) continue;
        s = check_sources_step(mesh, name);
        tt_corner_sources_free(s);
        tt_mesh_free(mesh);
        mesh = NULL;
    }

    /* two steps compose: mixed -> q1 -> q2, positions carried by s1 then s2 */
    make_mixed(&m);
    CHECK(build(&m, 0, &mesh, &err) == TT_OK, "mixed: %s", err.message);
    tm_free(&m);
    if (mesh && tt_mesh_quadrangulate(mesh, TT_SUBDIVIDE_LINEAR, NULL, &q1, &err) == TT_OK &&
        tt_mesh_quadrangulate(q1, TT_SUBDIVIDE_LINEAR, NULL, &q2, &err) == TT_OK &&
        tt_mesh_quadrangulate_sources(mesh, NULL, &s1, &err) == TT_OK &&
        tt_mesh_quadrangulate_sources(q1, NULL, &s2, &err) == TT_OK) {
        float *p0 = corner_positions(mesh);
        float *p1 = (float *)malloc(sizeof(float) * 3 * (size_t)s1->ncorners);
        float *p2 = (float *)malloc(sizeof(float) * 3 * (size_t)s2->ncorners);
        CHECK(s2->input_corners == s1->ncorners, "the second step reads %d corners, the first made %d",
              s2->input_corners, s1->ncorners);
        if (p0 && p1 && p2) {
            CHECK(tt_corner_sources_apply(s1, 3, p0, p1, &err) == TT_OK &&
                      tt_corner_sources_apply(s2, 3, p1, p2, &err) == TT_OK, "apply twice: %s", err.message);
            CHECK(count_position_mismatches(q2, p2, 1e-5) == 0, "two steps' sources do not carry positions to the "
                  "twice quadrangulated mesh");
        }
        free(p0);
        free(p1);
        free(p2);
    } else {
        CHECK(0, "mixed twice: %s", err.message);
    }
    tt_corner_sources_free(s2);
    s2 = NULL;

    if (mesh && s1) {
        float *in = corner_positions(mesh), *out = (float *)malloc(sizeof(float) * 3 * (size_t)s1->ncorners);
        tt_allocator half;
        counter used;
        int c;
        CHECK(in && out, "memory for the error cases");
        /* errors */
        s = (tt_corner_sources *)&s;
        CHECK(tt_mesh_quadrangulate_sources(NULL, NULL, &s, &err) == TT_ERROR_INVALID_ARGUMENT && s == NULL,
              "NULL mesh refused and *out cleared");
        CHECK(tt_mesh_quadrangulate_sources(mesh, NULL, NULL, &err) == TT_ERROR_INVALID_ARGUMENT, "NULL out refused");
        half = make_allocator(&used, -1);
        half.free = NULL;
        s = (tt_corner_sources *)&s;
        CHECK(tt_mesh_quadrangulate_sources(mesh, &half, &s, &err) == TT_ERROR_INVALID_ARGUMENT && s == NULL &&
                  strstr(err.message, "allocator") != NULL, "an allocator without free refused: %s", err.message);
        CHECK(tt_corner_sources_apply(NULL, 3, in, out, &err) == TT_ERROR_INVALID_ARGUMENT, "apply: NULL sources");
        CHECK(tt_corner_sources_apply(s1, 3, NULL, out, &err) == TT_ERROR_INVALID_ARGUMENT, "apply: NULL input");
        CHECK(tt_corner_sources_apply(s1, 3, in, NULL, &err) == TT_ERROR_INVALID_ARGUMENT, "apply: NULL output");
        CHECK(tt_corner_sources_apply(s1, 0, in, out, &err) == TT_ERROR_INVALID_ARGUMENT &&
                  msg_has_number(err.message, 0), "apply: 0 components refused: %s", err.message);
        CHECK(tt_corner_sources_apply(s1, 1, out, out, &err) == TT_ERROR_INVALID_ARGUMENT &&
                  strstr(err.message, "overlap") != NULL, "apply: input == output refused: %s", err.message);
        CHECK(tt_corner_sources_apply(s1, 1, out + s1->ncorners - 1, out, &err) == TT_ERROR_INVALID_ARGUMENT,
              "apply: the input inside the output refused");
        CHECK(tt_corner_sources_apply(s1, 1, out + 4 * (size_t)s1->input_corners, out, &err) == TT_OK,
              "apply: an input just past the output is fine: %s", err.message);
        /* input corner 5 (the bottom pentagon's first) is first read by new corner 20 */
        in[3 * 5 + 1] = (float)internal_not_a_number();
        CHECK(tt_corner_sources_apply(s1, 3, in, out, &err) == TT_ERROR_NON_FINITE && err.corner == 20,
              "apply: a NaN input is refused at the first corner it reaches (20, got %d): %s", err.corner,
              err.message);
        /* every value the largest float: the pentagon's weights, 1/5 rounded
           up, sum past 1, so its face point (new corner 2) overflows */
        for (c = 0; c < 3 * mesh->ncorners; c++) in[c] = FLT_MAX;
        CHECK(tt_corner_sources_apply(s1, 3, in, out, &err) == TT_ERROR_NON_FINITE && err.corner == 2,
              "apply at FLT_MAX: the face point overflows (corner 2, got %d): %s", err.corner, err.message);
        /* the allocator: the sources live in it and go back to it */
        {
            tt_allocator al = make_allocator(&used, -1);
            CHECK(tt_mesh_quadrangulate_sources(mesh, &al, &s, &err) == TT_OK && used.live == 4,
                  "the sources should be 4 allocations of the allocator given (%ld live)", used.live);
            tt_corner_sources_free(s);
            CHECK(used.live == 0 && used.bad_frees == 0, "tt_corner_sources_free: %ld live, %ld bad frees",
                  used.live, used.bad_frees);
        }
        tt_corner_sources_free(NULL);
        {
            sources_ctx ctx;
            ctx.mesh = mesh;
            oom_reset();
            oom_sweep("tt_mesh_quadrangulate_sources", oom_sources, &ctx, TT_OK);
        }
        free(in);
        free(out);
    }
    tt_corner_sources_free(s1);
    tt_mesh_free(q1);
    tt_mesh_free(q2);
    tt_mesh_free(mesh);
    mesh = NULL;

    /* a 32768-gon: 32768 * (5 + 32768) sources would pass the limit */
    {
        int n = 32768, i, *ring = (int *)malloc(sizeof(int) * (size_t)n);
        memset(&m, 0, sizeof m);
        for (i = 0; i < n && ring; i++) ring[i] = tm_vert(&m, cos(i * 6.283185307179586 / n), sin(i * 6.283185307179586 / n), 0);
        if (ring) tm_face(&m, n, ring);
        free(ring);
        CHECK(build(&m, 0, &mesh, &err) == TT_OK, "32768-gon: %s", err.message);
        tm_free(&m);
        s = (tt_corner_sources *)&s;
        if (mesh)
            CHECK(tt_mesh_quadrangulate_sources(mesh, NULL, &s, &err) == TT_ERROR_TOO_LARGE && s == NULL,
                  "a 32768-gon's sources are too many: got %s", err.message);
        tt_mesh_free(mesh);
    }
}

/* ---- tt_remesh_quads ---- */

/* An icosphere of radius r: an icosahedron with each triangle split into
   4^level and pushed onto the sphere. Its edges follow no direction. */
static void make_icosphere(tmesh *m, int level, double r)
{
    static const double t = 1.6180339887498949;
    static const int faces[20][3] = {{0, 11, 5}, {0, 5, 1}, {0, 1, 7}, {0, 7, 10}, {0, 10, 11}, {1, 5, 9},
                                     {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8}, {3, 9, 4}, {3, 4, 2},
                                     {3, 2, 6}, {3, 6, 8}, {3, 8, 9}, {4, 9, 5}, {2, 4, 11}, {6, 2, 10},
                                     {8, 6, 7}, {9, 8, 1}};
    double v[12][3] = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                       {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
    int f, n = 1 << level, i, j;
    for (f = 0; f < 20; f++) {
        const double *a = v[faces[f][0]], *b = v[faces[f][1]], *c = v[faces[f][2]];
        int row[65][65];
        for (i = 0; i <= n; i++)
            for (j = 0; i + j <= n; j++) {
                double p[3], len;
                int k;
                for (k = 0; k < 3; k++) p[k] = a[k] + (b[k] - a[k]) * i / n + (c[k] - a[k]) * j / n;
                len = sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
                row[i][j] = tm_vert(m, r * p[0] / len, r * p[1] / len, r * p[2] / len);
            }
        for (i = 0; i < n; i++)
            for (j = 0; i + j < n; j++) {
                tm_tri(m, row[i][j], row[i + 1][j], row[i][j + 1]);
                if (i + j + 1 < n) tm_tri(m, row[i + 1][j], row[i + 1][j + 1], row[i][j + 1]);
            }
    }
}

/* The icosphere above with shared vertices welded (the per-face grids
   repeat the edges' points): points sorted by their coordinates rounded to
   1e-5, equal neighbours merged. */
typedef struct weld_key {
    long long x, y, z;
    int index;
} weld_key;

static int weld_compare(const void *a, const void *b)
{
    const weld_key *p = (const weld_key *)a, *q = (const weld_key *)b;
    if (p->x != q->x) return p->x < q->x ? -1 : 1;
    if (p->y != q->y) return p->y < q->y ? -1 : 1;
    if (p->z != q->z) return p->z < q->z ? -1 : 1;
    return p->index - q->index;
}

static tt_result build_welded(const tmesh *m, tt_mesh **out, tt_error *err)
{
    tmesh w;
    int *map = (int *)malloc(sizeof(int) * (size_t)(m->nv + 1)), i, c;
    weld_key *keys = (weld_key *)malloc(sizeof(weld_key) * (size_t)(m->nv + 1));
    tt_result r;
    memset(&w, 0, sizeof w);
    for (i = 0; keys && i < m->nv; i++) {
        keys[i].x = llround(m->pos[3 * i] * 1e5);
        keys[i].y = llround(m->pos[3 * i + 1] * 1e5);
        keys[i].z = llround(m->pos[3 * i + 2] * 1e5);
        keys[i].index = i;
    }
    if (keys) qsort(keys, (size_t)m->nv, sizeof *keys, weld_compare);
    for (i = 0; keys && map && i < m->nv; i++) {
        const weld_key *k = &keys[i];
        if (i > 0 && k->x == keys[i - 1].x && k->y == keys[i - 1].y && k->z == keys[i - 1].z)
            map[k->index] = map[keys[i - 1].index];
        else
            map[k->index] = tm_vert(&w, m->pos[3 * k->index], m->pos[3 * k->index + 1], m->pos[3 * k->index + 2]);
    }
    for (c = 0; keys && map && c < m->nc; c += 3) tm_tri(&w, map[m->idx[c]], map[m->idx[c + 1]], map[m->idx[c + 2]]);
    r = build(&w, 0, out, err);
    tm_free(&w);
    free(map);
    free(keys);
    return r;
}

/* The projected up (0, 1, 0) on every face, and how firmly it holds: 0
   facing up or down, 1 on walls (tt_field_face_weights' rule, written
   out). With `random_field`, a random tangent direction of weight 1 on
   every face instead: the control. */
static void remesh_field(const tt_mesh *mesh, int random_field, float *vectors, float *weights)
{
    int f;
    lcg_seed(7);
    for (f = 0; f < mesh->nfaces; f++) {
        float n[3];
        double up[3] = {0.0, 1.0, 0.0}, p[3], len, t;
        int k;
        tt_face_normal(mesh, f, n);
        if (random_field) {
            double a[3] = {lcg_unit() - 0.5, lcg_unit() - 0.5, lcg_unit() - 0.5};
            for (k = 0; k < 3; k++) up[k] = a[k];
        }
        for (k = 0; k < 3; k++) p[k] = up[k] - (up[0] * n[0] + up[1] * n[1] + up[2] * n[2]) * n[k];
        len = sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
        for (k = 0; k < 3; k++) vectors[3 * f + k] = len > 0 ? (float)(p[k] / len) : 0.0f;
        t = (len - 0.1) / 0.4;
        t = t < 0 ? 0 : t > 1 ? 1 : t;
        weights[f] = random_field ? 1.0f : (float)(t * t * (3 - 2 * t));
    }
}

/* remesh_field's up field on new arrays (malloc): *vectors 3 floats per
   face, *weights one. */
static void remesh_field_new(const tt_mesh *mesh, float **vectors, float **weights)
{
    *vectors = (float *)malloc(sizeof(float) * 3 * (size_t)mesh->nfaces);
    *weights = (float *)malloc(sizeof(float) * (size_t)mesh->nfaces);
    remesh_field(mesh, 0, *vectors, *weights);
}

/* Options with this edge length and these face weights, the rest defaults. */
static tt_remesh_options remesh_options(float edge_length, const float *weights)
{
    tt_remesh_options o;
    memset(&o, 0, sizeof o);
    o.edge_length = edge_length;
    o.face_weights = weights;
    return o;
}

/* The welded icosphere of radius 1 at `level` (make_icosphere), or NULL
   after a failed CHECK. */
static tt_mesh *remesh_icosphere(int level)
{
    tmesh m;
    tt_mesh *mesh = NULL;
    tt_error err;
    memset(&m, 0, sizeof m);
    make_icosphere(&m, level, 1.0);
    CHECK(build_welded(&m, &mesh, &err) == TT_OK, "icosphere: %s", err.message);
    tm_free(&m);
    return mesh;
}

/* Of the edges of output faces on walls (normal within 45 degrees of
   horizontal), the share within 10 degrees of the projected up or across
   it; *median_edge gets the median edge length. */
static double remesh_aligned_share(const tt_mesh *q, double *median_edge)
{
    int f, c, aligned = 0, counted = 0, nlen = 0;
    double *len = (double *)malloc(sizeof(double) * (size_t)q->ncorners);
    for (f = 0; f < q->nfaces; f++) {
        float n[3];
        double up[3] = {0.0, 1.0, 0.0}, p[3], pl;
        int k;
        tt_face_normal(q, f, n);
        for (k = 0; k < 3; k++) p[k] = up[k] - n[1] * n[k];
        pl = sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
        for (c = q->face_start[f]; c < q->face_start[f + 1]; c++) {
            const float *a = q->pos + 3 * q->corner_vert[c], *b = q->pos + 3 * q->corner_vert[tt_mesh_next(q, c)];
            double e[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, el, cosine, angle;
            el = sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]);
            if (len) len[nlen++] = el;
            if (fabs(n[1]) > 0.7071 || el <= 0) continue;
            cosine = fabs(e[0] * p[0] + e[1] * p[1] + e[2] * p[2]) / (el * pl);
            angle = acos(cosine > 1 ? 1 : cosine) * 57.29577951308232;
            if (angle > 45) angle = 90 - angle;
            counted++;
            aligned += angle <= 10;
        }
    }
    *median_edge = len && nlen ? internal_median(len, nlen) : 0.0;
    free(len);
    return counted ? (double)aligned / counted : 0.0;
}

/* The share of wall quads (facing 45 degrees or more from up, +y) whose
   rows lie within 10 degrees of level, as the tile pipeline lays them:
   the rows are the pair of opposite sides further from up, their mean
   direction taken against the level direction in the quad's plane. */
static double remesh_rows_level_share(const tt_mesh *q)
{
    int f, walls = 0, level = 0;
    for (f = 0; f < q->nfaces; f++) {
        const int *v = q->corner_vert + q->face_start[f];
        double p[4][3], pair[2][3], along[2], up[3], ul;
        float n[3];
        int j, k;
        if (q->face_start[f + 1] - q->face_start[f] != 4) continue;
        tt_face_normal(q, f, n);
        if (fabs(n[1]) > 0.7071) continue;
        for (j = 0; j < 4; j++)
            for (k = 0; k < 3; k++) p[j][k] = q->pos[3 * v[j] + k];
        for (k = 0; k < 3; k++) {
            pair[0][k] = p[1][k] - p[0][k] + p[2][k] - p[3][k];
            pair[1][k] = p[3][k] - p[0][k] + p[2][k] - p[1][k];
            up[k] = (k == 1) - n[1] * n[k];
        }
        ul = sqrt(up[0] * up[0] + up[1] * up[1] + up[2] * up[2]);
        for (j = 0; j < 2; j++) {
            double l = sqrt(pair[j][0] * pair[j][0] + pair[j][1] * pair[j][1] + pair[j][2] * pair[j][2]);
            along[j] = l > 0 ? fabs(pair[j][0] * up[0] + pair[j][1] * up[1] + pair[j][2] * up[2]) / (l * ul) : 1.0;
        }
        walls++;
        level += asin(fmin(1.0, fmin(along[0], along[1]))) <= 10.0 / 57.29577951308232;
    }
    return walls ? (double)level / walls : 0.0;
}

/* Quads with a side more than `ratio` times another: a tile drawn into a streak. */
static int remesh_drawn_out(const tt_mesh *q, double ratio)
{
    int f, j, count = 0;
    for (f = 0; f < q->nfaces; f++) {
        double lo = HUGE_VAL, hi = 0.0;
        for (j = q->face_start[f]; j < q->face_start[f + 1]; j++) {
            const float *a = q->pos + 3 * q->corner_vert[j], *b = q->pos + 3 * q->corner_vert[tt_mesh_next(q, j)];
            double l = sqrt(((double)b[0] - a[0]) * (b[0] - a[0]) + ((double)b[1] - a[1]) * (b[1] - a[1]) +
                            ((double)b[2] - a[2]) * (b[2] - a[2]));
            lo = fmin(lo, l);
            hi = fmax(hi, l);
        }
        count += hi > ratio * lo;
    }
    return count;
}

/* The normal of triangle (o, o + e, o + e + f), for the fold test. */
static void remesh_cross(const double e[3], const double f[3], double out[3])
{
    out[0] = e[1] * f[2] - e[2] * f[1];
    out[1] = e[2] * f[0] - e[0] * f[2];
    out[2] = e[0] * f[1] - e[1] * f[0];
}

/* Quads folded: two corners on one point, or the two triangles on either
   diagonal facing apart. */
static int remesh_folded_quads(const tt_mesh *q)
{
    int f, folded = 0;
    for (f = 0; f < q->nfaces; f++) {
        const int *v = q->corner_vert + q->face_start[f];
        double e[4][3], a[3], b[3];
        int i, k, bad = 0;
        for (i = 0; i < 4; i++)
            for (k = 0; k < 3; k++) e[i][k] = (double)q->pos[3 * v[(i + 1) % 4] + k] - q->pos[3 * v[i] + k];
        for (i = 0; i < 4; i++) bad |= e[i][0] == 0.0 && e[i][1] == 0.0 && e[i][2] == 0.0;
        for (i = 0; i < 2; i++) {
            remesh_cross(e[i], e[i + 1], a);
            remesh_cross(e[i + 2], e[(i + 3) % 4], b);
            bad |= a[0] * b[0] + a[1] * b[1] + a[2] * b[2] < 0.0;
        }
        folded += bad;
    }
    return folded;
}

/* What tt_remesh_quads promises of every result: quads only, which
   tt_mesh_build accepts again (strict: no face of zero area), none with
   two corners at one point. Returns the interior vertices with two faces (doublets). */
static int remesh_check_clean(const tt_mesh *q, const char *what)
{
    tt_mesh_desc desc;
    tt_mesh *again = NULL;
    tt_error err;
    int f, v, c, k, same = 0, doublets = 0;
    int *count = (int *)calloc((size_t)q->nverts, sizeof(int));
    unsigned char *boundary = (unsigned char *)calloc((size_t)q->nverts, 1);
    if (!count || !boundary) {
        CHECK(0, "%s: out of memory", what);
        free(count); free(boundary);
        return -1;
    }
    CHECK(q->min_face_size == 4 && q->max_face_size == 4, "%s: faces of %d..%d sides", what, q->min_face_size,
          q->max_face_size);
    if (q->min_face_size == 4 && q->max_face_size == 4) {
        memset(&desc, 0, sizeof desc);
        desc.positions = q->pos;
        desc.nverts = q->nverts;
        desc.indices = q->corner_vert;
        desc.fixed_face_size = 4;
        desc.nfaces = q->nfaces;
        CHECK(tt_mesh_build(&desc, NULL, &again, &err) == TT_OK, "%s: the result builds again, strict: %s", what,
              err.message);
        tt_mesh_free(again);
    }
    for (f = 0; f < q->nfaces; f++)
        for (c = q->face_start[f]; c < q->face_start[f + 1]; c++)
            for (k = c + 1; k < q->face_start[f + 1]; k++)
                same += memcmp(q->pos + 3 * q->corner_vert[c], q->pos + 3 * q->corner_vert[k], 3 * sizeof(float)) == 0;
    CHECK(same == 0, "%s: %d pairs of a quad's corners at one point", what, same);
    for (c = 0; c < q->ncorners; c++) {
        count[q->corner_vert[c]]++;
        if (q->twin[c] < 0) boundary[q->corner_vert[c]] = 1;
    }
    for (v = 0; v < q->nverts; v++) doublets += count[v] == 2 && !boundary[v];
    free(count); free(boundary);
    return doublets;
}

static void test_remesh_sphere(void)
{
    tt_mesh *mesh = NULL, *q = NULL, *q2 = NULL;
    tt_error err;
    tt_remesh_options o;
    tt_remesh_report rep;
    tt_mesh_stats st;
    float *vec, *w;
    double median, share, control;
    int v, off = 0;
    mesh = remesh_icosphere(5);
    if (!mesh) return;
    remesh_field_new(mesh, &vec, &w);
    o = remesh_options(0.15f, w);
    CHECK(tt_remesh_quads(mesh, vec, &o, NULL, &q, &rep, &err) == TT_OK, "remesh: %s", err.message);
    if (q) {
        CHECK(tt_mesh_compute_stats(q, NULL, &st, &err) == TT_OK && st.genus == 0 && st.components == 1 &&
              st.boundary_loops == 0, "a sphere stays a closed sphere: genus %d, %d components, %d loops", st.genus,
              st.components, st.boundary_loops);
        CHECK(q->min_face_size == 4 && q->max_face_size == 4, "quads only: faces of %d to %d sides",
              q->min_face_size, q->max_face_size);
        /* The lattice (edges of 0.3 on a sphere of radius 1): rows of quads
           end every few steps as the circles of latitude shrink. */
        CHECK(rep.quads >= 2 * (rep.triangles + rep.pentagons + rep.larger_faces),
              "a lattice of mostly quads: %d quads, %d triangles, %d pentagons, %d larger", rep.quads,
              rep.triangles, rep.pentagons, rep.larger_faces);
        /* The lattice mended first: thin triangles joined to the face
           beyond their longest edge (28 here), then pairs of triangles on
           one edge, a square and its diagonal, made one quad (5). Few
           quads fold, where a group's cut cannot avoid it. */
        CHECK(rep.thin_triangles > 0 && rep.merged_triangles > 0, "lattice mended: %d thin triangles, %d pairs",
              rep.thin_triangles, rep.merged_triangles);
        v = remesh_folded_quads(q);
        CHECK(20 * v <= q->nfaces, "folded quads: %d of %d", v, q->nfaces);
        /* The odd faces paired into quads, none split: about one output
           quad per lattice face (a triangle and a pentagon make two, two
           triangles one, two pentagons three). */
        CHECK(!rep.split_all && rep.paired_faces >= rep.triangles + rep.pentagons &&
                  abs(q->nfaces + rep.merged_doublets - (rep.quads + rep.triangles + rep.pentagons)) <=
                      (rep.triangles + rep.pentagons) / 2 + 2 * rep.larger_faces,
              "lattice faces paired: %d triangles, %d quads, %d pentagons, %d larger, %d paired, %d quads out, "
              "split %d", rep.triangles, rep.quads, rep.pentagons, rep.larger_faces, rep.paired_faces, q->nfaces,
              rep.split_all);
        /* A vertex left with two quads that share both its edges makes
           each a wedge: the cuts reach such corners, and the merge takes
           what is left where the two make an unfolded quad. At most one in
           two hundred quads keeps one. */
        v = remesh_check_clean(q, "sphere");
        CHECK(200 * v <= q->nfaces, "doublets: %d left of %d quads, %d merged", v, q->nfaces, rep.merged_doublets);
        /* The icosphere's edges (about 0.04) are far below the 0.105 that
           extraction needs: it ran on a coarser level of the hierarchy. */
        CHECK(rep.refinements == 0 && rep.extracted_vertices < rep.working_vertices,
              "extracted from a coarser level: %d of %d vertices, %d refinements", rep.extracted_vertices,
              rep.working_vertices, rep.refinements);
        /* area 4 pi over 0.15^2: about 560 quads */
        CHECK(q->nfaces > 400 && q->nfaces < 750, "faces of about 0.15: %d", q->nfaces);
        share = remesh_aligned_share(q, &median);
        CHECK(median > 0.11 && median < 0.19, "median edge %.3f, asked 0.15", median);
        CHECK(share >= 0.85, "wall edges along or across up: %.3f", share);
        /* The rows of the pairing's quads kept level too: the field's
           lean in the cut, pairs sought along rows first (0.957 cut by
           shape alone, along the nearest path). */
        share = remesh_rows_level_share(q);
        CHECK(share >= 0.97, "wall quads with rows within 10 degrees of level: %.3f", share);
        /* On the input's faces: between the icosphere's flattest point and the sphere. */
        for (v = 0; v < q->nverts; v++) {
            const float *p = q->pos + 3 * v;
            double r = sqrt((double)p[0] * p[0] + (double)p[1] * p[1] + (double)p[2] * p[2]);
            off += r < 0.99 || r > 1.0 + 1e-5;
        }
        CHECK(off == 0, "vertices on the input's surface: %d of %d off", off, q->nverts);
        /* Deterministic. */
        CHECK(tt_remesh_quads(mesh, vec, &o, NULL, &q2, NULL, &err) == TT_OK, "again: %s", err.message);
        if (q2)
            CHECK(q2->nverts == q->nverts && q2->ncorners == q->ncorners &&
                  memcmp(q2->pos, q->pos, sizeof(float) * 3 * (size_t)q->nverts) == 0 &&
                  memcmp(q2->corner_vert, q->corner_vert, sizeof(int) * (size_t)q->ncorners) == 0,
                  "the same result twice");
        tt_mesh_free(q2);
        tt_mesh_free(q);
        q = NULL;
    }
    /* The control: a random direction on every face, held firmly. */
    remesh_field(mesh, 1, vec, w);
    CHECK(tt_remesh_quads(mesh, vec, &o, NULL, &q, &rep, &err) == TT_OK, "random field: %s", err.message);
    if (q) {
        control = remesh_aligned_share(q, &median);
        CHECK(control < 0.5, "a random field's edges do not follow up: %.3f", control);
    }
    tt_mesh_free(q);
    free(vec);
    free(w);
    tt_mesh_free(mesh);
}

/* A torus keeps its handle; an open tube its two boundary loops, with no
   face across its ends. */
static void test_remesh_topology(void)
{
    tmesh m;
    tt_mesh *mesh = NULL, *q = NULL;
    tt_error err;
    tt_remesh_options o;
    tt_mesh_stats st;
    float *vec, *w;
    int i, j;
    memset(&m, 0, sizeof m);
    make_torus(&m, 48, 24, 2.0, 0.7);
    CHECK(build(&m, 0, &mesh, &err) == TT_OK, "torus: %s", err.message);
    tm_free(&m);
    if (mesh) {
        remesh_field_new(mesh, &vec, &w);
        o = remesh_options(0.25f, w);
        CHECK(tt_remesh_quads(mesh, vec, &o, NULL, &q, NULL, &err) == TT_OK, "torus: %s", err.message);
        if (q) {
            CHECK(tt_mesh_compute_stats(q, NULL, &st, &err) == TT_OK && st.genus == 1 && st.components == 1 &&
                  st.boundary_loops == 0, "a torus: genus %d, %d components, %d loops", st.genus, st.components,
                  st.boundary_loops);
            remesh_check_clean(q, "torus");
        }
        tt_mesh_free(q);
        q = NULL;
        free(vec);
        free(w);
        tt_mesh_free(mesh);
        mesh = NULL;
    }
    /* A tube of radius 1 and length 4 along y, 40 x 20 quads. */
    memset(&m, 0, sizeof m);
    for (j = 0; j <= 20; j++)
        for (i = 0; i < 40; i++) {
            double a = 6.283185307179586 * i / 40;
            tm_vert(&m, cos(a), 0.2 * j, sin(a));
        }
    for (j = 0; j < 20; j++)
        for (i = 0; i < 40; i++)
            tm_quad(&m, j * 40 + i, (j + 1) * 40 + i, (j + 1) * 40 + (i + 1) % 40, j * 40 + (i + 1) % 40);
    CHECK(build(&m, 0, &mesh, &err) == TT_OK, "tube: %s", err.message);
    tm_free(&m);
    if (mesh) {
        tt_remesh_report rep;
        remesh_field_new(mesh, &vec, &w);
        o = remesh_options(0.3f, w);
        CHECK(tt_remesh_quads(mesh, vec, &o, NULL, &q, &rep, &err) == TT_OK, "tube: %s", err.message);
        if (q) {
            double median, share = remesh_aligned_share(q, &median);
            CHECK(tt_mesh_compute_stats(q, NULL, &st, &err) == TT_OK && st.genus == 0 && st.components == 1 &&
                  st.boundary_loops == 2, "an open tube: genus %d, %d components, %d loops", st.genus,
                  st.components, st.boundary_loops);
            /* A cylinder's field has no singularity: rows of quads all round. */
            CHECK(rep.quads >= 9 * (rep.triangles + rep.pentagons + rep.larger_faces) && share >= 0.95,
                  "a tube: %d quads, %d others, %.3f of its edges along or across up", rep.quads,
                  rep.triangles + rep.pentagons + rep.larger_faces, share);
            remesh_check_clean(q, "tube");
        }
        tt_mesh_free(q);
        free(vec);
        free(w);
        tt_mesh_free(mesh);
    }
}

/* A cone's walls: its circles shrink from radius 2 to 0.5 over a height
   of 3, so a column of quads ends every few rows all the way up, and the
   pairing's groups are on walls. Their rows stay level (the field's
   lean in the cut, pairs sought along rows first), and few of their
   quads are drawn out into streaks. */
static void test_remesh_cone(void)
{
    tmesh m;
    tt_mesh *mesh = NULL, *q = NULL;
    tt_error err;
    tt_remesh_options o;
    float *vec, *w;
    int i, j;
    memset(&m, 0, sizeof m);
    for (j = 0; j <= 30; j++)
        for (i = 0; i < 60; i++) {
            double a = 6.283185307179586 * i / 60, r = 2.0 - 1.5 * j / 30.0;
            tm_vert(&m, r * cos(a), 0.1 * j, r * sin(a));
        }
    for (j = 0; j < 30; j++)
        for (i = 0; i < 60; i++)
            tm_quad(&m, j * 60 + i, (j + 1) * 60 + i, (j + 1) * 60 + (i + 1) % 60, j * 60 + (i + 1) % 60);
    CHECK(build(&m, 0, &mesh, &err) == TT_OK, "cone: %s", err.message);
    tm_free(&m);
    if (!mesh) return;
    remesh_field_new(mesh, &vec, &w);
    o = remesh_options(0.15f, w);
    CHECK(tt_remesh_quads(mesh, vec, &o, NULL, &q, NULL, &err) == TT_OK, "cone: %s", err.message);
    if (q) {
        const double level = remesh_rows_level_share(q);
        const int drawn = remesh_drawn_out(q, 6.0);
        /* 0.978; cut by shape alone along the nearest path, about 0.956 */
        CHECK(level >= 0.97, "a cone's wall quads with rows within 10 degrees of level: %.3f", level);
        CHECK(200 * drawn <= q->nfaces, "quads with a side over 6 times another: %d of %d", drawn, q->nfaces);
        remesh_check_clean(q, "cone");
    }
    tt_mesh_free(q);
    free(vec);
    free(w);
    tt_mesh_free(mesh);
}

/* Sharp edges stay sharp: a cube (side 2, 12 x 12 cells a face, in
   triangles) remeshed at 0.2 with up y. Measured: the mean distance from
   points along the cube's 12 edges to the nearest edge of the output
   (0 where a row of output edges runs on the crease). The control turns
   creases off (crease_degrees 180): its edges cut the corners. */
static double remesh_crease_gap(const tt_mesh *q)
{
    double sum = 0.0;
    int axis, s, e, c, count = 0;
    for (axis = 0; axis < 3; axis++)
        for (e = 0; e < 4; e++)
            for (s = 1; s < 40; s++) {
                double p[3], best = 1e30;
                p[axis] = -1.0 + 2.0 * s / 40.0;
                p[(axis + 1) % 3] = (e & 1) ? 1.0 : -1.0;
                p[(axis + 2) % 3] = (e & 2) ? 1.0 : -1.0;
                for (c = 0; c < q->ncorners; c++) {
                    const float *a = q->pos + 3 * q->corner_vert[c], *b = q->pos + 3 * q->corner_vert[tt_mesh_next(q, c)];
                    double ab[3], ap[3], len2 = 0, along = 0, d2 = 0;
                    int k;
                    for (k = 0; k < 3; k++) {
                        ab[k] = (double)b[k] - a[k];
                        ap[k] = p[k] - a[k];
                        len2 += ab[k] * ab[k];
                        along += ap[k] * ab[k];
                    }
                    along = len2 > 0 ? along / len2 : 0;
                    along = along < 0 ? 0 : along > 1 ? 1 : along;
                    for (k = 0; k < 3; k++) d2 += (ap[k] - along * ab[k]) * (ap[k] - along * ab[k]);
                    if (d2 < best) best = d2;
                }
                sum += sqrt(best);
                count++;
            }
    return sum / count;
}

static void test_remesh_creases(void)
{
    tmesh m;
    tt_mesh *mesh = NULL, *q = NULL;
    tt_error err;
    tt_remesh_options o;
    tt_remesh_report rep;
    float *vec, *w;
    double gap = 1, control = 0;
    int side, i, j, n = 12;
    memset(&m, 0, sizeof m);
    for (side = 0; side < 6; side++) {
        int axis = side / 2, row[13][13];
        double sign = (side & 1) ? 1.0 : -1.0;
        for (i = 0; i <= n; i++)
            for (j = 0; j <= n; j++) {
                double p[3];
                p[axis] = sign;
                p[(axis + 1) % 3] = -1.0 + 2.0 * i / n;
                p[(axis + 2) % 3] = -1.0 + 2.0 * j / n;
                row[i][j] = tm_vert(&m, p[0], p[1], p[2]);
            }
        for (i = 0; i < n; i++)
            for (j = 0; j < n; j++) {
                /* outward: (axis+1) x (axis+2) = axis, so the order flips with the sign */
                if (sign > 0) {
                    tm_tri(&m, row[i][j], row[i + 1][j], row[i + 1][j + 1]);
                    tm_tri(&m, row[i][j], row[i + 1][j + 1], row[i][j + 1]);
                } else {
                    tm_tri(&m, row[i][j], row[i + 1][j + 1], row[i + 1][j]);
                    tm_tri(&m, row[i][j], row[i][j + 1], row[i + 1][j + 1]);
                }
            }
    }
    CHECK(build_welded(&m, &mesh, &err) == TT_OK, "cube: %s", err.message);
    tm_free(&m);
    if (!mesh) return;
    remesh_field_new(mesh, &vec, &w);
    o = remesh_options(0.2f, w);
    CHECK(tt_remesh_quads(mesh, vec, &o, NULL, &q, &rep, &err) == TT_OK, "cube: %s", err.message);
    if (q) {
        gap = remesh_crease_gap(q);
        CHECK(rep.snapped_vertices > 0, "vertices onto the creases: %d", rep.snapped_vertices);
        remesh_check_clean(q, "cube");
    }
    tt_mesh_free(q);
    q = NULL;
    o.crease_degrees = 180.0f;
    CHECK(tt_remesh_quads(mesh, vec, &o, NULL, &q, &rep, &err) == TT_OK, "cube, no creases: %s", err.message);
    if (q) {
        control = remesh_crease_gap(q);
        CHECK(rep.snapped_vertices == 0, "no creases, nothing snapped: %d", rep.snapped_vertices);
    }
    tt_mesh_free(q);
    CHECK(gap < 0.004 && control > 0.008 && gap < control / 4, "the cube's edges: %.4f from the output's edges (without creases %.4f)",
          gap, control);
    o.crease_degrees = -1.0f;
    q = (tt_mesh *)&q;
    CHECK(tt_remesh_quads(mesh, vec, &o, NULL, &q, NULL, &err) == TT_ERROR_INVALID_ARGUMENT && q == NULL,
          "crease_degrees -1: %s", err.message);
    o.crease_degrees = 181.0f;
    CHECK(tt_remesh_quads(mesh, vec, &o, NULL, &q, NULL, &err) == TT_ERROR_INVALID_ARGUMENT, "crease_degrees 181");
    free(vec);
    free(w);
    tt_mesh_free(mesh);
}

/* Records the fractions; asks to stop at call `stop_at` (-1: never). */
typedef struct remesh_progress {
    int calls, stop_at, decreasing;
    float last;
} remesh_progress;

static int remesh_progress_fn(float fraction, void *user_data)
{
    remesh_progress *p = (remesh_progress *)user_data;
    if (p->calls > 0 && fraction < p->last) p->decreasing++;
    p->last = fraction;
    return p->calls++ == p->stop_at;
}

typedef struct remesh_ctx {
    const tt_mesh *mesh;
    const float *vectors;
    tt_remesh_options options;
} remesh_ctx;

static tt_result oom_remesh(void *ctx, const tt_allocator *al, tt_error *error)
{
    remesh_ctx *r = (remesh_ctx *)ctx;
    tt_mesh *out = (tt_mesh *)&out;
    tt_result result = tt_remesh_quads(r->mesh, r->vectors, &r->options, al, &out, NULL, error);
    if (result == TT_OK) tt_mesh_free(out);
    else if (out != NULL) return TT_RESULT_MAX_ENUM;
    return result;
}

static void test_remesh_errors(void)
{
    tt_mesh *mesh = NULL, *q = (tt_mesh *)&q;
    tt_error err;
    tt_remesh_options o;
    tt_remesh_report rep;
    float *vec, *w;
    remesh_ctx ctx;
    tt_result r;
    mesh = remesh_icosphere(2);
    if (!mesh) return;
    remesh_field_new(mesh, &vec, &w);
    memset(&o, 0, sizeof o);
    r = tt_remesh_quads(NULL, vec, &o, NULL, &q, NULL, &err);
    CHECK(r == TT_ERROR_INVALID_ARGUMENT && q == NULL, "NULL mesh: %d", r);
    r = tt_remesh_quads(mesh, NULL, &o, NULL, &q, NULL, &err);
    CHECK(r == TT_ERROR_INVALID_ARGUMENT, "NULL vectors: %d", r);
    r = tt_remesh_quads(mesh, vec, &o, NULL, NULL, NULL, &err);
    CHECK(r == TT_ERROR_INVALID_ARGUMENT, "NULL out_mesh: %d", r);
    o.edge_length = -1.0f;
    r = tt_remesh_quads(mesh, vec, &o, NULL, &q, NULL, &err);
    CHECK(r == TT_ERROR_INVALID_ARGUMENT && strstr(err.message, "edge_length"), "negative edge: %s", err.message);
    o.edge_length = internal_infinity();
    r = tt_remesh_quads(mesh, vec, &o, NULL, &q, NULL, &err);
    CHECK(r == TT_ERROR_INVALID_ARGUMENT, "infinite edge: %s", err.message);
    o.edge_length = 0.5f;   /* the bounding box's diagonal is about 3.46: past an eighth of it */
    r = tt_remesh_quads(mesh, vec, &o, NULL, &q, NULL, &err);
    CHECK(r == TT_ERROR_INVALID_ARGUMENT && strstr(err.message, "eighth"), "edge too large: %s", err.message);
    o.edge_length = 1e-4f;
    r = tt_remesh_quads(mesh, vec, &o, NULL, &q, &rep, &err);
    CHECK(r == TT_ERROR_TOO_LARGE && q == NULL, "edge too small: %d %s", r, err.message);
    o.edge_length = 0.0f;
    o.sweeps = -1;
    r = tt_remesh_quads(mesh, vec, &o, NULL, &q, NULL, &err);
    CHECK(r == TT_ERROR_INVALID_ARGUMENT, "negative sweeps: %d", r);
    o.sweeps = 0;
    w[17] = 1.5f;
    o.face_weights = w;
    r = tt_remesh_quads(mesh, vec, &o, NULL, &q, NULL, &err);
    CHECK(r == TT_ERROR_INVALID_ARGUMENT && err.face == 17, "weight 1.5 on face 17: face %d, %s", err.face,
          err.message);
    w[17] = 1.0f;
    vec[3 * 5 + 1] = (float)internal_not_a_number();
    r = tt_remesh_quads(mesh, vec, &o, NULL, &q, NULL, &err);
    CHECK(r == TT_ERROR_NON_FINITE && err.face == 5, "NaN vector on face 5: face %d, %s", err.face, err.message);
    remesh_field(mesh, 0, vec, w);
    /* Progress: never decreasing, ending at 1; cancelling at any call
       leaves nothing allocated and no mesh. */
    {
        remesh_progress p;
        counter cnt;
        tt_allocator al = make_allocator(&cnt, -1);
        int calls, k, bad = 0;
        o = remesh_options(0.3f, w);
        o.progress = remesh_progress_fn;
        o.progress_user_data = &p;
        memset(&p, 0, sizeof p);
        p.stop_at = -1;
        r = tt_remesh_quads(mesh, vec, &o, &al, &q, NULL, &err);
        CHECK(r == TT_OK && p.calls >= 8 && p.decreasing == 0 && p.last == 1.0f,
              "progress: %d, %d calls, %d decreasing, last %g", r, p.calls, p.decreasing, p.last);
        tt_mesh_free(q);
        calls = p.calls;
        for (k = 0; k < calls; k++) {
            memset(&p, 0, sizeof p);
            p.stop_at = k;
            q = (tt_mesh *)&q;
            r = tt_remesh_quads(mesh, vec, &o, &al, &q, NULL, &err);
            if (r != TT_CANCELLED || q != NULL || cnt.live != 0 || err.result != TT_CANCELLED) {
                if (!bad++) DETAIL("cancelled at call %d: %d, out %p, %ld live", k, r, (void *)q, cnt.live);
            }
        }
        CHECK(bad == 0, "cancelling at each of %d calls: %d went wrong", calls, bad);
    }
    /* Every allocation failing in turn. */
    ctx.mesh = mesh;
    ctx.vectors = vec;
    memset(&ctx.options, 0, sizeof ctx.options);
    ctx.options.edge_length = 0.4f;
    ctx.options.face_weights = w;
    oom_reset();
    oom_sweep("tt_remesh_quads", oom_remesh, &ctx, TT_OK);
    free(vec);
    free(w);
    tt_mesh_free(mesh);
}

/* The centre the remesher tries for a split face that folds: the area
   centroid of the ring of its corners, which for a ring crossing itself
   (signed areas almost cancelling) is a quotient of two small numbers far
   outside the ring, once past the float range (a remeshed vertex at
   infinity); there it must fall back to the mean. */
static void test_remesh_ring_centroid(void)
{
    static const float trapezoid[4 * 3] = {0, 0, 0, 3, 0, 0, 2, 1, 0, 0, 1, 0};
    float bow_tie[4 * 3] = {0, 0, 0, 1, 1, 0, 1, 0, 0, 0, 1, 0};
    const float *shapes[2];
    double expected[2][3] = {{19.0 / 15.0, 7.0 / 15.0, 0.0}, {0.5, 0.5 + 0.25e-6, 0.0}};
    int indices[4] = {0, 1, 2, 3}, s, k;
    bow_tie[3 * 3 + 1] = 1.0f + 1e-6f;   /* the two lobes' areas differ by 5e-7 */
    shapes[0] = trapezoid;
    shapes[1] = bow_tie;
    for (s = 0; s < 2; s++) {
        tt_mesh_desc d;
        tt_mesh *face = NULL, *q = NULL;
        tt_error err;
        double centre[3] = {0.0, 0.0, 0.0}, off = 0.0;
        memset(&d, 0, sizeof d);
        d.positions = shapes[s];
        d.nverts = 4;
        d.indices = indices;
        d.fixed_face_size = 4;
        d.nfaces = 1;
        d.flags = TT_MESH_PERMISSIVE;
        if (tt_mesh_build(&d, NULL, &face, &err) != TT_OK ||
            tt_mesh_quadrangulate(face, TT_SUBDIVIDE_LINEAR, NULL, &q, &err) != TT_OK) {
            CHECK(0, "building shape %d: %s", s, err.message);
            tt_mesh_free(face);
            continue;
        }
        internal_remesh_ring_centroid(q, 0, 4, 1, centre);
        for (k = 0; k < 3; k++) off = fmax(off, fabs(centre[k] - expected[s][k]));
        CHECK(off < 1e-6, "%s: centre (%g, %g, %g), expected (%g, %g, %g)", s ? "a bow tie (the mean)" :
              "a trapezoid (its area centroid)", centre[0], centre[1], centre[2], expected[s][0], expected[s][1],
              expected[s][2]);
        tt_mesh_free(q);
        tt_mesh_free(face);
    }
}

/* A quad's cost in the pairing's cut: a square level with the field's up
   (+y) costs nothing; turned 30 degrees it costs more, but not where the
   field weighs nothing; rows leaning cost more than columns leaning by
   the same angle (the same shape, mirrored); a 3:1 rectangle, right
   angled, costs more than a square, a trapezoid more than the
   parallelogram of its angles; a folded quad more than any other. */
static void test_remesh_quad_cost(void)
{
    float pos[3 * 4];
    const int quad[4] = {0, 1, 2, 3};
    double up[3 * 4], weight[4], square, turned, turned_free, rows_lean, columns_lean, long_one, folded, t;
    double tapered, slanted;
    internal_pair_field field;
    int k;
    for (k = 0; k < 4; k++) {
        up[3 * k] = 0.0; up[3 * k + 1] = k == 2 ? -1.0 : 1.0; up[3 * k + 2] = 0.0;
        weight[k] = 1.0;
    }
    field.up = up;
    field.weight = weight;
    field.n = 4;
#define QUAD(x0, y0, x1, y1, x2, y2, x3, y3)                                                            \
    (pos[0] = x0, pos[1] = y0, pos[3] = x1, pos[4] = y1, pos[6] = x2, pos[7] = y2, pos[9] = x3, pos[10] = y3, \
     pos[2] = pos[5] = pos[8] = pos[11] = 0.0f)
    QUAD(0.0f, 0.0f, 1.0f, 0.0f, 1.0f, 1.0f, 0.0f, 1.0f);
    square = internal_remesh_quad_cost(pos, &field, quad);
    t = 30.0 / 57.29577951308232;
    QUAD(0.0f, 0.0f, (float)cos(t), (float)sin(t), (float)(cos(t) - sin(t)), (float)(sin(t) + cos(t)),
         (float)-sin(t), (float)cos(t));
    turned = internal_remesh_quad_cost(pos, &field, quad);
    for (k = 0; k < 4; k++) weight[k] = 0.0;
    turned_free = internal_remesh_quad_cost(pos, &field, quad);
    for (k = 0; k < 4; k++) weight[k] = 1.0;
    CHECK(fabs(square) < 1e-6 && turned > square + 1.0 && fabs(turned_free - square) < 1e-6,
          "a square level %g, turned 30 degrees %g, turned where up weighs nothing %g", square, turned, turned_free);
    QUAD(0.0f, 0.0f, 1.0f, 0.0f, 1.4f, 1.0f, 0.4f, 1.0f);     /* columns lean, rows level */
    columns_lean = internal_remesh_quad_cost(pos, &field, quad);
    QUAD(0.0f, 0.0f, 1.0f, 0.4f, 1.0f, 1.4f, 0.0f, 1.0f);     /* rows lean, columns plumb */
    rows_lean = internal_remesh_quad_cost(pos, &field, quad);
    CHECK(columns_lean > square && rows_lean > 2.0 * columns_lean,
          "columns leaning cost %g, rows leaning by as much %g", columns_lean, rows_lean);
    QUAD(0.0f, 0.0f, 3.0f, 0.0f, 3.0f, 1.0f, 0.0f, 1.0f);
    long_one = internal_remesh_quad_cost(pos, NULL, quad);
    /* corners of 60 and 120 degrees both, the same sums of opposite sides */
    QUAD(0.0f, 0.0f, 3.0f, 0.0f, 2.42265f, 1.0f, 0.57735f, 1.0f);
    tapered = internal_remesh_quad_cost(pos, NULL, quad);
    QUAD(0.0f, 0.0f, 2.42265f, 0.0f, 3.0f, 1.0f, 0.57735f, 1.0f);
    slanted = internal_remesh_quad_cost(pos, NULL, quad);
    CHECK(tapered > slanted + 0.3, "a trapezoid %g, the parallelogram of its angles and sides' sums %g", tapered,
          slanted);
    QUAD(0.0f, 0.0f, 2.0f, 0.0f, 0.5f, 0.5f, 0.0f, 2.0f);     /* a dart: the triangles on one diagonal face apart */
    folded = internal_remesh_quad_cost(pos, NULL, quad);
    CHECK(long_one > 3.0 && folded > 1000.0 && folded < HUGE_VAL, "a 3:1 rectangle %g, a folded quad %g", long_one,
          folded);
#undef QUAD
}

/* The naive reference for the cut of a polygon into quads: every
   quadrangulation by diagonals, by recursion on the quad that holds the
   edge from corner i to corner j; the least summed cost. */
static double naive_polygon_cut(const float *pos, const internal_pair_field *field, const int *poly, int i, int j)
{
    double best = HUGE_VAL;
    int a, b;
    if (j - i == 1) return 0.0;
    for (a = i + 1; a < j; a += 2)
        for (b = a + 1; b < j; b += 2) {
            int quad[4];
            double c;
            quad[0] = poly[i]; quad[1] = poly[a]; quad[2] = poly[b]; quad[3] = poly[j];
            c = internal_remesh_quad_cost(pos, field, quad);
            if (c == HUGE_VAL) continue;
            c += naive_polygon_cut(pos, field, poly, i, a) + naive_polygon_cut(pos, field, poly, a, b) +
                 naive_polygon_cut(pos, field, poly, b, j);
            if (c < best) best = c;
        }
    return best;
}

/* The lattice's odd faces are paired, each group cut into the cheapest
   quads: the dynamic programme finds the least cost that trying every
   cut finds, on random star-shaped polygons (some with corners that fold
   every cut: a cost, not a refusal), half of them with a random field
   (an up at each corner but the last, weights from 0 to 1); the quads it
   returns use each polygon corner and cover the polygon's area; a
   corner marked needy gets a diagonal; a pair marked joined gets none. */
static void test_remesh_polygon_cut(void)
{
    float pos[3 * 12];
    double up[3 * 12], weight[12];
    int poly[12], out[4 * 5], n, trial, k, mismatches = 0, uncovered = 0, unreached = 0, joined_used = 0;
    unsigned char joined[12 * 12], needy[12];
    internal_pair_field field;
    lcg_seed(7);
    for (trial = 0; trial < 300; trial++) {
        double cost, reference, area = 0.0, quads_area = 0.0;
        const internal_pair_field *with = trial & 1 ? &field : NULL;
        n = 4 + 2 * lcg_below(5);     /* 4 .. 12 */
        for (k = 0; k < n; k++) {
            double angle = 2.0 * 3.14159265358979 * (k + 0.8 * (lcg_unit() - 0.5)) / n;
            double radius = 0.4 + lcg_unit(), turn = 0.6 * (lcg_unit() - 0.5);
            pos[3 * k] = (float)(radius * cos(angle));
            pos[3 * k + 1] = (float)(radius * sin(angle));
            pos[3 * k + 2] = (float)(0.05 * lcg_unit());
            poly[k] = k;
            up[3 * k] = sin(turn);
            up[3 * k + 1] = (k & 2 ? -1.0 : 1.0) * cos(turn);    /* either way along the line */
            up[3 * k + 2] = 0.0;
            weight[k] = lcg_unit();
        }
        field.up = up;
        field.weight = weight;
        field.n = n - 1;
        memset(joined, 0, sizeof joined);
        memset(needy, 0, sizeof needy);
        if (!internal_remesh_quadrangulate_polygon(pos, with, poly, n, joined, needy, &cost, out)) {
            mismatches++;
            continue;
        }
        reference = naive_polygon_cut(pos, with, poly, 0, n - 1);
        mismatches += fabs(cost - reference) > 1e-9 * (1.0 + reference);
        for (k = 0; k < n; k++) {
            const float *p = pos + 3 * k, *r = pos + 3 * ((k + 1) % n);
            area += 0.5 * ((double)p[0] * r[1] - (double)r[0] * p[1]);
        }
        for (k = 0; k < n / 2 - 1; k++) {
            int j;
            for (j = 0; j < 4; j++) {
                const float *p = pos + 3 * out[4 * k + j], *r = pos + 3 * out[4 * k + (j + 1) % 4];
                quads_area += 0.5 * ((double)p[0] * r[1] - (double)r[0] * p[1]);
            }
        }
        uncovered += fabs(area - quads_area) > 1e-5 * fabs(area);
        /* Corner 3 needy, and the diagonal 0 - 2 taken: the cut honours both. */
        if (n >= 8) {
            int reached = 0;
            needy[3] = 1;
            joined[0 * n + 2] = joined[2 * n + 0] = 1;
            if (internal_remesh_quadrangulate_polygon(pos, with, poly, n, joined, needy, &cost, out)) {
                for (k = 0; k < n / 2 - 1; k++) {
                    int j;
                    for (j = 0; j < 4; j++) {
                        int a = out[4 * k + j], b = out[4 * k + (j + 1) % 4], gap = abs(a - b);
                        if (gap == 1 || gap == n - 1) continue;
                        reached |= a == 3 || b == 3;
                        joined_used += (a == 0 && b == 2) || (a == 2 && b == 0);
                    }
                }
                unreached += !reached;
            }
        }
    }
    CHECK(mismatches == 0, "the programme's least cost is every cut's least: %d of 300 differ", mismatches);
    CHECK(uncovered == 0, "the quads cover the polygon: %d of 300 do not", uncovered);
    CHECK(unreached == 0 && joined_used == 0, "needy corner reached, joined pair left alone: %d, %d", unreached,
          joined_used);
}

/* Flag bits the builder does not know are refused, not ignored: a caller
   who sets one expects something of it. */
static void test_builder_unknown_flags(void)
{
    tmesh m;
    tt_mesh_desc d;
    tt_mesh *mesh = NULL;
    tt_error err;
    tt_result r;
    memset(&m, 0, sizeof m);
    make_tetra(&m, 0);
    d = tm_desc(&m);
    d.flags = TT_MESH_PERMISSIVE | (1u << 7);
    r = tt_mesh_build(&d, NULL, &mesh, &err);
    CHECK(r == TT_ERROR_INVALID_ARGUMENT && mesh == NULL && strstr(err.message, "0x80"),
          "flags with bit 7: %d (%s)", r, err.message);
    d.flags = TT_MESH_PERMISSIVE | TT_MESH_BORROW_POSITIONS;
    r = tt_mesh_build(&d, NULL, &mesh, &err);
    CHECK(r == TT_OK, "the known flags: %d (%s)", r, err.message);
    tt_mesh_free(mesh);
    tm_free(&m);
}

void run_mesh_tests(void)
{
    RUN(test_builder_unknown_flags);
    RUN(test_remesh_polygon_cut);
    RUN(test_remesh_quad_cost);
    RUN(test_remesh_cone);
    RUN(test_builder_valid);
    RUN(test_builder_errors);
    RUN(test_builder_oom);
    RUN(test_queries);
    RUN(test_queries_oom);
    RUN(test_quadrangulate);
    RUN(test_quadrangulate_direct);
    RUN(test_quadrangulate_sources);
    RUN(test_corner_normals);
    RUN(test_mesh_null_errors);
    RUN(test_mesh_query_allocators);
    RUN(test_remesh_sphere);
    RUN(test_remesh_topology);
    RUN(test_remesh_creases);
    RUN(test_remesh_errors);
    RUN(test_remesh_ring_centroid);
}
