/* The named limits (LIMITS at the top of tiledtex.h) are constants a user
   can override: this program defines each one small before including the
   header and checks that the work it bounds is refused with
   TT_ERROR_TOO_LARGE, the message naming the limit, and that work under it
   still runs. tests/run.sh builds it with the sanitizers. Prints
   "limits_check: ok" and exits 0, or names the case that failed. */
#define TT_MAX_IMAGE_SIZE 64
#define TT_FFT_MAX_SIZE 64
#define TT_LAPPED_MAX_PASTES 3
#define TT_POLYCUBE_MAX_RESOLUTION 8
#define TT_POLYCUBE_MAX_CUBES 1000
#define TT_POLYCUBE_MAX_TRIANGLES 2000
#define TILEDTEX_IMPLEMENTATION
#include "tiledtex.h"

#include <stdio.h>
#include <string.h>

static int failures;

static void expect(int ok, const char *what, const tt_error *error)
{
    if (ok) return;
    failures++;
    printf("limits_check: FAIL %s (%s)\n", what, error ? error->message : "");
}

/* Refused with TT_ERROR_TOO_LARGE and a message that names `limit`. */
static void expect_limit(tt_result result, const tt_error *error, const char *limit, const char *what)
{
    expect(result == TT_ERROR_TOO_LARGE && error->result == result && strstr(error->message, limit) != NULL, what,
           error);
}

/* The unit cube as 12 triangles, counter-clockwise from outside. */
static tt_mesh *unit_cube(void)
{
    static const float positions[8 * 3] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0, 0, 1, 1, 0, 1, 1, 1, 1, 0, 1, 1};
    static const int triangles[12 * 3] = {0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4,
                                          1, 2, 6, 1, 6, 5, 2, 3, 7, 2, 7, 6, 3, 0, 4, 3, 4, 7};
    tt_mesh_desc desc;
    tt_mesh *mesh = NULL;
    memset(&desc, 0, sizeof desc);
    desc.positions = positions;
    desc.nverts = 8;
    desc.indices = triangles;
    desc.nfaces = 12;
    desc.fixed_face_size = 3;
    return tt_mesh_build(&desc, NULL, &mesh, NULL) == TT_OK ? mesh : NULL;
}

static void check_images(void)
{
    tt_image *image = NULL;
    tt_error error;
    tt_fft_plan *plan = NULL;
    expect_limit(tt_image_create(TT_MAX_IMAGE_SIZE + 1, 1, NULL, &image, &error), &error, "TT_MAX_IMAGE_SIZE",
                 "an image wider than TT_MAX_IMAGE_SIZE");
    expect(tt_image_create(TT_MAX_IMAGE_SIZE, TT_MAX_IMAGE_SIZE, NULL, &image, &error) == TT_OK, "an image at the limit",
           &error);
    tt_image_free(image);
    expect_limit(tt_fft_plan_create(2 * TT_FFT_MAX_SIZE, 1, NULL, &plan, &error), &error, "TT_FFT_MAX_SIZE",
                 "an FFT above TT_FFT_MAX_SIZE");
    expect(tt_fft_plan_create(TT_FFT_MAX_SIZE, TT_FFT_MAX_SIZE, NULL, &plan, &error) == TT_OK, "an FFT at the limit",
           &error);
    tt_fft_plan_free(plan);
}

