/* fuzz_lapped.c - libFuzzer target for the lapped-textures pipeline: tangent
   field, texture patches, the paste loop, the alignment measure, the pair
   atlas and baking.

   Build (tests/fuzz/run.sh does this, with the library compiled once from
   tests/fuzz/fuzz_library.c):
       clang -g -O1 -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=all \
             -I. tests/fuzz/fuzz_lapped.c tests/fuzz/fuzz_library.c -o build/fuzz/fuzz_lapped -lm

   Input bytes, read front to back (missing bytes read as 0; missing positions
   get distinct points on the twisted cubic (t, t^2, t^3), no three collinear):
       0      flags: bit0 TT_MESH_PERMISSIVE, bit1 isotropic pasting, bit2 one
              field constraint (bytes 10..14), bit3 a second texture patch
              whose mask comes from bytes 15..23, bit4 make allocation number
              byte[4] + 1 fail (the out-of-memory paths), bits 5..6 the atlas
              gutter (0..3), bit7 tt_tangent_field with NULL options
       1      nverts (0..40)
       2      ntris (0..40)
       3      field scale: (0.05 + 1.45 * b / 255) * bounding-box diagonal
       4      which allocation fails (1-based) when bit4 is set
       5      paste seed
       6      bit0 paste twice and compare (determinism), bit1 a progress
              callback (fractions in [0,1], never decreasing), bits 2..7 cancel
              after that many pastes (0 = never)
       7..9   up vector, (b - 128) each (all 128: the default up)
       10     constraint face (b % ntris)
       11..13 constraint direction, (b - 128) each; its length is
              scale * (0.5 + (byte[14] & 15) / 10)
       14     bits 4..6 constraint sigma (0 = default, else k/8 of the diagonal),
              bit7 weight 3.5 (else 0 = 1)
       15     falloff of the second patch (0 = default, else (b % 8) / 2)
       16..23 the second patch's mask: 8 x 8 bits over its 40 x 24 texels
              (5 x 3 texels a bit), row by row
       then   positions, one byte per coordinate: (b - 128) / 16; with
              byte[15] bit7 (extreme floats) a byte below 24 is
              fz_extreme_float(b) instead: +-FLT_MAX, +-1e38, denormals,
              -0.0, infinities, NaNs with payloads
       then   one byte per corner: the vertex index, b % nverts; a triangle cut
              short by the end of the input is dropped

   The first texture patch, a 32 x 32 splotch cut from a fixed image, is made
   once. Pastes are capped at MAX_PASTES (100), so finer fields are refused
   up front (TT_ERROR_TOO_LARGE) and one input stays well under a second with
   the sanitizers. Besides crashes, leaks and undefined behaviour, it aborts when a
   result breaks the documented contract: a field vector that is not finite,
   not in its face's plane, or (without constraints) not `scale` long; a
   successful paste where some face is in no entry, a face or patch index is
   out of range, a face appears twice in one paste, a UV is not finite, the
   pastes are not consecutive runs covering every entry, coverage is not 1 or
   the statistics disagree with the arrays (or, anisotropic, with
   tt_lapped_measure); a failed paste that leaves *result non-zero;
   tt_lapped_measure failing or finding an uncovered face; pair-atlas UVs
   outside [0,1]; tt_lapped_bake failing, or writing a non-finite value, a
   value outside [0,1], or alpha below 1/2 at a texel centre well inside a
   triangle (the pastes cover every face); the same bake from normal-map
   patches (kind TT_IMAGE_NORMAL, one tilted vector times each patch's
   alpha) failing, or leaving a texel that is not a unit vector; a progress fraction that decreases;
   a second paste with the same seed that differs; an allocation not given
   back; an error without a sentence or whose result differs from the return
   value; TT_ERROR_OUT_OF_MEMORY when no allocation failed; a failed call whose
   `T **out` is not NULL, or whose message is empty, unterminated or holds a
   run of more than 12 digits (fz_check_error in fuzz_common.h). Every
   allocating call gets the counting allocator as its parameter. */
#include "tiledtex.h"
#define FUZZ_NAME "fuzz_lapped"
#include "fuzz_common.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define MAX_VERTS 40
#define MAX_TRIS 40
#define MAX_PASTES 100
#define ATLAS_SIZE 128

