/* bench.c - throughput figures for tiledtex.h (`make bench`).

   Prints one line per figure, `name value unit`, nothing else on stdout
   (problems go to stderr and make the exit status non-zero). Every timed
   figure is the median of several runs after one warm-up run, measured with
   the monotonic clock.

       build/bench            all figures (about a minute)
       build/bench build      only the figures whose name contains "build"
                              (handy under `perf record` or valgrind)

   The meshes are 1000 x 1000 torus grids: 1M vertices, 1M quads, 4M
   half-edges, closed (genus 1), so every half-edge has a twin. The second copy
   has its vertex ids randomly permuted (faces in the same order): it shows
   how much of the builder's time is memory locality rather than arithmetic.

   `memcpy_1M_quads` is the floor any builder must pay: allocate fresh buffers
   for the index and position arrays and copy them. `build_assign_uv_over_memcpy`
   is the end-to-end path (build, allocate the per-corner outputs, assign
   boundaries and UVs) divided by that floor.

   Memory state matters as much as the code: the first touch of a freshly
   mapped page costs about as much as copying it several times over, and glibc
   decides per call whether a big block comes fresh from the kernel or is
   recycled, depending on what was freed before. So the allocator is pinned:
     - the plain figures are "cold": every big block is a fresh mapping, page
       faults included for the library and for memcpy alike (a one-shot
       importer, a command-line tool);
     - the `_warm` figures recycle memory freed by the previous run, so no page
       faults (an engine that rebuilds meshes all the time).
   On a C library other than glibc the allocator is left alone and both kinds
   are whatever it does.

   `hpm_20k_faces` runs tt_hpm_map on a 20k-triangle torus with a 256 x 256
   three-channel image, and prints the fits it made beside the time.
   `polycube_100k_faces_res32_*` time the polycube's construction and the
   vertices' projection onto it on a 100k-triangle torus;
   `polycube_100k_faces_res32` the whole mapping of that torus, voxelisation
   to UVs, with the triangles it made, the ones left to the fallback
   and the collapsed pieces (no area on S); its atlas (timed apart) is `synth_n2_tile64`, the
   paper's 256 tiles at 64 texels. `atlas_charts_100k_faces` times
   tt_atlas_pack_charts on that torus at 2048 x 2048 (gutter 2, the tool's
   --bake), with the charts it made and the fraction of the atlas they fill.
   `lapped_bake_coarse_over_fine` bakes the pastes of a 32-triangle torus
   (about a hundred pastes per face) and of a 20k-triangle one (a few) into
   1024 x 1024 atlases: the time per baked texel of the coarse over the
   fine, which stays near 1 only while the bake passes by the pastes that
   give a texel nothing (it was about 10 when it composited them all).

   Peers: bench/bench_build.c times the half-edge build on three 1M-face
   meshes beside a radix-sort pairing yardstick, and bench_build_cgal.cpp
   beside CGAL's Surface_mesh when libcgal-dev is installed. */
#define _POSIX_C_SOURCE 199309L
#define TILEDTEX_IMPLEMENTATION
#include "tiledtex.h"
#include "bench_clock.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#ifdef __GLIBC__
#include <malloc.h>
#endif

#define GRID 1000           /* torus grid side: GRID * GRID quads */
#define RUNS_FAST 5         /* runs of the sub-second figures */
#define RUNS_SLOW 3         /* runs of the multi-second ones */
#define SLOW_MS 2500.0      /* a warm-up slower than this gets a single timed run */

static int bench_failed = 0;

static void *xmalloc(size_t size)
{
    void *p = malloc(size ? size : 1);
    if (!p) {
        fprintf(stderr, "bench: out of memory (%lu bytes)\n", (unsigned long)size);
        exit(1);
    }
    return p;
}

static void fail(const char *what, tt_result r, const tt_error *err)
{
    fprintf(stderr, "bench: %s failed: %s%s%s\n", what, tt_result_string(r),
            err ? " - " : "", err ? err->message : "");
    exit(1);
}

static void report(const char *name, double value, const char *unit)
{
    printf("%s %.*f %s\n", name, value < 10.0 ? 2 : 1, value, unit);
    fflush(stdout);
}

/* Cold: big blocks are mapped fresh and unmapped on free. Warm: they come
   from the heap and stay there after free (up to glibc's 32 MB mmap maximum). */
static void malloc_cold(void)
{
#ifdef __GLIBC__
    malloc_trim(0);
    mallopt(M_MMAP_THRESHOLD, 128 * 1024);
    mallopt(M_TRIM_THRESHOLD, 128 * 1024);
    malloc_trim(0);
#endif
}

static void malloc_warm(void)
{
#ifdef __GLIBC__
    mallopt(M_MMAP_THRESHOLD, 32 * 1024 * 1024);
    mallopt(M_TRIM_THRESHOLD, 1 << 30);
#endif
}

/* ---- selection on the command line ---------------------------------------- */

static int g_argc;
static char **g_argv;

static int wanted(const char *name)
{
    int i;
    if (g_argc <= 1) return 1;
    for (i = 1; i < g_argc; ++i)
        if (strstr(name, g_argv[i])) return 1;
    return 0;
}

