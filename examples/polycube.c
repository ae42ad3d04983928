/* polycube.c - `tiledtex polycube`: texture any triangle mesh with Chang
   and Lin's polycube map and Wang tiles.

   MESH + IMAGE -> OUT_PREFIX.obj (the mesh's triangles, split where
   they cross the tiles' borders, one texture coordinate per corner),
   OUT_PREFIX.mtl, OUT_PREFIX.png (the tile atlas) and
   OUT_PREFIX_polycube.obj (the polycube's surface S with its tiles, to look
   at what the mesh was mapped onto). Unlike `tile`, the tiles' size on the
   surface is the cube size, whatever the mesh's triangles.

   The library calls, as a user of tiledtex.h makes them:

     tt_mesh_build            the OBJ's faces as triangle fans (the mapping
                              works on triangles)
     tt_polycube_build        the polycube: voxels, interior fill, manifold
                              repair, correction, its surface S of quads
     tt_polycube_edge_colors  the Wang colouring of S's edges, a palette of
                              two colours per axis (the paper's n = 2)
     tt_assign_boundaries     tile types from those colours; tt_assign_uvs
                              gives S its own texture coordinates
     tt_synthesize_tiles      the atlas (shared with `tile`: tiled.c): plain
                              tiles, and upright ones (the same edge
                              windows) for the walls and the tops, with
                              a plain side where a top meets a wall
     tt_polycube_map          the triangles split along S's quad edges,
                              each corner's point on S (on -j threads)
     tt_compact_atlas_create, tt_compact_atlas_image_parts
                              the tiles S shows, cut from the four sets
     tt_polycube_mapping_uvs_upright  those points as texture coordinates
     tt_measure_uv_distortion, tt_measure_seams   the summary's quality
*/
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tiled.h"

/* The paper's colours: two per axis, drawn from a palette of this many. */
#define POLYCUBE_DEFAULT_COLORS 2
/* The atlas's side the tiles' count aims at by default: 2048 x 2048 holds
   225 tiles of 128 texels with their gutters, and keeps a GLB with a four-map
   material of a scan under about 16 MB; up to TT_COMPACT_ATLAS_DEFAULT_MAX_SIZE
   when the tiles cannot be fewer. */
#define POLYCUBE_DEFAULT_MAX_ATLAS 2048

static void print_help(void)
{
    printf("usage: tiledtex polycube MESH IMAGE OUT_PREFIX [options]\n"
           "\n"
           "Texture MESH from IMAGE with no seams (Chang and Lin, polycube maps and Wang\n"
           "tiles): the mesh is wrapped in a polycube, a block of equal cubes; each square of its\n"
           "surface shows one tile of an atlas made from IMAGE, tiles that match across every\n"
           "edge, and the mesh's triangles are split where they cross the squares' borders and\n"
           "given the texture of the part of the polycube they lie over. Works on any closed\n"
           "triangle or polygon mesh, dense scans included; n-gons are split into triangle fans.\n"
           "Writes OUT_PREFIX.obj (the split triangles, one texture coordinate per corner),\n"
           "OUT_PREFIX.mtl, OUT_PREFIX.png (the atlas) and OUT_PREFIX_polycube.obj (the polycube's\n"
           "surface with its tiles). Look at it with 'tiledtex render OUT_PREFIX.obj OUT_PREFIX.png\n"
           "view.png'.\n");
    tool_print_mesh_help(1);
    printf("OUT_PREFIX is a name without extension; one ending in .obj, .mtl or .png loses it\n"
           "('out.obj' writes out.obj, not out.obj.obj); one ending in .glb writes OUT_PREFIX.glb\n"
           "(--format glb), one ending in .gltf OUT_PREFIX.gltf (--format gltf). It may be '-' (the\n"
           "standard output) only for a GLB, one file.\n"
           "\n"
           "options:\n"
           "  --resolution N   cubes along the mesh's longest side, 1 to %d (default: the first of\n"
           "                   16, 20, 24, 28, 32, 36, 40, 48, 56, 64 at which the polycube has the\n"
           "                   mesh's genus and the mesh lies near it, so thin parts are two cubes\n"
           "                   thick or more; 72, 80 or 96 when only they give the genus)\n"
           "  --cube-size X    the cubes' edge in mesh units instead (not with --resolution)\n"
           "  --texture-size X how much of the surface, in mesh units, one tile of IMAGE's texels\n"
           "                   (--tile) covers; each square of the polycube shows a tile of as many\n"
           "                   texels as its share of that. Default: the mesh's longest side / 16,\n"
           "                   whatever resolution is chosen; with --resolution or --cube-size,\n"
           "                   the cube size (one tile of --tile texels per square). A photo laid in\n"
           "                   courses shows one course per square at the least, at its own texels\n"
           "                   (its bricks then smaller than X asks; a note says so)\n",
           TT_POLYCUBE_MAX_RESOLUTION);
    printf(
           "  --colors N       edge colours of the palette each axis draws 2 from (default %d:\n"
           "                   the paper's 256 tiles); 1 gives 16 tiles\n"
           "  --seed K         random seed: colours, tiles, synthesis (default 0)\n"
           "  --tile S         tile size in texels (default: %d, or what IMAGE can feed)\n"
           "  --gutter G       texels of gutter around each tile, 0 for none (default %d)\n"
           "  --no-correct     skip the polycube's correction step (keeps every cube the surface\n"
           "                   meets)\n"
           "  --up AXIS        the direction the tiles' up follows: x, y, z, -x, -y, -z or X,Y,Z\n"
           "                   (its largest component counts; default y)\n"
           "  --no-upright     one set of plain tiles: a quarter of the atlas, but the left and\n"
           "                   right quarter of each tile turns a quarter (bricks, planks and grain\n"
           "                   run crosswise there); by default the tiles keep IMAGE's up throughout\n"
           "                   (on the walls) or one direction over every top, from three more sets\n"
           "                   of tiles: upright ones, and two with one plain side, for the tops'\n"
           "                   sides beside a wall\n"
           "  --no-courses     take IMAGE as it is: by default a photo laid in courses (bricks,\n"
           "                   blocks) is resampled so that a tile holds a whole number of them,\n"
           "                   and every tile is cut on them, so they run level through the walls\n"
           "  --format F       obj (default): the files above; glb: one binary glTF file,\n"
           "                   OUT_PREFIX.glb: the textured mesh with the atlas in it; gltf: the\n"
           "                   same as glTF text, OUT_PREFIX.gltf, with OUT_PREFIX.bin and\n"
           "                   OUT_PREFIX_baseColor.png (and a PNG per map) beside it (either way\n"
           "                   the polycube's surface is left out: write the OBJ files to see it)\n"
           "  --triangles      write the polycube surface's squares as two triangles each (the\n"
           "                   mesh is triangles already)\n"
           "  --max-atlas N    the atlas's larger side at most N texels (default %d, or up to %d\n"
           "                   when the tiles cannot be fewer): it holds only the tiles the\n"
           "                   polycube shows, as few as the squares' colours allow, in a\n"
           "                   power-of-two square or 2:1 rectangle\n"
           MATERIAL_OPTIONS_HELP("                   ")
           "\n"
           "Prints the polycube (cubes, squares, components, genus against the mesh's), the\n"
           "mapping (triangles split, triangles that fell back to one square: local seams, edges\n"
           "with no path on the polycube, folds), the tiles (how many, and which squares take\n"
           "upright ones), the stretch of the texture on the triangles and\n"
           "the spread of its texel density (5th percentile, median, 95th, by area), the\n"
           "seam score on the tiles' borders, over all edges, and on the polycube's squares near\n"
           "their corners, within 5 %% of each edge's ends, where three to six tiles meet (about 0:\n"
           "the texture continues, about 1: unrelated) and the time of each stage.\n"
           "\n"
           "example: tiledtex generate mesh sphere.obj --shape sphere --triangles\n"
           "         tiledtex generate texture stones.png --size 256\n"
           "         tiledtex polycube sphere.obj stones.png sphere_pc\n"
           "         tiledtex render sphere_pc.obj sphere_pc.png view.png\n",
           POLYCUBE_DEFAULT_COLORS,
           TT_DEFAULT_TILE_SIZE, TT_RECOMMENDED_GUTTER, POLYCUBE_DEFAULT_MAX_ATLAS, TT_COMPACT_ATLAS_DEFAULT_MAX_SIZE);
}

