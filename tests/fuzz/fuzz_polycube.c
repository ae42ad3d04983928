/* fuzz_polycube.c - libFuzzer target for the polycube + Wang tiles pipeline:
   tt_polycube_build, tt_polycube_edge_colors, tt_polycube_map (refinement,
   projection, relaxation, tracing, the triangle split) and the texture
   coordinates, plain and upright, on small meshes at resolutions 1..6.

   Build (tests/fuzz/run.sh does this, with the library compiled once from
   tests/fuzz/fuzz_library.c):
       clang -g -O1 -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=all \
             -I. tests/fuzz/fuzz_polycube.c tests/fuzz/fuzz_library.c -o build/fuzz/fuzz_polycube -lm

   Why so small: the time of tt_polycube_map follows the refined triangles
   and, above all, the folds the projection leaves (a random tetrahedron at
   resolution 15 refines to 8k triangles and spends 1.3 s at -O2, 40 % of it
   in the untangling's energy; at resolution 6 or less it takes 15 ms at
   most). The untangling's budget is fixed per folded vertex (sweeps x
   descent steps x halvings x star), so a part about one cube thick (the
   torus below at resolution 4) still costs 0.1-0.4 s: most runs take a
   few milliseconds, those dominate the mean. An inside-out mesh, which
   folds everywhere, is not mapped (the header asks for it reversed).
   TT_POLYCUBE_MAX_TRIANGLES is defined to 1024 here, so a refinement past
   it is refused (TT_ERROR_TOO_LARGE, the limit's own path) instead of
   running for seconds: at 2048 the grown corpus ran at 41 inputs a second
   (-O2, no fuzzer), at 1024 at 139, and 52 % of the runs still reach the
   triangle split (at 768: 40 %). Built without sanitizers and without
   comparison tracing (FUZZ_SANITIZE=0 tests/fuzz/run.sh), libFuzzer runs
   it at 180-250 inputs a second.

   Input bytes, read front to back (missing bytes read as 0):
       0      bits 0..1 both set, with byte[2] bit7 and byte[10] bit7:
              allocation number byte[1] + 256 * (byte[2] & 3) + 1 fails;
              bit2 a progress
              callback on the mapping, cancelling after byte[3] % 8 calls
              (0 = never) when byte[9] has bit7 set, else never; bit3
              TT_POLYCUBE_NO_CORRECT; bit4 cube_size instead of
              resolution: the box's longest side / (1 + byte[4] % 6); bit5
              the mapping twice and compare (determinism); bit6 with
              byte[4] >= 252 and byte[2] bit6 NULL options to
              tt_polycube_build; bit7 with byte[12] >= 232 an extreme
              option double (byte[12] % 3 picks the field, byte[13] the
              value: fz_extreme_double). The second conditions keep the
              runs that stop early (a failed allocation, resolution 16,
              which is not mapped here, an extreme option or a cancel
              mostly stops the mapping) rare enough that most runs reach
              the triangle split: the fuzzer, drawn to the paths these
              open, made them 16 % of its runs under looser gates (a
              failed allocation 5 %, NULL options 11 %), and half the
              runs fell short of the split.
       1, 2   which allocation fails (see above); byte[2] bits 6, 7 gate
              NULL options and the failing allocation
       3      cancel after (% 8); bit3 TT_MESH_PERMISSIVE; bits 4..7 up:
              0 default, else one of +-x, +-y, +-z, or a skew vector
       4      resolution 1 + b % 6
       5      max_edge: 0 = default (h / 2), 255 = HUGE_VAL (no refinement),
              else h * (16 + b) / 64 (at least h / 4: a finer one refines
              thousands of triangles and takes 0.1 s a run)
       6      max_quads: b % 9 (0 = default) below 245, else 60 + b - 245
              (60..64 the longest searches, 65..70 out of range)
       7      colors: 1 + b % 8, 250..255 out of range (0, 129, -1, ...)
       8      bit0 axis palettes; bits 1..7 the tile size 4 + 4 * (b >> 5),
              gutter (b >> 1) & 3
       9..11  edge colour seed (byte[10] bit7 also gates the failing
              allocation), boundary seed
       12, 13 the extreme option
       then   the mesh (fuzz_shape.h)

   Besides crashes, leaks and undefined behaviour, it aborts when a result
   breaks the contract: a polycube whose report disagrees with it, whose
   surface is not a closed strict mesh of quads or whose per-quad and
   per-vertex arrays are out of range; edge colours out of range or
   different on the two half-edges of an edge; a mapping with an index,
   source, weight, face or corner point out of range or not finite, or
   weights not summing to 1; UVs not finite or outside [0, 1] on TT_OK, or
   written on failure; a result other than the documented ones; a second
   mapping that differs; a progress fraction outside [0, 1] or going back;
   an error without a sentence, whose result differs, or out of memory with
   no failed allocation; an allocation not given back.

   It counts the runs that reach the triangle split (tt_polycube_map's
   report.triangles > 0 and a mapping) and prints the share at exit. */
