/* tiled.c - the tiled-texture steps `tiledtex synth`, `map` and `tile` share
   (see tiled.h): their options, mapping a mesh (Akleman et al.'s algorithm,
   Sec. 3, as a library user calls it), synthesising the atlas, writing the
   OBJ / MTL / PNG files, and the summary lines.

   Mapping a mesh:
     tt_mesh_build          validate the OBJ's faces into a half-edge mesh
     tt_mesh_quadrangulate  only when there are triangles or n-gons: each
                            n-gon becomes n quads (and again per --subdivide)
     tt_assign_boundaries   a random boundary type per half-edge, twins
                            complementary (seeded: same seed, same result)
     tt_assign_uvs          one UV per corner: the tile named by its four
                            boundary types, at its place in the atlas
   With --up or --constraints, instead of tt_assign_uvs:
     tt_tangent_field       the texture's up per quad (tool_make_face_field)
     tt_orient_tiles        each quad's tile turned to it, and the quads that
                            can show upright tiles
     tt_assign_uvs_oriented the UVs of the turned tiles, upright ones in the
                            right half of a plain | upright atlas
*/
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tiled.h"

void tiled_default_options(tiled_options *options)
{
    memset(options, 0, sizeof *options);
    options->layout.gutter = TT_RECOMMENDED_GUTTER;
}

int tiled_parse_option(int argc, char **argv, int *index, unsigned accept, tiled_options *options)
{
    const char *value;
    int number, taken;
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
    } else if ((accept & TILED_MESH_OPTIONS) && (taken = parse_mesh_option(argc, argv, index, &options->mesh)) != 0) {
        if (taken < 0) return -1;
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
    } else if ((accept & TILED_SYNTH_OPTIONS) && tool_flag(argv[*index], "--mips")) {
        options->mips = 1;
    } else if ((accept & TILED_REPORT_OPTION) && tool_flag(argv[*index], "--report")) {
        options->report = 1;
    } else if ((accept & TILED_MATERIAL_OPTIONS) && (taken = material_parse_option(argc, argv, index, &options->maps))) {
        if (taken < 0) return -1;
    } else if ((accept & (TILED_TRIANGLES_OPTION | TILED_FORMAT_OPTION)) &&
               (taken = parse_mesh_output_option(argc, argv, index, accept & TILED_FORMAT_OPTION,
                                                 &options->output)) != 0) {
        if (taken < 0) return -1;
    } else if ((accept & TILED_FIELD_OPTIONS) && (taken = parse_field_option(argc, argv, index, &options->field))) {
        if (taken < 0) return -1;
    } else if ((accept & TILED_FIELD_OPTIONS) && tool_flag(argv[*index], "--no-courses")) {
        options->no_courses = 1;
    } else if ((accept & TILED_FIELD_OPTIONS) && tool_option(argc, argv, index, "--remesh", &value)) {
        options->remesh = 1;
        options->remesh_size = 0.0;
        if (!value || (strcmp(value, "auto") != 0 &&
                       (parse_whole_double(value, &options->remesh_size) != 0 || !(options->remesh_size > 0.0)))) {
            tool_usage("--remesh wants the quads' side in mesh units (above 0) or 'auto', got '%s'",
                       value ? value : "nothing");
            return -1;
        }
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
    free(mesh->corner_normal);
    free(mesh->corner_type);
    free(mesh->corner_uv);
    free(mesh->face_turn);
    free(mesh->face_upright);
    memset(mesh, 0, sizeof *mesh);
}

/* tool_quadrangulate, keeping each quad's OBJ face in *source (when not
   NULL): quad q of the result comes from corner q's face. */
static int quadrangulate_traced(const char *obj_path, tiled_mesh *out, int smooth, int **source)
{
    int *traced = NULL, q, status;
    if (*source) {
        traced = (int *)malloc((size_t)out->mesh->ncorners * sizeof(int));
        if (!traced) return tool_fail("out of memory for the %d quads of %s", out->mesh->ncorners, obj_path);
        for (q = 0; q < out->mesh->ncorners; q++) traced[q] = (*source)[out->mesh->corner_face[q]];
    }
    status = tool_quadrangulate(obj_path, &out->mesh, smooth, NULL, &out->corner_normal);
    if (status != 0) {
        free(traced);
        return status;
    }
    if (traced) {
        free(*source);
        *source = traced;
    }
    return 0;
}

