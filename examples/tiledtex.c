/* tiledtex.c - the `tiledtex` command-line tool: main() and the list of
   subcommands. Each subcommand lives in its own file (synth.c, map.c, tile.c,
   lapped.c, hpm.c, polycube.c, render.c, generate.c) as `int cmd_NAME(int argc, char **argv)`.

   This is the one translation unit that compiles the library itself: */
#define TILEDTEX_IMPLEMENTATION
#include "tiledtex.h"

#include <stdio.h>
#include <string.h>
#if defined(__GLIBC__)
#include <malloc.h>
#endif

#include "tool.h"

typedef struct subcommand {
    const char *name;
    int (*run)(int argc, char **argv);
    const char *summary;
} subcommand;

static const subcommand subcommands[] = {
    {"tile", cmd_tile, "texture a mesh with Akleman et al.'s tiled textures: OBJ + MTL + atlas PNG"},
    {"lapped", cmd_lapped, "texture a mesh with Praun et al.'s lapped textures: overlapping pastes of one patch"},
    {"hpm", cmd_hpm, "texture a mesh with Soler et al.'s hierarchical pattern mapping: UVs into the image itself"},
    {"polycube", cmd_polycube, "texture any mesh with Chang and Lin's polycube map and Wang tiles: OBJ + MTL + atlas"},
    {"synth", cmd_synth, "synthesise a tile set (the atlas) from an example image"},
    {"map", cmd_map, "give a mesh tiled-texture UVs for a given tile layout"},
    {"render", cmd_render, "draw a textured OBJ to a PNG with the built-in software renderer"},
    {"generate", cmd_generate, "make a procedural example texture or test mesh"},
};
#define SUBCOMMAND_COUNT ((int)(sizeof subcommands / sizeof subcommands[0]))

static const subcommand *find_subcommand(const char *name)
{
    int i;
    for (i = 0; i < SUBCOMMAND_COUNT; i++)
        if (strcmp(subcommands[i].name, name) == 0) return &subcommands[i];
    return NULL;
}

static void print_help(void)
{
    int i;
    printf("tiledtex %s - texture any mesh from one example image, without seams or visible repetition\n\n",
           TILEDTEX_VERSION_STRING);
    printf("usage: tiledtex [-j N] [--max-pixels N] [--quiet] [--weld] COMMAND [ARGUMENTS]\n"
           "       tiledtex --version\n\ncommands:\n");
    for (i = 0; i < SUBCOMMAND_COUNT; i++) printf("  %-9s %s\n", subcommands[i].name, subcommands[i].summary);
    printf("\nglobal options (before or after the command):\n"
           "  --max-pixels N  refuse images of more than N pixels, checked before decoding them\n"
           "                  (default %d = 4096x4096; render: 8192x8192, the largest\n"
           "                  texture the tool writes). Peak memory per input pixel:\n"
           "                  lapped needs about 32 bytes, render 21, tile and synth 17\n"
           "  -j, --jobs N    run on N threads (default: the %d cores this process may use);\n"
           "                  -j 1 runs on this thread only. Outputs are the same at any N\n"
           "  -q, --quiet     print nothing but errors: no summary, progress line or warning\n"
           "  -V, --version   print the version and exit\n"
           "  --weld          merge mesh vertices closer than %g of the bounding box diagonal,\n"
           "                  for meshes exported with each face's own vertices\n"
           "\nOUT_PREFIX may end in .obj (or .mtl, .png, .gltf), which is taken off; one ending\n"
           "in .glb, or --format glb, makes tile, lapped, hpm and polycube write one binary glTF\n"
           "file instead of OBJ, MTL and PNGs. An output of exactly one file (render, generate,\n"
           "synth, map without --atlas, a GLB) may be '-' for the standard output.\n"
           "\nmeshes: Wavefront OBJ, STL (ASCII or binary, always welded) or OFF; other\n"
           "formats are named, with a conversion command (assimp export from assimp-utils)\n",
           TOOL_DEFAULT_MAX_PIXELS, tool_default_jobs(), TOOL_WELD_TOLERANCE);
    printf("\n'tiledtex help COMMAND' or 'tiledtex COMMAND --help' describes one command.\n"
           "Try it: tiledtex generate mesh torus.obj --shape torus\n"
           "        tiledtex generate texture stones.png\n"
           "        tiledtex tile torus.obj stones.png torus_tiled\n"
           "        tiledtex render torus_tiled.obj torus_tiled.png view.png\n"
           "        tiledtex lapped torus.obj stones.png torus_lapped\n"
           "        tiledtex render torus_lapped.obj torus_lapped_patch.png lapped.png\n"
           "        tiledtex hpm torus.obj stones.png torus_hpm\n"
           "        tiledtex render torus_hpm.obj stones.png hpm.png\n"
           "        tiledtex polycube torus.obj stones.png torus_pc\n"
           "        tiledtex render torus_pc.obj torus_pc.png polycube.png\n");
}

