/* tile.c - `tiledtex tile`: the whole tiled-texture job in one step.

   MESH + IMAGE -> OUT_PREFIX.obj (one UV per corner), OUT_PREFIX.mtl and
   OUT_PREFIX.png (the atlas): `tiledtex map` and `tiledtex synth` together,
   with the seam score measured on the result. Open the OBJ in Blender, or
   look at it with `tiledtex render OUT_PREFIX.obj OUT_PREFIX.png view.png`.
   With --up or --constraints the quads' tiles turn along the direction
   field (tiled_map_mesh), and the atlas holds four tile sets, plain and
   upright (tt_upright_atlas), as the polycube's.
*/
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tiled.h"

static void print_help(void)
{
    printf("usage: tiledtex tile MESH IMAGE OUT_PREFIX [options]\n"
           "\n"
           "Texture MESH from IMAGE with no seams: writes OUT_PREFIX.obj, OUT_PREFIX.mtl\n"
           "and OUT_PREFIX.png (the tile atlas). Triangles and n-gons are quadrangulated\n"
           "first; each quad shows one tile, so --subdivide makes the texture smaller on the\n"
           "surface.\n");
    tool_print_mesh_help(1);
    printf("OUT_PREFIX is a name without extension; one ending in .obj, .mtl or .png loses it\n"
           "('out.obj' writes out.obj, not out.obj.obj); one ending in .glb writes OUT_PREFIX.glb\n"
           "(--format glb), one ending in .gltf OUT_PREFIX.gltf (--format gltf). It may be '-' (the\n"
           "standard output) only for a GLB, one file.\n"
           "\n"
           "options:\n"
           "  --colors N             edge conditions n; (2n)^4 tiles (default 1)\n"
           "  --tile S               tile size in texels (default: %d, or what IMAGE can feed)\n"
           "  --gutter G             texels of gutter around each tile, 0 for none (default %d)\n"
           "  --seed K               random seed (default 0)\n"
           "  --subdivide L          quadrangulate L more times (smaller texture on the surface)\n"
           "  --smooth               Catmull-Clark positions when subdividing\n"
           "  --permissive           accept non-manifold or mis-oriented edges\n"
           "  --edge X,Y             condition k's S x 2S edge window, once per condition\n"
           "  --background X,Y,W,H   region the background windows come from\n"
           "  --mips                 also write the per-tile mip levels, OUT_PREFIX_mip1.png ...\n",
           TT_DEFAULT_TILE_SIZE, TT_RECOMMENDED_GUTTER);
    printf("  --up AXIS              turn each quad's tile so that its up follows AXIS (x, y, z, -x,\n"
           "                         -y, -z or X,Y,Z) along the surface, and give the quads upright\n"
           "                         tiles, which keep IMAGE's up on all four sides (bricks, planks\n"
           "                         and grain run level); a left or right side is plain where the\n"
           "                         field turns past a quad's diagonal: the atlas holds four sets,\n"
           "                         twice as wide and tall\n"
           "  --constraints FILE     the same, up given by lines FACE X Y Z [SIGMA [WEIGHT]] (FACE\n"
           "                         counts the OBJ's faces from 1), as 'tiledtex lapped' takes them\n"
           "  --remesh L             first remesh MESH into quads of side about L (mesh units, or\n"
           "                         'auto': 1/80 of its bounding-box diagonal) whose edges follow\n"
           "                         the field: with --up, rows of level quads on every wall, so a\n"
           "                         triangle scan shows courses level at the size you choose (the\n"
           "                         OBJ written is the new mesh; its vertices lie on MESH's faces)\n"
           "  --no-courses           with --up, take IMAGE as it is: by default a photo laid in\n"
           "                         courses (bricks, blocks) is resampled so that a tile holds a\n"
           "                         whole number of them, and every tile is cut on them\n"
           "  --report               also print tile usage and face stretch, and measure the\n"
           "                         seams on every edge (default: a sample of %d edges)\n"
           MATERIAL_OPTIONS_HELP("                         ")
           "  --format F             obj (default): the OBJ, MTL and PNG above; glb: one binary glTF\n"
           "                         file, OUT_PREFIX.glb, with the atlas in it; gltf: the same as\n"
           "                         glTF text, OUT_PREFIX.gltf, with OUT_PREFIX.bin and\n"
           "                         OUT_PREFIX_baseColor.png (and a PNG per map) beside it (neither\n"
           "                         with --mips)\n"
           "  --triangles            write each quad of the OBJ as two triangles, for programs that\n"
           "                         read only triangles (a GLB holds triangles anyway)\n"
           "\n"
           "A material's maps share IMAGE's tiles: the cuts are decided once, from IMAGE, and\n"
           "every map is cut and blended the same way, so the atlases line up texel for texel.\n"
           "\n"
           "Prints the mesh, the tiles and the seam score over every edge and near the tiles'\n"
           "corners, within 5 %% of each edge's ends, where three to six tiles meet (about 0: the\n"
           "texture continues, about 1: unrelated).\n",
           TOOL_REPORT_EDGES);
}

