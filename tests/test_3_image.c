/* tests/test_3_image.c - unit tests for section 3 of tiledtex.h: images,
   rotation, compositing, downsampling and the minimum-error cut. Run by
   run_image_tests() (tests/test_common.c calls it). */
#include "test_common.h"

#include <limits.h>
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

/* tt_image_create with *out set to a sentinel first, so that a failure
   which forgets to reset it shows. */
static tt_result create_image(int w, int h, const tt_allocator *al, tt_image **out)
{
    *out = (tt_image *)out;
    return tt_image_create(w, h, al, out, NULL);
}

static void test_image_basics(void)
{
    tt_image *im;
    counter cnt;
    tt_allocator al = make_allocator(&cnt, -1);
    int ch, x, y, k, bad, sp;
    unsigned char data[7 * 5 * 4 + 64], back[7 * 5 * 4];
    tt_error err;

    /* create: sizes */
    CHECK(create_image(0, 5, NULL, &im) == TT_ERROR_INVALID_ARGUMENT && im == NULL, "width 0 rejected");
    CHECK(create_image(5, 0, NULL, &im) == TT_ERROR_INVALID_ARGUMENT && im == NULL, "height 0 rejected");
    CHECK(create_image(-3, 5, NULL, &im) == TT_ERROR_INVALID_ARGUMENT && im == NULL, "width -3 rejected");
    CHECK(create_image(5, -1, NULL, &im) == TT_ERROR_INVALID_ARGUMENT && im == NULL, "height -1 rejected");
    CHECK(create_image(TT_MAX_IMAGE_SIZE + 1, 1, NULL, &im) == TT_ERROR_TOO_LARGE && im == NULL,
          "width TT_MAX_IMAGE_SIZE+1 should be TT_ERROR_TOO_LARGE");
    CHECK(create_image(1, TT_MAX_IMAGE_SIZE + 1, NULL, &im) == TT_ERROR_TOO_LARGE && im == NULL,
          "height TT_MAX_IMAGE_SIZE+1 should be TT_ERROR_TOO_LARGE");
    CHECK(tt_image_create(4, 4, NULL, NULL, &err) == TT_ERROR_INVALID_ARGUMENT && err.message[0] != '\0',
          "out_image NULL rejected");
    CHECK(create_image(TT_MAX_IMAGE_SIZE, 1, &al, &im) == TT_OK && im && im->width == TT_MAX_IMAGE_SIZE,
          "TT_MAX_IMAGE_SIZE x 1 is allowed");
    if (im) tt_image_free(im);
    {
        counter fc;
        tt_allocator fail = make_allocator(&fc, 0);
        CHECK(create_image(4, 4, &fail, &im) == TT_ERROR_OUT_OF_MEMORY && im == NULL && fc.live == 0,
              "tt_image_create with a failing allocator: clean TT_ERROR_OUT_OF_MEMORY");
    }
    cnt.calls = 0;
    CHECK(create_image(3, 2, &al, &im) == TT_OK && im, "create 3x2");
    if (im) {
        bad = 0;
        for (k = 0; k < 3 * 2 * 4; k++) bad += im->pixels[k] != 0.0f;
        CHECK(bad == 0 && im->width == 3 && im->height == 2, "a new image is zero-filled, %d non-zero values", bad);
        CHECK(cnt.calls == 1 && cnt.live == 1, "an image is one allocation: %ld calls, %ld live", cnt.calls,
              cnt.live);
        CHECK(im->allocator.alloc == al.alloc && im->allocator.user_data == al.user_data,
              "the image remembers its allocator");
        tt_image_free(im);
        CHECK(cnt.live == 0 && cnt.bad_frees == 0, "tt_image_free releases the one block: %ld live, %ld bad frees",
              cnt.live, cnt.bad_frees);
    }
    tt_image_free(NULL);

    /* from_bytes / to_rgba8 round trip, 1..4 channels, tight and padded
       stride, in both colour spaces */
    for (sp = 0; sp < 2; sp++) {
        tt_color_space space = sp ? TT_COLOR_LINEAR : TT_COLOR_SRGB;
        for (ch = 1; ch <= 4; ch++) {
            int stride_pad;
            for (stride_pad = 0; stride_pad <= 5; stride_pad += 5) {
                int stride = stride_pad ? 7 * ch + stride_pad : 0, rs = 7 * ch + stride_pad;
                lcg_seed(ch * 10 + stride_pad);
                for (k = 0; k < (int)sizeof data; k++) data[k] = (unsigned char)lcg_below(256);
                data[0] = 0;
                data[1] = 255;
                im = NULL;
                CHECK(tt_image_from_bytes(data, 7, 5, ch, stride, space, &al, &im, NULL) == TT_OK && im,
                      "from_bytes ch %d", ch);
                if (!im) continue;
                memset(back, 0x11, sizeof back);
                tt_image_to_rgba8(im, space, back);
                bad = 0;
                for (y = 0; y < 5; y++)
                    for (x = 0; x < 7; x++) {
                        const unsigned char *p = data + y * rs + x * ch, *q = back + (y * 7 + x) * 4;
                        const float *f = px(im, x, y);
                        unsigned char e[4];
                        if (ch <= 2) { e[0] = e[1] = e[2] = p[0]; e[3] = ch == 2 ? p[1] : 255; }
                        else { e[0] = p[0]; e[1] = p[1]; e[2] = p[2]; e[3] = ch == 4 ? p[3] : 255; }
                        for (k = 0; k < 4; k++) {
                            double want = k < 3 && space == TT_COLOR_SRGB ? tt_srgb_to_linear(e[k] / 255.0f)
                                                                          : e[k] / 255.0;
                            if (q[k] != e[k]) bad++;
                            if (!near(f[k], want, 1e-7)) bad++;
                        }
                    }
                CHECK(bad == 0, "round trip in space %d with %d channels, stride %d: %d values differ", (int)space,
                      ch, stride, bad);
                tt_image_free(im);
            }
        }
    }
    im = (tt_image *)&im;
    CHECK(tt_image_from_bytes(data, 7, 5, 0, 0, TT_COLOR_SRGB, &al, &im, NULL) == TT_ERROR_INVALID_ARGUMENT &&
              im == NULL,
          "0 channels rejected");
    CHECK(tt_image_from_bytes(data, 7, 5, 5, 0, TT_COLOR_SRGB, &al, &im, NULL) == TT_ERROR_INVALID_ARGUMENT,
          "5 channels rejected");
    CHECK(tt_image_from_bytes(data, 7, 5, 3, 20, TT_COLOR_SRGB, &al, &im, NULL) == TT_ERROR_INVALID_ARGUMENT,
          "stride smaller than width*channels rejected");
    CHECK(tt_image_from_bytes(NULL, 7, 5, 3, 0, TT_COLOR_SRGB, &al, &im, NULL) == TT_ERROR_INVALID_ARGUMENT,
          "data NULL rejected");
    CHECK(tt_image_from_bytes(data, 0, 5, 3, 0, TT_COLOR_SRGB, &al, &im, NULL) == TT_ERROR_INVALID_ARGUMENT,
          "width 0 rejected");
    /* to_rgba8 rounds and clamps */
    CHECK(create_image(2, 1, &al, &im) == TT_OK && im, "create 2x1");
    if (im) {
        im->pixels[0] = -0.5f; im->pixels[1] = 1.5f; im->pixels[2] = 0.5f; im->pixels[3] = (float)NAN;
        im->pixels[4] = 0.2f / 255.0f; im->pixels[5] = 0.6f / 255.0f; im->pixels[6] = 254.6f / 255.0f;
        im->pixels[7] = 1.0f;
        tt_image_to_rgba8(im, TT_COLOR_LINEAR, back);
        CHECK(back[0] == 0 && back[1] == 255 && back[2] == 128 && back[3] == 0 && back[4] == 0 && back[5] == 1 &&
                  back[6] == 255 && back[7] == 255,
              "to_rgba8 clamp/round: got %d %d %d %d %d %d %d %d", back[0], back[1], back[2], back[3], back[4],
              back[5], back[6], back[7]);
        tt_image_free(im);
    }

    /* bilinear */
    CHECK(create_image(5, 4, &al, &im) == TT_OK && im, "create 5x4");
    if (im) {
        int bad_centre = 0, bad_half = 0, bad_clamp = 0;
        float s[4];
        fill_random(im, 77);
        for (y = 0; y < 4; y++)
            for (x = 0; x < 5; x++) {
                tt_image_sample_bilinear(im, x + 0.5f, y + 0.5f, s);
                if (memcmp(s, px(im, x, y), sizeof s) != 0) bad_centre++;
                if (x + 1 < 5) {
                    tt_image_sample_bilinear(im, x + 1.0f, y + 0.5f, s);
                    for (k = 0; k < 4; k++)
                        if (!near(s[k], 0.5 * (px(im, x, y)[k] + px(im, x + 1, y)[k]), 1e-6)) bad_half++;
                }
                if (y + 1 < 4) {
                    tt_image_sample_bilinear(im, x + 0.5f, y + 1.0f, s);
                    for (k = 0; k < 4; k++)
                        if (!near(s[k], 0.5 * (px(im, x, y)[k] + px(im, x, y + 1)[k]), 1e-6)) bad_half++;
                }
                if (x + 1 < 5 && y + 1 < 4) {
                    tt_image_sample_bilinear(im, x + 1.0f, y + 1.0f, s);
                    for (k = 0; k < 4; k++)
                        if (!near(s[k], 0.25 * (px(im, x, y)[k] + px(im, x + 1, y)[k] + px(im, x, y + 1)[k] +
                                                px(im, x + 1, y + 1)[k]), 1e-6))
                            bad_half++;
                }
            }
        CHECK(bad_centre == 0, "bilinear at texel centres: %d texels differ", bad_centre);
        CHECK(bad_half == 0, "bilinear halfway: %d values differ from the average", bad_half);
        tt_image_sample_bilinear(im, -10.0f, -3.0f, s);
        bad_clamp += memcmp(s, px(im, 0, 0), sizeof s) != 0;
        tt_image_sample_bilinear(im, 100.0f, 50.0f, s);
        bad_clamp += memcmp(s, px(im, 4, 3), sizeof s) != 0;
        tt_image_sample_bilinear(im, 0.1f, 2.5f, s);   /* left of the first centre: clamps in x */
        bad_clamp += memcmp(s, px(im, 0, 2), sizeof s) != 0;
        tt_image_sample_bilinear(im, 3.5f, 3.9f, s);   /* below the last centre */
        bad_clamp += memcmp(s, px(im, 3, 3), sizeof s) != 0;
        CHECK(bad_clamp == 0, "bilinear clamps outside the image: %d cases wrong", bad_clamp);
        /* far outside: still the nearest edge texel */
        tt_image_sample_bilinear(im, -1e30f, 1e30f, s);
        CHECK(memcmp(s, px(im, 0, 3), sizeof s) == 0,
              "bilinear at (-1e30, 1e30) should clamp to the bottom-left texel (0,3): got %g, texel (0,3) %g, (0,0) %g",
              s[0], px(im, 0, 3)[0], px(im, 0, 0)[0]);
        tt_image_sample_bilinear(im, 3e9f, 2.5f, s);
        CHECK(memcmp(s, px(im, 4, 2), sizeof s) == 0,
              "bilinear at (3e9, 2.5) should clamp to the right texel (4,2): got %g, texel (4,2) %g, (0,2) %g", s[0],
              px(im, 4, 2)[0], px(im, 0, 2)[0]);
        tt_image_sample_bilinear(im, (float)NAN, 1.0f, s);   /* must not crash */
        CHECK(s[0] == s[0], "bilinear at NaN should return a number");
        tt_image_free(im);
    }
    CHECK(cnt.live == 0, "image basics: %ld allocations leaked", cnt.live);
}

