/* bench_build.c - tt_mesh_build on three ~1M-face meshes beside a yardstick.

   The meshes are bench_build_meshes.h's (a grid-ordered 1M-quad torus, the
   same with shuffled vertex ids, a welded 1M-triangle STL soup in file
   order); the yardstick is bench_radix_pairing.h (twins paired by a radix
   sort of edge keys, nothing validated). tt_mesh_build runs strict, positions
   copied, the default allocator. Prints `name value unit` lines only:
       build_<mesh>_<cold|warm>              tiledtex, ms
       radix_<mesh>_<cold|warm>              the yardstick, ms
       build_<mesh>_<cold|warm>_over_radix   their ratio in this run, x
   cold = every big block a fresh mapping (page faults paid in the run), warm
   = memory recycled from the previous run (no page faults). Each figure is the
   median of RUNS runs after a warm-up, tiledtex and the yardstick taking turns
   so that both see the same machine (it is shared and noisy). Before timing,
   the twins of both are compared: on these closed meshes they must agree.

       build/bench_build [grid|shuffled|soup ...]   (default: all three)

   The CGAL Surface_mesh peer is bench_build_cgal.cpp (same meshes). */
#define _POSIX_C_SOURCE 199309L
#define TILEDTEX_IMPLEMENTATION
#include "tiledtex.h"
#include "bench_build_meshes.h"
#include "bench_radix_pairing.h"

#define RUNS 5

static tt_mesh_desc desc_of(const bench_mesh *m)
{
    tt_mesh_desc d;
    memset(&d, 0, sizeof d);
    d.positions = m->pos;
    d.nverts = m->nverts;
    d.indices = m->idx;
    d.nfaces = m->nfaces;
    d.fixed_face_size = m->face_size;
    return d;
}

static double time_ours(const bench_mesh *m)
{
    tt_mesh_desc d = desc_of(m);
    tt_mesh *mesh = NULL;
    tt_error err;
    double t0 = bench_now_ms(), t1;
    tt_result r = tt_mesh_build(&d, NULL, &mesh, &err);
    t1 = bench_now_ms();
    if (r != TT_OK) {
        fprintf(stderr, "bench_build: %s: %s\n", m->name, err.message);
        exit(1);
    }
    tt_mesh_free(mesh);
    return t1 - t0;
}

static double time_radix(const bench_mesh *m)
{
    double t0 = bench_now_ms(), t1;
    int *twin = bench_radix_pairing(m->idx, m->nfaces, m->face_size, m->nverts);
    t1 = bench_now_ms();
    if (!twin) {
        fprintf(stderr, "bench_build: the yardstick failed on %s\n", m->name);
        exit(1);
    }
    free(twin);
    return t1 - t0;
}

static void check_same_twins(const bench_mesh *m)
{
    tt_mesh_desc d = desc_of(m);
    tt_mesh *mesh = NULL;
    tt_error err;
    int *twin = bench_radix_pairing(m->idx, m->nfaces, m->face_size, m->nverts), c, bad = 0;
    if (tt_mesh_build(&d, NULL, &mesh, &err) != TT_OK || !twin) {
        fprintf(stderr, "bench_build: %s does not build: %s\n", m->name, err.message);
        exit(1);
    }
    for (c = 0; c < mesh->ncorners; c++) bad += mesh->twin[c] != twin[c] || twin[c] < 0;
    if (bad) {
        fprintf(stderr, "bench_build: %s: %d twins differ from the yardstick's\n", m->name, bad);
        exit(1);
    }
    fprintf(stderr, "bench_build: %s: %d vertices, %d faces of %d, twins agree\n", m->name, m->nverts, m->nfaces,
            m->face_size);
    tt_mesh_free(mesh);
    free(twin);
}

static void report(const char *name, const char *mesh, const char *state, const char *suffix, double value,
                   const char *unit)
{
    printf("%s_%s_%s%s %.*f %s\n", name, mesh, state, suffix, value < 10.0 ? 2 : 1, value, unit);
    fflush(stdout);
}

static void bench_one(const bench_mesh *m, const char *state)
{
    double ours[RUNS], radix[RUNS], o, r;
    int i;
    time_ours(m);
    time_radix(m);
    for (i = 0; i < RUNS; i++) {
        ours[i] = time_ours(m);
        radix[i] = time_radix(m);
    }
    o = bench_median(ours, RUNS);
    r = bench_median(radix, RUNS);
    report("build", m->name, state, "", o, "ms");
    report("radix", m->name, state, "", r, "ms");
    report("build", m->name, state, "_over_radix", o / r, "x");
}

static int wanted(int argc, char **argv, const char *name)
{
    int i;
    if (argc <= 1) return 1;
    for (i = 1; i < argc; i++)
        if (strcmp(argv[i], name) == 0) return 1;
    return 0;
}

int main(int argc, char **argv)
{
    bench_mesh meshes[BENCH_NMESHES];
    int k;
    bench_malloc_cold();
    bench_make_meshes(meshes);
    for (k = 0; k < BENCH_NMESHES; k++) {
        if (!wanted(argc, argv, meshes[k].name)) continue;
        check_same_twins(&meshes[k]);
        bench_malloc_cold();
        bench_one(&meshes[k], "cold");
        bench_malloc_warm();
        bench_one(&meshes[k], "warm");
        bench_malloc_cold();
    }
    for (k = 0; k < BENCH_NMESHES; k++) bench_mesh_free(&meshes[k]);
    return 0;
}
