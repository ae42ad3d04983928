/* generate.c - `tiledtex generate`: example inputs made from nothing.

     tiledtex generate texture OUT.png [--size N] [--seed K]
     tiledtex generate mesh OUT.obj --shape NAME [--triangles]

   The texture is a photograph-like, non-repeating pavement of rounded stones.
   The meshes are small test surfaces of known topology (sphere, torus, double
   torus, ...), so the texturing methods can be tried on every kind of surface
   without downloading anything. Everything is deterministic: the same command
   gives the same file every time. (Random choices come from tt_rng and integer
   hashes, identical everywhere; only libm's sinf / expf may round the last bit
   differently on another platform.) */

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tool.h"

/* ======================================================================== */
/* Part 1: the texture                                                      */
/*                                                                          */
/* Stones are the cells of a Worley (Voronoi) pattern: a jittered point per */
/* grid cell, every pixel belongs to the nearest point. The distance from a */
/* pixel to its cell's border gives the mortar gap and the rounded profile  */
/* of each stone. A height field made of that profile plus value noise is   */
/* lit from the upper left, which is what makes it look photographed; each  */
/* stone gets its own colour, and fine grain goes on top. Nothing repeats:  */
/* random values come from hashing the lattice coordinates with keys drawn  */
/* from tt_rng, so no table wraps around.                                   */
/* ======================================================================== */

#define TEXTURE_DEFAULT_SIZE 512
#define TEXTURE_MAX_SIZE 8192
#define STONE_SPACING 44.0f     /* pixels between stone centres, on average */
#define ROUNDNESS 14.0f         /* sharpness of the soft minimum that rounds stone corners */

typedef struct stone_keys {
    uint32_t points, colors, warp_x, warp_y, bumps, mottle, mortar, grain;
} stone_keys;

/* An integer hash with good avalanche: every input bit flips about half of
   the output bits, so neighbouring lattice points get unrelated values. */
static uint32_t mix32(uint32_t h)
{
    h ^= h >> 16;
    h *= 0x7feb352du;
    h ^= h >> 15;
    h *= 0x846ca68bu;
    h ^= h >> 16;
    return h;
}

static uint32_t hash2(int x, int y, uint32_t key)
{
    return mix32(mix32(key ^ (uint32_t)x * 0x9e3779b1u) ^ (uint32_t)y * 0x85ebca77u);
}

/* Uniform in [0, 1) from the top 24 bits. */
static float hash_unit(uint32_t h) { return (float)(h >> 8) * (1.0f / 16777216.0f); }

static float smooth5(float t) { return t * t * t * (t * (t * 6.0f - 15.0f) + 10.0f); }

static float smoothstep(float edge0, float edge1, float x)
{
    float t = (x - edge0) / (edge1 - edge0);
    t = t < 0.0f ? 0.0f : t > 1.0f ? 1.0f : t;
    return t * t * (3.0f - 2.0f * t);
}

/* Value noise: random values on the integer lattice, smoothly interpolated. */
static float value_noise(float x, float y, uint32_t key)
{
    int ix = (int)floorf(x), iy = (int)floorf(y);
    float fx = smooth5(x - (float)ix), fy = smooth5(y - (float)iy);
    float a = hash_unit(hash2(ix, iy, key)), b = hash_unit(hash2(ix + 1, iy, key));
    float c = hash_unit(hash2(ix, iy + 1, key)), d = hash_unit(hash2(ix + 1, iy + 1, key));
    float top = a + (b - a) * fx, bottom = c + (d - c) * fx;
    return top + (bottom - top) * fy;
}

/* Fractal noise: octaves of value noise, each twice as fine and half as
   strong. Result roughly in [0, 1]. */
static float fractal_noise(float x, float y, int octaves, uint32_t key)
{
    float sum = 0.0f, amplitude = 0.5f, total = 0.0f;
    int i;
    for (i = 0; i < octaves; i++) {
        sum += amplitude * value_noise(x, y, key + (uint32_t)i * 0x632be5abu);
        total += amplitude;
        amplitude *= 0.5f;
        /* Not exactly 2: the octaves' lattices never line up. */
        x = x * 2.03f + 17.3f;
        y = y * 2.03f + 5.1f;
    }
    return sum / total;
}

/* The stone under point (x, y), in units of the stone grid: its lattice cell
   (which names it), and how far the point is from the stone's border. */
typedef struct stone_hit {
    int cell_x, cell_y;
    float border_distance;
    float centre_distance;
} stone_hit;

static void stone_feature_point(int cx, int cy, uint32_t key, float *px, float *py)
{
    /* Jitter within the middle 80% of the cell keeps stones from being slivers. */
    *px = (float)cx + 0.1f + 0.8f * hash_unit(hash2(cx, cy, key));
    *py = (float)cy + 0.1f + 0.8f * hash_unit(hash2(cx, cy, key ^ 0x5bd1e995u));
}

static stone_hit find_stone(float x, float y, uint32_t key)
{
    int gx = (int)floorf(x), gy = (int)floorf(y), dx, dy;
    float best = INFINITY, nearest_x = 0.0f, nearest_y = 0.0f, sum;
    stone_hit hit;
    hit.cell_x = gx;
    hit.cell_y = gy;
    /* Nearest feature point among the surrounding cells. */
    for (dy = -2; dy <= 2; dy++) {
        for (dx = -2; dx <= 2; dx++) {
            float px, py, d2;
            stone_feature_point(gx + dx, gy + dy, key, &px, &py);
            d2 = (px - x) * (px - x) + (py - y) * (py - y);
            if (d2 < best) {
                best = d2;
                hit.cell_x = gx + dx;
                hit.cell_y = gy + dy;
                nearest_x = px;
                nearest_y = py;
            }
        }
    }
    hit.centre_distance = sqrtf(best);
    /* Distance to the cell's border: to the bisectors between our point and
       each other point (exact for a Voronoi cell). A soft minimum over them
       instead of the plain one rounds the cell's corners, so cells look like
       stones rather than polygons. */
    sum = 0.0f;
    for (dy = -2; dy <= 2; dy++) {
        for (dx = -2; dx <= 2; dx++) {
            float px, py, nx, ny, length, distance;
            if (gx + dx == hit.cell_x && gy + dy == hit.cell_y) continue;
            stone_feature_point(gx + dx, gy + dy, key, &px, &py);
            nx = px - nearest_x;
            ny = py - nearest_y;
            length = sqrtf(nx * nx + ny * ny);
            if (length <= 0.0f) continue;
            distance = ((0.5f * (px + nearest_x) - x) * nx + (0.5f * (py + nearest_y) - y) * ny) / length;
            sum += expf(-ROUNDNESS * distance);
        }
    }
    hit.border_distance = sum > 0.0f ? -logf(sum) / ROUNDNESS : 1.0f;
    return hit;
}

