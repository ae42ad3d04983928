/* tests/test_common.h - what the unit tests of tiledtex.h share: the check
   framework, the counting and failing allocators, the allocation-failure
   sweep, small helpers and the hand-made meshes and images that more than
   one section file uses. Defined in tests/test_common.c, which is also the
   one file that compiles the implementation (TILEDTEX_IMPLEMENTATION) and
   holds main(). Plain C99, deterministic, reads no file. */
#ifndef TEST_COMMON_H
#define TEST_COMMON_H

#include <stddef.h>

#include "tiledtex.h"

/* ------------------------------------------------------------------------ */
/* Framework                                                                */
/* ------------------------------------------------------------------------ */

extern int g_passed, g_failed;
extern const char *g_test;   /* the test RUN is running, for the reports */

void check_report(int ok, const char *file, int line, const char *what, const char *fmt, ...);
void check_detail(const char *file, int line, const char *fmt, ...);

/* CHECK(cond, fmt, ...): fmt says what was expected and what came out. */
#define CHECK(cond, ...) check_report((cond) ? 1 : 0, __FILE__, __LINE__, #cond, __VA_ARGS__)
/* DETAIL(fmt, ...): the first offending case of a loop whose CHECK counts
   the offenders; printed, not counted. */
#define DETAIL(...) check_detail(__FILE__, __LINE__, __VA_ARGS__)
#define RUN(fn) do { g_test = #fn; fn(); } while (0)

/* One function per section file, RUNning its tests in the header's order;
   main calls them in section order. */
void run_common_tests(void);     /* tests/test_1_common.c */
void run_mesh_tests(void);       /* tests/test_2_mesh.c */
void run_image_tests(void);      /* tests/test_3_image.c */
void run_numerics_tests(void);   /* tests/test_4_numerics.c */
void run_fft_tests(void);        /* tests/test_4_fft.c */
void run_raster_tests(void);     /* tests/test_5_raster.c */
void run_tiled_tests(void);      /* tests/test_6_tiled.c */
void run_tiled_synthesis_tests(void); /* tests/test_6_tiled_synthesis.c */
void run_lapped_tests(void);     /* tests/test_7_lapped.c */
void run_hpm_tests(void);        /* tests/test_8_hpm.c */
void run_polycube_tests(void);   /* tests/test_9_polycube.c */
void run_contract_tests(void);   /* tests/test_contract.c: THE API CONTRACT, hostile arguments */

/* ------------------------------------------------------------------------ */
/* Counting and failing allocators                                          */
/* ------------------------------------------------------------------------ */

typedef struct counter {
    long live;          /* allocations not yet freed */
    long calls;         /* alloc calls so far */
    long fail_at;       /* fail the alloc call with this index (0-based); -1 = never */
    long failures;      /* how many calls were failed */
    long bad_frees;     /* frees of pointers we did not hand out */
    size_t live_bytes;
} counter;

/* Resets *c and returns an allocator counting into it that fails its
   allocation number fail_at (0-based; -1: never). */
tt_allocator make_allocator(counter *c, long fail_at);

/* ------------------------------------------------------------------------ */
/* Allocation-failure sweep                                                 */
/* ------------------------------------------------------------------------ */

/* The call a sweep repeats: run the function under test with `allocator`
   and `error` (pass it on as the function's tt_error), free whatever it
   made, and return its result (or TT_RESULT_MAX_ENUM when it broke its
   contract, e.g. an output not reset on failure). */
typedef tt_result (*oom_call)(void *ctx, const tt_allocator *allocator, tt_error *error);

/* The allocator and counter every OOM sweep uses: the call passes it as the
   allocator parameter of the function under test. Objects built through it
   before a sweep stay live: a run must leave `live` where it found it.
   oom_reset() zeroes the counter. */
extern counter g_oom_counter;
extern tt_allocator g_oom_allocator;
void oom_reset(void);

/* Run `call` with allocation k failing for k = 0, 1, ... until a run no
   longer reaches allocation k. Four CHECKs: the last result is
   expected_final, every run with a failed allocation returned
   TT_ERROR_OUT_OF_MEMORY and filled the tt_error it was given (that
   result and a sentence: the error is pre-filled with garbage before each
   run), no run leaked or freed a foreign pointer, and there was at least
   one allocation. */
