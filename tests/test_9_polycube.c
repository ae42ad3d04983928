/* tests/test_9_polycube.c - unit tests for section 9 of tiledtex.h, the
   polycube of Chang and Lin: voxelisation, fill, repair, correction, the
   surface S and its Wang colouring. Run by run_polycube_tests()
   (tests/test_common.c calls it). Occupancy is checked against the shapes'
   own definitions and masks are recomputed from the occupancy array. */
#include "test_common.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ------------------------------------------------------------------------ */
/* Shapes                                                                   */
/* ------------------------------------------------------------------------ */

/* The closed surface of a set of unit cubes: set[i + nx * (j + ny * k)] for
   cube [i, i+1] x [j, j+1] x [k, k+1] (times scale). One quad per cube face
   with an empty neighbour, outward CCW, on shared lattice vertices; each
   quad split into 2 triangles when `triangles`. The set must be
   well-composed (no edge or vertex contacts) for the result to be a
   manifold mesh. */
static void make_cube_set(tmesh *m, const unsigned char *set, int nx, int ny, int nz, double scale, int triangles)
{
    int *vid = (int *)malloc(sizeof(int) * (size_t)(nx + 1) * (ny + 1) * (nz + 1));
    int i, j, k, side, n = (nx + 1) * (ny + 1) * (nz + 1);
    for (i = 0; i < n; i++) vid[i] = -1;
    for (k = 0; k < nz; k++)
        for (j = 0; j < ny; j++)
            for (i = 0; i < nx; i++) {
                if (!set[i + nx * (j + ny * k)]) continue;
                for (side = 0; side < 6; side++) {
                    int a = side / 2, sign = side % 2 ? -1 : 1, c[3], nb[3], b = (a + 1) % 3, d = (a + 2) % 3;
                    int corner[4][3], q, v[4];
                    c[0] = i; c[1] = j; c[2] = k;
                    nb[0] = i; nb[1] = j; nb[2] = k;
                    nb[a] += sign;
                    if (nb[0] >= 0 && nb[1] >= 0 && nb[2] >= 0 && nb[0] < nx && nb[1] < ny && nb[2] < nz &&
                        set[nb[0] + nx * (nb[1] + ny * nb[2])])
                        continue;
                    /* (e_b, e_d, e_a) is right-handed: b -> d turns CCW seen from +a. */
                    for (q = 0; q < 4; q++) {
                        int db = (q == 1 || q == 2), dd = (q >= 2);
                        if (sign < 0) { int t = db; db = dd; dd = t; }
                        corner[q][a] = c[a] + (sign > 0);
                        corner[q][b] = c[b] + db;
                        corner[q][d] = c[d] + dd;
                    }
                    for (q = 0; q < 4; q++) {
                        int id = corner[q][0] + (nx + 1) * (corner[q][1] + (ny + 1) * corner[q][2]);
                        if (vid[id] < 0)
                            vid[id] = tm_vert(m, scale * corner[q][0], scale * corner[q][1], scale * corner[q][2]);
                        v[q] = vid[id];
                    }
                    if (triangles) {
                        tm_tri(m, v[0], v[1], v[2]);
                        tm_tri(m, v[0], v[2], v[3]);
                    } else {
                        tm_quad(m, v[0], v[1], v[2], v[3]);
                    }
                }
            }
    free(vid);
}

/* A closed box [lo, hi] of 12 triangles with its own 8 vertices. */
static void make_box(tmesh *m, const double lo[3], const double hi[3])
{
    unsigned char one = 1;
    tmesh unit;
    int i;
    memset(&unit, 0, sizeof unit);
    make_cube_set(&unit, &one, 1, 1, 1, 1.0, 1);
    for (i = 0; i < unit.nv; i++)
        tm_vert(m, unit.pos[3 * i] ? hi[0] : lo[0], unit.pos[3 * i + 1] ? hi[1] : lo[1],
                unit.pos[3 * i + 2] ? hi[2] : lo[2]);
    for (i = 0; i < unit.nf; i++)
        tm_tri(m, m->nv - unit.nv + unit.idx[3 * i], m->nv - unit.nv + unit.idx[3 * i + 1],
               m->nv - unit.nv + unit.idx[3 * i + 2]);
    tm_free(&unit);
}

static tt_polycube *polycube_of(const tmesh *m, const tt_polycube_options *o, tt_polycube_report *rep,
                                tt_result *result)
{
    tt_mesh *mesh = NULL;
    tt_polycube *pc = NULL;
    tt_error err;
    *result = build(m, 0, &mesh, &err);
    if (*result != TT_OK) {
        printf("test mesh does not build: %s\n", err.message);
        return NULL;
    }
    *result = tt_polycube_build(mesh, o, NULL, &pc, rep, &err);
    if (*result != TT_OK) printf("tt_polycube_build: %s\n", err.message);
    tt_mesh_free(mesh);
    return pc;
}

/* The 8-cube mask around lattice point (i, j, k) of pc's occupancy. */
static int pc_mask(const tt_polycube *pc, int i, int j, int k)
{
    int mask = 0, bit;
    for (bit = 0; bit < 8; bit++) {
        int x = i - 1 + (bit & 1), y = j - 1 + ((bit >> 1) & 1), z = k - 1 + (bit >> 2);
        if (x < 0 || y < 0 || z < 0 || x >= pc->dims[0] || y >= pc->dims[1] || z >= pc->dims[2]) continue;
        if (pc->occupied[x + pc->dims[0] * (y + pc->dims[1] * z)]) mask |= 1 << bit;
    }
    return mask;
}

/* Lattice points whose mask is neither empty, full nor a disc. */
static int pc_bad_points(const tt_polycube *pc)
{
    int i, j, k, bad = 0;
    for (k = 0; k <= pc->dims[2]; k++)
        for (j = 0; j <= pc->dims[1]; j++)
            for (i = 0; i <= pc->dims[0]; i++) {
                int mask = pc_mask(pc, i, j, k);
                if (mask != 0 && mask != 255 && !internal_polycube_mask_is_disc(mask)) bad++;
            }
    return bad;
}

/* Does pc's occupancy equal `set` (nx x ny x nz, each set cube `sub` x sub x
   sub polycube cubes) placed at the padding offset 2? */
static int pc_equals_set(const tt_polycube *pc, const unsigned char *set, int nx, int ny, int nz, int sub)
{
    int i, j, k, wrong = 0;
    if (pc->dims[0] != nx * sub + 4 || pc->dims[1] != ny * sub + 4 || pc->dims[2] != nz * sub + 4) return 0;
    for (k = 0; k < pc->dims[2]; k++)
        for (j = 0; j < pc->dims[1]; j++)
            for (i = 0; i < pc->dims[0]; i++) {
                int x = i - 2, y = j - 2, z = k - 2, want = 0;
                if (x >= 0 && y >= 0 && z >= 0 && x < nx * sub && y < ny * sub && z < nz * sub)
                    want = set[x / sub + nx * (y / sub + ny * (z / sub))];
                wrong += pc->occupied[i + pc->dims[0] * (j + pc->dims[1] * k)] != want;
            }
    return wrong == 0;
}

/* ------------------------------------------------------------------------ */
/* The configuration table                                                  */
/* ------------------------------------------------------------------------ */

static void test_masks(void)
{
    int mask, discs = 0, disagree = 0, by_type[7][9];
    memset(by_type, 0, sizeof by_type);
    for (mask = 0; mask < 256; mask++) {
        int disc = internal_polycube_mask_is_disc(mask), critical = internal_polycube_mask_critical(mask);
        int pop = 0, facelets = 0, bit, b;
        for (bit = 0; bit < 8; bit++) pop += (mask >> bit) & 1;
        for (bit = 0; bit < 8; bit++)
            for (b = 0; b < 3; b++)
                if (!((bit >> b) & 1) && ((mask >> bit) & 1) != ((mask >> (bit | 1 << b)) & 1)) facelets++;
        if (disc) {
            discs++;
            by_type[facelets][pop]++;
        }
        if (mask != 0 && mask != 255 && disc == (critical != 0)) {
            if (!disagree) DETAIL("mask 0x%02x: disc %d, critical %d", mask, disc, critical);
            disagree++;
        }
    }
    CHECK(discs == 126, "masks whose surface is a disc: 126, got %d", discs);
    CHECK(disagree == 0, "disc <=> no critical configuration on all non-empty, non-full masks: %d disagree", disagree);
    CHECK(!internal_polycube_mask_is_disc(0) && !internal_polycube_mask_is_disc(255) &&
              !internal_polycube_mask_critical(0) && !internal_polycube_mask_critical(255),
          "empty and full masks have no surface and no critical configuration");
    CHECK(by_type[3][1] == 8 && by_type[3][7] == 8, "corners: 8 + 8, got %d + %d", by_type[3][1], by_type[3][7]);
    CHECK(by_type[4][2] == 12 && by_type[4][6] == 12 && by_type[4][4] == 6, "edges 12 + 12, flat 6: %d %d %d",
          by_type[4][2], by_type[4][6], by_type[4][4]);
    CHECK(by_type[5][3] == 24 && by_type[5][5] == 24, "L: 24 + 24, got %d + %d", by_type[5][3], by_type[5][5]);
    CHECK(by_type[6][4] == 32, "tripod 8 + staircase 24 = 32, got %d", by_type[6][4]);
    CHECK(internal_polycube_mask_critical(0x09) == 1 && internal_polycube_mask_critical(0x81) == 2 &&
              internal_polycube_mask_critical(0x7e) == 3,
          "an edge-only pair is a checkerboard, an antipodal pair one, its complement the complement");
}

/* ------------------------------------------------------------------------ */
/* Voxelisation against an independent computation                          */
/* ------------------------------------------------------------------------ */

/* Does the triangle t (9 doubles) meet the box [lo, hi]? Sutherland-Hodgman
   clipping of the triangle against the box's 6 planes: non-empty after all. */
static int clip_meets_box(const double *t, const double lo[3], const double hi[3])
{
    double poly[2][24][3];
    int count = 3, cur = 0, a, s, i, k;
    for (i = 0; i < 3; i++)
        for (k = 0; k < 3; k++) poly[0][i][k] = t[3 * i + k];
    for (a = 0; a < 3 && count > 0; a++)
        for (s = 0; s < 2 && count > 0; s++) {
            int out = 0;
            for (i = 0; i < count; i++) {
                const double *p = poly[cur][i], *q = poly[cur][(i + 1) % count];
                double dp = s ? hi[a] - p[a] : p[a] - lo[a], dq = s ? hi[a] - q[a] : q[a] - lo[a];
                if (dp >= 0) { memcpy(poly[1 - cur][out++], p, sizeof(double) * 3); }
                if ((dp >= 0) != (dq >= 0)) {
                    double tt = dp / (dp - dq);
                    for (k = 0; k < 3; k++) poly[1 - cur][out][k] = p[k] + tt * (q[k] - p[k]);
                    out++;
                }
            }
            count = out;
            cur = 1 - cur;
        }
    return count > 0;
}

/* Voxelise one triangle on a unit grid at the origin; count marked cubes
   that do not meet the box grown by tol and unmarked ones whose box shrunk
   by tol it meets. */
static void voxelize_triangle(const double *t, int n, unsigned char *mark, int *extra, int *missing, int *zero)
{
    tmesh m;
    tt_mesh *mesh = NULL;
    tt_error err;
    const double origin[3] = {0, 0, 0}, tol = 1e-4;
    int dims[3], i, j, k;
    dims[0] = dims[1] = dims[2] = n;
    memset(&m, 0, sizeof m);
    for (i = 0; i < 3; i++) tm_vert(&m, t[3 * i], t[3 * i + 1], t[3 * i + 2]);
    tm_tri(&m, 0, 1, 2);
    *extra = *missing = 0;
    memset(mark, 0, (size_t)n * n * n);
    if (build(&m, TT_MESH_PERMISSIVE, &mesh, &err) != TT_OK) {
        tm_free(&m);
        *missing = -1;
        return;
    }
    *zero = internal_polycube_voxelize(mesh, origin, 1.0, dims, mark);
    for (k = 0; k < n; k++)
        for (j = 0; j < n; j++)
            for (i = 0; i < n; i++) {
                double glo[3], ghi[3], slo[3], shi[3];
                glo[0] = i - tol; glo[1] = j - tol; glo[2] = k - tol;
                ghi[0] = i + 1 + tol; ghi[1] = j + 1 + tol; ghi[2] = k + 1 + tol;
                slo[0] = i + tol; slo[1] = j + tol; slo[2] = k + tol;
                shi[0] = i + 1 - tol; shi[1] = j + 1 - tol; shi[2] = k + 1 - tol;
                if (mark[i + n * (j + n * k)]) *extra += !clip_meets_box(t, glo, ghi);
                else *missing += clip_meets_box(t, slo, shi) && !*zero;
            }
    tt_mesh_free(mesh);
    tm_free(&m);
}

static void test_voxelize(void)
{
    const int n = 12;
    unsigned char *mark = (unsigned char *)malloc(40 * 40 * 40);
    int trial, extra = 0, missing = 0, zero = 0, unsampled = 0, e, mi, s;
    double t[9];
    lcg_seed(91);
    for (trial = 0; trial < 60; trial++) {
        for (e = 0; e < 9; e++) t[e] = 1.0 + 10.0 * lcg_unit();
        if (trial % 3 == 0)   /* a small one, inside a few cubes */
            for (e = 3; e < 9; e++) t[e] = t[e % 3] + 1.5 * (lcg_unit() - 0.5);
        voxelize_triangle(t, n, mark, &e, &mi, &zero);
        extra += e;
        missing += mi;
        /* 10^4 samples: the cube of every sample away from the lattice planes is marked */
        for (s = 0; s < 10000; s++) {
            double a = lcg_unit(), b = lcg_unit(), p[3];
            int k, cube[3], near_plane = 0;
            if (a + b > 1) { a = 1 - a; b = 1 - b; }
            for (k = 0; k < 3; k++) {
                p[k] = t[k] + a * (t[3 + k] - t[k]) + b * (t[6 + k] - t[k]);
                cube[k] = (int)floor(p[k]);
                near_plane |= fabs(p[k] - floor(p[k] + 0.5)) < 1e-4;
            }
            if (!near_plane) unsampled += !mark[cube[0] + n * (cube[1] + n * cube[2])];
        }
    }
    CHECK(extra == 0, "marked cubes all within 1e-4 h of the triangle: %d are not", extra);
    CHECK(missing == 0, "cubes the triangle enters (by more than 1e-4 h) all marked: %d are not", missing);
    CHECK(unsampled == 0, "cubes holding a sample point all marked: %d samples in unmarked cubes", unsampled);

    {   /* A triangle in the lattice plane z = 5, normal +z: only the cubes behind it (k = 4). */
        const double flat[9] = {2.2, 2.3, 5, 8.7, 3.1, 5, 4.4, 9.6, 5};
        int i, in_front = 0, behind = 0;
        voxelize_triangle(flat, n, mark, &e, &mi, &zero);
        for (i = 0; i < n * n * n; i++) {
            if (!mark[i]) continue;
            if (i / (n * n) == 4) behind++;
            else in_front++;
        }
        CHECK(behind > 10 && in_front == 0, "a face on a lattice plane claims the layer behind it only (%d, %d)",
              behind, in_front);
    }
    {   /* Touching a lattice edge at one point: the cubes across it stay unmarked. */
        const double touch[9] = {5, 5, 5.5, 3, 4, 5.2, 4, 3, 5.7};
        voxelize_triangle(touch, n, mark, &e, &mi, &zero);
        CHECK(mark[4 + n * (4 + n * 5)] && !mark[5 + n * (5 + n * 5)] && !mark[4 + n * (5 + n * 5)] &&
                  !mark[5 + n * (4 + n * 5)],
              "a triangle touching a cube edge at a point claims only its own cube");
        CHECK(e == 0 && mi == 0, "and agrees with clipping (%d extra, %d missing)", e, mi);
    }
    {   /* Zero area: counted, nothing marked. */
        const double line[9] = {1, 1, 1, 5, 5, 5, 3, 3, 3};
        int i, marked = 0;
        voxelize_triangle(line, n, mark, &e, &mi, &zero);
        for (i = 0; i < n * n * n; i++) marked += mark[i];
        CHECK(zero == 1 && marked == 0, "a zero-area triangle is skipped and counted (%d, %d marked)", zero, marked);
    }
    {   /* Axis-parallel, inside one cube (MathGeoLib#51). */
        const double inside[9] = {5.2, 5.2, 5.5, 5.8, 5.3, 5.5, 5.4, 5.9, 5.5};
        int i, marked = 0;
        voxelize_triangle(inside, n, mark, &e, &mi, &zero);
        for (i = 0; i < n * n * n; i++) marked += mark[i];
        CHECK(marked == 1 && mark[5 + n * (5 + n * 5)], "an axis-parallel triangle inside a cube marks it (%d)",
              marked);
    }
    {   /* One triangle over about 1000 cubes. */
        const double big[9] = {0.5, 0.5, 0.5, 39.3, 1.7, 20.2, 2.1, 38.9, 37.6};
        int i, marked = 0;
        voxelize_triangle(big, 40, mark, &e, &mi, &zero);
        for (i = 0; i < 40 * 40 * 40; i++) marked += mark[i];
        CHECK(marked > 1000 && e == 0 && mi == 0, "a triangle over %d cubes: %d extra, %d missing", marked, e, mi);
    }
    free(mark);
}

/* ------------------------------------------------------------------------ */
/* Cubes and unions of boxes give themselves                                */
/* ------------------------------------------------------------------------ */

static void test_cube_block(void)
{
    unsigned char one = 1;
    int n, bad = 0, as_quads;
    for (as_quads = 0; as_quads < 2; as_quads++)
        for (n = 1; n <= 8; n++) {
            tmesh m;
            tt_polycube_options o;
            tt_polycube_report rep;
            tt_result r;
            tt_polycube *pc;
            unsigned char block[1];
            memset(&m, 0, sizeof m);
            make_cube_set(&m, &one, 1, 1, 1, 1.0, !as_quads);
            memset(&o, 0, sizeof o);
            o.resolution = n;
            pc = polycube_of(&m, &o, &rep, &r);
            block[0] = 1;
            if (!pc || !pc_equals_set(pc, block, 1, 1, 1, n) || rep.cubes != n * n * n ||
                rep.quads != 6 * n * n || pc->surface->nfaces != 6 * n * n || rep.components != 1 ||
                rep.polycube_genus != 0 || rep.mesh_genus != 0 || rep.genus_differs || rep.removed != 0 ||
                rep.repaired != 0 || rep.resolution != n || !near(rep.cube_size, 1.0 / n, 1e-12)) {
                if (!bad)
                    DETAIL("N = %d (%s): result %d, cubes %d, quads %d, removed %d, repaired %d", n,
                           as_quads ? "quads" : "triangles", r, rep.cubes, rep.quads, rep.removed, rep.repaired);
                bad++;
            }
            tt_polycube_free(pc);
            tm_free(&m);
        }
    CHECK(bad == 0, "the unit cube at N = 1..8 (triangles and quads) is the N^3 block, 6N^2 quads: %d wrong", bad);
}

static void check_set(const char *name, const unsigned char *set, int nx, int ny, int nz)
{
    int sub;
    for (sub = 1; sub <= 2; sub++) {
        tmesh m;
        tt_polycube_options o;
        tt_polycube_report rep;
        tt_result r;
        tt_polycube *pc;
        int longest = nx > ny ? (nx > nz ? nx : nz) : (ny > nz ? ny : nz);
        memset(&m, 0, sizeof m);
        make_cube_set(&m, set, nx, ny, nz, 0.7, 1);
        memset(&o, 0, sizeof o);
        o.resolution = longest * sub;
        pc = polycube_of(&m, &o, &rep, &r);
        CHECK(pc && pc_equals_set(pc, set, nx, ny, nz, sub), "%s at %d cubes per unit: the polycube is the union",
              name, sub);
        if (pc && !pc_equals_set(pc, set, nx, ny, nz, sub))
            DETAIL("dims %d %d %d, %d cubes, %d filled, %d repaired, %d removed, %d reverted", rep.dims[0],
                   rep.dims[1], rep.dims[2], rep.cubes, rep.filled, rep.repaired, rep.removed,
                   rep.correction_reverted);
        CHECK(pc && pc_bad_points(pc) == 0 && rep.components == 1 && rep.polycube_genus == 0 && !rep.genus_differs,
              "%s: manifold S, one component, genus 0 (%d components, genus %d)", name, rep.components,
              rep.polycube_genus);
        if (pc && sub == 1 && set[0] == 1 && nx == 2 && ny == 2 && nz == 2) {
            int i, j, k, concave_corner = 0;
            for (k = 0; k <= pc->dims[2]; k++)
                for (j = 0; j <= pc->dims[1]; j++)
                    for (i = 0; i <= pc->dims[0]; i++) concave_corner += pc_mask(pc, i, j, k) == (255 & ~0x80);
            CHECK(concave_corner == 1, "%s has one concave corner (7 of 8 cubes), got %d", name, concave_corner);
        }
        tt_polycube_free(pc);
        tm_free(&m);
    }
}

static void test_unions(void)
{
    /* L: 3 x 2 x 1 without cube (2, 1, 0); U: 3 x 2 x 2 without the middle column on top. */
    const unsigned char L[6] = {1, 1, 1, 1, 1, 0};
    const unsigned char U[12] = {1, 1, 1, 1, 1, 1, 1, 0, 1, 1, 0, 1};
    const unsigned char notched[8] = {1, 1, 1, 1, 1, 1, 1, 0};
    check_set("L-shape", L, 3, 2, 1);
    check_set("U-shape", U, 3, 2, 2);
    check_set("cube without one octant", notched, 2, 2, 2);
}

/* ------------------------------------------------------------------------ */
/* Contacts along an edge and at a vertex                                   */
/* ------------------------------------------------------------------------ */

static void check_contact(const char *name, const double lo2[3], const double hi2[3], unsigned flags)
{
    const double lo1[3] = {0, 0, 0}, hi1[3] = {1, 1, 1};
    tmesh m;
    tt_mesh *mesh = NULL;
    tt_polycube *pc = NULL;
    tt_polycube_options o;
    tt_polycube_report rep;
    tt_error err;
    tt_result r;
    memset(&m, 0, sizeof m);
    make_box(&m, lo1, hi1);
    make_box(&m, lo2, hi2);
    CHECK(build(&m, 0, &mesh, &err) == TT_OK, "%s: two boxes build", name);
    if (!mesh) { tm_free(&m); return; }
    {   /* Before repair: the voxels alone hold a critical configuration. */
        const double origin[3] = {-2, -2, -2};
        const int dims[3] = {6, 6, 6};
        unsigned char mark[216];
        int i, j, k, critical = 0, cubes = 0;
        memset(mark, 0, sizeof mark);
        internal_polycube_voxelize(mesh, origin, 1.0, dims, mark);
        for (i = 0; i < 216; i++) cubes += mark[i];
        for (k = 1; k < 6; k++)
            for (j = 1; j < 6; j++)
                for (i = 1; i < 6; i++) {
                    int mask = 0, bit;
                    for (bit = 0; bit < 8; bit++)
                        mask |= mark[(i - 1 + (bit & 1)) + 6 * ((j - 1 + ((bit >> 1) & 1)) + 6 * (k - 1 + (bit >> 2)))]
                                << bit;
                    critical += internal_polycube_mask_critical(mask) != 0;
                }
        CHECK(cubes == 2 && critical > 0, "%s: the voxels are the 2 boxes (%d) and the detector finds the contact (%d)",
              name, cubes, critical);
    }
    memset(&o, 0, sizeof o);
    o.cube_size = 1.0;
    o.flags = flags;
    r = tt_polycube_build(mesh, &o, NULL, &pc, &rep, &err);
    CHECK(r == TT_OK && pc, "%s: the polycube builds, S passes the strict builder (%d: %s)", name, r, err.message);
    if (pc) {
        CHECK(pc_bad_points(pc) == 0, "%s: every lattice point is a disc, empty or full after repair", name);
        CHECK(rep.repaired > 0 && rep.components == 1 && rep.polycube_genus == 0,
              "%s: repaired %d cubes, one component (%d), genus 0 (%d)", name, rep.repaired, rep.components,
              rep.polycube_genus);
        CHECK(rep.mesh_genus == 0 && rep.genus_differs == 0, "%s: two spheres (genus 0) and a sphere agree", name);
    }
    tt_polycube_free(pc);
    tt_mesh_free(mesh);
    tm_free(&m);
}

static void test_contacts(void)
{
    const double edge_lo[3] = {1, 1, 0}, edge_hi[3] = {2, 2, 1};
    const double vertex_lo[3] = {1, 1, 1}, vertex_hi[3] = {2, 2, 2};
    check_contact("edge contact", edge_lo, edge_hi, 0);
    check_contact("vertex contact", vertex_lo, vertex_hi, 0);
    check_contact("vertex contact, no correction", vertex_lo, vertex_hi, TT_POLYCUBE_NO_CORRECT);
}

/* ------------------------------------------------------------------------ */
/* Torus genus; open and flat meshes                                        */
/* ------------------------------------------------------------------------ */

static void test_torus(void)
{
    tmesh m;
    tt_polycube_options o;
    tt_polycube_report rep;
    tt_result r;
    tt_polycube *pc;
    memset(&m, 0, sizeof m);
    make_torus(&m, 48, 24, 3.0, 1.0);
    memset(&o, 0, sizeof o);
    o.resolution = 4;
    pc = polycube_of(&m, &o, &rep, &r);
    CHECK(pc && rep.mesh_genus == 1 && rep.polycube_genus == 0 && rep.genus_differs == 1,
          "torus at resolution 4: the hole closes, genus %d vs %d, warned %d", rep.polycube_genus, rep.mesh_genus,
          rep.genus_differs);
    tt_polycube_free(pc);
    o.resolution = 16;
    pc = polycube_of(&m, &o, &rep, &r);
    CHECK(pc && rep.polycube_genus == 1 && rep.components == 1 && rep.genus_differs == 0 && pc_bad_points(pc) == 0,
          "torus at resolution 16: chi 0 (genus %d), one component (%d), no warning (%d)", rep.polycube_genus,
          rep.components, rep.genus_differs);
    CHECK(pc && rep.filled > 0, "the torus's inside is filled (%d cubes)", rep.filled);
    CHECK(pc && rep.inside_out == 0, "the torus winds outward (inside_out %d)", rep.inside_out);
    tt_polycube_free(pc);
    {
        /* the same torus with every face reversed */
        int f, k, first = 0;
        for (f = 0; f < m.nf; f++) {
            for (k = 0; k < m.sizes[f] / 2; k++) {
                int t = m.idx[first + k];
                m.idx[first + k] = m.idx[first + m.sizes[f] - 1 - k];
                m.idx[first + m.sizes[f] - 1 - k] = t;
            }
            first += m.sizes[f];
        }
        pc = polycube_of(&m, &o, &rep, &r);
        CHECK(pc && rep.inside_out == 1, "reversed, the torus is reported inside-out (%d)", rep.inside_out);
        tt_polycube_free(pc);
    }
    tm_free(&m);
}

static void test_open_and_flat(void)
{
    tmesh m;
    tt_polycube_options o;
    tt_polycube_report rep;
    tt_result r;
    tt_polycube *pc;
    memset(&m, 0, sizeof m);
    make_grid(&m, 5, 3);
    memset(&o, 0, sizeof o);
    o.resolution = 5;
    pc = polycube_of(&m, &o, &rep, &r);
    CHECK(pc && rep.dims[0] == 9 && rep.dims[1] == 7 && rep.dims[2] == 5 && rep.cubes == 15 && rep.filled == 0,
          "a flat 5 x 3 grid: one layer of 5 x 3 cubes (dims %d %d %d, %d cubes)", rep.dims[0], rep.dims[1],
          rep.dims[2], rep.cubes);
    CHECK(pc && rep.mesh_genus == -1 && rep.genus_differs == 0 && rep.polycube_genus == 0,
          "an open mesh has no genus to compare (%d)", rep.mesh_genus);
    tt_polycube_free(pc);
    tm_free(&m);
}

/* ------------------------------------------------------------------------ */
/* The correction step (Chang and Lin Sec. 3)                               */
/* ------------------------------------------------------------------------ */

