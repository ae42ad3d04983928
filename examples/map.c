/* map.c - `tiledtex map`: give a mesh tiled-texture UVs.

   This is Akleman et al.'s mapping algorithm (Sec. 3) as a library user calls it:

     tt_mesh_build          validate the OBJ's faces into a half-edge mesh
     tt_mesh_quadrangulate  only when there are triangles or n-gons: each
                            n-gon becomes n quads (and again per --subdivide)
     tt_assign_boundaries   a random boundary type per half-edge, twins
                            complementary (seeded: same seed, same result)
     tt_assign_uvs          one UV per corner: the tile named by its four
                            boundary types, at its place in the atlas

   The UVs depend only on --colors, --tile and --gutter, never on an image:
   any atlas `tiledtex synth` makes with the same three fits them.
*/
#include <stdio.h>
#include <stdlib.h>
#include <math.h>
#include <string.h>

#include "tiled.h"

static void print_help(void)
{
    printf("usage: tiledtex map MESH.obj OUT.obj [options]\n"
           "\n"
           "Give every face of MESH.obj a tile of a tiled texture: writes OUT.obj with one\n"
           "texture coordinate per face corner. Triangles and n-gons are quadrangulated\n"
           "first (each n-gon into n quads). The UVs fit any atlas that `tiledtex synth`\n"
           "makes with the same --colors, --tile and --gutter.\n"
           "\n"
           "options:\n"
           "  --colors N       edge conditions n; the atlas holds (2n)^4 tiles (default 1)\n"
           "  --tile S         tile size in texels (default %d, or read off --atlas)\n"
           "  --gutter G       texels of gutter around each tile, 0 for none (default %d)\n"
           "  --seed K         random seed for the boundary types (default 0)\n"
           "  --subdivide L    quadrangulate L more times: smaller faces, smaller texture\n"
           "  --smooth         use Catmull-Clark positions when subdividing (default: keep the shape)\n"
           "  --atlas A.png    also write OUT.mtl naming A.png, and report the seam score\n"
           "  --permissive     accept non-manifold or mis-oriented edges (they become boundaries)\n"
           "  --report         also print tile usage and face stretch\n",
           TT_DEFAULT_TILE_SIZE, TT_RECOMMENDED_GUTTER);
}

void tiled_default_options(tiled_options *options)
{
    memset(options, 0, sizeof *options);
    options->layout.gutter = TT_RECOMMENDED_GUTTER;
}

int tiled_parse_option(int argc, char **argv, int *index, unsigned accept, tiled_options *options)
{
    const char *value;
    int number;
    if ((accept & TILED_LAYOUT_OPTIONS) && tool_option(argc, argv, index, "--colors", &value)) {
        if (parse_int("--colors", value, 1, 8, &options->layout.colors) != 0) return -1;
    } else if ((accept & TILED_LAYOUT_OPTIONS) && tool_option(argc, argv, index, "--tile", &value)) {
        if (parse_int("--tile", value, 4, TT_MAX_IMAGE_SIZE, &options->layout.tile_size) != 0) return -1;
        options->tile_size_given = 1;
    } else if ((accept & TILED_LAYOUT_OPTIONS) && tool_option(argc, argv, index, "--gutter", &value)) {
        if (parse_int("--gutter", value, 0, TT_MAX_IMAGE_SIZE, &number) != 0) return -1;
        options->layout.gutter = number;
    } else if ((accept & TILED_LAYOUT_OPTIONS) && tool_option(argc, argv, index, "--seed", &value)) {
        if (parse_u64("--seed", value, &options->seed) != 0) return -1;
    } else if ((accept & TILED_MESH_OPTIONS) && tool_option(argc, argv, index, "--subdivide", &value)) {
        if (parse_int("--subdivide", value, 0, 8, &options->subdivide) != 0) return -1;
    } else if ((accept & TILED_MESH_OPTIONS) && strcmp(argv[*index], "--smooth") == 0) {
        options->smooth = 1;
    } else if ((accept & TILED_MESH_OPTIONS) && strcmp(argv[*index], "--permissive") == 0) {
        options->permissive = 1;
    } else if ((accept & TILED_SYNTH_OPTIONS) && tool_option(argc, argv, index, "--edge", &value)) {
        int xy[2];
        if (parse_int_list("--edge", value, 2, xy) != 0) return -1;
        if (options->nedges >= TT_MAX_COLORS) { tool_usage("too many --edge options"); return -1; }
        options->edges[options->nedges].x = xy[0];
        options->edges[options->nedges].y = xy[1];
        options->nedges++;
    } else if ((accept & TILED_SYNTH_OPTIONS) && tool_option(argc, argv, index, "--background", &value)) {
        int r[4];
        if (parse_int_list("--background", value, 4, r) != 0) return -1;
        if (r[2] <= 0 || r[3] <= 0) { tool_usage("--background wants X,Y,W,H with W and H above 0"); return -1; }
        options->background.x = r[0];
        options->background.y = r[1];
        options->background.w = r[2];
        options->background.h = r[3];
    } else if ((accept & TILED_SYNTH_OPTIONS) && strcmp(argv[*index], "--mips") == 0) {
        options->mips = 1;
    } else if ((accept & TILED_REPORT_OPTION) && strcmp(argv[*index], "--report") == 0) {
        options->report = 1;
    } else if ((accept & TILED_ATLAS_OPTION) && tool_option(argc, argv, index, "--atlas", &value)) {
        if (!value) { tool_usage("--atlas needs a value"); return -1; }
        options->atlas_path = value;
    } else {
        return 0;
    }
    return 1;
}

