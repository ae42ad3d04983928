/* tests/test_3_image.c - unit tests for section 3 of tiledtex.h: images,
   rotation, compositing, downsampling and the minimum-error cut. Run by
   run_image_tests() (tests/test_common.c calls it). */
#include "test_common.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ------------------------------------------------------------------------ */
/* 3. Image                                                                 */
/* ------------------------------------------------------------------------ */

static void fill_random(tt_image *im, unsigned seed)
{
    size_t i, n = (size_t)im->width * im->height * 4;
    lcg_seed(seed);
    for (i = 0; i < n; i++) im->pixels[i] = (float)lcg_unit();
}

static void test_image_basics(void)
{
    tt_image im;
    counter cnt;
    tt_allocator al = make_allocator(&cnt, -1);
    int ch, x, y, k, bad;
    unsigned char data[7 * 5 * 4 + 64], back[7 * 5 * 4];

    /* create: sizes */
    CHECK(tt_image_create(&im, 0, 5, NULL) == TT_ERROR_INVALID_ARGUMENT && im.pixels == NULL, "width 0 rejected");
    CHECK(tt_image_create(&im, 5, 0, NULL) == TT_ERROR_INVALID_ARGUMENT && im.pixels == NULL, "height 0 rejected");
    CHECK(tt_image_create(&im, -3, 5, NULL) == TT_ERROR_INVALID_ARGUMENT && im.pixels == NULL, "width -3 rejected");
    CHECK(tt_image_create(&im, 5, -1, NULL) == TT_ERROR_INVALID_ARGUMENT && im.pixels == NULL, "height -1 rejected");
    CHECK(tt_image_create(&im, TT_MAX_IMAGE_SIZE + 1, 1, NULL) == TT_ERROR_TOO_LARGE && im.pixels == NULL,
          "width TT_MAX_IMAGE_SIZE+1 should be TT_ERROR_TOO_LARGE");
    CHECK(tt_image_create(&im, 1, TT_MAX_IMAGE_SIZE + 1, NULL) == TT_ERROR_TOO_LARGE && im.pixels == NULL,
          "height TT_MAX_IMAGE_SIZE+1 should be TT_ERROR_TOO_LARGE");
    CHECK(tt_image_create(NULL, 4, 4, NULL) == TT_ERROR_INVALID_ARGUMENT, "image NULL rejected");
    CHECK(tt_image_create(&im, TT_MAX_IMAGE_SIZE, 1, &al) == TT_OK && im.width == TT_MAX_IMAGE_SIZE,
          "TT_MAX_IMAGE_SIZE x 1 is allowed");
    tt_image_free(&im);
    {
        counter fc;
        tt_allocator fail = make_allocator(&fc, 0);
        CHECK(tt_image_create(&im, 4, 4, &fail) == TT_ERROR_OUT_OF_MEMORY && im.pixels == NULL && fc.live == 0,
              "tt_image_create with a failing allocator: clean TT_ERROR_OUT_OF_MEMORY");
    }
    CHECK(tt_image_create(&im, 3, 2, &al) == TT_OK, "create 3x2");
    bad = 0;
    for (k = 0; k < 3 * 2 * 4; k++) bad += im.pixels[k] != 0.0f;
    CHECK(bad == 0 && im.width == 3 && im.height == 2, "a new image is zero-filled, %d non-zero values", bad);
    tt_image_free(&im);
    CHECK(im.pixels == NULL && im.width == 0, "tt_image_free resets the image");
    tt_image_free(&im);   /* twice is harmless */
    tt_image_free(NULL);

    /* from_bytes / to_rgba8 round trip, 1..4 channels, tight and padded stride */
    for (ch = 1; ch <= 4; ch++) {
        int stride_pad;
        for (stride_pad = 0; stride_pad <= 5; stride_pad += 5) {
            int stride = stride_pad ? 7 * ch + stride_pad : 0, rs = 7 * ch + stride_pad;
            lcg_seed(ch * 10 + stride_pad);
            for (k = 0; k < (int)sizeof data; k++) data[k] = (unsigned char)lcg_below(256);
            data[0] = 0;
            data[1] = 255;
            CHECK(tt_image_from_bytes(&im, data, 7, 5, ch, stride, &al) == TT_OK, "from_bytes ch %d", ch);
            memset(back, 0x11, sizeof back);
            tt_image_to_rgba8(&im, back);
            bad = 0;
            for (y = 0; y < 5; y++)
                for (x = 0; x < 7; x++) {
                    const unsigned char *p = data + y * rs + x * ch, *q = back + (y * 7 + x) * 4;
                    const float *f = px(&im, x, y);
                    unsigned char e[4];
                    if (ch <= 2) { e[0] = e[1] = e[2] = p[0]; e[3] = ch == 2 ? p[1] : 255; }
                    else { e[0] = p[0]; e[1] = p[1]; e[2] = p[2]; e[3] = ch == 4 ? p[3] : 255; }
                    for (k = 0; k < 4; k++) {
                        if (q[k] != e[k]) bad++;
                        if (!near(f[k], e[k] / 255.0, 1e-7)) bad++;
                    }
                }
            CHECK(bad == 0, "round trip with %d channels, stride %d: %d values differ", ch, stride, bad);
            tt_image_free(&im);
        }
    }
    CHECK(tt_image_from_bytes(&im, data, 7, 5, 0, 0, &al) == TT_ERROR_INVALID_ARGUMENT, "0 channels rejected");
    CHECK(tt_image_from_bytes(&im, data, 7, 5, 5, 0, &al) == TT_ERROR_INVALID_ARGUMENT, "5 channels rejected");
    CHECK(tt_image_from_bytes(&im, data, 7, 5, 3, 20, &al) == TT_ERROR_INVALID_ARGUMENT,
          "stride smaller than width*channels rejected");
    CHECK(tt_image_from_bytes(&im, NULL, 7, 5, 3, 0, &al) == TT_ERROR_INVALID_ARGUMENT, "data NULL rejected");
    CHECK(tt_image_from_bytes(&im, data, 0, 5, 3, 0, &al) == TT_ERROR_INVALID_ARGUMENT, "width 0 rejected");
    /* to_rgba8 rounds and clamps */
    CHECK(tt_image_create(&im, 2, 1, &al) == TT_OK, "create 2x1");
    im.pixels[0] = -0.5f; im.pixels[1] = 1.5f; im.pixels[2] = 0.5f; im.pixels[3] = (float)NAN;
    im.pixels[4] = 0.2f / 255.0f; im.pixels[5] = 0.6f / 255.0f; im.pixels[6] = 254.6f / 255.0f; im.pixels[7] = 1.0f;
    tt_image_to_rgba8(&im, back);
    CHECK(back[0] == 0 && back[1] == 255 && back[2] == 128 && back[3] == 0 && back[4] == 0 && back[5] == 1 &&
              back[6] == 255 && back[7] == 255,
          "to_rgba8 clamp/round: got %d %d %d %d %d %d %d %d", back[0], back[1], back[2], back[3], back[4], back[5],
          back[6], back[7]);
    tt_image_free(&im);

    /* bilinear */
    CHECK(tt_image_create(&im, 5, 4, &al) == TT_OK, "create 5x4");
    fill_random(&im, 77);
    {
        int bad_centre = 0, bad_half = 0, bad_clamp = 0;
        float s[4];
        for (y = 0; y < 4; y++)
            for (x = 0; x < 5; x++) {
                tt_image_sample_bilinear(&im, x + 0.5f, y + 0.5f, s);
                if (memcmp(s, px(&im, x, y), sizeof s) != 0) bad_centre++;
                if (x + 1 < 5) {
                    tt_image_sample_bilinear(&im, x + 1.0f, y + 0.5f, s);
                    for (k = 0; k < 4; k++)
                        if (!near(s[k], 0.5 * (px(&im, x, y)[k] + px(&im, x + 1, y)[k]), 1e-6)) bad_half++;
                }
                if (y + 1 < 4) {
                    tt_image_sample_bilinear(&im, x + 0.5f, y + 1.0f, s);
                    for (k = 0; k < 4; k++)
                        if (!near(s[k], 0.5 * (px(&im, x, y)[k] + px(&im, x, y + 1)[k]), 1e-6)) bad_half++;
                }
                if (x + 1 < 5 && y + 1 < 4) {
                    tt_image_sample_bilinear(&im, x + 1.0f, y + 1.0f, s);
                    for (k = 0; k < 4; k++)
                        if (!near(s[k], 0.25 * (px(&im, x, y)[k] + px(&im, x + 1, y)[k] + px(&im, x, y + 1)[k] +
                                                px(&im, x + 1, y + 1)[k]), 1e-6))
                            bad_half++;
                }
            }
        CHECK(bad_centre == 0, "bilinear at texel centres: %d texels differ", bad_centre);
        CHECK(bad_half == 0, "bilinear halfway: %d values differ from the average", bad_half);
        tt_image_sample_bilinear(&im, -10.0f, -3.0f, s);
        bad_clamp += memcmp(s, px(&im, 0, 0), sizeof s) != 0;
        tt_image_sample_bilinear(&im, 100.0f, 50.0f, s);
        bad_clamp += memcmp(s, px(&im, 4, 3), sizeof s) != 0;
        tt_image_sample_bilinear(&im, 0.1f, 2.5f, s);   /* left of the first centre: clamps in x */
        bad_clamp += memcmp(s, px(&im, 0, 2), sizeof s) != 0;
        tt_image_sample_bilinear(&im, 3.5f, 3.9f, s);   /* below the last centre */
        bad_clamp += memcmp(s, px(&im, 3, 3), sizeof s) != 0;
        CHECK(bad_clamp == 0, "bilinear clamps outside the image: %d cases wrong", bad_clamp);
        /* far outside: still the nearest edge texel */
        tt_image_sample_bilinear(&im, -1e30f, 1e30f, s);
        CHECK(memcmp(s, px(&im, 0, 3), sizeof s) == 0,
              "bilinear at (-1e30, 1e30) should clamp to the bottom-left texel (0,3): got %g, texel (0,3) %g, (0,0) %g",
              s[0], px(&im, 0, 3)[0], px(&im, 0, 0)[0]);
        tt_image_sample_bilinear(&im, 3e9f, 2.5f, s);
        CHECK(memcmp(s, px(&im, 4, 2), sizeof s) == 0,
              "bilinear at (3e9, 2.5) should clamp to the right texel (4,2): got %g, texel (4,2) %g, (0,2) %g", s[0],
              px(&im, 4, 2)[0], px(&im, 0, 2)[0]);
        tt_image_sample_bilinear(&im, (float)NAN, 1.0f, s);   /* must not crash */
        CHECK(s[0] == s[0], "bilinear at NaN should return a number");
    }
    tt_image_free(&im);
    CHECK(cnt.live == 0, "image basics: %ld allocations leaked", cnt.live);
}

