/* tests/test_6_tiled.c - unit tests for section 6 of tiledtex.h: layout,
   boundary assignment, UVs, synthesis and the seam, histogram and stretch
   measures. Run by run_tiled_tests() (tests/test_common.c calls it). */
#include "test_common.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

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
    CHECK(tt_tile_layout_resolve(&in, NULL, &err) == TT_ERROR_INVALID_ARGUMENT, "NULL output rejected");

    /* Layouts whose figures would overflow an int are refused by resolve.
       (tt_tile_layout_tiles_per_side / atlas_size / tile_count give 0 for
       them but fail TT_ASSERT, which aborts this debug build, so they are
       called here only on layouts that resolve.) */
    {
        static const struct { int colors, size, gutter; tt_result expect; } bad[] = {
            {1000, 16, 2, TT_ERROR_INVALID_ARGUMENT},   {-5, 16, 2, TT_ERROR_INVALID_ARGUMENT},
            {2147483647, 16, 2, TT_ERROR_INVALID_ARGUMENT}, {-2147483647 - 1, 16, 2, TT_ERROR_INVALID_ARGUMENT},
            {1, 2147483647, 0, TT_ERROR_TOO_LARGE},     {1, -2147483647 - 1, 0, TT_ERROR_INVALID_ARGUMENT},
            {1, 16, 2147483647, TT_ERROR_INVALID_ARGUMENT}, {1, 16, -2147483647 - 1, TT_ERROR_INVALID_ARGUMENT},
            {TT_MAX_COLORS, 32768, 32768, TT_ERROR_TOO_LARGE}, {46, 4, 0, TT_ERROR_TOO_LARGE},
            {1, 32768, 1, TT_ERROR_TOO_LARGE},          {8, 128, 4, TT_ERROR_TOO_LARGE}};
        int i;
        for (i = 0; i < (int)(sizeof bad / sizeof bad[0]); i++) {
            tt_tile_layout o;
            memset(&o, 0x5a, sizeof o);
            in = make_layout(bad[i].colors, bad[i].size, bad[i].gutter);
            memset(&err, 0, sizeof err);
            r = tt_tile_layout_resolve(&in, &o, &err);
            CHECK(r == bad[i].expect && err.result == r && err.message[0] && o.colors == 0x5a5a5a5a,
                  "layout {%d, %d, %d}: expected %d with a message and the output untouched, got %d (%s)",
                  bad[i].colors, bad[i].size, bad[i].gutter, bad[i].expect, r, err.message);
        }
    }
    /* the largest layouts that resolve: n = 45 with 4-texel tiles (the bound
       in tt_tile_layout's comment), n = 7 with 128-texel tiles and gutter 4 */
    in = make_layout(45, 4, 0);
    r = tt_tile_layout_resolve(&in, &out, &err);
    CHECK(r == TT_OK && tt_tile_layout_tiles_per_side(&out) == 8100 && tt_tile_layout_atlas_size(&out) == 32400 &&
              tt_tile_layout_tile_count(&out) == 8100 * 8100,
          "n=45, S=4: %d, T %d, W %d, count %d", r, r == TT_OK ? tt_tile_layout_tiles_per_side(&out) : -1,
          r == TT_OK ? tt_tile_layout_atlas_size(&out) : -1, r == TT_OK ? tt_tile_layout_tile_count(&out) : -1);
    in = make_layout(7, 128, 4);
    r = tt_tile_layout_resolve(&in, &out, &err);
    CHECK(r == TT_OK && tt_tile_layout_atlas_size(&out) == 196 * 136,
          "n=7, S=128, g=4: %d, W %d (want %d)", r, r == TT_OK ? tt_tile_layout_atlas_size(&out) : -1, 196 * 136);
    /* the figures accept an unresolved layout (zeros mean defaults) */
    in = make_layout(0, 0, 3);
    CHECK(tt_tile_layout_tiles_per_side(&in) == 4 && tt_tile_layout_atlas_size(&in) == 4 * 134 &&
              tt_tile_layout_tile_count(&in) == 16,
          "layout {0, 0, 3}: T %d, W %d, count %d (want 4, 536, 16)", tt_tile_layout_tiles_per_side(&in),
          tt_tile_layout_atlas_size(&in), tt_tile_layout_tile_count(&in));
}

static void check_boundaries(const tt_mesh *mesh, int n, const char *name)
{
    uint8_t *a = (uint8_t *)malloc((size_t)mesh->ncorners), *b = (uint8_t *)malloc((size_t)mesh->ncorners);
    tt_tile_layout l = make_layout(n, 32, 4);
    int c, bad_pair = 0, bad_range = 0, differ = 0, *used = (int *)calloc((size_t)2 * n, sizeof(int));
    tt_result r;
    tt_error err;
    memset(a, 0xee, (size_t)mesh->ncorners);
    r = tt_assign_boundaries(mesh, &l, 1234, NULL, a, &err);
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
    tt_assign_boundaries(mesh, &l, 1234, NULL, b, NULL);
    CHECK(memcmp(a, b, (size_t)mesh->ncorners) == 0, "%s n=%d: same seed should give the same types", name, n);
    tt_assign_boundaries(mesh, &l, 1235, NULL, b, NULL);
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
        tt_result r;
        CHECK(tt_assign_boundaries(tet, &l, 1, NULL, types, &err) == TT_OK, "colors 0 (= 1) accepted");
        /* the layout is no longer optional (THE API CONTRACT: NULL is bad input) */
        r = tt_assign_boundaries(tet, NULL, 1, NULL, types, &err);
        CHECK(r == TT_ERROR_INVALID_ARGUMENT && err.result == r && err.message[0],
              "layout NULL: expected TT_ERROR_INVALID_ARGUMENT with a message, got %d", r);
        l.colors = -1;
        CHECK(tt_assign_boundaries(tet, &l, 1, NULL, types, &err) == TT_ERROR_INVALID_ARGUMENT && err.message[0],
              "colors -1 rejected");
        l.colors = TT_MAX_COLORS + 1;
        CHECK(tt_assign_boundaries(tet, &l, 1, NULL, types, &err) == TT_ERROR_INVALID_ARGUMENT,
              "colors TT_MAX_COLORS+1 rejected");
        l.colors = TT_MAX_COLORS;
        CHECK(tt_assign_boundaries(tet, &l, 1, NULL, types, &err) == TT_OK,
              "colors TT_MAX_COLORS accepted by assign_boundaries");
        CHECK(tt_assign_boundaries(NULL, &l, 1, NULL, types, &err) == TT_ERROR_INVALID_ARGUMENT, "mesh NULL rejected");
        CHECK(tt_assign_boundaries(tet, &l, 1, NULL, NULL, &err) == TT_ERROR_INVALID_ARGUMENT, "types NULL rejected");
        CHECK(tt_assign_boundaries(tet, &l, 1, NULL, types, NULL) == TT_OK, "error NULL is fine");
    }

    /* assign_uvs: not quads */
    {
        uint8_t types[64];
        float uv[128];
        tt_tile_layout l = make_layout(1, 32, 4);
        tt_result r;
        tt_assign_boundaries(tet, &l, 1, NULL, types, NULL);
        r = tt_assign_uvs(tet, &l, types, uv, &err);
        CHECK(r == TT_ERROR_NOT_QUAD_MESH && err.face == 0 && msg_has_number(err.message, 0),
              "tetrahedron: expected TT_ERROR_NOT_QUAD_MESH naming face 0, got %d face %d \"%s\"", r, err.face,
              err.message);
        tt_assign_boundaries(mixed, &l, 1, NULL, types, NULL);
        r = tt_assign_uvs(mixed, &l, types, uv, &err);
        CHECK(r == TT_ERROR_NOT_QUAD_MESH && err.face == 6 && err.corner == 24 && msg_has_number(err.message, 6),
              "grid + triangle: expected TT_ERROR_NOT_QUAD_MESH naming face 6 (corner 24), got %d face %d corner %d \"%s\"",
              r, err.face, err.corner, err.message);
        {
            int counts[16];
            memset(&err, 0, sizeof err);
            r = tt_tile_histogram(mixed, &l, types, counts, &err);
            CHECK(r == TT_ERROR_NOT_QUAD_MESH && err.result == r && err.face == 6 && err.corner == 24 &&
                      msg_has_number(err.message, 6),
                  "tile histogram on a mesh with a triangle: expected TT_ERROR_NOT_QUAD_MESH naming face 6 "
                  "(corner 24), got %d face %d corner %d \"%s\"", r, err.face, err.corner, err.message);
            r = tt_tile_histogram(tet, &l, types, counts, &err);
            CHECK(r == TT_ERROR_NOT_QUAD_MESH && err.face == 0 && err.corner == 0,
                  "tile histogram on a tetrahedron: expected TT_ERROR_NOT_QUAD_MESH naming face 0, got %d face %d",
                  r, err.face);
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
            tt_assign_boundaries(torus, &l, 77 + (uint64_t)n, NULL, types, NULL);
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
            CHECK(r == TT_ERROR_INDEX_OUT_OF_RANGE && err.result == r && err.corner == 13 && err.face == 3 &&
                      msg_has_number(err.message, 13),
                  "type %d at corner 13 (n=%d): expected TT_ERROR_INDEX_OUT_OF_RANGE at corner 13 face 3, got %d "
                  "%d %d \"%s\"", 2 * n, n, r, err.corner, err.face, err.message);
            types[13] = 255;
            r = tt_assign_uvs(torus, &l, types, uv, &err);
            CHECK(r == TT_ERROR_INDEX_OUT_OF_RANGE && err.corner == 13,
                  "type 255 at corner 13 (n=%d): expected TT_ERROR_INDEX_OUT_OF_RANGE at corner 13, got %d %d", n, r,
                  err.corner);
            free(types);
            free(uv);
        }
    }
    tt_mesh_free(torus);
    tt_mesh_free(grid);
    tt_mesh_free(tet);
    tt_mesh_free(mixed);
}

/* Prescribed edge colours on one mesh: kept where given (the twin's type is
   the complement), drawn where -1, all -1 equals NULL, deterministic. */
static void check_prescribed(const tt_mesh *mesh, int n, const char *name)
{
    size_t nc = (size_t)mesh->ncorners;
    uint8_t *a = (uint8_t *)malloc(nc), *b = (uint8_t *)malloc(nc);
    int *colors = (int *)malloc(sizeof(int) * nc), *drawn = (int *)calloc((size_t)n, sizeof(int));
    tt_tile_layout l = make_layout(n, 16, 2);
    int c, bad_kept = 0, bad_pair = 0, bad_range = 0, nprescribed = 0, nrandom = 0, sides[2] = {0, 0}, unused = 0, k;
    tt_error err;
    tt_result r;
    lcg_seed(1000 + (unsigned)n);
    /* per edge: -1 (random) about half the time, otherwise a colour */
    for (c = 0; c < mesh->ncorners; c++) {
        int t = mesh->twin[c];
        if (t >= 0 && t < c) { colors[c] = colors[t]; continue; }
        colors[c] = lcg_below(2) ? -1 : lcg_below(n);
    }
    memset(a, 0xee, nc);
    r = tt_assign_boundaries(mesh, &l, 31, colors, a, &err);
    CHECK(r == TT_OK, "%s n=%d: prescribed colours: %d (%s)", name, n, r, err.message);
    for (c = 0; c < mesh->ncorners; c++) {
        int t = mesh->twin[c];
        if (a[c] >= 2 * n) { bad_range++; continue; }
        if (t >= 0 && a[t] != (a[c] ^ 1)) bad_pair++;
        if (t >= 0 && t < c) continue;   /* one count per edge */
        if (colors[c] >= 0) {
            nprescribed++;
            sides[a[c] & 1]++;
            if (a[c] >> 1 != colors[c]) {
                if (!bad_kept) DETAIL("%s n=%d: corner %d prescribes %d, got type %d", name, n, c, colors[c], a[c]);
                bad_kept++;
            }
        } else {
            nrandom++;
            drawn[a[c] >> 1]++;
        }
    }
    CHECK(bad_range == 0, "%s n=%d prescribed: %d types outside 0..2n-1", name, n, bad_range);
    CHECK(bad_pair == 0, "%s n=%d prescribed: %d twin pairs whose types are not 2k+i and 2k+1-i", name, n, bad_pair);
    CHECK(bad_kept == 0 && nprescribed > 0, "%s n=%d: %d of %d prescribed colours not kept", name, n, bad_kept,
          nprescribed);
    /* sides come from the RNG on prescribed edges too */
    if (nprescribed >= 40)
        CHECK(sides[0] > nprescribed / 5 && sides[1] > nprescribed / 5,
              "%s n=%d: prescribed edges got side 0 %d times and side 1 %d times", name, n, sides[0], sides[1]);
    /* -1 entries are drawn at random: every colour shows up */
    if (nrandom >= 30 * n) {
        for (k = 0; k < n; k++) unused += drawn[k] == 0;
        CHECK(unused == 0, "%s n=%d: %d of %d colours never drawn on %d random edges", name, n, unused, n, nrandom);
    }
    /* determinism */
    memset(b, 0xee, nc);
    tt_assign_boundaries(mesh, &l, 31, colors, b, NULL);
    CHECK(memcmp(a, b, nc) == 0, "%s n=%d: same seed and colours should give the same types", name, n);
    /* all -1 is NULL */
    for (c = 0; c < mesh->ncorners; c++) colors[c] = -1;
    r = tt_assign_boundaries(mesh, &l, 31, colors, a, &err);
    tt_assign_boundaries(mesh, &l, 31, NULL, b, NULL);
    CHECK(r == TT_OK && memcmp(a, b, nc) == 0, "%s n=%d: all -1 should equal edge_colors NULL (result %d)", name, n,
          r);
    /* all prescribed: every type's k is the prescription */
    for (c = 0; c < mesh->ncorners; c++) {
        int t = mesh->twin[c];
        colors[c] = t >= 0 && t < c ? colors[t] : (c * 7 + 3) % n;
    }
    r = tt_assign_boundaries(mesh, &l, 32, colors, a, &err);
    bad_kept = 0;
    for (c = 0; c < mesh->ncorners; c++) bad_kept += a[c] >> 1 != colors[c];
    CHECK(r == TT_OK && bad_kept == 0, "%s n=%d, every edge prescribed: %d, %d corners not kept", name, n, r,
          bad_kept);
    free(a);
    free(b);
    free(colors);
    free(drawn);
}

