/* tests/test_6_tiled_synthesis.c - unit tests for section 6 of tiledtex.h,
   tile-set synthesis as a plan and its application: tt_synth_plan_create,
   tt_synth_apply, tt_synth_compose_tile, the plan's depths and masks, and
   tt_synthesize_tiles (bit-identical to the algorithm before the split).
   Run by run_tiled_synthesis_tests(). Uses CHECK / RUN, make_allocator and
   oom_reset / oom_sweep from test_common.h and nothing else of it; its
   images are made here. */
#include "test_common.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void run_tiled_synthesis_tests(void);

/* ------------------------------------------------------------------------ */
/* Images                                                                   */
/* ------------------------------------------------------------------------ */

/* Integer hash lattice and bilinear value noise using only + - * / on
   floats, so the image is the same bits on every IEEE machine and compiler
   (the hashes below depend on it). */
static uint32_t sy_hash(uint32_t x, uint32_t y, uint32_t s)
{
    uint32_t h = x * 0x8da6b343u ^ y * 0xd8163841u ^ s * 0xcb1ab31fu;
    h ^= h >> 13;
    h *= 0x85ebca6bu;
    h ^= h >> 16;
    h *= 0xc2b2ae35u;
    h ^= h >> 15;
    return h;
}

static float sy_lattice(int x, int y, uint32_t s)
{
    return (float)(sy_hash((uint32_t)x, (uint32_t)y, s) >> 8) / 16777216.0f;
}

static float sy_value_noise(int x, int y, int scale, uint32_t s)
{
    int cx = x / scale, cy = y / scale;
    float fx = (float)(x % scale) / (float)scale, fy = (float)(y % scale) / (float)scale;
    float a = sy_lattice(cx, cy, s), b = sy_lattice(cx + 1, cy, s);
    float c = sy_lattice(cx, cy + 1, s), d = sy_lattice(cx + 1, cy + 1, s);
    float top = a + (b - a) * fx, bottom = c + (d - c) * fx;
    return top + (bottom - top) * fy;
}

/* A w x h photograph-like image (noise at 7 and 19 texels plus grain, opaque). */
static tt_image *sy_noise(int w, int h, uint32_t seed)
{
    tt_image *im = NULL;
    int x, y, k;
    if (tt_image_create(w, h, NULL, &im, NULL) != TT_OK) return NULL;
    for (y = 0; y < h; y++)
        for (x = 0; x < w; x++) {
            float *p = im->pixels + ((size_t)y * w + x) * 4;
            for (k = 0; k < 3; k++) {
                uint32_t s = seed * 4u + (uint32_t)k;
                p[k] = 0.45f * sy_value_noise(x, y, 7, s) + 0.35f * sy_value_noise(x, y, 19, s + 100u) +
                       0.2f * sy_lattice(x, y, s + 200u);
            }
            p[3] = 1.0f;
        }
    return im;
}

static tt_image *sy_copy(const tt_image *src)
{
    tt_image *im = NULL;
    if (tt_image_create(src->width, src->height, NULL, &im, NULL) != TT_OK) return NULL;
    memcpy(im->pixels, src->pixels, (size_t)src->width * src->height * 4 * sizeof(float));
    return im;
}

static float *sy_px(const tt_image *im, int x, int y) { return im->pixels + ((size_t)y * im->width + x) * 4; }

static size_t sy_floats(const tt_image *im) { return (size_t)im->width * (size_t)im->height * 4; }

/* FNV-1a over the IEEE bits of every float, least significant byte first
   (the bytes of a little-endian machine, on any machine). */
static uint64_t sy_hash_image(uint64_t h, const tt_image *im)
{
    size_t i, n = sy_floats(im);
    for (i = 0; i < n; i++) {
        uint32_t bits;
        int b;
        memcpy(&bits, &im->pixels[i], sizeof bits);
        for (b = 0; b < 4; b++) {
            h ^= (bits >> (8 * b)) & 0xffu;
            h *= 1099511628211ull;
        }
    }
    return h;
}

static int sy_same_levels(const tt_tileset *a, const tt_tileset *b)
{
    int l;
    if (a->nlevels != b->nlevels || a->seamless_levels != b->seamless_levels) return 0;
    for (l = 0; l < a->nlevels; l++)
        if (a->levels[l].width != b->levels[l].width || a->levels[l].height != b->levels[l].height ||
            memcmp(a->levels[l].pixels, b->levels[l].pixels, sy_floats(&a->levels[l]) * sizeof(float)) != 0)
            return 0;
    return 1;
}

/* Does `msg` hold the decimal number n as a whole token? */
static int sy_has_number(const char *msg, int n)
{
    char digits[16];
    const char *p = msg;
    size_t len;
    sprintf(digits, "%d", n);
    len = strlen(digits);
    while ((p = strstr(p, digits)) != NULL) {
        int before = p > msg && (p[-1] >= '0' && p[-1] <= '9');
        int after = p[len] >= '0' && p[len] <= '9';
        if (!before && !after) return 1;
        p += len;
    }
    return 0;
}

/* Half an allocator (free without alloc), which every function refuses. */
static void sy_free(void *ptr, void *user_data)
{
    (void)user_data;
    free(ptr);
}

static tt_synth_options sy_options(int colors, int size, int gutter, uint64_t seed)
{
    tt_synth_options o;
    memset(&o, 0, sizeof o);
    o.layout.colors = colors;
    o.layout.tile_size = size;
    o.layout.gutter = gutter;
    o.seed = seed;
    return o;
}

/* The types of tile t (tt_tile_index numbering) and its cell's top-left. */
static void sy_tile_types(const tt_tile_layout *layout, int t, uint8_t types[4], int *cell_x, int *cell_y)
{
    int base = 2 * layout->colors, T = base * base, C = layout->tile_size + 2 * layout->gutter;
    int column = t % T, row = t / T;
    types[0] = (uint8_t)(column / base);
    types[1] = (uint8_t)(column % base);
    types[2] = (uint8_t)(row / base);
    types[3] = (uint8_t)(row % base);
    *cell_x = column * C;
    *cell_y = (T - 1 - row) * C;
}

/* ------------------------------------------------------------------------ */
/* Bit identity with the algorithm before the split                         */
/* ------------------------------------------------------------------------ */

/* Hashes of tt_synthesize_tiles's output: level 0 alone, then every level,
   the same with gcc -O0/-O2, clang -O2 and tcc. First made by the
   single-pass algorithm of branch `api` (commit e9e89f0, before synthesis
   became a plan and its application), which the plan matched bit for bit;
   made again when bands that both reach a corner's diagonal came to meet
   there (tt__band_alpha), the one change since. Configurations: n, S, g,
   feather, seed, given edge windows, background region, source size. That
   algorithm drew one random background window per tile:
   background_candidates = 1. */
typedef struct sy_reference {
    int colors, size, gutter, feather;
    unsigned seed;
    int given_windows, background_region, width, height;
    uint64_t level0, all_levels;
} sy_reference;

static const sy_reference sy_references[] = {
    {1, 32, 0, 0, 1u, 0, 0, 96, 128, 0x4d2c0b00b43e3352ull, 0x6a7d76c88ca4851dull},
    {1, 32, 4, 3, 7u, 1, 0, 96, 128, 0xe99e9a6d0746d0d5ull, 0xeb96f76e9cc6bccaull},
    {2, 16, 4, 0, 3u, 0, 0, 80, 96, 0x5e1053b1ec5e1c49ull, 0x91b2a6e13919c9c2ull},
    {2, 16, 0, 2, 11u, 1, 1, 80, 96, 0x2312781f478aa8bbull, 0xba326f00a8bddf63ull},
    {1, 64, 4, 0, 5u, 0, 0, 160, 192, 0xc69e1ab178d3d981ull, 0x8d81c3671455e333ull},
};

static void sy_reference_options(const sy_reference *ref, tt_rect windows[2], tt_synth_options *o)
{
    *o = sy_options(ref->colors, ref->size, ref->gutter, ref->seed);
    o->feather = ref->feather;
    o->background_candidates = 1;
    memset(windows, 0, 2 * sizeof *windows);
    windows[0].x = 5;
    windows[0].y = 9;
    windows[1].x = ref->width - ref->size - 3;
    windows[1].y = ref->height - 2 * ref->size - 1;
    if (ref->given_windows) o->edge_windows = windows;
    if (ref->background_region) {
        o->background.x = 10;
        o->background.y = 20;
        o->background.w = 50;
        o->background.h = 40;
    }
}

/* The mean grey of window r of `image`, every texel. */
static double sy_window_tone(const tt_image *image, const tt_rect *r)
{
    double sum = 0.0;
    int x, y;
    for (y = r->y; y < r->y + r->h; y++)
        for (x = r->x; x < r->x + r->w; x++) {
            const float *p = image->pixels + ((size_t)y * image->width + x) * 4;
            sum += ((double)p[0] + p[1] + p[2]) / 3.0;
        }
    return sum / ((double)r->w * r->h);
}

/* The spread (standard deviation) of the tiles' background tones. */
static double sy_background_spread(const tt_image *image, const tt_rect *windows, int n)
{
    double sum = 0.0, sum2 = 0.0;
    int t;
    for (t = 0; t < n; t++) {
        const double tone = sy_window_tone(image, &windows[t]);
        sum += tone;
        sum2 += tone * tone;
    }
    return sqrt(fmax(0.0, sum2 / n - (sum / n) * (sum / n)));
}

/* On a photo whose tone drifts slowly (a dark-to-bright ramp under the
   noise), the backgrounds chosen nearest the image's tone spread far less
   in tone than the paper's single random window per tile (the control,
   background_candidates = 1, must spread widely), and stay within the
   region; a count past the limit is refused. */
static void test_background_tone(void)
{
    tt_image *src = sy_noise(160, 160, 77u);
    tt_synth_options o = sy_options(2, 16, 2, 9u);
    tt_synth_plan *matched = NULL, *random = NULL, *bad = NULL;
    tt_error err;
    int x, y, k, t, ntiles, inside = 1;
    double spread_matched, spread_random;
    for (y = 0; y < 160; y++)
        for (x = 0; x < 160; x++)
            for (k = 0; k < 3; k++) src->pixels[((size_t)y * 160 + x) * 4 + k] += 1.5f * (float)x / 159.0f;
    o.background.x = 8;
    o.background.y = 4;
    o.background.w = 150;
    o.background.h = 150;
    CHECK(tt_synth_plan_create(src, &o, NULL, &matched, &err) == TT_OK, "default plan: %s", err.message);
    o.background_candidates = 1;
    CHECK(tt_synth_plan_create(src, &o, NULL, &random, &err) == TT_OK, "one-candidate plan: %s", err.message);
    if (matched && random) {
        ntiles = tt_tile_layout_tile_count(&matched->layout);
        spread_matched = sy_background_spread(src, matched->background_windows, ntiles);
        spread_random = sy_background_spread(src, random->background_windows, ntiles);
        for (t = 0; t < ntiles; t++) {
            const tt_rect *r = &matched->background_windows[t];
            inside &= r->x >= 8 && r->y >= 4 && r->x + r->w <= 158 && r->y + r->h <= 154 && r->w == 16 && r->h == 16;
        }
        printf("     background tone spread: %.4f nearest the image's tone, %.4f one random window each\n",
               spread_matched, spread_random);
        CHECK(spread_random > 0.3 && spread_matched < 0.3 * spread_random && inside,
              "background tones over %d tiles spread %.4f nearest the image's tone, %.4f one random window each "
              "(the control); inside the region: %d", ntiles, spread_matched, spread_random, inside);
    }
    o.background_candidates = TT_SYNTH_MAX_BACKGROUND_CANDIDATES + 1;
    CHECK(tt_synth_plan_create(src, &o, NULL, &bad, &err) == TT_ERROR_INVALID_ARGUMENT && !bad &&
              strstr(err.message, "background_candidates"),
          "too many background candidates refused: %s", err.message);
    o.background_candidates = -1;
    CHECK(tt_synth_plan_create(src, &o, NULL, &bad, &err) == TT_ERROR_INVALID_ARGUMENT && !bad,
          "negative background candidates refused: %s", err.message);
    tt_synth_plan_free(matched);
    tt_synth_plan_free(random);
    tt_image_free(src);
}

