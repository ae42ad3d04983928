/* tests/test_7_lapped.c - unit tests for section 7 of tiledtex.h: the
   tangent field, texture patches, the paste loop, patch hulls, measuring, atlas
   packing and baking. Run by run_lapped_tests() (tests/test_common.c calls it).
   */
#include "test_common.h"

#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The longest run of decimal digits in s: error messages print numbers
   compactly (%g), so no run is longer than 12. */
static int longest_digit_run(const char *s)
{
    int best = 0, run = 0;
    for (; *s; s++) {
        run = (*s >= '0' && *s <= '9') ? run + 1 : 0;
        if (run > best) best = run;
    }
    return best;
}

/* ------------------------------------------------------------------------ */
/* 7. Lapped textures: the tangent field                                    */
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

/* Faces tilted 30 degrees or more from facing up (|projected up| >= 0.5,
   where up decides the direction) must point along up projected on the
   face, within 1 degree. Returns how many faces up does not decide. */
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
        if (sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]) < 0.5) { perpendicular++; continue; }
        ang = fv_angle(a, p);
        if (!(ang < 3.14159265358979323846 / 180.0)) {
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
    CHECK(tt_tangent_field(mesh, &opt, NULL, v, &err) == TT_OK, "sphere field: %s", err.message);
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
    CHECK(tt_tangent_field(mesh, NULL, NULL, v, &err) == TT_OK, "NULL options: %s", err.message);
    check_field_plane_length(mesh, v, TT_DEFAULT_FIELD_SCALE * diag, "sphere, NULL options (default scale)");
    /* A tilted up vector, not unit length: only its direction counts. */
    opt.up[0] = 0.6f; opt.up[1] = 2.0f; opt.up[2] = -0.9f;
    CHECK(tt_tangent_field(mesh, &opt, NULL, v, &err) == TT_OK, "tilted up: %s", err.message);
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
    CHECK(tt_tangent_field(mesh, &opt, NULL, v, &err) == TT_OK, "torus field: %s", err.message);
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
    CHECK(tt_tangent_field(mesh, &opt, NULL, v, &err) == TT_OK, "grid field: %s", err.message);
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

/* Surfaces facing up: up decides no face's direction, so the field is the
   tie axis (x for up = +z) where nothing else reaches, and smooth. */
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
    CHECK(tt_tangent_field(mesh, &opt, NULL, v, &err) == TT_OK, "flat grid facing up: %s", err.message);
    for (f = 0; f < mesh->nfaces; f++)
        if (!near(v[3 * f], 1.0, 1e-6) || !near(v[3 * f + 1], 0.0, 1e-6) || !near(v[3 * f + 2], 0.0, 1e-6)) bad++;
    CHECK(bad == 0, "flat grid facing up: %d faces not (1, 0, 0) (the tie axis)", bad);
    free(v);
    tt_mesh_free(mesh);
    tm_free(&m);

    /* A gentle dome facing up (normals within ~8 degrees of +z, where up hardly decides): the field must stay
       tangent, keep the scale and vary slowly. */
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
    CHECK(tt_tangent_field(mesh, &opt, NULL, v, &err) == TT_OK, "dome facing up: %s", err.message);
    check_field_plane_length(mesh, v, 1.0, "dome facing up");
    CHECK(field_max_neighbour_angle(mesh, v) < 0.05, "dome facing up: neighbouring vectors differ by %g rad",
          field_max_neighbour_angle(mesh, v));
    /* Determinism: the same call gives the same bits. */
    CHECK(tt_tangent_field(mesh, &opt, NULL, w, &err) == TT_OK, "dome again: %s", err.message);
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
    CHECK(tt_tangent_field(mesh, &opt, NULL, v, &err) == TT_OK, "grid + torus + sliver: %s", err.message);
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
    CHECK(tt_tangent_field(mesh, &opt, NULL, v, &err) == TT_OK, "grid, one constraint: %s", err.message);
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
    CHECK(tt_tangent_field(mesh, &opt, NULL, v, &err) == TT_OK, "torus, constraints: %s", err.message);
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
    CHECK(tt_tangent_field(mesh, &opt, NULL, v, &err) == TT_OK, "grid + torus, constraint: %s", err.message);
    bad = 0;
    for (f = 0; f < 9; f++)
        if (!near(v[3 * f], 0.5, 1e-6) || !near(v[3 * f + 1], 0.0, 1e-6) || !near(v[3 * f + 2], 0.0, 1e-6)) bad++;
    CHECK(bad == 0, "constrained grid: %d faces differ from (0.5, 0, 0)", bad);
    {
        /* The torus alone, without constraints: the same field. */
        tmesh alone;
        tt_mesh *torus = NULL;
        float *w;
        double worst = 0.0;
        memset(&alone, 0, sizeof alone);
        make_torus(&alone, 12, 8, 3.0, 1.0);
        CHECK(build(&alone, 0, &torus, &err) == TT_OK, "torus builds: %s", err.message);
        w = (float *)malloc(sizeof(float) * 3 * (size_t)torus->nfaces);
        opt.constraints = NULL;
        opt.nconstraints = 0;
        CHECK(tt_tangent_field(torus, &opt, NULL, w, &err) == TT_OK, "torus alone: %s", err.message);
        bad = 0;
        for (f = 9; f < mesh->nfaces; f++) {
            double a[3], b[3], angle;
            int axis;
            if (!near(fv_len(v + 3 * f), 0.7, 1e-5)) bad++;
            for (axis = 0; axis < 3; axis++) {
                a[axis] = v[3 * f + axis];
                b[axis] = w[3 * (f - 9) + axis];
            }
            angle = fv_angle(a, b);
            if (angle > worst) worst = angle;
        }
        CHECK(bad == 0, "unconstrained torus: %d faces without the scale 0.7", bad);
        CHECK(worst < 1e-4, "the torus beside a constrained grid takes the default field (%g rad from it at most)",
              worst);
        free(w);
        tt_mesh_free(torus);
        tm_free(&alone);
    }
    free(v);
    tt_mesh_free(mesh);
    tm_free(&m);
}

/* Length of the global up (unit) projected on face f's plane: about 1 on
   walls, about 0 where the face looks up or down. */
static double field_projected_up(const tt_mesh *mesh, int f, const double up[3], double projected[3])
{
    float nrm[3];
    double d = 0.0;
    int k;
    tt_face_normal(mesh, f, nrm);
    for (k = 0; k < 3; k++) d += up[k] * nrm[k];
    for (k = 0; k < 3; k++) projected[k] = up[k] - d * nrm[k];
    return sqrt(projected[0] * projected[0] + projected[1] * projected[1] + projected[2] * projected[2]);
}

/* Where up is strong (walls: projected up at least this long) the texture
   should follow it; below, only smoothness counts (tops, bottoms). */
#define FIELD_WALL 0.7

/* Mean angle (degrees) the field turns across interior edges: each
   neighbour's vector carried into the face's plane by the rotation about
   their shared edge (parallel transport), every edge seen from both sides.
   With up given, only edges between two faces off the walls (projected up
   shorter than FIELD_WALL): the tops' smoothness. */
static double field_mean_turn(const tt_mesh *mesh, const float *v, const double *up)
{
    double sum = 0.0, unused[3];
    int c, count = 0;
    for (c = 0; c < mesh->ncorners; c++) {
        int f = mesh->corner_face[c], g, k, next = c + 1 < mesh->face_start[f + 1] ? c + 1 : mesh->face_start[f];
        float nf[3], ng[3];
        double e[3], le = 0.0, bf[3], bg[3], lf = 0.0, lg = 0.0, along, across, carried[3], a[3];
        if (mesh->twin[c] < 0) continue;
        g = mesh->corner_face[mesh->twin[c]];
        if (up && (field_projected_up(mesh, f, up, unused) >= FIELD_WALL ||
                   field_projected_up(mesh, g, up, unused) >= FIELD_WALL))
            continue;
        tt_face_normal(mesh, f, nf);
        tt_face_normal(mesh, g, ng);
        for (k = 0; k < 3; k++) {
            e[k] = mesh->pos[3 * mesh->corner_vert[next] + k] - mesh->pos[3 * mesh->corner_vert[c] + k];
            le += e[k] * e[k];
        }
        le = sqrt(le);
        for (k = 0; k < 3; k++) e[k] /= le;
        /* b = n x e in each face: the direction across the edge. */
        bf[0] = nf[1] * e[2] - nf[2] * e[1]; bf[1] = nf[2] * e[0] - nf[0] * e[2]; bf[2] = nf[0] * e[1] - nf[1] * e[0];
        bg[0] = ng[1] * e[2] - ng[2] * e[1]; bg[1] = ng[2] * e[0] - ng[0] * e[2]; bg[2] = ng[0] * e[1] - ng[1] * e[0];
        /* A bent quad's edge leaves its plane a little: b made unit all the same. */
        for (k = 0; k < 3; k++) {
            lf += bf[k] * bf[k];
            lg += bg[k] * bg[k];
        }
        for (k = 0; k < 3; k++) {
            bf[k] /= sqrt(lf);
            bg[k] /= sqrt(lg);
        }
        along = across = 0.0;
        for (k = 0; k < 3; k++) {
            along += v[3 * g + k] * e[k];
            across += v[3 * g + k] * bg[k];
        }
        for (k = 0; k < 3; k++) {
            carried[k] = along * e[k] + across * bf[k];
            a[k] = v[3 * f + k];
        }
        sum += fv_angle(a, carried) * 180.0 / 3.14159265358979323846;
        count++;
    }
    return count ? sum / count : 0.0;
}

