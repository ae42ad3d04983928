/* image_io.c - images for the `tiledtex` tool: loading any format stb_image
   reads into a float RGBA tt_image (after checking its size), and encoding
   PNG files (png_write.c compresses them). See tool.h for the interface. */

#include <limits.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tool.h"

/* stb_image (Debian package libstb-dev) is compiled in this one file (PNG
   files are written by png_write.c). They are not written for -Wextra -pedantic -Wshadow, so their
   own warnings are switched off around them - and only around them. */
#if defined(__GNUC__) || defined(__clang__)
#pragma GCC diagnostic push
#ifdef __clang__
#pragma clang diagnostic ignored "-Wunknown-warning-option"
#endif
#pragma GCC diagnostic ignored "-Wpedantic"
#pragma GCC diagnostic ignored "-Wunused-but-set-variable"
#pragma GCC diagnostic ignored "-Wshadow"
#pragma GCC diagnostic ignored "-Wunused-parameter"
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wsign-compare"
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#ifndef __cplusplus
#pragma GCC diagnostic ignored "-Wstrict-prototypes"
#endif
#pragma GCC diagnostic ignored "-Wimplicit-fallthrough"
#endif
#define STB_IMAGE_IMPLEMENTATION
#define STBI_FAILURE_USERMSG        /* friendlier texts from stbi_failure_reason() */
#include "stb_image.h"
#if defined(__GNUC__) || defined(__clang__)
#pragma GCC diagnostic pop
#endif

/* ======================================================================== */
/* Images                                                                   */
/* ======================================================================== */

static uint64_t image_max_pixels = TOOL_DEFAULT_MAX_PIXELS;
static int image_max_pixels_given = 0;

void image_set_max_pixels(uint64_t max_pixels)
{
    image_max_pixels = max_pixels;
    image_max_pixels_given = 1;
}

void image_set_default_max_pixels(uint64_t max_pixels)
{
    if (!image_max_pixels_given) image_max_pixels = max_pixels;
}

void image_free(tt_image *image)
{
    if (!image) return;
    free(image->pixels);
    free(image);
}

int image_crop(const tt_image *image, int x, int y, int width, int height, tt_image **out)
{
    tt_image *crop = (tt_image *)calloc(1, sizeof *crop);
    int row;
    *out = NULL;
    if (crop) crop->pixels = (float *)malloc((size_t)width * (size_t)height * 4 * sizeof(float));
    if (!crop || !crop->pixels) {
        free(crop);
        return -1;
    }
    crop->width = width;
    crop->height = height;
    crop->kind = image->kind;
    for (row = 0; row < height; row++)
        memcpy(crop->pixels + (size_t)row * (size_t)width * 4,
               image->pixels + ((size_t)(y + row) * (size_t)image->width + (size_t)x) * 4,
               (size_t)width * 4 * sizeof(float));
    *out = crop;
    return 0;
}

int image_resize(const tt_image *image, int width, int height, tt_image **out)
{
    tt_image *resized = NULL, *copy = (tt_image *)calloc(1, sizeof *copy);
    *out = NULL;
    if (copy && tt_image_resize(image, width, height, NULL, &resized, NULL) == TT_OK)
        copy->pixels = (float *)malloc((size_t)width * (size_t)height * 4 * sizeof(float));
    if (!copy || !copy->pixels) {
        tt_image_free(resized);
        free(copy);
        return -1;
    }
    copy->width = width;
    copy->height = height;
    copy->kind = resized->kind;
    memcpy(copy->pixels, resized->pixels, (size_t)width * (size_t)height * 4 * sizeof(float));
    tt_image_free(resized);
    *out = copy;
    return 0;
}

/* Rows converted at a time: the 8-bit decode shrinks by this much per step. */
#define LOAD_STRIP_BYTES (1u << 20)

/* 8-bit pixels (malloc'ed, width * channels bytes a row) to a float image in
   linear light, the tool's own (a view to the library, see image_free).
   The float pixels come from malloc untouched, and are filled in strips
   from the bottom row up; after each strip the 8-bit buffer is cut short by
   realloc, which gives its pages back. So the bytes and the floats are
   never both whole: at most 16 bytes a pixel and a strip, where converting
   in one go would hold 16 + channels. Takes ownership of `pixels`. */