static void test_synthesize_matches_old_algorithm(void)
{
    size_t i;
    for (i = 0; i < sizeof sy_references / sizeof sy_references[0]; i++) {
        const sy_reference *ref = &sy_references[i];
        tt_image *src = sy_noise(ref->width, ref->height, ref->seed + 1000u);
        tt_synth_options o;
        tt_rect windows[2];
        tt_tileset *set = NULL, *applied = NULL;
        tt_synth_plan *plan = NULL;
        tt_error err;
        tt_result r;
        uint64_t h0 = 1469598103934665603ull, all;
        int l;
        sy_reference_options(ref, windows, &o);
        r = tt_synthesize_tiles(src, &o, NULL, &set, &err);
        CHECK(r == TT_OK, "config %d: tt_synthesize_tiles: %d (%s)", (int)i, r, err.message);
        if (r != TT_OK) { tt_image_free(src); continue; }
        h0 = sy_hash_image(h0, &set->levels[0]);
        all = h0;
        for (l = 1; l < set->nlevels; l++) all = sy_hash_image(all, &set->levels[l]);
        CHECK(h0 == ref->level0 && all == ref->all_levels,
              "config %d (n=%d S=%d g=%d): atlas hash %016llx / all levels %016llx, the old algorithm gave "
              "%016llx / %016llx", (int)i, ref->colors, ref->size, ref->gutter, (unsigned long long)h0,
              (unsigned long long)all, (unsigned long long)ref->level0, (unsigned long long)ref->all_levels);
        /* The same through the two public halves, and the windows agree. */
        r = tt_synth_plan_create(src, &o, NULL, &plan, &err);
        CHECK(r == TT_OK, "config %d: plan: %d (%s)", (int)i, r, err.message);
        if (r == TT_OK) {
            r = tt_synth_apply(plan, src, NULL, &applied, &err);
            CHECK(r == TT_OK && sy_same_levels(applied, set),
                  "config %d: apply(plan_create(A), A) equals tt_synthesize_tiles(A) in every level (result %d)",
                  (int)i, r);
            if (r == TT_OK) {
                int tiles = tt_tile_layout_tile_count(&set->layout);
                CHECK(memcmp(applied->edge_windows, set->edge_windows, (size_t)ref->colors * sizeof(tt_rect)) ==
                              0 &&
                          memcmp(applied->background_windows, set->background_windows,
                                 (size_t)tiles * sizeof(tt_rect)) == 0 &&
                          memcmp(plan->edge_windows, set->edge_windows, (size_t)ref->colors * sizeof(tt_rect)) ==
                              0,
                      "config %d: the plan's and both tilesets' windows agree", (int)i);
            }
            tt_tileset_free(applied);
        }
        tt_synth_plan_free(plan);
        tt_tileset_free(set);
        tt_image_free(src);
    }
}

/* ------------------------------------------------------------------------ */
/* The plan                                                                 */
/* ------------------------------------------------------------------------ */

static void test_plan_fields(void)
{
    tt_image *a = sy_noise(96, 128, 21u), *b = sy_noise(96, 128, 22u);
    tt_synth_options o = sy_options(2, 16, 4, 77u);
    tt_synth_plan *plan = NULL, *other = NULL;
    tt_rect window;
    tt_error err;
    tt_result r;
    int S = 16, tiles, t, side, x, bad_range = 0, bad_step = 0, bad_alpha = 0, bad_raw = 0, min_depth, differ = 0;
    r = tt_synth_plan_create(a, &o, NULL, &plan, &err);
    CHECK(r == TT_OK && plan, "plan_create: %d (%s)", r, err.message);
    if (r != TT_OK) { tt_image_free(a); tt_image_free(b); return; }
    tiles = tt_tile_layout_tile_count(&plan->layout);
    CHECK(plan->layout.colors == 2 && plan->layout.tile_size == 16 && plan->layout.gutter == 4 && tiles == 256,
          "resolved layout %d/%d/%d, %d tiles", plan->layout.colors, plan->layout.tile_size, plan->layout.gutter,
          tiles);
    CHECK(plan->source_width == 96 && plan->source_height == 128, "source size %dx%d", plan->source_width,
          plan->source_height);
    CHECK(plan->feather == 2 && plan->max_depth == 4, "default feather max(2, S/16) = 2: %d; max depth S/4: %d",
          plan->feather, plan->max_depth);
    CHECK(plan->depth8 != NULL && plan->depth16 == NULL, "S < 1024: one byte per depth");
    CHECK(plan->edge_windows[0].w == S && plan->edge_windows[0].h == 2 * S && plan->edge_windows[1].w == S &&
              plan->background_windows[0].w == S && plan->background_windows[tiles - 1].h == S,
          "window sizes: edge %dx%d, background %dx%d", plan->edge_windows[0].w, plan->edge_windows[0].h,
          plan->background_windows[0].w, plan->background_windows[0].h);
    /* The cut's constraints: within [min(min_depth, hi), hi], hi =
       min(wedge, max_depth), steps of at most one row. */
    min_depth = 4 + 2 / 2 + 1;
    if (min_depth > plan->max_depth) min_depth = plan->max_depth;
    for (t = 0; t < tiles; t++)
        for (side = 0; side < 4; side++)
            for (x = 0; x < S; x++) {
                int depth = tt_synth_plan_depth(plan, t, side, x);
                int wedge = x < S - 1 - x ? x : S - 1 - x;
                int hi = wedge < plan->max_depth ? wedge : plan->max_depth;
                int lo = min_depth < hi ? min_depth : hi;
                float alpha0 = tt_synth_plan_band_alpha(plan, t, side, x, 0);
                if (depth != plan->depth8[(4 * (size_t)t + (size_t)side) * S + x]) bad_raw++;
                if (depth < lo || depth > hi) bad_range++;
                if (x > 0 && abs(depth - tt_synth_plan_depth(plan, t, side, x - 1)) > 1) bad_step++;
                if ((x == 0 || x == S - 1) ? alpha0 != 0.0f : alpha0 != 1.0f) bad_alpha++;
                if (depth + plan->feather + 1 < S && tt_synth_plan_band_alpha(plan, t, side, x, depth + plan->feather + 1) != 0.0f)
                    bad_alpha++;
                if (x > 0 && x < S - 1 && depth >= 1 && tt_synth_plan_band_alpha(plan, t, side, x, 1) <= 0.0f)
                    bad_alpha++;
            }
    CHECK(bad_raw == 0, "tt_synth_plan_depth reads depth8: %d mismatches", bad_raw);
    CHECK(bad_range == 0, "%d depths outside [min(min_depth, hi), hi]", bad_range);
    CHECK(bad_step == 0, "%d cut steps of more than one row", bad_step);
    CHECK(bad_alpha == 0, "%d band alphas off (edge row 1, corner columns 0, 0 past depth + feather)", bad_alpha);
    tt_synth_plan_free(plan);
    plan = NULL;
    /* The guide decides the cuts: another guide, other depths (same seed and
       windows). With S = 16 and g = 4 the depths have no freedom (min_depth
       = max_depth = 4), so S = 32 without gutters: depths 2..8. */
    o = sy_options(1, 32, 0, 77u);
    memset(&window, 0, sizeof window);
    window.x = 5;
    window.y = 9;
    o.edge_windows = &window;
    r = tt_synth_plan_create(a, &o, NULL, &plan, &err);
    if (r == TT_OK) r = tt_synth_plan_create(b, &o, NULL, &other, &err);
    CHECK(r == TT_OK, "plans of a and b: %d (%s)", r, err.message);
    if (r == TT_OK) {
        tiles = tt_tile_layout_tile_count(&plan->layout);
        for (t = 0; t < tiles; t++)
            for (side = 0; side < 4; side++)
                for (x = 0; x < 32; x++)
                    if (tt_synth_plan_depth(plan, t, side, x) != tt_synth_plan_depth(other, t, side, x)) differ++;
        CHECK(differ > 0, "plans of two different guides differ in some depth (%d differ)", differ);
    }
    tt_synth_plan_free(other);
    tt_synth_plan_free(plan);
    tt_image_free(a);
    tt_image_free(b);
}

/* Tiles of 1024 texels or more need 16-bit depths. Only the plan and one
   composed tile: the atlas would be 4128 texels a side. */
static void test_plan_wide_depths(void)
{
    tt_image *src = sy_noise(1024, 2048, 5u), *cell = NULL;
    tt_synth_options o = sy_options(1, 1024, 0, 1u);
    tt_synth_plan *plan = NULL;
    tt_error err;
    tt_result r;
    uint8_t types[4] = {1, 0, 0, 1};
    int x, bad = 0, max_seen = 0;
    r = tt_synth_plan_create(src, &o, NULL, &plan, &err);
    CHECK(r == TT_OK && plan && plan->depth16 && !plan->depth8 && plan->max_depth == 256,
          "S = 1024: 16-bit depths up to 256 (result %d: %s)", r, err.message);
    if (r == TT_OK && tt_image_create(1024, 1024, NULL, &cell, NULL) == TT_OK) {
        int tile = tt_tile_index(&plan->layout, types);
        for (x = 0; x < 1024; x++) {
            int d = tt_synth_plan_depth(plan, tile, 2, x);
            if (d > max_seen) max_seen = d;
            if (d > 256) bad++;
        }
        CHECK(bad == 0 && max_seen > 0, "depths within 0..256 (max seen %d)", max_seen);
        r = tt_synth_compose_tile(plan, src, types, cell, 0, 0, &err);
        CHECK(r == TT_OK, "compose one 1024-texel tile: %d (%s)", r, err.message);
        /* Its top edge row (side 2, type 0: the upper square read with x
           reversed by the half turn) is the edge sample exactly. */
        for (bad = 0, x = 1; x < 1023; x++) {
            const tt_rect *w = &plan->edge_windows[0];
            const float *want = sy_px(src, w->x + 1023 - x, w->y + 1023), *got = sy_px(cell, x, 0);
            if (memcmp(want, got, 3 * sizeof(float)) != 0) bad++;
        }
        CHECK(bad == 0, "top edge row = edge sample: %d texels differ", bad);
    }
    tt_image_free(cell);
    tt_synth_plan_free(plan);
    tt_image_free(src);
}

/* ------------------------------------------------------------------------ */
/* The per-tile step                                                        */
/* ------------------------------------------------------------------------ */

/* An allocator that hands out memory full of 0xFF bytes (NaN floats):
   synthesis must set every texel of the atlas and its levels itself. */
static void *garbage_alloc(size_t size, void *user_data)
{
    void *p = malloc(size);
    (void)user_data;
    if (p) memset(p, 0xff, size);
    return p;
}

static void garbage_free(void *p, void *user_data)
{
    (void)user_data;
    free(p);
}

/* The tiles planned and composed through an executor (reverse order, two
   threads) are the serial ones bit for bit, at every mip level, plain and
   upright, from the same plan; and so are they from memory that comes full
   of garbage. */
static void test_synthesis_executor_identical(void)
{
    static const int configs[][3] = {{1, 32, 4}, {2, 16, 2}, {2, 16, 0}};
    const tt_executor *executors[2];
    size_t c, e;
    executors[0] = &g_reverse_executor;
    executors[1] = &g_thread_executor;
    for (c = 0; c < sizeof configs / sizeof configs[0]; c++) {
        tt_image *src = sy_noise(96, 96, 71u + (unsigned)c);
        tt_synth_options o = sy_options(configs[c][0], configs[c][1], configs[c][2], 9u + c);
        tt_tileset *serial = NULL;
        tt_error err;
        tt_result r;
        o.upright = (int)c % 2;
        r = tt_synthesize_tiles(src, &o, NULL, &serial, &err);
        CHECK(r == TT_OK, "config %d: serial synthesis: %d (%s)", (int)c, r, err.message);
        for (e = 0; e < 2 && r == TT_OK; e++) {
            tt_tileset *par = NULL;
            int level, differ = 0;
            o.executor = executors[e];
            r = tt_synthesize_tiles(src, &o, NULL, &par, &err);
            CHECK(r == TT_OK && par->nlevels == serial->nlevels, "config %d executor %d: %d (%s)", (int)c, (int)e, r,
                  err.message);
            for (level = 0; r == TT_OK && level < serial->nlevels; level++) {
                const tt_image *a = &serial->levels[level], *b = &par->levels[level];
                differ += memcmp(a->pixels, b->pixels, (size_t)a->width * (size_t)a->height * 4 * sizeof(float)) != 0;
            }
            CHECK(r == TT_OK && differ == 0, "config %d executor %d: %d mip levels differ from the serial run", (int)c,
                  (int)e, differ);
            tt_tileset_free(par);
            o.executor = NULL;
        }
        if (r == TT_OK) {
            tt_allocator garbage = {garbage_alloc, garbage_free, NULL};
            tt_tileset *dirty = NULL;
            int level, differ = 0;
            o.executor = &g_thread_executor;
            r = tt_synthesize_tiles(src, &o, &garbage, &dirty, &err);
            o.executor = NULL;
            CHECK(r == TT_OK && dirty->nlevels == serial->nlevels, "config %d from garbage memory: %d (%s)", (int)c,
                  r, err.message);
            for (level = 0; r == TT_OK && level < serial->nlevels; level++) {
                const tt_image *a = &serial->levels[level], *b = &dirty->levels[level];
                differ += memcmp(a->pixels, b->pixels, (size_t)a->width * (size_t)a->height * 4 * sizeof(float)) != 0;
            }
            CHECK(r == TT_OK && differ == 0, "config %d: %d mip levels made in garbage memory differ", (int)c, differ);
            tt_tileset_free(dirty);
        }
        /* The plan itself (its tiles' cuts are planned in parallel too):
           the same windows and depths, byte for byte. */
        for (e = 0; e < 2 && r == TT_OK; e++) {
            tt_synth_plan *a = NULL, *b = NULL;
            size_t depths = 4 * (size_t)o.layout.tile_size * (size_t)tt_tile_layout_tile_count(&o.layout);
            int same;
            r = tt_synth_plan_create(src, &o, NULL, &a, &err);
            o.executor = executors[e];
            if (r == TT_OK) r = tt_synth_plan_create(src, &o, NULL, &b, &err);
            o.executor = NULL;
            CHECK(r == TT_OK && a && b, "config %d executor %d: plans: %d (%s)", (int)c, (int)e, r, err.message);
            if (r != TT_OK || !a || !b) { tt_synth_plan_free(a); tt_synth_plan_free(b); break; }
            same = memcmp(a->background_windows, b->background_windows,
                          (size_t)tt_tile_layout_tile_count(&o.layout) * sizeof(tt_rect)) == 0 &&
                   (a->depth8 ? memcmp(a->depth8, b->depth8, depths) == 0
                              : memcmp(a->depth16, b->depth16, depths * sizeof(uint16_t)) == 0);
            CHECK(same, "config %d executor %d: the plan's windows or depths differ from the serial plan's", (int)c,
                  (int)e);
            tt_synth_plan_free(a);
            tt_synth_plan_free(b);
        }
        tt_tileset_free(serial);
        tt_image_free(src);
    }
}