/* The global options, accepted before or after the command name (the error
   message about a large image suggests adding one to the same command line):
   take them out of argv before the command sees it. Returns 0, or the exit
   status for a bad value. */
static int take_global_options(int *argc, char **argv)
{
    const char *max_pixels = NULL, *jobs = NULL, *jobs_option = NULL;
    int i, kept = 1, given = 0;
    for (i = 1; i < *argc; i++) {
        const char *value;
        if (tool_option(*argc, argv, &i, "--max-pixels", &value)) {
            max_pixels = value;
            given = 1;
        } else if (tool_option(*argc, argv, &i, "--jobs", &value)) {
            jobs_option = "--jobs";
            jobs = value;
        } else if (tool_option(*argc, argv, &i, "-j", &value)) {
            jobs_option = "-j";
            jobs = value;
        } else if (strncmp(argv[i], "-j", 2) == 0 && argv[i][2] != '\0') {
            jobs_option = "-j";                 /* -j4, as make takes it */
            jobs = argv[i] + 2;
        } else if (tool_flag(argv[i], "--quiet") || strcmp(argv[i], "-q") == 0) {
            tool_set_quiet(1);
        } else if (tool_flag(argv[i], "--weld")) {
            mesh_set_weld(1);
        } else {
            argv[kept++] = argv[i];
        }
    }
    *argc = kept;
    argv[kept] = NULL;
    if (given) {
        uint64_t n;
        if (parse_u64("--max-pixels", max_pixels, &n) != 0) return TOOL_EXIT_USAGE;
        if (n == 0) return tool_usage("--max-pixels wants a number of pixels above 0, got '%s'", max_pixels);
        image_set_max_pixels(n);
    }
    if (jobs_option) {
        int n;
        if (parse_int(jobs_option, jobs, 1, TOOL_MAX_JOBS, &n) != 0) return TOOL_EXIT_USAGE;
        tool_set_jobs(n);
    }
    return 0;
}

int main(int argc, char **argv)
{
    const subcommand *command;
    int status;
#if defined(__GLIBC__)
    /* A command allocates and frees arrays of tens of megabytes stage after
       stage. By default glibc gives each back to the kernel when it is
       freed, and the next stage faults every page of its own in again: a
       third of the page faults of a 100k-face job and a tenth of its time.
       Kept in the heap, freed memory is reused, for a peak a few percent
       higher. */
    mallopt(M_MMAP_THRESHOLD, 1 << 30);
    mallopt(M_TRIM_THRESHOLD, 1 << 30);
#endif
    if ((status = take_global_options(&argc, argv)) != 0) return status;
    if (argc < 2)
        return tool_usage("needs a command: tile, lapped, hpm, polycube, synth, map, render or generate (see 'tiledtex --help')");
    if (tool_is_help(argv[1])) {
        print_help();
        return 0;
    }
    if (strcmp(argv[1], "--version") == 0 || strcmp(argv[1], "-V") == 0 || strcmp(argv[1], "version") == 0) {
        printf("tiledtex %s\n", TILEDTEX_VERSION_STRING);
        return 0;
    }
    if (strcmp(argv[1], "help") == 0) {
        /* "tiledtex help render" is "tiledtex render --help". */
        char help_flag[] = "--help";
        char *help_argv[3];
        if (argc < 3) {
            print_help();
            return 0;
        }
        command = find_subcommand(argv[2]);
        /* A bad command line like any other: the usage status. */
        if (!command) return tool_usage("no command called '%s' (try 'tiledtex --help')", argv[2]);
        help_argv[0] = argv[2];
        help_argv[1] = help_flag;
        help_argv[2] = NULL;
        tool_set_command(command->name);
        return command->run(2, help_argv);
    }
    command = find_subcommand(argv[1]);
    if (!command) {
        if (tool_is_option(argv[1])) return tool_usage("unknown option '%s' (try 'tiledtex --help')", argv[1]);
        return tool_usage("unknown command '%s' (try 'tiledtex --help')", argv[1]);
    }
    tool_set_command(command->name);
    tool_catch_interrupts();
    tool_progress_start();
    status = command->run(argc - 1, argv + 1);
    tool_progress_clear();
    if (status != 0 && tool_interrupted()) status = 130;   /* as a shell reports a command ended by Ctrl-C */
    if (status == 0) tool_print_notes();
    tool_forget_inputs();
    return status;
}
