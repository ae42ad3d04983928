/* map.c - `tiledtex map`: give a mesh tiled-texture UVs.

   This is Akleman et al.'s mapping algorithm (Sec. 3) as a library user calls
   it; the steps are in tiled.c (tiled_map_mesh), which `tile` shares:

     tt_mesh_build          validate the OBJ's faces into a half-edge mesh
     tt_mesh_quadrangulate  only when there are triangles or n-gons: each
                            n-gon becomes n quads (and again per --subdivide)
     tt_assign_boundaries   a random boundary type per half-edge, twins
                            complementary (seeded: same seed, same result)
     tt_assign_uvs          one UV per corner: the tile named by its four
                            boundary types, at its place in the atlas

   The UVs depend only on --colors, --tile and --gutter, never on an image:
   any atlas `tiledtex synth` makes with the same three fits them.
*/
#include <stdio.h>
#include <string.h>

#include "tiled.h"

static void print_help(void)
{
    printf("usage: tiledtex map MESH OUT.obj [options]\n"
           "\n"
           "Give every face of MESH a tile of a tiled texture: writes OUT.obj with one\n"
           "texture coordinate per face corner. Triangles and n-gons are quadrangulated\n"
           "first (each n-gon into n quads). The UVs fit any atlas that `tiledtex synth`\n"
           "makes with the same --colors, --tile and --gutter.\n");
    tool_print_mesh_help(1);
    printf("OUT.obj may be '-' (the standard output), but not with --atlas, which adds OUT.mtl.\n"
           "\n"
           "options:\n"
           "  --colors N       edge conditions n; the atlas holds (2n)^4 tiles (default 1)\n"
           "  --tile S         tile size in texels (default %d, or read off --atlas)\n"
           "  --gutter G       texels of gutter around each tile, 0 for none (default %d)\n"
           "  --seed K         random seed for the boundary types (default 0)\n"
           "  --subdivide L    quadrangulate L more times: smaller faces, smaller texture\n"
           "  --smooth         use Catmull-Clark positions when subdividing (default: keep the shape)\n"
           "  --atlas A.png    also write OUT.mtl naming A.png, and report the seam score\n"
           "  --permissive     accept non-manifold or mis-oriented edges (they become boundaries)\n"
           "  --report         also print tile usage and face stretch, and measure the seams on\n"
           "                   every edge (default: a sample of %d edges)\n"
           "  --triangles      write each quad as two triangles (same texture coordinates), for\n"
           "                   programs that read only triangles\n",
           TT_DEFAULT_TILE_SIZE, TT_RECOMMENDED_GUTTER, TOOL_REPORT_EDGES);
}


/* With --atlas: the atlas must have the layout's size. When --tile was not
   given, the tile size is read off the atlas instead (W = T * (S + 2g)). */
static int load_atlas_for_layout(const char *path, tiled_options *options, tt_image **out_atlas)
{
    char message[TOOL_ERROR_SIZE];
    tt_tile_layout layout;
    tt_error error;
    int tiles_per_side;
    tt_image *atlas;
    /* An atlas is colour (sRGB in the file); the seam measure compares it
       as displayed. */
    if (image_load(path, TT_COLOR_SRGB, out_atlas, message, sizeof message) != 0) return tool_fail("%s", message);
    atlas = *out_atlas;
    if (tt_tile_layout_resolve(&options->layout, &layout, &error) != TT_OK) {
        image_free(atlas);
        *out_atlas = NULL;
        return tool_fail("%s", error.message);
    }
    tiles_per_side = tt_tile_layout_tiles_per_side(&layout);
    if (!options->tile_size_given && atlas->width == atlas->height && atlas->width % tiles_per_side == 0 &&
        atlas->width / tiles_per_side - 2 * layout.gutter >= 4)
        options->layout.tile_size = layout.tile_size = atlas->width / tiles_per_side - 2 * layout.gutter;
    if (atlas->width != tt_tile_layout_atlas_size(&layout) || atlas->height != atlas->width) {
        int expected = tt_tile_layout_atlas_size(&layout), width = atlas->width, height = atlas->height;
        image_free(atlas);
        *out_atlas = NULL;
        return tool_fail("%s is %dx%d, but --colors %d --tile %d --gutter %d make %dx%d atlases", path, width,
                         height, layout.colors, layout.tile_size, layout.gutter, expected, expected);
    }
    return 0;
}

int cmd_map(int argc, char **argv)
{
    const char *positional[2];
    int status;
    tiled_options options;
    tiled_mesh mesh;
    tt_image *atlas = NULL;
    tool_seams seams, corners;
    tool_output output;
    char message[TOOL_ERROR_SIZE], mtl_path[4096];

    memset(&output, 0, sizeof output);
    status = tiled_parse_command_line(argc, argv,
                                      TILED_LAYOUT_OPTIONS | TILED_MESH_OPTIONS | TILED_ATLAS_OPTION | TILED_REPORT_OPTION |
                                          TILED_TRIANGLES_OPTION,
                                      &options, positional, 2, "MESH and OUT.obj", print_help);
    if (status >= 0) return status;
    if ((status = tool_refuse_stdout(positional[1], options.atlas_path != NULL, "OUT.obj with --atlas")) != 0)
        return status;

    if (options.atlas_path && (status = load_atlas_for_layout(options.atlas_path, &options, &atlas)) != 0)
        return status;
    if ((status = tiled_check_atlas_size(&options)) != 0 ||
        (status = tiled_map_mesh(positional[0], &options, &mesh)) != 0) {
        image_free(atlas);
        return status;
    }
    if (options.atlas_path) {
        char texture[4096];
        status = tool_measure_seams(positional[0], mesh.mesh, mesh.corner_uv, atlas, options.seed, 0, NULL, 0,
                                    options.report, 0.0f, &seams);
        if (status == 0)
            status = tool_measure_seams(positional[0], mesh.mesh, mesh.corner_uv, atlas, options.seed, 0, NULL, 0,
                                        options.report, TOOL_CORNER_ENDS, &corners);
        if (status != 0) goto done;
        /* The MTL sits beside the OBJ, and names the atlas relative to itself. */
        snprintf(mtl_path, sizeof mtl_path, "%.*s.mtl",
                 (int)(strlen(positional[1]) > 4 && strcmp(positional[1] + strlen(positional[1]) - 4, ".obj") == 0
                           ? strlen(positional[1]) - 4 : strlen(positional[1])),
                 positional[1]);
        tool_relative_path(options.atlas_path, mtl_path, texture, sizeof texture);
        status = tiled_add_mtl(&output, mtl_path, texture, NULL);
        if (status == 0) status = tiled_add_obj(&output, positional[1], &mesh, tool_basename(mtl_path),
                                                options.output.triangles);
    } else {
        status = tiled_add_obj(&output, positional[1], &mesh, NULL, options.output.triangles);
    }
    if (status == 0 && output_commit(&output, message, sizeof message) != 0) status = tool_fail("%s", message);
    if (status == 0) {
        tiled_print_notes(positional[0], &mesh);
        if (!tool_quiet())
            tiled_print_summary(positional[0], &mesh, options.atlas_path ? &seams : NULL,
                                options.atlas_path ? &corners : NULL, options.report);
    }
done:
    output_free(&output);
    tiled_mesh_free(&mesh);
    image_free(atlas);
    return status;
}
