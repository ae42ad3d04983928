/* tool_io.c - the plumbing every `tiledtex` subcommand shares: error lines,
   reading files, growing byte buffers, paths, atomic output, and progress
   on a terminal.
   See tool.h for the interface. Command-line parsing is in cli.c, images in
   image_io.c, OBJ / MTL in obj.c. */

#define _XOPEN_SOURCE 700          /* open, fdopen, fileno, stat, isatty, clock_gettime, realpath */

#include <ctype.h>
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <dirent.h>
#include <pthread.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <unistd.h>

#include "tool.h"

/* ======================================================================== */
/* Errors                                                                   */
/* ======================================================================== */

/* The tool is a single-threaded program, so one static "current command" is
   simpler than threading the name through every helper. */
static const char *tool_command_name = NULL;

void tool_set_command(const char *name) { tool_command_name = name; }
const char *tool_command(void) { return tool_command_name; }

/* --quiet, set once by main like the command name above; and whether the
   standard output carries the command's one output file, which silences
   the summary but not the notes on stderr. */
static int tool_quiet_flag = 0;
static int tool_stdout_taken = 0;

void tool_set_quiet(int quiet) { tool_quiet_flag = quiet; }
int tool_quiet(void) { return tool_quiet_flag || tool_stdout_taken; }

