/* lapped.c - `tiledtex lapped`: texture a mesh with Praun et al.'s lapped textures.

   MESH + IMAGE -> OUT_PREFIX.obj + .mtl + .png: the pastes composited
   into one texture over the mesh's own texture coordinates or a new atlas
   (Praun et al. Sec. 4, "rendering with a texture atlas"), an ordinary
   textured mesh that every program opens; or the same as glTF.

   --pasting writes the pastes themselves instead (Sec. 4, "runtime
   pasting"): OUT_PREFIX.obj, whose faces are the pastes in order (group
   paste_N: the triangles paste N covers, with that paste's texture
   coordinates, and the material of its patch), OUT_PREFIX.mtl and the
   texture patches (straight alpha): OUT_PREFIX_patch.png when there is
   one, OUT_PREFIX_patch_K.png when there are several (--patches: windows
   of the image, so that the pastes do not all show the same part of the
   photo). Drawn in file order with alpha blending, the pastes cover the
   surface; `tiledtex render` draws such a file that way, as do engines
   that composite in order; an importer that merges or reorders the copies
   of a triangle (Blender's, assimp's) cannot, which is why the bake is
   the default. The MTL files name the textures beside them by file name,
   so the folder can move.

   The library calls, as a user of tiledtex.h makes them:

     tt_mesh_build          validate the OBJ's faces, split into triangle
                            fans here first: lapped textures work on triangles
                            (--permissive cuts bad edges open)
     tt_mesh_quadrangulate  --subdivide: the triangles quadrangulated, each
                            quad split in two again (triangle_mesh.c)
     tt_tangent_field       each face's texture "up" and scale (Sec. 3.2):
                            --up, --scale, --constraints
     tt_make_texture_patch  the image, or each window of it, with a soft splotch (or
                            --mask) alpha (Sec. 3.1)
     tt_lapped_paste        the paste loop over all the patches (Sec. 3.3 - 3.6, 4)
     tt_lapped_measure      alignment measured from the written UVs alone
     tt_uv_check,           the bake: the OBJ's own texture coordinates when they
     tt_atlas_pack_charts,  can take a bake (--bake-uv), else an atlas of
     tt_lapped_bake         charts, and the pastes composited into it
*/
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tool.h"

/* Texels between charts of a packed atlas, and of extrapolated colour around
   each chart: enough for bilinear filtering and the first mip level. */
#define LAPPED_BAKE_GUTTER 2

/* --patches: at most this many (one PNG each). */
#define LAPPED_MAX_PATCHES 256
/* Windows smaller than this many texels a side are refused: a patch needs
   room inside its soft edge (TT_DEFAULT_PATCH_FALLOFF texels) for the part
   of the photo it shows. */
#define LAPPED_MIN_WINDOW 32
/* The default cuts 4 windows when they can be at least this large; from a
   smaller image a quarter holds too little of the photo to be worth it, and
   the whole image stays the one patch. */
#define LAPPED_DEFAULT_PATCHES 4
#define LAPPED_DEFAULT_MIN_WINDOW 64
/* The default output (and every glTF) holds the pastes baked, see
   parse_command_line. Unless --bake says, the bake's side is the power of
   two whose atlas gives at least the texels per unit length that the
   pastes show (bake_uvs), from LAPPED_MIN_BAKE_SIZE up to TOOL_MAX_ATLAS;
   the atlas is expected to fill about LAPPED_EXPECTED_FILL of its square
   (a first guess: the size doubles while the atlas falls short). */
#define LAPPED_MIN_BAKE_SIZE 256
#define LAPPED_EXPECTED_FILL 0.65

static void print_help(void)
{
    printf("usage: tiledtex lapped MESH IMAGE OUT_PREFIX [options]\n"
           "\n"
           "Cover MESH with overlapping pastes of texture patches cut from IMAGE (Praun et\n"
           "al., Lapped Textures): no seams show, because every paste fades out over the ones\n"
           "beneath it. Writes the pastes baked into one texture on the mesh, which every\n"
           "program opens: OUT_PREFIX.obj, OUT_PREFIX.mtl and OUT_PREFIX.png (--bake SIZE, by\n"
           "default as sharp as the pastes; the OBJ's texture coordinates or a new atlas, see\n"
           "--bake-uv), or with --format glb or gltf (or OUT_PREFIX.glb or .gltf) the same as\n"
           "glTF.\n"
           "--pasting writes instead the pastes themselves, to composite at run time:\n"
           "OUT_PREFIX.obj (group paste_N holds the triangles of paste N with its texture\n"
           "coordinates and its patch's material; draw the groups in order with alpha blending and\n"
           "clamped texture coordinates, the alpha times each vt's third number, the paste's fade:\n"
           "0 where it had to stop short of its soft edge), OUT_PREFIX.mtl and the patches\n"
           "(straight alpha): OUT_PREFIX_patch.png when there is one, OUT_PREFIX_patch_1.png, _2,\n"
           "... when there are several (the MTL has a material lapped_K for each, naming its PNG as\n"
           "map_Kd and map_d by file name: the folder can move). 'tiledtex render OUT_PREFIX.obj\n"
           "OUT_PREFIX_patch_1.png view.png' draws each paste with the patch its material names, as\n"
           "do engines that draw the faces in file order with blending; Blender's and assimp's\n"
           "importers cannot stack copies of a triangle and show it shredded.\n"
           "Lapped textures work on triangles: faces with more than 3 corners are split into\n"
           "triangle fans first. The mesh must be manifold and consistently oriented, or use\n"
           "--permissive.\n");
    tool_print_mesh_help(1);
    printf("OUT_PREFIX is a name without extension; one ending in .obj, .mtl or .png loses it\n"
           "('out.obj' writes out.obj, not out.obj.obj); one ending in .glb writes OUT_PREFIX.glb\n"
           "(--format glb), one ending in .gltf OUT_PREFIX.gltf (--format gltf). It may be '-' (the\n"
           "standard output) only for a GLB, one file.\n"
           "\n");
    /* Two pieces: C99 compilers need only take string literals of 4095 bytes. */
    printf("options:\n"
           "  --scale X            side of one texture patch on the surface, in mesh units\n"
           "                       (default: %g of the mesh's bounding-box diagonal)\n"
           "  --seed K             random seed: patch shape, windows, paste order (default 0)\n"
           "  --patches N          cut N patches (1 to %d) from different parts of IMAGE: square\n"
           "                       windows that do not overlap, spread over the image, picked by the\n"
           "                       seed, each with the same soft shape; a paste takes the patch its\n"
           "                       neighbours show least, so a blotch or crack of the photo is not\n"
           "                       stamped like wallpaper. Default: %d when %d windows of at least\n"
           "                       %dx%d texels fit (IMAGE at least %d texels on its shorter side),\n"
           "                       else 1. --patches 1 is the whole IMAGE as one patch. --scale is\n"
           "                       the side of one patch: a window half as wide as IMAGE shows the\n"
           "                       photo twice as large as the whole image would (halve --scale to\n"
           "                       keep the photo's size)\n"
           "  --patch-size S       side of each window in texels, %d or more (default: the largest\n"
           "                       that lets the N windows fit; with --patches 1, the whole IMAGE)\n"
           "  --up DIR             the texture's up direction, projected on each face: x, y, z,\n"
           "                       -x, -y, -z or X,Y,Z (default y)\n"
           "  --constraints FILE   the texture's direction and scale at chosen faces, one per line:\n"
           "                       FACE X Y Z [SIGMA [WEIGHT]]; FACE counts the OBJ's faces from 1,\n"
           "                       X Y Z points up along the face and its length is the scale there,\n"
           "                       SIGMA (mesh units, default %g of the diagonal) is how far it\n"
           "                       reaches, WEIGHT its weight (default 1); '#' starts a comment.\n"
           "                       Directions elsewhere blend the constraints; --up is unused\n"
           "  --isotropic          the texture has no direction: each paste turns its patch at random\n"
           "  --keep-edges         each paste keeps its patch's whole soft edge (default: where it lies\n"
           "                       over what is opaque, its edge is cut where it best matches what lies\n"
           "                       beneath, and the bake blends it over a quarter of the soft edge's\n"
           "                       width, so bricks or planks run on through the overlaps, not doubled)\n",
           TT_DEFAULT_FIELD_SCALE, LAPPED_MAX_PATCHES, LAPPED_DEFAULT_PATCHES, LAPPED_DEFAULT_PATCHES,
           LAPPED_DEFAULT_MIN_WINDOW, LAPPED_DEFAULT_MIN_WINDOW, 2 * LAPPED_DEFAULT_MIN_WINDOW, LAPPED_MIN_WINDOW,
           TT_DEFAULT_FIELD_SIGMA);
    printf("  --mask MASK.png      the patches' shape: MASK's alpha, or its grey when opaque\n"
           "                       (white = inside); one shape for every patch: MASK is the size of a\n"
           "                       patch, or of IMAGE and then scaled to the patch's (default: a random\n"
           "                       splotch, or the window's own alpha when IMAGE has one)\n"
           "  --bake SIZE          the baked texture's side, 16 to %d (default: the power of two, %d\n"
           "                       to %d, whose texels per unit length on the surface are at least\n"
           "                       the pastes' (patch texels over --scale), said in the summary);\n"
           "                       with --pasting, also write the bake, as OUT_PREFIX_baked.obj/.mtl/.png\n"
           "  --bake-uv auto|mesh|atlas\n"
           "                       where the bake goes: 'mesh' over the OBJ's own texture coordinates,\n"
           "                       refused unless every corner has one, all in [0,1], no triangle\n"
           "                       flipped, none overlapping another (two triangles drawing the same\n"
           "                       texels would bake scrambled); 'atlas' over a new atlas of charts\n"
           "                       (pieces of the surface flattened, one texel density, 2 texels\n"
           "                       of gutter each); 'auto' (default) the OBJ's own when they are\n"
           "                       fit, else an atlas, with a warning saying why when the OBJ has some\n"
           "  --pasting            write the pastes, not their bake (see above); OBJ only\n"
           "  --format F           obj (default), glb (one binary glTF file, OUT_PREFIX.glb) or gltf\n"
           "                       (glTF text, OUT_PREFIX.gltf, with OUT_PREFIX.bin and PNGs beside\n"
           "                       it): the pastes baked, with the material's maps\n"
           "  --triangles          accepted for the OBJ, whose faces are triangles already\n",
           TOOL_MAX_ATLAS, LAPPED_MIN_BAKE_SIZE, TOOL_MAX_ATLAS);
    printf(MATERIAL_OPTIONS_HELP("                       ")
           "                       (here baked with the same pastes as IMAGE: OUT_PREFIX_normal.png,\n"
           "                       ..., normals turned into the atlas; with --pasting each patch's\n"
           "                       window of each map, OUT_PREFIX_patch_1_normal.png, ..., and with\n"
           "                       --bake too OUT_PREFIX_baked_normal.png, ...)\n");
    printf("  --subdivide L        make the triangles smaller before pasting, L from 0 to 8 (default\n"
           "                       0): quadrangulate them L times, as 'tiledtex tile' does, and split\n"
           "                       every quad into two triangles, so a triangle becomes 6, 24, 96, ...\n"
           "                       (the outputs have these). A paste covers whole triangles: subdivide\n"
           "                       a coarse mesh when --scale is not several faces wide\n"
           "  --smooth             Catmull-Clark positions when subdividing (rounder, a little smaller)\n"
           "  --permissive         accept non-manifold or mis-oriented edges (an edge shared by three\n"
           "                       faces, as some exports have): they are cut open into boundaries\n"
           "\n"
           "Prints the number of pastes, the coverage, how often a face is drawn (overdraw), how\n"
           "well the texture follows the field (angle and scale error), the hard edges (where the\n"
           "paste on top stops while still at least 25%% opaque), the ghosting (the share of points\n"
           "where two pastes that differ each make at least 20%% of the colour: courses seen through\n"
           "each other), how many face entries hidden\n"
           "by later pastes were dropped, and how many pastes each patch got; of the bake, the\n"
           "baked texture's seam score (about 0: the texture continues across edges; about 1: it\n"
           "jumps) over every edge and over the edges where the paste on top changes.\n"
           "\n"
           "example: tiledtex generate mesh torus.obj --shape torus\n"
           "         tiledtex generate texture stones.png --size 128\n"
           "         tiledtex lapped torus.obj stones.png torus_lapped --scale 1.5\n"
           "         tiledtex render torus_lapped.obj torus_lapped.png view.png\n");
}