/* TT_WRAP_REPEAT: the image tiles the plane. Whole periods change nothing,
   the borders blend the last texel with the first, and coordinates that are
   not finite or far too large still sample a texel; TT_WRAP_CLAMP is the
   plain sampler. */
static void test_sample_wrap(void)
{
    tt_image *im = NULL;
    float s[4], t[4];
    int x, y, k, bad_period = 0, bad_clamp = 0;
    CHECK(tt_image_create(5, 4, NULL, &im, NULL) == TT_OK, "create 5x4");
    if (!im) return;
    fill_random(im, 31);
    for (y = 0; y < 8; y++)
        for (x = 0; x < 10; x++) {
            float fx = 0.37f * (float)x + 0.2f, fy = 0.55f * (float)y + 0.1f;
            tt_image_sample_bilinear_wrap(im, fx, fy, TT_WRAP_REPEAT, s);
            tt_image_sample_bilinear_wrap(im, fx + 10.0f, fy - 8.0f, TT_WRAP_REPEAT, t);
            for (k = 0; k < 4; k++) bad_period += !near(s[k], t[k], 1e-5);
            tt_image_sample_bilinear_wrap(im, fx * 3.0f - 4.0f, fy * 3.0f - 4.0f, TT_WRAP_CLAMP, s);
            tt_image_sample_bilinear(im, fx * 3.0f - 4.0f, fy * 3.0f - 4.0f, t);
            bad_clamp += memcmp(s, t, sizeof s) != 0;
        }
    CHECK(bad_period == 0, "repeat: %d values change by whole periods (10, -8)", bad_period);
    CHECK(bad_clamp == 0, "TT_WRAP_CLAMP: %d samples differ from tt_image_sample_bilinear", bad_clamp);
    /* x = 0 lies halfway between the last column's centre (4.5 - 5) and the
       first one's (0.5) */
    tt_image_sample_bilinear_wrap(im, 0.0f, 2.5f, TT_WRAP_REPEAT, s);
    for (k = 0; k < 4; k++) bad_period += !near(s[k], 0.5 * (px(im, 4, 2)[k] + px(im, 0, 2)[k]), 1e-6);
    tt_image_sample_bilinear_wrap(im, 2.5f, 4.0f, TT_WRAP_REPEAT, s);
    for (k = 0; k < 4; k++) bad_period += !near(s[k], 0.5 * (px(im, 2, 3)[k] + px(im, 2, 0)[k]), 1e-6);
    CHECK(bad_period == 0, "repeat blends the last texel with the first across each border");
    tt_image_sample_bilinear_wrap(im, (float)NAN, internal_infinity(), TT_WRAP_REPEAT, s);
    CHECK(memcmp(s, px(im, 0, 0), sizeof s) == 0, "repeat at (NaN, inf) should sample texel (0, 0): got %g", s[0]);
    tt_image_sample_bilinear_wrap(im, -3e38f, 1e30f, TT_WRAP_REPEAT, s);   /* must not crash */
    CHECK(s[0] == s[0], "repeat at (-3e38, 1e30) should return a number");
    tt_image_free(im);
}

/* IEC 61966-2-1 in double precision. */
static double ref_srgb_to_linear(double v)
{
    return v <= 0.04045 ? v / 12.92 : pow((v + 0.055) / 1.055, 2.4);
}
static double ref_linear_to_srgb(double v)
{
    return v <= 0.0031308 ? v * 12.92 : 1.055 * pow(v, 1.0 / 2.4) - 0.055;
}