static void test_prescribed_colors(void)
{
    tmesh m;
    tt_mesh *torus = NULL, *grid = NULL;
    tt_error err;
    int n;
    memset(&m, 0, sizeof m);
    make_torus(&m, 24, 16, 3, 1);
    CHECK(build(&m, 0, &torus, &err) == TT_OK, "torus build");
    tm_free(&m);
    make_grid(&m, 6, 5);
    CHECK(build(&m, 0, &grid, &err) == TT_OK, "grid build");
    tm_free(&m);
    if (!torus || !grid) { tt_mesh_free(torus); tt_mesh_free(grid); return; }
    for (n = 1; n <= 4; n++) {
        check_prescribed(torus, n, "torus");
        check_prescribed(grid, n, "open grid");
    }
    {
        /* bad prescriptions on the open grid: on its first boundary
           half-edge and on the first interior edge past face 0 */
        int nc = grid->ncorners, c, t = -1, boundary = -1, interior = -1;
        int *colors = (int *)malloc(sizeof(int) * (size_t)nc);
        uint8_t *types = (uint8_t *)malloc((size_t)nc);
        tt_tile_layout l = make_layout(3, 16, 2);
        tt_result r;
        for (c = 0; c < nc && (boundary < 0 || interior < 0); c++) {
            if (grid->twin[c] < 0 && boundary < 0) boundary = c;
            if (grid->twin[c] > c && interior < 0 && c > 4) interior = c;
        }
        t = grid->twin[interior];
        for (c = 0; c < nc; c++) colors[c] = -1;
        /* twins that disagree */
        colors[interior] = 1;
        colors[t] = 2;
        memset(&err, 0, sizeof err);
        r = tt_assign_boundaries(grid, &l, 1, colors, types, &err);
        CHECK(r == TT_ERROR_INVALID_ARGUMENT && err.result == r && (err.corner == interior || err.corner == t) &&
                  err.corner >= 0 && err.face == grid->corner_face[err.corner] &&
                  msg_has_number(err.message, err.corner),
              "twins %d and %d prescribing 1 and 2: expected TT_ERROR_INVALID_ARGUMENT naming one of them and its "
              "face, got %d corner %d face %d \"%s\"", interior, t, r, err.corner, err.face, err.message);
        /* one side given, the other -1: they disagree too */
        colors[t] = -1;
        r = tt_assign_boundaries(grid, &l, 1, colors, types, &err);
        CHECK(r == TT_ERROR_INVALID_ARGUMENT && (err.corner == interior || err.corner == t),
              "twins prescribing 1 and -1: expected TT_ERROR_INVALID_ARGUMENT naming one of them, got %d corner %d",
              r, err.corner);
        colors[t] = 1;
        r = tt_assign_boundaries(grid, &l, 1, colors, types, &err);
        CHECK(r == TT_OK && types[interior] >> 1 == 1 && types[t] >> 1 == 1,
              "twins agreeing on 1: %d, types %d %d", r, types[interior], types[t]);
        /* colours outside -1..n-1 */
        colors[boundary] = 3;
        memset(&err, 0, sizeof err);
        r = tt_assign_boundaries(grid, &l, 1, colors, types, &err);
        CHECK(r == TT_ERROR_INDEX_OUT_OF_RANGE && err.result == r && err.corner == boundary &&
                  err.face == grid->corner_face[boundary] && msg_has_number(err.message, boundary),
              "colour 3 of 3 at boundary corner %d: expected TT_ERROR_INDEX_OUT_OF_RANGE naming it, got %d corner %d "
              "face %d \"%s\"", boundary, r, err.corner, err.face, err.message);
        colors[boundary] = -2;
        r = tt_assign_boundaries(grid, &l, 1, colors, types, &err);
        CHECK(r == TT_ERROR_INDEX_OUT_OF_RANGE && err.corner == boundary,
              "colour -2 at corner %d: expected TT_ERROR_INDEX_OUT_OF_RANGE, got %d corner %d", boundary, r,
              err.corner);
        colors[boundary] = -1;
        colors[interior] = colors[t] = 1000;
        r = tt_assign_boundaries(grid, &l, 1, colors, types, &err);
        CHECK(r == TT_ERROR_INDEX_OUT_OF_RANGE && (err.corner == interior || err.corner == t),
              "colour 1000 on both sides of edge %d/%d: expected TT_ERROR_INDEX_OUT_OF_RANGE, got %d corner %d",
              interior, t, r, err.corner);
        colors[interior] = colors[t] = 2;
        CHECK(tt_assign_boundaries(grid, &l, 1, colors, types, &err) == TT_OK, "colour n-1 = 2 accepted");
        free(colors);
        free(types);
    }
    tt_mesh_free(torus);
    tt_mesh_free(grid);
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
                                          TT_ERROR_NOT_POSITIVE_DEFINITE, TT_ERROR_NOT_MEASURED};
        int a, b, bad = 0, ncodes = (int)(sizeof codes / sizeof codes[0]);
        const char *unknown = tt_result_string((tt_result)-99);
        for (a = 0; a < ncodes; a++) {
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

/* Distinct (group, tile) pairs the faces show, counted naively. */
static int count_tiles(const tt_mesh *mesh, const tt_tile_layout *layout, const uint8_t *types, const uint8_t *group)
{
    int f, g, distinct = 0;
    for (f = 0; f < mesh->nfaces; f++) {
        int index = tt_tile_index(layout, types + mesh->face_start[f]), seen = 0;
        for (g = 0; g < f && !seen; g++)
            seen = tt_tile_index(layout, types + mesh->face_start[g]) == index && (!group || group[g] == group[f]);
        distinct += !seen;
    }
    return distinct;
}

/* Twins are the two halves of one condition, types below 2n, prescribed colours kept. */
static int reduced_types_valid(const tt_mesh *mesh, int n, const uint8_t *types, const int *colors)
{
    int c, bad = 0;
    for (c = 0; c < mesh->ncorners; c++) {
        if (types[c] >= 2 * n) bad++;
        if (mesh->twin[c] >= 0 && types[mesh->twin[c]] != (types[c] ^ 1)) bad++;
        if (colors && colors[c] >= 0 && types[c] / 2 != colors[c]) bad++;
    }
    return bad;
}

typedef struct reduce_ctx {
    const tt_mesh *mesh;
    const uint8_t *types;
    uint8_t *work;
} reduce_ctx;

static tt_result oom_reduce(void *ctx, const tt_allocator *al, tt_error *error)
{
    reduce_ctx *r = (reduce_ctx *)ctx;
    tt_tile_layout layout = make_layout(2, 8, 0);
    tt_result result;
    memcpy(r->work, r->types, (size_t)r->mesh->ncorners);
    result = tt_reduce_tiles(r->mesh, &layout, 1, NULL, NULL, 40, al, r->work, NULL, error);
    if (result != TT_OK && memcmp(r->work, r->types, (size_t)r->mesh->ncorners) != 0) return TT_RESULT_MAX_ENUM;
    return result;
}

static void test_reduce_tiles(void)
{
    tmesh m;
    tt_mesh *torus = NULL, *mixed = NULL;
    tt_tile_layout layout = make_layout(2, 8, 0);
    tt_error err;
    uint8_t *types = NULL, *work = NULL, *again = NULL, *group = NULL;
    int *colors = NULL, before, after = -1, f, c;
    memset(&m, 0, sizeof m);
    make_torus(&m, 32, 24, 3, 1);
    CHECK(build(&m, 0, &torus, &err) == TT_OK, "torus build");
    tm_free(&m);
    make_grid(&m, 3, 2);
    tm_tri(&m, 1, 0, tm_vert(&m, 0.5, -1, 0));
    CHECK(build(&m, 0, &mixed, &err) == TT_OK, "grid+triangle build");
    tm_free(&m);
    if (!torus || !mixed) goto done;
    types = (uint8_t *)malloc((size_t)torus->ncorners);
    work = (uint8_t *)malloc((size_t)torus->ncorners);
    again = (uint8_t *)malloc((size_t)torus->ncorners);
    group = (uint8_t *)malloc((size_t)torus->nfaces);
    colors = (int *)malloc(sizeof(int) * (size_t)torus->ncorners);
    if (!types || !work || !again || !group || !colors) goto done;
    CHECK(tt_assign_boundaries(torus, &layout, 11, NULL, types, &err) == TT_OK, "boundaries: %s", err.message);
    before = count_tiles(torus, &layout, types, NULL);

    /* Already within the limit: nothing changes. */
    memcpy(work, types, (size_t)torus->ncorners);
    CHECK(tt_reduce_tiles(torus, &layout, 1, NULL, NULL, before, NULL, work, &after, &err) == TT_OK &&
              after == before && memcmp(work, types, (size_t)torus->ncorners) == 0,
          "max_tiles = the %d shown: unchanged (reports %d)", before, after);
    /* To a fifth of the tiles random types show (the control: `before`). */
    memcpy(work, types, (size_t)torus->ncorners);
    CHECK(tt_reduce_tiles(torus, &layout, 1, NULL, NULL, before / 5, NULL, work, &after, &err) == TT_OK,
          "reduce: %s", err.message);
    {
        const int counted = count_tiles(torus, &layout, work, NULL), invalid = reduced_types_valid(torus, 2, work, NULL);
        CHECK(after <= before / 5 && after == counted && invalid == 0,
              "768 quads from %d tiles to at most %d: %d (counted %d), %d invalid types", before, before / 5,
              after, counted, invalid);
    }
    /* Same seed, same result; another seed, another. */
    memcpy(again, types, (size_t)torus->ncorners);
    tt_reduce_tiles(torus, &layout, 1, NULL, NULL, before / 5, NULL, again, NULL, NULL);
    CHECK(memcmp(again, work, (size_t)torus->ncorners) == 0, "tt_reduce_tiles: same seed, same types");
    memcpy(again, types, (size_t)torus->ncorners);
    tt_reduce_tiles(torus, &layout, 2, NULL, NULL, before / 5, NULL, again, NULL, NULL);
    CHECK(memcmp(again, work, (size_t)torus->ncorners) != 0, "tt_reduce_tiles: another seed, other types");

    /* Prescribed colours stay; groups count apart. */
    lcg_seed(5);
    for (c = 0; c < torus->ncorners; c++)
        if (torus->twin[c] < 0 || c < torus->twin[c]) {
            colors[c] = lcg_below(3) - 1;   /* -1: free */
            if (torus->twin[c] >= 0) colors[torus->twin[c]] = colors[c];
        }
    for (f = 0; f < torus->nfaces; f++) group[f] = (uint8_t)(f % 3 == 0);
    CHECK(tt_assign_boundaries(torus, &layout, 12, colors, types, &err) == TT_OK, "boundaries: %s", err.message);
    before = count_tiles(torus, &layout, types, group);
    CHECK(tt_reduce_tiles(torus, &layout, 3, colors, group, before / 3, NULL, types, &after, &err) == TT_OK,
          "reduce with colours and groups: %s", err.message);
    {
        const int counted = count_tiles(torus, &layout, types, group);
        const int invalid = reduced_types_valid(torus, 2, types, colors);
        CHECK(after <= before / 3 && after == counted && invalid == 0,
              "with colours and groups: %d to at most %d: %d (counted %d), %d invalid", before, before / 3, after,
              counted, invalid);
    }

    /* Bad input: a specific result, the types as they were. */
    memcpy(work, types, (size_t)torus->ncorners);
    CHECK(tt_reduce_tiles(torus, &layout, 1, NULL, NULL, 0, NULL, work, NULL, &err) == TT_ERROR_INVALID_ARGUMENT,
          "max_tiles 0: %s", err.message);
    work[7] ^= 1;   /* its twin no longer the other half */
    CHECK(tt_reduce_tiles(torus, &layout, 1, NULL, NULL, 10, NULL, work, NULL, &err) == TT_ERROR_INVALID_ARGUMENT &&
              (err.corner == 7 || err.corner == torus->twin[7]) && work[7] == (types[7] ^ 1),
          "twins that disagree: %s (corner %d)", err.message, err.corner);
    work[7] ^= 1;
    for (c = 0; c < torus->ncorners && colors[c] < 0; c++) continue;
    if (c < torus->ncorners) {
        colors[c] = 1 - colors[c];
        if (torus->twin[c] >= 0) colors[torus->twin[c]] = colors[c];
        CHECK(tt_reduce_tiles(torus, &layout, 1, colors, NULL, 10, NULL, work, NULL, &err) ==
                  TT_ERROR_INVALID_ARGUMENT && memcmp(work, types, (size_t)torus->ncorners) == 0,
              "a type against its prescribed colour: %s", err.message);
    }
    CHECK(tt_reduce_tiles(mixed, &layout, 1, NULL, NULL, 10, NULL, work, NULL, &err) == TT_ERROR_NOT_QUAD_MESH &&
              err.face == 6,
          "a triangle: %s (face %d)", err.message, err.face);
    {
        reduce_ctx ctx;
        tt_assign_boundaries(torus, &layout, 11, NULL, types, NULL);
        ctx.mesh = torus;
        ctx.types = types;
        ctx.work = work;
        oom_reset();
        oom_sweep("tt_reduce_tiles", oom_reduce, &ctx, TT_OK);
    }
done:
    free(types);
    free(work);
    free(again);
    free(group);
    free(colors);
    tt_mesh_free(torus);
    tt_mesh_free(mixed);
}

/* ------------------------------------------------------------------------ */
/* 6b. Tile-set synthesis                                                   */
/* ------------------------------------------------------------------------ */

/* Random-noise RGB source, opaque, linear values uniform in [0, 1); free
   with tt_image_free. */
static tt_image *make_noise(int w, int h, unsigned seed)
{
    tt_image *im = NULL;
    int i;
    if (tt_image_create(w, h, NULL, &im, NULL) != TT_OK) return NULL;
    lcg_seed(seed);
    for (i = 0; i < w * h; i++) {
        im->pixels[4 * i] = (float)lcg_unit();
        im->pixels[4 * i + 1] = (float)lcg_unit();
        im->pixels[4 * i + 2] = (float)lcg_unit();
        im->pixels[4 * i + 3] = 1.0f;
    }
    return im;
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
    tt_image *src = make_noise(96, 192, 42);
    int n, gi;
    CHECK(src != NULL, "make_noise");
    if (!src) return;
    for (n = 1; n <= 2; n++)
        for (gi = 0; gi < 2; gi++) {
            tt_synth_options opt;
            tt_tileset *set = NULL, *again = NULL, *other = NULL;
            tt_error err;
            tt_result r;
            counter cnt;
            tt_allocator al = make_allocator(&cnt, -1);
            char name[64];
            memset(&opt, 0, sizeof opt);
            opt.layout = make_layout(n, 32, gi ? 4 : TT_NO_GUTTER);
            opt.seed = 7;
            sprintf(name, "noise n=%d gutter %d", n, gi ? 4 : 0);
            r = tt_synthesize_tiles(src, &opt, &al, &set, &err);
            CHECK(r == TT_OK, "%s: synthesize returned %d (%s)", name, r, err.message);
            if (r != TT_OK) continue;
            CHECK(set->allocator.alloc == al.alloc && set->allocator.user_data == &cnt,
                  "%s: the tileset should remember its allocator", name);
            check_tileset(set, src, 2, name);
            r = tt_synthesize_tiles(src, &opt, &al, &again, &err);
            CHECK(r == TT_OK && again->levels[0].width == set->levels[0].width &&
                      memcmp(again->levels[0].pixels, set->levels[0].pixels,
                             sizeof(float) * 4 * (size_t)set->levels[0].width * set->levels[0].height) == 0,
                  "%s: same seed should give a byte-identical atlas", name);
            opt.seed = 8;
            r = tt_synthesize_tiles(src, &opt, &al, &other, &err);
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
        r = tt_synthesize_tiles(src, &opt, NULL, &set, &err);
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
            check_tileset(set, src, 4, "given windows, feather 4, n=2, S=24, g=3");
            tt_tileset_free(set);
        }
        memset(&opt, 0, sizeof opt);
        opt.layout = make_layout(1, 64, 8);
        r = tt_synthesize_tiles(src, &opt, NULL, &set, &err);
        CHECK(r == TT_OK, "S=64: %d (%s)", r, err.message);
        if (r == TT_OK) {
            check_tileset(set, src, 4, "n=1, S=64, g=8");
            tt_tileset_free(set);
        }
    }
    tt_image_free(src);
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
    tt_tileset *set = (tt_tileset *)&set;
    tt_error err;
    counter cnt;
    tt_allocator al = make_allocator(&cnt, -1);
    tt_result r;
    err.message[0] = '\0';
    r = tt_synthesize_tiles(src, opt, &al, &set, &err);
    CHECK(r == code && set == NULL && err.result == code && err.message[0] != '\0',
          "%s: expected %d with *out NULL and a message, got %d (%s)", what, code, r, err.message);
    if (r == TT_OK && set) tt_tileset_free(set);
    CHECK(cnt.live == 0, "%s: %ld allocations leaked", what, cnt.live);
}

static void test_synth_errors(void)
{
    tt_image *src = make_noise(64, 128, 5), *small;
    tt_synth_options opt;
    tt_tileset *set = NULL;
    tt_error err;
    tt_result r;
    tt_rect win;
    CHECK(src != NULL, "make_noise");
    if (!src) return;
    memset(&opt, 0, sizeof opt);
    opt.layout = make_layout(1, 16, 2);

    r = tt_synthesize_tiles(src, &opt, NULL, NULL, &err);
    CHECK(r == TT_ERROR_INVALID_ARGUMENT, "out NULL: got %d", r);
    expect_synth_error(NULL, &opt, TT_ERROR_INVALID_ARGUMENT, "source NULL");
    {
        tt_image empty;
        memset(&empty, 0, sizeof empty);
        expect_synth_error(&empty, &opt, TT_ERROR_INVALID_ARGUMENT, "empty source");
    }
    {
        /* an allocator with only one of its two functions */
        counter cnt;
        tt_allocator half = make_allocator(&cnt, -1);
        half.free = NULL;
        set = (tt_tileset *)&set;
        r = tt_synthesize_tiles(src, &opt, &half, &set, &err);
        if (r == TT_OK) tt_tileset_free(set);
        CHECK(r == TT_ERROR_INVALID_ARGUMENT && set == NULL && cnt.calls == 0,
              "allocator without free: expected TT_ERROR_INVALID_ARGUMENT before any allocation, got %d (%ld calls)",
              r, cnt.calls);
    }
    opt.layout.colors = -1;
    expect_synth_error(src, &opt, TT_ERROR_INVALID_ARGUMENT, "colors -1");
    opt.layout.colors = TT_MAX_COLORS + 1;
    expect_synth_error(src, &opt, TT_ERROR_INVALID_ARGUMENT, "colors TT_MAX_COLORS+1");
    opt.layout.colors = 0;
    {
        counter cnt;
        tt_allocator al = make_allocator(&cnt, -1);
        r = tt_synthesize_tiles(src, &opt, &al, &set, &err);
        CHECK(r == TT_OK && set->layout.colors == 1 && set->layout.tile_size == 16 && set->layout.gutter == 2,
              "colors 0 means 1: got %d, colors %d", r, r == TT_OK ? set->layout.colors : -1);
        if (r == TT_OK) tt_tileset_free(set);
        CHECK(cnt.live == 0, "colors 0: leak");
    }
    opt.layout.colors = 1;
    opt.layout.tile_size = 3;
    {
        counter cnt;
        tt_allocator al = make_allocator(&cnt, -1);
        set = (tt_tileset *)&set;
        r = tt_synthesize_tiles(src, &opt, &al, &set, &err);
        if (r == TT_OK) tt_tileset_free(set);
        CHECK((r == TT_ERROR_INVALID_ARGUMENT || r == TT_ERROR_TOO_LARGE) && set == NULL && cnt.live == 0,
              "tile size 3 rejected, got %d", r);
    }
    opt.layout.tile_size = 40000;
    expect_synth_error(src, &opt, TT_ERROR_TOO_LARGE, "tile size 40000");
    opt.layout = make_layout(2, 2048, 4);
    expect_synth_error(src, &opt, TT_ERROR_TOO_LARGE, "n=2, S=2048: atlas over TT_MAX_IMAGE_SIZE");
    opt.layout = make_layout(1, 65, 2);
    expect_synth_error(src, &opt, TT_ERROR_IMAGE_TOO_SMALL, "S=65 on a 64x128 image (too narrow)");
    small = make_noise(64, 95, 1);
    opt.layout = make_layout(1, 48, 2);
    expect_synth_error(small, &opt, TT_ERROR_IMAGE_TOO_SMALL, "S=48 on a 64x95 image: fits S x S but not S x 2S");
    tt_image_free(small);
    small = make_noise(16, 31, 1);
    opt.layout = make_layout(1, 16, 2);
    expect_synth_error(small, &opt, TT_ERROR_IMAGE_TOO_SMALL, "16x31 image for S=16");
    tt_image_free(small);
    small = make_noise(16, 32, 1);
    {
        counter cnt;
        tt_allocator al = make_allocator(&cnt, -1);
        r = tt_synthesize_tiles(small, &opt, &al, &set, &err);
        CHECK(r == TT_OK, "16x32 image for S=16 (exactly S x 2S) should work, got %d (%s)", r, err.message);
        if (r == TT_OK) tt_tileset_free(set);
        CHECK(cnt.live == 0, "16x32: leak");
    }
    tt_image_free(small);

    /* edge windows outside the image */
    opt.layout = make_layout(1, 16, 2);
    opt.edge_windows = &win;
    win.w = win.h = 0;
    win.x = 64 - 16 + 1; win.y = 0;
    expect_synth_error(src, &opt, TT_ERROR_INVALID_ARGUMENT, "edge window one texel too far right");
    win.x = 0; win.y = 128 - 32 + 1;
    expect_synth_error(src, &opt, TT_ERROR_INVALID_ARGUMENT, "edge window one texel too low");
    win.x = -1; win.y = 0;
    expect_synth_error(src, &opt, TT_ERROR_INVALID_ARGUMENT, "edge window at x = -1");
    win.x = 64 - 16; win.y = 128 - 32;
    {
        counter cnt;
        tt_allocator al = make_allocator(&cnt, -1);
        r = tt_synthesize_tiles(src, &opt, &al, &set, &err);
        CHECK(r == TT_OK, "edge window at the bottom-right limit should fit, got %d (%s)", r, err.message);
        if (r == TT_OK) tt_tileset_free(set);
        CHECK(cnt.live == 0, "edge window at the limit: leak");
    }
    opt.edge_windows = NULL;
    /* background region */
    opt.background.x = 60; opt.background.y = 0; opt.background.w = 16; opt.background.h = 16;
    expect_synth_error(src, &opt, TT_ERROR_INVALID_ARGUMENT, "background region outside the image");
    opt.background.x = 0; opt.background.w = 15;
    expect_synth_error(src, &opt, TT_ERROR_IMAGE_TOO_SMALL, "background region narrower than a tile");
    memset(&opt.background, 0, sizeof opt.background);
    /* feather too wide */
    opt.feather = 16 / 4 + 2;
    expect_synth_error(src, &opt, TT_ERROR_INVALID_ARGUMENT, "feather wider than S/4+1");
    opt.feather = 0;

    /* progress: monotone in (0,1], ends at 1; cancelling cleans up */
    {
        counter cnt;
        tt_allocator al = make_allocator(&cnt, -1);
        tt_synth_options o = opt;
        o.progress = never_cancel;
        g_progress_calls = 0;
        g_progress_last = 0.0f;
        g_progress_monotone = 1;
        r = tt_synthesize_tiles(src, &o, &al, &set, &err);
        CHECK(r == TT_OK && g_progress_calls > 0 && g_progress_monotone && g_progress_last == 1.0f,
              "progress: %d calls, monotone %d, last %g", g_progress_calls, g_progress_monotone, g_progress_last);
        if (r == TT_OK) tt_tileset_free(set);
        o.progress = cancel_at_3;
        g_progress_calls = 0;
        g_progress_last = 0.0f;
        set = (tt_tileset *)&set;
        r = tt_synthesize_tiles(src, &o, &al, &set, &err);
        if (r == TT_OK) tt_tileset_free(set);
        CHECK(r == TT_CANCELLED && set == NULL && err.result == TT_CANCELLED && g_progress_calls == 3,
              "cancel at the 3rd progress call: expected TT_CANCELLED after 3 calls, got %d after %d", r,
              g_progress_calls);
        CHECK(cnt.live == 0 && cnt.bad_frees == 0, "cancelled synthesis leaked %ld allocations", cnt.live);
    }
    /* NULL options: defaults (n = 1, S = 128) need a 128 x 256 source */
    set = (tt_tileset *)&set;
    r = tt_synthesize_tiles(src, NULL, NULL, &set, &err);
    if (r == TT_OK) tt_tileset_free(set);
    CHECK(r == TT_ERROR_IMAGE_TOO_SMALL && set == NULL, "NULL options on a 64x128 image: expected %d, got %d",
          TT_ERROR_IMAGE_TOO_SMALL, r);
    tt_tileset_free(NULL);
    tt_image_free(src);
}