/* A few stone colours of a river-bed / old pavement (linear-ish RGB). */
static void stone_color(int cell_x, int cell_y, uint32_t key, float rgb[3])
{
    static const float palette[][3] = {
        {0.58f, 0.55f, 0.50f}, /* grey granite */
        {0.64f, 0.57f, 0.46f}, /* sandstone */
        {0.46f, 0.46f, 0.47f}, /* basalt grey */
        {0.60f, 0.50f, 0.43f}, /* reddish */
        {0.52f, 0.49f, 0.42f}, /* olive */
        {0.70f, 0.67f, 0.61f}, /* pale limestone */
    };
    uint32_t h = hash2(cell_x, cell_y, key);
    const float *base = palette[h % (sizeof palette / sizeof palette[0])];
    float brightness = 0.72f + 0.45f * hash_unit(mix32(h));
    float warmth = (hash_unit(mix32(h ^ 0x27d4eb2fu)) - 0.5f) * 0.08f;
    rgb[0] = base[0] * brightness + warmth;
    rgb[1] = base[1] * brightness;
    rgb[2] = base[2] * brightness - warmth;
}

/* The colours below are designed as displayed (sRGB-encoded) values; the
   last pass decodes them to linear light, what a tt_image holds, and the
   PNG is encoded back to sRGB: the file shows the designed values. */
/* The pavement's colour into *out_image; with `maps` (MATERIAL_MAPS
   images, NULL entries filled here) also its material: the normal map of
   the height field the colour is lit from (unit vectors, +Y up), the
   height itself, the roughness (polished stones, rough mortar) and the
   ambient occlusion the colour is darkened by - maps that match the
   colour texel for texel, to try the commands' --normal and the rest on. */
static int make_stone_texture(int size, uint64_t seed, tt_image **out_image, tt_image **maps)
{
    tt_image *image;
    const float mortar = 0.045f, light[3] = {-0.45f, -0.55f, 0.70f};
    float light_length = sqrtf(light[0] * light[0] + light[1] * light[1] + light[2] * light[2]);
    stone_keys keys;
    tt_rng rng;
    int x, y;

    tt_rng_seed(&rng, seed, 0x5701e5u);
    keys.points = tt_rng_next(&rng);
    keys.colors = tt_rng_next(&rng);
    keys.warp_x = tt_rng_next(&rng);
    keys.warp_y = tt_rng_next(&rng);
    keys.bumps = tt_rng_next(&rng);
    keys.mottle = tt_rng_next(&rng);
    keys.mortar = tt_rng_next(&rng);
    keys.grain = tt_rng_next(&rng);
    if (tt_image_create(size, size, NULL, out_image, NULL) != TT_OK) return -1;
    image = *out_image;
    if (maps) {
        int map;
        for (map = 0; map < MATERIAL_MAPS; map++)
            if (map != MATERIAL_METALLIC && tt_image_create(size, size, NULL, &maps[map], NULL) != TT_OK) return -1;
        maps[MATERIAL_NORMAL]->kind = TT_IMAGE_NORMAL;
    }

    /* Pass 1: albedo into RGB, height into alpha (a free scratch channel). */
    tool_stage("generating the stones");
    for (y = 0; y < size; y++) {
        /* the first pass is most of the time (a 4096 texture takes seconds) */
        if (y % 64 == 0) tool_stage_fraction(0.8 * y / size, "of the rows");
        for (x = 0; x < size; x++) {
            float *pixel = image->pixels + 4 * ((size_t)y * (size_t)size + (size_t)x);
            float fx = (float)x, fy = (float)y, sx, sy, stone, dome, height, mottle, grit, albedo[3];
            stone_hit hit;
            int k;
            /* Warp the lookup so stone borders wobble instead of being straight. */
            sx = (fx + 14.0f * (fractal_noise(fx / 37.0f, fy / 37.0f, 3, keys.warp_x) - 0.5f)) / STONE_SPACING;
            sy = (fy + 14.0f * (fractal_noise(fx / 37.0f, fy / 37.0f, 3, keys.warp_y) - 0.5f)) / STONE_SPACING;
            hit = find_stone(sx, sy, keys.points);

            /* 0 in the mortar, 1 on a stone; the height rises across the
               stone's edge in a quarter circle, so each stone is a dome. */
            stone = smoothstep(mortar, mortar + 0.025f, hit.border_distance);
            dome = (hit.border_distance - mortar) / 0.32f;
            dome = dome < 0.0f ? 0.0f : dome > 1.0f ? 1.0f : dome;
            dome = sqrtf(1.0f - (1.0f - dome) * (1.0f - dome));
            grit = fractal_noise(fx / 2.5f, fy / 2.5f, 2, keys.mortar);
            mottle = fractal_noise(fx / 9.0f + 100.0f * hash_unit(hash2(hit.cell_x, hit.cell_y, keys.mottle)),
                                   fy / 9.0f, 4, keys.mottle);
            height = 0.8f * dome + 0.18f * fractal_noise(fx / 5.0f, fy / 5.0f, 3, keys.bumps) * stone +
                     0.10f * grit * (1.0f - stone);

            if (maps) {
                float *rough = maps[MATERIAL_ROUGHNESS]->pixels + 4 * ((size_t)y * (size_t)size + (size_t)x);
                float *high = maps[MATERIAL_HEIGHT]->pixels + 4 * ((size_t)y * (size_t)size + (size_t)x);
                rough[0] = rough[1] = rough[2] = 0.9f - (0.45f - 0.15f * mottle) * stone;
                high[0] = high[1] = high[2] = height;
                rough[3] = high[3] = 1.0f;
            }
            stone_color(hit.cell_x, hit.cell_y, keys.colors, albedo);
            for (k = 0; k < 3; k++) {
                float on_stone = albedo[k] * (0.80f + 0.40f * mottle);
                float in_mortar = (k == 0 ? 0.50f : k == 1 ? 0.46f : 0.40f) * (0.70f + 0.6f * grit);
                pixel[k] = in_mortar + (on_stone - in_mortar) * stone;
            }
            pixel[3] = height;
        }
    }

    /* Pass 2: light the height field. The slope (central differences) tilts
       the surface normal; the light comes from the upper left. Mortar and the
       foot of each stone are darkened as if little light reached them. */
    for (y = 0; y < size; y++) {
        if (y % 64 == 0) tool_stage_fraction(0.8 + 0.2 * y / size, "of the rows");
        for (x = 0; x < size; x++) {
            float *pixel = image->pixels + 4 * ((size_t)y * (size_t)size + (size_t)x);
            int xl = x > 0 ? x - 1 : x, xr = x + 1 < size ? x + 1 : x;
            int yu = y > 0 ? y - 1 : y, yd = y + 1 < size ? y + 1 : y;
            float hl = image->pixels[4 * ((size_t)y * (size_t)size + (size_t)xl) + 3];
            float hr = image->pixels[4 * ((size_t)y * (size_t)size + (size_t)xr) + 3];
            float hu = image->pixels[4 * ((size_t)yu * (size_t)size + (size_t)x) + 3];
            float hd = image->pixels[4 * ((size_t)yd * (size_t)size + (size_t)x) + 3];
            float strength = 5.0f, nx, ny, nz = 1.0f, length, diffuse, occlusion, shade, grain;
            int k;
            nx = -(hr - hl) / (float)(xr - xl) * strength;
            ny = -(hd - hu) / (float)(yd - yu) * strength;
            length = sqrtf(nx * nx + ny * ny + nz * nz);
            diffuse = (nx * light[0] + ny * light[1] + nz * light[2]) / (length * light_length);
            if (diffuse < 0.0f) diffuse = 0.0f;
            occlusion = 0.62f + 0.38f * (pixel[3] > 0.8f ? 1.0f : pixel[3] / 0.8f);
            shade = (0.25f + 0.9f * diffuse) * occlusion;
            if (maps) {
                /* nx, ny are in the image's axes (y down); the map holds y up */
                float *normal = maps[MATERIAL_NORMAL]->pixels + 4 * ((size_t)y * (size_t)size + (size_t)x);
                float *ao = maps[MATERIAL_AO]->pixels + 4 * ((size_t)y * (size_t)size + (size_t)x);
                normal[0] = nx / length;
                normal[1] = -ny / length;
                normal[2] = nz / length;
                ao[0] = ao[1] = ao[2] = occlusion;
                normal[3] = ao[3] = 1.0f;
            }
            grain = 0.06f * (hash_unit(hash2(x, y, keys.grain)) - 0.5f);
            for (k = 0; k < 3; k++) {
                float value = pixel[k] * shade + grain;
                pixel[k] = tt_srgb_to_linear(value < 0.0f ? 0.0f : value > 1.0f ? 1.0f : value);
            }
        }
    }
    for (y = 0; y < size; y++)
        for (x = 0; x < size; x++) image->pixels[4 * ((size_t)y * (size_t)size + (size_t)x) + 3] = 1.0f;
    return 0;
}

