/* tool.h - shared pieces of the `tiledtex` command-line tool (not the library).

   The tool is a set of subcommands, one file each (synth.c, map.c, tile.c,
   lapped.c, hpm.c, polycube.c, render.c, generate.c), dispatched by
   tiledtex.c; synth, map, tile and polycube also share tiled.c (see
   tiled.h). They share what is
   declared here:

     tool_io.c   one-line errors         tool_fail, tool_usage
                 files, byte buffers     tool_read_file, tool_buffer
                 atomic output           tool_output: build every file in
                                         memory, then commit them all or none
                 progress, time          tool_progress, tool_seconds_now, tool_cpu_seconds_now
     cli.c       command-line helpers    tool_option, parse_int, parse_mesh_option, ...
     image_io.c  images                  image_load, png_encode, output_add_png,
                                         image_to_rgba8
     obj.c       OBJ reading, writing    obj_parse, obj_read_text, obj_write
     gltf.c      glTF 2.0 (.glb, .gltf)  gltf_write, output_add_gltf,
                                         gltf_pack_metallic_roughness,
                 tangent frames          triangle_texture_axes
     mesh_file.c any mesh file, --weld   mesh_read, mesh_weld
                 MTL writing             mtl_add_material, output_add_mtl
     material.c  a material's maps       material_parse_option, material_load,
                 (--normal, ...)         output_add_map_png
     triangle_mesh.c  an OBJ as triangles   triangle_mesh_read (lapped, hpm, polycube)
                 mesh options            tool_quadrangulate, tool_check_subdivide,
                 (parsed in cli.c)       tool_note_cut_edges
     measure.c   quality for summaries   tool_measure_seams, tool_format_seams
     format_number.c  numbers as text   tool_format_float, tool_format_int
     executor.c  threads for the library  tool_executor, tool_set_jobs (-j N),
                 and for the tool        tool_run_tasks, tool_parallel_ranges
     png_write.c PNG files, in parallel  png_write_to_memory

   Conventions every command follows:
     - Errors are one line on stderr, "tiledtex: <message>" (or
       "tiledtex CMD: <message>" for a bad command line), and a non-zero exit
       status: TOOL_EXIT_FAILURE for a failure, TOOL_EXIT_USAGE for a bad
       command line.
     - A command never leaves a half-written output: it adds every file it
       makes to a tool_output and commits them together at the end. The
       commit refuses any output that is the same file as an input.
     - Warnings that are not errors go through tool_note, printed only when
       the command succeeds.
*/
#ifndef TILEDTEX_TOOL_H
#define TILEDTEX_TOOL_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "tiledtex.h"

#define TOOL_NAME "tiledtex"
#define TOOL_EXIT_FAILURE 1
#define TOOL_EXIT_USAGE 2

/* A good size for the `err` buffers the functions below fill. */
#define TOOL_ERROR_SIZE 512

/* The tool refuses to write textures (atlases, baked textures) wider than
   this: an 8192^2 PNG is already about 200 MB in memory while it is written,
   and few renderers take larger textures. (The library's own limit is
   TT_MAX_IMAGE_SIZE.) */
#define TOOL_MAX_ATLAS 8192

/* ---------------------------------------------------------------------- */
/* Subcommands: argv[0] is the subcommand's name ("render"), options follow. */
/* Each returns the process exit status.                                     */
/* ---------------------------------------------------------------------- */

int cmd_synth(int argc, char **argv);
int cmd_map(int argc, char **argv);
int cmd_tile(int argc, char **argv);
int cmd_lapped(int argc, char **argv);
int cmd_hpm(int argc, char **argv);
int cmd_polycube(int argc, char **argv);
int cmd_render(int argc, char **argv);
int cmd_generate(int argc, char **argv);

/* ---------------------------------------------------------------------- */
/* Errors (tool_io.c)                                                       */
/* ---------------------------------------------------------------------- */

/* The subcommand being run ("render"); the dispatcher sets it so that
   command-line errors can say which command they are about. NULL = none. */
void tool_set_command(const char *name);
const char *tool_command(void);

/* --quiet (a global option main takes): commands print nothing but errors:
   no summary, no progress line, no note (tool_print_notes). tool_quiet()
   is also true once the one output went to the standard output ("-"),
   which a summary would corrupt; the notes still print then, on stderr. */
void tool_set_quiet(int quiet);
int tool_quiet(void);

/* Print "tiledtex: <message>" on stderr and return TOOL_EXIT_FAILURE, so a
   command can write `return tool_fail("cannot ...");`. */
int tool_fail(const char *format, ...)
#if defined(__GNUC__) || defined(__clang__)
    __attribute__((format(printf, 1, 2)))
#endif
    ;

/* Print "tiledtex CMD: <message>" on stderr and return TOOL_EXIT_USAGE: for a
   bad command line. */
int tool_usage(const char *format, ...)
#if defined(__GNUC__) || defined(__clang__)
    __attribute__((format(printf, 1, 2)))
#endif
    ;

/* A warning for the user that is not an error ("mesh.obj:3: skipped ..."):
   kept, and printed as "tiledtex: <message>" on stderr by tool_print_notes,
   which main calls when the command succeeds, so that a failing command
   still prints exactly one line. Notes past the first 16 are dropped. */
void tool_note(const char *format, ...)
#if defined(__GNUC__) || defined(__clang__)
    __attribute__((format(printf, 1, 2)))
#endif
    ;
void tool_print_notes(void);

/* Fill the `err` buffer a function was given (which may be NULL). */
void tool_set_error(char *err, size_t err_size, const char *format, ...)
#if defined(__GNUC__) || defined(__clang__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

/* ---------------------------------------------------------------------- */
/* Command-line helpers (cli.c)                                             */
/*                                                                          */
/* A command walks its arguments like this:                                 */
/*                                                                          */
/*     for (i = 1; i < argc; i++) {                                         */
/*         const char *value;                                               */
/*         if (tool_is_help(argv[i])) { print_help(); return 0; }           */
/*         else if (tool_option(argc, argv, &i, "--size", &value)) {        */
/*             if (parse_size("--size", value, 1, 4096, &w, &h) != 0)       */
/*                 return TOOL_EXIT_USAGE;                                  */
/*         } else if (tool_is_option(argv[i]))                              */
/*             return tool_unknown_option(argv[i]);                         */
/*         else positional[npositional++] = argv[i];                        */
/*     }                                                                    */
/*                                                                          */
/* The parse_* functions print the error themselves (one line, naming the   */
/* option and the text they were given) and return -1; 0 means success.    */
/* ---------------------------------------------------------------------- */

/* "-h" or "--help". */
int tool_is_help(const char *arg);
/* The lines a command's help gives about its MESH argument: the formats
   mesh_read takes and, for the commands that write OBJs (writes_obj), the
   normals those get. */
void tool_print_mesh_help(int writes_obj);
/* Looks like an option: starts with '-' and is not just "-" or a number. */
int tool_is_option(const char *arg);
/* Report "unknown option '--colours': did you mean '--colors'? (see
   'tiledtex CMD --help')": the suggestion is the nearest of the options the
   command's parser compared `arg` with (through tool_option and tool_flag)
   and the global ones, when one is near; returns TOOL_EXIT_USAGE. */
int tool_unknown_option(const char *arg);
/* Whether `arg` is the flag `name` ("--smooth"): strcmp, and `name` is
   remembered as an option of the command for tool_unknown_option. */
int tool_flag(const char *arg, const char *name);
/* Room for an OUT_PREFIX: tool_output_prefix refuses longer ones, leaving
   room for the longest name a command adds ("_polycube.obj", "_patch_12.png"). */
#define TOOL_PREFIX_SIZE 4000

/* What the commands that write a textured mesh (tile, lapped, hpm,
   polycube) write it as: an OBJ with its MTL and PNGs, one binary glTF
   file (.glb), or a glTF as text (.gltf) with its .bin and PNGs beside it.
   Zero-initialised: OBJ, faces as they are. */