/* A source with one NaN or infinite texel is refused, naming the texel by
   row (y) and column (x), with *out NULL and nothing leaked; the same texel
   finite again works. Each channel, including alpha, is checked. */
static void test_synth_non_finite(void)
{
    static const struct { int x, y, channel, kind; } cases[] = {
        {5, 7, 0, 0}, {63, 0, 1, 1}, {0, 127, 2, 2}, {30, 90, 3, 0}, {17, 33, 1, 2}};
    tt_image *src = make_noise(64, 128, 12);
    tt_synth_options opt;
    int i;
    CHECK(src != NULL, "make_noise");
    if (!src) return;
    memset(&opt, 0, sizeof opt);
    opt.layout = make_layout(1, 16, 2);
    for (i = 0; i < (int)(sizeof cases / sizeof cases[0]); i++) {
        float *p = px(src, cases[i].x, cases[i].y), keep = p[cases[i].channel];
        const char *kind = cases[i].kind == 0 ? "NaN" : cases[i].kind == 1 ? "+inf" : "-inf";
        tt_tileset *set = (tt_tileset *)&set;
        tt_error err;
        counter cnt;
        tt_allocator al = make_allocator(&cnt, -1);
        tt_result r;
        p[cases[i].channel] = cases[i].kind == 0 ? (float)internal_not_a_number()
                              : cases[i].kind == 1 ? internal_infinity() : -internal_infinity();
        memset(&err, 0, sizeof err);
        r = tt_synthesize_tiles(src, &opt, &al, &set, &err);
        if (r == TT_OK) tt_tileset_free(set);
        CHECK(r == TT_ERROR_NON_FINITE && err.result == r && set == NULL && err.row == cases[i].y &&
                  err.column == cases[i].x && msg_has_number(err.message, cases[i].x) &&
                  msg_has_number(err.message, cases[i].y),
              "%s in channel %d of texel (x %d, y %d): expected TT_ERROR_NON_FINITE with row %d, column %d and "
              "*out NULL, got %d row %d column %d out %s \"%s\"", kind, cases[i].channel, cases[i].x, cases[i].y,
              cases[i].y, cases[i].x, r, err.row, err.column, set ? "set" : "NULL", err.message);
        CHECK(cnt.live == 0 && cnt.bad_frees == 0, "%s texel: %ld allocations leaked", kind, cnt.live);
        p[cases[i].channel] = keep;
    }
    {
        /* two bad texels: the first in row order is named */
        tt_tileset *set = NULL;
        tt_error err;
        tt_result r;
        float *a = px(src, 40, 50), *b = px(src, 3, 51), ka = a[1], kb = b[0];
        a[1] = internal_infinity();
        b[0] = (float)internal_not_a_number();
        r = tt_synthesize_tiles(src, &opt, NULL, &set, &err);
        if (r == TT_OK) tt_tileset_free(set);
        CHECK(r == TT_ERROR_NON_FINITE && err.row == 50 && err.column == 40,
              "two bad texels: expected the first (row 50, column 40), got %d row %d column %d", r, err.row,
              err.column);
        a[1] = ka;
        b[0] = kb;
        r = tt_synthesize_tiles(src, &opt, NULL, &set, &err);
        CHECK(r == TT_OK, "all texels finite again: %d (%s)", r, err.message);
        if (r == TT_OK) tt_tileset_free(set);
    }
    tt_image_free(src);
}

typedef struct synth_ctx {
    const tt_image *src;
    tt_synth_options opt;
} synth_ctx;

static tt_result oom_synth(void *ctx, const tt_allocator *al, tt_error *error)
{
    synth_ctx *s = (synth_ctx *)ctx;
    tt_tileset *set = (tt_tileset *)&set;
    tt_result r;
    r = tt_synthesize_tiles(s->src, &s->opt, al, &set, error);
    if (r == TT_OK) tt_tileset_free(set);
    else if (set != NULL || error->result != r) return TT_RESULT_MAX_ENUM;
    return r;
}

static void test_synth_oom(void)
{
    synth_ctx s;
    tt_image *src = make_noise(24, 48, 8);
    CHECK(src != NULL, "make_noise");
    if (!src) return;
    oom_reset();
    memset(&s, 0, sizeof s);
    s.src = src;
    s.opt.layout = make_layout(1, 8, 2);
    oom_sweep("tt_synthesize_tiles(n=1, S=8)", oom_synth, &s, TT_OK);
    s.opt.layout = make_layout(2, 4, TT_NO_GUTTER);
    s.opt.seed = 3;
    oom_sweep("tt_synthesize_tiles(n=2, S=4)", oom_synth, &s, TT_OK);
    tt_image_free(src);
}

/* ------------------------------------------------------------------------ */
/* 6c. The compact atlas                                                     */
/* ------------------------------------------------------------------------ */

/* The full atlas's texel (x, y), y counted from the bottom as UVs are. */
static const float *texel_from_bottom(const tt_image *im, int x, int y)
{
    return im->pixels + 4 * ((size_t)(im->height - 1 - y) * (size_t)im->width + (size_t)x);
}

/* Check a compact atlas against the naive reference: the cells are the
   distinct tiles of the faces (tt_tile_index, the walls' half moved right
   when `wide`), the size is the smallest power-of-two rectangle that holds
   them, and every texel of every face's full cell reads the same through
   tt_compact_atlas_uv in the compact image. */
static void check_compact(const char *what, const tt_mesh *mesh, const tt_tile_layout *layout, const uint8_t *types,
                          const float *uv, const int *wall, const tt_image *full, const tt_compact_atlas *ca,
                          const tt_image *image)
{
    const int T = tt_tile_layout_tiles_per_side(layout), W = tt_tile_layout_atlas_size(layout);
    const int C = layout->tile_size + 2 * layout->gutter, columns = full->width / C;
    int *seen = (int *)calloc((size_t)columns * (size_t)T, sizeof(int));
    int f, distinct = 0, wrong_texels = 0, fits, smaller_fits;
    (void)uv;
    if (!seen) return;
    for (f = 0; f < mesh->nfaces; f++) {
        int index = tt_tile_index(layout, types + mesh->face_start[f]);
        int column = index % T + (wall && wall[f] ? T : 0), row = index / T, x, y;
        if (!seen[row * columns + column]++) distinct++;
        for (y = 0; y < C; y++)
            for (x = 0; x < C; x++) {
                float in[2], out[2];
                const float *a = texel_from_bottom(full, column * C + x, row * C + y), *b;
                int cx, cy;
                in[0] = (float)((column * C + x + 0.5) / full->width);
                in[1] = (float)((row * C + y + 0.5) / full->height);
                tt_compact_atlas_uv(ca, f, in, out);
                cx = (int)floor(out[0] * ca->width);
                cy = (int)floor(out[1] * ca->height);
                if (cx < 0 || cy < 0 || cx >= image->width || cy >= image->height) {
                    wrong_texels++;
                    continue;
                }
                b = texel_from_bottom(image, cx, cy);
                if (memcmp(a, b, 4 * sizeof(float)) != 0) wrong_texels++;
            }
    }
    fits = (ca->width / C) * (ca->height / C) >= distinct;
    /* The next smaller candidate: W/2 x W/2 before a W x W/2... */
    smaller_fits = ca->width == ca->height ? (ca->width / C) * (ca->width / 2 / C) >= distinct
                                           : (ca->height / C) * (ca->height / C) >= distinct;
    CHECK(ca->ncells == distinct && fits && !smaller_fits && (ca->width & (ca->width - 1)) == 0 &&
              (ca->height & (ca->height - 1)) == 0 && (ca->width == ca->height || ca->width == 2 * ca->height) &&
              image->width == ca->width && image->height == ca->height && ca->columns == ca->width / C,
          "%s: %d cells in %d x %d (columns %d) for %d distinct tiles of %d-texel cells (full %d x %d, W %d)", what,
          ca->ncells, ca->width, ca->height, ca->columns, distinct, C, full->width, full->height, W);
    CHECK(wrong_texels == 0, "%s: %d texels of the faces' cells read differently in the compact atlas", what,
          wrong_texels);
    free(seen);
}

typedef struct compact_ctx {
    const tt_mesh *mesh;
    const float *uv;
    tt_tile_layout layout;
    int full_width, full_height;
    const tt_image *full;
} compact_ctx;

static tt_result oom_compact(void *ctx, const tt_allocator *al, tt_error *error)
{
    compact_ctx *c = (compact_ctx *)ctx;
    tt_compact_atlas *ca = (tt_compact_atlas *)&ca;
    tt_image *image = (tt_image *)&image;
    tt_result r = tt_compact_atlas_create(c->mesh, c->uv, &c->layout, c->full_width, c->full_height, 0, al, &ca,
                                          error);
    if (r != TT_OK) return ca != NULL || error->result != r ? TT_RESULT_MAX_ENUM : r;
    r = tt_compact_atlas_image(ca, c->full, al, &image, error);
    tt_compact_atlas_free(ca);
    if (r != TT_OK) return image != NULL || error->result != r ? TT_RESULT_MAX_ENUM : r;
    tt_image_free(image);
    return r;
}

static void test_compact_atlas(void)
{
    tmesh m;
    tt_mesh *grid = NULL, *torus = NULL;
    tt_tile_layout layout = make_layout(2, 8, 2);   /* T 16, C 12, W 192 */
    tt_error err;
    uint8_t *types = NULL;
    float *uv = NULL, *wide_uv = NULL;
    int *wall = NULL, f, c;
    tt_image *full = NULL, *wide = NULL, *image = NULL;
    tt_compact_atlas *ca = NULL;
    memset(&m, 0, sizeof m);
    make_grid(&m, 6, 5);
    CHECK(build(&m, 0, &grid, &err) == TT_OK, "grid build");
    tm_free(&m);
    make_torus(&m, 32, 24, 3, 1);
    CHECK(build(&m, 0, &torus, &err) == TT_OK, "torus build");
    tm_free(&m);
    full = make_noise(192, 192, 5);
    wide = make_noise(384, 192, 6);
    types = (uint8_t *)malloc((size_t)torus->ncorners);
    uv = (float *)malloc(2 * sizeof(float) * (size_t)torus->ncorners);
    wide_uv = (float *)malloc(2 * sizeof(float) * (size_t)torus->ncorners);
    wall = (int *)malloc(sizeof(int) * (size_t)torus->nfaces);
    if (!grid || !torus || !full || !wide || !types || !uv || !wide_uv || !wall) goto done;

    /* A few faces, a few tiles: a small square or 2:1 atlas. */
    CHECK(tt_assign_boundaries(grid, &layout, 7, NULL, types, &err) == TT_OK &&
              tt_assign_uvs(grid, &layout, types, uv, &err) == TT_OK, "grid tiles: %s", err.message);
    CHECK(tt_compact_atlas_create(grid, uv, &layout, 192, 192, 0, NULL, &ca, &err) == TT_OK && ca,
          "compact atlas of the grid: %s", err.message);
    if (ca && tt_compact_atlas_image(ca, full, NULL, &image, &err) == TT_OK) {
        check_compact("grid", grid, &layout, types, uv, NULL, full, ca, image);
        /* The UVs inside a face keep their differences: a translation. */
        {
            int bad = 0;
            for (f = 0; f < grid->nfaces; f++)
                for (c = grid->face_start[f] + 1; c < grid->face_start[f + 1]; c++) {
                    float a[2], b[2];
                    const float *p = uv + 2 * grid->face_start[f], *q = uv + 2 * c;
                    tt_compact_atlas_uv(ca, f, p, a);
                    tt_compact_atlas_uv(ca, f, q, b);
                    if (fabs((b[0] - a[0]) * ca->width - (q[0] - p[0]) * 192.0) > 1e-3 ||
                        fabs((b[1] - a[1]) * ca->height - (q[1] - p[1]) * 192.0) > 1e-3)
                        bad++;
                }
            CHECK(bad == 0, "compact UVs: %d corners moved against their face's first", bad);
        }
        /* Texels outside every cell hold the cells' mean (the noise's, about 0.5). */
        {
            const float *corner = texel_from_bottom(image, image->width - 1, 0);
            CHECK(ca->ncells < ca->columns * (ca->height / 12) && near(corner[0], 0.5, 0.05) && corner[3] == 1.0f,
                  "the space beside the cells: %g %g (%d cells, %d a row)", corner[0], corner[3], ca->ncells,
                  ca->columns);
        }
        tt_image_free(image);
        image = NULL;
    }
    tt_compact_atlas_free(ca);
    ca = NULL;

    /* Upright-style: a 2W x W atlas, every third face a wall in the right half. */
    CHECK(tt_assign_boundaries(torus, &layout, 3, NULL, types, &err) == TT_OK &&
              tt_assign_uvs(torus, &layout, types, uv, &err) == TT_OK, "torus tiles: %s", err.message);
    for (f = 0; f < torus->nfaces; f++) {
        wall[f] = f % 3 == 0;
        for (c = torus->face_start[f]; c < torus->face_start[f + 1]; c++) {
            wide_uv[2 * c] = 0.5f * (uv[2 * c] + (float)wall[f]);
            wide_uv[2 * c + 1] = uv[2 * c + 1];
        }
    }
    CHECK(tt_compact_atlas_create(torus, wide_uv, &layout, 384, 192, 0, NULL, &ca, &err) == TT_OK && ca,
          "compact atlas of the torus: %s", err.message);
    if (ca && tt_compact_atlas_image(ca, wide, NULL, &image, &err) == TT_OK)
        check_compact("torus, walls", torus, &layout, types, wide_uv, wall, wide, ca, image);
    tt_image_free(image);
    image = NULL;
    /* A limit the cells do not fit: TOO_LARGE, saying the size that would. */
    if (ca) {
        char needed[64];
        tt_compact_atlas *small = (tt_compact_atlas *)&small;
        snprintf(needed, sizeof needed, "%d x %d", ca->width, ca->height);
        CHECK(tt_compact_atlas_create(torus, wide_uv, &layout, 384, 192, ca->width / 2, NULL, &small, &err) ==
                      TT_ERROR_TOO_LARGE &&
                  small == NULL && strstr(err.message, needed),
              "max_size %d below the %s needed: %s", ca->width / 2, needed, err.message);
    }
    tt_compact_atlas_free(ca);
    ca = NULL;
    /* A normal map's unused texels are a unit vector. */
    {
        tt_image *normals = make_noise(384, 192, 8);
        if (normals) {
            int i;
            normals->kind = TT_IMAGE_NORMAL;
            for (i = 0; i < 384 * 192; i++) normals->pixels[4 * i + 2] += 1.0f;
            if (tt_compact_atlas_create(grid, uv, &layout, 192, 192, 0, NULL, &ca, NULL) == TT_OK) {
                tt_image *small = NULL;
                normals->width = 192;   /* the first half of each row: any 192 x 192 image of the kind */
                normals->height = 192;
                if (tt_compact_atlas_image(ca, normals, NULL, &small, &err) == TT_OK) {
                    const float *p = texel_from_bottom(small, small->width - 1, 0);
                    CHECK(small->kind == TT_IMAGE_NORMAL && near(p[0] * p[0] + p[1] * p[1] + p[2] * p[2], 1.0, 1e-5),
                          "a normal map's fill: kind %d, length %g", (int)small->kind,
                          sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]));
                }
                tt_image_free(small);
                normals->width = 384;
                normals->height = 192;
            }
            tt_compact_atlas_free(ca);
            ca = NULL;
            tt_image_free(normals);
        }
    }
    /* Every allocation may fail. */
    {
        compact_ctx ctx;
        ctx.mesh = torus;
        ctx.uv = wide_uv;
        ctx.layout = layout;
        ctx.full_width = 384;
        ctx.full_height = 192;
        ctx.full = wide;
        oom_reset();
        oom_sweep("tt_compact_atlas_create + image", oom_compact, &ctx, TT_OK);
    }