static void print_generate_help(void)
{
    printf("usage: tiledtex generate texture OUT.png [--size N] [--seed K] [--material]\n"
           "       tiledtex generate mesh OUT.obj --shape NAME [--triangles]\n"
           "OUT.png or OUT.obj may be '-': the file goes to the standard output.\n"
           "\n"
           "texture: a photograph-like pavement of rounded stones that never repeats, N x N pixels\n"
           "         (default %d, at most %d); --seed K picks another pavement (default 1).\n"
           "         --material also writes the pavement's other maps beside OUT.png, texel for\n"
           "         texel: OUT_normal.png (tangent space, +Y up), OUT_height.png, OUT_roughness.png\n"
           "         and OUT_ao.png, to try the commands' --normal, --height, ... on.\n"
           "mesh:    a test surface as an OBJ file. Shapes:\n"
           "           double-torus  genus 2, smooth, all quads with vertices of valence 3, 4, 5 and 6\n"
           "                         (a plate with two holes, built from triangles, quads, a pentagon and\n"
           "                         a hexagon, then two Catmull-Clark steps)\n"
           "           genus3        a smooth plate with three holes, all quads\n"
           "           torus         genus 1, a 32 x 16 quad grid\n"
           "           sphere        genus 0, an icosphere of 1280 triangles\n"
           "           grid          an open, bumpy 32 x 32 quad sheet (one boundary loop)\n"
           "           pair          two separate closed quad surfaces: a torus and a ball\n"
           "         --triangles splits every face into triangles.\n",
           TEXTURE_DEFAULT_SIZE, TEXTURE_MAX_SIZE);
}

static int generate_texture(int argc, char **argv)
{
    const char *path = NULL;
    int size = TEXTURE_DEFAULT_SIZE, i, status, material = 0, map;
    uint64_t seed = 1;
    tt_image *image = NULL, *maps[MATERIAL_MAPS];
    tool_output output = TOOL_OUTPUT_INIT;
    char err[TOOL_ERROR_SIZE], prefix[TOOL_PREFIX_SIZE], map_path[TOOL_PREFIX_SIZE + 32];
    memset(maps, 0, sizeof maps);
    for (i = 2; i < argc; i++) {
        const char *value;
        if (tool_is_help(argv[i])) {
            print_generate_help();
            return 0;
        } else if (tool_option(argc, argv, &i, "--size", &value)) {
            if (parse_int("--size", value, 16, TEXTURE_MAX_SIZE, &size) != 0) return TOOL_EXIT_USAGE;
        } else if (tool_option(argc, argv, &i, "--seed", &value)) {
            if (parse_u64("--seed", value, &seed) != 0) return TOOL_EXIT_USAGE;
        } else if (tool_flag(argv[i], "--material")) {
            material = 1;
        } else if (tool_is_option(argv[i])) {
            return tool_unknown_option(argv[i]);
        } else if (!path) {
            path = argv[i];
        } else {
            return tool_usage("too many arguments: '%s' (usage: tiledtex generate texture OUT.png)", argv[i]);
        }
    }
    if (!path) return tool_usage("needs an output file: tiledtex generate texture OUT.png");
    /* The maps go beside OUT.png: OUT_normal.png, ... ("-" takes one file). */
    if (material && (tool_refuse_stdout(path, 1, "OUT.png with --material") != 0 ||
                     tool_output_prefix(path, NULL, prefix) != 0))
        return TOOL_EXIT_USAGE;
    status = 0;
    if (make_stone_texture(size, seed, &image, material ? maps : NULL) != 0)
        status = tool_fail("out of memory making a %dx%d texture", size, size);
    if (status == 0 && output_add_png(&output, path, image, TT_COLOR_SRGB, err, sizeof err) != 0)
        status = tool_fail("%s", err);
    for (map = 0; map < MATERIAL_MAPS && status == 0; map++) {
        if (!maps[map]) continue;
        material_path(map_path, sizeof map_path, prefix, map);
        status = output_add_map_png(&output, map_path, map, maps[map]);
    }
    if (status == 0 && output_commit(&output, err, sizeof err) != 0) status = tool_fail("%s", err);
    if (status == 0 && !tool_quiet()) {
        printf("wrote %s (%dx%d stones, seed %llu)", path, size, size, (unsigned long long)seed);
        if (material) printf(" and its normal, height, roughness and ao maps beside it");
        printf("\n");
    }
    output_free(&output);
    tt_image_free(image);
    for (map = 0; map < MATERIAL_MAPS; map++) tt_image_free(maps[map]);
    return status;
}

