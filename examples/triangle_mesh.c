/* triangle_mesh.c - an OBJ read as triangles, for the commands whose
   library pipelines take triangle meshes (lapped, hpm, polycube), and the
   mesh options --subdivide and --permissive as every command applies them
   (tiled.c's quad meshes too). See tool.h for the interface. */

#include <ctype.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tool.h"

/* ======================================================================== */
/* The mesh options                                                         */
/* ======================================================================== */

int tool_quadrangulate(const char *obj_path, tt_mesh **mesh, int smooth)
{
    tt_mesh *quads;
    tt_error error;
    if (tt_mesh_quadrangulate(*mesh, smooth ? TT_SUBDIVIDE_CATMULL_CLARK : TT_SUBDIVIDE_LINEAR, NULL, &quads,
                              &error) != TT_OK)
        return tool_fail("%s: cannot quadrangulate: %s", obj_path, error.message);
    tt_mesh_free(*mesh);
    *mesh = quads;
    return 0;
}

int tool_check_subdivide(const char *obj_path, const tt_mesh *mesh, int steps)
{
    /* The first step makes a quad of every corner, each later one four of
       every quad: refuse what would not fit in memory long before it is
       tried. */
    double quads = steps > 0 ? (double)mesh->ncorners * pow(4.0, steps - 1) : 0.0;
    if (quads > (double)TOOL_MAX_QUADS)
        return tool_fail("%s: --subdivide %d would make %.3g quads; the limit is %d (use a smaller level)", obj_path,
                         steps, quads, TOOL_MAX_QUADS);
    return 0;
}

void tool_note_cut_edges(const char *obj_path, int edges)
{
    if (edges > 0)
        tool_note("%s: --permissive cut %d non-manifold or mis-oriented edge%s open", obj_path, edges,
                  edges == 1 ? "" : "s");
}

/* ======================================================================== */
/* An OBJ as triangles                                                      */
/* ======================================================================== */

void triangle_mesh_free(triangle_mesh *m)
{
    obj_free(&m->obj);
    free(m->subdivided_pos);
    free(m->vert);
    free(m->corner_uv);
    free(m->face);
    free(m->first_triangle);
    tt_mesh_free(m->mesh);
    memset(m, 0, sizeof *m);
}

/* (Re)build m->mesh from m->pos and m->vert; a build error is said about the
   OBJ's face, suggesting --permissive when offer_permissive and it would
   help. It would not for a face of zero area (or one repeating a vertex,
   which makes one): --permissive builds such a face, but the triangle
   pipelines refuse it (tt_lapped_paste), so it is offered only for the edges
   and vertices it repairs. */
static int triangle_mesh_build(const char *path, triangle_mesh *m, int offer_permissive)
{
    tt_mesh_desc desc;
    tt_error error;
    tt_mesh_free(m->mesh);
    m->mesh = NULL;
    memset(&desc, 0, sizeof desc);
    desc.positions = m->pos;
    desc.nverts = m->nverts;
    desc.indices = m->vert;
    desc.nfaces = m->ntriangles;
    desc.fixed_face_size = 3;
    desc.flags = m->flags;
    if (tt_mesh_build(&desc, NULL, &m->mesh, &error) != TT_OK) {
        /* Say it about the OBJ's faces, which the user can find. */
        if (error.face >= 0 && error.face < m->ntriangles) error.face = m->face[error.face];
        if (error.other_face >= 0 && error.other_face < m->ntriangles) error.other_face = m->face[error.other_face];
        return obj_report_mesh_error(path, &m->obj, &error,
                                     offer_permissive && error.result != TT_ERROR_ZERO_AREA_FACE &&
                                         error.result != TT_ERROR_REPEATED_VERTEX);
    }
    return 0;
}

/* The triangles of an OBJ face follow one another, in fans and after
   subdivision alike. */
static void find_first_triangles(triangle_mesh *m)
{
    int t;
    for (t = m->ntriangles - 1; t >= 0; t--) m->first_triangle[m->face[t]] = t;
}

/* The OBJ's texture coordinates at the corners of the triangles, when every
   one of those corners has one (m->corner_uv stays NULL otherwise). */
static int take_corner_uvs(triangle_mesh *m, const int *corner)
{
    const obj_mesh *obj = &m->obj;
    size_t c, ncorners = 3 * (size_t)m->ntriangles;
    if (!obj->corner_uv) return 0;
    for (c = 0; c < ncorners; c++)
        if (obj->corner_uv[corner[c]] < 0) return 0;
    m->corner_uv = (float *)malloc(ncorners * 2 * sizeof(float));
    if (!m->corner_uv) return -1;
    for (c = 0; c < ncorners; c++)
        memcpy(m->corner_uv + 2 * c, obj->uv + 2 * obj->corner_uv[corner[c]], 2 * sizeof(float));
    return 0;
}

