/* cli.c - command-line helpers of the `tiledtex` tool: options and their
   values, and numbers read from text. See tool.h for the interface. */

#include <ctype.h>
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tool.h"

/* ======================================================================== */
/* Command-line helpers                                                     */
/* ======================================================================== */

int tool_is_help(const char *arg)
{
    return strcmp(arg, "-h") == 0 || strcmp(arg, "--help") == 0;
}

void tool_print_mesh_help(int writes_obj)
{
    printf("MESH is a Wavefront OBJ, an STL (ASCII or binary) or an OFF file (see 'tiledtex --help').\n");
    if (writes_obj)
        printf("The OBJs written keep MESH's own normals (an OBJ's vn) when every face corner has one,\n"
               "interpolated where new vertices appear; otherwise they get smooth normals, with a\n"
               "crease where faces meet at more than %g degrees.\n",
               (double)TOOL_CREASE_DEGREES);
}

int tool_is_option(const char *arg)
{
    /* "-" alone often means standard input, and "-3" is a number. */
    return arg[0] == '-' && arg[1] != '\0' && !isdigit((unsigned char)arg[1]) && arg[1] != '.';
}

/* The option names a command's parser has compared the argument being
   read with (tool_option and tool_flag record them), so that an unknown
   option can be answered with the nearest one the command takes. A
   different argument starts the list again. */
#define OFFERED_MAX 128
static struct {
    const char *arg;
    const char *names[OFFERED_MAX];
    int count;
} offered;

static void offer(const char *arg, const char *name)
{
    if (offered.arg != arg) {
        offered.arg = arg;
        offered.count = 0;
    }
    if (offered.count < OFFERED_MAX) offered.names[offered.count++] = name;
}

int tool_flag(const char *arg, const char *name)
{
    offer(arg, name);
    return strcmp(arg, name) == 0;
}

/* The options the tool takes before or after any command (tiledtex.c's
   take_global_options): a typo of one reaches the command's parser. */
static const char *const global_options[] = {"--max-pixels", "--jobs", "--quiet", "--weld"};

/* Edits (insertions, deletions, changes, swaps of two neighbours) that make
   a[0..na) into b[0..nb); anything above `most` is reported as most + 1. */
static int edit_distance(const char *a, size_t na, const char *b, size_t nb, int most)
{
    int row[3][64], *before = row[0], *previous = row[1], *current = row[2];
    size_t i, j;
    if (na >= 63 || nb >= 63) return most + 1;
    for (j = 0; j <= nb; j++) previous[j] = (int)j;
    for (i = 1; i <= na; i++) {
        int least = INT_MAX, *spare;
        current[0] = (int)i;
        for (j = 1; j <= nb; j++) {
            int d = previous[j - 1] + (a[i - 1] != b[j - 1]);
            if (previous[j] + 1 < d) d = previous[j] + 1;
            if (current[j - 1] + 1 < d) d = current[j - 1] + 1;
            if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1] && before[j - 2] + 1 < d)
                d = before[j - 2] + 1;
            current[j] = d;
            if (d < least) least = d;
        }
        if (least > most) return most + 1;
        spare = before;
        before = previous;
        previous = current;
        current = spare;
    }
    return previous[nb] <= most ? previous[nb] : most + 1;
}

/* The option nearest `arg` among those offered for it and the global ones:
   within two edits (one for a short name), or the only one `arg` begins
   (at least three letters after the dashes); NULL when none is near or two
   are equally near. */
static const char *nearest_option(const char *arg)
{
    const char *equals = strchr(arg, '='), *best = NULL;
    const char *candidates[OFFERED_MAX + sizeof global_options / sizeof global_options[0]];
    size_t length = equals ? (size_t)(equals - arg) : strlen(arg);
    int ncandidates = 0, best_distance = INT_MAX, ties = 0, prefixed = 0, k;
    const char *prefix_of = NULL;
    if (offered.arg == arg)
        for (k = 0; k < offered.count; k++) candidates[ncandidates++] = offered.names[k];
    for (k = 0; k < (int)(sizeof global_options / sizeof global_options[0]); k++)
        candidates[ncandidates++] = global_options[k];
    for (k = 0; k < ncandidates; k++) {
        const char *name = candidates[k];
        size_t name_length = strlen(name);
        int most = name_length > 5 ? 2 : 1, d;
        if (strlen(name) == length && strncmp(name, arg, length) == 0) continue;   /* the same option twice */
        if (length >= 5 && name_length > length && strncmp(name, arg, length) == 0) {
            if (!prefix_of || strcmp(prefix_of, name) != 0) prefixed++;
            prefix_of = name;
        }
        d = edit_distance(arg, length, name, name_length, most);
        if (d > most) continue;
        if (d < best_distance) {
            best_distance = d;
            best = name;
            ties = 0;
        } else if (d == best_distance && strcmp(best, name) != 0) {
            ties++;
        }
    }
    if (best && !ties) return best;
    return prefixed == 1 ? prefix_of : NULL;
}

