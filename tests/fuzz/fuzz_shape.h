/* fuzz_shape.h - a small triangle mesh from fuzz input, for the targets
   whose pipelines need a surface to work on (fuzz_hpm.c, fuzz_polycube.c).
   Include after fuzz_common.h.

   Random bytes rarely make a mesh that tt_mesh_build accepts and that is
   large enough for a pipeline's deep stages, so most inputs pick one of a
   few parametric shapes and perturb it; the raw mode still reaches
   whatever a hand-made mesh can be.

   Bytes read (missing bytes read as 0):
       0      shape: low 2 bits 0 grid (open), 1 sphere, 2 torus, 3 raw;
              bit2 extreme floats: each coordinate whose noise byte is
              below 16 becomes fz_extreme_float(noise byte + next byte);
              bit3 reverse every triangle (inside out)
       1      size: grid nx = g + b % 4, ny = g + (b / 4) % 4, g the
              caller's smallest grid side (1: 2 to 32 triangles, 2: 8 to
              50); sphere nu = 3 + b % 4, nv = 2 + (b / 4) % 3 (up to
              36); torus nu = 3 + b % 4, nv = 3 + (b / 4) % 2 (up to 48);
              raw: nverts = 3 + b % 22, up to 24 triangles. Small, so that
              one run of hpm or polycube takes milliseconds
       2      noise amplitude, b / 255 of the shape's size (0..1)
       3      stretch along x, 0.25 + b / 64 (thin and long shapes)
       then   one noise byte per coordinate (b - 128) / 128 * amplitude,
              until the input runs out (then 0)
       raw:   one byte per corner, b % nverts, 3 * (1 + next byte % 24)
              corners; a triangle cut short is dropped */
#ifndef TILEDTEX_FUZZ_SHAPE_H
#define TILEDTEX_FUZZ_SHAPE_H

#include <math.h>

#define FZ_SHAPE_MAX_VERTS 64
#define FZ_SHAPE_MAX_TRIS 128

typedef struct fz_shape {
    float pos[3 * FZ_SHAPE_MAX_VERTS];
    int tri[3 * FZ_SHAPE_MAX_TRIS];
    int nverts, ntris;
    int extreme;    /* some coordinate was replaced by an extreme float */
} fz_shape;

static inline void fz_shape_tri(fz_shape *s, int a, int b, int c)
{
    if (s->ntris >= FZ_SHAPE_MAX_TRIS) return;
    s->tri[3 * s->ntris] = a;
    s->tri[3 * s->ntris + 1] = b;
    s->tri[3 * s->ntris + 2] = c;
    s->ntris++;
}

static inline void fz_shape_quad(fz_shape *s, int a, int b, int c, int d)
{
    fz_shape_tri(s, a, b, c);
    fz_shape_tri(s, a, c, d);
}

/* Fill s from the reader (always something, maybe no triangle); a grid
   has at least grid_side x grid_side cells. */
