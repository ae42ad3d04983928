/* Compile check for tiledtex.h, built by tests/run.sh with several compilers
   and options and -Werror (C99, C++, clang, tcc, TILEDTEX_STATIC, user
   TT_MALLOC/TT_FREE). Calls every public function once, so that a static
   build has no unused function, and exits 0 when a tiny smoke run works.
   Valid C99 and C++98. Define COMPILE_CHECK_USER_ALLOC to route the default
   allocator through counting TT_MALLOC / TT_FREE macros. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifdef COMPILE_CHECK_USER_ALLOC
static long user_allocs, user_frees;
#define TT_MALLOC(size, user_data) ((void)(user_data), user_allocs++, malloc(size))
#define TT_FREE(ptr, user_data) ((void)(user_data), user_frees++, free(ptr))
#endif

#define TILEDTEX_IMPLEMENTATION
#include "tiledtex.h"
/* A second inclusion must be harmless. */
#include "tiledtex.h"

static int raster_count;
static void on_pixel(int x, int y, const float barycentric[3], void *user_data)
{
    (void)x;
    (void)y;
    (void)barycentric;
    (void)user_data;
    raster_count++;
}

static int progress(float fraction, void *user_data)
{
    (void)fraction;
    (void)user_data;
    return 0;
}

#define EXPECT(cond)                                                   \
    do {                                                               \
        if (!(cond)) {                                                 \
            printf("compile_check: %s:%d: %s\n", __FILE__, __LINE__, #cond); \
            failures++;                                                \
        }                                                              \
    } while (0)

int main(void)
{
    static const float cube_pos[8 * 3] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0, 0, 1, 1, 0, 1, 1, 1, 1, 0, 1, 1};
    static const int cube_idx[6 * 4] = {0, 3, 2, 1, 4, 5, 6, 7, 0, 1, 5, 4, 1, 2, 6, 5, 2, 3, 7, 6, 3, 0, 4, 7};
    int failures = 0, hist[8], comp[64], loops[64], nc = 0, nl = 0, lo[4] = {0, 0, 0, 0}, hi[4] = {1, 1, 1, 1};
    int path[4], rx = 0, ry = 0, major = 0;
    float cost[8] = {1, 1, 1, 1, 0, 0, 0, 0}, rgba[4], tri[6] = {0, 0, 4, 0, 0, 4}, uvc[2], over_dst[4] = {0, 0, 0, 0};
    float over_src[4] = {1, 1, 1, 1}, stretch[64], *uv;
    unsigned char bytes[16 * 32 * 3], out8[4 * 4 * 4];
    uint8_t *types;
    tt_rng rng;
    tt_mesh_desc desc;
    tt_mesh *mesh = NULL, *quads = NULL;
    tt_error err;
    tt_mesh_stats stats;
    tt_image *image = NULL, *rotated = NULL, *half = NULL, *atlas_copy = NULL;
    tt_tile_layout layout, resolved;
    tt_synth_options options;
    tt_tileset *tiles = NULL;
    tt_seam_report report;
    int counts[16], i;

    EXPECT(strlen(tt_result_string(TT_ERROR_OUT_OF_MEMORY)) > 0);
    EXPECT(strcmp(tt_version(&major, NULL, NULL), TILEDTEX_VERSION_STRING) == 0 &&
           major == TILEDTEX_VERSION_MAJOR);
    tt_rng_seed(&rng, 42, 54);
    EXPECT(tt_rng_next(&rng) == 0xa15c02b7u);
    EXPECT(tt_rng_below(&rng, 10) < 10);
    EXPECT(tt_rng_float(&rng) < 1.0f);

    memset(&desc, 0, sizeof desc);
    desc.positions = cube_pos;
    desc.nverts = 8;
    desc.indices = cube_idx;
    desc.nfaces = 6;
    desc.fixed_face_size = 4;
    EXPECT(tt_mesh_build(&desc, NULL, &mesh, &err) == TT_OK);
    if (!mesh) return 1;
    EXPECT(tt_mesh_next(mesh, 0) == 1 && tt_mesh_prev(mesh, 0) == 3);
    EXPECT(tt_mesh_compute_stats(mesh, NULL, &stats, &err) == TT_OK && stats.genus == 0);
    EXPECT(tt_mesh_valence(mesh, 0) == 3);
    EXPECT(tt_mesh_valence_histogram(mesh, NULL, hist, 8, &err) == TT_OK && hist[3] == 8);
    EXPECT(tt_mesh_components(mesh, NULL, comp, &nc, &err) == TT_OK && nc == 1);
    EXPECT(tt_mesh_boundary_loops(mesh, loops, &nl, &err) == TT_OK && nl == 0);
    EXPECT(tt_mesh_quadrangulate(mesh, TT_SUBDIVIDE_CATMULL_CLARK, NULL, &quads, &err) == TT_OK);
    if (!quads) return 1;
    {
        /* the cube's corners' x carried onto the quads' corners */
        tt_corner_sources *sources = NULL;
        float corner_x[24], quad_x[96] = {0};
        for (i = 0; i < 24; i++) corner_x[i] = cube_pos[3 * cube_idx[i]];
        EXPECT(tt_mesh_quadrangulate_sources(mesh, NULL, &sources, &err) == TT_OK && sources->ncorners == 96);
        EXPECT(tt_corner_sources_apply(sources, 1, corner_x, quad_x, &err) == TT_OK && quad_x[2] == 0.5f);
        tt_corner_sources_free(sources);
    }

    for (i = 0; i < (int)sizeof bytes; i++) bytes[i] = (unsigned char)(i * 7);
    EXPECT(tt_image_from_bytes(bytes, 16, 32, 3, 0, TT_COLOR_SRGB, NULL, &image, &err) == TT_OK);
    if (!image) return 1;
    EXPECT(tt_srgb_to_linear(tt_linear_to_srgb(0.25f)) > 0.2499f);
    tt_image_sample_bilinear(image, 1.5f, 1.5f, rgba);
    tt_image_sample_bilinear_wrap(image, -1.5f, 17.5f, TT_WRAP_REPEAT, rgba);
    tt_rotate_coords(1, 16, 32, 0, 0, &rx, &ry);
    EXPECT(rx == 0 && ry == 15);
    EXPECT(tt_image_rotate90(image, 1, NULL, &rotated, &err) == TT_OK && rotated->width == 32);
    EXPECT(tt_image_downsample2(image, NULL, &half, &err) == TT_OK && half->width == 8);
    {
        tt_image *resized = NULL;
        tt_courses courses;
        EXPECT(tt_image_resize(image, 5, 7, NULL, &resized, &err) == TT_OK && resized->height == 7);
        EXPECT(tt_find_courses(image, NULL, &courses, &err) == TT_OK && courses.period >= 0.0f);
        tt_image_free(resized);
    }
    EXPECT(tt_image_create(8, 16, NULL, &atlas_copy, &err) == TT_OK);
    if (!rotated || !half || !atlas_copy) return 1;
    EXPECT(tt_image_over(atlas_copy, half, &err) == TT_OK);
    tt_rgba_over(over_dst, over_src);
    EXPECT(over_dst[3] == 1.0f);
    {
        tt_image *small = NULL;
        EXPECT(tt_image_create(2, 2, NULL, &small, &err) == TT_OK);
        if (small) tt_image_to_rgba8(small, TT_COLOR_LINEAR, out8);
        tt_image_free(small);
    }
    EXPECT(tt_min_error_cut(cost, 4, 2, lo, hi, NULL, path, &err) == TT_OK && path[0] == 1);
    tt_raster_triangle(tri, 8, 8, on_pixel, NULL);
    EXPECT(raster_count > 0);

    memset(&layout, 0, sizeof layout);
    layout.tile_size = 8;
    layout.gutter = 2;
    EXPECT(tt_tile_layout_resolve(&layout, &resolved, &err) == TT_OK);
    EXPECT(tt_tile_layout_tiles_per_side(&resolved) == 4 && tt_tile_layout_tile_count(&resolved) == 16 &&
           tt_tile_layout_atlas_size(&resolved) == 48);
    types = (uint8_t *)malloc((size_t)quads->ncorners);
    uv = (float *)malloc(sizeof(float) * 2 * (size_t)quads->ncorners);
    if (!types || !uv) return 1;
    EXPECT(tt_assign_boundaries(quads, &layout, 1, NULL, types, &err) == TT_OK);
    EXPECT(tt_tile_index(&resolved, types) >= 0);
    tt_tile_corner_uv(&resolved, types, 2, uvc);
    EXPECT(tt_assign_uvs(quads, &layout, types, uv, &err) == TT_OK);
    EXPECT(tt_tile_histogram(quads, &layout, types, counts, &err) == TT_OK);
    EXPECT(tt_face_stretch(quads, uv, stretch, &err) == TT_OK);
    {
        tt_uv_distortion_options distortion_options;
        tt_uv_distortion_report distortion;
        memset(&distortion_options, 0, sizeof distortion_options);
        distortion_options.margin_texels = 0.5;
        EXPECT(tt_measure_uv_distortion(quads, uv, 256, 128, &distortion_options, NULL, &distortion, &err) == TT_OK &&
               distortion.faces_measured > 0);
    }

    memset(&options, 0, sizeof options);
    options.layout = layout;
    options.progress = progress;
    EXPECT(tt_synthesize_tiles(image, &options, NULL, &tiles, &err) == TT_OK);
    if (tiles) {
        EXPECT(tt_measure_seams(quads, uv, &tiles->levels[0], NULL, NULL, &report, &err) == TT_OK);
        {
            tt_seam_options seam_options;
            memset(&seam_options, 0, sizeof seam_options);
            seam_options.flags = TT_SEAM_UV_DISCONTINUOUS | TT_SEAM_WRAP;
            EXPECT(tt_measure_seams(quads, uv, &tiles->levels[0], &seam_options, NULL, &report, &err) == TT_OK &&
                   report.edges_discontinuous > 0);
        }
        tt_tileset_free(tiles);
    }
    {
        /* 6. The same synthesis as a plan applied to an image, and one tile. */
        tt_synth_plan *plan = NULL;
        tt_tileset *again = NULL;
        EXPECT(tt_synth_plan_create(image, &options, NULL, &plan, &err) == TT_OK);
        if (plan) {
            EXPECT(tt_synth_plan_depth(plan, 0, 0, 3) >= 0);
            EXPECT(tt_synth_plan_band_alpha(plan, 0, 0, 3, 0) == 1.0f);
            EXPECT(tt_synth_apply(plan, image, NULL, &again, &err) == TT_OK && again);
            if (again) {
                EXPECT(tt_synth_compose_tile(plan, image, types, &again->levels[0], 0, 0, &err) == TT_OK);
                tt_tileset_free(again);
            }
            tt_synth_plan_free(plan);
        }
    }

    free(types);
    free(uv);
    tt_image_free(image);
    tt_image_free(rotated);
    tt_image_free(half);
    tt_image_free(atlas_copy);
    if (mesh) {
        /* 7. Lapped textures: the tangent field. */
        float normal[3], *field = (float *)malloc(sizeof(float) * 3 * (size_t)mesh->nfaces);
        tt_face_normal(mesh, 0, normal);
        EXPECT(normal[0] * normal[0] + normal[1] * normal[1] + normal[2] * normal[2] > 0.99f);
        EXPECT(field && tt_tangent_field(mesh, NULL, NULL, field, &err) == TT_OK);
        free(field);
    }
    {
        /* 7. Lapped textures: a texture patch with a splotch mask. */
        tt_image *source = NULL, *patch = NULL;
        int k;
        EXPECT(tt_image_create(32, 32, NULL, &source, &err) == TT_OK);
        if (!source) return 1;
        for (k = 0; k < 32 * 32 * 4; k++) source->pixels[k] = 1.0f;
        EXPECT(tt_make_texture_patch(source, NULL, NULL, NULL, &patch, &err) == TT_OK && patch && patch->width == 32);
        if (patch) {
            /* 7. Lapped textures: paste, measure, pack and bake on the cube
               split into triangles. */
            int tri_idx[36], f, c;
            tt_mesh *tris = NULL;
            for (f = 0; f < 6; f++)
                for (c = 0; c < 3; c++) {
                    tri_idx[6 * f + c] = cube_idx[4 * f + c];
                    tri_idx[6 * f + 3 + c] = cube_idx[4 * f + (c + 2) % 4];
                }
            desc.indices = tri_idx;
            desc.nfaces = 12;
            desc.fixed_face_size = 3;
            EXPECT(tt_mesh_build(&desc, NULL, &tris, &err) == TT_OK);
            if (tris) {
                float field[36], corner_uv[72];
                tt_field_options fo;
                tt_lapped *lapped = NULL;
                tt_lapped_report lr;
                tt_image *baked = NULL;
                tt_bake_options bo;
                memset(&fo, 0, sizeof fo);
                memset(&bo, 0, sizeof bo);
                bo.gutter = 2;
                fo.scale = 0.6f;
                EXPECT(tt_tangent_field(tris, &fo, NULL, field, &err) == TT_OK);
                EXPECT(tt_lapped_paste(tris, field, &patch, 1, NULL, NULL, &lapped, &err) == TT_OK && lapped);
                if (lapped) {
                    EXPECT(tt_lapped_measure(tris, field, lapped, NULL, &lr, &err) == TT_OK &&
                           lr.uncovered_faces == 0);
                    EXPECT(tt_atlas_pack_pairs(tris, 64, 2, corner_uv, &err) == TT_OK);
                    {
                        tt_chart_atlas_report ar;
                        tt_uv_report ur;
                        EXPECT(tt_atlas_pack_charts(tris, 64, 2, NULL, NULL, corner_uv, &ar, &err) == TT_OK &&
                               ar.ncharts >= 1);
                        EXPECT(tt_uv_check(tris, corner_uv, NULL, &ur, &err) == TT_OK && ur.problem == TT_UV_USABLE);
                    }
                    EXPECT(tt_image_create(64, 64, NULL, &baked, &err) == TT_OK);
                    if (baked)
                        EXPECT(tt_lapped_bake(tris, lapped, &patch, 1, corner_uv, &bo, NULL, baked, &err) == TT_OK);
                    tt_image_free(baked);
                    tt_lapped_free(lapped);
                }
                {
                    /* 8. Hierarchical pattern mapping: every public function once. */
                    tt_cluster_options co;
                    tt_cluster_hierarchy *ch = NULL;
                    memset(&co, 0, sizeof co);
                    co.seed = 5;
                    EXPECT(tt_cluster_hierarchy_build(tris, &co, NULL, &ch, &err) == TT_OK && ch &&
                           ch->clusters[ch->nclusters - 1].nfaces == 1);
                    if (ch) {
                        tt_flatten_options flo;
                        tt_flatten_report fr;
                        memset(&flo, 0, sizeof flo);
                        flo.max_error = TT_DEFAULT_FLATTEN_MAX_ERROR;
                        flo.border = TT_FLATTEN_BORDER_PROJECTED;
                        /* a single face maps isometrically */
                        EXPECT(tt_flatten_cluster(tris, ch, ch->nclusters - 1, &flo, NULL, corner_uv, &fr, &err) ==
                                   TT_OK && fr.mapped && fr.flattening_error < 1e-6 && fr.flipped == 0);
                    }
                    tt_cluster_hierarchy_free(ch);
                }
                tt_mesh_free(tris);
            }
        }
        tt_image_free(patch);
        tt_image_free(source);
    }
    {
        /* 9. Polycube + Wang tiles: the unit cube at resolution 2 is a 2 x 2 x 2 block with 24 quads,
           whose edge colours tt_assign_boundaries accepts. */
        tt_polycube_options po;
        tt_polycube_report pr;
        tt_polycube *pc = NULL;
        memset(&po, 0, sizeof po);
        po.resolution = 2;
        EXPECT(tt_polycube_build(mesh, &po, NULL, &pc, &pr, &err) == TT_OK && pc && pr.cubes == 8 && pr.quads == 24);
        if (pc) {
            int edge_colors[96];
            uint8_t pc_types[96];
            tt_tile_layout pl;
            pl.colors = 4;
            pl.tile_size = 0;
            pl.gutter = 0;
            EXPECT(tt_polycube_edge_colors(pc, 4, 1, 9, edge_colors, &err) == TT_OK);
            EXPECT(tt_assign_boundaries(pc->surface, &pl, 9, edge_colors, pc_types, &err) == TT_OK);
        }
        if (pc) {
            /* The cube's 8 corners lie on S: each maps to itself. */
            tt_surface_point points[8];
            tt_polycube_projection_report ppr;
            double at[3];
            EXPECT(mesh->nverts == 8);
            EXPECT(tt_polycube_project(pc, mesh, NULL, points, &ppr, &err) == TT_OK && ppr.on_surface == 8 &&
                   ppr.fallbacks == 0);
            tt_polycube_point_position(pc, points[0], at);
            at[0] -= mesh->pos[0];
            at[1] -= mesh->pos[1];
            at[2] -= mesh->pos[2];
            EXPECT(at[0] * at[0] + at[1] * at[1] + at[2] * at[2] < 1e-12);
            {
                /* The cube's 12 edges on S (each passes the lattice point at its middle), and the unfolding
                   across one of S's edges and back. */
                tt_polycube_edges *pe = NULL;
                tt_polycube_edge_options peo;
                tt_quad_map there, back, round;
                double st[2];
                peo.max_quads = 6;
                EXPECT(tt_polycube_trace_edges(pc, mesh, points, 8, &peo, NULL, &pe, &err) == TT_OK && pe &&
                       pe->nedges == 12 && pe->nfailed == 0 && pe->ncrossings >= 12 &&
                       pe->first_crossing[pe->nedges] == pe->ncrossings);
                tt_polycube_edges_free(pe);
                there = tt_polycube_unfold(pc, 0);
                back = tt_polycube_unfold(pc, pc->surface->twin[0]);
                round = tt_quad_map_compose(there, back);
                tt_quad_map_apply(round, 0.25, 0.5, st);
                EXPECT(round.turns == 0 && st[0] == 0.25 && st[1] == 0.5);
            }
            {
                /* The cube as 12 triangles mapped onto S: each is cut at the lattice lines into 4, and its
                   UVs come from the quads' tiles. */
                int tri_index[36], q, c;
                tt_mesh_desc td;
                tt_mesh *tri_cube = NULL;
                for (q = 0; q < 6; q++)
                    for (c = 0; c < 3; c++) {
                        tri_index[6 * q + c] = mesh->corner_vert[4 * q + c];
                        tri_index[6 * q + 3 + c] = mesh->corner_vert[4 * q + (c + 2) % 4];
                    }
                memset(&td, 0, sizeof td);
                td.positions = mesh->pos;
                td.nverts = 8;
                td.indices = tri_index;
                td.nfaces = 12;
                EXPECT(tt_mesh_build(&td, NULL, &tri_cube, &err) == TT_OK);
                if (tri_cube) {
                    tt_polycube_map_options pmo;
                    tt_polycube_map_report pmr;
                    tt_polycube_mapping *pm = NULL;
                    memset(&pmo, 0, sizeof pmo);
                    pmo.max_quads = 6;
                    pmo.max_edge = HUGE_VAL;   /* the exact split, unrefined */
                    EXPECT(tt_polycube_map(pc, tri_cube, &pmo, NULL, &pm, &pmr, &err) == TT_OK && pm &&
                           pm->ntriangles == 48 && pmr.fallback_triangles == 0 && pmr.flipped == 0);
                    if (pm) {
                        float *muv = (float *)malloc(sizeof(float) * 6 * (size_t)pm->ntriangles);
                        uint8_t cube_types[96];
                        tt_tile_layout ml;
                        ml.colors = 1;
                        ml.tile_size = 0;
                        ml.gutter = 0;
                        memset(cube_types, 0, sizeof cube_types);
                        EXPECT(muv && tt_polycube_mapping_uvs(pc, pm, &ml, cube_types, muv, &err) == TT_OK &&
                               muv[0] >= 0.0f && muv[0] <= 1.0f);
                        free(muv);
                    }
                    tt_polycube_mapping_free(pm);
                }
                tt_mesh_free(tri_cube);
            }
        }
        tt_polycube_free(pc);
    }
    tt_mesh_free(quads);
    tt_mesh_free(mesh);
    {
        /* 4. Numerics: every public function once. */
        static const tt_triplet trip[4] = {{0, 0, 2.0}, {1, 1, 2.0}, {0, 1, 0.5}, {1, 0, 0.5}};
        tt_sparse_matrix *sm = NULL;
        double rhs[2] = {1.0, 1.0}, sol[2] = {0.0, 0.0}, prod[2];
        tt_cg_options cgo;
        tt_cg_report cgr;
        memset(&cgo, 0, sizeof cgo);
        cgo.progress = progress;
        EXPECT(tt_sparse_from_triplets(2, 2, trip, 4, NULL, &sm, &err) == TT_OK);
        if (!sm) return 1;
        EXPECT(tt_sparse_multiply(sm, rhs, prod, &err) == TT_OK && prod[0] == 2.5);
        EXPECT(tt_cg_solve(sm, rhs, &cgo, NULL, sol, &cgr, &err) == TT_OK && cgr.converged && sol[0] > 0.39 &&
               sol[0] < 0.41);
        EXPECT(tt_result_string(TT_ERROR_NOT_CONVERGED)[0] && tt_result_string(TT_ERROR_NOT_POSITIVE_DEFINITE)[0]);
        tt_sparse_matrix_free(sm);
    }
    {
        /* 4. Numerics, the FFTs and the masked correlation: every public function once. */
        static const double tex4[4] = {0.25, 0.5, 0.75, 1.0};
        static const double mask4[4] = {1.0, 0.0, 0.0, 0.0};
        double cplx[8] = {1, 0, 2, 0, 3, 0, 4, 0}, spec4[8], real4[4], work[24], map4[4];
        double values4[4] = {0.75, 0.0, 0.0, 0.0};
        tt_fft_plan *plan = NULL;
        tt_xcorr_texture *xt = NULL;
        tt_xcorr_match match;
        EXPECT(tt_fft_plan_create(2, 2, NULL, &plan, &err) == TT_OK);
        if (!plan) return 1;
        EXPECT(tt_fft_c2c(plan, cplx, 2, 2, TT_FFT_FORWARD, &err) == TT_OK && cplx[0] == 10.0);
        EXPECT(tt_fft_c2c(plan, cplx, 2, 2, TT_FFT_INVERSE, &err) == TT_OK && cplx[2] == 8.0);
        EXPECT(tt_fft_r2c(plan, tex4, 2, 2, spec4, &err) == TT_OK && spec4[0] == 2.5);
        EXPECT(tt_fft_c2r(plan, spec4, 2, 2, real4, &err) == TT_OK && real4[3] == 4.0);
        tt_fft_plan_free(plan);
        EXPECT(tt_xcorr_texture_create(2, 2, 1, tex4, NULL, &xt, &err) == TT_OK);
        if (!xt) return 1;
        EXPECT(xt->work_size <= 16);
        EXPECT(tt_xcorr_masked(xt, mask4, values4, NULL, work, map4, &match, &err) == TT_OK && match.x == 0 &&
               match.y == 1 && match.e < 1e-12);
        {
            const tt_xcorr_texture *both[2];
            int which = -1;
            both[0] = xt;
            both[1] = xt;
            EXPECT(xt->best_work_size <= 24);
            EXPECT(tt_xcorr_masked_best(both, 2, mask4, values4, NULL, work, &match, &which, &err) == TT_OK &&
                   which == 0 && match.x == 0 && match.y == 1 && match.e < 1e-12);
        }
        tt_xcorr_texture_free(xt);
    }
#ifdef COMPILE_CHECK_USER_ALLOC
    EXPECT(user_allocs > 0);
    EXPECT(user_allocs == user_frees);
    if (user_allocs != user_frees) printf("compile_check: TT_MALLOC %ld, TT_FREE %ld\n", user_allocs, user_frees);
#endif
    if (failures == 0) printf("compile_check: ok\n");
    return failures ? 1 : 0;
}
