/* triangle_mesh.c - an OBJ read as triangles, for the commands whose
   library pipelines take triangle meshes (lapped, hpm). See tool.h for the
   interface. */

#include <ctype.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tool.h"

void triangle_mesh_free(triangle_mesh *m)
{
    obj_free(&m->obj);
    free(m->corner);
    free(m->vert);
    free(m->face);
    free(m->first_triangle);
    tt_mesh_free(m->mesh);
    memset(m, 0, sizeof *m);
}

/* (Re)build m->mesh from m->vert; a build error is said about the OBJ's
   face. */
static int triangle_mesh_build(const char *path, triangle_mesh *m)
{
    tt_mesh_desc desc;
    tt_error error;
    tt_mesh_free(m->mesh);
    m->mesh = NULL;
    memset(&desc, 0, sizeof desc);
    desc.positions = m->obj.pos;
    desc.nverts = m->obj.nverts;
    desc.indices = m->vert;
    desc.nfaces = m->ntriangles;
    desc.fixed_face_size = 3;
    if (tt_mesh_build(&desc, NULL, &m->mesh, &error) != TT_OK) {
        /* Say it about the OBJ's faces, which the user can find. */
        if (error.face >= 0 && error.face < m->ntriangles) error.face = m->face[error.face];
        if (error.other_face >= 0 && error.other_face < m->ntriangles) error.other_face = m->face[error.other_face];
        return obj_report_mesh_error(path, &m->obj, &error, 0);
    }
    return 0;
}

/* Read the OBJ, split its faces into triangle fans and build those. */
int triangle_mesh_read(const char *path, triangle_mesh *m)
{
    char message[TOOL_ERROR_SIZE];
    int c, t, total, status;
    memset(m, 0, sizeof *m);
    if (obj_read(path, &m->obj, message, sizeof message) != 0) return tool_fail("%s", message);
    total = m->ntriangles = obj_triangle_fans(&m->obj, &m->corner, &m->face);
    if (total >= 0) {
        m->vert = (int *)malloc((size_t)total * 3 * sizeof(int));
        m->first_triangle = (int *)malloc((size_t)m->obj.nfaces * sizeof(int));
    }
    if (!m->vert || !m->first_triangle) {
        triangle_mesh_free(m);
        return tool_fail("out of memory for the triangles of %s", path);
    }
    for (c = 0; c < 3 * total; c++) m->vert[c] = m->obj.corner_vert[m->corner[c]];
    for (t = total - 1; t >= 0; t--) m->first_triangle[m->face[t]] = t;
    if ((status = triangle_mesh_build(path, m)) != 0) triangle_mesh_free(m);
    return status;
}

int triangle_mesh_reverse(const char *path, triangle_mesh *m)
{
    int t;
    for (t = 0; t < m->ntriangles; t++) {
        int swap = m->vert[3 * t + 1];
        m->vert[3 * t + 1] = m->vert[3 * t + 2];
        m->vert[3 * t + 2] = swap;
        swap = m->corner[3 * t + 1];
        m->corner[3 * t + 1] = m->corner[3 * t + 2];
        m->corner[3 * t + 2] = swap;
    }
    return triangle_mesh_build(path, m);
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