/* ======================================================================== */
/* Part 2: meshes                                                           */
/* ======================================================================== */

/* A growing polygon mesh: positions, face sizes, corner vertex indices -
   exactly what tt_mesh_desc and obj_write take. A failed allocation sets
   `failed`; later calls do nothing, and the caller checks once at the end. */
typedef struct poly_mesh {
    int nverts, nfaces, ncorners;
    int vert_capacity, face_capacity, corner_capacity;
    float *pos;
    int *face_size;
    int *corner_vert;
    int failed;
} poly_mesh;

static void poly_free(poly_mesh *m)
{
    free(m->pos);
    free(m->face_size);
    free(m->corner_vert);
    memset(m, 0, sizeof *m);
}

static int poly_grow(void **array, int *capacity, int needed, size_t element_size)
{
    int grown = *capacity ? *capacity : 64;
    void *resized;
    if (needed <= *capacity) return 0;
    while (grown < needed) grown *= 2;
    resized = realloc(*array, (size_t)grown * element_size);
    if (!resized) return -1;
    *array = resized;
    *capacity = grown;
    return 0;
}

static int poly_vertex(poly_mesh *m, float x, float y, float z)
{
    if (m->failed || poly_grow((void **)&m->pos, &m->vert_capacity, 3 * (m->nverts + 1), sizeof(float)) != 0) {
        m->failed = 1;
        return 0;
    }
    m->pos[3 * m->nverts] = x;
    m->pos[3 * m->nverts + 1] = y;
    m->pos[3 * m->nverts + 2] = z;
    return m->nverts++;
}

static void poly_face(poly_mesh *m, int size, const int *verts)
{
    if (m->failed || poly_grow((void **)&m->face_size, &m->face_capacity, m->nfaces + 1, sizeof(int)) != 0 ||
        poly_grow((void **)&m->corner_vert, &m->corner_capacity, m->ncorners + size, sizeof(int)) != 0) {
        m->failed = 1;
        return;
    }
    memcpy(m->corner_vert + m->ncorners, verts, (size_t)size * sizeof(int));
    m->face_size[m->nfaces++] = size;
    m->ncorners += size;
}

static void poly_quad(poly_mesh *m, int a, int b, int c, int d)
{
    int v[4];
    v[0] = a; v[1] = b; v[2] = c; v[3] = d;
    poly_face(m, 4, v);
}

static void poly_triangle(poly_mesh *m, int a, int b, int c)
{
    int v[3];
    v[0] = a; v[1] = b; v[2] = c;
    poly_face(m, 3, v);
}

/* Append a whole mesh (for shapes made of several parts). */
static void poly_append(poly_mesh *m, const poly_mesh *part)
{
    int offset = m->nverts, v, f, c = 0;
    for (v = 0; v < part->nverts; v++) poly_vertex(m, part->pos[3 * v], part->pos[3 * v + 1], part->pos[3 * v + 2]);
    for (f = 0; f < part->nfaces && !m->failed; f++) {
        int verts[16], i, size = part->face_size[f];
        for (i = 0; i < size && i < 16; i++) verts[i] = part->corner_vert[c + i] + offset;
        poly_face(m, size < 16 ? size : 16, verts);
        c += size;
    }
}

/* Split every face into a fan of triangles (--triangles). */
static void poly_triangulate(const poly_mesh *in, poly_mesh *out)
{
    int f, c = 0, i;
    memset(out, 0, sizeof *out);
    for (i = 0; i < in->nverts; i++) poly_vertex(out, in->pos[3 * i], in->pos[3 * i + 1], in->pos[3 * i + 2]);
    for (f = 0; f < in->nfaces; f++) {
        for (i = 1; i + 1 < in->face_size[f]; i++)
            poly_triangle(out, in->corner_vert[c], in->corner_vert[c + i], in->corner_vert[c + i + 1]);
        c += in->face_size[f];
    }
    out->failed |= in->failed;
}

static void poly_translate(poly_mesh *m, float dx, float dy, float dz)
{
    int v;
    for (v = 0; v < m->nverts; v++) {
        m->pos[3 * v] += dx;
        m->pos[3 * v + 1] += dy;
        m->pos[3 * v + 2] += dz;
    }
}

/* A closed surface around the origin that every ray from the origin crosses
   once (a ball, say) is oriented by turning each face whose normal points
   towards the origin. */
static void poly_orient_outward_from_origin(poly_mesh *m)
{
    int f, c = 0;
    for (f = 0; f < m->nfaces; c += m->face_size[f], f++) {
        int n = m->face_size[f], i;
        float normal[3] = {0, 0, 0}, centre[3] = {0, 0, 0};
        for (i = 0; i < n; i++) {
            const float *a = m->pos + 3 * m->corner_vert[c + i];
            const float *b = m->pos + 3 * m->corner_vert[c + (i + 1) % n];
            normal[0] += (a[1] - b[1]) * (a[2] + b[2]);
            normal[1] += (a[2] - b[2]) * (a[0] + b[0]);
            normal[2] += (a[0] - b[0]) * (a[1] + b[1]);
            centre[0] += a[0];
            centre[1] += a[1];
            centre[2] += a[2];
        }
        if (normal[0] * centre[0] + normal[1] * centre[1] + normal[2] * centre[2] < 0.0f) {
            for (i = 0; i < n / 2; i++) {       /* reverse the corner order */
                int t = m->corner_vert[c + i];
                m->corner_vert[c + i] = m->corner_vert[c + n - 1 - i];
                m->corner_vert[c + n - 1 - i] = t;
            }
        }
    }
}

static int poly_build(const poly_mesh *m, tt_mesh **mesh, tt_error *error)
{
    tt_mesh_desc desc;
    memset(&desc, 0, sizeof desc);
    desc.positions = m->pos;
    desc.nverts = m->nverts;
    desc.indices = m->corner_vert;
    desc.face_sizes = m->face_size;
    desc.nfaces = m->nfaces;
    return tt_mesh_build(&desc, NULL, mesh, error);
}