typedef enum tool_mesh_format { TOOL_FORMAT_OBJ = 0, TOOL_FORMAT_GLB = 1, TOOL_FORMAT_GLTF = 2 } tool_mesh_format;
typedef struct tool_mesh_output {
    tool_mesh_format format;    /* --format obj|glb|gltf, or an OUT_PREFIX ending in .glb or .gltf */
    int format_given;           /* --format was given */
    int triangles;              /* --triangles: OBJ faces written as triangle fans */
} tool_mesh_output;
/* If argv[*index] is --format obj|glb|gltf (only when accept_format) or
   --triangles, consume it and return 1; 0 for any other argument; -1 after
   printing a bad value. */
int parse_mesh_output_option(int argc, char **argv, int *index, int accept_format, tool_mesh_output *output);

/* OUT_PREFIX as given into `prefix` (TOOL_PREFIX_SIZE bytes), less a known
   extension (.obj, .mtl, .png, .glb, .gltf, any case): "out.obj" means
   out.obj + out.mtl + out.png, not out.obj.obj. With `output` (NULL for a
   command without --format) an OUT_PREFIX ending in .glb or .gltf also
   sets output->format to GLB or GLTF, and one that names another format
   than --format asks for is refused ("out.glb --format obj", "out.obj
   --format glb"); without `output` a .glb or .gltf name is refused (the
   command writes no glTF). A GLB is one file, so for GLB "-" (the standard
   output) is kept as the prefix; otherwise "-" is refused (the prefix
   names several files, standard output takes one), as are a directory and
   a too long prefix: prints the error and returns TOOL_EXIT_USAGE; 0
   otherwise. */
int tool_output_prefix(const char *text, tool_mesh_output *output, char *prefix);
/* The file PREFIX + SUFFIX ("out" + ".glb"), or "-" when the prefix is "-". */
void tool_output_path(const char *prefix, const char *suffix, char *path, size_t size);
/* The three arguments MESH IMAGE OUT_PREFIX of the commands that read a
   mesh and an image: checks there are exactly three and reads OUT_PREFIX
   with tool_output_prefix (and `output`, which may be NULL), reporting a
   problem (returns TOOL_EXIT_USAGE); 0 with the three set. */
int tool_mesh_image_prefix(const char *const *positional, int npositional, const char **mesh, const char **image,
                           tool_mesh_output *output, char *prefix);
/* Refuse "-" for `path` when the command writes several files this time
   (the standard output takes one): prints a usage error about `what`
   ("OUT.obj with --atlas") and returns TOOL_EXIT_USAGE; 0 otherwise. */
int tool_refuse_stdout(const char *path, int several, const char *what);

/* If argv[*index] is `name` ("--size"), consume its value - the next argument,
   or the text after '=' in "--size=800x600" - into *value, advance *index past
   it, and return 1. A missing value gives *value = NULL, which every parse_*
   function below reports as "--size needs a value". Returns 0 when argv[*index]
   is some other argument. */
int tool_option(int argc, char **argv, int *index, const char *name, const char **value);
/* The extension of the model file of `output`'s format: ".obj", ".glb" or ".gltf". */
const char *tool_model_extension(const tool_mesh_output *output);

/* An axis name: x, y or z (either case), with an optional sign: "-z",
   "+y". *axis gets 0, 1 or 2 and *sign +1 or -1; returns 0, or -1 without
   a message for anything else (NULL included), so that the caller can say
   what else it accepts. */
int parse_axis_name(const char *text, int *axis, int *sign);
/* --up and the like: an axis name (parse_axis_name) or a nonzero direction
   X,Y,Z, into up[3] (an axis becomes a unit vector, a direction is kept as
   given). Prints the error and returns -1 otherwise. */
int parse_up(const char *option, const char *text, double up[3]);
/* The texture's direction (lapped, hpm, tile): --up DIR (parse_up) and
   --constraints FILE, turned into a field by tool_make_field.
   Zero-initialised: no option given, up the library's default (+y). */
typedef struct tool_field {
    float up[3];                    /* --up; 0,0,0 = the library's default */
    const char *constraints_path;   /* --constraints FILE, or NULL */
    int given;                      /* --up or --constraints was given */
} tool_field;
/* If argv[*index] is --up or --constraints, consume it and return 1; 0 for
   any other argument; -1 after printing a bad value. */
int parse_field_option(int argc, char **argv, int *index, tool_field *field);
/* A photo laid in courses (bricks, blocks: tt_find_courses), with no --up
   given: one note, which says `without` (what the courses follow then) and
   what --up does, since a mesh made z-up shows them on end. found: the
   courses already found, or NULL to look here (a failure to look notes
   nothing). */
void tool_note_courses_without_up(const tt_image *image, const char *image_path, const tt_courses *found,
                                  const char *without);
/* Whether an image tiles: along each axis, the colour difference across its
   wrap (last column against the first, last row against the first) is no
   larger than that between at least TOOL_TILES_RANK of its neighbouring
   column (row) pairs. A photo that does not tile wraps onto unrelated
   texels, a larger difference than nearly every neighbouring pair (none
   of gravel_gray's, forest_floor's); a seamless one wraps like any pair
   (pebbles: 27 to 75 % of its pairs differ as much). 0 when it does not
   tile, is smaller than 3 x 3, or on a failed allocation. */
#define TOOL_TILES_RANK 0.05
int tool_image_tiles(const tt_image *image);
/* `without` for the commands whose up is +y unless told (lapped, polycube). */
#define TOOL_COURSES_DEFAULT_UP "they run level where +y is up, the default (OBJ's and glTF's convention)"

/* An integer in [min, max]: "tiledtex CMD: --seed wants an integer from 0 to 9, got 'x'". */
int parse_int(const char *option, const char *text, int min, int max, int *out);
/* An unsigned 64-bit integer (seeds), decimal or 0x hexadecimal. */
int parse_u64(const char *option, const char *text, uint64_t *out);
/* A finite number in [min, max]. */
int parse_float(const char *option, const char *text, double min, double max, double *out);
/* "WxH" such as "800x600", each side in [min, max]:
   "tiledtex render: --size wants WxH, got '12'". */
int parse_size(const char *option, const char *text, int min, int max, int *width, int *height);
/* Quiet versions for numbers read from files, whose errors name FILE:LINE:
   a whole string (blanks around allowed) as a long / a finite double;
   0 on success, -1 without a message otherwise. */
int parse_whole_long(const char *text, long *out);
int parse_whole_double(const char *text, double *out);
/* Exactly `count` comma-separated numbers, such as "X,Y" or "X,Y,W,H". */
int parse_float_list(const char *option, const char *text, int count, double *out);
int parse_int_list(const char *option, const char *text, int count, int *out);

/* ---------------------------------------------------------------------- */
/* Files and growing byte buffers (tool_io.c)                               */
/* ---------------------------------------------------------------------- */

/* Read a whole file (or "-" for standard input) into a malloc'ed buffer with a
   terminating NUL byte after the `*size` bytes of content. On failure returns
   -1 and says why in err ("cannot open 'x.obj': No such file or directory"). */
int tool_read_file(const char *path, unsigned char **data, size_t *size, char *err, size_t err_size);

/* tool_read_file remembers every regular file it read (device and inode,
   which catches "./m.obj" for "m.obj" and hard links). An output path that
   is a directory or is one of those inputs gives -1 and the reason in err,
   and so does a path that does not exist yet in a folder that does not
   exist or cannot be written; otherwise a new path is fine, and so is "-"
   (the standard output). output_commit checks every output; a command may check its
   outputs earlier, before a long computation, with
   tool_refuse_input_overwrite (prints the error, returns
   TOOL_EXIT_FAILURE, or 0 when the path is fine). */