static void test_correction(void)
{
    tmesh m;
    tt_polycube_options o;
    tt_polycube_report with, without, again;
    tt_result r;
    tt_polycube *pc, *plain, *pc2;
    memset(&m, 0, sizeof m);
    make_torus(&m, 48, 24, 3.0, 1.0);
    memset(&o, 0, sizeof o);
    o.resolution = 16;
    pc = polycube_of(&m, &o, &with, &r);
    pc2 = polycube_of(&m, &o, &again, &r);
    o.flags = TT_POLYCUBE_NO_CORRECT;
    plain = polycube_of(&m, &o, &without, &r);
    if (pc && plain && pc2) {
        int c, only_plain = 0, only_corrected = 0;
        for (c = 0; c < pc->dims[0] * pc->dims[1] * pc->dims[2]; c++) {
            only_plain += plain->occupied[c] && !pc->occupied[c];
            only_corrected += pc->occupied[c] && !plain->occupied[c];
        }
        CHECK(with.removed > 0 && with.correction_reverted == 0 && without.removed == 0,
              "the correction removes cubes of the torus (%d), the flag skips it", with.removed);
        CHECK(only_plain > 0 && only_plain <= with.removed && only_corrected <= with.repaired,
              "it only removes cubes, and adds only the repair's: %d fewer, %d more (removed %d, repaired %d)",
              only_plain, only_corrected, with.removed, with.repaired);
        CHECK(with.components == without.components && with.polycube_genus == without.polycube_genus &&
                  pc_bad_points(pc) == 0,
              "and keeps the topology (genus %d vs %d) and a manifold S", with.polycube_genus,
              without.polycube_genus);
        CHECK(memcmp(pc->occupied, pc2->occupied, (size_t)pc->dims[0] * pc->dims[1] * pc->dims[2]) == 0 &&
                  pc->surface->nfaces == pc2->surface->nfaces &&
                  memcmp(pc->surface->corner_vert, pc2->surface->corner_vert,
                         sizeof(int) * (size_t)pc->surface->ncorners) == 0,
              "the same input gives the same polycube and surface");
    }
    tt_polycube_free(pc);
    tt_polycube_free(pc2);
    tt_polycube_free(plain);
    tm_free(&m);

    {   /* A small triangle in the middle of a single cube (the grid is centred on it): the cells of
           most of the cube's corners miss it, so the correction would remove the only cube; that
           changes the topology and is undone. */
        o.flags = 0;
        o.resolution = 0;
        o.cube_size = 1.0;
        memset(&m, 0, sizeof m);
        tm_vert(&m, 0.1, 0.1, 0.2);
        tm_vert(&m, 0.3, 0.1, 0.2);
        tm_vert(&m, 0.1, 0.3, 0.2);
        tm_tri(&m, 0, 1, 2);
        pc = polycube_of(&m, &o, &with, &r);
        CHECK(pc && with.cubes == 1 && with.removed == 0 && with.correction_reverted == 1 && with.quads == 6,
              "a correction that would empty the polycube is undone (%d cubes, %d reverted)", with.cubes,
              with.correction_reverted);
        tt_polycube_free(pc);
        tm_free(&m);
    }
}

/* ------------------------------------------------------------------------ */
/* Corner 0: the tile's orientation                                         */
/* ------------------------------------------------------------------------ */

static void check_orientation(const tt_polycube *pc, int up_axis, int up_sign, const char *name)
{
    int f, wrong = 0;
    const tt_mesh *s = pc->surface;
    for (f = 0; f < s->nfaces; f++) {
        const float *p0 = s->pos + 3 * s->corner_vert[4 * f], *p1 = s->pos + 3 * s->corner_vert[4 * f + 1];
        const float *p3 = s->pos + 3 * s->corner_vert[4 * f + 3];
        double u[3], v[3], n[3], want_v[3] = {0, 0, 0}, want_n[3] = {0, 0, 0};
        int a, side = pc->quad_side[f], normal_axis = side / 2, ok = 1;
        for (a = 0; a < 3; a++) {
            u[a] = (p1[a] - p0[a]) / pc->h;
            v[a] = (p3[a] - p0[a]) / pc->h;
        }
        n[0] = u[1] * v[2] - u[2] * v[1];
        n[1] = u[2] * v[0] - u[0] * v[2];
        n[2] = u[0] * v[1] - u[1] * v[0];
        want_n[normal_axis] = side % 2 ? -1 : 1;
        if (normal_axis != up_axis) want_v[up_axis] = up_sign;
        else want_v[(up_axis + 1) % 3] = -up_sign;
        for (a = 0; a < 3; a++) ok &= near(v[a], want_v[a], 1e-4) && near(n[a], want_n[a], 1e-4);
        if (!ok && !wrong) DETAIL("%s: quad %d side %d: v (%g %g %g)", name, f, side, v[0], v[1], v[2]);
        wrong += !ok;
    }
    CHECK(wrong == 0, "%s: every quad's v axis (corner 0 -> 3) follows the up rule, u x v outward: %d wrong", name,
          wrong);
}

static void test_orientation(void)
{
    const unsigned char L[6] = {1, 1, 1, 1, 1, 0};
    tmesh m;
    tt_polycube_options o;
    tt_polycube_report rep;
    tt_result r;
    tt_polycube *pc;
    memset(&m, 0, sizeof m);
    make_cube_set(&m, L, 3, 2, 1, 1.0, 1);
    memset(&o, 0, sizeof o);
    o.resolution = 6;
    pc = polycube_of(&m, &o, &rep, &r);
    if (pc) check_orientation(pc, 1, 1, "default up (+Y): sides v = +Y, top and bottom v = -Z");
    tt_polycube_free(pc);
    o.up[2] = -0.9;
    o.up[0] = 0.3;
    pc = polycube_of(&m, &o, &rep, &r);
    if (pc) check_orientation(pc, 2, -1, "up (0.3, 0, -0.9): -Z");
    tt_polycube_free(pc);
    tm_free(&m);
}

/* ------------------------------------------------------------------------ */
/* The Wang colouring (Chang and Lin Sec. 3)                                */
/* ------------------------------------------------------------------------ */

static void test_edge_colors(void)
{
    unsigned char one = 1;
    tmesh m;
    tt_polycube_options o;
    tt_polycube_report rep;
    tt_result r;
    tt_polycube *pc;
    tt_error err;
    memset(&m, 0, sizeof m);
    make_cube_set(&m, &one, 1, 1, 1, 1.0, 1);
    memset(&o, 0, sizeof o);
    o.resolution = 4;
    pc = polycube_of(&m, &o, &rep, &r);
    if (pc) {
        const tt_mesh *s = pc->surface;
        int *colors = (int *)malloc(sizeof(int) * (size_t)s->ncorners);
        int *again = (int *)malloc(sizeof(int) * (size_t)s->ncorners);
        uint8_t *types = (uint8_t *)malloc((size_t)s->ncorners);
        int used[3][4], c, a, k, too_many = 0, twins_differ = 0, all_used = 0;
        tt_tile_layout layout = {4, 0, 0};
        CHECK(tt_polycube_edge_colors(pc, 4, 1, 7, colors, &err) == TT_OK, "axis palettes: %s", err.message);
        memset(used, 0, sizeof used);
        for (c = 0; c < s->ncorners; c++) {
            const float *p = s->pos + 3 * s->corner_vert[c], *q = s->pos + 3 * s->corner_vert[tt_mesh_next(s, c)];
            a = fabs(q[0] - p[0]) > 0 ? 0 : (fabs(q[1] - p[1]) > 0 ? 1 : 2);
            used[a][colors[c]] = 1;
            twins_differ += colors[s->twin[c]] != colors[c];
        }
        for (a = 0; a < 3; a++) {
            int n = 0;
            for (k = 0; k < 4; k++) n += used[a][k];
            too_many += n != 2;
        }
        CHECK(too_many == 0 && twins_differ == 0, "each axis uses exactly its 2 colours (%d axes do not), twins agree (%d)",
              too_many, twins_differ);
        CHECK(tt_assign_boundaries(s, &layout, 3, colors, types, &err) == TT_OK,
              "the colours are valid input for tt_assign_boundaries: %s", err.message);
        for (c = 0; c < s->ncorners; c++) too_many += types[c] / 2 != colors[c];
        CHECK(too_many == 0, "tt_assign_boundaries kept the prescribed colours");
        CHECK(tt_polycube_edge_colors(pc, 4, 1, 7, again, &err) == TT_OK &&
                  memcmp(colors, again, sizeof(int) * (size_t)s->ncorners) == 0,
              "same seed, same colours");
        CHECK(tt_polycube_edge_colors(pc, 4, 0, 7, colors, &err) == TT_OK, "all colours: %s", err.message);
        memset(used, 0, sizeof used);
        for (c = 0; c < s->ncorners; c++) used[0][colors[c]] = 1;
        for (k = 0; k < 4; k++) all_used += used[0][k];
        CHECK(all_used == 4, "without palettes all 4 colours appear (%d)", all_used);
        CHECK(tt_polycube_edge_colors(pc, 1, 1, 7, colors, &err) == TT_OK && colors[0] == 0, "one colour");
        CHECK(tt_polycube_edge_colors(pc, 0, 1, 7, colors, &err) == TT_ERROR_INVALID_ARGUMENT &&
                  tt_polycube_edge_colors(pc, TT_MAX_COLORS + 1, 0, 7, colors, &err) == TT_ERROR_INVALID_ARGUMENT &&
                  tt_polycube_edge_colors(NULL, 2, 0, 7, colors, &err) == TT_ERROR_INVALID_ARGUMENT &&
                  tt_polycube_edge_colors(pc, 2, 0, 7, NULL, &err) == TT_ERROR_INVALID_ARGUMENT,
              "colors 0 or above TT_MAX_COLORS, NULL polycube or output: invalid");
        free(colors);
        free(again);
        free(types);
    }
    tt_polycube_free(pc);
    tm_free(&m);
}

/* ------------------------------------------------------------------------ */
/* Errors and allocation failures                                           */
/* ------------------------------------------------------------------------ */

typedef struct pc_oom_ctx {
    const tt_mesh *mesh;
    unsigned flags;
} pc_oom_ctx;

static tt_result pc_oom_call(void *ctx, const tt_allocator *al, tt_error *error)
{
    pc_oom_ctx *c = (pc_oom_ctx *)ctx;
    tt_polycube *pc = (tt_polycube *)&pc;
    tt_polycube_options o;
    tt_result r;
    memset(&o, 0, sizeof o);
    o.cube_size = 0.5;
    o.flags = c->flags;
    r = tt_polycube_build(c->mesh, &o, al, &pc, NULL, error);
    if (error->result != r || (r != TT_OK) != (pc == NULL)) return TT_RESULT_MAX_ENUM;
    tt_polycube_free(pc);
    return r;
}

static void free_only(void *ptr, void *user_data)
{
    (void)ptr;
    (void)user_data;
}

static void test_errors(void)
{
    const double lo1[3] = {0, 0, 0}, hi1[3] = {1, 1, 1}, lo2[3] = {1, 1, 1}, hi2[3] = {2, 2, 2};
    tmesh m;
    tt_mesh *mesh = NULL, empty;
    tt_polycube *pc = (tt_polycube *)&pc;
    tt_polycube_options o;
    tt_polycube_report rep;
    tt_allocator half;
    tt_error err;
    tt_result r;
    pc_oom_ctx ctx;
    memset(&m, 0, sizeof m);
    make_box(&m, lo1, hi1);
    make_box(&m, lo2, hi2);
    if (build(&m, 0, &mesh, &err) != TT_OK) { tm_free(&m); CHECK(0, "two boxes build"); return; }
    memset(&o, 0, sizeof o);
    CHECK(tt_polycube_build(mesh, NULL, NULL, NULL, NULL, &err) == TT_ERROR_INVALID_ARGUMENT, "NULL out");
    r = tt_polycube_build(NULL, NULL, NULL, &pc, &rep, &err);
    CHECK(r == TT_ERROR_INVALID_ARGUMENT && pc == NULL, "NULL mesh: %d", r);
    memset(&empty, 0, sizeof empty);
    r = tt_polycube_build(&empty, NULL, NULL, &pc, NULL, &err);
    CHECK(r == TT_ERROR_EMPTY_MESH && pc == NULL, "no faces: %d", r);
    o.resolution = -1;
    r = tt_polycube_build(mesh, &o, NULL, &pc, NULL, &err);
    CHECK(r == TT_ERROR_INVALID_ARGUMENT && msg_has_number(err.message, -1), "resolution -1: %d (%s)", r, err.message);
    o.resolution = TT_POLYCUBE_MAX_RESOLUTION + 1;
    r = tt_polycube_build(mesh, &o, NULL, &pc, NULL, &err);
    CHECK(r == TT_ERROR_TOO_LARGE, "resolution above the limit: %d", r);
    o.resolution = 0;
    o.cube_size = internal_not_a_number();
    r = tt_polycube_build(mesh, &o, NULL, &pc, NULL, &err);
    CHECK(r == TT_ERROR_NON_FINITE, "cube_size NaN: %d", r);
    o.cube_size = -1;
    r = tt_polycube_build(mesh, &o, NULL, &pc, NULL, &err);
    CHECK(r == TT_ERROR_INVALID_ARGUMENT, "cube_size -1: %d", r);
    o.cube_size = 1e-4;
    r = tt_polycube_build(mesh, &o, NULL, &pc, NULL, &err);
    CHECK(r == TT_ERROR_TOO_LARGE && pc == NULL, "a cube size making 20000 cubes per axis: %d (%s)", r, err.message);
    o.cube_size = 0.005;
    r = tt_polycube_build(mesh, &o, NULL, &pc, NULL, &err);
    CHECK(r == TT_ERROR_TOO_LARGE && pc == NULL, "400^3 cubes, above TT_POLYCUBE_MAX_CUBES: %d (%s)", r, err.message);
    o.cube_size = 0;
    o.up[1] = internal_infinity();
    r = tt_polycube_build(mesh, &o, NULL, &pc, NULL, &err);
    CHECK(r == TT_ERROR_NON_FINITE, "an infinite up: %d", r);
    o.up[1] = 0;
    o.flags = 2;
    r = tt_polycube_build(mesh, &o, NULL, &pc, NULL, &err);
    CHECK(r == TT_ERROR_INVALID_ARGUMENT, "unknown flags: %d", r);
    memset(&half, 0, sizeof half);
    half.free = free_only;
    r = tt_polycube_build(mesh, NULL, &half, &pc, NULL, &err);
    CHECK(r == TT_ERROR_INVALID_ARGUMENT && pc == NULL, "an allocator with free only: %d", r);
    tt_polycube_free(NULL);

    {   /* Zero area everywhere: degenerate triangles of a permissive mesh. */
        tmesh line;
        tt_mesh *flat = NULL;
        memset(&line, 0, sizeof line);
        tm_vert(&line, 0, 0, 0);
        tm_vert(&line, 1, 1, 0);
        tm_vert(&line, 2, 2, 0);
        tm_tri(&line, 0, 1, 2);
        if (build(&line, TT_MESH_PERMISSIVE, &flat, &err) == TT_OK) {
            r = tt_polycube_build(flat, NULL, NULL, &pc, &rep, &err);
            CHECK(r == TT_ERROR_ZERO_AREA_FACE && pc == NULL, "a mesh of zero area: %d", r);
        }
        tt_mesh_free(flat);
        tm_free(&line);
    }

    ctx.mesh = mesh;
    ctx.flags = 0;
    oom_reset();
    oom_sweep("tt_polycube_build(two boxes at a vertex)", pc_oom_call, &ctx, TT_OK);
    ctx.flags = TT_POLYCUBE_NO_CORRECT;
    oom_sweep("tt_polycube_build(two boxes at a vertex, no correction)", pc_oom_call, &ctx, TT_OK);
    tt_mesh_free(mesh);
    tm_free(&m);
}

/* On S itself: the polycube's Wang tiling through the
   tiled-textures machinery. The per-axis colours, tt_assign_boundaries,
   tt_assign_uvs and tt_synthesize_tiles texture S seamlessly: the seam
   score over every edge of S is about 0 (at most 0.05), and the same tiles
   with the quads' coordinates shuffled score at least 0.8 (measured
   0.86 - with n = 2 a quarter of the shuffled edges still match by type,
   so it cannot reach 1). The
   paper's rotation rules (Figs. 3-5) need no code: this is the test that
   they come out of Akleman's per-side rule on S. */
static void test_wang_tiling(void)
{
    tmesh m;
    tt_polycube_options o;
    tt_polycube_report rep;
    tt_result r;
    tt_polycube *pc;
    tt_error err;
    tt_image *photo = NULL;
    tt_tileset *tiles = NULL;
    memset(&m, 0, sizeof m);
    make_torus(&m, 48, 24, 3.0, 1.0);
    memset(&o, 0, sizeof o);
    o.resolution = 10;
    pc = polycube_of(&m, &o, &rep, &r);
    make_value_noise(&photo, 160, 256, 9);
    if (pc && photo) {
        const tt_mesh *s = pc->surface;
        int pal, f, k;
        int *colors = (int *)malloc(sizeof(int) * (size_t)s->ncorners);
        uint8_t *types = (uint8_t *)malloc((size_t)s->ncorners);
        float *uv = (float *)malloc(sizeof(float) * 2 * (size_t)s->ncorners);
        float *shuffled = (float *)malloc(sizeof(float) * 2 * (size_t)s->ncorners);
        for (pal = 0; pal < 2; pal++) {
            tt_synth_options so;
            tt_seam_report fit, control;
            memset(&so, 0, sizeof so);
            so.layout.colors = 2;
            so.layout.tile_size = 32;
            so.layout.gutter = 4;
            so.seed = 5;
            CHECK(tt_polycube_edge_colors(pc, 2, pal, 11, colors, &err) == TT_OK &&
                      tt_assign_boundaries(s, &so.layout, 11, colors, types, &err) == TT_OK &&
                      tt_assign_uvs(s, &so.layout, types, uv, &err) == TT_OK,
                  "the tiling of S (%s)", err.message);
            if (!tiles) CHECK(tt_synthesize_tiles(photo, &so, NULL, &tiles, &err) == TT_OK, "tiles: %s", err.message);
            if (!tiles) break;
            /* a random permutation of the quads' coordinates */
            {
                int *perm = (int *)malloc(sizeof(int) * (size_t)s->nfaces);
                lcg_seed(77);
                for (f = 0; f < s->nfaces; f++) perm[f] = f;
                for (f = s->nfaces - 1; f > 0; f--) {
                    int j = lcg_below(f + 1), t = perm[f];
                    perm[f] = perm[j];
                    perm[j] = t;
                }
                for (f = 0; f < s->nfaces; f++)
                    for (k = 0; k < 8; k++) shuffled[8 * f + k] = uv[8 * perm[f] + k];
                free(perm);
            }
            CHECK(tt_measure_seams(s, uv, &tiles->levels[0], NULL, NULL, &fit, &err) == TT_OK &&
                      tt_measure_seams(s, shuffled, &tiles->levels[0], NULL, NULL, &control, &err) == TT_OK,
                  "seams measured: %s", err.message);
            printf("     Wang tiling of S (%d quads, %s): seam score %.3f, shuffled %.3f\n", s->nfaces,
                   pal ? "per-axis palettes" : "all colours", fit.score, control.score);
            CHECK(fit.score <= 0.05, "S is seamless (score %g)", fit.score);
            CHECK(control.score >= 0.8, "shuffled coordinates show seams (score %g)", control.score);
        }
        free(colors);
        free(types);
        free(uv);
        free(shuffled);
    }
    tt_tileset_free(tiles);
    tt_image_free(photo);
    tt_polycube_free(pc);
    tm_free(&m);
}

/* ------------------------------------------------------------------------ */
/* The vertices' points on S (Chang and Lin Sec. 4)                         */
/* ------------------------------------------------------------------------ */

/* A latitude-longitude sphere of triangles (closed: one vertex per pole),
   outward CCW; with `hemisphere` only the upper half (z >= 0), open at
   the equator. */
static void make_sphere(tmesh *m, int slices, int stacks, double r, const double c[3], int hemisphere)
{
    int i, j, first = m->nv, top, rings = hemisphere ? stacks / 2 : stacks - 1, bottom = -1;
    top = tm_vert(m, c[0], c[1], c[2] + r);
    for (j = 1; j <= rings; j++) {
        double theta = 3.14159265358979323846 * j / stacks;
        for (i = 0; i < slices; i++) {
            double phi = 2.0 * 3.14159265358979323846 * i / slices;
            tm_vert(m, c[0] + r * sin(theta) * cos(phi), c[1] + r * sin(theta) * sin(phi), c[2] + r * cos(theta));
        }
    }
    if (!hemisphere) bottom = tm_vert(m, c[0], c[1], c[2] - r);
    for (i = 0; i < slices; i++) {
        int a = first + 1 + i, b = first + 1 + (i + 1) % slices;
        tm_tri(m, top, a, b);
        for (j = 1; j < rings; j++) {
            int a2 = a + slices, b2 = b + slices;
            tm_tri(m, a, a2, b2);
            tm_tri(m, a, b2, b);
            a = a2;
            b = b2;
        }
        if (bottom >= 0) tm_tri(m, a, bottom, b);
    }
}

/* The area-weighted normal of every vertex (unnormalised; malloc). */
static double *vertex_normals(const tt_mesh *mesh)
{
    double *n = (double *)calloc((size_t)mesh->nverts * 3, sizeof(double));
    int f;
    for (f = 0; f < mesh->nfaces; f++) {
        float fn[3];
        const float *p0 = mesh->pos + 3 * mesh->corner_vert[mesh->face_start[f]];
        const float *p1 = mesh->pos + 3 * mesh->corner_vert[mesh->face_start[f] + 1];
        const float *p2 = mesh->pos + 3 * mesh->corner_vert[mesh->face_start[f] + 2];
        double e1[3], e2[3], area, c[3];
        int k, a;
        for (a = 0; a < 3; a++) {
            e1[a] = p1[a] - p0[a];
            e2[a] = p2[a] - p0[a];
        }
        c[0] = e1[1] * e2[2] - e1[2] * e2[1];
        c[1] = e1[2] * e2[0] - e1[0] * e2[2];
        c[2] = e1[0] * e2[1] - e1[1] * e2[0];
        area = sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);   /* triangles only */
        tt_face_normal(mesh, f, fn);
        for (k = mesh->face_start[f]; k < mesh->face_start[f + 1]; k++)
            for (a = 0; a < 3; a++) n[3 * mesh->corner_vert[k] + a] += area * fn[a];
    }
    return n;
}

/* n_f . n for the quad of point p. */
static double quad_agreement(const tt_polycube *pc, tt_surface_point p, const double *n)
{
    int side = pc->quad_side[p.quad];
    return side % 2 ? -n[side / 2] : n[side / 2];
}

/* What a projection looks like: the points valid, s and t in [0, 1], the
   distance from p to q (by tt_polycube_point_position) in units of h, and
   the vertices whose quad does not face their side. */
typedef struct projection_check {
    int bad_points, disagreeing;
    double max_distance;
} projection_check;

static projection_check check_projection(const tt_polycube *pc, const tt_mesh *mesh, const tt_surface_point *pts)
{
    projection_check c;
    double *n = vertex_normals(mesh);
    int v, a;
    memset(&c, 0, sizeof c);
    for (v = 0; v < mesh->nverts; v++) {
        double x[3], d = 0;
        if (pts[v].quad < 0 || pts[v].quad >= pc->surface->nfaces || !(pts[v].s >= 0 && pts[v].s <= 1) ||
            !(pts[v].t >= 0 && pts[v].t <= 1)) {
            c.bad_points++;
            continue;
        }
        tt_polycube_point_position(pc, pts[v], x);
        for (a = 0; a < 3; a++) d += (x[a] - mesh->pos[3 * v + a]) * (x[a] - mesh->pos[3 * v + a]);
        d = sqrt(d) / pc->h;
        if (d > c.max_distance) c.max_distance = d;
        c.disagreeing += !(quad_agreement(pc, pts[v], n + 3 * v) > 0);
    }
    free(n);
    return c;
}

/* Build the polycube of m and project m's vertices onto it; NULL (and a
   failed CHECK) when something fails. *mesh_out and *pts_out to free. */
static tt_polycube *projected(const tmesh *m, const tt_polycube_options *o, tt_mesh **mesh_out,
                              tt_surface_point **pts_out, tt_polycube_projection_report *pr, tt_polycube_report *rep)
{
    tt_error err;
    tt_polycube *pc = NULL;
    tt_result r;
    *mesh_out = NULL;
    *pts_out = NULL;
    if (build(m, 0, mesh_out, &err) != TT_OK) {
        CHECK(0, "test mesh builds: %s", err.message);
        return NULL;
    }
    r = tt_polycube_build(*mesh_out, o, NULL, &pc, rep, &err);
    if (r != TT_OK) {
        CHECK(0, "tt_polycube_build: %s", err.message);
        return NULL;
    }
    *pts_out = (tt_surface_point *)malloc(sizeof(tt_surface_point) * (size_t)(*mesh_out)->nverts);
    r = tt_polycube_project(pc, *mesh_out, NULL, *pts_out, pr, &err);
    if (r != TT_OK) {
        CHECK(0, "tt_polycube_project: %s", err.message);
        tt_polycube_free(pc);
        return NULL;
    }
    return pc;
}

/* A unit sphere of `segments` x `rings` (make_sphere) built, its polycube
   at `resolution` and its points on S (projected). */
static tt_polycube *projected_sphere(int segments, int rings, int resolution, tmesh *m, tt_mesh **mesh,
                                     tt_surface_point **pts)
{
    const double centre[3] = {0.0, 0.0, 0.0};
    tt_polycube_options o;
    tt_polycube_projection_report pr;
    tt_polycube_report rep;
    memset(m, 0, sizeof *m);
    make_sphere(m, segments, rings, 1.0, centre, 0);
    memset(&o, 0, sizeof o);
    o.resolution = resolution;
    return projected(m, &o, mesh, pts, &pr, &rep);
}

static void test_project_cube(void)
{
    unsigned char one = 1;
    int n, bad = 0;
    for (n = 1; n <= 8; n++) {
        tmesh m;
        tt_mesh *mesh;
        tt_surface_point *pts;
        tt_polycube_options o;
        tt_polycube_projection_report pr;
        tt_polycube_report rep;
        tt_polycube *pc;
        projection_check c;
        memset(&m, 0, sizeof m);
        make_cube_set(&m, &one, 1, 1, 1, 1.0, 1);
        memset(&o, 0, sizeof o);
        o.resolution = n;
        pc = projected(&m, &o, &mesh, &pts, &pr, &rep);
        if (pc) {
            c = check_projection(pc, mesh, pts);
            if (pr.on_surface != mesh->nverts || c.bad_points || c.max_distance > 1e-9 || pr.max_distance > 1e-9 ||
                c.disagreeing) {
                if (!bad)
                    DETAIL("N = %d: on S %d of %d, bad %d, distance %g (report %g), facing the other way %d", n,
                           pr.on_surface, mesh->nverts, c.bad_points, c.max_distance, pr.max_distance, c.disagreeing);
                bad++;
            }
        } else {
            bad++;
        }
        tt_polycube_free(pc);
        tt_mesh_free(mesh);
        free(pts);
        tm_free(&m);
    }
    CHECK(bad == 0, "the cube mesh at N = 1..8: every vertex on S, mapped to itself within 1e-9 h: %d wrong", bad);
}

static void test_project_sphere(void)
{
    const double center[3] = {0.13, -0.07, 0.21};
    int k;
    for (k = 0; k < 2; k++) {
        int res = k ? 16 : 8, in_empty = 0, v;
        tmesh m;
        tt_mesh *mesh;
        tt_surface_point *pts;
        tt_polycube_options o;
        tt_polycube_projection_report pr;
        tt_polycube_report rep;
        tt_polycube *pc;
        projection_check c;
        memset(&m, 0, sizeof m);
        make_sphere(&m, 48, 24, 1.0, center, 0);
        memset(&o, 0, sizeof o);
        o.resolution = res;
        pc = projected(&m, &o, &mesh, &pts, &pr, &rep);
        if (!pc) { tm_free(&m); continue; }
        c = check_projection(pc, mesh, pts);
        for (v = 0; v < mesh->nverts; v++) {
            int x = (int)floor((mesh->pos[3 * v] - pc->origin[0]) / pc->h);
            int y = (int)floor((mesh->pos[3 * v + 1] - pc->origin[1]) / pc->h);
            int z = (int)floor((mesh->pos[3 * v + 2] - pc->origin[2]) / pc->h);
            in_empty += !pc->occupied[x + pc->dims[0] * (y + pc->dims[1] * z)];
        }
        CHECK(c.bad_points == 0 && pr.rays + pr.nearest + pr.fallbacks + pr.on_surface == mesh->nverts,
              "sphere at resolution %d: all %d vertices mapped, s and t in [0, 1] (%d bad; rays %d, nearest %d, "
              "fallbacks %d, on S %d)", res, mesh->nverts, c.bad_points, pr.rays, pr.nearest, pr.fallbacks,
              pr.on_surface);
        CHECK(pr.fallbacks == 0 && c.disagreeing == 0,
              "sphere at resolution %d: no fallback (%d), every quad faces its vertex's side (%d do not)", res,
              pr.fallbacks, c.disagreeing);
        CHECK(c.max_distance < 1.5 && near(c.max_distance, pr.max_distance, 1e-5) && pr.mean_distance <= pr.max_distance,
              "sphere at resolution %d: |p - q| at most %.3f h (report: max %.3f, mean %.3f), below 1.5 h", res,
              c.max_distance, pr.max_distance, pr.mean_distance);
        CHECK(rep.removed > 0 && in_empty > 0,
              "sphere at resolution %d: the correction removed %d cubes and left %d vertices outside the polycube, "
              "mapped inward", res, rep.removed, in_empty);
        tt_polycube_free(pc);
        tt_mesh_free(mesh);
        free(pts);
        tm_free(&m);
    }
}

