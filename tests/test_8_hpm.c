/* tests/test_8_hpm.c - unit tests for section 8 of tiledtex.h, hierarchical
   pattern mapping: the face-cluster hierarchy and flattening. Run by run_hpm_tests()
   (tests/test_common.c calls it). Every property is recomputed here from the
   mesh's own arrays, independently of the implementation's helpers. */
#include "test_common.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <float.h>
#include <string.h>

/* ------------------------------------------------------------------------ */
/* Meshes                                                                   */
/* ------------------------------------------------------------------------ */

/* Every face of src fanned into triangles, appended to dst (vertices too). */
static void triangulate_into(tmesh *dst, const tmesh *src, double dx)
{
    int i, f, c = 0, base = dst->nv;
    for (i = 0; i < src->nv; i++) tm_vert(dst, src->pos[3 * i] + dx, src->pos[3 * i + 1], src->pos[3 * i + 2]);
    for (f = 0; f < src->nf; f++) {
        int n = src->sizes[f], k;
        for (k = 1; k + 1 < n; k++) tm_tri(dst, base + src->idx[c], base + src->idx[c + k], base + src->idx[c + k + 1]);
        c += n;
    }
}

static void hpm_torus(tmesh *m, int nu, int nv, double dx)
{
    tmesh q;
    memset(&q, 0, sizeof q);
    make_torus(&q, nu, nv, 3.0, 1.0);
    triangulate_into(m, &q, dx);
    tm_free(&q);
}

/* nx x ny unit grid, triangulated; the quads with hole[j * nx + i] != 0 left out. */
static void hpm_grid(tmesh *m, int nx, int ny, const unsigned char *hole, double dx)
{
    int i, j, base = m->nv;
    for (j = 0; j <= ny; j++)
        for (i = 0; i <= nx; i++) tm_vert(m, i + dx, j, 0);
    for (j = 0; j < ny; j++)
        for (i = 0; i < nx; i++) {
            int a = base + j * (nx + 1) + i, b = a + 1, c = a + nx + 2, d = a + nx + 1;
            if (hole && hole[j * nx + i]) continue;
            tm_tri(m, a, b, c);
            tm_tri(m, a, c, d);
        }
}

/* Latitude-longitude sphere of radius 2: triangles only, closed. */
static void hpm_sphere(tmesh *m, int nlat, int nlon)
{
    const double pi = 3.14159265358979323846;
    int i, j, base = m->nv, top, bottom;
    top = tm_vert(m, 0, 0, 2);
    for (j = 1; j < nlat; j++)
        for (i = 0; i < nlon; i++) {
            double t = pi * j / nlat, p = 2 * pi * i / nlon;
            tm_vert(m, 2 * sin(t) * cos(p), 2 * sin(t) * sin(p), 2 * cos(t));
        }
    bottom = tm_vert(m, 0, 0, -2);
    for (i = 0; i < nlon; i++) tm_tri(m, top, base + 1 + i, base + 1 + (i + 1) % nlon);
    for (j = 0; j + 2 < nlat; j++)
        for (i = 0; i < nlon; i++) {
            int a = base + 1 + j * nlon + i, b = base + 1 + j * nlon + (i + 1) % nlon;
            tm_tri(m, a, a + nlon, b + nlon);
            tm_tri(m, a, b + nlon, b);
        }
    for (i = 0; i < nlon; i++) {
        int r = base + 1 + (nlat - 2) * nlon;
        tm_tri(m, bottom, r + (i + 1) % nlon, r + i);
    }
}

enum { M_TORUS, M_SPHERE, M_GRID, M_TWO, M_HOLES, M_COUNT };
static const char *const mesh_names[M_COUNT] = {"torus", "sphere", "open grid", "two components",
                                                "grid with holes"};

static tt_mesh *hpm_mesh(int which)
{
    tmesh m;
    tt_mesh *mesh = NULL;
    tt_error err;
    unsigned char hole[24 * 24];
    int i, j;
    memset(&m, 0, sizeof m);
    switch (which) {
    case M_TORUS: hpm_torus(&m, 32, 12, 0.0); break;
    case M_SPHERE: hpm_sphere(&m, 14, 24); break;
    case M_GRID: hpm_grid(&m, 24, 16, NULL, 0.0); break;
    case M_TWO: hpm_torus(&m, 20, 8, 0.0); hpm_grid(&m, 12, 12, NULL, 10.0); break;
    default:
        memset(hole, 0, sizeof hole);
        for (j = 0; j < 24; j++)
            for (i = 0; i < 24; i++)
                hole[j * 24 + i] = (unsigned char)((i >= 4 && i < 8 && j >= 5 && j < 9) ||
                                                   (i >= 14 && i < 19 && j >= 12 && j < 20));
        hpm_grid(&m, 24, 24, hole, 0.0);
        break;
    }
    if (build(&m, 0, &mesh, &err) != TT_OK) CHECK(0, "building the %s failed: %s", mesh_names[which], err.message);
    tm_free(&m);
    return mesh;
}

static tt_cluster_hierarchy *hpm_build_on(const tt_mesh *mesh, uint64_t seed, const tt_executor *executor)
{
    tt_cluster_options opt;
    tt_cluster_hierarchy *h = NULL;
    tt_error err;
    tt_result r;
    memset(&opt, 0, sizeof opt);
    opt.seed = seed;
    opt.executor = executor;
    r = tt_cluster_hierarchy_build(mesh, &opt, NULL, &h, &err);
    CHECK(r == TT_OK && h, "tt_cluster_hierarchy_build returned %d (%s)", r, err.message);
    return r == TT_OK ? h : NULL;
}

static tt_cluster_hierarchy *hpm_build(const tt_mesh *mesh, uint64_t seed)
{
    return hpm_build_on(mesh, seed, NULL);
}

/* ------------------------------------------------------------------------ */
/* Independent recomputation                                                */
/* ------------------------------------------------------------------------ */

/* region[l * nfaces + f]: face f's region at level l (its cluster at l, or
   its leaf from a shallower level); -1 where no region or several claim it
   (counted in *bad). */
static int *regions_per_level(const tt_cluster_hierarchy *h, long *bad)
{
    int nf = h->nfaces, l, id, i;
    int *region = (int *)malloc(sizeof(int) * (size_t)nf * (size_t)h->nlevels);
    int *claims = (int *)calloc((size_t)nf * (size_t)h->nlevels, sizeof(int));
    *bad = 0;
    for (i = 0; i < nf * h->nlevels; i++) region[i] = -1;
    for (id = 0; id < h->nclusters; id++) {
        const tt_cluster *C = &h->clusters[id];
        int last = C->nchildren == 0 ? h->nlevels - 1 : C->level;
        for (l = C->level; l <= last; l++)
            for (i = 0; i < C->nfaces; i++) {
                int f = h->faces[C->first_face + i];
                region[l * nf + f] = id;
                claims[l * nf + f]++;
            }
    }
    for (i = 0; i < nf * h->nlevels; i++)
        if (claims[i] != 1) { (*bad)++; region[i] = -1; }
    free(claims);
    return region;
}

typedef struct topo {
    int v, e, f, loops, simple, connected;
} topo;

static int uf_find(int *p, int x)
{
    while (p[x] != x) x = p[x] = p[p[x]];
    return x;
}

/* V, E, F, border loops (connected pieces of the border edge graph), whether
   every border vertex has border degree 2, and face connectivity, of the
   faces f with inset[f] == 1. */
static topo topology_of(const tt_mesh *m, const unsigned char *inset, int *deg, int *uf, int *queue,
                        unsigned char *seen)
{
    topo t;
    int f, c, head = 0, tail = 0, first = -1, reached = 0;
    memset(&t, 0, sizeof t);
    t.simple = 1;
    for (c = 0; c < m->nverts; c++) { deg[c] = -1; uf[c] = c; }
    for (f = 0; f < m->nfaces; f++) {
        if (!inset[f]) continue;
        t.f++;
        if (first < 0) first = f;
        for (c = m->face_start[f]; c < m->face_start[f + 1]; c++) {
            int a = m->corner_vert[c], b = m->corner_vert[tt_mesh_next(m, c)];
            int tw = m->twin[c], border = tw < 0 || !inset[m->corner_face[tw]];
            if (deg[a] < 0) { deg[a] = 0; t.v++; }
            if (deg[b] < 0) { deg[b] = 0; t.v++; }
            if (border) {
                t.e++;
                deg[a]++;
                deg[b]++;
                uf[uf_find(uf, a)] = uf_find(uf, b);
            } else if (c < tw) {
                t.e++;
            }
        }
    }
    for (c = 0; c < m->nverts; c++)
        if (deg[c] > 0) {
            if (deg[c] != 2) t.simple = 0;
            if (uf_find(uf, c) == c) t.loops++;
        }
    if (m->nfaces > 0) memset(seen, 0, (size_t)m->nfaces);
    if (first >= 0) { queue[tail++] = first; seen[first] = 1; }
    while (head < tail) {
        int g = queue[head++];
        reached++;
        for (c = m->face_start[g]; c < m->face_start[g + 1]; c++) {
            int tw = m->twin[c];
            if (tw >= 0 && inset[m->corner_face[tw]] && !seen[m->corner_face[tw]]) {
                seen[m->corner_face[tw]] = 1;
                queue[tail++] = m->corner_face[tw];
            }
        }
    }
    t.connected = reached == t.f;
    return t;
}

/* Number of regions around each vertex at level l, "outside" (a mesh
   boundary) counted as one, capped at 3. */
static void vertex_regions(const tt_mesh *m, const int *region_l, int *count)
{
    int v, c, k;
    int *slot = (int *)malloc(sizeof(int) * 3 * (size_t)m->nverts);
    for (v = 0; v < m->nverts; v++) count[v] = 0;
    for (c = 0; c < m->ncorners; c++)
        if (m->twin[c] < 0) {
            int ends[2], e;
            ends[0] = m->corner_vert[c];
            ends[1] = m->corner_vert[tt_mesh_next(m, c)];
            for (e = 0; e < 2; e++)
                if (count[ends[e]] == 0) { slot[3 * ends[e]] = -2; count[ends[e]] = 1; }
        }
    for (c = 0; c < m->ncorners; c++) {
        int w = m->corner_vert[c], r = region_l[m->corner_face[c]], known = 0;
        for (k = 0; k < count[w]; k++) known |= slot[3 * w + k] == r;
        if (!known && count[w] < 3) slot[3 * w + count[w]++] = r;
    }
    free(slot);
}

/* ------------------------------------------------------------------------ */
/* The properties, checked on one hierarchy                                 */
/* ------------------------------------------------------------------------ */

/* Checks (1) partition and structure, (2) discs, (3) control vertices,
   (4) leaves, and the neighbour lists, of hierarchy h of mesh m. Returns
   the worst max/min face-count ratio of a level's clusters within one
   component, over the levels below 0 whose clusters all have more than 8
   faces (see test_hpm_uniform). */
static double check_hierarchy(const tt_mesh *m, const tt_cluster_hierarchy *h, const char *name, int verbose)
{
    int nf = m->nfaces, nv = m->nverts, l, id, i, c, ncomp = 0;
    long part_bad = 0, struct_bad = 0, child_bad = 0, disc_wrong = 0, nondisc_wrong = 0, loops_wrong = 0;
    long off_border = 0, order_bad = 0, too_few = 0, missing = 0, leaf_bad = 0, nb_bad = 0, top_bad = 0;
    long ndisc = 0, nnondisc = 0, nmappable = 0;
    double worst = 1.0;
    int *region = regions_per_level(h, &part_bad);
    int *comp = (int *)malloc(sizeof(int) * (size_t)nf);
    unsigned char *inset = (unsigned char *)calloc((size_t)nf, 1), *seen = (unsigned char *)malloc((size_t)nf);
    int *deg = (int *)malloc(sizeof(int) * (size_t)nv), *uf = (int *)malloc(sizeof(int) * (size_t)nv);
    int *queue = (int *)malloc(sizeof(int) * (size_t)nf), *vcount = (int *)malloc(sizeof(int) * (size_t)nv);
    int *nextv = (int *)malloc(sizeof(int) * (size_t)nv), *posv = (int *)malloc(sizeof(int) * (size_t)nv);
    int *isctl = (int *)calloc((size_t)nv, sizeof(int)), *nbs = (int *)malloc(sizeof(int) * 3 * (size_t)nf);

    CHECK(part_bad == 0, "%s: every face is in exactly one region per level (%ld face-levels are not)", name,
          part_bad);
    tt_mesh_components(m, NULL, comp, &ncomp, NULL);
    struct_bad += h->ncomponents != ncomp || h->level_start[0] != 0 || h->level_start[h->nlevels] != h->nclusters ||
                  h->level_start[1] != ncomp || h->nfaces != nf;
    for (l = 0; l < h->nlevels; l++)
        for (id = h->level_start[l]; id < h->level_start[l + 1]; id++) struct_bad += h->clusters[id].level != l;
    for (id = 0; id < ncomp && id < h->nclusters; id++) {
        const tt_cluster *C = &h->clusters[id];
        struct_bad += C->parent != -1 || C->component != id;
        for (i = 0; i < C->nfaces; i++) struct_bad += comp[h->faces[C->first_face + i]] != id;
    }
    for (l = 0; l < h->nlevels; l++) {
        vertex_regions(m, region + (size_t)l * nf, vcount);
        for (id = h->level_start[l]; id < h->level_start[l + 1]; id++) {
            const tt_cluster *C = &h->clusters[id];
            const int *fl = h->faces + C->first_face;
            const int *ctl = h->control + C->first_control;
            topo t;
            int is_disc, sum = 0, k, nn = 0, u, start, steps;
            /* Children cover exactly the parent's faces. */
            for (i = 0; i < C->nfaces; i++) inset[fl[i]] = 1;
            if (C->nchildren > 0) {
                for (k = 0; k < C->nchildren; k++) {
                    const tt_cluster *D = &h->clusters[C->first_child + k];
                    sum += D->nfaces;
                    child_bad += D->parent != id || D->level != l + 1 || D->component != C->component;
                    for (i = 0; i < D->nfaces; i++) child_bad += !inset[h->faces[D->first_face + i]];
                }
                child_bad += sum != C->nfaces || C->nchildren < 2;
            }
            /* Leaves. */
            leaf_bad += (C->nchildren == 0) != (C->nfaces == 1);
            if (C->nfaces == 1) leaf_bad += h->face_leaf[fl[0]] != id;
            /* Discs. */
            t = topology_of(m, inset, deg, uf, queue, seen);
            is_disc = t.connected && t.loops == 1 && t.simple && t.v - t.e + t.f == 1;
            if (C->flags & TT_CLUSTER_DISC) {
                ndisc++;
                if (!is_disc && disc_wrong++ == 0)
                    DETAIL("%s: cluster %d flagged a disc: V %d E %d F %d loops %d simple %d connected %d", name, id,
                           t.v, t.e, t.f, t.loops, t.simple, t.connected);
            } else {
                nnondisc++;
                if (is_disc && nondisc_wrong++ == 0)
                    DETAIL("%s: cluster %d (%d faces) flagged not a disc but is one", name, id, C->nfaces);
            }
            if (t.simple) loops_wrong += C->nloops != t.loops;
            /* Level 0 of a closed component: not mappable, no control vertex. */
            if (l == 0 && t.loops == 0) top_bad += (C->flags & TT_CLUSTER_MAPPABLE) || C->ncontrol != 0;
            if (C->flags & TT_CLUSTER_MAPPABLE) {
                nmappable++;
                too_few += C->ncontrol < 3 || !(C->flags & TT_CLUSTER_DISC);
            } else {
                too_few += (C->flags & TT_CLUSTER_DISC) != 0;
            }
            /* Control vertices: on the border; every 3-region border vertex is one. */
            for (k = 0; k < C->ncontrol; k++) {
                off_border += deg[ctl[k]] <= 0;
                isctl[ctl[k]] = id + 1;
            }
            for (i = 0; i < C->nfaces; i++)
                for (c = m->face_start[fl[i]]; c < m->face_start[fl[i] + 1]; c++) {
                    int w = m->corner_vert[c];
                    if (deg[w] > 0 && vcount[w] >= 3 && isctl[w] != id + 1 && missing++ == 0)
                        DETAIL("%s: vertex %d on cluster %d's border meets %d regions but is no control vertex",
                               name, w, id, vcount[w]);
                }
            /* Border order (discs): walk the border along the cluster's own half-edges. */
            if ((C->flags & TT_CLUSTER_DISC) && C->ncontrol > 0 && deg[ctl[0]] > 0) {
                for (i = 0; i < C->nfaces; i++)
                    for (c = m->face_start[fl[i]]; c < m->face_start[fl[i] + 1]; c++) {
                        int tw = m->twin[c];
                        if (tw < 0 || !inset[m->corner_face[tw]])
                            nextv[m->corner_vert[c]] = m->corner_vert[tt_mesh_next(m, c)];
                        posv[m->corner_vert[c]] = -1;
                    }
                start = ctl[0];
                for (u = start, steps = 0; steps <= t.e; steps++) {
                    posv[u] = steps;
                    u = nextv[u];
                    if (u == start) break;
                }
                for (k = 1; k < C->ncontrol; k++)
                    if (posv[ctl[k]] <= posv[ctl[k - 1]] && order_bad++ == 0)
                        DETAIL("%s: cluster %d's control vertices %d, %d are not in border order", name, id,
                               ctl[k - 1], ctl[k]);
            }
            /* Neighbours: the other regions across its border edges, ascending. */
            for (i = 0; i < C->nfaces; i++)
                for (c = m->face_start[fl[i]]; c < m->face_start[fl[i] + 1]; c++) {
                    int tw = m->twin[c];
                    if (tw >= 0 && !inset[m->corner_face[tw]]) {
                        int r = region[(size_t)l * nf + m->corner_face[tw]], known = 0;
                        for (k = 0; k < nn; k++) known |= nbs[k] == r;
                        if (!known) nbs[nn++] = r;
                    }
                }
            nb_bad += nn != C->nneighbours;
            for (k = 0; k < C->nneighbours; k++) {
                int r = h->neighbours[C->first_neighbour + k], known = 0, j;
                for (j = 0; j < nn; j++) known |= nbs[j] == r;
                nb_bad += !known || (k > 0 && r <= h->neighbours[C->first_neighbour + k - 1]);
            }
            for (i = 0; i < C->nfaces; i++) inset[fl[i]] = 0;
        }
    }
    /* Uniformity: max / min face count per (level, component) over the
       levels whose clusters are all still larger than 8 faces. */
    for (l = 1; l < h->nlevels; l++) {
        int k;
        for (k = 0; k < ncomp; k++) {
            int lo = 1 << 30, hi = 0;
            for (id = h->level_start[l]; id < h->level_start[l + 1]; id++)
                if (h->clusters[id].component == k) {
                    lo = lo < h->clusters[id].nfaces ? lo : h->clusters[id].nfaces;
                    hi = hi > h->clusters[id].nfaces ? hi : h->clusters[id].nfaces;
                }
            if (hi > 0 && lo > 8 && (double)hi / lo > worst) worst = (double)hi / lo;
        }
    }
    CHECK(struct_bad == 0, "%s: level ranges, levels, parents of level 0 and components are consistent (%ld bad)",
          name, struct_bad);
    CHECK(child_bad == 0, "%s: children partition their parent's faces, one level down (%ld bad)", name, child_bad);
    CHECK(disc_wrong == 0 && nondisc_wrong == 0 && ndisc > 0,
          "%s: the disc flags match a recomputation (%ld of %ld discs wrong, %ld of %ld non-discs wrong)", name,
          disc_wrong, ndisc, nondisc_wrong, nnondisc);
    CHECK(loops_wrong == 0, "%s: nloops matches the border's loops (%ld wrong)", name, loops_wrong);
    CHECK(top_bad == 0, "%s: a closed component's top cluster is not mappable and has no control vertex", name);
    CHECK(too_few == 0 && nmappable > 0,
          "%s: mappable == disc with >= 3 control vertices (%ld clusters disagree, %ld mappable)", name, too_few,
          nmappable);
    CHECK(off_border == 0, "%s: control vertices lie on their cluster's border (%ld do not)", name, off_border);
    CHECK(order_bad == 0, "%s: control vertices follow the border order (%ld pairs out of order)", name, order_bad);
    CHECK(missing == 0, "%s: every border vertex meeting 3+ regions is a control vertex (%ld missed)", name, missing);
    CHECK(leaf_bad == 0, "%s: leaves are exactly the single faces, and face_leaf names them (%ld bad)", name,
          leaf_bad);
    CHECK(nb_bad == 0, "%s: neighbour lists are the regions across the border, ascending (%ld bad)", name, nb_bad);
    if (verbose)
        printf("     %s: %d faces, %d clusters, %d levels, %ld non-disc, worst size ratio %.2f\n", name, nf,
               h->nclusters, h->nlevels, nnondisc, worst);
    free(region); free(comp); free(inset); free(seen); free(deg); free(uf); free(queue); free(vcount);
    free(nextv); free(posv); free(isctl); free(nbs);
    return worst;
}

