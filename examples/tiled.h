/* tiled.h - the tiled-texture steps shared by `tiledtex synth`, `map` and
   `tile`, implemented in tiled.c:

   tiled_map_mesh    turns an OBJ into a quad mesh with tiled-texture UVs (map)
   tiled_synthesize  turns a photo into an atlas of (2n)^4 tiles      (synth)
   tile.c does both in one go. The options they share are parsed in one place
   (tiled_parse_option).
*/
#ifndef TILEDTEX_TILED_H
#define TILEDTEX_TILED_H

#include "tool.h"

/* Which options a command accepts (tiled_parse_option's `accept`). */
enum {
    TILED_LAYOUT_OPTIONS = 1 << 0,   /* --colors --tile --gutter --seed */
    TILED_MESH_OPTIONS = 1 << 1,     /* --subdivide --smooth --permissive */
    TILED_SYNTH_OPTIONS = 1 << 2,    /* --edge --background --mips */
    TILED_ATLAS_OPTION = 1 << 3,     /* --atlas */
    TILED_REPORT_OPTION = 1 << 4,    /* --report: quality line, seams measured on every edge */
    TILED_MATERIAL_OPTIONS = 1 << 5, /* --normal --roughness --metallic --ao --height --normal-y-down */
    TILED_TRIANGLES_OPTION = 1 << 6, /* --triangles */
    TILED_FORMAT_OPTION = 1 << 7,    /* --format obj|gltf */
    TILED_FIELD_OPTIONS = 1 << 8     /* --up --constraints --no-courses --remesh: tiles turned along the direction
                                        field, and quads made to follow it */
};

/* From this many triangles on, a mesh counts as a dense triangle mesh, for
   which tiled textures are the wrong tool (tiled_print_notes says so). */
#define TILED_DENSE_TRIANGLES 1000

typedef struct tiled_options {
    tt_tile_layout layout;       /* zeros = the library's defaults */
    int tile_size_given;
    uint64_t seed;
    tool_mesh_options mesh;      /* --subdivide (extra quadrangulation steps), --smooth, --permissive */
    int nedges;                  /* --edge X,Y given this many times */
    tt_rect edges[TT_MAX_COLORS];
    tt_rect background;          /* all zero = whole image */
    int mips;                    /* also write the per-tile mip levels */
    const char *atlas_path;      /* --atlas */
    int report;                  /* --report: tile usage and stretch under the summary */
    tool_mesh_output output;     /* --format, --triangles */
    const tt_rect *upright_over; /* not NULL: upright tiles (tt_synth_options::upright) on these edge windows */
    int plain_sides;             /* with upright_over: tt_synth_options::plain_sides */
    int levels;                  /* tt_synth_options::levels: 1 when only level 0 is used */
    tool_field field;            /* --up, --constraints: each quad's tile turned along the field */
    int upright;                 /* with the field: faces may take upright tiles (the image feeds them) */
    material_maps maps;          /* the material's other maps (their paths; material_load loads them) */
    int no_courses;              /* --no-courses: upright tiles ignore the photo's courses */
    tt_courses courses;          /* tiled_fit_courses's: the windows stay on them (period 0: none) */
    int remesh;                  /* --remesh: a new quad mesh along the field first (tt_remesh_quads) */
    double remesh_size;          /* its quads' side in mesh units; 0 = auto (tt_remesh_quads' default) */
} tiled_options;

/* The tool's defaults: the library's, with a gutter of TT_RECOMMENDED_GUTTER
   so that mip-mapped rendering stays seamless. */
void tiled_default_options(tiled_options *options);

/* If argv[*index] is one of the accepted options, consume it (and its value)
   and return 1; return 0 for anything else; on a bad value print one line
   and return -1. */
int tiled_parse_option(int argc, char **argv, int *index, unsigned accept, tiled_options *options);