int tool_check_output_path(const char *path, char *err, size_t err_size);
int tool_refuse_input_overwrite(const char *path);
/* Whether paths a and b name one existing file (device and inode). */
int tool_same_file(const char *a, const char *b);
/* Forget the inputs remembered so far (frees their list). */
void tool_forget_inputs(void);

/* A byte buffer that grows as text is appended. A failed allocation sets
   `failed` and makes every later append a no-op, so a writer can append
   freely and check once at the end. Zero-initialise it before use.
   With a `sink` (output_stream_begin sets one) the buffer does not grow
   past TOOL_STREAM_CHUNK: what it holds is written to the sink whenever
   the next append would not fit, so a file of hundreds of megabytes is
   made in one small buffer that stays in the cache. A failed write sets
   `failed` and `sink_error` (its errno). */
typedef struct tool_buffer {
    char *data;
    size_t size;
    size_t capacity;
    int failed;
    FILE *sink;
    int sink_error;
} tool_buffer;
#define TOOL_STREAM_CHUNK ((size_t)1 << 18)

/* An empty buffer, for initialising one (plain `= {0}` draws a warning from
   C++ compilers with -Wextra). */
#define TOOL_BUFFER_INIT {NULL, 0, 0, 0, NULL, 0}

void buffer_append(tool_buffer *buffer, const void *bytes, size_t count);
/* Room for up to `count` more bytes at the buffer's end, for a writer to
   fill in place and then count with buffer_wrote (no copy, as an append
   makes); NULL after a failed allocation. */
char *buffer_room(tool_buffer *buffer, size_t count);
void buffer_wrote(tool_buffer *buffer, size_t count);
void buffer_printf(tool_buffer *buffer, const char *format, ...)
#if defined(__GNUC__) || defined(__clang__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;
void buffer_free(tool_buffer *buffer);

/* ---------------------------------------------------------------------- */
/* Atomic output (tool_io.c): build every file in memory, then write them   */
/* all or none                                                              */
/* ---------------------------------------------------------------------- */

typedef struct tool_output_file {
    char *path;
    unsigned char *data;
    size_t size;
    char *temporary;    /* a streamed file (output_stream_begin): its contents are in this file, not `data` */
} tool_output_file;

/* Zero-initialise (tool_output out = TOOL_OUTPUT_INIT;). */
typedef struct tool_output {
    tool_output_file *files;
    int count;
    int capacity;
} tool_output;
#define TOOL_OUTPUT_INIT {NULL, 0, 0}

/* Add a file. The batch takes ownership of `data` (malloc'ed, may be NULL when
   size is 0) whether or not the call succeeds. Adding a path that is already
   in the batch replaces its contents. Returns 0, or -1 when out of memory. */
int output_add(tool_output *output, const char *path, void *data, size_t size);
/* Add the contents of a tool_buffer (which is emptied). Fails when the
   buffer's `failed` flag is set. */
int output_add_buffer(tool_output *output, const char *path, tool_buffer *buffer);
/* A file of the batch written while it is made instead of held whole in
   memory (an OBJ of a million faces is a hundred MB of text):
   output_stream_begin makes the checks output_commit makes of PATH, then
   opens the file's temporary beside it (as the commit names them) as the
   sink of `buffer` (empty, zero-initialised); append to the buffer as
   usual; output_stream_end writes the rest, closes the temporary and
   empties the buffer. The file then commits with the batch, or is removed
   by output_free. "-" (the standard output) is not streamed: its text
   stays in the buffer, and output_stream_end adds it as output_add_buffer
   does. Each returns 0, or -1 with the reason in err (a path refused,
   "cannot write 'PATH': ...", out of memory); after a failed begin,
   output_stream_end is not called. */
int output_stream_begin(tool_output *output, const char *path, tool_buffer *buffer, char *err, size_t err_size);
int output_stream_end(tool_output *output, const char *path, tool_buffer *buffer, char *err, size_t err_size);

/* First refuse (writing nothing) when an output path names a directory or
   the same file as an input (see tool_check_output_path), and remove what
   killed runs left beside the outputs ("PATH.tiledtex-tmp-PID" and
   "PATH.tiledtex-old-PID" of processes that are gone). Then write every file
   to a new temporary file beside it ("PATH.tiledtex-tmp-PID"), and only when
   all of them were written completely rename each onto its real name: the
   model files (.obj, .glb, .gltf) last, their previous versions moved aside
   before anything is replaced, so a model file present on disk always goes
   with the MTL and textures beside it, even after a kill. On any failure
   every previous file is put back as it was and every new one removed; no
   other path is ever touched.
   Returns 0 or -1 with the reason in err. The batch stays valid; free it with
   output_free.
   A batch of one file whose path is "-" goes to the standard output instead
   (and tool_quiet() is then true: no summary after the data); "-" in a
   batch of several is refused. */
int output_commit(tool_output *output, char *err, size_t err_size);
void output_free(tool_output *output);

/* ---------------------------------------------------------------------- */
/* Images (image_io.c)                                                      */
/* ---------------------------------------------------------------------- */

/* The pixel budget for the images the tool reads (the global option
   --max-pixels): 4096 x 4096, which take 256 MB as float RGBA.
   image_set_max_pixels is the user's --max-pixels; a command whose own
   inputs may be larger raises its default with image_set_default_max_pixels,
   which leaves a budget the user gave alone. render takes the largest
   texture the tool writes (TOOL_MAX_ATLAS on a side, a lapped bake at its
   cap): its textures cost about 21 bytes a pixel with their mip levels, so
   1.4 GB at 8192 x 8192 (1.6 GB at the peak, measured). */
#define TOOL_DEFAULT_MAX_PIXELS 16777216
#define TOOL_RENDER_MAX_PIXELS ((uint64_t)TOOL_MAX_ATLAS * (uint64_t)TOOL_MAX_ATLAS)
void image_set_max_pixels(uint64_t max_pixels);
void image_set_default_max_pixels(uint64_t max_pixels);

/* Load a PNG / JPEG / TGA / BMP / PSD / GIF / HDR / PIC / PNM file as a float
   RGBA tt_image in linear light (grey and grey+alpha become RGB(A); no alpha
   means alpha 1). `space` says how the file's 8-bit values encode colour:
   TT_COLOR_SRGB for colour pictures (photos, atlases, textures),
   TT_COLOR_LINEAR for data (masks). *image is NULL on failure. It is the
   tool's own memory, handed to the library as a view: free it with
   image_free, never tt_image_free. The 8-bit decode is converted in strips
   and shrinks as it goes, so loading holds about 16 bytes a pixel, not
   16 + channels.
   Errors: the file is missing or unreadable, is not an image stb_image can
   decode, is wider or taller than TT_MAX_IMAGE_SIZE, or has more pixels than
   the budget (image_set_max_pixels). Sizes are read from the header before
   any pixel is decoded. */
int image_load(const char *path, tt_color_space space, tt_image **image, char *err, size_t err_size);
/* image_load on a file's bytes already in memory (`path` only names it in
   the messages; the bytes are not kept): what image_load does after reading
   the file, and what tests/fuzz/fuzz_image.c calls. */
int image_load_memory(const unsigned char *data, size_t size, const char *path, tt_color_space space,
                      tt_image **image, char *err, size_t err_size);
void image_free(tt_image *image);
/* A copy of the width x height rectangle of `image` whose top-left texel is
   (x, y), which must lie inside it; the tool's own memory, like image_load's
   (free it with image_free). Returns 0, or -1 when out of memory. */
int image_crop(const tt_image *image, int x, int y, int width, int height, tt_image **out);
/* `image` resampled to width x height (tt_image_resize), in the tool's own
   memory like image_load's. Returns 0, or -1 when out of memory. */
int image_resize(const tt_image *image, int width, int height, tt_image **out);

/* tt_image_to_rgba8 on the tool's threads (-j), in bands of rows: the same
   bytes. `out` must not be the image's own pixels (bands would write over
   floats another band has still to read). */