static void poly_from_tt_mesh(const tt_mesh *mesh, poly_mesh *out)
{
    int v, f;
    memset(out, 0, sizeof *out);
    for (v = 0; v < mesh->nverts; v++) poly_vertex(out, mesh->pos[3 * v], mesh->pos[3 * v + 1], mesh->pos[3 * v + 2]);
    for (f = 0; f < mesh->nfaces; f++)
        poly_face(out, mesh->face_start[f + 1] - mesh->face_start[f], mesh->corner_vert + mesh->face_start[f]);
}

/* ---- torus: a quad grid wrapped around both ways (genus 1) ------------- */

static void make_torus(poly_mesh *m, int around, int across, float major_radius, float minor_radius)
{
    const float two_pi = 6.28318530718f;
    int i, j, first = m->nverts;
    /* Lying flat: the hole's axis is vertical (y). */
    for (i = 0; i < around; i++) {
        float u = two_pi * (float)i / (float)around;
        for (j = 0; j < across; j++) {
            float v = two_pi * (float)j / (float)across;
            float ring = major_radius + minor_radius * cosf(v);
            poly_vertex(m, ring * cosf(u), minor_radius * sinf(v), -ring * sinf(u));
        }
    }
    /* Corner order chosen so the normals point out of the tube. */
    for (i = 0; i < around; i++) {
        int i1 = (i + 1) % around;
        for (j = 0; j < across; j++) {
            int j1 = (j + 1) % across;
            poly_quad(m, first + i * across + j, first + i1 * across + j, first + i1 * across + j1,
                      first + i * across + j1);
        }
    }
}

/* ---- ball of quads: a cube's faces gridded, pushed onto a sphere ------- */

static void make_quad_ball(poly_mesh *m, int n, float radius)
{
    /* Lattice points (a, b, c) in [0, n]^3 on the cube's surface share one
       vertex between the faces that meet there. */
    int *vertex_of = (int *)malloc((size_t)(n + 1) * (size_t)(n + 1) * (size_t)(n + 1) * sizeof(int));
    int axis, side, a, b;
    poly_mesh ball;
    if (!vertex_of) { m->failed = 1; return; }
    memset(&ball, 0, sizeof ball);
    for (a = 0; a < (n + 1) * (n + 1) * (n + 1); a++) vertex_of[a] = -1;
    for (axis = 0; axis < 3; axis++) {
        for (side = 0; side <= n; side += n) {
            for (a = 0; a < n; a++) {
                for (b = 0; b < n; b++) {
                    int quad[4], k;
                    static const int offsets[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
                    for (k = 0; k < 4; k++) {
                        int p[3], index;
                        p[axis] = side;
                        p[(axis + 1) % 3] = a + offsets[k][0];
                        p[(axis + 2) % 3] = b + offsets[k][1];
                        index = (p[0] * (n + 1) + p[1]) * (n + 1) + p[2];
                        if (vertex_of[index] < 0) {
                            float x = 2.0f * (float)p[0] / (float)n - 1.0f, y = 2.0f * (float)p[1] / (float)n - 1.0f;
                            float z = 2.0f * (float)p[2] / (float)n - 1.0f, length = sqrtf(x * x + y * y + z * z);
                            vertex_of[index] = poly_vertex(&ball, radius * x / length, radius * y / length,
                                                           radius * z / length);
                        }
                        quad[k] = vertex_of[index];
                    }
                    poly_face(&ball, 4, quad);
                }
            }
        }
    }
    free(vertex_of);
    poly_orient_outward_from_origin(&ball);
    poly_append(m, &ball);
    m->failed |= ball.failed;
    poly_free(&ball);
}

/* ---- icosphere: a subdivided icosahedron (genus 0, triangles) ---------- */

/* The 12 vertices of an icosahedron are the cyclic permutations of
   (0, +-1, +-phi); its 20 faces are the vertex triples at mutual distance 2.
   Finding them by that rule is shorter (and harder to get wrong) than typing
   a table. */
static void make_icosahedron(poly_mesh *m)
{
    const float phi = 1.61803398875f;
    float p[12][3];
    int i, j, k, n = 0, s1, s2;
    for (k = 0; k < 3; k++) {
        for (s1 = -1; s1 <= 1; s1 += 2) {
            for (s2 = -1; s2 <= 1; s2 += 2) {
                p[n][k] = 0.0f;
                p[n][(k + 1) % 3] = (float)s1;
                p[n][(k + 2) % 3] = (float)s2 * phi;
                n++;
            }
        }
    }
    for (i = 0; i < 12; i++) {
        float length = sqrtf(1.0f + phi * phi);
        poly_vertex(m, p[i][0] / length, p[i][1] / length, p[i][2] / length);
    }
#define ICO_EDGE(a, b) (fabsf((p[a][0] - p[b][0]) * (p[a][0] - p[b][0]) + (p[a][1] - p[b][1]) * (p[a][1] - p[b][1]) + \
                              (p[a][2] - p[b][2]) * (p[a][2] - p[b][2]) - 4.0f) < 0.01f)
    for (i = 0; i < 12; i++)
        for (j = i + 1; j < 12; j++)
            for (k = j + 1; k < 12; k++)
                if (ICO_EDGE(i, j) && ICO_EDGE(j, k) && ICO_EDGE(i, k)) poly_triangle(m, i, j, k);
#undef ICO_EDGE
    poly_orient_outward_from_origin(m);
}

/* One subdivision step: every triangle becomes four, with a new vertex at the
   middle of each edge, pushed out onto the unit sphere. The half-edge mesh
   tells which half-edges are the same edge (twins), so each edge gets exactly
   one midpoint. */
