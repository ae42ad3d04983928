/* fuzz_mesh_file.c - libFuzzer target for the tool's mesh file readers
   (examples/mesh_file.c): format detection, ASCII and binary STL, OFF, the
   refused formats, welding; fed on into the library when the file reads.

   Build (tests/fuzz/run.sh does this, with the library
   compiled from tests/fuzz/fuzz_library.c):
       clang -g -O1 -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=all \
             -I. -Iexamples -isystem /usr/include/stb tests/fuzz/fuzz_mesh_file.c tests/fuzz/fuzz_library.c \
             examples/mesh_file.c examples/obj.c examples/cli.c examples/tool_io.c \
             examples/format_number.c -o build/fuzz/fuzz_mesh_file -lm

   The first byte picks the file's name (its extension: .stl, .off, .obj,
   .STL, .OFF, .ply, .glb or none) and whether --weld is on; the rest is the
   file's content, exactly that many bytes (the reader gets no terminating
   NUL, so AddressSanitizer catches a read past the end). Each input:
     1. mesh_read_data into a struct full of garbage. On failure: -1, one
        line naming the file, *out zeroed, obj_free still safe. On success:
        every index in range, face sizes >= 3 adding up to ncorners, group
        and material 0 named ""; under --weld no two finite vertices at the
        same position.
     2. tt_mesh_build with TT_MESH_PERMISSIVE and the counting allocator;
        when it builds, one quadrangulation step with its corner sources,
        the positions carried by them equal to the linear step's. Every
        allocation must be given back. */
#include "tiledtex.h"
#include "tool.h"
#define FUZZ_NAME "fuzz_mesh_file"
#include "fuzz_common.h"
#include "fuzz_obj_mesh.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *const names[8] = {"fuzz.stl", "fuzz.off", "fuzz.obj", "FUZZ.STL",
                                     "fuzz.OFF", "fuzz.ply", "fuzz.glb", "fuzz"};

static void check_read(const obj_mesh *m, int welded)
{
    volatile float sink = 0.0f;
    int i, j;
    CHECK(m->nverts >= 0 && m->nfaces > 0 && m->ncorners >= 3 * m->nfaces, "counts %d %d %d", m->nverts, m->nfaces,
          m->ncorners);
    for (i = 0; i < 3 * m->nverts; ++i) sink += m->pos[i];
    for (i = 0; i < m->nverts; ++i) CHECK(m->vert_line[i] >= 0, "vertex %d on line %d", i, m->vert_line[i]);
    (void)sink;
    fz_check_obj_faces(m);
    for (i = 0; i < m->nfaces; ++i) CHECK(m->face_line[i] >= 0, "face %d on line %d", i, m->face_line[i]);
    CHECK(m->ngroups >= 1 && m->group_names[0] && m->group_names[0][0] == '\0', "group 0 is not \"\"");
    CHECK(m->nmaterials >= 1 && m->material_names[0] && m->material_names[0][0] == '\0', "material 0 is not \"\"");
    if (welded)
        for (i = 0; i < m->nverts; ++i) {
            const float *p = m->pos + 3 * i;
            if (!isfinite(p[0]) || !isfinite(p[1]) || !isfinite(p[2])) continue;
            for (j = i + 1; j < m->nverts; ++j) {
                const float *q = m->pos + 3 * j;
                CHECK(!(p[0] == q[0] && p[1] == q[1] && p[2] == q[2]), "vertices %d and %d share (%g, %g, %g) after "
                      "welding", i, j, (double)p[0], (double)p[1], (double)p[2]);
            }
        }
}

/* The library on what was read: built permissively, one linear step and
   its sources, which carry the corners' positions to the step's. */