typedef struct polycube_command_options {
    const char *mesh_path, *image_path;
    char prefix[TOOL_PREFIX_SIZE];  /* OUT_PREFIX without a known extension */
    tiled_options tiles;            /* --colors --tile --gutter --seed, as `tile` takes them */
    tt_polycube_options build;      /* zero fields: the library's defaults */
    int plain;                      /* --no-upright */
    int up_given;                   /* --up was given */
    int max_atlas;                  /* --max-atlas; 0 = the library's default */
    double texture_size;            /* --texture-size; 0 = the mesh's longest side / 16, or the cube size when
                                       --resolution or --cube-size chose it */
} polycube_command_options;

/* Returns -1 to go on, or the exit status to return now. */
static int parse_command_line(int argc, char **argv, polycube_command_options *options)
{
    const char *positional[3];
    int npositional = 0, resolution_given = 0, cube_size_given = 0, i;
    memset(options, 0, sizeof *options);
    tiled_default_options(&options->tiles);
    for (i = 1; i < argc; i++) {
        const char *value;
        int taken;
        if (tool_is_help(argv[i])) {
            print_help();
            return 0;
        }
        taken = tiled_parse_option(argc, argv, &i,
                                   TILED_LAYOUT_OPTIONS | TILED_MATERIAL_OPTIONS | TILED_TRIANGLES_OPTION |
                                       TILED_FORMAT_OPTION,
                                   &options->tiles);
        if (taken < 0) return TOOL_EXIT_USAGE;
        if (taken) continue;
        if (tool_option(argc, argv, &i, "--resolution", &value)) {
            if (parse_int("--resolution", value, 1, TT_POLYCUBE_MAX_RESOLUTION, &options->build.resolution) != 0)
                return TOOL_EXIT_USAGE;
            resolution_given = 1;
        } else if (tool_option(argc, argv, &i, "--cube-size", &value)) {
            double size;
            if (!value) return tool_usage("--cube-size needs a value");
            if (parse_whole_double(value, &size) != 0 || !(size > 0.0) || size > 1e30)
                return tool_usage("--cube-size wants the cubes' edge in mesh units, above 0, got '%s'", value);
            options->build.cube_size = size;
            cube_size_given = 1;
        } else if (tool_option(argc, argv, &i, "--texture-size", &value)) {
            if (!value) return tool_usage("--texture-size needs a value");
            if (parse_whole_double(value, &options->texture_size) != 0 || !(options->texture_size > 0.0) ||
                options->texture_size > 1e30)
                return tool_usage("--texture-size wants the surface one tile covers in mesh units, above 0, got "
                                  "'%s'", value);
        } else if (tool_option(argc, argv, &i, "--max-atlas", &value)) {
            if (parse_int("--max-atlas", value, 1, TT_MAX_IMAGE_SIZE, &options->max_atlas) != 0)
                return TOOL_EXIT_USAGE;
        } else if (tool_flag(argv[i], "--no-courses")) {
            options->tiles.no_courses = 1;
        } else if (tool_flag(argv[i], "--no-upright")) {
            options->plain = 1;
        } else if (tool_flag(argv[i], "--no-correct")) {
            options->build.flags |= TT_POLYCUBE_NO_CORRECT;
        } else if (tool_option(argc, argv, &i, "--up", &value)) {
            if (parse_up("--up", value, options->build.up) != 0) return TOOL_EXIT_USAGE;
            options->up_given = 1;
        } else if (tool_is_option(argv[i])) {
            return tool_unknown_option(argv[i]);
        } else if (npositional < 3) {
            positional[npositional++] = argv[i];
        } else {
            npositional++; /* counted, to say there are too many */
        }
    }
    if (resolution_given && cube_size_given)
        return tool_usage("give --resolution or --cube-size, not both (both set the cubes' size)");
    if (options->tiles.layout.colors == 0) options->tiles.layout.colors = POLYCUBE_DEFAULT_COLORS;
    if (tool_mesh_image_prefix(positional, npositional, &options->mesh_path, &options->image_path,
                               &options->tiles.output, options->prefix) != 0)
        return TOOL_EXIT_USAGE;
    return -1;
}

/* ======================================================================== */
/* The pipeline                                                             */
/* ======================================================================== */

