/* hpm.c - `tiledtex hpm`: texture a mesh with Soler et al.'s hierarchical
   pattern mapping.

   MESH + IMAGE -> OUT_PREFIX.obj, the mesh's triangles with one texture
   coordinate per face corner into IMAGE itself, and OUT_PREFIX.mtl naming
   IMAGE where it is. No texture is made: the method cuts the surface into
   clusters, coarse to fine, and places each on the image where what it shows
   best continues its textured neighbours.

   The library calls, as a user of tiledtex.h makes them:

     tt_mesh_build       validate the OBJ's faces, split into triangle fans
                         first: the method works on triangles
     tt_mesh_quadrangulate  --subdivide (by default as many times as the
                         texture's scale asks: hpm_auto_steps)
     tt_tangent_field    with --up or --constraints, the direction the
                         image's up follows on each face
     tt_hpm_map          the whole pipeline: cluster hierarchy, flattening,
                         band fits, traversal, per-corner UVs
     tt_measure_seams    how well the texture continues across the cluster
                         borders (and across every edge)
     tt_measure_uv_distortion  stretch, texel density, flipped triangles
     tt_measure_uv_direction   with a direction, how level the image lies on
                         the walls
*/
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tool.h"

/* --subdivide auto (the default; hpm_auto_steps below). Clusters are made
   of whole triangles, and the library stops splitting them at the floor:
   TT_DEFAULT_HPM_MIN_FACES faces or TT_DEFAULT_HPM_MIN_FOOTPRINT texels^2,
   whichever comes first. Where the median triangle alone covers more than
   half that footprint, the faces decide: the clusters at the floor are
   many footprints large, fitted whatever their error, with long straight
   borders that show (the bunny's 3.7k triangles with gravel: border seams
   0.37; subdivided once, 0.10). Each step of --subdivide makes a triangle
   6, then 4 times as many; a mesh already finer gains nothing and pays
   the time (a 14k-face knot tube: 0.10 either way, 3 times the CPU). A
   12-triangle cube takes six steps (0.67 after three, 0.01 after six).
   docs/hpm.md has the measures. */
#define HPM_AUTO_TRIANGLE_TEXELS (0.5 * TT_DEFAULT_HPM_MIN_FOOTPRINT)
#define HPM_AUTO_MAX_STEPS 8   /* --subdivide's own limit */
#define HPM_AUTO_MAX_TRIANGLES 1000000  /* no step past this many triangles */