/* Naive one-step counter-clockwise turn: (x, y) of a W x H image goes to
   (y, W-1-x) of an H x W image. */
static void naive_rotate(int turns, int w, int h, int x, int y, int *ox, int *oy)
{
    int t = ((turns % 4) + 4) % 4, i;
    for (i = 0; i < t; i++) {
        int nx = y, ny = w - 1 - x, tmp = w;
        x = nx;
        y = ny;
        w = h;
        h = tmp;
    }
    *ox = x;
    *oy = y;
}

static void test_rotate(void)
{
    tt_image src, dst;
    counter cnt;
    tt_allocator al = make_allocator(&cnt, -1);
    int turns, x, y, W = 7, H = 4;
    CHECK(tt_image_create(&src, W, H, &al) == TT_OK, "create");
    fill_random(&src, 3);
    for (turns = -5; turns <= 7; turns++) {
        int bad_coords = 0, bad_pixels = 0, odd = (((turns % 4) + 4) % 4) & 1;
        tt_result r;
        for (y = -2; y < H + 2; y++)
            for (x = -2; x < W + 2; x++) {
                int ax, ay, bx, by;
                tt_rotate_coords(turns, W, H, x, y, &ax, &ay);
                naive_rotate(turns, W, H, x, y, &bx, &by);
                if (ax != bx || ay != by) bad_coords++;
            }
        CHECK(bad_coords == 0, "tt_rotate_coords(%d) differs from the naive rotation at %d points", turns, bad_coords);
        r = tt_image_rotate90(&src, turns, &dst, &al);
        CHECK(r == TT_OK, "rotate90(%d) returned %d", turns, r);
        if (r != TT_OK) continue;
        CHECK(dst.width == (odd ? H : W) && dst.height == (odd ? W : H), "rotate90(%d): size %dx%d", turns, dst.width,
              dst.height);
        for (y = 0; y < H; y++)
            for (x = 0; x < W; x++) {
                int bx, by;
                naive_rotate(turns, W, H, x, y, &bx, &by);
                if (memcmp(px(&dst, bx, by), px(&src, x, y), 4 * sizeof(float)) != 0) bad_pixels++;
            }
        CHECK(bad_pixels == 0, "tt_image_rotate90(%d): %d pixels differ from the naive rotation", turns, bad_pixels);
        if (turns == 1) {
            /* one CCW turn: top-left goes to bottom-left; top-right to top-left */
            CHECK(memcmp(px(&dst, 0, dst.height - 1), px(&src, 0, 0), 16) == 0,
                  "one CCW turn should send the top-left pixel to the bottom-left");
            CHECK(memcmp(px(&dst, 0, 0), px(&src, W - 1, 0), 16) == 0,
                  "one CCW turn should send the top-right pixel to the top-left");
        }
        if (turns % 4 == 0)
            CHECK(memcmp(dst.pixels, src.pixels, sizeof(float) * 4 * W * H) == 0, "rotate90(%d) is the identity",
                  turns);
        tt_image_free(&dst);
    }
    /* composition: 1 turn then 3 turns = identity */
    {
        tt_image a, b;
        if (tt_image_rotate90(&src, 1, &a, &al) == TT_OK) {
            if (tt_image_rotate90(&a, 3, &b, &al) == TT_OK) {
                CHECK(b.width == W && memcmp(b.pixels, src.pixels, sizeof(float) * 4 * W * H) == 0,
                      "1 + 3 quarter turns should be the identity");
                tt_image_free(&b);
            }
            tt_image_free(&a);
        }
    }
    CHECK(tt_image_rotate90(&src, 1, &src, &al) == TT_ERROR_INVALID_ARGUMENT, "rotating in place is rejected");
    CHECK(tt_image_rotate90(NULL, 1, &dst, &al) == TT_ERROR_INVALID_ARGUMENT, "src NULL rejected");
    tt_image_free(&src);
    CHECK(cnt.live == 0, "rotate: %ld allocations leaked", cnt.live);
}

