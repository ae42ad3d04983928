/* render.c - `tiledtex render`: look at a textured mesh without any other program.

   A small software renderer, written to be read. The steps:

     1. Read the OBJ (positions, per-corner vt) and the texture, and the
        textures its materials name (MTL map_Kd), if any; build each
        texture's mip chain (each level half the size of the one before).
     2. Split every polygon into a fan of triangles; give every face corner a
        normal: the file's (vn) when every corner has one, as other programs
        shade it, else a smooth one (faces meeting at a sharp crease keep
        their own).
     3. Put a perspective camera on a sphere around the model: it looks at the
        centre of the model's bounding sphere from far enough away that the whole
        sphere fits the picture; --yaw and --pitch move it around, --up says
        which axis of the model points up.
     4. Visibility pass: every triangle is rasterised with tt_raster_triangle
        into a z-buffer twice as wide and tall as the picture (2x2 supersampling
        for anti-aliasing). Each sample keeps the nearest triangle's id.
     5. Shading pass: each sample's triangle is shaded once (so hidden surfaces
        cost nothing): perspective-correct UVs, trilinear mip-mapped texture
        lookup with the level chosen from how fast the UVs change across the
        screen, and simple two-sided lighting.
     6. Resolve: average each 2x2 block of samples into one pixel; save the PNG.

   Pasting meshes (lapped textures, Praun et al. Sec. 4, as `tiledtex lapped`
   writes them) draw the same triangle several times, once per paste, each
   time with the texture patch at other coordinates; drawn in file order
   with alpha blending, the pastes cover the surface. A mesh is drawn that way
   when some triangle occurs more than once (the same three vertices). Then
   each texture is premultiplied by its own alpha (the lapped MTL names the
   same PNG as map_d) before its mip chain is built, its coordinates are clamped instead
   of repeated (outside [0,1] is transparent), and between steps 4 and 5 a
   pasting pass rasterises every triangle again in file order: at each sample
   whose nearest triangle has the same three vertices, it composites its
   texture colour `over` an opaque grey base. Step 5 then lights that colour.
   Only the nearest surface is blended, so a gap between pastes shows grey,
   never the surface behind. Other meshes are drawn exactly as before.

   Colour: everything is computed in linear light, as light adds up. The
   texture file's sRGB bytes are decoded on load (TT_COLOR_SRGB), so mip
   levels, bilinear and trilinear filtering, the blending of pastes, the
   lighting and the 2x2 supersampling average linear values; the finished
   frame is encoded to sRGB once, when it is saved. The renderer's own
   colours (background, untextured grey, wireframe ink) are chosen as
   displayed sRGB values and decoded once. */

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tool.h"

#define RENDER_DEFAULT_WIDTH 800
#define RENDER_DEFAULT_HEIGHT 600
#define RENDER_MAX_SIZE 4096
#define SUPERSAMPLING 2                 /* samples per pixel along each axis */
#define FIELD_OF_VIEW_DEGREES 35.0f     /* along the picture's shorter side */
#define FRAME_MARGIN 1.1f               /* a little room around the model's bounding sphere */
#define CREASE_ANGLE_DEGREES 50.0f      /* faces meeting at a sharper angle are not smoothed together */
/* Displayed (sRGB-encoded) values; the scene holds their linear-light
   equivalents. */
#define UNTEXTURED_GREY_SRGB 0.75f
#define WIREFRAME_INK_SRGB 0.05f

static const float PI = 3.14159265358979f;

/* ======================================================================== */
/* A few vector helpers                                                     */
/* ======================================================================== */

typedef struct vec3 {
    float x, y, z;
} vec3;