static void print_help(void)
{
    printf("usage: tiledtex hpm MESH IMAGE OUT_PREFIX [options]\n"
           "\n"
           "Texture MESH with coordinates into IMAGE itself (Soler et al., Hierarchical Pattern\n"
           "Mapping): no new texture is made. The surface is cut into clusters, coarse to fine;\n"
           "each is flattened and placed on the image where its content best continues the\n"
           "clusters already textured around it, and split into smaller ones when no place fits\n"
           "well enough. Writes OUT_PREFIX.obj (the triangles with one texture coordinate per\n"
           "face corner), OUT_PREFIX.mtl and a copy of IMAGE beside them, OUT_PREFIX.png (or .jpg:\n"
           "a PNG or JPEG is copied byte for byte, another format written as a PNG), so that the\n"
           "folder can move. Look at it with 'tiledtex render OUT_PREFIX.obj OUT_PREFIX.png\n"
           "view.png'.\n"
           "Faces with more than 3 corners are split into triangle fans first. The mesh must be\n"
           "manifold and consistently oriented (--permissive cuts bad edges open).\n");
    tool_print_mesh_help(1);
    printf("OUT_PREFIX is a name without extension; one ending in .obj, .mtl or .png loses it\n"
           "('out.obj' writes out.obj, not out.obj.obj); one ending in .glb writes OUT_PREFIX.glb\n"
           "(--format glb), one ending in .gltf OUT_PREFIX.gltf (--format gltf). It may be '-' (the\n"
           "standard output) only for a GLB, one file.\n"
           "\n"
           "options:\n"
           "  --scale X        mesh units covered by the image's width (default: a quarter of the\n"
           "                   mesh's bounding-box diagonal)\n"
           "  --seed K         random seed: clusters, turns, starting places (default 0)\n"
           "  --threshold E    the largest fit error accepted before a cluster is split into\n"
           "                   smaller ones (default %g; 0 is a perfect continuation, about 1\n"
           "                   unrelated pixels; 'inf' accepts every fit)\n"
           "  --rotations R    orientations around the circle, 1 to 64 (default %d: steps of 19\n"
           "                   degrees)\n"
           "  --max-turn DEG   a fit tries only the orientations within DEG degrees of its main\n"
           "                   textured neighbour's, so the pattern keeps its direction (default\n"
           "                   %g; with --up, within DEG of it, default %g; 180: every orientation,\n"
           "                   as in the paper)\n"
           "  --band W         width in texels of the textured border a fit matches (default:\n"
           "                   per cluster, a fifth of its radius, 3 to 24)\n",
           TT_DEFAULT_HPM_THRESHOLD, TT_DEFAULT_HPM_ROTATIONS, TT_DEFAULT_HPM_MAX_TURN, TT_DEFAULT_HPM_FIELD_MAX_TURN);
    printf("  --up DIR         the image's up direction, projected on each face: x, y, z, -x, -y,\n"
           "                   -z or X,Y,Z. Each cluster is turned so that the image's up follows\n"
           "                   it, and --max-turn counts from it: bricks lie level. Without it\n"
           "                   (and --constraints) the direction spreads from patch to patch and\n"
           "                   wanders over a large mesh\n"
           "  --constraints FILE  the direction at chosen faces instead, one per line:\n"
           "                   FACE X Y Z [SIGMA [WEIGHT]] (FACE counts the OBJ's faces from 1, X Y Z\n"
           "                   points up along the face, SIGMA in mesh units is how far it reaches,\n"
           "                   WEIGHT its weight; '#' starts a comment); elsewhere the directions\n"
           "                   blend the constraints\n"
           "  --toroidal       IMAGE tiles: placements wrap around its edges, and texture\n"
           "                   coordinates leave [0,1] (render with repeat, as 'tiledtex render'\n"
           "                   does); without it every coordinate stays inside the image\n"
           "  --no-fit         the control: the same clusters, each placed at random\n"
           "  --format F       obj (default): the OBJ and MTL above; glb: one binary glTF file,\n"
           "                   OUT_PREFIX.glb, with IMAGE in it (as a PNG; repeated under --toroidal);\n"
           "                   gltf: the same as glTF text, OUT_PREFIX.gltf, with OUT_PREFIX.bin and\n"
           "                   OUT_PREFIX_baseColor.png (and a PNG per map) beside it\n"
           "  --triangles      accepted for the OBJ, whose faces are triangles already\n");
    printf("  --subdivide L    make the triangles smaller first, L from 0 to 8, or auto (the\n"
           "                   default): quadrangulate them L times, as 'tiledtex tile' does, and\n"
           "                   split every quad into two triangles, so a triangle becomes 6, 24, 96,\n"
           "                   ... (the outputs have these). Clusters are made of whole triangles, so\n"
           "                   on a coarse mesh their borders are few, long and visible. auto\n"
           "                   subdivides (not past %d triangles) until the median triangle\n"
           "                   covers at most %g texels^2 at --scale, half the smallest patch,\n"
           "                   and says so; 0 keeps the mesh as it is\n"
           "  --smooth         Catmull-Clark positions when subdividing (rounder, a little smaller)\n"
           "  --permissive     accept non-manifold or mis-oriented edges (an edge shared by three\n"
           "                   faces, as some exports have): they are cut open into boundaries\n"
           "  --reference-image  no copies: the MTL names IMAGE (and the maps) where they are,\n"
           "                   relative to itself; keep them there\n"
           MATERIAL_OPTIONS_HELP("                   ")
           "                   (the UVs serve every map as they serve IMAGE: each is copied beside\n"
           "                   the OBJ as IMAGE is, OUT_PREFIX_normal.png and so on; a\n"
           "                   --normal-y-down map is written turned +Y up)\n"
           "\n"
           "Prints the clusters textured per level of the hierarchy, the fits (accepted, accepted\n"
           "at the smallest cluster size, rejected: split), clusters that continue a neighbour's\n"
           "map without a fit, new starts, the fit error, the texel density and the time; then the\n"
           "seam score on the cluster borders and over all edges (about 0: the texture continues,\n"
           "about 1: unrelated), the faces' stretch, the texel density's error and the number of\n"
           "mirrored triangles; with --up or --constraints, how far the image's up turns from --up\n"
           "(y by default) projected on the walls (faces at least 45 degrees from level): how\n"
           "level courses of bricks lie.\n"
           "\n"
           "example: tiledtex generate mesh torus.obj --shape torus\n"
           "         tiledtex generate texture stones.png --size 256\n"
           "         tiledtex hpm torus.obj stones.png torus_hpm --scale 3\n"
           "         tiledtex render torus_hpm.obj stones.png view.png\n",
           HPM_AUTO_MAX_TRIANGLES, HPM_AUTO_TRIANGLE_TEXELS);
}

