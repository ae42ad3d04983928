/* fuzz_obj.c - libFuzzer target for the tool's OBJ reader (examples/obj.c),
   fed on into the library when the text parses.

   Build (tests/fuzz/run.sh does this, with the library
   compiled from tests/fuzz/fuzz_library.c):
       clang -g -O1 -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=all \
             -I. -Iexamples -isystem /usr/include/stb \
             tests/fuzz/fuzz_obj.c tests/fuzz/fuzz_library.c examples/obj.c examples/tool_io.c examples/format_number.c -o build/fuzz/fuzz_obj -lm

   The input is the OBJ text itself, exactly `size` bytes with no terminating
   NUL, so AddressSanitizer catches any read past the end. Each input:
     1. obj_parse into a struct full of garbage (the caller need not clear it).
        On failure: -1, a non-empty message, *out zeroed, obj_free still safe.
        On success: every index in range (corners, vt, groups), face sizes >= 3
        adding up to ncorners, group_names[0] == "", strings terminated.
     2. tt_mesh_build with TT_MESH_PERMISSIVE (real assets are messy) and the
        counting allocator of fuzz_common.h; when it builds: stats, boundary
        types, and UVs for quad meshes. Failures are checked by fz_check_error
        and fz_check_null; every allocation must be given back.
     3. obj_write the parsed mesh (with per-corner UVs and normals when every
        corner has one, and its groups and mtllib when their names are plain)
        and parse that text again: the same vertices (bit for bit, NaN for
        NaN), faces, UVs, normals, group names per face and mtllib must come
        back; obj_corner_normals gives unit normals exactly when every corner
        has a finite non-zero one. */
#include "tiledtex.h"
#include "tool.h"
#define FUZZ_NAME "fuzz_obj"
#include "fuzz_common.h"
#include "fuzz_obj_mesh.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int same_float(float a, float b)
{
    return (isnan(a) && isnan(b)) || memcmp(&a, &b, sizeof a) == 0 || (a == 0.0f && b == 0.0f);
}

/* Names that are not expected to survive a round trip, so the round trip
   leaves groups and mtllib out when there is one: control characters (the
   reader turns them into '_') and blanks at either end. A trailing backslash
   does survive: obj_write puts a blank after it. */
static int plain_name(const char *s)
{
    size_t n;
    if (!s) return 1;
    n = strlen(s);
    if (n > 0 && (s[0] == ' ' || s[n - 1] == ' ')) return 0;
    for (; *s; ++s)
        if ((unsigned char)*s < 0x20 || *s == 0x7f) return 0;
    return 1;
}

static size_t bounded_strlen(const char *s, size_t max)
{
    size_t n = 0;
    while (n < max && s[n]) ++n;
    return n;
}

/* Everything obj_parse promises about a successful result; also touches every
   byte of every array so AddressSanitizer sees a short allocation. */
static void check_parsed(const obj_mesh *m)
{
    volatile float sink = 0.0f;
    int i;
    CHECK(m->nverts >= 0 && m->nfaces >= 0 && m->ncorners >= 0 && m->nuvs >= 0 && m->nnormals >= 0,
          "counts %d %d %d %d %d", m->nverts, m->nfaces, m->ncorners, m->nuvs, m->nnormals);
    for (i = 0; i < 3 * m->nverts; ++i) sink += m->pos[i];
    for (i = 0; i < 2 * m->nuvs; ++i) sink += m->uv[i];
    for (i = 0; i < 3 * m->nnormals; ++i) sink += m->normal[i];
    (void)sink;
    fz_check_obj_faces(m);
    for (i = 0; i < m->ncorners; ++i) {
        if (m->corner_uv)
            CHECK(m->corner_uv[i] >= -1 && m->corner_uv[i] < m->nuvs, "corner %d vt %d of %d", i, m->corner_uv[i],
                  m->nuvs);
        if (m->corner_normal)
            CHECK(m->corner_normal[i] >= -1 && m->corner_normal[i] < m->nnormals, "corner %d vn %d of %d", i,
                  m->corner_normal[i], m->nnormals);
    }
    CHECK(m->ngroups >= 1 || m->nfaces == 0, "%d groups for %d faces", m->ngroups, m->nfaces);
    if (m->ngroups >= 1) CHECK(m->group_names[0] && m->group_names[0][0] == '\0', "group_names[0] is not \"\"");
    for (i = 0; i < m->ngroups; ++i) {
        CHECK(m->group_names[i] != NULL, "group name %d is NULL", i);
        (void)strlen(m->group_names[i]);
    }
    if (m->nmaterials >= 1)
        CHECK(m->material_names[0] && m->material_names[0][0] == '\0', "material_names[0] is not \"\"");
    for (i = 0; i < m->nmaterials; ++i) {
        CHECK(m->material_names[i] != NULL, "material name %d is NULL", i);
        (void)strlen(m->material_names[i]);
    }
    if (m->mtllib) (void)strlen(m->mtllib);
}