/* Near a tile's corners the wedges are narrow and most cuts reach the
   diagonal. Where both bands of a corner reach it, they meet there: the
   texel on the diagonal is covered by the two (1 - (1 - a)(1 - b) = 1, no
   background), and the atlas shows no line along it. The line measure:
   per such texel, how far it lies from the mean of its two neighbours
   across the diagonal, over the same for the texel 3 columns off it (1
   where the diagonal is like any other place; measured 0.81, the two bands
   blended there, and 1.20 when the faded bands let the background through,
   56 % of it). Control: the atlas with
   those texels set to the tile's background window, as faded bands let it
   through before: a line of another texture along every diagonal. */
static void test_bands_meet_on_diagonals(void)
{
    tt_image *src = sy_noise(160, 192, 41u);
    tt_synth_options o = sy_options(1, 32, 4, 5u);
    tt_synth_plan *plan = NULL;
    tt_tileset *set = NULL;
    tt_error err;
    tt_result r;
    const int S = 32, g = 4;
    int tiles, t, side, x, met = 0, uncovered = 0, pass, k;
    double ratio[2] = {0, 0};
    r = tt_synth_plan_create(src, &o, NULL, &plan, &err);
    if (r == TT_OK) r = tt_synth_apply(plan, src, NULL, &set, &err);
    CHECK(r == TT_OK, "plan + apply: %d (%s)", r, err.message);
    if (r != TT_OK) {
        tt_synth_plan_free(plan);
        tt_image_free(src);
        return;
    }
    tiles = tt_tile_layout_tile_count(&plan->layout);
    for (pass = 0; pass < 2; pass++) {
        const tt_image *atlas = &set->levels[0];
        double on = 0, off = 0;
        for (t = 0; t < tiles; t++) {
            uint8_t types[4];
            int cx, cy;
            sy_tile_types(&plan->layout, t, types, &cx, &cy);
            for (side = 0; side < 4; side++)
                for (x = 1; x < S / 2; x++) {
                    /* the diagonal texel of column x at side's start, shared
                       with side - 1's column S - 1 - x */
                    int neighbour = (side + 3) % 4, tx, ty, ox, oy, across[4];
                    float a, b;
                    const float *p, *q[4];
                    if (tt_synth_plan_depth(plan, t, side, x) < x ||
                        tt_synth_plan_depth(plan, t, neighbour, S - 1 - x) < x)
                        continue;
                    a = tt_synth_plan_band_alpha(plan, t, side, x, x);
                    b = tt_synth_plan_band_alpha(plan, t, neighbour, S - 1 - x, x);
                    if (pass == 0) {
                        met++;
                        if (1.0f - (1.0f - a) * (1.0f - b) < 0.999f) uncovered++;
                    }
                    tt_rotate_coords(side, S, S, x, S - 1 - x, &tx, &ty);
                    /* across the diagonal: the texels one row nearer the
                       edge in this side's frame and in the neighbour's */
                    tt_rotate_coords(side, S, S, x, S - x, &across[0], &across[1]);
                    tt_rotate_coords(neighbour, S, S, S - 1 - x, S - x, &across[2], &across[3]);
                    if (x >= S / 2 - 4) continue;
                    tt_rotate_coords(side, S, S, x + 3, S - 1 - x, &ox, &oy);
                    if (pass == 1) {
                        /* the control: the background window's texel there */
                        const tt_rect *bg = &plan->background_windows[t];
                        float *cell = px(atlas, cx + g + tx, cy + g + ty);
                        const float *from = px(src, bg->x + tx, bg->y + ty);
                        for (k = 0; k < 3; k++) cell[k] = from[k];
                    }
                    p = px(atlas, cx + g + tx, cy + g + ty);
                    q[0] = px(atlas, cx + g + across[0], cy + g + across[1]);
                    q[1] = px(atlas, cx + g + across[2], cy + g + across[3]);
                    for (k = 0; k < 3; k++) on += fabs(p[k] - 0.5 * (q[0][k] + q[1][k]));
                    /* the same 3 columns along, off the diagonal: its
                       neighbours one row up and one column across */
                    p = px(atlas, cx + g + ox, cy + g + oy);
                    tt_rotate_coords(side, S, S, x + 3, S - x, &across[0], &across[1]);
                    tt_rotate_coords(side, S, S, x + 2, S - 1 - x, &across[2], &across[3]);
                    q[0] = px(atlas, cx + g + across[0], cy + g + across[1]);
                    q[1] = px(atlas, cx + g + across[2], cy + g + across[3]);
                    for (k = 0; k < 3; k++) off += fabs(p[k] - 0.5 * (q[0][k] + q[1][k]));
                }
        }
        ratio[pass] = off > 0 ? on / off : 0;
    }
    printf("     %d diagonal texels where two bands meet, %d showing the background; line measure %.2f "
           "(the background there, the control: %.2f)\n", met, uncovered, ratio[0], ratio[1]);
    CHECK(met > tiles && uncovered == 0, "%d of %d diagonal texels where both bands reach let the background through",
          uncovered, met);
    CHECK(ratio[0] < 1.0 && ratio[1] > 1.6, "the diagonals' line measure %g (under 1), the control %g (over 1.6)",
          ratio[0], ratio[1]);
    tt_synth_plan_free(plan);
    tt_tileset_free(set);
    tt_image_free(src);
}

static void test_compose_tile_matches_apply(void)
{
    static const int configs[][3] = {{1, 32, 4}, {2, 16, 0}, {2, 16, 3}};
    size_t c;
    for (c = 0; c < sizeof configs / sizeof configs[0]; c++) {
        tt_image *src = sy_noise(80, 96, 31u + (unsigned)c), *atlas = NULL, *one = NULL;
        tt_synth_options o = sy_options(configs[c][0], configs[c][1], configs[c][2], 5u + c);
        tt_synth_plan *plan = NULL;
        tt_tileset *set = NULL;
        tt_error err;
        tt_result r;
        unsigned char *before = NULL;
        size_t plan_bytes;
        int W, C, tiles, t, failures = 0, cell_bad = 0, outside_bad = 0;
        r = tt_synth_plan_create(src, &o, NULL, &plan, &err);
        if (r == TT_OK) r = tt_synth_apply(plan, src, NULL, &set, &err);
        CHECK(r == TT_OK, "config %d: plan + apply: %d (%s)", (int)c, r, err.message);
        if (r != TT_OK) { tt_synth_plan_free(plan); tt_image_free(src); continue; }
        W = set->levels[0].width;
        C = plan->layout.tile_size + 2 * plan->layout.gutter;
        tiles = tt_tile_layout_tile_count(&plan->layout);
        /* The plan is only read: its whole block is unchanged after. */
        plan_bytes = (size_t)((unsigned char *)(plan->depth8 + 4 * (size_t)plan->layout.tile_size * tiles) -
                              (unsigned char *)plan);
        CHECK(plan_bytes <= (sizeof(tt_synth_plan) + 15) / 16 * 16 +
                                16 * ((size_t)plan->layout.colors + (size_t)tiles) +
                                4 * (size_t)plan->layout.tile_size * (size_t)tiles,
              "config %d: the plan is one block of %lu bytes, as the header says", (int)c, (unsigned long)plan_bytes);
        before = (unsigned char *)malloc(plan_bytes);
        if (before) memcpy(before, plan, plan_bytes);
        tt_image_create(W, W, NULL, &atlas, NULL);
        tt_image_create(C + 3, C + 5, NULL, &one, NULL);
        if (!atlas || !one) { CHECK(0, "images"); break; }
        for (t = 0; t < tiles; t++) {
            uint8_t types[4];
            int x, y, i, j;
            sy_tile_types(&plan->layout, t, types, &x, &y);
            if (tt_synth_compose_tile(plan, src, types, atlas, x, y, &err) != TT_OK) failures++;
            /* A one-cell image of the caller's at (2, 3), the rest marked. */
            for (i = 0; i < (C + 3) * (C + 5) * 4; i++) one->pixels[i] = -7.0f;
            if (tt_synth_compose_tile(plan, src, types, one, 2, 3, &err) != TT_OK) failures++;
            for (j = 0; j < C + 5; j++)
                for (i = 0; i < C + 3; i++) {
                    const float *p = sy_px(one, i, j);
                    if (i >= 2 && i < 2 + C && j >= 3 && j < 3 + C) {
                        if (memcmp(p, sy_px(&set->levels[0], x + i - 2, y + j - 3), 4 * sizeof(float)) != 0)
                            cell_bad++;
                    } else if (p[0] != -7.0f || p[1] != -7.0f || p[2] != -7.0f || p[3] != -7.0f) {
                        outside_bad++;
                    }
                }
        }
        CHECK(failures == 0, "config %d: %d compose calls failed", (int)c, failures);
        CHECK(memcmp(atlas->pixels, set->levels[0].pixels, sy_floats(atlas) * sizeof(float)) == 0,
              "config %d: compose_tile of every tile into one image = apply's level 0, bit for bit", (int)c);
        CHECK(cell_bad == 0, "config %d: a one-cell target at (2, 3) holds the atlas cell: %d texels differ", (int)c,
              cell_bad);
        CHECK(outside_bad == 0, "config %d: %d texels outside the cell were touched", (int)c, outside_bad);
        CHECK(before && memcmp(before, plan, plan_bytes) == 0, "config %d: composing left the plan unchanged", (int)c);
        free(before);
        tt_image_free(one);
        tt_image_free(atlas);
        tt_tileset_free(set);
        tt_synth_plan_free(plan);
        tt_image_free(src);
    }
}

/* ------------------------------------------------------------------------ */
/* Applying one plan to several maps                                        */
/* ------------------------------------------------------------------------ */

static void test_second_map_same_masks(void)
{
    const int w = 96, h = 128;
    tt_image *a = sy_noise(w, h, 41u), *b = sy_copy(a), *mark = NULL;
    tt_synth_options o = sy_options(1, 32, 4, 9u);
    tt_synth_plan *plan = NULL;
    tt_tileset *sa = NULL, *sb = NULL, *sm = NULL;
    tt_error err;
    tt_result r;
    int x, y, l, k, changed = 0, bad_same = 0, reached = 0, bad_edge = 0, t, tiles;
    tt_image_create(w, h, NULL, &mark, NULL);
    /* B = A but for a block of other texels; `mark` is 1 there, 0 elsewhere. */
    for (y = 40; y < 90; y++)
        for (x = 20; x < 70; x++) {
            float *p = sy_px(b, x, y), *m = sy_px(mark, x, y);
            for (k = 0; k < 3; k++) { p[k] = 1.0f - p[k] * 0.5f; m[k] = 1.0f; }
        }
    for (y = 0; y < h; y++)
        for (x = 0; x < w; x++) sy_px(mark, x, y)[3] = 1.0f;
    r = tt_synth_plan_create(a, &o, NULL, &plan, &err);
    if (r == TT_OK) r = tt_synth_apply(plan, a, NULL, &sa, &err);
    if (r == TT_OK) r = tt_synth_apply(plan, b, NULL, &sb, &err);
    if (r == TT_OK) r = tt_synth_apply(plan, mark, NULL, &sm, &err);
    CHECK(r == TT_OK, "plan of A applied to A, B and the mark: %d (%s)", r, err.message);
    if (r == TT_OK) {
        /* A map identical to the guide (another image with A's texels)
           synthesises to A's atlas, every level, bit for bit. */
        tt_image *same = sy_copy(a);
        tt_tileset *ss = NULL;
        CHECK(same && tt_synth_apply(plan, same, NULL, &ss, &err) == TT_OK && ss && sy_same_levels(ss, sa),
              "a map identical to the guide gives the guide's atlas");
        tt_tileset_free(ss);
        tt_image_free(same);
    }
    if (r == TT_OK) {
        /* Blending is convex, so an atlas texel of the mark's atlas is 0
           exactly when no changed texel reached it: there A's and B's
           atlases must agree to the bit, in every level. */
        for (l = 0; l < sa->nlevels; l++) {
            size_t i, n = sy_floats(&sa->levels[l]);
            for (i = 0; i < n; i += 4) {
                int differs = memcmp(sa->levels[l].pixels + i, sb->levels[l].pixels + i, 4 * sizeof(float)) != 0;
                int touched = sm->levels[l].pixels[i] != 0.0f;
                if (differs) changed++;
                if (touched) reached++;
                if (differs && !touched) bad_same++;
            }
        }
        CHECK(bad_same == 0, "%d atlas texels differ between A and B although no changed texel reaches them",
              bad_same);
        CHECK(changed > 0 && reached > 0, "the changed block shows in the atlas (%d texels differ, %d reached)",
              changed, reached);
        /* Seamlessness holds for the second map too: the edge row of every
           side but its corner texels is B's edge sample, exactly. Side 0
           (bottom) of tile t: texel (g + x, g + S-1) of its cell. */
        tiles = tt_tile_layout_tile_count(&plan->layout);
        for (t = 0; t < tiles; t++) {
            uint8_t types[4];
            int cx, cy;
            const tt_rect *wnd;
            sy_tile_types(&plan->layout, t, types, &cx, &cy);
            wnd = &plan->edge_windows[types[0] >> 1];
            for (x = 1; x < 31; x++) {
                const float *want = (types[0] & 1) == 0 ? sy_px(b, wnd->x + x, wnd->y + 31)
                                                        : sy_px(b, wnd->x + 31 - x, wnd->y + 32);
                if (memcmp(want, sy_px(&sb->levels[0], cx + 4 + x, cy + 4 + 31), 3 * sizeof(float)) != 0)
                    bad_edge++;
            }
        }
        CHECK(bad_edge == 0, "B's bottom edge rows are B's edge samples: %d texels differ", bad_edge);
    }
    tt_tileset_free(sa);
    tt_tileset_free(sb);
    tt_tileset_free(sm);
    tt_synth_plan_free(plan);
    tt_image_free(a);
    tt_image_free(b);
    tt_image_free(mark);
}