typedef struct hpm_command_options {
    const char *mesh_path, *image_path;
    char prefix[TOOL_PREFIX_SIZE];  /* OUT_PREFIX without a known extension */
    tt_hpm_options map;     /* zero fields: the library's defaults */
    tool_field field;       /* --up, --constraints: the direction the image's up follows */
    material_maps maps;     /* --normal ...: the material's other maps, on the same UVs */
    tool_mesh_output output;        /* --format, --triangles */
    tool_mesh_options mesh;         /* --subdivide, --smooth, --permissive */
    int reference_image;            /* --reference-image: the MTL names IMAGE and the maps where they are */
} hpm_command_options;

/* --threshold: a number above 0, or "inf" (every fit accepted). */
static int parse_threshold(const char *value, double *threshold)
{
    if (!value) return tool_usage("--threshold needs a value");
    if (strcmp(value, "inf") == 0 || strcmp(value, "infinity") == 0) {
        *threshold = INFINITY;
        return 0;
    }
    if (parse_whole_double(value, threshold) != 0 || !(*threshold > 0.0))
        return tool_usage("--threshold wants a fit error above 0 or 'inf', got '%s'", value);
    return 0;
}

/* Returns -1 to go on, or the exit status to return now. */
static int parse_command_line(int argc, char **argv, hpm_command_options *options)
{
    const char *positional[3];
    int npositional = 0, i;
    memset(options, 0, sizeof *options);
    options->mesh.subdivide = TOOL_SUBDIVIDE_AUTO;
    options->mesh.auto_allowed = 1;
    for (i = 1; i < argc; i++) {
        const char *value;
        double number;
        int taken;
        if (tool_is_help(argv[i])) {
            print_help();
            return 0;
        } else if ((taken = parse_mesh_output_option(argc, argv, &i, 1, &options->output)) != 0) {
            if (taken < 0) return TOOL_EXIT_USAGE;
        } else if (tool_option(argc, argv, &i, "--scale", &value)) {
            if (!value) return tool_usage("--scale needs a value");
            if (parse_whole_double(value, &number) != 0 || !(number > 0.0) || number > 1e30)
                return tool_usage("--scale wants the mesh units the image's width covers, above 0, got '%s'",
                                  value);
            options->map.scale = number;
        } else if (tool_option(argc, argv, &i, "--seed", &value)) {
            if (parse_u64("--seed", value, &options->map.seed) != 0) return TOOL_EXIT_USAGE;
        } else if (tool_option(argc, argv, &i, "--threshold", &value)) {
            if (parse_threshold(value, &options->map.threshold) != 0) return TOOL_EXIT_USAGE;
        } else if (tool_option(argc, argv, &i, "--rotations", &value)) {
            if (parse_int("--rotations", value, 1, 64, &options->map.rotations) != 0) return TOOL_EXIT_USAGE;
        } else if (tool_option(argc, argv, &i, "--max-turn", &value)) {
            if (parse_float("--max-turn", value, 0.01, 180.0, &options->map.max_turn) != 0) return TOOL_EXIT_USAGE;
        } else if (tool_option(argc, argv, &i, "--band", &value)) {
            if (parse_float("--band", value, 1.0, 1e6, &options->map.band) != 0) return TOOL_EXIT_USAGE;
        } else if ((taken = parse_field_option(argc, argv, &i, &options->field)) != 0) {
            if (taken < 0) return TOOL_EXIT_USAGE;
        } else if ((taken = parse_mesh_option(argc, argv, &i, &options->mesh)) != 0) {
            if (taken < 0) return TOOL_EXIT_USAGE;
        } else if (tool_flag(argv[i], "--toroidal")) {
            options->map.flags |= TT_HPM_TOROIDAL;
        } else if (tool_flag(argv[i], "--no-fit")) {
            options->map.flags |= TT_HPM_RANDOM_PLACEMENT;
        } else if (tool_flag(argv[i], "--reference-image")) {
            options->reference_image = 1;
        } else if ((taken = material_parse_option(argc, argv, &i, &options->maps)) != 0) {
            if (taken < 0) return TOOL_EXIT_USAGE;
        } else if (tool_is_option(argv[i])) {
            return tool_unknown_option(argv[i]);
        } else if (npositional < 3) {
            positional[npositional++] = argv[i];
        } else {
            npositional++; /* counted, to say there are too many */
        }
    }
    if (tool_mesh_image_prefix(positional, npositional, &options->mesh_path, &options->image_path,
                               &options->output, options->prefix) != 0)
        return TOOL_EXIT_USAGE;
    return -1;
}

/* ======================================================================== */
/* Subdividing a coarse mesh (--subdivide auto, the default)                */
/* ======================================================================== */