/* --bake-uv: where the bake goes. */
typedef enum bake_uv_choice { BAKE_UV_AUTO = 0, BAKE_UV_MESH, BAKE_UV_ATLAS } bake_uv_choice;

typedef struct lapped_options {
    const char *mesh_path, *image_path;
    char prefix[TOOL_PREFIX_SIZE];  /* OUT_PREFIX without a known extension */
    float scale;                    /* 0 = the library's default */
    uint64_t seed;
    tool_field field;               /* --up, --constraints */
    int isotropic;
    int keep_edges;
    const char *mask_path;          /* or NULL */
    int npatches;                   /* --patches N; 0 = the default (choose_windows) */
    int patch_size;                 /* --patch-size S in texels; 0 = the default */
    int pasting;                    /* --pasting: the pasting OBJ and its patches */
    int bake_size;                  /* 0 = no bake (only with --pasting) */
    int bake_auto;                  /* no --bake: bake_uvs chooses bake_size */
    char baked_stem[TOOL_PREFIX_SIZE + 8]; /* the baked files' names without extension */
    bake_uv_choice bake_uv;         /* --bake-uv */
    tool_mesh_options mesh;         /* --subdivide, --smooth, --permissive */
    material_maps maps;             /* --normal ...: the material's other maps, pasted alike */
    tool_mesh_output output;        /* --format, --triangles */
} lapped_options;

/* Returns -1 to go on, or the exit status to return now. */
static int parse_command_line(int argc, char **argv, lapped_options *options)
{
    const char *positional[3];
    int npositional = 0, i;
    memset(options, 0, sizeof *options);
    for (i = 1; i < argc; i++) {
        const char *value;
        double number;
        int taken;
        if (tool_is_help(argv[i])) {
            print_help();
            return 0;
        } else if ((taken = parse_mesh_option(argc, argv, &i, &options->mesh)) != 0) {
            if (taken < 0) return TOOL_EXIT_USAGE;
        } else if ((taken = parse_mesh_output_option(argc, argv, &i, 1, &options->output)) != 0) {
            if (taken < 0) return TOOL_EXIT_USAGE;
        } else if (tool_option(argc, argv, &i, "--scale", &value)) {
            if (!value) return tool_usage("--scale needs a value");
            if (parse_whole_double(value, &number) != 0 || !(number > 0.0) || number > 1e30)
                return tool_usage("--scale wants a patch size above 0 (in mesh units), got '%s'", value);
            options->scale = (float)number;
        } else if (tool_option(argc, argv, &i, "--seed", &value)) {
            if (parse_u64("--seed", value, &options->seed) != 0) return TOOL_EXIT_USAGE;
        } else if ((taken = parse_field_option(argc, argv, &i, &options->field)) != 0) {
            if (taken < 0) return TOOL_EXIT_USAGE;
        } else if (tool_option(argc, argv, &i, "--mask", &value)) {
            if (!value) return tool_usage("--mask needs a value");
            options->mask_path = value;
        } else if (tool_option(argc, argv, &i, "--patches", &value)) {
            if (parse_int("--patches", value, 1, LAPPED_MAX_PATCHES, &options->npatches) != 0) return TOOL_EXIT_USAGE;
        } else if (tool_option(argc, argv, &i, "--patch-size", &value)) {
            if (parse_int("--patch-size", value, LAPPED_MIN_WINDOW, TT_MAX_IMAGE_SIZE, &options->patch_size) != 0)
                return TOOL_EXIT_USAGE;
        } else if (tool_option(argc, argv, &i, "--bake", &value)) {
            if (parse_int("--bake", value, 16, TOOL_MAX_ATLAS, &options->bake_size) != 0) return TOOL_EXIT_USAGE;
        } else if (tool_option(argc, argv, &i, "--bake-uv", &value)) {
            if (!value) return tool_usage("--bake-uv needs a value: auto, mesh or atlas");
            if (strcmp(value, "auto") == 0) options->bake_uv = BAKE_UV_AUTO;
            else if (strcmp(value, "mesh") == 0) options->bake_uv = BAKE_UV_MESH;
            else if (strcmp(value, "atlas") == 0) options->bake_uv = BAKE_UV_ATLAS;
            else return tool_usage("--bake-uv wants auto, mesh or atlas, got '%s'", value);
        } else if (tool_flag(argv[i], "--isotropic")) {
            options->isotropic = 1;
        } else if (tool_flag(argv[i], "--keep-edges")) {
            options->keep_edges = 1;
        } else if (tool_flag(argv[i], "--pasting")) {
            options->pasting = 1;
        } else if ((taken = material_parse_option(argc, argv, &i, &options->maps)) != 0) {
            if (taken < 0) return TOOL_EXIT_USAGE;
        } else if (tool_is_option(argv[i])) {
            return tool_unknown_option(argv[i]);
        } else if (npositional < 3) {
            positional[npositional++] = argv[i];
        } else {
            npositional++; /* counted, to say there are too many */
        }
    }
    if (tool_mesh_image_prefix(positional, npositional, &options->mesh_path, &options->image_path,
                               &options->output, options->prefix) != 0)
        return TOOL_EXIT_USAGE;
    /* Only this tool's renderer and engines that draw the faces in file
       order with blending show the pasting OBJ right (Blender's and
       assimp's importers merge or shred the stacked copies of a triangle),
       so what is written unless --pasting asks, and every glTF, holds the
       pastes baked into one texture. */
    if (options->pasting && options->output.format != TOOL_FORMAT_OBJ)
        return tool_usage("--pasting writes the pasting OBJ; a glTF file holds the pastes baked (leave out --pasting, "
                          "or write OUT_PREFIX.obj)");
    if (!options->pasting && options->bake_size == 0) {
        options->bake_size = LAPPED_MIN_BAKE_SIZE;
        options->bake_auto = 1;
    }
    snprintf(options->baked_stem, sizeof options->baked_stem, "%s%s", options->prefix,
             options->pasting ? "_baked" : "");
    return -1;
}

/* ======================================================================== */
/* The texture patch                                                        */
/* ======================================================================== */

/* Where the patches come from: `count` square windows of `size` texels,
   the k-th with its top-left texel at (x[k], y[k]); or, with size 0, the
   whole image as the one patch (what the tool did before it cut windows,
   kept exactly). */
typedef struct patch_windows {
    int count, size;
    int x[LAPPED_MAX_PATCHES], y[LAPPED_MAX_PATCHES];
} patch_windows;

static int windows_that_fit(int width, int height, int size)
{
    return (width / size) * (height / size);
}

/* The largest window side at which `count` windows fit without
   overlapping; 0 when not even 1-texel windows do. */
static int largest_window(int width, int height, int count)
{
    int size = width < height ? width : height;
    while (size > 0 && windows_that_fit(width, height, size) < count) size--;
    return size;
}

/* Place the windows: the image holds a grid of cols x rows cells of the
   window's size, spread evenly from edge to edge (so that they do not
   overlap and together reach every part of it); the first window takes a
   cell at random, and each next the cell farthest from those taken (the
   first of equals in a seeded order), so that few windows still come from
   far-apart parts of the photo. Returns 0, or -1 when out of memory. */