/* ------------------------------------------------------------------------ */
/* Tests                                                                    */
/* ------------------------------------------------------------------------ */

/* (1)-(4) on every kind of mesh, plus what each kind promises at level 0. */
static void test_hpm_properties(void)
{
    int which;
    for (which = 0; which < M_COUNT; which++) {
        tt_mesh *mesh = hpm_mesh(which);
        tt_cluster_hierarchy *h;
        if (!mesh) continue;
        h = hpm_build(mesh, 1);
        if (h) {
            const tt_cluster *top = &h->clusters[0];
            check_hierarchy(mesh, h, mesh_names[which], 1);
            switch (which) {
            case M_TORUS: case M_SPHERE:
                CHECK(h->ncomponents == 1 && top->nloops == 0 && !(top->flags & TT_CLUSTER_DISC),
                      "%s: one closed top cluster, not a disc (loops %d, flags %u)", mesh_names[which], top->nloops,
                      top->flags);
                break;
            case M_GRID:
                CHECK(h->ncomponents == 1 && (top->flags & TT_CLUSTER_MAPPABLE) && top->ncontrol == 4,
                      "open grid: the top cluster is a mappable disc with 4 added control vertices (flags %u, %d)",
                      top->flags, top->ncontrol);
                break;
            case M_TWO:
                CHECK(h->ncomponents == 2 && h->level_start[1] == 2 &&
                          !(h->clusters[0].flags & TT_CLUSTER_MAPPABLE) && (h->clusters[1].flags & TT_CLUSTER_MAPPABLE),
                      "two components: a closed torus (not mappable) and an open grid (mappable) at level 0 (%d)",
                      h->ncomponents);
                break;
            default:
                CHECK(h->ncomponents == 1 && top->nloops == 3 && !(top->flags & TT_CLUSTER_DISC),
                      "grid with holes: the top cluster has 3 border loops and is no disc (%d loops)", top->nloops);
                break;
            }
        }
        tt_cluster_hierarchy_free(h);
        tt_mesh_free(mesh);
    }
}

/* A cluster surrounded by one neighbour (an annulus's inside) or a
   single triangle: control vertices added, counted, in order. A tetra's
   four faces give four single-face leaves below one closed cluster. */
static void test_hpm_small(void)
{
    tmesh t;
    tt_mesh *mesh = NULL;
    tt_cluster_hierarchy *h;
    tt_error err;
    int id;
    memset(&t, 0, sizeof t);
    make_tetra(&t, 0.0);
    if (build(&t, 0, &mesh, &err) != TT_OK) { CHECK(0, "tetra: %s", err.message); tm_free(&t); return; }
    h = hpm_build(mesh, 3);
    if (h) {
        check_hierarchy(mesh, h, "tetrahedron", 0);
        for (id = h->level_start[1]; id < h->nclusters; id++)
            if (h->clusters[id].nfaces == 1) {
                const tt_cluster *C = &h->clusters[id];
                int f = h->faces[C->first_face], k, same = C->ncontrol == 3;
                for (k = 0; k < 3 && same; k++) {
                    int v = h->control[C->first_control + k], j, found = 0;
                    for (j = 0; j < 3; j++) found |= mesh->corner_vert[3 * f + j] == v;
                    same = found;
                }
                CHECK(same, "tetrahedron: single face %d's control vertices are its 3 corners", f);
            }
    }
    tt_cluster_hierarchy_free(h);
    tt_mesh_free(mesh);
    tm_free(&t);
}

static int same_hierarchy(const tt_cluster_hierarchy *a, const tt_cluster_hierarchy *b)
{
    return a->nclusters == b->nclusters && a->nlevels == b->nlevels && a->nface_entries == b->nface_entries &&
           a->ncontrol == b->ncontrol && a->nneighbour_entries == b->nneighbour_entries &&
           !memcmp(a->clusters, b->clusters, sizeof(tt_cluster) * (size_t)a->nclusters) &&
           !memcmp(a->level_start, b->level_start, sizeof(int) * (size_t)(a->nlevels + 1)) &&
           !memcmp(a->faces, b->faces, sizeof(int) * (size_t)a->nface_entries) &&
           !memcmp(a->control, b->control, sizeof(int) * (size_t)a->ncontrol) &&
           !memcmp(a->neighbours, b->neighbours, sizeof(int) * (size_t)a->nneighbour_entries) &&
           !memcmp(a->face_leaf, b->face_leaf, sizeof(int) * (size_t)a->nfaces);
}

/* (5) The same seed gives the same hierarchy, whatever runs the splits in
   parallel (reverse-order and two-thread executors); another seed another
   one. */
static void test_hpm_determinism(void)
{
    int which;
    for (which = 0; which < M_COUNT; which++) {
        tt_mesh *mesh = hpm_mesh(which);
        tt_cluster_hierarchy *a, *b, *c, *reverse, *threads;
        if (!mesh) continue;
        a = hpm_build(mesh, 42);
        b = hpm_build(mesh, 42);
        c = hpm_build(mesh, 43);
        reverse = hpm_build_on(mesh, 42, &g_reverse_executor);
        threads = hpm_build_on(mesh, 42, &g_thread_executor);
        if (a && b && c && reverse && threads) {
            CHECK(same_hierarchy(a, b), "%s: seed 42 twice gives the same hierarchy", mesh_names[which]);
            CHECK(same_hierarchy(a, reverse) && same_hierarchy(a, threads),
                  "%s: the reverse-order and two-thread executors give the serial hierarchy", mesh_names[which]);
            CHECK(!same_hierarchy(a, c), "%s: seeds 42 and 43 give different hierarchies", mesh_names[which]);
        }
        tt_cluster_hierarchy_free(a);
        tt_cluster_hierarchy_free(b);
        tt_cluster_hierarchy_free(c);
        tt_cluster_hierarchy_free(reverse);
        tt_cluster_hierarchy_free(threads);
        tt_mesh_free(mesh);
    }
}

/* (6) Sizes per level: within a component, the largest cluster of a level
   has at most HPM_SIZE_RATIO times the faces of the smallest, on the levels
   whose clusters all have more than 8 faces (measured over seeds 0..9 on
   these meshes: 4.12; 8.31 without the relaxation round). */
#define HPM_SIZE_RATIO 5.0
/* Re-seeding keeps non-disc clusters rare: below level 0, 14 of
   53639 clusters over these meshes and seeds (83 without re-seeding). */
#define HPM_MAX_NONDISC 40
static void test_hpm_uniform(void)
{
    int which, seed;
    long nondisc = 0, clusters = 0;
    double worst = 1.0;
    for (which = 0; which < M_COUNT; which++) {
        tt_mesh *mesh = hpm_mesh(which);
        if (!mesh) continue;
        for (seed = 0; seed < 10; seed++) {
            tt_cluster_hierarchy *h = hpm_build(mesh, (uint64_t)seed);
            if (h) {
                double r = check_hierarchy(mesh, h, mesh_names[which], 0);
                int id;
                if (r > worst) worst = r;
                for (id = h->level_start[1]; id < h->nclusters; id++)
                    nondisc += !(h->clusters[id].flags & TT_CLUSTER_DISC);
                clusters += h->nclusters - h->level_start[1];
            }
            tt_cluster_hierarchy_free(h);
        }
        tt_mesh_free(mesh);
    }
    CHECK(worst <= HPM_SIZE_RATIO, "cluster sizes per level and component within a factor %.1f (worst %.2f)",
          HPM_SIZE_RATIO, worst);
    printf("     cluster size ratio per level (levels of > 8 faces), worst over 5 meshes x 10 seeds: %.2f\n", worst);
    CHECK(nondisc <= HPM_MAX_NONDISC, "re-seeding leaves at most %d non-disc clusters below level 0 (%ld of %ld)",
          HPM_MAX_NONDISC, nondisc, clusters);
    printf("     non-disc clusters below level 0 over 5 meshes x 10 seeds: %ld of %ld\n", nondisc, clusters);
}

typedef struct hpm_oom_ctx {
    const tt_mesh *mesh;
} hpm_oom_ctx;

static tt_result hpm_oom_call(void *ctx, const tt_allocator *al, tt_error *error)
{
    hpm_oom_ctx *c = (hpm_oom_ctx *)ctx;
    tt_cluster_hierarchy *h = (tt_cluster_hierarchy *)&h;
    tt_result r = tt_cluster_hierarchy_build(c->mesh, NULL, al, &h, error);
    if (error->result != r || (r != TT_OK) != (h == NULL)) return TT_RESULT_MAX_ENUM;
    tt_cluster_hierarchy_free(h);
    return r;
}

static void hpm_free_only(void *ptr, void *user_data)
{
    (void)user_data;
    free(ptr);
}

/* (7) Errors, and every allocation failing in turn. */
static void test_hpm_errors(void)
{
    tmesh q;
    tt_mesh *quads = NULL, *mesh = hpm_mesh(M_TWO), empty;
    tt_cluster_hierarchy *h = (tt_cluster_hierarchy *)&h;
    tt_cluster_options opt;
    tt_allocator half;
    tt_error err;
    tt_result r;
    hpm_oom_ctx ctx;
    if (!mesh) return;
    memset(&q, 0, sizeof q);
    make_grid(&q, 3, 2);
    build(&q, 0, &quads, &err);
    tm_free(&q);

    r = tt_cluster_hierarchy_build(NULL, NULL, NULL, &h, &err);
    CHECK(r == TT_ERROR_INVALID_ARGUMENT && h == NULL && err.result == r, "NULL mesh: %d, out reset", r);
    r = tt_cluster_hierarchy_build(mesh, NULL, NULL, NULL, &err);
    CHECK(r == TT_ERROR_INVALID_ARGUMENT, "NULL out: %d", r);
    h = (tt_cluster_hierarchy *)&h;
    r = tt_cluster_hierarchy_build(quads, NULL, NULL, &h, &err);
    CHECK(r == TT_ERROR_INVALID_ARGUMENT && err.face == 0 && h == NULL && strstr(err.message, "triangle"),
          "quads: %d, face %d: %s", r, err.face, err.message);
    memset(&empty, 0, sizeof empty);
    r = tt_cluster_hierarchy_build(&empty, NULL, NULL, &h, &err);
    CHECK(r == TT_ERROR_EMPTY_MESH && h == NULL, "a mesh with no faces: %d", r);
    memset(&opt, 0, sizeof opt);
    opt.branching = 1;
    r = tt_cluster_hierarchy_build(mesh, &opt, NULL, &h, &err);
    CHECK(r == TT_ERROR_INVALID_ARGUMENT && msg_has_number(err.message, 1), "branching 1: %d (%s)", r, err.message);
    opt.branching = 65;
    r = tt_cluster_hierarchy_build(mesh, &opt, NULL, &h, &err);
    CHECK(r == TT_ERROR_INVALID_ARGUMENT, "branching 65: %d", r);
    opt.branching = 2;
    r = tt_cluster_hierarchy_build(mesh, &opt, NULL, &h, &err);
    CHECK(r == TT_OK && h && h->nlevels > 5, "branching 2 works (%d, %d levels)", r, h ? h->nlevels : 0);
    if (r == TT_OK) check_hierarchy(mesh, h, "two components, branching 2", 0);
    tt_cluster_hierarchy_free(h);
    memset(&half, 0, sizeof half);
    half.free = hpm_free_only;
    r = tt_cluster_hierarchy_build(mesh, NULL, &half, &h, &err);
    CHECK(r == TT_ERROR_INVALID_ARGUMENT && h == NULL, "an allocator with free only: %d", r);
    tt_cluster_hierarchy_free(NULL);

    ctx.mesh = mesh;
    oom_reset();
    oom_sweep("tt_cluster_hierarchy_build(two components)", hpm_oom_call, &ctx, TT_OK);
    tt_mesh_free(quads);
    tt_mesh_free(mesh);
}


/* ------------------------------------------------------------------------ */
/* Flattening (tt_flatten_cluster)                                          */
/* ------------------------------------------------------------------------ */

static const float FLAT_SENTINEL = -12345.0f;

/* A planar (nx x ny) grid of unit squares, triangulated, rotated into a
   tilted plane (so the map's frame is not the xy plane). */
static tt_mesh *flat_tilted_grid(int nx, int ny)
{
    tmesh m;
    tt_mesh *mesh = NULL;
    tt_error err;
    int i, j;
    const double c1 = cos(0.7), s1 = sin(0.7), c2 = cos(0.4), s2 = sin(0.4);
    memset(&m, 0, sizeof m);
    for (j = 0; j <= ny; j++)
        for (i = 0; i <= nx; i++) {
            double x = i, y = j, z = 0, x1 = c1 * x - s1 * y, y1 = s1 * x + c1 * y;  /* about z */
            double y2 = c2 * y1 - s2 * z, z2 = s2 * y1 + c2 * z;                     /* about x */
            tm_vert(&m, x1 + 3, y2 - 1, z2 + 2);
        }
    for (j = 0; j < ny; j++)
        for (i = 0; i < nx; i++) {
            int a = j * (nx + 1) + i, b = a + 1, c = a + nx + 2, d = a + nx + 1;
            tm_tri(&m, a, b, c);
            tm_tri(&m, a, c, d);
        }
    if (build(&m, 0, &mesh, &err) != TT_OK) CHECK(0, "building the tilted grid failed: %s", err.message);
    tm_free(&m);
    return mesh;
}

/* A spherical cap of radius 1 and half-angle alpha: a centre vertex, nr
   rings of nphi vertices. */
static tt_mesh *flat_cap(double alpha, int nr, int nphi)
{
    const double pi = 3.14159265358979323846;
    tmesh m;
    tt_mesh *mesh = NULL;
    tt_error err;
    int i, j;
    memset(&m, 0, sizeof m);
    tm_vert(&m, 0, 0, 1);
    for (i = 1; i <= nr; i++)
        for (j = 0; j < nphi; j++) {
            double t = alpha * i / nr, p = 2 * pi * j / nphi;
            tm_vert(&m, sin(t) * cos(p), sin(t) * sin(p), cos(t));
        }
    for (j = 0; j < nphi; j++) tm_tri(&m, 0, 1 + j, 1 + (j + 1) % nphi);
    for (i = 1; i < nr; i++)
        for (j = 0; j < nphi; j++) {
            int in0 = 1 + (i - 1) * nphi + j, in1 = 1 + (i - 1) * nphi + (j + 1) % nphi;
            int out0 = in0 + nphi, out1 = in1 + nphi;
            tm_tri(&m, in0, out0, out1);
            tm_tri(&m, in0, out1, in1);
        }
    if (build(&m, 0, &mesh, &err) != TT_OK) CHECK(0, "building the cap failed: %s", err.message);
    tm_free(&m);
    return mesh;
}

/* Independent checks of a map written into uv for cluster c: counts of
   triangles with a non-positive signed area, the largest relative edge
   length error and the largest |corner disagreement| over shared vertices. */
