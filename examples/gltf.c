/* gltf.c - glTF 2.0 writing for the `tiledtex` tool: the textured mesh a
   command made, its material and the material's images, in the forms
   other programs open (Blender, game engines, web viewers). See tool.h for
   the interface.

   A GLB (.glb) is one file: a 12-byte header, a JSON chunk describing the
   scene and a BIN chunk holding the data the JSON points into. Here the
   BIN chunk holds, each from a 4-byte boundary: the vertices' positions,
   normals, tangents (with a normal map) and texture coordinates (one array
   each), the triangles' indices, and the material's PNG files. Every number
   in the file is little-endian, whatever the machine writing it.

   The separate form (.gltf) is the same scene as text: the JSON in the
   .gltf file, the same arrays in a .bin file beside it, and each PNG a file
   of its own, which the JSON names by relative URIs. An editor can open
   the JSON, and a PNG can be changed without rewriting the rest.

   glTF keeps one texture coordinate and one normal per vertex, where the
   tool's meshes have them per face corner: a glTF vertex is made for each
   distinct (position, texture coordinate, normal) a corner has, so the
   corners of smooth, continuous parts share vertices and a seam in the
   texture or a crease gets two. */

#include <limits.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tool.h"

#define GLB_MAGIC 0x46546C67u         /* "glTF" */
#define GLB_VERSION 2u
#define GLB_CHUNK_JSON 0x4E4F534Au    /* "JSON" */
#define GLB_CHUNK_BIN 0x004E4942u     /* "BIN\0" */
#define GLB_HEADER_SIZE 12u
#define GLB_CHUNK_HEADER_SIZE 8u

/* The numbers glTF takes from OpenGL. */
#define GL_UNSIGNED_SHORT 5123
#define GL_UNSIGNED_INT 5125
#define GL_FLOAT 5126
#define GL_ARRAY_BUFFER 34962
#define GL_ELEMENT_ARRAY_BUFFER 34963
#define GL_LINEAR 9729
#define GL_LINEAR_MIPMAP_LINEAR 9987
#define GL_REPEAT 10497
#define GL_CLAMP_TO_EDGE 33071
#define GLTF_TRIANGLES 4

/* glTF forbids an index equal to its type's largest value (the primitive
   restart value of some APIs), so 16-bit indices number at most 65535
   vertices, 0 to 65534. */
#define GLB_MAX_SHORT_VERTICES 65535

/* The texture slots of a material, in the order the file lists them. */
enum { SLOT_BASE_COLOR, SLOT_NORMAL, SLOT_METALLIC_ROUGHNESS, SLOT_OCCLUSION, SLOT_COUNT };
static const char *const slot_names[SLOT_COUNT] = {"baseColor", "normal", "metallicRoughness", "occlusion"};

/* The separate form's URIs, relative to the .gltf (percent-encoded): its
   buffer and each slot's PNG. The GLB form has none (a NULL gltf_uris). */
typedef struct gltf_uris {
    char buffer[1024];
    char image[SLOT_COUNT][1024];
} gltf_uris;

static size_t padded4(size_t size)
{
    return (size + 3u) & ~(size_t)3u;
}

static unsigned char *put_u32(unsigned char *p, uint32_t value)
{
    p[0] = (unsigned char)(value & 0xFFu);
    p[1] = (unsigned char)((value >> 8) & 0xFFu);
    p[2] = (unsigned char)((value >> 16) & 0xFFu);
    p[3] = (unsigned char)(value >> 24);
    return p + 4;
}

static unsigned char *put_floats(unsigned char *p, const float *values, size_t count)
{
    size_t i;
    for (i = 0; i < count; i++) {
        uint32_t bits;
        memcpy(&bits, &values[i], sizeof bits);
        p = put_u32(p, bits);
    }
    return p;
}

static uint32_t float_bits(float value)
{
    uint32_t bits;
    memcpy(&bits, &value, sizeof bits);
    return bits;
}

/* ======================================================================== */
/* The material's images                                                    */
/* ======================================================================== */

/* Row `y` of `image` as 8-bit RGBA in `space`, into `row` (4 * width bytes):
   the library's own conversion, on a one-row view, so that a whole image
   never needs a second buffer of bytes beside the packed one. */
static void row_to_rgba8(const tt_image *image, int y, tt_color_space space, unsigned char *row)
{
    tt_image view;
    memset(&view, 0, sizeof view);
    view.width = image->width;
    view.height = 1;
    view.pixels = image->pixels + 4 * (size_t)y * (size_t)image->width;
    tt_image_to_rgba8(&view, space, row);
}

int gltf_pack_metallic_roughness(const tt_image *roughness, const tt_image *metallic, unsigned char **rgba,
                                 int *width, int *height, char *err, size_t err_size)
{
    const tt_image *sized = roughness ? roughness : metallic;
    unsigned char *rough_row = NULL, *metal_row = NULL;
    int x, y;
    *rgba = NULL;
    *width = *height = 0;
    if (!sized) {
        tool_set_error(err, err_size, "no roughness or metallic map to pack");
        return -1;
    }
    if (roughness && metallic && (roughness->width != metallic->width || roughness->height != metallic->height)) {
        tool_set_error(err, err_size,
                       "the roughness map is %dx%d and the metallic map %dx%d: glTF packs them into one texture, "
                       "so they must be the same size",
                       roughness->width, roughness->height, metallic->width, metallic->height);
        return -1;
    }
    *rgba = (unsigned char *)malloc((size_t)sized->width * (size_t)sized->height * 4);
    if (roughness) rough_row = (unsigned char *)malloc((size_t)sized->width * 4);
    if (metallic) metal_row = (unsigned char *)malloc((size_t)sized->width * 4);
    if (!*rgba || (roughness && !rough_row) || (metallic && !metal_row)) {
        free(*rgba);
        free(rough_row);
        free(metal_row);
        *rgba = NULL;
        tool_set_error(err, err_size, "out of memory for a %dx%d metallic-roughness texture", sized->width,
                       sized->height);
        return -1;
    }
    for (y = 0; y < sized->height; y++) {
        unsigned char *out = *rgba + 4 * (size_t)y * (size_t)sized->width;
        if (roughness) row_to_rgba8(roughness, y, TT_COLOR_LINEAR, rough_row);
        if (metallic) row_to_rgba8(metallic, y, TT_COLOR_LINEAR, metal_row);
        for (x = 0; x < sized->width; x++) {
            /* glTF reads roughness from G and metalness from B and multiplies
               each by its factor; R is not read. An absent roughness map's
               channel is 1, so that its factor alone gives the value. An
               absent metallic map's factor is 0 (the material JSON), which
               makes B unread too: then R and B repeat the roughness and the
               PNG is a grey one, a third of the bytes. */
            const unsigned char rough = roughness ? rough_row[4 * x] : 255;
            out[4 * x] = metallic ? 255 : rough;
            out[4 * x + 1] = rough;
            out[4 * x + 2] = metallic ? metal_row[4 * x] : rough;
            out[4 * x + 3] = 255;
        }
    }
    free(rough_row);
    free(metal_row);
    *width = sized->width;
    *height = sized->height;
    return 0;
}

