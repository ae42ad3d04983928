/* tool_io.c - the plumbing every `tiledtex` subcommand shares: error lines,
   command-line parsing, reading files, OBJ / MTL, PNG, and atomic output.
   See tool.h for the interface; this file is its implementation. */

#include <ctype.h>
#include <errno.h>
#include <float.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tool.h"

/* stb_image and stb_image_write (Debian package libstb-dev) are compiled in
   this one file. They are not written for -Wextra -pedantic -Wshadow, so their
   own warnings are switched off around them - and only around them. */
#if defined(__GNUC__) || defined(__clang__)
#pragma GCC diagnostic push
#ifdef __clang__
#pragma clang diagnostic ignored "-Wunknown-warning-option"
#endif
#pragma GCC diagnostic ignored "-Wpedantic"
#pragma GCC diagnostic ignored "-Wunused-but-set-variable"
#pragma GCC diagnostic ignored "-Wshadow"
#pragma GCC diagnostic ignored "-Wunused-parameter"
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wsign-compare"
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#pragma GCC diagnostic ignored "-Wstrict-prototypes"
#pragma GCC diagnostic ignored "-Wimplicit-fallthrough"
#endif
#define STB_IMAGE_IMPLEMENTATION
#define STBI_FAILURE_USERMSG        /* friendlier texts from stbi_failure_reason() */
#include "stb_image.h"
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include "stb_image_write.h"
#if defined(__GNUC__) || defined(__clang__)
#pragma GCC diagnostic pop
#endif

/* ======================================================================== */
/* Errors                                                                   */
/* ======================================================================== */

/* The tool is a single-threaded program, so one static "current command" is
   simpler than threading the name through every helper. */
static const char *tool_command_name = NULL;

void tool_set_command(const char *name) { tool_command_name = name; }

static void print_error_line(const char *prefix_command, const char *format, va_list args)
{
    /* Format into a buffer first so the line reaches stderr in one piece, and
       so a newline inside the message cannot split it into several lines. */
    char message[1024];
    char *c;
    vsnprintf(message, sizeof message, format, args);
    for (c = message; *c; c++)
        if (*c == '\n' || *c == '\r') *c = ' ';
    if (prefix_command)
        fprintf(stderr, "%s %s: %s\n", TOOL_NAME, prefix_command, message);
    else
        fprintf(stderr, "%s: %s\n", TOOL_NAME, message);
}

int tool_fail(const char *format, ...)
{
    va_list args;
    va_start(args, format);
    print_error_line(NULL, format, args);
    va_end(args);
    return TOOL_EXIT_FAILURE;
}

int tool_usage(const char *format, ...)
{
    va_list args;
    va_start(args, format);
    print_error_line(tool_command_name, format, args);
    va_end(args);
    return TOOL_EXIT_USAGE;
}

/* Fill a caller's error buffer (which may be NULL). */
static void set_error(char *err, size_t err_size, const char *format, ...)
#if defined(__GNUC__) || defined(__clang__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;
static void set_error(char *err, size_t err_size, const char *format, ...)
{
    va_list args;
    if (!err || err_size == 0) return;
    va_start(args, format);
    vsnprintf(err, err_size, format, args);
    va_end(args);
}

/* ======================================================================== */
/* Command-line helpers                                                     */
/* ======================================================================== */

int tool_is_help(const char *arg)
{
    return strcmp(arg, "-h") == 0 || strcmp(arg, "--help") == 0;
}

int tool_is_option(const char *arg)
{
    /* "-" alone often means standard input, and "-3" is a number. */
    return arg[0] == '-' && arg[1] != '\0' && !isdigit((unsigned char)arg[1]) && arg[1] != '.';
}

int tool_unknown_option(const char *arg)
{
    if (tool_command_name)
        return tool_usage("unknown option '%s' (see '%s %s --help')", arg, TOOL_NAME, tool_command_name);
    return tool_usage("unknown option '%s' (see '%s --help')", arg, TOOL_NAME);
}