int tiled_parse_command_line(int argc, char **argv, unsigned accept, tiled_options *options,
                             const char **positional, int count, const char *names, void (*help)(void))
{
    int npositional = 0, i;
    tiled_default_options(options);
    for (i = 1; i < argc; i++) {
        int taken;
        if (tool_is_help(argv[i])) {
            help();
            return 0;
        }
        taken = tiled_parse_option(argc, argv, &i, accept, options);
        if (taken < 0) return TOOL_EXIT_USAGE;
        if (taken) continue;
        if (tool_is_option(argv[i])) return tool_unknown_option(argv[i]);
        if (npositional == count) return tool_usage("too many arguments (see 'tiledtex %s --help')", argv[0]);
        positional[npositional++] = argv[i];
    }
    if (npositional != count) return tool_usage("needs %s (see 'tiledtex %s --help')", names, argv[0]);
    return -1;
}

void tiled_mesh_free(tiled_mesh *mesh)
{
    tt_mesh_free(mesh->mesh);
    free(mesh->corner_type);
    free(mesh->corner_uv);
    memset(mesh, 0, sizeof *mesh);
}

/* Replace *mesh by one quadrangulation step of it. */
static int quadrangulate(tt_mesh **mesh, tt_subdivision scheme, const char *obj_path)
{
    tt_mesh *quads;
    tt_error error;
    if (tt_mesh_quadrangulate(*mesh, scheme, &quads, &error) != TT_OK)
        return tool_fail("%s: cannot quadrangulate: %s", obj_path, error.message);
    tt_mesh_free(*mesh);
    *mesh = quads;
    return 0;
}

