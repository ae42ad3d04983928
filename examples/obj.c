/* obj.c - Wavefront OBJ reading and writing, and MTL writing, for the
   `tiledtex` tool. See tool.h for the interface. */

#include <ctype.h>
#include <float.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tool.h"

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

/* A list of names (groups, materials) the mesh owns, with an open-
   addressing hash over it, so that a file with many names (one group per
   paste, say) stays linear-time. */
typedef struct name_index {
    char ***names;              /* the mesh's array */
    int *count;                 /* the mesh's count */
    int capacity;
    int *table;                 /* name index + 1, 0 = empty */
    int table_size;             /* a power of two, kept at least twice *count */
} name_index;

typedef struct obj_parser {
    const char *p, *end;        /* cursor over the text */
    int line;                   /* physical line of the cursor, 1-based */
    int statement_line;         /* line the current statement starts on */
    const char *statement;      /* its first byte, for quoting in messages */
    const char *source;         /* file name for messages, or NULL */
    char *err;
    size_t err_size;
    obj_mesh *mesh;
    int pos_capacity, vert_line_capacity, uv_capacity, uv_w_capacity, normal_capacity, face_capacity,
        corner_capacity;
    int current_group, current_material;
    name_index groups, materials;
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
        tool_set_error(P->err, P->err_size, "%s:%d: %s", P->source, P->statement_line, message);
    else
        tool_set_error(P->err, P->err_size, "line %d: %s", P->statement_line, message);
    return -1;
}

/* Lines end in "\n" (Unix), "\r\n" (Windows) or a lone "\r" (old Mac OS).
   Returns how many bytes the line end at p takes, 0 when p is not at one. */
static size_t line_end_length(const obj_parser *P, const char *p)
{
    if (p >= P->end) return 0;
    if (*p == '\n') return 1;
    if (*p == '\r') return (p + 1 < P->end && p[1] == '\n') ? 2 : 1;
    return 0;
}

/* The current statement as printable text for messages: its first line, at
   most 60 bytes, with control bytes and non-ASCII shown as '?'. */
static const char *quote_statement(const obj_parser *P, char *out, size_t out_size)
{
    const char *p = P->statement;
    size_t n = 0;
    while (p < P->end && !line_end_length(P, p) && n + 4 < out_size && n < 60) {
        unsigned char c = (unsigned char)*p++;
        out[n++] = (c >= 32 && c < 127) ? (char)c : '?';
    }
    if (p < P->end && !line_end_length(P, p)) {
        out[n++] = '.'; out[n++] = '.'; out[n++] = '.';
    }
    out[n] = '\0';
    return out;
}

static int out_of_memory(obj_parser *P)
{
    return obj_error(P, "out of memory");
}

/* Blanks between tokens ('\r' is a line end, see line_end_length). */
static int is_blank(char c)
{
    return c == ' ' || c == '\t' || c == '\v' || c == '\f';
}

/* A '\' right before the end of a line joins the next line to this one.
   Returns how many bytes the continuation takes (0 if there is none here). */
static size_t continuation_length(const obj_parser *P, const char *p)
{
    size_t newline;
    if (p >= P->end || *p != '\\') return 0;
    newline = line_end_length(P, p + 1);
    return newline ? 1 + newline : 0;
}

static void count_line(obj_parser *P)
{
    if (P->line < INT_MAX) P->line++;
}

/* Skip blanks and line continuations; stop at a line end, the end, or text. */
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
    return P->p >= P->end || line_end_length(P, P->p);
}

/* The next whitespace-separated token of the statement; length 0 at its end. */
static size_t next_token(obj_parser *P, const char **token)
{
    const char *start;
    skip_blanks(P);
    start = P->p;
    while (P->p < P->end && !is_blank(*P->p) && !line_end_length(P, P->p) && !continuation_length(P, P->p)) P->p++;
    *token = start;
    return (size_t)(P->p - start);
}

/* Move past the rest of the statement and its line end. */
static void finish_statement(obj_parser *P)
{
    while (P->p < P->end && !line_end_length(P, P->p)) {
        size_t joined = continuation_length(P, P->p);
        if (joined) { P->p += joined; count_line(P); }
        else P->p++;
    }
    if (P->p < P->end) { P->p += line_end_length(P, P->p); count_line(P); }
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
       message naming the vertex), as is a number beyond float range. */
    *out = tool_float_of(value);
    return 1;
}

/* The three numbers of a `v` or `vn` statement (`what` names it in the
   error: "a vertex"). Returns 0, or obj_error's status. */
static int read_three(obj_parser *P, const char *what, float xyz[3])
{
    int i;
    for (i = 0; i < 3; i++) {
        int got = read_number(P, &xyz[i]);
        if (got <= 0) {
            char quoted[80];
            quote_statement(P, quoted, sizeof quoted);
            return got < 0 ? obj_error(P, "cannot read a number in '%s'", quoted)
                           : obj_error(P, "%s needs 3 coordinates: '%s'", what, quoted);
        }
    }
    return 0;
}