static void flat_measure(const tt_mesh *m, const tt_cluster_hierarchy *h, int c, const float *uv, int *flips,
                         double *max_edge_error, double *mapped_area)
{
    const tt_cluster *C = &h->clusters[c];
    int i, k;
    *flips = 0;
    *max_edge_error = 0;
    *mapped_area = 0;
    for (i = 0; i < C->nfaces; i++) {
        int f = h->faces[C->first_face + i], c0 = m->face_start[f];
        const float *u0 = uv + 2 * c0, *u1 = uv + 2 * (c0 + 1), *u2 = uv + 2 * (c0 + 2);
        double a = 0.5 * (((double)u1[0] - u0[0]) * ((double)u2[1] - u0[1]) -
                          ((double)u2[0] - u0[0]) * ((double)u1[1] - u0[1]));
        *mapped_area += a;
        if (!(a > 0)) (*flips)++;
        for (k = 0; k < 3; k++) {
            int ca = c0 + k, cb = c0 + (k + 1) % 3, va = m->corner_vert[ca], vb = m->corner_vert[cb];
            double dx = m->pos[3 * va] - m->pos[3 * vb], dy = m->pos[3 * va + 1] - m->pos[3 * vb + 1];
            double dz = m->pos[3 * va + 2] - m->pos[3 * vb + 2], L3 = sqrt(dx * dx + dy * dy + dz * dz);
            double du = (double)uv[2 * ca] - uv[2 * cb], dv = (double)uv[2 * ca + 1] - uv[2 * cb + 1];
            double e = fabs(sqrt(du * du + dv * dv) - L3) / L3;
            if (e > *max_edge_error) *max_edge_error = e;
        }
    }
}

static float *flat_uv(const tt_mesh *m)
{
    float *uv = (float *)malloc(sizeof(float) * 2 * (size_t)m->ncorners);
    int i;
    for (i = 0; uv && i < 2 * m->ncorners; i++) uv[i] = FLAT_SENTINEL;
    return uv;
}

/* (8) A planar disc maps isometrically at every level, in both border
   modes where the border between control vertices is straight, and in the
   projected mode whatever the border's shape. */
static void test_flatten_plane(void)
{
    tt_mesh *m = flat_tilted_grid(20, 20);
    tt_cluster_hierarchy *h = m ? hpm_build(m, 7) : NULL;
    float *uv = m ? flat_uv(m) : NULL;
    tt_flatten_report rep;
    tt_flatten_options opt;
    tt_error err;
    tt_result r;
    int c, mapped = 0, refused = 0, flips, bad = 0;
    double worst_e = 0, worst_len = 0, worst_stretch = 0, edge, area;
    if (!h || !uv) goto end;
    for (c = 0; c < h->nclusters; c++) {
        if (!(h->clusters[c].flags & TT_CLUSTER_MAPPABLE)) continue;
        r = tt_flatten_cluster(m, h, c, NULL, NULL, uv, &rep, &err);
        if (r != TT_OK) {
            if (!refused) DETAIL("cluster %d (level %d) refused: %s", c, h->clusters[c].level, err.message);
            refused++;
            continue;
        }
        mapped++;
        flat_measure(m, h, c, uv, &flips, &edge, &area);
        if (flips) bad++;
        if (rep.flattening_error > worst_e) worst_e = rep.flattening_error;
        if (edge > worst_len) worst_len = edge;
        if (rep.max_stretch - 1 > worst_stretch) worst_stretch = rep.max_stretch - 1;
    }
    CHECK(mapped > 100 && refused == 0, "planar grid: %d clusters mapped, %d refused", mapped, refused);
    CHECK(worst_e < 1e-9, "planar grid: E_flat %.3g (< 1e-9)", worst_e);
    /* positions are floats, so a rotated grid is planar to about 1e-7 */
    CHECK(worst_stretch < 1e-5, "planar grid: stretch 1 + %.3g", worst_stretch);
    CHECK(worst_len < 1e-5, "planar grid: the UVs keep every edge length (worst relative error %.3g)", worst_len);
    CHECK(bad == 0, "planar grid: %d maps with a flipped triangle", bad);

    /* The whole square with its 4 corners as control vertices (hand-made):
       the borders between them are straight, so the chord mode is isometric
       too, up to the float rounding of the rotated positions (the chord
       lengths the polygon is fitted to carry it: E_flat about 4e-8). */
    {
        tt_cluster_hierarchy fake = *h;
        tt_cluster one = h->clusters[0];
        int corner_ids[4] = {0, 20, 21 * 21 - 1, 21 * 20};
        one.first_control = 0;
        one.ncontrol = 4;
        fake.clusters = &one;
        fake.nclusters = 1;
        fake.control = corner_ids;
        fake.ncontrol = 4;
        memset(&opt, 0, sizeof opt);
        opt.border = TT_FLATTEN_BORDER_CHORD;
        r = tt_flatten_cluster(m, &fake, 0, &opt, NULL, uv, &rep, &err);
        flat_measure(m, &fake, 0, uv, &flips, &edge, &area);
        CHECK(r == TT_OK && rep.mapped && rep.flattening_error < 1e-6 && rep.max_stretch < 1 + 1e-5 &&
                  rep.stretch_p95 < 1 + 1e-5 && edge < 1e-5 && flips == 0 && rep.ninterior == 19 * 19 &&
                  rep.nborder == 80 && rep.cg_iterations > 0,
              "chord mode, whole square: %d, E %.3g, stretch %.9g, edge error %.3g, %d interior, %d border, %d "
              "CG steps (%s)",
              r, rep.flattening_error, rep.max_stretch, edge, rep.ninterior, rep.nborder, rep.cg_iterations,
              err.message);
    }
end:
    free(uv);
    tt_cluster_hierarchy_free(h);
    tt_mesh_free(m);
}

/* (9) Spherical caps. E_flat follows tan^2(alpha/2) (the cap's border
   circle projects onto itself, so this holds whatever the control
   vertices), within 0.5 % + 1e-4 for 32 rings of 128 (measured: 0.01 %;
   the polyhedral cap's area and the 128-gon's fall short of the smooth ones
   alike); the 0.10 threshold accepts 20, 30 and 35 degrees (E_flat 0.0994)
   and refuses 40 and 50; no map has a flipped triangle. */
static void test_flatten_caps(void)
{
    const double pi = 3.14159265358979323846;
    static const double degrees[5] = {20, 30, 35, 40, 50};
    int i;
    for (i = 0; i < 5; i++) {
        double alpha = degrees[i] * pi / 180, expect = tan(alpha / 2) * tan(alpha / 2), edge, area;
        tt_mesh *m = flat_cap(alpha, 32, 128);
        tt_cluster_hierarchy *h = m ? hpm_build(m, 1) : NULL;
        float *uv = m ? flat_uv(m) : NULL;
        tt_flatten_options opt;
        tt_flatten_report rep, rep2;
        tt_error err;
        tt_result r, r2;
        int flips = -1;
        if (!h || !uv) {
            free(uv);
            tt_cluster_hierarchy_free(h);
            tt_mesh_free(m);
            continue;
        }
        memset(&opt, 0, sizeof opt);
        opt.max_error = 1e300 * 1e300;   /* +infinity: no limit, so the map always comes back */
        r = tt_flatten_cluster(m, h, 0, &opt, NULL, uv, &rep, &err);
        if (r == TT_OK) flat_measure(m, h, 0, uv, &flips, &edge, &area);
        CHECK(r == TT_OK && rep.mapped && flips == 0 && rep.flipped == 0 &&
                  fabs(rep.flattening_error - expect) <= 0.005 * expect + 1e-4 &&
                  fabs(area - rep.mapped_area) <= 1e-5 * area,
              "cap %g deg: %d, E_flat %.5f, tan^2(alpha/2) %.5f, %d flips (%s)", degrees[i], r, rep.flattening_error,
              expect, flips, err.message);
        r2 = tt_flatten_cluster(m, h, 0, NULL, NULL, uv, &rep2, &err);
        CHECK((degrees[i] <= 35) == (r2 == TT_OK) &&
                  (r2 == TT_OK || (r2 == TT_ERROR_NOT_FLAT && err.result == r2 && err.item == 0 &&
                                   rep2.mapped && rep2.flattening_error > TT_DEFAULT_FLATTEN_MAX_ERROR)),
              "cap %g deg at the default threshold: %d, E_flat %.4f (%s)", degrees[i], r2, rep2.flattening_error,
              err.message);
        /* The shear check: a cap stretches a little, a limit of 1.0001 refuses it. */
        opt.max_stretch = 1.0001;
        r2 = tt_flatten_cluster(m, h, 0, &opt, NULL, uv, &rep2, &err);
        CHECK(r2 == TT_ERROR_NOT_FLAT && rep2.stretch_p95 > 1.0001 && rep2.stretch_p95 < 2 &&
                  rep2.max_stretch >= rep2.stretch_p95,
              "cap %g deg with max_stretch 1.0001: %d, p95 %.5f, max %.5f", degrees[i], r2, rep2.stretch_p95,
              rep2.max_stretch);
        free(uv);
        tt_cluster_hierarchy_free(h);
        tt_mesh_free(m);
    }
}

/* (10) Folds and polygons that are not simple: a hand-made hierarchy with 3
   control vertices on a planar square, (0,0), (n,0), (n,n): in the chord
   mode the top and left borders collapse onto the diagonal and the corner
   triangle between them loses all its area (refused, the folded face
   named); in the
   projected mode the same cluster is isometric. Sheets rolled round a
   cylinder: the projected border, or the control polygon, is not simple. */
static void test_flatten_folds(void)
{
    tt_mesh *m = flat_tilted_grid(8, 8);
    tt_cluster_hierarchy *h = m ? hpm_build(m, 3) : NULL;
    float *uv = m ? flat_uv(m) : NULL;
    tt_cluster_hierarchy fake;
    tt_cluster one;
    int ctl[3] = {0, 8, 80}, i, untouched = 1, flips;
    tt_flatten_options opt;
    tt_flatten_report rep;
    tt_error err;
    tt_result r;
    double edge, area;
    if (h && uv) {
        fake = *h;
        one = h->clusters[0];
        one.first_control = 0;
        one.ncontrol = 3;
        fake.clusters = &one;
        fake.nclusters = 1;
        fake.control = ctl;
        fake.ncontrol = 3;
        memset(&opt, 0, sizeof opt);
        opt.border = TT_FLATTEN_BORDER_CHORD;
        r = tt_flatten_cluster(m, &fake, 0, &opt, NULL, uv, &rep, &err);
        for (i = 0; i < 2 * m->ncorners; i++) untouched &= uv[i] == FLAT_SENTINEL;
        CHECK(r == TT_ERROR_NOT_FLAT && err.result == r && rep.mapped && rep.polygon_simple && rep.flipped >= 1 &&
                  err.face >= 0 && err.item == 0 && untouched,
              "chord mode over a triangle of corners: %d, %d flipped, face %d, corner_uv untouched %d (%s)", r,
              rep.flipped, err.face, untouched, err.message);
        r = tt_flatten_cluster(m, &fake, 0, NULL, NULL, uv, &rep, &err);
        flat_measure(m, &fake, 0, uv, &flips, &edge, &area);
        CHECK(r == TT_OK && rep.flattening_error < 1e-9 && flips == 0 && edge < 1e-5,
              "projected mode, same cluster: %d, E %.3g, edge error %.3g (%s)", r, rep.flattening_error, edge,
              err.message);
    }
    free(uv);
    tt_cluster_hierarchy_free(h);
    tt_mesh_free(m);

    {
        /* 240 degrees: the 4 corners make a fine rectangle but the border arcs
           fold back in projection; 300 degrees: the rectangle itself turns
           clockwise. */
        const double pi = 3.14159265358979323846;
        static const double arcs[2] = {240, 300};
        static const char *const what[2] = {"its border", "its control polygon"};
        int a;
        for (a = 0; a < 2; a++) {
            tmesh q;
            int j, nu = 40, nv = 4;
            memset(&q, 0, sizeof q);
            for (j = 0; j <= nv; j++)
                for (i = 0; i <= nu; i++) {
                    double t = arcs[a] / 180.0 * pi * i / nu;
                    tm_vert(&q, cos(t), sin(t), 0.5 * j);
                }
            for (j = 0; j < nv; j++)
                for (i = 0; i < nu; i++) {
                    int v0 = j * (nu + 1) + i, v1 = v0 + 1, v2 = v0 + nu + 2, v3 = v0 + nu + 1;
                    tm_tri(&q, v0, v1, v2);
                    tm_tri(&q, v0, v2, v3);
                }
            m = NULL;
            if (build(&q, 0, &m, &err) != TT_OK) CHECK(0, "building the rolled sheet: %s", err.message);
            tm_free(&q);
            h = m ? hpm_build(m, 1) : NULL;
            uv = m ? flat_uv(m) : NULL;
            if (h && uv) {
                r = tt_flatten_cluster(m, h, 0, NULL, NULL, uv, &rep, &err);
                CHECK(r == TT_ERROR_NOT_FLAT && !rep.mapped && !rep.polygon_simple && rep.nborder > 0 &&
                          uv[0] == FLAT_SENTINEL && strstr(err.message, what[a]) && strstr(err.message, "not simple"),
                      "a sheet rolled %g degrees: %d, mapped %d, simple %d (%s)", arcs[a], r, rep.mapped,
                      rep.polygon_simple, err.message);
            }
            free(uv);
            tt_cluster_hierarchy_free(h);
            tt_mesh_free(m);
        }
    }
}

/* (11) Refusals, corners outside the cluster, determinism. */
static void test_flatten_clusters(void)
{
    tt_mesh *torus = hpm_mesh(M_TORUS), *holes = hpm_mesh(M_HOLES), *sphere = hpm_mesh(M_SPHERE);
    tt_cluster_hierarchy *ht = torus ? hpm_build(torus, 2) : NULL, *hh = holes ? hpm_build(holes, 2) : NULL;
    float *uv = sphere ? flat_uv(sphere) : NULL, *uv2 = sphere ? flat_uv(sphere) : NULL, *uvt = torus ? flat_uv(torus) : NULL;
    tt_cluster_hierarchy *hs = sphere ? hpm_build(sphere, 2) : NULL;
    tt_flatten_report rep, rep2;
    tt_error err;
    tt_result r, r2;
    int c, i, touched = 0, missing = 0, differ = 0, ok = 0, notflat = 0, tested = 0;
    if (ht && uvt) {
        r = tt_flatten_cluster(torus, ht, 0, NULL, NULL, uvt, &rep, &err);
        CHECK(r == TT_ERROR_INVALID_ARGUMENT && err.item == 0 && !rep.mapped && uvt[0] == FLAT_SENTINEL &&
                  strstr(err.message, "not mappable"),
              "the torus's closed top cluster: %d (%s)", r, err.message);
    }
    if (hh) {
        float *uvh = flat_uv(holes);
        CHECK(!(hh->clusters[0].flags & TT_CLUSTER_DISC), "the grid with two holes is not a disc");
        r = tt_flatten_cluster(holes, hh, 0, NULL, NULL, uvh, &rep, &err);
        CHECK(r == TT_ERROR_INVALID_ARGUMENT && err.item == 0 && strstr(err.message, "not a disc") && uvh &&
                  uvh[0] == FLAT_SENTINEL,
              "a cluster with three border loops: %d (%s)", r, err.message);
        free(uvh);
    }
    if (hs && uv && uv2) {
        r = tt_flatten_cluster(sphere, hs, 0, NULL, NULL, uv, &rep, &err);
        CHECK(r == TT_ERROR_INVALID_ARGUMENT && err.item == 0, "the sphere's closed top cluster: %d", r);
        /* every mappable cluster of level 2, one at a time into fresh buffers */
        for (c = hs->level_start[2]; c < hs->level_start[3] && c < hs->nclusters; c++) {
            const tt_cluster *C = &hs->clusters[c];
            if (!(C->flags & TT_CLUSTER_MAPPABLE)) continue;
            for (i = 0; i < 2 * sphere->ncorners; i++) uv[i] = uv2[i] = FLAT_SENTINEL;
            r = tt_flatten_cluster(sphere, hs, c, NULL, NULL, uv, &rep, &err);
            r2 = tt_flatten_cluster(sphere, hs, c, NULL, NULL, uv2, &rep2, &err);
            tested++;
            if (r != r2 || memcmp(uv, uv2, sizeof(float) * 2 * (size_t)sphere->ncorners) != 0 ||
                memcmp(&rep, &rep2, sizeof rep) != 0)
                differ++;
            if (r == TT_OK) {
                int f, k, j;
                ok++;
                for (f = 0; f < sphere->nfaces; f++) {
                    int in = 0;
                    for (j = 0; j < C->nfaces; j++) in |= hs->faces[C->first_face + j] == f;
                    for (k = 0; k < 3; k++) {
                        int cc = sphere->face_start[f] + k;
                        if (!in && (uv[2 * cc] != FLAT_SENTINEL || uv[2 * cc + 1] != FLAT_SENTINEL)) touched++;
                        if (in && (uv[2 * cc] == FLAT_SENTINEL || !(fabs(uv[2 * cc]) < 100))) missing++;
                    }
                }
                if (rep.flipped != 0) missing++;
            } else if (r == TT_ERROR_NOT_FLAT) {
                notflat++;
                for (i = 0; i < 2 * sphere->ncorners; i++) touched += uv[i] != FLAT_SENTINEL;
            } else {
                DETAIL("cluster %d: unexpected %d (%s)", c, r, err.message);
                missing++;
            }
        }
        CHECK(tested > 5 && ok > 0, "sphere level 2: %d clusters, %d mapped, %d not flat", tested, ok, notflat);
        CHECK(touched == 0 && missing == 0, "sphere level 2: %d corners outside written, %d inside missing", touched,
              missing);
        CHECK(differ == 0, "sphere level 2: %d clusters flatten differently on a second run", differ);
    }
    free(uv);
    free(uv2);
    free(uvt);
    tt_cluster_hierarchy_free(ht);
    tt_cluster_hierarchy_free(hh);
    tt_cluster_hierarchy_free(hs);
    tt_mesh_free(torus);
    tt_mesh_free(holes);
    tt_mesh_free(sphere);
}

typedef struct flat_oom_ctx {
    const tt_mesh *mesh;
    const tt_cluster_hierarchy *h;
    int cluster;
    float *uv;
} flat_oom_ctx;