int tiled_map_mesh(const char *obj_path, const tiled_options *options, tiled_mesh *out)
{
    obj_mesh obj;
    tt_mesh_desc desc;
    tt_error error;
    char message[TOOL_ERROR_SIZE];
    int status, step;

    memset(out, 0, sizeof *out);
    if (tt_tile_layout_resolve(&options->layout, &out->layout, &error) != TT_OK)
        return tool_fail("%s", error.message);
    if (obj_read(obj_path, &obj, message, sizeof message) != 0) return tool_fail("%s", message);

    desc = obj_mesh_desc(&obj, options->permissive ? TT_MESH_PERMISSIVE : 0);
    out->input_faces = obj.nfaces;
    if (tt_mesh_build(&desc, &out->mesh, &error) != TT_OK) {
        status = obj_report_mesh_error(obj_path, &obj, &error, 1);
        obj_free(&obj);
        return status;
    }
    obj_free(&obj);
    out->repaired_edges = out->mesh->repaired_edges;
    out->input_min_face_size = out->mesh->min_face_size;
    out->input_max_face_size = out->mesh->max_face_size;

    /* Tiles are square: every face must be a quad. */
    if (out->mesh->min_face_size != 4 || out->mesh->max_face_size != 4) {
        if ((status = quadrangulate(&out->mesh, TT_SUBDIVIDE_LINEAR, obj_path)) != 0) goto fail;
        out->quadrangulated = out->mesh->nfaces;
    }
    /* Each step makes four times the quads: refuse what would not fit in
       memory long before it is tried. */
    if (options->subdivide > 0 &&
        (double)out->mesh->nfaces * pow(4.0, options->subdivide) > (double)TILED_MAX_QUADS) {
        status = tool_fail("%s: --subdivide %d would make %.0f quads; the limit is %d (use a smaller level)",
                           obj_path, options->subdivide, (double)out->mesh->nfaces * pow(4.0, options->subdivide),
                           TILED_MAX_QUADS);
        goto fail;
    }
    for (step = 0; step < options->subdivide; step++)
        if ((status = quadrangulate(&out->mesh, options->smooth ? TT_SUBDIVIDE_CATMULL_CLARK : TT_SUBDIVIDE_LINEAR,
                                    obj_path)) != 0)
            goto fail;

    out->corner_type = (uint8_t *)malloc((size_t)out->mesh->ncorners);
    out->corner_uv = (float *)malloc((size_t)out->mesh->ncorners * 2 * sizeof(float));
    if (!out->corner_type || !out->corner_uv) {
        status = tool_fail("out of memory for %d corners", out->mesh->ncorners);
        goto fail;
    }
    tt_assign_boundaries(out->mesh, &out->layout, options->seed, out->corner_type);
    if (tt_assign_uvs(out->mesh, &out->layout, out->corner_type, out->corner_uv, &error) != TT_OK) {
        status = tool_fail("%s: %s", obj_path, error.message);
        goto fail;
    }
    if (tt_mesh_compute_stats(out->mesh, &out->stats) != TT_OK) {
        status = tool_fail("out of memory while measuring %s", obj_path);
        goto fail;
    }
    return 0;
fail:
    tiled_mesh_free(out);
    return status;
}

int tiled_add_obj(tool_output *output, const char *obj_path, const tiled_mesh *mesh, const char *mtl_name)
{
    tool_buffer text;
    obj_write_desc desc;
    char comment[256];
    memset(&text, 0, sizeof text);
    memset(&desc, 0, sizeof desc);
    snprintf(comment, sizeof comment,
             "tiled texture by tiledtex %s: %d quads, %d colors, %d-texel tiles, gutter %d",
             TILEDTEX_VERSION_STRING, mesh->mesh->nfaces, mesh->layout.colors, mesh->layout.tile_size,
             mesh->layout.gutter);
    desc.comment = comment;
    desc.nverts = mesh->mesh->nverts;
    desc.pos = mesh->mesh->pos;
    desc.nfaces = mesh->mesh->nfaces;
    desc.fixed_face_size = 4;
    desc.corner_vert = mesh->mesh->corner_vert;
    desc.corner_uv = mesh->corner_uv;
    desc.mtllib = mtl_name;
    desc.material = mtl_name ? "tiled" : NULL;
    if (obj_write(&text, &desc) != 0 || output_add_buffer(output, obj_path, &text) != 0) {
        buffer_free(&text);
        return tool_fail("out of memory while writing %s", obj_path);
    }
    return 0;
}

int tiled_add_mtl(tool_output *output, const char *mtl_path, const char *texture_name)
{
    tool_buffer text;
    memset(&text, 0, sizeof text);
    mtl_add_material(&text, "tiled", texture_name, 0);
    if (output_add_buffer(output, mtl_path, &text) != 0) {
        buffer_free(&text);
        return tool_fail("out of memory while writing %s", mtl_path);
    }
    return 0;
}

static int compare_floats(const void *a, const void *b)
{
    float x = *(const float *)a, y = *(const float *)b;
    return x < y ? -1 : x > y;
}

/* The rest of the quality report: how evenly the tiles are used (every tile
   equally often is what keeps repetition invisible) and how much each face
   stretches its tile (the ratio of the singular values of its map). */
