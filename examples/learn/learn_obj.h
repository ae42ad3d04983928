/* learn_obj.h - the smallest Wavefront OBJ reader and writer the learner's
   programs need, so that each of them can stay about the method it shows.

   Reading keeps only `v x y z` and `f a b c ...` lines (a face corner may be
   written a, a/t, a//n or a/t/n: only a, the vertex, is kept; negative
   indices count back from the last vertex). Everything else is skipped.
   Writing gives each face corner its own texture coordinate (one `vt` per
   corner), which is simple and always right, if not the smallest file, and
   writes the texture beside the OBJ with stb_image_write.
   Both return 0 on success and print one line to stderr otherwise. */
#ifndef LEARN_OBJ_H
#define LEARN_OBJ_H

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "tiledtex.h"               /* declarations only: the program holds the implementation */
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb/stb_image_write.h>    /* Debian's libstb-dev; include this header in one file only */

typedef struct learn_mesh {
    float *positions;   /* 3 * nverts */
    int nverts;
    int *indices;       /* face corners' vertices, faces one after another */
    int *face_sizes;    /* nfaces corner counts */
    int nfaces, ncorners;
} learn_mesh;

static void learn_obj_free(learn_mesh *mesh)
{
    free(mesh->positions);
    free(mesh->indices);
    free(mesh->face_sizes);
    memset(mesh, 0, sizeof *mesh);
}

/* One pass over the file: counts the vertices, faces and corners into
   `mesh`, and stores them too on the second pass, when `room` (the first
   pass's counts) says how much the arrays hold. */
static int learn_obj_pass(FILE *file, int triangulate, learn_mesh *mesh, const learn_mesh *room)
{
    char line[4096];
    mesh->nverts = mesh->nfaces = mesh->ncorners = 0;
    while (fgets(line, sizeof line, file)) {
        char *cursor = line + 1, *end;
        if (!strchr(line, '\n') && !feof(file)) return 1;                /* a line too long to read */
        if (line[0] == 'v' && (line[1] == ' ' || line[1] == '\t')) {
            int k;
            if (room && mesh->nverts >= room->nverts) return 1;           /* the file grew meanwhile */
            for (k = 0; k < 3; k++) {
                float value = strtof(cursor, &end);
                if (end == cursor) return 1;
                if (room) mesh->positions[3 * mesh->nverts + k] = value;
                cursor = end;
            }
            mesh->nverts++;
        } else if (line[0] == 'f' && (line[1] == ' ' || line[1] == '\t')) {
            int corners[256], n = 0, i;
            long index;
            while (n < 256 && (index = strtol(cursor, &end, 10), end != cursor)) {
                if (index > 1000000000L || index < -1000000000L) return 1;   /* keeps int sums exact */
                corners[n++] = index < 0 ? mesh->nverts + (int)index : (int)index - 1;   /* OBJ counts from 1 */
                cursor = end;
                while (*cursor && *cursor != ' ' && *cursor != '\t' && *cursor != '\n') cursor++;   /* past /t/n */
            }
            if (n < 3 || n == 256 || mesh->ncorners > 1000000000 - 3 * n) return 1;
            for (i = 1; i + 1 < n; i++) {           /* the fan's triangle (0, i, i + 1) */
                int size = triangulate ? 3 : n, k;
                if (room && (mesh->nfaces >= room->nfaces || mesh->ncorners + size > room->ncorners))
                    return 1;                       /* the file grew meanwhile */
                if (room) {
                    mesh->face_sizes[mesh->nfaces] = size;
                    for (k = 0; k < size; k++)
                        mesh->indices[mesh->ncorners + k] = corners[triangulate && k > 0 ? i + k - 1 : k];
                }
                mesh->nfaces++;
                mesh->ncorners += size;
                if (!triangulate) break;            /* the whole n-gon at once */
            }
        }
    }
    return 0;
}

/* Read `path`. With `triangulate`, each n-gon becomes the fan of n - 2
   triangles from its first corner (lapped textures, hierarchical pattern
   mapping and the polycube mapping take triangles). The library checks the
   indices and the geometry itself (tt_mesh_build). */