static int convert_decoded(unsigned char *pixels, int width, int height, int channels, tt_color_space space,
                           tt_image **out, tt_error *error)
{
    size_t row = (size_t)width * (size_t)channels;
    int rows_per_strip = (int)(LOAD_STRIP_BYTES / row) > 0 ? (int)(LOAD_STRIP_BYTES / row) : 1, y1 = height;
    tt_image *image = (tt_image *)calloc(1, sizeof *image);
    *out = NULL;
    if (image) image->pixels = (float *)malloc((size_t)width * (size_t)height * 4 * sizeof(float));
    if (!image || !image->pixels) {
        free(image);
        free(pixels);
        memset(error, 0, sizeof *error);
        error->result = TT_ERROR_OUT_OF_MEMORY;
        snprintf(error->message, sizeof error->message, "out of memory for a %d x %d image", width, height);
        return -1;
    }
    image->width = width;
    image->height = height;
    while (y1 > 0) {
        int y0 = y1 > rows_per_strip ? y1 - rows_per_strip : 0;
        tt_image *strip;
        unsigned char *shorter;
        if (tt_image_from_bytes(pixels + (size_t)y0 * row, width, y1 - y0, channels, 0, space, NULL, &strip,
                                error) != TT_OK) {
            image_free(image);
            free(pixels);
            return -1;
        }
        memcpy(image->pixels + (size_t)y0 * (size_t)width * 4, strip->pixels,
               (size_t)(y1 - y0) * (size_t)width * 4 * sizeof(float));
        image->kind = strip->kind;   /* a normal map's vectors */
        tt_image_free(strip);
        y1 = y0;
        if (y1 > 0 && (shorter = (unsigned char *)realloc(pixels, (size_t)y1 * row)) != NULL) pixels = shorter;
    }
    free(pixels);
    *out = image;
    return 0;
}

int image_load(const char *path, tt_color_space space, tt_image **image, char *err, size_t err_size)
{
    unsigned char *file_data;
    size_t file_size;
    int status;
    *image = NULL;
    tool_stage("reading %s", tool_basename(path));
    if (tool_read_file(path, &file_data, &file_size, err, err_size) != 0) return -1;
    status = image_load_memory(file_data, file_size, path, space, image, err, err_size);
    free(file_data);
    return status;
}

/* What stb_image cannot be trusted with in a JPEG's Huffman tables, found
   by walking the segments as the decoder does, before it sees the file:
   - JPEG_TABLE_OVERFLOW: a DHT segment declares more than 256 codes for a
     table; some stb_image versions (Debian's among them) write past the
     table's 257 code sizes then.
   - JPEG_TABLE_UNDEFINED: a scan uses a table no DHT segment before it
     defined; the decoder then reads a table left as it was in memory (it
     failed its own assertion, and aborted, only when earlier work had left
     something there: fuzz_image found it after 250,000 runs).
   Both are invalid JPEG. A progressive JPEG defines tables between its
   scans too, so the walk goes on through each scan's coded data, where
   0xFF is followed by 0x00 or a restart marker; like the decoder, it steps
   over bytes that start no segment until the next 0xFF. A scan needs the
   DC table of each of its components when it codes DC coefficients for the
   first time (Ss = 0, Ah = 0: a sequential scan, or a progressive DC scan's
   first pass) and the AC table when it codes AC ones (Se > 0). */
enum { JPEG_TABLES_USABLE, JPEG_TABLE_OVERFLOW, JPEG_TABLE_UNDEFINED };