static void feed_library(const obj_mesh *m)
{
    tt_mesh_desc desc = obj_mesh_desc(m, TT_MESH_PERMISSIVE);
    tt_mesh *mesh = (tt_mesh *)&desc, *quads = (tt_mesh *)&desc;
    tt_corner_sources *sources = (tt_corner_sources *)&desc;
    tt_error err;
    tt_result r;
    fz_alloc a;
    const tt_allocator *alloc = fz_alloc_init(&a, 0);
    memset(&err, 0x55, sizeof err);
    r = tt_mesh_build(&desc, alloc, &mesh, &err);
    if (r != TT_OK) {
        fz_check_null("tt_mesh_build", r, mesh);
        fz_check_error("tt_mesh_build", r, &err, &a);
        fz_check_all_freed(&a);
        return;
    }
    memset(&err, 0x55, sizeof err);
    r = tt_mesh_quadrangulate(mesh, TT_SUBDIVIDE_LINEAR, alloc, &quads, &err);
    if (r != TT_OK) {
        fz_check_null("tt_mesh_quadrangulate", r, quads);
        fz_check_error("tt_mesh_quadrangulate", r, &err, &a);
        CHECK(r == TT_ERROR_NON_FINITE || r == TT_ERROR_TOO_LARGE, "quadrangulate: %s", err.message);
        quads = NULL;
    }
    memset(&err, 0x55, sizeof err);
    r = tt_mesh_quadrangulate_sources(mesh, alloc, &sources, &err);
    if (r != TT_OK) {
        fz_check_null("tt_mesh_quadrangulate_sources", r, sources);
        fz_check_error("tt_mesh_quadrangulate_sources", r, &err, &a);
        CHECK(r == TT_ERROR_TOO_LARGE, "quadrangulate_sources: %s", err.message);
        sources = NULL;
    } else if (quads) {
        float *in = (float *)malloc(sizeof(float) * 3 * (size_t)mesh->ncorners);
        float *out = (float *)malloc(sizeof(float) * 3 * (size_t)sources->ncorners);
        int c, k;
        if (!in || !out) abort();
        for (c = 0; c < mesh->ncorners; ++c) memcpy(in + 3 * c, mesh->pos + 3 * mesh->corner_vert[c], 3 * sizeof(float));
        memset(&err, 0x55, sizeof err);
        r = tt_corner_sources_apply(sources, 3, in, out, &err);
        if (r != TT_OK) {
            fz_check_error("tt_corner_sources_apply", r, &err, NULL);
            CHECK(r == TT_ERROR_NON_FINITE, "apply: %s", err.message);
        } else {
            for (c = 0; c < quads->ncorners; ++c)
                for (k = 0; k < 3; ++k) {
                    double want = quads->pos[3 * quads->corner_vert[c] + k], got = out[3 * c + k];
                    CHECK(fabs(want - got) <= 1e-5 * (1.0 + fabs(want)), "corner %d: carried %.9g, the step's %.9g",
                          c, got, want);
                }
        }
        free(in);
        free(out);
    }
    tt_corner_sources_free(sources);
    tt_mesh_free(quads);
    tt_mesh_free(mesh);
    fz_check_all_freed(&a);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    obj_mesh m;
    char err[TOOL_ERROR_SIZE];
    const char *name;
    uint8_t *content;
    size_t length;
    int rc, weld;
    if (size < 1) return 0;
    name = names[data[0] & 7];
    weld = (data[0] >> 3) & 1;
    /* The content in a buffer of its own size: a read past it is caught. */
    length = size - 1;
    content = (uint8_t *)malloc(length ? length : 1);
    if (!content) abort();
    memcpy(content, data + 1, length);
    mesh_set_weld(weld);
    memset(&m, 0xA5, sizeof m);
    memset(err, 'x', sizeof err);
    /* (Notes - "looks unwelded" - pile up to their limit and are dropped.) */
    rc = mesh_read_data(name, content, length, &m, err, sizeof err);
    if (rc != 0) {
        size_t n = 0;
        while (n < sizeof err && err[n]) ++n;
        CHECK(rc == -1, "mesh_read_data returned %d", rc);
        CHECK(n > 0 && n < sizeof err, "message length %lu", (unsigned long)n);
        CHECK(strncmp(err, name, strlen(name)) == 0, "the message does not name the file: %s", err);
        CHECK(!memchr(err, '\n', n), "the message is more than one line: %s", err);
        fz_check_obj_zeroed(&m);
        obj_free(&m);
    } else {
        check_read(&m, weld);
        feed_library(&m);
        obj_free(&m);
    }
    free(content);
    return 0;
}