static int compare_doubles(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* The steps --subdivide auto takes on mesh: the fewest after which the
   median triangle covers at most HPM_AUTO_TRIANGLE_TEXELS at the
   mapping's scale (--scale, or the library's default: the image's width
   over a quarter of the bounding box's diagonal), and none that would
   pass HPM_AUTO_MAX_TRIANGLES. The median's area in texels^2 goes to
   *median_texels (0 when it has no finite area, or out of memory: then
   no step). */
static int hpm_auto_steps(const tt_mesh *mesh, const tt_image *image, double scale, double *median_texels)
{
    double lo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL}, diagonal = 0.0;
    double *areas = (double *)malloc((size_t)mesh->nfaces * sizeof(double)), texels, triangles;
    int f, k, steps = 0;
    *median_texels = 0.0;
    if (!areas) return 0;   /* out of memory: the mesh as it is */
    for (f = 0; f < mesh->nfaces; f++) {
        const float *p[3];
        double e1[3], e2[3], cross[3];
        for (k = 0; k < 3; k++) p[k] = mesh->pos + 3 * (size_t)mesh->corner_vert[mesh->face_start[f] + k];
        for (k = 0; k < 3; k++) {
            int j;
            for (j = 0; j < 3; j++) {
                lo[k] = fmin(lo[k], p[j][k]);
                hi[k] = fmax(hi[k], p[j][k]);
            }
            e1[k] = (double)p[1][k] - p[0][k];
            e2[k] = (double)p[2][k] - p[0][k];
        }
        cross[0] = e1[1] * e2[2] - e1[2] * e2[1];
        cross[1] = e1[2] * e2[0] - e1[0] * e2[2];
        cross[2] = e1[0] * e2[1] - e1[1] * e2[0];
        areas[f] = 0.5 * sqrt(cross[0] * cross[0] + cross[1] * cross[1] + cross[2] * cross[2]);
    }
    for (k = 0; k < 3; k++) diagonal += (hi[k] - lo[k]) * (hi[k] - lo[k]);
    diagonal = sqrt(diagonal);
    if (!(scale > 0.0)) scale = 0.25 * diagonal;
    qsort(areas, (size_t)mesh->nfaces, sizeof(double), compare_doubles);
    texels = areas[mesh->nfaces / 2] * ((double)image->width / scale) * ((double)image->width / scale);
    free(areas);
    if (!(texels > 0.0 && texels < HUGE_VAL)) return 0;
    *median_texels = texels;
    for (triangles = mesh->nfaces; steps < HPM_AUTO_MAX_STEPS && texels > HPM_AUTO_TRIANGLE_TEXELS; steps++) {
        double factor = steps == 0 ? 6.0 : 4.0;
        if (triangles * factor > HPM_AUTO_MAX_TRIANGLES) break;
        triangles *= factor;
        texels /= factor;
    }
    return steps;
}

/* --subdivide auto: m subdivided as hpm_auto_steps says, and said. */
static int subdivide_coarse_mesh(const hpm_command_options *options, const tt_image *image, triangle_mesh *m)
{
    char times[32];
    double median;
    int before = m->ntriangles, steps = hpm_auto_steps(m->mesh, image, options->map.scale, &median), status;
    if (steps == 0) {
        if (median > HPM_AUTO_TRIANGLE_TEXELS)
            tool_note("%s: its triangles cover %.0f texels^2 each (the median) at the texture's scale, more than "
                      "half the smallest patch (%g), but subdividing them would pass %d triangles",
                      options->mesh_path, median, TT_DEFAULT_HPM_MIN_FOOTPRINT, HPM_AUTO_MAX_TRIANGLES);
        return 0;
    }
    if ((status = triangle_mesh_subdivide(options->mesh_path, steps, options->mesh.smooth, m)) != 0) return status;
    if (steps <= 2) snprintf(times, sizeof times, "%s", steps == 1 ? "once" : "twice");
    else snprintf(times, sizeof times, "%d times", steps);
    tool_note("%s: its triangles cover %.0f texels^2 each (the median) at the texture's scale, more than half the "
              "smallest patch (%g): subdivided %s (--subdivide %d), %d triangles into %d, so that clusters can "
              "follow the texture (--subdivide 0 keeps them)",
              options->mesh_path, median, TT_DEFAULT_HPM_MIN_FOOTPRINT, times, steps, before, m->ntriangles);
    return 0;
}

/* ======================================================================== */
/* The mapping                                                              */
/* ======================================================================== */

/* corner_uv gets 2 floats per triangle corner; face_vectors is the
   direction field, or NULL. */