done:
    tt_image_free(full);
    tt_image_free(wide);
    free(types);
    free(uv);
    free(wide_uv);
    free(wall);
    tt_mesh_free(grid);
    tt_mesh_free(torus);
}

/* ------------------------------------------------------------------------ */
/* 6d. Quality measures                                                     */
/* ------------------------------------------------------------------------ */

/* UVs of one random tile per face: four types drawn independently, so the
   two sides of an edge mostly do not agree (the control for the seam
   measure). */
static void random_face_types(const tt_mesh *mesh, int n, unsigned seed, uint8_t *types)
{
    int c;
    lcg_seed(seed);
    for (c = 0; c < mesh->ncorners; c++) types[c] = (uint8_t)lcg_below(2 * n);
}

static void test_seams(void)
{
    tmesh m;
    tt_mesh *mesh = NULL;
    tt_error err;
    tt_image *src = NULL;
    tt_synth_options opt;
    tt_tileset *set = NULL;
    uint8_t *types;
    float *uv, *shuffled;
    tt_seam_options so;
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
    CHECK(src != NULL, "make_value_noise");
    if (!src) { tt_mesh_free(mesh); return; }
    types = (uint8_t *)malloc((size_t)mesh->ncorners);
    uv = (float *)malloc(sizeof(float) * 2 * (size_t)mesh->ncorners);
    shuffled = (float *)malloc(sizeof(float) * 2 * (size_t)mesh->ncorners);
    memset(&so, 0, sizeof so);
    so.seed = 99;
    for (n = 1; n <= 2; n++) {
        memset(&opt, 0, sizeof opt);
        opt.layout = make_layout(n, 32, 4);
        opt.seed = 11;
        r = tt_synthesize_tiles(src, &opt, NULL, &set, &err);
        CHECK(r == TT_OK, "seams n=%d: synthesize %d (%s)", n, r, err.message);
        if (r != TT_OK) continue;
        tt_assign_boundaries(mesh, &opt.layout, 5, NULL, types, NULL);
        r = tt_assign_uvs(mesh, &opt.layout, types, uv, &err);
        CHECK(r == TT_OK, "seams: assign_uvs %d", r);
        r = tt_measure_seams(mesh, uv, &set->levels[0], &so, NULL, &rep, &err);
        CHECK(r == TT_OK, "tt_measure_seams returned %d (%s)", r, err.message);
        CHECK(rep.edges_measured == 2 * mesh->nfaces, "seams: edges_measured expected %d, got %d", 2 * mesh->nfaces,
              rep.edges_measured);
        CHECK(rep.score <= 0.05, "seams n=%d: score %.4f > 0.05 (seam %.4f, same face %.4f, unrelated %.4f)", n,
              rep.score, rep.seam, rep.same_face, rep.unrelated);
        /* same seed, same report */
        tt_measure_seams(mesh, uv, &set->levels[0], &so, NULL, &rep2, NULL);
        CHECK(rep.score == rep2.score && rep.seam == rep2.seam && rep.samples == rep2.samples,
              "seams: the same seed should give the same report");
        /* NULL options: every edge, seed 0 */
        r = tt_measure_seams(mesh, uv, &set->levels[0], NULL, NULL, &rep2, &err);
        CHECK(r == TT_OK && rep2.edges_measured == 2 * mesh->nfaces && rep2.score <= 0.05,
              "seams n=%d, NULL options: %d, %d edges, score %.4f", n, r, rep2.edges_measured, rep2.score);
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
        r = tt_measure_seams(mesh, shuffled, &set->levels[0], &so, NULL, &rep2, &err);
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
    CHECK(tt_measure_seams(NULL, uv, src, NULL, NULL, &rep, &err) == TT_ERROR_INVALID_ARGUMENT &&
              tt_measure_seams(mesh, NULL, src, NULL, NULL, &rep, &err) == TT_ERROR_INVALID_ARGUMENT &&
              tt_measure_seams(mesh, uv, NULL, NULL, NULL, &rep, &err) == TT_ERROR_INVALID_ARGUMENT &&
              tt_measure_seams(mesh, uv, src, NULL, NULL, NULL, &err) == TT_ERROR_INVALID_ARGUMENT,
          "tt_measure_seams with NULL arguments should be rejected");
    {
        tt_image empty;
        memset(&empty, 0, sizeof empty);
        r = tt_measure_seams(mesh, uv, &empty, NULL, NULL, &rep, &err);
        CHECK(r == TT_ERROR_INVALID_ARGUMENT, "tt_measure_seams on an empty atlas: expected %d, got %d",
              TT_ERROR_INVALID_ARGUMENT, r);
    }
    {
        counter cnt;
        tt_allocator half = make_allocator(&cnt, -1);
        half.alloc = NULL;
        r = tt_measure_seams(mesh, uv, src, NULL, &half, &rep, &err);
        CHECK(r == TT_ERROR_INVALID_ARGUMENT, "tt_measure_seams with an allocator without alloc: expected %d, got %d",
              TT_ERROR_INVALID_ARGUMENT, r);
    }
    free(types);
    free(uv);
    free(shuffled);
    tt_image_free(src);
    tt_mesh_free(mesh);
}

/* A textured torus for the seam tests: a nu x nv torus of quads, a tile set
   synthesised from value noise, and room for corner types and UVs. */
typedef struct seam_fixture {
    tt_mesh *mesh;
    tt_image *src;
    tt_tileset *set;
    tt_tile_layout layout;
    uint8_t *types;
    float *uv;
} seam_fixture;

static void seam_fixture_free(seam_fixture *fx)
{
    free(fx->types);
    free(fx->uv);
    tt_tileset_free(fx->set);
    tt_image_free(fx->src);
    tt_mesh_free(fx->mesh);
    memset(fx, 0, sizeof *fx);
}

static int seam_fixture_make(seam_fixture *fx, int nu, int nv, int noise_width, unsigned noise_seed, int colors,
                             uint64_t synth_seed, const char *what)
{
    tmesh m;
    tt_synth_options opt;
    tt_error err;
    tt_result r;
    memset(fx, 0, sizeof *fx);
    memset(&m, 0, sizeof m);
    make_torus(&m, nu, nv, 3.0, 1.0);
    r = build(&m, 0, &fx->mesh, &err);
    tm_free(&m);
    CHECK(r == TT_OK, "%s: torus build %d", what, r);
    if (r != TT_OK) return 0;
    make_value_noise(&fx->src, noise_width, 256, noise_seed);
    memset(&opt, 0, sizeof opt);
    opt.layout = fx->layout = make_layout(colors, 32, 4);
    opt.seed = synth_seed;
    r = fx->src ? tt_synthesize_tiles(fx->src, &opt, NULL, &fx->set, &err) : TT_ERROR_OUT_OF_MEMORY;
    CHECK(r == TT_OK, "%s: synthesize %d (%s)", what, r, err.message);
    fx->types = (uint8_t *)malloc((size_t)fx->mesh->ncorners);
    fx->uv = (float *)malloc(sizeof(float) * 2 * (size_t)fx->mesh->ncorners);
    if (r != TT_OK || !fx->types || !fx->uv) {
        seam_fixture_free(fx);
        return 0;
    }
    return 1;
}

/* The control, on displayed colours: one random tile per face (corner types
   that do not match across edges) scores badly where the real assignment
   scores near 0, with the same atlas. */
static void test_seams_control(void)
{
    seam_fixture fx;
    tt_seam_report real, random;
    tt_error err;
    tt_result r;
    int c, matching = 0, interior = 0;
    if (!seam_fixture_make(&fx, 40, 24, 160, 21, 2, 4, "control")) return;
    tt_assign_boundaries(fx.mesh, &fx.layout, 8, NULL, fx.types, NULL);
    tt_assign_uvs(fx.mesh, &fx.layout, fx.types, fx.uv, NULL);
    r = tt_measure_seams(fx.mesh, fx.uv, &fx.set->levels[0], NULL, NULL, &real, &err);
    CHECK(r == TT_OK && real.score < 0.1, "control, real assignment: %d, score %.4f (want < 0.1)", r, real.score);
    random_face_types(fx.mesh, 2, 4242, fx.types);
    for (c = 0; c < fx.mesh->ncorners; c++)
        if (fx.mesh->twin[c] > c) {
            interior++;
            matching += fx.types[fx.mesh->twin[c]] == (fx.types[c] ^ 1);
        }
    CHECK(matching < interior / 2, "control: %d of %d random edges match; the control is not random", matching,
          interior);
    r = tt_assign_uvs(fx.mesh, &fx.layout, fx.types, fx.uv, &err);
    CHECK(r == TT_OK, "control: assign_uvs of random types %d", r);
    r = tt_measure_seams(fx.mesh, fx.uv, &fx.set->levels[0], NULL, NULL, &random, &err);
    CHECK(r == TT_OK && random.score > 0.3 && random.score > real.score + 0.25,
          "control, random tiles per face: %d, score %.4f (want > 0.3; real %.4f; seam %.4f, same face %.4f, "
          "unrelated %.4f)", r, random.score, real.score, random.seam, random.same_face, random.unrelated);
    seam_fixture_free(&fx);
}

/* tt_seam_options::ends measures only near the edges' ends, where the
   tiles' corners meet. On matching tiles it stays low; with a disc around
   every face corner's UV painted a flat colour of its own (the middles
   untouched), it
   rises well above the whole-edge score, which the middles dilute; and
   bad fractions are refused. */
static void test_seams_ends(void)
{
    seam_fixture fx;
    tt_seam_options so;
    tt_seam_report whole, ends, whole_spoilt, ends_spoilt;
    tt_error err;
    tt_result r1, r2;
    tt_image *atlas;
    const float bad[3] = {-0.1f, 0.6f, 0.0f};
    int x, y, k, c, corner = 5;
    uint32_t state = 12345u;
    if (!seam_fixture_make(&fx, 40, 24, 160, 21, 2, 4, "ends")) return;
    tt_assign_boundaries(fx.mesh, &fx.layout, 8, NULL, fx.types, NULL);
    tt_assign_uvs(fx.mesh, &fx.layout, fx.types, fx.uv, NULL);
    atlas = &fx.set->levels[0];
    memset(&so, 0, sizeof so);
    so.ends = 0.1f;
    r1 = tt_measure_seams(fx.mesh, fx.uv, atlas, NULL, NULL, &whole, &err);
    r2 = tt_measure_seams(fx.mesh, fx.uv, atlas, &so, NULL, &ends, &err);
    CHECK(r1 == TT_OK && r2 == TT_OK && whole.score < 0.1 && ends.score < 0.2,
          "ends, matching tiles: %d %d, whole-edge score %.4f (want < 0.1), near the ends %.4f (want < 0.2)", r1, r2,
          whole.score, ends.score);
    /* Spoil a disc of `corner` texels around every face corner's UV, each
       with a flat colour of its own (flat, so the same-face reference stays
       what it was). */
    for (c = 0; c < fx.mesh->ncorners; c++) {
        const int u = (int)(fx.uv[2 * c] * (float)atlas->width), v = (int)((1.0f - fx.uv[2 * c + 1]) * (float)atlas->height);
        float colour[3];
        for (k = 0; k < 3; k++) {
            state = state * 1664525u + 1013904223u;
            colour[k] = (float)(state >> 8) / 16777216.0f;
        }
        for (y = v - corner; y <= v + corner; y++)
            for (x = u - corner; x <= u + corner; x++) {
                if (x < 0 || y < 0 || x >= atlas->width || y >= atlas->height ||
                    (x - u) * (x - u) + (y - v) * (y - v) > corner * corner)
                    continue;
                for (k = 0; k < 3; k++) atlas->pixels[4 * ((size_t)y * atlas->width + x) + k] = colour[k];
            }
    }
    r1 = tt_measure_seams(fx.mesh, fx.uv, atlas, NULL, NULL, &whole_spoilt, &err);
    r2 = tt_measure_seams(fx.mesh, fx.uv, atlas, &so, NULL, &ends_spoilt, &err);
    CHECK(r1 == TT_OK && r2 == TT_OK && ends_spoilt.score > 0.5 && ends_spoilt.score > whole_spoilt.score + 0.25,
          "ends, corners spoilt: %d %d, near the ends %.4f (want > 0.5 and > whole-edge %.4f + 0.25)", r1, r2,
          ends_spoilt.score, whole_spoilt.score);
    printf("     seams near the ends: matching %.3f (whole %.3f), corners spoilt %.3f (whole %.3f)\n", ends.score,
           whole.score, ends_spoilt.score, whole_spoilt.score);
    for (k = 0; k < 3; k++) {
        so.ends = k < 2 ? bad[k] : (float)NAN;
        r1 = tt_measure_seams(fx.mesh, fx.uv, atlas, &so, NULL, &ends, &err);
        CHECK(r1 == TT_ERROR_INVALID_ARGUMENT && strstr(err.message, "ends") != NULL,
              "ends %g: expected TT_ERROR_INVALID_ARGUMENT naming ends, got %d (%s)", (double)so.ends, r1, err.message);
    }
    seam_fixture_free(&fx);
}

/* ---- Tiles turned along a field (tt_orient_tiles, tt_assign_uvs_oriented) ---- */

/* Whether face f (of tt_tileset_kind kind[f]) shows an upright band on
   half-edge c's side: a left or right side its kind keeps upright. */
static int side_is_upright(const uint8_t *turn, const uint8_t *kind, int f, int c)
{
    const int side = (c - 4 * f - turn[f]) & 3;
    if (side == 1) return kind[f] == TT_TILESET_UPRIGHT || kind[f] == TT_TILESET_LEFT_PLAIN;
    if (side == 3) return kind[f] == TT_TILESET_UPRIGHT || kind[f] == TT_TILESET_RIGHT_PLAIN;
    return 0;
}

/* Edges whose two faces show different bands (one upright, one plain or a
   bottom or top side): each must be 0 for every edge to match. */
static int mismatched_edges(const tt_mesh *mesh, const uint8_t *turn, const uint8_t *kind)
{
    int c, bad = 0;
    for (c = 0; c < mesh->ncorners; c++) {
        const int t = mesh->twin[c];
        if (t > c && side_is_upright(turn, kind, mesh->corner_face[c], c) !=
                         side_is_upright(turn, kind, mesh->corner_face[t], t))
            bad++;
    }
    return bad;
}

/* On a plane grid whose quads start at random corners, a field along +y
   turns every tile upright: its bottom side (half-edge turn) runs along +x.
   Turn 0 (tt_assign_uvs) does so only where the corners happen to start
   there: the control. One quad whose field runs along +x is plain (its
   left and right sides meet the bottom and top sides of the rows beside),
   its neighbours along its row keep upright tiles with the side that meets
   it plain, and every other quad stays upright; every edge's two faces
   show the same band. */
static void test_orient_tiles(void)
{
    const int nx = 7, ny = 5;
    tmesh m;
    tt_mesh *mesh = NULL;
    tt_error err;
    float vectors[3 * 35];
    uint8_t turn[35], upright[35];
    int f, k, along = 0, along_unturned = 0, count = -1, as_expected = 1;
    memset(&m, 0, sizeof m);
    make_grid(&m, nx, ny);
    lcg_seed(77);
    for (f = 0; f < m.nf; f++) {
        int q[4], r = lcg_below(4);
        for (k = 0; k < 4; k++) q[k] = m.idx[4 * f + (k + r) % 4];
        for (k = 0; k < 4; k++) m.idx[4 * f + k] = q[k];
    }
    CHECK(build(&m, 0, &mesh, &err) == TT_OK, "grid build: %s", err.message);
    if (!mesh) { tm_free(&m); return; }
    for (f = 0; f < mesh->nfaces; f++) {
        vectors[3 * f] = 0.0f; vectors[3 * f + 1] = 2.0f; vectors[3 * f + 2] = 0.0f;
    }
    CHECK(tt_orient_tiles(mesh, vectors, turn, upright, &count, &err) == TT_OK, "orient: %s", err.message);
    for (f = 0; f < mesh->nfaces; f++) {
        const float *a = mesh->pos + 3 * mesh->corner_vert[4 * f + turn[f]];
        const float *b = mesh->pos + 3 * mesh->corner_vert[4 * f + ((turn[f] + 1) & 3)];
        const float *a0 = mesh->pos + 3 * mesh->corner_vert[4 * f], *b0 = mesh->pos + 3 * mesh->corner_vert[4 * f + 1];
        along += b[0] - a[0] > 0.5f && fabsf(b[1] - a[1]) < 1e-6f;
        along_unturned += b0[0] - a0[0] > 0.5f && fabsf(b0[1] - a0[1]) < 1e-6f;
    }
    CHECK(along == nx * ny, "every tile's bottom runs along +x: %d of %d", along, nx * ny);
    CHECK(along_unturned < nx * ny / 2, "control: unturned, %d of %d run along +x (want few)", along_unturned,
          nx * ny);
    CHECK(count == nx * ny, "a grid along the field: every quad upright (%d of %d)", count, nx * ny);

    /* Quad (3, 2) turned a quarter by its field. */
    vectors[3 * (2 * nx + 3)] = 1.0f;
    vectors[3 * (2 * nx + 3) + 1] = 0.0f;
    CHECK(tt_orient_tiles(mesh, vectors, turn, upright, &count, &err) == TT_OK, "orient: %s", err.message);
    for (f = 0; f < mesh->nfaces; f++) {
        const int want = f == 2 * nx + 3   ? TT_TILESET_PLAIN
                         : f == 2 * nx + 2 ? TT_TILESET_RIGHT_PLAIN
                         : f == 2 * nx + 4 ? TT_TILESET_LEFT_PLAIN
                                           : TT_TILESET_UPRIGHT;
        as_expected &= upright[f] == want;
    }
    CHECK(mismatched_edges(mesh, turn, upright) == 0, "every edge's two faces show the same band: %d do not",
          mismatched_edges(mesh, turn, upright));
    CHECK(as_expected && count == nx * ny - 3,
          "one quad across the field is plain, its neighbours along the row have that side plain, the rest "
          "upright: %d upright (want %d)", count, nx * ny - 3);
    /* The control: upright everywhere leaves the quad's four edges mismatched. */
    memset(upright, TT_TILESET_UPRIGHT, sizeof upright);
    CHECK(mismatched_edges(mesh, turn, upright) == 4, "control: upright everywhere, %d edges mismatched (want 4)",
          mismatched_edges(mesh, turn, upright));
    /* Without face_upright only the turns are made. */
    CHECK(tt_orient_tiles(mesh, vectors, turn, NULL, &count, &err) == TT_OK && count == 0,
          "no face_upright: count 0, got %d", count);
    tt_mesh_free(mesh);
    tm_free(&m);
}

/* tt_assign_uvs_oriented: without turns and flags tt_assign_uvs's UVs to the
   bit; with them, corner turn + k of a quad gets corner k of the tile named
   by the types read from half-edge turn on (tt_tile_corner_uv), its u halved
   and moved to the right half for an upright quad. */
static void test_assign_uvs_oriented(void)
{
    tmesh m;
    tt_mesh *mesh = NULL;
    tt_error err;
    tt_tile_layout layout = make_layout(2, 16, 2);
    uint8_t types[4 * 12], turn[12], upright[12];
    float plain_uv[8 * 12], uv[8 * 12];
    int f, k, agree = 1;
    memset(&m, 0, sizeof m);
    make_grid(&m, 4, 3);
    CHECK(build(&m, 0, &mesh, &err) == TT_OK, "grid build");
    if (!mesh) { tm_free(&m); return; }
    CHECK(tt_assign_boundaries(mesh, &layout, 5, NULL, types, &err) == TT_OK, "boundaries");
    CHECK(tt_assign_uvs(mesh, &layout, types, plain_uv, &err) == TT_OK, "uvs");
    CHECK(tt_assign_uvs_oriented(mesh, &layout, types, NULL, NULL, uv, &err) == TT_OK &&
              memcmp(uv, plain_uv, sizeof uv) == 0,
          "no turns, no flags: tt_assign_uvs's UVs to the bit");
    for (f = 0; f < 12; f++) {
        turn[f] = (uint8_t)(f % 4);
        upright[f] = (uint8_t)(f % TT_TILESET_KINDS);
    }
    CHECK(tt_assign_uvs_oriented(mesh, &layout, types, turn, upright, uv, &err) == TT_OK, "oriented: %s",
          err.message);
    for (f = 0; f < 12; f++) {
        uint8_t e[4];
        for (k = 0; k < 4; k++) e[k] = types[4 * f + ((k + turn[f]) & 3)];
        for (k = 0; k < 4; k++) {
            float want[2];
            const float *got = uv + 2 * (4 * f + ((k + turn[f]) & 3));
            tt_tile_corner_uv(&layout, e, k, want);
            want[0] = 0.5f * (want[0] + (float)(upright[f] % 2));
            want[1] = 0.5f * (want[1] + (float)(upright[f] / 2));
            agree &= fabsf(got[0] - want[0]) < 1e-6f && fabsf(got[1] - want[1]) < 1e-6f;
        }
    }
    CHECK(agree, "each quad's corners are its turned tile's, in its set's quarter of the atlas");
    upright[5] = TT_TILESET_KINDS;
    CHECK(tt_assign_uvs_oriented(mesh, &layout, types, turn, upright, uv, &err) == TT_ERROR_INVALID_ARGUMENT &&
              err.face == 5,
          "a set beyond the four refused, naming the face: %s", err.message);
    tt_mesh_free(mesh);
    tm_free(&m);
}

/* Every edge matches with turned tiles, plain and upright: on a torus whose
   field runs along the meridians on one half and along the parallels on the
   other, or one or the other at random per quad, either way at random, the
   seam score of tt_orient_tiles's choice stays near 0. The control forces
   every quad upright on all four sides with the random field's turns: left
   and right sides then meet bottom and top sides, and the score rises. */
static void test_orient_tiles_seams(void)
{
    seam_fixture fx;
    tt_synth_options opt;
    tt_tileset *upright_sets[3] = {NULL, NULL, NULL}, *sets[TT_TILESET_KINDS];
    tt_image *atlas = NULL;
    tt_seam_report kept, forced;
    tt_error err;
    float *vectors;
    uint8_t *turn, *upright;
    int f, k, count = 0, field, made = 1;
    tt_result r;
    if (!seam_fixture_make(&fx, 40, 24, 160, 21, 2, 4, "oriented")) return;
    memset(&opt, 0, sizeof opt);
    opt.layout = fx.layout;
    opt.seed = 4;
    vectors = (float *)malloc(sizeof(float) * 3 * (size_t)fx.mesh->nfaces);
    turn = (uint8_t *)malloc((size_t)fx.mesh->nfaces);
    upright = (uint8_t *)malloc((size_t)fx.mesh->nfaces);
    sets[TT_TILESET_PLAIN] = fx.set;
    make_upright_sets(fx.src, opt, sets);
    for (k = 0; k < 3; k++) made &= (upright_sets[k] = sets[TT_TILESET_UPRIGHT + k]) != NULL;
    if (!vectors || !turn || !upright || !made ||
        tt_upright_atlas((const tt_tileset *const *)sets, 0, NULL, NULL, &atlas, &err) != TT_OK) {
        CHECK(0, "oriented: upright tiles and atlas");
        goto done;
    }
    tt_assign_boundaries(fx.mesh, &fx.layout, 8, NULL, fx.types, NULL);
    lcg_seed(31);
    for (field = 0; field < 2; field++) {
        for (f = 0; f < fx.mesh->nfaces; f++) {
            /* Face (i, j) of make_torus: half-edge 0 along the parallel, 3 (reversed) along the meridian. */
            const int meridian = field == 0 ? f / 40 < 12 : lcg_below(2);
            const float *a = fx.mesh->pos + 3 * fx.mesh->corner_vert[4 * f];
            const float *b = fx.mesh->pos + 3 * fx.mesh->corner_vert[4 * f + (meridian ? 3 : 1)];
            const float sign = lcg_below(2) ? 1.0f : -1.0f;
            int axis;
            for (axis = 0; axis < 3; axis++) vectors[3 * f + axis] = sign * (b[axis] - a[axis]);
        }
        CHECK(tt_orient_tiles(fx.mesh, vectors, turn, upright, &count, &err) == TT_OK, "orient: %s",
              err.message);
        CHECK(field == 1 || (count > 0 && count < fx.mesh->nfaces),
              "half along the meridians, half along the parallels: some quads upright, some plain (%d of %d)",
              count, fx.mesh->nfaces);
        tt_assign_uvs_oriented(fx.mesh, &fx.layout, fx.types, turn, upright, fx.uv, NULL);
        r = tt_measure_seams(fx.mesh, fx.uv, atlas, NULL, NULL, &kept, &err);
        CHECK(r == TT_OK && kept.score < 0.1, "field %d: turned tiles, upright where the rule allows: score %.4f "
              "(want < 0.1)", field, kept.score);
    }
    /* The control, on the random field's turns. */
    memset(upright, TT_TILESET_UPRIGHT, (size_t)fx.mesh->nfaces);
    tt_assign_uvs_oriented(fx.mesh, &fx.layout, fx.types, turn, upright, fx.uv, NULL);
    r = tt_measure_seams(fx.mesh, fx.uv, atlas, NULL, NULL, &forced, &err);
    CHECK(r == TT_OK && forced.score > kept.score + 0.2,
          "control, every quad upright whatever the turns: score %.4f (want above %.4f + 0.2)", forced.score,
          kept.score);
done:
    free(vectors);
    free(turn);
    free(upright);
    tt_image_free(atlas);
    for (k = 0; k < 3; k++) tt_tileset_free(upright_sets[k]);
    seam_fixture_free(&fx);
}

/* The seam measure compares colours as displayed: three unit quads in a row,
   each mapped onto its own flat 8 x 8 block of an atlas made from sRGB bytes
   100, 200, 100. Both interior edges then differ by exactly 100/255 as
   displayed (in linear light it would be 0.45), the same-face difference is
   0, and the measure does not depend on the atlas's linear values. */
static void test_seams_displayed(void)
{
    tmesh m;
    tt_mesh *mesh = NULL;
    tt_image *atlas = NULL;
    tt_error err;
    tt_seam_report rep;
    unsigned char bytes[8 * 24];
    float uv[24];
    tt_result r;
    int x, y, f;
    memset(&m, 0, sizeof m);
    make_grid(&m, 3, 1);
    r = build(&m, 0, &mesh, &err);
    tm_free(&m);
    CHECK(r == TT_OK, "row of three quads: build %d", r);
    if (r != TT_OK) return;
    for (y = 0; y < 8; y++)
        for (x = 0; x < 24; x++) bytes[y * 24 + x] = (unsigned char)(x / 8 == 1 ? 200 : 100);
    r = tt_image_from_bytes(bytes, 24, 8, 1, 0, TT_COLOR_SRGB, NULL, &atlas, &err);
    CHECK(r == TT_OK, "atlas from bytes: %d (%s)", r, err.message);
    if (r != TT_OK) { tt_mesh_free(mesh); return; }
    for (f = 0; f < 3; f++) {
        /* corners (f,0) (f+1,0) (f+1,1) (f,1): block f of the atlas */
        float u0 = (float)(8 * f) / 24.0f, u1 = (float)(8 * f + 8) / 24.0f;
        uv[8 * f] = u0; uv[8 * f + 1] = 0.0f;
        uv[8 * f + 2] = u1; uv[8 * f + 3] = 0.0f;
        uv[8 * f + 4] = u1; uv[8 * f + 5] = 1.0f;
        uv[8 * f + 6] = u0; uv[8 * f + 7] = 1.0f;
    }
    r = tt_measure_seams(mesh, uv, atlas, NULL, NULL, &rep, &err);
    CHECK(r == TT_OK && rep.edges_measured == 2 && rep.samples > 0,
          "row of three quads: expected TT_OK with 2 edges measured, got %d, %d edges (%s)", r, rep.edges_measured,
          err.message);
    CHECK(near(rep.seam, 100.0 / 255.0, 1e-4) && near(rep.same_face, 0.0, 1e-6),
          "seam across sRGB 100 | 200: expected %.5f as displayed (linear light would give %.5f), got seam %.5f, "
          "same face %.5f", 100.0 / 255.0, (double)(tt_srgb_to_linear(200.0f / 255.0f) - tt_srgb_to_linear(100.0f / 255.0f)),
          rep.seam, rep.same_face);
    tt_image_free(atlas);
    tt_mesh_free(mesh);
}

static void expect_not_measured(const tt_mesh *mesh, const float *uv, const tt_image *atlas, const char *what)
{
    tt_seam_report rep;
    tt_error err;
    tt_result r;
    memset(&rep, 0x55, sizeof rep);
    memset(&err, 0, sizeof err);
    r = tt_measure_seams(mesh, uv, atlas, NULL, NULL, &rep, &err);
    CHECK(r == TT_ERROR_NOT_MEASURED && err.result == r && err.message[0] && isnan(rep.score) &&
              rep.edges_measured == 0 && rep.samples == 0 && rep.seam == 0.0 && rep.same_face == 0.0 &&
              rep.unrelated == 0.0,
          "%s: expected TT_ERROR_NOT_MEASURED (%d) with score NaN and an empty report, got %d, score %g, %d edges, "
          "%lld samples, seam %g (\"%s\")", what, TT_ERROR_NOT_MEASURED, r, rep.score, rep.edges_measured,
          rep.samples, rep.seam, err.message);
}

/* Not measured reads as not measured: nothing to sample gives
   TT_ERROR_NOT_MEASURED and a NaN score, never a score of 0 (which would
   read as "seamless"). */
static void test_seams_not_measured(void)
{
    tmesh m;
    tt_mesh *quad = NULL, *pair = NULL, *torus = NULL;
    tt_image *atlas = NULL;
    tt_error err;
    float *uv;
    int c;
    make_value_noise(&atlas, 64, 64, 3);
    memset(&m, 0, sizeof m);
    make_grid(&m, 1, 1);
    CHECK(build(&m, 0, &quad, &err) == TT_OK, "one quad build");
    tm_free(&m);
    make_grid(&m, 2, 1);
    CHECK(build(&m, 0, &pair, &err) == TT_OK, "two quads build");
    tm_free(&m);
    make_torus(&m, 8, 6, 3, 1);
    CHECK(build(&m, 0, &torus, &err) == TT_OK, "torus build");
    tm_free(&m);
    if (!quad || !pair || !torus || !atlas) {
        tt_mesh_free(quad); tt_mesh_free(pair); tt_mesh_free(torus); tt_image_free(atlas);
        return;
    }
    uv = (float *)malloc(sizeof(float) * 2 * (size_t)torus->ncorners);
    for (c = 0; c < 2 * torus->ncorners; c++) uv[c] = (float)lcg_unit();
    expect_not_measured(quad, uv, atlas, "one quad (no interior edge)");
    expect_not_measured(pair, uv, atlas, "two quads (one interior edge: no unrelated edge to compare with)");
    for (c = 0; c < 2 * torus->ncorners; c++) uv[c] = (float)internal_not_a_number();
    expect_not_measured(torus, uv, atlas, "torus with all-NaN UVs");
    for (c = 0; c < 2 * torus->ncorners; c++) uv[c] = internal_infinity();
    expect_not_measured(torus, uv, atlas, "torus with all-infinite UVs");
    for (c = 0; c < 2 * torus->ncorners; c++) uv[c] = 0.25f;
    expect_not_measured(torus, uv, atlas, "torus with every UV at one point (zero-length edges)");
    {
        /* the control: the same torus with real UVs is measured */
        tt_seam_report rep;
        tt_result r;
        for (c = 0; c < 2 * torus->ncorners; c++) uv[c] = (float)lcg_unit();
        r = tt_measure_seams(torus, uv, atlas, NULL, NULL, &rep, &err);
        CHECK(r == TT_OK && rep.edges_measured > 0 && !isnan(rep.seam),
              "torus with random finite UVs should be measured: %d, %d edges", r, rep.edges_measured);
    }
    free(uv);
    tt_mesh_free(quad);
    tt_mesh_free(pair);
    tt_mesh_free(torus);
    tt_image_free(atlas);
}

/* max_edges: a random subset of edges estimates the full score. */
static void test_seams_sampled(void)
{
    seam_fixture fx;
    tt_error err;
    tt_seam_options so;
    tt_seam_report full, part, again;
    tt_result r;
    int pass, interior;
    if (!seam_fixture_make(&fx, 48, 32, 128, 17, 1, 2, "sampled")) return;
    interior = 2 * fx.mesh->nfaces;
    /* pass 0: the real assignment (score near 0), 200 edges; pass 1: random
       tiles per face (a high score, and edges that differ a lot from each
       other: half match by type, half do not), so a larger subset for the
       same tolerance: 1000 edges. */
    for (pass = 0; pass < 2; pass++) {
        const char *what = pass ? "random tiles" : "real assignment";
        const int subset = pass ? 1000 : 200;
        const double tolerance = pass ? 0.06 : 0.05;
        if (pass == 0) tt_assign_boundaries(fx.mesh, &fx.layout, 6, NULL, fx.types, NULL);
        else random_face_types(fx.mesh, 1, 99, fx.types);
        tt_assign_uvs(fx.mesh, &fx.layout, fx.types, fx.uv, NULL);
        memset(&so, 0, sizeof so);
        so.seed = 5;
        r = tt_measure_seams(fx.mesh, fx.uv, &fx.set->levels[0], &so, NULL, &full, &err);
        CHECK(r == TT_OK && full.edges_measured == interior, "%s, all edges: %d, %d of %d edges", what, r,
              full.edges_measured, interior);
        so.max_edges = subset;
        r = tt_measure_seams(fx.mesh, fx.uv, &fx.set->levels[0], &so, NULL, &part, &err);
        CHECK(r == TT_OK && part.edges_measured == subset && part.samples < full.samples && part.samples > 0,
              "%s, max_edges %d: %d, %d edges measured, %lld samples (full: %lld)", what, subset, r,
              part.edges_measured, part.samples, full.samples);
        CHECK(near(part.score, full.score, tolerance),
              "%s: max_edges %d scores %.4f, all %d edges %.4f (want within %g)", what, subset, part.score, interior,
              full.score, tolerance);
        tt_measure_seams(fx.mesh, fx.uv, &fx.set->levels[0], &so, NULL, &again, NULL);
        CHECK(again.score == part.score && again.samples == part.samples,
              "%s, max_edges %d: the same seed should give the same estimate", what, subset);
        if (pass == 1)
            CHECK(full.score > 0.15 && part.score > 0.15,
                  "random tiles (n = 1): full score %.4f and estimate %.4f should be clearly above 0", full.score,
                  part.score);
        /* max_edges at or above the number of edges measures them all */
        so.max_edges = interior;
        r = tt_measure_seams(fx.mesh, fx.uv, &fx.set->levels[0], &so, NULL, &part, &err);
        CHECK(r == TT_OK && part.edges_measured == interior && part.samples == full.samples,
              "%s, max_edges = all %d edges: %d, %d edges, %lld samples (full %lld)", what, interior, r,
              part.edges_measured, part.samples, full.samples);
    }
    so.max_edges = -1;
    r = tt_measure_seams(fx.mesh, fx.uv, &fx.set->levels[0], &so, NULL, &part, &err);
    CHECK(r == TT_ERROR_INVALID_ARGUMENT && err.result == r && err.message[0] && isnan(part.score),
          "max_edges -1: expected TT_ERROR_INVALID_ARGUMENT (score NaN), got %d score %g", r, part.score);
    seam_fixture_free(&fx);
}

typedef struct seams_ctx {
    const tt_mesh *mesh;
    const float *uv;
    const tt_image *atlas;
    const tt_seam_options *options;
} seams_ctx;

static tt_result oom_seams(void *ctx, const tt_allocator *al, tt_error *error)
{
    seams_ctx *s = (seams_ctx *)ctx;
    tt_seam_report rep;
    tt_result r = tt_measure_seams(s->mesh, s->uv, s->atlas, s->options, al, &rep, error);
    if (r != TT_OK && (error->result != r || !isnan(rep.score))) return TT_RESULT_MAX_ENUM;
    return r;
}

static void test_seams_oom(void)
{
    tmesh m;
    tt_mesh *mesh = NULL;
    tt_error err;
    tt_image *atlas = NULL;
    tt_tile_layout l = make_layout(1, 12, 2);
    uint8_t types[4 * 48];
    float uv[8 * 48];
    seams_ctx s;
    make_value_noise(&atlas, 64, 64, 4);
    memset(&m, 0, sizeof m);
    make_torus(&m, 8, 6, 3, 1);
    if (build(&m, 0, &mesh, &err) != TT_OK || !atlas) {
        CHECK(0, "seams OOM setup");
        tm_free(&m);
        tt_image_free(atlas);
        tt_mesh_free(mesh);
        return;
    }
    tm_free(&m);
    tt_assign_boundaries(mesh, &l, 1, NULL, types, NULL);
    tt_assign_uvs(mesh, &l, types, uv, NULL);
    s.mesh = mesh;
    s.uv = uv;
    s.atlas = atlas;
    s.options = NULL;
    oom_reset();
    oom_sweep("tt_measure_seams", oom_seams, &s, TT_OK);
    /* with an edge list (one more allocation) */
    {
        int edges[2] = {0, 5};
        tt_seam_options listed;
        memset(&listed, 0, sizeof listed);
        listed.edges = edges;
        listed.nedges = 2;
        s.options = &listed;
        oom_reset();
        oom_sweep("tt_measure_seams with an edge list", oom_seams, &s, TT_OK);
    }
    tt_image_free(atlas);
    tt_mesh_free(mesh);
}

/* Two charts on one open grid of 16 x 8 unit quads: corner UVs (0.05 + x/32,
   0.1 + y/32), each quad 4 x 4 texels of a 128 x 128 atlas, with the right
   half's faces (column 8 on) shifted by `shift` in u. The 8 edges on the
   line x = 8 are then the only UV-discontinuous ones (when shift != 0). */
static float *two_chart_uvs(const tt_mesh *mesh, float shift)
{
    float *uv = (float *)malloc(sizeof(float) * 2 * (size_t)mesh->ncorners);
    int f, k;
    if (!uv) return NULL;
    for (f = 0; f < mesh->nfaces; f++)
        for (k = mesh->face_start[f]; k < mesh->face_start[f + 1]; k++) {
            const float *p = mesh->pos + 3 * mesh->corner_vert[k];
            uv[2 * k] = 0.05f + p[0] / 32.0f + (f % 16 >= 8 ? shift : 0.0f);
            uv[2 * k + 1] = 0.1f + p[1] / 32.0f;
        }
    return uv;
}

static tt_mesh *two_chart_grid(void)
{
    tmesh m;
    tt_mesh *mesh = NULL;
    tt_error err;
    tt_result r;
    memset(&m, 0, sizeof m);
    make_grid(&m, 16, 8);
    r = build(&m, 0, &mesh, &err);
    tm_free(&m);
    CHECK(r == TT_OK, "16 x 8 grid build: %d", r);
    return mesh;
}

/* TT_SEAM_UV_DISCONTINUOUS: measured on the chart border alone, a shifted
   chart scores like unrelated places (about 1); measured on every edge the
   same border is diluted by the 224 continuous edges inside the charts. */
static void test_seams_discontinuous(void)
{
    tt_mesh *mesh = two_chart_grid();
    tt_image *atlas = NULL;
    float *uv = NULL;
    tt_seam_options so;
    tt_seam_report all, border, sampled;
    tt_error err;
    tt_result r;
    make_value_noise(&atlas, 128, 128, 7);
    if (mesh) uv = two_chart_uvs(mesh, 0.4f);
    if (!mesh || !atlas || !uv) {
        CHECK(0, "two-chart setup");
        goto done;
    }
    memset(&so, 0, sizeof so);
    so.seed = 3;
    r = tt_measure_seams(mesh, uv, atlas, &so, NULL, &all, &err);
    CHECK(r == TT_OK && all.edges_discontinuous == 8 && all.edges_measured == 232,
          "two charts, every edge: %d, %d discontinuous edges (want 8), %d measured (want 232) (%s)", r,
          all.edges_discontinuous, all.edges_measured, err.message);
    so.flags = TT_SEAM_UV_DISCONTINUOUS;
    r = tt_measure_seams(mesh, uv, atlas, &so, NULL, &border, &err);
    CHECK(r == TT_OK && border.edges_discontinuous == 8 && border.edges_measured == 8,
          "two charts, border only: %d, %d discontinuous, %d measured (want 8 and 8) (%s)", r,
          border.edges_discontinuous, border.edges_measured, err.message);
    CHECK(border.score >= 0.8 && all.score < 0.2 && all.score < border.score - 0.6,
          "a shifted chart: border-only score %.4f (want >= 0.8), every edge %.4f (want < 0.2: diluted)",
          border.score, all.score);
    /* max_edges samples within the border */
    so.max_edges = 3;
    r = tt_measure_seams(mesh, uv, atlas, &so, NULL, &sampled, &err);
    CHECK(r == TT_OK && sampled.edges_measured == 3 && sampled.edges_discontinuous == 8 && sampled.score > 0.5,
          "border only, max_edges 3: %d, %d measured (want 3), %d discontinuous, score %.4f", r,
          sampled.edges_measured, sampled.edges_discontinuous, sampled.score);
    /* one chart: nothing to measure in restricted mode; every edge still is */
    free(uv);
    uv = two_chart_uvs(mesh, 0.0f);
    if (!uv) goto done;
    so.max_edges = 0;
    memset(&border, 0x55, sizeof border);
    memset(&err, 0, sizeof err);
    r = tt_measure_seams(mesh, uv, atlas, &so, NULL, &border, &err);
    CHECK(r == TT_ERROR_NOT_MEASURED && err.result == r && strstr(err.message, "discontinuous") &&
              isnan(border.score) && border.edges_discontinuous == 0 && border.edges_measured == 0 &&
              border.samples == 0 && border.seam == 0.0 && border.same_face == 0.0 && border.unrelated == 0.0,
          "one chart, border only: expected TT_ERROR_NOT_MEASURED with an empty report, got %d, score %g, %d "
          "discontinuous, %d measured (\"%s\")", r, border.score, border.edges_discontinuous, border.edges_measured,
          err.message);
    so.flags = 0;
    r = tt_measure_seams(mesh, uv, atlas, &so, NULL, &all, &err);
    CHECK(r == TT_OK && all.edges_discontinuous == 0 && all.edges_measured == 232 && fabs(all.score) < 0.1,
          "one chart, every edge: %d, %d discontinuous, %d measured, score %.4f (want about 0)", r,
          all.edges_discontinuous, all.edges_measured, all.score);
    /* a difference below the tolerance is continuous, one above it is not */
    {
        int c = 0, twin_next;
        while (mesh->twin[c] < 0) c++;
        twin_next = tt_mesh_next(mesh, mesh->twin[c]);
        uv[2 * twin_next] += 1e-8f;
        r = tt_measure_seams(mesh, uv, atlas, &so, NULL, &all, &err);
        CHECK(r == TT_OK && all.edges_discontinuous == 0, "a UV 1e-8 away: %d discontinuous edges (want 0)",
              all.edges_discontinuous);
        uv[2 * twin_next] += 1e-4f;
        r = tt_measure_seams(mesh, uv, atlas, &so, NULL, &all, &err);
        CHECK(r == TT_OK && all.edges_discontinuous >= 1 && all.edges_discontinuous <= 2,
              "a UV 1e-4 away: %d discontinuous edges (want the one or two edges at that corner)",
              all.edges_discontinuous);
    }
    /* unknown flag bits are refused */
    so.flags = 1u << 7;
    r = tt_measure_seams(mesh, uv, atlas, &so, NULL, &all, &err);
    CHECK(r == TT_ERROR_INVALID_ARGUMENT && err.result == r && err.message[0] && isnan(all.score),
          "unknown seam flag 0x80: expected TT_ERROR_INVALID_ARGUMENT, got %d (\"%s\")", r, err.message);
done:
    free(uv);
    tt_image_free(atlas);
    tt_mesh_free(mesh);
}

static int same_seam_report(const tt_seam_report *a, const tt_seam_report *b)
{
    return a->seam == b->seam && a->same_face == b->same_face && a->unrelated == b->unrelated &&
           a->edges_measured == b->edges_measured && a->samples == b->samples &&
           a->edges_discontinuous == b->edges_discontinuous;
}

/* An edge list (tt_seam_options.edges) measures just those edges: listing
   every interior edge, by either corner, is the full measure; listing the
   chart border is the TT_SEAM_UV_DISCONTINUOUS measure; the edges inside one
   chart score about 0 where the border scores about 1. Lists that name
   nothing measurable or no edge at all are refused. */
static void test_seams_edge_list(void)
{
    tt_mesh *mesh = two_chart_grid();
    tt_image *atlas = NULL;
    float *uv = NULL;
    int *list = NULL, nlist, c, boundary = -1;
    tt_seam_options so;
    tt_seam_report expected, got;
    tt_error err;
    tt_result r;
    make_value_noise(&atlas, 128, 128, 7);
    if (mesh) {
        uv = two_chart_uvs(mesh, 0.4f);
        list = (int *)malloc((size_t)mesh->ncorners * sizeof(int));
    }
    if (!mesh || !atlas || !uv || !list) {
        CHECK(0, "edge-list setup");
        goto done;
    }
    memset(&so, 0, sizeof so);
    so.seed = 5;
    r = tt_measure_seams(mesh, uv, atlas, &so, NULL, &expected, &err);
    /* every interior edge, named by its higher corner (the library visits the lower) */
    for (nlist = 0, c = 0; c < mesh->ncorners; c++)
        if (mesh->twin[c] >= 0 && mesh->twin[c] < c) list[nlist++] = c;
    so.edges = list;
    so.nedges = nlist;
    r = tt_measure_seams(mesh, uv, atlas, &so, NULL, &got, &err);
    CHECK(r == TT_OK && nlist == 232 && same_seam_report(&expected, &got),
          "every edge listed by its other corner: %d, %d listed, score %.6f against %.6f unlisted (%s)", r, nlist,
          got.score, expected.score, err.message);
    /* the chart border, found here by comparing the corners' UVs */
    so.edges = NULL;
    so.nedges = 0;
    so.flags = TT_SEAM_UV_DISCONTINUOUS;
    r = tt_measure_seams(mesh, uv, atlas, &so, NULL, &expected, &err);
    for (nlist = 0, c = 0; c < mesh->ncorners; c++) {
        int t = mesh->twin[c], a_end, b_end;
        if (t < c) continue;
        a_end = tt_mesh_next(mesh, c);
        b_end = tt_mesh_next(mesh, t);
        if (uv[2 * c] != uv[2 * b_end] || uv[2 * c + 1] != uv[2 * b_end + 1] || uv[2 * a_end] != uv[2 * t] ||
            uv[2 * a_end + 1] != uv[2 * t + 1])
            list[nlist++] = c;
    }
    so.flags = 0;
    so.edges = list;
    so.nedges = nlist;
    r = tt_measure_seams(mesh, uv, atlas, &so, NULL, &got, &err);
    CHECK(r == TT_OK && nlist == 8 && same_seam_report(&expected, &got) && got.score >= 0.8,
          "the border listed: %d, %d listed (want 8), score %.4f against %.4f for TT_SEAM_UV_DISCONTINUOUS (%s)", r,
          nlist, got.score, expected.score, err.message);
    /* the border listed twice and in both directions measures the same edges */
    for (c = 0; c < 8; c++) list[8 + c] = mesh->twin[list[c]];
    so.nedges = 16;
    r = tt_measure_seams(mesh, uv, atlas, &so, NULL, &got, &err);
    CHECK(r == TT_OK && same_seam_report(&expected, &got), "the border listed twice: %d, %d edges measured", r,
          got.edges_measured);
    /* the edges inside the charts: continuous, about 0 */
    for (nlist = 0, c = 0; c < mesh->ncorners; c++) {
        int k, on_border = 0;
        if (mesh->twin[c] < c) continue;
        for (k = 0; k < 8; k++) on_border |= list[k] == c;
        if (!on_border) list[8 + nlist++] = c;
    }
    so.edges = list + 8;
    so.nedges = nlist;
    r = tt_measure_seams(mesh, uv, atlas, &so, NULL, &got, &err);
    CHECK(r == TT_OK && got.edges_measured == 224 && fabs(got.score) < 0.15,
          "the 224 edges inside the charts: %d, %d measured, score %.4f (want about 0)", r, got.edges_measured,
          got.score);
    /* listed, but none discontinuous: nothing to measure */
    so.flags = TT_SEAM_UV_DISCONTINUOUS;
    r = tt_measure_seams(mesh, uv, atlas, &so, NULL, &got, &err);
    CHECK(r == TT_ERROR_NOT_MEASURED && isnan(got.score) && strstr(err.message, "listed"),
          "inside edges, discontinuous only: expected TT_ERROR_NOT_MEASURED, got %d (\"%s\")", r, err.message);
    so.flags = 0;
    so.nedges = 0;
    r = tt_measure_seams(mesh, uv, atlas, &so, NULL, &got, &err);
    CHECK(r == TT_ERROR_NOT_MEASURED && isnan(got.score), "an empty list: expected TT_ERROR_NOT_MEASURED, got %d", r);
    /* bad lists */
    so.nedges = -1;
    r = tt_measure_seams(mesh, uv, atlas, &so, NULL, &got, &err);
    CHECK(r == TT_ERROR_INVALID_ARGUMENT, "nedges -1: expected TT_ERROR_INVALID_ARGUMENT, got %d", r);
    so.edges = NULL;
    so.nedges = 3;
    r = tt_measure_seams(mesh, uv, atlas, &so, NULL, &got, &err);
    CHECK(r == TT_ERROR_INVALID_ARGUMENT, "no list but nedges 3: expected TT_ERROR_INVALID_ARGUMENT, got %d", r);
    for (c = 0; mesh->twin[c] < 0; c++) {}
    list[0] = c;
    list[1] = mesh->ncorners;
    so.edges = list;
    so.nedges = 2;
    r = tt_measure_seams(mesh, uv, atlas, &so, NULL, &got, &err);
    CHECK(r == TT_ERROR_INDEX_OUT_OF_RANGE && err.item == 1,
          "a listed corner past the end: expected TT_ERROR_INDEX_OUT_OF_RANGE at item 1, got %d at %d", r, err.item);
    for (c = 0; c < mesh->ncorners && boundary < 0; c++)
        if (mesh->twin[c] < 0) boundary = c;
    list[1] = boundary;
    r = tt_measure_seams(mesh, uv, atlas, &so, NULL, &got, &err);
    CHECK(r == TT_ERROR_INVALID_ARGUMENT && err.item == 1 && strstr(err.message, "boundary"),
          "a listed boundary edge: expected TT_ERROR_INVALID_ARGUMENT at item 1, got %d at %d (\"%s\")", r, err.item,
          err.message);
done:
    free(list);
    free(uv);
    tt_image_free(atlas);
    tt_mesh_free(mesh);
}

/* The seam measure through an executor (reverse order, two threads): the
   serial report, bit for bit, on a mesh with several ranges of edges and
   of corners, measuring every edge, then only the discontinuous ones
   (some faces' UVs shifted apart from their neighbours'). */
static void test_seams_executor_identical(void)
{
    tmesh m;
    tt_mesh *mesh = NULL;
    tt_image *atlas = NULL;
    float *uv = NULL;
    int c;
    memset(&m, 0, sizeof m);
    make_grid(&m, 100, 100);
    make_value_noise(&atlas, 128, 128, 11);
    if (build(&m, 0, &mesh, NULL) == TT_OK && atlas) uv = (float *)malloc(sizeof(float) * 2 * (size_t)mesh->ncorners);
    if (uv) {
        tt_seam_options so;
        tt_seam_report serial, got;
        tt_result r0, r1, r2;
        int mode;
        for (mode = 0; mode < 2; mode++) {
            for (c = 0; c < mesh->ncorners; c++) {
                const float *p = mesh->pos + 3 * mesh->corner_vert[c];
                const float shift = mode && (mesh->corner_face[c] / 7) % 3 == 0 ? 0.01f : 0.0f;
                uv[2 * c] = p[0] / 100.0f * 0.9f + 0.04f + shift;
                uv[2 * c + 1] = p[1] / 100.0f * 0.9f + 0.04f;
            }
            memset(&so, 0, sizeof so);
            so.seed = 5;
            so.flags = mode ? TT_SEAM_UV_DISCONTINUOUS : 0;
            r0 = tt_measure_seams(mesh, uv, atlas, &so, NULL, &serial, NULL);
            CHECK(mesh->ncorners > 2 * 16384 &&
                      (mode ? serial.edges_discontinuous > 1000 : serial.edges_discontinuous == 0),
                  "%d corners, %d discontinuous edges", mesh->ncorners, serial.edges_discontinuous);
            so.executor = &g_reverse_executor;
            r1 = tt_measure_seams(mesh, uv, atlas, &so, NULL, &got, NULL);
            CHECK(r0 == TT_OK && serial.edges_measured > 2 * 512 && r1 == TT_OK &&
                      memcmp(&serial, &got, sizeof serial) == 0,
                  "reverse-order executor: %d/%d, %d edges, score %.17g against %.17g", r0, r1, serial.edges_measured,
                  got.score, serial.score);
            so.executor = &g_thread_executor;
            r2 = tt_measure_seams(mesh, uv, atlas, &so, NULL, &got, NULL);
            CHECK(r2 == TT_OK && memcmp(&serial, &got, sizeof serial) == 0,
                  "two-thread executor: %d, score %.17g against %.17g", r2, got.score, serial.score);
        }
    }
    CHECK(uv != NULL, "setup");
    free(uv);
    tt_image_free(atlas);
    tt_mesh_free(mesh);
    tm_free(&m);
}

/* flags 0 is the measure as it was before the flags existed: the reports of
   the two-chart case, taken with the library before this change (and again
   when the edges came to be measured in ranges with a random stream each,
   which moved every figure by sampling noise only). */
static void test_seams_flags_zero_unchanged(void)
{
    static const struct {
        int max_edges;
        double seam, same_face, unrelated, score;
        int edges_measured;
        long long samples;
    } before[2] = {
        {100, 0.0052319205900033319, 0.0044669354607661639, 0.018077256917953508, 0.056206249914339403, 100, 4000},
        {0, 0.0049908375260473616, 0.0045118926091722925, 0.018731507741574789, 0.03368198874691683, 232, 3944}};
    tt_mesh *mesh = two_chart_grid();
    tt_image *atlas = NULL;
    float *uv = NULL;
    int i;
    make_value_noise(&atlas, 128, 128, 7);
    if (mesh) uv = two_chart_uvs(mesh, 0.4f);
    for (i = 0; i < 2 && mesh && atlas && uv; i++) {
        tt_seam_options so;
        tt_seam_report rep;
        tt_error err;
        tt_result r;
        memset(&so, 0, sizeof so);
        so.seed = 3;
        so.max_edges = before[i].max_edges;
        r = tt_measure_seams(mesh, uv, atlas, &so, NULL, &rep, &err);
        CHECK(r == TT_OK && rep.edges_measured == before[i].edges_measured && rep.samples == before[i].samples &&
                  near(rep.seam, before[i].seam, 1e-12) && near(rep.same_face, before[i].same_face, 1e-12) &&
                  near(rep.unrelated, before[i].unrelated, 1e-12) && near(rep.score, before[i].score, 1e-9),
              "flags 0, max_edges %d: %d, seam %.17g same %.17g unrelated %.17g score %.17g, %d edges, %lld "
              "samples; before: %.17g %.17g %.17g %.17g, %d, %lld", before[i].max_edges, r, rep.seam,
              rep.same_face, rep.unrelated, rep.score, rep.edges_measured, rep.samples, before[i].seam,
              before[i].same_face, before[i].unrelated, before[i].score, before[i].edges_measured,
              before[i].samples);
    }
    CHECK(mesh && atlas && uv, "flags 0 setup");
    free(uv);
    tt_image_free(atlas);
    tt_mesh_free(mesh);
}

/* A periodic atlas: a sum of waves with whole numbers of periods across the
   64 x 64 image, so that TT_WRAP_REPEAT sampling is continuous everywhere. */
static tt_image *make_periodic_waves(void)
{
    tt_image *im = NULL;
    int x, y;
    if (tt_image_create(64, 64, NULL, &im, NULL) != TT_OK) return NULL;
    for (y = 0; y < 64; y++)
        for (x = 0; x < 64; x++) {
            double s = (x + 0.5) / 64.0 * 6.283185307179586, t = (y + 0.5) / 64.0 * 6.283185307179586;
            double a = 0.5 + 0.18 * sin(3 * s + 0.7) + 0.12 * sin(2 * s + 5 * t + 1.9) + 0.1 * sin(7 * t - 4 * s);
            px(im, x, y)[0] = (float)a;
            px(im, x, y)[1] = (float)(1.0 - a);
            px(im, x, y)[2] = (float)(0.5 + 0.3 * sin(4 * t + 1.0));
            px(im, x, y)[3] = 1.0f;
        }
    return im;
}

/* TT_SEAM_WRAP: the right chart shifted by a whole period (u + 1) continues
   the left one on a periodic atlas; clamped sampling breaks it. */
static void test_seams_wrap(void)
{
    tt_mesh *mesh = two_chart_grid();
    tt_image *atlas = make_periodic_waves();
    float *uv = NULL;
    tt_seam_options so;
    tt_seam_report wrapped, clamped, crossing;
    tt_error err;
    tt_result r;
    int c;
    if (mesh) uv = two_chart_uvs(mesh, 1.0f);
    if (!mesh || !atlas || !uv) {
        CHECK(0, "wrap setup");
        goto done;
    }
    memset(&so, 0, sizeof so);
    so.seed = 9;
    so.flags = TT_SEAM_UV_DISCONTINUOUS | TT_SEAM_WRAP;
    r = tt_measure_seams(mesh, uv, atlas, &so, NULL, &wrapped, &err);
    CHECK(r == TT_OK && wrapped.edges_discontinuous == 8 && wrapped.edges_measured == 8 &&
              fabs(wrapped.score) < 0.15,
          "a chart one period over, wrapped: %d, %d discontinuous (want 8), score %.4f (want about 0; seam %.4f, "
          "same face %.4f, unrelated %.4f)", r, wrapped.edges_discontinuous, wrapped.score, wrapped.seam,
          wrapped.same_face, wrapped.unrelated);
    so.flags = TT_SEAM_UV_DISCONTINUOUS;
    r = tt_measure_seams(mesh, uv, atlas, &so, NULL, &clamped, &err);
    CHECK(r == TT_OK && clamped.score > 0.3 && clamped.score > wrapped.score + 0.3,
          "a chart one period over, clamped: %d, score %.4f (want > 0.3: the clamp breaks it; wrapped %.4f)", r,
          clamped.score, wrapped.score);
    /* one continuous chart whose UVs cross the image's border (u in 0.75 ..
       1.25): continuous when wrapped */
    for (c = 0; c < mesh->ncorners; c++) {
        const float *p = mesh->pos + 3 * mesh->corner_vert[c];
        uv[2 * c] = 0.75f + p[0] / 32.0f;
    }
    so.flags = TT_SEAM_WRAP;
    r = tt_measure_seams(mesh, uv, atlas, &so, NULL, &crossing, &err);
    CHECK(r == TT_OK && crossing.edges_discontinuous == 0 && fabs(crossing.score) < 0.1,
          "one chart across the border, wrapped: %d, %d discontinuous, score %.4f (want about 0)", r,
          crossing.edges_discontinuous, crossing.score);
done:
    free(uv);
    tt_image_free(atlas);
    tt_mesh_free(mesh);
}

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
    tt_assign_boundaries(mesh, &l, 2025, NULL, types, NULL);
    for (t = 0; t < ntiles; t++) counts[t] = -7;   /* the histogram must overwrite, not add */
    r = tt_tile_histogram(mesh, &l, types, counts, &err);
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
    memset(&err, 0, sizeof err);
    r = tt_tile_histogram(mesh, &l, types, counts, &err);
    CHECK(r == TT_ERROR_INDEX_OUT_OF_RANGE && err.result == r && err.corner == 5 && err.face == 1 &&
              msg_has_number(err.message, 5),
          "histogram: type %d at corner 5: expected TT_ERROR_INDEX_OUT_OF_RANGE naming corner 5 (face 1), got %d "
          "corner %d face %d \"%s\"", 2 * n, r, err.corner, err.face, err.message);
    CHECK(tt_tile_histogram(NULL, &l, types, counts, &err) == TT_ERROR_INVALID_ARGUMENT, "histogram: mesh NULL");
    CHECK(tt_tile_histogram(mesh, NULL, types, counts, &err) == TT_ERROR_INVALID_ARGUMENT, "histogram: layout NULL");
    CHECK(tt_tile_histogram(mesh, &l, NULL, counts, &err) == TT_ERROR_INVALID_ARGUMENT, "histogram: types NULL");
    CHECK(tt_tile_histogram(mesh, &l, types, NULL, &err) == TT_ERROR_INVALID_ARGUMENT, "histogram: counts NULL");
    {
        tt_tile_layout bad = make_layout(1000, 16, 2);
        r = tt_tile_histogram(mesh, &bad, types, counts, &err);
        CHECK(r == TT_ERROR_INVALID_ARGUMENT, "histogram with 1000 colors: expected TT_ERROR_INVALID_ARGUMENT, got %d",
              r);
    }
    free(types);
    free(counts);
    tt_mesh_free(mesh);
}

