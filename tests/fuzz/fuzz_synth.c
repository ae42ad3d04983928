/* fuzz_synth.c - libFuzzer target for tiled-texture synthesis and what uses
   its atlas: tt_synthesize_tiles, tt_assign_boundaries (random or prescribed
   edge colours), tt_assign_uvs, tt_measure_seams; and the 8-bit image
   conversions tt_image_from_bytes / tt_image_to_rgba8.

   Build (tests/fuzz/run.sh does this, with the library compiled once from
   tests/fuzz/fuzz_library.c):
       clang -g -O1 -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=all \
             -I. tests/fuzz/fuzz_synth.c tests/fuzz/fuzz_library.c -o build/fuzz/fuzz_synth -lm

   Input bytes, read front to back (missing bytes read as 0):
       0      flags: bit0 non-finite texels (NaN, +inf, -inf) at byte 21..23,
              bit1 out-of-range texels (huge, negative, FLT_MAX, denormal)
              at byte 24..26, bit2 edge windows given (bytes 15..20), bit3
              prescribed edge colours (byte 27 on), bit4 make allocation number
              byte[1] + 1 fail, bit5 a cube (else a 2x2 grid of quads), bit6
              raw layout / feather (any value, mostly invalid), bit7 a progress
              callback cancelling after byte[28] & 7 calls (0 = never)
       1      which allocation fails (1-based) when bit4 is set
       2, 3   source width, height: 8 + b % 73 (8..80)
       4      colors: 1 + b % 3 (raw: (int8_t)b)
       5      tile size: 4 + b % 29 (raw: (int8_t)b)
       6      gutter: b % (tile size + 1) (raw: (int8_t)b)
       7      feather: (int8_t)b % 12 (-11..11: negative and too wide included)
       8, 9   synthesis seed
       10     background: b & 3 = 0 whole image, 1 a rect that fits, 2 raw bytes
              11..14 (x, y, w, h, may not fit), 3 negative or huge values;
              courses: b & 4 those tt_find_courses finds in the source (a
              finite one), b & 8 raw ones, period (int8_t)byte 11 / 4 (0, too
              short or negative included) and phase byte 12 / 3
       11..14 background rect bytes
       15..20 edge windows: x = b - 8, y = b' - 8 for colours 0..2 (out of range
              ones included)
       21..23 non-finite texel: column b % W, row b' % H, kind b'' % 3 (and a
              second one further on when b'' & 4)
       24..26 out-of-range texel: column, row, value (HUGE[b % 8])
       27     prescribed colours: per edge (b + 7 * edge) % (n + 2) - 1 (so -1..n:
              n is out of range); b & 0x80: one twin disagrees
       28     progress cancel count (bits 0..2), seam options max_edges (bits 3..5:
              0 all, 7 = -1 invalid, else that many), bit 6 NULL seam options,
              bit 7 the source is a normal map (its texels made unit vectors)
       29..35 tt_image_from_bytes: width, height (b % 24, 0 = 0; 255 = 32769),
              channels (b % 6), stride mode (b % 5: 0 packed, 1 exact, 2 padded,
              3 too short, 4 negative), colour space (b % 5: 0 sRGB, 1 linear,
              2 and 3 normal maps, 4 invalid), NULL
              data (b & 1), NULL out (b & 1)
       then   pixel bytes: the source is RGB from these bytes (cycled, with the
              position mixed in), decoded sRGB or linear by byte 0's parity of
              byte 29; the rest also feeds tt_image_from_bytes

   Checked, besides crashes, leaks and undefined behaviour:
     - synthesis: every documented refusal is predicted from the inputs (a
       non-finite texel gives TT_ERROR_NON_FINITE naming, by error->row and
       column, the first non-finite texel in row-major order; a layout that
       does not resolve, a negative or too wide feather, a background or edge
       window that does not fit, a source smaller than S x 2S each give their
       code), and valid inputs succeed (or run out of memory / are
       cancelled when asked). On success levels[0] is W x W with
       W = tt_tile_layout_atlas_size, every texel finite, in [0, 1] when the
       source was (a unit vector at every level from a normal-map source),
       alpha 1; each mip level half the one before and finite;
       edge windows S x 2S inside the source (the given ones when given);
     - boundaries: prescribed colours out of range give
       TT_ERROR_INDEX_OUT_OF_RANGE and twins that disagree
       TT_ERROR_INVALID_ARGUMENT, naming a corner that really is wrong; on
       success types below 2n, twins complementary, prescribed k kept;
     - UVs in [0, 1]; tt_measure_seams TT_OK (finite seam when samples > 0)
       or TT_ERROR_NOT_MEASURED (score NaN), a negative max_edges refused;
     - tt_image_from_bytes: the result predicted from the arguments; bytes ->
       image -> bytes (tt_image_to_rgba8, same space) is the identity for
       colour spaces; a normal space gives an image of kind normal holding
       unit vectors (alpha still exact both ways);
     - every failure: fz_check_error and fz_check_null (fuzz_common.h); the
       counting allocator's live count back to zero at the end. */