/* Everything the command makes, freed by polycube_job_free. */
typedef struct polycube_job {
    triangle_mesh mesh;
    tt_polycube *polycube;
    tt_polycube_report build_report;
    tt_polycube_resolution_report resolution_report;   /* the resolutions tried */
    int photo_tile;                 /* texels of IMAGE one tile of --texture-size takes (--tile) */
    tt_tile_layout layout;          /* resolved */
    int *edge_colors;               /* per S half-edge */
    uint8_t *surface_type;          /* per S half-edge: its boundary type */
    uint8_t *surface_group;         /* per S quad: its tile set (tt_polycube_quad_tileset), 0 with --no-upright */
    float *surface_uv;              /* per S corner: S's own texture coordinates */
    tt_tileset *tiles;              /* plain: tops with walls on both sides (all of S with --no-upright) */
    /* Upright, TT_TILESET_UPRIGHT + k: the walls and the tops among
       tops, then the tops with a wall on the right or the left; NULL with
       --no-upright. */
    tt_tileset *upright_tiles[TILED_UPRIGHT_SETS];
    tt_image *atlas;                /* the compact atlas: the tiles S shows */
    /* The same for each map of the material (NULL for the maps not given). */
    tt_tileset *map_tiles[MATERIAL_MAPS], *map_upright_tiles[TILED_UPRIGHT_SETS][MATERIAL_MAPS];
    tt_image *map_atlas[MATERIAL_MAPS];
    int upright;                    /* upright tiles (IMAGE was large enough) */
    tt_compact_atlas *compact;      /* the cells S shows, and where they went */
    int full_width, full_height;    /* the atlas of every tile, which the compact one replaced */
    tt_polycube_mapping *mapping;
    tt_polycube_map_report map_report;
    float *corner_uv;               /* 6 per mapped triangle */
    double build_seconds, synth_seconds, map_seconds;
} polycube_job;

/* Every tile set and its maps' (the atlases hold what the outputs use). */
static void polycube_tilesets_free(polycube_job *job)
{
    tiled_tilesets_free(&job->tiles, job->map_tiles);
    tiled_upright_free(job->upright_tiles, job->map_upright_tiles);
}

static void polycube_job_free(polycube_job *job)
{
    int map;
    triangle_mesh_free(&job->mesh);
    tt_polycube_free(job->polycube);
    free(job->edge_colors);
    free(job->surface_type);
    free(job->surface_group);
    free(job->surface_uv);
    polycube_tilesets_free(job);
    tt_image_free(job->atlas);
    for (map = 0; map < MATERIAL_MAPS; map++) tt_image_free(job->map_atlas[map]);
    tt_compact_atlas_free(job->compact);
    tt_polycube_mapping_free(job->mapping);
    free(job->corner_uv);
    memset(job, 0, sizeof *job);
}

/* The tiles an atlas within --max-atlas holds: the whole cells of the
   largest power-of-two square within it (the compact atlas's sides are
   powers of two). */
static int polycube_tile_budget(const polycube_command_options *options, const tt_tile_layout *layout)
{
    const int limit = options->max_atlas ? options->max_atlas : POLYCUBE_DEFAULT_MAX_ATLAS;
    int side = 1, across;
    while (2 * side <= limit) side *= 2;
    across = side / (layout->tile_size + 2 * layout->gutter);
    return across > 0 ? across * across : 1;
}

/* The polycube: at the resolution the mesh needs, unless --resolution or
   --cube-size chose it. */
static int build_polycube(const polycube_command_options *options, polycube_job *job)
{
    const char *path = options->mesh_path;
    const tt_polycube_resolution_report *tried = &job->resolution_report;
    tt_error error;
    double start = tool_seconds_now();
    tool_stage("building the polycube");
    if (tt_polycube_build_auto(job->mesh.mesh, &options->build, 0, NULL, &job->polycube, &job->build_report,
                               &job->resolution_report, &error) != TT_OK)
        return triangle_mesh_report_error(path, &job->mesh, &error);
    if (job->build_report.inside_out) {
        /* The mapping needs outward faces (its projection tells the sides of a thin part by the normals, and
           the polycube's squares turn counter-clockwise seen from outside): map the faces reversed, and write
           them so. The resolution is chosen again on the faces turned out. */
        int status = triangle_mesh_reverse(path, &job->mesh);
        if (status != 0) return status;
        tool_note("%s: the faces wind inward (the mesh is inside out): mapped them reversed, and the output's "
                  "faces wind outward", path);
        tt_polycube_free(job->polycube);
        job->polycube = NULL;
        if (tt_polycube_build_auto(job->mesh.mesh, &options->build, 0, NULL, &job->polycube, &job->build_report,
                                   &job->resolution_report, &error) != TT_OK)
            return triangle_mesh_report_error(path, &job->mesh, &error);
    }
    job->build_seconds = tool_seconds_now() - start;
    if (job->build_report.genus_differs)
        tool_note("%s: the polycube has genus %d, the mesh %d: handles are closed or opened where the cubes are "
                  "too coarse (%s)", path, job->build_report.polycube_genus, job->build_report.mesh_genus,
                  tried->tries > 1 ? "the same up to the largest resolution tried; a larger --resolution may close "
                                     "them, with many more triangles"
                                   : "raise --resolution");
    else if (tried->tries > 1 && tried->mean_distance[tried->chosen] > TT_POLYCUBE_AUTO_NEAR)
        tool_note("%s: parts of the mesh are thinner than two cubes even at resolution %d (the largest tried): "
                  "their texture is drawn out there (a larger --resolution follows them, with many more "
                  "triangles)", path, job->build_report.resolution);
    return 0;
}

/* Each square's tile in texels: --tile texels cover --texture-size of the
   surface, and a square covers the cube size h of it. Multiples of 8
   (the tiles' mip levels), 16 at least. Without --texture-size the
   texture keeps the size the default resolution (16) gives it, however
   fine the polycube the mesh needed; a resolution the user chose keeps a
   tile per square, the size --cube-size always promised. A photo laid in
   courses (course_period texels apart; 0: none) shows one course per
   square at the least (tiled_fit_courses), so a square shows at least a
   course's texels. */