static void test_color_transfer(void)
{
    static const float enc[] = {0.0f, 0.01f, 0.04f, 0.04045f, 0.05f, 0.1f, 0.2f, 0.5f, 0.735357f, 0.9f, 1.0f};
    static const float lin[] = {0.0f, 0.001f, 0.0031308f, 0.004f, 0.01f, 0.18f, 0.214041f, 0.5f, 0.8f, 1.0f};
    int i, bad = 0;
    for (i = 0; i < (int)(sizeof enc / sizeof enc[0]); i++) {
        double want = ref_srgb_to_linear(enc[i]), got = tt_srgb_to_linear(enc[i]);
        if (!near(got, want, 2e-6 * (want > 1e-3 ? want : 1e-3))) {
            if (!bad) DETAIL("tt_srgb_to_linear(%g): expected %.9g, got %.9g", enc[i], want, got);
            bad++;
        }
    }
    CHECK(bad == 0, "tt_srgb_to_linear differs from IEC 61966-2-1 at %d of %d points", bad,
          (int)(sizeof enc / sizeof enc[0]));
    bad = 0;
    for (i = 0; i < (int)(sizeof lin / sizeof lin[0]); i++) {
        double want = ref_linear_to_srgb(lin[i]), got = tt_linear_to_srgb(lin[i]);
        if (!near(got, want, 2e-6 * (want > 1e-3 ? want : 1e-3))) {
            if (!bad) DETAIL("tt_linear_to_srgb(%g): expected %.9g, got %.9g", lin[i], want, got);
            bad++;
        }
    }
    CHECK(bad == 0, "tt_linear_to_srgb differs from IEC 61966-2-1 at %d of %d points", bad,
          (int)(sizeof lin / sizeof lin[0]));
    /* Landmarks: sRGB 0.5 is linear 0.214; linear 0.5 is sRGB 0.7354 (byte 187.5). */
    CHECK(near(tt_srgb_to_linear(0.5f), 0.21404114, 1e-6) && near(tt_linear_to_srgb(0.5f), 0.73535698, 1e-6),
          "sRGB landmarks: to_linear(0.5) = %.7g (0.2140411), to_srgb(0.5) = %.7g (0.7353570)",
          tt_srgb_to_linear(0.5f), tt_linear_to_srgb(0.5f));
    /* Clamped to [0, 1] (1 within float rounding of the 1.055 x - 0.055 form). */
    CHECK(tt_srgb_to_linear(-0.5f) == 0.0f && near(tt_srgb_to_linear(2.0f), 1.0, 1e-6) &&
              tt_linear_to_srgb(-1.0f) == 0.0f && near(tt_linear_to_srgb(7.0f), 1.0, 1e-6),
          "clamping: %g %g %g %g", tt_srgb_to_linear(-0.5f), tt_srgb_to_linear(2.0f), tt_linear_to_srgb(-1.0f),
          tt_linear_to_srgb(7.0f));
    /* Inverses of each other (float rounding) over [0, 1]. */
    bad = 0;
    for (i = 0; i <= 1000; i++) {
        float v = (float)i / 1000.0f;
        if (!near(tt_linear_to_srgb(tt_srgb_to_linear(v)), v, 1e-5)) bad++;
    }
    CHECK(bad == 0, "linear_to_srgb(srgb_to_linear(v)) != v at %d of 1001 points", bad);
}

/* Every byte value through from_bytes and back in both spaces and with
   1..4 channels: channel c of pixel x holds (x + 37 c) mod 256, so each
   channel sees all 256 values. */
static void test_color_bytes_identity(void)
{
    unsigned char data[256 * 4], back[256 * 4];
    counter cnt;
    tt_allocator al = make_allocator(&cnt, -1);
    int sp, ch, x, c, bad_bytes, bad_alpha;
    for (sp = 0; sp < 2; sp++) {
        tt_color_space space = sp ? TT_COLOR_LINEAR : TT_COLOR_SRGB;
        for (ch = 1; ch <= 4; ch++) {
            tt_image *im = NULL;
            tt_result r;
            for (x = 0; x < 256; x++)
                for (c = 0; c < ch; c++) data[x * ch + c] = (unsigned char)((x + 37 * c) % 256);
            r = tt_image_from_bytes(data, 256, 1, ch, 0, space, &al, &im, NULL);
            CHECK(r == TT_OK && im, "from_bytes 256 x 1, %d channels, space %d: %d", ch, (int)space, r);
            if (!im) continue;
            tt_image_to_rgba8(im, space, back);
            bad_bytes = 0;
            bad_alpha = 0;
            for (x = 0; x < 256; x++) {
                const unsigned char *p = data + x * ch;
                unsigned char e[4];
                if (ch <= 2) { e[0] = e[1] = e[2] = p[0]; e[3] = ch == 2 ? p[1] : 255; }
                else { e[0] = p[0]; e[1] = p[1]; e[2] = p[2]; e[3] = ch == 4 ? p[3] : 255; }
                for (c = 0; c < 4; c++)
                    if (back[4 * x + c] != e[c]) {
                        if (!bad_bytes)
                            DETAIL("space %d, %d channels: byte %d of channel %d came back as %d", (int)space, ch,
                                   e[c], c, back[4 * x + c]);
                        bad_bytes++;
                    }
                /* alpha is linear in both spaces: v / 255 */
                if (px(im, x, 0)[3] != (float)e[3] / 255.0f) bad_alpha++;
            }
            CHECK(bad_bytes == 0, "bytes -> linear -> bytes, space %d, %d channels: %d of 1024 values differ",
                  (int)space, ch, bad_bytes);
            CHECK(bad_alpha == 0, "space %d, %d channels: %d alpha values are not byte / 255", (int)space, ch,
                  bad_alpha);
            tt_image_free(im);
        }
    }
    CHECK(cnt.live == 0, "byte identity: %ld allocations leaked", cnt.live);
}

/* The byte a value encodes to, the naive way: the number of bounds (the
   values halfway between neighbouring bytes, in the encoded scale) at or
   below it, counted one by one; NaN gives 0. The reference for the
   library's faster encoder. */
static unsigned char naive_encode(const float bound[255], float value)
{
    int b = 0;
    while (b < 255 && value >= bound[b]) b++;
    return (unsigned char)b;
}

static void naive_bounds(tt_color_space space, float bound[255])
{
    int b;
    for (b = 0; b < 255; b++)
        bound[b] = space == TT_COLOR_SRGB     ? tt_srgb_to_linear(((float)b + 0.5f) / 255.0f)
                   : space == TT_COLOR_LINEAR ? ((float)b + 0.5f) / 255.0f
                                              : 2.0f * ((float)b + 0.5f) / 255.0f - 1.0f;
}

static float float_from_bits(uint32_t bits)
{
    float f;
    memcpy(&f, &bits, sizeof f);
    return f;
}

static uint32_t bits_of_float(float f)
{
    uint32_t bits;
    memcpy(&bits, &f, sizeof bits);
    return bits;
}

/* tt_image_to_rgba8 against naive_encode in every space: on the floats
   next to every bound (8 on each side, where rounding decides), on a sweep
   through the bit patterns of all floats from -2 to 2 (every 1021st, both
   signs), on 0, 1, -0, the infinities and NaN; and every byte through
   tt_image_from_bytes and back (grey, so the colour channels and alpha each
   see all 256 values). */
static void test_color_bytes_against_naive(void)
{
    static const tt_color_space spaces[] = {TT_COLOR_SRGB, TT_COLOR_LINEAR, TT_COLOR_NORMAL};
    const uint32_t top = bits_of_float(2.0f), step = 1021;
    int nvalues = 255 * 17 + 2 * (int)(top / step + 1) + 6, h = (nvalues + 4 * 1024 - 1) / (4 * 1024), n = 1024 * h;
    int sp;
    tt_image *im = NULL;
    unsigned char *out;
    if (tt_image_create(1024, h, NULL, &im, NULL) != TT_OK) { CHECK(0, "create 1024 x %d", h); return; }
    out = (unsigned char *)malloc((size_t)n * 4);
    for (sp = 0; sp < 3 && out; sp++) {
        tt_color_space space = spaces[sp];
        float bound[255], alpha_bound[255];
        unsigned char bytes[256 * 2], back[256 * 4];
        uint32_t bits;
        int i = 0, b, k, bad = 0, first = -1;
        tt_image *grey = NULL;
        naive_bounds(space, bound);
        naive_bounds(TT_COLOR_LINEAR, alpha_bound);
        for (b = 0; b < 255; b++)
            for (k = -8; k <= 8; k++) im->pixels[i++] = float_from_bits(bits_of_float(bound[b]) + (uint32_t)k);
        for (bits = 0; bits <= top; bits += step) {
            im->pixels[i++] = float_from_bits(bits);
            im->pixels[i++] = float_from_bits(bits | 0x80000000u);
        }
        im->pixels[i++] = 0.0f; im->pixels[i++] = 1.0f; im->pixels[i++] = -0.0f;
        im->pixels[i++] = (float)INFINITY; im->pixels[i++] = (float)-INFINITY; im->pixels[i++] = (float)NAN;
        while (i < 4 * n) im->pixels[i++] = 0.5f;
        tt_image_to_rgba8(im, space, out);
        for (i = 0; i < 4 * n; i++) {
            /* The normal spaces renormalise nothing on the way out: each
               channel encodes alone, as the naive count does. */
            unsigned char want = naive_encode(i % 4 == 3 ? alpha_bound : bound, im->pixels[i]);
            if (out[i] != want) {
                if (first < 0) first = i;
                bad++;
            }
        }
        if (first >= 0)
            DETAIL("space %d: %.9g (bits %08lx) encodes to %d, the naive count says %d", (int)space,
                   im->pixels[first], (unsigned long)bits_of_float(im->pixels[first]), out[first],
                   naive_encode(first % 4 == 3 ? alpha_bound : bound, im->pixels[first]));
        CHECK(bad == 0, "space %d: %d of %d values encode to another byte than the naive count", (int)space, bad,
              4 * n);
        /* every byte, decoded then encoded */
        if (space == TT_COLOR_NORMAL) continue;   /* not every byte triple is a unit vector */
        for (b = 0; b < 256; b++) {
            bytes[2 * b] = (unsigned char)b;
            bytes[2 * b + 1] = (unsigned char)(255 - b);
        }
        CHECK(tt_image_from_bytes(bytes, 256, 1, 2, 0, space, NULL, &grey, NULL) == TT_OK && grey,
              "from_bytes, every byte, space %d", (int)space);
        if (!grey) continue;
        tt_image_to_rgba8(grey, space, back);
        for (b = 0, bad = 0; b < 256; b++)
            bad += back[4 * b] != b || back[4 * b + 1] != b || back[4 * b + 2] != b || back[4 * b + 3] != 255 - b;
        CHECK(bad == 0, "space %d: %d of the 256 bytes do not come back through from_bytes and to_rgba8",
              (int)space, bad);
        tt_image_free(grey);
    }
    free(out);
    tt_image_free(im);
}