int tool_unknown_option(const char *arg)
{
    const char *nearest = nearest_option(arg);
    char hint[160] = "";
    if (nearest) snprintf(hint, sizeof hint, ": did you mean '%s'?", nearest);
    if (tool_command())
        return tool_usage("unknown option '%s'%s (see '%s %s --help')", arg, hint, TOOL_NAME, tool_command());
    return tool_usage("unknown option '%s'%s (see '%s --help')", arg, hint, TOOL_NAME);
}

/* Extensions an output prefix may end with by mistake: the files the
   commands write, and the glTF a user may expect from a mesh tool. */
static const char *const output_extensions[] = {".obj", ".mtl", ".png", ".glb", ".gltf"};

const char *tool_model_extension(const tool_mesh_output *output)
{
    switch (output->format) {
    case TOOL_FORMAT_GLB: return ".glb";
    case TOOL_FORMAT_GLTF: return ".gltf";
    default: return ".obj";
    }
}

int parse_mesh_output_option(int argc, char **argv, int *index, int accept_format, tool_mesh_output *output)
{
    const char *value;
    if (accept_format && tool_option(argc, argv, index, "--format", &value)) {
        if (!value) {
            tool_usage("--format needs a value: obj, glb or gltf");
            return -1;
        }
        if (strcmp(value, "obj") == 0) output->format = TOOL_FORMAT_OBJ;
        else if (strcmp(value, "glb") == 0) output->format = TOOL_FORMAT_GLB;
        else if (strcmp(value, "gltf") == 0) output->format = TOOL_FORMAT_GLTF;
        else {
            tool_usage("--format wants obj, glb or gltf, got '%s'", value);
            return -1;
        }
        output->format_given = 1;
    } else if (tool_flag(argv[*index], "--triangles")) {
        output->triangles = 1;
    } else {
        return 0;
    }
    return 1;
}

/* The known extension `text` ends with (output_extensions), or NULL; only
   when something is left of the name: ".obj" alone stays a name. */
static const char *output_extension(const char *text)
{
    size_t length = strlen(text), k;
    for (k = 0; k < sizeof output_extensions / sizeof output_extensions[0]; k++)
        if (tool_has_extension(text, output_extensions[k]) &&
            length - strlen(output_extensions[k]) > (size_t)(tool_basename(text) - text))
            return text + length - strlen(output_extensions[k]);
    return NULL;
}

int tool_output_prefix(const char *text, tool_mesh_output *output, char *prefix)
{
    /* By tool_mesh_format: its --format value, the file's kind, what it writes. */
    static const char *const format_names[] = {"obj", "glb", "gltf"};
    static const char *const kinds[] = {"OBJ", "GLB", "glTF"};
    static const char *const writes[] = {"OBJ files", "one .glb file", "a .gltf file with its .bin and PNGs"};
    const char *extension = output_extension(text);
    size_t length = extension ? (size_t)(extension - text) : strlen(text);
    int named = TOOL_FORMAT_OBJ;   /* the format the name's extension says */
    if (extension && tool_has_extension(extension, ".glb")) named = TOOL_FORMAT_GLB;
    if (extension && tool_has_extension(extension, ".gltf")) named = TOOL_FORMAT_GLTF;
    if (!output && named != TOOL_FORMAT_OBJ)
        return tool_usage("OUT_PREFIX '%s' names a %s file, but this command writes OBJ and PNG files only", text,
                          kinds[named]);
    if (output && output->format_given && named != TOOL_FORMAT_OBJ && (int)output->format != named)
        return tool_usage("OUT_PREFIX '%s' names a %s file, but --format %s asks for %s: drop one of them", text,
                          kinds[named], format_names[output->format], writes[output->format]);
    if (output && extension && named == TOOL_FORMAT_OBJ && output->format != TOOL_FORMAT_OBJ)
        return tool_usage("OUT_PREFIX '%s' ends in %s, but --format %s writes %s: name it '%.*s%s'", text, extension,
                          format_names[output->format], writes[output->format], (int)length, text,
                          tool_model_extension(output));
    if (output && named != TOOL_FORMAT_OBJ) output->format = (tool_mesh_format)named;
    if (strcmp(text, "-") == 0 && output && output->format == TOOL_FORMAT_GLB) {
        strcpy(prefix, "-");
        return 0;
    }
    if (strcmp(text, "-") == 0)
        return tool_usage("OUT_PREFIX cannot be '-' (standard output): it names several files; give a name such as "
                          "'out'%s", output ? ", or add --format glb for one file" : "");
    if (length + 16 > TOOL_PREFIX_SIZE) return tool_usage("OUT_PREFIX is too long");
    memcpy(prefix, text, length);
    prefix[length] = '\0';
    if (tool_basename(prefix)[0] == '\0')
        return tool_usage("OUT_PREFIX '%s' names a directory: give a name for the files, such as '%sout'", text, text);
    return 0;
}