/* A plate 0.25 h thick is one slab of cubes; its top maps to
   the slab's top, its bottom to the slab's bottom. */
static void test_project_thin_plate(void)
{
    unsigned char set[36];
    const double h = 0.45, thickness = 0.25 * 0.45;
    tmesh m;
    tt_mesh *mesh;
    tt_surface_point *pts;
    tt_polycube_options o;
    tt_polycube_projection_report pr;
    tt_polycube_report rep;
    tt_polycube *pc;
    projection_check c;
    int v, wrong_inside = 0, wrong_sheet = 0, top = 0, bottom = 0;
    memset(set, 1, sizeof set);
    memset(&m, 0, sizeof m);
    make_cube_set(&m, set, 6, 1, 6, 1.0, 1);
    for (v = 0; v < m.nv; v++) {
        /* 3 x thickness x 3, off the lattice in x and z */
        m.pos[3 * v] *= 0.5f;
        m.pos[3 * v + 1] *= (float)thickness;
        m.pos[3 * v + 2] *= 0.5f;
    }
    memset(&o, 0, sizeof o);
    o.cube_size = h;
    pc = projected(&m, &o, &mesh, &pts, &pr, &rep);
    if (!pc) { tm_free(&m); return; }
    c = check_projection(pc, mesh, pts);
    for (v = 0; v < mesh->nverts; v++) {
        const float *p = mesh->pos + 3 * v;
        int is_top = p[1] > 0.5 * thickness, side = pc->quad_side[pts[v].quad];
        int inside = p[0] > 0 && p[0] < 3 && p[2] > 0 && p[2] < 3;
        top += is_top;
        bottom += !is_top;
        if (inside && side != (is_top ? 2 : 3)) wrong_inside++;
        if (side == (is_top ? 3 : 2)) wrong_sheet++;
    }
    CHECK(rep.dims[1] == 5, "the plate is one layer of cubes (%d with padding)", rep.dims[1]);
    CHECK(wrong_inside == 0 && wrong_sheet == 0 && c.disagreeing == 0 && pr.fallbacks == 0,
          "thin plate (%d top, %d bottom vertices): inner vertices on their own side's quads (%d wrong), no vertex "
          "on the opposite sheet (%d), all facing their side (%d not), %d fallbacks", top, bottom, wrong_inside,
          wrong_sheet, c.disagreeing, pr.fallbacks);
    tt_polycube_free(pc);
    tt_mesh_free(mesh);
    free(pts);
    tm_free(&m);
}

/* Open meshes stay shells; the side rule picks the sheet.                  */
static void test_project_open(void)
{
    const double center[3] = {0.05, 0.11, -0.02};
    int k;
    for (k = 0; k < 2; k++) {
        tmesh m;
        tt_mesh *mesh;
        tt_surface_point *pts;
        tt_polycube_options o;
        tt_polycube_projection_report pr;
        tt_polycube_report rep;
        tt_polycube *pc;
        projection_check c;
        const char *name = k ? "a disc (a 7 x 5 grid)" : "a hemisphere";
        memset(&m, 0, sizeof m);
        if (k) make_grid(&m, 7, 5);
        else make_sphere(&m, 40, 20, 1.0, center, 1);
        memset(&o, 0, sizeof o);
        o.resolution = 10;
        pc = projected(&m, &o, &mesh, &pts, &pr, &rep);
        if (!pc) { tm_free(&m); continue; }
        c = check_projection(pc, mesh, pts);
        CHECK(c.bad_points == 0 && pr.fallbacks == 0 && c.disagreeing == 0 && c.max_distance < 1.5,
              "%s at resolution 10: all %d vertices mapped (%d bad), %d fallbacks, %d facing the other way, "
              "|p - q| at most %.3f h (rays %d, nearest %d, on S %d)", name, mesh->nverts, c.bad_points,
              pr.fallbacks, c.disagreeing, c.max_distance, pr.rays, pr.nearest, pr.on_surface);
        tt_polycube_free(pc);
        tt_mesh_free(mesh);
        free(pts);
        tm_free(&m);
    }
}

typedef struct project_oom_ctx {
    const tt_polycube *pc;
    const tt_mesh *mesh;
    tt_surface_point *pts;
} project_oom_ctx;

static tt_result project_oom_call(void *ctx, const tt_allocator *al, tt_error *error)
{
    project_oom_ctx *c = (project_oom_ctx *)ctx;
    tt_polycube_projection_report pr;
    tt_result r;
    pr.rays = -1;
    r = tt_polycube_project(c->pc, c->mesh, al, c->pts, &pr, error);
    if (error->result != r || (r != TT_OK && pr.rays != 0)) return TT_RESULT_MAX_ENUM;
    return r;
}

/* tt_polycube_build_auto: a mesh the default resolution fits stays there;
   a thin part or a handle the default misses raises it, and a control
   built at the default shows what the search saw (a mesh far from S, a
   genus that differs); an explicit resolution is tt_polycube_build. */
static void test_polycube_auto_resolution(void)
{
    const double centre[3] = {0.0, 0.0, 0.0};
    tmesh sphere, needle, ring;
    tt_mesh *mesh = NULL;
    tt_polycube *pc = NULL, *plain = NULL;
    tt_polycube_report rep, plain_rep;
    tt_polycube_resolution_report tried;
    tt_polycube_projection_report projection;
    tt_polycube_options o;
    tt_surface_point *points = NULL;
    tt_error err;
    int i;
    memset(&sphere, 0, sizeof sphere);
    memset(&needle, 0, sizeof needle);
    memset(&ring, 0, sizeof ring);
    memset(&o, 0, sizeof o);

    /* A sphere: the default resolution, one build. */
    make_sphere(&sphere, 32, 16, 1.0, centre, 0);
    CHECK(build(&sphere, 0, &mesh, &err) == TT_OK, "sphere builds");
    if (mesh && tt_polycube_build_auto(mesh, NULL, 0, NULL, &pc, &rep, &tried, &err) == TT_OK) {
        CHECK(tried.tries == 1 && rep.resolution == TT_POLYCUBE_DEFAULT_RESOLUTION && tried.chosen == 0,
              "a sphere keeps the default resolution (%d tries, resolution %d)", tried.tries, rep.resolution);
        CHECK(tried.mean_distance[0] >= 0.0 && tried.mean_distance[0] <= TT_POLYCUBE_AUTO_NEAR,
              "the sphere lies near S (%g cubes)", tried.mean_distance[0]);
    } else {
        CHECK(0, "auto build of a sphere: %s", err.message);
    }
    tt_polycube_free(pc);
    pc = NULL;
    tt_mesh_free(mesh);
    mesh = NULL;

    /* A needle (an ellipsoid 1.4 across, 16 long): at 16 it is about one cube thick. */
    make_sphere(&needle, 24, 64, 1.0, centre, 0);
    for (i = 0; i < needle.nv; i++) {
        needle.pos[3 * i] *= 0.7f;
        needle.pos[3 * i + 1] *= 0.7f;
        needle.pos[3 * i + 2] *= 8.0f;
    }
    CHECK(build(&needle, 0, &mesh, &err) == TT_OK, "needle builds");
    if (mesh && tt_polycube_build_auto(mesh, NULL, 0, NULL, &pc, &rep, &tried, &err) == TT_OK) {
        CHECK(rep.resolution > TT_POLYCUBE_DEFAULT_RESOLUTION && tried.tries >= 2,
              "a needle raises the resolution (%d after %d tries)", rep.resolution, tried.tries);
        CHECK(tried.mean_distance[tried.chosen] <= TT_POLYCUBE_AUTO_NEAR,
              "the needle lies near the chosen S (%g cubes)", tried.mean_distance[tried.chosen]);
        CHECK(tried.resolution[tried.chosen] == rep.resolution, "the report names the chosen resolution");
        /* The control: at the default the needle's vertices land far from it. */
        o.resolution = TT_POLYCUBE_DEFAULT_RESOLUTION;
        points = (tt_surface_point *)malloc(sizeof *points * (size_t)mesh->nverts);
        if (points && tt_polycube_build(mesh, &o, NULL, &plain, NULL, &err) == TT_OK &&
            tt_polycube_project(plain, mesh, NULL, points, &projection, &err) == TT_OK)
            CHECK(projection.mean_distance > TT_POLYCUBE_AUTO_NEAR,
                  "control: at the default the needle lies %g cubes from S", projection.mean_distance);
        else
            CHECK(0, "control build: %s", err.message);
        free(points);
        points = NULL;
        tt_polycube_free(plain);
        plain = NULL;
        /* max_resolution holds the search: the default only, with the report of that one try. */
        tt_polycube_free(pc);
        pc = NULL;
        CHECK(tt_polycube_build_auto(mesh, NULL, TT_POLYCUBE_DEFAULT_RESOLUTION, NULL, &pc, &rep, &tried, &err) ==
                      TT_OK &&
                  tried.tries == 1 && rep.resolution == TT_POLYCUBE_DEFAULT_RESOLUTION,
              "max_resolution stops the search (%d tries, resolution %d)", tried.tries, rep.resolution);
    } else {
        CHECK(0, "auto build of a needle: %s", err.message);
    }
    tt_polycube_free(pc);
    pc = NULL;

    /* An explicit resolution is that build, bit for bit. */
    o.resolution = 12;
    if (mesh && tt_polycube_build_auto(mesh, &o, 0, NULL, &pc, &rep, &tried, &err) == TT_OK &&
        tt_polycube_build(mesh, &o, NULL, &plain, &plain_rep, &err) == TT_OK) {
        CHECK(tried.tries == 1 && rep.resolution == plain_rep.resolution && pc->surface->nfaces == plain->surface->nfaces &&
                  memcmp(pc->occupied, plain->occupied, (size_t)pc->dims[0] * pc->dims[1] * pc->dims[2]) == 0,
              "an explicit resolution builds as tt_polycube_build");
    } else {
        CHECK(0, "explicit resolution: %s", err.message);
    }
    tt_polycube_free(pc);
    tt_polycube_free(plain);
    pc = plain = NULL;
    tt_mesh_free(mesh);
    mesh = NULL;

    /* A ring whose hole (0.4 across, 4.4 outside) closes at 16: the search goes on until S has the handle. */
    make_torus(&ring, 64, 32, 1.2, 1.0);
    CHECK(build(&ring, 0, &mesh, &err) == TT_OK, "ring builds");
    memset(&o, 0, sizeof o);
    o.resolution = TT_POLYCUBE_DEFAULT_RESOLUTION;
    if (mesh && tt_polycube_build(mesh, &o, NULL, &plain, &plain_rep, &err) == TT_OK)
        CHECK(plain_rep.mesh_genus == 1 && plain_rep.genus_differs,
              "control: at the default the ring's hole closes (genus %d)", plain_rep.polycube_genus);
    if (mesh && tt_polycube_build_auto(mesh, NULL, 0, NULL, &pc, &rep, &tried, &err) == TT_OK) {
        int first = 1;
        CHECK(!rep.genus_differs && rep.polycube_genus == 1 && rep.resolution > TT_POLYCUBE_DEFAULT_RESOLUTION &&
                  tried.genus[0] != 1 && tried.mean_distance[0] < 0.0,
              "the search keeps the ring's handle (genus %d at %d)", rep.polycube_genus, rep.resolution);
        /* the lowest resolution that passes, so the squares (and a brick
           photo's courses on them) are as large as the shape allows */
        for (i = 0; i < tried.chosen; i++)
            if (tried.genus[i] == 1 && tried.mean_distance[i] <= TT_POLYCUBE_AUTO_NEAR) first = 0;
        CHECK(first && tried.chosen == tried.tries - 1 && tried.resolution[tried.chosen] == rep.resolution,
              "the ring's resolution is the first that passes (%d, try %d of %d)", rep.resolution, tried.chosen + 1,
              tried.tries);
    }
    if (pc) printf("     auto resolution: a ring with a small hole gets genus 1 at %d (genus %d at 16)\n", rep.resolution,
                   plain_rep.polycube_genus);
    if (!pc)
        CHECK(0, "auto build of a ring: %s", err.message);
    tt_polycube_free(pc);
    tt_polycube_free(plain);
    tt_mesh_free(mesh);
    pc = plain = NULL;
    mesh = NULL;
    tm_free(&ring);

    /* The same ring with 40960 vertices: each try measures every second one, and
       that mean is the whole mesh's within 0.02 cubes. */
    memset(&ring, 0, sizeof ring);
    make_torus(&ring, 256, 160, 1.2, 1.0);
    CHECK(build(&ring, 0, &mesh, &err) == TT_OK && mesh && mesh->nverts > 2 * 16384, "dense ring builds");
    if (mesh && tt_polycube_build_auto(mesh, NULL, 0, NULL, &pc, &rep, &tried, &err) == TT_OK) {
        tt_surface_point *all = (tt_surface_point *)malloc(sizeof(tt_surface_point) * (size_t)mesh->nverts);
        tt_polycube_projection_report whole;
        memset(&whole, 0, sizeof whole);
        CHECK(all && tt_polycube_project(pc, mesh, NULL, all, &whole, &err) == TT_OK &&
                  !rep.genus_differs && tried.mean_distance[tried.chosen] <= TT_POLYCUBE_AUTO_NEAR &&
                  fabs(tried.mean_distance[tried.chosen] - whole.mean_distance) <= 0.02,
              "dense ring: resolution %d, the sample's mean distance %g against the whole mesh's %g",
              rep.resolution, tried.mean_distance[tried.chosen], whole.mean_distance);
        printf("     auto resolution: a ring of %d vertices at %d, mean distance %.4f cubes over every second vertex, "
               "%.4f over all\n", mesh->nverts, rep.resolution, tried.mean_distance[tried.chosen], whole.mean_distance);
        free(all);
    } else {
        CHECK(0, "auto build of a dense ring: %s", err.message);
    }
    tt_polycube_free(pc);
    tt_mesh_free(mesh);
    pc = NULL;
    mesh = NULL;
    tm_free(&ring);

    /* A hole 0.2 across (4.6 outside) closes up to 64: past it, only the genus goes on (72 here); with
       max_resolution 64 the search stops short, at the lowest of the closest genus. */
    memset(&ring, 0, sizeof ring);
    make_torus(&ring, 96, 48, 1.2, 1.1);
    CHECK(build(&ring, 0, &mesh, &err) == TT_OK, "narrow ring builds");
    if (mesh && tt_polycube_build_auto(mesh, NULL, 0, NULL, &pc, &rep, &tried, &err) == TT_OK) {
        int at64 = -1;
        for (i = 0; i < tried.tries; i++)
            if (tried.resolution[i] == 64) at64 = i;
        CHECK(!rep.genus_differs && rep.polycube_genus == 1 && rep.resolution > 64 && at64 >= 0 &&
                  tried.genus[at64] == 0,
              "past 64 for the genus: genus %d at %d (at 64: genus %d)", rep.polycube_genus, rep.resolution,
              at64 >= 0 ? tried.genus[at64] : -1);
    }
    tt_polycube_free(pc);
    pc = NULL;
    if (mesh && tt_polycube_build_auto(mesh, NULL, 64, NULL, &pc, &rep, &tried, &err) == TT_OK)
        CHECK(rep.genus_differs && rep.polycube_genus == 0 && tried.tries >= 5 &&
                  tried.resolution[tried.tries - 1] == 64 && rep.resolution == 16,
              "control: up to 64 the hole stays closed (genus %d at %d after %d tries)", rep.polycube_genus,
              rep.resolution, tried.tries);
    tt_polycube_free(pc);
    tt_mesh_free(mesh);
    tm_free(&sphere);
    tm_free(&needle);
    tm_free(&ring);
}

static void test_project_determinism_and_errors(void)
{
    const double center[3] = {0.31, 0.02, -0.17};
    tmesh m;
    tt_mesh *mesh, empty;
    tt_surface_point *pts, *again;
    tt_polycube_options o;
    tt_polycube_projection_report pr, pr2;
    tt_polycube_report rep;
    tt_polycube *pc, tampered;
    tt_allocator half;
    tt_error err;
    tt_result r;
    project_oom_ctx ctx;
    memset(&m, 0, sizeof m);
    make_sphere(&m, 32, 16, 1.0, center, 0);
    memset(&o, 0, sizeof o);
    o.resolution = 8;
    pc = projected(&m, &o, &mesh, &pts, &pr, &rep);
    if (!pc) { tm_free(&m); return; }
    again = (tt_surface_point *)malloc(sizeof(tt_surface_point) * (size_t)mesh->nverts);
    r = tt_polycube_project(pc, mesh, NULL, again, &pr2, NULL);
    CHECK(r == TT_OK && memcmp(pts, again, sizeof(tt_surface_point) * (size_t)mesh->nverts) == 0 &&
              memcmp(&pr, &pr2, sizeof pr) == 0,
          "same input, same points and report");

    CHECK(tt_polycube_project(NULL, mesh, NULL, again, NULL, &err) == TT_ERROR_INVALID_ARGUMENT &&
              tt_polycube_project(pc, NULL, NULL, again, NULL, &err) == TT_ERROR_INVALID_ARGUMENT &&
              tt_polycube_project(pc, mesh, NULL, NULL, NULL, &err) == TT_ERROR_INVALID_ARGUMENT,
          "NULL polycube, mesh or points: invalid");
    memset(&half, 0, sizeof half);
    half.free = free_only;
    CHECK(tt_polycube_project(pc, mesh, &half, again, NULL, &err) == TT_ERROR_INVALID_ARGUMENT,
          "an allocator with free only: invalid");
    memset(&empty, 0, sizeof empty);
    pr2.rays = 5;
    r = tt_polycube_project(pc, &empty, NULL, again, &pr2, &err);
    CHECK(r == TT_ERROR_EMPTY_MESH && pr2.rays == 0, "a mesh without faces: %d, report zeroed", r);
    tampered = *pc;
    tampered.surface = NULL;
    r = tt_polycube_project(&tampered, mesh, NULL, again, NULL, &err);
    CHECK(r == TT_ERROR_INVALID_ARGUMENT, "a polycube without a surface: %d", r);
    tampered = *pc;
    tampered.dims[0] -= 1;   /* the occupancy no longer matches the quads */
    r = tt_polycube_project(&tampered, mesh, NULL, again, NULL, &err);
    CHECK(r == TT_ERROR_INVALID_ARGUMENT, "a polycube whose cubes do not match its quads: %d (%s)", r, err.message);
    {
        float *pos = (float *)mesh->pos, keep = pos[3 * 7 + 1];
        pos[3 * 7 + 1] = internal_infinity();
        r = tt_polycube_project(pc, mesh, NULL, again, NULL, &err);
        CHECK(r == TT_ERROR_NON_FINITE && err.vertex == 7, "an infinite coordinate of vertex 7: %d at vertex %d", r,
              err.vertex);
        pos[3 * 7 + 1] = keep;
    }
    ctx.pc = pc;
    ctx.mesh = mesh;
    ctx.pts = again;
    oom_reset();
    oom_sweep("tt_polycube_project(sphere at resolution 8)", project_oom_call, &ctx, TT_OK);
    free(again);
    tt_polycube_free(pc);
    tt_mesh_free(mesh);
    free(pts);
    tm_free(&m);
}

/* ------------------------------------------------------------------------ */
/* The images of the mesh's edges on S (Chang and Lin Sec. 4)               */
/* ------------------------------------------------------------------------ */

/* The 3D point of a crossing: `along` on its S half-edge, between the
   half-edge's two corners (in double). */
static void crossing_position(const tt_polycube *pc, tt_edge_crossing x, double xyz[3])
{
    const tt_mesh *s = pc->surface;
    int quad = s->corner_face[x.halfedge], k = x.halfedge - s->face_start[quad], i, a;
    double end[2][3];
    for (i = 0; i < 2; i++) {
        int corner = (k + i) & 3;
        tt_surface_point p;
        p.quad = quad;
        p.s = (float)(corner == 1 || corner == 2);
        p.t = (float)(corner >= 2);
        tt_polycube_point_position(pc, p, end[i]);
    }
    for (a = 0; a < 3; a++) xyz[a] = end[0][a] + x.along * (end[1][a] - end[0][a]);
}

/* The axis an S half-edge runs along. */
static int halfedge_axis(const tt_polycube *pc, int h)
{
    const tt_mesh *s = pc->surface;
    int quad = s->corner_face[h], next = s->face_start[quad] + ((h - s->face_start[quad] + 1) & 3), a, best = 0;
    const float *p0 = s->pos + 3 * s->corner_vert[h], *p1 = s->pos + 3 * s->corner_vert[next];
    for (a = 1; a < 3; a++)
        if (fabs(p1[a] - p0[a]) > fabs(p1[best] - p0[best])) best = a;
    return best;
}

static tt_polycube_edges *traced(const tt_polycube *pc, const tt_mesh *mesh, const tt_surface_point *pts,
                                 int max_quads)
{
    tt_polycube_edges *edges = NULL;
    tt_polycube_edge_options eo;
    tt_error err;
    eo.max_quads = max_quads;
    if (tt_polycube_trace_edges(pc, mesh, pts, mesh->nverts, &eo, NULL, &edges, &err) != TT_OK)
        CHECK(0, "tt_polycube_trace_edges: %s", err.message);
    return edges;
}

/* For the edges: the cube mesh lies on S, so every edge's image is
   the edge itself. Edges are N or N sqrt 2 cubes long here, so the path
   limit is raised to 2N + 2 quads (a face diagonal passes N - 1 quad
   corners: 2N - 1 quads). */
static void test_edges_cube(void)
{
    unsigned char one = 1;
    int n;
    for (n = 1; n <= 8; n++) {
        tmesh m;
        tt_mesh *mesh;
        tt_surface_point *pts;
        tt_polycube_options o;
        tt_polycube_projection_report pr;
        tt_polycube_report rep;
        tt_polycube *pc;
        tt_polycube_edges *edges;
        int e, failed = 0, wrong_count = 0, off_edge = 0, wrong_line = 0, at_ends = 0, unsnapped = 0, along_fold = 0;
        double worst = 0.0;
        memset(&m, 0, sizeof m);
        make_cube_set(&m, &one, 1, 1, 1, 1.0, 1);
        memset(&o, 0, sizeof o);
        o.resolution = n;
        pc = projected(&m, &o, &mesh, &pts, &pr, &rep);
        edges = pc ? traced(pc, mesh, pts, 2 * n + 2) : NULL;
        if (!edges) {
            tt_polycube_free(pc);
            tt_mesh_free(mesh);
            free(pts);
            tm_free(&m);
            continue;
        }
        for (e = 0; e < edges->nedges; e++) {
            const float *pa = mesh->pos + 3 * edges->edge_vertices[2 * e];
            const float *pb = mesh->pos + 3 * edges->edge_vertices[2 * e + 1];
            int expected = 0, interior = 0, a, k, marks[3][9];
            memset(marks, 0, sizeof marks);
            for (a = 0; a < 3; a++) {
                int span = (int)floor(fabs(pb[a] - pa[a]) / pc->h + 0.5);
                if (span > 1) expected += span - 1;
            }
            if (edges->failed[e]) { failed++; continue; }
            for (k = edges->first_crossing[e]; k < edges->first_crossing[e + 1]; k++) {
                tt_edge_crossing x = edges->crossings[k];
                double at[3], on_edge[3], d = 0, g;
                int axis = halfedge_axis(pc, x.halfedge), line = -1;
                crossing_position(pc, x, at);
                for (a = 0; a < 3; a++) {
                    on_edge[a] = pa[a] + x.t * (pb[a] - pa[a]);
                    d += (at[a] - on_edge[a]) * (at[a] - on_edge[a]);
                }
                d = sqrt(d) / pc->h;
                if (d > worst) worst = d;
                off_edge += d > 1e-6;
                if (x.t == 0.0 || x.t == 1.0) { at_ends++; continue; }
                /* The lattice line crossed: across an axis the edge runs along and the S edge does not. */
                for (a = 0; a < 3; a++)
                    if (a != axis && fabs(pb[a] - pa[a]) > 0.5 * pc->h) line = a;
                if (line < 0) {
                    /* The S edge runs along the mesh edge (a fold of the cube): the path passes to the quad
                       across the fold where the segment enters that S edge, crossing no lattice line. */
                    along_fold++;
                    continue;
                }
                interior++;
                g = (at[line] - pc->origin[line]) / pc->h;
                if (fabs(g - floor(g + 0.5)) > 1e-6) { wrong_line++; continue; }
                g = fabs(at[line] - pa[line]) / pc->h;
                if (marks[line][(int)floor(g + 0.5)]++) wrong_line++;
                /* A crossing at a quad corner is snapped onto it exactly. */
                unsnapped += x.along != 0.0 && x.along != 1.0 && fabs(x.along - floor(x.along + 0.5)) < 1e-3;
            }
            wrong_count += interior != expected;
        }
        CHECK(failed == 0 && wrong_count == 0 && off_edge == 0 && wrong_line == 0 && unsnapped == 0,
              "cube at N = %d: %d edges, %d crossings, none failed (%d), inner crossings as many as the lattice "
              "lines crossed in 3D on every edge (%d edges wrong), each on a distinct line crossed (%d not), at "
              "the mesh edge's point of t within 1e-6 h (%d not, worst %.2g h), corners snapped (%d not); %d "
              "crossings at the edge's ends, %d onto the quad across a fold", n, edges->nedges, edges->ncrossings,
              failed, wrong_count, wrong_line, off_edge, worst, unsnapped, at_ends, along_fold);
        tt_polycube_edges_free(edges);
        tt_polycube_free(pc);
        tt_mesh_free(mesh);
        free(pts);
        tm_free(&m);
    }
}

/* Is the record of `edges` a connected path from quad(q_a) to quad(q_b),
   ordered by t, with t in proportion to the length walked on S? Each piece
   between two crossings lies in one flat quad, so its 3D length is its
   length on S: piece k must be (t_k+1 - t_k) times the path's length
   (1e-5 h for the snapping). Counts the offending edges. */
typedef struct edges_check {
    int disordered, disconnected, out_of_range, mismatched_halfedges, wrong_lengths;
} edges_check;

static double distance3(const double *p, const double *q)
{
    return sqrt((p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) + (p[2] - q[2]) * (p[2] - q[2]));
}

/* Whether point p lies in `quad`: its own, or any quad around the corner of
   S that p is on. */
static int point_in_quad(const tt_mesh *s, tt_surface_point p, int quad)
{
    int k, corner, vertex;
    if (quad == p.quad) return 1;
    if ((p.s != 0.0f && p.s != 1.0f) || (p.t != 0.0f && p.t != 1.0f)) return 0;
    corner = p.t == 0.0f ? (p.s == 0.0f ? 0 : 1) : (p.s == 0.0f ? 3 : 2);
    vertex = s->corner_vert[s->face_start[p.quad] + corner];
    for (k = 0; k < 4; k++)
        if (s->corner_vert[s->face_start[quad] + k] == vertex) return 1;
    return 0;
}