/* The PNG files of a material, one per slot that has an image. */
typedef struct glb_images {
    unsigned char *png[SLOT_COUNT];
    size_t size[SLOT_COUNT];
} glb_images;

static void glb_images_free(glb_images *images)
{
    int s;
    for (s = 0; s < SLOT_COUNT; s++) free(images->png[s]);
    memset(images, 0, sizeof *images);
}

static int encode_image(const tt_image *image, tt_color_space space, const char *what, unsigned char **png,
                        size_t *size, char *err, size_t err_size)
{
    char message[TOOL_ERROR_SIZE];
    if (png_encode(image, space, png, size, message, sizeof message) != 0) {
        tool_set_error(err, err_size, "the %s texture: %s", what, message);
        return -1;
    }
    return 0;
}

/* Colour is sRGB in the file, as glTF defines baseColorTexture; the other
   maps are data, their bytes taken as they are. The images are encoded one
   after another, so at most one image's bytes exist beside the PNGs. */
static int encode_material(const tool_material *material, glb_images *images, char *err, size_t err_size)
{
    memset(images, 0, sizeof *images);
    if (material->base_color &&
        encode_image(material->base_color, TT_COLOR_SRGB, "base colour", &images->png[SLOT_BASE_COLOR],
                     &images->size[SLOT_BASE_COLOR], err, err_size) != 0)
        goto fail;
    /* A normal map of unit vectors (TT_IMAGE_NORMAL, as the commands hold
       them) is encoded to glTF's (n + 1) / 2; one still in its bytes' form
       is written as it is. */
    if (material->normal &&
        encode_image(material->normal, material->normal->kind == TT_IMAGE_NORMAL ? TT_COLOR_NORMAL : TT_COLOR_LINEAR,
                     "normal", &images->png[SLOT_NORMAL], &images->size[SLOT_NORMAL], err, err_size) != 0)
        goto fail;
    if (material->roughness || material->metallic) {
        unsigned char *rgba;
        int width, height, status;
        char message[TOOL_ERROR_SIZE];
        if (gltf_pack_metallic_roughness(material->roughness, material->metallic, &rgba, &width, &height, err,
                                         err_size) != 0)
            goto fail;
        status = png_encode_rgba8(rgba, width, height, &images->png[SLOT_METALLIC_ROUGHNESS],
                                  &images->size[SLOT_METALLIC_ROUGHNESS], message, sizeof message);
        free(rgba);
        if (status != 0) {
            tool_set_error(err, err_size, "the metallic-roughness texture: %s", message);
            goto fail;
        }
    }
    if (material->occlusion &&
        encode_image(material->occlusion, TT_COLOR_LINEAR, "occlusion", &images->png[SLOT_OCCLUSION],
                     &images->size[SLOT_OCCLUSION], err, err_size) != 0)
        goto fail;
    return 0;
fail:
    glb_images_free(images);
    return -1;
}

/* ======================================================================== */
/* Vertices: one per distinct (position, texture coordinate, normal)        */
/* ======================================================================== */

typedef struct glb_vertices {
    int count;
    int *source;            /* per vertex: the first corner that made it */
    int *corner_vertex;     /* per corner: its vertex */
    float *unit_normal;     /* 3 per corner: the corner's normal made unit length; NULL without normals */
    float *tangent;         /* 4 per vertex (make_tangents), or NULL */
    int ntriangles;
    float min[3], max[3];   /* the positions' bounds */
} glb_vertices;

static void glb_vertices_free(glb_vertices *v)
{
    free(v->source);
    free(v->corner_vertex);
    free(v->unit_normal);
    free(v->tangent);
    memset(v, 0, sizeof *v);
}

static int face_size_of(const obj_write_desc *mesh, int f)
{
    return mesh->face_size ? mesh->face_size[f] : mesh->fixed_face_size;
}

/* A face's normal by Newell's method (the sum of its edges' cross terms):
   exact for a planar polygon, sensible for a bent one, zero only for a
   face without area. */
static void face_normal(const obj_write_desc *mesh, int first, int size, double n[3])
{
    int i;
    n[0] = n[1] = n[2] = 0.0;
    for (i = 0; i < size; i++) {
        const float *a = mesh->pos + 3 * (size_t)mesh->corner_vert[first + i];
        const float *b = mesh->pos + 3 * (size_t)mesh->corner_vert[first + (i + 1) % size];
        n[0] += ((double)a[1] - b[1]) * ((double)a[2] + b[2]);
        n[1] += ((double)a[2] - b[2]) * ((double)a[0] + b[0]);
        n[2] += ((double)a[0] - b[0]) * ((double)a[1] + b[1]);
    }
}

/* glTF wants unit normals. A corner's normal is normalised; one of zero
   length (or not finite) takes its face's normal, and a face without area
   any unit vector (it covers no pixel). */