/* The mip of a black and white checkerboard is linear 0.5: sRGB byte 188,
   not the 128 that averaging the encoded bytes would give. */
static void test_color_mip(void)
{
    unsigned char data[8 * 8 * 4], out[4 * 4 * 4];
    int sp, x, y;
    for (y = 0; y < 8; y++)
        for (x = 0; x < 8; x++) {
            unsigned char v = (unsigned char)(((x + y) & 1) ? 255 : 0);
            data[(y * 8 + x) * 4] = data[(y * 8 + x) * 4 + 1] = data[(y * 8 + x) * 4 + 2] = v;
            data[(y * 8 + x) * 4 + 3] = 255;
        }
    for (sp = 0; sp < 2; sp++) {
        tt_color_space space = sp ? TT_COLOR_LINEAR : TT_COLOR_SRGB;
        int want = sp ? 128 : 188, bad = 0, i;
        tt_image *im = NULL, *mip = NULL;
        tt_result r = tt_image_from_bytes(data, 8, 8, 4, 0, space, NULL, &im, NULL);
        if (r == TT_OK) r = tt_image_downsample2(im, NULL, &mip, NULL);
        CHECK(r == TT_OK && mip && mip->width == 4 && mip->height == 4, "checkerboard mip, space %d: result %d",
              (int)space, r);
        if (mip) {
            tt_image_to_rgba8(mip, space, out);
            for (i = 0; i < 16; i++)
                bad += out[4 * i] != want || out[4 * i + 1] != want || out[4 * i + 2] != want || out[4 * i + 3] != 255;
            CHECK(bad == 0, "checkerboard mip, space %d: expected (%d,%d,%d,255), got (%d,%d,%d,%d) in %d texels",
                  (int)space, want, want, want, out[0], out[1], out[2], out[3], bad);
        }
        tt_image_free(mip);
        tt_image_free(im);
    }
}

/* tt_image_to_rgba8 into the image's own pixels gives the same bytes as
   into a separate buffer (the tool converts large photos that way). */
static void test_color_bytes_in_place(void)
{
    tt_image *im = NULL;
    unsigned char *apart;
    int i, n = 37 * 23, sp, bad;
    if (tt_image_create(37, 23, NULL, &im, NULL) != TT_OK) { CHECK(0, "create 37x23"); return; }
    apart = (unsigned char *)malloc((size_t)n * 4);
    for (sp = 0; sp < 2 && apart; sp++) {
        tt_color_space space = sp ? TT_COLOR_LINEAR : TT_COLOR_SRGB;
        for (i = 0; i < 4 * n; i++) im->pixels[i] = (float)((i * 7919) % 1000) / 999.0f;
        tt_image_to_rgba8(im, space, apart);
        tt_image_to_rgba8(im, space, (unsigned char *)im->pixels);
        for (i = 0, bad = 0; i < 4 * n; i++) bad += ((unsigned char *)im->pixels)[i] != apart[i];
        CHECK(bad == 0, "space %d: %d of %d bytes differ when converting in place", (int)space, bad, 4 * n);
    }
    free(apart);
    tt_image_free(im);
}

/* Alpha is never sRGB-converted; NaN encodes to 0 in every channel. */
static void test_color_alpha_nan(void)
{
    tt_image *im = NULL;
    unsigned char out[3 * 4], two[2] = {128, 64};
    int sp;
    if (tt_image_create(3, 1, NULL, &im, NULL) != TT_OK) { CHECK(0, "create 3x1"); return; }
    for (sp = 0; sp < 2; sp++) {
        tt_color_space space = sp ? TT_COLOR_LINEAR : TT_COLOR_SRGB;
        float *p = im->pixels;
        p[0] = p[1] = p[2] = 0.5f; p[3] = 0.5f;                              /* half grey, half alpha */
        p[4] = (float)NAN; p[5] = (float)NAN; p[6] = (float)NAN; p[7] = (float)NAN;
        p[8] = 0.25f; p[9] = (float)-NAN; p[10] = 1.0f; p[11] = 0.2f;
        memset(out, 0x77, sizeof out);
        tt_image_to_rgba8(im, space, out);
        CHECK(out[3] == 128 && out[11] == 51, "space %d: alpha 0.5 and 0.2 should be bytes 128 and 51, got %d %d",
              (int)space, out[3], out[11]);
        CHECK(out[0] == (sp ? 128 : 188), "space %d: linear 0.5 should encode to %d, got %d", (int)space,
              sp ? 128 : 188, out[0]);
        CHECK(out[4] == 0 && out[5] == 0 && out[6] == 0 && out[7] == 0 && out[9] == 0,
              "space %d: NaN should encode to 0, got %d %d %d %d and %d", (int)space, out[4], out[5], out[6], out[7],
              out[9]);
    }
    tt_image_free(im);
    /* decoding: grey + alpha, sRGB: the grey is decoded, the alpha is not */
    im = NULL;
    CHECK(tt_image_from_bytes(two, 1, 1, 2, 0, TT_COLOR_SRGB, NULL, &im, NULL) == TT_OK && im, "from_bytes 1x1x2");
    if (im) {
        CHECK(im->pixels[3] == 64.0f / 255.0f && near(im->pixels[0], ref_srgb_to_linear(128.0 / 255.0), 1e-6),
              "sRGB grey+alpha (128, 64): expected (%g, %g), got (%g, %g)", ref_srgb_to_linear(128.0 / 255.0),
              64.0 / 255.0, im->pixels[0], im->pixels[3]);
        tt_image_free(im);
    }
}