/* A normal map is applied with the guide's plan, its vectors turned as the
   content is. Where a band's edge row lies (alpha 1: the edge sample alone),
   a ramp image r = x, g = y applied with the same plan tells which source
   step each tile step came from, hence the band's turn; the normal atlas
   must hold the source vector turned by exactly that (a constant "up" on a
   band turned a quarter turn reads as the turned direction). Checked for
   plain and upright plans, every tile, every side; every texel of every
   level is a unit vector. The control, the same vectors applied as a colour
   image, must fail the check. */
static void test_normal_map_turns(void)
{
    const int S = 24, g = 3, W = 96, H = 96;
    tt_image *guide = sy_noise(W, H, 17u), *ramp = NULL, *normal = NULL;
    int upright, x, y;
    const float v[3] = {0.3f, 0.5f, 0.81240384f};   /* |v| = 1, no axis */
    tt_image_create(W, H, NULL, &ramp, NULL);
    tt_image_create(W, H, NULL, &normal, NULL);
    if (!guide || !ramp || !normal) {
        CHECK(0, "test images");
        goto done;
    }
    normal->kind = TT_IMAGE_NORMAL;
    for (y = 0; y < H; y++)
        for (x = 0; x < W; x++) {
            float *r = sy_px(ramp, x, y), *n = sy_px(normal, x, y);
            r[0] = (float)x; r[1] = (float)y; r[2] = 0.0f; r[3] = 1.0f;
            n[0] = v[0]; n[1] = v[1]; n[2] = v[2]; n[3] = 1.0f;
        }
    for (upright = 0; upright <= 1; upright++) {
        tt_synth_options o = sy_options(1, S, g, 5u);
        tt_synth_plan *plan = NULL;
        tt_tileset *ramps = NULL, *normals = NULL, *control = NULL;
        tt_error err;
        tt_result r;
        int t, side, checked = 0, bad = 0, control_bad = 0, not_unit = 0, level, turned = 0;
        o.upright = upright;
        r = tt_synth_plan_create(guide, &o, NULL, &plan, &err);
        if (r == TT_OK) r = tt_synth_apply(plan, ramp, NULL, &ramps, &err);
        if (r == TT_OK) r = tt_synth_apply(plan, normal, NULL, &normals, &err);
        normal->kind = TT_IMAGE_COLOR;
        if (r == TT_OK) r = tt_synth_apply(plan, normal, NULL, &control, &err);
        normal->kind = TT_IMAGE_NORMAL;
        CHECK(r == TT_OK, "upright %d: plan, ramp, normal map, control: %d (%s)", upright, r, err.message);
        if (r != TT_OK) goto next;
        CHECK(normals->levels[0].kind == TT_IMAGE_NORMAL && control->levels[0].kind == TT_IMAGE_COLOR,
              "the atlas is of its source's kind");
        for (t = 0; t < tt_tile_layout_tile_count(&plan->layout); t++) {
            uint8_t types[4];
            int cx, cy;
            sy_tile_types(&plan->layout, t, types, &cx, &cy);
            for (side = 0; side < 4; side++)
                for (x = 2; x < S - 2; x++) {
                    int tx0, ty0, tx1, ty1, stx, sty, ssx, ssy;
                    const float *r0, *r1, *n, *c;
                    double ex, ey;
                    /* edge row d = 0 of the side: texels x and x + 1 */
                    tt_rotate_coords(side, S, S, x, S - 1, &tx0, &ty0);
                    tt_rotate_coords(side, S, S, x + 1, S - 1, &tx1, &ty1);
                    r0 = sy_px(&ramps->levels[0], cx + g + tx0, cy + g + ty0);
                    r1 = sy_px(&ramps->levels[0], cx + g + tx1, cy + g + ty1);
                    stx = tx1 - tx0; sty = ty1 - ty0;                             /* the tile step */
                    ssx = (int)lrintf(r1[0] - r0[0]); ssy = (int)lrintf(r1[1] - r0[1]);  /* its source step */
                    /* the rotation taking (ssx, ssy) to (stx, sty), both unit axis steps, image axes
                       (y down), applied to v flipped into image axes and back */
                    {
                        double cs = ssx * stx + ssy * sty, sn = ssx * sty - ssy * stx;
                        double ix = v[0], iy = -v[1];
                        ex = cs * ix - sn * iy;
                        ey = -(sn * ix + cs * iy);
                    }
                    if (abs(ssx) + abs(ssy) != 1) {
                        bad++;
                        continue;
                    }
                    n = sy_px(&normals->levels[0], cx + g + tx0, cy + g + ty0);
                    c = sy_px(&control->levels[0], cx + g + tx0, cy + g + ty0);
                    checked++;
                    if (fabs(ex - v[0]) > 1e-3 || fabs(ey - v[1]) > 1e-3) turned++;
                    if (fabs(n[0] - ex) > 1e-5 || fabs(n[1] - ey) > 1e-5 || fabs(n[2] - v[2]) > 1e-5) {
                        if (bad == 0)
                            DETAIL("upright %d tile %d side %d x %d: (%g, %g), want (%g, %g)", upright, t, side, x,
                                   n[0], n[1], ex, ey);
                        bad++;
                    }
                    if (fabs(c[0] - ex) > 1e-5 || fabs(c[1] - ey) > 1e-5) control_bad++;
                }
        }
        CHECK(checked > 0 && bad == 0, "upright %d: %d of %d edge-row texels hold the wrong turn", upright, bad,
              checked);
        CHECK(turned > checked / 4, "upright %d: %d of %d edge-row texels are turned content (the test can fail)",
              upright, turned, checked);
        CHECK(control_bad > checked / 4, "control (vectors not turned): %d of %d edge-row texels wrong", control_bad,
              checked);
        for (level = 0; level < normals->nlevels; level++) {
            const tt_image *im = &normals->levels[level];
            size_t i, count = (size_t)im->width * (size_t)im->height;
            CHECK(im->kind == TT_IMAGE_NORMAL, "level %d is a normal map", level);
            for (i = 0; i < count; i++) {
                const float *p = im->pixels + 4 * i;
                double length = sqrt((double)p[0] * p[0] + (double)p[1] * p[1] + (double)p[2] * p[2]);
                if (fabs(length - 1.0) > 1e-5) not_unit++;
            }
        }
        CHECK(not_unit == 0, "upright %d: %d texels of the normal atlas and its mips are not unit vectors", upright,
              not_unit);
    next:
        tt_tileset_free(ramps);
        tt_tileset_free(normals);
        tt_tileset_free(control);
        tt_synth_plan_free(plan);
    }
done:
    tt_image_free(guide);
    tt_image_free(ramp);
    tt_image_free(normal);
}

/* A normal map whose texels are not unit vectors (made by hand: here every
   one of length 2) still gives an atlas of unit vectors, gutters and mips
   included: the gutters once copied the source's vectors as they were. */
static void test_normal_map_not_unit(void)
{
    const int W = 96, H = 96;
    tt_image *normal = NULL;
    tt_synth_options o = sy_options(1, 24, 3, 7u);
    tt_tileset *normals = NULL;
    tt_error err;
    tt_result r;
    int x, y, level, not_unit = 0, texels = 0;
    tt_image_create(W, H, NULL, &normal, NULL);
    if (!normal) {
        CHECK(0, "test image");
        goto done;
    }
    normal->kind = TT_IMAGE_NORMAL;
    for (y = 0; y < H; y++)
        for (x = 0; x < W; x++) {
            float *n = sy_px(normal, x, y);
            double a = 0.05 * x, b = 0.04 * y;
            n[0] = (float)(2.0 * 0.5 * cos(a));
            n[1] = (float)(2.0 * 0.5 * sin(b));
            n[2] = (float)(2.0 * sqrt(1.0 - 0.25 * cos(a) * cos(a) - 0.25 * sin(b) * sin(b)));
            n[3] = 1.0f;
        }
    r = tt_synthesize_tiles(normal, &o, NULL, &normals, &err);
    CHECK(r == TT_OK, "normal map of length-2 vectors: %d (%s)", r, err.message);
    if (r != TT_OK) goto done;
    for (level = 0; level < normals->nlevels; level++) {
        const tt_image *im = &normals->levels[level];
        size_t i, count = (size_t)im->width * (size_t)im->height;
        for (i = 0; i < count; i++) {
            const float *p = im->pixels + 4 * i;
            double length = sqrt((double)p[0] * p[0] + (double)p[1] * p[1] + (double)p[2] * p[2]);
            not_unit += fabs(length - 1.0) > 1e-5;
            texels++;
        }
    }
    CHECK(not_unit == 0, "%d of %d texels of the atlas and its mips are not unit vectors", not_unit, texels);
done:
    tt_tileset_free(normals);
    tt_image_free(normal);
}

/* B = s * A + o texel by texel (one s, o per channel): every atlas level of
   B is s * atlas_A + o up to float rounding. The masks do not depend on the
   applied image, and every step (over, corner means, mip averages) is an
   affine combination with weights summing to 1. */
/* tt_synth_options::upright: every band of an upright tile keeps the
   source's up (a source of horizontal stripes gives tiles of horizontal
   stripes, changing along the rows only where layers blend; plain tiles
   turn the left and right bands into vertical stripes), and two upright tiles still meet seamlessly across a left/right
   edge: the gutter beyond tile A's right side (type t) is what tile B shows
   along its left side (type t ^ 1), and not what a B of type t shows. */
static void test_upright_tiles(void)
{
    const int S = 32, g = 4;
    tt_image *stripes = NULL, *noise = sy_noise(96, 80, 41u);
    int upright, x, y, k;
    tt_error err;
    tt_image_create(80, 72, NULL, &stripes, NULL);
    if (!stripes || !noise) {
        CHECK(0, "images");
        tt_image_free(stripes);
        tt_image_free(noise);
        return;
    }
    for (y = 0; y < stripes->height; y++)
        for (x = 0; x < stripes->width; x++) {
            float *p = sy_px(stripes, x, y);
            for (k = 0; k < 3; k++) p[k] = (float)(sy_hash((uint32_t)y, (uint32_t)k, 5u) % 1000u) / 1000.0f;
            p[3] = 1.0f;
        }
    for (upright = 0; upright < 2; upright++) {
        tt_synth_options o = sy_options(2, S, g, 9u);
        tt_synth_plan *plan = NULL;
        tt_tileset *set = NULL;
        double along = 0.0, across = 0.0;
        int tiles, t;
        o.upright = upright;
        if (tt_synth_plan_create(stripes, &o, NULL, &plan, &err) != TT_OK ||
            tt_synth_apply(plan, stripes, NULL, &set, &err) != TT_OK) {
            CHECK(0, "upright %d: stripes tiles: %s", upright, err.message);
            tt_synth_plan_free(plan);
            continue;
        }
        CHECK(upright ? plan->vertical_windows && set->vertical_windows && plan->vertical_windows[1].w == 2 * S &&
                            plan->vertical_windows[1].h == S
                      : !plan->vertical_windows && !set->vertical_windows,
              "upright %d: the vertical windows are %s", upright, upright ? "there, 2S x S" : "absent");
        tiles = tt_tile_layout_tile_count(&plan->layout);
        for (t = 0; t < tiles; t++) {
            uint8_t types[4];
            int cx, cy;
            sy_tile_types(&plan->layout, t, types, &cx, &cy);
            for (y = 1; y < S - 1; y++)
                for (x = 1; x < S - 1; x++)
                    for (k = 0; k < 3; k++) {
                        const float *p = sy_px(&set->levels[0], cx + g + x, cy + g + y);
                        along += fabs(sy_px(&set->levels[0], cx + g + x + 1, cy + g + y)[k] - p[k]);
                        across += fabs(sy_px(&set->levels[0], cx + g + x, cy + g + y + 1)[k] - p[k]);
                    }
        }
        printf("     %s tiles of horizontal stripes: change along the rows %.3f of that across them\n",
               upright ? "upright" : "plain", along / across);
        if (upright)
            CHECK(along < 0.15 * across, "upright tiles keep stripes horizontal: change along the rows %.3f of that "
                  "across", along / across);
        else
            CHECK(along > 0.3 * across, "plain tiles turn the side bands' stripes: change along the rows %.3f of "
                  "that across", along / across);
        tt_tileset_free(set);
        tt_synth_plan_free(plan);
    }
    {
        tt_synth_options o = sy_options(2, S, g, 12u);
        tt_synth_plan *plan = NULL;
        tt_image *a = NULL, *b = NULL;
        int type, matched = 1, control_differs = 0;
        o.upright = 1;
        tt_image_create(S + 2 * g, S + 2 * g, NULL, &a, NULL);
        tt_image_create(S + 2 * g, S + 2 * g, NULL, &b, NULL);
        if (!a || !b || tt_synth_plan_create(noise, &o, NULL, &plan, &err) != TT_OK) {
            CHECK(0, "upright plan of noise");
        } else {
            for (type = 0; type < 4; type++) {
                const uint8_t ta[4] = {1, (uint8_t)type, 2, 0};
                const uint8_t tb[4] = {3, 0, 0, (uint8_t)(type ^ 1)};
                const uint8_t tc[4] = {3, 0, 0, (uint8_t)type};
                int j;
                CHECK(tt_synth_compose_tile(plan, noise, ta, a, 0, 0, &err) == TT_OK &&
                          tt_synth_compose_tile(plan, noise, tb, b, 0, 0, &err) == TT_OK,
                      "compose upright tiles");
                for (y = g + 2; y < S - g - 2; y++)
                    for (j = 0; j < g; j++)
                        matched &= memcmp(sy_px(a, g + S + j, g + y), sy_px(b, g + j, g + y), 3 * sizeof(float)) == 0;
                CHECK(tt_synth_compose_tile(plan, noise, tc, b, 0, 0, &err) == TT_OK, "compose the control");
                for (y = g + 2; y < S - g - 2; y++)
                    for (j = 0; j < g; j++)
                        control_differs += memcmp(sy_px(a, g + S + j, g + y), sy_px(b, g + j, g + y),
                                                  3 * sizeof(float)) != 0;
            }
            CHECK(matched, "upright tiles: the gutter beyond the right side is the left side of the tile across");
            CHECK(control_differs > 0, "the same type on both sides of the edge does not match (%d texels differ)",
                  control_differs);
        }
        tt_synth_plan_free(plan);
        tt_image_free(a);
        tt_image_free(b);
    }
    /* Upright tiles need the vertical windows' 2S columns. */
    {
        tt_synth_options o = sy_options(2, 40, g, 1u);
        tt_synth_plan *plan = NULL;
        tt_image *narrow = sy_noise(60, 100, 3u);
        o.upright = 1;
        CHECK(narrow && tt_synth_plan_create(narrow, &o, NULL, &plan, &err) == TT_ERROR_IMAGE_TOO_SMALL && !plan &&
                  strstr(err.message, "upright") && sy_has_number(err.message, 80),
              "a 60x100 image for upright 40-texel tiles: %s", err.message);
        o.upright = 0;
        CHECK(narrow && tt_synth_plan_create(narrow, &o, NULL, &plan, &err) == TT_OK, "plain 40-texel tiles fit: %s",
              err.message);
        tt_synth_plan_free(plan);
        tt_image_free(narrow);
    }
    tt_image_free(stripes);
    tt_image_free(noise);
}