static int parse_vertex(obj_parser *P)
{
    obj_mesh *mesh = P->mesh;
    float xyz[3];
    if (read_three(P, "a vertex", xyz) != 0) return -1;
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
    float uv[3] = {0.0f, 0.0f, 1.0f};   /* "vt u" alone means v = 0; w is 1 where absent (see uv_w) */
    int i, j;
    for (i = 0; i < 3; i++) {
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
    if (i == 3 || mesh->uv_w) {
        /* The first w: every vt before it had none, so 1. */
        int first = mesh->uv_w ? mesh->nuvs : 0;
        if (grow_array((void **)&mesh->uv_w, &P->uv_w_capacity, mesh->nuvs + 1, sizeof(float)) != 0)
            return out_of_memory(P);
        for (j = first; j < mesh->nuvs; j++) mesh->uv_w[j] = 1.0f;
        mesh->uv_w[mesh->nuvs] = uv[2];
    }
    mesh->nuvs++;
    return 0;
}

static int parse_normal(obj_parser *P)
{
    obj_mesh *mesh = P->mesh;
    float xyz[3];
    if (read_three(P, "a normal", xyz) != 0) return -1;
    if (mesh->nnormals >= OBJ_MAX_COUNT) return obj_error(P, "too many normals (at most %d)", OBJ_MAX_COUNT);
    if (grow_array((void **)&mesh->normal, &P->normal_capacity, (mesh->nnormals + 1) * 3, sizeof(float)) != 0)
        return out_of_memory(P);
    memcpy(mesh->normal + 3 * (size_t)mesh->nnormals, xyz, sizeof xyz);
    mesh->nnormals++;
    return 0;
}

/* A per-corner index array (corner_uv, corner_normal) made when the first
   corner with such an index comes: the corners before it had none (-1). It
   shares corner_vert's capacity. */
static int start_corner_indices(obj_parser *P, int **indices)
{
    int c;
    *indices = (int *)malloc((size_t)P->corner_capacity * sizeof(int));
    if (!*indices) return out_of_memory(P);
    for (c = 0; c < P->mesh->ncorners; c++) (*indices)[c] = -1;
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
        long long v_index, vt_index = 0, vn_index = 0;
        const char *vn_text = NULL;
        size_t v_length, vn_length = 0;
        int v_valid, vt_valid = 0, vn_valid = 0, vertex, uv = -1, normal = -1;
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
                vn_text = ++p;
                vn_length = read_index(p, token_end, &vn_index, &vn_valid);
                p += vn_length;
                /* "v/vt/" : no normal, tolerated as many readers do */
                if (!vn_valid && vn_length > 0) p = token;   /* force the error below */
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
        if (vn_valid && resolve_index(P, vn_index, mesh->nnormals, "normal", vn_text, vn_length, &normal) != 0)
            return -1;

        if (mesh->ncorners >= OBJ_MAX_COUNT) return obj_error(P, "too many face corners (at most %d)", OBJ_MAX_COUNT);
        if (mesh->ncorners == P->corner_capacity) {
            /* corner_vert, corner_uv and corner_normal (once they exist)
               share one capacity. */
            int capacity;
            if (grown_capacity(P->corner_capacity, mesh->ncorners + 1, sizeof(int), &capacity) != 0 ||
                resize_array((void **)&mesh->corner_vert, capacity, sizeof(int)) != 0 ||
                (mesh->corner_uv && resize_array((void **)&mesh->corner_uv, capacity, sizeof(int)) != 0) ||
                (mesh->corner_normal && resize_array((void **)&mesh->corner_normal, capacity, sizeof(int)) != 0))
                return out_of_memory(P);
            P->corner_capacity = capacity;
        }
        if (uv >= 0 && !mesh->corner_uv && start_corner_indices(P, &mesh->corner_uv) != 0) return -1;
        if (normal >= 0 && !mesh->corner_normal && start_corner_indices(P, &mesh->corner_normal) != 0) return -1;
        mesh->corner_vert[mesh->ncorners] = vertex;
        if (mesh->corner_uv) mesh->corner_uv[mesh->ncorners] = uv;
        if (mesh->corner_normal) mesh->corner_normal[mesh->ncorners] = normal;
        mesh->ncorners++;
        corners++;
    }
    if (corners < 3) return obj_error(P, "face with fewer than 3 corners");
    if (mesh->nfaces >= OBJ_MAX_COUNT) return obj_error(P, "too many faces (at most %d)", OBJ_MAX_COUNT);
    if (mesh->nfaces == P->face_capacity) {
        /* face_size, face_group, face_material and face_line share one capacity. */
        int capacity;
        if (grown_capacity(P->face_capacity, mesh->nfaces + 1, sizeof(int), &capacity) != 0 ||
            resize_array((void **)&mesh->face_size, capacity, sizeof(int)) != 0 ||
            resize_array((void **)&mesh->face_group, capacity, sizeof(int)) != 0 ||
            resize_array((void **)&mesh->face_material, capacity, sizeof(int)) != 0 ||
            resize_array((void **)&mesh->face_line, capacity, sizeof(int)) != 0)
            return out_of_memory(P);
        P->face_capacity = capacity;
    }
    mesh->face_size[mesh->nfaces] = corners;
    mesh->face_group[mesh->nfaces] = P->current_group;
    mesh->face_material[mesh->nfaces] = P->current_material;
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

/* Index of `name` in the index's list, adding it if it is new. */
static int find_or_add_name(obj_parser *P, name_index *index, const char *name, size_t length)
{
    uint32_t mask, slot;
    if (*index->count * 2 >= index->table_size) {
        /* Rebuild the table twice as large. */
        int size = index->table_size ? index->table_size * 2 : 64, g;
        int *table;
        if (size > OBJ_MAX_COUNT) return out_of_memory(P);
        table = (int *)calloc((size_t)size, sizeof(int));
        if (!table) return out_of_memory(P);
        for (g = 0; g < *index->count; g++) {
            uint32_t s = hash_name((*index->names)[g]) & (uint32_t)(size - 1);
            while (table[s]) s = (s + 1) & (uint32_t)(size - 1);
            table[s] = g + 1;
        }
        free(index->table);
        index->table = table;
        index->table_size = size;
    }
    mask = (uint32_t)index->table_size - 1;
    for (slot = hash_name(name) & mask; index->table[slot]; slot = (slot + 1) & mask)
        if (strcmp((*index->names)[index->table[slot] - 1], name) == 0) return index->table[slot] - 1;
    if (grow_array((void **)index->names, &index->capacity, *index->count + 1, sizeof(char *)) != 0)
        return out_of_memory(P);
    (*index->names)[*index->count] = tool_copy_string(name, length);
    if (!(*index->names)[*index->count]) return out_of_memory(P);
    index->table[slot] = *index->count + 1;
    return (*index->count)++;
}

/* Statements that are valid OBJ but carry nothing this tool uses: smoothing
   groups (the normals say it), lines, points, parameter-space vertices and
   display attributes. They are skipped without a word. */
static int is_ignored_keyword(const char *keyword, size_t length)
{
    static const char *const ignored[] = {"vp", "s", "l", "p", "lod", "bevel", "c_interp", "d_interp",
                                          "maplib", "usemap", "shadow_obj", "trace_obj"};
    size_t i;
    for (i = 0; i < sizeof ignored / sizeof ignored[0]; i++)
        if (token_is(keyword, length, ignored[i])) return 1;
    return 0;
}

static int parse_statement(obj_parser *P)
{
    const char *keyword;
    size_t length = next_token(P, &keyword);
    char name[OBJ_MAX_NAME_LENGTH];
    if (token_is(keyword, length, "v")) return parse_vertex(P);
    if (token_is(keyword, length, "vt")) return parse_texture_vertex(P);
    if (token_is(keyword, length, "f")) return parse_face(P);
    if (token_is(keyword, length, "vn")) return parse_normal(P);
    if (token_is(keyword, length, "g") || token_is(keyword, length, "o") || token_is(keyword, length, "usemtl")) {
        size_t name_length = read_name(P, name, sizeof name);
        int group = find_or_add_name(P, &P->groups, name, name_length);
        if (group < 0) return -1;
        P->current_group = group;
        if (token_is(keyword, length, "usemtl")) {
            int material = find_or_add_name(P, &P->materials, name, name_length);
            if (material < 0) return -1;
            P->current_material = material;
        }
        return 0;
    }
    if (token_is(keyword, length, "mtllib")) {
        size_t name_length = read_name(P, name, sizeof name);
        if (!P->mesh->mtllib && name_length > 0) {
            P->mesh->mtllib = tool_copy_string(name, name_length);
            if (!P->mesh->mtllib) return out_of_memory(P);
        }
        return 0;
    }
    if (length == 0 || keyword[0] == '#' || is_ignored_keyword(keyword, length)) return 0;
    /* Anything else is not OBJ this reader knows: skip it, but count it, so
       the tool can say so (a mangled "v" line would shift every index). */
    if (P->mesh->unknown_statements++ == 0) {
        size_t i, shown = length < sizeof P->mesh->first_unknown - 1 ? length : sizeof P->mesh->first_unknown - 1;
        for (i = 0; i < shown; i++) {
            unsigned char c = (unsigned char)keyword[i];
            P->mesh->first_unknown[i] = (c >= 32 && c < 127) ? (char)c : '?';
        }
        P->mesh->first_unknown[shown] = '\0';
        P->mesh->first_unknown_line = P->statement_line;
    }
    return 0;
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
    /* A UTF-8 byte-order mark, as some Windows editors write, is not part of
       the first statement. */
    if (P->end - P->p >= 3 && memcmp(P->p, "\xEF\xBB\xBF", 3) == 0) P->p += 3;
    P->line = 1;
    P->source = source;
    P->err = err;
    P->err_size = err_size;
    P->mesh = out;
    P->groups.names = &out->group_names;
    P->groups.count = &out->ngroups;
    P->materials.names = &out->material_names;
    P->materials.count = &out->nmaterials;
    tool_set_error(err, err_size, "no error");

    /* group 0: faces before any g / o / usemtl; material 0: before any usemtl */
    if (find_or_add_name(P, &P->groups, "", 0) != 0 || find_or_add_name(P, &P->materials, "", 0) != 0) goto fail;
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
        if (source) tool_set_error(err, err_size, "%s: no faces", source);
        else tool_set_error(err, err_size, "no faces");
        goto fail;
    }
    free(P->groups.table);
    free(P->materials.table);
    return 0;

fail:
    free(P->groups.table);
    free(P->materials.table);
    obj_free(out);
    return -1;
}

