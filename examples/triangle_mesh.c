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

/* values (components floats per corner of the mesh `sources` reads) carried
   to the new corners. NULL when out of memory or when a value is not finite
   (said). */
static float *carry_corner_values(const char *obj_path, const tt_corner_sources *sources, int components,
                                  const float *values)
{
    float *carried = (float *)malloc((size_t)sources->ncorners * (size_t)components * sizeof(float));
    tt_error error;
    if (!carried) {
        tool_fail("out of memory quadrangulating %s", obj_path);
        return NULL;
    }
    if (tt_corner_sources_apply(sources, components, values, carried, &error) != TT_OK) {
        tool_fail("%s: cannot carry the corners' values through quadrangulation: %s", obj_path, error.message);
        free(carried);
        return NULL;
    }
    return carried;
}

int tool_quadrangulate(const char *obj_path, tt_mesh **mesh, int smooth, float **corner_uv, float **corner_normal)
{
    tt_mesh *quads = NULL;
    tt_corner_sources *sources = NULL;
    float *uv = NULL, *normal = NULL;
    tt_error error;
    int carry_uv = corner_uv && *corner_uv, carry_normal = corner_normal && *corner_normal;
    if ((carry_uv || carry_normal) && tt_mesh_quadrangulate_sources(*mesh, NULL, &sources, &error) != TT_OK)
        return tool_fail("%s: cannot quadrangulate: %s", obj_path, error.message);
    tool_stage("subdividing");
    if (tt_mesh_quadrangulate(*mesh, smooth ? TT_SUBDIVIDE_CATMULL_CLARK : TT_SUBDIVIDE_LINEAR, NULL, &quads,
                              &error) != TT_OK) {
        tt_corner_sources_free(sources);
        return tool_fail("%s: cannot quadrangulate: %s", obj_path, error.message);
    }
    if ((carry_uv && !(uv = carry_corner_values(obj_path, sources, 2, *corner_uv))) ||
        (carry_normal && !(normal = carry_corner_values(obj_path, sources, 3, *corner_normal)))) {
        free(uv);
        tt_corner_sources_free(sources);
        tt_mesh_free(quads);
        return TOOL_EXIT_FAILURE;
    }
    tt_corner_sources_free(sources);
    tt_mesh_free(*mesh);
    *mesh = quads;
    if (carry_uv) {
        free(*corner_uv);
        *corner_uv = uv;
    }
    if (carry_normal) {
        free(*corner_normal);
        *corner_normal = normal;
    }
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
    free(m->corner_normal);
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
    tool_stage("checking the mesh");
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

/* The file's normals at the corners of the triangles (obj_corner_normals),
   when every corner has one (m->corner_normal stays NULL otherwise). */
static int take_corner_normals(const char *path, triangle_mesh *m, const int *corner)
{
    float *normals;
    size_t c, ncorners = 3 * (size_t)m->ntriangles;
    if (obj_corner_normals(path, &m->obj, &normals) != 0) return -1;
    if (!normals) return 0;
    m->corner_normal = (float *)malloc(ncorners * 3 * sizeof(float));
    for (c = 0; c < ncorners && m->corner_normal; c++)
        memcpy(m->corner_normal + 3 * c, normals + 3 * (size_t)corner[c], 3 * sizeof(float));
    free(normals);
    return m->corner_normal ? 0 : -1;
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
   quad c of the next mesh from corner c of `mesh`: each quad gets the OBJ
   face of the triangle it grows in. NULL when out of memory. */
static int *quad_faces(const tt_mesh *mesh, const int *face)
{
    int *quad_face = (int *)malloc((size_t)mesh->ncorners * sizeof(int)), c;
    for (c = 0; c < mesh->ncorners && quad_face; c++) quad_face[c] = face[mesh->corner_face[c]];
    return quad_face;
}

/* --subdivide splits every quad into two triangles along the diagonal from
   its first corner (the vertex it grew from) to its third (the face point),
   which halves a square into two right triangles: corner k of the triangles
   of quad q is corner split[k] of q. */
static const int quad_split[6] = {0, 1, 2, 0, 2, 3};

/* Per-corner values of the quads (components floats per corner) at the
   corners of their triangles; malloc'd. */
static float *split_corner_values(const tt_mesh *quads, const float *values, int components)
{
    float *split = (float *)malloc((size_t)quads->nfaces * 6 * (size_t)components * sizeof(float));
    int q, k;
    for (q = 0; q < quads->nfaces && split; q++)
        for (k = 0; k < 6; k++)
            memcpy(split + (6 * (size_t)q + (size_t)k) * (size_t)components,
                   values + ((size_t)quads->face_start[q] + (size_t)quad_split[k]) * (size_t)components,
                   (size_t)components * sizeof(float));
    return split;
}

/* --subdivide L: the validated triangles quadrangulated L times, then every
   quad split into two triangles (quad_split). Every triangle keeps its OBJ
   face, and the OBJ's texture coordinates and normals are carried along.
   Replaces the triangles of m and builds them again. */
int triangle_mesh_subdivide(const char *path, int steps, int smooth, triangle_mesh *m)
{
    tt_mesh *mesh = m->mesh;
    int *face = m->face, *quad_face, *vert = NULL, step, q, k, status;
    float *uv = m->corner_uv, *normal = m->corner_normal, *split_uv = NULL, *split_normal = NULL, *pos = NULL;
    /* This function owns mesh, face, uv and normal from here on. */
    m->mesh = NULL;
    m->face = NULL;
    m->corner_uv = NULL;
    m->corner_normal = NULL;
    if ((status = tool_check_subdivide(path, mesh, steps)) != 0) goto done;
    for (step = 0; step < steps; step++) {
        if (!(quad_face = quad_faces(mesh, face))) goto out_of_memory;
        free(face);
        face = quad_face;
        if ((status = tool_quadrangulate(path, &mesh, smooth, &uv, &normal)) != 0) goto done;
    }

    quad_face = (int *)malloc((size_t)mesh->nfaces * 2 * sizeof(int));
    vert = (int *)malloc((size_t)mesh->nfaces * 6 * sizeof(int));
    pos = (float *)malloc((size_t)mesh->nverts * 3 * sizeof(float));
    if (uv) split_uv = split_corner_values(mesh, uv, 2);
    if (normal) split_normal = split_corner_values(mesh, normal, 3);
    if (!quad_face || !vert || !pos || (uv && !split_uv) || (normal && !split_normal)) {
        free(quad_face);
        goto out_of_memory;
    }
    for (q = 0; q < mesh->nfaces; q++) {
        for (k = 0; k < 6; k++) vert[6 * (size_t)q + k] = mesh->corner_vert[mesh->face_start[q] + quad_split[k]];
        quad_face[2 * q] = quad_face[2 * q + 1] = face[q];
    }
    memcpy(pos, mesh->pos, (size_t)mesh->nverts * 3 * sizeof(float));
    free(m->vert);
    m->vert = vert;
    m->face = quad_face;
    m->corner_uv = split_uv;
    m->corner_normal = split_normal;
    m->subdivided_pos = pos;
    m->pos = pos;
    m->nverts = mesh->nverts;
    m->ntriangles = 2 * mesh->nfaces;
    m->subdivided = steps;
    vert = NULL;
    pos = NULL;
    split_uv = split_normal = NULL;
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
    free(normal);
    free(split_uv);
    free(split_normal);
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
    if (!m->vert || !m->first_triangle || take_corner_uvs(m, corner) != 0 ||
        take_corner_normals(path, m, corner) != 0) {
        free(corner);
        triangle_mesh_free(m);
        return tool_fail("out of memory for the triangles of %s", path);
    }
    for (c = 0; c < 3 * total; c++) m->vert[c] = m->obj.corner_vert[corner[c]];
    free(corner);
    find_first_triangles(m);
    status = triangle_mesh_build(path, m, options != NULL);
    if (status == 0) m->repaired_edges = m->mesh->repaired_edges;
    if (status == 0 && options && options->subdivide > 0)
        status = triangle_mesh_subdivide(path, options->subdivide, options->smooth, m);
    if (status == 0) tool_note_cut_edges(path, m->repaired_edges);
    else triangle_mesh_free(m);
    return status;
}

/* The file's normals after its faces were reversed: a file whose normals
   follow its (inward) winding gets them turned round with the faces, one
   whose normals already faced out despite the winding keeps them. Which,
   by the faces' normals against the file's over the whole mesh. */
static void orient_carried_normals(triangle_mesh *m)
{
    double agreement = 0.0;
    int t, k;
    float face[3];
    for (t = 0; t < m->ntriangles; t++) {
        tt_face_normal(m->mesh, t, face);
        for (k = 0; k < 3; k++) {
            const float *n = m->corner_normal + 9 * (size_t)t + 3 * k;
            agreement += (double)n[0] * face[0] + (double)n[1] * face[1] + (double)n[2] * face[2];
        }
    }
    if (agreement < 0.0)
        for (k = 0; k < 9 * m->ntriangles; k++) m->corner_normal[k] = -m->corner_normal[k];
}

int triangle_mesh_reverse(const char *path, triangle_mesh *m)
{
    int t, k, status;
    for (t = 0; t < m->ntriangles; t++) {
        int swap = m->vert[3 * t + 1];
        m->vert[3 * t + 1] = m->vert[3 * t + 2];
        m->vert[3 * t + 2] = swap;
        for (k = 0; k < 2 && m->corner_uv; k++) {
            float *uv = m->corner_uv + 6 * (size_t)t, swap_uv = uv[2 + k];
            uv[2 + k] = uv[4 + k];
            uv[4 + k] = swap_uv;
        }
        for (k = 0; k < 3 && m->corner_normal; k++) {
            float *normal = m->corner_normal + 9 * (size_t)t, swap_normal = normal[3 + k];
            normal[3 + k] = normal[6 + k];
            normal[6 + k] = swap_normal;
        }
    }
    status = triangle_mesh_build(path, m, 0);
    if (status == 0 && m->corner_normal) orient_carried_normals(m);
    return status;
}

tool_face_source triangle_mesh_faces(const triangle_mesh *m)
{
    tool_face_source faces;
    faces.mesh = m->mesh;
    faces.nfaces = m->ntriangles;
    faces.nsources = m->obj.nfaces;
    faces.source = m->face;
    faces.first = m->first_triangle;
    faces.source_line = m->obj.face_line;
    return faces;
}

/* The library's "face N" is the Nth face of the mesh counted from 0: replace
   the first such mention (not "face N0...") by the OBJ face it came from,
   counted from 1. */
static void face_source_rewrite(const tool_face_source *faces, const tt_error *error, char *message, size_t size)
{
    char pattern[32];
    const char *at = NULL;
    size_t length = 0;
    if (error->face >= 0 && error->face < faces->nfaces) {
        length = (size_t)snprintf(pattern, sizeof pattern, "face %d", error->face);
        for (at = strstr(error->message, pattern); at && isdigit((unsigned char)at[length]);
             at = strstr(at + 1, pattern))
            continue;
    }
    if (at)
        snprintf(message, size, "%.*sface %d%s", (int)(at - error->message), error->message,
                 faces->source[error->face] + 1, at + length);
    else
        snprintf(message, size, "%s", error->message);
}

static int face_source_report_error(const char *path, const tool_face_source *faces, const tt_error *error)
{
    char message[sizeof error->message + 32];
    if (error->face < 0 || error->face >= faces->nfaces) return tool_fail("%s: %s", path, error->message);
    /* Faces made anew (--remesh) trace back to no line of the file. */
    if (!faces->source_line) return tool_fail("%s: %s", path, error->message);
    face_source_rewrite(faces, error, message, sizeof message);
    return tool_fail("%s:%d: %s", path, faces->source_line[faces->source[error->face]], message);
}

void triangle_mesh_rewrite_face(const triangle_mesh *m, const tt_error *error, char *message, size_t size)
{
    tool_face_source faces = triangle_mesh_faces(m);
    face_source_rewrite(&faces, error, message, size);
}

int triangle_mesh_report_error(const char *path, const triangle_mesh *m, const tt_error *error)
{
    tool_face_source faces = triangle_mesh_faces(m);
    return face_source_report_error(path, &faces, error);
}

/* ======================================================================== */
/* The direction field: --up and --constraints (lapped, hpm, tile)          */
/* ======================================================================== */

typedef struct constraint_list {
    tt_field_constraint *items;
    int *line;              /* the file line of each */
    int count;
} constraint_list;

static void constraint_list_free(constraint_list *list)
{
    free(list->items);
    free(list->line);
    memset(list, 0, sizeof *list);
}

/* One line "FACE X Y Z [SIGMA [WEIGHT]]" ('#' comments and blank lines are
   skipped by the caller). FACE counts the OBJ's faces from 1; a polygon's
   constraint goes on the first face made from it (the first triangle of its
   fan, the first of its quads: they share its plane, or nearly).
   Returns 0, or the exit status after printing "FILE:LINE: ...". */
static int parse_constraint(char *text, const char *where, const tool_face_source *faces, tt_field_constraint *out)
{
    char *token[6];
    double value[6];
    long face;
    int ntokens = 0, k;
    char *p;
    for (p = strtok(text, " \t\r\v\f"); p; p = strtok(NULL, " \t\r\v\f")) {
        if (ntokens < 6) token[ntokens] = p;
        ntokens++;
    }
    if (ntokens < 4 || ntokens > 6)
        return tool_fail("%s: wants FACE X Y Z [SIGMA [WEIGHT]], got %d value%s", where, ntokens,
                         ntokens == 1 ? "" : "s");
    if (parse_whole_long(token[0], &face) != 0)
        return tool_fail("%s: FACE wants a face number, got '%s'", where, token[0]);
    if (face < 1 || face > faces->nsources)
        return tool_fail("%s: face %s is out of range: the mesh has faces 1 to %d", where, token[0],
                         faces->nsources);
    for (k = 1; k < ntokens; k++)
        if (parse_whole_double(token[k], &value[k]) != 0)
            return tool_fail("%s: '%s' is not a finite number", where, token[k]);
    if (value[1] == 0.0 && value[2] == 0.0 && value[3] == 0.0)
        return tool_fail("%s: the vector 0 0 0 has no direction", where);
    if ((ntokens > 4 && !(value[4] > 0.0)) || (ntokens > 5 && !(value[5] > 0.0)))
        return tool_fail("%s: SIGMA and WEIGHT must be above 0", where);
    memset(out, 0, sizeof *out);
    out->face = faces->first[face - 1];
    for (k = 0; k < 3; k++) out->vector[k] = (float)value[k + 1];
    out->sigma = ntokens > 4 ? (float)value[4] : 0.0f;
    out->weight = ntokens > 5 ? (float)value[5] : 0.0f;
    return 0;
}

static int read_constraints(const char *path, const tool_face_source *faces, constraint_list *list)
{
    unsigned char *data;
    size_t size;
    char message[TOOL_ERROR_SIZE], where[4096], *line, *next;
    int capacity = 0, number = 0, status = 0;
    memset(list, 0, sizeof *list);
    if (tool_read_file(path, &data, &size, message, sizeof message) != 0)
        return tool_fail("--constraints: %s", message);
    for (line = (char *)data; line && status == 0; line = next) {
        char *comment;
        number++;
        next = strchr(line, '\n');
        if (next) *next++ = '\0';
        if ((comment = strchr(line, '#')) != NULL) *comment = '\0';
        if (strspn(line, " \t\r\v\f") == strlen(line)) continue;
        if (list->count == capacity) {
            int grown = capacity ? 2 * capacity : 16;
            tt_field_constraint *items = (tt_field_constraint *)realloc(list->items, (size_t)grown * sizeof *items);
            int *lines = items ? (int *)realloc(list->line, (size_t)grown * sizeof(int)) : NULL;
            if (items) list->items = items;
            if (lines) list->line = lines;
            if (!items || !lines) {
                status = tool_fail("out of memory reading %s", path);
                break;
            }
            capacity = grown;
        }
        snprintf(where, sizeof where, "%s:%d", path, number);
        status = parse_constraint(line, where, faces, &list->items[list->count]);
        list->line[list->count++] = number;
    }
    free(data);
    if (status != 0) constraint_list_free(list);
    return status;
}

int tool_make_field(const char *mesh_path, const triangle_mesh *m, const tool_field *options, float scale,
                    float *face_vectors)
{
    tool_face_source faces = triangle_mesh_faces(m);
    return tool_make_face_field(mesh_path, &faces, options, scale, face_vectors);
}

int tool_make_face_field(const char *mesh_path, const tool_face_source *faces, const tool_field *options,
                         float scale, float *face_vectors)
{
    constraint_list constraints;
    tt_field_options field;
    tt_error error;
    int status = 0;
    memset(&constraints, 0, sizeof constraints);
    if (options->constraints_path &&
        (status = read_constraints(options->constraints_path, faces, &constraints)) != 0)
        return status;
    memset(&field, 0, sizeof field);
    memcpy(field.up, options->up, sizeof field.up);
    field.scale = scale;
    field.constraints = constraints.items;
    field.nconstraints = constraints.count;
    tool_stage("computing the direction field");
    if (tt_tangent_field(faces->mesh, &field, NULL, face_vectors, &error) != TT_OK) {
        /* An error about a constraint names it in error.item: say it at its
           line of the file (what reading the file could not see, such as a
           vector that the face's plane reduces to nothing). The library's
           sentence counts constraints and triangles from 0; its face is
           rewritten as the OBJ's face. */
        if (error.item >= 0 && error.item < constraints.count) {
            char message[sizeof error.message + 32], prefix[32];
            size_t length = (size_t)snprintf(prefix, sizeof prefix, "constraint %d", error.item);
            const char *text = message;
            face_source_rewrite(faces, &error, message, sizeof message);
            /* "constraint 0 (face 7): ..." counts from 0; the line says which. */
            if (strncmp(message, prefix, length) == 0 && !isdigit((unsigned char)message[length])) {
                text = message + length;
                while (*text == ' ') text++;
                status = tool_fail("%s:%d: the constraint %s", options->constraints_path,
                                   constraints.line[error.item], text);
            } else {
                status = tool_fail("%s:%d: %s", options->constraints_path, constraints.line[error.item], text);
            }
        } else {
            status = face_source_report_error(mesh_path, faces, &error);
        }
    }
    constraint_list_free(&constraints);
    return status;
}