/* tt_synth_options::plain_sides: an upright tile whose right (left) side
   is plain meets a plain tile across that side and an upright one across
   the other, texel for texel in the gutters; the same side of a fully
   upright tile (the control) does not meet the plain tile. Plans that
   differ only in plain_sides share their windows. */
static int sy_gutter_matches(const tt_image *a, int a_side, const tt_image *b, int S, int g)
{
    /* a_side 1: a's gutter beyond its right side against b's first g
       columns (b lies to the right); a_side 3: a's gutter before its left
       side against b's last g columns (b lies to the left). */
    int y, j, same = 1;
    for (y = g + 2; y < S - g - 2; y++)
        for (j = 0; j < g; j++)
            same &= memcmp(sy_px(a, a_side == 1 ? g + S + j : j, g + y), sy_px(b, a_side == 1 ? g + j : S + j, g + y),
                           3 * sizeof(float)) == 0;
    return same;
}

static void test_upright_plain_sides(void)
{
    const int S = 32, g = 4;
    tt_image *noise = sy_noise(96, 80, 43u), *a = NULL, *b = NULL;
    tt_synth_plan *plain = NULL, *upright = NULL, *mixed[2] = {NULL, NULL};
    tt_synth_options o = sy_options(2, S, g, 21u);
    tt_error err;
    int m, type;
    tt_image_create(S + 2 * g, S + 2 * g, NULL, &a, NULL);
    tt_image_create(S + 2 * g, S + 2 * g, NULL, &b, NULL);
    if (!noise || !a || !b || tt_synth_plan_create(noise, &o, NULL, &plain, &err) != TT_OK) {
        CHECK(0, "plain plan of noise");
        goto done;
    }
    o.edge_windows = plain->edge_windows;
    o.upright = 1;
    if (tt_synth_plan_create(noise, &o, NULL, &upright, &err) != TT_OK) {
        CHECK(0, "upright plan: %s", err.message);
        goto done;
    }
    for (m = 0; m < 2; m++) {
        int n = plain->layout.colors, tiles = tt_tile_layout_tile_count(&plain->layout);
        o.plain_sides = m == 0 ? 1 << 1 : 1 << 3;
        if (tt_synth_plan_create(noise, &o, NULL, &mixed[m], &err) != TT_OK) {
            CHECK(0, "plain_sides %d: %s", o.plain_sides, err.message);
            goto done;
        }
        CHECK(mixed[m]->plain_sides == o.plain_sides &&
                  memcmp(mixed[m]->vertical_windows, upright->vertical_windows, (size_t)n * sizeof(tt_rect)) == 0 &&
                  memcmp(mixed[m]->background_windows, upright->background_windows,
                         (size_t)tiles * sizeof(tt_rect)) == 0,
              "plain_sides %d: the plan keeps it, and the upright plan's vertical and background windows",
              o.plain_sides);
    }
    for (type = 0; type < 4; type++) {
        /* The mixed tile in the middle: its side 1 (plain_sides 2) or 3
           (plain_sides 8) has type `type`; the tile across shows type ^ 1. */
        const uint8_t right_plain[4] = {1, (uint8_t)type, 2, 0}, left_plain[4] = {1, 0, 2, (uint8_t)type};
        const uint8_t across_right[4] = {3, 0, 0, (uint8_t)(type ^ 1)}, across_left[4] = {3, (uint8_t)(type ^ 1), 0, 0};
        const uint8_t left_of_type0[4] = {3, 1, 0, 0}, right_of_type0[4] = {3, 0, 0, 1};   /* across a side of type 0 */
        /* the right side plain (plain_sides 2): a plain tile across it, an upright one across the left */
        int ok = tt_synth_compose_tile(mixed[0], noise, right_plain, a, 0, 0, &err) == TT_OK &&
                 tt_synth_compose_tile(plain, noise, across_right, b, 0, 0, &err) == TT_OK;
        CHECK(ok && sy_gutter_matches(a, 1, b, S, g), "type %d: a plain right side meets a plain tile", type);
        ok = tt_synth_compose_tile(upright, noise, left_of_type0, b, 0, 0, &err) == TT_OK;
        CHECK(ok && sy_gutter_matches(a, 3, b, S, g), "type %d: its upright left side meets an upright tile", type);
        /* the left side plain (plain_sides 8) */
        ok = tt_synth_compose_tile(mixed[1], noise, left_plain, a, 0, 0, &err) == TT_OK &&
             tt_synth_compose_tile(plain, noise, across_left, b, 0, 0, &err) == TT_OK;
        CHECK(ok && sy_gutter_matches(a, 3, b, S, g), "type %d: a plain left side meets a plain tile", type);
        ok = tt_synth_compose_tile(upright, noise, right_of_type0, b, 0, 0, &err) == TT_OK;
        CHECK(ok && sy_gutter_matches(a, 1, b, S, g), "type %d: its upright right side meets an upright tile", type);
        /* controls: an upright side does not meet a plain tile */
        ok = tt_synth_compose_tile(upright, noise, right_plain, a, 0, 0, &err) == TT_OK &&
             tt_synth_compose_tile(plain, noise, across_right, b, 0, 0, &err) == TT_OK;
        CHECK(ok && !sy_gutter_matches(a, 1, b, S, g),
              "type %d: (control) an upright right side does not meet a plain tile", type);
        ok = tt_synth_compose_tile(upright, noise, left_plain, a, 0, 0, &err) == TT_OK &&
             tt_synth_compose_tile(plain, noise, across_left, b, 0, 0, &err) == TT_OK;
        CHECK(ok && !sy_gutter_matches(a, 3, b, S, g),
              "type %d: (control) an upright left side does not meet a plain tile", type);
    }
    {
        tt_synth_plan *bad = NULL;
        o.plain_sides = 1 << 2;
        CHECK(tt_synth_plan_create(noise, &o, NULL, &bad, &err) == TT_ERROR_INVALID_ARGUMENT && !bad &&
                  strstr(err.message, "plain_sides"),
              "plain_sides 4 (a bottom or top side) is refused: %s", err.message);
        o.plain_sides = 1 << 1;
        o.upright = 0;
        CHECK(tt_synth_plan_create(noise, &o, NULL, &bad, &err) == TT_ERROR_INVALID_ARGUMENT && !bad &&
                  strstr(err.message, "upright"),
              "plain_sides without upright is refused: %s", err.message);
        tt_synth_plan_free(bad);
    }
done:
    tt_synth_plan_free(plain);
    tt_synth_plan_free(upright);
    tt_synth_plan_free(mixed[0]);
    tt_synth_plan_free(mixed[1]);
    tt_image_free(noise);
    tt_image_free(a);
    tt_image_free(b);
}

typedef struct upright_atlas_oom_ctx {
    const tt_tileset *const *sets;
} upright_atlas_oom_ctx;

static tt_result upright_atlas_oom_call(void *ctx, const tt_allocator *al, tt_error *error)
{
    upright_atlas_oom_ctx *c = (upright_atlas_oom_ctx *)ctx;
    tt_image *atlas = (tt_image *)&atlas;
    tt_result r = tt_upright_atlas(c->sets, 0, NULL, al, &atlas, error);
    if (error->result != r || (r != TT_OK) != (atlas == NULL)) return TT_RESULT_MAX_ENUM;
    tt_image_free(atlas);
    return r;
}

/* 1 when rows [0, rows) of `part` are the block of `atlas` at texel
   column x0, image row y0. */
static int atlas_block_is(const tt_image *atlas, int x0, int y0, const tt_image *part, int rows)
{
    int row;
    for (row = 0; row < rows; row++)
        if (memcmp(atlas->pixels + ((size_t)(y0 + row) * atlas->width + x0) * 4,
                   part->pixels + (size_t)row * part->width * 4, (size_t)part->width * 4 * sizeof(float)) != 0)
            return 0;
    return 1;
}

/* tt_upright_atlas: level L of the four tilesets, set i in column i % 2
   and tile-row block i / 2 from the bottom, texel for texel, the same
   through an executor; sets that do not go together, or in another
   order, are refused; every allocation failure is reported. */
static void upright_atlas_checks(const tt_tileset *const *sets, const tt_image *atlas)
{
    const tt_tileset *plain = sets[0], *upright = sets[1];
    const tt_tileset *reordered[TT_TILESET_KINDS];
    tt_tileset moved_set;
    tt_rect moved[TT_MAX_COLORS];
    tt_image *level1 = NULL, *bad = (tt_image *)&bad;
    upright_atlas_oom_ctx ctx;
    tt_error err;
    int i, i2, same = 1, W = plain->levels[0].width;
    CHECK(atlas->width == 2 * W && atlas->height == 2 * W, "the atlas is %dx%d (want %dx%d)", atlas->width,
          atlas->height, 2 * W, 2 * W);
    for (i = 0; i < TT_TILESET_KINDS; i++)
        same &= atlas_block_is(atlas, (i % 2) * W, (1 - i / 2) * W, &sets[i]->levels[0], W);
    CHECK(same, "the atlas is the four sets, 2 x 2, the first two at the bottom");
    {
        /* Bands of rows through an executor: the same atlas, byte for byte. */
        const tt_executor *executors[2];
        int e;
        executors[0] = &g_reverse_executor;
        executors[1] = &g_thread_executor;
        for (e = 0; e < 2; e++) {
            tt_image *parallel = NULL;
            CHECK(tt_upright_atlas(sets, 0, executors[e], NULL, &parallel, &err) ==
                          TT_OK &&
                      parallel && parallel->width == atlas->width && parallel->height == atlas->height &&
                      memcmp(parallel->pixels, atlas->pixels, (size_t)atlas->width * atlas->height * 4 * sizeof(float)) ==
                          0,
                  "executor %d: the atlas differs from the serial one", e);
            tt_image_free(parallel);
        }
    }
    CHECK(tt_upright_atlas(sets, 1, NULL, NULL, &level1, &err) == TT_OK && level1 &&
              level1->width == W && level1->height == W && atlas_block_is(level1, 0, W / 2, &plain->levels[1], W / 2),
          "level 1: %s", err.message);
    tt_image_free(level1);
    for (i = 0; i < TT_TILESET_KINDS; i++) reordered[i] = sets[i];
    reordered[2] = sets[3];
    reordered[3] = sets[2];
    CHECK(tt_upright_atlas(reordered, 0, NULL, NULL, &bad, &err) ==
                  TT_ERROR_INVALID_ARGUMENT && !bad && err.item == 2,
          "the left- and right-plain sets swapped refused, naming set 2: %s", err.message);
    bad = (tt_image *)&bad;
    for (i = 0; i < TT_TILESET_KINDS; i++) reordered[i] = sets[i];
    reordered[0] = upright;
    reordered[1] = plain;
    CHECK(tt_upright_atlas(reordered, 0, NULL, NULL, &bad, &err) == TT_ERROR_INVALID_ARGUMENT && !bad,
          "upright first refused: %s", err.message);
    bad = (tt_image *)&bad;
    CHECK(tt_upright_atlas(sets, plain->nlevels, NULL, NULL, &bad, &err) ==
                  TT_ERROR_INDEX_OUT_OF_RANGE && !bad,
          "level %d refused: %s", plain->nlevels, err.message);
    for (i = 0; i < 2; i++) {
        /* another edge window, then another vertical window, in set 2 */
        moved_set = *sets[2];
        memcpy(moved, i == 0 ? sets[2]->edge_windows : sets[2]->vertical_windows,
               sizeof(tt_rect) * (size_t)plain->layout.colors);
        moved[1].x += 1;
        if (i == 0) moved_set.edge_windows = moved;
        else moved_set.vertical_windows = moved;
        for (i2 = 0; i2 < TT_TILESET_KINDS; i2++) reordered[i2] = sets[i2];
        reordered[2] = &moved_set;
        bad = (tt_image *)&bad;
        CHECK(tt_upright_atlas(reordered, 0, NULL, NULL, &bad, &err) ==
                      TT_ERROR_INVALID_ARGUMENT &&
                  !bad && err.item == 1 && strstr(err.message, i == 0 ? "edge window" : "vertical window"),
              "another %s window in set 2 refused: %s", i == 0 ? "edge" : "vertical", err.message);
    }
    ctx.sets = sets;
    oom_reset();
    oom_sweep("tt_upright_atlas", upright_atlas_oom_call, &ctx, TT_OK);
}


