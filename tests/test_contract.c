/* tests/test_contract.c - THE API CONTRACT of tiledtex.h, checked on every
   fallible public function with hostile arguments: NULL for each pointer,
   zero and negative sizes and counts, NaN and infinities (arguments, option
   fields, positions, texels), out-of-range indices, sizes that overflow,
   unknown flag bits and enum values, a half-set allocator, garbage options
   and hand-made objects that lie about themselves. Valid baseline inputs are
   built first; each case then changes one argument. Every case runs twice,
   with a tt_error pre-filled with 0x5a bytes and with NULL, and must give a
   negative tt_result (the same both times, never a crash or a sanitizer
   report), error->result equal to it with a one-sentence message, and every
   `T **out` NULL afterwards. Run by run_contract_tests() (section
   "contract"). TT_CONTRACT_FORK=1 runs each case in a child process, so that
   a crash counts as one violation and the run goes on (for hunting; the
   ordinary run must simply not crash). */
#define _POSIX_C_SOURCE 200809L   /* fork and waitpid under -std=c99 */
#include "test_common.h"

#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

/* The fallible public functions (every `TTDEF tt_result` of the header), in
   the header's order. tests/check_api.sh checks that this list is exactly
   the header's: a new function fails there until it has cases here. */
/* CONTRACT FUNCTIONS BEGIN */
static const char *const k_functions[] = {
    "tt_mesh_build",
    "tt_mesh_compute_stats",
    "tt_mesh_valence_histogram",
    "tt_mesh_components",
    "tt_mesh_boundary_loops",
    "tt_mesh_quadrangulate",
    "tt_mesh_quadrangulate_sources",
    "tt_corner_sources_apply",
    "tt_corner_normals",
    "tt_remesh_quads",
    "tt_image_create",
    "tt_image_from_bytes",
    "tt_image_rotate90",
    "tt_image_over",
    "tt_image_downsample2",
    "tt_image_resize",
    "tt_min_error_cut",
    "tt_sparse_from_triplets",
    "tt_sparse_multiply",
    "tt_cg_solve",
    "tt_fft_plan_create",
    "tt_fft_c2c",
    "tt_fft_r2c",
    "tt_fft_c2r",
    "tt_xcorr_texture_create",
    "tt_xcorr_masked",
    "tt_xcorr_masked_best",
    "tt_tile_layout_resolve",
    "tt_assign_boundaries",
    "tt_assign_uvs",
    "tt_orient_tiles",
    "tt_assign_uvs_oriented",
    "tt_reduce_tiles",
    "tt_find_courses",
    "tt_synth_plan_create",
    "tt_synth_compose_tile",
    "tt_synth_apply",
    "tt_synthesize_tiles",
    "tt_upright_atlas",
    "tt_compact_atlas_create",
    "tt_compact_atlas_image",
    "tt_compact_atlas_image_parts",
    "tt_measure_seams",
    "tt_tile_histogram",
    "tt_face_stretch",
    "tt_measure_uv_distortion",
    "tt_tangent_field",
    "tt_field_face_weights",
    "tt_make_texture_patch",
    "tt_lapped_paste",
    "tt_lapped_measure",
    "tt_measure_uv_direction",
    "tt_atlas_pack_pairs",
    "tt_atlas_pack_charts",
    "tt_uv_check",
    "tt_lapped_bake",
    "tt_cluster_hierarchy_build",
    "tt_flatten_cluster",
    "tt_hpm_map",
    "tt_polycube_build",
    "tt_polycube_edge_colors",
    "tt_polycube_project",
    "tt_polycube_build_auto",
    "tt_polycube_trace_edges",
    "tt_polycube_map",
    "tt_polycube_mapping_uvs",
    "tt_polycube_orient_upright",
    "tt_polycube_mapping_uvs_upright",
};
/* CONTRACT FUNCTIONS END */
#define NFUNCTIONS ((int)(sizeof k_functions / sizeof k_functions[0]))

static int g_cases[NFUNCTIONS], g_violations[NFUNCTIONS], g_total_cases, g_total_violations, g_unknown;
static int g_fork;
static int g_garbage;   /* *out is set to &g_garbage before each call: it must come back NULL */

enum { OUT_NULL, OUT_UNTOUCHED, OUT_OBJECT };
static int out_state(const void *p) { return p == NULL ? OUT_NULL : p == (const void *)&g_garbage ? OUT_UNTOUCHED : OUT_OBJECT; }
static void no_free(void *p) { (void)p; }

/* The function a case calls: the name its text starts with. */
static int function_index(const char *call)
{
    int i;
    size_t n = strcspn(call, "( ");
    for (i = 0; i < NFUNCTIONS; i++)
        if (strlen(k_functions[i]) == n && strncmp(call, k_functions[i], n) == 0) return i;
    return -1;
}

static void violation(const char *call, int line, const char *why)
{
    int f = function_index(call);
    if (f >= 0) g_violations[f]++;
    g_total_violations++;
    if (g_total_violations <= 40) check_detail(__FILE__, line, "%s: %s", call, why);
}

/* Before a case: in fork mode the parent runs it in a child and counts what
   the child reports (exit 0 kept the contract, 2 broke it, anything else
   crashed), returning 0; otherwise (and in the child) 1: run it here. */
static int case_begin(const char *call, int line)
{
    int f = function_index(call);
    if (f < 0) {
        g_unknown++;
        return 0;
    }
    g_cases[f]++;
    g_total_cases++;
    if (g_fork) {
        int status = 0;
        pid_t pid;
        fflush(stdout);
        pid = fork();
        if (pid == 0) return 1;
        if (pid < 0 || waitpid(pid, &status, 0) != pid) {
            violation(call, line, "could not fork");
            return 0;
        }
        if (WIFEXITED(status) && WEXITSTATUS(status) == 0) return 0;
        if (WIFEXITED(status) && WEXITSTATUS(status) == 2) {
            g_violations[f]++;
            g_total_violations++;
            return 0;
        }
        violation(call, line, "crashed (a signal or a sanitizer report: run it without TT_CONTRACT_FORK)");
        return 0;
    }
    return 1;
}

/* After a case: the contract on its two runs. */
static void case_end(const char *call, int line, tt_result with, tt_result without, const tt_error *err, int has_out,
                     int out_with, int out_without)
{
    char why[400];
    const char *msg_end = (const char *)memchr(err->message, '\0', sizeof err->message);
    int before = g_total_violations;
    why[0] = '\0';
    if (with >= 0 || without >= 0)
        snprintf(why, sizeof why, "result %d with the error, %d without (expected negative)", (int)with, (int)without);
    else if (with != without)
        snprintf(why, sizeof why, "result %d with the error but %d without", (int)with, (int)without);
    else if (err->result != with)
        snprintf(why, sizeof why, "returned %d but error->result is %d", (int)with, (int)err->result);
    else if (!msg_end || err->message[0] == '\0')
        snprintf(why, sizeof why, "returned %d with %s message", (int)with, msg_end ? "an empty" : "an unterminated");
    else if (has_out && (out_with != OUT_NULL || out_without != OUT_NULL))
        snprintf(why, sizeof why, "returned %d and left *out %s", (int)with,
                 out_with == OUT_UNTOUCHED || out_without == OUT_UNTOUCHED ? "unset" : "pointing at an object");
    if (why[0]) {
        if (with < 0 && !(with >= 0 || without >= 0) && msg_end) {
            size_t n = strlen(why);
            snprintf(why + n, sizeof why - n, " [%s]", err->message);
        }
        violation(call, line, why);
    }
    if (g_fork) {
        fflush(stdout);
        _exit(g_total_violations > before ? 2 : 0);
    }
}

/* One case: `call` names E for its tt_error argument and, for OUT_CASE,
   passes &out (out a T * variable, freed with freefn if a call makes it). */
