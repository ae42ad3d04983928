/* fuzz_mesh_build.c - libFuzzer target for the half-edge builder and everything
   that runs on a built mesh.

   Build (tests/fuzz/run.sh does this, with the library compiled once from
   tests/fuzz/fuzz_library.c):
       clang -g -O1 -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=all \
             -I. tests/fuzz/fuzz_mesh_build.c tests/fuzz/fuzz_library.c -o build/fuzz/fuzz_mesh_build -lm

   Input bytes, read front to back (missing bytes read as 0; missing positions
   get distinct points on the twisted cubic (t, t^2, t^3), no three collinear):
       0      flags: bit0 TT_MESH_PERMISSIVE, bit1 TT_MESH_BORROW_POSITIONS,
              bit2 per-face sizes (else fixed_face_size = bits 5..7, 0 = default),
              bit3 raw positions (12 bytes = 3 floats per vertex, any bit pattern)
              else one byte per coordinate, bit4 make allocation number byte[4]
              fail (exercises the out-of-memory paths)
       1      nverts (0..255)
       2      nfaces (0..63)
       3      layout colors (low 7 bits: 0..127, 0 = default); bit 7 set = abuse
              mode: the description is broken in way seed & 7 (negative
              counts, NULL arrays, sizes past the 2^30-corner limit, a negative
              face size) and the build must fail with the right code without
              reading the arrays or allocating
       4      which allocation fails (1-based) when bit4 is set
       5      layout: tile_size = low 4 bits (0 = default), gutter = high 4 bits - 1
              (so -1 = TT_NO_GUTTER, 0 = default)
       6, 7   seed
       then   nfaces face sizes (one byte each, low 5 bits: 0..31) when bit2
       then   one byte per corner: the vertex index, b % nverts, except
              250 -> -1, 251 -> nverts, 252 -> INT_MAX, 253 -> INT_MIN
       then   positions; one-byte coordinates are (b - 128) / 8, except
              0 -> NaN, 1 -> +inf, 2 -> -inf, 3 -> FLT_MAX, 4 -> a denormal,
              5..36 -> an extreme value (EXTREME[b - 5]: +-FLT_MAX, +-1e38,
              1e-38, denormals, values near 2^24 and 1e10 whose differences
              collapse, +-0), 37..42 -> NaNs with payloads, either sign,
              quiet and signalling (fz_extreme_float), so that one face
              mixes huge and tiny coordinates
              and zero-area and overflow paths run

   The allocator is a parameter of every allocating call: the counting
   allocator of fuzz_common.h, failing allocation number byte[4] + 1 when
   bit4 is set. Every call gets a tt_error; on failure fz_check_error and
   fz_check_null (fuzz_common.h) check the error and the NULL output.

   Besides crashes, leaks and undefined behaviour, it aborts when a result breaks
   the documented contract: twins that are not mutual or not reversed, corners not
   aligned with the index buffer, a vert_corner that is not a boundary half-edge
   when one exists, stats that disagree with the arrays, boundary types whose twins
   are not complementary (2k+i vs 2k+1-i), UVs outside [0,1], a quadrangulation
   with the wrong counts, an allocation not given back, an error without a place or
   a sentence, or TT_ERROR_OUT_OF_MEMORY when no allocation failed; with any
   coordinates, a build result outside the documented codes, or a built mesh
   whose face normal is not a finite unit vector (or, permissive only, zero). */
#include "tiledtex.h"
#define FUZZ_NAME "fuzz_mesh_build"
#include "fuzz_common.h"

#include <float.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Extreme but finite coordinates: overflow when subtracted or multiplied
   (FLT_MAX - -FLT_MAX, 1e38^2), underflow (1e-38^2, denormals), and values
   whose differences collapse in float (2^24 and 2^24 + 1 are one float;
   1e10 and 1e10 + 512 too). */