static int scale_tiles(polycube_command_options *options, polycube_job *job, const tt_image *image,
                       double course_period)
{
    double extent, texels;
    int size;
    job->photo_tile = options->tiles.layout.tile_size;
    extent = options->texture_size;
    if (!(extent > 0.0) && (options->build.resolution || options->build.cube_size > 0.0))
        extent = job->polycube->h;
    /* The chosen polycube's cube is the mesh's longest side over its
       resolution: the default is the cube of resolution 16. */
    if (!(extent > 0.0)) extent = job->polycube->h * job->build_report.resolution / TT_POLYCUBE_DEFAULT_RESOLUTION;
    texels = job->photo_tile * job->polycube->h / extent;
    if (extent == job->polycube->h) return 0;   /* one --tile per square, as given */
    size = (int)(texels / 8.0 + 0.5) * 8;
    if (size < course_period) {
        /* Fewer texels than a course would shrink the photo to fit one
           (brick_red on the elephant at 72: to 0.61, 24 texels a course, its
           bricks blurred). The bricks are a square tall on the surface
           either way; with the course's own texels (half a texel less at
           most) they keep their detail, at a higher texel density. */
        size = (int)ceil((course_period - 0.5) / 8.0) * 8;
        if (size < 16) size = 16;
        tool_note("%s: a square of the polycube (%.4g units) would show %.3g texels of %s, fewer than one of its "
                  "courses (%.1f); shows %d, a course per square (the bricks are smaller on the surface than "
                  "--texture-size %.4g asks)", options->mesh_path, job->polycube->h, texels, options->image_path,
                  course_period, size, extent);
    } else if (size < 16) {
        tool_note("%s: a square of the polycube (%.4g units) would show %.3g texels of %s; shows 16 (the texture "
                  "is larger on the surface than --texture-size %.4g asks)", options->mesh_path, job->polycube->h,
                  texels, options->image_path, extent);
        size = 16;
    }
    if (size > job->photo_tile) {
        /* More texels than --tile: as many as IMAGE can feed (an edge window is S x 2S, at most 2/5 of its
           smaller side, as tiled_fit_tile_size allows). */
        const int side = image->width < image->height ? image->width : image->height;
        int feed = 2 * side / 5 - (2 * side / 5) % 8;
        if (feed < job->photo_tile) feed = job->photo_tile;
        if (size > feed) {
            tool_note("%s: a square of the polycube (%.4g units) would show %d texels of %s, more than it can "
                      "feed; shows %d (the texture is smaller on the surface than --texture-size %.4g asks)",
                      options->mesh_path, job->polycube->h, size, options->image_path, feed, extent);
            size = feed;
        }
    }
    options->tiles.layout.tile_size = size;
    return 0;
}

/* The tiles of the polycube's surface S. */
static int tile_polycube(const polycube_command_options *options, polycube_job *job)
{
    const char *path = options->mesh_path;
    tt_error error;
    int ncorners, q;
    ncorners = job->polycube->surface->ncorners;
    job->edge_colors = (int *)malloc((size_t)ncorners * sizeof(int));
    job->surface_type = (uint8_t *)malloc((size_t)ncorners);
    job->surface_uv = (float *)malloc((size_t)ncorners * 2 * sizeof(float));
    job->surface_group = (uint8_t *)malloc((size_t)job->polycube->surface->nfaces);
    if (!job->edge_colors || !job->surface_type || !job->surface_uv || !job->surface_group)
        return tool_fail("out of memory for the %d quads of the polycube", job->polycube->surface->nfaces);
    /* axis_palettes = 1: the edges along each axis draw from two colours
       of the palette picked for that axis, the paper's scheme. */
    if (tt_polycube_edge_colors(job->polycube, job->layout.colors, 1, options->tiles.seed, job->edge_colors,
                                &error) != TT_OK ||
        tt_assign_boundaries(job->polycube->surface, &job->layout, options->tiles.seed, job->edge_colors,
                             job->surface_type, &error) != TT_OK)
        return tool_fail("%s: the polycube's tiles: %s", path, error.message);
    /* As few tiles as fit the atlas's limit: each set's count apart, each
       tile its own cell. */
    for (q = 0; q < job->polycube->surface->nfaces; q++)
        job->surface_group[q] = (uint8_t)(options->plain ? 0 : tt_polycube_quad_tileset(job->polycube, q));
    /* A photo laid in courses: every band upright, so no course shows
       mirrored about a tile's edge. */
    if (tt_reduce_tiles(job->polycube->surface, &job->layout, options->tiles.seed, job->edge_colors,
                        job->surface_group, polycube_tile_budget(options, &job->layout), NULL, job->surface_type,
                        NULL, &error) != TT_OK ||
        (!options->plain && options->tiles.courses.period > 0.0f &&
         tt_polycube_orient_upright(job->polycube, job->surface_type, NULL, &error) != TT_OK) ||
        tt_assign_uvs(job->polycube->surface, &job->layout, job->surface_type, job->surface_uv, &error) != TT_OK)
        return tool_fail("%s: the polycube's tiles: %s", path, error.message);
    return 0;
}

/* The upright tiles, on the plain tiles' edge windows: the atlas of every
   tile is the four sets, 2 x 2 in the order of tt_tileset_kind, as
   tt_polycube_mapping_uvs_upright reads it; S's own texture coordinates
   move into their quarters. An image too narrow for upright tiles (they
   need 2S x 2S) keeps the plain ones, with a note. */
static int synthesize_upright(const polycube_command_options *options, const tt_image *image, polycube_job *job)
{
    tt_error error;
    int status;
    if (image->width < 2 * job->layout.tile_size || image->height < 2 * job->layout.tile_size) {
        tool_note("%s: %dx%d is too small for upright %d-texel tiles (they need %dx%d): the tiles are plain, "
                  "turned a quarter on their left and right sides (use a smaller --tile)",
                  options->image_path, image->width, image->height, job->layout.tile_size,
                  2 * job->layout.tile_size, 2 * job->layout.tile_size);
        return 0;
    }
    if ((status = tiled_synthesize_upright(image, options->image_path, &options->tiles, job->tiles,
                                           job->upright_tiles, job->map_upright_tiles)) != 0)
        return status;
    job->upright = 1;
    /* surface_group holds each square's set (tile_polycube): S's own UVs in
       its set's quarter, as tt_polycube_mapping_uvs_upright puts the mesh's. */
    if (tt_assign_uvs_oriented(job->polycube->surface, &job->layout, job->surface_type, NULL, job->surface_group,
                               job->surface_uv, &error) != TT_OK)
        return tool_fail("%s: the polycube's tiles: %s", options->mesh_path, error.message);
    return 0;
}

/* The atlas of one map (-1: the colour) in parts: level 0 of each set, or
   of the plain set alone. Returns the parts each way (2, or 1). */
static int atlas_parts(const polycube_job *job, int map, const tt_image *parts[TT_TILESET_KINDS])
{
    int k;
    parts[TT_TILESET_PLAIN] = map < 0 ? &job->tiles->levels[0] : &job->map_tiles[map]->levels[0];
    if (!job->upright) return 1;
    for (k = 0; k < TILED_UPRIGHT_SETS; k++)
        parts[TT_TILESET_UPRIGHT + k] =
            map < 0 ? &job->upright_tiles[k]->levels[0] : &job->map_upright_tiles[k][map]->levels[0];
    return 2;
}

/* The atlas of the tiles S shows (tt_compact_atlas_create), cut from the
   tile sets (the atlas of every tile is never put together): S's texture
   coordinates move into it. */