static void test_from_bytes_errors(void)
{
    static unsigned char small[64];
    unsigned char *wide;
    tt_image *im;
    tt_error err;
    counter cnt;
    tt_allocator al = make_allocator(&cnt, -1);
    static const int bad_channels[3] = {0, 5, -1};
    int i;
    for (i = 0; i < 3; i++) {
        im = (tt_image *)&im;
        memset(&err, 0, sizeof err);
        CHECK(tt_image_from_bytes(small, 2, 2, bad_channels[i], 0, TT_COLOR_SRGB, &al, &im, &err) ==
                      TT_ERROR_INVALID_ARGUMENT &&
                  err.result == TT_ERROR_INVALID_ARGUMENT && err.message[0] != '\0' && im == NULL,
              "%d channels: expected TT_ERROR_INVALID_ARGUMENT with a message and *out NULL, got %d (%s)",
              bad_channels[i], err.result, err.message);
    }
    im = (tt_image *)&im;
    CHECK(tt_image_from_bytes(small, 4, 2, 3, 11, TT_COLOR_SRGB, &al, &im, &err) == TT_ERROR_INVALID_ARGUMENT &&
              err.message[0] != '\0' && im == NULL,
          "stride 11 < 4 pixels * 3 channels: got %d (%s)", err.result, err.message);
    CHECK(tt_image_from_bytes(small, 4, 2, 3, -12, TT_COLOR_SRGB, &al, &im, &err) == TT_ERROR_INVALID_ARGUMENT,
          "a negative stride is rejected: got %d", err.result);
    CHECK(tt_image_from_bytes(small, 2, 2, 3, 0, (tt_color_space)7, &al, &im, &err) == TT_ERROR_INVALID_ARGUMENT,
          "an unknown colour space is rejected: got %d", err.result);
    CHECK(tt_image_from_bytes(small, TT_MAX_IMAGE_SIZE + 1, 1, 1, 0, TT_COLOR_SRGB, &al, &im, &err) ==
                  TT_ERROR_TOO_LARGE &&
              err.message[0] != '\0' && im == NULL,
          "width TT_MAX_IMAGE_SIZE + 1: expected TT_ERROR_TOO_LARGE, got %d", err.result);
    CHECK(tt_image_from_bytes(small, 1, TT_MAX_IMAGE_SIZE + 1, 1, 0, TT_COLOR_SRGB, &al, &im, &err) ==
              TT_ERROR_TOO_LARGE,
          "height TT_MAX_IMAGE_SIZE + 1: expected TT_ERROR_TOO_LARGE, got %d", err.result);
    CHECK(cnt.calls == 0, "rejected from_bytes calls allocated %ld times", cnt.calls);
    /* The widest row: 32768 pixels of 4 channels = 131072 bytes per row
       (width * channels and the stride arithmetic must not overflow: the
       UBSan build traps signed overflow). */
    wide = (unsigned char *)malloc((size_t)TT_MAX_IMAGE_SIZE * 4 * 2);
    for (i = 0; i < TT_MAX_IMAGE_SIZE * 4 * 2; i++) wide[i] = (unsigned char)(i % 251);
    im = NULL;
    CHECK(tt_image_from_bytes(wide, TT_MAX_IMAGE_SIZE, 2, 4, 0, TT_COLOR_LINEAR, &al, &im, &err) == TT_OK && im,
          "32768 x 2 pixels of 4 channels: %d (%s)", err.result, err.message);
    if (im) {
        const float *last = px(im, TT_MAX_IMAGE_SIZE - 1, 1);
        size_t o = ((size_t)TT_MAX_IMAGE_SIZE * 4 * 2) - 4;
        CHECK(last[0] == wide[o] / 255.0f && last[3] == wide[o + 3] / 255.0f,
              "the last pixel of a 32768-wide image: expected %g, got %g", wide[o] / 255.0, last[0]);
        tt_image_free(im);
    }
    im = (tt_image *)&im;
    CHECK(tt_image_from_bytes(wide, TT_MAX_IMAGE_SIZE, 1, 4, TT_MAX_IMAGE_SIZE * 4 - 1, TT_COLOR_LINEAR, &al, &im,
                              &err) == TT_ERROR_INVALID_ARGUMENT && im == NULL,
          "stride one byte short of 32768 * 4: got %d", err.result);
    free(wide);
    CHECK(cnt.live == 0, "from_bytes errors: %ld allocations leaked", cnt.live);
}

/* tt_rotate_coords computes in 64 bits: large widths and coordinates whose
   intermediate sums would overflow an int still give the right result
   whenever it fits (the precondition). */
static void test_rotate_coords_large(void)
{
    static const long long sizes[] = {1, 2, 1073741824LL, 2147483647LL};
    static const long long coords[] = {0, 5, -1073741824LL, 1073741823LL, -2147483647LL, 2147483647LL};
    int turns, a, b, c, d, calls = 0, bad = 0;
    for (turns = 0; turns < 4; turns++)
        for (a = 0; a < 4; a++)
            for (b = 0; b < 4; b++)
                for (c = 0; c < 6; c++)
                    for (d = 0; d < 6; d++) {
                        long long w = sizes[a], h = sizes[b], x = coords[c], y = coords[d], rx, ry;
                        int ox = 0, oy = 0;
                        switch (turns) {
                        case 0: rx = x; ry = y; break;
                        case 1: rx = y; ry = w - 1 - x; break;
                        case 2: rx = w - 1 - x; ry = h - 1 - y; break;
                        default: rx = h - 1 - y; ry = x; break;
                        }
                        if (rx < INT_MIN || rx > INT_MAX || ry < INT_MIN || ry > INT_MAX) continue;
                        tt_rotate_coords(turns, (int)w, (int)h, (int)x, (int)y, &ox, &oy);
                        calls++;
                        if (ox != rx || oy != ry) {
                            if (!bad)
                                DETAIL("rotate %d of %lld x %lld at (%lld, %lld): expected (%lld, %lld), got (%d, %d)",
                                       turns, w, h, x, y, rx, ry, ox, oy);
                            bad++;
                        }
                    }
    CHECK(bad == 0 && calls > 300, "tt_rotate_coords with large values: %d of %d wrong", bad, calls);
    {
        /* (w - x) would overflow an int, w - 1 - x = INT_MAX does not. */
        int ox = 0, oy = 0;
        tt_rotate_coords(1, 1073741824, 3, -1073741824, 2, &ox, &oy);
        CHECK(ox == 2 && oy == INT_MAX, "rotate 1 of 2^30 x 3 at (-2^30, 2): expected (2, %d), got (%d, %d)",
              INT_MAX, ox, oy);
        tt_rotate_coords(-1, 3, 1073741824, 7, -1073741824, &ox, &oy);
        CHECK(ox == INT_MAX && oy == 7, "rotate -1 of 3 x 2^30 at (7, -2^30): expected (%d, 7), got (%d, %d)",
              INT_MAX, ox, oy);
    }
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
    tt_image *src = NULL, *dst;
    counter cnt;
    tt_allocator al = make_allocator(&cnt, -1);
    tt_error err;
    int turns, x, y, W = 7, H = 4;
    CHECK(tt_image_create(W, H, &al, &src, NULL) == TT_OK && src, "create");
    if (!src) return;
    fill_random(src, 3);
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
        dst = NULL;
        r = tt_image_rotate90(src, turns, &al, &dst, NULL);
        CHECK(r == TT_OK && dst, "rotate90(%d) returned %d", turns, r);
        if (r != TT_OK || !dst) continue;
        CHECK(dst->width == (odd ? H : W) && dst->height == (odd ? W : H), "rotate90(%d): size %dx%d", turns,
              dst->width, dst->height);
        for (y = 0; y < H; y++)
            for (x = 0; x < W; x++) {
                int bx, by;
                naive_rotate(turns, W, H, x, y, &bx, &by);
                if (memcmp(px(dst, bx, by), px(src, x, y), 4 * sizeof(float)) != 0) bad_pixels++;
            }
        CHECK(bad_pixels == 0, "tt_image_rotate90(%d): %d pixels differ from the naive rotation", turns, bad_pixels);
        if (turns == 1) {
            /* one CCW turn: top-left goes to bottom-left; top-right to top-left */
            CHECK(memcmp(px(dst, 0, dst->height - 1), px(src, 0, 0), 16) == 0,
                  "one CCW turn should send the top-left pixel to the bottom-left");
            CHECK(memcmp(px(dst, 0, 0), px(src, W - 1, 0), 16) == 0,
                  "one CCW turn should send the top-right pixel to the top-left");
        }
        if (turns % 4 == 0)
            CHECK(memcmp(dst->pixels, src->pixels, sizeof(float) * 4 * W * H) == 0, "rotate90(%d) is the identity",
                  turns);
        tt_image_free(dst);
    }
    /* composition: 1 turn then 3 turns = identity */
    {
        tt_image *a = NULL, *b = NULL;
        if (tt_image_rotate90(src, 1, &al, &a, NULL) == TT_OK) {
            if (tt_image_rotate90(a, 3, &al, &b, NULL) == TT_OK) {
                CHECK(b->width == W && memcmp(b->pixels, src->pixels, sizeof(float) * 4 * W * H) == 0,
                      "1 + 3 quarter turns should be the identity");
                tt_image_free(b);
            }
            tt_image_free(a);
        }
    }
    CHECK(tt_image_rotate90(src, 1, &al, NULL, &err) == TT_ERROR_INVALID_ARGUMENT && err.message[0] != '\0',
          "out_image NULL is rejected");
    dst = (tt_image *)&dst;
    CHECK(tt_image_rotate90(NULL, 1, &al, &dst, &err) == TT_ERROR_INVALID_ARGUMENT && dst == NULL,
          "src NULL rejected");
    {
        counter fc;
        tt_allocator fail = make_allocator(&fc, 0);
        dst = (tt_image *)&dst;
        CHECK(tt_image_rotate90(src, 1, &fail, &dst, &err) == TT_ERROR_OUT_OF_MEMORY && dst == NULL && fc.live == 0,
              "rotate90 with a failing allocator: clean TT_ERROR_OUT_OF_MEMORY");
    }
    tt_image_free(src);
    CHECK(cnt.live == 0, "rotate: %ld allocations leaked", cnt.live);
}