static int compare_doubles(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

/* On the walls (projected up at least FIELD_WALL long): the mean and the
   90th percentile of the angle (degrees) between each face's vector and
   the projected up. Returns the number of wall faces. */
static int field_wall_angles(const tt_mesh *mesh, const float *v, const double up[3], double *mean, double *p90)
{
    double *angle = (double *)malloc(sizeof(double) * (size_t)mesh->nfaces), sum = 0.0;
    int f, k, n = 0;
    for (f = 0; f < mesh->nfaces; f++) {
        double p[3], a[3];
        if (field_projected_up(mesh, f, up, p) < FIELD_WALL) continue;
        for (k = 0; k < 3; k++) a[k] = v[3 * f + k];
        angle[n] = fv_angle(a, p) * 180.0 / 3.14159265358979323846;
        sum += angle[n++];
    }
    qsort(angle, (size_t)n, sizeof *angle, compare_doubles);
    *mean = n ? sum / n : 0.0;
    *p90 = n ? angle[(int)(0.9 * (n - 1))] : 0.0;
    free(angle);
    return n;
}

/* A bumpy sphere of triangles (a bent quad has no one plane to carry a
   vector in), radius 1 with 4 % noise, its poles on z (up = +y makes walls
   and tops). */
static void make_bumpy_sphere(tmesh *m)
{
    tmesh quads;
    int corner = 0, i, f, k;
    memset(&quads, 0, sizeof quads);
    make_field_sphere(&quads, 40, 64, 1.0);
    memset(m, 0, sizeof *m);
    lcg_seed(7);
    for (i = 0; i < quads.nv; i++) {
        double r = 1.0 + 0.04 * (lcg_unit() - 0.5);
        tm_vert(m, quads.pos[3 * i] * r, quads.pos[3 * i + 1] * r, quads.pos[3 * i + 2] * r);
    }
    for (f = 0; f < quads.nf; f++) {
        for (k = 2; k < quads.sizes[f]; k++)
            tm_tri(m, quads.idx[corner], quads.idx[corner + k - 1], quads.idx[corner + k]);
        corner += quads.sizes[f];
    }
    tm_free(&quads);
}

/* The default field follows up where up is strong and is the smoothest
   where up is weak: on a closed box the walls point up and the top (where
   up says nothing, and the walls' vectors, perpendicular to it, say
   nothing either) is constant; on a bumpy sphere, off the walls it turns
   across edges less than half as much as the projected up does (the
   control, the paper's plain rule), and on the walls it is the projected
   up (within 1 degree on average, 2 at the 90th percentile; the smoothed
   field was 4.9 and 11.4 off), where a random field (the control) is not. */
static void test_field_smooth(void)
{
    static const double box[6][3][3] = {
        /* origin, u, v (u x v outward) of each side of the box [0,2]x[0,1]x[0,1.5] */
        {{0, 0, 1.5}, {2, 0, 0}, {0, 1, 0}},   {{2, 0, 0}, {-2, 0, 0}, {0, 1, 0}}, {{2, 0, 1.5}, {0, 0, -1.5}, {0, 1, 0}},
        {{0, 0, 0}, {0, 0, 1.5}, {0, 1, 0}},   {{0, 1, 1.5}, {2, 0, 0}, {0, 0, -1.5}}, {{0, 0, 0}, {2, 0, 0}, {0, 0, 1.5}}};
    const int n = 8;
    tmesh m;
    tt_mesh *mesh = NULL;
    tt_error err;
    float *v, *control;
    int side, i, j, f, k;
    double walls = 0.0, top = 0.0, bottom = 0.0, smooth, plain, walls_mean, walls_p90, random_mean, random_p90;
    const double up[3] = {0.0, 1.0, 0.0};
    int walls_n;
    memset(&m, 0, sizeof m);
    for (side = 0; side < 6; side++) {
        int base = m.nv;
        for (j = 0; j <= n; j++)
            for (i = 0; i <= n; i++) {
                double p[3];
                for (k = 0; k < 3; k++) p[k] = box[side][0][k] + box[side][1][k] * i / n + box[side][2][k] * j / n;
                tm_vert(&m, p[0], p[1], p[2]);
            }
        for (j = 0; j < n; j++)
            for (i = 0; i < n; i++) {
                int a = base + j * (n + 1) + i;
                tm_tri(&m, a, a + 1, a + n + 2);
                tm_tri(&m, a, a + n + 2, a + n + 1);
            }
    }
    /* Weld the sides' shared edges. */
    {
        tmesh welded;
        int *map = (int *)malloc(sizeof(int) * (size_t)m.nv);
        memset(&welded, 0, sizeof welded);
        for (i = 0; i < m.nv; i++) {
            for (j = 0; j < welded.nv; j++)
                if (fabs(welded.pos[3 * j] - m.pos[3 * i]) < 1e-6 && fabs(welded.pos[3 * j + 1] - m.pos[3 * i + 1]) < 1e-6 &&
                    fabs(welded.pos[3 * j + 2] - m.pos[3 * i + 2]) < 1e-6)
                    break;
            map[i] = j < welded.nv ? j : tm_vert(&welded, m.pos[3 * i], m.pos[3 * i + 1], m.pos[3 * i + 2]);
        }
        for (f = 0; f < m.nf; f++)
            tm_tri(&welded, map[m.idx[3 * f]], map[m.idx[3 * f + 1]], map[m.idx[3 * f + 2]]);
        free(map);
        tm_free(&m);
        m = welded;
    }
    CHECK(build(&m, 0, &mesh, &err) == TT_OK, "box builds: %s", err.message);
    v = (float *)malloc(sizeof(float) * 3 * (size_t)mesh->nfaces);
    CHECK(tt_tangent_field(mesh, NULL, NULL, v, &err) == TT_OK, "box field: %s", err.message);
    {
        double top_mean[3] = {0, 0, 0}, bottom_mean[3] = {0, 0, 0};
        for (f = 0; f < mesh->nfaces; f++) {
            float nrm[3];
            tt_face_normal(mesh, f, nrm);
            for (k = 0; k < 3; k++) (nrm[1] > 0.5f ? top_mean : bottom_mean)[k] += nrm[1] > 0.5f || nrm[1] < -0.5f ? v[3 * f + k] : 0.0;
        }
        for (f = 0; f < mesh->nfaces; f++) {
            float nrm[3];
            double a[3];
            tt_face_normal(mesh, f, nrm);
            for (k = 0; k < 3; k++) a[k] = v[3 * f + k];
            if (nrm[1] > 0.5f) top = fmax(top, fv_angle(a, top_mean));
            else if (nrm[1] < -0.5f) bottom = fmax(bottom, fv_angle(a, bottom_mean));
            else walls = fmax(walls, fv_angle(a, up));
        }
    }
    printf("     default field on a closed box: walls %.3f degrees from up, top and bottom %.3f and %.3f from constant\n",
           walls * 180.0 / 3.14159265358979323846, top * 180.0 / 3.14159265358979323846,
           bottom * 180.0 / 3.14159265358979323846);
    CHECK(walls * 180.0 / 3.14159265358979323846 <= 1.0 && top * 180.0 / 3.14159265358979323846 <= 1.0 &&
              bottom * 180.0 / 3.14159265358979323846 <= 1.0,
          "closed box: the walls' field within 1 degree of up (%.3g), the top's and bottom's constant within 1 degree "
          "(%.3g, %.3g)", walls * 180.0 / 3.14159265358979323846, top * 180.0 / 3.14159265358979323846,
          bottom * 180.0 / 3.14159265358979323846);
    free(v);
    tt_mesh_free(mesh);
    tm_free(&m);

    /* The control for the tops is the projected up, normalised. */
    make_bumpy_sphere(&m);
    CHECK(build(&m, 0, &mesh, &err) == TT_OK, "bumpy sphere builds: %s", err.message);
    v = (float *)malloc(sizeof(float) * 3 * (size_t)mesh->nfaces);
    control = (float *)malloc(sizeof(float) * 3 * (size_t)mesh->nfaces);
    CHECK(tt_tangent_field(mesh, NULL, NULL, v, &err) == TT_OK, "bumpy sphere field: %s", err.message);
    for (f = 0; f < mesh->nfaces; f++) {
        float nrm[3];
        double l;
        tt_face_normal(mesh, f, nrm);
        for (k = 0; k < 3; k++) control[3 * f + k] = (float)((k == 1) - nrm[1] * nrm[k]);
        l = fv_len(control + 3 * f);
        for (k = 0; k < 3; k++) control[3 * f + k] = (float)(control[3 * f + k] / (l > 0.0 ? l : 1.0));
    }
    smooth = field_mean_turn(mesh, v, up);
    plain = field_mean_turn(mesh, control, up);
    CHECK(smooth <= 0.5 * plain, "bumpy sphere: off the walls the field turns %.3g degrees across an edge on average, "
          "the projected up %.3g (at most half wanted)", smooth, plain);
    /* On the walls the field follows up; a random field (the control) does not. */
    walls_n = field_wall_angles(mesh, v, up, &walls_mean, &walls_p90);
    lcg_seed(11);
    for (f = 0; f < mesh->nfaces; f++) {
        float nrm[3];
        double r[3], d = 0.0, l;
        tt_face_normal(mesh, f, nrm);
        for (k = 0; k < 3; k++) r[k] = lcg_unit() - 0.5;
        for (k = 0; k < 3; k++) d += r[k] * nrm[k];
        for (k = 0; k < 3; k++) r[k] -= d * nrm[k];
        l = sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
        for (k = 0; k < 3; k++) control[3 * f + k] = (float)(r[k] / (l > 0.0 ? l : 1.0));
    }
    field_wall_angles(mesh, control, up, &random_mean, &random_p90);
    CHECK(walls_n > mesh->nfaces / 2 && walls_mean <= 1.0 && walls_p90 <= 2.0,
          "bumpy sphere: on %d wall faces the field is %.3g degrees from the projected up on average, %.3g at the "
          "90th percentile (at most 1 and 2 wanted: the field is the projected up there)", walls_n, walls_mean,
          walls_p90);
    CHECK(random_mean > 5.0 && random_p90 > 12.0,
          "control: a random field is %.3g degrees from up on average on the walls, %.3g at the 90th percentile",
          random_mean, random_p90);
    printf("     default field on a bumpy sphere: off the walls mean turn across edges %.2f degrees (projected up "
           "%.2f); on the walls %.2f degrees from up, p90 %.2f (random field %.1f, %.1f)\n",
           smooth, plain, walls_mean, walls_p90, random_mean, random_p90);
    free(v);
    free(control);
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
    int i;
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
    FIELD_EXPECT(tt_tangent_field(NULL, &opt, NULL, v, &err), TT_ERROR_INVALID_ARGUMENT, -1, "NULL mesh");
    FIELD_EXPECT(tt_tangent_field(mesh, &opt, NULL, NULL, &err), TT_ERROR_INVALID_ARGUMENT, -1, "NULL output");
    CHECK(tt_tangent_field(NULL, &opt, NULL, v, NULL) == TT_ERROR_INVALID_ARGUMENT, "NULL error pointer is allowed");
    opt.up[0] = nan_f;
    FIELD_EXPECT(tt_tangent_field(mesh, &opt, NULL, v, &err), TT_ERROR_INVALID_ARGUMENT, -1, "NaN up");
    opt.up[0] = 1e-45f;   /* denormal: non-zero, still a direction */
    CHECK(tt_tangent_field(mesh, &opt, NULL, v, &err) == TT_OK, "tiny up is a direction: %s", err.message);
    opt.up[0] = 0.0f;
    opt.scale = -1.0f;
    FIELD_EXPECT(tt_tangent_field(mesh, &opt, NULL, v, &err), TT_ERROR_INVALID_ARGUMENT, -1, "negative scale");
    opt.scale = 1.0f / 0.0f;
    FIELD_EXPECT(tt_tangent_field(mesh, &opt, NULL, v, &err), TT_ERROR_INVALID_ARGUMENT, -1, "infinite scale");
    opt.scale = 0.0f;
    opt.sigma = nan_f;
    FIELD_EXPECT(tt_tangent_field(mesh, &opt, NULL, v, &err), TT_ERROR_INVALID_ARGUMENT, -1, "NaN sigma");
    opt.sigma = 0.0f;
    opt.nconstraints = -1;
    FIELD_EXPECT(tt_tangent_field(mesh, &opt, NULL, v, &err), TT_ERROR_INVALID_ARGUMENT, -1, "negative nconstraints");
    opt.nconstraints = 1;
    FIELD_EXPECT(tt_tangent_field(mesh, &opt, NULL, v, &err), TT_ERROR_INVALID_ARGUMENT, -1, "NULL constraints");

    memset(con, 0, sizeof con);
    con[0].face = 3; con[0].vector[0] = 1.0f;
    con[1].face = 16; con[1].vector[1] = 1.0f;
    opt.constraints = con;
    opt.nconstraints = 2;
    FIELD_EXPECT(tt_tangent_field(mesh, &opt, NULL, v, &err), TT_ERROR_INDEX_OUT_OF_RANGE, 16, "face == nfaces");
    CHECK(msg_has_number(err.message, 16) && msg_has_number(err.message, 1) && strstr(err.message, "constraint"),
          "the message names constraint 1 and face 16: %s", err.message);
    con[1].face = -1;
    FIELD_EXPECT(tt_tangent_field(mesh, &opt, NULL, v, &err), TT_ERROR_INDEX_OUT_OF_RANGE, -1, "face -1");
    con[1].face = 5;
    con[1].vector[1] = 0.0f;
    FIELD_EXPECT(tt_tangent_field(mesh, &opt, NULL, v, &err), TT_ERROR_INVALID_ARGUMENT, 5, "zero vector");
    CHECK(strstr(err.message, "constraint 1") != NULL, "the message names constraint 1: %s", err.message);
    con[1].vector[2] = 1.0f;   /* along the grid's normal */
    FIELD_EXPECT(tt_tangent_field(mesh, &opt, NULL, v, &err), TT_ERROR_INVALID_ARGUMENT, 5, "perpendicular vector");
    con[1].vector[2] = 0.0f;
    con[1].vector[1] = nan_f;
    FIELD_EXPECT(tt_tangent_field(mesh, &opt, NULL, v, &err), TT_ERROR_NON_FINITE, 5, "NaN vector");
    con[1].vector[1] = 1.0f / 0.0f;
    FIELD_EXPECT(tt_tangent_field(mesh, &opt, NULL, v, &err), TT_ERROR_NON_FINITE, 5, "infinite vector");
    /* Every component finite, the length beyond FLT_MAX: turned into
       another face's plane it would be infinite as a float. */
    con[1].vector[0] = 3e38f;
    con[1].vector[1] = 3e38f;
    FIELD_EXPECT(tt_tangent_field(mesh, &opt, NULL, v, &err), TT_ERROR_NON_FINITE, 5, "vector longer than FLT_MAX");
    CHECK(strstr(err.message, "largest float") != NULL, "the message says the length overflows: %s", err.message);
    con[1].vector[0] = 2e38f;   /* 2.8e38 long: fits */
    con[1].vector[1] = 2e38f;
    CHECK(tt_tangent_field(mesh, &opt, NULL, v, &err) == TT_OK, "a vector 2.8e38 long: %s", err.message);
    for (i = 0; i < 3 * mesh->nfaces; i++) CHECK(isfinite(v[i]), "field component %d is %g", i, (double)v[i]);
    con[1].vector[0] = 0.0f;
    con[1].vector[1] = 1.0f;
    con[1].weight = -1.0f;
    FIELD_EXPECT(tt_tangent_field(mesh, &opt, NULL, v, &err), TT_ERROR_INVALID_ARGUMENT, 5, "negative weight");
    con[1].weight = 0.0f;
    con[1].sigma = -2.0f;
    FIELD_EXPECT(tt_tangent_field(mesh, &opt, NULL, v, &err), TT_ERROR_INVALID_ARGUMENT, 5, "negative sigma");
    con[1].sigma = 0.0f;
    CHECK(tt_tangent_field(mesh, &opt, NULL, v, &err) == TT_OK, "valid constraints: %s", err.message);

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
    FIELD_EXPECT(tt_tangent_field(dmesh, &opt, NULL, v, &err), TT_ERROR_ZERO_AREA_FACE, 2, "constraint on a zero-area face");
#undef FIELD_EXPECT
    tt_mesh_free(dmesh);
    tm_free(&md);
    tt_mesh_free(mesh);
    tm_free(&m);
}

/* Every constraint error names the constraint in error->item and its face
   in error->face. The bad constraint sits at index 2, after two good ones,
   so item cannot be confused with 0 or with the face. */
/* Coordinates at FLT_MAX beside ordinary ones and a denormal (what the
   fuzz target found): the smoothing's solution comes out near 1e198, past
   what its squares can hold, and used to normalise to a zero vector on
   faces with a plane. Each such face must still get a vector in its plane,
   as long as the others. */
static void test_field_extreme_coordinates(void)
{
    static const double pos[9][3] = {{-4, 7.9375, 7.5},
                                     {7.9375, -5.8125, -2.5},
                                     {1.02261157e-40, 1.17549435e-38, 0},
                                     {-4.875, 3.40282347e+38, -3.40282347e+38},
                                     {3.40282347e+38, 0, 1},
                                     {4, 0, 0},
                                     {1, 0, 0},
                                     {4.625, 2.5, 1.5},
                                     {0, 2.5, -3.9375}};
    tmesh m;
    tt_mesh *mesh = NULL;
    tt_error err;
    float v[9];
    double first = 0.0;
    int f;
    memset(&m, 0, sizeof m);
    for (f = 0; f < 9; f++) tm_vert(&m, pos[f][0], pos[f][1], pos[f][2]);
    tm_tri(&m, 2, 6, 0);
    tm_tri(&m, 6, 2, 8);
    tm_tri(&m, 6, 1, 3);   /* a needle 1e38 long and a few units wide: zero area against its size, no vector */
    if (build(&m, TT_MESH_PERMISSIVE, &mesh, &err) != TT_OK) {
        CHECK(0, "the mesh builds permissively: %s", err.message);
        tm_free(&m);
        return;
    }
    CHECK(tt_tangent_field(mesh, NULL, NULL, v, &err) == TT_OK, "extreme coordinates, default options: %s",
          err.message);
    for (f = 0; f < 2; f++) {
        float n[3];
        const double len = sqrt((double)v[3 * f] * v[3 * f] + (double)v[3 * f + 1] * v[3 * f + 1] +
                                (double)v[3 * f + 2] * v[3 * f + 2]);
        tt_face_normal(mesh, f, n);
        CHECK(isfinite(len) && len > 0.0, "face %d (it has a plane) has the vector (%g, %g, %g)", f, (double)v[3 * f],
              (double)v[3 * f + 1], (double)v[3 * f + 2]);
        CHECK(fabs((double)v[3 * f] * n[0] + (double)v[3 * f + 1] * n[1] + (double)v[3 * f + 2] * n[2]) <= 1e-4 * len,
              "face %d's vector is off its plane", f);
        if (f == 0) first = len;
        else CHECK(fabs(len - first) <= 1e-4 * first, "the vectors are %g and %g long: both the scale", first, len);
    }
    tt_mesh_free(mesh);
    tm_free(&m);
}

static void test_field_constraint_items(void)
{
    tmesh m, md;
    tt_mesh *mesh = NULL, *dmesh = NULL;
    tt_field_options opt;
    tt_field_constraint con[4];
    tt_error err;
    float *v;
    float nan_f = (float)internal_not_a_number();
    memset(&m, 0, sizeof m);
    make_grid(&m, 4, 4);
    CHECK(build(&m, 0, &mesh, &err) == TT_OK, "grid builds: %s", err.message);
    v = (float *)malloc(sizeof(float) * 3 * (size_t)mesh->nfaces);

#define ITEM_EXPECT(code, item_, face_, what)                                                                   \
    do {                                                                                                        \
        tt_result r_;                                                                                           \
        memset(&err, 0x5a, sizeof err);                                                                         \
        r_ = tt_tangent_field(mesh, &opt, NULL, v, &err);                                                       \
        CHECK(r_ == (code) && err.result == (code) && err.item == (item_) && err.face == (face_) &&             \
                  err.corner == -1 && err.vertex == -1 && err.row == -1 && err.column == -1 &&                  \
                  err.message[0] != '\0' && strlen(err.message) < sizeof err.message &&                         \
                  longest_digit_run(err.message) <= 12,                                                         \
              "%s: expected %d (item %d, face %d), got %d (item %d, face %d, corner %d): %.100s", what,         \
              (int)(code), item_, face_, (int)r_, err.item, err.face, err.corner, err.message);                 \
        CHECK(strstr(err.message, "constraint 2") != NULL, "%s: the message names constraint 2: %.100s", what,  \
              err.message);                                                                                     \
    } while (0)

    memset(&opt, 0, sizeof opt);
    memset(con, 0, sizeof con);
    con[0].face = 3; con[0].vector[0] = 1.0f;
    con[1].face = 9; con[1].vector[1] = 0.5f;
    con[2].face = 11; con[2].vector[0] = 0.7f; con[2].vector[1] = 0.7f;
    con[3].face = 14; con[3].vector[1] = -1.0f;
    opt.constraints = con;
    opt.nconstraints = 4;
    CHECK(tt_tangent_field(mesh, &opt, NULL, v, &err) == TT_OK && err.item == -1,
          "four valid constraints: %s (item %d)", err.message, err.item);

    con[2].face = mesh->nfaces + 5;
    ITEM_EXPECT(TT_ERROR_INDEX_OUT_OF_RANGE, 2, mesh->nfaces + 5, "constraint 2 on face nfaces + 5");
    con[2].face = -3;
    ITEM_EXPECT(TT_ERROR_INDEX_OUT_OF_RANGE, 2, -3, "constraint 2 on face -3");
    con[2].face = 11;
    con[2].vector[1] = nan_f;
    ITEM_EXPECT(TT_ERROR_NON_FINITE, 2, 11, "constraint 2 with a NaN vector");
    con[2].vector[1] = 0.7f;
    con[2].sigma = -0.5f;
    ITEM_EXPECT(TT_ERROR_INVALID_ARGUMENT, 2, 11, "constraint 2 with a negative sigma");
    con[2].sigma = 0.0f;
    con[2].vector[0] = con[2].vector[1] = con[2].vector[2] = 0.0f;
    ITEM_EXPECT(TT_ERROR_INVALID_ARGUMENT, 2, 11, "constraint 2 with a zero vector");
    con[2].vector[2] = 3.0f;   /* along the grid's normal */
    ITEM_EXPECT(TT_ERROR_INVALID_ARGUMENT, 2, 11, "constraint 2 perpendicular to its face");
    con[2].vector[0] = 0.001f;   /* projects to 1/3000 of its length: still perpendicular */
    ITEM_EXPECT(TT_ERROR_INVALID_ARGUMENT, 2, 11, "constraint 2 nearly perpendicular to its face");
    con[2].vector[0] = 0.7f;
    con[2].vector[2] = 0.0f;
    CHECK(tt_tangent_field(mesh, &opt, NULL, v, &err) == TT_OK, "restored: %s", err.message);

    /* A constraint on a zero-area face (permissive mesh): faces 0..7 are the
       grid, face 8 the sliver. */
    memset(&md, 0, sizeof md);
    make_grid(&md, 4, 2);
    {
        int a = tm_vert(&md, 5, 0, 0), b = tm_vert(&md, 6, 0, 0), c = tm_vert(&md, 7, 0, 0);
        tm_tri(&md, a, b, c);
    }
    CHECK(build(&md, TT_MESH_PERMISSIVE, &dmesh, &err) == TT_OK, "sliver mesh builds: %s", err.message);
    if (dmesh) {
        tt_mesh *grid = mesh;
        mesh = dmesh;
        con[1].face = 5;
        con[2].face = 8;
        con[3].face = 7;
        ITEM_EXPECT(TT_ERROR_ZERO_AREA_FACE, 2, 8, "constraint 2 on the zero-area face 8");
        mesh = grid;
    }
#undef ITEM_EXPECT
    tt_mesh_free(dmesh);
    tm_free(&md);
    free(v);
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

static tt_result field_oom_call(void *ctx, const tt_allocator *al, tt_error *error)
{
    field_oom_ctx *c = (field_oom_ctx *)ctx;
    tt_field_options opt;
    tt_result r;
    memset(&opt, 0, sizeof opt);
    memcpy(opt.up, c->up, sizeof opt.up);
    opt.constraints = c->constraints;
    opt.nconstraints = c->nconstraints;
    r = tt_tangent_field(c->mesh, &opt, al, c->out, error);
    if (error->result != r) return TT_RESULT_MAX_ENUM;
    return r;
}

/* tt_field_face_weights: 0 where up decides nothing, 1 on walls, the
   smooth step between (|P(up)| from 0.1 to 0.5), 1 everywhere with
   constraints; and the field holds the projected up exactly where the
   weight is 1 and the face is a wall. */
static void test_field_face_weights(void)
{
    tmesh m;
    tt_mesh *mesh = NULL;
    tt_field_options opt;
    tt_field_constraint con;
    tt_error err;
    float *w, *v;
    int f, wrong = 0, ones = 0, zeros = 0, level_wrong = 0;
    memset(&m, 0, sizeof m);
    make_field_sphere(&m, 24, 32, 2.0);
    CHECK(build(&m, 0, &mesh, &err) == TT_OK, "sphere builds: %s", err.message);
    tm_free(&m);
    if (!mesh) return;
    w = (float *)malloc(sizeof(float) * (size_t)mesh->nfaces);
    v = (float *)malloc(sizeof(float) * 3 * (size_t)mesh->nfaces);
    memset(&opt, 0, sizeof opt);
    CHECK(tt_field_face_weights(mesh, &opt, w, &err) == TT_OK, "weights: %s", err.message);
    CHECK(tt_tangent_field(mesh, &opt, NULL, v, &err) == TT_OK, "field: %s", err.message);
    for (f = 0; f < mesh->nfaces; f++) {
        float n[3];
        double p = 0, t, expect, dot, len;
        tt_face_normal(mesh, f, n);
        p = sqrt(1.0 - (double)n[1] * n[1] > 0 ? 1.0 - (double)n[1] * n[1] : 0);
        t = (p - 0.1) / 0.4;
        t = t < 0 ? 0 : t > 1 ? 1 : t;
        expect = t * t * (3 - 2 * t);
        if (fabs(w[f] - expect) > 1e-5) {
            if (!wrong++) DETAIL("face %d: |P(up)| %.4f, weight %.6f, expected %.6f", f, p, w[f], expect);
        }
        ones += w[f] == 1.0f;
        zeros += w[f] == 0.0f;
        /* Walls (|P(up)| >= 0.8): the field is the projected up there. */
        len = sqrt((double)v[3 * f] * v[3 * f] + (double)v[3 * f + 1] * v[3 * f + 1] + (double)v[3 * f + 2] * v[3 * f + 2]);
        dot = len > 0 ? v[3 * f + 1] / len : 0;
        if (p >= 0.8 && w[f] == 1.0f && fabs(dot - p) > 1e-3) {
            if (!level_wrong++) DETAIL("face %d: field . up %.4f, |P(up)| %.4f", f, dot, p);
        }
    }
    CHECK(wrong == 0 && ones > 0 && ones + zeros < mesh->nfaces, "weights by the rule: %d wrong, %d ones, %d zeros of %d",
          wrong, ones, zeros, mesh->nfaces);
    CHECK(level_wrong == 0, "weight-1 walls carry the projected up: %d do not", level_wrong);
    memset(&con, 0, sizeof con);
    con.face = 3;
    {
        float n[3];
        tt_face_normal(mesh, 3, n);
        con.vector[0] = -n[1]; con.vector[1] = n[0]; con.vector[2] = 0.0f;
        if (fabsf(con.vector[0]) + fabsf(con.vector[1]) < 1e-3f) { con.vector[0] = 0; con.vector[1] = -n[2]; con.vector[2] = n[1]; }
    }
    opt.constraints = &con;
    opt.nconstraints = 1;
    CHECK(tt_field_face_weights(mesh, &opt, w, &err) == TT_OK, "constraints: %s", err.message);
    for (f = 0, wrong = 0; f < mesh->nfaces; f++) wrong += w[f] != 1.0f;
    CHECK(wrong == 0, "with constraints every weight is 1: %d are not", wrong);
    free(w);
    free(v);
    tt_mesh_free(mesh);
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
/* 7b. Texture patches                                                      */
/* ------------------------------------------------------------------------ */

/* A smooth, opaque RGB test source. */
static tt_image *patch_source(int w, int h)
{
    tt_image *img = NULL;
    int x, y;
    tt_result r = tt_image_create(w, h, NULL, &img, NULL);
    CHECK(r == TT_OK && img, "tt_image_create(%d, %d): %d", w, h, (int)r);
    if (!img) return NULL;
    for (y = 0; y < h; y++)
        for (x = 0; x < w; x++) {
            float *p = img->pixels + 4 * (y * w + x);
            p[0] = 0.2f + 0.6f * (float)x / (float)w;
            p[1] = 0.3f + 0.5f * (float)y / (float)h;
            p[2] = 0.7f;
            p[3] = 1.0f;
        }
    return img;
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
    tt_image *src, *patch = NULL;
    tt_patch_options opt;
    tt_error err;
    int w = 96, h = 80, x, y, inside = 0, half = 0, border_bad = 0, deep_bad = 0, pm_bad = 0, contour_bad = 0;
    unsigned char *in = (unsigned char *)malloc((size_t)(w * h));
    src = patch_source(w, h);
    memset(&opt, 0, sizeof opt);
    opt.seed = 7;
    CHECK(tt_make_texture_patch(src, NULL, &opt, NULL, &patch, &err) == TT_OK, "splotch: ok (%s)", err.message);
    CHECK(patch->width == w && patch->height == h && patch->pixels, "splotch: %d x %d patch", patch->width, patch->height);
    if (patch) {
        for (y = 0; y < h; y++)
            for (x = 0; x < w; x++) {
                const float *p = patch->pixels + 4 * (y * w + x), *s = src->pixels + 4 * (y * w + x);
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
            for (x = w / 2 - 10; x < w / 2 + 10; x++) deep_bad += patch->pixels[4 * (y * w + x) + 3] != 1.0f;
        CHECK(deep_bad == 0, "alpha is 1 in the centre: %d texels are not", deep_bad);
        /* The 0.5 contour lies falloff/2 texels inside the shape's edge: every
           texel with alpha >= 0.5 is at least 2 texels from an outside centre,
           every one with 0 < alpha < 0.5 at most 2 (falloff 3: depth 0.5 + 1.5). */
        for (y = 0; y < h; y++)
            for (x = 0; x < w; x++) {
                float a = patch->pixels[4 * (y * w + x) + 3];
                double d = patch_brute_depth(in, w, h, x, y);
                if (a >= 0.5f && d < 2.0 - 1e-6) contour_bad++;
                if (a > 0.0f && a < 0.5f && d > 2.0 + 1e-6) contour_bad++;
            }
        CHECK(contour_bad == 0, "the 0.5 contour is falloff/2 = 1.5 texels inside the edge: %d texels off",
              contour_bad);
        patch_check_ramp(patch, in, 3.0f, "splotch, falloff 3");
    }
    tt_image_free(patch);
    /* A wider falloff is honoured too. */
    opt.falloff = 6.5f;
    CHECK(tt_make_texture_patch(src, NULL, &opt, NULL, &patch, &err) == TT_OK, "falloff 6.5: ok (%s)", err.message);
    if (patch) {
        int ramp = 0;
        for (y = 0; y < h; y++)
            for (x = 0; x < w; x++) {
                float a = patch->pixels[4 * (y * w + x) + 3];
                in[y * w + x] = (unsigned char)(a > 0.0f);
                if ((x < 6 || y < 6 || x >= w - 6 || y >= h - 6) && a != 0.0f) border_bad++;
                ramp += a > 0.0f && a < 1.0f;
            }
        CHECK(border_bad == 0, "falloff 6.5: margin of 6.5 texels is transparent: %d texels are not", border_bad);
        CHECK(ramp > 6 * 150, "falloff 6.5: a wide ramp (%d texels between 0 and 1)", ramp);
        patch_check_ramp(patch, in, 6.5f, "splotch, falloff 6.5");
    }
    tt_image_free(patch);
    tt_image_free(src);
    free(in);
}

static void test_patch_seeds(void)
{
    tt_image *src, *a = NULL, *b = NULL, *c = NULL;
    tt_patch_options opt;
    int w = 64, h = 64, seed, differ = 0, min_cov = w * h, max_cov = 0;
    size_t i;
    src = patch_source(w, h);
    memset(&opt, 0, sizeof opt);
    opt.seed = 123;
    CHECK(tt_make_texture_patch(src, NULL, &opt, NULL, &a, NULL) == TT_OK, "seed 123: ok");
    CHECK(tt_make_texture_patch(src, NULL, &opt, NULL, &b, NULL) == TT_OK, "seed 123 again: ok");
    opt.seed = 124;
    CHECK(tt_make_texture_patch(src, NULL, &opt, NULL, &c, NULL) == TT_OK, "seed 124: ok");
    if (a && b && c) {
        CHECK(memcmp(a->pixels, b->pixels, sizeof(float) * 4 * (size_t)(w * h)) == 0, "same seed, same patch");
        for (i = 0; i < (size_t)(w * h); i++) differ += (a->pixels[4 * i + 3] > 0.0f) != (c->pixels[4 * i + 3] > 0.0f);
        CHECK(differ > 20, "seeds 123 and 124 give different shapes: %d texels differ", differ);
    }
    tt_image_free(a);
    tt_image_free(b);
    tt_image_free(c);
    /* Coverage holds over many seeds, and at the roughest setting. */
    for (seed = 0; seed < 40; seed++) {
        int cov = 0;
        opt.seed = (uint64_t)seed * 0x9e3779b97f4a7c15ull;
        opt.roughness = seed < 20 ? 0.0f : 0.6f;
        if (tt_make_texture_patch(src, NULL, &opt, NULL, &a, NULL) != TT_OK) { cov = -1; }
        else {
            for (i = 0; i < (size_t)(w * h); i++) cov += a->pixels[4 * i + 3] > 0.0f;
            tt_image_free(a);
        }
        if (cov < min_cov) min_cov = cov;
        if (cov > max_cov) max_cov = cov;
    }
    CHECK(min_cov >= 0.60 * w * h && max_cov <= 0.75 * w * h, "40 seeds: coverage %.1f%% .. %.1f%%",
          100.0 * min_cov / (w * h), 100.0 * max_cov / (w * h));
    tt_image_free(src);
}

static void test_patch_masks(void)
{
    tt_image *src, *mask = NULL, *patch = NULL;
    tt_error err;
    int w = 40, h = 30, x, y, bad = 0;
    unsigned char *in = (unsigned char *)malloc((size_t)(w * h));
    src = patch_source(w, h);
    tt_image_create(w, h, NULL, &mask, NULL);
    /* Grey mask (opaque): a rectangle of grey 0.6 plus a stray 0.4 texel (outside). */
    for (y = 0; y < h; y++)
        for (x = 0; x < w; x++) {
            float *p = mask->pixels + 4 * (y * w + x);
            float g = (x >= 5 && x < 35 && y >= 4 && y < 26) ? 0.6f : 0.0f;
            if (x == 1 && y == 1) g = 0.4f;
            p[0] = p[1] = p[2] = g;
            p[3] = 1.0f;
            in[y * w + x] = (unsigned char)(g >= 0.5f);
        }
    CHECK(tt_make_texture_patch(src, mask, NULL, NULL, &patch, &err) == TT_OK, "grey mask: ok (%s)", err.message);
    if (patch) {
        patch_check_ramp(patch, in, 3.0f, "grey mask");
        CHECK(patch->pixels[4 * (15 * w + 20) + 3] == 1.0f, "grey mask: centre alpha 1, got %g",
              patch->pixels[4 * (15 * w + 20) + 3]);
        CHECK(patch->pixels[4 * (4 * w + 20) + 3] > 0.16f && patch->pixels[4 * (4 * w + 20) + 3] < 0.17f,
              "grey mask: edge texel alpha 0.5/3, got %g", patch->pixels[4 * (4 * w + 20) + 3]);
    }
    tt_image_free(patch);
    /* Mask alpha (not all 1): alpha is used, the grey ignored. */
    for (y = 0; y < h; y++)
        for (x = 0; x < w; x++) {
            float *p = mask->pixels + 4 * (y * w + x);
            int inside = (x - 20) * (x - 20) + (y - 15) * (y - 15) <= 100;
            p[0] = p[1] = p[2] = 1.0f - (float)inside;   /* grey says the opposite */
            p[3] = inside ? 0.75f : 0.25f;
            in[y * w + x] = (unsigned char)inside;
        }
    CHECK(tt_make_texture_patch(src, mask, NULL, NULL, &patch, &err) == TT_OK, "alpha mask: ok (%s)", err.message);
    if (patch) patch_check_ramp(patch, in, 3.0f, "alpha mask");
    tt_image_free(patch);
    /* Source alpha takes precedence over the mask: a band x in [10, 30). */
    for (y = 0; y < h; y++)
        for (x = 0; x < w; x++) {
            src->pixels[4 * (y * w + x) + 3] = (x >= 10 && x < 30) ? 1.0f : 0.0f;
            in[y * w + x] = (unsigned char)(x >= 10 && x < 30);
        }
    CHECK(tt_make_texture_patch(src, mask, NULL, NULL, &patch, &err) == TT_OK, "source alpha: ok (%s)", err.message);
    if (patch) {
        patch_check_ramp(patch, in, 3.0f, "source alpha over mask");
        for (y = 0; y < h; y++)
            for (x = 0; x < w; x++) {
                const float *p = patch->pixels + 4 * (y * w + x), *s = src->pixels + 4 * (y * w + x);
                if (p[0] != s[0] * p[3] || p[1] != s[1] * p[3] || p[2] != s[2] * p[3]) bad++;
            }
        CHECK(bad == 0, "source alpha: premultiplied exactly, %d texels differ", bad);
    }
    tt_image_free(patch);
    /* A fully opaque grey mask still fades out at the image border. */
    for (y = 0; y < h * w * 4; y++) mask->pixels[y] = 1.0f;
    for (y = 0; y < h * w; y++) { src->pixels[4 * y + 3] = 1.0f; in[y] = 1; }
    CHECK(tt_make_texture_patch(src, mask, NULL, NULL, &patch, &err) == TT_OK, "full mask: ok (%s)", err.message);
    if (patch) patch_check_ramp(patch, in, 3.0f, "full mask");
    tt_image_free(patch);
    tt_image_free(mask);
    tt_image_free(src);
    free(in);
}

static void test_patch_errors(void)
{
    tt_image *src, *mask = NULL, *patch = NULL, empty;
    tt_patch_options opt;
    tt_error err;
    float nan_value = (float)internal_not_a_number();
    src = patch_source(32, 32);
    memset(&empty, 0, sizeof empty);
    memset(&opt, 0, sizeof opt);
    CHECK(tt_make_texture_patch(NULL, NULL, NULL, NULL, &patch, &err) == TT_ERROR_INVALID_ARGUMENT, "NULL source");
    CHECK(tt_make_texture_patch(&empty, NULL, NULL, NULL, &patch, &err) == TT_ERROR_INVALID_ARGUMENT, "empty source");
    CHECK(tt_make_texture_patch(src, NULL, NULL, NULL, NULL, &err) == TT_ERROR_INVALID_ARGUMENT, "NULL patch");
    tt_image_create(31, 32, NULL, &mask, NULL);
    CHECK(tt_make_texture_patch(src, mask, NULL, NULL, &patch, &err) == TT_ERROR_INVALID_ARGUMENT, "mask size");
    CHECK(strstr(err.message, "31 x 32") && strstr(err.message, "32 x 32"), "size message: %s", err.message);
    CHECK(patch == NULL, "patch left NULL on error");
    tt_image_free(mask);
    tt_image_create(32, 32, NULL, &mask, NULL);   /* all zero: transparent black */
    CHECK(tt_make_texture_patch(src, mask, NULL, NULL, &patch, &err) == TT_ERROR_INVALID_ARGUMENT, "empty mask");
    CHECK(strstr(err.message, "the mask has no opaque pixel") != NULL, "empty mask message: %s", err.message);
    CHECK(err.result == TT_ERROR_INVALID_ARGUMENT, "err.result set: %d", err.result);
    mask->pixels[3] = nan_value;
    CHECK(tt_make_texture_patch(src, mask, NULL, NULL, &patch, &err) == TT_ERROR_NON_FINITE, "NaN mask: %s", err.message);
    tt_image_free(mask);
    opt.falloff = -1.0f;
    CHECK(tt_make_texture_patch(src, NULL, &opt, NULL, &patch, &err) == TT_ERROR_INVALID_ARGUMENT, "negative falloff");
    CHECK(strstr(err.message, "negative") != NULL, "negative falloff message: %s", err.message);
    opt.falloff = 15.0f;
    CHECK(tt_make_texture_patch(src, NULL, &opt, NULL, &patch, &err) == TT_ERROR_INVALID_ARGUMENT, "falloff 15 on 32: %s",
          err.message);
    opt.falloff = 10.0f;   /* room for a splotch, but it is not 10 texels deep */
    CHECK(tt_make_texture_patch(src, NULL, &opt, NULL, &patch, &err) == TT_ERROR_INVALID_ARGUMENT, "falloff 10 on 32: %s",
          err.message);
    CHECK(strstr(err.message, "no opaque texel") != NULL, "falloff 10 message: %s", err.message);
    opt.falloff = internal_infinity();
    CHECK(tt_make_texture_patch(src, NULL, &opt, NULL, &patch, &err) == TT_ERROR_NON_FINITE, "infinite falloff");
    opt.falloff = nan_value;
    CHECK(tt_make_texture_patch(src, NULL, &opt, NULL, &patch, &err) == TT_ERROR_NON_FINITE, "NaN falloff");
    opt.falloff = 0.0f;
    opt.roughness = nan_value;
    CHECK(tt_make_texture_patch(src, NULL, &opt, NULL, &patch, &err) == TT_ERROR_NON_FINITE, "NaN roughness");
    opt.roughness = 1.0f;
    CHECK(tt_make_texture_patch(src, NULL, &opt, NULL, &patch, &err) == TT_ERROR_INVALID_ARGUMENT, "roughness 1");
    opt.roughness = -0.5f;
    CHECK(tt_make_texture_patch(src, NULL, &opt, NULL, &patch, &err) == TT_ERROR_INVALID_ARGUMENT, "roughness -0.5");
    opt.roughness = 0.0f;
    src->pixels[4 * 33 + 1] = nan_value;
    CHECK(tt_make_texture_patch(src, NULL, &opt, NULL, &patch, &err) == TT_ERROR_NON_FINITE, "NaN source");
    CHECK(strstr(err.message, "(1, 1)") != NULL, "NaN source names the texel: %s", err.message);
    CHECK(patch == NULL, "patch left NULL on error");
    tt_image_free(src);
}

typedef struct patch_oom_ctx {
    const tt_image *source, *mask;
    uint64_t seed;
} patch_oom_ctx;

static tt_result patch_oom_call(void *ctx, const tt_allocator *al, tt_error *error)
{
    patch_oom_ctx *c = (patch_oom_ctx *)ctx;
    tt_patch_options opt;
    tt_image *patch = (tt_image *)ctx;   /* must be reset to NULL on failure */
    tt_result r;
    memset(&opt, 0, sizeof opt);
    opt.seed = c->seed;
    r = tt_make_texture_patch(c->source, c->mask, &opt, al, &patch, error);
    if (r != TT_OK && (patch != NULL || error->result != r)) return TT_RESULT_MAX_ENUM;
    tt_image_free(patch);
    return r;
}

static void test_patch_oom(void)
{
    tt_image *src, *mask = NULL;
    patch_oom_ctx c;
    int i;
    src = patch_source(24, 20);
    tt_image_create(24, 20, NULL, &mask, NULL);
    for (i = 0; i < 24 * 20; i++) mask->pixels[4 * i + 3] = (i % 24 > 4 && i % 24 < 20) ? 1.0f : 0.0f;
    oom_reset();
    c.source = src;
    c.mask = NULL;
    c.seed = 3;
    oom_sweep("tt_make_texture_patch(splotch)", patch_oom_call, &c, TT_OK);
    c.mask = mask;
    oom_sweep("tt_make_texture_patch(mask)", patch_oom_call, &c, TT_OK);
    memset(mask->pixels, 0, sizeof(float) * 4 * 24 * 20);
    oom_sweep("tt_make_texture_patch(empty mask)", patch_oom_call, &c, TT_ERROR_INVALID_ARGUMENT);
    tt_image_free(mask);
    tt_image_free(src);
}

/* ------------------------------------------------------------------------ */
/* 7c. The paste loop                                                       */
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
static tt_image *lapped_patch(int size, unsigned seed)
{
    tt_image *src = NULL, *patch = NULL;
    tt_patch_options po;
    tt_error err;
    tt_result r;
    make_value_noise(&src, size, size, seed);
    memset(&po, 0, sizeof po);
    po.seed = seed;
    r = tt_make_texture_patch(src, NULL, &po, NULL, &patch, &err);
    CHECK(r == TT_OK && patch, "lapped_patch(%d, %u): %d %s", size, seed, (int)r, err.message);
    tt_image_free(src);
    return patch;
}

/* Composite alpha (times the fade) of every entry of face f at barycentric
   point w, the pastes drawn in order with "over", recomputed from the
   output alone. */
static double lapped_alpha_at(const tt_lapped *lapped, tt_image *const *patches, int f, const double w[3])
{
    double alpha = 0.0;
    int p, e;
    for (p = 0; p < lapped->npastes; p++)
        for (e = lapped->pastes[p].first; e < lapped->pastes[p].first + lapped->pastes[p].nfaces; e++) {
            const float *uv = lapped->uv + 6 * (size_t)e;
            const tt_image *im = patches[lapped->pastes[p].patch];
            float rgba[4];
            double u, v;
            if (lapped->faces[e] != f) continue;
            u = w[0] * uv[0] + w[1] * uv[2] + w[2] * uv[4];
            v = w[0] * uv[1] + w[1] * uv[3] + w[2] * uv[5];
            tt_image_sample_bilinear(im, (float)(u * im->width), (float)((1.0 - v) * im->height), rgba);
            if (lapped->fade) {
                const float *fade = lapped->fade + 3 * (size_t)e;
                rgba[3] *= (float)(w[0] * fade[0] + w[1] * fade[1] + w[2] * fade[2]);
            }
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

/* An address no tt_lapped_paste returns: outputs are preset to it, to see
   that a failing call resets them to NULL. */
static tt_lapped g_lapped_sentinel;

static int lapped_run(const tmesh *m, int isotropic, uint64_t seed, float scale, tt_mesh **mesh, float **field,
                      tt_image *patch, tt_lapped **out)
{
    tt_field_options fo;
    tt_lapped_options lo;
    tt_error err;
    tt_result r;
    *mesh = NULL;
    *field = NULL;
    *out = NULL;
    if (build(m, 0, mesh, &err) != TT_OK) return -1;
    *field = (float *)malloc(sizeof(float) * 3 * (size_t)(*mesh)->nfaces);
    memset(&fo, 0, sizeof fo);
    fo.scale = scale;
    if (tt_tangent_field(*mesh, &fo, NULL, *field, &err) != TT_OK) return -1;
    memset(&lo, 0, sizeof lo);
    lo.seed = seed;
    lo.isotropic = isotropic;
    *out = &g_lapped_sentinel;   /* tt_lapped_paste must set it */
    r = tt_lapped_paste(*mesh, *field, &patch, 1, &lo, NULL, out, &err);
    CHECK(r == TT_OK && *out != NULL, "tt_lapped_paste: %d %s", r, err.message);
    CHECK(r == TT_OK || *out == NULL, "tt_lapped_paste failed but left *out_lapped set");
    if (r != TT_OK) *out = NULL;   /* never free the sentinel */
    return r == TT_OK && *out ? 0 : -1;
}

/* tt_lapped.top_changes and visible_cuts recomputed from the output alone:
   the last entry of each face is on top; across an edge whose tops are two
   pastes, the later one stops there, and it is a cut when its alpha times
   its fade (lapped->fade, linear along the edge; NULL is 1) at one of 5 even
   points along the edge (clamped lookups) reaches TT_LAPPED_VISIBLE_CUT. */
static void lapped_count_cuts(const tt_mesh *mesh, const tt_lapped *lapped, tt_image *const *patches, int *changes,
                              int *cuts)
{
    int *top = (int *)malloc(sizeof(int) * (size_t)mesh->nfaces), *paste_of = (int *)malloc(sizeof(int) *
                                                                                               (size_t)(lapped->nentries + 1));
    int p, e, c;
    for (c = 0; c < mesh->nfaces; c++) top[c] = -1;
    for (p = 0; p < lapped->npastes; p++)
        for (e = lapped->pastes[p].first; e < lapped->pastes[p].first + lapped->pastes[p].nfaces; e++) {
            paste_of[e] = p;
            top[lapped->faces[e]] = e;
        }
    *changes = *cuts = 0;
    for (c = 0; c < mesh->ncorners; c++) {
        int t = mesh->twin[c], ef, eg, upper, corner, i;
        float most = 0.0f;
        if (t < c || (ef = top[c / 3]) < 0 || (eg = top[t / 3]) < 0 || paste_of[ef] == paste_of[eg]) continue;
        (*changes)++;
        upper = paste_of[ef] > paste_of[eg] ? ef : eg;
        corner = upper == ef ? c % 3 : t % 3;
        for (i = 0; i <= 4; i++) {
            const float *a = lapped->uv + 6 * (size_t)upper + 2 * corner, *b = lapped->uv + 6 * (size_t)upper + 2 * ((corner + 1) % 3);
            const tt_image *im = patches[lapped->pastes[paste_of[upper]].patch];
            float u = a[0] + 0.25f * i * (b[0] - a[0]), v = a[1] + 0.25f * i * (b[1] - a[1]), rgba[4], fade = 1.0f;
            if (lapped->fade) {
                const float *f = lapped->fade + 3 * (size_t)upper;
                fade = f[corner] + 0.25f * i * (f[(corner + 1) % 3] - f[corner]);
            }
            tt_image_sample_bilinear(im, u * im->width, (1.0f - v) * im->height, rgba);
            if (rgba[3] * fade > most) most = rgba[3] * fade;
        }
        *cuts += most >= TT_LAPPED_VISIBLE_CUT;
    }
    free(top);
    free(paste_of);
}


/* The alignment energy sum_f a_f (|phi(S_f) - (1,0)|^2 + |phi(T_f) - (0,1)|^2)
   of Praun et al. Sec. 3.4 over the faces listed, from the per-face
   weights ws, wt (3 each per listed face) and areas a. */
static double align_energy(const tt_mesh *mesh, const int *faces, int nfaces, const double *ws, const double *wt,
                           const double *a, const double *uv)
{
    double energy = 0.0;
    int i, k;
    for (i = 0; i < nfaces; i++) {
        double s[2] = {0, 0}, t[2] = {0, 0};
        for (k = 0; k < 3; k++) {
            const double *p = uv + 2 * mesh->corner_vert[3 * faces[i] + k];
            s[0] += ws[3 * i + k] * p[0];
            s[1] += ws[3 * i + k] * p[1];
            t[0] += wt[3 * i + k] * p[0];
            t[1] += wt[3 * i + k] * p[1];
        }
        energy += a[i] * ((s[0] - 1) * (s[0] - 1) + s[1] * s[1] + t[0] * t[0] + (t[1] - 1) * (t[1] - 1));
    }
    return energy;
}

/* The weights w (summing to 0) with sum_k w_k P_k = v for a vector v in
   triangle f's plane: v = w1 e1 + w2 e2 over its edges from corner 0. */
static void align_weights(const tt_mesh *mesh, int f, const double v[3], double w[3])
{
    const float *p0 = mesh->pos + 3 * mesh->corner_vert[3 * f], *p1 = mesh->pos + 3 * mesh->corner_vert[3 * f + 1];
    const float *p2 = mesh->pos + 3 * mesh->corner_vert[3 * f + 2];
    double e1[3], e2[3], g11 = 0, g12 = 0, g22 = 0, r1 = 0, r2 = 0, det;
    int k;
    for (k = 0; k < 3; k++) {
        e1[k] = (double)p1[k] - p0[k];
        e2[k] = (double)p2[k] - p0[k];
        g11 += e1[k] * e1[k];
        g12 += e1[k] * e2[k];
        g22 += e2[k] * e2[k];
        r1 += e1[k] * v[k];
        r2 += e2[k] * v[k];
    }
    det = g11 * g22 - g12 * g12;
    w[1] = (g22 * r1 - g12 * r2) / det;
    w[2] = (g11 * r2 - g12 * r1) / det;
    w[0] = -w[1] - w[2];
}

/* The alignment solve of Sec. 3.4 (multigrid-preconditioned conjugate
   gradients, tolerance 1e-3) on a disc of a wavy grid at three densities
   (about 1100, 4400 and 17500 unknowns) against a naive reference: the
   normal equations assembled here from the formula - per face S = T x N
   and the field's T as combinations of its corners, a_f its area over the
   mean, the seed point held on the anchor by a penalty of trace / n -
   solved to 1e-12 by tt_cg_solve with IC(0), both starting from a map
   turned 10 degrees and stretched 5 % off the field, then moved so the
   seed point sits on the anchor. The solve lands within 2e-3 of the
   reference (texture units: the patch is 1 across), and short of the
   reference's energy by at most 1e-3 of the way from the start; and the
   steps it takes do not grow with the density while its unknowns grow 16
   times. The control: tt_cg_solve with IC(0) to the same tolerance, the
   solve the paste loop used before, takes at least 10 more steps at the
   finest than at the coarsest (23, 25, 44 here; 70 at 900 unknowns and
   350 at 4600 on the horse's pastes). */
static void test_lapped_align_solve(void)
{
    static const int sizes[3] = {40, 80, 160};
    const float anchor[2] = {0.45f, 0.55f};
    const double side = 1.2, seed_weight[3] = {0.2, 0.3, 0.5};
    int level, unknowns[3] = {0, 0, 0}, steps[3] = {0, 0, 0}, ic_steps[3] = {0, 0, 0};
    for (level = 0; level < 3; level++) {
        const int n = sizes[level];
        tmesh q, t;
        tt_mesh *mesh = NULL;
        tt_field_options fo;
        tt_error err;
        tt_triplet *tri = NULL;
        tt_sparse_matrix *A = NULL;
        tt_cg_options cg;
        float *field = NULL;
        int *faces = NULL, nfaces = 0, seed = -1, i, k, j, nt = 0, nlocal = 0, *local = NULL;
        double *uv = NULL, *ref = NULL, *ws = NULL, *wt = NULL, *a = NULL, *bs = NULL, *bt = NULL, *xs = NULL,
               *xt = NULL, best = 1e30, mean_area = 0.0, trace = 0.0, worst = 0.0, e_new, e_ref, e_start, shift[2];
        tt_cg_report rep;
        tt_result r;
        memset(&q, 0, sizeof q);
        make_grid(&q, n, n);
        for (i = 0; i < q.nv; i++) {
            float *p = q.pos + 3 * i;
            p[0] *= 2.0f / (float)n;
            p[1] *= 2.0f / (float)n;
            p[2] = (float)(0.25 * sin(2.0 * p[0]) * cos(1.5 * p[1]));
        }
        tm_triangulate(&q, &t);
        tm_free(&q);
        r = build(&t, 0, &mesh, &err);
        tm_free(&t);
        CHECK(r == TT_OK, "align solve: grid %d: %s", n, err.message);
        if (r != TT_OK) return;
        field = (float *)malloc(sizeof(float) * 3 * (size_t)mesh->nfaces);
        memset(&fo, 0, sizeof fo);
        fo.scale = (float)side;
        tt_tangent_field(mesh, &fo, NULL, field, &err);
        /* The disc: faces whose centroid lies within 0.75 of (1, 1); the seed face the nearest. */
        faces = (int *)malloc(sizeof(int) * (size_t)mesh->nfaces);
        for (i = 0; i < mesh->nfaces; i++) {
            double cx = 0, cy = 0, d;
            for (k = 0; k < 3; k++) {
                cx += mesh->pos[3 * mesh->corner_vert[3 * i + k]] / 3.0;
                cy += mesh->pos[3 * mesh->corner_vert[3 * i + k] + 1] / 3.0;
            }
            d = (cx - 1.0) * (cx - 1.0) + (cy - 1.0) * (cy - 1.0);
            if (d > 0.75 * 0.75) continue;
            faces[nfaces++] = i;
            if (d < best) {
                best = d;
                seed = i;
            }
        }
        /* A start off the field: the plane's coordinates turned 10 degrees, 5 % too large. */
        uv = (double *)calloc(2 * (size_t)mesh->nverts, sizeof(double));
        ref = (double *)calloc(2 * (size_t)mesh->nverts, sizeof(double));
        for (i = 0; i < mesh->nverts; i++) {
            const double x = mesh->pos[3 * i] - 1.0, y = mesh->pos[3 * i + 1] - 1.0, c = cos(0.1745), s_ = sin(0.1745);
            uv[2 * i] = ref[2 * i] = anchor[0] + 1.05 / side * (c * x - s_ * y);
            uv[2 * i + 1] = ref[2 * i + 1] = anchor[1] + 1.05 / side * (s_ * x + c * y);
        }
        r = internal_lapped_align(mesh, field, faces, nfaces, seed, seed_weight, anchor, uv, &unknowns[level],
                                  &steps[level]);
        CHECK(r == TT_OK, "align solve: grid %d: %d", n, (int)r);

        /* The reference. */
        local = (int *)malloc(sizeof(int) * (size_t)mesh->nverts);
        for (i = 0; i < mesh->nverts; i++) local[i] = -1;
        ws = (double *)malloc(sizeof(double) * 3 * (size_t)nfaces);
        wt = (double *)malloc(sizeof(double) * 3 * (size_t)nfaces);
        a = (double *)malloc(sizeof(double) * (size_t)nfaces);
        for (i = 0; i < nfaces; i++) {
            const int f = faces[i];
            const float *p0 = mesh->pos + 3 * mesh->corner_vert[3 * f], *p1 = mesh->pos + 3 * mesh->corner_vert[3 * f + 1];
            const float *p2 = mesh->pos + 3 * mesh->corner_vert[3 * f + 2];
            double e1[3], e2[3], nrm[3], tv[3], sv[3], len, dot = 0;
            for (k = 0; k < 3; k++) {
                e1[k] = (double)p1[k] - p0[k];
                e2[k] = (double)p2[k] - p0[k];
            }
            nrm[0] = e1[1] * e2[2] - e1[2] * e2[1];
            nrm[1] = e1[2] * e2[0] - e1[0] * e2[2];
            nrm[2] = e1[0] * e2[1] - e1[1] * e2[0];
            len = sqrt(nrm[0] * nrm[0] + nrm[1] * nrm[1] + nrm[2] * nrm[2]);
            a[i] = 0.5 * len;
            mean_area += a[i] / nfaces;
            for (k = 0; k < 3; k++) nrm[k] /= len;
            for (k = 0; k < 3; k++) dot += field[3 * f + k] * nrm[k];
            for (k = 0; k < 3; k++) tv[k] = field[3 * f + k] - dot * nrm[k];
            sv[0] = tv[1] * nrm[2] - tv[2] * nrm[1];
            sv[1] = tv[2] * nrm[0] - tv[0] * nrm[2];
            sv[2] = tv[0] * nrm[1] - tv[1] * nrm[0];
            align_weights(mesh, f, tv, wt + 3 * i);
            align_weights(mesh, f, sv, ws + 3 * i);
            for (k = 0; k < 3; k++)
                if (local[mesh->corner_vert[3 * f + k]] < 0) local[mesh->corner_vert[3 * f + k]] = nlocal++;
        }
        for (i = 0; i < nfaces; i++) a[i] /= mean_area;
        tri = (tt_triplet *)malloc(sizeof(tt_triplet) * (9 * (size_t)nfaces + 9));
        bs = (double *)calloc((size_t)nlocal, sizeof(double));
        bt = (double *)calloc((size_t)nlocal, sizeof(double));
        xs = (double *)malloc(sizeof(double) * (size_t)nlocal);
        xt = (double *)malloc(sizeof(double) * (size_t)nlocal);
        for (i = 0; i < nfaces; i++)
            for (k = 0; k < 3; k++) {
                const int row = local[mesh->corner_vert[3 * faces[i] + k]];
                bs[row] += a[i] * ws[3 * i + k];
                bt[row] += a[i] * wt[3 * i + k];
                for (j = 0; j < 3; j++) {
                    tri[nt].row = row;
                    tri[nt].col = local[mesh->corner_vert[3 * faces[i] + j]];
                    tri[nt++].value = a[i] * (wt[3 * i + k] * wt[3 * i + j] + ws[3 * i + k] * ws[3 * i + j]);
                }
                trace += a[i] * (wt[3 * i + k] * wt[3 * i + k] + ws[3 * i + k] * ws[3 * i + k]);
            }
        for (k = 0; k < 3; k++) {
            const int row = local[mesh->corner_vert[3 * seed + k]];
            bs[row] += trace / nlocal * seed_weight[k] * anchor[0];
            bt[row] += trace / nlocal * seed_weight[k] * anchor[1];
            for (j = 0; j < 3; j++) {
                tri[nt].row = row;
                tri[nt].col = local[mesh->corner_vert[3 * seed + j]];
                tri[nt++].value = trace / nlocal * seed_weight[k] * seed_weight[j];
            }
        }
        for (i = 0; i < mesh->nverts; i++)
            if (local[i] >= 0) {
                xs[local[i]] = ref[2 * i];
                xt[local[i]] = ref[2 * i + 1];
            }
        memset(&cg, 0, sizeof cg);
        cg.tolerance = 1e-12;
        cg.preconditioner = TT_CG_INCOMPLETE_CHOLESKY;
        cg.max_iterations = 100000;
        r = tt_sparse_from_triplets(nlocal, nlocal, tri, nt, NULL, &A, &err);
        /* The control first, from the same start: IC(0) to the solve's tolerance. */
        cg.tolerance = 1e-3;
        if (r == TT_OK) r = tt_cg_solve(A, bs, &cg, NULL, xs, &rep, &err);
        ic_steps[level] = rep.iterations;
        for (i = 0; i < mesh->nverts; i++)
            if (local[i] >= 0) xs[local[i]] = ref[2 * i];
        cg.tolerance = 1e-12;
        if (r == TT_OK) r = tt_cg_solve(A, bs, &cg, NULL, xs, NULL, &err);
        if (r == TT_OK) r = tt_cg_solve(A, bt, &cg, NULL, xt, NULL, &err);
        CHECK(r == TT_OK, "align solve: grid %d: the reference solve: %s", n, err.message);
        e_start = align_energy(mesh, faces, nfaces, ws, wt, a, ref);
        shift[0] = anchor[0];
        shift[1] = anchor[1];
        for (k = 0; k < 3; k++) {
            shift[0] -= seed_weight[k] * xs[local[mesh->corner_vert[3 * seed + k]]];
            shift[1] -= seed_weight[k] * xt[local[mesh->corner_vert[3 * seed + k]]];
        }
        for (i = 0; i < mesh->nverts; i++)
            if (local[i] >= 0) {
                ref[2 * i] = xs[local[i]] + shift[0];
                ref[2 * i + 1] = xt[local[i]] + shift[1];
                worst = fmax(worst, fmax(fabs(uv[2 * i] - ref[2 * i]), fabs(uv[2 * i + 1] - ref[2 * i + 1])));
            }
        e_new = align_energy(mesh, faces, nfaces, ws, wt, a, uv);
        e_ref = align_energy(mesh, faces, nfaces, ws, wt, a, ref);
        CHECK(unknowns[level] == nlocal && worst <= 2e-3 && e_new - e_ref <= 1e-3 * (e_start - e_ref),
              "align solve: grid %d: %d unknowns (reference %d), |uv - reference| up to %.2e (want <= 2e-3), energy "
              "%.6g against %.6g from %.6g (want within 1e-3 of the way)", n, unknowns[level], nlocal, worst, e_new,
              e_ref, e_start);
        if (level == 2)
            printf("     alignment solve against exact CG: %d / %d / %d unknowns in %d / %d / %d steps (IC(0): %d / %d / "
                   "%d); at the finest |uv - reference| <= %.1e, energy %.4f against %.4f from %.4f\n", unknowns[0],
                   unknowns[1], unknowns[2], steps[0], steps[1], steps[2], ic_steps[0], ic_steps[1], ic_steps[2],
                   worst, e_new, e_ref, e_start);
        tt_sparse_matrix_free(A);
        free(tri);
        free(bs);
        free(bt);
        free(xs);
        free(xt);
        free(ws);
        free(wt);
        free(a);
        free(local);
        free(uv);
        free(ref);
        free(faces);
        free(field);
        tt_mesh_free(mesh);
    }
    CHECK(unknowns[2] > 12 * unknowns[0] && steps[0] > 0 && steps[2] <= steps[0] + 3 && steps[2] <= 15,
          "align solve: %d, %d, %d unknowns (want 16 times as many at the finest) took %d, %d, %d steps (want no "
          "growth: at most 3 more at the finest, and at most 15)", unknowns[0], unknowns[1], unknowns[2], steps[0],
          steps[1], steps[2]);
    CHECK(ic_steps[2] >= ic_steps[0] + 10, "align solve, the control: IC(0) took %d, %d, %d steps (want at least 10 "
          "more at the finest)", ic_steps[0], ic_steps[1], ic_steps[2]);
}

/* The fade (tt_lapped.fade): within [0, 1]; one value per vertex of each
   paste (entries of a paste meeting at a vertex agree), so a paste's alpha
   is continuous; used (some paste fades on the sphere, where pastes stop
   short of the poles' bends; the sheet's cuts are all at its boundary,
   where nothing fades); and with it the
   composite stays opaque everywhere, not only at face centres: 25 points a
   face on a sphere and on a wavy sheet (a boundary, where nothing fades). */
static void test_lapped_fade(void)
{
    tt_image *patch = lapped_patch(64, 3);
    int shape;
    for (shape = 0; shape < 2 && patch; shape++) {
        tmesh m;
        tt_mesh *mesh;
        float *field;
        tt_lapped *lapped = NULL;
        int e, k, f, i, bad_range = 0, disagree = 0, faded = 0, thin = 0;
        double least = 1.0;
        float *at_vertex;
        make_lapped_shape(&m, shape);
        if (lapped_run(&m, 0, 7, 0.0f, &mesh, &field, patch, &lapped) != 0) {
            tm_free(&m);
            continue;
        }
        CHECK(lapped->fade != NULL, "shape %d: the output has a fade", shape);
        at_vertex = (float *)malloc(sizeof(float) * (size_t)mesh->nverts);
        for (i = 0; lapped->fade && i < lapped->npastes; i++) {
            const tt_paste *paste = &lapped->pastes[i];
            for (k = 0; k < mesh->nverts; k++) at_vertex[k] = -1.0f;
            for (e = paste->first; e < paste->first + paste->nfaces; e++)
                for (k = 0; k < 3; k++) {
                    float value = lapped->fade[3 * (size_t)e + k];
                    int v = mesh->corner_vert[3 * lapped->faces[e] + k];
                    bad_range += !(value >= 0.0f && value <= 1.0f);
                    faded += value < 1.0f;
                    if (at_vertex[v] < 0.0f) at_vertex[v] = value;
                    else disagree += at_vertex[v] != value;
                }
        }
        for (f = 0; f < mesh->nfaces; f++)
            for (i = 0; i < 25; i++) {
                double w[3], a = (i % 5 + 0.5) / 5.0, b = (i / 5 + 0.5) / 5.0, alpha;
                if (a + b > 1.0) { a = 1.0 - a; b = 1.0 - b; }
                w[0] = 1.0 - a - b; w[1] = a; w[2] = b;
                alpha = lapped_alpha_at(lapped, &patch, f, w);
                if (alpha < least) least = alpha;
                thin += alpha < 0.98;
            }
        CHECK(bad_range == 0 && disagree == 0 && (shape != 0 || faded > 0),
              "shape %d: %d fades outside [0, 1], %d corners disagreeing with their paste's vertex, %d faded corners "
              "(want some on the sphere)", shape, bad_range, disagree, faded);
        CHECK(thin == 0, "shape %d: %d of %d points with composite alpha below 0.98 (least %.3f): a translucent hole",
              shape, thin, 25 * mesh->nfaces, least);
        free(at_vertex);
        tt_lapped_free(lapped);
        tt_mesh_free(mesh);
        free(field);
        tm_free(&m);
    }
    tt_image_free(patch);
}

/* The hard edges counted: against the recount from the output; the
   control, a fully opaque patch with its fade ignored (every paste ends at
   a cut), against the soft splotch with its fade on the same sphere. */
static void test_lapped_cuts(void)
{
    tt_image *patch = lapped_patch(64, 5), *opaque = lapped_patch(64, 5);
    int which, fraction_ok = 1;
    double fractions[2] = {0.0, 0.0}, opaque_faded = 0.0;
    size_t i;
    for (i = 0; opaque && i < (size_t)opaque->width * opaque->height; i++) opaque->pixels[4 * i + 3] = 1.0f;
    for (which = 0; which < 2 && patch && opaque; which++) {
        tmesh m;
        tt_mesh *mesh;
        float *field;
        tt_lapped *lapped = NULL;
        tt_image *used = which ? opaque : patch;
        int changes, cuts;
        make_lapped_shape(&m, 0);
        if (lapped_run(&m, 0, 11, 0.0f, &mesh, &field, used, &lapped) == 0) {
            lapped_count_cuts(mesh, lapped, &used, &changes, &cuts);
            CHECK(changes == lapped->top_changes && cuts == lapped->visible_cuts,
                  "%s patch: %d of %d edges cuts, recounted from the output %d of %d", which ? "opaque" : "splotch",
                  lapped->visible_cuts, lapped->top_changes, cuts, changes);
            fractions[which] = changes ? (double)cuts / changes : 0.0;
            if (which) {
                float *fade = lapped->fade;
                opaque_faded = fractions[1];
                lapped->fade = NULL;
                lapped_count_cuts(mesh, lapped, &used, &changes, &cuts);
                lapped->fade = fade;
                fractions[1] = changes ? (double)cuts / changes : 0.0;
            }
            fraction_ok &= changes > 0;
            tt_lapped_free(lapped);
        }
        tt_mesh_free(mesh);
        free(field);
        tm_free(&m);
    }
    CHECK(fraction_ok && fractions[1] >= 0.9 && fractions[0] <= 0.25 * fractions[1] && opaque_faded < fractions[1],
          "cuts among the edges where the top paste changes: %.2f with the soft splotch, %.2f with an opaque patch "
          "and no fade (the control: every paste ends at a cut), %.2f with its fade", fractions[0], fractions[1],
          opaque_faded);
    printf("     hard edges on a sphere: %.0f%% of the top paste's changes with the soft splotch, %.0f%% with an "
           "opaque patch without its fade (%.0f%% with it)\n", 100.0 * fractions[0], 100.0 * fractions[1],
           100.0 * opaque_faded);
    tt_image_free(patch);
    tt_image_free(opaque);
}

static void test_lapped_cover(void)
{
    tt_image *patch;
    int shape, iso;
    patch = lapped_patch(64, 5);
    for (shape = 0; shape < 4; shape++)
        for (iso = 0; iso < 2; iso++) {
            tmesh m;
            tt_mesh *mesh;
            float *field;
            tt_lapped *lapped = NULL;
            double angle_sum = 0.0, worst_alpha = 1.0;
            int f, e, p, missing = 0, bad_points = 0, points = 0, bad_entries = 0, order_ok = 1;
            char *seen;
            make_lapped_shape(&m, shape);
            if (lapped_run(&m, iso, 11, 0.0f, &mesh, &field, patch, &lapped) != 0) {
                tt_mesh_free(mesh);
                free(field);
                tm_free(&m);
                continue;
            }
            seen = (char *)calloc((size_t)mesh->nfaces, 1);
            for (p = 0; p < lapped->npastes; p++) {
                order_ok &= lapped->pastes[p].first == (p ? lapped->pastes[p - 1].first + lapped->pastes[p - 1].nfaces : 0);
                order_ok &= lapped->pastes[p].nfaces > 0 && lapped->pastes[p].patch == 0;
            }
            CHECK(order_ok && lapped->npastes > 0, "%s: pastes are not consecutive runs of entries",
                  LAPPED_SHAPE_NAMES[shape]);
            CHECK(lapped->npastes == 0 ||
                      lapped->pastes[lapped->npastes - 1].first + lapped->pastes[lapped->npastes - 1].nfaces ==
                          lapped->nentries,
                  "%s: the pastes do not account for every entry", LAPPED_SHAPE_NAMES[shape]);
            for (e = 0; e < lapped->nentries; e++) {
                double angle, length;
                int k;
                if (lapped->faces[e] < 0 || lapped->faces[e] >= mesh->nfaces) { bad_entries++; continue; }
                seen[lapped->faces[e]] = 1;
                for (k = 0; k < 6; k++) bad_entries += !isfinite(lapped->uv[6 * e + k]);
                lapped_entry_error(mesh, field, lapped, e, &angle, &length);
                angle_sum += angle;
            }
            for (f = 0; f < mesh->nfaces; f++) missing += !seen[f];
            CHECK(bad_entries == 0, "%s: %d entries with a bad face or UV", LAPPED_SHAPE_NAMES[shape], bad_entries);
            CHECK(missing == 0, "%s (isotropic %d): %d faces in no paste", LAPPED_SHAPE_NAMES[shape], iso, missing);
            CHECK(lapped->coverage == 1.0, "%s: coverage %g", LAPPED_SHAPE_NAMES[shape], lapped->coverage);
            CHECK(near(lapped->mean_overdraw, (double)lapped->nentries / mesh->nfaces, 1e-12),
                  "%s: mean overdraw %g != entries / faces", LAPPED_SHAPE_NAMES[shape], lapped->mean_overdraw);
            CHECK(lapped->mean_overdraw >= 1.0 && lapped->mean_overdraw < 12.0, "%s: overdraw %g",
                  LAPPED_SHAPE_NAMES[shape], lapped->mean_overdraw);
            /* Coverage seen from the output alone: random points of every
               face, every paste composited in order, are opaque. */
            lcg_seed(77);
            for (f = 0; f < mesh->nfaces; f++) {
                int s;
                for (s = 0; s < 12; s++) {
                    double w[3], a = lcg_unit(), b = lcg_unit(), alpha;
                    if (a + b > 1.0) { a = 1.0 - a; b = 1.0 - b; }
                    w[0] = 1.0 - a - b; w[1] = a; w[2] = b;
                    alpha = lapped_alpha_at(lapped, &patch, f, w);
                    points++;
                    if (alpha < 0.98) bad_points++;
                    if (alpha < worst_alpha) worst_alpha = alpha;
                }
            }
            CHECK(bad_points <= points / 500, "%s (isotropic %d): %d of %d random points are not opaque (worst alpha %g)",
                  LAPPED_SHAPE_NAMES[shape], iso, bad_points, points, worst_alpha);
            if (!iso && lapped->nentries > 0) {
                tt_lapped_report measured;
                tt_error err;
                CHECK(near(angle_sum / lapped->nentries, lapped->mean_angle_error, 1e-3),
                      "%s: reported mean angle %g, measured from the UVs %g", LAPPED_SHAPE_NAMES[shape],
                      lapped->mean_angle_error, angle_sum / lapped->nentries);
                /* The paste's statistics are read from the UVs it returns, as tt_lapped_measure reads them:
                   the same figures to the bit. */
                CHECK(tt_lapped_measure(mesh, field, lapped, NULL, &measured, &err) == TT_OK &&
                          measured.mean_angle_error == lapped->mean_angle_error &&
                          measured.median_scale_error == lapped->median_scale_error,
                      "%s: paste reports %.17g deg / %.17g, tt_lapped_measure %.17g / %.17g",
                      LAPPED_SHAPE_NAMES[shape], lapped->mean_angle_error, lapped->median_scale_error,
                      measured.mean_angle_error, measured.median_scale_error);
                CHECK(lapped->mean_angle_error <= 8.0, "%s: mean angle error %g deg", LAPPED_SHAPE_NAMES[shape],
                      lapped->mean_angle_error);
            }
            CHECK(lapped->median_scale_error <= 0.1, "%s (isotropic %d): median scale error %g",
                  LAPPED_SHAPE_NAMES[shape], iso, lapped->median_scale_error);
            free(seen);
            tt_lapped_free(lapped);
            tt_mesh_free(mesh);
            free(field);
            tm_free(&m);
        }
    tt_image_free(patch);
}

/* A flat sheet with a constant field: the optimum maps every face exactly
   (phi(S) = (1,0), phi(T) = (0,1)), so the error is 0 up to rounding. */
static void test_lapped_plane(void)
{
    tmesh g, m;
    tt_mesh *mesh;
    float *field;
    tt_image *patch;
    tt_lapped *lapped = NULL;
    int e;
    double worst = 0.0, worst_len = 0.0;
    memset(&g, 0, sizeof g);
    make_grid(&g, 20, 20);
    tm_triangulate(&g, &m);
    patch = lapped_patch(48, 9);
    if (lapped_run(&m, 0, 3, 4.0f, &mesh, &field, patch, &lapped) == 0) {
        for (e = 0; e < lapped->nentries; e++) {
            double angle, length;
            lapped_entry_error(mesh, field, lapped, e, &angle, &length);
            if (angle > worst) worst = angle;
            if (fabs(length - 1.0) > worst_len) worst_len = fabs(length - 1.0);
        }
        CHECK(worst < 1e-3 && worst_len < 1e-4, "plane: worst angle %g deg, worst scale error %g", worst, worst_len);
        CHECK(lapped->mean_angle_error < 1e-3 && lapped->median_scale_error < 1e-4, "plane: reported %g deg, %g",
              lapped->mean_angle_error, lapped->median_scale_error);
        /* a 20 x 20 sheet with 4-unit patches needs a few dozen pastes */
        CHECK(lapped->npastes >= 20 && lapped->npastes <= 400, "plane: %d pastes", lapped->npastes);
    }
    tt_lapped_free(lapped);
    tt_mesh_free(mesh);
    free(field);
    tm_free(&m);
    tm_free(&g);
    tt_image_free(patch);
}

/* Mean squared difference (first channel, straight colour) between the
   paste on top and the one beneath, over points of faces where both are at
   least half opaque (alpha times fade): how far the overlapping pastes
   disagree, which shows as broken or doubled courses of a structured photo.
   shift: 2 per paste added to its UVs (the control), or NULL. */
static double lapped_overlap_mismatch(const tt_mesh *mesh, const tt_lapped *lapped, tt_image *const *patches,
                                      const double *shift, int *points)
{
    int *last = (int *)malloc(sizeof(int) * 2 * (size_t)mesh->nfaces), p, e, i, j, k;
    double sum = 0.0;
    *points = 0;
    /* The two last entries of each face (pastes come in order). */
    for (i = 0; i < 2 * mesh->nfaces; i++) last[i] = -1;
    for (p = 0; p < lapped->npastes; p++)
        for (e = lapped->pastes[p].first; e < lapped->pastes[p].first + lapped->pastes[p].nfaces; e++) {
            last[2 * lapped->faces[e] + 1] = last[2 * lapped->faces[e]];
            last[2 * lapped->faces[e]] = e;
        }
    for (i = 0; i < mesh->nfaces; i++) {
        if (last[2 * i + 1] < 0) continue;
        for (j = 0; j < 9; j++) {
            const double w[3] = {(1 + j % 3) / 4.5, (1 + j / 3) / 4.5, 1.0 - (2 + j % 3 + j / 3) / 4.5};
            double value[2], alpha[2];
            for (k = 0; k < 2; k++) {
                const int en = last[2 * i + k];
                const float *uv = lapped->uv + 6 * (size_t)en, *fade = lapped->fade + 3 * (size_t)en;
                int paste = 0;
                float rgba[4];
                double u, v;
                while (paste + 1 < lapped->npastes && lapped->pastes[paste + 1].first <= en) paste++;
                u = w[0] * uv[0] + w[1] * uv[2] + w[2] * uv[4] + (shift ? shift[2 * paste] : 0.0);
                v = w[0] * uv[1] + w[1] * uv[3] + w[2] * uv[5] + (shift ? shift[2 * paste + 1] : 0.0);
                tt_image_sample_bilinear(patches[lapped->pastes[paste].patch], (float)(u * patches[0]->width),
                                         (float)((1.0 - v) * patches[0]->height), rgba);
                alpha[k] = rgba[3] * (w[0] * fade[0] + w[1] * fade[1] + w[2] * fade[2]);
                value[k] = rgba[3] > 0.0f ? rgba[0] / rgba[3] : 0.0;
            }
            if (alpha[0] < 0.5 || alpha[1] < 0.5) continue;
            sum += (value[0] - value[1]) * (value[0] - value[1]);
            ++*points;
        }
    }
    free(last);
    return *points ? sum / *points : 0.0;
}

/* Registration: on a flat sheet, pastes of a striped patch (courses 32
   texels apart) land at random heights against each other; moved to match
   what lies beneath, the overlaps show one course, not two. The control
   moves each paste back by a random shift as large as registration may
   make (a quarter of the patch): its overlaps disagree many times more. */
static void test_lapped_register(void)
{
    tmesh g, m;
    tt_mesh *mesh = NULL;
    float *field = NULL;
    tt_image *src = NULL, *patch = NULL;
    tt_lapped *lapped = NULL;
    tt_patch_options po;
    double *shift, registered, control;
    int x, y, k, points, control_points;
    memset(&g, 0, sizeof g);
    make_grid(&g, 40, 40);
    tm_triangulate(&g, &m);
    CHECK(tt_image_create(128, 128, NULL, &src, NULL) == TT_OK, "stripes image");
    for (y = 0; y < 128; y++)
        for (x = 0; x < 128; x++)
            for (k = 0; k < 4; k++)
                px(src, x, y)[k] = k == 3 ? 1.0f : (float)(0.5 + 0.5 * sin(2.0 * 3.14159265358979323846 * y / 32.0));
    memset(&po, 0, sizeof po);
    po.seed = 5;
    CHECK(tt_make_texture_patch(src, NULL, &po, NULL, &patch, NULL) == TT_OK, "striped patch");
    if (lapped_run(&m, 0, 7, 8.0f, &mesh, &field, patch, &lapped) == 0) {
        shift = (double *)malloc(sizeof(double) * 2 * (size_t)lapped->npastes);
        lcg_seed(3);
        for (k = 0; k < 2 * lapped->npastes; k++) shift[k] = 0.5 * lcg_unit() - 0.25;
        registered = lapped_overlap_mismatch(mesh, lapped, &patch, NULL, &points);
        control = lapped_overlap_mismatch(mesh, lapped, &patch, shift, &control_points);
        printf("     registration on a striped sheet: overlaps differ by %.4f (mean square, %d points), "
               "%.4f when each paste moves at random (%d points), %d pastes\n",
               registered, points, control, control_points, lapped->npastes);
        CHECK(points > 1000 && registered <= 0.25 * control,
              "striped sheet: the overlaps differ by %.4f on average (%d points), against %.4f for pastes moved "
              "at random: at most a quarter wanted", registered, points, control);
        free(shift);
    }
    tt_lapped_free(lapped);
    tt_mesh_free(mesh);
    free(field);
    tm_free(&m);
    tm_free(&g);
    tt_image_free(patch);
    tt_image_free(src);
}

/* A paste's cut at (u, v) of its texture space, from tt_lapped.cut as its
   declaration describes it: 1 within, smoothstep down to 0 over the
   feather beyond. shift_columns turns the cut about the anchor (the
   control: a cut of the same depths in the wrong places). */
static double lapped_cut_factor(const tt_lapped *lapped, int paste, double u, double v, int shift_columns)
{
    const int K = lapped->cut_columns;
    const float *cut = lapped->cut + (size_t)(2 + K) * paste;
    const double du = u - cut[0], dv = v - cut[1], r = sqrt(du * du + dv * dv);
    double at = atan2(dv, du) / (2.0 * 3.14159265358979323846) * K, reach, x;
    int j, j0, j1;
    if (at < 0.0) at += K;
    j = (int)at < K ? (int)at : K - 1;
    j0 = (j + shift_columns) % K;
    j1 = (j + 1 + shift_columns) % K;
    reach = cut[2 + j0] + (at - j) * (cut[2 + j1] - cut[2 + j0]);
    if (r <= reach) return 1.0;
    x = (reach + lapped->cut_feather - r) / lapped->cut_feather;
    return x <= 0.0 ? 0.0 : x * x * (3.0 - 2.0 * x);
}

/* Mean squared difference (straight colour, 3 channels) between the paste
   on top and the one beneath it over the points where the top one blends
   into it: its alpha times fade, times its cut over what is beneath (as
   tt_lapped_bake composites it), between 0.02 and 0.98, and the one beneath
   at least half opaque. That is where a seam shows. use_cut: 0 ignores the
   cut, 1 uses it, 2 uses it turned (the control). */
static double lapped_seam_mismatch(const tt_mesh *mesh, const tt_lapped *lapped, tt_image *const *patches,
                                   int use_cut, int *points)
{
    int *last = (int *)malloc(sizeof(int) * 2 * (size_t)mesh->nfaces);
    int *paste_of = (int *)malloc(sizeof(int) * (size_t)(lapped->nentries + 1)), *turn = NULL, p, e, i, j, k, c;
    double sum = 0.0;
    *points = 0;
    if (use_cut == 2) {
        turn = (int *)malloc(sizeof(int) * (size_t)lapped->npastes);
        for (p = 0; p < lapped->npastes; p++) turn[p] = lapped->cut_columns / 4 + (int)(lcg_unit() * lapped->cut_columns / 2);
    }
    for (p = 0; p < lapped->npastes; p++)
        for (e = lapped->pastes[p].first; e < lapped->pastes[p].first + lapped->pastes[p].nfaces; e++) paste_of[e] = p;
    for (i = 0; i < 2 * mesh->nfaces; i++) last[i] = -1;
    for (e = 0; e < lapped->nentries; e++) {
        last[2 * lapped->faces[e] + 1] = last[2 * lapped->faces[e]];
        last[2 * lapped->faces[e]] = e;
    }
    for (i = 0; i < mesh->nfaces; i++) {
        if (last[2 * i + 1] < 0) continue;
        for (j = 0; j < 36; j++) {
            const int a = j % 6, b = j / 6;
            double w[3], value[2][3], alpha[2], u = 0.0, v = 0.0, d = 0.0;
            if (a + b > 5) continue;
            w[0] = (a + 0.5) / 7.0;
            w[1] = (b + 0.5) / 7.0;
            w[2] = 1.0 - w[0] - w[1];
            for (k = 1; k >= 0; k--) {
                const int en = last[2 * i + k];
                const float *uv = lapped->uv + 6 * (size_t)en, *fade = lapped->fade + 3 * (size_t)en;
                const tt_image *patch = patches[lapped->pastes[paste_of[en]].patch];
                float rgba[4];
                u = w[0] * uv[0] + w[1] * uv[2] + w[2] * uv[4];
                v = w[0] * uv[1] + w[1] * uv[3] + w[2] * uv[5];
                tt_image_sample_bilinear(patch, (float)(u * patch->width), (float)((1.0 - v) * patch->height), rgba);
                alpha[k] = rgba[3] * (w[0] * fade[0] + w[1] * fade[1] + w[2] * fade[2]);
                for (c = 0; c < 3; c++) value[k][c] = rgba[3] > 0.0f ? rgba[c] / rgba[3] : 0.0;
            }
            if (use_cut && lapped->cut) {
                const double cut = lapped_cut_factor(lapped, paste_of[last[2 * i]], u, v, use_cut == 2 ? turn[paste_of[last[2 * i]]] : 0);
                alpha[0] *= 1.0 - (1.0 - cut) * (alpha[1] < 1.0 ? alpha[1] : 1.0);
            }
            if (alpha[1] < 0.5 || alpha[0] <= 0.02 || alpha[0] >= 0.98) continue;
            for (c = 0; c < 3; c++) d += (value[0][c] - value[1][c]) * (value[0][c] - value[1][c]);
            sum += d / 3.0;
            ++*points;
        }
    }
    free(last);
    free(paste_of);
    free(turn);
    return *points ? sum / *points : 0.0;
}

/* Pastes of the photo src (its patch, seed 5) over the sheet m, along a
   field of scale 8 (seed 7): *cut with the cut of each paste's edge, *kept
   with keep_edges. */
static void lapped_sheet_pair(const tmesh *m, const tt_image *src, tt_mesh **mesh, float **field, tt_image **patch,
                              tt_lapped **cut, tt_lapped **kept)
{
    tt_patch_options po;
    tt_field_options fo;
    tt_lapped_options lo;
    tt_error err;
    memset(&po, 0, sizeof po);
    po.seed = 5;
    CHECK(tt_make_texture_patch(src, NULL, &po, NULL, patch, NULL) == TT_OK, "sheet's patch");
    CHECK(build(m, 0, mesh, &err) == TT_OK, "sheet");
    if (*mesh && *patch) {
        *field = (float *)malloc(sizeof(float) * 3 * (size_t)(*mesh)->nfaces);
        memset(&fo, 0, sizeof fo);
        fo.scale = 8.0f;
        CHECK(tt_tangent_field(*mesh, &fo, NULL, *field, &err) == TT_OK, "field: %s", err.message);
        memset(&lo, 0, sizeof lo);
        lo.seed = 7;
        CHECK(tt_lapped_paste(*mesh, *field, patch, 1, &lo, NULL, cut, &err) == TT_OK, "cut: %s", err.message);
        lo.keep_edges = 1;
        CHECK(tt_lapped_paste(*mesh, *field, patch, 1, &lo, NULL, kept, &err) == TT_OK, "kept: %s", err.message);
    }
}

/* The cut of each paste's edge: on a flat sheet, pastes of blotchy noise
   (which registration cannot line up everywhere) blend into those beneath
   where the two agree better than along the patch's own edge
   (keep_edges), and better than along the same cuts turned about each
   paste's anchor (the control, cuts as deep in the wrong places). The cut
   changes what tt_lapped_bake shows, never the coverage (the baked alpha
   is that of keep_edges). */
static void test_lapped_cut(void)
{
    tmesh g, m;
    tt_mesh *mesh = NULL;
    float *field = NULL;
    tt_image *src = NULL, *patch = NULL;
    tt_lapped *cut = NULL, *kept = NULL;
    tt_error err;
    double lattice[17][17][3], with_cut, without, turned;
    int x, y, k, points[3];
    memset(&g, 0, sizeof g);
    make_grid(&g, 40, 40);
    tm_triangulate(&g, &m);
    lcg_seed(11);
    for (y = 0; y < 17; y++)
        for (x = 0; x < 17; x++)
            for (k = 0; k < 3; k++) lattice[y][x][k] = lcg_unit();
    CHECK(tt_image_create(128, 128, NULL, &src, NULL) == TT_OK, "noise image");
    for (y = 0; y < 128; y++)
        for (x = 0; x < 128; x++) {
            const double fx = x / 8.0, fy = y / 8.0;
            const int ix = (int)fx, iy = (int)fy;
            const double tx = fx - ix, ty = fy - iy;
            for (k = 0; k < 3; k++)
                px(src, x, y)[k] = (float)((1 - ty) * ((1 - tx) * lattice[iy][ix][k] + tx * lattice[iy][ix + 1][k]) +
                                           ty * ((1 - tx) * lattice[iy + 1][ix][k] + tx * lattice[iy + 1][ix + 1][k]));
            px(src, x, y)[3] = 1.0f;
        }
    lapped_sheet_pair(&m, src, &mesh, &field, &patch, &cut, &kept);
    if (cut && kept) {
        CHECK(cut->cut && cut->cut_columns > 0 && cut->cut_feather > 0.0f, "the pastes carry their cut");
        CHECK(!kept->cut && kept->cut_columns == 0, "keep_edges: no cut");
        /* Entries under a cut are not hidden there: it shows them. */
        CHECK(cut->nentries >= kept->nentries - kept->nentries / 10,
              "the cut keeps what it shows: %d entries against %d", cut->nentries, kept->nentries);
        if (cut->cut) {
            lcg_seed(4);
            with_cut = lapped_seam_mismatch(mesh, cut, &patch, 1, &points[0]);
            without = lapped_seam_mismatch(mesh, cut, &patch, 0, &points[1]);
            turned = lapped_seam_mismatch(mesh, cut, &patch, 2, &points[2]);
            printf("     cut edges on a noise sheet: seams differ by %.4f (mean square, %d points), %.4f along the "
                   "patch's edge (%d), %.4f along the cuts turned (%d)\n",
                   with_cut, points[0], without, points[1], turned, points[2]);
            CHECK(points[0] > 1000 && with_cut <= 0.9 * without && with_cut <= 0.9 * turned,
                  "noise sheet: seams differ by %.4f with the cut, %.4f along the edge, %.4f along turned cuts: "
                  "at most 0.9 of both wanted", with_cut, without, turned);
        }
        /* The bake: the cut changes colours, never the coverage (it shows
           only what is opaque beneath); a cut without columns is refused. */
        {
            float *uv = (float *)malloc(sizeof(float) * 2 * (size_t)mesh->ncorners);
            tt_image *a = NULL, *b = NULL;
            size_t t, texels = 1024 * 1024;
            int changed = 0, alpha_same = 1, columns = cut->cut_columns;
            CHECK(tt_atlas_pack_pairs(mesh, 1024, 2, uv, &err) == TT_OK &&
                      tt_image_create(1024, 1024, NULL, &a, NULL) == TT_OK &&
                      tt_image_create(1024, 1024, NULL, &b, NULL) == TT_OK,
                  "atlas for the bakes: %s", err.message);
            if (a && b) {
                CHECK(tt_lapped_bake(mesh, cut, &patch, 1, uv, NULL, NULL, a, &err) == TT_OK, "bake, cut: %s",
                      err.message);
                cut->cut_columns = 0;
                CHECK(tt_lapped_bake(mesh, cut, &patch, 1, uv, NULL, NULL, b, &err) == TT_ERROR_INVALID_ARGUMENT,
                      "a cut of 0 columns is refused");
                cut->cut_columns = columns;
                CHECK(tt_lapped_bake(mesh, kept, &patch, 1, uv, NULL, NULL, b, &err) == TT_OK, "bake, kept: %s",
                      err.message);
                for (t = 0; t < texels; t++) {
                    for (k = 0; k < 3; k++) changed += fabsf(a->pixels[4 * t + k] - b->pixels[4 * t + k]) > 0.05f;
                    alpha_same &= fabsf(a->pixels[4 * t + 3] - b->pixels[4 * t + 3]) <= 1e-4f;
                }
                CHECK(alpha_same && changed > 100, "the cut's bake: alpha as without it (%d), %d channels changed",
                      alpha_same, changed);
            }
            tt_image_free(a);
            tt_image_free(b);
            free(uv);
        }
    }
    tt_lapped_free(cut);
    tt_lapped_free(kept);
    tt_mesh_free(mesh);
    free(field);
    tm_free(&m);
    tm_free(&g);
    tt_image_free(patch);
    tt_image_free(src);
}

/* Share of the opaque texels of a bake of a black-and-white photo that are
   grey (0.25 to 0.75) with no step of 0.25 or more to a 4-neighbour: a
   course and the mortar of another pasted over it blend to a smooth grey,
   while the bilinear edges of the bricks within one paste step sharply. */
static double lapped_grey_share(const tt_image *baked)
{
    const int w = baked->width, h = baked->height;
    long opaque = 0, grey = 0;
    int x, y, k;
    for (y = 1; y < h - 1; y++)
        for (x = 1; x < w - 1; x++) {
            const float *p = baked->pixels + 4 * ((size_t)y * (size_t)w + (size_t)x);
            const int dx[4] = {1, -1, 0, 0}, dy[4] = {0, 0, 1, -1};
            int smooth = 1;
            if (p[3] < 0.99f) continue;
            opaque++;
            if (p[0] < 0.25f || p[0] > 0.75f) continue;
            for (k = 0; k < 4; k++) {
                const float *q = baked->pixels + 4 * ((size_t)(y + dy[k]) * (size_t)w + (size_t)(x + dx[k]));
                smooth &= q[3] >= 0.99f && fabsf(q[0] - p[0]) < 0.25f;
            }
            grey += smooth;
        }
    return opaque ? (double)grey / (double)opaque : 0.0;
}

/* Ghosting: a brick photo (white bricks 13 texels high in black mortar,
   each course's bricks of its own length, 20 to 43 texels, so that no
   shift lines up every course of two pastes) pasted over a flat sheet and
   baked. With the cut, the pastes' soft edges are narrowed
   (TT_LAPPED_CUT_BLEND), so the bake shows one course where pastes
   overlap; the control, keep_edges, blends the whole soft edge (the
   patch's alpha and the fade) and must show clearly more smooth grey
   (measured: 0.0044 against 0.0082). The photo itself, resampled at the
   bake's density, is the floor. */
static void test_lapped_ghosting(void)
{
    tmesh g, m;
    tt_mesh *mesh = NULL;
    float *field = NULL, *uv = NULL;
    tt_image *src = NULL, *patch = NULL, *baked = NULL;
    tt_lapped *cut = NULL, *kept = NULL;
    tt_error err;
    double narrow = 1.0, wide = 0.0, floor_share;
    int x, y, k, period[8], joint[8];
    memset(&g, 0, sizeof g);
    make_grid(&g, 40, 40);
    tm_triangulate(&g, &m);
    lcg_seed(9);
    for (k = 0; k < 8; k++) {
        period[k] = 20 + (int)(lcg_unit() * 24.0);
        joint[k] = (int)(lcg_unit() * period[k]);
    }
    CHECK(tt_image_create(128, 128, NULL, &src, NULL) == TT_OK, "brick image");
    for (y = 0; y < 128; y++)
        for (x = 0; x < 128; x++) {
            const int course = y / 16, along = (x + joint[course]) % period[course];
            const float value = y % 16 < 3 || along < 3 ? 0.0f : 1.0f;
            for (k = 0; k < 3; k++) px(src, x, y)[k] = value;
            px(src, x, y)[3] = 1.0f;
        }
    lapped_sheet_pair(&m, src, &mesh, &field, &patch, &cut, &kept);
    /* The floor: the photo itself resampled at the bake's density (the
       sheet is 40 units, 5 patches of 8, on 1024 texels: about 1.6 texels
       per patch texel). */
    {
        tt_image *resampled = NULL;
        CHECK(tt_image_create(205, 205, NULL, &resampled, NULL) == TT_OK, "resampled photo");
        for (y = 0; resampled && y < 205; y++)
            for (x = 0; x < 205; x++)
                tt_image_sample_bilinear(src, (float)((x + 0.5) * 128.0 / 205.0), (float)((y + 0.5) * 128.0 / 205.0),
                                         resampled->pixels + 4 * ((size_t)y * 205 + (size_t)x));
        floor_share = resampled ? lapped_grey_share(resampled) : 1.0;
        tt_image_free(resampled);
    }
    if (cut && kept) {
        uv = (float *)malloc(sizeof(float) * 2 * (size_t)mesh->ncorners);
        CHECK(tt_atlas_pack_pairs(mesh, 1024, 2, uv, &err) == TT_OK &&
                  tt_image_create(1024, 1024, NULL, &baked, NULL) == TT_OK,
              "atlas for the bakes: %s", err.message);
        if (baked) {
            CHECK(tt_lapped_bake(mesh, cut, &patch, 1, uv, NULL, NULL, baked, &err) == TT_OK, "bake, cut: %s",
                  err.message);
            narrow = lapped_grey_share(baked);
            CHECK(tt_lapped_bake(mesh, kept, &patch, 1, uv, NULL, NULL, baked, &err) == TT_OK, "bake, kept: %s",
                  err.message);
            wide = lapped_grey_share(baked);
        }
        printf("     ghosting on a brick sheet: %.4f of the baked texels smooth grey with the cut's narrow edges, %.4f "
               "with the whole soft edge (keep_edges); %.4f in the photo itself\n", narrow, wide, floor_share);
        CHECK(wide >= 0.004 && narrow - floor_share <= 0.65 * (wide - floor_share),
              "brick sheet: %.4f of the baked texels smooth grey with the cut, %.4f with keep_edges, %.4f in the "
              "photo: keep_edges at least 0.004, and the cut's excess over the photo at most 0.65 of keep_edges's "
              "wanted", narrow, wide, floor_share);
    }
    tt_image_free(baked);
    free(uv);
    tt_lapped_free(cut);
    tt_lapped_free(kept);
    tt_mesh_free(mesh);
    free(field);
    tm_free(&m);
    tm_free(&g);
    tt_image_free(patch);
    tt_image_free(src);
}

/* On the walls (projected up at least FIELD_WALL long): the mean and 90th
   percentile of the angle (degrees) between the pasted texture's up - the
   direction on the face that each entry's UVs map to (0, 1) - and the
   projected up, over the entries. Independent of the field. */
static int lapped_wall_angles(const tt_mesh *mesh, const tt_lapped *lapped, const double up[3], double *mean,
                              double *p90)
{
    double *angle = (double *)malloc(sizeof(double) * (size_t)(lapped->nentries + 1)), sum = 0.0;
    int e, k, n = 0;
    for (e = 0; e < lapped->nentries; e++) {
        const int f = lapped->faces[e];
        const float *p0 = mesh->pos + 3 * mesh->corner_vert[3 * f], *p1 = mesh->pos + 3 * mesh->corner_vert[3 * f + 1];
        const float *p2 = mesh->pos + 3 * mesh->corner_vert[3 * f + 2], *uv = lapped->uv + 6 * (size_t)e;
        const double du1 = uv[2] - uv[0], dv1 = uv[3] - uv[1], du2 = uv[4] - uv[0], dv2 = uv[5] - uv[1];
        const double det = du1 * dv2 - du2 * dv1;
        double p[3], dir[3];
        if (field_projected_up(mesh, f, up, p) < FIELD_WALL) continue;
        for (k = 0; k < 3; k++)
            dir[k] = det != 0.0 ? (-du2 * ((double)p1[k] - p0[k]) + du1 * ((double)p2[k] - p0[k])) / det : 0.0;
        angle[n] = fv_angle(dir, p) * 180.0 / 3.14159265358979323846;
        sum += angle[n++];
    }
    qsort(angle, (size_t)n, sizeof *angle, compare_doubles);
    *mean = n ? sum / n : 0.0;
    *p90 = n ? angle[(int)(0.9 * (n - 1))] : 0.0;
    free(angle);
    return n;
}

/* The pasted texture stands up on walls: on the bumpy sphere the pastes'
   up is within 5 degrees of the projected up on average, 12 at the 90th
   percentile. The control pastes along a field turned 15 degrees from up
   on every face, and the measure sees it. */
static void test_lapped_walls(void)
{
    const double up[3] = {0.0, 1.0, 0.0};
    tmesh m;
    tt_mesh *mesh = NULL;
    tt_image *patch = lapped_patch(48, 3);
    tt_field_options fo;
    tt_lapped_options lo;
    tt_lapped *lapped = NULL, *turned = NULL;
    tt_error err;
    float *field;
    double mean = 0.0, p90 = 0.0, turned_mean = 0.0, turned_p90 = 0.0;
    int f, k, n = 0;
    make_bumpy_sphere(&m);
    CHECK(build(&m, 0, &mesh, &err) == TT_OK, "bumpy sphere builds: %s", err.message);
    field = (float *)malloc(sizeof(float) * 3 * (size_t)mesh->nfaces);
    memset(&fo, 0, sizeof fo);
    fo.scale = 0.6f;
    memset(&lo, 0, sizeof lo);
    lo.seed = 2;
    CHECK(tt_tangent_field(mesh, &fo, NULL, field, &err) == TT_OK, "bumpy sphere field: %s", err.message);
    if (tt_lapped_paste(mesh, field, &patch, 1, &lo, NULL, &lapped, &err) == TT_OK)
        n = lapped_wall_angles(mesh, lapped, up, &mean, &p90);
    CHECK(lapped && n > 1000 && mean <= 5.0 && p90 <= 12.0,
          "bumpy sphere: on %d wall entries the pasted up is %.3g degrees from the projected up on average, %.3g at "
          "the 90th percentile (at most 5 and 12 wanted)", n, mean, p90);
    /* The control: every vector turned 15 degrees about its face's normal. */
    for (f = 0; f < mesh->nfaces; f++) {
        float nrm[3], v[3], side[3];
        const double c = cos(15.0 * 3.14159265358979323846 / 180.0), s = sin(15.0 * 3.14159265358979323846 / 180.0);
        tt_face_normal(mesh, f, nrm);
        for (k = 0; k < 3; k++) v[k] = field[3 * f + k];
        side[0] = nrm[1] * v[2] - nrm[2] * v[1];
        side[1] = nrm[2] * v[0] - nrm[0] * v[2];
        side[2] = nrm[0] * v[1] - nrm[1] * v[0];
        for (k = 0; k < 3; k++) field[3 * f + k] = (float)(c * v[k] + s * side[k]);
    }
    if (tt_lapped_paste(mesh, field, &patch, 1, &lo, NULL, &turned, &err) == TT_OK)
        lapped_wall_angles(mesh, turned, up, &turned_mean, &turned_p90);
    CHECK(turned && turned_mean > 10.0, "control: pasted along a field turned 15 degrees, the walls' pasted up is "
          "%.3g degrees from up on average", turned_mean);
    printf("     pasted up on the bumpy sphere's walls: %.2f degrees from up on average, p90 %.2f (control, field "
           "turned 15 degrees: %.2f, %.2f)\n", mean, p90, turned_mean, turned_p90);
    tt_lapped_free(lapped);
    tt_lapped_free(turned);
    tt_mesh_free(mesh);
    free(field);
    tm_free(&m);
    tt_image_free(patch);
}

/* Each triangle of a triangle mesh cut 1-to-4 at its edges' midpoints, in
   place: the shape stays, the triangles are 4 times as many (as
   bench/bench_subdivide.awk cuts the horse). */
static void tm_cut_1_to_4(tmesh *m)
{
    tmesh out;
    int *mid, *next, *first, f, i, nv = m->nv;
    memset(&out, 0, sizeof out);
    for (i = 0; i < nv; i++) tm_vert(&out, m->pos[3 * i], m->pos[3 * i + 1], m->pos[3 * i + 2]);
    /* midpoint of edge (a, b), a < b: a list per vertex a of (b, midpoint) */
    mid = (int *)malloc(sizeof(int) * 6 * (size_t)m->nf);
    next = (int *)malloc(sizeof(int) * 3 * (size_t)m->nf);
    first = (int *)malloc(sizeof(int) * (size_t)nv);
    for (i = 0; i < nv; i++) first[i] = -1;
    for (f = 0; f < m->nf; f++) {
        int k, v[3], w[3];
        for (k = 0; k < 3; k++) v[k] = m->idx[3 * f + k];
        for (k = 0; k < 3; k++) {
            int a = v[k] < v[(k + 1) % 3] ? v[k] : v[(k + 1) % 3], b = v[k] + v[(k + 1) % 3] - a, e;
            for (e = first[a]; e >= 0 && mid[2 * e] != b; e = next[e]) {}
            if (e < 0) {
                e = 3 * f + k;
                mid[2 * e] = b;
                mid[2 * e + 1] = tm_vert(&out, 0.5 * (m->pos[3 * a] + m->pos[3 * b]),
                                         0.5 * (m->pos[3 * a + 1] + m->pos[3 * b + 1]),
                                         0.5 * (m->pos[3 * a + 2] + m->pos[3 * b + 2]));
                next[e] = first[a];
                first[a] = e;
            }
            w[k] = mid[2 * e + 1];
        }
        tm_tri(&out, v[0], w[0], w[2]);
        tm_tri(&out, w[0], v[1], w[1]);
        tm_tri(&out, w[2], w[1], v[2]);
        tm_tri(&out, w[0], w[1], w[2]);
    }
    free(mid);
    free(next);
    free(first);
    tm_free(m);
    *m = out;
}

/* A paste covers about the same surface whatever the density of the
   triangles under it: a bumpy sphere (2208 triangles), and the same cut
   1-to-4 twice (35328), where each triangle is 16 of the same surface.
   Measured by the faces each paste recorded (its entries, hidden ones
   included), per paste, as a share of the faces: 0.130 and 0.169. Growth once placed the paste's vertices by the
   unfolding alone, which drifts in scale at random, more the finer the
   mesh, and growth nearest first follows where it shrank: 0.136 and 0.276
   here, and at a million triangles of the horse ten times the surface the
   patch covers. */
static void test_lapped_density(void)
{
    tt_image *patch = lapped_patch(64, 5);
    double per_paste[2] = {0.0, 0.0};
    int level;
    for (level = 0; level < 2; level++) {
        tmesh m, sphere;
        tt_mesh *mesh;
        float *field;
        tt_lapped *lapped = NULL;
        int i;
        memset(&sphere, 0, sizeof sphere);
        make_field_sphere(&sphere, 24, 48, 1.0);
        tm_triangulate(&sphere, &m);
        tm_free(&sphere);
        for (i = 0; i < m.nv; i++) {
            float *p = m.pos + 3 * i;
            double r = 1.0 + 0.15 * sin(7.0 * p[0]) * sin(6.0 * p[1]) * sin(5.0 * p[2] + 1.0);
            p[0] *= (float)r;
            p[1] *= (float)r;
            p[2] *= (float)r;
        }
        for (i = 0; i < 2 * level; i++) tm_cut_1_to_4(&m);
        if (lapped_run(&m, 0, 3, 2.0f, &mesh, &field, patch, &lapped) == 0) {
            per_paste[level] = (double)(lapped->nentries + lapped->removed_entries) / lapped->npastes / mesh->nfaces;
            DETAIL("density: %d triangles, %d pastes, %.4g of the faces recorded per paste", mesh->nfaces,
                   lapped->npastes, per_paste[level]);
        }
        tt_lapped_free(lapped);
        tt_mesh_free(mesh);
        free(field);
        tm_free(&m);
    }
    CHECK(per_paste[1] > 0.6 * per_paste[0] && per_paste[1] < 1.5 * per_paste[0],
          "a paste records %.4g of the bumpy sphere's faces, %.4g of it cut to 16 times the triangles",
          per_paste[0], per_paste[1]);
    tt_image_free(patch);
}

static void test_lapped_determinism(void)
{
    tmesh m;
    tt_mesh *mesh[3];
    float *field[3];
    tt_image *patch;
    tt_lapped *out[3];
    int i, same, differ;
    make_lapped_shape(&m, 3);
    patch = lapped_patch(48, 2);
    for (i = 0; i < 3; i++) lapped_run(&m, 0, i == 2 ? 8 : 7, 0.0f, &mesh[i], &field[i], patch, &out[i]);
    same = differ = 0;
    if (out[0] && out[1] && out[2]) {
        same = out[0]->nentries == out[1]->nentries && out[0]->npastes == out[1]->npastes &&
               memcmp(out[0]->faces, out[1]->faces, sizeof(int) * (size_t)out[0]->nentries) == 0 &&
               memcmp(out[0]->uv, out[1]->uv, sizeof(float) * 6 * (size_t)out[0]->nentries) == 0;
        differ = out[0]->nentries != out[2]->nentries ||
                 memcmp(out[0]->uv, out[2]->uv,
                        sizeof(float) * 6 *
                            (size_t)(out[0]->nentries < out[2]->nentries ? out[0]->nentries : out[2]->nentries)) != 0;
    }
    CHECK(same, "the same seed gave different pastes");
    CHECK(differ, "different seeds gave the same pastes");
    for (i = 0; i < 3; i++) {
        tt_lapped_free(out[i]);
        tt_mesh_free(mesh[i]);
        free(field[i]);
    }
    tm_free(&m);
    tt_image_free(patch);
}

/* The sphere of make_lapped_shape built, with its default field (*field,
   malloc'ed). */
static tt_mesh *lapped_sphere(tmesh *m, float **field)
{
    tt_mesh *mesh = NULL;
    tt_error err;
    make_lapped_shape(m, 0);
    CHECK(build(m, 0, &mesh, &err) == TT_OK, "sphere builds: %s", err.message);
    *field = (float *)malloc(sizeof(float) * 3 * (size_t)mesh->nfaces);
    CHECK(tt_tangent_field(mesh, NULL, NULL, *field, &err) == TT_OK, "sphere field: %s", err.message);
    return mesh;
}

/* Across the edges where the paste on top changes, how often both sides
   show the same patch; *random gets what random picks would give (the sum
   of the patches' squared shares of the pastes, times the edges). */
static int lapped_same_patch_edges(const tt_mesh *mesh, const tt_lapped *out, int npatches, int *changes,
                                   double *random)
{
    int *top = (int *)malloc(sizeof(int) * (size_t)mesh->nfaces), *used = (int *)calloc((size_t)npatches, sizeof(int));
    int f, p, e, c, same = 0;
    for (f = 0; f < mesh->nfaces; f++) top[f] = -1;
    for (p = 0; p < out->npastes; p++) {
        used[out->pastes[p].patch]++;
        for (e = out->pastes[p].first; e < out->pastes[p].first + out->pastes[p].nfaces; e++) top[out->faces[e]] = p;
    }
    *changes = 0;
    for (c = 0; c < mesh->ncorners; c++) {
        int t = mesh->twin[c], a, b;
        if (t < c || (a = top[mesh->corner_face[c]]) < 0 || (b = top[mesh->corner_face[t]]) < 0 || a == b) continue;
        (*changes)++;
        same += out->pastes[a].patch == out->pastes[b].patch;
    }
    *random = 0.0;
    for (p = 0; p < npatches; p++) *random += ((double)used[p] / out->npastes) * ((double)used[p] / out->npastes);
    *random *= *changes;
    free(top);
    free(used);
    return same;
}

/* At most `share` of the random picks' borders with one patch on both sides
   (counts from lapped_same_patch_edges, summed over runs). */
static void check_patch_borders(int same, int changes, double random, double share, const char *what)
{
    CHECK(changes > 0 && same <= share * random, "%s: %d of %d edges where the paste on top changes show one patch "
          "on both sides (random picks: about %.0f)", what, same, changes, random);
    printf("     %s: one patch on both sides of %d of %d top changes (random picks: about %.0f)\n", what, same, changes,
           random);
}

/* Several texture patches: all get used, the mesh is covered with the
   right patch's alpha, and a paste avoids the patches around its seed:
   across the edges where the paste on top changes, both sides show the same
   patch less often than random picks would (the control). */
static void test_lapped_patches(void)
{
    tmesh m;
    tt_mesh *mesh;
    tt_lapped_options lo;
    tt_lapped *out = NULL;
    tt_error err;
    tt_image *patches[3];
    float *field;
    int used[3] = {0, 0, 0}, p, f, bad = 0;
    tt_result r;
    mesh = lapped_sphere(&m, &field);
    patches[0] = lapped_patch(48, 1);
    patches[1] = lapped_patch(64, 2);
    patches[2] = lapped_patch(40, 3);
    memset(&lo, 0, sizeof lo);
    lo.seed = 5;
    r = tt_lapped_paste(mesh, field, patches, 3, &lo, NULL, &out, &err);
    CHECK(r == TT_OK && out, "three patches: %d %s", r, err.message);
    if (out) {
        for (p = 0; p < out->npastes; p++)
            if (out->pastes[p].patch >= 0 && out->pastes[p].patch < 3) used[out->pastes[p].patch]++;
            else bad++;
        CHECK(bad == 0 && used[0] > 0 && used[1] > 0 && used[2] > 0, "patches used %d %d %d, %d out of range",
              used[0], used[1], used[2], bad);
        for (f = 0; f < mesh->nfaces; f++) {
            double w[3] = {1.0 / 3.0, 1.0 / 3.0, 1.0 / 3.0};
            if (lapped_alpha_at(out, patches, f, w) < 0.98) bad++;
        }
        CHECK(bad == 0, "three patches: %d face centres not opaque", bad);
        int changes = 0, same;
        double random = 0.0;
        same = lapped_same_patch_edges(mesh, out, 3, &changes, &random);
        check_patch_borders(same, changes, random, 0.85, "three patches of three masks");
    }
    tt_lapped_free(out);
    for (p = 0; p < 3; p++) tt_image_free(patches[p]);
    tt_mesh_free(mesh);
    free(field);
    tm_free(&m);
}

/* Patches of one mask (windows of one photo, as the tool cuts them) are
   interchangeable once a paste's faces are known: each paste takes the one
   its faces show least, so neighbours rarely share a patch; against the
   random pick as control. */
static void test_lapped_patch_twins(void)
{
    tmesh m;
    tt_mesh *mesh;
    tt_lapped_options lo;
    tt_lapped *out = NULL;
    tt_error err;
    tt_image *patches[3] = {NULL, NULL, NULL};
    float *field;
    int p, same_sum = 0, changes_sum = 0;
    double random_sum = 0.0;
    size_t i;
    mesh = lapped_sphere(&m, &field);
    patches[0] = lapped_patch(64, 4);
    for (p = 1; p < 3 && patches[0]; p++) {
        CHECK(tt_image_create(64, 64, NULL, &patches[p], &err) == TT_OK, "patch copy: %s", err.message);
        if (!patches[p]) continue;
        for (i = 0; i < 4 * 64 * 64; i++)
            patches[p]->pixels[i] = i % 4 == 3 ? patches[0]->pixels[i] : patches[0]->pixels[i] * (float)(1.0 - 0.3 * p);
    }
    memset(&lo, 0, sizeof lo);
    /* Over several seeds: one paste order alone varies by a tenth. */
    for (lo.seed = 1; lo.seed <= 6 && patches[1] && patches[2]; lo.seed++) {
        int changes = 0;
        double random = 0.0;
        CHECK(tt_lapped_paste(mesh, field, patches, 3, &lo, NULL, &out, &err) == TT_OK && out, "three twins: %s",
              err.message);
        if (!out) continue;
        same_sum += lapped_same_patch_edges(mesh, out, 3, &changes, &random);
        changes_sum += changes;
        random_sum += random;
        tt_lapped_free(out);
        out = NULL;
    }
    check_patch_borders(same_sum, changes_sum, random_sum, 0.6, "three patches of one mask, six seeds");
    for (p = 0; p < 3; p++) tt_image_free(patches[p]);
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
    if (fraction < p->last || fraction > 1.0f || !(fraction >= 0.0f)) p->decreasing = 1;
    p->last = fraction;
    return ++p->calls == p->cancel_at;
}

/* A lapped-function error: result, err.result, a message, no run of more
   than 12 digits in it (numbers are printed compactly), *out reset. */
#define LAPPED_EXPECT(r_, out_, code, what)                                                                      \
    do {                                                                                                         \
        CHECK((r_) == (code) && err.result == (code) && err.message[0] != '\0' &&                                \
                  longest_digit_run(err.message) <= 12 && (out_) == NULL,                                        \
              "%s: expected %d, got %d (err.result %d, out %p): %s", what, (int)(code), (int)(r_), (int)err.result, \
              (void *)(out_), err.message);                                                                      \
    } while (0)

static void test_lapped_errors(void)
{
    tmesh m, q;
    tt_mesh *mesh = NULL, *quads = NULL;
    float *field;
    tt_image *patch, empty, *clear = NULL, *two[2];
    tt_lapped *out = NULL;
    tt_lapped_options lo;
    tt_field_options fo;
    tt_error err;
    tt_result r;
    lapped_progress prog;
    tt_allocator half;
    make_lapped_shape(&m, 0);
    CHECK(build(&m, 0, &mesh, &err) == TT_OK, "sphere builds: %s", err.message);
    field = (float *)malloc(sizeof(float) * 3 * (size_t)mesh->nfaces);
    memset(&fo, 0, sizeof fo);
    tt_tangent_field(mesh, &fo, NULL, field, &err);
    patch = lapped_patch(32, 1);
    memset(&empty, 0, sizeof empty);
    tt_image_create(16, 16, NULL, &clear, NULL);
    memset(&lo, 0, sizeof lo);

    out = &g_lapped_sentinel;
    r = tt_lapped_paste(NULL, field, &patch, 1, NULL, NULL, &out, &err);
    LAPPED_EXPECT(r, out, TT_ERROR_INVALID_ARGUMENT, "NULL mesh");
    out = &g_lapped_sentinel;
    r = tt_lapped_paste(mesh, NULL, &patch, 1, NULL, NULL, &out, &err);
    LAPPED_EXPECT(r, out, TT_ERROR_INVALID_ARGUMENT, "NULL field");
    r = tt_lapped_paste(mesh, field, NULL, 1, NULL, NULL, &out, &err);
    LAPPED_EXPECT(r, out, TT_ERROR_INVALID_ARGUMENT, "NULL patches");
    CHECK(tt_lapped_paste(mesh, field, &patch, 1, NULL, NULL, NULL, &err) == TT_ERROR_INVALID_ARGUMENT, "NULL out");
    r = tt_lapped_paste(mesh, field, &patch, 0, NULL, NULL, &out, &err);
    LAPPED_EXPECT(r, out, TT_ERROR_INVALID_ARGUMENT, "no patches");
    memset(&half, 0, sizeof half);
    {
        counter hc;
        tt_allocator full = make_allocator(&hc, -1);
        half.alloc = full.alloc;   /* alloc without free */
        half.user_data = &hc;
        out = &g_lapped_sentinel;
        r = tt_lapped_paste(mesh, field, &patch, 1, NULL, &half, &out, &err);
        LAPPED_EXPECT(r, out, TT_ERROR_INVALID_ARGUMENT, "allocator with alloc but no free");
        CHECK(hc.calls == 0, "a refused allocator is not used: %ld calls", hc.calls);
    }
    out = &g_lapped_sentinel;
    r = tt_lapped_paste(mesh, field, &clear, 1, NULL, NULL, &out, &err);
    LAPPED_EXPECT(r, out, TT_ERROR_INVALID_ARGUMENT, "transparent patch");
    CHECK(strstr(err.message, "no opaque") != NULL && err.item == 0, "transparent patch: item %d, %s", err.item,
          err.message);
    lo.max_pastes = -1;
    r = tt_lapped_paste(mesh, field, &patch, 1, &lo, NULL, &out, &err);
    LAPPED_EXPECT(r, out, TT_ERROR_INVALID_ARGUMENT, "max_pastes < 0");
    lo.max_pastes = 0;

    /* The patches array: a NULL entry, an empty image and one with no opaque
       texel are named by their index in error->item. */
    two[0] = patch;
    two[1] = NULL;
    out = &g_lapped_sentinel;
    r = tt_lapped_paste(mesh, field, two, 2, NULL, NULL, &out, &err);
    LAPPED_EXPECT(r, out, TT_ERROR_INVALID_ARGUMENT, "NULL patches[1]");
    CHECK(err.item == 1 && msg_has_number(err.message, 1), "NULL patches[1]: item %d (want 1): %s", err.item,
          err.message);
    two[1] = &empty;
    r = tt_lapped_paste(mesh, field, two, 2, NULL, NULL, &out, &err);
    LAPPED_EXPECT(r, out, TT_ERROR_INVALID_ARGUMENT, "empty patches[1]");
    CHECK(err.item == 1, "empty patches[1]: item %d (want 1): %s", err.item, err.message);
    two[1] = clear;
    r = tt_lapped_paste(mesh, field, two, 2, NULL, NULL, &out, &err);
    LAPPED_EXPECT(r, out, TT_ERROR_INVALID_ARGUMENT, "transparent patches[1]");
    CHECK(err.item == 1 && strstr(err.message, "texture patch 1 has no opaque texel") != NULL,
          "transparent patches[1]: item %d (want 1): %s", err.item, err.message);
    two[0] = clear;
    two[1] = patch;
    r = tt_lapped_paste(mesh, field, two, 2, NULL, NULL, &out, &err);
    LAPPED_EXPECT(r, out, TT_ERROR_INVALID_ARGUMENT, "transparent patches[0]");
    CHECK(err.item == 0 && strstr(err.message, "texture patch 0 has no opaque texel") != NULL,
          "transparent patches[0]: item %d (want 0): %s", err.item, err.message);

    /* field vectors: zero, NaN, perpendicular to the face */
    {
        float saved[3];
        memcpy(saved, field + 3 * 5, sizeof saved);
        field[15] = field[16] = field[17] = 0.0f;
        r = tt_lapped_paste(mesh, field, &patch, 1, NULL, NULL, &out, &err);
        LAPPED_EXPECT(r, out, TT_ERROR_INVALID_ARGUMENT, "zero field vector");
        CHECK(err.face == 5 && strstr(err.message, "zero length"), "zero field vector: %d %d %s", r, err.face,
              err.message);
        field[16] = (float)internal_not_a_number();
        r = tt_lapped_paste(mesh, field, &patch, 1, NULL, NULL, &out, &err);
        LAPPED_EXPECT(r, out, TT_ERROR_NON_FINITE, "NaN field vector");
        CHECK(err.face == 5, "NaN field vector: face %d: %s", err.face, err.message);
        tt_face_normal(mesh, 5, field + 15);
        r = tt_lapped_paste(mesh, field, &patch, 1, NULL, NULL, &out, &err);
        LAPPED_EXPECT(r, out, TT_ERROR_INVALID_ARGUMENT, "normal as field vector");
        CHECK(err.face == 5 && strstr(err.message, "perpendicular"), "normal as field vector: %d %s", r,
              err.message);
        memcpy(field + 15, saved, sizeof saved);
    }
    /* a patch larger than the mesh, and ones so small it would take forever */
    {
        float *big = (float *)malloc(sizeof(float) * 3 * (size_t)mesh->nfaces);
        fo.scale = 5.0f;
        tt_tangent_field(mesh, &fo, NULL, big, &err);
        r = tt_lapped_paste(mesh, big, &patch, 1, NULL, NULL, &out, &err);
        LAPPED_EXPECT(r, out, TT_ERROR_INVALID_ARGUMENT, "patch larger than the mesh");
        CHECK(strstr(err.message, "larger than the mesh") != NULL, "patch larger than the mesh: %s", err.message);
        fo.scale = 1e-4f;
        tt_tangent_field(mesh, &fo, NULL, big, &err);
        r = tt_lapped_paste(mesh, big, &patch, 1, NULL, NULL, &out, &err);
        LAPPED_EXPECT(r, out, TT_ERROR_TOO_LARGE, "tiny patches");
        CHECK(strstr(err.message, "pastes") != NULL, "tiny patches: %s", err.message);
        /* max_pastes only lowers the compile-time limit: asking for more is held to it. */
        lo.max_pastes = INT_MAX;
        out = &g_lapped_sentinel;
        r = tt_lapped_paste(mesh, big, &patch, 1, &lo, NULL, &out, &err);
        LAPPED_EXPECT(r, out, TT_ERROR_TOO_LARGE, "tiny patches with max_pastes INT_MAX");
        CHECK(msg_has_number(err.message, TT_LAPPED_MAX_PASTES), "max_pastes INT_MAX: the limit %d holds: %s",
              TT_LAPPED_MAX_PASTES, err.message);
        lo.max_pastes = 0;
        /* Astronomically many pastes (about 1e60): the message stays short
           and gives the estimate in %g form, not 61 digits. */
        fo.scale = 1e-30f;
        CHECK(tt_tangent_field(mesh, &fo, NULL, big, &err) == TT_OK, "field of scale 1e-30: %s", err.message);
        out = &g_lapped_sentinel;
        r = tt_lapped_paste(mesh, big, &patch, 1, NULL, NULL, &out, &err);
        LAPPED_EXPECT(r, out, TT_ERROR_TOO_LARGE, "patches of 1e-30 mesh units");
        CHECK(strstr(err.message, "e+") != NULL && strlen(err.message) < 200 &&
                  longest_digit_run(err.message) <= 12,
              "patches of 1e-30 mesh units: the estimate in %%g form, short: %s", err.message);
        free(big);
    }
    /* progress after every paste, never decreasing, ending at 1 */
    memset(&prog, 0, sizeof prog);
    prog.cancel_at = -1;
    lo.progress = lapped_progress_fn;
    lo.progress_user_data = &prog;
    r = tt_lapped_paste(mesh, field, &patch, 1, &lo, NULL, &out, &err);
    CHECK(r == TT_OK && out && prog.calls >= out->npastes && !prog.decreasing && prog.last == 1.0f,
          "progress: %d calls for %d pastes, last %g, decreasing %d", prog.calls, out ? out->npastes : -1,
          prog.last, prog.decreasing);
    tt_lapped_free(out);
    out = NULL;
    /* one paste short of what it takes */
    lo.max_pastes = prog.calls - 1;
    out = &g_lapped_sentinel;
    r = tt_lapped_paste(mesh, field, &patch, 1, &lo, NULL, &out, &err);
    LAPPED_EXPECT(r, out, TT_ERROR_NOT_CONVERGED, "one paste short");
    CHECK(strstr(err.message, "uncovered") != NULL, "max_pastes %d: %d %s", lo.max_pastes, r, err.message);
    lo.max_pastes = 0;
    memset(&prog, 0, sizeof prog);
    prog.cancel_at = 3;
    out = &g_lapped_sentinel;
    r = tt_lapped_paste(mesh, field, &patch, 1, &lo, NULL, &out, &err);
    LAPPED_EXPECT(r, out, TT_CANCELLED, "cancel");
    CHECK(prog.calls == 3, "cancel: %d after %d calls", r, prog.calls);

    /* not triangles */
    memset(&q, 0, sizeof q);
    make_grid(&q, 3, 3);
    CHECK(build(&q, 0, &quads, &err) == TT_OK, "grid builds: %s", err.message);
    {
        float *qf = (float *)malloc(sizeof(float) * 3 * (size_t)quads->nfaces);
        tt_tangent_field(quads, &fo, NULL, qf, &err);
        r = tt_lapped_paste(quads, qf, &patch, 1, NULL, NULL, &out, &err);
        LAPPED_EXPECT(r, out, TT_ERROR_INVALID_ARGUMENT, "quads");
        CHECK(err.face == 0 && strstr(err.message, "triangle"), "quads: %d %s", r, err.message);
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
        CHECK(build(&z, TT_MESH_PERMISSIVE, &zm, &err) == TT_OK, "permissive sliver mesh builds: %s", err.message);
        if (zm) {
            r = tt_lapped_paste(zm, zf, &patch, 1, NULL, NULL, &out, &err);
            LAPPED_EXPECT(r, out, TT_ERROR_ZERO_AREA_FACE, "zero-area face");
            CHECK(err.face == 1, "zero-area face: face %d: %s", err.face, err.message);
        }
        tt_mesh_free(zm);
        tm_free(&z);
    }
    tt_image_free(clear);
    tt_image_free(patch);
    tt_mesh_free(mesh);
    free(field);
    tm_free(&m);
}

typedef struct lapped_oom_ctx {
    const tt_mesh *mesh;
    const float *field;
    tt_image *patch;
    int isotropic;
} lapped_oom_ctx;

static tt_result lapped_oom_call(void *ctx, const tt_allocator *al, tt_error *error)
{
    lapped_oom_ctx *c = (lapped_oom_ctx *)ctx;
    tt_lapped_options lo;
    tt_lapped *out = &g_lapped_sentinel;   /* must be reset to NULL on failure */
    tt_result r;
    memset(&lo, 0, sizeof lo);
    lo.isotropic = c->isotropic;
    r = tt_lapped_paste(c->mesh, c->field, &c->patch, 1, &lo, al, &out, error);
    if (r != TT_OK && (out != NULL || error->result != r)) return TT_RESULT_MAX_ENUM;
    if (r == TT_OK && (!out || out->nentries <= 0)) return TT_RESULT_MAX_ENUM;
    tt_lapped_free(out);
    return r;
}

static void test_lapped_oom(void)
{
    tmesh m;
    tt_mesh *mesh = NULL;
    tt_field_options fo;
    tt_error err;
    float *field;
    tt_image *patch;
    lapped_oom_ctx c;
    memset(&m, 0, sizeof m);
    make_field_sphere(&m, 5, 6, 1.0);
    {
        tmesh t;
        tm_triangulate(&m, &t);
        tm_free(&m);
        m = t;
    }
    CHECK(build(&m, 0, &mesh, &err) == TT_OK, "small sphere builds: %s", err.message);
    field = (float *)malloc(sizeof(float) * 3 * (size_t)mesh->nfaces);
    memset(&fo, 0, sizeof fo);
    fo.scale = 2.0f;
    tt_tangent_field(mesh, &fo, NULL, field, &err);
    patch = lapped_patch(32, 4);
    oom_reset();
    c.mesh = mesh;
    c.field = field;
    c.patch = patch;
    c.isotropic = 0;
    oom_sweep("tt_lapped_paste", lapped_oom_call, &c, TT_OK);
    c.isotropic = 1;
    oom_sweep("tt_lapped_paste(isotropic)", lapped_oom_call, &c, TT_OK);
    tt_image_free(patch);
    tt_mesh_free(mesh);
    free(field);
    tm_free(&m);
}

/* ------------------------------------------------------------------------ */
/* 7d. Patch hulls (Sec. 3.3, Fig. 4)                                       */
/* ------------------------------------------------------------------------ */

/* A transparent w x h image. */
static tt_image *hull_image(int w, int h)
{
    tt_image *img = NULL;
    tt_result r = tt_image_create(w, h, NULL, &img, NULL);
    CHECK(r == TT_OK && img, "tt_image_create(%d, %d): %d", w, h, (int)r);
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
    double o1 = internal_orient2(a[0], a[1], b[0], b[1], c[0], c[1]), o2 = internal_orient2(a[0], a[1], b[0], b[1], d[0], d[1]);
    double o3 = internal_orient2(c[0], c[1], d[0], d[1], a[0], a[1]), o4 = internal_orient2(c[0], c[1], d[0], d[1], b[0], b[1]);
    if (((o1 > 0 && o2 < 0) || (o1 < 0 && o2 > 0)) && ((o3 > 0 && o4 < 0) || (o3 < 0 && o4 > 0))) return 1;
    return internal_point_on_segment(c[0], c[1], a[0], a[1], b[0], b[1]) ||
           internal_point_on_segment(d[0], d[1], a[0], a[1], b[0], b[1]) ||
           internal_point_on_segment(a[0], a[1], c[0], c[1], d[0], d[1]) ||
           internal_point_on_segment(b[0], b[1], c[0], c[1], d[0], d[1]);
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
                if (internal_point_on_segment(d[0], d[1], a[0], a[1], b[0], b[1]) ||
                    internal_point_on_segment(a[0], a[1], c[0], c[1], d[0], d[1]))
                    return 0;
            } else if ((j + 1) % n == i) {
                if (internal_point_on_segment(c[0], c[1], a[0], a[1], b[0], b[1]) ||
                    internal_point_on_segment(b[0], b[1], c[0], c[1], d[0], d[1]))
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
        double o = internal_orient2(a[0], a[1], b[0], b[1], x, y);
        if (internal_point_segment_distance(x, y, a[0], a[1], b[0], b[1]) <= eps) return 1;
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
    if (internal_hull_convex(img, NULL, &xs, &ys, &n) != TT_OK) return -1.0;
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
    tt_result r = internal_patch_hull(img, max_vertices, NULL, &xy, &n);
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
    tt_image *img;
    lcg_seed(1234);

    img = hull_image(64, 64); hull_disc(img, 32, 32, 25, 1.0f); hull_check_budgets(img, "disc"); tt_image_free(img);
    img = hull_image(40, 30); hull_rect(img, 5, 5, 15, 25); hull_rect(img, 5, 18, 35, 25);
    hull_check_budgets(img, "L"); tt_image_free(img);
    img = hull_image(50, 50); hull_disc(img, 25, 25, 20, 1.0f); hull_disc(img, 25, 25, 10, 0.0f);
    hull_check_budgets(img, "ring"); tt_image_free(img);
    img = hull_image(50, 50); hull_disc(img, 25, 25, 20, 1.0f); hull_disc(img, 25, 25, 10, 0.0f);
    hull_disc(img, 25, 25, 4, 1.0f); hull_check_budgets(img, "ring with island"); tt_image_free(img);
    img = hull_image(60, 40); hull_disc(img, 12, 12, 8, 1.0f); hull_disc(img, 45, 28, 9, 1.0f);
    hull_check_budgets(img, "two blobs"); tt_image_free(img);
    img = hull_image(32, 32); hull_rect(img, 0, 0, 32, 32); hull_check_budgets(img, "full square"); tt_image_free(img);
    img = hull_image(1, 1); hull_set_alpha(img, 0, 0, 1.0f); hull_check_budgets(img, "1x1"); tt_image_free(img);
    img = hull_image(9, 7); hull_set_alpha(img, 4, 2, 0.1f); hull_check_budgets(img, "single texel");
    tt_image_free(img);
    img = hull_image(40, 40);
    for (s = 3; s < 37; s++) hull_set_alpha(img, s, s, 1.0f);
    hull_check_budgets(img, "diagonal"); tt_image_free(img);
    img = hull_image(40, 40);
    for (s = 3; s < 37; s++) hull_set_alpha(img, s, 39 - s, 1.0f);
    hull_check_budgets(img, "anti-diagonal"); tt_image_free(img);
    img = hull_image(40, 40);
    for (s = 0; s < 40; s++) hull_set_alpha(img, s, (s * 7) % 40 < 20 ? s / 2 : 39 - s / 3, 1.0f);
    hull_check_budgets(img, "scattered line"); tt_image_free(img);
    img = hull_image(1, 37); hull_rect(img, 0, 3, 1, 30); hull_check_budgets(img, "1xN"); tt_image_free(img);
    img = hull_image(37, 1); hull_rect(img, 3, 0, 30, 1); hull_check_budgets(img, "Nx1"); tt_image_free(img);
    img = hull_image(1, 37); hull_rect(img, 0, 3, 1, 10); hull_rect(img, 0, 20, 1, 30);
    hull_check_budgets(img, "1xN split"); tt_image_free(img);
    img = hull_image(16, 16);
    for (s = 0; s < 256; s++)
        if (((s % 16) + (s / 16)) % 2 == 0) hull_set_alpha(img, s % 16, s / 16, 1.0f);
    hull_check_budgets(img, "checkerboard"); tt_image_free(img);
    img = hull_image(60, 40); /* comb: deep narrow slots */
    hull_rect(img, 2, 30, 58, 36);
    for (s = 2; s < 58; s += 4) hull_rect(img, s, 3, s + 2, 30);
    hull_check_budgets(img, "comb"); tt_image_free(img);
    img = hull_image(64, 64); /* square spiral, one texel wide with one-texel gaps */
    {
        int x = 31, y = 31, len = 1, d = 0, k, step;
        for (k = 0; k < 58; k++) {
            for (step = 0; step < len; step++) {
                hull_set_alpha(img, x, y, 1.0f);
                x += d == 0 ? 1 : (d == 2 ? -1 : 0);
                y += d == 1 ? 1 : (d == 3 ? -1 : 0);
            }
            d = (d + 1) & 3;
            if (k % 2 == 1) len += 2;
        }
    }
    hull_check_budgets(img, "spiral"); tt_image_free(img);

    for (s = 0; s < 40; s++) {
        int w = 8 + lcg_below(90), h = 8 + lcg_below(90);
        img = hull_image(w, h);
        hull_blob(img, 1 + lcg_below(w * h / 3));
        sprintf(name, "blob %d (%dx%d)", s, w, h);
        hull_check_budgets(img, name);
        tt_image_free(img);
    }
    for (s = 0; s < 10; s++) {
        int k;
        img = hull_image(30, 30);
        for (k = 0; k < 900; k++)
            if (lcg_unit() < 0.3) hull_set_alpha(img, k % 30, k / 30, 1.0f);
        sprintf(name, "noise %d", s);
        hull_check_budgets(img, name);
        tt_image_free(img);
    }
    for (s = 0; s < 6; s++) {
        img = hull_image(128, 128);
        hull_splotch(img, s * 3.0, 0);
        sprintf(name, "splotch %d", s);
        hull_check_budgets(img, name);
        tt_image_free(img);
        img = hull_image(128, 128);
        hull_splotch(img, s * 3.0, 1);
        sprintf(name, "speckled splotch %d", s);
        hull_check_budgets(img, name);
        tt_image_free(img);
    }
}

/* Large splotches (smooth, ragged, speckled) at 32 vertices. */
static void test_hull_large(void)
{
    static const char *const names[3] = {"smooth 512 splotch", "ragged 512 splotch", "speckled 512 splotch"};
    int kind;
    lcg_seed(77);
    for (kind = 0; kind < 3; kind++) {
        tt_image *img = hull_image(512, 512);
        hull_splotch(img, kind ? 24.0 : 0.0, kind == 2);
        hull_check(img, 32, names[kind]);
        tt_image_free(img);
    }
}

static void test_hull_area(void)
{
    tt_image *img = hull_image(256, 256);
    double disc, convex, a32, a8;
    hull_disc(img, 128, 128, 100, 1.0f);
    disc = 3.14159265358979 * 100.0 * 100.0 / (256.0 * 256.0);
    convex = hull_convex_area(img);
    CHECK(convex > disc, "convex hull of the disc: area %g above the disc's %g", convex, disc);
    a32 = hull_check(img, 32, "disc r=100");
    a8 = hull_check(img, 8, "disc r=100");
    CHECK(a32 <= 1.3 * disc, "32-gon area %g within 1.3 x the disc's %g", a32, disc);
    CHECK(a32 <= 1.1 * convex, "32-gon area %g within 1.1 x the convex hull's %g", a32, convex);
    CHECK(a8 <= 1.3 * convex, "8-gon area %g within 1.3 x the convex hull's %g", a8, convex);
    tt_image_free(img);

    img = hull_image(32, 32);
    hull_rect(img, 4, 6, 20, 30);
    a32 = hull_check(img, 4, "rectangle");
    CHECK(fabs(a32 - hull_mask_area(img)) < 1e-6, "rectangle: hull is the rectangle, area %g vs %g", a32,
          hull_mask_area(img));
    tt_image_free(img);

    img = hull_image(64, 64);
    hull_rect(img, 4, 4, 20, 60); hull_rect(img, 4, 44, 60, 60);
    a32 = hull_check(img, 32, "L exact");
    CHECK(a32 < 1.01 * hull_mask_area(img), "L: hull area %g vs mask %g (should stay non-convex)", a32,
          hull_mask_area(img));
    tt_image_free(img);
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
        if (internal_segments_near(a[0], a[1], b[0], b[1], c[0], c[1], d[0], d[1], 0.0)) return 0.0;
        dist[0] = internal_point_segment_distance(c[0], c[1], a[0], a[1], b[0], b[1]);
        dist[1] = internal_point_segment_distance(d[0], d[1], a[0], a[1], b[0], b[1]);
        dist[2] = internal_point_segment_distance(a[0], a[1], c[0], c[1], d[0], d[1]);
        dist[3] = internal_point_segment_distance(b[0], b[1], c[0], c[1], d[0], d[1]);
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
        tt_image *img = hull_image(48, 48);
        float *xy;
        int n;
        if (shape % 3 == 0) hull_disc(img, 24, 24, 18, 1.0f);
        else if (shape % 3 == 1) { hull_rect(img, 4, 4, 14, 44); hull_rect(img, 4, 34, 44, 44); }
        else hull_blob(img, 600);
        if (internal_patch_hull(img, shape < 6 ? 32 : 8, NULL, &xy, &n) != TT_OK) {
            CHECK(0, "shape %d: hull for the segment test", shape);
            tt_image_free(img);
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
            got = internal_segment_meets_polygon(a, b, xy, n);
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
        tt_image_free(img);
    }
    CHECK(mismatches == 0 && ntests == 3000, "%d of %d random segments disagree with sampling", mismatches, ntests);

    {
        /* unit square, hand-made cases */
        const float sq[8] = {0, 0, 1, 0, 1, 1, 0, 1};
        float a[2], b[2];
        a[0] = 0.2f; a[1] = 0.2f; b[0] = 0.4f; b[1] = 0.6f;
        CHECK(internal_segment_meets_polygon(a, b, sq, 4) == 1, "segment inside");
        a[0] = -1; a[1] = 0.5f; b[0] = 2; b[1] = 0.5f;
        CHECK(internal_segment_meets_polygon(a, b, sq, 4) == 1, "segment through");
        a[0] = -1; a[1] = 2; b[0] = 2; b[1] = 2;
        CHECK(internal_segment_meets_polygon(a, b, sq, 4) == 0, "segment above");
        a[0] = -1; a[1] = 1; b[0] = 2; b[1] = 1;
        CHECK(internal_segment_meets_polygon(a, b, sq, 4) == 1, "segment along the top edge");
        a[0] = 1; a[1] = 2; b[0] = 2; b[1] = 1;
        CHECK(internal_segment_meets_polygon(a, b, sq, 4) == 0, "segment near the corner");
        a[0] = 0; a[1] = 2; b[0] = 2; b[1] = 0;
        CHECK(internal_segment_meets_polygon(a, b, sq, 4) == 1, "segment touching the corner");
        a[0] = 1; a[1] = 1; b[0] = 1; b[1] = 1;
        CHECK(internal_segment_meets_polygon(a, b, sq, 4) == 1, "a point on the corner");
        a[0] = 1.5f; a[1] = 0.5f; b[0] = 1.5f; b[1] = 0.5f;
        CHECK(internal_segment_meets_polygon(a, b, sq, 4) == 0, "a point outside");
    }
}

static void test_hull_errors(void)
{
    tt_image *img = hull_image(8, 8);
    float *xy = (float *)img; /* must be reset to NULL on failure */
    int n = 5;
    CHECK(internal_patch_hull(img, 32, NULL, &xy, &n) == TT_ERROR_INVALID_ARGUMENT, "transparent patch refused");
    CHECK(xy == NULL && n == 0, "outputs reset on failure: %p, %d", (void *)xy, n);
    hull_set_alpha(img, 3, 3, 1.0f);
    CHECK(internal_patch_hull(img, 2, NULL, &xy, &n) == TT_ERROR_INVALID_ARGUMENT, "max_vertices 2 refused");
    CHECK(internal_patch_hull(NULL, 32, NULL, &xy, &n) == TT_ERROR_INVALID_ARGUMENT, "NULL patch refused");
    CHECK(internal_patch_hull(img, 32, NULL, NULL, &n) == TT_ERROR_INVALID_ARGUMENT, "NULL out refused");
    hull_set_alpha(img, 3, 3, -1.0f);
    CHECK(internal_patch_hull(img, 32, NULL, &xy, &n) == TT_ERROR_INVALID_ARGUMENT, "negative alpha only refused");
    tt_image_free(img);
}

typedef struct hull_oom_ctx {
    const tt_image *img;
    int max_vertices;
} hull_oom_ctx;

static tt_result hull_oom_call(void *ctx, const tt_allocator *al, tt_error *error)
{
    hull_oom_ctx *c = (hull_oom_ctx *)ctx;
    float *xy = (float *)ctx;
    int n = -1;
    tt_result r;
    (void)error;   /* a private helper: no tt_error */
    r = internal_patch_hull(c->img, c->max_vertices, al, &xy, &n);
    if (r != TT_OK) return xy == NULL && n == 0 ? r : TT_RESULT_MAX_ENUM;   /* outputs reset on failure */
    if (!xy || n < 3 || n > c->max_vertices) r = TT_RESULT_MAX_ENUM;
    internal_free(al, xy);
    return r;
}

static void test_hull_oom(void)
{
    tt_image *img;
    hull_oom_ctx c;
    int s;
    oom_reset();
    lcg_seed(5);
    img = hull_image(64, 64);
    hull_blob(img, 900);
    c.img = img;
    c.max_vertices = 32;
    oom_sweep_internal("tt__patch_hull(blob, contour)", hull_oom_call, &c, TT_OK);
    tt_image_free(img);

    img = hull_image(40, 40);
    hull_disc(img, 10, 10, 6, 1.0f); hull_disc(img, 30, 28, 7, 1.0f);
    c.img = img;
    c.max_vertices = 8;
    oom_sweep_internal("tt__patch_hull(two blobs, convex)", hull_oom_call, &c, TT_OK);
    tt_image_free(img);

    img = hull_image(16, 16);
    hull_rect(img, 2, 2, 14, 14);
    c.img = img;
    c.max_vertices = 3;
    oom_sweep_internal("tt__patch_hull(square to triangle, bounding)", hull_oom_call, &c, TT_OK);
    tt_image_free(img);

    img = hull_image(200, 200); /* long straight sides plus fine detail: the edge grid grows */
    hull_rect(img, 10, 10, 190, 190);
    for (s = 12; s < 188; s += 3) hull_set_alpha(img, s, 9, 1.0f);
    for (s = 12; s < 188; s += 5) hull_set_alpha(img, 190, s, 1.0f);
    c.img = img;
    c.max_vertices = 4;
    oom_sweep_internal("tt__patch_hull(square with teeth)", hull_oom_call, &c, TT_OK);
    tt_image_free(img);

    img = hull_image(60, 40); /* comb: the edge grid's node pool grows */
    hull_rect(img, 2, 30, 58, 36);
    for (s = 2; s < 58; s += 4) hull_rect(img, s, 3, s + 2, 30);
    c.img = img;
    c.max_vertices = 8;
    oom_sweep_internal("tt__patch_hull(comb)", hull_oom_call, &c, TT_OK);
    tt_image_free(img);

    img = hull_image(8, 8);   /* transparent: refused before any allocation */
    c.img = img;
    c.max_vertices = 8;
    CHECK(hull_oom_call(&c, &g_oom_allocator, NULL) == TT_ERROR_INVALID_ARGUMENT && g_oom_counter.live == 0,
          "transparent patch refused, nothing allocated");
    tt_image_free(img);
    CHECK(g_oom_counter.live == 0 && g_oom_counter.bad_frees == 0, "hull sweeps: %ld blocks live, %ld bad frees",
          g_oom_counter.live, g_oom_counter.bad_frees);
}

/* ------------------------------------------------------------------------ */
/* 7e. Measuring, atlas packing, baking (Sec. 4)                            */
/* ------------------------------------------------------------------------ */

/* Build a tmesh (optionally with an allocator). */
static tt_mesh *bake_build(const tmesh *m, const tt_allocator *al)
{
    tt_mesh_desc d = tm_desc(m);
    tt_mesh *mesh = NULL;
    tt_error err;
    tt_result r = tt_mesh_build(&d, al, &mesh, &err);
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
static tt_image *bake_constant(int w, int h, float r, float g, float b, float a)
{
    tt_image *img = NULL;
    int i;
    if (tt_image_create(w, h, NULL, &img, NULL) != TT_OK) return NULL;
    for (i = 0; i < w * h; i++) {
        img->pixels[4 * i] = r * a;
        img->pixels[4 * i + 1] = g * a;
        img->pixels[4 * i + 2] = b * a;
        img->pixels[4 * i + 3] = a;
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
    tt_error err;
    lcg_seed(11);
    mesh = bake_grid(4, 3, 0.4, NULL);
    fv = bake_face_vectors(mesh, 0.0f, 1.0f);
    rot[0] = s * cos(a); rot[1] = -s * sin(a); rot[2] = s * sin(a); rot[3] = s * cos(a);

    /* Rotation by 10 degrees and scale 1.2 on every face. */
    lb_init(&b);
    lb_paste_all(&b, mesh, 0, rot, o);
    CHECK(tt_lapped_measure(mesh, fv, &b.l, NULL, &rep, &err) == TT_OK, "rotated paste: ok");
    CHECK(fabs(rep.mean_angle_error - 10.0) < 1e-4, "rotated paste: angle 10, got %.8f", rep.mean_angle_error);
    CHECK(fabs(rep.median_scale_error - 0.2) < 1e-4, "rotated paste: scale error 0.2, got %.8f",
          rep.median_scale_error);
    CHECK(fabs(rep.mean_overdraw - 1.0) < 1e-12, "rotated paste: overdraw 1, got %g", rep.mean_overdraw);
    CHECK(rep.uncovered_faces == 0, "rotated paste: no uncovered faces, got %d", rep.uncovered_faces);

    /* A face vector of length 2 along x maps to rotated (2.4, ...): 80 degrees off up. */
    {
        float *fx = bake_face_vectors(mesh, 2.0f, 0.0f);
        CHECK(tt_lapped_measure(mesh, fx, &b.l, NULL, &rep, &err) == TT_OK, "x field: ok");
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
    CHECK(tt_lapped_measure(mesh, fv, &b.l, NULL, &rep, &err) == TT_OK, "partial paste: ok");
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
        CHECK(tt_lapped_measure(mesh, fv, &b.l, NULL, &rep, &err) == TT_OK, "4 scales: ok");
        CHECK(fabs(rep.median_scale_error - 0.45) < 1e-5, "4 scales: median 0.45, got %.8f", rep.median_scale_error);
        /* Odd count: add scale 1 (error 0): sorted 0 .1 .3 .6 1 -> 0.3. */
        bake_affine_uv(mesh, 4, id, o, uv);
        lb_add(&b, 4, uv);
        CHECK(tt_lapped_measure(mesh, fv, &b.l, NULL, &rep, &err) == TT_OK, "5 scales: ok");
        CHECK(fabs(rep.median_scale_error - 0.3) < 1e-5, "5 scales: median 0.3, got %.8f", rep.median_scale_error);
        /* Degenerate UVs (all corners one point): phi(T) = 0 counts 180
           degrees and scale error 1. */
        for (i = 0; i < 6; i++) uv[i] = 0.5f;
        lb_add(&b, 5, uv);
        CHECK(tt_lapped_measure(mesh, fv, &b.l, NULL, &rep, &err) == TT_OK, "degenerate entry: ok");
        CHECK(fabs(rep.mean_angle_error - 30.0) < 1e-4, "degenerate entry: angle (5 * 0 + 180) / 6 = 30, got %g",
              rep.mean_angle_error);
        CHECK(fabs(rep.median_scale_error - 0.45) < 1e-5,
              "degenerate entry: errors 0 .1 .3 .6 1 1, median 0.45, got %g", rep.median_scale_error);
        lb_free(&b);
    }

    /* No entries: errors 0, every face uncovered. */
    lb_init(&b);
    CHECK(tt_lapped_measure(mesh, fv, &b.l, NULL, &rep, &err) == TT_OK, "no entries: ok");
    CHECK(rep.mean_angle_error == 0.0 && rep.median_scale_error == 0.0 && rep.mean_overdraw == 0.0 &&
              rep.uncovered_faces == mesh->nfaces,
          "no entries: zeros and %d uncovered, got %g %g %g %d", mesh->nfaces, rep.mean_angle_error,
          rep.median_scale_error, rep.mean_overdraw, rep.uncovered_faces);
    free(fv);
    tt_mesh_free(mesh);
}

/* A tt_lapped_measure error: the code, err.result, a message, the entry in
   err.item and its face in err.face (-2: not compared), and a report of
   zeros. */
#define MEASURE_EXPECT(call, code, item_, face_, what)                                                          \
    do {                                                                                                        \
        tt_result r_;                                                                                           \
        memset(&rep, 0x55, sizeof rep);                                                                         \
        r_ = (call);                                                                                            \
        CHECK(r_ == (code) && err.result == (code) && err.message[0] != '\0' &&                                 \
                  longest_digit_run(err.message) <= 12 && (item_ == -2 || err.item == item_) &&                \
                  (face_ == -2 || err.face == face_),                                                           \
              "%s: expected %d (item %d, face %d), got %d (item %d, face %d): %s", what, (int)(code), item_,  \
              face_, (int)r_, err.item, err.face, err.message);                                                \
        CHECK(rep.uncovered_faces == 0 && rep.mean_overdraw == 0.0, "%s: report not zeroed on failure", what); \
    } while (0)

static void test_lapped_measure_errors(void)
{
    tt_mesh *mesh, *qm;
    float *fv, uv[6], qv[3] = {0, 1, 0};
    lb_builder b;
    tt_lapped_report rep;
    tt_error err;
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
    CHECK(tt_lapped_measure(mesh, fv, &b.l, NULL, &rep, &err) == TT_OK && err.result == TT_OK, "valid input: ok");
    CHECK(tt_lapped_measure(mesh, fv, &b.l, NULL, &rep, NULL) == TT_OK, "valid input, no error struct: ok");
    MEASURE_EXPECT(tt_lapped_measure(NULL, fv, &b.l, NULL, &rep, &err), TT_ERROR_INVALID_ARGUMENT, -1, -1,
                   "NULL mesh");
    MEASURE_EXPECT(tt_lapped_measure(mesh, NULL, &b.l, NULL, &rep, &err), TT_ERROR_INVALID_ARGUMENT, -1, -1,
                   "NULL vectors");
    MEASURE_EXPECT(tt_lapped_measure(mesh, fv, NULL, NULL, &rep, &err), TT_ERROR_INVALID_ARGUMENT, -1, -1,
                   "NULL lapped");
    CHECK(tt_lapped_measure(mesh, fv, &b.l, NULL, NULL, &err) == TT_ERROR_INVALID_ARGUMENT, "NULL report refused");
    {
        counter hc;
        tt_allocator half = make_allocator(&hc, -1);
        half.free = NULL;   /* alloc without free */
        MEASURE_EXPECT(tt_lapped_measure(mesh, fv, &b.l, &half, &rep, &err), TT_ERROR_INVALID_ARGUMENT, -1, -1,
                       "allocator without free");
        CHECK(hc.calls == 0, "a refused allocator is not used: %ld calls", hc.calls);
    }
    /* An entry naming a face out of range: the entry in item. */
    b.l.faces[2] = mesh->nfaces;
    MEASURE_EXPECT(tt_lapped_measure(mesh, fv, &b.l, NULL, &rep, &err), TT_ERROR_INDEX_OUT_OF_RANGE, 2, -2,
                   "entry 2 names face nfaces");
    CHECK(msg_has_number(err.message, 2) && msg_has_number(err.message, mesh->nfaces),
          "the message names entry 2 and face %d: %s", mesh->nfaces, err.message);
    b.l.faces[2] = -1;
    MEASURE_EXPECT(tt_lapped_measure(mesh, fv, &b.l, NULL, &rep, &err), TT_ERROR_INDEX_OUT_OF_RANGE, 2, -2,
                   "entry 2 names face -1");
    b.l.faces[2] = 2;
    b.l.faces[3] = 1 << 30;
    MEASURE_EXPECT(tt_lapped_measure(mesh, fv, &b.l, NULL, &rep, &err), TT_ERROR_INDEX_OUT_OF_RANGE, 3, -2,
                   "entry 3 names face 2^30");
    b.l.faces[3] = 3;
    /* A non-finite UV: the entry in item, its face in face. */
    b.l.uv[7] = (float)internal_not_a_number();
    MEASURE_EXPECT(tt_lapped_measure(mesh, fv, &b.l, NULL, &rep, &err), TT_ERROR_NON_FINITE, 1, 1,
                   "NaN paste uv of entry 1");
    b.l.uv[7] = 0.0f;
    b.l.faces[3] = 7;   /* entry 3 now on face 7: item and face differ */
    b.l.uv[6 * 3 + 4] = -internal_infinity();
    MEASURE_EXPECT(tt_lapped_measure(mesh, fv, &b.l, NULL, &rep, &err), TT_ERROR_NON_FINITE, 3, 7,
                   "infinite paste uv of entry 3 (face 7)");
    b.l.uv[6 * 3 + 4] = 0.0f;
    b.l.faces[3] = 3;
    fv[3 * 3 + 1] = internal_infinity();
    MEASURE_EXPECT(tt_lapped_measure(mesh, fv, &b.l, NULL, &rep, &err), TT_ERROR_NON_FINITE, 3, 3,
                   "infinite face vector of face 3 (entry 3)");
    fv[3 * 3 + 1] = 1.0f;
    b.l.nentries = -1;
    MEASURE_EXPECT(tt_lapped_measure(mesh, fv, &b.l, NULL, &rep, &err), TT_ERROR_INVALID_ARGUMENT, -2, -2,
                   "nentries -1");
    b.l.nentries = 4;
    CHECK(tt_lapped_measure(mesh, fv, &b.l, NULL, &rep, &err) == TT_OK, "restored input: ok");
    /* A paste whose entries run past the list: the paste in item. */
    b.l.pastes[0].nfaces = 9;
    MEASURE_EXPECT(tt_lapped_measure(mesh, fv, &b.l, NULL, &rep, &err), TT_ERROR_INDEX_OUT_OF_RANGE, 0, -2,
                   "paste 0 has 9 entries of 4");
    b.l.pastes[0].nfaces = 4;
    /* Fades out of [0, 1] or NaN: the entry in item, its face in face. */
    {
        float fade[12];
        for (i = 0; i < 12; i++) fade[i] = 1.0f;
        b.l.fade = fade;
        CHECK(tt_lapped_measure(mesh, fv, &b.l, NULL, &rep, &err) == TT_OK, "fades of 1: ok");
        fade[3 * 2 + 1] = (float)internal_not_a_number();
        MEASURE_EXPECT(tt_lapped_measure(mesh, fv, &b.l, NULL, &rep, &err), TT_ERROR_NON_FINITE, 2, 2,
                       "NaN fade of entry 2");
        fade[3 * 2 + 1] = 1.5f;
        MEASURE_EXPECT(tt_lapped_measure(mesh, fv, &b.l, NULL, &rep, &err), TT_ERROR_INVALID_ARGUMENT, 2, 2,
                       "fade 1.5 of entry 2");
        b.l.fade = NULL;
    }
    lb_free(&b);

    /* Not triangles: INVALID_ARGUMENT naming the first face that is not one. */
    qm = bake_quad();
    lb_init(&b);
    MEASURE_EXPECT(tt_lapped_measure(qm, qv, &b.l, NULL, &rep, &err), TT_ERROR_INVALID_ARGUMENT, -2, 0,
                   "quad mesh");
    tt_mesh_free(qm);
    {
        /* Two triangles, then a quad: face 2 is named. */
        tmesh mix;
        tt_mesh *mm = NULL;
        float mv[9] = {0, 1, 0, 0, 1, 0, 0, 1, 0};
        memset(&mix, 0, sizeof mix);
        tm_vert(&mix, 0, 0, 0); tm_vert(&mix, 1, 0, 0); tm_vert(&mix, 0, 1, 0); tm_vert(&mix, 1, 1, 0);
        tm_vert(&mix, 2, 0, 0); tm_vert(&mix, 2, 1, 0);
        tm_tri(&mix, 0, 1, 2);
        tm_tri(&mix, 1, 3, 2);
        tm_quad(&mix, 1, 4, 5, 3);
        CHECK(build(&mix, 0, &mm, &err) == TT_OK, "two triangles and a quad build: %s", err.message);
        if (mm) {
            MEASURE_EXPECT(tt_lapped_measure(mm, mv, &b.l, NULL, &rep, &err), TT_ERROR_INVALID_ARGUMENT, -2, 2,
                           "face 2 is a quad");
            CHECK(msg_has_number(err.message, 2) && msg_has_number(err.message, 4),
                  "the message names face 2 and its 4 corners: %s", err.message);
        }
        tt_mesh_free(mm);
        tm_free(&mix);
    }
    free(fv);
    tt_mesh_free(mesh);
}
#undef MEASURE_EXPECT

typedef struct measure_oom_ctx {
    const tt_mesh *mesh;
    const float *fv;
    const tt_lapped *lapped;
} measure_oom_ctx;

static tt_result measure_oom_call(void *ctx, const tt_allocator *al, tt_error *error)
{
    measure_oom_ctx *c = (measure_oom_ctx *)ctx;
    tt_lapped_report rep;
    tt_result r = tt_lapped_measure(c->mesh, c->fv, c->lapped, al, &rep, error);
    if (error->result != r) return TT_RESULT_MAX_ENUM;
    return r;
}

static void test_lapped_measure_oom(void)
{
    tt_mesh *mesh;
    float *fv;
    lb_builder b;
    measure_oom_ctx c;
    double id[4] = {1, 0, 0, 1}, o[2] = {0.3, -0.2};
    mesh = bake_grid(3, 3, 0.0, NULL);   /* the mesh's own allocator is not used */
    if (!mesh) return;
    oom_reset();
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
    double area2 = internal_orient2(x[0], y[0], x[1], y[1], x[2], y[2]), best = 1e300;
    int i, inside = 1;
    for (i = 0; i < 3; i++) {
        int j = (i + 1) % 3;
        double d = internal_point_segment_distance(qx, qy, x[i], y[i], x[j], y[j]);
        if (internal_orient2(x[i], y[i], x[j], y[j], qx, qy) * area2 < 0) inside = 0;
        if (d < best) best = d;
    }
    return inside ? 0.0 : best;
}

/* Texel centres within `gutter` of atlas triangles of two different
   charts, label[f] being face f's chart (NULL: every triangle its own): the
   texels a bake with that gutter would write twice. */
static int bake_gutter_overlaps(const tt_mesh *mesh, const float *uv, const int *label, int size, int gutter)
{
    int *owner = (int *)malloc(sizeof(int) * (size_t)size * size);
    int f, i, shared = 0;
    for (i = 0; i < size * size; i++) owner[i] = -1;
    for (f = 0; f < mesh->nfaces; f++) {
        double x[3], y[3], lo_x = 1e30, hi_x = -1e30, lo_y = 1e30, hi_y = -1e30;
        int k, j, chart = label ? label[f] : f;
        for (k = 0; k < 3; k++) {
            int c = mesh->face_start[f] + k;
            x[k] = uv[2 * c] * (double)size;
            y[k] = (1.0 - uv[2 * c + 1]) * (double)size;
            lo_x = fmin(lo_x, x[k]); hi_x = fmax(hi_x, x[k]);
            lo_y = fmin(lo_y, y[k]); hi_y = fmax(hi_y, y[k]);
        }
        for (j = (int)floor(lo_y - gutter - 1); j <= (int)ceil(hi_y + gutter + 1); j++)
            for (i = (int)floor(lo_x - gutter - 1); i <= (int)ceil(hi_x + gutter + 1); i++) {
                int *o;
                if (i < 0 || j < 0 || i >= size || j >= size) continue;
                if (bake_triangle_distance(x, y, i + 0.5, j + 0.5) > gutter + 1e-3) continue;
                o = owner + (size_t)j * size + i;
                if (*o < 0) *o = chart;
                else if (*o != chart) shared++;
            }
    }
    free(owner);
    return shared;
}

/* Texel centres inside two atlas triangles (tt_raster_triangle's rule). */
static int bake_raster_overlaps(const tt_mesh *mesh, const float *uv, int size)
{
    bake_count cb;
    int f, k;
    cb.width = size;
    cb.overlaps = 0;
    cb.count = (int *)calloc((size_t)size * size, sizeof(int));
    for (f = 0; f < mesh->nfaces; f++) {
        float xy[6];
        for (k = 0; k < 3; k++) {
            int c = mesh->face_start[f] + k;
            xy[2 * k] = uv[2 * c] * (float)size;
            xy[2 * k + 1] = (1.0f - uv[2 * c + 1]) * (float)size;
        }
        tt_raster_triangle(xy, size, size, bake_count_texel, &cb);
    }
    free(cb.count);
    return cb.overlaps;
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
        bad = bake_gutter_overlaps(mesh, uv, NULL, size, gutter);
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
        bad = bake_gutter_overlaps(mesh, uv, NULL, s2, gutter);
        CHECK(bad == 0, "grid %d: gutters disjoint at size %d, %d texels shared", t, s2, bad);
        bad = bake_raster_overlaps(mesh, uv, s2);
        CHECK(bad == 0, "grid %d: raster overlaps %d", t, bad);
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
    bad = bake_gutter_overlaps(m3, uv, NULL, 64, 2);
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

/* A hand-made mesh with no faces (tt_mesh_build refuses one, a caller's
   struct need not): every triangle-mesh entry point says so instead of
   dividing by zero or reading face 0. */
static void test_zero_face_mesh_refused(void)
{
    tt_mesh *built = bake_grid(2, 2, 0.0, NULL), empty;
    tt_image *patch = NULL, *atlas = NULL;
    tt_lapped *lapped = NULL;
    tt_uv_report uv_report;
    float uv[48], field[24];
    tt_error err;
    tt_result r;
    int i;
    if (!built) { CHECK(0, "bake_grid"); return; }
    empty = *built;
    empty.nfaces = 0;
    empty.ncorners = 0;
    empty.min_face_size = empty.max_face_size = 0;
    for (i = 0; i < 24; i++) field[i] = i % 3 == 0 ? 1.0f : 0.0f;
    for (i = 0; i < 48; i++) uv[i] = 0.5f;
    tt_image_create(16, 16, NULL, &patch, NULL);
    tt_image_create(32, 32, NULL, &atlas, NULL);
    r = tt_atlas_pack_pairs(&empty, 64, 1, uv, &err);
    CHECK(r == TT_ERROR_EMPTY_MESH && strstr(err.message, "no faces"), "tt_atlas_pack_pairs: %d (%s)", r, err.message);
    r = tt_atlas_pack_charts(&empty, 64, 1, NULL, NULL, uv, NULL, &err);
    CHECK(r == TT_ERROR_EMPTY_MESH, "tt_atlas_pack_charts: %d (%s)", r, err.message);
    r = tt_lapped_paste(&empty, field, &patch, 1, NULL, NULL, &lapped, &err);
    CHECK(r == TT_ERROR_EMPTY_MESH && lapped == NULL, "tt_lapped_paste: %d (%s)", r, err.message);
    r = tt_uv_check(&empty, uv, NULL, &uv_report, &err);
    CHECK(r == TT_ERROR_EMPTY_MESH, "tt_uv_check: %d (%s)", r, err.message);
    /* A gutter so wide that twice it overflows an int: refused before. */
    r = tt_atlas_pack_charts(built, 64, 0x7fffffff, NULL, NULL, uv, NULL, &err);
    CHECK(r == TT_ERROR_IMAGE_TOO_SMALL && strstr(err.message, "2147483647") && !strstr(err.message, "-1"),
          "tt_atlas_pack_charts, gutter INT_MAX: %d (%s)", r, err.message);
    tt_image_free(patch);
    tt_image_free(atlas);
    tt_mesh_free(built);
}

/* ---- tt_atlas_pack_charts ---- */

/* A torus of nu x nv quads, each split in two, every vertex moved by up to
   jitter (mesh units) along each axis: 2 nu nv triangles. */
static tt_mesh *chart_torus(int nu, int nv, double jitter)
{
    tmesh q, t;
    tt_mesh *mesh;
    int i;
    memset(&q, 0, sizeof q);
    make_torus(&q, nu, nv, 3.0, 1.0);
    for (i = 0; i < 3 * q.nv; i++) q.pos[i] += (float)(jitter * (lcg_unit() - 0.5));
    tm_triangulate(&q, &t);
    mesh = bake_build(&t, NULL);
    tm_free(&q);
    tm_free(&t);
    return mesh;
}

/* An n x n wavy sheet whose rows and columns are spaced geometrically by
   `ratio`: its triangles' sides differ by ratio^(n-1) (areas by its
   square), the uneven tessellation of real scans and CAD exports. */
static tt_mesh *chart_uneven_sheet(int n, double ratio)
{
    tmesh q, t;
    tt_mesh *mesh;
    int i, j;
    memset(&q, 0, sizeof q);
    make_grid(&q, n, n);
    for (j = 0; j <= n; j++)
        for (i = 0; i <= n; i++) {
            float *p = q.pos + 3 * (j * (n + 1) + i);
            double x = pow(ratio, i) - 1.0, y = pow(ratio, j) - 1.0;
            p[0] = (float)x;
            p[1] = (float)y;
            p[2] = (float)(3.0 * sin(x / 6.0) * cos(y / 7.0));
        }
    tm_triangulate(&q, &t);
    mesh = bake_build(&t, NULL);
    tm_free(&q);
    tm_free(&t);
    return mesh;
}

/* A ramp winding `turns` times round the z axis (radii 1 to 2, rising 0.2
   a turn): its normals stay within 5 degrees of +z, so one direction would
   take it all, but seen along z it covers itself `turns` times. */
static tt_mesh *chart_spiral_ramp(double turns)
{
    const double pi = 3.14159265358979323846;
    const int steps = (int)(48 * turns);
    tmesh q, t;
    tt_mesh *mesh;
    int i;
    memset(&q, 0, sizeof q);
    for (i = 0; i <= steps; i++) {
        double a = 2.0 * pi * turns * i / steps, z = 0.2 * turns * i / steps;
        tm_vert(&q, cos(a), sin(a), z);
        tm_vert(&q, 2.0 * cos(a), 2.0 * sin(a), z);
    }
    for (i = 0; i < steps; i++) tm_quad(&q, 2 * i, 2 * i + 1, 2 * i + 3, 2 * i + 2);
    tm_triangulate(&q, &t);
    mesh = bake_build(&t, NULL);
    tm_free(&q);
    tm_free(&t);
    return mesh;
}

/* Union-find root of face f. */
static int chart_root(int *parent, int f)
{
    while (parent[f] != f) f = parent[f] = parent[parent[f]];
    return f;
}

/* The charts of an atlas as its UVs show them: faces joined across every
   edge whose two ends have the same UVs on both sides. label gets a chart
   per face (a face index); returns the number of charts. */
static int chart_labels(const tt_mesh *mesh, const float *uv, int *label)
{
    int f, c, count = 0;
    for (f = 0; f < mesh->nfaces; f++) label[f] = f;
    for (c = 0; c < mesh->ncorners; c++) {
        int t = mesh->twin[c], cn, tn;
        if (t < 0) continue;
        cn = tt_mesh_next(mesh, c);
        tn = tt_mesh_next(mesh, t);
        if (uv[2 * c] == uv[2 * tn] && uv[2 * c + 1] == uv[2 * tn + 1] && uv[2 * cn] == uv[2 * t] &&
            uv[2 * cn + 1] == uv[2 * t + 1]) {
            int a = chart_root(label, mesh->corner_face[c]), b = chart_root(label, mesh->corner_face[t]);
            if (a != b) label[a] = b;
        }
    }
    for (f = 0; f < mesh->nfaces; f++) label[f] = chart_root(label, f);
    for (f = 0; f < mesh->nfaces; f++) count += label[f] == f;
    return count;
}

/* Texel density per triangle, sqrt(UV area in texels / surface area), at
   the 5th, 50th and 95th percentile over the triangles (each counts once,
   whatever its area: small triangles are as visible as large ones). */
static void chart_density(const tt_mesh *mesh, const float *uv, int size, double out[3])
{
    static const double fractions[3] = {0.05, 0.5, 0.95};
    double *value = (double *)malloc(sizeof(double) * (size_t)mesh->nfaces);
    double *weight = (double *)malloc(sizeof(double) * (size_t)mesh->nfaces);
    int f, k;
    for (f = 0; f < mesh->nfaces; f++) {
        const float *a = uv + 6 * f;
        double uv_area = 0.5 * fabs(internal_orient2(a[0], a[1], a[2], a[3], a[4], a[5])) * size * size;
        float n[3];
        double surface;
        const float *p[3];
        double e1[3], e2[3], cr[3];
        for (k = 0; k < 3; k++) p[k] = mesh->pos + 3 * mesh->corner_vert[mesh->face_start[f] + k];
        for (k = 0; k < 3; k++) {
            e1[k] = (double)p[1][k] - p[0][k];
            e2[k] = (double)p[2][k] - p[0][k];
        }
        cr[0] = e1[1] * e2[2] - e1[2] * e2[1];
        cr[1] = e1[2] * e2[0] - e1[0] * e2[2];
        cr[2] = e1[0] * e2[1] - e1[1] * e2[0];
        surface = 0.5 * sqrt(cr[0] * cr[0] + cr[1] * cr[1] + cr[2] * cr[2]);
        (void)n;
        value[f] = surface > 0.0 ? sqrt(uv_area / surface) : 0.0;
        weight[f] = 1.0;
    }
    for (k = 0; k < 3; k++) out[k] = internal_weighted_percentile(value, weight, mesh->nfaces, fractions[k]);
    free(value);
    free(weight);
}

/* UV triangles of zero or negative area (v up: counter-clockwise is positive). */
static int chart_flipped(const tt_mesh *mesh, const float *uv)
{
    int f, bad = 0;
    for (f = 0; f < mesh->nfaces; f++) {
        const float *a = uv + 6 * f;
        bad += !(internal_orient2(a[0], a[1], a[2], a[3], a[4], a[5]) > 0.0);
    }
    return bad;
}

/* Every promise of a chart atlas on `mesh` at `size`: UVs in [0, 1], no
   flips, the report's charts are the UVs' charts, no texel within the
   gutter of two charts, no texel centre in two triangles, the density
   spread within +-25 % of the median (returned in spread[3]). */
static void chart_check_atlas(const char *what, const tt_mesh *mesh, const float *uv,
                              const tt_chart_atlas_report *report, int size, int gutter, double spread[3])
{
    int *label = (int *)malloc(sizeof(int) * (size_t)mesh->nfaces), bad, charts;
    bad = bake_uv_outside(uv, 2 * mesh->ncorners);
    CHECK(bad == 0, "%s: %d UVs outside [0,1]", what, bad);
    bad = chart_flipped(mesh, uv);
    CHECK(bad == 0, "%s: %d triangles flipped or empty", what, bad);
    charts = chart_labels(mesh, uv, label);
    CHECK(charts == report->ncharts, "%s: the UVs show %d charts, the report says %d", what, charts, report->ncharts);
    bad = bake_gutter_overlaps(mesh, uv, label, size, gutter);
    CHECK(bad == 0, "%s: %d texels within the gutter of two charts", what, bad);
    bad = bake_raster_overlaps(mesh, uv, size);
    CHECK(bad == 0, "%s: %d texel centres in two triangles", what, bad);
    chart_density(mesh, uv, size, spread);
    CHECK(spread[0] >= 0.75 * spread[1] && spread[2] <= 1.25 * spread[1],
          "%s: density 5th-95th percentile %.4g..%.4g within 25%% of the median %.4g", what, spread[0], spread[2],
          spread[1]);
    CHECK(report->texels_per_unit > 0.0 && report->fill > 0.0 && report->fill <= 1.0,
          "%s: report %.4g texels per unit, fill %.4g", what, report->texels_per_unit, report->fill);
    free(label);
}

/* A 20k-triangle torus, jittered: fits 1024 with gutter 2 and keeps every
   promise; the density is the report's; the same call gives the same UVs. */
static void test_atlas_pack_charts(void)
{
    tt_mesh *mesh;
    float *uv, *again;
    tt_chart_atlas_report report, report2;
    tt_error err;
    double spread[3];
    lcg_seed(41);
    mesh = chart_torus(100, 100, 0.02);
    if (!mesh) return;
    CHECK(mesh->nfaces == 20000, "20000 triangles, got %d", mesh->nfaces);
    uv = (float *)malloc(sizeof(float) * 2 * (size_t)mesh->ncorners);
    again = (float *)malloc(sizeof(float) * 2 * (size_t)mesh->ncorners);
    CHECK(tt_atlas_pack_charts(mesh, 1024, 2, NULL, NULL, uv, &report, &err) == TT_OK, "20k triangles fit 1024: %s",
          err.message);
    chart_check_atlas("torus at 1024", mesh, uv, &report, 1024, 2, spread);
    CHECK(fabs(spread[1] / report.texels_per_unit - 1.0) < 0.05, "median density %.4g is the report's %.4g", spread[1],
          report.texels_per_unit);
    CHECK(report.fill > 0.25, "the triangles fill %.3g of the atlas", report.fill);
    CHECK(tt_atlas_pack_charts(mesh, 1024, 2, NULL, NULL, again, &report2, NULL) == TT_OK &&
              memcmp(uv, again, sizeof(float) * 2 * (size_t)mesh->ncorners) == 0,
          "deterministic");
    {
        /* The four turns tried at once pick what one after another picks. */
        const tt_executor *executors[2];
        tt_chart_pack_options po;
        int e;
        executors[0] = &g_reverse_executor;
        executors[1] = &g_thread_executor;
        for (e = 0; e < 2; e++) {
            memset(&po, 0, sizeof po);
            po.executor = executors[e];
            memset(again, 0, sizeof(float) * 2 * (size_t)mesh->ncorners);
            CHECK(tt_atlas_pack_charts(mesh, 1024, 2, &po, NULL, again, &report2, &err) == TT_OK &&
                      memcmp(uv, again, sizeof(float) * 2 * (size_t)mesh->ncorners) == 0 &&
                      report2.fill == report.fill,
                  "the %s executor packs the same atlas (fill %.4f against %.4f)", e ? "threads'" : "reverse",
                  report2.fill, report.fill);
        }
    }
    /* Gutter 0 and 4, a small size: still every promise. */
    CHECK(tt_atlas_pack_charts(mesh, 256, 4, NULL, NULL, uv, &report, &err) == TT_OK, "gutter 4 at 256: %s", err.message);
    chart_check_atlas("torus at 256, gutter 4", mesh, uv, &report, 256, 4, spread);
    CHECK(tt_atlas_pack_charts(mesh, 512, 0, NULL, NULL, uv, &report, &err) == TT_OK, "gutter 0 at 512: %s", err.message);
    chart_check_atlas("torus at 512, gutter 0", mesh, uv, &report, 512, 0, spread);
    free(uv);
    free(again);
    tt_mesh_free(mesh);
}

/* The fill a packing of the charts' bounding boxes would reach at the same
   density: each chart's box in the atlas (its UVs' bounds, `gutter` more
   every way), laid in shelves `size` wide by decreasing height; the
   triangles' texels over size times the shelves' height. */
static double chart_box_fill(const tt_mesh *mesh, const float *uv, int size, int gutter)
{
    int *label = (int *)malloc(sizeof(int) * (size_t)mesh->nfaces), f, k, c, n = 0, i, j;
    double *box = (double *)malloc(sizeof(double) * 4 * (size_t)mesh->nfaces), texels = 0.0;
    double x = 0.0, y = 0.0, shelf = 0.0;
    int *order = (int *)malloc(sizeof(int) * (size_t)mesh->nfaces);
    chart_labels(mesh, uv, label);
    for (f = 0; f < mesh->nfaces; f++) {
        box[4 * f] = box[4 * f + 1] = 1e300;
        box[4 * f + 2] = box[4 * f + 3] = -1e300;
    }
    for (f = 0; f < mesh->nfaces; f++) {
        const float *a = uv + 6 * f;
        double *b = box + 4 * label[f];
        texels += 0.5 * fabs(internal_orient2(a[0], a[1], a[2], a[3], a[4], a[5])) * size * size;
        for (k = 0; k < 3; k++) {
            b[0] = fmin(b[0], a[2 * k] * size);
            b[1] = fmin(b[1], a[2 * k + 1] * size);
            b[2] = fmax(b[2], a[2 * k] * size);
            b[3] = fmax(b[3], a[2 * k + 1] * size);
        }
    }
    for (f = 0; f < mesh->nfaces; f++)
        if (label[f] == f) order[n++] = f;
    for (i = 1; i < n; i++)   /* by decreasing height */
        for (j = i; j > 0 && box[4 * order[j] + 3] - box[4 * order[j] + 1] >
                               box[4 * order[j - 1] + 3] - box[4 * order[j - 1] + 1]; j--) {
            c = order[j];
            order[j] = order[j - 1];
            order[j - 1] = c;
        }
    for (i = 0; i < n; i++) {
        const double *b = box + 4 * order[i];
        double w = ceil(b[2] - b[0] + 2.0 * gutter), h = ceil(b[3] - b[1] + 2.0 * gutter);
        if (x + w > size) {
            y += shelf;
            x = 0.0;
            shelf = 0.0;
        }
        x += w;
        shelf = fmax(shelf, h);
    }
    y += shelf;
    free(label);
    free(box);
    free(order);
    return texels / ((double)size * fmax(y, size));
}

/* A lumpy sphere of n x n latitude-longitude cells as triangles: radius
   1 + 0.15 sin(3 theta) cos(4 phi), each vertex pushed in or out by up to
   noise / 2 (seeded, so the same every run). */
static void make_lumpy_sphere(tmesh *m, int n, double noise)
{
    tmesh quads;
    int i, f, k, corner = 0;
    memset(&quads, 0, sizeof quads);
    memset(m, 0, sizeof *m);
    make_field_sphere(&quads, n, n, 1.0);
    lcg_seed(43);
    for (i = 0; i < quads.nv; i++) {
        const float *p = quads.pos + 3 * i;
        double t = acos(fmax(-1.0, fmin(1.0, p[2]))), phi = atan2(p[1], p[0]);
        double r = 1.0 + 0.15 * sin(3.0 * t) * cos(4.0 * phi) + noise * (lcg_unit() - 0.5);
        tm_vert(m, p[0] * r, p[1] * r, p[2] * r);
    }
    for (f = 0; f < quads.nf; f++) {
        for (k = 2; k < quads.sizes[f]; k++)
            tm_tri(m, quads.idx[corner], quads.idx[corner + k - 1], quads.idx[corner + k]);
        corner += quads.sizes[f];
    }
    tm_free(&quads);
}

/* A scan-like chart set: a lumpy sphere of 19800 triangles (radius 1 +-
   0.15 in lumps, +-0.0015 of noise per vertex). The triangles fill at
   least 60 % of the atlas at one texel density (p95 / p5 within 1.2); the
   control, the same charts' bounding boxes in shelves (how the atlas was
   packed before), must stay below 55 % (rounder charts box better than ragged ones). */
static void test_atlas_pack_charts_fill(void)
{
    tt_mesh *mesh;
    float *uv;
    tt_chart_atlas_report report;
    tt_error err;
    double spread[3], boxes;
    tmesh m;
    int i;
    make_lumpy_sphere(&m, 100, 0.003);
    mesh = bake_build(&m, NULL);
    tm_free(&m);
    if (!mesh) return;
    uv = (float *)malloc(sizeof(float) * 2 * (size_t)mesh->ncorners);
    CHECK(tt_atlas_pack_charts(mesh, 2048, 2, NULL, NULL, uv, &report, &err) == TT_OK, "2048: %s", err.message);
    chart_check_atlas("lumpy sphere at 2048", mesh, uv, &report, 2048, 2, spread);
    CHECK(spread[2] / spread[0] <= 1.2, "texel density p95 / p5 %.3f", spread[2] / spread[0]);
    boxes = chart_box_fill(mesh, uv, 2048, 2);
    CHECK(report.fill >= 0.6, "%d charts fill %.3f of the atlas", report.ncharts, report.fill);
    CHECK(boxes < 0.55, "control: their boxes in shelves would fill %.3f", boxes);
    /* Above 2048 texels a side the packing works in blocks of texels
       (here 2, the gutter of 3 rounded up to 2 blocks): every promise still
       holds, at the same or a better fill. */
    {
        tt_chart_atlas_report large;
        float *uv_large = (float *)malloc(sizeof(float) * 2 * (size_t)mesh->ncorners);
        CHECK(tt_atlas_pack_charts(mesh, 4096, 3, NULL, NULL, uv_large, &large, &err) == TT_OK, "4096: %s", err.message);
        chart_check_atlas("lumpy sphere at 4096, gutter 3", mesh, uv_large, &large, 4096, 3, spread);
        CHECK(large.fill >= 0.6, "at 4096 the charts fill %.3f", large.fill);
        /* Gutter 4 at 4096 is gutter 2 at 2048 drawn twice as large: a
           block's texels lie within a quarter of its diagonal of its
           centre, so the blocks reserve at most 0.7 texel more round each
           chart than texels would (half the diagonal, 1.4 more, lost 3
           points of fill here). */
        CHECK(tt_atlas_pack_charts(mesh, 4096, 4, NULL, NULL, uv_large, &large, &err) == TT_OK, "4096, gutter 4: %s",
              err.message);
        chart_check_atlas("lumpy sphere at 4096, gutter 4", mesh, uv_large, &large, 4096, 4, spread);
        printf("     in blocks of 2 texels: %d charts fill %.3f at 4096 with gutter 4, %.3f at 2048 with gutter 2\n",
               large.ncharts, large.fill, report.fill);
        CHECK(large.fill >= report.fill - 0.015, "at 4096 with gutter 4 the charts fill %.3f, at 2048 with gutter 2 %.3f",
              large.fill, report.fill);
        free(uv_large);
    }
    printf("     atlas fill on a lumpy sphere: %d charts fill %.3f at 2048 (their boxes in shelves: %.3f), density "
           "p95/p5 %.3f\n", report.ncharts, report.fill, boxes, spread[2] / spread[0]);
    /* The search of the scale: starting from the fill it reaches, it takes
       fewer packings than from a far guess (the control) and ends at the
       same fill within the search's 0.5 % of the scale; a progress that
       cancels stops it at once, the UVs untouched. */
    {
        tt_chart_pack_options po;
        tt_chart_atlas_report guessed, far;
        lapped_progress near_p, far_p, cancel_p;
        float *again = (float *)malloc(sizeof(float) * 2 * (size_t)mesh->ncorners);
        int same = 1;
        memset(&near_p, 0, sizeof near_p);
        memset(&far_p, 0, sizeof far_p);
        memset(&cancel_p, 0, sizeof cancel_p);
        cancel_p.cancel_at = 1;
        memset(&po, 0, sizeof po);
        po.progress = lapped_progress_fn;
        po.progress_user_data = &near_p;
        po.fill_guess = report.fill;
        CHECK(tt_atlas_pack_charts(mesh, 2048, 2, &po, NULL, again, &guessed, &err) == TT_OK, "guessed: %s",
              err.message);
        po.progress_user_data = &far_p;
        po.fill_guess = 0.2;
        CHECK(tt_atlas_pack_charts(mesh, 2048, 2, &po, NULL, again, &far, &err) == TT_OK, "far: %s", err.message);
        printf("     packing searches: %d tries from the fill reached (%.3f), %d from a guess of 0.2 (%.3f)\n",
               near_p.calls - 1, guessed.fill, far_p.calls - 1, far.fill);
        CHECK(near_p.calls + 2 <= far_p.calls && fabs(guessed.fill - report.fill) <= 0.02 &&
                  fabs(far.fill - report.fill) <= 0.02 && !near_p.decreasing && !far_p.decreasing &&
                  near_p.last == 1.0f,
              "searches: %d tries from the fill reached (fill %.3f), %d from 0.2 (fill %.3f), against %.3f",
              near_p.calls - 1, guessed.fill, far_p.calls - 1, far.fill, report.fill);
        for (i = 0; i < 2 * mesh->ncorners; i++) again[i] = -1.0f;
        po.progress_user_data = &cancel_p;
        CHECK(tt_atlas_pack_charts(mesh, 2048, 2, &po, NULL, again, &guessed, &err) == TT_CANCELLED,
              "a progress returning non-zero cancels the packing");
        for (i = 0; i < 2 * mesh->ncorners; i++) same &= again[i] == -1.0f;
        CHECK(same, "cancelled: the UVs are untouched");
        free(again);
    }
    free(uv);
    tt_mesh_free(mesh);
}

/* Triangles whose sides differ 40-fold: one density for all of them with
   charts; the pair atlas, which gives every triangle the same texels, is
   the control that must break the same bound. */
static void test_atlas_pack_charts_uneven(void)
{
    tt_mesh *mesh = chart_uneven_sheet(32, 1.125);
    float *uv;
    tt_chart_atlas_report report;
    tt_error err;
    double spread[3];
    if (!mesh) return;
    uv = (float *)malloc(sizeof(float) * 2 * (size_t)mesh->ncorners);
    CHECK(tt_atlas_pack_charts(mesh, 512, 2, NULL, NULL, uv, &report, &err) == TT_OK, "uneven sheet: %s", err.message);
    chart_check_atlas("uneven sheet", mesh, uv, &report, 512, 2, spread);
    CHECK(tt_atlas_pack_pairs(mesh, 512, 2, uv, &err) == TT_OK, "pairs: %s", err.message);
    chart_density(mesh, uv, 512, spread);
    CHECK(spread[0] < 0.75 * spread[1] || spread[2] > 1.25 * spread[1],
          "control: the pair atlas spreads the density beyond 25%% (%.4g..%.4g, median %.4g)", spread[0], spread[2],
          spread[1]);
    free(uv);
    tt_mesh_free(mesh);
}

/* A ramp that covers itself seen from one direction: its charts are split
   where the flattening would overlap, and the UVs pass tt_uv_check. */
static void test_atlas_pack_charts_overlap(void)
{
    tt_mesh *mesh = chart_spiral_ramp(2.5);
    float *uv;
    tt_chart_atlas_report report;
    tt_uv_report check;
    tt_error err;
    tt_result result;
    double spread[3];
    if (!mesh) return;
    uv = (float *)malloc(sizeof(float) * 2 * (size_t)mesh->ncorners);
    CHECK(tt_atlas_pack_charts(mesh, 512, 2, NULL, NULL, uv, &report, &err) == TT_OK, "ramp: %s", err.message);
    CHECK(report.ncharts >= 3, "2.5 turns need at least 3 charts, got %d", report.ncharts);
    chart_check_atlas("spiral ramp", mesh, uv, &report, 512, 2, spread);
    result = tt_uv_check(mesh, uv, NULL, &check, &err);
    CHECK(result == TT_OK && check.problem == TT_UV_USABLE,
          "the ramp's atlas passes the UV check (problem %d at faces %d, %d)", (int)check.problem, check.face,
          check.other_face);
    free(uv);
    tt_mesh_free(mesh);
}


/* A coarse torus (32 x 16 quads, each split in two) at 512, gutter 2: with
   round charts, straightened borders and outlines of the texels the bake
   fills, the triangles fill 0.58 or more (0.60); charts by the cone alone
   as outlines of touched texels widened square filled 0.54. Control: the
   same mesh with gutter 6 fills less (0.43), so the bound tells the
   outlines' size apart. */
static void test_atlas_pack_charts_coarse(void)
{
    tt_mesh *mesh;
    float *uv;
    tt_chart_atlas_report report, wide;
    tt_error err;
    double spread[3];
    mesh = chart_torus(32, 16, 0.0);
    if (!mesh) return;
    uv = (float *)malloc(sizeof(float) * 2 * (size_t)mesh->ncorners);
    CHECK(tt_atlas_pack_charts(mesh, 512, 2, NULL, NULL, uv, &report, &err) == TT_OK, "512: %s", err.message);
    chart_check_atlas("coarse torus at 512", mesh, uv, &report, 512, 2, spread);
    CHECK(report.fill >= 0.58, "%d charts fill %.3f of the atlas", report.ncharts, report.fill);
    CHECK(tt_atlas_pack_charts(mesh, 512, 6, NULL, NULL, uv, &wide, &err) == TT_OK, "gutter 6: %s", err.message);
    chart_check_atlas("coarse torus at 512, gutter 6", mesh, uv, &wide, 512, 6, spread);
    CHECK(wide.fill < 0.58, "control: gutter 6 fills %.3f", wide.fill);
    free(uv);
    tt_mesh_free(mesh);
}

/* A coarse, noisy scan: a lumpy sphere of 3120 triangles with +-0.015 of
   noise per vertex, so that its normals scatter as a decimated scan's do
   and a chart is only a few triangles across. At 1024, gutter 2, the
   atlas fills 0.70 at one density (round charts grown in a 30 degree
   cone, their teeth moved in 40; the cone alone in 40); round charts grown
   in the 40 degree cone filled 0.66, with ragged borders along the cone's
   limit. */
static void test_atlas_pack_charts_noisy(void)
{
    tt_mesh *mesh;
    float *uv;
    tt_chart_atlas_report report;
    tt_error err;
    double spread[3];
    tmesh m;
    make_lumpy_sphere(&m, 40, 0.03);
    mesh = bake_build(&m, NULL);
    tm_free(&m);
    if (!mesh) return;
    uv = (float *)malloc(sizeof(float) * 2 * (size_t)mesh->ncorners);
    CHECK(tt_atlas_pack_charts(mesh, 1024, 2, NULL, NULL, uv, &report, &err) == TT_OK, "1024: %s", err.message);
    chart_check_atlas("noisy lumpy sphere at 1024", mesh, uv, &report, 1024, 2, spread);
    CHECK(spread[2] / spread[0] <= 1.2, "texel density p95 / p5 %.3f", spread[2] / spread[0]);
    CHECK(report.fill >= 0.68, "%d charts fill %.3f of the atlas", report.ncharts, report.fill);
    printf("     atlas fill on a noisy lumpy sphere: %d charts fill %.3f at 1024, density p95/p5 %.3f\n",
           report.ncharts, report.fill, spread[2] / spread[0]);
    free(uv);
    tt_mesh_free(mesh);
}

/* Too small: the size the message names is the smallest that works. */
static void test_atlas_pack_charts_small(void)
{
    const char *key = "smallest size that works is ";
    tt_mesh *mesh;
    float *uv;
    tt_chart_atlas_report report;
    tt_error err;
    const char *hint;
    int size = 0, f;
    lcg_seed(43);
    mesh = chart_torus(24, 12, 0.05);
    if (!mesh) return;
    uv = (float *)malloc(sizeof(float) * 2 * (size_t)mesh->ncorners);
    for (f = 0; f < 2 * mesh->ncorners; f++) uv[f] = -7.0f;
    CHECK(tt_atlas_pack_charts(mesh, 8, 2, NULL, NULL, uv, &report, &err) == TT_ERROR_IMAGE_TOO_SMALL,
          "8 texels too small: %s", err.message);
    CHECK(uv[0] == -7.0f && report.ncharts == 0, "nothing written on failure");
    hint = strstr(err.message, key);
    CHECK(hint != NULL, "the message suggests a size: %s", err.message);
    if (hint) size = atoi(hint + strlen(key));
    CHECK(tt_atlas_pack_charts(mesh, size, 2, NULL, NULL, uv, &report, &err) == TT_OK, "suggested size %d works: %s", size,
          err.message);
    CHECK(tt_atlas_pack_charts(mesh, size - 1, 2, NULL, NULL, uv, &report, &err) == TT_ERROR_IMAGE_TOO_SMALL,
          "size %d - 1 does not", size);
    CHECK(tt_atlas_pack_charts(mesh, 1024, 10000, NULL, NULL, uv, &report, &err) == TT_ERROR_IMAGE_TOO_SMALL &&
              strstr(err.message, "lower the gutter"),
          "a gutter no size holds: %s", err.message);
    free(uv);
    tt_mesh_free(mesh);
}

static void test_atlas_pack_charts_errors(void)
{
    tt_mesh *mesh = bake_grid(2, 2, 0.0, NULL), *qm;
    float uv[48];
    counter count;
    tt_allocator half = make_allocator(&count, -1);
    tt_error err;
    half.free = NULL;
    CHECK(tt_atlas_pack_charts(NULL, 64, 1, NULL, NULL, uv, NULL, &err) == TT_ERROR_INVALID_ARGUMENT, "NULL mesh refused");
    CHECK(tt_atlas_pack_charts(mesh, 64, 1, NULL, NULL, NULL, NULL, &err) == TT_ERROR_INVALID_ARGUMENT, "NULL uv refused");
    CHECK(tt_atlas_pack_charts(mesh, 0, 1, NULL, NULL, uv, NULL, &err) == TT_ERROR_INVALID_ARGUMENT, "size 0 refused");
    CHECK(tt_atlas_pack_charts(mesh, TT_MAX_IMAGE_SIZE + 1, 1, NULL, NULL, uv, NULL, &err) == TT_ERROR_INVALID_ARGUMENT,
          "size above TT_MAX_IMAGE_SIZE refused");
    CHECK(tt_atlas_pack_charts(mesh, 64, -1, NULL, NULL, uv, NULL, &err) == TT_ERROR_INVALID_ARGUMENT,
          "negative gutter refused");
    CHECK(tt_atlas_pack_charts(mesh, 64, 1, NULL, &half, uv, NULL, &err) == TT_ERROR_INVALID_ARGUMENT,
          "an allocator without free refused: %s", err.message);
    CHECK(tt_atlas_pack_charts(mesh, 64, 1, NULL, NULL, uv, NULL, NULL) == TT_OK, "no report, no error: fine");
    tt_mesh_free(mesh);
    qm = bake_quad();
    CHECK(tt_atlas_pack_charts(qm, 64, 1, NULL, NULL, uv, NULL, &err) == TT_ERROR_INVALID_ARGUMENT && err.face == 0,
          "quads refused, face 0 named: %s", err.message);
    tt_mesh_free(qm);
}

typedef struct chart_oom_ctx {
    const tt_mesh *mesh;
    float *uv;
} chart_oom_ctx;

static tt_result chart_oom_call(void *ctx, const tt_allocator *al, tt_error *error)
{
    chart_oom_ctx *c = (chart_oom_ctx *)ctx;
    tt_chart_atlas_report report;
    tt_result r = tt_atlas_pack_charts(c->mesh, 256, 2, NULL, al, c->uv, &report, error);
    if (error->result != r || (r != TT_OK && report.ncharts != 0)) return TT_RESULT_MAX_ENUM;
    return r;
}

static void test_atlas_pack_charts_oom(void)
{
    chart_oom_ctx c;
    tt_mesh *mesh;
    lcg_seed(47);
    mesh = chart_torus(16, 8, 0.05);
    if (!mesh) return;
    c.mesh = mesh;
    c.uv = (float *)malloc(sizeof(float) * 2 * (size_t)mesh->ncorners);
    oom_reset();
    oom_sweep("tt_atlas_pack_charts", chart_oom_call, &c, TT_OK);
    free(c.uv);
    tt_mesh_free(mesh);
}

/* ---- tt_uv_check ---- */

/* Each kind of problem, at the face it is put on; atlases of both kinds
   pass; triangles that only share an edge in UV do not overlap. */
static void test_uv_check(void)
{
    tt_mesh *mesh;
    float *uv, keep[6];
    tt_uv_report r;
    tt_error err;
    tt_result result;
    int k;
    lcg_seed(53);
    mesh = bake_grid(6, 5, 0.4, NULL);
    if (!mesh) return;
    uv = (float *)malloc(sizeof(float) * 2 * (size_t)mesh->ncorners);
    CHECK(tt_atlas_pack_charts(mesh, 128, 2, NULL, NULL, uv, NULL, &err) == TT_OK, "charts: %s", err.message);
    result = tt_uv_check(mesh, uv, NULL, &r, &err);
    CHECK(result == TT_OK && r.problem == TT_UV_USABLE && r.face == -1 &&
              r.other_face == -1 && r.flipped_faces == 0,
          "a chart atlas is usable (problem %d)", (int)r.problem);
    CHECK(tt_atlas_pack_pairs(mesh, 128, 2, uv, &err) == TT_OK, "pairs: %s", err.message);
    result = tt_uv_check(mesh, uv, NULL, &r, &err);
    CHECK(result == TT_OK && r.problem == TT_UV_USABLE, "a pair atlas is usable (%d)",
          (int)r.problem);
    /* The grid's own positions as UVs: neighbours share edges exactly. */
    for (k = 0; k < mesh->ncorners; k++) {
        uv[2 * k] = mesh->pos[3 * mesh->corner_vert[k]] / 6.0f;
        uv[2 * k + 1] = mesh->pos[3 * mesh->corner_vert[k] + 1] / 5.0f;
    }
    result = tt_uv_check(mesh, uv, NULL, &r, &err);
    CHECK(result == TT_OK && r.problem == TT_UV_USABLE,
          "the planar layout of the grid is usable (problem %d at %d, %d)", (int)r.problem, r.face, r.other_face);
    memcpy(keep, uv + 6 * 7, sizeof keep);
    /* Face 7 mirrored (u -> 1 - u): flipped, and the only one. */
    for (k = 0; k < 3; k++) uv[6 * 7 + 2 * k] = 1.0f - uv[6 * 7 + 2 * k];
    result = tt_uv_check(mesh, uv, NULL, &r, &err);
    CHECK(result == TT_OK && r.problem == TT_UV_FLIPPED && r.face == 7 &&
              r.flipped_faces == 1,
          "mirrored face 7: flipped (problem %d, face %d, %d flipped)", (int)r.problem, r.face, r.flipped_faces);
    /* Face 7 on top of face 3: an overlap naming both. */
    memcpy(uv + 6 * 7, uv + 6 * 3, sizeof keep);
    result = tt_uv_check(mesh, uv, NULL, &r, &err);
    CHECK(result == TT_OK && r.problem == TT_UV_OVERLAP && r.face == 3 &&
              r.other_face == 7,
          "face 7 over face 3: overlap (problem %d, faces %d and %d)", (int)r.problem, r.face, r.other_face);
    memcpy(uv + 6 * 7, keep, sizeof keep);
    /* Face 9 collapsed onto a line. */
    memcpy(keep, uv + 6 * 9, sizeof keep);
    uv[6 * 9 + 4] = uv[6 * 9 + 2];
    uv[6 * 9 + 5] = uv[6 * 9 + 3];
    result = tt_uv_check(mesh, uv, NULL, &r, &err);
    CHECK(result == TT_OK && r.problem == TT_UV_DEGENERATE && r.face == 9,
          "face 9 of zero area: degenerate (problem %d, face %d)", (int)r.problem, r.face);
    memcpy(uv + 6 * 9, keep, sizeof keep);
    uv[6 * 11 + 3] = 1.0001f;
    result = tt_uv_check(mesh, uv, NULL, &r, &err);
    CHECK(result == TT_OK && r.problem == TT_UV_OUTSIDE && r.face == 11,
          "face 11 past v = 1: outside (problem %d, face %d)", (int)r.problem, r.face);
    uv[6 * 2 + 1] = (float)internal_not_a_number();
    result = tt_uv_check(mesh, uv, NULL, &r, &err);
    CHECK(result == TT_OK && r.problem == TT_UV_NON_FINITE && r.face == 2,
          "NaN at face 2: non-finite first (problem %d, face %d)", (int)r.problem, r.face);
    free(uv);
    tt_mesh_free(mesh);
}

static void test_uv_check_errors(void)
{
    tt_mesh *mesh = bake_grid(2, 2, 0.0, NULL), *qm;
    float uv[48] = {0};
    tt_uv_report r;
    counter count;
    tt_allocator half = make_allocator(&count, -1);
    tt_error err;
    half.alloc = NULL;
    CHECK(tt_uv_check(NULL, uv, NULL, &r, &err) == TT_ERROR_INVALID_ARGUMENT, "NULL mesh refused");
    CHECK(tt_uv_check(mesh, NULL, NULL, &r, &err) == TT_ERROR_INVALID_ARGUMENT, "NULL uv refused");
    CHECK(tt_uv_check(mesh, uv, NULL, NULL, &err) == TT_ERROR_INVALID_ARGUMENT, "NULL report refused");
    CHECK(tt_uv_check(mesh, uv, &half, &r, &err) == TT_ERROR_INVALID_ARGUMENT, "an allocator without alloc refused");
    tt_mesh_free(mesh);
    qm = bake_quad();
    CHECK(tt_uv_check(qm, uv, NULL, &r, &err) == TT_ERROR_INVALID_ARGUMENT && err.face == 0,
          "quads refused, face 0 named: %s", err.message);
    tt_mesh_free(qm);
}

typedef struct uv_check_oom_ctx {
    const tt_mesh *mesh;
    const float *uv;
    tt_uv_problem expected;
} uv_check_oom_ctx;

static tt_result uv_check_oom_call(void *ctx, const tt_allocator *al, tt_error *error)
{
    uv_check_oom_ctx *c = (uv_check_oom_ctx *)ctx;
    tt_uv_report report;
    tt_result r = tt_uv_check(c->mesh, c->uv, al, &report, error);
    if (error->result != r || (r == TT_OK && report.problem != c->expected)) return TT_RESULT_MAX_ENUM;
    return r;
}

static void test_uv_check_oom(void)
{
    uv_check_oom_ctx c;
    tt_mesh *mesh;
    float *uv;
    lcg_seed(59);
    mesh = bake_grid(5, 5, 0.3, NULL);
    if (!mesh) return;
    uv = (float *)malloc(sizeof(float) * 2 * (size_t)mesh->ncorners);
    tt_atlas_pack_pairs(mesh, 128, 2, uv, NULL);
    c.mesh = mesh;
    c.uv = uv;
    c.expected = TT_UV_USABLE;
    oom_reset();
    oom_sweep("tt_uv_check (usable)", uv_check_oom_call, &c, TT_OK);
    memcpy(uv + 6 * 4, uv + 6 * 1, 6 * sizeof(float));
    c.expected = TT_UV_OVERLAP;
    oom_sweep("tt_uv_check (overlap)", uv_check_oom_call, &c, TT_OK);
    free(uv);
    tt_mesh_free(mesh);
}

/* ---- tt_lapped_bake ---- */

/* tt_lapped_bake with only a gutter set (default allocator). */
static tt_result bake_gutter(const tt_mesh *mesh, const tt_lapped *lapped, tt_image *const *patches, int npatches,
                             const float *uv, int gutter, tt_image *atlas, tt_error *err)
{
    tt_bake_options opt;
    memset(&opt, 0, sizeof opt);
    opt.gutter = gutter;
    return tt_lapped_bake(mesh, lapped, patches, npatches, uv, &opt, NULL, atlas, err);
}

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
    tt_image *patches[2], *atlas = NULL;
    lb_builder b;
    tt_error err;
    unsigned char *inside;
    int i, bad, ninside = 0;
    patches[0] = bake_constant(16, 16, 1, 0, 0, 1);
    patches[1] = bake_constant(8, 8, 0, 0, 1, 0.5f);
    bake_square_uvs(mesh, 0.25, 0.75, uv);
    lb_init(&b);
    lb_paste_all(&b, mesh, 0, id, zero);
    tt_image_create(40, 32, NULL, &atlas, NULL);
    CHECK(bake_gutter(mesh, &b.l, patches, 2, uv, 2, atlas, &err) == TT_OK, "red: %s", err.message);
    inside = bake_raster_mask(mesh, uv, 40, 32);
    for (i = 0; i < 40 * 32; i++) ninside += inside[i];
    CHECK(ninside > 200, "triangles cover %d texels", ninside);
    bad = bake_count_off(atlas, inside, 1, 0, 0, 1);
    CHECK(bad == 0, "red: %d texels inside the triangles not opaque red", bad);
    bad = bake_count_off(atlas, NULL, 1, 0, 0, 1);
    CHECK(bad == 0, "red: %d texels anywhere not red after the fill", bad);

    /* A second paste, half-transparent blue over red: straight colour is the
       premultiplied "over" divided by alpha: (0.5, 0, 0.5), alpha 1. */
    lb_paste_all(&b, mesh, 1, id, zero);
    CHECK(bake_gutter(mesh, &b.l, patches, 2, uv, 2, atlas, &err) == TT_OK, "blue over red: %s", err.message);
    bad = bake_count_off(atlas, NULL, 0.5, 0, 0.5, 1);
    CHECK(bad == 0, "%d texels differ from blue (alpha 0.5) over red", bad);

    /* Only the blue paste: alpha 0.5, straight colour pure blue. */
    b.l.pastes[0].nfaces = 0;
    CHECK(bake_gutter(mesh, &b.l, patches, 2, uv, 0, atlas, &err) == TT_OK, "blue only: %s", err.message);
    bad = bake_count_off(atlas, NULL, 0, -1, 1, 0.5);
    CHECK(bad == 0, "%d texels not straight blue with alpha 0.5", bad);

    /* No pastes at all: transparent black everywhere, still OK. */
    b.l.npastes = 0;
    CHECK(bake_gutter(mesh, &b.l, patches, 2, uv, 1, atlas, &err) == TT_OK, "no pastes: %s", err.message);
    bad = bake_count_off(atlas, NULL, 0, 0, 0, 0);
    CHECK(bad == 0, "no pastes: %d texels not transparent black", bad);
    free(inside);
    lb_free(&b);
    tt_image_free(atlas);
    tt_image_free(patches[0]);
    tt_image_free(patches[1]);
    tt_mesh_free(mesh);
}

/* Normal-map patches: the vectors are turned from each paste's frame into
   the atlas's. A grid whose atlas UVs are its positions (scaled), pasted
   with uv = s R(theta) (x, y) + o: the patch's axes lie along R(-theta) of
   the atlas's, so a constant patch vector v bakes to R(-theta) v; a
   half-transparent paste over another bakes to the normalised blend of the
   two turned vectors. The control, the same patch baked as colour, keeps v
   unturned and must fail; patches of mixed kinds are refused. */
static void test_lapped_bake_normals(void)
{
    tt_mesh *mesh = bake_grid(4, 4, 0.3, NULL);
    const double t0 = 0.7, t1 = -2.1, zero[2] = {0.5, 0.5};
    const float v[3] = {0.36f, 0.48f, 0.8f};
    double m0[4], m1[4], e0[2], e1[2], mix[3], length;
    tt_image *patches[2], *atlas = NULL;
    float *uv = NULL;
    lb_builder b;
    tt_error err;
    unsigned char *inside = NULL;
    int c, i, bad, control_bad, pass;
    if (!mesh) return;
    uv = (float *)malloc(sizeof(float) * 2 * (size_t)mesh->ncorners);
    for (c = 0; c < mesh->ncorners; c++) {
        const float *p = mesh->pos + 3 * mesh->corner_vert[c];
        uv[2 * c] = 0.1f + 0.2f * p[0];
        uv[2 * c + 1] = 0.1f + 0.2f * p[1];
    }
    m0[0] = 0.2 * cos(t0); m0[1] = -0.2 * sin(t0); m0[2] = 0.2 * sin(t0); m0[3] = 0.2 * cos(t0);
    m1[0] = 0.2 * cos(t1); m1[1] = -0.2 * sin(t1); m1[2] = 0.2 * sin(t1); m1[3] = 0.2 * cos(t1);
    e0[0] = cos(-t0) * v[0] - sin(-t0) * v[1]; e0[1] = sin(-t0) * v[0] + cos(-t0) * v[1];
    e1[0] = cos(-t1) * v[0] - sin(-t1) * v[1]; e1[1] = sin(-t1) * v[0] + cos(-t1) * v[1];
    mix[0] = 0.5 * (e0[0] + e1[0]); mix[1] = 0.5 * (e0[1] + e1[1]); mix[2] = v[2];
    length = sqrt(mix[0] * mix[0] + mix[1] * mix[1] + mix[2] * mix[2]);
    patches[0] = bake_constant(32, 32, v[0], v[1], v[2], 1.0f);
    patches[1] = bake_constant(32, 32, v[0], v[1], v[2], 0.5f);
    tt_image_create(64, 64, NULL, &atlas, NULL);
    inside = bake_raster_mask(mesh, uv, 64, 64);
    lb_init(&b);
    lb_paste_all(&b, mesh, 0, m0, zero);
    for (pass = 0; pass < 3; pass++) {
        const double *want = pass == 0 ? e0 : mix;
        double wz = pass == 0 ? v[2] : v[2] / length, wx = pass == 0 ? want[0] : want[0] / length,
               wy = pass == 0 ? want[1] : want[1] / length;
        int normal = pass < 2;
        if (pass == 1) lb_paste_all(&b, mesh, 1, m1, zero);
        patches[0]->kind = patches[1]->kind = normal ? TT_IMAGE_NORMAL : TT_IMAGE_COLOR;
        CHECK(bake_gutter(mesh, &b.l, patches, 2, uv, 2, atlas, &err) == TT_OK, "bake pass %d: %s", pass,
              err.message);
        bad = control_bad = 0;
        for (i = 0; i < 64 * 64; i++) {
            const float *p = atlas->pixels + 4 * i;
            int off = fabs(p[0] - wx) > 1e-4 || fabs(p[1] - wy) > 1e-4 || fabs(p[2] - wz) > 1e-4;
            if (!inside[i]) continue;
            if (normal) bad += off;
            else control_bad += off;
        }
        if (normal) {
            CHECK(atlas->kind == TT_IMAGE_NORMAL, "the atlas of normal patches is a normal map");
            CHECK(bad == 0, "pass %d: %d texels are not the turned (and blended) vector (%g, %g, %g)", pass, bad, wx,
                  wy, wz);
        } else {
            CHECK(atlas->kind == TT_IMAGE_COLOR, "the atlas of colour patches is colour");
            CHECK(control_bad > 100, "control (patches as colour): %d texels off the turned blend", control_bad);
        }
    }
    patches[1]->kind = TT_IMAGE_NORMAL;
    CHECK(bake_gutter(mesh, &b.l, patches, 2, uv, 2, atlas, &err) == TT_ERROR_INVALID_ARGUMENT &&
              strstr(err.message, "normal map"),
          "a colour patch and a normal patch in one bake are refused: %s", err.message);
    free(inside);
    free(uv);
    lb_free(&b);
    tt_image_free(atlas);
    tt_image_free(patches[0]);
    tt_image_free(patches[1]);
    tt_mesh_free(mesh);
}

/* A smooth colour ramp patch: r = x / w, g = y / h, b = 0.5, opaque. */
static tt_image *bake_ramp(int w, int h)
{
    tt_image *img = NULL;
    int x, y;
    if (tt_image_create(w, h, NULL, &img, NULL) != TT_OK) return NULL;
    for (y = 0; y < h; y++)
        for (x = 0; x < w; x++) {
            float *p = img->pixels + 4 * (y * w + x);
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
    tt_image *ramp = bake_ramp(64, 64), *atlas = NULL;
    lb_builder b;
    tt_error err;
    unsigned char *inside;
    int W = 50, H = 60, x, y, k, ngutter = 0, bad = 0, gutter = 3, nfar = 0, badfar = 0;
    double maxdiff = 0, X[3], Y[3], area2;
    lb_init(&b);
    lb_begin(&b, 0);
    lb_add(&b, 0, puv);
    tt_image_create(W, H, NULL, &atlas, NULL);
    CHECK(bake_gutter(mesh, &b.l, &ramp, 1, uv, gutter, atlas, &err) == TT_OK, "bake: %s", err.message);
    inside = bake_raster_mask(mesh, uv, W, H);
    for (k = 0; k < 3; k++) { X[k] = uv[2 * k] * W; Y[k] = (1.0 - uv[2 * k + 1]) * H; }
    area2 = (X[1] - X[0]) * (Y[2] - Y[0]) - (X[2] - X[0]) * (Y[1] - Y[0]);
    for (y = 0; y < H; y++)
        for (x = 0; x < W; x++) {
            double qx = x + 0.5, qy = y + 0.5, w0, w1, w2, u, v, d = bake_triangle_distance(X, Y, qx, qy);
            float want[4];
            const float *got = atlas->pixels + 4 * (y * W + x);
            w0 = ((X[1] - qx) * (Y[2] - qy) - (X[2] - qx) * (Y[1] - qy)) / area2;
            w1 = ((X[2] - qx) * (Y[0] - qy) - (X[0] - qx) * (Y[2] - qy)) / area2;
            w2 = 1 - w0 - w1;
            u = w0 * puv[0] + w1 * puv[2] + w2 * puv[4];
            v = w0 * puv[1] + w1 * puv[3] + w2 * puv[5];
            tt_image_sample_bilinear(ramp, (float)(u * 64), (float)((1 - v) * 64), want);
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
    tt_image_free(atlas);
    tt_image_free(ramp);
    tt_mesh_free(mesh);
}

static tt_image *bake_checker(int w, int h, int square)
{
    tt_image *img = NULL;
    int x, y;
    if (tt_image_create(w, h, NULL, &img, NULL) != TT_OK) return NULL;
    for (y = 0; y < h; y++)
        for (x = 0; x < w; x++) {
            float *p = img->pixels + 4 * (y * w + x);
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
    tt_image *checker = bake_checker(64, 64, 8), *atlas = NULL;
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
    tt_image_create(size, size, NULL, &atlas, NULL);
    CHECK(bake_gutter(mesh, &b.l, &checker, 1, uv, 2, atlas, &err) == TT_OK, "bake: %s", err.message);
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
        diff = bake_seam_diff(mesh, &b.l, uv, atlas, checker, f, w);
        sum_all += diff;
        n_all++;
        if (fmin(w[0], fmin(w[1], w[2])) < 0.01) { sum_edge += diff; n_edge++; }
    }
    CHECK(sum_all / n_all < 0.02, "mean abs difference %g", sum_all / n_all);
    CHECK(n_edge > 5000 && sum_edge / n_edge < 0.02, "near edges: mean abs difference %g over %d",
          n_edge ? sum_edge / n_edge : -1.0, n_edge);
    /* Without gutters the same edge samples read the fill's copies: the
       gutter must do better than that. */
    CHECK(bake_gutter(mesh, &b.l, &checker, 1, uv, 0, atlas, &err) == TT_OK, "bake without gutter: %s",
          err.message);
    lcg_seed(99);
    for (i = 0; i < 10000; i++) {
        int f = lcg_below(mesh->nfaces);
        double w[3], r;
        w[0] = 0.002 * lcg_unit();
        r = lcg_unit();
        w[1] = (1 - w[0]) * r;
        w[2] = 1 - w[0] - w[1];
        sum_nogutter += bake_seam_diff(mesh, &b.l, uv, atlas, checker, f, w);
        ne++;
    }
    sum_nogutter /= ne;
    CHECK(n_edge > 0 && sum_nogutter >= sum_edge / n_edge, "gutter helps at edges: %g with, %g without",
          n_edge ? sum_edge / n_edge : -1.0, sum_nogutter);
    free(uv);
    lb_free(&b);
    tt_image_free(atlas);
    tt_image_free(checker);
    tt_mesh_free(mesh);
}

/* The interior edges where the paste on top changes, each named by its
   lower corner; returns how many (edges holds ncorners). */
static int lapped_top_change_edges(const tt_mesh *mesh, const tt_lapped *lapped, int *edges)
{
    int *top = (int *)malloc(sizeof(int) * (size_t)mesh->nfaces), f, p, e, c, n = 0;
    for (f = 0; f < mesh->nfaces; f++) top[f] = -1;
    for (p = 0; p < lapped->npastes; p++)
        for (e = lapped->pastes[p].first; e < lapped->pastes[p].first + lapped->pastes[p].nfaces; e++)
            top[lapped->faces[e]] = p;
    for (c = 0; c < mesh->ncorners; c++)
        if (mesh->twin[c] > c && top[mesh->corner_face[c]] != top[mesh->corner_face[mesh->twin[c]]]) edges[n++] = c;
    free(top);
    return n;
}

/* The acceptance measure of soft edges: the seam score (tt_measure_seams)
   of the baked texture over an atlas of triangle pairs, over every edge and
   over the edges where the paste on top changes. Controls that must score
   badly: the same bake with each face given another face's UVs, and a fully
   opaque patch baked without its fade (every paste ends with a hard
   edge). */
static void test_lapped_baked_seams(void)
{
    tt_image *patch = lapped_patch(64, 5), *opaque = lapped_patch(64, 5);
    double scores[2][2] = {{0, 0}, {0, 0}}, shuffled = 0.0;
    int which, ok = 1;
    size_t i;
    for (i = 0; opaque && i < (size_t)opaque->width * opaque->height; i++) opaque->pixels[4 * i + 3] = 1.0f;
    for (which = 0; which < 2 && patch && opaque; which++) {
        tmesh m;
        tt_mesh *mesh;
        float *field, *uv = NULL, *moved = NULL;
        int *edges = NULL, nedges = 0, f, k;
        float *fade, *cut;
        tt_lapped *lapped = NULL;
        tt_image *used = which ? opaque : patch, *atlas = NULL;
        tt_seam_options so;
        tt_seam_report rep;
        tt_error err;
        make_lapped_shape(&m, 0);
        if (lapped_run(&m, 0, 11, 0.0f, &mesh, &field, used, &lapped) != 0) {
            ok = 0;
            tm_free(&m);
            continue;
        }
        uv = (float *)malloc(sizeof(float) * 2 * (size_t)mesh->ncorners);
        moved = (float *)malloc(sizeof(float) * 2 * (size_t)mesh->ncorners);
        edges = (int *)malloc(sizeof(int) * (size_t)mesh->ncorners);
        fade = lapped->fade;
        cut = lapped->cut;
        /* The control's pastes end hard: neither faded nor cut. */
        if (which) lapped->fade = lapped->cut = NULL;
        tt_image_create(512, 512, NULL, &atlas, NULL);
        ok &= uv && moved && edges && atlas && tt_atlas_pack_pairs(mesh, 512, 2, uv, &err) == TT_OK &&
              bake_gutter(mesh, lapped, &used, 1, uv, 2, atlas, &err) == TT_OK;
        if (ok) {
            memset(&so, 0, sizeof so);
            so.seed = 3;
            ok &= tt_measure_seams(mesh, uv, atlas, &so, NULL, &rep, &err) == TT_OK;
            scores[which][0] = rep.score;
            nedges = lapped_top_change_edges(mesh, lapped, edges);
            so.edges = edges;
            so.nedges = nedges;
            ok &= nedges > 0 && tt_measure_seams(mesh, uv, atlas, &so, NULL, &rep, &err) == TT_OK;
            scores[which][1] = rep.score;
            if (which == 0) {
                /* each face reads the atlas triangle of the face a third of the mesh further on */
                for (f = 0; f < mesh->nfaces; f++)
                    for (k = 0; k < 6; k++)
                        moved[6 * f + k] = uv[6 * ((f + mesh->nfaces / 3) % mesh->nfaces) + k];
                so.edges = NULL;
                so.nedges = 0;
                ok &= tt_measure_seams(mesh, moved, atlas, &so, NULL, &rep, &err) == TT_OK;
                shuffled = rep.score;
            }
        }
        free(uv);
        free(moved);
        free(edges);
        tt_image_free(atlas);
        lapped->fade = fade;
        lapped->cut = cut;
        tt_lapped_free(lapped);
        tt_mesh_free(mesh);
        free(field);
        tm_free(&m);
    }
    CHECK(ok && scores[0][0] <= 0.05 && scores[0][1] <= 0.1,
          "baked seam score with the soft splotch: %.3f over every edge (want <= 0.05), %.3f where the top paste "
          "changes (want <= 0.1)", scores[0][0], scores[0][1]);
    CHECK(ok && shuffled >= 0.8, "the control, faces given other faces' UVs: %.3f (want >= 0.8)", shuffled);
    CHECK(ok && scores[1][1] >= 0.5 && scores[1][1] >= 4.0 * scores[0][1],
          "the control, an opaque patch without its fade: %.3f where the top paste changes (want >= 0.5 and 4 times "
          "the splotch's %.3f)",
          scores[1][1], scores[0][1]);
    printf("     baked seam score on a sphere: %.3f over every edge, %.3f where the top paste changes; controls: "
           "shuffled UVs %.3f, an opaque patch without its fade %.3f\n", scores[0][0], scores[0][1], shuffled, scores[1][1]);
    tt_image_free(patch);
    tt_image_free(opaque);
}

/* The bake through an executor (bands of rows run in reverse order, or on
   two threads) gives the serial atlas bit for bit: colour patches with a
   gutter, and normal-map patches (turned per face and paste). */
static void test_lapped_bake_executor(void)
{
    tmesh m;
    tt_mesh *mesh = NULL;
    float *field = NULL, *uv = NULL;
    tt_lapped *lapped = NULL;
    tt_image *patch = lapped_patch(64, 7), *atlas = NULL, *serial = NULL;
    const tt_executor *executors[2];
    int kind, e;
    executors[0] = &g_reverse_executor;
    executors[1] = &g_thread_executor;
    make_lapped_shape(&m, 0);
    if (!patch || lapped_run(&m, 0, 5, 0.0f, &mesh, &field, patch, &lapped) != 0) {
        CHECK(0, "bake executor: the pastes could not be made");
        tm_free(&m);
        tt_image_free(patch);
        return;
    }
    uv = (float *)malloc(sizeof(float) * 2 * (size_t)mesh->ncorners);
    tt_image_create(300, 700, NULL, &atlas, NULL);
    tt_image_create(300, 700, NULL, &serial, NULL);
    CHECK(tt_atlas_pack_pairs(mesh, 300, 2, uv, NULL) == TT_OK, "bake executor: pack");
    for (kind = 0; kind < 2; kind++) {
        tt_bake_options opt;
        tt_error err;
        tt_result r;
        size_t n = 4 * (size_t)300 * 700;
        patch->kind = kind ? TT_IMAGE_NORMAL : TT_IMAGE_COLOR;
        memset(&opt, 0, sizeof opt);
        opt.gutter = 2;
        r = tt_lapped_bake(mesh, lapped, &patch, 1, uv, &opt, NULL, serial, &err);
        CHECK(r == TT_OK, "bake executor, %s: serial bake %d (%s)", kind ? "normals" : "colour", (int)r, err.message);
        for (e = 0; e < 2 && r == TT_OK; e++) {
            opt.executor = executors[e];
            memset(atlas->pixels, 0, n * sizeof(float));
            r = tt_lapped_bake(mesh, lapped, &patch, 1, uv, &opt, NULL, atlas, &err);
            CHECK(r == TT_OK && atlas->kind == serial->kind &&
                      memcmp(atlas->pixels, serial->pixels, n * sizeof(float)) == 0,
                  "bake executor %d, %s: %d (%s), the atlas differs from the serial one", e,
                  kind ? "normals" : "colour", (int)r, err.message);
        }
    }
    free(uv);
    tt_image_free(atlas);
    tt_image_free(serial);
    tt_lapped_free(lapped);
    tt_mesh_free(mesh);
    free(field);
    tm_free(&m);
    tt_image_free(patch);
}

/* Two faces with the same atlas triangle: the later face's pastes win. */
static void test_lapped_bake_order(void)
{
    float uv[12] = {0.1f, 0.1f, 0.9f, 0.1f, 0.9f, 0.9f, 0.1f, 0.1f, 0.9f, 0.1f, 0.9f, 0.9f};
    float puv[6] = {0, 0, 1, 0, 1, 1};
    tt_mesh *mesh = bake_grid(1, 1, 0.0, NULL);
    tt_image *patches[2], *atlas = NULL;
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
    tt_image_create(20, 20, NULL, &atlas, NULL);
    CHECK(bake_gutter(mesh, &b.l, patches, 2, uv, 1, atlas, &err) == TT_OK, "bake: %s", err.message);
    p = atlas->pixels + 4 * (12 * 20 + 14);
    CHECK(p[1] == 1.0f && p[0] == 0.0f, "face 1 (green) wins, got %g %g %g", p[0], p[1], p[2]);
    lb_free(&b);
    tt_image_free(atlas);
    tt_image_free(patches[0]);
    tt_image_free(patches[1]);
    tt_mesh_free(mesh);
}

/* A face far larger than its pastes (a coarse mesh): 90 small pastes over
   one square, most of them 0 at most texels, which the bake passes by. The
   atlas must equal every paste composited with "over", bottom first, at
   every texel (a naive reference). Every seventh paste is a patch whose
   border is not clear: clamped sampling spreads its edge over the whole
   square, so it must never be passed by. */
static void test_lapped_bake_many_small_pastes(void)
{
    const int size = 64, npastes = 90;
    tt_mesh *mesh = bake_grid(1, 1, 0.0, NULL);
    tt_image *patches[2], *atlas = NULL;
    float uv[12];
    double maps[90][6];
    lb_builder b;
    tt_error err;
    int k, x, y, i, worst_x = -1, worst_y = -1;
    double worst = 0.0;
    CHECK(tt_image_create(16, 16, NULL, &patches[0], NULL) == TT_OK, "patch 0");
    for (y = 0; y < 16; y++)
        for (x = 0; x < 16; x++) {
            float *p = patches[0]->pixels + 4 * (y * 16 + x);
            double r = sqrt((x + 0.5 - 8.0) * (x + 0.5 - 8.0) + (y + 0.5 - 8.0) * (y + 0.5 - 8.0));
            float a = r < 5.0 ? 1.0f : (r < 7.0 ? (float)((7.0 - r) / 2.0) : 0.0f);
            p[0] = a * (float)x / 16.0f;
            p[1] = a * (float)y / 16.0f;
            p[2] = a * 0.5f;
            p[3] = a;
        }
    patches[1] = bake_constant(8, 8, 0.2f, 0.9f, 0.4f, 0.25f);
    lcg_seed(7);
    lb_init(&b);
    for (k = 0; k < npastes; k++) {
        double angle = 6.283185307179586 * lcg_unit(), scale = 1.0 / (0.1 + 0.1 * lcg_unit());
        double cx = lcg_unit(), cy = lcg_unit(), *m = maps[k];
        m[0] = scale * cos(angle);
        m[1] = -scale * sin(angle);
        m[2] = scale * sin(angle);
        m[3] = scale * cos(angle);
        m[4] = 0.5 - m[0] * cx - m[1] * cy;
        m[5] = 0.5 - m[2] * cx - m[3] * cy;
        lb_paste_all(&b, mesh, k % 7 == 3, m, m + 4);
    }
    bake_square_uvs(mesh, 0.0, 1.0, uv);
    tt_image_create(size, size, NULL, &atlas, NULL);
    CHECK(bake_gutter(mesh, &b.l, patches, 2, uv, 0, atlas, &err) == TT_OK, "bake: %s", err.message);
    for (y = 0; y < size; y++)
        for (x = 0; x < size; x++) {
            /* the surface point of the texel's centre: atlas UV = position */
            double px = (x + 0.5) / size, py = 1.0 - (y + 0.5) / size, d;
            float out[4] = {0.0f, 0.0f, 0.0f, 0.0f};
            const float *got = atlas->pixels + 4 * (y * size + x);
            for (k = 0; k < npastes; k++) {
                const tt_image *patch = patches[k % 7 == 3];
                double u = maps[k][0] * px + maps[k][1] * py + maps[k][4];
                double v = maps[k][2] * px + maps[k][3] * py + maps[k][5];
                double sx = u * patch->width, sy = (1.0 - v) * patch->height;
                float sample[4];
                sx = sx < -1.0 ? -1.0 : (sx > patch->width + 1.0 ? patch->width + 1.0 : sx);
                sy = sy < -1.0 ? -1.0 : (sy > patch->height + 1.0 ? patch->height + 1.0 : sy);
                tt_image_sample_bilinear(patch, (float)sx, (float)sy, sample);
                for (i = 0; i < 4; i++) out[i] = sample[i] + (1.0f - sample[3]) * out[i];
            }
            /* the bake stores straight colour */
            if (out[3] > 0.0f)
                for (i = 0; i < 3; i++) out[i] /= out[3];
            for (i = 0; i < 4; i++) {
                d = fabs((double)got[i] - out[i]);
                if (d > worst) {
                    worst = d;
                    worst_x = x;
                    worst_y = y;
                }
            }
        }
    CHECK(worst < 1e-4, "90 pastes on one square: the bake differs from compositing every paste by %g at texel (%d, %d)",
          worst, worst_x, worst_y);
    lb_free(&b);
    tt_image_free(atlas);
    tt_image_free(patches[0]);
    tt_image_free(patches[1]);
    tt_mesh_free(mesh);
}

/* A tt_lapped_bake error: the code, err.result, a message without long
   digit runs, the item (-2: not compared) and the face (-2: not compared). */
#define BAKE_EXPECT(call, code, item_, face_, what)                                                             \
    do {                                                                                                        \
        tt_result r_ = (call);                                                                                  \
        CHECK(r_ == (code) && err.result == (code) && err.message[0] != '\0' &&                                 \
                  longest_digit_run(err.message) <= 12 && (item_ == -2 || err.item == item_) &&                \
                  (face_ == -2 || err.face == face_),                                                           \
              "%s: expected %d (item %d, face %d), got %d (item %d, face %d): %s", what, (int)(code), item_,  \
              face_, (int)r_, err.item, err.face, err.message);                                                \
    } while (0)

static void test_lapped_bake_errors(void)
{
    tt_mesh *mesh = bake_grid(1, 1, 0.0, NULL), *qm;
    float uv[12], quv[8] = {0, 0, 1, 0, 1, 1, 0, 1};
    double id[4] = {1, 0, 0, 1}, zero[2] = {0, 0};
    tt_image *red = bake_constant(4, 4, 1, 0, 0, 1), *atlas = NULL, empty, *two[2];
    lb_builder b;
    tt_error err;
    bake_square_uvs(mesh, 0.1, 0.9, uv);
    lb_init(&b);
    lb_paste_all(&b, mesh, 0, id, zero);
    tt_image_create(16, 16, NULL, &atlas, NULL);
    memset(&empty, 0, sizeof empty);

    BAKE_EXPECT(bake_gutter(NULL, &b.l, &red, 1, uv, 1, atlas, &err), TT_ERROR_INVALID_ARGUMENT, -1, -1, "NULL mesh");
    BAKE_EXPECT(bake_gutter(mesh, NULL, &red, 1, uv, 1, atlas, &err), TT_ERROR_INVALID_ARGUMENT, -1, -1,
                "NULL lapped");
    BAKE_EXPECT(bake_gutter(mesh, &b.l, NULL, 1, uv, 1, atlas, &err), TT_ERROR_INVALID_ARGUMENT, -1, -1,
                "NULL patches");
    BAKE_EXPECT(bake_gutter(mesh, &b.l, &red, 1, NULL, 1, atlas, &err), TT_ERROR_INVALID_ARGUMENT, -1, -1, "NULL uv");
    BAKE_EXPECT(bake_gutter(mesh, &b.l, &red, 1, uv, 1, NULL, &err), TT_ERROR_INVALID_ARGUMENT, -1, -1, "NULL atlas");
    BAKE_EXPECT(bake_gutter(mesh, &b.l, &red, 1, uv, 1, &empty, &err), TT_ERROR_INVALID_ARGUMENT, -2, -2,
                "empty atlas");
    BAKE_EXPECT(bake_gutter(mesh, &b.l, &red, 0, uv, 1, atlas, &err), TT_ERROR_INVALID_ARGUMENT, -2, -2,
                "npatches 0");
    BAKE_EXPECT(bake_gutter(mesh, &b.l, &red, 1, uv, -1, atlas, &err), TT_ERROR_INVALID_ARGUMENT, -2, -2,
                "gutter -1");
    {
        counter hc;
        tt_allocator half = make_allocator(&hc, -1);
        half.alloc = NULL;   /* free without alloc */
        BAKE_EXPECT(tt_lapped_bake(mesh, &b.l, &red, 1, uv, NULL, &half, atlas, &err), TT_ERROR_INVALID_ARGUMENT, -2,
                    -2, "allocator without alloc");
    }
    /* The patches array: an empty image, a NULL pointer; the index in item. */
    two[0] = red;
    two[1] = &empty;
    BAKE_EXPECT(bake_gutter(mesh, &b.l, two, 2, uv, 1, atlas, &err), TT_ERROR_INVALID_ARGUMENT, 1, -2,
                "empty patches[1]");
    two[0] = NULL;
    two[1] = red;
    BAKE_EXPECT(bake_gutter(mesh, &b.l, two, 2, uv, 1, atlas, &err), TT_ERROR_INVALID_ARGUMENT, 0, -2,
                "NULL patches[0]");

    /* Bad pastes and entries: the paste or entry in item. */
    lb_begin(&b, 0);   /* paste 1: empty, then made bad */
    b.l.pastes[1].patch = 1;
    BAKE_EXPECT(bake_gutter(mesh, &b.l, &red, 1, uv, 1, atlas, &err), TT_ERROR_INDEX_OUT_OF_RANGE, 1, -2,
                "paste 1 uses patch 1 of 1");
    CHECK(msg_has_number(err.message, 1), "paste 1 named: %s", err.message);
    b.l.pastes[1].patch = 0;
    b.l.pastes[0].patch = -1;
    BAKE_EXPECT(bake_gutter(mesh, &b.l, &red, 1, uv, 1, atlas, &err), TT_ERROR_INDEX_OUT_OF_RANGE, 0, -2,
                "paste 0 uses patch -1");
    b.l.pastes[0].patch = 0;
    b.l.pastes[1].first = 1;
    b.l.pastes[1].nfaces = 2;   /* entries 1..2 of 2 */
    BAKE_EXPECT(bake_gutter(mesh, &b.l, &red, 1, uv, 1, atlas, &err), TT_ERROR_INDEX_OUT_OF_RANGE, 1, -2,
                "paste 1 runs past the entries");
    b.l.pastes[1].first = -1;
    b.l.pastes[1].nfaces = 1;
    BAKE_EXPECT(bake_gutter(mesh, &b.l, &red, 1, uv, 1, atlas, &err), TT_ERROR_INDEX_OUT_OF_RANGE, 1, -2,
                "paste 1 starts at entry -1");
    b.l.pastes[1].first = 2;
    b.l.pastes[1].nfaces = 0;
    CHECK(bake_gutter(mesh, &b.l, &red, 1, uv, 1, atlas, &err) == TT_OK, "an empty paste is fine: %s", err.message);
    b.l.pastes[0].nfaces = 3;
    BAKE_EXPECT(bake_gutter(mesh, &b.l, &red, 1, uv, 1, atlas, &err), TT_ERROR_INDEX_OUT_OF_RANGE, 0, -2,
                "paste 0 has 3 entries of 2");
    b.l.pastes[0].nfaces = 2;
    b.l.faces[1] = 2;
    BAKE_EXPECT(bake_gutter(mesh, &b.l, &red, 1, uv, 1, atlas, &err), TT_ERROR_INDEX_OUT_OF_RANGE, 1, -2,
                "entry 1 names face 2 of 2");
    CHECK(msg_has_number(err.message, 2), "face 2 in the message: %s", err.message);
    b.l.faces[1] = -7;
    BAKE_EXPECT(bake_gutter(mesh, &b.l, &red, 1, uv, 1, atlas, &err), TT_ERROR_INDEX_OUT_OF_RANGE, 1, -2,
                "entry 1 names face -7");
    b.l.faces[1] = 1;
    b.l.uv[3] = (float)internal_not_a_number();
    BAKE_EXPECT(bake_gutter(mesh, &b.l, &red, 1, uv, 1, atlas, &err), TT_ERROR_NON_FINITE, 0, 0,
                "NaN paste uv of entry 0");
    b.l.uv[3] = 0.0f;
    b.l.uv[6 + 5] = internal_infinity();
    BAKE_EXPECT(bake_gutter(mesh, &b.l, &red, 1, uv, 1, atlas, &err), TT_ERROR_NON_FINITE, 1, 1,
                "infinite paste uv of entry 1");
    b.l.uv[6 + 5] = 0.0f;
    {
        /* A NaN fade would be drawn as NaN alpha: refused, the entry named. */
        float fade[6] = {1, 1, 1, 1, 1, 1};
        b.l.fade = fade;
        fade[4] = (float)internal_not_a_number();
        BAKE_EXPECT(bake_gutter(mesh, &b.l, &red, 1, uv, 1, atlas, &err), TT_ERROR_NON_FINITE, 1, 1,
                    "NaN fade of entry 1");
        b.l.fade = NULL;
    }
    uv[7] = internal_infinity();
    BAKE_EXPECT(bake_gutter(mesh, &b.l, &red, 1, uv, 1, atlas, &err), TT_ERROR_NON_FINITE, -2, 1,
                "infinite atlas uv");
    CHECK(err.corner == 3, "infinite atlas uv, corner named: %d %s", err.corner, err.message);
    bake_square_uvs(mesh, 0.1, 0.9, uv);
    CHECK(bake_gutter(mesh, &b.l, &red, 1, uv, 1, atlas, &err) == TT_OK, "fixed: %s", err.message);
    b.l.nentries = -1;
    BAKE_EXPECT(bake_gutter(mesh, &b.l, &red, 1, uv, 1, atlas, &err), TT_ERROR_INVALID_ARGUMENT, -2, -2,
                "nentries -1");
    b.l.nentries = 2;
    lb_free(&b);

    qm = bake_quad();
    lb_init(&b);
    BAKE_EXPECT(bake_gutter(qm, &b.l, &red, 1, quv, 1, atlas, &err), TT_ERROR_INVALID_ARGUMENT, -2, 0,
                "quads refused, face 0 named");
    tt_mesh_free(qm);
    tt_image_free(atlas);
    tt_image_free(red);
    tt_mesh_free(mesh);
}

/* Progress and cancelling, options NULL (no gutter). */
typedef struct bake_progress {
    int calls, cancel_at, bad;
    float last;
} bake_progress;

static int bake_progress_fn(float fraction, void *user_data)
{
    bake_progress *p = (bake_progress *)user_data;
    if (!(fraction >= p->last) || !(fraction <= 1.0f)) p->bad++;
    p->last = fraction;
    return ++p->calls == p->cancel_at;
}

static void test_lapped_bake_progress(void)
{
    tt_mesh *mesh;
    float *uv;
    double m[4] = {0.25, 0, 0, 0.25}, zero[2] = {0, 0};
    tt_image *checker = bake_checker(32, 32, 4), *atlas = NULL, *reference = NULL;
    tt_bake_options opt;
    bake_progress prog;
    lb_builder b;
    tt_error err;
    tt_result r;
    size_t i, n;
    int nonzero, differ;
    lcg_seed(41);
    mesh = bake_grid(5, 4, 0.3, NULL);
    uv = (float *)malloc(sizeof(float) * 2 * (size_t)mesh->ncorners);
    CHECK(tt_atlas_pack_pairs(mesh, 128, 2, uv, &err) == TT_OK, "pack: %s", err.message);
    lb_init(&b);
    lb_paste_all(&b, mesh, 0, m, zero);
    tt_image_create(128, 128, NULL, &atlas, NULL);
    tt_image_create(128, 128, NULL, &reference, NULL);
    n = 4 * (size_t)128 * 128;

    /* options NULL is no gutter: the same atlas as gutter 0. */
    CHECK(tt_lapped_bake(mesh, &b.l, &checker, 1, uv, NULL, NULL, atlas, &err) == TT_OK && err.result == TT_OK,
          "options NULL: %s", err.message);
    CHECK(bake_gutter(mesh, &b.l, &checker, 1, uv, 0, reference, &err) == TT_OK, "gutter 0: %s", err.message);
    CHECK(memcmp(atlas->pixels, reference->pixels, n * sizeof(float)) == 0, "options NULL bakes as gutter 0");
    CHECK(bake_gutter(mesh, &b.l, &checker, 1, uv, 2, reference, &err) == TT_OK, "gutter 2: %s", err.message);
    differ = memcmp(atlas->pixels, reference->pixels, n * sizeof(float)) != 0;
    CHECK(differ, "a gutter of 2 changes the atlas (so the NULL-options check can fail)");

    /* Progress: between batches of rows and once at the end, fractions in
       [0, 1], never decreasing. */
    memset(&opt, 0, sizeof opt);
    memset(&prog, 0, sizeof prog);
    prog.cancel_at = -1;
    prog.last = 0.0f;
    opt.gutter = 2;
    opt.progress = bake_progress_fn;
    opt.progress_user_data = &prog;
    r = tt_lapped_bake(mesh, &b.l, &checker, 1, uv, &opt, NULL, atlas, &err);
    CHECK(r == TT_OK, "bake with progress: %d %s", (int)r, err.message);
    CHECK(prog.calls >= 2 && prog.bad == 0 && prog.last == 1.0f,
          "progress: %d calls (want at least one before the rows and one at the end), %d out of order, last %g "
          "(want 1)", prog.calls, prog.bad, prog.last);
    CHECK(memcmp(atlas->pixels, reference->pixels, n * sizeof(float)) == 0,
          "a progress callback that never cancels does not change the atlas");

    /* Cancel at every call of a bake tall enough for several batches of
       rows, the first (nothing baked) to the last (every row baked, the fill
       not yet run): TT_CANCELLED, no call after it, and an atlas of zeros,
       not half-written. */
    {
        tt_image *tall = NULL;
        size_t tall_n;
        int calls, at;
        tt_image_create(64, 1600, NULL, &tall, NULL);
        tall_n = 4 * (size_t)64 * 1600;
        memset(&prog, 0, sizeof prog);
        prog.cancel_at = -1;
        r = tt_lapped_bake(mesh, &b.l, &checker, 1, uv, &opt, NULL, tall, &err);
        calls = prog.calls;
        CHECK(r == TT_OK && calls >= 3 && prog.bad == 0 && prog.last == 1.0f,
              "a 64 x 1600 atlas: %d, %d progress calls (want at least 3: batches of rows), %d out of order", (int)r,
              calls, prog.bad);
        for (at = 1; at <= calls; at++) {
            memset(&prog, 0, sizeof prog);
            prog.cancel_at = at;
            for (i = 0; i < tall_n; i++) tall->pixels[i] = 0.25f;
            r = tt_lapped_bake(mesh, &b.l, &checker, 1, uv, &opt, NULL, tall, &err);
            nonzero = 0;
            for (i = 0; i < tall_n; i++) nonzero += tall->pixels[i] != 0.0f;
            CHECK(r == TT_CANCELLED && err.result == TT_CANCELLED && err.message[0] != '\0' &&
                      prog.calls == at && nonzero == 0,
                  "cancel at call %d of %d: %d (%s), %d calls, %d values not 0", at, calls, (int)r, err.message,
                  prog.calls, nonzero);
        }
        tt_image_free(tall);
    }
    /* And through a view of someone else's pixels. */
    {
        tt_image view;
        float *pixels = (float *)malloc(sizeof(float) * 4 * 40 * 30);
        memset(&view, 0, sizeof view);
        view.width = 40;
        view.height = 30;
        view.pixels = pixels;
        for (i = 0; i < 4 * 40 * 30; i++) pixels[i] = 0.5f;
        memset(&prog, 0, sizeof prog);
        prog.cancel_at = 2;
        r = tt_lapped_bake(mesh, &b.l, &checker, 1, uv, &opt, NULL, &view, &err);
        nonzero = 0;
        for (i = 0; i < 4 * 40 * 30; i++) nonzero += pixels[i] != 0.0f;
        CHECK(r == TT_CANCELLED && nonzero == 0, "cancel into a view: %d, %d values not 0", (int)r, nonzero);
        free(pixels);
    }
    free(uv);
    lb_free(&b);
    tt_image_free(atlas);
    tt_image_free(reference);
    tt_image_free(checker);
    tt_mesh_free(mesh);
}

typedef struct bake_oom_ctx {
    const tt_mesh *mesh;
    const tt_lapped *lapped;
    tt_image *patch;
    const float *uv;
    tt_image *atlas;
} bake_oom_ctx;

static tt_result bake_oom_call(void *ctx, const tt_allocator *al, tt_error *error)
{
    bake_oom_ctx *c = (bake_oom_ctx *)ctx;
    tt_bake_options opt;
    tt_result r;
    int i, n = 4 * c->atlas->width * c->atlas->height;
    memset(&opt, 0, sizeof opt);
    opt.gutter = 1;
    for (i = 0; i < n; i++) c->atlas->pixels[i] = 0.25f;
    r = tt_lapped_bake(c->mesh, c->lapped, &c->patch, 1, c->uv, &opt, al, c->atlas, error);
    if (error->result != r) return TT_RESULT_MAX_ENUM;
    if (r != TT_OK) {
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
    tt_image *red = bake_constant(4, 4, 1, 0, 0, 1), *atlas = NULL;
    lb_builder b;
    bake_oom_ctx c;
    tt_error err;
    lcg_seed(31);
    mesh = bake_grid(4, 4, 0.3, NULL);   /* the mesh's own allocator is not used */
    if (!mesh) return;
    oom_reset();
    CHECK(tt_atlas_pack_pairs(mesh, 64, 1, uv, &err) == TT_OK, "pack: %s", err.message);
    lb_init(&b);
    lb_paste_all(&b, mesh, 0, m, zero);
    tt_image_create(64, 64, NULL, &atlas, NULL);
    c.mesh = mesh;
    c.lapped = &b.l;
    c.patch = red;
    c.uv = uv;
    c.atlas = atlas;
    oom_sweep("tt_lapped_bake", bake_oom_call, &c, TT_OK);
    /* entries by face (2), items, state, fill queue, the bands' lists (3) and the patches' clear borders */
    CHECK(g_oom_counter.calls == 9, "tt_lapped_bake: 9 allocations, got %ld", g_oom_counter.calls);
    tt_mesh_free(mesh);
    CHECK(g_oom_counter.live == 0 && g_oom_counter.bad_frees == 0, "all freed (%ld live, %ld bad frees)",
          g_oom_counter.live, g_oom_counter.bad_frees);
    lb_free(&b);
    tt_image_free(atlas);
    tt_image_free(red);
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
    tt_image *red = bake_constant(4, 4, 1, 0, 0, 1), *atlas = NULL;
    lb_builder b;
    tt_error err;
    int i, bad = 0;
    lb_init(&b);
    lb_begin(&b, 0);
    lb_add(&b, 0, puv);
    lb_add(&b, 1, puv);
    tt_image_create(32, 32, NULL, &atlas, NULL);
    CHECK(bake_gutter(mesh, &b.l, &red, 1, uv, 4, atlas, &err) == TT_OK, "bake: %s", err.message);
    for (i = 0; i < 32 * 32 * 4; i++) bad += atlas->pixels[i] != 0.0f;
    CHECK(bad == 0, "face 2 without pastes covers the atlas: transparent (%d values off)", bad);
    lb_add(&b, 2, puv);
    CHECK(bake_gutter(mesh, &b.l, &red, 1, uv, 4, atlas, &err) == TT_OK, "bake: %s", err.message);
    bad = 0;
    for (i = 0; i < 32 * 32; i++) bad += atlas->pixels[4 * i] != 1.0f || atlas->pixels[4 * i + 3] != 1.0f;
    CHECK(bad == 0, "face 2 pasted red: all red (%d texels off)", bad);
    lb_free(&b);
    tt_image_free(atlas);
    tt_image_free(red);
    tt_mesh_free(mesh);
}

void run_lapped_tests(void)
{
    RUN(test_field_default);
    RUN(test_field_fallback);
    RUN(test_field_smooth);
    RUN(test_field_constraints);
    RUN(test_field_errors);
    RUN(test_field_constraint_items);
    RUN(test_field_extreme_coordinates);
    RUN(test_field_face_weights);
    RUN(test_field_oom);
    RUN(test_patch_splotch);
    RUN(test_patch_seeds);
    RUN(test_patch_masks);
    RUN(test_patch_errors);
    RUN(test_patch_oom);
    RUN(test_lapped_align_solve);
    RUN(test_lapped_plane);
    RUN(test_lapped_register);
    RUN(test_lapped_cut);
    RUN(test_lapped_ghosting);
    RUN(test_lapped_walls);
    RUN(test_lapped_cover);
    RUN(test_lapped_density);
    RUN(test_lapped_cuts);
    RUN(test_lapped_fade);
    RUN(test_lapped_determinism);
    RUN(test_lapped_patches);
    RUN(test_lapped_patch_twins);
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
    RUN(test_zero_face_mesh_refused);
    RUN(test_atlas_pack_charts);
    RUN(test_atlas_pack_charts_fill);
    RUN(test_atlas_pack_charts_uneven);
    RUN(test_atlas_pack_charts_overlap);
    RUN(test_atlas_pack_charts_small);
    RUN(test_atlas_pack_charts_coarse);
    RUN(test_atlas_pack_charts_noisy);
    RUN(test_atlas_pack_charts_errors);
    RUN(test_atlas_pack_charts_oom);
    RUN(test_uv_check);
    RUN(test_uv_check_errors);
    RUN(test_uv_check_oom);
    RUN(test_lapped_bake_constant);
    RUN(test_lapped_bake_normals);
    RUN(test_lapped_baked_seams);
    RUN(test_lapped_bake_gutter);
    RUN(test_lapped_bake_seams);
    RUN(test_lapped_bake_order);
    RUN(test_lapped_bake_many_small_pastes);
    RUN(test_lapped_bake_errors);
    RUN(test_lapped_bake_progress);
    RUN(test_lapped_bake_executor);
    RUN(test_lapped_bake_oom);
    RUN(test_lapped_bake_thin);
}