static void test_upright_atlas(void)
{
    tt_image *noise = sy_noise(96, 96, 47u), *atlas = NULL;
    tt_tileset *sets[TT_TILESET_KINDS] = {NULL, NULL, NULL, NULL};
    tt_synth_options o = sy_options(2, 16, 2, 13u);
    tt_error err;
    int k;
    if (!noise || tt_synthesize_tiles(noise, &o, NULL, &sets[TT_TILESET_PLAIN], &err) != TT_OK) {
        CHECK(0, "plain tiles of noise");
        tt_image_free(noise);
        return;
    }
    make_upright_sets(noise, o, sets);
    if (!sets[1] || !sets[2] || !sets[3] ||
        tt_upright_atlas((const tt_tileset *const *)sets, 0, NULL, NULL, &atlas, &err) != TT_OK)
        CHECK(0, "the upright sets and their atlas: %s", err.message);
    else
        upright_atlas_checks((const tt_tileset *const *)sets, atlas);
    tt_image_free(atlas);
    for (k = 0; k < TT_TILESET_KINDS; k++) tt_tileset_free(sets[k]);
    tt_image_free(noise);
}

/* tt_synth_options::levels: 1 makes level 0 alone, 2 two levels, 0 every
   level the cells allow (the control: more than 2), the same level 0 each
   time; a negative count is refused. */
static void test_synth_levels(void)
{
    tt_image *noise = sy_noise(96, 96, 53u);
    tt_tileset *sets[3] = {NULL, NULL, NULL};
    tt_synth_options o = sy_options(1, 32, 4, 17u);
    tt_synth_plan *bad = NULL;
    tt_error err;
    int k, same = 1;
    for (k = 0; k < 3 && noise; k++) {
        o.levels = k == 0 ? 0 : k;
        if (tt_synthesize_tiles(noise, &o, NULL, &sets[k], &err) != TT_OK) sets[k] = NULL;
    }
    for (k = 1; k < 3; k++)
        same &= sets[0] && sets[k] &&
                memcmp(sets[0]->levels[0].pixels, sets[k]->levels[0].pixels,
                       (size_t)sets[0]->levels[0].width * sets[0]->levels[0].height * 4 * sizeof(float)) == 0;
    CHECK(sets[0] && sets[1] && sets[2] && sets[0]->nlevels > 2 && sets[1]->nlevels == 1 && sets[2]->nlevels == 2 &&
              same,
          "levels 0, 1, 2: %d, %d, %d mip levels, level 0 the same", sets[0] ? sets[0]->nlevels : -1,
          sets[1] ? sets[1]->nlevels : -1, sets[2] ? sets[2]->nlevels : -1);
    o.levels = -1;
    CHECK(noise && tt_synth_plan_create(noise, &o, NULL, &bad, &err) == TT_ERROR_INVALID_ARGUMENT && !bad &&
              strstr(err.message, "levels"),
          "levels -1 refused: %s", err.message);
    for (k = 0; k < 3; k++) tt_tileset_free(sets[k]);
    tt_image_free(noise);
}

/* Bricks: courses `period` texels tall (any real number) whose mortar, 3
   texels thick, is centred on the heights phase + k * period; head joints
   every 2.2 courses, each course's at its own offset (so nothing repeats
   across the image); each brick its own grey, with grain. */
static tt_image *sy_bricks(int w, int h, double period, double phase, uint32_t seed)
{
    const double brick = 2.2 * period;
    tt_image *im = NULL;
    int x, y, k;
    if (tt_image_create(w, h, NULL, &im, NULL) != TT_OK) return NULL;
    for (y = 0; y < h; y++) {
        const double course = (y + 0.5 - phase) / period;
        const int c = (int)floor(course + 0.5);
        const int mortar_row = fabs(course - c) * period < 1.5;
        for (x = 0; x < w; x++) {
            const double along = (x + 0.5) / brick + (double)(sy_hash((uint32_t)c + 99u, 5u, seed) % 1000u) / 1000.0;
            const int b = (int)floor(along);
            const int joint = (along - b) * brick < 2.5;
            const float grain = (float)(sy_hash((uint32_t)x, (uint32_t)y, seed) % 1000u) / 1000.0f * 0.06f;
            const float face = 0.35f + (float)(sy_hash((uint32_t)b, (uint32_t)c + 7u, seed) % 100u) / 400.0f;
            const float tone = mortar_row || joint ? 0.85f : face;
            for (k = 0; k < 3; k++) sy_px(im, x, y)[k] = tone + grain;
            sy_px(im, x, y)[3] = 1.0f;
        }
    }
    return im;
}

/* The distance from v to the nearest phase + k * period. */
static double sy_off_courses(double v, const tt_courses *c)
{
    double r = fmod(v - c->phase, c->period);
    if (r < 0.0) r += c->period;
    return r < c->period - r ? r : c->period - r;
}

/* Correlation of two series of n values (0 when one is flat). */
static double sy_correlation(const double *a, const double *b, int n)
{
    double ma = 0.0, mb = 0.0, ab = 0.0, aa = 0.0, bb = 0.0;
    int i;
    for (i = 0; i < n; i++) {
        ma += a[i] / n;
        mb += b[i] / n;
    }
    for (i = 0; i < n; i++) {
        ab += (a[i] - ma) * (b[i] - mb);
        aa += (a[i] - ma) * (a[i] - ma);
        bb += (b[i] - mb) * (b[i] - mb);
    }
    return aa > 0.0 && bb > 0.0 ? ab / sqrt(aa * bb) : 0.0;
}

static void test_find_courses(void)
{
    const double period = 23.5, phase = 7.25;
    tt_image *bricks = sy_bricks(240, 240, period, phase, 3u), *turned = NULL, *noise = sy_noise(240, 240, 8u);
    tt_courses c;
    tt_error err;
    int x, y, shifted;
    if (!bricks || !noise || tt_image_rotate90(bricks, 1, NULL, &turned, NULL) != TT_OK) {
        CHECK(0, "images");
        tt_image_free(bricks);
        tt_image_free(noise);
        return;
    }
    CHECK(tt_find_courses(bricks, NULL, &c, &err) == TT_OK && fabs(c.period - period) < 0.15 &&
              c.strength >= TT_COURSES_MIN_STRENGTH && c.coherence >= TT_COURSES_MIN_COHERENCE && c.phase >= 0.0f &&
              c.phase < c.period,
          "bricks of courses %.2f texels tall: period %.3f, strength %.3f, coherence %.3f", period, c.period,
          c.strength, c.coherence);
    /* The mortar's middle, or a course's: the rows mirror about both. */
    {
        tt_courses half = c;
        half.period = c.period / 2.0f;
        CHECK(sy_off_courses(phase, &half) < 0.75, "phase %.3f: the mortar is centred at %.2f (mod %.2f)", c.phase,
              phase, c.period / 2.0f);
    }
    /* Light falling off down the photo does not hide the courses or add one. */
    for (y = 0; y < bricks->height; y++)
        for (x = 0; x < bricks->width; x++) {
            float *p = sy_px(bricks, x, y);
            p[0] *= 1.0f - 0.5f * y / bricks->height;
            p[1] *= 1.0f - 0.5f * y / bricks->height;
            p[2] *= 1.0f - 0.5f * y / bricks->height;
        }
    CHECK(tt_find_courses(bricks, NULL, &c, &err) == TT_OK && fabs(c.period - period) < 0.15,
          "bricks darkening downward: period %.3f", c.period);
    /* Controls: courses running up the image, and a photo without rows. */
    CHECK(tt_find_courses(turned, NULL, &c, &err) == TT_OK && c.period == 0.0f && c.strength == 0.0f,
          "bricks turned a quarter: no courses across the rows (period %.3f)", c.period);
    CHECK(tt_find_courses(noise, NULL, &c, &err) == TT_OK && c.period == 0.0f && c.coherence == 0.0f,
          "noise: no courses (period %.3f)", c.period);
    /* The courses move with the rows. */
    tt_image_free(turned);
    turned = sy_bricks(240, 240, period, phase + 5.0, 3u);
    shifted = turned && tt_find_courses(turned, NULL, &c, &err) == TT_OK;
    c.period /= 2.0f;   /* either of the two mirror lines of a course */
    CHECK(shifted && sy_off_courses(phase + 5.0, &c) < 0.75, "bricks moved down 5 rows: phase %.3f", c.phase);
    /* A photo taller than the rows looked at is reduced first; what is
       found is scaled back. */
    {
        tt_image *tall = sy_bricks(500, 700, 61.25, 20.0, 4u);
        tt_courses half;
        CHECK(tall && tt_find_courses(tall, NULL, &c, &err) == TT_OK && fabs(c.period - 61.25) < 0.6,
              "bricks 700 rows tall, courses 61.25: period %.3f", c.period);
        half = c;
        half.period = c.period / 2.0f;
        CHECK(c.period > 0.0f && sy_off_courses(20.0, &half) < 2.5, "700 rows tall: phase %.3f, mortar at 20 (mod %.2f)",
              c.phase, half.period);
        tt_image_free(tall);
    }
    /* Too short for three courses of any height: none, and no error. */
    {
        tt_image *flat = sy_bricks(64, 11, 3.0, 0.0, 1u);
        CHECK(flat && tt_find_courses(flat, NULL, &c, &err) == TT_OK && c.period == 0.0f, "an 11-row photo");
        tt_image_free(flat);
    }
    /* Errors. */
    CHECK(tt_find_courses(bricks, NULL, NULL, &err) == TT_ERROR_INVALID_ARGUMENT, "NULL out: %s", err.message);
    CHECK(tt_find_courses(NULL, NULL, &c, &err) == TT_ERROR_INVALID_ARGUMENT && c.period == 0.0f, "NULL image: %s",
          err.message);
    sy_px(bricks, 3, 100)[1] = (float)internal_not_a_number();
    CHECK(tt_find_courses(bricks, NULL, &c, &err) == TT_ERROR_NON_FINITE && c.period == 0.0f, "a NaN texel: %s",
          err.message);
    tt_image_free(bricks);
    tt_image_free(turned);
    tt_image_free(noise);
}

/* Upright tiles cut on the courses: every window starts on them, and in
   every tile the courses run level, band and background alike. The control
   is the same plan without courses. The measure: per tile, each 4-texel
   column strip's row profile against the tile's background's, the worst
   strip of the tile, averaged over the tiles. */