static tt_result flat_oom_call(void *ctx, const tt_allocator *al, tt_error *error)
{
    flat_oom_ctx *c = (flat_oom_ctx *)ctx;
    tt_flatten_report rep;
    int i;
    tt_result r;
    for (i = 0; i < 2 * c->mesh->ncorners; i++) c->uv[i] = FLAT_SENTINEL;
    r = tt_flatten_cluster(c->mesh, c->h, c->cluster, NULL, al, c->uv, &rep, error);
    if (error->result != r) return TT_RESULT_MAX_ENUM;
    if (r != TT_OK)
        for (i = 0; i < 2 * c->mesh->ncorners; i++)
            if (c->uv[i] != FLAT_SENTINEL) return TT_RESULT_MAX_ENUM;
    return r;
}

/* (12) Errors, and every allocation failing in turn. */
static void test_flatten_errors(void)
{
    tt_mesh *m = flat_tilted_grid(6, 6), *other = flat_tilted_grid(5, 6);
    tt_cluster_hierarchy *h = m ? hpm_build(m, 4) : NULL;
    float *uv = m ? flat_uv(m) : NULL;
    tt_flatten_options opt;
    tt_flatten_report rep;
    tt_allocator half;
    tt_error err;
    tt_result r;
    flat_oom_ctx ctx;
    if (!h || !uv || !other) goto end;
    r = tt_flatten_cluster(NULL, h, 0, NULL, NULL, uv, &rep, &err);
    CHECK(r == TT_ERROR_INVALID_ARGUMENT && err.result == r && err.message[0], "NULL mesh: %d", r);
    r = tt_flatten_cluster(m, NULL, 0, NULL, NULL, uv, &rep, &err);
    CHECK(r == TT_ERROR_INVALID_ARGUMENT && err.result == r, "NULL hierarchy: %d", r);
    r = tt_flatten_cluster(m, h, 0, NULL, NULL, NULL, &rep, &err);
    CHECK(r == TT_ERROR_INVALID_ARGUMENT && err.result == r, "NULL corner_uv: %d", r);
    r = tt_flatten_cluster(m, h, -1, NULL, NULL, uv, &rep, &err);
    CHECK(r == TT_ERROR_INDEX_OUT_OF_RANGE && err.item == -1 && err.result == r, "cluster -1: %d", r);
    r = tt_flatten_cluster(m, h, h->nclusters, NULL, NULL, uv, &rep, &err);
    CHECK(r == TT_ERROR_INDEX_OUT_OF_RANGE && err.item == h->nclusters && msg_has_number(err.message, h->nclusters),
          "cluster nclusters: %d (%s)", r, err.message);
    r = tt_flatten_cluster(other, h, 0, NULL, NULL, uv, &rep, &err);
    CHECK(r == TT_ERROR_INVALID_ARGUMENT && err.result == r, "a hierarchy of another mesh: %d (%s)", r,
          err.message);
    memset(&half, 0, sizeof half);
    half.free = hpm_free_only;
    r = tt_flatten_cluster(m, h, 0, NULL, &half, uv, &rep, &err);
    CHECK(r == TT_ERROR_INVALID_ARGUMENT && err.result == r && strstr(err.message, "alloc"),
          "an allocator with free only: %d", r);
    memset(&opt, 0, sizeof opt);
    opt.max_error = -1;
    r = tt_flatten_cluster(m, h, 0, &opt, NULL, uv, &rep, &err);
    CHECK(r == TT_ERROR_INVALID_ARGUMENT, "max_error -1: %d", r);
    opt.max_error = 0;
    opt.max_stretch = 0.5;
    r = tt_flatten_cluster(m, h, 0, &opt, NULL, uv, &rep, &err);
    CHECK(r == TT_ERROR_INVALID_ARGUMENT, "max_stretch 0.5: %d", r);
    opt.max_stretch = 0;
    opt.border = 2;
    r = tt_flatten_cluster(m, h, 0, &opt, NULL, uv, &rep, &err);
    CHECK(r == TT_ERROR_INVALID_ARGUMENT, "border 2: %d", r);
    opt.border = 0;
    opt.cg_tolerance = 1;
    r = tt_flatten_cluster(m, h, 0, &opt, NULL, uv, &rep, &err);
    CHECK(r == TT_ERROR_INVALID_ARGUMENT, "cg_tolerance 1: %d", r);
    opt.cg_tolerance = 0;
    opt.cg_max_iterations = 1;
    r = tt_flatten_cluster(m, h, 0, &opt, NULL, uv, &rep, &err);
    CHECK(r == TT_ERROR_NOT_CONVERGED && err.result == r && uv[0] == FLAT_SENTINEL,
          "one CG step: %d (%s)", r, err.message);
    r = tt_flatten_cluster(m, h, 0, NULL, NULL, uv, NULL, NULL);
    CHECK(r == TT_OK, "NULL report and error: %d", r);
    CHECK(strcmp(tt_result_string(TT_ERROR_NOT_FLAT), tt_result_string(TT_ERROR_INVALID_ARGUMENT)) != 0,
          "TT_ERROR_NOT_FLAT has its own sentence");

    ctx.mesh = m;
    ctx.h = h;
    ctx.cluster = 0;
    ctx.uv = uv;
    oom_reset();
    oom_sweep("tt_flatten_cluster(6 x 6 grid)", flat_oom_call, &ctx, TT_OK);
end:
    free(uv);
    tt_cluster_hierarchy_free(h);
    tt_mesh_free(m);
    tt_mesh_free(other);
}


/* ------------------------------------------------------------------------ */
/* The pipeline: tt_hpm_map                                                 */
/* ------------------------------------------------------------------------ */

/* A plane folded along x = 0 by `fold` radians (0: flat), nx x ny unit
   quads, triangulated, CCW seen from +z. */
static tt_mesh *hpm_book(int nx, int ny, double fold)
{
    tmesh m;
    tt_mesh *mesh = NULL;
    tt_error err;
    int i, j;
    memset(&m, 0, sizeof m);
    for (j = 0; j <= ny; j++)
        for (i = 0; i <= nx; i++) {
            double x = i - nx / 2.0;
            if (x <= 0)
                tm_vert(&m, x, j, 0);
            else
                tm_vert(&m, x * cos(fold), j, x * sin(fold));
        }
    for (j = 0; j < ny; j++)
        for (i = 0; i < nx; i++) {
            int a = j * (nx + 1) + i, b = a + 1, c = a + nx + 2, d = a + nx + 1;
            tm_tri(&m, a, b, c);
            tm_tri(&m, a, c, d);
        }
    if (build(&m, 0, &mesh, &err) != TT_OK) CHECK(0, "building the book failed: %s", err.message);
    tm_free(&m);
    return mesh;
}

static tt_result hpm_run(const tt_mesh *mesh, const tt_image *im, const tt_hpm_options *o, float **uv,
                         int **cluster, tt_hpm_report *rep)
{
    tt_error err;
    tt_result r;
    *uv = (float *)malloc(sizeof(float) * 2 * (size_t)mesh->ncorners);
    *cluster = (int *)malloc(sizeof(int) * (size_t)mesh->nfaces);
    r = tt_hpm_map(mesh, im, o, NULL, *uv, *cluster, rep, &err);
    CHECK(r == TT_OK, "tt_hpm_map returned %d (%s)", r, err.message);
    return r;
}

/* UV triangles with a signed area <= 0 (v up), and corners that are not
   finite or (bounded) closer than one texel to the border. */
static void hpm_uv_checks(const tt_mesh *mesh, const float *uv, int w, int h, int bounded, int *flipped,
                          int *bad)
{
    int f, k;
    *flipped = *bad = 0;
    for (f = 0; f < mesh->nfaces; f++) {
        const float *a = uv + 2 * mesh->face_start[f], *b = a + 2, *c = a + 4;
        double area = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
        if (!(area > 0)) (*flipped)++;
    }
    for (k = 0; k < mesh->ncorners; k++) {
        double u = uv[2 * k], v = uv[2 * k + 1];
        if (!isfinite(u) || !isfinite(v)) (*bad)++;
        else if (bounded && (u * w < 1 - 1e-3 || u * w > w - 1 + 1e-3 || v * h < 1 - 1e-3 || v * h > h - 1 + 1e-3))
            (*bad)++;
    }
}

/* Largest jump of a vertex's texel position across interior edges. */
static double hpm_max_jump(const tt_mesh *mesh, const float *uv, int w, int h, int periodic)
{
    int c;
    double worst = 0;
    for (c = 0; c < mesh->ncorners; c++) {
        int t = mesh->twin[c], k;
        if (t < 0) continue;
        /* corner c and the corner after t sit on the same vertex */
        k = tt_mesh_next(mesh, t);
        {
            double du = (uv[2 * c] - uv[2 * k]) * w, dv = (uv[2 * c + 1] - uv[2 * k + 1]) * h;
            /* toroidal maps: whole clusters move by whole periods */
            if (periodic) {
                du -= w * floor(du / w + 0.5);
                dv -= h * floor(dv / h + 0.5);
            }
            double d = sqrt(du * du + dv * dv);
            if (d > worst) worst = d;
        }
    }
    return worst;
}

/* sigma1 / sigma2 of face f's map from the surface to texels (a large
   number for a degenerate one), recomputed here from positions and UVs. */
static double hpm_face_stretch(const tt_mesh *m, const float *uv, int f, int w, int h)
{
    const float *p0 = m->pos + 3 * m->corner_vert[3 * f], *p1 = m->pos + 3 * m->corner_vert[3 * f + 1],
                *p2 = m->pos + 3 * m->corner_vert[3 * f + 2];
    double e1[3], e2[3], cr[3], l1, x2, y2, a, b, c, d, E, G, F, tr, det, s1, s2;
    int k;
    for (k = 0; k < 3; k++) {
        e1[k] = p1[k] - p0[k];
        e2[k] = p2[k] - p0[k];
    }
    cr[0] = e1[1] * e2[2] - e1[2] * e2[1];
    cr[1] = e1[2] * e2[0] - e1[0] * e2[2];
    cr[2] = e1[0] * e2[1] - e1[1] * e2[0];
    l1 = sqrt(e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2]);
    x2 = (e1[0] * e2[0] + e1[1] * e2[1] + e1[2] * e2[2]) / l1;
    y2 = sqrt(cr[0] * cr[0] + cr[1] * cr[1] + cr[2] * cr[2]) / l1;
    /* the map's Jacobian in the triangle's own frame (e1 along x) */
    a = (uv[6 * f + 2] - uv[6 * f]) * w / l1;
    c = (uv[6 * f + 3] - uv[6 * f + 1]) * h / l1;
    b = ((uv[6 * f + 4] - uv[6 * f]) * w - a * x2) / y2;
    d = ((uv[6 * f + 5] - uv[6 * f + 1]) * h - c * x2) / y2;
    E = a * a + c * c;
    G = b * b + d * d;
    F = a * b + c * d;
    tr = E + G;
    det = sqrt((E - G) * (E - G) + 4 * F * F);
    s1 = sqrt(0.5 * (tr + det));
    s2 = sqrt(fmax(0.0, 0.5 * (tr - det)));
    return s2 > 1e-12 * s1 ? s1 / s2 : 1e12;
}

/* No shards at a crease: a book folded by 90 degrees, at a scale where
   clusters span the fold. E_flat weighs areas only, so a cluster folded
   over the crease passed it while the flattening squashed the triangles
   along its border: 1 and 14 triangles were stretched past 2 (up to 11)
   at seeds 1 and 2. Now no triangle is (measured: at most 1.25). Control:
   the book projected on its first page (the folded page squashed onto
   the fold line) fails the same check. */
static void test_hpm_map_crease(void)
{
    tt_mesh *mesh = hpm_book(40, 24, 1.5707963267948966);
    tt_image *im = NULL;
    tt_hpm_options o;
    tt_hpm_report rep;
    float *uv = NULL;
    int *cl = NULL, f, t, past, c;
    double worst;
    make_value_noise(&im, 160, 120, 6);
    if (!mesh || !im) goto done;
    for (t = 0; t < 2; t++) {
        memset(&o, 0, sizeof o);
        o.seed = (uint64_t)(1 + t);
        o.scale = 20;
        if (hpm_run(mesh, im, &o, &uv, &cl, &rep) != TT_OK) break;
        worst = 0;
        past = 0;
        for (f = 0; f < mesh->nfaces; f++) {
            double s = hpm_face_stretch(mesh, uv, f, 160, 120);
            if (s > worst) worst = s;
            past += s > 2;
        }
        CHECK(past == 0, "seed %d: %d triangles stretched past 2 (the largest %g)", (int)o.seed, past, worst);
        free(uv);
        free(cl);
        uv = NULL;
        cl = NULL;
    }
    /* the control */
    uv = (float *)malloc(sizeof(float) * 2 * (size_t)mesh->ncorners);
    if (!uv) goto done;
    for (c = 0; c < mesh->ncorners; c++) {
        const float *p = mesh->pos + 3 * mesh->corner_vert[c];
        uv[2 * c] = 0.5f + p[0] / 160.0f;
        uv[2 * c + 1] = 0.2f + p[1] / 120.0f;
    }
    past = 0;
    for (f = 0; f < mesh->nfaces; f++) past += hpm_face_stretch(mesh, uv, f, 160, 120) > 2;
    CHECK(past >= mesh->nfaces / 3, "the projected book: %d of %d triangles past 2 (the control: at least a third)",
          past, mesh->nfaces);
done:
    free(uv);
    free(cl);
    tt_image_free(im);
    tt_mesh_free(mesh);
}

/* A plane that fits in a bounded image maps as one undistorted piece. */
static void test_hpm_map_plane(void)
{
    tt_mesh *mesh = hpm_book(30, 20, 0);
    tt_image *im = NULL;
    tt_hpm_options o;
    tt_hpm_report rep;
    float *uv = NULL;
    int *cl = NULL, f, flipped, bad, differ = 0;
    double worst = 0;
    make_value_noise(&im, 96, 80, 3);
    memset(&o, 0, sizeof o);
    o.scale = 60; /* 30 units across = half the image */
    if (!mesh || !im || hpm_run(mesh, im, &o, &uv, &cl, &rep) != TT_OK) goto done;
    CHECK(rep.clusters == 1 && rep.fits == 0 && rep.starts == 1, "one cluster, placed once (%d clusters, %d fits)",
          rep.clusters, rep.fits);
    for (f = 1; f < mesh->nfaces; f++) differ += cl[f] != cl[0];
    CHECK(differ == 0 && cl[0] >= 0, "every face shows cluster %d (%d differ)", cl[0], differ);
    CHECK(near(rep.texels_per_unit, 96.0 / 60, 1e-12), "texel density %g", rep.texels_per_unit);
    /* A similarity: texel distances are world distances times the density. */
    for (f = 0; f < mesh->nfaces; f++) {
        int c = mesh->face_start[f], k;
        for (k = 0; k < 3; k++) {
            int a = c + k, b = c + (k + 1) % 3;
            const float *pa = mesh->pos + 3 * mesh->corner_vert[a], *pb = mesh->pos + 3 * mesh->corner_vert[b];
            double d3 = sqrt((pa[0] - pb[0]) * (pa[0] - pb[0]) + (pa[1] - pb[1]) * (pa[1] - pb[1]));
            double du = (uv[2 * a] - uv[2 * b]) * 96, dv = (uv[2 * a + 1] - uv[2 * b + 1]) * 80;
            double e = fabs(sqrt(du * du + dv * dv) - d3 * 96 / 60);
            if (e > worst) worst = e;
        }
    }
    CHECK(worst < 1e-3, "edge lengths kept to %g texels", worst);
    CHECK(hpm_max_jump(mesh, uv, 96, 80, 0) < 1e-3, "no UV discontinuity inside the plane (%g texels)",
          hpm_max_jump(mesh, uv, 96, 80, 0));
    hpm_uv_checks(mesh, uv, 96, 80, 1, &flipped, &bad);
    CHECK(flipped == 0 && bad == 0, "%d flipped, %d corners outside the image's margin", flipped, bad);
done:
    free(uv);
    free(cl);
    tt_image_free(im);
    tt_mesh_free(mesh);
}

/* With TT_HPM_EXACT_CONTINUATION and one orientation, a cluster next to a
   textured one is placed as its exact continuation, so a folded sheet (two
   planes, neither flat across the fold) comes out as one continuous map;
   with the default exclusion of that continuation it does not. */
static void test_hpm_map_continuation(void)
{
    tt_mesh *mesh = hpm_book(40, 24, 1.2);
    tt_image *im = NULL;
    tt_hpm_options o;
    tt_hpm_report rep;
    float *uv = NULL;
    int *cl = NULL, flipped, bad;
    make_value_noise(&im, 64, 64, 5);
    memset(&o, 0, sizeof o);
    o.scale = 20;
    o.rotations = 1;
    o.flags = TT_HPM_TOROIDAL | TT_HPM_EXACT_CONTINUATION;
    o.min_faces = 4;
    o.min_footprint = 16;
    /* only exactly planar clusters: a cluster across the fold flattens
       with a little distortion, and its continuation is then not exact */
    o.max_flattening_error = 1e-9;
    if (!mesh || !im || hpm_run(mesh, im, &o, &uv, &cl, &rep) != TT_OK) goto done;
    CHECK(rep.fits >= 2, "the sheet needs fits (%d, %d clusters)", rep.fits, rep.clusters);
    CHECK(rep.max_error < 1e-4, "continuations fit exactly (largest eps %g)", rep.max_error);
    CHECK(hpm_max_jump(mesh, uv, 64, 64, 1) < 0.01, "the map is continuous across every border (%g texels)",
          hpm_max_jump(mesh, uv, 64, 64, 1));
    hpm_uv_checks(mesh, uv, 64, 64, 0, &flipped, &bad);
    CHECK(flipped == 0 && bad == 0, "%d flipped, %d non-finite", flipped, bad);
    free(uv);
    free(cl);
    uv = NULL;
    cl = NULL;
    o.flags = TT_HPM_TOROIDAL;
    if (hpm_run(mesh, im, &o, &uv, &cl, &rep) != TT_OK) goto done;
    CHECK(rep.fits >= 2 && rep.max_error > 1e-3, "without the switch no fit is the exact continuation (eps %g)",
          rep.max_error);
    CHECK(hpm_max_jump(mesh, uv, 64, 64, 1) > 1, "and the borders show (%g texels)", hpm_max_jump(mesh, uv, 64, 64, 1));
done:
    free(uv);
    free(cl);
    tt_image_free(im);
    tt_mesh_free(mesh);
}