static void test_histogram(void)
{
    check_histogram(200, 1, 0.20);
    check_histogram(400, 2, 0.25);
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
        tt_assign_boundaries(mesh, &l, 1, NULL, types, NULL);
        tt_assign_uvs(mesh, &l, types, uv, &err);
        CHECK(tt_face_stretch(mesh, uv, st, &err) == TT_OK, "face_stretch");
        for (f = 0; f < mesh->nfaces; f++) bad += !near(st[f], 1.0, 1e-5);
        CHECK(bad == 0, "unit squares on square tiles: %d faces with stretch != 1 (face 0: %g)", bad, st[0]);
        tt_mesh_free(mesh);
    }
    /* 2:1 rectangles */
    for (f = 0; f < m.nv; f++) m.pos[3 * f] *= 2.0f;
    r = build(&m, 0, &mesh, &err);
    if (r == TT_OK) {
        tt_assign_boundaries(mesh, &l, 1, NULL, types, NULL);
        tt_assign_uvs(mesh, &l, types, uv, &err);
        CHECK(tt_face_stretch(mesh, uv, st, &err) == TT_OK, "face_stretch");
        bad = 0;
        for (f = 0; f < mesh->nfaces; f++) bad += !near(st[f], 2.0, 1e-5);
        CHECK(bad == 0, "2:1 rectangles on square tiles: %d faces with stretch != 2 (face 0: %g)", bad, st[0]);
        /* a non-finite UV is refused, naming its corner and face */
        {
            static const int corners[3] = {9, 0, 23};
            int i;
            for (i = 0; i < 3; i++) {
                int c = corners[i], k = i == 1 ? 0 : 1;
                float keep = uv[2 * c + k];
                uv[2 * c + k] = i == 2 ? -internal_infinity() : (float)internal_not_a_number();
                memset(&err, 0, sizeof err);
                r = tt_face_stretch(mesh, uv, st, &err);
                CHECK(r == TT_ERROR_NON_FINITE && err.result == r && err.corner == c && err.face == c / 4 &&
                          msg_has_number(err.message, c),
                      "%s in the UV of corner %d: expected TT_ERROR_NON_FINITE naming corner %d (face %d), got %d "
                      "corner %d face %d \"%s\"", i == 2 ? "-inf" : "NaN", c, c, c / 4, r, err.corner, err.face,
                      err.message);
                uv[2 * c + k] = keep;
            }
        }
        /* a face whose UVs collapse is infinitely stretched */
        for (f = 0; f < 4; f++) { uv[2 * f] = 0.5f; uv[2 * f + 1] = 0.5f; }
        tt_face_stretch(mesh, uv, st, NULL);
        CHECK(isinf(st[0]) && st[0] > 0, "collapsed UVs: stretch expected +inf, got %g", st[0]);
        CHECK(tt_face_stretch(NULL, uv, st, &err) == TT_ERROR_INVALID_ARGUMENT, "face_stretch mesh NULL");
        CHECK(tt_face_stretch(mesh, NULL, st, &err) == TT_ERROR_INVALID_ARGUMENT, "face_stretch uv NULL");
        CHECK(tt_face_stretch(mesh, uv, NULL, &err) == TT_ERROR_INVALID_ARGUMENT, "face_stretch stretch NULL");
        tt_mesh_free(mesh);
    }
    tm_free(&m);
    /* a right triangle with legs 1 and 3 mapped to legs of equal length: 3 */
    tm_vert(&m, 0, 0, 0); tm_vert(&m, 1, 0, 0); tm_vert(&m, 0, 3, 0);
    tm_tri(&m, 0, 1, 2);
    r = build(&m, 0, &mesh, &err);
    if (r == TT_OK) {
        float tuv[6] = {0, 0, 0.1f, 0, 0, 0.1f};
        CHECK(tt_face_stretch(mesh, tuv, st, &err) == TT_OK, "face_stretch on a triangle");
        CHECK(near(st[0], 3.0, 1e-4), "triangle 1 x 3 on a 1 x 1 UV triangle: stretch expected 3, got %g", st[0]);
        tt_mesh_free(mesh);
    }
    tm_free(&m);
}