#include "tiledtex.h"
#define FUZZ_NAME "fuzz_synth"
#include "fuzz_common.h"

#include <float.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The atlas side is capped so one input stays well under a second with the
   sanitizers: (2n)^2 (S + 2g) <= MAX_ATLAS for valid layouts. */
#define MAX_ATLAS 640

static const float HUGE_TEXEL[8] = {1e30f, -1e30f, FLT_MAX, -FLT_MAX, -0.5f, 2.0f, 1e-40f, 3e38f};


static int is_finite_texel(const float *p) { return isfinite(p[0]) && isfinite(p[1]) && isfinite(p[2]) && isfinite(p[3]); }

/* ---- tt_image_from_bytes and the round trip --------------------------------- */

static void check_bytes(reader *rd, const uint8_t *hdr, fz_alloc *a)
{
    int w = hdr[29] % 24, h = hdr[30] % 24, channels = hdr[31] % 6, smode = hdr[32] % 5, space = hdr[33] % 5;
    int normal = space == TT_COLOR_NORMAL || space == TT_COLOR_NORMAL_Y_DOWN;
    int null_data = hdr[34] & 1, null_out = hdr[35] & 1, stride, row, x, y, k;
    size_t need = 1, i;
    unsigned char *data, *back;
    tt_image *img = (tt_image *)&stride;
    tt_error err;
    tt_result r, expect = TT_OK;
    if (hdr[29] == 255) w = TT_MAX_IMAGE_SIZE + 1;
    if (hdr[30] == 255) h = TT_MAX_IMAGE_SIZE + 1;
    row = w * channels;
    switch (smode) {
    case 0: stride = 0; break;
    case 1: stride = row; break;
    case 2: stride = row + 1 + hdr[32] % 7; break;
    case 3: stride = row - 1; break;
    default: stride = -1 - hdr[32]; break;
    }
    /* what the header promises, in its order of checks */
    if (null_out || null_data || channels < 1 || channels > 4 || space > 3 || (normal && channels < 3) || w < 1 ||
        h < 1)
        expect = TT_ERROR_INVALID_ARGUMENT;
    else if (w > TT_MAX_IMAGE_SIZE || h > TT_MAX_IMAGE_SIZE)
        expect = TT_ERROR_TOO_LARGE;
    else if (stride < 0 || (stride > 0 && stride < row))
        expect = TT_ERROR_INVALID_ARGUMENT;
    if (expect == TT_OK) need = (size_t)(h - 1) * (size_t)(stride ? stride : row) + (size_t)row;
    /* exactly `need` bytes, so AddressSanitizer sees a read past the last row */
    data = (unsigned char *)malloc(need);
    if (!data) abort();
    for (i = 0; i < need; ++i) data[i] = (uint8_t)(rd_u8(rd) ^ (uint8_t)(i * 37u));
    memset(&err, 0x55, sizeof err);
    r = tt_image_from_bytes(null_data ? NULL : data, w, h, channels, stride, (tt_color_space)space, &a->tt,
                            null_out ? NULL : &img, &err);
    if (expect != TT_OK) {
        CHECK(r == expect, "tt_image_from_bytes(%dx%d, %d channels, stride %d, space %d): %d, expected %d (%s)", w,
              h, channels, stride, space, (int)r, (int)expect, r == TT_OK ? "ok" : err.message);
        fz_check_error("tt_image_from_bytes", r, &err, a);
        if (!null_out) fz_check_null("tt_image_from_bytes", r, img);
        free(data);
        return;
    }
    if (r != TT_OK) {
        fz_check_error("tt_image_from_bytes", r, &err, a);
        fz_check_null("tt_image_from_bytes", r, img);
        CHECK(r == TT_ERROR_OUT_OF_MEMORY, "tt_image_from_bytes(%dx%d, %d channels, stride %d): %s", w, h, channels,
              stride, err.message);
        free(data);
        return;
    }
    CHECK(img->width == w && img->height == h && img->pixels, "image %dx%d from %dx%d", img->width, img->height, w, h);
    CHECK(img->kind == (normal ? TT_IMAGE_NORMAL : TT_IMAGE_COLOR), "space %d made an image of kind %d", space,
          (int)img->kind);
    if (normal)
        for (i = 0; i < (size_t)w * (size_t)h; ++i) {
            const float *p = img->pixels + 4 * i;
            double length = sqrt((double)p[0] * p[0] + (double)p[1] * p[1] + (double)p[2] * p[2]);
            CHECK(fabs(length - 1.0) < 1e-5, "space %d: texel %d is not a unit vector (length %g)", space, (int)i,
                  length);
        }
    back = (unsigned char *)malloc((size_t)w * h * 4);
    if (!back) abort();
    tt_image_to_rgba8(img, (tt_color_space)space, back);
    for (y = 0; y < h; ++y)
        for (x = 0; x < w; ++x) {
            const unsigned char *p = data + (size_t)y * (size_t)(stride ? stride : row) + (size_t)x * channels;
            const unsigned char *q = back + 4 * ((size_t)y * w + x);
            unsigned char want[4];
            switch (channels) {
            case 1: want[0] = want[1] = want[2] = p[0]; want[3] = 255; break;
            case 2: want[0] = want[1] = want[2] = p[0]; want[3] = p[1]; break;
            case 3: want[0] = p[0]; want[1] = p[1]; want[2] = p[2]; want[3] = 255; break;
            default: memcpy(want, p, 4); break;
            }
            for (k = normal ? 3 : 0; k < 4; ++k)
                CHECK(q[k] == want[k], "round trip (space %d, %d channels): texel %d,%d channel %d: %d -> %.9g -> %d",
                      space, channels, x, y, k, want[k], (double)img->pixels[4 * ((size_t)y * w + x) + k], q[k]);
        }
    free(back);
    free(data);
    tt_image_free(img);
}