/* The relaxation's classes, against the pairwise definition: on a torus
   and a sphere (poles of high valence), with every vertex on the border or
   every third, no two vertices of a class share a face, every vertex is
   in exactly one class, the classes come out sorted by (class, vertex),
   the border vertices' marks are cleared and the others' left alone. */
static void test_hpm_relax_classes(void)
{
    int which;
    for (which = 0; which < 2; which++) {
        tt_mesh *mesh = hpm_mesh(which == 0 ? M_TORUS : M_SPHERE);
        int step;
        for (step = 1; step <= 3 && mesh; step += 2) {
            int *vmark = (int *)malloc(sizeof(int) * (size_t)mesh->nverts);
            int *verts = (int *)malloc(sizeof(int) * (size_t)mesh->nverts);
            int *class_end = (int *)malloc(sizeof(int) * (size_t)mesh->nverts);
            int *cls = (int *)malloc(sizeof(int) * (size_t)mesh->nverts);
            int n = 0, v, k, f, c, d, nclasses, conflicts = 0, misplaced = 0, marks_changed = 0;
            if (!verts || !class_end || !cls || !vmark) abort();
            for (v = 0; v < mesh->nverts; v++) {
                vmark[v] = v % 5 == 0 ? -1 : v; /* what the other uses leave */
                cls[v] = -1;
                if (v % step == 0) verts[n++] = v;
            }
            nclasses = internal_hpm_relax_classes(mesh, vmark, verts, n, class_end);
            CHECK(nclasses >= 2 && nclasses <= 16 && class_end[nclasses - 1] == n,
                  "mesh %d step %d: %d classes ending at %d of %d", which, step, nclasses,
                  nclasses > 0 ? class_end[nclasses - 1] : -1, n);
            for (k = 0; k < nclasses; k++)
                for (c = k == 0 ? 0 : class_end[k - 1]; c < class_end[k]; c++) {
                    misplaced += cls[verts[c]] != -1 || (c > (k == 0 ? 0 : class_end[k - 1]) && verts[c] <= verts[c - 1]);
                    cls[verts[c]] = k;
                }
            for (v = 0; v < mesh->nverts; v++) {
                misplaced += (v % step == 0) != (cls[v] >= 0);
                marks_changed += vmark[v] != (v % step == 0 ? 0 : v % 5 == 0 ? -1 : v);
            }
            for (f = 0; f < mesh->nfaces; f++)
                for (c = mesh->face_start[f]; c < mesh->face_start[f + 1]; c++)
                    for (d = c + 1; d < mesh->face_start[f + 1]; d++) {
                        int a = cls[mesh->corner_vert[c]], b = cls[mesh->corner_vert[d]];
                        conflicts += a >= 0 && a == b;
                    }
            CHECK(conflicts == 0 && misplaced == 0,
                  "mesh %d step %d: %d face-sharing pairs in one class, %d vertices misplaced", which, step, conflicts,
                  misplaced);
            CHECK(marks_changed == 0, "mesh %d step %d: %d vertex marks wrong after", which, step,
                  marks_changed);
            free(verts);
            free(class_end);
            free(cls);
            free(vmark);
        }
        tt_mesh_free(mesh);
    }
}

/* The executor runs the hierarchy's splits, each fit's turned copies,
   the relaxation's classes and the border choice's sweeps (ranges of
   faces) as tasks: the same UVs and
   clusters, bit for bit, whether they run serially, in reverse order or on
   two threads; with the default bands (summed directly) and with wide ones
   on a toroidal image (large clusters: their correlations by transforms). */
static void test_hpm_map_executor(void)
{
    tt_mesh *mesh = hpm_mesh(M_SPHERE);
    tt_image *im = NULL;
    const tt_executor *executors[3];
    int config, e;
    executors[0] = NULL;
    executors[1] = &g_reverse_executor;
    executors[2] = &g_thread_executor;
    make_value_noise(&im, 128, 128, 9);
    for (config = 0; config < 2 && mesh && im; config++) {
        float *uv[3] = {NULL, NULL, NULL};
        int *cl[3] = {NULL, NULL, NULL};
        tt_hpm_report rep[3];
        tt_hpm_options o;
        memset(&o, 0, sizeof o);
        o.scale = config == 0 ? 6 : 3;
        if (config == 1) {
            o.band = 24;
            o.max_turn = 180;
            o.flags = TT_HPM_TOROIDAL;
        }
        for (e = 0; e < 3; e++) {
            o.executor = executors[e];
            if (hpm_run(mesh, im, &o, &uv[e], &cl[e], &rep[e]) != TT_OK) break;
        }
        if (e == 3) {
            CHECK(rep[0].fits > 10, "configuration %d fits %d clusters (more than 10)", config, rep[0].fits);
            CHECK(rep[0].faces_moved > 0 && mesh->nfaces > 2 * 256,
                  "configuration %d: faces change sides at borders (%d), in several ranges of 256 (%d faces)",
                  config, rep[0].faces_moved, mesh->nfaces);
            for (e = 1; e < 3; e++)
                CHECK(memcmp(uv[0], uv[e], sizeof(float) * 2 * (size_t)mesh->ncorners) == 0 &&
                          memcmp(cl[0], cl[e], sizeof(int) * (size_t)mesh->nfaces) == 0 &&
                          rep[0].fits == rep[e].fits && rep[0].mean_error == rep[e].mean_error,
                      "configuration %d: the %s executor gives the serial UVs bit for bit", config,
                      e == 1 ? "reverse-order" : "two-thread");
        }
        for (e = 0; e < 3; e++) {
            free(uv[e]);
            free(cl[e]);
        }
    }
    tt_image_free(im);
    tt_mesh_free(mesh);
}

/* Seams on cluster borders: the fit against random placement of the same
   clusters (the control must score much worse). */
static void test_hpm_map_seams(void)
{
    tt_mesh *mesh = hpm_mesh(M_SPHERE);
    tt_image *im = NULL;
    tt_hpm_options o;
    tt_hpm_report rep, rep_random;
    tt_seam_options so;
    tt_seam_report fit, rnd;
    float *uv = NULL, *uv_random = NULL;
    int *cl = NULL, *cl_random = NULL, f, same = 1, flipped, bad;
    make_value_noise(&im, 128, 128, 9);
    memset(&o, 0, sizeof o);
    o.scale = 6;
    if (!mesh || !im || hpm_run(mesh, im, &o, &uv, &cl, &rep) != TT_OK) goto done;
    o.flags = TT_HPM_RANDOM_PLACEMENT;
    if (hpm_run(mesh, im, &o, &uv_random, &cl_random, &rep_random) != TT_OK) goto done;
    for (f = 0; f < mesh->nfaces; f++) same &= cl[f] == cl_random[f];
    CHECK(same && rep.clusters == rep_random.clusters && rep.clusters > 4,
          "the control textures the same %d clusters", rep.clusters);
    hpm_uv_checks(mesh, uv, 128, 128, 1, &flipped, &bad);
    CHECK(flipped == 0 && bad == 0, "fit: %d flipped, %d corners outside the margin", flipped, bad);
    hpm_uv_checks(mesh, uv_random, 128, 128, 1, &flipped, &bad);
    CHECK(flipped == 0 && bad == 0, "control: %d flipped, %d corners outside the margin", flipped, bad);
    /* On the cluster borders only (inside a cluster the map is
       continuous, which would dilute the score) */
    memset(&so, 0, sizeof so);
    so.flags = TT_SEAM_UV_DISCONTINUOUS;
    CHECK(tt_measure_seams(mesh, uv, im, &so, NULL, &fit, NULL) == TT_OK &&
              tt_measure_seams(mesh, uv_random, im, &so, NULL, &rnd, NULL) == TT_OK,
          "seams measured");
    /* the control jumps on every cluster border; the fit on most (where it
       closed a crack the border is continuous, no seam at all, and it is
       left out: the score is over the harder rest) */
    CHECK(fit.edges_discontinuous > 50 && fit.edges_discontinuous <= rnd.edges_discontinuous &&
              fit.edges_discontinuous >= 0.8 * rnd.edges_discontinuous,
          "the border edges: %d of the control's %d", fit.edges_discontinuous, rnd.edges_discontinuous);
    printf("     seams on %d cluster-border edges: fitted %.3f, placed at random %.3f\n", fit.edges_discontinuous,
           fit.score, rnd.score);
    CHECK(fit.score <= 0.3, "fitted borders score %g (at most 0.3)", fit.score);
    CHECK(rnd.score >= 0.8, "the control's borders score %g (at least 0.8)", rnd.score);
    /* Stretch and texel density */
    {
        tt_uv_distortion_options dop;
        tt_uv_distortion_report d;
        memset(&dop, 0, sizeof dop);
        dop.texels_per_unit = rep.texels_per_unit;
        CHECK(tt_measure_uv_distortion(mesh, uv, 128, 128, &dop, NULL, &d, NULL) == TT_OK, "distortion measured");
        CHECK(d.stretch_median <= 1.15 && d.stretch_p95 <= 1.6 && d.density_median <= 0.10 && d.flipped == 0,
              "stretch median %g (<= 1.15), p95 %g (<= 1.6), density error median %g (<= 0.1), %d flipped",
              d.stretch_median, d.stretch_p95, d.density_median, d.flipped);
    }
done:
    free(uv);
    free(uv_random);
    free(cl);
    free(cl_random);
    tt_image_free(im);
    tt_mesh_free(mesh);
}

/* A 256-texel grey noise of 3-texel grains (a fine stochastic photo, as
   gravel is), or NULL. */
static tt_image *fine_grain_image(void)
{
    tt_image *im = NULL;
    float *w = (float *)malloc(sizeof(float) * 256 * 256);
    int x, y;
    if (!w || tt_image_create(256, 256, NULL, &im, NULL) != TT_OK) {
        free(w);
        return NULL;
    }
    lcg_seed(17);
    for (x = 0; x < 256 * 256; x++) w[x] = (float)lcg_unit();
    for (y = 0; y < 256; y++)
        for (x = 0; x < 256; x++) {
            float *p = px(im, x, y), a = 0;
            int dx, dy;
            for (dy = 0; dy < 3; dy++)
                for (dx = 0; dx < 3; dx++) a += w[((y + dy) % 256) * 256 + (x + dx) % 256];
            p[0] = p[1] = p[2] = a / 9;
            p[3] = 1;
        }
    free(w);
    return im;
}

/* A fine stochastic photo on a plane of n x n squares (two triangles
   each), seeds 0 and 1 with `threshold`: the mean border seam score of
   the fits and of the control placed at random, and the clusters that
   continued a neighbour (below the floor, or in place of a fit) and of
   those, how many in place of a fit under the threshold. */
static void fine_grain_run(int n, float threshold, double *seams, double *seams_random, int *continued,
                           int *instead_of_accepted, int *clusters)
{
    tmesh m;
    tt_mesh *mesh = NULL;
    tt_image *im = fine_grain_image();
    tt_error err;
    int seed;
    *seams = *seams_random = 0.0;
    *continued = *instead_of_accepted = *clusters = 0;
    memset(&m, 0, sizeof m);
    hpm_grid(&m, n, n, NULL, 0.0);
    if (build(&m, 0, &mesh, &err) != TT_OK) CHECK(0, "building the grid: %s", err.message);
    tm_free(&m);
    for (seed = 0; seed < 2 && mesh && im; seed++) {
        tt_hpm_options o;
        tt_hpm_report rep;
        tt_seam_options so;
        tt_seam_report fit, rnd;
        float *uv = NULL, *uv_random = NULL;
        int *cl = NULL, *cl_random = NULL;
        memset(&o, 0, sizeof o);
        o.seed = (uint64_t)seed;
        o.threshold = threshold;
        memset(&so, 0, sizeof so);
        so.flags = TT_SEAM_UV_DISCONTINUOUS;
        if (hpm_run(mesh, im, &o, &uv, &cl, &rep) == TT_OK) {
            o.flags = TT_HPM_RANDOM_PLACEMENT;
            if (hpm_run(mesh, im, &o, &uv_random, &cl_random, NULL) == TT_OK &&
                tt_measure_seams(mesh, uv, im, &so, NULL, &fit, NULL) == TT_OK &&
                tt_measure_seams(mesh, uv_random, im, &so, NULL, &rnd, NULL) == TT_OK) {
                printf("     %d x %d, threshold %g, seed %d: %d clusters, %d at the floor, %d accepted; %d continued, "
                       "%d in place of a floor fit, %d of an accepted one; border seams %.3f, at random %.3f\n",
                       n, n, (double)threshold, seed, rep.clusters, rep.floor_fits, rep.accepted_fits, rep.continued,
                       rep.floor_continued, rep.accepted_continued, fit.score, rnd.score);
                *seams += fit.score / 2;
                *seams_random += rnd.score / 2;
                *continued += rep.continued + rep.floor_continued + rep.accepted_continued;
                *instead_of_accepted += rep.accepted_continued;
                *clusters += rep.clusters;
            } else
                CHECK(0, "seed %d: the control or the seams failed", seed);
        }
        free(uv);
        free(uv_random);
        free(cl);
        free(cl_random);
    }
    tt_image_free(im);
    tt_mesh_free(mesh);
}

/* A fine stochastic photo (gravel: grains of a few texels). The fit
   matches the band on the image box-filtered to match_size (128), where
   grains of 3 texels of a 256-texel image are gone, so its borders are
   unrelated texel for texel; a neighbour's continuation is exact along
   that neighbour. A fit that is taken competes with the continuations by
   the colour mismatch along the borders.
   - At the floor (the default threshold, which these fits pass only
     there): before, every floor cluster of this plane took its fit (0 or
     1 continued; border seams 0.345 and 0.389 for seeds 0 and 1), now a
     sixth or more give way (seams 0.266, 0.227).
   - Above the floor (a threshold every fit passes, on a plane of more,
     smaller faces, so that clusters are fitted before the floor): fits
     under the threshold give way too (10 to 12 of about 50): seams 0.063
     and 0.105, 0.084 on average. When only floor fits competed, none
     continued: 0.149 and 0.097, 0.123 on average.
   The control, placed at random, scores about 1. */
static void test_hpm_map_fine_grain(void)
{
    double seams, seams_random;
    int continued, instead_of_accepted, clusters;
    fine_grain_run(32, 0.0f, &seams, &seams_random, &continued, &instead_of_accepted, &clusters);
    CHECK(continued >= clusters / 6, "%d of %d clusters continued (at least a sixth)", continued, clusters);
    CHECK(seams <= 0.31, "fine grain: border seams %g on average (at most 0.31)", seams);
    CHECK(seams_random >= 0.8, "fine grain, the control: %g on average (at least 0.8)", seams_random);
    fine_grain_run(64, 1.0f, &seams, &seams_random, &continued, &instead_of_accepted, &clusters);
    CHECK(instead_of_accepted > 0, "fits under the threshold: %d gave way to a continuation", instead_of_accepted);
    CHECK(seams <= 0.10, "fine grain above the floor: border seams %g on average (at most 0.10)", seams);
    CHECK(seams_random >= 0.8, "fine grain above the floor, the control: %g on average (at least 0.8)", seams_random);
}

/* Per face of a mesh in the z = 0 plane: the angle (radians, mod pi) of
   the world direction along which u stays constant - the direction of the
   image's vertical stripes on the surface. */
static double hpm_stripe_angle(const tt_mesh *mesh, const float *uv, int f, int w)
{
    int c = mesh->face_start[f];
    const float *p0 = mesh->pos + 3 * mesh->corner_vert[c], *p1 = mesh->pos + 3 * mesh->corner_vert[c + 1],
                *p2 = mesh->pos + 3 * mesh->corner_vert[c + 2];
    double x1 = p1[0] - p0[0], y1 = p1[1] - p0[1], x2 = p2[0] - p0[0], y2 = p2[1] - p0[1];
    double u1 = (uv[2 * c + 2] - uv[2 * c]) * w, u2 = (uv[2 * c + 4] - uv[2 * c]) * w;
    double det = x1 * y2 - x2 * y1, gx = (u1 * y2 - u2 * y1) / det, gy = (x1 * u2 - x2 * u1) / det;
    double a = atan2(gx, -gy); /* perpendicular to grad u */
    return a - 3.14159265358979323846 * floor(a / 3.14159265358979323846);
}

static int hpm_double_compare(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : (x > y);
}

/* Median turn (degrees, 0..90) of the stripe direction across the edges
   between clusters. */
static double hpm_median_turn(const tt_mesh *mesh, const float *uv, const int *cl, int w, int *count)
{
    double *d = (double *)malloc(sizeof(double) * (size_t)mesh->ncorners), m = 180;
    int c, n = 0;
    for (c = 0; d && c < mesh->ncorners; c++) {
        int t = mesh->twin[c], f = mesh->corner_face[c], g;
        double a;
        if (t < 0) continue;
        g = mesh->corner_face[t];
        if (f > g || cl[f] == cl[g]) continue;
        a = fabs(hpm_stripe_angle(mesh, uv, f, w) - hpm_stripe_angle(mesh, uv, g, w)) * 180 / 3.14159265358979323846;
        if (a > 90) a = 180 - a;
        d[n++] = a;
    }
    if (n > 0) {
        qsort(d, (size_t)n, sizeof *d, hpm_double_compare);
        m = d[n / 2];
    }
    *count = n;
    free(d);
    return m;
}

/* The orientation propagates. Vertical stripes on a plane split into
   many clusters keep their direction across the borders (median turn at
   most 10 degrees; the fit tries turns of 0, +-19 and +-38 degrees); the
   same clusters placed at random turn by about 45 degrees. */