static int place_windows(int width, int height, uint64_t seed, patch_windows *windows)
{
    const int size = windows->size, cols = width / size, rows = height / size, ncells = cols * rows;
    int *order = (int *)malloc((size_t)ncells * sizeof(int));
    double *nearest = (double *)malloc((size_t)ncells * sizeof(double));     /* squared distance to the taken */
    tt_rng rng;
    int i, k;
    if (!order || !nearest) {
        free(order);
        free(nearest);
        return -1;
    }
    tt_rng_seed(&rng, seed, 0x77196);
    for (i = 0; i < ncells; i++) {
        int j = (int)tt_rng_below(&rng, (uint32_t)i + 1u);
        order[i] = order[j];
        order[j] = i;
        nearest[i] = HUGE_VAL;
    }
    for (k = 0; k < windows->count; k++) {
        int best = -1, cell;
        for (i = 0; i < ncells; i++)
            if (nearest[i] > 0.0 && (best < 0 || nearest[i] > nearest[best])) best = i;
        cell = order[best];
        windows->x[k] = cols > 1 ? (int)((long long)(cell % cols) * (width - size) / (cols - 1)) : (width - size) / 2;
        windows->y[k] = rows > 1 ? (int)((long long)(cell / cols) * (height - size) / (rows - 1)) : (height - size) / 2;
        for (i = 0; i < ncells; i++) {
            double dx = (double)(order[i] % cols - cell % cols), dy = (double)(order[i] / cols - cell / cols);
            if (dx * dx + dy * dy < nearest[i]) nearest[i] = dx * dx + dy * dy;
        }
    }
    free(order);
    free(nearest);
    return 0;
}

/* How many patches, of what size, from where: --patches and --patch-size,
   or their defaults (see the help). Returns 0, or the exit status after
   printing why the windows do not fit the image. */
static int choose_windows(const lapped_options *options, int width, int height, patch_windows *windows)
{
    int count = options->npatches, size = options->patch_size;
    if (count == 0 && size == 0) {
        size = largest_window(width, height, LAPPED_DEFAULT_PATCHES);
        count = size >= LAPPED_DEFAULT_MIN_WINDOW ? LAPPED_DEFAULT_PATCHES : 1;
        if (count == 1) size = 0;
    } else if (count == 0) {
        count = size <= width && size <= height && windows_that_fit(width, height, size) >= LAPPED_DEFAULT_PATCHES
                    ? LAPPED_DEFAULT_PATCHES : 1;
    } else if (count > 1 && size == 0) {
        size = largest_window(width, height, count);
        if (size < LAPPED_MIN_WINDOW)
            return tool_fail("--patches %d: %d windows fit in %s (%dx%d) only at %dx%d texels, below the least "
                             "patch of %dx%d: use fewer patches", count, count, options->image_path, width,
                             height, size, size, LAPPED_MIN_WINDOW, LAPPED_MIN_WINDOW);
    }
    windows->count = count;
    windows->size = size;
    if (size == 0) {
        windows->x[0] = windows->y[0] = 0;
        return 0;
    }
    if (size > width || size > height)
        return tool_fail("--patch-size %d: %s is only %dx%d texels", size, options->image_path, width, height);
    if (windows_that_fit(width, height, size) < count)
        return tool_fail("--patches %d: only %d window%s of %dx%d texels fit%s in %s (%dx%d) without overlapping: "
                         "use fewer patches or a smaller --patch-size", count, windows_that_fit(width, height, size),
                         windows_that_fit(width, height, size) == 1 ? "" : "s", size, size,
                         windows_that_fit(width, height, size) == 1 ? "s" : "", options->image_path, width, height);
    if (place_windows(width, height, options->seed, windows) != 0)
        return tool_fail("out of memory while placing the patches in %s", options->image_path);
    return 0;
}

/* The --mask image, read once for every patch, at the patches' size: a
   mask of the image's size is scaled to a window's (nearest texel: it is a
   shape, cut at one half by tt_make_texture_patch). NULL without --mask. */
static int load_mask(const lapped_options *options, int width, int height, const patch_windows *windows,
                     tt_image **mask)
{
    char message[TOOL_ERROR_SIZE];
    const int size = windows->size;
    tt_image *scaled;
    int x, y;
    *mask = NULL;
    if (!options->mask_path) return 0;
    /* A mask is data, not colour: its bytes are read as they are
       (TT_COLOR_LINEAR), so grey 128 and up is inside, as the help says. */
    if (image_load(options->mask_path, TT_COLOR_LINEAR, mask, message, sizeof message) != 0)
        return tool_fail("--mask: %s", message);
    /* The whole image as the patch: tt_make_texture_patch says it when the
       sizes differ, as it always did. */
    if (size == 0 || ((*mask)->width == size && (*mask)->height == size)) return 0;
    if ((*mask)->width != width || (*mask)->height != height) {
        int status = tool_fail("--mask %s is %dx%d: a mask must be the size of a patch (%dx%d) or of %s (%dx%d)",
                               options->mask_path, (*mask)->width, (*mask)->height, size, size,
                               options->image_path, width, height);
        image_free(*mask);
        *mask = NULL;
        return status;
    }
    /* A tool image of the patch's size (its texels are all set below). */
    if (image_crop(*mask, 0, 0, size, size, &scaled) != 0) {
        image_free(*mask);
        *mask = NULL;
        return tool_fail("out of memory for the mask %s", options->mask_path);
    }
    for (y = 0; y < size; y++)
        for (x = 0; x < size; x++) {
            int from_x = (int)(((long long)x * 2 + 1) * width / (2 * size));
            int from_y = (int)(((long long)y * 2 + 1) * height / (2 * size));
            memcpy(scaled->pixels + 4 * ((size_t)y * size + x),
                   (*mask)->pixels + 4 * ((size_t)from_y * width + from_x), 4 * sizeof(float));
        }
    image_free(*mask);
    *mask = scaled;
    return 0;
}

static int make_patch(const lapped_options *options, const tt_image *source, const tt_image *mask, tt_image **patch)
{
    tt_patch_options patch_options;
    tt_error error;
    *patch = NULL;
    /* One seed for every window: windows of one size get one splotch, and
       the paste loop takes them for interchangeable twins. */
    memset(&patch_options, 0, sizeof patch_options);
    patch_options.seed = options->seed;
    if (tt_make_texture_patch(source, mask, &patch_options, NULL, patch, &error) != TT_OK)
        return tool_fail("%s: %s", options->mask_path ? options->mask_path : options->image_path, error.message);
    return 0;
}

/* The patch as a PNG wants straight alpha. Where alpha > 0 that is the
   premultiplied patch divided by its alpha, which is the image's own colour;
   taking the image's colour everywhere also keeps real colours under alpha 0,
   so a viewer that filters straight-alpha textures shows no dark fringes.
   So the image itself becomes the straight patch: its alpha is replaced by
   the patch's, in place (the image is not used afterwards), and it is
   encoded as sRGB colour with linear alpha, as PNG wants it, into its own
   pixels (tt_image_to_rgba8 may write over the floats it reads): no second
   buffer, and the photo is gone (*image = NULL) before the PNG is
   compressed. */
static int add_patch_png(tool_output *output, const char *path, tt_image **image, const tt_image *patch)
{
    char message[TOOL_ERROR_SIZE];
    int width = (*image)->width, height = (*image)->height, status;
    size_t i, n = (size_t)width * (size_t)height;
    unsigned char *rgba = (unsigned char *)(*image)->pixels, *shorter;
    for (i = 0; i < n; i++) (*image)->pixels[4 * i + 3] = patch->pixels[4 * i + 3];
    tt_image_to_rgba8(*image, TT_COLOR_SRGB, rgba);
    (*image)->pixels = NULL;
    image_free(*image);
    *image = NULL;
    /* The bytes fill the first quarter of the old float buffer: give the
       rest back before compressing. */
    if ((shorter = (unsigned char *)realloc(rgba, n * 4)) != NULL) rgba = shorter;
    status = output_add_png_rgba8(output, path, rgba, width, height, message, sizeof message);
    free(rgba);
    return status != 0 ? tool_fail("%s", message) : 0;
}

/* The texture patches and what the outputs call them. */
typedef struct lapped_patches {
    int count;
    int size;               /* window side in texels; 0 = the whole image */
    tt_image **images;      /* count patches (premultiplied), NULL until made */
    char **png_paths;       /* OUT_PREFIX_patch.png for one, else OUT_PREFIX_patch_K.png, K from 1 */
    char **materials;       /* "lapped" for one, else "lapped_K" */
    /* The material's other maps: patch k's window of map m is written as
       map_png_paths[k * MATERIAL_MAPS + m] (its PNG name with _normal, ...;
       NULL for a map not given), and with --bake kept, premultiplied by
       patch k's alpha, as map_images[k * MATERIAL_MAPS + m]. */
    char **map_png_paths;
    tt_image **map_images;
} lapped_patches;

static void lapped_patches_free(lapped_patches *patches)
{
    int k;
    for (k = 0; k < patches->count; k++) {
        if (patches->images) tt_image_free(patches->images[k]);
        if (patches->png_paths) free(patches->png_paths[k]);
        if (patches->materials) free(patches->materials[k]);
    }
    for (k = 0; k < patches->count * MATERIAL_MAPS; k++) {
        if (patches->map_png_paths) free(patches->map_png_paths[k]);
        if (patches->map_images) tt_image_free(patches->map_images[k]);
    }
    free(patches->images);
    free(patches->png_paths);
    free(patches->materials);
    free(patches->map_png_paths);
    free(patches->map_images);
    memset(patches, 0, sizeof *patches);
}

/* The names, before anything is made: the paths are checked against the
   inputs before the long part. One patch keeps the names it always had. */