static int jpeg_huffman_tables_check(const unsigned char *data, size_t size)
{
    size_t at = 0;
    unsigned char defined[2][4] = {{0, 0, 0, 0}, {0, 0, 0, 0}}; /* [DC, AC][table id] */
    /* the start marker, after as many fill bytes (0xFF) as the file has */
    if (size < 2 || data[0] != 0xFF) return JPEG_TABLES_USABLE;
    while (at < size && data[at] == 0xFF) at++;
    if (at == size || data[at] != 0xD8) return JPEG_TABLES_USABLE;
    at++;
    while (at + 4 <= size) {
        size_t length, end, table;
        unsigned marker;
        if (data[at] != 0xFF) {           /* coded data, or junk the decoder skips too */
            at++;
            continue;
        }
        marker = data[at + 1];
        if (marker == 0xFF) {             /* fill byte */
            at++;
            continue;
        }
        if (marker == 0xD9) return JPEG_TABLES_USABLE; /* the end */
        if (marker == 0x00 || marker == 0x01 || (marker >= 0xD0 && marker <= 0xD7)) {
            at += 2;
            continue;
        }
        length = ((size_t)data[at + 2] << 8) | data[at + 3];
        if (length < 2) return JPEG_TABLES_USABLE;
        end = at + 2 + length;
        if (end > size) end = size;
        /* As the decoder reads a DHT: table after table while the segment's
           length lasts, each table's 16 counts read whole even where they run
           past the segment's end (or, as zeros, past the file's) */
        if (marker == 0xC4)
            for (table = at + 4; table < end;) {
                size_t codes = 0, k;
                unsigned kind = data[table] >> 4, id = data[table] & 15;
                for (k = 1; k <= 16; k++) codes += table + k < size ? data[table + k] : 0;
                if (codes > 256) return JPEG_TABLE_OVERFLOW;
                if (kind <= 1 && id <= 3) defined[kind][id] = 1;
                table += 17 + codes;
            }
        /* A scan's header: its component count, each component's table
           ids (DC high, AC low), then Ss, Se and Ah/Al. */
        if (marker == 0xDA && at + 5 <= size) {
            size_t count = data[at + 4], spectrum = at + 5 + 2 * count, k;
            if (spectrum + 2 < end) {
                int dc = data[spectrum] == 0 && (data[spectrum + 2] >> 4) == 0, ac = data[spectrum + 1] > 0;
                for (k = 0; k < count; k++) {
                    unsigned ids = data[at + 6 + 2 * k];
                    if ((dc && (ids >> 4) <= 3 && !defined[0][ids >> 4]) || (ac && (ids & 15) <= 3 && !defined[1][ids & 15]))
                        return JPEG_TABLE_UNDEFINED;
                }
            }
        }
        at = at + 2 + length;
    }
    return JPEG_TABLES_USABLE;
}

/* stb_image reads a binary PNM's width, height and maximum value into an
   int, digit by digit, without a bound: a longer number is undefined
   behaviour there. The header is read here as the decoder reads it (its
   whitespace and # comments) and a number over INT_MAX refused. */
static int pnm_header_overflows(const unsigned char *data, size_t size)
{
    size_t at = 2;
    int c, number;
    if (size < 2 || data[0] != 'P' || (data[1] != '5' && data[1] != '6')) return 0;
    c = at < size ? data[at++] : 0;
    for (number = 0; number < 3; number++) {
        uint64_t value = 0;
        for (;;) {
            while (at < size && (c == ' ' || (c >= '\t' && c <= '\r'))) c = data[at++];
            if (at >= size || c != '#') break;
            while (at < size && c != '\n' && c != '\r') c = data[at++];
        }
        while (at < size && c >= '0' && c <= '9') {
            value = value * 10 + (uint64_t)(c - '0');
            if (value > INT_MAX) return 1;
            c = data[at++];
        }
    }
    return 0;
}

/* stb_image grows its buffer for a PNG's compressed data to what each
   IDAT chunk's header declares, up to a gigabyte a chunk, before it reads
   the chunk: a file of a few dozen bytes made it ask for 2 GB. A chunk
   longer than what is left of the file is corrupt, so the chunks are walked
   here (length, type, data, CRC) and such a file refused before decoding. */
static int png_chunk_overruns(const unsigned char *data, size_t size)
{
    static const unsigned char signature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
    size_t at = 8;
    if (size < 8 || memcmp(data, signature, 8) != 0) return 0;
    while (at + 8 <= size) {
        uint64_t length = ((uint64_t)data[at] << 24) | ((uint64_t)data[at + 1] << 16) |
                          ((uint64_t)data[at + 2] << 8) | data[at + 3];
        if (length > size - at - 8) return 1;
        if (memcmp(data + at + 4, "IEND", 4) == 0) return 0;
        at += 8 + (size_t)length + 4;
    }
    return 0;
}