/* ---- the fixed texture patch ------------------------------------------------------ */

/* A smooth, non-repeating straight RGBA image with alpha 1 everywhere (so the
   patch's shape is the seeded splotch, or the mask). */
static tt_image *fixed_source(int w, int h)
{
    tt_image *img = NULL;
    int x, y;
    if (tt_image_create(w, h, NULL, &img, NULL) != TT_OK) abort();
    for (y = 0; y < h; ++y)
        for (x = 0; x < w; ++x) {
            float *p = img->pixels + 4 * ((size_t)y * w + x);
            p[0] = 0.5f + 0.5f * sinf(0.37f * (float)x + 0.11f * (float)y);
            p[1] = (float)((x * 7 + y * 13) % 17) / 16.0f;
            p[2] = (float)(x + y) / (float)(w + h);
            p[3] = 1.0f;
        }
    return img;
}

/* Made once with the default allocator and kept for the whole run. */
static tt_image *splotch_patch(void)
{
    static tt_image *patch;
    if (!patch) {
        tt_image *src;
        tt_patch_options po;
        tt_error err;
        memset(&po, 0, sizeof po);
        po.seed = 7;
        src = fixed_source(32, 32);
        if (tt_make_texture_patch(src, NULL, &po, NULL, &patch, &err) != TT_OK) {
            fprintf(stderr, "fuzz_lapped: the fixed patch: %s\n", err.message);
            abort();
        }
        tt_image_free(src);
    }
    return patch;
}

/* ---- contract checks ---------------------------------------------------------- */

#define check_error fz_check_error


static void check_field(const tt_mesh *m, const float *fv, int constrained, double scale)
{
    int f;
    for (f = 0; f < m->nfaces; ++f) {
        float n[3];
        const float *t = fv + 3 * (size_t)f;
        double len, dot;
        CHECK(isfinite(t[0]) && isfinite(t[1]) && isfinite(t[2]), "field vector %d (%g, %g, %g)", f,
              (double)t[0], (double)t[1], (double)t[2]);
        tt_face_normal(m, f, n);
        len = sqrt((double)t[0] * t[0] + (double)t[1] * t[1] + (double)t[2] * t[2]);
        if (n[0] == 0.0f && n[1] == 0.0f && n[2] == 0.0f) {
            CHECK(len == 0.0, "zero-area face %d has field vector of length %g", f, len);
            continue;
        }
        dot = (double)t[0] * n[0] + (double)t[1] * n[1] + (double)t[2] * n[2];
        CHECK(len > 0.0, "face %d has a zero field vector", f);
        CHECK(fabs(dot) <= 1e-4 * len, "field vector %d is off its face's plane: T.N = %g, |T| = %g", f, dot, len);
        if (!constrained)
            CHECK(fabs(len - scale) <= 1e-4 * scale, "field vector %d has length %.9g, scale %.9g", f, len, scale);
    }
}

/* Every documented property of a successful paste. */
static void check_lapped(const tt_mesh *m, const tt_lapped *l, int npatches)
{
    char *seen = (char *)calloc((size_t)m->nfaces, 1);
    int *stamp = (int *)malloc(sizeof(int) * (size_t)m->nfaces);
    int p, e, f, at = 0;
    if (!seen || !stamp) abort();
    for (f = 0; f < m->nfaces; ++f) stamp[f] = -1;
    CHECK(l->npastes >= 1 && l->pastes, "%d pastes", l->npastes);
    CHECK(l->nentries >= m->nfaces && l->faces && l->uv, "%d entries for %d faces", l->nentries, m->nfaces);
    for (p = 0; p < l->npastes; ++p) {
        const tt_paste *ps = &l->pastes[p];
        CHECK(ps->patch >= 0 && ps->patch < npatches, "paste %d uses patch %d of %d", p, ps->patch, npatches);
        CHECK(ps->first == at, "paste %d starts at entry %d, expected %d", p, ps->first, at);
        CHECK(ps->nfaces >= 1 && ps->nfaces <= l->nentries - at, "paste %d has %d entries from %d of %d", p,
              ps->nfaces, at, l->nentries);
        for (e = ps->first; e < ps->first + ps->nfaces; ++e) {
            int k;
            f = l->faces[e];
            CHECK(f >= 0 && f < m->nfaces, "entry %d names face %d of %d", e, f, m->nfaces);
            CHECK(stamp[f] != p, "face %d twice in paste %d", f, p);
            stamp[f] = p;
            seen[f] = 1;
            for (k = 0; k < 6; ++k)
                CHECK(isfinite(l->uv[6 * (size_t)e + k]), "entry %d uv[%d] = %g", e, k, (double)l->uv[6 * (size_t)e + k]);
        }
        at += ps->nfaces;
    }
    CHECK(at == l->nentries, "pastes cover %d of %d entries", at, l->nentries);
    for (f = 0; f < m->nfaces; ++f) CHECK(seen[f], "face %d is in no paste", f);
    CHECK(l->coverage == 1.0, "coverage %.17g", l->coverage);
    CHECK(l->removed_entries >= 0, "removed %d", l->removed_entries);
    CHECK(fabs(l->mean_overdraw - (double)l->nentries / m->nfaces) <= 1e-9 * l->mean_overdraw,
          "mean_overdraw %g, %d entries / %d faces", l->mean_overdraw, l->nentries, m->nfaces);
    CHECK(l->mean_angle_error >= 0.0 && l->mean_angle_error <= 180.0, "mean angle error %g", l->mean_angle_error);
    CHECK(l->median_scale_error >= 0.0 && isfinite(l->median_scale_error), "median scale error %g",
          l->median_scale_error);
    free(seen);
    free(stamp);
}