static int lapped_patches_name(const char *prefix, const patch_windows *windows, const material_maps *maps,
                               lapped_patches *patches)
{
    const size_t path_size = strlen(prefix) + 48;
    int k, map;
    memset(patches, 0, sizeof *patches);
    patches->images = (tt_image **)calloc((size_t)windows->count, sizeof(tt_image *));
    patches->png_paths = (char **)calloc((size_t)windows->count, sizeof(char *));
    patches->materials = (char **)calloc((size_t)windows->count, sizeof(char *));
    patches->map_png_paths = (char **)calloc((size_t)windows->count * MATERIAL_MAPS, sizeof(char *));
    patches->map_images = (tt_image **)calloc((size_t)windows->count * MATERIAL_MAPS, sizeof(tt_image *));
    if (!patches->images || !patches->png_paths || !patches->materials || !patches->map_png_paths ||
        !patches->map_images) {
        lapped_patches_free(patches);
        return tool_fail("out of memory for the patches' names");
    }
    patches->count = windows->count;
    patches->size = windows->size;
    for (k = 0; k < patches->count; k++) {
        patches->png_paths[k] = (char *)malloc(path_size);
        patches->materials[k] = (char *)malloc(32);
        if (!patches->png_paths[k] || !patches->materials[k]) {
            lapped_patches_free(patches);
            return tool_fail("out of memory for the patches' names");
        }
        if (patches->count == 1) {
            snprintf(patches->png_paths[k], path_size, "%s_patch.png", prefix);
            snprintf(patches->materials[k], 32, "lapped");
        } else {
            snprintf(patches->png_paths[k], path_size, "%s_patch_%d.png", prefix, k + 1);
            snprintf(patches->materials[k], 32, "lapped_%d", k + 1);
        }
        for (map = 0; map < MATERIAL_MAPS; map++) {
            char **path = &patches->map_png_paths[k * MATERIAL_MAPS + map];
            if (!maps->paths[map]) continue;
            if (!(*path = (char *)malloc(path_size))) {
                lapped_patches_free(patches);
                return tool_fail("out of memory for the patches' names");
            }
            /* beside the patch's PNG: OUT_PREFIX_patch_K_normal.png */
            snprintf(*path, path_size, "%.*s_%s.png", (int)(strlen(patches->png_paths[k]) - 4),
                     patches->png_paths[k], material_map_names[map]);
        }
    }
    return 0;
}

/* Each patch's window of each map: its PNG (the map as it is, opaque: the
   colour patch's alpha shows where it lies; none when output is NULL) and,
   for --bake, the window premultiplied by the colour patch's alpha, so that
   every map is composited exactly where and as much as the colour is. Frees
   the maps. */
static int make_map_patches(const lapped_options *options, material_maps *maps, const patch_windows *windows,
                            tool_output *output, lapped_patches *patches)
{
    int k, map, status = 0;
    for (map = 0; map < MATERIAL_MAPS && status == 0; map++) {
        const tt_image *image = maps->images[map];
        if (!image) continue;
        for (k = 0; k < patches->count && status == 0; k++) {
            const tt_image *alpha = patches->images[k];
            tt_image *window = NULL, *patch = NULL;
            size_t i, count;
            tt_error error;
            if (windows->size > 0 &&
                image_crop(image, windows->x[k], windows->y[k], windows->size, windows->size, &window) != 0)
                status = tool_fail("out of memory for patch %d of %s", k + 1, maps->paths[map]);
            else if (output)
                status = output_add_map_png(output, patches->map_png_paths[k * MATERIAL_MAPS + map], map,
                                            window ? window : image);
            if (status == 0 && options->bake_size > 0) {
                const tt_image *source = window ? window : image;
                if (tt_image_create(source->width, source->height, NULL, &patch, &error) != TT_OK) {
                    status = tool_fail("%s: %s", maps->paths[map], error.message);
                } else {
                    patch->kind = source->kind;
                    count = (size_t)source->width * (size_t)source->height;
                    for (i = 0; i < count; i++) {
                        float a = alpha->pixels[4 * i + 3];
                        patch->pixels[4 * i] = source->pixels[4 * i] * a;
                        patch->pixels[4 * i + 1] = source->pixels[4 * i + 1] * a;
                        patch->pixels[4 * i + 2] = source->pixels[4 * i + 2] * a;
                        patch->pixels[4 * i + 3] = a;
                    }
                    patches->map_images[k * MATERIAL_MAPS + map] = patch;
                }
            }
            image_free(window);
        }
    }
    material_free(maps);
    return status;
}

/* Each window of *image made a patch, and its PNG added to the output
   (none when output is NULL: a GLB holds only the baked result); the image
   is freed here (*image = NULL). The whole image as the one patch becomes
   the PNG in its own memory (add_patch_png); a window is copied out first,
   and that copy becomes the PNG. */
static int make_patches(const lapped_options *options, tt_image **image, const patch_windows *windows,
                        const tt_image *mask, tool_output *output, lapped_patches *patches)
{
    int k, status = 0;
    if (windows->size == 0) {
        status = make_patch(options, *image, mask, &patches->images[0]);
        if (status == 0 && output) status = add_patch_png(output, patches->png_paths[0], image, patches->images[0]);
    } else {
        for (k = 0; k < windows->count && status == 0; k++) {
            tt_image *window;
            if (image_crop(*image, windows->x[k], windows->y[k], windows->size, windows->size, &window) != 0) {
                status = tool_fail("out of memory for patch %d of %s", k + 1, options->image_path);
                break;
            }
            status = make_patch(options, window, mask, &patches->images[k]);
            if (status == 0 && output)
                status = add_patch_png(output, patches->png_paths[k], &window, patches->images[k]);
            image_free(window);
        }
    }
    image_free(*image);
    *image = NULL;
    return status;
}

/* ======================================================================== */
/* Output files                                                             */
/* ======================================================================== */

/* OUT_PREFIX.obj: the vertices, then paste after paste a group "paste_N"
   (N counts the pastes from 1) with its triangles and their texture
   coordinates in the patch. A paste whose faces were all hidden has none. */
static int add_pasting_obj(tool_output *output, const char *path, const char *mtl_name, const triangle_mesh *m,
                           const tt_lapped *lapped, const lapped_patches *patches)
{
    const tt_mesh *mesh = m->mesh;
    int *corner_vert = (int *)malloc((size_t)lapped->nentries * 3 * sizeof(int));
    float *corner_uv = (float *)malloc((size_t)lapped->nentries * 6 * sizeof(float));
    float *corner_normal = (float *)malloc((size_t)lapped->nentries * 9 * sizeof(float));
    float *mesh_normals = tool_corner_normals(path, m->mesh, m->corner_normal);
    int *face_group = (int *)malloc((size_t)lapped->nentries * sizeof(int));
    char **names = (char **)calloc((size_t)lapped->npastes + 1, sizeof(char *));
    const char **materials = (const char **)calloc((size_t)lapped->npastes + 1, sizeof(char *));
    char comment[512];
    tool_buffer text;
    obj_write_desc desc;
    int p, n = 0, status = 0;

    memset(&text, 0, sizeof text);
    if (!mesh_normals) {
        status = TOOL_EXIT_FAILURE;
        goto done;
    }
    if (!corner_vert || !corner_uv || !corner_normal || !face_group || !names || !materials) goto out_of_memory;
    for (p = 0; p < lapped->npastes; p++) {
        const tt_paste *paste = &lapped->pastes[p];
        int e, k;
        names[p] = (char *)malloc(24);
        if (!names[p]) goto out_of_memory;
        snprintf(names[p], 24, "paste_%d", p + 1);
        materials[p] = patches->materials[paste->patch];
        for (e = paste->first; e < paste->first + paste->nfaces; e++, n++) {
            int face = lapped->faces[e];
            for (k = 0; k < 3; k++) corner_vert[3 * n + k] = mesh->corner_vert[mesh->face_start[face] + k];
            memcpy(corner_uv + 6 * n, lapped->uv + 6 * (size_t)e, 6 * sizeof(float));
            memcpy(corner_normal + 9 * n, mesh_normals + 3 * (size_t)mesh->face_start[face], 9 * sizeof(float));
            face_group[n] = p;
        }
    }
    snprintf(comment, sizeof comment,
             "lapped texture by tiledtex %s (Praun et al.): %d pastes over %d triangles%s\n"
             "draw the groups in order, each blended over the ones before through the patch's alpha\n"
             "times the fade, each vt's third number (0 where a paste had to stop short of its soft\n"
             "edge), with texture coordinates clamped (outside [0,1] is transparent)",
             TILEDTEX_VERSION_STRING, lapped->npastes, mesh->nfaces,
             patches->count > 1 ? ", each with its patch's material" : "");
    memset(&desc, 0, sizeof desc);
    desc.comment = comment;
    desc.nverts = mesh->nverts;
    desc.pos = mesh->pos;
    desc.nfaces = n;
    desc.fixed_face_size = 3;
    desc.corner_vert = corner_vert;
    desc.corner_uv = corner_uv;
    desc.corner_uv_w = lapped->fade;   /* entries are written in order: entry e is OBJ face e */
    desc.corner_normal = corner_normal;
    /* A vertex takes one UV per paste and one smooth normal: each distinct
       vt and vn once (the horse: 237k vt and 49k vn lines for the 909k
       corners of its entries, one of each per corner before). */
    desc.share_equal = 1;
    desc.mtllib = mtl_name;
    desc.material = patches->materials[0];
    desc.face_group = face_group;
    desc.ngroups = lapped->npastes;
    desc.group_names = (const char *const *)names;
    /* One patch: one usemtl for the whole file, as before there were several. */
    if (patches->count > 1) desc.group_materials = materials;
    if (obj_write(&text, &desc) != 0 || output_add_buffer(output, path, &text) != 0) goto out_of_memory;
    goto done;
out_of_memory:
    status = tool_fail("out of memory while writing %s", path);
done:
    buffer_free(&text);
    if (names)
        for (p = 0; p < lapped->npastes; p++) free(names[p]);
    free(names);
    free(materials);
    free(corner_vert);
    free(corner_uv);
    free(corner_normal);
    free(mesh_normals);
    free(face_group);
    return status;
}

/* A colour image (straight alpha) as sRGB bytes; the image is freed as
   soon as it is converted, before the PNG is compressed. */
