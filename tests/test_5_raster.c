/* tests/test_5_raster.c - unit tests for section 5 of tiledtex.h: triangle
   rasterisation. Run by run_raster_tests() (tests/test_common.c calls it). */
#include "test_common.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ------------------------------------------------------------------------ */
/* 5. Raster                                                                */
/* ------------------------------------------------------------------------ */

#define RW 48
#define RH 36

typedef struct raster_rec {
    int hits[RH][RW];
    float bary[RH][RW][3];
    int out_of_grid;
    int bad_sum;
} raster_rec;

static void raster_cb(int x, int y, const float b[3], void *user)
{
    raster_rec *r = (raster_rec *)user;
    if (x < 0 || y < 0 || x >= RW || y >= RH) { r->out_of_grid++; return; }
    r->hits[y][x]++;
    memcpy(r->bary[y][x], b, sizeof(float) * 3);
    if (!near((double)b[0] + b[1] + b[2], 1.0, 1e-5)) r->bad_sum++;
}

/* Naive: signed distances of (px,py) to the 3 edges, positive inside for
   either winding; returns the smallest; +inside / -outside. */
static double naive_inside(const float *t, double px_, double py_)
{
    double area = ((double)t[2] - t[0]) * ((double)t[5] - t[1]) - ((double)t[4] - t[0]) * ((double)t[3] - t[1]);
    double sgn = area > 0 ? 1.0 : -1.0, best = 1e300;
    int i;
    for (i = 0; i < 3; i++) {
        double ax = t[2 * i], ay = t[2 * i + 1], bx = t[2 * ((i + 1) % 3)], by = t[2 * ((i + 1) % 3) + 1];
        double len = sqrt((bx - ax) * (bx - ax) + (by - ay) * (by - ay));
        double e = ((bx - ax) * (py_ - ay) - (by - ay) * (px_ - ax)) * sgn / (len > 0 ? len : 1);
        if (e < best) best = e;
    }
    return best;
}

static void raster_compare(const float *t, double margin, int *bad_cover, int *bad_bary, int *bad_other)
{
    static raster_rec rec;
    int x, y;
    memset(&rec, 0, sizeof rec);
    tt_raster_triangle(t, RW, RH, raster_cb, &rec);
    *bad_other += rec.out_of_grid + rec.bad_sum;
    for (y = 0; y < RH; y++)
        for (x = 0; x < RW; x++) {
            double d = naive_inside(t, x + 0.5, y + 0.5);
            if (rec.hits[y][x] > 1) (*bad_other)++;
            if (fabs(d) > margin && (d > 0) != (rec.hits[y][x] == 1)) (*bad_cover)++;
            if (rec.hits[y][x]) {
                const float *b = rec.bary[y][x];
                double qx = b[0] * t[0] + b[1] * t[2] + b[2] * t[4], qy = b[0] * t[1] + b[1] * t[3] + b[2] * t[5];
                if (!near(qx, x + 0.5, 2e-3) || !near(qy, y + 0.5, 2e-3)) (*bad_bary)++;
                if (b[0] < -1e-3 || b[1] < -1e-3 || b[2] < -1e-3) (*bad_bary)++;
            }
        }
}

static void test_raster_random(void)
{
    int trial, bad_cover = 0, bad_bary = 0, bad_other = 0, bad_wind = 0;
    static raster_rec r1, r2;
    lcg_seed(555);
    for (trial = 0; trial < 600; trial++) {
        float t[6], u[6];
        int i, x, y;
        for (i = 0; i < 6; i++) {
            double lo = -6.0, hi = (i % 2 ? RH : RW) + 6.0, v = lo + (hi - lo) * lcg_unit();
            /* half the triangles on the 1/256 grid, where the rasteriser's
               snapping changes nothing (margin 1e-3 px); half arbitrary, where
               snapping moves an edge by up to ~0.003 px (margin 6e-3 px) */
            t[i] = trial % 2 ? (float)(floor(v * 256.0) / 256.0) : (float)v;
        }
        raster_compare(t, trial % 2 ? 1e-3 : 6e-3, &bad_cover, &bad_bary, &bad_other);
        /* the other winding: same pixels, weights follow their vertices */
        u[0] = t[0]; u[1] = t[1]; u[2] = t[4]; u[3] = t[5]; u[4] = t[2]; u[5] = t[3];
        memset(&r1, 0, sizeof r1);
        memset(&r2, 0, sizeof r2);
        tt_raster_triangle(t, RW, RH, raster_cb, &r1);
        tt_raster_triangle(u, RW, RH, raster_cb, &r2);
        for (y = 0; y < RH; y++)
            for (x = 0; x < RW; x++) {
                if (r1.hits[y][x] != r2.hits[y][x]) bad_wind++;
                else if (r1.hits[y][x] &&
                         (!near(r1.bary[y][x][0], r2.bary[y][x][0], 1e-5) ||
                          !near(r1.bary[y][x][1], r2.bary[y][x][2], 1e-5) ||
                          !near(r1.bary[y][x][2], r2.bary[y][x][1], 1e-5)))
                    bad_wind++;
            }
    }
    CHECK(bad_cover == 0, "raster: %d pixel centres differ from the naive point-in-triangle test", bad_cover);
    CHECK(bad_bary == 0, "raster: %d barycentrics do not reproduce the pixel centre", bad_bary);
    CHECK(bad_other == 0, "raster: %d pixels outside the grid, hit twice, or weights not summing to 1", bad_other);
    CHECK(bad_wind == 0, "raster: %d pixels differ between the two windings", bad_wind);
    {
        /* degenerate, NaN and empty-grid inputs draw nothing and do not crash
           (NULL xy or fn is a broken precondition now: TT_ASSERT) */
        float flat[6] = {1, 1, 5, 5, 9, 9}, nan_t[6] = {1, 1, 5, 1, 1, 5};
        static raster_rec rr;
        memset(&rr, 0, sizeof rr);
        tt_raster_triangle(flat, RW, RH, raster_cb, &rr);
        nan_t[3] = (float)NAN;
        tt_raster_triangle(nan_t, RW, RH, raster_cb, &rr);
        tt_raster_triangle(flat, 0, RH, raster_cb, &rr);
        {
            int x, y, n = 0;
            for (y = 0; y < RH; y++) for (x = 0; x < RW; x++) n += rr.hits[y][x];
            CHECK(n == 0, "degenerate / NaN triangles should draw nothing, drew %d", n);
        }
    }
}

