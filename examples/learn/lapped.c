/* lapped.c - the learner's second program: Praun, Finkelstein and Hoppe's
   lapped textures (SIGGRAPH 2000).

   Copies of one texture patch, a soft-edged splotch cut from the photo, are
   pasted over the surface one after another, each aligned with a smooth
   field of "up" directions, until every face is covered. The overlapping
   soft edges hide where pastes meet. Drawing the pastes needs a renderer
   that blends them; here they are baked into one atlas instead, so any
   viewer shows an ordinary textured OBJ.

       cc -std=c99 -O1 -Wall -Wextra -pedantic -I. examples/learn/lapped.c -o learn_lapped -lm
       ./learn_lapped mesh.obj photo.png out    # writes out.obj, out.mtl, out.png
*/
#include <stdio.h>
#include <stdlib.h>
#define STB_IMAGE_IMPLEMENTATION
#include <stb/stb_image.h>          /* Debian's libstb-dev */
#define TILEDTEX_IMPLEMENTATION
#include "tiledtex.h"
#include "learn_obj.h"              /* OBJ in; OBJ + MTL + PNG out */

#define ATLAS_SIZE 1024             /* texels a side of the baked texture */
#define ATLAS_GUTTER 2              /* texels of margin around each chart, filled by the bake */

int main(int argc, char **argv)
{
    learn_mesh obj;
    tt_mesh_desc desc = {0};
    tt_mesh *mesh = NULL;
    tt_image *photo = NULL, *patch = NULL, *atlas = NULL;
    tt_lapped *pastes = NULL;
    tt_chart_atlas_report charts;
    tt_bake_options bake = {0};
    float *field = NULL, *uv = NULL;
    unsigned char *bytes;
    int width, height, channels, status = 1;
    tt_result decoded;
    tt_error error;

    if (argc != 4) {
        fprintf(stderr, "usage: %s MESH.obj PHOTO OUT_PREFIX   (writes OUT_PREFIX.obj, .mtl, .png)\n", argv[0]);
        return 2;
    }
    if (learn_obj_read(argv[1], 1, &obj) != 0) return 1;   /* 1: as triangles, which the method pastes */
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

    field = (float *)malloc(3 * sizeof(float) * (size_t)mesh->nfaces);
    uv = (float *)malloc(2 * sizeof(float) * (size_t)mesh->ncorners);
    if (!field || !uv) {
        fprintf(stderr, "out of memory\n");
        goto done;
    }
    /* Sec. 3.2: a vector per face, in its plane: the direction in which the
       patch's up should run there, and by its length the patch's size
       (by default +Y made smooth over the surface, a tenth of the mesh's
       bounding-box diagonal long). */
    if (tt_tangent_field(mesh, NULL, NULL, field, &error) != TT_OK) goto failed;
    /* Sec. 3.1: the texture patch, the photo under a soft irregular splotch
       mask whose alpha falls off over a few texels at its border. */
    if (tt_make_texture_patch(photo, NULL, NULL, NULL, &patch, &error) != TT_OK) goto failed;
    /* Sec. 3.3-3.6: the paste loop. Pick an uncovered face, grow a surface
       patch around it while it stays a disc and inside the patch's outline,
       align its map with the field by least squares, record the paste, mark
       the faces it covers; repeat until all are. Then Sec. 4: faces hidden
       by later pastes are dropped from earlier ones. */
    if (tt_lapped_paste(mesh, field, &patch, 1, NULL, NULL, &pastes, &error) != TT_OK) goto failed;

    /* Sec. 4, "rendering with a texture atlas": cut the mesh into charts of
       faces that face about the same way, lay them flat side by side in one
       square, and composite every paste of each face into its place. */
    if (tt_atlas_pack_charts(mesh, ATLAS_SIZE, ATLAS_GUTTER, NULL, NULL, uv, &charts, &error) != TT_OK) goto failed;
    if (tt_image_create(ATLAS_SIZE, ATLAS_SIZE, NULL, &atlas, &error) != TT_OK) goto failed;
    bake.gutter = ATLAS_GUTTER;     /* fill the charts' margins, so filtering at their borders reads them */
    if (tt_lapped_bake(mesh, pastes, &patch, 1, uv, &bake, NULL, atlas, &error) != TT_OK) goto failed;

    if (learn_obj_write(argv[3], mesh->pos, mesh->nverts, mesh->corner_vert, mesh->ncorners, 3, uv, atlas) != 0)
        goto done;
    printf("lapped: %d triangles, %d pastes (each face drawn %.1f times), baked in %d charts of a %dx%d atlas: "
           "wrote %s.obj, %s.mtl, %s.png\n", mesh->nfaces, pastes->npastes, pastes->mean_overdraw, charts.ncharts,
           ATLAS_SIZE, ATLAS_SIZE, argv[3], argv[3], argv[3]);
    status = 0;
    goto done;
failed:
    fprintf(stderr, "lapped: %s\n", error.message);
done:
    tt_lapped_free(pastes);
    tt_image_free(atlas);
    tt_image_free(patch);
    tt_image_free(photo);
    tt_mesh_free(mesh);
    free(field);
    free(uv);
    learn_obj_free(&obj);
    return status;
}