static void test_over_downsample(void)
{
    tt_image a, b, c, d;
    counter cnt;
    tt_allocator al = make_allocator(&cnt, -1);
    int x, y, k, bad;
    float dst[4] = {0.3f, 0.6f, 0.9f, 0.8f}, keep[4], src[4];

    memcpy(keep, dst, sizeof dst);
    src[0] = src[1] = src[2] = src[3] = 0.0f;
    tt_rgba_over(dst, src);
    CHECK(memcmp(dst, keep, sizeof dst) == 0, "over with alpha 0 leaves dst exactly");
    src[0] = 0.123f; src[1] = 0.456f; src[2] = 0.789f; src[3] = 1.0f;
    tt_rgba_over(dst, src);
    CHECK(memcmp(dst, src, sizeof dst) == 0, "over with alpha 1 gives src exactly: got %g %g %g %g", dst[0], dst[1],
          dst[2], dst[3]);
    memcpy(dst, keep, sizeof dst);
    src[0] = 0.1f; src[1] = 0.2f; src[2] = 0.3f; src[3] = 0.5f;
    tt_rgba_over(dst, src);
    bad = 0;
    for (k = 0; k < 4; k++) bad += !near(dst[k], src[k] + 0.5 * keep[k], 1e-6);
    CHECK(bad == 0, "over with alpha .5: expected src + .5 dst, %d channels differ", bad);

    CHECK(tt_image_create(&a, 6, 4, &al) == TT_OK && tt_image_create(&b, 6, 4, &al) == TT_OK, "create");
    fill_random(&a, 11);
    fill_random(&b, 12);
    for (y = 0; y < 4; y++)
        for (x = 0; x < 6; x++) {
            float *p = px(&b, x, y);
            int kind = (x + y) % 3;
            p[3] = kind == 0 ? 0.0f : kind == 1 ? 1.0f : 0.5f;
            if (kind == 0) p[0] = p[1] = p[2] = 0.0f;
            for (k = 0; k < 3; k++) p[k] *= p[3];   /* premultiplied */
        }
    CHECK(tt_image_create(&c, 6, 4, &al) == TT_OK, "create");
    memcpy(c.pixels, a.pixels, sizeof(float) * 4 * 24);
    CHECK(tt_image_over(&a, &b) == TT_OK, "tt_image_over");
    bad = 0;
    for (y = 0; y < 4; y++)
        for (x = 0; x < 6; x++) {
            const float *s = px(&b, x, y), *o = px(&c, x, y), *r = px(&a, x, y);
            for (k = 0; k < 4; k++) {
                if (s[3] == 0.0f) bad += r[k] != o[k];
                else if (s[3] == 1.0f) bad += r[k] != s[k];
                else bad += !near(r[k], s[k] + (1.0 - s[3]) * o[k], 1e-6);
            }
        }
    CHECK(bad == 0, "tt_image_over: %d values differ from the formula", bad);
    tt_image_free(&c);
    CHECK(tt_image_create(&c, 5, 4, &al) == TT_OK, "create");
    CHECK(tt_image_over(&a, &c) == TT_ERROR_INVALID_ARGUMENT, "over with different sizes rejected");
    CHECK(tt_image_over(NULL, &c) == TT_ERROR_INVALID_ARGUMENT, "over NULL rejected");
    tt_image_free(&c);

    /* downsample against a naive box */
    CHECK(tt_image_downsample2(&a, &d, &al) == TT_OK, "downsample 6x4");
    CHECK(d.width == 3 && d.height == 2, "downsample size %dx%d", d.width, d.height);
    bad = 0;
    for (y = 0; y < 2; y++)
        for (x = 0; x < 3; x++)
            for (k = 0; k < 4; k++) {
                double e = (px(&a, 2 * x, 2 * y)[k] + px(&a, 2 * x + 1, 2 * y)[k] + px(&a, 2 * x, 2 * y + 1)[k] +
                            px(&a, 2 * x + 1, 2 * y + 1)[k]) / 4.0;
                bad += !near(px(&d, x, y)[k], e, 1e-6);
            }
    CHECK(bad == 0, "downsample2: %d values differ from the naive box", bad);
    tt_image_free(&d);
    CHECK(tt_image_create(&c, 5, 4, &al) == TT_OK, "create");
    CHECK(tt_image_downsample2(&c, &d, &al) == TT_ERROR_INVALID_ARGUMENT && d.pixels == NULL, "odd width rejected");
    tt_image_free(&c);
    CHECK(tt_image_create(&c, 4, 3, &al) == TT_OK, "create");
    CHECK(tt_image_downsample2(&c, &d, &al) == TT_ERROR_INVALID_ARGUMENT && d.pixels == NULL, "odd height rejected");
    tt_image_free(&c);
    CHECK(tt_image_create(&c, 2, 2, &al) == TT_OK, "create");
    CHECK(tt_image_downsample2(&c, &d, &al) == TT_OK && d.width == 1 && d.height == 1, "2x2 -> 1x1");
    tt_image_free(&d);
    CHECK(tt_image_downsample2(&c, &c, &al) == TT_ERROR_INVALID_ARGUMENT, "in place rejected");
    tt_image_free(&c);
    tt_image_free(&a);
    tt_image_free(&b);
    CHECK(cnt.live == 0, "over/downsample: %ld allocations leaked", cnt.live);
}