static int add_png(tool_output *output, const char *path, tt_image *image)
{
    char message[TOOL_ERROR_SIZE];
    int width = image->width, height = image->height, status;
    unsigned char *rgba = (unsigned char *)malloc((size_t)width * (size_t)height * 4);
    if (!rgba) {
        tt_image_free(image);
        return tool_fail("out of memory while encoding %s", path);
    }
    image_to_rgba8(image, TT_COLOR_SRGB, rgba);
    tt_image_free(image);
    status = output_add_png_rgba8(output, path, rgba, width, height, message, sizeof message);
    free(rgba);
    return status != 0 ? tool_fail("%s", message) : 0;
}

/* Why the OBJ's texture coordinates cannot take a bake, as the end of a
   sentence about them ("its texture coordinates ..."), with the OBJ's face
   numbers (from 1); "" when they can. */
static void describe_uv_problem(const triangle_mesh *m, const tt_uv_report *report, char *text, size_t size)
{
    int face = report->face >= 0 ? m->face[report->face] + 1 : 0;
    int other = report->other_face >= 0 ? m->face[report->other_face] + 1 : 0;
    text[0] = '\0';
    switch (report->problem) {
    case TT_UV_USABLE: break;
    case TT_UV_NON_FINITE: snprintf(text, size, "are not finite numbers (face %d)", face); break;
    case TT_UV_OUTSIDE: snprintf(text, size, "reach outside [0,1] (face %d): they repeat the texture", face); break;
    case TT_UV_DEGENERATE: snprintf(text, size, "give face %d no area in the texture", face); break;
    case TT_UV_FLIPPED:
        snprintf(text, size, "are mirrored on %d triangle%s (face %d first)", report->flipped_faces,
                 report->flipped_faces == 1 ? "" : "s", face);
        break;
    case TT_UV_OVERLAP:
        if (face == other) snprintf(text, size, "overlap within face %d (its triangle fan folds)", face);
        else snprintf(text, size, "overlap (faces %d and %d)", face, other);
        break;
    }
}

/* What the summary says of the bake's atlas. */
typedef struct bake_atlas {
    int charts;                 /* charts of the new atlas; 0 over the OBJ's own texture coordinates */
    double fill;                /* the share of the atlas the triangles cover */
    double density_spread;      /* texel density, area-weighted 95th percentile over 5th */
    double texels_per_unit;     /* the atlas's texels per mesh unit of length */
    double paste_texels;        /* the pastes': patch texels over the patch's side on the surface */
} bake_atlas;

/* The texels per mesh unit of length that the pastes show: the patch's
   side in texels over the patch's side on the surface (the field's
   length), as the root mean square over the surface, so that an atlas at
   this density holds as many texels as the pastes spread over it.
   *surface gets the mesh's area. 0 for a mesh without area. */
static double paste_texel_density(const triangle_mesh *m, const float *field, int patch_texels, double *surface)
{
    const tt_mesh *mesh = m->mesh;
    double texels = 0.0;
    int f, k;
    *surface = 0.0;
    for (f = 0; f < mesh->nfaces; f++) {
        const float *v = field + 3 * (size_t)f;
        const float *p[3];
        double e1[3], e2[3], area, length2 = (double)v[0] * v[0] + (double)v[1] * v[1] + (double)v[2] * v[2];
        for (k = 0; k < 3; k++) p[k] = mesh->pos + 3 * (size_t)mesh->corner_vert[mesh->face_start[f] + k];
        for (k = 0; k < 3; k++) {
            e1[k] = (double)p[1][k] - p[0][k];
            e2[k] = (double)p[2][k] - p[0][k];
        }
        area = 0.5 * sqrt((e1[1] * e2[2] - e1[2] * e2[1]) * (e1[1] * e2[2] - e1[2] * e2[1]) +
                          (e1[2] * e2[0] - e1[0] * e2[2]) * (e1[2] * e2[0] - e1[0] * e2[2]) +
                          (e1[0] * e2[1] - e1[1] * e2[0]) * (e1[0] * e2[1] - e1[1] * e2[0]));
        *surface += area;
        if (length2 > 0.0) texels += area * (double)patch_texels * patch_texels / length2;
    }
    return *surface > 0.0 ? sqrt(texels / *surface) : 0.0;
}

/* --bake's texture coordinates per triangle corner, as --bake-uv chooses:
   the OBJ's own when they can take a bake (tt_uv_check), else an atlas of
   charts; *atlas says which and how well it fills. Without --bake the
   atlas's side is chosen here: the smallest power of two whose atlas
   gives at least the pastes' texels per unit length, up to TOOL_MAX_ATLAS
   (said when it falls short there). Made before anything is pasted, so a
   size too small for the mesh, or UVs --bake-uv mesh refuses, are said at
   once. */
static int bake_uvs(lapped_options *options, const triangle_mesh *m, const float *field, int patch_texels,
                    float **corner_uv, bake_atlas *atlas)
{
    const size_t ncorners = 3 * (size_t)m->ntriangles;
    char problem[160] = "have none at some corners";
    tt_chart_atlas_report report;
    tt_chart_pack_options pack;
    tool_progress progress;
    tt_uv_distortion_report distortion;
    tt_uv_report check;
    tt_error error;
    double surface;
    memset(atlas, 0, sizeof *atlas);
    atlas->paste_texels = paste_texel_density(m, field, patch_texels, &surface);
    if (options->bake_uv != BAKE_UV_ATLAS && m->corner_uv) {
        if (tt_uv_check(m->mesh, m->corner_uv, NULL, &check, &error) != TT_OK)
            return tool_fail("%s: cannot check its texture coordinates: %s", options->mesh_path, error.message);
        describe_uv_problem(m, &check, problem, sizeof problem);
    }
    if (options->bake_uv == BAKE_UV_MESH && problem[0])
        return tool_fail("--bake-uv mesh: %s: its texture coordinates %s, and baking over them would scramble the "
                         "texture (--bake-uv atlas makes a new atlas)",
                         options->mesh_path, problem);
    *corner_uv = (float *)malloc(ncorners * 2 * sizeof(float));
    if (!*corner_uv) return tool_fail("out of memory for the texture coordinates of %s", options->mesh_path);
    if (options->bake_uv != BAKE_UV_ATLAS && !problem[0]) {
        memcpy(*corner_uv, m->corner_uv, ncorners * 2 * sizeof(float));
    } else {
        if (options->bake_auto) {
            /* A first guess from the surface's area, then doubled while the
               packed atlas falls short of the pastes' density. */
            double side = atlas->paste_texels * sqrt(surface / LAPPED_EXPECTED_FILL);
            while (options->bake_size < TOOL_MAX_ATLAS && options->bake_size < side) options->bake_size *= 2;
        }
        /* Cancellable (Ctrl-C); a doubled side starts from the fill the
           last packing reached, which changes little with the side. */
        tool_progress_begin(&progress, "packing the bake's atlas", "of the search");
        memset(&pack, 0, sizeof pack);
        pack.progress = tool_show_progress;
        pack.progress_user_data = &progress;
        pack.executor = tool_executor();
        for (;;) {
            tt_result packed = tt_atlas_pack_charts(m->mesh, options->bake_size, LAPPED_BAKE_GUTTER, &pack, NULL,
                                                    *corner_uv, &report, &error);
            if (packed == TT_OK) pack.fill_guess = report.fill;
            if (packed != TT_OK) {
                if (options->bake_auto && error.result == TT_ERROR_IMAGE_TOO_SMALL &&
                    options->bake_size < TOOL_MAX_ATLAS) {
                    options->bake_size *= 2;
                    continue;
                }
                tool_progress_end(&progress);
                free(*corner_uv);
                *corner_uv = NULL;
                return tool_fail("--bake %d: %s", options->bake_size, error.message);
            }
            if (!options->bake_auto || report.texels_per_unit >= atlas->paste_texels ||
                options->bake_size >= TOOL_MAX_ATLAS)
                break;
            options->bake_size *= 2;
        }
        tool_progress_end(&progress);
        atlas->charts = report.ncharts;
        atlas->fill = report.fill;
        /* Only an OBJ that has texture coordinates was asked for them. */
        if (options->bake_uv == BAKE_UV_AUTO && m->corner_uv)
            tool_note("%s: its texture coordinates %s; baking over a new atlas", options->mesh_path, problem);
    }
    if (tt_measure_uv_distortion(m->mesh, *corner_uv, options->bake_size, options->bake_size, NULL, NULL,
                                 &distortion, &error) == TT_OK) {
        atlas->density_spread = distortion.density_spread;
        atlas->texels_per_unit = distortion.texels_per_unit;
    }
    /* The OBJ's own coordinates: their density grows with the side. */
    if (options->bake_auto && atlas->charts == 0 && atlas->texels_per_unit > 0.0) {
        double side = options->bake_size * atlas->paste_texels / atlas->texels_per_unit;
        int size = options->bake_size;
        while (size < TOOL_MAX_ATLAS && size < side) size *= 2;
        atlas->texels_per_unit *= (double)size / options->bake_size;
        options->bake_size = size;
    }
    return 0;
}

/* What the summary says of the bake. */
typedef struct baked_summary {
    tool_seams all;             /* every interior edge */
    tool_seams top_changes;     /* the edges where the paste on top changes */
    double seconds;             /* wall time of the colour bake itself (tt_lapped_bake) */
    double cpu_seconds;         /* and its CPU time, all threads */
} baked_summary;

/* The interior edges whose two faces show different pastes on top, each
   named by one of its corners (*edges is malloc'd): where pastes end, softly
   or with a hard edge. */
static int top_change_edges(const tt_mesh *mesh, const tt_lapped *lapped, int **edges, int *count)
{
    int *top = (int *)malloc((size_t)(mesh->nfaces > 0 ? mesh->nfaces : 1) * sizeof(int));
    int p, e, c;
    *count = 0;
    *edges = (int *)malloc((size_t)(mesh->ncorners > 0 ? mesh->ncorners : 1) * sizeof(int));
    if (!top || !*edges) {
        free(top);
        free(*edges);
        *edges = NULL;
        return tool_fail("out of memory for the edges of %d faces", mesh->nfaces);
    }
    for (c = 0; c < mesh->nfaces; c++) top[c] = -1;
    for (p = 0; p < lapped->npastes; p++)
        for (e = lapped->pastes[p].first; e < lapped->pastes[p].first + lapped->pastes[p].nfaces; e++)
            top[lapped->faces[e]] = p;
    for (c = 0; c < mesh->ncorners; c++)
        if (mesh->twin[c] > c && top[mesh->corner_face[c]] != top[mesh->corner_face[mesh->twin[c]]])
            (*edges)[(*count)++] = c;
    free(top);
    return 0;
}