static edges_check check_edges(const tt_polycube *pc, const tt_mesh *mesh, const tt_surface_point *pts,
                               const tt_polycube_edges *edges)
{
    const tt_mesh *s = pc->surface;
    edges_check c;
    int e, h, failed = 0;
    memset(&c, 0, sizeof c);
    for (e = 0; e < edges->nedges; e++) {
        int quad = edges->end_quads[2 * e], k, bad_order = 0, bad_path = 0, bad_range = 0;
        failed += edges->failed[e];
        /* A path may leave (or reach) a point in another quad only where the point is a corner of S. */
        for (k = 0; k < 2; k++)
            bad_path |= !point_in_quad(s, pts[edges->edge_vertices[2 * e + k]], edges->end_quads[2 * e + k]);
        if (edges->failed[e]) {
            bad_path = edges->first_crossing[e] != edges->first_crossing[e + 1];
        } else {
            for (k = edges->first_crossing[e]; k < edges->first_crossing[e + 1]; k++) {
                tt_edge_crossing x = edges->crossings[k];
                bad_range |= !(x.t >= 0 && x.t <= 1 && x.along >= 0 && x.along <= 1);
                bad_order |= k > edges->first_crossing[e] && !(edges->crossings[k - 1].t <= x.t);
                bad_path |= x.halfedge < 0 || x.halfedge >= s->ncorners || s->corner_face[x.halfedge] != quad;
                if (!bad_path) quad = s->corner_face[s->twin[x.halfedge]];
            }
            bad_path |= quad != edges->end_quads[2 * e + 1];
            if (!bad_path && !bad_order) {
                int first = edges->first_crossing[e], last = edges->first_crossing[e + 1], n = last - first + 2, i;
                double *at = (double *)malloc(sizeof(double) * 3 * (size_t)n);
                double *t = (double *)malloc(sizeof(double) * (size_t)n);
                double walked = 0.0;
                tt_polycube_point_position(pc, pts[edges->edge_vertices[2 * e]], at);
                tt_polycube_point_position(pc, pts[edges->edge_vertices[2 * e + 1]], at + 3 * (n - 1));
                t[0] = 0.0;
                t[n - 1] = 1.0;
                for (i = 1; i + 1 < n; i++) {
                    crossing_position(pc, edges->crossings[first + i - 1], at + 3 * i);
                    t[i] = edges->crossings[first + i - 1].t;
                }
                for (i = 0; i + 1 < n; i++) walked += distance3(at + 3 * i, at + 3 * i + 3);
                for (i = 0; i + 1 < n; i++)
                    if (fabs(distance3(at + 3 * i, at + 3 * i + 3) - (t[i + 1] - t[i]) * walked) > 1e-5 * pc->h) break;
                c.wrong_lengths += i + 1 < n;
                free(at);
                free(t);
            }
        }
        c.disordered += bad_order;
        c.disconnected += bad_path;
        c.out_of_range += bad_range;
    }
    for (h = 0; h < mesh->ncorners; h++) {
        int f = mesh->corner_face[h], next = h + 1 < mesh->face_start[f + 1] ? h + 1 : mesh->face_start[f];
        int edge = edges->edge_of_halfedge[h], a = mesh->corner_vert[h], b = mesh->corner_vert[next];
        c.mismatched_halfedges += edge < 0 || edge >= edges->nedges ||
                                  (mesh->twin[h] >= 0 && edges->edge_of_halfedge[mesh->twin[h]] != edge) ||
                                  edges->edge_vertices[2 * edge] != (a < b ? a : b) ||
                                  edges->edge_vertices[2 * edge + 1] != (a < b ? b : a);
    }
    c.out_of_range += failed != edges->nfailed || edges->first_crossing[0] != 0 ||
                      edges->first_crossing[edges->nedges] != edges->ncrossings;
    return c;
}

static void test_edges_sphere(void)
{
    const double center[3] = {0.13, -0.07, 0.21};
    int k;
    for (k = 0; k < 2; k++) {
        int res = k ? 16 : 8;
        tmesh m;
        tt_mesh *mesh;
        tt_surface_point *pts;
        tt_polycube_options o;
        tt_polycube_projection_report pr;
        tt_polycube_report rep;
        tt_polycube *pc;
        tt_polycube_edges *edges;
        edges_check c;
        memset(&m, 0, sizeof m);
        make_sphere(&m, 48, 24, 1.0, center, 0);
        memset(&o, 0, sizeof o);
        o.resolution = res;
        pc = projected(&m, &o, &mesh, &pts, &pr, &rep);
        edges = pc ? traced(pc, mesh, pts, 0) : NULL;
        if (edges) {
            c = check_edges(pc, mesh, pts, edges);
            CHECK(edges->nedges == mesh->ncorners / 2 && c.mismatched_halfedges == 0,
                  "sphere at resolution %d: %d edges for %d half-edges, both half-edges of each on its record "
                  "(%d not)", res, edges->nedges, mesh->ncorners, c.mismatched_halfedges);
            CHECK(c.disordered == 0 && c.disconnected == 0 && c.out_of_range == 0 && c.wrong_lengths == 0,
                  "sphere at resolution %d: %d crossings, ordered by t on every edge (%d not), each a connected "
                  "path from q_a's quad to q_b's (%d not), t and along in [0, 1] (%d not), t in proportion to "
                  "the length on S (%d not)", res, edges->ncrossings, c.disordered, c.disconnected, c.out_of_range,
                  c.wrong_lengths);
            /* At 16 the equator's edges are 1.5 h long; where they cross a staircase some need 5 quads. */
            CHECK(res == 8 ? edges->nfailed == 0 : edges->nfailed * 100 <= edges->nedges,
                  "sphere at resolution %d: %d of %d edges without a path of at most 4 quads (at most %s)", res,
                  edges->nfailed, edges->nedges, res == 8 ? "none" : "1 %");
            if (res == 16) {
                tt_polycube_edges *longer = traced(pc, mesh, pts, 6);
                edges_check lc;
                memset(&lc, 0, sizeof lc);
                if (longer) lc = check_edges(pc, mesh, pts, longer);
                CHECK(longer && longer->nfailed == 0 && lc.disconnected == 0 && lc.disordered == 0 &&
                          lc.wrong_lengths == 0,
                      "sphere at resolution 16 with paths of up to 6 quads: every edge traced (%d failed)",
                      longer ? longer->nfailed : -1);
                tt_polycube_edges_free(longer);
            }
        }
        tt_polycube_edges_free(edges);
        tt_polycube_free(pc);
        tt_mesh_free(mesh);
        free(pts);
        tm_free(&m);
    }
}

/* Unfolding across an edge and back is the identity; the shared edge's
   corners land on each other (the map is fixed by the half-edges alone). */
static void test_unfold(void)
{
    unsigned char set[8] = {1, 1, 1, 0, 1, 0, 0, 0};   /* an L of cubes: convex and concave folds, corners */
    tmesh m;
    tt_mesh *mesh = NULL;
    tt_polycube *pc = NULL;
    tt_polycube_options o;
    tt_error err;
    int h, not_identity = 0, corners_apart = 0, turns_seen = 0;
    memset(&m, 0, sizeof m);
    make_cube_set(&m, set, 2, 2, 2, 1.0, 1);
    memset(&o, 0, sizeof o);
    o.resolution = 2;
    if (build(&m, 0, &mesh, &err) != TT_OK || tt_polycube_build(mesh, &o, NULL, &pc, NULL, &err) != TT_OK) {
        CHECK(0, "L-shape polycube: %s", err.message);
        tt_mesh_free(mesh);
        tm_free(&m);
        return;
    }
    for (h = 0; h < pc->surface->ncorners; h++) {
        const tt_mesh *s = pc->surface;
        int twin = s->twin[h], i = h - s->face_start[s->corner_face[h]], j = twin - s->face_start[s->corner_face[twin]];
        tt_quad_map there = tt_polycube_unfold(pc, h), back = tt_polycube_unfold(pc, twin);
        tt_quad_map round = tt_quad_map_compose(there, back);
        double p[2], q[2], c0[2], c1[2];
        not_identity += round.turns != 0 || round.offset[0] != 0 || round.offset[1] != 0;
        tt_quad_map_apply(there, (j & 3) == 1 || (j & 3) == 2, (j & 3) >= 2, p);
        tt_quad_map_apply(there, ((j + 1) & 3) == 1 || ((j + 1) & 3) == 2, ((j + 1) & 3) >= 2, q);
        c0[0] = ((i + 1) & 3) == 1 || ((i + 1) & 3) == 2;
        c0[1] = ((i + 1) & 3) >= 2;
        c1[0] = (i & 3) == 1 || (i & 3) == 2;
        c1[1] = (i & 3) >= 2;
        corners_apart += p[0] != c0[0] || p[1] != c0[1] || q[0] != c1[0] || q[1] != c1[1];
        turns_seen |= 1 << there.turns;
        {
            /* The far quad's centre lands on the other side of the shared edge, one unit away. */
            double centre[2], dx, dy;
            tt_quad_map_apply(there, 0.5, 0.5, centre);
            dx = centre[0] - 0.5;
            dy = centre[1] - 0.5;
            corners_apart += !(fabs(dx) + fabs(dy) == 1.0);
        }
    }
    CHECK(not_identity == 0 && corners_apart == 0,
          "L-shape at resolution 2, %d half-edges: across and back is the identity (%d not), the shared edge's "
          "corners meet and the far quad lies beside (%d not)", pc->surface->ncorners, not_identity, corners_apart);
    CHECK(turns_seen == 15, "every quarter turn occurs among the maps (mask %d)", turns_seen);
    tt_polycube_free(pc);
    tt_mesh_free(mesh);
    tm_free(&m);
}

typedef struct edges_oom_ctx {
    const tt_polycube *pc;
    const tt_mesh *mesh;
    const tt_surface_point *pts;
} edges_oom_ctx;

static tt_result edges_oom_call(void *ctx, const tt_allocator *al, tt_error *error)
{
    edges_oom_ctx *c = (edges_oom_ctx *)ctx;
    tt_polycube_edges *edges = (tt_polycube_edges *)&edges;
    tt_result r = tt_polycube_trace_edges(c->pc, c->mesh, c->pts, c->mesh->nverts, NULL, al, &edges, error);
    if (error->result != r || (r != TT_OK) != (edges == NULL)) return TT_RESULT_MAX_ENUM;
    tt_polycube_edges_free(edges);
    return r;
}

/* A point on a corner of S lies in every quad around it: an edge from a
   saddle corner (5 quads) to the middle of a quad there that shares no
   edge with the point's own quad starts in that quad, with no crossing
   (end_quads says which); from a point just off the corner, inside its
   own quad, the same edge must pass through the corner. */
static void test_edges_from_corner(void)
{
    const unsigned char L[6] = {1, 1, 1, 1, 1, 0};
    tmesh m, tri;
    tt_mesh *mesh = NULL, *one = NULL;
    tt_surface_point *pts = NULL, p[3];
    tt_polycube_options o;
    tt_polycube_projection_report pr;
    tt_polycube_report rep;
    tt_polycube *pc;
    tt_error err;
    int h = -1, c, k, valence = 0, quads[8], far = -1, trials;
    memset(&m, 0, sizeof m);
    memset(&tri, 0, sizeof tri);
    make_cube_set(&m, L, 3, 2, 1, 1.0, 1);
    memset(&o, 0, sizeof o);
    o.resolution = 3;
    pc = projected(&m, &o, &mesh, &pts, &pr, &rep);
    if (!pc) { tm_free(&m); return; }
    /* A half-edge leaving a vertex of S with 5 quads around it, and those quads in turn. */
    for (c = 0; c < pc->surface->ncorners && h < 0; c++) {
        int around = c, n = 0;
        do {
            int quad = pc->surface->corner_face[around];
            if (n < 8) quads[n] = quad;
            n++;
            around = pc->surface->twin[pc->surface->face_start[quad] + ((around - pc->surface->face_start[quad] + 3) & 3)];
        } while (around != c && n < 9);
        if (n == 5) { h = c; valence = n; }
    }
    CHECK(h >= 0, "the L-shape's polycube has a vertex with 5 quads around it");
    if (h >= 0) {
        const tt_mesh *s = pc->surface;
        int corner = h - s->face_start[quads[0]];
        far = quads[2];   /* two steps around: no edge shared with quads[0] */
        for (trials = 0; trials < 2; trials++) {
            double xyz[3];
            tt_polycube_edges *edges;
            p[0].quad = quads[0];
            p[0].s = (float)(corner == 1 || corner == 2);
            p[0].t = (float)(corner >= 2);
            if (trials == 1) {  /* a hair inside the quad */
                p[0].s = p[0].s == 0.0f ? 0.01f : 0.99f;
                p[0].t = p[0].t == 0.0f ? 0.01f : 0.99f;
            }
            p[1].quad = far;
            p[1].s = p[1].t = 0.5f;
            p[2].quad = quads[0];
            p[2].s = p[2].t = 0.5f;
            tm_free(&tri);
            memset(&tri, 0, sizeof tri);
            for (k = 0; k < 3; k++) {
                tt_polycube_point_position(pc, p[k], xyz);
                tm_vert(&tri, xyz[0] + 0.01 * k, xyz[1] - 0.02 * k, xyz[2] + 0.03 * k);
            }
            tm_tri(&tri, 0, 1, 2);
            tt_mesh_free(one);
            one = NULL;
            if (build(&tri, 0, &one, &err) != TT_OK) {
                CHECK(0, "one triangle builds: %s", err.message);
                break;
            }
            edges = traced(pc, one, p, 4);
            if (!edges) break;
            for (k = 0; k < edges->nedges; k++) {
                int a = edges->edge_vertices[2 * k], b = edges->edge_vertices[2 * k + 1], n;
                if (a != 0 || b != 1) continue;
                n = edges->first_crossing[k + 1] - edges->first_crossing[k];
                if (trials == 0)
                    CHECK(!edges->failed[k] && n == 0 && edges->end_quads[2 * k] == far && edges->end_quads[2 * k + 1] == far,
                          "an edge from a corner of S with %d quads into the middle of a quad there that shares no "
                          "edge with the point's own: traced (%s) with no crossing (%d) from that quad (%d, want %d)",
                          valence, edges->failed[k] ? "no" : "yes", n, edges->end_quads[2 * k], far);
                else
                    CHECK(!edges->failed[k] && n >= 2 && edges->end_quads[2 * k] == quads[0] &&
                              edges->crossings[edges->first_crossing[k]].t > 0.0,
                          "the same edge from a point just inside the quad: traced (%s) through the corner (%d "
                          "crossings, want 2 or more) from the point's own quad (%d, want %d)",
                          edges->failed[k] ? "no" : "yes", n, edges->end_quads[2 * k], quads[0]);
            }
            tt_polycube_edges_free(edges);
        }
    }
    tt_mesh_free(one);
    tt_polycube_free(pc);
    tt_mesh_free(mesh);
    free(pts);
    tm_free(&tri);
    tm_free(&m);
}

static void test_edges_determinism_and_errors(void)
{
    const double center[3] = {0.31, 0.02, -0.17};
    tmesh m;
    tt_mesh *mesh, empty;
    tt_surface_point *pts;
    tt_polycube_options o;
    tt_polycube_projection_report pr;
    tt_polycube_report rep;
    tt_polycube *pc;
    tt_polycube_edges *edges, *again = NULL, *none = (tt_polycube_edges *)&none;
    tt_polycube_edge_options eo;
    tt_allocator half;
    tt_error err;
    tt_result r;
    edges_oom_ctx ctx;
    int same;
    memset(&m, 0, sizeof m);
    make_sphere(&m, 32, 16, 1.0, center, 0);
    memset(&o, 0, sizeof o);
    o.resolution = 8;
    pc = projected(&m, &o, &mesh, &pts, &pr, &rep);
    edges = pc ? traced(pc, mesh, pts, 0) : NULL;
    if (!edges) {
        tt_polycube_free(pc);
        tt_mesh_free(mesh);
        free(pts);
        tm_free(&m);
        return;
    }
    r = tt_polycube_trace_edges(pc, mesh, pts, mesh->nverts, NULL, NULL, &again, NULL);
    same = r == TT_OK && again->nedges == edges->nedges && again->ncrossings == edges->ncrossings &&
           again->nfailed == edges->nfailed &&
           memcmp(again->first_crossing, edges->first_crossing, sizeof(int) * (size_t)(edges->nedges + 1)) == 0 &&
           memcmp(again->failed, edges->failed, (size_t)edges->nedges) == 0 &&
           memcmp(again->edge_vertices, edges->edge_vertices, sizeof(int) * 2 * (size_t)edges->nedges) == 0;
    if (same) {
        int k;
        for (k = 0; k < edges->ncrossings; k++)
            same &= again->crossings[k].halfedge == edges->crossings[k].halfedge &&
                    memcmp(&again->crossings[k].along, &edges->crossings[k].along, sizeof(double)) == 0 &&
                    memcmp(&again->crossings[k].t, &edges->crossings[k].t, sizeof(double)) == 0;
    }
    CHECK(same, "same input (options NULL = max_quads 0), bitwise the same record");
    tt_polycube_edges_free(again);

    CHECK(tt_polycube_trace_edges(NULL, mesh, pts, mesh->nverts, NULL, NULL, &none, &err) == TT_ERROR_INVALID_ARGUMENT &&
              none == NULL &&
              tt_polycube_trace_edges(pc, NULL, pts, mesh->nverts, NULL, NULL, &none, &err) == TT_ERROR_INVALID_ARGUMENT &&
              tt_polycube_trace_edges(pc, mesh, NULL, mesh->nverts, NULL, NULL, &none, &err) == TT_ERROR_INVALID_ARGUMENT &&
              tt_polycube_trace_edges(pc, mesh, pts, mesh->nverts, NULL, NULL, NULL, &err) == TT_ERROR_INVALID_ARGUMENT,
          "NULL polycube, mesh, points or out: invalid, *out NULL");
    none = (tt_polycube_edges *)&none;
    r = tt_polycube_trace_edges(pc, mesh, pts, mesh->nverts - 1, NULL, NULL, &none, &err);
    CHECK(r == TT_ERROR_INVALID_ARGUMENT && none == NULL && msg_has_number(err.message, mesh->nverts - 1),
          "one point too few: %d (%s)", r, err.message);
    memset(&half, 0, sizeof half);
    half.free = free_only;
    CHECK(tt_polycube_trace_edges(pc, mesh, pts, mesh->nverts, NULL, &half, &none, &err) == TT_ERROR_INVALID_ARGUMENT,
          "an allocator with free only: invalid");
    eo.max_quads = TT_POLYCUBE_EDGE_MAX_QUADS + 1;
    r = tt_polycube_trace_edges(pc, mesh, pts, mesh->nverts, &eo, NULL, &none, &err);
    eo.max_quads = -1;
    CHECK(r == TT_ERROR_INVALID_ARGUMENT &&
              tt_polycube_trace_edges(pc, mesh, pts, mesh->nverts, &eo, NULL, &none, &err) == TT_ERROR_INVALID_ARGUMENT,
          "max_quads above TT_POLYCUBE_EDGE_MAX_QUADS or below 0: invalid");
    memset(&empty, 0, sizeof empty);
    CHECK(tt_polycube_trace_edges(pc, &empty, pts, 0, NULL, NULL, &none, &err) == TT_ERROR_EMPTY_MESH,
          "a mesh without faces: empty");
    {
        tt_surface_point keep = pts[5];
        int bad = 0, variant;
        for (variant = 0; variant < 4; variant++) {
            pts[5] = keep;
            if (variant == 0) pts[5].quad = -1;
            if (variant == 1) pts[5].quad = pc->surface->nfaces;
            if (variant == 2) pts[5].s = 1.5f;
            if (variant == 3) pts[5].t = (float)internal_not_a_number();
            r = tt_polycube_trace_edges(pc, mesh, pts, mesh->nverts, NULL, NULL, &none, &err);
            bad += !(r == TT_ERROR_INVALID_ARGUMENT && err.vertex == 5 && none == NULL);
        }
        pts[5] = keep;
        CHECK(bad == 0, "a point with a quad outside S (-1, nfaces) or s, t outside [0, 1] (1.5, NaN): invalid at "
                        "its vertex (%d cases not)", bad);
    }
    {
        tt_polycube tampered = *pc;
        tampered.dims[0] -= 1;
        CHECK(tt_polycube_trace_edges(&tampered, mesh, pts, mesh->nverts, NULL, NULL, &none, &err) ==
                  TT_ERROR_INVALID_ARGUMENT,
              "a polycube whose cubes do not match its quads: invalid");
    }
    ctx.pc = pc;
    ctx.mesh = mesh;
    ctx.pts = pts;
    oom_reset();
    oom_sweep("tt_polycube_trace_edges(sphere at resolution 8)", edges_oom_call, &ctx, TT_OK);
    tt_polycube_edges_free(edges);
    tt_polycube_free(pc);
    tt_mesh_free(mesh);
    free(pts);
    tm_free(&m);
}

/* ------------------------------------------------------------------------ */
/* The model split on S and its UVs (Chang and Lin Sec. 4)                  */
/* ------------------------------------------------------------------------ */

/* What a mapping must be, whatever the mesh (the header's contract of
   tt_polycube_map): output vertices are the weighted input vertices they
   name (on the model's triangles), input vertex v stays output vertex v,
   the areas add up to the input's, corner points lie in [0, 1]^2 of a
   quad of S, and the output is a closed manifold (strict build) when the
   input is: no crack, no T-junction. */
typedef struct mapping_check {
    int off_surface, moved_inputs, bad_points, bad_faces;
    double area_error;      /* relative */
    int strict_fails, open_edges;
} mapping_check;

/* Whether a mapping's check found it sound: every output vertex on the
   model, every corner's point in its triangle's quad, the area kept, a
   closed strict mesh. */
static int mapping_sound(const mapping_check *c)
{
    return !(c->off_surface || c->bad_points || c->bad_faces || c->area_error > 1e-6 || c->strict_fails ||
             c->open_edges);
}

static double triangle_area3(const float *a, const float *b, const float *c)
{
    double u[3], v[3], n[3];
    int k;
    for (k = 0; k < 3; k++) {
        u[k] = (double)b[k] - a[k];
        v[k] = (double)c[k] - a[k];
    }
    n[0] = u[1] * v[2] - u[2] * v[1];
    n[1] = u[2] * v[0] - u[0] * v[2];
    n[2] = u[0] * v[1] - u[1] * v[0];
    return 0.5 * sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
}

/* A mapping's triangles as a tt_mesh built with `flags` (0: strict, as
   the seam measure and the soundness check want it); NULL when they make
   none. */
static tt_mesh *mapping_mesh(const tt_polycube_mapping *map, unsigned flags)
{
    tt_mesh_desc d;
    tt_mesh *out = NULL;
    memset(&d, 0, sizeof d);
    d.positions = map->positions;
    d.nverts = map->nverts;
    d.indices = map->triangles;
    d.nfaces = map->ntriangles;
    d.fixed_face_size = 3;
    d.flags = flags;
    if (tt_mesh_build(&d, NULL, &out, NULL) != TT_OK) return NULL;
    return out;
}

static mapping_check check_mapping(const tt_polycube *pc, const tt_mesh *mesh, const tt_polycube_mapping *m)
{
    mapping_check c;
    double in = 0.0, out = 0.0, scale = 0.0;
    int v, f, k, a;
    tt_mesh *built = NULL;
    memset(&c, 0, sizeof c);
    for (v = 0; v < 3 * mesh->nverts; v++) scale = fmax(scale, fabs(mesh->pos[v]));
    for (v = 0; v < m->nverts; v++) {
        double p[3] = {0, 0, 0}, sum = 0, d2 = 0;
        for (k = 0; k < 3; k++) {
            int src = m->source[3 * v + k];
            if (src < 0 || src >= mesh->nverts) { c.off_surface++; break; }
            sum += m->weights[3 * v + k];
            for (a = 0; a < 3; a++) p[a] += m->weights[3 * v + k] * mesh->pos[3 * src + a];
        }
        for (a = 0; a < 3; a++) d2 += (p[a] - m->positions[3 * v + a]) * (p[a] - m->positions[3 * v + a]);
        c.off_surface += fabs(sum - 1.0) > 1e-5 || sqrt(d2) > 1e-5 * scale;
        if (v < mesh->nverts)
            c.moved_inputs += memcmp(m->positions + 3 * v, mesh->pos + 3 * v, 3 * sizeof(float)) != 0;
    }
    for (f = 0; f < mesh->nfaces; f++)
        in += triangle_area3(mesh->pos + 3 * mesh->corner_vert[3 * f], mesh->pos + 3 * mesh->corner_vert[3 * f + 1],
                             mesh->pos + 3 * mesh->corner_vert[3 * f + 2]);
    for (f = 0; f < m->ntriangles; f++) {
        const int *t = m->triangles + 3 * f;
        out += triangle_area3(m->positions + 3 * t[0], m->positions + 3 * t[1], m->positions + 3 * t[2]);
        c.bad_faces += m->triangle_face[f] < 0 || m->triangle_face[f] >= mesh->nfaces;
        for (k = 0; k < 3; k++) {
            tt_surface_point p = m->corner_points[3 * f + k];
            c.bad_points += p.quad != m->corner_points[3 * f].quad || p.quad < 0 || p.quad >= pc->surface->nfaces ||
                            !(p.s >= 0.0f && p.s <= 1.0f && p.t >= 0.0f && p.t <= 1.0f);
        }
    }
    c.area_error = fabs(out - in) / in;
    if (!(built = mapping_mesh(m, 0))) {
        c.strict_fails = 1;
    } else {
        for (k = 0; k < built->ncorners; k++) c.open_edges += built->twin[k] < 0;
        tt_mesh_free(built);
    }
    return c;
}

/* A progress callback that records the fractions and cancels at call
   number cancel_at (0-based; -1: never). */
typedef struct progress_log {
    int calls, cancel_at, decreasing;
    int within_smoothing;   /* fractions strictly between the projection's end (0.2) and the tracing's start (0.45) */
    float last;
} progress_log;

static int log_progress(float fraction, void *user_data)
{
    progress_log *log = (progress_log *)user_data;
    if (fraction < log->last || !(fraction >= 0.0f && fraction <= 1.0f)) log->decreasing++;
    log->within_smoothing += fraction > 0.2f && fraction < 0.45f;
    log->last = fraction;
    return log->calls++ == log->cancel_at;
}

static tt_polycube_mapping *mapped(const tmesh *m, int resolution, int max_quads, double max_edge,
                                   tt_polycube **pc_out, tt_mesh **mesh_out, tt_polycube_map_report *report)
{
    tt_polycube_map_options mo;
    tt_polycube_options o;
    tt_polycube_report rep;
    tt_polycube_mapping *mapping = NULL;
    tt_error err;
    *pc_out = NULL;
    *mesh_out = NULL;
    if (build(m, 0, mesh_out, &err) != TT_OK) {
        CHECK(0, "test mesh builds: %s", err.message);
        return NULL;
    }
    memset(&o, 0, sizeof o);
    o.resolution = resolution;
    if (tt_polycube_build(*mesh_out, &o, NULL, pc_out, &rep, &err) != TT_OK) {
        CHECK(0, "tt_polycube_build: %s", err.message);
        return NULL;
    }
    memset(&mo, 0, sizeof mo);
    mo.max_quads = max_quads;
    mo.max_edge = max_edge;
    CHECK(tt_polycube_map(*pc_out, *mesh_out, &mo, NULL, &mapping, report, &err) == TT_OK, "tt_polycube_map: %s",
          err.message);
    return mapping;
}

/* The largest relative difference between a triangle's 3D edge lengths and
   its lengths on S (times h): 0 for an isometry, i.e. stretch 1. */
static double isometry_error(const tt_polycube *pc, const tt_polycube_mapping *m, int f)
{
    double worst = 0.0;
    int k;
    for (k = 0; k < 3; k++) {
        const float *p = m->positions + 3 * m->triangles[3 * f + k];
        const float *q = m->positions + 3 * m->triangles[3 * f + (k + 1) % 3];
        tt_surface_point a = m->corner_points[3 * f + k], b = m->corner_points[3 * f + (k + 1) % 3];
        double d3 = sqrt(((double)q[0] - p[0]) * ((double)q[0] - p[0]) + ((double)q[1] - p[1]) * ((double)q[1] - p[1]) +
                         ((double)q[2] - p[2]) * ((double)q[2] - p[2]));
        double d2 = pc->h * sqrt(((double)b.s - a.s) * ((double)b.s - a.s) + ((double)b.t - a.t) * ((double)b.t - a.t));
        worst = fmax(worst, fabs(d3 - d2) / pc->h);
    }
    return worst;
}

/* The 12-triangle cube on the lattice at N = 1..8 maps onto the N^3
   block isometrically: every triangle is cut exactly at the lattice lines
   into N^2 pieces (N (N - 1) / 2 squares of 2 triangles and N halves on
   the diagonal), 2 N^2 per cube face, stretch 1, nothing flipped or left
   to the fallback. */
static void test_map_cube(void)
{
    unsigned char one = 1;
    int n;
    for (n = 1; n <= 8; n++) {
        tmesh m;
        tt_mesh *mesh;
        tt_polycube *pc;
        tt_polycube_map_report rep;
        tt_polycube_mapping *map;
        mapping_check c;
        double worst = 0.0;
        int f;
        memset(&m, 0, sizeof m);
        make_cube_set(&m, &one, 1, 1, 1, 1.0, 1);
        map = mapped(&m, n, 2 * n + 2, HUGE_VAL, &pc, &mesh, &rep);
        if (map) {
            c = check_mapping(pc, mesh, map);
            for (f = 0; f < map->ntriangles; f++) worst = fmax(worst, isometry_error(pc, map, f));
            CHECK(map->ntriangles == 12 * n * n && rep.split_triangles == (n > 1 ? 12 : 0) &&
                      rep.fallback_triangles == 0 && rep.flipped == 0 && rep.collapsed == 0 && worst <= 1e-6 &&
                      c.off_surface == 0 &&
                      c.moved_inputs == 0 && c.bad_points == 0 && c.bad_faces == 0 && c.area_error <= 1e-6 &&
                      !c.strict_fails && c.open_edges == 0,
                  "cube at N = %d: %d output triangles (12 N^2 = %d), %d split, %d fallbacks, %d flipped, lengths "
                  "kept within %.2g h (stretch 1), %d vertices off the model, %d inputs moved, %d corner points "
                  "off one quad, area error %.2g, strict build %s with %d open edges",
                  n, map->ntriangles, 12 * n * n, rep.split_triangles, rep.fallback_triangles, rep.flipped, worst,
                  c.off_surface, c.moved_inputs, c.bad_points, c.area_error, c.strict_fails ? "fails" : "holds",
                  c.open_edges);
        }
        tt_polycube_mapping_free(map);
        tt_polycube_free(pc);
        tt_mesh_free(mesh);
        tm_free(&m);
    }
}