/* Brute force over all paths; ties: smallest last row, then smallest row
   one column earlier, and so on (what "ties go to the smaller row" gives
   when each step prefers the smaller row). */
static int brute_cut(const float *cost, int w, int h, const int *lo, const int *hi, int *best_path, double *best_cost)
{
    int path[8], x, found = 0;
    for (x = 0; x < w; x++) path[x] = 0;
    for (;;) {
        int ok = 1;
        double sum = 0.0;
        for (x = 0; x < w && ok; x++) {
            if (path[x] < lo[x] || path[x] > hi[x]) ok = 0;
            if (x > 0 && abs(path[x] - path[x - 1]) > 1) ok = 0;
        }
        if (ok) {
            for (x = 0; x < w; x++) sum += cost[path[x] * w + x];
            if (!found || sum < *best_cost) {
                found = 1;
                *best_cost = sum;
                memcpy(best_path, path, sizeof(int) * (size_t)w);
            } else if (sum == *best_cost) {
                /* compare from the last column */
                for (x = w - 1; x >= 0; x--) {
                    if (path[x] != best_path[x]) {
                        if (path[x] < best_path[x]) memcpy(best_path, path, sizeof(int) * (size_t)w);
                        break;
                    }
                }
            }
        }
        for (x = 0; x < w; x++) {
            if (++path[x] < h) break;
            path[x] = 0;
        }
        if (x == w) break;
    }
    return found;
}