static void test_over_downsample(void)
{
    tt_image *a = NULL, *b = NULL, *c = NULL, *d = NULL;
    counter cnt;
    tt_allocator al = make_allocator(&cnt, -1);
    tt_error err;
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

    CHECK(tt_image_create(6, 4, &al, &a, NULL) == TT_OK && tt_image_create(6, 4, &al, &b, NULL) == TT_OK, "create");
    CHECK(tt_image_create(6, 4, &al, &c, NULL) == TT_OK, "create");
    if (!a || !b || !c) { tt_image_free(a); tt_image_free(b); tt_image_free(c); return; }
    fill_random(a, 11);
    fill_random(b, 12);
    for (y = 0; y < 4; y++)
        for (x = 0; x < 6; x++) {
            float *p = px(b, x, y);
            int kind = (x + y) % 3;
            p[3] = kind == 0 ? 0.0f : kind == 1 ? 1.0f : 0.5f;
            if (kind == 0) p[0] = p[1] = p[2] = 0.0f;
            for (k = 0; k < 3; k++) p[k] *= p[3];   /* premultiplied */
        }
    memcpy(c->pixels, a->pixels, sizeof(float) * 4 * 24);
    CHECK(tt_image_over(a, b, &err) == TT_OK, "tt_image_over");
    bad = 0;
    for (y = 0; y < 4; y++)
        for (x = 0; x < 6; x++) {
            const float *s = px(b, x, y), *o = px(c, x, y), *r = px(a, x, y);
            for (k = 0; k < 4; k++) {
                if (s[3] == 0.0f) bad += r[k] != o[k];
                else if (s[3] == 1.0f) bad += r[k] != s[k];
                else bad += !near(r[k], s[k] + (1.0 - s[3]) * o[k], 1e-6);
            }
        }
    CHECK(bad == 0, "tt_image_over: %d values differ from the formula", bad);
    tt_image_free(c);
    c = NULL;
    CHECK(tt_image_create(5, 4, &al, &c, NULL) == TT_OK, "create");
    CHECK(tt_image_over(a, c, &err) == TT_ERROR_INVALID_ARGUMENT && err.message[0] != '\0',
          "over with different sizes rejected");
    CHECK(tt_image_over(NULL, c, &err) == TT_ERROR_INVALID_ARGUMENT && tt_image_over(a, NULL, NULL) ==
              TT_ERROR_INVALID_ARGUMENT,
          "over NULL rejected");

    /* downsample against a naive box */
    CHECK(tt_image_downsample2(a, &al, &d, NULL) == TT_OK && d, "downsample 6x4");
    if (d) {
        CHECK(d->width == 3 && d->height == 2, "downsample size %dx%d", d->width, d->height);
        bad = 0;
        for (y = 0; y < 2; y++)
            for (x = 0; x < 3; x++)
                for (k = 0; k < 4; k++) {
                    double e = (px(a, 2 * x, 2 * y)[k] + px(a, 2 * x + 1, 2 * y)[k] + px(a, 2 * x, 2 * y + 1)[k] +
                                px(a, 2 * x + 1, 2 * y + 1)[k]) / 4.0;
                    bad += !near(px(d, x, y)[k], e, 1e-6);
                }
        CHECK(bad == 0, "downsample2: %d values differ from the naive box", bad);
        tt_image_free(d);
    }
    d = (tt_image *)&d;
    CHECK(tt_image_downsample2(c, &al, &d, &err) == TT_ERROR_INVALID_ARGUMENT && d == NULL &&
              err.message[0] != '\0',
          "odd width rejected");
    tt_image_free(c);
    c = NULL;
    CHECK(tt_image_create(4, 3, &al, &c, NULL) == TT_OK, "create");
    d = (tt_image *)&d;
    CHECK(tt_image_downsample2(c, &al, &d, NULL) == TT_ERROR_INVALID_ARGUMENT && d == NULL, "odd height rejected");
    tt_image_free(c);
    c = NULL;
    CHECK(tt_image_create(2, 2, &al, &c, NULL) == TT_OK, "create");
    d = NULL;
    CHECK(tt_image_downsample2(c, &al, &d, NULL) == TT_OK && d && d->width == 1 && d->height == 1, "2x2 -> 1x1");
    tt_image_free(d);
    CHECK(tt_image_downsample2(c, &al, NULL, &err) == TT_ERROR_INVALID_ARGUMENT, "out_image NULL rejected");
    d = (tt_image *)&d;
    CHECK(tt_image_downsample2(NULL, &al, &d, &err) == TT_ERROR_INVALID_ARGUMENT && d == NULL, "src NULL rejected");
    tt_image_free(c);
    tt_image_free(a);
    tt_image_free(b);
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

/* tt_image_resize against a naive reference: the tent filter written out
   for one texel at a time, in two dimensions at once. */
static void resize_reference(const tt_image *src, int w, int h, int x, int y, float out[4])
{
    const double rx = (double)src->width / w, ry = (double)src->height / h;
    const double ax = rx > 1.0 ? rx : 1.0, ay = ry > 1.0 ? ry : 1.0;
    const double cx = (x + 0.5) * rx - 0.5, cy = (y + 0.5) * ry - 0.5;
    double sum[4] = {0, 0, 0, 0}, total = 0.0;
    int i, j, k;
    for (j = (int)floor(cy - ay) - 1; j <= (int)ceil(cy + ay) + 1; j++)
        for (i = (int)floor(cx - ax) - 1; i <= (int)ceil(cx + ax) + 1; i++) {
            const double wx = 1.0 - fabs(i - cx) / ax, wy = 1.0 - fabs(j - cy) / ay;
            const float *p;
            if (wx <= 0.0 || wy <= 0.0) continue;
            p = px(src, i < 0 ? 0 : (i >= src->width ? src->width - 1 : i),
                   j < 0 ? 0 : (j >= src->height ? src->height - 1 : j));
            for (k = 0; k < 4; k++) sum[k] += wx * wy * p[k];
            total += wx * wy;
        }
    for (k = 0; k < 4; k++) out[k] = (float)(sum[k] / total);
}

static void test_resize(void)
{
    static const int sizes[][2] = {{23, 17}, {40, 9}, {5, 31}, {1, 1}, {48, 32}};
    tt_image *src = NULL, *out = NULL;
    tt_error err;
    tt_result r;
    int s, x, y, k, bad;
    double worst;
    make_value_noise(&src, 24, 16, 9);
    if (!src) return;
    for (s = 0; s < (int)(sizeof sizes / sizeof sizes[0]); s++) {
        const int w = sizes[s][0], h = sizes[s][1];
        r = tt_image_resize(src, w, h, NULL, &out, &err);
        CHECK(r == TT_OK && out && out->width == w && out->height == h, "resize 24x16 to %dx%d: %s", w, h,
              err.message);
        if (!out) continue;
        worst = 0.0;
        for (y = 0; y < h; y++)
            for (x = 0; x < w; x++) {
                float ref[4];
                resize_reference(src, w, h, x, y, ref);
                for (k = 0; k < 4; k++)
                    if (fabs(ref[k] - px(out, x, y)[k]) > worst) worst = fabs(ref[k] - px(out, x, y)[k]);
            }
        CHECK(worst < 1e-5, "resize to %dx%d agrees with the naive tent filter (worst %g)", w, h, worst);
        tt_image_free(out);
        out = NULL;
    }
    /* The same size is the image itself; a linear ramp stays linear inside
       when enlarged (the tent is linear interpolation there). */
    r = tt_image_resize(src, 24, 16, NULL, &out, &err);
    CHECK(r == TT_OK && out && memcmp(out->pixels, src->pixels, sizeof(float) * 4 * 24 * 16) == 0,
          "resize to its own size is exact");
    tt_image_free(out);
    for (y = 0; y < 16; y++)
        for (x = 0; x < 24; x++)
            for (k = 0; k < 4; k++) px(src, x, y)[k] = 0.01f * x + 0.02f * y;
    r = tt_image_resize(src, 60, 40, NULL, &out, &err);
    bad = 0;
    for (y = 3; out && y < 37; y++)
        for (x = 3; x < 57; x++) {
            const double sx = (x + 0.5) * 24.0 / 60.0 - 0.5, sy = (y + 0.5) * 16.0 / 40.0 - 0.5;
            bad += fabs(px(out, x, y)[0] - (0.01 * sx + 0.02 * sy)) > 1e-5;
        }
    CHECK(r == TT_OK && bad == 0, "a ramp enlarged 2.5x stays the ramp: %d texels off", bad);
    tt_image_free(out);
    out = NULL;
    /* A normal map stays unit vectors. */
    src->kind = TT_IMAGE_NORMAL;
    for (y = 0; y < 16; y++)
        for (x = 0; x < 24; x++) {
            float *p = px(src, x, y);
            const double a = 0.3 * x, z = 0.8;
            p[0] = (float)(0.6 * cos(a));
            p[1] = (float)(0.6 * sin(a));
            p[2] = (float)z;
        }
    r = tt_image_resize(src, 10, 7, NULL, &out, &err);
    bad = 0;
    for (y = 0; out && y < 7; y++)
        for (x = 0; x < 10; x++) {
            const float *p = px(out, x, y);
            bad += fabs(p[0] * p[0] + p[1] * p[1] + p[2] * p[2] - 1.0) > 1e-4;
        }
    CHECK(r == TT_OK && out && out->kind == TT_IMAGE_NORMAL && bad == 0, "a resized normal map: %d not unit", bad);
    tt_image_free(out);
    /* Errors. */
    r = tt_image_resize(src, 0, 5, NULL, &out, &err);
    CHECK(r == TT_ERROR_INVALID_ARGUMENT && !out, "width 0: %d (%s)", r, err.message);
    r = tt_image_resize(src, 5, TT_MAX_IMAGE_SIZE + 1, NULL, &out, &err);
    CHECK(r == TT_ERROR_TOO_LARGE && !out, "height above TT_MAX_IMAGE_SIZE: %d (%s)", r, err.message);
    r = tt_image_resize(NULL, 5, 5, NULL, &out, &err);
    CHECK(r == TT_ERROR_INVALID_ARGUMENT && !out, "NULL source: %d (%s)", r, err.message);
    CHECK(tt_image_resize(src, 5, 5, NULL, NULL, &err) == TT_ERROR_INVALID_ARGUMENT, "NULL out: %s", err.message);
    src->kind = (tt_image_kind)7;
    r = tt_image_resize(src, 5, 5, NULL, &out, &err);
    CHECK(r == TT_ERROR_INVALID_ARGUMENT && !out && strstr(err.message, "kind 7"), "kind 7: %s", err.message);
    tt_image_free(src);
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
        r = tt_min_error_cut(cost, w, h, lo, hi, &al, path, NULL);
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
        tt_error err;
        CHECK(tt_min_error_cut(cost, 2, 2, badlo, hi01, &al, path, &err) == TT_ERROR_INVALID_ARGUMENT &&
                  err.column == 0 && err.message[0] != '\0',
              "lo > hi in column 0 rejected, naming the column: column %d", err.column);
        CHECK(tt_min_error_cut(cost, 2, 2, lo, badhi, &al, path, NULL) == TT_ERROR_INVALID_ARGUMENT,
              "hi >= height rejected");
        CHECK(tt_min_error_cut(NULL, 2, 2, lo, hi, &al, path, NULL) == TT_ERROR_INVALID_ARGUMENT, "cost NULL rejected");
        CHECK(tt_min_error_cut(cost, 0, 2, lo, hi, &al, path, NULL) == TT_ERROR_INVALID_ARGUMENT, "width 0 rejected");
        CHECK(tt_min_error_cut(cost, 2, 2, lo, hi, NULL, path, NULL) == TT_OK && path[0] == 0 && path[1] == 0,
              "default allocator: path %d %d", path[0], path[1]);
        {
            counter fc;
            tt_allocator fail;
            int k;
            for (k = 0; k < 2; k++) {
                fail = make_allocator(&fc, k);
                CHECK(tt_min_error_cut(cost, 2, 2, lo, hi, &fail, path, NULL) == TT_ERROR_OUT_OF_MEMORY && fc.live == 0,
                      "min_error_cut with allocation %d failing: clean TT_ERROR_OUT_OF_MEMORY", k);
            }
        }
    }
    {
        /* A NaN or infinite cost: TT_ERROR_NON_FINITE naming its row and column. */
        float cost[12];
        int lo[4] = {0, 0, 0, 0}, hi[4] = {2, 2, 2, 2}, path[4], k;
        tt_error err;
        for (k = 0; k < 12; k++) cost[k] = (float)k;
        cost[2 * 4 + 1] = (float)NAN;   /* row 2, column 1 */
        memset(&err, 0, sizeof err);
        CHECK(tt_min_error_cut(cost, 4, 3, lo, hi, &al, path, &err) == TT_ERROR_NON_FINITE &&
                  err.result == TT_ERROR_NON_FINITE && err.row == 2 && err.column == 1 && err.message[0] != '\0',
              "NaN cost at row 2, column 1: result %d, row %d, column %d (%s)", err.result, err.row, err.column,
              err.message);
        cost[2 * 4 + 1] = 0.0f;
        cost[1 * 4 + 3] = -(float)INFINITY;   /* row 1, column 3 */
        CHECK(tt_min_error_cut(cost, 4, 3, lo, hi, &al, path, &err) == TT_ERROR_NON_FINITE && err.row == 1 &&
                  err.column == 3,
              "-inf cost at row 1, column 3: result %d, row %d, column %d", err.result, err.row, err.column);
        CHECK(tt_min_error_cut(cost, 4, 3, lo, hi, &al, path, NULL) == TT_ERROR_NON_FINITE,
              "-inf cost with error NULL");
    }
    CHECK(cnt.live == 0, "min_error_cut: %ld allocations leaked", cnt.live);
}