/* The direction field on the quads, each quad's tile turned to it, and
   the UVs of those tiles. */
static int orient_tiles(const char *obj_path, const tiled_options *options, const int *source, const int *lines,
                        int nsources, tiled_mesh *out)
{
    const int nfaces = out->mesh->nfaces;
    float *vectors = (float *)malloc((size_t)nfaces * 3 * sizeof(float));
    int *first = (int *)calloc((size_t)nsources, sizeof(int));
    tool_face_source faces;
    tt_error error;
    int f, status;
    out->face_turn = (uint8_t *)malloc((size_t)nfaces);
    out->face_upright = options->upright ? (uint8_t *)malloc((size_t)nfaces) : NULL;
    if (!vectors || !first || !out->face_turn || (options->upright && !out->face_upright)) {
        free(vectors);
        free(first);
        return tool_fail("out of memory for the direction field of %d quads", nfaces);
    }
    for (f = nfaces - 1; f >= 0; f--) first[source[f]] = f;
    faces.mesh = out->mesh;
    faces.nfaces = nfaces;
    faces.nsources = nsources;
    faces.source = source;
    faces.first = first;
    faces.source_line = lines;
    status = tool_make_face_field(obj_path, &faces, &options->field, 0.0f, vectors);
    free(first);
    if (status == 0 && (tt_orient_tiles(out->mesh, vectors, out->face_turn, out->face_upright, &out->upright_faces,
                                        &error) != TT_OK ||
                        tt_assign_uvs_oriented(out->mesh, &out->layout, out->corner_type, out->face_turn,
                                               out->face_upright, out->corner_uv, &error) != TT_OK))
        status = tool_fail("%s: %s", obj_path, error.message);
    free(vectors);
    return status;
}

/* --remesh: the OBJ's mesh replaced by one whose quads follow the field
   (tt_remesh_quads), with up from --up (the library's +y without it) held
   as firmly as tt_field_face_weights says. The OBJ's normals do not carry
   over (the new mesh gets computed ones). With the field given, *source
   and *nsources then name the new faces themselves: the field is made
   again on the quads. */
static int remesh_along_field(const char *obj_path, const tiled_options *options, int **source, int *nsources,
                              tiled_mesh *out)
{
    const int nfaces = out->mesh->nfaces;
    float *vectors = (float *)malloc((size_t)nfaces * 3 * sizeof(float));
    float *weights = (float *)malloc((size_t)nfaces * sizeof(float));
    tt_field_options field;
    tt_remesh_options remesh;
    tt_mesh *remeshed = NULL;
    tt_error error;
    int f, status = 0;
    if (!vectors || !weights) {
        free(vectors);
        free(weights);
        return tool_fail("out of memory for the direction field of %d faces", nfaces);
    }
    memset(&field, 0, sizeof field);
    memcpy(field.up, options->field.up, sizeof field.up);
    memset(&remesh, 0, sizeof remesh);
    remesh.edge_length = (float)options->remesh_size;
    remesh.face_weights = weights;
    tool_stage("computing the direction field");
    if (tt_mesh_compute_stats(out->mesh, NULL, &out->input_stats, &error) != TT_OK ||
        tt_tangent_field(out->mesh, &field, NULL, vectors, &error) != TT_OK ||
        tt_field_face_weights(out->mesh, &field, weights, &error) != TT_OK)
        status = tool_fail("%s: %s", obj_path, error.message);
    if (status == 0) {
        tool_progress progress;
        tt_result result;
        tool_progress_begin(&progress, "remeshing", "along the field");
        remesh.progress = tool_show_progress;
        remesh.progress_user_data = &progress;
        result = tt_remesh_quads(out->mesh, vectors, &remesh, NULL, &remeshed, &out->remesh, &error);
        tool_progress_end(&progress);
        if (result != TT_OK && options->remesh_size > 0.0)
            status = tool_fail("%s: --remesh %g: %s", obj_path, options->remesh_size, error.message);
        else if (result != TT_OK)
            status = tool_fail("%s: --remesh auto: %s", obj_path, error.message);
    }
    free(vectors);
    free(weights);
    if (status != 0) return status;
    if (*source) {
        int *own = (int *)malloc((size_t)remeshed->nfaces * sizeof(int));
        if (!own) {
            tt_mesh_free(remeshed);
            return tool_fail("out of memory for the %d faces remeshed from %s", remeshed->nfaces, obj_path);
        }
        for (f = 0; f < remeshed->nfaces; f++) own[f] = f;
        free(*source);
        *source = own;
        *nsources = remeshed->nfaces;
    }
    tt_mesh_free(out->mesh);
    out->mesh = remeshed;
    free(out->corner_normal);
    out->corner_normal = NULL;
    out->remeshed = remeshed->nfaces;
    return 0;
}

