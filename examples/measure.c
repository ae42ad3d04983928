/* measure.c - the library's quality measures as the commands' summaries
   report them. See tool.h for the interface. */

#include <stdio.h>
#include <string.h>

#include "tool.h"

int tool_measure_seams(const char *obj_path, const tt_mesh *mesh, const float *corner_uv, const tt_image *atlas,
                       uint64_t seed, unsigned flags, const int *edges, int nedges, int all_edges, float ends,
                       tool_seams *out)
{
    tt_seam_options options;
    tt_error error;
    tt_result result;
    size_t length;
    int c;
    memset(out, 0, sizeof *out);
    /* The summary is a report, not the acceptance measure: a random sample
       of edges keeps it fast on big meshes (within about 0.01 of the full
       score). all_edges asks for the full measure. */
    memset(&options, 0, sizeof options);
    options.seed = seed;
    options.flags = flags;
    options.max_edges = all_edges ? 0 : TOOL_REPORT_EDGES;
    options.edges = edges;
    options.nedges = nedges;
    options.ends = ends;
    options.executor = tool_executor();
    tool_stage("measuring the seams");
    result = tt_measure_seams(mesh, corner_uv, atlas, &options, NULL, &out->report, &error);
    if (edges) {
        out->edges = nedges;
    } else if (flags & TT_SEAM_UV_DISCONTINUOUS) {
        out->edges = out->report.edges_discontinuous;
    } else {
        for (c = 0; c < mesh->ncorners; c++)
            if (mesh->twin[c] > c) out->edges++;
    }
    out->sampled = !all_edges && out->edges > TOOL_REPORT_EDGES;
    if (result == TT_ERROR_NOT_MEASURED) {
        /* Not an error: the summary says why there is no number. */
        snprintf(out->reason, sizeof out->reason, "%s", error.message);
        length = strlen(out->reason);
        if (length > 0 && out->reason[length - 1] == '.') out->reason[length - 1] = '\0';
        return 0;
    }
    if (result != TT_OK) return tool_fail("%s: cannot measure the seams: %s", obj_path, error.message);
    out->measured = 1;
    return 0;
}

void tool_format_seams(const tool_seams *seams, const char *edges, char *text, size_t size)
{
    const tt_seam_report *r = &seams->report;
    if (!seams->measured)
        snprintf(text, size, "not measured (%s)", seams->reason);
    else if (r->score == r->score)
        snprintf(text, size, "%.3f (%d of %d %s%s)", r->score, r->edges_measured, seams->edges, edges,
                 seams->sampled ? " sampled" : "");
    else
        snprintf(text, size, "n/a: unrelated places differ no more than neighbours (%d %s; seam - same-face %.4f)",
                 r->edges_measured, edges, r->seam - r->same_face);
}

int tool_measure_level(const char *obj_path, const tt_mesh *mesh, const float *corner_uv, int width, int height,
                       const float up[3], tool_level *level)
{
    tt_uv_direction_options options;
    tt_error error;
    tt_result result;
    memset(level, 0, sizeof *level);
    memset(&options, 0, sizeof options);
    memcpy(options.up, up, sizeof options.up);
    result = tt_measure_uv_direction(mesh, corner_uv, width, height, &options, NULL, &level->report, &error);
    if (result == TT_ERROR_NOT_MEASURED) {
        size_t length;
        snprintf(level->reason, sizeof level->reason, "%s", error.message);
        length = strlen(level->reason);
        if (length > 0 && level->reason[length - 1] == '.') level->reason[length - 1] = '\0';
        return 0;
    }
    if (result != TT_OK) return tool_fail("%s: cannot measure the texture's direction: %s", obj_path, error.message);
    level->measured = 1;
    return 0;
}

void tool_print_level(const tool_level *level)
{
    const tt_uv_direction_report *r = &level->report;
    if (level->measured)
        printf("level: the image's up %.1f%% of %d wall faces within 10 degrees of --up, mean %.1f, p90 %.1f "
               "degrees; its rows (courses) %.1f%%, mean %.1f, p90 %.1f\n", 100.0 * r->within, r->faces, r->mean,
               r->p90, 100.0 * r->rows_within, r->rows_mean, r->rows_p90);
    else
        printf("level: not measured (%s)\n", level->reason);
}