static void unit_corner_normal(const obj_write_desc *mesh, int corner, const double face[3], float out[3])
{
    const float *n = mesh->corner_normal + 3 * (size_t)corner;
    double x = n[0], y = n[1], z = n[2], length = sqrt(x * x + y * y + z * z);
    if (!(length > 0.0) || !(length < HUGE_VAL)) {
        x = face[0];
        y = face[1];
        z = face[2];
        length = sqrt(x * x + y * y + z * z);
    }
    if (!(length > 0.0) || !(length < HUGE_VAL)) {
        x = y = 0.0;
        z = length = 1.0;
    }
    out[0] = (float)(x / length);
    out[1] = (float)(y / length);
    out[2] = (float)(z / length);
}

static uint32_t mix_hash(uint32_t hash, uint32_t value)
{
    hash ^= value;
    hash *= 0x9E3779B1u;
    return hash ^ (hash >> 15);
}

static uint32_t corner_hash(const obj_write_desc *mesh, const glb_vertices *v, int c)
{
    uint32_t hash = mix_hash(0x2545F491u, (uint32_t)mesh->corner_vert[c]);
    int k;
    if (mesh->corner_uv)
        for (k = 0; k < 2; k++) hash = mix_hash(hash, float_bits(mesh->corner_uv[2 * (size_t)c + k]));
    if (v->unit_normal)
        for (k = 0; k < 3; k++) hash = mix_hash(hash, float_bits(v->unit_normal[3 * (size_t)c + k]));
    return hash;
}

/* The same vertex: the same position, and bit for bit the same texture
   coordinate and normal. */
static int same_corner(const obj_write_desc *mesh, const glb_vertices *v, int a, int b)
{
    return mesh->corner_vert[a] == mesh->corner_vert[b] &&
           (!mesh->corner_uv || memcmp(mesh->corner_uv + 2 * (size_t)a, mesh->corner_uv + 2 * (size_t)b,
                                       2 * sizeof(float)) == 0) &&
           (!v->unit_normal || memcmp(v->unit_normal + 3 * (size_t)a, v->unit_normal + 3 * (size_t)b,
                                      3 * sizeof(float)) == 0);
}

static int make_vertices(const obj_write_desc *mesh, glb_vertices *v, char *err, size_t err_size)
{
    int f, c, first = 0, ncorners = 0, k;
    size_t table_size = 16, mask;
    int *table = NULL;
    memset(v, 0, sizeof *v);
    for (f = 0; f < mesh->nfaces; f++) {
        int size = face_size_of(mesh, f);
        if (size < 3) {
            tool_set_error(err, err_size, "face %d has %d corners", f + 1, size);
            return -1;
        }
        if (size > INT_MAX - ncorners) {
            tool_set_error(err, err_size, "too many face corners for one GLB");
            return -1;
        }
        ncorners += size;
        v->ntriangles += size - 2;
    }
    if (v->ntriangles == 0) {
        tool_set_error(err, err_size, "the mesh has no faces");
        return -1;
    }
    for (c = 0; c < ncorners; c++)
        if (mesh->corner_vert[c] < 0 || mesh->corner_vert[c] >= mesh->nverts) {
            tool_set_error(err, err_size, "face corner %d names vertex %d of %d", c + 1, mesh->corner_vert[c] + 1,
                           mesh->nverts);
            return -1;
        }
    while (table_size < 2 * (size_t)ncorners) table_size *= 2;
    mask = table_size - 1;
    table = (int *)calloc(table_size, sizeof(int));
    v->source = (int *)malloc((size_t)ncorners * sizeof(int));
    v->corner_vertex = (int *)malloc((size_t)ncorners * sizeof(int));
    if (mesh->corner_normal) v->unit_normal = (float *)malloc((size_t)ncorners * 3 * sizeof(float));
    if (!table || !v->source || !v->corner_vertex || (mesh->corner_normal && !v->unit_normal)) {
        free(table);
        glb_vertices_free(v);
        tool_set_error(err, err_size, "out of memory for the vertices of %d face corners", ncorners);
        return -1;
    }
    if (v->unit_normal)
        for (f = 0; f < mesh->nfaces; first += face_size_of(mesh, f), f++) {
            double normal[3];
            face_normal(mesh, first, face_size_of(mesh, f), normal);
            for (c = first; c < first + face_size_of(mesh, f); c++)
                unit_corner_normal(mesh, c, normal, v->unit_normal + 3 * (size_t)c);
        }
    for (c = 0; c < ncorners; c++) {
        size_t slot = corner_hash(mesh, v, c) & mask;
        /* table holds vertex + 1, 0 = empty; at most half full: probing ends. */
        while (table[slot] && !same_corner(mesh, v, v->source[table[slot] - 1], c)) slot = (slot + 1) & mask;
        if (!table[slot]) {
            v->source[v->count++] = c;
            table[slot] = v->count;
        }
        v->corner_vertex[c] = table[slot] - 1;
    }
    free(table);
    for (k = 0; k < 3; k++) v->min[k] = v->max[k] = mesh->pos[3 * (size_t)mesh->corner_vert[0] + k];
    for (c = 0; c < ncorners; c++) {
        const float *xyz = mesh->pos + 3 * (size_t)mesh->corner_vert[c];
        const float *uv = mesh->corner_uv ? mesh->corner_uv + 2 * (size_t)c : NULL;
        /* glTF has no use for NaN or infinity (the validator calls them
           errors), and neither has a renderer. */
        if (!isfinite(xyz[0]) || !isfinite(xyz[1]) || !isfinite(xyz[2]) ||
            (uv && (!isfinite(uv[0]) || !isfinite(uv[1])))) {
            glb_vertices_free(v);
            tool_set_error(err, err_size, "vertex %d has a %s that is NaN or infinite", mesh->corner_vert[c] + 1,
                           uv && (!isfinite(uv[0]) || !isfinite(uv[1])) ? "texture coordinate" : "coordinate");
            return -1;
        }
        for (k = 0; k < 3; k++) {
            if (xyz[k] < v->min[k]) v->min[k] = xyz[k];
            if (xyz[k] > v->max[k]) v->max[k] = xyz[k];
        }
    }
    return 0;
}