/* The whole command line of synth, map or tile: the tool's defaults, then
   --help (prints `help` and asks to exit 0), the accepted options, and
   exactly `count` positional arguments described by `names` ("MESH.obj and
   OUT.obj"). Returns -1 to go on, or the exit status to return now. */
int tiled_parse_command_line(int argc, char **argv, unsigned accept, tiled_options *options,
                             const char **positional, int count, const char *names, void (*help)(void));

/* IMAGE's courses (tt_find_courses) into *courses, period 0 when it has
   none or options->no_courses is set. Returns 0 or the exit status. */
int tiled_find_courses(const tt_image *image, const char *image_path, const tiled_options *options,
                       tt_courses *courses);

/* Before upright tiles are synthesised from *image (tile size chosen): a
   photo with courses (tt_find_courses: bricks, blocks laid in rows) is
   resampled, with its maps, so that a tile holds a whole number of them,
   and options->courses keeps every window on them; a note says so. Nothing
   changes for a photo without courses, with --no-courses, or when the
   resampled photo would be too small for the tiles. found: the courses
   tiled_find_courses already found in *image, or NULL to find them here.
   *image is replaced (the old one freed) when resampled. Returns 0 or the
   exit status. */
int tiled_fit_courses(tt_image **image, const char *image_path, tiled_options *options, const tt_courses *found);

/* A quad mesh with its tiled-texture UVs, ready to write. */
typedef struct tiled_mesh {
    tt_mesh *mesh;
    uint8_t *corner_type;        /* ncorners boundary types */
    float *corner_uv;            /* 2 * ncorners */
    float *corner_normal;        /* 3 * ncorners: the OBJ's normals carried through quadrangulation, or
                                    NULL (obj_corner_normals): the OBJ gets computed ones */
    tt_tile_layout layout;       /* resolved */
    tt_mesh_stats stats;
    int input_faces;             /* faces in the OBJ */
    int quadrangulated;          /* quads made from the OBJ's triangles or n-gons; 0 if all quads */
    int input_min_face_size, input_max_face_size;
    int repaired_edges;          /* edges --permissive cut open */
    int remeshed;                /* --remesh: the quads tt_remesh_quads made */
    tt_remesh_report remesh;     /* ...and its report (the quads' side: remesh.edge_length) */
    tt_mesh_stats input_stats;   /* --remesh: the OBJ's topology, to say where the new mesh differs */
    /* With --up or --constraints (else NULL and 0): */
    uint8_t *face_turn;          /* per quad: the half-edge its tile's bottom side lies on (tt_orient_tiles) */
    uint8_t *face_upright;       /* per quad: its tile set (tt_tileset_kind), the atlas's quarter; NULL without */
    int upright_faces;           /* quads with upright tiles on all four sides */
} tiled_mesh;

/* Read an OBJ, build and validate it, quadrangulate when it is not all quads
   (said on stderr), subdivide (the file's normals carried along when every
   corner has one), assign boundaries and UVs; with options->field given,
   each quad's tile turned along the direction field, and with
   options->upright the UVs of a plain | upright atlas (tt_assign_uvs_oriented). Prints the error and returns
   an exit status on failure, 0 on success. */
int tiled_map_mesh(const char *obj_path, const tiled_options *options, tiled_mesh *out);
void tiled_mesh_free(tiled_mesh *mesh);

/* Add OBJ_PATH (positions, then each distinct vt and vn once, the corners
   sharing them (obj_write_desc::share_equal), using MATERIAL from MTL_NAME
   when mtl_name is not NULL; with `triangles` each quad as two triangles)
   to the output batch. */
int tiled_add_obj(tool_output *output, const char *obj_path, const tiled_mesh *mesh, const char *mtl_name,
                  int triangles);
/* Add GLB_PATH: the same mesh with `material` (its base colour the atlas). */
int tiled_add_gltf(tool_output *output, const char *gltf_path, const tiled_mesh *mesh, const tool_material *material);
/* Add an MTL file with one material, "tiled", whose texture is TEXTURE_NAME
   and whose other maps are map_names (as mtl_add_material's maps). */
