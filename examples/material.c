/* material.c - the maps of a material beside its colour: --normal,
   --roughness, --metallic, --ao, --height, --normal-y-down.

   A material is several images that must line up texel for texel. The
   commands that make textures (tile, lapped, hpm, polycube) decide their
   layout once, from the colour image (IMAGE), and apply it to every map
   given here: one plan of tiles, one set of pastes, one set of UVs. What
   this file does is what they share: reading the options, loading the maps
   the right way (a normal map as vectors, data maps as they are, never
   through the sRGB curve), naming the outputs and writing them.
*/
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tool.h"

const char *const material_map_names[MATERIAL_MAPS] = {"normal", "roughness", "metallic", "ao", "height"};

/* The option that gives each map, named in its messages. */
static const char *const map_options[MATERIAL_MAPS] = {"--normal", "--roughness", "--metallic", "--ao", "--height"};

int material_parse_option(int argc, char **argv, int *index, material_maps *maps)
{
    const char *value;
    int map;
    if (tool_flag(argv[*index], "--normal-y-down")) {
        maps->normal_y_down = 1;
        return 1;
    }
    for (map = 0; map < MATERIAL_MAPS; map++)
        if (tool_option(argc, argv, index, map_options[map], &value)) {
            if (!value || !*value) {
                tool_usage("%s needs an image", map_options[map]);
                return -1;
            }
            maps->paths[map] = value;
            return 1;
        }
    return 0;
}

int material_count(const material_maps *maps)
{
    int map, count = 0;
    for (map = 0; map < MATERIAL_MAPS; map++) count += maps->paths[map] != NULL;
    return count;
}

int material_load(material_maps *maps, const char *image_path, int width, int height)
{
    char message[TOOL_ERROR_SIZE];
    int map;
    if (maps->normal_y_down && !maps->paths[MATERIAL_NORMAL])
        return tool_usage("--normal-y-down says how --normal N.png is encoded, but no --normal was given");
    for (map = 0; map < MATERIAL_MAPS; map++) {
        tt_color_space space = TT_COLOR_LINEAR;
        tt_image *image;
        size_t i, count;
        if (!maps->paths[map]) continue;
        if (map == MATERIAL_NORMAL) space = maps->normal_y_down ? TT_COLOR_NORMAL_Y_DOWN : TT_COLOR_NORMAL;
        if (image_load(maps->paths[map], space, &maps->images[map], message, sizeof message) != 0) {
            material_free(maps);
            return tool_fail("%s: %s", map_options[map], message);
        }
        image = maps->images[map];
        if (image->width != width || image->height != height) {
            int status = tool_fail("%s %s is %dx%d but %s is %dx%d: every map of a material must have the colour "
                                   "image's size, texel for texel",
                                   map_options[map], maps->paths[map], image->width, image->height, image_path, width,
                                   height);
            material_free(maps);
            return status;
        }
        /* A map's alpha means nothing here: the colour image's (or the
           splotch's) decides where a paste shows, for every map alike. */
        count = (size_t)width * (size_t)height;
        for (i = 0; i < count; i++) image->pixels[4 * i + 3] = 1.0f;
    }
    return 0;
}

void material_free(material_maps *maps)
{
    int map;
    for (map = 0; map < MATERIAL_MAPS; map++) {
        image_free(maps->images[map]);
        maps->images[map] = NULL;
    }
}

tt_color_space material_space(int map)
{
    /* Normal maps are written +Y up whatever they came as: glTF's and
       Blender's convention (--normal-y-down only says how the input is). */
    return map == MATERIAL_NORMAL ? TT_COLOR_NORMAL : TT_COLOR_LINEAR;
}

void material_path(char *path, size_t size, const char *stem, int map)
{
    snprintf(path, size, "%s_%s.png", stem, material_map_names[map]);
}

int material_refuse_overwrite(const material_maps *maps, const char *stem)
{
    char path[4200];
    int map, status = 0;
    for (map = 0; map < MATERIAL_MAPS && status == 0; map++) {
        if (!maps->paths[map]) continue;
        material_path(path, sizeof path, stem, map);
        status = tool_refuse_input_overwrite(path);
    }
    return status;
}

void material_for_glb(tool_material *material, const material_maps *maps, const tt_image *const *images)
{
    material->normal = images[MATERIAL_NORMAL];
    material->roughness = images[MATERIAL_ROUGHNESS];
    material->metallic = images[MATERIAL_METALLIC];
    material->occlusion = images[MATERIAL_AO];
    if (maps->paths[MATERIAL_HEIGHT])
        tool_note("glTF has no height map: %s is not in the GLB (the OBJ output writes it)", maps->paths[MATERIAL_HEIGHT]);
}

int output_add_map_png(tool_output *output, const char *path, int map, const tt_image *image)
{
    char message[TOOL_ERROR_SIZE];
    size_t i, count = (size_t)image->width * (size_t)image->height;
    unsigned char *rgba = (unsigned char *)malloc(count * 4);
    int status;
    if (!rgba) return tool_fail("out of memory while writing %s", path);
    image_to_rgba8(image, material_space(map), rgba);
    /* Written opaque: a map has no coverage of its own (a baked one's alpha
       is the colour's coverage, which the colour PNG carries). */
    for (i = 0; i < count; i++) rgba[4 * i + 3] = 255;
    status = output_add_png_rgba8(output, path, rgba, image->width, image->height, message, sizeof message);
    free(rgba);
    return status != 0 ? tool_fail("%s", message) : 0;
}