int tiled_map_mesh(const char *obj_path, const tiled_options *options, tiled_mesh *out)
{
    obj_mesh obj;
    tt_mesh_desc desc;
    tt_error error;
    char message[TOOL_ERROR_SIZE];
    int status, step, f, *source = NULL, *lines = NULL, nsources;

    memset(out, 0, sizeof *out);
    if (tt_tile_layout_resolve(&options->layout, &out->layout, &error) != TT_OK)
        return tool_fail("%s", error.message);
    if (mesh_read(obj_path, &obj, message, sizeof message) != 0) return tool_fail("%s", message);

    desc = obj_mesh_desc(&obj, options->mesh.permissive ? TT_MESH_PERMISSIVE : 0);
    out->input_faces = obj.nfaces;
    if (options->field.given) {
        /* Each quad's OBJ face and the faces' lines, for --constraints. */
        source = (int *)malloc((size_t)obj.nfaces * sizeof(int));
        lines = (int *)malloc((size_t)obj.nfaces * sizeof(int));
        if (!source || !lines) {
            free(source);
            free(lines);
            obj_free(&obj);
            return tool_fail("out of memory for the %d faces of %s", obj.nfaces, obj_path);
        }
        for (f = 0; f < obj.nfaces; f++) source[f] = f;
        memcpy(lines, obj.face_line, (size_t)obj.nfaces * sizeof(int));
    }
    tool_stage("checking the mesh");
    if (tt_mesh_build(&desc, NULL, &out->mesh, &error) != TT_OK) {
        status = obj_report_mesh_error(obj_path, &obj, &error, 1);
        obj_free(&obj);
        free(source);
        free(lines);
        return status;
    }
    /* The mesh's corners are the OBJ's, in order. */
    status = obj_corner_normals(obj_path, &obj, &out->corner_normal);
    obj_free(&obj);
    if (status != 0) {
        tiled_mesh_free(out);
        free(source);
        free(lines);
        return tool_fail("out of memory for the normals of %s", obj_path);
    }
    out->repaired_edges = out->mesh->repaired_edges;
    out->input_min_face_size = out->mesh->min_face_size;
    out->input_max_face_size = out->mesh->max_face_size;
    nsources = out->input_faces;
    if (options->remesh) {
        if ((status = remesh_along_field(obj_path, options, &source, &nsources, out)) != 0) goto fail;
        /* The constraints' lines name the OBJ's faces; the new ones have none. */
        free(lines);
        lines = NULL;
    }

    /* Tiles are square: every face must be a quad. */
    if (out->mesh->min_face_size != 4 || out->mesh->max_face_size != 4) {
        if ((status = quadrangulate_traced(obj_path, out, 0, &source)) != 0) goto fail;
        out->quadrangulated = out->mesh->nfaces;
    }
    if ((status = tool_check_subdivide(obj_path, out->mesh, options->mesh.subdivide)) != 0) goto fail;
    for (step = 0; step < options->mesh.subdivide; step++)
        if ((status = quadrangulate_traced(obj_path, out, options->mesh.smooth, &source)) != 0) goto fail;

    out->corner_type = (uint8_t *)malloc((size_t)out->mesh->ncorners);
    out->corner_uv = (float *)malloc((size_t)out->mesh->ncorners * 2 * sizeof(float));
    if (!out->corner_type || !out->corner_uv) {
        status = tool_fail("out of memory for %d corners", out->mesh->ncorners);
        goto fail;
    }
    /* NULL edge colours: every edge's condition comes from the seed. */
    if (tt_assign_boundaries(out->mesh, &out->layout, options->seed, NULL, out->corner_type, &error) != TT_OK ||
        tt_assign_uvs(out->mesh, &out->layout, out->corner_type, out->corner_uv, &error) != TT_OK) {
        status = tool_fail("%s: %s", obj_path, error.message);
        goto fail;
    }
    if (source && (status = orient_tiles(obj_path, options, source, lines, nsources, out)) != 0) goto fail;
    if (tt_mesh_compute_stats(out->mesh, NULL, &out->stats, &error) != TT_OK) {
        status = tool_fail("%s: %s", obj_path, error.message);
        goto fail;
    }
    free(source);
    free(lines);
    return 0;
fail:
    free(source);
    free(lines);
    tiled_mesh_free(out);
    return status;
}