static void test_synthesis_keeps_courses(void)
{
    const int S = 32, g = 4;
    tt_image *bricks = sy_bricks(200, 200, 16.0, 5.0, 11u);
    tt_courses found;
    double score[2] = {0.0, 0.0};
    int with, on_courses[2] = {0, 0}, windows[2] = {0, 0};
    tt_error err;
    if (!bricks || tt_find_courses(bricks, NULL, &found, &err) != TT_OK || found.period == 0.0f) {
        CHECK(0, "bricks and their courses: %s", bricks ? err.message : "no image");
        tt_image_free(bricks);
        return;
    }
    for (with = 0; with < 2; with++) {
        tt_synth_options o = sy_options(2, S, g, 21u);
        tt_synth_plan *plan = NULL;
        tt_tileset *set = NULL;
        int tiles, t, k;
        o.upright = 1;
        if (with) o.courses = found;
        if (tt_synth_plan_create(bricks, &o, NULL, &plan, &err) != TT_OK ||
            tt_synth_apply(plan, bricks, NULL, &set, &err) != TT_OK) {
            CHECK(0, "upright tiles of bricks: %s", err.message);
            tt_synth_plan_free(plan);
            continue;
        }
        tiles = tt_tile_layout_tile_count(&plan->layout);
        for (k = 0; k < 2; k++) {
            on_courses[with] += sy_off_courses(plan->edge_windows[k].y, &found) <= 0.51;
            on_courses[with] += sy_off_courses(plan->vertical_windows[k].y, &found) <= 0.51;
            windows[with] += 2;
        }
        for (t = 0; t < tiles; t++) {
            double profile[32], background[32], worst = 1.0;
            uint8_t types[4];
            int cx, cy, x0, x, y;
            on_courses[with] += sy_off_courses(plan->background_windows[t].y, &found) <= 0.51;
            windows[with]++;
            sy_tile_types(&plan->layout, t, types, &cx, &cy);
            for (y = 0; y < S; y++) {
                const tt_rect *r = &plan->background_windows[t];
                background[y] = 0.0;
                for (x = 0; x < S; x++) background[y] += sy_px(bricks, r->x + x, r->y + y)[0];
            }
            for (x0 = 0; x0 < S; x0 += 4) {
                double c;
                for (y = 0; y < S; y++) {
                    profile[y] = 0.0;
                    for (x = x0; x < x0 + 4; x++) profile[y] += sy_px(&set->levels[0], cx + g + x, cy + g + y)[0];
                }
                c = sy_correlation(profile, background, S);
                if (c < worst) worst = c;
            }
            score[with] += worst / tiles;
        }
        tt_tileset_free(set);
        tt_synth_plan_free(plan);
    }
    printf("     upright tiles of bricks, worst column strip against the background: %.3f on the courses, "
           "%.3f without (windows on the courses: %d of %d, %d of %d)\n",
           score[1], score[0], on_courses[1], windows[1], on_courses[0], windows[0]);
    CHECK(on_courses[1] == windows[1], "with courses every window starts on them: %d of %d", on_courses[1],
          windows[1]);
    CHECK(on_courses[0] < windows[0] / 2, "the control's windows fall anywhere: %d of %d on the courses",
          on_courses[0], windows[0]);
    CHECK(score[1] >= 0.6, "on the courses every strip of a tile follows its background's rows: %.3f", score[1]);
    CHECK(score[0] <= 0.3, "the control's bands show other rows: %.3f", score[0]);
    /* Bad courses are refused. */
    {
        tt_synth_options o = sy_options(2, S, g, 21u);
        tt_synth_plan *plan = NULL;
        o.courses.period = 1.0f;
        CHECK(tt_synth_plan_create(bricks, &o, NULL, &plan, &err) == TT_ERROR_INVALID_ARGUMENT && !plan &&
                  strstr(err.message, "period"),
              "a period of 1: %s", err.message);
        o.courses.period = 16.0f;
        o.courses.phase = (float)internal_not_a_number();
        CHECK(tt_synth_plan_create(bricks, &o, NULL, &plan, &err) == TT_ERROR_INVALID_ARGUMENT && !plan,
              "a NaN phase: %s", err.message);
    }
    tt_image_free(bricks);
}

static void test_affine_map(void)
{
    static const float scale[3] = {0.5f, -0.7f, 2.0f}, offset[3] = {0.25f, 0.9f, -0.5f};
    tt_image *a = sy_noise(80, 96, 51u), *b = NULL;
    tt_synth_options o = sy_options(2, 16, 4, 13u);
    tt_synth_plan *plan = NULL;
    tt_tileset *sa = NULL, *sb = NULL;
    tt_error err;
    tt_result r;
    size_t i, n;
    int l, k, bad = 0, alpha_bad = 0;
    double worst = 0.0;
    b = sy_copy(a);
    n = sy_floats(a);
    for (i = 0; i < n; i += 4)
        for (k = 0; k < 3; k++) b->pixels[i + k] = scale[k] * a->pixels[i + k] + offset[k];
    r = tt_synth_plan_create(a, &o, NULL, &plan, &err);
    if (r == TT_OK) r = tt_synth_apply(plan, a, NULL, &sa, &err);
    if (r == TT_OK) r = tt_synth_apply(plan, b, NULL, &sb, &err);
    CHECK(r == TT_OK, "plan + two applies: %d (%s)", r, err.message);
    if (r == TT_OK) {
        for (l = 0; l < sa->nlevels; l++) {
            n = sy_floats(&sa->levels[l]);
            for (i = 0; i < n; i += 4) {
                for (k = 0; k < 3; k++) {
                    double want = (double)scale[k] * sa->levels[l].pixels[i + k] + offset[k];
                    double e = fabs(want - sb->levels[l].pixels[i + k]);
                    if (e > worst) worst = e;
                    if (e > 2e-6) bad++;
                }
                if (sa->levels[l].pixels[i + 3] != 1.0f || sb->levels[l].pixels[i + 3] != 1.0f) alpha_bad++;
            }
        }
        CHECK(bad == 0, "atlas_B = s * atlas_A + o: %d values off by more than 2e-6 (worst %g)", bad, worst);
        CHECK(alpha_bad == 0, "both atlases opaque: %d texels with alpha != 1", alpha_bad);
    }
    tt_tileset_free(sa);
    tt_tileset_free(sb);
    tt_synth_plan_free(plan);
    tt_image_free(a);
    tt_image_free(b);
}

/* ------------------------------------------------------------------------ */
/* Errors                                                                   */
/* ------------------------------------------------------------------------ */

static void test_plan_create_errors(void)
{
    tt_image *src = sy_noise(96, 128, 61u), *bad = NULL;
    tt_synth_options o = sy_options(1, 32, 4, 1u);
    tt_synth_plan *plan;
    tt_allocator half;
    tt_rect windows[2];
    tt_image empty;
    tt_error err;
    tt_result r;
    memset(&empty, 0, sizeof empty);
    memset(&half, 0, sizeof half);
    half.free = sy_free;

    CHECK(tt_synth_plan_create(src, &o, NULL, NULL, &err) == TT_ERROR_INVALID_ARGUMENT && err.message[0],
          "NULL out_plan");
    plan = (tt_synth_plan *)&o;
    CHECK(tt_synth_plan_create(NULL, &o, NULL, &plan, &err) == TT_ERROR_INVALID_ARGUMENT && plan == NULL,
          "NULL guide: TT_ERROR_INVALID_ARGUMENT, *out_plan NULL");
    CHECK(tt_synth_plan_create(&empty, &o, NULL, &plan, &err) == TT_ERROR_INVALID_ARGUMENT, "empty guide");
    CHECK(tt_synth_plan_create(src, &o, &half, &plan, &err) == TT_ERROR_INVALID_ARGUMENT,
          "an allocator with free but no alloc");
    r = tt_synth_plan_create(src, NULL, NULL, &plan, &err);
    CHECK(r == TT_ERROR_IMAGE_TOO_SMALL, "NULL options = defaults: 128-texel tiles need 128x256, the guide is "
          "96x128: %d", r);
    /* A NaN and an infinity in the guide, named by row and column. */
    bad = sy_copy(src);
    sy_px(bad, 17, 33)[1] = NAN;
    plan = (tt_synth_plan *)&o;
    r = tt_synth_plan_create(bad, &o, NULL, &plan, &err);
    CHECK(r == TT_ERROR_NON_FINITE && err.row == 33 && err.column == 17 && plan == NULL,
          "NaN guide texel (17, 33): %d, row %d column %d (%s)", r, err.row, err.column, err.message);
    sy_px(bad, 17, 33)[1] = 0.5f;
    sy_px(bad, 95, 127)[3] = INFINITY;
    r = tt_synth_plan_create(bad, &o, NULL, &plan, &err);
    CHECK(r == TT_ERROR_NON_FINITE && err.row == 127 && err.column == 95,
          "infinite alpha at the last texel: %d, row %d column %d", r, err.row, err.column);
    tt_image_free(bad);
    /* Layout, size, feather, regions, windows. */
    o.layout.colors = -1;
    CHECK(tt_synth_plan_create(src, &o, NULL, &plan, &err) == TT_ERROR_INVALID_ARGUMENT, "colors -1");
    o.layout.colors = 1;
    o.layout.tile_size = 3;
    CHECK(tt_synth_plan_create(src, &o, NULL, &plan, &err) == TT_ERROR_INVALID_ARGUMENT, "tile size 3");
    o.layout.tile_size = 65;
    r = tt_synth_plan_create(src, &o, NULL, &plan, &err);
    CHECK(r == TT_ERROR_IMAGE_TOO_SMALL && sy_has_number(err.message, 65),
          "65-texel tiles need 65x130 in a 96x128 guide: %d (%s)", r, err.message);
    o.layout.tile_size = 32;
    o.feather = 32 / 4 + 2;
    CHECK(tt_synth_plan_create(src, &o, NULL, &plan, &err) == TT_ERROR_INVALID_ARGUMENT, "feather S/4 + 2");
    o.feather = 32 / 4 + 1;
    r = tt_synth_plan_create(src, &o, NULL, &plan, &err);
    CHECK(r == TT_OK && plan->feather == 9, "feather S/4 + 1 is allowed: %d", r);
    tt_synth_plan_free(plan);
    o.feather = 0;
    o.background.x = 70;
    o.background.y = 0;
    o.background.w = 32;
    o.background.h = 32;
    CHECK(tt_synth_plan_create(src, &o, NULL, &plan, &err) == TT_ERROR_INVALID_ARGUMENT,
          "background region past the right side");
    o.background.x = 0;
    o.background.w = 31;
    CHECK(tt_synth_plan_create(src, &o, NULL, &plan, &err) == TT_ERROR_IMAGE_TOO_SMALL,
          "background region narrower than a tile");
    memset(&o.background, 0, sizeof o.background);
    memset(windows, 0, sizeof windows);
    windows[0].x = 96 - 32 + 1;
    o.edge_windows = windows;
    r = tt_synth_plan_create(src, &o, NULL, &plan, &err);
    CHECK(r == TT_ERROR_INVALID_ARGUMENT && err.item == 0 && plan == NULL,
          "an edge window one texel past the side: %d, item %d", r, err.item);
    windows[0].x = 96 - 32;
    windows[0].y = 128 - 64;
    r = tt_synth_plan_create(src, &o, NULL, &plan, &err);
    CHECK(r == TT_OK && plan->edge_windows[0].x == 64 && plan->edge_windows[0].y == 64 &&
              plan->edge_windows[0].w == 32 && plan->edge_windows[0].h == 64,
          "an edge window in the bottom-right corner fits: %d", r);
    tt_synth_plan_free(plan);
    tt_synth_plan_free(NULL);
    tt_image_free(src);
}