static const float EXTREME[32] = {
    FLT_MAX,      -FLT_MAX,      1e38f,        -1e38f,        3e38f,      1e-38f,      -1e-38f,    FLT_MIN,
    1e-45f,       -1e-45f,       1e-40f,       16777216.0f,   16777217.0f, 16777218.0f, 16777215.0f, -16777216.0f,
    33554432.0f,  33554436.0f,   8388608.0f,   8388608.5f,    1e20f,      -1e20f,      1e19f,      1e-20f,
    1.00000012f,  1.0f,          0.99999994f,  0.0f,          -0.0f,      1e10f,       1e10f + 512.0f, 2e19f};

static float coord_from_byte(uint8_t b)
{
    if (b >= 5 && b < 5 + 32) return EXTREME[b - 5];
    /* NaNs with payloads and either sign, quiet and signalling */
    if (b >= 37 && b < 43) return fz_extreme_float((uint8_t)(16 + b - 37));
    switch (b) {
    case 0: return NAN;
    case 1: return INFINITY;
    case 2: return -INFINITY;
    case 3: return FLT_MAX;
    case 4: return 1e-40f;
    default: return (float)((int)b - 128) / 8.0f;
    }
}

static int index_from_byte(uint8_t b, int nverts)
{
    switch (b) {
    case 250: return -1;
    case 251: return nverts;
    case 252: return INT_MAX;
    case 253: return INT_MIN;
    default: return nverts > 0 ? (int)b % nverts : (int)b - 128;
    }
}

/* ---- contract checks ---------------------------------------------------------- */

static void check_error(tt_result r, const tt_error *err, int nfaces, int ncorners, const fz_alloc *a)
{
    fz_check_error(FUZZ_NAME, r, err, a);
    CHECK(err->face >= -1 && err->face < (nfaces > 0 ? nfaces : 1), "face %d of %d: %s", err->face, nfaces,
          err->message);
    CHECK(err->corner >= -1 && err->corner < (ncorners > 0 ? ncorners : 1), "corner %d of %d: %s", err->corner,
          ncorners, err->message);
}

/* Everything the header promises about a built mesh. `indices` (may be NULL)
   is the index buffer it was built from. */
static void check_mesh(const tt_mesh *m, const int *indices, int strict)
{
    int f, c, v, minf = INT_MAX, maxf = 0;
    char *has_boundary_out;
    CHECK(m->nfaces > 0 && m->nverts > 0, "%d faces %d verts", m->nfaces, m->nverts);
    CHECK(m->face_start[0] == 0, "%d", m->face_start[0]);
    CHECK(m->face_start[m->nfaces] == m->ncorners, "%d vs %d", m->face_start[m->nfaces], m->ncorners);
    for (f = 0; f < m->nfaces; ++f) {
        int s = m->face_start[f], e = m->face_start[f + 1];
        CHECK(e - s >= 3, "face %d has %d corners", f, e - s);
        if (e - s < minf) minf = e - s;
        if (e - s > maxf) maxf = e - s;
        for (c = s; c < e; ++c) {
            int nx = c + 1 < e ? c + 1 : s, pv = c > s ? c - 1 : e - 1;
            CHECK(m->corner_face[c] == f, "corner %d face %d, expected %d", c, m->corner_face[c], f);
            CHECK(tt_mesh_next(m, c) == nx, "next(%d) = %d, expected %d", c, tt_mesh_next(m, c), nx);
            CHECK(tt_mesh_prev(m, c) == pv, "prev(%d) = %d, expected %d", c, tt_mesh_prev(m, c), pv);
        }
    }
    CHECK(m->min_face_size == minf && m->max_face_size == maxf, "face sizes %d..%d, expected %d..%d",
          m->min_face_size, m->max_face_size, minf, maxf);
    CHECK(!strict || m->repaired_edges == 0, "strict build repaired %d edges", m->repaired_edges);
    for (c = 0; c < m->ncorners; ++c) {
        int t = m->twin[c], a = m->corner_vert[c], b = m->corner_vert[tt_mesh_next(m, c)];
        CHECK(a >= 0 && a < m->nverts, "corner %d vertex %d of %d", c, a, m->nverts);
        CHECK(!indices || a == indices[c], "corner %d vertex %d, index buffer says %d", c, a, indices[c]);
        if (t == -1) continue;
        CHECK(t >= 0 && t < m->ncorners && t != c, "twin[%d] = %d", c, t);
        CHECK(m->twin[t] == c, "twin[twin[%d]] = %d", c, m->twin[t]);
        CHECK(m->corner_vert[t] == b && m->corner_vert[tt_mesh_next(m, t)] == a,
              "half-edge %d (%d->%d) twin %d (%d->%d)", c, a, b, t, m->corner_vert[t],
              m->corner_vert[tt_mesh_next(m, t)]);
        CHECK(a != b, "degenerate half-edge %d (%d->%d) has twin %d", c, a, b, t);
    }
    has_boundary_out = (char *)calloc((size_t)m->nverts, 1);
    if (!has_boundary_out) abort();
    for (c = 0; c < m->ncorners; ++c)
        has_boundary_out[m->corner_vert[c]] |= (char)(1 | (m->twin[c] < 0 ? 2 : 0));
    for (v = 0; v < m->nverts; ++v) {
        int vc = m->vert_corner[v];
        if (!has_boundary_out[v]) {
            CHECK(vc == -1, "unused vertex %d has vert_corner %d", v, vc);
            continue;
        }
        CHECK(vc >= 0 && vc < m->ncorners && m->corner_vert[vc] == v, "vert_corner[%d] = %d", v, vc);
        CHECK(!(has_boundary_out[v] & 2) || m->twin[vc] == -1,
              "vertex %d has a boundary half-edge but vert_corner %d is interior", v, vc);
    }
    free(has_boundary_out);
}