/* ---- the source image ------------------------------------------------------- */

static tt_image *make_source(reader *rd, int w, int h, tt_color_space space, fz_alloc *a)
{
    size_t n = (size_t)w * h * 3, i, left = rd_left(rd), period = left ? left : 1;
    unsigned char *bytes = (unsigned char *)malloc(n);
    tt_image *img = NULL;
    tt_error err;
    tt_result r;
    if (!bytes) abort();
    for (i = 0; i < n; ++i) {
        uint8_t b = left ? rd->p[rd->at + i % left] : 0;
        bytes[i] = (uint8_t)(b + (uint8_t)((i / period) * 71u));   /* cycled input, shifted each round */
    }
    memset(&err, 0x55, sizeof err);
    r = tt_image_from_bytes(bytes, w, h, 3, 0, space, &a->tt, &img, &err);
    free(bytes);
    if (r != TT_OK) {
        fz_check_error("tt_image_from_bytes (source)", r, &err, a);
        fz_check_null("tt_image_from_bytes (source)", r, img);
        CHECK(r == TT_ERROR_OUT_OF_MEMORY, "source %dx%d: %s", w, h, err.message);
        return NULL;
    }
    return img;
}

/* ---- the mesh: a 2x2 grid of quads or a cube -------------------------------- */

static tt_mesh *make_mesh(int cube, fz_alloc *a)
{
    static const float grid_pos[27] = {0, 0, 0, 1, 0, 0, 2, 0, 0, 0, 1, 0, 1, 1, 0, 2, 1, 0, 0, 2, 0, 1, 2, 0, 2, 2, 0};
    static const int grid_idx[16] = {0, 1, 4, 3, 1, 2, 5, 4, 3, 4, 7, 6, 4, 5, 8, 7};
    static const float cube_pos[24] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0, 0, 1, 1, 0, 1, 1, 1, 1, 0, 1, 1};
    static const int cube_idx[24] = {0, 3, 2, 1, 4, 5, 6, 7, 0, 1, 5, 4, 1, 2, 6, 5, 2, 3, 7, 6, 3, 0, 4, 7};
    tt_mesh_desc desc;
    tt_mesh *mesh = (tt_mesh *)&desc;
    tt_error err;
    tt_result r;
    memset(&desc, 0, sizeof desc);
    desc.positions = cube ? cube_pos : grid_pos;
    desc.nverts = cube ? 8 : 9;
    desc.indices = cube ? cube_idx : grid_idx;
    desc.nfaces = cube ? 6 : 4;
    desc.fixed_face_size = 4;
    memset(&err, 0x55, sizeof err);
    r = tt_mesh_build(&desc, &a->tt, &mesh, &err);
    if (r != TT_OK) {
        fz_check_error("tt_mesh_build", r, &err, a);
        fz_check_null("tt_mesh_build", r, mesh);
        CHECK(r == TT_ERROR_OUT_OF_MEMORY, "the %s does not build: %s", cube ? "cube" : "grid", err.message);
        return NULL;
    }
    return mesh;
}