/* The baked texture's seam score (tt_measure_seams) over every edge and over
   the edges where the paste on top changes: about 0 where pastes fade out
   softly, about 1 where one ends with a hard edge. */
static int measure_baked(const lapped_options *options, const triangle_mesh *m, const tt_lapped *lapped,
                         const float *corner_uv, const tt_image *atlas, baked_summary *summary)
{
    int *edges = NULL, nedges = 0;
    int status = tool_measure_seams(options->mesh_path, m->mesh, corner_uv, atlas, options->seed, 0, NULL, 0, 0,
                                    0.0f, &summary->all);
    if (status == 0) status = top_change_edges(m->mesh, lapped, &edges, &nedges);
    if (status == 0)
        status = tool_measure_seams(options->mesh_path, m->mesh, corner_uv, atlas, options->seed, 0, edges, nedges, 0,
                                    0.0f, &summary->top_changes);
    free(edges);
    return status;
}

/* Map `map` baked into `atlas` with the pastes, UVs and options the colour
   was baked with, from its own patches (the colour's alpha): the maps line
   up with the colour texel for texel. map_patches has room for one patch
   per window. */
static int bake_map(const lapped_options *options, const triangle_mesh *m, const tt_lapped *lapped,
                    const lapped_patches *patches, const float *corner_uv, const tt_bake_options *bake, int map,
                    tt_image **map_patches, tt_image *atlas)
{
    tt_error error;
    int k;
    for (k = 0; k < patches->count; k++) map_patches[k] = patches->map_images[k * MATERIAL_MAPS + map];
    if (tt_lapped_bake(m->mesh, lapped, map_patches, patches->count, corner_uv, bake, NULL, atlas, &error) != TT_OK)
        return triangle_mesh_report_error(options->mesh_path, m, &error);
    return 0;
}

/* --bake: the pastes composited into a size x size texture over corner_uv
   (from bake_uvs; freed here); an ordinary OBJ + MTL + PNG (and a PNG per
   map), or with a gltf_path (not NULL) that GLB. */
static int add_baked(tool_output *output, const lapped_options *options, const triangle_mesh *m,
                     const tt_lapped *lapped, const lapped_patches *patches, float *corner_uv,
                     const char *gltf_path, baked_summary *summary)
{
    char obj_path[4096], mtl_path[4096], png_path[4096], comment[256], map_paths[MATERIAL_MAPS][4200];
    const char *map_names[MATERIAL_MAPS];
    tt_image *atlas = NULL, **map_patches = NULL, *map_atlases[MATERIAL_MAPS];
    float *normals = NULL;
    tt_bake_options bake;
    tool_progress progress;
    tt_result result;
    tt_error error;
    obj_write_desc desc;
    int status = 0, map;

    memset(map_atlases, 0, sizeof map_atlases);
    map_patches = (tt_image **)malloc((size_t)patches->count * sizeof(tt_image *));
    if (!map_patches) return tool_fail("out of memory for the baked maps");

    snprintf(obj_path, sizeof obj_path, "%s.obj", options->baked_stem);
    snprintf(mtl_path, sizeof mtl_path, "%s.mtl", options->baked_stem);
    snprintf(png_path, sizeof png_path, "%s.png", options->baked_stem);
    if (tt_image_create(options->bake_size, options->bake_size, NULL, &atlas, &error) != TT_OK) {
        status = tool_fail("--bake %d: %s", options->bake_size, error.message);
        goto done;
    }
    memset(&bake, 0, sizeof bake);
    bake.gutter = LAPPED_BAKE_GUTTER;
    bake.executor = tool_executor();
    tool_progress_begin(&progress, "baking", "of the atlas");
    bake.progress = tool_show_progress;
    bake.progress_user_data = &progress;
    summary->seconds = tool_seconds_now();
    summary->cpu_seconds = tool_cpu_seconds_now();
    result = tt_lapped_bake(m->mesh, lapped, patches->images, patches->count, corner_uv, &bake, NULL, atlas, &error);
    tool_progress_end(&progress);
    if (result != TT_OK) {
        status = triangle_mesh_report_error(options->mesh_path, m, &error);
        goto done;
    }
    summary->seconds = tool_seconds_now() - summary->seconds;
    summary->cpu_seconds = tool_cpu_seconds_now() - summary->cpu_seconds;
    if ((status = measure_baked(options, m, lapped, corner_uv, atlas, summary)) != 0) goto done;

    snprintf(comment, sizeof comment, "lapped texture by tiledtex %s, baked into %s", TILEDTEX_VERSION_STRING,
             tool_basename(png_path));
    if (!(normals = tool_corner_normals(gltf_path ? gltf_path : obj_path, m->mesh, m->corner_normal))) {
        status = TOOL_EXIT_FAILURE;
        goto done;
    }
    memset(&desc, 0, sizeof desc);
    desc.nverts = m->mesh->nverts;
    desc.pos = m->mesh->pos;
    desc.nfaces = m->ntriangles;
    desc.fixed_face_size = 3;
    desc.corner_vert = m->vert;
    desc.corner_uv = corner_uv;
    desc.corner_normal = normals;
    desc.share_equal = 1;   /* a chart's corners at one vertex share a vt */
    if (gltf_path) {
        /* The GLB is written at once: every map baked into an atlas of its own. */
        tool_material material;
        for (map = 0; map < MATERIAL_MAPS && status == 0; map++) {
            if (!options->maps.paths[map]) continue;
            if (tt_image_create(options->bake_size, options->bake_size, NULL, &map_atlases[map], &error) != TT_OK)
                status = tool_fail("out of memory for the baked %s map", material_map_names[map]);
            else
                status = bake_map(options, m, lapped, patches, corner_uv, &bake, map, map_patches, map_atlases[map]);
        }
        if (status != 0) goto done;
        memset(&material, 0, sizeof material);
        material.name = "lapped_baked";
        material.base_color = atlas;
        material_for_glb(&material, &options->maps, (const tt_image *const *)map_atlases);
        status = output_add_gltf(output, gltf_path, &desc, &material);
        goto done;
    }
    desc.comment = comment;
    desc.mtllib = tool_basename(mtl_path);
    desc.material = "lapped_baked";
    if ((status = output_add_obj(output, obj_path, &desc)) != 0) goto done;
    for (map = 0; map < MATERIAL_MAPS; map++) {
        material_path(map_paths[map], sizeof map_paths[map], options->baked_stem, map);
        map_names[map] = options->maps.paths[map] ? map_paths[map] : NULL;
    }
    status = output_add_mtl(output, mtl_path, "lapped_baked", png_path, 0, map_names);
    /* The baked texture holds linear straight RGBA: written as sRGB colour. */
    if (status == 0) status = add_png(output, png_path, atlas);
    atlas = NULL;   /* add_png freed it */
    if (status != 0 || material_count(&options->maps) == 0) goto done;

    /* The maps one atlas at a time, the colour's memory given back first. */
    if (tt_image_create(options->bake_size, options->bake_size, NULL, &atlas, &error) != TT_OK) {
        status = tool_fail("out of memory for the baked maps");
        goto done;
    }
    for (map = 0; map < MATERIAL_MAPS && status == 0; map++) {
        if (!map_names[map]) continue;
        status = bake_map(options, m, lapped, patches, corner_uv, &bake, map, map_patches, atlas);
        if (status == 0) status = output_add_map_png(output, map_paths[map], map, atlas);
    }
done:
    tt_image_free(atlas);
    for (map = 0; map < MATERIAL_MAPS; map++) tt_image_free(map_atlases[map]);
    free(map_patches);
    free(normals);
    free(corner_uv);
    return status;
}

/* ======================================================================== */
/* The command                                                              */
/* ======================================================================== */

static int paste(const lapped_options *options, const triangle_mesh *m, const float *field,
                 const lapped_patches *patches, tt_lapped **lapped)
{
    tt_lapped_options paste_options;
    tool_progress progress;
    tt_error error;
    tt_result result;
    tool_progress_begin(&progress, "pasting", "of the surface covered");
    memset(&paste_options, 0, sizeof paste_options);
    paste_options.seed = options->seed;
    paste_options.isotropic = options->isotropic;
    paste_options.keep_edges = options->keep_edges;
    paste_options.progress = tool_show_progress;
    paste_options.progress_user_data = &progress;
    result = tt_lapped_paste(m->mesh, field, patches->images, patches->count, &paste_options, NULL, lapped, &error);
    tool_progress_end(&progress);
    return result == TT_OK ? 0 : triangle_mesh_report_error(options->mesh_path, m, &error);
}

/* "patches: 4 of 4 used (512x512 windows), 98/95/92/95 pastes": the pastes
   each patch got (they add up to the pastes). */
static void print_patch_use(const lapped_patches *patches, const tt_lapped *lapped)
{
    int *uses = (int *)calloc((size_t)patches->count, sizeof(int));
    int p, k, used = 0;
    if (!uses) return;
    for (p = 0; p < lapped->npastes; p++) uses[lapped->pastes[p].patch]++;
    for (k = 0; k < patches->count; k++) used += uses[k] > 0;
    printf("patches: %d of %d used", used, patches->count);
    if (patches->size > 0) printf(" (%dx%d windows)", patches->size, patches->size);
    else printf(" (the whole image)");
    for (k = 0; k < patches->count; k++) printf("%s%d", k == 0 ? ", " : "/", uses[k]);
    printf(" pastes\n");
    free(uses);
}