static int compact_atlas(const polycube_command_options *options, polycube_job *job)
{
    const tt_mesh *surface = job->polycube->surface;
    const tt_image *parts[TT_TILESET_KINDS];
    tt_error error;
    int c, map, each_way = atlas_parts(job, -1, parts);
    tool_stage("packing the tiles S shows");
    job->full_width = each_way * parts[0]->width;
    job->full_height = each_way * parts[0]->height;
    if (tt_compact_atlas_create(surface, job->surface_uv, &job->layout, job->full_width, job->full_height,
                                options->max_atlas, NULL, &job->compact, &error) != TT_OK)
        return tool_fail("%s: the atlas: %s%s", options->mesh_path, error.message,
                         error.result == TT_ERROR_TOO_LARGE ? "; here: a larger --max-atlas, --colors 1 or a smaller --tile"
                                                            : "");
    if (tt_compact_atlas_image_parts(job->compact, parts, each_way, each_way, NULL, &job->atlas, &error) != TT_OK)
        return tool_fail("the %dx%d atlas: %s", job->compact->width, job->compact->height, error.message);
    for (map = 0; map < MATERIAL_MAPS; map++) {
        if (!job->map_tiles[map]) continue;
        atlas_parts(job, map, parts);
        if (tt_compact_atlas_image_parts(job->compact, parts, each_way, each_way, NULL, &job->map_atlas[map],
                                         &error) != TT_OK)
            return tool_fail("the %dx%d %s atlas: %s", job->compact->width, job->compact->height,
                             material_map_names[map], error.message);
    }
    for (c = 0; c < surface->ncorners; c++)
        tt_compact_atlas_uv(job->compact, surface->corner_face[c], &job->surface_uv[2 * c], &job->surface_uv[2 * c]);
    /* The compact atlases hold every texel the outputs use. */
    polycube_tilesets_free(job);
    return 0;
}

/* The triangles split along S's quads, with their texture coordinates. */
static int map_mesh(const polycube_command_options *options, polycube_job *job)
{
    tt_polycube_map_options map_options;
    tt_error error;
    tool_progress progress;
    tt_result result;
    double start = tool_seconds_now();
    int i;
    /* -j: the projection, the relaxation, the tracing and the split on the tool's threads (the same mapping). */
    memset(&map_options, 0, sizeof map_options);
    map_options.executor = tool_executor();
    tool_progress_begin(&progress, "mapping", "of the steps done");
    map_options.progress = tool_show_progress;
    map_options.progress_user_data = &progress;
    result = tt_polycube_map(job->polycube, job->mesh.mesh, &map_options, NULL, &job->mapping, &job->map_report,
                             &error);
    tool_progress_end(&progress);
    if (result != TT_OK) return triangle_mesh_report_error(options->mesh_path, &job->mesh, &error);
    job->map_seconds = tool_seconds_now() - start;
    /* Above 0.1 % (the target), the cuts show: say why they come and what may help. */
    if (job->map_report.fallback_triangles > 0.001 * job->map_report.triangles)
        tool_note("%s: %d of the %d triangles mapped (%.2g %%) have no seamless place on the polycube and show a cut each: "
                  "parts thinner than about two cubes, parts less than a cube apart (joined on the polycube), "
                  "handles the polycube lacks, or wide holes; try another --resolution, or hpm or lapped, which "
                  "need no polycube", options->mesh_path, job->map_report.fallback_triangles, job->map_report.triangles,
                  100.0 * job->map_report.fallback_triangles / job->map_report.triangles);
    job->corner_uv = (float *)malloc((size_t)job->mapping->ntriangles * 6 * sizeof(float));
    if (!job->corner_uv)
        return tool_fail("out of memory for the texture coordinates of %d triangles", job->mapping->ntriangles);
    if ((job->upright ? tt_polycube_mapping_uvs_upright : tt_polycube_mapping_uvs)(
            job->polycube, job->mapping, &job->layout, job->surface_type, job->corner_uv, &error) != TT_OK)
        return tool_fail("%s: the texture coordinates: %s", options->mesh_path, error.message);
    for (i = 0; i < 3 * job->mapping->ntriangles; i++)
        tt_compact_atlas_uv(job->compact, job->mapping->corner_points[i].quad, &job->corner_uv[2 * i],
                            &job->corner_uv[2 * i]);
    return 0;
}

/* ======================================================================== */
/* The measures and the summary                                             */
/* ======================================================================== */

typedef struct polycube_quality {
    tool_seams borders;             /* UV-discontinuous edges: the tiles' borders */
    tool_seams all;                 /* every interior edge */
    tool_seams corners;             /* S's squares near their corners, where 3 to 6 tiles meet */
    tt_uv_distortion_report distortion;
    int distortion_measured;
    char distortion_reason[224];    /* why the distortion was not measured */
    int mesh_built;                 /* 0: the mapped triangles made no tt_mesh, nothing was measured */
    char mesh_reason[TOOL_ERROR_SIZE];   /* why */
} polycube_quality;

/* The measures take a tt_mesh: the mapped triangles make one, the same
   surface as the input's, cut along the tiles' borders. */
static int measure_quality(const polycube_command_options *options, const polycube_job *job,
                           polycube_quality *quality)
{
    const tt_image *atlas = job->atlas;
    tt_mesh_desc desc;
    tt_mesh *mapped = NULL;
    tt_uv_distortion_options distortion;
    tt_error error;
    tt_result result;
    int status;
    memset(quality, 0, sizeof *quality);
    memset(&desc, 0, sizeof desc);
    desc.positions = job->mapping->positions;
    desc.nverts = job->mapping->nverts;
    desc.indices = job->mapping->triangles;
    desc.nfaces = job->mapping->ntriangles;
    desc.fixed_face_size = 3;
    /* Permissive: a triangle of no area (a sliver the split kept to close
       the surface) must not switch the whole report off; the measures
       count it as degenerate. */
    desc.flags = TT_MESH_PERMISSIVE;
    tool_stage("measuring the texture's stretch");
    if (tt_mesh_build(&desc, NULL, &mapped, &error) != TT_OK) {
        /* A report, not the job: the files are still right. */
        snprintf(quality->mesh_reason, sizeof quality->mesh_reason, "the mapped triangles: %s", error.message);
        return 0;
    }
    quality->mesh_built = 1;
    status = tool_measure_seams(options->mesh_path, mapped, job->corner_uv, atlas, options->tiles.seed,
                                TT_SEAM_UV_DISCONTINUOUS, NULL, 0, 0, 0.0f, &quality->borders);
    if (status == 0)
        status = tool_measure_seams(options->mesh_path, mapped, job->corner_uv, atlas, options->tiles.seed, 0, NULL,
                                    0, 0, 0.0f, &quality->all);
    /* The tiles' corners, on S's own squares: near the mapped triangles'
       corners the samples would mostly fall where a model edge crosses a
       square's edge, not at the square's corner. */
    if (status == 0)
        status = tool_measure_seams(options->mesh_path, job->polycube->surface, job->surface_uv, atlas,
                                    options->tiles.seed, 0, NULL, 0, 0, TOOL_CORNER_ENDS, &quality->corners);
    if (status == 0) {
        /* One tile covers one cube face: the intended density is the tile's
           texels over the cube's edge. */
        memset(&distortion, 0, sizeof distortion);
        distortion.texels_per_unit = job->layout.tile_size / job->polycube->h;
        result = tt_measure_uv_distortion(mapped, job->corner_uv, atlas->width, atlas->height, &distortion, NULL,
                                          &quality->distortion, &error);
        if (result == TT_OK)
            quality->distortion_measured = 1;
        else if (result == TT_ERROR_NOT_MEASURED)
            snprintf(quality->distortion_reason, sizeof quality->distortion_reason, "%s", error.message);
        else
            status = tool_fail("%s: cannot measure the distortion: %s", options->mesh_path, error.message);
    }
    tt_mesh_free(mapped);
    return status;
}