static int map_mesh(const hpm_command_options *options, const triangle_mesh *m, const tt_image *image,
                    const float *face_vectors, float *corner_uv, tt_hpm_report *report)
{
    tt_hpm_options map = options->map;
    tool_progress progress;
    tt_error error;
    tt_result result;
    tool_progress_begin(&progress, "mapping", "done");
    map.progress = tool_show_progress;
    map.progress_user_data = &progress;
    map.executor = tool_executor();
    map.face_vectors = face_vectors;
    result = tt_hpm_map(m->mesh, image, &map, NULL, corner_uv, NULL, report, &error);
    tool_progress_end(&progress);
    if (result == TT_OK) return 0;
    /* A texel error is about the image (an HDR file with infinities), as
       is a bounded image too small to keep a texel's margin; the rest is
       about the mesh. */
    if ((result == TT_ERROR_NON_FINITE && error.face < 0) ||
        (result == TT_ERROR_INVALID_ARGUMENT && !(map.flags & TT_HPM_TOROIDAL) &&
         (image->width < 3 || image->height < 3)))
        return tool_fail("%s: %s", options->image_path, error.message);
    return triangle_mesh_report_error(options->mesh_path, m, &error);
}

/* The triangles with one texture coordinate and one normal per corner, for
   either file. */
static void hpm_write_desc(const triangle_mesh *m, const float *corner_uv, const float *normals, obj_write_desc *desc)
{
    memset(desc, 0, sizeof *desc);
    desc->nverts = m->mesh->nverts;
    desc->pos = m->mesh->pos;
    desc->nfaces = m->ntriangles;
    desc->fixed_face_size = 3;
    desc->corner_vert = m->vert;
    desc->corner_uv = corner_uv;
    desc->corner_normal = normals;
}

/* OUT_PREFIX.obj: the vertices, the triangles, a vt for each triangle
   corner (the corners of a vertex inside one cluster share it, as those of
   a smooth vertex share their vn). */
static int add_obj(tool_output *output, const char *path, const char *mtl_name, const hpm_command_options *options,
                   const triangle_mesh *m, const float *corner_uv)
{
    char comment[512];
    obj_write_desc desc;
    float *normals = tool_corner_normals(path, m->mesh, m->corner_normal);
    int status;
    if (!normals) return TOOL_EXIT_FAILURE;
    snprintf(comment, sizeof comment,
             "hierarchical pattern mapping by tiledtex %s (Soler et al.): texture coordinates into %s\n%s",
             TILEDTEX_VERSION_STRING, tool_basename(options->image_path),
             (options->map.flags & TT_HPM_TOROIDAL)
                 ? "the image tiles: coordinates leave [0,1], sample it with repeat addressing"
                 : "every coordinate lies inside the image");
    hpm_write_desc(m, corner_uv, normals, &desc);
    desc.comment = comment;
    desc.mtllib = mtl_name;
    desc.material = "hpm";
    desc.share_equal = 1;
    status = output_add_obj(output, path, &desc);
    free(normals);
    return status;
}

/* OUT_PREFIX.glb: the same triangles, IMAGE embedded as the material's
   colour; repeated when --toroidal lets the coordinates leave [0,1]. */
static int add_gltf(tool_output *output, const char *path, const hpm_command_options *options, const triangle_mesh *m,
                   const float *corner_uv, const tt_image *image)
{
    obj_write_desc desc;
    tool_material material;
    float *normals = tool_corner_normals(path, m->mesh, m->corner_normal);
    int status;
    if (!normals) return TOOL_EXIT_FAILURE;
    hpm_write_desc(m, corner_uv, normals, &desc);
    memset(&material, 0, sizeof material);
    material.name = "hpm";
    material.base_color = image;
    material_for_glb(&material, &options->maps, (const tt_image *const *)options->maps.images);
    material.repeat = (options->map.flags & TT_HPM_TOROIDAL) != 0;
    status = output_add_gltf(output, path, &desc, &material);
    free(normals);
    return status;
}

/* ======================================================================== */
/* The measures and the summary                                             */
/* ======================================================================== */

/* A bounded image's coordinates stay this far inside it (the library's
   promise, checked here): bilinear filtering then never reads past the
   image's edge. */
#define HPM_MARGIN_TEXELS 1.0

typedef struct hpm_quality {
    tool_seams borders;             /* UV-discontinuous edges: where clusters meet */
    tool_seams all;                 /* every interior edge */
    tt_uv_distortion_report distortion;
    int distortion_measured;
    char distortion_reason[224];
    tool_level level;               /* with --up or --constraints */
} hpm_quality;

/* The seams are measured on the image itself, the texture the OBJ uses;
   a toroidal image is sampled the way it is drawn, repeated. */