static int subdivide_sphere(poly_mesh *m)
{
    tt_mesh *mesh;
    tt_error error;
    poly_mesh finer;
    int *midpoint, c, f;
    if (poly_build(m, &mesh, &error) != TT_OK) return -1;
    memset(&finer, 0, sizeof finer);
    midpoint = (int *)malloc((size_t)mesh->ncorners * sizeof(int));
    if (!midpoint) { tt_mesh_free(mesh); return -1; }
    for (c = 0; c < m->nverts; c++) poly_vertex(&finer, m->pos[3 * c], m->pos[3 * c + 1], m->pos[3 * c + 2]);
    for (c = 0; c < mesh->ncorners; c++) {
        int twin = mesh->twin[c];
        if (twin >= 0 && twin < c) {
            midpoint[c] = midpoint[twin];       /* this edge's midpoint exists already */
        } else {
            const float *a = mesh->pos + 3 * mesh->corner_vert[c];
            const float *b = mesh->pos + 3 * mesh->corner_vert[tt_mesh_next(mesh, c)];
            float x = a[0] + b[0], y = a[1] + b[1], z = a[2] + b[2], length = sqrtf(x * x + y * y + z * z);
            midpoint[c] = poly_vertex(&finer, x / length, y / length, z / length);
        }
    }
    for (f = 0; f < mesh->nfaces; f++) {
        int c0 = mesh->face_start[f], a = mesh->corner_vert[c0], b = mesh->corner_vert[c0 + 1];
        int cc = mesh->corner_vert[c0 + 2];
        int ab = midpoint[c0], bc = midpoint[c0 + 1], ca = midpoint[c0 + 2];
        poly_triangle(&finer, a, ab, ca);
        poly_triangle(&finer, ab, b, bc);
        poly_triangle(&finer, ca, bc, cc);
        poly_triangle(&finer, ab, bc, ca);
    }
    free(midpoint);
    tt_mesh_free(mesh);
    poly_free(m);
    *m = finer;
    return m->failed ? -1 : 0;
}

/* ---- grid: an open sheet with gentle bumps ----------------------------- */

static void make_grid(poly_mesh *m, int n)
{
    int i, j;
    for (j = 0; j <= n; j++) {
        for (i = 0; i <= n; i++) {
            float x = 2.0f * (float)i / (float)n - 1.0f, z = 2.0f * (float)j / (float)n - 1.0f;
            float y = 0.22f * sinf(3.1f * x + 0.4f) * cosf(2.3f * z) + 0.08f * sinf(5.3f * (x + z));
            poly_vertex(m, x, y, z);
        }
    }
    /* Counter-clockwise seen from above (+y). */
    for (j = 0; j < n; j++)
        for (i = 0; i < n; i++)
            poly_quad(m, j * (n + 1) + i, (j + 1) * (n + 1) + i, (j + 1) * (n + 1) + i + 1, j * (n + 1) + i + 1);
}

/* ---- plates with holes: double torus and genus 3 ----------------------- */

/* A thick plate on a grid of cells in the x-y plane (facing the default
   camera), some cells cut out as holes. Each solid cell has a top face
   (z = +half) and a bottom face (z = -half); a wall joins them wherever the
   neighbouring cell is a hole or outside. Lattice point (i, j) has vertex
   top = 2 * (j * (nx + 1) + i) and bottom = top + 1. */
typedef struct plate {
    int nx, ny;
    const float *xs, *ys;       /* nx + 1 and ny + 1 cell borders */
    const char *holes;          /* ny rows of nx chars: '#' solid, '.' hole */
} plate;

typedef struct face_list {
    int count;
    int size[64 * 4];
    int verts[64 * 4][8];
} face_list;

static int plate_solid(const plate *p, int i, int j)
{
    return i >= 0 && j >= 0 && i < p->nx && j < p->ny && p->holes[j * p->nx + i] == '#';
}

static int plate_vertex(const plate *p, int i, int j, int bottom) { return 2 * (j * (p->nx + 1) + i) + bottom; }

static void list_add(face_list *list, int size, const int *verts)
{
    if (list->count >= (int)(sizeof list->size / sizeof list->size[0])) return;
    list->size[list->count] = size;
    memcpy(list->verts[list->count], verts, (size_t)size * sizeof(int));
    list->count++;
}

static void plate_faces(const plate *p, face_list *list)
{
    static const int corner_di[4] = {0, 1, 1, 0}, corner_dj[4] = {0, 0, 1, 1};
    static const int side_di[4] = {0, 1, 0, -1}, side_dj[4] = {-1, 0, 1, 0};
    int i, j, k;
    list->count = 0;
    for (j = 0; j < p->ny; j++) {
        for (i = 0; i < p->nx; i++) {
            int top[4], bottom[4];
            if (!plate_solid(p, i, j)) continue;
            /* Top corners counter-clockwise seen from +z; the bottom reversed. */
            for (k = 0; k < 4; k++) {
                top[k] = plate_vertex(p, i + corner_di[k], j + corner_dj[k], 0);
                bottom[3 - k] = plate_vertex(p, i + corner_di[k], j + corner_dj[k], 1);
            }
            list_add(list, 4, top);
            list_add(list, 4, bottom);
            /* Side k of the top face runs from corner k to corner k + 1; a wall
               there uses that edge the other way round, then goes down. */
            for (k = 0; k < 4; k++) {
                int wall[4], next = (k + 1) % 4;
                if (plate_solid(p, i + side_di[k], j + side_dj[k])) continue;
                wall[0] = top[k];
                wall[1] = top[k] + 1;       /* the bottom vertex below it */
                wall[2] = top[next] + 1;
                wall[3] = top[next];
                list_add(list, 4, wall);
            }
        }
    }
}

static int find_face(const face_list *list, int size, const int *verts)
{
    int f, k;
    for (f = 0; f < list->count; f++) {
        if (list->size[f] != size) continue;
        for (k = 0; k < size && list->verts[f][k] == verts[k]; k++) {
        }
        if (k == size) return f;
    }
    return -1;
}

static void remove_face(face_list *list, int f)
{
    list->count--;
    list->size[f] = list->size[list->count];
    memcpy(list->verts[f], list->verts[list->count], sizeof list->verts[f]);
}

/* Merge faces a and b along their one shared edge u -> v (in a) / v -> u (in
   b): walk a from v round to u, then b from the corner after u round to the
   one before v. Sizes add up minus the two shared corners. */
static int merge_faces(face_list *list, int a, int b)
{
    int na = list->size[a], nb = list->size[b], i, j, merged[8], n = 0;
    for (i = 0; i < na; i++) {
        int u = list->verts[a][i], v = list->verts[a][(i + 1) % na];
        for (j = 0; j < nb; j++)
            if (list->verts[b][j] == v && list->verts[b][(j + 1) % nb] == u) break;
        if (j < nb) {
            int k;
            if (na + nb - 2 > 8) return -1;
            for (k = 1; k <= na; k++) merged[n++] = list->verts[a][(i + k) % na];
            for (k = 2; k < nb; k++) merged[n++] = list->verts[b][(j + k) % nb];
            list->size[a] = n;
            memcpy(list->verts[a], merged, (size_t)n * sizeof(int));
            remove_face(list, b);
            return 0;
        }
    }
    return -1;
}