int triangle_texture_axes(const float *p0, const float *p1, const float *p2, const float *t0, const float *t1,
                          const float *t2, double axes[6])
{
    double du1 = (double)t1[0] - t0[0], dv1 = (double)t1[1] - t0[1];
    double du2 = (double)t2[0] - t0[0], dv2 = (double)t2[1] - t0[1];
    double det = du1 * dv2 - du2 * dv1;
    int k;
    for (k = 0; k < 6; k++) axes[k] = 0.0;
    if (!(fabs(det) > 0.0)) return -1;
    for (k = 0; k < 3; k++) {
        double e1 = (double)p1[k] - p0[k], e2 = (double)p2[k] - p0[k];
        axes[k] = (e1 * dv2 - e2 * dv1) / det;
        axes[3 + k] = (e2 * du1 - e1 * du2) / det;
    }
    for (k = 0; k < 6; k++)
        if (!isfinite(axes[k])) {
            for (k = 0; k < 6; k++) axes[k] = 0.0;
            return -1;
        }
    return 0;
}

/* Tangents for a normal map: glTF reads a normal texture in the frame of
   each vertex's tangent (xyz, along +u) and bitangent (cross(normal,
   tangent) * w, along the image's up, which is +v in the tool's
   coordinates). Without them a renderer derives its own (the validator
   warns that those may differ between programs). Each triangle's texture
   axes dP/du and dP/dv, made unit so that every triangle counts alike, are
   summed at its vertices; a vertex's tangent is the sum made perpendicular
   to its normal, and w says on which side the summed bitangent lies. These
   are the axes the tool's maps were laid out along (its renderer takes
   them per triangle), and what MikkTSpace gives where the texture is
   continuous. Returns -1 when out of memory. */
static int make_tangents(const obj_write_desc *mesh, glb_vertices *v)
{
    double *sum = (double *)calloc((size_t)v->count * 6, sizeof(double));
    int f, i, k, first = 0;
    v->tangent = (float *)malloc((size_t)v->count * 4 * sizeof(float));
    if (!sum || !v->tangent) {
        free(sum);
        free(v->tangent);
        v->tangent = NULL;
        return -1;
    }
    for (f = 0; f < mesh->nfaces; first += face_size_of(mesh, f), f++)
        for (i = 1; i + 1 < face_size_of(mesh, f); i++) {
            int corner[3] = {first, first + i, first + i + 1};
            const float *p0 = mesh->pos + 3 * (size_t)mesh->corner_vert[corner[0]];
            const float *p1 = mesh->pos + 3 * (size_t)mesh->corner_vert[corner[1]];
            const float *p2 = mesh->pos + 3 * (size_t)mesh->corner_vert[corner[2]];
            double axes[6], lt = 0.0, lb = 0.0;
            if (triangle_texture_axes(p0, p1, p2, mesh->corner_uv + 2 * (size_t)corner[0],
                                      mesh->corner_uv + 2 * (size_t)corner[1], mesh->corner_uv + 2 * (size_t)corner[2],
                                      axes) != 0)
                continue;
            for (k = 0; k < 3; k++) {
                lt += axes[k] * axes[k];
                lb += axes[3 + k] * axes[3 + k];
            }
            lt = sqrt(lt);
            lb = sqrt(lb);
            if (!(lt > 0.0) || !(lb > 0.0) || !(lt < HUGE_VAL) || !(lb < HUGE_VAL)) continue;
            for (k = 0; k < 3; k++) {
                int j;
                double *s = sum + 6 * (size_t)v->corner_vertex[corner[k]];
                for (j = 0; j < 3; j++) {
                    s[j] += axes[j] / lt;
                    s[3 + j] += axes[3 + j] / lb;
                }
            }
        }
    for (i = 0; i < v->count; i++) {
        const float *n = v->unit_normal + 3 * (size_t)v->source[i];
        const double *s = sum + 6 * (size_t)i;
        double along = s[0] * n[0] + s[1] * n[1] + s[2] * n[2], t[3], length, c[3];
        for (k = 0; k < 3; k++) t[k] = s[k] - along * n[k];
        length = sqrt(t[0] * t[0] + t[1] * t[1] + t[2] * t[2]);
        if (!(length > 1e-12)) {
            /* no texture axes here: any direction across the normal */
            double a[3] = {fabs(n[0]) < 0.9 ? 1.0 : 0.0, fabs(n[0]) < 0.9 ? 0.0 : 1.0, 0.0};
            along = a[0] * n[0] + a[1] * n[1];
            for (k = 0; k < 3; k++) t[k] = a[k] - along * n[k];
            length = sqrt(t[0] * t[0] + t[1] * t[1] + t[2] * t[2]);
        }
        for (k = 0; k < 3; k++) v->tangent[4 * (size_t)i + k] = (float)(t[k] / length);
        c[0] = n[1] * t[2] - n[2] * t[1];
        c[1] = n[2] * t[0] - n[0] * t[2];
        c[2] = n[0] * t[1] - n[1] * t[0];
        v->tangent[4 * (size_t)i + 3] = c[0] * s[3] + c[1] * s[4] + c[2] * s[5] < 0.0 ? -1.0f : 1.0f;
    }
    free(sum);
    return 0;
}

/* ======================================================================== */
/* The JSON chunk                                                           */
/* ======================================================================== */

/* The length of the well-formed UTF-8 sequence at s (2 to 4 bytes), or 0:
   no overlong forms, no surrogates, nothing past U+10FFFF. */
