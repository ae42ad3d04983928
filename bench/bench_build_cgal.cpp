// bench_build_cgal.cpp - the peer of bench_build.c: CGAL's Surface_mesh built
// from the same three meshes (bench_build_meshes.h) the usual way: reserve,
// add_vertex for every point, add_face for every face (CGAL::Euler::add_face
// finds the twins through the halfedges around each vertex and rejects a face
// that would make the mesh non-manifold: it validates topology, not geometry).
// Kernel: Exact_predicates_inexact_constructions_kernel (points of 3 doubles).
// Prints, `name value unit`:
//     cgal_<mesh>_<cold|warm>              CGAL, ms
//     build_<mesh>_<cold|warm>             tt_mesh_build in this same run, ms
//     cgal_<mesh>_<cold|warm>_over_build   their ratio (>1: tiledtex is faster)
// Medians of 5 runs after a warm-up, the two builders taking turns; cold and
// warm as in bench_build.c (glibc's allocator pinned either way). The
// destructors are not timed, as tt_mesh_free is not.
// Needs CGAL 5 (Debian: libcgal-dev, header-only here); single-threaded:
//     c++ -O2 -DNDEBUG -I. -Ibench bench/bench_build_cgal.cpp -o build/bench_build_cgal -lgmp
#define TILEDTEX_IMPLEMENTATION
#include "tiledtex.h"
#include "bench_build_meshes.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/version.h>

#include <cstdio>
#include <cstring>

typedef CGAL::Exact_predicates_inexact_constructions_kernel Kernel;
typedef CGAL::Surface_mesh<Kernel::Point_3> Mesh;

static const int RUNS = 5;

static double time_cgal(const bench_mesh *m)
{
    double t0 = bench_now_ms(), t1;
    Mesh *sm = new Mesh();
    int rejected = 0;
    size_t nhalf = (size_t)m->nfaces * (size_t)m->face_size;
    sm->reserve((Mesh::size_type)m->nverts, (Mesh::size_type)(nhalf / 2), (Mesh::size_type)m->nfaces);
    for (int v = 0; v < m->nverts; v++) {
        const float *p = m->pos + 3 * (size_t)v;
        sm->add_vertex(Kernel::Point_3(p[0], p[1], p[2]));
    }
    for (int f = 0; f < m->nfaces; f++) {
        const int *q = m->idx + (size_t)m->face_size * f;
        Mesh::Face_index added;
        if (m->face_size == 3)
            added = sm->add_face(Mesh::Vertex_index(q[0]), Mesh::Vertex_index(q[1]), Mesh::Vertex_index(q[2]));
        else
            added = sm->add_face(Mesh::Vertex_index(q[0]), Mesh::Vertex_index(q[1]), Mesh::Vertex_index(q[2]),
                                 Mesh::Vertex_index(q[3]));
        rejected += added == Mesh::null_face();
    }
    t1 = bench_now_ms();
    if (rejected || sm->number_of_halfedges() != nhalf) {
        std::fprintf(stderr, "bench_build_cgal: %s: %d faces rejected, %lu halfedges\n", m->name, rejected,
                     (unsigned long)sm->number_of_halfedges());
        std::exit(1);
    }
    delete sm;
    return t1 - t0;
}

static double time_ours(const bench_mesh *m)
{
    tt_mesh_desc d;
    std::memset(&d, 0, sizeof d);
    d.positions = m->pos;
    d.nverts = m->nverts;
    d.indices = m->idx;
    d.nfaces = m->nfaces;
    d.fixed_face_size = m->face_size;
    tt_mesh *mesh = NULL;
    tt_error err;
    double t0 = bench_now_ms(), t1;
    tt_result r = tt_mesh_build(&d, NULL, &mesh, &err);
    t1 = bench_now_ms();
    if (r != TT_OK) {
        std::fprintf(stderr, "bench_build_cgal: %s: %s\n", m->name, err.message);
        std::exit(1);
    }
    tt_mesh_free(mesh);
    return t1 - t0;
}

static void report(const char *name, const bench_mesh *m, const char *state, const char *suffix, double value,
                   const char *unit)
{
    std::printf("%s_%s_%s%s %.*f %s\n", name, m->name, state, suffix, value < 10.0 ? 2 : 1, value, unit);
    std::fflush(stdout);
}

static void bench_one(const bench_mesh *m, const char *state)
{
    double cgal[RUNS], ours[RUNS];
    time_cgal(m);
    time_ours(m);
    for (int i = 0; i < RUNS; i++) {
        cgal[i] = time_cgal(m);
        ours[i] = time_ours(m);
    }
    double c = bench_median(cgal, RUNS), o = bench_median(ours, RUNS);
    report("cgal", m, state, "", c, "ms");
    report("build", m, state, "", o, "ms");
    report("cgal", m, state, "_over_build", c / o, "x");
}

int main(int argc, char **argv)
{
    bench_mesh meshes[BENCH_NMESHES];
    bench_malloc_cold();
    bench_make_meshes(meshes);
    std::fprintf(stderr, "bench_build_cgal: CGAL %s\n", CGAL_VERSION_STR);
    for (int k = 0; k < BENCH_NMESHES; k++) {
        bool wanted = argc <= 1;
        for (int i = 1; i < argc; i++) wanted = wanted || std::strcmp(argv[i], meshes[k].name) == 0;
        if (!wanted) continue;
        bench_malloc_cold();
        bench_one(&meshes[k], "cold");
        bench_malloc_warm();
        bench_one(&meshes[k], "warm");
        bench_malloc_cold();
    }
    for (int k = 0; k < BENCH_NMESHES; k++) bench_mesh_free(&meshes[k]);
    return 0;
}
