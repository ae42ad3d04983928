/* The preconditions of the helpers that return no tt_result (THE API
   CONTRACT): each broken one is caught by TT_ASSERT before any memory is
   touched. Built by tests/run.sh twice:
     - with TT_ASSERT defined here to jump back out (setjmp/longjmp), so every
       case below must reach the assertion, never a crash or a wrong read
       (the sanitizers watch);
     - with -DASSERT_CHECK_NDEBUG, where TT_ASSERT is the default assert()
       compiled out by NDEBUG: the helpers that promise a safe answer for a
       bad argument (an unresolvable layout gives 0) must give it, with no
       undefined behaviour.
   Prints "assert_check: ok" and exits 0, or names the case that failed. */
#include <setjmp.h>
#include <stdio.h>
#include <string.h>

#ifdef ASSERT_CHECK_NDEBUG
#define NDEBUG 1
#else
static jmp_buf assert_jump;
static int asserts_fired;
#define TT_ASSERT(condition) \
    do {                                   \
        if (!(condition)) {                \
            asserts_fired++;               \
            longjmp(assert_jump, 1);       \
        }                                  \
    } while (0)
#endif

#define TILEDTEX_IMPLEMENTATION
#include "tiledtex.h"

static int failures;

static void on_pixel(int x, int y, const float barycentric[3], void *user_data)
{
    (void)x; (void)y; (void)barycentric; (void)user_data;
}

#ifndef ASSERT_CHECK_NDEBUG
/* Run `call`; it must end in TT_ASSERT. */
#define EXPECT_ASSERT(what, call)                                              \
    do {                                                                       \
        int before = asserts_fired;                                            \
        if (setjmp(assert_jump) == 0) {                                        \
            call;                                                              \
        }                                                                      \
        if (asserts_fired != before + 1) {                                     \
            printf("assert_check: %s: TT_ASSERT did not fire\n", what);        \
            failures++;                                                        \
        }                                                                      \
    } while (0)
#endif

