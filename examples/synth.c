/* synth.c - `tiledtex synth`: make a tiled-texture atlas from one image.

   Akleman et al. Sec. 4 as a library user calls it: load the photo into a
   tt_image, fill a tt_synth_options, call tt_synthesize_tiles. The atlas holds
   all (2n)^4 tiles, each placed where its name puts it (Sec. 2), so the UVs of
   `tiledtex map` with the same --colors/--tile/--gutter find them.

   Every tile ABCD = AXXX over XBXX over XXCX over XXXD over XXXX: a band per
   side taken from that side's edge window, over a background window of its
   own. Edge windows are S wide and 2S tall: the line between their upper and
   lower squares is what two tiles meeting across an edge continue.
*/
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tiled.h"

static void print_help(void)
{
    printf("usage: tiledtex synth IMAGE ATLAS.png [options]\n"
           "\n"
           "Make a tiled-texture atlas of (2n)^4 tiles from IMAGE (PNG, JPEG, TGA, BMP, ...).\n"
           "Tiles meet seamlessly in any arrangement `tiledtex map` gives them.\n"
           "ATLAS.png may be '-' (the standard output), but not with --mips.\n"
           "\n"
           "options:\n"
           "  --colors N             edge conditions n (default 1: 16 tiles; 2: 256 tiles)\n"
           "  --tile S               tile size in texels (default %d); IMAGE needs S x 2S at least\n"
           "  --gutter G             texels of gutter around each tile, 0 for none (default %d)\n"
           "  --seed K               random seed for the windows (default 0)\n"
           "  --edge X,Y             top-left of condition k's S x 2S edge window; give it once\n"
           "                         per condition (default: chosen from the seed)\n"
           "  --background X,Y,W,H   region the per-tile background windows come from\n"
           "                         (default: the whole image)\n"
           "  --mips                 also write the per-tile mip levels as ATLAS_mipL.png\n"
           MATERIAL_OPTIONS_HELP("                         ")
           "                         (here beside ATLAS.png: ATLAS_normal.png, ...; not with '-')\n",
           TT_DEFAULT_TILE_SIZE, TT_RECOMMENDED_GUTTER);
}


int cmd_synth(int argc, char **argv)
{
    const char *positional[2];
    int k, status, map;
    tiled_options options;
    tt_image *image = NULL;
    tt_tileset *tiles = NULL, *map_tiles[MATERIAL_MAPS];
    tool_output output;
    char message[TOOL_ERROR_SIZE], stem[TOOL_PREFIX_SIZE], map_paths[MATERIAL_MAPS][TOOL_PREFIX_SIZE + 32];

    memset(&output, 0, sizeof output);
    memset(map_tiles, 0, sizeof map_tiles);
    status = tiled_parse_command_line(argc, argv, TILED_LAYOUT_OPTIONS | TILED_SYNTH_OPTIONS | TILED_MATERIAL_OPTIONS,
                                      &options, positional, 2, "IMAGE and ATLAS.png", print_help);
    if (status >= 0) return status;

    if ((status = tool_refuse_stdout(positional[1], options.mips || material_count(&options.maps) > 0,
                                     "ATLAS.png with --mips or a material's maps")) != 0)
        return status;
    /* The maps' atlases go beside ATLAS.png: ATLAS_normal.png, ... */
    if (material_count(&options.maps) > 0 && tool_output_prefix(positional[1], NULL, stem) != 0)
        return TOOL_EXIT_USAGE;
    for (map = 0; map < MATERIAL_MAPS; map++) material_path(map_paths[map], sizeof map_paths[map], stem, map);
    if ((status = tiled_check_atlas_size(&options)) != 0) return status;
    /* A photo: sRGB in the file, linear light in the library. */
    if (image_load(positional[0], TT_COLOR_SRGB, &image, message, sizeof message) != 0)
        return tool_fail("%s", message);
    status = material_load(&options.maps, positional[0], image->width, image->height);
    if (status == 0) status = material_refuse_overwrite(&options.maps, stem);
    if (status == 0) status = tiled_synthesize(image, positional[0], &options, &options.maps, &tiles, map_tiles);
    image_free(image);       /* not needed past the synthesis, nor are the maps */
    image = NULL;
    material_free(&options.maps);
    if (status == 0) status = tiled_add_atlas(&output, positional[1], tiles, options.mips, TT_COLOR_SRGB);
    for (map = 0; map < MATERIAL_MAPS && status == 0; map++)
        if (map_tiles[map])
            status = tiled_add_atlas(&output, map_paths[map], map_tiles[map], options.mips, material_space(map));
    if (status == 0 && output_commit(&output, message, sizeof message) != 0) status = tool_fail("%s", message);
    if (status == 0 && !tool_quiet()) {
        printf("%s: %dx%d atlas of %d tiles (n=%d, %d texels, gutter %d) from %s; edge windows",
               positional[1], tiles->levels[0].width, tiles->levels[0].height,
               tt_tile_layout_tile_count(&tiles->layout), tiles->layout.colors, tiles->layout.tile_size,
               tiles->layout.gutter, positional[0]);
        for (k = 0; k < tiles->layout.colors; k++)
            printf(" %d,%d", tiles->edge_windows[k].x, tiles->edge_windows[k].y);
        printf("; seamless mip levels: %d", tiles->seamless_levels);
        for (map = 0, k = 0; map < MATERIAL_MAPS; map++)
            if (map_tiles[map]) printf("%s %s", k++ == 0 ? "; with" : ",", map_paths[map]);
        printf("\n");
    }
    output_free(&output);
    tiled_tilesets_free(&tiles, map_tiles);
    material_free(&options.maps);
    image_free(image);
    return status;
}