void tool_output_path(const char *prefix, const char *suffix, char *path, size_t size)
{
    if (strcmp(prefix, "-") == 0) snprintf(path, size, "-");
    else snprintf(path, size, "%s%s", prefix, suffix);
}

int tool_mesh_image_prefix(const char *const *positional, int npositional, const char **mesh, const char **image,
                           tool_mesh_output *output, char *prefix)
{
    const char *command = tool_command() ? tool_command() : "CMD";
    if (npositional > 3) return tool_usage("too many arguments (see '%s %s --help')", TOOL_NAME, command);
    if (npositional < 3)
        return tool_usage("needs MESH, IMAGE and OUT_PREFIX (see '%s %s --help')", TOOL_NAME, command);
    if (tool_output_prefix(positional[2], output, prefix) != 0) return TOOL_EXIT_USAGE;
    *mesh = positional[0];
    *image = positional[1];
    return 0;
}

int tool_refuse_stdout(const char *path, int several, const char *what)
{
    if (several && strcmp(path, "-") == 0)
        return tool_usage("%s cannot be '-' (standard output): that makes several files; give a file name", what);
    return 0;
}

int parse_axis_name(const char *text, int *axis, int *sign)
{
    const char *name = text;
    if (!text) return -1;
    *sign = 1;
    if (name[0] == '+' || name[0] == '-') {
        if (name[0] == '-') *sign = -1;
        name++;
    }
    if (name[0] == '\0' || name[1] != '\0') return -1;
    switch (name[0]) {
    case 'x': case 'X': *axis = 0; return 0;
    case 'y': case 'Y': *axis = 1; return 0;
    case 'z': case 'Z': *axis = 2; return 0;
    default: return -1;
    }
}

int tool_option(int argc, char **argv, int *index, const char *name, const char **value)
{
    const char *arg = argv[*index];
    size_t name_length = strlen(name);
    offer(arg, name);
    if (strncmp(arg, name, name_length) != 0) return 0;
    if (arg[name_length] == '=') {              /* --size=800x600 */
        *value = arg + name_length + 1;
        return 1;
    }
    if (arg[name_length] != '\0') return 0;     /* --sizes is another option */
    if (*index + 1 < argc) {
        *index += 1;
        *value = argv[*index];
    } else {
        *value = NULL;
    }
    return 1;
}

static int missing_value(const char *option)
{
    tool_usage("%s needs a value", option);
    return -1;
}

int parse_whole_long(const char *text, long *out)
{
    char *end;
    long value;
    while (isspace((unsigned char)*text)) text++;
    if (*text == '\0') return -1;
    errno = 0;
    value = strtol(text, &end, 10);
    if (errno == ERANGE || end == text) return -1;
    while (isspace((unsigned char)*end)) end++;
    if (*end != '\0') return -1;
    *out = value;
    return 0;
}

int parse_whole_double(const char *text, double *out)
{
    char *end;
    double value;
    while (isspace((unsigned char)*text)) text++;
    if (*text == '\0') return -1;
    value = strtod(text, &end);
    if (end == text) return -1;
    while (isspace((unsigned char)*end)) end++;
    if (*end != '\0' || !isfinite(value)) return -1;
    *out = value;
    return 0;
}

