/* fuzz_image.c - libFuzzer target for image input: the tool's loader
   (examples/image_io.c: stb_image's PNG, JPEG, BMP, TGA, GIF, PSD, HDR, PIC
   and PNM decoders behind the size checks, then tt_image_from_bytes in
   strips) and, on whatever decodes, tt_image_rotate90,
   tt_image_downsample2, tt_image_resize, tt_find_courses and
   tt_image_over; and tt_image_from_bytes directly on raw bytes with fuzzed
   sizes, channels, stride and colour space.

   Build (tests/fuzz/run.sh does this, with the library compiled once from
   tests/fuzz/fuzz_library.c; stb_image from libstb-dev):
       clang -g -O1 -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=all \
             -fno-sanitize=shift (see tests/fuzz/run.sh) \
             -I. -Iexamples -isystem /usr/include/stb tests/fuzz/fuzz_image.c tests/fuzz/fuzz_library.c \
             examples/image_io.c examples/png_write.c examples/tool_io.c \
             examples/executor.c examples/obj.c examples/format_number.c \
             -o build/fuzz/fuzz_image -lm -pthread

   Input bytes:
       0      bits 0..1 colour space (sRGB, linear, normal, normal y-down);
              bit2 raw mode (below) instead of the loader; bit3 allocation
              number byte[1] % 16 + 1 fails in the library calls; bits 4..7
              quarter turns - 8 (-8..7)
       1      which allocation fails
       then   the loader: the whole rest is the file. Raw mode: byte 2
              width 1..64 (0 and 65..255: b - 128, so negatives and zero too),
              3 height the same, 4 channels b % 6 (0 and 5 are refused), 5
              stride: 0 = packed, else packed + b % 8 - 2 (too short
              refused), then the pixel bytes (a short buffer is padded with
              a pattern so the library never reads past what it was given).

   The loader's pixel budget is set to 2^16 pixels (image_set_max_pixels),
   so a header that claims more is refused before decoding and a run stays
   fast. Besides crashes, leaks and undefined behaviour it aborts when a
   result breaks the contract: a decoded image with a size outside 1..256
   per side or a non-finite texel, an alpha outside [0, 1], a colour outside
   [0, 1] for sRGB or linear, a normal that is not a unit vector; a loader
   failure without a message; a turn with the wrong size or texels (a
   quarter turn four times is the image); a downsample of an odd size that
   succeeds or an even one that fails other than out of memory, or whose
   size is not half; `over` of an image with itself turned by 180 degrees
   failing, or with a non-finite result; an error without a sentence or out
   of memory with no failed allocation; an allocation not given back. */
#include "tiledtex.h"
#define FUZZ_NAME "fuzz_image"
#include "fuzz_common.h"
#include "tool.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define MAX_PIXELS 65536

static void check_image(const char *what, const tt_image *img, tt_color_space space)
{
    size_t i, n;
    CHECK(img && img->pixels && img->width >= 1 && img->height >= 1 && img->width <= 65536 &&
              (size_t)img->width * (size_t)img->height <= 4 * MAX_PIXELS,
          "%s: %d x %d", what, img ? img->width : -1, img ? img->height : -1);
    n = (size_t)img->width * (size_t)img->height;
    for (i = 0; i < n; ++i) {
        const float *p = img->pixels + 4 * i;
        CHECK(isfinite(p[0]) && isfinite(p[1]) && isfinite(p[2]) && isfinite(p[3]), "%s: texel %lu not finite", what,
              (unsigned long)i);
        CHECK(p[3] >= 0.0f && p[3] <= 1.0f, "%s: texel %lu alpha %g", what, (unsigned long)i, (double)p[3]);
        if (space == TT_COLOR_SRGB || space == TT_COLOR_LINEAR) {
            CHECK(img->kind == TT_IMAGE_COLOR, "%s: kind %d", what, (int)img->kind);
            CHECK(p[0] >= 0.0f && p[0] <= 1.0f && p[1] >= 0.0f && p[1] <= 1.0f && p[2] >= 0.0f && p[2] <= 1.0f,
                  "%s: texel %lu (%g, %g, %g)", what, (unsigned long)i, (double)p[0], (double)p[1], (double)p[2]);
        } else {
            double len = sqrt((double)p[0] * p[0] + (double)p[1] * p[1] + (double)p[2] * p[2]);
            CHECK(img->kind == TT_IMAGE_NORMAL, "%s: normal map of kind %d", what, (int)img->kind);
            CHECK(fabs(len - 1.0) < 1e-3, "%s: normal %lu has length %g", what, (unsigned long)i, len);
        }
    }
}

