/* hpm.c - the learner's third program: Soler, Cani and Angelidis'
   hierarchical pattern mapping (SIGGRAPH 2002).

   No new image is made: every face gets texture coordinates into the photo
   itself. The mesh is cut into a hierarchy of clusters, from whole parts
   down to single faces; coarse to fine, each cluster is flattened and
   placed where the photo best continues the clusters already textured
   around it. A cluster that fits nowhere well enough is split and its
   children try again, so large pieces of the photo land on the surface
   whole and only the places that need it get small ones.

       cc -std=c99 -O1 -Wall -Wextra -pedantic -I. examples/learn/hpm.c -o learn_hpm -lm
       ./learn_hpm mesh.obj photo.png out       # writes out.obj, out.mtl, out.png (the photo)
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
    tt_hpm_report report;
    float *uv = NULL;
    unsigned char *bytes;
    int width, height, channels, status = 1;
    tt_result decoded;
    tt_error error;

    if (argc != 4) {
        fprintf(stderr, "usage: %s MESH.obj PHOTO OUT_PREFIX   (writes OUT_PREFIX.obj, .mtl, .png)\n", argv[0]);
        return 2;
    }
    if (learn_obj_read(argv[1], 1, &obj) != 0) return 1;   /* 1: as triangles, which the method flattens */
    desc.positions = obj.positions;
    desc.nverts = obj.nverts;
    desc.indices = obj.indices;
    desc.nfaces = obj.nfaces;
    desc.fixed_face_size = 3;
    if (tt_mesh_build(&desc, NULL, &mesh, &error) != TT_OK) goto failed;

    /* The photo in linear light: the fits compare its colours. */
    bytes = stbi_load(argv[2], &width, &height, &channels, 0);
    if (!bytes) {
        fprintf(stderr, "cannot read %s: %s\n", argv[2], stbi_failure_reason());
        goto done;
    }
    decoded = tt_image_from_bytes(bytes, width, height, channels, 0, TT_COLOR_SRGB, NULL, &photo, &error);
    stbi_image_free(bytes);
    if (decoded != TT_OK) goto failed;

    uv = (float *)malloc(2 * sizeof(float) * (size_t)mesh->ncorners);
    if (!uv) {
        fprintf(stderr, "out of memory\n");
        goto done;
    }
    /* The whole method in one call, with default options (NULL); the steps:
         Sec. 3.1  the face-cluster hierarchy: level 0 a cluster per part,
                   each cluster split into discs by a geodesic Voronoi
                   partition, down to single faces;
         Sec. 3.2  each cluster flattened over its border (a harmonic map),
                   split instead when that distorts it too much;
         Sec. 2.2  the traversal, coarse to fine, the cluster with the most
                   textured neighbours first;
         Sec. 4.1-4.2  its fit: the band of textured neighbours around it
                   matched against the photo at every offset and a few
                   turns (masked correlation by FFT); above the error
                   threshold the cluster is split and its children queued;
         Sec. 4.3-4.4  texture coordinates per corner, the cracks along
                   cluster borders closed and the borders relaxed. */
    if (tt_hpm_map(mesh, photo, NULL, NULL, uv, NULL, &report, &error) != TT_OK) goto failed;

    /* The UVs point into the photo, so the photo is the texture. */
    if (learn_obj_write(argv[3], mesh->pos, mesh->nverts, mesh->corner_vert, mesh->ncorners, 3, uv, photo) != 0)
        goto done;
    printf("hpm: %d triangles in %d clusters over %d levels (%d fits accepted, %d split), mean fit error %.2f: "
           "wrote %s.obj, %s.mtl, %s.png\n", mesh->nfaces, report.clusters, report.levels, report.accepted_fits,
           report.rejected_fits, report.mean_error, argv[3], argv[3], argv[3]);
    status = 0;
    goto done;
failed:
    fprintf(stderr, "hpm: %s\n", error.message);
done:
    tt_image_free(photo);
    tt_mesh_free(mesh);
    free(uv);
    learn_obj_free(&obj);
    return status;
}