int obj_parse(const char *text, size_t length, obj_mesh *out, char *err, size_t err_size)
{
    return obj_parse_named(text, length, NULL, out, err, err_size);
}


int obj_read_text(const char *path, const char *text, size_t size, obj_mesh *out, char *err, size_t err_size)
{
    int result = obj_parse_named(text, size, path, out, err, err_size);
    if (result == 0 && out->unknown_statements == 1)
        tool_note("%s:%d: skipped a line with an unknown keyword, '%s'", path, out->first_unknown_line,
                  out->first_unknown);
    else if (result == 0 && out->unknown_statements > 1)
        tool_note("%s:%d: skipped %d lines with unknown keywords, the first '%s'", path,
                  out->first_unknown_line, out->unknown_statements, out->first_unknown);
    return result;
}

/* ======================================================================== */
/* MTL reading                                                              */
/* ======================================================================== */

/* A map_ statement's file name: what follows its options. Options start
   with '-' and take numbers or on/off, so when the value starts with '-'
   the name is its last word ("-s 2 2 1 stone.png" -> "stone.png"); a name
   with blanks in it is read whole when no option comes first. */
static const char *map_file_name(const char *value)
{
    const char *last_blank = strrchr(value, ' ');
    return value[0] == '-' && last_blank ? last_blank + 1 : value;
}