/* Cut a quad along the diagonal from corner 0 to corner 2. */
static void split_quad(face_list *list, int f)
{
    int tri[3];
    tri[0] = list->verts[f][0];
    tri[1] = list->verts[f][2];
    tri[2] = list->verts[f][3];
    list->size[f] = 3;              /* keeps corners 0, 1, 2 */
    list_add(list, 3, tri);
}

static int plate_cell_face(const plate *p, const face_list *list, int i, int j, int bottom)
{
    static const int corner_di[4] = {0, 1, 1, 0}, corner_dj[4] = {0, 0, 1, 1};
    int v[4], k;
    for (k = 0; k < 4; k++) v[bottom ? 3 - k : k] = plate_vertex(p, i + corner_di[k], j + corner_dj[k], bottom);
    return find_face(list, 4, v);
}

/* Mix in other polygons, so the surface has vertices of valence 3, 4, 5 and
   6 after quadrangulation: on the top, cells (1,0) and (2,0) become one
   hexagon and cell (2,2) two triangles; underneath, cell (0,2) is cut into two
   triangles and one of them joins cell (1,2) as a pentagon. */
static int plate_mix_polygons(const plate *p, face_list *list)
{
    int a = plate_cell_face(p, list, 1, 0, 0), b = plate_cell_face(p, list, 2, 0, 0), f;
    if (a < 0 || b < 0 || merge_faces(list, a, b) != 0) return -1;
    f = plate_cell_face(p, list, 2, 2, 0);
    if (f < 0) return -1;
    split_quad(list, f);
    f = plate_cell_face(p, list, 0, 2, 1);
    if (f < 0) return -1;
    split_quad(list, f);                                /* f keeps corners 0, 1, 2 */
    a = plate_cell_face(p, list, 1, 2, 1);
    return a < 0 ? -1 : merge_faces(list, a, f);
}

static void plate_to_poly(const plate *p, const face_list *list, poly_mesh *m)
{
    int i, j, f;
    float cx = 0.5f * (p->xs[0] + p->xs[p->nx]), cy = 0.5f * (p->ys[0] + p->ys[p->ny]);
    memset(m, 0, sizeof *m);
    for (j = 0; j <= p->ny; j++) {
        for (i = 0; i <= p->nx; i++) {
            poly_vertex(m, p->xs[i] - cx, p->ys[j] - cy, 0.5f);
            poly_vertex(m, p->xs[i] - cx, p->ys[j] - cy, -0.5f);
        }
    }
    for (f = 0; f < list->count; f++) poly_face(m, list->size[f], list->verts[f]);
}

/* Catmull-Clark twice through the library: every face becomes quads, and the
   surface becomes smooth and round. */
static int smooth_twice(poly_mesh *m, char *err, size_t err_size)
{
    tt_mesh *mesh, *once, *twice;
    tt_error error;
    if (poly_build(m, &mesh, &error) != TT_OK) {
        snprintf(err, err_size, "internal error: the plate is not a valid mesh: %s", error.message);
        return -1;
    }
    if (tt_mesh_quadrangulate(mesh, TT_SUBDIVIDE_CATMULL_CLARK, NULL, &once, &error) != TT_OK) {
        tt_mesh_free(mesh);
        snprintf(err, err_size, "cannot subdivide: %s", error.message);
        return -1;
    }
    tt_mesh_free(mesh);
    if (tt_mesh_quadrangulate(once, TT_SUBDIVIDE_CATMULL_CLARK, NULL, &twice, &error) != TT_OK) {
        tt_mesh_free(once);
        snprintf(err, err_size, "cannot subdivide: %s", error.message);
        return -1;
    }
    tt_mesh_free(once);
    poly_free(m);
    poly_from_tt_mesh(twice, m);
    tt_mesh_free(twice);
    return m->failed ? -1 : 0;
}

/* A thick plate with `holes` holes in a row, smoothed: a surface of genus
   `holes`. Holes are wider than the arms around them so they stay open after
   smoothing. With mix_polygons some cells become triangles, pentagons and a
   hexagon first, so the smoothed quads meet at vertices of valence 3 to 6. */
static int make_holed_plate(poly_mesh *m, int holes, int mix_polygons, char *err, size_t err_size)
{
    static const float xs[] = {0.0f, 1.0f, 2.4f, 3.4f, 4.8f, 5.8f, 7.2f, 8.2f}, ys[] = {0.0f, 1.0f, 2.4f, 3.4f};
    static const char *const middle_rows[] = {"", "#.#", "#.#.#", "#.#.#.#"};
    char holes_text[3 * 8];
    plate p;
    face_list list;
    p.nx = 2 * holes + 1;
    p.ny = 3;
    p.xs = xs;
    p.ys = ys;
    memset(holes_text, '#', (size_t)(3 * p.nx));
    memcpy(holes_text + p.nx, middle_rows[holes], (size_t)p.nx);
    holes_text[3 * p.nx] = '\0';
    p.holes = holes_text;
    plate_faces(&p, &list);
    if (mix_polygons && plate_mix_polygons(&p, &list) != 0) {
        snprintf(err, err_size, "internal error: could not mix polygons into the plate");
        return -1;
    }
    plate_to_poly(&p, &list, m);
    return smooth_twice(m, err, err_size);
}

static int make_double_torus(poly_mesh *m, char *err, size_t err_size)
{
    return make_holed_plate(m, 2, 1, err, err_size);
}

static int make_genus3(poly_mesh *m, char *err, size_t err_size)
{
    return make_holed_plate(m, 3, 0, err, err_size);
}

/* ---- the command --------------------------------------------------------- */

static const char *const shape_names[] = {"double-torus", "genus3", "torus", "sphere", "grid", "pair"};

static int make_shape(const char *shape, poly_mesh *m, char *err, size_t err_size)
{
    int i;
    memset(m, 0, sizeof *m);
    if (strcmp(shape, "double-torus") == 0) return make_double_torus(m, err, err_size);
    if (strcmp(shape, "genus3") == 0) return make_genus3(m, err, err_size);
    if (strcmp(shape, "torus") == 0) {
        make_torus(m, 32, 16, 1.0f, 0.4f);
    } else if (strcmp(shape, "sphere") == 0) {
        make_icosahedron(m);
        for (i = 0; i < 3; i++)
            if (subdivide_sphere(m) != 0) break;
    } else if (strcmp(shape, "grid") == 0) {
        make_grid(m, 32);
    } else if (strcmp(shape, "pair") == 0) {
        poly_mesh torus, ball;
        memset(&torus, 0, sizeof torus);
        memset(&ball, 0, sizeof ball);
        make_torus(&torus, 24, 12, 0.8f, 0.3f);
        poly_translate(&torus, -1.3f, 0.0f, 0.0f);
        make_quad_ball(&ball, 8, 0.8f);
        poly_translate(&ball, 1.3f, 0.0f, 0.0f);
        poly_append(m, &torus);
        poly_append(m, &ball);
        m->failed |= torus.failed | ball.failed;
        poly_free(&torus);
        poly_free(&ball);
    }
    if (m->failed) {
        snprintf(err, err_size, "out of memory making the %s", shape);
        return -1;
    }
    return 0;
}