int parse_int(const char *option, const char *text, int min, int max, int *out)
{
    long value;
    if (!text) return missing_value(option);
    if (parse_whole_long(text, &value) != 0 || value < min || value > max) {
        tool_usage("%s wants an integer from %d to %d, got '%s'", option, min, max, text);
        return -1;
    }
    *out = (int)value;
    return 0;
}

int parse_u64(const char *option, const char *text, uint64_t *out)
{
    const char *p = text;
    uint64_t value = 0;
    int base = 10, digits = 0;
    if (!text) return missing_value(option);
    if (p[0] == '0' && (p[1] == 'x' || p[1] == 'X')) { base = 16; p += 2; }
    for (; *p; p++, digits++) {
        int digit;
        if (isdigit((unsigned char)*p)) digit = *p - '0';
        else if (base == 16 && isxdigit((unsigned char)*p)) digit = tolower((unsigned char)*p) - 'a' + 10;
        else break;
        if (value > (UINT64_MAX - (uint64_t)digit) / (uint64_t)base) { digits = 0; break; }  /* overflow */
        value = value * (uint64_t)base + (uint64_t)digit;
    }
    if (digits == 0 || *p != '\0') {
        tool_usage("%s wants a non-negative integer below 2^64, got '%s'", option, text);
        return -1;
    }
    *out = value;
    return 0;
}

int parse_float(const char *option, const char *text, double min, double max, double *out)
{
    double value;
    if (!text) return missing_value(option);
    if (parse_whole_double(text, &value) != 0 || value < min || value > max) {
        tool_usage("%s wants a number from %g to %g, got '%s'", option, min, max, text);
        return -1;
    }
    *out = value;
    return 0;
}

int parse_size(const char *option, const char *text, int min, int max, int *width, int *height)
{
    char first[32];
    const char *x;
    long w, h;
    size_t first_length;
    if (!text) return missing_value(option);
    x = strpbrk(text, "xX");
    first_length = x ? (size_t)(x - text) : 0;
    if (!x || first_length >= sizeof first) {
        tool_usage("%s wants WxH, got '%s'", option, text);
        return -1;
    }
    memcpy(first, text, first_length);
    first[first_length] = '\0';
    if (parse_whole_long(first, &w) != 0 || parse_whole_long(x + 1, &h) != 0) {
        tool_usage("%s wants WxH, got '%s'", option, text);
        return -1;
    }
    if (w < min || w > max || h < min || h > max) {
        tool_usage("%s wants WxH with each side from %d to %d, got '%s'", option, min, max, text);
        return -1;
    }
    *width = (int)w;
    *height = (int)h;
    return 0;
}

/* Split "a,b,c" into exactly `count` pieces and hand each to `parse_one`. */
static int parse_list(const char *option, const char *text, int count, void *out,
                      int (*parse_one)(const char *piece, void *out, int i))
{
    const char *p = text;
    int i;
    if (!text) return missing_value(option);
    for (i = 0; i < count; i++) {
        char piece[64];
        const char *comma = strchr(p, ',');
        size_t length = comma ? (size_t)(comma - p) : strlen(p);
        if ((comma != NULL) != (i + 1 < count) || length >= sizeof piece) break;
        memcpy(piece, p, length);
        piece[length] = '\0';
        if (parse_one(piece, out, i) != 0) break;
        p = comma ? comma + 1 : p + length;
    }
    if (i < count) {
        static const char *const shapes[] = {"", "X", "X,Y", "X,Y,Z", "X,Y,W,H"};
        if (count >= 1 && count <= 4)
            tool_usage("%s wants %s, got '%s'", option, shapes[count], text);
        else
            tool_usage("%s wants %d comma-separated numbers, got '%s'", option, count, text);
        return -1;
    }
    return 0;
}

static int parse_one_double(const char *piece, void *out, int i)
{
    return parse_whole_double(piece, (double *)out + i);
}

static int parse_one_int(const char *piece, void *out, int i)
{
    long value;
    if (parse_whole_long(piece, &value) != 0 || value < INT_MIN || value > INT_MAX) return -1;
    ((int *)out)[i] = (int)value;
    return 0;
}

int parse_float_list(const char *option, const char *text, int count, double *out)
{
    return parse_list(option, text, count, out, parse_one_double);
}