static int same_lapped(const tt_lapped *a, const tt_lapped *b)
{
    return a->npastes == b->npastes && a->nentries == b->nentries && a->removed_entries == b->removed_entries &&
           memcmp(a->pastes, b->pastes, sizeof(tt_paste) * (size_t)a->npastes) == 0 &&
           memcmp(a->faces, b->faces, sizeof(int) * (size_t)a->nentries) == 0 &&
           memcmp(a->uv, b->uv, sizeof(float) * 6 * (size_t)a->nentries) == 0;
}

/* Signed distance (texels, positive inside) of point q from the edges of the
   counter-clockwise or clockwise triangle t[6]; the minimum over the edges. */
static double inside_depth(const double *t, double qx, double qy)
{
    double area = (t[2] - t[0]) * (t[5] - t[1]) - (t[4] - t[0]) * (t[3] - t[1]), best = 1e300;
    int k;
    if (area == 0.0) return -1.0;
    for (k = 0; k < 3; ++k) {
        double ax = t[2 * k], ay = t[2 * k + 1], bx = t[2 * ((k + 1) % 3)], by = t[2 * ((k + 1) % 3) + 1];
        double ex = bx - ax, ey = by - ay, el = sqrt(ex * ex + ey * ey), d;
        if (el == 0.0) return -1.0;
        d = (ex * (qy - ay) - ey * (qx - ax)) / el;
        if (area < 0.0) d = -d;
        if (d < best) best = d;
    }
    return best;
}