static void test_min_error_cut(void)
{
    int trial, bad_cost = 0, bad_path = 0, bad_valid = 0, bad_result = 0, nvalid = 0, ninvalid = 0;
    counter cnt;
    tt_allocator al = make_allocator(&cnt, -1);
    lcg_seed(2024);
    for (trial = 0; trial < 3000; trial++) {
        int w = 1 + lcg_below(6), h = 1 + lcg_below(5), x, lo[8], hi[8], path[8], best[8], found;
        float cost[64];
        double best_cost = 0.0, got = 0.0;
        tt_result r;
        int integer = trial % 2;   /* integer costs: many ties */
        for (x = 0; x < w * h; x++) cost[x] = integer ? (float)lcg_below(3) : (float)lcg_unit();
        for (x = 0; x < w; x++) {
            int a = lcg_below(h), b = lcg_below(h);
            if (trial % 3 == 0) { a = 0; b = h - 1; }
            lo[x] = a < b ? a : b;
            hi[x] = a < b ? b : a;
        }
        found = brute_cut(cost, w, h, lo, hi, best, &best_cost);
        for (x = 0; x < 8; x++) path[x] = -99;
        r = tt_min_error_cut(cost, w, h, lo, hi, path, &al);
        if (!found) {
            ninvalid++;
            if (r != TT_ERROR_INVALID_ARGUMENT) bad_result++;
            continue;
        }
        nvalid++;
        if (r != TT_OK) { bad_result++; continue; }
        for (x = 0; x < w; x++) {
            if (path[x] < lo[x] || path[x] > hi[x] || (x > 0 && abs(path[x] - path[x - 1]) > 1)) { bad_valid++; break; }
            got += cost[path[x] * w + x];
        }
        if (got != best_cost) bad_cost++;
        else if (memcmp(path, best, sizeof(int) * (size_t)w) != 0) bad_path++;
    }
    CHECK(bad_result == 0, "min_error_cut: %d results differ (expected OK when a path exists, INVALID_ARGUMENT otherwise)",
          bad_result);
    CHECK(bad_valid == 0, "min_error_cut: %d paths leave their range or jump more than one row", bad_valid);
    CHECK(bad_cost == 0, "min_error_cut: %d paths are not of minimal cost", bad_cost);
    CHECK(bad_path == 0, "min_error_cut: %d tied paths differ from the smaller-row choice", bad_path);
    CHECK(nvalid > 1000 && ninvalid > 100, "min_error_cut sampling: %d valid, %d invalid cases", nvalid, ninvalid);
    {
        float cost[4] = {1, 2, 3, 4};
        int lo[2] = {0, 0}, hi[2] = {1, 1}, path[2], badlo[2] = {1, 0}, badhi[2] = {0, 5}, hi01[2] = {0, 1};
        CHECK(tt_min_error_cut(cost, 2, 2, badlo, hi01, path, &al) == TT_ERROR_INVALID_ARGUMENT, "lo > hi rejected");
        CHECK(tt_min_error_cut(cost, 2, 2, lo, badhi, path, &al) == TT_ERROR_INVALID_ARGUMENT, "hi >= height rejected");
        CHECK(tt_min_error_cut(NULL, 2, 2, lo, hi, path, &al) == TT_ERROR_INVALID_ARGUMENT, "cost NULL rejected");
        CHECK(tt_min_error_cut(cost, 0, 2, lo, hi, path, &al) == TT_ERROR_INVALID_ARGUMENT, "width 0 rejected");
        CHECK(tt_min_error_cut(cost, 2, 2, lo, hi, path, NULL) == TT_OK && path[0] == 0 && path[1] == 0,
              "default allocator: path %d %d", path[0], path[1]);
        {
            counter fc;
            tt_allocator fail;
            int k;
            for (k = 0; k < 2; k++) {
                fail = make_allocator(&fc, k);
                CHECK(tt_min_error_cut(cost, 2, 2, lo, hi, path, &fail) == TT_ERROR_OUT_OF_MEMORY && fc.live == 0,
                      "min_error_cut with allocation %d failing: clean TT_ERROR_OUT_OF_MEMORY", k);
            }
        }
    }
    CHECK(cnt.live == 0, "min_error_cut: %ld allocations leaked", cnt.live);
}

void run_image_tests(void)
{
    RUN(test_image_basics);
    RUN(test_rotate);
    RUN(test_over_downsample);
    RUN(test_min_error_cut);
}