/* The invariants on curved and open meshes (in part):
   a sphere at resolutions 4 to 32 and a hemisphere (open), each watertight
   after the split (the strict builder accepts the sphere's output closed:
   the two triangles on an edge split it at the same vertices), area
   kept, every vertex on the model, at most 0.1 % of the (refined)
   triangles left to the fallback, none flipped on the sphere (a few at the
   hemisphere's open rim, where the sheet's edge meets the slab: at most
   0.2 %). */
static void test_map_sphere(void)
{
    const double centre[3] = {0.13, -0.21, 0.05};
    int resolution, hemisphere;
    for (hemisphere = 0; hemisphere < 2; hemisphere++)
        for (resolution = 4; resolution <= 32; resolution *= 2) {
            tmesh m;
            tt_mesh *mesh;
            tt_polycube *pc;
            tt_polycube_map_report rep;
            tt_polycube_mapping *map;
            memset(&m, 0, sizeof m);
            make_sphere(&m, 48, 24, 1.0, centre, hemisphere);
            map = mapped(&m, resolution, 0, 0.0, &pc, &mesh, &rep);
            if (map) {
                mapping_check c = check_mapping(pc, mesh, map);
                printf("     %s at resolution %d: %d triangles (%d refined) -> %d, %d split, %d fallbacks, %d "
                       "flipped\n", hemisphere ? "hemisphere" : "sphere", resolution, mesh->nfaces, rep.triangles,
                       map->ntriangles, rep.split_triangles, rep.fallback_triangles, rep.flipped);
                CHECK(c.off_surface == 0 && c.moved_inputs == 0 && c.bad_points == 0 && c.bad_faces == 0 &&
                          c.area_error <= 1e-6 && !c.strict_fails && (hemisphere || c.open_edges == 0) &&
                          rep.split_triangles > 0 && rep.fallback_triangles <= rep.triangles / 1000 &&
                          rep.flipped == 0,
                      "%s at resolution %d: %d vertices off the model, %d inputs moved, %d corner points off one "
                      "quad, area error %.2g, strict build %s, %d open edges, %d split, %d fallbacks (at most "
                      "0.1 %% of %d), %d flipped",
                      hemisphere ? "hemisphere" : "sphere", resolution, c.off_surface, c.moved_inputs,
                      c.bad_points, c.area_error, c.strict_fails ? "fails" : "holds", c.open_edges,
                      rep.split_triangles, rep.fallback_triangles, rep.triangles, rep.flipped);
            }
            tt_polycube_mapping_free(map);
            tt_polycube_free(pc);
            tt_mesh_free(mesh);
            tm_free(&m);
        }
}

/* Output triangles drawn out into streaks: those whose area on S (in cube
   faces) is below a thousandth of their area on the model (in cube faces
   too), measured here from the corner points and positions alone. */
static int count_streaks(const tt_polycube *pc, const tt_polycube_mapping *m)
{
    int j, streaks = 0;
    for (j = 0; j < m->ntriangles; j++) {
        const tt_surface_point *p = m->corner_points + 3 * j;
        const int *v = m->triangles + 3 * j;
        double on_s = 0.5 * ((p[1].s - p[0].s) * (p[2].t - p[0].t) - (p[1].t - p[0].t) * (p[2].s - p[0].s));
        double on_model = triangle_area3(m->positions + 3 * v[0], m->positions + 3 * v[1], m->positions + 3 * v[2]) /
                          (pc->h * pc->h);
        streaks += on_model > 1e-9 && on_s < 1e-3 * on_model;
    }
    return streaks;
}

/* A triangle with a vertex on a saddle of S whose corner there spans more
   than half a turn has no straight image: the path across from that vertex
   runs through the saddle too, and the triangle collapses onto two
   segments. The mapping splits that edge (unpinched); a piece that still
   has no area on S falls back (a local seam, not a streak). On
   triangulated tori (whose polycubes have saddles around the hole) at
   several resolutions: pinches occur, the output stays closed, area-true
   and one quad per triangle, no output triangle is a streak (the measure's
   control: a corner moved onto the line of the other two counts one), and
   the fallbacks stay under 0.5 % of the triangles. */
static void test_map_unpinch(void)
{
    int round, unpinched = 0, streaks = 0, fallbacks = 0, triangles = 0, bad = 0, control = -1;
    for (round = 0; round < 3; round++) {
        const double pi = 3.14159265358979323846, R = 1.0, r = 0.3 + 0.05 * round;
        const int nu = 64, nv = 24;
        tmesh m;
        tt_mesh *mesh;
        tt_polycube *pc;
        tt_polycube_map_report rep;
        tt_polycube_mapping *map;
        int i, j;
        memset(&m, 0, sizeof m);
        for (j = 0; j < nv; j++)
            for (i = 0; i < nu; i++) {
                double a = 2 * pi * (i + 0.5 * j) / nu, b = 2 * pi * j / nv;
                tm_vert(&m, (R + r * cos(b)) * cos(a), (R + r * cos(b)) * sin(a), r * sin(b) + 0.1 * sin(3 * a));
            }
        for (j = 0; j < nv; j++)
            for (i = 0; i < nu; i++) {
                /* Row nv is row 0 turned by half nv columns (the rows are sheared). */
                int i1 = (i + 1) % nu, j1 = (j + 1) % nv, wrap = j1 == 0 ? nv / 2 : 0;
                int a = j * nu + i, b = j * nu + i1, c = j1 * nu + (i1 + wrap) % nu, d = j1 * nu + (i + wrap) % nu;
                tm_tri(&m, a, b, c);
                tm_tri(&m, a, c, d);
            }
        map = mapped(&m, 16 + 8 * round, 0, 0.0, &pc, &mesh, &rep);
        if (map) {
            mapping_check c = check_mapping(pc, mesh, map);
            if (!mapping_sound(&c)) bad++;
            printf("     torus r %.2f at %d: %d unpinched, %d collapsed, %d fallbacks of %d\n", r, 16 + 8 * round,
                   rep.unpinched, rep.collapsed, rep.fallback_triangles, rep.triangles);
            unpinched += rep.unpinched;
            streaks += count_streaks(pc, map) + rep.collapsed;
            fallbacks += rep.fallback_triangles;
            triangles += rep.triangles;
            if (round == 0 && map->ntriangles > 0) {
                tt_surface_point *p = map->corner_points;
                p[2].s = 0.5f * (p[0].s + p[1].s);
                p[2].t = 0.5f * (p[0].t + p[1].t);
                control = count_streaks(pc, map);
            }
        } else {
            bad++;
        }
        tt_polycube_mapping_free(map);
        tt_polycube_free(pc);
        tt_mesh_free(mesh);
        tm_free(&m);
    }
    CHECK(bad == 0, "tori with pinches: %d mappings not closed, area-true and one quad per triangle", bad);
    CHECK(unpinched > 0 && streaks == 0 && control == 1 && fallbacks * 200 < triangles,
          "tori: %d pinches split (some expected), %d streaks (none expected; the control with one corner moved "
          "counts %d, 1 expected), %d fallbacks of %d triangles (under 0.5 %% expected)",
          unpinched, streaks, control, fallbacks, triangles);
}

/* The default refinement maps once with edges up to a cube, then refines
   to half a cube only the faces that mapping fell short on and maps again.
   The control, one mapping at a cube, must fall short somewhere (a
   triangle put whole into a quad, or a piece of no area); the default
   must fall short less, and make far fewer triangles than half a cube
   everywhere (both unmerged, so that the refinement is measured), with
   no more fallbacks than the sphere test allows. */
static void test_map_refine_where_needed(void)
{
    const double centre[3] = {0.13, -0.21, 0.05};
    tmesh m;
    tt_mesh *mesh;
    tt_polycube *pc;
    tt_polycube_map_report rep, coarse_rep, fine_rep, unmerged_rep;
    tt_polycube_map_options mo;
    tt_polycube_mapping *map, *coarse = NULL, *fine = NULL, *unmerged = NULL;
    tt_error err;
    memset(&m, 0, sizeof m);
    memset(&mo, 0, sizeof mo);
    make_sphere(&m, 48, 24, 1.0, centre, 0);
    map = mapped(&m, 32, 0, 0.0, &pc, &mesh, &rep);
    if (map) {
        mo.max_edge = pc->h;
        CHECK(tt_polycube_map(pc, mesh, &mo, NULL, &coarse, &coarse_rep, &err) == TT_OK, "coarse: %s", err.message);
        mo.max_map_error = -1.0;
        mo.max_edge = 0.5 * pc->h;
        CHECK(tt_polycube_map(pc, mesh, &mo, NULL, &fine, &fine_rep, &err) == TT_OK, "fine: %s", err.message);
        mo.max_edge = 0.0;
        CHECK(tt_polycube_map(pc, mesh, &mo, NULL, &unmerged, &unmerged_rep, &err) == TT_OK, "unmerged: %s",
              err.message);
    }
    if (map && coarse && fine && unmerged) {
        printf("     sphere at 32: one mapping at a cube %d triangles, %d fallbacks, %d empty; default %d, %d, %d (%d "
               "faces refined again); unmerged, half a cube %d, the default %d\n", coarse->ntriangles,
               coarse_rep.fallback_triangles, coarse_rep.collapsed, map->ntriangles, rep.fallback_triangles,
               rep.collapsed, rep.refined_again, fine->ntriangles, unmerged->ntriangles);
        CHECK(coarse_rep.fallback_triangles + coarse_rep.collapsed > 0 && coarse_rep.refined_again == 0,
              "control: one mapping at a cube falls short (%d fallbacks, %d empty)", coarse_rep.fallback_triangles,
              coarse_rep.collapsed);
        CHECK(rep.refined_again > 0 && rep.fallback_triangles + rep.collapsed <
                                           coarse_rep.fallback_triangles + coarse_rep.collapsed,
              "the default refines again (%d faces) and falls short less (%d + %d against %d + %d)",
              rep.refined_again, rep.fallback_triangles, rep.collapsed, coarse_rep.fallback_triangles,
              coarse_rep.collapsed);
        CHECK(unmerged->ntriangles <= 0.7 * fine->ntriangles && unmerged_rep.refined_again == rep.refined_again &&
                  rep.fallback_triangles <= rep.triangles / 1000,
              "the default refinement makes %d triangles unmerged (at most 70 %% of half a cube's %d), with %d "
              "fallbacks (at most 0.1 %% of %d)", unmerged->ntriangles, fine->ntriangles, rep.fallback_triangles,
              rep.triangles);
    }
    tt_polycube_mapping_free(map);
    tt_polycube_mapping_free(coarse);
    tt_polycube_mapping_free(fine);
    tt_polycube_mapping_free(unmerged);
    tt_polycube_free(pc);
    tt_mesh_free(mesh);
    tm_free(&m);
}

/* How far a merged mapping moves the texture from the unmerged one: each
   unmerged piece's centroid, found in a merged triangle of the same input
   face and quad, gets a point on S there; the largest distance from the
   centroid's own point, in quads. *unfound counts centroids no merged
   triangle of their face holds in their quad (a grid line's preimage
   straightened by a merge can move a piece's centroid across it). */
static double merge_moved(const tt_polycube_mapping *ref, const tt_polycube_mapping *merged, int nfaces,
                          int *unfound)
{
    int *start = (int *)calloc((size_t)nfaces + 1, sizeof(int)), *items = (int *)malloc(sizeof(int) * (size_t)merged->ntriangles);
    double worst = 0.0;
    int f, j, i;
    *unfound = 0;
    if (!start || !items) {
        free(start);
        free(items);
        *unfound = ref->ntriangles;
        return HUGE_VAL;
    }
    for (j = 0; j < merged->ntriangles; j++) start[merged->triangle_face[j] + 1]++;
    for (f = 0; f < nfaces; f++) start[f + 1] += start[f];
    for (j = 0; j < merged->ntriangles; j++) items[start[merged->triangle_face[j]]++] = j;
    for (f = nfaces; f > 0; f--) start[f] = start[f - 1];
    start[0] = 0;
    for (j = 0; j < ref->ntriangles; j++) {
        const int face = ref->triangle_face[j], quad = ref->corner_points[3 * j].quad;
        double p[3] = {0, 0, 0}, s = 0, t = 0, best = -HUGE_VAL, moved = 0;
        int k, a;
        for (k = 0; k < 3; k++) {
            for (a = 0; a < 3; a++) p[a] += ref->positions[3 * ref->triangles[3 * j + k] + a] / 3.0;
            s += ref->corner_points[3 * j + k].s / 3.0;
            t += ref->corner_points[3 * j + k].t / 3.0;
        }
        for (i = start[face]; i < start[face + 1]; i++) {
            const int g = items[i];
            double q[3][3], e1[3], e2[3], d[3], n[3], c[3], nn, l[3];
            if (merged->corner_points[3 * g].quad != quad) continue;
            for (k = 0; k < 3; k++)
                for (a = 0; a < 3; a++) q[k][a] = merged->positions[3 * merged->triangles[3 * g + k] + a];
            for (a = 0; a < 3; a++) {
                e1[a] = q[1][a] - q[0][a];
                e2[a] = q[2][a] - q[0][a];
            }
            n[0] = e1[1] * e2[2] - e1[2] * e2[1];
            n[1] = e1[2] * e2[0] - e1[0] * e2[2];
            n[2] = e1[0] * e2[1] - e1[1] * e2[0];
            nn = n[0] * n[0] + n[1] * n[1] + n[2] * n[2];
            if (!(nn > 0.0)) continue;
            for (k = 0; k < 3; k++) {
                const double *u = q[(k + 1) % 3], *w = q[(k + 2) % 3];
                for (a = 0; a < 3; a++) {
                    e1[a] = w[a] - u[a];
                    d[a] = p[a] - u[a];
                }
                c[0] = e1[1] * d[2] - e1[2] * d[1];
                c[1] = e1[2] * d[0] - e1[0] * d[2];
                c[2] = e1[0] * d[1] - e1[1] * d[0];
                l[k] = (c[0] * n[0] + c[1] * n[1] + c[2] * n[2]) / nn;
            }
            if (fmin(l[0], fmin(l[1], l[2])) > best) {
                double ds = -s, dt = -t;
                for (k = 0; k < 3; k++) {
                    ds += l[k] * merged->corner_points[3 * g + k].s;
                    dt += l[k] * merged->corner_points[3 * g + k].t;
                }
                best = fmin(l[0], fmin(l[1], l[2]));
                moved = sqrt(ds * ds + dt * dt);
            }
        }
        if (best < -1e-4) (*unfound)++;
        else worst = fmax(worst, moved);
    }
    free(start);
    free(items);
    return worst;
}

/* A mapping's triangles with less area on the model than `below`
   (slivers). */
static int mapping_slivers(const tt_polycube_mapping *map, double below)
{
    int j, count = 0;
    for (j = 0; j < map->ntriangles; j++) {
        const int *v = map->triangles + 3 * j;
        count += triangle_area3(map->positions + 3 * v[0], map->positions + 3 * v[1], map->positions + 3 * v[2]) <
                 below;
    }
    return count;
}

/* A mapping's mean triangle area on the model. */
static double mapping_mean_area(const tt_polycube_mapping *map)
{
    double sum = 0.0;
    int j;
    for (j = 0; j < map->ntriangles; j++) {
        const int *v = map->triangles + 3 * j;
        sum += triangle_area3(map->positions + 3 * v[0], map->positions + 3 * v[1], map->positions + 3 * v[2]);
    }
    return map->ntriangles > 0 ? sum / map->ntriangles : 0.0;
}

/* The per-face stretch of a mapping: each output triangle against its
   points on S scaled to cube units (all three lie in one quad, whose frame
   is a unit square of side h), through tt_measure_uv_distortion. */
static tt_uv_distortion_report mapping_stretch(const tt_polycube_mapping *map)
{
    tt_uv_distortion_report d;
    tt_mesh *out = mapping_mesh(map, TT_MESH_PERMISSIVE);
    float *uv = (float *)malloc(sizeof(float) * 6 * (size_t)map->ntriangles);
    int i;
    memset(&d, 0, sizeof d);
    for (i = 0; i < 3 * map->ntriangles; i++) {
        uv[2 * i] = map->corner_points[i].s;
        uv[2 * i + 1] = map->corner_points[i].t;
    }
    if (out) tt_measure_uv_distortion(out, uv, 256, 256, NULL, NULL, &d, NULL);
    tt_mesh_free(out);
    free(uv);
    return d;
}

/* Step 7, the pieces merged: on a coarse sphere (its triangles span
   several squares, so the split leaves many vertices inside them) the
   default mapping has far fewer triangles than with merging off
   (max_map_error below 0), is as sound (on the model, the area kept,
   closed, each triangle in one quad, none flipped), and its texture keeps
   close to the unmerged one's shape: the stretch percentile the summary
   reports (tt_measure_uv_distortion) within 0.05, the texel density's
   within 0.05 below and 0.1 above (a merge may give a triangle any
   density its star had). Control: merged
   as far without the shape bounds, the stretch p95 grows by more than 1.
   A tight max_map_error holds: the texture stays within
   1/256 of a quad of the unmerged one (control: merged with 0.05 quads,
   the same measure finds it moved past that); the split's slivers on the
   model are mostly gone, and none is made. */
static void test_map_merge(void)
{
    const double centre[3] = {0.02, -0.03, 0.01}, tight_error = 1.0 / 256;
    tmesh m;
    tt_mesh *mesh;
    tt_polycube *pc;
    tt_polycube_map_report rep, ref_rep, tight_rep, loose_rep, free_rep;
    tt_polycube_map_options mo;
    tt_polycube_mapping *map, *ref = NULL, *tight = NULL, *loose = NULL, *unbounded = NULL;
    tt_error err;
    memset(&m, 0, sizeof m);
    memset(&mo, 0, sizeof mo);
    make_sphere(&m, 16, 8, 1.0, centre, 0);
    map = mapped(&m, 24, 0, 0.0, &pc, &mesh, &rep);
    if (map) {
        mo.max_map_error = -1.0;
        CHECK(tt_polycube_map(pc, mesh, &mo, NULL, &ref, &ref_rep, &err) == TT_OK, "unmerged: %s", err.message);
        CHECK(tt_polycube_map(pc, mesh, &mo, NULL, &unbounded, &free_rep, &err) == TT_OK, "unmerged: %s",
              err.message);
        mo.max_map_error = NAN;
        CHECK(tt_polycube_map(pc, mesh, &mo, NULL, &loose, &loose_rep, &err) == TT_ERROR_INVALID_ARGUMENT && !loose,
              "a NaN max_map_error is refused");
        mo.max_map_error = tight_error;
        CHECK(tt_polycube_map(pc, mesh, &mo, NULL, &tight, &tight_rep, &err) == TT_OK, "tight: %s", err.message);
        mo.max_map_error = 0.05;
        CHECK(tt_polycube_map(pc, mesh, &mo, NULL, &loose, &loose_rep, &err) == TT_OK, "loose: %s", err.message);
    }
    if (map && ref && tight && loose && unbounded) {
        const mapping_check c = check_mapping(pc, mesh, map);
        const double ref_mean = mapping_mean_area(ref);
        int unfound, loose_unfound, slivers, ref_slivers;
        double moved, loose_moved, ref_low, ref_high, low, high;
        tt_uv_distortion_report ref_shape, shape, free_shape;
        CHECK(internal_mapping_merge(unbounded, mesh, TT_POLYCUBE_MAP_DEFAULT_ERROR, 0) > 0,
              "the control merges");
        moved = merge_moved(ref, tight, mesh->nfaces, &unfound);
        loose_moved = merge_moved(ref, loose, mesh->nfaces, &loose_unfound);
        slivers = mapping_slivers(map, 1e-4 * ref_mean);
        ref_slivers = mapping_slivers(ref, 1e-4 * ref_mean);
        ref_shape = mapping_stretch(ref);
        shape = mapping_stretch(map);
        free_shape = mapping_stretch(unbounded);
        ref_low = ref_shape.density_p5_over_median;
        ref_high = ref_shape.density_p95_over_median;
        low = shape.density_p5_over_median;
        high = shape.density_p95_over_median;
        printf("     coarse sphere at 24: %d triangles unmerged, %d merged by default, %d within %.3g quads (texture "
               "moved %.2g quads, %d centroids across a line), %d within 0.05 (moved %.2g), %d without the shape "
               "bounds; slivers %d unmerged, %d merged\n", ref->ntriangles, map->ntriangles, tight->ntriangles,
               tight_error, moved, unfound, loose->ntriangles, loose_moved, unbounded->ntriangles, ref_slivers,
               slivers);
        printf("     stretch p95 / density p5, p95: unmerged %.3f / %.3f, %.3f; default %.3f / %.3f, %.3f; "
               "control %.3f / %.3f, %.3f\n", ref_shape.stretch_p95, ref_low, ref_high, shape.stretch_p95, low, high,
               free_shape.stretch_p95, free_shape.density_p5_over_median, free_shape.density_p95_over_median);
        CHECK(ref_rep.merged == 0 && rep.merged == ref->ntriangles - map->ntriangles &&
                  map->ntriangles <= 0.5 * ref->ntriangles && map->ntriangles < loose->ntriangles &&
                  loose->ntriangles < tight->ntriangles && tight->ntriangles <= 0.95 * ref->ntriangles,
              "merging: %d triangles unmerged, %d by default (report %d), %d within 0.05 quads, %d within %.3g",
              ref->ntriangles, map->ntriangles, rep.merged, loose->ntriangles, tight->ntriangles, tight_error);
        CHECK(mapping_sound(&c) && c.moved_inputs == 0 && rep.flipped == 0 &&
                  rep.fallback_triangles == ref_rep.fallback_triangles,
              "the merged mapping is sound (%d off the model, %d inputs moved, %d bad points, area error %.2g, "
              "strict build %s, %d open edges), %d flipped, %d fallbacks (unmerged %d)", c.off_surface,
              c.moved_inputs, c.bad_points, c.area_error, c.strict_fails ? "fails" : "holds", c.open_edges,
              rep.flipped, rep.fallback_triangles, ref_rep.fallback_triangles);
        CHECK(shape.stretch_p95 <= ref_shape.stretch_p95 + 0.05 && low >= ref_low - 0.05 && high <= ref_high + 0.1,
              "the default keeps the texture's shape: stretch p95 %.3f (unmerged %.3f), density p5 %.3f, p95 %.3f "
              "(unmerged %.3f, %.3f)", shape.stretch_p95, ref_shape.stretch_p95, low, high, ref_low, ref_high);
        CHECK(free_shape.stretch_p95 > ref_shape.stretch_p95 + 1.0,
              "control: merged as far without the shape bounds, the stretch p95 grows (%.3f, unmerged %.3f)",
              free_shape.stretch_p95, ref_shape.stretch_p95);
        CHECK(moved <= tight_error + 1e-5 && unfound <= ref->ntriangles / 100,
              "within %.3g quads the texture moved %.3g quads, %d of %d centroids not found", tight_error, moved,
              unfound, ref->ntriangles);
        CHECK(loose_moved > tight_error + 1e-5 && loose_moved <= 0.05 + 1e-5,
              "control: merged within 0.05 quads the texture moved %.3g (above %.3g)", loose_moved, tight_error);
        CHECK(4 * slivers <= ref_slivers && mapping_slivers(map, 1e-6 * ref_mean) == 0,
              "merging takes the split's slivers away and makes none: %d under 1e-4 of the unmerged mean area "
              "(unmerged %d), %d under 1e-6 (unmerged %d)", slivers, ref_slivers,
              mapping_slivers(map, 1e-6 * ref_mean), mapping_slivers(ref, 1e-6 * ref_mean));
    }
    tt_polycube_mapping_free(map);
    tt_polycube_mapping_free(ref);
    tt_polycube_mapping_free(tight);
    tt_polycube_mapping_free(loose);
    tt_polycube_mapping_free(unbounded);
    tt_polycube_free(pc);
    tt_mesh_free(mesh);
    tm_free(&m);
}

/* The seam tests' tiles: n = 2, 32-texel tiles with a 4-texel gutter, seed 3,
   from a 160 x 256 value noise (*photo, to free); NULL on failure. */
static tt_tileset *seam_test_tiles(tt_synth_options *so, tt_image **photo)
{
    tt_tileset *tiles = NULL;
    tt_error err;
    memset(so, 0, sizeof *so);
    so->layout.colors = 2;
    so->layout.tile_size = 32;
    so->layout.gutter = 4;
    so->seed = 3;
    make_value_noise(photo, 160, 256, 9);
    if (!*photo || tt_synthesize_tiles(*photo, so, NULL, &tiles, &err) != TT_OK) return NULL;
    return tiles;
}

/* The UVs of a mapping put each output
   triangle inside its quad's tile (the three UVs in one tile rectangle),
   the textured model is seamless on the tile borders and over all edges,
   and giving each output triangle another's UVs (shuffled) shows seams. */
static void test_map_uvs_and_seams(void)
{
    const double centre[3] = {0.02, 0.11, -0.07};
    int shape;
    tt_image *photo = NULL;
    tt_tileset *tiles = NULL;
    tt_synth_options so;
    tt_error err;
    if (!(tiles = seam_test_tiles(&so, &photo))) {
        CHECK(0, "tiles for the seam test");
        tt_image_free(photo);
        return;
    }
    for (shape = 0; shape < 2; shape++) {
        tmesh m;
        tt_mesh *mesh, *out = NULL;
        tt_polycube *pc;
        tt_polycube_map_report rep;
        tt_polycube_mapping *map;
        unsigned char one = 1;
        memset(&m, 0, sizeof m);
        if (shape == 0) make_cube_set(&m, &one, 1, 1, 1, 1.0, 1);
        else make_sphere(&m, 48, 24, 1.0, centre, 0);
        map = mapped(&m, shape == 0 ? 3 : 8, shape == 0 ? 8 : 0, 0.0, &pc, &mesh, &rep);
        if (map) {
            const tt_mesh *s = pc->surface;
            int *colors = (int *)malloc(sizeof(int) * (size_t)s->ncorners);
            uint8_t *types = (uint8_t *)malloc((size_t)s->ncorners);
            float *uv = (float *)malloc(sizeof(float) * 6 * (size_t)map->ntriangles);
            float *shuffled = (float *)malloc(sizeof(float) * 6 * (size_t)map->ntriangles);
            int f, k, outside = 0;
            tt_seam_options border;
            tt_seam_report fit_border, fit_all, control_border, control_all;
            CHECK(tt_polycube_edge_colors(pc, 2, 1, 7, colors, &err) == TT_OK &&
                      tt_assign_boundaries(s, &so.layout, 7, colors, types, &err) == TT_OK &&
                      tt_polycube_mapping_uvs(pc, map, &so.layout, types, uv, &err) == TT_OK,
                  "the mapping's UVs: %s", err.message);
            for (f = 0; f < map->ntriangles; f++) {
                const uint8_t *t = types + s->face_start[map->corner_points[3 * f].quad];
                float lo[2], hi[2];
                tt_tile_corner_uv(&so.layout, t, 0, lo);
                tt_tile_corner_uv(&so.layout, t, 2, hi);
                for (k = 0; k < 3; k++)
                    outside += uv[6 * f + 2 * k] < lo[0] - 1e-6f || uv[6 * f + 2 * k] > hi[0] + 1e-6f ||
                               uv[6 * f + 2 * k + 1] < lo[1] - 1e-6f || uv[6 * f + 2 * k + 1] > hi[1] + 1e-6f;
            }
            CHECK(outside == 0, "%s: every corner's UV in its quad's tile (%d not)", shape ? "sphere" : "cube",
                  outside);
            lcg_seed(91);
            for (f = 0; f < map->ntriangles; f++) {
                int other = lcg_below(map->ntriangles);
                for (k = 0; k < 6; k++) shuffled[6 * f + k] = uv[6 * other + k];
            }
            memset(&border, 0, sizeof border);
            border.flags = TT_SEAM_UV_DISCONTINUOUS;
            if ((out = mapping_mesh(map, 0)) != NULL &&
                tt_measure_seams(out, uv, &tiles->levels[0], &border, NULL, &fit_border, &err) == TT_OK &&
                tt_measure_seams(out, uv, &tiles->levels[0], NULL, NULL, &fit_all, &err) == TT_OK &&
                tt_measure_seams(out, shuffled, &tiles->levels[0], &border, NULL, &control_border, &err) == TT_OK &&
                tt_measure_seams(out, shuffled, &tiles->levels[0], NULL, NULL, &control_all, &err) == TT_OK) {
                printf("     %s mapped and textured: seam %.3f on tile borders, %.3f over all edges; shuffled "
                       "%.3f, %.3f; %d fallbacks\n", shape ? "sphere" : "cube", fit_border.score, fit_all.score,
                       control_border.score, control_all.score, rep.fallback_triangles);
                CHECK(fit_border.score <= 0.05 && fit_all.score <= 0.05,
                      "%s seamless: %.3f on tile borders, %.3f over all edges", shape ? "sphere" : "cube",
                      fit_border.score, fit_all.score);
                CHECK(control_border.score >= 0.8 && control_all.score >= 0.8,
                      "%s with shuffled UVs shows seams: %.3f, %.3f", shape ? "sphere" : "cube",
                      control_border.score, control_all.score);
            } else {
                CHECK(0, "seams of the mapping measured: %s", err.message);
            }
            tt_mesh_free(out);
            free(colors);
            free(types);
            free(uv);
            free(shuffled);
        }
        tt_polycube_mapping_free(map);
        tt_polycube_free(pc);
        tt_mesh_free(mesh);
        tm_free(&m);
    }
    tt_tileset_free(tiles);
    tt_image_free(photo);
}