void oom_sweep(const char *what, oom_call call, void *ctx, tt_result expected_final);

/* The same for the private helpers that take no tt_error: the error check
   is skipped. */
void oom_sweep_internal(const char *what, oom_call call, void *ctx, tt_result expected_final);

/* ------------------------------------------------------------------------ */
/* Small helpers                                                            */
/* ------------------------------------------------------------------------ */

int near(double a, double b, double tol);   /* |a - b| <= tol */

/* A deterministic LCG for test data (one global state). */
void lcg_seed(unsigned long long s);
unsigned lcg_next(void);
int lcg_below(int n);     /* in [0, n) */
double lcg_unit(void);    /* in [0, 1) */
/* values[i] for i < n in one of the orders that defeat naive selection
   pivots (pattern 0..5: random, many repeats, sorted, reversed, all equal,
   an organ pipe); draws from the LCG. */
void hostile_order(double *values, int n, int pattern);

/* Does `msg` contain the decimal number n as a whole token? */
int msg_has_number(const char *msg, int n);

/* ------------------------------------------------------------------------ */
/* Hand-made meshes                                                         */
/* ------------------------------------------------------------------------ */

/* A growable polygon soup (malloc); zero-initialise, free with tm_free. */
typedef struct tmesh {
    float *pos;
    int nv, cap_v;
    int *idx;
    int nc, cap_c;
    int *sizes;
    int nf, cap_f;
} tmesh;

void tm_free(tmesh *m);
int tm_vert(tmesh *m, double x, double y, double z);   /* returns the new vertex */
void tm_face(tmesh *m, int n, const int *v);
void tm_tri(tmesh *m, int a, int b, int c);
void tm_quad(tmesh *m, int a, int b, int c, int d);
tt_mesh_desc tm_desc(const tmesh *m);   /* borrows m's arrays; flags 0 */

/* Regular tetrahedron-ish: 4 vertices, 4 triangles, outward CCW. */
void make_tetra(tmesh *m, double ox);
/* nu x nv quads on a torus (nu, nv >= 3). Quad (i,j) is face j*nu + i. */
void make_torus(tmesh *m, int nu, int nv, double R, double r);
/* Open nx x ny grid of unit quads in the plane z = 0. */
void make_grid(tmesh *m, int nx, int ny);

/* tt_mesh_build of m with `flags` and the default allocator (NULL). */
tt_result build(const tmesh *m, unsigned flags, tt_mesh **out, tt_error *err);

/* ------------------------------------------------------------------------ */
/* Images                                                                   */
/* ------------------------------------------------------------------------ */

/* The RGBA texel (x, y) of im. */
float *px(const tt_image *im, int x, int y);

/* Photograph-like: value noise at 6, 13 and 29 texel scales plus grain. A row
   of it looks different from its own mirror image, as rows of real textures
   do, so tiles that do not belong together show (the seam test shuffles).
   Creates *im (w x h, opaque, linear values used as they are) with the
   default allocator (free it with tt_image_free; *im is NULL, and a CHECK
   fails, if it cannot be created); reseeds the LCG. */
void make_value_noise(tt_image **im, int w, int h, unsigned seed);

/* Executors for the parallel paths: each runs every task once, so results
   must equal a serial run's bit for bit. g_reverse_executor runs them on
   this thread in reverse order (a task reading another's output, or a
   result that depends on order, shows); g_thread_executor on two POSIX
   threads taking indices as they come (a data race shows under TSan, and
   as differences elsewhere). */
extern const tt_executor g_reverse_executor;
extern const tt_executor g_thread_executor;

/* sets[1..3] (tt_tileset_kind's upright, right side plain, left side
   plain) made from `photo` with `so` on the edge windows of sets[0], the
   plain set; NULL where one fails. */
void make_upright_sets(const tt_image *photo, tt_synth_options so, tt_tileset *sets[TT_TILESET_KINDS]);