/* Level `level` of the four sets' atlas (tt_tileset_kind's quarters);
   prints the error. */
static int upright_atlas(const tt_tileset *plain, tt_tileset *const upright[TILED_UPRIGHT_SETS], int level,
                         tt_image **out)
{
    const tt_tileset *sets[TT_TILESET_KINDS];
    tt_error error;
    tiled_tileset_kinds(plain, upright, sets);
    if (tt_upright_atlas(sets, level, tool_executor(), NULL, out, &error) != TT_OK)
        return tool_fail("the %dx%d atlas: %s", 2 * plain->levels[level].width, 2 * plain->levels[level].height,
                         error.message);
    return 0;
}

/* tiled_add_atlas for the four sets' atlas: level 0 is made already, the
   mip levels (--mips) laid out as level 0's. */
static int add_upright_atlas(tool_output *output, const char *png_path, const tt_image *atlas,
                             const tt_tileset *plain, tt_tileset *const upright[TILED_UPRIGHT_SETS], int mips,
                             tt_color_space space)
{
    char message[TOOL_ERROR_SIZE], path[4096];
    size_t stem = strlen(png_path);
    int level, k, levels = plain->nlevels, status = 0;
    for (k = 0; k < TILED_UPRIGHT_SETS; k++) levels = upright[k]->nlevels < levels ? upright[k]->nlevels : levels;
    if (output_add_png(output, png_path, atlas, space, message, sizeof message) != 0)
        return tool_fail("%s", message);
    if (stem > 4 && strcmp(png_path + stem - 4, ".png") == 0) stem -= 4;
    for (level = 1; mips && status == 0 && level < levels; level++) {
        tt_image *image = NULL;
        snprintf(path, sizeof path, "%.*s_mip%d.png", (int)stem, png_path, level);
        if ((status = upright_atlas(plain, upright, level, &image)) == 0 &&
            output_add_png(output, path, image, space, message, sizeof message) != 0)
            status = tool_fail("%s", message);
        tt_image_free(image);
    }
    return status;
}

