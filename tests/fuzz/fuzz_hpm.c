/* fuzz_hpm.c - libFuzzer target for hierarchical pattern mapping: the
   face-cluster hierarchy, the flattening of its clusters and tt_hpm_map, on
   small meshes and images so that one input takes milliseconds.

   Build (tests/fuzz/run.sh does this, with the library compiled once from
   tests/fuzz/fuzz_library.c):
       clang -g -O1 -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=all \
             -I. tests/fuzz/fuzz_hpm.c tests/fuzz/fuzz_library.c -o build/fuzz/fuzz_hpm -lm

   Input bytes, read front to back (missing bytes read as 0):
       0      bits 0..1 both set: allocation number byte[1] + 256 * (byte[2]
              & 7) + 1 fails (the out-of-memory paths); bit2 a progress
              callback (checked), cancelling after byte[3] % 8 calls (0 =
              never); bit3 tt_hpm_map with NULL options; bit4 map twice
              and compare (determinism); bit5 TT_HPM_TOROIDAL; bit6
              TT_HPM_RANDOM_PLACEMENT; bit7 TT_HPM_EXACT_CONTINUATION
       1, 2   which allocation fails (see above)
       3      cancel after (% 8); bit3 TT_HPM_NO_RELAXATION; bit4 the
              flattening's chord border; bit5 a max_stretch of 2;
              bit6 TT_MESH_PERMISSIVE; bit7 an extreme option double
              (byte[16] picks the field, byte[17] the value: fz_extreme_double)
       4      image: width 16 + 8 * (b & 3), height 16 + 8 * ((b >> 2) & 3),
              pattern b >> 4 (stripes, checks, noise, rings; grey or colour)
       5      scale: 0 = default, else (0.02 + b / 32) * the box's diagonal
       6      threshold: 0 = default, 255 = +infinity, else b / 64
       7      rotations: b % 65 (0 = default 19)
       8      max_turn: b * 180 / 255 degrees (0 = default)
       9      band: (b % 40) / 2 texels (0 = per cluster)
       10     min_faces: b % 24 (0 = default 16)
       11     min_footprint: b * 3 texels^2 (0 = default 576)
       12     branching: 0 = default, 250..255 out of range (1, 65, ...),
              else 2 + b % 63
       13, 14 seed
       15     max_flattening_error: 0 = default, else b / 100
       16, 17 the extreme option (byte[3] bit7)
       then   the mesh (fuzz_shape.h): a grid (at least 2 x 2 cells), sphere,
              torus or raw triangles with noise, or extreme floats in the
              coordinates

   match_size is 16 (the smallest), so the matching copy and its FFTs are
   tiny. Besides crashes, leaks and undefined behaviour it aborts when a
   result breaks the contract: a hierarchy whose clusters do not cover the
   faces level by level; a flattening that returns TT_OK with a non-finite
   UV or touches a corner outside its cluster, or fails and touches any;
   tt_hpm_map returning TT_OK with a non-finite UV, a UV outside [0, 1] for
   a bounded image, a face_cluster that is not an ancestor (or the leaf) of
   its face in the hierarchy of the same seed and branching (when no face
   moved in the border choice and no cluster continued a neighbour), or -1
   for a face with area and ordinary coordinates, or failing and
   touching corner_uv or face_cluster; a result other than the documented
   ones; a second run with the same input that differs; a progress fraction
   outside [0, 1] or going back; an error without a sentence, whose result
   differs, or out of memory when no allocation failed; an allocation not
   given back.

   It counts the runs whose tt_hpm_map reached a fit or a split (report fits
   + not_flat + no_room > 0: the deep stage) and prints the share at exit. */
#include "tiledtex.h"
#define FUZZ_NAME "fuzz_hpm"
#include "fuzz_common.h"
#include "fuzz_shape.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define MAX_FLATTENED 48    /* clusters flattened per input: keeps a run short */
#define SENTINEL 1234.5f    /* what corner_uv holds before a call: untouched must stay it */

/* The fuzz program's own counters (the library keeps none). */
static long runs, deep_runs;

static void print_share(void)
{
    if (runs > 0)
        fprintf(stderr, "fuzz_hpm: %ld of %ld runs (%.1f %%) reached a fit or a split\n", deep_runs, runs,
                100.0 * (double)deep_runs / (double)runs);
}