int image_load_memory(const unsigned char *file_data, size_t file_size, const char *path, tt_color_space space,
                      tt_image **image, char *err, size_t err_size)
{
    unsigned char *pixels;
    int width, height, channels;
    tt_error error;
    *image = NULL;
    if (file_size > INT_MAX) {
        tool_set_error(err, err_size, "'%s' is too large to be an image this tool can read", path);
        return -1;
    }
    /* Before stb_image reads anything: its header scan already reads the
       Huffman tables that come before a JPEG's frame header, a PNG's
       chunks and a PNM's numbers. */
    switch (jpeg_huffman_tables_check(file_data, file_size)) {
    case JPEG_TABLE_OVERFLOW:
        tool_set_error(err, err_size, "cannot decode '%s' (a corrupt JPEG: a Huffman table of more than 256 codes)",
                       path);
        return -1;
    case JPEG_TABLE_UNDEFINED:
        tool_set_error(err, err_size, "cannot decode '%s' (a corrupt JPEG: a scan uses a Huffman table never defined)",
                       path);
        return -1;
    default:
        break;
    }
    if (png_chunk_overruns(file_data, file_size)) {
        tool_set_error(err, err_size, "cannot decode '%s' (a corrupt PNG: a chunk longer than the rest of the file)",
                       path);
        return -1;
    }
    if (pnm_header_overflows(file_data, file_size)) {
        tool_set_error(err, err_size, "cannot decode '%s' (a corrupt PNM header: a number over %d)", path, INT_MAX);
        return -1;
    }
    /* Look at the header first: a corrupt or hostile file can claim a huge
       size, and we want to refuse it before anything is allocated for it. */
    if (!stbi_info_from_memory(file_data, (int)file_size, &width, &height, &channels)) {
        tool_set_error(err, err_size, "'%s' is not an image that can be read (%s)", path, stbi_failure_reason());
        return -1;
    }
    /* stb_image's HDR reader takes a size line such as "-Y 1 +X 0" at its
       word: no pixels (and a division by zero further on). */
    if (width < 1 || height < 1) {
        tool_set_error(err, err_size, "'%s' is an image of %d x %d pixels: nothing to read", path, width, height);
        return -1;
    }
    if (width > TT_MAX_IMAGE_SIZE || height > TT_MAX_IMAGE_SIZE) {
        tool_set_error(err, err_size, "'%s' is %dx%d; images up to %dx%d are supported", path, width, height,
                  TT_MAX_IMAGE_SIZE, TT_MAX_IMAGE_SIZE);
        return -1;
    }
    /* A small file can declare a huge image (a 62 KB PNG of 8000x8000 zeros
       would take over 1 GB as floats): refuse it before decoding a pixel. */
    if ((uint64_t)width * (uint64_t)height > image_max_pixels) {
        tool_set_error(err, err_size,
                       "'%s' is %dx%d = %llu pixels, over the limit of %llu (raise it with --max-pixels N)", path,
                       width, height, (unsigned long long)width * (unsigned long long)height,
                       (unsigned long long)image_max_pixels);
        return -1;
    }
    pixels = stbi_load_from_memory(file_data, (int)file_size, &width, &height, &channels, 0);
    if (!pixels) {
        tool_set_error(err, err_size, "cannot decode '%s' (%s)", path, stbi_failure_reason());
        return -1;
    }
    /* stb_image allocates with malloc (STBI_MALLOC is not overridden), so
       the decode may be shrunk with realloc and freed with free. */
    if (convert_decoded(pixels, width, height, channels, space, image, &error) != 0) {
        tool_set_error(err, err_size, "cannot use '%s': %s", path, error.message);
        return -1;
    }
    return 0;
}

/* The fewest channels that hold the image: no alpha when it is opaque, one
   grey channel when every texel has r = g = b (a roughness, height or
   occlusion map, a grey photo's atlas: a third of the bytes to compress).
   Packs the bytes in place (each pixel moves to a lower address, so it never
   overwrites one not yet moved) and returns the channel count they now have:
   1 grey, 2 grey + alpha, 3 RGB, 4 RGBA. */
static int pack_channels(unsigned char *rgba, size_t npixels)
{
    size_t i;
    int opaque = 1, grey = 1, channels, k;
    for (i = 0; i < npixels && (opaque || grey); i++) {
        const unsigned char *p = rgba + 4 * i;
        if (p[3] != 255) opaque = 0;
        if (p[0] != p[1] || p[0] != p[2]) grey = 0;
    }
    channels = (grey ? 1 : 3) + !opaque;
    if (channels == 4) return 4;
    for (i = 0; i < npixels; i++) {
        const unsigned char *p = rgba + 4 * i;
        unsigned char *q = rgba + (size_t)channels * i;
        unsigned char alpha = p[3];
        if (grey) q[0] = p[0];
        else
            for (k = 0; k < 3; k++) q[k] = p[k];
        if (!opaque) q[channels - 1] = alpha;
    }
    return channels;
}