static int measure_quality(const hpm_command_options *options, const triangle_mesh *m, const tt_image *image,
                           const float *corner_uv, const tt_hpm_report *report, hpm_quality *quality)
{
    unsigned wrap = (options->map.flags & TT_HPM_TOROIDAL) ? TT_SEAM_WRAP : 0u;
    tt_uv_distortion_options distortion;
    tt_error error;
    tt_result result;
    int status;
    memset(quality, 0, sizeof *quality);
    status = tool_measure_seams(options->mesh_path, m->mesh, corner_uv, image, options->map.seed,
                                TT_SEAM_UV_DISCONTINUOUS | wrap, NULL, 0, 0, 0.0f, &quality->borders);
    if (status == 0)
        status = tool_measure_seams(options->mesh_path, m->mesh, corner_uv, image, options->map.seed, wrap, NULL,
                                    0, 0, 0.0f, &quality->all);
    if (status != 0) return status;
    memset(&distortion, 0, sizeof distortion);
    distortion.texels_per_unit = report->texels_per_unit;
    distortion.margin_texels = (options->map.flags & TT_HPM_TOROIDAL) ? 0.0 : HPM_MARGIN_TEXELS;
    tool_stage("measuring the texture's stretch");
    result = tt_measure_uv_distortion(m->mesh, corner_uv, image->width, image->height, &distortion, NULL,
                                      &quality->distortion, &error);
    if (result == TT_ERROR_NOT_MEASURED) {
        snprintf(quality->distortion_reason, sizeof quality->distortion_reason, "%s", error.message);
        return 0;
    }
    if (result != TT_OK) return tool_fail("%s: cannot measure the distortion: %s", options->mesh_path, error.message);
    quality->distortion_measured = 1;
    if (options->field.given)
        return tool_measure_level(options->mesh_path, m->mesh, corner_uv, image->width, image->height,
                                  options->field.up, &quality->level);
    return 0;
}

static void print_summary(const hpm_command_options *options, const triangle_mesh *m, const tt_image *image,
                          const tt_hpm_report *report, const hpm_quality *quality, double seconds)
{
    const tt_uv_distortion_report *d = &quality->distortion;
    char borders[320], all[320];
    int level, last = -1, counted = report->levels < TT_HPM_MAX_LEVELS ? report->levels : TT_HPM_MAX_LEVELS;
    for (level = 0; level < counted; level++)
        if (report->mapped_per_level[level] > 0) last = level;
    printf("%s: %d triangles", options->mesh_path, m->ntriangles);
    if (m->subdivided > 0) printf(" (%d faces, --subdivide %d)", m->obj.nfaces, m->subdivided);
    else if (m->ntriangles != m->obj.nfaces) printf(" (fans of %d faces)", m->obj.nfaces);
    printf(", %d levels, %d clusters textured%s\n", report->levels, report->clusters,
           (options->map.flags & TT_HPM_RANDOM_PLACEMENT) ? " (--no-fit: each placed at random)" : "");
    printf("clusters per level:");
    for (level = 0; level <= last; level++)
        printf("%s L%d %d", level == 0 ? "" : ",", level, report->mapped_per_level[level]);
    printf("\n");
    printf("fits: %d accepted, %d at the floor, %d rejected (split); %d continued, %d in place of a fit (%d at the "
           "floor), %d starts; split before fitting: %d not flat, %d no room; %d faces changed sides at borders\n",
           report->accepted_fits, report->floor_fits, report->rejected_fits, report->continued,
           report->accepted_continued + report->floor_continued, report->floor_continued, report->starts,
           report->not_flat, report->no_room, report->faces_moved);
    if (report->faces_unflattened > 0)
        printf("%d faces no cluster could flatten show a neighbour's map continued over their edge, or their own\n",
               report->faces_unflattened);
    if (report->accepted_fits + report->floor_fits > 0)
        printf("fit error: mean %.3f, max %.3f (threshold %g)\n", report->mean_error, report->max_error,
               options->map.threshold > 0 ? options->map.threshold : TT_DEFAULT_HPM_THRESHOLD);
    printf("texel density %.4g texels per unit (the image's %d texels span %.4g units); %.1f s\n",
           report->texels_per_unit, image->width, (double)image->width / report->texels_per_unit, seconds);
    tool_format_seams(&quality->borders, "border edges", borders, sizeof borders);
    tool_format_seams(&quality->all, "edges", all, sizeof all);
    printf("seam score: cluster borders %s; all edges %s\n", borders, all);
    if (options->field.given) tool_print_level(&quality->level);
    if (!quality->distortion_measured) {
        printf("UV distortion: not measured (%s)\n", quality->distortion_reason);
        return;
    }
    printf("UV distortion: stretch p5 %.3f, median %.3f, p95 %.3f; texel density p5 %.2f, p95 %.2f of its "
           "median; density error median %.1f%%, p95 %.1f%%; %d flipped UV triangle%s",
           d->stretch_p5, d->stretch_median, d->stretch_p95, d->density_p5_over_median, d->density_p95_over_median,
           100.0 * d->density_median, 100.0 * d->density_p95, d->flipped, d->flipped == 1 ? "" : "s");
    if (d->degenerate > 0) printf(", %d degenerate", d->degenerate);
    if (d->non_finite > 0) printf(", %d with non-finite coordinates", d->non_finite);
    if (d->outside_margin > 0)
        printf(", %d corner%s closer than %g texel to the image's border", d->outside_margin,
               d->outside_margin == 1 ? "" : "s", HPM_MARGIN_TEXELS);
    printf("\n");
}