static void check_types_and_uvs(const tt_mesh *m, const tt_tile_layout *layout, uint64_t seed, fz_alloc *a)
{
    uint8_t *types = (uint8_t *)malloc((size_t)m->ncorners);
    float *uv = (float *)malloc(sizeof(float) * 2 * (size_t)m->ncorners);
    tt_tile_layout resolved;
    tt_error err;
    tt_result r, rl;
    int c, n;
    if (!types || !uv) abort();
    memset(&err, 0x55, sizeof err);
    rl = tt_tile_layout_resolve(layout, &resolved, &err);
    if (rl != TT_OK) check_error(rl, &err, m->nfaces, m->ncorners, a);
    n = layout->colors ? layout->colors : 1;
    memset(&err, 0x55, sizeof err);
    r = tt_assign_boundaries(m, layout, seed, NULL, types, &err);
    if (r != TT_OK) {
        check_error(r, &err, m->nfaces, m->ncorners, a);
        CHECK(r == TT_ERROR_INVALID_ARGUMENT && (n < 1 || n > TT_MAX_COLORS), "assign_boundaries with %d colors: %s",
              n, err.message);
    }
    if (r == TT_OK) {
        for (c = 0; c < m->ncorners; ++c) {
            CHECK(types[c] < 2 * n, "type[%d] = %d with %d colors", c, types[c], n);
            if (m->twin[c] >= 0)
                CHECK((types[m->twin[c]] ^ 1) == types[c], "types %d / %d across half-edge %d", types[c],
                      types[m->twin[c]], c);
        }
        memset(&err, 0x55, sizeof err);
        r = tt_assign_uvs(m, layout, types, uv, &err);
        if (m->min_face_size != 4 || m->max_face_size != 4) {
            CHECK(r != TT_OK, "tt_assign_uvs accepted a mesh with %d..%d-gons", m->min_face_size, m->max_face_size);
        } else if (rl == TT_OK) {
            /* tt_assign_uvs allocates nothing: it cannot run out of memory */
            CHECK(r == TT_OK, "tt_assign_uvs on a quad mesh: %s", err.message);
        }
        if (r == TT_OK) {
            for (c = 0; c < 2 * m->ncorners; ++c)
                CHECK(uv[c] >= 0.0f && uv[c] <= 1.0f, "uv[%d] = %g", c, (double)uv[c]);
        } else {
            check_error(r, &err, m->nfaces, m->ncorners, a);
        }
        if (r == TT_OK && rl == TT_OK && tt_tile_layout_tile_count(&resolved) <= 4096) {
            int *counts;
            size_t ntiles = (size_t)tt_tile_layout_tile_count(&resolved), t;
            long total = 0;
            counts = (int *)malloc(sizeof(int) * (ntiles ? ntiles : 1));
            if (!counts) abort();
            memset(&err, 0x55, sizeof err);
            r = tt_tile_histogram(m, layout, types, counts, &err);
            CHECK(r == TT_OK, "tt_tile_histogram on a quad mesh with valid types: %s", err.message);
            for (t = 0; t < ntiles; ++t) total += counts[t];
            CHECK(total == m->nfaces, "tile histogram counts %ld of %d quads", total, m->nfaces);
            free(counts);
        }
    }
    free(types);
    free(uv);
}