/* ---- timing harness --------------------------------------------------------- */

/* One run: do untimed setup, time the work, do untimed teardown; return ms. */
typedef double (*run_fn)(void *ctx);

static double median_ms(run_fn fn, void *ctx, int runs)
{
    double t[16];
    int i;
    double warm = fn(ctx);
    if (warm > SLOW_MS) runs = 1;
    if (runs > 16) runs = 16;
    for (i = 0; i < runs; ++i) t[i] = fn(ctx);
    qsort(t, (size_t)runs, sizeof t[0], bench_cmp_double);
    return t[runs / 2];
}

/* ---- test data ---------------------------------------------------------------- */

static uint64_t splitmix64(uint64_t *s)
{
    uint64_t z = (*s += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

typedef struct grid_mesh {
    int nverts, nfaces;
    float *pos;     /* 3 * nverts */
    int *idx;       /* 4 * nfaces */
} grid_mesh;

/* Torus, u around the main axis (i), v around the tube (j); quad (i, j) is
   (i,j) (i+1,j) (i+1,j+1) (i,j+1), which is counter-clockwise seen from
   outside because dP/du x dP/dv points outwards. */
static void make_torus_rows(grid_mesh *m, int n, double thin);
static void make_torus(grid_mesh *m, int n) { make_torus_rows(m, n, 0.0); }

/* The n x n torus grid; with thin > 0 (n even) its rows around the ring come
   in pairs `thin` of a row's width apart, so half its quads (and their
   triangles) are slivers, as CAD exports and remeshed scans have. */
static void make_torus_rows(grid_mesh *m, int n, double thin)
{
    const double R = 1.0, r = 0.35, two_pi = 6.283185307179586;
    int i, j;
    m->nverts = n * n;
    m->nfaces = n * n;
    m->pos = (float *)xmalloc(sizeof(float) * 3 * (size_t)m->nverts);
    m->idx = (int *)xmalloc(sizeof(int) * 4 * (size_t)m->nfaces);
    for (i = 0; i < n; ++i) {
        double u = thin > 0.0 ? two_pi * (2 * (i / 2) + (i % 2) * 2.0 * thin) / n : two_pi * i / n;
        double cu = cos(u), su = sin(u);
        for (j = 0; j < n; ++j) {
            double v = two_pi * j / n, ring = R + r * cos(v);
            float *p = m->pos + 3 * ((size_t)i * n + j);
            p[0] = (float)(ring * cu);
            p[1] = (float)(ring * su);
            p[2] = (float)(r * sin(v));
        }
    }
    for (i = 0; i < n; ++i) {
        int i1 = (i + 1) % n;
        for (j = 0; j < n; ++j) {
            int j1 = (j + 1) % n;
            int *q = m->idx + 4 * ((size_t)i * n + j);
            q[0] = i * n + j;
            q[1] = i1 * n + j;
            q[2] = i1 * n + j1;
            q[3] = i * n + j1;
        }
    }
}

/* Same mesh with vertex ids renamed by a random permutation. */
static void make_shuffled(const grid_mesh *src, grid_mesh *dst, uint64_t seed)
{
    int *perm = (int *)xmalloc(sizeof(int) * (size_t)src->nverts);
    int v, c, ncorners = 4 * src->nfaces;
    for (v = 0; v < src->nverts; ++v) perm[v] = v;
    for (v = src->nverts - 1; v > 0; --v) {
        int k = (int)(splitmix64(&seed) % (uint64_t)(v + 1)), t = perm[v];
        perm[v] = perm[k];
        perm[k] = t;
    }
    dst->nverts = src->nverts;
    dst->nfaces = src->nfaces;
    dst->pos = (float *)xmalloc(sizeof(float) * 3 * (size_t)src->nverts);
    dst->idx = (int *)xmalloc(sizeof(int) * (size_t)ncorners);
    for (v = 0; v < src->nverts; ++v)
        memcpy(dst->pos + 3 * (size_t)perm[v], src->pos + 3 * (size_t)v, 3 * sizeof(float));
    for (c = 0; c < ncorners; ++c) dst->idx[c] = perm[src->idx[c]];
    free(perm);
}

static void free_grid(grid_mesh *m)
{
    free(m->pos);
    free(m->idx);
}

static tt_mesh_desc grid_desc(const grid_mesh *m)
{
    tt_mesh_desc d;
    memset(&d, 0, sizeof d);
    d.positions = m->pos;
    d.nverts = m->nverts;
    d.indices = m->idx;
    d.nfaces = m->nfaces;
    d.fixed_face_size = 4;
    d.flags = 0;            /* positions copied, strict validation */
    return d;
}

/* Value noise on an integer lattice, smoothly interpolated. */
static double lattice(int x, int y, int channel)
{
    uint64_t s = ((uint64_t)(uint32_t)x << 32) ^ (uint64_t)(uint32_t)y ^ ((uint64_t)channel << 58);
    return (double)(splitmix64(&s) >> 11) * (1.0 / 9007199254740992.0);
}

static double value_noise(double x, double y, int channel)
{
    int x0 = (int)floor(x), y0 = (int)floor(y);
    double fx = x - x0, fy = y - y0;
    double sx = fx * fx * (3 - 2 * fx), sy = fy * fy * (3 - 2 * fy);
    double a = lattice(x0, y0, channel), b = lattice(x0 + 1, y0, channel);
    double c = lattice(x0, y0 + 1, channel), d = lattice(x0 + 1, y0 + 1, channel);
    return (a + (b - a) * sx) * (1 - sy) + (c + (d - c) * sx) * sy;
}

/* A 512 x 512 "stone" texture: four octaves of noise per channel plus dark
   cracks where a coarse noise crosses one half. */
static tt_image *make_source(int size)
{
    int x, y, ch;
    tt_image *img = NULL;
    tt_error err;
    tt_result r = tt_image_create(size, size, NULL, &img, &err);
    if (r != TT_OK) fail("tt_image_create", r, &err);
    for (y = 0; y < size; ++y)
        for (x = 0; x < size; ++x) {
            float *p = img->pixels + 4 * ((size_t)y * size + x);
            double crack = fabs(value_noise(x / 24.0, y / 24.0, 7) - 0.5);
            double dark = crack < 0.03 ? 0.45 : 1.0;
            for (ch = 0; ch < 3; ++ch) {
                double v = 0, amp = 0.5, freq = 1.0 / 32.0;
                int o;
                for (o = 0; o < 4; ++o, amp *= 0.5, freq *= 2.0)
                    v += amp * value_noise(x * freq, y * freq, ch * 4 + o);
                v = (0.35 + 0.2 * ch) * 0.5 + 0.55 * v;
                p[ch] = (float)(v * dark);
            }
            p[3] = 1.0f;
        }
    return img;
}

/* ---- the figures ---------------------------------------------------------------- */

typedef struct build_ctx {
    const grid_mesh *grid;
} build_ctx;

static double run_build(void *p)
{
    build_ctx *ctx = (build_ctx *)p;
    tt_mesh_desc d = grid_desc(ctx->grid);
    tt_mesh *mesh = NULL;
    tt_error err;
    double t0 = bench_now_ms(), t1;
    tt_result r = tt_mesh_build(&d, NULL, &mesh, &err);
    t1 = bench_now_ms();
    if (r != TT_OK) fail("tt_mesh_build", r, &err);
    tt_mesh_free(mesh);
    return t1 - t0;
}

typedef struct assign_ctx {
    const tt_mesh *mesh;
    uint8_t *types;
    float *uv;
    uint64_t seed;
} assign_ctx;

static double run_assign(void *p)
{
    assign_ctx *ctx = (assign_ctx *)p;
    tt_tile_layout layout;
    tt_error err;
    tt_result r;
    double t0, t1;
    memset(&layout, 0, sizeof layout);
    t0 = bench_now_ms();
    r = tt_assign_boundaries(ctx->mesh, &layout, ctx->seed++, NULL, ctx->types, &err);
    if (r == TT_OK) r = tt_assign_uvs(ctx->mesh, &layout, ctx->types, ctx->uv, &err);
    t1 = bench_now_ms();
    if (r != TT_OK) fail("tt_assign_boundaries / tt_assign_uvs", r, NULL);
    return t1 - t0;
}

static double run_build_assign(void *p)
{
    build_ctx *ctx = (build_ctx *)p;
    tt_mesh_desc d = grid_desc(ctx->grid);
    tt_mesh *mesh = NULL;
    tt_tile_layout layout;
    uint8_t *types;
    float *uv;
    tt_error err;
    tt_result r;
    double t0, t1;
    memset(&layout, 0, sizeof layout);
    t0 = bench_now_ms();
    r = tt_mesh_build(&d, NULL, &mesh, &err);
    if (r != TT_OK) fail("tt_mesh_build", r, &err);
    types = (uint8_t *)xmalloc((size_t)mesh->ncorners);
    uv = (float *)xmalloc(sizeof(float) * 2 * (size_t)mesh->ncorners);
    r = tt_assign_boundaries(mesh, &layout, 42, NULL, types, &err);
    if (r == TT_OK) r = tt_assign_uvs(mesh, &layout, types, uv, &err);
    t1 = bench_now_ms();
    if (r != TT_OK) fail("tt_assign_boundaries / tt_assign_uvs", r, NULL);
    free(uv);
    free(types);
    tt_mesh_free(mesh);
    return t1 - t0;
}

static double run_memcpy(void *p)
{
    build_ctx *ctx = (build_ctx *)p;
    size_t ibytes = sizeof(int) * 4 * (size_t)ctx->grid->nfaces;
    size_t pbytes = sizeof(float) * 3 * (size_t)ctx->grid->nverts;
    int *idx;
    float *pos;
    double t0 = bench_now_ms(), t1;
    idx = (int *)xmalloc(ibytes);
    pos = (float *)xmalloc(pbytes);
    memcpy(idx, ctx->grid->idx, ibytes);
    memcpy(pos, ctx->grid->pos, pbytes);
    t1 = bench_now_ms();
    /* keep the copy observable so it cannot be optimised away */
    if (idx[ctx->grid->nfaces] != ctx->grid->idx[ctx->grid->nfaces] || pos[1] != ctx->grid->pos[1])
        fail("memcpy check", TT_OK, NULL);
    free(idx);
    free(pos);
    return t1 - t0;
}

typedef struct quad_ctx {
    const tt_mesh *mesh;
} quad_ctx;

static double run_quadrangulate(void *p)
{
    quad_ctx *ctx = (quad_ctx *)p;
    tt_mesh *out = NULL;
    tt_error err;
    double t0 = bench_now_ms(), t1;
    tt_result r = tt_mesh_quadrangulate(ctx->mesh, TT_SUBDIVIDE_LINEAR, NULL, &out, &err);
    t1 = bench_now_ms();
    if (r != TT_OK) fail("tt_mesh_quadrangulate", r, &err);
    tt_mesh_free(out);
    return t1 - t0;
}

typedef struct synth_ctx {
    const tt_image *source;
    int colors, tile_size;
    uint64_t seed;
} synth_ctx;

static double run_synth(void *p)
{
    synth_ctx *ctx = (synth_ctx *)p;
    tt_synth_options opt;
    tt_tileset *tiles = NULL;
    tt_error err;
    tt_result r;
    double t0, t1;
    memset(&opt, 0, sizeof opt);
    opt.layout.colors = ctx->colors;
    opt.layout.tile_size = ctx->tile_size;
    opt.seed = ctx->seed++;
    t0 = bench_now_ms();
    r = tt_synthesize_tiles(ctx->source, &opt, NULL, &tiles, &err);
    t1 = bench_now_ms();
    if (r != TT_OK) fail("tt_synthesize_tiles", r, &err);
    tt_tileset_free(tiles);
    return t1 - t0;
}

/* Untimed: the meshes really are what the figures claim (closed torus). */
/* Lapped textures (Praun et al.) end to end on a triangulated torus: the
   default tangent field and one 256 x 256 splotch patch at the default scale
   (a tenth of the bounding-box diagonal), field + paste loop timed. */
typedef struct lapped_ctx {
    tt_mesh *mesh;
    tt_image *patch;
    float *field;
    int pastes;
    double angle, scale, overdraw;
} lapped_ctx;

/* The default tangent field alone (a sparse solve, part of run_lapped). */
static double run_lapped_field(void *p)
{
    lapped_ctx *c = (lapped_ctx *)p;
    tt_error err;
    double t0 = bench_now_ms();
    tt_result r = tt_tangent_field(c->mesh, NULL, NULL, c->field, &err);
    if (r != TT_OK) fail("tt_tangent_field", r, &err);
    return bench_now_ms() - t0;
}

static double run_lapped(void *p)
{
    lapped_ctx *c = (lapped_ctx *)p;
    tt_lapped *lapped = NULL;
    tt_lapped_options options;
    tt_error err;
    tt_result r;
    double t0 = bench_now_ms(), t1;
    r = tt_tangent_field(c->mesh, NULL, NULL, c->field, &err);
    if (r != TT_OK) fail("tt_tangent_field", r, &err);
    memset(&options, 0, sizeof options);
    options.seed = 1;
    r = tt_lapped_paste(c->mesh, c->field, &c->patch, 1, &options, NULL, &lapped, &err);
    t1 = bench_now_ms();
    if (r != TT_OK) fail("tt_lapped_paste", r, &err);
    c->pastes = lapped->npastes;
    c->angle = lapped->mean_angle_error;
    c->scale = lapped->median_scale_error;
    c->overdraw = lapped->mean_overdraw;
    tt_lapped_free(lapped);
    return t1 - t0;
}

/* The n x n torus grid with every quad split into two triangles (rows
   paired `thin` apart: make_torus_rows). */
static tt_mesh *make_triangle_torus(int n, double thin)
{
    grid_mesh quads;
    tt_mesh_desc d;
    tt_mesh *mesh;
    tt_error err;
    tt_result r;
    int *tri, f, k;
    make_torus_rows(&quads, n, thin);
    tri = (int *)xmalloc(sizeof(int) * 6 * (size_t)quads.nfaces);
    for (f = 0; f < quads.nfaces; ++f)
        for (k = 0; k < 3; ++k) {
            tri[6 * (size_t)f + k] = quads.idx[4 * (size_t)f + k];
            tri[6 * (size_t)f + 3 + k] = quads.idx[4 * (size_t)f + (k + 2) % 4];
        }
    d = grid_desc(&quads);
    d.indices = tri;
    d.nfaces = 2 * quads.nfaces;
    d.fixed_face_size = 3;
    r = tt_mesh_build(&d, NULL, &mesh, &err);
    if (r != TT_OK) fail("tt_mesh_build (triangle torus)", r, &err);
    free(tri);
    free_grid(&quads);
    return mesh;
}

/* Returns the paste loop's time (the whole run less the field's). */
static double bench_lapped(const char *name, int n, double thin, tt_image *patch)
{
    lapped_ctx lc;
    char label[64];
    double total, field;
    lc.mesh = make_triangle_torus(n, thin);
    lc.patch = patch;
    lc.field = (float *)xmalloc(sizeof(float) * 3 * (size_t)lc.mesh->nfaces);
    report(name, total = median_ms(run_lapped, &lc, RUNS_SLOW), "ms");
    snprintf(label, sizeof label, "%s_field", name);
    report(label, field = median_ms(run_lapped_field, &lc, RUNS_SLOW), "ms");
    snprintf(label, sizeof label, "%s_pastes", name);
    report(label, lc.pastes, "pastes");
    snprintf(label, sizeof label, "%s_overdraw", name);
    report(label, lc.overdraw, "x");
    snprintf(label, sizeof label, "%s_angle_error", name);
    report(label, lc.angle, "deg");
    snprintf(label, sizeof label, "%s_scale_error", name);
    report(label, 100.0 * lc.scale, "%");
    free(lc.field);
    tt_mesh_free(lc.mesh);
    return total - field;
}

typedef struct bake_ctx {
    tt_mesh *mesh;
    tt_lapped *lapped;
    tt_image *patch, *atlas;
    float *uv;
} bake_ctx;

static double run_bake(void *p)
{
    bake_ctx *c = (bake_ctx *)p;
    tt_error err;
    double t0 = bench_now_ms(), t1;
    tt_result r = tt_lapped_bake(c->mesh, c->lapped, &c->patch, 1, c->uv, NULL, NULL, c->atlas, &err);
    t1 = bench_now_ms();
    if (r != TT_OK) fail("tt_lapped_bake", r, &err);
    return t1 - t0;
}

/* The bake of a torus of n x n quads split in two, pasted with the default
   field, reported with the pastes' overdraw; returns its time per texel
   inside the charts (ms per million). */
static double bench_bake(const char *name, int n, tt_image *patch)
{
    bake_ctx c;
    tt_lapped_options options;
    tt_chart_atlas_report atlas_report;
    float *field;
    char label[64];
    tt_error err;
    tt_result r;
    double ms, overdraw;
    c.mesh = make_triangle_torus(n, 0.0);
    c.patch = patch;
    field = (float *)xmalloc(sizeof(float) * 3 * (size_t)c.mesh->nfaces);
    c.uv = (float *)xmalloc(sizeof(float) * 2 * (size_t)c.mesh->ncorners);
    r = tt_tangent_field(c.mesh, NULL, NULL, field, &err);
    if (r != TT_OK) fail("tt_tangent_field", r, &err);
    memset(&options, 0, sizeof options);
    options.seed = 1;
    r = tt_lapped_paste(c.mesh, field, &c.patch, 1, &options, NULL, &c.lapped, &err);
    if (r != TT_OK) fail("tt_lapped_paste", r, &err);
    overdraw = c.lapped->mean_overdraw;
    r = tt_atlas_pack_charts(c.mesh, 1024, 2, NULL, NULL, c.uv, &atlas_report, &err);
    if (r != TT_OK) fail("tt_atlas_pack_charts", r, &err);
    r = tt_image_create(1024, 1024, NULL, &c.atlas, &err);
    if (r != TT_OK) fail("tt_image_create", r, &err);
    ms = median_ms(run_bake, &c, RUNS_FAST);
    report(name, ms, "ms");
    snprintf(label, sizeof label, "%s_overdraw", name);
    report(label, overdraw, "x");
    tt_image_free(c.atlas);
    tt_lapped_free(c.lapped);
    free(c.uv);
    free(field);
    tt_mesh_free(c.mesh);
    /* the atlas's texels inside its charts, which the bake composites */
    return ms / (atlas_report.fill * 1024.0 * 1024.0 / 1e6);
}

typedef struct hpm_ctx {
    tt_mesh *mesh;
    tt_image *image;
    float *uv;
    tt_hpm_report report;
} hpm_ctx;

typedef struct polycube_ctx {
    tt_mesh *mesh;
    tt_polycube *polycube;      /* the last build's, kept for the projection */
    tt_surface_point *points;
    tt_polycube_report report;
    tt_polycube_projection_report projection;
    tt_polycube_map_report map_report;
    int output_triangles;
} polycube_ctx;

/* The polycube of a mesh at resolution 32: voxelisation, fill, repair,
   correction and the surface S. */
static double run_polycube_build(void *p)
{
    polycube_ctx *c = (polycube_ctx *)p;
    tt_polycube_options options;
    tt_error err;
    tt_result r;
    double t0, t1;
    tt_polycube_free(c->polycube);
    c->polycube = NULL;
    memset(&options, 0, sizeof options);
    options.resolution = 32;
    t0 = bench_now_ms();
    r = tt_polycube_build(c->mesh, &options, NULL, &c->polycube, &c->report, &err);
    t1 = bench_now_ms();
    if (r != TT_OK) fail("tt_polycube_build", r, &err);
    return t1 - t0;
}

/* Every vertex's point on S (the mapping's first step). */
static double run_polycube_project(void *p)
{
    polycube_ctx *c = (polycube_ctx *)p;
    tt_error err;
    tt_result r;
    double t0 = bench_now_ms(), t1;
    r = tt_polycube_project(c->polycube, c->mesh, NULL, c->points, &c->projection, &err);
    t1 = bench_now_ms();
    if (r != TT_OK) fail("tt_polycube_project", r, &err);
    return t1 - t0;
}

/* The whole mapping, voxelisation to UVs: the polycube, its
   Wang colouring and tile types, the model split on S, the UVs. The
   atlas's synthesis is timed apart: synth_n2_tile64, the paper's 256-tile
   layout. */
static double run_polycube_map(void *p)
{
    polycube_ctx *c = (polycube_ctx *)p;
    tt_polycube_options options;
    tt_polycube *polycube = NULL;
    tt_polycube_mapping *mapping = NULL;
    tt_tile_layout layout;
    int *colors = NULL;
    uint8_t *types = NULL;
    float *uv = NULL;
    tt_error err;
    tt_result r;
    double t0, t1;
    memset(&options, 0, sizeof options);
    options.resolution = 32;
    layout.colors = 2;
    layout.tile_size = 64;
    layout.gutter = 4;
    t0 = bench_now_ms();
    r = tt_polycube_build(c->mesh, &options, NULL, &polycube, NULL, &err);
    if (r != TT_OK) fail("tt_polycube_build", r, &err);
    colors = (int *)xmalloc(sizeof(int) * (size_t)polycube->surface->ncorners);
    types = (uint8_t *)xmalloc((size_t)polycube->surface->ncorners);
    if ((r = tt_polycube_edge_colors(polycube, 2, 1, 7, colors, &err)) != TT_OK ||
        (r = tt_assign_boundaries(polycube->surface, &layout, 7, colors, types, &err)) != TT_OK)
        fail("the polycube's tile types", r, &err);
    r = tt_polycube_map(polycube, c->mesh, NULL, NULL, &mapping, &c->map_report, &err);
    if (r != TT_OK) fail("tt_polycube_map", r, &err);
    uv = (float *)xmalloc(sizeof(float) * 6 * (size_t)mapping->ntriangles);
    r = tt_polycube_mapping_uvs(polycube, mapping, &layout, types, uv, &err);
    t1 = bench_now_ms();
    if (r != TT_OK) fail("tt_polycube_mapping_uvs", r, &err);
    c->output_triangles = mapping->ntriangles;
    free(uv);
    free(types);
    free(colors);
    tt_polycube_mapping_free(mapping);
    tt_polycube_free(polycube);
    return t1 - t0;
}

/* Hierarchical pattern mapping end to end: hierarchy, flattening, the
   turned copies' spectra, the fits and the texture coordinates. */
static double run_hpm(void *p)
{
    hpm_ctx *c = (hpm_ctx *)p;
    tt_hpm_options options;
    tt_error err;
    tt_result r;
    double t0 = bench_now_ms(), t1;
    memset(&options, 0, sizeof options);
    options.seed = 1;
    r = tt_hpm_map(c->mesh, c->image, &options, NULL, c->uv, NULL, &c->report, &err);
    t1 = bench_now_ms();
    if (r != TT_OK) fail("tt_hpm_map", r, &err);
    return t1 - t0;
}

/* The chart atlas of a mesh at 2048 x 2048, gutter 2 (the tool's --bake). */
typedef struct atlas_ctx {
    tt_mesh *mesh;
    float *uv;
    tt_chart_atlas_report report;
} atlas_ctx;

static double run_atlas_charts(void *p)
{
    atlas_ctx *c = (atlas_ctx *)p;
    tt_error err;
    tt_result r;
    double t0 = bench_now_ms(), t1;
    r = tt_atlas_pack_charts(c->mesh, 2048, 2, NULL, NULL, c->uv, &c->report, &err);
    t1 = bench_now_ms();
    if (r != TT_OK) fail("tt_atlas_pack_charts", r, &err);
    return t1 - t0;
}

static void check_mesh(const tt_mesh *mesh, const char *what)
{
    tt_mesh_stats st;
    tt_result r = tt_mesh_compute_stats(mesh, NULL, &st, NULL);
    if (r != TT_OK) fail("tt_mesh_compute_stats", r, NULL);
    if (mesh->ncorners != 4 * GRID * GRID || st.boundary_edges != 0 || st.genus != 1 ||
        st.edges != 2 * GRID * GRID || st.min_valence != 4 || st.max_valence != 4) {
        fprintf(stderr, "bench: %s: unexpected topology (corners %d, edges %d, boundary %d, genus %d, valence %d..%d)\n",
                what, mesh->ncorners, st.edges, st.boundary_edges, st.genus, st.min_valence, st.max_valence);
        bench_failed = 1;
    }
}

int main(int argc, char **argv)
{
    grid_mesh grid, shuffled;
    build_ctx bc, bcs;
    double build_ms = -1, e2e_ms = -1, memcpy_ms = -1;
    int halfedges = 4 * GRID * GRID;

    g_argc = argc;
    g_argv = argv;
    malloc_cold();
    make_torus(&grid, GRID);
    bc.grid = &grid;

    if (wanted("build_1M_quads") || wanted("build_1M_quads_per_halfedge")) {
        build_ms = median_ms(run_build, &bc, RUNS_FAST);
        report("build_1M_quads", build_ms, "ms");
        report("build_1M_quads_per_halfedge", build_ms * 1e6 / halfedges, "ns");
    }
    if (wanted("build_1M_quads_shuffled")) {
        double ms;
        make_shuffled(&grid, &shuffled, 12345);
        bcs.grid = &shuffled;
        ms = median_ms(run_build, &bcs, RUNS_FAST);
        report("build_1M_quads_shuffled", ms, "ms");
        report("build_1M_quads_shuffled_per_halfedge", ms * 1e6 / halfedges, "ns");
        {
            tt_mesh_desc d = grid_desc(&shuffled);
            tt_mesh *mesh;
            tt_error err;
            tt_result r = tt_mesh_build(&d, NULL, &mesh, &err);
            if (r != TT_OK) fail("tt_mesh_build (shuffled)", r, &err);
            check_mesh(mesh, "shuffled torus");
            tt_mesh_free(mesh);
        }
        free_grid(&shuffled);
    }
    if (wanted("assign_uv_1M_quads") || wanted("quadrangulate_1M_quads")) {
        tt_mesh_desc d = grid_desc(&grid);
        tt_mesh *mesh;
        tt_error err;
        tt_result r = tt_mesh_build(&d, NULL, &mesh, &err);
        if (r != TT_OK) fail("tt_mesh_build", r, &err);
        check_mesh(mesh, "torus");
        if (wanted("assign_uv_1M_quads")) {
            assign_ctx ac;
            ac.mesh = mesh;
            ac.seed = 1;
            ac.types = (uint8_t *)xmalloc((size_t)mesh->ncorners);
            ac.uv = (float *)xmalloc(sizeof(float) * 2 * (size_t)mesh->ncorners);
            report("assign_uv_1M_quads", median_ms(run_assign, &ac, RUNS_FAST), "ms");
            free(ac.types);
            free(ac.uv);
        }
        if (wanted("quadrangulate_1M_quads")) {
            quad_ctx qc;
            qc.mesh = mesh;
            report("quadrangulate_1M_quads", median_ms(run_quadrangulate, &qc, RUNS_SLOW), "ms");
        }
        tt_mesh_free(mesh);
    }
    if (wanted("build_assign_uv_1M_quads") || wanted("build_assign_uv_over_memcpy")) {
        e2e_ms = median_ms(run_build_assign, &bc, RUNS_FAST);
        report("build_assign_uv_1M_quads", e2e_ms, "ms");
    }
    if (wanted("memcpy_1M_quads") || wanted("build_assign_uv_over_memcpy")) {
        memcpy_ms = median_ms(run_memcpy, &bc, RUNS_FAST);
        report("memcpy_1M_quads", memcpy_ms, "ms");
    }
    if (e2e_ms >= 0 && memcpy_ms > 0) report("build_assign_uv_over_memcpy", e2e_ms / memcpy_ms, "x");

    malloc_warm();
    if (wanted("build_1M_quads_warm")) {
        build_ms = median_ms(run_build, &bc, RUNS_FAST);
        report("build_1M_quads_warm", build_ms, "ms");
        report("build_1M_quads_warm_per_halfedge", build_ms * 1e6 / halfedges, "ns");
    }
    e2e_ms = memcpy_ms = -1;
    if (wanted("build_assign_uv_1M_quads_warm") || wanted("build_assign_uv_over_memcpy_warm")) {
        e2e_ms = median_ms(run_build_assign, &bc, RUNS_FAST);
        report("build_assign_uv_1M_quads_warm", e2e_ms, "ms");
    }
    if (wanted("memcpy_1M_quads_warm") || wanted("build_assign_uv_over_memcpy_warm")) {
        memcpy_ms = median_ms(run_memcpy, &bc, RUNS_FAST);
        report("memcpy_1M_quads_warm", memcpy_ms, "ms");
    }
    if (e2e_ms >= 0 && memcpy_ms > 0) report("build_assign_uv_over_memcpy_warm", e2e_ms / memcpy_ms, "x");
    malloc_cold();
    free_grid(&grid);

    if (wanted("synth_n1_tile256") || wanted("synth_n2_tile64")) {
        tt_image *source = make_source(512);
        synth_ctx sc;
        sc.source = source;
        sc.seed = 7;
        if (wanted("synth_n1_tile256")) {
            sc.colors = 1;
            sc.tile_size = 256;
            report("synth_n1_tile256", median_ms(run_synth, &sc, RUNS_SLOW), "ms");
        }
        if (wanted("synth_n2_tile64")) {
            sc.colors = 2;
            sc.tile_size = 64;
            report("synth_n2_tile64", median_ms(run_synth, &sc, RUNS_SLOW), "ms");
        }
        tt_image_free(source);
    }
    if (wanted("lapped_20k_faces") || wanted("lapped_100k_faces") || wanted("lapped_slivers")) {
        tt_image *source = make_source(256), *patch = NULL;
        tt_error err;
        tt_result r;
        r = tt_make_texture_patch(source, NULL, NULL, NULL, &patch, &err);
        if (r != TT_OK) fail("tt_make_texture_patch", r, &err);
        if (wanted("lapped_20k_faces")) bench_lapped("lapped_20k_faces", 100, 0.0, patch);      /* 20000 triangles */
        if (wanted("lapped_100k_faces") || wanted("lapped_slivers")) {
            /* The same torus with half its triangles slivers (rows 1/25 of a row apart): the paste loop's
               time against the regular one's, at the same faces per paste and patch size. */
            double regular = bench_lapped("lapped_100k_faces", 224, 0.0, patch);      /* 100352 triangles */
            double slivers = bench_lapped("lapped_100k_faces_slivers", 224, 0.04, patch);
            report("lapped_slivers_over_regular", slivers / regular, "x");
        }
        tt_image_free(patch);
        tt_image_free(source);
    }
    if (wanted("lapped_bake")) {
        tt_image *source = make_source(256), *patch = NULL;
        tt_error err;
        tt_result r;
        double coarse, fine;
        r = tt_make_texture_patch(source, NULL, NULL, NULL, &patch, &err);
        if (r != TT_OK) fail("tt_make_texture_patch", r, &err);
        coarse = bench_bake("lapped_bake_coarse_32_faces", 4, patch);
        fine = bench_bake("lapped_bake_fine_20k_faces", 100, patch);
        report("lapped_bake_coarse_over_fine", coarse / fine, "x");
        tt_image_free(patch);
        tt_image_free(source);
    }
    if (wanted("hpm_20k_faces")) {
        /* 20000 triangles of a torus and a 256 x 256 three-channel photo-like
           image (the paper's sizes; the target is at most 5 s) */
        hpm_ctx hc;
        hc.mesh = make_triangle_torus(100, 0.0);
        hc.image = make_source(256);
        hc.uv = (float *)xmalloc(sizeof(float) * 2 * (size_t)hc.mesh->ncorners);
        report("hpm_20k_faces", median_ms(run_hpm, &hc, RUNS_SLOW), "ms");
        report("hpm_20k_faces_fits", hc.report.fits, "fits");
        report("hpm_20k_faces_fits_accepted", hc.report.accepted_fits, "fits");
        report("hpm_20k_faces_fits_rejected", hc.report.rejected_fits, "fits");
        report("hpm_20k_faces_clusters", hc.report.clusters, "clusters");
        report("hpm_20k_faces_mean_error", hc.report.mean_error, "eps");
        free(hc.uv);
        tt_image_free(hc.image);
        tt_mesh_free(hc.mesh);
    }
    if (wanted("atlas_charts_100k_faces")) {
        /* the chart atlas of a 100k-triangle torus at 2048 x 2048, gutter 2:
           growing the charts, flattening, packing at the largest scale */
        atlas_ctx ac;
        ac.mesh = make_triangle_torus(224, 0.0);
        ac.uv = (float *)xmalloc(sizeof(float) * 2 * (size_t)ac.mesh->ncorners);
        report("atlas_charts_100k_faces", median_ms(run_atlas_charts, &ac, RUNS_FAST), "ms");
        report("atlas_charts_100k_faces_charts", ac.report.ncharts, "charts");
        report("atlas_charts_100k_faces_fill", ac.report.fill, "fraction");
        free(ac.uv);
        tt_mesh_free(ac.mesh);
    }
    if (wanted("polycube_100k_faces_res32")) {
        /* the polycube on a 100k-triangle torus: its construction and the
           projection alone, then the whole mapping, voxelisation to UVs
           (the target is at most 1 s); its atlas is synth_n2_tile64 */
        polycube_ctx pc;
        memset(&pc, 0, sizeof pc);
        pc.mesh = make_triangle_torus(224, 0.0);
        pc.points = (tt_surface_point *)xmalloc(sizeof(tt_surface_point) * (size_t)pc.mesh->nverts);
        report("polycube_100k_faces_res32_build", median_ms(run_polycube_build, &pc, RUNS_FAST), "ms");
        report("polycube_100k_faces_res32_quads", pc.report.quads, "quads");
        report("polycube_100k_faces_res32_project", median_ms(run_polycube_project, &pc, RUNS_FAST), "ms");
        report("polycube_100k_faces_res32_fallbacks", pc.projection.fallbacks, "vertices");
        report("polycube_100k_faces_res32", median_ms(run_polycube_map, &pc, RUNS_SLOW), "ms");
        report("polycube_100k_faces_res32_output_triangles", pc.output_triangles, "triangles");
        report("polycube_100k_faces_res32_fallback_triangles", pc.map_report.fallback_triangles, "triangles");
        report("polycube_100k_faces_res32_flipped", pc.map_report.flipped, "triangles");
        report("polycube_100k_faces_res32_collapsed", pc.map_report.collapsed, "triangles");
        free(pc.points);
        tt_polycube_free(pc.polycube);
        tt_mesh_free(pc.mesh);
    }
    return bench_failed;
}