#define TT_POLYCUBE_MAX_TRIANGLES 1024
#include "tiledtex.h"
#define FUZZ_NAME "fuzz_polycube"
#include "fuzz_common.h"
#include "fuzz_shape.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define SENTINEL 1234.5f

/* The fuzz program's own counters (the library keeps none). */
static long runs, deep_runs;

static void print_share(void)
{
    if (runs > 0)
        fprintf(stderr, "fuzz_polycube: %ld of %ld runs (%.1f %%) reached the triangle split\n", deep_runs, runs,
                100.0 * (double)deep_runs / (double)runs);
}

/* Whether triangles f and g use the same three vertices (a closed pair
   with no inside, which tt_polycube_map refuses), compared corner by corner. */
static int same_corners(const tt_mesh *m, int f, int g)
{
    int i, j, found = 0;
    if (f < 0 || g < 0 || f == g || f >= m->nfaces || g >= m->nfaces) return 0;
    for (i = 0; i < 3; ++i)
        for (j = 0; j < 3; ++j)
            found += m->corner_vert[m->face_start[f] + i] == m->corner_vert[m->face_start[g] + j];
    return found == 3;
}

static void check_polycube(const tt_polycube *pc, const tt_polycube_report *rep)
{
    const tt_mesh *s = pc->surface;
    long ncubes = (long)pc->dims[0] * pc->dims[1] * pc->dims[2], lattice = (long)(pc->dims[0] + 1) *
                                                                          (pc->dims[1] + 1) * (pc->dims[2] + 1);
    int q, c, occupied = 0;
    CHECK(pc->dims[0] >= 1 && pc->dims[1] >= 1 && pc->dims[2] >= 1 && pc->h > 0.0 && isfinite(pc->h), "dims %d %d %d h %g",
          pc->dims[0], pc->dims[1], pc->dims[2], pc->h);
    CHECK(rep->dims[0] == pc->dims[0] && rep->dims[1] == pc->dims[1] && rep->dims[2] == pc->dims[2] &&
              rep->cube_size == pc->h,
          "report dims/h differ");
    for (c = 0; c < ncubes; ++c) {
        CHECK(pc->occupied[c] <= 1, "cube %d occupied %d", c, pc->occupied[c]);
        occupied += pc->occupied[c];
    }
    CHECK(occupied == rep->cubes, "%d occupied, report says %d", occupied, rep->cubes);
    CHECK(s && s->nfaces == rep->quads && s->min_face_size == 4 && s->max_face_size == 4, "surface: %d quads, report %d",
          s ? s->nfaces : -1, rep->quads);
    for (c = 0; c < s->ncorners; ++c) CHECK(s->twin[c] >= 0, "surface half-edge %d has no twin", c);
    for (q = 0; q < s->nfaces; ++q) {
        CHECK(pc->quad_cube[q] >= 0 && pc->quad_cube[q] < ncubes && pc->occupied[pc->quad_cube[q]],
              "quad %d cube %d", q, pc->quad_cube[q]);
        CHECK(pc->quad_side[q] < 6, "quad %d side %d", q, pc->quad_side[q]);
    }
    for (c = 0; c < s->nverts; ++c)
        CHECK(pc->vertex_lattice[c] >= 0 && pc->vertex_lattice[c] < lattice, "vertex %d lattice %d", c,
              pc->vertex_lattice[c]);
    CHECK(pc->up_axis >= 0 && pc->up_axis < 3 && (pc->up_sign == 1 || pc->up_sign == -1), "up %d %d", pc->up_axis,
          pc->up_sign);
}