int parse_int_list(const char *option, const char *text, int count, int *out)
{
    return parse_list(option, text, count, out, parse_one_int);
}

int parse_mesh_option(int argc, char **argv, int *index, tool_mesh_options *options)
{
    const char *value;
    if (tool_option(argc, argv, index, "--subdivide", &value)) {
        if (options->auto_allowed && value && strcmp(value, "auto") == 0) options->subdivide = TOOL_SUBDIVIDE_AUTO;
        else if (parse_int("--subdivide", value, 0, 8, &options->subdivide) != 0) return -1;
    } else if (tool_flag(argv[*index], "--smooth")) {
        options->smooth = 1;
    } else if (tool_flag(argv[*index], "--permissive")) {
        options->permissive = 1;
    } else {
        return 0;
    }
    return 1;
}

int parse_up(const char *option, const char *text, double up[3])
{
    int axis, sign;
    if (!text) return missing_value(option);
    if (parse_axis_name(text, &axis, &sign) == 0) {
        up[0] = up[1] = up[2] = 0.0;
        up[axis] = sign;
        return 0;
    }
    if (!strchr(text, ',')) {
        tool_usage("%s wants an axis (x, y, z, -x, -y or -z) or a direction X,Y,Z, got '%s'", option, text);
        return -1;
    }
    if (parse_float_list(option, text, 3, up) != 0) return -1;
    if (up[0] == 0.0 && up[1] == 0.0 && up[2] == 0.0) {
        tool_usage("%s wants a direction, got the zero vector '%s'", option, text);
        return -1;
    }
    return 0;
}

void tool_note_courses_without_up(const tt_image *image, const char *image_path, const tt_courses *found,
                                  const char *without)
{
    tt_courses courses;
    if (found) courses = *found;
    else if (tt_find_courses(image, NULL, &courses, NULL) != TT_OK) return;
    if (courses.period > 0.0f)
        tool_note("%s has courses (bricks, blocks laid in rows): %s; --up gives the mesh's up (z for a mesh made "
                  "z-up: CAD parts, many scans) and keeps them level on every wall",
                  image_path, without);
}

/* Mean absolute RGB difference of texels a and b. */
static double texel_difference(const float *a, const float *b)
{
    return (fabs((double)a[0] - b[0]) + fabs((double)a[1] - b[1]) + fabs((double)a[2] - b[2])) / 3.0;
}

/* One axis of tool_image_tiles: `lines` lines (columns, or rows) of
   `length` texels, texel i of line k at pixels + 4 (k * line_step + i *
   texel_step). */
static int wraps_like_its_pairs(const float *pixels, int lines, int length, size_t line_step, size_t texel_step)
{
    double wrap = 0.0, *pair = (double *)calloc((size_t)lines, sizeof(double));
    int k, i, as_large = 0;
    if (!pair) return 0;
    for (k = 0; k < lines; k++)
        for (i = 0; i < length; i++) {
            const float *p = pixels + 4 * ((size_t)k * line_step + (size_t)i * texel_step);
            const float *next = pixels + 4 * ((size_t)((k + 1) % lines) * line_step + (size_t)i * texel_step);
            if (k + 1 < lines) pair[k] += texel_difference(p, next);
            else wrap += texel_difference(p, next);
        }
    for (k = 0; k + 1 < lines; k++) as_large += pair[k] >= wrap;
    free(pair);
    return as_large >= TOOL_TILES_RANK * (lines - 1);
}

int tool_image_tiles(const tt_image *image)
{
    const int w = image->width, h = image->height;
    if (w < 3 || h < 3) return 0;
    return wraps_like_its_pairs(image->pixels, w, h, 1, (size_t)w) &&
           wraps_like_its_pairs(image->pixels, h, w, (size_t)w, 1);
}

int parse_field_option(int argc, char **argv, int *index, tool_field *field)
{
    const char *value;
    double up[3];
    int k;
    if (tool_option(argc, argv, index, "--up", &value)) {
        if (parse_up("--up", value, up) != 0) return -1;
        for (k = 0; k < 3; k++) field->up[k] = (float)up[k];
    } else if (tool_option(argc, argv, index, "--constraints", &value)) {
        if (!value) {
            tool_usage("--constraints needs a value");
            return -1;
        }
        field->constraints_path = value;
    } else {
        return 0;
    }
    field->given = 1;
    return 1;
}