/* ---- UV distortion ---- */

/* An open grid of nx x ny unit squares in the plane z = 0, each cut into two
   counter-clockwise triangles. */
static tt_mesh *triangle_grid(int nx, int ny)
{
    tmesh m;
    tt_mesh *mesh = NULL;
    tt_error err;
    tt_result r;
    int i, j;
    memset(&m, 0, sizeof m);
    for (j = 0; j <= ny; j++)
        for (i = 0; i <= nx; i++) tm_vert(&m, i, j, 0);
    for (j = 0; j < ny; j++)
        for (i = 0; i < nx; i++) {
            int a = j * (nx + 1) + i, b = a + 1, c = a + nx + 2, d = a + nx + 1;
            tm_tri(&m, a, b, c);
            tm_tri(&m, a, c, d);
        }
    r = build(&m, 0, &mesh, &err);
    tm_free(&m);
    CHECK(r == TT_OK, "triangle grid build: %d", r);
    return mesh;
}

/* UV of every corner: its vertex's (x, y) times (sx, sy) texels per unit,
   plus (ox, oy) texels, in a width x height image. */
static void linear_uvs(const tt_mesh *mesh, double sx, double sy, double ox, double oy, int width, int height,
                       float *uv)
{
    int c;
    for (c = 0; c < mesh->ncorners; c++) {
        const float *p = mesh->pos + 3 * (size_t)mesh->corner_vert[c];
        uv[2 * c] = (float)((p[0] * sx + ox) / width);
        uv[2 * c + 1] = (float)((p[1] * sy + oy) / height);
    }
}