void image_to_rgba8(const tt_image *image, tt_color_space space, unsigned char *out);
/* Encode an image as an 8-bit PNG in memory (malloc'ed; free it), its
   colours encoded into `space` (TT_COLOR_SRGB for every colour output).
   Written with the fewest channels that hold them: no alpha when opaque
   (else straight alpha), one grey channel when r = g = b everywhere. */
int png_encode(const tt_image *image, tt_color_space space, unsigned char **png, size_t *png_size, char *err,
               size_t err_size);
/* The same from 8-bit RGBA already encoded (width * height * 4 bytes), which
   the encoder may rewrite in place (packed to fewer channels). */
int png_encode_rgba8(unsigned char *rgba, int width, int height, unsigned char **png, size_t *png_size, char *err,
                     size_t err_size);
/* The PNG file of width x height pixels of `channels` bytes (1 grey, 2
   grey + alpha, 3 RGB, 4 RGBA), rows packed, in memory (malloc'ed; free
   it): filtered and compressed on the tool's threads (png_write.c), the
   same bytes at every -j. Returns 0, or -1 when out of memory or for sizes
   out of range. */
int png_write_to_memory(const unsigned char *pixels, int width, int height, int channels, unsigned char **png,
                        size_t *png_size);
/* Encode as PNG and add it to an output batch. */
int output_add_png(tool_output *output, const char *path, const tt_image *image, tt_color_space space, char *err,
                   size_t err_size);
int output_add_png_rgba8(tool_output *output, const char *path, unsigned char *rgba, int width, int height,
                         char *err, size_t err_size);

/* ---------------------------------------------------------------------- */
/* A material's maps (material.c)                                           */
/* ---------------------------------------------------------------------- */

/* The maps a material may have beside its colour (IMAGE), in this order;
   material_map_names gives each one's name in options, output names
   (OUT_PREFIX_normal.png) and summaries. */
enum { MATERIAL_NORMAL, MATERIAL_ROUGHNESS, MATERIAL_METALLIC, MATERIAL_AO, MATERIAL_HEIGHT, MATERIAL_MAPS };
extern const char *const material_map_names[MATERIAL_MAPS];

typedef struct material_maps {
    const char *paths[MATERIAL_MAPS];   /* --normal N.png ..., NULL when not given */
    int normal_y_down;                  /* --normal-y-down: N.png is DirectX-style, its y points down */
    tt_image *images[MATERIAL_MAPS];    /* material_load's, NULL when not given: the normal map as
                                           unit vectors +Y up (TT_IMAGE_NORMAL), the others linear
                                           data; alpha 1 */
} material_maps;

/* The help lines of the options, for the commands' help texts: INDENT is
   the string of spaces before the command's option descriptions. */
#define MATERIAL_OPTIONS_HELP(INDENT)                                                                  \
    "  --normal N.png\n" INDENT "a tangent-space normal map of IMAGE (+Y up: OpenGL, glTF, Blender),\n" \
    INDENT "laid out like IMAGE's texture, written as OUT_PREFIX_normal.png; its\n"                      \
    INDENT "vectors turn wherever the texture turns\n"                                                   \
    "  --normal-y-down\n" INDENT "N.png is DirectX style (y down); the output is +Y up all the same\n"   \
    "  --roughness R.png, --metallic M.png, --ao A.png, --height H.png\n" INDENT                          \
    "data maps of IMAGE (read as they are, never as sRGB colour), laid out\n" INDENT                      \
    "the same way: OUT_PREFIX_roughness.png, ... Every map must be IMAGE's\n" INDENT                      \
    "size; the MTL names them all\n"

/* If argv[*index] is one of the options above, consume it (and its value)
   and return 1; 0 for another argument; -1 after printing a bad value. */
int material_parse_option(int argc, char **argv, int *index, material_maps *maps);
/* How many maps were given. */
int material_count(const material_maps *maps);
/* Load every map given, each checked to be width x height (the colour
   image's, named image_path in the message). Prints the error and returns
   the exit status (nothing stays loaded then); 0 otherwise. */
int material_load(material_maps *maps, const char *image_path, int width, int height);
void material_free(material_maps *maps);
/* How a map is written to 8 bits: TT_COLOR_NORMAL or TT_COLOR_LINEAR. */
tt_color_space material_space(int map);
/* STEM_NAME.png, the output name of `map` beside STEM.png. */
void material_path(char *path, size_t size, const char *stem, int map);
/* tool_refuse_input_overwrite for each map's output beside STEM. */
int material_refuse_overwrite(const material_maps *maps, const char *stem);
/* Encode a map (of any kind: alpha is written as 1) as a PNG into the
   batch; prints the error and returns the exit status on failure. */
int output_add_map_png(tool_output *output, const char *path, int map, const tt_image *image);
/* A GLB's material gets the maps laid out as images[map] (NULL for a map
   not given): normal, roughness, metallic and occlusion; glTF has no slot
   for the height map, which a note then says. */
struct tool_material;
void material_for_glb(struct tool_material *material, const material_maps *maps, const tt_image *const *images);

/* ---------------------------------------------------------------------- */
/* Wavefront OBJ (obj.c)                                                    */
/* ---------------------------------------------------------------------- */

typedef struct obj_mesh {
    int nverts;  float *pos;          /* 3 * nverts */
    int nfaces;  int *face_size;      /* corners per face */
    int ncorners; int *corner_vert;   /* 0-based vertex per corner, faces one after another */
    int nuvs;    float *uv;           /* 2 * nuvs, from vt lines */
    float *uv_w;                      /* nuvs: each vt's third number, 1 where a vt has none; NULL
                                         when none has one (the tool writes w as a paste's fade) */
    int *corner_uv;                   /* ncorners entries (0-based vt index) or NULL when no face has vt; -1 for a corner without one */
    int nnormals; float *normal;      /* 3 * nnormals, from vn lines, as written (not normalised) */
    int *corner_normal;               /* ncorners entries (0-based vn index) or NULL when no face has vn; -1 for a corner without one */
    int *face_group;                  /* nfaces: index into group_names of the `g`/`o`/`usemtl` group the face is in (0 = before any) */
    int ngroups; char **group_names;  /* group_names[0] = "" */
    int *face_material;               /* nfaces: index into material_names of the latest `usemtl` (0 = before any) */
    int nmaterials; char **material_names;  /* material_names[0] = "" */
    char *mtllib;                     /* first mtllib name or NULL */
    int *vert_line;                   /* nverts: the file line of each `v`, for messages */
    int *face_line;                   /* nfaces: the file line of each `f` */
    int unknown_statements;           /* statements with a keyword the reader does not know (skipped) */
    int first_unknown_line;           /* the line of the first of them */
    char first_unknown[32];           /* its keyword, cut short, unprintable bytes as '?' */
} obj_mesh;

/* Parse OBJ text (`length` bytes, need not end in NUL; any bytes are safe).
   Reads v, vt, vn, f (corners v, v/vt, v//vn, v/vt/vn; negative indices count
   back from the latest vertex, texture vertex or normal), g / o / usemtl
   (which group each face is in; the latest of these statements names it),
   usemtl again on its own (each face's material: the latest usemtl,
   whatever g / o came after it), and the first mtllib. Everything
   else (s, l, p, comments, unknown statements) is skipped; unknown
   statements are counted in unknown_statements. Lines end in LF, CRLF or a
   lone CR; a UTF-8 byte-order mark at the start is skipped. A line ending in
   '\' continues on the next. Returns 0, or -1 with a message naming the line
   in err ("line 12: face with fewer than 3 corners") and *out zeroed. */
int obj_parse(const char *text, size_t length, obj_mesh *out, char *err, size_t err_size);
/* The file's normals at the face corners (unit length, 3 floats per corner,
   malloc'd) when every corner has a usable one: a vn that is neither zero
   nor NaN nor infinite. Otherwise *out is NULL: silently when no corner
   has a vn (STL, OFF, most scans), with a note naming `path` when only
   some have one (the outputs then get computed normals). Returns 0, or -1
   when out of memory. */