/* The quads with their tiles' UVs and shading normals, for either file. */
static void tiled_write_desc(const tiled_mesh *mesh, const float *normals, obj_write_desc *desc)
{
    memset(desc, 0, sizeof *desc);
    desc->nverts = mesh->mesh->nverts;
    desc->pos = mesh->mesh->pos;
    desc->nfaces = mesh->mesh->nfaces;
    desc->fixed_face_size = 4;
    desc->corner_vert = mesh->mesh->corner_vert;
    desc->corner_uv = mesh->corner_uv;
    desc->corner_normal = normals;
}

int tiled_add_obj(tool_output *output, const char *obj_path, const tiled_mesh *mesh, const char *mtl_name,
                  int triangles)
{
    obj_write_desc desc;
    char comment[256];
    float *normals = tool_corner_normals(obj_path, mesh->mesh, mesh->corner_normal);
    int status;
    if (!normals) return TOOL_EXIT_FAILURE;
    tiled_write_desc(mesh, normals, &desc);
    snprintf(comment, sizeof comment,
             "tiled texture by tiledtex %s: %d quads, %d colors, %d-texel tiles, gutter %d",
             TILEDTEX_VERSION_STRING, mesh->mesh->nfaces, mesh->layout.colors, mesh->layout.tile_size,
             mesh->layout.gutter);
    desc.comment = comment;
    desc.mtllib = mtl_name;
    desc.material = mtl_name ? "tiled" : NULL;
    desc.triangles = triangles;
    desc.share_equal = 1;
    status = output_add_obj(output, obj_path, &desc);
    free(normals);
    return status;
}

int tiled_add_gltf(tool_output *output, const char *gltf_path, const tiled_mesh *mesh, const tool_material *material)
{
    obj_write_desc desc;
    float *normals = tool_corner_normals(gltf_path, mesh->mesh, mesh->corner_normal);
    int status;
    if (!normals) return TOOL_EXIT_FAILURE;
    tiled_write_desc(mesh, normals, &desc);
    status = output_add_gltf(output, gltf_path, &desc, material);
    free(normals);
    return status;
}

