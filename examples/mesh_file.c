/* mesh_file.c - the one way every command reads its mesh: a Wavefront OBJ,
   or an STL or OFF file (small formats, read here into the same obj_mesh),
   with other mesh formats named and refused, and --weld. See tool.h for the
   interface.

   STL stores every triangle with its own three corner positions, so an STL
   is always welded (exactly equal positions become one vertex): without that
   each triangle would be a component of its own. */

#include <ctype.h>
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tool.h"

static int weld_requested = 0;

void mesh_set_weld(int weld)
{
    weld_requested = weld;
}

/* ======================================================================== */
/* Which format                                                             */
/* ======================================================================== */

typedef enum mesh_format {
    MESH_OBJ, MESH_STL_ASCII, MESH_STL_BINARY, MESH_OFF,
    /* named and refused */
    MESH_GLTF, MESH_GLB, MESH_PLY, MESH_FBX, MESH_COLLADA, MESH_3DS
} mesh_format;

static const char *const format_names[] = {
    "a Wavefront OBJ mesh", "an ASCII STL mesh", "a binary STL mesh", "an OFF mesh",
    "a glTF mesh", "a binary glTF (GLB) mesh", "a PLY mesh", "an FBX mesh", "a COLLADA mesh", "a 3DS mesh"
};