/* Rasterise a set of triangles; every pixel whose centre is inside the union
   (by `inside`) must be hit exactly once, no pixel twice. */
static void raster_cover(const float *tris, int ntris, int (*inside)(double, double, const void *), const void *ctx,
                         const char *what)
{
    static raster_rec rec;
    int i, x, y, twice = 0, gaps = 0, extra = 0;
    memset(&rec, 0, sizeof rec);
    for (i = 0; i < ntris; i++) tt_raster_triangle(tris + 6 * i, RW, RH, raster_cb, &rec);
    for (y = 0; y < RH; y++)
        for (x = 0; x < RW; x++) {
            int in = inside(x + 0.5, y + 0.5, ctx);
            if (rec.hits[y][x] > 1) twice++;
            if (in == 1 && rec.hits[y][x] == 0) gaps++;
            if (in == 0 && rec.hits[y][x] != 0) extra++;
        }
    CHECK(twice == 0 && gaps == 0 && extra == 0 && rec.out_of_grid == 0,
          "%s: %d pixels hit twice, %d gaps, %d outside hits, %d off-grid", what, twice, gaps, extra, rec.out_of_grid);
}

static int inside_everything(double x, double y, const void *ctx) { (void)x; (void)y; (void)ctx; return 1; }

typedef struct poly_ctx {
    const float *pts;
    int n;
} poly_ctx;

/* 1 inside the convex polygon, 0 outside, 2 within 1e-3 of its boundary. */
static int inside_convex(double x, double y, const void *ctx)
{
    const poly_ctx *p = (const poly_ctx *)ctx;
    int i;
    double best = 1e300;
    for (i = 0; i < p->n; i++) {
        double ax = p->pts[2 * i], ay = p->pts[2 * i + 1];
        double bx = p->pts[2 * ((i + 1) % p->n)], by = p->pts[2 * ((i + 1) % p->n) + 1];
        double len = sqrt((bx - ax) * (bx - ax) + (by - ay) * (by - ay));
        double e = ((bx - ax) * (y - ay) - (by - ay) * (x - ax)) / len;
        if (e < best) best = e;
    }
    if (fabs(best) < 1e-3) return 2;
    return best > 0 ? 1 : 0;
}