static float hash01(uint32_t x)
{
    x ^= x >> 16;
    x *= 0x7feb352du;
    x ^= x >> 15;
    x *= 0x846ca68bu;
    x ^= x >> 16;
    return (float)(x & 0xffffu) / 65535.0f;
}

/* A small linear RGBA image with some structure to match. */
static tt_image *make_image(uint8_t b, uint32_t seed)
{
    int w = 16 + 8 * (b & 3), h = 16 + 8 * ((b >> 2) & 3), pattern = b >> 4, x, y;
    tt_image *img = NULL;
    if (tt_image_create(w, h, NULL, &img, NULL) != TT_OK) abort();
    for (y = 0; y < h; ++y)
        for (x = 0; x < w; ++x) {
            float *p = img->pixels + 4 * ((size_t)y * w + x), v;
            switch (pattern & 3) {
            case 0: v = (float)((x / 3) & 1); break;
            case 1: v = (float)(((x / 4) ^ (y / 4)) & 1); break;
            case 2: v = hash01(seed * 7919u + (uint32_t)(y * w + x)); break;
            default: v = 0.5f + 0.5f * sinf(0.5f * sqrtf((float)((x - w / 2) * (x - w / 2) + (y - h / 3) * (y - h / 3))));
            }
            p[0] = v;
            p[1] = (pattern & 4) ? hash01((uint32_t)(x * 31 + y)) : v;
            p[2] = (pattern & 8) ? 1.0f - v : v;
            p[3] = 1.0f;
        }
    return img;
}

static void check_untouched(const char *what, const float *uv, int n)
{
    int k;
    for (k = 0; k < n; ++k) CHECK(uv[k] == SENTINEL, "%s failed but changed corner_uv[%d] to %g", what, k, (double)uv[k]);
}

/* Every level of the hierarchy holds every face once, children nest in
   their parents, and each face's leaf is a one-face cluster holding it. */
static void check_hierarchy(const tt_mesh *m, const tt_cluster_hierarchy *h)
{
    int c, f;
    CHECK(h->nclusters >= 1 && h->nlevels >= 1 && h->nfaces == m->nfaces, "%d clusters %d levels %d faces",
          h->nclusters, h->nlevels, h->nfaces);
    CHECK(h->level_start[0] == 0 && h->level_start[h->nlevels] == h->nclusters, "level_start %d..%d of %d",
          h->level_start[0], h->level_start[h->nlevels], h->nclusters);
    for (c = 0; c < h->nclusters; ++c) {
        const tt_cluster *cl = &h->clusters[c];
        CHECK(cl->nfaces >= 1 && cl->first_face >= 0 && cl->first_face + cl->nfaces <= h->nface_entries,
              "cluster %d faces %d+%d of %d", c, cl->first_face, cl->nfaces, h->nface_entries);
        CHECK(cl->level >= 0 && cl->level < h->nlevels, "cluster %d level %d", c, cl->level);
        CHECK(c >= h->level_start[cl->level] && c < h->level_start[cl->level + 1], "cluster %d not in its level %d", c,
              cl->level);
        CHECK((cl->level == 0) == (cl->parent == -1), "cluster %d level %d parent %d", c, cl->level, cl->parent);
        if (cl->parent >= 0) {
            const tt_cluster *pa = &h->clusters[cl->parent];
            CHECK(cl->parent < c && pa->level == cl->level - 1 && c >= pa->first_child &&
                      c < pa->first_child + pa->nchildren,
                  "cluster %d parent %d", c, cl->parent);
        }
        for (f = cl->first_face; f < cl->first_face + cl->nfaces; ++f)
            CHECK(h->faces[f] >= 0 && h->faces[f] < m->nfaces, "cluster %d face %d", c, h->faces[f]);
    }
    for (f = 0; f < m->nfaces; ++f) {
        int leaf = h->face_leaf[f];
        CHECK(leaf >= 0 && leaf < h->nclusters && h->clusters[leaf].nfaces == 1 &&
                  h->faces[h->clusters[leaf].first_face] == f,
              "face %d leaf %d", f, leaf);
    }
}