int obj_corner_normals(const char *path, const obj_mesh *mesh, float **out);
/* The description that hands an OBJ's arrays to tt_mesh_build as they are:
   corners are faces one after another, the library's index-buffer layout. */
tt_mesh_desc obj_mesh_desc(const obj_mesh *mesh, unsigned flags);

/* Parse the text of the OBJ file `path` (size bytes; mesh_read reads the
   file); messages start with the path ("mesh.obj:12: ..."). Unknown
   statements give one tool_note naming the first and the count. */
int obj_read_text(const char *path, const char *text, size_t size, obj_mesh *out, char *err, size_t err_size);
void obj_free(obj_mesh *mesh);

/* ---------------------------------------------------------------------- */
/* Mesh files (mesh_file.c): how every command reads its mesh               */
/* ---------------------------------------------------------------------- */

/* --weld merges vertices closer than this times the diagonal of the mesh's
   bounding box (and only those: vertices of one face that merge make a
   face that repeats a vertex, which the build then names). */
#define TOOL_WELD_TOLERANCE 1e-6

/* The global option --weld: mesh_read welds every mesh it reads. */
void mesh_set_weld(int weld);

/* Read a mesh file into an obj_mesh: a Wavefront OBJ (obj_read_text), an
   STL (ASCII or binary; always welded at exactly equal positions, since
   STL has no shared vertices) or an OFF file. The format is told by the
   first bytes, then by the extension (any case); glTF / GLB, PLY, FBX,
   COLLADA and 3DS files are refused with one line naming the format and a
   conversion command. Under --weld the mesh is welded (mesh_weld with
   TOOL_WELD_TOLERANCE); without it, a mesh whose every vertex is in one
   corner while positions repeat gets a note suggesting --weld (welding
   leaves the corners as they are, with their normals). STL and OFF
   meshes have no texture coordinates, normals (an STL's facet normals are
   flat: they are skipped), groups or materials; a binary
   STL's faces have no line (face_line 0). Returns 0, or -1 with the
   message in err. */
int mesh_read(const char *path, obj_mesh *out, char *err, size_t err_size);
/* The same on the file's bytes already read (`size` of them, any bytes;
   need not end in NUL): `path` names the file in messages and lends its
   extension to the format's detection. */
int mesh_read_data(const char *path, const unsigned char *data, size_t size, obj_mesh *out, char *err,
                   size_t err_size);

/* Merge every vertex into the first (by index) within `tolerance` times
   the bounding box diagonal (0: exactly equal positions), renumbering the
   vertices in that order and the corners with them; non-finite positions
   stay apart. Returns how many vertices were merged away, or -1 when out
   of memory (the mesh is then unchanged). */
int mesh_weld(obj_mesh *mesh, double tolerance);

/* The materials of an MTL file: newmtl NAME, its map_Kd (the diffuse
   texture) and its norm (a tangent-space normal map) as the file names
   them: relative to the MTL's directory unless absolute; options before
   the name are skipped. Everything else in the file is skipped. */
typedef struct mtl_library {
    int count;
    char **names;           /* count material names */
    char **diffuse_maps;    /* count map_Kd file names, NULL for a material without one */
    char **normal_maps;     /* count norm file names, NULL for a material without one */
} mtl_library;

/* Read an MTL file. Returns 0, or -1 with a message in err (a file that
   cannot be read, out of memory). */
int mtl_read(const char *path, mtl_library *out, char *err, size_t err_size);
void mtl_free(mtl_library *library);
/* The index of the material called `name`, or -1. */
int mtl_find(const mtl_library *library, const char *name);

/* Split every face (c0, c1, ..., cn-1) into the fan of triangles (c0, ci,
   ci+1), in face order: exact for triangles and convex polygons, which is
   what meshes are made of, and each triangle keeps its face's winding.
   *corners gets 3 OBJ corners per triangle (indices into corner_vert and
   corner_uv), *faces the OBJ face of each (both malloc'ed). Returns the
   number of triangles, or -1 when out of memory. */
int obj_triangle_fans(const obj_mesh *mesh, int **corners, int **faces);

/* Print a tt_mesh_build error about `obj` the OBJ file's way - faces and
   vertices counted from 1, "mesh.obj:12: face 3 has zero area ..." - and
   return TOOL_EXIT_FAILURE. The error's face and vertex indices must be the
   OBJ's. offer_permissive: the command has --permissive, so say when it
   would accept the mesh. */
int obj_report_mesh_error(const char *obj_path, const obj_mesh *obj, const tt_error *error, int offer_permissive);

/* What obj_write writes. Only positions and faces are required. */
typedef struct obj_write_desc {
    const char *comment;            /* "# ..." header lines (may contain '\n'), or NULL */
    int nverts;
    const float *pos;               /* 3 * nverts */
    int nfaces;
    const int *face_size;           /* nfaces corner counts, or NULL: all fixed_face_size */
    int fixed_face_size;
    const int *corner_vert;         /* 0-based, faces one after another */
    const float *corner_uv;         /* 2 floats per corner, or NULL: no vt, faces are "f v v v" */
    const float *corner_uv_w;       /* 1 float per corner written as each vt's third number (a
                                       lapped paste's fade), or NULL: "vt u v" */
    const float *corner_normal;     /* 3 floats per corner written as "vn", faces "f v/vt/vn" (or
                                       "v//vn"), or NULL: no normals */
    const char *mtllib;             /* "mtllib NAME" line, or NULL */
    const char *material;           /* "usemtl NAME" before the faces, or NULL */
    int triangles;                  /* --triangles: each face written as the fan of triangles
                                       (c0, ci, ci+1), with its corners' vt and vn */
    int share_equal;                /* each distinct vt and vn (equal bit for bit) written once, in
                                       the order corners first use it: tile's UVs take a few values
                                       and smooth normals one per vertex, so the file is less than
                                       half as long. 0: one of each per corner, corner c using
                                       vt c + 1 and vn c + 1 */
    /* Optional groups: face_group[f] indexes group_names (and group_materials,
       when given); "g NAME" (and "usemtl MATERIAL") is written before every
       run of faces whose group differs from the previous face's. */
    const int *face_group;          /* nfaces, or NULL */
    int ngroups;
    const char *const *group_names;
    const char *const *group_materials;   /* or NULL: use `material` for all */
} obj_write_desc;

/* Append the OBJ text to `out`: "v x y z", then one "vt u v" per face corner
   (when corner_uv is given), one "vn x y z" per face corner (when
   corner_normal is given) - or each distinct one once (share_equal) -
   then "f v/vt/vn ..." with 1-based indices. Numbers
   use 9 significant digits (tool_format_float), so floats read back exactly. At -j N the lines are
   formatted on the tool's threads (tool_executor), in pieces joined in order: the same text. Returns
   0, or -1 on an invalid description or when the buffer ran out of memory. */
int obj_write(tool_buffer *out, const obj_write_desc *desc);
/* obj_write into a new file of the batch; on failure (out of memory) one
   line "out of memory while writing PATH" and the failure exit status. */
int output_add_obj(tool_output *output, const char *path, const obj_write_desc *desc);

/* Faces meeting at more than this many degrees keep their own normals in
   the OBJs the commands write (a CAD part's edges); the rest are smoothed
   (a scan). */
#define TOOL_CREASE_DEGREES 60.0f

/* Shading normals for an output OBJ, 3 floats per corner of `mesh`,
   malloc'd: `carried` renormalised (the input file's normals carried to
   these corners, interpolated) when it is not NULL, else computed (tt_corner_normals at
   TOOL_CREASE_DEGREES). NULL when out of memory, with the error printed
   naming `path`. */
float *tool_corner_normals(const char *path, const tt_mesh *mesh, const float *carried);