/* Check the result with the library and say what it is: faces, components,
   genus, boundary loops and the valences that occur. */
static int describe_mesh(const poly_mesh *m, const char *shape, char *summary, size_t summary_size)
{
    tt_mesh *mesh;
    tt_error error;
    tt_mesh_stats stats;
    int histogram[16], v, faces_of_size[4] = {0, 0, 0, 0}, f;
    char valences[160];
    size_t used = 0;
    if (poly_build(m, &mesh, &error) != TT_OK)
        return tool_fail("internal error: the generated %s is not a valid mesh: %s", shape, error.message);
    if (tt_mesh_compute_stats(mesh, NULL, &stats, &error) != TT_OK ||
        tt_mesh_valence_histogram(mesh, NULL, histogram, (int)(sizeof histogram / sizeof histogram[0]), &error) !=
            TT_OK) {
        tt_mesh_free(mesh);
        return tool_fail("cannot check the %s: %s", shape, error.message);
    }
    valences[0] = '\0';
    for (v = 0; v < 16; v++)
        if (histogram[v] > 0 && used < sizeof valences)
            used += (size_t)snprintf(valences + used, sizeof valences - used, "%s%d%s:%d", used ? " " : "", v,
                                     v == 15 ? "+" : "", histogram[v]);
    for (f = 0; f < m->nfaces; f++) faces_of_size[m->face_size[f] == 3 ? 0 : m->face_size[f] == 4 ? 1 : 2]++;
    snprintf(summary, summary_size,
             "%s, %d vertices, %d faces (%d triangles, %d quads, %d other), %d component%s, genus %d, "
             "%d boundary loop%s, valences %s",
             shape, stats.used_vertices, m->nfaces, faces_of_size[0], faces_of_size[1], faces_of_size[2],
           stats.components, stats.components == 1 ? "" : "s", stats.genus, stats.boundary_loops,
           stats.boundary_loops == 1 ? "" : "s", valences);
    tt_mesh_free(mesh);
    return 0;
}

static int generate_mesh(int argc, char **argv)
{
    const char *path = NULL, *shape = NULL;
    int triangles = 0, i, known = 0, status = TOOL_EXIT_FAILURE;
    char err[TOOL_ERROR_SIZE], comment[200], summary[400];
    poly_mesh m, split;
    obj_write_desc desc;
    tt_mesh *built = NULL;
    tt_error error;
    float *normals = NULL;
    tool_buffer text = TOOL_BUFFER_INIT;
    tool_output output = TOOL_OUTPUT_INIT;
    for (i = 2; i < argc; i++) {
        const char *value;
        if (tool_is_help(argv[i])) {
            print_generate_help();
            return 0;
        } else if (tool_option(argc, argv, &i, "--shape", &value)) {
            if (!value) return tool_usage("--shape needs a value");
            shape = value;
        } else if (tool_flag(argv[i], "--triangles")) {
            triangles = 1;
        } else if (tool_is_option(argv[i])) {
            return tool_unknown_option(argv[i]);
        } else if (!path) {
            path = argv[i];
        } else {
            return tool_usage("too many arguments: '%s' (usage: tiledtex generate mesh OUT.obj --shape NAME)", argv[i]);
        }
    }
    if (!path) return tool_usage("needs an output file: tiledtex generate mesh OUT.obj --shape NAME");
    if (!shape)
        return tool_usage("needs --shape NAME: double-torus, genus3, torus, sphere, grid or pair");
    for (i = 0; i < (int)(sizeof shape_names / sizeof shape_names[0]); i++) known |= strcmp(shape, shape_names[i]) == 0;
    if (!known)
        return tool_usage("unknown shape '%s': choose double-torus, genus3, torus, sphere, grid or pair", shape);

    if (make_shape(shape, &m, err, sizeof err) != 0) {
        poly_free(&m);
        return tool_fail("%s", err);
    }
    if (triangles) {
        poly_triangulate(&m, &split);
        poly_free(&m);
        m = split;
        if (m.failed) {
            poly_free(&m);
            return tool_fail("out of memory making the %s", shape);
        }
    }
    if (describe_mesh(&m, shape, summary, sizeof summary) != 0) goto done;
    /* Normals per corner, as every OBJ the tool writes has them: the shapes
       are smooth, but for the grid's sheet edges (crease normals). */
    if (poly_build(&m, &built, &error) != TT_OK) {
        tool_fail("internal error: the generated %s is not a valid mesh: %s", shape, error.message);
        goto done;
    }
    if (!(normals = tool_corner_normals(path, built, NULL))) goto done;

    snprintf(comment, sizeof comment, "tiledtex generate mesh --shape %s%s\n%d vertices, %d faces", shape,
             triangles ? " --triangles" : "", m.nverts, m.nfaces);
    memset(&desc, 0, sizeof desc);
    desc.comment = comment;
    desc.nverts = m.nverts;
    desc.pos = m.pos;
    desc.nfaces = m.nfaces;
    desc.face_size = m.face_size;
    desc.corner_vert = m.corner_vert;
    desc.corner_normal = normals;
    if (obj_write(&text, &desc) != 0 || output_add_buffer(&output, path, &text) != 0) {
        tool_fail("out of memory writing %s", path);
        goto done;
    }
    if (output_commit(&output, err, sizeof err) != 0) {
        tool_fail("%s", err);
        goto done;
    }
    if (!tool_quiet()) printf("wrote %s: %s\n", path, summary);
    status = 0;
done:
    buffer_free(&text);
    output_free(&output);
    tt_mesh_free(built);
    free(normals);
    poly_free(&m);
    return status;
}

int cmd_generate(int argc, char **argv)
{
    if (argc >= 2 && tool_is_help(argv[1])) {
        print_generate_help();
        return 0;
    }
    if (argc < 2) return tool_usage("needs 'texture' or 'mesh' (see 'tiledtex generate --help')");
    if (strcmp(argv[1], "texture") == 0) return generate_texture(argc, argv);
    if (strcmp(argv[1], "mesh") == 0) return generate_mesh(argc, argv);
    return tool_usage("unknown kind '%s': choose 'texture' or 'mesh'", argv[1]);
}