/* Rows of a wall tile that darken going down, beyond the noise: the
   courses photo brightens down every course, so an upright tile (one
   course, cut on it) brightens down everywhere and a band turned half a
   turn shows up as rows that darken. */
static int darkening_rows(const tt_image *cell, int g, int S)
{
    int x, y, count = 0;
    for (x = 1; x < S - 1; x++)
        for (y = 0; y + 1 < S; y++) {
            const float *a = cell->pixels + 4 * ((size_t)(g + y) * cell->width + g + x), *b = a + 4 * cell->width;
            if ((b[0] + b[1] + b[2]) - (a[0] + a[1] + a[2]) < -0.05f) count++;
        }
    return count;
}

/* A wall of S: a quad facing sideways. */
static int is_wall(const tt_polycube *pc, int q)
{
    return pc->quad_side[q] / 2 != pc->up_axis;
}

/* tt_polycube_orient_upright: every wall's bottom and right sides take the
   even type, its top and left the odd one, and so do a top's sides that
   meet another top, whole edges turning (the conditions kept, twins still
   the two halves of one); a second call turns nothing. The effect: upright
   tiles of walls and of tops among tops, composed from a photo that
   brightens down every course (courses one tile tall, windows cut on
   them), brighten down everywhere; with the sides tt_assign_boundaries
   drew, turned bands darken down somewhere. */
static void test_orient_upright(void)
{
    const double centre[3] = {0.02, 0.11, -0.07};
    const int S = 16, g = 2;
    tt_polycube_options o;
    tt_polycube_report rep;
    tt_polycube *pc;
    tt_result r;
    tt_error err;
    tmesh m;
    memset(&m, 0, sizeof m);
    make_sphere(&m, 48, 24, 1.0, centre, 0);
    memset(&o, 0, sizeof o);
    o.resolution = 8;
    pc = polycube_of(&m, &o, &rep, &r);
    CHECK(pc != NULL, "sphere polycube: %d", r);
    if (pc) {
        const tt_mesh *s = pc->surface;
        tt_tile_layout layout;
        tt_synth_options so;
        tt_synth_plan *plain_plan = NULL, *upright_plan = NULL;
        tt_image *photo = NULL, *cell = NULL;
        int *colors = (int *)malloc(sizeof(int) * (size_t)s->ncorners);
        uint8_t *drawn = (uint8_t *)malloc((size_t)s->ncorners), *types = (uint8_t *)malloc((size_t)s->ncorners);
        int c, q, k, x, y, turned = -1, again = -1, wrong_before = 0, wrong_after = 0, kept = 0, paired = 0;
        int walls = 0, dark_before = 0, dark_after = 0, tiles_before = 0, tiles_after = 0;
        int top_sides = 0, top_wrong_before = 0, top_wrong_after = 0, tops = 0;
        memset(&layout, 0, sizeof layout);
        layout.colors = 2;
        layout.tile_size = S;
        layout.gutter = g;
        CHECK(colors && drawn && types && tt_polycube_edge_colors(pc, 2, 1, 7, colors, &err) == TT_OK &&
                  tt_assign_boundaries(s, &layout, 7, colors, drawn, &err) == TT_OK,
              "types: %s", err.message);
        memcpy(types, drawn, (size_t)s->ncorners);
        for (q = 0; q < s->nfaces; q++)
            if (is_wall(pc, q))
                for (k = 0; k < 4; k++) wrong_before += (drawn[s->face_start[q] + k] & 1) != (k >= 2);
        CHECK(tt_polycube_orient_upright(pc, types, &turned, &err) == TT_OK && turned > 0, "oriented (%d turned): %s",
              turned, err.message);
        CHECK(tt_polycube_orient_upright(pc, types, &again, &err) == TT_OK && again == 0,
              "a second call turns nothing (%d)", again);
        for (c = 0; c < s->ncorners; c++) {
            int t = s->twin[c];
            kept += types[c] / 2 == drawn[c] / 2;
            paired += types[t] == (types[c] ^ 1);
        }
        for (q = 0; q < s->nfaces; q++) {
            if (is_wall(pc, q)) {
                walls++;
                for (k = 0; k < 4; k++) wrong_after += (types[s->face_start[q] + k] & 1) != (k >= 2);
                continue;
            }
            for (k = 0; k < 4; k++) {
                /* a top's side across which lies a quad facing the same way */
                const int corner = s->face_start[q] + k, across = s->corner_face[s->twin[corner]];
                if (pc->quad_side[across] != pc->quad_side[q]) continue;
                top_sides++;
                top_wrong_before += (drawn[corner] & 1) != (k >= 2);
                top_wrong_after += (types[corner] & 1) != (k >= 2);
            }
        }
        CHECK(wrong_before > 0 && wrong_after == 0 && walls > 0,
              "walls' sides of the wrong type: %d of %d drawn, %d after", wrong_before, 4 * walls, wrong_after);
        CHECK(top_wrong_before > 0 && top_wrong_after == 0,
              "tops' sides meeting tops of the wrong type: %d of %d drawn, %d after", top_wrong_before, top_sides,
              top_wrong_after);
        CHECK(kept == s->ncorners && paired == s->ncorners, "conditions kept (%d), twins paired (%d) of %d", kept,
              paired, s->ncorners);

        /* The photo: 8 courses of 16 rows brightening down, a trace of noise across. */
        if (tt_image_create(96, 128, NULL, &photo, &err) == TT_OK)
            for (y = 0; y < 128; y++)
                for (x = 0; x < 96; x++) {
                    float v = 0.1f + 0.8f * (float)(y % S) / (float)S + 0.01f * (float)((x * 7 + y * 13) % 5);
                    float *p = photo->pixels + 4 * ((size_t)y * 96 + x);
                    p[0] = p[1] = p[2] = v;
                    p[3] = 1.0f;
                }
        memset(&so, 0, sizeof so);
        so.layout = layout;
        so.seed = 5;
        so.courses.period = (float)S;
        so.courses.phase = 0.0f;
        CHECK(photo && tt_synth_plan_create(photo, &so, NULL, &plain_plan, &err) == TT_OK, "plain plan: %s",
              err.message);
        if (plain_plan) {
            so.upright = 1;
            so.edge_windows = plain_plan->edge_windows;
            CHECK(tt_synth_plan_create(photo, &so, NULL, &upright_plan, &err) == TT_OK, "upright plan: %s",
                  err.message);
        }
        if (upright_plan && tt_image_create(S + 2 * g, S + 2 * g, NULL, &cell, &err) == TT_OK)
            for (q = 0; q < s->nfaces; q++) {
                uint8_t before[4], after[4];
                if (!is_wall(pc, q)) {
                    /* a top all of whose sides meet tops: a wall decides the edges it shares with
                       a top, and one whose top side meets the top's top side turns that band */
                    int among = 1;
                    for (k = 0; k < 4; k++)
                        among &= pc->quad_side[s->corner_face[s->twin[s->face_start[q] + k]]] == pc->quad_side[q];
                    if (!among) continue;
                    tops++;
                }
                for (k = 0; k < 4; k++) {
                    before[k] = drawn[s->face_start[q] + k];
                    after[k] = types[s->face_start[q] + k];
                }
                if (tt_synth_compose_tile(upright_plan, photo, before, cell, 0, 0, &err) == TT_OK) {
                    int n = darkening_rows(cell, g, S);
                    dark_before += n;
                    tiles_before += n > 0;
                }
                if (tt_synth_compose_tile(upright_plan, photo, after, cell, 0, 0, &err) == TT_OK) {
                    int n = darkening_rows(cell, g, S);
                    dark_after += n;
                    tiles_after += n > 0;
                }
            }
        CHECK(upright_plan && cell && tops > 0 && tiles_before > (walls + tops) / 4 && dark_after == 0,
              "upright tiles (%d walls, %d tops) with rows darkening down: %d as drawn (%d rows), %d after (%d rows)",
              walls, tops, tiles_before, dark_before, tiles_after, dark_after);
        printf("     orient upright: %d of %d wall sides turned, %d of %d tops' sides between tops; upright tiles "
               "with a turned band %d -> %d of %d\n",
               wrong_before, 4 * walls, top_wrong_before, top_sides, tiles_before, tiles_after, walls + tops);
        CHECK(tt_polycube_orient_upright(NULL, types, NULL, &err) == TT_ERROR_INVALID_ARGUMENT &&
                  tt_polycube_orient_upright(pc, NULL, NULL, &err) == TT_ERROR_INVALID_ARGUMENT,
              "NULL polycube or types refused");
        memcpy(drawn, types, (size_t)s->ncorners);
        types[s->twin[0]] = types[0];
        CHECK(tt_polycube_orient_upright(pc, types, &turned, &err) == TT_ERROR_INVALID_ARGUMENT && turned == 0 &&
                  (err.corner == 0 || err.corner == s->twin[0]) && types[s->twin[0]] == types[0],
              "twins of one type refused, naming the corner (%d), types as they were: %s", err.corner, err.message);
        tt_image_free(cell);
        tt_image_free(photo);
        tt_synth_plan_free(plain_plan);
        tt_synth_plan_free(upright_plan);
        free(colors);
        free(drawn);
        free(types);
    }
    tt_polycube_free(pc);
    tm_free(&m);
}

/* Upright tiles (tt_polycube_mapping_uvs_upright): a sphere textured from
   the four tile sets, 2 x 2, is seamless on the tile borders; every
   corner's UV lies in its quad's set's quarter, and the tops take all four
   sets (among tops, and beside a wall on the right, the left or both).
   Upright tiles on every quad instead (the control) break the edges where
   a top's left or right side meets a wall's top side. */
static void test_map_uvs_upright(void)
{
    const double centre[3] = {0.02, 0.11, -0.07};
    tt_image *photo = NULL, *atlas = NULL;
    tt_tileset *sets[TT_TILESET_KINDS] = {NULL, NULL, NULL, NULL};
    tt_synth_options so;
    tt_polycube *pc = NULL;
    tt_mesh *mesh = NULL, *out = NULL;
    tt_polycube_map_report rep;
    tt_polycube_mapping *map;
    tt_error err;
    tmesh m;
    int k;
    if (!(sets[0] = seam_test_tiles(&so, &photo))) {
        CHECK(0, "plain tiles");
        tt_image_free(photo);
        return;
    }
    make_upright_sets(photo, so, sets);
    if (!sets[1] || !sets[2] || !sets[3] ||
        tt_upright_atlas((const tt_tileset *const *)sets, 0, NULL, NULL, &atlas, &err) != TT_OK) {
        CHECK(0, "upright tiles and their atlas: %s", err.message);
        for (k = 0; k < TT_TILESET_KINDS; k++) tt_tileset_free(sets[k]);
        tt_image_free(photo);
        return;
    }
    memset(&m, 0, sizeof m);
    make_sphere(&m, 48, 24, 1.0, centre, 0);
    map = mapped(&m, 8, 0, 0.0, &pc, &mesh, &rep);
    if (map) {
        const tt_mesh *s = pc->surface;
        int *colors = (int *)malloc(sizeof(int) * (size_t)s->ncorners);
        uint8_t *types = (uint8_t *)malloc((size_t)s->ncorners);
        float *uv = (float *)malloc(sizeof(float) * 6 * (size_t)map->ntriangles);
        float *everywhere = (float *)malloc(sizeof(float) * 6 * (size_t)map->ntriangles);
        int i, q, wrong_quarter = 0, walls = 0, top_sets[TT_TILESET_KINDS] = {0, 0, 0, 0};
        tt_seam_options border;
        tt_seam_report fit, control;
        CHECK(colors && types && uv && everywhere && tt_polycube_edge_colors(pc, 2, 1, 7, colors, &err) == TT_OK &&
                  tt_assign_boundaries(s, &so.layout, 7, colors, types, &err) == TT_OK &&
                  tt_polycube_mapping_uvs_upright(pc, map, &so.layout, types, uv, &err) == TT_OK &&
                  tt_polycube_mapping_uvs(pc, map, &so.layout, types, everywhere, &err) == TT_OK,
              "the upright UVs: %s", err.message);
        CHECK(pc->up_axis == 1 && pc->up_sign == 1, "the default up is +y: axis %d, sign %d", pc->up_axis,
              pc->up_sign);
        for (q = 0; q < s->nfaces; q++) {
            const int set = (int)tt_polycube_quad_tileset(pc, q);
            if (is_wall(pc, q)) {
                walls++;
                wrong_quarter += set != TT_TILESET_UPRIGHT;
            } else {
                top_sets[set]++;
            }
        }
        for (i = 0; i < 3 * map->ntriangles; i++) {
            const int set = (int)tt_polycube_quad_tileset(pc, map->corner_points[i].quad);
            wrong_quarter += uv[2 * i] < 0.5f * (float)(set % 2) || uv[2 * i] > 0.5f * (float)(set % 2 + 1) ||
                             uv[2 * i + 1] < 0.5f * (float)(set / 2) || uv[2 * i + 1] > 0.5f * (float)(set / 2 + 1);
            everywhere[2 * i] = 0.5f * (everywhere[2 * i] + 1.0f);
            everywhere[2 * i + 1] = 0.5f * everywhere[2 * i + 1];
        }
        CHECK(wrong_quarter == 0 && walls > 0, "every wall upright, every corner in its set's quarter: %d not",
              wrong_quarter);
        CHECK(top_sets[0] > 0 && top_sets[1] > 0 && top_sets[2] > 0 && top_sets[3] > 0,
              "tops and bottoms in every set: plain %d, upright %d, right side plain %d, left side plain %d",
              top_sets[0], top_sets[1], top_sets[2], top_sets[3]);
        memset(&border, 0, sizeof border);
        border.flags = TT_SEAM_UV_DISCONTINUOUS;
        if ((out = mapping_mesh(map, 0)) != NULL &&
            tt_measure_seams(out, uv, atlas, &border, NULL, &fit, &err) == TT_OK &&
            tt_measure_seams(out, everywhere, atlas, &border, NULL, &control, &err) == TT_OK) {
            printf("     sphere with upright tiles, plain sides beside the walls: seam %.3f on tile borders; "
                   "upright tiles everywhere: %.3f\n", fit.score, control.score);
            CHECK(fit.score <= 0.05, "upright tiles seamless: %.3f on the tile borders", fit.score);
            /* Only the edges where a top's left or right side meets a wall break (a tenth of the borders),
               so the control's score rises by less than a seam's full 1. */
            CHECK(control.score >= fit.score + 0.08, "upright tops beside walls show seams: %.3f against %.3f",
                  control.score, fit.score);
        } else {
            CHECK(0, "seams measured: %s", err.message);
        }
        free(colors);
        free(types);
        free(uv);
        free(everywhere);
    }
    tt_mesh_free(out);
    tt_polycube_mapping_free(map);
    tt_polycube_free(pc);
    tt_mesh_free(mesh);
    tm_free(&m);
    tt_image_free(atlas);
    for (k = 0; k < TT_TILESET_KINDS; k++) tt_tileset_free(sets[k]);
    tt_image_free(photo);
}

typedef struct map_oom_ctx {
    const tt_polycube *pc;
    const tt_mesh *mesh;
} map_oom_ctx;

static tt_result map_oom_call(void *ctx, const tt_allocator *al, tt_error *error)
{
    map_oom_ctx *c = (map_oom_ctx *)ctx;
    tt_polycube_mapping *map = (tt_polycube_mapping *)&map;
    tt_result r = tt_polycube_map(c->pc, c->mesh, NULL, al, &map, NULL, error);
    if (error->result != r || (r != TT_OK) != (map == NULL)) return TT_RESULT_MAX_ENUM;
    tt_polycube_mapping_free(map);
    return r;
}

/* Determinism and the errors: the same input gives bitwise the same mapping; bad
   arguments and polygons are refused with *out NULL; every allocation
   failure is reported and leaks nothing. */
static void test_map_determinism_and_errors(void)
{
    const double centre[3] = {0.3, 0.1, -0.2};
    tmesh m, quads;
    tt_mesh *mesh, *quad_mesh = NULL;
    tt_polycube *pc;
    tt_polycube_map_report rep;
    tt_polycube_map_options mo;
    tt_polycube_mapping *map, *again = NULL, *none = (tt_polycube_mapping *)&none;
    tt_error err;
    tt_result r;
    map_oom_ctx ctx;
    unsigned char one = 1;
    memset(&m, 0, sizeof m);
    make_sphere(&m, 24, 12, 1.0, centre, 0);
    map = mapped(&m, 6, 0, 0.0, &pc, &mesh, &rep);
    if (!map) {
        tt_polycube_free(pc);
        tt_mesh_free(mesh);
        tm_free(&m);
        return;
    }
    r = tt_polycube_map(pc, mesh, NULL, NULL, &again, NULL, &err);
    CHECK(r == TT_OK && again->nverts == map->nverts && again->ntriangles == map->ntriangles &&
              memcmp(again->positions, map->positions, sizeof(float) * 3 * (size_t)map->nverts) == 0 &&
              memcmp(again->source, map->source, sizeof(int) * 3 * (size_t)map->nverts) == 0 &&
              memcmp(again->weights, map->weights, sizeof(float) * 3 * (size_t)map->nverts) == 0 &&
              memcmp(again->triangles, map->triangles, sizeof(int) * 3 * (size_t)map->ntriangles) == 0 &&
              memcmp(again->triangle_face, map->triangle_face, sizeof(int) * (size_t)map->ntriangles) == 0 &&
              memcmp(again->corner_points, map->corner_points, sizeof(tt_surface_point) * 3 * (size_t)map->ntriangles) == 0,
          "same input, bitwise the same mapping");
    tt_polycube_mapping_free(again);
    CHECK(tt_polycube_map(NULL, mesh, NULL, NULL, &none, NULL, &err) == TT_ERROR_INVALID_ARGUMENT && none == NULL &&
              tt_polycube_map(pc, NULL, NULL, NULL, &none, NULL, &err) == TT_ERROR_INVALID_ARGUMENT &&
              tt_polycube_map(pc, mesh, NULL, NULL, NULL, NULL, &err) == TT_ERROR_INVALID_ARGUMENT,
          "NULL polycube, mesh or out: invalid, *out NULL");
    memset(&mo, 0, sizeof mo);
    mo.max_quads = TT_POLYCUBE_EDGE_MAX_QUADS + 1;
    none = (tt_polycube_mapping *)&none;
    r = tt_polycube_map(pc, mesh, &mo, NULL, &none, &rep, &err);
    CHECK(r == TT_ERROR_INVALID_ARGUMENT && none == NULL && rep.flipped == 0 && rep.projection.rays == 0,
          "max_quads out of range: invalid, the report zeroed (%s)", err.message);
    mo.max_quads = 0;
    mo.max_edge = -1.0;
    r = tt_polycube_map(pc, mesh, &mo, NULL, &none, &rep, &err);
    mo.max_edge = internal_not_a_number();
    CHECK(r == TT_ERROR_INVALID_ARGUMENT && none == NULL &&
              tt_polycube_map(pc, mesh, &mo, NULL, &none, &rep, &err) == TT_ERROR_INVALID_ARGUMENT && none == NULL,
          "max_edge negative or NaN: invalid (%s)", err.message);
    /* A max_edge whose refinement would pass TT_POLYCUBE_MAX_TRIANGLES is
       refused before any work, naming the limit (it used to refine until
       memory ran out). */
    mo.max_edge = 1e-30;
    oom_reset();
    r = tt_polycube_map(pc, mesh, &mo, &g_oom_allocator, &none, &rep, &err);
    CHECK(r == TT_ERROR_TOO_LARGE && none == NULL && strstr(err.message, "TT_POLYCUBE_MAX_TRIANGLES") != NULL &&
              g_oom_counter.live == 0,
          "max_edge 1e-30: too large, naming the limit (%d: %s)", r, err.message);
    mo.max_edge = 2e-3 * pc->h;   /* the sphere's area over (2e-3 h)^2 passes 2^22 */
    g_oom_counter.calls = 0;
    r = tt_polycube_map(pc, mesh, &mo, &g_oom_allocator, &none, &rep, &err);
    CHECK(r == TT_ERROR_TOO_LARGE && none == NULL && g_oom_counter.calls == 0,
          "max_edge 2e-3 cubes: too large before any allocation (%d, %ld allocations: %s)", r, g_oom_counter.calls,
          err.message);
    mo.max_edge = 0;
    /* The progress callback: fractions rising to 1; cancelling at any call
       stops with TT_CANCELLED, nothing returned and nothing left allocated. */
    {
        progress_log log;
        int k, calls, bad = 0;
        memset(&log, 0, sizeof log);
        log.cancel_at = -1;
        mo.progress = log_progress;
        mo.progress_user_data = &log;
        r = tt_polycube_map(pc, mesh, &mo, NULL, &none, NULL, &err);
        CHECK(r == TT_OK && log.calls >= 6 && log.decreasing == 0 && log.last == 1.0f,
              "progress: %d calls, %d out of order, last %g (%d)", log.calls, log.decreasing, log.last, r);
        /* The relaxation and the smoothing, which take seconds on a scan,
           report from inside their sweeps, not only where they end. */
        CHECK(log.within_smoothing >= 3, "progress: %d calls from inside the relaxation and the smoothing",
              log.within_smoothing);
        tt_polycube_mapping_free(none);
        calls = log.calls;
        for (k = 0; k < calls; k++) {
            memset(&log, 0, sizeof log);
            log.cancel_at = k;
            oom_reset();
            none = (tt_polycube_mapping *)&none;
            r = tt_polycube_map(pc, mesh, &mo, &g_oom_allocator, &none, &rep, &err);
            if (r != TT_CANCELLED || none != NULL || g_oom_counter.live != 0 || err.result != TT_CANCELLED ||
                log.calls != k + 1) {
                if (!bad) DETAIL("cancelled at call %d: result %d, %ld blocks live, %d calls", k, r, g_oom_counter.live,
                                 log.calls);
                bad++;
            }
        }
        CHECK(bad == 0, "cancelling at each of the %d progress calls: %d did not stop cleanly", calls, bad);
        mo.progress = NULL;
    }
    memset(&quads, 0, sizeof quads);
    make_cube_set(&quads, &one, 1, 1, 1, 1.0, 0);
    if (build(&quads, 0, &quad_mesh, &err) == TT_OK) {
        r = tt_polycube_map(pc, quad_mesh, NULL, NULL, &none, NULL, &err);
        CHECK(r == TT_ERROR_INVALID_ARGUMENT && err.face == 0 && strstr(err.message, "triangles") != NULL,
              "a quad mesh: invalid, naming face 0 and saying triangles are needed (%s)", err.message);
    }
    {
        float uv[6];
        uint8_t types[4] = {0, 0, 0, 0};
        tt_tile_layout layout = {2, 32, 4};
        CHECK(tt_polycube_mapping_uvs(NULL, map, &layout, types, uv, &err) == TT_ERROR_INVALID_ARGUMENT &&
                  tt_polycube_mapping_uvs(pc, NULL, &layout, types, uv, &err) == TT_ERROR_INVALID_ARGUMENT &&
                  tt_polycube_mapping_uvs(pc, map, &layout, NULL, uv, &err) == TT_ERROR_INVALID_ARGUMENT,
              "tt_polycube_mapping_uvs with NULL arguments: invalid");
    }
    if (map && map->ntriangles > 0) {
        /* A corner point off its quad (NaN, or s > 1): refused, not written
           as a UV. */
        tt_tile_layout layout = {1, 32, 4};
        uint8_t *types = (uint8_t *)calloc((size_t)pc->surface->ncorners, 1);
        float *uv = (float *)malloc(sizeof(float) * 6 * (size_t)map->ntriangles);
        tt_surface_point saved = map->corner_points[4];
        if (types && uv) {
            map->corner_points[4].s = (float)internal_not_a_number();
            r = tt_polycube_mapping_uvs(pc, map, &layout, types, uv, &err);
            CHECK(r == TT_ERROR_NON_FINITE && err.corner == 4 && err.face == 1,
                  "a NaN corner point: %d, corner %d (%s)", r, err.corner, err.message);
            map->corner_points[4].s = saved.s;
            map->corner_points[4].t = 1.5f;
            r = tt_polycube_mapping_uvs_upright(pc, map, &layout, types, uv, &err);
            CHECK(r == TT_ERROR_INVALID_ARGUMENT && err.corner == 4, "t = 1.5: %d (%s)", r, err.message);
            map->corner_points[4] = saved;
            r = tt_polycube_mapping_uvs(pc, map, &layout, types, uv, &err);
            CHECK(r == TT_OK, "restored: %d (%s)", r, err.message);
        }
        free(types);
        free(uv);
    }
    ctx.pc = pc;
    ctx.mesh = mesh;
    oom_reset();
    oom_sweep("tt_polycube_map(sphere at resolution 6)", map_oom_call, &ctx, TT_OK);
    tt_mesh_free(quad_mesh);
    tm_free(&quads);
    tt_polycube_mapping_free(map);
    tt_polycube_free(pc);
    tt_mesh_free(mesh);
    tm_free(&m);
}

/* The stretch floor of a voxel polycube: a cube turned 45
   degrees about z maps its four sides onto staircases sqrt 2 longer across
   the slope, at any resolution. A uniform map of a side has stretch sqrt 2
   everywhere; a map may trade some of it for density (stretching less in
   one place, more in another), so the area-weighted median may fall below
   sqrt 2 but the 95th percentile may not (the sides are 2/3 of the area),
   and nothing is far above it; a metric that only measured area would see
   1. */
static void test_map_stretch_floor(void)
{
    const double lo[3] = {-0.5, -0.5, -0.5}, hi[3] = {0.5, 0.5, 0.5}, c = cos(0.25 * 3.14159265358979323846),
                 sn = sin(0.25 * 3.14159265358979323846);
    int resolution;
    for (resolution = 16; resolution <= 64; resolution *= 4) {
        tmesh m;
        tt_mesh *mesh;
        tt_polycube *pc;
        tt_polycube_map_report rep;
        tt_polycube_mapping *map;
        int i;
        memset(&m, 0, sizeof m);
        make_box(&m, lo, hi);
        for (i = 0; i < m.nv; i++) {
            double x = m.pos[3 * i], y = m.pos[3 * i + 1];
            m.pos[3 * i] = (float)(c * x - sn * y);
            m.pos[3 * i + 1] = (float)(sn * x + c * y);
        }
        map = mapped(&m, resolution, 0, 0.0, &pc, &mesh, &rep);
        if (map) {
            tt_uv_distortion_report d = mapping_stretch(map);
            printf("     cube turned 45 degrees at resolution %d: stretch median %.3f, p95 %.3f; %d fallbacks of %d, "
                   "%d flipped\n", resolution, d.stretch_median, d.stretch_p95, rep.fallback_triangles,
                   rep.triangles, rep.flipped);
            CHECK(d.stretch_median >= 1.15 && d.stretch_p95 >= 0.95 * sqrt(2.0) && d.stretch_p95 <= 1.15 * sqrt(2.0),
                  "cube turned 45 degrees at resolution %d: median stretch %.3f (1.15 or more), p95 %.3f (sqrt 2 "
                  "within -5 %% and +15 %%)", resolution, d.stretch_median, d.stretch_p95);
        }
        tt_polycube_mapping_free(map);
        tt_polycube_free(pc);
        tt_mesh_free(mesh);
        tm_free(&m);
    }
}

/* A thin plate: a plate a quarter of a cube thick
   becomes a one-cube slab, and its two sides go to the slab's opposite
   faces (the side rule of the projection): no part of the top on the
   slab's bottom or the other way round (near the rim both wrap onto the
   slab's sides), with nothing flipped or left to the fallback. */