/* Boundaries (random or prescribed), UVs and the seam measure on the atlas. */
static void use_atlas(const tt_mesh *m, const tt_tileset *set, const tt_tile_layout *layout, const uint8_t *hdr,
                      int prescribed, fz_alloc *a)
{
    int n = set->layout.colors, c, bad_range = 0, bad_twin = 0;
    int *colors = NULL;
    uint8_t types[24];
    float uv[48];
    tt_error err;
    tt_result r;
    tt_seam_options so;
    tt_seam_report rep;
    if (prescribed) {
        int disagree = hdr[27] & 0x80, e = 0;
        colors = (int *)malloc(sizeof(int) * (size_t)m->ncorners);
        if (!colors) abort();
        for (c = 0; c < m->ncorners; ++c) colors[c] = -2;   /* not yet set */
        for (c = 0; c < m->ncorners; ++c) {
            int t = m->twin[c];
            if (colors[c] != -2) continue;
            colors[c] = (int)((hdr[27] + 7u * (unsigned)e) % (unsigned)(n + 2)) - 1;
            if (t >= 0) colors[t] = colors[c];
            ++e;
        }
        if (disagree) {
            /* the first interior half-edge gets another colour than its twin */
            for (c = 0; c < m->ncorners && m->twin[c] < 0; ++c) {}
            if (c < m->ncorners) colors[c] = colors[c] + 1 < n ? colors[c] + 1 : -1;
        }
        for (c = 0; c < m->ncorners; ++c) {
            if (colors[c] < -1 || colors[c] >= n) bad_range = 1;
            if (m->twin[c] >= 0 && colors[c] != colors[m->twin[c]]) bad_twin = 1;
        }
    }
    memset(&err, 0x55, sizeof err);
    r = tt_assign_boundaries(m, layout, (uint64_t)hdr[8] * 31u, colors, types, &err);
    if (r != TT_OK) {
        int k;
        fz_check_error("tt_assign_boundaries", r, &err, a);
        CHECK(bad_range || bad_twin, "tt_assign_boundaries refused valid colours: %s", err.message);
        CHECK((bad_range && r == TT_ERROR_INDEX_OUT_OF_RANGE) || (bad_twin && r == TT_ERROR_INVALID_ARGUMENT),
              "tt_assign_boundaries returned %d (out of range %d, twins disagree %d): %s", (int)r, bad_range,
              bad_twin, err.message);
        k = err.corner;
        CHECK(k >= 0 && k < m->ncorners, "tt_assign_boundaries names corner %d: %s", k, err.message);
        if (r == TT_ERROR_INDEX_OUT_OF_RANGE)
            CHECK(colors[k] < -1 || colors[k] >= n, "corner %d has colour %d, fine for %d colours: %s", k, colors[k],
                  n, err.message);
        else
            CHECK(m->twin[k] >= 0 && colors[k] != colors[m->twin[k]], "corner %d agrees with its twin: %s", k,
                  err.message);
        free(colors);
        return;
    }
    CHECK(!bad_range && !bad_twin, "tt_assign_boundaries accepted bad colours (range %d, twins %d)", bad_range,
          bad_twin);
    for (c = 0; c < m->ncorners; ++c) {
        CHECK(types[c] < 2 * n, "type[%d] = %d with %d colors", c, types[c], n);
        if (m->twin[c] >= 0)
            CHECK((types[m->twin[c]] ^ 1) == types[c], "types %d / %d across half-edge %d", types[c],
                  types[m->twin[c]], c);
        if (colors && colors[c] >= 0)
            CHECK(types[c] / 2 == colors[c], "corner %d: prescribed colour %d, type %d", c, colors[c], types[c]);
    }
    free(colors);

    memset(&err, 0x55, sizeof err);
    r = tt_assign_uvs(m, layout, types, uv, &err);
    CHECK(r == TT_OK, "tt_assign_uvs on a quad mesh with a layout that synthesised: %s", err.message);
    for (c = 0; c < 2 * m->ncorners; ++c) CHECK(uv[c] >= 0.0f && uv[c] <= 1.0f, "uv[%d] = %g", c, (double)uv[c]);

    memset(&so, 0, sizeof so);
    so.seed = hdr[9];
    so.max_edges = (hdr[28] >> 3) & 7;
    if (so.max_edges == 7) so.max_edges = -1;
    memset(&rep, 0x55, sizeof rep);
    memset(&err, 0x55, sizeof err);
    r = tt_measure_seams(m, uv, &set->levels[0], (hdr[28] & 64) ? NULL : &so, &a->tt, &rep, &err);
    if (!(hdr[28] & 64) && so.max_edges < 0) {
        CHECK(r == TT_ERROR_INVALID_ARGUMENT, "negative max_edges gave %d", (int)r);
        fz_check_error("tt_measure_seams", r, &err, a);
        return;
    }
    if (r == TT_OK) {
        CHECK(rep.samples >= 0 && rep.edges_measured >= 1, "seams: %d edges, %lld samples", rep.edges_measured,
              rep.samples);
        CHECK(rep.samples == 0 || (isfinite(rep.seam) && isfinite(rep.same_face) && isfinite(rep.unrelated)),
              "TT_OK with %lld samples but seam %g, same face %g, unrelated %g", rep.samples, rep.seam,
              rep.same_face, rep.unrelated);
        CHECK(rep.seam >= 0.0 && rep.seam <= 1.0, "seam difference %g", rep.seam);
    } else {
        fz_check_error("tt_measure_seams", r, &err, a);
        CHECK(r == TT_ERROR_NOT_MEASURED || (r == TT_ERROR_OUT_OF_MEMORY && a->failed), "tt_measure_seams: %d: %s",
              (int)r, err.message);
        if (r == TT_ERROR_NOT_MEASURED)
            CHECK(isnan(rep.score) && rep.samples == 0 && rep.edges_measured == 0, "not measured but %lld samples",
                  rep.samples);
    }
}