/* Append one MTL material: "newmtl NAME", white diffuse colour, and
   "map_Kd TEXTURE" when texture is not NULL; with texture_alpha also
   "map_d TEXTURE": the texture's alpha channel is the material's opacity.
   maps (NULL, or MATERIAL_MAPS names, each NULL when absent) adds the
   material's other maps: the normal map as "map_Bump -bm 1" (how Blender
   writes and reads one) and "norm" (the PBR extension's name, which
   assimp and three.js read), roughness "map_Pr", metallic "map_Pm", height
   "disp", and the occlusion map as a comment (MTL has no statement for it;
   the .glb output carries it). */
void mtl_add_material(tool_buffer *out, const char *name, const char *texture, int texture_alpha,
                      const char *const *maps);
/* Add a one-material MTL file to an output batch; it names texture_path
   (a path from the current directory) relative to the MTL's own directory
   (tool_relative_path), so the folder can move; map_paths as
   mtl_add_material's maps, paths from the current directory too. Returns 0,
   or the exit status after printing the error. */
int output_add_mtl(tool_output *output, const char *mtl_path, const char *material, const char *texture_path,
                   int texture_alpha, const char *const *map_paths);
/* The same with `count` materials, materials[k] naming texture_paths[k] and
   the MATERIAL_MAPS map paths from map_paths + k * MATERIAL_MAPS (map_paths
   may be NULL: colour only). */
int output_add_mtl_materials(tool_output *output, const char *mtl_path, int count, const char *const *materials,
                             const char *const *texture_paths, int texture_alpha, const char *const *map_paths);

/* ---------------------------------------------------------------------- */
/* glTF 2.0, .glb and .gltf (gltf.c)                                      */
/* ---------------------------------------------------------------------- */

/* The material of a GLB, as a command holds it: its images, each NULL when
   the command has none. Every image is the tool's float RGBA, row 0 at the
   top (image_load's, or one the library made); colour in linear light, the
   data maps as their bytes say (loaded with TT_COLOR_LINEAR). Absent maps
   take glTF's neutral meaning: no normal or occlusion texture, roughness 1
   (matte, as the tool's MTL files ask with Ks 0) and metalness 0. */
typedef struct tool_material {
    const char *name;               /* the material's name ("tiled"); NULL: the object's */
    const tt_image *base_color;     /* colour (written as sRGB, as glTF reads it); its alpha is
                                       not used: the material is opaque. NULL: white */
    const tt_image *normal;         /* tangent-space normal map, +Y up (OpenGL's and glTF's
                                       convention): unit vectors (TT_IMAGE_NORMAL, as
                                       material_load gives them), or RGB = (n + 1) / 2 */
    const tt_image *roughness;      /* roughness in R (a grey map); packed with metallic into
                                       glTF's metallicRoughness texture (G roughness, B metallic) */
    const tt_image *metallic;       /* metalness in R, the same size as roughness when both are given */
    const tt_image *occlusion;      /* ambient occlusion in R, 1 = open */
    int repeat;                     /* the texture coordinates leave [0,1] and the images tile
                                       (hpm --toroidal): REPEAT addressing; 0: CLAMP_TO_EDGE, for
                                       atlases, whose coordinates stay inside their tiles or charts */
} tool_material;

/* glTF's metallicRoughness texture from separate maps, either of which may
   be NULL (not both): G = roughness's R, B = metallic's R, each rounded to
   a byte; an absent roughness map's channel is 255, so that the material's
   factor alone gives its value (roughnessFactor 1); without a metallic map
   gltf_write writes metallicFactor 0, B is then unread and R and B repeat
   G (a grey image, which the PNG writer stores in one channel); otherwise R
   is 255. Alpha is 255 (glTF reads neither R nor alpha).
   *rgba gets width * height * 4 bytes, malloc'ed. Returns 0, or -1 with the
   reason in err: both NULL, sizes that differ, out of memory. */
int gltf_pack_metallic_roughness(const tt_image *roughness, const tt_image *metallic, unsigned char **rgba,
                                 int *width, int *height, char *err, size_t err_size);

/* A whole GLB file in memory (*glb malloc'ed, *glb_size bytes): one scene
   with one node and mesh called `name`, the mesh's faces as triangle fans
   with one material, and the material's images as embedded PNGs. The mesh
   is the one obj_write takes - positions, faces of any size, texture
   coordinates and normals per corner; its comment, mtllib, material and
   groups are not used, nor corner_uv_w, nor triangles (a GLB holds
   triangles only). Texture coordinates are required when the material has
   an image, and are given the OBJ's way (v up from the image's bottom row;
   they are flipped for glTF, whose v runs down from the top). Each
   distinct (position, texture coordinate, normal) of a corner becomes one
   glTF vertex; normals are made unit length (a zero normal takes its
   face's). Returns 0, or -1 with the reason in err: a face of fewer than 3
   corners or none at all, a corner naming no vertex, a NaN or infinite
   coordinate, a file over 4 GB, out of memory. */
int gltf_write(const obj_write_desc *mesh, const tool_material *material, const char *name, unsigned char **glb,
               size_t *glb_size, char *err, size_t err_size);
/* The scene of gltf_write into the batch, its object named after the file
   ("out" for out.glb or out.gltf; "tiledtex" for "-"): for a PATH ending
   in .gltf (any case) the separate form, PATH holding the JSON, PATH less
   .gltf plus ".bin" the arrays and PATH less .gltf plus "_baseColor.png",
   "_normal.png", "_metallicRoughness.png" and "_occlusion.png" the images
   it has, each named from the JSON by a relative URI; otherwise one GLB
   file. On failure one line naming PATH, and the failure exit status. */
int output_add_gltf(tool_output *output, const char *path, const obj_write_desc *mesh, const tool_material *material);
/* PATH as a summary names what was written: a .gltf with the files beside
   it ("p.gltf, p.bin, p_*.png", into `text`), a GLB alone (PATH itself). */
const char *gltf_written(const char *path, char *text, size_t size);

/* A triangle's texture axes: dP/du into axes[0..2] and dP/dv into
   axes[3..5], the derivatives of the linear map its corners' texture
   coordinates t0, t1, t2 (v up, as in OBJ) make from positions p0, p1, p2.
   The frame a tangent-space normal map is read in (x along +u, y along +v),
   for the GLB's tangents and render's normal mapping. Returns 0, or -1
   (axes zeroed) when the coordinates span no area or the axes are not
   finite. */
int triangle_texture_axes(const float *p0, const float *p1, const float *p2, const float *t0, const float *t1,
                          const float *t2, double axes[6]);

/* ---------------------------------------------------------------------- */
/* Meshes refined and repaired: --subdivide, --smooth, --permissive         */
/* (cli.c parses them, triangle_mesh.c applies them)                        */
/* ---------------------------------------------------------------------- */

/* The options of the commands that may refine or repair the mesh they read
   (map, tile, lapped, hpm). */
typedef struct tool_mesh_options {
    int subdivide;          /* --subdivide L: quadrangulation steps, or TOOL_SUBDIVIDE_AUTO */
    int smooth;             /* --smooth: Catmull-Clark positions for those steps */
    int permissive;         /* --permissive: built with TT_MESH_PERMISSIVE, bad edges cut open */
    int auto_allowed;       /* set by the command before parsing: --subdivide auto is accepted */
} tool_mesh_options;

/* --subdivide auto (hpm's default): the command chooses the steps once it
   knows the texture's scale; triangle_mesh_read then leaves the mesh as
   it is, for triangle_mesh_subdivide. */
#define TOOL_SUBDIVIDE_AUTO (-1)

/* If argv[*index] is --subdivide L (0 to 8, or auto where auto_allowed),
   --smooth or --permissive, consume it and return 1; 0 for any other
   argument; -1 after printing a bad value. */
int parse_mesh_option(int argc, char **argv, int *index, tool_mesh_options *options);