static void test_map_thin_plate(void)
{
    const double lo[3] = {0.0, 0.0, 0.0}, hi[3] = {1.0, 1.0, 0.0625};
    tmesh m;
    tt_mesh *mesh;
    tt_polycube *pc;
    tt_polycube_map_report rep;
    tt_polycube_mapping *map;
    memset(&m, 0, sizeof m);
    make_box(&m, lo, hi);
    map = mapped(&m, 4, 0, 0.0, &pc, &mesh, &rep);
    if (map) {
        int f, wrong = 0, top = 0, bottom = 0;
        mapping_check c = check_mapping(pc, mesh, map);
        for (f = 0; f < map->ntriangles; f++) {
            float n[3];
            int side = pc->quad_side[map->corner_points[3 * f].quad];
            tt_face_normal(mesh, map->triangle_face[f], n);
            if (n[2] > 0.9f) {
                top++;
                wrong += side == 5;
            } else if (n[2] < -0.9f) {
                bottom++;
                wrong += side == 4;
            }
        }
        CHECK(wrong == 0 && top > 0 && bottom > 0 && rep.flipped == 0 && rep.fallback_triangles == 0 &&
                  c.area_error <= 1e-6 && !c.strict_fails && c.open_edges == 0,
              "thin plate: %d of %d top and %d bottom triangles on the slab's opposite face, %d flipped, %d "
              "fallbacks, area error %.2g, strict build %s with %d open edges", wrong, top, bottom, rep.flipped,
              rep.fallback_triangles, c.area_error, c.strict_fails ? "fails" : "holds", c.open_edges);
    }
    tt_polycube_mapping_free(map);
    tt_polycube_free(pc);
    tt_mesh_free(mesh);
    tm_free(&m);
}

/* Open and messy meshes: a flat disc (one layer of cubes, both sides
   of S around it) and a sphere cut into 32 patches that share no vertex
   (an unwelded export): every triangle is mapped, the area kept, every
   vertex on the model. */
static void test_map_open_and_messy(void)
{
    const double centre[3] = {0.0, 0.0, 0.0};
    int shape;
    for (shape = 0; shape < 2; shape++) {
        tmesh m, src;
        tt_mesh *mesh;
        tt_polycube *pc;
        tt_polycube_map_report rep;
        tt_polycube_mapping *map;
        int i, k;
        memset(&m, 0, sizeof m);
        memset(&src, 0, sizeof src);
        if (shape == 0) {
            int centre_vertex = tm_vert(&m, 0.0, 0.0, 0.0);
            for (i = 0; i < 24; i++) {
                double a = 2.0 * 3.14159265358979323846 * i / 24;
                tm_vert(&m, cos(a), sin(a), 0.0);
            }
            for (i = 0; i < 24; i++) tm_tri(&m, centre_vertex, 1 + i, 1 + (i + 1) % 24);
        } else {
            /* Each triangle of a sphere in one of 32 patches by longitude, each patch with its own copies. */
            make_sphere(&src, 32, 16, 1.0, centre, 0);
            for (i = 0; i < src.nf; i++) {
                int v[3];
                for (k = 0; k < 3; k++) {
                    int o = src.idx[3 * i + k];
                    v[k] = tm_vert(&m, src.pos[3 * o], src.pos[3 * o + 1], src.pos[3 * o + 2]);
                }
                tm_tri(&m, v[0], v[1], v[2]);
            }
        }
        map = mapped(&m, 8, 0, 0.0, &pc, &mesh, &rep);
        if (map) {
            mapping_check c = check_mapping(pc, mesh, map);
            int covered = 1, *seen = (int *)calloc((size_t)mesh->nfaces, sizeof(int));
            for (i = 0; i < map->ntriangles; i++) seen[map->triangle_face[i]] = 1;
            for (i = 0; i < mesh->nfaces; i++) covered &= seen[i];
            free(seen);
            CHECK(covered && c.off_surface == 0 && c.bad_points == 0 && c.area_error <= 1e-6,
                  "%s: every triangle mapped (%s), %d vertices off the model, %d corner points off one quad, area "
                  "error %.2g; %d fallbacks of %d", shape ? "sphere in 32 unwelded patches" : "disc",
                  covered ? "yes" : "no", c.off_surface, c.bad_points, c.area_error, rep.fallback_triangles,
                  rep.triangles);
        }
        tt_polycube_mapping_free(map);
        tt_polycube_free(pc);
        tt_mesh_free(mesh);
        tm_free(&m);
        tm_free(&src);
    }
}

/* ------------------------------------------------------------------------ */
/* The relaxation's kernel move and its untangling (Chang and Lin Sec. 4)   */
/* ------------------------------------------------------------------------ */

/* Whether p sees every triangle (p, a, b) of the star turning
   counter-clockwise by more than `margin` (twice the area). */
static int star_unfolded(const double (*ring)[2], int n, const double p[2], double margin)
{
    int i;
    for (i = 0; i < n; i++) {
        const double *a = ring[2 * i], *b = ring[2 * i + 1];
        if ((a[0] - p[0]) * (b[1] - p[1]) - (a[1] - p[1]) * (b[0] - p[0]) <= margin) return 0;
    }
    return 1;
}

/* The kernel centre against brute force: on random rings around a point
   (some star-shaped, some not), a centre when found unfolds the whole star,
   and wherever a fine grid finds a point that does, a centre is found. */
static void test_relax_kernel(void)
{
    int round, found = 0, missed = 0, wrong = 0, empty = 0;
    lcg_seed(99);
    for (round = 0; round < 400; round++) {
        double ring[2 * 12][2], angle[12], radius[12], centre[2], lo[2] = {1e9, 1e9}, hi[2] = {-1e9, -1e9};
        int n = 3 + lcg_below(10), i, j, k, grid_found = 0, got;
        /* Even turns around the origin (star-shaped there), random ones sorted, whose gaps may pass half a
           turn (star-shaped or not), or unsorted (a ring crossing itself: mostly no kernel). */
        for (i = 0; i < n; i++) {
            angle[i] = round % 2 ? 6.283185307179586 * lcg_unit() : 6.283185307179586 * (i + 0.8 * lcg_unit()) / n;
            radius[i] = 0.2 + lcg_unit();
        }
        for (i = 1; i < n && round % 4 != 3; i++)
            for (j = i; j > 0 && angle[j - 1] > angle[j]; j--) {
                double swap = angle[j];
                angle[j] = angle[j - 1];
                angle[j - 1] = swap;
            }
        for (i = 0; i < n; i++)
            for (k = 0; k < 2; k++) {
                const int at = (i + k) % n;
                ring[2 * i + k][0] = radius[at] * cos(angle[at]);
                ring[2 * i + k][1] = radius[at] * sin(angle[at]);
                for (j = 0; j < 2; j++) {
                    if (ring[2 * i + k][j] < lo[j]) lo[j] = ring[2 * i + k][j];
                    if (ring[2 * i + k][j] > hi[j]) hi[j] = ring[2 * i + k][j];
                }
            }
        for (i = 0; i <= 200 && !grid_found; i++)
            for (j = 0; j <= 200 && !grid_found; j++) {
                double p[2];
                p[0] = lo[0] + (hi[0] - lo[0]) * i / 200.0;
                p[1] = lo[1] + (hi[1] - lo[1]) * j / 200.0;
                grid_found = star_unfolded((const double (*)[2])ring, n, p, 1e-6);
            }
        got = internal_relax_kernel_centre((const double (*)[2])ring, n, centre);
        found += got;
        empty += !grid_found;
        missed += grid_found && !got;
        wrong += got && !star_unfolded((const double (*)[2])ring, n, centre, 0.0);
    }
    CHECK(missed == 0 && wrong == 0 && found > 50 && empty > 50,
          "star kernels of 400 random rings: %d found (%d empty by a 200 x 200 grid), %d missed where the grid "
          "found a point, %d centres that leave a triangle folded", found, empty, missed, wrong);
}

/* The untangling energy (Escobar et al. in 2D): 1 per triangle for a
   similarity of the triangle's shape, its gradient as central differences
   give it, and its fold count as orientation gives it. */
static void test_untangle_energy(void)
{
    double ring[8][2][2], shape[8][2][2], x[2] = {0.0, 0.0}, gradient[2];
    int round, i, folded, bad_gradient = 0, bad_folds = 0;
    double worst = 0.0, similarity;
    lcg_seed(7);
    for (i = 0; i < 6; i++) {
        double a0 = 6.283185307179586 * i / 6, a1 = 6.283185307179586 * (i + 1) / 6;
        double scale = 0.3, turn = 0.7, k;
        shape[i][0][0] = cos(a0);
        shape[i][0][1] = sin(a0);
        shape[i][1][0] = cos(a1);
        shape[i][1][1] = sin(a1);
        for (k = 0; k < 2; k++) {
            const double *p = shape[i][(int)k];
            ring[i][(int)k][0] = scale * (cos(turn) * p[0] - sin(turn) * p[1]);
            ring[i][(int)k][1] = scale * (sin(turn) * p[0] + cos(turn) * p[1]);
        }
    }
    similarity = internal_untangle_energy(6, (const double (*)[2][2])ring, (const double (*)[2][2])shape, x, 0.0,
                                          0.0, gradient, NULL, &folded);
    CHECK(fabs(similarity - 6.0) < 1e-12 && folded == 0 && fabs(gradient[0]) + fabs(gradient[1]) < 1e-9,
          "a star turned and scaled as a whole costs 1 per triangle (%.15g for 6), none folded (%d), and is "
          "a minimum (gradient %.2g, %.2g)", similarity, folded, gradient[0], gradient[1]);
    for (round = 0; round < 200; round++) {
        double delta2 = round % 4 ? 1e-4 + 1e-3 * lcg_unit() : 0.0, step = 1e-6, plus, minus, p[2], g[2];
        int n = 3 + lcg_below(6), naive = 0, k;
        for (i = 0; i < n; i++)
            for (k = 0; k < 2; k++) {
                ring[i][k][0] = 2.0 * lcg_unit() - 1.0;
                ring[i][k][1] = 2.0 * lcg_unit() - 1.0;
                shape[i][k][0] = k ? 0.2 + lcg_unit() : 0.5 + lcg_unit();
                shape[i][k][1] = k ? 0.3 + lcg_unit() : 0.0;
            }
        x[0] = 0.5 * lcg_unit() - 0.25;
        x[1] = 0.5 * lcg_unit() - 0.25;
        internal_untangle_energy(n, (const double (*)[2][2])ring, (const double (*)[2][2])shape, x, delta2, 0.0,
                                 gradient, NULL, &folded);
        for (i = 0; i < n; i++)
            naive += (ring[i][0][0] - x[0]) * (ring[i][1][1] - x[1]) - (ring[i][0][1] - x[1]) * (ring[i][1][0] - x[0]) <= 0.0;
        bad_folds += naive != folded;
        if (delta2 == 0.0 && naive) continue;   /* without delta a fold has no finite energy */
        for (k = 0; k < 2; k++) {
            double scale;
            p[0] = x[0];
            p[1] = x[1];
            p[k] += step;
            plus = internal_untangle_energy(n, (const double (*)[2][2])ring, (const double (*)[2][2])shape, p, delta2,
                                            0.0, g, NULL, &folded);
            p[k] -= 2.0 * step;
            minus = internal_untangle_energy(n, (const double (*)[2][2])ring, (const double (*)[2][2])shape, p, delta2,
                                             0.0, g, NULL, &folded);
            scale = fabs(gradient[k]) > 1.0 ? fabs(gradient[k]) : 1.0;
            if (fabs((plus - minus) / (2.0 * step) - gradient[k]) / scale > worst)
                worst = fabs((plus - minus) / (2.0 * step) - gradient[k]) / scale;
        }
        bad_gradient += worst > 1e-4;
    }
    CHECK(bad_gradient == 0 && bad_folds == 0,
          "untangling energy on 200 random stars: gradient as central differences (worst relative error %.2g), "
          "folds as orientation (%d stars differ)", worst, bad_folds);
}

/* The smoothing energy (tt__untangle_energy with a density): a star turned
   as a whole and scaled to the density costs 2 per unit of its area and is
   a minimum; on random stars its gradient and Hessian agree with central
   differences; a folded star costs HUGE_VAL (the barrier). */
static void test_smooth_energy(void)
{
    double ring[8][2][2], shape[8][2][2], x[2] = {0.0, 0.0}, gradient[2], hessian[3], area = 0.0;
    double worst_gradient = 0.0, worst_hessian = 0.0, energy;
    int round, i, k, folded, checked = 0, barriers = 0, folded_stars = 0;
    lcg_seed(11);
    for (i = 0; i < 6; i++) {
        double a0 = 6.283185307179586 * i / 6, a1 = 6.283185307179586 * (i + 1) / 6, scale = 0.3, turn = 0.7;
        shape[i][0][0] = cos(a0);
        shape[i][0][1] = sin(a0);
        shape[i][1][0] = cos(a1);
        shape[i][1][1] = sin(a1);
        area += 0.5 * sin(a1 - a0);
        for (k = 0; k < 2; k++) {
            const double *p = shape[i][k];
            ring[i][k][0] = scale * (cos(turn) * p[0] - sin(turn) * p[1]);
            ring[i][k][1] = scale * (sin(turn) * p[0] + cos(turn) * p[1]);
        }
    }
    energy = internal_untangle_energy(6, (const double (*)[2][2])ring, (const double (*)[2][2])shape, x, 0.0, 0.09,
                                      gradient, hessian, &folded);
    CHECK(fabs(energy - 2.0 * area) < 1e-12 && folded == 0 && fabs(gradient[0]) + fabs(gradient[1]) < 1e-9 &&
              hessian[0] > 0.0 && hessian[0] * hessian[2] - hessian[1] * hessian[1] > 0.0,
          "a star turned and scaled to the density costs 2 per unit area (%.15g for %.15g) and is a minimum "
          "(gradient %.2g, %.2g; Hessian %.3g %.3g %.3g)", energy, area, gradient[0], gradient[1], hessian[0],
          hessian[1], hessian[2]);
    for (round = 0; round < 400; round++) {
        const double density = 0.2 + 3.0 * lcg_unit(), step = 1e-6;
        int n = 3 + lcg_below(6), naive = 0;
        double angle[9];
        /* A fan around the origin at jittered angles (unfolded at x near the
           origin), every fourth with two of its points swapped (folded). */
        for (i = 0; i <= n; i++) angle[i] = 6.283185307179586 * (i + 0.4 * lcg_unit()) / n;
        for (i = 0; i < n; i++)
            for (k = 0; k < 2; k++) {
                const double a = k ? (i + 1 < n ? angle[i + 1] : angle[0]) : angle[i], r = 0.5 + lcg_unit();
                ring[i][k][0] = r * cos(a);
                ring[i][k][1] = r * sin(a);
                shape[i][k][0] = k ? 0.2 + lcg_unit() : 0.5 + lcg_unit();
                shape[i][k][1] = k ? 0.3 + lcg_unit() : 0.0;
            }
        if (round % 4 == 3) {
            double swap[2][2];
            memcpy(swap, ring[0], sizeof swap);
            memcpy(ring[0][0], swap[1], sizeof swap[1]);
            memcpy(ring[0][1], swap[0], sizeof swap[0]);
        }
        x[0] = 0.2 * lcg_unit() - 0.1;
        x[1] = 0.2 * lcg_unit() - 0.1;
        for (i = 0; i < n; i++)
            naive += (ring[i][0][0] - x[0]) * (ring[i][1][1] - x[1]) - (ring[i][0][1] - x[1]) * (ring[i][1][0] - x[0]) <= 0.0;
        energy = internal_untangle_energy(n, (const double (*)[2][2])ring, (const double (*)[2][2])shape, x, 0.0,
                                          density, gradient, hessian, &folded);
        if (naive) {
            folded_stars++;
            barriers += energy == HUGE_VAL;
            continue;
        }
        checked++;
        for (k = 0; k < 2; k++) {
            double p[2], g_plus[2], g_minus[2], h[3], plus, minus, scale;
            int j;
            p[0] = x[0];
            p[1] = x[1];
            p[k] += step;
            plus = internal_untangle_energy(n, (const double (*)[2][2])ring, (const double (*)[2][2])shape, p, 0.0,
                                            density, g_plus, h, &folded);
            p[k] -= 2.0 * step;
            minus = internal_untangle_energy(n, (const double (*)[2][2])ring, (const double (*)[2][2])shape, p, 0.0,
                                             density, g_minus, h, &folded);
            scale = fmax(1.0, fabs(gradient[k]));
            worst_gradient = fmax(worst_gradient, fabs((plus - minus) / (2.0 * step) - gradient[k]) / scale);
            /* Row k of the Hessian: (xx, xy) for k = 0, (xy, yy) for k = 1. */
            for (j = 0; j < 2; j++) {
                const double exact = hessian[k + j], numeric = (g_plus[j] - g_minus[j]) / (2.0 * step);
                worst_hessian = fmax(worst_hessian, fabs(numeric - exact) / fmax(1.0, fabs(exact)));
            }
        }
    }
    CHECK(checked >= 100 && worst_gradient < 1e-4 && worst_hessian < 1e-4,
          "smoothing energy on %d unfolded random stars: gradient (worst relative error %.2g) and Hessian (%.2g) "
          "as central differences", checked, worst_gradient, worst_hessian);
    CHECK(folded_stars >= 20 && barriers == folded_stars, "%d of %d folded stars cost HUGE_VAL", barriers,
          folded_stars);
}

/* The descent of a star's centre: to the centre of a regular star from
   off it, lower in energy each time (untangling and smoothing), and
   nowhere, with every number finite, when one triangle is within rounding
   of flat: its gradient overflows (1 / det^2 with det near 1e-170), and
   the step it would give is no number at all. Before, such a star sent
   the vertex to a place never computed (found by fuzzing: the same input
   mapped twice came out two ways). */
static void test_untangle_descend(void)
{
    double ring[8][2][2], shape[8][2][2], x[2], kept[2], gradient[2];
    double start_energy, end_energy;
    int i, k, mode, folded;
    for (i = 0; i < 6; i++) {
        double a0 = 6.283185307179586 * i / 6, a1 = 6.283185307179586 * (i + 1) / 6;
        shape[i][0][0] = cos(a0);
        shape[i][0][1] = sin(a0);
        shape[i][1][0] = cos(a1);
        shape[i][1][1] = sin(a1);
        for (k = 0; k < 2; k++) {
            ring[i][k][0] = 0.4 * shape[i][k][0];
            ring[i][k][1] = 0.4 * shape[i][k][1];
        }
    }
    for (mode = 0; mode < 2; mode++) {
        const double density = mode ? 0.16 : 0.0;
        x[0] = 0.11;
        x[1] = -0.07;
        internal_untangle_descend(6, (const double (*)[2][2])ring, (const double (*)[2][2])shape, x, 0.4, 0.0, density,
                                  1, kept);
        start_energy = internal_untangle_energy(6, (const double (*)[2][2])ring, (const double (*)[2][2])shape, x, 0.0,
                                                density, gradient, NULL, &folded);
        end_energy = internal_untangle_energy(6, (const double (*)[2][2])ring, (const double (*)[2][2])shape, kept,
                                              0.0, density, gradient, NULL, &folded);
        CHECK(fabs(kept[0]) + fabs(kept[1]) < 1e-5 && end_energy < start_energy,
              "%s: a regular star's centre descends from (0.11, -0.07) to (%.3g, %.3g), energy %.6g -> %.6g",
              mode ? "smoothing" : "untangling", kept[0], kept[1], start_energy, end_energy);
    }
    /* The first triangle nearly flat at x: (x, a, b) with b a hair off the line x a. */
    x[0] = 0.0;
    x[1] = 0.0;
    ring[0][0][0] = 0.4;
    ring[0][0][1] = 0.0;
    ring[0][1][0] = 0.4;
    ring[0][1][1] = 1e-170;
    for (mode = 0; mode < 2; mode++) {
        const double density = mode ? 0.16 : 0.0;
        kept[0] = kept[1] = 12345.0;
        internal_untangle_energy(6, (const double (*)[2][2])ring, (const double (*)[2][2])shape, x, 0.0, density,
                                 gradient, NULL, &folded);
        internal_untangle_descend(6, (const double (*)[2][2])ring, (const double (*)[2][2])shape, x, 0.4, 0.0, density,
                                  mode == 0, kept);
        CHECK(!isfinite(gradient[0]) || !isfinite(gradient[1]),
              "%s: the flat triangle's gradient overflows (%g, %g), the case this test is for",
              mode ? "smoothing" : "untangling", gradient[0], gradient[1]);
        CHECK(kept[0] == x[0] && kept[1] == x[1], "%s: a star with a flat triangle keeps its centre (%g, %g)",
              mode ? "smoothing" : "untangling", kept[0], kept[1]);
    }
}

/* The area-weighted 95th percentile of the stretch (sigma1 / sigma2) of the
   triangles whose three points lie in one quad, and how many of those
   turn clockwise. */
static double same_quad_stretch_p95(const tt_mesh *mesh, const tt_surface_point *pts, int *folded, int *counted)
{
    double *stretch = (double *)malloc(sizeof(double) * (size_t)mesh->nfaces + 1);
    double *weight = (double *)malloc(sizeof(double) * (size_t)mesh->nfaces + 1), p95;
    int f, n = 0;
    *folded = 0;
    for (f = 0; f < mesh->nfaces; f++) {
        const int *t = mesh->corner_vert + 3 * f;
        const tt_surface_point *a = &pts[t[0]], *b = &pts[t[1]], *c = &pts[t[2]];
        double e1[3], e2[3], len, along[3], normal[3], across[3], P[2][2], Q[2][2], J[2][2], det, fro, root;
        int k;
        if (a->quad != b->quad || a->quad != c->quad) continue;
        for (k = 0; k < 3; k++) {
            e1[k] = (double)mesh->pos[3 * t[1] + k] - mesh->pos[3 * t[0] + k];
            e2[k] = (double)mesh->pos[3 * t[2] + k] - mesh->pos[3 * t[0] + k];
        }
        len = sqrt(e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2]);
        normal[0] = e1[1] * e2[2] - e1[2] * e2[1];
        normal[1] = e1[2] * e2[0] - e1[0] * e2[2];
        normal[2] = e1[0] * e2[1] - e1[1] * e2[0];
        for (k = 0; k < 3; k++) along[k] = e1[k] / len;
        across[0] = normal[1] * along[2] - normal[2] * along[1];
        across[1] = normal[2] * along[0] - normal[0] * along[2];
        across[2] = normal[0] * along[1] - normal[1] * along[0];
        P[0][0] = len;  /* the triangle's own edges (columns) in its plane */
        P[1][0] = 0.0;
        P[0][1] = e2[0] * along[0] + e2[1] * along[1] + e2[2] * along[2];
        P[1][1] = (e2[0] * across[0] + e2[1] * across[1] + e2[2] * across[2]) /
                  sqrt(normal[0] * normal[0] + normal[1] * normal[1] + normal[2] * normal[2]);
        Q[0][0] = b->s - a->s;
        Q[1][0] = b->t - a->t;
        Q[0][1] = c->s - a->s;
        Q[1][1] = c->t - a->t;
        det = P[0][0] * P[1][1] - P[0][1] * P[1][0];
        /* J = Q P^-1 */
        J[0][0] = (Q[0][0] * P[1][1] - Q[0][1] * P[1][0]) / det;
        J[0][1] = (Q[0][1] * P[0][0] - Q[0][0] * P[0][1]) / det;
        J[1][0] = (Q[1][0] * P[1][1] - Q[1][1] * P[1][0]) / det;
        J[1][1] = (Q[1][1] * P[0][0] - Q[1][0] * P[0][1]) / det;
        det = J[0][0] * J[1][1] - J[0][1] * J[1][0];
        if (det <= 0.0) {
            ++*folded;
            continue;
        }
        fro = J[0][0] * J[0][0] + J[0][1] * J[0][1] + J[1][0] * J[1][0] + J[1][1] * J[1][1];
        root = sqrt(fmax(0.0, fro * fro - 4.0 * det * det));
        stretch[n] = sqrt((fro + root) / fmax(fro - root, 1e-300));
        weight[n] = 0.5 * len * P[1][1];
        n++;
    }
    *counted = n;
    p95 = n ? internal_weighted_percentile(stretch, weight, n, 0.95) : 0.0;
    free(stretch);
    free(weight);
    return p95;
}

typedef struct smooth_oom_ctx {
    const tt_polycube *pc;
    const tt_mesh *mesh;
    const tt_surface_point *start;
    tt_surface_point *pts;
} smooth_oom_ctx;

static tt_result smooth_oom_call(void *ctx, const tt_allocator *al, tt_error *error)
{
    smooth_oom_ctx *c = (smooth_oom_ctx *)ctx;
    int held;
    (void)error;   /* a private helper: no tt_error */
    memcpy(c->pts, c->start, sizeof *c->pts * (size_t)c->mesh->nverts);
    return internal_polycube_smooth(c->pc, c->mesh, c->pts, NULL, al, &held) >= 0 ? TT_OK : TT_ERROR_OUT_OF_MEMORY;
}

/* A sphere on a polycube of resolution 4 is oblique to S almost
   everywhere: the projection lays it on in strips. The smoothing lowers
   the stretch's tail, folds nothing, holds few vertices (at the cones of
   S, where a star's chart is cut), and gives the same
   points whatever the executor; points thrown at random into their
   quads (the control) score far worse. */
static void test_polycube_smooth(void)
{
    tmesh m;
    tt_mesh *mesh = NULL;
    tt_surface_point *pts = NULL, *start, *other;
    tt_polycube *pc = projected_sphere(96, 48, 4, &m, &mesh, &pts);
    smooth_oom_ctx ctx;
    const tt_executor *executors[2];
    double before, after, shuffled;
    int moves, held = -1, folded_before, folded_after, folded_shuffled, counted, e, v, same = 1;
    if (!pc) { tm_free(&m); return; }
    internal_polycube_relax(pc, mesh, pts);
    start = (tt_surface_point *)malloc(sizeof *start * (size_t)mesh->nverts);
    other = (tt_surface_point *)malloc(sizeof *other * (size_t)mesh->nverts);
    memcpy(start, pts, sizeof *start * (size_t)mesh->nverts);
    before = same_quad_stretch_p95(mesh, pts, &folded_before, &counted);
    moves = internal_polycube_smooth(pc, mesh, pts, NULL, NULL, &held);
    after = same_quad_stretch_p95(mesh, pts, &folded_after, &counted);
    CHECK(moves > mesh->nverts && held <= mesh->nverts / 100 && folded_before == 0 && folded_after == 0 &&
              after < 0.95 * before && counted > mesh->nfaces / 2,
          "sphere at resolution 4: stretch p95 %.3f before smoothing, %.3f after (%d moves, %d held; folded %d, "
          "then %d, of %d triangles in one quad)", before, after, moves, held, folded_before, folded_after, counted);
    executors[0] = &g_reverse_executor;
    executors[1] = &g_thread_executor;
    for (e = 0; e < 2; e++) {
        int other_held;
        memcpy(other, start, sizeof *other * (size_t)mesh->nverts);
        internal_polycube_smooth(pc, mesh, other, executors[e], NULL, &other_held);
        for (v = 0; v < mesh->nverts; v++)
            same &= other[v].quad == pts[v].quad && other[v].s == pts[v].s && other[v].t == pts[v].t;
        same &= other_held == held;
    }
    CHECK(same, "the smoothing's points are the same with the reverse and the threaded executors");
    lcg_seed(5);
    for (v = 0; v < mesh->nverts; v++) {
        other[v] = start[v];
        other[v].s = (float)lcg_unit();
        other[v].t = (float)lcg_unit();
    }
    shuffled = same_quad_stretch_p95(mesh, other, &folded_shuffled, &counted);
    CHECK(shuffled > 3.0 * before && folded_shuffled > mesh->nfaces / 10,
          "control: points thrown at random into their quads score stretch p95 %.3f with %d folded", shuffled,
          folded_shuffled);
    ctx.pc = pc;
    ctx.mesh = mesh;
    ctx.start = start;
    ctx.pts = other;
    oom_reset();
    oom_sweep_internal("smoothing (sphere at resolution 4)", smooth_oom_call, &ctx, TT_OK);
    free(start);
    free(other);
    tt_polycube_free(pc);
    tt_mesh_free(mesh);
    free(pts);
    tm_free(&m);
}

/* A patch of points mirrored inside its quad is folded all through: no
   vertex inside it has a place of its own that unfolds its star (its ring
   is folded too), so moves one vertex at a time cannot open it. The
   untangling opens it from its rim. */