/* ---- synthesis ------------------------------------------------------------- */

static void check_tileset(const tt_tileset *set, const tt_tile_layout *layout, const tt_image *src, int in_unit,
                          int normal, const tt_rect *windows)
{
    tt_tile_layout res;
    int W, L, k, S;
    size_t i, n;
    CHECK(tt_tile_layout_resolve(layout, &res, NULL) == TT_OK, "a layout that synthesised does not resolve");
    CHECK(memcmp(&res, &set->layout, sizeof res) == 0, "tileset layout %d/%d/%d, resolved %d/%d/%d",
          set->layout.colors, set->layout.tile_size, set->layout.gutter, res.colors, res.tile_size, res.gutter);
    W = tt_tile_layout_atlas_size(&res);
    S = res.tile_size;
    CHECK(set->nlevels >= 1 && set->nlevels <= TT_MAX_MIP_LEVELS, "%d levels", set->nlevels);
    CHECK(set->seamless_levels >= 0 && set->seamless_levels <= set->nlevels, "%d seamless of %d levels",
          set->seamless_levels, set->nlevels);
    CHECK(set->levels[0].width == W && set->levels[0].height == W, "atlas %dx%d, W = %d", set->levels[0].width,
          set->levels[0].height, W);
    for (L = 0; L < set->nlevels; ++L) {
        const tt_image *im = &set->levels[L];
        if (L > 0)
            CHECK(im->width == set->levels[L - 1].width / 2 && im->height == set->levels[L - 1].height / 2,
                  "level %d is %dx%d after %dx%d", L, im->width, im->height, set->levels[L - 1].width,
                  set->levels[L - 1].height);
        n = (size_t)im->width * im->height;
        for (i = 0; i < n; ++i) {
            const float *p = im->pixels + 4 * i;
            CHECK(is_finite_texel(p), "level %d texel %lu (%g, %g, %g, %g) from a finite source", L,
                  (unsigned long)i, (double)p[0], (double)p[1], (double)p[2], (double)p[3]);
            CHECK(fabsf(p[3] - 1.0f) <= 1e-6f, "level %d texel %lu alpha %.9g", L, (unsigned long)i, (double)p[3]);
            if (normal) {
                double length = sqrt((double)p[0] * p[0] + (double)p[1] * p[1] + (double)p[2] * p[2]);
                CHECK(fabs(length - 1.0) < 1e-5, "level %d texel %lu of a normal map has length %.9g", L,
                      (unsigned long)i, length);
            } else if (in_unit)
                for (k = 0; k < 3; ++k)
                    CHECK(p[k] >= 0.0f && p[k] <= 1.0f, "level %d texel %lu channel %d = %.9g from a [0,1] source", L,
                          (unsigned long)i, k, (double)p[k]);
        }
    }
    for (k = 0; k < res.colors; ++k) {
        const tt_rect *r = &set->edge_windows[k];
        CHECK(r->w == S && r->h == 2 * S && r->x >= 0 && r->y >= 0 && r->x + S <= src->width &&
                  r->y + 2 * S <= src->height,
              "edge window %d at %d,%d %dx%d in a %dx%d source", k, r->x, r->y, r->w, r->h, src->width, src->height);
        if (windows)
            CHECK(r->x == windows[k].x && r->y == windows[k].y, "edge window %d at %d,%d, asked %d,%d", k, r->x, r->y,
                  windows[k].x, windows[k].y);
    }
    n = (size_t)tt_tile_layout_tile_count(&res);
    for (i = 0; i < n; ++i) {
        const tt_rect *r = &set->background_windows[i];
        CHECK(r->x >= 0 && r->y >= 0 && r->x + S <= src->width && r->y + S <= src->height,
              "background window %lu at %d,%d in a %dx%d source", (unsigned long)i, r->x, r->y, src->width,
              src->height);
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    reader rd;
    fz_alloc a;
    uint8_t hdr[36], flags;
    int w, h, k, raw, S, g, n, T, feather, in_unit = 1, nonfinite = 0, first_bad = -1, layout_ok;
    int bg_ok = 1, windows_ok = 1, courses_ok, big_enough;
    tt_image *src = NULL;
    tt_tileset *set = NULL;
    tt_mesh *mesh = NULL;
    tt_synth_options opt;
    tt_tile_layout resolved;
    tt_rect windows[3];
    fz_progress ps;
    tt_error err;
    tt_result r;

    rd.p = data;
    rd.n = size;
    rd.at = 0;
    for (k = 0; k < 36; ++k) hdr[k] = rd_u8(&rd);
    flags = hdr[0];
    fz_alloc_init(&a, (flags & 16) ? (long)hdr[1] + 1 : 0);

    check_bytes(&rd, hdr, &a);
    fz_check_all_freed(&a);

    /* ---- the source ---- */
    w = 8 + hdr[2] % 73;
    h = 8 + hdr[3] % 73;
    src = make_source(&rd, w, h, (tt_color_space)(hdr[29] & 1), &a);
    if (!src) goto out;
    if (hdr[28] & 0x80) {
        /* a normal map: each texel's colour read as a vector and made unit */
        src->kind = TT_IMAGE_NORMAL;
        for (k = 0; k < w * h; ++k) {
            float *p = src->pixels + 4 * (size_t)k;
            double x = 2.0 * p[0] - 1.0, y = 2.0 * p[1] - 1.0, z = 2.0 * p[2] - 1.0, l = sqrt(x * x + y * y + z * z);
            if (!(l > 1e-6)) { x = 0.0; y = 0.0; z = 1.0; l = 1.0; }
            p[0] = (float)(x / l);
            p[1] = (float)(y / l);
            p[2] = (float)(z / l);
        }
    }
    if (flags & 2) {
        float *p = src->pixels + 4 * ((size_t)(hdr[25] % h) * w + hdr[24] % w);
        p[hdr[26] % 3] = HUGE_TEXEL[hdr[26] % 8];
        in_unit = 0;
    }
    if (flags & 1) {
        static const float kinds[3] = {NAN, INFINITY, -INFINITY};
        int x = hdr[21] % w, y = hdr[22] % h;
        src->pixels[4 * ((size_t)y * w + x) + hdr[23] % 4] = kinds[hdr[23] % 3];
        if (hdr[23] & 4) src->pixels[4 * ((size_t)(h - 1 - y) * w + (w - 1 - x))] = kinds[(hdr[23] + 1) % 3];
        nonfinite = 1;
        for (k = 0; k < w * h; ++k)
            if (!is_finite_texel(src->pixels + 4 * (size_t)k)) {
                first_bad = k;
                break;
            }
    }

    /* ---- layout and options ---- */
    raw = (flags & 64) != 0;
    memset(&opt, 0, sizeof opt);
    if (raw) {
        opt.layout.colors = (int8_t)hdr[4];
        opt.layout.tile_size = (int8_t)hdr[5] * ((hdr[6] & 1) ? 1 : 300);
        opt.layout.gutter = (int8_t)hdr[6];
    } else {
        n = 1 + hdr[4] % 3;
        S = 4 + hdr[5] % 29;
        g = hdr[6] % (S + 1);
        T = 4 * n * n;
        /* keep the atlas small: shrink the gutter, then the tile */
        while (T * (S + 2 * g) > MAX_ATLAS && g > 0) g /= 2;
        while (T * (S + 2 * g) > MAX_ATLAS && S > 4) S--;
        opt.layout.colors = n;
        opt.layout.tile_size = S;
        opt.layout.gutter = g;
    }
    layout_ok = tt_tile_layout_resolve(&opt.layout, &resolved, NULL) == TT_OK;
    if (layout_ok) {
        S = resolved.tile_size;
        n = resolved.colors;
        if (tt_tile_layout_atlas_size(&resolved) > MAX_ATLAS) goto out;   /* raw layouts: too slow */
    } else {
        S = 4;
        n = 1;
    }
    opt.seed = (uint64_t)hdr[8] | (uint64_t)hdr[9] << 8;
    opt.feather = (int8_t)hdr[7] % 12;
    feather = opt.feather > 0 ? opt.feather : (S / 16 > 2 ? S / 16 : 2);
    switch (hdr[10] & 3) {
    case 0: break;
    case 1:
        if (w >= S && h >= S) {
            opt.background.w = S + hdr[13] % (w - S + 1);
            opt.background.h = S + hdr[14] % (h - S + 1);
            opt.background.x = hdr[11] % (w - opt.background.w + 1);
            opt.background.y = hdr[12] % (h - opt.background.h + 1);
        }
        break;
    case 2:
        opt.background.x = hdr[11];
        opt.background.y = hdr[12];
        opt.background.w = hdr[13];
        opt.background.h = hdr[14];
        break;
    default:
        opt.background.x = (hdr[11] & 1) ? INT_MIN : -(int)hdr[11];
        opt.background.y = (hdr[12] & 1) ? INT_MAX : hdr[12];
        opt.background.w = (hdr[13] & 1) ? INT_MAX : -(int)hdr[13];
        opt.background.h = (hdr[14] & 1) ? INT_MIN : hdr[14];
        break;
    }
    {
        tt_rect b = opt.background;
        if (b.x == 0 && b.y == 0 && b.w == 0 && b.h == 0) {
            b.w = w;
            b.h = h;
        }
        bg_ok = b.x >= 0 && b.y >= 0 && b.w >= S && b.h >= S && (long long)b.x + b.w <= w && (long long)b.y + b.h <= h;
    }
    if (flags & 4) {
        for (k = 0; k < 3; ++k) {
            windows[k].x = (int)hdr[15 + 2 * k] - 8;
            windows[k].y = (int)hdr[16 + 2 * k] - 8;
            windows[k].w = windows[k].h = 0;
        }
        opt.edge_windows = windows;
        for (k = 0; k < n && k < 3; ++k)
            if (windows[k].x < 0 || windows[k].y < 0 || windows[k].x + S > w || windows[k].y + 2 * S > h)
                windows_ok = 0;
        if (n > 3) goto out;    /* only 3 windows given: a larger raw n would read past them */
    }
    if ((hdr[10] & 4) && !nonfinite) {
        tt_courses found;
        memset(&err, 0x55, sizeof err);
        r = tt_find_courses(src, &a.tt, &found, &err);
        if (r != TT_OK) {
            fz_check_error("tt_find_courses", r, &err, &a);
            CHECK(r == TT_ERROR_OUT_OF_MEMORY && a.failed, "tt_find_courses on a finite source: %d: %s", (int)r,
                  err.message);
            goto out;
        }
        CHECK(found.period == 0.0f ? found.phase == 0.0f && found.strength == 0.0f
                                   : found.period >= 2.0f && found.period <= h / 3.0f + 1.0f && found.phase >= 0.0f &&
                                         found.phase < found.period && found.strength >= TT_COURSES_MIN_STRENGTH &&
                                         found.strength <= 1.0f,
              "courses of a %dx%d source: period %g, phase %g, strength %g", w, h, (double)found.period,
              (double)found.phase, (double)found.strength);
        opt.courses = found;
    } else if (hdr[10] & 8) {
        opt.courses.period = (float)(int8_t)hdr[11] / 4.0f;
        opt.courses.phase = (float)hdr[12] / 3.0f;
    }
    courses_ok = opt.courses.period == 0.0f || opt.courses.period >= 2.0f;
    memset(&ps, 0, sizeof ps);
    if (flags & 128) {
        ps.cancel_after = hdr[28] & 7;
        opt.progress = fz_on_progress;
        opt.progress_user_data = &ps;
    }
    big_enough = w >= S && h >= 2 * S;

    memset(&err, 0x55, sizeof err);
    set = (tt_tileset *)&rd;
    r = tt_synthesize_tiles(src, &opt, &a.tt, &set, &err);
    if (r != TT_OK) {
        fz_check_error("tt_synthesize_tiles", r, &err, &a);
        fz_check_null("tt_synthesize_tiles", r, set);
        if (nonfinite) {
            const float *p;
            CHECK(r == TT_ERROR_NON_FINITE, "a source with a non-finite texel gave %d: %s", (int)r, err.message);
            CHECK(err.row >= 0 && err.row < h && err.column >= 0 && err.column < w, "texel row %d column %d of %dx%d",
                  err.row, err.column, w, h);
            p = src->pixels + 4 * ((size_t)err.row * w + err.column);
            CHECK(!is_finite_texel(p), "the error names texel (row %d, column %d) = (%g, %g, %g, %g): finite",
                  err.row, err.column, (double)p[0], (double)p[1], (double)p[2], (double)p[3]);
            CHECK(err.row * w + err.column == first_bad, "the error names texel %d, the first non-finite is %d",
                  err.row * w + err.column, first_bad);
            goto out;
        }
        if (r == TT_ERROR_OUT_OF_MEMORY) goto out;
        if (r == TT_CANCELLED) {
            CHECK(ps.cancel_after > 0 && ps.calls == ps.cancel_after, "cancelled after %d calls, asked after %d",
                  ps.calls, ps.cancel_after);
            goto out;
        }
        /* huge texels may overflow a cut's cost: a specific NON_FINITE */
        if (r == TT_ERROR_NON_FINITE && !in_unit) goto out;
        CHECK(!layout_ok || !big_enough || !bg_ok || !windows_ok || !courses_ok || opt.feather < 0 ||
                  feather > S / 4 + 1,
              "valid synthesis refused (layout %d/%d/%d, feather %d, source %dx%d): %s", opt.layout.colors,
              opt.layout.tile_size, opt.layout.gutter, opt.feather, w, h, err.message);
        if (!layout_ok)
            CHECK(r == TT_ERROR_INVALID_ARGUMENT || r == TT_ERROR_TOO_LARGE, "bad layout gave %d: %s", (int)r,
                  err.message);
        else if (!big_enough)
            CHECK(r == TT_ERROR_IMAGE_TOO_SMALL, "source %dx%d for tile %d gave %d: %s", w, h, S, (int)r, err.message);
        else
            CHECK(r == TT_ERROR_INVALID_ARGUMENT || r == TT_ERROR_IMAGE_TOO_SMALL, "bad options gave %d: %s", (int)r,
                  err.message);
        goto out;
    }
    CHECK(!nonfinite, "synthesis accepted a non-finite texel (first at %d)", first_bad);
    CHECK(layout_ok && big_enough && bg_ok && windows_ok && courses_ok, "synthesis accepted bad input: layout %d, "
          "source %d, background %d, windows %d, courses %d", layout_ok, big_enough, bg_ok, windows_ok, courses_ok);
    CHECK(opt.feather >= 0, "synthesis accepted feather %d", opt.feather);
    CHECK(feather <= S / 4 + 1, "synthesis accepted feather %d for %d-texel tiles", feather, S);
    CHECK(ps.cancel_after == 0 || ps.calls < ps.cancel_after, "not cancelled after %d calls", ps.calls);
    check_tileset(set, &opt.layout, src, in_unit, src->kind == TT_IMAGE_NORMAL, (flags & 4) ? windows : NULL);

    mesh = make_mesh((flags & 32) != 0, &a);
    if (mesh) use_atlas(mesh, set, &opt.layout, hdr, (flags & 8) != 0, &a);

out:
    tt_mesh_free(mesh);
    tt_tileset_free(set);
    tt_image_free(src);
    fz_check_all_freed(&a);
    return 0;
}