static void print_error_line(const char *prefix_command, const char *format, va_list args)
{
    /* Format into a buffer first so the line reaches stderr in one piece, and
       so a newline inside the message cannot split it into several lines. */
    char message[1024];
    char *c;
    tool_progress_clear();
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

#define MAX_NOTES 16
static char tool_notes[MAX_NOTES][TOOL_ERROR_SIZE];
static int tool_note_count = 0;

void tool_note(const char *format, ...)
{
    va_list args;
    if (tool_note_count == MAX_NOTES) return;
    va_start(args, format);
    vsnprintf(tool_notes[tool_note_count], sizeof tool_notes[0], format, args);
    va_end(args);
    tool_note_count++;
}

void tool_print_notes(void)
{
    int i;
    tool_progress_clear();
    for (i = 0; i < tool_note_count && !tool_quiet_flag; i++) {
        char *c;
        for (c = tool_notes[i]; *c; c++)
            if (*c == '\n' || *c == '\r') *c = ' ';
        fprintf(stderr, "%s: %s\n", TOOL_NAME, tool_notes[i]);
    }
    tool_note_count = 0;
}

/* Fill a caller's error buffer (which may be NULL). */
void tool_set_error(char *err, size_t err_size, const char *format, ...)
{
    va_list args;
    if (!err || err_size == 0) return;
    va_start(args, format);
    vsnprintf(err, err_size, format, args);
    va_end(args);
}

/* ======================================================================== */
/* Files and byte buffers                                                   */
/* ======================================================================== */

/* Make room for `extra` more bytes (plus a NUL we always keep after the data,
   so text in a buffer can be handed to C string functions). */
/* Bytes to the buffer's sink; a failed write fails the buffer. */
static int buffer_write_out(tool_buffer *buffer, const void *bytes, size_t count)
{
    errno = 0;
    if (count > 0 && fwrite(bytes, 1, count, buffer->sink) != count) {
        buffer->sink_error = errno ? errno : EIO;
        buffer->failed = 1;
        return -1;
    }
    return 0;
}

static int buffer_reserve(tool_buffer *buffer, size_t extra)
{
    size_t needed, capacity;
    char *grown;
    if (buffer->failed) return -1;
    if (extra > SIZE_MAX - 1 - buffer->size) { buffer->failed = 1; return -1; }
    needed = buffer->size + extra + 1;
    if (needed <= buffer->capacity) return 0;
    if (buffer->sink && buffer->size > 0) {
        if (buffer_write_out(buffer, buffer->data, buffer->size) != 0) return -1;
        buffer->size = 0;
        needed = extra + 1;
        if (needed <= buffer->capacity) return 0;
    }
    capacity = buffer->capacity ? buffer->capacity : buffer->sink ? TOOL_STREAM_CHUNK : 4096;
    while (capacity < needed) capacity = capacity > SIZE_MAX / 2 ? needed : capacity * 2;
    grown = (char *)realloc(buffer->data, capacity);
    if (!grown) { buffer->failed = 1; return -1; }
    buffer->data = grown;
    buffer->capacity = capacity;
    return 0;
}

char *buffer_room(tool_buffer *buffer, size_t count)
{
    return buffer_reserve(buffer, count) != 0 ? NULL : buffer->data + buffer->size;
}

void buffer_wrote(tool_buffer *buffer, size_t count)
{
    if (buffer->failed) return;
    buffer->size += count;
    buffer->data[buffer->size] = '\0';
}

void buffer_append(tool_buffer *buffer, const void *bytes, size_t count)
{
    char *room;
    if (buffer->sink && count >= TOOL_STREAM_CHUNK && !buffer->failed) {
        /* Written as it is, after what the buffer holds: no copy. */
        if (buffer_write_out(buffer, buffer->data, buffer->size) == 0) buffer_write_out(buffer, bytes, count);
        buffer->size = 0;
        return;
    }
    room = buffer_room(buffer, count);
    if (!room) return;
    if (count) memcpy(room, bytes, count);
    buffer_wrote(buffer, count);
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

/* Every file read so far, by device and inode, so that no output can replace
   one (output_commit checks). */
typedef struct input_file {
    dev_t device;
    ino_t inode;
    char *path;
} input_file;
static input_file *tool_inputs = NULL;
static int tool_input_count = 0, tool_input_capacity = 0;

static void remember_input(FILE *file, const char *path)
{
    struct stat info;
    if (fstat(fileno(file), &info) != 0 || !S_ISREG(info.st_mode)) return;   /* pipes cannot be overwritten */
    if (tool_input_count == tool_input_capacity) {
        int capacity = tool_input_capacity ? 2 * tool_input_capacity : 8;
        input_file *grown = (input_file *)realloc(tool_inputs, (size_t)capacity * sizeof *grown);
        if (!grown) return;
        tool_inputs = grown;
        tool_input_capacity = capacity;
    }
    tool_inputs[tool_input_count].path = tool_copy_string(path, strlen(path));
    if (!tool_inputs[tool_input_count].path) return;
    tool_inputs[tool_input_count].device = info.st_dev;
    tool_inputs[tool_input_count].inode = info.st_ino;
    tool_input_count++;
}

/* The directory part of `path` with its slash ("out/" for "out/m.obj"), or
   "./" for a bare name: malloc'd, NULL when out of memory. */
static char *directory_of(const char *path)
{
    const char *slash = strrchr(path, '/');
    size_t length = slash ? (size_t)(slash - path) + 1 : 0;
    char *directory = (char *)malloc(length + 3);
    if (!directory) return NULL;
    if (slash) {
        memcpy(directory, path, length);
        directory[length] = '\0';
    } else {
        strcpy(directory, "./");
    }
    return directory;
}

/* A path that does not exist yet can still not be written: its folder is
   missing or closed to this user. Said before a long run rather than after
   it. */
static int check_output_directory(const char *path, char *err, size_t err_size)
{
    struct stat info;
    char *directory = directory_of(path);
    int status = 0;
    if (!directory) return 0;                   /* the write itself will say */
    if (stat(directory, &info) != 0 || !S_ISDIR(info.st_mode)) {
        tool_set_error(err, err_size, "cannot write '%s': there is no folder '%s'", path, directory);
        status = -1;
    } else if (access(directory, W_OK | X_OK) != 0) {
        tool_set_error(err, err_size, "cannot write '%s': the folder '%s': %s", path, directory, strerror(errno));
        status = -1;
    }
    free(directory);
    return status;
}

int tool_check_output_path(const char *path, char *err, size_t err_size)
{
    struct stat info;
    int i;
    if (strcmp(path, "-") == 0) return 0;      /* standard output: never a file on disk */
    if (stat(path, &info) != 0) return check_output_directory(path, err, err_size); /* cannot be an input */
    if (S_ISDIR(info.st_mode)) {
        tool_set_error(err, err_size, "cannot write '%s': it is a directory", path);
        return -1;
    }
    for (i = 0; i < tool_input_count; i++) {
        if (tool_inputs[i].device == info.st_dev && tool_inputs[i].inode == info.st_ino) {
            if (strcmp(tool_inputs[i].path, "-") == 0)
                tool_set_error(err, err_size, "will not overwrite '%s': it is the standard input; choose another "
                               "output name", path);
            else if (strcmp(tool_inputs[i].path, path) == 0)
                tool_set_error(err, err_size, "will not overwrite the input '%s' with an output; choose another "
                               "output name", path);
            else
                tool_set_error(err, err_size, "will not overwrite '%s': it is the input '%s'; choose another "
                               "output name", path, tool_inputs[i].path);
            return -1;
        }
    }
    return 0;
}

int tool_same_file(const char *a, const char *b)
{
    struct stat info_a, info_b;
    return stat(a, &info_a) == 0 && stat(b, &info_b) == 0 && info_a.st_dev == info_b.st_dev &&
           info_a.st_ino == info_b.st_ino;
}

int tool_refuse_input_overwrite(const char *path)
{
    char message[TOOL_ERROR_SIZE];
    if (tool_check_output_path(path, message, sizeof message) != 0) return tool_fail("%s", message);
    return 0;
}

void tool_forget_inputs(void)
{
    int i;
    for (i = 0; i < tool_input_count; i++) free(tool_inputs[i].path);
    free(tool_inputs);
    tool_inputs = NULL;
    tool_input_count = tool_input_capacity = 0;
}

int tool_read_file(const char *path, unsigned char **data, size_t *size, char *err, size_t err_size)
{
    tool_buffer buffer = TOOL_BUFFER_INIT;
    FILE *file;
    int from_stdin = strcmp(path, "-") == 0;
    *data = NULL;
    *size = 0;
    file = from_stdin ? stdin : fopen(path, "rb");
    if (!file) {
        tool_set_error(err, err_size, "cannot open '%s': %s", path, strerror(errno));
        return -1;
    }
    /* Read in chunks rather than asking for the file's size: that also works
       for pipes and standard input. */
    for (;;) {
        size_t got;
        if (buffer_reserve(&buffer, 65536) != 0) {
            tool_set_error(err, err_size, "'%s' is too large to read into memory", path);
            break;
        }
        got = fread(buffer.data + buffer.size, 1, buffer.capacity - buffer.size - 1, file);
        buffer.size += got;
        if (got == 0) break;
    }
    if (!buffer.failed && ferror(file)) {
        tool_set_error(err, err_size, "cannot read '%s': %s", path, strerror(errno));
        buffer.failed = 1;
    }
    if (!buffer.failed) remember_input(file, path);
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

/* The relative path from from_file's directory to target, both relative
   to the same directory or both absolute. Returns how many directories the
   two share at the start, with *ups the "../" steps the path then climbs;
   or -1 when from_file's directory climbs with ".." after the parts they
   share (the way back down cannot be named from the text alone). */
static int relative_path_between(const char *target, const char *from_file, char *out, size_t out_size, int *ups)
{
    /* Directory parts of both, as text ranges; "." parts are skipped. */
    const char *from_end = tool_basename(from_file), *target_name = tool_basename(target);
    const char *f = from_file, *t = target;
    size_t used = 0;
    int shared = 0, steps;
    *ups = 0;
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
        shared++;
    }
    /* Every directory left on the file's side is one step up. */
    while (f < from_end) {
        const char *fe = f;
        while (fe < from_end && *fe != '/') fe++;
        if (fe - f == 2 && f[0] == '.' && f[1] == '.') return -1;
        if (fe > f && !(fe - f == 1 && f[0] == '.')) (*ups)++;
        f = fe;
        while (f < from_end && *f == '/') f++;
    }
    out[0] = '\0';
    for (steps = *ups; steps > 0 && used + 3 < out_size; steps--) {
        memcpy(out + used, "../", 3);
        used += 3;
    }
    snprintf(out + used, out_size - used, "%s", t);
    return shared;
}

/* A path from the root, through the file system: its directory's real path
   and its name, so that a file not written yet resolves too. Malloc'ed;
   NULL when the directory does not resolve. */
static char *resolve_path(const char *path)
{
    const char *name = tool_basename(path);
    char *directory = tool_copy_string(path, (size_t)(name - path)), *real = NULL, *resolved = NULL;
    if (directory) real = realpath(directory[0] ? directory : ".", NULL);
    if (real) {
        size_t length = strlen(real);
        resolved = (char *)malloc(length + strlen(name) + 2);
        if (resolved) sprintf(resolved, "%s%s%s", real, real[length - 1] == '/' ? "" : "/", name);
    }
    free(real);
    free(directory);
    return resolved;
}

void tool_relative_path(const char *target, const char *from_file, char *out, size_t out_size)
{
    char *resolved_target = NULL, *resolved_file = NULL;
    const char *named = target;
    int shared = -1, ups = 0;
    if ((target[0] == '/') == (from_file[0] == '/'))
        shared = relative_path_between(target, from_file, out, out_size, &ups);
    if (shared < 0) {
        /* One path is absolute and the other is not, or from_file's
           directory climbs out of the current one ("../out/a.mtl"): ask the
           file system where both are. Target's directory exists (it was
           read, or is being written) and so does the file's; when either
           cannot be resolved, target's absolute path, or target as given,
           is the best left. */
        resolved_target = resolve_path(target);
        resolved_file = resolve_path(from_file);
        if (resolved_target) named = resolved_target;
        if (resolved_target && resolved_file)
            shared = relative_path_between(resolved_target, resolved_file, out, out_size, &ups);
    }
    /* Absolute paths that share nothing but the root: the way up to it breaks
       as soon as the folder moves, where the absolute path still names the
       file. */
    if (shared < 0 || (named[0] == '/' && shared == 0 && ups > 0)) snprintf(out, out_size, "%s", named);
    free(resolved_target);
    free(resolved_file);
}

void tool_path_beside(const char *name, const char *from_file, char *out, size_t out_size)
{
    const char *directory_end = tool_basename(from_file);
    if (name[0] == '/' || directory_end == from_file) snprintf(out, out_size, "%s", name);
    else snprintf(out, out_size, "%.*s%s", (int)(directory_end - from_file), from_file, name);
}

const char *tool_basename(const char *path)
{
    const char *base = path, *p;
    for (p = path; *p; p++)
        if (*p == '/' || *p == '\\') base = p + 1;
    return base;
}

int tool_has_extension(const char *path, const char *extension)
{
    size_t length = strlen(path), n = strlen(extension), i;
    if (length < n) return 0;
    for (i = 0; i < n; i++)
        if (tolower((unsigned char)path[length - n + i]) != tolower((unsigned char)extension[i])) return 0;
    return 1;
}

char *tool_copy_string(const char *text, size_t length)
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
        tool_output_file *file = &output->files[i];
        if (strcmp(file->path, path) == 0) {   /* same file again: the new contents win */
            free(file->data);
            file->data = (unsigned char *)data;
            file->size = size;
            if (file->temporary) remove(file->temporary);
            free(file->temporary);
            file->temporary = NULL;
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
    path_copy = tool_copy_string(path, strlen(path));
    if (!path_copy) { free(data); return -1; }
    output->files[output->count].path = path_copy;
    output->files[output->count].data = (unsigned char *)data;
    output->files[output->count].size = size;
    output->files[output->count].temporary = NULL;
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

float *tool_corner_normals(const char *path, const tt_mesh *mesh, const float *carried)
{
    float *normals = (float *)malloc(3 * (size_t)(mesh->ncorners > 0 ? mesh->ncorners : 1) * sizeof(float));
    tt_error error;
    if (!normals) {
        tool_fail("out of memory for the normals of %s", path);
        return NULL;
    }
    if (carried) {
        int c, k;
        for (c = 0; c < mesh->ncorners; c++) {
            const float *n = carried + 3 * (size_t)c;
            double length = sqrt((double)n[0] * n[0] + (double)n[1] * n[1] + (double)n[2] * n[2]);
            /* Opposite normals averaged to nothing stay (0, 0, 0), as
               tt_corner_normals leaves a corner with nothing to average. */
            for (k = 0; k < 3; k++) normals[3 * (size_t)c + k] = length > 0.0 ? (float)(n[k] / length) : 0.0f;
        }
        return normals;
    }
    if (tt_corner_normals(mesh, TOOL_CREASE_DEGREES, NULL, normals, &error) != TT_OK) {
        tool_fail("%s: %s", path, error.message);
        free(normals);
        return NULL;
    }
    return normals;
}

int output_add_obj(tool_output *output, const char *path, const obj_write_desc *desc)
{
    tool_buffer text = TOOL_BUFFER_INIT;
    char err[TOOL_ERROR_SIZE];
    int written;
    tool_stage("writing %s", tool_basename(path));
    if (output_stream_begin(output, path, &text, err, sizeof err) != 0) return tool_fail("%s", err);
    written = obj_write(&text, desc);
    /* A failed write says why before the writer's own failure does. */
    if (output_stream_end(output, path, &text, err, sizeof err) != 0) return tool_fail("%s", err);
    if (written != 0) return tool_fail("out of memory while writing %s", path);
    return 0;
}

/* The names a commit gives its own files beside PATH: PATH.tiledtex-tmp-PID
   (with -N after it when taken) while a file is written, and
   PATH.tiledtex-old-PID for the previous run's file while it is being
   replaced. The process id tells a later run which of these a killed run
   left behind (its process is gone): those it removes. */
#define TEMPORARY_MARK ".tiledtex-tmp-"
#define BACKUP_MARK ".tiledtex-old-"
#define TEMPORARY_ATTEMPTS 100

/* Create a new temporary file beside `path` (an existing file or directory
   of that name is never opened, let alone removed). On success *name is the
   malloc'ed name of a file this call created, open in *file. */
static int create_temporary(const char *path, char **name, FILE **file)
{
    size_t length = strlen(path), size = length + sizeof TEMPORARY_MARK + 32;
    int attempt;
    *name = (char *)malloc(size);
    *file = NULL;
    if (!*name) { errno = ENOMEM; return -1; }
    for (attempt = 0; attempt < TEMPORARY_ATTEMPTS; attempt++) {
        int fd;
        if (attempt == 0) snprintf(*name, size, "%s%s%ld", path, TEMPORARY_MARK, (long)getpid());
        else snprintf(*name, size, "%s%s%ld-%d", path, TEMPORARY_MARK, (long)getpid(), attempt);
        fd = open(*name, O_WRONLY | O_CREAT | O_EXCL, 0666);
        if (fd >= 0) {
            *file = fdopen(fd, "wb");
            if (*file) return 0;
            close(fd);
            remove(*name);          /* ours: created just now */
            break;
        }
        if (errno != EEXIST) break;
    }
    if (attempt == TEMPORARY_ATTEMPTS) errno = EEXIST;
    free(*name);
    *name = NULL;
    return -1;
}

/* Write one file completely; any short write or failed close is an error
   (a full disk often shows up only at fclose). Closes the file. */
static int write_whole_file(FILE *file, const unsigned char *data, size_t size)
{
    int ok = (size == 0 || fwrite(data, 1, size, file) == size);
    ok = (fflush(file) == 0) && ok;
    ok = (fclose(file) == 0) && ok;
    return ok ? 0 : -1;
}

/* The one output file as the standard output ("-"). The summary a command
   prints next would land in the middle of the data, so it is silenced as if
   by --quiet. */
static int write_standard_output(const void *data, size_t size, char *err, size_t err_size)
{
    tool_stdout_taken = 1;
    if ((size > 0 && fwrite(data, 1, size, stdout) != size) || fflush(stdout) != 0) {
        tool_set_error(err, err_size, "cannot write to the standard output: %s", strerror(errno));
        return -1;
    }
    return 0;
}

/* Whether `entry` (a name in the directory of `path`) is one of the files a
   commit makes beside path (TEMPORARY_MARK or BACKUP_MARK and a process id,
   with an optional -N), left by a process that no longer runs. */
static int left_by_dead_run(const char *path, const char *entry)
{
    const char *base = strrchr(path, '/'), *rest, *marks[2];
    size_t length;
    int m;
    base = base ? base + 1 : path;
    length = strlen(base);
    if (strncmp(entry, base, length) != 0) return 0;
    marks[0] = TEMPORARY_MARK;
    marks[1] = BACKUP_MARK;
    for (m = 0; m < 2; m++) {
        char *end;
        long pid;
        size_t mark = strlen(marks[m]);
        if (strncmp(entry + length, marks[m], mark) != 0) continue;
        rest = entry + length + mark;
        if (*rest < '0' || *rest > '9') return 0;
        errno = 0;
        pid = strtol(rest, &end, 10);
        if (errno != 0 || pid <= 0 || (long)(pid_t)pid != pid) return 0;
        if (*end == '-') {
            if (end[1] < '0' || end[1] > '9') return 0;
            strtol(end + 1, &end, 10);
        }
        if (*end != '\0') return 0;
        if ((pid_t)pid == getpid()) return 0;
        return kill((pid_t)pid, 0) != 0 && errno == ESRCH;
    }
    return 0;
}

/* Remove what killed runs left beside `path`: their temporaries (a
   kill -9 while writing) and the previous files they had moved aside.
   Only regular files of exactly those names go. */
static void remove_leftovers(const char *path)
{
    char *directory = directory_of(path);
    size_t dir_length;
    DIR *dir;
    struct dirent *entry;
    if (!directory) return;
    dir_length = strlen(directory);
    dir = opendir(directory);
    while (dir && (entry = readdir(dir)) != NULL) {
        struct stat info;
        char *full;
        if (!left_by_dead_run(path, entry->d_name)) continue;
        full = (char *)malloc(dir_length + strlen(entry->d_name) + 1);
        if (!full) break;
        memcpy(full, directory, dir_length);
        strcpy(full + dir_length, entry->d_name);
        if (lstat(full, &info) == 0 && S_ISREG(info.st_mode)) remove(full);
        free(full);
    }
    if (dir) closedir(dir);
    free(directory);
}

/* The file that says a run is complete: the model (OBJ, GLB, glTF). It is
   renamed into place last, and its previous version moved aside first, so
   whenever a model file is present, the files it names are from its run. */
static int is_model_file(const char *path)
{
    static const char *const endings[] = {".obj", ".glb", ".gltf"};
    size_t length = strlen(path), i;
    for (i = 0; i < sizeof endings / sizeof endings[0]; i++) {
        size_t n = strlen(endings[i]);
        if (length >= n && strcmp(path + length - n, endings[i]) == 0) return 1;
    }
    return 0;
}

/* Per file of a commit: its temporary, the previous file's backup name
   (when there was one), and whether the new file is in place. */
typedef struct commit_file {
    char *temporary;
    char *backup;
    int linked;         /* the backup is a second link: the previous file is still at its name too */
    int placed;
} commit_file;

/* Move the existing file at `path` (if any) aside to its backup name: a
   hard link where the file system has them, so the previous file stays at
   its name until the new one replaces it in one rename; otherwise a rename. */
static int back_up(const char *path, commit_file *file, int move_aside)
{
    struct stat info;
    size_t size = strlen(path) + sizeof BACKUP_MARK + 24;
    if (lstat(path, &info) != 0) return errno == ENOENT ? 0 : -1;
    file->backup = (char *)malloc(size);
    if (!file->backup) { errno = ENOMEM; return -1; }
    snprintf(file->backup, size, "%s%s%ld", path, BACKUP_MARK, (long)getpid());
    remove(file->backup);       /* ours: this process's name */
    if (!move_aside && link(path, file->backup) == 0) {
        file->linked = 1;
        return 0;
    }
    if (rename(path, file->backup) == 0) return 0;
    free(file->backup);
    file->backup = NULL;
    return -1;
}

/* What output_commit refuses before writing anything: a path naming a
   directory, or the same file as one of the command's inputs. */
static int check_output(const char *path, char *err, size_t err_size)
{
    size_t length = strlen(path);
    if (length == 0 || path[length - 1] == '/') {
        tool_set_error(err, err_size, "'%s' names a directory: give a file name", path);
        return -1;
    }
    return tool_check_output_path(path, err, err_size);
}

int output_stream_begin(tool_output *output, const char *path, tool_buffer *buffer, char *err, size_t err_size)
{
    char *temporary;
    FILE *stream;
    int i;
    if (strcmp(path, "-") == 0) return 0;
    if (check_output(path, err, err_size) != 0) return -1;
    if (create_temporary(path, &temporary, &stream) != 0) {
        tool_set_error(err, err_size, "cannot write '%s': %s", path, strerror(errno));
        return -1;
    }
    if (output_add(output, path, NULL, 0) != 0) {
        fclose(stream);
        remove(temporary);
        free(temporary);
        tool_set_error(err, err_size, "out of memory while writing %s", path);
        return -1;
    }
    for (i = 0; strcmp(output->files[i].path, path) != 0; i++) continue;
    output->files[i].temporary = temporary;
    buffer->sink = stream;
    return 0;
}

int output_stream_end(tool_output *output, const char *path, tool_buffer *buffer, char *err, size_t err_size)
{
    FILE *stream = buffer->sink;
    int failed, error;
    if (!stream) {
        if (output_add_buffer(output, path, buffer) == 0) return 0;
        tool_set_error(err, err_size, "out of memory while writing %s", path);
        return -1;
    }
    if (!buffer->failed) buffer_write_out(buffer, buffer->data, buffer->size);
    failed = buffer->failed;
    error = buffer->sink_error;
    /* A full disk often shows up only when the file is closed. */
    if (fflush(stream) != 0 && !failed) {
        failed = 1;
        error = errno ? errno : EIO;
    }
    if (fclose(stream) != 0 && !failed) {
        failed = 1;
        error = errno ? errno : EIO;
    }
    buffer_free(buffer);
    if (failed && error) tool_set_error(err, err_size, "cannot write '%s': %s", path, strerror(error));
    else if (failed) tool_set_error(err, err_size, "out of memory while writing %s", path);
    return failed ? -1 : 0;
}

static int commit_files(tool_output *output, char *err, size_t err_size)
{
    commit_file *files;
    int *order, i, k, failed = 0;
    if (output->count <= 0) return 0;
    for (i = 0; i < output->count; i++) {
        if (strcmp(output->files[i].path, "-") != 0) continue;
        /* Commands refuse "-" on their command line when they write several
           files; this is the backstop, so that no file called "-" appears. */
        if (output->count != 1) {
            tool_set_error(err, err_size, "'-' (standard output) can take only one file, and this command writes %d",
                           output->count);
            return -1;
        }
        return write_standard_output(output->files[0].data, output->files[0].size, err, err_size);
    }
    /* Before anything is written: no output may name a directory, or the
       same file as one of the command's inputs. */
    for (i = 0; i < output->count; i++)
        if (check_output(output->files[i].path, err, err_size) != 0) return -1;
    for (i = 0; i < output->count; i++) remove_leftovers(output->files[i].path);
    files = (commit_file *)calloc((unsigned)output->count, sizeof *files);
    order = (int *)calloc((unsigned)output->count, sizeof *order);
    if (!files || !order) {
        free(files);
        free(order);
        tool_set_error(err, err_size, "out of memory while writing the output files");
        return -1;
    }
    /* The model files last, the others in the order they were added. */
    for (i = 0, k = 0; i < output->count; i++)
        if (!is_model_file(output->files[i].path)) order[k++] = i;
    for (i = 0; i < output->count; i++)
        if (is_model_file(output->files[i].path)) order[k++] = i;
    /* Phase 1: every file to a temporary name beside the real one (the same
       directory, so the renames below cannot cross file systems). */
    for (i = 0; i < output->count && !failed; i++) {
        tool_output_file *file = &output->files[i];
        FILE *stream;
        if (file->temporary) {      /* streamed: written already */
            files[i].temporary = file->temporary;
            file->temporary = NULL;
            continue;
        }
        if (create_temporary(file->path, &files[i].temporary, &stream) != 0 ||
            write_whole_file(stream, file->data, file->size) != 0) {
            tool_set_error(err, err_size, "cannot write '%s': %s", file->path, strerror(errno));
            failed = 1;
        }
    }
    /* Phase 2, only when all are complete: the previous model files move
       aside first (from here until the end, no model file is present that
       does not go with the files beside it), then each file takes its name,
       the previous one kept under its backup name. */
    for (i = 0; i < output->count && !failed; i++)
        if (is_model_file(output->files[i].path) && back_up(output->files[i].path, &files[i], 1) != 0) {
            tool_set_error(err, err_size, "cannot replace '%s': %s", output->files[i].path, strerror(errno));
            failed = 1;
        }
    for (k = 0; k < output->count && !failed; k++) {
        const char *path = output->files[order[k]].path;
        commit_file *file = &files[order[k]];
        if (!file->backup && !is_model_file(path) && back_up(path, file, 0) != 0) {
            tool_set_error(err, err_size, "cannot replace '%s': %s", path, strerror(errno));
            failed = 1;
        } else if (rename(file->temporary, path) != 0) {
            tool_set_error(err, err_size, "cannot write '%s': %s", path, strerror(errno));
            failed = 1;
        } else {
            free(file->temporary);
            file->temporary = NULL;
            file->placed = 1;
        }
    }
    for (i = 0; i < output->count; i++) {
        commit_file *file = &files[i];
        const char *path = output->files[i].path;
        if (file->temporary) remove(file->temporary);
        if (failed) {
            /* Undo: the previous file back at its name (over the new one),
               or, where there was none, the new file removed. A linked
               backup of a file not yet replaced is only a second name. */
            if (file->backup && file->linked && !file->placed) remove(file->backup);
            else if (file->backup) rename(file->backup, path);
            else if (file->placed) remove(path);
        } else if (file->backup) {
            remove(file->backup);
        }
        free(file->temporary);
        free(file->backup);
    }
    free(files);
    free(order);
    return failed ? -1 : 0;
}

int output_commit(tool_output *output, char *err, size_t err_size)
{
    int status;
    tool_stage("saving %d file%s", output->count, output->count == 1 ? "" : "s");
    status = commit_files(output, err, err_size);
    /* the summary comes next, on a clean line */
    tool_progress_clear();
    return status;
}

void output_free(tool_output *output)
{
    int i;
    for (i = 0; i < output->count; i++) {
        free(output->files[i].path);
        free(output->files[i].data);
        /* A streamed file never committed. */
        if (output->files[i].temporary) remove(output->files[i].temporary);
        free(output->files[i].temporary);
    }
    free(output->files);
    memset(output, 0, sizeof *output);
}

/* ======================================================================== */
/* Time and progress on a terminal                                          */
/* ======================================================================== */

double tool_seconds_now(void)
{
    struct timespec now;
    clock_gettime(CLOCK_MONOTONIC, &now);
    return (double)now.tv_sec + 1e-9 * (double)now.tv_nsec;
}

double tool_cpu_seconds_now(void)
{
    struct timespec used;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &used);
    return (double)used.tv_sec + 1e-9 * (double)used.tv_nsec;
}

/* Ctrl-C (SIGINT) or SIGTERM during a library call that takes a progress
   callback cancels it through that callback: the call returns TT_CANCELLED
   with everything freed, the command fails with one line, and no output
   is written. Outside such a call the signal does what it always does
   (the output commit's temporary files are removed by the next run). */
static volatile sig_atomic_t interrupt_requested, progress_active;

static void on_interrupt(int signal_number)
{
    if (!progress_active) {
        signal(signal_number, SIG_DFL);
        raise(signal_number);
        return;
    }
    interrupt_requested = 1;
}

void tool_catch_interrupts(void)
{
    struct sigaction action;
    memset(&action, 0, sizeof action);
    action.sa_handler = on_interrupt;
    sigemptyset(&action.sa_mask);
    sigaction(SIGINT, &action, NULL);
    sigaction(SIGTERM, &action, NULL);
}

int tool_interrupted(void) { return interrupt_requested != 0; }

/* The progress line (see tool.h): one per command, so a static like the
   command name above. A library call may run for seconds between two of
   its progress callbacks (a polycube's smoothing, hpm's hierarchy), so on
   a terminal a thread of the tool redraws the line once a second with the
   seconds the stage has taken; the lock keeps its redraws and the
   command's own (which library callbacks may make from any thread) from
   mixing, and from drawing over an erased line. */
#define PROGRESS_DELAY 0.5     /* seconds before the first line */
#define PROGRESS_INTERVAL 0.1  /* seconds between redraws of one stage */
#define PROGRESS_HEARTBEAT 0.8 /* seconds: redrawn at least once a second while a stage lasts */
static pthread_mutex_t progress_lock = PTHREAD_MUTEX_INITIALIZER;
static struct {
    double start, last;     /* seconds: the command's start, the last redraw */
    double stage_start;
    int terminal;           /* stderr is a terminal and not -q */
    int width;              /* characters of the line on screen, 0 = none */
    int drawn;              /* this stage was drawn */
    char stage[160];        /* "" between stages: nothing to draw */
    double done;            /* the stage's fraction, or -1: unknown */
    const char *what;
} progress_line;

/* Under progress_lock. */
static void progress_draw(int heartbeat)
{
    char text[256];
    int n, pad, seconds;
    double now = tool_seconds_now();
    if (!progress_line.terminal || !progress_line.stage[0] || now - progress_line.start < PROGRESS_DELAY) return;
    if (progress_line.drawn && now - progress_line.last < (heartbeat ? PROGRESS_HEARTBEAT : PROGRESS_INTERVAL))
        return;
    if (progress_line.done >= 0.0)
        n = snprintf(text, sizeof text, "%s: %s: %5.1f%%%s%s", TOOL_NAME, progress_line.stage,
                     100.0 * fmin(progress_line.done, 0.999), progress_line.what ? " " : "",
                     progress_line.what ? progress_line.what : "");
    else
        n = snprintf(text, sizeof text, "%s: %s", TOOL_NAME, progress_line.stage);
    seconds = (int)(now - progress_line.stage_start);
    if (n >= 0 && n < (int)sizeof text && seconds >= 1)
        n += snprintf(text + n, sizeof text - (size_t)n, " (%d s)", seconds);
    if (n < 0) return;
    if (n >= (int)sizeof text) n = (int)sizeof text - 1;
    /* spaces over what is left of a longer line before */
    pad = progress_line.width > n ? progress_line.width - n : 0;
    fprintf(stderr, "\r%s%*s", text, pad, "");
    if (pad > 0) fprintf(stderr, "\r%s", text);
    fflush(stderr);
    progress_line.width = n;
    progress_line.drawn = 1;
    progress_line.last = now;
}

static void *progress_heartbeat(void *unused)
{
    struct timespec pause = {0, 200000000};
    (void)unused;
    for (;;) {
        nanosleep(&pause, NULL);
        pthread_mutex_lock(&progress_lock);
        progress_draw(1);
        pthread_mutex_unlock(&progress_lock);
    }
    return NULL;
}

void tool_progress_start(void)
{
    pthread_t thread;
    pthread_attr_t attributes;
    memset(&progress_line, 0, sizeof progress_line);
    progress_line.start = progress_line.stage_start = tool_seconds_now();
    progress_line.terminal = !tool_quiet() && isatty(STDERR_FILENO);
    progress_line.done = -1.0;
    if (!progress_line.terminal) return;
    /* Detached: it sleeps until the process ends. Without it (no thread to
       be had) the line is drawn only by the command's own calls. */
    if (pthread_attr_init(&attributes) != 0) return;
    pthread_attr_setdetachstate(&attributes, PTHREAD_CREATE_DETACHED);
    pthread_create(&thread, &attributes, progress_heartbeat, NULL);
    pthread_attr_destroy(&attributes);
}

void tool_stage(const char *format, ...)
{
    va_list args;
    pthread_mutex_lock(&progress_lock);
    va_start(args, format);
    vsnprintf(progress_line.stage, sizeof progress_line.stage, format, args);
    va_end(args);
    progress_line.stage_start = tool_seconds_now();
    progress_line.done = -1.0;
    progress_line.what = NULL;
    progress_line.drawn = 0;
    progress_draw(0);
    pthread_mutex_unlock(&progress_lock);
}

void tool_stage_fraction(double done, const char *what)
{
    pthread_mutex_lock(&progress_lock);
    progress_line.done = done > 0.0 ? done : 0.0;
    progress_line.what = what;
    progress_draw(0);
    pthread_mutex_unlock(&progress_lock);
}

void tool_progress_clear(void)
{
    pthread_mutex_lock(&progress_lock);
    progress_line.stage[0] = '\0';
    if (progress_line.width > 0) {
        fprintf(stderr, "\r%*s\r", progress_line.width, "");
        fflush(stderr);
    }
    progress_line.width = 0;
    progress_line.drawn = 0;
    pthread_mutex_unlock(&progress_lock);
}

void tool_progress_begin(tool_progress *progress, const char *activity, const char *what)
{
    progress_active = 1;
    progress->activity = activity;
    progress->what = what;
    tool_stage("%s", activity);
}

int tool_show_progress(float fraction, void *user_data)
{
    tool_progress *progress = (tool_progress *)user_data;
    if (interrupt_requested) return 1;
    tool_stage_fraction((double)fraction, progress->what);
    return 0;
}

void tool_progress_end(tool_progress *progress)
{
    (void)progress;
    progress_active = 0;
}