/* How evenly the photo is spread over the surface, as a bake shows it: the
   texel density spread (tt_measure_uv_distortion: area-weighted 95th
   percentile of sqrt(texels / surface area) over its 5th, 1 = the same
   everywhere) of the map each triangle has from the paste on top, the
   last to draw it (what the bake shows where that paste is opaque). UVs of
   a patch of another size than the first are scaled into the first's
   texels. 0 when it cannot be measured. */
static double top_density_spread(const triangle_mesh *m, const tt_lapped *lapped, const lapped_patches *patches)
{
    const tt_mesh *mesh = m->mesh;
    const tt_image *first = patches->images[0];
    float *uv = (float *)calloc(2 * (size_t)mesh->ncorners, sizeof(float));
    tt_uv_distortion_report report;
    tt_error error;
    double spread = 0.0;
    int p, e, k;
    if (!uv) return 0.0;
    for (p = 0; p < lapped->npastes; p++) {
        const tt_image *patch = patches->images[lapped->pastes[p].patch];
        const float su = (float)patch->width / (float)first->width, sv = (float)patch->height / (float)first->height;
        for (e = lapped->pastes[p].first; e < lapped->pastes[p].first + lapped->pastes[p].nfaces; e++) {
            float *to = uv + 2 * (size_t)mesh->face_start[lapped->faces[e]];
            for (k = 0; k < 3; k++) {
                to[2 * k] = su * lapped->uv[6 * (size_t)e + 2 * k];
                to[2 * k + 1] = sv * lapped->uv[6 * (size_t)e + 2 * k + 1];
            }
        }
    }
    if (tt_measure_uv_distortion(mesh, uv, first->width, first->height, NULL, NULL, &report, &error) == TT_OK)
        spread = report.density_spread;
    free(uv);
    return spread;
}

/* Paste `paste`'s cut at (u, v) of its texture space, as tt_lapped.cut
   describes it: 1 within, smoothstep down to 0 over the feather beyond. */
static double paste_cut_factor(const tt_lapped *lapped, int paste, double u, double v)
{
    const int K = lapped->cut_columns;
    const float *cut = lapped->cut + (size_t)(2 + K) * (size_t)paste;
    const double du = u - cut[0], dv = v - cut[1], r = sqrt(du * du + dv * dv);
    double at = atan2(dv, du) / (2.0 * 3.14159265358979323846) * K, reach, x;
    int j;
    if (at < 0.0) at += K;
    j = (int)at < K ? (int)at : K - 1;
    reach = cut[2 + j] + (at - j) * (cut[2 + (j + 1) % K] - cut[2 + j]);
    if (r <= reach) return 1.0;
    x = (reach + lapped->cut_feather - r) / lapped->cut_feather;
    return x <= 0.0 ? 0.0 : x * x * (3.0 - 2.0 * x);
}

/* Pastes composited at one point, at most (beneath them the rest is hidden
   in practice: the walk stops below 0.001 of light left). */
#define GHOST_DEPTH 64

/* One paste (straight colour S, alpha a = patch alpha times fade, cut c)
   composited over out[4] as tt_lapped_bake does it (narrowed with a cut,
   TT_LAPPED_CUT_BLEND, then cut), also on share[0 .. n - 1], out's
   premultiplied colour split by the pastes beneath (share[n] is this
   one's). */
static void ghost_over(double out[4], double *share, int n, const double S[3], double a, double c, int narrow)
{
    double own = a, beneath = 0.0;   /* the sample's colour: own S + beneath out */
    int i, k;
    if (narrow && out[3] > 0.0 && a > 0.0 && a < 1.0) {
        const double A = a + (1.0 - a) * out[3], x0 = (a / A - 0.5) / TT_LAPPED_CUT_BLEND + 0.5;
        const double x = x0 < 0.0 ? 0.0 : (x0 > 1.0 ? 1.0 : x0), g = x * x * (3.0 - 2.0 * x);
        own = g * A;
        beneath = (1.0 - g) * A / out[3] - (1.0 - a);
    }
    if (c < 1.0) {
        const double keep = 1.0 - (1.0 - c) * out[3];
        own *= keep;
        beneath = keep * beneath + (1.0 - c) * a;
    }
    for (k = 0; k < n; k++) share[k] *= beneath + 1.0 - a;
    share[n] = own;
    for (i = 0; i < 3; i++) out[i] = own * S[i] + (beneath + 1.0 - a) * out[i];
    out[3] = a + (1.0 - a) * out[3];
}

/* Ghosting: the share of sample points (21 per face) whose composited
   colour mixes two pastes, each at least GHOST_SHARE of it, whose colours
   differ by at least GHOST_DIFFERENCE (mean square over RGB): two courses
   of a structured photo seen through each other. *mixed gets the share of
   points that mix two pastes at all. -1 when out of memory. */
#define GHOST_SHARE 0.2
#define GHOST_DIFFERENCE 0.02
static double ghosting(const tt_mesh *mesh, const tt_lapped *lapped, const lapped_patches *patches, double *mixed)
{
    int *paste_of = (int *)malloc(sizeof(int) * (size_t)(lapped->nentries + 1));
    int *head = (int *)malloc(sizeof(int) * (size_t)(mesh->nfaces + 1));
    int *below = (int *)malloc(sizeof(int) * (size_t)(lapped->nentries + 1));
    long points = 0, mixing = 0, ghosts = 0;
    int p, e, f, j;
    *mixed = 0.0;
    if (!paste_of || !head || !below) {
        free(paste_of);
        free(head);
        free(below);
        return -1.0;
    }
    for (p = 0; p < lapped->npastes; p++)
        for (e = lapped->pastes[p].first; e < lapped->pastes[p].first + lapped->pastes[p].nfaces; e++) paste_of[e] = p;
    for (f = 0; f < mesh->nfaces; f++) head[f] = -1;
    for (e = 0; e < lapped->nentries; e++) {
        below[e] = head[lapped->faces[e]];
        head[lapped->faces[e]] = e;
    }
    for (f = 0; f < mesh->nfaces; f++)
        for (j = 0; j < 36; j++) {
            const int wa = j % 6, wb = j / 6;
            double w[3], S[GHOST_DEPTH][3], alpha[GHOST_DEPTH], cut[GHOST_DEPTH], share[GHOST_DEPTH];
            double light = 1.0, out[4] = {0.0, 0.0, 0.0, 0.0}, first = 0.0, second = 0.0, d = 0.0;
            int n = 0, c, k, i1 = 0, i2 = 0;
            if (wa + wb > 5 || head[f] < 0) continue;
            w[0] = (wa + 0.5) / 7.0;
            w[1] = (wb + 0.5) / 7.0;
            w[2] = 1.0 - w[0] - w[1];
            /* From the top down while light gets through, then composited upward. */
            for (e = head[f]; e >= 0 && light > 0.001 && n < GHOST_DEPTH; e = below[e], n++) {
                const float *uv = lapped->uv + 6 * (size_t)e, *fd = lapped->fade ? lapped->fade + 3 * (size_t)e : NULL;
                const tt_image *patch = patches->images[lapped->pastes[paste_of[e]].patch];
                const double u = w[0] * uv[0] + w[1] * uv[2] + w[2] * uv[4], v = w[0] * uv[1] + w[1] * uv[3] + w[2] * uv[5];
                double fade = fd ? w[0] * fd[0] + w[1] * fd[1] + w[2] * fd[2] : 1.0;
                float rgba[4];
                tt_image_sample_bilinear(patch, (float)(u * patch->width), (float)((1.0 - v) * patch->height), rgba);
                fade = fade < 0.0 ? 0.0 : (fade > 1.0 ? 1.0 : fade);
                alpha[n] = rgba[3] * fade;
                cut[n] = lapped->cut ? paste_cut_factor(lapped, paste_of[e], u, v) : 1.0;
                for (c = 0; c < 3; c++) S[n][c] = rgba[3] > 0.0f ? rgba[c] / rgba[3] : 0.0;
                light *= 1.0 - alpha[n];
            }
            for (k = 0; k < n; k++)
                ghost_over(out, share, k, S[n - 1 - k], alpha[n - 1 - k], cut[n - 1 - k], lapped->cut != NULL);
            points++;
            if (!(out[3] > 0.0)) continue;
            for (k = 0; k < n; k++) {
                const double s = share[k] / out[3];
                if (s > first) {
                    second = first;
                    i2 = i1;
                    first = s;
                    i1 = k;
                } else if (s > second) {
                    second = s;
                    i2 = k;
                }
            }
            if (second < GHOST_SHARE) continue;
            mixing++;
            for (c = 0; c < 3; c++) d += (S[n - 1 - i1][c] - S[n - 1 - i2][c]) * (S[n - 1 - i1][c] - S[n - 1 - i2][c]);
            ghosts += d / 3.0 >= GHOST_DIFFERENCE;
        }
    free(paste_of);
    free(head);
    free(below);
    *mixed = points ? (double)mixing / (double)points : 0.0;
    return points ? (double)ghosts / (double)points : 0.0;
}