static void test_hpm_map_orientation(void)
{
    tt_mesh *mesh = hpm_book(60, 40, 0);
    tt_image *im = NULL;
    tt_hpm_options o;
    tt_hpm_report rep;
    float *uv = NULL;
    int *cl = NULL, x, y, edges;
    double turn;
    CHECK(tt_image_create(128, 128, NULL, &im, NULL) == TT_OK, "image");
    if (!mesh || !im) goto done;
    for (y = 0; y < 128; y++)
        for (x = 0; x < 128; x++) {
            float *p = im->pixels + 4 * (y * 128 + x);
            /* stripes 8 texels apart, their widths varying so that places differ */
            double v = 0.5 + 0.4 * sin(x * 0.785398 + 0.8 * sin(y * 0.09) + 0.5 * sin(x * 0.031 + y * 0.05));
            p[0] = p[1] = p[2] = (float)v;
            p[3] = 1;
        }
    memset(&o, 0, sizeof o);
    o.scale = 20; /* the plane is three image widths across */
    o.seed = 4;
    if (hpm_run(mesh, im, &o, &uv, &cl, &rep) != TT_OK) goto done;
    turn = hpm_median_turn(mesh, uv, cl, 128, &edges);
    CHECK(rep.clusters >= 4 && edges > 20, "%d clusters, %d border edges", rep.clusters, edges);
    printf("     stripes across %d cluster-border edges turn by %.1f degrees (median)", edges, turn);
    CHECK(turn <= 10, "the stripes turn by %g degrees across borders (median; at most 10)", turn);
    free(uv);
    free(cl);
    o.flags = TT_HPM_RANDOM_PLACEMENT;
    if (hpm_run(mesh, im, &o, &uv, &cl, &rep) != TT_OK) goto done;
    turn = hpm_median_turn(mesh, uv, cl, 128, &edges);
    printf(", placed at random %.1f\n", turn);
    CHECK(turn >= 25, "placed at random they turn by %g degrees (median; at least 25)", turn);
done:
    free(uv);
    free(cl);
    tt_image_free(im);
    tt_mesh_free(mesh);
}

/* Bricks in running bond, courses along x: level when the image's up is
   the surface's up. Tiles with period w (a multiple of 16). */
static void hpm_bricks(tt_image *im)
{
    int x, y;
    for (y = 0; y < im->height; y++)
        for (x = 0; x < im->width; x++) {
            float *p = im->pixels + 4 * ((size_t)y * im->width + x);
            int course = y / 8, mortar = y % 8 < 2 || (x + 8 * (course % 2)) % 16 < 2;
            float v = mortar ? 0.85f : 0.25f + 0.1f * (float)((x / 16 + 3 * course) % 4);
            p[0] = v;
            p[1] = 0.6f * v;
            p[2] = 0.5f * v;
            p[3] = 1;
        }
}

/* tt_measure_uv_direction against maps whose answer is known: a wall (the
   plane x-z, up z) mapped with v along z lies level, turned by 30 degrees
   it does not, upside down it lies level again (between lines), and the
   rows read the same; sheared, the image's up and the rows part (each
   case the other's control); a floor has no wall face. */
static void test_uv_direction_measure(void)
{
    tmesh m;
    tt_mesh *wall = NULL, *floor_mesh = NULL;
    tt_uv_direction_options o;
    tt_uv_direction_report r;
    tt_error err;
    float *uv = NULL;
    int f, k;
    const int turns[3] = {0, 30, 180};
    for (k = 0; k < 2; k++) {
        /* 6 x 4 squares, two triangles each: a floor (z = 0), then a wall (y = 0) */
        int i, j;
        memset(&m, 0, sizeof m);
        for (j = 0; j <= 4; j++)
            for (i = 0; i <= 6; i++) tm_vert(&m, i, k ? 0 : j, k ? j : 0);
        for (j = 0; j < 4; j++)
            for (i = 0; i < 6; i++) {
                int a = j * 7 + i;
                tm_tri(&m, a, a + 1, a + 8);
                tm_tri(&m, a, a + 8, a + 7);
            }
        CHECK(build(&m, 0, k ? &wall : &floor_mesh, NULL) == TT_OK, "mesh %d", k);
        tm_free(&m);
    }
    if (!wall || !floor_mesh) goto done;
    uv = (float *)malloc(sizeof(float) * 2 * (size_t)wall->ncorners);
    memset(&o, 0, sizeof o);
    o.up[2] = 1;
    for (k = 0; k < 3; k++) {
        double a = turns[k] * 3.14159265358979323846 / 180;
        for (f = 0; f < wall->ncorners; f++) {
            const float *p = wall->pos + 3 * wall->corner_vert[f];
            uv[2 * f] = (float)(0.1 * (cos(a) * p[0] - sin(a) * p[2]));
            uv[2 * f + 1] = (float)(0.1 * (sin(a) * p[0] + cos(a) * p[2]));
        }
        CHECK(tt_measure_uv_direction(wall, uv, 64, 64, &o, NULL, &r, &err) == TT_OK, "measured: %s",
              err.message);
        CHECK(r.faces == wall->nfaces && near(r.mean, turns[k] == 30 ? 30 : 0, 1e-3) &&
                  near(r.p90, r.mean, 1e-3) && r.within == (turns[k] == 30 ? 0.0 : 1.0) && r.singular == 0,
              "turned %d degrees: %d faces, mean %g, p90 %g, within %g", turns[k], r.faces, r.mean, r.p90, r.within);
        CHECK(near(r.rows_mean, r.mean, 1e-3) && near(r.rows_p90, r.p90, 1e-3) && r.rows_within == r.within,
              "turned %d degrees, the rows read the same: mean %g, p90 %g, within %g", turns[k], r.rows_mean,
              r.rows_p90, r.rows_within);
    }
    /* Sheared: rows level, head joints leaning 30 degrees (u = x + z tan 30,
       v = z) read 30 by the image's up and 0 by the rows; the converse
       (u = x, v = z + x tan 30, rows rising) 0 and 30. */
    for (k = 0; k < 2; k++) {
        const double lean = tan(30 * 3.14159265358979323846 / 180);
        for (f = 0; f < wall->ncorners; f++) {
            const float *p = wall->pos + 3 * wall->corner_vert[f];
            uv[2 * f] = (float)(0.1 * (p[0] + (k ? 0.0 : lean * p[2])));
            uv[2 * f + 1] = (float)(0.1 * (p[2] + (k ? lean * p[0] : 0.0)));
        }
        CHECK(tt_measure_uv_direction(wall, uv, 64, 64, &o, NULL, &r, &err) == TT_OK &&
                  near(r.mean, k ? 0 : 30, 1e-3) && near(r.rows_mean, k ? 30 : 0, 1e-3) &&
                  r.rows_within == (k ? 0.0 : 1.0),
              "sheared %s: the image's up %g degrees, the rows %g (%d and %d expected)",
              k ? "with the rows rising" : "with the rows level", r.mean, r.rows_mean, k ? 0 : 30, k ? 30 : 0);
    }
    /* Quads (a tiling's faces) are measured as their fans: the same wall in
       quads reads 30 degrees turned; each quad's corners' UVs passed on by
       one (its tile turned a quarter) read 90. */
    {
        tt_mesh *quads = NULL;
        float *quad_uv;
        int i, j;
        memset(&m, 0, sizeof m);
        for (j = 0; j <= 4; j++)
            for (i = 0; i <= 6; i++) tm_vert(&m, i, 0, j);
        for (j = 0; j < 4; j++)
            for (i = 0; i < 6; i++) tm_quad(&m, j * 7 + i, j * 7 + i + 1, j * 7 + i + 8, j * 7 + i + 7);
        CHECK(build(&m, 0, &quads, NULL) == TT_OK, "quad wall");
        tm_free(&m);
        quad_uv = quads ? (float *)malloc(sizeof(float) * 2 * (size_t)quads->ncorners) : NULL;
        for (k = 0; quad_uv && k < 2; k++) {
            double a = 30 * 3.14159265358979323846 / 180;
            for (f = 0; f < quads->ncorners; f++) {
                const int c = k ? quads->face_start[f / 4] + (f % 4 + 1) % 4 : f;
                const float *p = quads->pos + 3 * quads->corner_vert[c];
                quad_uv[2 * f] = (float)(0.1 * (cos(a) * p[0] - sin(a) * p[2]));
                quad_uv[2 * f + 1] = (float)(0.1 * (sin(a) * p[0] + cos(a) * p[2]));
            }
            CHECK(tt_measure_uv_direction(quads, quad_uv, 64, 64, &o, NULL, &r, &err) == TT_OK &&
                      r.faces == quads->nfaces && near(r.mean, k ? 60 : 30, 1e-3) && r.within == 0.0,
                  "quads turned 30 degrees%s: %d faces, mean %g (%d expected)", k ? " and a quarter" : "", r.faces,
                  r.mean, k ? 60 : 30);
        }
        free(quad_uv);
        tt_mesh_free(quads);
    }
    /* a non-square image weighs its axes: turned 45 degrees in (u, v), the
       map is turned atan(1/2) = 26.6 degrees in texels of a 64 x 128 image */
    for (f = 0; f < wall->ncorners; f++) {
        const float *p = wall->pos + 3 * wall->corner_vert[f];
        uv[2 * f] = (float)(0.1 * (p[0] + p[2]));
        uv[2 * f + 1] = (float)(0.1 * (p[2] - p[0]));
    }
    CHECK(tt_measure_uv_direction(wall, uv, 64, 128, &o, NULL, &r, NULL) == TT_OK &&
              near(r.mean, 26.565, 0.01),
          "64 x 128 texels: %g degrees (26.57)", r.mean);
    for (f = 0; f < wall->ncorners; f++) uv[2 * f] = uv[2 * f + 1] = 0.5f;
    CHECK(tt_measure_uv_direction(wall, uv, 64, 64, &o, NULL, &r, NULL) == TT_OK && r.singular == wall->nfaces &&
              r.mean == 90 && r.within == 0 && r.rows_mean == 90 && r.rows_within == 0,
          "a collapsed map counts as 90 degrees: %d singular, mean %g, rows %g", r.singular, r.mean, r.rows_mean);
    CHECK(tt_measure_uv_direction(floor_mesh, uv, 64, 64, &o, NULL, &r, &err) == TT_ERROR_NOT_MEASURED &&
              r.faces == 0 && r.mean != r.mean && r.rows_mean != r.rows_mean,
          "a floor has no wall: %s", err.message);
    o.up[2] = 0;
    o.tolerance = -1;
    CHECK(tt_measure_uv_direction(wall, uv, 64, 64, &o, NULL, &r, NULL) == TT_ERROR_INVALID_ARGUMENT,
          "a negative tolerance is refused");
    CHECK(tt_measure_uv_direction(wall, NULL, 64, 64, NULL, NULL, &r, NULL) == TT_ERROR_INVALID_ARGUMENT &&
              tt_measure_uv_direction(wall, uv, 0, 64, NULL, NULL, &r, NULL) == TT_ERROR_INVALID_ARGUMENT,
          "NULL UVs and an empty image are refused");
done:
    free(uv);
    tt_mesh_free(wall);
    tt_mesh_free(floor_mesh);
}

/* An open tower around the z axis, its wall bulging in and out: radius 2
   + 0.4 sin(3 phi) sin(z), z from 0 to 6, nu x nv squares split in two. */
static tt_mesh *hpm_tower(int nu, int nv)
{
    const double pi = 3.14159265358979323846;
    tmesh m;
    tt_mesh *mesh = NULL;
    int i, j;
    memset(&m, 0, sizeof m);
    for (j = 0; j <= nv; j++)
        for (i = 0; i < nu; i++) {
            double p = 2 * pi * i / nu, z = 6.0 * j / nv, r = 2 + 0.4 * sin(3 * p) * sin(z);
            tm_vert(&m, r * cos(p), r * sin(p), z);
        }
    for (j = 0; j < nv; j++)
        for (i = 0; i < nu; i++) {
            int a = j * nu + i, b = j * nu + (i + 1) % nu;
            tm_tri(&m, a, b, b + nu);
            tm_tri(&m, a, b + nu, a + nu);
        }
    CHECK(build(&m, 0, &mesh, NULL) == TT_OK, "tower");
    tm_free(&m);
    return mesh;
}

/* With a direction field the courses lie level. Bricks on a bulging
   tower (up z): carried from neighbour to neighbour the direction of the
   courses turns over the curved wall; turned to the field at every
   cluster it stays level on nearly every face. Controls: the same
   without a field, and with a field pointing every which way. */
static void test_hpm_map_level(void)
{
    tt_mesh *mesh = hpm_tower(64, 32);
    tt_image *im = NULL;
    tt_hpm_options o;
    tt_hpm_report rep;
    tt_field_options fo;
    tt_uv_direction_options mo;
    tt_uv_direction_report with, without, random_field;
    tt_error err;
    float *field = NULL, *uv = NULL;
    int *cl = NULL, f, k;
    CHECK(tt_image_create(64, 64, NULL, &im, NULL) == TT_OK, "image");
    if (!mesh || !im) goto done;
    hpm_bricks(im);
    field = (float *)malloc(sizeof(float) * 3 * (size_t)mesh->nfaces);
    memset(&fo, 0, sizeof fo);
    fo.up[2] = 1;
    CHECK(tt_tangent_field(mesh, &fo, NULL, field, NULL) == TT_OK, "field");
    memset(&mo, 0, sizeof mo);
    mo.up[2] = 1;
    memset(&o, 0, sizeof o);
    o.scale = 2;
    o.seed = 5;
    o.flags = TT_HPM_TOROIDAL;
    o.face_vectors = field;
    if (hpm_run(mesh, im, &o, &uv, &cl, &rep) != TT_OK) goto done;
    CHECK(tt_measure_uv_direction(mesh, uv, 64, 64, &mo, NULL, &with, NULL) == TT_OK, "measured");
    CHECK(rep.clusters >= 8, "%d clusters", rep.clusters);
    free(uv);
    free(cl);
    /* without a field, started level (TT_HPM_EXACT_CONTINUATION starts at
       angle 0), so that what is lost is the drift alone */
    o.face_vectors = NULL;
    o.flags |= TT_HPM_EXACT_CONTINUATION;
    if (hpm_run(mesh, im, &o, &uv, &cl, &rep) != TT_OK) goto done;
    CHECK(tt_measure_uv_direction(mesh, uv, 64, 64, &mo, NULL, &without, NULL) == TT_OK, "measured");
    o.flags &= ~(unsigned)TT_HPM_EXACT_CONTINUATION;
    free(uv);
    free(cl);
    lcg_seed(11);
    for (f = 0; f < mesh->nfaces; f++) {
        /* a random direction, left in the face's plane by the library's
           own weights (only its projection counts) */
        for (k = 0; k < 3; k++) field[3 * f + k] = (float)(2 * lcg_unit() - 1);
    }
    o.face_vectors = field;
    if (hpm_run(mesh, im, &o, &uv, &cl, &rep) != TT_OK) goto done;
    CHECK(tt_measure_uv_direction(mesh, uv, 64, 64, &mo, NULL, &random_field, NULL) == TT_OK, "measured");
    printf("     courses within 10 degrees of level on %d wall faces: %.0f%% with the field (mean %.1f), "
           "%.0f%% without, started level (mean %.1f), %.0f%% with a random field\n",
           with.faces, 100 * with.within, with.mean, 100 * without.within, without.mean, 100 * random_field.within);
    CHECK(with.within >= 0.9, "with the field %g of the wall faces lie within 10 degrees of level (at least 0.9)",
          with.within);
    CHECK(without.within < 0.8, "without it, started level, %g do (the control: under 0.8)", without.within);
    CHECK(random_field.within < 0.6, "with a random field %g do (the control: under 0.6)", random_field.within);
    /* a field that is not finite is refused, naming the face */
    field[3 * 7 + 1] = internal_not_a_number();
    CHECK(tt_hpm_map(mesh, im, &o, NULL, uv, NULL, NULL, &err) == TT_ERROR_NON_FINITE && err.face == 7,
          "a NaN direction: %s", err.message);
done:
    free(field);
    free(uv);
    free(cl);
    tt_image_free(im);
    tt_mesh_free(mesh);
}

/* Over a curved cluster the field turns, and one rigid turn per cluster
   cannot follow it: bricks on a sphere (up z) at a scale where a cluster
   spans about 30 degrees of latitude. Each cluster's flattening is combed
   along the field and the border work keeps the triangles it moves level,
   so the courses lie within 10 degrees of level on at least 90 % of the
   wall faces (measured 95 to 96 %; 77 to 80 % before either), with no
   flipped triangle. The same on the sphere with its vertices moved at
   random by a third of an edge and back onto it, irregular triangles as a
   scan has: there the border work sheared triangles whose image's up it
   kept within its bound, and their rows leaned (88 % level); bounding both
   keeps 97 %, so the rows must be at least 93 %. Control: a field pointing
   every which way leaves far fewer level. (Shuffling the field over the
   faces is no control here: on a sphere nearly every face's direction,
   projected on another face, still points up.) */