int main(void)
{
    static const float pos[12] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
    static const int quad[4] = {0, 1, 2, 3};
    tt_mesh_desc desc;
    tt_mesh *mesh = NULL;
    tt_tile_layout bad_layout, layout;
    uint8_t types[4] = {0, 1, 0, 1}, big_types[4] = {0, 9, 0, 1};
    float normal[3], uv[2], rgba[4], xy[6] = {0, 0, 4, 0, 0, 4};
    unsigned char bytes[16];
    int rx, ry;
    tt_image empty, one;
    float one_texel[4] = {0.25f, 0.5f, 0.75f, 1.0f};
    tt_polycube *polycube = NULL;
    tt_surface_point point;
    double xyz[3];

    memset(&desc, 0, sizeof desc);
    desc.positions = pos;
    desc.nverts = 4;
    desc.indices = quad;
    desc.nfaces = 1;
    desc.fixed_face_size = 4;
    if (tt_mesh_build(&desc, NULL, &mesh, NULL) != TT_OK) {
        printf("assert_check: the quad does not build\n");
        return 1;
    }
    memset(&bad_layout, 0, sizeof bad_layout);
    bad_layout.colors = 1000;   /* (2n)^2 tiles a side would overflow an atlas, and an int squared */
    memset(&layout, 0, sizeof layout);
    memset(&empty, 0, sizeof empty);
    memset(&one, 0, sizeof one);
    one.width = one.height = 1;
    one.pixels = one_texel;
    if (tt_polycube_build(mesh, NULL, NULL, &polycube, NULL, NULL) != TT_OK) {
        printf("assert_check: the quad's polycube does not build\n");
        tt_mesh_free(mesh);
        return 1;
    }
    memset(&point, 0, sizeof point);
    (void)point; (void)xyz;
    (void)one; (void)normal; (void)uv; (void)rgba; (void)xy; (void)bytes; (void)rx; (void)ry; (void)types; (void)big_types;

#ifdef ASSERT_CHECK_NDEBUG
    if (tt_tile_layout_tiles_per_side(&bad_layout) != 0 || tt_tile_layout_atlas_size(&bad_layout) != 0 ||
        tt_tile_layout_tile_count(&bad_layout) != 0) {
        printf("assert_check: an unresolvable layout must give 0 figures under NDEBUG\n");
        failures++;
    }
    if (tt_mesh_valence(mesh, -1) != 0 || tt_mesh_valence(mesh, 4) != 0) {
        printf("assert_check: tt_mesh_valence out of range must give 0 under NDEBUG\n");
        failures++;
    }
    tt_raster_triangle(NULL, 8, 8, on_pixel, NULL);   /* visits nothing */
#else
    EXPECT_ASSERT("tt_face_normal(NULL mesh)", tt_face_normal(NULL, 0, normal));
    EXPECT_ASSERT("tt_face_normal(face -1)", tt_face_normal(mesh, -1, normal));
    EXPECT_ASSERT("tt_face_normal(face nfaces)", tt_face_normal(mesh, 1, normal));
    EXPECT_ASSERT("tt_face_normal(NULL normal)", tt_face_normal(mesh, 0, NULL));
    EXPECT_ASSERT("tt_mesh_next(corner -1)", tt_mesh_next(mesh, -1));
    EXPECT_ASSERT("tt_mesh_next(corner ncorners)", tt_mesh_next(mesh, 4));
    EXPECT_ASSERT("tt_mesh_prev(NULL mesh)", tt_mesh_prev(NULL, 0));
    EXPECT_ASSERT("tt_mesh_valence(vertex nverts)", tt_mesh_valence(mesh, 4));
    EXPECT_ASSERT("tt_tile_index(NULL types)", tt_tile_index(&layout, NULL));
    EXPECT_ASSERT("tt_tile_index(type 9 of n = 1)", tt_tile_index(&layout, big_types));
    EXPECT_ASSERT("tt_tile_index(colors 1000)", tt_tile_index(&bad_layout, types));
    EXPECT_ASSERT("tt_tile_corner_uv(corner 4)", tt_tile_corner_uv(&layout, types, 4, uv));
    EXPECT_ASSERT("tt_tile_corner_uv(NULL uv)", tt_tile_corner_uv(&layout, types, 0, NULL));
    EXPECT_ASSERT("tt_tile_layout_tiles_per_side(colors 1000)", tt_tile_layout_tiles_per_side(&bad_layout));
    EXPECT_ASSERT("tt_tile_layout_atlas_size(NULL)", tt_tile_layout_atlas_size(NULL));
    EXPECT_ASSERT("tt_image_sample_bilinear(empty image)", tt_image_sample_bilinear(&empty, 0.5f, 0.5f, rgba));
    EXPECT_ASSERT("tt_image_sample_bilinear_wrap(empty image)",
                  tt_image_sample_bilinear_wrap(&empty, 0.5f, 0.5f, TT_WRAP_REPEAT, rgba));
    EXPECT_ASSERT("tt_image_sample_bilinear_wrap(wrap 7)",
                  tt_image_sample_bilinear_wrap(&one, 0.5f, 0.5f, (tt_wrap)7, rgba));
    EXPECT_ASSERT("tt_image_to_rgba8(empty image)", tt_image_to_rgba8(&empty, TT_COLOR_SRGB, bytes));
    EXPECT_ASSERT("tt_rgba_over(NULL)", tt_rgba_over(NULL, rgba));
    EXPECT_ASSERT("tt_rotate_coords(NULL out)", tt_rotate_coords(1, 4, 4, 0, 0, NULL, &ry));
    EXPECT_ASSERT("tt_rotate_coords(result beyond int)",
                  tt_rotate_coords(1, 0x7fffffff, 4, -0x7fffffff, 0, &rx, &ry));
    EXPECT_ASSERT("tt_rng_next(NULL)", tt_rng_next(NULL));
    EXPECT_ASSERT("tt_raster_triangle(NULL xy)", tt_raster_triangle(NULL, 8, 8, on_pixel, NULL));
    EXPECT_ASSERT("tt_raster_triangle(NULL fn)", tt_raster_triangle(xy, 8, 8, NULL, NULL));
    EXPECT_ASSERT("tt_polycube_point_position(NULL polycube)", tt_polycube_point_position(NULL, point, xyz));
    EXPECT_ASSERT("tt_polycube_point_position(NULL xyz)", tt_polycube_point_position(polycube, point, NULL));
    point.quad = -1;
    EXPECT_ASSERT("tt_polycube_point_position(quad -1)", tt_polycube_point_position(polycube, point, xyz));
    point.quad = polycube->surface->nfaces;
    EXPECT_ASSERT("tt_polycube_point_position(quad nfaces)", tt_polycube_point_position(polycube, point, xyz));
#endif
    tt_polycube_free(polycube);
    tt_mesh_free(mesh);
    if (failures == 0) printf("assert_check: ok\n");
    return failures ? 1 : 0;
}