static int learn_obj_read(const char *path, int triangulate, learn_mesh *mesh)
{
    learn_mesh counted;
    FILE *file = fopen(path, "r");
    int failed;
    memset(mesh, 0, sizeof *mesh);
    if (!file) { fprintf(stderr, "cannot open %s\n", path); return 1; }
    failed = learn_obj_pass(file, triangulate, &counted, NULL);
    if (!failed) {
        mesh->positions = (float *)malloc(3 * sizeof(float) * (size_t)(counted.nverts + 1));
        mesh->indices = (int *)malloc(sizeof(int) * (size_t)(counted.ncorners + 1));
        mesh->face_sizes = (int *)malloc(sizeof(int) * (size_t)(counted.nfaces + 1));
        failed = !mesh->positions || !mesh->indices || !mesh->face_sizes;
        rewind(file);
        if (!failed) failed = learn_obj_pass(file, triangulate, mesh, &counted);
    }
    fclose(file);
    if (failed) { fprintf(stderr, "cannot read %s: a bad v or f line, or out of memory\n", path); learn_obj_free(mesh); }
    return failed;
}

/* Write PREFIX.png (the texture, encoded to sRGB as a colour photo is),
   PREFIX.mtl (a material showing it) and PREFIX.obj: positions, one
   texture coordinate per corner (2 floats, origin bottom-left), faces of
   `face_size` corners whose vertices are corner_vert[]. */
static int learn_obj_write(const char *prefix, const float *positions, int nverts, const int *corner_vert,
                           int ncorners, int face_size, const float *corner_uv, const tt_image *texture)
{
    char path[1024];
    const char *name = strrchr(prefix, '/') ? strrchr(prefix, '/') + 1 : prefix;   /* files beside the OBJ */
    unsigned char *rgba = (unsigned char *)malloc((size_t)texture->width * (size_t)texture->height * 4);
    FILE *obj, *mtl;
    int v, c, ok;
    snprintf(path, sizeof path, "%s.png", prefix);
    if (rgba) tt_image_to_rgba8(texture, TT_COLOR_SRGB, rgba);
    ok = rgba && stbi_write_png(path, texture->width, texture->height, 4, rgba, 4 * texture->width);
    free(rgba);
    if (!ok) { fprintf(stderr, "cannot write %s\n", path); return 1; }
    snprintf(path, sizeof path, "%s.mtl", prefix);
    if (!(mtl = fopen(path, "w"))) { fprintf(stderr, "cannot write %s\n", path); return 1; }
    fprintf(mtl, "newmtl textured\nKd 1 1 1\nmap_Kd %s.png\n", name);
    ok = !ferror(mtl);
    if (fclose(mtl) != 0 || !ok) { fprintf(stderr, "cannot write %s\n", path); return 1; }
    snprintf(path, sizeof path, "%s.obj", prefix);
    if (!(obj = fopen(path, "w"))) { fprintf(stderr, "cannot write %s\n", path); return 1; }
    fprintf(obj, "mtllib %s.mtl\nusemtl textured\n", name);
    for (v = 0; v < nverts; v++)
        fprintf(obj, "v %.9g %.9g %.9g\n", positions[3 * v], positions[3 * v + 1], positions[3 * v + 2]);
    for (c = 0; c < ncorners; c++) fprintf(obj, "vt %.9g %.9g\n", corner_uv[2 * c], corner_uv[2 * c + 1]);
    for (c = 0; c < ncorners; c++)   /* OBJ counts from 1: corner c is vertex corner_vert[c] + 1, vt c + 1 */
        fprintf(obj, "%s%d/%d%s", c % face_size ? " " : "f ", corner_vert[c] + 1, c + 1,
                c % face_size == face_size - 1 ? "\n" : "");
    ok = !ferror(obj);
    if (fclose(obj) != 0 || !ok) { fprintf(stderr, "cannot write %s\n", path); return 1; }
    return 0;
}

#endif