static void test_hpm_map_level_curved(void)
{
    tmesh m;
    tt_mesh *mesh = NULL;
    tt_image *im = NULL;
    tt_hpm_options o;
    tt_hpm_report rep;
    tt_field_options fo;
    tt_uv_direction_options mo;
    tt_uv_direction_report r;
    float *field = NULL, *random_field = NULL, *uv = NULL;
    int *cl = NULL, f, k, t, v, jittered, flipped, bad;
    CHECK(tt_image_create(64, 64, NULL, &im, NULL) == TT_OK, "image");
    if (!im) return;
    hpm_bricks(im);
    memset(&mo, 0, sizeof mo);
    mo.up[2] = 1;
    for (jittered = 0; jittered < 2; jittered++) {
        memset(&m, 0, sizeof m);
        hpm_sphere(&m, 24, 48);
        lcg_seed(11);
        for (v = 0; jittered && v < m.nv; v++) {
            float *p = m.pos + 3 * v;
            double length = 0;
            for (k = 0; k < 3; k++) p[k] += (float)(0.08 * (2 * lcg_unit() - 1));
            for (k = 0; k < 3; k++) length += (double)p[k] * p[k];
            for (k = 0; k < 3; k++) p[k] = (float)(2 * p[k] / sqrt(length));
        }
        CHECK(build(&m, 0, &mesh, NULL) == TT_OK, "sphere");
        tm_free(&m);
        if (!mesh) break;
        field = (float *)malloc(sizeof(float) * 3 * (size_t)mesh->nfaces);
        random_field = (float *)malloc(sizeof(float) * 3 * (size_t)mesh->nfaces);
        if (!field || !random_field) break;
        memset(&fo, 0, sizeof fo);
        fo.up[2] = 1;
        CHECK(tt_tangent_field(mesh, &fo, NULL, field, NULL) == TT_OK, "field");
        lcg_seed(5);
        for (f = 0; f < mesh->nfaces; f++) /* only its projection on the face counts */
            for (k = 0; k < 3; k++) random_field[3 * f + k] = (float)(2 * lcg_unit() - 1);
        for (t = 0; t < 3; t++) {
            const double rows = jittered ? 0.93 : 0.9;
            memset(&o, 0, sizeof o);
            o.scale = 4;
            o.seed = (uint64_t)(1 + t % 2);
            o.flags = TT_HPM_TOROIDAL;
            o.face_vectors = t < 2 ? field : random_field;
            if (hpm_run(mesh, im, &o, &uv, &cl, &rep) != TT_OK) break;
            CHECK(tt_measure_uv_direction(mesh, uv, 64, 64, &mo, NULL, &r, NULL) == TT_OK, "measured");
            hpm_uv_checks(mesh, uv, 64, 64, 0, &flipped, &bad);
            printf("     sphere%s, seed %d%s: %.0f%% of %d wall faces within 10 degrees of level (mean %.1f), "
                   "rows %.0f%% (mean %.1f), %d clusters\n", jittered ? " jittered" : "", (int)o.seed,
                   t < 2 ? "" : ", random field", 100 * r.within, r.faces, r.mean, 100 * r.rows_within, r.rows_mean,
                   rep.clusters);
            if (t < 2)
                CHECK(r.within >= 0.9 && r.rows_within >= rows && flipped == 0 && bad == 0,
                      "%s seed %d: %g of the wall faces within 10 degrees of level, their rows %g (at least 0.9 and "
                      "%g), %d flipped, %d bad", jittered ? "jittered," : "regular,", (int)o.seed, r.within,
                      r.rows_within, rows, flipped, bad);
            else
                CHECK(r.within < 0.4 && r.rows_within < 0.4,
                      "a random field: %g within 10 degrees, rows %g (the control: under 0.4)", r.within,
                      r.rows_within);
            free(uv);
            free(cl);
            uv = NULL;
            cl = NULL;
        }
        free(field);
        free(random_field);
        field = random_field = NULL;
        tt_mesh_free(mesh);
        mesh = NULL;
    }
    free(field);
    free(random_field);
    tt_mesh_free(mesh);
    tt_image_free(im);
}

/* The budget: a 6144-face torus at a scale where clusters of
   a few dozen faces are needed, with a threshold almost no fit meets, so
   every cluster is split down to the floor. The floor stops it there,
   fitting the clusters at the floor once each: far fewer fits than faces
   (measured: 58, about 1 per 100 faces; without the floor the splits
   would go on down to single faces, thousands of fits). */
static void test_hpm_map_budget(void)
{
    tmesh m;
    tt_mesh *mesh = NULL;
    tt_image *im = NULL;
    tt_hpm_options o;
    tt_hpm_report rep;
    tt_error err;
    float *uv = NULL;
    int *cl = NULL, level, per_level = 0, accepted = 0;
    memset(&m, 0, sizeof m);
    hpm_torus(&m, 96, 32, 0.0);
    if (build(&m, 0, &mesh, &err) != TT_OK) CHECK(0, "building the torus failed: %s", err.message);
    tm_free(&m);
    make_value_noise(&im, 128, 128, 6);
    memset(&o, 0, sizeof o);
    o.scale = 5;
    o.rotations = 7;
    o.threshold = 0.05; /* nearly every fit is rejected: the clusters go down to the floor */
    if (!mesh || !im || hpm_run(mesh, im, &o, &uv, &cl, &rep) != TT_OK) goto done;
    printf("     budget: %d faces, %d clusters, %d fits (%d accepted, %d at the floor, %d rejected)\n", mesh->nfaces,
           rep.clusters, rep.fits, rep.accepted_fits, rep.floor_fits, rep.rejected_fits);
    CHECK(rep.fits >= 10 && rep.fits <= mesh->nfaces / 30, "%d fits for %d faces (at most one per 30 faces)",
          rep.fits, mesh->nfaces);
    CHECK(rep.fits == rep.accepted_fits + rep.floor_fits + rep.rejected_fits, "every fit is counted once");
    for (level = 0; level < TT_HPM_MAX_LEVELS; level++) {
        per_level += rep.fits_per_level[level];
        accepted += rep.accepted_per_level[level];
    }
    CHECK(per_level == rep.fits && accepted == rep.accepted_fits, "fits per level add up (%d, %d)", per_level,
          accepted);
done:
    free(uv);
    free(cl);
    tt_image_free(im);
    tt_mesh_free(mesh);
}

/* Every face textured, no flip, UVs finite (bounded: inside
   the margin) on a torus, a sphere, an open grid, two components and a
   grid with holes, with a non-square, non-power-of-two image; the same seed
   gives the same bits, another seed other bits. */
static void test_hpm_map_topology(void)
{
    int which;
    tt_image *im = NULL;
    make_value_noise(&im, 90, 70, 2);
    for (which = 0; which < M_COUNT && im; which++) {
        tt_mesh *mesh = hpm_mesh(which);
        tt_hpm_options o;
        tt_hpm_report rep;
        float *uv = NULL, *uv2 = NULL;
        int *cl = NULL, *cl2 = NULL, f, untextured = 0, flipped, bad, t;
        for (t = 0; t < 2 && mesh; t++) {
            memset(&o, 0, sizeof o);
            o.seed = 7;
            o.flags = t ? TT_HPM_TOROIDAL : 0;
            if (hpm_run(mesh, im, &o, &uv, &cl, &rep) != TT_OK) break;
            for (f = 0; f < mesh->nfaces; f++) untextured += cl[f] < 0;
            hpm_uv_checks(mesh, uv, 90, 70, !t, &flipped, &bad);
            CHECK(untextured == 0 && flipped == 0 && bad == 0,
                  "%s (%s): %d faces untextured, %d flipped, %d bad corners", mesh_names[which],
                  t ? "toroidal" : "bounded", untextured, flipped, bad);
            if (hpm_run(mesh, im, &o, &uv2, &cl2, &rep) == TT_OK)
                CHECK(memcmp(uv, uv2, sizeof(float) * 2 * (size_t)mesh->ncorners) == 0,
                      "%s: the same seed gives the same UVs", mesh_names[which]);
            free(uv2);
            free(cl2);
            o.seed = 8;
            if (hpm_run(mesh, im, &o, &uv2, &cl2, &rep) == TT_OK)
                CHECK(memcmp(uv, uv2, sizeof(float) * 2 * (size_t)mesh->ncorners) != 0,
                      "%s: another seed gives other UVs", mesh_names[which]);
            free(uv);
            free(cl);
            free(uv2);
            free(cl2);
            uv = uv2 = NULL;
            cl = cl2 = NULL;
        }
        free(uv);
        free(cl);
        tt_mesh_free(mesh);
    }
    tt_image_free(im);
}

/* Vertices with hundreds of corners (a lat-long sphere's poles: 200):
   the border work moves a vertex by writing every corner of its ring, so
   a ring cut short leaves a tear inside a cluster. Within each cluster
   every vertex keeps one UV (over all interior edges, not only at the
   poles), and the map has no flipped triangle; with and without a
   direction field, bounded and tiling. Cutting the rings at 64 corners
   tore 1 to 4 pole edges in each of these runs. */
static void test_hpm_map_high_valence(void)
{
    tmesh m;
    tt_mesh *mesh = NULL;
    tt_image *im = NULL;
    tt_error err;
    float *uv = NULL, *field = NULL;
    int *cl = NULL, npole = 0, torn, torn_pole, flipped, bad, c, f, t;
    tt_hpm_options o;
    tt_hpm_report rep;
    memset(&m, 0, sizeof m);
    hpm_sphere(&m, 24, 200);
    CHECK(build(&m, 0, &mesh, &err) == TT_OK, "lat-long sphere: %s", err.message);
    tm_free(&m);
    make_value_noise(&im, 160, 120, 4);
    if (!mesh || !im) goto done;
    /* the field: +z projected on each face */
    field = (float *)malloc(sizeof(float) * 3 * (size_t)mesh->nfaces);
    for (f = 0; f < mesh->nfaces && field; f++) {
        float n[3];
        double z[3] = {0, 0, 1}, d;
        tt_face_normal(mesh, f, n);
        d = n[2];
        for (c = 0; c < 3; c++) field[3 * f + c] = (float)(z[c] - d * n[c]);
    }
    for (c = 0; c < mesh->ncorners; c++) npole += mesh->corner_vert[c] == 0;
    for (t = 0; t < 3 && field; t++) {
        memset(&o, 0, sizeof o);
        o.seed = (uint64_t)(4 + 2 * t);
        o.scale = 1.5 + t;
        if (t == 1) o.flags = TT_HPM_TOROIDAL;
        if (t == 2) o.face_vectors = field;
        if (hpm_run(mesh, im, &o, &uv, &cl, &rep) != TT_OK) break;
        torn = torn_pole = 0;
        for (c = 0; c < mesh->ncorners; c++) {
            int tw = mesh->twin[c], k, v = mesh->corner_vert[c];
            if (tw < 0) continue;
            /* corner c and the corner after its twin sit on the same vertex */
            k = tt_mesh_next(mesh, tw);
            if (cl[mesh->corner_face[c]] >= 0 && cl[mesh->corner_face[c]] == cl[mesh->corner_face[k]] &&
                (uv[2 * c] != uv[2 * k] || uv[2 * c + 1] != uv[2 * k + 1])) {
                torn++;
                torn_pole += v == 0 || v == mesh->nverts - 1;
            }
        }
        hpm_uv_checks(mesh, uv, 160, 120, !(o.flags & TT_HPM_TOROIDAL), &flipped, &bad);
        CHECK(npole == 200 && torn == 0 && flipped == 0 && bad == 0,
              "poles of valence %d, scale %g, run %d: %d edges of one cluster with different UVs at a vertex "
              "(%d at the poles), %d flipped, %d bad",
              npole, o.scale, t, torn, torn_pole, flipped, bad);
        free(uv);
        free(cl);
        uv = NULL;
        cl = NULL;
    }
done:
    free(field);
    tt_image_free(im);
    tt_mesh_free(mesh);
}

typedef struct hpm_map_ctx {
    const tt_mesh *mesh;
    const tt_image *im;
    float *uv;
    const float *field;     /* or NULL */
} hpm_map_ctx;

static tt_result hpm_map_oom_call(void *ctx, const tt_allocator *al, tt_error *error)
{
    hpm_map_ctx *c = (hpm_map_ctx *)ctx;
    tt_hpm_options o;
    memset(&o, 0, sizeof o);
    o.rotations = 3;
    o.match_size = 16;
    o.face_vectors = c->field;
    return tt_hpm_map(c->mesh, c->im, &o, al, c->uv, NULL, NULL, error);
}

/* A mesh whose faces are large for the image at the default scale (an
   octahedron, one triangle): every face still gets a map of its own, with
   a scale chosen so that each face fits the image; a scale the caller sets
   that no face fits is refused, naming the face and a scale that works. */