static inline void fz_shape_read(reader *rd, fz_shape *s, int grid_side)
{
    uint8_t mode = rd_u8(rd), size = rd_u8(rd), amp_b = rd_u8(rd), stretch_b = rd_u8(rd);
    double amp = amp_b / 255.0, stretch = 0.25 + stretch_b / 64.0;
    const double pi = 3.14159265358979323846;
    int i, j, k;
    memset(s, 0, sizeof *s);
    switch (mode & 3) {
    case 0: { /* grid in the xy plane, (nx + 1) x (ny + 1) vertices */
        int nx = grid_side + size % 4, ny = grid_side + (size / 4) % 4;
        for (j = 0; j <= ny; ++j)
            for (i = 0; i <= nx; ++i) {
                float *p = s->pos + 3 * s->nverts++;
                p[0] = (float)i / (float)nx;
                p[1] = (float)j / (float)ny;
                p[2] = 0.0f;
            }
        for (j = 0; j < ny; ++j)
            for (i = 0; i < nx; ++i) {
                int v = j * (nx + 1) + i;
                fz_shape_quad(s, v, v + 1, v + nx + 2, v + nx + 1);
            }
        break;
    }
    case 1: { /* UV sphere: two poles and nv - 1 rings of nu vertices */
        int nu = 3 + size % 4, nv = 2 + (size / 4) % 3;
        s->nverts = 2;
        s->pos[2] = 1.0f;
        s->pos[5] = -1.0f;
        for (j = 1; j < nv; ++j)
            for (i = 0; i < nu; ++i) {
                double th = pi * j / nv, ph = 2 * pi * i / nu;
                float *p = s->pos + 3 * s->nverts++;
                p[0] = (float)(sin(th) * cos(ph));
                p[1] = (float)(sin(th) * sin(ph));
                p[2] = (float)cos(th);
            }
        for (i = 0; i < nu; ++i) {
            int i1 = (i + 1) % nu, last = 2 + (nv - 2) * nu;
            fz_shape_tri(s, 0, 2 + i, 2 + i1);
            fz_shape_tri(s, 1, last + i1, last + i);
            for (j = 0; j + 1 < nv - 1; ++j)
                fz_shape_quad(s, 2 + j * nu + i, 2 + (j + 1) * nu + i, 2 + (j + 1) * nu + i1, 2 + j * nu + i1);
        }
        break;
    }
    case 2: { /* torus, radii 1 and 0.4 */
        int nu = 3 + size % 4, nv = 3 + (size / 4) % 2;
        for (j = 0; j < nv; ++j)
            for (i = 0; i < nu; ++i) {
                double ph = 2 * pi * i / nu, th = 2 * pi * j / nv, r = 1.0 + 0.4 * cos(th);
                float *p = s->pos + 3 * s->nverts++;
                p[0] = (float)(r * cos(ph));
                p[1] = (float)(r * sin(ph));
                p[2] = (float)(0.4 * sin(th));
            }
        for (j = 0; j < nv; ++j)
            for (i = 0; i < nu; ++i) {
                int i1 = (i + 1) % nu, j1 = (j + 1) % nv;
                fz_shape_quad(s, j * nu + i, j * nu + i1, j1 * nu + i1, j1 * nu + i);
            }
        break;
    }
    default: { /* raw: points on a twisted cubic (no three collinear), then noise */
        int ncorners;
        s->nverts = 3 + size % 22;
        for (i = 0; i < s->nverts; ++i) {
            float t = (float)i / (float)s->nverts * 2.0f - 1.0f;
            s->pos[3 * i] = t;
            s->pos[3 * i + 1] = t * t;
            s->pos[3 * i + 2] = t * t * t;
        }
        ncorners = 3 * (1 + rd_u8(rd) % 24);
        for (k = 0; k + 3 <= ncorners && rd_left(rd) >= 3; k += 3) {
            int a = rd_u8(rd) % s->nverts, b = rd_u8(rd) % s->nverts, c = rd_u8(rd) % s->nverts;
            fz_shape_tri(s, a, b, c);
        }
        break;
    }
    }
    for (i = 0; i < 3 * s->nverts; ++i) {
        uint8_t b = rd_u8(rd);
        if ((mode & 4) && b < 16) {
            s->pos[i] = fz_extreme_float((uint8_t)(b + rd_u8(rd)));
            s->extreme = 1;
            continue;
        }
        s->pos[i] += (float)(((int)b - 128) / 128.0 * amp);
        if (i % 3 == 0) s->pos[i] *= (float)stretch;
    }
    if (mode & 8)
        for (i = 0; i < s->ntris; ++i) {
            int t = s->tri[3 * i + 1];
            s->tri[3 * i + 1] = s->tri[3 * i + 2];
            s->tri[3 * i + 2] = t;
        }
}

/* The shape as a tt_mesh (permissive or not): on failure the output and
   the error are checked as every failure is (fuzz_common.h) and the result
   returned, *mesh NULL. */
static inline tt_result fz_shape_build(const fz_shape *s, int permissive, const tt_allocator *alloc,
                                       const fz_alloc *a, tt_mesh **mesh)
{
    tt_mesh_desc desc;
    tt_error err;
    tt_result r;
    memset(&desc, 0, sizeof desc);
    desc.positions = s->pos;
    desc.nverts = s->nverts;
    desc.indices = s->tri;
    desc.nfaces = s->ntris;
    desc.fixed_face_size = 3;
    desc.flags = permissive ? TT_MESH_PERMISSIVE : 0;
    memset(&err, 0x55, sizeof err);
    r = tt_mesh_build(&desc, alloc, mesh, &err);
    if (r != TT_OK) {
        fz_check_null("tt_mesh_build", r, *mesh);
        fz_check_error("tt_mesh_build", r, &err, a);
    }
    return r;
}

#endif /* TILEDTEX_FUZZ_SHAPE_H */