/* Normal maps: bytes <-> unit vectors in both conventions, and the steps that
   turn or blend an image keep them unit vectors turned with the content. */
static void test_normal_maps(void)
{
    unsigned char bytes[4 * 3 * 4], back[4 * 3 * 4];
    tt_image *gl = NULL, *dx = NULL, *turned = NULL, *half = NULL;
    counter cnt;
    tt_allocator al = make_allocator(&cnt, -1);
    tt_error err;
    int i, x, y, bad = 0, turns;
    /* a few directions encoded the usual way: (n + 1) / 2 * 255 */
    static const float dirs[4][3] = {{0.0f, 0.0f, 1.0f}, {0.6f, 0.0f, 0.8f}, {0.0f, -0.6f, 0.8f}, {0.48f, 0.36f, 0.8f}};
    for (i = 0; i < 12; i++) {
        const float *n = dirs[i % 4];
        int k;
        for (k = 0; k < 3; k++) bytes[4 * i + k] = (unsigned char)floor((n[k] + 1.0) * 0.5 * 255.0 + 0.5);
        bytes[4 * i + 3] = 255;
    }
    CHECK(tt_image_from_bytes(bytes, 4, 3, 4, 0, TT_COLOR_NORMAL, &al, &gl, &err) == TT_OK && gl,
          "decode a normal map: %s", err.message);
    CHECK(tt_image_from_bytes(bytes, 4, 3, 4, 0, TT_COLOR_NORMAL_Y_DOWN, &al, &dx, &err) == TT_OK && dx,
          "decode a Y-down normal map: %s", err.message);
    if (!gl || !dx) goto done;
    CHECK(gl->kind == TT_IMAGE_NORMAL && dx->kind == TT_IMAGE_NORMAL, "decoded normal maps are of kind normal");
    for (i = 0; i < 12; i++) {
        const float *n = dirs[i % 4], *a = gl->pixels + 4 * i, *b = dx->pixels + 4 * i;
        double length = sqrt((double)a[0] * a[0] + (double)a[1] * a[1] + (double)a[2] * a[2]);
        if (fabs(length - 1.0) > 1e-5 || fabs(a[0] - n[0]) > 0.01f || fabs(a[1] - n[1]) > 0.01f ||
            fabs(a[2] - n[2]) > 0.01f || b[0] != a[0] || b[1] != -a[1] || b[2] != a[2] || a[3] != 1.0f)
            bad++;
    }
    CHECK(bad == 0, "decoded unit vectors, y negated for Y-down: %d texels wrong", bad);
    tt_image_to_rgba8(gl, TT_COLOR_NORMAL, back);
    CHECK(memcmp(back, bytes, sizeof bytes) == 0, "bytes of unit vectors -> normal map -> the same bytes");
    tt_image_to_rgba8(dx, TT_COLOR_NORMAL_Y_DOWN, back);
    CHECK(memcmp(back, bytes, sizeof bytes) == 0, "the same round trip in the Y-down convention");
    /* a quarter turn counter-clockwise turns a vector pointing right to one pointing up */
    for (turns = -3; turns <= 5; turns++) {
        double angle = turns * 1.5707963267948966;
        int worst = 0;
        turned = NULL;
        CHECK(tt_image_rotate90(gl, turns, &al, &turned, NULL) == TT_OK && turned, "rotate90(%d)", turns);
        if (!turned) continue;
        CHECK(turned->kind == TT_IMAGE_NORMAL, "a turned normal map stays a normal map");
        for (y = 0; y < gl->height; y++)
            for (x = 0; x < gl->width; x++) {
                int rx, ry;
                const float *a = gl->pixels + 4 * (y * gl->width + x), *b;
                double ex = cos(angle) * a[0] - sin(angle) * a[1], ey = sin(angle) * a[0] + cos(angle) * a[1];
                tt_rotate_coords(turns, gl->width, gl->height, x, y, &rx, &ry);
                b = turned->pixels + 4 * (ry * turned->width + rx);
                if (fabs(b[0] - ex) > 1e-6 || fabs(b[1] - ey) > 1e-6 || b[2] != a[2]) worst++;
            }
        CHECK(worst == 0, "rotate90(%d) turns each vector by %d quarter turns: %d texels wrong", turns, turns, worst);
        tt_image_free(turned);
    }
    /* a 2x2 average of two directions is renormalised, and a colour image is not */
    {
        tt_image *sq = NULL;
        if (tt_image_create(2, 2, &al, &sq, NULL) == TT_OK) {
            sq->kind = TT_IMAGE_NORMAL;
            for (i = 0; i < 4; i++) {
                sq->pixels[4 * i] = i % 2 ? 0.6f : -0.6f;
                sq->pixels[4 * i + 2] = 0.8f;
                sq->pixels[4 * i + 3] = 1.0f;
            }
            CHECK(tt_image_downsample2(sq, &al, &half, NULL) == TT_OK && half, "halve a normal map");
            if (half)
                CHECK(half->kind == TT_IMAGE_NORMAL && fabs(half->pixels[0]) < 1e-6 && fabs(half->pixels[2] - 1.0f) < 1e-6,
                      "the mean of (-0.6, 0, 0.8) and (0.6, 0, 0.8) is renormalised to (0, 0, 1), got (%g, %g, %g)",
                      half->pixels[0], half->pixels[1], half->pixels[2]);
            tt_image_free(half);
            half = NULL;
            sq->kind = TT_IMAGE_COLOR;
            CHECK(tt_image_downsample2(sq, &al, &half, NULL) == TT_OK && half && fabs(half->pixels[2] - 0.8f) < 1e-6,
                  "a colour image is averaged as it is");
            tt_image_free(half);
            half = NULL;
            tt_image_free(sq);
        }
    }
    {
        tt_image *im = (tt_image *)&im;
        CHECK(tt_image_from_bytes(bytes, 4, 3, 2, 0, TT_COLOR_NORMAL, &al, &im, &err) == TT_ERROR_INVALID_ARGUMENT &&
                  im == NULL && strstr(err.message, "channels"),
              "a grey normal map is refused: %s", err.message);
        CHECK(tt_image_from_bytes(bytes, 4, 3, 4, 0, (tt_color_space)7, &al, &im, &err) == TT_ERROR_INVALID_ARGUMENT,
              "an unknown colour space is refused");
    }
done:
    tt_image_free(gl);
    tt_image_free(dx);
    CHECK(cnt.live == 0, "normal maps: %ld blocks left", cnt.live);
}