static tt_result distortion(const tt_mesh *mesh, const float *uv, int width, int height, double texels_per_unit,
                            double margin, tt_uv_distortion_report *rep, tt_error *err)
{
    tt_uv_distortion_options opt;
    memset(&opt, 0, sizeof opt);
    opt.texels_per_unit = texels_per_unit;
    opt.margin_texels = margin;
    return tt_measure_uv_distortion(mesh, uv, width, height, &opt, NULL, rep, err);
}

/* Linear maps of known distortion on a non-square 256 x 128 image:
   isometric, uniformly scaled, anisotropic; triangles and quads. */
static void test_uv_distortion_maps(void)
{
    tt_mesh *tris = triangle_grid(6, 4), *quads = NULL;
    tt_uv_distortion_report rep;
    tt_error err;
    tt_result r;
    float *uv;
    tmesh m;
    if (!tris) return;
    uv = (float *)malloc(sizeof(float) * 2 * (size_t)tris->ncorners);
    if (!uv) { tt_mesh_free(tris); return; }
    /* isometric at 16 texels a unit: given or measured, the density is right */
    linear_uvs(tris, 16, 16, 10, 10, 256, 128, uv);
    r = distortion(tris, uv, 256, 128, 16, 0, &rep, &err);
    CHECK(r == TT_OK && rep.faces_measured == 48 && near(rep.stretch_median, 1, 1e-9) &&
              near(rep.stretch_p95, 1, 1e-9) && near(rep.stretch_max, 1, 1e-9) && near(rep.density_median, 0, 1e-6) &&
              near(rep.density_p95, 0, 1e-6) && rep.texels_per_unit == 16 && rep.flipped == 0 &&
              rep.degenerate == 0 && rep.non_finite == 0 && rep.outside_margin == 0,
          "isometric: %d, %d faces, stretch %g / %g / %g, density error %g / %g, %g texels a unit, flipped %d, "
          "degenerate %d (%s)", r, rep.faces_measured, rep.stretch_median, rep.stretch_p95, rep.stretch_max,
          rep.density_median, rep.density_p95, rep.texels_per_unit, rep.flipped, rep.degenerate, err.message);
    r = distortion(tris, uv, 256, 128, 0, 0, &rep, &err);
    CHECK(r == TT_OK && near(rep.texels_per_unit, 16, 1e-4) && near(rep.density_p95, 0, 1e-6) &&
              near(rep.density_spread, 1, 1e-6) && near(rep.stretch_p5, 1, 1e-9) &&
              near(rep.density_p5_over_median, 1, 1e-6) && near(rep.density_p95_over_median, 1, 1e-6),
          "isometric, scale measured: %d, %g texels a unit (want 16), density error p95 %g, spread %g (want 1)", r,
          rep.texels_per_unit, rep.density_p95, rep.density_spread);
    /* uniformly twice the intended scale: no stretch, density error exactly 1 */
    linear_uvs(tris, 32, 32, 10, 10, 256, 128, uv);
    r = distortion(tris, uv, 256, 128, 16, 0, &rep, &err);
    CHECK(r == TT_OK && near(rep.stretch_max, 1, 1e-9) && near(rep.density_median, 1, 1e-6) &&
              near(rep.density_p95, 1, 1e-6),
          "uniform scale 2: %d, stretch max %g, density error %g / %g (want 1)", r, rep.stretch_max,
          rep.density_median, rep.density_p95);
    CHECK(r == TT_OK && near(rep.density_spread, 1, 1e-6), "uniform scale 2: density spread %g (want 1)",
          rep.density_spread);
    /* 8 of the 48 equal triangles (a sixth of the area) at twice the
       density of the rest, whatever the intended scale: p95 / p5 = 2 */
    {
        int f, k, c;
        for (f = 0; f < 8; f++) {
            const int first = tris->face_start[f];
            for (c = first + 1; c < tris->face_start[f + 1]; c++)
                for (k = 0; k < 2; k++) uv[2 * c + k] = 2.0f * uv[2 * c + k] - uv[2 * first + k];
        }
        for (k = 0; k < 2; k++) {
            r = distortion(tris, uv, 256, 128, k ? 16 : 0, 0, &rep, &err);
            CHECK(r == TT_OK && near(rep.density_spread, 2, 1e-6) && near(rep.density_p5_over_median, 1, 1e-6) &&
                      near(rep.density_p95_over_median, 2, 1e-6),
                  "a sixth of the area at twice the density (texels_per_unit %d): %d, spread %g (want 2), p5 and "
                  "p95 over the median %g and %g (want 1 and 2)", k ? 16 : 0, r, rep.density_spread,
                  rep.density_p5_over_median, rep.density_p95_over_median);
        }
    }
    /* 3 : 1 in texels (u three times as fine as v): stretch exactly 3 */
    linear_uvs(tris, 48, 16, 10, 10, 256, 128, uv);
    r = distortion(tris, uv, 256, 128, 16, 0, &rep, &err);
    CHECK(r == TT_OK && near(rep.stretch_median, 3, 1e-6) && near(rep.stretch_max, 3, 1e-6) &&
              near(rep.stretch_p5, 3, 1e-6) &&
              near(rep.density_median, sqrt(3.0) - 1, 1e-6),
          "anisotropic 3 : 1: %d, stretch %g / %g (want 3), density error %g (want %g)", r, rep.stretch_median,
          rep.stretch_max, rep.density_median, sqrt(3.0) - 1);
    /* the same UVs in a square image are a different map: u in texels 256 / 128 as fine */
    r = distortion(tris, uv, 128, 128, 0, 0, &rep, &err);
    CHECK(r == TT_OK && near(rep.stretch_median, 1.5, 1e-6),
          "the 3 : 1 UVs in a 128 x 128 image: stretch %g (want 1.5)", rep.stretch_median);
    free(uv);
    tt_mesh_free(tris);
    /* quads, their map taken at the centre */
    memset(&m, 0, sizeof m);
    make_grid(&m, 5, 3);
    r = build(&m, 0, &quads, &err);
    tm_free(&m);
    if (r == TT_OK) {
        uv = (float *)malloc(sizeof(float) * 2 * (size_t)quads->ncorners);
        if (uv) {
            linear_uvs(quads, 20, 40, 3, 3, 256, 128, uv);
            r = distortion(quads, uv, 256, 128, 0, 0, &rep, &err);
            CHECK(r == TT_OK && rep.faces_measured == 15 && near(rep.stretch_max, 2, 1e-6) &&
                      near(rep.texels_per_unit, sqrt(800.0), 1e-3) && near(rep.density_p95, 0, 1e-6),
                  "quads at 20 x 40 texels a unit: %d, %d faces, stretch %g (want 2), %g texels a unit (want %g)",
                  r, rep.faces_measured, rep.stretch_max, rep.texels_per_unit, sqrt(800.0));
            free(uv);
        }
        tt_mesh_free(quads);
    }
}