static uint32_t read_u32_le(const unsigned char *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

/* A binary STL is an 80-byte header, a triangle count, and 50 bytes per
   triangle: its size alone says so (its header may well begin "solid"). */
static int is_binary_stl(const unsigned char *data, size_t size)
{
    return size >= 84 && (size - 84) % 50 == 0 && (size - 84) / 50 == read_u32_le(data + 80);
}

/* Bytes no text file holds (NUL and the control codes other than tab, line
   ends and form feed) among the first 512: a binary file. */
static int looks_binary(const unsigned char *data, size_t size)
{
    size_t i;
    for (i = 0; i < size && i < 512; i++)
        if (data[i] < 32 && data[i] != '\t' && data[i] != '\n' && data[i] != '\r' && data[i] != '\f') return 1;
    return 0;
}

/* Why a binary file that should be a binary STL is not one: its size and
   its triangle count disagree (a truncated or padded file). */
static void refuse_broken_binary_stl(const char *path, const unsigned char *data, size_t size, char *err,
                                     size_t err_size)
{
    if (size < 84) {
        tool_set_error(err, err_size, "%s: a binary STL of %lu bytes, shorter than its 84-byte header: the file is "
                       "truncated", path, (unsigned long)size);
    } else {
        uint32_t count = read_u32_le(data + 80);
        double want = 84.0 + 50.0 * (double)count;
        tool_set_error(err, err_size, "%s: a binary STL whose header counts %lu triangles (%.0f bytes with the "
                       "84-byte header) is %lu bytes long: the file is %s", path, (unsigned long)count, want,
                       (unsigned long)size, (double)size < want ? "truncated" : "longer than its triangles, or the count is wrong");
    }
}

/* The first word of the text, after blanks, is `word` (case-insensitive),
   followed by a blank, a line end or the end. */
static int starts_with_word(const unsigned char *data, size_t size, const char *word)
{
    size_t i = 0, n = strlen(word), k;
    while (i < size && isspace(data[i])) i++;
    if (size - i < n) return 0;
    for (k = 0; k < n; k++)
        if (tolower(data[i + k]) != tolower((unsigned char)word[k])) return 0;
    return i + n == size || isspace(data[i + n]);
}

/* Does `needle` occur in the first `limit` bytes? */
static int appears_early(const unsigned char *data, size_t size, const char *needle, size_t limit)
{
    size_t n = strlen(needle), i;
    if (size > limit) size = limit;
    for (i = 0; i + n <= size; i++)
        if (memcmp(data + i, needle, n) == 0) return 1;
    return 0;
}

/* An OFF header: "OFF", optionally with the letters of its variants (C
   colours, N normals, ST texture coordinates), all of which keep x y z
   first on every vertex line. */
static int is_off_header(const unsigned char *data, size_t size)
{
    size_t i = 0, start;
    while (i < size && isspace(data[i])) i++;
    start = i;
    while (i < size && (data[i] == 'C' || data[i] == 'N' || data[i] == 'S' || data[i] == 'T')) i++;
    return size - i >= 3 && memcmp(data + i, "OFF", 3) == 0 && (i + 3 == size || isspace(data[i + 3])) &&
           i - start <= 4;
}

/* The format the first bytes say, or MESH_OBJ when they say none. */
static mesh_format format_by_content(const unsigned char *data, size_t size)
{
    if (size >= 4 && memcmp(data, "glTF", 4) == 0) return MESH_GLB;
    if (size >= 4 && memcmp(data, "ply", 3) == 0 && (data[3] == '\n' || data[3] == '\r')) return MESH_PLY;
    if (size >= 18 && memcmp(data, "Kaydara FBX Binary", 18) == 0) return MESH_FBX;
    if (is_binary_stl(data, size)) return MESH_STL_BINARY;
    if (starts_with_word(data, size, "solid") && appears_early(data, size, "facet", 4096)) return MESH_STL_ASCII;
    if (is_off_header(data, size)) return MESH_OFF;
    if (appears_early(data, size, "<COLLADA", 1024)) return MESH_COLLADA;
    if (size >= 1 && data[0] == '{' && appears_early(data, size, "\"asset\"", 4096)) return MESH_GLTF;
    return MESH_OBJ;
}

/* The format the file name's extension says (any case), or -1. */
static int format_by_extension(const char *path)
{
    static const struct { const char *extension; mesh_format format; } known[] = {
        {"stl", MESH_STL_ASCII}, {"off", MESH_OFF}, {"gltf", MESH_GLTF}, {"glb", MESH_GLB}, {"ply", MESH_PLY},
        {"fbx", MESH_FBX}, {"dae", MESH_COLLADA}, {"3ds", MESH_3DS}
    };
    const char *dot = strrchr(tool_basename(path), '.');
    size_t i, k;
    if (!dot) return -1;
    for (i = 0; i < sizeof known / sizeof known[0]; i++) {
        const char *e = known[i].extension;
        for (k = 0; e[k] && dot[1 + k] && tolower((unsigned char)dot[1 + k]) == e[k]; k++) continue;
        if (!e[k] && !dot[1 + k]) return (int)known[i].format;
    }
    return -1;
}

/* The content decides, since a misnamed file is still what it is; a name
   the content does not contradict decides for what leaves no mark in its
   first bytes (a 3DS file, a broken STL). */
static mesh_format detect_format(const char *path, const unsigned char *data, size_t size)
{
    mesh_format by_content = format_by_content(data, size);
    int by_name = format_by_extension(path);
    if (by_content != MESH_OBJ || by_name < 0) return by_content;
    return by_name == MESH_STL_ASCII && is_binary_stl(data, size) ? MESH_STL_BINARY : (mesh_format)by_name;
}

/* "tiledtex: m.ply: a PLY mesh; tiledtex reads ...": what the file is and
   how to get an OBJ from it. A misnamed file (its content says other than
   its name) is said to be so, and the suggested output gets a name of its
   own rather than the input's. */
static void refuse_format(const char *path, mesh_format format, int misnamed, char *err, size_t err_size)
{
    const char *dot = strrchr(tool_basename(path), '.');
    size_t stem = dot ? (size_t)(dot - path) : strlen(path);
    tool_set_error(err, err_size,
                   "%s: %s%s; tiledtex reads Wavefront OBJ, STL and OFF: convert it (e.g. assimp export %s "
                   "%.*s%s.obj, from Debian's assimp-utils)",
                   path, format_names[format], misnamed ? " (by its first bytes, whatever its name)" : "", path,
                   (int)stem, path, misnamed ? "_converted" : "");
}

/* ======================================================================== */
/* STL and OFF into an obj_mesh                                             */
/* ======================================================================== */

/* Growing arrays for a reader; counts capped so 3 * count fits an int. */
#define MESH_MAX_COUNT (1 << 28)

typedef struct mesh_builder {
    obj_mesh *mesh;
    int vert_capacity, face_capacity, corner_capacity;
} mesh_builder;

/* The capacity, doubled from `capacity`, that holds `needed` elements. */
static int grown(int capacity, int needed)
{
    capacity = capacity > 0 ? capacity : 64;
    while (capacity < needed) capacity = capacity > MESH_MAX_COUNT ? needed : 2 * capacity;
    return capacity;
}

static int resize(void **array, int count, size_t element_size)
{
    void *resized = realloc(*array, (size_t)count * element_size);
    if (!resized) return -1;
    *array = resized;
    return 0;
}

/* The parts of an obj_mesh an OBJ always has: group 0 and material 0, "". */
static int builder_start(mesh_builder *b, obj_mesh *mesh)
{
    memset(b, 0, sizeof *b);
    memset(mesh, 0, sizeof *mesh);
    b->mesh = mesh;
    mesh->group_names = (char **)malloc(sizeof(char *));
    mesh->material_names = (char **)malloc(sizeof(char *));
    if (!mesh->group_names || !mesh->material_names) return -1;
    mesh->group_names[0] = tool_copy_string("", 0);
    mesh->ngroups = mesh->group_names[0] ? 1 : 0;
    mesh->material_names[0] = tool_copy_string("", 0);
    mesh->nmaterials = mesh->material_names[0] ? 1 : 0;
    return mesh->ngroups && mesh->nmaterials ? 0 : -1;
}

static int add_vertex(mesh_builder *b, const double xyz[3], int line)
{
    obj_mesh *m = b->mesh;
    int k;
    if (m->nverts >= MESH_MAX_COUNT) return -1;
    if (m->nverts == b->vert_capacity) {
        int capacity = grown(b->vert_capacity, m->nverts + 1);
        if (resize((void **)&m->pos, 3 * capacity, sizeof(float)) != 0 ||
            resize((void **)&m->vert_line, capacity, sizeof(int)) != 0)
            return -1;
        b->vert_capacity = capacity;
    }
    for (k = 0; k < 3; k++)   /* beyond float range: infinity, which the library names */
        m->pos[3 * (size_t)m->nverts + k] = tool_float_of(xyz[k]);
    m->vert_line[m->nverts++] = line;
    return 0;
}

/* A face of the given corners (vertex indices already checked), in group 0
   and material 0. */
static int add_face(mesh_builder *b, const int *corners, int count, int line)
{
    obj_mesh *m = b->mesh;
    if (m->nfaces >= MESH_MAX_COUNT || m->ncorners > MESH_MAX_COUNT - count) return -1;
    if (m->ncorners + count > b->corner_capacity) {
        int capacity = grown(b->corner_capacity, m->ncorners + count);
        if (resize((void **)&m->corner_vert, capacity, sizeof(int)) != 0) return -1;
        b->corner_capacity = capacity;
    }
    if (m->nfaces == b->face_capacity) {
        int capacity = grown(b->face_capacity, m->nfaces + 1);
        if (resize((void **)&m->face_size, capacity, sizeof(int)) != 0 ||
            resize((void **)&m->face_line, capacity, sizeof(int)) != 0 ||
            resize((void **)&m->face_group, capacity, sizeof(int)) != 0 ||
            resize((void **)&m->face_material, capacity, sizeof(int)) != 0)
            return -1;
        b->face_capacity = capacity;
    }
    memcpy(m->corner_vert + m->ncorners, corners, (size_t)count * sizeof(int));
    m->ncorners += count;
    m->face_size[m->nfaces] = count;
    m->face_line[m->nfaces] = line;
    m->face_group[m->nfaces] = 0;
    m->face_material[m->nfaces] = 0;
    m->nfaces++;
    return 0;
}

/* A cursor over text, by whitespace-separated words, counting lines. */
typedef struct text_cursor {
    const char *p, *end;
    int line;
} text_cursor;

/* The next word (length 0 at the end); with same_line, only on this line. */
static size_t next_word(text_cursor *t, const char **word, int same_line)
{
    for (;;) {
        while (t->p < t->end && (*t->p == ' ' || *t->p == '\t' || *t->p == '\r' || *t->p == '\f' ||
                                 *t->p == '\v' || (*t->p == '\n' && !same_line))) {
            if (*t->p == '\n') t->line++;
            t->p++;
        }
        if (t->p < t->end && *t->p == '#') {   /* OFF comments run to the line's end */
            while (t->p < t->end && *t->p != '\n') t->p++;
            if (!same_line) continue;
        }
        break;
    }
    *word = t->p;
    if (t->p < t->end && *t->p == '\n') return 0;
    while (t->p < t->end && !isspace((unsigned char)*t->p)) t->p++;
    return (size_t)(t->p - *word);
}

static int word_is(const char *word, size_t length, const char *expected)
{
    return strlen(expected) == length && memcmp(word, expected, length) == 0;
}

/* A word as a number: 0, or -1 when it is not one. */
static int word_number(const char *word, size_t length, double *out)
{
    char text[128];
    if (length == 0 || length >= sizeof text) return -1;
    memcpy(text, word, length);
    text[length] = '\0';
    return parse_whole_double(text, out);
}

/* The next `count` words as numbers. */
static int read_numbers(text_cursor *t, double *out, int count, int same_line)
{
    int i;
    for (i = 0; i < count; i++) {
        const char *word;
        size_t length = next_word(t, &word, same_line);
        if (word_number(word, length, &out[i]) != 0) return -1;
    }
    return 0;
}

static void skip_line(text_cursor *t)
{
    while (t->p < t->end && *t->p != '\n') t->p++;
}

/* ASCII STL: "facet normal ... outer loop vertex x y z ... endloop
   endfacet", repeated; every vertex is new (welding joins them). */
static int read_stl_ascii(const char *path, const char *text, size_t size, mesh_builder *b, char *err,
                          size_t err_size)
{
    text_cursor t;
    int corners[3], ncorners = 0, facet_line = 0;
    t.p = text;
    t.end = text + size;
    t.line = 1;
    for (;;) {
        const char *word;
        size_t length = next_word(&t, &word, 0);
        double xyz[3];
        if (length == 0) break;
        if (word_is(word, length, "solid") || word_is(word, length, "endsolid")) {
            skip_line(&t);   /* the solid's name */
        } else if (word_is(word, length, "facet")) {
            facet_line = t.line;
            ncorners = 0;
            skip_line(&t);   /* the normal, which the mesh recomputes */
        } else if (word_is(word, length, "vertex")) {
            if (read_numbers(&t, xyz, 3, 1) != 0) {
                tool_set_error(err, err_size, "%s:%d: a vertex needs 3 numbers", path, t.line);
                return -1;
            }
            if (ncorners == 3) {
                tool_set_error(err, err_size, "%s:%d: a facet with more than 3 vertices", path, t.line);
                return -1;
            }
            corners[ncorners++] = b->mesh->nverts;
            if (add_vertex(b, xyz, t.line) != 0) goto too_big;
        } else if (word_is(word, length, "endfacet")) {
            if (ncorners != 3) {
                tool_set_error(err, err_size, "%s:%d: a facet with %d vertices (STL facets have 3)", path, t.line,
                               ncorners);
                return -1;
            }
            if (add_face(b, corners, 3, facet_line) != 0) goto too_big;
            ncorners = 0;
        } else if (!word_is(word, length, "outer") && !word_is(word, length, "loop") &&
                   !word_is(word, length, "endloop")) {
            tool_set_error(err, err_size, "%s:%d: '%.*s' is not an STL keyword", path, t.line,
                           (int)(length > 40 ? 40 : length), word);
            return -1;
        }
    }
    return 0;
too_big:
    tool_set_error(err, err_size, "%s: out of memory (or more than %d vertices)", path, MESH_MAX_COUNT);
    return -1;
}

/* Binary STL: after the header and count, per triangle a normal, three
   corners (little-endian floats) and two attribute bytes. */
static int read_stl_binary(const char *path, const unsigned char *data, mesh_builder *b, char *err,
                           size_t err_size)
{
    uint32_t ntriangles = read_u32_le(data + 80), t;
    if (ntriangles > MESH_MAX_COUNT / 3) {
        tool_set_error(err, err_size, "%s: %lu triangles; the limit is %d", path, (unsigned long)ntriangles,
                       MESH_MAX_COUNT / 3);
        return -1;
    }
    for (t = 0; t < ntriangles; t++) {
        const unsigned char *triangle = data + 84 + 50 * (size_t)t;
        int corners[3], k, i;
        for (k = 0; k < 3; k++) {
            double xyz[3];
            for (i = 0; i < 3; i++) {
                uint32_t bits = read_u32_le(triangle + 12 + 12 * k + 4 * i);
                float value;
                memcpy(&value, &bits, sizeof value);
                xyz[i] = value;
            }
            corners[k] = b->mesh->nverts;
            if (add_vertex(b, xyz, 0) != 0) goto too_big;
        }
        if (add_face(b, corners, 3, 0) != 0) goto too_big;
    }
    return 0;
too_big:
    tool_set_error(err, err_size, "%s: out of memory", path);
    return -1;
}

/* OFF: the header word, then "nverts nfaces nedges", nverts lines of x y z
   (anything after them, colours or normals, is skipped), nfaces lines of
   "n v0 ... v(n-1)" with 0-based indices (a colour may follow). */
static int read_off(const char *path, const char *text, size_t size, mesh_builder *b, char *err, size_t err_size)
{
    text_cursor t;
    const char *word;
    double counts[3];
    int *corners = NULL, nverts, nfaces, i, k, status = -1;
    t.p = text;
    t.end = text + size;
    t.line = 1;
    if (!is_off_header((const unsigned char *)text, size)) {   /* a .off file without one */
        tool_set_error(err, err_size, "%s:1: an OFF file starts with 'OFF'", path);
        return -1;
    }
    next_word(&t, &word, 0);
    if (read_numbers(&t, counts, 3, 0) != 0 || counts[0] < 0 || counts[1] < 0 || counts[0] > MESH_MAX_COUNT ||
        counts[1] > MESH_MAX_COUNT || counts[0] != floor(counts[0]) || counts[1] != floor(counts[1])) {
        tool_set_error(err, err_size, "%s:%d: an OFF file needs its counts (vertices faces edges) after 'OFF'",
                       path, t.line);
        return -1;
    }
    nverts = (int)counts[0];
    nfaces = (int)counts[1];
    for (i = 0; i < nverts; i++) {
        double xyz[3];
        if (read_numbers(&t, xyz, 3, 0) != 0) {
            tool_set_error(err, err_size, "%s:%d: vertex %d of %d: needs x y z", path, t.line, i + 1, nverts);
            return -1;
        }
        if (add_vertex(b, xyz, t.line) != 0) goto too_big;
        skip_line(&t);
    }
    for (i = 0; i < nfaces; i++) {
        double number;
        if (read_numbers(&t, &number, 1, 0) != 0 || number < 3 || number > 1000000 || number != floor(number)) {
            tool_set_error(err, err_size, "%s:%d: face %d of %d: needs its corner count (3 or more), then the "
                           "corners", path, t.line, i + 1, nfaces);
            goto done;
        }
        free(corners);
        if (!(corners = (int *)malloc((size_t)number * sizeof(int)))) goto too_big;
        for (k = 0; k < (int)number; k++) {
            double v;
            if (read_numbers(&t, &v, 1, 1) != 0 || v < 0 || v >= nverts || v != floor(v)) {
                tool_set_error(err, err_size, "%s:%d: face %d: corner %d is not a vertex index from 0 to %d",
                               path, t.line, i + 1, k + 1, nverts - 1);
                goto done;
            }
            corners[k] = (int)v;
        }
        if (add_face(b, corners, (int)number, t.line) != 0) goto too_big;
        skip_line(&t);
    }
    status = 0;
    goto done;
too_big:
    tool_set_error(err, err_size, "%s: out of memory", path);
done:
    free(corners);
    return status;
}

/* ======================================================================== */
/* Welding                                                                  */
/* ======================================================================== */

/* Which vertex each vertex becomes: the first earlier one (by index) within
   `tolerance` times the bounding box diagonal, looked for in a grid of
   cells at least that size (the 27 cells around a vertex hold every
   candidate), or itself when there is none. map[v] is a new, compact index
   in the order of the first vertex of each group. Non-finite positions are
   never merged (the library names them). Returns the number of vertices
   after welding, or -1 when out of memory. */
static int weld_map(const float *pos, int nverts, double tolerance, int *map)
{
    double low[3] = {DBL_MAX, DBL_MAX, DBL_MAX}, high[3] = {-DBL_MAX, -DBL_MAX, -DBL_MAX}, diagonal = 0.0, cell,
           distance;
    size_t table_size = 16, mask;
    int64_t *keys;
    int *heads, *next, *representative, v, k, count = 0;
    for (v = 0; v < nverts; v++)
        for (k = 0; k < 3; k++)
            if (isfinite(pos[3 * (size_t)v + k])) {
                if (pos[3 * (size_t)v + k] < low[k]) low[k] = pos[3 * (size_t)v + k];
                if (pos[3 * (size_t)v + k] > high[k]) high[k] = pos[3 * (size_t)v + k];
            }
    for (k = 0; k < 3; k++)
        if (high[k] >= low[k]) diagonal += (high[k] - low[k]) * (high[k] - low[k]);
    diagonal = sqrt(diagonal);
    distance = tolerance * diagonal;
    /* Cells of at least a millionth of the diagonal keep cell numbers below
       about 1e6, whatever the tolerance; all at one point: one cell. */
    cell = diagonal > 0.0 ? diagonal * (tolerance > 1e-6 ? tolerance : 1e-6) : 1.0;
    while (table_size < 2 * (size_t)nverts) table_size *= 2;
    mask = table_size - 1;
    keys = (int64_t *)malloc(table_size * sizeof *keys);
    heads = (int *)malloc(table_size * sizeof *heads);
    next = (int *)malloc(((size_t)nverts + 1) * sizeof *next);
    representative = (int *)malloc(((size_t)nverts + 1) * sizeof *representative);
    if (!keys || !heads || !next || !representative) {
        count = -1;
        goto done;
    }
    for (k = 0; k < (int)table_size; k++) heads[k] = -1;
    for (v = 0; v < nverts; v++) {
        const float *p = pos + 3 * (size_t)v;
        int64_t c[3], d[3];
        int found = -1;
        if (!isfinite(p[0]) || !isfinite(p[1]) || !isfinite(p[2])) {
            map[v] = count++;
            continue;
        }
        for (k = 0; k < 3; k++) c[k] = (int64_t)floor((p[k] - low[k]) / cell) + 1;
        for (d[0] = -1; d[0] <= 1 && found < 0; d[0]++)
            for (d[1] = -1; d[1] <= 1 && found < 0; d[1]++)
                for (d[2] = -1; d[2] <= 1 && found < 0; d[2]++) {
                    int64_t key = ((c[0] + d[0]) << 42) | ((c[1] + d[1]) << 21) | (c[2] + d[2]);
                    size_t slot = (size_t)(((uint64_t)key * 0x9E3779B97F4A7C15ull) >> 20) & mask;
                    int r;
                    while (heads[slot] >= 0 && keys[slot] != key) slot = (slot + 1) & mask;
                    for (r = heads[slot]; r >= 0 && found < 0; r = next[r]) {
                        const float *q = pos + 3 * (size_t)representative[r];
                        double dx = (double)p[0] - q[0], dy = (double)p[1] - q[1], dz = (double)p[2] - q[2];
                        if (dx * dx + dy * dy + dz * dz <= distance * distance) found = r;
                    }
                }
        if (found >= 0) {
            map[v] = found;
        } else {
            int64_t key = (c[0] << 42) | (c[1] << 21) | c[2];
            size_t slot = (size_t)(((uint64_t)key * 0x9E3779B97F4A7C15ull) >> 20) & mask;
            while (heads[slot] >= 0 && keys[slot] != key) slot = (slot + 1) & mask;
            keys[slot] = key;
            representative[count] = v;
            next[count] = heads[slot];
            heads[slot] = count;
            map[v] = count++;
        }
    }
done:
    free(keys);
    free(heads);
    free(next);
    free(representative);
    return count;
}

int mesh_weld(obj_mesh *mesh, double tolerance)
{
    int *map = (int *)malloc(((size_t)mesh->nverts + 1) * sizeof(int)), count, v, c;
    if (!map || (count = weld_map(mesh->pos, mesh->nverts, tolerance, map)) < 0) {
        free(map);
        return -1;
    }
    /* Each group keeps its first vertex's position and line; groups are
       numbered in the order of their first vertices, so moving those down
       in index order overwrites nothing still needed. */
    for (v = 0, c = 0; v < mesh->nverts; v++)
        if (map[v] == c) {
            memmove(mesh->pos + 3 * (size_t)c, mesh->pos + 3 * (size_t)v, 3 * sizeof(float));
            mesh->vert_line[c] = mesh->vert_line[v];
            c++;
        }
    for (c = 0; c < mesh->ncorners; c++) mesh->corner_vert[c] = map[mesh->corner_vert[c]];
    v = mesh->nverts - count;
    mesh->nverts = count;
    free(map);
    return v;
}

/* Every vertex in at most one face corner, more than one face, and some
   positions repeated: faces exported each with its own vertices. */
static int looks_unwelded(const obj_mesh *mesh)
{
    unsigned char *used;
    int *map, c, unwelded = 1;
    if (mesh->nfaces < 2) return 0;
    used = (unsigned char *)calloc((size_t)mesh->nverts + 1, 1);
    if (!used) return 0;
    for (c = 0; c < mesh->ncorners && unwelded; c++)
        if (used[mesh->corner_vert[c]]++) unwelded = 0;
    free(used);
    if (!unwelded) return 0;
    map = (int *)malloc(((size_t)mesh->nverts + 1) * sizeof(int));
    unwelded = map && weld_map(mesh->pos, mesh->nverts, 0.0, map) < mesh->nverts;
    free(map);
    return unwelded;
}

/* ======================================================================== */
/* Reading                                                                  */
/* ======================================================================== */

int mesh_read(const char *path, obj_mesh *out, char *err, size_t err_size)
{
    unsigned char *data;
    size_t size;
    int status;
    memset(out, 0, sizeof *out);
    tool_stage("reading %s", tool_basename(path));
    if (tool_read_file(path, &data, &size, err, err_size) != 0) return -1;
    status = mesh_read_data(path, data, size, out, err, err_size);
    free(data);
    return status;
}

int mesh_read_data(const char *path, const unsigned char *data, size_t size, obj_mesh *out, char *err,
                   size_t err_size)
{
    mesh_builder builder;
    mesh_format format;
    int status = -1, is_stl;
    memset(out, 0, sizeof *out);
    format = detect_format(path, data, size);
    is_stl = format == MESH_STL_ASCII || format == MESH_STL_BINARY;
    if (format > MESH_OFF) {
        refuse_format(path, format, format_by_extension(path) != (int)format, err, err_size);
    } else if (format == MESH_OBJ) {
        status = obj_read_text(path, (const char *)data, size, out, err, err_size);
    } else if (builder_start(&builder, out) != 0) {
        tool_set_error(err, err_size, "%s: out of memory", path);
    } else if (format == MESH_STL_BINARY) {
        status = read_stl_binary(path, data, &builder, err, err_size);
    } else if (format == MESH_STL_ASCII && looks_binary(data, size)) {
        refuse_broken_binary_stl(path, data, size, err, err_size);
    } else if (format == MESH_STL_ASCII) {
        status = read_stl_ascii(path, (const char *)data, size, &builder, err, err_size);
    } else {
        status = read_off(path, (const char *)data, size, &builder, err, err_size);
    }
    if (status == 0 && out->nfaces == 0) {   /* (obj_read_text says so itself) */
        tool_set_error(err, err_size, "%s: no faces", path);
        status = -1;
    }
    /* STL always (exactly equal positions), the others on request. */
    if (status == 0 && (weld_requested || is_stl) &&
        mesh_weld(out, weld_requested ? TOOL_WELD_TOLERANCE : 0.0) < 0) {
        tool_set_error(err, err_size, "%s: out of memory", path);
        status = -1;
    }
    if (status != 0) obj_free(out);
    else if (!weld_requested && !is_stl && looks_unwelded(out))
        tool_note("%s looks unwelded (each face has its own vertices): try --weld", path);
    return status;
}