static void print_summary(const polycube_command_options *options, const polycube_job *job,
                          const polycube_quality *quality)
{
    const tt_polycube_report *b = &job->build_report;
    const tt_polycube_map_report *m = &job->map_report;
    const tt_polycube_projection_report *p = &m->projection;
    const tt_uv_distortion_report *d = &quality->distortion;
    char borders[320], all[320], corners[320];

    printf("%s: %d triangles", options->mesh_path, job->mesh.ntriangles);
    if (job->mesh.ntriangles != job->mesh.obj.nfaces) printf(" (fans of %d faces)", job->mesh.obj.nfaces);
    printf("; polycube: %d cubes of %.4g units (resolution %d), %d quads, %d component%s, genus %d", b->cubes,
           b->cube_size, b->resolution, b->quads, b->components, b->components == 1 ? "" : "s", b->polycube_genus);
    if (job->resolution_report.tries > 1) {
        /* How the resolution was chosen: per try, the genus where it differed, else how far the mesh lay. */
        const tt_polycube_resolution_report *r = &job->resolution_report;
        int i;
        printf(" (resolution chosen of");
        for (i = 0; i < r->tries; i++) {
            printf("%s %d: ", i ? "," : "", r->resolution[i]);
            if (r->mean_distance[i] < 0.0) printf("genus %d", r->genus[i]);
            else printf("%.2f cubes away", r->mean_distance[i]);
        }
        printf(")");
    }
    if (b->mesh_genus < 0 && b->sealed > 0) printf(" (the mesh's: not closed; %d cubes sealed behind its holes)\n", b->sealed);
    else if (b->mesh_genus < 0) printf(" (the mesh's: not closed)\n");
    else if (b->genus_differs) printf(" (the mesh's %d: they differ)\n", b->mesh_genus);
    else printf(" (as the mesh)\n");
    printf("mapping: %d triangles, %d split, %d fallback, %d failed edges, %d flipped, %d collapsed",
           job->mapping->ntriangles, m->split_triangles, m->fallback_triangles, m->failed_edges, m->flipped,
           m->collapsed);
    /* The library halves edges longer than a cube first, so that no
       triangle holds several corners of the polycube, and to half a cube
       where that mapping fell short. */
    if (m->triangles != job->mesh.ntriangles) printf(" (of %d after refining long edges)", m->triangles);
    if (m->refined_again) printf(" (%d input faces refined further, where a first mapping fell short)", m->refined_again);
    if (m->unpinched) printf(" (%d edges split where a triangle wrapped a saddle of the polycube)", m->unpinched);
    if (m->merged) printf(" (%d merged away, the triangles around keeping their stretch and density)", m->merged);
    printf("; smoothing: %d moves, %d vertices left as projected", m->smoothed, m->held);
    printf("; vertices onto the polycube: %d by rays, %d nearest, %d fallback, mean distance %.2f cubes\n", p->rays,
           p->nearest, p->fallbacks, p->mean_distance);
    printf("tiles: %d of the %s%d shown (n=%d, %d texels, gutter %d%s), in a %dx%d atlas (all would take %dx%d); "
           "%.4g texels per unit\n", job->compact->ncells, job->upright ? "4 x " : "",
           tt_tile_layout_tile_count(&job->layout), job->layout.colors, job->layout.tile_size, job->layout.gutter,
           job->upright ? "; upright, plain on a top's side beside a wall" : "", job->compact->width,
           job->compact->height, job->full_width, job->full_height, job->layout.tile_size / job->polycube->h);
    if (job->upright) {
        /* How the squares' tiles split among the four sets. */
        const tt_polycube *pc = job->polycube;
        int q, walls = 0, tops = 0, one_side = 0, plain = 0;
        for (q = 0; q < pc->surface->nfaces; q++) {
            const tt_tileset_kind kind = tt_polycube_quad_tileset(pc, q);
            if (pc->quad_side[q] / 2 != pc->up_axis) walls++;
            else if (kind == TT_TILESET_UPRIGHT) tops++;
            else if (kind == TT_TILESET_PLAIN) plain++;
            else one_side++;
        }
        printf("squares: %d walls upright; %d tops and bottoms: %d upright, %d with one side plain (beside a wall), "
               "%d plain\n", walls, tops + one_side + plain, tops, one_side, plain);
    }
    if (!quality->mesh_built) {
        printf("stretch and seam score: not measured (%s)\n", quality->mesh_reason);
    } else {
        if (quality->distortion_measured) {
            /* Percentiles, area-weighted: a maximum is one sliver's. */
            printf("stretch: p5 %.3f, median %.3f, p95 %.3f; texel density p5 %.2f, p95 %.2f of its median; "
                   "density error median %.1f%%, p95 %.1f%%; %d flipped UV triangle%s",
                   d->stretch_p5, d->stretch_median, d->stretch_p95, d->density_p5_over_median,
                   d->density_p95_over_median, 100.0 * d->density_median, 100.0 * d->density_p95, d->flipped,
                   d->flipped == 1 ? "" : "s");
            if (d->degenerate > 0) printf(", %d degenerate", d->degenerate);
            printf("\n");
        } else {
            printf("stretch: not measured (%s)\n", quality->distortion_reason);
        }
        tool_format_seams(&quality->borders, "border edges", borders, sizeof borders);
        tool_format_seams(&quality->all, "edges", all, sizeof all);
        tool_format_seams(&quality->corners, "square edges", corners, sizeof corners);
        printf("seam score: tile borders %s; all edges %s; near the squares' corners (within %.0f %% of an edge's "
               "ends) %s\n", borders, all, 100.0 * TOOL_CORNER_ENDS, corners);
    }
    printf("time: build %.2f s, synthesis %.2f s, mapping %.2f s\n", job->build_seconds, job->synth_seconds,
           job->map_seconds);
}