#define RUN_CASE(has_out, out, freefn, call)                                                                \
    do {                                                                                                   \
        if (case_begin(#call, __LINE__)) {                                                                           \
            tt_error err_, *E = &err_;                                                                     \
            tt_result r1_, r2_;                                                                            \
            int o1_, o2_;                                                                                  \
            memset(&err_, 0x5a, sizeof err_);                                                              \
            out = (void *)&g_garbage;                                                                      \
            r1_ = (call);                                                                                  \
            o1_ = out_state(out);                                                                          \
            if (o1_ == OUT_OBJECT) freefn(out);                                                            \
            E = NULL;                                                                                      \
            out = (void *)&g_garbage;                                                                      \
            r2_ = (call);                                                                                  \
            o2_ = out_state(out);                                                                          \
            if (o2_ == OUT_OBJECT) freefn(out);                                                            \
            out = NULL;                                                                                    \
            case_end(#call, __LINE__, r1_, r2_, &err_, has_out, o1_, o2_);                                           \
        }                                                                                                  \
    } while (0)
static void *g_no_out;
#define CASE(call) RUN_CASE(0, g_no_out, no_free, call)
#define OUT_CASE(out, freefn, call) RUN_CASE(1, out, freefn, call)

/* ------------------------------------------------------------------------ */
/* Allocators                                                               */
/* ------------------------------------------------------------------------ */

/* A valid allocator that refuses blocks above 256 MB, so that a size the
   library does not cap comes back as TT_ERROR_OUT_OF_MEMORY instead of an
   allocation the sanitizer aborts on. */
static void *capped_alloc(size_t size, void *user_data)
{
    (void)user_data;
    return size > ((size_t)256 << 20) ? NULL : malloc(size);
}
static void capped_free(void *p, void *user_data)
{
    (void)user_data;
    free(p);
}
static const tt_allocator g_capped = {capped_alloc, capped_free, NULL};
static const tt_allocator g_half_alloc = {capped_alloc, NULL, NULL};   /* alloc set, free NULL */
static const tt_allocator g_half_free = {NULL, capped_free, NULL};     /* free set, alloc NULL */
#define AL (&g_capped)
#define BA1 (&g_half_alloc)
#define BA2 (&g_half_free)

/* ------------------------------------------------------------------------ */
/* The cases                                                                */
/* ------------------------------------------------------------------------ */

static const float k_cube_pos[8 * 3] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0, 0, 1, 1, 0, 1, 1, 1, 1, 0, 1, 1};
static const int k_cube_idx[6 * 4] = {0, 3, 2, 1, 4, 5, 6, 7, 0, 1, 5, 4, 1, 2, 6, 5, 2, 3, 7, 6, 3, 0, 4, 7};

/* The baseline inputs every group of cases varies. */
typedef struct baseline {
    tt_mesh *quads;        /* the unit cube, 6 quads (closed) */
    tt_mesh *grid;         /* a 2 x 2 grid of quads (open) */
    tt_mesh *tris;         /* the unit cube, 12 triangles (closed) */
    tt_mesh *nan_tris;     /* tris over borrowed positions, one made NaN after the build */
    float nan_pos[8 * 3];
    tt_mesh empty;         /* tris as a hand-made mesh of no faces */
    tt_image *image;       /* 32 x 32 value noise, opaque */
    float nan_t, inf_t;
    double nan_d, inf_d;
} baseline;

static float *fdup(const float *p, size_t n)
{
    float *q = (float *)malloc(sizeof(float) * n);
    memcpy(q, p, sizeof(float) * n);
    return q;
}

/* A w x h view filled with `fill` (the caller's pixels: free(v.pixels)). */
static tt_image image_view(int w, int h, float fill)
{
    tt_image v;
    size_t i, n = (size_t)(w > 0 ? w : 1) * (h > 0 ? h : 1) * 4;
    memset(&v, 0, sizeof v);
    v.width = w;
    v.height = h;
    v.pixels = (float *)malloc(sizeof(float) * n);
    for (i = 0; i < n; i++) v.pixels[i] = fill;
    return v;
}

static void cases_mesh(const baseline *b)
{
    tt_mesh *out = NULL;
    tt_mesh_desc d, v;
    const tt_mesh *m = b->quads;
    tt_mesh_stats stats;
    int hist[8], comp[64], nc = 0, loops[64], nl = 0;
    float pos[8 * 3];
    int idx[6 * 4], sizes[2];
    tt_corner_sources *cs = NULL, *src = NULL;
    float in[96 * 3], outv[96 * 3], normals[96 * 3];
    memset(&d, 0, sizeof d);
    memcpy(pos, k_cube_pos, sizeof pos);
    memcpy(idx, k_cube_idx, sizeof idx);
    d.positions = pos;
    d.nverts = 8;
    d.indices = idx;
    d.nfaces = 6;
    d.fixed_face_size = 4;

    OUT_CASE(out, tt_mesh_free, tt_mesh_build(NULL, AL, &out, E));
    CASE(tt_mesh_build(&d, AL, NULL, E));
    OUT_CASE(out, tt_mesh_free, tt_mesh_build(&d, BA1, &out, E));
    OUT_CASE(out, tt_mesh_free, tt_mesh_build(&d, BA2, &out, E));
    v = d; v.positions = NULL;
    OUT_CASE(out, tt_mesh_free, tt_mesh_build(&v, AL, &out, E));
    v = d; v.indices = NULL;
    OUT_CASE(out, tt_mesh_free, tt_mesh_build(&v, AL, &out, E));
    v = d; v.nverts = 0;
    OUT_CASE(out, tt_mesh_free, tt_mesh_build(&v, AL, &out, E));
    v = d; v.nverts = -1;
    OUT_CASE(out, tt_mesh_free, tt_mesh_build(&v, AL, &out, E));
    v = d; v.nfaces = 0;
    OUT_CASE(out, tt_mesh_free, tt_mesh_build(&v, AL, &out, E));
    v = d; v.nfaces = -1;
    OUT_CASE(out, tt_mesh_free, tt_mesh_build(&v, AL, &out, E));
    v = d; v.nfaces = INT_MAX;   /* 4 * INT_MAX corners overflow */
    OUT_CASE(out, tt_mesh_free, tt_mesh_build(&v, AL, &out, E));
    v = d; v.fixed_face_size = 2;
    OUT_CASE(out, tt_mesh_free, tt_mesh_build(&v, AL, &out, E));
    v = d; v.fixed_face_size = -1;
    OUT_CASE(out, tt_mesh_free, tt_mesh_build(&v, AL, &out, E));
    v = d; v.fixed_face_size = INT_MAX;
    OUT_CASE(out, tt_mesh_free, tt_mesh_build(&v, AL, &out, E));
    v = d; v.nfaces = 2; v.face_sizes = sizes; sizes[0] = 4; sizes[1] = -3;
    OUT_CASE(out, tt_mesh_free, tt_mesh_build(&v, AL, &out, E));
    v = d; v.nfaces = 2; v.face_sizes = sizes; sizes[0] = INT_MAX; sizes[1] = INT_MAX;
    OUT_CASE(out, tt_mesh_free, tt_mesh_build(&v, AL, &out, E));
    v = d; v.flags = 1u << 7;
    OUT_CASE(out, tt_mesh_free, tt_mesh_build(&v, AL, &out, E));
    v = d; v.flags = 0x80000000u;
    OUT_CASE(out, tt_mesh_free, tt_mesh_build(&v, AL, &out, E));
    pos[4] = b->nan_t;
    OUT_CASE(out, tt_mesh_free, tt_mesh_build(&d, AL, &out, E));
    pos[4] = b->inf_t;
    OUT_CASE(out, tt_mesh_free, tt_mesh_build(&d, AL, &out, E));
    pos[4] = -b->inf_t;
    OUT_CASE(out, tt_mesh_free, tt_mesh_build(&d, AL, &out, E));
    pos[4] = 0;
    idx[5] = -1;
    OUT_CASE(out, tt_mesh_free, tt_mesh_build(&d, AL, &out, E));
    idx[5] = 8;
    OUT_CASE(out, tt_mesh_free, tt_mesh_build(&d, AL, &out, E));
    idx[5] = INT_MIN;
    OUT_CASE(out, tt_mesh_free, tt_mesh_build(&d, AL, &out, E));
    idx[5] = idx[4];
    OUT_CASE(out, tt_mesh_free, tt_mesh_build(&d, AL, &out, E));
    idx[5] = k_cube_idx[5];

    CASE(tt_mesh_compute_stats(NULL, AL, &stats, E));
    CASE(tt_mesh_compute_stats(m, AL, NULL, E));
    CASE(tt_mesh_compute_stats(m, BA1, &stats, E));
    CASE(tt_mesh_compute_stats(m, BA2, &stats, E));
    CASE(tt_mesh_compute_stats(&b->empty, AL, &stats, E));

    CASE(tt_mesh_valence_histogram(NULL, AL, hist, 8, E));
    CASE(tt_mesh_valence_histogram(m, AL, NULL, 8, E));
    CASE(tt_mesh_valence_histogram(m, AL, hist, 0, E));
    CASE(tt_mesh_valence_histogram(m, AL, hist, -1, E));
    CASE(tt_mesh_valence_histogram(m, AL, hist, INT_MIN, E));
    CASE(tt_mesh_valence_histogram(m, BA1, hist, 8, E));
    CASE(tt_mesh_valence_histogram(m, BA2, hist, 8, E));

    CASE(tt_mesh_components(NULL, AL, comp, &nc, E));
    CASE(tt_mesh_components(m, AL, NULL, &nc, E));
    CASE(tt_mesh_components(m, AL, comp, NULL, E));
    CASE(tt_mesh_components(m, BA1, comp, &nc, E));
    CASE(tt_mesh_components(m, BA2, comp, &nc, E));

    CASE(tt_mesh_boundary_loops(NULL, loops, &nl, E));
    CASE(tt_mesh_boundary_loops(m, NULL, &nl, E));
    CASE(tt_mesh_boundary_loops(m, loops, NULL, E));

    OUT_CASE(out, tt_mesh_free, tt_mesh_quadrangulate(NULL, TT_SUBDIVIDE_LINEAR, AL, &out, E));
    CASE(tt_mesh_quadrangulate(m, TT_SUBDIVIDE_LINEAR, AL, NULL, E));
    OUT_CASE(out, tt_mesh_free, tt_mesh_quadrangulate(m, (tt_subdivision)2, AL, &out, E));
    OUT_CASE(out, tt_mesh_free, tt_mesh_quadrangulate(m, (tt_subdivision)-1, AL, &out, E));
    OUT_CASE(out, tt_mesh_free, tt_mesh_quadrangulate(m, (tt_subdivision)0x7fffffff, AL, &out, E));
    OUT_CASE(out, tt_mesh_free, tt_mesh_quadrangulate(m, TT_SUBDIVIDE_LINEAR, BA1, &out, E));
    OUT_CASE(out, tt_mesh_free, tt_mesh_quadrangulate(m, TT_SUBDIVIDE_CATMULL_CLARK, BA2, &out, E));
    OUT_CASE(out, tt_mesh_free, tt_mesh_quadrangulate(&b->empty, TT_SUBDIVIDE_LINEAR, AL, &out, E));

    OUT_CASE(cs, tt_corner_sources_free, tt_mesh_quadrangulate_sources(NULL, AL, &cs, E));
    CASE(tt_mesh_quadrangulate_sources(m, AL, NULL, E));
    OUT_CASE(cs, tt_corner_sources_free, tt_mesh_quadrangulate_sources(m, BA1, &cs, E));
    OUT_CASE(cs, tt_corner_sources_free, tt_mesh_quadrangulate_sources(m, BA2, &cs, E));
    OUT_CASE(cs, tt_corner_sources_free, tt_mesh_quadrangulate_sources(&b->empty, AL, &cs, E));

    CHECK(tt_mesh_quadrangulate_sources(m, AL, &src, NULL) == TT_OK && src, "baseline corner sources");
    if (src) {
        int i;
        for (i = 0; i < 24 * 3; i++) in[i] = (float)i;
        CASE(tt_corner_sources_apply(NULL, 1, in, outv, E));
        CASE(tt_corner_sources_apply(src, 1, NULL, outv, E));
        CASE(tt_corner_sources_apply(src, 1, in, NULL, E));
        CASE(tt_corner_sources_apply(src, 0, in, outv, E));
        CASE(tt_corner_sources_apply(src, -1, in, outv, E));
        CASE(tt_corner_sources_apply(src, INT_MIN, in, outv, E));
        CASE(tt_corner_sources_apply(src, INT_MAX, in, outv, E));   /* components * corners overflow */
        CASE(tt_corner_sources_apply(src, 1, in, in, E));
        CASE(tt_corner_sources_apply(src, 1, outv + 10, outv, E));
        in[3] = b->nan_t;
        CASE(tt_corner_sources_apply(src, 1, in, outv, E));
        in[3] = -b->inf_t;
        CASE(tt_corner_sources_apply(src, 1, in, outv, E));
        tt_corner_sources_free(src);
    }

    CASE(tt_corner_normals(NULL, 30, AL, normals, E));
    CASE(tt_corner_normals(m, 30, AL, NULL, E));
    CASE(tt_corner_normals(m, b->nan_t, AL, normals, E));
    CASE(tt_corner_normals(m, b->inf_t, AL, normals, E));
    CASE(tt_corner_normals(m, -b->inf_t, AL, normals, E));
    CASE(tt_corner_normals(m, -1, AL, normals, E));
    CASE(tt_corner_normals(m, 181, AL, normals, E));
    CASE(tt_corner_normals(m, 30, BA1, normals, E));
    CASE(tt_corner_normals(m, 30, BA2, normals, E));
    CASE(tt_corner_normals(&b->empty, 30, AL, normals, E));

    {
        /* The cube's 12 triangles with a tangent of each (x, or z on the
           faces facing x); its diagonal is sqrt(3). */
        float vectors[12 * 3], weights[12];
        tt_remesh_options ro;
        tt_mesh *rm = NULL;
        const tt_mesh *t = b->tris;
        int f;
        for (f = 0; f < 12; f++) {
            float n[3];
            tt_face_normal(t, f, n);
            vectors[3 * f] = fabsf(n[0]) > 0.5f ? 0.0f : 1.0f;
            vectors[3 * f + 1] = 0.0f;
            vectors[3 * f + 2] = fabsf(n[0]) > 0.5f ? 1.0f : 0.0f;
            weights[f] = 1.0f;
        }
        memset(&ro, 0, sizeof ro);
        ro.edge_length = 0.2f;
        OUT_CASE(rm, tt_mesh_free, tt_remesh_quads(NULL, vectors, &ro, AL, &rm, NULL, E));
        OUT_CASE(rm, tt_mesh_free, tt_remesh_quads(t, NULL, &ro, AL, &rm, NULL, E));
        CASE(tt_remesh_quads(t, vectors, &ro, AL, NULL, NULL, E));
        OUT_CASE(rm, tt_mesh_free, tt_remesh_quads(t, vectors, &ro, BA1, &rm, NULL, E));
        OUT_CASE(rm, tt_mesh_free, tt_remesh_quads(t, vectors, &ro, BA2, &rm, NULL, E));
        OUT_CASE(rm, tt_mesh_free, tt_remesh_quads(&b->empty, vectors, &ro, AL, &rm, NULL, E));
        OUT_CASE(rm, tt_mesh_free, tt_remesh_quads(b->nan_tris, vectors, &ro, AL, &rm, NULL, E));
        ro.edge_length = -1.0f;
        OUT_CASE(rm, tt_mesh_free, tt_remesh_quads(t, vectors, &ro, AL, &rm, NULL, E));
        ro.edge_length = b->nan_t;
        OUT_CASE(rm, tt_mesh_free, tt_remesh_quads(t, vectors, &ro, AL, &rm, NULL, E));
        ro.edge_length = b->inf_t;
        OUT_CASE(rm, tt_mesh_free, tt_remesh_quads(t, vectors, &ro, AL, &rm, NULL, E));
        ro.edge_length = 1.0f;      /* more than a quarter of the diagonal */
        OUT_CASE(rm, tt_mesh_free, tt_remesh_quads(t, vectors, &ro, AL, &rm, NULL, E));
        ro.edge_length = 1e-30f;    /* the refinement would pass TT_MAX_REMESH_VERTICES */
        OUT_CASE(rm, tt_mesh_free, tt_remesh_quads(t, vectors, &ro, AL, &rm, NULL, E));
        ro.edge_length = 0.2f;
        ro.sweeps = -1;
        OUT_CASE(rm, tt_mesh_free, tt_remesh_quads(t, vectors, &ro, AL, &rm, NULL, E));
        ro.sweeps = INT_MIN;
        OUT_CASE(rm, tt_mesh_free, tt_remesh_quads(t, vectors, &ro, AL, &rm, NULL, E));
        ro.sweeps = 0;
        ro.crease_degrees = -1.0f;
        OUT_CASE(rm, tt_mesh_free, tt_remesh_quads(t, vectors, &ro, AL, &rm, NULL, E));
        ro.crease_degrees = 180.5f;
        OUT_CASE(rm, tt_mesh_free, tt_remesh_quads(t, vectors, &ro, AL, &rm, NULL, E));
        ro.crease_degrees = b->nan_t;
        OUT_CASE(rm, tt_mesh_free, tt_remesh_quads(t, vectors, &ro, AL, &rm, NULL, E));
        ro.crease_degrees = 0.0f;
        ro.face_weights = weights;
        weights[3] = -0.5f;
        OUT_CASE(rm, tt_mesh_free, tt_remesh_quads(t, vectors, &ro, AL, &rm, NULL, E));
        weights[3] = b->nan_t;
        OUT_CASE(rm, tt_mesh_free, tt_remesh_quads(t, vectors, &ro, AL, &rm, NULL, E));
        weights[3] = 2.0f;
        OUT_CASE(rm, tt_mesh_free, tt_remesh_quads(t, vectors, &ro, AL, &rm, NULL, E));
        weights[3] = 1.0f;
        vectors[7] = b->nan_t;
        OUT_CASE(rm, tt_mesh_free, tt_remesh_quads(t, vectors, &ro, AL, &rm, NULL, E));
        vectors[7] = -b->inf_t;
        OUT_CASE(rm, tt_mesh_free, tt_remesh_quads(t, vectors, &ro, AL, &rm, NULL, E));
    }
}

static void cases_image(const baseline *b)
{
    tt_image *out = NULL, *img = b->image, v, w, odd, dst;
    unsigned char bytes[8 * 8 * 4];
    float cost[8 * 4];
    int lo[8], hi[8], path[8], i;
    memset(bytes, 100, sizeof bytes);

    OUT_CASE(out, tt_image_free, tt_image_create(0, 4, AL, &out, E));
    OUT_CASE(out, tt_image_free, tt_image_create(4, 0, AL, &out, E));
    OUT_CASE(out, tt_image_free, tt_image_create(-1, 4, AL, &out, E));
    OUT_CASE(out, tt_image_free, tt_image_create(4, INT_MIN, AL, &out, E));
    OUT_CASE(out, tt_image_free, tt_image_create(INT_MAX, 4, AL, &out, E));
    OUT_CASE(out, tt_image_free, tt_image_create(INT_MAX, INT_MAX, AL, &out, E));
    OUT_CASE(out, tt_image_free, tt_image_create(TT_MAX_IMAGE_SIZE + 1, 1, AL, &out, E));
    CASE(tt_image_create(4, 4, AL, NULL, E));
    OUT_CASE(out, tt_image_free, tt_image_create(4, 4, BA1, &out, E));
    OUT_CASE(out, tt_image_free, tt_image_create(4, 4, BA2, &out, E));

    OUT_CASE(out, tt_image_free, tt_image_from_bytes(NULL, 8, 8, 4, 0, TT_COLOR_SRGB, AL, &out, E));
    OUT_CASE(out, tt_image_free, tt_image_from_bytes(bytes, 0, 8, 4, 0, TT_COLOR_SRGB, AL, &out, E));
    OUT_CASE(out, tt_image_free, tt_image_from_bytes(bytes, -8, 8, 4, 0, TT_COLOR_SRGB, AL, &out, E));
    OUT_CASE(out, tt_image_free, tt_image_from_bytes(bytes, 8, 0, 4, 0, TT_COLOR_SRGB, AL, &out, E));
    OUT_CASE(out, tt_image_free, tt_image_from_bytes(bytes, 8, -1, 4, 0, TT_COLOR_SRGB, AL, &out, E));
    OUT_CASE(out, tt_image_free, tt_image_from_bytes(bytes, INT_MAX, 1, 4, 0, TT_COLOR_SRGB, AL, &out, E));
    OUT_CASE(out, tt_image_free, tt_image_from_bytes(bytes, 8, 8, 0, 0, TT_COLOR_SRGB, AL, &out, E));
    OUT_CASE(out, tt_image_free, tt_image_from_bytes(bytes, 8, 8, 5, 0, TT_COLOR_SRGB, AL, &out, E));
    OUT_CASE(out, tt_image_free, tt_image_from_bytes(bytes, 8, 8, -3, 0, TT_COLOR_SRGB, AL, &out, E));
    OUT_CASE(out, tt_image_free, tt_image_from_bytes(bytes, 8, 8, 4, -1, TT_COLOR_SRGB, AL, &out, E));
    OUT_CASE(out, tt_image_free, tt_image_from_bytes(bytes, 8, 8, 4, 31, TT_COLOR_SRGB, AL, &out, E));
    OUT_CASE(out, tt_image_free, tt_image_from_bytes(bytes, 8, 8, 4, 0, (tt_color_space)4, AL, &out, E));
    OUT_CASE(out, tt_image_free, tt_image_from_bytes(bytes, 8, 8, 4, 0, (tt_color_space)-1, AL, &out, E));
    OUT_CASE(out, tt_image_free, tt_image_from_bytes(bytes, 8, 8, 1, 0, TT_COLOR_NORMAL, AL, &out, E));
    OUT_CASE(out, tt_image_free, tt_image_from_bytes(bytes, 8, 8, 2, 0, TT_COLOR_NORMAL_Y_DOWN, AL, &out, E));
    CASE(tt_image_from_bytes(bytes, 8, 8, 4, 0, TT_COLOR_SRGB, AL, NULL, E));
    OUT_CASE(out, tt_image_free, tt_image_from_bytes(bytes, 8, 8, 4, 0, TT_COLOR_SRGB, BA1, &out, E));
    OUT_CASE(out, tt_image_free, tt_image_from_bytes(bytes, 8, 8, 4, 0, TT_COLOR_SRGB, BA2, &out, E));

    OUT_CASE(out, tt_image_free, tt_image_rotate90(NULL, 1, AL, &out, E));
    CASE(tt_image_rotate90(img, 1, AL, NULL, E));
    OUT_CASE(out, tt_image_free, tt_image_rotate90(img, 1, BA1, &out, E));
    OUT_CASE(out, tt_image_free, tt_image_rotate90(img, 1, BA2, &out, E));
    v = *img;
    v.pixels = NULL;
    OUT_CASE(out, tt_image_free, tt_image_rotate90(&v, 1, AL, &out, E));
    v = *img;
    v.width = 0;
    OUT_CASE(out, tt_image_free, tt_image_rotate90(&v, 1, AL, &out, E));
    v = *img;
    v.height = -4;
    OUT_CASE(out, tt_image_free, tt_image_rotate90(&v, 1, AL, &out, E));
    v = *img;
    v.width = INT_MAX;   /* above TT_MAX_IMAGE_SIZE */
    OUT_CASE(out, tt_image_free, tt_image_rotate90(&v, 1, AL, &out, E));
    v = *img;
    v.kind = (tt_image_kind)7;
    OUT_CASE(out, tt_image_free, tt_image_rotate90(&v, 1, AL, &out, E));
    v.kind = (tt_image_kind)-1;
    OUT_CASE(out, tt_image_free, tt_image_rotate90(&v, 2, AL, &out, E));

    dst = image_view(32, 32, 0.5f);
    w = image_view(16, 32, 0.5f);
    CASE(tt_image_over(NULL, img, E));
    CASE(tt_image_over(&dst, NULL, E));
    CASE(tt_image_over(&dst, &w, E));
    v = *img;
    v.pixels = NULL;
    CASE(tt_image_over(&dst, &v, E));
    CASE(tt_image_over(&v, img, E));
    v = *img;
    v.width = v.height = 0;
    CASE(tt_image_over(&v, &v, E));
    v = *img;
    v.width = -32;
    CASE(tt_image_over(&v, &v, E));
    v = *img;
    v.kind = (tt_image_kind)7;
    CASE(tt_image_over(&dst, &v, E));
    dst.kind = (tt_image_kind)9;
    CASE(tt_image_over(&dst, img, E));
    free(dst.pixels);
    free(w.pixels);

    odd = image_view(3, 4, 0.5f);
    OUT_CASE(out, tt_image_free, tt_image_downsample2(NULL, AL, &out, E));
    CASE(tt_image_downsample2(img, AL, NULL, E));
    OUT_CASE(out, tt_image_free, tt_image_downsample2(&odd, AL, &out, E));
    odd.width = 4;
    odd.height = 3;
    OUT_CASE(out, tt_image_free, tt_image_downsample2(&odd, AL, &out, E));
    odd.width = 0;
    odd.height = 0;
    OUT_CASE(out, tt_image_free, tt_image_downsample2(&odd, AL, &out, E));
    odd.width = -2;
    odd.height = 2;
    OUT_CASE(out, tt_image_free, tt_image_downsample2(&odd, AL, &out, E));
    v = *img;
    v.pixels = NULL;
    OUT_CASE(out, tt_image_free, tt_image_downsample2(&v, AL, &out, E));
    v = *img;
    v.kind = (tt_image_kind)7;
    OUT_CASE(out, tt_image_free, tt_image_downsample2(&v, AL, &out, E));
    OUT_CASE(out, tt_image_free, tt_image_downsample2(img, BA1, &out, E));
    OUT_CASE(out, tt_image_free, tt_image_downsample2(img, BA2, &out, E));
    free(odd.pixels);

    OUT_CASE(out, tt_image_free, tt_image_resize(NULL, 4, 4, AL, &out, E));
    CASE(tt_image_resize(img, 4, 4, AL, NULL, E));
    OUT_CASE(out, tt_image_free, tt_image_resize(img, 0, 4, AL, &out, E));
    OUT_CASE(out, tt_image_free, tt_image_resize(img, 4, -3, AL, &out, E));
    OUT_CASE(out, tt_image_free, tt_image_resize(img, TT_MAX_IMAGE_SIZE + 1, 4, AL, &out, E));
    OUT_CASE(out, tt_image_free, tt_image_resize(img, 65536, 65536, AL, &out, E));
    v = *img;
    v.pixels = NULL;
    OUT_CASE(out, tt_image_free, tt_image_resize(&v, 4, 4, AL, &out, E));
    v = *img;
    v.width = -32;
    OUT_CASE(out, tt_image_free, tt_image_resize(&v, 4, 4, AL, &out, E));
    v = *img;
    v.kind = (tt_image_kind)7;
    OUT_CASE(out, tt_image_free, tt_image_resize(&v, 4, 4, AL, &out, E));
    OUT_CASE(out, tt_image_free, tt_image_resize(img, 4, 4, BA1, &out, E));
    OUT_CASE(out, tt_image_free, tt_image_resize(img, 4, 4, BA2, &out, E));

    for (i = 0; i < 32; i++) cost[i] = (float)(i % 5);
    for (i = 0; i < 8; i++) {
        lo[i] = 0;
        hi[i] = 3;
    }
    CASE(tt_min_error_cut(NULL, 8, 4, lo, hi, AL, path, E));
    CASE(tt_min_error_cut(cost, 8, 4, NULL, hi, AL, path, E));
    CASE(tt_min_error_cut(cost, 8, 4, lo, NULL, AL, path, E));
    CASE(tt_min_error_cut(cost, 8, 4, lo, hi, AL, NULL, E));
    CASE(tt_min_error_cut(cost, 0, 4, lo, hi, AL, path, E));
    CASE(tt_min_error_cut(cost, -8, 4, lo, hi, AL, path, E));
    CASE(tt_min_error_cut(cost, 8, 0, lo, hi, AL, path, E));
    CASE(tt_min_error_cut(cost, 8, INT_MIN, lo, hi, AL, path, E));
    CASE(tt_min_error_cut(cost, 8, 4, lo, hi, BA1, path, E));
    CASE(tt_min_error_cut(cost, 8, 4, lo, hi, BA2, path, E));
    lo[3] = 2;
    hi[3] = 1;
    CASE(tt_min_error_cut(cost, 8, 4, lo, hi, AL, path, E));
    lo[3] = -1;
    hi[3] = 3;
    CASE(tt_min_error_cut(cost, 8, 4, lo, hi, AL, path, E));
    lo[3] = 0;
    hi[3] = 4;
    CASE(tt_min_error_cut(cost, 8, 4, lo, hi, AL, path, E));
    hi[3] = INT_MAX;
    lo[3] = INT_MAX;
    CASE(tt_min_error_cut(cost, 8, 4, lo, hi, AL, path, E));
    lo[3] = INT_MIN;
    hi[3] = INT_MIN;
    CASE(tt_min_error_cut(cost, 8, 4, lo, hi, AL, path, E));
    lo[3] = 0;
    hi[3] = 0;
    lo[4] = 3;
    hi[4] = 3;   /* consecutive ranges no path can follow */
    CASE(tt_min_error_cut(cost, 8, 4, lo, hi, AL, path, E));
    lo[3] = lo[4] = 0;
    hi[3] = hi[4] = 3;
    cost[9] = b->nan_t;
    CASE(tt_min_error_cut(cost, 8, 4, lo, hi, AL, path, E));
}

static void cases_numerics(const baseline *b)
{
    static const tt_triplet trip[4] = {{0, 0, 2.0}, {1, 1, 2.0}, {0, 1, 0.5}, {1, 0, 0.5}};
    tt_triplet t[4];
    tt_sparse_matrix *out = NULL, *A = NULL, hand;
    double x[4] = {1, 1, 0, 0}, y[4], rhs[2] = {1, 1}, sol[2] = {0, 0};
    int rs[3], col[3];
    double val[3];
    tt_cg_options co;
    tt_cg_report rep;

    OUT_CASE(out, tt_sparse_matrix_free, tt_sparse_from_triplets(-1, 2, trip, 4, AL, &out, E));
    OUT_CASE(out, tt_sparse_matrix_free, tt_sparse_from_triplets(2, -1, trip, 4, AL, &out, E));
    OUT_CASE(out, tt_sparse_matrix_free, tt_sparse_from_triplets(INT_MIN, INT_MIN, trip, 4, AL, &out, E));
    OUT_CASE(out, tt_sparse_matrix_free, tt_sparse_from_triplets(INT_MAX, INT_MAX, trip, 4, AL, &out, E));
    OUT_CASE(out, tt_sparse_matrix_free, tt_sparse_from_triplets(2, 2, NULL, 4, AL, &out, E));
    OUT_CASE(out, tt_sparse_matrix_free, tt_sparse_from_triplets(2, 2, trip, -1, AL, &out, E));
    CASE(tt_sparse_from_triplets(2, 2, trip, 4, AL, NULL, E));
    OUT_CASE(out, tt_sparse_matrix_free, tt_sparse_from_triplets(2, 2, trip, 4, BA1, &out, E));
    OUT_CASE(out, tt_sparse_matrix_free, tt_sparse_from_triplets(2, 2, trip, 4, BA2, &out, E));
    memcpy(t, trip, sizeof t);
    t[2].row = -1;
    OUT_CASE(out, tt_sparse_matrix_free, tt_sparse_from_triplets(2, 2, t, 4, AL, &out, E));
    t[2].row = 2;
    OUT_CASE(out, tt_sparse_matrix_free, tt_sparse_from_triplets(2, 2, t, 4, AL, &out, E));
    t[2].row = 0;
    t[2].col = INT_MIN;
    OUT_CASE(out, tt_sparse_matrix_free, tt_sparse_from_triplets(2, 2, t, 4, AL, &out, E));
    t[2].col = 2;
    OUT_CASE(out, tt_sparse_matrix_free, tt_sparse_from_triplets(2, 2, t, 4, AL, &out, E));
    t[2].col = 1;
    t[2].value = b->nan_d;
    OUT_CASE(out, tt_sparse_matrix_free, tt_sparse_from_triplets(2, 2, t, 4, AL, &out, E));
    t[2].value = -b->inf_d;
    OUT_CASE(out, tt_sparse_matrix_free, tt_sparse_from_triplets(2, 2, t, 4, AL, &out, E));
    t[2].value = 1e308;
    t[3].row = 0;
    t[3].col = 1;
    t[3].value = 1e308;   /* the two sum to infinity */
    OUT_CASE(out, tt_sparse_matrix_free, tt_sparse_from_triplets(2, 2, t, 4, AL, &out, E));

    CHECK(tt_sparse_from_triplets(2, 2, trip, 4, AL, &A, NULL) == TT_OK && A, "baseline matrix");
    if (!A) return;
    CASE(tt_sparse_multiply(NULL, x, y, E));
    CASE(tt_sparse_multiply(A, NULL, y, E));
    CASE(tt_sparse_multiply(A, x, NULL, E));
    CASE(tt_sparse_multiply(A, x, x, E));
    hand = *A;
    hand.rows = -1;
    CASE(tt_sparse_multiply(&hand, x, y, E));
    hand = *A;
    hand.row_start = NULL;
    CASE(tt_sparse_multiply(&hand, x, y, E));

    memset(&co, 0, sizeof co);
    CASE(tt_cg_solve(NULL, rhs, &co, AL, sol, &rep, E));
    CASE(tt_cg_solve(A, NULL, &co, AL, sol, &rep, E));
    CASE(tt_cg_solve(A, rhs, &co, AL, NULL, &rep, E));
    CASE(tt_cg_solve(A, rhs, &co, AL, rhs, &rep, E));
    CASE(tt_cg_solve(A, rhs, &co, BA1, sol, &rep, E));
    CASE(tt_cg_solve(A, rhs, &co, BA2, sol, NULL, E));
    co.max_iterations = -1;
    CASE(tt_cg_solve(A, rhs, &co, AL, sol, &rep, E));
    co.max_iterations = INT_MIN;
    CASE(tt_cg_solve(A, rhs, &co, AL, sol, &rep, E));
    co.max_iterations = 0;
    co.tolerance = -1;
    CASE(tt_cg_solve(A, rhs, &co, AL, sol, &rep, E));
    co.tolerance = b->nan_d;
    CASE(tt_cg_solve(A, rhs, &co, AL, sol, &rep, E));
    co.tolerance = -b->inf_d;
    CASE(tt_cg_solve(A, rhs, &co, AL, sol, &rep, E));
    co.tolerance = 0;
    co.preconditioner = 7;
    CASE(tt_cg_solve(A, rhs, &co, AL, sol, &rep, E));
    co.preconditioner = -1;
    CASE(tt_cg_solve(A, rhs, &co, AL, sol, &rep, E));
    co.preconditioner = 0;
    rhs[1] = b->nan_d;
    CASE(tt_cg_solve(A, rhs, &co, AL, sol, &rep, E));
    rhs[1] = b->inf_d;
    CASE(tt_cg_solve(A, rhs, &co, AL, sol, &rep, E));
    rhs[1] = 1;
    sol[0] = b->nan_d;
    CASE(tt_cg_solve(A, rhs, &co, AL, sol, &rep, E));
    sol[0] = 0;
    /* hand-made CSR: not square, decreasing row_start, a column outside, a NaN entry, NULL arrays */
    hand = *A;
    hand.cols = 3;
    CASE(tt_cg_solve(&hand, rhs, &co, AL, sol, &rep, E));
    rs[0] = 0;
    rs[1] = 3;
    rs[2] = 2;
    col[0] = 0;
    col[1] = 1;
    col[2] = 1;
    val[0] = val[1] = val[2] = 1;
    hand.rows = hand.cols = 2;
    hand.nnz = 2;
    hand.row_start = rs;
    hand.col = col;
    hand.value = val;
    CASE(tt_cg_solve(&hand, rhs, &co, AL, sol, &rep, E));   /* (tt_sparse_multiply trusts the CSR arrays) */
    rs[0] = 1;
    rs[1] = 1;
    rs[2] = 2;
    CASE(tt_cg_solve(&hand, rhs, &co, AL, sol, &rep, E));
    rs[0] = 0;
    rs[1] = 1;
    rs[2] = 2;
    col[1] = 5;
    CASE(tt_cg_solve(&hand, rhs, &co, AL, sol, &rep, E));
    col[1] = -1;
    CASE(tt_cg_solve(&hand, rhs, &co, AL, sol, &rep, E));
    col[1] = 1;
    val[1] = b->nan_d;
    CASE(tt_cg_solve(&hand, rhs, &co, AL, sol, &rep, E));
    val[1] = 1;
    hand.nnz = 5;   /* row_start[rows] says 2 */
    CASE(tt_cg_solve(&hand, rhs, &co, AL, sol, &rep, E));
    hand.nnz = 2;
    hand.col = NULL;
    CASE(tt_cg_solve(&hand, rhs, &co, AL, sol, &rep, E));
    hand.col = col;
    hand.rows = hand.cols = -2;
    CASE(tt_cg_solve(&hand, rhs, &co, AL, sol, &rep, E));
    tt_sparse_matrix_free(A);
}


static void cases_fft(const baseline *b)
{
    static const double tex4[4] = {0.25, 0.5, 0.75, 1.0};
    double data[32], real[16], spec[2 * 4 * 3], t4[4], mask4[4] = {1, 0, 0, 0}, values4[4] = {0.75, 0, 0, 0};
    double work[64], map4[4], tex16[16];
    unsigned char allowed[4] = {0, 0, 0, 0};
    tt_fft_plan *out = NULL, *plan = NULL;
    tt_xcorr_texture *xt = NULL, *xt4 = NULL, *xout = NULL;
    tt_xcorr_match match;
    const tt_xcorr_texture *list[2];
    const unsigned char *allow_list[2];
    int which = 0, i;

    OUT_CASE(out, tt_fft_plan_free, tt_fft_plan_create(0, 4, AL, &out, E));
    OUT_CASE(out, tt_fft_plan_free, tt_fft_plan_create(4, 0, AL, &out, E));
    OUT_CASE(out, tt_fft_plan_free, tt_fft_plan_create(-4, 4, AL, &out, E));
    OUT_CASE(out, tt_fft_plan_free, tt_fft_plan_create(4, INT_MIN, AL, &out, E));
    OUT_CASE(out, tt_fft_plan_free, tt_fft_plan_create(3, 4, AL, &out, E));
    OUT_CASE(out, tt_fft_plan_free, tt_fft_plan_create(4, 12, AL, &out, E));
    OUT_CASE(out, tt_fft_plan_free, tt_fft_plan_create(INT_MAX, 4, AL, &out, E));
    OUT_CASE(out, tt_fft_plan_free, tt_fft_plan_create(1 << 30, 1 << 30, AL, &out, E));
    OUT_CASE(out, tt_fft_plan_free, tt_fft_plan_create(TT_FFT_MAX_SIZE * 2, 1, AL, &out, E));
    CASE(tt_fft_plan_create(4, 4, AL, NULL, E));
    OUT_CASE(out, tt_fft_plan_free, tt_fft_plan_create(4, 4, BA1, &out, E));
    OUT_CASE(out, tt_fft_plan_free, tt_fft_plan_create(4, 4, BA2, &out, E));

    CHECK(tt_fft_plan_create(4, 4, AL, &plan, NULL) == TT_OK && plan, "baseline FFT plan");
    if (!plan) return;
    for (i = 0; i < 32; i++) data[i] = i % 3;
    for (i = 0; i < 16; i++) real[i] = i % 5;
    CASE(tt_fft_c2c(NULL, data, 4, 4, TT_FFT_FORWARD, E));
    CASE(tt_fft_c2c(plan, NULL, 4, 4, TT_FFT_FORWARD, E));
    CASE(tt_fft_c2c(plan, data, 2, 4, TT_FFT_FORWARD, E));
    CASE(tt_fft_c2c(plan, data, 4, 8, TT_FFT_FORWARD, E));
    CASE(tt_fft_c2c(plan, data, -4, 4, TT_FFT_FORWARD, E));
    CASE(tt_fft_c2c(plan, data, 4, 4, 0, E));
    CASE(tt_fft_c2c(plan, data, 4, 4, 2, E));
    CASE(tt_fft_c2c(plan, data, 4, 4, INT_MIN, E));
    data[5] = b->nan_d;
    CASE(tt_fft_c2c(plan, data, 4, 4, TT_FFT_FORWARD, E));
    data[5] = b->inf_d;
    CASE(tt_fft_c2c(plan, data, 4, 4, TT_FFT_INVERSE, E));
    data[5] = 1e308;
    data[7] = 1e308;   /* overflows */
    CASE(tt_fft_c2c(plan, data, 4, 4, TT_FFT_FORWARD, E));

    CASE(tt_fft_r2c(NULL, real, 4, 4, spec, E));
    CASE(tt_fft_r2c(plan, NULL, 4, 4, spec, E));
    CASE(tt_fft_r2c(plan, real, 4, 4, NULL, E));
    CASE(tt_fft_r2c(plan, real, 8, 4, spec, E));
    CASE(tt_fft_r2c(plan, real, 4, 0, spec, E));
    CASE(tt_fft_r2c(plan, real, 4, 4, real, E));
    real[3] = b->nan_d;
    CASE(tt_fft_r2c(plan, real, 4, 4, spec, E));
    real[3] = -b->inf_d;
    CASE(tt_fft_r2c(plan, real, 4, 4, spec, E));
    real[3] = 3;

    for (i = 0; i < 24; i++) spec[i] = i % 4;
    CASE(tt_fft_c2r(NULL, spec, 4, 4, real, E));
    CASE(tt_fft_c2r(plan, NULL, 4, 4, real, E));
    CASE(tt_fft_c2r(plan, spec, 4, 4, NULL, E));
    CASE(tt_fft_c2r(plan, spec, 4, 2, real, E));
    CASE(tt_fft_c2r(plan, spec, INT_MIN, 4, real, E));
    CASE(tt_fft_c2r(plan, spec, 4, 4, spec, E));
    spec[2] = b->nan_d;
    CASE(tt_fft_c2r(plan, spec, 4, 4, real, E));
    spec[2] = b->inf_d;
    CASE(tt_fft_c2r(plan, spec, 4, 4, real, E));
    tt_fft_plan_free(plan);

    memcpy(t4, tex4, sizeof t4);
    OUT_CASE(xout, tt_xcorr_texture_free, tt_xcorr_texture_create(0, 2, 1, t4, AL, &xout, E));
    OUT_CASE(xout, tt_xcorr_texture_free, tt_xcorr_texture_create(2, -2, 1, t4, AL, &xout, E));
    OUT_CASE(xout, tt_xcorr_texture_free, tt_xcorr_texture_create(3, 1, 1, t4, AL, &xout, E));
    OUT_CASE(xout, tt_xcorr_texture_free, tt_xcorr_texture_create(INT_MAX, 1, 1, t4, AL, &xout, E));
    OUT_CASE(xout, tt_xcorr_texture_free, tt_xcorr_texture_create(1 << 30, 1 << 30, 1, t4, AL, &xout, E));
    OUT_CASE(xout, tt_xcorr_texture_free, tt_xcorr_texture_create(2, 2, 0, t4, AL, &xout, E));
    OUT_CASE(xout, tt_xcorr_texture_free, tt_xcorr_texture_create(2, 2, -1, t4, AL, &xout, E));
    OUT_CASE(xout, tt_xcorr_texture_free, tt_xcorr_texture_create(2, 2, 1, NULL, AL, &xout, E));
    CASE(tt_xcorr_texture_create(2, 2, 1, t4, AL, NULL, E));
    OUT_CASE(xout, tt_xcorr_texture_free, tt_xcorr_texture_create(2, 2, 1, t4, BA1, &xout, E));
    OUT_CASE(xout, tt_xcorr_texture_free, tt_xcorr_texture_create(2, 2, 1, t4, BA2, &xout, E));
    t4[2] = b->nan_d;
    OUT_CASE(xout, tt_xcorr_texture_free, tt_xcorr_texture_create(2, 2, 1, t4, AL, &xout, E));
    t4[2] = b->inf_d;
    OUT_CASE(xout, tt_xcorr_texture_free, tt_xcorr_texture_create(2, 2, 1, t4, AL, &xout, E));
    t4[2] = 1e200;   /* its square overflows */
    OUT_CASE(xout, tt_xcorr_texture_free, tt_xcorr_texture_create(2, 2, 1, t4, AL, &xout, E));

    for (i = 0; i < 16; i++) tex16[i] = i % 7 * 0.1;
    CHECK(tt_xcorr_texture_create(2, 2, 1, tex4, AL, &xt, NULL) == TT_OK && xt, "baseline xcorr texture");
    CHECK(tt_xcorr_texture_create(4, 4, 1, tex16, AL, &xt4, NULL) == TT_OK && xt4, "baseline 4 x 4 xcorr texture");
    if (!xt || !xt4) {
        tt_xcorr_texture_free(xt);
        tt_xcorr_texture_free(xt4);
        return;
    }
    CASE(tt_xcorr_masked(NULL, mask4, values4, NULL, work, map4, &match, E));
    CASE(tt_xcorr_masked(xt, NULL, values4, NULL, work, map4, &match, E));
    CASE(tt_xcorr_masked(xt, mask4, NULL, NULL, work, map4, &match, E));
    CASE(tt_xcorr_masked(xt, mask4, values4, NULL, NULL, map4, &match, E));
    CASE(tt_xcorr_masked(xt, mask4, values4, NULL, work, NULL, NULL, E));
    CASE(tt_xcorr_masked(xt, mask4, values4, allowed, work, map4, &match, E));   /* no offset allowed */
    mask4[1] = -1;
    CASE(tt_xcorr_masked(xt, mask4, values4, NULL, work, map4, &match, E));
    mask4[1] = b->nan_d;
    CASE(tt_xcorr_masked(xt, mask4, values4, NULL, work, map4, &match, E));
    mask4[1] = b->inf_d;
    CASE(tt_xcorr_masked(xt, mask4, values4, NULL, work, map4, &match, E));
    mask4[1] = 0;
    mask4[0] = 0;   /* all zero: not measured */
    CASE(tt_xcorr_masked(xt, mask4, values4, NULL, work, map4, &match, E));
    mask4[0] = 1;
    values4[0] = b->nan_d;
    CASE(tt_xcorr_masked(xt, mask4, values4, NULL, work, map4, &match, E));
    values4[0] = -b->inf_d;
    CASE(tt_xcorr_masked(xt, mask4, values4, NULL, work, map4, &match, E));
    values4[0] = 1e200;
    CASE(tt_xcorr_masked(xt, mask4, values4, NULL, work, map4, &match, E));
    values4[0] = 0.75;

    list[0] = xt;
    list[1] = xt;
    allow_list[0] = allowed;
    allow_list[1] = allowed;
    CASE(tt_xcorr_masked_best(NULL, 2, mask4, values4, NULL, work, &match, &which, E));
    CASE(tt_xcorr_masked_best(list, 0, mask4, values4, NULL, work, &match, &which, E));
    CASE(tt_xcorr_masked_best(list, -1, mask4, values4, NULL, work, &match, &which, E));
    CASE(tt_xcorr_masked_best(list, INT_MIN, mask4, values4, NULL, work, &match, &which, E));
    CASE(tt_xcorr_masked_best(list, 2, NULL, values4, NULL, work, &match, &which, E));
    CASE(tt_xcorr_masked_best(list, 2, mask4, NULL, NULL, work, &match, &which, E));
    CASE(tt_xcorr_masked_best(list, 2, mask4, values4, NULL, NULL, &match, &which, E));
    CASE(tt_xcorr_masked_best(list, 2, mask4, values4, NULL, work, NULL, &which, E));
    CASE(tt_xcorr_masked_best(list, 2, mask4, values4, NULL, work, &match, NULL, E));
    CASE(tt_xcorr_masked_best(list, 2, mask4, values4, allow_list, work, &match, &which, E));
    list[1] = NULL;
    CASE(tt_xcorr_masked_best(list, 2, mask4, values4, NULL, work, &match, &which, E));
    list[1] = xt4;   /* another size */
    CASE(tt_xcorr_masked_best(list, 2, mask4, values4, NULL, work, &match, &which, E));
    list[1] = xt;
    mask4[2] = -0.5;
    CASE(tt_xcorr_masked_best(list, 2, mask4, values4, NULL, work, &match, &which, E));
    mask4[2] = b->nan_d;
    CASE(tt_xcorr_masked_best(list, 2, mask4, values4, NULL, work, &match, &which, E));
    mask4[2] = 0;
    values4[0] = b->nan_d;
    CASE(tt_xcorr_masked_best(list, 2, mask4, values4, NULL, work, &match, &which, E));
    values4[0] = 0.75;
    mask4[0] = 0;
    CASE(tt_xcorr_masked_best(list, 2, mask4, values4, NULL, work, &match, &which, E));
    tt_xcorr_texture_free(xt);
    tt_xcorr_texture_free(xt4);
}

static void cases_tiled(const baseline *b)
{
    const tt_mesh *m = b->quads;
    tt_tile_layout L, bad, res;
    uint8_t types[24], bt[24];
    int ec[24], i;
    float uv[48], bad_uv[48], stretch[8];
    int counts[4 * 4 * 4 * 4];
    tt_synth_options so, sb;
    tt_synth_plan *plan = NULL, *pout = NULL;
    tt_tileset *ts = NULL;
    tt_image v, cell, *img = b->image;
    tt_seam_options seo;
    tt_seam_report srep;
    tt_uv_distortion_options dop;
    tt_uv_distortion_report drep;
    tt_rect win;
    int edges[2];

    memset(&L, 0, sizeof L);
    L.tile_size = 8;
    L.gutter = 2;
    CASE(tt_tile_layout_resolve(NULL, &res, E));
    CASE(tt_tile_layout_resolve(&L, NULL, E));
    bad = L; bad.colors = -1;
    CASE(tt_tile_layout_resolve(&bad, &res, E));
    bad = L; bad.colors = TT_MAX_COLORS + 1;
    CASE(tt_tile_layout_resolve(&bad, &res, E));
    bad = L; bad.colors = INT_MAX;
    CASE(tt_tile_layout_resolve(&bad, &res, E));
    bad = L; bad.tile_size = 3;
    CASE(tt_tile_layout_resolve(&bad, &res, E));
    bad = L; bad.tile_size = -8;
    CASE(tt_tile_layout_resolve(&bad, &res, E));
    bad = L; bad.tile_size = INT_MAX;
    CASE(tt_tile_layout_resolve(&bad, &res, E));
    bad = L; bad.gutter = -1;
    CASE(tt_tile_layout_resolve(&bad, &res, E));
    bad = L; bad.gutter = 9;
    CASE(tt_tile_layout_resolve(&bad, &res, E));
    bad = L; bad.gutter = INT_MAX;
    CASE(tt_tile_layout_resolve(&bad, &res, E));
    bad = L; bad.colors = 45; bad.tile_size = 128;   /* an atlas beyond TT_MAX_IMAGE_SIZE */
    CASE(tt_tile_layout_resolve(&bad, &res, E));
    bad = L; bad.colors = TT_MAX_COLORS; bad.tile_size = TT_MAX_IMAGE_SIZE; bad.gutter = TT_MAX_IMAGE_SIZE;
    CASE(tt_tile_layout_resolve(&bad, &res, E));
    memset(&bad, 0x5a, sizeof bad);
    CASE(tt_tile_layout_resolve(&bad, &res, E));

    CASE(tt_assign_boundaries(NULL, &L, 1, NULL, types, E));
    CASE(tt_assign_boundaries(m, NULL, 1, NULL, types, E));
    CASE(tt_assign_boundaries(m, &L, 1, NULL, NULL, E));
    bad = L; bad.colors = -1;
    CASE(tt_assign_boundaries(m, &bad, 1, NULL, types, E));
    bad = L; bad.colors = TT_MAX_COLORS + 1;
    CASE(tt_assign_boundaries(m, &bad, 1, NULL, types, E));
    for (i = 0; i < 24; i++) ec[i] = 0;
    ec[5] = 1;   /* colour 1 of 1 */
    CASE(tt_assign_boundaries(m, &L, 1, ec, types, E));
    ec[5] = -2;
    CASE(tt_assign_boundaries(m, &L, 1, ec, types, E));
    ec[5] = INT_MIN;
    CASE(tt_assign_boundaries(m, &L, 1, ec, types, E));
    bad = L; bad.colors = 2;
    ec[5] = 1;   /* its twin says 0 */
    CASE(tt_assign_boundaries(m, &bad, 1, ec, types, E));
    CASE(tt_assign_boundaries(&b->empty, &L, 1, NULL, types, E));

    CHECK(tt_assign_boundaries(m, &L, 1, NULL, types, NULL) == TT_OK, "baseline boundary types");
    CASE(tt_assign_uvs(NULL, &L, types, uv, E));
    CASE(tt_assign_uvs(m, NULL, types, uv, E));
    CASE(tt_assign_uvs(m, &L, NULL, uv, E));
    CASE(tt_assign_uvs(m, &L, types, NULL, E));
    bad = L; bad.tile_size = -1;
    CASE(tt_assign_uvs(m, &bad, types, uv, E));
    memset(&bad, 0x5a, sizeof bad);
    CASE(tt_assign_uvs(m, &bad, types, uv, E));
    CASE(tt_assign_uvs(b->tris, &L, types, uv, E));
    memcpy(bt, types, sizeof bt);
    bt[3] = 2;   /* 2n with n = 1 */
    CASE(tt_assign_uvs(m, &L, bt, uv, E));
    bt[3] = 255;
    CASE(tt_assign_uvs(m, &L, bt, uv, E));
    CASE(tt_assign_uvs(&b->empty, &L, types, uv, E));
    CHECK(tt_assign_uvs(m, &L, types, uv, NULL) == TT_OK, "baseline UVs");

    {
        /* 12 faces' worth: b->tris (12 triangles) reads that many. */
        float fv[36];
        uint8_t turn[12], up[12];
        volatile float zero = 0.0f;
        for (i = 0; i < 36; i++) fv[i] = i % 3 == 1 ? 1.0f : 0.0f;
        CASE(tt_orient_tiles(NULL, fv, turn, up, NULL, E));
        CASE(tt_orient_tiles(m, NULL, turn, up, NULL, E));
        CASE(tt_orient_tiles(m, fv, NULL, up, NULL, E));
        CASE(tt_orient_tiles(b->tris, fv, turn, up, NULL, E));
        CASE(tt_orient_tiles(&b->empty, fv, turn, up, NULL, E));
        fv[4] = zero / zero;
        CASE(tt_orient_tiles(m, fv, turn, up, NULL, E));
        fv[4] = 1.0f / zero;
        CASE(tt_orient_tiles(m, fv, turn, up, NULL, E));
        fv[4] = 1.0f;
        CHECK(tt_orient_tiles(m, fv, turn, up, NULL, NULL) == TT_OK, "baseline orientation");
        CASE(tt_assign_uvs_oriented(NULL, &L, types, turn, up, uv, E));
        CASE(tt_assign_uvs_oriented(m, NULL, types, turn, up, uv, E));
        CASE(tt_assign_uvs_oriented(m, &L, NULL, turn, up, uv, E));
        CASE(tt_assign_uvs_oriented(m, &L, types, turn, up, NULL, E));
        CASE(tt_assign_uvs_oriented(b->tris, &L, types, turn, up, uv, E));
        CASE(tt_assign_uvs_oriented(&b->empty, &L, types, turn, up, uv, E));
        turn[2] = 4;
        CASE(tt_assign_uvs_oriented(m, &L, types, turn, up, uv, E));
        turn[2] = 255;
        CASE(tt_assign_uvs_oriented(m, &L, types, turn, up, uv, E));
        turn[2] = 0;
        up[1] = TT_TILESET_KINDS;
        CASE(tt_assign_uvs_oriented(m, &L, types, turn, up, uv, E));
        up[1] = 255;
        CASE(tt_assign_uvs_oriented(m, &L, types, turn, up, uv, E));
        up[1] = 0;
        CHECK(tt_assign_uvs_oriented(m, &L, types, turn, up, uv, NULL) == TT_OK, "baseline oriented UVs");
    }

    {
        uint8_t rt[24];
        memcpy(rt, types, sizeof rt);
        CASE(tt_reduce_tiles(NULL, &L, 1, NULL, NULL, 4, AL, rt, NULL, E));
        CASE(tt_reduce_tiles(m, NULL, 1, NULL, NULL, 4, AL, rt, NULL, E));
        CASE(tt_reduce_tiles(m, &L, 1, NULL, NULL, 4, AL, NULL, NULL, E));
        CASE(tt_reduce_tiles(m, &L, 1, NULL, NULL, 4, BA1, rt, NULL, E));
        CASE(tt_reduce_tiles(m, &L, 1, NULL, NULL, 4, BA2, rt, NULL, E));
        CASE(tt_reduce_tiles(m, &L, 1, NULL, NULL, 0, AL, rt, NULL, E));
        CASE(tt_reduce_tiles(m, &L, 1, NULL, NULL, -1, AL, rt, NULL, E));
        CASE(tt_reduce_tiles(m, &L, 1, NULL, NULL, INT_MIN, AL, rt, NULL, E));
        bad = L; bad.colors = -1;
        CASE(tt_reduce_tiles(m, &bad, 1, NULL, NULL, 4, AL, rt, NULL, E));
        bad = L; bad.colors = TT_MAX_COLORS + 1;
        CASE(tt_reduce_tiles(m, &bad, 1, NULL, NULL, 4, AL, rt, NULL, E));
        CASE(tt_reduce_tiles(b->tris, &L, 1, NULL, NULL, 4, AL, rt, NULL, E));
        CASE(tt_reduce_tiles(&b->empty, &L, 1, NULL, NULL, 4, AL, rt, NULL, E));
        rt[3] = 2;   /* 2n with n = 1 */
        CASE(tt_reduce_tiles(m, &L, 1, NULL, NULL, 4, AL, rt, NULL, E));
        rt[3] = 255;
        CASE(tt_reduce_tiles(m, &L, 1, NULL, NULL, 4, AL, rt, NULL, E));
        memcpy(rt, types, sizeof rt);
        rt[3] ^= 1;   /* its twin no longer the other half */
        CASE(tt_reduce_tiles(m, &L, 1, NULL, NULL, 4, AL, rt, NULL, E));
        memcpy(rt, types, sizeof rt);
        for (i = 0; i < 24; i++) ec[i] = 0;
        ec[5] = 1;   /* colour 1 of 1 */
        CASE(tt_reduce_tiles(m, &L, 1, ec, NULL, 4, AL, rt, NULL, E));
        ec[5] = INT_MIN;
        CASE(tt_reduce_tiles(m, &L, 1, ec, NULL, 4, AL, rt, NULL, E));
        ec[5] = 0;
        CHECK(tt_reduce_tiles(m, &L, 1, ec, NULL, 1, AL, rt, NULL, NULL) == TT_OK, "baseline fewer tiles");
    }

    CASE(tt_tile_histogram(NULL, &L, types, counts, E));
    CASE(tt_tile_histogram(m, NULL, types, counts, E));
    CASE(tt_tile_histogram(m, &L, NULL, counts, E));
    CASE(tt_tile_histogram(m, &L, types, NULL, E));
    bad = L; bad.gutter = -3;
    CASE(tt_tile_histogram(m, &bad, types, counts, E));
    CASE(tt_tile_histogram(b->tris, &L, types, counts, E));
    CASE(tt_tile_histogram(m, &L, bt, counts, E));
    CASE(tt_tile_histogram(&b->empty, &L, types, counts, E));

    CASE(tt_face_stretch(NULL, uv, stretch, E));
    CASE(tt_face_stretch(m, NULL, stretch, E));
    CASE(tt_face_stretch(m, uv, NULL, E));
    memcpy(bad_uv, uv, sizeof bad_uv);
    bad_uv[7] = b->nan_t;
    CASE(tt_face_stretch(m, bad_uv, stretch, E));
    bad_uv[7] = b->inf_t;
    CASE(tt_face_stretch(m, bad_uv, stretch, E));
    CASE(tt_face_stretch(&b->empty, uv, stretch, E));

    memset(&dop, 0, sizeof dop);
    CASE(tt_measure_uv_distortion(NULL, uv, 64, 64, &dop, AL, &drep, E));
    CASE(tt_measure_uv_distortion(m, NULL, 64, 64, &dop, AL, &drep, E));
    CASE(tt_measure_uv_distortion(m, uv, 64, 64, &dop, AL, NULL, E));
    CASE(tt_measure_uv_distortion(m, uv, 0, 64, &dop, AL, &drep, E));
    CASE(tt_measure_uv_distortion(m, uv, 64, -1, &dop, AL, &drep, E));
    CASE(tt_measure_uv_distortion(m, uv, INT_MIN, 64, &dop, AL, &drep, E));
    CASE(tt_measure_uv_distortion(m, uv, 64, 64, &dop, BA1, &drep, E));
    CASE(tt_measure_uv_distortion(m, uv, 64, 64, &dop, BA2, &drep, E));
    dop.texels_per_unit = -1;
    CASE(tt_measure_uv_distortion(m, uv, 64, 64, &dop, AL, &drep, E));
    dop.texels_per_unit = b->nan_d;
    CASE(tt_measure_uv_distortion(m, uv, 64, 64, &dop, AL, &drep, E));
    dop.texels_per_unit = b->inf_d;
    CASE(tt_measure_uv_distortion(m, uv, 64, 64, &dop, AL, &drep, E));
    dop.texels_per_unit = 0;
    dop.margin_texels = -1;
    CASE(tt_measure_uv_distortion(m, uv, 64, 64, &dop, AL, &drep, E));
    dop.margin_texels = b->nan_d;
    CASE(tt_measure_uv_distortion(m, uv, 64, 64, &dop, AL, &drep, E));
    dop.margin_texels = -b->inf_d;
    CASE(tt_measure_uv_distortion(m, uv, 64, 64, &dop, AL, &drep, E));
    dop.margin_texels = 0;
    CASE(tt_measure_uv_distortion(&b->empty, uv, 64, 64, &dop, AL, &drep, E));

    {
        tt_courses courses;
        CASE(tt_find_courses(NULL, AL, &courses, E));
        CASE(tt_find_courses(img, AL, NULL, E));
        CASE(tt_find_courses(img, BA1, &courses, E));
        CASE(tt_find_courses(img, BA2, &courses, E));
        v = *img;
        v.pixels = NULL;
        CASE(tt_find_courses(&v, AL, &courses, E));
        v = *img;
        v.height = 0;
        CASE(tt_find_courses(&v, AL, &courses, E));
        v = *img;
        v.kind = (tt_image_kind)6;
        CASE(tt_find_courses(&v, AL, &courses, E));
        v = image_view(32, 32, 0.5f);
        v.pixels[4 * 40 + 2] = b->nan_t;
        CASE(tt_find_courses(&v, AL, &courses, E));
        free(v.pixels);
    }
    memset(&so, 0, sizeof so);
    so.layout = L;
    OUT_CASE(pout, tt_synth_plan_free, tt_synth_plan_create(NULL, &so, AL, &pout, E));
    CASE(tt_synth_plan_create(img, &so, AL, NULL, E));
    OUT_CASE(pout, tt_synth_plan_free, tt_synth_plan_create(img, &so, BA1, &pout, E));
    OUT_CASE(pout, tt_synth_plan_free, tt_synth_plan_create(img, &so, BA2, &pout, E));
    so.courses.period = 1.5f;
    OUT_CASE(pout, tt_synth_plan_free, tt_synth_plan_create(img, &so, AL, &pout, E));
    so.courses.period = -4.0f;
    OUT_CASE(pout, tt_synth_plan_free, tt_synth_plan_create(img, &so, AL, &pout, E));
    so.courses.period = b->inf_t;
    OUT_CASE(pout, tt_synth_plan_free, tt_synth_plan_create(img, &so, AL, &pout, E));
    so.courses.period = 8.0f;
    so.courses.phase = b->nan_t;
    OUT_CASE(pout, tt_synth_plan_free, tt_synth_plan_create(img, &so, AL, &pout, E));
    memset(&so.courses, 0, sizeof so.courses);
    v = *img;
    v.pixels = NULL;
    OUT_CASE(pout, tt_synth_plan_free, tt_synth_plan_create(&v, &so, AL, &pout, E));
    v = *img;
    v.width = 0;
    OUT_CASE(pout, tt_synth_plan_free, tt_synth_plan_create(&v, &so, AL, &pout, E));
    v = *img;
    v.height = -32;
    OUT_CASE(pout, tt_synth_plan_free, tt_synth_plan_create(&v, &so, AL, &pout, E));
    v = *img;
    v.width = 4;   /* narrower than S = 8 */
    OUT_CASE(pout, tt_synth_plan_free, tt_synth_plan_create(&v, &so, AL, &pout, E));
    v = *img;
    v.kind = (tt_image_kind)5;
    OUT_CASE(pout, tt_synth_plan_free, tt_synth_plan_create(&v, &so, AL, &pout, E));
    v = image_view(32, 32, 0.5f);
    v.pixels[4 * 40 + 1] = b->nan_t;
    OUT_CASE(pout, tt_synth_plan_free, tt_synth_plan_create(&v, &so, AL, &pout, E));
    v.pixels[4 * 40 + 1] = -b->inf_t;
    OUT_CASE(pout, tt_synth_plan_free, tt_synth_plan_create(&v, &so, AL, &pout, E));
    free(v.pixels);
    sb = so; sb.layout.tile_size = 2;
    OUT_CASE(pout, tt_synth_plan_free, tt_synth_plan_create(img, &sb, AL, &pout, E));
    sb = so; sb.layout.colors = -5;
    OUT_CASE(pout, tt_synth_plan_free, tt_synth_plan_create(img, &sb, AL, &pout, E));
    sb = so; sb.layout.tile_size = 64;   /* the guide is smaller than S x 2S */
    OUT_CASE(pout, tt_synth_plan_free, tt_synth_plan_create(img, &sb, AL, &pout, E));
    sb = so; sb.feather = -1;
    OUT_CASE(pout, tt_synth_plan_free, tt_synth_plan_create(img, &sb, AL, &pout, E));
    sb = so; sb.feather = INT_MAX;
    OUT_CASE(pout, tt_synth_plan_free, tt_synth_plan_create(img, &sb, AL, &pout, E));
    sb = so; sb.levels = -1;
    OUT_CASE(pout, tt_synth_plan_free, tt_synth_plan_create(img, &sb, AL, &pout, E));
    sb = so; sb.levels = INT_MIN;
    OUT_CASE(pout, tt_synth_plan_free, tt_synth_plan_create(img, &sb, AL, &pout, E));
    sb = so; sb.plain_sides = 1 << 1;   /* without upright */
    OUT_CASE(pout, tt_synth_plan_free, tt_synth_plan_create(img, &sb, AL, &pout, E));
    sb = so; sb.upright = 1; sb.plain_sides = -1;
    OUT_CASE(pout, tt_synth_plan_free, tt_synth_plan_create(img, &sb, AL, &pout, E));
    sb = so; sb.background_candidates = -1;
    OUT_CASE(pout, tt_synth_plan_free, tt_synth_plan_create(img, &sb, AL, &pout, E));
    sb = so; sb.background_candidates = INT_MAX;
    OUT_CASE(pout, tt_synth_plan_free, tt_synth_plan_create(img, &sb, AL, &pout, E));
    sb = so; sb.background_candidates = INT_MIN;
    OUT_CASE(pout, tt_synth_plan_free, tt_synth_plan_create(img, &sb, AL, &pout, E));
    sb = so; sb.background.x = 30; sb.background.y = 0; sb.background.w = 16; sb.background.h = 16;
    OUT_CASE(pout, tt_synth_plan_free, tt_synth_plan_create(img, &sb, AL, &pout, E));
    sb = so; sb.background.x = -4; sb.background.y = 0; sb.background.w = 16; sb.background.h = 16;
    OUT_CASE(pout, tt_synth_plan_free, tt_synth_plan_create(img, &sb, AL, &pout, E));
    sb = so; sb.background.x = 0; sb.background.y = 0; sb.background.w = -16; sb.background.h = 16;
    OUT_CASE(pout, tt_synth_plan_free, tt_synth_plan_create(img, &sb, AL, &pout, E));
    sb = so; sb.background.x = INT_MAX; sb.background.y = INT_MAX; sb.background.w = INT_MAX; sb.background.h = 16;
    OUT_CASE(pout, tt_synth_plan_free, tt_synth_plan_create(img, &sb, AL, &pout, E));
    sb = so; sb.background.x = 0; sb.background.y = 0; sb.background.w = 4; sb.background.h = 4;   /* < S */
    OUT_CASE(pout, tt_synth_plan_free, tt_synth_plan_create(img, &sb, AL, &pout, E));
    win.x = 30; win.y = 0; win.w = 8; win.h = 16;
    sb = so; sb.edge_windows = &win;
    OUT_CASE(pout, tt_synth_plan_free, tt_synth_plan_create(img, &sb, AL, &pout, E));
    win.x = -1; win.y = INT_MAX;
    OUT_CASE(pout, tt_synth_plan_free, tt_synth_plan_create(img, &sb, AL, &pout, E));
    win.x = INT_MAX; win.y = 0;
    OUT_CASE(pout, tt_synth_plan_free, tt_synth_plan_create(img, &sb, AL, &pout, E));
    sb = so; sb.upright = 1; sb.layout.tile_size = 32;   /* upright needs 2S x 2S */
    OUT_CASE(pout, tt_synth_plan_free, tt_synth_plan_create(img, &sb, AL, &pout, E));

    OUT_CASE(ts, tt_tileset_free, tt_synthesize_tiles(NULL, &so, AL, &ts, E));
    CASE(tt_synthesize_tiles(img, &so, AL, NULL, E));
    OUT_CASE(ts, tt_tileset_free, tt_synthesize_tiles(img, &so, BA1, &ts, E));
    OUT_CASE(ts, tt_tileset_free, tt_synthesize_tiles(img, &so, BA2, &ts, E));
    sb = so; sb.layout.gutter = -1;
    OUT_CASE(ts, tt_tileset_free, tt_synthesize_tiles(img, &sb, AL, &ts, E));
    sb = so; sb.feather = -7;
    OUT_CASE(ts, tt_tileset_free, tt_synthesize_tiles(img, &sb, AL, &ts, E));
    v = image_view(32, 32, 0.5f);
    v.pixels[4 * 100 + 2] = b->nan_t;
    OUT_CASE(ts, tt_tileset_free, tt_synthesize_tiles(&v, &so, AL, &ts, E));
    v.pixels[4 * 100 + 2] = 0.5f;
    v.width = -1;
    OUT_CASE(ts, tt_tileset_free, tt_synthesize_tiles(&v, &so, AL, &ts, E));
    free(v.pixels);

    CHECK(tt_synth_plan_create(img, &so, AL, &plan, NULL) == TT_OK && plan, "baseline plan");
    if (!plan) return;
    OUT_CASE(ts, tt_tileset_free, tt_synth_apply(NULL, img, AL, &ts, E));
    OUT_CASE(ts, tt_tileset_free, tt_synth_apply(plan, NULL, AL, &ts, E));
    CASE(tt_synth_apply(plan, img, AL, NULL, E));
    OUT_CASE(ts, tt_tileset_free, tt_synth_apply(plan, img, BA1, &ts, E));
    OUT_CASE(ts, tt_tileset_free, tt_synth_apply(plan, img, BA2, &ts, E));
    v = image_view(16, 32, 0.5f);
    OUT_CASE(ts, tt_tileset_free, tt_synth_apply(plan, &v, AL, &ts, E));
    free(v.pixels);
    v = image_view(32, 32, 0.5f);
    v.pixels[4 * 200] = b->nan_t;
    OUT_CASE(ts, tt_tileset_free, tt_synth_apply(plan, &v, AL, &ts, E));
    v.pixels[4 * 200] = 0.5f;
    v.kind = (tt_image_kind)3;
    OUT_CASE(ts, tt_tileset_free, tt_synth_apply(plan, &v, AL, &ts, E));
    v.kind = TT_IMAGE_COLOR;
    {
        float *keep = v.pixels;
        v.pixels = NULL;
        OUT_CASE(ts, tt_tileset_free, tt_synth_apply(plan, &v, AL, &ts, E));
        v.pixels = keep;
    }

    cell = image_view(12, 12, 0);
    memset(bt, 0, 4);
    CASE(tt_synth_compose_tile(NULL, img, bt, &cell, 0, 0, E));
    CASE(tt_synth_compose_tile(plan, NULL, bt, &cell, 0, 0, E));
    CASE(tt_synth_compose_tile(plan, img, NULL, &cell, 0, 0, E));
    CASE(tt_synth_compose_tile(plan, img, bt, NULL, 0, 0, E));
    CASE(tt_synth_compose_tile(plan, img, bt, &cell, -1, 0, E));
    CASE(tt_synth_compose_tile(plan, img, bt, &cell, 0, 1, E));
    CASE(tt_synth_compose_tile(plan, img, bt, &cell, INT_MAX, 0, E));
    CASE(tt_synth_compose_tile(plan, img, bt, &cell, 0, INT_MIN, E));
    CASE(tt_synth_compose_tile(plan, &cell, bt, &cell, 0, 0, E));   /* not the plan's size */
    CASE(tt_synth_compose_tile(plan, &v, bt, &v, 0, 0, E));        /* shares texels with the source */
    bt[2] = 2;
    CASE(tt_synth_compose_tile(plan, img, bt, &cell, 0, 0, E));
    bt[2] = 255;
    CASE(tt_synth_compose_tile(plan, img, bt, &cell, 0, 0, E));
    bt[2] = 0;
    {
        tt_image nop = cell;
        nop.pixels = NULL;
        CASE(tt_synth_compose_tile(plan, img, bt, &nop, 0, 0, E));
        nop = cell;
        nop.width = -12;
        CASE(tt_synth_compose_tile(plan, img, bt, &nop, 0, 0, E));
    }
    for (i = 0; i < 32 * 32 * 4; i++) v.pixels[i] = b->nan_t;
    CASE(tt_synth_compose_tile(plan, &v, bt, &cell, 0, 0, E));
    free(v.pixels);
    free(cell.pixels);
    tt_synth_plan_free(plan);

    memset(&seo, 0, sizeof seo);
    CASE(tt_measure_seams(NULL, uv, img, &seo, AL, &srep, E));
    CASE(tt_measure_seams(m, NULL, img, &seo, AL, &srep, E));
    CASE(tt_measure_seams(m, uv, NULL, &seo, AL, &srep, E));
    CASE(tt_measure_seams(m, uv, img, &seo, AL, NULL, E));
    CASE(tt_measure_seams(m, uv, img, &seo, BA1, &srep, E));
    CASE(tt_measure_seams(m, uv, img, &seo, BA2, &srep, E));
    v = *img;
    v.width = 0;
    CASE(tt_measure_seams(m, uv, &v, &seo, AL, &srep, E));
    v = *img;
    v.pixels = NULL;
    CASE(tt_measure_seams(m, uv, &v, &seo, AL, &srep, E));
    seo.max_edges = -1;
    CASE(tt_measure_seams(m, uv, img, &seo, AL, &srep, E));
    seo.max_edges = 0;
    seo.nedges = -1;
    seo.edges = edges;
    CASE(tt_measure_seams(m, uv, img, &seo, AL, &srep, E));
    seo.nedges = 1;
    seo.edges = NULL;
    CASE(tt_measure_seams(m, uv, img, &seo, AL, &srep, E));
    seo.edges = edges;
    edges[0] = -1;
    CASE(tt_measure_seams(m, uv, img, &seo, AL, &srep, E));
    edges[0] = 24;
    CASE(tt_measure_seams(m, uv, img, &seo, AL, &srep, E));
    edges[0] = INT_MIN;
    CASE(tt_measure_seams(m, uv, img, &seo, AL, &srep, E));
    edges[0] = 0;   /* a boundary edge of the grid */
    CASE(tt_measure_seams(b->grid, uv, img, &seo, AL, &srep, E));
    seo.nedges = 0;
    seo.edges = NULL;
    seo.flags = 1u << 5;
    CASE(tt_measure_seams(m, uv, img, &seo, AL, &srep, E));
    seo.flags = 0x80000000u;
    CASE(tt_measure_seams(m, uv, img, &seo, AL, &srep, E));
    seo.flags = 0;
    CASE(tt_measure_seams(&b->empty, uv, img, &seo, AL, &srep, E));

    /* The compact atlas of the quads' tiles (the full atlas: 4 x 4 cells of 12 texels). */
    {
        tt_compact_atlas *ca = NULL, *cout = NULL;
        tt_image *iout = NULL;
        OUT_CASE(cout, tt_compact_atlas_free, tt_compact_atlas_create(NULL, uv, &L, 48, 48, 0, AL, &cout, E));
        OUT_CASE(cout, tt_compact_atlas_free, tt_compact_atlas_create(m, NULL, &L, 48, 48, 0, AL, &cout, E));
        OUT_CASE(cout, tt_compact_atlas_free, tt_compact_atlas_create(m, uv, NULL, 48, 48, 0, AL, &cout, E));
        CASE(tt_compact_atlas_create(m, uv, &L, 48, 48, 0, AL, NULL, E));
        OUT_CASE(cout, tt_compact_atlas_free, tt_compact_atlas_create(m, uv, &L, 48, 48, 0, BA1, &cout, E));
        OUT_CASE(cout, tt_compact_atlas_free, tt_compact_atlas_create(m, uv, &L, 48, 48, 0, BA2, &cout, E));
        bad = L; bad.tile_size = -8;
        OUT_CASE(cout, tt_compact_atlas_free, tt_compact_atlas_create(m, uv, &bad, 48, 48, 0, AL, &cout, E));
        OUT_CASE(cout, tt_compact_atlas_free, tt_compact_atlas_create(m, uv, &L, 47, 48, 0, AL, &cout, E));
        OUT_CASE(cout, tt_compact_atlas_free, tt_compact_atlas_create(m, uv, &L, 48, 0, 0, AL, &cout, E));
        OUT_CASE(cout, tt_compact_atlas_free, tt_compact_atlas_create(m, uv, &L, -48, 48, 0, AL, &cout, E));
        OUT_CASE(cout, tt_compact_atlas_free, tt_compact_atlas_create(m, uv, &L, INT_MAX, 48, 0, AL, &cout, E));
        OUT_CASE(cout, tt_compact_atlas_free, tt_compact_atlas_create(m, uv, &L, 48, INT_MIN, 0, AL, &cout, E));
        OUT_CASE(cout, tt_compact_atlas_free, tt_compact_atlas_create(m, uv, &L, 48, 48, -1, AL, &cout, E));
        OUT_CASE(cout, tt_compact_atlas_free,
                 tt_compact_atlas_create(m, uv, &L, 48, 48, TT_MAX_IMAGE_SIZE + 1, AL, &cout, E));
        OUT_CASE(cout, tt_compact_atlas_free, tt_compact_atlas_create(m, uv, &L, 48, 48, INT_MIN, AL, &cout, E));
        OUT_CASE(cout, tt_compact_atlas_free, tt_compact_atlas_create(m, uv, &L, 48, 48, 8, AL, &cout, E));
        memcpy(bad_uv, uv, sizeof bad_uv);
        bad_uv[5] = b->nan_t;
        OUT_CASE(cout, tt_compact_atlas_free, tt_compact_atlas_create(m, bad_uv, &L, 48, 48, 0, AL, &cout, E));
        bad_uv[5] = b->inf_t;
        OUT_CASE(cout, tt_compact_atlas_free, tt_compact_atlas_create(m, bad_uv, &L, 48, 48, 0, AL, &cout, E));
        bad_uv[5] = 1e30f;
        OUT_CASE(cout, tt_compact_atlas_free, tt_compact_atlas_create(m, bad_uv, &L, 48, 48, 0, AL, &cout, E));
        bad_uv[5] = uv[5] + 0.5f;   /* one corner in another cell */
        OUT_CASE(cout, tt_compact_atlas_free, tt_compact_atlas_create(m, bad_uv, &L, 48, 48, 0, AL, &cout, E));
        for (i = 0; i < 48; i++) bad_uv[i] = -1.0f;   /* every face outside */
        OUT_CASE(cout, tt_compact_atlas_free, tt_compact_atlas_create(m, bad_uv, &L, 48, 48, 0, AL, &cout, E));
        OUT_CASE(cout, tt_compact_atlas_free, tt_compact_atlas_create(&b->empty, uv, &L, 48, 48, 0, AL, &cout, E));

        CHECK(tt_compact_atlas_create(m, uv, &L, 48, 48, 0, AL, &ca, NULL) == TT_OK && ca, "baseline compact atlas");
        if (!ca) return;
        v = image_view(48, 48, 0.5f);
        OUT_CASE(iout, tt_image_free, tt_compact_atlas_image(NULL, &v, AL, &iout, E));
        OUT_CASE(iout, tt_image_free, tt_compact_atlas_image(ca, NULL, AL, &iout, E));
        CASE(tt_compact_atlas_image(ca, &v, AL, NULL, E));
        OUT_CASE(iout, tt_image_free, tt_compact_atlas_image(ca, &v, BA1, &iout, E));
        OUT_CASE(iout, tt_image_free, tt_compact_atlas_image(ca, &v, BA2, &iout, E));
        v.width = 47;
        OUT_CASE(iout, tt_image_free, tt_compact_atlas_image(ca, &v, AL, &iout, E));
        v.width = -48;
        OUT_CASE(iout, tt_image_free, tt_compact_atlas_image(ca, &v, AL, &iout, E));
        v.width = 48;
        {
            float *keep = v.pixels;
            v.pixels = NULL;
            OUT_CASE(iout, tt_image_free, tt_compact_atlas_image(ca, &v, AL, &iout, E));
            v.pixels = keep;
        }
        {
            /* The full atlas in parts: 2 x 1 of 24 x 48 is its size. */
            tt_image left = image_view(24, 48, 0.5f), right = image_view(24, 48, 0.25f);
            const tt_image *two[2], *with_null[2];
            two[0] = &left;
            two[1] = &right;
            with_null[0] = &left;
            with_null[1] = NULL;
            OUT_CASE(iout, tt_image_free, tt_compact_atlas_image_parts(NULL, two, 2, 1, AL, &iout, E));
            OUT_CASE(iout, tt_image_free, tt_compact_atlas_image_parts(ca, NULL, 2, 1, AL, &iout, E));
            OUT_CASE(iout, tt_image_free, tt_compact_atlas_image_parts(ca, with_null, 2, 1, AL, &iout, E));
            CASE(tt_compact_atlas_image_parts(ca, two, 2, 1, AL, NULL, E));
            OUT_CASE(iout, tt_image_free, tt_compact_atlas_image_parts(ca, two, 2, 1, BA1, &iout, E));
            OUT_CASE(iout, tt_image_free, tt_compact_atlas_image_parts(ca, two, 0, 1, AL, &iout, E));
            OUT_CASE(iout, tt_image_free, tt_compact_atlas_image_parts(ca, two, 2, 0, AL, &iout, E));
            OUT_CASE(iout, tt_image_free, tt_compact_atlas_image_parts(ca, two, 3, 1, AL, &iout, E));
            OUT_CASE(iout, tt_image_free, tt_compact_atlas_image_parts(ca, two, -1, -2, AL, &iout, E));
            OUT_CASE(iout, tt_image_free, tt_compact_atlas_image_parts(ca, two, 1, 2, AL, &iout, E));
            right.width = 23;
            OUT_CASE(iout, tt_image_free, tt_compact_atlas_image_parts(ca, two, 2, 1, AL, &iout, E));
            right.width = 24;
            right.kind = TT_IMAGE_NORMAL;
            OUT_CASE(iout, tt_image_free, tt_compact_atlas_image_parts(ca, two, 2, 1, AL, &iout, E));
            free(left.pixels);
            free(right.pixels);
        }
        free(v.pixels);
        tt_compact_atlas_free(ca);
    }
}

static void cases_lapped(const baseline *b)
{
    const tt_mesh *m = b->tris;
    float field[36], bf[36], cuv[72], buv[72];
    tt_field_options fo, fb;
    tt_field_constraint fc;
    tt_patch_options po;
    tt_image *source = NULL, *patch = NULL, *pout = NULL, v, mask, *patches[2], *atlas = NULL;
    tt_lapped *lapped = NULL, *lout = NULL, hand;
    tt_lapped_options lo;
    tt_lapped_report lrep;
    tt_chart_atlas_report crep;
    tt_uv_report urep;
    tt_bake_options bo;
    tt_paste paste;
    int i;

    memset(&fo, 0, sizeof fo);
    fo.scale = 0.6f;
    memset(&fc, 0, sizeof fc);
    fc.face = 0;
    fc.vector[0] = 1;
    CASE(tt_field_face_weights(NULL, &fo, field, E));
    CASE(tt_field_face_weights(m, &fo, NULL, E));
    CASE(tt_field_face_weights(&b->empty, &fo, field, E));
    fb = fo; fb.up[0] = b->nan_t;
    CASE(tt_field_face_weights(m, &fb, field, E));
    fb = fo; fb.up[1] = b->inf_t;
    CASE(tt_field_face_weights(m, &fb, field, E));
    fb = fo; fb.sigma = -1;
    CASE(tt_field_face_weights(m, &fb, field, E));
    fb = fo; fb.nconstraints = 1; fb.constraints = NULL;
    CASE(tt_field_face_weights(m, &fb, field, E));

    CASE(tt_tangent_field(NULL, &fo, AL, field, E));
    CASE(tt_tangent_field(m, &fo, AL, NULL, E));
    CASE(tt_tangent_field(m, &fo, BA1, field, E));
    CASE(tt_tangent_field(m, &fo, BA2, field, E));
    CASE(tt_tangent_field(&b->empty, &fo, AL, field, E));
    fb = fo; fb.up[2] = b->nan_t;
    CASE(tt_tangent_field(m, &fb, AL, field, E));
    fb = fo; fb.up[1] = b->inf_t;
    CASE(tt_tangent_field(m, &fb, AL, field, E));
    fb = fo; fb.scale = -1;
    CASE(tt_tangent_field(m, &fb, AL, field, E));
    fb = fo; fb.scale = b->nan_t;
    CASE(tt_tangent_field(m, &fb, AL, field, E));
    fb = fo; fb.scale = b->inf_t;
    CASE(tt_tangent_field(m, &fb, AL, field, E));
    fb = fo; fb.sigma = -1;
    CASE(tt_tangent_field(m, &fb, AL, field, E));
    fb = fo; fb.sigma = b->nan_t;
    CASE(tt_tangent_field(m, &fb, AL, field, E));
    fb = fo; fb.nconstraints = -1;
    CASE(tt_tangent_field(m, &fb, AL, field, E));
    fb = fo; fb.nconstraints = 1; fb.constraints = NULL;
    CASE(tt_tangent_field(m, &fb, AL, field, E));
    fb = fo; fb.nconstraints = 1; fb.constraints = &fc;
    fc.face = -1;
    CASE(tt_tangent_field(m, &fb, AL, field, E));
    fc.face = 12;
    CASE(tt_tangent_field(m, &fb, AL, field, E));
    fc.face = INT_MIN;
    CASE(tt_tangent_field(m, &fb, AL, field, E));
    fc.face = 0;
    fc.vector[0] = 0;
    CASE(tt_tangent_field(m, &fb, AL, field, E));
    fc.vector[0] = b->nan_t;
    CASE(tt_tangent_field(m, &fb, AL, field, E));
    fc.vector[0] = -b->inf_t;
    CASE(tt_tangent_field(m, &fb, AL, field, E));
    fc.vector[0] = 0;
    fc.vector[2] = 1;   /* face 0 lies in z = 0: perpendicular */
    CASE(tt_tangent_field(m, &fb, AL, field, E));
    fc.vector[2] = 0;
    fc.vector[0] = 1;
    fc.sigma = -1;
    CASE(tt_tangent_field(m, &fb, AL, field, E));
    fc.sigma = b->nan_t;
    CASE(tt_tangent_field(m, &fb, AL, field, E));
    fc.sigma = 0;
    fc.weight = -1;
    CASE(tt_tangent_field(m, &fb, AL, field, E));
    fc.weight = b->inf_t;
    CASE(tt_tangent_field(m, &fb, AL, field, E));
    fc.weight = 0;

    CHECK(tt_tangent_field(m, &fo, AL, field, NULL) == TT_OK, "baseline field");
    CHECK(tt_image_create(32, 32, AL, &source, NULL) == TT_OK && source, "baseline patch source");
    if (!source) return;
    for (i = 0; i < 32 * 32 * 4; i++) source->pixels[i] = 1.0f;
    memset(&po, 0, sizeof po);
    OUT_CASE(pout, tt_image_free, tt_make_texture_patch(NULL, NULL, &po, AL, &pout, E));
    CASE(tt_make_texture_patch(source, NULL, &po, AL, NULL, E));
    OUT_CASE(pout, tt_image_free, tt_make_texture_patch(source, NULL, &po, BA1, &pout, E));
    OUT_CASE(pout, tt_image_free, tt_make_texture_patch(source, NULL, &po, BA2, &pout, E));
    v = *source;
    v.width = 0;
    OUT_CASE(pout, tt_image_free, tt_make_texture_patch(&v, NULL, &po, AL, &pout, E));
    v = *source;
    v.height = -3;
    OUT_CASE(pout, tt_image_free, tt_make_texture_patch(&v, NULL, &po, AL, &pout, E));
    v = *source;
    v.pixels = NULL;
    OUT_CASE(pout, tt_image_free, tt_make_texture_patch(&v, NULL, &po, AL, &pout, E));
    v = *source;
    v.width = INT_MAX;
    OUT_CASE(pout, tt_image_free, tt_make_texture_patch(&v, NULL, &po, AL, &pout, E));
    v = *source;
    v.kind = (tt_image_kind)4;
    OUT_CASE(pout, tt_image_free, tt_make_texture_patch(&v, NULL, &po, AL, &pout, E));
    mask = image_view(16, 32, 1.0f);
    OUT_CASE(pout, tt_image_free, tt_make_texture_patch(source, &mask, &po, AL, &pout, E));
    free(mask.pixels);
    mask = image_view(32, 32, 0.0f);   /* no opaque texel */
    OUT_CASE(pout, tt_image_free, tt_make_texture_patch(source, &mask, &po, AL, &pout, E));
    for (i = 0; i < 32 * 32 * 4; i++) mask.pixels[i] = 1.0f;
    mask.pixels[4 * 33] = b->inf_t;
    OUT_CASE(pout, tt_image_free, tt_make_texture_patch(source, &mask, &po, AL, &pout, E));
    mask.pixels[4 * 33 + 3] = b->nan_t;
    OUT_CASE(pout, tt_image_free, tt_make_texture_patch(source, &mask, &po, AL, &pout, E));
    {
        float *keep = mask.pixels;
        mask.pixels = NULL;
        OUT_CASE(pout, tt_image_free, tt_make_texture_patch(source, &mask, &po, AL, &pout, E));
        mask.pixels = keep;
    }
    free(mask.pixels);
    v = image_view(32, 32, 1.0f);
    v.pixels[4 * 500 + 1] = b->nan_t;
    OUT_CASE(pout, tt_image_free, tt_make_texture_patch(&v, NULL, &po, AL, &pout, E));
    v.pixels[4 * 500 + 1] = b->inf_t;
    OUT_CASE(pout, tt_image_free, tt_make_texture_patch(&v, NULL, &po, AL, &pout, E));
    free(v.pixels);
    po.falloff = -1;
    OUT_CASE(pout, tt_image_free, tt_make_texture_patch(source, NULL, &po, AL, &pout, E));
    po.falloff = b->nan_t;
    OUT_CASE(pout, tt_image_free, tt_make_texture_patch(source, NULL, &po, AL, &pout, E));
    po.falloff = b->inf_t;
    OUT_CASE(pout, tt_image_free, tt_make_texture_patch(source, NULL, &po, AL, &pout, E));
    po.falloff = 1e6f;
    OUT_CASE(pout, tt_image_free, tt_make_texture_patch(source, NULL, &po, AL, &pout, E));
    po.falloff = 0;
    po.roughness = -0.25f;
    OUT_CASE(pout, tt_image_free, tt_make_texture_patch(source, NULL, &po, AL, &pout, E));
    po.roughness = 1;
    OUT_CASE(pout, tt_image_free, tt_make_texture_patch(source, NULL, &po, AL, &pout, E));
    po.roughness = b->nan_t;
    OUT_CASE(pout, tt_image_free, tt_make_texture_patch(source, NULL, &po, AL, &pout, E));
    memset(&po, 0x5a, sizeof po);
    OUT_CASE(pout, tt_image_free, tt_make_texture_patch(source, NULL, &po, AL, &pout, E));

    CHECK(tt_make_texture_patch(source, NULL, NULL, AL, &patch, NULL) == TT_OK && patch, "baseline patch");
    if (!patch) {
        tt_image_free(source);
        return;
    }
    patches[0] = patch;
    patches[1] = NULL;
    memset(&lo, 0, sizeof lo);
    OUT_CASE(lout, tt_lapped_free, tt_lapped_paste(NULL, field, patches, 1, &lo, AL, &lout, E));
    OUT_CASE(lout, tt_lapped_free, tt_lapped_paste(m, NULL, patches, 1, &lo, AL, &lout, E));
    OUT_CASE(lout, tt_lapped_free, tt_lapped_paste(m, field, NULL, 1, &lo, AL, &lout, E));
    CASE(tt_lapped_paste(m, field, patches, 1, &lo, AL, NULL, E));
    OUT_CASE(lout, tt_lapped_free, tt_lapped_paste(m, field, patches, 0, &lo, AL, &lout, E));
    OUT_CASE(lout, tt_lapped_free, tt_lapped_paste(m, field, patches, -1, &lo, AL, &lout, E));
    OUT_CASE(lout, tt_lapped_free, tt_lapped_paste(m, field, patches, INT_MIN, &lo, AL, &lout, E));
    OUT_CASE(lout, tt_lapped_free, tt_lapped_paste(m, field, patches, 2, &lo, AL, &lout, E));   /* patches[1] NULL */
    OUT_CASE(lout, tt_lapped_free, tt_lapped_paste(m, field, patches, 1, &lo, BA1, &lout, E));
    OUT_CASE(lout, tt_lapped_free, tt_lapped_paste(m, field, patches, 1, &lo, BA2, &lout, E));
    OUT_CASE(lout, tt_lapped_free, tt_lapped_paste(b->quads, field, patches, 1, &lo, AL, &lout, E));
    OUT_CASE(lout, tt_lapped_free, tt_lapped_paste(&b->empty, field, patches, 1, &lo, AL, &lout, E));
    lo.max_pastes = -1;
    OUT_CASE(lout, tt_lapped_free, tt_lapped_paste(m, field, patches, 1, &lo, AL, &lout, E));
    lo.max_pastes = INT_MIN;
    OUT_CASE(lout, tt_lapped_free, tt_lapped_paste(m, field, patches, 1, &lo, AL, &lout, E));
    lo.max_pastes = 0;
    memcpy(bf, field, sizeof bf);
    bf[3] = bf[4] = bf[5] = 0;
    OUT_CASE(lout, tt_lapped_free, tt_lapped_paste(m, bf, patches, 1, &lo, AL, &lout, E));
    memcpy(bf, field, sizeof bf);
    bf[4] = b->nan_t;
    OUT_CASE(lout, tt_lapped_free, tt_lapped_paste(m, bf, patches, 1, &lo, AL, &lout, E));
    bf[4] = -b->inf_t;
    OUT_CASE(lout, tt_lapped_free, tt_lapped_paste(m, bf, patches, 1, &lo, AL, &lout, E));
    for (i = 0; i < 36; i++) bf[i] = field[i] * 100;   /* a patch larger than the mesh */
    OUT_CASE(lout, tt_lapped_free, tt_lapped_paste(m, bf, patches, 1, &lo, AL, &lout, E));
    v = image_view(32, 32, 0.0f);   /* no opaque texel */
    patches[1] = &v;
    OUT_CASE(lout, tt_lapped_free, tt_lapped_paste(m, field, patches, 2, &lo, AL, &lout, E));
    for (i = 0; i < 32 * 32 * 4; i++) v.pixels[i] = 1.0f;
    v.pixels[4 * 300] = b->nan_t;
    OUT_CASE(lout, tt_lapped_free, tt_lapped_paste(m, field, patches, 2, &lo, AL, &lout, E));
    v.pixels[4 * 300] = 1.0f;
    v.width = 0;
    OUT_CASE(lout, tt_lapped_free, tt_lapped_paste(m, field, patches, 2, &lo, AL, &lout, E));
    v.width = 32;
    {
        float *keep = v.pixels;
        v.pixels = NULL;
        OUT_CASE(lout, tt_lapped_free, tt_lapped_paste(m, field, patches, 2, &lo, AL, &lout, E));
        v.pixels = keep;
    }
    patches[1] = NULL;

    {
        /* how level a map lies: hostile arguments */
        float duv[72];
        tt_uv_direction_options dopt;
        tt_uv_direction_report drep;
        memset(duv, 0, sizeof duv);
        memset(&dopt, 0, sizeof dopt);
        CASE(tt_measure_uv_direction(NULL, duv, 64, 64, &dopt, AL, &drep, E));
        CASE(tt_measure_uv_direction(m, NULL, 64, 64, &dopt, AL, &drep, E));
        CASE(tt_measure_uv_direction(m, duv, 64, 64, &dopt, AL, NULL, E));
        CASE(tt_measure_uv_direction(m, duv, 0, 64, &dopt, AL, &drep, E));
        CASE(tt_measure_uv_direction(m, duv, 64, INT_MIN, &dopt, AL, &drep, E));
        CASE(tt_measure_uv_direction(m, duv, 64, 64, &dopt, BA1, &drep, E));
        CASE(tt_measure_uv_direction(m, duv, 64, 64, &dopt, BA2, &drep, E));
        {
            /* quads are measured (as fans), not refused: a collapsed map reads 90 degrees */
            float *quad_uv = (float *)calloc(2 * (size_t)b->quads->ncorners, sizeof(float));
            CHECK(quad_uv && tt_measure_uv_direction(b->quads, quad_uv, 64, 64, &dopt, AL, &drep, NULL) != TT_ERROR_INVALID_ARGUMENT &&
                      drep.singular == drep.faces,
                  "a quad mesh is measured: %d of %d faces singular", drep.singular, drep.faces);
            free(quad_uv);
        }
        /* a collapsed or non-finite map is measured, not refused: 90 degrees */
        duv[3] = b->nan_t;
        CHECK(tt_measure_uv_direction(m, duv, 64, 64, NULL, AL, &drep, NULL) == TT_OK && drep.faces > 0 &&
                  drep.singular == drep.faces && drep.mean == 90,
              "collapsed and NaN UVs: %d of %d faces singular", drep.singular, drep.faces);
        dopt.up[1] = b->inf_t;
        CASE(tt_measure_uv_direction(m, duv, 64, 64, &dopt, AL, &drep, E));
        dopt.up[1] = b->nan_t;
        CASE(tt_measure_uv_direction(m, duv, 64, 64, &dopt, AL, &drep, E));
        dopt.up[1] = 1;
        dopt.min_projected = 2;
        CASE(tt_measure_uv_direction(m, duv, 64, 64, &dopt, AL, &drep, E));
        dopt.min_projected = b->nan_t;
        CASE(tt_measure_uv_direction(m, duv, 64, 64, &dopt, AL, &drep, E));
        dopt.min_projected = 0;
        dopt.tolerance = -b->inf_t;
        CASE(tt_measure_uv_direction(m, duv, 64, 64, &dopt, AL, &drep, E));
    }
    CHECK(tt_lapped_paste(m, field, patches, 1, &lo, AL, &lapped, NULL) == TT_OK && lapped, "baseline pastes");
    if (lapped) {
        CASE(tt_lapped_measure(NULL, field, lapped, AL, &lrep, E));
        CASE(tt_lapped_measure(m, NULL, lapped, AL, &lrep, E));
        CASE(tt_lapped_measure(m, field, NULL, AL, &lrep, E));
        CASE(tt_lapped_measure(m, field, lapped, AL, NULL, E));
        CASE(tt_lapped_measure(m, field, lapped, BA1, &lrep, E));
        CASE(tt_lapped_measure(m, field, lapped, BA2, &lrep, E));
        CASE(tt_lapped_measure(b->quads, field, lapped, AL, &lrep, E));
        memcpy(bf, field, sizeof bf);
        for (i = 0; i < 36; i++) bf[i] = b->nan_t;
        CASE(tt_lapped_measure(m, bf, lapped, AL, &lrep, E));
        hand = *lapped;
        paste = lapped->pastes[0];
        hand.pastes = &paste;
        hand.npastes = 1;
        paste.nfaces = lapped->nentries + 5;   /* beyond the list */
        CASE(tt_lapped_measure(m, field, &hand, AL, &lrep, E));
        paste.nfaces = -1;
        CASE(tt_lapped_measure(m, field, &hand, AL, &lrep, E));
        paste.nfaces = INT_MAX;
        CASE(tt_lapped_measure(m, field, &hand, AL, &lrep, E));
        paste.nfaces = 1;
        paste.first = -1;
        CASE(tt_lapped_measure(m, field, &hand, AL, &lrep, E));
        paste.first = INT_MAX;
        CASE(tt_lapped_measure(m, field, &hand, AL, &lrep, E));
        paste.first = 0;
        hand.npastes = -1;
        CASE(tt_lapped_measure(m, field, &hand, AL, &lrep, E));
        hand.npastes = 1;
        hand.nentries = -1;
        CASE(tt_lapped_measure(m, field, &hand, AL, &lrep, E));
        hand.nentries = lapped->nentries;
        hand.pastes = NULL;
        CASE(tt_lapped_measure(m, field, &hand, AL, &lrep, E));
        hand.pastes = &paste;
        {
            int *faces = (int *)malloc(sizeof(int) * (size_t)lapped->nentries);
            float *uvs = fdup(lapped->uv, 6 * (size_t)lapped->nentries);
            float *fade = lapped->fade ? fdup(lapped->fade, 3 * (size_t)lapped->nentries) : NULL;
            memcpy(faces, lapped->faces, sizeof(int) * (size_t)lapped->nentries);
            hand.faces = faces;
            faces[0] = 12;
            CASE(tt_lapped_measure(m, field, &hand, AL, &lrep, E));
            faces[0] = -1;
            CASE(tt_lapped_measure(m, field, &hand, AL, &lrep, E));
            faces[0] = lapped->faces[0];
            hand.uv = uvs;
            uvs[1] = b->nan_t;
            CASE(tt_lapped_measure(m, field, &hand, AL, &lrep, E));
            uvs[1] = b->inf_t;
            CASE(tt_lapped_measure(m, field, &hand, AL, &lrep, E));
            uvs[1] = lapped->uv[1];
            hand.faces = NULL;
            CASE(tt_lapped_measure(m, field, &hand, AL, &lrep, E));
            hand.faces = faces;
            hand.uv = NULL;
            CASE(tt_lapped_measure(m, field, &hand, AL, &lrep, E));
            hand.uv = uvs;

            /* the bake */
            CHECK(tt_atlas_pack_pairs(m, 64, 2, cuv, NULL) == TT_OK, "baseline pair atlas");
            CHECK(tt_image_create(64, 64, AL, &atlas, NULL) == TT_OK && atlas, "baseline bake target");
            memset(&bo, 0, sizeof bo);
            if (atlas) {
                tt_image a2 = *atlas;
                patches[1] = NULL;
                CASE(tt_lapped_bake(NULL, lapped, patches, 1, cuv, &bo, AL, atlas, E));
                CASE(tt_lapped_bake(m, NULL, patches, 1, cuv, &bo, AL, atlas, E));
                CASE(tt_lapped_bake(m, lapped, NULL, 1, cuv, &bo, AL, atlas, E));
                CASE(tt_lapped_bake(m, lapped, patches, 1, NULL, &bo, AL, atlas, E));
                CASE(tt_lapped_bake(m, lapped, patches, 1, cuv, &bo, AL, NULL, E));
                CASE(tt_lapped_bake(m, lapped, patches, 0, cuv, &bo, AL, atlas, E));
                CASE(tt_lapped_bake(m, lapped, patches, -1, cuv, &bo, AL, atlas, E));
                CASE(tt_lapped_bake(m, lapped, patches, 2, cuv, &bo, AL, atlas, E));   /* patches[1] NULL */
                CASE(tt_lapped_bake(m, lapped, patches, 1, cuv, &bo, BA1, atlas, E));
                CASE(tt_lapped_bake(m, lapped, patches, 1, cuv, &bo, BA2, atlas, E));
                CASE(tt_lapped_bake(b->quads, lapped, patches, 1, cuv, &bo, AL, atlas, E));
                CASE(tt_lapped_bake(&b->empty, lapped, patches, 1, cuv, &bo, AL, atlas, E));
                a2.width = 0;
                CASE(tt_lapped_bake(m, lapped, patches, 1, cuv, &bo, AL, &a2, E));
                a2 = *atlas;
                a2.height = -64;
                CASE(tt_lapped_bake(m, lapped, patches, 1, cuv, &bo, AL, &a2, E));
                a2 = *atlas;
                a2.pixels = NULL;
                CASE(tt_lapped_bake(m, lapped, patches, 1, cuv, &bo, AL, &a2, E));
                a2 = *atlas;
                a2.width = INT_MAX;
                CASE(tt_lapped_bake(m, lapped, patches, 1, cuv, &bo, AL, &a2, E));
                bo.gutter = -1;
                CASE(tt_lapped_bake(m, lapped, patches, 1, cuv, &bo, AL, atlas, E));
                bo.gutter = INT_MIN;
                CASE(tt_lapped_bake(m, lapped, patches, 1, cuv, &bo, AL, atlas, E));
                bo.gutter = 0;
                memcpy(buv, cuv, sizeof buv);
                buv[9] = b->nan_t;
                CASE(tt_lapped_bake(m, lapped, patches, 1, buv, &bo, AL, atlas, E));
                buv[9] = -b->inf_t;
                CASE(tt_lapped_bake(m, lapped, patches, 1, buv, &bo, AL, atlas, E));
                paste.nfaces = lapped->pastes[0].nfaces;
                paste.patch = 3;
                CASE(tt_lapped_bake(m, &hand, patches, 1, cuv, &bo, AL, atlas, E));
                paste.patch = -1;
                CASE(tt_lapped_bake(m, &hand, patches, 1, cuv, &bo, AL, atlas, E));
                paste.patch = 0;
                paste.nfaces = lapped->nentries + 5;
                CASE(tt_lapped_bake(m, &hand, patches, 1, cuv, &bo, AL, atlas, E));
                paste.nfaces = 1;
                paste.first = -3;
                CASE(tt_lapped_bake(m, &hand, patches, 1, cuv, &bo, AL, atlas, E));
                paste.first = 0;
                faces[0] = 99;
                CASE(tt_lapped_bake(m, &hand, patches, 1, cuv, &bo, AL, atlas, E));
                faces[0] = lapped->faces[0];
                uvs[0] = b->nan_t;
                CASE(tt_lapped_bake(m, &hand, patches, 1, cuv, &bo, AL, atlas, E));
                uvs[0] = lapped->uv[0];
                if (fade) {
                    hand.fade = fade;
                    fade[0] = b->nan_t;
                    CASE(tt_lapped_bake(m, &hand, patches, 1, cuv, &bo, AL, atlas, E));
                    fade[0] = -b->inf_t;
                    CASE(tt_lapped_bake(m, &hand, patches, 1, cuv, &bo, AL, atlas, E));
                    hand.fade = lapped->fade;
                }
                hand.npastes = -2;
                CASE(tt_lapped_bake(m, &hand, patches, 1, cuv, &bo, AL, atlas, E));
                hand.npastes = 1;
                {
                    tt_image normal = *patch;
                    normal.kind = TT_IMAGE_NORMAL;
                    patches[1] = &normal;   /* one colour patch, one normal map */
                    CASE(tt_lapped_bake(m, lapped, patches, 2, cuv, &bo, AL, atlas, E));
                    normal.kind = (tt_image_kind)6;
                    patches[0] = &normal;
                    CASE(tt_lapped_bake(m, lapped, patches, 1, cuv, &bo, AL, atlas, E));
                    patches[0] = patch;
                    patches[1] = NULL;
                }
            }
            free(faces);
            free(uvs);
            free(fade);
        }
        tt_lapped_free(lapped);
    }
    free(v.pixels);

    CASE(tt_atlas_pack_pairs(NULL, 64, 2, cuv, E));
    CASE(tt_atlas_pack_pairs(m, 64, 2, NULL, E));
    CASE(tt_atlas_pack_pairs(m, 0, 2, cuv, E));
    CASE(tt_atlas_pack_pairs(m, -64, 2, cuv, E));
    CASE(tt_atlas_pack_pairs(m, TT_MAX_IMAGE_SIZE + 1, 2, cuv, E));
    CASE(tt_atlas_pack_pairs(m, INT_MAX, 2, cuv, E));
    CASE(tt_atlas_pack_pairs(m, 64, -1, cuv, E));
    CASE(tt_atlas_pack_pairs(m, 64, INT_MAX, cuv, E));
    CASE(tt_atlas_pack_pairs(m, 64, INT_MAX / 2, cuv, E));
    CASE(tt_atlas_pack_pairs(m, 4, 2, cuv, E));   /* cells too small */
    CASE(tt_atlas_pack_pairs(b->quads, 64, 2, cuv, E));
    CASE(tt_atlas_pack_pairs(&b->empty, 64, 2, cuv, E));

    CASE(tt_atlas_pack_charts(NULL, 64, 2, NULL, AL, cuv, &crep, E));
    CASE(tt_atlas_pack_charts(m, 64, 2, NULL, AL, NULL, &crep, E));
    CASE(tt_atlas_pack_charts(m, 0, 2, NULL, AL, cuv, &crep, E));
    CASE(tt_atlas_pack_charts(m, INT_MIN, 2, NULL, AL, cuv, &crep, E));
    CASE(tt_atlas_pack_charts(m, INT_MAX, 2, NULL, AL, cuv, &crep, E));
    CASE(tt_atlas_pack_charts(m, 64, -2, NULL, AL, cuv, &crep, E));
    CASE(tt_atlas_pack_charts(m, 64, INT_MAX, NULL, AL, cuv, &crep, E));
    CASE(tt_atlas_pack_charts(m, 64, INT_MAX / 2 + 1, NULL, AL, cuv, &crep, E));
    CASE(tt_atlas_pack_charts(m, 4, 2, NULL, AL, cuv, &crep, E));
    CASE(tt_atlas_pack_charts(m, 64, 2, NULL, BA1, cuv, &crep, E));
    CASE(tt_atlas_pack_charts(m, 64, 2, NULL, BA2, cuv, &crep, E));
    CASE(tt_atlas_pack_charts(b->quads, 64, 2, NULL, AL, cuv, &crep, E));
    CASE(tt_atlas_pack_charts(&b->empty, 64, 2, NULL, AL, cuv, &crep, E));

    CASE(tt_uv_check(NULL, cuv, AL, &urep, E));
    CASE(tt_uv_check(m, NULL, AL, &urep, E));
    CASE(tt_uv_check(m, cuv, AL, NULL, E));
    CASE(tt_uv_check(m, cuv, BA1, &urep, E));
    CASE(tt_uv_check(m, cuv, BA2, &urep, E));
    CASE(tt_uv_check(b->quads, cuv, AL, &urep, E));
    CASE(tt_uv_check(&b->empty, cuv, AL, &urep, E));

    tt_image_free(atlas);
    tt_image_free(patch);
    tt_image_free(source);
}

static void cases_hpm(const baseline *b)
{
    const tt_mesh *m = b->tris;
    tt_cluster_options co;
    tt_cluster_hierarchy *h = NULL, *hout = NULL, hand;
    tt_flatten_options fo;
    tt_flatten_report frep;
    tt_hpm_options ho, hb;
    tt_hpm_report hrep;
    tt_image v, *img = b->image;
    float uv[72];
    int fc[12], leaf;

    memset(&co, 0, sizeof co);
    OUT_CASE(hout, tt_cluster_hierarchy_free, tt_cluster_hierarchy_build(NULL, &co, AL, &hout, E));
    CASE(tt_cluster_hierarchy_build(m, &co, AL, NULL, E));
    OUT_CASE(hout, tt_cluster_hierarchy_free, tt_cluster_hierarchy_build(m, &co, BA1, &hout, E));
    OUT_CASE(hout, tt_cluster_hierarchy_free, tt_cluster_hierarchy_build(m, &co, BA2, &hout, E));
    OUT_CASE(hout, tt_cluster_hierarchy_free, tt_cluster_hierarchy_build(b->quads, &co, AL, &hout, E));
    OUT_CASE(hout, tt_cluster_hierarchy_free, tt_cluster_hierarchy_build(&b->empty, &co, AL, &hout, E));
    co.branching = 1;
    OUT_CASE(hout, tt_cluster_hierarchy_free, tt_cluster_hierarchy_build(m, &co, AL, &hout, E));
    co.branching = 65;
    OUT_CASE(hout, tt_cluster_hierarchy_free, tt_cluster_hierarchy_build(m, &co, AL, &hout, E));
    co.branching = -1;
    OUT_CASE(hout, tt_cluster_hierarchy_free, tt_cluster_hierarchy_build(m, &co, AL, &hout, E));
    memset(&co, 0x5a, sizeof co);
    OUT_CASE(hout, tt_cluster_hierarchy_free, tt_cluster_hierarchy_build(m, &co, AL, &hout, E));
    memset(&co, 0, sizeof co);

    CHECK(tt_cluster_hierarchy_build(m, &co, AL, &h, NULL) == TT_OK && h, "baseline hierarchy");
    if (h) {
        leaf = h->face_leaf[0];
        memset(&fo, 0, sizeof fo);
        CASE(tt_flatten_cluster(NULL, h, leaf, &fo, AL, uv, &frep, E));
        CASE(tt_flatten_cluster(m, NULL, leaf, &fo, AL, uv, &frep, E));
        CASE(tt_flatten_cluster(m, h, leaf, &fo, AL, NULL, &frep, E));
        CASE(tt_flatten_cluster(m, h, leaf, &fo, BA1, uv, &frep, E));
        CASE(tt_flatten_cluster(m, h, leaf, &fo, BA2, uv, &frep, E));
        CASE(tt_flatten_cluster(m, h, -1, &fo, AL, uv, &frep, E));
        CASE(tt_flatten_cluster(m, h, h->nclusters, &fo, AL, uv, &frep, E));
        CASE(tt_flatten_cluster(m, h, INT_MAX, &fo, AL, uv, &frep, E));
        CASE(tt_flatten_cluster(m, h, INT_MIN, &fo, AL, uv, &frep, E));
        CASE(tt_flatten_cluster(m, h, 0, &fo, AL, uv, &frep, E));   /* the closed top: not mappable */
        CASE(tt_flatten_cluster(b->quads, h, leaf, &fo, AL, uv, &frep, E));   /* another mesh */
        CASE(tt_flatten_cluster(&b->empty, h, leaf, &fo, AL, uv, &frep, E));
        fo.max_error = -1;
        CASE(tt_flatten_cluster(m, h, leaf, &fo, AL, uv, &frep, E));
        fo.max_error = b->nan_d;
        CASE(tt_flatten_cluster(m, h, leaf, &fo, AL, uv, &frep, E));
        fo.max_error = -b->inf_d;
        CASE(tt_flatten_cluster(m, h, leaf, &fo, AL, uv, &frep, E));
        fo.max_error = 0;
        fo.max_stretch = 0.5;
        CASE(tt_flatten_cluster(m, h, leaf, &fo, AL, uv, &frep, E));
        fo.max_stretch = b->nan_d;
        CASE(tt_flatten_cluster(m, h, leaf, &fo, AL, uv, &frep, E));
        fo.max_stretch = -1;
        CASE(tt_flatten_cluster(m, h, leaf, &fo, AL, uv, &frep, E));
        fo.max_stretch = 0;
        fo.border = 2;
        CASE(tt_flatten_cluster(m, h, leaf, &fo, AL, uv, &frep, E));
        fo.border = -1;
        CASE(tt_flatten_cluster(m, h, leaf, &fo, AL, uv, &frep, E));
        fo.border = 0;
        fo.cg_tolerance = -1;
        CASE(tt_flatten_cluster(m, h, leaf, &fo, AL, uv, &frep, E));
        fo.cg_tolerance = 1;
        CASE(tt_flatten_cluster(m, h, leaf, &fo, AL, uv, &frep, E));
        fo.cg_tolerance = b->nan_d;
        CASE(tt_flatten_cluster(m, h, leaf, &fo, AL, uv, &frep, E));
        fo.cg_tolerance = 0;
        fo.cg_max_iterations = -1;
        CASE(tt_flatten_cluster(m, h, leaf, &fo, AL, uv, &frep, E));
        fo.cg_max_iterations = INT_MIN;
        CASE(tt_flatten_cluster(m, h, leaf, &fo, AL, uv, &frep, E));
        memset(&fo, 0x5a, sizeof fo);
        CASE(tt_flatten_cluster(m, h, leaf, &fo, AL, uv, &frep, E));
        memset(&fo, 0, sizeof fo);
        hand = *h;
        hand.nclusters = -1;
        CASE(tt_flatten_cluster(m, &hand, leaf, &fo, AL, uv, &frep, E));
        tt_cluster_hierarchy_free(h);
    }

    memset(&ho, 0, sizeof ho);
    ho.match_size = 16;
    ho.rotations = 4;
    CASE(tt_hpm_map(NULL, img, &ho, AL, uv, fc, &hrep, E));
    CASE(tt_hpm_map(m, NULL, &ho, AL, uv, fc, &hrep, E));
    CASE(tt_hpm_map(m, img, &ho, AL, NULL, fc, &hrep, E));
    CASE(tt_hpm_map(m, img, &ho, BA1, uv, fc, &hrep, E));
    CASE(tt_hpm_map(m, img, &ho, BA2, uv, fc, &hrep, E));
    CASE(tt_hpm_map(b->quads, img, &ho, AL, uv, fc, &hrep, E));
    CASE(tt_hpm_map(&b->empty, img, &ho, AL, uv, fc, &hrep, E));
    v = *img;
    v.width = 0;
    CASE(tt_hpm_map(m, &v, &ho, AL, uv, fc, &hrep, E));
    v = *img;
    v.height = -32;
    CASE(tt_hpm_map(m, &v, &ho, AL, uv, fc, &hrep, E));
    v = *img;
    v.pixels = NULL;
    CASE(tt_hpm_map(m, &v, &ho, AL, uv, fc, &hrep, E));
    v = *img;
    v.width = INT_MAX;
    CASE(tt_hpm_map(m, &v, &ho, AL, uv, fc, &hrep, E));
    v = *img;
    v.kind = (tt_image_kind)8;
    CASE(tt_hpm_map(m, &v, &ho, AL, uv, fc, &hrep, E));
    v = image_view(32, 32, 0.5f);
    v.pixels[4 * 77] = b->nan_t;
    CASE(tt_hpm_map(m, &v, &ho, AL, uv, fc, &hrep, E));
    v.pixels[4 * 77] = b->inf_t;
    CASE(tt_hpm_map(m, &v, &ho, AL, uv, fc, &hrep, E));
    free(v.pixels);
#define HPM_BAD(field, value)                                                                                   \
    hb = ho;                                                                                                     \
    hb.field = value;                                                                                            \
    CASE(tt_hpm_map(m, img, &hb, AL, uv, fc, &hrep, E))
    HPM_BAD(scale, -1);
    HPM_BAD(scale, b->nan_d);
    HPM_BAD(scale, b->inf_d);
    HPM_BAD(scale, 1e-300);   /* a face far larger than the image */
    HPM_BAD(threshold, -1);
    HPM_BAD(threshold, b->nan_d);
    HPM_BAD(rotations, -1);
    HPM_BAD(rotations, 65);
    HPM_BAD(rotations, INT_MIN);
    HPM_BAD(max_turn, -1);
    HPM_BAD(max_turn, 181);
    HPM_BAD(max_turn, b->nan_d);
    HPM_BAD(max_turn, b->inf_d);
    {
        float bad_field[36];
        int k;
        for (k = 0; k < 36; k++) bad_field[k] = k % 3 == 0 ? 1.0f : 0.0f;
        bad_field[13] = b->nan_t;
        HPM_BAD(face_vectors, bad_field);
        bad_field[13] = -b->inf_t;
        HPM_BAD(face_vectors, bad_field);
    }
    HPM_BAD(band, -1);
    HPM_BAD(band, b->nan_d);
    HPM_BAD(band, b->inf_d);
    HPM_BAD(match_size, 8);
    HPM_BAD(match_size, 17);
    HPM_BAD(match_size, 1024);
    HPM_BAD(match_size, -16);
    HPM_BAD(min_footprint, -1);
    HPM_BAD(min_footprint, b->nan_d);
    HPM_BAD(min_footprint, b->inf_d);
    HPM_BAD(min_faces, -1);
    HPM_BAD(min_faces, INT_MIN);
    HPM_BAD(flags, 1u << 9);
    HPM_BAD(flags, 0x80000000u);
    HPM_BAD(branching, 1);
    HPM_BAD(branching, 65);
    HPM_BAD(branching, -3);
    HPM_BAD(max_flattening_error, -1);
    HPM_BAD(max_flattening_error, b->nan_d);
#undef HPM_BAD
}

static void cases_polycube(const baseline *b)
{
    const tt_mesh *q = b->quads, *m = b->tris;
    tt_polycube_options po, pb;
    tt_polycube *pc = NULL, *pout = NULL, hand;
    tt_polycube_report prep;
    tt_polycube_projection_report jrep;
    tt_surface_point pts[8], bp[8];
    tt_polycube_edge_options eo;
    tt_polycube_edges *edges = NULL;
    tt_polycube_map_options mo, mb;
    tt_polycube_map_report mrep;
    tt_polycube_mapping *pm = NULL, *mout = NULL, mhand;
    tt_tile_layout L, bad;
    tt_synth_options so;
    tt_tileset *plain = NULL, *upright = NULL;
    tt_image *aout = NULL;
    int ec[96];
    uint8_t types[96], bt[96];
    float *muv = NULL;

    memset(&po, 0, sizeof po);
    po.resolution = 2;
    OUT_CASE(pout, tt_polycube_free, tt_polycube_build(NULL, &po, AL, &pout, &prep, E));
    CASE(tt_polycube_build(q, &po, AL, NULL, &prep, E));
    OUT_CASE(pout, tt_polycube_free, tt_polycube_build(q, &po, BA1, &pout, &prep, E));
    OUT_CASE(pout, tt_polycube_free, tt_polycube_build(q, &po, BA2, &pout, NULL, E));
    OUT_CASE(pout, tt_polycube_free, tt_polycube_build(&b->empty, &po, AL, &pout, &prep, E));
    OUT_CASE(pout, tt_polycube_free, tt_polycube_build(b->nan_tris, &po, AL, &pout, &prep, E));
#define PC_BAD(field, value)                                                                                   \
    pb = po;                                                                                                    \
    pb.field = value;                                                                                           \
    OUT_CASE(pout, tt_polycube_free, tt_polycube_build(q, &pb, AL, &pout, &prep, E))
    PC_BAD(flags, 1u << 4);
    PC_BAD(flags, 0x80000000u);
    PC_BAD(resolution, -1);
    PC_BAD(resolution, INT_MIN);
    PC_BAD(resolution, TT_POLYCUBE_MAX_RESOLUTION + 1);
    PC_BAD(resolution, INT_MAX);
    PC_BAD(cube_size, -1);
    PC_BAD(cube_size, b->nan_d);
    PC_BAD(cube_size, b->inf_d);
    PC_BAD(cube_size, 1e-30);   /* a grid beyond the limits */
    PC_BAD(cube_size, 5e-324);
    PC_BAD(up[1], b->nan_d);
    PC_BAD(up[0], -b->inf_d);
#undef PC_BAD
    memset(&pb, 0x5a, sizeof pb);
    OUT_CASE(pout, tt_polycube_free, tt_polycube_build(q, &pb, AL, &pout, &prep, E));

    CHECK(tt_polycube_build(q, &po, AL, &pc, &prep, NULL) == TT_OK && pc, "baseline polycube");
    if (!pc) return;
    CASE(tt_polycube_edge_colors(NULL, 4, 1, 9, ec, E));
    CASE(tt_polycube_edge_colors(pc, 4, 1, 9, NULL, E));
    CASE(tt_polycube_edge_colors(pc, 0, 1, 9, ec, E));
    CASE(tt_polycube_edge_colors(pc, -1, 1, 9, ec, E));
    CASE(tt_polycube_edge_colors(pc, TT_MAX_COLORS + 1, 1, 9, ec, E));
    CASE(tt_polycube_edge_colors(pc, INT_MIN, 0, 9, ec, E));
    hand = *pc;
    hand.surface = NULL;
    CASE(tt_polycube_edge_colors(&hand, 4, 1, 9, ec, E));

    CASE(tt_polycube_project(NULL, m, AL, pts, &jrep, E));
    CASE(tt_polycube_project(pc, NULL, AL, pts, &jrep, E));
    CASE(tt_polycube_project(pc, m, AL, NULL, &jrep, E));
    CASE(tt_polycube_project(pc, m, BA1, pts, &jrep, E));
    CASE(tt_polycube_project(pc, m, BA2, pts, &jrep, E));
    CASE(tt_polycube_project(pc, &b->empty, AL, pts, &jrep, E));
    CASE(tt_polycube_project(pc, b->nan_tris, AL, pts, &jrep, E));
    CASE(tt_polycube_project(&hand, m, AL, pts, &jrep, E));   /* no surface */
    hand = *pc;
    hand.quad_cube = NULL;
    CASE(tt_polycube_project(&hand, m, AL, pts, &jrep, E));
    {
        tt_polycube_resolution_report rr;
        OUT_CASE(pout, tt_polycube_free, tt_polycube_build_auto(NULL, NULL, 0, AL, &pout, &prep, &rr, E));
        CASE(tt_polycube_build_auto(m, NULL, 0, AL, NULL, &prep, &rr, E));
        OUT_CASE(pout, tt_polycube_free, tt_polycube_build_auto(m, NULL, 0, BA1, &pout, &prep, &rr, E));
        OUT_CASE(pout, tt_polycube_free, tt_polycube_build_auto(m, NULL, 0, BA2, &pout, NULL, NULL, E));
        OUT_CASE(pout, tt_polycube_free, tt_polycube_build_auto(&b->empty, NULL, 0, AL, &pout, &prep, &rr, E));
        OUT_CASE(pout, tt_polycube_free, tt_polycube_build_auto(b->nan_tris, NULL, 0, AL, &pout, &prep, &rr, E));
        OUT_CASE(pout, tt_polycube_free, tt_polycube_build_auto(m, NULL, -1, AL, &pout, &prep, &rr, E));
        OUT_CASE(pout, tt_polycube_free, tt_polycube_build_auto(m, NULL, INT_MIN, AL, &pout, &prep, &rr, E));
        OUT_CASE(pout, tt_polycube_free,
                 tt_polycube_build_auto(m, NULL, TT_POLYCUBE_MAX_RESOLUTION + 1, AL, &pout, &prep, &rr, E));
        memset(&pb, 0x5a, sizeof pb);
        OUT_CASE(pout, tt_polycube_free, tt_polycube_build_auto(m, &pb, 0, AL, &pout, &prep, &rr, E));
        pb = po;
        pb.resolution = -1;
        OUT_CASE(pout, tt_polycube_free, tt_polycube_build_auto(m, &pb, 0, AL, &pout, &prep, &rr, E));
    }
    hand = *pc;
    hand.occupied = NULL;
    CASE(tt_polycube_project(&hand, m, AL, pts, &jrep, E));
    hand = *pc;
    hand.dims[0] = -1;
    CASE(tt_polycube_project(&hand, m, AL, pts, &jrep, E));
    hand = *pc;
    hand.h = b->nan_d;
    CASE(tt_polycube_project(&hand, m, AL, pts, &jrep, E));

    CHECK(tt_polycube_project(pc, m, AL, pts, &jrep, NULL) == TT_OK, "baseline points");
    hand = *pc;
    hand.quad_cube = NULL;   /* quads that do not match the cubes */
    memset(&eo, 0, sizeof eo);
    eo.max_quads = 6;
    OUT_CASE(edges, tt_polycube_edges_free, tt_polycube_trace_edges(NULL, m, pts, 8, &eo, AL, &edges, E));
    OUT_CASE(edges, tt_polycube_edges_free, tt_polycube_trace_edges(pc, NULL, pts, 8, &eo, AL, &edges, E));
    OUT_CASE(edges, tt_polycube_edges_free, tt_polycube_trace_edges(pc, m, NULL, 8, &eo, AL, &edges, E));
    CASE(tt_polycube_trace_edges(pc, m, pts, 8, &eo, AL, NULL, E));
    OUT_CASE(edges, tt_polycube_edges_free, tt_polycube_trace_edges(pc, m, pts, 8, &eo, BA1, &edges, E));
    OUT_CASE(edges, tt_polycube_edges_free, tt_polycube_trace_edges(pc, m, pts, 8, &eo, BA2, &edges, E));
    OUT_CASE(edges, tt_polycube_edges_free, tt_polycube_trace_edges(pc, m, pts, 7, &eo, AL, &edges, E));
    OUT_CASE(edges, tt_polycube_edges_free, tt_polycube_trace_edges(pc, m, pts, -1, &eo, AL, &edges, E));
    OUT_CASE(edges, tt_polycube_edges_free, tt_polycube_trace_edges(pc, m, pts, INT_MAX, &eo, AL, &edges, E));
    OUT_CASE(edges, tt_polycube_edges_free, tt_polycube_trace_edges(pc, &b->empty, pts, 0, &eo, AL, &edges, E));
    OUT_CASE(edges, tt_polycube_edges_free, tt_polycube_trace_edges(&hand, m, pts, 8, &eo, AL, &edges, E));
    eo.max_quads = -1;
    OUT_CASE(edges, tt_polycube_edges_free, tt_polycube_trace_edges(pc, m, pts, 8, &eo, AL, &edges, E));
    eo.max_quads = TT_POLYCUBE_EDGE_MAX_QUADS + 1;
    OUT_CASE(edges, tt_polycube_edges_free, tt_polycube_trace_edges(pc, m, pts, 8, &eo, AL, &edges, E));
    eo.max_quads = INT_MIN;
    OUT_CASE(edges, tt_polycube_edges_free, tt_polycube_trace_edges(pc, m, pts, 8, &eo, AL, &edges, E));
    eo.max_quads = 6;
    memcpy(bp, pts, sizeof bp);
    bp[2].quad = -1;
    OUT_CASE(edges, tt_polycube_edges_free, tt_polycube_trace_edges(pc, m, bp, 8, &eo, AL, &edges, E));
    bp[2].quad = pc->surface->nfaces;
    OUT_CASE(edges, tt_polycube_edges_free, tt_polycube_trace_edges(pc, m, bp, 8, &eo, AL, &edges, E));
    bp[2].quad = INT_MIN;
    OUT_CASE(edges, tt_polycube_edges_free, tt_polycube_trace_edges(pc, m, bp, 8, &eo, AL, &edges, E));
    bp[2] = pts[2];
    bp[2].s = b->nan_t;
    OUT_CASE(edges, tt_polycube_edges_free, tt_polycube_trace_edges(pc, m, bp, 8, &eo, AL, &edges, E));
    bp[2].s = -0.5f;
    OUT_CASE(edges, tt_polycube_edges_free, tt_polycube_trace_edges(pc, m, bp, 8, &eo, AL, &edges, E));
    bp[2].s = 0.5f;
    bp[2].t = b->inf_t;
    OUT_CASE(edges, tt_polycube_edges_free, tt_polycube_trace_edges(pc, m, bp, 8, &eo, AL, &edges, E));
    bp[2].t = 1.5f;
    OUT_CASE(edges, tt_polycube_edges_free, tt_polycube_trace_edges(pc, m, bp, 8, &eo, AL, &edges, E));
    memset(&eo, 0x5a, sizeof eo);
    OUT_CASE(edges, tt_polycube_edges_free, tt_polycube_trace_edges(pc, m, pts, 8, &eo, AL, &edges, E));

    memset(&mo, 0, sizeof mo);
    mo.max_quads = 6;
    mo.max_edge = HUGE_VAL;
    OUT_CASE(mout, tt_polycube_mapping_free, tt_polycube_map(NULL, m, &mo, AL, &mout, &mrep, E));
    OUT_CASE(mout, tt_polycube_mapping_free, tt_polycube_map(pc, NULL, &mo, AL, &mout, &mrep, E));
    CASE(tt_polycube_map(pc, m, &mo, AL, NULL, &mrep, E));
    OUT_CASE(mout, tt_polycube_mapping_free, tt_polycube_map(pc, m, &mo, BA1, &mout, &mrep, E));
    OUT_CASE(mout, tt_polycube_mapping_free, tt_polycube_map(pc, m, &mo, BA2, &mout, NULL, E));
    OUT_CASE(mout, tt_polycube_mapping_free, tt_polycube_map(pc, q, &mo, AL, &mout, &mrep, E));
    OUT_CASE(mout, tt_polycube_mapping_free, tt_polycube_map(pc, &b->empty, &mo, AL, &mout, &mrep, E));
    OUT_CASE(mout, tt_polycube_mapping_free, tt_polycube_map(pc, b->nan_tris, &mo, AL, &mout, &mrep, E));
    OUT_CASE(mout, tt_polycube_mapping_free, tt_polycube_map(&hand, m, &mo, AL, &mout, &mrep, E));
#define MAP_BAD(field, value)                                                                                  \
    mb = mo;                                                                                                    \
    mb.field = value;                                                                                           \
    OUT_CASE(mout, tt_polycube_mapping_free, tt_polycube_map(pc, m, &mb, AL, &mout, &mrep, E))
    MAP_BAD(max_quads, -1);
    MAP_BAD(max_quads, TT_POLYCUBE_EDGE_MAX_QUADS + 1);
    MAP_BAD(max_edge, -1);
    MAP_BAD(max_edge, -b->inf_d);
    MAP_BAD(max_edge, b->nan_d);
    MAP_BAD(max_edge, 1e-30);   /* beyond TT_POLYCUBE_MAX_TRIANGLES */
#undef MAP_BAD

    CHECK(tt_polycube_map(pc, m, &mo, AL, &pm, &mrep, NULL) == TT_OK && pm, "baseline mapping");
    CHECK(tt_polycube_edge_colors(pc, 1, 1, 9, ec, NULL) == TT_OK, "baseline polycube colours");
    memset(&L, 0, sizeof L);
    L.tile_size = 8;
    L.gutter = 2;
    CHECK(tt_assign_boundaries(pc->surface, &L, 9, ec, types, NULL) == TT_OK, "baseline polycube types");
    CASE(tt_polycube_orient_upright(NULL, types, NULL, E));
    CASE(tt_polycube_orient_upright(pc, NULL, NULL, E));
    if (pm) {
        tt_surface_point *cp = (tt_surface_point *)malloc(sizeof *cp * 3 * (size_t)pm->ntriangles);
        muv = (float *)malloc(sizeof(float) * 6 * (size_t)pm->ntriangles);
        memcpy(cp, pm->corner_points, sizeof *cp * 3 * (size_t)pm->ntriangles);
        memcpy(bt, types, sizeof bt);
        bt[7] = 2;
        CASE(tt_polycube_orient_upright(pc, bt, NULL, E));
#define UV_CASES(fn)                                                                                          \
    CASE(fn(NULL, pm, &L, types, muv, E));                                                                     \
    CASE(fn(pc, NULL, &L, types, muv, E));                                                                     \
    CASE(fn(pc, pm, NULL, types, muv, E));                                                                     \
    CASE(fn(pc, pm, &L, NULL, muv, E));                                                                        \
    CASE(fn(pc, pm, &L, types, NULL, E));                                                                      \
    bad = L;                                                                                                    \
    bad.tile_size = 1;                                                                                          \
    CASE(fn(pc, pm, &bad, types, muv, E));                                                                     \
    bad = L;                                                                                                    \
    bad.colors = 45;                                                                                            \
    bad.tile_size = 128;                                                                                        \
    CASE(fn(pc, pm, &bad, types, muv, E));                                                                     \
    CASE(fn(pc, pm, &L, bt, muv, E));                                                                          \
    CASE(fn(&hand, pm, &L, types, muv, E));                                                                    \
    mhand = *pm;                                                                                                \
    mhand.corner_points = cp;                                                                                   \
    cp[4].quad = -1;                                                                                            \
    CASE(fn(pc, &mhand, &L, types, muv, E));                                                                   \
    cp[4].quad = pc->surface->nfaces;                                                                           \
    CASE(fn(pc, &mhand, &L, types, muv, E));                                                                   \
    cp[4] = pm->corner_points[4];                                                                               \
    cp[4].s = b->nan_t;                                                                                         \
    CASE(fn(pc, &mhand, &L, types, muv, E));                                                                   \
    cp[4].s = 0.5f;                                                                                             \
    cp[4].t = -b->inf_t;                                                                                        \
    CASE(fn(pc, &mhand, &L, types, muv, E));                                                                   \
    cp[4].t = 7.0f;                                                                                             \
    CASE(fn(pc, &mhand, &L, types, muv, E));                                                                   \
    cp[4] = pm->corner_points[4];                                                                               \
    mhand.ntriangles = -1;                                                                                      \
    CASE(fn(pc, &mhand, &L, types, muv, E));                                                                   \
    mhand.ntriangles = pm->ntriangles;                                                                          \
    mhand.corner_points = NULL;                                                                                 \
    CASE(fn(pc, &mhand, &L, types, muv, E))
        hand = *pc;
        hand.surface = NULL;
        UV_CASES(tt_polycube_mapping_uvs);
        UV_CASES(tt_polycube_mapping_uvs_upright);
#undef UV_CASES
        free(cp);
    }

    memset(&so, 0, sizeof so);
    so.layout = L;
    CHECK(tt_synthesize_tiles(b->image, &so, AL, &plain, NULL) == TT_OK && plain, "baseline plain tiles");
    if (plain) {
        so.upright = 1;
        so.edge_windows = plain->edge_windows;
        CHECK(tt_synthesize_tiles(b->image, &so, AL, &upright, NULL) == TT_OK && upright, "baseline upright tiles");
    }
    if (plain && upright) {
        tt_tileset other = *upright, other2, right = *upright, left = *upright;
        const tt_tileset *four[TT_TILESET_KINDS];
        tt_rect moved[TT_MAX_COLORS];
        /* The same texels serve the upright sets with a plain side: only
           their kind is checked before the texels are copied. */
        right.plain_sides = 1 << 1;
        left.plain_sides = 1 << 3;
#define ATLAS_CASE(a, b, level, al) \
        do { four[0] = (a); four[1] = (b); four[2] = &right; four[3] = &left; \
             OUT_CASE(aout, tt_image_free, tt_upright_atlas(four, level, NULL, al, &aout, E)); } while (0)
        ATLAS_CASE(NULL, upright, 0, AL);
        ATLAS_CASE(plain, NULL, 0, AL);
        OUT_CASE(aout, tt_image_free, tt_upright_atlas(NULL, 0, NULL, AL, &aout, E));
        four[0] = plain;
        four[1] = upright;
        four[2] = &right;
        four[3] = &left;
        CASE(tt_upright_atlas(four, 0, NULL, AL, NULL, E));
        four[3] = &right;   /* both with the right side plain */
        OUT_CASE(aout, tt_image_free, tt_upright_atlas(four, 0, NULL, AL, &aout, E));
        four[2] = four[3] = upright;   /* sets 2 and 3 need plain_sides */
        OUT_CASE(aout, tt_image_free, tt_upright_atlas(four, 0, NULL, AL, &aout, E));
        four[3] = NULL;
        OUT_CASE(aout, tt_image_free, tt_upright_atlas(four, 0, NULL, AL, &aout, E));
        ATLAS_CASE(plain, upright, 0, BA1);
        ATLAS_CASE(plain, upright, 0, BA2);
        ATLAS_CASE(plain, upright, -1, AL);
        ATLAS_CASE(plain, upright, plain->nlevels, AL);
        ATLAS_CASE(plain, upright, TT_MAX_MIP_LEVELS, AL);
        ATLAS_CASE(plain, upright, INT_MAX, AL);
        ATLAS_CASE(plain, upright, INT_MIN, AL);
        ATLAS_CASE(upright, plain, 0, AL);
        ATLAS_CASE(plain, plain, 0, AL);
        other.nlevels = -1;
        ATLAS_CASE(plain, &other, 0, AL);
        other.nlevels = TT_MAX_MIP_LEVELS + 5;   /* every set claims levels beyond the array */
        other2 = *plain;
        other2.nlevels = TT_MAX_MIP_LEVELS + 5;
        right.nlevels = left.nlevels = TT_MAX_MIP_LEVELS + 5;
        ATLAS_CASE(&other2, &other, TT_MAX_MIP_LEVELS + 1, AL);
        right.nlevels = left.nlevels = upright->nlevels;
        other = *upright;
        other.layout.colors = 2;
        ATLAS_CASE(plain, &other, 0, AL);
        other = *upright;
        other.levels[0].kind = TT_IMAGE_NORMAL;
        ATLAS_CASE(plain, &other, 0, AL);
        other = *upright;
        other.levels[0].pixels = NULL;
        ATLAS_CASE(plain, &other, 0, AL);
        other = *upright;
        other.levels[0].width = 3;
        ATLAS_CASE(plain, &other, 0, AL);
        other = *upright;
        other.plain_sides = 1 << 1;
        ATLAS_CASE(plain, &other, 0, AL);
        other = *upright;
        memcpy(moved, upright->edge_windows, sizeof(tt_rect) * (size_t)upright->layout.colors);
        moved[0].y += 1;
        other.edge_windows = moved;
        ATLAS_CASE(plain, &other, 0, AL);
#undef ATLAS_CASE
    }
    tt_tileset_free(plain);
    tt_tileset_free(upright);
    free(muv);
    tt_polycube_mapping_free(pm);
    tt_polycube_free(pc);
}

/* ------------------------------------------------------------------------ */
/* The run                                                                  */
/* ------------------------------------------------------------------------ */

static void test_contract(void)
{
    baseline b;
    tmesh grid = {0};
    tt_mesh_desc d;
    int tri_idx[36], f, c, i, missing = 0;
    const char *env = getenv("TT_CONTRACT_FORK");
    char names[400];

    g_fork = env && *env && *env != '0';
    memset(&b, 0, sizeof b);
    b.nan_d = internal_not_a_number();
    b.inf_d = (double)internal_infinity();
    b.nan_t = (float)b.nan_d;
    b.inf_t = internal_infinity();
    memset(&d, 0, sizeof d);
    d.positions = k_cube_pos;
    d.nverts = 8;
    d.indices = k_cube_idx;
    d.nfaces = 6;
    d.fixed_face_size = 4;
    CHECK(tt_mesh_build(&d, NULL, &b.quads, NULL) == TT_OK, "baseline quad cube");
    for (f = 0; f < 6; f++)
        for (c = 0; c < 3; c++) {
            tri_idx[6 * f + c] = k_cube_idx[4 * f + c];
            tri_idx[6 * f + 3 + c] = k_cube_idx[4 * f + (c + 2) % 4];
        }
    d.indices = tri_idx;
    d.nfaces = 12;
    d.fixed_face_size = 3;
    CHECK(tt_mesh_build(&d, NULL, &b.tris, NULL) == TT_OK, "baseline triangle cube");
    memcpy(b.nan_pos, k_cube_pos, sizeof b.nan_pos);
    d.positions = b.nan_pos;
    d.flags = TT_MESH_BORROW_POSITIONS;
    CHECK(tt_mesh_build(&d, NULL, &b.nan_tris, NULL) == TT_OK, "baseline borrowed triangle cube");
    b.nan_pos[3 * 6 + 1] = b.nan_t;   /* after the build: the mesh sees it */
    make_grid(&grid, 2, 2);
    CHECK(build(&grid, 0, &b.grid, NULL) == TT_OK, "baseline grid");
    tm_free(&grid);
    make_value_noise(&b.image, 32, 32, 7);
    if (!b.quads || !b.tris || !b.nan_tris || !b.grid || !b.image) return;
    b.empty = *b.tris;
    b.empty.nfaces = b.empty.ncorners = b.empty.nverts = 0;

    cases_mesh(&b);
    cases_image(&b);
    cases_numerics(&b);
    cases_fft(&b);
    cases_tiled(&b);
    cases_lapped(&b);
    cases_hpm(&b);
    cases_polycube(&b);

    for (i = 0; i < NFUNCTIONS; i++)
        if (g_violations[i]) printf("    contract: %s: %d of %d cases broke it\n", k_functions[i], g_violations[i], g_cases[i]);
    names[0] = '\0';
    for (i = 0; i < NFUNCTIONS; i++)
        if (!g_cases[i]) {
            size_t n = strlen(names);
            missing++;
            snprintf(names + n, sizeof names - n, " %s", k_functions[i]);
        }
    printf("    contract: %d cases over %d functions, %d violations%s\n", g_total_cases, NFUNCTIONS - missing,
           g_total_violations, g_fork ? " (each case in a child process)" : "");
    CHECK(g_total_violations == 0 && g_unknown == 0, "0 violations over %d cases: %d (%d cases name no listed function)",
          g_total_cases, g_total_violations, g_unknown);
    CHECK(missing == 0, "every one of the %d functions has cases: %d have none:%s", NFUNCTIONS, missing, names);

    tt_image_free(b.image);
    tt_mesh_free(b.grid);
    tt_mesh_free(b.nan_tris);
    tt_mesh_free(b.tris);
    tt_mesh_free(b.quads);
}

void run_contract_tests(void) { RUN(test_contract); }