static void print_quality(const tiled_mesh *mesh)
{
    int ntiles = tt_tile_layout_tile_count(&mesh->layout), nfaces = mesh->mesh->nfaces, used = 0, least = -1,
        most = 0, t, f, degenerate = 0;
    int *counts = (int *)malloc((size_t)ntiles * sizeof(int));
    float *stretch = (float *)malloc((size_t)nfaces * sizeof(float));
    if (!counts || !stretch || tt_tile_histogram(mesh->mesh, &mesh->layout, mesh->corner_type, counts) != TT_OK ||
        tt_face_stretch(mesh->mesh, mesh->corner_uv, stretch) != TT_OK) {
        free(counts);
        free(stretch);
        return;
    }
    for (t = 0; t < ntiles; t++) {
        if (counts[t] > 0) used++;
        if (least < 0 || counts[t] < least) least = counts[t];
        if (counts[t] > most) most = counts[t];
    }
    qsort(stretch, (size_t)nfaces, sizeof(float), compare_floats);
    for (f = nfaces; f > 0 && !(stretch[f - 1] < 1e30f); f--) degenerate++;
    printf("quality: %d of %d tiles used (%d to %d faces each, %.1f on average)", used, ntiles, least, most,
           (double)nfaces / ntiles);
    if (nfaces > degenerate)
        printf("; stretch median %.2f, 95th percentile %.2f, max %.2f", stretch[(nfaces - degenerate) / 2],
               stretch[(int)(0.95 * (nfaces - degenerate - 1))], stretch[nfaces - degenerate - 1]);
    if (degenerate > 0) printf("; %d degenerate face%s", degenerate, degenerate == 1 ? "" : "s");
    printf("\n");
    free(counts);
    free(stretch);
}

int tiled_check_atlas_size(const tiled_options *options)
{
    tt_tile_layout layout;
    tt_error error;
    int atlas;
    if (tt_tile_layout_resolve(&options->layout, &layout, &error) != TT_OK) return tool_fail("%s", error.message);
    atlas = tt_tile_layout_atlas_size(&layout);
    if (atlas > TOOL_MAX_ATLAS)
        return tool_fail("--colors %d with %d-texel tiles and gutter %d makes a %dx%d atlas; the tool writes at most "
                         "%dx%d (use fewer --colors or a smaller --tile)",
                         layout.colors, layout.tile_size, layout.gutter, atlas, atlas, TOOL_MAX_ATLAS, TOOL_MAX_ATLAS);
    return 0;
}

void tiled_print_notes(const char *obj_path, const tiled_mesh *mesh)
{
    if (mesh->repaired_edges > 0)
        fprintf(stderr, "tiledtex: %s: --permissive cut %d non-manifold or mis-oriented edge%s open\n", obj_path,
                mesh->repaired_edges, mesh->repaired_edges == 1 ? "" : "s");
    if (mesh->quadrangulated) {
        char sizes[64];
        if (mesh->input_max_face_size == 3) snprintf(sizes, sizeof sizes, "triangles");
        else snprintf(sizes, sizeof sizes, "faces of %d to %d corners", mesh->input_min_face_size,
                      mesh->input_max_face_size);
        fprintf(stderr, "tiledtex: %s has %s: quadrangulated %d face%s into %d quads\n", obj_path, sizes,
                mesh->input_faces, mesh->input_faces == 1 ? "" : "s", mesh->quadrangulated);
    }
}

void tiled_print_summary(const char *obj_path, const tiled_mesh *mesh, const tt_seam_report *seams, int report)
{
    const tt_mesh_stats *s = &mesh->stats;
    printf("%s: %d quads, %d vertices, genus %d, %d component%s, %d boundary loop%s, valence %d..%d, "
           "%d tiles (n=%d, %d texels, gutter %d)",
           obj_path, mesh->mesh->nfaces, s->used_vertices, s->genus, s->components, s->components == 1 ? "" : "s",
           s->boundary_loops, s->boundary_loops == 1 ? "" : "s", s->min_valence, s->max_valence,
           tt_tile_layout_tile_count(&mesh->layout), mesh->layout.colors, mesh->layout.tile_size,
           mesh->layout.gutter);
    if (seams && seams->score == seams->score)
        printf(", seam score %.3f (seam %.4f, same-face %.4f, unrelated %.4f)", seams->score, seams->seam,
               seams->same_face, seams->unrelated);
    else if (seams)
        printf(", seam score n/a: unrelated places differ no more than neighbours (seam %.4f, same-face %.4f, "
               "unrelated %.4f)", seams->seam, seams->same_face, seams->unrelated);
    printf("\n");
    if (report) print_quality(mesh);
}