/* ======================================================================== */
/* The files                                                                */
/* ======================================================================== */

/* mapped_corner_normals' work, cut in ranges of triangles. */
typedef struct mapped_normals_job {
    const tt_mesh *input;
    const tt_polycube_mapping *mapping;
    const float *from;          /* the input's corner normals */
    float *out;                 /* 9 per mapped triangle */
} mapped_normals_job;

/* Mapped triangles [begin, end): each writes its own three normals. */
static void mapped_normals_range(void *context, int begin, int end)
{
    const mapped_normals_job *job = (const mapped_normals_job *)context;
    const tt_mesh *input = job->input;
    const tt_polycube_mapping *mapping = job->mapping;
    const float *from = job->from;
    int t, k, s, j;
    for (t = begin; t < end; t++) {
        int face = mapping->triangle_face[t];
        for (k = 0; k < 3; k++) {
            int v = mapping->triangles[3 * t + k];
            float *n = job->out + 9 * (size_t)t + 3 * k;
            double sum[3] = {0.0, 0.0, 0.0}, length;
            for (s = 0; s < 3; s++) {
                double w = mapping->weights[3 * (size_t)v + s];
                if (w == 0.0) continue;
                for (j = input->face_start[face]; j < input->face_start[face + 1]; j++)
                    if (input->corner_vert[j] == mapping->source[3 * (size_t)v + s]) {
                        sum[0] += w * from[3 * (size_t)j];
                        sum[1] += w * from[3 * (size_t)j + 1];
                        sum[2] += w * from[3 * (size_t)j + 2];
                    }
            }
            length = sqrt(sum[0] * sum[0] + sum[1] * sum[1] + sum[2] * sum[2]);
            n[0] = length > 0.0 ? (float)(sum[0] / length) : 0.0f;
            n[1] = length > 0.0 ? (float)(sum[1] / length) : 0.0f;
            n[2] = length > 0.0 ? (float)(sum[2] / length) : 0.0f;
        }
    }
}

/* The mapped triangles' corner normals: the input mesh's (the file's when
   every corner has one, else tt_corner_normals, so its creases stay),
   carried to each output vertex by the mapping's source vertices and
   weights within the input face the triangle is part of, renormalised.
   NULL when out of memory (said). */
static float *mapped_corner_normals(const char *path, const polycube_job *job)
{
    mapped_normals_job normals;
    float *from = tool_corner_normals(path, job->mesh.mesh, job->mesh.corner_normal);
    float *out = (float *)malloc(9 * (size_t)(job->mapping->ntriangles > 0 ? job->mapping->ntriangles : 1) *
                                 sizeof(float));
    if (!from || !out) {
        if (from && !out) tool_fail("out of memory for the normals of %s", path);
        free(from);
        free(out);
        return NULL;
    }
    normals.input = job->mesh.mesh;
    normals.mapping = job->mapping;
    normals.from = from;
    normals.out = out;
    /* -j: ranges of triangles on the tool's threads. */
    tool_parallel_ranges(tool_executor(), job->mapping->ntriangles, 8192, mapped_normals_range, &normals);
    free(from);
    return out;
}

/* The mapped triangles, one texture coordinate and one normal per corner,
   for either file. */
static void mapped_write_desc(const polycube_job *job, const float *normals, obj_write_desc *desc)
{
    memset(desc, 0, sizeof *desc);
    desc->nverts = job->mapping->nverts;
    desc->pos = job->mapping->positions;
    desc->nfaces = job->mapping->ntriangles;
    desc->fixed_face_size = 3;
    desc->corner_vert = job->mapping->triangles;
    desc->corner_uv = job->corner_uv;
    desc->corner_normal = normals;
}

/* OUT_PREFIX.obj: the mapped triangles. */
static int add_obj(tool_output *output, const char *path, const char *mtl_name, const polycube_job *job)
{
    char comment[512];
    obj_write_desc desc;
    float *normals = mapped_corner_normals(path, job);
    int status;
    if (!normals) return TOOL_EXIT_FAILURE;
    snprintf(comment, sizeof comment,
             "polycube texture by tiledtex %s (Chang and Lin): %d triangles over %d polycube quads of %.9g units,\n"
             "%d colors, %d-texel tiles, gutter %d",
             TILEDTEX_VERSION_STRING, job->mapping->ntriangles, job->polycube->surface->nfaces, job->polycube->h,
             job->layout.colors, job->layout.tile_size, job->layout.gutter);
    mapped_write_desc(job, normals, &desc);
    desc.comment = comment;
    desc.mtllib = mtl_name;
    desc.material = "tiled";
    /* The corners of a vertex in one tile share their vt, and those of a
       smooth vertex their vn: the file is 40 % as long. */
    desc.share_equal = 1;
    status = output_add_obj(output, path, &desc);
    free(normals);
    return status;
}

/* OUT_PREFIX.glb: the mapped triangles with `material`. The polycube's
   surface, a look at what the mesh was mapped onto, stays out of it: a GLB
   is the textured mesh to take to other programs, and the surface would
   enclose it. */
static int add_gltf(tool_output *output, const char *path, const polycube_job *job, const tool_material *material)
{
    obj_write_desc desc;
    float *normals = mapped_corner_normals(path, job);
    int status;
    if (!normals) return TOOL_EXIT_FAILURE;
    mapped_write_desc(job, normals, &desc);
    status = output_add_gltf(output, path, &desc, material);
    free(normals);
    return status;
}

/* OUT_PREFIX_polycube.obj: S with its own tiles, written the way `tile`
   writes a quad mesh (S is one, with the tiles' UVs). */
static int add_surface_obj(tool_output *output, const char *path, const char *mtl_name, const polycube_job *job,
                           int triangles)
{
    tiled_mesh surface;
    memset(&surface, 0, sizeof surface);
    surface.mesh = job->polycube->surface;
    surface.corner_uv = job->surface_uv;
    surface.layout = job->layout;
    return tiled_add_obj(output, path, &surface, mtl_name, triangles);
}