static int utf8_length(const unsigned char *s)
{
    int n = s[0] >= 0xC2 && s[0] <= 0xDF ? 2 : s[0] >= 0xE0 && s[0] <= 0xEF ? 3 : s[0] >= 0xF0 && s[0] <= 0xF4 ? 4 : 0;
    int i;
    if (n == 0) return 0;
    for (i = 1; i < n; i++)
        if ((s[i] & 0xC0) != 0x80) return 0;
    if ((s[0] == 0xE0 && s[1] < 0xA0) || (s[0] == 0xED && s[1] >= 0xA0) || (s[0] == 0xF0 && s[1] < 0x90) ||
        (s[0] == 0xF4 && s[1] >= 0x90))
        return 0;
    return n;
}

/* A JSON string: quotes, backslashes and control bytes escaped, UTF-8 kept;
   a byte that is not UTF-8 (a file name in Latin-1, say) becomes '?', since
   glTF's JSON must be UTF-8. */
static void json_string(tool_buffer *out, const char *text)
{
    const unsigned char *p = (const unsigned char *)text;
    buffer_append(out, "\"", 1);
    while (*p) {
        int length = *p < 0x80 ? 1 : utf8_length(p);
        if (*p == '"' || *p == '\\') {
            char escaped[2];
            escaped[0] = '\\';
            escaped[1] = (char)*p;
            buffer_append(out, escaped, 2);
        } else if (*p < 0x20) {
            buffer_printf(out, "\\u%04x", *p);
        } else {
            buffer_append(out, length ? (const char *)p : "?", length ? (size_t)length : 1);
        }
        p += length ? length : 1;
    }
    buffer_append(out, "\"", 1);
}

/* Floats as the OBJ writer prints them: 9 significant digits read back as
   the same float, which the validator wants of an accessor's min and max. */
static void json_floats(tool_buffer *out, const float *values, int count)
{
    int i;
    buffer_append(out, "[", 1);
    for (i = 0; i < count; i++) {
        char text[TOOL_NUMBER_TEXT_SIZE];
        int length = tool_format_float(values[i], text);
        if (i > 0) buffer_append(out, ",", 1);
        buffer_append(out, text, (size_t)length);
    }
    buffer_append(out, "]", 1);
}

enum { VIEW_POSITION, VIEW_NORMAL, VIEW_TANGENT, VIEW_UV, VIEW_INDEX, VIEW_IMAGE };
/* Where each array starts in the BIN chunk, and how long it is. */
typedef struct glb_layout {
    size_t offset[VIEW_IMAGE + SLOT_COUNT], length[VIEW_IMAGE + SLOT_COUNT];
    int view[VIEW_IMAGE + SLOT_COUNT];   /* its bufferView, -1 when absent */
    int nviews;
    size_t bin_size;
    int short_indices;
} glb_layout;

/* The BIN chunk's (or the .bin file's) arrays; the images go into it in
   the GLB form only (embed_images). */
static void plan_layout(const glb_vertices *v, int has_normals, int has_uvs, const glb_images *images,
                        int embed_images, glb_layout *layout)
{
    size_t lengths[VIEW_IMAGE + SLOT_COUNT];
    int i;
    memset(layout, 0, sizeof *layout);
    layout->short_indices = v->count <= GLB_MAX_SHORT_VERTICES;
    lengths[VIEW_POSITION] = 12 * (size_t)v->count;
    lengths[VIEW_NORMAL] = has_normals ? 12 * (size_t)v->count : 0;
    lengths[VIEW_TANGENT] = v->tangent ? 16 * (size_t)v->count : 0;
    lengths[VIEW_UV] = has_uvs ? 8 * (size_t)v->count : 0;
    lengths[VIEW_INDEX] = 3 * (size_t)v->ntriangles * (layout->short_indices ? 2 : 4);
    for (i = 0; i < SLOT_COUNT; i++) lengths[VIEW_IMAGE + i] = embed_images && images->png[i] ? images->size[i] : 0;
    for (i = 0; i < VIEW_IMAGE + SLOT_COUNT; i++) {
        layout->view[i] = lengths[i] > 0 ? layout->nviews++ : -1;
        layout->offset[i] = layout->bin_size;
        layout->length[i] = lengths[i];
        layout->bin_size += padded4(lengths[i]);
    }
}

static void json_view(tool_buffer *out, const glb_layout *layout, int i, int target)
{
    buffer_printf(out, "%s{\"buffer\":0,\"byteOffset\":%lu,\"byteLength\":%lu", layout->view[i] > 0 ? "," : "",
                  (unsigned long)layout->offset[i], (unsigned long)layout->length[i]);
    if (target) buffer_printf(out, ",\"target\":%d", target);
    buffer_append(out, "}", 1);
}

/* The scene's JSON; `uris` NULL for the GLB form (images in the BIN
   chunk), else the separate form's files. */