int tiled_add_mtl(tool_output *output, const char *mtl_path, const char *texture_name, const char *const *map_names);

/* The tile size `tile` picks when none is given: TT_DEFAULT_TILE_SIZE, or for
   a small image a multiple of 8 up to 2/5 of its smaller side, or less so the
   atlas of `colors` fits TOOL_MAX_ATLAS; 4 for a tiny image; 0 when even a
   4 x 8 edge window does not fit. */
int tiled_fit_tile_size(int width, int height, int colors, int gutter);

/* Without --tile, set the layout's tile size to tiled_fit_tile_size's for
   a width x height image, with a note (tool_note) when it is below
   TT_DEFAULT_TILE_SIZE. Prints the error and returns an exit status when
   the image is too small for any tile, 0 otherwise. */
int tiled_pick_tile_size(const char *image_path, int width, int height, tiled_options *options);

/* Synthesise the atlas from an image already loaded, and with `maps` (may
   be NULL) the atlas of each map loaded there into map_tiles[map] (NULL for
   the others), all with the one plan the colour image decides. Prints the
   error and returns an exit status on failure (nothing stays allocated). */
int tiled_synthesize(const tt_image *image, const char *image_path, const tiled_options *options,
                     const material_maps *maps, tt_tileset **out, tt_tileset **map_tiles);
/* Free what tiled_synthesize made (map_tiles may be NULL) and set it NULL. */
void tiled_tilesets_free(tt_tileset **tiles, tt_tileset **map_tiles);

/* The upright tile sets, TT_TILESET_UPRIGHT and the two after it. */
#define TILED_UPRIGHT_SETS (TT_TILESET_KINDS - TT_TILESET_UPRIGHT)
/* The upright sets on the plain tiles' edge windows, upright[k] of
   tt_tileset_kind TT_TILESET_UPRIGHT + k (tt_synth_options::plain_sides 0,
   then the right side, then the left side plain), each with its maps'
   (map_upright[k], as tiled_synthesize's map_tiles). Prints the error and
   returns an exit status on failure (what was made stays, for
   tiled_upright_free). */
int tiled_synthesize_upright(const tt_image *image, const char *image_path, const tiled_options *options,
                             const tt_tileset *plain, tt_tileset *upright[TILED_UPRIGHT_SETS],
                             tt_tileset *map_upright[TILED_UPRIGHT_SETS][MATERIAL_MAPS]);
/* Free what tiled_synthesize_upright made. */
void tiled_upright_free(tt_tileset *upright[TILED_UPRIGHT_SETS],
                        tt_tileset *map_upright[TILED_UPRIGHT_SETS][MATERIAL_MAPS]);
/* sets[k] = the set of tt_tileset_kind k: plain, then upright[0..2]. */
void tiled_tileset_kinds(const tt_tileset *plain, tt_tileset *const upright[TILED_UPRIGHT_SETS],
                         const tt_tileset *sets[TT_TILESET_KINDS]);
/* Add the atlas (and with --mips its levels as PREFIX_mipL.png) to the
   batch, encoded into `space` (TT_COLOR_SRGB for colour, material_space's
   for a map). */
int tiled_add_atlas(tool_output *output, const char *png_path, const tt_tileset *tiles, int mips,
                    tt_color_space space);

/* Check a layout against the tool's atlas limit; prints the error. */
int tiled_check_atlas_size(const tiled_options *options);

/* The notes a successful map or tile gives on stderr (quadrangulated, edges
   cut open): said only on success, so a failing command prints one line. */
void tiled_print_notes(const char *obj_path, const tiled_mesh *mesh);

/* The one-line summary map and tile print; seams may be NULL. With `report`
   a second line gives tile usage and face stretch. */
void tiled_print_summary(const char *obj_path, const tiled_mesh *mesh, const tool_seams *seams,
                         const tool_seams *corners, int report);

#endif /* TILEDTEX_TILED_H */