int mtl_read(const char *path, mtl_library *out, char *err, size_t err_size)
{
    unsigned char *data;
    size_t size;
    obj_parser parser;
    obj_parser *P = &parser;
    char name[OBJ_MAX_NAME_LENGTH];
    int capacity = 0, status = 0;
    memset(out, 0, sizeof *out);
    if (tool_read_file(path, &data, &size, err, err_size) != 0) return -1;
    memset(P, 0, sizeof *P);
    P->p = (const char *)data;
    P->end = P->p + size;
    P->line = 1;
    P->source = path;
    P->err = err;
    P->err_size = err_size;
    while (P->p < P->end && status == 0) {
        const char *keyword;
        size_t length;
        skip_blanks(P);
        P->statement = P->p;
        P->statement_line = P->line;
        length = next_token(P, &keyword);
        if (token_is(keyword, length, "newmtl")) {
            size_t name_length = read_name(P, name, sizeof name);
            int had = capacity;
            /* names and diffuse_maps share one capacity. */
            if (out->count >= OBJ_MAX_COUNT ||
                grow_array((void **)&out->names, &capacity, out->count + 1, sizeof(char *)) != 0 ||
                (capacity != had && resize_array((void **)&out->diffuse_maps, capacity, sizeof(char *)) != 0) ||
                (capacity != had && resize_array((void **)&out->normal_maps, capacity, sizeof(char *)) != 0) ||
                !(out->names[out->count] = tool_copy_string(name, name_length))) {
                status = out_of_memory(P);
                break;
            }
            out->diffuse_maps[out->count] = NULL;
            out->normal_maps[out->count++] = NULL;
        } else if ((token_is(keyword, length, "map_Kd") || token_is(keyword, length, "norm")) && out->count > 0) {
            const char *file;
            char **map = token_is(keyword, length, "norm") ? &out->normal_maps[out->count - 1]
                                                           : &out->diffuse_maps[out->count - 1];
            read_name(P, name, sizeof name);
            file = map_file_name(name);
            free(*map);
            if (!(*map = tool_copy_string(file, strlen(file)))) status = out_of_memory(P);
        }
        finish_statement(P);
    }
    free(data);
    if (status != 0) mtl_free(out);
    return status;
}

void mtl_free(mtl_library *library)
{
    int k;
    for (k = 0; k < library->count; k++) {
        free(library->names[k]);
        free(library->diffuse_maps[k]);
        free(library->normal_maps[k]);
    }
    free(library->names);
    free(library->diffuse_maps);
    free(library->normal_maps);
    memset(library, 0, sizeof *library);
}