/* One quadrangulation step's bookkeeping, before tool_quadrangulate makes
   quad c of the next mesh from corner c of `mesh`: its corners are the
   corner's vertex, the point of the edge after it, the face point and the
   point of the edge before it (tt_mesh_quadrangulate's order). Each quad
   gets its OBJ face, and texture coordinates where the linear step puts
   those points: the corner's own, the edges' midpoints, the face's
   average. */
static int quad_sources(const tt_mesh *mesh, const int *face, const float *uv, int **quad_face, float **quad_uv)
{
    int f;
    *quad_face = (int *)malloc((size_t)mesh->ncorners * sizeof(int));
    *quad_uv = uv ? (float *)malloc((size_t)mesh->ncorners * 8 * sizeof(float)) : NULL;
    if (!*quad_face || (uv && !*quad_uv)) {
        free(*quad_face);
        free(*quad_uv);
        *quad_face = NULL;
        *quad_uv = NULL;
        return -1;
    }
    for (f = 0; f < mesh->nfaces; f++) {
        int first = mesh->face_start[f], end = mesh->face_start[f + 1], c, k;
        double centre[2] = {0.0, 0.0};
        for (c = first; c < end && uv; c++)
            for (k = 0; k < 2; k++) centre[k] += uv[2 * c + k];
        for (c = first; c < end; c++) {
            int next = c + 1 < end ? c + 1 : first, previous = c > first ? c - 1 : end - 1;
            float *q = uv ? *quad_uv + 8 * (size_t)c : NULL;
            (*quad_face)[c] = face[f];
            for (k = 0; k < 2 && q; k++) {
                q[k] = uv[2 * c + k];
                q[2 + k] = 0.5f * (uv[2 * c + k] + uv[2 * next + k]);
                q[4 + k] = (float)(centre[k] / (end - first));
                q[6 + k] = 0.5f * (uv[2 * previous + k] + uv[2 * c + k]);
            }
        }
    }
    return 0;
}

/* --subdivide L: the validated triangles quadrangulated L times, then every
   quad split into two triangles along the diagonal from its first corner
   (the vertex it grew from) to its third (the face point), which halves a
   square into two right triangles. Every triangle keeps its OBJ face, and
   the OBJ's texture coordinates are carried along. Replaces the triangles of
   m and builds them again. */
static int triangle_mesh_subdivide(const char *path, const tool_mesh_options *options, triangle_mesh *m)
{
    static const int split[6] = {0, 1, 2, 0, 2, 3};
    tt_mesh *mesh = m->mesh;
    int *face = m->face, *quad_face, *vert = NULL, step, q, k, status;
    float *uv = m->corner_uv, *quad_uv, *pos = NULL;
    /* This function owns mesh, face and uv from here on. */
    m->mesh = NULL;
    m->face = NULL;
    m->corner_uv = NULL;
    if ((status = tool_check_subdivide(path, mesh, options->subdivide)) != 0) goto done;
    for (step = 0; step < options->subdivide; step++) {
        if (quad_sources(mesh, face, uv, &quad_face, &quad_uv) != 0) goto out_of_memory;
        free(face);
        free(uv);
        face = quad_face;
        uv = quad_uv;
        if ((status = tool_quadrangulate(path, &mesh, options->smooth)) != 0) goto done;
    }

    quad_face = (int *)malloc((size_t)mesh->nfaces * 2 * sizeof(int));
    quad_uv = uv ? (float *)malloc((size_t)mesh->nfaces * 12 * sizeof(float)) : NULL;
    vert = (int *)malloc((size_t)mesh->nfaces * 6 * sizeof(int));
    pos = (float *)malloc((size_t)mesh->nverts * 3 * sizeof(float));
    if (!quad_face || (uv && !quad_uv) || !vert || !pos) {
        free(quad_face);
        free(quad_uv);
        goto out_of_memory;
    }
    for (q = 0; q < mesh->nfaces; q++) {
        const int *corner = mesh->corner_vert + mesh->face_start[q];
        const float *corner_uv = uv ? uv + 2 * (size_t)mesh->face_start[q] : NULL;
        int *triangles = vert + 6 * (size_t)q;
        float *triangles_uv = uv ? quad_uv + 12 * (size_t)q : NULL;
        for (k = 0; k < 6; k++) {
            triangles[k] = corner[split[k]];
            if (uv) memcpy(triangles_uv + 2 * k, corner_uv + 2 * split[k], 2 * sizeof(float));
        }
        quad_face[2 * q] = quad_face[2 * q + 1] = face[q];
    }
    memcpy(pos, mesh->pos, (size_t)mesh->nverts * 3 * sizeof(float));
    free(m->vert);
    m->vert = vert;
    m->face = quad_face;
    m->corner_uv = quad_uv;
    m->subdivided_pos = pos;
    m->pos = pos;
    m->nverts = mesh->nverts;
    m->ntriangles = 2 * mesh->nfaces;
    m->subdivided = options->subdivide;
    vert = NULL;
    pos = NULL;
    find_first_triangles(m);
    status = triangle_mesh_build(path, m, 1);
    goto done;
out_of_memory:
    status = tool_fail("out of memory subdividing %s", path);
done:
    free(vert);
    free(pos);
    free(face);
    free(uv);
    tt_mesh_free(mesh);
    return status;
}