static void test_compose_tile_errors(void)
{
    tt_image *src = sy_noise(96, 128, 71u), *small = sy_noise(96, 127, 71u), *target = NULL, *bad = NULL;
    tt_synth_options o = sy_options(1, 32, 4, 3u);
    tt_synth_plan *plan = NULL, copy;
    tt_image no_pixels;
    uint8_t types[4] = {0, 1, 1, 0}, wrong[4] = {0, 1, 2, 0};
    tt_error err;
    tt_result r;
    int tile, fx = -1, fy = -1, x, y;
    memset(&no_pixels, 0, sizeof no_pixels);
    no_pixels.width = no_pixels.height = 64;
    r = tt_synth_plan_create(src, &o, NULL, &plan, &err);
    tt_image_create(50, 45, NULL, &target, NULL);
    CHECK(r == TT_OK && target, "plan: %d (%s)", r, err.message);
    if (r != TT_OK || !target) goto out;
    CHECK(tt_synth_compose_tile(plan, src, types, target, 10, 5, &err) == TT_OK, "a 40x40 cell at (10, 5) of 50x45");
    CHECK(tt_synth_compose_tile(NULL, src, types, target, 0, 0, &err) == TT_ERROR_INVALID_ARGUMENT, "NULL plan");
    CHECK(tt_synth_compose_tile(plan, NULL, types, target, 0, 0, &err) == TT_ERROR_INVALID_ARGUMENT, "NULL source");
    CHECK(tt_synth_compose_tile(plan, src, NULL, target, 0, 0, &err) == TT_ERROR_INVALID_ARGUMENT, "NULL types");
    CHECK(tt_synth_compose_tile(plan, src, types, NULL, 0, 0, &err) == TT_ERROR_INVALID_ARGUMENT, "NULL target");
    CHECK(tt_synth_compose_tile(plan, src, types, &no_pixels, 0, 0, &err) == TT_ERROR_INVALID_ARGUMENT,
          "a target without pixels");
    r = tt_synth_compose_tile(plan, src, wrong, target, 0, 0, &err);
    CHECK(r == TT_ERROR_INDEX_OUT_OF_RANGE && err.item == 2,
          "type 2 with n = 1 on side 2: %d, item %d (%s)", r, err.item, err.message);
    wrong[2] = 255;
    CHECK(tt_synth_compose_tile(plan, src, wrong, target, 0, 0, &err) == TT_ERROR_INDEX_OUT_OF_RANGE, "type 255");
    r = tt_synth_compose_tile(plan, src, types, target, 11, 0, &err);
    CHECK(r == TT_ERROR_INVALID_ARGUMENT, "cell one texel past the right side: %d", r);
    CHECK(tt_synth_compose_tile(plan, src, types, target, 0, 6, &err) == TT_ERROR_INVALID_ARGUMENT,
          "cell one texel past the bottom");
    CHECK(tt_synth_compose_tile(plan, src, types, target, -1, 0, &err) == TT_ERROR_INVALID_ARGUMENT, "x = -1");
    CHECK(tt_synth_compose_tile(plan, src, types, target, 0, -1, &err) == TT_ERROR_INVALID_ARGUMENT, "y = -1");
    CHECK(tt_synth_compose_tile(plan, src, types, target, 0x7fffffff, 0, &err) == TT_ERROR_INVALID_ARGUMENT,
          "x = INT_MAX");
    r = tt_synth_compose_tile(plan, small, types, target, 0, 0, &err);
    CHECK(r == TT_ERROR_INVALID_ARGUMENT && sy_has_number(err.message, 127),
          "a 96x127 source for a plan of 96x128: %d (%s)", r, err.message);
    /* A plan changed by its reader is refused, never a read out of bounds. */
    copy = *plan;
    copy.feather = 0;
    CHECK(tt_synth_compose_tile(&copy, src, types, target, 0, 0, &err) == TT_ERROR_INVALID_ARGUMENT,
          "a plan with feather 0");
    copy = *plan;
    copy.depth8 = NULL;
    CHECK(tt_synth_compose_tile(&copy, src, types, target, 0, 0, &err) == TT_ERROR_INVALID_ARGUMENT,
          "a plan without depths");
    tile = tt_tile_index(&plan->layout, types);
    {
        tt_rect keep = plan->background_windows[tile];
        tt_tileset *set = NULL;
        plan->background_windows[tile].x = 96 - 31;
        r = tt_synth_compose_tile(plan, src, types, target, 0, 0, &err);
        CHECK(r == TT_ERROR_INVALID_ARGUMENT && err.item == tile, "a background window moved out: %d, item %d", r,
              err.item);
        r = tt_synth_apply(plan, src, NULL, &set, &err);
        CHECK(r == TT_ERROR_INVALID_ARGUMENT && set == NULL, "apply with that plan: %d", r);
        plan->background_windows[tile] = keep;
    }
    /* A NaN the tile reads (the middle of its background window, which no
       band covers) is named; a NaN outside every window the tile reads is
       not read, but apply, which reads the whole image, names it. */
    bad = sy_copy(src);
    {
        const tt_rect *bg = &plan->background_windows[tile];
        sy_px(bad, bg->x + 16, bg->y + 16)[0] = NAN;
        r = tt_synth_compose_tile(plan, bad, types, target, 0, 0, &err);
        CHECK(r == TT_ERROR_NON_FINITE && err.row == bg->y + 16 && err.column == bg->x + 16,
              "NaN in the tile's background: %d, row %d column %d (%s)", r, err.row, err.column, err.message);
        sy_px(bad, bg->x + 16, bg->y + 16)[0] = 0.5f;
        for (y = 0; y < 128 && fx < 0; y++)
            for (x = 0; x < 96 && fx < 0; x++) {
                const tt_rect *e = &plan->edge_windows[0];
                int in_bg = x >= bg->x && x < bg->x + 32 && y >= bg->y && y < bg->y + 32;
                int in_edge = x >= e->x && x < e->x + 32 && y >= e->y && y < e->y + 64;
                if (!in_bg && !in_edge) { fx = x; fy = y; }
            }
        CHECK(fx >= 0, "a texel outside the tile's windows");
        if (fx >= 0) {
            tt_tileset *set = NULL;
            sy_px(bad, fx, fy)[2] = INFINITY;
            r = tt_synth_compose_tile(plan, bad, types, target, 0, 0, &err);
            CHECK(r == TT_OK, "an infinity the tile does not read: %d (%s)", r, err.message);
            r = tt_synth_apply(plan, bad, NULL, &set, &err);
            CHECK(r == TT_ERROR_NON_FINITE && err.row == fy && err.column == fx && set == NULL,
                  "apply names it: %d, row %d column %d", r, err.row, err.column);
        }
    }
out:
    tt_image_free(bad);
    tt_image_free(target);
    tt_synth_plan_free(plan);
    tt_image_free(small);
    tt_image_free(src);
}

static void test_apply_errors(void)
{
    tt_image *src = sy_noise(96, 128, 81u), *other = sy_noise(97, 128, 81u);
    tt_synth_options o = sy_options(1, 32, 4, 3u);
    tt_synth_plan *plan = NULL;
    tt_tileset *set;
    tt_allocator half;
    tt_error err;
    tt_result r;
    memset(&half, 0, sizeof half);
    half.free = sy_free;
    r = tt_synth_plan_create(src, &o, NULL, &plan, &err);
    CHECK(r == TT_OK, "plan: %d", r);
    if (r == TT_OK) {
        set = (tt_tileset *)&o;
        CHECK(tt_synth_apply(NULL, src, NULL, &set, &err) == TT_ERROR_INVALID_ARGUMENT && set == NULL,
              "NULL plan, *out NULL");
        CHECK(tt_synth_apply(plan, NULL, NULL, &set, &err) == TT_ERROR_INVALID_ARGUMENT, "NULL source");
        CHECK(tt_synth_apply(plan, src, NULL, NULL, &err) == TT_ERROR_INVALID_ARGUMENT, "NULL out");
        CHECK(tt_synth_apply(plan, src, &half, &set, &err) == TT_ERROR_INVALID_ARGUMENT, "half an allocator");
        r = tt_synth_apply(plan, other, NULL, &set, &err);
        CHECK(r == TT_ERROR_INVALID_ARGUMENT && set == NULL && sy_has_number(err.message, 97),
              "a 97x128 source for a 96x128 plan: %d (%s)", r, err.message);
    }
    tt_synth_plan_free(plan);
    tt_image_free(other);
    tt_image_free(src);
}

/* ------------------------------------------------------------------------ */
/* Progress and cancelling                                                  */
/* ------------------------------------------------------------------------ */

typedef struct sy_progress {
    int calls, cancel_at, decreasing;
    float first, last;
} sy_progress;

static int sy_on_progress(float fraction, void *user_data)
{
    sy_progress *p = (sy_progress *)user_data;
    if (p->calls == 0) p->first = fraction;
    else if (fraction < p->last) p->decreasing++;
    p->last = fraction;
    p->calls++;
    return p->cancel_at >= 0 && p->calls > p->cancel_at;
}

static void sy_progress_reset(sy_progress *p, int cancel_at)
{
    memset(p, 0, sizeof *p);
    p->cancel_at = cancel_at;
}

static void test_progress_and_cancel(void)
{
    tt_image *src = sy_noise(80, 96, 91u);
    tt_synth_options o = sy_options(1, 16, 2, 3u);
    tt_synth_plan *plan = NULL;
    tt_tileset *set = NULL;
    sy_progress p;
    counter cnt;
    tt_allocator counting = make_allocator(&cnt, -1);
    tt_error err;
    tt_result r;
    const int tiles = 16;
    o.progress = sy_on_progress;
    o.progress_user_data = &p;

    sy_progress_reset(&p, -1);
    r = tt_synth_plan_create(src, &o, &counting, &plan, &err);
    CHECK(r == TT_OK && p.calls == tiles && p.decreasing == 0 && p.first > 0.0f && p.last == 1.0f,
          "plan_create reports once per tile, 0 < first, never decreasing, last 1: %d calls, first %g, last %g, "
          "%d decreases (result %d)", p.calls, p.first, p.last, p.decreasing, r);
    CHECK(r == TT_OK && plan->progress == sy_on_progress && plan->progress_user_data == &p,
          "the plan keeps the callback for apply");
    if (r == TT_OK) {
        sy_progress_reset(&p, -1);
        r = tt_synth_apply(plan, src, &counting, &set, &err);
        CHECK(r == TT_OK && p.calls == tiles && p.decreasing == 0 && p.last == 1.0f,
              "apply reports once per tile up to 1: %d calls, last %g", p.calls, p.last);
        tt_tileset_free(set);
        sy_progress_reset(&p, 5);
        set = (tt_tileset *)&o;
        r = tt_synth_apply(plan, src, &counting, &set, &err);
        CHECK(r == TT_CANCELLED && set == NULL && p.calls == 6, "apply cancelled at the 6th report: %d, %d calls",
              r, p.calls);
        plan->progress = NULL;
        sy_progress_reset(&p, 0);
        r = tt_synth_apply(plan, src, &counting, &set, &err);
        CHECK(r == TT_OK && p.calls == 0, "the plan's callback may be removed: %d, %d calls", r, p.calls);
        tt_tileset_free(set);
    }
    tt_synth_plan_free(plan);
    CHECK(cnt.live == 0, "plan and tilesets freed: %ld live allocations", cnt.live);

    sy_progress_reset(&p, 3);
    plan = (tt_synth_plan *)&o;
    r = tt_synth_plan_create(src, &o, &counting, &plan, &err);
    CHECK(r == TT_CANCELLED && plan == NULL && cnt.live == 0,
          "plan_create cancelled: %d, %ld live allocations", r, cnt.live);

    /* One run from 0 to 1 across both halves. */
    sy_progress_reset(&p, -1);
    r = tt_synthesize_tiles(src, &o, &counting, &set, &err);
    CHECK(r == TT_OK && p.calls == 2 * tiles && p.decreasing == 0 && p.first > 0.0f && p.last == 1.0f,
          "tt_synthesize_tiles: %d calls, first %g, last %g, %d decreases", p.calls, p.first, p.last, p.decreasing);
    tt_tileset_free(set);
    sy_progress_reset(&p, tiles + 2);
    r = tt_synthesize_tiles(src, &o, &counting, &set, &err);
    CHECK(r == TT_CANCELLED && set == NULL && cnt.live == 0,
          "tt_synthesize_tiles cancelled while applying: %d, %ld live", r, cnt.live);
    tt_image_free(src);
}

/* ------------------------------------------------------------------------ */
/* Allocation failures                                                      */
/* ------------------------------------------------------------------------ */

typedef struct sy_oom_context {
    const tt_image *source;
    const tt_synth_plan *plan;
    tt_synth_options options;
} sy_oom_context;

static tt_result sy_oom_plan(void *ctx, const tt_allocator *allocator, tt_error *error)
{
    sy_oom_context *c = (sy_oom_context *)ctx;
    tt_synth_plan *plan = (tt_synth_plan *)ctx;
    tt_result r = tt_synth_plan_create(c->source, &c->options, allocator, &plan, error);
    if (r != TT_OK && plan != NULL) return TT_RESULT_MAX_ENUM;
    tt_synth_plan_free(plan);
    return r;
}

static tt_result sy_oom_apply(void *ctx, const tt_allocator *allocator, tt_error *error)
{
    sy_oom_context *c = (sy_oom_context *)ctx;
    tt_tileset *set = (tt_tileset *)ctx;
    tt_result r = tt_synth_apply(c->plan, c->source, allocator, &set, error);
    if (r != TT_OK && set != NULL) return TT_RESULT_MAX_ENUM;
    tt_tileset_free(set);
    return r;
}

static tt_result sy_oom_synthesize(void *ctx, const tt_allocator *allocator, tt_error *error)
{
    sy_oom_context *c = (sy_oom_context *)ctx;
    tt_tileset *set = (tt_tileset *)ctx;
    tt_result r = tt_synthesize_tiles(c->source, &c->options, allocator, &set, error);
    if (r != TT_OK && set != NULL) return TT_RESULT_MAX_ENUM;
    tt_tileset_free(set);
    return r;
}

static void test_allocation_failures(void)
{
    tt_image *src = sy_noise(64, 64, 101u);
    sy_oom_context c;
    tt_synth_plan *plan = NULL;
    c.source = src;
    c.options = sy_options(1, 8, 2, 4u);
    tt_synth_plan_create(src, &c.options, NULL, &plan, NULL);
    c.plan = plan;
    oom_reset();
    oom_sweep("tt_synth_plan_create", sy_oom_plan, &c, TT_OK);
    oom_sweep("tt_synth_apply", sy_oom_apply, &c, TT_OK);
    oom_sweep("tt_synthesize_tiles", sy_oom_synthesize, &c, TT_OK);
    tt_synth_plan_free(plan);
    /* Upright: the turned guide the vertical windows are chosen on, and the tileset's copy of them. */
    c.options.upright = 1;
    tt_synth_plan_create(src, &c.options, NULL, &plan, NULL);
    c.plan = plan;
    oom_sweep("tt_synth_plan_create upright", sy_oom_plan, &c, TT_OK);
    oom_sweep("tt_synth_apply upright", sy_oom_apply, &c, TT_OK);
    tt_synth_plan_free(plan);
    tt_image_free(src);
}

/* ------------------------------------------------------------------------ */

void run_tiled_synthesis_tests(void)
{
    RUN(test_synthesize_matches_old_algorithm);
    RUN(test_background_tone);
    RUN(test_plan_fields);
    RUN(test_plan_wide_depths);
    RUN(test_compose_tile_matches_apply);
    RUN(test_bands_meet_on_diagonals);
    RUN(test_synthesis_executor_identical);
    RUN(test_upright_tiles);
    RUN(test_upright_plain_sides);
    RUN(test_upright_atlas);
    RUN(test_synth_levels);
    RUN(test_find_courses);
    RUN(test_synthesis_keeps_courses);
    RUN(test_second_map_same_masks);
    RUN(test_normal_map_turns);
    RUN(test_normal_map_not_unit);
    RUN(test_affine_map);
    RUN(test_plan_create_errors);
    RUN(test_compose_tile_errors);
    RUN(test_apply_errors);
    RUN(test_progress_and_cancel);
    RUN(test_allocation_failures);
}