/* Subdividing past this many quads is refused (an OBJ of 16M quads is already
   about 1.5 GB of text). */
#define TOOL_MAX_QUADS (1 << 24)

/* One quadrangulation step (tt_mesh_quadrangulate) replacing *mesh: linear,
   which keeps the shape, or with smooth Catmull-Clark positions. Per-corner
   values go along (tt_mesh_quadrangulate_sources, interpolated linearly
   within each face): *corner_uv (2 floats per corner) and *corner_normal
   (3; renormalised only when written, by tool_corner_normals, so several
   steps interpolate as one) are replaced by the new corners' (malloc'd, the old ones freed), each when
   neither the pointer nor the array it points to is NULL. Prints the error
   and returns the exit status on failure, everything then unchanged. */
int tool_quadrangulate(const char *obj_path, tt_mesh **mesh, int smooth, float **corner_uv, float **corner_normal);
/* Before `steps` such steps of `mesh`: refuse (one line, the exit status)
   what would make more than TOOL_MAX_QUADS quads; 0 otherwise. */
int tool_check_subdivide(const char *obj_path, const tt_mesh *mesh, int steps);

/* The note a successful command gives (tool_note) when --permissive cut
   `edges` edges open. */
void tool_note_cut_edges(const char *obj_path, int edges);

/* ---------------------------------------------------------------------- */
/* An OBJ as triangles (triangle_mesh.c), for lapped, hpm, polycube         */
/* ---------------------------------------------------------------------- */

typedef struct triangle_mesh {
    obj_mesh obj;
    int ntriangles;
    int nverts;
    const float *pos;       /* 3 * nverts: the triangles' vertices, obj.pos or subdivided_pos */
    float *subdivided_pos;  /* --subdivide: the OBJ's vertices, then the new ones; else NULL */
    int *vert;              /* 3 per triangle: its vertices */
    float *corner_uv;       /* 6 per triangle: the OBJ's texture coordinates at its corners
                               (interpolated on subdivided triangles), or NULL when some
                               corner of the OBJ has none */
    float *corner_normal;   /* 9 per triangle: the OBJ's normals at its corners, unit length
                               (interpolated, not renormalised, on subdivided triangles), or
                               NULL unless every corner of the OBJ has one (obj_corner_normals):
                               pass it to tool_corner_normals */
    int *face;              /* per triangle: its OBJ face */
    int *first_triangle;    /* per OBJ face: the first of its triangles (they follow one another) */
    int subdivided;         /* --subdivide steps taken */
    int repaired_edges;     /* edges --permissive cut open in the OBJ's triangles */
    unsigned flags;         /* TT_MESH_* the triangles are built with */
    tt_mesh *mesh;          /* the triangles, validated */
} triangle_mesh;

/* Read the OBJ, split its faces into triangle fans (obj_triangle_fans) and
   build those with tt_mesh_build. `options` is NULL for a command without
   the mesh options; with them, --permissive builds with TT_MESH_PERMISSIVE
   (and a build error says when it would help), and --subdivide L
   quadrangulates the triangles L times (with Catmull-Clark positions under
   --smooth) and splits every quad into two triangles: a triangle becomes 6,
   then 24, 96, ... (TOOL_SUBDIVIDE_AUTO leaves that to the command,
   triangle_mesh_subdivide); the file's texture coordinates and normals, when every
   corner has them, go along (corner_uv, corner_normal). A build error is
   printed about the OBJ's own face and line. Returns 0, or the exit status after printing the error (*m is then
   empty). */
int triangle_mesh_read(const char *path, const tool_mesh_options *options, triangle_mesh *m);
/* The triangles of m (read without subdividing) quadrangulated `steps`
   times (smooth: Catmull-Clark positions) and every quad split in two, as
   --subdivide does; built again. Returns 0, or the exit status after
   printing the error (m then holds no triangles: free it). */
int triangle_mesh_subdivide(const char *path, int steps, int smooth, triangle_mesh *m);
void triangle_mesh_free(triangle_mesh *m);
/* Reverse every triangle's corners (an inside-out mesh turned outward) and
   build the mesh again; the file's normals, if any, are turned round too
   unless they already faced the new way. Returns 0, or the exit status
   after printing the error. */
int triangle_mesh_reverse(const char *path, triangle_mesh *m);


/* A library error about the triangles said the OBJ's way: the library counts
   faces from 0 and means the triangles. rewrite_face writes error->message
   into `message` with its "face N" replaced by the OBJ face, counted from 1;
   report_error prints "MESH.obj:LINE: ..." at that face's line (or
   "MESH.obj: ..." when the error names no face) and returns
   TOOL_EXIT_FAILURE. */
void triangle_mesh_rewrite_face(const triangle_mesh *m, const tt_error *error, char *message, size_t size);
int triangle_mesh_report_error(const char *path, const triangle_mesh *m, const tt_error *error);

/* The faces of a mesh made from an OBJ's (triangle fans, quads), traced
   back to them for constraints and error messages. */
typedef struct tool_face_source {
    const tt_mesh *mesh;
    int nfaces;                 /* the mesh's faces */
    int nsources;               /* the OBJ's faces */
    const int *source;          /* per mesh face: its OBJ face */
    const int *first;           /* per OBJ face: the first mesh face made from it */
    const int *source_line;     /* per OBJ face: its line in the file; NULL for faces made anew (--remesh) */
} tool_face_source;
tool_face_source triangle_mesh_faces(const triangle_mesh *m);

/* tt_tangent_field from --up and --constraints (tool_field): face_vectors
   gets 3 floats per triangle, `scale` (mesh units, 0 = the library's
   default) their length. A constraints file's line is "FACE X Y Z [SIGMA
   [WEIGHT]]", FACE counting the OBJ's faces from 1 ('#' comments). Returns
   0, or the exit status after printing the error, a constraint's at its
   line of the file. */
int tool_make_field(const char *mesh_path, const triangle_mesh *m, const tool_field *field, float scale,
                    float *face_vectors);
/* The same on any mesh whose faces trace back to the OBJ's (a constraint
   goes on the first face made from its OBJ face); face_vectors gets 3
   floats per face. */
int tool_make_face_field(const char *mesh_path, const tool_face_source *faces, const tool_field *field,
                         float scale, float *face_vectors);

/* ---------------------------------------------------------------------- */
/* Quality measures for the summaries (measure.c)                          */
/* ---------------------------------------------------------------------- */

/* The seam report the commands print: tt_measure_seams on at most this many
   edges drawn at random (the library's full measure, every edge, is the
   acceptance measure; 20000 edges stay within about 0.01 of it and keep the
   report fast on meshes of hundreds of thousands of faces). */
#define TOOL_REPORT_EDGES 20000

typedef struct tool_seams {
    int measured;               /* 0: TT_ERROR_NOT_MEASURED, `reason` says why */
    int sampled;                /* 1: fewer edges measured than `edges` */
    int edges;                  /* the edges the mode measures: every interior edge, with
                                   TT_SEAM_UV_DISCONTINUOUS the chart borders, or those listed */
    tt_seam_report report;
    char reason[224];           /* the library's sentence, without its full stop */
} tool_seams;

/* Measure the seams of per-corner UVs on `atlas` for a summary: flags are
   tt_seam_options.flags; edges (nedges of them, each named by a corner) the
   edges to measure, or NULL for every one the flags allow; a sample of
   TOOL_REPORT_EDGES edges, or with all_edges every one; ends as
   tt_seam_options.ends (0: whole edges; TOOL_CORNER_ENDS: near the
   corners where the tiles meet). Nothing measurable (a one-face mesh, say) is not an
   error: seams->measured is 0. Other library errors are printed as one line
   naming obj_path; returns the exit status. */
/* How near an edge's ends the corner seam score samples: within 5 % of
   the edge at either end, where three to six tiles meet. */