static void write_json(tool_buffer *out, const tool_material *material, const char *name, const glb_vertices *v,
                       const glb_images *images, const glb_layout *layout, const gltf_uris *uris)
{
    int texture[SLOT_COUNT], ntextures = 0, s, accessor = 0;
    int normal_accessor = -1, tangent_accessor = -1, uv_accessor = -1, index_accessor;
    for (s = 0; s < SLOT_COUNT; s++) texture[s] = images->png[s] ? ntextures++ : -1;

    buffer_printf(out, "{\"asset\":{\"version\":\"2.0\",\"generator\":\"tiledtex %s\"},", TILEDTEX_VERSION_STRING);
    buffer_printf(out, "\"scene\":0,\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"mesh\":0,\"name\":");
    json_string(out, name);
    buffer_printf(out, "}],");

    /* accessors: positions, normals, texture coordinates, indices */
    buffer_printf(out, "\"accessors\":[{\"bufferView\":%d,\"componentType\":%d,\"count\":%d,\"type\":\"VEC3\",\"min\":",
                  layout->view[VIEW_POSITION], GL_FLOAT, v->count);
    json_floats(out, v->min, 3);
    buffer_printf(out, ",\"max\":");
    json_floats(out, v->max, 3);
    buffer_append(out, "}", 1);
    if (layout->view[VIEW_NORMAL] >= 0) {
        normal_accessor = ++accessor;
        buffer_printf(out, ",{\"bufferView\":%d,\"componentType\":%d,\"count\":%d,\"type\":\"VEC3\"}",
                      layout->view[VIEW_NORMAL], GL_FLOAT, v->count);
    }
    if (layout->view[VIEW_TANGENT] >= 0) {
        tangent_accessor = ++accessor;
        buffer_printf(out, ",{\"bufferView\":%d,\"componentType\":%d,\"count\":%d,\"type\":\"VEC4\"}",
                      layout->view[VIEW_TANGENT], GL_FLOAT, v->count);
    }
    if (layout->view[VIEW_UV] >= 0) {
        uv_accessor = ++accessor;
        buffer_printf(out, ",{\"bufferView\":%d,\"componentType\":%d,\"count\":%d,\"type\":\"VEC2\"}",
                      layout->view[VIEW_UV], GL_FLOAT, v->count);
    }
    index_accessor = ++accessor;
    buffer_printf(out, ",{\"bufferView\":%d,\"componentType\":%d,\"count\":%lu,\"type\":\"SCALAR\"}],",
                  layout->view[VIEW_INDEX], layout->short_indices ? GL_UNSIGNED_SHORT : GL_UNSIGNED_INT,
                  (unsigned long)3 * (unsigned long)v->ntriangles);

    buffer_printf(out, "\"meshes\":[{\"name\":");
    json_string(out, name);
    buffer_printf(out, ",\"primitives\":[{\"attributes\":{\"POSITION\":0");
    if (normal_accessor >= 0) buffer_printf(out, ",\"NORMAL\":%d", normal_accessor);
    if (tangent_accessor >= 0) buffer_printf(out, ",\"TANGENT\":%d", tangent_accessor);
    if (uv_accessor >= 0) buffer_printf(out, ",\"TEXCOORD_0\":%d", uv_accessor);
    buffer_printf(out, "},\"indices\":%d,\"material\":0,\"mode\":%d}]}],", index_accessor, GLTF_TRIANGLES);

    /* The material. Without maps it is matte (roughness 1) and not metal,
       as the MTL files the tool writes describe theirs (no specular
       colour); a map's channel is multiplied by its factor, 1. Both sides
       are drawn, as `tiledtex render` draws them: an open mesh shows its
       inside. */
    buffer_printf(out, "\"materials\":[{\"name\":");
    json_string(out, material->name ? material->name : name);
    buffer_printf(out, ",\"pbrMetallicRoughness\":{");
    if (texture[SLOT_BASE_COLOR] >= 0)
        buffer_printf(out, "\"baseColorTexture\":{\"index\":%d},", texture[SLOT_BASE_COLOR]);
    if (texture[SLOT_METALLIC_ROUGHNESS] >= 0)
        buffer_printf(out, "\"metallicRoughnessTexture\":{\"index\":%d},", texture[SLOT_METALLIC_ROUGHNESS]);
    buffer_printf(out, "\"metallicFactor\":%d,\"roughnessFactor\":1}", material->metallic ? 1 : 0);
    if (texture[SLOT_NORMAL] >= 0) buffer_printf(out, ",\"normalTexture\":{\"index\":%d}", texture[SLOT_NORMAL]);
    if (texture[SLOT_OCCLUSION] >= 0)
        buffer_printf(out, ",\"occlusionTexture\":{\"index\":%d}", texture[SLOT_OCCLUSION]);
    buffer_printf(out, ",\"doubleSided\":true}],");

    if (ntextures > 0) {
        /* Atlases keep their coordinates inside tiles and charts, with
           gutters: clamped, mip levels never blend one edge of the image
           into the other. A texture the coordinates repeat is sampled
           repeated, as `tiledtex render` samples it. */
        int wrap = material->repeat ? GL_REPEAT : GL_CLAMP_TO_EDGE, first = 1;
        buffer_printf(out, "\"samplers\":[{\"magFilter\":%d,\"minFilter\":%d,\"wrapS\":%d,\"wrapT\":%d}],", GL_LINEAR,
                      GL_LINEAR_MIPMAP_LINEAR, wrap, wrap);
        buffer_printf(out, "\"textures\":[");
        for (s = 0; s < SLOT_COUNT; s++)
            if (texture[s] >= 0) {
                buffer_printf(out, "%s{\"sampler\":0,\"source\":%d}", first ? "" : ",", texture[s]);
                first = 0;
            }
        buffer_printf(out, "],\"images\":[");
        first = 1;
        for (s = 0; s < SLOT_COUNT; s++)
            if (texture[s] >= 0) {
                if (uris) {
                    buffer_printf(out, "%s{\"uri\":", first ? "" : ",");
                    json_string(out, uris->image[s]);
                } else {
                    buffer_printf(out, "%s{\"bufferView\":%d", first ? "" : ",", layout->view[VIEW_IMAGE + s]);
                }
                buffer_printf(out, ",\"mimeType\":\"image/png\",\"name\":\"%s\"}", slot_names[s]);
                first = 0;
            }
        buffer_printf(out, "],");
    }

    buffer_printf(out, "\"bufferViews\":[");
    json_view(out, layout, VIEW_POSITION, GL_ARRAY_BUFFER);
    if (layout->view[VIEW_NORMAL] >= 0) json_view(out, layout, VIEW_NORMAL, GL_ARRAY_BUFFER);
    if (layout->view[VIEW_TANGENT] >= 0) json_view(out, layout, VIEW_TANGENT, GL_ARRAY_BUFFER);
    if (layout->view[VIEW_UV] >= 0) json_view(out, layout, VIEW_UV, GL_ARRAY_BUFFER);
    json_view(out, layout, VIEW_INDEX, GL_ELEMENT_ARRAY_BUFFER);
    for (s = 0; s < SLOT_COUNT; s++)
        if (layout->view[VIEW_IMAGE + s] >= 0) json_view(out, layout, VIEW_IMAGE + s, 0);
    buffer_printf(out, "],\"buffers\":[{");
    if (uris) {
        buffer_printf(out, "\"uri\":");
        json_string(out, uris->buffer);
        buffer_append(out, ",", 1);
    }
    buffer_printf(out, "\"byteLength\":%lu}]}", (unsigned long)layout->bin_size);
}