/* With --atlas: the atlas must have the layout's size. When --tile was not
   given, the tile size is read off the atlas instead (W = T * (S + 2g)). */
static int load_atlas_for_layout(const char *path, tiled_options *options, tt_image *atlas)
{
    char message[TOOL_ERROR_SIZE];
    tt_tile_layout layout;
    tt_error error;
    int tiles_per_side;
    if (image_load(path, atlas, message, sizeof message) != 0) return tool_fail("%s", message);
    if (tt_tile_layout_resolve(&options->layout, &layout, &error) != TT_OK) {
        tt_image_free(atlas);
        return tool_fail("%s", error.message);
    }
    tiles_per_side = tt_tile_layout_tiles_per_side(&layout);
    if (!options->tile_size_given && atlas->width == atlas->height && atlas->width % tiles_per_side == 0 &&
        atlas->width / tiles_per_side - 2 * layout.gutter >= 4)
        options->layout.tile_size = layout.tile_size = atlas->width / tiles_per_side - 2 * layout.gutter;
    if (atlas->width != tt_tile_layout_atlas_size(&layout) || atlas->height != atlas->width) {
        int expected = tt_tile_layout_atlas_size(&layout), width = atlas->width, height = atlas->height;
        tt_image_free(atlas);
        return tool_fail("%s is %dx%d, but --colors %d --tile %d --gutter %d make %dx%d atlases", path, width,
                         height, layout.colors, layout.tile_size, layout.gutter, expected, expected);
    }
    return 0;
}

int cmd_map(int argc, char **argv)
{
    const char *positional[2];
    int status;
    tiled_options options;
    tiled_mesh mesh;
    tt_image atlas;
    tt_seam_report seams;
    tool_output output;
    char message[TOOL_ERROR_SIZE], mtl_path[4096];

    memset(&output, 0, sizeof output);
    memset(&atlas, 0, sizeof atlas);
    status = tiled_parse_command_line(argc, argv,
                                      TILED_LAYOUT_OPTIONS | TILED_MESH_OPTIONS | TILED_ATLAS_OPTION | TILED_REPORT_OPTION,
                                      &options, positional, 2, "MESH.obj and OUT.obj", print_help);
    if (status >= 0) return status;

    if (options.atlas_path && (status = load_atlas_for_layout(options.atlas_path, &options, &atlas)) != 0)
        return status;
    if ((status = tiled_check_atlas_size(&options)) != 0 ||
        (status = tiled_map_mesh(positional[0], &options, &mesh)) != 0) {
        tt_image_free(&atlas);
        return status;
    }
    if (options.atlas_path) {
        char texture[4096];
        if (tt_measure_seams(mesh.mesh, mesh.corner_uv, &atlas, options.seed, &seams) != TT_OK) {
            status = tool_fail("out of memory while measuring the seams of %s", positional[0]);
            goto done;
        }
        /* The MTL sits beside the OBJ, and names the atlas relative to itself. */
        snprintf(mtl_path, sizeof mtl_path, "%.*s.mtl",
                 (int)(strlen(positional[1]) > 4 && strcmp(positional[1] + strlen(positional[1]) - 4, ".obj") == 0
                           ? strlen(positional[1]) - 4 : strlen(positional[1])),
                 positional[1]);
        tool_relative_path(options.atlas_path, mtl_path, texture, sizeof texture);
        status = tiled_add_mtl(&output, mtl_path, texture);
        if (status == 0) status = tiled_add_obj(&output, positional[1], &mesh, tool_basename(mtl_path));
    } else {
        status = tiled_add_obj(&output, positional[1], &mesh, NULL);
    }
    if (status == 0 && output_commit(&output, message, sizeof message) != 0) status = tool_fail("%s", message);
    if (status == 0) {
        tiled_print_notes(positional[0], &mesh);
        tiled_print_summary(positional[0], &mesh, options.atlas_path ? &seams : NULL, options.report);
    }
done:
    output_free(&output);
    tiled_mesh_free(&mesh);
    tt_image_free(&atlas);
    return status;
}