static void test_hpm_map_coarse(void)
{
    static const double octa[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    static const int faces[8][3] = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4},
                                    {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
    tt_image *im = NULL;
    int which;
    make_value_noise(&im, 64, 48, 5);
    for (which = 0; which < 2 && im; which++) {
        tmesh m;
        tt_mesh *mesh = NULL;
        tt_error err;
        tt_hpm_options o;
        tt_hpm_report rep;
        float uv[2 * 24];
        int cluster[8], i, f, unmapped = 0, still = 0, nf = which == 0 ? 8 : 1;
        tt_result r;
        memset(&m, 0, sizeof m);
        for (i = 0; i < 6; i++) tm_vert(&m, octa[i][0], octa[i][1], octa[i][2]);
        for (f = 0; f < nf; f++) tm_tri(&m, faces[f][0], faces[f][1], faces[f][2]);
        if (build(&m, 0, &mesh, &err) != TT_OK) {
            CHECK(0, "building the coarse mesh: %s", err.message);
            tm_free(&m);
            continue;
        }
        r = tt_hpm_map(mesh, im, NULL, NULL, uv, cluster, &rep, &err);
        for (f = 0; f < nf; f++) {
            const float *a = uv + 2 * mesh->face_start[f];
            double area = (a[2] - a[0]) * (a[5] - a[1]) - (a[4] - a[0]) * (a[3] - a[1]);
            if (cluster[f] < 0) unmapped++;
            if (!(fabs(area) > 1e-4)) still++;
        }
        CHECK(r == TT_OK && rep.clusters > 0 && unmapped == 0 && still == 0,
              "%s at the default scale: result %d, %d clusters textured, %d faces with no map, %d with no UV area",
              which == 0 ? "octahedron" : "one triangle", r, rep.clusters, unmapped, still);
        CHECK(r != TT_OK || rep.texels_per_unit * sqrt(2.0) <= 0.75 * (48 - 2) + 1e-9,
              "the longest edge spans %g texels, more than 3/4 of the image's 46", rep.texels_per_unit * sqrt(2.0));
        memset(&o, 0, sizeof o);
        o.scale = 0.5;   /* the image's 64 texels over half a unit: an edge of sqrt 2 spans 181 */
        r = tt_hpm_map(mesh, im, &o, NULL, uv, NULL, NULL, &err);
        CHECK(r == TT_ERROR_INVALID_ARGUMENT && err.face >= 0 && err.face < nf && strstr(err.message, "at least 1.9"),
              "a scale too small for the faces: result %d, face %d, '%s' (1.41421 * 64 / 46 = 1.968 would do)", r,
              err.face, err.message);
        o.flags = TT_HPM_TOROIDAL;   /* a tileable image: placements wrap, any scale works */
        r = tt_hpm_map(mesh, im, &o, NULL, uv, NULL, NULL, &err);
        CHECK(r == TT_OK, "the same scale with a tileable image: %d (%s)", r, err.message);
        tt_mesh_free(mesh);
        tm_free(&m);
    }
    tt_image_free(im);
}

/* fuzz_hpm: with a flattening error bound so strict that no cluster of
   several faces flattens (a 4 x 3 torus, 24 triangles), 16 to 18 faces
   were left with no cluster (-1) and corners copied from their neighbours,
   4 of them collapsing to no UV area. Each now shows a neighbour's map
   continued over an edge, or its own leaf laid flat; every face has a
   cluster, UV area and the turn of the others, inside the image. */
static void test_hpm_map_unflattened(void)
{
    static const int branching[2] = {0, 44};
    tt_image *im = NULL;
    int which;
    make_value_noise(&im, 24, 32, 3);
    for (which = 0; which < 2 && im; which++) {
        tmesh m;
        tt_mesh *mesh = NULL;
        tt_error err;
        tt_hpm_options o;
        tt_hpm_report rep;
        float *uv;
        int *cluster, f, k, unmapped = 0, collapsed = 0, turned[2] = {0, 0}, outside = 0;
        tt_result r;
        tmesh quads;
        memset(&m, 0, sizeof m);
        memset(&quads, 0, sizeof quads);
        make_torus(&quads, 4, 3, 1.0, 0.45);
        triangulate_into(&m, &quads, 0.0);
        tm_free(&quads);
        if (build(&m, 0, &mesh, &err) != TT_OK) {
            CHECK(0, "building the coarse torus: %s", err.message);
            tm_free(&m);
            continue;
        }
        uv = (float *)malloc(sizeof(float) * 2 * (size_t)mesh->ncorners);
        cluster = (int *)malloc(sizeof(int) * (size_t)mesh->nfaces);
        memset(&o, 0, sizeof o);
        o.max_flattening_error = 1e-300;
        o.branching = branching[which];
        o.match_size = 16;
        r = tt_hpm_map(mesh, im, &o, NULL, uv, cluster, &rep, &err);
        for (f = 0; r == TT_OK && f < mesh->nfaces; f++) {
            const float *a = uv + 2 * mesh->face_start[f];
            double area = (a[2] - a[0]) * (a[5] - a[1]) - (a[4] - a[0]) * (a[3] - a[1]);
            if (cluster[f] < 0) unmapped++;
            if (!(fabs(area) > 1e-6)) collapsed++;
            else turned[area > 0]++;
            for (k = 0; k < 6; k++) outside += !(a[k] >= 0.0f && a[k] <= 1.0f);
        }
        CHECK(r == TT_OK && rep.faces_unflattened >= 8 && rep.not_flat > 0 && unmapped == 0 && collapsed == 0 &&
                  (turned[0] == 0 || turned[1] == 0) && outside == 0,
              "coarse torus, no flattening error allowed, branching %d: result %d (%s), %d faces unflattened, %d "
              "not flat; %d faces with no cluster, %d with no UV area, turned %d / %d, %d UVs outside",
              branching[which], r, r == TT_OK ? "TT_OK" : err.message, rep.faces_unflattened, rep.not_flat, unmapped,
              collapsed, turned[0], turned[1], outside);
        free(uv);
        free(cluster);
        tt_mesh_free(mesh);
        tm_free(&m);
    }
    tt_image_free(im);
}

/* A progress callback that records the fractions and cancels at call
   number cancel_at (0-based; -1: never). */
typedef struct hpm_progress_log {
    int calls, cancel_at, decreasing;
    int below_traversal;    /* fractions strictly between 0 and the traversal's start (0.2): the hierarchy's */
    float last;
} hpm_progress_log;

static int hpm_log_progress(float fraction, void *user_data)
{
    hpm_progress_log *log = (hpm_progress_log *)user_data;
    if (fraction < log->last || !(fraction >= 0.0f && fraction <= 1.0f)) log->decreasing++;
    log->below_traversal += fraction > 0.0f && fraction < 0.2f;
    log->last = fraction;
    return log->calls++ == log->cancel_at;
}

/* tt_cluster_hierarchy_build's progress: after each level, rising, below
   1; cancelling at any call returns TT_CANCELLED with nothing allocated. */
static void test_cluster_hierarchy_progress(void)
{
    tt_mesh *mesh = hpm_mesh(M_GRID);
    tt_cluster_options opt;
    tt_cluster_hierarchy *h = NULL;
    hpm_progress_log log;
    tt_error err;
    tt_result r;
    int k, calls, bad = 0;
    if (!mesh) return;
    memset(&opt, 0, sizeof opt);
    opt.progress = hpm_log_progress;
    opt.progress_user_data = &log;
    memset(&log, 0, sizeof log);
    log.cancel_at = -1;
    r = tt_cluster_hierarchy_build(mesh, &opt, NULL, &h, &err);
    CHECK(r == TT_OK && h && log.calls >= 2 && log.calls >= h->nlevels - 1 && log.decreasing == 0 && log.last < 1.0f,
          "hierarchy progress: %d calls over %d levels, %d out of order, last %g (%d: %s)", log.calls,
          h ? h->nlevels : -1, log.decreasing, log.last, r, err.message);
    tt_cluster_hierarchy_free(h);
    calls = log.calls;
    for (k = 0; k < calls; k++) {
        memset(&log, 0, sizeof log);
        log.cancel_at = k;
        oom_reset();
        h = (tt_cluster_hierarchy *)&log;
        r = tt_cluster_hierarchy_build(mesh, &opt, &g_oom_allocator, &h, &err);
        if (r != TT_CANCELLED || err.result != r || h != NULL || g_oom_counter.live != 0 || log.calls != k + 1) bad++;
    }
    CHECK(bad == 0, "hierarchy: cancelling at each of the %d progress calls: %d did not stop cleanly", calls, bad);
    tt_mesh_free(mesh);
}

/* The progress callback: fractions rising to 1 (the hierarchy, the image,
   every cluster, the borders); cancelling at any call stops the mapping
   with TT_CANCELLED, the UVs untouched and nothing left allocated. */
static void test_hpm_map_progress(void)
{
    tt_mesh *mesh = hpm_mesh(M_GRID);
    tt_image *im = NULL;
    tt_hpm_options o;
    hpm_progress_log log;
    tt_error err;
    float *uv = NULL;
    int k, calls, bad = 0, n;
    tt_result r;
    make_value_noise(&im, 40, 40, 1);
    if (!mesh || !im) goto done;
    n = 2 * mesh->ncorners;
    uv = (float *)malloc(sizeof(float) * (size_t)n);
    memset(&o, 0, sizeof o);
    o.rotations = 3;
    o.match_size = 16;
    o.progress = hpm_log_progress;
    o.progress_user_data = &log;
    memset(&log, 0, sizeof log);
    log.cancel_at = -1;
    r = tt_hpm_map(mesh, im, &o, NULL, uv, NULL, NULL, &err);
    CHECK(r == TT_OK && log.calls >= 4 && log.decreasing == 0 && log.last == 1.0f,
          "progress: %d calls, %d out of order, last %g (%d: %s)", log.calls, log.decreasing, log.last, r, err.message);
    /* The hierarchy, a second of a scan's run, reports level by level. */
    CHECK(log.below_traversal >= 2, "progress: %d calls from the hierarchy", log.below_traversal);
    calls = log.calls;
    for (k = 0; k < calls; k++) {
        int i, touched = 0;
        for (i = 0; i < n; i++) uv[i] = -7.0f;
        memset(&log, 0, sizeof log);
        log.cancel_at = k;
        oom_reset();
        r = tt_hpm_map(mesh, im, &o, &g_oom_allocator, uv, NULL, NULL, &err);
        for (i = 0; i < n; i++) touched += uv[i] != -7.0f;
        if (r != TT_CANCELLED || err.result != r || touched || g_oom_counter.live != 0 || log.calls != k + 1) {
            if (!bad) DETAIL("cancelled at call %d: result %d, %d UVs written, %ld blocks live", k, r, touched,
                             g_oom_counter.live);
            bad++;
        }
    }
    CHECK(bad == 0, "cancelling at each of the %d progress calls: %d did not stop cleanly", calls, bad);
done:
    free(uv);
    tt_image_free(im);
    tt_mesh_free(mesh);
}

static void test_hpm_map_errors(void)
{
    tt_mesh *mesh = hpm_mesh(M_GRID), *quads = NULL;
    tt_image *im = NULL;
    tt_hpm_options o;
    tt_error err;
    tmesh q;
    float *uv, *field;
    hpm_map_ctx ctx;
    make_value_noise(&im, 40, 40, 1);
    if (!mesh || !im) goto done;
    uv = (float *)malloc(sizeof(float) * 2 * (size_t)mesh->ncorners);
    CHECK(tt_hpm_map(NULL, im, NULL, NULL, uv, NULL, NULL, &err) == TT_ERROR_INVALID_ARGUMENT, "NULL mesh");
    CHECK(tt_hpm_map(mesh, NULL, NULL, NULL, uv, NULL, NULL, &err) == TT_ERROR_INVALID_ARGUMENT, "NULL image");
    CHECK(tt_hpm_map(mesh, im, NULL, NULL, NULL, NULL, NULL, &err) == TT_ERROR_INVALID_ARGUMENT, "NULL uv");
    memset(&o, 0, sizeof o);
    o.rotations = 65;
    CHECK(tt_hpm_map(mesh, im, &o, NULL, uv, NULL, NULL, &err) == TT_ERROR_INVALID_ARGUMENT &&
              strstr(err.message, "rotations"),
          "rotations 65: %s", err.message);
    memset(&o, 0, sizeof o);
    o.match_size = 100;
    CHECK(tt_hpm_map(mesh, im, &o, NULL, uv, NULL, NULL, &err) == TT_ERROR_INVALID_ARGUMENT, "match_size 100");
    memset(&o, 0, sizeof o);
    o.scale = -1;
    CHECK(tt_hpm_map(mesh, im, &o, NULL, uv, NULL, NULL, &err) == TT_ERROR_INVALID_ARGUMENT, "negative scale");
    memset(&o, 0, sizeof o);
    o.threshold = (double)NAN;
    CHECK(tt_hpm_map(mesh, im, &o, NULL, uv, NULL, NULL, &err) == TT_ERROR_INVALID_ARGUMENT, "NaN threshold");
    memset(&o, 0, sizeof o);
    o.flags = 1u << 7;
    CHECK(tt_hpm_map(mesh, im, &o, NULL, uv, NULL, NULL, &err) == TT_ERROR_INVALID_ARGUMENT, "unknown flag");
    px(im, 3, 4)[1] = (float)NAN;
    CHECK(tt_hpm_map(mesh, im, NULL, NULL, uv, NULL, NULL, &err) == TT_ERROR_NON_FINITE && err.row == 4 &&
              err.column == 3,
          "a NaN texel is named (row %d, column %d)", err.row, err.column);
    px(im, 3, 4)[1] = 0.5f;
    /* A bounded image keeps a texel's margin: under 3 texels on a side it
       has no room (the default scale divided by zero there, and the error
       blamed "scale 0"); a tiling one has no margin to keep. */
    {
        tt_image *small = NULL;
        int side;
        for (side = 1; side <= 3; side++) {
            tt_result r;
            if (tt_image_create(side == 3 ? 3 : 2, side, NULL, &small, NULL) != TT_OK) break;
            memset(&o, 0, sizeof o);
            r = tt_hpm_map(mesh, small, &o, NULL, uv, NULL, NULL, &err);
            if (side < 3)
                CHECK(r == TT_ERROR_INVALID_ARGUMENT && strstr(err.message, "at least 3 on each side"),
                      "a bounded %d x %d image: %d (%s)", small->width, side, r, err.message);
            else
                CHECK(r == TT_OK, "a bounded 3 x 3 image: %d (%s)", r, err.message);
            o.flags = TT_HPM_TOROIDAL;
            r = tt_hpm_map(mesh, small, &o, NULL, uv, NULL, NULL, &err);
            CHECK(r == TT_OK, "a tiling %d x %d image: %d (%s)", small->width, side, r, err.message);
            tt_image_free(small);
            small = NULL;
        }
    }
    memset(&q, 0, sizeof q);
    make_grid(&q, 3, 3);
    if (build(&q, 0, &quads, &err) == TT_OK) {
        float quv[2 * 36];
        CHECK(tt_hpm_map(quads, im, NULL, NULL, quv, NULL, NULL, &err) == TT_ERROR_INVALID_ARGUMENT &&
                  err.face == 0,
              "quads are refused, naming face 0 (%d)", err.face);
    }
    tm_free(&q);
    tt_mesh_free(quads);
    ctx.mesh = mesh;
    ctx.im = im;
    ctx.uv = uv;
    ctx.field = NULL;
    oom_reset();
    oom_sweep("tt_hpm_map", hpm_map_oom_call, &ctx, TT_OK);
    /* with a direction field: the combing's and the level border work's
       allocations too */
    ctx.field = field = (float *)malloc(sizeof(float) * 3 * (size_t)mesh->nfaces);
    if (field && tt_tangent_field(mesh, NULL, NULL, field, NULL) == TT_OK) {
        oom_reset();
        oom_sweep("tt_hpm_map with a field", hpm_map_oom_call, &ctx, TT_OK);
    }
    free(field);
    free(uv);
done:
    tt_image_free(im);
    tt_mesh_free(mesh);
}

/* fuzz_hpm: a 40-triangle torus with 15 of its 20 vertices at FLT_MAX and
   a caller's scale of 4.7e39 (texel density below FLT_MIN) textured no
   cluster and returned TT_OK, every UV at the image centre (a one-colour
   model, issue 21 row 5). Now TT_ERROR_NON_FINITE, corner_uv untouched. */
static void test_hpm_extreme_floats_refused(void)
{
    /* three vertices of the fuzzer's input, the other 17 at FLT_MAX */
    static const float first[9] = {4.2010684f, 0.145220593f, 0.145220593f, 1.5710144f, 1.47669971f,
                                   0.145220593f, -1.40792274f, 1.43766642f, 0.435661763f};
    float pos[60];
    static const int tris[120] = {
        0, 6, 1, 0, 5, 6, 1, 7, 2, 1, 6, 7,
        2, 8, 3, 2, 7, 8, 3, 9, 4, 3, 8, 9,
        4, 5, 0, 4, 9, 5, 5, 11, 6, 5, 10, 11,
        6, 12, 7, 6, 11, 12, 7, 13, 8, 7, 12, 13,
        8, 14, 9, 8, 13, 14, 9, 10, 5, 9, 14, 10,
        10, 16, 11, 10, 15, 16, 11, 17, 12, 11, 16, 17,
        12, 18, 13, 12, 17, 18, 13, 19, 14, 13, 18, 19,
        14, 15, 10, 14, 19, 15, 15, 1, 16, 15, 0, 1,
        16, 2, 17, 16, 1, 2, 17, 3, 18, 17, 2, 3,
        18, 4, 19, 18, 3, 4, 19, 0, 15, 19, 4, 0,};
    tt_mesh_desc d;
    tt_mesh *mesh = NULL;
    tt_image *img = NULL;
    tt_hpm_options o;
    tt_error err;
    tt_result r;
    float uv[240];
    int k, untouched = 1;
    for (k = 0; k < 60; k++) pos[k] = k < 9 ? first[k] : FLT_MAX;
    memset(&d, 0, sizeof d);
    d.positions = pos;
    d.nverts = 20;
    d.indices = tris;
    d.nfaces = 40;
    d.fixed_face_size = 3;
    d.flags = TT_MESH_PERMISSIVE;
    if (tt_mesh_build(&d, NULL, &mesh, &err) != TT_OK || tt_image_create(16, 16, NULL, &img, &err) != TT_OK) {
        CHECK(0, "the extreme torus and its image build: %s", err.message);
        tt_mesh_free(mesh);
        return;
    }
    for (k = 0; k < 16 * 16 * 4; k++) img->pixels[k] = (float)(k * 7 % 13) / 13.0f;
    for (k = 0; k < 2 * mesh->ncorners; k++) uv[k] = -7.0f;
    memset(&o, 0, sizeof o);
    o.scale = 4.7e39;
    o.match_size = 16;
    r = tt_hpm_map(mesh, img, &o, NULL, uv, NULL, NULL, &err);
    for (k = 0; k < 2 * mesh->ncorners; k++) untouched &= uv[k] == -7.0f;
    CHECK(r == TT_ERROR_NON_FINITE && untouched, "FLT_MAX coordinates at scale 4.7e39: %d (%s), corner_uv %s",
          (int)r, r == TT_OK ? "TT_OK" : err.message, untouched ? "untouched" : "written");
    tt_image_free(img);
    tt_mesh_free(mesh);
}

/* A flat strip along the bounding box's diagonal, `reach` x FLT_MAX from
   its centre on each axis: 2 sqrt(3) reach FLT_MAX long, 0.05 FLT_MAX wide. */
static tt_mesh *flat_diagonal_strip(double reach)
{
    tmesh m;
    tt_mesh *mesh = NULL;
    tt_error err;
    int i, j;
    memset(&m, 0, sizeof m);
    for (j = 0; j <= 2; j++)
        for (i = 0; i <= 8; i++) {
            double s = reach * (i / 4.0 - 1.0), t = 0.05 * (j - 1.0) / sqrt(2.0);
            tm_vert(&m, (s + t) * FLT_MAX, (s - t) * FLT_MAX, s * FLT_MAX);
        }
    for (j = 0; j < 2; j++)
        for (i = 0; i < 8; i++) {
            int a = j * 9 + i;
            tm_tri(&m, a, a + 1, a + 10);
            tm_tri(&m, a, a + 10, a + 9);
        }
    if (build(&m, 0, &mesh, &err) != TT_OK) CHECK(0, "building the diagonal strip failed: %s", err.message);
    tm_free(&m);
    return mesh;
}

/* fuzz_hpm: a cluster whose flat map is longer than single precision
   holds (centred, more than FLT_MAX from its middle) came out as -inf
   UVs with TT_OK. Now TT_ERROR_NON_FINITE naming a face of the cluster,
   corner_uv untouched; the same strip at 0.4 of that reach maps exactly. */
static void test_flatten_beyond_float(void)
{
    static const double reach[2] = {0.95, 0.4};
    int k;
    for (k = 0; k < 2; k++) {
        tt_mesh *m = flat_diagonal_strip(reach[k]);
        tt_cluster_hierarchy *h = m ? hpm_build(m, 3) : NULL;
        float *uv = m ? flat_uv(m) : NULL;
        tt_flatten_report rep;
        tt_error err;
        tt_result r;
        int c, whole = -1, untouched = 1, finite = 1;
        double length_uv, length_3d;
        if (!h || !uv) goto next;
        for (c = 0; c < h->nclusters; c++)
            if (h->clusters[c].nfaces == m->nfaces && (h->clusters[c].flags & TT_CLUSTER_MAPPABLE)) whole = c;
        CHECK(whole >= 0, "reach %.2f: a mappable cluster holds the whole strip", reach[k]);
        if (whole < 0) goto next;
        memset(&err, 0, sizeof err);
        r = tt_flatten_cluster(m, h, whole, NULL, NULL, uv, &rep, &err);
        for (c = 0; c < 2 * m->ncorners; c++) {
            untouched &= uv[c] == FLAT_SENTINEL;
            finite &= fabsf(uv[c]) <= FLT_MAX;
        }
        if (k == 0) {
            CHECK(r == TT_ERROR_NON_FINITE && err.result == r && err.item == whole && err.face >= 0 &&
                      err.face < m->nfaces && strstr(err.message, "beyond single precision") && untouched,
                  "a strip 3.3 FLT_MAX long: %d (%s), face %d, item %d, corner_uv %s", (int)r, err.message, err.face,
                  err.item, untouched ? "untouched" : "written");
        } else {
            /* vertices 9 and 17 are the strip's two ends on its middle line */
            const float *p0 = m->pos + 3 * 9, *p1 = m->pos + 3 * 17;
            int c0 = -1, c1 = -1;
            for (c = 0; c < m->ncorners; c++) {
                if (m->corner_vert[c] == 9) c0 = c;
                if (m->corner_vert[c] == 17) c1 = c;
            }
            length_3d = sqrt(((double)p1[0] - p0[0]) * ((double)p1[0] - p0[0]) +
                             ((double)p1[1] - p0[1]) * ((double)p1[1] - p0[1]) +
                             ((double)p1[2] - p0[2]) * ((double)p1[2] - p0[2]));
            length_uv = c0 < 0 || c1 < 0 ? 0 : sqrt(((double)uv[2 * c1] - uv[2 * c0]) * ((double)uv[2 * c1] - uv[2 * c0]) +
                                                   ((double)uv[2 * c1 + 1] - uv[2 * c0 + 1]) *
                                                       ((double)uv[2 * c1 + 1] - uv[2 * c0 + 1]));
            CHECK(r == TT_OK && finite && !untouched && fabs(length_uv / length_3d - 1.0) < 1e-5,
                  "the strip at 0.4 of that reach: %d (%s), UVs %s, length kept to %.3g", (int)r,
                  r == TT_OK ? "TT_OK" : err.message, finite ? "finite" : "not finite", length_uv / length_3d - 1.0);
        }
    next:
        free(uv);
        tt_cluster_hierarchy_free(h);
        tt_mesh_free(m);
    }
}

void run_hpm_tests(void)
{
    RUN(test_hpm_properties);
    RUN(test_hpm_small);
    RUN(test_hpm_determinism);
    RUN(test_hpm_uniform);
    RUN(test_hpm_errors);
    RUN(test_flatten_plane);
    RUN(test_flatten_caps);
    RUN(test_flatten_folds);
    RUN(test_flatten_clusters);
    RUN(test_flatten_errors);
    RUN(test_flatten_beyond_float);
    RUN(test_hpm_map_plane);
    RUN(test_hpm_map_continuation);
    RUN(test_hpm_relax_classes);
    RUN(test_hpm_map_executor);
    RUN(test_hpm_map_seams);
    RUN(test_hpm_map_fine_grain);
    RUN(test_hpm_map_orientation);
    RUN(test_uv_direction_measure);
    RUN(test_hpm_map_level);
    RUN(test_hpm_map_level_curved);
    RUN(test_hpm_map_crease);
    RUN(test_hpm_map_budget);
    RUN(test_hpm_map_topology);
    RUN(test_hpm_map_high_valence);
    RUN(test_hpm_map_coarse);
    RUN(test_hpm_map_unflattened);
    RUN(test_cluster_hierarchy_progress);
    RUN(test_hpm_map_progress);
    RUN(test_hpm_map_errors);
    RUN(test_hpm_extreme_floats_refused);
}