static void check_atlas(const tt_mesh *m, const tt_image *atlas, const float *corner_uv)
{
    int x, y, f, k, n = atlas->width * atlas->height;
    for (k = 0; k < 4 * n; ++k) {
        float v = atlas->pixels[k];
        CHECK(isfinite(v) && v >= -1e-4f && v <= 1.0f + 1e-4f, "atlas texel %d channel %d = %g", k / 4, k % 4,
              (double)v);
    }
    /* Texel centres well inside a triangle's image show that face, which the
       pastes cover (coverage 1): no hole there. */
    for (f = 0; f < m->nfaces; ++f) {
        double t[6];
        int x0, x1, y0, y1;
        for (k = 0; k < 3; ++k) {
            t[2 * k] = (double)corner_uv[2 * (3 * f + k)] * atlas->width;
            t[2 * k + 1] = (double)corner_uv[2 * (3 * f + k) + 1] * atlas->height;
        }
        x0 = (int)floor(fmin(t[0], fmin(t[2], t[4])));
        x1 = (int)ceil(fmax(t[0], fmax(t[2], t[4])));
        y0 = (int)floor(fmin(t[1], fmin(t[3], t[5])));
        y1 = (int)ceil(fmax(t[1], fmax(t[3], t[5])));
        if (x0 < 0) x0 = 0;
        if (y0 < 0) y0 = 0;
        if (x1 > atlas->width) x1 = atlas->width;
        if (y1 > atlas->height) y1 = atlas->height;
        for (y = y0; y < y1; ++y)
            for (x = x0; x < x1; ++x) {
                /* texel (x, row) has its centre at v = 1 - (row + 0.5) / height */
                int row = atlas->height - 1 - y;
                float alpha = atlas->pixels[4 * ((size_t)row * atlas->width + x) + 3];
                if (inside_depth(t, x + 0.5, y + 0.5) < 1.0) continue;
                CHECK(alpha >= 0.5f, "atlas texel (%d, %d) inside face %d has alpha %g", x, row, f, (double)alpha);
            }
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    reader rd;
    fz_alloc a;
    tt_mesh_desc desc;
    tt_mesh *mesh = NULL;
    tt_error err;
    tt_result r;
    tt_field_options fo;
    tt_field_constraint con;
    tt_lapped_options lo;
    tt_bake_options bo;
    tt_lapped *lapped = NULL, *again = NULL;
    tt_image *patches[2], *atlas = NULL, *normals[2] = {NULL, NULL};
    const tt_allocator *alloc;
    fz_progress ps;
    uint8_t flags, misc, hdr[24];
    int nverts, ntris, npatches = 1, f, v, k, gutter, extreme = 0;   /* extreme: some coordinate is an extreme float */
    int indices[3 * MAX_TRIS];
    float pos[3 * MAX_VERTS + 3], *field = NULL, *corner_uv = NULL;
    double lo3[3], hi3[3], diag, scale;

    rd.p = data;
    rd.n = size;
    rd.at = 0;
    memset(&desc, 0, sizeof desc);
    patches[0] = splotch_patch();
    patches[1] = NULL;

    for (k = 0; k < 24; ++k) hdr[k] = rd_u8(&rd);
    flags = hdr[0];
    nverts = hdr[1] % (MAX_VERTS + 1);
    ntris = hdr[2] % (MAX_TRIS + 1);
    alloc = fz_alloc_init(&a, (flags & 16) ? (long)hdr[4] + 1 : 0);
    misc = hdr[6];
    gutter = (flags >> 5) & 3;

    for (v = 0; v < nverts; ++v) {
        float t = (float)v / 8.0f;
        if (rd.n - rd.at >= 3) {
            for (k = 0; k < 3; ++k) {
                uint8_t b = rd_u8(&rd);
                /* extreme-float mode: a low byte is a value that breaks naive arithmetic */
                const int wild = (hdr[15] & 128) && b < 24;
                pos[3 * v + k] = wild ? fz_extreme_float(b) : (float)((int)b - 128) / 16.0f;
                extreme |= wild;
            }
        } else {
            pos[3 * v] = t;
            pos[3 * v + 1] = t * t;
            pos[3 * v + 2] = t * t * t;
        }
    }
    for (f = 0; f < ntris; ++f) {
        if (rd.n - rd.at < 3) break;
        for (k = 0; k < 3; ++k) {
            uint8_t b = rd_u8(&rd);
            indices[3 * f + k] = nverts > 0 ? b % nverts : b;
        }
    }
    ntris = f;

    desc.positions = pos;
    desc.nverts = nverts;
    desc.indices = indices;
    desc.nfaces = ntris;
    desc.fixed_face_size = 3;
    desc.flags = flags & TT_MESH_PERMISSIVE;
    memset(&err, 0x55, sizeof err);
    mesh = (tt_mesh *)&rd;
    r = tt_mesh_build(&desc, alloc, &mesh, &err);
    if (r != TT_OK) {
        fz_check_null("tt_mesh_build", r, mesh);
        check_error("tt_mesh_build", r, &err, &a);
        goto out;
    }

    /* ---- tangent field ---- */
    for (k = 0; k < 3; ++k) {
        lo3[k] = 1e300;
        hi3[k] = -1e300;
    }
    for (v = 0; v < nverts; ++v)
        for (k = 0; k < 3; ++k) {
            if (pos[3 * v + k] < lo3[k]) lo3[k] = pos[3 * v + k];
            if (pos[3 * v + k] > hi3[k]) hi3[k] = pos[3 * v + k];
        }
    diag = sqrt((hi3[0] - lo3[0]) * (hi3[0] - lo3[0]) + (hi3[1] - lo3[1]) * (hi3[1] - lo3[1]) +
                (hi3[2] - lo3[2]) * (hi3[2] - lo3[2]));
    scale = (float)((0.05 + 1.45 * hdr[3] / 255.0) * diag);
    field = (float *)malloc(sizeof(float) * 3 * (size_t)mesh->nfaces);
    if (!field) abort();
    memset(&fo, 0, sizeof fo);
    fo.up[0] = (float)((int)hdr[7] - 128);
    fo.up[1] = (float)((int)hdr[8] - 128);
    fo.up[2] = (float)((int)hdr[9] - 128);
    fo.scale = (float)scale;
    if (flags & 4) {
        double len;
        memset(&con, 0, sizeof con);
        con.face = hdr[10] % mesh->nfaces;
        for (k = 0; k < 3; ++k) con.vector[k] = (float)((int)hdr[11 + k] - 128);
        len = sqrt((double)con.vector[0] * con.vector[0] + (double)con.vector[1] * con.vector[1] +
                   (double)con.vector[2] * con.vector[2]);
        if (len > 0.0)
            for (k = 0; k < 3; ++k)
                con.vector[k] = (float)(con.vector[k] / len * scale * (0.5 + (hdr[14] & 15) / 10.0));
        con.sigma = (float)(diag * ((hdr[14] >> 4) & 7) / 8.0);
        con.weight = (hdr[14] & 128) ? 3.5f : 0.0f;
        fo.constraints = &con;
        fo.nconstraints = 1;
    }
    memset(&err, 0x55, sizeof err);
    if (flags & 128) {
        r = tt_tangent_field(mesh, NULL, alloc, field, &err);
    } else {
        r = tt_tangent_field(mesh, &fo, alloc, field, &err);
    }
    if (r != TT_OK) {
        check_error("tt_tangent_field", r, &err, &a);
        /* Valid options on a valid mesh: only a constraint can be refused.
           Extreme coordinates: the target's own scale (a fraction of the
           box's diagonal) may overflow to infinity, which must be refused,
           and the smoothing may overflow (TT_ERROR_NON_FINITE, documented). */
        CHECK(r == TT_ERROR_OUT_OF_MEMORY || (fo.nconstraints > 0 && !(flags & 128)) ||
                  (!(flags & 128) && !isfinite(fo.scale)) || (r == TT_ERROR_NON_FINITE && extreme),
              "tt_tangent_field failed without a constraint: %s", err.message);
        goto out;
    }
    if (flags & 128) {
        /* the default scale: a fraction of the used vertices' box */
        for (k = 0; k < 3; ++k) {
            lo3[k] = 1e300;
            hi3[k] = -1e300;
        }
        for (k = 0; k < mesh->ncorners; ++k) {
            int j;
            for (j = 0; j < 3; ++j) {
                double x = pos[3 * mesh->corner_vert[k] + j];
                if (x < lo3[j]) lo3[j] = x;
                if (x > hi3[j]) hi3[j] = x;
            }
        }
        scale = TT_DEFAULT_FIELD_SCALE * sqrt((hi3[0] - lo3[0]) * (hi3[0] - lo3[0]) +
                                              (hi3[1] - lo3[1]) * (hi3[1] - lo3[1]) +
                                              (hi3[2] - lo3[2]) * (hi3[2] - lo3[2]));
    }
    check_field(mesh, field, (flags & 4) && !(flags & 128), scale);

    /* ---- a second patch with a mask from the input ---- */
    if (flags & 8) {
        tt_image *src, *mask = NULL;
        tt_patch_options po;
        int x, y;
        src = fixed_source(40, 24);
        if (tt_image_create(40, 24, NULL, &mask, NULL) != TT_OK) abort();
        for (y = 0; y < 24; ++y)
            for (x = 0; x < 40; ++x) {
                int bit = (hdr[16 + y / 3] >> (x / 5)) & 1;
                float *p = mask->pixels + 4 * ((size_t)y * 40 + x);
                p[0] = p[1] = p[2] = (float)bit;
                p[3] = 1.0f;
            }
        memset(&po, 0, sizeof po);
        po.falloff = (float)(hdr[15] % 8) * 0.5f;
        memset(&err, 0x55, sizeof err);
        patches[1] = (tt_image *)&rd;
        r = tt_make_texture_patch(src, mask, &po, alloc, &patches[1], &err);
        if (r == TT_OK) {
            CHECK(patches[1]->width == 40 && patches[1]->height == 24 && patches[1]->pixels, "mask patch %dx%d",
                  patches[1]->width, patches[1]->height);
            npatches = 2;
        } else {
            check_error("tt_make_texture_patch", r, &err, &a);
            fz_check_null("tt_make_texture_patch", r, patches[1]);
            CHECK(r == TT_ERROR_INVALID_ARGUMENT || r == TT_ERROR_OUT_OF_MEMORY, "mask patch: %s", err.message);
        }
        tt_image_free(src);
        tt_image_free(mask);
    }

    /* ---- the paste loop ---- */
    memset(&lo, 0, sizeof lo);
    lo.seed = hdr[5];
    lo.isotropic = (flags >> 1) & 1;
    lo.max_pastes = MAX_PASTES;
    memset(&ps, 0, sizeof ps);
    if (misc & 2) {
        ps.cancel_after = misc >> 2;
        lo.progress = fz_on_progress;
        lo.progress_user_data = &ps;
    }
    memset(&err, 0x55, sizeof err);
    lapped = (tt_lapped *)&rd;
    r = tt_lapped_paste(mesh, field, patches, npatches, &lo, alloc, &lapped, &err);
    if (r != TT_OK) {
        check_error("tt_lapped_paste", r, &err, &a);
        fz_check_null("tt_lapped_paste", r, lapped);
        CHECK(r != TT_CANCELLED || (ps.cancel_after > 0 && ps.calls == ps.cancel_after),
              "cancelled after %d progress calls, asked after %d", ps.calls, ps.cancel_after);
        goto out;
    }
    CHECK(ps.cancel_after == 0 || ps.calls < ps.cancel_after, "not cancelled after %d calls", ps.calls);
    check_lapped(mesh, lapped, npatches);
    if (misc & 1) {
        long count_before = a.count;
        lo.progress = NULL;
        memset(&err, 0x55, sizeof err);
        again = (tt_lapped *)&rd;
        r = tt_lapped_paste(mesh, field, patches, npatches, &lo, alloc, &again, &err);
        if (r != TT_OK) {
            check_error("tt_lapped_paste (again)", r, &err, &a);
            fz_check_null("tt_lapped_paste (again)", r, again);
            CHECK(r == TT_ERROR_OUT_OF_MEMORY && a.fail_at > count_before, "second paste failed: %s", err.message);
        } else {
            CHECK(same_lapped(lapped, again), "same seed, different pastes (%d/%d pastes, %d/%d entries)",
                  lapped->npastes, again->npastes, lapped->nentries, again->nentries);
        }
        tt_lapped_free(again);
        again = NULL;
    }

    /* ---- measure ---- */
    {
        tt_lapped_report rep;
        memset(&err, 0x55, sizeof err);
        r = tt_lapped_measure(mesh, field, lapped, alloc, &rep, &err);
        if (r != TT_OK) check_error("tt_lapped_measure", r, &err, &a);
        CHECK(r == TT_OK || (r == TT_ERROR_OUT_OF_MEMORY && a.failed), "tt_lapped_measure returned %d", (int)r);
        if (r == TT_OK) {
            CHECK(rep.uncovered_faces == 0, "%d faces uncovered", rep.uncovered_faces);
            CHECK(fabs(rep.mean_overdraw - lapped->mean_overdraw) <= 1e-9 * lapped->mean_overdraw,
                  "overdraw %g measured %g", lapped->mean_overdraw, rep.mean_overdraw);
            if (!lo.isotropic) {
                CHECK(fabs(rep.mean_angle_error - lapped->mean_angle_error) <= 0.5 + 1e-3 * lapped->mean_angle_error,
                      "mean angle error %g, measured %g", lapped->mean_angle_error, rep.mean_angle_error);
                CHECK(fabs(rep.median_scale_error - lapped->median_scale_error) <=
                          1e-2 + 1e-3 * lapped->median_scale_error,
                      "median scale error %g, measured %g", lapped->median_scale_error, rep.median_scale_error);
            }
        }
    }

    /* ---- pair atlas and bake ---- */
    corner_uv = (float *)malloc(sizeof(float) * 2 * (size_t)mesh->ncorners);
    if (!corner_uv) abort();
    memset(&err, 0x55, sizeof err);
    r = tt_atlas_pack_pairs(mesh, ATLAS_SIZE, gutter, corner_uv, &err);
    if (r != TT_OK) {
        check_error("tt_atlas_pack_pairs", r, &err, &a);
        CHECK(r == TT_ERROR_IMAGE_TOO_SMALL, "tt_atlas_pack_pairs: %s", err.message);
        goto out;
    }
    for (k = 0; k < 2 * mesh->ncorners; ++k)
        CHECK(corner_uv[k] >= 0.0f && corner_uv[k] <= 1.0f, "atlas uv[%d] = %g", k, (double)corner_uv[k]);
    memset(&err, 0x55, sizeof err);
    atlas = (tt_image *)&rd;
    r = tt_image_create(ATLAS_SIZE, ATLAS_SIZE, alloc, &atlas, &err);
    if (r != TT_OK) {
        check_error("tt_image_create", r, &err, &a);
        fz_check_null("tt_image_create", r, atlas);
        CHECK(r == TT_ERROR_OUT_OF_MEMORY, "tt_image_create: %s", err.message);
        goto out;
    }
    memset(&bo, 0, sizeof bo);
    bo.gutter = gutter;
    memset(&err, 0x55, sizeof err);
    r = tt_lapped_bake(mesh, lapped, (tt_image *const *)patches, npatches, corner_uv, &bo, alloc, atlas, &err);
    if (r != TT_OK) {
        check_error("tt_lapped_bake", r, &err, &a);
        CHECK(r == TT_ERROR_OUT_OF_MEMORY, "tt_lapped_bake: %s", err.message);
        goto out;
    }
    check_atlas(mesh, atlas, corner_uv);

    /* ---- the same pastes baked from normal-map patches ---- */
    for (k = 0; k < npatches; ++k) {
        int i, n = patches[k]->width * patches[k]->height;
        memset(&err, 0x55, sizeof err);
        normals[k] = (tt_image *)&rd;
        r = tt_image_create(patches[k]->width, patches[k]->height, alloc, &normals[k], &err);
        if (r != TT_OK) {
            check_error("tt_image_create", r, &err, &a);
            fz_check_null("tt_image_create", r, normals[k]);
            CHECK(r == TT_ERROR_OUT_OF_MEMORY, "tt_image_create: %s", err.message);
            goto out;
        }
        normals[k]->kind = TT_IMAGE_NORMAL;
        for (i = 0; i < n; ++i) {
            float alpha = patches[k]->pixels[4 * i + 3];
            normals[k]->pixels[4 * i] = 0.3f * alpha;
            normals[k]->pixels[4 * i + 1] = (k ? -0.4f : 0.4f) * alpha;
            normals[k]->pixels[4 * i + 2] = 0.8660254f * alpha;
            normals[k]->pixels[4 * i + 3] = alpha;
        }
    }
    memset(&err, 0x55, sizeof err);
    r = tt_lapped_bake(mesh, lapped, (tt_image *const *)normals, npatches, corner_uv, &bo, alloc, atlas, &err);
    if (r != TT_OK) {
        check_error("tt_lapped_bake (normal maps)", r, &err, &a);
        CHECK(r == TT_ERROR_OUT_OF_MEMORY, "tt_lapped_bake (normal maps): %s", err.message);
        goto out;
    }
    CHECK(atlas->kind == TT_IMAGE_NORMAL, "a bake of normal-map patches made an atlas of kind %d", (int)atlas->kind);
    for (k = 0; k < ATLAS_SIZE * ATLAS_SIZE; ++k) {
        const float *p = atlas->pixels + 4 * (size_t)k;
        double length = sqrt((double)p[0] * p[0] + (double)p[1] * p[1] + (double)p[2] * p[2]);
        CHECK(fabs(length - 1.0) < 1e-5, "normal atlas texel %d has length %.9g", k, length);
    }

out:
    tt_image_free(normals[0]);
    tt_image_free(normals[1]);
    tt_image_free(atlas);
    tt_lapped_free(lapped);
    if (npatches == 2) tt_image_free(patches[1]);
    tt_mesh_free(mesh);
    free(field);
    free(corner_uv);
    fz_check_all_freed(&a);
    return 0;
}