static void test_raster_cover(void)
{
    static float tris[6 * 4096];
    int n, i, j, k, variant;
    const double pi = 3.14159265358979323846;
    /* fans around a point: centre at a pixel centre, at a pixel corner, and
       at an arbitrary place; rim points at pixel centres / corners / anywhere */
    for (variant = 0; variant < 6; variant++) {
        float pts[2 * 64];
        int npts = variant < 3 ? 12 : 7;
        double cx = variant % 3 == 0 ? 20.5 : variant % 3 == 1 ? 20.0 : 20.3137, cy = variant % 3 == 0 ? 17.5
                                                                                   : variant % 3 == 1 ? 18.0 : 16.871;
        poly_ctx pc;
        char what[96];
        for (i = 0; i < npts; i++) {
            double a = 2 * pi * i / npts + 0.01 * variant, rx = cx + 14 * cos(a), ry = cy + 14 * sin(a);
            if (variant % 3 == 0) { rx = floor(rx) + 0.5; ry = floor(ry) + 0.5; }
            if (variant % 3 == 1) { rx = floor(rx + 0.5); ry = floor(ry + 0.5); }
            pts[2 * i] = (float)rx;
            pts[2 * i + 1] = (float)ry;
        }
        /* pts go counter-clockwise in a y-up frame = clockwise on screen; the
           convex test needs consistent winding: reverse when negative. */
        {
            double area = 0;
            for (i = 0; i < npts; i++)
                area += pts[2 * i] * pts[2 * ((i + 1) % npts) + 1] - pts[2 * ((i + 1) % npts)] * pts[2 * i + 1];
            if (area < 0)
                for (i = 0; i < npts / 2; i++)
                    for (k = 0; k < 2; k++) {
                        float t = pts[2 * i + k];
                        pts[2 * i + k] = pts[2 * (npts - 1 - i) + k];
                        pts[2 * (npts - 1 - i) + k] = t;
                    }
        }
        n = 0;
        for (i = 0; i < npts; i++) {
            float *t = tris + 6 * n++;
            t[0] = (float)cx; t[1] = (float)cy;
            /* alternate windings inside the fan */
            if (i % 2) { t[2] = pts[2 * i]; t[3] = pts[2 * i + 1]; t[4] = pts[2 * ((i + 1) % npts)]; t[5] = pts[2 * ((i + 1) % npts) + 1]; }
            else { t[4] = pts[2 * i]; t[5] = pts[2 * i + 1]; t[2] = pts[2 * ((i + 1) % npts)]; t[3] = pts[2 * ((i + 1) % npts) + 1]; }
        }
        pc.pts = pts;
        pc.n = npts;
        sprintf(what, "fan variant %d (centre %.4g,%.4g)", variant, cx, cy);
        raster_cover(tris, n, inside_convex, &pc, what);
    }
    /* grids of quads split in two, covering [0,RW] x [0,RH] exactly: lines at
       pixel corners (spacing 4), at pixel centres (spacing 3, offset .5),
       at half pixels (spacing 2.5), and jittered interior vertices */
    for (variant = 0; variant < 8; variant++) {
        float gx[64], gy[64];
        int nx, ny, diag = variant & 1;
        int kind = variant / 2;
        char what[96];
        lcg_seed(100 + variant);
        if (kind == 0) { nx = RW / 4; ny = RH / 4; for (i = 0; i <= nx; i++) gx[i] = 4.0f * i; for (j = 0; j <= ny; j++) gy[j] = 4.0f * j; }
        else if (kind == 1) {
            nx = 0; gx[nx++] = 0; for (i = 0; 0.5 + 3 * i < RW; i++) gx[nx++] = 0.5f + 3.0f * i; gx[nx] = RW;
            ny = 0; gy[ny++] = 0; for (j = 0; 0.5 + 3 * j < RH; j++) gy[ny++] = 0.5f + 3.0f * j; gy[ny] = RH;
        } else if (kind == 2) {
            nx = 0; for (i = 0; 2.5 * i < RW; i++) gx[nx++] = 2.5f * i; gx[nx] = RW;
            ny = 0; for (j = 0; 2.5 * j < RH; j++) gy[ny++] = 2.5f * j; gy[ny] = RH;
        } else { nx = 9; ny = 7; for (i = 0; i <= nx; i++) gx[i] = (float)RW * i / nx; for (j = 0; j <= ny; j++) gy[j] = (float)RH * j / ny; }
        n = 0;
        {
            /* vertex positions, jittered inside for kind 3 */
            static float vx[64][64], vy[64][64];
            for (j = 0; j <= ny; j++)
                for (i = 0; i <= nx; i++) {
                    vx[j][i] = gx[i];
                    vy[j][i] = gy[j];
                    if (kind == 3 && i > 0 && i < nx && j > 0 && j < ny) {
                        vx[j][i] += (float)((lcg_unit() - 0.5) * 2.0);
                        vy[j][i] += (float)((lcg_unit() - 0.5) * 2.0);
                    }
                }
            for (j = 0; j < ny; j++)
                for (i = 0; i < nx; i++) {
                    float a[2], b[2], c[2], d[2], *t;
                    a[0] = vx[j][i]; a[1] = vy[j][i];
                    b[0] = vx[j][i + 1]; b[1] = vy[j][i + 1];
                    c[0] = vx[j + 1][i + 1]; c[1] = vy[j + 1][i + 1];
                    d[0] = vx[j + 1][i]; d[1] = vy[j + 1][i];
                    t = tris + 6 * n++;
                    if (!diag) { t[0] = a[0]; t[1] = a[1]; t[2] = b[0]; t[3] = b[1]; t[4] = c[0]; t[5] = c[1]; }
                    else { t[0] = a[0]; t[1] = a[1]; t[2] = b[0]; t[3] = b[1]; t[4] = d[0]; t[5] = d[1]; }
                    t = tris + 6 * n++;
                    if (!diag) { t[0] = a[0]; t[1] = a[1]; t[2] = d[0]; t[3] = d[1]; t[4] = c[0]; t[5] = c[1]; }
                    else { t[0] = b[0]; t[1] = b[1]; t[2] = d[0]; t[3] = d[1]; t[4] = c[0]; t[5] = c[1]; }
                }
        }
        sprintf(what, "grid kind %d diagonal %d (%dx%d quads)", kind, diag, nx, ny);
        raster_cover(tris, n, inside_everything, NULL, what);
    }
}

void run_raster_tests(void)
{
    RUN(test_raster_random);
    RUN(test_raster_cover);
}