/* An image file beside the OBJ, so that the folder can move: `source`'s
   bytes as they are when it is a PNG or a JPEG (which every program
   reads), into STEM.png or STEM.jpg; any other format as a PNG of the
   image as loaded (`map` a material map, or -1 for the colour image,
   sRGB). A source that is that file already is named, not copied. The
   path the MTL is to name goes to `path`. */
static int add_image_copy(tool_output *output, const char *source, const tt_image *loaded, int map, const char *stem,
                          char *path, size_t size)
{
    static const unsigned char png_signature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
    char message[TOOL_ERROR_SIZE];
    unsigned char *data;
    size_t length;
    int png, jpeg;
    if (tool_read_file(source, &data, &length, message, sizeof message) != 0) return tool_fail("%s", message);
    png = length >= 8 && memcmp(data, png_signature, 8) == 0;
    jpeg = length >= 3 && data[0] == 0xFF && data[1] == 0xD8 && data[2] == 0xFF;
    snprintf(path, size, "%s%s", stem, jpeg ? ".jpg" : ".png");
    if (tool_same_file(source, path)) {
        free(data);
        return 0;
    }
    if (png || jpeg) {
        if (output_add(output, path, data, length) != 0) return tool_fail("out of memory while writing %s", path);
        return 0;
    }
    free(data);
    if (map >= 0) return output_add_map_png(output, path, map, loaded);
    if (output_add_png(output, path, loaded, TT_COLOR_SRGB, message, sizeof message) != 0)
        return tool_fail("%s: %s", path, message);
    return 0;
}

/* ======================================================================== */
/* The command                                                              */
/* ======================================================================== */