static void check_lapped(const tt_mesh *cube)
{
    float field[12 * 3];
    tt_image *source = NULL, *patch = NULL;
    tt_lapped *lapped = NULL;
    tt_error error;
    tt_field_options field_options;
    int i;
    memset(&field_options, 0, sizeof field_options);
    field_options.scale = 0.1f;   /* patches a tenth of the cube: far more than 3 pastes */
    if (tt_tangent_field(cube, &field_options, NULL, field, &error) != TT_OK ||
        tt_image_create(64, 64, NULL, &source, &error) != TT_OK) {
        expect(0, "the lapped setup", &error);
        tt_image_free(source);
        return;
    }
    for (i = 0; i < 4 * 64 * 64; i++) source->pixels[i] = i % 4 == 3 ? 1.0f : (float)((i * 37) % 101) / 100.0f;
    if (tt_make_texture_patch(source, NULL, NULL, NULL, &patch, &error) != TT_OK) {
        expect(0, "the lapped patch", &error);
        tt_image_free(source);
        return;
    }
    expect_limit(tt_lapped_paste(cube, field, &patch, 1, NULL, NULL, &lapped, &error), &error, "TT_LAPPED_MAX_PASTES",
                 "more pastes than TT_LAPPED_MAX_PASTES");
    expect(lapped == NULL, "no result when refused", &error);
    tt_image_free(patch);
    tt_image_free(source);
}

static void check_polycube(const tt_mesh *cube)
{
    tt_polycube_options options;
    tt_polycube_map_options map_options;
    tt_polycube *polycube = NULL;
    tt_polycube_mapping *mapping = NULL;
    tt_error error;
    memset(&options, 0, sizeof options);
    options.resolution = TT_POLYCUBE_MAX_RESOLUTION + 1;
    expect_limit(tt_polycube_build(cube, &options, NULL, &polycube, NULL, &error), &error,
                 "TT_POLYCUBE_MAX_RESOLUTION", "a resolution above TT_POLYCUBE_MAX_RESOLUTION");
    options.resolution = 0;
    options.cube_size = 1.0 / 20;   /* 20 + 4 padding cubes a side: 13824 > TT_POLYCUBE_MAX_CUBES */
    expect(tt_polycube_build(cube, &options, NULL, &polycube, NULL, &error) == TT_ERROR_TOO_LARGE,
           "a grid above TT_POLYCUBE_MAX_CUBES (or the resolution) is refused", &error);
    options.cube_size = 0;
    options.resolution = 2;   /* 6 x 6 x 6 with the padding */
    if (tt_polycube_build(cube, &options, NULL, &polycube, NULL, &error) != TT_OK) {
        expect(0, "a polycube at resolution 2", &error);
        return;
    }
    /* The cube's 12 triangles refined to edges of 0.1 take 4 rounds: 12,
       48, 192, 768, 3072 triangles. The area alone (6 / (0.433 0.1^2) =
       1386) passes the limit of 2000: the refusal comes at the last round,
       before it is made. */
    memset(&map_options, 0, sizeof map_options);
    map_options.max_edge = 0.1;
    expect_limit(tt_polycube_map(polycube, cube, &map_options, NULL, &mapping, NULL, &error), &error,
                 "TT_POLYCUBE_MAX_TRIANGLES", "a refinement that passes TT_POLYCUBE_MAX_TRIANGLES round by round");
    expect(mapping == NULL && strstr(error.message, " 3072 ") != NULL, "refused at the round of 3072 triangles",
           &error);
    map_options.max_edge = 0.01;   /* the area alone: 138,564 triangles */
    expect_limit(tt_polycube_map(polycube, cube, &map_options, NULL, &mapping, NULL, &error), &error,
                 "TT_POLYCUBE_MAX_TRIANGLES", "a refinement whose area passes TT_POLYCUBE_MAX_TRIANGLES");
    expect(strstr(error.message, " 138564 ") != NULL, "refused by the area's floor, 138564 triangles", &error);
    map_options.max_edge = 0.2;   /* 768 triangles */
    expect(tt_polycube_map(polycube, cube, &map_options, NULL, &mapping, NULL, &error) == TT_OK,
           "a refinement under TT_POLYCUBE_MAX_TRIANGLES", &error);
    tt_polycube_mapping_free(mapping);
    tt_polycube_free(polycube);
}

int main(void)
{
    tt_mesh *cube = unit_cube();
    if (!cube) {
        printf("limits_check: FAIL building the cube\n");
        return 1;
    }
    check_images();
    check_lapped(cube);
    check_polycube(cube);
    tt_mesh_free(cube);
    if (failures) return 1;
    printf("limits_check: ok\n");
    return 0;
}