static void feed_library(const obj_mesh *m)
{
    tt_mesh_desc desc;
    tt_mesh *mesh = (tt_mesh *)&desc;   /* must be set to NULL on failure */
    tt_error err;
    tt_result r;
    fz_alloc a;
    const tt_allocator *alloc = fz_alloc_init(&a, 0);
    desc = obj_mesh_desc(m, TT_MESH_PERMISSIVE);
    memset(&err, 0x55, sizeof err);
    r = tt_mesh_build(&desc, alloc, &mesh, &err);
    if (r != TT_OK) {
        fz_check_null("tt_mesh_build", r, mesh);
        fz_check_error("tt_mesh_build", r, &err, &a);
        fz_check_all_freed(&a);
        return;
    }
    {
        tt_mesh_stats st;
        tt_tile_layout layout;
        uint8_t *types = (uint8_t *)malloc((size_t)mesh->ncorners);
        float *uv = (float *)malloc(sizeof(float) * 2 * (size_t)mesh->ncorners);
        int c;
        if (!types || !uv) abort();
        memset(&layout, 0, sizeof layout);
        memset(&err, 0x55, sizeof err);
        CHECK(tt_mesh_compute_stats(mesh, alloc, &st, &err) == TT_OK, "stats failed: %s", err.message);
        memset(&err, 0x55, sizeof err);
        CHECK(tt_assign_boundaries(mesh, &layout, 1, NULL, types, &err) == TT_OK, "assign_boundaries failed: %s",
              err.message);
        memset(&err, 0x55, sizeof err);
        r = tt_assign_uvs(mesh, &layout, types, uv, &err);
        if (mesh->min_face_size == 4 && mesh->max_face_size == 4) {
            CHECK(r == TT_OK, "assign_uvs on quads: %s", err.message);
            for (c = 0; c < 2 * mesh->ncorners; ++c) CHECK(uv[c] >= 0.0f && uv[c] <= 1.0f, "uv %g", (double)uv[c]);
        } else {
            CHECK(r == TT_ERROR_NOT_QUAD_MESH, "assign_uvs on non-quads returned %d", (int)r);
            fz_check_error("tt_assign_uvs", r, &err, &a);
        }
        free(types);
        free(uv);
        tt_mesh_free(mesh);
        fz_check_all_freed(&a);
    }
}

/* obj_corner_normals: unit normals exactly when every corner names a vn of
   finite, non-zero length. */
static void check_corner_normals(const obj_mesh *m)
{
    float *normals = (float *)&normals;
    int c, usable = m->corner_normal != NULL;
    CHECK(obj_corner_normals("fuzz.obj", m, &normals) == 0, "obj_corner_normals failed (out of memory?)");
    for (c = 0; c < m->ncorners && usable; ++c) {
        const float *v = m->corner_normal[c] >= 0 ? m->normal + 3 * m->corner_normal[c] : NULL;
        double length = v ? sqrt((double)v[0] * v[0] + (double)v[1] * v[1] + (double)v[2] * v[2]) : 0.0;
        usable = length > 0.0 && length < HUGE_VAL;
    }
    CHECK(!normals == !usable, "obj_corner_normals %s normals, every corner %s a usable one", normals ? "gave" : "gave no",
          usable ? "has" : "does not have");
    for (c = 0; c < m->ncorners && normals; ++c) {
        const float *n = normals + 3 * c;
        double length = sqrt((double)n[0] * n[0] + (double)n[1] * n[1] + (double)n[2] * n[2]);
        CHECK(fabs(length - 1.0) < 1e-5, "corner %d's normal has length %.9g", c, length);
    }
    free(normals);
}