int cmd_hpm(int argc, char **argv)
{
    hpm_command_options options;
    triangle_mesh mesh;
    tt_image *image = NULL;
    tt_hpm_report report;
    hpm_quality quality;
    tool_output output = TOOL_OUTPUT_INIT;
    float *corner_uv = NULL, *field = NULL;
    char obj_path[4096], mtl_path[4096], gltf_path[4096], written[8400], message[TOOL_ERROR_SIZE], normal_path[4200];
    char texture_path[4200], copy_paths[MATERIAL_MAPS][4200], stem[4200];
    const char *map_paths[MATERIAL_MAPS], *texture = NULL;
    double start = tool_seconds_now();
    int status, map, gltf;

    status = parse_command_line(argc, argv, &options);
    if (status >= 0) return status;
    snprintf(obj_path, sizeof obj_path, "%s.obj", options.prefix);
    snprintf(mtl_path, sizeof mtl_path, "%s.mtl", options.prefix);
    tool_output_path(options.prefix, tool_model_extension(&options.output), gltf_path, sizeof gltf_path);
    gltf = options.output.format != TOOL_FORMAT_OBJ;
    /* The UVs are into IMAGE itself, so they serve every map of its size as
       it is; a Y-down normal map alone is rewritten, +Y up. */
    material_path(normal_path, sizeof normal_path, options.prefix, MATERIAL_NORMAL);
    for (map = 0; map < MATERIAL_MAPS; map++) map_paths[map] = options.maps.paths[map];
    if (options.maps.normal_y_down) map_paths[MATERIAL_NORMAL] = normal_path;

    if ((status = triangle_mesh_read(options.mesh_path, &options.mesh, &mesh)) != 0) return status;
    /* A photo: sRGB bytes in the file, linear light in the library (which
       matches colours as displayed again, by itself). */
    if (image_load(options.image_path, TT_COLOR_SRGB, &image, message, sizeof message) != 0)
        status = tool_fail("%s", message);
    if (status == 0 && !options.field.given)
        tool_note_courses_without_up(image, options.image_path, NULL,
                                     "without --up each cluster takes its own direction, so they wander");
    /* A seamless photo held inside its bounds leaves each cluster fewer
       places, and more of them at the floor are fitted where a neighbour
       could have been continued across the wrap (a knotted tube with
       pebbles: cluster borders 0.18 to 0.23, 0.04 to 0.07 with
       --toroidal). */
    if (status == 0 && !(options.map.flags & TT_HPM_TOROIDAL) && tool_image_tiles(image))
        tool_note("%s tiles (its opposite edges continue each other): --toroidal lets the clusters wrap round it, "
                  "with lower seams (the texture coordinates then leave [0,1]; render with repeat)",
                  options.image_path);
    if (status == 0 && options.mesh.subdivide == TOOL_SUBDIVIDE_AUTO)
        status = subdivide_coarse_mesh(&options, image, &mesh);
    if (status == 0) status = material_load(&options.maps, options.image_path, image->width, image->height);
    /* Refuse, before the long part, outputs that would replace an input
       (the commit checks again, but only after mapping). */
    if (status == 0 && gltf) status = tool_refuse_input_overwrite(gltf_path);
    if (status == 0 && !gltf) status = tool_refuse_input_overwrite(obj_path);
    if (status == 0 && !gltf) status = tool_refuse_input_overwrite(mtl_path);
    if (status == 0 && !gltf && options.maps.normal_y_down) status = tool_refuse_input_overwrite(normal_path);
    if (status == 0) {
        corner_uv = (float *)malloc((size_t)mesh.ntriangles * 6 * sizeof(float));
        if (!corner_uv) status = tool_fail("out of memory for the texture coordinates of %s", options.mesh_path);
    }
    if (status == 0 && options.field.given) {
        field = (float *)malloc((size_t)mesh.ntriangles * 3 * sizeof(float));
        status = field ? tool_make_field(options.mesh_path, &mesh, &options.field, 0.0f, field)
                       : tool_fail("out of memory for the direction field of %s", options.mesh_path);
    }
    if (status == 0) status = map_mesh(&options, &mesh, image, field, corner_uv, &report);
    if (status == 0) status = measure_quality(&options, &mesh, image, corner_uv, &report, &quality);

    if (status == 0 && gltf) status = add_gltf(&output, gltf_path, &options, &mesh, corner_uv, image);
    if (status == 0 && !gltf) status = add_obj(&output, obj_path, tool_basename(mtl_path), &options, &mesh, corner_uv);
    /* IMAGE and the maps copied beside the OBJ (--reference-image: named where they are). */
    texture = options.image_path;
    if (status == 0 && !gltf && !options.reference_image) {
        status = add_image_copy(&output, options.image_path, image, -1, options.prefix, texture_path,
                                sizeof texture_path);
        texture = texture_path;
        for (map = 0; map < MATERIAL_MAPS && status == 0; map++) {
            if (!options.maps.paths[map] || (map == MATERIAL_NORMAL && options.maps.normal_y_down)) continue;
            snprintf(stem, sizeof stem, "%s_%s", options.prefix, material_map_names[map]);
            status = add_image_copy(&output, options.maps.paths[map], options.maps.images[map], map, stem,
                                    copy_paths[map], sizeof copy_paths[map]);
            map_paths[map] = copy_paths[map];
        }
    }
    if (status == 0 && !gltf) status = output_add_mtl(&output, mtl_path, "hpm", texture, 0, map_paths);
    if (status == 0 && !gltf && options.maps.normal_y_down)
        status = output_add_map_png(&output, normal_path, MATERIAL_NORMAL, options.maps.images[MATERIAL_NORMAL]);
    if (status == 0 && output_commit(&output, message, sizeof message) != 0) status = tool_fail("%s", message);

    if (status == 0 && !tool_quiet()) {
        print_summary(&options, &mesh, image, &report, &quality, tool_seconds_now() - start);
        if (gltf && options.output.format == TOOL_FORMAT_GLTF)
            printf("wrote %s\n", gltf_written(gltf_path, written, sizeof written));
        else if (gltf)
            printf("wrote %s (with %s in it)\n", gltf_path, options.image_path);
        else {
            printf("wrote %s, %s", obj_path, mtl_path);
            if (!options.reference_image && !tool_same_file(options.image_path, texture)) printf(", %s", texture);
            for (map = 0; map < MATERIAL_MAPS; map++)
                if (map_paths[map] && map_paths[map] != options.maps.paths[map] &&
                    !tool_same_file(options.maps.paths[map], map_paths[map]))
                    printf(", %s", map_paths[map]);
            printf("\n");
        }
    }
    output_free(&output);
    image_free(image);
    material_free(&options.maps);
    free(corner_uv);
    free(field);
    triangle_mesh_free(&mesh);
    return status;
}