/* ------------------------------------------------------------------------ */
/* Internal functions of the implementation the tests call                  */
/* ------------------------------------------------------------------------ */

/* The implementation's static tt__<name> functions, reachable only from the
   file that compiles it; internal_<name> forwards to tt__<name>. */
void internal_free(const tt_allocator *allocator, void *ptr);
float internal_infinity(void);
double internal_not_a_number(void);
double internal_orient2(double ax, double ay, double bx, double by, double cx, double cy);
/* tt__weighted_percentiles of (values[i], weights[i]) at one fraction. */
double internal_weighted_percentile(const double *values, const double *weights, int count, double fraction);
/* tt__median (reorders values). */
double internal_median(double *values, int count);
double internal_point_segment_distance(double px_, double py_, double ax, double ay, double bx, double by);
int internal_point_on_segment(double px_, double py_, double ax, double ay, double bx, double by);
int internal_segments_near(double ax, double ay, double bx, double by, double cx, double cy, double dx, double dy,
                           double eps);
int internal_segment_meets_polygon(const float a[2], const float b[2], const float *xy, int count);
tt_result internal_hull_convex(const tt_image *patch, const tt_allocator *allocator, double **out_x, double **out_y,
                               int *out_n);
tt_result internal_patch_hull(const tt_image *patch, int max_vertices, const tt_allocator *allocator, float **out_xy,
                              int *out_count);

/* Section 9's voxeliser (marks boxes of side h at origin + h * (i + 1/2, ...)
   that the mesh meets under the tie rule; returns the zero-area triangles
   skipped), its disc predicate and its critical-configuration classifier
   (0 none, 1 a checkerboard, 2 an antipodal pair, 3 its complement) on a mask of 8 cubes. */
int internal_polycube_voxelize(const tt_mesh *mesh, const double origin[3], double h, const int dims[3],
                               unsigned char *mark);
int internal_polycube_mask_is_disc(int mask);
/* Section 9's relaxation and untangling of points on S (Chang and Lin Sec. 4; NULL
   allocator; returns the moves, -1 out of memory), the kernel centre of a
   star (ring: two points per triangle, its far edge counter-clockwise; 0
   when empty) and the untangling energy of a star of n <= 64 triangles. */
/* The incomplete Cholesky factor of A (columns increasing, no repeats)
   checked against A: made as tt__ic0_factor returns, worst |(L L^T)_ij -
   A_ij| / |A_ii| over A's lower pattern. */
typedef struct ic0_check_result {
    int made;
    double worst;
} ic0_check_result;
ic0_check_result internal_ic0_check(const tt_sparse_matrix *A);
int internal_polycube_relax(const tt_polycube *polycube, const tt_mesh *model, tt_surface_point *points);
/* Traces the edges once, then re-seats the vertices with a failed one ncalls times with one memory (the
   later calls see the edges as first traced), flagging those moved in moved[] (cleared by the caller);
   before the last call, vertex `nudged` (-1: none) moves a hair. The path-search steps of each call go to
   spent[] (may be NULL); returns the moves of all calls, -1 when out of memory, -2 tracing. */
int internal_polycube_reseat_calls(const tt_polycube *polycube, const tt_mesh *model, tt_surface_point *points,
                                   unsigned char *moved, const tt_allocator *allocator, int ncalls, int nudged,
                                   double *spent);
int internal_relax_kernel_centre(const double (*ring)[2], int ntriangles, double centre[2]);
/* density > 0: the smoothing energy (delta2 unused); hessian (xx, xy, yy) may be NULL. */
double internal_untangle_energy(int n, const double (*ring)[2][2], const double (*shape)[2][2], const double x[2],
                                double delta2, double density, double gradient[2], double hessian[3], int *folded);
/* Where a star's centre descends from x (tt__untangle_descend). */
void internal_untangle_descend(int n, const double (*ring)[2][2], const double (*shape)[2][2], const double x[2],
                               double reach, double delta2, double density, int strict, double kept[2]);
/* Section 2's area centroid of the ring around a split face of q
   (tt__remesh_ring_centroid): quads first .. first + count - 1, ring 0 its
   edge points, 1 its corners. */