/* Flipped, degenerate and non-finite faces and corners near the border are
   counted; only the flipped ones stay in the statistics. */
static void test_uv_distortion_counts(void)
{
    tt_mesh *tris = triangle_grid(6, 4);
    tt_uv_distortion_report rep;
    tt_error err;
    tt_result r;
    float *uv, keep[2];
    int c, expect_margin = 0;
    if (!tris) return;
    uv = (float *)malloc(sizeof(float) * 2 * (size_t)tris->ncorners);
    if (!uv) { tt_mesh_free(tris); return; }
    linear_uvs(tris, 16, 16, 10, 10, 256, 128, uv);
    /* face 5 mirrored: its first two corners swap UVs */
    keep[0] = uv[30]; keep[1] = uv[31];
    uv[30] = uv[32]; uv[31] = uv[33];
    uv[32] = keep[0]; uv[33] = keep[1];
    /* face 7 collapsed onto one UV point */
    for (c = 21; c < 24; c++) { uv[2 * c] = 0.5f; uv[2 * c + 1] = 0.5f; }
    /* face 9 has a NaN UV, face 11 an infinite one */
    uv[2 * 28 + 1] = (float)internal_not_a_number();
    uv[2 * 34] = internal_infinity();
    r = distortion(tris, uv, 256, 128, 16, 0, &rep, &err);
    CHECK(r == TT_OK && rep.flipped == 1 && rep.degenerate == 1 && rep.non_finite == 2 && rep.faces_measured == 45,
          "one mirrored, one collapsed, two non-finite faces: %d, flipped %d, degenerate %d, non-finite %d, %d "
          "measured (want 1, 1, 2, 45) (%s)", r, rep.flipped, rep.degenerate, rep.non_finite, rep.faces_measured,
          err.message);
    /* the mirrored face is the reflection across its hypotenuse (corners
       (0,0) and (1,1) swap, (0,1) stays): flipped, yet no stretch; and the
       excluded faces do not count */
    CHECK(near(rep.stretch_median, 1, 1e-9) && near(rep.stretch_max, 1, 1e-9) && near(rep.density_p95, 0, 1e-6),
          "a mirrored isometric face and excluded faces: stretch median %g, max %g (want 1), density error p95 %g "
          "(want 0)", rep.stretch_median, rep.stretch_max, rep.density_p95);
    /* a stretched face among similar ones: the area-weighted median stays 1,
       the maximum shows it; face 0 (corners (0,0) (1,0) (1,1)) gets its
       second corner moved to (3, 0) in texture units of 16 texels */
    linear_uvs(tris, 16, 16, 10, 10, 256, 128, uv);
    uv[2] = (float)((3 * 16 + 10) / 256.0);
    r = distortion(tris, uv, 256, 128, 16, 0, &rep, &err);
    CHECK(r == TT_OK && rep.faces_measured == 48 && rep.flipped == 0 && near(rep.stretch_median, 1, 1e-6) &&
              rep.stretch_max > 2,
          "one stretched face: %d, stretch median %g (want 1), max %g (want > 2)", r, rep.stretch_median,
          rep.stretch_max);
    /* margins: the grid spans texels 10 .. 106 x 10 .. 74; a margin of 12
       catches the corners on x = 0 and y = 0 (texel 10) */
    linear_uvs(tris, 16, 16, 10, 10, 256, 128, uv);
    for (c = 0; c < tris->ncorners; c++) {
        const float *p = tris->pos + 3 * (size_t)tris->corner_vert[c];
        expect_margin += p[0] == 0.0f || p[1] == 0.0f;
    }
    uv[0] = 1.01f;   /* corner 0 (at the origin) outside the image: counted once */
    r = distortion(tris, uv, 256, 128, 16, 12, &rep, &err);
    CHECK(r == TT_OK && rep.outside_margin == expect_margin, "margin 12 texels: %d corners (want %d)",
          rep.outside_margin, expect_margin);
    r = distortion(tris, uv, 256, 128, 16, 0, &rep, &err);
    CHECK(r == TT_OK && rep.outside_margin == 0, "no margin check: %d corners (want 0)", rep.outside_margin);
    r = distortion(tris, uv, 256, 128, 16, 9.5, &rep, &err);
    CHECK(r == TT_OK && rep.outside_margin == 1, "margin 9.5 texels: %d corners (want only the one outside)",
          rep.outside_margin);
    /* nothing measurable */
    for (c = 0; c < 2 * tris->ncorners; c++) uv[c] = (float)internal_not_a_number();
    memset(&err, 0, sizeof err);
    r = distortion(tris, uv, 256, 128, 0, 0, &rep, &err);
    CHECK(r == TT_ERROR_NOT_MEASURED && err.result == r && err.message[0] && rep.non_finite == 48 &&
              rep.faces_measured == 0 && isnan(rep.stretch_median) && isnan(rep.density_p95) &&
              isnan(rep.density_spread) && isnan(rep.stretch_max) && isnan(rep.stretch_p5) &&
              isnan(rep.density_p5_over_median) && isnan(rep.density_p95_over_median),
          "all-NaN UVs: expected TT_ERROR_NOT_MEASURED with 48 non-finite faces and NaN statistics, got %d, %d, "
          "stretch %g (\"%s\")", r, rep.non_finite, rep.stretch_median, err.message);
    for (c = 0; c < 2 * tris->ncorners; c++) uv[c] = 0.25f;
    r = distortion(tris, uv, 256, 128, 0, 0, &rep, &err);
    CHECK(r == TT_ERROR_NOT_MEASURED && rep.degenerate == 48, "every UV at one point: %d, %d degenerate", r,
          rep.degenerate);
    free(uv);
    tt_mesh_free(tris);
}

/* The weighted percentile against its definition, evaluated naively:
   integer weights, so that every sum is exact in both. */
static void test_weighted_percentile(void)
{
    static const double fractions[5] = {0.0, 0.25, 0.5, 0.95, 1.0};
    double values[40], weights[40];
    int trial, k, i, j, bad = 0;
    lcg_seed(606);
    for (trial = 0; trial < 200; trial++) {
        int n = 1 + lcg_below(40);
        for (i = 0; i < n; i++) {
            values[i] = (double)lcg_below(12) + (lcg_below(2) ? 0.5 : 0.0);   /* ties on purpose */
            weights[i] = (double)lcg_below(6);   /* zero weights too */
        }
        weights[lcg_below(n)] += 1.0;   /* a positive total */
        for (k = 0; k < 5; k++) {
            double total = 0.0, want = 0.0, got;
            int found = 0;
            for (i = 0; i < n; i++) total += weights[i];
            /* the smallest value whose at-or-below weight reaches the goal */
            for (i = 0; i < n; i++) {
                double below = 0.0;
                for (j = 0; j < n; j++)
                    if (values[j] <= values[i]) below += weights[j];
                if (below >= fractions[k] * total && (!found || values[i] < want)) {
                    want = values[i];
                    found = 1;
                }
            }
            got = internal_weighted_percentile(values, weights, n, fractions[k]);
            if (got != want) {
                if (!bad) DETAIL("trial %d, %d items, fraction %g: got %g, want %g", trial, n, fractions[k], got, want);
                bad++;
            }
        }
    }
    CHECK(bad == 0, "weighted percentiles: %d of 1000 differ from the naive reference", bad);
}

static int weighted_pair_compare(const void *a, const void *b)
{
    const double x = ((const double *)a)[0], y = ((const double *)b)[0];
    return x < y ? -1 : x > y;
}

/* The weighted percentile (a weighted selection, with a sort when the
   pivots keep missing) on long arrays in orders that defeat naive pivots:
   random, many repeats, sorted, reversed, all equal, an organ pipe; against
   a sorted copy scanned (integer weights: exact sums). */
static void test_weighted_percentile_orders(void)
{
    static const double fractions[5] = {0.0, 0.05, 0.5, 0.95, 1.0};
    int pattern, n, i, k, bad = 0, checked = 0;
    for (pattern = 0; pattern < 6; pattern++)
        for (n = 1; n <= 3001; n = n < 20 ? n + 1 : 2 * n + 1) {
            double *values = (double *)malloc(sizeof(double) * (size_t)n);
            double *weights = (double *)malloc(sizeof(double) * (size_t)n);
            double *pairs = (double *)malloc(sizeof(double) * 2 * (size_t)n), total = 0.0;
            if (!values || !weights || !pairs) abort();
            lcg_seed(23u + (unsigned)n);
            hostile_order(values, n, pattern);
            for (i = 0; i < n; i++) weights[i] = (double)lcg_below(5);
            weights[n / 2] += 1.0;
            for (i = 0; i < n; i++) {
                pairs[2 * i] = values[i];
                pairs[2 * i + 1] = weights[i];
                total += weights[i];
            }
            qsort(pairs, (size_t)n, 2 * sizeof(double), weighted_pair_compare);
            for (k = 0; k < 5; k++) {
                double cumulative = 0.0, want = pairs[2 * (n - 1)];
                for (i = 0; i < n; i++) {
                    cumulative += pairs[2 * i + 1];
                    if (cumulative >= fractions[k] * total) {
                        want = pairs[2 * i];
                        break;
                    }
                }
                if (internal_weighted_percentile(values, weights, n, fractions[k]) != want) {
                    if (!bad) DETAIL("pattern %d, %d items, fraction %g: got %g, want %g", pattern, n, fractions[k],
                                     internal_weighted_percentile(values, weights, n, fractions[k]), want);
                    bad++;
                }
                checked++;
            }
            free(values);
            free(weights);
            free(pairs);
        }
    CHECK(bad == 0, "weighted percentiles in hostile orders: %d of %d differ from a sorted copy", bad, checked);
}

static void test_uv_distortion_errors(void)
{
    tt_mesh *tris = triangle_grid(2, 2);
    tt_uv_distortion_options opt;
    tt_uv_distortion_report rep;
    counter cnt;
    tt_allocator half = make_allocator(&cnt, -1);
    tt_error err;
    float uv[2 * 24];
    int i;
    struct {
        double texels_per_unit, margin;
        const char *what;
    } bad_options[5] = {{-1, 0, "texels_per_unit -1"}, {0, -0.5, "margin -0.5"}, {0, 0, "texels_per_unit NaN"},
                        {16, 0, "margin inf"}, {0, 0, "texels_per_unit inf"}};
    if (!tris) return;
    bad_options[2].texels_per_unit = internal_not_a_number();
    bad_options[3].margin = internal_infinity();
    bad_options[4].texels_per_unit = internal_infinity();
    linear_uvs(tris, 16, 16, 1, 1, 64, 64, uv);
    CHECK(tt_measure_uv_distortion(tris, uv, 64, 64, NULL, NULL, &rep, &err) == TT_OK && rep.faces_measured == 8,
          "options NULL: %s", err.message);
    CHECK(tt_measure_uv_distortion(NULL, uv, 64, 64, NULL, NULL, &rep, &err) == TT_ERROR_INVALID_ARGUMENT &&
              tt_measure_uv_distortion(tris, NULL, 64, 64, NULL, NULL, &rep, &err) == TT_ERROR_INVALID_ARGUMENT &&
              tt_measure_uv_distortion(tris, uv, 64, 64, NULL, NULL, NULL, &err) == TT_ERROR_INVALID_ARGUMENT,
          "tt_measure_uv_distortion with NULL arguments should be rejected");
    for (i = 0; i < 2; i++) {
        tt_result r = tt_measure_uv_distortion(tris, uv, i ? 64 : 0, i ? -3 : 64, NULL, NULL, &rep, &err);
        CHECK(r == TT_ERROR_INVALID_ARGUMENT && err.result == r && err.message[0] && isnan(rep.stretch_median) &&
                  rep.faces_measured == 0,
              "image %d x %d: expected TT_ERROR_INVALID_ARGUMENT with an empty report, got %d", i ? 64 : 0,
              i ? -3 : 64, r);
    }
    for (i = 0; i < 5; i++) {
        tt_result r;
        memset(&opt, 0, sizeof opt);
        opt.texels_per_unit = bad_options[i].texels_per_unit;
        opt.margin_texels = bad_options[i].margin;
        memset(&err, 0, sizeof err);
        r = tt_measure_uv_distortion(tris, uv, 64, 64, &opt, NULL, &rep, &err);
        CHECK(r == TT_ERROR_INVALID_ARGUMENT && err.result == r && err.message[0],
              "%s: expected TT_ERROR_INVALID_ARGUMENT, got %d (\"%s\")", bad_options[i].what, r, err.message);
    }
    half.alloc = NULL;
    CHECK(tt_measure_uv_distortion(tris, uv, 64, 64, NULL, &half, &rep, &err) == TT_ERROR_INVALID_ARGUMENT,
          "an allocator with free but no alloc should be rejected");
    tt_mesh_free(tris);
}

typedef struct distortion_ctx {
    const tt_mesh *mesh;
    const float *uv;
} distortion_ctx;

static tt_result oom_distortion(void *ctx, const tt_allocator *al, tt_error *error)
{
    distortion_ctx *d = (distortion_ctx *)ctx;
    tt_uv_distortion_report rep;
    tt_result r = tt_measure_uv_distortion(d->mesh, d->uv, 64, 32, NULL, al, &rep, error);
    if (r != TT_OK && (error->result != r || !isnan(rep.stretch_median))) return TT_RESULT_MAX_ENUM;
    return r;
}

static void test_uv_distortion_oom(void)
{
    tt_mesh *tris = triangle_grid(3, 2);
    float uv[2 * 36];
    distortion_ctx d;
    if (!tris) return;
    linear_uvs(tris, 8, 8, 1, 1, 64, 32, uv);
    d.mesh = tris;
    d.uv = uv;
    oom_reset();
    oom_sweep("tt_measure_uv_distortion", oom_distortion, &d, TT_OK);
    tt_mesh_free(tris);
}

void run_tiled_tests(void)
{
    RUN(test_layout);
    RUN(test_boundaries_uvs);
    RUN(test_prescribed_colors);
    RUN(test_tile_uv_index);
    RUN(test_reduce_tiles);
    RUN(test_synthesis);
    RUN(test_synth_errors);
    RUN(test_synth_non_finite);
    RUN(test_synth_oom);
    RUN(test_compact_atlas);
    RUN(test_seams);
    RUN(test_seams_control);
    RUN(test_seams_ends);
    RUN(test_orient_tiles);
    RUN(test_assign_uvs_oriented);
    RUN(test_orient_tiles_seams);
    RUN(test_seams_displayed);
    RUN(test_seams_not_measured);
    RUN(test_seams_sampled);
    RUN(test_seams_oom);
    RUN(test_seams_discontinuous);
    RUN(test_seams_edge_list);
    RUN(test_seams_flags_zero_unchanged);
    RUN(test_seams_executor_identical);
    RUN(test_seams_wrap);
    RUN(test_histogram);
    RUN(test_stretch);
    RUN(test_weighted_percentile);
    RUN(test_weighted_percentile_orders);
    RUN(test_uv_distortion_maps);
    RUN(test_uv_distortion_counts);
    RUN(test_uv_distortion_errors);
    RUN(test_uv_distortion_oom);
}