#define TOOL_CORNER_ENDS 0.05f
int tool_measure_seams(const char *obj_path, const tt_mesh *mesh, const float *corner_uv, const tt_image *atlas,
                       uint64_t seed, unsigned flags, const int *edges, int nedges, int all_edges, float ends,
                       tool_seams *seams);
/* The score as a summary says it, `edges` naming what was measured
   ("border edges"): "0.123 (456 of 789 border edges sampled)", "n/a: ..."
   when unrelated places differ no more than neighbours, or "not measured
   (reason)". */
void tool_format_seams(const tool_seams *seams, const char *edges, char *text, size_t size);

typedef struct tool_level {
    int measured;               /* 0: TT_ERROR_NOT_MEASURED (no wall face), `reason` says why */
    tt_uv_direction_report report;
    char reason[224];           /* the library's sentence, without its full stop */
} tool_level;

/* How level the image lies on the walls with up `up` (--up; 0,0,0 the
   library's default), for a summary's `level:` line. No wall face is not
   an error: level->measured is 0. Other library errors are printed as one
   line naming obj_path; returns the exit status. */
int tool_measure_level(const char *obj_path, const tt_mesh *mesh, const float *corner_uv, int width, int height,
                       const float up[3], tool_level *level);
/* The summary's line: "level: the image's up 95.1% of 812 wall faces
   within 10 degrees of --up, ...", or "level: not measured (reason)". */
void tool_print_level(const tool_level *level);

/* ---------------------------------------------------------------------- */
/* Numbers as text without printf (format_number.c)                        */
/* ---------------------------------------------------------------------- */

/* Room for any text below, with its NUL ("-1.23456789e-38"). */
#define TOOL_NUMBER_TEXT_SIZE 24

/* A float with 9 significant digits, the text printf("%.9g") gives (up to,
   rarely, the last digit), which reads back as exactly the same float; NaN
   and infinity go through snprintf. Writes a NUL-terminated string into out
   (TOOL_NUMBER_TEXT_SIZE bytes) and returns its length. Several times faster
   than printf. */
int tool_format_float(float value, char *out);
/* A decimal integer the same way. */
int tool_format_int(long value, char *out);
/* A number read as a double (strtod), as a float: the float nearest to it,
   as the conversion rounds, and infinity only where that rounding
   overflows (from FLT_MAX + half its step up). Converting a double beyond
   FLT_MAX is undefined in C, and calling all of them infinity would read
   the text printed for FLT_MAX (3.40282347e+38, a little above it) as
   infinity. NaN stays NaN. */
float tool_float_of(double value);

/* ---------------------------------------------------------------------- */
/* Time and progress on a terminal (tool_io.c)                              */
/* ---------------------------------------------------------------------- */

/* Seconds on a monotonic clock, for "took 1.2 s". */
double tool_seconds_now(void);
/* CPU seconds the process has used so far, all its threads together (user
   and system): a stage's CPU is the difference, whatever else runs on the
   machine. */
double tool_cpu_seconds_now(void);

/* The progress line. On a terminal (stderr), one line redrawn in place
   says what the command is doing, "tiledtex: reading horse.obj: 42.0%" or
   "tiledtex: building the polycube", from half a second after the command
   started (most runs end sooner) until it writes its summary: the line is
   erased before any other output (the summary, a note, an error). Nothing
   with -q or when stderr is not a terminal (a log would fill with "\r"
   lines). A fraction is shown below 100 % (a stage that is done gives way
   to the next one, it does not sit at 100 %), and redrawn at most ten
   times a second. main calls tool_progress_start when the command begins. */
void tool_progress_start(void);
/* A stage begins, named like printf ("writing %s", path); its fraction is
   unknown until tool_stage_fraction says. */
void tool_stage(const char *format, ...);
/* How far the current stage is, 0 to 1, with what the fraction counts
   (NULL, or "of the surface covered"). */
void tool_stage_fraction(double done, const char *what);
/* Erase the line, so that the next output starts on a clean line. */
void tool_progress_clear(void);

/* A long library call's progress callback, on the progress line: fill one
   with tool_progress_begin (which begins a stage named ACTIVITY), pass
   tool_show_progress as the options' tt_progress_fn and the state as its
   user data, and call tool_progress_end afterwards. */
typedef struct tool_progress {
    const char *activity, *what;    /* "pasting", "of the surface covered" */
} tool_progress;

void tool_progress_begin(tool_progress *progress, const char *activity, const char *what);
/* Also answers "cancel" once Ctrl-C or SIGTERM came (tool_catch_interrupts). */
int tool_show_progress(float fraction, void *user_data);
/* The library call returned: Ctrl-C kills the tool again. */
void tool_progress_end(tool_progress *progress);

/* Between tool_progress_begin and _end, SIGINT and SIGTERM cancel the
   library call through tool_show_progress instead of killing the tool;
   outside, they kill it as usual. main installs this once. */
void tool_catch_interrupts(void);
/* A signal came: the command was cancelled (exit status 130). */
int tool_interrupted(void);

/* ---------------------------------------------------------------------- */
/* Threads (executor.c)                                                     */
/* ---------------------------------------------------------------------- */

/* -j N / --jobs N (a global option main takes) runs the library's parallel
   work (tile synthesis, the seam measure, ...) on N threads: a pool of N - 1
   threads, started the first time work arrives and kept for every later
   run, with the calling thread taking part. The outputs are the same at
   every N. tool_executor() is the pool as the library's options take it,
   or NULL at -j 1 (serial, no thread started). */
#define TOOL_MAX_JOBS 256
void tool_set_jobs(int jobs);
/* -j as given, or the default: the cores this process may run on. */
int tool_jobs(void);
int tool_default_jobs(void);
const tt_executor *tool_executor(void);
/* The tool's own parallel loops, as the library runs its (the same rules:
   tasks write disjoint outputs, the split never depends on the executor):
   task(context, i) for i in [0, count) on `executor` (NULL: in order, here),
   and body(context, begin, end) over [0, n) cut into ranges of `grain`. */
void tool_run_tasks(const tt_executor *executor, int count, tt_task_fn task, void *context);
void tool_parallel_ranges(const tt_executor *executor, int n, int grain, void (*body)(void *context, int begin, int end),
                          void *context);

/* ---------------------------------------------------------------------- */
/* Paths and strings (tool_io.c)                                            */
/* ---------------------------------------------------------------------- */

/* A malloc'ed, NUL-terminated copy of `length` bytes of text; NULL when out
   of memory. */
char *tool_copy_string(const char *text, size_t length);

/* Whether `path` ends with `extension` (".gltf"), in any case. */
int tool_has_extension(const char *path, const char *extension);
/* The file name part of a path ("out/a.png" -> "a.png"), for mtllib / map_Kd
   lines that must be relative to the OBJ / MTL file. */
const char *tool_basename(const char *path);

/* `target` (a path from the current directory, or absolute) as seen from
   the directory of `from_file`: what an MTL beside from_file should write to
   name target, so that the folder can move ("out/a.mtl", "out/tex.png" ->
   "tex.png"; "out/a.mtl", "tex.png" -> "../tex.png"; "/tmp/out/a.mtl",
   "/tmp/out/tex.png" -> "tex.png"). Absolute paths that share nothing but
   the root give target's absolute path: climbing to the root breaks as
   soon as the folder moves, where the absolute path still names the file.
   When one path is absolute and the other is not, or from_file's directory
   climbs with ".." ("../out/a.mtl"), the text alone cannot say the way, so
   both are resolved on the file system (their directories must exist);
   failing that, target's absolute path is used, or target as given. */
void tool_relative_path(const char *target, const char *from_file, char *out, size_t out_size);
/* The other way: `name`, as a file beside from_file names it (relative to
   from_file's directory, or absolute), as a path from the current
   directory ("out/a.obj", "a.mtl" -> "out/a.mtl"). */
void tool_path_beside(const char *name, const char *from_file, char *out, size_t out_size);

#endif /* TILEDTEX_TOOL_H */