/* ======================================================================== */
/* The command                                                              */
/* ======================================================================== */

int cmd_polycube(int argc, char **argv)
{
    polycube_command_options options;
    polycube_job job;
    polycube_quality quality;
    tt_image *image = NULL;
    tool_output output = TOOL_OUTPUT_INIT;
    tt_courses photo_courses;
    tt_error error;
    char obj_path[4096], mtl_path[4096], png_path[4096], surface_path[4096], gltf_path[4096], written[8400],
        message[TOOL_ERROR_SIZE];
    char map_paths[MATERIAL_MAPS][4200];
    const char *map_names[MATERIAL_MAPS];
    int status, map, gltf;
    double start;

    memset(&job, 0, sizeof job);
    memset(&photo_courses, 0, sizeof photo_courses);
    status = parse_command_line(argc, argv, &options);
    if (status >= 0) return status;
    snprintf(obj_path, sizeof obj_path, "%s.obj", options.prefix);
    snprintf(mtl_path, sizeof mtl_path, "%s.mtl", options.prefix);
    snprintf(png_path, sizeof png_path, "%s.png", options.prefix);
    snprintf(surface_path, sizeof surface_path, "%s_polycube.obj", options.prefix);
    tool_output_path(options.prefix, tool_model_extension(&options.tiles.output), gltf_path, sizeof gltf_path);
    gltf = options.tiles.output.format != TOOL_FORMAT_OBJ;
    for (map = 0; map < MATERIAL_MAPS; map++) {
        material_path(map_paths[map], sizeof map_paths[map], options.prefix, map);
        map_names[map] = options.tiles.maps.paths[map] ? tool_basename(map_paths[map]) : NULL;
    }

    if ((status = triangle_mesh_read(options.mesh_path, NULL, &job.mesh)) != 0) return status;
    /* A photo: sRGB bytes in the file, linear light in the library. */
    if (image_load(options.image_path, TT_COLOR_SRGB, &image, message, sizeof message) != 0)
        status = tool_fail("%s", message);
    if (status == 0) status = tiled_pick_tile_size(options.image_path, image->width, image->height, &options.tiles);
    if (status == 0) status = material_load(&options.tiles.maps, options.image_path, image->width, image->height);
    /* Refuse, before the long part, outputs that would replace an input
       (the commit checks again). */
    if (status == 0 && gltf) status = tool_refuse_input_overwrite(gltf_path);
    if (status == 0 && !gltf) status = tool_refuse_input_overwrite(obj_path);
    if (status == 0 && !gltf) status = tool_refuse_input_overwrite(mtl_path);
    if (status == 0 && !gltf) status = tool_refuse_input_overwrite(png_path);
    if (status == 0 && !gltf) status = tool_refuse_input_overwrite(surface_path);
    if (status == 0 && !gltf) status = material_refuse_overwrite(&options.tiles.maps, options.prefix);

    if (status == 0) status = build_polycube(&options, &job);
    if (status == 0 && !options.plain)
        status = tiled_find_courses(image, options.image_path, &options.tiles, &photo_courses);
    if (status == 0 && !options.plain && !options.up_given)
        tool_note_courses_without_up(image, options.image_path, &photo_courses, TOOL_COURSES_DEFAULT_UP);
    if (status == 0) status = scale_tiles(&options, &job, image, photo_courses.period);
    if (status == 0) status = tiled_check_atlas_size(&options.tiles);
    if (status == 0 && tt_tile_layout_resolve(&options.tiles.layout, &job.layout, &error) != TT_OK)
        status = tool_fail("%s", error.message);
    if (status == 0 && !options.plain)
        status = tiled_fit_courses(&image, options.image_path, &options.tiles, &photo_courses);
    if (status == 0) status = tile_polycube(&options, &job);
    if (status == 0) {
        start = tool_seconds_now();
        /* The compact atlas is cut from level 0; the mip levels would only take memory. */
        options.tiles.levels = 1;
        status = tiled_synthesize(image, options.image_path, &options.tiles, &options.tiles.maps, &job.tiles,
                                  job.map_tiles);
        if (status == 0 && !options.plain) status = synthesize_upright(&options, image, &job);
        if (status == 0) status = compact_atlas(&options, &job);
        job.synth_seconds = tool_seconds_now() - start;
    }
    /* The photo and the maps are not needed past the synthesis; they are
       the largest things the command holds. */
    image_free(image);
    image = NULL;
    material_free(&options.tiles.maps);
    if (status == 0) status = map_mesh(&options, &job);
    if (status == 0) status = measure_quality(&options, &job, &quality);

    if (status == 0 && gltf) {
        tool_material material;
        const tt_image *map_images[MATERIAL_MAPS];
        memset(&material, 0, sizeof material);
        material.name = "tiled";
        material.base_color = job.atlas;
        for (map = 0; map < MATERIAL_MAPS; map++) map_images[map] = job.map_atlas[map];
        material_for_glb(&material, &options.tiles.maps, map_images);
        status = add_gltf(&output, gltf_path, &job, &material);
    }
    if (status == 0 && !gltf && output_add_png(&output, png_path, job.atlas, TT_COLOR_SRGB, message, sizeof message) != 0)
        status = tool_fail("%s", message);
    for (map = 0; map < MATERIAL_MAPS && status == 0 && !gltf; map++)
        if (job.map_atlas[map]) status = output_add_map_png(&output, map_paths[map], map, job.map_atlas[map]);
    if (status == 0 && !gltf) status = tiled_add_mtl(&output, mtl_path, tool_basename(png_path), map_names);
    if (status == 0 && !gltf) status = add_obj(&output, obj_path, tool_basename(mtl_path), &job);
    if (status == 0 && !gltf)
        status = add_surface_obj(&output, surface_path, tool_basename(mtl_path), &job, options.tiles.output.triangles);
    if (status == 0 && output_commit(&output, message, sizeof message) != 0) status = tool_fail("%s", message);

    if (status == 0 && !tool_quiet()) {
        print_summary(&options, &job, &quality);
        if (gltf) {
            printf("wrote %s\n", gltf_written(gltf_path, written, sizeof written));
        } else {
            printf("wrote %s, %s, %s, %s", obj_path, mtl_path, png_path, surface_path);
            for (map = 0; map < MATERIAL_MAPS; map++)
                if (job.map_atlas[map]) printf(", %s", map_paths[map]);
            printf("\n");
        }
    }
    output_free(&output);
    image_free(image);
    material_free(&options.tiles.maps);
    polycube_job_free(&job);
    return status;
}