int tiled_add_mtl(tool_output *output, const char *mtl_path, const char *texture_name, const char *const *map_names)
{
    tool_buffer text;
    memset(&text, 0, sizeof text);
    mtl_add_material(&text, "tiled", texture_name, 0, map_names);
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
   stretches its tile (the ratio of the singular values of its map). With
   --up a tile counts once whether plain or upright. */
static void print_quality(const tiled_mesh *mesh)
{
    int ntiles = tt_tile_layout_tile_count(&mesh->layout), nfaces = mesh->mesh->nfaces, used = 0, least = -1,
        most = 0, t, f, degenerate = 0;
    int *counts = (int *)malloc((size_t)ntiles * sizeof(int));
    float *stretch = (float *)malloc((size_t)nfaces * sizeof(float)), *uv = NULL;
    uint8_t *types = NULL;
    tt_error error;
    if (!counts || !stretch) {
        printf("quality: not measured (out of memory)\n");
        free(counts);
        free(stretch);
        return;
    }
    if (mesh->face_turn) {
        /* Turned tiles: each quad's types from its tile's bottom side on,
           and the UVs of the four sets' atlas measured in a set's texels. */
        types = (uint8_t *)malloc((size_t)mesh->mesh->ncorners);
        uv = (float *)malloc((size_t)mesh->mesh->ncorners * 2 * sizeof(float));
        if (!types || !uv) {
            printf("quality: not measured (out of memory)\n");
            free(counts);
            free(stretch);
            free(types);
            free(uv);
            return;
        }
        for (f = 0; f < nfaces; f++)
            for (t = 0; t < 4; t++) types[4 * f + t] = mesh->corner_type[4 * f + ((t + mesh->face_turn[f]) & 3)];
        for (t = 0; t < mesh->mesh->ncorners; t++) {
            uv[2 * t] = mesh->face_upright ? 2.0f * mesh->corner_uv[2 * t] : mesh->corner_uv[2 * t];
            uv[2 * t + 1] = mesh->face_upright ? 2.0f * mesh->corner_uv[2 * t + 1] : mesh->corner_uv[2 * t + 1];
        }
    }
    if (tt_tile_histogram(mesh->mesh, &mesh->layout, types ? types : mesh->corner_type, counts, &error) != TT_OK ||
        tt_face_stretch(mesh->mesh, uv ? uv : mesh->corner_uv, stretch, &error) != TT_OK) {
        printf("quality: not measured (%s)\n", error.message);
        free(counts);
        free(stretch);
        free(types);
        free(uv);
        return;
    }
    free(types);
    free(uv);
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
    tool_note_cut_edges(obj_path, mesh->repaired_edges);
    if (mesh->remeshed) {
        const tt_remesh_report *r = &mesh->remesh;
        const tt_mesh_stats *in = &mesh->input_stats, *s = &mesh->stats;
        if (tool_quiet()) return;
        tool_progress_clear();
        fprintf(stderr, "tiledtex: %s remeshed along the field into %d quads of side about %g (from a lattice of "
                        "%d quad%s, %d triangle%s, %d pentagon%s and %d larger face%s, ", obj_path, mesh->remeshed,
                r->split_all ? 0.5 * r->edge_length : r->edge_length, r->quads, r->quads == 1 ? "" : "s",
                r->triangles, r->triangles == 1 ? "" : "s", r->pentagons, r->pentagons == 1 ? "" : "s",
                r->larger_faces, r->larger_faces == 1 ? "" : "s");
        if (r->split_all)
            fprintf(stderr, "each split into quads around its centre: some could not be paired");
        else
            fprintf(stderr, "%d joined into groups of quads", r->paired_faces);
        if (r->folded_faces) fprintf(stderr, "; %d folded", r->folded_faces);
        fprintf(stderr, ")\n");
        /* Where the surface is thinner than an edge, the new mesh closes a
           handle or a hole, or loses a piece smaller than a face. */
        if (in->genus != s->genus || in->components != s->components || in->boundary_loops != s->boundary_loops)
            fprintf(stderr, "tiledtex: the remeshed surface has genus %d, %d component%s and %d boundary loop%s; "
                            "%s has %d, %d and %d: parts of it are thinner than an edge (a smaller --remesh "
                            "follows them)\n", s->genus, s->components, s->components == 1 ? "" : "s",
                    s->boundary_loops, s->boundary_loops == 1 ? "" : "s", obj_path, in->genus, in->components,
                    in->boundary_loops);
        return;
    }
    if (mesh->quadrangulated) {
        char sizes[64];
        if (mesh->input_max_face_size == 3) snprintf(sizes, sizeof sizes, "triangles");
        else snprintf(sizes, sizeof sizes, "faces of %d to %d corners", mesh->input_min_face_size,
                      mesh->input_max_face_size);
        /* Like the notes: nothing but errors under --quiet. */
        if (tool_quiet()) return;
        tool_progress_clear();
        fprintf(stderr, "tiledtex: %s has %s: quadrangulated %d face%s into %d quads\n", obj_path, sizes,
                mesh->input_faces, mesh->input_faces == 1 ? "" : "s", mesh->quadrangulated);
        /* Each triangle becomes three kite-shaped quads, each showing a
           whole tile: on a dense scan the texture comes out a fraction of
           the part's size, with stars at the vertices, whatever --tile. */
        if (mesh->input_max_face_size == 3 && mesh->input_faces >= TILED_DENSE_TRIANGLES)
            fprintf(stderr, "tiledtex: %d triangles make %d tiny tiles with stars at the vertices: for a dense "
                            "triangle mesh use --remesh (quads of the size you choose, along the field), or "
                            "'tiledtex polycube', 'tiledtex hpm' or 'tiledtex lapped'\n", mesh->input_faces,
                    mesh->quadrangulated);
    }
}

void tiled_print_summary(const char *obj_path, const tiled_mesh *mesh, const tool_seams *seams,
                         const tool_seams *corners, int report)
{
    const tt_mesh_stats *s = &mesh->stats;
    printf("%s: %d quads, %d vertices, genus %d, %d component%s, %d boundary loop%s, valence %d..%d, "
           "%d tiles (n=%d, %d texels, gutter %d)",
           obj_path, mesh->mesh->nfaces, s->used_vertices, s->genus, s->components, s->components == 1 ? "" : "s",
           s->boundary_loops, s->boundary_loops == 1 ? "" : "s", s->min_valence, s->max_valence,
           tt_tile_layout_tile_count(&mesh->layout), mesh->layout.colors, mesh->layout.tile_size,
           mesh->layout.gutter);
    if (seams && !seams->measured) {
        printf(", seam score: not measured (%s)", seams->reason);
    } else if (seams) {
        const tt_seam_report *r = &seams->report;
        char edges[96];
        snprintf(edges, sizeof edges, "%d of %d edges%s", r->edges_measured, seams->edges,
                 seams->sampled ? " sampled" : "");
        if (r->score == r->score)
            printf(", seam score %.3f (%s; seam %.4f, same-face %.4f, unrelated %.4f)", r->score, edges, r->seam,
                   r->same_face, r->unrelated);
        else
            printf(", seam score n/a: unrelated places differ no more than neighbours (%s; seam %.4f, "
                   "same-face %.4f, unrelated %.4f)", edges, r->seam, r->same_face, r->unrelated);
    }
    if (corners) {
        char text[320];
        tool_format_seams(corners, "edges", text, sizeof text);
        printf("; near the tiles' corners (within %.0f %% of an edge's ends) %s", 100.0 * TOOL_CORNER_ENDS, text);
    }
    printf("\n");
    if (report) print_quality(mesh);
}

int tiled_fit_tile_size(int width, int height, int colors, int gutter)
{
    /* An edge window is S x 2S; at 2/5 of the smaller side it still has room
       to move, so synthesis can choose an inconspicuous line for the edges
       (with h = 2S exactly there is only one) and varied backgrounds. With
       more colors the atlas, (2n)^2 tiles a side, must stay within
       TOOL_MAX_ATLAS. Multiples of 8 keep mip levels per tile. */
    int side = width < height ? width : height, n = colors > 0 ? colors : 1;
    int fit = 2 * side / 5, fits_atlas = TOOL_MAX_ATLAS / (4 * n * n) - 2 * gutter;
    if (fit > TT_DEFAULT_TILE_SIZE) fit = TT_DEFAULT_TILE_SIZE;
    if (fit > fits_atlas) fit = fits_atlas;
    if (fit >= 8) return fit - fit % 8;
    if (fits_atlas >= 4 && width >= 4 && height >= 8) return 4;
    return 0;
}

int tiled_pick_tile_size(const char *image_path, int width, int height, tiled_options *options)
{
    int fit;
    if (options->tile_size_given) return 0;
    fit = tiled_fit_tile_size(width, height, options->layout.colors, options->layout.gutter);
    if (fit == 0)
        return tool_fail("%s is %dx%d: too small to cut tiles from (it needs at least 4x8 texels)", image_path,
                         width, height);
    options->layout.tile_size = fit;
    if (fit < TT_DEFAULT_TILE_SIZE)
        tool_note("%s is %dx%d: used %d-texel tiles (--tile to choose)", image_path, width, height, fit);
    return 0;
}

int tiled_find_courses(const tt_image *image, const char *image_path, const tiled_options *options,
                       tt_courses *courses)
{
    tt_error error;
    memset(courses, 0, sizeof *courses);
    if (options->no_courses) return 0;
    if (tt_find_courses(image, NULL, courses, &error) != TT_OK) return tool_fail("%s: %s", image_path, error.message);
    return 0;
}

int tiled_fit_courses(tt_image **image, const char *image_path, tiled_options *options, const tt_courses *found)
{
    const int S = options->layout.tile_size ? options->layout.tile_size : TT_DEFAULT_TILE_SIZE;
    tt_image *resized[1 + MATERIAL_MAPS] = {NULL};
    tt_courses courses;
    double scale, row_scale = 1.0;
    int courses_per_tile, width, height, map, status;
    memset(&options->courses, 0, sizeof options->courses);
    if (found)
        courses = *found;
    else if ((status = tiled_find_courses(*image, image_path, options, &courses)) != 0)
        return status;
    if (courses.period == 0.0f) return 0;
    /* The nearest whole number of courses to a tile: every band of an
       upright tile then starts where the tile above or below ends. */
    courses_per_tile = (int)floor(S / courses.period + 0.5);
    if (courses_per_tile < 1) courses_per_tile = 1;
    scale = S / (courses_per_tile * (double)courses.period);
    width = (int)floor((*image)->width * scale + 0.5);
    height = (int)floor((*image)->height * scale + 0.5);
    if (width < 2 * S || height < 2 * S) {
        tool_note("%s: courses every %.1f texels, but resampled to hold %d in a %d-texel tile it would be too small "
                  "for the tiles; its courses are not kept level (use a smaller --tile)",
                  image_path, (double)courses.period, courses_per_tile, S);
        return 0;
    }
    if (fabs(scale - 1.0) > 1e-3) {
        row_scale = (double)height / (*image)->height;
        if (image_resize(*image, width, height, &resized[0]) != 0) return tool_fail("out of memory");
        for (map = 0; map < MATERIAL_MAPS; map++)
            if (options->maps.images[map] && image_resize(options->maps.images[map], width, height,
                                                          &resized[1 + map]) != 0) {
                for (map = 0; map <= MATERIAL_MAPS; map++) image_free(resized[map]);
                return tool_fail("out of memory");
            }
        image_free(*image);
        *image = resized[0];
        for (map = 0; map < MATERIAL_MAPS; map++)
            if (resized[1 + map]) {
                image_free(options->maps.images[map]);
                options->maps.images[map] = resized[1 + map];
            }
    }
    /* Where the courses now lie: scaled with the rows. */
    options->courses = courses;
    options->courses.period = (float)(courses.period * row_scale);
    options->courses.phase = (float)(courses.phase * row_scale);
    if (row_scale != 1.0)
        tool_note("%s has courses every %.1f texels: resampled by %.3g so that a %d-texel tile holds %d, and every "
                  "tile cut on them, so they run level from tile to tile (--no-courses: as it is)",
                  image_path, (double)courses.period, scale, S, courses_per_tile);
    else
        tool_note("%s has courses every %.1f texels, %d to a %d-texel tile: every tile cut on them, so they run "
                  "level from tile to tile (--no-courses: anywhere)",
                  image_path, (double)courses.period, courses_per_tile, S);
    return 0;
}

int tiled_synthesize(const tt_image *image, const char *image_path, const tiled_options *options,
                     const material_maps *maps, tt_tileset **out, tt_tileset **map_tiles)
{
    tt_synth_options synth;
    tt_synth_plan *plan = NULL;
    tt_error error;
    tool_progress progress;
    tt_result result;
    int map;
    *out = NULL;
    for (map = 0; maps && map < MATERIAL_MAPS; map++) map_tiles[map] = NULL;
    memset(&synth, 0, sizeof synth);
    synth.layout = options->layout;
    synth.seed = options->seed;
    synth.background = options->background;
    synth.courses = options->courses;
    synth.levels = options->levels;
    synth.executor = tool_executor();
    if (options->nedges > 0) {
        int colors = options->layout.colors ? options->layout.colors : 1;
        if (options->nedges != colors)
            return tool_usage("--edge was given %d time%s, but there %s %d color%s: give it once per color",
                              options->nedges, options->nedges == 1 ? "" : "s", colors == 1 ? "is" : "are", colors,
                              colors == 1 ? "" : "s");
        synth.edge_windows = options->edges;
    }
    if (options->upright_over) {
        synth.edge_windows = options->upright_over;
        synth.upright = 1;
        synth.plain_sides = options->plain_sides;
    }
    /* One plan, from the colour image, for every map: the maps' tiles are
       cut where the colour's are, and line up texel for texel. */
    tool_progress_begin(&progress, "synthesis", "of the tiles");
    synth.progress = tool_show_progress;
    synth.progress_user_data = &progress;
    result = tt_synth_plan_create(image, &synth, NULL, &plan, &error);
    if (result == TT_OK) result = tt_synth_apply(plan, image, NULL, out, &error);
    if (result != TT_OK) {
        tool_progress_end(&progress);
        tt_synth_plan_free(plan);
        if (error.result == TT_ERROR_IMAGE_TOO_SMALL || error.result == TT_ERROR_INVALID_ARGUMENT)
            return tool_fail("%s: %s", image_path, error.message);
        return tool_fail("%s", error.message);
    }
    for (map = 0; maps && map < MATERIAL_MAPS; map++) {
        if (!maps->images[map]) continue;
        if (tt_synth_apply(plan, maps->images[map], NULL, &map_tiles[map], &error) != TT_OK) {
            int status;
            tool_progress_end(&progress);
            status = tool_fail("%s: %s", maps->paths[map], error.message);
            tt_synth_plan_free(plan);
            tiled_tilesets_free(out, maps ? map_tiles : NULL);
            return status;
        }
    }
    tool_progress_end(&progress);
    tt_synth_plan_free(plan);
    return 0;
}

void tiled_tilesets_free(tt_tileset **tiles, tt_tileset **map_tiles)
{
    int map;
    tt_tileset_free(*tiles);
    *tiles = NULL;
    for (map = 0; map_tiles && map < MATERIAL_MAPS; map++) {
        tt_tileset_free(map_tiles[map]);
        map_tiles[map] = NULL;
    }
}

int tiled_synthesize_upright(const tt_image *image, const char *image_path, const tiled_options *options,
                             const tt_tileset *plain, tt_tileset *upright[TILED_UPRIGHT_SETS],
                             tt_tileset *map_upright[TILED_UPRIGHT_SETS][MATERIAL_MAPS])
{
    static const int plain_sides[TILED_UPRIGHT_SETS] = {0, 1 << 1, 1 << 3};
    int k, status;
    for (k = 0; k < TILED_UPRIGHT_SETS; k++) {
        tiled_options over = *options;
        over.upright_over = plain->edge_windows;
        over.plain_sides = plain_sides[k];
        if ((status = tiled_synthesize(image, image_path, &over, &options->maps, &upright[k], map_upright[k])) != 0)
            return status;
    }
    return 0;
}

void tiled_upright_free(tt_tileset *upright[TILED_UPRIGHT_SETS],
                        tt_tileset *map_upright[TILED_UPRIGHT_SETS][MATERIAL_MAPS])
{
    int k;
    for (k = 0; k < TILED_UPRIGHT_SETS; k++) tiled_tilesets_free(&upright[k], map_upright[k]);
}

void tiled_tileset_kinds(const tt_tileset *plain, tt_tileset *const upright[TILED_UPRIGHT_SETS],
                         const tt_tileset *sets[TT_TILESET_KINDS])
{
    int k;
    sets[TT_TILESET_PLAIN] = plain;
    for (k = 0; k < TILED_UPRIGHT_SETS; k++) sets[TT_TILESET_UPRIGHT + k] = upright[k];
}

int tiled_add_atlas(tool_output *output, const char *png_path, const tt_tileset *tiles, int mips,
                    tt_color_space space)
{
    char message[TOOL_ERROR_SIZE], path[4096];
    int level;
    size_t stem = strlen(png_path);
    /* The atlas and its mip levels are colour: encoded to sRGB. The levels
       are the library's linear-light averages, so a black and white
       checkerboard's mip is sRGB 188, as the eye averages it. */
    if (output_add_png(output, png_path, &tiles->levels[0], space, message, sizeof message) != 0)
        return tool_fail("%s", message);
    if (stem > 4 && strcmp(png_path + stem - 4, ".png") == 0) stem -= 4;
    for (level = 1; mips && level < tiles->nlevels; level++) {
        snprintf(path, sizeof path, "%.*s_mip%d.png", (int)stem, png_path, level);
        if (output_add_png(output, path, &tiles->levels[level], space, message, sizeof message) != 0)
            return tool_fail("%s", message);
    }
    return 0;
}