static void test_relax_untangles(void)
{
    tmesh m;
    tt_mesh *mesh = NULL;
    tt_surface_point *pts = NULL;
    tt_polycube *pc = projected_sphere(96, 48, 4, &m, &mesh, &pts);
    int *in_quad, best = -1, v, c, mirrored = 0, before = 0, after = 0;
    if (!pc) { tm_free(&m); return; }
    in_quad = (int *)calloc((size_t)pc->surface->nfaces, sizeof(int));
    for (v = 0; v < mesh->nverts; v++) in_quad[pts[v].quad]++;
    for (c = 0; c < pc->surface->nfaces; c++)
        if (best < 0 || in_quad[c] > in_quad[best]) best = c;
    /* Mirror the points near the middle of the fullest quad: s -> 1 - s about its middle line. */
    for (v = 0; v < mesh->nverts; v++)
        if (pts[v].quad == best && fabs(pts[v].s - 0.5f) < 0.3f && fabs(pts[v].t - 0.5f) < 0.3f) {
            pts[v].s = 1.0f - pts[v].s;
            mirrored++;
        }
    for (c = 0; c < mesh->ncorners; c += 3) {
        const tt_surface_point *a = &pts[mesh->corner_vert[c]], *b = &pts[mesh->corner_vert[c + 1]],
                               *d = &pts[mesh->corner_vert[c + 2]];
        if (a->quad == best && b->quad == best && d->quad == best)
            before += (b->s - a->s) * (d->t - a->t) - (b->t - a->t) * (d->s - a->s) <= 0.0f;
    }
    internal_polycube_relax(pc, mesh, pts);
    for (c = 0; c < mesh->ncorners; c += 3) {
        const tt_surface_point *a = &pts[mesh->corner_vert[c]], *b = &pts[mesh->corner_vert[c + 1]],
                               *d = &pts[mesh->corner_vert[c + 2]];
        if (a->quad == b->quad && a->quad == d->quad)
            after += (b->s - a->s) * (d->t - a->t) - (b->t - a->t) * (d->s - a->s) <= 0.0f;
    }
    CHECK(mirrored >= 20 && before >= 30 && after == 0,
          "a mirrored patch of %d points (%d triangles folded in its quad) untangled: %d triangles within one quad "
          "still folded", mirrored, before, after);
    free(in_quad);
    tt_polycube_free(pc);
    tt_mesh_free(mesh);
    free(pts);
    tm_free(&m);
}

static int failed_edges(const tt_polycube *pc, const tt_mesh *mesh, const tt_surface_point *pts)
{
    tt_polycube_edges *edges = NULL;
    int n;
    if (tt_polycube_trace_edges(pc, mesh, pts, mesh->nverts, NULL, NULL, &edges, NULL) != TT_OK) return -1;
    n = edges->nfailed;
    tt_polycube_edges_free(edges);
    return n;
}

typedef struct reseat_oom_ctx {
    const tt_polycube *pc;
    const tt_mesh *mesh;
    const tt_surface_point *start;
    tt_surface_point *pts;
    unsigned char *moved;
} reseat_oom_ctx;

static tt_result reseat_oom_call(void *ctx, const tt_allocator *al, tt_error *error)
{
    reseat_oom_ctx *c = (reseat_oom_ctx *)ctx;
    (void)error;   /* a private helper: no tt_error */
    memcpy(c->pts, c->start, sizeof *c->pts * (size_t)c->mesh->nverts);
    memset(c->moved, 0, (size_t)c->mesh->nverts);
    return internal_polycube_reseat_calls(c->pc, c->mesh, c->pts, c->moved, al, 1, -1, NULL) == 1
               ? TT_OK : TT_ERROR_OUT_OF_MEMORY;
}

/* A vertex seated on the far side of S (as the closest point does across a
   part about a cube thick) has edges with no path on S; re-seating puts it
   back on its neighbours' sheet, next to its own position, and moves
   nothing else. */
static void test_reseat(void)
{
    tmesh m;
    tt_mesh *mesh = NULL;
    tt_surface_point *pts = NULL;
    tt_polycube *pc = projected_sphere(48, 24, 6, &m, &mesh, &pts);
    unsigned char *moved;
    tt_surface_point *start, *copy;
    reseat_oom_ctx ctx;
    int v, far = 0, near = 0, before, after, reseated, others = 0, a;
    double at[3], d2 = 0.0;
    if (!pc) { tm_free(&m); return; }
    for (v = 0; v < mesh->nverts; v++) {
        if (mesh->pos[3 * v] > mesh->pos[3 * near]) near = v;
        if (mesh->pos[3 * v] < mesh->pos[3 * far]) far = v;
    }
    CHECK(failed_edges(pc, mesh, pts) == 0, "the sphere's edges all trace before the test moves a point");
    /* The vertex at +x seated next to the one at -x. */
    pts[near] = pts[far];
    pts[near].s = pts[far].s < 0.5f ? pts[far].s + 0.05f : pts[far].s - 0.05f;
    before = failed_edges(pc, mesh, pts);
    moved = (unsigned char *)calloc((size_t)mesh->nverts, 1);
    start = (tt_surface_point *)malloc(sizeof *start * (size_t)mesh->nverts);
    copy = (tt_surface_point *)malloc(sizeof *copy * (size_t)mesh->nverts);
    memcpy(start, pts, sizeof *start * (size_t)mesh->nverts);
    reseated = internal_polycube_reseat_calls(pc, mesh, pts, moved, NULL, 1, -1, NULL);
    after = failed_edges(pc, mesh, pts);
    for (v = 0; v < mesh->nverts; v++) others += moved[v] && v != near;
    tt_polycube_point_position(pc, pts[near], at);
    for (a = 0; a < 3; a++) d2 += (at[a] - mesh->pos[3 * near + a]) * (at[a] - mesh->pos[3 * near + a]);
    CHECK(before >= 4 && reseated == 1 && moved[near] && others == 0 && after == 0 && sqrt(d2) <= pc->h,
          "a vertex seated across the sphere (%d edges with no path) re-seated: %d moved (%d others), %d edges "
          "fail after, %.3g cubes from its position", before, reseated, others, after, sqrt(d2) / pc->h);
    ctx.pc = pc;
    ctx.mesh = mesh;
    ctx.start = start;
    ctx.pts = copy;
    ctx.moved = moved;
    oom_reset();
    oom_sweep_internal("re-seating (sphere at resolution 6, one vertex across)", reseat_oom_call, &ctx, TT_OK);
    /* The re-seatings of one mapping remember who stayed: with the edges as
       first traced, the moved vertex is tried again (it moved) and stays;
       a third call then tries nothing, unless a neighbour of it moved. */
    {
        double spent[3];
        int neighbour = -1, f, k, calls, nudge;
        for (f = 0; f < mesh->nfaces && neighbour < 0; f++)
            for (k = 0; k < 3; k++)
                if (mesh->corner_vert[3 * f + k] == near) neighbour = mesh->corner_vert[3 * f + (k + 1) % 3];
        for (nudge = 0; nudge < 2; nudge++) {
            memcpy(copy, start, sizeof *copy * (size_t)mesh->nverts);
            memset(moved, 0, (size_t)mesh->nverts);
            calls = internal_polycube_reseat_calls(pc, mesh, copy, moved, NULL, 3, nudge ? neighbour : -1, spent);
            CHECK(calls == 1 && spent[0] > 0.0 && spent[1] > 0.0 && (nudge ? spent[2] > 0.0 : spent[2] == 0.0),
                  "re-seating three times%s: %d moves, path-search steps %g, %g, %g", nudge ?
                  " with a neighbour nudged before the third" : "", calls, spent[0], spent[1], spent[2]);
        }
    }
    free(start);
    free(copy);
    free(moved);
    tt_polycube_free(pc);
    tt_mesh_free(mesh);
    free(pts);
    tm_free(&m);
}

/* As the library reads the paper's polycube for an open mesh: an open mesh whose holes are narrower
   than a couple of cubes (a scan missing a few faces) is sealed, its
   polycube solid like the closed mesh's, one sheet instead of a shell;
   a bowl (a hemisphere, its rim a whole side) is not, nor is a closed
   mesh touched. */
static void test_seal(void)
{
    const double centre[3] = {0.0, 0.0, 0.0};
    int shape;
    tt_polycube_report reports[3];
    tt_polycube_map_report maps[3];
    for (shape = 0; shape < 3; shape++) {
        tmesh full, m;
        tt_mesh *mesh = NULL;
        tt_polycube *pc = NULL;
        tt_polycube_options o;
        tt_polycube_mapping *map = NULL;
        tt_error err;
        int i;
        memset(&full, 0, sizeof full);
        memset(&m, 0, sizeof m);
        make_sphere(&full, 48, 32, 1.0, centre, shape == 2);
        /* shape 1: the sphere without the faces at its top pole's first ring, a hole 0.39 wide (3 cubes). */
        for (i = 0; i < full.nv; i++) tm_vert(&m, full.pos[3 * i], full.pos[3 * i + 1], full.pos[3 * i + 2]);
        for (i = 0; i < full.nf; i++) {
            const int *v = full.idx + 3 * i;
            if (shape == 1 && (v[0] <= 48 || v[1] <= 48 || v[2] <= 48)) continue;
            tm_tri(&m, v[0], v[1], v[2]);
        }
        memset(&o, 0, sizeof o);
        o.resolution = 16;
        memset(&reports[shape], 0, sizeof reports[shape]);
        memset(&maps[shape], 0, sizeof maps[shape]);
        if (build(&m, 0, &mesh, &err) == TT_OK && tt_polycube_build(mesh, &o, NULL, &pc, &reports[shape], &err) == TT_OK)
            tt_polycube_map(pc, mesh, NULL, NULL, &map, &maps[shape], &err);
        else
            CHECK(0, "sealing test mesh %d builds: %s", shape, err.message);
        tt_polycube_mapping_free(map);
        tt_polycube_free(pc);
        tt_mesh_free(mesh);
        tm_free(&m);
        tm_free(&full);
    }
    CHECK(reports[0].sealed == 0 && reports[1].sealed > 0 && reports[1].quads == reports[0].quads &&
              abs(reports[1].cubes - reports[0].cubes) <= reports[0].cubes / 100 && maps[1].failed_edges == 0 &&
              maps[1].fallback_triangles <= maps[1].triangles / 1000,
          "a sphere with a hole 3 cubes wide is sealed (%d cubes) into the closed sphere's polycube (%d and %d "
          "quads, %d and %d cubes), mapped with %d failed edges and %d fallbacks of %d", reports[1].sealed,
          reports[1].quads, reports[0].quads, reports[1].cubes, reports[0].cubes, maps[1].failed_edges,
          maps[1].fallback_triangles, maps[1].triangles);
    CHECK(reports[2].sealed == 0, "a hemisphere (a bowl) is not sealed (%d cubes)", reports[2].sealed);
}

/* In short: small random closed meshes (bumpy spheres, turned and
   scaled at random) at random resolutions map without a crack (closed
   strict output), with their area, every corner in one quad, and no
   sliver. */
static void test_map_random(void)
{
    int round, bad = 0, fallbacks = 0, triangles = 0, flipped = 0, collapsed = 0, slivers = 0;
    lcg_seed(4242);
    for (round = 0; round < 24; round++) {
        const double centre[3] = {0.0, 0.0, 0.0};
        tmesh m;
        tt_mesh *mesh;
        tt_polycube *pc;
        tt_polycube_map_report rep;
        tt_polycube_mapping *map;
        double a = 6.283 * lcg_unit(), b = 6.283 * lcg_unit(), scale = 0.01 + 100.0 * lcg_unit();
        int i, resolution = 1 + lcg_below(14);
        memset(&m, 0, sizeof m);
        make_sphere(&m, 8 + lcg_below(24), 4 + lcg_below(12), 1.0, centre, 0);
        for (i = 0; i < m.nv; i++) {
            double x = m.pos[3 * i], y = m.pos[3 * i + 1], z = m.pos[3 * i + 2], bump = 1.0 + 0.2 * lcg_unit();
            double x1 = cos(a) * x - sin(a) * y, y1 = sin(a) * x + cos(a) * y;
            double y2 = cos(b) * y1 - sin(b) * z, z2 = sin(b) * y1 + cos(b) * z;
            m.pos[3 * i] = (float)(scale * bump * x1);
            m.pos[3 * i + 1] = (float)(scale * bump * y2);
            m.pos[3 * i + 2] = (float)(scale * bump * z2);
        }
        map = mapped(&m, resolution, 0, 0.0, &pc, &mesh, &rep);
        if (map) {
            mapping_check c = check_mapping(pc, mesh, map);
            if (!mapping_sound(&c)) {
                bad++;
                printf("     random mesh %d (resolution %d): %d off, %d points, area error %.2g, strict %s, %d open\n",
                       round, resolution, c.off_surface, c.bad_points, c.area_error, c.strict_fails ? "fails" : "holds",
                       c.open_edges);
            }
            fallbacks += rep.fallback_triangles;
            triangles += rep.triangles;
            slivers += mapping_slivers(map, 1e-6 * mapping_mean_area(map));
            flipped += rep.flipped;
            collapsed += rep.collapsed;
        } else {
            bad++;
        }
        tt_polycube_mapping_free(map);
        tt_polycube_free(pc);
        tt_mesh_free(mesh);
        tm_free(&m);
    }
    printf("     24 random meshes: %d of %d triangles left to the fallback, %d output triangles collapsed, %d "
           "slivers\n", fallbacks, triangles, collapsed, slivers);
    CHECK(bad == 0, "24 random bumpy spheres at resolutions 1-14: %d not watertight, area-true and in one quad "
                    "per triangle", bad);
    /* A model edge passing a hair from a corner of S cut a sliver off there (one here before the edges were
       turned through or away from such corners). */
    CHECK(slivers == 0, "24 random bumpy spheres: %d output triangles under a millionth of the mean area", slivers);
    /* No flipped triangle: the fallback's pieces too keep their turn (a clamped projection folds some of these). */
    CHECK(fallbacks > 0 && flipped == 0, "24 random bumpy spheres: %d flipped output triangles (0 expected), with %d "
          "triangles left to the fallback", flipped, fallbacks);
}

/* The executor (tt_polycube_map_options::executor) runs the projection,
   the relaxation's groups of vertices, the tracing and the split as
   tasks: a bumpy sphere, big enough for several tasks of each (and two
   batches of the split) and with folds to untangle, maps to the same
   arrays, bit for bit, and the same report, serially, with the tasks in
   reverse order and on two threads. */
static void test_map_executors(void)
{
    const double centre[3] = {0.0, 0.0, 0.0};
    const tt_executor *executors[2];
    tmesh m;
    tt_mesh *mesh = NULL;
    tt_polycube *pc = NULL;
    tt_polycube_options o;
    tt_polycube_map_options mo;
    tt_polycube_map_report serial_report, report;
    tt_polycube_mapping *serial = NULL, *map = NULL;
    tt_polycube_report rep;
    tt_error err;
    int i, k;
    executors[0] = &g_reverse_executor;
    executors[1] = &g_thread_executor;
    memset(&m, 0, sizeof m);
    lcg_seed(515);
    make_sphere(&m, 96, 48, 1.0, centre, 0);
    for (i = 0; i < m.nv; i++) {
        /* Bumps a few triangles wide: the projection folds some of them over. */
        double bump = 1.0 + 0.06 * sin(23.0 * m.pos[3 * i]) * sin(19.0 * m.pos[3 * i + 1]) + 0.02 * lcg_unit();
        for (k = 0; k < 3; k++) m.pos[3 * i + k] = (float)(bump * m.pos[3 * i + k]);
    }
    memset(&o, 0, sizeof o);
    o.resolution = 12;
    if (build(&m, 0, &mesh, &err) != TT_OK || tt_polycube_build(mesh, &o, NULL, &pc, &rep, &err) != TT_OK) {
        CHECK(0, "the bumpy sphere builds: %s", err.message);
        tt_mesh_free(mesh);
        tm_free(&m);
        return;
    }
    memset(&mo, 0, sizeof mo);
    mo.max_edge = 0.25 * pc->h;
    if (tt_polycube_map(pc, mesh, &mo, NULL, &serial, &serial_report, &err) != TT_OK) {
        CHECK(0, "the bumpy sphere maps: %s", err.message);
    } else {
        for (k = 0; k < 2; k++) {
            mo.executor = executors[k];
            CHECK(tt_polycube_map(pc, mesh, &mo, NULL, &map, &report, &err) == TT_OK &&
                      map->nverts == serial->nverts && map->ntriangles == serial->ntriangles &&
                      memcmp(map->positions, serial->positions, sizeof(float) * 3 * (size_t)map->nverts) == 0 &&
                      memcmp(map->source, serial->source, sizeof(int) * 3 * (size_t)map->nverts) == 0 &&
                      memcmp(map->weights, serial->weights, sizeof(float) * 3 * (size_t)map->nverts) == 0 &&
                      memcmp(map->triangles, serial->triangles, sizeof(int) * 3 * (size_t)map->ntriangles) == 0 &&
                      memcmp(map->triangle_face, serial->triangle_face, sizeof(int) * (size_t)map->ntriangles) == 0 &&
                      memcmp(map->corner_points, serial->corner_points,
                             sizeof(tt_surface_point) * 3 * (size_t)map->ntriangles) == 0 &&
                      memcmp(&report, &serial_report, sizeof report) == 0,
                  "bumpy sphere (%d refined triangles, %d relaxation moves, %d fallbacks) mapped %s: the serial "
                  "mapping bit for bit, the same report",
                  serial_report.triangles, serial_report.relaxed, serial_report.fallback_triangles,
                  k ? "on two threads" : "with the tasks in reverse order");
            tt_polycube_mapping_free(map);
            map = NULL;
        }
        CHECK(serial_report.triangles > 32 * 1024 && serial_report.relaxed > 100,
              "the executor test mesh has %d refined triangles (two batches of the split need more than 32768) "
              "and %d relaxation moves", serial_report.triangles, serial_report.relaxed);
    }
    tt_polycube_mapping_free(serial);
    tt_polycube_free(pc);
    tt_mesh_free(mesh);
    tm_free(&m);
}

/* A flat square of two triangles at resolution 1: a range of edges whose
   traces cross nothing keeps a NULL crossing array, and gathering the
   ranges once computed NULL + 0 (undefined behaviour; clang's UBSan stops
   there, gcc's does not flag it, so build this with clang to see it fail
   before the fix). Found by tests/fuzz/fuzz_polycube.c on its empty input. */
static void test_map_flat_square_coarse(void)
{
    float pos[12] = {-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0};
    int idx[6] = {0, 1, 2, 0, 2, 3};
    tt_mesh_desc d;
    tt_mesh *mesh = NULL;
    tt_polycube *pc = NULL;
    tt_polycube_options po;
    tt_polycube_mapping *map = NULL;
    tt_polycube_map_report report;
    tt_error err;
    tt_result r;
    memset(&d, 0, sizeof d);
    memset(&po, 0, sizeof po);
    d.positions = pos;
    d.nverts = 4;
    d.indices = idx;
    d.nfaces = 2;
    d.fixed_face_size = 3;
    po.resolution = 1;
    if (tt_mesh_build(&d, NULL, &mesh, &err) != TT_OK || tt_polycube_build(mesh, &po, NULL, &pc, NULL, &err) != TT_OK) {
        CHECK(0, "the flat square builds: %s", err.message);
    } else {
        r = tt_polycube_map(pc, mesh, NULL, NULL, &map, &report, &err);
        CHECK(r == TT_OK && map && map->ntriangles >= 2 && report.triangles >= 2,
              "a flat square at resolution 1 maps (got %d, %d triangles: %s)", (int)r, map ? map->ntriangles : 0,
              r == TT_OK ? "" : err.message);
    }
    tt_polycube_mapping_free(map);
    tt_polycube_free(pc);
    tt_mesh_free(mesh);
}

/* A closed pair of triangles on the same three corners (a "pillow") has no
   inside: refused up front, naming both faces, rather than refined into
   edges with four triangles. The tetrahedron beside it maps on its own. */
static void test_map_pillow(void)
{
    int with_pillow;
    for (with_pillow = 0; with_pillow < 2; with_pillow++) {
        tmesh m;
        tt_mesh *mesh = NULL;
        tt_polycube *pc = NULL;
        tt_polycube_options po;
        tt_polycube_mapping *map = NULL;
        tt_error err;
        tt_result r;
        memset(&m, 0, sizeof m);
        memset(&po, 0, sizeof po);
        make_tetra(&m, 0.0);   /* faces 0..3 */
        if (with_pillow) {
            const int a = tm_vert(&m, 3, 0, 0), b = tm_vert(&m, 4, 0, 0), c = tm_vert(&m, 3, 1, 0);
            tm_tri(&m, a, b, c);   /* faces 4 and 5: the same corners, facing away from each other */
            tm_tri(&m, a, c, b);
        }
        po.resolution = 4;
        if (build(&m, 0, &mesh, &err) != TT_OK || tt_polycube_build(mesh, &po, NULL, &pc, NULL, &err) != TT_OK) {
            CHECK(0, "the tetrahedron%s builds: %s", with_pillow ? " and pillow" : "", err.message);
        } else {
            r = tt_polycube_map(pc, mesh, NULL, NULL, &map, NULL, &err);
            if (with_pillow)
                CHECK(r == TT_ERROR_INVALID_ARGUMENT && map == NULL && err.result == r && err.face == 4 &&
                          err.other_face == 5 && strstr(err.message, "faces 4 and 5 have the same three corners"),
                      "a pillow beside a tetrahedron: invalid, naming faces 4 and 5 (got %d, faces %d %d: %s)", (int)r,
                      err.face, err.other_face, err.message);
            else
                CHECK(r == TT_OK && map != NULL, "the tetrahedron alone maps (got %d: %s)", (int)r,
                      r == TT_OK ? "" : err.message);
        }
        tt_polycube_mapping_free(map);
        tt_polycube_free(pc);
        tt_mesh_free(mesh);
        tm_free(&m);
    }
}

/* Two vertices 4e-9 apart (a strict build accepts their sliver
   triangles): the refinement's midpoints of their long edges round to
   one float, and the refined triangle between them has no area. The
   mapping goes on (found by fuzz_polycube: it returned
   TT_ERROR_ZERO_AREA_FACE naming a refined face the caller never had). */
static void test_map_refined_sliver(void)
{
    static const float positions[9][3] = {
        {-0.0617647059f, -0.247058824f, -0.24509804f}, {0.0622548983f, -0.250980407f, -0.250980407f},
        {0.205392152f, -0.250980407f, -0.14705883f},   {0.062254902f, 0.249019593f, -0.250980407f},
        {0.0622548983f, 0.249019593f, -0.250980407f},  {0.187254906f, 0.249019593f, -0.250980407f},
        {-0.0627451017f, 0.749019623f, -0.250980407f}, {0.0622548983f, 0.749019623f, -0.250980407f},
        {0.187254906f, 0.749019623f, -0.250980407f}};
    static const int triangles[8][3] = {{0, 1, 4}, {0, 4, 3}, {1, 2, 5}, {1, 5, 4},
                                        {3, 4, 7}, {3, 7, 6}, {4, 5, 8}, {4, 8, 7}};
    tmesh m;
    tt_mesh *mesh = NULL;
    tt_polycube *pc = NULL;
    tt_polycube_options po;
    tt_polycube_map_options mo;
    tt_polycube_mapping *map = NULL;
    tt_polycube_map_report rep;
    tt_error err;
    tt_result r;
    int i;
    memset(&m, 0, sizeof m);
    memset(&po, 0, sizeof po);
    for (i = 0; i < 9; i++) tm_vert(&m, positions[i][0], positions[i][1], positions[i][2]);
    for (i = 0; i < 8; i++) tm_tri(&m, triangles[i][0], triangles[i][1], triangles[i][2]);
    po.cube_size = 1.0;
    memset(&mo, 0, sizeof mo);
    mo.max_edge = 0.5;  /* halves the long edges whatever the default */
    if (build(&m, 0, &mesh, &err) != TT_OK || tt_polycube_build(mesh, &po, NULL, &pc, NULL, &err) != TT_OK) {
        CHECK(0, "the strip with a sliver builds: %s", err.message);
    } else {
        r = tt_polycube_map(pc, mesh, &mo, NULL, &map, &rep, &err);
        CHECK(r == TT_OK && map != NULL && rep.triangles > mesh->nfaces,
              "a sliver whose refined triangles lose their area maps (got %d: %s; %d refined triangles)", (int)r,
              r == TT_OK ? "" : err.message, r == TT_OK ? rep.triangles : 0);
    }
    tt_polycube_mapping_free(map);
    tt_polycube_free(pc);
    tt_mesh_free(mesh);
    tm_free(&m);
}

/* A split vertex lies on its input triangle: interpolating corners at
   FLT_MAX with weights that round past 1 stays FLT_MAX, not infinity
   (found by fuzz_polycube: an output position of inf), and an ordinary
   interpolation is exact. */
static void test_split_vertex_data(void)
{
    tmesh m;
    tt_mesh *mesh = NULL;
    tt_error err;
    const int source[3] = {0, 1, 2};
    const double past_one[3] = {0.5000001, 0.5, 0.0}, inside[3] = {0.25, 0.25, 0.5};
    float position[3], weight[3];
    memset(&m, 0, sizeof m);
    tm_vert(&m, FLT_MAX, FLT_MAX, 0.0);
    tm_vert(&m, FLT_MAX, 0.0, FLT_MAX);
    tm_vert(&m, 0.0, 1.0, 2.0);
    tm_tri(&m, 0, 1, 2);
    if (build(&m, 0, &mesh, &err) != TT_OK) {
        CHECK(0, "the triangle at FLT_MAX builds: %s", err.message);
        tm_free(&m);
        return;
    }
    internal_split_vertex_data(mesh, source, past_one, position, weight);
    CHECK(position[0] == FLT_MAX && isfinite(position[1]) && isfinite(position[2]),
          "weights past 1 between corners at FLT_MAX: (%g, %g, %g)", position[0], position[1], position[2]);
    internal_split_vertex_data(mesh, source, inside, position, weight);
    CHECK(position[0] == (float)(0.5 * FLT_MAX) && position[1] == (float)(0.25 * FLT_MAX + 0.5) &&
              position[2] == (float)(0.25 * FLT_MAX + 1.0) && weight[2] == 0.5f,
          "an inside point interpolates: (%g, %g, %g)", position[0], position[1], position[2]);
    /* A weight a rounding below 0 (found by fuzz_polycube on a split edge)
       is 0, the others summing to 1: the mapping's weights stay in [0, 1]. */
    {
        const double below[3] = {1.0 + 4.55e-17, -4.55e-17, 0.0}, outside[3] = {0.6, 0.5, -0.1};
        internal_split_vertex_data(mesh, source, below, position, weight);
        CHECK(weight[0] == 1.0f && weight[1] == 0.0f && !signbit(weight[1]) && weight[2] == 0.0f,
              "weights (1 + 4.55e-17, -4.55e-17, 0) give (%.9g, %.9g, %.9g)", (double)weight[0], (double)weight[1],
              (double)weight[2]);
        internal_split_vertex_data(mesh, source, outside, position, weight);
        CHECK(fabs(weight[0] - 0.6f / 1.1f) < 1e-7 && fabs(weight[1] - 0.5f / 1.1f) < 1e-7 && weight[2] == 0.0f,
              "weights (0.6, 0.5, -0.1) give (%.9g, %.9g, %.9g): onto the triangle, summing to 1", (double)weight[0],
              (double)weight[1], (double)weight[2]);
    }
    tt_mesh_free(mesh);
    tm_free(&m);
}

void run_polycube_tests(void)
{
    RUN(test_masks);
    RUN(test_voxelize);
    RUN(test_cube_block);
    RUN(test_unions);
    RUN(test_contacts);
    RUN(test_torus);
    RUN(test_open_and_flat);
    RUN(test_correction);
    RUN(test_orientation);
    RUN(test_edge_colors);
    RUN(test_wang_tiling);
    RUN(test_errors);
    RUN(test_project_cube);
    RUN(test_project_sphere);
    RUN(test_project_thin_plate);
    RUN(test_project_open);
    RUN(test_polycube_auto_resolution);
    RUN(test_project_determinism_and_errors);
    RUN(test_unfold);
    RUN(test_edges_cube);
    RUN(test_edges_sphere);
    RUN(test_edges_from_corner);
    RUN(test_relax_kernel);
    RUN(test_untangle_energy);
    RUN(test_relax_untangles);
    RUN(test_smooth_energy);
    RUN(test_untangle_descend);
    RUN(test_polycube_smooth);
    RUN(test_reseat);
    RUN(test_seal);
    RUN(test_edges_determinism_and_errors);
    RUN(test_map_cube);
    RUN(test_map_sphere);
    RUN(test_map_refine_where_needed);
    RUN(test_map_merge);
    RUN(test_map_unpinch);
    RUN(test_map_uvs_and_seams);
    RUN(test_map_uvs_upright);
    RUN(test_orient_upright);
    RUN(test_map_determinism_and_errors);
    RUN(test_map_stretch_floor);
    RUN(test_map_thin_plate);
    RUN(test_map_open_and_messy);
    RUN(test_map_flat_square_coarse);
    RUN(test_map_pillow);
    RUN(test_map_refined_sliver);
    RUN(test_split_vertex_data);
    RUN(test_map_random);
    RUN(test_map_executors);
}