void internal_remesh_ring_centroid(const tt_mesh *q, int first, int count, int ring, double out[3]);
/* Section 2's pairing field: up (3 per vertex, unit tangents) and weight
   (1 per vertex) for the first n vertices of pos; up NULL for none. */
typedef struct internal_pair_field {
    const double *up, *weight;
    int n;
} internal_pair_field;
/* Section 2's cut of polygon poly (n corners of pos, n even, at most 32)
   into the cheapest quads (tt__remesh_quadrangulate_polygon), with field
   (NULL for none): n / 2 - 1 quads to out, their summed cost to *cost; 0
   when none fits joined and needy (n * n and n flags). */
int internal_remesh_quadrangulate_polygon(const float *pos, const internal_pair_field *field, const int *poly, int n,
                                          const unsigned char *joined, const unsigned char *needy, double *cost,
                                          int *out);
/* A quad's cost in that cut (tt__remesh_quad_cost), with field (NULL for none). */
double internal_remesh_quad_cost(const float *pos, const internal_pair_field *field, const int quad[4]);
/* The position and weights of a split vertex interpolating three of mesh's vertices (tt__split_vertex_data). */
/* tt_polycube_map's step 7 on `mapping` (in place): merges moving the
   texture up to `tolerance` quads, bounded by the shapes of their stars
   when keep_shape (0: the control, bounded by the tolerance only);
   returns the triangles removed. */
int internal_mapping_merge(tt_polycube_mapping *mapping, const tt_mesh *mesh, double tolerance, int keep_shape);
void internal_split_vertex_data(const tt_mesh *mesh, const int source[3], const double weight[3], float position[3],
                                float weight_out[3]);
/* Smooths the points (tt__polycube_smooth); returns its moves, -1 when out of memory; *held as it says. */
int internal_polycube_smooth(const tt_polycube *polycube, const tt_mesh *model, tt_surface_point *points,
                             const tt_executor *executor, const tt_allocator *allocator, int *held);
int internal_polycube_mask_critical(int mask);
/* Section 4's multigrid-preconditioned conjugate gradients: the hierarchy
   of A, two solves (b and x interleaved: b[2i + c]) from the x given, the
   hierarchy freed; *levels and *iterations say how it went. */
tt_result internal_amg_solve2(const tt_sparse_matrix *A, const double *b, double *x, double tolerance,
                              int max_iterations, const tt_allocator *allocator, int *levels, int *iterations);
/* Section 7's alignment of one paste (Praun et al. Sec. 3.4) as the paste
   loop solves it: the faces listed (a disc of triangles), the field's
   vectors, the seed point (a face and barycentric weights) held on anchor,
   from uv (2 per mesh vertex, the listed faces' vertices read and written);
   *unknowns and *steps give the solve's size and its conjugate gradient
   steps. */
tt_result internal_lapped_align(const tt_mesh *mesh, const float *field, const int *faces, int nfaces, int seed_face,
                                const double seed_weight[3], const float anchor[2], double *uv, int *unknowns,
                                int *steps);
/* Section 8's relaxation classes (tt__hpm_relax_classes) of the sorted
   vertices verts[0 .. n) of mesh, with vmark as the per-vertex marks;
   returns the number of classes, verts sorted by (class, vertex) and
   class_end[k] the end of class k. */
int internal_hpm_relax_classes(const tt_mesh *mesh, int *vmark, int *verts, int n, int *class_end);
/* Section 4's direct masked sums (tt__xcorr_direct) over every offset of a
   texture (`channels` float planes h x w), the terms' texels (x, y),
   weights and values (channels per term): rows 0 .. h - 1, each over the
   offsets lo .. hi (wrapping), none excluded. The smallest E's offset (y w
   + x, the first in row-major order on a tie) and E; returns the
   non-finite flag. */
uint64_t internal_xcorr_direct(int w, int h, int channels, const float *texture, int count, const int *x,
                               const int *y, const double *weight, const double *values, int lo, int hi, int *best,
                               double *best_e);

#endif /* TEST_COMMON_H */