static void check_mapping(const tt_polycube *pc, const tt_mesh *m, const tt_polycube_mapping *mp,
                          const tt_polycube_map_report *rep)
{
    int v, t, k;
    CHECK(mp->ntriangles >= 1 && mp->nverts >= m->nverts, "%d triangles %d verts", mp->ntriangles, mp->nverts);
    CHECK(rep->triangles >= m->nfaces, "report: %d triangles for %d faces", rep->triangles, m->nfaces);
    for (v = 0; v < mp->nverts; ++v) {
        double sum = 0.0;
        for (k = 0; k < 3; ++k) {
            int src = mp->source[3 * v + k];
            float w = mp->weights[3 * v + k];
            CHECK(isfinite(mp->positions[3 * v + k]), "vertex %d position %g", v, (double)mp->positions[3 * v + k]);
            CHECK(isfinite(w) && w >= 0.0f && w <= 1.0f, "vertex %d weight %g", v, (double)w);
            CHECK(w == 0.0f || (src >= 0 && src < m->nverts), "vertex %d source %d of %d", v, src, m->nverts);
            sum += w;
        }
        CHECK(fabs(sum - 1.0) <= 1e-4, "vertex %d weights sum to %.9g", v, sum);
    }
    for (t = 0; t < mp->ntriangles; ++t) {
        CHECK(mp->triangle_face[t] >= 0 && mp->triangle_face[t] < m->nfaces, "triangle %d face %d", t,
              mp->triangle_face[t]);
        for (k = 0; k < 3; ++k) {
            const tt_surface_point *p = &mp->corner_points[3 * t + k];
            CHECK(mp->triangles[3 * t + k] >= 0 && mp->triangles[3 * t + k] < mp->nverts, "triangle %d vertex %d", t,
                  mp->triangles[3 * t + k]);
            CHECK(p->quad >= 0 && p->quad < pc->surface->nfaces && p->s >= 0.0f && p->s <= 1.0f && p->t >= 0.0f &&
                      p->t <= 1.0f,
                  "triangle %d corner %d at quad %d (%g, %g)", t, k, p->quad, (double)p->s, (double)p->t);
            CHECK(p->quad == mp->corner_points[3 * t].quad, "triangle %d spans quads %d and %d", t,
                  mp->corner_points[3 * t].quad, p->quad);
        }
    }
}