int tool_option(int argc, char **argv, int *index, const char *name, const char **value)
{
    const char *arg = argv[*index];
    size_t name_length = strlen(name);
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

/* ======================================================================== */
/* Files and byte buffers                                                   */
/* ======================================================================== */

/* Make room for `extra` more bytes (plus a NUL we always keep after the data,
   so text in a buffer can be handed to C string functions). */
static int buffer_reserve(tool_buffer *buffer, size_t extra)
{
    size_t needed, capacity;
    char *grown;
    if (buffer->failed) return -1;
    if (extra > SIZE_MAX - 1 - buffer->size) { buffer->failed = 1; return -1; }
    needed = buffer->size + extra + 1;
    if (needed <= buffer->capacity) return 0;
    capacity = buffer->capacity ? buffer->capacity : 4096;
    while (capacity < needed) capacity = capacity > SIZE_MAX / 2 ? needed : capacity * 2;
    grown = (char *)realloc(buffer->data, capacity);
    if (!grown) { buffer->failed = 1; return -1; }
    buffer->data = grown;
    buffer->capacity = capacity;
    return 0;
}

void buffer_append(tool_buffer *buffer, const void *bytes, size_t count)
{
    if (buffer_reserve(buffer, count) != 0) return;
    if (count) memcpy(buffer->data + buffer->size, bytes, count);
    buffer->size += count;
    buffer->data[buffer->size] = '\0';
}

void buffer_printf(tool_buffer *buffer, const char *format, ...)
{
    va_list args;
    int length;
    size_t room;
    if (buffer_reserve(buffer, 256) != 0) return;
    /* Try to format in place; only when the text is longer than the room left
       do we grow the buffer and format a second time. */
    room = buffer->capacity - buffer->size;
    va_start(args, format);
    length = vsnprintf(buffer->data + buffer->size, room, format, args);
    va_end(args);
    if (length < 0) { buffer->failed = 1; return; }
    if ((size_t)length >= room) {
        if (buffer_reserve(buffer, (size_t)length) != 0) return;
        va_start(args, format);
        vsnprintf(buffer->data + buffer->size, (size_t)length + 1, format, args);
        va_end(args);
    }
    buffer->size += (size_t)length;
}

void buffer_free(tool_buffer *buffer)
{
    free(buffer->data);
    memset(buffer, 0, sizeof *buffer);
}

int tool_read_file(const char *path, unsigned char **data, size_t *size, char *err, size_t err_size)
{
    tool_buffer buffer = {0};
    FILE *file;
    int from_stdin = strcmp(path, "-") == 0;
    *data = NULL;
    *size = 0;
    file = from_stdin ? stdin : fopen(path, "rb");
    if (!file) {
        set_error(err, err_size, "cannot open '%s': %s", path, strerror(errno));
        return -1;
    }
    /* Read in chunks rather than asking for the file's size: that also works
       for pipes and standard input. */
    for (;;) {
        size_t got;
        if (buffer_reserve(&buffer, 65536) != 0) {
            set_error(err, err_size, "'%s' is too large to read into memory", path);
            break;
        }
        got = fread(buffer.data + buffer.size, 1, buffer.capacity - buffer.size - 1, file);
        buffer.size += got;
        if (got == 0) break;
    }
    if (!buffer.failed && ferror(file)) {
        set_error(err, err_size, "cannot read '%s': %s", path, strerror(errno));
        buffer.failed = 1;
    }
    if (!from_stdin) fclose(file);
    if (buffer.failed) {
        buffer_free(&buffer);
        return -1;
    }
    buffer.data[buffer.size] = '\0';
    *data = (unsigned char *)buffer.data;
    *size = buffer.size;
    return 0;
}

void tool_relative_path(const char *target, const char *from_file, char *out, size_t out_size)
{
    /* Directory parts of both, as text ranges; "." parts are skipped. */
    const char *from_end = tool_basename(from_file), *target_name = tool_basename(target);
    const char *f = from_file, *t = target;
    size_t used = 0;
    int ups = 0;
    if (target[0] == '/') {
        snprintf(out, out_size, "%s", target);
        return;
    }
    /* Skip the directories both paths share, one part at a time. */
    for (;;) {
        const char *fe, *te;
        while (f < from_end && (*f == '/' || (f[0] == '.' && (f[1] == '/')))) f += (*f == '/') ? 1 : 2;
        while (t < target_name && (*t == '/' || (t[0] == '.' && (t[1] == '/')))) t += (*t == '/') ? 1 : 2;
        fe = f;
        te = t;
        while (fe < from_end && *fe != '/') fe++;
        while (te < target_name && *te != '/') te++;
        if (f == from_end || t == target_name || fe - f != te - t || strncmp(f, t, (size_t)(fe - f)) != 0) break;
        f = fe;
        t = te;
    }
    /* Every directory left on the file's side is one step up, unless it is a
       step up itself: then the way back cannot be named, so keep the path. */
    while (f < from_end) {
        const char *fe = f;
        while (fe < from_end && *fe != '/') fe++;
        if (fe - f == 2 && f[0] == '.' && f[1] == '.') {
            snprintf(out, out_size, "%s", target);
            return;
        }
        if (fe > f && !(fe - f == 1 && f[0] == '.')) ups++;
        f = fe;
        while (f < from_end && *f == '/') f++;
    }
    out[0] = '\0';
    while (ups-- > 0 && used + 3 < out_size) {
        memcpy(out + used, "../", 3);
        used += 3;
    }
    snprintf(out + used, out_size - used, "%s", t);
}

const char *tool_basename(const char *path)
{
    const char *base = path, *p;
    for (p = path; *p; p++)
        if (*p == '/' || *p == '\\') base = p + 1;
    return base;
}

static char *copy_string(const char *text, size_t length)
{
    char *copy = (char *)malloc(length + 1);
    if (!copy) return NULL;
    memcpy(copy, text, length);
    copy[length] = '\0';
    return copy;
}

/* ======================================================================== */
/* Atomic output                                                            */
/* ======================================================================== */

int output_add(tool_output *output, const char *path, void *data, size_t size)
{
    int i;
    char *path_copy;
    for (i = 0; i < output->count; i++) {
        if (strcmp(output->files[i].path, path) == 0) {   /* same file again: the new contents win */
            free(output->files[i].data);
            output->files[i].data = (unsigned char *)data;
            output->files[i].size = size;
            return 0;
        }
    }
    if (output->count == output->capacity) {
        int capacity = output->capacity ? output->capacity * 2 : 4;
        tool_output_file *grown = (tool_output_file *)realloc(output->files, (size_t)capacity * sizeof *grown);
        if (!grown) { free(data); return -1; }
        output->files = grown;
        output->capacity = capacity;
    }
    path_copy = copy_string(path, strlen(path));
    if (!path_copy) { free(data); return -1; }
    output->files[output->count].path = path_copy;
    output->files[output->count].data = (unsigned char *)data;
    output->files[output->count].size = size;
    output->count++;
    return 0;
}

int output_add_buffer(tool_output *output, const char *path, tool_buffer *buffer)
{
    int failed = buffer->failed;
    void *data = buffer->data;
    size_t size = buffer->size;
    memset(buffer, 0, sizeof *buffer);
    if (failed) { free(data); return -1; }
    return output_add(output, path, data, size);
}

int output_add_png(tool_output *output, const char *path, const tt_image *image, char *err, size_t err_size)
{
    unsigned char *png;
    size_t png_size;
    if (png_encode(image, &png, &png_size, err, err_size) != 0) return -1;
    if (output_add(output, path, png, png_size) != 0) {
        set_error(err, err_size, "out of memory while preparing '%s'", path);
        return -1;
    }
    return 0;
}

#define TEMPORARY_SUFFIX ".tiledtex-tmp"

static char *temporary_name(const char *path)
{
    size_t length = strlen(path);
    char *name = (char *)malloc(length + sizeof TEMPORARY_SUFFIX);
    if (!name) return NULL;
    memcpy(name, path, length);
    memcpy(name + length, TEMPORARY_SUFFIX, sizeof TEMPORARY_SUFFIX);
    return name;
}

/* Write one file completely; any short write or failed close is an error
   (a full disk often shows up only at fclose). */
static int write_whole_file(const char *path, const unsigned char *data, size_t size)
{
    FILE *file = fopen(path, "wb");
    int ok;
    if (!file) return -1;
    ok = (size == 0 || fwrite(data, 1, size, file) == size);
    ok = (fflush(file) == 0) && ok;
    ok = (fclose(file) == 0) && ok;
    return ok ? 0 : -1;
}

int output_commit(tool_output *output, char *err, size_t err_size)
{
    char **temporaries;
    int written = 0, renamed = 0, i, failed = 0;
    if (output->count == 0) return 0;
    temporaries = (char **)calloc((size_t)output->count, sizeof *temporaries);
    if (!temporaries) {
        set_error(err, err_size, "out of memory while writing the output files");
        return -1;
    }
    /* Phase 1: every file to its temporary name beside the real one (the same
       directory, so the rename below cannot cross file systems). */
    for (i = 0; i < output->count && !failed; i++) {
        const tool_output_file *file = &output->files[i];
        size_t length = strlen(file->path);
        if (length == 0 || file->path[length - 1] == '/') {
            set_error(err, err_size, "'%s' names a directory: give a file name", file->path);
            failed = 1;
            break;
        }
        temporaries[i] = temporary_name(file->path);
        if (!temporaries[i]) {
            set_error(err, err_size, "out of memory while writing '%s'", file->path);
            failed = 1;
        } else if (write_whole_file(temporaries[i], file->data, file->size) != 0) {
            set_error(err, err_size, "cannot write '%s': %s", file->path, strerror(errno));
            remove(temporaries[i]);     /* may exist half-written */
            failed = 1;
        } else {
            written = i + 1;
        }
    }
    /* Phase 2: only when all are complete, give them their real names. */
    for (i = 0; i < written && !failed; i++) {
        if (rename(temporaries[i], output->files[i].path) != 0) {
            set_error(err, err_size, "cannot write '%s': %s", output->files[i].path, strerror(errno));
            failed = 1;
        } else {
            renamed = i + 1;
        }
    }
    if (failed) {
        /* Undo: no temporary stays behind, and no file of this batch either. */
        for (i = renamed; i < written; i++) remove(temporaries[i]);
        for (i = 0; i < renamed; i++) remove(output->files[i].path);
    }
    for (i = 0; i < output->count; i++) free(temporaries[i]);
    free(temporaries);
    return failed ? -1 : 0;
}

void output_free(tool_output *output)
{
    int i;
    for (i = 0; i < output->count; i++) {
        free(output->files[i].path);
        free(output->files[i].data);
    }
    free(output->files);
    memset(output, 0, sizeof *output);
}

/* ======================================================================== */
/* Images                                                                   */
/* ======================================================================== */

int image_load(const char *path, tt_image *image, char *err, size_t err_size)
{
    unsigned char *file_data, *pixels;
    size_t file_size;
    int width, height, channels;
    tt_result result;
    memset(image, 0, sizeof *image);
    if (tool_read_file(path, &file_data, &file_size, err, err_size) != 0) return -1;
    if (file_size > INT_MAX) {
        set_error(err, err_size, "'%s' is too large to be an image this tool can read", path);
        free(file_data);
        return -1;
    }
    /* Look at the header first: a corrupt or hostile file can claim a huge
       size, and we want to refuse it before anything is allocated for it. */
    if (!stbi_info_from_memory(file_data, (int)file_size, &width, &height, &channels)) {
        set_error(err, err_size, "'%s' is not an image that can be read (%s)", path, stbi_failure_reason());
        free(file_data);
        return -1;
    }
    if (width > TT_MAX_IMAGE_SIZE || height > TT_MAX_IMAGE_SIZE) {
        set_error(err, err_size, "'%s' is %dx%d; images up to %dx%d are supported", path, width, height,
                  TT_MAX_IMAGE_SIZE, TT_MAX_IMAGE_SIZE);
        free(file_data);
        return -1;
    }
    pixels = stbi_load_from_memory(file_data, (int)file_size, &width, &height, &channels, 0);
    free(file_data);
    if (!pixels) {
        set_error(err, err_size, "cannot decode '%s' (%s)", path, stbi_failure_reason());
        return -1;
    }
    result = tt_image_from_bytes(image, pixels, width, height, channels, 0, NULL);
    stbi_image_free(pixels);
    if (result != TT_OK) {
        set_error(err, err_size, "cannot use '%s': %s", path, tt_result_string(result));
        memset(image, 0, sizeof *image);
        return -1;
    }
    return 0;
}

/* stb_image_write hands the encoded PNG over in pieces; collect them. */
static void collect_png_bytes(void *context, void *bytes, int count)
{
    if (count > 0) buffer_append((tool_buffer *)context, bytes, (size_t)count);
}

int png_encode(const tt_image *image, unsigned char **png, size_t *png_size, char *err, size_t err_size)
{
    tool_buffer buffer = {0};
    unsigned char *rgba;
    size_t bytes;
    int ok;
    *png = NULL;
    *png_size = 0;
    if (!image || !image->pixels || image->width <= 0 || image->height <= 0 ||
        image->width > TT_MAX_IMAGE_SIZE || image->height > TT_MAX_IMAGE_SIZE) {
        set_error(err, err_size, "cannot save an empty or oversized image");
        return -1;
    }
    bytes = (size_t)image->width * (size_t)image->height * 4;
    rgba = (unsigned char *)malloc(bytes);
    if (!rgba) {
        set_error(err, err_size, "out of memory while encoding a %dx%d PNG", image->width, image->height);
        return -1;
    }
    tt_image_to_rgba8(image, rgba);
    ok = stbi_write_png_to_func(collect_png_bytes, &buffer, image->width, image->height, 4, rgba,
                                image->width * 4);
    free(rgba);
    if (!ok || buffer.failed) {
        set_error(err, err_size, "could not encode a %dx%d PNG (out of memory?)", image->width, image->height);
        buffer_free(&buffer);
        return -1;
    }
    *png = (unsigned char *)buffer.data;
    *png_size = buffer.size;
    return 0;
}

/* ======================================================================== */
/* OBJ reading                                                              */
/*                                                                          */
/* One pass over the text with a cursor; no allocation per token. Arrays    */
/* grow by doubling with overflow-checked sizes. Counts are capped well     */
/* below INT_MAX so that 3 * nverts and 2 * ncorners still fit an int.      */
/* ======================================================================== */

#define OBJ_MAX_COUNT (1 << 28)
#define OBJ_MAX_NUMBER_LENGTH 128   /* longer "numbers" are not numbers */
#define OBJ_MAX_NAME_LENGTH 1024    /* group / material names are cut here */

typedef struct obj_parser {
    const char *p, *end;        /* cursor over the text */
    int line;                   /* physical line of the cursor, 1-based */
    int statement_line;         /* line the current statement starts on */
    const char *statement;      /* its first byte, for quoting in messages */
    const char *source;         /* file name for messages, or NULL */
    char *err;
    size_t err_size;
    obj_mesh *mesh;
    int pos_capacity, vert_line_capacity, uv_capacity, face_capacity, corner_capacity, group_capacity;
    int nnormals;
    int current_group;
    int *group_table;           /* open-addressing hash: group index + 1, 0 = empty */
    int group_table_size;       /* a power of two, kept at least twice ngroups */
} obj_parser;

/* The capacity to grow an array to so that `needed` elements fit: doubling,
   so appending n elements costs O(n) in all; -1 if the bytes would overflow. */
static int grown_capacity(int capacity, int needed, size_t element_size, int *out)
{
    size_t grown = capacity > 0 ? (size_t)capacity : 16;
    while (grown < (size_t)needed) grown *= 2;
    if (grown > INT_MAX) grown = (size_t)needed;
    if (grown > SIZE_MAX / element_size) return -1;
    *out = (int)grown;
    return 0;
}

static int resize_array(void **array, int capacity, size_t element_size)
{
    void *resized = realloc(*array, (size_t)capacity * element_size);
    if (!resized) return -1;
    *array = resized;
    return 0;
}

/* Grow *array (of element_size bytes each) so it holds at least `needed`. */
static int grow_array(void **array, int *capacity, int needed, size_t element_size)
{
    int new_capacity;
    if (needed <= *capacity) return 0;
    if (grown_capacity(*capacity, needed, element_size, &new_capacity) != 0) return -1;
    if (resize_array(array, new_capacity, element_size) != 0) return -1;
    *capacity = new_capacity;
    return 0;
}

/* Report an error on the current statement's line. Always returns -1. */
static int obj_error(obj_parser *P, const char *format, ...)
#if defined(__GNUC__) || defined(__clang__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;
static int obj_error(obj_parser *P, const char *format, ...)
{
    char message[400];
    va_list args;
    va_start(args, format);
    vsnprintf(message, sizeof message, format, args);
    va_end(args);
    if (P->source)
        set_error(P->err, P->err_size, "%s:%d: %s", P->source, P->statement_line, message);
    else
        set_error(P->err, P->err_size, "line %d: %s", P->statement_line, message);
    return -1;
}

/* The current statement as printable text for messages: its first line, at
   most 60 bytes, with control bytes and non-ASCII shown as '?'. */
static const char *quote_statement(const obj_parser *P, char *out, size_t out_size)
{
    const char *p = P->statement;
    size_t n = 0;
    while (p < P->end && *p != '\n' && n + 4 < out_size && n < 60) {
        unsigned char c = (unsigned char)*p++;
        if (c == '\r' && (p == P->end || *p == '\n')) break;
        out[n++] = (c >= 32 && c < 127) ? (char)c : '?';
    }
    if (p < P->end && *p != '\n' && !(*p == '\r' && (p + 1 == P->end || p[1] == '\n'))) {
        out[n++] = '.'; out[n++] = '.'; out[n++] = '.';
    }
    out[n] = '\0';
    return out;
}

static int out_of_memory(obj_parser *P)
{
    return obj_error(P, "out of memory");
}

static int is_blank(char c)
{
    return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f';
}

/* A '\' right before the end of a line joins the next line to this one.
   Returns how many bytes the continuation takes (0 if there is none here). */
static size_t continuation_length(const obj_parser *P, const char *p)
{
    if (p >= P->end || *p != '\\') return 0;
    if (p + 1 < P->end && p[1] == '\n') return 2;
    if (p + 2 < P->end && p[1] == '\r' && p[2] == '\n') return 3;
    return 0;
}

static void count_line(obj_parser *P)
{
    if (P->line < INT_MAX) P->line++;
}

/* Skip blanks and line continuations; stop at a newline, the end, or text. */
static void skip_blanks(obj_parser *P)
{
    for (;;) {
        size_t joined;
        while (P->p < P->end && is_blank(*P->p)) P->p++;
        joined = continuation_length(P, P->p);
        if (!joined) return;
        P->p += joined;
        count_line(P);
    }
}

static int at_statement_end(const obj_parser *P)
{
    return P->p >= P->end || *P->p == '\n';
}

/* The next whitespace-separated token of the statement; length 0 at its end. */
static size_t next_token(obj_parser *P, const char **token)
{
    const char *start;
    skip_blanks(P);
    start = P->p;
    while (P->p < P->end && *P->p != '\n' && !is_blank(*P->p) && !continuation_length(P, P->p)) P->p++;
    *token = start;
    return (size_t)(P->p - start);
}

/* Move past the rest of the statement and its newline. */
static void finish_statement(obj_parser *P)
{
    while (P->p < P->end && *P->p != '\n') {
        size_t joined = continuation_length(P, P->p);
        if (joined) { P->p += joined; count_line(P); }
        else P->p++;
    }
    if (P->p < P->end) { P->p++; count_line(P); }
}

static int token_is(const char *token, size_t length, const char *word)
{
    return strlen(word) == length && memcmp(token, word, length) == 0;
}

/* Read the next token as a number. Returns 1 on success, 0 when the statement
   has ended (or a comment starts), -1 when the token is not a number. */
static int read_number(obj_parser *P, float *out)
{
    char text[OBJ_MAX_NUMBER_LENGTH];
    const char *token;
    char *end;
    double value;
    size_t length = next_token(P, &token);
    if (length == 0 || token[0] == '#') return 0;
    if (length >= sizeof text) return -1;
    /* strtod needs a NUL-terminated string, and the input has no NUL after
       the token, so copy it (at most 127 bytes, on the stack). */
    memcpy(text, token, length);
    text[length] = '\0';
    value = strtod(text, &end);
    if (end != text + length) return -1;
    /* NaN and infinity are passed through (the library rejects them with a
       message naming the vertex); a finite double beyond float range becomes
       infinity explicitly, because converting it is undefined behaviour. */
    if (value > FLT_MAX) *out = (float)INFINITY;
    else if (value < -FLT_MAX) *out = (float)-INFINITY;
    else *out = (float)value;
    return 1;
}

static int parse_vertex(obj_parser *P)
{
    obj_mesh *mesh = P->mesh;
    float xyz[3];
    int i;
    for (i = 0; i < 3; i++) {
        int got = read_number(P, &xyz[i]);
        if (got <= 0) {
            char quoted[80];
            return obj_error(P, got < 0 ? "cannot read a number in '%s'"
                                        : "a vertex needs 3 coordinates: '%s'",
                             quote_statement(P, quoted, sizeof quoted));
        }
    }
    /* A 4th number (w) or vertex colours may follow; they are not needed. */
    if (mesh->nverts >= OBJ_MAX_COUNT) return obj_error(P, "too many vertices (at most %d)", OBJ_MAX_COUNT);
    if (grow_array((void **)&mesh->pos, &P->pos_capacity, (mesh->nverts + 1) * 3, sizeof(float)) != 0 ||
        grow_array((void **)&mesh->vert_line, &P->vert_line_capacity, mesh->nverts + 1, sizeof(int)) != 0)
        return out_of_memory(P);
    memcpy(mesh->pos + 3 * (size_t)mesh->nverts, xyz, sizeof xyz);
    mesh->vert_line[mesh->nverts] = P->statement_line;
    mesh->nverts++;
    return 0;
}

static int parse_texture_vertex(obj_parser *P)
{
    obj_mesh *mesh = P->mesh;
    float uv[2] = {0.0f, 0.0f};     /* "vt u" alone means v = 0 */
    int i;
    for (i = 0; i < 2; i++) {
        int got = read_number(P, &uv[i]);
        if (got < 0 || (got == 0 && i == 0)) {
            char quoted[80];
            return obj_error(P, got < 0 ? "cannot read a number in '%s'"
                                        : "a texture vertex needs a coordinate: '%s'",
                             quote_statement(P, quoted, sizeof quoted));
        }
        if (got == 0) break;
    }
    if (mesh->nuvs >= OBJ_MAX_COUNT) return obj_error(P, "too many texture vertices (at most %d)", OBJ_MAX_COUNT);
    if (grow_array((void **)&mesh->uv, &P->uv_capacity, (mesh->nuvs + 1) * 2, sizeof(float)) != 0)
        return out_of_memory(P);
    mesh->uv[2 * (size_t)mesh->nuvs] = uv[0];
    mesh->uv[2 * (size_t)mesh->nuvs + 1] = uv[1];
    mesh->nuvs++;
    return 0;
}

/* One index field of a face corner ("12", "-3"). Returns the number of bytes
   read (0 if the field is empty). *value saturates at +-(INT_MAX + 1), which is
   out of range for every count, so overflow cannot slip through. */
static size_t read_index(const char *p, const char *end, long long *value, int *valid)
{
    const char *start = p;
    int negative = 0;
    long long v = 0;
    if (p < end && (*p == '-' || *p == '+')) { negative = (*p == '-'); p++; }
    *valid = (p < end && isdigit((unsigned char)*p));
    while (p < end && isdigit((unsigned char)*p)) {
        if (v <= INT_MAX) v = v * 10 + (*p - '0');
        p++;
    }
    *value = negative ? -v : v;
    return (size_t)(p - start);
}

/* Turn a 1-based or negative (relative) OBJ index into a 0-based one. */
static int resolve_index(obj_parser *P, long long index, int defined, const char *what,
                         const char *text, size_t text_length, int *out)
{
    long long resolved = index > 0 ? index - 1 : (long long)defined + index;
    if (index == 0)
        return obj_error(P, "face refers to %s 0, but OBJ numbers them from 1", what);
    if (resolved < 0 || resolved >= defined) {
        /* Quote the index as written (it may be too long for an int). */
        int shown = text_length > 24 ? 24 : (int)text_length;
        return obj_error(P, "face refers to %s %.*s%s but only %d %s defined so far", what, shown, text,
                         shown < (int)text_length ? "..." : "", defined, defined == 1 ? "is" : "are");
    }
    *out = (int)resolved;
    return 0;
}

static int parse_face(obj_parser *P)
{
    obj_mesh *mesh = P->mesh;
    int corners = 0;
    for (;;) {
        const char *token, *p, *token_end;
        long long v_index, vt_index = 0, vn_index;
        size_t v_length;
        int v_valid, vt_valid = 0, vn_valid, vertex, uv = -1;
        size_t length = next_token(P, &token);
        char quoted[80];
        if (length == 0 || token[0] == '#') break;
        p = token;
        token_end = token + length;
        /* v, v/vt, v//vn or v/vt/vn */
        v_length = read_index(p, token_end, &v_index, &v_valid);
        p += v_length;
        if (v_valid && p < token_end && *p == '/') {
            p++;
            p += read_index(p, token_end, &vt_index, &vt_valid);
            if (p < token_end && *p == '/') {
                const char *normal = ++p;
                p += read_index(p, token_end, &vn_index, &vn_valid);
                if (p == normal) vn_valid = 1;   /* "v/vt/" : tolerated, as many readers do */
                (void)vn_index;                  /* normals are recomputed, not read */
                if (!vn_valid) p = token;        /* force the error below */
            }
        }
        if (!v_valid || p != token_end) {
            int shown = length > 24 ? 24 : (int)length;
            return obj_error(P, "cannot read the face corner '%.*s' in '%s'", shown, token,
                             quote_statement(P, quoted, sizeof quoted));
        }
        if (resolve_index(P, v_index, mesh->nverts, "vertex", token, v_length, &vertex) != 0)
            return -1;
        if (vt_valid) {
            const char *vt_text = (const char *)memchr(token, '/', length);
            size_t vt_length = 0;
            vt_text++;
            while (vt_text + vt_length < token_end && vt_text[vt_length] != '/') vt_length++;
            if (resolve_index(P, vt_index, mesh->nuvs, "texture vertex", vt_text, vt_length, &uv) != 0)
                return -1;
        }

        if (mesh->ncorners >= OBJ_MAX_COUNT) return obj_error(P, "too many face corners (at most %d)", OBJ_MAX_COUNT);
        if (mesh->ncorners == P->corner_capacity) {
            /* corner_vert and corner_uv (once it exists) share one capacity. */
            int capacity;
            if (grown_capacity(P->corner_capacity, mesh->ncorners + 1, sizeof(int), &capacity) != 0 ||
                resize_array((void **)&mesh->corner_vert, capacity, sizeof(int)) != 0 ||
                (mesh->corner_uv && resize_array((void **)&mesh->corner_uv, capacity, sizeof(int)) != 0))
                return out_of_memory(P);
            P->corner_capacity = capacity;
        }
        if (uv >= 0 && !mesh->corner_uv) {
            /* The first corner with a texture vertex: from now on every corner
               records one, and the earlier corners had none. */
            int c;
            mesh->corner_uv = (int *)malloc((size_t)P->corner_capacity * sizeof(int));
            if (!mesh->corner_uv) return out_of_memory(P);
            for (c = 0; c < mesh->ncorners; c++) mesh->corner_uv[c] = -1;
        }
        mesh->corner_vert[mesh->ncorners] = vertex;
        if (mesh->corner_uv) mesh->corner_uv[mesh->ncorners] = uv;
        mesh->ncorners++;
        corners++;
    }
    if (corners < 3) return obj_error(P, "face with fewer than 3 corners");
    if (mesh->nfaces >= OBJ_MAX_COUNT) return obj_error(P, "too many faces (at most %d)", OBJ_MAX_COUNT);
    if (mesh->nfaces == P->face_capacity) {
        /* face_size, face_group and face_line share one capacity. */
        int capacity;
        if (grown_capacity(P->face_capacity, mesh->nfaces + 1, sizeof(int), &capacity) != 0 ||
            resize_array((void **)&mesh->face_size, capacity, sizeof(int)) != 0 ||
            resize_array((void **)&mesh->face_group, capacity, sizeof(int)) != 0 ||
            resize_array((void **)&mesh->face_line, capacity, sizeof(int)) != 0)
            return out_of_memory(P);
        P->face_capacity = capacity;
    }
    mesh->face_size[mesh->nfaces] = corners;
    mesh->face_group[mesh->nfaces] = P->current_group;
    mesh->face_line[mesh->nfaces] = P->statement_line;
    mesh->nfaces++;
    return 0;
}

/* The rest of the statement as one name ("g left arm" -> "left arm"), with
   runs of blanks turned into single spaces and a trailing comment dropped. */
static size_t read_name(obj_parser *P, char *name, size_t name_size)
{
    size_t n = 0;
    for (;;) {
        const char *token;
        size_t length = next_token(P, &token);
        if (length == 0 || token[0] == '#') break;
        if (n > 0 && n + 1 < name_size) name[n++] = ' ';
        if (length > name_size - 1 - n) length = name_size - 1 - n;
        /* Control bytes (a NUL would end the C string early) become '_'. */
        for (; length > 0; length--, token++) name[n++] = (unsigned char)*token < 0x20 ? '_' : *token;
    }
    name[n] = '\0';
    return n;
}

static uint32_t hash_name(const char *name)
{
    uint32_t h = 2166136261u;   /* FNV-1a */
    while (*name) { h ^= (unsigned char)*name++; h *= 16777619u; }
    return h;
}

/* Index of the group called `name`, adding it if it is new. Names are looked
   up in a hash table, so a file with many groups (one per paste, say) stays
   linear-time. */
static int find_or_add_group(obj_parser *P, const char *name, size_t length)
{
    obj_mesh *mesh = P->mesh;
    uint32_t mask, slot;
    if (mesh->ngroups * 2 >= P->group_table_size) {
        /* Rebuild the table twice as large. */
        int size = P->group_table_size ? P->group_table_size * 2 : 64, g;
        int *table;
        if (size > OBJ_MAX_COUNT) return out_of_memory(P);
        table = (int *)calloc((size_t)size, sizeof(int));
        if (!table) return out_of_memory(P);
        for (g = 0; g < mesh->ngroups; g++) {
            uint32_t s = hash_name(mesh->group_names[g]) & (uint32_t)(size - 1);
            while (table[s]) s = (s + 1) & (uint32_t)(size - 1);
            table[s] = g + 1;
        }
        free(P->group_table);
        P->group_table = table;
        P->group_table_size = size;
    }
    mask = (uint32_t)P->group_table_size - 1;
    for (slot = hash_name(name) & mask; P->group_table[slot]; slot = (slot + 1) & mask)
        if (strcmp(mesh->group_names[P->group_table[slot] - 1], name) == 0) return P->group_table[slot] - 1;
    if (grow_array((void **)&mesh->group_names, &P->group_capacity, mesh->ngroups + 1, sizeof(char *)) != 0)
        return out_of_memory(P);
    mesh->group_names[mesh->ngroups] = copy_string(name, length);
    if (!mesh->group_names[mesh->ngroups]) return out_of_memory(P);
    P->group_table[slot] = mesh->ngroups + 1;
    return mesh->ngroups++;
}

static int parse_statement(obj_parser *P)
{
    const char *keyword;
    size_t length = next_token(P, &keyword);
    char name[OBJ_MAX_NAME_LENGTH];
    if (token_is(keyword, length, "v")) return parse_vertex(P);
    if (token_is(keyword, length, "vt")) return parse_texture_vertex(P);
    if (token_is(keyword, length, "f")) return parse_face(P);
    if (token_is(keyword, length, "vn")) {
        P->nnormals++;      /* counted only; normals are recomputed by whoever needs them */
        return 0;
    }
    if (token_is(keyword, length, "g") || token_is(keyword, length, "o") || token_is(keyword, length, "usemtl")) {
        size_t name_length = read_name(P, name, sizeof name);
        int group = find_or_add_group(P, name, name_length);
        if (group < 0) return -1;
        P->current_group = group;
        return 0;
    }
    if (token_is(keyword, length, "mtllib")) {
        size_t name_length = read_name(P, name, sizeof name);
        if (!P->mesh->mtllib && name_length > 0) {
            P->mesh->mtllib = copy_string(name, name_length);
            if (!P->mesh->mtllib) return out_of_memory(P);
        }
        return 0;
    }
    return 0;   /* comments and everything else (vn, vp, s, l, p, curves, ...) are skipped */
}

static int obj_parse_named(const char *text, size_t length, const char *source, obj_mesh *out, char *err,
                           size_t err_size)
{
    obj_parser parser;
    obj_parser *P = &parser;
    memset(out, 0, sizeof *out);
    memset(P, 0, sizeof *P);
    P->p = text ? text : "";
    P->end = P->p + (text ? length : 0);
    P->line = 1;
    P->source = source;
    P->err = err;
    P->err_size = err_size;
    P->mesh = out;
    set_error(err, err_size, "no error");

    if (find_or_add_group(P, "", 0) != 0) goto fail;    /* group 0: faces before any g / o / usemtl */
    while (P->p < P->end) {
        skip_blanks(P);
        if (at_statement_end(P)) {      /* blank line */
            finish_statement(P);
            continue;
        }
        P->statement = P->p;
        P->statement_line = P->line;
        if (parse_statement(P) != 0) goto fail;
        finish_statement(P);
    }
    if (out->nfaces == 0) {
        if (source) set_error(err, err_size, "%s: no faces", source);
        else set_error(err, err_size, "no faces");
        goto fail;
    }
    free(P->group_table);
    return 0;

fail:
    free(P->group_table);
    obj_free(out);
    return -1;
}

int obj_parse(const char *text, size_t length, obj_mesh *out, char *err, size_t err_size)
{
    return obj_parse_named(text, length, NULL, out, err, err_size);
}

int obj_read(const char *path, obj_mesh *out, char *err, size_t err_size)
{
    unsigned char *data;
    size_t size;
    int result;
    memset(out, 0, sizeof *out);
    if (tool_read_file(path, &data, &size, err, err_size) != 0) return -1;
    result = obj_parse_named((const char *)data, size, path, out, err, err_size);
    free(data);
    return result;
}

tt_mesh_desc obj_mesh_desc(const obj_mesh *mesh, unsigned flags)
{
    tt_mesh_desc desc;
    memset(&desc, 0, sizeof desc);
    desc.positions = mesh->pos;
    desc.nverts = mesh->nverts;
    desc.indices = mesh->corner_vert;
    desc.face_sizes = mesh->face_size;
    desc.nfaces = mesh->nfaces;
    desc.flags = flags;
    return desc;
}

int obj_triangle_fans(const obj_mesh *mesh, int **corners, int **faces)
{
    int f, first = 0, t = 0, total = 0;
    for (f = 0; f < mesh->nfaces; f++) total += mesh->face_size[f] - 2;   /* < ncorners: no overflow */
    *corners = (int *)malloc((size_t)total * 3 * sizeof(int));
    *faces = (int *)malloc((size_t)total * sizeof(int));
    if (!*corners || !*faces) {
        free(*corners);
        free(*faces);
        *corners = *faces = NULL;
        return -1;
    }
    for (f = 0; f < mesh->nfaces; f++) {
        int i;
        for (i = 1; i + 1 < mesh->face_size[f]; i++, t++) {
            (*corners)[3 * t] = first;
            (*corners)[3 * t + 1] = first + i;
            (*corners)[3 * t + 2] = first + i + 1;
            (*faces)[t] = f;
        }
        first += mesh->face_size[f];
    }
    return total;
}

/* The library counts faces and vertices from 0, as C arrays do; an OBJ file
   counts them from 1 and a user finds them by line. Say it the file's way,
   from the error's fields. */
int obj_report_mesh_error(const char *obj_path, const obj_mesh *obj, const tt_error *error, int offer_permissive)
{
    int face = error->face, vertex = error->vertex, other = error->other_vertex;
    int line = face >= 0 && face < obj->nfaces ? obj->face_line[face]
             : vertex >= 0 && vertex < obj->nverts ? obj->vert_line[vertex] : 0;
    const char *or_permissive = offer_permissive ? " (or use --permissive)" : "";
    char where[4096];
    if (line > 0) snprintf(where, sizeof where, "%s:%d", obj_path, line);
    else snprintf(where, sizeof where, "%s", obj_path);
    switch (error->result) {
    case TT_ERROR_NON_FINITE:
        return tool_fail("%s: vertex %d has a coordinate that is NaN or infinite", where, vertex + 1);
    case TT_ERROR_REPEATED_VERTEX:
        return tool_fail("%s: face %d uses vertex %d twice%s", where, face + 1, vertex + 1, or_permissive);
    case TT_ERROR_ZERO_AREA_FACE:
        return tool_fail("%s: face %d has zero area: its corners coincide or lie on one line%s", where, face + 1,
                         or_permissive);
    case TT_ERROR_NON_MANIFOLD_EDGE:
        return tool_fail("%s: the edge between vertices %d and %d is shared by more than two faces (face %d and "
                         "face %d among them)%s",
                         where, vertex + 1, other + 1, face + 1, error->other_face + 1,
                         offer_permissive ? "; --permissive cuts it open" : "");
    case TT_ERROR_INCONSISTENT_ORIENTATION:
        return tool_fail("%s: faces %d and %d both run from vertex %d to vertex %d: one of them is flipped "
                         "(fix its winding%s)",
                         where, face + 1, error->other_face + 1, vertex + 1, other + 1,
                         offer_permissive ? ", or use --permissive" : "");
    case TT_ERROR_NON_MANIFOLD_VERTEX:
        return tool_fail("%s: vertex %d is non-manifold: surfaces touch at that one point%s",
                         vertex >= 0 && vertex < obj->nverts ? where : obj_path, vertex + 1, or_permissive);
    default:
        return tool_fail("%s: %s", obj_path, error->message);
    }
}

void obj_free(obj_mesh *mesh)
{
    int g;
    if (!mesh) return;
    free(mesh->pos);
    free(mesh->face_size);
    free(mesh->corner_vert);
    free(mesh->uv);
    free(mesh->corner_uv);
    free(mesh->face_group);
    free(mesh->face_line);
    free(mesh->vert_line);
    for (g = 0; g < mesh->ngroups; g++) free(mesh->group_names[g]);
    free(mesh->group_names);
    free(mesh->mtllib);
    memset(mesh, 0, sizeof *mesh);
}

/* ======================================================================== */
/* OBJ and MTL writing                                                      */
/* ======================================================================== */

/* "KEYWORD NAME" and a newline. A name ending in '\\' gets a blank after it,
   or the reader would take the backslash for a line continuation. */
static void write_name_line(tool_buffer *out, const char *keyword, const char *name)
{
    size_t length = strlen(name);
    buffer_printf(out, "%s %s%s\n", keyword, name, length > 0 && name[length - 1] == '\\' ? " " : "");
}

int obj_write(tool_buffer *out, const obj_write_desc *desc)
{
    int v, f, c = 0, previous_group = -1;
    if (!desc || desc->nverts < 0 || desc->nfaces < 0 || (desc->nverts > 0 && !desc->pos) ||
        (desc->nfaces > 0 && !desc->corner_vert) || (!desc->face_size && desc->fixed_face_size < 3 && desc->nfaces > 0))
        return -1;
    if (desc->face_group && (desc->ngroups <= 0 || !desc->group_names)) return -1;

    if (desc->comment) {
        const char *line = desc->comment;
        while (*line) {
            const char *newline = strchr(line, '\n');
            size_t length = newline ? (size_t)(newline - line) : strlen(line);
            buffer_printf(out, "# %.*s\n", (int)length, line);
            line += length + (newline ? 1 : 0);
        }
    }
    if (desc->mtllib) write_name_line(out, "mtllib", desc->mtllib);

    /* %.9g: nine significant digits are enough for any float to read back
       exactly, so writing a mesh and reading it again changes nothing. */
    for (v = 0; v < desc->nverts; v++)
        buffer_printf(out, "v %.9g %.9g %.9g\n", desc->pos[3 * v], desc->pos[3 * v + 1], desc->pos[3 * v + 2]);

    if (desc->corner_uv) {
        /* One vt per face corner, in corner order: corner c uses vt c + 1. */
        int ncorners = 0;
        for (f = 0; f < desc->nfaces; f++) ncorners += desc->face_size ? desc->face_size[f] : desc->fixed_face_size;
        for (c = 0; c < ncorners; c++)
            buffer_printf(out, "vt %.9g %.9g\n", desc->corner_uv[2 * c], desc->corner_uv[2 * c + 1]);
        c = 0;
    }

    if (desc->material && !(desc->face_group && desc->group_materials)) write_name_line(out, "usemtl", desc->material);
    for (f = 0; f < desc->nfaces; f++) {
        int size = desc->face_size ? desc->face_size[f] : desc->fixed_face_size, i;
        if (size < 3) return -1;
        if (desc->face_group) {
            int group = desc->face_group[f];
            if (group < 0 || group >= desc->ngroups) return -1;
            if (group != previous_group) {
                write_name_line(out, "g", desc->group_names[group]);
                if (desc->group_materials && desc->group_materials[group])
                    write_name_line(out, "usemtl", desc->group_materials[group]);
                previous_group = group;
            }
        }
        buffer_append(out, "f", 1);
        for (i = 0; i < size; i++, c++) {
            int vertex = desc->corner_vert[c];
            if (vertex < 0 || vertex >= desc->nverts) return -1;
            if (desc->corner_uv) buffer_printf(out, " %d/%d", vertex + 1, c + 1);
            else buffer_printf(out, " %d", vertex + 1);
        }
        buffer_append(out, "\n", 1);
    }
    return out->failed ? -1 : 0;
}

void mtl_add_material(tool_buffer *out, const char *name, const char *texture, int texture_alpha)
{
    write_name_line(out, "newmtl", name);
    buffer_printf(out, "Ka 1 1 1\nKd 1 1 1\nKs 0 0 0\nd 1\nillum 1\n");
    if (texture) write_name_line(out, "map_Kd", texture);
    if (texture && texture_alpha) write_name_line(out, "map_d", texture);
    buffer_printf(out, "\n");
}