static void round_trip(const obj_mesh *m)
{
    tool_buffer buf;
    obj_write_desc d;
    obj_mesh back;
    char err[TOOL_ERROR_SIZE];
    float *corner_uv = NULL, *corner_normal = NULL;
    int i, rc, names_plain;
    if (m->nfaces == 0) return;
    if (m->corner_normal) {
        corner_normal = (float *)malloc(sizeof(float) * 3 * (size_t)m->ncorners);
        if (!corner_normal) abort();
        for (i = 0; i < m->ncorners && m->corner_normal[i] >= 0; ++i)
            memcpy(corner_normal + 3 * i, m->normal + 3 * m->corner_normal[i], 3 * sizeof(float));
        if (i < m->ncorners) {
            free(corner_normal);
            corner_normal = NULL;
        }
    }
    memset(&buf, 0, sizeof buf);
    memset(&d, 0, sizeof d);
    if (m->corner_uv) {
        corner_uv = (float *)malloc(sizeof(float) * 2 * (size_t)m->ncorners);
        if (!corner_uv) abort();
        for (i = 0; i < m->ncorners; ++i) {
            if (m->corner_uv[i] < 0) break;
            corner_uv[2 * i] = m->uv[2 * m->corner_uv[i]];
            corner_uv[2 * i + 1] = m->uv[2 * m->corner_uv[i] + 1];
        }
        if (i < m->ncorners) {
            free(corner_uv);
            corner_uv = NULL;
        }
    }
    d.nverts = m->nverts;
    d.pos = m->pos;
    d.nfaces = m->nfaces;
    d.face_size = m->face_size;
    d.corner_vert = m->corner_vert;
    d.corner_uv = corner_uv;
    d.corner_normal = corner_normal;
    names_plain = plain_name(m->mtllib) && !(m->mtllib && !m->mtllib[0]);
    for (i = 0; i < m->ngroups; ++i) names_plain &= plain_name(m->group_names[i]);
    if (names_plain) {
        d.mtllib = m->mtllib;
        d.face_group = m->face_group;
        d.ngroups = m->ngroups;
        d.group_names = (const char *const *)m->group_names;
    }
    rc = obj_write(&buf, &d);
    if (rc == 0) {
        CHECK(!buf.failed, "obj_write returned 0 with a failed buffer");
        memset(&back, 0xA5, sizeof back);
        err[0] = '\0';
        rc = obj_parse(buf.data, buf.size, &back, err, sizeof err);
        if (rc != 0) {
            fprintf(stderr, "---- written text ----\n%.*s\n----\n", (int)(buf.size < 4000 ? buf.size : 4000),
                    buf.data);
            CHECK(rc == 0, "obj_write output does not parse back: %s", err);
        }
        check_parsed(&back);
        CHECK(back.nverts == m->nverts && back.nfaces == m->nfaces && back.ncorners == m->ncorners,
              "read back %d/%d/%d, wrote %d/%d/%d", back.nverts, back.nfaces, back.ncorners, m->nverts, m->nfaces,
              m->ncorners);
        for (i = 0; i < 3 * m->nverts; ++i)
            CHECK(same_float(back.pos[i], m->pos[i]), "coordinate %d: wrote %.9g, read %.9g", i, (double)m->pos[i],
                  (double)back.pos[i]);
        for (i = 0; i < m->nfaces; ++i) {
            CHECK(back.face_size[i] == m->face_size[i], "face %d size", i);
            CHECK(!names_plain || strcmp(back.group_names[back.face_group[i]], m->group_names[m->face_group[i]]) == 0,
                  "face %d group '%s' read back as '%s'", i, m->group_names[m->face_group[i]],
                  back.group_names[back.face_group[i]]);
        }
        CHECK(!names_plain || (!m->mtllib && !back.mtllib) || (m->mtllib && back.mtllib && strcmp(m->mtllib, back.mtllib) == 0),
              "mtllib '%s' read back as '%s'", m->mtllib ? m->mtllib : "(none)", back.mtllib ? back.mtllib : "(none)");
        for (i = 0; i < m->ncorners; ++i) CHECK(back.corner_vert[i] == m->corner_vert[i], "corner %d vertex", i);
        CHECK(!corner_uv == !back.corner_uv, "UVs %s on the way", corner_uv ? "lost" : "appeared");
        if (corner_uv)
            for (i = 0; i < m->ncorners; ++i) {
                int t = back.corner_uv[i];
                CHECK(t >= 0, "corner %d lost its vt", i);
                CHECK(same_float(back.uv[2 * t], corner_uv[2 * i]) && same_float(back.uv[2 * t + 1], corner_uv[2 * i + 1]),
                      "corner %d uv (%.9g, %.9g) read back as (%.9g, %.9g)", i, (double)corner_uv[2 * i],
                      (double)corner_uv[2 * i + 1], (double)back.uv[2 * t], (double)back.uv[2 * t + 1]);
            }
        CHECK(!corner_normal == !back.corner_normal, "normals %s on the way", corner_normal ? "lost" : "appeared");
        if (corner_normal)
            for (i = 0; i < m->ncorners; ++i) {
                int n = back.corner_normal[i], k;
                CHECK(n >= 0, "corner %d lost its vn", i);
                for (k = 0; k < 3; ++k)
                    CHECK(same_float(back.normal[3 * n + k], corner_normal[3 * i + k]),
                          "corner %d normal component %d: wrote %.9g, read %.9g", i, k,
                          (double)corner_normal[3 * i + k], (double)back.normal[3 * n + k]);
            }
        obj_free(&back);
    }
    buffer_free(&buf);
    free(corner_uv);
    free(corner_normal);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    obj_mesh m;
    char err[TOOL_ERROR_SIZE];
    int rc;
    memset(&m, 0xA5, sizeof m);
    memset(err, 'x', sizeof err);
    rc = obj_parse((const char *)data, size, &m, err, sizeof err);
    if (rc != 0) {
        size_t len = bounded_strlen(err, sizeof err);
        CHECK(rc == -1, "obj_parse returned %d", rc);
        CHECK(len > 0 && len < sizeof err, "message length %lu", (unsigned long)len);
        fz_check_obj_zeroed(&m);
        obj_free(&m);
        return 0;
    }
    check_parsed(&m);
    feed_library(&m);
    check_corner_normals(&m);
    round_trip(&m);
    obj_free(&m);
    return 0;
}