int png_encode_rgba8(unsigned char *rgba, int width, int height, unsigned char **png, size_t *png_size, char *err,
                     size_t err_size)
{
    int channels;
    *png = NULL;
    *png_size = 0;
    if (!rgba || width <= 0 || height <= 0 || width > TT_MAX_IMAGE_SIZE || height > TT_MAX_IMAGE_SIZE) {
        tool_set_error(err, err_size, "cannot save an empty or oversized image");
        return -1;
    }
    tool_stage("compressing a %dx%d PNG", width, height);
    channels = pack_channels(rgba, (size_t)width * (size_t)height);
    if (png_write_to_memory(rgba, width, height, channels, png, png_size) != 0) {
        tool_set_error(err, err_size, "could not encode a %dx%d PNG (out of memory?)", width, height);
        return -1;
    }
    return 0;
}

/* Texels per task of image_to_rgba8: a few hundred tasks for an atlas. */
#define RGBA8_BAND_TEXELS 65536

typedef struct rgba8_job {
    const tt_image *image;
    tt_color_space space;
    unsigned char *out;
} rgba8_job;

static void rgba8_band(void *context, int begin, int end)
{
    const rgba8_job *job = (const rgba8_job *)context;
    size_t first = (size_t)begin * (size_t)job->image->width;
    tt_image band = *job->image;   /* a view of rows begin..end */
    band.height = end - begin;
    band.pixels = job->image->pixels + 4 * first;
    tt_image_to_rgba8(&band, job->space, job->out + 4 * first);
}

void image_to_rgba8(const tt_image *image, tt_color_space space, unsigned char *out)
{
    rgba8_job job;
    int rows = RGBA8_BAND_TEXELS / image->width;
    job.image = image;
    job.space = space;
    job.out = out;
    tool_parallel_ranges(tool_executor(), image->height, rows < 1 ? 1 : rows, rgba8_band, &job);
}

int png_encode(const tt_image *image, tt_color_space space, unsigned char **png, size_t *png_size, char *err,
               size_t err_size)
{
    unsigned char *rgba;
    int status;
    *png = NULL;
    *png_size = 0;
    if (!image || !image->pixels || image->width <= 0 || image->height <= 0 ||
        image->width > TT_MAX_IMAGE_SIZE || image->height > TT_MAX_IMAGE_SIZE) {
        tool_set_error(err, err_size, "cannot save an empty or oversized image");
        return -1;
    }
    rgba = (unsigned char *)malloc((size_t)image->width * (size_t)image->height * 4);
    if (!rgba) {
        tool_set_error(err, err_size, "out of memory while encoding a %dx%d PNG", image->width, image->height);
        return -1;
    }
    image_to_rgba8(image, space, rgba);
    status = png_encode_rgba8(rgba, image->width, image->height, png, png_size, err, err_size);
    free(rgba);
    return status;
}

static int add_encoded(tool_output *output, const char *path, unsigned char *png, size_t png_size, char *err,
                       size_t err_size)
{
    if (output_add(output, path, png, png_size) != 0) {
        tool_set_error(err, err_size, "out of memory while preparing '%s'", path);
        return -1;
    }
    return 0;
}

int output_add_png(tool_output *output, const char *path, const tt_image *image, tt_color_space space, char *err,
                   size_t err_size)
{
    unsigned char *png;
    size_t png_size;
    if (png_encode(image, space, &png, &png_size, err, err_size) != 0) return -1;
    return add_encoded(output, path, png, png_size, err, err_size);
}

int output_add_png_rgba8(tool_output *output, const char *path, unsigned char *rgba, int width, int height,
                         char *err, size_t err_size)
{
    unsigned char *png;
    size_t png_size;
    if (png_encode_rgba8(rgba, width, height, &png, &png_size, err, err_size) != 0) return -1;
    return add_encoded(output, path, png, png_size, err, err_size);
}