int mtl_find(const mtl_library *library, const char *name)
{
    int k;
    for (k = 0; k < library->count; k++)
        if (strcmp(library->names[k], name) == 0) return k;
    return -1;
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

int obj_corner_normals(const char *path, const obj_mesh *mesh, float **out)
{
    int c, k, unusable = 0;
    *out = NULL;
    if (!mesh->corner_normal) return 0;
    for (c = 0; c < mesh->ncorners; c++) {
        int n = mesh->corner_normal[c];
        const float *v = n >= 0 ? mesh->normal + 3 * (size_t)n : NULL;
        double length = v ? sqrt((double)v[0] * v[0] + (double)v[1] * v[1] + (double)v[2] * v[2]) : 0.0;
        /* (NaN fails the comparison too) */
        unusable += !(length > 0.0 && length < HUGE_VAL);
    }
    if (unusable > 0) {
        tool_note("%s: %d of %d face corners have no usable normal (no vn, or a zero or non-finite one): every "
                  "output gets computed normals instead of the file's",
                  path, unusable, mesh->ncorners);
        return 0;
    }
    *out = (float *)malloc((size_t)mesh->ncorners * 3 * sizeof(float));
    if (!*out) return -1;
    for (c = 0; c < mesh->ncorners; c++) {
        const float *v = mesh->normal + 3 * (size_t)mesh->corner_normal[c];
        double length = sqrt((double)v[0] * v[0] + (double)v[1] * v[1] + (double)v[2] * v[2]);
        for (k = 0; k < 3; k++) (*out)[3 * (size_t)c + k] = (float)(v[k] / length);
    }
    return 0;
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
    free(mesh->uv_w);
    free(mesh->corner_uv);
    free(mesh->normal);
    free(mesh->corner_normal);
    free(mesh->face_group);
    free(mesh->face_material);
    free(mesh->face_line);
    free(mesh->vert_line);
    for (g = 0; g < mesh->ngroups; g++) free(mesh->group_names[g]);
    free(mesh->group_names);
    for (g = 0; g < mesh->nmaterials; g++) free(mesh->material_names[g]);
    free(mesh->material_names);
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

/* "KEYWORD x y z" and a newline, written in place at the buffer's end. */
static void write_floats(tool_buffer *out, const char *keyword, const float *values, int count)
{
    size_t length = strlen(keyword);
    char *line = buffer_room(out, length + 3 * (TOOL_NUMBER_TEXT_SIZE + 1) + 1);
    int i;
    if (!line) return;
    memcpy(line, keyword, length);
    for (i = 0; i < count && i < 3; i++) {
        line[length++] = ' ';
        length += (size_t)tool_format_float(values[i], line + length);
    }
    line[length++] = '\n';
    buffer_wrote(out, length);
}

/* With desc->share_equal, each distinct vt (or vn) is written once: a
   corner's row of floats (u, v and w; or x, y, z), compared bit for bit
   with the rows before it through a hash table. */
typedef struct distinct_rows {
    int count;
    int *of_corner;         /* per corner: the 0-based index of its row among the distinct ones */
    int *first_corner;      /* per distinct row: the first corner that has it, in corner order */
} distinct_rows;

/* The vt rows (u, v and w, 0 without one) or the vn rows (x, y, z). */
typedef enum row_kind { TEXTURE_ROWS, NORMAL_ROWS } row_kind;

static void read_row(const obj_write_desc *desc, row_kind kind, int c, float row[3])
{
    if (kind == NORMAL_ROWS) {
        memcpy(row, desc->corner_normal + 3 * (size_t)c, 3 * sizeof(float));
    } else {
        row[0] = desc->corner_uv[2 * (size_t)c];
        row[1] = desc->corner_uv[2 * (size_t)c + 1];
        row[2] = desc->corner_uv_w ? desc->corner_uv_w[c] : 0.0f;
    }
}

static uint32_t row_hash(const float row[3])
{
    uint32_t bits[3], hash;
    memcpy(bits, row, sizeof bits);
    hash = bits[0] * 0x9e3779b1u + bits[1] * 0x85ebca77u + bits[2] * 0xc2b2ae3du;
    return hash ^ (hash >> 15);
}

static void distinct_rows_free(distinct_rows *rows)
{
    free(rows->of_corner);
    free(rows->first_corner);
    memset(rows, 0, sizeof *rows);
}

/* A hint to the processor that *address will be read soon. */
#if defined(__GNUC__) || defined(__clang__)
#define PREFETCH(address) __builtin_prefetch(address)
#else
#define PREFETCH(address) ((void)(address))
#endif
#define PREFETCH_AHEAD 16

/* The row a vertex's last corner had (find_distinct_rows, for normals). */
typedef struct vertex_row {
    float row[3];
    int index;              /* its distinct row, or -1: no corner yet */
} vertex_row;

/* A slot of find_distinct_rows' hash table: a distinct row and its hash,
   so that probing and growing compare hashes, not rows. */
typedef struct row_slot {
    int index;              /* distinct row + 1; 0 = empty */
    uint32_t hash;
} row_slot;

/* Returns 0, or -1 when out of memory. The table grows to stay at most
   half full. A corner's normal is first compared with the one its vertex's
   last corner had: a smooth normal is one per vertex, so most corners need
   no look-up in the table, which starts with room for one row per vertex. */
static int find_distinct_rows(const obj_write_desc *desc, int ncorners, row_kind kind, distinct_rows *rows)
{
    size_t size = 1024, mask, slot;
    row_slot *table;
    vertex_row *last = NULL;
    int c, v, by_vertex = kind == NORMAL_ROWS;
    memset(rows, 0, sizeof *rows);
    while (by_vertex && size < 2 * (size_t)desc->nverts) size *= 2;
    mask = size - 1;
    table = (row_slot *)calloc(size, sizeof *table);
    rows->of_corner = (int *)malloc(((size_t)ncorners + 1) * sizeof(int));
    rows->first_corner = (int *)malloc(((size_t)ncorners + 1) * sizeof(int));
    if (by_vertex && (last = (vertex_row *)malloc(((size_t)desc->nverts + 1) * sizeof *last)) != NULL)
        for (v = 0; v < desc->nverts; v++) last[v].index = -1;
    if (!table || !rows->of_corner || !rows->first_corner || (by_vertex && !last)) goto failed;
    for (c = 0; c < ncorners; c++) {
        float row[3], other[3];
        vertex_row *at = last ? &last[desc->corner_vert[c]] : NULL;
        uint32_t hash;
        int index = -1;
        if (last && c + PREFETCH_AHEAD < ncorners) {
            /* The table is far larger than the cache and is read at random:
               ask for the slot of a vertex's first corner a few corners
               ahead, so that the memory works while this one is done. */
            const vertex_row *ahead = &last[desc->corner_vert[c + PREFETCH_AHEAD]];
            if (ahead->index < 0) {
                read_row(desc, kind, c + PREFETCH_AHEAD, other);
                PREFETCH(&table[row_hash(other) & mask]);
            }
        }
        read_row(desc, kind, c, row);
        if (at && at->index >= 0 && memcmp(row, at->row, sizeof row) == 0) {
            rows->of_corner[c] = at->index;
            continue;
        }
        hash = row_hash(row);
        for (slot = hash & mask; table[slot].index; slot = (slot + 1) & mask) {
            if (table[slot].hash != hash) continue;
            read_row(desc, kind, rows->first_corner[table[slot].index - 1], other);
            if (memcmp(row, other, sizeof row) == 0) {
                index = table[slot].index - 1;
                break;
            }
        }
        if (index < 0) {
            index = rows->count++;
            rows->first_corner[index] = c;
            table[slot].index = index + 1;
            table[slot].hash = hash;
            if (2 * (size_t)rows->count > size) {
                row_slot *grown = (row_slot *)calloc(2 * size, sizeof *grown);
                size_t k;
                if (!grown) goto failed;
                for (k = 0; k < size; k++) {
                    size_t to = table[k].hash & (2 * size - 1);
                    if (!table[k].index) continue;
                    while (grown[to].index) to = (to + 1) & (2 * size - 1);
                    grown[to] = table[k];
                }
                free(table);
                table = grown;
                size *= 2;
                mask = size - 1;
            }
        }
        rows->of_corner[c] = index;
        if (at) {
            memcpy(at->row, row, sizeof row);
            at->index = index;
        }
    }
    free(table);
    free(last);
    return 0;
failed:
    free(table);
    free(last);
    distinct_rows_free(rows);
    return -1;
}

/* Where each corner's vt and vn are: corner c uses vt c + 1 and vn c + 1,
   or with shared rows the one of_corner names. */
typedef struct corner_refs {
    const obj_write_desc *desc;
    const int *texture;     /* of_corner of the vt rows, or NULL: one per corner */
    const int *normal;      /* of_corner of the vn rows, or NULL */
} corner_refs;

/* One corner of an "f" line into text: " v", " v/vt", " v//vn" or
   " v/vt/vn"; returns its length (at most CORNER_TEXT_SIZE). */
#define CORNER_TEXT_SIZE (3 * TOOL_NUMBER_TEXT_SIZE + 3)
static int format_corner(const corner_refs *refs, int c, char *text)
{
    const obj_write_desc *desc = refs->desc;
    int length;
    text[0] = ' ';
    length = 1 + tool_format_int((long)desc->corner_vert[c] + 1, text + 1);
    if (desc->corner_uv || desc->corner_normal) {
        text[length++] = '/';
        if (desc->corner_uv)
            length += tool_format_int((long)(refs->texture ? refs->texture[c] : c) + 1, text + length);
    }
    if (desc->corner_normal) {
        text[length++] = '/';
        length += tool_format_int((long)(refs->normal ? refs->normal[c] : c) + 1, text + length);
    }
    return length;
}

/* "f" with corner `first`, then `count` corners from `next` on, written in
   place at the buffer's end. */
static void write_face_corners(tool_buffer *out, const corner_refs *refs, int first, int next, int count)
{
    char *line = buffer_room(out, 2 + ((size_t)count + 1) * CORNER_TEXT_SIZE);
    size_t length = 1;
    int i;
    if (!line) return;
    line[0] = 'f';
    length += (size_t)format_corner(refs, first, line + length);
    for (i = 0; i < count; i++) length += (size_t)format_corner(refs, next + i, line + length);
    line[length++] = '\n';
    buffer_wrote(out, length);
}

/* One section of the file - the v lines, the vt or vn lines (of every
   corner in order, or of each distinct row once when `rows` is not NULL),
   or the f lines - whose lines can be made in any order and joined: at -j N
   runs of them are formatted on the tool's threads, each into its own
   buffer, and appended in order (the same bytes). */
typedef enum section_kind { VERTEX_LINES, TEXTURE_LINES, NORMAL_LINES, FACE_LINES } section_kind;

typedef struct section {
    const obj_write_desc *desc;
    section_kind kind;
    const distinct_rows *rows;      /* TEXTURE_LINES, NORMAL_LINES: the distinct rows, or NULL */
    const corner_refs *refs;        /* FACE_LINES */
    int count;                      /* lines (faces for FACE_LINES) */
    int first_piece;                /* the batch's first piece (see write_section) */
    tool_buffer *pieces;            /* SECTION_BATCH of them */
    int *invalid;                   /* per piece of the batch: 1 when it has a face obj_write refuses */
} section;

/* Lines per piece, and pieces made at once (their text held at the same time). */
#define SECTION_PIECE 8192
#define SECTION_BATCH 16

/* Items [begin, end) of the section into `out`, the faces' first corner
   being `corner`. Returns 0, or -1 for a face of fewer than 3 corners or
   one naming no vertex. */
static int write_items(tool_buffer *out, const section *sec, int begin, int end, int corner)
{
    const obj_write_desc *desc = sec->desc;
    int k, i;
    for (k = begin; k < end; k++) {
        float row[3];
        int size;
        switch (sec->kind) {
        case VERTEX_LINES:
            write_floats(out, "v", desc->pos + 3 * (size_t)k, 3);
            break;
        case TEXTURE_LINES:
            read_row(desc, TEXTURE_ROWS, sec->rows ? sec->rows->first_corner[k] : k, row);
            write_floats(out, "vt", row, desc->corner_uv_w ? 3 : 2);
            break;
        case NORMAL_LINES:
            read_row(desc, NORMAL_ROWS, sec->rows ? sec->rows->first_corner[k] : k, row);
            write_floats(out, "vn", row, 3);
            break;
        case FACE_LINES:
            size = desc->face_size ? desc->face_size[k] : desc->fixed_face_size;
            if (size < 3) return -1;
            for (i = 0; i < size; i++)
                if (desc->corner_vert[corner + i] < 0 || desc->corner_vert[corner + i] >= desc->nverts) return -1;
            if (desc->triangles) {
                /* The fan from the first corner, as readers split a polygon
                   themselves: each triangle keeps the face's winding. */
                for (i = 1; i + 1 < size; i++) write_face_corners(out, sec->refs, corner, corner + i, 2);
            } else {
                write_face_corners(out, sec->refs, corner, corner + 1, size - 1);
            }
            corner += size;
            break;
        }
    }
    return 0;
}

static void section_task(void *context, int index)
{
    const section *sec = (const section *)context;
    int piece = sec->first_piece + index, begin = piece * SECTION_PIECE;
    int end = sec->count - begin > SECTION_PIECE ? begin + SECTION_PIECE : sec->count;
    int corner = sec->kind == FACE_LINES ? begin * sec->desc->fixed_face_size : 0;
    sec->invalid[index] = write_items(&sec->pieces[index], sec, begin, end, corner) != 0;
}

/* The section's lines into `out`: here at -j 1 (and for faces of several
   sizes, whose pieces would not know their first corners), else piece by
   piece on the tool's threads. Returns 0, or -1 as write_items (or when out
   of memory: out->failed). */
static int write_section(tool_buffer *out, section *sec)
{
    const tt_executor *executor = tool_executor();
    tool_buffer pieces[SECTION_BATCH];
    int invalid[SECTION_BATCH], npieces = (sec->count + SECTION_PIECE - 1) / SECTION_PIECE, status = 0, p;
    if (!executor || npieces < 2 || (sec->kind == FACE_LINES && sec->desc->face_size))
        return write_items(out, sec, 0, sec->count, 0);
    memset(pieces, 0, sizeof pieces);
    sec->pieces = pieces;
    sec->invalid = invalid;
    for (sec->first_piece = 0; sec->first_piece < npieces && status == 0; sec->first_piece += SECTION_BATCH) {
        int batch = npieces - sec->first_piece < SECTION_BATCH ? npieces - sec->first_piece : SECTION_BATCH;
        tool_run_tasks(executor, batch, section_task, sec);
        for (p = 0; p < batch; p++) {
            if (invalid[p] || pieces[p].failed) status = -1;
            if (status == 0) buffer_append(out, pieces[p].data, pieces[p].size);
            pieces[p].size = 0;
        }
    }
    for (p = 0; p < SECTION_BATCH; p++) buffer_free(&pieces[p]);
    return status != 0 || out->failed ? -1 : 0;
}

int obj_write(tool_buffer *out, const obj_write_desc *desc)
{
    int f, c = 0, ncorners = 0, previous_group = -1, status = 0;
    distinct_rows textures, normals;
    corner_refs refs;
    section sec;
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

    /* Nine significant digits (tool_format_float) are enough for any float
       to read back exactly, so writing a mesh and reading it again changes
       nothing. */
    memset(&sec, 0, sizeof sec);
    sec.desc = desc;
    sec.kind = VERTEX_LINES;
    sec.count = desc->nverts;
    if (write_section(out, &sec) != 0) return -1;
    /* The progress line (a scan's OBJ takes a second): after each section,
       the faces, the largest, last. */
    tool_stage_fraction(0.2, NULL);

    for (f = 0; f < desc->nfaces; f++) ncorners += desc->face_size ? desc->face_size[f] : desc->fixed_face_size;
    memset(&textures, 0, sizeof textures);
    memset(&normals, 0, sizeof normals);
    if (desc->share_equal && ((desc->corner_uv && find_distinct_rows(desc, ncorners, TEXTURE_ROWS, &textures) != 0) ||
                              (desc->corner_normal && find_distinct_rows(desc, ncorners, NORMAL_ROWS, &normals) != 0))) {
        distinct_rows_free(&textures);
        return -1;
    }
    tool_stage_fraction(0.35, NULL);
    refs.desc = desc;
    refs.texture = textures.of_corner;
    refs.normal = normals.of_corner;
    /* One vt (and vn) per face corner in corner order, corner c using vt
       c + 1; or each distinct one once, in the order corners first use it. */
    if (desc->corner_uv) {
        sec.kind = TEXTURE_LINES;
        sec.rows = desc->share_equal ? &textures : NULL;
        sec.count = sec.rows ? sec.rows->count : ncorners;
        status = write_section(out, &sec);
        tool_stage_fraction(0.5, NULL);
    }
    if (desc->corner_normal && status == 0) {
        sec.kind = NORMAL_LINES;
        sec.rows = desc->share_equal ? &normals : NULL;
        sec.count = sec.rows ? sec.rows->count : ncorners;
        status = write_section(out, &sec);
        tool_stage_fraction(0.65, NULL);
    }

    if (desc->material && !(desc->face_group && desc->group_materials)) write_name_line(out, "usemtl", desc->material);
    sec.kind = FACE_LINES;
    sec.rows = NULL;
    sec.refs = &refs;
    sec.count = desc->nfaces;
    if (!desc->face_group && status == 0) status = write_section(out, &sec);
    /* With groups, a "g" line (and "usemtl") before each run of a group. */
    for (f = 0; desc->face_group && f < desc->nfaces && status == 0; f++) {
        int group = desc->face_group[f];
        if (group < 0 || group >= desc->ngroups) {
            status = -1;
            break;
        }
        if (group != previous_group) {
            write_name_line(out, "g", desc->group_names[group]);
            if (desc->group_materials && desc->group_materials[group])
                write_name_line(out, "usemtl", desc->group_materials[group]);
            previous_group = group;
        }
        status = write_items(out, &sec, f, f + 1, c);
        c += desc->face_size ? desc->face_size[f] : desc->fixed_face_size;
        if (f % 65536 == 65535) tool_stage_fraction(0.65 + 0.35 * f / desc->nfaces, NULL);
    }
    distinct_rows_free(&textures);
    distinct_rows_free(&normals);
    return status != 0 || out->failed ? -1 : 0;
}

void mtl_add_material(tool_buffer *out, const char *name, const char *texture, int texture_alpha,
                      const char *const *maps)
{
    write_name_line(out, "newmtl", name);
    buffer_printf(out, "Ka 1 1 1\nKd 1 1 1\nKs 0 0 0\nd 1\nillum 1\n");
    if (texture) write_name_line(out, "map_Kd", texture);
    if (texture && texture_alpha) write_name_line(out, "map_d", texture);
    if (maps && maps[MATERIAL_NORMAL]) {
        write_name_line(out, "map_Bump -bm 1", maps[MATERIAL_NORMAL]);
        write_name_line(out, "norm", maps[MATERIAL_NORMAL]);
    }
    if (maps && maps[MATERIAL_ROUGHNESS]) write_name_line(out, "map_Pr", maps[MATERIAL_ROUGHNESS]);
    if (maps && maps[MATERIAL_METALLIC]) write_name_line(out, "map_Pm", maps[MATERIAL_METALLIC]);
    if (maps && maps[MATERIAL_HEIGHT]) write_name_line(out, "disp", maps[MATERIAL_HEIGHT]);
    if (maps && maps[MATERIAL_AO]) write_name_line(out, "# ambient occlusion:", maps[MATERIAL_AO]);
    buffer_printf(out, "\n");
}

int output_add_mtl(tool_output *output, const char *mtl_path, const char *material, const char *texture_path,
                   int texture_alpha, const char *const *map_paths)
{
    return output_add_mtl_materials(output, mtl_path, 1, &material, &texture_path, texture_alpha, map_paths);
}
int output_add_mtl_materials(tool_output *output, const char *mtl_path, int count, const char *const *materials,
                             const char *const *texture_paths, int texture_alpha, const char *const *map_paths)
{
    tool_buffer text = TOOL_BUFFER_INIT;
    char texture[4096], maps[MATERIAL_MAPS][4096];
    int k, map;
    for (k = 0; k < count; k++) {
        const char *names[MATERIAL_MAPS];
        tool_relative_path(texture_paths[k], mtl_path, texture, sizeof texture);
        for (map = 0; map < MATERIAL_MAPS; map++) {
            const char *path = map_paths ? map_paths[(size_t)k * MATERIAL_MAPS + map] : NULL;
            names[map] = NULL;
            if (!path) continue;
            tool_relative_path(path, mtl_path, maps[map], sizeof maps[map]);
            names[map] = maps[map];
        }
        mtl_add_material(&text, materials[k], texture, texture_alpha, names);
    }
    if (output_add_buffer(output, mtl_path, &text) != 0) {
        buffer_free(&text);
        return tool_fail("out of memory while writing %s", mtl_path);
    }
    return 0;
}