/* ======================================================================== */
/* The file                                                                 */
/* ======================================================================== */

/* The BIN chunk's arrays, at `bin` (layout->bin_size bytes, zeroed: the
   padding stays zero). */
static void write_bin(unsigned char *bin, const obj_write_desc *mesh, const glb_vertices *v,
                      const glb_images *images, const glb_layout *layout)
{
    unsigned char *p;
    int i, f, first = 0, s;
    p = bin + layout->offset[VIEW_POSITION];
    for (i = 0; i < v->count; i++) p = put_floats(p, mesh->pos + 3 * (size_t)mesh->corner_vert[v->source[i]], 3);
    if (layout->view[VIEW_NORMAL] >= 0) {
        p = bin + layout->offset[VIEW_NORMAL];
        for (i = 0; i < v->count; i++) p = put_floats(p, v->unit_normal + 3 * (size_t)v->source[i], 3);
    }
    if (layout->view[VIEW_TANGENT] >= 0) {
        p = bin + layout->offset[VIEW_TANGENT];
        for (i = 0; i < v->count; i++) p = put_floats(p, v->tangent + 4 * (size_t)i, 4);
    }
    if (layout->view[VIEW_UV] >= 0) {
        /* The tool's v runs up from the image's bottom row (OBJ's
           convention); glTF's runs down from its top row. */
        p = bin + layout->offset[VIEW_UV];
        for (i = 0; i < v->count; i++) {
            const float *uv = mesh->corner_uv + 2 * (size_t)v->source[i];
            float flipped[2];
            flipped[0] = uv[0];
            flipped[1] = 1.0f - uv[1];
            p = put_floats(p, flipped, 2);
        }
    }
    /* Each face as a fan of triangles from its first corner, the way the
       OBJ readers split a polygon: the same winding, so the same front. */
    p = bin + layout->offset[VIEW_INDEX];
    for (f = 0; f < mesh->nfaces; first += face_size_of(mesh, f), f++)
        for (i = 1; i + 1 < face_size_of(mesh, f); i++) {
            int corner[3], k;
            corner[0] = first;
            corner[1] = first + i;
            corner[2] = first + i + 1;
            for (k = 0; k < 3; k++) {
                uint32_t index = (uint32_t)v->corner_vertex[corner[k]];
                if (layout->short_indices) {
                    p[0] = (unsigned char)(index & 0xFFu);
                    p[1] = (unsigned char)(index >> 8);
                    p += 2;
                } else {
                    p = put_u32(p, index);
                }
            }
        }
    for (s = 0; s < SLOT_COUNT; s++)
        if (layout->view[VIEW_IMAGE + s] >= 0)
            memcpy(bin + layout->offset[VIEW_IMAGE + s], images->png[s], images->size[s]);
}

/* What both forms are made of: the vertices, the material's PNGs, where
   the arrays go and the JSON (padded with spaces to 4 bytes, which JSON
   ignores). */
typedef struct gltf_parts {
    glb_vertices v;
    glb_images images;
    glb_layout layout;
    tool_buffer json;
} gltf_parts;

static void gltf_parts_free(gltf_parts *parts)
{
    buffer_free(&parts->json);
    glb_vertices_free(&parts->v);
    glb_images_free(&parts->images);
}

/* The parts of the scene (uris NULL: the GLB form). Returns 0, or -1 with
   the reason in err and nothing left allocated. */
static int gltf_prepare(const obj_write_desc *mesh, const tool_material *material, const char *name,
                        const gltf_uris *uris, gltf_parts *parts, char *err, size_t err_size)
{
    int s, textured = 0;
    memset(parts, 0, sizeof *parts);
    if (!mesh || !material || !name || mesh->nverts < 0 || mesh->nfaces < 0 || (mesh->nverts > 0 && !mesh->pos) ||
        (mesh->nfaces > 0 && !mesh->corner_vert) || (!mesh->face_size && mesh->fixed_face_size < 3)) {
        tool_set_error(err, err_size, "an invalid mesh for glTF");
        return -1;
    }
    if (encode_material(material, &parts->images, err, err_size) != 0) return -1;
    for (s = 0; s < SLOT_COUNT; s++) textured |= parts->images.png[s] != NULL;
    if (textured && !mesh->corner_uv) {
        tool_set_error(err, err_size, "a textured glTF needs texture coordinates");
        goto fail;
    }
    if (make_vertices(mesh, &parts->v, err, err_size) != 0) goto fail;
    if (parts->images.png[SLOT_NORMAL] && parts->v.unit_normal && make_tangents(mesh, &parts->v) != 0) {
        tool_set_error(err, err_size, "out of memory for the tangents of %d vertices", parts->v.count);
        goto fail;
    }
    plan_layout(&parts->v, mesh->corner_normal != NULL, mesh->corner_uv != NULL, &parts->images, uris == NULL,
                &parts->layout);
    write_json(&parts->json, material, name, &parts->v, &parts->images, &parts->layout, uris);
    while (parts->json.size % 4) buffer_append(&parts->json, " ", 1);
    if (parts->json.failed) {
        tool_set_error(err, err_size, "out of memory while writing the glTF");
        goto fail;
    }
    return 0;
fail:
    gltf_parts_free(parts);
    return -1;
}