int cmd_tile(int argc, char **argv)
{
    const char *positional[3];
    int status;
    tiled_options options;
    tiled_mesh mesh;
    tt_image *image = NULL;
    tt_tileset *tiles = NULL, *map_tiles[MATERIAL_MAPS], *upright[TILED_UPRIGHT_SETS],
        *map_upright[TILED_UPRIGHT_SETS][MATERIAL_MAPS];
    tt_image *atlas = NULL, *map_atlas[MATERIAL_MAPS];
    tool_seams seams, corners;
    tool_level level;
    tool_output output;
    char message[TOOL_ERROR_SIZE], prefix[TOOL_PREFIX_SIZE], obj_path[4096], mtl_path[4096], png_path[4096],
        gltf_path[4096], written[8400];
    char map_paths[MATERIAL_MAPS][4200];
    const char *map_names[MATERIAL_MAPS];
    int map, gltf;

    memset(&output, 0, sizeof output);
    memset(&mesh, 0, sizeof mesh);
    memset(map_tiles, 0, sizeof map_tiles);
    memset(upright, 0, sizeof upright);
    memset(map_upright, 0, sizeof map_upright);
    memset(map_atlas, 0, sizeof map_atlas);
    status = tiled_parse_command_line(argc, argv,
                                      TILED_LAYOUT_OPTIONS | TILED_MESH_OPTIONS | TILED_SYNTH_OPTIONS |
                                          TILED_REPORT_OPTION | TILED_MATERIAL_OPTIONS | TILED_TRIANGLES_OPTION |
                                          TILED_FORMAT_OPTION | TILED_FIELD_OPTIONS,
                                      &options, positional, 3, "MESH, IMAGE and OUT_PREFIX", print_help);
    if (status >= 0) return status;
    if (options.remesh && options.field.constraints_path)
        return tool_usage("--remesh follows --up: not with --constraints, whose face numbers are the OBJ's");
    if (tool_output_prefix(positional[2], &options.output, prefix) != 0) return TOOL_EXIT_USAGE;
    gltf = options.output.format != TOOL_FORMAT_OBJ;
    /* The per-tile mip levels keep coarse levels from blending neighbouring
       tiles; a GLB has no place for them (its viewer makes its own). */
    if (gltf && options.mips) return tool_usage("--mips writes PNG files beside an OBJ: not with glTF (--format obj)");
    snprintf(obj_path, sizeof obj_path, "%s.obj", prefix);
    snprintf(mtl_path, sizeof mtl_path, "%s.mtl", prefix);
    snprintf(png_path, sizeof png_path, "%s.png", prefix);
    tool_output_path(prefix, tool_model_extension(&options.output), gltf_path, sizeof gltf_path);
    for (map = 0; map < MATERIAL_MAPS; map++) {
        material_path(map_paths[map], sizeof map_paths[map], prefix, map);
        map_names[map] = options.maps.paths[map] ? tool_basename(map_paths[map]) : NULL;
    }

    /* A photo: its 8-bit values are sRGB, the library works in linear light. */
    if (image_load(positional[1], TT_COLOR_SRGB, &image, message, sizeof message) != 0)
        return tool_fail("%s", message);
    status = tiled_pick_tile_size(positional[1], image->width, image->height, &options);
    if (status == 0 && !options.field.given && !options.no_courses)
        tool_note_courses_without_up(image, positional[1], NULL,
                                     "without --up each tile follows its quad, so they turn with the quads");
    if (status == 0) status = material_load(&options.maps, positional[1], image->width, image->height);
    if (status != 0) {
        image_free(image);
        return status;
    }
    status = tiled_check_atlas_size(&options);
    if (status == 0 && options.field.given) {
        /* Upright tiles cut their left and right bands from 2S x S windows
           beside the plain ones' S x 2S; the atlas of the four sets is twice
           as wide and twice as tall. */
        const int S = options.layout.tile_size ? options.layout.tile_size : TT_DEFAULT_TILE_SIZE;
        int side = 0;
        tt_tile_layout layout;
        tt_error error;
        if (tt_tile_layout_resolve(&options.layout, &layout, &error) == TT_OK)
            side = tt_tile_layout_atlas_size(&layout);
        options.upright = image->width >= 2 * S && image->height >= 2 * S;
        if (!options.upright)
            tool_note("%s is %dx%d: too small for upright %d-texel tiles (they need %dx%d): the tiles are turned "
                      "along --up, but plain, their left and right quarters turned a quarter (use a smaller --tile)",
                      positional[1], image->width, image->height, S, 2 * S, 2 * S);
        else if (2 * side > TOOL_MAX_ATLAS)
            status = tool_fail("--up makes a %dx%d atlas of plain and upright tiles; the tool writes at most %d "
                               "texels a side (use fewer --colors or a smaller --tile)", 2 * side, 2 * side,
                               TOOL_MAX_ATLAS);
    }
    if (status == 0 && options.upright) {
        status = tiled_fit_courses(&image, positional[1], &options, NULL);
    }
    if (status == 0) status = tiled_map_mesh(positional[0], &options, &mesh);
    /* Before the synthesis: no output may replace an input (checked again at the commit). */
    if (status == 0 && gltf) status = tool_refuse_input_overwrite(gltf_path);
    if (status == 0 && !gltf) status = tool_refuse_input_overwrite(obj_path);
    if (status == 0 && !gltf) status = tool_refuse_input_overwrite(mtl_path);
    if (status == 0 && !gltf) status = tool_refuse_input_overwrite(png_path);
    if (status == 0 && !gltf) status = material_refuse_overwrite(&options.maps, prefix);
    if (status == 0) status = tiled_synthesize(image, positional[1], &options, &options.maps, &tiles, map_tiles);
    if (status == 0 && mesh.face_upright) {
        status = tiled_synthesize_upright(image, positional[1], &options, tiles, upright, map_upright);
        if (status == 0) status = upright_atlas(tiles, upright, 0, &atlas);
        for (map = 0; map < MATERIAL_MAPS && status == 0; map++)
            if (map_tiles[map]) {
                tt_tileset *map_sets[TILED_UPRIGHT_SETS];
                int k;
                for (k = 0; k < TILED_UPRIGHT_SETS; k++) map_sets[k] = map_upright[k][map];
                status = upright_atlas(map_tiles[map], map_sets, 0, &map_atlas[map]);
            }
    }
    /* The photo and the maps are not needed past the synthesis: free them
       before the PNGs are encoded (they are the largest things the command
       holds). */
    image_free(image);
    image = NULL;
    material_free(&options.maps);
    if (status == 0)
        status = tool_measure_seams(positional[0], mesh.mesh, mesh.corner_uv, atlas ? atlas : &tiles->levels[0],
                                    options.seed, 0,
                                    NULL, 0, options.report, 0.0f, &seams);
    if (status == 0)
        status = tool_measure_seams(positional[0], mesh.mesh, mesh.corner_uv, atlas ? atlas : &tiles->levels[0],
                                    options.seed, 0, NULL, 0, options.report, TOOL_CORNER_ENDS, &corners);
    if (status == 0 && gltf) {
        tool_material material;
        const tt_image *map_atlases[MATERIAL_MAPS];
        for (map = 0; map < MATERIAL_MAPS; map++)
            map_atlases[map] = map_atlas[map] ? map_atlas[map] : map_tiles[map] ? &map_tiles[map]->levels[0] : NULL;
        memset(&material, 0, sizeof material);
        material.name = "tiled";
        material.base_color = atlas ? atlas : &tiles->levels[0];
        material_for_glb(&material, &options.maps, map_atlases);
        status = tiled_add_gltf(&output, gltf_path, &mesh, &material);
    }
    if (status == 0 && !gltf)
        status = atlas ? add_upright_atlas(&output, png_path, atlas, tiles, upright, options.mips, TT_COLOR_SRGB)
                       : tiled_add_atlas(&output, png_path, tiles, options.mips, TT_COLOR_SRGB);
    for (map = 0; map < MATERIAL_MAPS && status == 0 && !gltf; map++)
        if (map_atlas[map]) {
            tt_tileset *map_sets[TILED_UPRIGHT_SETS];
            int k;
            for (k = 0; k < TILED_UPRIGHT_SETS; k++) map_sets[k] = map_upright[k][map];
            status = add_upright_atlas(&output, map_paths[map], map_atlas[map], map_tiles[map], map_sets,
                                       options.mips, material_space(map));
        } else if (map_tiles[map])
            status = tiled_add_atlas(&output, map_paths[map], map_tiles[map], options.mips, material_space(map));
    if (status == 0 && !gltf) status = tiled_add_mtl(&output, mtl_path, tool_basename(png_path), map_names);
    if (status == 0 && !gltf)
        status = tiled_add_obj(&output, obj_path, &mesh, tool_basename(mtl_path), options.output.triangles);
    if (status == 0 && output_commit(&output, message, sizeof message) != 0) status = tool_fail("%s", message);
    if (status == 0) {
        /* Said only on success: a failing command prints its one error line. */
        tiled_print_notes(positional[0], &mesh);
        if (!tool_quiet()) {
            tiled_print_summary(positional[0], &mesh, &seams, &corners, options.report);
            if (mesh.face_turn) {
                /* Kinds 2 and 3 have one plain side, 0 two (or no direction). */
                int f, one_side = 0;
                for (f = 0; mesh.face_upright && f < mesh.mesh->nfaces; f++)
                    one_side += mesh.face_upright[f] >= TT_TILESET_RIGHT_PLAIN;
                printf("up: %d quads' tiles turned along the field, %d upright, %d with one side plain and %d plain "
                       "(a side is plain where the field turns past a quad's diagonal)\n", mesh.mesh->nfaces,
                       mesh.upright_faces, one_side, mesh.mesh->nfaces - mesh.upright_faces - one_side);
            }
            /* Each quad's tile turns by quarter turns only: on a mesh whose quads do not follow the field
               the courses tilt up to 45 degrees, which this line shows. */
            if (options.field.given && tool_measure_level(positional[0], mesh.mesh, mesh.corner_uv,
                                                          atlas ? atlas->width : tiles->levels[0].width,
                                                          atlas ? atlas->height : tiles->levels[0].height,
                                                          options.field.up, &level) == 0)
                tool_print_level(&level);
            if (gltf) {
                printf("wrote %s (%dx%d atlas)\n", gltf_written(gltf_path, written, sizeof written),
                       atlas ? atlas->width : tiles->levels[0].width, atlas ? atlas->height : tiles->levels[0].height);
            } else {
                printf("wrote %s, %s, %s", obj_path, mtl_path, png_path);
                for (map = 0; map < MATERIAL_MAPS; map++)
                    if (map_tiles[map]) printf(", %s", map_paths[map]);
                printf(" (%dx%d atlas)\n", atlas ? atlas->width : tiles->levels[0].width,
                       atlas ? atlas->height : tiles->levels[0].height);
            }
        }
    }
    output_free(&output);
    tiled_mesh_free(&mesh);
    tiled_tilesets_free(&tiles, map_tiles);
    tiled_upright_free(upright, map_upright);
    tt_image_free(atlas);
    for (map = 0; map < MATERIAL_MAPS; map++) tt_image_free(map_atlas[map]);
    material_free(&options.maps);
    image_free(image);
    return status;
}