static void print_summary(const lapped_options *options, const triangle_mesh *m, const float *field,
                          const tt_lapped *lapped, const lapped_patches *patches, const bake_atlas *atlas,
                          const baked_summary *baked, double seconds)
{
    char all[256], top[256];
    tt_lapped_report report;
    tt_error error;
    double angle = lapped->mean_angle_error, scale = lapped->median_scale_error;
    /* Anisotropic: measured again from the UVs that were written, an
       independent check of what the paste loop believes. Isotropic pastes
       choose their own directions, which only the loop knows. */
    if (!options->isotropic) {
        if (tt_lapped_measure(m->mesh, field, lapped, NULL, &report, &error) == TT_OK) {
            angle = report.mean_angle_error;
            scale = report.median_scale_error;
        } else {
            tool_note("alignment measured by the paste loop only: %s", error.message);
        }
    }
    printf("%s: %d triangles", options->mesh_path, m->ntriangles);
    if (m->subdivided > 0) printf(" (%d faces, --subdivide %d)", m->obj.nfaces, m->subdivided);
    else if (m->ntriangles != m->obj.nfaces) printf(" (fans of %d faces)", m->obj.nfaces);
    printf(", %d pastes, coverage %.1f%%, mean overdraw %.2f\n", lapped->npastes, 100.0 * lapped->coverage,
           lapped->mean_overdraw);
    printf("alignment: mean angle error %.1f degrees, median scale error %.1f%%%s\n", angle, 100.0 * scale,
           options->isotropic ? " (isotropic: the angle is against the field, which the pastes do not follow; "
                                "only the scale error counts)" : "");
    printf("texel density of the pastes on top: 95th percentile over 5th %.3f\n",
           top_density_spread(m, lapped, patches));
    {
        double mixed, ghosts = ghosting(m->mesh, lapped, patches, &mixed);
        if (ghosts >= 0.0)
            printf("ghosting: %.1f%% of the sample points show two pastes that differ, each at least %.0f%% of the colour "
                   "(%.1f%% mixes two)\n", 100.0 * ghosts, 100.0 * GHOST_SHARE, 100.0 * mixed);
    }
    printf("cuts: %d of %d edges where the top paste changes end it at %.0f%% alpha or more\n", lapped->visible_cuts,
           lapped->top_changes, 100.0 * TT_LAPPED_VISIBLE_CUT);
    if (options->bake_size > 0) {
        tool_format_seams(&baked->all, "edges", all, sizeof all);
        tool_format_seams(&baked->top_changes, "edges", top, sizeof top);
        printf("baked seam score: all edges %s; where the top paste changes %s\n", all, top);
        printf("bake: %dx%d texels in %.2f s wall, %.2f s CPU (%d thread%s)\n", options->bake_size,
               options->bake_size, baked->seconds, baked->cpu_seconds, tool_jobs(), tool_jobs() == 1 ? "" : "s");
        if (atlas->charts > 0)
            printf("bake atlas: %d charts fill %.1f%% of it; texel density %.3g texels per unit, 95th percentile "
                   "over 5th %.3f\n",
                   atlas->charts, 100.0 * atlas->fill, atlas->texels_per_unit, atlas->density_spread);
        if (options->bake_auto && atlas->texels_per_unit >= atlas->paste_texels)
            printf("bake size %d: the smallest power of two whose texels per unit (%.3g) reach the pastes' (%.3g; "
                   "--bake to choose)\n",
                   options->bake_size, atlas->texels_per_unit, atlas->paste_texels);
        else if (options->bake_auto)
            printf("bake size %d: capped there; its %.3g texels per unit fall short of the pastes' %.3g, so the bake "
                   "is softer than the pasting (a larger --scale or smaller --patch-size lowers theirs)\n",
                   options->bake_size, atlas->texels_per_unit, atlas->paste_texels);
    }
    printf("removed %d hidden face entries; %.1f s\n", lapped->removed_entries, seconds);
}

/* Refuse, before the long part, outputs that would replace an input (the
   commit checks again, but only after pasting). */
static int refuse_overwriting_inputs(const lapped_options *options, const char *obj_path, const char *mtl_path,
                                     const char *gltf_path, const lapped_patches *patches)
{
    static const char *const baked[] = {".obj", ".mtl", ".png"};
    char path[TOOL_PREFIX_SIZE + 16];
    int status = 0, k;
    if (options->output.format != TOOL_FORMAT_OBJ) return tool_refuse_input_overwrite(gltf_path);
    if (options->pasting) {
        status = tool_refuse_input_overwrite(obj_path);
        if (status == 0) status = tool_refuse_input_overwrite(mtl_path);
        for (k = 0; k < patches->count && status == 0; k++)
            status = tool_refuse_input_overwrite(patches->png_paths[k]);
        for (k = 0; k < patches->count * MATERIAL_MAPS && status == 0; k++)
            if (patches->map_png_paths[k]) status = tool_refuse_input_overwrite(patches->map_png_paths[k]);
    }
    if (options->bake_size == 0) return status;
    if (status == 0) status = material_refuse_overwrite(&options->maps, options->baked_stem);
    for (k = 0; k < 3 && status == 0; k++) {
        snprintf(path, sizeof path, "%s%s", options->baked_stem, baked[k]);
        status = tool_refuse_input_overwrite(path);
    }
    return status;
}

int cmd_lapped(int argc, char **argv)
{
    lapped_options options;
    triangle_mesh mesh;
    tt_image *image = NULL, *mask = NULL;
    tt_lapped *lapped = NULL;
    tool_output output;
    patch_windows windows;
    lapped_patches patches;
    float *field = NULL, *bake_uv = NULL;
    baked_summary baked;
    char obj_path[4096], mtl_path[4096], gltf_path[4096], written[8400], message[TOOL_ERROR_SIZE];
    double start = tool_seconds_now();
    int status, gltf;
    bake_atlas atlas;

    status = parse_command_line(argc, argv, &options);
    if (status >= 0) return status;
    snprintf(obj_path, sizeof obj_path, "%s.obj", options.prefix);
    snprintf(mtl_path, sizeof mtl_path, "%s.mtl", options.prefix);
    tool_output_path(options.prefix, tool_model_extension(&options.output), gltf_path, sizeof gltf_path);
    gltf = options.output.format != TOOL_FORMAT_OBJ;
    memset(&output, 0, sizeof output);
    memset(&baked, 0, sizeof baked);
    memset(&patches, 0, sizeof patches);
    memset(&windows, 0, sizeof windows);

    if ((status = triangle_mesh_read(options.mesh_path, &options.mesh, &mesh)) != 0) return status;
    field = (float *)malloc((size_t)mesh.ntriangles * 3 * sizeof(float));
    if (!field) status = tool_fail("out of memory for the field of %s", options.mesh_path);
    if (status == 0) status = tool_make_field(options.mesh_path, &mesh, &options.field, options.scale, field);
    /* A photo: sRGB bytes in the file, linear light in the library. */
    if (status == 0 && image_load(options.image_path, TT_COLOR_SRGB, &image, message, sizeof message) != 0)
        status = tool_fail("%s", message);
    if (status == 0 && !options.field.given && !options.isotropic)
        tool_note_courses_without_up(image, options.image_path, NULL, TOOL_COURSES_DEFAULT_UP);
    if (status == 0) status = material_load(&options.maps, options.image_path, image->width, image->height);
    if (status == 0) status = choose_windows(&options, image->width, image->height, &windows);
    if (status == 0) status = lapped_patches_name(options.prefix, &windows, &options.maps, &patches);
    if (status == 0) status = refuse_overwriting_inputs(&options, obj_path, mtl_path, gltf_path, &patches);
    memset(&atlas, 0, sizeof atlas);
    if (status == 0 && options.bake_size > 0)
        status = bake_uvs(&options, &mesh, field,
                          windows.size > 0 ? windows.size : image->width > image->height ? image->width : image->height,
                          &bake_uv, &atlas);
    if (status == 0) status = load_mask(&options, image->width, image->height, &windows, &mask);
    /* Memory: the image is needed only to make the patches and their PNGs,
       so the PNGs are encoded now and the image freed before the paste
       loop; from here on the command holds the patches and the compressed
       PNGs. */
    if (status == 0)
        status = make_patches(&options, &image, &windows, mask, options.pasting ? &output : NULL, &patches);
    if (status == 0)
        status = make_map_patches(&options, &options.maps, &windows, options.pasting ? &output : NULL, &patches);
    material_free(&options.maps);
    image_free(image);
    image = NULL;
    image_free(mask);
    mask = NULL;
    if (status == 0) status = paste(&options, &mesh, field, &patches, &lapped);

    if (status == 0 && options.pasting)
        status = add_pasting_obj(&output, obj_path, tool_basename(mtl_path), &mesh, lapped, &patches);
    if (status == 0 && options.pasting)
        status = output_add_mtl_materials(&output, mtl_path, patches.count, (const char *const *)patches.materials,
                                          (const char *const *)patches.png_paths, 1,
                                          (const char *const *)patches.map_png_paths);
    if (status == 0 && options.bake_size > 0) {
        status = add_baked(&output, &options, &mesh, lapped, &patches, bake_uv, gltf ? gltf_path : NULL, &baked);
        bake_uv = NULL;   /* add_baked freed it */
    }
    if (status == 0 && output_commit(&output, message, sizeof message) != 0) status = tool_fail("%s", message);

    if (status == 0 && !tool_quiet()) {
        print_summary(&options, &mesh, field, lapped, &patches, &atlas, &baked, tool_seconds_now() - start);
        print_patch_use(&patches, lapped);
        if (options.pasting) {
            printf("wrote %s, %s, %s", obj_path, mtl_path, patches.png_paths[0]);
            if (patches.count > 1) printf(" to %s", patches.png_paths[patches.count - 1]);
            if (options.bake_size > 0) printf("; %s.obj/.mtl/.png", options.baked_stem);
        } else {
            printf("wrote %s", gltf ? gltf_written(gltf_path, written, sizeof written) : obj_path);
            if (!gltf) printf(", %s, %s.png", mtl_path, options.baked_stem);
        }
        if (options.bake_size > 0) {
            printf(" (the pastes baked into %dx%d, over ", options.bake_size, options.bake_size);
            if (atlas.charts == 0) printf("the OBJ's texture coordinates)");
            else printf("an atlas of %d chart%s)", atlas.charts, atlas.charts == 1 ? "" : "s");
        }
        printf("\n");
        if (options.pasting)
            printf("%s holds the pastes: 'tiledtex render' and engines that draw its faces in file order with "
                   "blending show it right; Blender and assimp do not (the stacked copies of a triangle come out "
                   "dropped or shredded): %s\n",
                   obj_path,
                   options.bake_size > 0 ? "the baked files are for them"
                                         : "leave out --pasting for a bake that they show right");
    }
    output_free(&output);
    tt_lapped_free(lapped);
    lapped_patches_free(&patches);
    image_free(image);
    free(field);
    free(bake_uv);
    triangle_mesh_free(&mesh);
    return status;
}