/* An image whose kind is not a tt_image_kind (a caller's struct) is refused
   by the steps that act on the kind, not taken as colour. */
/* The allocation-failure sweep of every image entry point that allocates:
   each allocation failed in turn gives TT_ERROR_OUT_OF_MEMORY with the
   error filled, *out NULL, and nothing leaked. */
typedef struct image_oom_ctx {
    const tt_image *src;
    const unsigned char *bytes;
    const float *cost;
    int which;
} image_oom_ctx;

static tt_result image_oom_call(void *ctx, const tt_allocator *al, tt_error *error)
{
    image_oom_ctx *c = (image_oom_ctx *)ctx;
    tt_image *out = (tt_image *)ctx;   /* must be reset to NULL on failure */
    tt_result r;
    int path[16], lo[5], hi[5], x;
    for (x = 0; x < 5; x++) {
        lo[x] = 2;
        hi[x] = 13;
    }
    switch (c->which) {
    case 0: r = tt_image_create(24, 16, al, &out, error); break;
    case 1: r = tt_image_from_bytes(c->bytes, 8, 6, 3, 0, TT_COLOR_SRGB, al, &out, error); break;
    case 2: r = tt_image_rotate90(c->src, 1, al, &out, error); break;
    case 3: r = tt_image_downsample2(c->src, al, &out, error); break;
    case 4: r = tt_image_resize(c->src, 7, 13, al, &out, error); break;
    case 5: {
        tt_courses courses;
        out = NULL;
        return tt_find_courses(c->src, al, &courses, error);
    }
    default:
        out = NULL;
        return tt_min_error_cut(c->cost, 5, 16, lo, hi, al, path, error);
    }
    if (r != TT_OK && out != NULL) return TT_RESULT_MAX_ENUM;
    tt_image_free(out);
    return r;
}

static void test_image_oom(void)
{
    static const char *const names[7] = {"tt_image_create", "tt_image_from_bytes", "tt_image_rotate90",
                                         "tt_image_downsample2", "tt_image_resize", "tt_find_courses",
                                         "tt_min_error_cut"};
    image_oom_ctx c;
    tt_image *src = NULL;
    unsigned char bytes[8 * 6 * 3];
    float cost[5 * 16];
    int i;
    make_value_noise(&src, 10, 16, 3);
    for (i = 0; i < (int)sizeof bytes; i++) bytes[i] = (unsigned char)(i * 29);
    for (i = 0; i < 5 * 16; i++) cost[i] = (float)((i * 7) % 11);
    c.src = src;
    c.bytes = bytes;
    c.cost = cost;
    for (c.which = 0; c.which < 7 && src; c.which++) {
        oom_reset();
        oom_sweep(names[c.which], image_oom_call, &c, TT_OK);
    }
    tt_image_free(src);
}

static void test_image_unknown_kind(void)
{
    tt_image *im = NULL, *out = NULL;
    tt_error err;
    tt_result r;
    if (tt_image_create(4, 4, NULL, &im, NULL) != TT_OK) { CHECK(0, "tt_image_create"); return; }
    im->kind = (tt_image_kind)7;
    r = tt_image_rotate90(im, 1, NULL, &out, &err);
    CHECK(r == TT_ERROR_INVALID_ARGUMENT && out == NULL && strstr(err.message, "kind 7"), "rotate90: %d (%s)", r,
          err.message);
    r = tt_image_downsample2(im, NULL, &out, &err);
    CHECK(r == TT_ERROR_INVALID_ARGUMENT && out == NULL && strstr(err.message, "kind 7"), "downsample2: %d (%s)", r,
          err.message);
    im->kind = TT_IMAGE_NORMAL;
    r = tt_image_rotate90(im, 1, NULL, &out, &err);
    CHECK(r == TT_OK && out && out->kind == TT_IMAGE_NORMAL, "rotate90 of a normal map: %d (%s)", r, err.message);
    tt_image_free(out);
    tt_image_free(im);
}

void run_image_tests(void)
{
    RUN(test_image_unknown_kind);
    RUN(test_image_basics);
    RUN(test_sample_wrap);
    RUN(test_color_transfer);
    RUN(test_color_bytes_identity);
    RUN(test_color_bytes_against_naive);
    RUN(test_color_mip);
    RUN(test_color_bytes_in_place);
    RUN(test_color_alpha_nan);
    RUN(test_from_bytes_errors);
    RUN(test_rotate);
    RUN(test_rotate_coords_large);
    RUN(test_over_downsample);
    RUN(test_resize);
    RUN(test_normal_maps);
    RUN(test_min_error_cut);
    RUN(test_image_oom);
}
