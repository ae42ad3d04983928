/* tile.c - the learner's first program: Akleman et al.'s tiled textures.

   One quad of the mesh shows one whole tile. Each edge of the mesh gets a
   boundary condition and a side, so the two quads on an edge pick tiles
   whose borders along it are the same strip of the photo: every edge is
   seamless, whatever tiles meet there. The UVs depend on the boundary types
   alone; the tiles are cut from the photo afterwards.

       cc -std=c99 -O1 -Wall -Wextra -pedantic -I. examples/learn/tile.c -o learn_tile -lm
       ./learn_tile mesh.obj photo.png out      # writes out.obj, out.mtl, out.png
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
    tt_mesh *mesh = NULL, *quads = NULL;
    tt_image *photo = NULL;
    tt_tileset *tiles = NULL;
    tt_synth_options synth = {0};
    /* n = 1 condition (16 tiles), 128-texel tiles, and a gutter around each
       tile holding what lies across its edges, so that bilinear filtering
       at a tile's border reads the right neighbour. */
    tt_tile_layout layout = {1, 128, TT_RECOMMENDED_GUTTER};
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
    if (learn_obj_read(argv[1], 0, &obj) != 0) return 1;
    desc.positions = obj.positions;
    desc.nverts = obj.nverts;
    desc.indices = obj.indices;
    desc.face_sizes = obj.face_sizes;
    desc.nfaces = obj.nfaces;
    if (tt_mesh_build(&desc, NULL, &mesh, &error) != TT_OK) goto failed;

    /* The method textures quadrilateral meshes, one tile per quad (Sec. 3).
       Any other mesh becomes one by a subdivision step: each n-gon into n
       quads, the shape kept. */
    if (mesh->min_face_size != 4 || mesh->max_face_size != 4) {
        if (tt_mesh_quadrangulate(mesh, TT_SUBDIVIDE_LINEAR, NULL, &quads, &error) != TT_OK) goto failed;
        tt_mesh_free(mesh);
        mesh = quads;
    }

    /* The photo, decoded from sRGB into linear light, where the tiles'
       bands are blended. */
    bytes = stbi_load(argv[2], &width, &height, &channels, 0);
    if (!bytes) {
        fprintf(stderr, "cannot read %s: %s\n", argv[2], stbi_failure_reason());
        goto done;
    }
    decoded = tt_image_from_bytes(bytes, width, height, channels, 0, TT_COLOR_SRGB, NULL, &photo, &error);
    stbi_image_free(bytes);
    if (decoded != TT_OK) goto failed;

    types = (uint8_t *)malloc((size_t)mesh->ncorners);
    uv = (float *)malloc(2 * sizeof(float) * (size_t)mesh->ncorners);
    if (!types || !uv) {
        fprintf(stderr, "out of memory\n");
        goto done;
    }
    /* Sec. 3, AssignBoundaries: every edge a random condition k and side i;
       one half-edge gets type 2k + i, its twin 2k + 1 - i. */
    if (tt_assign_boundaries(mesh, &layout, 1 /* seed */, NULL, types, &error) != TT_OK) goto failed;
    /* Sec. 3, AssignTextureCoordinates: a quad's four types name its tile,
       and so its place in the atlas. */
    if (tt_assign_uvs(mesh, &layout, types, uv, &error) != TT_OK) goto failed;
    /* Sec. 4: the (2n)^4 tiles, each a background window of the photo with
       the edge window of each side's type laid along that side, cut where
       the two agree best. Zero options mean defaults; only the layout is ours. */
    synth.layout = layout;
    if (tt_synthesize_tiles(photo, &synth, NULL, &tiles, &error) != TT_OK) goto failed;

    if (learn_obj_write(argv[3], mesh->pos, mesh->nverts, mesh->corner_vert, mesh->ncorners, 4, uv,
                        &tiles->levels[0]) != 0)
        goto done;
    printf("tile: %d quads, %d tiles in a %dx%d atlas: wrote %s.obj, %s.mtl, %s.png\n", mesh->nfaces,
           tt_tile_layout_tile_count(&layout), tiles->levels[0].width, tiles->levels[0].height, argv[3], argv[3],
           argv[3]);
    status = 0;
    goto done;
failed:
    fprintf(stderr, "tile: %s\n", error.message);
done:
    tt_tileset_free(tiles);
    tt_image_free(photo);
    tt_mesh_free(mesh);
    free(types);
    free(uv);
    learn_obj_free(&obj);
    return status;
}