/* The library's operations on a decoded image (the tool's own memory: a
   view with width, height, kind and pixels, which the library only reads). */
static void operate(const tt_image *img, tt_color_space space, int turns, fz_alloc *a)
{
    tt_image *rot = NULL, *back = NULL, *half = NULL, *copy = NULL, *flip = NULL;
    tt_error err;
    tt_result r;
    size_t n = (size_t)img->width * (size_t)img->height;

    memset(&err, 0x55, sizeof err);
    r = tt_image_rotate90(img, turns, &a->tt, &rot, &err);
    if (r != TT_OK) {
        fz_check_error("tt_image_rotate90", r, &err, a);
        fz_check_null("tt_image_rotate90", r, rot);
        CHECK(r == TT_ERROR_OUT_OF_MEMORY, "tt_image_rotate90: %s", err.message);
    } else {
        int odd = turns & 1;
        CHECK(rot->width == (odd ? img->height : img->width) && rot->height == (odd ? img->width : img->height),
              "turned %d: %d x %d from %d x %d", turns, rot->width, rot->height, img->width, img->height);
        CHECK(rot->kind == img->kind, "turned kind %d from %d", (int)rot->kind, (int)img->kind);
        /* turning back gives the texels again (normals turn back too, to rounding) */
        memset(&err, 0x55, sizeof err);
        r = tt_image_rotate90(rot, -turns, &a->tt, &back, &err);
        if (r != TT_OK) {
            fz_check_error("tt_image_rotate90 (back)", r, &err, a);
            CHECK(r == TT_ERROR_OUT_OF_MEMORY, "tt_image_rotate90 back: %s", err.message);
        } else {
            size_t i;
            for (i = 0; i < 4 * n; ++i)
                CHECK(fabsf(back->pixels[i] - img->pixels[i]) <= 1e-5f, "turned %d and back: value %lu %g, was %g",
                      turns, (unsigned long)i, (double)back->pixels[i], (double)img->pixels[i]);
        }
    }

    memset(&err, 0x55, sizeof err);
    r = tt_image_downsample2(img, &a->tt, &half, &err);
    if (r != TT_OK) {
        fz_check_error("tt_image_downsample2", r, &err, a);
        fz_check_null("tt_image_downsample2", r, half);
        CHECK(r == TT_ERROR_OUT_OF_MEMORY || (r == TT_ERROR_INVALID_ARGUMENT && ((img->width | img->height) & 1)),
              "tt_image_downsample2 of %d x %d: %s", img->width, img->height, err.message);
    } else {
        CHECK(!((img->width | img->height) & 1), "downsampled an odd %d x %d", img->width, img->height);
        CHECK(half->width == img->width / 2 && half->height == img->height / 2, "half of %d x %d is %d x %d",
              img->width, img->height, half->width, half->height);
        check_image("downsampled", half, space);
    }

    /* resized to a size from the turns (shrunk, kept or grown on each axis):
       within the source's range of values (the filter's weights are
       non-negative), a normal map's vectors unit; and its courses, if any,
       inside its height */
    {
        static const int factors[4] = {1, 2, 3, 5};
        const int rw = img->width * factors[(turns + 8) & 3] / 3 + 1;
        const int rh = img->height * factors[((turns + 8) >> 2) & 3] / 3 + 1;
        tt_image *resized = NULL;
        tt_courses courses;
        memset(&err, 0x55, sizeof err);
        r = tt_image_resize(img, rw, rh, &a->tt, &resized, &err);
        if (r != TT_OK) {
            fz_check_error("tt_image_resize", r, &err, a);
            fz_check_null("tt_image_resize", r, resized);
            CHECK(r == TT_ERROR_OUT_OF_MEMORY, "tt_image_resize of %d x %d to %d x %d: %s", img->width, img->height,
                  rw, rh, err.message);
        } else {
            CHECK(resized->width == rw && resized->height == rh && resized->kind == img->kind,
                  "resized to %d x %d (kind %d) when asked %d x %d", resized->width, resized->height,
                  (int)resized->kind, rw, rh);
            check_image("resized", resized, space);
        }
        tt_image_free(resized);
        memset(&err, 0x55, sizeof err);
        r = tt_find_courses(img, &a->tt, &courses, &err);
        if (r != TT_OK) {
            fz_check_error("tt_find_courses", r, &err, a);
            CHECK(r == TT_ERROR_OUT_OF_MEMORY, "tt_find_courses of %d x %d: %s", img->width, img->height,
                  err.message);
        } else {
            CHECK(courses.period == 0.0f || (courses.period >= 2.0f && courses.period <= img->height / 3.0f + 1.0f &&
                                             courses.phase >= 0.0f && courses.phase < courses.period),
                  "courses of a %d x %d image: period %g, phase %g", img->width, img->height, (double)courses.period,
                  (double)courses.phase);
        }
    }

    /* over: a copy of the image (premultiplied where it is colour) under itself turned by 180 degrees */
    if (img->kind == TT_IMAGE_COLOR) {
        memset(&err, 0x55, sizeof err);
        if (tt_image_create(img->width, img->height, &a->tt, &copy, &err) == TT_OK &&
            tt_image_rotate90(img, 2, &a->tt, &flip, &err) == TT_OK) {
            size_t i;
            memcpy(copy->pixels, img->pixels, sizeof(float) * 4 * n);
            for (i = 0; i < n; ++i) {
                float *p = flip->pixels + 4 * i;
                p[0] *= p[3];
                p[1] *= p[3];
                p[2] *= p[3];
            }
            memset(&err, 0x55, sizeof err);
            r = tt_image_over(copy, flip, &err);
            CHECK(r == TT_OK, "tt_image_over: %s", err.message);
            for (i = 0; i < 4 * n; ++i)
                CHECK(isfinite(copy->pixels[i]) && copy->pixels[i] >= 0.0f && copy->pixels[i] <= 1.0f + 1e-5f,
                      "over: value %lu = %g", (unsigned long)i, (double)copy->pixels[i]);
        } else {
            CHECK(a->failed, "tt_image_create or rotate90 failed without an allocation failing: %s", err.message);
        }
    }
    tt_image_free(rot);
    tt_image_free(back);
    tt_image_free(half);
    tt_image_free(copy);
    tt_image_free(flip);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    fz_alloc a;
    uint8_t mode = size > 0 ? data[0] : 0, fail = size > 1 ? data[1] : 0;
    tt_color_space space = (tt_color_space)(mode & 3);
    int turns = (int)(mode >> 4) - 8;
    tt_image *img = NULL;

    image_set_max_pixels(MAX_PIXELS);
    fz_alloc_init(&a, (mode & 8) ? (long)(fail % 16) + 1 : 0);
    if (!(mode & 4)) {
        char err[TOOL_ERROR_SIZE];
        err[0] = '\0';
        if (image_load_memory(size > 2 ? data + 2 : data, size > 2 ? size - 2 : 0, "fuzz input", space, &img, err,
                              sizeof err) != 0) {
            CHECK(img == NULL && err[0] != '\0' && strlen(err) < sizeof err, "loader failed: img %p, message '%s'",
                  (void *)img, err);
            return 0;
        }
        check_image("decoded", img, space);
        operate(img, space, turns, &a);
        image_free(img);
    } else {
        /* tt_image_from_bytes on raw bytes */
        int w = size > 2 ? (data[2] >= 1 && data[2] <= 64 ? data[2] : (int)data[2] - 128) : 0;
        int h = size > 3 ? (data[3] >= 1 && data[3] <= 64 ? data[3] : (int)data[3] - 128) : 0;
        int ch = size > 4 ? data[4] % 6 : 0, stride_b = size > 5 ? data[5] : 0, stride = 0;
        unsigned char *buf;
        size_t need, k;
        tt_error e;
        tt_result r;
        if (w > 0 && ch > 0 && stride_b) stride = w * ch + stride_b % 8 - 2;
        need = (w > 0 && h > 0 && ch > 0) ? (size_t)(stride > w * ch ? stride : w * ch) * (size_t)h : 1;
        buf = (unsigned char *)malloc(need);
        if (!buf) abort();
        for (k = 0; k < need; ++k) buf[k] = 6 + k < size ? data[6 + k] : (unsigned char)(k * 37);
        memset(&e, 0x55, sizeof e);
        img = (tt_image *)&a;
        r = tt_image_from_bytes(buf, w, h, ch, stride, space, &a.tt, &img, &e);
        if (r != TT_OK) {
            fz_check_error("tt_image_from_bytes", r, &e, &a);
            fz_check_null("tt_image_from_bytes", r, img);
            CHECK(r == TT_ERROR_OUT_OF_MEMORY || w < 1 || h < 1 || ch < 1 || ch > 4 || (stride && stride < w * ch) ||
                      (ch < 3 && space >= TT_COLOR_NORMAL),
                  "tt_image_from_bytes %d x %d x %d stride %d space %d: %s", w, h, ch, stride, (int)space, e.message);
        } else {
            CHECK(img->width == w && img->height == h, "%d x %d from %d x %d", img->width, img->height, w, h);
            check_image("from bytes", img, space);
            operate(img, space, turns, &a);
            tt_image_free(img);
        }
        free(buf);
    }
    fz_check_all_freed(&a);
    return 0;
}