static int is_ancestor_or_self(const tt_cluster_hierarchy *h, int cluster, int leaf)
{
    for (; leaf >= 0; leaf = h->clusters[leaf].parent)
        if (leaf == cluster) return 1;
    return 0;
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
    tt_image *image = NULL;
    tt_cluster_hierarchy *hier = NULL;
    tt_cluster_options co;
    tt_flatten_options fo;
    tt_hpm_options ho;
    tt_hpm_report rep;
    tt_error err;
    tt_result r;
    const tt_allocator *alloc;
    uint8_t hdr[18];
    float *uv = NULL, *uv2 = NULL;
    int *fc = NULL, *fc2 = NULL, k, c, flattened = 0, expect_ok_options = 1;
    double lo3[3] = {1e300, 1e300, 1e300}, hi3[3] = {-1e300, -1e300, -1e300}, diag;

    if (!registered) {
        registered = 1;
        atexit(print_share);
    }
    rd.p = data;
    rd.n = size;
    rd.at = 0;
    for (k = 0; k < 18; ++k) hdr[k] = rd_u8(&rd);
    /* Grids of at least 2 x 2 cells: a 1 x 1 grid (two triangles, what a
       zero size byte gives) is one cluster placed at random, which never
       reaches a fit or a split; it was a sixth of the shallow runs. */
    fz_shape_read(&rd, &shape, 2);
    runs++;
    alloc = fz_alloc_init(&a, (hdr[0] & 3) == 3 ? (long)hdr[1] + 256L * (hdr[2] & 7) + 1 : 0);

    if (fz_shape_build(&shape, hdr[3] & 64, alloc, &a, &mesh) != TT_OK) goto out;
    image = make_image(hdr[4], (uint32_t)hdr[13] | (uint32_t)hdr[14] << 8);
    uv = (float *)malloc(sizeof(float) * 2 * (size_t)mesh->ncorners);
    uv2 = (float *)malloc(sizeof(float) * 2 * (size_t)mesh->ncorners);
    fc = (int *)malloc(sizeof(int) * (size_t)mesh->nfaces);
    fc2 = (int *)malloc(sizeof(int) * (size_t)mesh->nfaces);
    if (!uv || !uv2 || !fc || !fc2) abort();

    /* ---- the hierarchy and the flattening of its mappable clusters ---- */
    memset(&co, 0, sizeof co);
    co.seed = (uint64_t)hdr[13] | (uint64_t)hdr[14] << 8;
    co.branching = hdr[12] == 0 ? 0 : hdr[12] >= 250 ? (hdr[12] & 1 ? 1 : 65 + hdr[12] - 250) : 2 + hdr[12] % 63;
    memset(&err, 0x55, sizeof err);
    hier = (tt_cluster_hierarchy *)&rd;
    r = tt_cluster_hierarchy_build(mesh, &co, alloc, &hier, &err);
    if (r != TT_OK) {
        fz_check_null("tt_cluster_hierarchy_build", r, hier);
        fz_check_error("tt_cluster_hierarchy_build", r, &err, &a);
        CHECK(r == TT_ERROR_OUT_OF_MEMORY || (r == TT_ERROR_INVALID_ARGUMENT && hdr[12] >= 250),
              "tt_cluster_hierarchy_build: %s", err.message);
    } else {
        check_hierarchy(mesh, hier);
        memset(&fo, 0, sizeof fo);
        fo.border = (hdr[3] & 16) ? TT_FLATTEN_BORDER_CHORD : TT_FLATTEN_BORDER_PROJECTED;
        fo.max_stretch = (hdr[3] & 32) ? 2.0 : 0.0;
        fo.max_error = hdr[15] / 100.0;
        for (c = 0; c < hier->nclusters && flattened < MAX_FLATTENED; ++c) {
            const tt_cluster *cl = &hier->clusters[c];
            tt_flatten_report fr;
            if (!(cl->flags & TT_CLUSTER_MAPPABLE) && (c & 7)) continue; /* a few refusals too */
            flattened++;
            for (k = 0; k < 2 * mesh->ncorners; ++k) uv[k] = SENTINEL;
            memset(&err, 0x55, sizeof err);
            r = tt_flatten_cluster(mesh, hier, c, &fo, alloc, uv, &fr, &err);
            if (r != TT_OK) {
                fz_check_error("tt_flatten_cluster", r, &err, &a);
                check_untouched("tt_flatten_cluster", uv, 2 * mesh->ncorners);
                CHECK(r == TT_ERROR_NOT_FLAT || r == TT_ERROR_NOT_CONVERGED || r == TT_ERROR_OUT_OF_MEMORY ||
                          (r == TT_ERROR_NON_FINITE && shape.extreme) ||
                          (r == TT_ERROR_INVALID_ARGUMENT && !(cl->flags & TT_CLUSTER_MAPPABLE)),
                      "tt_flatten_cluster(%d): %d %s", c, (int)r, err.message);
                continue;
            }
            CHECK(cl->flags & TT_CLUSTER_MAPPABLE, "cluster %d is not mappable but flattened", c);
            CHECK(fr.mapped == 1 && fr.polygon_simple == 1 && fr.flipped == 0, "flatten %d: mapped %d simple %d flipped %d",
                  c, fr.mapped, fr.polygon_simple, fr.flipped);
            {
                /* its corners finite, every other corner untouched */
                char *in = (char *)calloc((size_t)mesh->nfaces, 1);
                if (!in) abort();
                for (k = cl->first_face; k < cl->first_face + cl->nfaces; ++k) in[hier->faces[k]] = 1;
                for (k = 0; k < mesh->ncorners; ++k) {
                    const float *p = uv + 2 * k;
                    if (in[mesh->corner_face[k]])
                        CHECK(isfinite(p[0]) && isfinite(p[1]), "flatten %d corner %d (%g, %g)", c, k, (double)p[0],
                              (double)p[1]);
                    else
                        CHECK(p[0] == SENTINEL && p[1] == SENTINEL, "flatten %d wrote corner %d outside it", c, k);
                }
                free(in);
            }
        }
    }

    /* ---- the pipeline ---- */
    for (k = 0; k < 3 * mesh->nverts; ++k) {
        double x = shape.pos[k];
        if (x < lo3[k % 3]) lo3[k % 3] = x;
        if (x > hi3[k % 3]) hi3[k % 3] = x;
    }
    diag = sqrt((hi3[0] - lo3[0]) * (hi3[0] - lo3[0]) + (hi3[1] - lo3[1]) * (hi3[1] - lo3[1]) +
                (hi3[2] - lo3[2]) * (hi3[2] - lo3[2]));
    memset(&ho, 0, sizeof ho);
    ho.seed = co.seed;
    ho.scale = hdr[5] ? (0.02 + hdr[5] / 32.0) * diag : 0.0;
    ho.threshold = hdr[6] == 255 ? HUGE_VAL : hdr[6] / 64.0;
    ho.rotations = hdr[7] % 65;
    ho.max_turn = hdr[8] * 180.0 / 255.0;
    ho.band = (hdr[9] % 40) / 2.0;
    ho.match_size = 16;
    ho.min_faces = hdr[10] % 24;
    ho.min_footprint = hdr[11] * 3.0;
    ho.flags = ((hdr[0] & 32) ? TT_HPM_TOROIDAL : 0) | ((hdr[0] & 64) ? TT_HPM_RANDOM_PLACEMENT : 0) |
               ((hdr[0] & 128) ? TT_HPM_EXACT_CONTINUATION : 0) | ((hdr[3] & 8) ? TT_HPM_NO_RELAXATION : 0);
    ho.branching = co.branching;
    ho.max_flattening_error = hdr[15] / 100.0;
    if (!(ho.scale >= 0.0 && isfinite(ho.scale))) ho.scale = 0.0; /* a mesh with extreme floats */
    if (hdr[3] & 128) {
        double v = fz_extreme_double(hdr[17]);
        switch (hdr[16] % 6) {
        case 0: ho.scale = v; break;
        case 1: ho.threshold = v; break;
        case 2: ho.max_turn = v; break;
        case 3: ho.band = v; break;
        case 4: ho.min_footprint = v; break;
        default: ho.max_flattening_error = v; break;
        }
        expect_ok_options = 0;
    }
    if (hdr[12] >= 250) expect_ok_options = 0;
    memset(&ps, 0, sizeof ps);
    if (hdr[0] & 4) {
        ps.cancel_after = hdr[3] % 8;
        ho.progress = fz_on_progress;
        ho.progress_user_data = &ps;
    }
    for (k = 0; k < 2 * mesh->ncorners; ++k) uv[k] = SENTINEL;
    for (k = 0; k < mesh->nfaces; ++k) fc[k] = -7;
    memset(&err, 0x55, sizeof err);
    memset(&rep, 0x55, sizeof rep);
    r = tt_hpm_map(mesh, image, (hdr[0] & 8) ? NULL : &ho, alloc, uv, fc, &rep, &err);
    if (r != TT_OK) {
        fz_check_error("tt_hpm_map", r, &err, &a);
        check_untouched("tt_hpm_map", uv, 2 * mesh->ncorners);
        for (k = 0; k < mesh->nfaces; ++k) CHECK(fc[k] == -7, "tt_hpm_map failed but wrote face_cluster[%d]", k);
        /* With valid options INVALID_ARGUMENT is only a scale the caller
           set at which a face does not fit (the default scale always fits);
           extreme coordinates may also make the scale non-finite. */
        CHECK(r == TT_ERROR_OUT_OF_MEMORY || r == TT_ERROR_ZERO_AREA_FACE ||
                  (r == TT_CANCELLED && ps.cancel_after > 0 && ps.calls == ps.cancel_after) ||
                  (r == TT_ERROR_INVALID_ARGUMENT && ho.scale > 0.0 && !(hdr[0] & 8)) || !expect_ok_options ||
                  shape.extreme,
              "tt_hpm_map: %d %s", (int)r, err.message);
        goto out;
    }
    CHECK(ps.cancel_after == 0 || ps.calls < ps.cancel_after, "not cancelled after %d calls", ps.calls);
    if (rep.fits + rep.not_flat + rep.no_room > 0) deep_runs++;
    CHECK(rep.clusters >= 1 && rep.fits == rep.accepted_fits + rep.floor_fits + rep.rejected_fits,
          "report: %d clusters, %d fits = %d + %d + %d", rep.clusters, rep.fits, rep.accepted_fits, rep.floor_fits,
          rep.rejected_fits);
    for (k = 0; k < 2 * mesh->ncorners; ++k) {
        CHECK(isfinite(uv[k]), "uv[%d] = %g", k, (double)uv[k]);
        if (!(ho.flags & TT_HPM_TOROIDAL) || (hdr[0] & 8))
            CHECK(uv[k] >= 0.0f && uv[k] <= 1.0f, "bounded image, uv[%d] = %g", k, (double)uv[k]);
    }
    /* A face shows its own cluster's map, unless the border choice moved it
       to a neighbour's or its small cluster continued a neighbour's map. */
    if (hier && !(hdr[0] & 8))
        for (k = 0; k < mesh->nfaces; ++k) {
            float n[3];
            tt_face_normal(mesh, k, n);
            /* -1: a face with no area, or (documented, though a refusal
               might be better) coordinates near FLT_MAX whose area overflows */
            if (fc[k] == -1 && ((n[0] == 0.0f && n[1] == 0.0f && n[2] == 0.0f) || shape.extreme)) continue;
            CHECK(fc[k] >= 0 && fc[k] < hier->nclusters, "face %d shows cluster %d of %d", k, fc[k], hier->nclusters);
            if (rep.faces_moved == 0 && rep.continued == 0 && rep.faces_unflattened == 0)
                CHECK(is_ancestor_or_self(hier, fc[k], hier->face_leaf[k]),
                      "face %d shows cluster %d, not one of its own (nothing moved or continued)", k, fc[k]);
        }
    if (hdr[0] & 16) {
        long count_before = a.count;
        tt_hpm_report rep2;
        ho.progress = NULL;
        memset(&err, 0x55, sizeof err);
        r = tt_hpm_map(mesh, image, (hdr[0] & 8) ? NULL : &ho, alloc, uv2, fc2, &rep2, &err);
        if (r != TT_OK) {
            fz_check_error("tt_hpm_map (again)", r, &err, &a);
            CHECK(r == TT_ERROR_OUT_OF_MEMORY && a.fail_at > count_before, "second run failed: %s", err.message);
        } else {
            CHECK(memcmp(uv, uv2, sizeof(float) * 2 * (size_t)mesh->ncorners) == 0 &&
                      memcmp(fc, fc2, sizeof(int) * (size_t)mesh->nfaces) == 0,
                  "same input, different UVs or clusters");
        }
    }

out:
    tt_cluster_hierarchy_free(hier == (tt_cluster_hierarchy *)&rd ? NULL : hier);
    tt_mesh_free(mesh);
    tt_image_free(image);
    fz_check_all_freed(&a);
    free(uv);
    free(uv2);
    free(fc);
    free(fc2);
    return 0;
}