int gltf_write(const obj_write_desc *mesh, const tool_material *material, const char *name, unsigned char **glb,
               size_t *glb_size, char *err, size_t err_size)
{
    gltf_parts parts;
    size_t total;
    unsigned char *p;
    *glb = NULL;
    *glb_size = 0;
    if (gltf_prepare(mesh, material, name, NULL, &parts, err, err_size) != 0) return -1;
    total = GLB_HEADER_SIZE + 2 * GLB_CHUNK_HEADER_SIZE + parts.json.size + parts.layout.bin_size;
    if (total > UINT32_MAX || total < parts.layout.bin_size) {
        tool_set_error(err, err_size, "the GLB would be over 4 GB, more than the format holds");
        gltf_parts_free(&parts);
        return -1;
    }
    *glb = (unsigned char *)calloc(total, 1);
    if (!*glb) {
        tool_set_error(err, err_size, "out of memory for a GLB of %lu bytes", (unsigned long)total);
        gltf_parts_free(&parts);
        return -1;
    }
    p = put_u32(*glb, GLB_MAGIC);
    p = put_u32(p, GLB_VERSION);
    p = put_u32(p, (uint32_t)total);
    p = put_u32(p, (uint32_t)parts.json.size);
    p = put_u32(p, GLB_CHUNK_JSON);
    memcpy(p, parts.json.data, parts.json.size);
    p += parts.json.size;
    p = put_u32(p, (uint32_t)parts.layout.bin_size);
    p = put_u32(p, GLB_CHUNK_BIN);
    write_bin(p, mesh, &parts.v, &parts.images, &parts.layout);
    *glb_size = total;
    gltf_parts_free(&parts);
    return 0;
}

/* `name` as a relative URI: the bytes of RFC 3986's unreserved characters
   as they are, every other byte (spaces, UTF-8 beyond ASCII) as %XX. 0, or
   -1 when it does not fit in `size` bytes. */
static int uri_encode(const char *name, char *uri, size_t size)
{
    static const char hex[] = "0123456789ABCDEF";
    size_t n = 0;
    for (; *name; name++) {
        const unsigned char c = (unsigned char)*name;
        if ((c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '-' || c == '.' ||
            c == '_' || c == '~') {
            if (n + 1 >= size) return -1;
            uri[n++] = (char)c;
        } else {
            if (n + 3 >= size) return -1;
            uri[n++] = '%';
            uri[n++] = hex[c >> 4];
            uri[n++] = hex[c & 15];
        }
    }
    uri[n] = '\0';
    return 0;
}

/* The separate form into the batch: PATH (the JSON), PATH less ".gltf"
   plus ".bin", and a PNG per image, PATH less ".gltf" plus "_baseColor.png"
   and the like. */
static int output_add_gltf_separate(tool_output *output, const char *path, const char *name,
                                    const obj_write_desc *mesh, const tool_material *material)
{
    char message[TOOL_ERROR_SIZE], bin_path[4200], image_path[SLOT_COUNT][4200];
    gltf_uris uris;
    gltf_parts parts;
    size_t stem = strlen(path) - strlen(".gltf");
    unsigned char *bin;
    int s, status = 0;
    memset(&uris, 0, sizeof uris);
    snprintf(bin_path, sizeof bin_path, "%.*s.bin", (int)stem, path);
    for (s = 0; s < SLOT_COUNT; s++)
        snprintf(image_path[s], sizeof image_path[s], "%.*s_%s.png", (int)stem, path, slot_names[s]);
    if (stem + 32 > 4096 || uri_encode(tool_basename(bin_path), uris.buffer, sizeof uris.buffer) != 0)
        return tool_fail("%s: the name is too long for the files beside it", path);
    for (s = 0; s < SLOT_COUNT; s++)
        if (uri_encode(tool_basename(image_path[s]), uris.image[s], sizeof uris.image[s]) != 0)
            return tool_fail("%s: the name is too long for the files beside it", path);
    if (gltf_prepare(mesh, material, name, &uris, &parts, message, sizeof message) != 0)
        return tool_fail("%s: %s", path, message);
    bin = (unsigned char *)calloc(parts.layout.bin_size > 0 ? parts.layout.bin_size : 1, 1);
    if (!bin) {
        gltf_parts_free(&parts);
        return tool_fail("out of memory for %s (%lu bytes)", bin_path, (unsigned long)parts.layout.bin_size);
    }
    write_bin(bin, mesh, &parts.v, &parts.images, &parts.layout);
    /* The batch owns what it is given, whether or not it takes it. */
    if (output_add(output, bin_path, bin, parts.layout.bin_size) != 0) status = -1;
    for (s = 0; s < SLOT_COUNT; s++)
        if (parts.images.png[s]) {
            if (output_add(output, image_path[s], parts.images.png[s], parts.images.size[s]) != 0) status = -1;
            parts.images.png[s] = NULL;
        }
    if (status == 0) {
        status = output_add(output, path, parts.json.data, parts.json.size);
        parts.json.data = NULL;
    }
    gltf_parts_free(&parts);
    if (status != 0) return tool_fail("out of memory while writing %s", path);
    return 0;
}

int output_add_gltf(tool_output *output, const char *path, const obj_write_desc *mesh, const tool_material *material)
{
    char message[TOOL_ERROR_SIZE], name[256];
    const char *base = strcmp(path, "-") == 0 ? "tiledtex" : tool_basename(path);
    size_t length = strlen(base);
    int separate = tool_has_extension(path, ".gltf");
    unsigned char *glb;
    size_t size;
    /* The scene's object is named after the file, as an importer would
       name it ("bunny_tiled" from bunny_tiled.glb). */
    if (separate) length -= strlen(".gltf");
    else if (tool_has_extension(base, ".glb")) length -= strlen(".glb");
    snprintf(name, sizeof name, "%.*s", (int)(length < sizeof name ? length : sizeof name - 1), base);
    if (separate) return output_add_gltf_separate(output, path, name, mesh, material);
    if (gltf_write(mesh, material, name, &glb, &size, message, sizeof message) != 0)
        return tool_fail("%s: %s", path, message);
    if (output_add(output, path, glb, size) != 0) return tool_fail("out of memory while writing %s", path);
    return 0;
}

const char *gltf_written(const char *path, char *text, size_t size)
{
    size_t stem = strlen(path) - strlen(".gltf");
    if (!tool_has_extension(path, ".gltf")) return path;
    snprintf(text, size, "%s, %.*s.bin, %.*s_*.png", path, (int)stem, path, (int)stem, path);
    return text;
}