static vec3 vec3_make(float x, float y, float z) { vec3 v; v.x = x; v.y = y; v.z = z; return v; }
static vec3 vec3_add(vec3 a, vec3 b) { return vec3_make(a.x + b.x, a.y + b.y, a.z + b.z); }
static vec3 vec3_sub(vec3 a, vec3 b) { return vec3_make(a.x - b.x, a.y - b.y, a.z - b.z); }
static vec3 vec3_scale(vec3 a, float s) { return vec3_make(a.x * s, a.y * s, a.z * s); }
static float vec3_dot(vec3 a, vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static float vec3_length(vec3 a) { return sqrtf(vec3_dot(a, a)); }
static vec3 vec3_cross(vec3 a, vec3 b)
{
    return vec3_make(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
static vec3 vec3_normalize(vec3 a)
{
    float length = vec3_length(a);
    return length > 0.0f ? vec3_scale(a, 1.0f / length) : a;
}
static vec3 vertex_position(const obj_mesh *mesh, int v)
{
    return vec3_make(mesh->pos[3 * v], mesh->pos[3 * v + 1], mesh->pos[3 * v + 2]);
}

/* ======================================================================== */
/* Texture: mip chain and filtered lookups                                  */
/* ======================================================================== */

/* levels[0] is the image; level k + 1 is level k halved with a 2x2 box filter
   (tt_image_downsample2), for as long as both sides are even. Coarser detail
   than the last level can hold is simply sampled from the last level. */
typedef struct mip_texture {
    int nlevels;
    tt_image *levels[TT_MAX_MIP_LEVELS];    /* linear light */
} mip_texture;

static void texture_free(mip_texture *texture)
{
    int i;
    /* Level 0 is the loaded image (the tool's, image_free); the others are
       the library's. */
    if (texture->nlevels > 0) image_free(texture->levels[0]);
    for (i = 1; i < texture->nlevels; i++) tt_image_free(texture->levels[i]);
    texture->nlevels = 0;
}

/* rgb *= alpha, in place: straight colours to premultiplied ones. */
static void premultiply_alpha(tt_image *image)
{
    size_t i, n = (size_t)image->width * (size_t)image->height;
    for (i = 0; i < n; i++) {
        float *p = image->pixels + 4 * i;
        p[0] *= p[3];
        p[1] *= p[3];
        p[2] *= p[3];
    }
}

/* Takes ownership of `image` (linear light: the mip averages are linear).
   On failure the library's message is in `message`. */
static int texture_build(mip_texture *texture, tt_image *image, char *message, size_t message_size)
{
    tt_error error;
    memset(texture, 0, sizeof *texture);
    texture->levels[0] = image;
    texture->nlevels = 1;
    while (texture->nlevels < TT_MAX_MIP_LEVELS) {
        const tt_image *last = texture->levels[texture->nlevels - 1];
        if (last->width % 2 != 0 || last->height % 2 != 0) break;
        if (tt_image_downsample2(last, NULL, &texture->levels[texture->nlevels], &error) != TT_OK) {
            snprintf(message, message_size, "%s", error.message);
            texture_free(texture);
            return -1;
        }
        texture->nlevels++;
    }
    return 0;
}

/* Bilinear lookup at texture coordinates (u, v). v = 0 is the bottom of the
   image (OBJ convention) while row 0 is its top, hence y = (1 - v) * height.
   repeat: the texture repeats outside [0,1], as for an ordinary textured
   mesh. Otherwise it is a texture patch of a pasting mesh, whose coordinates
   run far outside [0,1] and must be clamped (Praun et al. Sec. 4): outside
   is transparent, and texels are not blended across the image's border. */
static void sample_bilinear(const tt_image *image, float u, float v, int repeat, float rgba[4])
{
    int w = image->width, h = image->height, x0, y0, x1, y1, i;
    float x, y, fx, fy;
    const float *p00, *p10, *p01, *p11;
    if (repeat) {
        u -= floorf(u);                  /* into [0, 1): the repeat */
        v -= floorf(v);
    } else if (!(u >= 0.0f && u <= 1.0f && v >= 0.0f && v <= 1.0f)) {
        rgba[0] = rgba[1] = rgba[2] = rgba[3] = 0.0f;
        return;
    }
    x = u * (float)w - 0.5f;             /* texel centres sit at half-integers */
    y = (1.0f - v) * (float)h - 0.5f;
    x0 = (int)floorf(x);
    y0 = (int)floorf(y);
    fx = x - (float)x0;
    fy = y - (float)y0;
    if (repeat) {
        /* Neighbours across the image's border come from the opposite side. */
        x0 = (x0 % w + w) % w;
        y0 = (y0 % h + h) % h;
        x1 = x0 + 1 == w ? 0 : x0 + 1;
        y1 = y0 + 1 == h ? 0 : y0 + 1;
    } else {
        /* u, v in [0, 1] put x0, y0 in [-1, w - 1], [-1, h - 1]. */
        x1 = x0 + 1 < w ? x0 + 1 : w - 1;
        y1 = y0 + 1 < h ? y0 + 1 : h - 1;
        x0 = x0 < 0 ? 0 : x0;
        y0 = y0 < 0 ? 0 : y0;
    }
    p00 = image->pixels + 4 * ((size_t)y0 * (size_t)w + (size_t)x0);
    p10 = image->pixels + 4 * ((size_t)y0 * (size_t)w + (size_t)x1);
    p01 = image->pixels + 4 * ((size_t)y1 * (size_t)w + (size_t)x0);
    p11 = image->pixels + 4 * ((size_t)y1 * (size_t)w + (size_t)x1);
    for (i = 0; i < 4; i++) {
        float top = p00[i] + (p10[i] - p00[i]) * fx;
        float bottom = p01[i] + (p11[i] - p01[i]) * fx;
        rgba[i] = top + (bottom - top) * fy;
    }
}

/* Trilinear lookup: `texels_per_pixel` says how many level-0 texels one screen
   sample spans; its log2 is the mip level (fractional: blend two levels). */
static void sample_trilinear(const mip_texture *texture, float u, float v, float texels_per_pixel, int repeat,
                             float rgba[4])
{
    float lod = texels_per_pixel > 1.0f ? log2f(texels_per_pixel) : 0.0f;
    float coarse[4], t;
    int level, i;
    if (!isfinite(u) || !isfinite(v)) u = v = 0.0f;
    if (!(lod < (float)(texture->nlevels - 1))) {   /* also catches NaN */
        sample_bilinear(texture->levels[texture->nlevels - 1], u, v, repeat, rgba);
        return;
    }
    level = (int)lod;
    t = lod - (float)level;
    sample_bilinear(texture->levels[level], u, v, repeat, rgba);
    if (t <= 0.0f) return;
    sample_bilinear(texture->levels[level + 1], u, v, repeat, coarse);
    for (i = 0; i < 4; i++) rgba[i] += (coarse[i] - rgba[i]) * t;
}

/* ======================================================================== */
/* Camera                                                                   */
/* ======================================================================== */

typedef struct camera {
    vec3 eye;
    vec3 right, up, forward;    /* orthonormal; the camera looks along `forward` */
    float focal;                /* in samples: screen x = centre_x + focal * x / z */
    float centre_x, centre_y;
} camera;

/* Which way is up in the model: most OBJ files use +y, CAD parts and scans
   often +z. `side` and `front` complete a right-handed frame with it, so that
   yaw 0 looks at the model's front. */
typedef struct up_axis {
    vec3 up, side, front;
} up_axis;

/* The frame around an up direction (parse_up: an axis or any X,Y,Z). The
   front is +z, or -y when up is closest to the z axis, made perpendicular
   to up; side = up x front. For the six axes this is the usual frame: y up
   looks from +z with +x to the right, z up looks from -y, and a negative
   axis turns the picture upside down. */
static void up_axis_from(const double direction[3], up_axis *axis)
{
    vec3 up = vec3_normalize(vec3_make((float)direction[0], (float)direction[1], (float)direction[2]));
    vec3 front = fabsf(up.z) > fabsf(up.x) && fabsf(up.z) > fabsf(up.y) ? vec3_make(0, -1, 0) : vec3_make(0, 0, 1);
    front = vec3_normalize(vec3_sub(front, vec3_scale(up, vec3_dot(front, up))));
    axis->up = up;
    axis->front = front;
    axis->side = vec3_cross(up, front);
}

/* Orbit: yaw turns the camera around the up axis, pitch raises it above the
   model. yaw 0, pitch 0 looks at the model's front. The distance is chosen so
   that the bounding sphere fits the field of view with a small margin, which also puts every
   vertex in front of the camera: no clipping is ever needed. */
static void camera_orbit(camera *cam, vec3 centre, float radius, const up_axis *axis, float yaw_degrees,
                         float pitch_degrees, float zoom, int width, int height)
{
    float yaw = yaw_degrees * PI / 180.0f, pitch = pitch_degrees * PI / 180.0f;
    float half_fov = 0.5f * FIELD_OF_VIEW_DEGREES * PI / 180.0f;
    float distance = FRAME_MARGIN * radius / sinf(half_fov);
    vec3 toward_eye = vec3_add(vec3_add(vec3_scale(axis->side, cosf(pitch) * sinf(yaw)),
                                        vec3_scale(axis->up, sinf(pitch))),
                               vec3_scale(axis->front, cosf(pitch) * cosf(yaw)));
    cam->eye = vec3_add(centre, vec3_scale(toward_eye, distance));
    cam->forward = vec3_scale(toward_eye, -1.0f);
    cam->right = vec3_normalize(vec3_cross(cam->forward, axis->up));
    cam->up = vec3_cross(cam->right, cam->forward);
    /* Zooming narrows the view instead of moving closer: nothing can come to
       lie behind the camera. */
    cam->focal = zoom * 0.5f * (float)(width < height ? width : height) / tanf(half_fov);
    cam->centre_x = 0.5f * (float)width;
    cam->centre_y = 0.5f * (float)height;
}

/* ======================================================================== */
/* Scene: the mesh as triangles, ready to draw                              */
/* ======================================================================== */

typedef struct scene {
    const obj_mesh *mesh;
    int ntriangles;
    int *triangle_corners;      /* 3 per triangle: corners of the OBJ (index into corner_vert / corner_uv) */
    int *triangle_face;         /* the OBJ face each triangle comes from */
    unsigned char *triangle_edges; /* bit k: the edge opposite corner k is an edge of the OBJ face */
    int *triangle_shape;        /* the first triangle with the same three vertices (often itself) */
    int pasting;                /* some triangle is drawn more than once: a pasting mesh */
    signed char *triangle_facing; /* +1: the camera sees the side the winding calls "outside", -1: the inside */
    float *corner_normal;       /* 3 per OBJ corner, unit length */
    float *screen;              /* 3 per vertex: x and y in samples, then q = 1 / depth */
    const mip_texture *textures; /* the textures faces are drawn with */
    const mip_texture *normal_map; /* a tangent-space normal map over the same UVs, or NULL */
    float *triangle_axes;       /* with a normal map: 6 per triangle, its dP/du and dP/dv (zero: none) */
    const int *face_texture;    /* per OBJ face: index into textures, -1: draw grey */
    int wireframe;              /* draw the OBJ faces' edges over the surface */
    int unlit;                  /* the texture's colour as it is: no lighting (--unlit) */
    vec3 light_key, light_fill; /* unit vectors towards the two lights */
    int width, height;          /* of the sample grid */
    float untextured_grey;      /* linear light */
    float wireframe_ink;        /* linear light */
} scene;

static void scene_free(scene *s)
{
    free(s->triangle_corners);
    free(s->triangle_face);
    free(s->triangle_edges);
    free(s->triangle_shape);
    free(s->triangle_facing);
    free(s->corner_normal);
    free(s->triangle_axes);
    free(s->screen);
    memset(s, 0, sizeof *s);
}

/* Fan triangulation: face (c0, c1, ..., cn-1) becomes (c0, ci, ci+1). Exact for
   triangles and convex polygons, which is what meshes are made of. */
static int scene_triangulate(scene *s)
{
    int t, total = obj_triangle_fans(s->mesh, &s->triangle_corners, &s->triangle_face);
    if (total < 0) return -1;
    s->ntriangles = total;
    s->triangle_facing = (signed char *)malloc((size_t)total);
    s->triangle_edges = (unsigned char *)malloc((size_t)total);
    if (!s->triangle_facing || !s->triangle_edges) return -1;
    for (t = 0; t < total; t++) {
        /* Triangle (c0, ci, ci+1): (ci, ci+1) is always a side of the face;
           (ci+1, c0) and (c0, ci) only for the last and the first of the fan. */
        const int *corner = s->triangle_corners + 3 * t;
        int i = corner[1] - corner[0], size = s->mesh->face_size[s->triangle_face[t]];
        s->triangle_edges[t] = (unsigned char)(1u | (i + 2 == size ? 2u : 0u) | (i == 1 ? 4u : 0u));
    }
    return 0;
}

/* Triangles named by their vertices, sorted so that copies lie together. */
typedef struct triangle_key {
    int vertex[3];              /* ascending */
    int triangle;
} triangle_key;

static int compare_triangle_keys(const void *a, const void *b)
{
    const triangle_key *x = (const triangle_key *)a, *y = (const triangle_key *)b;
    int k;
    for (k = 0; k < 3; k++)
        if (x->vertex[k] != y->vertex[k]) return x->vertex[k] < y->vertex[k] ? -1 : 1;
    return (x->triangle > y->triangle) - (x->triangle < y->triangle);
}

/* A pasting mesh (lapped textures, Praun et al. Sec. 4) draws the same
   triangle once per paste that covers it, each time with other texture
   coordinates. Give every triangle the first triangle of the same three
   vertices, whatever their order; there is pasting when one is not itself. */
static int scene_find_pastes(scene *s)
{
    const obj_mesh *mesh = s->mesh;
    triangle_key *keys = (triangle_key *)malloc((size_t)s->ntriangles * sizeof(triangle_key));
    int t, first = 0;
    s->triangle_shape = (int *)malloc((size_t)s->ntriangles * sizeof(int));
    if (!keys || !s->triangle_shape) {
        free(keys);
        return -1;
    }
    for (t = 0; t < s->ntriangles; t++) {
        int *v = keys[t].vertex, k, swap;
        for (k = 0; k < 3; k++) v[k] = mesh->corner_vert[s->triangle_corners[3 * t + k]];
        if (v[0] > v[1]) { swap = v[0]; v[0] = v[1]; v[1] = swap; }
        if (v[1] > v[2]) { swap = v[1]; v[1] = v[2]; v[2] = swap; }
        if (v[0] > v[1]) { swap = v[0]; v[0] = v[1]; v[1] = swap; }
        keys[t].triangle = t;
    }
    qsort(keys, (size_t)s->ntriangles, sizeof(triangle_key), compare_triangle_keys);
    s->pasting = 0;
    for (t = 0; t < s->ntriangles; t++) {
        if (t > 0 && memcmp(keys[t].vertex, keys[first].vertex, sizeof keys[t].vertex) != 0) first = t;
        s->triangle_shape[keys[t].triangle] = keys[first].triangle;
        if (t != first) s->pasting = 1;
    }
    free(keys);
    return 0;
}

/* Normal of a polygon by Newell's method: for a planar polygon it is the normal
   with length twice the area, and for a bent one a sensible average. */
static vec3 polygon_normal(const obj_mesh *mesh, int first_corner, int size)
{
    vec3 n = vec3_make(0.0f, 0.0f, 0.0f);
    int i;
    for (i = 0; i < size; i++) {
        vec3 a = vertex_position(mesh, mesh->corner_vert[first_corner + i]);
        vec3 b = vertex_position(mesh, mesh->corner_vert[first_corner + (i + 1) % size]);
        n.x += (a.y - b.y) * (a.z + b.z);
        n.y += (a.z - b.z) * (a.x + b.x);
        n.z += (a.x - b.x) * (a.y + b.y);
    }
    return n;
}

/* The file's own normals (vn, one per corner: obj_corner_normals) instead
   of computed ones, each turned to the side its face's winding calls
   outside: lighting is two-sided and turns normals towards the viewer by
   the winding, so a normal must agree with it (an inside-out file's
   normals would otherwise light its surface from behind). */
static void scene_use_file_normals(scene *s, float *normals)
{
    const obj_mesh *mesh = s->mesh;
    int f, c = 0, i;
    for (f = 0; f < mesh->nfaces; f++) {
        vec3 face = polygon_normal(mesh, c, mesh->face_size[f]);
        for (i = 0; i < mesh->face_size[f]; i++, c++) {
            float *n = normals + 3 * (size_t)c;
            if (vec3_dot(face, vec3_make(n[0], n[1], n[2])) < 0.0f) {
                n[0] = -n[0];
                n[1] = -n[1];
                n[2] = -n[2];
            }
        }
    }
    free(s->corner_normal);
    s->corner_normal = normals;
}

/* Smooth normals per corner: the area-weighted average of the normals of the
   faces around the corner's vertex - but only of those within the crease angle
   of the corner's own face, so a cube keeps its edges and faces wound the
   other way (a badly oriented neighbour) do not cancel out. */
static int scene_compute_normals(scene *s)
{
    const obj_mesh *mesh = s->mesh;
    int nv = mesh->nverts, nc = mesh->ncorners, nf = mesh->nfaces, f, c, v, ok = 0;
    float cos_crease = cosf(CREASE_ANGLE_DEGREES * PI / 180.0f);
    vec3 *face_normal = (vec3 *)malloc((size_t)nf * sizeof(vec3));
    int *corner_face = (int *)malloc((size_t)nc * sizeof(int));
    int *vertex_start = (int *)calloc((size_t)nv + 1, sizeof(int));    /* corners around each vertex, */
    int *vertex_corners = (int *)malloc((size_t)nc * sizeof(int));     /* as compressed rows */
    s->corner_normal = (float *)malloc((size_t)nc * 3 * sizeof(float));
    if (!face_normal || !corner_face || !vertex_start || !vertex_corners || !s->corner_normal) goto done;

    for (f = 0, c = 0; f < nf; f++) {
        int i;
        face_normal[f] = polygon_normal(mesh, c, mesh->face_size[f]);
        for (i = 0; i < mesh->face_size[f]; i++) corner_face[c++] = f;
    }
    for (c = 0; c < nc; c++) vertex_start[mesh->corner_vert[c] + 1]++;
    for (v = 0; v < nv; v++) vertex_start[v + 1] += vertex_start[v];
    for (c = 0; c < nc; c++) vertex_corners[vertex_start[mesh->corner_vert[c]]++] = c;
    for (v = nv; v > 0; v--) vertex_start[v] = vertex_start[v - 1];   /* undo the shift the fill made */
    vertex_start[0] = 0;

    for (c = 0; c < nc; c++) {
        int vertex = mesh->corner_vert[c], k;
        vec3 own = vec3_normalize(face_normal[corner_face[c]]);
        vec3 sum = vec3_make(0.0f, 0.0f, 0.0f);
        for (k = vertex_start[vertex]; k < vertex_start[vertex + 1]; k++) {
            vec3 other = face_normal[corner_face[vertex_corners[k]]];
            if (vec3_dot(own, vec3_normalize(other)) >= cos_crease) sum = vec3_add(sum, other);
        }
        sum = vec3_normalize(sum);
        if (vec3_dot(sum, sum) == 0.0f) sum = own;     /* a degenerate face: whatever we have */
        s->corner_normal[3 * c] = sum.x;
        s->corner_normal[3 * c + 1] = sum.y;
        s->corner_normal[3 * c + 2] = sum.z;
    }
    ok = 1;
done:
    free(face_normal);
    free(corner_face);
    free(vertex_start);
    free(vertex_corners);
    return ok ? 0 : -1;
}

/* Bounding sphere of the vertices faces use: centre of the bounding box, radius
   to the farthest vertex. Fails on a non-finite coordinate. */
static int mesh_bounding_sphere(const obj_mesh *mesh, vec3 *centre, float *radius, int *bad_vertex)
{
    vec3 lo = vec3_make(INFINITY, INFINITY, INFINITY), hi = vec3_scale(lo, -1.0f);
    float r2 = 0.0f;
    int c;
    for (c = 0; c < mesh->ncorners; c++) {
        vec3 p = vertex_position(mesh, mesh->corner_vert[c]);
        if (!isfinite(p.x) || !isfinite(p.y) || !isfinite(p.z)) {
            *bad_vertex = mesh->corner_vert[c];
            return -1;
        }
        lo = vec3_make(fminf(lo.x, p.x), fminf(lo.y, p.y), fminf(lo.z, p.z));
        hi = vec3_make(fmaxf(hi.x, p.x), fmaxf(hi.y, p.y), fmaxf(hi.z, p.z));
    }
    *centre = vec3_add(vec3_scale(lo, 0.5f), vec3_scale(hi, 0.5f));   /* halves first: no overflow */
    for (c = 0; c < mesh->ncorners; c++) {
        vec3 d = vec3_sub(vertex_position(mesh, mesh->corner_vert[c]), *centre);
        float d2 = vec3_dot(d, d);
        if (d2 > r2) r2 = d2;
    }
    *radius = sqrtf(r2);
    /* A mesh squeezed into a point (or too large for floats) still gets a view. */
    if (!(*radius > 1e-30f) || !isfinite(*radius * 4.0f)) *radius = 1.0f;
    return 0;
}

/* Project every vertex: x, y on the sample grid (y down) and q = 1 / depth.
   q is what varies linearly across a triangle on screen, so it is what the
   z-buffer stores (larger q = nearer). */
static int scene_project(scene *s, const camera *cam)
{
    const obj_mesh *mesh = s->mesh;
    int v, t;
    s->screen = (float *)malloc((size_t)mesh->nverts * 3 * sizeof(float));
    if (!s->screen) return -1;
    for (v = 0; v < mesh->nverts; v++) {
        vec3 d = vec3_sub(vertex_position(mesh, v), cam->eye);
        float depth = vec3_dot(d, cam->forward);
        float q = depth > 0.0f ? 1.0f / depth : 0.0f;
        float x = cam->centre_x + cam->focal * vec3_dot(d, cam->right) * q;
        float y = cam->centre_y - cam->focal * vec3_dot(d, cam->up) * q;
        /* A vertex that lands nowhere (float overflow in an absurd mesh) gets
           q = 0, which makes the visibility pass skip its triangles. */
        if (!isfinite(x) || !isfinite(y) || !isfinite(q)) x = y = q = 0.0f;
        s->screen[3 * v] = x;
        s->screen[3 * v + 1] = y;
        s->screen[3 * v + 2] = q;
    }
    /* Which side of each triangle faces the camera: lighting is two-sided, so
       a mesh wound inwards (or an open surface seen from behind) still gets
       its normals turned towards the viewer. */
    for (t = 0; t < s->ntriangles; t++) {
        const int *corner = s->triangle_corners + 3 * t;
        vec3 p0 = vertex_position(mesh, mesh->corner_vert[corner[0]]);
        vec3 p1 = vertex_position(mesh, mesh->corner_vert[corner[1]]);
        vec3 p2 = vertex_position(mesh, mesh->corner_vert[corner[2]]);
        vec3 normal = vec3_cross(vec3_sub(p1, p0), vec3_sub(p2, p0));
        s->triangle_facing[t] = vec3_dot(normal, vec3_sub(cam->eye, p0)) >= 0.0f ? 1 : -1;
    }
    return 0;
}

/* ======================================================================== */
/* Sample buffers                                                           */
/* ======================================================================== */

typedef struct sample_buffer {
    int width, height;          /* SUPERSAMPLING times the picture's */
    float *depth;               /* q = 1 / depth of the nearest surface; 0 = nothing */
    int *triangle;              /* the nearest triangle, -1 = background */
    float *color;               /* 3 per sample, RGB */
    float *paste;               /* pasting meshes only: 4 per sample, the pastes composited, premultiplied */
} sample_buffer;

static int samples_create(sample_buffer *b, int width, int height, int pasting)
{
    size_t n = (size_t)width * (size_t)height, i;
    b->width = width;
    b->height = height;
    b->depth = (float *)calloc(n, sizeof(float));
    b->triangle = (int *)malloc(n * sizeof(int));
    b->color = (float *)malloc(n * 3 * sizeof(float));
    b->paste = pasting ? (float *)malloc(n * 4 * sizeof(float)) : NULL;
    if (!b->depth || !b->triangle || !b->color || (pasting && !b->paste)) return -1;
    for (i = 0; i < n; i++) b->triangle[i] = -1;
    return 0;
}

static void samples_free(sample_buffer *b)
{
    free(b->depth);
    free(b->triangle);
    free(b->color);
    free(b->paste);
    memset(b, 0, sizeof *b);
}

/* ======================================================================== */
/* Pass 1: visibility                                                       */
/* ======================================================================== */

typedef struct visibility_job {
    sample_buffer *samples;
    int triangle;
    float q[3];                 /* 1 / depth at the three corners */
} visibility_job;

/* Called by tt_raster_triangle for every sample the triangle covers. */
static void visibility_sample(int x, int y, const float barycentric[3], void *user_data)
{
    visibility_job *job = (visibility_job *)user_data;
    size_t i = (size_t)y * (size_t)job->samples->width + (size_t)x;
    float q = barycentric[0] * job->q[0] + barycentric[1] * job->q[1] + barycentric[2] * job->q[2];
    if (q > job->samples->depth[i]) {       /* nearer than what is there */
        job->samples->depth[i] = q;
        job->samples->triangle[i] = job->triangle;
    }
}

/* Triangle t's corners on the sample grid (xy) and their q = 1 / depth.
   Returns 0 when a corner lies behind the camera, which cannot happen with
   the orbit camera but would make the triangle meaningless. */
static int triangle_on_screen(const scene *s, int t, float xy[6], float q[3])
{
    int k, usable = 1;
    for (k = 0; k < 3; k++) {
        const float *p = s->screen + 3 * s->mesh->corner_vert[s->triangle_corners[3 * t + k]];
        xy[2 * k] = p[0];
        xy[2 * k + 1] = p[1];
        q[k] = p[2];
        if (!(p[2] > 0.0f)) usable = 0;
    }
    return usable;
}

static void draw_visibility(const scene *s, sample_buffer *samples)
{
    visibility_job job;
    int t;
    job.samples = samples;
    for (t = 0; t < s->ntriangles; t++) {
        float xy[6];
        if (!triangle_on_screen(s, t, xy, job.q)) continue;
        job.triangle = t;
        tt_raster_triangle(xy, samples->width, samples->height, visibility_sample, &job);
    }
}

/* ======================================================================== */
/* Pass 2: shading                                                          */
/* ======================================================================== */

/* Where a sample lies on a triangle: its screen-space barycentrics b, how
   they change per sample step in x and y (constant over the triangle), and
   w, the true (perspective-correct) weights of the corners there. */
typedef struct surface_point {
    const float *corner[3];     /* the corners' screen x, y, q */
    float b[3], dbdx[3], dbdy[3];
    float q, qx, qy;            /* 1 / depth and its steps in x and y */
    float w[3];
} surface_point;

static void locate_sample(const scene *s, int t, float px, float py, surface_point *point)
{
    const int *corner = s->triangle_corners + 3 * t;
    const float *p0 = s->screen + 3 * s->mesh->corner_vert[corner[0]];
    const float *p1 = s->screen + 3 * s->mesh->corner_vert[corner[1]];
    const float *p2 = s->screen + 3 * s->mesh->corner_vert[corner[2]];
    float *b = point->b, *dbdx = point->dbdx, *dbdy = point->dbdy, area, q;

    point->corner[0] = p0;
    point->corner[1] = p1;
    point->corner[2] = p2;
    area = (p1[1] - p2[1]) * (p0[0] - p2[0]) + (p2[0] - p1[0]) * (p0[1] - p2[1]);
    if (area == 0.0f) area = 1e-20f;
    dbdx[0] = (p1[1] - p2[1]) / area;  dbdy[0] = (p2[0] - p1[0]) / area;
    dbdx[1] = (p2[1] - p0[1]) / area;  dbdy[1] = (p0[0] - p2[0]) / area;
    dbdx[2] = -dbdx[0] - dbdx[1];      dbdy[2] = -dbdy[0] - dbdy[1];
    b[0] = dbdx[0] * (px - p2[0]) + dbdy[0] * (py - p2[1]);
    b[1] = dbdx[1] * (px - p2[0]) + dbdy[1] * (py - p2[1]);
    b[2] = 1.0f - b[0] - b[1];

    /* Perspective correction: attributes divided by depth (times q) are linear
       on screen, so interpolate a*q and q, then divide. */
    q = b[0] * p0[2] + b[1] * p1[2] + b[2] * p2[2];
    point->qx = dbdx[0] * p0[2] + dbdx[1] * p1[2] + dbdx[2] * p2[2];
    point->qy = dbdy[0] * p0[2] + dbdy[1] * p1[2] + dbdy[2] * p2[2];
    if (!(q > 0.0f)) q = 1e-20f;
    point->q = q;
    point->w[0] = b[0] * p0[2] / q;
    point->w[1] = b[1] * p1[2] / q;
    point->w[2] = b[2] * p2[2] / q;
}

/* Triangle t's texture coordinates at a point, with their steps per sample
   in x and y (uv[0..1]; du/dx, dv/dx, du/dy, dv/dy in uv[2..5]); 0 when a
   corner has none. */
static int surface_uv(const scene *s, int t, const surface_point *point, float uv[6])
{
    const obj_mesh *mesh = s->mesh;
    const int *corner = s->triangle_corners + 3 * t;
    const float *uv0, *uv1, *uv2, *w = point->w, *dbdx = point->dbdx, *dbdy = point->dbdy;
    const float *p0 = point->corner[0], *p1 = point->corner[1], *p2 = point->corner[2];
    float q = point->q, qx = point->qx, qy = point->qy, u, v, uqx, uqy, vqx, vqy;
    if (!mesh->corner_uv || mesh->corner_uv[corner[0]] < 0 || mesh->corner_uv[corner[1]] < 0 ||
        mesh->corner_uv[corner[2]] < 0)
        return 0;
    uv0 = mesh->uv + 2 * mesh->corner_uv[corner[0]];
    uv1 = mesh->uv + 2 * mesh->corner_uv[corner[1]];
    uv2 = mesh->uv + 2 * mesh->corner_uv[corner[2]];
    u = w[0] * uv0[0] + w[1] * uv1[0] + w[2] * uv2[0];
    v = w[0] * uv0[1] + w[1] * uv1[1] + w[2] * uv2[1];
    /* d(u)/dx = (d(u q)/dx - u dq/dx) / q, the quotient rule on u = (u q) / q. */
    uqx = dbdx[0] * uv0[0] * p0[2] + dbdx[1] * uv1[0] * p1[2] + dbdx[2] * uv2[0] * p2[2];
    uqy = dbdy[0] * uv0[0] * p0[2] + dbdy[1] * uv1[0] * p1[2] + dbdy[2] * uv2[0] * p2[2];
    vqx = dbdx[0] * uv0[1] * p0[2] + dbdx[1] * uv1[1] * p1[2] + dbdx[2] * uv2[1] * p2[2];
    vqy = dbdy[0] * uv0[1] * p0[2] + dbdy[1] * uv1[1] * p1[2] + dbdy[2] * uv2[1] * p2[2];
    uv[0] = u;
    uv[1] = v;
    uv[2] = (uqx - u * qx) / q;
    uv[3] = (vqx - v * qx) / q;
    uv[4] = (uqy - u * qy) / q;
    uv[5] = (vqy - v * qy) / q;
    return 1;
}

/* A texture's trilinear sample at texture coordinates from surface_uv. */
static void sample_surface(const mip_texture *texture, const float uv[6], int repeat, float rgba[4])
{
    const tt_image *base = texture->levels[0];
    float dudx = uv[2] * (float)base->width, dvdx = uv[3] * (float)base->height;
    float dudy = uv[4] * (float)base->width, dvdy = uv[5] * (float)base->height;
    /* The footprint of one sample in texels: the longer of its two sides. */
    float footprint = sqrtf(fmaxf(dudx * dudx + dvdx * dvdx, dudy * dudy + dvdy * dvdy));
    sample_trilinear(texture, uv[0], uv[1], footprint, repeat, rgba);
}

/* Triangle t's texture colour at a point: the texture (straight alpha, or
   premultiplied for a pasting mesh, whose texture is premultiplied, times
   the paste's fade when its vt carry one), or opaque grey when a corner
   has no UV. */
static void texture_color(const scene *s, int t, const surface_point *point, float rgba[4])
{
    const obj_mesh *mesh = s->mesh;
    const int *corner = s->triangle_corners + 3 * t;
    const int index = s->face_texture[s->triangle_face[t]];
    const mip_texture *texture = index >= 0 ? &s->textures[index] : NULL;
    const float *w = point->w;
    float uv[6];
    rgba[0] = rgba[1] = rgba[2] = s->untextured_grey;
    rgba[3] = 1.0f;
    if (texture && surface_uv(s, t, point, uv)) {
        sample_surface(texture, uv, !s->pasting, rgba);
        if (s->pasting && mesh->uv_w) {
            /* A paste's fade (the vt's third number, written by 'lapped'):
               its alpha goes to 0 where it had to stop; premultiplied, so
               colour and alpha alike. */
            float fade = w[0] * mesh->uv_w[mesh->corner_uv[corner[0]]] + w[1] * mesh->uv_w[mesh->corner_uv[corner[1]]] +
                         w[2] * mesh->uv_w[mesh->corner_uv[corner[2]]];
            int k;
            fade = fade < 0.0f ? 0.0f : (fade > 1.0f ? 1.0f : fade);
            for (k = 0; k < 4; k++) rgba[k] *= fade;
        }
    }
}

/* Each triangle's texture axes (triangle_texture_axes), once, for
   mapped_normal; zero for a triangle without texture coordinates. Returns
   -1 when out of memory. */
static int scene_texture_axes(scene *s)
{
    const obj_mesh *mesh = s->mesh;
    int t, k;
    s->triangle_axes = (float *)calloc((size_t)s->ntriangles * 6, sizeof(float));
    if (!s->triangle_axes) return -1;
    for (t = 0; t < s->ntriangles && mesh->corner_uv; t++) {
        const int *corner = s->triangle_corners + 3 * t;
        const float *p[3], *uv[3];
        double axes[6];
        for (k = 0; k < 3; k++) {
            if (mesh->corner_uv[corner[k]] < 0) break;
            p[k] = mesh->pos + 3 * (size_t)mesh->corner_vert[corner[k]];
            uv[k] = mesh->uv + 2 * (size_t)mesh->corner_uv[corner[k]];
        }
        if (k < 3 || triangle_texture_axes(p[0], p[1], p[2], uv[0], uv[1], uv[2], axes) != 0) continue;
        for (k = 0; k < 6; k++) s->triangle_axes[6 * (size_t)t + k] = (float)axes[k];
    }
    return 0;
}

/* The normal a tangent-space normal map gives at a point of triangle t
   whose interpolated normal is n: the map's vector in the frame of the
   triangle's texture axes (tangent along +u, bitangent along +v, each made
   perpendicular to n) - the frame glTF and Blender build from the UVs. */
static vec3 mapped_normal(const scene *s, int t, const surface_point *point, vec3 n)
{
    const float *axes = s->triangle_axes + 6 * (size_t)t;
    float uv[6], sample[4];
    vec3 tangent = vec3_make(axes[0], axes[1], axes[2]), bitangent = vec3_make(axes[3], axes[4], axes[5]);
    if (vec3_dot(tangent, tangent) == 0.0f || !surface_uv(s, t, point, uv)) return n;
    tangent = vec3_normalize(vec3_sub(tangent, vec3_scale(n, vec3_dot(tangent, n))));
    bitangent = vec3_normalize(vec3_sub(bitangent, vec3_scale(n, vec3_dot(bitangent, n))));
    sample_surface(s->normal_map, uv, 1, sample);
    return vec3_normalize(vec3_add(vec3_add(vec3_scale(tangent, sample[0]), vec3_scale(bitangent, sample[1])),
                                   vec3_scale(n, sample[2])));
}

/* Light an RGB colour on triangle t at a point (unless unlit), and draw the
   wireframe. */
static void light_sample(const scene *s, int t, const surface_point *point, float rgb[3])
{
    const int *corner = s->triangle_corners + 3 * t;
    vec3 normal = vec3_make(0.0f, 0.0f, 0.0f);
    float light;
    int k;

    /* Ambient plus two directional lights fixed to the camera, with the
       normal turned towards the viewer (two-sided). */
    for (k = 0; k < 3; k++) {
        const float *n = s->corner_normal + 3 * corner[k];
        normal = vec3_add(normal, vec3_scale(vec3_make(n[0], n[1], n[2]), point->w[k]));
    }
    normal = vec3_normalize(normal);
    if (s->normal_map) normal = mapped_normal(s, t, point, normal);
    normal = vec3_scale(normal, (float)s->triangle_facing[t]);
    light = 0.32f + 0.72f * fmaxf(0.0f, vec3_dot(normal, s->light_key)) +
            0.22f * fmaxf(0.0f, vec3_dot(normal, s->light_fill));
    /* Unlit: the colour an emission shader shows, so that another renderer's
       picture can be compared with this one whatever its lights. */
    if (s->unlit) light = 1.0f;
    for (k = 0; k < 3; k++) rgb[k] *= light;

    /* Wireframe: b[k] / |grad b[k]| is the distance in samples to the edge
       opposite corner k; darken within a line's width of a face's edge. */
    if (s->wireframe) {
        float ink = 0.0f;
        for (k = 0; k < 3; k++) {
            float gradient = sqrtf(point->dbdx[k] * point->dbdx[k] + point->dbdy[k] * point->dbdy[k]);
            if ((s->triangle_edges[t] >> k) & 1u && gradient > 0.0f)
                ink = fmaxf(ink, 1.0f - fminf(1.0f, fmaxf(0.0f, point->b[k] / gradient - 0.6f) / 0.8f));
        }
        for (k = 0; k < 3; k++) rgb[k] = rgb[k] * (1.0f - 0.85f * ink) + s->wireframe_ink * ink;
    }
}

/* Pasting meshes: every triangle again, in file order. Where the nearest
   surface at a sample is this very triangle (this copy or another paste of
   it), its texture colour goes `over` what the earlier pastes left there. */
typedef struct paste_job {
    const scene *s;
    sample_buffer *samples;
    int triangle;
} paste_job;

static void paste_sample(int x, int y, const float barycentric[3], void *user_data)
{
    paste_job *job = (paste_job *)user_data;
    size_t i = (size_t)y * (size_t)job->samples->width + (size_t)x;
    int nearest = job->samples->triangle[i];
    surface_point point;
    float rgba[4];
    (void)barycentric;
    if (nearest < 0 || job->s->triangle_shape[nearest] != job->s->triangle_shape[job->triangle]) return;
    locate_sample(job->s, job->triangle, (float)x + 0.5f, (float)y + 0.5f, &point);
    texture_color(job->s, job->triangle, &point, rgba);
    tt_rgba_over(job->samples->paste + 4 * i, rgba);
}

static void draw_pastes(const scene *s, sample_buffer *samples)
{
    paste_job job;
    size_t i, n = (size_t)samples->width * (size_t)samples->height;
    int t;
    /* An opaque grey base: where the pastes leave a gap, the surface shows
       as an untextured one would. */
    for (i = 0; i < n; i++) {
        float *base = samples->paste + 4 * i;
        base[0] = base[1] = base[2] = s->untextured_grey;
        base[3] = 1.0f;
    }
    job.s = s;
    job.samples = samples;
    for (t = 0; t < s->ntriangles; t++) {
        float xy[6], q[3];
        if (!triangle_on_screen(s, t, xy, q)) continue;
        job.triangle = t;
        tt_raster_triangle(xy, samples->width, samples->height, paste_sample, &job);
    }
}

/* A quiet vertical gradient, so both dark and light models stand out:
   chosen as displayed values, returned in linear light. */
static void background_color(float y_fraction, float rgb[3])
{
    float grey = 0.86f - 0.16f * y_fraction;
    rgb[0] = tt_srgb_to_linear(grey);
    rgb[1] = rgb[0];
    rgb[2] = tt_srgb_to_linear(grey + 0.015f);
}

static void shade_samples(const scene *s, sample_buffer *samples)
{
    int x, y;
    for (y = 0; y < samples->height; y++) {
        float background[3];
        background_color((float)y / (float)samples->height, background);
        for (x = 0; x < samples->width; x++) {
            size_t i = (size_t)y * (size_t)samples->width + (size_t)x;
            float *out = samples->color + 3 * i, rgba[4];
            int t = samples->triangle[i], k;
            surface_point point;
            if (t < 0) {
                memcpy(out, background, sizeof background);
                continue;
            }
            locate_sample(s, t, (float)x + 0.5f, (float)y + 0.5f, &point);
            if (samples->paste) memcpy(rgba, samples->paste + 4 * i, sizeof rgba);   /* opaque: over grey */
            else texture_color(s, t, &point, rgba);     /* opaque surfaces: alpha is ignored */
            light_sample(s, t, &point, rgba);
            for (k = 0; k < 3; k++) out[k] = rgba[k];
        }
    }
}

/* ======================================================================== */
/* Resolve: average the samples of each pixel                               */
/* ======================================================================== */

/* The average is taken in linear light (anti-aliased edges get the colour
   the eye would average); *out_picture stays linear until it is saved. */
static int resolve(const sample_buffer *samples, tt_image **out_picture, tt_error *error)
{
    int width = samples->width / SUPERSAMPLING, height = samples->height / SUPERSAMPLING, x, y;
    const float weight = 1.0f / (float)(SUPERSAMPLING * SUPERSAMPLING);
    tt_image *picture;
    if (tt_image_create(width, height, NULL, out_picture, error) != TT_OK) return -1;
    picture = *out_picture;
    for (y = 0; y < height; y++) {
        for (x = 0; x < width; x++) {
            float *pixel = picture->pixels + 4 * ((size_t)y * (size_t)width + (size_t)x);
            int sx, sy, k;
            for (sy = 0; sy < SUPERSAMPLING; sy++) {
                for (sx = 0; sx < SUPERSAMPLING; sx++) {
                    size_t i = (size_t)(y * SUPERSAMPLING + sy) * (size_t)samples->width +
                               (size_t)(x * SUPERSAMPLING + sx);
                    for (k = 0; k < 3; k++) pixel[k] += samples->color[3 * i + k] * weight;
                }
            }
            pixel[3] = 1.0f;
        }
    }
    return 0;
}

/* ======================================================================== */
/* Textures: TEXTURE, and those the OBJ's materials name                    */
/* ======================================================================== */

/* The textures faces are drawn with: textures[0] is TEXTURE; a face whose
   material (its latest usemtl) has a map_Kd in the OBJ's MTL file is drawn
   with that texture, each file loaded once - so a pasting OBJ with one
   material per texture patch shows each paste with its own patch. TEXTURE
   stands in wherever a material names no texture, or one that cannot be
   read (a note says so). */
typedef struct texture_set {
    int count;
    mip_texture *textures;      /* up to 1 + materials */
    char **paths;               /* the file each was loaded from (textures[0]: TEXTURE) */
    int *face_texture;          /* per OBJ face: index into textures */
    char *normal_map;           /* the normal map (norm) the faces' materials name, when they name
                                   one and the same; NULL otherwise */
} texture_set;

static void texture_set_free(texture_set *set)
{
    int k;
    for (k = 0; k < set->count; k++) {
        texture_free(&set->textures[k]);
        free(set->paths[k]);
    }
    free(set->textures);
    free(set->paths);
    free(set->face_texture);
    free(set->normal_map);
    memset(set, 0, sizeof *set);
}

/* Load a colour texture (sRGB bytes, decoded to linear light) into the set,
   premultiplied for a pasting mesh: blending, like mip-mapping, needs
   premultiplied colours (or transparent texels bleed their colour).
   Returns its index, or -1 with the reason in err. */
static int texture_set_add(texture_set *set, const char *path, int premultiply, char *err, size_t err_size)
{
    char message[TOOL_ERROR_SIZE];
    tt_image *image;
    int k;
    for (k = 0; k < set->count; k++)
        if (strcmp(set->paths[k], path) == 0) return k;
    if (image_load(path, TT_COLOR_SRGB, &image, err, err_size) != 0) return -1;
    if (premultiply) premultiply_alpha(image);
    if (!(set->paths[set->count] = tool_copy_string(path, strlen(path)))) {
        image_free(image);
        tool_set_error(err, err_size, "out of memory for the texture %s", path);
        return -1;
    }
    if (texture_build(&set->textures[set->count], image, message, sizeof message) != 0) {
        free(set->paths[set->count]);
        tool_set_error(err, err_size, "cannot prepare the texture %s: %s", path, message);
        return -1;
    }
    return set->count++;
}

/* TEXTURE (must load: the command fails otherwise), then, unless
   use_materials is 0, the textures of the materials the faces use.
   Returns 0, or the exit status after printing the error. */
static int load_textures(const char *obj_path, const char *texture_path, const obj_mesh *mesh, int pasting,
                         int use_materials, texture_set *set)
{
    char err[TOOL_ERROR_SIZE], mtl_path[4096], map_path[4096];
    mtl_library library;
    int *material_texture = NULL, f, m, status = 0, several_normal_maps = 0;
    memset(set, 0, sizeof *set);
    memset(&library, 0, sizeof library);
    set->textures = (mip_texture *)calloc((size_t)mesh->nmaterials + 1, sizeof(mip_texture));
    set->paths = (char **)calloc((size_t)mesh->nmaterials + 1, sizeof(char *));
    set->face_texture = (int *)calloc((size_t)mesh->nfaces, sizeof(int));      /* 0: TEXTURE */
    material_texture = (int *)calloc((size_t)mesh->nmaterials, sizeof(int));
    if (!set->textures || !set->paths || !set->face_texture || !material_texture) {
        status = tool_fail("out of memory while rendering %s", obj_path);
        goto done;
    }
    if (texture_set_add(set, texture_path, pasting, err, sizeof err) < 0) {
        status = tool_fail("%s", err);
        goto done;
    }
    if (!use_materials || !mesh->mtllib || mesh->nmaterials < 2) goto done;
    tool_path_beside(mesh->mtllib, obj_path, mtl_path, sizeof mtl_path);
    if (mtl_read(mtl_path, &library, err, sizeof err) != 0) {
        tool_note("%s; drawn with %s", err, texture_path);
        goto done;
    }
    /* Only the materials some face uses: a texture no face shows is not loaded. */
    for (f = 0; f < mesh->nfaces; f++) material_texture[mesh->face_material[f]] = -1;
    for (m = 1; m < mesh->nmaterials; m++) {
        int k;
        if (material_texture[m] == 0) continue;
        material_texture[m] = 0;
        k = mtl_find(&library, mesh->material_names[m]);
        if (k >= 0 && library.normal_maps[k] && !several_normal_maps) {
            tool_path_beside(library.normal_maps[k], mtl_path, map_path, sizeof map_path);
            if (!set->normal_map) {
                if (!(set->normal_map = tool_copy_string(map_path, strlen(map_path)))) {
                    status = tool_fail("out of memory while rendering %s", obj_path);
                    goto done;
                }
            } else if (strcmp(set->normal_map, map_path) != 0) {
                /* one normal map lights the whole surface here */
                several_normal_maps = 1;
                free(set->normal_map);
                set->normal_map = NULL;
                tool_note("the materials of %s name different normal maps: drawn without them", obj_path);
            }
        }
        if (k < 0 || !library.diffuse_maps[k]) continue;
        tool_path_beside(library.diffuse_maps[k], mtl_path, map_path, sizeof map_path);
        material_texture[m] = texture_set_add(set, map_path, pasting, err, sizeof err);
        if (material_texture[m] < 0) {
            tool_note("material %s of %s: %s; drawn with %s", mesh->material_names[m], obj_path, err, texture_path);
            material_texture[m] = 0;
        }
    }
    for (f = 0; f < mesh->nfaces; f++) set->face_texture[f] = material_texture[mesh->face_material[f]];
done:
    mtl_free(&library);
    free(material_texture);
    return status;
}

/* ======================================================================== */
/* The command                                                              */
/* ======================================================================== */

static void print_render_help(void)
{
    printf("usage: tiledtex render MESH TEXTURE OUT.png [--size WxH] [--yaw DEG] [--pitch DEG] [--up AXIS]\n"
           "                       [--zoom F] [--wireframe] [--no-materials] [--unlit]\n"
           "OUT.png may be '-': the PNG goes to the standard output.\n"
           "\n"
           "Draw MESH with TEXTURE (PNG, JPEG, TGA, BMP, ...) applied through the mesh's per-corner\n"
           "texture coordinates (vt) and save the picture as OUT.png. Faces without texture\n"
           "coordinates are drawn in grey (an STL or OFF mesh has none). The camera looks at the\n"
           "whole model; texture coordinates outside [0,1] repeat the texture. The surface is shaded\n"
           "with the mesh's own normals (vn) when every face corner has one, as Blender and engines\n"
           "shade it, else with smooth normals that keep edges sharper than 50 degrees.\n");
    tool_print_mesh_help(0);
    printf("\n"
           "Materials: when MESH names an MTL file (mtllib) and its faces materials (usemtl), a face\n"
           "whose material has a texture (map_Kd, a path relative to the MTL, which is relative to\n"
           "MESH) is drawn with that texture; TEXTURE serves the other faces, and stands in for a\n"
           "material texture that cannot be read (a note says so). So a mesh with several\n"
           "textures shows each where it belongs, whichever TEXTURE is given. A normal map the\n"
           "materials name (norm, as the tool's MTL files do) lights the surface, as --normal\n"
           "does, when they all name the same one.\n"
           "\n"
           "Pasting meshes (from 'tiledtex lapped'), where the same triangle occurs several times,\n"
           "are drawn as the paper draws them: each occurrence in file order, blended over the\n"
           "ones before through its texture's alpha, which is the texture patch (each paste's\n"
           "material names its patch); the coordinates are clamped, not repeated.\n"
           "\n"
           "  --size WxH    picture size in pixels, each side up to %d (default %dx%d)\n"
           "  --yaw DEG     turn the camera around the model's up axis (default 30)\n"
           "  --pitch DEG   raise the camera above the model, -89 to 89 (default 20)\n"
           "  --up AXIS     the model's up axis: y (default, usual for OBJ), z (usual for CAD\n"
           "                and scans), x, -y, -z or -x, or a direction X,Y,Z\n"
           "  --zoom F      magnify the view F times, 0.1 to 100 (default 1: the whole model)\n"
           "  --wireframe   draw the edges of the mesh's faces over the surface\n"
           "  --unlit       draw the texture's colours as they are, without lighting (as an\n"
           "                emission shader shows them): for comparing with other renderers\n"
           "  --no-materials  draw every face with TEXTURE, whatever its material names\n"
           "  --normal N.png  light the surface through a tangent-space normal map over the same\n"
           "                texture coordinates (+Y up, as the tool writes them; the frame is the\n"
           "                texture's u and v axes on each triangle, as glTF and Blender take it);\n"
           "                not for pasting meshes: render the bake (lapped without --pasting)\n"
           "  --normal-y-down  N.png is DirectX style (y down)\n",
           RENDER_MAX_SIZE, RENDER_DEFAULT_WIDTH, RENDER_DEFAULT_HEIGHT);
}

int cmd_render(int argc, char **argv)
{
    const char *positional[3];
    int npositional = 0, width = RENDER_DEFAULT_WIDTH, height = RENDER_DEFAULT_HEIGHT, i, status = TOOL_EXIT_FAILURE;
    double yaw = 30.0, pitch = 20.0, zoom = 1.0;
    int wireframe = 0, use_materials = 1, normal_y_down = 0, unlit = 0;
    const char *normal_path = NULL;
    float *file_normals = NULL;
    mip_texture normal_map;
    char err[TOOL_ERROR_SIZE];
    obj_mesh mesh;
    tt_image *picture = NULL;
    tt_error error;
    texture_set textures;
    scene s;
    camera cam;
    sample_buffer samples;
    tool_output output = TOOL_OUTPUT_INIT;
    vec3 centre;
    float radius;
    int bad_vertex = -1;
    up_axis axis;
    double up[3] = {0.0, 1.0, 0.0};   /* y up, usual for OBJ */

    /* The tool's own outputs must open here without a flag: a lapped bake
       may be 8192 x 8192 (see TOOL_RENDER_MAX_PIXELS). */
    image_set_default_max_pixels(TOOL_RENDER_MAX_PIXELS);
    for (i = 1; i < argc; i++) {
        const char *value;
        if (tool_is_help(argv[i])) {
            print_render_help();
            return 0;
        } else if (tool_option(argc, argv, &i, "--size", &value)) {
            if (parse_size("--size", value, 8, RENDER_MAX_SIZE, &width, &height) != 0) return TOOL_EXIT_USAGE;
        } else if (tool_option(argc, argv, &i, "--yaw", &value)) {
            if (parse_float("--yaw", value, -3600.0, 3600.0, &yaw) != 0) return TOOL_EXIT_USAGE;
        } else if (tool_option(argc, argv, &i, "--pitch", &value)) {
            if (parse_float("--pitch", value, -89.0, 89.0, &pitch) != 0) return TOOL_EXIT_USAGE;
        } else if (tool_option(argc, argv, &i, "--zoom", &value)) {
            if (parse_float("--zoom", value, 0.1, 100.0, &zoom) != 0) return TOOL_EXIT_USAGE;
        } else if (tool_flag(argv[i], "--wireframe")) {
            wireframe = 1;
        } else if (tool_flag(argv[i], "--unlit")) {
            unlit = 1;
        } else if (tool_flag(argv[i], "--no-materials")) {
            use_materials = 0;
        } else if (tool_option(argc, argv, &i, "--normal", &value)) {
            if (!value || !*value) return tool_usage("--normal needs an image");
            normal_path = value;
        } else if (tool_flag(argv[i], "--normal-y-down")) {
            normal_y_down = 1;
        } else if (tool_option(argc, argv, &i, "--up", &value)) {
            if (parse_up("--up", value, up) != 0) return TOOL_EXIT_USAGE;
        } else if (tool_is_option(argv[i])) {
            return tool_unknown_option(argv[i]);
        } else if (npositional < 3) {
            positional[npositional++] = argv[i];
        } else {
            return tool_usage("too many arguments: '%s' (usage: tiledtex render MESH TEXTURE OUT.png)", argv[i]);
        }
    }
    if (npositional < 3)
        return tool_usage("needs MESH, TEXTURE and OUT.png (see 'tiledtex render --help')");
    up_axis_from(up, &axis);

    if (normal_y_down && !normal_path)
        return tool_usage("--normal-y-down says how --normal N.png is encoded, but no --normal was given");
    if (unlit && normal_path)
        return tool_usage("--unlit draws no lighting, which is all --normal %s changes: give one of them", normal_path);
    memset(&textures, 0, sizeof textures);
    memset(&normal_map, 0, sizeof normal_map);
    memset(&s, 0, sizeof s);
    memset(&samples, 0, sizeof samples);
    if (mesh_read(positional[0], &mesh, err, sizeof err) != 0) return tool_fail("%s", err);
    if (mesh_bounding_sphere(&mesh, &centre, &radius, &bad_vertex) != 0) {
        tool_fail("%s: vertex %d has a coordinate that is not a finite number", positional[0], bad_vertex + 1);
        goto done;
    }

    s.mesh = &mesh;
    if (scene_triangulate(&s) != 0 || scene_find_pastes(&s) != 0) {
        tool_fail("out of memory while rendering %s", positional[0]);
        goto done;
    }
    if (load_textures(positional[0], positional[1], &mesh, s.pasting, use_materials, &textures) != 0) goto done;
    /* The materials' normal map lights the surface unless --normal names
       another (a pasting mesh's per-patch maps are for engines that
       composite in order); unlit, nothing would show it. */
    if (!normal_path && textures.normal_map && !s.pasting && !unlit) {
        tt_image *image;
        /* as a material texture that cannot be read: a note, and drawn without */
        if (image_load(textures.normal_map, TT_COLOR_NORMAL, &image, err, sizeof err) != 0)
            tool_note("%s; drawn without the materials' normal map", err);
        else if (texture_build(&normal_map, image, err, sizeof err) != 0)
            tool_note("cannot prepare the normal map %s: %s; drawn without it", textures.normal_map, err);
        else
            s.normal_map = &normal_map;
    } else if (normal_path) {
        tt_image *image;
        if (s.pasting) {
            tool_fail("%s is a pasting mesh: --normal needs one texture over the surface (render the bake, which "
                      "lapped writes without --pasting)",
                      positional[0]);
            goto done;
        }
        if (image_load(normal_path, normal_y_down ? TT_COLOR_NORMAL_Y_DOWN : TT_COLOR_NORMAL, &image, err,
                       sizeof err) != 0) {
            tool_fail("%s", err);
            goto done;
        }
        if (texture_build(&normal_map, image, err, sizeof err) != 0) {
            tool_fail("cannot prepare the normal map %s: %s", normal_path, err);
            goto done;
        }
        s.normal_map = &normal_map;
    }
    if (s.normal_map && scene_texture_axes(&s) != 0) {
        tool_fail("out of memory while rendering %s", positional[0]);
        goto done;
    }
    s.textures = textures.textures;
    s.face_texture = textures.face_texture;
    s.width = width * SUPERSAMPLING;
    s.height = height * SUPERSAMPLING;
    s.wireframe = wireframe;
    s.unlit = unlit;
    s.untextured_grey = tt_srgb_to_linear(UNTEXTURED_GREY_SRGB);
    s.wireframe_ink = tt_srgb_to_linear(WIREFRAME_INK_SRGB);
    camera_orbit(&cam, centre, radius, &axis, (float)yaw, (float)pitch, (float)zoom, s.width, s.height);
    /* Key light from the upper left behind the viewer, a weaker fill from the right. */
    s.light_key = vec3_normalize(vec3_add(vec3_add(vec3_scale(cam.right, -0.45f), vec3_scale(cam.up, 0.6f)),
                                          vec3_scale(cam.forward, -0.75f)));
    s.light_fill = vec3_normalize(vec3_add(vec3_scale(cam.right, 0.8f), vec3_scale(cam.forward, -0.4f)));
    if (scene_compute_normals(&s) != 0 || obj_corner_normals(positional[0], &mesh, &file_normals) != 0 ||
        scene_project(&s, &cam) != 0 || samples_create(&samples, s.width, s.height, s.pasting) != 0) {
        tool_fail("out of memory while rendering %s", positional[0]);
        goto done;
    }
    if (file_normals) scene_use_file_normals(&s, file_normals);

    tool_stage("drawing %d triangles", s.ntriangles);
    draw_visibility(&s, &samples);
    if (s.pasting) draw_pastes(&s, &samples);
    shade_samples(&s, &samples);
    if (resolve(&samples, &picture, &error) != 0) {
        tool_fail("cannot render %s: %s", positional[0], error.message);
        goto done;
    }
    /* The frame is encoded to sRGB once, here. */
    if (output_add_png(&output, positional[2], picture, TT_COLOR_SRGB, err, sizeof err) != 0 ||
        output_commit(&output, err, sizeof err) != 0) {
        tool_fail("%s", err);
        goto done;
    }
    if (!tool_quiet()) printf("wrote %s (%dx%d, %d triangles)\n", positional[2], width, height, s.ntriangles);
    status = 0;

done:
    output_free(&output);
    tt_image_free(picture);
    samples_free(&samples);
    scene_free(&s);
    texture_set_free(&textures);
    texture_free(&normal_map);
    obj_free(&mesh);
    return status;
}
