/* polycube.c - the learner's fourth program: Chang and Lin's polycube maps
   with Wang tiles.

   Tiled textures (tile.c) need a quad mesh whose quads are all about the
   same size. This method makes one that fits any shape: a polycube, the
   outer surface S of the cubes of a grid that the model passes through.
   S is tiled as tile.c tiles a quad mesh, and the model is mapped onto S,
   each of its triangles cut where S's quad edges cross it, so every piece
   takes its texture from one tile.

       cc -std=c99 -O1 -Wall -Wextra -pedantic -I. examples/learn/polycube.c -o learn_polycube -lm
       ./learn_polycube mesh.obj photo.png out  # writes out.obj, out.mtl, out.png
*/
#include <stdio.h>
#include <stdlib.h>
#define STB_IMAGE_IMPLEMENTATION
#include <stb/stb_image.h>          /* Debian's libstb-dev */
#define TILEDTEX_IMPLEMENTATION
#include "tiledtex.h"
#include "learn_obj.h"              /* OBJ in; OBJ + MTL + PNG out */

int main(int argc, char **argv)
{
    learn_mesh obj;
    tt_mesh_desc desc = {0};
    tt_mesh *mesh = NULL;
    tt_image *photo = NULL;
    tt_polycube *polycube = NULL;
    tt_polycube_report cubes;
    tt_polycube_mapping *mapping = NULL;
    tt_polycube_map_report mapped;
    tt_tileset *tiles = NULL;
    tt_synth_options synth = {0};
    /* Wang tiles with n = 2 conditions (256 tiles) of 64 texels, with
       gutters for filtering, as in tile.c. */
    tt_tile_layout layout = {2, 64, TT_RECOMMENDED_GUTTER};
    int *edge_colors = NULL;
    uint8_t *types = NULL;
    float *uv = NULL;
    unsigned char *bytes;
    int width, height, channels, status = 1;
    tt_result decoded;
    tt_error error;

    if (argc != 4) {
        fprintf(stderr, "usage: %s MESH.obj PHOTO OUT_PREFIX   (writes OUT_PREFIX.obj, .mtl, .png)\n", argv[0]);
        return 2;
    }
    if (learn_obj_read(argv[1], 1, &obj) != 0) return 1;   /* 1: as triangles, which the mapping cuts */
    desc.positions = obj.positions;
    desc.nverts = obj.nverts;
    desc.indices = obj.indices;
    desc.nfaces = obj.nfaces;
    desc.fixed_face_size = 3;
    if (tt_mesh_build(&desc, NULL, &mesh, &error) != TT_OK) goto failed;

    bytes = stbi_load(argv[2], &width, &height, &channels, 0);
    if (!bytes) {
        fprintf(stderr, "cannot read %s: %s\n", argv[2], stbi_failure_reason());
        goto done;
    }
    decoded = tt_image_from_bytes(bytes, width, height, channels, 0, TT_COLOR_SRGB, NULL, &photo, &error);
    stbi_image_free(bytes);
    if (decoded != TT_OK) goto failed;

    /* Sec. 3.1: the automatic polycube. The cubes of a grid (16 along the
       model's longest side) that its surface meets, the inside filled,
       cubes added where S would not be a manifold; S gets one quad per
       exposed cube face, each turned so that its tile's up follows +Y on
       the walls. */
    if (tt_polycube_build(mesh, NULL, NULL, &polycube, &cubes, &error) != TT_OK) goto failed;

    edge_colors = (int *)malloc(sizeof(int) * (size_t)polycube->surface->ncorners);
    types = (uint8_t *)malloc((size_t)polycube->surface->ncorners);
    if (!edge_colors || !types) {
        fprintf(stderr, "out of memory\n");
        goto done;
    }
    /* Sec. 3.2: the Wang colouring of S's edges. The edges fall into three
       groups by their axis, each group draws two of the colours (here n = 2:
       both) and each edge one of its group's. Then, as in tile.c, each
       half-edge's boundary type from its edge's colour and a random side. */
    if (tt_polycube_edge_colors(polycube, layout.colors, 1 /* per-axis groups */, 1 /* seed */, edge_colors,
                                &error) != TT_OK)
        goto failed;
    if (tt_assign_boundaries(polycube->surface, &layout, 1, edge_colors, types, &error) != TT_OK) goto failed;
    /* The tiles themselves, from the photo, as tile.c makes them. */
    synth.layout = layout;
    if (tt_synthesize_tiles(photo, &synth, NULL, &tiles, &error) != TT_OK) goto failed;

    /* Sec. 4: the model mapped onto S. Its triangles are refined, each
       vertex projected onto S and the points relaxed where triangles fold,
       and each triangle cut along S's quad edges into pieces inside one
       quad (Sec. 4.2-4.3 do this with cells; here the quads of S are the
       cells). The output is a new mesh with the same shape. */
    if (tt_polycube_map(polycube, mesh, NULL, NULL, &mapping, &mapped, &error) != TT_OK) goto failed;
    uv = (float *)malloc(6 * sizeof(float) * (size_t)mapping->ntriangles);
    if (!uv) {
        fprintf(stderr, "out of memory\n");
        goto done;
    }
    /* Sec. 4.3: each piece's points on its quad (s, t in [0, 1]) become
       texture coordinates inside that quad's tile. */
    if (tt_polycube_mapping_uvs(polycube, mapping, &layout, types, uv, &error) != TT_OK) goto failed;

    if (learn_obj_write(argv[3], mapping->positions, mapping->nverts, mapping->triangles, 3 * mapping->ntriangles,
                        3, uv, &tiles->levels[0]) != 0)
        goto done;
    printf("polycube: %d cubes, %d quads on S, %d triangles mapped onto %d (%d put whole in one quad): "
           "wrote %s.obj, %s.mtl, %s.png\n", cubes.cubes, cubes.quads, mesh->nfaces, mapping->ntriangles,
           mapped.fallback_triangles, argv[3], argv[3], argv[3]);
    status = 0;
    goto done;
failed:
    fprintf(stderr, "polycube: %s\n", error.message);
done:
    tt_polycube_mapping_free(mapping);
    tt_tileset_free(tiles);
    tt_polycube_free(polycube);
    tt_image_free(photo);
    tt_mesh_free(mesh);
    free(edge_colors);
    free(types);
    free(uv);
    learn_obj_free(&obj);
    return status;
}