static int same_mapping(const tt_polycube_mapping *a, const tt_polycube_mapping *b)
{
    return a->nverts == b->nverts && a->ntriangles == b->ntriangles &&
           memcmp(a->positions, b->positions, sizeof(float) * 3 * (size_t)a->nverts) == 0 &&
           memcmp(a->source, b->source, sizeof(int) * 3 * (size_t)a->nverts) == 0 &&
           memcmp(a->weights, b->weights, sizeof(float) * 3 * (size_t)a->nverts) == 0 &&
           memcmp(a->triangles, b->triangles, sizeof(int) * 3 * (size_t)a->ntriangles) == 0 &&
           memcmp(a->triangle_face, b->triangle_face, sizeof(int) * (size_t)a->ntriangles) == 0 &&
           memcmp(a->corner_points, b->corner_points, sizeof(tt_surface_point) * 3 * (size_t)a->ntriangles) == 0;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static int registered;
    reader rd;
    fz_alloc a;
    fz_shape shape;
    fz_progress ps;
    tt_mesh *mesh = NULL;
    tt_polycube *pc = NULL;
    tt_polycube_options po;
    tt_polycube_report prep;
    tt_polycube_map_options mo;
    tt_polycube_map_report mrep;
    tt_polycube_mapping *mp = NULL, *mp2 = NULL;
    tt_tile_layout layout;
    tt_error err;
    tt_result r;
    const tt_allocator *alloc;
    uint8_t hdr[14];
    int *colors = NULL, ncolors, k, valid_options = 1, null_options;
    uint8_t *types = NULL;
    float *uv = NULL;
    double lo3[3] = {1e300, 1e300, 1e300}, hi3[3] = {-1e300, -1e300, -1e300}, longest;

    if (!registered) {
        registered = 1;
        atexit(print_share);
    }
    rd.p = data;
    rd.n = size;
    rd.at = 0;
    for (k = 0; k < 14; ++k) hdr[k] = rd_u8(&rd);
    fz_shape_read(&rd, &shape, 1);
    runs++;
    null_options = (hdr[0] & 64) && hdr[4] >= 252 && (hdr[2] & 64);
    alloc = fz_alloc_init(&a, (hdr[0] & 3) == 3 && (hdr[2] & 128) && (hdr[10] & 128)
                                  ? (long)hdr[1] + 256L * (hdr[2] & 3) + 1
                                  : 0);

    if (fz_shape_build(&shape, hdr[3] & 8, alloc, &a, &mesh) != TT_OK) goto out;

    /* ---- the polycube ---- */
    for (k = 0; k < 3 * shape.nverts; ++k) {
        double x = shape.pos[k];
        if (x < lo3[k % 3]) lo3[k % 3] = x;
        if (x > hi3[k % 3]) hi3[k % 3] = x;
    }
    longest = fmax(hi3[0] - lo3[0], fmax(hi3[1] - lo3[1], hi3[2] - lo3[2]));
    memset(&po, 0, sizeof po);
    po.resolution = 1 + hdr[4] % 6;
    if ((hdr[0] & 16) && longest > 0.0 && isfinite(longest)) {
        /* the same size of grid as a resolution, through cube_size */
        po.resolution = 0;
        po.cube_size = longest / (1 + hdr[4] % 6) * 1.0001;
    }
    po.flags = (hdr[0] & 8) ? TT_POLYCUBE_NO_CORRECT : 0;
    switch (hdr[3] >> 4) {
    case 0: break;
    case 1: po.up[0] = 1; break;
    case 2: po.up[0] = -1; break;
    case 3: po.up[1] = -1; break;
    case 4: po.up[2] = 1; break;
    case 5: po.up[2] = -1; break;
    default: po.up[0] = 0.3; po.up[1] = -0.2; po.up[2] = (hdr[3] >> 4) - 10.0; break;
    }
    if ((hdr[0] & 128) && hdr[12] >= 232 && (hdr[12] % 3) < 2) {
        double v = fz_extreme_double(hdr[13]);
        if (hdr[12] % 3 == 0) po.cube_size = v;
        else po.up[hdr[13] % 3] = v;
        valid_options = 0;
    }
    memset(&err, 0x55, sizeof err);
    memset(&prep, 0x55, sizeof prep);
    pc = (tt_polycube *)&rd;
    r = tt_polycube_build(mesh, null_options ? NULL : &po, alloc, &pc, &prep, &err);
    if (r != TT_OK) {
        fz_check_null("tt_polycube_build", r, pc);
        fz_check_error("tt_polycube_build", r, &err, &a);
        /* NULL options: resolution 16, which this target does not go on with */
        CHECK(r == TT_ERROR_OUT_OF_MEMORY || r == TT_ERROR_ZERO_AREA_FACE || !valid_options || shape.extreme ||
                  (r == TT_ERROR_TOO_LARGE && po.cube_size > 0.0),
              "tt_polycube_build: %d %s", (int)r, err.message);
        goto out;
    }
    check_polycube(pc, &prep);
    if (null_options) goto out; /* resolution 16: too slow to map here */
    /* An inside-out mesh must be reversed before mapping (the header says
       so; the tool does it): every triangle folds, and the untangling then
       spends its whole budget (0.7 s for a 36-triangle sphere). */
    if (prep.inside_out) goto out;

    /* ---- the Wang colouring and the boundary types ---- */
    colors = (int *)malloc(sizeof(int) * (size_t)pc->surface->ncorners);
    types = (uint8_t *)malloc((size_t)pc->surface->ncorners);
    if (!colors || !types) abort();
    ncolors = hdr[7] >= 250 ? (hdr[7] == 250 ? 0 : hdr[7] == 251 ? TT_MAX_COLORS + 1 : -1) : 1 + hdr[7] % 8;
    memset(&err, 0x55, sizeof err);
    r = tt_polycube_edge_colors(pc, ncolors, hdr[8] & 1, (uint64_t)hdr[9] | (uint64_t)hdr[10] << 8, colors, &err);
    if (r != TT_OK) {
        fz_check_error("tt_polycube_edge_colors", r, &err, &a);
        CHECK(r == TT_ERROR_INVALID_ARGUMENT && (ncolors < 1 || ncolors > TT_MAX_COLORS), "edge colours %d: %s",
              ncolors, err.message);
        ncolors = 0;
    } else {
        for (k = 0; k < pc->surface->ncorners; ++k) {
            CHECK(colors[k] >= 0 && colors[k] < ncolors, "edge %d colour %d of %d", k, colors[k], ncolors);
            CHECK(colors[pc->surface->twin[k]] == colors[k], "half-edges %d, %d colours %d, %d", k,
                  pc->surface->twin[k], colors[k], colors[pc->surface->twin[k]]);
        }
    }
    layout.colors = ncolors > 0 ? ncolors : 1;
    layout.tile_size = 4 + 4 * (hdr[8] >> 5);
    layout.gutter = (hdr[8] >> 1) & 3;
    memset(&err, 0x55, sizeof err);
    r = tt_assign_boundaries(pc->surface, &layout, hdr[11], ncolors > 0 ? colors : NULL, types, &err);
    CHECK(r == TT_OK, "tt_assign_boundaries: %s", err.message);

    /* ---- the mapping ---- */
    memset(&mo, 0, sizeof mo);
    mo.max_edge = hdr[5] == 255 ? HUGE_VAL : hdr[5] == 0 ? 0.0 : pc->h * (16 + hdr[5]) / 64.0;
    /* 0..8 mostly: a long path search (60..64 quads) on a mesh whose edges
       fail spends its whole step budget per edge, seconds a run */
    mo.max_quads = hdr[6] < 245 ? hdr[6] % 9 : 60 + (hdr[6] - 245);
    if ((hdr[0] & 128) && hdr[12] >= 232 && hdr[12] % 3 == 2) {
        mo.max_edge = fz_extreme_double(hdr[13]);
        valid_options = 0;
    }
    memset(&ps, 0, sizeof ps);
    if (hdr[0] & 4) {
        ps.cancel_after = (hdr[9] & 128) ? hdr[3] % 8 : 0;
        mo.progress = fz_on_progress;
        mo.progress_user_data = &ps;
    }
    memset(&err, 0x55, sizeof err);
    memset(&mrep, 0x55, sizeof mrep);
    mp = (tt_polycube_mapping *)&rd;
    r = tt_polycube_map(pc, mesh, &mo, alloc, &mp, &mrep, &err);
    if (r != TT_OK) {
        fz_check_null("tt_polycube_map", r, mp);
        fz_check_error("tt_polycube_map", r, &err, &a);
        CHECK(r == TT_ERROR_OUT_OF_MEMORY || r == TT_ERROR_TOO_LARGE ||
                  (r == TT_CANCELLED && ps.cancel_after > 0 && ps.calls == ps.cancel_after) ||
                  (r == TT_ERROR_INVALID_ARGUMENT &&
                   (mo.max_quads > TT_POLYCUBE_EDGE_MAX_QUADS || same_corners(mesh, err.face, err.other_face))) ||
                  !valid_options,
              "tt_polycube_map: %d %s", (int)r, err.message);
        goto out;
    }
    CHECK(ps.cancel_after == 0 || ps.calls < ps.cancel_after, "not cancelled after %d calls", ps.calls);
    if (mrep.triangles > 0 && mp) deep_runs++;
    check_mapping(pc, mesh, mp, &mrep);

    if (hdr[0] & 32) {
        long count_before = a.count;
        tt_polycube_map_report rep2;
        mo.progress = NULL;
        memset(&err, 0x55, sizeof err);
        r = tt_polycube_map(pc, mesh, &mo, alloc, &mp2, &rep2, &err);
        if (r != TT_OK) {
            fz_check_error("tt_polycube_map (again)", r, &err, &a);
            CHECK(r == TT_ERROR_OUT_OF_MEMORY && a.fail_at > count_before, "second mapping failed: %s", err.message);
        } else {
            CHECK(same_mapping(mp, mp2), "same input, different mappings");
        }
    }

    /* ---- texture coordinates, plain and upright ---- */
    uv = (float *)malloc(sizeof(float) * 6 * (size_t)mp->ntriangles);
    if (!uv) abort();
    for (k = 0; k < 2; ++k) {
        int i;
        for (i = 0; i < 6 * mp->ntriangles; ++i) uv[i] = SENTINEL;
        memset(&err, 0x55, sizeof err);
        r = k == 0 ? tt_polycube_mapping_uvs(pc, mp, &layout, types, uv, &err)
                   : tt_polycube_mapping_uvs_upright(pc, mp, &layout, types, uv, &err);
        CHECK(r == TT_OK, "tt_polycube_mapping_uvs%s: %d %s", k ? "_upright" : "", (int)r, err.message);
        for (i = 0; i < 6 * mp->ntriangles; ++i)
            CHECK(isfinite(uv[i]) && uv[i] >= 0.0f && uv[i] <= 1.0f, "uv%s[%d] = %g", k ? " (upright)" : "", i,
                  (double)uv[i]);
    }

out:
    free(uv);
    free(colors);
    free(types);
    tt_polycube_mapping_free(mp == (tt_polycube_mapping *)&rd ? NULL : mp);
    tt_polycube_mapping_free(mp2);
    tt_polycube_free(pc == (tt_polycube *)&rd ? NULL : pc);
    tt_mesh_free(mesh);
    fz_check_all_freed(&a);
    return 0;
}