/* Face normals: a finite unit vector, or (0,0,0) for a face of numerically
   zero area, which only a permissive mesh may hold. */
static void check_normals(const tt_mesh *m, int strict)
{
    int f;
    for (f = 0; f < m->nfaces; ++f) {
        float n[3];
        double len;
        n[0] = n[1] = n[2] = NAN;
        tt_face_normal(m, f, n);
        CHECK(isfinite(n[0]) && isfinite(n[1]) && isfinite(n[2]), "face %d normal (%g, %g, %g)", f, (double)n[0],
              (double)n[1], (double)n[2]);
        len = sqrt((double)n[0] * n[0] + (double)n[1] * n[1] + (double)n[2] * n[2]);
        if (len == 0.0) {
            CHECK(!strict, "face %d of a strict mesh has a zero normal (zero area, but the build accepted it)", f);
            continue;
        }
        CHECK(fabs(len - 1.0) <= 1e-5, "face %d normal has length %.9g", f, len);
    }
}

static void exercise(const tt_mesh *m, const tt_tile_layout *layout, uint64_t seed, int strict, fz_alloc *a,
                     int depth)
{
    tt_mesh_stats st;
    tt_error err;
    tt_result r;
    int *corner_loop = (int *)malloc(sizeof(int) * (size_t)m->ncorners);
    int *face_comp = (int *)malloc(sizeof(int) * (size_t)m->nfaces);
    int hist[8];
    int c, f, v, nloops = -1, ncomp = -1, nboundary = 0, s, stats_ok;
    if (!corner_loop || !face_comp) abort();
    for (c = 0; c < m->ncorners; ++c) nboundary += m->twin[c] < 0;

    /* Only a mesh the builder validated promises no zero-area face: a
       quadrangulation may collapse one (coincident corners, or new points
       float cannot separate), as tt_mesh_quadrangulate documents. */
    check_normals(m, strict && depth == 0);
    memset(&st, 0, sizeof st);
    memset(&err, 0x55, sizeof err);
    r = tt_mesh_compute_stats(m, &a->tt, &st, &err);
    stats_ok = r == TT_OK;
    if (r != TT_OK) check_error(r, &err, m->nfaces, m->ncorners, a);
    CHECK(r == TT_OK || (r == TT_ERROR_OUT_OF_MEMORY && a->failed), "stats returned %d", (int)r);
    if (r == TT_OK) {
        CHECK(st.boundary_edges == nboundary, "%d boundary edges, %d boundary half-edges", st.boundary_edges,
              nboundary);
        CHECK(2 * st.edges == m->ncorners + nboundary, "%d edges, %d corners, %d boundary", st.edges,
              m->ncorners, nboundary);
        CHECK(st.euler_characteristic == st.used_vertices - st.edges + m->nfaces, "chi %d", st.euler_characteristic);
        CHECK(!strict || st.nonmanifold_vertices == 0, "%d non-manifold vertices in a strict mesh",
              st.nonmanifold_vertices);
        CHECK(st.components >= 1 && st.components <= m->nfaces, "%d components", st.components);
        CHECK(st.min_valence <= st.max_valence, "valence %d..%d", st.min_valence, st.max_valence);
    }
    for (v = 0; v < m->nverts; ++v) CHECK(tt_mesh_valence(m, v) >= 0, "valence(%d)", v);
    memset(&err, 0x55, sizeof err);
    r = tt_mesh_valence_histogram(m, &a->tt, hist, 8, &err);
    if (r != TT_OK) check_error(r, &err, m->nfaces, m->ncorners, a);
    CHECK(r == TT_OK || (r == TT_ERROR_OUT_OF_MEMORY && a->failed), "valence histogram: %s", err.message);
    if (r == TT_OK && stats_ok) {
        for (s = 0, v = 0; v < 8; ++v) s += hist[v];
        CHECK(st.used_vertices == s, "histogram sums to %d of %d used", s, st.used_vertices);
    }

    memset(&err, 0x55, sizeof err);
    r = tt_mesh_boundary_loops(m, corner_loop, &nloops, &err);
    /* allocates nothing: it cannot fail on a built mesh */
    CHECK(r == TT_OK, "boundary_loops returned %d", (int)r);
    if (r == TT_OK) {
        for (c = 0; c < m->ncorners; ++c) {
            if (m->twin[c] >= 0)
                CHECK(corner_loop[c] == -1, "interior corner %d in loop %d", c, corner_loop[c]);
            else
                CHECK(corner_loop[c] >= 0 && corner_loop[c] < nloops, "boundary corner %d loop %d of %d", c,
                      corner_loop[c], nloops);
        }
        CHECK(nloops <= nboundary, "%d loops for %d boundary half-edges", nloops, nboundary);
    }

    memset(&err, 0x55, sizeof err);
    r = tt_mesh_components(m, &a->tt, face_comp, &ncomp, &err);
    if (r != TT_OK) check_error(r, &err, m->nfaces, m->ncorners, a);
    CHECK(r == TT_OK || (r == TT_ERROR_OUT_OF_MEMORY && a->failed), "components returned %d", (int)r);
    if (r == TT_OK) {
        int seen = 0;
        for (f = 0; f < m->nfaces; ++f) {
            CHECK(face_comp[f] >= 0 && face_comp[f] <= seen, "face %d component %d after %d", f, face_comp[f], seen);
            if (face_comp[f] == seen) ++seen;
        }
        CHECK(seen == ncomp, "%d components numbered, %d reported", seen, ncomp);
        for (c = 0; c < m->ncorners; ++c)
            if (m->twin[c] >= 0)
                CHECK(face_comp[m->corner_face[c]] == face_comp[m->corner_face[m->twin[c]]],
                      "twins %d/%d in different components", c, m->twin[c]);
    }

    check_types_and_uvs(m, layout, seed, a);

    if (depth == 0) {
        /* tt_remesh_quads, each face's first edge its direction, at the
           largest edge allowed (an eighth of the diagonal: little
           refinement): a strict mesh of quads, or a documented error. */
        float *vectors = (float *)malloc(3 * (size_t)(m->nfaces > 0 ? m->nfaces : 1) * sizeof(float));
        double lo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
        tt_remesh_options ro;
        tt_mesh *rq = (tt_mesh *)&err;   /* must be set to NULL on failure */
        int face, corner, k;
        CHECK(vectors != NULL, "out of memory");
        for (face = 0; face < m->nfaces; face++) {
            const float *p0 = m->pos + 3 * m->corner_vert[m->face_start[face]];
            const float *p1 = m->pos + 3 * m->corner_vert[m->face_start[face] + 1];
            for (k = 0; k < 3; k++) vectors[3 * face + k] = (float)((double)p1[k] - p0[k]);
            for (k = 0; k < 3; k++)
                if (!(fabsf(vectors[3 * face + k]) <= FLT_MAX)) vectors[3 * face + k] = 0.0f;
        }
        for (corner = 0; corner < m->ncorners; corner++)
            for (k = 0; k < 3; k++) {
                lo[k] = fmin(lo[k], m->pos[3 * m->corner_vert[corner] + k]);
                hi[k] = fmax(hi[k], m->pos[3 * m->corner_vert[corner] + k]);
            }
        memset(&ro, 0, sizeof ro);
        ro.edge_length = (float)(0.124 * sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                                              (hi[2] - lo[2]) * (hi[2] - lo[2])));
        if (!(ro.edge_length > 0.0f && ro.edge_length <= FLT_MAX)) ro.edge_length = 0.0f;
        memset(&err, 0x55, sizeof err);
        r = tt_remesh_quads(m, vectors, &ro, &a->tt, &rq, NULL, &err);
        if (r != TT_OK) {
            fz_check_null("tt_remesh_quads", r, rq);
            check_error(r, &err, m->nfaces, m->ncorners, a);
            CHECK(r == TT_ERROR_OUT_OF_MEMORY || r == TT_ERROR_NON_FINITE || r == TT_ERROR_ZERO_AREA_FACE ||
                      r == TT_ERROR_TOO_LARGE || r == TT_ERROR_NOT_CONVERGED || r == TT_ERROR_INVALID_ARGUMENT,
                  "remeshing failed outside the documented codes: %d %s", r, err.message);
        } else {
            tt_mesh_desc again_desc;
            tt_mesh *again = NULL;
            check_mesh(rq, NULL, 1);
            CHECK(rq->min_face_size == 4 && rq->max_face_size == 4, "remeshed faces of %d..%d sides",
                  rq->min_face_size, rq->max_face_size);
            /* The promise: tt_mesh_build accepts the result again, strict
               (no face of zero area). */
            memset(&again_desc, 0, sizeof again_desc);
            again_desc.positions = rq->pos;
            again_desc.nverts = rq->nverts;
            again_desc.indices = rq->corner_vert;
            again_desc.fixed_face_size = 4;
            again_desc.nfaces = rq->nfaces;
            r = tt_mesh_build(&again_desc, NULL, &again, &err);
            CHECK(r == TT_OK, "the remeshed mesh does not build again: %s", err.message);
            tt_mesh_free(again);
            tt_mesh_free(rq);
        }
        free(vectors);
    }
    if (depth == 0) {
        int scheme;
        for (scheme = 0; scheme < 2; ++scheme) {
            tt_mesh *q = (tt_mesh *)&err;   /* must be set to NULL on failure */
            memset(&err, 0x55, sizeof err);
            r = tt_mesh_quadrangulate(m, (tt_subdivision)scheme, &a->tt, &q, &err);
            if (r != TT_OK) {
                fz_check_null("tt_mesh_quadrangulate", r, q);
                /* the error names a face / corner of the new mesh */
                check_error(r, &err, m->ncorners, 4 * m->ncorners, a);
                /* A valid mesh must quadrangulate, except that new points may
                   overflow to infinity. */
                CHECK(r == TT_ERROR_OUT_OF_MEMORY || r == TT_ERROR_NON_FINITE,
                      "quadrangulating a valid mesh failed: %s", err.message);
                continue;
            }
            check_mesh(q, NULL, strict);
            CHECK(q->nfaces == m->ncorners && q->ncorners == 4 * m->ncorners, "quadrangulated %d faces %d corners",
                  q->nfaces, q->ncorners);
            CHECK(q->min_face_size == 4 && q->max_face_size == 4, "quadrangulated %d..%d", q->min_face_size,
                  q->max_face_size);
            CHECK(!(q->flags & TT_MESH_BORROW_POSITIONS), "quadrangulated mesh borrows");
            if (stats_ok)
                CHECK(q->nverts == m->nverts + st.edges + m->nfaces, "quadrangulated %d verts, expected %d+%d+%d",
                      q->nverts, m->nverts, st.edges, m->nfaces);
            for (v = 0; v < 3 * m->nverts && scheme == TT_SUBDIVIDE_LINEAR; ++v)
                CHECK(memcmp(&q->pos[v], &m->pos[v], sizeof(float)) == 0 || (m->vert_corner[v / 3] < 0),
                      "linear quadrangulation moved old vertex %d", v / 3);
            exercise(q, layout, seed + 1, strict, a, depth + 1);
            tt_mesh_free(q);
        }
    }
    free(corner_loop);
    free(face_comp);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    reader rd;
    fz_alloc a;
    const tt_allocator *alloc;
    tt_mesh_desc desc;
    tt_tile_layout layout;
    tt_mesh *mesh = (tt_mesh *)&rd;     /* must be set to NULL on failure */
    tt_error err;
    tt_result r;
    uint8_t flags, lay, abuse;
    int nverts, nfaces, fixed, ncorners = 0, f, c, v, k;
    int *sizes = NULL, *indices = NULL;
    float *pos = NULL;
    uint64_t seed;

    rd.p = data;
    rd.n = size;
    rd.at = 0;
    memset(&desc, 0, sizeof desc);
    memset(&layout, 0, sizeof layout);

    flags = rd_u8(&rd);
    nverts = rd_u8(&rd);
    nfaces = rd_u8(&rd) % 64;
    lay = rd_u8(&rd);
    layout.colors = lay & 0x7f;
    abuse = lay >> 7;
    k = rd_u8(&rd);
    alloc = fz_alloc_init(&a, (flags & 16) ? (long)k + 1 : 0);
    lay = rd_u8(&rd);
    layout.tile_size = lay & 15;
    layout.gutter = (lay >> 4) - 1;
    seed = rd_u8(&rd);
    seed |= (uint64_t)rd_u8(&rd) << 8;
    fixed = (flags >> 5) & 7;

    sizes = (int *)malloc(sizeof(int) * (size_t)(nfaces + 1));
    if (!sizes) abort();
    for (f = 0; f < nfaces; ++f) {
        sizes[f] = (flags & 4) ? (rd_u8(&rd) & 31) : (fixed ? fixed : 3);
        ncorners += sizes[f];
    }
    indices = (int *)malloc(sizeof(int) * (size_t)(ncorners + 1));
    if (!indices) abort();
    /* read corners face by face; a face cut short by the end of the input is dropped */
    for (f = 0, c = 0; f < nfaces; ++f) {
        if (sizes[f] > 0 && rd.n - rd.at < (size_t)sizes[f]) break;
        for (k = 0; k < sizes[f]; ++k) indices[c++] = index_from_byte(rd_u8(&rd), nverts);
    }
    nfaces = f;
    ncorners = c;

    pos = (float *)malloc(sizeof(float) * 3 * (size_t)(nverts + 1));
    if (!pos) abort();
    for (v = 0; v < nverts; ++v) {
        float t = (float)v / 16.0f;
        if ((flags & 8) && rd.n - rd.at >= 12) {
            memcpy(&pos[3 * v], rd.p + rd.at, 12);
            rd.at += 12;
        } else if (!(flags & 8) && rd.n - rd.at >= 3) {
            for (k = 0; k < 3; ++k) pos[3 * v + k] = coord_from_byte(rd_u8(&rd));
        } else {
            pos[3 * v] = t;
            pos[3 * v + 1] = t * t;
            pos[3 * v + 2] = t * t * t;
        }
    }

    desc.positions = pos;
    desc.nverts = nverts;
    desc.indices = indices;
    desc.nfaces = nfaces;
    if (flags & 4)
        desc.face_sizes = sizes;
    else
        desc.fixed_face_size = fixed;
    desc.flags = flags & (TT_MESH_PERMISSIVE | TT_MESH_BORROW_POSITIONS);

    if (abuse) {
        static const tt_result expect[8] = {TT_ERROR_INVALID_ARGUMENT, TT_ERROR_INVALID_ARGUMENT,
                                            TT_ERROR_INVALID_ARGUMENT, TT_ERROR_INVALID_ARGUMENT,
                                            TT_ERROR_TOO_LARGE,        TT_ERROR_TOO_LARGE,
                                            TT_ERROR_FACE_TOO_SMALL,   TT_ERROR_TOO_LARGE};
        int how = (int)(seed & 7);
        desc.nfaces = 1;    /* at least one face: an empty mesh would be reported first */
        desc.face_sizes = NULL;
        desc.fixed_face_size = 3;
        switch (how) {
        case 0: desc.nverts = -1 - (int)(seed >> 3); break;
        case 1: desc.nfaces = -1 - (int)(seed >> 3); break;
        case 2: desc.indices = NULL; break;
        case 3: desc.positions = NULL; desc.nverts = nverts > 0 ? nverts : 1; break;
        case 4: desc.fixed_face_size = INT_MAX - (int)(seed >> 3); break;
        case 5: sizes[0] = 0x40000000 + (int)(seed >> 3); desc.face_sizes = sizes; break;
        case 6: desc.fixed_face_size = -1 - (int)(seed >> 3); break;
        default: desc.nfaces = INT_MAX - (int)(seed >> 3); desc.fixed_face_size = 4; break;
        }
        memset(&err, 0x55, sizeof err);
        r = tt_mesh_build(&desc, alloc, &mesh, &err);
        CHECK(r == expect[how], "abuse %d: got %d, expected %d (%s)", how, (int)r, (int)expect[how],
              r == TT_OK ? "built" : err.message);
        fz_check_null("tt_mesh_build", r, mesh);
        check_error(r, &err, 1, 0, &a);
        CHECK(a.count == 0, "abuse %d: %ld allocations before the description was checked", how, a.count);
        mesh = (tt_mesh *)&rd;
        CHECK(tt_mesh_build(NULL, alloc, &mesh, NULL) == TT_ERROR_INVALID_ARGUMENT && mesh == NULL, "NULL desc");
        CHECK(tt_mesh_build(&desc, alloc, NULL, NULL) == TT_ERROR_INVALID_ARGUMENT, "NULL out_mesh");
        {
            /* an allocator with only one of alloc and free */
            tt_allocator half = a.tt;
            if (seed & 8)
                half.free = NULL;
            else
                half.alloc = NULL;
            desc.nverts = nverts;
            desc.positions = pos;
            desc.indices = indices;
            mesh = (tt_mesh *)&rd;
            memset(&err, 0x55, sizeof err);
            r = tt_mesh_build(&desc, &half, &mesh, &err);
            CHECK(r < 0, "a half allocator was accepted");
            check_error(r, &err, 1, 0, &a);
            fz_check_null("tt_mesh_build (half allocator)", r, mesh);
        }
        fz_check_all_freed(&a);
        free(sizes);
        free(indices);
        free(pos);
        return 0;
    }

    memset(&err, 0x55, sizeof err);
    r = tt_mesh_build(&desc, alloc, &mesh, &err);
    if (r != TT_OK) {
        fz_check_null("tt_mesh_build", r, mesh);
        check_error(r, &err, nfaces, ncorners, &a);
        CHECK(r == TT_ERROR_EMPTY_MESH || r == TT_ERROR_FACE_TOO_SMALL || r == TT_ERROR_TOO_LARGE ||
                  r == TT_ERROR_NON_FINITE || r == TT_ERROR_INDEX_OUT_OF_RANGE || r == TT_ERROR_REPEATED_VERTEX ||
                  r == TT_ERROR_ZERO_AREA_FACE || r == TT_ERROR_NON_MANIFOLD_EDGE ||
                  r == TT_ERROR_INCONSISTENT_ORIENTATION || r == TT_ERROR_NON_MANIFOLD_VERTEX ||
                  r == TT_ERROR_OUT_OF_MEMORY,
              "tt_mesh_build returned %d: %s", (int)r, err.message);
        CHECK(!(flags & TT_MESH_PERMISSIVE) ||
                  (r != TT_ERROR_ZERO_AREA_FACE && r != TT_ERROR_NON_MANIFOLD_EDGE && r != TT_ERROR_REPEATED_VERTEX &&
                   r != TT_ERROR_INCONSISTENT_ORIENTATION && r != TT_ERROR_NON_MANIFOLD_VERTEX),
              "permissive build refused with %d: %s", (int)r, err.message);
    } else {
        int strict = !(flags & TT_MESH_PERMISSIVE);
        CHECK(mesh->nfaces == nfaces && mesh->ncorners == ncorners && mesh->nverts == nverts,
              "mesh %d/%d/%d from %d/%d/%d", mesh->nfaces, mesh->ncorners, mesh->nverts, nfaces, ncorners, nverts);
        CHECK(((flags & TT_MESH_BORROW_POSITIONS) != 0) == (mesh->pos == pos), "borrowing");
        CHECK(memcmp(mesh->pos, pos, sizeof(float) * 3 * (size_t)nverts) == 0, "positions changed");
        check_mesh(mesh, indices, strict);
        exercise(mesh, &layout, seed, strict, &a, 0);
        tt_mesh_free(mesh);
    }
    fz_check_all_freed(&a);
    free(sizes);
    free(indices);
    free(pos);
    return 0;
}