/* Read the OBJ, split its faces into triangle fans and build those; then the
   mesh options. */
int triangle_mesh_read(const char *path, const tool_mesh_options *options, triangle_mesh *m)
{
    char message[TOOL_ERROR_SIZE];
    int c, total, status, *corner = NULL;
    memset(m, 0, sizeof *m);
    if (mesh_read(path, &m->obj, message, sizeof message) != 0) return tool_fail("%s", message);
    m->nverts = m->obj.nverts;
    m->pos = m->obj.pos;
    m->flags = options && options->permissive ? TT_MESH_PERMISSIVE : 0;
    total = m->ntriangles = obj_triangle_fans(&m->obj, &corner, &m->face);
    if (total >= 0) {
        m->vert = (int *)malloc((size_t)total * 3 * sizeof(int));
        m->first_triangle = (int *)malloc((size_t)m->obj.nfaces * sizeof(int));
    }
    if (!m->vert || !m->first_triangle || take_corner_uvs(m, corner) != 0) {
        free(corner);
        triangle_mesh_free(m);
        return tool_fail("out of memory for the triangles of %s", path);
    }
    for (c = 0; c < 3 * total; c++) m->vert[c] = m->obj.corner_vert[corner[c]];
    free(corner);
    find_first_triangles(m);
    status = triangle_mesh_build(path, m, options != NULL);
    if (status == 0) m->repaired_edges = m->mesh->repaired_edges;
    if (status == 0 && options && options->subdivide > 0) status = triangle_mesh_subdivide(path, options, m);
    if (status == 0) tool_note_cut_edges(path, m->repaired_edges);
    else triangle_mesh_free(m);
    return status;
}

int triangle_mesh_reverse(const char *path, triangle_mesh *m)
{
    int t, k;
    for (t = 0; t < m->ntriangles; t++) {
        int swap = m->vert[3 * t + 1];
        m->vert[3 * t + 1] = m->vert[3 * t + 2];
        m->vert[3 * t + 2] = swap;
        for (k = 0; k < 2 && m->corner_uv; k++) {
            float *uv = m->corner_uv + 6 * (size_t)t, swap_uv = uv[2 + k];
            uv[2 + k] = uv[4 + k];
            uv[4 + k] = swap_uv;
        }
    }
    return triangle_mesh_build(path, m, 0);
}

/* The library's "face N" is the Nth triangle counted from 0: replace the
   first such mention (not "face N0...") by the OBJ face it came from, counted
   from 1. */
void triangle_mesh_rewrite_face(const triangle_mesh *m, const tt_error *error, char *message, size_t size)
{
    char pattern[32];
    const char *at = NULL;
    size_t length = 0;
    if (error->face >= 0 && error->face < m->ntriangles) {
        length = (size_t)snprintf(pattern, sizeof pattern, "face %d", error->face);
        for (at = strstr(error->message, pattern); at && isdigit((unsigned char)at[length]);
             at = strstr(at + 1, pattern))
            continue;
    }
    if (at)
        snprintf(message, size, "%.*sface %d%s", (int)(at - error->message), error->message,
                 m->face[error->face] + 1, at + length);
    else
        snprintf(message, size, "%s", error->message);
}

int triangle_mesh_report_error(const char *path, const triangle_mesh *m, const tt_error *error)
{
    char message[sizeof error->message + 32];
    if (error->face < 0 || error->face >= m->ntriangles) return tool_fail("%s: %s", path, error->message);
    triangle_mesh_rewrite_face(m, error, message, sizeof message);
    return tool_fail("%s:%d: %s", path, m->obj.face_line[m->face[error->face]], message);
}
