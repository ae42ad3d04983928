/* tiledtex.h - v0.2.0 - texture any mesh from one example image, with no seams,
   no singularities and no visible repetition.   MIT license: see end of file.

   Do this in *one* C or C++ file before including this file:

       #define TILEDTEX_IMPLEMENTATION
       #include "tiledtex.h"

   Other files just #include "tiledtex.h". Define TILEDTEX_STATIC as well to make
   every function static to that one file.

   Optional overrides (define before the implementation):
       TT_MALLOC(size, user_data)   default: the C library's malloc  } both
       TT_FREE(ptr, user_data)      default: the C library's free    } or neither
       TT_ASSERT(condition)         default: assert() from <assert.h>, so it is
                                    off under NDEBUG; checks the preconditions
                                    of the helpers that return no tt_result

   THE API CONTRACT (true of every public function)
     - Errors. A function that can fail returns tt_result (TT_OK == 0, errors
       negative, tt_result_string() gives a sentence) and takes, as its last
       parameter, an optional `tt_error *error` (NULL: no details). On failure
       the error names the place it refers to (face, corner, vertex, matrix row
       and column or texel, input item) and holds one sentence. Bad input of any
       kind - NULL, out of range, NaN, infinity, sizes that overflow - gets a
       specific result, never a crash and never TT_OK with a wrong answer.
     - Helpers that cannot fail (tt_mesh_next, tt_face_normal, tt_tile_index,
       tt_image_sample_bilinear, ...) return their answer directly; each states
       its preconditions, and TT_ASSERT checks them.
     - Memory. A function that allocates takes `const tt_allocator *allocator`
       as the parameter before its outputs: NULL means TT_MALLOC / TT_FREE. An
       allocator sets both of its functions, alloc and free: one without the
       other is TT_ERROR_INVALID_ARGUMENT. Every allocation, temporary or returned, goes
       through it and is freed on every error path. An object it returns
       remembers its allocator.
     - Ownership. Where the size of an output is known up front (per-corner UVs,
       per-face vectors, a bake target) you pass the buffer; its size is stated
       (a count such as mesh->ncorners, or a *_bound function). Where the
       library must allocate, it returns one object through `T **out`, NULL on
       failure, released by its one tt_T_free (NULL is fine to free).
     - Options structs zero-initialised mean defaults; each default is written
       next to its field. Long operations take a progress callback that can
       cancel (TT_CANCELLED).
     - No global or static mutable state: every function is reentrant and safe
       to call from several threads on distinct outputs.
     - The library never touches files.

   QUICK START: tile a quad mesh from a photo (Akleman et al.'s tiled textures)

       tt_mesh_desc desc = {0};                                 // your arrays:
       desc.positions = xyz; desc.nverts = nverts;              //   float xyz[3 * nverts]
       desc.indices = quads; desc.nfaces = nquads;              //   int quads[4 * nquads]
       desc.fixed_face_size = 4;
       tt_mesh *mesh; tt_image *photo; tt_tileset *tiles; tt_error err;
       if (tt_mesh_build(&desc, NULL, &mesh, &err) != TT_OK) { puts(err.message); return 1; }
       // 8-bit pixels from your image loader (stbi_load, say), sRGB-encoded:
       tt_image_from_bytes(bytes, w, h, channels, 0, TT_COLOR_SRGB, NULL, &photo, &err);
       tt_tile_layout layout = {1, 128, TT_RECOMMENDED_GUTTER};  // n, tile size, gutter
       tt_assign_boundaries(mesh, &layout, 42, NULL, types, &err); // uint8_t types[4 * nquads]
       tt_assign_uvs(mesh, &layout, types, uv, &err);            // float uv[8 * nquads]: 2 per corner
       tt_synth_options opt = {0};  opt.layout = layout;
       if (tt_synthesize_tiles(photo, &opt, NULL, &tiles, &err) != TT_OK) { puts(err.message); return 1; }
       tt_image_to_rgba8(&tiles->levels[0], TT_COLOR_SRGB, rgba); // the atlas, W * W * 4 bytes
       tt_tileset_free(tiles); tt_image_free(photo); tt_mesh_free(mesh);

   QUICK START: lapped textures on a triangle mesh (Praun et al.)

       tt_tangent_field(mesh, NULL, NULL, field, &err);         // float field[3 * ntris]: up = +Y,
                                                                //   length 0.1 * bbox diagonal
       tt_image *patch; tt_lapped *pastes;
       tt_make_texture_patch(photo, NULL, NULL, NULL, &patch, &err);
       tt_lapped_paste(mesh, field, &patch, 1, NULL, NULL, &pastes, &err);
       // draw pastes->pastes[p] in order, alpha-blended: faces pastes->faces[first..],
       // corner UVs pastes->uv[6 * entry ..] into the patch; or bake them:
       tt_atlas_pack_pairs(mesh, 2048, 2, corner_uv, &err);      // float corner_uv[6 * ntris]
       tt_lapped_bake(mesh, pastes, &patch, 1, corner_uv, NULL, NULL, atlas, &err);
       tt_lapped_free(pastes); tt_image_free(patch);             // atlas: your 2048 x 2048 tt_image

   Triangles or n-gons? tt_mesh_quadrangulate() turns every n-gon into n quads first
   (the per-corner outputs then line up with the quadrangulated mesh's corners:
   mesh->corner_vert is its index buffer).

   CONVENTIONS
     - Half-edges are corners: the half-edges of face f are stored contiguously in
       the order of your index buffer, so half-edge id == corner id == position in
       your `indices` array. Every per-corner output (boundary types, UVs) lines up
       with your own index buffer: no remapping.
     - Half-edge c runs from corner c to the next corner of the same face. Faces are
       counter-clockwise seen from outside.
     - UV origin is the bottom-left of the image (OBJ / OpenGL). Images are stored
       with row 0 at the top (as image files are), so v = 1 - y / height.
     - tt_image holds linear-light RGBA floats, nominally in [0, 1]: blending,
       feathering, filtering and mip averaging are done in linear light. Colour
       photos arrive sRGB-encoded: convert them with tt_image_from_bytes(...,
       TT_COLOR_SRGB, ...) and back with tt_image_to_rgba8. Data maps (normals,
       roughness, height) are TT_COLOR_LINEAR and never converted.

   SECTIONS (each uses only the ones above it; read top to bottom)
     1. Common  - results and errors, allocator hooks, asserts, seeded RNG,
                  version, and the small tools every section shares
     2. Mesh    - half-edge builder with validation, queries, quadrangulation,
                  face normals, corner normals with creases
     3. Image   - float RGBA images, colour spaces, bilinear sampling, 90-degree
                  rotations, premultiplied `over`, box downsampling,
                  minimum-error cut
     4. Numerics - triplets to CSR sparse matrices, Jacobi-preconditioned
                  conjugate gradients (symmetric positive definite systems),
                  radix-2 FFTs (1D, 2D, real input), masked cross-correlation
     5. Raster  - 2D triangle rasterisation with barycentrics
     6. Tiled textures (Akleman, Chen, Meenakshisundaram, Srinivasan, "Tiled
                  Textures: A Simple and Practical Technique for Seamless Texturing")
                - boundary assignment (random or prescribed), UV formula,
                  tile-set synthesis as a plan applied to one or more images,
                  quality report
     7. Lapped textures (Praun, Finkelstein, Hoppe, "Lapped Textures")
                - tangent field: texture up and scale per face (Sec. 3.2)
                - texture patches with soft splotch masks (Sec. 3.1)
                - the paste loop: surface patches grown over the mesh, aligned
                  with the field by least squares, until covered (Sec. 3.3-3.6)
                - runtime pasting lists, alignment measure, atlases (triangle
                  pairs or charts), a UV check, and baking (Sec. 4)
     8. Hierarchical pattern mapping (Soler, Cani, Angelidis, "Hierarchical
                  Pattern Mapping")
                - the face-cluster hierarchy: components down to single faces,
                  discs checked, control vertices (Sec. 2.1, 3.1)
                - flattening of a cluster over its control polygon: a harmonic
                  map, its flattening error and fold check (Sec. 3.2)
                - the pipeline, tt_hpm_map: coarse to fine, each cluster placed
                  where the image best continues its textured neighbours (a
                  masked FFT correlation over turned copies), its borders
                  relaxed; per-corner UVs into the original image (Sec. 2.2, 4)
     9. Polycube + Wang tiles (Chang, Lin, "Texture Tiling on 3D Models
                  Using Automatic Polycube-maps and Wang Tiles")
                - the automatic polycube: voxelisation, interior fill,
                  manifold repair, the correction step, the quad surface S
                  with tile orientation from an up direction (Sec. 3.1)
                - the Wang colouring of S's edges per axis group, for the
                  tiled-textures boundary assignment (Sec. 3.2)
                - the mapping, tt_polycube_map: the model refined, each
                  vertex projected to a point of S on the side its normal
                  faces, the points relaxed, each edge traced on S as a path
                  of quads (exact unfoldings), each triangle split along S's
                  quad edges into pieces inside one quad; the UVs from the
                  tiles (Sec. 4)
*/
#ifndef TILEDTEX_H
#define TILEDTEX_H

#define TILEDTEX_VERSION_MAJOR 0
#define TILEDTEX_VERSION_MINOR 2
#define TILEDTEX_VERSION_PATCH 0
#define TILEDTEX_VERSION_STRING "0.2.0"

#include <stddef.h>
#include <stdint.h>

#ifndef TTDEF
#ifdef TILEDTEX_STATIC
#if defined(__GNUC__) || defined(__clang__)
#define TTDEF static __attribute__((unused))   /* a file may use only some functions */
#else
#define TTDEF static
#endif
#else
#define TTDEF extern
#endif
#endif

#ifdef __cplusplus
extern "C" {
#endif

/* ======================================================================== */
/* 1. Common                                                                */
/* ======================================================================== */

typedef enum tt_result {
    TT_OK = 0,
    TT_CANCELLED = -1,                      /* a progress callback asked to stop */
    TT_ERROR_INVALID_ARGUMENT = -2,         /* NULL pointer, count or option out of range */
    TT_ERROR_OUT_OF_MEMORY = -3,
    TT_ERROR_TOO_LARGE = -4,                /* a size would overflow or exceed a documented limit */
    TT_ERROR_EMPTY_MESH = -5,               /* no faces */
    TT_ERROR_INDEX_OUT_OF_RANGE = -6,       /* an index names something that does not exist */
    TT_ERROR_FACE_TOO_SMALL = -7,           /* a face with fewer than 3 corners */
    TT_ERROR_REPEATED_VERTEX = -8,          /* a face uses one vertex twice */
    TT_ERROR_NON_FINITE = -9,               /* a NaN or infinite input value, or an overflow */
    TT_ERROR_ZERO_AREA_FACE = -10,          /* a face whose corners are collinear or coincide */
    TT_ERROR_NON_MANIFOLD_EDGE = -11,       /* an edge shared by more than two faces */
    TT_ERROR_INCONSISTENT_ORIENTATION = -12,/* two faces use an edge in the same direction */
    TT_ERROR_NON_MANIFOLD_VERTEX = -13,     /* the faces around a vertex form more than one fan */
    TT_ERROR_NOT_QUAD_MESH = -14,           /* this step needs quads; quadrangulate first */
    TT_ERROR_IMAGE_TOO_SMALL = -15,         /* the image cannot hold the requested windows */
    TT_ERROR_NOT_CONVERGED = -16,           /* an iterative method hit its limit first */
    TT_ERROR_NOT_POSITIVE_DEFINITE = -17,   /* a matrix that must be positive definite is not */
    TT_ERROR_NOT_MEASURED = -18,            /* a measure found nothing it could measure */
    TT_ERROR_NOT_FLAT = -19,                /* a surface piece does not flatten within the allowed distortion */
    TT_RESULT_MAX_ENUM = 0x7fffffff
} tt_result;

/* A sentence describing a result code (static storage, never NULL). It fits
   every function that returns the code; tt_error::message says more. */
TTDEF const char *tt_result_string(tt_result result);

/* Where an error happened. Fields that do not apply are -1. `message` is one
   complete sentence such as "face 12 (corners 48..51) uses vertex 1033, but
   the mesh has 1000 vertices"; numbers in it are printed compactly. */
typedef struct tt_error {
    tt_result result;
    int face;
    int corner;
    int vertex;
    int other_vertex;   /* the second end of an edge, for edge errors */
    int other_face;     /* a second face on that edge, for edge errors */
    int row, column;    /* a matrix entry, a row of a linear system, or an image texel (row y, column x) */
    int item;           /* the offending element of an input array that is not a face, corner or
                           vertex: a triplet, a constraint, a paste entry, a texture patch */
    char message[224];
} tt_error;

/* Allocation hooks (see THE API CONTRACT): both alloc and free, or pass NULL
   for TT_MALLOC / TT_FREE. `alloc` returns memory suitably aligned for any
   type, or NULL. */
typedef struct tt_allocator {
    void *(*alloc)(size_t size, void *user_data);
    void (*free)(void *ptr, void *user_data);
    void *user_data;
} tt_allocator;

/* Progress callback for long operations: `fraction` runs from 0 to 1 and
   never decreases. Return non-zero to cancel; the operation then cleans up
   and returns TT_CANCELLED. */
typedef int (*tt_progress_fn)(float fraction, void *user_data);

/* The library's version at run time, which may differ from the
   TILEDTEX_VERSION_* macros your code was compiled with when the
   implementation lives in another file: the string, and the numbers through
   the pointers that are not NULL. */
TTDEF const char *tt_version(int *major, int *minor, int *patch);

/* Seeded random numbers (PCG32). Integer arithmetic only, so the same seed gives
   the same sequence on every machine and compiler. Not for cryptography. */
typedef struct tt_rng {
    uint64_t state;
    uint64_t increment;
} tt_rng;

/* Start a sequence. Different `stream` values give independent sequences for
   the same seed. Then draw from it.
   Preconditions (TT_ASSERT): rng is not NULL. */
TTDEF void tt_rng_seed(tt_rng *rng, uint64_t seed, uint64_t stream);
TTDEF uint32_t tt_rng_next(tt_rng *rng);                    /* uniform 32 bits */
TTDEF uint32_t tt_rng_below(tt_rng *rng, uint32_t bound);   /* uniform in [0, bound); 0 if bound==0 */
TTDEF float tt_rng_float(tt_rng *rng);                      /* uniform in [0, 1), 24-bit grid */

/* ======================================================================== */
/* 2. Mesh                                                                  */
/* ======================================================================== */

enum {
    /* Accept real-world assets: edges shared by more than two faces, edges two
       faces use in the same direction, and degenerate edges (a face repeating a
       vertex) become boundary edges instead of errors; non-manifold vertices and
       zero-area faces are accepted. tt_mesh::repaired_edges counts the edges cut. */
    TT_MESH_PERMISSIVE = 1u << 0,
    /* Do not copy positions: the mesh points at desc->positions, which must
       outlive the mesh and not change while it is in use. */
    TT_MESH_BORROW_POSITIONS = 1u << 1
};

typedef struct tt_mesh_desc {
    const float *positions;     /* 3 * nverts floats: x, y, z */
    int nverts;
    const int *indices;         /* corner vertex indices, 0-based, faces one after another */
    const int *face_sizes;      /* nfaces corner counts, or NULL: every face has fixed_face_size */
    int nfaces;
    int fixed_face_size;        /* used when face_sizes is NULL; 0 means 3 */
    unsigned flags;             /* TT_MESH_* */
} tt_mesh_desc;

/* A polygon mesh as half-edges. Read the arrays freely; do not modify them.
   Corner c of face f is in [face_start[f], face_start[f+1]); the next corner of
   the same face is implicit (wrapping), so half-edge c runs from corner_vert[c]
   to corner_vert[next]. */
typedef struct tt_mesh {
    int nverts, nfaces, ncorners;
    const float *pos;           /* 3 * nverts; owned unless TT_MESH_BORROW_POSITIONS */
    int *face_start;            /* nfaces + 1 */
    int *corner_vert;           /* ncorners: vertex at corner c = origin of half-edge c */
    int *corner_face;           /* ncorners: face of corner c */
    int *twin;                  /* ncorners: opposite half-edge, -1 on a boundary */
    int *vert_corner;           /* nverts: one outgoing half-edge (a boundary one if any), -1 if unused */
    int min_face_size, max_face_size;
    int repaired_edges;         /* TT_MESH_PERMISSIVE only: edges turned into boundaries */
    unsigned flags;
    tt_allocator allocator;     /* the one it was built with */
} tt_mesh;

/* Build a half-edge mesh and validate it. On failure *out_mesh is NULL and the
   error names the first problem found, checking in this order: counts (empty
   mesh, a face with fewer than 3 corners, sizes that overflow), coordinates
   (every vertex, used or not: NaN or infinite), then face by face in index
   order (index out of range, repeated vertex, zero area), then edges, the one
   with the smallest corner first (shared by more than two faces, or used twice
   in the same direction), then vertices (faces forming several fans).
   Twin pairing is O(corners log valence). Free the mesh with tt_mesh_free. */
TTDEF tt_result tt_mesh_build(const tt_mesh_desc *desc, const tt_allocator *allocator, tt_mesh **out_mesh,
                              tt_error *error);
TTDEF void tt_mesh_free(tt_mesh *mesh);

/* Index of the corner after / before c in its face.
   Preconditions (TT_ASSERT): mesh is not NULL, 0 <= corner < mesh->ncorners. */
TTDEF int tt_mesh_next(const tt_mesh *mesh, int corner);
TTDEF int tt_mesh_prev(const tt_mesh *mesh, int corner);

typedef struct tt_mesh_stats {
    int used_vertices;          /* vertices referenced by at least one face */
    int edges;                  /* undirected edges (a repaired edge counts once per side) */
    int boundary_edges;
    int boundary_loops;
    int components;             /* connected through shared edges */
    int euler_characteristic;   /* used_vertices - edges + faces */
    int genus;                  /* sum over components of (2 - chi - loops) / 2 */
    int min_valence, max_valence;   /* edges per used vertex */
    int nonmanifold_vertices;   /* only possible with TT_MESH_PERMISSIVE */
} tt_mesh_stats;

/* Topology summary (temporary memory only). Errors: NULL mesh or stats, a bad
   allocator (TT_ERROR_INVALID_ARGUMENT), TT_ERROR_OUT_OF_MEMORY. */
TTDEF tt_result tt_mesh_compute_stats(const tt_mesh *mesh, const tt_allocator *allocator, tt_mesh_stats *stats,
                                      tt_error *error);

/* Number of edges at vertex v (0 for an unused vertex).
   Preconditions (TT_ASSERT): mesh is not NULL, 0 <= vertex < mesh->nverts. */
TTDEF int tt_mesh_valence(const tt_mesh *mesh, int vertex);

/* histogram[k] = number of used vertices of valence k for k < nbins-1; the last
   bin counts every valence >= nbins-1. nbins >= 1. */
TTDEF tt_result tt_mesh_valence_histogram(const tt_mesh *mesh, const tt_allocator *allocator, int *histogram,
                                          int nbins, tt_error *error);

/* face_component[f] = component id (0..n-1, numbered in order of first face);
   face_component has mesh->nfaces entries. */
TTDEF tt_result tt_mesh_components(const tt_mesh *mesh, const tt_allocator *allocator, int *face_component,
                                   int *ncomponents, tt_error *error);

/* corner_loop[c] = boundary loop id of boundary half-edge c, -1 for interior
   ones; corner_loop has mesh->ncorners entries. Allocates nothing. */
TTDEF tt_result tt_mesh_boundary_loops(const tt_mesh *mesh, int *corner_loop, int *nloops, tt_error *error);

typedef enum tt_subdivision {
    TT_SUBDIVIDE_LINEAR = 0,        /* new points on the old faces: the shape is kept */
    TT_SUBDIVIDE_CATMULL_CLARK = 1  /* Catmull-Clark positions: smoother, shrinks a little */
} tt_subdivision;

/* One step that turns every n-gon into n quads: a point per face and per edge;
   quad i of face f is (corner i's vertex, edge point of half-edge i, face point,
   edge point of half-edge i-1). New vertex order: old vertices, then edge points
   (edges in order of their first half-edge), then face points. Repeat it to make
   the faces smaller (it is how you choose the texture's scale on the surface).
   The result inherits the input's flags (without BORROW_POSITIONS). A valid
   mesh always quadrangulates, but a new quad can have zero area even in a
   strict result: where a valid polygon repeats a position at distinct
   vertices, or where float cannot separate the new points (a tiny face far
   from the origin); tt_face_normal gives (0, 0, 0) for such a quad. New
   points that overflow float are TT_ERROR_NON_FINITE. */
TTDEF tt_result tt_mesh_quadrangulate(const tt_mesh *mesh, tt_subdivision scheme, const tt_allocator *allocator,
                                      tt_mesh **out_mesh, tt_error *error);

/* Unit normal of face f by Newell's method (the normal of the best-fit plane,
   so non-planar polygons are fine), CCW seen from outside. A face of
   numerically zero area (as tt_mesh_build judges it) gets (0,0,0).
   Preconditions (TT_ASSERT): mesh and normal are not NULL,
   0 <= face < mesh->nfaces. */
TTDEF void tt_face_normal(const tt_mesh *mesh, int face, float normal[3]);

/* Smooth shading normals with creases, for meshes that come without any:
   corner_normal gets 3 floats per corner, the unit mean of the normals of
   the faces around the corner's vertex that are within crease_degrees of
   its own face's normal (its own always counts), each weighted by its angle
   at the vertex (so that splitting a face into triangles changes nothing).
   0 degrees gives each corner its face's normal (flat); 180 smooths every
   vertex; 30 to 60 keeps a CAD part's edges and smooths a scan. Faces of
   zero area weigh nothing; a corner with nothing to average gets (0, 0, 0).
   Errors: NULL mesh or corner_normal, crease_degrees not in [0, 180]
   (TT_ERROR_INVALID_ARGUMENT); TT_ERROR_OUT_OF_MEMORY. */
TTDEF tt_result tt_corner_normals(const tt_mesh *mesh, float crease_degrees, const tt_allocator *allocator,
                                  float *corner_normal, tt_error *error);

/* ======================================================================== */
/* 3. Image                                                                 */
/* ======================================================================== */

/* Width or height above this is refused with TT_ERROR_TOO_LARGE. */
#define TT_MAX_IMAGE_SIZE 32768

/* Float RGBA, row-major, row 0 at the top, in linear light (see CONVENTIONS).
   Colours may be straight or premultiplied by alpha: each function says which
   it expects. Images the library creates come from tt_image_create and its
   kin and are freed with tt_image_free. You may also fill this struct
   yourself to hand the library your own pixels (a view): leave `allocator`
   zeroed and never pass a view to tt_image_free. */
typedef struct tt_image {
    int width, height;
    float *pixels;              /* 4 * width * height */
    tt_allocator allocator;     /* the one it was created with */
} tt_image;

/* How 8-bit values encode colour. */
typedef enum tt_color_space {
    TT_COLOR_SRGB = 0,          /* colour photos and albedo maps: sRGB transfer curve on r, g, b
                                   (IEC 61966-2-1); alpha is always linear */
    TT_COLOR_LINEAR = 1         /* data maps (normals, roughness, height, masks): v / 255 as is */
} tt_color_space;

/* The sRGB transfer curve and its inverse, on values in [0, 1] (clamped). */
TTDEF float tt_srgb_to_linear(float encoded);
TTDEF float tt_linear_to_srgb(float linear);

/* A zero-filled image (transparent black). Errors: sizes below 1
   (TT_ERROR_INVALID_ARGUMENT) or above TT_MAX_IMAGE_SIZE (TT_ERROR_TOO_LARGE),
   a bad allocator, TT_ERROR_OUT_OF_MEMORY. One allocation holds the struct and
   its pixels. */
TTDEF tt_result tt_image_create(int width, int height, const tt_allocator *allocator, tt_image **out_image,
                                tt_error *error);
/* Free an image the library created (NULL is fine). */
TTDEF void tt_image_free(tt_image *image);

/* From 8-bit pixels with 1 (grey), 2 (grey+alpha), 3 (RGB) or 4 (RGBA)
   channels, `stride` bytes per row (0 = width * channels; otherwise at least
   that). r, g, b are decoded from `space` into linear light (alpha: v / 255).
   Bytes -> linear -> bytes (tt_image_to_rgba8, same space) is exact. */
TTDEF tt_result tt_image_from_bytes(const unsigned char *data, int width, int height, int channels, int stride,
                                    tt_color_space space, const tt_allocator *allocator, tt_image **out_image,
                                    tt_error *error);
/* To 8-bit RGBA, width * height * 4 bytes: r, g, b encoded into `space`
   (straight alpha: pass an un-premultiplied image), everything rounded to
   the nearest byte and clamped to [0, 255]; NaN becomes 0. `out` may be the
   image's own pixels: each texel's bytes land on floats already read, so a
   large image converts without a second buffer (the floats are gone then).
   Preconditions (TT_ASSERT): image, its pixels and out are not NULL. */
TTDEF void tt_image_to_rgba8(const tt_image *image, tt_color_space space, unsigned char *out);

/* How a sample outside the image is addressed. */
typedef enum tt_wrap {
    TT_WRAP_CLAMP = 0,      /* the edge texels continue outward */
    TT_WRAP_REPEAT = 1      /* the image tiles the plane (a periodic texture): x is taken modulo the
                               width, y modulo the height, and texels blend across the borders */
} tt_wrap;

/* Bilinear sample at continuous pixel coordinates: texel (i, j) covers
   [i, i+1) x [j, j+1), so its centre is (i + 0.5, j + 0.5). Clamps to the edge.
   Preconditions (TT_ASSERT): image has pixels and a size of at least 1 x 1. */
TTDEF void tt_image_sample_bilinear(const tt_image *image, float x, float y, float rgba[4]);
/* The same with a choice of addressing; TT_WRAP_CLAMP is
   tt_image_sample_bilinear exactly. With TT_WRAP_REPEAT a NaN or infinite
   coordinate samples texel 0 of its axis (clamping takes texel 0 for NaN
   and the edge for an infinity).
   Preconditions (TT_ASSERT): as tt_image_sample_bilinear, and wrap is a
   tt_wrap value. */
TTDEF void tt_image_sample_bilinear_wrap(const tt_image *image, float x, float y, tt_wrap wrap, float rgba[4]);

/* Where pixel (x, y) of a width x height image lands after `quarter_turns`
   counter-clockwise quarter turns (as the picture is seen, row 0 on top).
   Works for coordinates outside the image too (it is an affine map).
   Preconditions (TT_ASSERT): out_x and out_y are not NULL, and the result
   fits an int (|x|, |y|, width, height below 2^30 always do). */
TTDEF void tt_rotate_coords(int quarter_turns, int width, int height, int x, int y, int *out_x, int *out_y);

/* *dst = src turned counter-clockwise by quarter_turns * 90 degrees (any
   integer, negative = clockwise); sizes swap for odd turns. */
TTDEF tt_result tt_image_rotate90(const tt_image *src, int quarter_turns, const tt_allocator *allocator,
                                  tt_image **out_image, tt_error *error);

/* Porter-Duff `over` on premultiplied RGBA: dst = src + (1 - src.a) * dst.
   alpha 1 gives src exactly and alpha 0 leaves dst exactly. Same sizes
   (TT_ERROR_INVALID_ARGUMENT otherwise). */
TTDEF tt_result tt_image_over(tt_image *dst, const tt_image *src, tt_error *error);
/* The same on one pixel. Preconditions (TT_ASSERT): neither is NULL. */
TTDEF void tt_rgba_over(float dst[4], const float src_premultiplied[4]);

/* *dst = src halved by a 2x2 box filter (width and height must be even; in
   linear light, so a black and white checkerboard becomes sRGB 188, not 128). */
TTDEF tt_result tt_image_downsample2(const tt_image *src, const tt_allocator *allocator, tt_image **out_image,
                                     tt_error *error);

/* Minimum-error cut (as in image quilting): in a width x height cost map, find
   the path path[x] (one row per column) with path[x] in [lo[x], hi[x]] and
   |path[x] - path[x-1]| <= 1 that minimises the sum of cost[path[x]*width + x].
   Ties go to the smaller row. Needs lo[x] <= hi[x] and consecutive ranges
   that a path can follow (TT_ERROR_INVALID_ARGUMENT otherwise, naming the
   column); a NaN cost is TT_ERROR_NON_FINITE. path has width entries. */
TTDEF tt_result tt_min_error_cut(const float *cost, int width, int height, const int *lo, const int *hi,
                                 const tt_allocator *allocator, int *path, tt_error *error);

/* ======================================================================== */
/* 4. Numerics                                                              */
/* ======================================================================== */

/* Sparse linear systems. The pipelines that flatten a piece of surface into
   the plane solve least-squares problems whose normal equations are sparse,
   symmetric and positive definite: lapped textures align each paste with the
   tangent field (Praun et al. Sec. 3.4), hierarchical pattern mapping
   flattens each face cluster (Soler et al. Sec. 3.2). Such a system is
   assembled as triplets, compressed into rows (CSR) and solved by the Jacobi
   (diagonal) preconditioned conjugate gradient method, with the formulas of
   Shewchuk, "An Introduction to the Conjugate Gradient Method Without the
   Agonizing Pain" (edition 1 1/4, 1994), Sec. 12 and the preconditioned
   algorithm of its Appendix B3 (M = diag(A)):

       r0 = b - A x0,   z0 = M^-1 r0,   p0 = z0
       alpha_k = (r_k . z_k) / (p_k . A p_k)
       x_k+1 = x_k + alpha_k p_k,   r_k+1 = r_k - alpha_k A p_k
       z_k+1 = M^-1 r_k+1
       beta_k = (r_k+1 . z_k+1) / (r_k . z_k),   p_k+1 = z_k+1 + beta_k p_k

   stopping when |r| <= tolerance * |b| (Euclidean norms, computed with a
   scale so that no |b_i| of any finite size overflows or underflows them),
   and confirming it with a freshly computed b - A x (Shewchuk Sec. 11)
   before reporting success.

   Errors about a matrix entry give its row and column in tt_error::row and
   tt_error::column, errors about a triplet its position in tt_error::item,
   errors about an unknown or a right-hand side value its index in
   tt_error::row. */

/* One entry of a sparse matrix being assembled: A[row][col] += value. */
typedef struct tt_triplet {
    int row, col;
    double value;
} tt_triplet;

/* Compressed sparse rows (CSR). The entries of row i are k in
   [row_start[i], row_start[i+1]): A[i][col[k]] = value[k]. Matrices made by
   tt_sparse_from_triplets have strictly increasing columns within each row.
   You may change value[] in place (same pattern, new numbers); do not change
   the other fields. You may also fill this struct yourself from your own CSR
   arrays to call tt_sparse_multiply or tt_cg_solve (then do not call
   tt_sparse_matrix_free on it); such arrays may have unsorted or repeated columns
   (repeats add up). */
typedef struct tt_sparse_matrix {
    int rows, cols;
    int nnz;                    /* stored entries = row_start[rows] */
    int *row_start;             /* rows + 1, row_start[0] == 0 */
    int *col;                   /* nnz column indices, 0-based */
    double *value;              /* nnz values */
    tt_allocator allocator;     /* the one the arrays came from */
} tt_sparse_matrix;

/* Build an rows x cols CSR matrix from `ntriplets` triplets in any order.
   Triplets naming the same entry are summed, in the order given (so the result
   is the same on every run); entries that sum to zero are kept (the pattern is
   what the triplets name). Rows without triplets are empty. Fails, with
   *out_matrix NULL and nothing left allocated, on:
     TT_ERROR_INDEX_OUT_OF_RANGE  a triplet outside the matrix (error->item,
                                  row and column name it),
     TT_ERROR_NON_FINITE          a NaN or infinite value, or triplets of one
                                  entry whose sum overflows to infinity
                                  (error->row, column),
     TT_ERROR_INVALID_ARGUMENT    NULL out_matrix, negative sizes, triplets
                                  NULL while ntriplets > 0, a bad allocator,
     TT_ERROR_TOO_LARGE           byte counts that overflow size_t,
     TT_ERROR_OUT_OF_MEMORY.
   Time O(ntriplets + rows + cols) (two stable bucket passes); memory: the
   result (12 bytes per entry + 4 per row) plus 8 bytes per triplet and 4 per
   row or column of temporary space. Free the matrix with tt_sparse_matrix_free.
   Thread-safe: reads only the triplets. */
TTDEF tt_result tt_sparse_from_triplets(int rows, int cols, const tt_triplet *triplets, int ntriplets,
                                        const tt_allocator *allocator, tt_sparse_matrix **out_matrix,
                                        tt_error *error);

/* Release a matrix made by tt_sparse_from_triplets (NULL is fine; never a
   struct you filled yourself). */
TTDEF void tt_sparse_matrix_free(tt_sparse_matrix *matrix);

/* y = A x: x has A->cols entries, y gets A->rows. x and y must not overlap
   (x == y is refused with TT_ERROR_INVALID_ARGUMENT). The CSR arrays are
   trusted (tt_cg_solve checks them, this does not). Does not allocate;
   thread-safe for distinct y. */
TTDEF tt_result tt_sparse_multiply(const tt_sparse_matrix *A, const double *x, double *y, tt_error *error);

typedef struct tt_cg_options {
    int max_iterations;         /* cap on CG steps; 0 = max(2 * n, 100) for an n x n system */
    /* Stop at |b - A x| <= tolerance * |b|; 0 = 1e-8. Success is confirmed on
       a recomputed b - A x, so a tolerance below what double precision can
       reach for this A (roughly 1e-16 times its condition number) ends in
       TT_ERROR_NOT_CONVERGED at the cap rather than in a false success. */
    double tolerance;
    /* Called before every step with a fraction in [0, 1] that never
       decreases: the larger of steps / max_iterations and
       log(residual) / log(tolerance). Non-zero return cancels. May be NULL. */
    tt_progress_fn progress;
    void *progress_user_data;
    int preconditioner;         /* TT_CG_JACOBI (0, the default) or TT_CG_INCOMPLETE_CHOLESKY */
} tt_cg_options;

/* tt_cg_options.preconditioner. Jacobi (the diagonal) needs no setup. The
   incomplete Cholesky factor IC(0) (L L^T close to A, L on A's lower
   pattern) costs one pass to make and about two products with A per step,
   and takes far fewer steps on mesh matrices (4 times fewer in the lapped
   textures' alignment solves, for 15 % less time). It needs each row's
   columns strictly increasing (as tt_sparse_from_triplets makes them); when
   the factorisation breaks down (a pivot <= 0, possible for some positive
   definite matrices) the solve uses Jacobi instead and says so in
   tt_cg_report.preconditioner. */
#define TT_CG_JACOBI 0
#define TT_CG_INCOMPLETE_CHOLESKY 1

typedef struct tt_cg_report {
    int iterations;             /* CG steps taken (0 when x0 already solved the system) */
    double residual;            /* |b - A x| / |b| for the x returned, recomputed from A, x, b; 0 when b = 0 */
    int converged;              /* 1 when residual <= tolerance */
    int preconditioner;         /* the one used (see TT_CG_INCOMPLETE_CHOLESKY) */
} tt_cg_report;

/* Solve A x = b for a symmetric positive definite n x n A by preconditioned
   conjugate gradients (see the section comment), Jacobi or incomplete
   Cholesky (options->preconditioner).
     b   n values, read only; must not overlap x. Any finite values: the
         norms are scaled, so b = (1e155, 1) or entries of 1e-200 are solved
         like any other.
     x   n values: in, the initial guess (warm start; zeros if you have none),
         out, the solution. It must be finite.
     options, allocator (for 5 n scratch doubles; with incomplete Cholesky
     n more and the factor, 12 bytes per entry of A's lower triangle and 4
     per row), report, error may be NULL (defaults; TT_MALLOC; no report; no
     details).
     report is filled on every return; before any step it reads
     {0, 0.0, 0, the preconditioner} (converged = 1 for b = 0 or an x0 that
     already solves).
   Returns
     TT_OK                          converged: report->residual <= tolerance;
     TT_ERROR_NOT_CONVERGED         max_iterations steps did not get there: x is
                                    the last iterate, report says how close;
     TT_ERROR_NOT_POSITIVE_DEFINITE a diagonal entry <= 0 or missing (names the
                                    row: before any work, x untouched), or the
                                    iteration broke down with p . A p <= 0
                                    (x is the last iterate);
     TT_ERROR_NON_FINITE            NaN or infinity in A, b or x (error->row
                                    names it), or an overflow during the
                                    iteration;
     TT_ERROR_INVALID_ARGUMENT      NULL pointers, b == x, A not square or its
                                    row_start array inconsistent, negative
                                    max_iterations or tolerance, an unknown
                                    preconditioner, or incomplete Cholesky on
                                    a row whose columns do not increase
                                    (error->row);
     TT_ERROR_INDEX_OUT_OF_RANGE    a column index outside the matrix (only
                                    possible in a CSR you filled yourself);
     TT_CANCELLED                   the progress callback asked to stop (x is
                                    the last iterate);
     TT_ERROR_OUT_OF_MEMORY.
   b = 0 gives x = 0 at once. Symmetry is assumed, not checked (checking
   costs more than several steps): a non-symmetric A may stall or break down.
   Memory: one scratch block of 5 n doubles for the whole solve, nothing per
   step. A step costs one product with A (with p . A p in the same pass) and
   two fused passes over the vectors; one more product confirms the result.
   Thread-safe: several threads may solve with the same A and b into
   distinct x. */
TTDEF tt_result tt_cg_solve(const tt_sparse_matrix *A, const double *b, const tt_cg_options *options,
                            const tt_allocator *allocator, double *x, tt_cg_report *report, tt_error *error);

/* ---- Fast Fourier transforms and masked cross-correlation ----

   Hierarchical pattern mapping (Soler et al. Sec. 4.2) finds where a masked
   piece of texture fits best in an image by correlating it with the image
   at every offset at once, with the FFT. This part gives the transforms and
   that masked correlation.

   Transforms. Complex double, in place, radix-2 family (sizes are powers of
   two, pad the data to them), iterative: a bit-reversal permutation, one
   radix-2 stage when log2 n is odd, then radix-4 stages (each does the work of
   two radix-2 stages with one load and store of 4 points and 3 complex
   multiplies instead of 4). The twiddle factors of each stage are stored
   contiguously in the plan, each computed directly with cos and sin (no
   recurrence, so no drift). Arrays are row-major, `height` rows of `width`
   values; complex values are interleaved (re, im) doubles. A 2D transform
   runs the 1D transform along every row, then along every column. The
   column pass works on strips of 32 adjacent columns at once, in place:
   each butterfly then combines row segments of 32 complex numbers with one
   twiddle, a unit-stride loop the compiler vectorises, where gathering one
   column at a time would touch a row's worth of cache line per value (about
   4x slower at 512 x 512). The stages that combine rows close together run
   on 64 KB blocks of a strip while they are in cache: with a power-of-two
   row stride a whole strip maps onto a fraction of the cache's sets and
   would not stay there. Width and height are independent (64 x 32 is fine);
   height 1 is a 1D transform. Forward plus inverse at 256 x 256 and
   512 x 512 takes 2-2.5x the time of FFTW's FFTW_MEASURE plans in a plain
   -O2 build (make bench; no SIMD intrinsics here, FFTW uses AVX).

   Conventions (as FFTW's): forward (TT_FFT_FORWARD = -1)
       X(k, l) = sum over x < width, y < height of d(x, y) e^(-2 pi i (k x / width + l y / height)),
   inverse (TT_FFT_INVERSE = +1) the same with e^(+2 pi i ...) and NOT
   normalised: inverse(forward(d)) = width * height * d. Callers fold the
   1 / (width * height) into a pass they make anyway.

   Memory and threads. The plan holds the twiddles and the bit-reversal table
   (about 40 bytes per value of the larger side); the transforms allocate
   nothing and need no scratch, so a plan is read-only after
   tt_fft_plan_create and several threads may transform distinct arrays with
   one plan at once. The data is not checked before a transform (another
   pass over memory); the result is, where the last stage writes it while it
   is in cache: a NaN or infinity in the data, or an overflow, comes out as
   TT_ERROR_NON_FINITE.

   Masked correlation. See tt_xcorr_masked: with the correlation
       (f * g)(x0) = sum over x of f(x) g(x + x0) = F^-1( conj(F(f)) F(g) )(x0)
   (Soler et al.'s footnote 2; the paper's printed F^-1(F(f) conj(F(g)))
   is the mirror image, and would return -x0). */

#define TT_FFT_FORWARD (-1)   /* e^(-2 pi i ...) */
#define TT_FFT_INVERSE 1      /* e^(+2 pi i ...), unnormalised */
#define TT_FFT_MAX_SIZE 32768 /* the largest width or height of a plan (2^15) */

/* The sizes and tables of transforms of height x width values. Read-only
   after creation: several threads may use it at once. The arrays are the
   plan's own; do not change them. */
typedef struct tt_fft_plan {
    int width, height;          /* powers of two in [1, TT_FFT_MAX_SIZE] */
    int log2_width, log2_height;
    int size;                   /* max(width, height): the tables' size */
    double *twiddles;           /* per radix-4 stage of quarter length L = 1, 2, 4, .., size / 4: at 6 (L - 1),
                                   L triples (cos, sin) of 2 pi k m / (4 L), m = 1, 2, 3, k < L */
    double *real_twiddles;      /* (cos, sin) of 2 pi k / width for k < width / 2: the real transforms' pass */
    int *bit_reverse;           /* size entries: i with its log2(size) bits reversed */
    tt_allocator allocator;     /* the one the arrays came from */
} tt_fft_plan;

/* Make the plan for transforms of height rows by width columns (height 1:
   a 1D transform of width values). Fails, with *out NULL and nothing left
   allocated, on:
     TT_ERROR_INVALID_ARGUMENT  a size that is not a power of two from 1 to
                                TT_FFT_MAX_SIZE (the message says the nearest
                                power of two and the one to pad to), NULL out,
                                a bad allocator,
     TT_ERROR_OUT_OF_MEMORY.
   Time O(size) cos/sin calls; memory about 40 bytes per value of the larger
   side. Free it with tt_fft_plan_free. Thread-safe. */
TTDEF tt_result tt_fft_plan_create(int width, int height, const tt_allocator *allocator, tt_fft_plan **out,
                                   tt_error *error);

/* Release a plan (NULL is fine). */
TTDEF void tt_fft_plan_free(tt_fft_plan *plan);

/* Transform data, height x width complex values (2 * width * height
   doubles, interleaved re, im; row y starts at data[2 * width * y]), in place:
   direction TT_FFT_FORWARD or TT_FFT_INVERSE (unnormalised; see the
   conventions above). width and height are the data's, and must be the
   plan's: they guard against transforming a 512 x 512 array with a 256 x 256
   plan. Returns
     TT_ERROR_INVALID_ARGUMENT  NULL plan or data, a direction other than -1
                                or +1, sizes that are not the plan's (data
                                untouched);
     TT_ERROR_NON_FINITE        the result holds a NaN or infinity: the data
                                did, or its values overflowed (above about
                                1e300 / (width * height)); the data is then
                                transformed as IEEE arithmetic made it.
   Allocates nothing; O(n log n) for n = width * height. Thread-safe for
   distinct data. */
TTDEF tt_result tt_fft_c2c(const tt_fft_plan *plan, double *data, int width, int height, int direction,
                           tt_error *error);

/* Forward transform of real data, height x width doubles (row-major), into
   its half spectrum: height x (width / 2 + 1) complex values (2 * height *
   (width / 2 + 1) doubles, interleaved; row l starts at
   spectrum[2 * (width / 2 + 1) * l]), where spectrum entry (l, k) is the
   forward c2c transform's X(k, l) for k = 0 .. width / 2. The other half is
   redundant: X(k, l) = conj(X(width - k, (height - l) mod height)).
   The rows use the N/2 packing: a row of width reals is read as
   width / 2 complex values (x[2m] + i x[2m + 1]), transformed, and split
   into bins 0 .. width / 2 by one pass; about half the work of the complex
   transform. real and spectrum must not overlap. Errors as tt_fft_c2c
   (width and height are the real data's; TT_ERROR_NON_FINITE leaves the
   spectrum unspecified). Allocates nothing; thread-safe for distinct
   outputs. */
TTDEF tt_result tt_fft_r2c(const tt_fft_plan *plan, const double *real, int width, int height, double *spectrum,
                           tt_error *error);

/* Inverse of tt_fft_r2c, unnormalised like tt_fft_c2c:
   c2r(r2c(x)) = width * height * x. spectrum (the half spectrum, laid out as
   tt_fft_r2c writes it) is used as work space and destroyed; real gets
   height x width doubles and must not overlap it. The spectrum is taken to
   be that of real data (Hermitian), as r2c's output and sums and products of
   such spectra are: the imaginary parts of bins k = 0 and k = width / 2 after
   the column pass are ignored, as FFTW's c2r does. Errors as tt_fft_r2c.
   Allocates nothing; thread-safe for distinct arrays. */
TTDEF tt_result tt_fft_c2r(const tt_fft_plan *plan, double *spectrum, int width, int height, double *real,
                           tt_error *error);

/* The cached part of a masked correlation against one image T: its plan
   and the half spectra (tt_fft_r2c) of each channel T_c and of sum_c T_c^2.
   Read-only after creation: several threads may correlate against it at
   once. */
typedef struct tt_xcorr_texture {
    int width, height;          /* T's size: powers of two (pad T to them) */
    int channels;
    size_t work_size;           /* doubles of work space tt_xcorr_masked needs: 2 * spectrum_size */
    size_t best_work_size;      /* doubles of work space tt_xcorr_masked_best needs against textures of this
                                   size and channel count: (channels + 2) * spectrum_size (the spectra of
                                   J and of each J I_c, made once and kept, and one combined spectrum) */
    size_t spectrum_size;       /* doubles in one half spectrum: 2 * height * (width / 2 + 1) */
    tt_fft_plan *plan;          /* width x height; the object's own */
    double *spectra;            /* channels + 1 half spectra, spectrum_size doubles apart: F(T_0), ..,
                                   F(T_channels-1), F(sum_c T_c^2) */
    tt_allocator allocator;     /* the one everything here came from */
} tt_xcorr_texture;

/* Cache an image T for tt_xcorr_masked: `texture` holds `channels` planes of
   height x width doubles, plane c starting at texture[c * width * height]
   (row-major). Correlation is circular (toroidal): an offset compares the
   mask with T(x mod width, y mod height). For a bounded image, pad it with
   zeros to a power-of-two size and restrict the offsets (the `allowed` map
   of tt_xcorr_masked); for a periodic one of another size, fill the padded
   size periodically. Use a Euclidean colour space (the channels' squared
   differences are added). Fails, with *out NULL and nothing left allocated,
   on:
     TT_ERROR_INVALID_ARGUMENT  sizes that are not powers of two from 1 to
                                TT_FFT_MAX_SIZE, channels < 1, NULL texture
                                or out, a bad allocator,
     TT_ERROR_NON_FINITE        a NaN or infinite value (error->row, column
                                and item = channel name it), or values whose
                                squares overflow,
     TT_ERROR_TOO_LARGE         byte counts that overflow size_t,
     TT_ERROR_OUT_OF_MEMORY.
   Time: channels + 1 real transforms; memory: (channels + 1) half spectra,
   16 bytes per texel of each. Free it with tt_xcorr_texture_free.
   Thread-safe: reads only `texture`. */
TTDEF tt_result tt_xcorr_texture_create(int width, int height, int channels, const double *texture,
                                        const tt_allocator *allocator, tt_xcorr_texture **out, tt_error *error);

/* Release a cached texture (NULL is fine). */
TTDEF void tt_xcorr_texture_free(tt_xcorr_texture *texture);

/* The best offset of a masked correlation. */
typedef struct tt_xcorr_match {
    int x, y;                   /* the allowed offset with the smallest E; -1, -1 when there is none */
    double e;                   /* E(x, y) there (>= 0); 0 when there is none */
    double mask_sum;            /* |J| = sum of the mask's weights */
    double masked_energy;       /* sum over texels and channels of J I^2: E if T were 0 */
} tt_xcorr_match;

/* Masked sum of squared differences between values I (under mask J) and
   the cached image T, at every offset (x, y) at once:
       E(x, y) = sum over texels p and channels c of J(p) (I_c(p) - T_c(p + (x, y)))^2
               = sum J I^2 - 2 sum_c ((J I_c) * T_c)(x, y) + (J * sum_c T_c^2)(x, y)
   with p + (x, y) taken mod (width, height) and * the correlation of the
   section comment (F^-1(conj(F(f)) F(g))): so E(x, y) compares the value at
   texel p with T at p + (x, y). In other words, if the values are a crop of
   T placed at (x0, y0), I(p) = T(p + (x0, y0)) under the mask, then
   E(x0, y0) = 0. Computed with real transforms in double: channels + 1
   forward ones and one inverse per call; each E is clamped at 0 (the sum of
   three large terms can round below 0).
     mask     height x width weights J >= 0 (1 / 0 for a binary mask; soft
              coverage works too: the weighted form above is exact for it).
     values   `channels` planes of height x width, laid out as the texture;
              read only where J > 0 (elsewhere anything, even NaN).
     allowed  height x width bytes, non-zero where an offset may be chosen
              (row y, column x = offset (x, y)); NULL: every offset.
     work     texture->work_size doubles of scratch (the caller's, so that
              repeated fits allocate nothing); must not overlap the others.
     out_map  height x width doubles receiving E(x, y) at every offset (row
              y, column x), allowed or not; may be NULL when only the match
              is wanted.
     out_match  the allowed offset with the smallest E, ties broken by the
              smallest y * width + x (the first in row-major order); may be
              NULL when only the map is wanted (not both NULL).
   Returns
     TT_ERROR_NOT_MEASURED      the mask is all zero (every offset fits
                                equally: E = 0 everywhere, out_match
                                {-1, -1, 0, 0, 0}) or no offset is allowed
                                (out_match -1, -1; the map is filled),
     TT_ERROR_INVALID_ARGUMENT  NULL texture, mask, values or work, both
                                outputs NULL, a negative mask weight
                                (error->row, column),
     TT_ERROR_NON_FINITE        a NaN or infinite weight, or value under the
                                mask (error->row, column and item = channel),
                                or sums that overflow.
   Allocates nothing. Thread-safe: several threads may use one texture with
   their own work and outputs. */
TTDEF tt_result tt_xcorr_masked(const tt_xcorr_texture *texture, const double *mask, const double *values,
                                const unsigned char *allowed, double *work, double *out_map,
                                tt_xcorr_match *out_match, tt_error *error);

/* The best fit of one masked piece over several cached textures at once: the
   offset and texture with the smallest E of tt_xcorr_masked. It exists for
   hierarchical pattern mapping, which fits a band against R turned copies of
   one image (R = 19 by default): only T differs between the copies, so the
   forward transforms of J and of each J I_c are made once and kept, and each
   texture then costs one pass of spectrum products and one inverse
   transform. Total: channels + 1 forward and ntextures inverse transforms,
   where ntextures calls of tt_xcorr_masked make (channels + 2) ntextures:
   19 textures of 512 x 512 and 3 channels take about a third of the time of
   19 calls (make bench). The result is bit for bit the one those calls
   give: E is computed by the same code, clamped at 0.
     textures    ntextures >= 1 cached textures, all of the same width,
                 height and channels (made by tt_xcorr_texture_create).
     mask, values  as for tt_xcorr_masked, sized as the textures.
     allowed     NULL (every offset of every texture), or ntextures
                 pointers: allowed[k] is NULL (every offset of texture k) or
                 a height x width byte map as tt_xcorr_masked's. A texture
                 none of whose offsets is allowed is skipped: not transformed.
     work        textures[0]->best_work_size doubles of scratch; must not
                 overlap the others.
     out_match   the best allowed offset over all textures; ties broken by
                 the smallest (texture index, y, x): the first texture wins
                 an exact tie, then the first offset in row-major order.
                 mask_sum and masked_energy as tt_xcorr_masked's.
     out_texture the index of the texture it lies in; -1 when there is none.
   Returns
     TT_ERROR_NOT_MEASURED      the mask is all zero, or no offset of any
                                texture is allowed (out_match
                                {-1, -1, 0, ...}, out_texture -1),
     TT_ERROR_INVALID_ARGUMENT  NULL textures, a NULL texture (error->item
                                names it), NULL mask, values, work,
                                out_match or out_texture; ntextures < 1; a
                                texture whose width, height or channels
                                differ from textures[0]'s (the first such,
                                error->item); a negative mask weight
                                (error->row, column),
     TT_ERROR_NON_FINITE        a NaN or infinite weight, or value under the
                                mask (error->row, column and item = channel),
                                or sums that overflow (for the correlation
                                with one texture, error->item names it).
   Allocates nothing. Time: channels + 1 real forward transforms, then per
   texture with an allowed offset (channels + 1) products over the half
   spectrum, one real inverse transform and one pass over the offsets.
   Thread-safe: several threads may use the same textures with their own
   work and outputs. */
TTDEF tt_result tt_xcorr_masked_best(const tt_xcorr_texture *const *textures, int ntextures, const double *mask,
                                     const double *values, const unsigned char *const *allowed, double *work,
                                     tt_xcorr_match *out_match, int *out_texture, tt_error *error);

/* ======================================================================== */
/* 5. Raster                                                                */
/* ======================================================================== */

/* Called once per covered pixel; barycentric[i] is the weight of vertex i at the
   pixel centre (x + 0.5, y + 0.5), and the three sum to 1. */
typedef void (*tt_raster_fn)(int x, int y, const float barycentric[3], void *user_data);

/* Visit the pixels of a width x height grid whose centres lie inside the 2D
   triangle xy = {x0,y0, x1,y1, x2,y2} (either winding). A centre exactly on an
   edge belongs to the triangle only if that edge is a top or left edge, so
   triangles sharing an edge never both draw a pixel and leave no gap. An empty
   grid, a degenerate triangle or a non-finite or huge coordinate (beyond
   2^21 pixels) visits nothing. Preconditions (TT_ASSERT): xy and fn are not
   NULL. */
TTDEF void tt_raster_triangle(const float xy[6], int width, int height, tt_raster_fn fn, void *user_data);

/* ======================================================================== */
/* 6. Tiled textures                                                        */
/* ======================================================================== */

/* Based on: E. Akleman, J. Chen, V. Meenakshisundaram, V. Srinivasan, "Tiled
   Textures: A Simple and Practical Technique for Seamless Texturing".
   The steps, for a quad mesh (tt_mesh_quadrangulate any other first):
     1. tt_assign_boundaries: a boundary type per half-edge (Sec. 3, 6);
     2. tt_assign_uvs: each quad's UVs from its four types alone (Sec. 3);
     3. tt_synthesize_tiles, or tt_synth_plan_create + tt_synth_apply for
        several maps of one material: the (2n)^4 tiles composited from
        windows of the photo (Sec. 4), with gutters and mips;
     4. tt_measure_seams, tt_tile_histogram, tt_face_stretch: the report
        (tt_measure_uv_distortion measures any charting, tiled or not).
   Memory: nothing per photo pixel beyond the photo itself (16 bytes a
   pixel, yours): synthesis reads windows of it. The atlas and its mips take
   about 4/3 * W * W * 16 bytes, the plan about 4 * S bytes per tile, and
   planning about 20 * S * S bytes of scratch. */

#define TT_MAX_COLORS 128           /* boundary conditions n; types 0..2n-1 fit a byte */
#define TT_DEFAULT_TILE_SIZE 128
#define TT_NO_GUTTER 0
#define TT_RECOMMENDED_GUTTER 4      /* what the tiledtex tool uses: mip levels 0..2 stay seamless */

/* How tiles sit in the atlas. The UVs depend on this and nothing else, so UVs
   made with one layout fit every atlas synthesised with it.
   T = (2n)^2 tiles per side, cell C = S + 2g, atlas side W = T * C. */
typedef struct tt_tile_layout {
    int colors;       /* n, distinct edge conditions; 0 = 1. Up to TT_MAX_COLORS for boundary
                         assignment; an atlas of (2n)^2 tiles a side must fit TT_MAX_IMAGE_SIZE,
                         so n <= 7 with 128-texel tiles and gutter 4, n <= 45 at most */
    int tile_size;    /* S, texels per tile side; 0 = TT_DEFAULT_TILE_SIZE */
    int gutter;       /* g, texels around each tile, 0 = none; TT_RECOMMENDED_GUTTER for mip-mapping */
} tt_tile_layout;

/* Replace zeros by defaults and check ranges: colors 1..TT_MAX_COLORS, tile
   size 4..TT_MAX_IMAGE_SIZE, gutter 0..tile size, and an atlas side within
   TT_MAX_IMAGE_SIZE (TT_ERROR_TOO_LARGE otherwise; TT_ERROR_INVALID_ARGUMENT
   for the others). Resolving a resolved layout changes nothing. */
TTDEF tt_result tt_tile_layout_resolve(const tt_tile_layout *in, tt_tile_layout *out, tt_error *error);
/* Tiles per atlas side T, atlas side W, total tiles (2n)^4; zeros in the
   layout mean defaults, as everywhere.
   Preconditions (TT_ASSERT): a layout that tt_tile_layout_resolve accepts;
   any other gives 0, never an overflow. */
TTDEF int tt_tile_layout_tiles_per_side(const tt_tile_layout *layout);
TTDEF int tt_tile_layout_atlas_size(const tt_tile_layout *layout);
TTDEF int tt_tile_layout_tile_count(const tt_tile_layout *layout);

/* Akleman et al. Sec. 3 / 6, AssignBoundaries: every edge gets a condition k in
   [0, n) and a side i in {0, 1}; one half-edge gets type 2k+i, its twin
   2k+1-i. Boundary half-edges get a type too. Works on any mesh.
     edge_colors  NULL: every k from the seeded RNG. Otherwise mesh->ncorners
                  entries: the condition k of the edge of half-edge c, or -1
                  to draw it at random; both half-edges of an edge must say
                  the same (a polycube's per-axis palettes, say). The side i
                  always comes from the RNG.
     corner_type  mesh->ncorners entries out, aligned with the index buffer.
   Only layout->colors is read (0 = 1). Same seed and inputs, same result.
   Errors: NULL mesh, layout or corner_type, colors outside 1..TT_MAX_COLORS
   (TT_ERROR_INVALID_ARGUMENT); a prescribed colour outside -1..n-1
   (TT_ERROR_INDEX_OUT_OF_RANGE) or twins that disagree
   (TT_ERROR_INVALID_ARGUMENT), naming the corner. */
TTDEF tt_result tt_assign_boundaries(const tt_mesh *mesh, const tt_tile_layout *layout, uint64_t seed,
                                     const int *edge_colors, uint8_t *corner_type, tt_error *error);

/* Tile of a quad whose half-edges have types e0..e3 (bottom, right, top, left):
   column = 2n*e0 + e1, row = 2n*e2 + e3 (row 0 at the bottom of the atlas);
   returns row * T + column.
   Preconditions (TT_ASSERT): layout and types are not NULL, layout->colors
   in 0..TT_MAX_COLORS (0 = 1), every type below 2n. */
TTDEF int tt_tile_index(const tt_tile_layout *layout, const uint8_t types[4]);

/* UV of corner i (0..3) of the tile with types e0..e3 (Akleman Sec. 3 with n
   conditions and gutters): j = ((i+1) mod 4) / 2,
       u = (column*C + g + j*S) / W,   v = (row*C + g + (i/2)*S) / W.
   Preconditions (TT_ASSERT): as tt_tile_index, a layout that resolves, and
   0 <= corner < 4. */
TTDEF void tt_tile_corner_uv(const tt_tile_layout *layout, const uint8_t types[4], int corner, float uv[2]);

/* AssignTextureCoordinates: corner_uv gets 2 * mesh->ncorners floats. Every face
   must be a quad (TT_ERROR_NOT_QUAD_MESH names the first that is not). The
   layout is resolved internally (zeros mean defaults). */
TTDEF tt_result tt_assign_uvs(const tt_mesh *mesh, const tt_tile_layout *layout, const uint8_t *corner_type,
                              float *corner_uv, tt_error *error);

typedef struct tt_rect {
    int x, y, w, h;         /* pixels; (x, y) is the top-left corner, row 0 at the top */
} tt_rect;

/* --- Tile-set synthesis (Akleman Sec. 4), as a plan and its application ---

   Synthesis has two halves:
     1. The plan (tt_synth_plan_create), decided once from a guide image
        (usually the colour map): the edge window of each condition (Sec. 4 /
        Sec. 6: two S x S squares whose middle line is the condition), the
        background window of each tile (its XXXX), and, per tile and side, the
        depth of the edge band in every column, from a minimum-error cut of the
        band against what lies beneath it (the paper's f4) kept inside the
        side's wedge (f1..f3). The depths, the feather and the wedge decide
        each band's alpha, i.e. every mask.
     2. The application to any image of the guide's size (tt_synth_apply for
        the whole atlas and its mip chain, tt_synth_compose_tile for one
        tile): ABCD = AXXX over XBXX over XXCX over XXXD over XXXX with the
        plan's windows and masks, then the corner texels and the gutters.
   Applying one plan to several maps of one material (colour, normal,
   roughness, ...) gives atlases whose tiles line up texel for texel: the
   masks do not depend on the applied image, and blending is linear, so an
   image B = a * A + b gives atlas a * atlas_A + b (up to float rounding).
   tt_synthesize_tiles is plan_create + apply + plan_free in one call. */

typedef struct tt_synth_options {
    tt_tile_layout layout;
    uint64_t seed;
    /* Edge condition k is a window of two S x S squares stacked vertically: the
       line between them is the condition; the upper square lines edges of type
       2k, the lower one (turned 180 degrees) edges of type 2k+1. NULL: chosen
       from the seed. Otherwise `colors` rects; only x and y are read. */
    const tt_rect *edge_windows;
    /* Nonzero: upright tiles. Plain tiles turn each edge's band to its side,
       so on the left and right sides an anisotropic texture (bricks, planks,
       grain) runs a quarter turn off: walls come out a maze. Upright tiles
       cut the bands of sides 1 and 3 from a second window per condition
       (`vertical_windows` of the plan, 2S x S, the condition the line
       between its left and right squares), so every band keeps the source's
       up (or is turned half a turn). Two upright tiles meet seamlessly
       across an edge that both see as a left/right side or both as a
       bottom/top side; an edge that is bottom/top to both also meets a plain
       tile of a plan with the same edge_windows seamlessly (the walls and
       the tops of a polycube, tt_polycube_upright_atlas). Needs a
       source of at least 2S x 2S. */
    int upright;
    /* Region from which each tile's S x S background window is drawn; all zero =
       the whole image. */
    tt_rect background;
    int feather;            /* texels of soft blend across each cut; 0 = max(2, S/16); negative is refused */
    /* Called by tt_synth_plan_create (which copies it into the plan) and by
       tt_synth_apply with that plan; tt_synthesize_tiles reports both as one
       run from 0 to 1. */
    tt_progress_fn progress;
    void *progress_user_data;
} tt_synth_options;

/* A synthesis plan: everything that decides the tiles except the texels they
   are made of. Read its fields freely; only progress and progress_user_data
   may be changed (before an apply). Made by tt_synth_plan_create, freed by
   tt_synth_plan_free.

   The band of side s (0 bottom, 1 right, 2 top, 3 left: e0..e3) is described
   in its side frame: x = 0..S-1 runs along the side in the direction of its
   half-edge, d is the distance from the side into the tile (d = 0 is the
   side's edge row, d < 0 lies in the gutter, across the edge). Side-frame
   (x, d) is tile texel tt_rotate_coords(s, S, S, x, S-1-d) (row 0 at the
   top), which is texel (g + tx, g + ty) of the tile's C x C cell. The band's
   alpha at (x, d) is tt_synth_plan_band_alpha: 1 on the edge row, then
   clamp((depth - d - 1/2) / feather + 1/2, 0, 1) times a 2-texel blend at
   the side's wedge (the triangle between the tile's diagonals), 0 in the
   two corner columns x = 0 and x = S-1 and beyond depth + feather.

   Memory: one allocation of about sizeof(tt_synth_plan) + 16 * (n + (2n)^4)
   (2n for an upright plan) + 4 * S * (2n)^4 bytes (the last term doubles for S >= 1024, whose depths
   need 16 bits): n = 1, S = 128: 8.5 KiB; n = 2, S = 64: 68 KiB; about
   1/(4S) of the atlas level 0 it describes. */
typedef struct tt_synth_plan {
    tt_tile_layout layout;          /* resolved: n, S, g */
    int source_width, source_height;/* the guide's size: every applied image must have it */
    int feather;                    /* resolved (options.feather or max(2, S/16)) */
    int max_depth;                  /* max(1, S/4): no band goes deeper (before its feather) */
    tt_rect *edge_windows;          /* n rects (w = S, h = 2S), one per condition */
    tt_rect *vertical_windows;      /* upright plans: n rects (w = 2S, h = S) for sides 1 and 3; else NULL */
    tt_rect *background_windows;    /* one S x S rect per tile, indexed like tt_tile_index */
    /* The band depth (0..max_depth) of tile t, side s, column x at entry
       (4 * t + s) * S + x of the one of these that is not NULL: depth8 when
       max_depth <= 255 (S < 1024), depth16 otherwise. tt_synth_plan_depth
       reads either. */
    uint8_t *depth8;
    uint16_t *depth16;
    tt_progress_fn progress;        /* copied from the options; tt_synth_apply reports to it */
    void *progress_user_data;
    tt_allocator allocator;         /* the one it was made with */
} tt_synth_plan;

/* Plan the tile set of options->layout (options may be NULL: all defaults)
   from `guide`, whose texels decide the edge windows (when not given) and the
   cuts; the seed decides the rest. Same guide, options and seed: same plan.
   Errors: NULL out_plan or an empty guide (TT_ERROR_INVALID_ARGUMENT), a bad
   allocator, a non-finite guide texel (TT_ERROR_NON_FINITE, error->row /
   column = its y / x), a layout that does not resolve, a guide smaller than S
   x 2S or a background region that cannot hold a tile
   (TT_ERROR_IMAGE_TOO_SMALL), a background region outside the guide, a given
   edge window that does not fit, a feather wider than S/4 + 1
   (TT_ERROR_INVALID_ARGUMENT), TT_ERROR_OUT_OF_MEMORY, TT_CANCELLED by the
   progress callback. *out_plan is NULL on failure and nothing is left
   allocated. Temporary memory, freed before it returns: about 20 * S * S
   bytes (a scratch tile and the cut's cost tables). Time: about that of
   composing every tile once, plus the cuts. */
TTDEF tt_result tt_synth_plan_create(const tt_image *guide, const tt_synth_options *options,
                                     const tt_allocator *allocator, tt_synth_plan **out_plan, tt_error *error);
/* Free a plan (NULL is fine). */
TTDEF void tt_synth_plan_free(tt_synth_plan *plan);

/* The band depth of tile `tile` (tt_tile_index numbering), side 0..3, column
   0..S-1, from whichever depth array the plan holds.
   Preconditions (TT_ASSERT): a plan from tt_synth_plan_create, indices in
   range. */
TTDEF int tt_synth_plan_depth(const tt_synth_plan *plan, int tile, int side, int x);
/* The alpha (0..1) with which the band of `side` covers side-frame texel (x,
   d) of tile `tile`, d = 0..S-1 (see tt_synth_plan above): the mask the
   compositing uses, the same for every image the plan is applied to.
   Preconditions (TT_ASSERT): as tt_synth_plan_depth, 0 <= d < S. */
TTDEF float tt_synth_plan_band_alpha(const tt_synth_plan *plan, int tile, int side, int x, int d);

/* The per-tile step: compose the tile whose sides have types[0..3] (e0..e3,
   each below 2n) from `source` with the plan's windows and masks, and write
   it with its gutters, one C x C cell (C = S + 2g), into `target` with the
   cell's top-left texel at (x, y); the tile itself is the S x S square at
   (x + g, y + g). The tile's background window is the plan's
   background_windows[tt_tile_index(&plan->layout, types)], so the cell is
   bit for bit the one tt_synth_apply puts in the atlas. Texels outside the
   cell are not touched; alpha is 1. `target` is any image of yours (an
   atlas, a one-cell image, a view) that shares no texels with `source`; it
   is the only thing written, and the tile is composed in place there.
   Allocates nothing. The plan and source are only read, so several threads
   may compose with one plan and source at once into cells that do not
   overlap.
   Errors: NULL plan, source, types or target, a target without pixels
   (TT_ERROR_INVALID_ARGUMENT); a source whose size is not the plan's
   (TT_ERROR_INVALID_ARGUMENT); a type of 2n or more
   (TT_ERROR_INDEX_OUT_OF_RANGE, error->item = the side); a cell that does
   not lie inside the target (TT_ERROR_INVALID_ARGUMENT). A non-finite source
   texel that reaches the tile is TT_ERROR_NON_FINITE (error->row / column =
   the source texel's y / x); the cell has been written then. */
TTDEF tt_result tt_synth_compose_tile(const tt_synth_plan *plan, const tt_image *source, const uint8_t types[4],
                                      tt_image *target, int x, int y, tt_error *error);

#define TT_MAX_MIP_LEVELS 16

typedef struct tt_tileset {
    tt_tile_layout layout;          /* resolved */
    /* levels[0] is the atlas (W x W, opaque, straight alpha = 1); level L is built
       per tile by halving each cell, for as long as the cell size stays even.
       Levels 0..seamless_levels-1 (up to log2(g)) keep every edge seamless under
       bilinear filtering. */
    int nlevels;
    int seamless_levels;
    tt_image levels[TT_MAX_MIP_LEVELS];
    tt_rect *edge_windows;          /* colors rects actually used (w = S, h = 2S) */
    tt_rect *vertical_windows;      /* upright tiles: colors rects (w = 2S, h = S) for sides 1 and 3; else NULL */
    tt_rect *background_windows;    /* one per tile, indexed like tt_tile_index */
    tt_allocator allocator;         /* the one it was made with */
} tt_tileset;

/* Apply a plan to `source` (the guide itself, or another map of the same
   size): every tile of the layout into its cell of a W x W atlas (tile
   row 0 of tt_tile_index at the bottom), then the mip chain, as
   tt_synthesize_tiles. The plan is only read: several threads may apply one
   plan at once (each then calls plan->progress, if set); the tileset's
   windows are copies of the plan's. Memory: the
   atlas and its mips, about 4/3 * W * W * 16 bytes, from `allocator`. Free
   the result with tt_tileset_free.
   Errors: NULL plan, source or out (TT_ERROR_INVALID_ARGUMENT), a bad
   allocator, a source whose size is not the plan's source_width x
   source_height (TT_ERROR_INVALID_ARGUMENT), a non-finite source texel
   (TT_ERROR_NON_FINITE, error->row / column = its y / x),
   TT_ERROR_OUT_OF_MEMORY, TT_CANCELLED by plan->progress. *out is NULL on
   failure and nothing is left allocated. */
TTDEF tt_result tt_synth_apply(const tt_synth_plan *plan, const tt_image *source, const tt_allocator *allocator,
                               tt_tileset **out, tt_error *error);

/* Akleman Sec. 4, tile-set synthesis in one call: tt_synth_plan_create from
   `source`, tt_synth_apply to it, tt_synth_plan_free. Every tile ABCD = AXXX
   over XBXX over XXCX over XXXD over XXXX. The band along each side is the
   edge sample for its type, turned to that side; it is cut against what lies
   beneath where the two agree (minimum-error cut) and feathered, and every
   texel of a tile's edge rows except the two corner texels is the edge sample
   alone, exactly. Gutters hold what lies across each edge on the surface.
   Errors: those of tt_synth_plan_create (a source of at least S x 2S texels,
   finite, ...) and tt_synth_apply. To synthesise several maps of one
   material with the same tiles, make the plan once and apply it to each.
   Free with tt_tileset_free. */
TTDEF tt_result tt_synthesize_tiles(const tt_image *source, const tt_synth_options *options,
                                    const tt_allocator *allocator, tt_tileset **out_tileset, tt_error *error);
TTDEF void tt_tileset_free(tt_tileset *tileset);

/* Seam measure across every interior edge (the project's acceptance measure):
   at points along the edge, sample the atlas just inside each of the two faces,
   half a texel from the edge; compare with two samples the same distance apart
   inside one face, and with samples from two unrelated edges. Differences are
   mean absolute differences of bilinear samples of r, g, b as displayed
   (sRGB-encoded, in [0, 1]), so the thresholds mean what the eye sees.
   score = (seam - same_face) / (unrelated - same_face): about 0 when an edge
   looks like any other place in the image, about 1 when tiles do not match.
   When unrelated places differ no more than neighbours do (pure noise at the
   texel scale) the score means nothing and is NaN; read seam - same_face.

   UV-discontinuous edges. An interior edge's UVs are continuous when each of
   its two ends has the same UV seen from both faces: for the half-edge a ->
   a' and its twin b -> b', uv[a] equals uv[b'] and uv[a'] equals uv[b], each
   coordinate within TT_SEAM_UV_TOLERANCE * max(1, |x|, |y|) (1e-6 of the UV
   scale, about 16 float roundings: UVs written once per vertex and copied
   per corner compare equal). Otherwise, or when one of them is not finite,
   the edge is discontinuous. Continuous edges lie inside one chart, where
   the texture is continuous by construction; the discontinuous ones are the
   chart borders (every edge of a tiled-texture mesh, the cluster borders of
   hierarchical pattern mapping). UVs a whole period apart count as
   discontinuous: they are what TT_SEAM_WRAP then measures. */
#define TT_SEAM_UV_TOLERANCE 1e-6
enum {
    /* Measure only the UV-discontinuous interior edges (see above): on a mesh
       of large charts, every edge dilutes the border's score with the many
       edges inside charts, seamless by construction. max_edges then samples
       among these edges. The same-face reference is taken next to the
       measured edges, as always; the unrelated pairs are still drawn from
       every interior edge, because they describe how different two places of
       the texture are, a property of the texture rather than of the borders:
       the reference is then the same in both modes, so restricted and full
       scores compare, and it stays defined with a single border edge. With
       no discontinuous edge the result is TT_ERROR_NOT_MEASURED. */
    TT_SEAM_UV_DISCONTINUOUS = 1u << 0,
    /* Sample the atlas with TT_WRAP_REPEAT: UVs outside [0, 1] on a periodic
       (toroidal) image, as a charting that continues across the image's
       borders produces. Without it samples clamp to the atlas's edge. */
    TT_SEAM_WRAP = 1u << 1
};

typedef struct tt_seam_options {
    uint64_t seed;          /* picks the sample positions, unrelated pairs and sampled edges */
    /* 0: every measured edge (the acceptance measure). Otherwise at most this
       many of them, drawn at random without replacement: an estimate for quick
       reports (with 20000 edges it stays within about 0.01 of the full score). */
    int max_edges;
    unsigned flags;         /* TT_SEAM_*; 0 = every interior edge, clamped sampling */
    /* NULL: every interior edge (with TT_SEAM_UV_DISCONTINUOUS, every
       discontinuous one). Otherwise only the interior edges listed, each named
       by either of its two corners (half-edges); a list naming nothing
       measurable gives TT_ERROR_NOT_MEASURED. Where a lapped texture's paste
       on top changes, for example: that is where a paste can end with a hard
       edge. The same-face and unrelated references are taken as always. */
    const int *edges;
    int nedges;
} tt_seam_options;

typedef struct tt_seam_report {
    double seam;            /* mean difference across edges */
    double same_face;       /* the same distance apart inside one face */
    double unrelated;       /* between unrelated edges */
    double score;           /* NaN when unrelated - same_face <= 1e-9 (see above) */
    int edges_measured;     /* measured edges that gave at least one sample */
    long long samples;
    int edges_discontinuous;/* interior edges with discontinuous UVs (see above), counted in every mode:
                               how many chart borders there are */
} tt_seam_report;

/* Works on any mesh with per-corner UVs (2 * ncorners floats) and any atlas.
   options may be NULL (every edge, seed 0, flags 0). Not measured reads as
   not measured: when no sample could be taken (no interior edge, fewer than
   two, every measured edge of zero length or non-finite UVs, or with
   TT_SEAM_UV_DISCONTINUOUS no discontinuous edge) the result is
   TT_ERROR_NOT_MEASURED and the report is zero with score NaN, except
   edges_discontinuous, which is counted before any sampling. Other errors: NULL pointers or an empty atlas
   (TT_ERROR_INVALID_ARGUMENT), a negative max_edges or nedges, edges NULL with
   nedges > 0, an unknown flag bit (TT_ERROR_INVALID_ARGUMENT); a listed edge
   that is not a corner of the mesh (TT_ERROR_INDEX_OUT_OF_RANGE) or lies on
   the boundary (TT_ERROR_INVALID_ARGUMENT), error->item naming its place in
   the list; TT_ERROR_OUT_OF_MEMORY. */
TTDEF tt_result tt_measure_seams(const tt_mesh *mesh, const float *corner_uv, const tt_image *atlas,
                                 const tt_seam_options *options, const tt_allocator *allocator,
                                 tt_seam_report *report, tt_error *error);

/* counts[t] = number of quads using tile t (tt_tile_layout_tile_count entries).
   Errors: NULL pointers, a layout that does not resolve
   (TT_ERROR_INVALID_ARGUMENT), a face that is not a quad
   (TT_ERROR_NOT_QUAD_MESH, naming it), a type of 2n or more
   (TT_ERROR_INDEX_OUT_OF_RANGE, naming the corner). */
TTDEF tt_result tt_tile_histogram(const tt_mesh *mesh, const tt_tile_layout *layout, const uint8_t *corner_type,
                                  int *counts, tt_error *error);

/* stretch[f] = ratio of the larger to the smaller singular value of face f's
   surface -> texture map (1 = no stretch), taken at the face's centre; faces
   with a degenerate map get INFINITY. nfaces floats. Errors: NULL pointers
   (TT_ERROR_INVALID_ARGUMENT), a non-finite UV (TT_ERROR_NON_FINITE, naming
   the corner). */
TTDEF tt_result tt_face_stretch(const tt_mesh *mesh, const float *corner_uv, float *stretch, tt_error *error);

/* UV distortion of a charting (the acceptance measure of pipelines that map
   into an existing image, such as tt_hpm_map): how far each face's map from
   surface to texture is from a similarity of the intended scale. Texture
   space is measured in texels, (u * width, v * height), so a non-square
   image weighs its axes right. Per face:
     stretch  = sigma_max / sigma_min of the surface -> texture map at the
                face's centre, as tt_face_stretch computes it (1 = no
                stretch; a triangle's map is linear, a quad's the bilinear
                patch's at its centre, another polygon's its first
                triangle's);
     density  = sqrt(UV area in texels^2 / surface area), whole polygons
                (Newell's vector area on the surface, the shoelace in UV);
     density error = |density / texels_per_unit - 1|.
   Statistics are weighted by surface area: the weighted p-th percentile is
   the smallest per-face value v at which the area of the faces with values
   <= v reaches p times the total (the median is p = 0.5, always one face's
   value). */
typedef struct tt_uv_distortion_options {
    double texels_per_unit;     /* intended texels per world unit; 0 = the area-weighted median of the
                                   measured faces' own densities (then density errors say how uniform the
                                   scale is, not whether it is the one intended) */
    double margin_texels;       /* outside_margin counts corners closer than this to the image's border
                                   (or beyond it); 0 = no check */
} tt_uv_distortion_options;

typedef struct tt_uv_distortion_report {
    double stretch_median;      /* area-weighted median of the per-face stretch (1 = none) */
    double stretch_p95;         /* area-weighted 95th percentile of it */
    double stretch_max;         /* the largest over measured faces (unweighted) */
    double density_median;      /* area-weighted median of the relative density error (0 = as intended) */
    double density_p95;         /* area-weighted 95th percentile of it */
    double texels_per_unit;     /* the scale the density errors are relative to: given or measured */
    int faces_measured;         /* faces in the statistics: not degenerate, finite UVs */
    int flipped;                /* measured faces whose UV polygon turns clockwise (negative signed area in
                                   texels, v up) while the face is counter-clockwise on the surface: the
                                   texture is mirrored there. They stay in the statistics */
    int degenerate;             /* faces with zero surface area or zero UV area (numerically zero against
                                   the polygon's own size, as tt_mesh_build judges faces) or a singular
                                   map at the centre; not in the statistics */
    int non_finite;             /* faces with a NaN or infinite UV; not in the statistics */
    int outside_margin;         /* corners with finite UVs within margin_texels of the image's border or
                                   outside [0, 1]; 0 when margin_texels is 0 */
} tt_uv_distortion_report;

/* Measure the UV distortion of per-corner UVs (2 * mesh->ncorners floats)
   into a width x height image; options NULL = all defaults. The report is
   the point: non-finite UVs, degenerate and flipped faces are counted, not
   refused. Temporary memory: 32 bytes a face, through `allocator`. Only
   reads its inputs: safe from several threads.
   Errors: NULL mesh, UVs or report, width or height below 1, a negative or
   non-finite option, a bad allocator (TT_ERROR_INVALID_ARGUMENT);
   TT_ERROR_OUT_OF_MEMORY; no face measurable (TT_ERROR_NOT_MEASURED: the
   counts are filled in, the statistics are NaN). On an argument error the
   report is zero with NaN statistics. */
TTDEF tt_result tt_measure_uv_distortion(const tt_mesh *mesh, const float *corner_uv, int width, int height,
                                         const tt_uv_distortion_options *options, const tt_allocator *allocator,
                                         tt_uv_distortion_report *report, tt_error *error);

/* ======================================================================== */
/* 7. Lapped textures                                                       */
/* ======================================================================== */

/* Based on: Praun, Finkelstein, Hoppe, "Lapped Textures" (SIGGRAPH 2000).
   The steps, for a triangle mesh:
     1. tt_tangent_field: the texture's up and scale per face (Sec. 3.2);
     2. tt_make_texture_patch: the photo with a soft-edged alpha (Sec. 3.1);
     3. tt_lapped_paste: the paste loop, until every face is covered
        (Sec. 3.3-3.6), returning the runtime pasting list (Sec. 4);
     4. tt_lapped_measure, and an atlas (tt_atlas_pack_charts, or
        tt_atlas_pack_pairs; tt_uv_check says whether the mesh's own UVs
        would do) + tt_lapped_bake for an ordinary texture (Sec. 4).
   Memory per photo pixel, besides the photo (16 bytes, yours): the patch
   holds 16 bytes, and making it takes nothing more (its scratch lives in
   the patch's own pixels); the paste loop keeps 4 bytes per patch pixel
   (its opaque depth) and takes up to 5 more while it traces the patch's
   hull. A caller that frees the photo once the patch is made (as the
   tiledtex tool does) peaks at 32 bytes per photo pixel, while the patch is
   made. The bake's scratch is 8 bytes per atlas texel.

   The tangent field, Sec. 3.2 (establishing local orientation and scale).
   Each face f gets a vector T_f in its plane: its direction is the texture's
   "up", its length the texture's local scale (the side of a texture patch in
   mesh units). The "right" direction is S = T x N (Sec. 3.2). Isotropic
   textures need no direction: the patch-growing step picks one per patch
   (Sec. 3.2, last paragraph); give it this field's length only. */

/* options->scale = 0: this fraction of the mesh's bounding-box diagonal. */
#define TT_DEFAULT_FIELD_SCALE 0.1f
/* options->sigma = 0: this fraction of the mesh's bounding-box diagonal. */
#define TT_DEFAULT_FIELD_SIGMA 0.25f

/* The user says "at this face, up is this way and this long" (Sec. 3.2). */
typedef struct tt_field_constraint {
    int face;           /* 0 .. nfaces-1 */
    float vector[3];    /* finite, non-zero; projected on the face's plane, where it must not vanish;
                           its length is the scale there (mesh units) */
    float sigma;        /* extent of this basis function (mesh units); 0 = options->sigma */
    float weight;       /* relative weight of this basis function; 0 = 1 */
} tt_field_constraint;

typedef struct tt_field_options {
    float up[3];        /* global up for the default field; 0,0,0 = (0,1,0); only its direction counts */
    float scale;        /* length of the default field's vectors (mesh units);
                           0 = TT_DEFAULT_FIELD_SCALE * bounding-box diagonal */
    const tt_field_constraint *constraints;     /* nconstraints entries, or NULL when 0 */
    int nconstraints;
    float sigma;        /* default Gaussian extent (mesh units); 0 = TT_DEFAULT_FIELD_SIGMA * diagonal */
} tt_field_options;

/* The tangent field of Sec. 3.2. face_vectors gets 3 * mesh->nfaces floats,
   T_f = face_vectors[3f .. 3f+2], in the plane of face f (|T.N| ~ 1e-7 |T|).
   options may be NULL (all defaults).

   Without constraints (the default field, Sec. 3.2 "project the global up
   direction onto the surface, and then normalize", made smooth): the
   smoothest direction field that follows the projected up P_f(up) = up -
   (up.N_f) N_f (|up| = 1) where up decides the direction, found by least
   squares over the faces with tt_cg_solve. Up decides fully on faces
   tilted 30 degrees or more from facing up (|P_f(up)| >= 0.5), not at all
   within 6 degrees of it (|P_f(up)| <= 0.1), where the paper's rule turns
   the texture at random (a scan's noise, the flat top of a CAD part): there
   the field continues its surroundings smoothly, carried across edges by
   parallel transport, and a region cut off from them by creases (across a
   right angle nothing is carried: a box's walls point up, their vectors
   say nothing of its top) is constant, along the world axis least along up
   (x for the default up). The field is smoothed over the field scale or 8
   mean edge lengths, whichever is less. Measured: on a closed box the walls
   follow up and the top is constant to 0.001 degrees; the mean turn across
   edges (after parallel transport) against the earlier rule (projected up,
   breadth-first from neighbours within 11.5 degrees of facing up): the
   bunny 7.6 to 3.2 degrees, the horse 2.1 to 1.1, a mannequin 4.4 to 2.4,
   the elephant 9.1 to 5.6; a CAD flange 6.2 to 6.2 (its turns are at its
   creases).

   With constraints (Sec. 3.2 "Gaussian radial basis functions, where radius
   is defined as distance over the mesh, as computed using Dijkstra's
   algorithm"): d_i(f) is the shortest path from constraint i's face to f over
   the dual graph, each step centroid -> shared edge's midpoint -> centroid;
   w_i(f) = weight_i * exp(-d_i(f)^2 / (2 sigma_i^2)). c_i is carried to f by
   parallel transport along the Dijkstra tree (rotation about each shared
   edge, so it stays tangent and keeps its length), giving t_i(f). Then
       T_f = (sum_i w_i |c_i| / sum_i w_i) * normalize(sum_i w_i t_i(f)),
   the normalised average direction with the averaged length. Weights are
   normalised, so far from every constraint the nearest one decides (no
   underflow: the sums are kept relative to the largest weight). A face that
   carries constraints gets exactly the average of its own (projected)
   constraint vectors. Faces no constraint reaches (other components) follow
   the default rule with `scale`. If the directions cancel exactly, the
   constraint of largest weight (first on ties) gives the direction.
   Transport along each constraint's own shortest-path tree is exact on
   developable pieces, but on curved closed surfaces paths that go round a
   handle or a bump different ways meet with different holonomy: the field
   can turn sharply along that cut locus, far from the constraint (Sec. 3.3
   calls such places discontinuities of the direction field; add a
   constraint there, or lower sigma, to move them).

   One Dijkstra pass (binary heap) per constraint: O(K F log F) for K
   constraints; the smooth field is one sparse solve of 2 unknowns per face
   (about 0.2 s for 100k faces, -O2). Faces of zero area (TT_MESH_PERMISSIVE meshes
   only) get (0,0,0) and nothing is transported through them.
   Errors: NULL mesh or face_vectors, a zero or non-finite up, negative or
   non-finite scale or sigma, nconstraints < 0 or constraints NULL with
   nconstraints > 0: TT_ERROR_INVALID_ARGUMENT. A constraint on a face out of
   range: TT_ERROR_INDEX_OUT_OF_RANGE (error->face = that index); a zero,
   perpendicular (projects to under 1e-3 of its length) vector or a negative
   sigma or weight: TT_ERROR_INVALID_ARGUMENT; a non-finite one:
   TT_ERROR_NON_FINITE; a constraint on a zero-area face:
   TT_ERROR_ZERO_AREA_FACE. Every constraint error names the constraint in
   error->item (and its face in error->face). Temporary memory only.
   Deterministic; reentrant and thread-safe on distinct outputs. */
TTDEF tt_result tt_tangent_field(const tt_mesh *mesh, const tt_field_options *options,
                                 const tt_allocator *allocator, float *face_vectors, tt_error *error);

/* Texture patches.
   Based on: Praun, Finkelstein, Hoppe, "Lapped Textures" (SIGGRAPH 2000),
   Sec. 3.1 (creating the texture patches: "the texture patch is assigned an
   alpha mask that falls off near the patch boundary (e.g. over a distance of
   3 pixels)"; for homogeneous textures a predefined irregular "splotch"). */

/* options->falloff = 0: this many texels of soft edge (the paper's value). */
#define TT_DEFAULT_PATCH_FALLOFF 3.0f
/* options->roughness = 0: the splotch radius varies by up to this fraction. */
#define TT_DEFAULT_PATCH_ROUGHNESS 0.25f
/* The splotch covers about this fraction of the image (as a binary shape, before
   the soft edge), when the image is large next to the falloff. */
#define TT_PATCH_SPLOTCH_COVERAGE 0.70f

typedef struct tt_patch_options {
    uint64_t seed;          /* picks the splotch's shape; unused when a mask is given */
    float falloff;          /* texels of soft edge; 0 = TT_DEFAULT_PATCH_FALLOFF */
    float roughness;        /* how irregular the splotch boundary is, in [0, 1);
                               0 = TT_DEFAULT_PATCH_ROUGHNESS */
} tt_patch_options;

/* Cut a texture patch from `source` (straight, un-premultiplied RGBA): *patch
   is created with the source's size and holds premultiplied RGBA,
   rgb = source.rgb * alpha, with a soft alpha (free it with tt_image_free).

   The shape, a binary mask (a texel is inside when its value >= 0.5), is the
   first that applies of:
     1. the source's own alpha, when some source alpha is below 1;
     2. `mask` (same size as the source): its alpha channel, or, when every
        mask alpha is 1, its grey value (r + g + b) / 3;
     3. a seeded splotch: a blob centred in the image whose radius, on a
        rounded-square base shape (|x|^4 + |y|^4 = 1), varies with the angle
        theta by 1 + roughness * sum_k c_k cos(k theta + phi_k), k = 2..5,
        with seeded weights c_k (sum 1) and phases; it stays `falloff` texels
        (at least 1) inside the image, and its size is chosen so that it
        covers TT_PATCH_SPLOTCH_COVERAGE of the image (less when the margin
        leaves no room).
   Soft falloff: with d the exact Euclidean distance (separable distance
   transform, Felzenszwalb-Huttenlocher, O(pixels)) from a texel's centre to
   the nearest texel centre outside the shape (everything beyond the image
   counts as outside), alpha = clamp((d - 0.5) / falloff, 0, 1): 0 outside,
   rising over `falloff` texels from the shape's edge (which lies half a texel
   beyond the last inside centre) to 1. So a shape that reaches the image
   border still fades out there.

   Errors (*patch is NULL, memory freed on every path):
     TT_ERROR_INVALID_ARGUMENT  NULL or empty source or patch; a mask of
                                another size (the message gives both sizes);
                                "the mask has no opaque pixel" (no texel >=
                                0.5); a negative falloff, a roughness outside
                                [0, 1), or a falloff so large that no texel
                                gets alpha 1 (the message says how deep the
                                shape is);
     TT_ERROR_NON_FINITE        a NaN or infinite option, source value or
                                mask value (the message names the texel);
     TT_ERROR_TOO_LARGE         a source above TT_MAX_IMAGE_SIZE;
     TT_ERROR_OUT_OF_MEMORY.
   options may be NULL (all defaults, seed 0). Deterministic for a given seed
   on a given platform (the splotch uses cosf/atan2f). */
TTDEF tt_result tt_make_texture_patch(const tt_image *source, const tt_image *mask, const tt_patch_options *options,
                                      const tt_allocator *allocator, tt_image **out_patch, tt_error *error);

/* The paste loop.
   Based on: Praun, Finkelstein, Hoppe, "Lapped Textures" (SIGGRAPH 2000),
   Sec. 3 (overview), 3.3 (growing the surface patch), 3.4 (optimizing its
   parametrization), 3.5 (recording the paste), 3.6 (face coverage) and 4
   (runtime pasting: faces hidden by later pastes are dropped).

   Texture space: each paste maps its faces into the unit square of one texture
   patch, (0,0) bottom-left, (1,1) top-right (OBJ / OpenGL convention), the
   patch's image being 1 x 1. The face vector T_f (from tt_tangent_field) should
   map to the patch's up axis (0,1) and S_f = T_f x N_f to its right axis (1,0):
   |T_f| mesh units at face f are one patch side. Coordinates outside [0,1] are
   meant to be clamped (the patches are transparent at their border).

   The loop, until every face is covered:
     1. pick a face not yet covered at random (seeded) and a point of it not
        yet covered; pick a texture patch at random;
     2. map the seed face so that point lands on the patch's anchor (its
        deepest opaque texel, the "center" for any mask shape) with (S, T)
        along the axes;
     3. grow the surface patch one face at a time, nearest (in texture space)
        first, across an edge only when (a) the face keeps the patch a disc,
        (b) the edge's image meets the patch's conservative polygonal hull
        (Sec. 3.3, Fig. 4), (c) the face's predicted map is not too distorted
        (a looser limit than the solved map's, as the prediction drifts from
        the field: TT_LAPPED_GROW_DISTORTION); each new vertex is placed by similar-
        triangle prediction from every patch face containing it and a mapped
        edge, taking the centroid (Sec. 3.3, after Maillot et al.);
     4. solve the least-squares alignment of Sec. 3.4, sum over the patch's
        faces of |phi(S_f) - (1,0)|^2 + |phi(T_f) - (0,1)|^2, with the seed point
        held on the anchor, by tt_cg_solve warm-started from the prediction
        (s and t decouple: one matrix, two right-hand sides); if the new map
        moved an edge of the patch back over the hull, grow and solve again;
        faces the solved map leaves too distorted (TT_LAPPED_MAX_DISTORTION)
        are dropped from the paste, except the seed face and the fringe:
        faces up to TT_LAPPED_GROW_DISTORTION off where the patch's alpha
        over them stays below one half, kept for the paste's soft border
        (faint there) and covering nothing;
     5. fade the paste where it stops while its patch still shows (a cut:
        an edge to a face left out, whatever the reason): a factor on its
        alpha per vertex, 0 at the cut and rising with the distance from it
        in texture space to 1 within 0.05 patch sides, never on the seed
        face (tt_lapped.fade). The paper accepts such "hard edges" (Sec.
        3.3); faded, a paste ends softly everywhere, and what it fades is
        left for later pastes to cover;
     6. mark coverage (Sec. 3.6): each face carries a fixed set of sample
        points (its own barycentric raster: tt_raster_triangle on a right
        triangle, about 64 points per patch side, at least 4 and at most 256
        a side); a sample is covered when a paste puts it so deep inside the
        patch's opaque part (alpha >= TT_LAPPED_OPAQUE) that every point of
        the face near it, and every texel a bilinear lookup there reads, is
        opaque too - so the gaps between samples are covered as well - and
        the fade there is at least TT_LAPPED_OPAQUE. The seed point itself
        always counts (it sits on the deepest texel, unfaded), so every
        paste makes progress.
   Then, walking the pastes from last to first, a face whose samples are all
   covered by later pastes is removed from the earlier paste (Sec. 4).

   Isotropic mode (Sec. 3.2, last paragraph): the seed face's direction is
   random, and each face added gets the average direction of its neighbours
   already in the patch, projected on its plane; only |T_f| is used.

   Hard edges: where growth stops (a disc would close, or distortion), the
   paste would end at a mesh edge without its soft falloff (Sec. 3.3 finds
   them "less objectionable than distorted texture"); step 5 fades it
   there instead. What stays hard is a cut along the seed face itself (a
   crease or a part thinner than a patch that no paste crosses).
   tt_lapped.visible_cuts counts the cuts left on top: 4 % of the edges
   where the paste on top changes on a sphere, 6 % on the bunny, 11 % on
   the elephant (without the fade: 5 %, 17 % and 49 %). The fade costs
   pastes: faded rims cover nothing, so 1.5 to 2.5 times as many pastes
   are needed on meshes with many cuts. A patch may fold over itself in
   texture space (allowed by the paper); coverage is still counted per
   face, correctly. */

/* Faces whose solved map (Sec. 3.4) turns T_f by more than this many
   degrees, or scales it by more than 1 + this / 90 or less than
   1 / (1 + this / 90), are left out of the paste (a "hard edge", Sec. 3.3),
   unless the patch is already fading out over them (the fringe, below).
   Lower values align better and leave more hard edges. */
#define TT_LAPPED_MAX_DISTORTION 20.0f
/* Growth crosses into a face whose predicted map is up to this far off
   (the same measure), and the fringe shows faces up to this far off where
   the patch's alpha over them stays below one half. The prediction, an
   unfolding, drifts from the field that the solve then follows, so a face
   it puts 20 to 30 degrees off mostly lands within TT_LAPPED_MAX_DISTORTION
   once solved. Before pastes faded at their cuts, growth stopped at
   TT_LAPPED_MAX_DISTORTION left half as many hard edges again (bunny: 260
   against 176 at 45 degrees, of about 1400 edges where the top paste
   changes); with the fade, 30 degrees keeps the baked seams as low as 45
   while the alignment stays closer (elephant: mean angle error 4.3 against
   5.0 degrees); at 60 or 90 degrees more faces drift off in the solve and
   are dropped after it. */
#define TT_LAPPED_GROW_DISTORTION 30.0f
/* A sample counts as covered under an alpha of at least this. */
#define TT_LAPPED_OPAQUE 0.99f
/* tt_lapped.visible_cuts: a paste that stops at an edge with at least this
   alpha there shows a hard edge. */
#define TT_LAPPED_VISIBLE_CUT 0.25f
/* options->max_pastes = 0: this cap (a few minutes of work). */
#define TT_LAPPED_MAX_PASTES 200000
/* Pastes take about this many times the surface area over the patch's
   opaque area (they overlap, and their hulls reach past the opaque part):
   3 to 5 on smooth meshes. tt_lapped_paste refuses up front when the
   estimate exceeds max_pastes, and gives up when the loop runs past 16
   times the estimate (a mesh with parts thinner than a patch, whose pastes
   fade at many cuts, took up to 6 times: the horse's legs). */
#define TT_LAPPED_PASTES_PER_AREA 4.0

typedef struct tt_lapped_options {
    uint64_t seed;              /* random seed: same seed, same result */
    int isotropic;              /* 1: orientation by propagation per paste (only |T_f| counts) */
    int max_pastes;             /* cap on pastes; 0 = TT_LAPPED_MAX_PASTES */
    /* Called after every paste with the fraction of sample points covered
       (never decreasing); non-zero return cancels with TT_CANCELLED. */
    tt_progress_fn progress;
    void *progress_user_data;
} tt_lapped_options;

/* One paste operation (Sec. 3.5 / 4): texture patch `patch` over faces
   lapped->faces[first .. first + nfaces - 1]. */
typedef struct tt_paste {
    int patch;                  /* index into the patches given to tt_lapped_paste */
    int first;                  /* first entry of this paste in lapped->faces / lapped->uv */
    int nfaces;                 /* entries (after hidden faces were removed) */
} tt_paste;

/* Result of tt_lapped_paste, in paste order: draw the pastes in order with
   alpha blending ("over") and the surface is covered. */
typedef struct tt_lapped {
    int npastes;
    tt_paste *pastes;           /* npastes */
    int nentries;               /* face entries over all pastes */
    int *faces;                 /* nentries face indices */
    float *uv;                  /* 6 * nentries: entry e's corners 0, 1, 2 (the face's own corner
                                   order) at uv[6e .. 6e+5], in its patch's texture space */
    float *fade;                /* 3 * nentries: entry e's corners' factors on the patch's alpha at
                                   fade[3e .. 3e+2], linear over the face: 1 inside the paste, 0 where
                                   it had to stop while its patch still showed (a cut). Draw alpha *
                                   fade. NULL (in a tt_lapped made by hand) means 1 everywhere */
    /* Statistics (also available from tt_lapped_measure for any UVs). */
    double coverage;            /* fraction of faces whose samples are all covered: 1 on success */
    double mean_overdraw;       /* nentries / faces: how often a face is drawn */
    int removed_entries;        /* face entries dropped because later pastes hide them */
    double mean_angle_error;    /* degrees, mean over entries of the angle between phi(T_f) and (0,1)
                                   (isotropic: against each paste's propagated direction) */
    double median_scale_error;  /* median over entries of | |phi(T_f)| - 1 | */
    int top_changes;            /* interior edges whose two faces show different pastes on top */
    int visible_cuts;           /* of those, the ones where the upper paste stops while still at least
                                   TT_LAPPED_VISIBLE_CUT opaque along the edge: a hard edge (target 0) */
    tt_allocator allocator;     /* the one it was made with */
} tt_lapped;

/* Cover `mesh` (triangles only) with pastes of the `npatches` texture patches
   (premultiplied RGBA with alpha, e.g. from tt_make_texture_patch; each needs
   at least one texel with alpha >= TT_LAPPED_OPAQUE). face_vectors: 3 per
   face, from tt_tangent_field or your own (in each face's plane; only their
   lengths count when isotropic). options may be NULL (defaults, seed 0).
   With several patches, each paste takes one the faces around its seed
   show least on top (random among equals), so that one part of the photo
   does not land next to itself; patches of one size and alpha (windows of
   one photo under one mask) are interchangeable, and a paste then takes
   the one the pastes it borders show least (on a sphere, half as many
   borders with one patch on both sides as random picks give).
   *out_lapped gets the result (free it with tt_lapped_free), NULL on failure.
   Errors:
     TT_ERROR_INVALID_ARGUMENT  NULL pointers, npatches < 1, a face that is not
                                a triangle (error->face), an empty patch or one
                                with no opaque texel ("texture patch 2 has no
                                opaque texel", error->item = 2), a zero
                                field vector or one
                                perpendicular to its face (error->face), a
                                patch larger than the mesh (|T_f| above the
                                mesh's bounding-box diagonal), a face so many
                                patch sides long that no paste could cover it
                                (error->face; subdivide), max_pastes < 0;
     TT_ERROR_NON_FINITE        a NaN or infinite field vector (error->face)
                                or patch texel;
     TT_ERROR_ZERO_AREA_FACE    a face of zero area (permissive meshes);
     TT_ERROR_TOO_LARGE         the patches are so small next to the mesh that
                                more than max_pastes would be needed (the
                                message gives the estimate, see
                                TT_LAPPED_PASTES_PER_AREA);
     TT_ERROR_NOT_CONVERGED     max_pastes pastes, or 16 times the estimate,
                                did not cover the mesh;
     TT_CANCELLED, TT_ERROR_OUT_OF_MEMORY.
   Deterministic for a seed; time about O(faces * overdraw * CG steps). */
TTDEF tt_result tt_lapped_paste(const tt_mesh *mesh, const float *face_vectors, tt_image *const *patches,
                                int npatches, const tt_lapped_options *options, const tt_allocator *allocator,
                                tt_lapped **out_lapped, tt_error *error);
TTDEF void tt_lapped_free(tt_lapped *lapped);

typedef struct tt_lapped_report {
    double mean_angle_error;    /* degrees: mean over entries of angle(phi(T_f), (0,1)) */
    double median_scale_error;  /* median over entries of | |phi(T_f)| - 1 | */
    double mean_overdraw;       /* nentries / nfaces */
    int uncovered_faces;        /* faces in no paste */
} tt_lapped_report;

/* Measure alignment from the UVs alone: phi(T_f) is T_f pushed through each
   entry's linear map (the UVs of its three corners). An independent check of
   the statistics tt_lapped_paste reports (anisotropic mode), or of UVs from
   anywhere. phi(T_f) = 0 (a degenerate face or UV triangle) counts as the
   worst case, 180 degrees and scale error 1; no entries give 0 errors.
   Errors: NULL pointers, a mesh of non-triangles (error->face) or
   inconsistent counts: TT_ERROR_INVALID_ARGUMENT; an entry's face out of
   range: TT_ERROR_INDEX_OUT_OF_RANGE; a non-finite UV or field vector of an
   entry: TT_ERROR_NON_FINITE; each naming the entry in error->item and its
   face; TT_ERROR_OUT_OF_MEMORY. */
TTDEF tt_result tt_lapped_measure(const tt_mesh *mesh, const float *face_vectors, const tt_lapped *lapped,
                                  const tt_allocator *allocator, tt_lapped_report *report, tt_error *error);

/* A simple atlas for meshes without UVs (Sec. 4 "rendering with a texture
   atlas"; the paper's charts were arranged by hand, this is automatic):
   triangles in pairs, each pair in one square cell of a grid over a size x
   size texture, one triangle in each half of the cell, `gutter` texels apart
   from each other and from the cell border. corner_uv gets 2 floats per
   corner (origin bottom-left). The corner with the largest angle takes the
   right angle and the winding is kept (nothing is mirrored). Errors:
   non-triangles, size outside [1, TT_MAX_IMAGE_SIZE] or gutter < 0
   (TT_ERROR_INVALID_ARGUMENT); cells smaller than ceil((2 + sqrt 2) *
   gutter) + 4 texels, the least that keeps both triangles' gutters apart
   (TT_ERROR_IMAGE_TOO_SMALL; the message gives the smallest size that
   works). */
TTDEF tt_result tt_atlas_pack_pairs(const tt_mesh *mesh, int size, int gutter, float *corner_uv, tt_error *error);

/* An atlas of charts (Sec. 4 "rendering with a texture atlas", made
   automatically): far fewer seams and one texel density, where the pair
   atlas above gives every triangle the same texel area whatever its size.
   Charts come from the mesh alone (so an atlas that cannot fit is known
   before anything is pasted): each grows breadth-first from the lowest
   unplaced face across edges, taking a face when its normal lies within
   TT_ATLAS_CHART_CONE degrees of the seed face's and its image, projected
   on the plane perpendicular to the seed's normal, overlaps none of the
   chart's faces already taken (tested in a hashed grid); a face refused
   starts or joins a later chart. Within the cone every face keeps its
   winding (no flips), and the projection shrinks a face's area by at most
   cos(cone), so density varies by at most sqrt(1 / cos(cone)) across a
   chart, less after each chart is scaled to keep its total area. Each
   chart is turned to its smallest bounding box (16 angles tried), laid
   with its long side across, and the boxes, `gutter` texels of margin on
   every side (2 * gutter between charts), are packed in shelves by
   decreasing height; the largest scale that fits size x size is found by
   bisection. Faces of zero area (permissive meshes) join a neighbouring
   chart. */

/* Degrees: the normals of a chart's faces stay within this of its seed face's normal. */
#define TT_ATLAS_CHART_CONE 40.0

typedef struct tt_chart_atlas_report {
    int ncharts;
    double texels_per_unit;     /* atlas texels per mesh unit of length, the same on every chart */
    double fill;                /* fraction of the atlas the triangles cover */
} tt_chart_atlas_report;

/* corner_uv gets 2 floats per corner (mesh->ncorners * 2, origin
   bottom-left), report (may be NULL) the charts made. The texels within
   `gutter` of a chart's triangles belong to no other chart (what
   tt_lapped_bake with that gutter fills). Errors: NULL mesh or corner_uv,
   non-triangles (error->face), size outside [1, TT_MAX_IMAGE_SIZE], gutter
   < 0, a half-set allocator (TT_ERROR_INVALID_ARGUMENT); charts that do
   not fit even when shrunk to nothing - each needs 2 * gutter + 1 texels a
   side (TT_ERROR_IMAGE_TOO_SMALL; the message gives the smallest size that
   holds them); TT_ERROR_OUT_OF_MEMORY. corner_uv is written only on
   success. Temporary memory only: about 200 bytes per face. Time O(faces)
   for the charts (with the faces of a chart in a bounded number of grid
   cells each) and O(charts log charts) for the packing. Deterministic;
   reentrant and thread-safe on distinct outputs. */
TTDEF tt_result tt_atlas_pack_charts(const tt_mesh *mesh, int size, int gutter, const tt_allocator *allocator,
                                     float *corner_uv, tt_chart_atlas_report *report, tt_error *error);

/* What tt_uv_check finds first, in this order of kinds (each the lowest face). */
typedef enum tt_uv_problem {
    TT_UV_USABLE = 0,       /* none: every triangle has its own part of [0, 1]^2 */
    TT_UV_NON_FINITE,       /* face: a corner's UV is NaN or infinite */
    TT_UV_OUTSIDE,          /* face: a corner's UV lies outside [0, 1] */
    TT_UV_DEGENERATE,       /* face: its UV triangle has zero area */
    TT_UV_FLIPPED,          /* face: its UV triangle turns the other way from most of them */
    TT_UV_OVERLAP           /* face and other_face: their UV triangles overlap */
} tt_uv_problem;

typedef struct tt_uv_report {
    tt_uv_problem problem;
    int face, other_face;   /* where; -1 when unused */
    int flipped_faces;      /* how many turn the other way from most (0 unless problem >= TT_UV_FLIPPED) */
} tt_uv_report;

/* Can texture coordinates (2 per corner, e.g. an OBJ's) take a bake, each
   texel belonging to one triangle? They must be finite, inside [0, 1],
   every triangle of non-zero area turning the same way, and no two
   triangles overlapping by more than 1e-6 (a 250th of a texel at 4096:
   triangles sharing an edge or touching do not count). The problems found
   are the answer, in *report (the first kind of the list that occurs, at
   its lowest face; an overlap names the pair found first), not errors:
   the result is TT_OK whenever the check ran. Overlaps are found in a
   hashed grid of about one cell per triangle, each triangle tested
   against those sharing a cell with it: O(faces) for ordinary layouts.
   Errors: NULL mesh, corner_uv or report, non-triangles (error->face), a
   half-set allocator (TT_ERROR_INVALID_ARGUMENT); TT_ERROR_OUT_OF_MEMORY.
   Temporary memory only; reentrant and thread-safe. */
TTDEF tt_result tt_uv_check(const tt_mesh *mesh, const float *corner_uv, const tt_allocator *allocator,
                            tt_uv_report *report, tt_error *error);

typedef struct tt_bake_options {
    int gutter;             /* texels past each triangle's image filled by extrapolating its
                               composite across its edges; 0 = none (the nearest-texel fill
                               still covers the rest); the tool uses 2 */
    /* Called before each face with the fraction of faces done (never
       decreasing), and with 1 when all are baked; non-zero return cancels
       with TT_CANCELLED. */
    tt_progress_fn progress;
    void *progress_user_data;
} tt_bake_options;

/* Bake the pastes into `atlas` (yours: its size is the resolution; a view is
   fine) over the texture coordinates corner_uv (2 floats per corner, origin
   bottom-left: the mesh's own, or from tt_atlas_pack_pairs). Every texel
   whose centre lies in a triangle's image (tt_raster_triangle) gets the
   pastes of that face composited in paste order ("over" of the
   premultiplied patches, each sampled bilinearly with clamping at the UVs
   interpolated from the entry's corners, times the entry's fade when
   lapped->fade is given). Texels within `gutter` texels
   outside a triangle get the same composite extrapolated across its edges
   (the face's maps extended linearly), and every texel still empty is then
   filled from the nearest filled texel, so bilinear filtering and mipmaps
   near chart borders read chart colours, not background. The atlas holds
   straight (un-premultiplied) RGBA, alpha the composited coverage (1 where
   the pastes cover the face). Where two triangles' images overlap, the
   later face wins. Work: proportional to the texels the triangles and
   their gutters cover plus one pass over the atlas. options may be NULL
   (no gutter). Errors: NULL pointers, an empty atlas, non-triangles,
   npatches < 1, a negative gutter (TT_ERROR_INVALID_ARGUMENT); an entry
   naming a patch or face out of range (TT_ERROR_INDEX_OUT_OF_RANGE,
   error->item names the paste or entry); non-finite corner_uv
   (TT_ERROR_NON_FINITE); TT_CANCELLED; TT_ERROR_OUT_OF_MEMORY (all scratch
   is allocated before the atlas is touched). */
TTDEF tt_result tt_lapped_bake(const tt_mesh *mesh, const tt_lapped *lapped, tt_image *const *patches,
                               int npatches, const float *corner_uv, const tt_bake_options *options,
                               const tt_allocator *allocator, tt_image *atlas, tt_error *error);

/* ======================================================================== */
/* 8. Hierarchical pattern mapping                                          */
/* ======================================================================== */

/* Based on: Soler, Cani, Angelidis, "Hierarchical Pattern Mapping"
   (SIGGRAPH 2002). The steps, for a triangle mesh:
     1. tt_cluster_hierarchy_build: the face-cluster hierarchy, from whole
        components down to single faces, with control vertices (Sec. 2.1,
        3.1) - this block;
     2. flattening of a cluster over its control polygon (Sec. 3.2);
     3. fitting: the band of textured neighbours matched against the image
        by FFT over several orientations (Sec. 4.1-4.2);
     4. the coarse-to-fine traversal with one priority queue per level
        (Sec. 2.2);
     5. texture coordinates, crack removal and relaxation (Sec. 4.3-4.4).

   The face-cluster hierarchy (Sec. 3.1). Level 0 holds one cluster per
   connected component. A cluster of more than one face is split into n
   children, n = max(2, round(area / (component area / branching^(level+1))))
   (at most its face count): n seed faces by farthest-point sampling (the
   first drawn from the seeded RNG) and a geodesic Voronoi partition of the
   parent, a multi-source Dijkstra over the faces of the parent with the
   step centroid -> shared edge's midpoint -> centroid; then one Lloyd-like
   round moves each seed to its cell's centre (the face farthest from the
   cell's border) and partitions again, which halves the spread of sizes
   (largest / smallest cluster of a level: 4.3 instead of 9.4 on the tests'
   meshes). A child is a disc
   when its faces are edge-connected, its border is one loop that meets no
   vertex twice, and V - E + F = 1 over its faces. When a child is not a
   disc the parent is split again with n + 1 seeds, at most TT_CLUSTER_RESEEDS
   times; the split with the fewest non-disc children is kept (the first of
   equals), its non-disc children flagged and still split further. Single
   faces are discs and are not split: the tree ends there. Border
   regularisation and the non-alignment test of the spec (D14) are not done.

   What holds per level. Levels are depths in the tree (a cluster's children
   are at its level + 1). The *regions* of level l are its clusters plus the
   leaves (single faces) of levels above l, carried down unchanged. The
   regions of every level partition the mesh's faces; the clusters of level
   l alone partition the faces not in a shallower leaf. A cluster's children
   partition its faces. Every face's deepest cluster is a leaf holding just
   that face (hierarchy->face_leaf).

   Control vertices (Sec. 3.1, spec D12). A vertex of a cluster's border is
   a control vertex when the faces around it belong to at least 3 regions
   of the cluster's level, a mesh boundary counting as one more region
   ("outside"). A border loop with fewer than 3 (4 when the loop has at least
   TT_CLUSTER_LONG_LOOP vertices) gets extra ones: with none, at equal
   arc-length fractions from the loop's first vertex; otherwise one at a
   time, at the loop vertex nearest the middle of the longest arc between
   control vertices. A single face's control vertices are its corners. The
   top cluster of a closed component has no border and no control vertex.

   Memory: fewer than 2 * faces clusters (each split makes at least 2
   children and the leaves are the faces); the face array holds at most
   mesh->nfaces entries per level and the control and neighbour arrays at
   most 3 * faces per level, so O(faces * levels) in all (horse, 97k faces:
   11 levels, 0.93M face entries). Scratch while building: 140 bytes per
   face, 29 per corner, 10 per vertex. Time: O(F log F) per level, each
   split costing about four Dijkstra passes over its parent, more where a
   split is retried (horse: 0.5 s; 26k faces: 0.08 s, at -O2). */

/* Re-splits of a parent with a non-disc child (spec D13). */
#define TT_CLUSTER_RESEEDS 3
/* A border loop of at least this many vertices gets at least 4 control
   vertices, a shorter one at least 3. */
#define TT_CLUSTER_LONG_LOOP 12
/* options->branching = 0: this many children per split on average. */
#define TT_DEFAULT_CLUSTER_BRANCHING 4

enum {
    TT_CLUSTER_DISC = 1u << 0,      /* connected, one simple border loop, V - E + F = 1 */
    TT_CLUSTER_MAPPABLE = 1u << 1   /* a disc with at least 3 control vertices: may be flattened */
};

typedef struct tt_cluster_options {
    uint64_t seed;      /* seeds the RNG that draws each split's first seed (any value, 0 included) */
    int branching;      /* average children per split: each level's target cluster area is the
                           level above's divided by this; 0 = TT_DEFAULT_CLUSTER_BRANCHING; 2..64 */
} tt_cluster_options;

typedef struct tt_cluster {
    int level;              /* depth in the tree: 0 = a whole connected component */
    int parent;             /* cluster index, -1 at level 0 */
    int first_child;        /* children are clusters first_child .. first_child + nchildren - 1, */
    int nchildren;          /*   all at level + 1; 0 for a leaf (a single face) */
    int first_face;         /* faces are hierarchy->faces[first_face .. first_face + nfaces - 1], */
    int nfaces;             /*   ascending within the cluster */
    int first_control;      /* control vertices are hierarchy->control[first_control .. + ncontrol - 1]: */
    int ncontrol;           /*   mesh vertex indices, loop after loop, each loop in border order
                               (counter-clockwise seen from outside: the direction of the cluster's
                               own half-edges on its border), starting at the control vertex met
                               first from the loop's smallest border half-edge */
    int nloops;             /* border loops: 1 for a disc, 0 for a closed component */
    int first_neighbour;    /* neighbours are hierarchy->neighbours[first_neighbour .. + nneighbours - 1]: */
    int nneighbours;        /*   the regions of this level sharing an edge with it, ascending cluster
                               indices (same-level clusters, or shallower leaves carried down) */
    int component;          /* connected component, numbered as tt_mesh_components numbers them */
    unsigned flags;         /* TT_CLUSTER_DISC, TT_CLUSTER_MAPPABLE */
    double area;            /* sum of its faces' areas (mesh units squared) */
} tt_cluster;

/* The hierarchy as flat arrays. Clusters are numbered level by level, so
   level l's clusters are level_start[l] .. level_start[l + 1] - 1, and each
   cluster's children follow one another in the order of their parents. */
typedef struct tt_cluster_hierarchy {
    int nclusters;
    tt_cluster *clusters;       /* nclusters */
    int nlevels;                /* depth + 1: levels 0 .. nlevels - 1 */
    int *level_start;           /* nlevels + 1 */
    int nface_entries;
    int *faces;                 /* nface_entries: each cluster's faces, contiguous */
    int ncontrol;
    int *control;               /* ncontrol vertex indices: each cluster's control vertices */
    int nneighbour_entries;
    int *neighbours;            /* nneighbour_entries cluster indices: each cluster's neighbours */
    int nfaces;                 /* the mesh's face count */
    int *face_leaf;             /* nfaces: the leaf (single-face cluster) of each face */
    int ncomponents;            /* level 0's cluster count */
    tt_allocator allocator;     /* the one it was built with */
} tt_cluster_hierarchy;

/* Build the face-cluster hierarchy of `mesh` (triangles only). options may
   be NULL (defaults, seed 0). The same mesh, options and seed give the same
   hierarchy. *out gets it (free it with tt_cluster_hierarchy_free), NULL on
   failure. Errors: NULL mesh or out, a bad allocator, a face that is not a
   triangle (error->face), branching outside 2..64 (TT_ERROR_INVALID_ARGUMENT);
   no faces (TT_ERROR_EMPTY_MESH); TT_ERROR_OUT_OF_MEMORY. */
TTDEF tt_result tt_cluster_hierarchy_build(const tt_mesh *mesh, const tt_cluster_options *options,
                                           const tt_allocator *allocator, tt_cluster_hierarchy **out,
                                           tt_error *error);
TTDEF void tt_cluster_hierarchy_free(tt_cluster_hierarchy *hierarchy);

/* ---- Flattening (Sec. 3.2; spec D9, D10, D18) ----

   tt_flatten_cluster maps one mappable cluster (a disc with at least 3
   control vertices) into the plane, in world units (a flat cluster keeps
   its lengths), as one continuous map:
     1. The control polygon (D10): the 3D control vertices projected onto
        their least-squares (PCA) plane, whose normal is turned to the side
        of the cluster's area-weighted normal, then TT_FLATTEN_POLYGON_PASSES
        Gauss-Seidel passes of edge-length projection (each edge moved
        towards its 3D chord length). A planar polygon is unchanged. The
        polygon must be simple and counter-clockwise, or the cluster is not
        flat.
     2. The border (options->border). TT_FLATTEN_BORDER_PROJECTED (default):
        the border vertices between control vertices i and i + 1 are
        projected onto the same plane and carried by the similarity that
        takes the projected chord to polygon edge i - so a planar cluster
        maps isometrically whatever the shape of its border, and the border
        of a spherical cap keeps its circle (E_flat = tan^2(alpha/2) for any
        number of control vertices); the mapped border must then be a simple
        loop. TT_FLATTEN_BORDER_CHORD: placed on polygon edge i at their
        fraction of the 3D arc length (the spec's D18 wording; a flat
        cluster with a bent border is then distorted).
     3. The interior: the harmonic map with cotangent weights, each clamped
        to at least 1e-3 times the mean |weight| (symmetric positive
        definite, positive weights), solved for u and v by tt_cg_solve
        starting from the border's centroid.
     4. The measures (D9): r = surface area / sum of the mapped triangles'
        signed areas, flattening error E_flat = |r - 1| (infinite when the
        mapped sum is not positive); a triangle with a signed area <= 0 is
        flipped; per triangle stretch = sigma1 / sigma2 of its Jacobian.
   Accepted when the polygon and border are simple, no triangle is flipped,
   E_flat <= max_error and (if asked) the area-weighted 95th percentile
   stretch <= max_stretch.

   Memory: O(n) for a cluster of n faces (about 650 bytes per face at
   most, with the triplets, the sparse matrix and the CG scratch), nothing
   proportional to the whole mesh, so flattening every cluster costs
   O(faces * levels) in all. Time: O(n log n) plus the two CG solves (about
   sqrt(n) steps of O(n) each for a disc), plus an O(k^2) polygon test for
   k control vertices and, in the projected border mode, an O(b^2) border
   test for b border vertices. Every mappable
   cluster of every level, at -O2: bunny (3.7k faces) 15 ms; horse (97k
   faces) 1.0 s, 0.45 s of it for level 1's four 24k-face clusters.

   What it accepts at the default 0.10 (projected border): bunny levels 1-6
   0 %, 5 %, 66 %, 86 %, 97 %, 98 % of the mappable clusters; horse levels
   1-9 0 %, 7 %, 44 %, 68 %, 88 %, 98 %, 99.3 %, 99.8 %, 97 %. The chord
   border accepts far fewer (bunny level 4: 19 % against 86 %), mostly
   because triangles whose corners all lie on one straight polygon edge
   lose their area and count as folds. */

/* options->max_error = 0: E_flat above this refuses the cluster (D9: a
   spherical cap of half-angle up to about 35 degrees maps in one piece). */
#define TT_DEFAULT_FLATTEN_MAX_ERROR 0.10
/* Edge-length projection passes over the control polygon (D10). */
#define TT_FLATTEN_POLYGON_PASSES 8
/* options->cg_tolerance = 0: relative residual of the harmonic solves. */
#define TT_DEFAULT_FLATTEN_CG_TOLERANCE 1e-10

enum {
    TT_FLATTEN_BORDER_PROJECTED = 0,    /* border vertices projected, fitted to the polygon edges (default) */
    TT_FLATTEN_BORDER_CHORD = 1         /* border vertices on the polygon edges, by 3D arc length */
};

typedef struct tt_flatten_options {
    double max_error;       /* the largest accepted E_flat = |r - 1|; 0 = TT_DEFAULT_FLATTEN_MAX_ERROR;
                               positive, +infinity for no limit */
    double max_stretch;     /* the largest accepted area-weighted 95th percentile of the per-triangle
                               stretch sigma1 / sigma2; 0 = no shear check (the spec suggests 2); >= 1 */
    int border;             /* TT_FLATTEN_BORDER_PROJECTED (0) or TT_FLATTEN_BORDER_CHORD */
    double cg_tolerance;    /* 0 = TT_DEFAULT_FLATTEN_CG_TOLERANCE; in (0, 1) */
    int cg_max_iterations;  /* 0 = tt_cg_solve's default, max(2 n, 100); >= 0 */
} tt_flatten_options;

typedef struct tt_flatten_report {
    int mapped;             /* 1 when a map was computed (the fields below then hold), else 0 */
    int polygon_simple;     /* 1 when the control polygon (and, projected, the border) is simple and CCW */
    double r;               /* surface area / mapped signed area (+infinity if that is <= 0) */
    double flattening_error;/* |r - 1| */
    int flipped;            /* triangles whose mapped signed area is <= 0 */
    double max_stretch;     /* largest sigma1 / sigma2 over the triangles (+infinity for a degenerate one) */
    double stretch_p95;     /* area-weighted 95th percentile of sigma1 / sigma2 */
    double surface_area;    /* the cluster's area, world units squared */
    double mapped_area;     /* sum of the mapped triangles' signed areas */
    int nborder, ninterior; /* border and interior vertices */
    int cg_iterations;      /* the two solves' CG steps together */
} tt_flatten_report;

/* Flatten cluster `cluster` of `hierarchy` (built from `mesh`). corner_uv
   has 2 * mesh->ncorners floats: on TT_OK the corners of the cluster's
   faces get their (u, v) in world units (the plane's own frame: the PCA
   plane of the control polygon, seen from the normal side), every other
   corner is untouched; on any error corner_uv is untouched. options may be
   NULL (defaults), report may be NULL. The same inputs give the same bits.
   Results:
     TT_OK                      mapped and accepted;
     TT_ERROR_NOT_FLAT          the polygon or mapped border is not simple
                                or not counter-clockwise (report->mapped =
                                0, polygon_simple = 0), or the map has a
                                flipped triangle (error->face names the
                                first), or E_flat > max_error, or the
                                stretch percentile > max_stretch: split it;
     TT_ERROR_INVALID_ARGUMENT  NULL mesh, hierarchy or corner_uv, a bad
                                allocator, options out of range, a
                                hierarchy built from another mesh (face
                                counts differ), or a cluster that is not
                                TT_CLUSTER_MAPPABLE (not a disc, fewer
                                than 3 control vertices, or the closed top
                                of a component; error->item = cluster), or
                                whose border does not match its control
                                vertices (a hand-made hierarchy);
     TT_ERROR_INDEX_OUT_OF_RANGE  cluster outside 0 .. nclusters - 1
                                (error->item);
     TT_ERROR_NOT_CONVERGED     (and the other tt_cg_solve errors) the
                                harmonic solve failed;
     TT_ERROR_OUT_OF_MEMORY.
   report is zeroed first and filled as far as the work got: with mapped =
   1 for TT_OK and for every TT_ERROR_NOT_FLAT after the solve, so a
   traversal can read E_flat and decide to split. */
TTDEF tt_result tt_flatten_cluster(const tt_mesh *mesh, const tt_cluster_hierarchy *hierarchy, int cluster,
                                   const tt_flatten_options *options, const tt_allocator *allocator,
                                   float *corner_uv, tt_flatten_report *report, tt_error *error);

/* ---- The pipeline: tt_hpm_map (Sec. 2.2, 4; spec D2-D8, D15-D17, D22-D33) ----

   tt_hpm_map textures a triangle mesh with texture coordinates into the
   original image: no new texture is made. Coarse to fine, each cluster of
   the hierarchy is flattened (above) and placed on the image where its
   content best continues the already textured neighbours:
     1. The matching copy of the image (D3, D30): r, g, b as displayed
        (sRGB-encoded) turned into Y, Cb, Cr - a Euclidean colour space, so
        squared differences add up; one channel (Y) for a grey image - and
        box-filtered by 2^k until its larger side is at most match_size.
        Copies of it turned by 2 pi i / rotations, those within max_turn of
        no turn, are laid out on a P x P grid (P a power of two holding a
        turned copy, or for a toroidal image two periods of it) and their
        spectra cached once (tt_xcorr_texture): this is the memory of the
        method, copies * (channels + 1) * P * (P / 2 + 1) * 16 bytes (5
        copies, 3 channels, P = 256: 10 MB; all 19: 40 MB).
        Why max_turn: the paper tries all 19 orientations and lets the
        orientation "propagate from the first texture patch" (Sec. 2.2)
        through the fit alone; with a band a few texels wide, a brick or a
        plank turned by 60 or 120 degrees often matches about as well, and
        the pattern's direction then wanders from patch to patch. Copy 0 is
        the main neighbour's orientation (step 2), so limiting the turn
        keeps the direction coherent and makes each fit 2 to 4 times
        cheaper; max_turn 180 restores the paper's search.
     2. The band (Sec. 4.1, D15, D16): the textured faces near the cluster
        C are drawn into C's flattened frame, each textured neighbour N
        through the rigid map that best takes N's texture coordinates of the
        vertices it shares with C onto C's flattened positions (a 2D
        Procrustes fit), with the colours of the image at N's coordinates,
        so the mask holds a rigid copy of what N shows; only pixels outside
        C within `band` texels of it are kept. C's frame is first turned by
        a random angle (D8), so that the exact continuation of a single
        neighbour is not the answer unless asked for.
     3. The fit (Sec. 4.2, D1, D5-D7, D27, D33): one masked correlation of
        the band against every turned copy (tt_xcorr_masked_best), offsets
        restricted so that C's footprint and its band stay inside a bounded
        image with a margin of one texel (D6; for a toroidal image, inside
        the copy's grid). The best offset is refined at full resolution by a
        direct sum over +-2^k texels. Its normalised error (D4)
            eps = (sum of squared differences) / (channels * band pixels) / (2 sigma^2)
        with sigma^2 the image's mean per-channel variance: 0 for a perfect
        continuation, about 1 for unrelated pixels.
     4. The traversal (Sec. 2.2, D22, D23): one priority queue per level,
        the cluster with most textured neighbouring regions first (then the
        larger share of textured border, then the smaller index). A cluster
        is split (its children queued at the next level) when it is not a
        disc, not flat enough, has no room in a bounded image, or fits worse
        than `threshold` - unless its children would be smaller than the
        floor (min_footprint texels^2 or min_faces faces), where the best
        fit is taken whatever its error. A cluster smaller than the floor
        (reached only below a cluster that could not be flattened) is not
        fitted: it continues the map of the neighbour it shares most
        vertices with. A cluster with no textured neighbour waits until
        nothing else can be done; then it starts a new textured region at
        a random place (the first cluster, each further component, regions
        the queues never reached).
     5. Texture coordinates (Sec. 4.3, D17, D19-D21): per corner, a
        similarity of the cluster's flattened map - continuous inside a
        cluster, never wrapped per vertex; for a toroidal image each cluster
        is moved by whole periods so its centre lies in [0, 1)^2, the rest
        continues outside (sample with REPEAT). For a bounded image every
        UV lies at least one texel inside the image.
     6. The borders (Sec. 4.4, D17, D25), after each placement: the cracks
        against the matched band closed, the border vertices of the cluster
        and of its neighbours relaxed to lower the colour difference across
        the border, the interior re-solved. After the traversal, faces on a
        border may change sides where that lowers the mismatch (the border
        choice). TT_HPM_NO_RELAXATION leaves all of this out.
   The same mesh, image, options and seed give the same bits. */

#define TT_DEFAULT_HPM_THRESHOLD 0.35   /* eps above which a fit splits the cluster (D4) */
#define TT_DEFAULT_HPM_ROTATIONS 19     /* orientations around the circle: the paper's (Sec. 4.2) */
#define TT_DEFAULT_HPM_MAX_TURN 40.0    /* degrees a patch may turn from its main neighbour: 5 of the 19 */
#define TT_DEFAULT_HPM_MATCH_SIZE 128   /* larger side of the matching copy of the image (D30) */
#define TT_DEFAULT_HPM_MIN_FACES 16     /* the floor in faces (D23) */
#define TT_DEFAULT_HPM_MIN_FOOTPRINT 576.0  /* the floor in texels^2: a patch 24 texels across */
#define TT_HPM_MAX_LEVELS 32            /* levels the report counts one by one (deeper ones go to the last) */

enum {
    TT_HPM_TOROIDAL = 1u << 0,          /* the image tiles: offsets wrap, UVs may leave [0, 1] */
    TT_HPM_RANDOM_PLACEMENT = 1u << 1,  /* the control: the same traversal and decisions, but every
                                           cluster is output at a random place and orientation */
    TT_HPM_NO_RANDOM_TURN = 1u << 2,    /* no random turn of the frame before a fit (D8) and
                                           starts at angle 0: a neighbour's exact continuation
                                           can then be found (tests) */
    TT_HPM_NO_RELAXATION = 1u << 3      /* no work on the borders after each placement: neither
                                           the crack closing (D17), the relaxation (Sec. 4.4)
                                           nor the interior re-solve (D25): the fits alone */
};

typedef struct tt_hpm_options {
    uint64_t seed;          /* hierarchy seeds, random turns and starts (any value, 0 included) */
    double scale;           /* world units covered by the image's width (D26); 0 = the bounding box's
                               diagonal / 4 */
    double threshold;       /* the largest accepted eps; 0 = TT_DEFAULT_HPM_THRESHOLD; +infinity
                               accepts every fit (clusters split only when not flat or with no room) */
    int rotations;          /* orientations around the circle, 1..64 (steps of 360 / rotations
                               degrees); 0 = TT_DEFAULT_HPM_ROTATIONS */
    double max_turn;        /* degrees, 0..180: a fit tries only the orientations within this turn of
                               the main textured neighbour's; 0 = TT_DEFAULT_HPM_MAX_TURN; 180 = every
                               one (the paper) */
    double band;            /* band width in image texels; 0 = per cluster clamp(0.2 * r, 3, 24), r the
                               radius of a disc of the cluster's area (D15) */
    int match_size;         /* 0 = TT_DEFAULT_HPM_MATCH_SIZE; a power of two from 16 to 512 */
    double min_footprint;   /* the floor in texels^2; 0 = TT_DEFAULT_HPM_MIN_FOOTPRINT */
    int min_faces;          /* the floor in faces; 0 = TT_DEFAULT_HPM_MIN_FACES */
    unsigned flags;         /* TT_HPM_* */
    int branching;          /* the hierarchy's (tt_cluster_options); 0 = its default */
    double max_flattening_error; /* tt_flatten_options.max_error; 0 = its default (0.10) */
    tt_progress_fn progress;     /* fraction of faces textured; may cancel */
    void *progress_user_data;
} tt_hpm_options;

typedef struct tt_hpm_report {
    int levels;                             /* the hierarchy's */
    int clusters;                           /* clusters textured */
    int mapped_per_level[TT_HPM_MAX_LEVELS];/* clusters textured at each level */
    int fits_per_level[TT_HPM_MAX_LEVELS];  /* fits run at each level */
    int accepted_per_level[TT_HPM_MAX_LEVELS]; /* of those, accepted under the threshold */
    int fits;                               /* fits that found a place: accepted + floor + rejected
                                               (each a masked correlation over every copy) */
    int copies;                             /* turned copies of the image each fit tries */
    int accepted_fits;                      /* fits at or below the threshold */
    int floor_fits;                         /* fits above it, accepted at the floor */
    int rejected_fits;                      /* fits above it: the cluster was split */
    int continued;                          /* small clusters continuing a neighbour's map (no fit) */
    int faces_moved;                        /* faces that changed sides in the border choice */
    int starts;                             /* clusters placed at random (no textured neighbour) */
    int not_flat;                           /* clusters split because they did not flatten */
    int no_room;                            /* clusters split because they did not fit in the image */
    double mean_error, max_error;           /* eps over the accepted fits (floor ones included) */
    double texels_per_unit;                 /* the texel density: image width / scale */
    int match_width, match_height;          /* the matching copy's size */
    int fft_size;                           /* P */
} tt_hpm_report;

/* Texture `mesh` (triangles) from `image` (linear RGBA; alpha ignored).
   corner_uv gets 2 * mesh->ncorners floats, (u, v) per corner in the
   library's UV convention; face_cluster (may be NULL) gets, per face, the
   hierarchy cluster whose map it shows (the numbering of
   tt_cluster_hierarchy_build with the same seed and branching). options and
   report may be NULL. Results:
     TT_OK;
     TT_ERROR_INVALID_ARGUMENT  NULL mesh, image or corner_uv, a bad
                                allocator, options out of range, a face
                                that is not a triangle (error->face);
     TT_ERROR_EMPTY_MESH        no faces;
     TT_ERROR_ZERO_AREA_FACE    every face has zero area (no scale);
     TT_ERROR_NON_FINITE        a NaN or infinite texel (error->row, column);
     TT_CANCELLED               the progress callback stopped it;
     TT_ERROR_OUT_OF_MEMORY.
   On any error corner_uv and face_cluster are untouched. Time: the
   hierarchy and flattening (above) plus about 10 ms per fit at P = 256
   (report->fits), typically a few hundred fits for 20k faces. */
TTDEF tt_result tt_hpm_map(const tt_mesh *mesh, const tt_image *image, const tt_hpm_options *options,
                           const tt_allocator *allocator, float *corner_uv, int *face_cluster,
                           tt_hpm_report *report, tt_error *error);

/* ======================================================================== */
/* 9. Polycube + Wang tiles                                                 */
/* ======================================================================== */

/* Based on: C.-C. Chang and C.-Y. Lin, "Texture Tiling on 3D Models Using
   Automatic Polycube-maps and Wang Tiles" (Journal of Information Science
   and Engineering 25, 2009). The steps of the whole pipeline:
     1. tt_polycube_build: the automatic polycube (Sec. 3.1) - this block:
        a. voxelisation: the cubes of a uniform grid over the bounding box
           that the model's surface meets (triangle-cube test);
        b. interior fill, so that a closed part gives one outer sheet of
           quads, not the paper's hollow shell (spec P4);
        c. manifold repair: cubes added where cubes touch along an edge or
           at a vertex only, so the surface S is a 2-manifold (spec P6);
        d. the paper's correction step, read as in spec P5, undone per
           component where it would change the topology;
        e. extraction of S: one quad per exposed cube face, built as a
           strict half-edge mesh, with each quad's corner 0 fixed by an up
           direction so anisotropic textures keep their direction (P8, P9).
     2. tt_polycube_edge_colors: the Wang colouring of S's edges, per axis
        group (Sec. 3.2); tt_assign_boundaries turns it into tile types and
        tt_synthesize_tiles makes the tiles: the paper's rotation rules
        (Figs. 3-5) come out of Akleman's per-side rule on any consistently
        oriented quad mesh, which S is (spec P9, P10).
     3. tt_polycube_map: the mapping of the model onto S (Sec. 4, spec
        P11), in place of the paper's per-cell configurations (P11, P12):
        a. the model refined until no edge is longer than half a cube, so
           a triangle holds about one vertex of S at most;
        b. tt_polycube_project: each vertex gets its point q(v) = (quad,
           s, t) on S (P11 step 2);
        c. the relaxation of the points on S where a triangle folds or an
           edge finds no short path (step 5);
        d. tt_polycube_trace_edges: each edge gets its image on S, the
           quads it passes and where it crosses their edges (S half-edge,
           position on it, t on the mesh edge), one record per edge, so
           the two triangles on an edge split it at the same points (step
           3, P12, Q11); tt_polycube_unfold lays two quads side by side,
           exactly;
        e. the triangle split (step 4): a triangle's boundary unfolded
           into one chart and clipped by the quad grid into pieces inside
           one quad each, or fanned around the one vertex of S inside it,
           or - the fallback (step 7) - put whole into one quad.
     4. tt_polycube_mapping_uvs: each piece's points on S as texture
        coordinates in its quad's tile (step 6).

   The grid (spec P2). L = the bounding box's longest side; the cube edge is
   h = L / resolution, or options->cube_size. Each axis has
   max(1, ceil(extent / h)) cubes, centred on the bounding box (a flat mesh
   gets one layer, halfway through it), plus 2 empty cubes of padding on
   every side. Cube (i, j, k) spans origin + h * [i, i+1] x [j, j+1] x
   [k, k+1]; lattice point (i, j, k) is at origin + h * (i, j, k); linear
   indices run x fastest: i + dims[0] * (j + dims[1] * k), and lattice
   points likewise with dims + 1 per axis.

   Voxelisation (Sec. 3.1, spec P1, P3). The paper uses Voorhies' gem; this
   uses the exact separating-axis test of Akenine-Moeller (13 axes), in
   double, relative to the cube centre, over the cubes of each triangle's
   bounding box only (polygons: their fan triangles from corner 0). The
   tie rule of P3, with a tolerance t = 1e-6 h (more for a mesh far from
   the origin: 8 float ulps of its largest coordinate, as the input is
   float): each triangle is moved 2t against its normal (into the solid)
   and each cube shrunk by t on every side, so a face on a
   lattice plane claims only the cubes behind it and a triangle that only
   touches a cube's face, edge or corner does not claim it: an axis-aligned
   cube mesh on the lattice gives exactly its block of cubes, a union of
   boxes exactly the union. Zero-area triangles are skipped and counted
   (their edges belong to their neighbours).

   Interior (spec P4). The exterior is flooded from the padding through
   face-connected empty cubes, and the empty cubes it does not reach are
   filled. A mesh with holes (an open scan, a model missing a few faces)
   lets the flood in, and the spec keeps such a polycube a hollow shell;
   measured, a shell maps badly (the pig at resolution 32: 1.4 % of the
   triangles to the fallback and stretch p95 6.1, against 0.26 % and 2.7
   sealed), because the two sheets lie one cube apart and neighbouring
   vertices land on different ones. So for an open mesh the holes are
   sealed: the exterior is flooded again around the occupied cubes grown
   by r = 1 + (resolution - 1) / 32 cubes (holes narrower than about 2r
   cubes close), grown back by r, and each remaining component of empty
   cubes is filled when the mesh's generalised winding number (the solid
   angle it spans, over 4 pi) at two of three cubes sampled in it is above
   0.9: the inside of a surface with small holes, not a gap between its
   parts (about 0) nor the inside of a bowl (0.5 to 0.9), which stays open.
   A mesh with no hole (every edge shared), or a surface open all around
   (a bowl, a sheet), has nothing to seal.

   Manifold repair (spec P6). Around a lattice point the 8 cubes give an
   occupancy mask; S is a disc there for exactly 126 of the 256 masks, and
   a mask is a disc (or empty, or full) exactly when it holds no critical
   configuration: C1, a 2 x 2 checkerboard around a lattice edge; C2, two
   antipodal cubes of the 2 x 2 x 2 block alone, or the complement. The
   repair adds cubes until none remains: for C1 one of the two empty cubes,
   for C2 the two cubes of a face-connected staircase between the occupied
   pair, for its complement one of the two empty cubes. "Nearer to the
   mesh" (the spec's choice) is judged at the grid's resolution: a cube the
   surface meets first, then the one with more such face neighbours, then
   the smaller index (a staircase by the sum over its two cubes, then the
   order x, y, z of its steps). Adding only ever grows the set, so the
   loop ends and the model stays inside; then the interior is filled again.

   Correction (Sec. 3.1, spec P5). The paper's sentence cannot be meant as
   written; read as: a cube is removed when one of its 8 corner cells (unit
   boxes centred on its corners) holds part of S but does not meet the
   model. One pass over the polycube as it is, then repair and fill. Where
   that changes the number of components or the Euler characteristic of
   the polycube, it is done again component by component, keeping it only
   for the components where neither changes. TT_POLYCUBE_NO_CORRECT skips
   it.

   Cost. Time O(sum over triangles of the cubes in their bounding boxes)
   for the voxelisation (twice: cubes and corner cells), O(cubes) per
   repair, fill and topology count, with the correction's retries
   O(components * cubes) at worst (many separate parts whose correction
   changes the topology). Bunny, flange, elephant (4-6k faces): 2-10 ms at
   resolution 16-32, 30-45 ms at 64 (-O2). Memory while building: up to
   about 14 bytes per grid cube (occupancy, the cubes and cells the surface
   meets, a queue, the correction's copy and labels), 4 bytes per lattice
   point while extracting, and the result: 1 byte per cube plus the
   surface mesh. The grid, padding included, is capped at
   TT_POLYCUBE_MAX_CUBES cubes. */

#define TT_POLYCUBE_DEFAULT_RESOLUTION 16
#define TT_POLYCUBE_MAX_RESOLUTION 1024       /* cubes along any axis, padding excluded */
#define TT_POLYCUBE_MAX_CUBES (1 << 25)       /* cubes in the padded grid */

enum {
    TT_POLYCUBE_NO_CORRECT = 1u << 0          /* skip the correction step (spec P5) */
};

typedef struct tt_polycube_options {
    int resolution;     /* cubes along the bounding box's longest side; 0 = TT_POLYCUBE_DEFAULT_RESOLUTION,
                           at most TT_POLYCUBE_MAX_RESOLUTION */
    double cube_size;   /* the cube edge h in mesh units; > 0 overrides resolution, 0 = use resolution */
    unsigned flags;     /* TT_POLYCUBE_* */
    double up[3];       /* the up direction for the tiles' orientation (spec P9); zero = +Y. Only its
                           axis counts: the lattice axis of its largest component (the first of equals),
                           with that component's sign */
} tt_polycube_options;

typedef struct tt_polycube_report {
    int dims[3];                /* the grid, padding included */
    double cube_size;           /* h */
    int resolution;             /* cubes along the longest axis, padding excluded */
    int cubes;                  /* occupied cubes of the result */
    int quads;                  /* faces of S */
    int components;             /* connected components of S */
    int filled;                 /* interior cubes added by the fills (P4), sealed ones included */
    int sealed;                 /* of those, the cubes inside an open mesh, behind its holes */
    int repaired;               /* cubes added by the manifold repair (P6) */
    int removed;                /* cubes the correction removed where it was kept (P5); 0 when skipped */
    int correction_reverted;    /* components where the correction was undone (it changed the topology) */
    int mesh_genus;             /* the input's genus when every component is closed and manifold, else -1 */
    int polycube_genus;         /* sum over S's components of (2 - chi) / 2 */
    int genus_differs;          /* mesh_genus >= 0 and differs from polycube_genus: raise the resolution (P8) */
    int zero_area_triangles;    /* fan triangles the voxeliser skipped */
    int inside_out;             /* the mesh is closed and its faces wind inward (negative volume): its normals
                                   point in, and tt_polycube_project's side rule then picks the wrong side;
                                   reverse its faces */
} tt_polycube_report;

/* A polycube and its surface S. Read the fields freely; do not modify them. */
typedef struct tt_polycube {
    int dims[3];                /* cubes per axis, 2 cubes of padding on every side included */
    double origin[3], h;        /* lattice point (i, j, k) is at origin + h * (i, j, k) */
    unsigned char *occupied;    /* dims[0] * dims[1] * dims[2], 1 = in the polycube, x fastest */
    tt_mesh *surface;           /* S: one quad per occupied cube face whose neighbour is empty, CCW seen from
                                   outside; a strict half-edge mesh (closed, manifold) */
    int *quad_cube;             /* per quad: its cube's linear index */
    unsigned char *quad_side;   /* per quad: its outward normal, 0..5 = +x, -x, +y, -y, +z, -z */
    int *vertex_lattice;        /* per S vertex: its lattice point's linear index */
    int up_axis, up_sign;       /* the up of the tiles (tt_polycube_options::up): lattice axis 0..2, +1 or -1 */
    tt_allocator allocator;     /* the one it was built with */
} tt_polycube;

/* Build the polycube of `mesh` (any polygon mesh; each face is voxelised as
   its fan of triangles from corner 0) and its surface S.
   Corner 0 of each quad, i.e. the tile's orientation (spec P9): corner 0 ->
   1 is the tile's u axis, corner 0 -> 3 its v axis, and u x v points out of
   the polycube. With up = +A (a lattice axis A with sign s, see
   tt_polycube_options::up): a quad facing sideways (normal not along A)
   has v = s * e_A; a quad facing +A or -A has v = -s * e_B with B the axis
   after A (x -> y -> z -> x). For the default +Y: side quads have v = +Y,
   top and bottom quads v = -Z, so the front (+Z) and the top (+Y) tiles
   share the u axis +X and unfold into one another across their edge.
   options and report may be NULL. Results:
     TT_OK;
     TT_ERROR_INVALID_ARGUMENT  NULL mesh or out, a bad allocator, unknown
                                flags, resolution or cube_size below 0;
     TT_ERROR_EMPTY_MESH        no faces;
     TT_ERROR_NON_FINITE        a NaN or infinite option or coordinate;
     TT_ERROR_ZERO_AREA_FACE    every face has zero area (no grid to make);
     TT_ERROR_TOO_LARGE         resolution above TT_POLYCUBE_MAX_RESOLUTION,
                                or a grid beyond TT_POLYCUBE_MAX_RESOLUTION
                                cubes per axis or TT_POLYCUBE_MAX_CUBES in all;
     TT_ERROR_OUT_OF_MEMORY.
   On failure *out is NULL and nothing stays allocated. Free the result with
   tt_polycube_free. Thread-safe: reads only the mesh. */
TTDEF tt_result tt_polycube_build(const tt_mesh *mesh, const tt_polycube_options *options,
                                  const tt_allocator *allocator, tt_polycube **out, tt_polycube_report *report,
                                  tt_error *error);
TTDEF void tt_polycube_free(tt_polycube *polycube);

/* The Wang colouring of S (Sec. 3.2, spec P9): every edge of S gets a
   colour (boundary condition) in 0..colors-1. Edges fall into three groups
   by their direction, x, y and z. With axis_palettes non-zero each group
   first draws its own random 2 of the `colors` colours (all of them when
   colors < 2) and its edges draw from those (the paper: 2 of 4 samples per
   axis); otherwise every edge draws from all colours. edge_colors gets
   polycube->surface->ncorners entries, the two half-edges of an edge the
   same colour: the edge_colors input of tt_assign_boundaries (with a layout
   of `colors` colours). Same seed, same result. Errors: NULL polycube or
   edge_colors, colors outside 1..TT_MAX_COLORS (TT_ERROR_INVALID_ARGUMENT).
   Allocates nothing; thread-safe. */
TTDEF tt_result tt_polycube_edge_colors(const tt_polycube *polycube, int colors, int axis_palettes, uint64_t seed,
                                        int *edge_colors, tt_error *error);

/* A point of S: a quad and its coordinates in it. s runs along the quad's
   corner 0 -> 1 and t along corner 0 -> 3, both in [0, 1]: the tile's u and
   v (spec P9), so corners 0..3 are (0,0), (1,0), (1,1), (0,1). */
typedef struct tt_surface_point {
    int quad;           /* face of polycube->surface */
    float s, t;
} tt_surface_point;

/* How tt_polycube_project placed the vertices (every vertex counts in
   exactly one of the first four). */
typedef struct tt_polycube_projection_report {
    int rays;           /* by a ray along the projection field (P11 step 2, the first choice) */
    int nearest;        /* by the closest point among the facelets facing the vertex's side (the second) */
    int fallbacks;      /* by the plain closest point on S, side ignored (target 0) */
    int on_surface;     /* already on S (closer than 1e-9 h to a facelet facing their side): mapped to themselves */
    double mean_distance, max_distance;   /* |p - q(v)| in units of h */
} tt_polycube_projection_report;

/* Projection of the model's vertices onto S (Sec. 4; spec P11 step 2): for
   each vertex v of `mesh` (normally the mesh the polycube was built from)
   its point q(v) on S, into points[v] (mesh->nverts entries).
   Method. n_v is the vertex's area-weighted normal, and a facelet "faces
   v's side" when its outward normal n_f has n_f . n_v > 0. The projection
   field d: at each lattice point of S the sum of the normals of its
   facelets facing v's side (the normal on a flat, the diagonal of a fold
   or a corner), interpolated trilinearly at the vertex and normalised.
   The spec sums all facelets; on a filled polycube that is the same but
   where the two sides of a thin part meet, and on the hollow shell of an
   open mesh (spec P4) the inner and outer sheets lie within a cube of each
   other, so their normals cancel and d turns along the surface. In order:
     - a vertex closer than 1e-9 h to a facelet facing its side maps to
       itself (on a quad's edge or corner: the quad facing v's side best,
       then the smallest index), so a mesh lying on the lattice keeps its
       exact positions;
     - rays from p_v along +d and -d, 3 h long, through the cubes (a 3D
       DDA; S is where the ray passes from an occupied cube to an empty one
       or back): the nearest crossing of a facelet facing v's side. This
       sends the two sides of a thin part to opposite faces of its slab
       (spec P4, P14) and works on both sides of S, as the correction
       leaves the model partly outside (P5);
     - else the closest point of S among the facelets facing v's side, by
       a search of the cubes in growing shells around p_v, up to
       TT_POLYCUBE_PROJECT_SIDE_REACH h away;
     - else the plain closest point of S, counted as a fallback.
   Where d vanishes (a vertex inside the solid, far from S) the rays go
   along n_v. A vertex with no area around it (unused, or only on zero-area
   faces) has no side: every facelet faces it.
   report may be NULL. Results: TT_OK; TT_ERROR_INVALID_ARGUMENT for a NULL
   polycube, mesh or points, a bad allocator, or a polycube whose quads do
   not match its cubes (not made by tt_polycube_build, or a surface without
   quads); TT_ERROR_EMPTY_MESH for a mesh without faces;
   TT_ERROR_NON_FINITE for a NaN or infinite coordinate (error->vertex says
   which); TT_ERROR_OUT_OF_MEMORY. On failure the report is zeroed,
   points is untouched and nothing stays allocated.
   Same input, same output. Cost: a check of the polycube, O(cubes), then
   per vertex the cubes its two rays cross (at most 20) or, for the few
   vertices the rays miss, the cubes of the shells searched ((2 reach +
   1)^3 = 2197 at most, farther only for a fallback); a ray grazing a
   lattice plane (a rim lying on one) may miss and go to the shells.
   Measured at -O2: 2-3 ms for the bunny, flange and elephant (2-3k
   vertices) at resolution 16-64, 23 ms for the horse (48k) at 16-64.
   The side rule needs outward normals: on an inside-out closed mesh no
   facelet near a vertex faces its side, most vertices go to the shells and
   land on the far side of thin parts (the horse as shipped: 85 % by the
   shells, 391 fallbacks at 64, 280 ms); flip such a mesh first.
   Memory: 24 bytes per vertex (the normals) while it runs; S's quads are
   found by binary search in quad_cube, so no table is built.
   Thread-safe: reads only its inputs. */
#define TT_POLYCUBE_PROJECT_SIDE_REACH 6
TTDEF tt_result tt_polycube_project(const tt_polycube *polycube, const tt_mesh *mesh, const tt_allocator *allocator,
                                    tt_surface_point *points, tt_polycube_projection_report *report,
                                    tt_error *error);

/* The 3D position of a point of S, into xyz.
   Preconditions (TT_ASSERT): polycube and its surface are not NULL,
   0 <= p.quad < polycube->surface->nfaces, xyz is not NULL. */
TTDEF void tt_polycube_point_position(const tt_polycube *polycube, tt_surface_point p, double xyz[3]);

/* Unfolding (spec P11 steps 3-4). Each quad of S is the unit square of its
   own (s, t) frame; two quads sharing an edge unfold into one plane by a
   rigid map that turns by a multiple of 90 degrees and shifts by whole
   units, so it is exact in floating point and any chain of them composes
   exactly. A tt_quad_map takes (s, t) to R^turns (s, t) + offset, R the
   quarter turn counter-clockwise ((s, t) -> (-t, s)). */
typedef struct tt_quad_map {
    int turns;          /* 0..3 quarter turns, counter-clockwise */
    int offset[2];
} tt_quad_map;

/* The map from the frame of the quad across S half-edge `halfedge` (the
   quad of its twin) into the frame of halfedge's own quad, so the two
   squares lie side by side along that edge. Derived from the half-edge
   structure alone: half-edge i of a quad runs from corner i to corner i + 1
   and its twin j the other way, so corner j of the far quad lands on
   corner i + 1 and corner j + 1 on corner i. The map across the twin is its
   inverse. Preconditions (TT_ASSERT): polycube and its surface are not
   NULL, 0 <= halfedge < polycube->surface->ncorners, and the half-edge has
   a twin (S is closed, so every one has). */
TTDEF tt_quad_map tt_polycube_unfold(const tt_polycube *polycube, int halfedge);

/* outer after inner: the map taking p to outer(inner(p)).
   Preconditions (TT_ASSERT): both turns in 0..3. */
TTDEF tt_quad_map tt_quad_map_compose(tt_quad_map outer, tt_quad_map inner);

/* map applied to (s, t), into out[2]. Exact: the results are sums of the
   inputs' values, their negations and small integers.
   Preconditions (TT_ASSERT): map.turns in 0..3, out is not NULL. */
TTDEF void tt_quad_map_apply(tt_quad_map map, double s, double t, double out[2]);

/* Where the image of a mesh edge crosses an edge of S. */
typedef struct tt_edge_crossing {
    int halfedge;       /* the S half-edge crossed, as seen from the quad the path leaves */
    double along;       /* the point on that half-edge from its start corner, 0..1 */
    double t;           /* the point on the mesh edge from its first vertex, 0..1 */
} tt_edge_crossing;

#define TT_POLYCUBE_EDGE_DEFAULT_QUADS 4      /* spec P11 step 3 */
#define TT_POLYCUBE_EDGE_MAX_QUADS 64

typedef struct tt_polycube_edge_options {
    int max_quads;      /* the longest quad path searched, quads counted; 0 = TT_POLYCUBE_EDGE_DEFAULT_QUADS,
                           at most TT_POLYCUBE_EDGE_MAX_QUADS */
} tt_polycube_edge_options;

/* The images of a mesh's edges on S. Read the fields freely; do not modify
   them. Edge e runs from edge_vertices[2e] to edge_vertices[2e + 1], the
   smaller vertex id first, whichever way its half-edges run; a half-edge
   running the other way reads the crossings backwards, with t -> 1 - t,
   halfedge -> its twin and along -> 1 - along (the same point). Several
   crossings at one t at a quad corner (along 0 or 1) pass an S vertex: on
   a flat vertex (4 quads) the path goes straight through it, on a saddle
   (5 or 6) it may bend there, so a chart unfolded across that vertex is
   not flat (spec P11 step 4.3's cone points, met on an edge). */
typedef struct tt_polycube_edges {
    int nedges;                 /* the mesh's undirected edges */
    int ncrossings;
    int *edge_of_halfedge;      /* per mesh half-edge (corner): its edge */
    int *edge_vertices;         /* 2 * nedges: first and second vertex */
    int *first_crossing;        /* nedges + 1: edge e's crossings are [first_crossing[e], first_crossing[e+1]),
                                   in order of t */
    tt_edge_crossing *crossings;
    int *end_quads;             /* 2 * nedges: the quad edge e's image leaves its first vertex's point in, and the
                                   one it reaches the second's in; another than the point's own quad only where
                                   that point is a corner of S (then it lies in every quad around the corner) */
    unsigned char *failed;      /* per edge: 1 = no consistent path within max_quads (P11 step 7's fallback) */
    int nfailed;
    tt_allocator allocator;     /* the one it was made with */
} tt_polycube_edges;

/* The image on S of every edge of `mesh` (spec P11 step 3, "edge images
   (intrinsic)"), from its vertices' points (tt_polycube_project; npoints
   = mesh->nverts). For edge (a, b) the search runs over the quad paths
   from q_a's quad to q_b's with at most max_quads quads, none twice,
   depth first, a quad's half-edges in corner order; each path is unfolded
   into q_a's quad plane (tt_polycube_unfold) and kept when the straight
   segment q_a -> q_b crosses exactly its edges in order: each crossing on
   the closed edge, in the direction out of the quad left, at a t no
   smaller than the one before. A segment through a quad corner is a path
   through one of the quads at that corner with two crossings at the same t
   (the lattice lines it crosses there); a segment running along an edge of
   S may pass to the quad across it where it enters that edge. The shortest
   unfolded segment wins, then the path with fewer quads, then the one found
   first, so the result is deterministic. Paths are pruned while they grow:
   the distance from q_a to the last edge crossed must not exceed the best
   length found, and beyond 6 quads (where only straight paths count) the
   directions from q_a through every edge crossed must still overlap (a
   funnel), which keeps long searches (max_quads up to 2N + 2 for the
   N-cube's edges in the tests) small. An edge whose points lie in one
   quad has no crossing. A path of at most 6 quads may also bend at saddle
   vertices of S (5 or 6 quads around, more than a full turn): the
   staircases of a slope are full of them, and a shortest path on S
   between points on either side goes through the vertex, on no straight
   unfolding. A bend is
   kept when the angles on both sides of it are at least half a turn, its
   crossings are the edges around the vertex the path passes, all at the
   vertex (along 0 or 1) and at one t; t runs in proportion to the length
   along the path. An edge with no consistent path is flagged in `failed`
   and has no crossing; the triangles around it are for P11 step 7's
   fallback.
   Snapping (P11 step 4.5): along and t within 1e-6 of 0 or 1 are set to
   0 or 1; the record is made once per edge, so the triangles on both sides
   read the same numbers and split the edge at bitwise identical points
   (spec Q11): p_a + t * (p_b - p_a) in 3D, and on S the point `along` on
   the half-edge crossed. along and t are double: an edge may cross many
   quads and step 4 rebuilds chart points from them, where float's 6e-8
   would be up to 1e-6 h on an edge 16 h long, the size of the snap.
   The search gives up on an edge after 200000 steps (reachable only with
   a large max_quads), keeping the best path found by then.
   Measured (-O2, the default 4 quads; the models of
   tt_polycube_project's cost note): bunny (5.5k edges) 12 ms at
   resolution 16 with none failed, 22 ms at 32 with 72 failed (1.3 %);
   flange (9.7k) 17 ms and 408 (4.2 %), 29 ms and 110 (1.1 %); elephant
   (8.3k) 13 ms and 116 (1.4 %), 25 ms and 317 (3.8 %). Raising max_quads
   to 6 takes about 5 times as long and leaves 0, 40 (0.4 %) and 170 (2 %)
   failed at 32: the rest join vertices that the projection sent to
   different sheets (more than 6 quads apart on S though less than 1 h
   apart in 3D), which the relaxation of P11 step 5 is for.
   Memory: the result (4 bytes per half-edge, 9 per edge, 24 per crossing)
   and a search state of about 5 KB; the search recurses max_quads deep.
   options and the allocator may be NULL. Results: TT_OK;
   TT_ERROR_INVALID_ARGUMENT for a NULL polycube, mesh, points or out, a
   bad allocator, npoints other than mesh->nverts, max_quads outside
   0..TT_POLYCUBE_EDGE_MAX_QUADS, a polycube whose quads do not match its
   cubes, or a point with a quad outside S or s, t outside [0, 1]
   (error->vertex says which); TT_ERROR_EMPTY_MESH for a mesh without
   faces; TT_ERROR_OUT_OF_MEMORY. On failure *out is NULL and nothing stays
   allocated. Free the result with tt_polycube_edges_free. Same input, same
   output; thread-safe. */
TTDEF tt_result tt_polycube_trace_edges(const tt_polycube *polycube, const tt_mesh *mesh,
                                        const tt_surface_point *points, int npoints,
                                        const tt_polycube_edge_options *options, const tt_allocator *allocator,
                                        tt_polycube_edges **out, tt_error *error);
TTDEF void tt_polycube_edges_free(tt_polycube_edges *edges);

/* The model mapped onto S (spec P11 steps 4, 6, 7; the paper's Sec. 4.3
   with its cells replaced by S's quads, P12): every triangle of the model
   is split where its image on S crosses an edge of S, so that each output
   triangle lies in one quad, and each output corner gets its point on S.
   The split points of a model edge come from its record of
   tt_polycube_trace_edges, made once per edge, so the two triangles on it
   share the very same output vertices (no T-junction, no crack; spec Q11).
   Output vertex v < mesh->nverts is input vertex v; the others lie on the
   model's triangles, each with the (up to 3) input vertices and weights
   it interpolates, so normals, colours or skin weights carry through. */
typedef struct tt_polycube_map_options {
    int max_quads;      /* the longest edge path, as tt_polycube_edge_options; 0 = its default */
    double max_edge;    /* model edges longer than this (mesh units) are halved first, until none is;
                           0 = TT_POLYCUBE_MAP_DEFAULT_EDGE times the cube size h; HUGE_VAL: never */
} tt_polycube_map_options;

#define TT_POLYCUBE_MAP_DEFAULT_EDGE 0.5

typedef struct tt_polycube_map_report {
    int triangles;          /* triangles of the model after refinement (max_edge), the ones mapped */
    tt_polycube_projection_report projection;   /* how the (refined) model's vertices went onto S */
    int relaxed;            /* moves of points on S that unfolded a fold or joined a vertex to its neighbours'
                               sheet (P11 step 5) */
    int failed_edges;       /* model edges with no path on S within max_quads */
    int split_triangles;    /* input triangles cut into two or more output triangles */
    int fallback_triangles; /* of `triangles`, those put whole into one quad (P11 step 7): a local seam; target 0 */
    int flipped;            /* output triangles whose points on S turn clockwise (a fold; none is expected) */
    int collapsed;          /* output triangles whose points on S have no area (a sliver of stretched texture) */
} tt_polycube_map_report;

typedef struct tt_polycube_mapping {
    int nverts;
    float *positions;       /* 3 * nverts */
    int *source;            /* 3 * nverts: the input vertices output vertex v interpolates... */
    float *weights;         /* 3 * nverts: ...with these weights (sum 1; unused slots have weight 0) */
    int ntriangles;
    int *triangles;         /* 3 * ntriangles output vertex indices, wound as the input */
    int *triangle_face;     /* per output triangle: the input face it is part of */
    tt_surface_point *corner_points;    /* 3 * ntriangles: each corner's point on S, the three in one quad */
    tt_allocator allocator; /* the one it was made with */
} tt_polycube_mapping;

/* Map `mesh` (triangles, outward facing; the mesh the polycube was built
   from, or any other near its surface) onto S:
     1. refinement: edges longer than max_edge (half a cube by default)
        are halved until none is, so a triangle spans few quads and holds
        about one vertex of S at most;
     2. tt_polycube_project (points within 1e-5 of a quad's edge are put
        on it, so the model's vertices on lattice lines are on S's edges
        exactly);
     3. relaxation (P11 step 5): points of folded triangles move toward
        their neighbours' in a local chart of S, or into the kernel of
        their star, points cut off from their neighbours (no short path)
        onto a neighbour's sheet, a move kept only when it leaves the
        vertex's triangles better placed; then the folds left (a whole
        patch folded, where no vertex has a good place of its own) are
        untangled by Escobar et al.'s energy, from their rims inward;
     4. tt_polycube_trace_edges (max_quads); a vertex with an edge that
        finds no path (the projection seated it on the far side of a part
        about a cube thick) is tried on each neighbour's sheet and kept
        where fewest of its edges fail, then fewest of its triangles fold;
        its edges are traced again, and the relaxation of step 3 runs
        again around the points so moved; then spikes: a vertex whose
        two edges in one triangle leave it through the same corner W of S
        (it lies just behind a saddle) would map part of that triangle
        onto a line; it is moved onto W unless another point is there,
        and the edges are traced again (a vertex whose edges then find no
        path goes back, and they are traced once more);
     5. per triangle, the split (P11 step 4):
        - its boundary (its vertices and its edges' split points, from
          the records) is unfolded into one chart from its first vertex's
          quad; where an edge runs along an edge of S the quad on the
          triangle's side is taken, and the quads follow each other across
          S's edges, or clockwise around a vertex of S (through the
          triangle's side);
        - when the chart closes (back in the first quad, in the same
          frame), turns counter-clockwise and every split point lies on
          the straight chart triangle (no cone point of S inside, no bend
          at a saddle), the chart triangle is clipped by the unit grid of
          the chart (Sutherland-Hodgman) into convex pieces, one per quad,
          each fanned into triangles; the quads of the grid cells are found
          by walking across S's edges from the boundary's quads, and must
          agree. A cut of a side is that side's split point on the grid
          line (the record's numbers, so the neighbour's split is the
          same), a grid point inside interpolates the triangle's vertices
          with its barycentric coordinates; every split point must end up
          a corner of a piece;
        - otherwise, when every quad the boundary passes is around one
          vertex V of S and the boundary winds once around V (a cone point
          inside) or passes through it (a bend), the triangle is the fan
          from V over its boundary, each fan triangle in its segment's
          quad (one may collapse to a line on S: counted in collapsed); a
          V inside becomes a vertex at the boundary's mean value
          coordinates seen from V, which lie on the triangle;
        - otherwise (an edge with no path, a fold the relaxation could not
          open, several cones) the triangle keeps its boundary, so its
          neighbours still meet it without a crack, and is fanned from its
          centroid into one quad - of its vertices' quads, the one facing
          most like it - laid flat in its own plane, turned so that its
          axis nearest the quad's s runs along s, at the model's scale or
          shrunk to fit the quad, over its centroid's projection (P11 step
          7, whose clamped projection would fold triangles facing away
          from the quad): a local seam, counted in fallback_triangles,
          but no flipped piece.
   Every split point of an edge is one output vertex shared by the two
   triangles on the edge: a closed manifold model gives a closed manifold
   output. Pieces of zero area (an edge along a lattice line) are dropped;
   the output's area equals the input's. An inside-out mesh
   (tt_polycube_report::inside_out) must be reversed first: the points go
   to the wrong sides of thin parts and every chart turns clockwise.
   Measured (-O2, default options, resolution 32): a 100k-triangle torus
   in about 0.4 s (make bench) with no fallback; the bunny (3.7k
   triangles, 51k refined) in 0.4 s with 0.01 % fallbacks; a 97k-triangle
   horse in 1 s with 0.04 %; a CAD flange in 0.6 s with 0.10 %; no
   flipped triangle on any. Parts about a cube thick cost more time and
   leave more fallbacks (an elephant's trunk and legs: 2.4 %, 2.5 s).
   report may be NULL.
   Results: TT_OK; TT_ERROR_INVALID_ARGUMENT for a NULL polycube, mesh or
   out, a bad allocator, max_quads outside 0..TT_POLYCUBE_EDGE_MAX_QUADS,
   max_edge not above 0, a face that is not a triangle (error->face;
   triangulate first), or a polycube not made by tt_polycube_build;
   TT_ERROR_EMPTY_MESH; TT_ERROR_NON_FINITE; TT_ERROR_TOO_LARGE when the
   refinement would pass INT_MAX / 4 vertices; TT_ERROR_OUT_OF_MEMORY. On
   failure *out is NULL, the report zeroed, and nothing stays allocated.
   Memory: the refined model and the edge records (about 100 bytes per
   refined triangle) while it runs, and the result. Free the result with
   tt_polycube_mapping_free. Same input, same output; thread-safe. */
TTDEF tt_result tt_polycube_map(const tt_polycube *polycube, const tt_mesh *mesh,
                                const tt_polycube_map_options *options, const tt_allocator *allocator,
                                tt_polycube_mapping **out, tt_polycube_map_report *report, tt_error *error);
TTDEF void tt_polycube_mapping_free(tt_polycube_mapping *mapping);

/* Texture coordinates of a mapping (spec P11 step 6): corner i of output
   triangle f at point (quad, s, t) gets the point (s, t) of that quad's
   tile, u = (column*C + g + s*S) / W, v = (row*C + g + t*S) / W, the tile
   from the quad's four boundary types (corner_type: one per S half-edge,
   from tt_assign_boundaries on polycube->surface with this layout), as
   tt_tile_corner_uv gives at s, t in {0, 1}. corner_uv gets
   6 * mapping->ntriangles floats. Errors: NULL arguments, a layout that
   does not resolve, a type of 2n or more (TT_ERROR_INVALID_ARGUMENT,
   TT_ERROR_TOO_LARGE as tt_tile_layout_resolve), a corner point outside S
   (TT_ERROR_INDEX_OUT_OF_RANGE). Allocates nothing; thread-safe. */
TTDEF tt_result tt_polycube_mapping_uvs(const tt_polycube *polycube, const tt_polycube_mapping *mapping,
                                        const tt_tile_layout *layout, const uint8_t *corner_type,
                                        float *corner_uv, tt_error *error);
/* Upright tiles on the walls, so bricks, planks and grain keep their
   direction all round the model (tt_synth_options::upright). The walls -
   quads facing sideways, their normal not along polycube->up_axis: 1 from
   tt_polycube_quad_upright - take upright tiles, the tops and bottoms plain
   ones. Every edge of S then meets seamlessly: the edges along the up axis
   are left/right sides of both their quads (upright tiles both), and every
   other edge is a bottom/top side of each wall it borders, alike in both
   sets when they share their edge windows.
     1. tt_synthesize_tiles (or plan and apply) the plain tiles, then the
        upright ones with the same layout and seed, options.upright = 1 and
        options.edge_windows = the plain tileset's edge_windows;
     2. tt_polycube_upright_atlas: the two side by side, 2W x W, plain on
        the left (per mip level, as you need them);
     3. tt_polycube_mapping_uvs_upright: as tt_polycube_mapping_uvs, u
        halved, and moved to the right half for a wall.
   tt_polycube_quad_upright is 1 for a wall, 0 for a top or bottom.
   Preconditions (TT_ASSERT): a polycube from tt_polycube_build, 0 <= quad <
   its surface's nfaces. */
TTDEF int tt_polycube_quad_upright(const tt_polycube *polycube, int quad);
/* Errors: NULL arguments, a bad allocator, tilesets of different layouts,
   a plain tileset with vertical windows or an upright one without, edge
   windows that differ (TT_ERROR_INVALID_ARGUMENT); a level that is not in
   both tilesets (TT_ERROR_INDEX_OUT_OF_RANGE). *out_image is NULL on
   failure; free it with tt_image_free. */
TTDEF tt_result tt_polycube_upright_atlas(const tt_tileset *plain, const tt_tileset *upright, int level,
                                          const tt_allocator *allocator, tt_image **out_image, tt_error *error);
/* Errors and the rest as tt_polycube_mapping_uvs. */
TTDEF tt_result tt_polycube_mapping_uvs_upright(const tt_polycube *polycube, const tt_polycube_mapping *mapping,
                                                const tt_tile_layout *layout, const uint8_t *corner_type,
                                                float *corner_uv, tt_error *error);

#ifdef __cplusplus
}
#endif

#endif /* TILEDTEX_H */

/* ======================================================================== */
/* ======================================================================== */
/*                           IMPLEMENTATION                                 */
/* ======================================================================== */
/* ======================================================================== */

#ifdef TILEDTEX_IMPLEMENTATION
#ifndef TILEDTEX_IMPLEMENTATION_INCLUDED
#define TILEDTEX_IMPLEMENTATION_INCLUDED

#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#if defined(TT_MALLOC) && defined(TT_FREE)
#elif !defined(TT_MALLOC) && !defined(TT_FREE)
#include <stdlib.h>
#define TT_MALLOC(size, user_data) ((void)(user_data), malloc(size))
#define TT_FREE(ptr, user_data) ((void)(user_data), free(ptr))
#else
#error "tiledtex.h: define both TT_MALLOC and TT_FREE, or neither"
#endif

#ifndef TT_ASSERT
#include <assert.h>
#define TT_ASSERT(condition) assert(condition)
#endif

#ifdef __cplusplus
extern "C" {
#endif

/* ------------------------------------------------------------------------ */
/* 1. Common                                                                */
/* ------------------------------------------------------------------------ */

TTDEF const char *tt_result_string(tt_result result)
{
    switch (result) {
    case TT_OK: return "success";
    case TT_CANCELLED: return "cancelled by the progress callback";
    case TT_ERROR_INVALID_ARGUMENT: return "invalid argument";
    case TT_ERROR_OUT_OF_MEMORY: return "out of memory";
    case TT_ERROR_TOO_LARGE: return "a size is too large";
    case TT_ERROR_EMPTY_MESH: return "the mesh has no faces";
    case TT_ERROR_INDEX_OUT_OF_RANGE: return "an index is out of range";
    case TT_ERROR_FACE_TOO_SMALL: return "a face has fewer than 3 corners";
    case TT_ERROR_REPEATED_VERTEX: return "a face uses the same vertex twice";
    case TT_ERROR_NON_FINITE: return "a value is NaN or infinite";
    case TT_ERROR_ZERO_AREA_FACE: return "a face has zero area";
    case TT_ERROR_NON_MANIFOLD_EDGE: return "an edge is shared by more than two faces";
    case TT_ERROR_INCONSISTENT_ORIENTATION: return "two neighbouring faces are oriented inconsistently";
    case TT_ERROR_NON_MANIFOLD_VERTEX: return "the faces around a vertex form more than one fan";
    case TT_ERROR_NOT_QUAD_MESH: return "this step needs a mesh of quads";
    case TT_ERROR_IMAGE_TOO_SMALL: return "an image is too small for what was asked";
    case TT_ERROR_NOT_CONVERGED: return "an iterative method did not finish within its limit";
    case TT_ERROR_NOT_POSITIVE_DEFINITE: return "the matrix is not symmetric positive definite";
    case TT_ERROR_NOT_MEASURED: return "nothing could be measured";
    case TT_ERROR_NOT_FLAT: return "the surface does not flatten within the allowed distortion";
    default: return "unknown tiledtex result";
    }
}

TTDEF const char *tt_version(int *major, int *minor, int *patch)
{
    if (major) *major = TILEDTEX_VERSION_MAJOR;
    if (minor) *minor = TILEDTEX_VERSION_MINOR;
    if (patch) *patch = TILEDTEX_VERSION_PATCH;
    return TILEDTEX_VERSION_STRING;
}

static void tt__clear_places(tt_error *error)
{
    error->face = error->corner = error->vertex = error->other_vertex = error->other_face = -1;
    error->row = error->column = error->item = -1;
}

/* Fill *error (if given) and return `result`. Every error path goes through
   here, so every error carries a sentence and the place it refers to; places
   other than a face, corner or vertex are set after it (tt__fail_at). Numbers
   in messages use %g-style formats, never %f, so a huge value cannot push
   the sentence past the buffer. */
static tt_result tt__fail(tt_error *error, tt_result result, int face, int corner, int vertex,
                          int other_vertex, const char *format, ...)
{
    if (error) {
        va_list args;
        tt__clear_places(error);
        error->result = result;
        error->face = face;
        error->corner = corner;
        error->vertex = vertex;
        error->other_vertex = other_vertex;
        va_start(args, format);
        vsnprintf(error->message, sizeof error->message, format, args);
        va_end(args);
    }
    return result;
}

/* The same for errors about an input item, a matrix entry or a texel. */
static tt_result tt__fail_at(tt_error *error, tt_result result, int item, int row, int column, const char *format,
                             ...)
{
    if (error) {
        va_list args;
        tt__clear_places(error);
        error->result = result;
        error->item = item;
        error->row = row;
        error->column = column;
        va_start(args, format);
        vsnprintf(error->message, sizeof error->message, format, args);
        va_end(args);
    }
    return result;
}

static tt_result tt__ok(tt_error *error)
{
    if (error) {
        tt__clear_places(error);
        error->result = TT_OK;
        error->message[0] = '\0';
    }
    return TT_OK;
}

/* THE API CONTRACT's allocator rule: NULL means TT_MALLOC / TT_FREE; a given
   allocator sets both functions (or neither, to pass user_data to the
   TT_MALLOC / TT_FREE macros). */
static tt_result tt__check_allocator(const tt_allocator *allocator, tt_error *error)
{
    if (allocator && (allocator->alloc == NULL) != (allocator->free == NULL))
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "the allocator sets %s but not %s: set both, or pass NULL for TT_MALLOC / TT_FREE",
                        allocator->alloc ? "alloc" : "free", allocator->alloc ? "free" : "alloc");
    return TT_OK;
}

/* The allocator an object remembers: a copy, zeroed for NULL. */
static tt_allocator tt__allocator_copy(const tt_allocator *allocator)
{
    tt_allocator copy;
    if (allocator) return *allocator;
    memset(&copy, 0, sizeof copy);
    return copy;
}

static void *tt__alloc(const tt_allocator *allocator, size_t size)
{
    if (size == 0) size = 1;
    if (allocator && allocator->alloc) return allocator->alloc(size, allocator->user_data);
    return TT_MALLOC(size, allocator ? allocator->user_data : NULL);
}

static void tt__free(const tt_allocator *allocator, void *ptr)
{
    if (!ptr) return;
    if (allocator && allocator->alloc) {
        void (*release)(void *, void *) = allocator->free;   /* set: tt__check_allocator */
        release(ptr, allocator->user_data);
        return;
    }
    TT_FREE(ptr, allocator ? allocator->user_data : NULL);
}

/* count elements of element_size bytes fit in a size_t byte count. */
static int tt__size_fits(size_t count, size_t element_size)
{
    return element_size == 0 || count <= (size_t)-1 / element_size;
}

/* count * element_size bytes, or NULL when that overflows size_t. */
static void *tt__alloc_array(const tt_allocator *allocator, size_t count, size_t element_size)
{
    if (!tt__size_fits(count, element_size)) return NULL;
    return tt__alloc(allocator, count * element_size);
}

#define TT__ALLOC(allocator, type, count) ((type *)tt__alloc_array((allocator), (size_t)(count), sizeof(type)))

/* Growable array: `array` (holding *capacity elements of `size` bytes)
   grown to hold at least `need`, doubling; NULL when out of memory, the old
   array then still the caller's. */
static void *tt__grow(const tt_allocator *al, void *array, int *capacity, int need, size_t size)
{
    int cap = *capacity;
    void *bigger;
    if (need <= cap) return array;
    while (cap < need) {
        if (cap > INT_MAX / 2) return NULL;
        cap = cap ? 2 * cap : 64;
    }
    if (!tt__size_fits((size_t)cap, size)) return NULL;
    bigger = tt__alloc(al, (size_t)cap * size);
    if (!bigger) return NULL;
    if (array) memcpy(bigger, array, (size_t)*capacity * size);
    tt__free(al, array);
    *capacity = cap;
    return bigger;
}

#define TT__PI 3.14159265358979323846
#define TT__TWO_PI 6.28318530717958647692

static int tt__min_i(int a, int b) { return a < b ? a : b; }
static int tt__max_i(int a, int b) { return a > b ? a : b; }
static int tt__abs_i(int x) { return x < 0 ? -x : x; }
static int tt__clamp_i(int x, int lo, int hi) { return x < lo ? lo : (x > hi ? hi : x); }
static float tt__clamp_f(float x, float lo, float hi) { return x < lo ? lo : (x > hi ? hi : x); }

/* NaN and infinity have an all-ones exponent. Tested on the bits so that the
   answer does not depend on compiler flags such as -ffast-math. */
static int tt__is_finite(float x)
{
    uint32_t bits;
    memcpy(&bits, &x, sizeof bits);
    return (bits & 0x7f800000u) != 0x7f800000u;
}

/* Double version of tt__is_finite: tested on the bits, like it. */
static int tt__is_finite_d(double x)
{
    uint64_t bits;
    memcpy(&bits, &x, sizeof bits);
    return (bits & 0x7ff0000000000000ull) != 0x7ff0000000000000ull;
}

static double tt__not_a_number(void)
{
    uint64_t bits = 0x7ff8000000000000ull;
    double x;
    memcpy(&x, &bits, sizeof x);
    return x;
}

static float tt__infinity(void)
{
    uint32_t bits = 0x7f800000u;
    float x;
    memcpy(&x, &bits, sizeof x);
    return x;
}

/* ---- Small 3D vector math (doubles) ---- */

static double tt__dot3(const double *a, const double *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

static double tt__length3(const double *v) { return sqrt(tt__dot3(v, v)); }

/* |v| of a float vector, in double. */
static double tt__length3f(const float *v)
{
    double d[3];
    d[0] = v[0]; d[1] = v[1]; d[2] = v[2];
    return tt__length3(d);
}

/* out = a - b for float points, in double. */
static void tt__sub3f(const float *a, const float *b, double *out)
{
    out[0] = (double)a[0] - b[0]; out[1] = (double)a[1] - b[1]; out[2] = (double)a[2] - b[2];
}

static void tt__cross3(const double *a, const double *b, double *out)
{
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}

/* Scale v to unit length; returns the old length (v untouched when it is 0). */
static double tt__normalize3(double *v)
{
    double len = tt__length3(v);
    if (len > 0.0) { v[0] /= len; v[1] /= len; v[2] /= len; }
    return len;
}

/* v minus its component along the unit normal n. */
static void tt__project3(const double *v, const double *n, double *out)
{
    double d = tt__dot3(v, n);
    out[0] = v[0] - d * n[0]; out[1] = v[1] - d * n[1]; out[2] = v[2] - d * n[2];
}

/* ---- Small 2D geometry ---- */

/* Twice the signed area of triangle a, b, c: positive when it turns left. */
static double tt__orient2(double ax, double ay, double bx, double by, double cx, double cy)
{
    return (bx - ax) * (cy - ay) - (by - ay) * (cx - ax);
}

/* Distance from (px, py) to the segment from a to b (to a when b == a). */
static double tt__point_segment_distance(double px, double py, double ax, double ay, double bx, double by)
{
    double dx = bx - ax, dy = by - ay;
    double wx = px - ax, wy = py - ay, length2 = dx * dx + dy * dy, t = 0.0;
    if (length2 > 0.0) {
        t = (wx * dx + wy * dy) / length2;
        t = t < 0.0 ? 0.0 : (t > 1.0 ? 1.0 : t);
    }
    wx -= t * dx;
    wy -= t * dy;
    return sqrt(wx * wx + wy * wy);
}

/* ---- Binary min-heap of (key, value) items ----
   Ties are broken by the smaller value, so the order of pops is
   deterministic. The caller owns the array and its capacity. */
typedef struct tt__heap_item {
    double key;
    int value;
} tt__heap_item;

static int tt__heap_less(const tt__heap_item *a, const tt__heap_item *b)
{
    return a->key < b->key || (a->key == b->key && a->value < b->value);
}

static void tt__heap_push(tt__heap_item *heap, int *count, double key, int value)
{
    int i = (*count)++;
    tt__heap_item item;
    item.key = key;
    item.value = value;
    while (i > 0) {
        int parent = (i - 1) / 2;
        if (!tt__heap_less(&item, &heap[parent])) break;
        heap[i] = heap[parent];
        i = parent;
    }
    heap[i] = item;
}

static tt__heap_item tt__heap_pop(tt__heap_item *heap, int *count)
{
    tt__heap_item top = heap[0], last = heap[--(*count)];
    int i = 0, n = *count;
    for (;;) {
        int child = 2 * i + 1;
        if (child >= n) break;
        if (child + 1 < n && tt__heap_less(&heap[child + 1], &heap[child])) child++;
        if (!tt__heap_less(&heap[child], &last)) break;
        heap[i] = heap[child];
        i = child;
    }
    if (n > 0) heap[i] = last;
    return top;
}

/* ---- Sorting in place (ascending) ----
   Heapsort: O(n log n) whatever the input, so the exact median of a million
   entries, or the edges of a million-face fan around one vertex, never
   degrade to a quadratic worst case. One definition, made for each element
   type the library sorts: by `<` (TT__DEFINE_HEAPSORT: doubles here, the
   half-edge builder's 64-bit edge keys in the mesh section), or by a
   comparison `less(a, b)` on two elements (TT__DEFINE_HEAPSORT_BY: structs
   sorted by one field). */
#define TT__DEFINE_HEAPSORT_BY(name, type, less)                                \
    static void name(type *v, int n)                                            \
    {                                                                           \
        int start = n / 2 - 1, end = n;                                         \
        while (end > 1) {                                                       \
            int root;                                                           \
            type tmp;                                                           \
            if (start >= 0) {                                                   \
                root = start--;      /* building the heap */                    \
            } else {                                                            \
                end--;               /* moving the largest behind the heap */   \
                tmp = v[0]; v[0] = v[end]; v[end] = tmp;                        \
                root = 0;                                                       \
            }                                                                   \
            for (;;) {                                                          \
                int child = 2 * root + 1;                                       \
                if (child >= end) break;                                        \
                if (child + 1 < end && less(v[child], v[child + 1])) child++;   \
                if (!less(v[root], v[child])) break;                            \
                tmp = v[root]; v[root] = v[child]; v[child] = tmp;              \
                root = child;                                                   \
            }                                                                   \
        }                                                                       \
    }

#define TT__LESS_THAN(a, b) ((a) < (b))
#define TT__DEFINE_HEAPSORT(name, type) TT__DEFINE_HEAPSORT_BY(name, type, TT__LESS_THAN)

TT__DEFINE_HEAPSORT(tt__sort_doubles, double)

/* PCG32 (O'Neill 2014): a 64-bit LCG whose output is a permuted 32-bit word. */
TTDEF uint32_t tt_rng_next(tt_rng *rng)
{
    uint64_t old;
    uint32_t xorshifted, rotation;
    TT_ASSERT(rng);
    old = rng->state;
    rng->state = old * 6364136223846793005ull + rng->increment;
    xorshifted = (uint32_t)(((old >> 18) ^ old) >> 27);
    rotation = (uint32_t)(old >> 59);
    return (xorshifted >> rotation) | (xorshifted << ((32u - rotation) & 31u));
}

TTDEF void tt_rng_seed(tt_rng *rng, uint64_t seed, uint64_t stream)
{
    TT_ASSERT(rng);
    rng->state = 0;
    rng->increment = (stream << 1) | 1u;
    tt_rng_next(rng);
    rng->state += seed;
    tt_rng_next(rng);
}

TTDEF uint32_t tt_rng_below(tt_rng *rng, uint32_t bound)
{
    /* Reject the few values that would make `% bound` favour small results. */
    uint32_t threshold, r;
    if (bound == 0) return 0;
    threshold = (0u - bound) % bound;
    do {
        r = tt_rng_next(rng);
    } while (r < threshold);
    return r % bound;
}

TTDEF float tt_rng_float(tt_rng *rng)
{
    return (float)(tt_rng_next(rng) >> 8) * (1.0f / 16777216.0f);
}

/* ------------------------------------------------------------------------ */
/* 2. Mesh                                                                  */
/* ------------------------------------------------------------------------ */

TTDEF int tt_mesh_next(const tt_mesh *mesh, int corner)
{
    int face;
    TT_ASSERT(mesh && corner >= 0 && corner < mesh->ncorners);
    face = mesh->corner_face[corner];
    return corner + 1 < mesh->face_start[face + 1] ? corner + 1 : mesh->face_start[face];
}

TTDEF int tt_mesh_prev(const tt_mesh *mesh, int corner)
{
    int face;
    TT_ASSERT(mesh && corner >= 0 && corner < mesh->ncorners);
    face = mesh->corner_face[corner];
    return corner > mesh->face_start[face] ? corner - 1 : mesh->face_start[face + 1] - 1;
}

TTDEF void tt_mesh_free(tt_mesh *mesh)
{
    tt_allocator allocator;
    if (!mesh) return;
    allocator = mesh->allocator;
    if (!(mesh->flags & TT_MESH_BORROW_POSITIONS)) tt__free(&allocator, (void *)mesh->pos);
    tt__free(&allocator, mesh->face_start);
    tt__free(&allocator, mesh->corner_vert);
    tt__free(&allocator, mesh->corner_face);
    tt__free(&allocator, mesh->twin);
    tt__free(&allocator, mesh->vert_corner);
    tt__free(&allocator, mesh);
}

/* A half-edge in the bucket of its edge's smaller vertex, as one sort key:
   the larger vertex in the high 32 bits, corner_dir = 2 * corner + 1 when the
   half-edge runs from the larger vertex to the smaller in the low ones. Both
   halves of an edge share one bucket, so pairing never has to look into
   another vertex's bucket. */
#define TT__EDGE_KEY(other, corner_dir) (((uint64_t)(uint32_t)(other) << 32) | (uint32_t)(corner_dir))
#define TT__KEY_OTHER(key) ((int)((key) >> 32))
#define TT__KEY_CORNER_DIR(key) ((int)((key) & 0xffffffffu))

TT__DEFINE_HEAPSORT(tt__heapsort_keys, uint64_t)

/* Sorting networks for the usual bucket sizes (a grid's buckets hold 4
   half-edges, a triangle mesh's 4 to 8): compare-exchanges without branches,
   where an insertion sort mispredicts about once per entry. */
#define TT__SORT2(k, i, j)                                              \
    do {                                                                \
        uint64_t x_ = (k)[i], y_ = (k)[j];                              \
        (k)[i] = x_ < y_ ? x_ : y_;                                     \
        (k)[j] = x_ < y_ ? y_ : x_;                                     \
    } while (0)

/* Buckets hold about half a vertex's valence worth of edges: a network or an
   insertion sort for the usual handful, heapsort so that a pathological fan
   of a million faces around one vertex is still O(n log n) rather than
   quadratic. */
static void tt__sort_edge_keys(uint64_t *k, int count)
{
    int i;
    switch (count) {
    case 0: case 1: return;
    case 2: TT__SORT2(k, 0, 1); return;
    case 4:
        TT__SORT2(k, 0, 1); TT__SORT2(k, 2, 3); TT__SORT2(k, 0, 2); TT__SORT2(k, 1, 3); TT__SORT2(k, 1, 2);
        return;
    case 6:
        TT__SORT2(k, 1, 2); TT__SORT2(k, 4, 5); TT__SORT2(k, 0, 2); TT__SORT2(k, 3, 5); TT__SORT2(k, 0, 1);
        TT__SORT2(k, 3, 4); TT__SORT2(k, 2, 5); TT__SORT2(k, 0, 3); TT__SORT2(k, 1, 4); TT__SORT2(k, 2, 4);
        TT__SORT2(k, 1, 3); TT__SORT2(k, 2, 3);
        return;
    case 8:
        TT__SORT2(k, 0, 2); TT__SORT2(k, 1, 3); TT__SORT2(k, 4, 6); TT__SORT2(k, 5, 7); TT__SORT2(k, 0, 4);
        TT__SORT2(k, 1, 5); TT__SORT2(k, 2, 6); TT__SORT2(k, 3, 7); TT__SORT2(k, 0, 1); TT__SORT2(k, 2, 3);
        TT__SORT2(k, 4, 5); TT__SORT2(k, 6, 7); TT__SORT2(k, 2, 4); TT__SORT2(k, 3, 5); TT__SORT2(k, 1, 4);
        TT__SORT2(k, 3, 6); TT__SORT2(k, 1, 2); TT__SORT2(k, 3, 4); TT__SORT2(k, 5, 6);
        return;
    default: break;
    }
    if (count <= 24) {
        for (i = 1; i < count; i++) {
            uint64_t key = k[i];
            int j = i - 1;
            while (j >= 0 && key < k[j]) { k[j + 1] = k[j]; j--; }
            k[j + 1] = key;
        }
        return;
    }
    tt__heapsort_keys(k, count);
}

/* The corner of the first repeated vertex in a face, or -1. Triangles and
   quads, nearly every face there is, compare their few pairs directly; large
   faces stamp vertices (stamp[v] == face) to stay linear. */
static int tt__repeated_corner(const int *v, int count, int face, int *stamp)
{
    int i, j;
    if (count == 3) return v[1] == v[0] ? 1 : (v[2] == v[0] || v[2] == v[1]) ? 2 : -1;
    if (count == 4)
        return v[1] == v[0] ? 1 : (v[2] == v[0] || v[2] == v[1]) ? 2 : (v[3] == v[0] || v[3] == v[1] || v[3] == v[2]) ? 3 : -1;
    if (!stamp) {
        for (i = 1; i < count; i++)
            for (j = 0; j < i; j++)
                if (v[i] == v[j]) return i;
        return -1;
    }
    for (i = 0; i < count; i++) {
        if (stamp[v[i]] == face) return i;
        stamp[v[i]] = face;
    }
    return -1;
}

/* Twice the vector area of a polygon by Newell's method taken relative to
   its first corner (the terms with that corner vanish, and faces far from the
   origin lose no precision): n = sum over i of (p_i - p_0) x (p_(i+1) - p_0),
   with the face's own size, scale = sum of |p_i - p_0|^2. */
static void tt__polygon_newell(const float *pos, const int *verts, int count, double n[3], double *scale)
{
    const float *o = pos + 3 * (size_t)verts[0];
    double a[3] = {0.0, 0.0, 0.0};
    int i;
    n[0] = n[1] = n[2] = 0.0;
    *scale = 0.0;
    for (i = 1; i < count; i++) {
        const float *q = pos + 3 * (size_t)verts[i];
        double b[3], ab[3];
        tt__sub3f(q, o, b);
        tt__cross3(a, b, ab);
        n[0] += ab[0]; n[1] += ab[1]; n[2] += ab[2];
        *scale += tt__dot3(b, b);
        a[0] = b[0]; a[1] = b[1]; a[2] = b[2];
    }
}

/* "Zero area" means numerically zero against the face's own size, not
   merely thin. Squares are compared: no square root per face. */
static int tt__newell_is_zero(const double n[3], double scale)
{
    return tt__dot3(n, n) <= 1e-24 * scale * scale;
}

static int tt__face_has_zero_area(const float *pos, const int *verts, int count)
{
    double n[3], scale;
    if (count == 4) {
        /* The builder's hot path: for a quad, Newell's vector is the cross
           product of its diagonals, and their squared lengths a fair size. */
        const float *o = pos + 3 * (size_t)verts[0], *p = pos + 3 * (size_t)verts[1];
        const float *q = pos + 3 * (size_t)verts[2], *r = pos + 3 * (size_t)verts[3];
        float d[3], e[3];
        d[0] = q[0] - o[0]; d[1] = q[1] - o[1]; d[2] = q[2] - o[2];
        e[0] = r[0] - p[0]; e[1] = r[1] - p[1]; e[2] = r[2] - p[2];
        n[0] = (double)d[1] * e[2] - (double)d[2] * e[1];
        n[1] = (double)d[2] * e[0] - (double)d[0] * e[2];
        n[2] = (double)d[0] * e[1] - (double)d[1] * e[0];
        scale = (double)d[0] * d[0] + (double)d[1] * d[1] + (double)d[2] * d[2] + (double)e[0] * e[0] +
                (double)e[1] * e[1] + (double)e[2] * e[2];
        return tt__newell_is_zero(n, scale);
    }
    tt__polygon_newell(pos, verts, count, n, &scale);
    return tt__newell_is_zero(n, scale);
}

/* The unit normal, or zero for a face of numerically zero area (judged as
   tt_mesh_build judges it, through tt__polygon_newell). */
static int tt__face_normal_d(const tt_mesh *mesh, int face, double normal[3])
{
    int begin = mesh->face_start[face];
    double n[3], scale, inverse;
    tt__polygon_newell(mesh->pos, mesh->corner_vert + begin, mesh->face_start[face + 1] - begin, n, &scale);
    if (tt__newell_is_zero(n, scale)) {
        normal[0] = normal[1] = normal[2] = 0.0;
        return 0;
    }
    inverse = 1.0 / tt__length3(n);
    normal[0] = n[0] * inverse; normal[1] = n[1] * inverse; normal[2] = n[2] * inverse;
    return 1;
}

/* Area of a face (its Newell vector's half length). */
static double tt__face_area_d(const tt_mesh *mesh, int face)
{
    int begin = mesh->face_start[face];
    double n[3], scale;
    tt__polygon_newell(mesh->pos, mesh->corner_vert + begin, mesh->face_start[face + 1] - begin, n, &scale);
    return 0.5 * tt__length3(n);
}

/* TT_OK when every face is a triangle; else TT_ERROR_INVALID_ARGUMENT
   naming the first other face: "face F has N corners: <why>". */
static tt_result tt__require_triangles(const tt_mesh *mesh, const char *why, tt_error *error)
{
    int f;
    for (f = 0; f < mesh->nfaces; f++) {
        int count = mesh->face_start[f + 1] - mesh->face_start[f];
        if (count != 3)
            return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, f, mesh->face_start[f], -1, -1,
                            "face %d has %d corners: %s", f, count, why);
    }
    return TT_OK;
}

/* Mean of a face's corner positions. */
static void tt__face_centroid(const tt_mesh *mesh, int face, double centroid[3])
{
    const int begin = mesh->face_start[face], end = mesh->face_start[face + 1];
    int c, k;
    centroid[0] = centroid[1] = centroid[2] = 0.0;
    for (c = begin; c < end; c++)
        for (k = 0; k < 3; k++) centroid[k] += mesh->pos[3 * (size_t)mesh->corner_vert[c] + k];
    for (k = 0; k < 3; k++) centroid[k] /= (double)(end - begin);
}

TTDEF void tt_face_normal(const tt_mesh *mesh, int face, float normal[3])
{
    double n[3];
    TT_ASSERT(mesh && normal && face >= 0 && face < mesh->nfaces);
    tt__face_normal_d(mesh, face, n);
    normal[0] = (float)n[0]; normal[1] = (float)n[1]; normal[2] = (float)n[2];
}

#define TT__NOT_WRITTEN 2.0f

/* The angle of face corner c between its two edges (0 for a degenerate one). */
static double tt__corner_angle(const tt_mesh *mesh, int c)
{
    const float *p = mesh->pos + 3 * (size_t)mesh->corner_vert[c];
    const float *a = mesh->pos + 3 * (size_t)mesh->corner_vert[tt_mesh_next(mesh, c)];
    const float *b = mesh->pos + 3 * (size_t)mesh->corner_vert[tt_mesh_prev(mesh, c)];
    double u[3], v[3], cross[3];
    tt__sub3f(a, p, u);
    tt__sub3f(b, p, v);
    tt__cross3(u, v, cross);
    return atan2(tt__length3(cross), tt__dot3(u, v));
}

TTDEF tt_result tt_corner_normals(const tt_mesh *mesh, float crease_degrees, const tt_allocator *allocator,
                                  float *corner_normal, tt_error *error)
{
    double *face_normal, cos_crease;
    int *fan, c, f;
    tt__ok(error);
    if (!mesh || !corner_normal)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "tt_corner_normals needs a mesh and an output array (got NULL)");
    if (!(crease_degrees >= 0.0f && crease_degrees <= 180.0f))
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "crease angle %g degrees: it must be from 0 (flat) to 180 (smooth everywhere)",
                        (double)crease_degrees);
    if (tt__check_allocator(allocator, error) != TT_OK) return TT_ERROR_INVALID_ARGUMENT;
    face_normal = TT__ALLOC(allocator, double, 3 * (size_t)(mesh->nfaces > 0 ? mesh->nfaces : 1));
    fan = TT__ALLOC(allocator, int, mesh->ncorners > 0 ? mesh->ncorners : 1);
    if (!face_normal || !fan) {
        tt__free(allocator, face_normal);
        tt__free(allocator, fan);
        return tt__fail(error, TT_ERROR_OUT_OF_MEMORY, -1, -1, -1, -1, "out of memory for the normals of %d faces",
                        mesh->nfaces);
    }
    /* Exactly -1 at 180 degrees would still leave out faces turned fully back
       out; the margin takes them in. */
    cos_crease = crease_degrees >= 180.0f ? -2.0 : cos((double)crease_degrees * (TT__PI / 180.0));
    for (f = 0; f < mesh->nfaces; f++)
        if (!tt__face_normal_d(mesh, f, face_normal + 3 * (size_t)f))
            face_normal[3 * (size_t)f] = face_normal[3 * (size_t)f + 1] = face_normal[3 * (size_t)f + 2] = 0.0;
    /* Each fan is written once, marked until then by an x no unit normal
       has (a permissive mesh's cut-open vertex has several fans). */
    for (c = 0; c < mesh->ncorners; c++) corner_normal[3 * (size_t)c] = TT__NOT_WRITTEN;
    for (c = 0; c < mesh->ncorners; c++) {
        /* The fan of corners around c's vertex that c belongs to: back to
           its start (a boundary, or all the way round), then forward, the
           turn of tt__fan_size. */
        int start = c, h, count = 0, guard = 0, i, j;
        if (corner_normal[3 * (size_t)c] != TT__NOT_WRITTEN) continue;
        while (guard++ < mesh->ncorners) {
            int back = mesh->twin[start];
            if (back < 0 || (back = tt_mesh_next(mesh, back)) == c) break;
            start = back;
        }
        h = start;
        while (h >= 0 && count < mesh->ncorners) {
            fan[count++] = h;
            h = mesh->twin[tt_mesh_prev(mesh, h)];
            if (h == start) break;
        }
        for (i = 0; i < count; i++) {
            const double *own = face_normal + 3 * (size_t)mesh->corner_face[fan[i]];
            double sum[3] = {0.0, 0.0, 0.0}, length;
            float *out = corner_normal + 3 * (size_t)fan[i];
            for (j = 0; j < count; j++) {
                const double *other = face_normal + 3 * (size_t)mesh->corner_face[fan[j]];
                double weight;
                if (j != i && tt__dot3(own, other) < cos_crease) continue;
                weight = tt__corner_angle(mesh, fan[j]);
                sum[0] += weight * other[0];
                sum[1] += weight * other[1];
                sum[2] += weight * other[2];
            }
            length = tt__length3(sum);
            out[0] = length > 0.0 ? (float)(sum[0] / length) : 0.0f;
            out[1] = length > 0.0 ? (float)(sum[1] / length) : 0.0f;
            out[2] = length > 0.0 ? (float)(sum[2] / length) : 0.0f;
        }
    }
    tt__free(allocator, face_normal);
    tt__free(allocator, fan);
    return TT_OK;
}

/* A problem found while pairing twins; the one with the smallest corner is
   reported, so the error names the first problem in index-buffer order. */
typedef struct tt__edge_problem {
    int corner;              /* -1: none */
    tt_result result;
    int a, b;                /* the edge, as vertices */
    int faces[3];
    int nfaces;
} tt__edge_problem;

static tt_result tt__report_edge_problem(const tt__edge_problem *p, tt_error *error)
{
    if (p->result == TT_ERROR_INCONSISTENT_ORIENTATION)
        tt__fail(error, p->result, p->faces[0], p->corner, p->a, p->b,
                 "faces %d and %d both run along the edge from vertex %d to vertex %d in the same direction: one "
                 "of them is flipped (fix its winding, or build with TT_MESH_PERMISSIVE)",
                 p->faces[0], p->faces[1], p->a, p->b);
    else
        tt__fail(error, p->result, p->faces[0], p->corner, p->a, p->b,
                 "the edge between vertices %d and %d is shared by %d faces (%d, %d, %d%s): a surface edge can "
                 "border at most two (build with TT_MESH_PERMISSIVE to cut it open)",
                 p->a, p->b, p->nfaces, p->faces[0], p->faces[1], p->faces[2], p->nfaces > 3 ? ", ..." : "");
    if (error) error->other_face = p->faces[1];
    return p->result;
}

/* Number of outgoing half-edges met turning around v from vert_corner[v] (a
   boundary half-edge when v has one) by h -> twin(prev(h)). A vertex is
   manifold exactly when this reaches all of its outgoing half-edges. */
static int tt__fan_size(const tt_mesh *mesh, int v)
{
    /* All triangles or all quads (the usual meshes): prev is arithmetic with
       a constant divisor, no face lookups. */
    int start = mesh->vert_corner[v], h = start, visited = 1;
    int k = mesh->min_face_size == mesh->max_face_size ? mesh->min_face_size : 0;
    if (start < 0) return 0;
    while (visited <= mesh->ncorners) {
        int prev = k == 4 ? ((h & 3) == 0 ? h + 3 : h - 1)
                 : k == 3 ? (h % 3 == 0 ? h + 2 : h - 1)
                 : tt_mesh_prev(mesh, h);
        int next = mesh->twin[prev];
        if (next < 0 || next == start) break;
        h = next;
        visited++;
    }
    return visited;
}

/* The face of corner c from face_start alone (binary search): for the build's
   error path, while corner_face still holds the pairing buckets. */
static int tt__face_of_corner(const tt_mesh *mesh, int corner)
{
    int lo = 0, hi = mesh->nfaces - 1;
    while (lo < hi) {
        int mid = lo + (hi - lo + 1) / 2;
        if (mesh->face_start[mid] <= corner) lo = mid; else hi = mid - 1;
    }
    return lo;
}

/* A hint that memory is about to be read; it does nothing where the
   compiler has no prefetch builtin. */
#if defined(__GNUC__) || defined(__clang__)
#define TT__PREFETCH(address) __builtin_prefetch(address)
#else
#define TT__PREFETCH(address) ((void)0)
#endif

/* How many corners ahead the builder prefetches a vertex's id and position. */
#define TT__BUILD_PREFETCH 48

/* Forced inlining, so that the builder's face loop is compiled once per fixed
   face size (3, 4) with the per-face loops unrolled. */
#if defined(__GNUC__) || defined(__clang__)
#define TT__BUILD_INLINE __attribute__((always_inline)) inline
#elif defined(_MSC_VER)
#define TT__BUILD_INLINE __forceinline
#else
#define TT__BUILD_INLINE
#endif

/* The state of one tt_mesh_build, handed from phase to phase (see
   tt_mesh_build). While the build runs, the mesh's own arrays hold much of
   its scratch (each phase says what they hold), so that its largest arrays
   cost no extra memory. A local id numbers the used vertices in order of
   first use; there are nused <= nlocal = min(nverts, ncorners) of them. */
typedef struct tt__builder {
    const tt_mesh_desc *desc;
    const tt_allocator *allocator;
    const int *indices;
    const float *positions;
    int nverts, nfaces, ncorners, nlocal;
    int fixed_size;     /* every face's corners, or 0 when desc->face_sizes gives them */
    int permissive;
    tt_mesh *mesh;      /* the result, its arrays allocated */
    float *copy;        /* the mesh's own copy of the positions; NULL when borrowed */
    /* The face loop (tt__build_face). */
    int nused;          /* local ids handed out so far */
    int *local_of;      /* nverts: local id of a vertex, -1 unseen (the mesh's vert_corner) */
    int *lid;           /* ncorners: local id of corner c's vertex (the mesh's corner_vert) */
    int *last;          /* nlocal: the last corner of a local id so far (the mesh's corner_face) */
    int *out_count;     /* nlocal: outgoing half-edges */
    int *inverse;       /* nlocal: the vertex of a local id */
    int *count;         /* nlocal: edges in the bucket of a local id (bucket_start + 1) */
    int *stamp;         /* nverts: tt__repeated_corner's marks, for strict faces over 16 corners */
    /* The pairing. */
    int *bucket_start;  /* nlocal + 1: each local id's bucket of edges, see tt__build_buckets */
    int largest_bucket; /* entries in the largest bucket */
    uint64_t *keys;     /* largest_bucket: one bucket's entries, to sort */
    int boundary;       /* whether some half-edge has no twin */
} tt__builder;

/* One face of the face loop: range-check its corners, number their
   vertices, count its edges into buckets, and (strict) check it for repeated
   vertices and zero area. Called with a constant size for all-triangle and
   all-quad meshes, so that the loops unroll, and a constant `prefetch`. */
static TT__BUILD_INLINE tt_result tt__build_face(tt__builder *b, int f, int first, int size, int prefetch,
                                                 int *stamp, tt_error *error)
{
    int i, c, repeated;
    const int *verts = b->indices + first;
    for (i = 0, c = first; i < size; i++, c++) {
        int vert = b->indices[c], l;
        if (prefetch && c + TT__BUILD_PREFETCH < b->ncorners) {
            /* With scattered vertex ids these two reads are the build's
               cache misses: start them early. */
            unsigned ahead = (unsigned)b->indices[c + TT__BUILD_PREFETCH];
            if (ahead < (unsigned)b->nverts) {
                TT__PREFETCH(b->local_of + ahead);
                if (!b->permissive) TT__PREFETCH(b->positions + 3 * (size_t)ahead);
            }
        }
        if (vert < 0 || vert >= b->nverts)
            return tt__fail(error, TT_ERROR_INDEX_OUT_OF_RANGE, f, c, vert, -1,
                            "face %d (corner %d) refers to vertex %d, but the mesh has %d vertices (0..%d)", f, c,
                            vert, b->nverts, b->nverts - 1);
        l = b->local_of[vert];
        if (l < 0) {
            l = b->nused++;
            b->local_of[vert] = l;
            b->inverse[l] = vert;
            b->out_count[l] = 0;
            b->count[l] = 0;
        }
        b->out_count[l]++;
        b->last[l] = c;
        b->lid[c] = l;
    }
    for (i = 0; i < size; i++) {
        int x = b->lid[first + i], y = b->lid[first + (i + 1 < size ? i + 1 : 0)];
        b->count[x < y ? x : y]++;
    }
    if (b->permissive) return TT_OK;
    /* A repeated vertex makes a degenerate edge or pinches the face. */
    repeated = tt__repeated_corner(verts, size, f, size > 16 ? stamp : NULL);
    if (repeated >= 0)
        return tt__fail(error, TT_ERROR_REPEATED_VERTEX, f, first + repeated, verts[repeated], -1,
                        "face %d uses vertex %d more than once (corner %d)", f, verts[repeated], first + repeated);
    if (tt__face_has_zero_area(b->positions, verts, size))
        return tt__fail(error, TT_ERROR_ZERO_AREA_FACE, f, first, verts[0], -1,
                        "face %d has zero area: its %d corners coincide or lie on one line", f, size);
    return TT_OK;
}

/* Whether the face loop should prefetch: when many consecutive corners'
   vertex ids are far apart (shuffled ids: about 3 in 4 steps of a quad mesh,
   the others are shared corners), where it saves most of the cache misses;
   ids that follow the index buffer (grids, welded files) are served by the
   caches, and the prefetches would only cost instructions. Judged on four
   samples of 256 corners spread over the index buffer; in doubt, prefetch
   (a needless prefetch costs far less than a missing one). */
static int tt__build_should_prefetch(const int *indices, int ncorners)
{
    int window = 256, far = 0, pairs = 0, w, c;
    if (ncorners < 4 * window) return 1;
    for (w = 0; w < 4; w++) {
        int first = (int)((long long)(ncorners - window) * w / 3);
        for (c = first + 1; c < first + window; c++, pairs++) {
            long long step = (long long)indices[c] - indices[c - 1];
            far += step > 4096 || step < -4096;
        }
    }
    return far * 5 > pairs * 2;
}

/* Put a face's half-edges into the buckets of their edges' smaller local id
   (slot[l]: the next free entry of bucket l), an entry's fields in two arrays:
   other[] and corner_dir[] (see TT__EDGE_KEY). */
static TT__BUILD_INLINE void tt__scatter_face(const int *lid, int first, int size, int *slot, int *other,
                                              int *corner_dir)
{
    int i, a = lid[first];
    for (i = 0; i < size; i++) {
        int b = lid[i + 1 < size ? first + i + 1 : first], at = slot[a < b ? a : b]++;
        other[at] = a < b ? b : a;
        corner_dir[at] = 2 * (first + i) + (a > b);
        a = b;
    }
}

/* A mesh with its arrays allocated (positions excepted), or NULL. */
static tt_mesh *tt__mesh_alloc(const tt_allocator *allocator, int nverts, int nfaces, int ncorners, unsigned flags)
{
    tt_mesh *mesh = TT__ALLOC(allocator, tt_mesh, 1);
    if (!mesh) return NULL;
    memset(mesh, 0, sizeof *mesh);
    mesh->allocator = tt__allocator_copy(allocator);
    mesh->flags = flags;
    mesh->nverts = nverts;
    mesh->nfaces = nfaces;
    mesh->ncorners = ncorners;
    mesh->face_start = TT__ALLOC(allocator, int, (size_t)nfaces + 1);
    mesh->corner_vert = TT__ALLOC(allocator, int, ncorners);
    mesh->corner_face = TT__ALLOC(allocator, int, ncorners);
    mesh->twin = TT__ALLOC(allocator, int, ncorners);
    mesh->vert_corner = TT__ALLOC(allocator, int, nverts);
    if (!mesh->face_start || !mesh->corner_vert || !mesh->corner_face || !mesh->twin || !mesh->vert_corner) {
        tt_mesh_free(mesh);
        return NULL;
    }
    return mesh;
}

/* Phase 1: the counts and the face sizes, checked before anything is
   allocated: they decide how many corners there are, and so how large
   every array is. */
static tt_result tt__build_check_counts(tt__builder *b, tt_error *error)
{
    const tt_mesh_desc *desc = b->desc;
    long long total_corners;
    int f;
    b->permissive = (desc->flags & TT_MESH_PERMISSIVE) != 0;
    b->nverts = desc->nverts;
    b->nfaces = desc->nfaces;
    b->indices = desc->indices;
    b->positions = desc->positions;
    if (b->nverts < 0 || b->nfaces < 0)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "negative count: nverts = %d, nfaces = %d", b->nverts, b->nfaces);
    if (b->nfaces == 0) return tt__fail(error, TT_ERROR_EMPTY_MESH, -1, -1, -1, -1, "the mesh has no faces");
    if (!desc->indices || (b->nverts > 0 && !desc->positions))
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "desc->indices or desc->positions is NULL");
    b->fixed_size = desc->face_sizes ? 0 : (desc->fixed_face_size ? desc->fixed_face_size : 3);
    if (desc->face_sizes) {
        total_corners = 0;
        for (f = 0; f < b->nfaces; f++) {
            int size = desc->face_sizes[f];
            if (size < 3)
                return tt__fail(error, TT_ERROR_FACE_TOO_SMALL, f, size > 0 ? (int)total_corners : -1, -1, -1,
                                "face %d has %d corners; a face needs at least 3", f, size);
            total_corners += size;
            if (total_corners > 0x3fffffff)
                return tt__fail(error, TT_ERROR_TOO_LARGE, f, -1, -1, -1,
                                "the faces have more than %d corners in all", 0x3fffffff);
        }
    } else {
        if (b->fixed_size < 3)
            return tt__fail(error, TT_ERROR_FACE_TOO_SMALL, 0, 0, -1, -1,
                            "fixed_face_size is %d; a face needs at least 3 corners", b->fixed_size);
        total_corners = (long long)b->nfaces * b->fixed_size;
        if (total_corners > 0x3fffffff)
            return tt__fail(error, TT_ERROR_TOO_LARGE, -1, -1, -1, -1,
                            "%d faces of %d corners are more than %d corners", b->nfaces, b->fixed_size,
                            0x3fffffff);
    }
    b->ncorners = (int)total_corners;
    b->nlocal = b->nverts < b->ncorners ? b->nverts : b->ncorners;
    return TT_OK;
}

/* Phase 2: the mesh, the per-local-id scratch, and the mesh's copy of the
   positions (or the caller's, borrowed), together, so that most builds too
   large for memory fail before any work is done. (Two smaller arrays come
   later: the sort buffer, sized by the largest bucket, and the marks for
   faces of over 16 corners.) */
static tt_result tt__build_alloc(tt__builder *b, tt_error *error)
{
    const tt_allocator *allocator = b->allocator;
    tt_mesh *mesh = tt__mesh_alloc(allocator, b->nverts, b->nfaces, b->ncorners,
                                   b->desc->flags & ~(unsigned)TT_MESH_BORROW_POSITIONS);
    b->mesh = mesh;
    if (mesh) {
        b->bucket_start = TT__ALLOC(allocator, int, (size_t)b->nlocal + 1);
        b->out_count = TT__ALLOC(allocator, int, b->nlocal);
        b->inverse = TT__ALLOC(allocator, int, b->nlocal);
        if (b->desc->flags & TT_MESH_BORROW_POSITIONS) {
            mesh->flags = b->desc->flags;
            mesh->pos = b->positions;
        } else {
            b->copy = TT__ALLOC(allocator, float, (size_t)b->nverts * 3);
            mesh->pos = b->copy;
        }
    }
    if (!mesh || !b->bucket_start || !b->out_count || !b->inverse || !mesh->pos)
        return tt__fail(error, TT_ERROR_OUT_OF_MEMORY, -1, -1, -1, -1,
                        "out of memory for a mesh of %d faces and %d corners", b->nfaces, b->ncorners);
    return TT_OK;
}

/* Phase 3: coordinates must be finite, since everything downstream measures
   lengths; copied unless borrowed. Whole blocks of 1024 vertices are copied
   and then tested while in the cache, without branches (the loop
   vectorises); a block with a bad coordinate, and the tail, vertex by
   vertex, to name the first bad vertex. */
static tt_result tt__build_positions(tt__builder *b, tt_error *error)
{
    const float *positions = b->positions;
    float *copy = b->copy;
    int nverts = b->nverts, v;
    for (v = 0; v + 1024 <= nverts; v += 1024) {
        const float *p = positions + 3 * (size_t)v;
        uint32_t bad = 0;
        int k;
        if (copy) memcpy(copy + 3 * (size_t)v, p, 3 * 1024 * sizeof(float));
        for (k = 0; k < 3 * 1024; k++) {
            uint32_t bits;
            memcpy(&bits, p + k, sizeof bits);
            bad |= (bits & 0x7f800000u) == 0x7f800000u;
        }
        if (bad) break;
    }
    for (; v < nverts; v++) {
        const float *p = positions + 3 * (size_t)v;
        if (!tt__is_finite(p[0]) || !tt__is_finite(p[1]) || !tt__is_finite(p[2]))
            return tt__fail(error, TT_ERROR_NON_FINITE, -1, -1, v, -1,
                            "vertex %d has a coordinate that is NaN or infinite (%g, %g, %g)", v, p[0], p[1],
                            p[2]);
        if (copy) memcpy(copy + 3 * (size_t)v, p, 3 * sizeof(float));
    }
    return TT_OK;
}

/* Phase 4, the face loop (tt__build_face on every face, in order): range-
   check the corners, check strict faces for repeated vertices and zero
   area, and give the used vertices local ids in order of first use (the
   index buffer's order). Everything the pairing touches afterwards is
   indexed by corner or by local id, so it runs through memory in
   index-buffer order whatever the numbering of the vertices: a mesh with
   shuffled vertex ids costs about what a grid-ordered one does. Also fills
   face_start and the face size range, and counts each edge in the bucket of
   its end with the smaller local id. Afterwards vert_corner[v] is the last
   corner of v, an outgoing half-edge (-1: unused). */
static tt_result tt__build_faces(tt__builder *b, tt_error *error)
{
    /* The loop works on a local copy of the builder: stores through its
       arrays could otherwise alias its int fields, which would then be
       reloaded at every corner. */
    tt__builder s = *b;
    tt_mesh *mesh = s.mesh;
    int nfaces = s.nfaces, prefetch = tt__build_should_prefetch(s.indices, s.ncorners), f, c, l;
    tt_result result = TT_OK;
    s.local_of = mesh->vert_corner;
    s.lid = mesh->corner_vert;
    s.last = mesh->corner_face;
    s.count = s.bucket_start + 1;
    s.nused = 0;
    memset(s.local_of, 0xff, (size_t)s.nverts * sizeof(int));
    s.bucket_start[0] = 0;
    if (s.fixed_size == 3) {
        mesh->min_face_size = mesh->max_face_size = 3;
        for (f = 0; f < nfaces && result == TT_OK; f++) {
            mesh->face_start[f] = 3 * f;
            result = prefetch ? tt__build_face(&s, f, 3 * f, 3, 1, NULL, error)
                              : tt__build_face(&s, f, 3 * f, 3, 0, NULL, error);
        }
    } else if (s.fixed_size == 4) {
        mesh->min_face_size = mesh->max_face_size = 4;
        for (f = 0; f < nfaces && result == TT_OK; f++) {
            mesh->face_start[f] = 4 * f;
            result = prefetch ? tt__build_face(&s, f, 4 * f, 4, 1, NULL, error)
                              : tt__build_face(&s, f, 4 * f, 4, 0, NULL, error);
        }
    } else {
        for (f = 0, c = 0; f < nfaces && result == TT_OK; f++) {
            int size = s.fixed_size ? s.fixed_size : s.desc->face_sizes[f];
            mesh->face_start[f] = c;
            if (size > mesh->max_face_size) mesh->max_face_size = size;
            if (f == 0 || size < mesh->min_face_size) mesh->min_face_size = size;
            if (size > 16 && !s.permissive && !s.stamp) {
                s.stamp = TT__ALLOC(s.allocator, int, s.nverts);
                if (!s.stamp) {
                    result = tt__fail(error, TT_ERROR_OUT_OF_MEMORY, -1, -1, -1, -1, "out of memory");
                    break;
                }
                memset(s.stamp, 0xff, (size_t)s.nverts * sizeof(int));
            }
            result = tt__build_face(&s, f, c, size, prefetch, s.stamp, error);
            c += size;
        }
    }
    *b = s;
    if (result != TT_OK) return result;
    mesh->face_start[nfaces] = s.ncorners;
    for (l = 0; l < s.nused; l++) mesh->vert_corner[s.inverse[l]] = s.last[l];
    return TT_OK;
}

/* Phase 5: a counting sort of the half-edges into the buckets of their
   edges' smaller local ids, so that an edge's halves meet in one small
   bucket. An entry (TT__EDGE_KEY: the other end's local id, and
   2 * corner + 1 when the half-edge runs from the larger local id to the
   smaller) is split between corner_face (other) and twin (corner_dir),
   which are only filled at the end: with the far end in the entry, the
   pairing reads nothing else, and no extra memory for the largest arrays of
   the build. Afterwards bucket_start[l] is where bucket l ends. */
static void tt__build_buckets(tt__builder *b)
{
    tt_mesh *mesh = b->mesh;
    int *bucket_start = b->bucket_start, *lid = mesh->corner_vert, *other = mesh->corner_face;
    int *corner_dir = mesh->twin, nfaces = b->nfaces, nused = b->nused, largest = 0, f, l;
    for (l = 0; l < nused; l++) {
        if (bucket_start[l + 1] > largest) largest = bucket_start[l + 1];
        bucket_start[l + 1] += bucket_start[l];
    }
    b->largest_bucket = largest;
    if (b->fixed_size == 3) {
        for (f = 0; f < nfaces; f++) tt__scatter_face(lid, 3 * f, 3, bucket_start, other, corner_dir);
    } else if (b->fixed_size == 4) {
        for (f = 0; f < nfaces; f++) tt__scatter_face(lid, 4 * f, 4, bucket_start, other, corner_dir);
    } else {
        for (f = 0; f < nfaces; f++)
            tt__scatter_face(lid, mesh->face_start[f], mesh->face_start[f + 1] - mesh->face_start[f], bucket_start,
                             other, corner_dir);
    }
}

/* The usual bucket, sorted (see tt__build_pair_twins): every edge an
   interior one, its two halves side by side, one each way. Checked, and then
   paired, without branches; 0 when the bucket is not like that. */
static TT__BUILD_INLINE int tt__pair_interior_bucket(const uint64_t *e, int count, int l, int *twin)
{
    int paired = (count & 1) == 0, k;
    for (k = 0; paired && k < count; k += 2) {
        uint64_t x = e[k], y = e[k + 1];
        paired = ((x ^ y) >> 32) == 0 && ((x ^ y) & 1) && TT__KEY_OTHER(x) != l &&
                 (k + 2 == count || TT__KEY_OTHER(e[k + 2]) != TT__KEY_OTHER(x));
    }
    if (!paired) return 0;
    for (k = 0; k < count; k += 2) {
        int x = TT__KEY_CORNER_DIR(e[k]) >> 1, y = TT__KEY_CORNER_DIR(e[k + 1]) >> 1;
        twin[x] = y;
        twin[y] = x;
    }
    return 1;
}

/* Any other bucket, sorted, run by run of equal `other` (one run, one edge):
   one half-edge each way is an interior edge, a single one a boundary;
   anything else is non-manifold (three or more) or flipped (two the same
   way), and cut loose into boundaries. In strict mode the problem with the
   smallest corner is kept in *problem, so that errors come in index-buffer
   order. */
static void tt__pair_bucket_runs(tt__builder *b, const uint64_t *e, int count, int l, int *twin,
                                 tt__edge_problem *problem)
{
    int i = 0, k;
    while (i < count) {
        int other = TT__KEY_OTHER(e[i]), run_end = i + 1, backward = TT__KEY_CORNER_DIR(e[i]) & 1;
        while (run_end < count && TT__KEY_OTHER(e[run_end]) == other)
            backward += TT__KEY_CORNER_DIR(e[run_end++]) & 1;
        if (other != l && run_end - i == 2 && backward == 1) {
            int x = TT__KEY_CORNER_DIR(e[i]) >> 1, y = TT__KEY_CORNER_DIR(e[i + 1]) >> 1;
            twin[x] = y;
            twin[y] = x;
        } else if (other != l && run_end - i == 1) {
            twin[TT__KEY_CORNER_DIR(e[i]) >> 1] = -1;
            b->boundary = 1;
        } else {
            int lowest = TT__KEY_CORNER_DIR(e[i]) >> 1;
            if (!b->permissive && other != l && (problem->corner < 0 || lowest < problem->corner)) {
                problem->corner = lowest;
                problem->a = b->indices[lowest];
                problem->b = problem->a == b->inverse[l] ? b->inverse[other] : b->inverse[l];
                problem->result = run_end - i > 2 ? TT_ERROR_NON_MANIFOLD_EDGE : TT_ERROR_INCONSISTENT_ORIENTATION;
                problem->nfaces = run_end - i;
                for (k = 0; k < 3; k++)
                    problem->faces[k] =
                        i + k < run_end ? tt__face_of_corner(b->mesh, TT__KEY_CORNER_DIR(e[i + k]) >> 1) : -1;
            }
            for (k = i; k < run_end; k++) twin[TT__KEY_CORNER_DIR(e[k]) >> 1] = -1;
            b->boundary = 1;
            b->mesh->repaired_edges++;
        }
        i = run_end;
    }
}

/* Phase 6: pair the twins bucket by bucket, each bucket's entries sorted by
   (other end, corner) so that the halves of an edge sit side by side in
   corner order, and find the edge problems (strict mode fails on the first).
   The local ids are no longer needed: the twins go into corner_vert's
   array, which then becomes twin, while twin's array becomes corner_vert (a
   copy of the indices). */
static tt_result tt__build_pair_twins(tt__builder *b, tt_error *error)
{
    tt_mesh *mesh = b->mesh;
    const int *bucket_start = b->bucket_start, *other = mesh->corner_face, *corner_dir = mesh->twin;
    int *twin = mesh->corner_vert, nused = b->nused, l, k;
    uint64_t *e;
    tt__edge_problem problem;
    e = b->keys = TT__ALLOC(b->allocator, uint64_t, b->largest_bucket);
    if (!e) return tt__fail(error, TT_ERROR_OUT_OF_MEMORY, -1, -1, -1, -1, "out of memory");
    memset(&problem, 0, sizeof problem);
    problem.corner = -1;
    for (l = 0; l < nused; l++) {
        int begin = l > 0 ? bucket_start[l - 1] : 0, count = bucket_start[l] - begin;
        for (k = 0; k < count; k++) e[k] = TT__EDGE_KEY(other[begin + k], corner_dir[begin + k]);
        tt__sort_edge_keys(e, count);
        if (!tt__pair_interior_bucket(e, count, l, twin)) tt__pair_bucket_runs(b, e, count, l, twin, &problem);
    }
    mesh->corner_vert = mesh->twin;
    mesh->twin = twin;
    memcpy(mesh->corner_vert, b->indices, (size_t)b->ncorners * sizeof(int));
    if (problem.corner >= 0) return tt__report_edge_problem(&problem, error);
    if (!b->permissive) mesh->repaired_edges = 0;
    return TT_OK;
}

/* Phase 7, when some half-edge has no twin: vert_corner prefers a boundary
   half-edge (the fan walks and tt_mesh_valence start there). Of a vertex's
   boundary half-edges, the one to the largest vertex id (then the largest
   corner), whatever order they were paired in. */
static void tt__build_prefer_boundary(tt__builder *b)
{
    tt_mesh *mesh = b->mesh;
    int f, c;
    for (f = 0; f < b->nfaces; f++) {
        int first = mesh->face_start[f], end = mesh->face_start[f + 1];
        for (c = first; c < end; c++)
            if (mesh->twin[c] < 0) {
                int u = mesh->corner_vert[c], w = mesh->corner_vert[c + 1 < end ? c + 1 : first];
                int cur = mesh->vert_corner[u], cur_face = tt__face_of_corner(mesh, cur), cur_w;
                cur_w = mesh->corner_vert[cur + 1 < mesh->face_start[cur_face + 1] ? cur + 1
                                                                                    : mesh->face_start[cur_face]];
                if (mesh->twin[cur] >= 0 || cur_w < w || (cur_w == w && cur < c)) mesh->vert_corner[u] = c;
            }
    }
}

/* Phase 8, strict mode: every vertex's faces must form one fan
   (tt__fan_size's walk reaches all of its outgoing half-edges); the
   smallest vertex id that does not is reported. The walk is a chain of
   dependent loads, so each step is made one load: corner_face first holds
   fan_next[h] = twin[prev(h)]. */
static tt_result tt__build_check_fans(tt__builder *b, tt_error *error)
{
    tt_mesh *mesh = b->mesh;
    const int *inverse = b->inverse, *out_count = b->out_count;
    int bad = -1, bad_local = -1, *fan_next = mesh->corner_face, f, c, l;
    for (f = 0; f < b->nfaces; f++) {
        int first = mesh->face_start[f], end = mesh->face_start[f + 1];
        fan_next[first] = mesh->twin[end - 1];
        for (c = first + 1; c < end; c++) fan_next[c] = mesh->twin[c - 1];
    }
    for (l = 0; l < b->nused; l++) {
        int start = mesh->vert_corner[inverse[l]], h = start, fan = 1, next;
        while ((next = fan_next[h]) >= 0 && next != start) h = next, fan++;
        if (fan != out_count[l] && (bad < 0 || inverse[l] < bad)) {
            bad = inverse[l];
            bad_local = l;
        }
    }
    if (bad >= 0) {
        int bad_corner = mesh->vert_corner[bad];
        return tt__fail(error, TT_ERROR_NON_MANIFOLD_VERTEX, tt__face_of_corner(mesh, bad_corner), bad_corner, bad,
                        -1,
                        "vertex %d is non-manifold: its %d faces form more than one fan (surfaces "
                        "touching at a point); build with TT_MESH_PERMISSIVE to accept it",
                        bad, out_count[bad_local]);
    }
    return TT_OK;
}

/* Phase 9: corner_face, the last array still holding scratch. */
static void tt__build_corner_faces(tt__builder *b)
{
    tt_mesh *mesh = b->mesh;
    int f, c;
    for (f = 0; f < b->nfaces; f++)
        for (c = mesh->face_start[f]; c < mesh->face_start[f + 1]; c++) mesh->corner_face[c] = f;
}

/* The build as a driver of its phases (above, in order). Each phase leaves
   the builder ready for the next, or fails with the error filled in; the
   scratch is freed either way, and the mesh too on failure. */
TTDEF tt_result tt_mesh_build(const tt_mesh_desc *desc, const tt_allocator *allocator, tt_mesh **out_mesh,
                              tt_error *error)
{
    tt__builder b;
    tt_result result;
    tt__ok(error);
    if (!out_mesh) return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1, "out_mesh is NULL");
    *out_mesh = NULL;
    if (!desc) return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1, "desc is NULL");
    if (tt__check_allocator(allocator, error) != TT_OK) return TT_ERROR_INVALID_ARGUMENT;
    memset(&b, 0, sizeof b);
    b.desc = desc;
    b.allocator = allocator;
    result = tt__build_check_counts(&b, error);
    if (result != TT_OK) return result;

    result = tt__build_alloc(&b, error);
    if (result == TT_OK) result = tt__build_positions(&b, error);
    if (result == TT_OK) result = tt__build_faces(&b, error);
    if (result == TT_OK) {
        tt__build_buckets(&b);
        result = tt__build_pair_twins(&b, error);
    }
    if (result == TT_OK && b.boundary) tt__build_prefer_boundary(&b);
    if (result == TT_OK && !b.permissive) result = tt__build_check_fans(&b, error);
    if (result == TT_OK) tt__build_corner_faces(&b);

    tt__free(allocator, b.bucket_start);
    tt__free(allocator, b.out_count);
    tt__free(allocator, b.inverse);
    tt__free(allocator, b.keys);
    tt__free(allocator, b.stamp);
    if (result != TT_OK) {
        tt_mesh_free(b.mesh);
        return result;
    }
    *out_mesh = b.mesh;
    return TT_OK;
}

TTDEF int tt_mesh_valence(const tt_mesh *mesh, int vertex)
{
    /* Edges at a vertex: one per outgoing half-edge of its fan, plus the
       incoming boundary edge that closes an open fan (vert_corner is a
       boundary half-edge exactly when the fan is open). */
    TT_ASSERT(mesh && vertex >= 0 && vertex < mesh->nverts);
    if (!mesh || vertex < 0 || vertex >= mesh->nverts || mesh->vert_corner[vertex] < 0) return 0;
    return tt__fan_size(mesh, vertex) + (mesh->twin[mesh->vert_corner[vertex]] < 0 ? 1 : 0);
}

/* valence[v] for every vertex in O(corners), counting edges rather than walking
   fans so that it is right for non-manifold vertices too. */
static void tt__valences(const tt_mesh *mesh, int *valence)
{
    int c;
    memset(valence, 0, (size_t)mesh->nverts * sizeof(int));
    for (c = 0; c < mesh->ncorners; c++) {
        valence[mesh->corner_vert[c]]++;
        if (mesh->twin[c] < 0) valence[mesh->corner_vert[tt_mesh_next(mesh, c)]]++;
    }
}

TTDEF tt_result tt_mesh_valence_histogram(const tt_mesh *mesh, const tt_allocator *allocator, int *histogram,
                                          int nbins, tt_error *error)
{
    int *valence, v;
    tt__ok(error);
    if (!mesh || !histogram)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1, "the mesh or the histogram is NULL");
    if (nbins < 1)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1, "nbins is %d: need at least 1", nbins);
    if (tt__check_allocator(allocator, error) != TT_OK) return TT_ERROR_INVALID_ARGUMENT;
    valence = TT__ALLOC(allocator, int, mesh->nverts);
    if (!valence)
        return tt__fail(error, TT_ERROR_OUT_OF_MEMORY, -1, -1, -1, -1, "out of memory counting valences");
    tt__valences(mesh, valence);
    memset(histogram, 0, (size_t)nbins * sizeof(int));
    for (v = 0; v < mesh->nverts; v++)
        if (mesh->vert_corner[v] >= 0) histogram[tt__min_i(valence[v], nbins - 1)]++;
    tt__free(allocator, valence);
    return TT_OK;
}

TTDEF tt_result tt_mesh_components(const tt_mesh *mesh, const tt_allocator *allocator, int *face_component,
                                   int *ncomponents, tt_error *error)
{
    int *queue, f, count = 0;
    tt__ok(error);
    if (!mesh || !face_component || !ncomponents)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "tt_mesh_components needs a mesh and both outputs (got NULL)");
    if (tt__check_allocator(allocator, error) != TT_OK) return TT_ERROR_INVALID_ARGUMENT;
    queue = TT__ALLOC(allocator, int, mesh->nfaces);
    if (!queue)
        return tt__fail(error, TT_ERROR_OUT_OF_MEMORY, -1, -1, -1, -1, "out of memory finding components");
    for (f = 0; f < mesh->nfaces; f++) face_component[f] = -1;
    for (f = 0; f < mesh->nfaces; f++) {
        int head = 0, tail = 0;
        if (face_component[f] >= 0) continue;
        face_component[f] = count;
        queue[tail++] = f;
        while (head < tail) {
            int g = queue[head++], c;
            for (c = mesh->face_start[g]; c < mesh->face_start[g + 1]; c++) {
                int t = mesh->twin[c];
                if (t >= 0 && face_component[mesh->corner_face[t]] < 0) {
                    face_component[mesh->corner_face[t]] = count;
                    queue[tail++] = mesh->corner_face[t];
                }
            }
        }
        count++;
    }
    *ncomponents = count;
    tt__free(allocator, queue);
    return TT_OK;
}

TTDEF tt_result tt_mesh_boundary_loops(const tt_mesh *mesh, int *corner_loop, int *nloops, tt_error *error)
{
    int c, count = 0;
    tt__ok(error);
    if (!mesh || !corner_loop || !nloops)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "tt_mesh_boundary_loops needs a mesh and both outputs (got NULL)");
    for (c = 0; c < mesh->ncorners; c++) corner_loop[c] = mesh->twin[c] < 0 ? -2 : -1;
    for (c = 0; c < mesh->ncorners; c++) {
        int h = c, steps;
        if (corner_loop[c] != -2) continue;
        /* Follow the boundary: from the end of h, turn around its end vertex
           across interior edges until the outgoing boundary half-edge. */
        for (steps = 0; steps <= mesh->ncorners && corner_loop[h] == -2; steps++) {
            int x = tt_mesh_next(mesh, h), guard;
            corner_loop[h] = count;
            for (guard = 0; guard <= mesh->ncorners && mesh->twin[x] >= 0; guard++)
                x = tt_mesh_next(mesh, mesh->twin[x]);
            if (mesh->twin[x] >= 0) break;
            h = x;
        }
        count++;
    }
    *nloops = count;
    return TT_OK;
}

TTDEF tt_result tt_mesh_compute_stats(const tt_mesh *mesh, const tt_allocator *allocator, tt_mesh_stats *stats,
                                      tt_error *error)
{
    int *valence = NULL, *face_component = NULL, *corner_loop = NULL, *twice_genus = NULL;
    int *loop_component = NULL, *faces_by_component = NULL, *component_start = NULL;
    int ncomponents = 0, nloops = 0, v, c, f, k;
    long long genus_sum = 0;
    tt_result result = tt__ok(error);
    if (!mesh || !stats)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1, "the mesh or the stats is NULL");
    if (tt__check_allocator(allocator, error) != TT_OK) return TT_ERROR_INVALID_ARGUMENT;
    memset(stats, 0, sizeof *stats);
    valence = TT__ALLOC(allocator, int, mesh->nverts);
    face_component = TT__ALLOC(allocator, int, mesh->nfaces);
    corner_loop = TT__ALLOC(allocator, int, mesh->ncorners);
    faces_by_component = TT__ALLOC(allocator, int, mesh->nfaces);
    if (!valence || !face_component || !corner_loop || !faces_by_component) goto out_of_memory;

    tt__valences(mesh, valence);
    for (v = 0; v < mesh->nverts; v++) {
        if (mesh->vert_corner[v] < 0) continue;
        if (stats->used_vertices == 0 || valence[v] < stats->min_valence) stats->min_valence = valence[v];
        if (valence[v] > stats->max_valence) stats->max_valence = valence[v];
        stats->used_vertices++;
    }
    for (c = 0; c < mesh->ncorners; c++) {
        if (mesh->twin[c] < 0) stats->boundary_edges++;
        if (mesh->twin[c] < c) stats->edges++;   /* boundary, or the later half of a pair */
    }
    /* Non-manifold vertices: the fan from vert_corner misses some corners. */
    memset(valence, 0, (size_t)mesh->nverts * sizeof(int));
    for (c = 0; c < mesh->ncorners; c++) valence[mesh->corner_vert[c]]++;
    for (v = 0; v < mesh->nverts; v++)
        if (mesh->vert_corner[v] >= 0 && tt__fan_size(mesh, v) != valence[v]) stats->nonmanifold_vertices++;

    if ((result = tt_mesh_components(mesh, allocator, face_component, &ncomponents, error)) != TT_OK) goto done;
    if ((result = tt_mesh_boundary_loops(mesh, corner_loop, &nloops, error)) != TT_OK) goto done;
    stats->components = ncomponents;
    stats->boundary_loops = nloops;
    stats->euler_characteristic = stats->used_vertices - stats->edges + mesh->nfaces;

    /* genus_c = (2 - chi_c - b_c) / 2 with chi_c = V_c - E_c + F_c; twice_genus
       starts at 2 per component and takes each term as it is counted. */
    twice_genus = TT__ALLOC(allocator, int, ncomponents);
    loop_component = TT__ALLOC(allocator, int, nloops);
    component_start = TT__ALLOC(allocator, int, (size_t)ncomponents + 1);
    if (!twice_genus || !loop_component || !component_start) goto out_of_memory;
    for (k = 0; k < ncomponents; k++) twice_genus[k] = 2;
    for (f = 0; f < mesh->nfaces; f++) twice_genus[face_component[f]] -= 1;
    for (c = 0; c < mesh->ncorners; c++)
        if (mesh->twin[c] < c) twice_genus[face_component[mesh->corner_face[c]]] += 1;
    for (k = 0; k < nloops; k++) loop_component[k] = -1;
    for (c = 0; c < mesh->ncorners; c++)
        if (corner_loop[c] >= 0 && loop_component[corner_loop[c]] < 0)
            loop_component[corner_loop[c]] = face_component[mesh->corner_face[c]];
    for (k = 0; k < nloops; k++) twice_genus[loop_component[k]] -= 1;
    /* A vertex counts once in every component that uses it (more than one only
       for a non-manifold vertex): visit faces grouped by component. */
    memset(component_start, 0, ((size_t)ncomponents + 1) * sizeof(int));
    for (f = 0; f < mesh->nfaces; f++) component_start[face_component[f] + 1]++;
    for (k = 0; k < ncomponents; k++) component_start[k + 1] += component_start[k];
    for (f = 0; f < mesh->nfaces; f++) faces_by_component[component_start[face_component[f]]++] = f;
    for (v = 0; v < mesh->nverts; v++) valence[v] = -1;   /* now: last component that counted v */
    for (k = 0; k < mesh->nfaces; k++) {
        int face = faces_by_component[k], comp = face_component[face];
        for (c = mesh->face_start[face]; c < mesh->face_start[face + 1]; c++) {
            int vert = mesh->corner_vert[c];
            if (valence[vert] != comp) { valence[vert] = comp; twice_genus[comp] -= 1; }
        }
    }
    for (k = 0; k < ncomponents; k++) genus_sum += twice_genus[k];
    stats->genus = (int)(genus_sum / 2);
    goto done;
out_of_memory:
    result = tt__fail(error, TT_ERROR_OUT_OF_MEMORY, -1, -1, -1, -1, "out of memory computing mesh statistics");
done:
    tt__free(allocator, valence);
    tt__free(allocator, face_component);
    tt__free(allocator, corner_loop);
    tt__free(allocator, faces_by_component);
    tt__free(allocator, twice_genus);
    tt__free(allocator, loop_component);
    tt__free(allocator, component_start);
    return result;
}

/* Quadrangulation: one Catmull-Clark step's topology. Based on: Catmull and
   Clark 1978 (the paper's reference [3]); Akleman Sec. 6 uses it to turn any
   mesh into quads. Edge ids follow the first half-edge of each edge. */
TTDEF tt_result tt_mesh_quadrangulate(const tt_mesh *mesh, tt_subdivision scheme, const tt_allocator *allocator,
                                      tt_mesh **out_mesh, tt_error *error)
{
    int *edge_of = NULL, nedges = 0, c, f, v, nverts_new;
    double *sum = NULL;       /* CC vertex rule accumulators: 3 face sums, 3 edge-midpoint sums, 3 boundary sums */
    int *count = NULL;        /* per vertex: faces, edges, boundary edges */
    float *pos = NULL;
    tt_mesh *quads = NULL;
    long long nverts_wanted, ncorners_new;
    tt_result result = TT_OK;

    tt__ok(error);
    if (!out_mesh) return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1, "out_mesh is NULL");
    *out_mesh = NULL;
    if (!mesh) return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1, "mesh is NULL");
    if (scheme != TT_SUBDIVIDE_LINEAR && scheme != TT_SUBDIVIDE_CATMULL_CLARK)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1, "unknown subdivision scheme %d",
                        (int)scheme);
    if (tt__check_allocator(allocator, error) != TT_OK) return TT_ERROR_INVALID_ARGUMENT;
    edge_of = TT__ALLOC(allocator, int, mesh->ncorners);
    if (!edge_of) return tt__fail(error, TT_ERROR_OUT_OF_MEMORY, -1, -1, -1, -1, "out of memory");
    for (c = 0; c < mesh->ncorners; c++) {
        int t = mesh->twin[c];
        edge_of[c] = (t < 0 || c < t) ? nedges++ : edge_of[t];
    }
    nverts_wanted = (long long)mesh->nverts + nedges + mesh->nfaces;
    ncorners_new = 4LL * mesh->ncorners;
    if (nverts_wanted > 0x3fffffff || ncorners_new > 0x3fffffff) {
        tt__free(allocator, edge_of);
        return tt__fail(error, TT_ERROR_TOO_LARGE, -1, -1, -1, -1,
                        "quadrangulating %d corners would make %lld corners, more than %d", mesh->ncorners,
                        ncorners_new, 0x3fffffff);
    }
    nverts_new = (int)nverts_wanted;
    pos = TT__ALLOC(allocator, float, (size_t)nverts_new * 3);
    quads = tt__mesh_alloc(allocator, nverts_new, mesh->ncorners, (int)ncorners_new,
                           mesh->flags & ~(unsigned)TT_MESH_BORROW_POSITIONS);
    if (!pos || !quads) {
        result = tt__fail(error, TT_ERROR_OUT_OF_MEMORY, -1, -1, -1, -1, "out of memory");
        goto done;
    }

    /* Topology, straight from the input's: no search, and a valid mesh gives
       a valid result. Quad c (one per input corner c of face f, with next n,
       previous p) is (v_c, E(c), F(f), E(p)); its half-edges are
         4c   v_c -> E(c)   first half of old c:  twin is the second half of
                            twin(c), i.e. half-edge 4 next(twin c) + 3
         4c+1 E(c) -> F     inside f:             twin 4n + 2
         4c+2 F -> E(p)     inside f:             twin 4p + 1
         4c+3 E(p) -> v_c   second half of old p: twin 4 twin(p) */
    for (f = 0; f < mesh->nfaces; f++) {
        int first = mesh->face_start[f], end = mesh->face_start[f + 1];
        int face_point = mesh->nverts + nedges + f;
        for (c = first; c < end; c++) {
            int n = c + 1 < end ? c + 1 : first, p = c > first ? c - 1 : end - 1, t = mesh->twin[c], k;
            int *q = quads->corner_vert + 4 * (size_t)c, *tw = quads->twin + 4 * (size_t)c;
            q[0] = mesh->corner_vert[c];
            q[1] = mesh->nverts + edge_of[c];
            q[2] = face_point;
            q[3] = mesh->nverts + edge_of[p];
            tw[0] = t >= 0 ? 4 * tt_mesh_next(mesh, t) + 3 : -1;
            tw[1] = 4 * n + 2;
            tw[2] = 4 * p + 1;
            tw[3] = mesh->twin[p] >= 0 ? 4 * mesh->twin[p] : -1;
            quads->face_start[c] = 4 * c;
            for (k = 0; k < 4; k++) quads->corner_face[4 * c + k] = c;
        }
        quads->vert_corner[face_point] = 4 * first + 2;
    }
    quads->face_start[mesh->ncorners] = 4 * mesh->ncorners;
    /* Outgoing half-edges, a boundary one where there is one: an old vertex
       keeps its own (first half of it); an edge point takes the second half of
       its edge (a boundary exactly when the edge is). */
    for (v = 0; v < mesh->nverts; v++) quads->vert_corner[v] = mesh->vert_corner[v] >= 0 ? 4 * mesh->vert_corner[v] : -1;
    for (c = 0; c < mesh->ncorners; c++)
        if (mesh->twin[c] < 0 || c < mesh->twin[c])
            quads->vert_corner[mesh->nverts + edge_of[c]] = 4 * tt_mesh_next(mesh, c) + 3;
    quads->min_face_size = quads->max_face_size = 4;
    quads->repaired_edges = 2 * mesh->repaired_edges;   /* each cut edge is now two */

    /* Face points: centroids. Edge points: midpoints (linear, and CC on a
       boundary) or the average of the two ends and the two face points (CC). */
    for (f = 0; f < mesh->nfaces; f++) {
        int first = mesh->face_start[f], end = mesh->face_start[f + 1], k;
        double centre[3] = {0, 0, 0};
        float *out = pos + 3 * ((size_t)mesh->nverts + nedges + f);
        for (c = first; c < end; c++)
            for (k = 0; k < 3; k++) centre[k] += mesh->pos[3 * (size_t)mesh->corner_vert[c] + k];
        for (k = 0; k < 3; k++) out[k] = (float)(centre[k] / (end - first));
    }
    for (c = 0; c < mesh->ncorners; c++) {
        int t = mesh->twin[c], k;
        const float *a, *b;
        float *out;
        if (!(t < 0 || c < t)) continue;
        a = mesh->pos + 3 * (size_t)mesh->corner_vert[c];
        b = mesh->pos + 3 * (size_t)mesh->corner_vert[tt_mesh_next(mesh, c)];
        out = pos + 3 * ((size_t)mesh->nverts + edge_of[c]);
        if (scheme == TT_SUBDIVIDE_CATMULL_CLARK && t >= 0) {
            const float *f0 = pos + 3 * ((size_t)mesh->nverts + nedges + mesh->corner_face[c]);
            const float *f1 = pos + 3 * ((size_t)mesh->nverts + nedges + mesh->corner_face[t]);
            for (k = 0; k < 3; k++) out[k] = (float)(((double)a[k] + b[k] + f0[k] + f1[k]) * 0.25);
        } else {
            for (k = 0; k < 3; k++) out[k] = (float)(((double)a[k] + b[k]) * 0.5);
        }
    }

    /* Old vertices: kept (linear), or moved by the Catmull-Clark rules:
       interior  (Q + 2R + (n-3) S) / n  with Q the average face point, R the
       average edge midpoint, n the number of faces; boundary  3/4 S + 1/8 of
       each boundary neighbour; a boundary vertex with other than two boundary
       edges (a corner of a permissive mesh) stays. */
    if (mesh->nverts > 0) memcpy(pos, mesh->pos, (size_t)mesh->nverts * 3 * sizeof(float));
    if (scheme == TT_SUBDIVIDE_CATMULL_CLARK && mesh->nverts > 0) {
        sum = TT__ALLOC(allocator, double, (size_t)mesh->nverts * 9);
        count = TT__ALLOC(allocator, int, (size_t)mesh->nverts * 3);
        if (!sum || !count) {
            result = tt__fail(error, TT_ERROR_OUT_OF_MEMORY, -1, -1, -1, -1, "out of memory");
            goto done;
        }
        memset(sum, 0, (size_t)mesh->nverts * 9 * sizeof(double));
        memset(count, 0, (size_t)mesh->nverts * 3 * sizeof(int));
        for (c = 0; c < mesh->ncorners; c++) {
            int a = mesh->corner_vert[c], b = mesh->corner_vert[tt_mesh_next(mesh, c)], t = mesh->twin[c], k;
            const float *fp = pos + 3 * ((size_t)mesh->nverts + nedges + mesh->corner_face[c]);
            for (k = 0; k < 3; k++) sum[9 * (size_t)a + k] += fp[k];
            count[3 * (size_t)a]++;
            if (t < 0 || c < t) {
                for (k = 0; k < 3; k++) {
                    double mid = 0.5 * ((double)mesh->pos[3 * (size_t)a + k] + mesh->pos[3 * (size_t)b + k]);
                    sum[9 * (size_t)a + 3 + k] += mid;
                    sum[9 * (size_t)b + 3 + k] += mid;
                }
                count[3 * (size_t)a + 1]++;
                count[3 * (size_t)b + 1]++;
            }
            if (t < 0) {
                /* Boundary neighbours of a and b: the other end of this edge. */
                for (k = 0; k < 3; k++) {
                    sum[9 * (size_t)a + 6 + k] += mesh->pos[3 * (size_t)b + k];
                    sum[9 * (size_t)b + 6 + k] += mesh->pos[3 * (size_t)a + k];
                }
                count[3 * (size_t)a + 2]++;
                count[3 * (size_t)b + 2]++;
            }
        }
        for (v = 0; v < mesh->nverts; v++) {
            const double *sv = sum + 9 * (size_t)v;
            const int *n = count + 3 * (size_t)v;
            const float *old = mesh->pos + 3 * (size_t)v;
            float *out = pos + 3 * (size_t)v;
            int k;
            if (n[0] == 0) continue;
            if (n[2] == 2) {
                for (k = 0; k < 3; k++) out[k] = (float)(0.75 * old[k] + 0.125 * sv[6 + k]);
            } else if (n[2] == 0) {
                double faces = n[0];
                for (k = 0; k < 3; k++)
                    out[k] = (float)((sv[k] / faces + 2.0 * sv[3 + k] / n[1] + (faces - 3.0) * old[k]) / faces);
            }
        }
    }
    /* Averages of finite numbers can still overflow float. */
    for (v = 0; v < nverts_new; v++)
        if (!tt__is_finite(pos[3 * (size_t)v]) || !tt__is_finite(pos[3 * (size_t)v + 1]) ||
            !tt__is_finite(pos[3 * (size_t)v + 2])) {
            result = tt__fail(error, TT_ERROR_NON_FINITE, -1, -1, v, -1,
                              "quadrangulation overflowed: new vertex %d is not finite (coordinates near the "
                              "float limit)", v);
            goto done;
        }
    quads->pos = pos;
    pos = NULL;
    *out_mesh = quads;
    quads = NULL;
done:
    tt__free(allocator, edge_of);
    tt__free(allocator, pos);
    tt__free(allocator, sum);
    tt__free(allocator, count);
    tt_mesh_free(quads);
    return result;
}

/* ------------------------------------------------------------------------ */
/* 3. Image                                                                 */
/* ------------------------------------------------------------------------ */

/* Size checks shared by every image the library makes. */
static tt_result tt__check_image_size(int width, int height, tt_error *error)
{
    if (width <= 0 || height <= 0)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1, "an image of %d x %d texels is empty",
                        width, height);
    if (width > TT_MAX_IMAGE_SIZE || height > TT_MAX_IMAGE_SIZE)
        return tt__fail(error, TT_ERROR_TOO_LARGE, -1, -1, -1, -1,
                        "an image of %d x %d texels is above the limit of %d a side", width, height,
                        TT_MAX_IMAGE_SIZE);
    return TT_OK;
}

/* Pixels for an image held by value inside a larger object (a tileset's mip
   levels); released with tt__image_release. */
static tt_result tt__image_init(tt_image *image, int width, int height, const tt_allocator *allocator,
                                tt_error *error)
{
    size_t count;
    tt_result result;
    memset(image, 0, sizeof *image);
    if ((result = tt__check_image_size(width, height, error)) != TT_OK) return result;
    count = (size_t)width * (size_t)height;   /* <= 2^30: fits any size_t of 32 bits or more */
    image->allocator = tt__allocator_copy(allocator);
    image->pixels = TT__ALLOC(allocator, float, count * 4);
    if (!image->pixels)
        return tt__fail(error, TT_ERROR_OUT_OF_MEMORY, -1, -1, -1, -1, "out of memory for a %d x %d image", width,
                        height);
    memset(image->pixels, 0, count * 4 * sizeof(float));
    image->width = width;
    image->height = height;
    return TT_OK;
}

static void tt__image_release(tt_image *image)
{
    tt__free(&image->allocator, image->pixels);
    memset(image, 0, sizeof *image);
}

/* TT_ERROR_NON_FINITE naming the first NaN or infinite texel, by row and
   column: one bad texel would otherwise spread through every blend. */
static tt_result tt__check_finite_texels(const tt_image *image, const char *what, tt_error *error)
{
    size_t i, n = (size_t)image->width * (size_t)image->height * 4;
    for (i = 0; i < n; i++)
        if (!tt__is_finite(image->pixels[i])) {
            int texel = (int)(i / 4), x = texel % image->width, y = texel / image->width;
            return tt__fail_at(error, TT_ERROR_NON_FINITE, -1, y, x, "the %s has a non-finite value at texel %d, %d",
                               what, x, y);
        }
    return TT_OK;
}

/* The struct and its pixels share one block; the header is padded to 64
   bytes so the pixels keep the allocator's alignment. */
#define TT__IMAGE_HEADER 64

TTDEF tt_result tt_image_create(int width, int height, const tt_allocator *allocator, tt_image **out_image,
                                tt_error *error)
{
    size_t count;
    tt_image *image;
    tt_result result;
    tt__ok(error);
    if (!out_image) return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1, "out_image is NULL");
    *out_image = NULL;
    if (tt__check_allocator(allocator, error) != TT_OK) return TT_ERROR_INVALID_ARGUMENT;
    if ((result = tt__check_image_size(width, height, error)) != TT_OK) return result;
    count = (size_t)width * (size_t)height;
    image = (tt_image *)tt__alloc(allocator, TT__IMAGE_HEADER + count * 4 * sizeof(float));
    if (!image)
        return tt__fail(error, TT_ERROR_OUT_OF_MEMORY, -1, -1, -1, -1, "out of memory for a %d x %d image", width,
                        height);
    memset(image, 0, TT__IMAGE_HEADER + count * 4 * sizeof(float));
    image->width = width;
    image->height = height;
    image->pixels = (float *)(void *)((unsigned char *)image + TT__IMAGE_HEADER);
    image->allocator = tt__allocator_copy(allocator);
    *out_image = image;
    return TT_OK;
}

TTDEF void tt_image_free(tt_image *image)
{
    tt_allocator allocator;
    if (!image) return;
    allocator = image->allocator;
    tt__free(&allocator, image);
}

/* IEC 61966-2-1: linear segment near black, a 2.4 power above it. */
TTDEF float tt_srgb_to_linear(float encoded)
{
    float v = encoded != encoded ? 0.0f : tt__clamp_f(encoded, 0.0f, 1.0f);
    return v <= 0.04045f ? v / 12.92f : powf((v + 0.055f) / 1.055f, 2.4f);
}

TTDEF float tt_linear_to_srgb(float linear)
{
    float v = linear != linear ? 0.0f : tt__clamp_f(linear, 0.0f, 1.0f);
    if (v >= 1.0f) return 1.0f;   /* the formula rounds to 0.99999994 there */
    return v <= 0.0031308f ? v * 12.92f : 1.055f * powf(v, 1.0f / 2.4f) - 0.055f;
}

/* decode[b]: the linear value of byte b. */
static void tt__decode_table(tt_color_space space, float decode[256])
{
    int b;
    for (b = 0; b < 256; b++)
        decode[b] = space == TT_COLOR_SRGB ? tt_srgb_to_linear((float)b / 255.0f) : (float)b / 255.0f;
}

/* bound[b], b = 0..254: the linear value halfway (in the encoded scale)
   between bytes b and b + 1, so that encoding rounds to the nearest byte by
   a search among the bounds, with no power function per texel, and decode
   then encode gives back every byte. */
static void tt__encode_bounds(tt_color_space space, float bound[255])
{
    int b;
    for (b = 0; b < 255; b++)
        bound[b] = space == TT_COLOR_SRGB ? tt_srgb_to_linear(((float)b + 0.5f) / 255.0f)
                                          : ((float)b + 0.5f) / 255.0f;
}

static unsigned char tt__encode_byte(const float bound[255], float value)
{
    int lo = 0, hi = 255;   /* the answer is the number of bounds <= value */
    if (!(value >= bound[0])) return 0;   /* NaN too */
    while (hi - lo > 1) {
        int mid = (lo + hi) / 2;
        if (value >= bound[mid - 1]) lo = mid; else hi = mid;
    }
    return (unsigned char)(value >= bound[lo] ? lo + 1 : lo);
}

TTDEF tt_result tt_image_from_bytes(const unsigned char *data, int width, int height, int channels, int stride,
                                    tt_color_space space, const tt_allocator *allocator, tt_image **out_image,
                                    tt_error *error)
{
    float decode[256], alpha[256];
    tt_image *image;
    tt_result result;
    long long row_bytes;
    int x, y;
    tt__ok(error);
    if (!out_image) return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1, "out_image is NULL");
    *out_image = NULL;
    if (!data) return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1, "the pixel data is NULL");
    if (channels < 1 || channels > 4)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1, "%d channels: need 1, 2, 3 or 4",
                        channels);
    if (space != TT_COLOR_SRGB && space != TT_COLOR_LINEAR)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1, "unknown colour space %d", (int)space);
    if ((result = tt__check_image_size(width, height, error)) != TT_OK) return result;
    row_bytes = (long long)width * channels;   /* width <= 32768: no overflow */
    if (stride < 0 || (stride > 0 && stride < row_bytes))
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "a stride of %d bytes is less than a row of %d pixels of %d channels", stride, width,
                        channels);
    if (stride == 0) stride = (int)row_bytes;
    if ((result = tt_image_create(width, height, allocator, &image, error)) != TT_OK) return result;
    tt__decode_table(space, decode);
    tt__decode_table(TT_COLOR_LINEAR, alpha);
    for (y = 0; y < height; y++) {
        const unsigned char *row = data + (size_t)y * (size_t)stride;
        float *out = image->pixels + (size_t)y * width * 4;
        for (x = 0; x < width; x++, out += 4) {
            const unsigned char *p = row + (size_t)x * channels;
            switch (channels) {
            case 1: out[0] = out[1] = out[2] = decode[p[0]]; out[3] = 1.0f; break;
            case 2: out[0] = out[1] = out[2] = decode[p[0]]; out[3] = alpha[p[1]]; break;
            case 3: out[0] = decode[p[0]]; out[1] = decode[p[1]]; out[2] = decode[p[2]]; out[3] = 1.0f; break;
            default:
                out[0] = decode[p[0]]; out[1] = decode[p[1]]; out[2] = decode[p[2]]; out[3] = alpha[p[3]];
                break;
            }
        }
    }
    *out_image = image;
    return TT_OK;
}

TTDEF void tt_image_to_rgba8(const tt_image *image, tt_color_space space, unsigned char *out)
{
    float bound[255], alpha_bound[255];
    size_t i, n;
    TT_ASSERT(image && image->pixels && out);
    if (!image || !image->pixels || !out) return;
    tt__encode_bounds(space, bound);
    tt__encode_bounds(TT_COLOR_LINEAR, alpha_bound);
    n = (size_t)image->width * image->height;
    for (i = 0; i < n; i++) {
        /* Read the whole texel before writing: out may alias the pixels
           (bytes 4i.. lie on floats of texel i/4 <= i, read already). */
        const float *p = image->pixels + 4 * i;
        float red = p[0], green = p[1], blue = p[2], alpha = p[3];
        out[4 * i] = tt__encode_byte(bound, red);
        out[4 * i + 1] = tt__encode_byte(bound, green);
        out[4 * i + 2] = tt__encode_byte(bound, blue);
        out[4 * i + 3] = tt__encode_byte(alpha_bound, alpha);
    }
}

/* Repeat addressing along one axis of `size` texels: the texel pair (*lo,
   *hi) that bilinear filtering blends at coordinate f (pixel units, texel
   centres at integers), and the weight of *hi. The reduction modulo `size` is
   done in double; where rounding still leaves [0, size) (a tiny negative f,
   or one so huge that its period is lost) and for NaN and infinities (whose
   remainder is NaN), texel 0 is taken. */
static float tt__repeat_axis(float f, int size, int *lo, int *hi)
{
    double reduced = (double)f - floor((double)f / size) * size;
    if (!(reduced >= 0.0 && reduced < size)) reduced = 0.0;   /* NaN, or rounding at a huge or tiny f */
    *lo = (int)floor(reduced);
    *hi = *lo + 1 == size ? 0 : *lo + 1;
    return (float)(reduced - *lo);
}

TTDEF void tt_image_sample_bilinear_wrap(const tt_image *image, float x, float y, tt_wrap wrap, float rgba[4])
{
    float fx = x - 0.5f, fy = y - 0.5f, tx, ty;
    int x0, y0, x1, y1, k;
    const float *p00, *p10, *p01, *p11;
    TT_ASSERT(image && image->pixels && image->width > 0 && image->height > 0 && rgba);
    TT_ASSERT(wrap == TT_WRAP_CLAMP || wrap == TT_WRAP_REPEAT);
    if (wrap == TT_WRAP_REPEAT) {
        tx = tt__repeat_axis(fx, image->width, &x0, &x1);
        ty = tt__repeat_axis(fy, image->height, &y0, &y1);
    } else {
        /* Far outside is the same as just outside (clamping), and it keeps
           the conversion to int defined; NaN samples the first texel. */
        fx = fx != fx ? 0.0f : tt__clamp_f(fx, -1.0f, (float)image->width);
        fy = fy != fy ? 0.0f : tt__clamp_f(fy, -1.0f, (float)image->height);
        x0 = (int)floorf(fx);
        y0 = (int)floorf(fy);
        tx = fx - (float)x0;
        ty = fy - (float)y0;
        x1 = tt__clamp_i(x0 + 1, 0, image->width - 1);
        y1 = tt__clamp_i(y0 + 1, 0, image->height - 1);
        x0 = tt__clamp_i(x0, 0, image->width - 1);
        y0 = tt__clamp_i(y0, 0, image->height - 1);
    }
    p00 = image->pixels + ((size_t)y0 * image->width + x0) * 4;
    p10 = image->pixels + ((size_t)y0 * image->width + x1) * 4;
    p01 = image->pixels + ((size_t)y1 * image->width + x0) * 4;
    p11 = image->pixels + ((size_t)y1 * image->width + x1) * 4;
    for (k = 0; k < 4; k++) {
        float top = p00[k] + (p10[k] - p00[k]) * tx;
        float bottom = p01[k] + (p11[k] - p01[k]) * tx;
        rgba[k] = top + (bottom - top) * ty;
    }
}

TTDEF void tt_image_sample_bilinear(const tt_image *image, float x, float y, float rgba[4])
{
    tt_image_sample_bilinear_wrap(image, x, y, TT_WRAP_CLAMP, rgba);
}

TTDEF void tt_rotate_coords(int quarter_turns, int width, int height, int x, int y, int *out_x, int *out_y)
{
    /* One counter-clockwise quarter turn of a W x H picture (row 0 on top)
       sends the top-left corner to the bottom-left: (x, y) -> (y, W-1-x).
       Computed in 64 bits: a result that does not fit an int is a broken
       precondition, caught by TT_ASSERT and never undefined behaviour. */
    long long rx, ry, w = width, h = height;
    TT_ASSERT(out_x && out_y);
    switch (((quarter_turns % 4) + 4) % 4) {
    case 0: rx = x; ry = y; break;
    case 1: rx = y; ry = w - 1 - x; break;
    case 2: rx = w - 1 - x; ry = h - 1 - y; break;
    default: rx = h - 1 - y; ry = x; break;
    }
    TT_ASSERT(rx >= INT_MIN && rx <= INT_MAX && ry >= INT_MIN && ry <= INT_MAX);
    *out_x = (int)rx;
    *out_y = (int)ry;
}

TTDEF tt_result tt_image_rotate90(const tt_image *src, int quarter_turns, const tt_allocator *allocator,
                                  tt_image **out_image, tt_error *error)
{
    int odd, x, y;
    tt_image *dst;
    tt_result result;
    tt__ok(error);
    if (!out_image) return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1, "out_image is NULL");
    *out_image = NULL;
    if (!src || !src->pixels)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1, "the source image is NULL or empty");
    odd = (((quarter_turns % 4) + 4) % 4) & 1;
    result = tt_image_create(odd ? src->height : src->width, odd ? src->width : src->height, allocator, &dst, error);
    if (result != TT_OK) return result;
    for (y = 0; y < src->height; y++)
        for (x = 0; x < src->width; x++) {
            int rx, ry;
            tt_rotate_coords(quarter_turns, src->width, src->height, x, y, &rx, &ry);
            memcpy(dst->pixels + ((size_t)ry * dst->width + rx) * 4, src->pixels + ((size_t)y * src->width + x) * 4,
                   4 * sizeof(float));
        }
    *out_image = dst;
    return TT_OK;
}

TTDEF void tt_rgba_over(float dst[4], const float src[4])
{
    float keep;
    TT_ASSERT(dst && src);
    keep = 1.0f - src[3];
    dst[0] = src[0] + keep * dst[0];
    dst[1] = src[1] + keep * dst[1];
    dst[2] = src[2] + keep * dst[2];
    dst[3] = src[3] + keep * dst[3];
}

TTDEF tt_result tt_image_over(tt_image *dst, const tt_image *src, tt_error *error)
{
    size_t i, n;
    tt__ok(error);
    if (!dst || !src || !dst->pixels || !src->pixels)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1, "an image is NULL or empty");
    if (dst->width != src->width || dst->height != src->height)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "the images differ in size: %d x %d over %d x %d", src->width, src->height, dst->width,
                        dst->height);
    n = (size_t)dst->width * dst->height;
    for (i = 0; i < n; i++) tt_rgba_over(dst->pixels + 4 * i, src->pixels + 4 * i);
    return TT_OK;
}

/* dst (allocated, half the size of src) = src halved by a 2x2 box. */
static void tt__downsample_into(const tt_image *src, tt_image *dst)
{
    int x, y, k, w = dst->width, h = dst->height;
    for (y = 0; y < h; y++)
        for (x = 0; x < w; x++) {
            const float *a = src->pixels + ((size_t)(2 * y) * src->width + 2 * x) * 4;
            const float *b = a + (size_t)src->width * 4;
            float *out = dst->pixels + ((size_t)y * w + x) * 4;
            for (k = 0; k < 4; k++) out[k] = 0.25f * (a[k] + a[4 + k] + b[k] + b[4 + k]);
        }
}

TTDEF tt_result tt_image_downsample2(const tt_image *src, const tt_allocator *allocator, tt_image **out_image,
                                     tt_error *error)
{
    tt_result result;
    tt__ok(error);
    if (!out_image) return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1, "out_image is NULL");
    *out_image = NULL;
    if (!src || !src->pixels)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1, "the source image is NULL or empty");
    if (src->width % 2 || src->height % 2)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "a %d x %d image cannot be halved: both sides must be even", src->width, src->height);
    if ((result = tt_image_create(src->width / 2, src->height / 2, allocator, out_image, error)) != TT_OK)
        return result;
    tt__downsample_into(src, *out_image);
    return TT_OK;
}

TTDEF tt_result tt_min_error_cut(const float *cost, int width, int height, const int *lo, const int *hi,
                                 const tt_allocator *allocator, int *path, tt_error *error)
{
    /* Dynamic programming over columns (Efros and Freeman 2001, the paper's
       reference [2]): total[x][y] = cost[y][x] + min over y-1..y+1 of
       total[x-1][.], restricted to each column's allowed rows. */
    double *total;
    signed char *step;
    int x, y, best = -1;
    const double unreachable = 1e300;
    tt__ok(error);
    if (!cost || !lo || !hi || !path)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "tt_min_error_cut needs the cost, lo, hi and path arrays (got NULL)");
    if (width <= 0 || height <= 0)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1, "a %d x %d cost map is empty", width,
                        height);
    if (tt__check_allocator(allocator, error) != TT_OK) return TT_ERROR_INVALID_ARGUMENT;
    for (x = 0; x < width; x++)
        if (lo[x] < 0 || hi[x] >= height || lo[x] > hi[x])
            return tt__fail_at(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, x,
                               "column %d allows rows %d..%d of a cost map %d rows high", x, lo[x], hi[x], height);
    if ((size_t)width * (size_t)height > ((size_t)1 << 28))
        return tt__fail(error, TT_ERROR_TOO_LARGE, -1, -1, -1, -1, "a %d x %d cost map is above 2^28 entries",
                        width, height);
    for (y = 0; y < height; y++)
        for (x = 0; x < width; x++)
            if (!tt__is_finite(cost[(size_t)y * width + x]))
                return tt__fail_at(error, TT_ERROR_NON_FINITE, -1, y, x, "the cost at row %d, column %d is %g", y,
                                   x, (double)cost[(size_t)y * width + x]);
    total = TT__ALLOC(allocator, double, (size_t)width * height);
    step = TT__ALLOC(allocator, signed char, (size_t)width * height);
    if (!total || !step) {
        tt__free(allocator, total);
        tt__free(allocator, step);
        return tt__fail(error, TT_ERROR_OUT_OF_MEMORY, -1, -1, -1, -1, "out of memory for a %d x %d cut", width,
                        height);
    }
    for (x = 0; x < width; x++) {
        for (y = 0; y < height; y++) {
            size_t i = (size_t)x * height + y;
            double from = 0.0;
            int d, choice = 0;
            total[i] = unreachable;
            step[i] = 0;
            if (y < lo[x] || y > hi[x]) continue;
            if (x > 0) {
                from = unreachable;
                for (d = -1; d <= 1; d++) {
                    int py = y + d;
                    if (py < 0 || py >= height) continue;
                    if (total[(size_t)(x - 1) * height + py] < from) {
                        from = total[(size_t)(x - 1) * height + py];
                        choice = d;
                    }
                }
                if (from >= unreachable) continue;
            }
            total[i] = from + cost[(size_t)y * width + x];
            step[i] = (signed char)choice;
        }
    }
    for (y = 0; y < height; y++)
        if (total[(size_t)(width - 1) * height + y] < unreachable &&
            (best < 0 || total[(size_t)(width - 1) * height + y] < total[(size_t)(width - 1) * height + best]))
            best = y;
    if (best < 0) {
        tt__free(allocator, total);
        tt__free(allocator, step);
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "no path can follow the allowed rows from column to column (steps of at most one row)");
    }
    for (x = width - 1; x >= 0; x--) {
        path[x] = best;
        best += step[(size_t)x * height + best];
    }
    tt__free(allocator, total);
    tt__free(allocator, step);
    return TT_OK;
}

/* ------------------------------------------------------------------------ */
/* 4. Numerics                                                              */
/* ------------------------------------------------------------------------ */

/* `restrict` tells the compiler that the vectors of one loop do not overlap,
   which lets it keep values in registers and vectorise. It is C99 only; C++
   compilers spell it __restrict, others get nothing (correct, maybe slower). */
#ifndef TT__RESTRICT
#if defined(__cplusplus)
#if defined(__GNUC__) || defined(__clang__) || defined(_MSC_VER)
#define TT__RESTRICT __restrict
#else
#define TT__RESTRICT
#endif
#elif defined(__STDC_VERSION__) && __STDC_VERSION__ >= 199901L
#define TT__RESTRICT restrict
#else
#define TT__RESTRICT
#endif
#endif

/* The median of values[0 .. count-1] (sorts them); 0 for none. */
static double tt__median(double *values, int count)
{
    if (count <= 0) return 0.0;
    tt__sort_doubles(values, count);
    return count % 2 ? values[count / 2] : 0.5 * (values[count / 2 - 1] + values[count / 2]);
}

/* A value and its weight (an area, say), for weighted percentiles. */
typedef struct tt__weighted {
    double value, weight;
} tt__weighted;

#define TT__WEIGHTED_LESS(a, b) ((a).value < (b).value)
TT__DEFINE_HEAPSORT_BY(tt__sort_weighted, tt__weighted, TT__WEIGHTED_LESS)

/* Weighted percentiles: out[k] = the smallest value v of the items at which
   the weight of the items with values <= v reaches fraction[k] of the total
   weight (fraction 0.5: the weighted median, which is always one of the
   values, never an average of two). Sorts the items by value once for all
   the fractions. Preconditions (the callers': TT_ASSERT): count >= 1, values
   not NaN, weights >= 0 with a positive total, fractions in [0, 1]. */
static void tt__weighted_percentiles(tt__weighted *items, int count, const double *fraction, int nfractions,
                                     double *out)
{
    double total = 0.0;
    int i, k;
    TT_ASSERT(items && count >= 1);
    tt__sort_weighted(items, count);
    for (i = 0; i < count; i++) total += items[i].weight;
    for (k = 0; k < nfractions; k++) {
        double goal = fraction[k] * total, cumulative = 0.0;
        /* The last value when rounding keeps the sum just below a goal of
           the whole total. */
        out[k] = items[count - 1].value;
        for (i = 0; i < count; i++) {
            cumulative += items[i].weight;
            if (cumulative >= goal) {
                out[k] = items[i].value;
                break;
            }
        }
    }
}

TTDEF tt_result tt_sparse_from_triplets(int rows, int cols, const tt_triplet *triplets, int ntriplets,
                                        const tt_allocator *allocator, tt_sparse_matrix **out_matrix,
                                        tt_error *error)
{
    /* Two stable bucket passes (a radix sort with the column as the low digit
       and the row as the high digit) put the triplets in row order with
       increasing columns inside each row; duplicates then sit next to each
       other, in their input order, and are summed in one walk. */
    size_t nt, nbuckets, k;
    int *work, *bucket, *by_col, *by_row;
    int r, nnz, pos, begin;
    tt_sparse_matrix *matrix;
    tt__ok(error);
    if (!out_matrix)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1, "out_matrix is NULL");
    *out_matrix = NULL;
    if (tt__check_allocator(allocator, error) != TT_OK) return TT_ERROR_INVALID_ARGUMENT;
    if (rows < 0 || cols < 0 || ntriplets < 0)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "a %d x %d matrix from %d triplets: sizes and counts must not be negative", rows, cols,
                        ntriplets);
    if (!triplets && ntriplets > 0)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "%d triplets announced but `triplets` is NULL", ntriplets);
    for (k = 0; k < (size_t)ntriplets; k++) {
        const tt_triplet *t = triplets + k;
        if (t->row < 0 || t->row >= rows || t->col < 0 || t->col >= cols)
            return tt__fail_at(error, TT_ERROR_INDEX_OUT_OF_RANGE, (int)k, t->row, t->col,
                               "triplet %d is at row %d, column %d, outside the %d x %d matrix", (int)k, t->row,
                               t->col, rows, cols);
        if (!tt__is_finite_d(t->value))
            return tt__fail_at(error, TT_ERROR_NON_FINITE, (int)k, t->row, t->col,
                               "triplet %d (row %d, column %d) has the value %g", (int)k, t->row, t->col, t->value);
    }

    nt = (size_t)ntriplets;
    nbuckets = (size_t)(rows > cols ? rows : cols) + 1;
    if (nt > ((size_t)-1 / sizeof(int) - nbuckets) / 2 || !tt__size_fits(nt, sizeof(double)) ||
        !tt__size_fits((size_t)rows + 1, sizeof(int)))
        return tt__fail(error, TT_ERROR_TOO_LARGE, -1, -1, -1, -1,
                        "a %d x %d matrix from %d triplets needs more bytes than size_t can count", rows, cols,
                        ntriplets);
    matrix = TT__ALLOC(allocator, tt_sparse_matrix, 1);
    if (!matrix)
        return tt__fail(error, TT_ERROR_OUT_OF_MEMORY, -1, -1, -1, -1, "out of memory for a %d x %d matrix", rows,
                        cols);
    memset(matrix, 0, sizeof *matrix);
    matrix->allocator = tt__allocator_copy(allocator);
    work = TT__ALLOC(&matrix->allocator, int, nbuckets + 2 * nt);
    if (!work) goto out_of_memory;
    bucket = work;
    by_col = work + nbuckets;
    by_row = by_col + nt;

    /* Pass 1, by column: bucket[c] = first slot of column c, then scatter. */
    memset(bucket, 0, ((size_t)cols + 1) * sizeof(int));
    for (k = 0; k < nt; k++) bucket[triplets[k].col + 1]++;
    for (r = 0; r < cols; r++) bucket[r + 1] += bucket[r];
    for (k = 0; k < nt; k++) by_col[bucket[triplets[k].col]++] = (int)k;
    /* Pass 2, by row, reading in column order (stable): afterwards
       bucket[r] = one past the last slot of row r. */
    memset(bucket, 0, ((size_t)rows + 1) * sizeof(int));
    for (k = 0; k < nt; k++) bucket[triplets[k].row + 1]++;
    for (r = 0; r < rows; r++) bucket[r + 1] += bucket[r];
    for (k = 0; k < nt; k++) {
        int t = by_col[k];
        by_row[bucket[triplets[t].row]++] = t;
    }

    /* Distinct (row, column) pairs. */
    nnz = 0;
    for (r = 0, begin = 0; r < rows; begin = bucket[r], r++) {
        int i, last = -1;
        for (i = begin; i < bucket[r]; i++)
            if (triplets[by_row[i]].col != last) {
                last = triplets[by_row[i]].col;
                nnz++;
            }
    }

    matrix->row_start = TT__ALLOC(&matrix->allocator, int, (size_t)rows + 1);
    matrix->col = TT__ALLOC(&matrix->allocator, int, nnz);
    matrix->value = TT__ALLOC(&matrix->allocator, double, nnz);
    if (!matrix->row_start || !matrix->col || !matrix->value) {
        tt__free(&matrix->allocator, work);
        goto out_of_memory;
    }
    matrix->rows = rows;
    matrix->cols = cols;
    matrix->nnz = nnz;
    matrix->row_start[0] = 0;
    for (r = 0, begin = 0, pos = 0; r < rows; begin = bucket[r], r++) {
        int i, last = -1;
        for (i = begin; i < bucket[r]; i++) {
            const tt_triplet *t = triplets + by_row[i];
            if (t->col != last) {
                last = t->col;
                matrix->col[pos] = t->col;
                matrix->value[pos] = t->value;
                pos++;
            } else {
                /* Finite triplets can still sum to infinity: that entry is
                   not a number the solver can use. */
                matrix->value[pos - 1] += t->value;
                if (!tt__is_finite_d(matrix->value[pos - 1])) {
                    int item = by_row[i], column = t->col;   /* by_row lives in work, freed next */
                    tt__free(&matrix->allocator, work);
                    tt_sparse_matrix_free(matrix);
                    return tt__fail_at(error, TT_ERROR_NON_FINITE, item, r, column,
                                       "the triplets of row %d, column %d sum to infinity (triplet %d overflows)",
                                       r, column, item);
                }
            }
        }
        matrix->row_start[r + 1] = pos;
    }
    tt__free(&matrix->allocator, work);
    *out_matrix = matrix;
    return TT_OK;

out_of_memory:
    tt_sparse_matrix_free(matrix);
    return tt__fail(error, TT_ERROR_OUT_OF_MEMORY, -1, -1, -1, -1,
                    "out of memory building a %d x %d matrix from %d triplets", rows, cols, ntriplets);
}

TTDEF void tt_sparse_matrix_free(tt_sparse_matrix *matrix)
{
    tt_allocator allocator;
    if (!matrix) return;
    allocator = matrix->allocator;
    tt__free(&allocator, matrix->row_start);
    tt__free(&allocator, matrix->col);
    tt__free(&allocator, matrix->value);
    tt__free(&allocator, matrix);
}

/* y = A x for rows [0, n). */
static void tt__spmv(int n, const int *TT__RESTRICT row_start, const int *TT__RESTRICT col,
                     const double *TT__RESTRICT value, const double *TT__RESTRICT x, double *TT__RESTRICT y)
{
    int i;
    for (i = 0; i < n; i++) {
        int k, end = row_start[i + 1];
        double sum = 0.0;
        for (k = row_start[i]; k < end; k++) sum += value[k] * x[col[k]];
        y[i] = sum;
    }
}

TTDEF tt_result tt_sparse_multiply(const tt_sparse_matrix *A, const double *x, double *y, tt_error *error)
{
    tt__ok(error);
    if (!A || !x || !y || A->rows < 0 || (A->rows > 0 && !A->row_start))
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "tt_sparse_multiply needs a matrix with rows, x and y (got NULL or a negative size)");
    if (x == y)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1, "x and y must not overlap");
    tt__spmv(A->rows, A->row_start, A->col, A->value, x, y);
    return TT_OK;
}

/* The CG step's product: Ap = A p, returning p . Ap (the alpha denominator)
   from the same pass, while p[i] is still in a register. */
static double tt__spmv_dot(int n, const int *TT__RESTRICT row_start, const int *TT__RESTRICT col,
                           const double *TT__RESTRICT value, const double *TT__RESTRICT p, double *TT__RESTRICT Ap)
{
    double dot = 0.0;
    int i;
    for (i = 0; i < n; i++) {
        int k, end = row_start[i + 1];
        double sum = 0.0;
        for (k = row_start[i]; k < end; k++) sum += value[k] * p[col[k]];
        Ap[i] = sum;
        dot += sum * p[i];
    }
    return dot;
}

/* r = b - A x; returns r . r. */
static double tt__cg_residual(const tt_sparse_matrix *A, const double *TT__RESTRICT b, const double *TT__RESTRICT x,
                              double *TT__RESTRICT r)
{
    double rr = 0.0;
    int i;
    tt__spmv(A->rows, A->row_start, A->col, A->value, x, r);
    for (i = 0; i < A->rows; i++) {
        r[i] = b[i] - r[i];
        rr += r[i] * r[i];
    }
    return rr;
}

/* p = z = M^-1 r (a fresh start of the directions); returns r . z. */
static double tt__cg_restart(int n, const double *TT__RESTRICT r, const double *TT__RESTRICT inv_diag,
                             double *TT__RESTRICT p)
{
    double rz = 0.0;
    int i;
    for (i = 0; i < n; i++) {
        p[i] = r[i] * inv_diag[i];
        rz += r[i] * p[i];
    }
    return rz;
}

/* r -= alpha Ap and the two new dot products in one pass: returns r . z with
   z = M^-1 r (z itself is never stored), *rr_out = r . r. Four partial sums
   (lanes i mod 4) break the chain of dependent additions, so the loop runs at
   the speed of memory rather than of the adder's latency. */
static double tt__cg_update(int n, double alpha, double *TT__RESTRICT r, const double *TT__RESTRICT Ap,
                            const double *TT__RESTRICT inv_diag, double *rr_out)
{
    double rz[4] = {0.0, 0.0, 0.0, 0.0}, rr[4] = {0.0, 0.0, 0.0, 0.0};
    int i, lane;
    for (i = 0; i + 3 < n; i += 4)
        for (lane = 0; lane < 4; lane++) {
            double ri = r[i + lane] - alpha * Ap[i + lane];
            r[i + lane] = ri;
            rr[lane] += ri * ri;
            rz[lane] += ri * ri * inv_diag[i + lane];
        }
    for (; i < n; i++) {
        double ri = r[i] - alpha * Ap[i];
        r[i] = ri;
        rr[0] += ri * ri;
        rz[0] += ri * ri * inv_diag[i];
    }
    *rr_out = (rr[0] + rr[1]) + (rr[2] + rr[3]);
    return (rz[0] + rz[1]) + (rz[2] + rz[3]);
}

/* x += alpha p with the old direction, then p = M^-1 r + beta p: x is updated
   here rather than with r, so that p is read once per step, not twice. */
static void tt__cg_direction(int n, double alpha, double beta, const double *TT__RESTRICT r,
                             const double *TT__RESTRICT inv_diag, double *TT__RESTRICT p, double *TT__RESTRICT x)
{
    int i;
    for (i = 0; i < n; i++) {
        double pi = p[i];
        x[i] += alpha * pi;
        p[i] = r[i] * inv_diag[i] + beta * pi;
    }
}

/* x += alpha p: the last step's update of x when no new direction follows. */
static void tt__cg_axpy(int n, double alpha, const double *TT__RESTRICT p, double *TT__RESTRICT x)
{
    int i;
    for (i = 0; i < n; i++) x[i] += alpha * p[i];
}

/* One pass over A for tt_cg_solve: consistent row_start, columns in range,
   finite values, a positive diagonal (repeated diagonal entries add up);
   inv_diag[i] = 1 / A[i][i]. */
static tt_result tt__cg_check_matrix(const tt_sparse_matrix *A, double *inv_diag, tt_error *error)
{
    int i, k, n = A->rows;
    if (n > 0 && !A->row_start)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1, "the matrix has %d rows but no row_start", n);
    if (n > 0 && (A->row_start[0] != 0 || A->row_start[n] != A->nnz))
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "the matrix's row_start runs from %d to %d; it must run from 0 to nnz = %d", A->row_start[0],
                        A->row_start[n], A->nnz);
    if (A->nnz > 0 && (!A->col || !A->value))
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "the matrix has %d entries but no col or value array", A->nnz);
    for (i = 0; i < n; i++) {
        int begin = A->row_start[i], end = A->row_start[i + 1];
        double diagonal = 0.0;
        if (end < begin)
            return tt__fail_at(error, TT_ERROR_INVALID_ARGUMENT, -1, i, -1,
                               "the matrix's row_start decreases at row %d (%d, then %d)", i, begin, end);
        for (k = begin; k < end; k++) {
            int c = A->col[k];
            double v = A->value[k];
            if (c < 0 || c >= n)
                return tt__fail_at(error, TT_ERROR_INDEX_OUT_OF_RANGE, -1, i, c,
                                   "entry %d of the matrix is at row %d, column %d, outside the %d x %d matrix", k,
                                   i, c, n, n);
            if (!tt__is_finite_d(v))
                return tt__fail_at(error, TT_ERROR_NON_FINITE, -1, i, c,
                                   "the matrix entry at row %d, column %d is %g", i, c, v);
            if (c == i) diagonal += v;
        }
        if (!(diagonal > 0.0))
            return tt__fail_at(error, TT_ERROR_NOT_POSITIVE_DEFINITE, -1, i, i,
                               "row %d has diagonal entry %g%s: a symmetric positive definite matrix has a positive "
                               "diagonal", i, diagonal, begin == end ? " (the row is empty)" : "");
        inv_diag[i] = 1.0 / diagonal;
    }
    return TT_OK;
}

/* The incomplete Cholesky factor IC(0): row i of L holds A's entries of
   row i at columns <= i, the diagonal last; L L^T matches A on that
   pattern. */
typedef struct tt__ic0 {
    int *start;                 /* n + 1 */
    int *col;
    double *value;
} tt__ic0;

/* Makes the factor (arrays from the allocator, into *F). Returns 1, 0 when a
   pivot is not positive (F freed), -1 when out of memory, -2 when row
   *bad_row's columns do not increase. */
static int tt__ic0_factor(const tt_sparse_matrix *A, const tt_allocator *allocator, tt__ic0 *F, int *bad_row)
{
    const int n = A->rows;
    int i, k, m = 0, made = -1;
    memset(F, 0, sizeof *F);
    for (i = 0; i < n; i++)
        for (k = A->row_start[i]; k < A->row_start[i + 1]; k++) {
            if (k > A->row_start[i] && A->col[k] <= A->col[k - 1]) {
                *bad_row = i;
                return -2;
            }
            m += A->col[k] <= i;
        }
    F->start = TT__ALLOC(allocator, int, (size_t)n + 1);
    F->col = TT__ALLOC(allocator, int, m > 0 ? m : 1);
    F->value = TT__ALLOC(allocator, double, m > 0 ? m : 1);
    if (!F->start || !F->col || !F->value) goto failed;
    m = 0;
    for (i = 0; i < n; i++) {
        F->start[i] = m;
        for (k = A->row_start[i]; k < A->row_start[i + 1] && A->col[k] <= i; k++) {
            F->col[m] = A->col[k];
            F->value[m++] = A->value[k];
        }
        /* Every row has its diagonal (tt__cg_check_matrix), last. */
    }
    F->start[n] = m;
    for (i = 0; i < n; i++)
        for (k = F->start[i]; k < F->start[i + 1]; k++) {
            const int c = F->col[k];
            int a = F->start[i], b = F->start[c];
            double sum = F->value[k];
            /* sum over the columns j < c that rows i and c both have */
            while (a < k && b < F->start[c + 1] - 1) {
                if (F->col[a] == F->col[b]) sum -= F->value[a++] * F->value[b++];
                else if (F->col[a] < F->col[b]) a++;
                else b++;
            }
            if (c < i) {
                F->value[k] = sum / F->value[F->start[c + 1] - 1];
            } else if (sum > 0.0) {
                F->value[k] = sqrt(sum);
            } else {
                made = 0;
                goto failed;
            }
        }
    return 1;
failed:
    tt__free(allocator, F->start);
    tt__free(allocator, F->col);
    tt__free(allocator, F->value);
    memset(F, 0, sizeof *F);
    return made;
}

/* z = (L L^T)^-1 r: forward, then backward (L^T by columns of L's rows). */
static void tt__ic0_apply(const tt__ic0 *F, int n, const double *TT__RESTRICT r, double *TT__RESTRICT z)
{
    int i, k;
    for (i = 0; i < n; i++) {
        const int last = F->start[i + 1] - 1;
        double sum = r[i];
        for (k = F->start[i]; k < last; k++) sum -= F->value[k] * z[F->col[k]];
        z[i] = sum / F->value[last];
    }
    for (i = n - 1; i >= 0; i--) {
        const int last = F->start[i + 1] - 1;
        z[i] /= F->value[last];
        for (k = F->start[i]; k < last; k++) z[F->col[k]] -= F->value[k] * z[i];
    }
}

/* r -= alpha Ap (*rr_out = r . r), z = M^-1 r; returns r . z. */
static double tt__ic0_update(const tt__ic0 *F, int n, double alpha, double *TT__RESTRICT r,
                             const double *TT__RESTRICT Ap, double *TT__RESTRICT z, double *rr_out)
{
    double rr = 0.0, rz = 0.0;
    int i;
    for (i = 0; i < n; i++) {
        r[i] -= alpha * Ap[i];
        rr += r[i] * r[i];
    }
    tt__ic0_apply(F, n, r, z);
    for (i = 0; i < n; i++) rz += r[i] * z[i];
    *rr_out = rr;
    return rz;
}

/* x += alpha p with the old direction, then p = z + beta p. */
static void tt__ic0_direction(int n, double alpha, double beta, const double *TT__RESTRICT z, double *TT__RESTRICT p,
                              double *TT__RESTRICT x)
{
    int i;
    for (i = 0; i < n; i++) {
        x[i] += alpha * p[i];
        p[i] = z[i] + beta * p[i];
    }
}

/* p = z = M^-1 r; returns r . z. */
static double tt__ic0_restart(const tt__ic0 *F, int n, const double *TT__RESTRICT r, double *TT__RESTRICT z,
                              double *TT__RESTRICT p)
{
    double rz = 0.0;
    int i;
    tt__ic0_apply(F, n, r, z);
    for (i = 0; i < n; i++) {
        p[i] = z[i];
        rz += r[i] * z[i];
    }
    return rz;
}

TTDEF tt_result tt_cg_solve(const tt_sparse_matrix *A, const double *b_in, const tt_cg_options *options,
                            const tt_allocator *allocator, double *x, tt_cg_report *report, tt_error *error)
{
    tt_cg_options opt;
    tt_cg_report rep;
    tt_result result = TT_OK;
    double *block, *r, *p, *Ap, *inv_diag, *b, *z = NULL;
    tt__ic0 factor;
    int ic = 0;
    double bb = 0.0, b_max = 0.0, norm_b, limit, rr, rz, shown = 0.0;
    int i, n, max_iterations, r_is_true, b_exponent = 0;

    memset(&rep, 0, sizeof rep);
    memset(&factor, 0, sizeof factor);
    if (options) rep.preconditioner = options->preconditioner;
    if (report) *report = rep;
    tt__ok(error);
    if (options) opt = *options;
    else memset(&opt, 0, sizeof opt);
    if (tt__check_allocator(allocator, error) != TT_OK) return TT_ERROR_INVALID_ARGUMENT;
    if (!A || !b_in || !x)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "tt_cg_solve needs a matrix, a right-hand side and a solution vector; one is NULL");
    if (b_in == x)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "the right-hand side b and the solution x must be different arrays");
    if (opt.max_iterations < 0 || !(opt.tolerance >= 0.0) || !tt__is_finite_d(opt.tolerance))
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "max_iterations %d and tolerance %g: neither may be negative (0 = default)", opt.max_iterations,
                        opt.tolerance);
    if (opt.preconditioner != TT_CG_JACOBI && opt.preconditioner != TT_CG_INCOMPLETE_CHOLESKY)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "preconditioner %d: use TT_CG_JACOBI (0) or TT_CG_INCOMPLETE_CHOLESKY (1)", opt.preconditioner);
    if (A->rows != A->cols || A->rows < 0)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "the matrix is %d x %d; conjugate gradients need a square matrix", A->rows, A->cols);
    n = A->rows;
    if (opt.tolerance == 0.0) opt.tolerance = 1e-8;
    max_iterations = opt.max_iterations;
    if (max_iterations == 0) max_iterations = n > 0x3fffffff ? 0x7fffffff : (2 * n > 100 ? 2 * n : 100);

    /* One block for the whole solve: r, p, Ap, the inverse diagonal and b
       scaled (below). */
    if (!tt__size_fits((size_t)n, 6 * sizeof(double)))
        return tt__fail(error, TT_ERROR_TOO_LARGE, -1, -1, -1, -1, "%d unknowns need more bytes than size_t can count",
                        n);
    block = TT__ALLOC(allocator, double, (size_t)n * (opt.preconditioner == TT_CG_INCOMPLETE_CHOLESKY ? 6 : 5));
    if (!block)
        return tt__fail(error, TT_ERROR_OUT_OF_MEMORY, -1, -1, -1, -1, "out of memory for %d unknowns", n);
    r = block;
    p = r + n;
    Ap = p + n;
    inv_diag = Ap + n;
    b = inv_diag + n;

    if ((result = tt__cg_check_matrix(A, inv_diag, error)) != TT_OK) goto done;
    if (opt.preconditioner == TT_CG_INCOMPLETE_CHOLESKY) {
        int bad_row = -1, made = tt__ic0_factor(A, allocator, &factor, &bad_row);
        if (made == -1) {
            result = tt__fail(error, TT_ERROR_OUT_OF_MEMORY, -1, -1, -1, -1,
                              "out of memory for the incomplete Cholesky factor of %d unknowns", n);
            goto done;
        }
        if (made == -2) {
            result = tt__fail_at(error, TT_ERROR_INVALID_ARGUMENT, -1, bad_row, -1,
                                 "row %d's columns do not increase: incomplete Cholesky needs them strictly "
                                 "increasing (as tt_sparse_from_triplets makes them)", bad_row);
            goto done;
        }
        ic = made == 1;
        z = b + n;
        rep.preconditioner = ic ? TT_CG_INCOMPLETE_CHOLESKY : TT_CG_JACOBI;   /* a pivot <= 0: Jacobi */
    }
    for (i = 0; i < n; i++) {
        if (!tt__is_finite_d(b_in[i])) {
            result = tt__fail_at(error, TT_ERROR_NON_FINITE, -1, i, -1, "the right-hand side b[%d] is %g", i, b_in[i]);
            goto done;
        }
        if (!tt__is_finite_d(x[i])) {
            result = tt__fail_at(error, TT_ERROR_NON_FINITE, -1, i, -1, "the initial guess x[%d] is %g", i, x[i]);
            goto done;
        }
        if (fabs(b_in[i]) > b_max) b_max = fabs(b_in[i]);
    }
    if (b_max == 0.0) {
        /* A x = 0 with A positive definite: x = 0 exactly. */
        for (i = 0; i < n; i++) x[i] = 0.0;
        rep.converged = 1;
        goto done;
    }
    /* The system is solved for b / 2^e and x / 2^e with max |b_i| / 2^e in
       [0.5, 1): powers of two scale exactly, and the sums of squares can then
       neither overflow (|b_i| above 1e154) nor underflow to zero (all |b_i|
       below 1e-162), which would make any x look converged. */
    frexp(b_max, &b_exponent);
    for (i = 0; i < n; i++) {
        b[i] = ldexp(b_in[i], -b_exponent);
        x[i] = ldexp(x[i], -b_exponent);
        bb += b[i] * b[i];
    }
    norm_b = sqrt(bb);
    limit = opt.tolerance * norm_b;

    rr = tt__cg_residual(A, b, x, r);
    r_is_true = 1;
    rz = ic ? tt__ic0_restart(&factor, n, r, z, p) : tt__cg_restart(n, r, inv_diag, p);
    for (;;) {
        double pAp, alpha, rz_next;
        if (sqrt(rr) <= limit) {
            /* The updated r drifts from b - A x by rounding: success is only
               claimed for a freshly computed residual. If that one is still too
               big, start the directions afresh from it (Shewchuk Sec. 11). */
            if (!r_is_true) {
                rr = tt__cg_residual(A, b, x, r);
                r_is_true = 1;
            }
            if (sqrt(rr) <= limit) {
                rep.converged = 1;
                break;
            }
            rz = ic ? tt__ic0_restart(&factor, n, r, z, p) : tt__cg_restart(n, r, inv_diag, p);
        }
        if (rep.iterations >= max_iterations) {
            result = TT_ERROR_NOT_CONVERGED;   /* the message, with the final residual, below */
            break;
        }
        if (opt.progress) {
            double rel = sqrt(rr) / norm_b, fraction = (double)rep.iterations / max_iterations;
            if (opt.tolerance < 1.0 && rel < 1.0 && log(rel) / log(opt.tolerance) > fraction)
                fraction = log(rel) / log(opt.tolerance);
            if (fraction > 1.0) fraction = 1.0;
            if (fraction > shown) shown = fraction;
            if (opt.progress((float)shown, opt.progress_user_data)) {
                result = tt__fail(error, TT_CANCELLED, -1, -1, -1, -1,
                                  "cancelled by the progress callback after %d conjugate gradient steps",
                                  rep.iterations);
                break;
            }
        }
        pAp = tt__spmv_dot(n, A->row_start, A->col, A->value, p, Ap);
        if (!tt__is_finite_d(pAp)) {
            result = tt__fail(error, TT_ERROR_NON_FINITE, -1, -1, -1, -1,
                              "conjugate gradients overflowed at step %d (p . A p = %g): scale the system",
                              rep.iterations, pAp);
            break;
        }
        if (pAp <= 0.0) {
            result = tt__fail(error, TT_ERROR_NOT_POSITIVE_DEFINITE, -1, -1, -1, -1,
                              "conjugate gradients broke down at step %d: p . A p = %g <= 0, so the matrix is not "
                              "positive definite", rep.iterations, pAp);
            break;
        }
        alpha = rz / pAp;
        rz_next = ic ? tt__ic0_update(&factor, n, alpha, r, Ap, z, &rr) : tt__cg_update(n, alpha, r, Ap, inv_diag, &rr);
        rep.iterations++;
        r_is_true = 0;
        if (sqrt(rr) <= limit) {
            tt__cg_axpy(n, alpha, p, x);
            continue;   /* confirmed (or restarted) at the top */
        }
        if (ic) tt__ic0_direction(n, alpha, rz_next / rz, z, p, x);
        else tt__cg_direction(n, alpha, rz_next / rz, r, inv_diag, p, x);
        rz = rz_next;
    }
    if (!r_is_true) rr = tt__cg_residual(A, b, x, r);
    rep.residual = sqrt(rr) / norm_b;
    for (i = 0; i < n; i++) x[i] = ldexp(x[i], b_exponent);
    for (i = 0; i < n && result == TT_OK; i++)
        if (!tt__is_finite_d(x[i]))
            result = tt__fail_at(error, TT_ERROR_NON_FINITE, -1, i, -1,
                                 "the solution overflows at x[%d]: scale the system", i);
    if (result == TT_ERROR_NOT_CONVERGED)
        tt__fail(error, result, -1, -1, -1, -1,
                 "conjugate gradients stopped after %d steps (max_iterations) at relative residual %.3g, above the "
                 "tolerance %.3g", rep.iterations, rep.residual, opt.tolerance);

done:
    tt__free(allocator, block);
    tt__free(allocator, factor.start);
    tt__free(allocator, factor.col);
    tt__free(allocator, factor.value);
    if (report) *report = rep;
    return result;
}

/* ---- Fast Fourier transforms ---- */

/* log2 n for a power of two n >= 1, else -1. */
static int tt__fft_log2(int n)
{
    int k = 0;
    if (n < 1 || (n & (n - 1)) != 0) return -1;
    while ((1 << k) < n) k++;
    return k;
}

/* TT_OK when n is a power of two in [1, TT_FFT_MAX_SIZE]; otherwise the
   error, naming the nearest power of two and the one to pad to. */
static tt_result tt__fft_check_size(const char *what, int n, tt_error *error)
{
    int below = 1;
    if (n >= 1 && n <= TT_FFT_MAX_SIZE && tt__fft_log2(n) >= 0) return TT_OK;
    if (n < 1)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "%s %d: FFT sizes are powers of two from 1 to %d", what, n, TT_FFT_MAX_SIZE);
    if (n > TT_FFT_MAX_SIZE)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "%s %d is above the largest FFT size, %d (the nearest power of two allowed)", what, n,
                        TT_FFT_MAX_SIZE);
    while (below * 2 < n) below *= 2;
    return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                    "%s %d is not a power of two: the nearest is %d; pad the data to %d", what, n,
                    n - below <= 2 * below - n ? below : 2 * below, 2 * below);
}

TTDEF void tt_fft_plan_free(tt_fft_plan *plan)
{
    tt_allocator allocator;
    if (!plan) return;
    allocator = plan->allocator;
    tt__free(&allocator, plan->twiddles);
    tt__free(&allocator, plan->real_twiddles);
    tt__free(&allocator, plan->bit_reverse);
    tt__free(&allocator, plan);
}

TTDEF tt_result tt_fft_plan_create(int width, int height, const tt_allocator *allocator, tt_fft_plan **out,
                                   tt_error *error)
{
    tt_fft_plan *plan;
    int size, log2_size, i, L;
    tt__ok(error);
    if (!out) return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1, "out is NULL");
    *out = NULL;
    if (tt__check_allocator(allocator, error) != TT_OK) return TT_ERROR_INVALID_ARGUMENT;
    if (tt__fft_check_size("the width", width, error) != TT_OK ||
        tt__fft_check_size("the height", height, error) != TT_OK)
        return TT_ERROR_INVALID_ARGUMENT;
    plan = TT__ALLOC(allocator, tt_fft_plan, 1);
    if (!plan) goto out_of_memory;
    memset(plan, 0, sizeof *plan);
    plan->allocator = tt__allocator_copy(allocator);
    plan->width = width;
    plan->height = height;
    plan->log2_width = tt__fft_log2(width);
    plan->log2_height = tt__fft_log2(height);
    size = width > height ? width : height;
    log2_size = tt__fft_log2(size);
    plan->size = size;
    /* 6 (L - 1) doubles before the stage of quarter length L: 6 (size / 2 - 1)
       in all (at least one, so that a size-1 plan still has an array). */
    plan->twiddles = TT__ALLOC(&plan->allocator, double, size >= 4 ? 6 * (size / 2 - 1) : 1);
    plan->real_twiddles = TT__ALLOC(&plan->allocator, double, width);
    plan->bit_reverse = TT__ALLOC(&plan->allocator, int, size);
    if (!plan->twiddles || !plan->real_twiddles || !plan->bit_reverse) {
        tt_fft_plan_free(plan);
        goto out_of_memory;
    }
    for (L = 1; 4 * L <= size; L *= 2) {
        double *t = plan->twiddles + 6 * (L - 1);
        int k, m;
        for (k = 0; k < L; k++)
            for (m = 1; m <= 3; m++) {
                /* Each entry directly from its angle: no recurrence, no drift. */
                double angle = TT__TWO_PI * (double)(k * m) / (double)(4 * L);
                t[6 * k + 2 * (m - 1)] = cos(angle);
                t[6 * k + 2 * (m - 1) + 1] = sin(angle);
            }
    }
    for (i = 0; i < width / 2; i++) {
        double angle = TT__TWO_PI * (double)i / (double)width;
        plan->real_twiddles[2 * i] = cos(angle);
        plan->real_twiddles[2 * i + 1] = sin(angle);
    }
    if (width == 1) plan->real_twiddles[0] = 1.0;
    for (i = 0; i < size; i++) {
        int b, r = 0;
        for (b = 0; b < log2_size; b++)
            if (i & (1 << b)) r |= 1 << (log2_size - 1 - b);
        plan->bit_reverse[i] = r;
    }
    *out = plan;
    return TT_OK;

out_of_memory:
    return tt__fail(error, TT_ERROR_OUT_OF_MEMORY, -1, -1, -1, -1, "out of memory for a %d x %d FFT plan", width,
                    height);
}

/* Non-zero (bit 63) when one of v[0 .. n-1] is a NaN or infinity: adding 1
   to an all-ones exponent carries into the sign bit. Integer operations on
   the bits, so it holds under -ffast-math and vectorises. */
static uint64_t tt__fft_nonfinite(const double *v, size_t n)
{
    uint64_t found = 0;
    size_t i;
    for (i = 0; i < n; i++) {
        uint64_t bits;
        memcpy(&bits, v + i, sizeof bits);
        found |= (bits & 0x7ff0000000000000ull) + 0x0010000000000000ull;
    }
    return found >> 63;
}

/* The 1D transform of n = 2^log2n contiguous complex values x (a row), in
   place; sign = direction. Bit reversal, one radix-2 stage when log2n is
   odd, then radix-4 stages. After the stages of quarter length L, each block
   of 4 L values holds, as radix-2 bit reversal leaves them, the transforms of
   its elements r mod 4 in the order r = 0, 2, 1, 3; the radix-4 butterfly
   combines them as X(k + q L) = sum_r w^(r k) Y_r(k) (sign i)^(r q). */
static void tt__fft_row(const tt_fft_plan *plan, double *TT__RESTRICT x, int n, int log2n, double sign)
{
    int i, L, shift = tt__fft_log2(plan->size) - log2n;
    for (i = 0; i < n; i++) {
        int j = plan->bit_reverse[i] >> shift;
        if (i < j) {
            double re = x[2 * i], im = x[2 * i + 1];
            x[2 * i] = x[2 * j];
            x[2 * i + 1] = x[2 * j + 1];
            x[2 * j] = re;
            x[2 * j + 1] = im;
        }
    }
    L = 1;
    if (log2n & 1) {
        for (i = 0; i < 2 * n; i += 4) {
            double ar = x[i], ai = x[i + 1], br = x[i + 2], bi = x[i + 3];
            x[i] = ar + br;
            x[i + 1] = ai + bi;
            x[i + 2] = ar - br;
            x[i + 3] = ai - bi;
        }
        L = 2;
    }
    for (; 4 * L <= n; L *= 4) {
        const double *tw = plan->twiddles + 6 * (L - 1);
        int base, k;
        for (base = 0; base < n; base += 4 * L) {
            {
                double *p0 = x + 2 * base, *p1 = p0 + 2 * L, *p2 = p1 + 2 * L, *p3 = p2 + 2 * L;
                double ar = p0[0], ai = p0[1], br = p2[0], bi = p2[1], cr = p1[0], ci = p1[1], dr = p3[0];
                double di = p3[1], t0r = ar + cr, t0i = ai + ci, t1r = ar - cr, t1i = ai - ci;   /* k = 0: w = 1 */
                double t2r = br + dr, t2i = bi + di, t3r = sign * (br - dr), t3i = sign * (bi - di);
                p0[0] = t0r + t2r;
                p0[1] = t0i + t2i;
                p2[0] = t0r - t2r;
                p2[1] = t0i - t2i;
                p1[0] = t1r - t3i;
                p1[1] = t1i + t3r;
                p3[0] = t1r + t3i;
                p3[1] = t1i - t3r;
            }
            for (k = 1; k < L; k++) {
                double *p0 = x + 2 * (base + k), *p1 = p0 + 2 * L, *p2 = p1 + 2 * L, *p3 = p2 + 2 * L;
                double w1r = tw[6 * k], w1i = sign * tw[6 * k + 1], w2r = tw[6 * k + 2], w2i = sign * tw[6 * k + 3];
                double w3r = tw[6 * k + 4], w3i = sign * tw[6 * k + 5];
                double ar = p0[0], ai = p0[1];
                double br = w1r * p2[0] - w1i * p2[1], bi = w1r * p2[1] + w1i * p2[0];   /* w^k Y1 */
                double cr = w2r * p1[0] - w2i * p1[1], ci = w2r * p1[1] + w2i * p1[0];   /* w^2k Y2 */
                double dr = w3r * p3[0] - w3i * p3[1], di = w3r * p3[1] + w3i * p3[0];   /* w^3k Y3 */
                double t0r = ar + cr, t0i = ai + ci, t1r = ar - cr, t1i = ai - ci;
                double t2r = br + dr, t2i = bi + di, t3r = sign * (br - dr), t3i = sign * (bi - di);
                p0[0] = t0r + t2r;
                p0[1] = t0i + t2i;
                p2[0] = t0r - t2r;
                p2[1] = t0i - t2i;
                p1[0] = t1r - t3i;   /* t1 + sign i t3 */
                p1[1] = t1i + t3r;
                p3[0] = t1r + t3i;   /* t1 - sign i t3 */
                p3[1] = t1i - t3r;
            }
        }
    }
}

/* The radix-4 butterfly on four row segments of `count` complex values
   with one set of twiddles: the column pass's inner loop, unit-stride and
   free of branches so that it vectorises. */
static void tt__fft_strip_butterfly(double *TT__RESTRICT p0, double *TT__RESTRICT p1, double *TT__RESTRICT p2,
                                    double *TT__RESTRICT p3, int count, const double *w, double sign)
{
    double w1r = w[0], w1i = sign * w[1], w2r = w[2], w2i = sign * w[3], w3r = w[4], w3i = sign * w[5];
    int j;
    for (j = 0; j < 2 * count; j += 2) {
        double ar = p0[j], ai = p0[j + 1];
        double br = w1r * p2[j] - w1i * p2[j + 1], bi = w1r * p2[j + 1] + w1i * p2[j];
        double cr = w2r * p1[j] - w2i * p1[j + 1], ci = w2r * p1[j + 1] + w2i * p1[j];
        double dr = w3r * p3[j] - w3i * p3[j + 1], di = w3r * p3[j + 1] + w3i * p3[j];
        double t0r = ar + cr, t0i = ai + ci, t1r = ar - cr, t1i = ai - ci;
        double t2r = br + dr, t2i = bi + di, t3r = sign * (br - dr), t3i = sign * (bi - di);
        p0[j] = t0r + t2r;
        p0[j + 1] = t0i + t2i;
        p2[j] = t0r - t2r;
        p2[j + 1] = t0i - t2i;
        p1[j] = t1r - t3i;
        p1[j + 1] = t1i + t3r;
        p3[j] = t1r + t3i;
        p3[j + 1] = t1i - t3r;
    }
}

/* The same for k = 0, whose twiddles are 1: no multiplies. */
static void tt__fft_strip_butterfly1(double *TT__RESTRICT p0, double *TT__RESTRICT p1, double *TT__RESTRICT p2,
                                     double *TT__RESTRICT p3, int count, double sign)
{
    int j;
    for (j = 0; j < 2 * count; j += 2) {
        double ar = p0[j], ai = p0[j + 1], br = p2[j], bi = p2[j + 1];
        double cr = p1[j], ci = p1[j + 1], dr = p3[j], di = p3[j + 1];
        double t0r = ar + cr, t0i = ai + ci, t1r = ar - cr, t1i = ai - ci;
        double t2r = br + dr, t2i = bi + di, t3r = sign * (br - dr), t3i = sign * (bi - di);
        p0[j] = t0r + t2r;
        p0[j + 1] = t0i + t2i;
        p2[j] = t0r - t2r;
        p2[j + 1] = t0i - t2i;
        p1[j] = t1r - t3i;
        p1[j + 1] = t1i + t3r;
        p3[j] = t1r + t3i;
        p3[j + 1] = t1i - t3r;
    }
}

/* The radix-2 butterfly (twiddle 1) on two row segments. */
static void tt__fft_strip_radix2(double *TT__RESTRICT p0, double *TT__RESTRICT p1, int count)
{
    int j;
    for (j = 0; j < 2 * count; j++) {
        double a = p0[j], b = p1[j];
        p0[j] = a + b;
        p1[j] = a - b;
    }
}

static void tt__fft_strip_swap(double *TT__RESTRICT p0, double *TT__RESTRICT p1, int count)
{
    int j;
    for (j = 0; j < 2 * count; j++) {
        double t = p0[j];
        p0[j] = p1[j];
        p1[j] = t;
    }
}

/* One radix-4 stage of quarter length L over `rows` rows of a strip. With
   `check`, tt__fft_nonfinite over the rows written, while they are hot. */
static uint64_t tt__fft_strip_stage(const tt_fft_plan *plan, double *strip, size_t stride, int count, int rows,
                                    int L, double sign, int check)
{
    const double *tw = plan->twiddles + 6 * (L - 1);
    uint64_t found = 0;
    int base, k, q;
    for (base = 0; base < rows; base += 4 * L)
        for (k = 0; k < L; k++) {
            double *p0 = strip + stride * (size_t)(base + k), *p1 = p0 + stride * (size_t)L;
            double *p2 = p1 + stride * (size_t)L, *p3 = p2 + stride * (size_t)L;
            if (k == 0) tt__fft_strip_butterfly1(p0, p1, p2, p3, count, sign);
            else tt__fft_strip_butterfly(p0, p1, p2, p3, count, tw + 6 * k, sign);
            if (check)
                for (q = 0; q < 4; q++) found |= tt__fft_nonfinite(p0 + stride * (size_t)(q * L), 2 * (size_t)count);
        }
    return found;
}

#define TT__FFT_STRIP 32          /* columns transformed together by the column pass */
#define TT__FFT_BLOCK_BYTES 65536 /* the rows of a strip whose first stages run together */

/* The 1D transform along the columns of n = 2^log2n rows of `columns`
   complex values, `stride` doubles apart: strips of TT__FFT_STRIP columns,
   each run through the same stages as tt__fft_row with whole row segments
   as its points. The stages that combine rows less than a block apart (a
   block: TT__FFT_BLOCK_BYTES of the strip) run block by block while it is in
   cache; the rest sweep the strip, one stage at a time. That matters because
   a power-of-two row stride maps a strip's rows onto a fraction of the
   cache's sets: a 512 x 512 strip of 256 KB does not stay in a 2 MB L2.
   Returns tt__fft_nonfinite over the result, checked where it is last
   written. */
static uint64_t tt__fft_columns(const tt_fft_plan *plan, double *data, int columns, size_t stride, int n,
                                int log2n, double sign)
{
    int shift = tt__fft_log2(plan->size) - log2n, first;
    uint64_t found = 0;
    for (first = 0; first < columns; first += TT__FFT_STRIP) {
        double *strip = data + 2 * (size_t)first;
        int count = columns - first < TT__FFT_STRIP ? columns - first : TT__FFT_STRIP, i, L = 1, block, b;
        for (i = 0; i < n; i++) {
            int j = plan->bit_reverse[i] >> shift;
            if (i < j) tt__fft_strip_swap(strip + stride * (size_t)i, strip + stride * (size_t)j, count);
        }
        block = 1;
        while (block < n && (size_t)block * 2 * count * 16 <= TT__FFT_BLOCK_BYTES) block *= 2;
        for (b = 0; b < n; b += block) {
            double *rows = strip + stride * (size_t)b;
            L = 1;
            if (log2n & 1) {
                for (i = 0; i < block; i += 2)
                    tt__fft_strip_radix2(rows + stride * (size_t)i, rows + stride * (size_t)(i + 1), count);
                L = 2;
            }
            for (; 4 * L <= block; L *= 4) tt__fft_strip_stage(plan, rows, stride, count, block, L, sign, 0);
            if (block == n)
                for (i = 0; i < n; i++) found |= tt__fft_nonfinite(rows + stride * (size_t)i, 2 * (size_t)count);
        }
        for (; 4 * L <= n; L *= 4) found |= tt__fft_strip_stage(plan, strip, stride, count, n, L, sign, 4 * L == n);
    }
    return found;
}

/* The 2D complex transform of a plan-sized array (no argument checks). */
static uint64_t tt__fft_c2c(const tt_fft_plan *plan, double *data, double sign)
{
    int y, w = plan->width, h = plan->height;
    uint64_t found = 0;
    if (w > 1)
        for (y = 0; y < h; y++) tt__fft_row(plan, data + 2 * (size_t)w * y, w, plan->log2_width, sign);
    if (h == 1) return tt__fft_nonfinite(data, 2 * (size_t)w);
    if (w == 1) {
        /* One column: contiguous, so the row kernel does it. */
        tt__fft_row(plan, data, h, plan->log2_height, sign);
        return tt__fft_nonfinite(data, 2 * (size_t)h);
    }
    found = tt__fft_columns(plan, data, w, 2 * (size_t)w, h, plan->log2_height, sign);
    return found;
}

/* The forward real transform in place: rows of 2 (width / 2 + 1) doubles, each
   holding `width` reals on entry and its width / 2 + 1 bins on return. Row
   reals x[2m] + i x[2m + 1] are transformed as width / 2 complex values Z;
   then, with w = e^(-2 pi i / width), bins k and width / 2 - k come from
   E = (Z(k) + conj Z(n - k)) / 2 and O = (Z(k) - conj Z(n - k)) / (2i)
   (n = width / 2, indices mod n) as X(k) = E + w^k O and
   X(n - k) = conj(E - w^k O). */
static uint64_t tt__fft_r2c_inplace(const tt_fft_plan *plan, double *data)
{
    int y, w = plan->width, h = plan->height, n = w / 2;
    size_t stride = 2 * (size_t)(w / 2 + 1);
    for (y = 0; y < h; y++) {
        double *x = data + stride * (size_t)y;
        int k;
        if (w == 1) {
            x[1] = 0.0;
            continue;
        }
        if (n > 1) tt__fft_row(plan, x, n, plan->log2_width - 1, -1.0);
        {
            double z0r = x[0], z0i = x[1];
            x[0] = z0r + z0i;
            x[1] = 0.0;
            x[2 * n] = z0r - z0i;
            x[2 * n + 1] = 0.0;
        }
        for (k = 1; 2 * k <= n; k++) {
            double *a = x + 2 * k, *b = x + 2 * (n - k);
            double wr = plan->real_twiddles[2 * k], wi = -plan->real_twiddles[2 * k + 1];
            double er = 0.5 * (a[0] + b[0]), ei = 0.5 * (a[1] - b[1]);
            double or_ = 0.5 * (a[1] + b[1]), oi = -0.5 * (a[0] - b[0]);   /* (a - conj b) / 2i */
            double mr = wr * or_ - wi * oi, mi = wr * oi + wi * or_;
            a[0] = er + mr;
            a[1] = ei + mi;
            if (2 * k != n) {
                b[0] = er - mr;
                b[1] = -(ei - mi);
            }
        }
    }
    if (h == 1) return tt__fft_nonfinite(data, 2 * (size_t)(n + 1));
    return tt__fft_columns(plan, data, n + 1, stride, h, plan->log2_height, -1.0);
}

/* The inverse of tt__fft_r2c_inplace, unnormalised, in place: rows of
   2 (width / 2 + 1) doubles holding width / 2 + 1 bins on entry and `width` reals on
   return. The inverse of the split: Z(k) = (X(k) + conj X(n - k)) +
   i conj(w^k) (X(k) - conj X(n - k)), then the inverse of Z gives
   x[2m] + i x[2m + 1]. */
static uint64_t tt__fft_c2r_inplace(const tt_fft_plan *plan, double *data)
{
    int y, w = plan->width, h = plan->height, n = w / 2;
    size_t stride = 2 * (size_t)(w / 2 + 1);
    uint64_t found = 0;
    if (h > 1) tt__fft_columns(plan, data, n + 1, stride, h, plan->log2_height, 1.0);
    for (y = 0; y < h; y++) {
        double *x = data + stride * (size_t)y;
        int k;
        if (w == 1) {
            found |= tt__fft_nonfinite(x, 1);
            continue;
        }
        {
            double x0 = x[0], xn = x[2 * n];
            x[0] = x0 + xn;
            x[1] = x0 - xn;
        }
        for (k = 1; 2 * k <= n; k++) {
            double *a = x + 2 * k, *b = x + 2 * (n - k);
            double wr = plan->real_twiddles[2 * k], wi = plan->real_twiddles[2 * k + 1];   /* conj(w^k) */
            double er = a[0] + b[0], ei = a[1] - b[1];       /* X(k) + conj X(n - k) */
            double dr = a[0] - b[0], di = a[1] + b[1];       /* X(k) - conj X(n - k) */
            double mr = wr * dr - wi * di, mi = wr * di + wi * dr;   /* conj(w^k) d */
            a[0] = er - mi;   /* e + i m */
            a[1] = ei + mr;
            if (2 * k != n) {
                /* Z(n - k) = conj(e) + i (-w^k) conj(d) = conj(e - i m) */
                b[0] = er + mi;
                b[1] = -(ei - mr);
            }
        }
        if (n > 1) tt__fft_row(plan, x, n, plan->log2_width - 1, 1.0);
        found |= tt__fft_nonfinite(x, (size_t)w);
    }
    return found;
}

/* The checks every transform makes. */
static tt_result tt__fft_check_call(const tt_fft_plan *plan, const void *a, const void *b, int width, int height,
                                    const char *name, tt_error *error)
{
    if (!plan || !a || !b)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1, "%s needs a plan and its arrays; %s is NULL",
                        name, !plan ? "the plan" : "an array");
    if (width != plan->width || height != plan->height)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "%s: the data is %d x %d (width x height) but the plan is for %d x %d", name, width, height,
                        plan->width, plan->height);
    return TT_OK;
}

static tt_result tt__fft_nonfinite_error(const char *name, tt_error *error)
{
    return tt__fail(error, TT_ERROR_NON_FINITE, -1, -1, -1, -1,
                    "%s: the result holds a NaN or infinity: the input has one, or its values overflow", name);
}

TTDEF tt_result tt_fft_c2c(const tt_fft_plan *plan, double *data, int width, int height, int direction,
                           tt_error *error)
{
    tt__ok(error);
    if (tt__fft_check_call(plan, data, data, width, height, "tt_fft_c2c", error) != TT_OK)
        return TT_ERROR_INVALID_ARGUMENT;
    if (direction != TT_FFT_FORWARD && direction != TT_FFT_INVERSE)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "the direction is %d: use TT_FFT_FORWARD (-1) or TT_FFT_INVERSE (+1)", direction);
    if (tt__fft_c2c(plan, data, (double)direction)) return tt__fft_nonfinite_error("tt_fft_c2c", error);
    return TT_OK;
}

TTDEF tt_result tt_fft_r2c(const tt_fft_plan *plan, const double *real, int width, int height, double *spectrum,
                           tt_error *error)
{
    int y;
    tt__ok(error);
    if (tt__fft_check_call(plan, real, spectrum, width, height, "tt_fft_r2c", error) != TT_OK)
        return TT_ERROR_INVALID_ARGUMENT;
    /* Each row of reals into its row of the spectrum (width / 2 + 1 complex
       values: room for the bins), transformed there. */
    for (y = 0; y < height; y++)
        memcpy(spectrum + 2 * (size_t)(width / 2 + 1) * y, real + (size_t)width * y,
               sizeof(double) * (size_t)width);
    if (tt__fft_r2c_inplace(plan, spectrum)) return tt__fft_nonfinite_error("tt_fft_r2c", error);
    return TT_OK;
}

TTDEF tt_result tt_fft_c2r(const tt_fft_plan *plan, double *spectrum, int width, int height, double *real,
                           tt_error *error)
{
    int y;
    uint64_t found;
    tt__ok(error);
    if (tt__fft_check_call(plan, spectrum, real, width, height, "tt_fft_c2r", error) != TT_OK)
        return TT_ERROR_INVALID_ARGUMENT;
    found = tt__fft_c2r_inplace(plan, spectrum);
    for (y = 0; y < height; y++)
        memcpy(real + (size_t)width * y, spectrum + 2 * (size_t)(width / 2 + 1) * y,
               sizeof(double) * (size_t)width);
    if (found) return tt__fft_nonfinite_error("tt_fft_c2r", error);
    return TT_OK;
}

/* ---- Masked cross-correlation ---- */

TTDEF void tt_xcorr_texture_free(tt_xcorr_texture *texture)
{
    tt_allocator allocator;
    if (!texture) return;
    allocator = texture->allocator;
    tt_fft_plan_free(texture->plan);
    tt__free(&allocator, texture->spectra);
    tt__free(&allocator, texture);
}

TTDEF tt_result tt_xcorr_texture_create(int width, int height, int channels, const double *texture,
                                        const tt_allocator *allocator, tt_xcorr_texture **out, tt_error *error)
{
    tt_xcorr_texture *tex;
    size_t plane, half, stride;
    tt_result result;
    int c, x, y;
    double *sum;
    tt__ok(error);
    if (!out) return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1, "out is NULL");
    *out = NULL;
    if (tt__check_allocator(allocator, error) != TT_OK) return TT_ERROR_INVALID_ARGUMENT;
    if (tt__fft_check_size("the texture's width", width, error) != TT_OK ||
        tt__fft_check_size("the texture's height", height, error) != TT_OK)
        return TT_ERROR_INVALID_ARGUMENT;
    if (channels < 1 || !texture)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "a texture needs 1 or more channels and its values (got %d channels%s)", channels,
                        texture ? "" : ", values NULL");
    plane = (size_t)width * (size_t)height;
    stride = 2 * (size_t)(width / 2 + 1);
    if (!tt__size_fits(stride, (size_t)height) ||
        !tt__size_fits(stride * height, ((size_t)channels + 2) * sizeof(double)))   /* best_work_size's bytes */
        return tt__fail(error, TT_ERROR_TOO_LARGE, -1, -1, -1, -1,
                        "the spectra of a %d x %d texture of %d channels need more bytes than size_t can count", width,
                        height, channels);
    half = stride * (size_t)height;
    for (c = 0; c < channels; c++)
        for (y = 0; y < height; y++)
            for (x = 0; x < width; x++) {
                double v = texture[plane * c + (size_t)width * y + x];
                if (!tt__is_finite_d(v) || !tt__is_finite_d(v * v))
                    return tt__fail_at(error, TT_ERROR_NON_FINITE, c, y, x,
                                       "the texture's channel %d at row %d, column %d is %g%s", c, y, x, v,
                                       tt__is_finite_d(v) ? ", whose square overflows" : "");
            }
    tex = TT__ALLOC(allocator, tt_xcorr_texture, 1);
    if (!tex) goto out_of_memory;
    memset(tex, 0, sizeof *tex);
    tex->allocator = tt__allocator_copy(allocator);
    tex->width = width;
    tex->height = height;
    tex->channels = channels;
    tex->spectrum_size = half;
    tex->work_size = 2 * half;
    tex->best_work_size = ((size_t)channels + 2) * half;
    result = tt_fft_plan_create(width, height, &tex->allocator, &tex->plan, NULL);
    tex->spectra = TT__ALLOC(&tex->allocator, double, half * ((size_t)channels + 1));
    if (result != TT_OK || !tex->spectra) {
        tt_xcorr_texture_free(tex);
        goto out_of_memory;
    }
    sum = tex->spectra + half * (size_t)channels;
    memset(sum, 0, sizeof(double) * half);
    for (c = 0; c < channels; c++) {
        double *spectrum = tex->spectra + half * (size_t)c;
        for (y = 0; y < height; y++) {
            const double *row = texture + plane * c + (size_t)width * y;
            double *dst = spectrum + stride * y, *s = sum + stride * y;
            for (x = 0; x < width; x++) {
                dst[x] = row[x];
                s[x] += row[x] * row[x];
            }
        }
        tt__fft_r2c_inplace(tex->plan, spectrum);
    }
    if (tt__fft_nonfinite(sum, half) || tt__fft_r2c_inplace(tex->plan, sum)) {
        tt_xcorr_texture_free(tex);
        return tt__fail(error, TT_ERROR_NON_FINITE, -1, -1, -1, -1,
                        "the sum of the texture's squares overflows: scale the values");
    }
    *out = tex;
    return TT_OK;

out_of_memory:
    return tt__fail(error, TT_ERROR_OUT_OF_MEMORY, -1, -1, -1, -1,
                    "out of memory for the spectra of a %d x %d texture of %d channels", width, height, channels);
}

/* acc (+)= conj(a) b over n complex values. */
static void tt__xcorr_accumulate(double *TT__RESTRICT acc, const double *TT__RESTRICT a,
                                 const double *TT__RESTRICT b, size_t n, int first)
{
    size_t i;
    if (first)
        for (i = 0; i < 2 * n; i += 2) {
            acc[i] = a[i] * b[i] + a[i + 1] * b[i + 1];
            acc[i + 1] = a[i] * b[i + 1] - a[i + 1] * b[i];
        }
    else
        for (i = 0; i < 2 * n; i += 2) {
            acc[i] += a[i] * b[i] + a[i + 1] * b[i + 1];
            acc[i + 1] += a[i] * b[i + 1] - a[i + 1] * b[i];
        }
}

/* The inputs of a masked correlation of w x h texels and `channels` planes,
   checked (finite, non-negative weights; finite values where the weight is
   not 0), and the two sums that need no transform: |J| = sum J and
   sum J I^2. */
static tt_result tt__xcorr_masked_sums(int w, int h, int channels, const double *mask, const double *values,
                                       double *out_mask_sum, double *out_energy, tt_error *error)
{
    size_t plane = (size_t)w * (size_t)h;
    double mask_sum = 0.0, energy = 0.0;
    int c, x, y;
    for (y = 0; y < h; y++)
        for (x = 0; x < w; x++) {
            double j = mask[(size_t)w * y + x];
            if (!tt__is_finite_d(j))
                return tt__fail_at(error, TT_ERROR_NON_FINITE, -1, y, x, "the mask at row %d, column %d is %g", y, x,
                                   j);
            if (j < 0.0)
                return tt__fail_at(error, TT_ERROR_INVALID_ARGUMENT, -1, y, x,
                                   "the mask at row %d, column %d is %g: weights must not be negative", y, x, j);
            if (j == 0.0) continue;
            mask_sum += j;
            for (c = 0; c < channels; c++) {
                double v = values[plane * c + (size_t)w * y + x];
                if (!tt__is_finite_d(v))
                    return tt__fail_at(error, TT_ERROR_NON_FINITE, c, y, x,
                                       "the value of channel %d at row %d, column %d (under the mask) is %g", c, y, x,
                                       v);
                energy += j * v * v;
            }
        }
    if (!tt__is_finite_d(mask_sum) || !tt__is_finite_d(energy))
        return tt__fail(error, TT_ERROR_NON_FINITE, -1, -1, -1, -1,
                        "the sums of the mask (%g) or of J I^2 (%g) overflow: scale the values", mask_sum, energy);
    *out_mask_sum = mask_sum;
    *out_energy = energy;
    return TT_OK;
}

/* The half spectrum of one masked plane, times its factor in the combined
   spectrum (tt__xcorr_add_term), into `spectrum` (spectrum_size doubles):
   F(J) / (w h) for plane -1, -2 F(J I_c) / (w h) for plane c >= 0. J I_c is
   0 where J is, whatever I_c holds there (it may be NaN). The factors are
   powers of two, so scaling the plane before its transform scales every
   product exactly (barring underflow), and costs nothing per texture it
   meets. Returns the transform's non-finite flag. */
static uint64_t tt__xcorr_masked_spectrum(const tt_xcorr_texture *texture, const double *mask, const double *values,
                                          int plane_index, double *spectrum)
{
    int w = texture->width, h = texture->height, x, y;
    size_t plane = (size_t)w * (size_t)h, stride = 2 * (size_t)(w / 2 + 1);
    double inv_n = 1.0 / (double)plane, factor = plane_index < 0 ? inv_n : -2.0 * inv_n;
    for (y = 0; y < h; y++) {
        const double *jr = mask + (size_t)w * y;
        double *dst = spectrum + stride * y;
        if (plane_index < 0) {
            for (x = 0; x < w; x++) dst[x] = factor * jr[x];
        } else {
            const double *vr = values + plane * plane_index + (size_t)w * y;
            for (x = 0; x < w; x++) dst[x] = jr[x] != 0.0 ? factor * (jr[x] * vr[x]) : 0.0;
        }
    }
    return tt__fft_r2c_inplace(texture->plan, spectrum);
}

/* One term of the combined spectrum
       acc = (conj F(J) F(sum T^2) - 2 sum_c conj F(J I_c) F(T_c)) / (w h)
   over its complex values [begin, begin + count): plane -1 sets acc, plane
   c >= 0 adds its product; `masked` is that plane's scaled spectrum
   (tt__xcorr_masked_spectrum). The division by w h lets the unnormalised
   inverse give the two correlation terms of E. */
static void tt__xcorr_add_term(double *acc, const double *masked, const tt_xcorr_texture *texture, int plane_index,
                               size_t begin, size_t count)
{
    size_t at = 2 * begin;
    if (plane_index < 0) {
        const double *squares = texture->spectra + texture->spectrum_size * (size_t)texture->channels;
        tt__xcorr_accumulate(acc + at, masked + at, squares + at, count, 1);
    } else {
        const double *channel = texture->spectra + texture->spectrum_size * (size_t)plane_index;
        tt__xcorr_accumulate(acc + at, masked + at, channel + at, count, 0);
    }
}

/* One row of E over the correlation's row v, in place:
   v[x] = max(v[x] + energy, 0) (the clamp: the sum of three large terms can
   round below 0), and the row's smallest E into *row_min. Two values a step,
   so that at -O2 each step is one vector operation, as in the transforms.
   Returns non-zero when a sum is a NaN or infinity, tested before the clamp
   could hide it. */
static uint64_t tt__xcorr_energy_row(double *v, int n, double energy, double *row_min)
{
    double low0 = HUGE_VAL, low1 = HUGE_VAL;
    uint64_t found;
    int x;
    for (x = 0; x + 2 <= n; x += 2) {
        v[x] += energy;
        v[x + 1] += energy;
    }
    if (x < n) v[x] += energy;
    found = tt__fft_nonfinite(v, (size_t)n);
    for (x = 0; x + 2 <= n; x += 2) {
        double e0 = v[x] > 0.0 ? v[x] : 0.0, e1 = v[x + 1] > 0.0 ? v[x + 1] : 0.0;
        v[x] = e0;
        v[x + 1] = e1;
        low0 = e0 < low0 ? e0 : low0;
        low1 = e1 < low1 ? e1 : low1;
    }
    if (x < n) {
        v[x] = v[x] > 0.0 ? v[x] : 0.0;
        low0 = v[x] < low0 ? v[x] : low0;
    }
    *row_min = low0 < low1 ? low0 : low1;
    return found;
}

/* E from the inverse transform of the combined spectrum (`correlation`,
   rows 2 (width / 2 + 1) doubles apart), E = sum J I^2 + it at every
   offset, over the correlation (work space) and copied to map (row-major)
   unless map is NULL; and the allowed offset with the smallest E, the first
   in row-major order on a tie, into *best (y * width + x; -1 when none is
   allowed) and *best_e. A row whose smallest E, allowed or not, is no
   smaller than the best so far is not searched. Returns non-zero when an E
   is a NaN or infinity. */
static uint64_t tt__xcorr_scan(const tt_xcorr_texture *texture, double energy, double *correlation,
                               const unsigned char *allowed, double *map, int *best, double *best_e)
{
    int w = texture->width, h = texture->height, x, y, at = -1;
    size_t stride = 2 * (size_t)(w / 2 + 1);
    double low = HUGE_VAL, row_min;
    uint64_t found = 0;
    for (y = 0; y < h; y++) {
        double *e = correlation + stride * y;
        const unsigned char *ok = allowed ? allowed + (size_t)w * y : NULL;
        found |= tt__xcorr_energy_row(e, w, energy, &row_min);
        if (map) memcpy(map + (size_t)w * y, e, sizeof(double) * (size_t)w);
        if (!(row_min < low)) continue;
        for (x = 0; x < w; x++)
            if (e[x] < low && (!ok || ok[x])) {
                at = w * y + x;
                low = e[x];
            }
    }
    *best = at;
    *best_e = at < 0 ? 0.0 : low;
    return found;
}

TTDEF tt_result tt_xcorr_masked(const tt_xcorr_texture *texture, const double *mask, const double *values,
                                const unsigned char *allowed, double *work, double *out_map,
                                tt_xcorr_match *out_match, tt_error *error)
{
    int c, best;
    size_t half, plane, i;
    double *acc, *tmp, mask_sum, energy, best_e;
    uint64_t found = 0;
    tt_xcorr_match match;
    tt_result result;
    match.x = match.y = -1;
    match.e = match.mask_sum = match.masked_energy = 0.0;
    if (out_match) *out_match = match;
    tt__ok(error);
    if (!texture || !mask || !values || !work)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "tt_xcorr_masked needs a texture, a mask, values and work space; %s is NULL",
                        !texture ? "the texture" : !mask ? "the mask" : !values ? "values" : "work");
    if (!out_map && !out_match)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "tt_xcorr_masked: out_map and out_match are both NULL, so there is nothing to compute");
    result = tt__xcorr_masked_sums(texture->width, texture->height, texture->channels, mask, values, &mask_sum,
                                   &energy, error);
    if (result != TT_OK) return result;
    match.mask_sum = mask_sum;
    match.masked_energy = energy;
    plane = (size_t)texture->width * (size_t)texture->height;
    if (mask_sum == 0.0) {
        if (out_map)
            for (i = 0; i < plane; i++) out_map[i] = 0.0;
        if (out_match) *out_match = match;
        return tt__fail(error, TT_ERROR_NOT_MEASURED, -1, -1, -1, -1,
                        "the mask is all zero: every offset fits equally (E = 0)");
    }
    /* One masked plane at a time through tmp, its term added to acc. */
    half = texture->spectrum_size;
    acc = work;
    tmp = work + half;
    for (c = -1; c < texture->channels; c++) {
        found |= tt__xcorr_masked_spectrum(texture, mask, values, c, tmp);
        tt__xcorr_add_term(acc, tmp, texture, c, 0, half / 2);
    }
    found |= tt__fft_c2r_inplace(texture->plan, acc);
    found |= tt__xcorr_scan(texture, energy, acc, allowed, out_map, &best, &best_e);
    if (found)
        return tt__fail(error, TT_ERROR_NON_FINITE, -1, -1, -1, -1,
                        "the correlation overflows (a NaN or infinity in E): scale the values");
    if (best < 0) {
        if (out_match) *out_match = match;
        return tt__fail(error, TT_ERROR_NOT_MEASURED, -1, -1, -1, -1,
                        "no offset is allowed (the allowed map is all zero)");
    }
    match.x = best % texture->width;
    match.y = best / texture->width;
    match.e = best_e;
    if (out_match) *out_match = match;
    return TT_OK;
}

/* Complex values of the combined spectrum that tt_xcorr_masked_best builds
   in one go, every term over them before the next block, so that the block
   stays in the first-level cache while the spectra stream past. 128 (2 KB)
   measured fastest: at 512 x 512, 3 channels, the products took half the
   time they take in blocks of 1024 and a third less than in blocks of 512. */
#define TT__XCORR_BLOCK 128

/* Does texture k have an allowed offset (allowed as tt_xcorr_masked_best's)? */
static int tt__xcorr_any_allowed(const unsigned char *const *allowed, int k, size_t plane)
{
    size_t i;
    if (!allowed || !allowed[k]) return 1;
    for (i = 0; i < plane; i++)
        if (allowed[k][i]) return 1;
    return 0;
}

TTDEF tt_result tt_xcorr_masked_best(const tt_xcorr_texture *const *textures, int ntextures, const double *mask,
                                     const double *values, const unsigned char *const *allowed, double *work,
                                     tt_xcorr_match *out_match, int *out_texture, tt_error *error)
{
    const tt_xcorr_texture *first;
    int k, c, any = 0, best_texture = -1;
    size_t half, plane, begin, count;
    double *acc, mask_sum, energy;
    tt_xcorr_match match;
    tt_result result;
    match.x = match.y = -1;
    match.e = match.mask_sum = match.masked_energy = 0.0;
    if (out_match) *out_match = match;
    if (out_texture) *out_texture = -1;
    tt__ok(error);
    if (!textures || !mask || !values || !work || !out_match || !out_texture)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "tt_xcorr_masked_best needs textures, a mask, values, work space, out_match and out_texture; "
                        "%s is NULL",
                        !textures ? "textures" : !mask ? "the mask" : !values ? "values" : !work ? "work"
                        : !out_match ? "out_match" : "out_texture");
    if (ntextures < 1)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "tt_xcorr_masked_best needs 1 or more textures (got %d)", ntextures);
    for (k = 0; k < ntextures; k++) {
        const tt_xcorr_texture *t = textures[k];
        if (!t) return tt__fail_at(error, TT_ERROR_INVALID_ARGUMENT, k, -1, -1, "texture %d is NULL", k);
        if (t->width != textures[0]->width || t->height != textures[0]->height ||
            t->channels != textures[0]->channels)
            return tt__fail_at(error, TT_ERROR_INVALID_ARGUMENT, k, -1, -1,
                               "texture %d is %d x %d with %d channels, texture 0 %d x %d with %d: all must be alike",
                               k, t->width, t->height, t->channels, textures[0]->width, textures[0]->height,
                               textures[0]->channels);
    }
    first = textures[0];
    result = tt__xcorr_masked_sums(first->width, first->height, first->channels, mask, values, &mask_sum, &energy,
                                   error);
    if (result != TT_OK) return result;
    match.mask_sum = mask_sum;
    match.masked_energy = energy;
    if (mask_sum == 0.0) {
        *out_match = match;
        return tt__fail(error, TT_ERROR_NOT_MEASURED, -1, -1, -1, -1,
                        "the mask is all zero: every offset fits equally (E = 0)");
    }
    plane = (size_t)first->width * (size_t)first->height;
    for (k = 0; k < ntextures && !any; k++) any = tt__xcorr_any_allowed(allowed, k, plane);
    if (!any) {
        *out_match = match;
        return tt__fail(error, TT_ERROR_NOT_MEASURED, -1, -1, -1, -1,
                        "no offset of any of the %d textures is allowed (every allowed map is all zero)", ntextures);
    }

    /* The spectra of J and of each J I_c, once: plane c at work + (c + 1) half. */
    half = first->spectrum_size;
    acc = work + half * ((size_t)first->channels + 1);
    for (c = -1; c < first->channels; c++)
        if (tt__xcorr_masked_spectrum(first, mask, values, c, work + half * (size_t)(c + 1)))
            return tt__fail(error, TT_ERROR_NON_FINITE, -1, -1, -1, -1,
                            "the spectrum of the masked values overflows: scale the values");
    /* Per texture: the combined spectrum, its inverse, E and its argmin;
       a strictly smaller E is needed to displace an earlier texture's. */
    for (k = 0; k < ntextures; k++) {
        const tt_xcorr_texture *texture = textures[k];
        const unsigned char *allowed_k = allowed ? allowed[k] : NULL;
        uint64_t found;
        double e;
        int best;
        if (!tt__xcorr_any_allowed(allowed, k, plane)) continue;
        for (begin = 0; begin < half / 2; begin += count) {
            count = half / 2 - begin < TT__XCORR_BLOCK ? half / 2 - begin : TT__XCORR_BLOCK;
            for (c = -1; c < texture->channels; c++)
                tt__xcorr_add_term(acc, work + half * (size_t)(c + 1), texture, c, begin, count);
        }
        found = tt__fft_c2r_inplace(texture->plan, acc);
        found |= tt__xcorr_scan(texture, energy, acc, allowed_k, NULL, &best, &e);
        if (found)
            return tt__fail_at(error, TT_ERROR_NON_FINITE, k, -1, -1,
                               "the correlation with texture %d overflows (a NaN or infinity in E): scale the values",
                               k);
        if (best >= 0 && (best_texture < 0 || e < match.e)) {
            best_texture = k;
            match.x = best % texture->width;
            match.y = best / texture->width;
            match.e = e;
        }
    }
    *out_match = match;
    *out_texture = best_texture;
    return TT_OK;
}

/* ------------------------------------------------------------------------ */
/* 5. Raster                                                                */
/* ------------------------------------------------------------------------ */

/* Vertices are snapped to 1/256 pixel and edge functions evaluated in 64-bit
   integers, as GPUs do: two triangles sharing an edge then compute exactly
   opposite edge values, so the top-left rule can give every pixel centre on
   the shared edge to exactly one of them. */
#define TT__SUBPIXEL 256
#define TT__RASTER_LIMIT 2097152.0   /* |coordinate| in pixels; keeps products within 63 bits */

TTDEF void tt_raster_triangle(const float xy[6], int width, int height, tt_raster_fn fn, void *user_data)
{
    long long px[3], py[3], area, bias[3], step_x[3], step_y[3], row[3];
    float min_x, max_x, min_y, max_y, inverse_area;
    int i, x0, x1, y0, y1, x, y, swapped = 0;
    TT_ASSERT(xy && fn);
    if (!xy || !fn || width <= 0 || height <= 0) return;
    for (i = 0; i < 6; i++)
        if (!(xy[i] > -TT__RASTER_LIMIT && xy[i] < TT__RASTER_LIMIT)) return;
    for (i = 0; i < 3; i++) {
        px[i] = (long long)floor((double)xy[2 * i] * TT__SUBPIXEL + 0.5);
        py[i] = (long long)floor((double)xy[2 * i + 1] * TT__SUBPIXEL + 0.5);
    }
    area = (px[1] - px[0]) * (py[2] - py[0]) - (px[2] - px[0]) * (py[1] - py[0]);
    if (area == 0) return;
    if (area < 0) {   /* make the winding positive; remember to swap weights back */
        long long t;
        t = px[1]; px[1] = px[2]; px[2] = t;
        t = py[1]; py[1] = py[2]; py[2] = t;
        area = -area;
        swapped = 1;
    }
    min_x = max_x = xy[0];
    min_y = max_y = xy[1];
    for (i = 1; i < 3; i++) {
        if (xy[2 * i] < min_x) min_x = xy[2 * i];
        if (xy[2 * i] > max_x) max_x = xy[2 * i];
        if (xy[2 * i + 1] < min_y) min_y = xy[2 * i + 1];
        if (xy[2 * i + 1] > max_y) max_y = xy[2 * i + 1];
    }
    x0 = tt__max_i((int)floorf(min_x - 0.5f), 0);
    y0 = tt__max_i((int)floorf(min_y - 0.5f), 0);
    x1 = tt__min_i((int)ceilf(max_x - 0.5f), width - 1);
    y1 = tt__min_i((int)ceilf(max_y - 0.5f), height - 1);
    if (x0 > x1 || y0 > y1) return;
    inverse_area = 1.0f / (float)area;

    /* Edge i is opposite vertex i, from vertex i+1 to i+2; its function is
       positive inside. With y pointing down, a top edge is horizontal with
       the inside below (dy == 0, dx > 0) and a left edge has dy < 0; on other
       edges a centre exactly on the line is outside (bias -1). */
    for (i = 0; i < 3; i++) {
        int a = (i + 1) % 3, b = (i + 2) % 3;
        long long dx = px[b] - px[a], dy = py[b] - py[a];
        long long cx = (long long)x0 * TT__SUBPIXEL + TT__SUBPIXEL / 2;
        long long cy = (long long)y0 * TT__SUBPIXEL + TT__SUBPIXEL / 2;
        int top_left = (dy == 0 && dx > 0) || dy < 0;
        bias[i] = top_left ? 0 : -1;
        row[i] = dx * (cy - py[a]) - dy * (cx - px[a]);
        step_x[i] = -dy * TT__SUBPIXEL;
        step_y[i] = dx * TT__SUBPIXEL;
    }
    for (y = y0; y <= y1; y++) {
        long long e0 = row[0], e1 = row[1], e2 = row[2];
        for (x = x0; x <= x1; x++) {
            if (e0 + bias[0] >= 0 && e1 + bias[1] >= 0 && e2 + bias[2] >= 0) {
                float weight[3];
                weight[0] = (float)e0 * inverse_area;
                weight[1] = (float)e1 * inverse_area;
                weight[2] = 1.0f - weight[0] - weight[1];
                if (swapped) { float t = weight[1]; weight[1] = weight[2]; weight[2] = t; }
                fn(x, y, weight, user_data);
            }
            e0 += step_x[0]; e1 += step_x[1]; e2 += step_x[2];
        }
        row[0] += step_y[0]; row[1] += step_y[1]; row[2] += step_y[2];
    }
}

/* ------------------------------------------------------------------------ */
/* 6. Tiled textures                                                        */
/* ------------------------------------------------------------------------ */
/* Based on: E. Akleman, J. Chen, V. Meenakshisundaram, V. Srinivasan, "Tiled
   Textures: A Simple and Practical Technique for Seamless Texturing".
     Sec. 2   tiles named by their four boundary types, placed by their name
     Sec. 3   AssignBoundaries + AssignTextureCoordinates   -> tt_assign_boundaries,
                                                               tt_assign_uvs
     Sec. 4   tile synthesis by compositing, split into a plan and its
              application (tt_synthesize_tiles does both):
              plan (tt_synth_plan_create), from a guide image:
                1. edge windows: one S x 2S window per condition, chosen
                   from the seed as the least conspicuous of 128 candidates
                   (or given)                             -> tt__choose_edge_windows
                2. per tile, its S x S background window XXXX from the seed
                3. per tile and side (D, C, B, A in that order), the band
                   depth per column: a minimum-error cut of the band against
                   what lies beneath (f4), kept inside the side's wedge
                   (f1..f3), the band then laid over the scratch tile so the
                   next cut sees it                       -> tt__band_depths
              application to any image of the guide's size:
                4. ABCD = AXXX over XBXX over XXCX over XXXD over XXXX, with
                   each band's alpha from its depths and the feather
                   (tt__band_alpha), composed in place in the target cell
                5. corner texels: the mean of the two edge samples there
                6. gutters (beyond the paper): each side's edge sample
                   continued across the edge              -> tt__compose_cell
                7. every tile into the atlas, then the per-tile mip chain
              tt_synth_compose_tile does 4-6 for one tile (the per-tile step,
              e.g. for a polycube's quads), tt_synth_apply 4-7 for the atlas.
     Sec. 6   n conditions: types 2k, 2k+1; (2n)^4 tiles
   Beyond the paper: gutters around tiles and a per-tile mip chain, so that
   bilinear filtering and mip-mapping do not bleed across tiles; a measured
   seam score (tt_measure_seams).

   A quad's corners 0..3 are counter-clockwise; half-edge i runs from corner i
   to corner i+1, so e0 is the tile's bottom, e1 its right, e2 its top, e3 its
   left side. */

/* Defaults filled in without validation, for the small pure functions. */
static tt_tile_layout tt__layout_with_defaults(const tt_tile_layout *layout)
{
    tt_tile_layout out = *layout;
    if (out.colors == 0) out.colors = 1;
    if (out.tile_size == 0) out.tile_size = TT_DEFAULT_TILE_SIZE;
    return out;
}

TTDEF tt_result tt_tile_layout_resolve(const tt_tile_layout *in, tt_tile_layout *out, tt_error *error)
{
    tt_tile_layout layout;
    long long tiles_per_side, atlas;
    tt__ok(error);
    if (!in || !out) return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1, "layout is NULL");
    layout = tt__layout_with_defaults(in);
    if (layout.colors < 1 || layout.colors > TT_MAX_COLORS)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "colors (boundary conditions) must be 1..%d, got %d", TT_MAX_COLORS, in->colors);
    if (layout.tile_size < 4 || layout.tile_size > TT_MAX_IMAGE_SIZE)
        return tt__fail(error, layout.tile_size > TT_MAX_IMAGE_SIZE ? TT_ERROR_TOO_LARGE : TT_ERROR_INVALID_ARGUMENT,
                        -1, -1, -1, -1, "tile size must be 4..%d texels, got %d", TT_MAX_IMAGE_SIZE, in->tile_size);
    if (layout.gutter < 0 || layout.gutter > layout.tile_size)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "gutter must be 0..%d texels (at most the tile size), got %d", layout.tile_size,
                        in->gutter);
    tiles_per_side = 4LL * layout.colors * layout.colors;
    atlas = tiles_per_side * (layout.tile_size + 2LL * layout.gutter);
    if (atlas > TT_MAX_IMAGE_SIZE)
        return tt__fail(error, TT_ERROR_TOO_LARGE, -1, -1, -1, -1,
                        "%d colors of %d-texel tiles with a %d-texel gutter need an atlas %lld texels wide; "
                        "the limit is %d (use fewer colors or smaller tiles)",
                        layout.colors, layout.tile_size, layout.gutter, atlas, TT_MAX_IMAGE_SIZE);
    *out = layout;
    return TT_OK;
}

/* The three layout figures, or 0 for a layout that does not resolve: all
   computed from a resolved copy, so no product can overflow. */
static int tt__layout_figure(const tt_tile_layout *layout, int which)
{
    tt_tile_layout resolved = {0, 0, 0}; /* written by tt_tile_layout_resolve; set so no compiler sees it unset */
    int side;
    TT_ASSERT(layout);
    if (!layout || tt_tile_layout_resolve(layout, &resolved, NULL) != TT_OK) {
        TT_ASSERT(!"the layout does not resolve (see tt_tile_layout_resolve)");
        return 0;
    }
    side = 4 * resolved.colors * resolved.colors;   /* <= TT_MAX_IMAGE_SIZE / 4 once resolved */
    if (which == 0) return side;
    if (which == 1) return side * (resolved.tile_size + 2 * resolved.gutter);
    return side <= 46340 ? side * side : 0;   /* 46340^2 < 2^31 */
}

TTDEF int tt_tile_layout_tiles_per_side(const tt_tile_layout *layout) { return tt__layout_figure(layout, 0); }
TTDEF int tt_tile_layout_atlas_size(const tt_tile_layout *layout) { return tt__layout_figure(layout, 1); }
TTDEF int tt_tile_layout_tile_count(const tt_tile_layout *layout) { return tt__layout_figure(layout, 2); }

TTDEF int tt_tile_index(const tt_tile_layout *layout, const uint8_t types[4])
{
    int base, column, row;
    TT_ASSERT(layout && types && layout->colors >= 0 && layout->colors <= TT_MAX_COLORS);
    base = 2 * (layout->colors ? layout->colors : 1);
    TT_ASSERT(types[0] < base && types[1] < base && types[2] < base && types[3] < base);
    column = base * types[0] + types[1];
    row = base * types[2] + types[3];
    return row * base * base + column;
}

TTDEF void tt_tile_corner_uv(const tt_tile_layout *layout, const uint8_t types[4], int corner, float uv[2])
{
    /* The paper prints floor(j/2) in the u equation (Figure 6); with
       j = floor(((i+1) mod 4)/2) already 0 or 1 that would pin u to the
       tile's left side. j itself is the corner's column within the tile. */
    tt_tile_layout L;
    int base, tiles, cell, column, row, j, k;
    double atlas;
    TT_ASSERT(layout && types && uv && corner >= 0 && corner < 4);
    L = tt__layout_with_defaults(layout);
    TT_ASSERT(L.colors >= 1 && L.colors <= TT_MAX_COLORS && L.tile_size >= 1 && L.gutter >= 0);
    base = 2 * L.colors;
    tiles = base * base;
    cell = L.tile_size + 2 * L.gutter;
    atlas = (double)tiles * cell;
    column = base * types[0] + types[1];
    row = base * types[2] + types[3];
    j = ((corner + 1) & 3) >> 1;
    k = (corner & 3) >> 1;
    uv[0] = (float)(((double)column * cell + L.gutter + (double)j * L.tile_size) / atlas);
    uv[1] = (float)(((double)row * cell + L.gutter + (double)k * L.tile_size) / atlas);
}

TTDEF tt_result tt_assign_boundaries(const tt_mesh *mesh, const tt_tile_layout *layout, uint64_t seed,
                                     const int *edge_colors, uint8_t *corner_type, tt_error *error)
{
    tt_rng rng;
    int n, c;
    tt__ok(error);
    if (!mesh || !layout || !corner_type)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "tt_assign_boundaries needs a mesh, a layout and corner_type (got NULL)");
    n = layout->colors ? layout->colors : 1;
    if (n < 1 || n > TT_MAX_COLORS)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "colors (boundary conditions) must be 1..%d, got %d", TT_MAX_COLORS, layout->colors);
    if (edge_colors)
        for (c = 0; c < mesh->ncorners; c++) {
            int t = mesh->twin[c];
            if (edge_colors[c] < -1 || edge_colors[c] >= n)
                return tt__fail(error, TT_ERROR_INDEX_OUT_OF_RANGE, mesh->corner_face[c], c, -1, -1,
                                "corner %d prescribes colour %d, but %d colors allow 0..%d (or -1: random)", c,
                                edge_colors[c], n, n - 1);
            if (t >= 0 && edge_colors[t] != edge_colors[c])
                return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, mesh->corner_face[c], c, -1, -1,
                                "corners %d and %d are the two sides of one edge but prescribe colours %d and %d",
                                c, t, edge_colors[c], edge_colors[t]);
        }
    tt_rng_seed(&rng, seed, 0x6564676573ull /* "edges" */);
    /* Edges are visited in order of their first half-edge, so the result
       depends only on the mesh and the seed. A prescribed colour draws no
       number for k, so the other edges' draws do not depend on it. */
    for (c = 0; c < mesh->ncorners; c++) {
        int t = mesh->twin[c];
        uint32_t k, side;
        if (t >= 0 && t < c) continue;
        if (edge_colors && edge_colors[c] >= 0) k = (uint32_t)edge_colors[c];
        else k = n > 1 ? tt_rng_below(&rng, (uint32_t)n) : 0u;
        side = tt_rng_next(&rng) >> 31;
        corner_type[c] = (uint8_t)(2u * k + side);
        if (t >= 0) corner_type[t] = (uint8_t)(2u * k + 1u - side);
    }
    return TT_OK;
}

TTDEF tt_result tt_assign_uvs(const tt_mesh *mesh, const tt_tile_layout *layout, const uint8_t *corner_type,
                              float *corner_uv, tt_error *error)
{
    tt_tile_layout resolved = {0, 0, 0}; /* written by tt_tile_layout_resolve; set so no compiler sees it unset */
    tt_result result;
    double cell, atlas;
    int f, base, c;
    tt__ok(error);
    if (!mesh || !layout || !corner_type || !corner_uv)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1, "NULL argument to tt_assign_uvs");
    if ((result = tt_tile_layout_resolve(layout, &resolved, error)) != TT_OK) return result;
    base = 2 * resolved.colors;
    cell = resolved.tile_size + 2.0 * resolved.gutter;
    atlas = (double)base * base * cell;
    for (f = 0; f < mesh->nfaces; f++)
        if (mesh->face_start[f + 1] - mesh->face_start[f] != 4)
            return tt__fail(error, TT_ERROR_NOT_QUAD_MESH, f, mesh->face_start[f], -1, -1,
                            "face %d has %d corners; tiled textures need quads (quadrangulate the mesh first)",
                            f, mesh->face_start[f + 1] - mesh->face_start[f]);
    for (c = 0; c < mesh->ncorners; c++)
        if (corner_type[c] >= base)
            return tt__fail(error, TT_ERROR_INDEX_OUT_OF_RANGE, mesh->corner_face[c], c, -1, -1,
                            "corner %d has boundary type %d, but %d colors allow 0..%d", c, corner_type[c],
                            resolved.colors, base - 1);
    for (f = 0; f < mesh->nfaces; f++) {
        /* tt_tile_corner_uv's formula, term for term, so the two agree to
           the bit. */
        const uint8_t *e = corner_type + 4 * (size_t)f;
        float *uv = corner_uv + 8 * (size_t)f;
        int column = base * e[0] + e[1], row = base * e[2] + e[3];
        float u0 = (float)(((double)column * cell + resolved.gutter) / atlas);
        float u1 = (float)(((double)column * cell + resolved.gutter + (double)resolved.tile_size) / atlas);
        float v0 = (float)(((double)row * cell + resolved.gutter) / atlas);
        float v1 = (float)(((double)row * cell + resolved.gutter + (double)resolved.tile_size) / atlas);
        uv[0] = u0; uv[1] = v0;   /* corner 0: bottom-left  */
        uv[2] = u1; uv[3] = v0;   /* corner 1: bottom-right */
        uv[4] = u1; uv[5] = v1;   /* corner 2: top-right    */
        uv[6] = u0; uv[7] = v1;   /* corner 3: top-left     */
    }
    return TT_OK;
}

/* --- tile-set synthesis (Akleman Sec. 4): plan and application ----------- */

/* What composing one tile needs. Tiles are composed in a "side frame" per
   side s: x runs along the side in the direction of its half-edge, d is the
   distance from the side into the tile (d = 0 is the side's edge row, d < 0
   lies in the gutter, across the edge). The side frame is the tile's bottom
   side turned by s quarter turns, so it maps to tile texels through
   tt_rotate_coords(s, S, S, x, S-1-d). The S x S tile being composed lies at
   `tile`, `stride` floats per row: a scratch tile while planning, the tile's
   square inside its cell of the caller's image while applying. */
typedef struct tt__synth {
    const tt_image *source;
    const tt_rect *windows;   /* per condition: S x 2S, top-left (x, y) */
    const tt_rect *vertical;  /* upright tiles: per condition, 2S x S, for sides 1 and 3; else NULL */
    int size, gutter, feather;
    float *tile;              /* RGBA, premultiplied (opaque) */
    size_t stride;            /* floats per row of `tile` */
} tt__synth;

static float *tt__synth_texel(const tt__synth *s, int tx, int ty)
{
    /* tx or ty may be negative (the gutter before the tile, inside its cell) */
    return s->tile + (ptrdiff_t)ty * (ptrdiff_t)s->stride + (ptrdiff_t)tx * 4;
}

/* The edge sample for side `side` of type t at side-frame (x, d). Condition
   k's window holds two squares, upper U and lower L, meeting at the line
   between rows S-1 and S. Type 2k lines the side with U as it is, so d counts
   rows up from that line; type 2k+1 lines it with L turned 180 degrees. For
   d < 0 both continue across the line, which is exactly what the neighbour
   across the edge (with the other type) shows: this is why tiles meet
   seamlessly. Upright tiles read sides 1 and 3 from the vertical window, a
   left and a right square meeting at the line between columns S-1 and S,
   turned back by the side's quarter turn: type 2k lines side 1 with the left
   square as it is (the band's tile texels are the window's, shifted), type
   2k+1 with the right square turned 180 degrees, and across the line each
   continues into the other as before. */
static const float *tt__edge_sample(const tt__synth *s, int side, int type, int x, int d)
{
    const int S = s->size;
    int sx, sy;
    if (s->vertical && (side & 1)) {
        const tt_rect *w = &s->vertical[type >> 1];
        if ((type & 1) == 0) { sx = w->x + S - 1 - d; sy = w->y + S - 1 - x; }
        else { sx = w->x + S + d; sy = w->y + x; }
    } else {
        const tt_rect *w = &s->windows[type >> 1];
        if ((type & 1) == 0) { sx = w->x + x; sy = w->y + S - 1 - d; }
        else { sx = w->x + S - 1 - x; sy = w->y + S + d; }
    }
    return s->source->pixels + ((size_t)sy * s->source->width + sx) * 4;
}

static void tt__side_to_tile(const tt__synth *s, int side, int x, int d, int *tx, int *ty)
{
    tt_rotate_coords(side, s->size, s->size, x, s->size - 1 - d, tx, ty);
}

/* The band depth of entry i ((4 * tile + side) * S + x) of a plan. */
static int tt__plan_depth_at(const tt_synth_plan *plan, size_t i)
{
    return plan->depth8 ? plan->depth8[i] : plan->depth16[i];
}

/* The band's alpha at side-frame (x, d) for a column of depth `depth`: one
   formula for planning, applying and tt_synth_plan_band_alpha. The edge row
   is the edge sample, exactly; below it the band fades out across the cut
   (`feather` texels) and, near the corners where two bands meet along the
   diagonal, across the side's wedge (a short 2-texel blend that keeps both
   bands' rows next to their edges intact). Corner columns belong to the
   neighbouring sides. */
static float tt__band_alpha(int size, int feather, int depth, int x, int d)
{
    float a_cut, a_wedge;
    int wedge;
    if (x <= 0 || x >= size - 1 || d < 0 || d > tt__min_i(depth + feather, size - 1)) return 0.0f;
    if (d == 0) return 1.0f;
    wedge = tt__min_i(x, size - 1 - x);   /* rows strictly inside this side's wedge */
    a_cut = tt__clamp_f(((float)depth - (float)d - 0.5f) / (float)feather + 0.5f, 0.0f, 1.0f);
    a_wedge = tt__clamp_f(((float)wedge - (float)d - 0.5f) / 2.0f + 0.5f, 0.0f, 1.0f);
    return a_cut * a_wedge;
}

/* XXXX: the tile's background window, opaque. */
static void tt__copy_background(const tt__synth *s, const tt_rect *bg)
{
    int x, y;
    for (y = 0; y < s->size; y++)
        for (x = 0; x < s->size; x++) {
            const float *p = s->source->pixels + ((size_t)(bg->y + y) * s->source->width + bg->x + x) * 4;
            float *q = tt__synth_texel(s, x, y);
            q[0] = p[0]; q[1] = p[1]; q[2] = p[2]; q[3] = 1.0f;
        }
}

/* Lay the band of side `side` (type `type`) over the tile composed so far:
   AXXX over (what is there), with the depths of the plan's entries
   depth_base .. depth_base + S-1. */
static void tt__lay_band(const tt__synth *s, const tt_synth_plan *plan, size_t depth_base, int side, int type)
{
    const int S = s->size;
    int x, d, k;
    for (x = 1; x < S - 1; x++) {
        int depth = tt__plan_depth_at(plan, depth_base + (size_t)x);
        int last = tt__min_i(depth + s->feather, S - 1);
        for (d = 0; d <= last; d++) {
            float alpha = tt__band_alpha(S, s->feather, depth, x, d), premultiplied[4];
            const float *band;
            int tx, ty;
            if (alpha <= 0.0f) continue;
            band = tt__edge_sample(s, side, type, x, d);
            for (k = 0; k < 3; k++) premultiplied[k] = band[k] * alpha;
            premultiplied[3] = alpha;
            tt__side_to_tile(s, side, x, d, &tx, &ty);
            tt_rgba_over(tt__synth_texel(s, tx, ty), premultiplied);
        }
    }
}

/* Planning: the depth of side `side`'s band in every column. It follows a
   minimum-error cut against what lies beneath (the paper's f4: "once colour
   values of two image layers become similar, the foreground becomes
   transparent"), kept inside the side's wedge (the triangle between the
   tile's diagonals, the paper's f1..f3 keeping it off the other sides) and
   between min_depth and max_depth. cost has S * (max_depth + 1) floats; lo,
   hi and cut S ints each. */
static tt_result tt__band_depths(const tt__synth *s, int side, int type, int min_depth, int max_depth, float *cost,
                                 int *lo, int *hi, int *cut, const tt_allocator *allocator, tt_error *error)
{
    const int S = s->size, rows = max_depth + 1;
    int x, d, k;
    for (d = 0; d < rows; d++)
        for (x = 0; x < S; x++) {
            int tx, ty;
            const float *band = tt__edge_sample(s, side, type, x, d);
            const float *below;
            float err = 0.0f;
            tt__side_to_tile(s, side, x, d, &tx, &ty);
            below = tt__synth_texel(s, tx, ty);
            for (k = 0; k < 3; k++) err += (band[k] - below[k]) * (band[k] - below[k]);
            cost[(size_t)d * S + x] = err;
        }
    for (x = 0; x < S; x++) {
        int wedge = tt__min_i(x, S - 1 - x);
        hi[x] = tt__min_i(wedge, max_depth);
        lo[x] = tt__min_i(min_depth, hi[x]);
    }
    return tt_min_error_cut(cost, S, rows, lo, hi, allocator, cut, error);
}

/* Applying: compose tile `tile` (types e0..e3) from `source` with the plan's
   windows and masks into the C x C cell whose top-left texel is at `cell`
   (`stride` floats per row): background, the four bands, the corner texels,
   then the gutters. Checks nothing: the callers have. */
static void tt__compose_cell(const tt_synth_plan *plan, const tt_image *source, const uint8_t types[4], int tile,
                             float *cell, size_t stride)
{
    const int S = plan->layout.tile_size, g = plan->layout.gutter, C = S + 2 * g;
    tt__synth s;
    int side, k, x, y, d;
    s.source = source;
    s.windows = plan->edge_windows;
    s.vertical = plan->vertical_windows;
    s.size = S;
    s.gutter = g;
    s.feather = plan->feather;
    s.stride = stride;
    s.tile = cell + (size_t)g * stride + (size_t)g * 4;
    tt__copy_background(&s, &plan->background_windows[tile]);
    /* ABCD = AXXX over XBXX over XXCX over XXXD over XXXX: lay D first. */
    for (side = 3; side >= 0; side--)
        tt__lay_band(&s, plan, (4 * (size_t)tile + (size_t)side) * (size_t)S, side, types[side]);
    /* A corner texel lies on two sides' edge rows, and whatever meets it
       around a mesh vertex differs from tile to tile: the mean of the two
       edge samples there matches each neighbour across an edge halfway. */
    for (side = 0; side < 4; side++) {
        const float *a = tt__edge_sample(&s, side, types[side], 0, 0);
        const float *b = tt__edge_sample(&s, (side + 3) % 4, types[(side + 3) % 4], S - 1, 0);
        int tx, ty;
        float *corner;
        tt__side_to_tile(&s, side, 0, 0, &tx, &ty);
        corner = tt__synth_texel(&s, tx, ty);
        for (k = 0; k < 3; k++) corner[k] = 0.5f * (a[k] + b[k]);
    }
    if (g == 0) return;
    /* Gutters. The strip outside each side holds the edge sample continued
       across the edge (d < 0), i.e. the first rows of whichever tile lies
       across that edge on the surface; the g x g corner squares repeat the
       nearest tile texel. */
    for (y = 0; y < C; y++) {
        if (y >= g && y < g + S) continue;
        for (x = 0; x < C; x++) {
            if (x >= g && x < g + S) continue;
            memcpy(cell + (size_t)y * stride + (size_t)x * 4,
                   tt__synth_texel(&s, tt__clamp_i(x - g, 0, S - 1), tt__clamp_i(y - g, 0, S - 1)),
                   4 * sizeof(float));
        }
    }
    for (side = 0; side < 4; side++)
        for (d = -g; d < 0; d++)
            for (x = 0; x < S; x++) {
                int tx, ty;
                float *out;
                tt__side_to_tile(&s, side, x, d, &tx, &ty);
                out = tt__synth_texel(&s, tx, ty);
                memcpy(out, tt__edge_sample(&s, side, types[side], x, d), 3 * sizeof(float));
                out[3] = 1.0f;
            }
}

TTDEF void tt_tileset_free(tt_tileset *tileset)
{
    tt_allocator allocator;
    int i;
    if (!tileset) return;
    allocator = tileset->allocator;
    for (i = 0; i < tileset->nlevels; i++) tt__image_release(&tileset->levels[i]);
    tt__free(&allocator, tileset->edge_windows);
    tt__free(&allocator, tileset->vertical_windows);
    tt__free(&allocator, tileset->background_windows);
    tt__free(&allocator, tileset);
}

/* Mean absolute RGB difference of two texels, the seam measure's unit. */
static double tt__texel_difference(const float *a, const float *b)
{
    return (fabs((double)a[0] - b[0]) + fabs((double)a[1] - b[1]) + fabs((double)a[2] - b[2])) / 3.0;
}

/* What a typical place of the image looks like, for choosing edge windows:
   its mean brightness and the mean difference between vertically adjacent
   texels (the difference a seam should show, since every edge shows two rows
   of a window that were neighbours in the image). */
typedef struct tt__image_statistics {
    double mean;
    double variance;          /* of a texel's mean of R, G, B */
    double row_difference;
} tt__image_statistics;

static tt__image_statistics tt__measure_image(const tt_image *image)
{
    tt__image_statistics st;
    size_t x, y, w = (size_t)image->width, h = (size_t)image->height;
    double sum = 0.0, sum2 = 0.0, difference = 0.0;
    for (y = 0; y < h; y++)
        for (x = 0; x < w; x++) {
            const float *p = image->pixels + (y * w + x) * 4;
            double grey = ((double)p[0] + p[1] + p[2]) / 3.0;
            sum += grey;
            sum2 += grey * grey;
            if (y + 1 < h) difference += tt__texel_difference(p, p + 4 * w);
        }
    st.mean = sum / (double)(w * h);
    st.variance = sum2 / (double)(w * h) - st.mean * st.mean;
    st.row_difference = h > 1 ? difference / (double)(w * (h - 1)) : 0.0;
    return st;
}

/* How conspicuous condition window (x, y) would be. Every edge of the mesh
   shows the rows next to the window's middle line, so
   - structure running along that line (a mortar joint, a plank border) would
     draw the mesh's edges as a grid: the variance of the row means over the
     S/4 rows on each side of the line;
   - an unusually bright or dark strip would too: their mean against the
     image's;
   - anything distinctive in it (a joint crossing the line, a knot) repeats
     at the same place along every edge: their contrast (texel variance)
     against the image's, so the blandest typical strip wins;
   - the two rows that meet across every edge, and the rows next to them
     inside each square, should differ like any two neighbouring rows of the
     image, or every edge looks unlike the rest: their mean differences
     against the image's.
   Each term is relative to the image's own (texel variance, neighbour
   difference), so one scale fits any image. Most of all, the pair that meets
   across every edge must not differ more than the pairs beside it inside the
   squares: then no edge can stand out from the texture next to it. */
static double tt__edge_window_score(const tt_image *source, int x, int y, int size, const tt__image_statistics *st)
{
    int half = tt__max_i(2, size / 4), r, i;
    double sum = 0.0, sum2 = 0.0, texel_sum2 = 0.0, across = 0.0, upper = 0.0, lower = 0.0;
    const float *line = source->pixels + ((size_t)(y + size) * source->width + x) * 4;   /* first row of L */
    const size_t stride = (size_t)source->width * 4;
    for (r = y + size - half; r < y + size + half; r++) {
        const float *p = source->pixels + ((size_t)r * source->width + x) * 4;
        double row = 0.0;
        for (i = 0; i < size; i++, p += 4) {
            double grey = ((double)p[0] + p[1] + p[2]) / 3.0;
            row += grey;
            texel_sum2 += grey * grey;
        }
        row /= size;
        sum += row;
        sum2 += row * row;
    }
    sum /= 2 * half;
    for (i = 0; i < size; i++) {
        const float *p = line + 4 * (size_t)i;
        across += tt__texel_difference(p - stride, p);
        upper += tt__texel_difference(p - 2 * stride, p - stride);
        lower += tt__texel_difference(p, p + stride);
    }
    {
        double variance = st->variance > 1e-12 ? st->variance : 1e-12;
        double difference = st->row_difference > 1e-6 ? st->row_difference : 1e-6;
        double excess;
        across = across / size / difference;
        upper = upper / size / difference;
        lower = lower / size / difference;
        excess = across - 0.5 * (upper + lower);
        excess = excess > 0.0 ? excess : 0.0;
        double contrast = texel_sum2 / (2.0 * half * size) - sum * sum;
        return ((sum2 / (2 * half) - sum * sum) + (sum - st->mean) * (sum - st->mean) + contrast) / variance +
               16.0 * excess * excess + (across - 1.0) * (across - 1.0) + (upper - 1.0) * (upper - 1.0) +
               (lower - 1.0) * (lower - 1.0);
    }
}

/* Condition windows from the seed: the least conspicuous of 128 random
   candidates, among those at least S away from the windows already chosen
   (so several conditions use different parts of the image) when there are
   any. */
static void tt__choose_edge_windows(tt_rng *rng, const tt_image *source, int size, int n, tt_rect *windows)
{
    const int candidates = 128;
    tt__image_statistics st = tt__measure_image(source);
    int k, trial;
    for (k = 0; k < n; k++) {
        double best_score = 0.0;
        int best_far = -1;
        for (trial = 0; trial < candidates; trial++) {
            tt_rect r;
            double score;
            int j, far = 1;
            r.x = (int)tt_rng_below(rng, (uint32_t)(source->width - size + 1));
            r.y = (int)tt_rng_below(rng, (uint32_t)(source->height - 2 * size + 1));
            r.w = size;
            r.h = 2 * size;
            for (j = 0; j < k; j++)
                if (tt__abs_i(r.x - windows[j].x) < size && tt__abs_i(r.y - windows[j].y) < size) far = 0;
            score = tt__edge_window_score(source, r.x, r.y, size, &st);
            if (far > best_far || (far == best_far && score < best_score)) {
                best_far = far;
                best_score = score;
                windows[k] = r;
            }
        }
    }
}

/* Progress of step `done` of `total` within [from, to] of the caller's
   0..1; non-zero when the callback asks to stop. */
static int tt__synth_report(tt_progress_fn progress, void *user_data, float from, float to, int done, int total)
{
    return progress && progress(from + (to - from) * ((float)done / (float)total), user_data);
}

/* Share of tt_synthesize_tiles's progress that planning takes. */
#define TT__PLAN_SHARE 0.5f

static int tt__rect_fits(const tt_rect *r, int w, int h, int width, int height)
{
    return r->x >= 0 && r->y >= 0 && r->x <= width - w && r->y <= height - h;
}

/* A plan as tt_synth_plan_create makes it (it is a public struct: a caller
   may have changed it): every figure the composing relies on, so that a bad
   plan is an error and never a read outside an image. Windows are checked by
   the callers (all of them, or those of one tile). */
static tt_result tt__check_plan(const tt_synth_plan *plan, tt_error *error)
{
    tt_tile_layout resolved = {0, 0, 0}; /* written by tt_tile_layout_resolve; set so no compiler sees it unset */
    int S = plan->layout.tile_size;
    if (tt_tile_layout_resolve(&plan->layout, &resolved, NULL) != TT_OK || resolved.colors != plan->layout.colors ||
        resolved.tile_size != S || resolved.gutter != plan->layout.gutter || plan->feather < 1 ||
        plan->feather > S / 4 + 1 || plan->max_depth != tt__max_i(1, S / 4) || plan->source_width < S ||
        plan->source_height < 2 * S || plan->source_width > TT_MAX_IMAGE_SIZE ||
        plan->source_height > TT_MAX_IMAGE_SIZE || !plan->edge_windows || !plan->background_windows ||
        (plan->max_depth <= 255 ? !plan->depth8 : !plan->depth16))
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "the plan is not one tt_synth_plan_create made (its layout, feather, depths or source size "
                        "have been changed)");
    return TT_OK;
}

static tt_result tt__check_plan_source(const tt_synth_plan *plan, const tt_image *source, tt_error *error)
{
    if (!source->pixels || source->width != plan->source_width || source->height != plan->source_height)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "the source image is %dx%d, but the plan was made for a %dx%d image", source->width,
                        source->height, plan->source_width, plan->source_height);
    return TT_OK;
}

static tt_result tt__bad_plan_window(tt_error *error, const char *which, int index)
{
    return tt__fail_at(error, TT_ERROR_INVALID_ARGUMENT, index, -1, -1,
                       "the plan's %s window %d does not lie inside its source size (the plan has been changed)",
                       which, index);
}

/* Whether every edge (and vertical) window of a plan lies inside a source of its size. */
static tt_result tt__check_plan_windows(const tt_synth_plan *plan, const tt_image *source, tt_error *error)
{
    const int S = plan->layout.tile_size;
    int k;
    for (k = 0; k < plan->layout.colors; k++) {
        if (!tt__rect_fits(&plan->edge_windows[k], S, 2 * S, source->width, source->height))
            return tt__bad_plan_window(error, "edge", k);
        if (plan->vertical_windows &&
            !tt__rect_fits(&plan->vertical_windows[k], 2 * S, S, source->width, source->height))
            return tt__bad_plan_window(error, "vertical", k);
    }
    return TT_OK;
}

static tt_result tt__synth_plan_create(const tt_image *guide, const tt_synth_options *options,
                                       const tt_allocator *allocator, tt_synth_plan **out_plan, tt_error *error,
                                       const char *what, float progress_from, float progress_to)
{
    tt_synth_options defaults;
    const tt_synth_options *opt = options;
    tt_synth_plan *plan = NULL;
    tt__synth s;
    tt_tile_layout layout;
    tt_rect region;
    tt_rng rng;
    tt_result result;
    float *scratch = NULL, *cost = NULL;
    int *lo = NULL, *hi = NULL, *cut = NULL;
    int S, g, T, n, ntiles, feather, min_depth, max_depth, depth_size, t, k, side;
    unsigned long long head, edge_bytes, background_bytes, depth_count, bytes;

    tt__ok(error);
    if (!out_plan) return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1, "the output pointer is NULL");
    *out_plan = NULL;
    if (!opt) {
        memset(&defaults, 0, sizeof defaults);
        opt = &defaults;
    }
    if (tt__check_allocator(allocator, error) != TT_OK) return TT_ERROR_INVALID_ARGUMENT;
    if (!guide || !guide->pixels || guide->width <= 0 || guide->height <= 0)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1, "the %s is empty", what);
    if ((result = tt__check_finite_texels(guide, what, error)) != TT_OK) return result;
    if ((result = tt_tile_layout_resolve(&opt->layout, &layout, error)) != TT_OK) return result;
    S = layout.tile_size;
    g = layout.gutter;
    n = layout.colors;
    T = tt_tile_layout_tiles_per_side(&layout);
    ntiles = T * T;   /* T <= TT_MAX_IMAGE_SIZE / 4 once resolved: fits an int */
    if (guide->width < (opt->upright ? 2 * S : S) || guide->height < 2 * S)
        return tt__fail(error, TT_ERROR_IMAGE_TOO_SMALL, -1, -1, -1, -1,
                        "the %s is %dx%d, but %d-texel %stiles need an edge window of %dx%d "
                        "(use a tile size of at most %d)",
                        what, guide->width, guide->height, S, opt->upright ? "upright " : "",
                        opt->upright ? 2 * S : S, 2 * S,
                        tt__min_i(opt->upright ? guide->width / 2 : guide->width, guide->height / 2));
    if (opt->feather < 0)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1, "feather %d is negative", opt->feather);
    feather = opt->feather > 0 ? opt->feather : tt__max_i(2, S / 16);
    if (feather > S / 4 + 1)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "feather %d is too wide for %d-texel tiles (at most %d)", feather, S, S / 4 + 1);
    /* Every edge of a type shows the same band, so a deep band repeats
       visibly across the surface: bands go no deeper than the cut needs. At
       least past the gutter's depth plus half the feather (so the rows a
       neighbour's gutter copies are the sample alone), at most S/4 (so most
       of each tile is its own background). */
    max_depth = tt__max_i(1, S / 4);
    min_depth = tt__min_i(tt__max_i(2, g + feather / 2 + 1), max_depth);

    region = opt->background;
    if (region.x == 0 && region.y == 0 && region.w == 0 && region.h == 0) {
        region.w = guide->width;
        region.h = guide->height;
    }
    if (region.x < 0 || region.y < 0 || region.w < S || region.h < S ||
        region.x > guide->width - region.w || region.y > guide->height - region.h)
        return tt__fail(error, region.w < S || region.h < S ? TT_ERROR_IMAGE_TOO_SMALL : TT_ERROR_INVALID_ARGUMENT,
                        -1, -1, -1, -1,
                        "the background region %d,%d %dx%d must lie inside the %dx%d image and hold a %dx%d tile",
                        region.x, region.y, region.w, region.h, guide->width, guide->height, S, S);
    if (opt->edge_windows)
        for (k = 0; k < n; k++)
            if (!tt__rect_fits(&opt->edge_windows[k], S, 2 * S, guide->width, guide->height))
                return tt__fail_at(error, TT_ERROR_INVALID_ARGUMENT, k, -1, -1,
                                   "edge window %d at %d,%d does not fit: it needs %dx%d texels inside the %dx%d "
                                   "image", k, opt->edge_windows[k].x, opt->edge_windows[k].y, S, 2 * S,
                                   guide->width, guide->height);

    /* One block: the struct, the edge windows, the background windows, the
       depths (each part a multiple of 16 bytes long but the last). */
    depth_size = max_depth <= 255 ? 1 : 2;
    head = (sizeof(tt_synth_plan) + 15u) / 16u * 16u;
    edge_bytes = (unsigned long long)(opt->upright ? 2 * n : n) * sizeof(tt_rect);
    background_bytes = (unsigned long long)ntiles * sizeof(tt_rect);
    depth_count = 4ull * (unsigned long long)S * (unsigned long long)ntiles;
    bytes = head + edge_bytes + background_bytes + depth_count * (unsigned long long)depth_size;
    if (bytes > (unsigned long long)(size_t)-1)
        return tt__fail(error, TT_ERROR_TOO_LARGE, -1, -1, -1, -1,
                        "a plan of %d tiles of %d texels needs more memory than this machine can address", ntiles,
                        S);
    plan = (tt_synth_plan *)tt__alloc(allocator, (size_t)bytes);
    scratch = TT__ALLOC(allocator, float, (size_t)S * S * 4);
    cost = TT__ALLOC(allocator, float, (size_t)S * (max_depth + 1));
    lo = TT__ALLOC(allocator, int, S);
    hi = TT__ALLOC(allocator, int, S);
    cut = TT__ALLOC(allocator, int, S);
    if (!plan || !scratch || !cost || !lo || !hi || !cut) {
        result = tt__fail(error, TT_ERROR_OUT_OF_MEMORY, -1, -1, -1, -1, "out of memory");
        goto done;
    }
    memset(plan, 0, sizeof *plan);
    plan->layout = layout;
    plan->source_width = guide->width;
    plan->source_height = guide->height;
    plan->feather = feather;
    plan->max_depth = max_depth;
    plan->edge_windows = (tt_rect *)(void *)((unsigned char *)plan + head);
    if (opt->upright) plan->vertical_windows = plan->edge_windows + n;
    plan->background_windows = (tt_rect *)(void *)((unsigned char *)plan + head + edge_bytes);
    if (depth_size == 1) plan->depth8 = (uint8_t *)plan + head + edge_bytes + background_bytes;
    else plan->depth16 = (uint16_t *)(void *)((unsigned char *)plan + head + edge_bytes + background_bytes);
    plan->progress = opt->progress;
    plan->progress_user_data = opt->progress_user_data;
    plan->allocator = tt__allocator_copy(allocator);

    tt_rng_seed(&rng, opt->seed, 0x74696c6573ull /* "tiles" */);
    if (opt->edge_windows) {
        for (k = 0; k < n; k++) {
            plan->edge_windows[k] = opt->edge_windows[k];
            plan->edge_windows[k].w = S;
            plan->edge_windows[k].h = 2 * S;
        }
    } else {
        tt__choose_edge_windows(&rng, guide, S, n, plan->edge_windows);
    }
    if (opt->upright) {
        /* The vertical windows: edge windows chosen on the guide turned a
           quarter, whose lines then run down the guide. Texel (x, y) of the
           guide is (y, W-1-x) of the turned image, so the turned window at
           (x, y) covers guide columns W-y-2S .. W-y-1 and rows x .. x+S-1. */
        tt_image *turned = NULL;
        if ((result = tt_image_rotate90(guide, 1, allocator, &turned, error)) != TT_OK) goto done;
        tt__choose_edge_windows(&rng, turned, S, n, plan->vertical_windows);
        tt_image_free(turned);
        for (k = 0; k < n; k++) {
            tt_rect r = plan->vertical_windows[k];
            plan->vertical_windows[k].x = guide->width - r.y - 2 * S;
            plan->vertical_windows[k].y = r.x;
            plan->vertical_windows[k].w = 2 * S;
            plan->vertical_windows[k].h = S;
        }
    }

    s.source = guide;
    s.windows = plan->edge_windows;
    s.vertical = plan->vertical_windows;
    s.size = S;
    s.gutter = g;
    s.feather = feather;
    s.tile = scratch;
    s.stride = (size_t)S * 4;
    for (t = 0; t < ntiles; t++) {
        int column = t % T, row = t / T, base = 2 * n, x;
        uint8_t types[4];
        tt_rect *bg = &plan->background_windows[t];
        types[0] = (uint8_t)(column / base);
        types[1] = (uint8_t)(column % base);
        types[2] = (uint8_t)(row / base);
        types[3] = (uint8_t)(row % base);
        /* XXXX: a fresh background window per tile gives the aperiodicity. */
        bg->x = region.x + (int)tt_rng_below(&rng, (uint32_t)(region.w - S + 1));
        bg->y = region.y + (int)tt_rng_below(&rng, (uint32_t)(region.h - S + 1));
        bg->w = bg->h = S;
        tt__copy_background(&s, bg);
        /* Each band's cut is against what the bands laid before it left
           (D first); the last band (A) covers nothing that is cut later. */
        for (side = 3; side >= 0; side--) {
            size_t depth_base = (4 * (size_t)t + (size_t)side) * (size_t)S;
            result = tt__band_depths(&s, side, types[side], min_depth, max_depth, cost, lo, hi, cut, allocator, error);
            if (result != TT_OK) goto done;
            for (x = 0; x < S; x++) {
                if (plan->depth8) plan->depth8[depth_base + (size_t)x] = (uint8_t)cut[x];
                else plan->depth16[depth_base + (size_t)x] = (uint16_t)cut[x];
            }
            if (side > 0) tt__lay_band(&s, plan, depth_base, side, types[side]);
        }
        if (tt__synth_report(opt->progress, opt->progress_user_data, progress_from, progress_to, t + 1, ntiles)) {
            result = tt__fail(error, TT_CANCELLED, -1, -1, -1, -1, "tile synthesis was cancelled");
            goto done;
        }
    }
    result = TT_OK;

done:
    tt__free(allocator, scratch);
    tt__free(allocator, cost);
    tt__free(allocator, lo);
    tt__free(allocator, hi);
    tt__free(allocator, cut);
    if (result != TT_OK) {
        tt__free(allocator, plan);
        return result;
    }
    *out_plan = plan;
    return TT_OK;
}

TTDEF tt_result tt_synth_plan_create(const tt_image *guide, const tt_synth_options *options,
                                     const tt_allocator *allocator, tt_synth_plan **out_plan, tt_error *error)
{
    return tt__synth_plan_create(guide, options, allocator, out_plan, error, "guide image", 0.0f, 1.0f);
}

TTDEF void tt_synth_plan_free(tt_synth_plan *plan)
{
    tt_allocator allocator;
    if (!plan) return;
    allocator = plan->allocator;
    tt__free(&allocator, plan);
}

TTDEF int tt_synth_plan_depth(const tt_synth_plan *plan, int tile, int side, int x)
{
    int S;
    TT_ASSERT(plan && (plan->depth8 || plan->depth16));
    if (!plan || (!plan->depth8 && !plan->depth16)) return 0;
    S = plan->layout.tile_size;
    TT_ASSERT(tile >= 0 && tile < tt_tile_layout_tile_count(&plan->layout) && side >= 0 && side < 4 && x >= 0 &&
              x < S);
    if (tile < 0 || tile >= tt_tile_layout_tile_count(&plan->layout) || side < 0 || side > 3 || x < 0 || x >= S)
        return 0;
    return tt__plan_depth_at(plan, (4 * (size_t)tile + (size_t)side) * (size_t)S + (size_t)x);
}

TTDEF float tt_synth_plan_band_alpha(const tt_synth_plan *plan, int tile, int side, int x, int d)
{
    TT_ASSERT(plan && d >= 0 && d < plan->layout.tile_size);
    if (!plan) return 0.0f;
    return tt__band_alpha(plan->layout.tile_size, plan->feather, tt_synth_plan_depth(plan, tile, side, x), x, d);
}

/* A compose_tile whose cell came out non-finite: name the source texel that
   reached it. The tile reads its background window and, per side, its edge
   sample from g rows across the edge to max_depth + feather rows in. */
static tt_result tt__compose_non_finite(const tt_synth_plan *plan, const tt_image *source, const uint8_t types[4],
                                        int tile, int cell_x, int cell_y, tt_error *error)
{
    const int S = plan->layout.tile_size, g = plan->layout.gutter;
    const int deepest = tt__min_i(plan->max_depth + plan->feather, S - 1);
    const tt_rect *bg = &plan->background_windows[tile];
    const float *bad = NULL;
    tt__synth s;
    int x, y, d, side;
    s.source = source;
    s.windows = plan->edge_windows;
    s.vertical = plan->vertical_windows;
    s.size = S;
    for (y = 0; y < S && !bad; y++)
        for (x = 0; x < S && !bad; x++) {
            const float *p = source->pixels + ((size_t)(bg->y + y) * source->width + bg->x + x) * 4;
            if (!tt__is_finite(p[0]) || !tt__is_finite(p[1]) || !tt__is_finite(p[2])) bad = p;
        }
    for (side = 0; side < 4 && !bad; side++)
        for (d = -g; d <= deepest && !bad; d++)
            for (x = 0; x < S && !bad; x++) {
                const float *p = tt__edge_sample(&s, side, types[side], x, d);
                if (!tt__is_finite(p[0]) || !tt__is_finite(p[1]) || !tt__is_finite(p[2])) bad = p;
            }
    if (bad) {
        size_t texel = (size_t)(bad - source->pixels) / 4;
        int sx = (int)(texel % (size_t)source->width), sy = (int)(texel / (size_t)source->width);
        return tt__fail_at(error, TT_ERROR_NON_FINITE, -1, sy, sx,
                           "the source image has a non-finite value at texel %d, %d, which tile %d reads", sx, sy,
                           tile);
    }
    return tt__fail_at(error, TT_ERROR_NON_FINITE, -1, -1, -1,
                       "tile %d composed at %d, %d came out non-finite", tile, cell_x, cell_y);
}

TTDEF tt_result tt_synth_compose_tile(const tt_synth_plan *plan, const tt_image *source, const uint8_t types[4],
                                      tt_image *target, int x, int y, tt_error *error)
{
    tt_result result;
    int S, C, base, side, tile, row;
    tt__ok(error);
    if (!plan || !source || !types || !target)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "tt_synth_compose_tile needs a plan, a source, types and a target (got NULL)");
    if ((result = tt__check_plan(plan, error)) != TT_OK) return result;
    if ((result = tt__check_plan_source(plan, source, error)) != TT_OK) return result;
    if (!target->pixels || target->width <= 0 || target->height <= 0)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1, "the target image is empty");
    base = 2 * plan->layout.colors;
    for (side = 0; side < 4; side++)
        if (types[side] >= base)
            return tt__fail_at(error, TT_ERROR_INDEX_OUT_OF_RANGE, side, -1, -1,
                               "side %d has boundary type %d, but %d colors allow 0..%d", side, types[side],
                               plan->layout.colors, base - 1);
    S = plan->layout.tile_size;
    C = S + 2 * plan->layout.gutter;
    if (x < 0 || y < 0 || x > target->width - C || y > target->height - C)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "a %dx%d cell at %d, %d does not lie inside the %dx%d target", C, C, x, y, target->width,
                        target->height);
    tile = tt_tile_index(&plan->layout, types);
    if (!tt__rect_fits(&plan->background_windows[tile], S, S, source->width, source->height))
        return tt__bad_plan_window(error, "background", tile);
    if ((result = tt__check_plan_windows(plan, source, error)) != TT_OK) return result;
    tt__compose_cell(plan, source, types, tile, target->pixels + ((size_t)y * target->width + (size_t)x) * 4,
                     (size_t)target->width * 4);
    for (row = 0; row < C; row++) {
        const float *p = target->pixels + ((size_t)(y + row) * target->width + (size_t)x) * 4;
        int i;
        for (i = 0; i < 4 * C; i++)
            if (!tt__is_finite(p[i])) return tt__compose_non_finite(plan, source, types, tile, x, y, error);
    }
    return TT_OK;
}

static tt_result tt__synth_apply(const tt_synth_plan *plan, const tt_image *source, const tt_allocator *allocator,
                                 tt_tileset **out, tt_error *error, int check_source, float progress_from,
                                 float progress_to)
{
    tt_tileset *set = NULL;
    tt_result result;
    int S, g, C, T, W, n, ntiles, t;

    tt__ok(error);
    if (!out) return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1, "the output pointer is NULL");
    *out = NULL;
    if (!plan || !source)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "tt_synth_apply needs a plan and a source image (got NULL)");
    if (tt__check_allocator(allocator, error) != TT_OK) return TT_ERROR_INVALID_ARGUMENT;
    if ((result = tt__check_plan(plan, error)) != TT_OK) return result;
    if ((result = tt__check_plan_source(plan, source, error)) != TT_OK) return result;
    if (check_source && (result = tt__check_finite_texels(source, "source image", error)) != TT_OK) return result;
    S = plan->layout.tile_size;
    g = plan->layout.gutter;
    n = plan->layout.colors;
    C = S + 2 * g;
    T = tt_tile_layout_tiles_per_side(&plan->layout);
    W = T * C;
    ntiles = T * T;
    if ((result = tt__check_plan_windows(plan, source, error)) != TT_OK) return result;
    for (t = 0; t < ntiles; t++)
        if (!tt__rect_fits(&plan->background_windows[t], S, S, source->width, source->height))
            return tt__bad_plan_window(error, "background", t);

    set = TT__ALLOC(allocator, tt_tileset, 1);
    if (!set) return tt__fail(error, TT_ERROR_OUT_OF_MEMORY, -1, -1, -1, -1, "out of memory");
    memset(set, 0, sizeof *set);
    set->allocator = tt__allocator_copy(allocator);
    set->layout = plan->layout;
    set->edge_windows = TT__ALLOC(allocator, tt_rect, n);
    set->background_windows = TT__ALLOC(allocator, tt_rect, ntiles);
    if (plan->vertical_windows) set->vertical_windows = TT__ALLOC(allocator, tt_rect, n);
    if (!set->edge_windows || !set->background_windows || (plan->vertical_windows && !set->vertical_windows)) {
        result = tt__fail(error, TT_ERROR_OUT_OF_MEMORY, -1, -1, -1, -1, "out of memory");
        goto done;
    }
    memcpy(set->edge_windows, plan->edge_windows, (size_t)n * sizeof(tt_rect));
    if (plan->vertical_windows) memcpy(set->vertical_windows, plan->vertical_windows, (size_t)n * sizeof(tt_rect));
    memcpy(set->background_windows, plan->background_windows, (size_t)ntiles * sizeof(tt_rect));
    if ((result = tt__image_init(&set->levels[0], W, W, allocator, error)) != TT_OK) goto done;
    set->nlevels = 1;

    for (t = 0; t < ntiles; t++) {
        int column = t % T, row = t / T, base = 2 * n;
        uint8_t types[4];
        tt_image *atlas = &set->levels[0];
        types[0] = (uint8_t)(column / base);
        types[1] = (uint8_t)(column % base);
        types[2] = (uint8_t)(row / base);
        types[3] = (uint8_t)(row % base);
        /* Tile row 0 of the formula is at the bottom of the atlas image. */
        tt__compose_cell(plan, source, types, t,
                         atlas->pixels + ((size_t)(T - 1 - row) * C * (size_t)W + (size_t)column * C) * 4,
                         (size_t)W * 4);
        if (tt__synth_report(plan->progress, plan->progress_user_data, progress_from, progress_to, t + 1, ntiles)) {
            result = tt__fail(error, TT_CANCELLED, -1, -1, -1, -1, "tile synthesis was cancelled");
            goto done;
        }
    }

    /* Mip levels: while the cell size stays even, 2x2 blocks never straddle
       two cells, so halving the whole atlas halves every tile on its own. A
       level is seamless while its gutter is still at least a texel wide. */
    while (set->nlevels < TT_MAX_MIP_LEVELS && ((C >> (set->nlevels - 1)) % 2) == 0) {
        const tt_image *above = &set->levels[set->nlevels - 1];
        result = tt__image_init(&set->levels[set->nlevels], above->width / 2, above->height / 2, allocator, error);
        if (result != TT_OK) goto done;
        tt__downsample_into(above, &set->levels[set->nlevels]);
        set->nlevels++;
    }
    set->seamless_levels = 0;
    while (set->seamless_levels < set->nlevels && (g >> set->seamless_levels) >= 1) set->seamless_levels++;
    result = TT_OK;

done:
    if (result != TT_OK) {
        tt_tileset_free(set);
        return result;
    }
    *out = set;
    return TT_OK;
}

TTDEF tt_result tt_synth_apply(const tt_synth_plan *plan, const tt_image *source, const tt_allocator *allocator,
                               tt_tileset **out, tt_error *error)
{
    return tt__synth_apply(plan, source, allocator, out, error, 1, 0.0f, 1.0f);
}

TTDEF tt_result tt_synthesize_tiles(const tt_image *source, const tt_synth_options *options,
                                    const tt_allocator *allocator, tt_tileset **out_tileset, tt_error *error)
{
    tt_synth_plan *plan;
    tt_result result;
    tt__ok(error);
    if (!out_tileset) return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1, "out_tileset is NULL");
    *out_tileset = NULL;
    result = tt__synth_plan_create(source, options, allocator, &plan, error, "source image", 0.0f, TT__PLAN_SHARE);
    if (result != TT_OK) return result;
    /* The plan checked the source (size, finite texels) already. */
    result = tt__synth_apply(plan, source, allocator, out_tileset, error, 0, TT__PLAN_SHARE, 1.0f);
    tt_synth_plan_free(plan);
    return result;
}

/* --- quality report ------------------------------------------------------ */

typedef struct tt__edge_point {
    float px, py;     /* on the edge, atlas pixel coordinates */
    float nx, ny;     /* unit normal into the face, in pixels */
} tt__edge_point;

/* The point at parameter t along half-edge c, in atlas pixels, with the unit
   normal pointing into c's face (toward the face's UV centroid, so the answer
   does not depend on the face's winding in UV space). */
static int tt__edge_point_at(const tt_mesh *mesh, const float *uv, const tt_image *atlas, int c, float t,
                             tt__edge_point *out)
{
    int next = tt_mesh_next(mesh, c), face = mesh->corner_face[c], k, count = 0;
    float ax = uv[2 * c] * atlas->width, ay = (1.0f - uv[2 * c + 1]) * atlas->height;
    float bx = uv[2 * next] * atlas->width, by = (1.0f - uv[2 * next + 1]) * atlas->height;
    float cx = 0.0f, cy = 0.0f, ex = bx - ax, ey = by - ay, len = sqrtf(ex * ex + ey * ey);
    if (!(len > 1e-6f)) return 0;
    for (k = mesh->face_start[face]; k < mesh->face_start[face + 1]; k++, count++) {
        cx += uv[2 * k] * atlas->width;
        cy += (1.0f - uv[2 * k + 1]) * atlas->height;
    }
    cx /= (float)count;
    cy /= (float)count;
    out->px = ax + ex * t;
    out->py = ay + ey * t;
    out->nx = -ey / len;
    out->ny = ex / len;
    if (out->nx * (cx - out->px) + out->ny * (cy - out->py) < 0.0f) { out->nx = -out->nx; out->ny = -out->ny; }
    return 1;
}

/* A colour as displayed, `depth` pixels inside the face from edge point p:
   the seam measure's thresholds are about what the eye sees, and they were
   set when images held sRGB-encoded values. */
static void tt__displayed(const tt_image *atlas, tt_wrap wrap, const tt__edge_point *p, float depth, float rgb[3])
{
    float rgba[4];
    tt_image_sample_bilinear_wrap(atlas, p->px + p->nx * depth, p->py + p->ny * depth, wrap, rgba);
    rgb[0] = tt_linear_to_srgb(rgba[0]);
    rgb[1] = tt_linear_to_srgb(rgba[1]);
    rgb[2] = tt_linear_to_srgb(rgba[2]);
}

/* Do two UV coordinates agree within TT_SEAM_UV_TOLERANCE of their scale?
   NaN agrees with nothing. */
static int tt__uv_coordinate_agrees(float x, float y)
{
    double scale = fabs((double)x) > fabs((double)y) ? fabs((double)x) : fabs((double)y);
    if (!(scale > 1.0)) scale = 1.0;
    return fabs((double)x - (double)y) <= TT_SEAM_UV_TOLERANCE * scale;
}

/* Interior half-edge a -> a' with twin b -> b': its UVs are continuous when
   uv[a] == uv[b'] and uv[a'] == uv[b] (see TT_SEAM_UV_TOLERANCE). */
static int tt__edge_uv_discontinuous(const tt_mesh *mesh, const float *uv, int a)
{
    int b = mesh->twin[a], ends[2][2], k;
    ends[0][0] = a; ends[0][1] = tt_mesh_next(mesh, b);
    ends[1][0] = tt_mesh_next(mesh, a); ends[1][1] = b;
    for (k = 0; k < 2; k++)
        if (!tt__uv_coordinate_agrees(uv[2 * ends[k][0]], uv[2 * ends[k][1]]) ||
            !tt__uv_coordinate_agrees(uv[2 * ends[k][0] + 1], uv[2 * ends[k][1] + 1]))
            return 1;
    return 0;
}

TTDEF tt_result tt_measure_seams(const tt_mesh *mesh, const float *corner_uv, const tt_image *atlas,
                                 const tt_seam_options *options, const tt_allocator *allocator,
                                 tt_seam_report *report, tt_error *error)
{
    const unsigned known_flags = TT_SEAM_UV_DISCONTINUOUS | TT_SEAM_WRAP;
    int *interior, ninterior = 0, npopulation, nmeasured, ndiscontinuous = 0, c, i, j, points_per_edge;
    unsigned char *listed;      /* with an edge list: per corner, 1 on the lower corner of a listed edge */
    double seam = 0.0, same = 0.0, unrelated = 0.0;
    long long samples = 0;
    tt_seam_options opt;
    tt_wrap wrap;
    tt_rng rng;
    tt__ok(error);
    if (report) {
        memset(report, 0, sizeof *report);
        report->score = tt__not_a_number();
    }
    if (!mesh || !corner_uv || !atlas || !report)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "tt_measure_seams needs a mesh, UVs, an atlas and a report (got NULL)");
    if (!atlas->pixels || atlas->width <= 0 || atlas->height <= 0)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1, "the atlas is empty");
    if (options) opt = *options;
    else memset(&opt, 0, sizeof opt);
    if (opt.max_edges < 0)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1, "max_edges is %d: 0 (all) or more",
                        opt.max_edges);
    if (opt.flags & ~known_flags)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "seam option flags 0x%x include unknown bits 0x%x (known: TT_SEAM_UV_DISCONTINUOUS, "
                        "TT_SEAM_WRAP)", opt.flags, opt.flags & ~known_flags);
    if (opt.nedges < 0 || (!opt.edges && opt.nedges > 0))
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "the edge list has %d entries at %s: give a list and its length, or NULL for every edge",
                        opt.nedges, opt.edges ? "an address" : "NULL");
    for (i = 0; opt.edges && i < opt.nedges; i++) {
        if (opt.edges[i] < 0 || opt.edges[i] >= mesh->ncorners)
            return tt__fail_at(error, TT_ERROR_INDEX_OUT_OF_RANGE, i, -1, -1,
                               "listed edge %d is corner %d, outside the mesh's %d corners", i, opt.edges[i],
                               mesh->ncorners);
        if (mesh->twin[opt.edges[i]] < 0)
            return tt__fail_at(error, TT_ERROR_INVALID_ARGUMENT, i, -1, -1,
                               "listed edge %d (corner %d) is on the boundary: a seam needs a face on each side", i,
                               opt.edges[i]);
    }
    if (tt__check_allocator(allocator, error) != TT_OK) return TT_ERROR_INVALID_ARGUMENT;
    wrap = (opt.flags & TT_SEAM_WRAP) ? TT_WRAP_REPEAT : TT_WRAP_CLAMP;
    interior = TT__ALLOC(allocator, int, mesh->ncorners);
    listed = opt.edges ? TT__ALLOC(allocator, unsigned char, mesh->ncorners) : NULL;
    if (!interior || (opt.edges && !listed)) {
        tt__free(allocator, interior);
        tt__free(allocator, listed);
        return tt__fail(error, TT_ERROR_OUT_OF_MEMORY, -1, -1, -1, -1, "out of memory measuring %d corners",
                        mesh->ncorners);
    }
    if (listed) {
        /* Each edge marked on its lower corner, the one the loop below visits. */
        memset(listed, 0, (size_t)mesh->ncorners);
        for (i = 0; i < opt.nedges; i++) {
            int a = opt.edges[i], b = mesh->twin[a];
            listed[a < b ? a : b] = 1;
        }
    }
    for (c = 0; c < mesh->ncorners; c++)
        if (mesh->twin[c] > c) {
            interior[ninterior++] = c;
            ndiscontinuous += tt__edge_uv_discontinuous(mesh, corner_uv, c);
        }
    report->edges_discontinuous = ndiscontinuous;
    /* The measured population is interior[0 .. npopulation-1]: every interior
       edge, or those listed and, in restricted mode, discontinuous, swapped
       to the front (the others follow: they remain candidates for unrelated
       pairs). */
    npopulation = ninterior;
    if ((opt.flags & TT_SEAM_UV_DISCONTINUOUS) || listed) {
        npopulation = 0;
        for (i = 0; i < ninterior; i++)
            if ((!listed || listed[interior[i]]) &&
                (!(opt.flags & TT_SEAM_UV_DISCONTINUOUS) || tt__edge_uv_discontinuous(mesh, corner_uv, interior[i]))) {
                int edge = interior[i];
                interior[i] = interior[npopulation];
                interior[npopulation++] = edge;
            }
    }
    tt__free(allocator, listed);
    if (npopulation == 0 && ((opt.flags & TT_SEAM_UV_DISCONTINUOUS) || listed)) {
        tt__free(allocator, interior);
        if ((opt.flags & TT_SEAM_UV_DISCONTINUOUS) && ndiscontinuous == 0)
            return tt__fail(error, TT_ERROR_NOT_MEASURED, -1, -1, -1, -1,
                            "no interior edge has discontinuous UVs: nothing to measure in "
                            "TT_SEAM_UV_DISCONTINUOUS mode");
        return tt__fail(error, TT_ERROR_NOT_MEASURED, -1, -1, -1, -1, "no listed edge is left to measure (%d listed%s)",
                        opt.nedges, (opt.flags & TT_SEAM_UV_DISCONTINUOUS) ? ", none of them discontinuous" : "");
    }
    tt_rng_seed(&rng, opt.seed, 0x7365616d73ull /* "seams" */);
    /* A quick estimate measures a random subset of the population: the first
       max_edges of a partial Fisher-Yates shuffle. Unrelated pairs are still
       drawn from every interior edge. */
    nmeasured = npopulation;
    if (opt.max_edges > 0 && opt.max_edges < npopulation) {
        nmeasured = opt.max_edges;
        for (i = 0; i < nmeasured; i++) {
            int pick = i + (int)tt_rng_below(&rng, (uint32_t)(npopulation - i)), swap = interior[i];
            interior[i] = interior[pick];
            interior[pick] = swap;
        }
    }
    /* Four points an edge, more on small meshes so that every measure rests
       on a few thousand samples. */
    points_per_edge = nmeasured > 0 ? tt__clamp_i(4096 / nmeasured, 4, 64) : 4;
    for (i = 0; i < nmeasured && ninterior > 1; i++) {
        int a = interior[i], b = mesh->twin[a], edge_samples = 0;
        for (j = 0; j < points_per_edge; j++) {
            /* Stratified along the edge; the twin runs the other way. */
            float t = ((float)j + tt_rng_float(&rng)) / (float)points_per_edge;
            int other = interior[(i + 1 + (int)tt_rng_below(&rng, (uint32_t)(ninterior - 1))) % ninterior];
            float t_other = tt_rng_float(&rng);
            tt__edge_point pa, pb, po;
            float sa[3], sa_deeper[3], sb[3], so[3];
            if (!tt__edge_point_at(mesh, corner_uv, atlas, a, t, &pa) ||
                !tt__edge_point_at(mesh, corner_uv, atlas, b, 1.0f - t, &pb) ||
                !tt__edge_point_at(mesh, corner_uv, atlas, other, t_other, &po))
                continue;
            tt__displayed(atlas, wrap, &pa, 0.5f, sa);
            tt__displayed(atlas, wrap, &pa, 1.5f, sa_deeper);
            tt__displayed(atlas, wrap, &pb, 0.5f, sb);
            tt__displayed(atlas, wrap, &po, 0.5f, so);
            seam += tt__texel_difference(sa, sb);
            same += tt__texel_difference(sa, sa_deeper);
            unrelated += tt__texel_difference(sa, so);
            samples++;
            edge_samples++;
        }
        if (edge_samples > 0) report->edges_measured++;
    }
    tt__free(allocator, interior);
    if (samples == 0) {
        report->edges_measured = 0;
        return tt__fail(error, TT_ERROR_NOT_MEASURED, -1, -1, -1, -1,
                        ninterior < 2 ? "the mesh has %d interior edges: the seam measure needs at least two"
                                      : "none of the %d measured interior edges could be sampled (zero length or "
                                        "non-finite UVs)",
                        ninterior < 2 ? ninterior : npopulation);
    }
    report->samples = samples;
    report->seam = seam / (double)samples;
    report->same_face = same / (double)samples;
    report->unrelated = unrelated / (double)samples;
    if (report->unrelated - report->same_face > 1e-9)
        report->score = (report->seam - report->same_face) / (report->unrelated - report->same_face);
    return TT_OK;
}

TTDEF tt_result tt_tile_histogram(const tt_mesh *mesh, const tt_tile_layout *layout, const uint8_t *corner_type,
                                  int *counts, tt_error *error)
{
    tt_tile_layout resolved = {0, 0, 0}; /* written by tt_tile_layout_resolve; set so no compiler sees it unset */
    tt_result result;
    int f, c, base;
    tt__ok(error);
    if (!mesh || !layout || !corner_type || !counts)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "tt_tile_histogram needs a mesh, a layout, corner types and counts (got NULL)");
    if ((result = tt_tile_layout_resolve(layout, &resolved, error)) != TT_OK) return result;
    base = 2 * resolved.colors;
    for (f = 0; f < mesh->nfaces; f++)
        if (mesh->face_start[f + 1] - mesh->face_start[f] != 4)
            return tt__fail(error, TT_ERROR_NOT_QUAD_MESH, f, mesh->face_start[f], -1, -1,
                            "face %d has %d corners; tiles belong to quads", f,
                            mesh->face_start[f + 1] - mesh->face_start[f]);
    for (c = 0; c < mesh->ncorners; c++)
        if (corner_type[c] >= base)
            return tt__fail(error, TT_ERROR_INDEX_OUT_OF_RANGE, mesh->corner_face[c], c, -1, -1,
                            "corner %d has boundary type %d, but %d colors allow 0..%d", c, corner_type[c],
                            resolved.colors, base - 1);
    memset(counts, 0, (size_t)tt_tile_layout_tile_count(&resolved) * sizeof(int));
    for (f = 0; f < mesh->nfaces; f++) counts[tt_tile_index(&resolved, corner_type + 4 * (size_t)f)]++;
    return TT_OK;
}

/* The two tangents of a face's own parametrisation (s, t) at its centre, for
   points of `dims` coordinates: a quad's bilinear patch derivatives, or the
   edges of the first triangle for any other face. */
static void tt__face_tangents(const float *const point[4], int dims, int size, double tangent[2][3])
{
    int k;
    for (k = 0; k < dims; k++) {
        if (size == 4) {
            tangent[0][k] = 0.5 * (((double)point[1][k] - point[0][k]) + ((double)point[2][k] - point[3][k]));
            tangent[1][k] = 0.5 * (((double)point[3][k] - point[0][k]) + ((double)point[2][k] - point[1][k]));
        } else {
            tangent[0][k] = (double)point[1][k] - point[0][k];
            tangent[1][k] = (double)point[2][k] - point[0][k];
        }
    }
}

/* The map from texture to surface of `face` at its centre, M (3x2, columns
   dP/du and dP/dv), through the face's own parametrisation (s, t): for a
   quad the bilinear patch's derivatives, otherwise the first triangle.
   A = dP/d(s,t) (3x2), B = dUV/d(s,t) (2x2) with texture coordinates
   (u * u_scale, v * v_scale) (1, 1: UV units; width, height: texels), and
   M = A B^-1. Gives the eigenvalues big >= small of M^T M, the squares of
   M's singular values; returns 0 when B is singular (|det B| < 1e-30). */
/* Eigenvalues big >= small of the symmetric 2x2 matrix [g11 g12; g12 g22]:
   a map's metric, whose square roots are its singular values. */
static void tt__metric_eigenvalues(double g11, double g12, double g22, double *big, double *small)
{
    double tr = g11 + g22, disc = sqrt((g11 - g22) * (g11 - g22) + 4.0 * g12 * g12);
    *big = 0.5 * (tr + disc);
    *small = 0.5 * (tr - disc);
}

static int tt__face_texture_to_surface(const tt_mesh *mesh, const float *corner_uv, int face, double u_scale,
                                       double v_scale, double *big, double *small)
{
    int first = mesh->face_start[face], size = mesh->face_start[face + 1] - first, k;
    const float *p[4], *q[4];
    double a[2][3], b[2][3], det, m[2][3], g11 = 0, g12 = 0, g22 = 0;
    for (k = 0; k < 4; k++) {
        int corner = first + (size == 4 ? k : (k < 3 ? k : 2));
        p[k] = mesh->pos + 3 * (size_t)mesh->corner_vert[corner];
        q[k] = corner_uv + 2 * (size_t)corner;
    }
    tt__face_tangents(p, 3, size, a);
    tt__face_tangents(q, 2, size, b);
    for (k = 0; k < 2; k++) {
        b[k][0] *= u_scale;
        b[k][1] *= v_scale;
    }
    /* b[i] is d(u,v)/d(param i); rows of A likewise. Solve M B = A for the
       two texture axes: M's column for u and v. */
    det = b[0][0] * b[1][1] - b[0][1] * b[1][0];
    if (fabs(det) < 1e-30) return 0;
    for (k = 0; k < 3; k++) {
        m[0][k] = (a[0][k] * b[1][1] - a[1][k] * b[0][1]) / det;   /* dP/du */
        m[1][k] = (a[1][k] * b[0][0] - a[0][k] * b[1][0]) / det;   /* dP/dv */
        g11 += m[0][k] * m[0][k];
        g12 += m[0][k] * m[1][k];
        g22 += m[1][k] * m[1][k];
    }
    tt__metric_eigenvalues(g11, g12, g22, big, small);
    return 1;
}

/* sigma_max / sigma_min from the eigenvalues of tt__face_texture_to_surface
   (the same ratio for the map and its inverse, surface -> texture);
   infinity when the smaller one vanishes against the larger. */
static double tt__stretch_ratio(double big, double small)
{
    return small > 1e-30 * (big > 0 ? big : 1) ? sqrt(big / small) : (double)tt__infinity();
}

TTDEF tt_result tt_face_stretch(const tt_mesh *mesh, const float *corner_uv, float *stretch, tt_error *error)
{
    int f, c;
    tt__ok(error);
    if (!mesh || !corner_uv || !stretch)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "tt_face_stretch needs a mesh, UVs and the stretch array (got NULL)");
    for (c = 0; c < 2 * mesh->ncorners; c++)
        if (!tt__is_finite(corner_uv[c]))
            return tt__fail(error, TT_ERROR_NON_FINITE, mesh->corner_face[c / 2], c / 2, -1, -1,
                            "corner %d (face %d) has a non-finite UV", c / 2, mesh->corner_face[c / 2]);
    for (f = 0; f < mesh->nfaces; f++) {
        double big, small;
        stretch[f] = tt__face_texture_to_surface(mesh, corner_uv, f, 1.0, 1.0, &big, &small)
                         ? (float)tt__stretch_ratio(big, small)
                         : tt__infinity();
    }
    return TT_OK;
}

/* Twice the signed area of face f's UV polygon in texels (u * width, v *
   height; positive counter-clockwise with v up), taken relative to its first
   corner as tt__polygon_newell does in 3D, and the polygon's own size (the
   sum of squared distances to that corner) to judge it zero against. */
static void tt__uv_polygon_area(const tt_mesh *mesh, const float *corner_uv, int face, int width, int height,
                                double *twice_area, double *scale)
{
    int first = mesh->face_start[face], end = mesh->face_start[face + 1], c;
    double ox = (double)corner_uv[2 * first] * width, oy = (double)corner_uv[2 * first + 1] * height;
    double ax = 0.0, ay = 0.0;
    *twice_area = 0.0;
    *scale = 0.0;
    for (c = first + 1; c < end; c++) {
        double bx = (double)corner_uv[2 * c] * width - ox, by = (double)corner_uv[2 * c + 1] * height - oy;
        *twice_area += ax * by - ay * bx;
        *scale += bx * bx + by * by;
        ax = bx;
        ay = by;
    }
}

TTDEF tt_result tt_measure_uv_distortion(const tt_mesh *mesh, const float *corner_uv, int width, int height,
                                         const tt_uv_distortion_options *options, const tt_allocator *allocator,
                                         tt_uv_distortion_report *report, tt_error *error)
{
    static const double median_and_p95[2] = {0.5, 0.95};
    tt_uv_distortion_options opt;
    tt__weighted *stretch, *density;
    double texels_per_unit, stats[2];
    int f, c, n = 0;
    tt__ok(error);
    if (report) {
        double not_measured = tt__not_a_number();
        memset(report, 0, sizeof *report);
        report->stretch_median = report->stretch_p95 = report->stretch_max = not_measured;
        report->density_median = report->density_p95 = report->texels_per_unit = not_measured;
    }
    if (!mesh || !corner_uv || !report)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "tt_measure_uv_distortion needs a mesh, UVs and a report (got NULL)");
    if (width < 1 || height < 1)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "the image is %d x %d texels: both sizes must be at least 1", width, height);
    if (options) opt = *options;
    else memset(&opt, 0, sizeof opt);
    if (!tt__is_finite_d(opt.texels_per_unit) || opt.texels_per_unit < 0.0)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "texels_per_unit is %g: 0 (measure it) or a positive finite number", opt.texels_per_unit);
    if (!tt__is_finite_d(opt.margin_texels) || opt.margin_texels < 0.0)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "margin_texels is %g: 0 (no check) or a positive finite number", opt.margin_texels);
    if (tt__check_allocator(allocator, error) != TT_OK) return TT_ERROR_INVALID_ARGUMENT;
    stretch = TT__ALLOC(allocator, tt__weighted, 2 * (size_t)mesh->nfaces);
    if (!stretch)
        return tt__fail(error, TT_ERROR_OUT_OF_MEMORY, -1, -1, -1, -1,
                        "out of memory measuring the UV distortion of %d faces", mesh->nfaces);
    density = stretch + mesh->nfaces;

    if (opt.margin_texels > 0.0)
        for (c = 0; c < mesh->ncorners; c++) {
            double x = (double)corner_uv[2 * c] * width, y = (double)corner_uv[2 * c + 1] * height;
            double m = opt.margin_texels;
            if (tt__is_finite_d(x) && tt__is_finite_d(y) && (x < m || x > width - m || y < m || y > height - m))
                report->outside_margin++;
        }
    for (f = 0; f < mesh->nfaces; f++) {
        int first = mesh->face_start[f], size = mesh->face_start[f + 1] - first, finite = 1;
        double normal[3], surface_scale, twice_uv_area, uv_scale, uv_normal[3], big, small, surface_area, ratio;
        for (c = first; c < first + size; c++)
            finite &= tt__is_finite(corner_uv[2 * c]) && tt__is_finite(corner_uv[2 * c + 1]);
        if (!finite) {
            report->non_finite++;
            continue;
        }
        /* Zero area in either space is judged as tt_mesh_build judges it:
           against the polygon's own size. */
        tt__polygon_newell(mesh->pos, mesh->corner_vert + first, size, normal, &surface_scale);
        tt__uv_polygon_area(mesh, corner_uv, f, width, height, &twice_uv_area, &uv_scale);
        uv_normal[0] = uv_normal[1] = 0.0;
        uv_normal[2] = twice_uv_area;
        if (tt__newell_is_zero(normal, surface_scale) || tt__newell_is_zero(uv_normal, uv_scale) ||
            !tt__face_texture_to_surface(mesh, corner_uv, f, width, height, &big, &small) ||
            !tt__is_finite_d(ratio = tt__stretch_ratio(big, small))) {
            report->degenerate++;
            continue;
        }
        if (twice_uv_area < 0.0) report->flipped++;
        surface_area = 0.5 * tt__length3(normal);
        stretch[n].value = ratio;
        stretch[n].weight = surface_area;
        /* texel density = sqrt(UV area in texels^2 / surface area) */
        density[n].value = sqrt(0.5 * fabs(twice_uv_area) / surface_area);
        density[n].weight = surface_area;
        if (!(ratio <= report->stretch_max)) report->stretch_max = ratio;   /* the first replaces the NaN */
        n++;
    }
    report->faces_measured = n;
    if (n == 0) {
        tt__free(allocator, stretch);
        return tt__fail(error, TT_ERROR_NOT_MEASURED, -1, -1, -1, -1,
                        "none of the %d faces could be measured: %d have zero surface or UV area, %d a non-finite "
                        "UV", mesh->nfaces, report->degenerate, report->non_finite);
    }
    tt__weighted_percentiles(stretch, n, median_and_p95, 2, stats);
    report->stretch_median = stats[0];
    report->stretch_p95 = stats[1];
    texels_per_unit = opt.texels_per_unit;
    if (texels_per_unit == 0.0) tt__weighted_percentiles(density, n, median_and_p95, 1, &texels_per_unit);
    report->texels_per_unit = texels_per_unit;
    for (f = 0; f < n; f++) density[f].value = fabs(density[f].value / texels_per_unit - 1.0);
    tt__weighted_percentiles(density, n, median_and_p95, 2, stats);
    report->density_median = stats[0];
    report->density_p95 = stats[1];
    tt__free(allocator, stretch);
    return TT_OK;
}

/* ------------------------------------------------------------------------ */
/* 7. Lapped textures                                                       */
/* ------------------------------------------------------------------------ */

/* Parallel transport across half-edge c (of the source face, normal ns) into
   the face across it (normal nt): with e the unit edge direction and
   b = n x e, v = (v.e) e + (v.b_s) b_s  ->  (v.e) e + (v.b_s) b_t, i.e. the
   rotation about the edge taking ns to nt. The result is projected on the
   target plane (non-planar polygons) and given v's tangential length back. */
static void tt__field_transport(const tt_mesh *mesh, int c, const double *ns, const double *nt, const double *v,
                                double *out)
{
    const float *p = mesh->pos + 3 * (size_t)mesh->corner_vert[c];
    const float *q = mesh->pos + 3 * (size_t)mesh->corner_vert[tt_mesh_next(mesh, c)];
    double e[3], bs[3], bt[3], r[3], ve, vb, len;
    tt__sub3f(q, p, e);
    len = tt__length3(v);
    if (tt__normalize3(e) <= 0.0) { tt__project3(v, nt, out); return; }
    tt__cross3(ns, e, bs);
    tt__cross3(nt, e, bt);
    tt__normalize3(bs);
    tt__normalize3(bt);
    ve = tt__dot3(v, e);
    vb = tt__dot3(v, bs);
    r[0] = ve * e[0] + vb * bt[0]; r[1] = ve * e[1] + vb * bt[1]; r[2] = ve * e[2] + vb * bt[2];
    tt__project3(r, nt, out);
    if (tt__normalize3(out) > 0.0) { out[0] *= len; out[1] *= len; out[2] *= len; }
}

/* Distance of one dual step from face a across half-edge c (of a) to face b:
   centroid(a) -> midpoint of the edge -> centroid(b). */
static double tt__field_step(const tt_mesh *mesh, const double *centroid, int a, int c, int b)
{
    const float *p = mesh->pos + 3 * (size_t)mesh->corner_vert[c];
    const float *q = mesh->pos + 3 * (size_t)mesh->corner_vert[tt_mesh_next(mesh, c)];
    double m[3], da[3], db[3];
    int k;
    for (k = 0; k < 3; k++) {
        m[k] = 0.5 * ((double)p[k] + q[k]);
        da[k] = m[k] - centroid[3 * (size_t)a + k];
        db[k] = m[k] - centroid[3 * (size_t)b + k];
    }
    return tt__length3(da) + tt__length3(db);
}

/* The tangent field's working state, shared by its phases. */
#define TT__FIELD_DECIDES_FROM 0.1     /* |P(up)| below which up says nothing of a face's direction (6 degrees
                                          from facing up: a scan's noise turns it at random there)... */
#define TT__FIELD_DECIDES_AT 0.5       /* ...and from which it decides it (30 degrees) */
#define TT__FIELD_SMOOTHING_EDGES 4.0  /* the smoothing length in mean edge lengths at most */
#define TT__FIELD_TIE 0.01             /* the tie axis's pull where up says nothing, against up's where it does */
#define TT__FIELD_TOLERANCE 1e-2       /* CG's relative residual: at 3e-2 faces where up decides stray past 1 degree */

typedef struct tt__field {
    const tt_mesh *mesh;
    const tt_allocator *al;
    tt_field_options opt;       /* the caller's options, or all zero */
    int nf;
    double up[3];               /* unit global up */
    double scale, sigma;        /* defaults resolved (mesh units) */
    double *normal;             /* 3 per face: unit normal, 0 for zero area */
    double *vec;                /* 3 per face: the field being built */
    int *state;                 /* -1 = zero-area face (never assigned), 0 = unassigned, 1 = assigned */
    int *queue;                 /* nf ints of scratch */
} tt__field;

/* Phase 1 (Sec. 3.2's parameters): check the options, resolve up, and the
   default scale and sigma from the bounding-box diagonal of the vertices
   the faces use. Nothing is allocated. */
static tt_result tt__field_setup(tt__field *F, const tt_mesh *mesh, const tt_field_options *options,
                                 const tt_allocator *allocator, tt_error *error)
{
    tt_field_options *opt = &F->opt;
    double diag, lo[3], hi[3];
    int c, k;

    memset(F, 0, sizeof *F);
    F->mesh = mesh;
    F->al = allocator;
    if (options) *opt = *options;
    else memset(opt, 0, sizeof *opt);
    if (tt__check_allocator(allocator, error) != TT_OK) return TT_ERROR_INVALID_ARGUMENT;
    F->nf = mesh->nfaces;

    /* Options. */
    for (k = 0; k < 3; k++)
        if (!tt__is_finite(opt->up[k]))
            return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                            "the up vector (%g, %g, %g) is not finite", opt->up[0], opt->up[1], opt->up[2]);
    if (opt->up[0] == 0.0f && opt->up[1] == 0.0f && opt->up[2] == 0.0f) opt->up[1] = 1.0f;
    for (k = 0; k < 3; k++) F->up[k] = opt->up[k];
    if (!(tt__normalize3(F->up) > 0.0))
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "the up vector (%g, %g, %g) has no usable length", opt->up[0], opt->up[1], opt->up[2]);
    if (!tt__is_finite(opt->scale) || opt->scale < 0.0f)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "scale %g must be finite and >= 0 (0 = default)", opt->scale);
    if (!tt__is_finite(opt->sigma) || opt->sigma < 0.0f)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "sigma %g must be finite and >= 0 (0 = default)", opt->sigma);
    if (opt->nconstraints < 0 || (opt->nconstraints > 0 && !opt->constraints))
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "nconstraints is %d with constraints %s", opt->nconstraints,
                        opt->constraints ? "given" : "NULL");
    if (F->nf <= 0) return TT_OK;   /* nothing to build: the driver stops here */

    /* Bounding-box diagonal of the vertices the faces use. */
    for (k = 0; k < 3; k++) { lo[k] = 1e300; hi[k] = -1e300; }
    for (c = 0; c < mesh->ncorners; c++) {
        const float *p = mesh->pos + 3 * (size_t)mesh->corner_vert[c];
        for (k = 0; k < 3; k++) {
            if (p[k] < lo[k]) lo[k] = p[k];
            if (p[k] > hi[k]) hi[k] = p[k];
        }
    }
    for (k = 0; k < 3; k++) lo[k] = hi[k] - lo[k];
    diag = tt__length3(lo);
    if (!(diag > 0.0)) diag = 1.0;
    F->scale = opt->scale > 0.0f ? (double)opt->scale : TT_DEFAULT_FIELD_SCALE * diag;
    F->sigma = opt->sigma > 0.0f ? (double)opt->sigma : TT_DEFAULT_FIELD_SIGMA * diag;
    return TT_OK;
}

/* Phase 2, first: every constraint checked before any work (face in range,
   finite, not negative, on a face with a plane, not perpendicular to it). */
static tt_result tt__field_check_constraints(const tt__field *F, tt_error *error)
{
    int i, k, nf = F->nf;
    for (i = 0; i < F->opt.nconstraints; i++) {
        const tt_field_constraint *con = &F->opt.constraints[i];
        double v[3], p[3], len, plen;
        tt_result result = TT_OK;
        if (con->face < 0 || con->face >= nf) {
            result = tt__fail(error, TT_ERROR_INDEX_OUT_OF_RANGE, con->face, -1, -1, -1,
                              "constraint %d names face %d, but the mesh has %d faces", i, con->face, nf);
        } else if (!tt__is_finite(con->vector[0]) || !tt__is_finite(con->vector[1]) ||
                   !tt__is_finite(con->vector[2]) || !tt__is_finite(con->sigma) || !tt__is_finite(con->weight)) {
            result = tt__fail(error, TT_ERROR_NON_FINITE, con->face, -1, -1, -1,
                              "constraint %d (face %d) has a NaN or infinite vector, sigma or weight", i, con->face);
        } else if (con->sigma < 0.0f || con->weight < 0.0f) {
            result = tt__fail(error, TT_ERROR_INVALID_ARGUMENT, con->face, -1, -1, -1,
                              "constraint %d (face %d) has sigma %g and weight %g; neither may be negative", i,
                              con->face, con->sigma, con->weight);
        } else if (F->state[con->face] < 0) {
            result = tt__fail(error, TT_ERROR_ZERO_AREA_FACE, con->face, -1, -1, -1,
                              "constraint %d is on face %d, which has zero area and no plane", i, con->face);
        } else {
            for (k = 0; k < 3; k++) v[k] = con->vector[k];
            len = tt__length3(v);
            tt__project3(v, F->normal + 3 * (size_t)con->face, p);
            plen = tt__length3(p);
            if (!(len > 0.0) || !(plen > 1e-3 * len))
                result = tt__fail(error, TT_ERROR_INVALID_ARGUMENT, con->face, -1, -1, -1,
                                  "constraint %d (face %d): its vector (%g, %g, %g) is %s", i, con->face,
                                  con->vector[0], con->vector[1], con->vector[2],
                                  len > 0.0 ? "perpendicular to the face" : "zero");
        }
        if (result != TT_OK) {
            if (error) error->item = i;
            return result;
        }
    }
    return TT_OK;
}

/* Scratch of the constraint phase: per face, the Dijkstra distance and
   tree, the transported constraint vector, and the running weighted sums. */
typedef struct tt__field_rbf {
    double *centroid;           /* 3 per face */
    double *dist;               /* Dijkstra distance, -1 unreached */
    double *trans;              /* 3 per face: t_i(f), constraint i carried to f */
    double *sum, *wsum, *lsum;  /* sum of w t_i (3 per face), of w, of w |c_i|, relative to wlog */
    double *wlog;               /* the largest log weight so far */
    double *best;               /* 4 per face: best log weight, then that constraint's t_i(f) */
    int *parent;                /* half-edge crossed into the face; -2 unreached, -1 source, -3 settled */
    tt__heap_item *heap;        /* ncorners + 1 */
} tt__field_rbf;

/* Phase 2a (Sec. 3.2 "Gaussian radial basis functions, where radius is
   defined as distance over the mesh, as computed using Dijkstra's
   algorithm"): one Dijkstra pass from constraint con over the dual graph,
   carrying its vector by parallel transport along the tree and adding
   w = weight exp(-d^2 / 2 sigma^2) times it into every face reached. */
static void tt__field_dijkstra(const tt__field *F, tt__field_rbf *R, const tt_field_constraint *con)
{
    const tt_mesh *mesh = F->mesh;
    double s = con->sigma > 0.0f ? (double)con->sigma : F->sigma;
    double wt = con->weight > 0.0f ? (double)con->weight : 1.0, len, v[3];
    int nheap = 0, f, c, k;
    for (k = 0; k < 3; k++) v[k] = con->vector[k];
    len = tt__length3(v);
    for (f = 0; f < F->nf; f++) { R->dist[f] = -1.0; R->parent[f] = -2; }   /* -2 unreached, -1 source */
    R->dist[con->face] = 0.0;
    R->parent[con->face] = -1;
    tt__heap_push(R->heap, &nheap, 0.0, con->face);
    while (nheap > 0) {
        tt__heap_item top = tt__heap_pop(R->heap, &nheap);
        int g = top.value, begin, end;
        double *t = R->trans + 3 * (size_t)g, lw, scl;
        if (top.key > R->dist[g]) continue;   /* stale entry */
        if (R->parent[g] == -1) {
            tt__project3(v, F->normal + 3 * (size_t)g, t);
            tt__normalize3(t);
            t[0] *= len; t[1] *= len; t[2] *= len;
        } else {
            int from = mesh->corner_face[R->parent[g]];
            tt__field_transport(mesh, R->parent[g], F->normal + 3 * (size_t)from, F->normal + 3 * (size_t)g,
                                R->trans + 3 * (size_t)from, t);
        }
        R->parent[g] = -3;   /* settled */
        /* Accumulate w = wt exp(-d^2 / 2s^2) relative to the largest log weight so far. */
        lw = log(wt) - top.key * top.key / (2.0 * s * s);
        if (lw > R->wlog[g]) {
            scl = R->wsum[g] > 0.0 ? exp(R->wlog[g] - lw) : 0.0;
            for (k = 0; k < 3; k++) R->sum[3 * (size_t)g + k] *= scl;
            R->wsum[g] *= scl;
            R->lsum[g] *= scl;
            R->wlog[g] = lw;
        }
        scl = exp(lw - R->wlog[g]);
        for (k = 0; k < 3; k++) R->sum[3 * (size_t)g + k] += scl * t[k];
        R->wsum[g] += scl;
        R->lsum[g] += scl * len;
        if (lw > R->best[4 * (size_t)g]) {
            R->best[4 * (size_t)g] = lw;
            for (k = 0; k < 3; k++) R->best[4 * (size_t)g + 1 + k] = t[k];
        }
        begin = mesh->face_start[g];
        end = mesh->face_start[g + 1];
        for (c = begin; c < end; c++) {
            int tw = mesh->twin[c], h;
            double d;
            if (tw < 0) continue;
            h = mesh->corner_face[tw];
            if (F->state[h] < 0 || R->parent[h] == -3 || R->parent[h] == -1) continue;
            d = top.key + tt__field_step(mesh, R->centroid, g, c, h);
            if (R->dist[h] < 0.0 || d < R->dist[h]) {
                R->dist[h] = d;
                R->parent[h] = c;
                tt__heap_push(R->heap, &nheap, d, h);
            }
        }
    }
}

/* Phase 2b: T_f = (sum w |c_i| / sum w) normalize(sum w t_i(f)) on every face
   a constraint reached (the strongest constraint's direction where the
   directions cancel); then a constrained face gets exactly the average of
   its own constraints. R->sum and R->wsum are reused as scratch. */
static void tt__field_blend(tt__field *F, tt__field_rbf *R)
{
    const tt_field_constraint *cons = F->opt.constraints;
    int f, i, k;
    for (f = 0; f < F->nf; f++) {
        double *o = F->vec + 3 * (size_t)f, dir[3];
        if (F->state[f] < 0 || !(R->wsum[f] > 0.0)) continue;
        for (k = 0; k < 3; k++) dir[k] = R->sum[3 * (size_t)f + k];
        tt__project3(dir, F->normal + 3 * (size_t)f, dir);
        if (!(tt__normalize3(dir) > 1e-9 * (R->lsum[f] / R->wsum[f]))) {
            for (k = 0; k < 3; k++) dir[k] = R->best[4 * (size_t)f + 1 + k];
            tt__normalize3(dir);
        }
        for (k = 0; k < 3; k++) o[k] = dir[k] * (R->lsum[f] / R->wsum[f]);
        F->state[f] = 1;
    }
    /* A constrained face gets exactly the average of its own constraints. */
    for (f = 0; f < F->nf; f++) R->wsum[f] = 0.0;
    for (i = 0; i < F->opt.nconstraints; i++) {
        const tt_field_constraint *con = &cons[i];
        double *o = R->sum + 3 * (size_t)con->face;
        if (R->wsum[con->face] == 0.0) o[0] = o[1] = o[2] = 0.0;
        for (k = 0; k < 3; k++) o[k] += con->vector[k];
        R->wsum[con->face] += 1.0;
    }
    for (i = 0; i < F->opt.nconstraints; i++) {
        int g = cons[i].face;
        double p[3], *o = F->vec + 3 * (size_t)g;
        if (R->wsum[g] == 0.0) continue;
        for (k = 0; k < 3; k++) R->sum[3 * (size_t)g + k] /= R->wsum[g];
        tt__project3(R->sum + 3 * (size_t)g, F->normal + 3 * (size_t)g, p);
        if (tt__normalize3(p) > 0.0) {   /* opposite constraints on one face keep the blended one */
            double l = 0.0;
            int j;
            for (j = 0; j < F->opt.nconstraints; j++)
                if (cons[j].face == g) l += tt__length3f(cons[j].vector);
            l /= R->wsum[g];
            for (k = 0; k < 3; k++) o[k] = p[k] * l;
        }
        R->wsum[g] = 0.0;
    }
}

/* Phase 2 (Sec. 3.2, constraints): Gaussian RBFs over Dijkstra distances,
   one pass per constraint, then the blend. Faces it assigns get state 1. */
static tt_result tt__field_constraints(tt__field *F)
{
    const tt_mesh *mesh = F->mesh;
    const tt_allocator *al = F->al;
    tt__field_rbf R;
    tt_result result = TT_OK;
    int nf = F->nf, f, i;
    R.centroid = TT__ALLOC(al, double, 3 * (size_t)nf);
    R.dist = TT__ALLOC(al, double, nf);
    R.trans = TT__ALLOC(al, double, 3 * (size_t)nf);
    R.sum = TT__ALLOC(al, double, 3 * (size_t)nf);
    R.wsum = TT__ALLOC(al, double, nf);
    R.lsum = TT__ALLOC(al, double, nf);
    R.wlog = TT__ALLOC(al, double, nf);
    R.best = TT__ALLOC(al, double, 4 * (size_t)nf);
    R.parent = TT__ALLOC(al, int, nf);
    R.heap = TT__ALLOC(al, tt__heap_item, (size_t)mesh->ncorners + 1);
    if (!R.centroid || !R.dist || !R.trans || !R.sum || !R.wsum || !R.lsum || !R.wlog || !R.best || !R.parent ||
        !R.heap) {
        result = TT_ERROR_OUT_OF_MEMORY;
        goto done;
    }
    for (f = 0; f < nf; f++) {
        tt__face_centroid(mesh, f, R.centroid + 3 * (size_t)f);
        R.sum[3 * (size_t)f] = R.sum[3 * (size_t)f + 1] = R.sum[3 * (size_t)f + 2] = 0.0;
        R.wsum[f] = R.lsum[f] = 0.0;
        R.wlog[f] = -1e300;
        R.best[4 * (size_t)f] = -1e300;
    }
    for (i = 0; i < F->opt.nconstraints; i++) tt__field_dijkstra(F, &R, &F->opt.constraints[i]);
    tt__field_blend(F, &R);

done:
    tt__free(al, R.centroid);
    tt__free(al, R.dist);
    tt__free(al, R.trans);
    tt__free(al, R.sum);
    tt__free(al, R.wsum);
    tt__free(al, R.lsum);
    tt__free(al, R.wlog);
    tt__free(al, R.best);
    tt__free(al, R.parent);
    tt__free(al, R.heap);
    return result;
}

/* How much up decides face f's direction, from |P_f(up)| (|up| = 1): 0
   below TT__FIELD_DECIDES_FROM, 1 above TT__FIELD_DECIDES_AT, smooth in
   between. */
static double tt__field_decided(double projected)
{
    double t = (projected - TT__FIELD_DECIDES_FROM) / (TT__FIELD_DECIDES_AT - TT__FIELD_DECIDES_FROM);
    if (t <= 0.0) return 0.0;
    if (t >= 1.0) return 1.0;
    return t * t * (3.0 - 2.0 * t);
}

/* Face f's vector in its own frame (e1 = first edge, e2 = N x e1) as unit
   coordinates. */
static void tt__field_coordinates(const double *frame, const double *v, double xy[2])
{
    double length;
    xy[0] = tt__dot3(frame, v);
    xy[1] = tt__dot3(frame + 3, v);
    length = sqrt(xy[0] * xy[0] + xy[1] * xy[1]);
    if (length > 0.0) xy[0] /= length, xy[1] /= length;
}

/* Phase 3 (Sec. 3.2 "project the global up direction onto the surface",
   made smooth): every face no constraint reached gets the direction x_f
   (unit coordinates in its frame) minimising
       sum over edges  w_e |R_e x_f - x_g|^2
     + sum over faces  A_f / L^2 (d_f |x_f - u_f|^2 + TIE (1 - d_f) |x_f - s_f|^2),
   with R_e the rotation about the shared edge (parallel transport), w_e =
   |edge| / |centroid f - centroid g| (N_f . N_g)^2, u_f the projected up
   and d_f how much it decides (tt__field_decided), s_f the projected tie
   axis (the world axis least along up) and L the smoothing length: the
   field scale, at most TT__FIELD_SMOOTHING_EDGES mean edge lengths (which
   also bounds the CG steps). Where up decides, the field follows it,
   smoothed over about L; where it does not (a top facing up), the field is
   the smoothest continuation, and where nothing reaches (a flat top cut
   off by creases, whose weight (N_f . N_g)^2 is 0 across a right angle)
   the tie makes it constant. Solved by tt_cg_solve to TT__FIELD_TOLERANCE
   (a direction needs no more); faces with constraints stay fixed. */
static tt_result tt__field_smooth(tt__field *F)
{
    const tt_mesh *mesh = F->mesh;
    const tt_allocator *al = F->al;
    double *frame = NULL, *centroid = NULL, *rhs = NULL, *x = NULL, *weight = NULL, tie[3], mean_edge = 0.0, length;
    tt_triplet *triplets = NULL;
    tt_sparse_matrix *A = NULL;
    tt_cg_options cg;
    tt_result result = TT_OK;
    int *unknown = F->queue, n = 0, ntriplets = 0, f, c, k, least = 0;
    for (f = 0; f < F->nf; f++) unknown[f] = F->state[f] == 0 ? n++ : -1;
    if (n == 0) return TT_OK;
    for (k = 1; k < 3; k++)
        if (fabs(F->up[k]) < fabs(F->up[least])) least = k;
    tie[0] = tie[1] = tie[2] = 0.0;
    tie[least] = 1.0;
    tt__project3(tie, F->up, tie);
    tt__normalize3(tie);
    frame = TT__ALLOC(al, double, 6 * (size_t)F->nf);
    centroid = TT__ALLOC(al, double, 3 * (size_t)F->nf);
    rhs = TT__ALLOC(al, double, 2 * (size_t)n);
    x = TT__ALLOC(al, double, 2 * (size_t)n);
    weight = TT__ALLOC(al, double, n);
    triplets = TT__ALLOC(al, tt_triplet, 2 * (size_t)n + 6 * (size_t)mesh->ncorners);
    if (!frame || !centroid || !rhs || !x || !weight || !triplets) {
        result = TT_ERROR_OUT_OF_MEMORY;
        goto done;
    }
    for (c = 0; c < mesh->ncorners; c++) {
        double edge[3];
        tt__sub3f(mesh->pos + 3 * (size_t)mesh->corner_vert[tt_mesh_next(mesh, c)],
                  mesh->pos + 3 * (size_t)mesh->corner_vert[c], edge);
        mean_edge += tt__length3(edge) / mesh->ncorners;
    }
    length = F->scale < TT__FIELD_SMOOTHING_EDGES * mean_edge ? F->scale : TT__FIELD_SMOOTHING_EDGES * mean_edge;
    for (f = 0; f < F->nf; f++) {
        const int begin = mesh->face_start[f];
        double *e1 = frame + 6 * (size_t)f, *e2 = e1 + 3;
        tt__face_centroid(mesh, f, centroid + 3 * (size_t)f);
        tt__sub3f(mesh->pos + 3 * (size_t)mesh->corner_vert[begin + 1], mesh->pos + 3 * (size_t)mesh->corner_vert[begin],
                  e1);
        tt__project3(e1, F->normal + 3 * (size_t)f, e1);
        if (!(tt__normalize3(e1) > 0.0)) e1[0] = 1.0, e1[1] = e1[2] = 0.0;   /* zero area: never an unknown */
        tt__cross3(F->normal + 3 * (size_t)f, e1, e2);
    }
    for (f = 0; f < n; f++) weight[f] = rhs[2 * f] = rhs[2 * f + 1] = 0.0;
    /* Smoothness, once per edge between faces with a plane. */
    for (c = 0; c < mesh->ncorners; c++) {
        const int t = mesh->twin[c], a = mesh->corner_face[c];
        const double *na = F->normal + 3 * (size_t)a, *ea = frame + 6 * (size_t)a;
        double edge[3], between[3], moved[2][3], R[2][2], w, facing, xa[2], xb[2];
        int b, i, j;
        if (t < 0 || t < c) continue;
        b = mesh->corner_face[t];
        if (F->state[a] < 0 || F->state[b] < 0 || (unknown[a] < 0 && unknown[b] < 0)) continue;
        facing = tt__dot3(na, F->normal + 3 * (size_t)b);
        if (!(facing > 0.0)) continue;
        tt__sub3f(mesh->pos + 3 * (size_t)mesh->corner_vert[tt_mesh_next(mesh, c)],
                  mesh->pos + 3 * (size_t)mesh->corner_vert[c], edge);
        for (k = 0; k < 3; k++) between[k] = centroid[3 * (size_t)a + k] - centroid[3 * (size_t)b + k];
        w = (tt__length3(between) > 0.0 ? tt__length3(edge) / tt__length3(between) : 1.0) * facing * facing;
        /* R: a's frame carried into b's plane, in b's frame (a rotation). */
        tt__field_transport(mesh, c, na, F->normal + 3 * (size_t)b, ea, moved[0]);
        tt__cross3(F->normal + 3 * (size_t)b, moved[0], moved[1]);
        for (i = 0; i < 2; i++)
            for (j = 0; j < 2; j++) R[i][j] = tt__dot3(frame + 6 * (size_t)b + 3 * i, moved[j]);
        if (unknown[a] >= 0 && unknown[b] >= 0) {
            for (i = 0; i < 2; i++)
                for (j = 0; j < 2; j++) {
                    triplets[ntriplets].row = 2 * unknown[b] + i;
                    triplets[ntriplets].col = 2 * unknown[a] + j;
                    triplets[ntriplets++].value = -w * R[i][j];
                    triplets[ntriplets].row = 2 * unknown[a] + j;
                    triplets[ntriplets].col = 2 * unknown[b] + i;
                    triplets[ntriplets++].value = -w * R[i][j];
                }
        } else if (unknown[a] >= 0) {   /* b is fixed (a constraint's): R^T x_b pulls a */
            tt__field_coordinates(frame + 6 * (size_t)b, F->vec + 3 * (size_t)b, xb);
            for (j = 0; j < 2; j++) rhs[2 * unknown[a] + j] += w * (R[0][j] * xb[0] + R[1][j] * xb[1]);
        } else {                        /* a is fixed: R x_a pulls b */
            tt__field_coordinates(frame + 6 * (size_t)a, F->vec + 3 * (size_t)a, xa);
            for (i = 0; i < 2; i++) rhs[2 * unknown[b] + i] += w * (R[i][0] * xa[0] + R[i][1] * xa[1]);
        }
        if (unknown[a] >= 0) weight[unknown[a]] += w;
        if (unknown[b] >= 0) weight[unknown[b]] += w;
    }
    /* Data: toward the projected up as much as it decides, else toward the tie axis; the start is the data. */
    for (f = 0; f < F->nf; f++) {
        const int u = unknown[f];
        const double area = u >= 0 ? tt__face_area_d(mesh, f) : 0.0;
        double p[3], q[3], decided, to_up, to_tie, start[2];
        int i;
        if (u < 0) continue;
        tt__project3(F->up, F->normal + 3 * (size_t)f, p);
        decided = tt__field_decided(tt__normalize3(p));
        tt__project3(tie, F->normal + 3 * (size_t)f, q);
        if (!(tt__normalize3(q) > 1e-6)) q[0] = q[1] = q[2] = 0.0;   /* then up decides fully */
        to_up = decided * area / (length * length);
        to_tie = TT__FIELD_TIE * (1.0 - decided) * area / (length * length);
        for (i = 0; i < 2; i++) {
            const double *e = frame + 6 * (size_t)f + 3 * i;
            triplets[ntriplets].row = triplets[ntriplets].col = 2 * u + i;
            triplets[ntriplets++].value = weight[u] + to_up + to_tie;
            rhs[2 * u + i] += to_up * tt__dot3(e, p) + to_tie * tt__dot3(e, q);
            start[i] = decided * tt__dot3(e, p) + (1.0 - decided) * tt__dot3(e, q);
        }
        x[2 * u] = start[0];
        x[2 * u + 1] = start[1];
    }
    if ((result = tt_sparse_from_triplets(2 * n, 2 * n, triplets, ntriplets, al, &A, NULL)) != TT_OK) goto done;
    memset(&cg, 0, sizeof cg);
    cg.tolerance = TT__FIELD_TOLERANCE;
    result = tt_cg_solve(A, rhs, &cg, al, x, NULL, NULL);
    if (result == TT_ERROR_NOT_CONVERGED) result = TT_OK;   /* the last iterate is as smooth a field */
    if (result != TT_OK) goto done;
    for (f = 0; f < F->nf; f++) {
        const int u = unknown[f];
        const double *e1 = frame + 6 * (size_t)f, *e2 = e1 + 3;
        double *o = F->vec + 3 * (size_t)f;
        if (u < 0) continue;
        for (k = 0; k < 3; k++) o[k] = x[2 * u] * e1[k] + x[2 * u + 1] * e2[k];
        if (!(tt__normalize3(o) > 0.0))
            for (k = 0; k < 3; k++) o[k] = e1[k];
        for (k = 0; k < 3; k++) o[k] *= F->scale;
        F->state[f] = 1;
    }
done:
    tt_sparse_matrix_free(A);
    tt__free(al, frame);
    tt__free(al, centroid);
    tt__free(al, rhs);
    tt__free(al, x);
    tt__free(al, weight);
    tt__free(al, triplets);
    return result;
}

TTDEF tt_result tt_tangent_field(const tt_mesh *mesh, const tt_field_options *options,
                                 const tt_allocator *allocator, float *face_vectors, tt_error *error)
{
    tt__field F;
    tt_result result;
    int f;

    if (!mesh || !face_vectors)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "tt_tangent_field needs a mesh and an output array (got NULL)");
    if ((result = tt__field_setup(&F, mesh, options, allocator, error)) != TT_OK) return result;
    if (F.nf <= 0) return tt__ok(error);

    F.normal = TT__ALLOC(F.al, double, 3 * (size_t)F.nf);
    F.vec = TT__ALLOC(F.al, double, 3 * (size_t)F.nf);
    F.state = TT__ALLOC(F.al, int, F.nf);
    F.queue = TT__ALLOC(F.al, int, F.nf);
    if (!F.normal || !F.vec || !F.state || !F.queue) { result = TT_ERROR_OUT_OF_MEMORY; goto done; }
    for (f = 0; f < F.nf; f++) {
        F.state[f] = tt__face_normal_d(mesh, f, F.normal + 3 * (size_t)f) ? 0 : -1;
        F.vec[3 * (size_t)f] = F.vec[3 * (size_t)f + 1] = F.vec[3 * (size_t)f + 2] = 0.0;
    }

    /* Constraints first (they decide every face they reach), then the
       default rule, then propagation into what is left. */
    if ((result = tt__field_check_constraints(&F, error)) != TT_OK) goto done;
    if (F.opt.nconstraints > 0 && (result = tt__field_constraints(&F)) != TT_OK) goto done;
    if ((result = tt__field_smooth(&F)) != TT_OK) goto done;

    for (f = 0; f < 3 * F.nf; f++) face_vectors[f] = (float)F.vec[f];
    result = tt__ok(error);

done:
    if (result == TT_ERROR_OUT_OF_MEMORY)
        tt__fail(error, TT_ERROR_OUT_OF_MEMORY, -1, -1, -1, -1, "out of memory building the tangent field");
    tt__free(F.al, F.normal);
    tt__free(F.al, F.vec);
    tt__free(F.al, F.state);
    tt__free(F.al, F.queue);
    return result;
}

/* ---- Texture patches (Praun et al. Sec. 3.1) ---------------------------- */

/* Exact 1D squared distance transform of f[0..n-1] (Felzenszwalb and
   Huttenlocher, "Distance Transforms of Sampled Functions"): d[q] = min_p
   (q - p)^2 + f[p]. v gets n ints, z n + 1 floats of scratch. */
static void tt__edt_1d(const float *f, int n, float *d, int *v, float *z, float big)
{
    int k = 0, q;
    v[0] = 0;
    z[0] = -big;
    z[1] = big;
    for (q = 1; q < n; q++) {
        float s;
        for (;;) {
            int p = v[k];
            s = ((f[q] + (float)q * (float)q) - (f[p] + (float)p * (float)p)) / (2.0f * (float)(q - p));
            if (s <= z[k] && k > 0) { k--; continue; }
            break;
        }
        if (s <= z[k]) {   /* k == 0 and the new parabola is lower everywhere */
            v[0] = q;
            z[0] = -big;
            z[1] = big;
            continue;
        }
        k++;
        v[k] = q;
        z[k] = s;
        z[k + 1] = big;
    }
    k = 0;
    for (q = 0; q < n; q++) {
        float dq;
        while (z[k + 1] < (float)q) k++;
        dq = (float)(q - v[k]);
        d[q] = dq * dq + f[v[k]];
    }
}

/* Exact squared Euclidean distance transform of a gw x gh grid, in place:
   cells holding 0 are the sites, cells holding `big` get the squared distance
   (in cells) to the nearest site. Separable: columns, then rows. Scratch:
   line and dline of max(gw, gh) floats, v of as many ints, z of one more
   float. */
static void tt__distance_transform(float *grid, int gw, int gh, float *line, float *dline, int *v, float *z,
                                   float big)
{
    int x, y;
    for (x = 0; x < gw; x++) {
        for (y = 0; y < gh; y++) line[y] = grid[(size_t)y * (size_t)gw + (size_t)x];
        tt__edt_1d(line, gh, dline, v, z, big);
        for (y = 0; y < gh; y++) grid[(size_t)y * (size_t)gw + (size_t)x] = dline[y];
    }
    for (y = 0; y < gh; y++) {
        float *row = grid + (size_t)y * (size_t)gw;
        memcpy(line, row, sizeof(float) * (size_t)gw);
        tt__edt_1d(line, gw, row, v, z, big);
    }
}

/* Shape from an image (Sec. 3.1, a patch cut by a mask): grid cell (x+1,
   y+1) becomes `big` where the source's alpha (source_alpha), the mask's
   alpha (mask_alpha) or else the mask's grey value is >= 0.5. Returns how
   many texels are inside. */
static int tt__patch_mask_shape(const tt_image *src_image, int source_alpha, int mask_alpha, float big,
                                float *grid, int gw)
{
    const float *src = src_image->pixels;
    int w = src_image->width, h = src_image->height, x, y, inside = 0;
    for (y = 0; y < h; y++)
        for (x = 0; x < w; x++) {
            const float *p = src + 4 * ((size_t)y * (size_t)w + (size_t)x);
            float value = (source_alpha || mask_alpha) ? p[3] : (p[0] + p[1] + p[2]) * (1.0f / 3.0f);
            if (value >= 0.5f) {
                grid[(size_t)(y + 1) * (size_t)gw + (size_t)(x + 1)] = big;
                inside++;
            }
        }
    return inside;
}

/* The seeded splotch (Sec. 3.1: for homogeneous textures, a predefined
   irregular "splotch" shape): q = rho / (1 + g(theta)) where rho <= 1
   (inside the rounded-square base shape shrunk by the margin), else
   infinite; inside <=> q <= s, with s found by bisection so that the shape
   covers TT_PATCH_SPLOTCH_COVERAGE of the w x h image. Inside cells of grid
   (padded by one, gw wide) become `big`; *inside counts them. q is w * h
   floats of scratch. */
static void tt__patch_splotch(int w, int h, uint64_t seed, float roughness, float falloff, float big, float *grid,
                              int gw, float *q, int *inside)
{
    size_t count = (size_t)w * (size_t)h, i;
    tt_rng rng;
    float c[4], phi[4], csum = 0.0f, lo, hi, ax, ay, margin = falloff > 1.0f ? falloff : 1.0f;
    long target = (long)((double)TT_PATCH_SPLOTCH_COVERAGE * (double)count + 0.5);
    int k, it, x, y;
    *inside = 0;
    tt_rng_seed(&rng, seed, 0x7061746368ull);   /* "patch" */
    for (k = 0; k < 4; k++) {
        c[k] = (0.5f + 0.5f * tt_rng_float(&rng)) / (float)(k + 2);
        phi[k] = (float)TT__TWO_PI * tt_rng_float(&rng);
        csum += c[k];
    }
    for (k = 0; k < 4; k++) c[k] *= roughness / csum;
    ax = 0.5f * (float)w - margin;
    ay = 0.5f * (float)h - margin;
    for (y = 0; y < h; y++)
        for (x = 0; x < w; x++) {
            float dx = ((float)x + 0.5f - 0.5f * (float)w) / ax, dy = ((float)y + 0.5f - 0.5f * (float)h) / ay;
            float dx2 = dx * dx, dy2 = dy * dy, rho = sqrtf(sqrtf(dx2 * dx2 + dy2 * dy2));
            float theta = atan2f(dy, dx), g = 1.0f;
            for (k = 0; k < 4; k++) g += c[k] * cosf((float)(k + 2) * theta + phi[k]);
            q[(size_t)y * (size_t)w + (size_t)x] = rho <= 1.0f ? rho / g : big;
        }
    lo = 0.0f;
    hi = 1.0f / (1.0f - roughness) + 1.0f;
    for (it = 0; it < 40; it++) {
        float mid = 0.5f * (lo + hi);
        long covered = 0;
        for (i = 0; i < count; i++) covered += q[i] <= mid;
        if (covered < target) lo = mid;
        else hi = mid;
    }
    for (y = 0; y < h; y++)
        for (x = 0; x < w; x++)
            if (q[(size_t)y * (size_t)w + (size_t)x] <= hi) {
                grid[(size_t)(y + 1) * (size_t)gw + (size_t)(x + 1)] = big;
                (*inside)++;
            }
}

/* The soft falloff (Sec. 3.1: alpha "falls off near the patch boundary"):
   the exact Euclidean distance transform of the padded grid (0 outside the
   shape, `big` inside), then each inside texel's distance to the shape's
   edge, d - 0.5, in place. Fails when no texel is `falloff` deep. */
static tt_result tt__patch_soft_edge(float *grid, int gw, int gh, float *line, float *dline, int *v, float *z,
                                     float big, float falloff, tt_error *error)
{
    float deepest = 0.0f;
    int x, y;
    tt__distance_transform(grid, gw, gh, line, dline, v, z, big);
    for (y = 1; y < gh - 1; y++)
        for (x = 1; x < gw - 1; x++) {
            float d = sqrtf(grid[(size_t)y * (size_t)gw + (size_t)x]) - 0.5f;
            grid[(size_t)y * (size_t)gw + (size_t)x] = d;
            if (d > deepest) deepest = d;
        }
    if (deepest < falloff)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "falloff %g leaves no opaque texel: the shape is at most %g texels deep", (double)falloff,
                        (double)deepest);
    return TT_OK;
}

TTDEF tt_result tt_make_texture_patch(const tt_image *source, const tt_image *mask, const tt_patch_options *options,
                                      const tt_allocator *allocator, tt_image **out_patch, tt_error *error)
{
    const float big = 1e30f;
    tt_patch_options opt;
    const tt_allocator *al = allocator;
    tt_image *patch = NULL;
    tt_result result = TT_OK;
    float *grid = NULL, *line = NULL, *dline = NULL, *z = NULL, *alpha;
    int *v = NULL;
    int w, h, gw, gh, x, y, n, inside = 0, source_alpha = 0, mask_alpha = 0, in_place = 0;
    size_t count, i;
    float falloff, roughness;

    tt__ok(error);
    if (!out_patch) return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1, "out_patch is NULL");
    *out_patch = NULL;
    if (tt__check_allocator(allocator, error) != TT_OK) return TT_ERROR_INVALID_ARGUMENT;
    if (!source || !source->pixels || source->width <= 0 || source->height <= 0)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1, "the source image is NULL or empty");
    w = source->width;
    h = source->height;
    if (w > TT_MAX_IMAGE_SIZE || h > TT_MAX_IMAGE_SIZE)
        return tt__fail(error, TT_ERROR_TOO_LARGE, -1, -1, -1, -1, "the source is %d x %d texels, above %d", w, h,
                        TT_MAX_IMAGE_SIZE);
    if (mask && (!mask->pixels || mask->width != w || mask->height != h))
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "the mask is %d x %d texels but the source is %d x %d", mask->pixels ? mask->width : 0,
                        mask->pixels ? mask->height : 0, w, h);
    if (options) opt = *options;
    else memset(&opt, 0, sizeof opt);
    if (!tt__is_finite(opt.falloff) || !tt__is_finite(opt.roughness))
        return tt__fail(error, TT_ERROR_NON_FINITE, -1, -1, -1, -1, "options: falloff %g or roughness %g is not finite",
                        (double)opt.falloff, (double)opt.roughness);
    if (opt.falloff < 0.0f)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1, "options: falloff %g is negative",
                        (double)opt.falloff);
    if (opt.roughness < 0.0f || opt.roughness >= 1.0f)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1, "options: roughness %g is outside [0, 1)",
                        (double)opt.roughness);
    falloff = opt.falloff > 0.0f ? opt.falloff : TT_DEFAULT_PATCH_FALLOFF;
    roughness = opt.roughness > 0.0f ? opt.roughness : TT_DEFAULT_PATCH_ROUGHNESS;
    count = (size_t)w * (size_t)h;

    /* Which shape: source alpha, mask alpha, mask grey, or the splotch. */
    for (i = 0; i < count * 4; i++) {
        if (!tt__is_finite(source->pixels[i]))
            return tt__fail_at(error, TT_ERROR_NON_FINITE, -1, (int)((i / 4) / (size_t)w), (int)((i / 4) % (size_t)w),
                               "source texel (%d, %d) is not finite", (int)((i / 4) % (size_t)w),
                               (int)((i / 4) / (size_t)w));
        if ((i & 3) == 3 && source->pixels[i] < 1.0f) source_alpha = 1;
    }
    if (!source_alpha && mask) {
        for (i = 0; i < count * 4; i++) {
            if (!tt__is_finite(mask->pixels[i]))
                return tt__fail_at(error, TT_ERROR_NON_FINITE, -1, (int)((i / 4) / (size_t)w),
                                   (int)((i / 4) % (size_t)w), "mask texel (%d, %d) is not finite",
                                   (int)((i / 4) % (size_t)w), (int)((i / 4) / (size_t)w));
            if ((i & 3) == 3 && mask->pixels[i] < 1.0f) mask_alpha = 1;
        }
    }
    if (!source_alpha && !mask) {
        /* The splotch needs a margin of max(falloff, 1) texels on every side. */
        float margin = falloff > 1.0f ? falloff : 1.0f;
        if (2.0f * margin + 2.0f >= (float)(w < h ? w : h))
            return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                            "falloff %g leaves no room for a splotch in a %d x %d image", (double)falloff, w, h);
    }

    /* The patch's own pixels (4 floats a texel) are the scratch space: the
       padded distance grid, (w + 2)(h + 2) floats, at their start, the
       splotch's w * h values after it, and at the end (from 3 w h on) the
       alpha plane, read back as the colours are written from the start. So a
       patch costs its 16 bytes a texel and nothing more per texel (w, h >= 4
       keep the three apart; smaller images get a scratch grid of their own). */
    gw = w + 2;
    gh = h + 2;
    n = (gw > gh ? gw : gh);
    if ((result = tt_image_create(w, h, al, &patch, error)) != TT_OK) return result;
    in_place = (size_t)gw * (size_t)gh + count <= 3 * count;
    grid = in_place ? patch->pixels : TT__ALLOC(al, float, (size_t)gw * (size_t)gh + count);
    line = TT__ALLOC(al, float, n);
    dline = TT__ALLOC(al, float, n);
    z = TT__ALLOC(al, float, n + 1);
    v = TT__ALLOC(al, int, n);
    if (!grid || !line || !dline || !z || !v) {
        result = tt__fail(error, TT_ERROR_OUT_OF_MEMORY, -1, -1, -1, -1, "out of memory making a %d x %d texture patch",
                          w, h);
        goto done;
    }

    /* grid: 0 outside the shape (and on the one-texel frame around the image), big inside. */
    for (i = 0; i < (size_t)gw * (size_t)gh; i++) grid[i] = 0.0f;
    if (source_alpha || mask) {
        inside = tt__patch_mask_shape(source_alpha ? source : mask, source_alpha, mask_alpha, big, grid, gw);
        if (inside == 0) {
            result = tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                              "the mask has no opaque pixel (no %s value >= 0.5)",
                              source_alpha ? "source alpha" : (mask_alpha ? "mask alpha" : "mask grey"));
            goto done;
        }
    } else {
        tt__patch_splotch(w, h, opt.seed, roughness, falloff, big, grid, gw, grid + (size_t)gw * (size_t)gh, &inside);
        if (inside == 0) {   /* not reachable with the margin check above; kept for safety */
            result = tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1, "the mask has no opaque pixel");
            goto done;
        }
    }

    if ((result = tt__patch_soft_edge(grid, gw, gh, line, dline, v, z, big, falloff, error)) != TT_OK) goto done;

    /* The alpha plane first (it lies beyond the grid), then the colours from
       the start: texel `at` is written after its alpha is read, and never
       over an alpha still to be read (3 w h + at' >= 4 at + 4 for at' > at). */
    alpha = patch->pixels + 3 * count;
    for (y = 0; y < h; y++)
        for (x = 0; x < w; x++)
            alpha[(size_t)y * (size_t)w + (size_t)x] =
                tt__clamp_f(grid[(size_t)(y + 1) * (size_t)gw + (size_t)(x + 1)] / falloff, 0.0f, 1.0f);
    for (i = 0; i < count; i++) {
        float a = alpha[i];
        const float *src = source->pixels + 4 * i;
        float *o = patch->pixels + 4 * i;
        o[0] = src[0] * a;
        o[1] = src[1] * a;
        o[2] = src[2] * a;
        o[3] = a;
    }
    *out_patch = patch;
    patch = NULL;
    result = tt__ok(error);

done:
    if (!in_place) tt__free(al, grid);
    tt_image_free(patch);
    tt__free(al, line);
    tt__free(al, dline);
    tt__free(al, z);
    tt__free(al, v);
    return result;
}

/* Conservative polygonal hull of a texture patch (Sec. 3.3, Fig. 4).

   Growth (Sec. 3.3) crosses a mesh edge only while the edge's image still
   meets the texture patch; the paper answers that with a polygon that
   contains the patch. Choice made here:
     1. the outer contour of the union of the texel squares with alpha > 0.
        Holes are filled (conservative), and where two texels touch only at a
        corner with outside on both other sides (a "pinch", which would make
        the contour touch itself) one of the two outside texels is filled too,
        so the contour is a simple polygon through texel corners;
     2. that polygon simplified by the 2D progressive-hull operations of
        Fig. 4 (Sander et al.'s conservative edge collapses): removing a
        reflex or straight vertex (its triangle is outside the polygon), or
        collapsing an edge between two convex vertices into the intersection
        of the lines of its two neighbouring edges. Each only adds area, the
        smallest addition first, and one that would bring a new edge within
        a small clearance of another edge is refused, so the polygon stays
        simple even after rounding to float;
     3. if the filled mask still has several components, or the operations
        cannot get down to max_vertices, the convex hull of all nonzero texel
        corners simplified the same way (for a convex polygon only the edge
        collapse applies); if even that stalls (a parallelogram cannot lose a
        vertex that way), the bounding rectangle, or a triangle around it.
   Coordinates inside are texel units of the image padded by one transparent
   texel on every side, y up: texel (i, j) is the square [i+1, i+2] x
   [h-j, h-j+1], so the unit-square point is ((x - 1) / w, (y - 1) / h). */

enum { TT__HULL_DEAD = 0, TT__HULL_LIVE = 1, TT__HULL_BLOCKED = 2 };
enum { TT__HULL_REMOVE = 1, TT__HULL_COLLAPSE = 2 };
enum { TT__CELL_EMPTY = 0, TT__CELL_FULL = 1, TT__CELL_OUTSIDE = 2 };

/* Filling a pinch can close a new hole or make a new pinch; this many rounds
   of (flood the outside, fill pinches) settle every shape met in practice,
   and a shape that does not settle gets the convex hull instead. */
#define TT__HULL_PINCH_ROUNDS 16
/* A refused operation can become possible after operations elsewhere moved
   the edge in its way; the queue is rebuilt at most this many times. */
#define TT__HULL_ROUNDS 8

/* One entry of the grid of edges that makes the simplicity test local. */
typedef struct tt__hull_node {
    int vertex;     /* the edge from this vertex to its successor */
    int stamp;      /* that vertex's edge stamp when the entry was made */
    int next;       /* next entry in the same cell, -1 at the end */
} tt__hull_node;

typedef struct tt__hull {
    const tt_allocator *allocator;
    int n;                  /* vertex slots */
    int count;              /* live vertices */
    double *x, *y;
    int *next, *prev;
    int *stamp;             /* changes whenever the edge leaving the vertex changes */
    double *key;            /* area of the operation last queued for the vertex */
    unsigned char *state;   /* TT__HULL_DEAD / LIVE / BLOCKED */
    tt__heap_item *heap;
    int heap_count, heap_cap;
    int gx, gy;             /* grid of edges: gx * gy cells of side 1 / inv_cell */
    double inv_cell;
    int *cell_head;
    tt__hull_node *nodes;
    int node_count, node_cap, node_free;
    double eps;             /* clearance kept between edges that do not share a vertex */
    double lo[2], hi[2];    /* box in which a new vertex may be placed */
} tt__hull;

typedef struct tt__hull_op {
    int kind;               /* TT__HULL_REMOVE or TT__HULL_COLLAPSE */
    double area;            /* area it adds to the polygon */
    double vx, vy;          /* collapse: the new vertex */
} tt__hull_op;

/* 1 when segments a-b and c-d come closer than eps (crossing counts). */
static int tt__segments_near(double ax, double ay, double bx, double by, double cx, double cy, double dx,
                             double dy, double eps)
{
    double o1 = tt__orient2(ax, ay, bx, by, cx, cy), o2 = tt__orient2(ax, ay, bx, by, dx, dy);
    double o3 = tt__orient2(cx, cy, dx, dy, ax, ay), o4 = tt__orient2(cx, cy, dx, dy, bx, by);
    if (((o1 > 0.0 && o2 < 0.0) || (o1 < 0.0 && o2 > 0.0)) && ((o3 > 0.0 && o4 < 0.0) || (o3 < 0.0 && o4 > 0.0)))
        return 1;
    return tt__point_segment_distance(cx, cy, ax, ay, bx, by) < eps ||
           tt__point_segment_distance(dx, dy, ax, ay, bx, by) < eps ||
           tt__point_segment_distance(ax, ay, cx, cy, dx, dy) < eps ||
           tt__point_segment_distance(bx, by, cx, cy, dx, dy) < eps;
}

static void tt__hull_free(tt__hull *h)
{
    tt__free(h->allocator, h->x);
    tt__free(h->allocator, h->y);
    tt__free(h->allocator, h->next);
    tt__free(h->allocator, h->prev);
    tt__free(h->allocator, h->stamp);
    tt__free(h->allocator, h->key);
    tt__free(h->allocator, h->state);
    tt__free(h->allocator, h->heap);
    tt__free(h->allocator, h->cell_head);
    tt__free(h->allocator, h->nodes);
    memset(h, 0, sizeof *h);
}

/* Cells overlapped by the box [x0, x1] x [y0, y1]; outside the grid clamps
   to its border cells, which is still a superset. */
static void tt__hull_cells(const tt__hull *h, double x0, double y0, double x1, double y1, int range[4])
{
    double bound = (double)(h->gx > h->gy ? h->gx : h->gy) + 1.0;
    double c[4];
    int k;
    c[0] = floor(x0 * h->inv_cell); c[1] = floor(y0 * h->inv_cell);
    c[2] = floor(x1 * h->inv_cell); c[3] = floor(y1 * h->inv_cell);
    for (k = 0; k < 4; k++) {
        double v = c[k] < -1.0 ? -1.0 : (c[k] > bound ? bound : c[k]);
        range[k] = tt__clamp_i((int)v, 0, (k & 1) ? h->gy - 1 : h->gx - 1);
    }
}

/* Record the edge leaving u in every cell its box overlaps; older entries
   for u go stale through the stamp and are dropped when next met. */
static tt_result tt__hull_insert_edge(tt__hull *h, int u)
{
    int w = h->next[u], range[4], cx, cy;
    h->stamp[u]++;
    tt__hull_cells(h, h->x[u] < h->x[w] ? h->x[u] : h->x[w], h->y[u] < h->y[w] ? h->y[u] : h->y[w],
                   h->x[u] > h->x[w] ? h->x[u] : h->x[w], h->y[u] > h->y[w] ? h->y[u] : h->y[w], range);
    for (cy = range[1]; cy <= range[3]; cy++) {
        for (cx = range[0]; cx <= range[2]; cx++) {
            int cell = cy * h->gx + cx, k;
            if (h->node_free >= 0) {
                k = h->node_free;
                h->node_free = h->nodes[k].next;
            } else {
                if (h->node_count == h->node_cap) {
                    void *grown = tt__grow(h->allocator, h->nodes, &h->node_cap, h->node_count + 1, sizeof *h->nodes);
                    if (!grown) return TT_ERROR_OUT_OF_MEMORY;
                    h->nodes = (tt__hull_node *)grown;
                }
                k = h->node_count++;
            }
            h->nodes[k].vertex = u;
            h->nodes[k].stamp = h->stamp[u];
            h->nodes[k].next = h->cell_head[cell];
            h->cell_head[cell] = k;
        }
    }
    return TT_OK;
}

/* The n-gon (xs, ys), counter-clockwise and simple, ready to simplify;
   width x height is the padded image in texel units (grid and box). */
static tt_result tt__hull_init(tt__hull *h, const double *xs, const double *ys, int n, int width, int height,
                               const tt_allocator *allocator)
{
    double side = (double)tt__max_i(width, height), cell;
    int v, c;
    tt_result result;
    memset(h, 0, sizeof *h);
    h->allocator = allocator;
    h->n = h->count = n;
    /* Cells about as many as vertices, so a short new edge meets O(1) others. */
    cell = sqrt((double)width * (double)height / (double)n);
    if (cell < 1.0) cell = 1.0;
    h->gx = tt__clamp_i((int)((double)width / cell) + 1, 1, 1024);
    h->gy = tt__clamp_i((int)((double)height / cell) + 1, 1, 1024);
    h->inv_cell = 1.0 / cell;
    h->heap_cap = 7 * n + 8;
    h->node_cap = 4 * n + 64;
    h->node_free = -1;
    h->x = TT__ALLOC(allocator, double, n);
    h->y = TT__ALLOC(allocator, double, n);
    h->next = TT__ALLOC(allocator, int, n);
    h->prev = TT__ALLOC(allocator, int, n);
    h->stamp = TT__ALLOC(allocator, int, n);
    h->key = TT__ALLOC(allocator, double, n);
    h->state = TT__ALLOC(allocator, unsigned char, n);
    h->heap = TT__ALLOC(allocator, tt__heap_item, h->heap_cap);
    h->cell_head = TT__ALLOC(allocator, int, h->gx * h->gy);
    h->nodes = TT__ALLOC(allocator, tt__hull_node, h->node_cap);
    if (!h->x || !h->y || !h->next || !h->prev || !h->stamp || !h->key || !h->state || !h->heap || !h->cell_head ||
        !h->nodes) {
        tt__hull_free(h);
        return TT_ERROR_OUT_OF_MEMORY;
    }
    /* 1e-5 of the patch side: far above float rounding of unit-square
       coordinates, far below a texel for any allowed image size. */
    h->eps = 1e-5 * side;
    h->lo[0] = -side; h->lo[1] = -side;
    h->hi[0] = (double)width + side; h->hi[1] = (double)height + side;
    for (c = 0; c < h->gx * h->gy; c++) h->cell_head[c] = -1;
    for (v = 0; v < n; v++) {
        h->x[v] = xs[v];
        h->y[v] = ys[v];
        h->next[v] = v + 1 < n ? v + 1 : 0;
        h->prev[v] = v > 0 ? v - 1 : n - 1;
        h->stamp[v] = 0;
        h->key[v] = 0.0;
        h->state[v] = TT__HULL_LIVE;
    }
    for (v = 0; v < n; v++) {
        if ((result = tt__hull_insert_edge(h, v)) != TT_OK) {
            tt__hull_free(h);
            return result;
        }
    }
    return TT_OK;
}

/* The cheapest conservative operation owned by vertex v (Fig. 4): removing v
   when it is reflex or straight (the triangle prev-v-next lies outside), or,
   when v and its successor q are both convex, moving v to where the lines of
   the edges before v and after q meet and dropping q. */
static int tt__hull_candidate(const tt__hull *h, int v, tt__hull_op *op)
{
    int p = h->prev[v], q = h->next[v], r = h->next[q];
    double turn_v = tt__orient2(h->x[p], h->y[p], h->x[v], h->y[v], h->x[q], h->y[q]);
    double d1x, d1y, d2x, d2y, ex, ey, den, t, s, vx, vy;
    if (h->count <= 3) return 0;
    if (turn_v <= 0.0) {
        op->kind = TT__HULL_REMOVE;
        op->area = -0.5 * turn_v;
        op->vx = op->vy = 0.0;
        return 1;
    }
    if (tt__orient2(h->x[v], h->y[v], h->x[q], h->y[q], h->x[r], h->y[r]) <= 0.0) return 0;
    d1x = h->x[v] - h->x[p]; d1y = h->y[v] - h->y[p];
    d2x = h->x[q] - h->x[r]; d2y = h->y[q] - h->y[r];
    ex = h->x[q] - h->x[v]; ey = h->y[q] - h->y[v];
    den = d1x * d2y - d1y * d2x;
    if (den == 0.0) return 0;
    t = (ex * d2y - ey * d2x) / den;
    s = (ex * d1y - ey * d1x) / den;
    if (!(t > 0.0) || !(s > 0.0)) return 0;
    vx = h->x[v] + t * d1x;
    vy = h->y[v] + t * d1y;
    /* Nearly parallel lines meet far away: such a vertex would add more area
       than any useful operation, and would cost precision. */
    if (!(vx >= h->lo[0] && vx <= h->hi[0] && vy >= h->lo[1] && vy <= h->hi[1])) return 0;
    /* The new vertex must lie right of v-q, outside the polygon. */
    if (!(tt__orient2(h->x[v], h->y[v], h->x[q], h->y[q], vx, vy) < 0.0)) return 0;
    op->kind = TT__HULL_COLLAPSE;
    op->area = -0.5 * tt__orient2(h->x[v], h->y[v], h->x[q], h->y[q], vx, vy);
    op->vx = vx;
    op->vy = vy;
    return 1;
}

/* 1 when the new edge a-b (between vertices ia and ib) keeps the clearance
   from every edge not leaving a vertex in skip; edges sharing ia or ib must
   merely not fold back onto it. Stale grid entries are unlinked on the way. */
static int tt__hull_clear(tt__hull *h, double ax, double ay, double bx, double by, int ia, int ib, const int *skip,
                          int nskip)
{
    int range[4], cx, cy;
    tt__hull_cells(h, (ax < bx ? ax : bx) - h->eps, (ay < by ? ay : by) - h->eps, (ax > bx ? ax : bx) + h->eps,
                   (ay > by ? ay : by) + h->eps, range);
    for (cy = range[1]; cy <= range[3]; cy++) {
        for (cx = range[0]; cx <= range[2]; cx++) {
            int *link = &h->cell_head[cy * h->gx + cx];
            while (*link >= 0) {
                int k = *link, u = h->nodes[k].vertex, w, s, skipped = 0;
                if (h->state[u] == TT__HULL_DEAD || h->nodes[k].stamp != h->stamp[u]) {
                    *link = h->nodes[k].next;
                    h->nodes[k].next = h->node_free;
                    h->node_free = k;
                    continue;
                }
                link = &h->nodes[k].next;
                for (s = 0; s < nskip; s++) skipped |= skip[s] == u;
                if (skipped) continue;
                w = h->next[u];
                if (u == ia || w == ia || u == ib || w == ib) {
                    int shared_a = u == ia || w == ia, e = (u == ia || u == ib) ? w : u;
                    double ox = shared_a ? bx : ax, oy = shared_a ? by : ay;
                    double sx = shared_a ? ax : bx, sy = shared_a ? ay : by;
                    if (tt__point_segment_distance(h->x[e], h->y[e], ax, ay, bx, by) < h->eps ||
                        tt__point_segment_distance(ox, oy, sx, sy, h->x[e], h->y[e]) < h->eps)
                        return 0;
                } else if (tt__segments_near(ax, ay, bx, by, h->x[u], h->y[u], h->x[w], h->y[w], h->eps)) {
                    return 0;
                }
            }
        }
    }
    return 1;
}

/* Simplicity (Sec. 3.3: "operations that would give rise to
   self-intersections are disallowed"): only the new edges need testing. */
static int tt__hull_valid(tt__hull *h, int v, const tt__hull_op *op)
{
    int p = h->prev[v], q = h->next[v], skip[3];
    skip[0] = p;
    skip[1] = v;
    skip[2] = q;
    if (op->kind == TT__HULL_REMOVE) return tt__hull_clear(h, h->x[p], h->y[p], h->x[q], h->y[q], p, q, skip, 2);
    return tt__hull_clear(h, h->x[p], h->y[p], op->vx, op->vy, p, v, skip, 3) &&
           tt__hull_clear(h, op->vx, op->vy, h->x[h->next[q]], h->y[h->next[q]], v, h->next[q], skip, 3);
}

static void tt__hull_evaluate(tt__hull *h, int v)
{
    tt__hull_op op;
    h->state[v] = TT__HULL_LIVE;
    if (h->heap_count < h->heap_cap && tt__hull_candidate(h, v, &op)) {
        h->key[v] = op.area;
        tt__heap_push(h->heap, &h->heap_count, op.area, v);
    }
}

static tt_result tt__hull_apply(tt__hull *h, int v, const tt__hull_op *op)
{
    int p = h->prev[v], q = h->next[v], touched[6], k;
    tt_result result;
    if (op->kind == TT__HULL_REMOVE) {
        h->next[p] = q;
        h->prev[q] = p;
        h->state[v] = TT__HULL_DEAD;
        h->count--;
        if ((result = tt__hull_insert_edge(h, p)) != TT_OK) return result;
        touched[2] = p;
        touched[3] = q;
    } else {
        int r = h->next[q];
        h->x[v] = op->vx;
        h->y[v] = op->vy;
        h->next[v] = r;
        h->prev[r] = v;
        h->state[q] = TT__HULL_DEAD;
        h->count--;
        if ((result = tt__hull_insert_edge(h, p)) != TT_OK) return result;
        if ((result = tt__hull_insert_edge(h, v)) != TT_OK) return result;
        touched[2] = p;
        touched[3] = v;
    }
    /* Every vertex whose operation reads a moved vertex or a changed edge. */
    touched[1] = h->prev[touched[2]];
    touched[0] = h->prev[touched[1]];
    touched[4] = h->next[touched[3]];
    touched[5] = h->next[touched[4]];
    for (k = 0; k < 6; k++) tt__hull_evaluate(h, touched[k]);
    return TT_OK;
}

/* Smallest added area first (Sec. 3.3), until max_vertices remain or no
   operation is allowed. Each round queues at most n + 6 * (operations done)
   entries, within heap_cap. */
static tt_result tt__hull_simplify(tt__hull *h, int max_vertices)
{
    int round, v;
    for (round = 0; round < TT__HULL_ROUNDS && h->count > max_vertices; round++) {
        int done = 0;
        h->heap_count = 0;
        for (v = 0; v < h->n; v++)
            if (h->state[v] != TT__HULL_DEAD) tt__hull_evaluate(h, v);
        while (h->count > max_vertices && h->heap_count > 0) {
            tt__heap_item item = tt__heap_pop(h->heap, &h->heap_count);
            tt__hull_op op;
            tt_result result;
            v = item.value;
            if (h->state[v] != TT__HULL_LIVE || h->key[v] != item.key || !tt__hull_candidate(h, v, &op)) continue;
            if (!tt__hull_valid(h, v, &op)) {
                h->state[v] = TT__HULL_BLOCKED;
                continue;
            }
            if ((result = tt__hull_apply(h, v, &op)) != TT_OK) return result;
            done++;
        }
        if (!done) break;
    }
    return TT_OK;
}

/* n points (texel units, padded) to the caller's unit-square floats, in
   index order, or along `next` from `start` when next is not NULL. */
static tt_result tt__hull_emit(const double *xs, const double *ys, const int *next, int start, int n, int w, int h,
                               const tt_allocator *allocator, float **out_xy, int *out_count)
{
    float *xy = TT__ALLOC(allocator, float, 2 * n);
    int k, v = start;
    if (!xy) return TT_ERROR_OUT_OF_MEMORY;
    for (k = 0; k < n; k++) {
        if (!next) v = k;
        xy[2 * k] = (float)((xs[v] - 1.0) / (double)w);
        xy[2 * k + 1] = (float)((ys[v] - 1.0) / (double)h);
        if (next) v = next[v];
    }
    *out_xy = xy;
    *out_count = n;
    return TT_OK;
}

/* Simplify the n-gon and, when at most max_vertices remain, emit it;
   otherwise leave *out_xy NULL. */
static tt_result tt__hull_reduce(const double *xs, const double *ys, int n, int w, int h, int max_vertices,
                                 const tt_allocator *allocator, float **out_xy, int *out_count)
{
    tt__hull hull;
    tt_result result = tt__hull_init(&hull, xs, ys, n, w + 2, h + 2, allocator);
    if (result != TT_OK) return result;
    result = tt__hull_simplify(&hull, max_vertices);
    if (result == TT_OK && hull.count <= max_vertices) {
        int start = 0;
        while (hull.state[start] == TT__HULL_DEAD) start++;
        result = tt__hull_emit(hull.x, hull.y, hull.next, start, hull.count, w, h, allocator, out_xy, out_count);
    }
    tt__hull_free(&hull);
    return result;
}

static int tt__hull_in(const unsigned char *cells, int width, int x, int y)
{
    return cells[(size_t)y * (size_t)width + (size_t)x] != TT__CELL_OUTSIDE;
}

/* Mark as outside every non-full cell 4-connected to the padding. */
static void tt__hull_flood(unsigned char *cells, int *stack, int width, int height)
{
    size_t total = (size_t)width * (size_t)height, k;
    int top = 0;
    for (k = 0; k < total; k++)
        if (cells[k] == TT__CELL_OUTSIDE) cells[k] = TT__CELL_EMPTY;
    cells[0] = TT__CELL_OUTSIDE;
    stack[top++] = 0;
    while (top > 0) {
        int c = stack[--top], x = c % width, y = c / width, d;
        for (d = 0; d < 4; d++) {
            int nx = x + (d == 0) - (d == 1), ny = y + (d == 2) - (d == 3), nc;
            if (nx < 0 || ny < 0 || nx >= width || ny >= height) continue;
            nc = ny * width + nx;
            if (cells[nc] != TT__CELL_EMPTY) continue;
            cells[nc] = TT__CELL_OUTSIDE;
            stack[top++] = nc;
        }
    }
}

/* Fill one outside cell of every pinch (two diagonal inside cells, the other
   two outside); returns how many were filled. */
static int tt__hull_fill_pinches(unsigned char *cells, int width, int height)
{
    int x, y, filled = 0;
    for (y = 0; y + 1 < height; y++) {
        for (x = 0; x + 1 < width; x++) {
            int a = tt__hull_in(cells, width, x, y), b = tt__hull_in(cells, width, x + 1, y);
            int c = tt__hull_in(cells, width, x, y + 1), d = tt__hull_in(cells, width, x + 1, y + 1);
            if (a && d && !b && !c) {
                cells[(size_t)(y * width + x + 1)] = TT__CELL_FULL;
                filled++;
            } else if (b && c && !a && !d) {
                cells[(size_t)(y * width + x)] = TT__CELL_FULL;
                filled++;
            }
        }
    }
    return filled;
}

/* Step 1: the outer contour, counter-clockwise, one vertex per turn. *n = 0
   (and TT_OK) when the shape needs the convex-hull fallback instead. */
static tt_result tt__hull_outer_contour(const tt_image *patch, const tt_allocator *allocator, double **out_x,
                                        double **out_y, int *out_n)
{
    int w = patch->width, h = patch->height, width = w + 2, height = h + 2;
    int i, j, round, x, y, dir, sx = -1, sy = -1, n = 0, closed = 0;
    size_t total = (size_t)width * (size_t)height, boundary = 0, steps = 0, k;
    unsigned char *cells = TT__ALLOC(allocator, unsigned char, total);
    int *stack = TT__ALLOC(allocator, int, total);
    double *xs = NULL, *ys = NULL;
    *out_x = *out_y = NULL;
    *out_n = 0;
    if (!cells || !stack) {
        tt__free(allocator, cells);
        tt__free(allocator, stack);
        return TT_ERROR_OUT_OF_MEMORY;
    }
    memset(cells, TT__CELL_EMPTY, total);
    for (j = 0; j < h; j++)
        for (i = 0; i < w; i++)
            if (patch->pixels[4 * ((size_t)j * (size_t)w + (size_t)i) + 3] > 0.0f)
                cells[(size_t)(h - j) * (size_t)width + (size_t)(i + 1)] = TT__CELL_FULL;
    for (round = 0;; round++) {
        tt__hull_flood(cells, stack, width, height);
        if (!tt__hull_fill_pinches(cells, width, height)) break;
        if (round + 1 == TT__HULL_PINCH_ROUNDS) goto fallback;
    }
    for (y = 1; y + 1 < height; y++) {
        for (x = 1; x + 1 < width; x++) {
            if (!tt__hull_in(cells, width, x, y)) continue;
            if (sx < 0) { sx = x; sy = y; }
            boundary += (size_t)!tt__hull_in(cells, width, x - 1, y) + (size_t)!tt__hull_in(cells, width, x + 1, y) +
                        (size_t)!tt__hull_in(cells, width, x, y - 1) + (size_t)!tt__hull_in(cells, width, x, y + 1);
        }
    }
    /* Keeps 7 * n + 8 (the queue) within int. */
    if (boundary > 0x7fffffffu / 8u) goto fallback;
    xs = TT__ALLOC(allocator, double, boundary);
    ys = TT__ALLOC(allocator, double, boundary);
    if (!xs || !ys) {
        tt__free(allocator, xs);
        tt__free(allocator, ys);
        tt__free(allocator, cells);
        tt__free(allocator, stack);
        return TT_ERROR_OUT_OF_MEMORY;
    }
    /* Square tracing along texel edges with the inside on the left, from the
       bottom-left corner of the lowest, leftmost inside cell heading east.
       Directions 0..3: east, north, west, south. */
    x = sx;
    y = sy;
    dir = 0;
    for (k = 0; k < boundary; k++) {
        int ahead_left, ahead_right, turn;
        x += dir == 0 ? 1 : (dir == 2 ? -1 : 0);
        y += dir == 1 ? 1 : (dir == 3 ? -1 : 0);
        steps++;
        switch (dir) {
        case 0: ahead_left = tt__hull_in(cells, width, x, y); ahead_right = tt__hull_in(cells, width, x, y - 1); break;
        case 1: ahead_left = tt__hull_in(cells, width, x - 1, y); ahead_right = tt__hull_in(cells, width, x, y); break;
        case 2: ahead_left = tt__hull_in(cells, width, x - 1, y - 1); ahead_right = tt__hull_in(cells, width, x - 1, y); break;
        default: ahead_left = tt__hull_in(cells, width, x, y - 1); ahead_right = tt__hull_in(cells, width, x - 1, y - 1); break;
        }
        turn = !ahead_left ? 1 : (ahead_right ? 3 : 0);
        if (turn) {
            xs[n] = (double)x;
            ys[n] = (double)y;
            n++;
            dir = (dir + turn) & 3;
        }
        if (x == sx && y == sy && dir == 0) {
            closed = 1;
            break;
        }
    }
    tt__free(allocator, cells);
    tt__free(allocator, stack);
    /* Another component has edges of its own: the traced loop missed them. */
    if (!closed || steps != boundary || n < 4) {
        tt__free(allocator, xs);
        tt__free(allocator, ys);
        return TT_OK;
    }
    *out_x = xs;
    *out_y = ys;
    *out_n = n;
    return TT_OK;

fallback:
    tt__free(allocator, cells);
    tt__free(allocator, stack);
    return TT_OK;
}

/* Step 3: convex hull of the nonzero texels' corners (Andrew's monotone
   chain over the extreme corners of each row). */
static tt_result tt__hull_convex(const tt_image *patch, const tt_allocator *allocator, double **out_x, double **out_y,
                                 int *out_n)
{
    int w = patch->width, h = patch->height, lines = h + 3, npoints = 0, k = 0, i, j, t;
    int *lo = TT__ALLOC(allocator, int, 2 * lines);
    double *px = TT__ALLOC(allocator, double, 2 * lines), *py = TT__ALLOC(allocator, double, 2 * lines);
    double *hx = TT__ALLOC(allocator, double, 4 * lines + 2), *hy = TT__ALLOC(allocator, double, 4 * lines + 2);
    double area = 0.0;
    *out_x = *out_y = NULL;
    *out_n = 0;
    if (!lo || !px || !py || !hx || !hy) {
        tt__free(allocator, lo);
        tt__free(allocator, px);
        tt__free(allocator, py);
        tt__free(allocator, hx);
        tt__free(allocator, hy);
        return TT_ERROR_OUT_OF_MEMORY;
    }
    for (t = 0; t < lines; t++) {
        lo[2 * t] = w + 3;
        lo[2 * t + 1] = -1;
    }
    for (j = 0; j < h; j++) {
        int first = -1, last = -1, row = h - j;
        for (i = 0; i < w; i++) {
            if (patch->pixels[4 * ((size_t)j * (size_t)w + (size_t)i) + 3] > 0.0f) {
                if (first < 0) first = i;
                last = i;
            }
        }
        if (first < 0) continue;
        for (t = row; t <= row + 1; t++) {
            lo[2 * t] = tt__min_i(lo[2 * t], first + 1);
            lo[2 * t + 1] = tt__max_i(lo[2 * t + 1], last + 2);
        }
    }
    /* Sorted by (y, x): the chain's order need not be by x. */
    for (t = 0; t < lines; t++) {
        if (lo[2 * t + 1] < 0) continue;
        px[npoints] = (double)lo[2 * t]; py[npoints] = (double)t; npoints++;
        px[npoints] = (double)lo[2 * t + 1]; py[npoints] = (double)t; npoints++;
    }
    for (i = 0; i < npoints; i++) {
        while (k >= 2 && tt__orient2(hx[k - 2], hy[k - 2], hx[k - 1], hy[k - 1], px[i], py[i]) <= 0.0) k--;
        hx[k] = px[i]; hy[k] = py[i]; k++;
    }
    for (i = npoints - 2, t = k + 1; i >= 0; i--) {
        while (k >= t && tt__orient2(hx[k - 2], hy[k - 2], hx[k - 1], hy[k - 1], px[i], py[i]) <= 0.0) k--;
        hx[k] = px[i]; hy[k] = py[i]; k++;
    }
    k--;
    for (i = 0; i < k; i++) area += hx[i] * hy[(i + 1) % k] - hx[(i + 1) % k] * hy[i];
    if (area < 0.0) {
        for (i = 0; i < k / 2; i++) {
            double sx = hx[i], sy = hy[i];
            hx[i] = hx[k - 1 - i]; hy[i] = hy[k - 1 - i];
            hx[k - 1 - i] = sx; hy[k - 1 - i] = sy;
        }
    }
    tt__free(allocator, lo);
    tt__free(allocator, px);
    tt__free(allocator, py);
    *out_x = hx;
    *out_y = hy;
    *out_n = k;
    return TT_OK;
}

static tt_result tt__patch_hull(const tt_image *patch, int max_vertices, const tt_allocator *allocator,
                                float **out_xy, int *out_count)
{
    double *xs, *ys, bx[4], by[4], x0, y0, x1, y1;
    int n, k, any = 0;
    size_t texels, t;
    tt_result result;
    if (out_xy) *out_xy = NULL;
    if (out_count) *out_count = 0;
    if (!patch || !patch->pixels || !out_xy || !out_count || max_vertices < 3 || patch->width < 1 ||
        patch->height < 1 || patch->width > TT_MAX_IMAGE_SIZE || patch->height > TT_MAX_IMAGE_SIZE)
        return TT_ERROR_INVALID_ARGUMENT;
    texels = (size_t)patch->width * (size_t)patch->height;
    for (t = 0; t < texels && !any; t++) any = patch->pixels[4 * t + 3] > 0.0f;
    if (!any) return TT_ERROR_INVALID_ARGUMENT;

    if ((result = tt__hull_outer_contour(patch, allocator, &xs, &ys, &n)) != TT_OK) return result;
    if (n > 0) {
        result = tt__hull_reduce(xs, ys, n, patch->width, patch->height, max_vertices, allocator, out_xy, out_count);
        tt__free(allocator, xs);
        tt__free(allocator, ys);
        if (result != TT_OK || *out_xy) return result;
    }

    if ((result = tt__hull_convex(patch, allocator, &xs, &ys, &n)) != TT_OK) return result;
    result = tt__hull_reduce(xs, ys, n, patch->width, patch->height, max_vertices, allocator, out_xy, out_count);
    x0 = x1 = xs[0];
    y0 = y1 = ys[0];
    for (k = 1; k < n; k++) {
        x0 = xs[k] < x0 ? xs[k] : x0; x1 = xs[k] > x1 ? xs[k] : x1;
        y0 = ys[k] < y0 ? ys[k] : y0; y1 = ys[k] > y1 ? ys[k] : y1;
    }
    tt__free(allocator, xs);
    tt__free(allocator, ys);
    if (result != TT_OK || *out_xy) return result;

    /* Last resort: the bounding box, or for a triangle the one with legs
       along its bottom and left sides, twice as long (its hypotenuse passes
       through the box's top-right corner). */
    bx[0] = x0; by[0] = y0;
    if (max_vertices >= 4) {
        bx[1] = x1; by[1] = y0;
        bx[2] = x1; by[2] = y1;
        bx[3] = x0; by[3] = y1;
        return tt__hull_emit(bx, by, NULL, 0, 4, patch->width, patch->height, allocator, out_xy, out_count);
    }
    bx[1] = x0 + 2.0 * (x1 - x0); by[1] = y0;
    bx[2] = x0; by[2] = y0 + 2.0 * (y1 - y0);
    return tt__hull_emit(bx, by, NULL, 0, 3, patch->width, patch->height, allocator, out_xy, out_count);
}

static int tt__point_on_segment(double px, double py, double ax, double ay, double bx, double by)
{
    return tt__orient2(ax, ay, bx, by, px, py) == 0.0 && px >= (ax < bx ? ax : bx) && px <= (ax > bx ? ax : bx) &&
           py >= (ay < by ? ay : by) && py <= (ay > by ? ay : by);
}

/* Inside or on the boundary, by the winding number. */
static int tt__point_in_polygon(double px, double py, const float *xy, int count)
{
    int k, winding = 0;
    for (k = 0; k < count; k++) {
        const float *a = xy + 2 * k, *b = xy + 2 * ((k + 1) % count);
        double o = tt__orient2(a[0], a[1], b[0], b[1], px, py);
        if (tt__point_on_segment(px, py, a[0], a[1], b[0], b[1])) return 1;
        if (a[1] <= py && b[1] > py && o > 0.0) winding++;
        else if (a[1] > py && b[1] <= py && o < 0.0) winding--;
    }
    return winding != 0;
}

/* Growth test of Sec. 3.3. If the segment meets the polygon without
   crossing or touching its boundary, it lies inside, and so do its ends. */
static int tt__segment_meets_polygon(const float a[2], const float b[2], const float *xy, int count)
{
    int k;
    if (!xy || count < 1) return 0;
    if (count >= 3 && (tt__point_in_polygon(a[0], a[1], xy, count) || tt__point_in_polygon(b[0], b[1], xy, count)))
        return 1;
    for (k = 0; k < count; k++) {
        const float *c = xy + 2 * k, *d = xy + 2 * ((k + 1) % count);
        double o1 = tt__orient2(a[0], a[1], b[0], b[1], c[0], c[1]), o2 = tt__orient2(a[0], a[1], b[0], b[1], d[0], d[1]);
        double o3 = tt__orient2(c[0], c[1], d[0], d[1], a[0], a[1]), o4 = tt__orient2(c[0], c[1], d[0], d[1], b[0], b[1]);
        if (((o1 > 0.0 && o2 < 0.0) || (o1 < 0.0 && o2 > 0.0)) && ((o3 > 0.0 && o4 < 0.0) || (o3 < 0.0 && o4 > 0.0)))
            return 1;
        if (tt__point_on_segment(c[0], c[1], a[0], a[1], b[0], b[1]) ||
            tt__point_on_segment(d[0], d[1], a[0], a[1], b[0], b[1]) ||
            tt__point_on_segment(a[0], a[1], c[0], c[1], d[0], d[1]) ||
            tt__point_on_segment(b[0], b[1], c[0], c[1], d[0], d[1]))
            return 1;
    }
    return 0;
}

/* ---- The paste loop (Praun et al. Sec. 3, 3.3-3.6, 4) ---- */

/* Coverage samples per patch side: a face's sample points lie about
   1/TT__LAPPED_SAMPLES_PER_SIDE of a patch side apart (Sec. 3.6). */
#define TT__LAPPED_SAMPLES_PER_SIDE 64
/* Sample raster resolutions range over [TT__LAPPED_MIN_SAMPLE_RES, this] (a
   face then carries about R^2 / 2 samples); faces larger than the spacing
   allows are sampled more coarsely, and covered more conservatively. */
#define TT__LAPPED_MIN_SAMPLE_RES 4
#define TT__LAPPED_MAX_SAMPLE_RES 256
/* Every point of a face's canonical raster triangle lies within this many
   raster cells of one of its sample points (1.58 at the acute corners). */
#define TT__LAPPED_SAMPLE_REACH 1.6
/* A sample's nearest texel, and the 2 x 2 texels a bilinear lookup reads
   within reach of it, lie within this many texels of the sample. */
#define TT__LAPPED_TEXEL_REACH 2.2
/* Points along an edge where a paste's alpha is probed, less one. */
#define TT__LAPPED_CUT_PROBES 4
/* Faces looked at around a seed to pick its patch (tt__pick_patch), at most. */
#define TT__LAPPED_NEAR_FACES 4096
/* The fringe (tt__paste_may_show): a paste may show a face mapped up to
   TT_LAPPED_GROW_DISTORTION off the field where its alpha over the face
   stays below this. */
#define TT__LAPPED_FRINGE_ALPHA 0.5f
/* tt__paste_fade: an edge where a paste stops is a cut when the patch's
   alpha along it reaches this; the paste fades to 0 there over this many
   patch sides. */
#define TT__LAPPED_CUT_ALPHA 0.1f
#define TT__LAPPED_FADE_WIDTH 0.05
/* A face seeded more than this many times gets an unfaded paste
   (tt__paste_fade); a paste whose fade leaves it covering less than this
   share of what it would cover unfaded is not faded (tt__record_paste). At
   0.5 the elephant kept half again as many hard edges; at 0 (fade always)
   a torus thinner than its patch took 900 pastes and more. */
#define TT__LAPPED_FADED_SEEDS 2
#define TT__LAPPED_FADE_KEEPS 0.1
/* Vertices of a patch's conservative hull (Sec. 3.3, Fig. 4). */
#define TT__LAPPED_HULL_VERTICES 32
/* Grow-and-solve rounds per paste (Sec. 3.3: "when this occurs, we further
   grow the patch and optimize again"). */
#define TT__LAPPED_GROW_ROUNDS 3
/* After regrowing, the patch is solved again only when it grew by more than
   1/this of its faces. */
#define TT__LAPPED_RESOLVE_FRACTION 10
/* Relative residual of the alignment solve. 1e-5 costs a sliver-rich mesh
   a fifth more time and moves the mean angle error by 0.05 degrees. */
#define TT__LAPPED_CG_TOLERANCE 1e-4
/* Early seed faces: the most difficult of this many random draws. */
#define TT__LAPPED_PRIORITY_DRAWS 8

/* One face of one paste (Sec. 3.5), with its alignment error (Sec. 3.4). */
typedef struct tt__entry {
    int face, paste;
    float uv[6];
    float fade[3];              /* per corner: the factor on the patch's alpha (tt__paste_fade) */
    unsigned char covers;       /* the paste may cover samples of the face (not the fringe) */
    float angle_error, scale_error;
} tt__entry;

typedef struct tt__lapper {
    const tt_mesh *mesh;
    tt_image *const *patches;
    int npatches;
    const float *field;
    int isotropic;
    const tt_allocator *al;
    tt_rng rng;
    /* per texture patch */
    float **hull;               /* conservative hull, texture space, CCW */
    int *hull_count;
    float **depth;              /* per texel: distance (texels) to the nearest texel not opaque */
    float *anchor;              /* 2 per patch: where a paste's seed point lands */
    /* per face */
    double *normal;             /* 3 per face */
    double *tangent;            /* 3 per face: T of the current paste (isotropic: propagated) */
    float *difficulty;          /* tt__face_difficulty, for the seed priority */
    int *sample_res;            /* R of the face's sample raster */
    int *sample_start;          /* nfaces + 1: its samples in covered[] */
    unsigned char *covered;     /* one byte per sample */
    int *covered_count;
    int *uncovered, *uncovered_pos, nuncovered;
    long long total_samples, covered_samples;
    /* barycentric sample tables, one per raster resolution R in use */
    float *table[TT__LAPPED_MAX_SAMPLE_RES + 1];    /* 2 per sample: weights of corners 1 and 2 */
    int table_count[TT__LAPPED_MAX_SAMPLE_RES + 1];
    /* per paste (stamped with the paste number, so nothing is cleared) */
    int *face_stamp, *vert_stamp, *edge_stamp, *vert_local;
    int *top_patch;             /* per face: the patch of the last paste on it, or -1 */
    int *near_stamp, *near_queue;   /* per face: the paste whose neighbourhood it was found in; a queue */
    int *patch_count;           /* per patch: faces near the seed showing it on top */
    int *shape_of;              /* per patch: the first patch with the same size and alpha (interchangeable) */
    int round_stamp;
    int seed_face, seed_sample;  /* the current paste's seed point */
    double expected_pastes;     /* TT_LAPPED_PASTES_PER_AREA estimate */
    double *vert_uv;            /* 2 per vertex */
    double *vert_cut_distance;  /* per vertex: texture-space distance to the current paste's cuts */
    int *face_entry;            /* per face: its entry in the paste being recorded */
    unsigned char *seeded;      /* per face: pastes seeded on it (at most 255) */
    int *patch_faces, npatch_faces;
    int *patch_verts, npatch_verts;
    tt__heap_item *heap;        /* half-edges to grow across (`value`), or vertices by cut distance */
    int heap_count;
    tt_triplet *triplets;
    double *solve;              /* 4 per patch vertex: b_s, b_t, x_s, x_t */
    /* recorded pastes (Sec. 3.5) */
    int *paste_patch, npastes, paste_capacity;
    tt__entry *entries;
    int nentries, entry_capacity;
} tt__lapper;

/* Sec. 3.6 counts a face point as covered where a paste is opaque. Here a
   sample point counts only when every texel a bilinear lookup could read
   anywhere within reach of it (rho texels) is opaque, so that the points
   between samples are covered too: depth[t] is the distance from texel t's
   centre to the nearest centre of a texel with alpha < TT_LAPPED_OPAQUE
   (outside the image counts as such: clamped lookups beyond the border are
   not relied on). The anchor, where a paste's seed point lands, is the
   deepest texel - the patch's "center" (Sec. 3.3) for any mask shape.
   Returns the depth of the anchor (0: nothing opaque), or -1 when out of
   memory. */
static float tt__patch_depth(tt__lapper *L, int index)
{
    const tt_image *patch = L->patches[index];
    const float big = 1e30f;
    int w = patch->width, h = patch->height, gw = w + 2, gh = h + 2, n = gw > gh ? gw : gh, x, y;
    float *grid = TT__ALLOC(L->al, float, (size_t)gw * gh), *line = TT__ALLOC(L->al, float, n);
    float *dline = TT__ALLOC(L->al, float, n), *z = TT__ALLOC(L->al, float, (size_t)n + 1), deepest = 0.0f;
    int *v = TT__ALLOC(L->al, int, n), ok;
    float *depth = TT__ALLOC(L->al, float, (size_t)w * h);
    L->depth[index] = depth;
    ok = grid && line && dline && z && v && depth;
    if (ok) {
        for (y = 0; y < gh; y++)
            for (x = 0; x < gw; x++) {
                int inside = x > 0 && y > 0 && x <= w && y <= h &&
                             patch->pixels[4 * ((size_t)(y - 1) * w + (x - 1)) + 3] >= TT_LAPPED_OPAQUE;
                grid[(size_t)y * gw + x] = inside ? big : 0.0f;
            }
        tt__distance_transform(grid, gw, gh, line, dline, v, z, big);
        for (y = 0; y < h; y++)
            for (x = 0; x < w; x++) {
                float d = sqrtf(grid[(size_t)(y + 1) * gw + (x + 1)]);
                depth[(size_t)y * w + x] = d;
                if (d > deepest) {
                    deepest = d;
                    L->anchor[2 * (size_t)index] = (float)((x + 0.5) / w);
                    L->anchor[2 * (size_t)index + 1] = (float)(1.0 - (y + 0.5) / h);
                }
            }
    }
    tt__free(L->al, grid);
    tt__free(L->al, line);
    tt__free(L->al, dline);
    tt__free(L->al, z);
    tt__free(L->al, v);
    return ok ? deepest : -1.0f;
}

typedef struct tt__table_fill {
    float *table;
    int count;
} tt__table_fill;

static void tt__table_add(int x, int y, const float barycentric[3], void *user_data)
{
    tt__table_fill *fill = (tt__table_fill *)user_data;
    (void)x; (void)y;
    if (fill->table) {
        fill->table[2 * fill->count] = barycentric[1];
        fill->table[2 * fill->count + 1] = barycentric[2];
    }
    fill->count++;
}

/* Sample points of a face (Sec. 3.6, "render all the patch faces ... and
   count covered pixels"): the pixel centres of an R x R raster that fall in
   the right triangle (0,0), (R,0), (0,R) by tt_raster_triangle, as
   barycentric weights of the face's corners - the same set for every face of
   resolution R, so coverage is counted on points fixed to the surface,
   whichever paste maps them. Built once per R in use. */
static int tt__sample_table(tt__lapper *L, int r)
{
    float xy[6];
    tt__table_fill fill;
    if (L->table[r]) return 1;
    xy[0] = 0.0f; xy[1] = 0.0f; xy[2] = (float)r; xy[3] = 0.0f; xy[4] = 0.0f; xy[5] = (float)r;
    fill.table = NULL;
    fill.count = 0;
    tt_raster_triangle(xy, r, r, tt__table_add, &fill);
    L->table[r] = TT__ALLOC(L->al, float, 2 * (size_t)fill.count);
    if (!L->table[r]) return 0;
    L->table_count[r] = fill.count;
    fill.table = L->table[r];
    fill.count = 0;
    tt_raster_triangle(xy, r, r, tt__table_add, &fill);
    return 1;
}

static const float *tt__corner_pos(const tt_mesh *mesh, int corner)
{
    return mesh->pos + 3 * (size_t)mesh->corner_vert[corner];
}

/* The weights (w0, w1, w2), summing to 0, with which a vector t in the plane
   of triangle f is a combination of its corners: t = sum w_i P_i (Sec. 3.4,
   footnote 1). Then phi(t) = sum w_i phi(P_i) for the linear map phi. */
static void tt__face_vector_weights(const tt_mesh *mesh, int f, const double *t, double w[3])
{
    const float *a = tt__corner_pos(mesh, 3 * f), *b = tt__corner_pos(mesh, 3 * f + 1);
    const float *c = tt__corner_pos(mesh, 3 * f + 2);
    double e1[3], e2[3], g11, g12, g22, r1, r2, det;
    tt__sub3f(b, a, e1);
    tt__sub3f(c, a, e2);
    g11 = tt__dot3(e1, e1); g12 = tt__dot3(e1, e2); g22 = tt__dot3(e2, e2);
    r1 = tt__dot3(e1, t); r2 = tt__dot3(e2, t);
    det = g11 * g22 - g12 * g12;   /* g11 g22 sin^2 of the angle at corner 0 */
    if (!(det > 1e-14 * g11 * g22)) { w[0] = w[1] = w[2] = 0.0; return; }
    w[1] = (g22 * r1 - g12 * r2) / det;
    w[2] = (g11 * r2 - g12 * r1) / det;
    w[0] = -w[1] - w[2];
}

/* phi(T_f) of face f under the current vertex UVs: what the alignment error
   is read from. */
static void tt__face_up_image(const tt__lapper *L, int f, double image_t[2])
{
    const tt_mesh *mesh = L->mesh;
    double wt[3];
    int k;
    tt__face_vector_weights(mesh, f, L->tangent + 3 * (size_t)f, wt);
    image_t[0] = image_t[1] = 0.0;
    for (k = 0; k < 3; k++) {
        const double *uv = L->vert_uv + 2 * (size_t)mesh->corner_vert[3 * f + k];
        image_t[0] += wt[k] * uv[0];
        image_t[1] += wt[k] * uv[1];
    }
}

/* Angle (degrees) between phi(T) and the texture's up axis, and phi(T)'s length. */
static void tt__alignment_error(const double image_t[2], double *angle, double *scale)
{
    *scale = sqrt(image_t[0] * image_t[0] + image_t[1] * image_t[1]);
    *angle = *scale > 0.0 ? fabs(atan2(image_t[0], image_t[1])) * (180.0 / TT__PI) : 180.0;
}

/* The paste's alpha along the segment from uv a to uv b, times the fade
   going linearly from fade_a to fade_b: the largest of
   TT__LAPPED_CUT_PROBES + 1 bilinear lookups, clamped at the patch's border
   as pastes are drawn. */
static float tt__paste_alpha_along(const tt_image *patch, const float a[2], const float b[2], float fade_a,
                                   float fade_b)
{
    float most = 0.0f;
    int i;
    for (i = 0; i <= TT__LAPPED_CUT_PROBES; i++) {
        const float t = (float)i / TT__LAPPED_CUT_PROBES, u = a[0] + t * (b[0] - a[0]), v = a[1] + t * (b[1] - a[1]);
        float rgba[4], alpha;
        tt_image_sample_bilinear(patch, u * patch->width, (1.0f - v) * patch->height, rgba);
        alpha = rgba[3] * (fade_a + t * (fade_b - fade_a));
        if (alpha > most) most = alpha;
    }
    return most;
}

/* The most of the paste's alpha over a face whose corners map to uv[6]:
   along its edges and at its centre. */
static float tt__face_alpha_most(const tt_image *patch, const float uv[6])
{
    const float centre[2] = {(uv[0] + uv[2] + uv[4]) / 3.0f, (uv[1] + uv[3] + uv[5]) / 3.0f};
    float most = tt__paste_alpha_along(patch, centre, centre, 1.0f, 1.0f);
    int k;
    for (k = 0; k < 3; k++) {
        float a = tt__paste_alpha_along(patch, uv + 2 * k, uv + 2 * ((k + 1) % 3), 1.0f, 1.0f);
        if (a > most) most = a;
    }
    return most;
}

/* Whether an alignment error (tt__alignment_error) turns T_f by at most
   `most` degrees and scales it within 1 + most / 90 either way
   (TT_LAPPED_MAX_DISTORTION). */
static int tt__aligned_within(double angle, double scale, double most)
{
    double limit = 1.0 + most / 90.0;
    return angle <= most && scale <= limit && scale * limit >= 1.0;
}

/* Face f's corner UVs as the current map has them. */
static void tt__face_uv(const tt__lapper *L, int f, float uv[6])
{
    int k;
    for (k = 0; k < 3; k++) {
        const double *p = L->vert_uv + 2 * (size_t)L->mesh->corner_vert[3 * f + k];
        uv[2 * k] = (float)p[0];
        uv[2 * k + 1] = (float)p[1];
    }
}

/* Whether a paste of `patch` may show face f under its current map: within
   TT_LAPPED_MAX_DISTORTION, or within TT_LAPPED_GROW_DISTORTION where
   the patch is already fading out over the face (its alpha below
   TT__LAPPED_FRINGE_ALPHA). The fringe keeps the paste's soft border where
   the map drifts from the field toward the paste's rim, so that it need
   not end there with a hard edge; the texture shown there is faint, and
   covers nothing (Sec. 3.6 counts opaque points only). angle and scale are
   the face's alignment error (tt__alignment_error). */
static int tt__paste_may_show(const tt__lapper *L, int f, int patch, double angle, double scale)
{
    float uv[6];
    if (tt__aligned_within(angle, scale, TT_LAPPED_MAX_DISTORTION)) return 1;
    if (!tt__aligned_within(angle, scale, TT_LAPPED_GROW_DISTORTION)) return 0;
    tt__face_uv(L, f, uv);
    return tt__face_alpha_most(L->patches[patch], uv) < TT__LAPPED_FRINGE_ALPHA;
}

static void tt__map_vertex(tt__lapper *L, int v, int paste)
{
    L->vert_stamp[v] = paste;
    L->vert_local[v] = L->npatch_verts;
    L->patch_verts[L->npatch_verts++] = v;
}

/* Queue the half-edges of patch face f whose far side is not in the patch
   and whose image still meets the hull of texture patch `patch` (Sec. 3.3:
   "the patch is only grown over an edge if the edge is still partially
   inside the texture patch"), keyed by the distance of the edge's image
   from the anchor, so that the patch grows nearest first. */
static void tt__queue_edges(tt__lapper *L, int f, int paste, int patch)
{
    const tt_mesh *mesh = L->mesh;
    const float *anchor = L->anchor + 2 * (size_t)patch;
    int k;
    for (k = 0; k < 3; k++) {
        int c = 3 * f + k, t = mesh->twin[c];
        const double *p, *q;
        float a[2], b[2];
        double mx, my;
        if (t < 0 || L->face_stamp[t / 3] == paste || L->edge_stamp[c] == L->round_stamp) continue;
        p = L->vert_uv + 2 * (size_t)mesh->corner_vert[c];
        q = L->vert_uv + 2 * (size_t)mesh->corner_vert[3 * f + (k + 1) % 3];
        a[0] = (float)p[0]; a[1] = (float)p[1]; b[0] = (float)q[0]; b[1] = (float)q[1];
        if (!tt__segment_meets_polygon(a, b, L->hull[patch], L->hull_count[patch])) continue;
        L->edge_stamp[c] = L->round_stamp;
        mx = 0.5 * (p[0] + q[0]) - anchor[0];
        my = 0.5 * (p[1] + q[1]) - anchor[1];
        tt__heap_push(L->heap, &L->heap_count, mx * mx + my * my, c);
    }
}

/* Isotropic mode (Sec. 3.2, last paragraph): "the direction of each
   subsequently added face is computed by projecting onto its face plane the
   average direction of neighboring faces already in the patch"; the length
   stays the field's. `from` is the half-edge of the patch face g was reached
   across, the fallback when the average cancels. */
static void tt__propagate_direction(tt__lapper *L, int g, int from, int paste)
{
    const tt_mesh *mesh = L->mesh;
    double sum[3] = {0.0, 0.0, 0.0}, d[3], *out = L->tangent + 3 * (size_t)g;
    const float *field = L->field + 3 * (size_t)g;
    double length = tt__length3f(field);
    int k;
    for (k = 0; k < 3; k++) {
        int t = mesh->twin[3 * g + k], h;
        if (t < 0 || L->face_stamp[h = t / 3] != paste) continue;
        d[0] = L->tangent[3 * (size_t)h]; d[1] = L->tangent[3 * (size_t)h + 1]; d[2] = L->tangent[3 * (size_t)h + 2];
        tt__normalize3(d);
        sum[0] += d[0]; sum[1] += d[1]; sum[2] += d[2];
    }
    tt__project3(sum, L->normal + 3 * (size_t)g, out);
    if (tt__normalize3(out) <= 1e-6) {
        int h = from / 3;
        tt__field_transport(mesh, from, L->normal + 3 * (size_t)h, L->normal + 3 * (size_t)g,
                            L->tangent + 3 * (size_t)h, out);
        tt__normalize3(out);
    }
    out[0] *= length; out[1] *= length; out[2] *= length;
}

/* Similar-triangle prediction (Sec. 3.3, after Maillot et al.): for every
   face around vertex v whose other two corners x, y are mapped, place v so
   the UV triangle is similar to the 3D one; v gets the mean of the
   predictions, each weighted by 1 / (a^2 + b^2) where (a, b) is v's place
   in units of the edge x y it comes from (along it and across it): the
   error of x's and y's UVs reaches v scaled by about that distance, so a
   short edge (a sliver's) seeing v far away would throw the mean off. The fan
   walk starts at vert_corner, the outgoing boundary half-edge when v is on
   a boundary, so one sweep sees every face. Returns 0 when no face
   predicts v. */
static int tt__predict_vertex(const tt__lapper *L, int v, int paste, double uv[2])
{
    const tt_mesh *mesh = L->mesh;
    const float *pv = mesh->pos + 3 * (size_t)v;
    int start = mesh->vert_corner[v], c = start, guard = 0;
    double weight = 0.0;
    uv[0] = uv[1] = 0.0;
    while (c >= 0 && guard++ < mesh->ncorners) {
        int f = c / 3, k = c % 3;
        int x = mesh->corner_vert[3 * f + (k + 1) % 3], y = mesh->corner_vert[3 * f + (k + 2) % 3];
        if (L->vert_stamp[x] == paste && L->vert_stamp[y] == paste) {
            const float *px = mesh->pos + 3 * (size_t)x, *py = mesh->pos + 3 * (size_t)y;
            const double *ux = L->vert_uv + 2 * (size_t)x, *uy = L->vert_uv + 2 * (size_t)y;
            double e[3], q[3], n[3], ee, along, across, w;
            int j;
            for (j = 0; j < 3; j++) { e[j] = (double)py[j] - px[j]; q[j] = (double)pv[j] - px[j]; }
            ee = tt__dot3(e, e);
            if (ee > 0.0) {
                /* The face (v, x, y) is counter-clockwise, so v lies left of
                   x -> y: the perpendicular offset turns x -> y by +90 deg. */
                tt__cross3(e, q, n);
                along = tt__dot3(q, e) / ee;
                across = tt__length3(n) / ee;
                w = 1.0 / (along * along + across * across + 1e-12);
                uv[0] += w * (ux[0] + along * (uy[0] - ux[0]) - across * (uy[1] - ux[1]));
                uv[1] += w * (ux[1] + along * (uy[1] - ux[1]) + across * (uy[0] - ux[0]));
                weight += w;
            }
        }
        c = mesh->twin[3 * f + (k + 2) % 3];
        if (c == start) break;
    }
    if (!(weight > 0.0)) return 0;
    uv[0] /= weight;
    uv[1] /= weight;
    return 1;
}

/* Add the face across half-edge c (of a patch face) if the three rules of
   Sec. 3.3 allow it: the patch stays a disc (the face meets the patch along
   one edge with a new vertex, or along two edges), and the face's predicted
   map is not too distorted ("patch growth is stopped when distortion
   becomes excessive"). Returns 1 when it was added. */
static int tt__try_add_face(tt__lapper *L, int c, int paste)
{
    const tt_mesh *mesh = L->mesh;
    int t = mesh->twin[c], g = t / 3, v = mesh->corner_vert[3 * g + (t % 3 + 2) % 3], shared = 0, k, mapped;
    double uv[2], image_t[2], angle, scale;
    if (L->face_stamp[g] == paste) return 0;
    for (k = 0; k < 3; k++) {
        int u = mesh->twin[3 * g + k];
        if (u >= 0 && L->face_stamp[u / 3] == paste) shared++;
    }
    mapped = L->vert_stamp[v] == paste;
    if (mapped ? shared != 2 : shared != 1) return 0;
    if (L->isotropic) tt__propagate_direction(L, g, c, paste);
    if (!mapped) {
        if (!tt__predict_vertex(L, v, paste, uv)) return 0;
        L->vert_uv[2 * (size_t)v] = uv[0];        /* provisional until v is stamped */
        L->vert_uv[2 * (size_t)v + 1] = uv[1];
    }
    tt__face_up_image(L, g, image_t);
    tt__alignment_error(image_t, &angle, &scale);
    if (!tt__aligned_within(angle, scale, TT_LAPPED_GROW_DISTORTION)) return 0;
    L->face_stamp[g] = paste;
    L->patch_faces[L->npatch_faces++] = g;
    if (!mapped) tt__map_vertex(L, v, paste);
    return 1;
}

static void tt__grow_patch(tt__lapper *L, int paste, int patch)
{
    int i, count = L->npatch_faces;
    L->round_stamp++;
    L->heap_count = 0;
    for (i = 0; i < count; i++) tt__queue_edges(L, L->patch_faces[i], paste, patch);
    while (L->heap_count > 0) {
        int c = tt__heap_pop(L->heap, &L->heap_count).value;
        if (tt__try_add_face(L, c, paste))
            tt__queue_edges(L, L->patch_faces[L->npatch_faces - 1], paste, patch);
    }
}

/* Sec. 3.4: minimise sum_f a_f (|phi(S_f) - (1,0)|^2 + |phi(T_f) - (0,1)|^2)
   over the patch's vertex UVs, a_f the face's area over the patch's mean
   (the paper's sum has no weights; see below). With phi(T_f) = sum_i wt_i
   uv_i (and ws for S), the s and t coordinates decouple into one normal
   matrix
       A = sum_f a_f (wt wt^T + ws ws^T),   A s = sum_f a_f ws,   A t = sum_f a_f wt.
   The minimum is unique up to a translation; a penalty holding the seed
   point on the anchor removes it (at the optimum the penalty is zero, so its
   weight only affects conditioning), and a final exact translation puts the
   seed on the anchor. Solved by tt_cg_solve from the current map. A solve
   that fails for a numerical reason keeps the predicted map. */
static tt_result tt__optimize_patch(tt__lapper *L, int seed_face, const double seed_weight[3], const float anchor[2])
{
    const tt_mesh *mesh = L->mesh;
    int n = L->npatch_verts, nt = 0, i, j, k, f;
    double trace = 0.0, penalty, seed_uv[2] = {0.0, 0.0}, mean_area = 0.0;
    double *b_s, *b_t, *x_s, *x_t;
    tt_sparse_matrix *A;
    tt_cg_options cg;
    tt_result r;
    memset(&A, 0, sizeof A);
    b_s = L->solve; b_t = b_s + n; x_s = b_t + n; x_t = x_s + n;
    for (i = 0; i < 4 * n; i++) L->solve[i] = 0.0;
    for (i = 0; i < n; i++) {
        x_s[i] = L->vert_uv[2 * (size_t)L->patch_verts[i]];
        x_t[i] = L->vert_uv[2 * (size_t)L->patch_verts[i] + 1];
    }
    /* Each face's term weighted by its area (relative to the patch's mean):
       the paper's plain sum over faces lets a sliver weigh as much as a
       large face, and its huge gradient weights make the matrix so
       ill-conditioned that CG crawls (a torus with half its triangles
       slivers took 2.2 times as long to paste; 1.55 weighted). Weighted, it
       is the integral over the surface. */
    for (f = 0; f < L->npatch_faces; f++) mean_area += tt__face_area_d(mesh, L->patch_faces[f]) / L->npatch_faces;
    for (f = 0; f < L->npatch_faces; f++) {
        int face = L->patch_faces[f], local[3];
        double s[3], wt[3], ws[3], a = mean_area > 0.0 ? tt__face_area_d(mesh, face) / mean_area : 1.0;
        const double *t = L->tangent + 3 * (size_t)face;
        tt__cross3(t, L->normal + 3 * (size_t)face, s);
        tt__face_vector_weights(mesh, face, t, wt);
        tt__face_vector_weights(mesh, face, s, ws);
        for (k = 0; k < 3; k++) local[k] = L->vert_local[mesh->corner_vert[3 * face + k]];
        for (k = 0; k < 3; k++) {
            b_s[local[k]] += a * ws[k];
            b_t[local[k]] += a * wt[k];
            trace += a * (wt[k] * wt[k] + ws[k] * ws[k]);
            for (j = 0; j < 3; j++) {
                L->triplets[nt].row = local[k];
                L->triplets[nt].col = local[j];
                L->triplets[nt].value = a * (wt[k] * wt[j] + ws[k] * ws[j]);
                nt++;
            }
        }
    }
    penalty = trace / n;
    for (k = 0; k < 3; k++) {
        int row = L->vert_local[mesh->corner_vert[3 * seed_face + k]];
        b_s[row] += penalty * seed_weight[k] * anchor[0];
        b_t[row] += penalty * seed_weight[k] * anchor[1];
        for (j = 0; j < 3; j++) {
            L->triplets[nt].row = row;
            L->triplets[nt].col = L->vert_local[mesh->corner_vert[3 * seed_face + j]];
            L->triplets[nt].value = penalty * seed_weight[k] * seed_weight[j];
            nt++;
        }
    }
    r = tt_sparse_from_triplets(n, n, L->triplets, nt, L->al, &A, NULL);
    if (r != TT_OK) return r == TT_ERROR_OUT_OF_MEMORY ? r : TT_OK;
    memset(&cg, 0, sizeof cg);
    cg.tolerance = TT__LAPPED_CG_TOLERANCE;
    cg.preconditioner = TT_CG_INCOMPLETE_CHOLESKY;
    r = tt_cg_solve(A, b_s, &cg, L->al, x_s, NULL, NULL);
    if (r == TT_OK || r == TT_ERROR_NOT_CONVERGED) r = tt_cg_solve(A, b_t, &cg, L->al, x_t, NULL, NULL);
    tt_sparse_matrix_free(A);
    if (r == TT_ERROR_OUT_OF_MEMORY) return r;
    if (r != TT_OK && r != TT_ERROR_NOT_CONVERGED) return TT_OK;
    for (k = 0; k < 3; k++) {
        int local = L->vert_local[mesh->corner_vert[3 * seed_face + k]];
        seed_uv[0] += seed_weight[k] * x_s[local];
        seed_uv[1] += seed_weight[k] * x_t[local];
    }
    for (i = 0; i < n; i++) {
        L->vert_uv[2 * (size_t)L->patch_verts[i]] = x_s[i] + (anchor[0] - seed_uv[0]);
        L->vert_uv[2 * (size_t)L->patch_verts[i] + 1] = x_t[i] + (anchor[1] - seed_uv[1]);
    }
    return TT_OK;
}

/* The face's sample points not yet in marks[] (the face's slice of a
   per-sample array) that an entry's map (corner UVs uv[6]) puts safely
   inside the opaque part of texture patch `patch` (see tt__patch_depth),
   where its fade (fade[3], linear over the face) is at least
   TT_LAPPED_OPAQUE: marks them and returns how many it marked. With
   `unfaded` it marks nothing, counts them, and adds to *unfaded how many
   there would be with no fade. Any point of the face lies within
   TT__LAPPED_SAMPLE_REACH raster cells of a sample; the face's map
   stretches a cell to at most rho texels. */
static int tt__mark_opaque_samples(const tt__lapper *L, int f, const float *uv, const float *fade, int patch,
                                   unsigned char *marks, int *unfaded)
{
    const tt_image *image = L->patches[patch];
    const float *depth = L->depth[patch];
    int r = L->sample_res[f], count = L->sample_start[f + 1] - L->sample_start[f], s, added = 0;
    int w = image->width, h = image->height;
    const float *table = L->table[r];
    double e1u = (uv[2] - uv[0]) * w, e1v = (uv[3] - uv[1]) * h, e2u = (uv[4] - uv[0]) * w, e2v = (uv[5] - uv[1]) * h;
    double rho = TT__LAPPED_SAMPLE_REACH * sqrt(e1u * e1u + e1v * e1v + e2u * e2u + e2v * e2v) / r;
    float need = (float)(rho + TT__LAPPED_TEXEL_REACH);
    for (s = 0; s < count; s++) {
        double w1 = table[2 * s], w2 = table[2 * s + 1], w0 = 1.0 - w1 - w2, x, y;
        if (marks[s]) continue;
        x = (w0 * uv[0] + w1 * uv[2] + w2 * uv[4]) * w;
        y = (1.0 - (w0 * uv[1] + w1 * uv[3] + w2 * uv[5])) * h;
        if (!(x >= 0.0 && y >= 0.0 && x < w && y < h) || !(depth[(size_t)(int)y * w + (int)x] > need)) continue;
        if (unfaded) {
            (*unfaded)++;
            if (w0 * fade[0] + w1 * fade[1] + w2 * fade[2] >= TT_LAPPED_OPAQUE) added++;
        } else if (w0 * fade[0] + w1 * fade[1] + w2 * fade[2] >= TT_LAPPED_OPAQUE) {
            marks[s] = 1;
            added++;
        }
    }
    return added;
}

/* Face f got `count` more covered samples; a face now fully covered leaves
   the list seed points are drawn from. Returns count. */
static int tt__count_covered(tt__lapper *L, int f, int count)
{
    L->covered_count[f] += count;
    if (count > 0 && L->covered_count[f] == L->sample_start[f + 1] - L->sample_start[f]) {
        int at = L->uncovered_pos[f], last = L->uncovered[--L->nuncovered];
        L->uncovered[at] = last;
        L->uncovered_pos[last] = at;
        L->uncovered_pos[f] = -1;
    }
    return count;
}

static int tt__face_has_vertex(const tt_mesh *mesh, int f, int v)
{
    return mesh->corner_vert[3 * f] == v || mesh->corner_vert[3 * f + 1] == v || mesh->corner_vert[3 * f + 2] == v;
}

/* Whether face f has an entry in the paste being recorded, whose entries
   are L->entries[first ..]. */
static int tt__in_paste(const tt__lapper *L, int f, int first)
{
    int e = L->face_entry[f];
    return e >= first && e < L->nentries && L->entries[e].face == f;
}

/* Whether face g, left out of the paste being recorded, is a hole in it:
   the paste covers every face around it. Dropping a face the solve left
   distorted (a sliver's map turns wildly with the slightest error) only
   lets what lies beneath show through that one face; it is no place where
   the paste ends, and fading around it would uncover a patch-wide disc. */
static int tt__hole_in_paste(const tt__lapper *L, int g, int first)
{
    int k;
    for (k = 0; k < 3; k++) {
        int t = L->mesh->twin[3 * g + k];
        if (t >= 0 && !tt__in_paste(L, t / 3, first)) return 0;
    }
    return 1;
}

/* The fade of the paste whose entries are L->entries[first ..]: where the
   paste has to stop while its patch still shows (a cut: an edge to a face
   it leaves out, with alpha of at least TT__LAPPED_CUT_ALPHA along it; the
   mesh's own boundary is no cut), its alpha goes to 0, rising with the
   distance d from the nearest cut, in texture space along the paste's
   edges (Dijkstra), as smoothstep(d / W) to 1 at W =
   TT__LAPPED_FADE_WIDTH patch sides. So the paste ends softly there too,
   as the paper's do where growth covers the whole patch (Sec. 3.3), and the
   faces it fades cover nothing: later pastes cover them. W shrinks to 0.9
   of the seed face's distance from the cuts, so the seed face is never
   faded and every paste makes progress; the seed face's own corners are
   not where fading starts, so a cut next to the seed face (a crease or a
   thin part that no paste can cross) stays hard along that face alone
   and fades along the rest. A face seeded more than TT__LAPPED_FADED_SEEDS
   times is still not covered: the pastes around it fade there, every time
   (a part thinner than a patch, where every paste stops and its rim
   covers nothing), and the next paste seeded on it does not fade, so the
   loop ends as it did before fading. */
static void tt__paste_fade(tt__lapper *L, int first)
{
    const tt_mesh *mesh = L->mesh;
    const tt_image *image = L->patches[L->paste_patch[L->entries[first].paste]];
    double *distance = L->vert_cut_distance, width = TT__LAPPED_FADE_WIDTH;
    int e, k, count = 0;
    for (e = first; e < L->nentries; e++) {
        L->face_entry[L->entries[e].face] = e;
        for (k = 0; k < 3; k++) distance[mesh->corner_vert[3 * L->entries[e].face + k]] = HUGE_VAL;
    }
    for (e = first; e < L->nentries; e++) {
        const tt__entry *entry = &L->entries[e];
        for (k = 0; k < 3; k++) {
            int t = mesh->twin[3 * entry->face + k], g, a, b;
            if (t < 0) continue;
            g = t / 3;
            if (tt__in_paste(L, g, first) || tt__hole_in_paste(L, g, first)) continue;
            if (tt__paste_alpha_along(image, entry->uv + 2 * k, entry->uv + 2 * ((k + 1) % 3), 1.0f, 1.0f) <
                TT__LAPPED_CUT_ALPHA)
                continue;
            a = mesh->corner_vert[3 * entry->face + k];
            b = mesh->corner_vert[3 * entry->face + (k + 1) % 3];
            if (distance[a] > 0.0 && !tt__face_has_vertex(mesh, L->seed_face, a)) {
                distance[a] = 0.0;
                tt__heap_push(L->heap, &count, 0.0, a);
            }
            if (distance[b] > 0.0 && !tt__face_has_vertex(mesh, L->seed_face, b)) {
                distance[b] = 0.0;
                tt__heap_push(L->heap, &count, 0.0, b);
            }
        }
    }
    while (count > 0) {
        tt__heap_item top = tt__heap_pop(L->heap, &count);
        int v = top.value, start = mesh->vert_corner[v], c = start, guard = 0;
        if (top.key > distance[v]) continue;
        /* The paste's faces around v, and along each its edges from v: the
           edge to the next corner, and to the previous one when the face
           across that edge is not in the paste (else that face relaxes it as
           its next). Each edge is relaxed once each way, so the pushes stay
           within the heap (vertices plus corners). */
        while (c >= 0 && guard++ < mesh->ncorners) {
            int f = c / 3, j = c % 3, into_previous = mesh->twin[3 * f + (j + 2) % 3];
            if (tt__in_paste(L, f, first))
                for (k = 1; k < 3; k++) {
                    int x = mesh->corner_vert[3 * f + (j + k) % 3];
                    if (k == 2 && into_previous >= 0 && tt__in_paste(L, into_previous / 3, first)) continue;
                    double du = L->vert_uv[2 * (size_t)x] - L->vert_uv[2 * (size_t)v];
                    double dv = L->vert_uv[2 * (size_t)x + 1] - L->vert_uv[2 * (size_t)v + 1];
                    double through = distance[v] + sqrt(du * du + dv * dv);
                    if (through < distance[x]) {
                        distance[x] = through;
                        tt__heap_push(L->heap, &count, through, x);
                    }
                }
            c = mesh->twin[3 * f + (j + 2) % 3];
            if (c == start) break;
        }
    }
    for (k = 0; k < 3; k++) {
        double d = 0.9 * distance[mesh->corner_vert[3 * L->seed_face + k]];
        if (d < width) width = d;
    }
    if (L->seeded[L->seed_face] > TT__LAPPED_FADED_SEEDS) width = 0.0;
    for (e = first; e < L->nentries; e++)
        for (k = 0; k < 3; k++) {
            double x = width > 0.0 ? distance[mesh->corner_vert[3 * L->entries[e].face + k]] / width : 1.0;
            x = x < 1.0 ? x : 1.0;
            L->entries[e].fade[k] = (float)(x * x * (3.0 - 2.0 * x));
        }
}

/* Sec. 3.5 and 3.6: record the paste (one entry per patch face, with its
   corner UVs, its fade and its alignment error) and update the coverage.
   Returns the number of samples newly covered, or -1 when out of memory. */
static long long tt__record_paste(tt__lapper *L, int patch)
{
    long long added = 0;
    int i, pass, paste = L->npastes, first = L->nentries;
    void *grown = tt__grow(L->al, L->paste_patch, &L->paste_capacity, paste + 1, sizeof(int));
    if (!grown) return -1;
    L->paste_patch = (int *)grown;
    L->paste_patch[L->npastes++] = patch;
    grown = tt__grow(L->al, L->entries, &L->entry_capacity, L->nentries + L->npatch_faces, sizeof(tt__entry));
    if (!grown) return -1;
    L->entries = (tt__entry *)grown;
    for (i = 0; i < L->npatch_faces; i++) {
        int f = L->patch_faces[i];
        tt__entry *entry;
        double image_t[2], angle, scale;
        tt__face_up_image(L, f, image_t);
        tt__alignment_error(image_t, &angle, &scale);
        /* Sec. 3.3 stops growth where distortion becomes excessive; the
           optimization can still leave faces far off the field (near its
           singularities), and they are left out of the paste too: a cut
           there (faded, tt__paste_fade), and another paste covers them.
           Faces of the fringe stay but cover nothing. The seed face always
           stays, and covers. */
        if (f != L->seed_face && !tt__paste_may_show(L, f, patch, angle, scale)) continue;
        entry = &L->entries[L->nentries++];
        tt__face_uv(L, f, entry->uv);
        entry->covers = f == L->seed_face || tt__aligned_within(angle, scale, TT_LAPPED_MAX_DISTORTION);
        entry->face = f;
        entry->paste = paste;
        L->top_patch[f] = patch;
        entry->angle_error = (float)angle;
        entry->scale_error = (float)fabs(scale - 1.0);
    }
    tt__paste_fade(L, first);
    /* A paste that its fade would leave covering less than
       TT__LAPPED_FADE_KEEPS of what it covers unfaded is not faded: around
       a part thinner than the patch (the paste wraps and meets itself) every
       paste has cuts all over, and faded pastes would each cover a sliver,
       without end. Such a paste keeps its hard edges, as in the paper. */
    for (pass = 0; pass < 2; pass++) {
        long long faded = 0, unfaded = 0;
        for (i = first; i < L->nentries; i++) {
            const tt__entry *entry = &L->entries[i];
            int f = entry->face, got, none = 0;
            if (!entry->covers || L->covered_count[f] == L->sample_start[f + 1] - L->sample_start[f]) continue;
            if (pass == 0) {
                faded += tt__mark_opaque_samples(L, f, entry->uv, entry->fade, patch, L->covered + L->sample_start[f],
                                                 &none);
                unfaded += none;
                continue;
            }
            got = tt__mark_opaque_samples(L, f, entry->uv, entry->fade, patch, L->covered + L->sample_start[f], NULL);
            added += tt__count_covered(L, f, got);
        }
        if (pass == 0 && (double)faded < TT__LAPPED_FADE_KEEPS * (double)unfaded)
            for (i = first; i < L->nentries; i++)
                L->entries[i].fade[0] = L->entries[i].fade[1] = L->entries[i].fade[2] = 1.0f;
    }
    /* The seed point sits on the patch's deepest texel, so it is covered
       even where the face's map is too stretched for the test above to
       vouch for the points around it: every paste makes progress. */
    if (!L->covered[L->sample_start[L->seed_face] + L->seed_sample]) {
        L->covered[L->sample_start[L->seed_face] + L->seed_sample] = 1;
        added += tt__count_covered(L, L->seed_face, 1);
    }
    L->covered_samples += added;
    return added;
}

/* Sec. 3.3: "Early in the process we give higher priority both to areas of
   high curvature and to discontinuities in the direction field - where the
   parametrization is difficult - with the hope that any distorted regions
   will be covered over later." Until half the samples are covered, the seed
   face is the most difficult of TT__LAPPED_PRIORITY_DRAWS random uncovered
   faces; then any uncovered face, uniformly. */
static int tt__pick_seed_face(tt__lapper *L)
{
    int f = L->uncovered[tt_rng_below(&L->rng, (uint32_t)L->nuncovered)], k;
    if (2 * L->covered_samples >= L->total_samples) return f;
    for (k = 1; k < TT__LAPPED_PRIORITY_DRAWS; k++) {
        int g = L->uncovered[tt_rng_below(&L->rng, (uint32_t)L->nuncovered)];
        if (L->difficulty[g] > L->difficulty[f]) f = g;
    }
    return f;
}

/* How hard face f is to parametrize: the largest bend to a neighbour (angle
   between normals) plus the largest turn of the field across an edge (the
   neighbour's vector carried over by parallel transport), in radians. The
   field does not count in isotropic mode. */
static float tt__face_difficulty(const tt__lapper *L, int f)
{
    const tt_mesh *mesh = L->mesh;
    const double *n = L->normal + 3 * (size_t)f, *t = L->tangent + 3 * (size_t)f;
    double worst = 0.0;
    int k;
    for (k = 0; k < 3; k++) {
        int c = mesh->twin[3 * f + k], g;
        double bend, turn = 0.0, carried[3], tn;
        if (c < 0) continue;
        g = c / 3;
        bend = acos(tt__clamp_f((float)tt__dot3(n, L->normal + 3 * (size_t)g), -1.0f, 1.0f));
        if (!L->isotropic) {
            tt__field_transport(mesh, c, L->normal + 3 * (size_t)g, n, L->tangent + 3 * (size_t)g, carried);
            tn = sqrt(tt__dot3(t, t) * tt__dot3(carried, carried));
            if (tn > 0.0) turn = acos(tt__clamp_f((float)(tt__dot3(t, carried) / tn), -1.0f, 1.0f));
        }
        if (bend + turn > worst) worst = bend + turn;
    }
    return (float)worst;
}

static void tt__lapper_free(tt__lapper *L)
{
    int i;
    for (i = 0; i < L->npatches; i++) {
        if (L->hull) tt__free(L->al, L->hull[i]);
        if (L->depth) tt__free(L->al, L->depth[i]);
    }
    for (i = 0; i <= TT__LAPPED_MAX_SAMPLE_RES; i++) tt__free(L->al, L->table[i]);
    tt__free(L->al, L->hull);
    tt__free(L->al, L->depth);
    tt__free(L->al, L->hull_count);
    tt__free(L->al, L->anchor);
    tt__free(L->al, L->normal);
    tt__free(L->al, L->tangent);
    tt__free(L->al, L->difficulty);
    tt__free(L->al, L->sample_res);
    tt__free(L->al, L->sample_start);
    tt__free(L->al, L->covered);
    tt__free(L->al, L->covered_count);
    tt__free(L->al, L->uncovered);
    tt__free(L->al, L->uncovered_pos);
    tt__free(L->al, L->face_stamp);
    tt__free(L->al, L->patch_count);
    tt__free(L->al, L->shape_of);
    tt__free(L->al, L->top_patch);
    tt__free(L->al, L->near_stamp);
    tt__free(L->al, L->near_queue);
    tt__free(L->al, L->vert_stamp);
    tt__free(L->al, L->edge_stamp);
    tt__free(L->al, L->vert_local);
    tt__free(L->al, L->vert_uv);
    tt__free(L->al, L->vert_cut_distance);
    tt__free(L->al, L->face_entry);
    tt__free(L->al, L->seeded);
    tt__free(L->al, L->patch_faces);
    tt__free(L->al, L->patch_verts);
    tt__free(L->al, L->heap);
    tt__free(L->al, L->triplets);
    tt__free(L->al, L->solve);
    tt__free(L->al, L->paste_patch);
    tt__free(L->al, L->entries);
}

/* Check the inputs and prepare the per-face and per-patch data. */
static tt_result tt__lapper_setup(tt__lapper *L, int max_pastes, tt_error *error)
{
    const tt_mesh *mesh = L->mesh;
    int nf = mesh->nfaces, nv = mesh->nverts, f, i, k;
    double lo[3], hi[3], diagonal, estimate = 0.0, opaque_fraction = 0.0;
    float shallowest = 0.0f;
    int widest = 1;
    long long total = 0;
    if (mesh->min_face_size != 3 || mesh->max_face_size != 3) {
        for (f = 0; f < nf && mesh->face_start[f + 1] - mesh->face_start[f] == 3; f++) {}
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, f, -1, -1, -1,
                        "lapped textures need a triangle mesh: face %d has %d corners (split it into triangles)", f,
                        mesh->face_start[f + 1] - mesh->face_start[f]);
    }
    for (i = 0; i < L->npatches; i++) {
        const tt_image *p = L->patches[i];
        size_t n, j;
        if (!p || p->width <= 0 || p->height <= 0 || !p->pixels)
            return tt__fail_at(error, TT_ERROR_INVALID_ARGUMENT, i, -1, -1, "texture patch %d is NULL or empty", i);
        n = (size_t)p->width * p->height * 4;
        for (j = 0; j < n; j++)
            if (!tt__is_finite(p->pixels[j]))
                return tt__fail_at(error, TT_ERROR_NON_FINITE, i, (int)(j / 4 / (size_t)p->width),
                                   (int)(j / 4 % (size_t)p->width),
                                   "texture patch %d has a NaN or infinite value at texel (%d, %d)", i,
                                   (int)(j / 4 % (size_t)p->width), (int)(j / 4 / (size_t)p->width));
    }
    L->hull = TT__ALLOC(L->al, float *, L->npatches);
    L->depth = TT__ALLOC(L->al, float *, L->npatches);
    for (i = 0; i < L->npatches; i++) {
        if (L->hull) L->hull[i] = NULL;
        if (L->depth) L->depth[i] = NULL;
    }
    L->hull_count = TT__ALLOC(L->al, int, L->npatches);
    L->patch_count = TT__ALLOC(L->al, int, L->npatches);
    L->shape_of = TT__ALLOC(L->al, int, L->npatches);
    L->top_patch = TT__ALLOC(L->al, int, nf);
    L->near_stamp = TT__ALLOC(L->al, int, nf);
    L->near_queue = TT__ALLOC(L->al, int, nf);
    L->anchor = TT__ALLOC(L->al, float, 2 * (size_t)L->npatches);
    L->normal = TT__ALLOC(L->al, double, 3 * (size_t)nf);
    L->tangent = TT__ALLOC(L->al, double, 3 * (size_t)nf);
    L->difficulty = TT__ALLOC(L->al, float, nf);
    L->sample_res = TT__ALLOC(L->al, int, nf);
    L->sample_start = TT__ALLOC(L->al, int, (size_t)nf + 1);
    L->covered_count = TT__ALLOC(L->al, int, nf);
    L->uncovered = TT__ALLOC(L->al, int, nf);
    L->uncovered_pos = TT__ALLOC(L->al, int, nf);
    L->face_stamp = TT__ALLOC(L->al, int, nf);
    L->vert_stamp = TT__ALLOC(L->al, int, nv);
    L->edge_stamp = TT__ALLOC(L->al, int, mesh->ncorners);
    L->vert_local = TT__ALLOC(L->al, int, nv);
    L->vert_uv = TT__ALLOC(L->al, double, 2 * (size_t)nv);
    L->patch_faces = TT__ALLOC(L->al, int, nf);
    L->patch_verts = TT__ALLOC(L->al, int, nv);
    /* growth pushes each half-edge once; the cut distances each vertex and
       each half-edge's relaxation at most once */
    L->heap = TT__ALLOC(L->al, tt__heap_item, (size_t)mesh->ncorners + nv);
    L->vert_cut_distance = TT__ALLOC(L->al, double, nv);
    L->face_entry = TT__ALLOC(L->al, int, nf);
    L->seeded = TT__ALLOC(L->al, unsigned char, nf);
    L->triplets = TT__ALLOC(L->al, tt_triplet, 9 * ((size_t)nf + 1));
    L->solve = TT__ALLOC(L->al, double, 4 * (size_t)nv);
    if (!L->hull || !L->hull_count || !L->patch_count || !L->shape_of || !L->top_patch || !L->near_stamp || !L->near_queue ||
        !L->anchor || !L->normal || !L->tangent || !L->difficulty || !L->sample_res ||
        !L->sample_start || !L->covered_count || !L->uncovered || !L->uncovered_pos || !L->face_stamp ||
        !L->vert_stamp || !L->edge_stamp || !L->vert_local || !L->vert_uv || !L->patch_faces ||
        !L->patch_verts || !L->heap || !L->triplets || !L->solve || !L->depth || !L->vert_cut_distance ||
        !L->face_entry || !L->seeded)
        return tt__fail(error, TT_ERROR_OUT_OF_MEMORY, -1, -1, -1, -1, "out of memory");
    for (i = 0; i < L->npatches; i++) {
        const tt_image *p = L->patches[i];
        size_t j, n = (size_t)p->width * p->height, opaque = 0;
        float deepest = tt__patch_depth(L, i);
        int other;
        /* Patches of one size and alpha (windows of one photo under one mask) give a paste the same faces
           and map: interchangeable after growth (tt__least_overlapping_twin). */
        L->shape_of[i] = i;
        for (other = 0; other < i && L->shape_of[i] == i; other++) {
            const tt_image *q = L->patches[other];
            if (L->shape_of[other] != other || q->width != p->width || q->height != p->height) continue;
            for (j = 0; j < n && q->pixels[4 * j + 3] == p->pixels[4 * j + 3]; j++) continue;
            if (j == n) L->shape_of[i] = other;
        }
        tt_result r;
        if (deepest < 0.0f) return tt__fail(error, TT_ERROR_OUT_OF_MEMORY, -1, -1, -1, -1, "out of memory");
        if (deepest == 0.0f)
            return tt__fail_at(error, TT_ERROR_INVALID_ARGUMENT, i, -1, -1,
                               "texture patch %d has no opaque texel (alpha >= %g)", i, TT_LAPPED_OPAQUE);
        if (i == 0 || deepest < shallowest) shallowest = deepest;
        r = tt__patch_hull(p, TT__LAPPED_HULL_VERTICES, L->al, &L->hull[i], &L->hull_count[i]);
        if (r != TT_OK)
            return tt__fail(error, r, -1, -1, -1, -1, "texture patch %d: %s", i, tt_result_string(r));
        for (j = 0; j < n; j++) opaque += p->pixels[4 * j + 3] >= TT_LAPPED_OPAQUE;
        if (p->width > widest) widest = p->width;
        if (p->height > widest) widest = p->height;
        opaque_fraction += (double)opaque / (double)n / L->npatches;
    }

    for (k = 0; k < 3; k++) lo[k] = hi[k] = mesh->pos[k];
    for (i = 0; i < nv; i++)
        for (k = 0; k < 3; k++) {
            double x = mesh->pos[3 * (size_t)i + k];
            if (x < lo[k]) lo[k] = x;
            if (x > hi[k]) hi[k] = x;
        }
    diagonal = sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                    (hi[2] - lo[2]) * (hi[2] - lo[2]));
    for (f = 0; f < nf; f++) {
        const float *fv = L->field + 3 * (size_t)f;
        double *n = L->normal + 3 * (size_t)f, *t = L->tangent + 3 * (size_t)f, v[3], length, projected;
        if (!tt__face_normal_d(mesh, f, n))
            return tt__fail(error, TT_ERROR_ZERO_AREA_FACE, f, -1, -1, -1, "face %d has zero area", f);
        if (!tt__is_finite(fv[0]) || !tt__is_finite(fv[1]) || !tt__is_finite(fv[2]))
            return tt__fail(error, TT_ERROR_NON_FINITE, f, -1, -1, -1,
                            "the field vector of face %d is NaN or infinite", f);
        v[0] = fv[0]; v[1] = fv[1]; v[2] = fv[2];
        length = tt__length3(v);
        tt__project3(v, n, t);
        projected = tt__length3(t);
        if (!(length > 0.0) || projected < 1e-3 * length)
            return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, f, -1, -1, -1,
                            length > 0.0 ? "the field vector of face %d is perpendicular to the face"
                                         : "the field vector of face %d has zero length", f);
        if (projected > diagonal)
            return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, f, -1, -1, -1,
                            "the texture patch (%g mesh units at face %d) is larger than the mesh "
                            "(bounding-box diagonal %g): use a smaller scale", projected, f, diagonal);
        /* Pastes needed: the area over the patch's opaque area, |T|^2
           times its opaque fraction, times TT_LAPPED_PASTES_PER_AREA. */
        {
            const float *a = tt__corner_pos(mesh, 3 * f), *b = tt__corner_pos(mesh, 3 * f + 1);
            const float *c = tt__corner_pos(mesh, 3 * f + 2);
            double e1[3], e2[3], cr[3];
            tt__sub3f(b, a, e1);
            tt__sub3f(c, a, e2);
            tt__cross3(e1, e2, cr);
            estimate += TT_LAPPED_PASTES_PER_AREA * 0.5 * tt__length3(cr) /
                        (projected * projected * opaque_fraction);
        }
    }
    L->expected_pastes = estimate;
    if (estimate > max_pastes)
        return tt__fail(error, TT_ERROR_TOO_LARGE, -1, -1, -1, -1,
                        "the texture patches are too small for this mesh: covering it would take about "
                        "%.3g pastes, more than the limit of %d (use a larger scale)", estimate, max_pastes);
    for (f = 0; f < nf; f++) {
        const double *t = L->tangent + 3 * (size_t)f;
        double projected = tt__length3(t), longest = 0.0;
        for (k = 0; k < 3; k++) {
            const float *a = tt__corner_pos(mesh, 3 * f + k), *b = tt__corner_pos(mesh, 3 * f + (k + 1) % 3);
            double e[3];
            tt__sub3f(b, a, e);
            if (tt__length3(e) > longest) longest = tt__length3(e);
        }
        {
            /* Faces so large next to the patch that even its deepest point
               cannot cover a sample's reach would never be covered. */
            double r = ceil(longest / projected * TT__LAPPED_SAMPLES_PER_SIDE), rho;
            L->sample_res[f] = r < TT__LAPPED_MIN_SAMPLE_RES ? TT__LAPPED_MIN_SAMPLE_RES
                             : r > TT__LAPPED_MAX_SAMPLE_RES ? TT__LAPPED_MAX_SAMPLE_RES : (int)r;
            rho = TT__LAPPED_SAMPLE_REACH * 1.5 * longest / projected * widest / L->sample_res[f];
            /* A paste should cover a good disc around its centre, not just
               its deepest texel: the samples' reach may use a quarter of the
               depth. */
            if (rho > 0.25 * shallowest || rho + TT__LAPPED_TEXEL_REACH >= shallowest)
                return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, f, -1, -1, -1,
                                "face %d is %.3g texture patches long, too coarse for a patch whose opaque part is "
                                "%.3g texels deep: subdivide the mesh, or use a larger scale or a larger image",
                                f, longest / projected, (double)shallowest);
        }
        if (!tt__sample_table(L, L->sample_res[f]))
            return tt__fail(error, TT_ERROR_OUT_OF_MEMORY, -1, -1, -1, -1, "out of memory");
        L->sample_start[f] = (int)total;
        total += L->table_count[L->sample_res[f]];
        if (total > INT_MAX)
            return tt__fail(error, TT_ERROR_TOO_LARGE, -1, -1, -1, -1,
                            "too many faces: the coverage samples do not fit an int");
    }
    L->sample_start[nf] = (int)total;
    L->total_samples = total;
    L->covered = TT__ALLOC(L->al, unsigned char, (size_t)total);
    if (!L->covered) return tt__fail(error, TT_ERROR_OUT_OF_MEMORY, -1, -1, -1, -1, "out of memory");
    memset(L->covered, 0, (size_t)total);
    for (f = 0; f < nf; f++) {
        L->covered_count[f] = 0;
        L->seeded[f] = 0;
        L->uncovered[f] = f;
        L->uncovered_pos[f] = f;
        L->face_stamp[f] = -1;
        L->top_patch[f] = -1;
        L->near_stamp[f] = -1;
    }
    L->nuncovered = nf;
    for (f = 0; f < nf; f++) L->difficulty[f] = tt__face_difficulty(L, f);
    for (i = 0; i < nv; i++) L->vert_stamp[i] = -1;
    for (i = 0; i < mesh->ncorners; i++) L->edge_stamp[i] = -1;
    L->round_stamp = 0;
    return TT_OK;
}

/* The texture patch for a paste seeded on face f: one of those that the
   faces around f (within the field's length, a patch's size, of f's
   centre, found breadth first) show on top least often, at random among
   them. Where every patch shows equally (or there is one) this is a
   uniform draw; else a paste avoids the patches of the pastes around it,
   so that the same part of the photo does not land next to itself (a
   blotch stamped like wallpaper). tt__least_overlapping_twin refines the
   choice once the paste's faces are known. */
static int tt__pick_patch(tt__lapper *L, int paste, int f)
{
    const tt_mesh *mesh = L->mesh;
    double centre[3], reach;
    int head = 0, tail = 0, i, k, least = INT_MAX, ties = 0, pick;
    /* One patch: the draw the uniform pick always made, so that seeds give the pastes they gave. */
    if (L->npatches == 1) return (int)tt_rng_below(&L->rng, 1u);
    tt__face_centroid(mesh, f, centre);
    reach = tt__length3f(L->field + 3 * (size_t)f);
    reach *= reach;
    for (i = 0; i < L->npatches; i++) L->patch_count[i] = 0;
    L->near_stamp[f] = paste;
    L->near_queue[tail++] = f;
    while (head < tail && tail < TT__LAPPED_NEAR_FACES) {
        const int g = L->near_queue[head++];
        if (L->top_patch[g] >= 0) L->patch_count[L->top_patch[g]]++;
        for (k = 0; k < 3 && tail < TT__LAPPED_NEAR_FACES; k++) {
            const int t = mesh->twin[3 * g + k];
            const float *p;
            double d2 = 0.0;
            if (t < 0 || L->near_stamp[t / 3] == paste) continue;
            p = tt__corner_pos(mesh, t);
            for (i = 0; i < 3; i++) d2 += (p[i] - centre[i]) * (p[i] - centre[i]);
            L->near_stamp[t / 3] = paste;
            if (d2 <= reach) L->near_queue[tail++] = t / 3;
        }
    }
    for (i = 0; i < L->npatches; i++) {
        if (L->patch_count[i] < least) least = L->patch_count[i], ties = 0;
        if (L->patch_count[i] == least) ties++;
    }
    pick = (int)tt_rng_below(&L->rng, (uint32_t)ties);
    for (i = 0; i < L->npatches; i++)
        if (L->patch_count[i] == least && pick-- == 0) return i;
    return 0;
}

/* Once the paste's faces are known: of the patches interchangeable with
   `patch` (tt__lapper.shape_of), the one shown least on top by the faces
   just outside the paste (across its boundary edges: the pastes it will
   border), `patch` itself on ties. On a sphere with three patches of one
   mask, 248 of 1575 borders between pastes (six seeds) show one patch on
   both sides, against about 525 for random picks; counting the faces it
   covers instead of its border did less (one seed: 47 of 252 against 31). */
static int tt__least_overlapping_twin(tt__lapper *L, int patch)
{
    const tt_mesh *mesh = L->mesh;
    int i, k, best = patch;
    for (i = 0; i < L->npatches; i++) L->patch_count[i] = 0;
    for (i = 0; i < L->npatch_faces; i++)
        for (k = 0; k < 3; k++) {
            const int t = mesh->twin[3 * L->patch_faces[i] + k];
            if (t >= 0 && L->face_stamp[t / 3] != L->npastes && L->top_patch[t / 3] >= 0)
                L->patch_count[L->top_patch[t / 3]]++;
        }
    for (i = 0; i < L->npatches; i++)
        if (L->shape_of[i] == L->shape_of[patch] && L->patch_count[i] < L->patch_count[best]) best = i;
    return best;
}

/* Start paste number `paste` (Sec. 3.3): a random face not yet covered, a
   random uncovered sample point of it, and a random texture patch; the face
   is mapped so that the point lands on the patch's anchor with (S, T) along
   the texture axes. Returns the patch; fills the seed point's weights. */
static int tt__seed_paste(tt__lapper *L, int paste, int *seed_face, double seed_weight[3])
{
    const tt_mesh *mesh = L->mesh;
    int f = tt__pick_seed_face(L);
    int r = L->sample_res[f], count = L->sample_start[f + 1] - L->sample_start[f];
    int pick = (int)tt_rng_below(&L->rng, (uint32_t)(count - L->covered_count[f])), s, k;
    int patch = tt__pick_patch(L, paste, f);
    const unsigned char *marks = L->covered + L->sample_start[f];
    const float *w = L->table[r], *anchor = L->anchor + 2 * (size_t)patch;
    double *t = L->tangent + 3 * (size_t)f, s_axis[3], point[3] = {0.0, 0.0, 0.0}, tt_, ss;
    for (s = 0; s < count; s++)
        if (!marks[s] && pick-- == 0) break;
    seed_weight[1] = w[2 * s];
    seed_weight[2] = w[2 * s + 1];
    seed_weight[0] = 1.0 - seed_weight[1] - seed_weight[2];
    if (L->isotropic) {
        /* "the center face of the patch is assigned an arbitrary tangent
           direction" (Sec. 3.2): the field's direction turned at random. */
        const float *fv = L->field + 3 * (size_t)f;
        double v[3], across[3], angle = TT__TWO_PI * tt_rng_float(&L->rng), length;
        v[0] = fv[0]; v[1] = fv[1]; v[2] = fv[2];
        length = tt__length3(v);
        tt__project3(v, L->normal + 3 * (size_t)f, t);
        tt__normalize3(t);
        tt__cross3(L->normal + 3 * (size_t)f, t, across);
        for (k = 0; k < 3; k++) t[k] = length * (cos(angle) * t[k] + sin(angle) * across[k]);
    }
    tt__cross3(t, L->normal + 3 * (size_t)f, s_axis);
    tt_ = tt__dot3(t, t);
    ss = tt__dot3(s_axis, s_axis);
    for (k = 0; k < 3; k++) {
        const float *p = tt__corner_pos(mesh, 3 * f + k);
        point[0] += seed_weight[k] * p[0]; point[1] += seed_weight[k] * p[1]; point[2] += seed_weight[k] * p[2];
    }
    L->npatch_faces = 0;
    L->npatch_verts = 0;
    L->face_stamp[f] = paste;
    L->patch_faces[L->npatch_faces++] = f;
    for (k = 0; k < 3; k++) {
        int v = mesh->corner_vert[3 * f + k];
        const float *p = mesh->pos + 3 * (size_t)v;
        double d[3];
        d[0] = p[0] - point[0]; d[1] = p[1] - point[1]; d[2] = p[2] - point[2];
        L->vert_uv[2 * (size_t)v] = anchor[0] + tt__dot3(d, s_axis) / ss;
        L->vert_uv[2 * (size_t)v + 1] = anchor[1] + tt__dot3(d, t) / tt_;
        tt__map_vertex(L, v, paste);
    }
    *seed_face = f;
    L->seed_face = f;
    if (L->seeded[f] < 255) L->seeded[f]++;
    L->seed_sample = s;
    return patch;
}

/* Sec. 4: "we remove for a given paste operation any faces that are
   completely occluded by subsequent paste operations". Walking the entries
   from the last paste to the first, an entry whose face's samples are all
   opaque under later pastes is dropped (face = -1). Returns how many. */
static int tt__remove_hidden(tt__lapper *L)
{
    int e, removed = 0, f;
    memset(L->covered, 0, (size_t)L->total_samples);
    for (f = 0; f < L->mesh->nfaces; f++) L->covered_count[f] = 0;
    for (e = L->nentries - 1; e >= 0; e--) {
        tt__entry *entry = &L->entries[e];
        int face = entry->face;
        if (L->covered_count[face] == L->sample_start[face + 1] - L->sample_start[face]) {
            entry->face = -1;
            removed++;
            continue;
        }
        L->covered_count[face] += tt__mark_opaque_samples(L, face, entry->uv, entry->fade, L->paste_patch[entry->paste],
                                                          L->covered + L->sample_start[face], NULL);
    }
    return removed;
}

/* The edges where the paste on top changes, and of those the cuts: the
   upper of the two pastes (absent from the other face) still at least
   TT_LAPPED_VISIBLE_CUT opaque along the edge. 0 when out of memory. */
static int tt__lapped_count_cuts(const tt__lapper *L, tt_lapped *out)
{
    const tt_mesh *mesh = L->mesh;
    int *top = TT__ALLOC(L->al, int, mesh->nfaces), e, c;
    if (!top) return 0;
    for (c = 0; c < mesh->nfaces; c++) top[c] = -1;
    for (e = 0; e < L->nentries; e++)
        if (L->entries[e].face >= 0) top[L->entries[e].face] = e;
    out->top_changes = out->visible_cuts = 0;
    for (c = 0; c < mesh->ncorners; c++) {
        const int t = mesh->twin[c];
        const tt__entry *upper;
        int corner, ef, eg;
        if (t < c || (ef = top[c / 3]) < 0 || (eg = top[t / 3]) < 0 || L->entries[ef].paste == L->entries[eg].paste)
            continue;
        out->top_changes++;
        upper = L->entries[ef].paste > L->entries[eg].paste ? &L->entries[ef] : &L->entries[eg];
        corner = upper == &L->entries[ef] ? c % 3 : t % 3;
        if (tt__paste_alpha_along(L->patches[L->paste_patch[upper->paste]], upper->uv + 2 * corner,
                                  upper->uv + 2 * ((corner + 1) % 3), upper->fade[corner],
                                  upper->fade[(corner + 1) % 3]) >= TT_LAPPED_VISIBLE_CUT)
            out->visible_cuts++;
    }
    tt__free(L->al, top);
    return 1;
}

/* Move the surviving entries into the result, pastes that lost every face
   dropped. */
static tt_result tt__lapped_output(tt__lapper *L, int removed, tt_lapped *out)
{
    int kept = L->nentries - removed, e, n = 0, p = -1, last_paste = -1, i;
    double angle_sum = 0.0;
    double *scales;
    out->allocator = tt__allocator_copy(L->al);
    out->faces = TT__ALLOC(L->al, int, kept > 0 ? kept : 1);
    out->uv = TT__ALLOC(L->al, float, 6 * (size_t)(kept > 0 ? kept : 1));
    out->fade = TT__ALLOC(L->al, float, 3 * (size_t)(kept > 0 ? kept : 1));
    out->pastes = TT__ALLOC(L->al, tt_paste, L->npastes > 0 ? L->npastes : 1);
    scales = TT__ALLOC(L->al, double, kept > 0 ? kept : 1);
    if (!out->faces || !out->uv || !out->fade || !out->pastes || !scales) {
        tt__free(L->al, scales);
        return TT_ERROR_OUT_OF_MEMORY;
    }
    for (e = 0; e < L->nentries; e++) {
        const tt__entry *entry = &L->entries[e];
        if (entry->face < 0) continue;
        if (entry->paste != last_paste) {
            last_paste = entry->paste;
            p++;
            out->pastes[p].patch = L->paste_patch[entry->paste];
            out->pastes[p].first = n;
            out->pastes[p].nfaces = 0;
        }
        out->faces[n] = entry->face;
        for (i = 0; i < 6; i++) out->uv[6 * (size_t)n + i] = entry->uv[i];
        for (i = 0; i < 3; i++) out->fade[3 * (size_t)n + i] = entry->fade[i];
        angle_sum += entry->angle_error;
        scales[n] = entry->scale_error;
        out->pastes[p].nfaces++;
        n++;
    }
    out->npastes = p + 1;
    out->nentries = n;
    out->removed_entries = removed;
    out->coverage = 1.0;
    out->mean_overdraw = (double)n / L->mesh->nfaces;
    out->mean_angle_error = n > 0 ? angle_sum / n : 0.0;
    out->median_scale_error = tt__median(scales, n);
    tt__free(L->al, scales);
    return tt__lapped_count_cuts(L, out) ? TT_OK : TT_ERROR_OUT_OF_MEMORY;
}

TTDEF tt_result tt_lapped_paste(const tt_mesh *mesh, const float *face_vectors, tt_image *const *patches,
                                int npatches, const tt_lapped_options *options, const tt_allocator *allocator,
                                tt_lapped **out_lapped, tt_error *error)
{
    tt__lapper L;
    tt_lapped_options opts;
    tt_lapped *result;
    tt_result r;
    int max_pastes;
    tt__ok(error);
    if (out_lapped) *out_lapped = NULL;
    if (!mesh || !face_vectors || !patches || !out_lapped)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "tt_lapped_paste: mesh, face_vectors, patches and out_lapped must not be NULL");
    if (tt__check_allocator(allocator, error) != TT_OK) return TT_ERROR_INVALID_ARGUMENT;
    if (npatches < 1)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "tt_lapped_paste: npatches is %d, it must be at least 1", npatches);
    if (options) opts = *options;
    else memset(&opts, 0, sizeof opts);
    if (opts.max_pastes < 0)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "tt_lapped_paste: max_pastes is %d, it must be 0 (default) or more", opts.max_pastes);
    max_pastes = opts.max_pastes ? opts.max_pastes : TT_LAPPED_MAX_PASTES;
    memset(&L, 0, sizeof L);
    L.mesh = mesh;
    L.patches = patches;
    L.npatches = npatches;
    L.field = face_vectors;
    L.isotropic = opts.isotropic != 0;
    L.al = allocator;
    tt_rng_seed(&L.rng, opts.seed, 0x1a99ed);
    r = tt__lapper_setup(&L, max_pastes, error);
    while (r == TT_OK && L.nuncovered > 0) {
        int seed_face, patch, round;
        double seed_weight[3];
        long long added;
        if (L.npastes >= max_pastes || L.npastes > 16.0 * L.expected_pastes + 100.0) {
            r = tt__fail(error, TT_ERROR_NOT_CONVERGED, -1, -1, -1, -1,
                         "%d pastes (about %.3g expected) left %d faces uncovered: the pastes cover too little "
                         "of each face (use a larger scale, or subdivide the mesh)",
                         L.npastes, L.expected_pastes, L.nuncovered);
            break;
        }
        patch = tt__seed_paste(&L, L.npastes, &seed_face, seed_weight);
        tt__grow_patch(&L, L.npastes, patch);
        for (round = 0;; round++) {
            int before;
            r = tt__optimize_patch(&L, seed_face, seed_weight, L.anchor + 2 * (size_t)patch);
            if (r != TT_OK || round + 1 == TT__LAPPED_GROW_ROUNDS) break;
            before = L.npatch_faces;
            tt__grow_patch(&L, L.npastes, patch);
            /* A few faces more keep their predicted map: a new solve would
               hardly move the rest, and it is most of the cost. */
            if (L.npatch_faces - before <= before / TT__LAPPED_RESOLVE_FRACTION) break;
        }
        if (r != TT_OK) {
            r = tt__fail(error, r, -1, -1, -1, -1, "out of memory");
            break;
        }
        patch = tt__least_overlapping_twin(&L, patch);
        added = tt__record_paste(&L, patch);
        if (added < 0) {
            r = tt__fail(error, TT_ERROR_OUT_OF_MEMORY, -1, -1, -1, -1, "out of memory");
            break;
        }
        if (opts.progress && opts.progress((float)((double)L.covered_samples / (double)L.total_samples),
                                           opts.progress_user_data)) {
            r = tt__fail(error, TT_CANCELLED, -1, -1, -1, -1, "cancelled");
            break;
        }
    }
    if (r == TT_OK) {
        int removed = tt__remove_hidden(&L);
        result = TT__ALLOC(L.al, tt_lapped, 1);
        if (result) {
            memset(result, 0, sizeof *result);
            r = tt__lapped_output(&L, removed, result);
        }
        if (!result || r != TT_OK) {
            tt_lapped_free(result);
            result = NULL;
            r = tt__fail(error, TT_ERROR_OUT_OF_MEMORY, -1, -1, -1, -1, "out of memory for the paste list");
        }
        *out_lapped = result;
    }
    tt__lapper_free(&L);
    return r == TT_OK ? tt__ok(error) : r;
}

TTDEF void tt_lapped_free(tt_lapped *lapped)
{
    tt_allocator allocator;
    if (!lapped) return;
    allocator = lapped->allocator;
    tt__free(&allocator, lapped->pastes);
    tt__free(&allocator, lapped->faces);
    tt__free(&allocator, lapped->uv);
    tt__free(&allocator, lapped->fade);
    tt__free(&allocator, lapped);
}

/* ---- Measuring, packing and baking (Praun et al. Sec. 4) ---------------- */

/* phi(v) for one entry: the combination of the face's corners that gives v
   (tt__face_vector_weights, exact for v in the face's plane, its
   least-squares projection otherwise) applied to the entry's corner UVs. A
   face without a map (edges parallel to float precision) gives 0, which the
   caller reports as the worst alignment. */
static void tt__entry_map_vector(const tt_mesh *mesh, int face, const float *uv, const float *vector,
                                 double out[2])
{
    double v[3], w[3];
    v[0] = vector[0]; v[1] = vector[1]; v[2] = vector[2];
    tt__face_vector_weights(mesh, face, v, w);
    out[0] = w[0] * uv[0] + w[1] * uv[2] + w[2] * uv[4];
    out[1] = w[0] * uv[1] + w[1] * uv[3] + w[2] * uv[5];
}

/* Alignment of every entry's map with the field (Sec. 3.4's objective, read
   back from the UVs). phi(T_f) = 0 (a zero field vector, a degenerate face or
   degenerate UVs) counts as the worst case: angle 180 degrees, scale error 1.
   With no entries both errors are 0. Non-finite UVs or field vectors of an
   entry give TT_ERROR_NON_FINITE rather than NaN statistics. */
TTDEF tt_result tt_lapped_measure(const tt_mesh *mesh, const float *face_vectors, const tt_lapped *lapped,
                                  const tt_allocator *allocator, tt_lapped_report *report, tt_error *error)
{
    const tt_allocator *al = allocator;
    double *scale_error = NULL, angle_sum = 0.0;
    unsigned char *covered = NULL;
    int n, e, f, k;

    tt__ok(error);
    if (report) memset(report, 0, sizeof *report);
    if (!mesh || !face_vectors || !lapped || !report)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "tt_lapped_measure needs a mesh, face vectors, pastes and a report (got NULL)");
    if (tt__check_allocator(allocator, error) != TT_OK) return TT_ERROR_INVALID_ARGUMENT;
    if (mesh->min_face_size != 3 || mesh->max_face_size != 3) {
        for (f = 0; f < mesh->nfaces && mesh->face_start[f + 1] - mesh->face_start[f] == 3; f++) {}
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, f, -1, -1, -1,
                        "face %d has %d corners: the alignment measure needs triangles", f,
                        mesh->face_start[f + 1] - mesh->face_start[f]);
    }
    n = lapped->nentries;
    if (n < 0 || (n > 0 && (!lapped->faces || !lapped->uv)))
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "the pastes are inconsistent: %d entries with faces or uv NULL", n);
    for (e = 0; e < n; e++) {
        f = lapped->faces[e];
        if (f < 0 || f >= mesh->nfaces)
            return tt__fail_at(error, TT_ERROR_INDEX_OUT_OF_RANGE, e, -1, -1,
                               "entry %d names face %d, but the mesh has %d faces", e, f, mesh->nfaces);
        for (k = 0; k < 6; k++)
            if (!tt__is_finite(lapped->uv[6 * (size_t)e + k])) {
                tt__fail_at(error, TT_ERROR_NON_FINITE, e, -1, -1, "entry %d (face %d) has a non-finite UV", e, f);
                if (error) error->face = f;
                return TT_ERROR_NON_FINITE;
            }
        for (k = 0; k < 3; k++)
            if (!tt__is_finite(face_vectors[3 * (size_t)f + k])) {
                tt__fail_at(error, TT_ERROR_NON_FINITE, e, -1, -1,
                            "the field vector of face %d (entry %d) is not finite", f, e);
                if (error) error->face = f;
                return TT_ERROR_NON_FINITE;
            }
    }

    scale_error = TT__ALLOC(al, double, n);
    covered = TT__ALLOC(al, unsigned char, mesh->nfaces);
    if (!scale_error || !covered) {
        tt__free(al, scale_error);
        tt__free(al, covered);
        return tt__fail(error, TT_ERROR_OUT_OF_MEMORY, -1, -1, -1, -1, "out of memory measuring %d entries", n);
    }
    memset(covered, 0, (size_t)mesh->nfaces);

    for (e = 0; e < n; e++) {
        double image[2], angle, length;
        f = lapped->faces[e];
        covered[f] = 1;
        tt__entry_map_vector(mesh, f, lapped->uv + 6 * (size_t)e, face_vectors + 3 * (size_t)f, image);
        tt__alignment_error(image, &angle, &length);
        angle_sum += angle;
        scale_error[e] = fabs(length - 1.0);
    }
    if (n > 0) {
        report->mean_angle_error = angle_sum / n;
        report->median_scale_error = tt__median(scale_error, n);
    }
    report->mean_overdraw = mesh->nfaces > 0 ? (double)n / mesh->nfaces : 0.0;
    for (f = 0; f < mesh->nfaces; f++) report->uncovered_faces += !covered[f];

    tt__free(al, scale_error);
    tt__free(al, covered);
    return TT_OK;
}

/* The corner opposite a triangle's longest edge: its largest angle, which
   becomes the right angle of the atlas image (the least change of shape a
   right isosceles image can give). The first such corner on ties. */
static int tt__pack_right_corner(const tt_mesh *mesh, int first)
{
    int best = 0, i, k;
    double best_length = -1.0;
    for (i = 0; i < 3; i++) {
        const float *p = mesh->pos + 3 * (size_t)mesh->corner_vert[first + (i + 1) % 3];
        const float *q = mesh->pos + 3 * (size_t)mesh->corner_vert[first + (i + 2) % 3];
        double length = 0.0;
        for (k = 0; k < 3; k++) length += ((double)q[k] - p[k]) * ((double)q[k] - p[k]);
        if (length > best_length) {
            best_length = length;
            best = i;
        }
    }
    return best;
}

/* Sec. 4 "rendering with a texture atlas" leaves chart layout to the user;
   this is the automatic fallback. In cell-local texel coordinates (s right,
   t up, 0..c) the first triangle of a pair is {s >= m, t >= m, s + t <= c - h}
   and the second its point reflection through the cell centre, with m = g and
   h = sqrt(2) g + 1/2. Offsetting each edge outward by g (tt_lapped_bake's
   gutter) gives s >= 0, t >= 0, s + t <= c - 1/2 and its reflection: gutters
   stay inside the cell and the two halves stay apart by a band that holds
   the texel centres with s + t = c, so no texel centre belongs to two
   gutters. The legs are c - (2 + sqrt 2) g - 1/2 texels; cells below
   (2 + sqrt 2) g + 4 texels (legs under 3.5 texels) are refused. */
TTDEF tt_result tt_atlas_pack_pairs(const tt_mesh *mesh, int size, int gutter, float *corner_uv, tt_error *error)
{
    const double root2 = 1.4142135623730951;
    int f, npairs, per_side, cell;
    double need, m, h, leg;

    if (!mesh || !corner_uv)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "tt_atlas_pack_pairs needs a mesh and an output array (got NULL)");
    if (size < 1 || size > TT_MAX_IMAGE_SIZE)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1, "atlas size %d is outside 1..%d", size,
                        TT_MAX_IMAGE_SIZE);
    if (gutter < 0)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1, "gutter %d is negative", gutter);
    if (tt__require_triangles(mesh, "the atlas packs triangles only", error) != TT_OK)
        return TT_ERROR_INVALID_ARGUMENT;

    npairs = mesh->nfaces / 2 + mesh->nfaces % 2;
    per_side = (int)ceil(sqrt((double)npairs));
    while ((double)per_side * per_side < (double)npairs) per_side++;
    while (per_side > 1 && (double)(per_side - 1) * (per_side - 1) >= (double)npairs) per_side--;
    cell = size / per_side;
    need = ceil((2.0 + root2) * gutter + 4.0);
    if ((double)cell < need) {
        double smallest = need * per_side;
        if (smallest <= TT_MAX_IMAGE_SIZE)
            return tt__fail(error, TT_ERROR_IMAGE_TOO_SMALL, -1, -1, -1, -1,
                            "%d triangles need %d x %d cells of at least %.6g texels for gutter %d: size %d "
                            "gives %d, the smallest size that works is %.6g",
                            mesh->nfaces, per_side, per_side, need, gutter, size, cell, smallest);
        return tt__fail(error, TT_ERROR_IMAGE_TOO_SMALL, -1, -1, -1, -1,
                        "%d triangles need %d x %d cells of at least %.6g texels for gutter %d: that is %.6g "
                        "texels, above the limit of %d; lower the gutter",
                        mesh->nfaces, per_side, per_side, need, gutter, smallest, TT_MAX_IMAGE_SIZE);
    }

    m = gutter;
    h = root2 * gutter + 0.5;
    leg = cell - 2.0 * m - h;
    for (f = 0; f < mesh->nfaces; f++) {
        int pair = f / 2, first = mesh->face_start[f], right = tt__pack_right_corner(mesh, first), k;
        double x0 = (double)(pair % per_side) * cell, y0 = (double)(pair / per_side) * cell;
        double s[3], t[3];
        /* Corners right, right+1, right+2 counter-clockwise, as on the surface. */
        if (f % 2 == 0) {
            s[0] = m; t[0] = m;
            s[1] = m + leg; t[1] = m;
            s[2] = m; t[2] = m + leg;
        } else {
            s[0] = cell - m; t[0] = cell - m;
            s[1] = cell - m - leg; t[1] = cell - m;
            s[2] = cell - m; t[2] = cell - m - leg;
        }
        for (k = 0; k < 3; k++) {
            int corner = first + (right + k) % 3;
            /* Cells fill the image from its top-left (row 0 on top); v = 1 - y / size. */
            corner_uv[2 * (size_t)corner] = (float)((x0 + s[k]) / size);
            corner_uv[2 * (size_t)corner + 1] = (float)(1.0 - (y0 + cell - t[k]) / size);
        }
    }
    return tt__ok(error);
}

/* ---- Triangles in a hashed grid: which ones overlap (the chart atlas, tt_uv_check) ---- */

/* 1 when triangles a and b (x, y of three corners each) overlap by more than
   eps. Separating axes: two convex polygons whose interiors are disjoint are
   separated along a normal of one of their edges, so the triangles overlap
   when no edge normal of either keeps them eps apart. Triangles that share an
   edge or only touch do not overlap, nor does one of zero area. */
static int tt__triangles_overlap(const double *a, const double *b, double eps)
{
    const double *tri[2];
    int t, i, k, j;
    if (tt__orient2(a[0], a[1], a[2], a[3], a[4], a[5]) == 0.0 || tt__orient2(b[0], b[1], b[2], b[3], b[4], b[5]) == 0.0)
        return 0;
    tri[0] = a;
    tri[1] = b;
    for (t = 0; t < 2; t++)
        for (i = 0; i < 3; i++) {
            const double *p = tri[t] + 2 * i, *q = tri[t] + 2 * ((i + 1) % 3);
            double nx = p[1] - q[1], ny = q[0] - p[0], length = sqrt(nx * nx + ny * ny), lo[2], hi[2];
            if (!(length > 0.0)) continue;
            nx /= length;
            ny /= length;
            for (k = 0; k < 2; k++) {
                lo[k] = hi[k] = nx * tri[k][0] + ny * tri[k][1];
                for (j = 1; j < 3; j++) {
                    double d = nx * tri[k][2 * j] + ny * tri[k][2 * j + 1];
                    if (d < lo[k]) lo[k] = d;
                    if (d > hi[k]) hi[k] = d;
                }
            }
            if (hi[0] <= lo[1] + eps || hi[1] <= lo[0] + eps) return 0;
        }
    return 1;
}

/* The x range of triangle t inside the slab y0 <= y <= y1: the ends of its
   edges clipped to the slab (the extremes of a convex polygon are at its
   vertices). 0 when the triangle misses the slab. */
static int tt__triangle_slab(const double *t, double y0, double y1, double *x0, double *x1)
{
    int i, any = 0;
    for (i = 0; i < 3; i++) {
        const double *p = t + 2 * i, *q = t + 2 * ((i + 1) % 3);
        double from = 0.0, to = 1.0, dy = q[1] - p[1], xa, xb;
        if (dy == 0.0) {
            if (p[1] < y0 || p[1] > y1) continue;
        } else {
            double s0 = (y0 - p[1]) / dy, s1 = (y1 - p[1]) / dy;
            if (s0 > s1) { double swap = s0; s0 = s1; s1 = swap; }
            if (s0 > from) from = s0;
            if (s1 < to) to = s1;
            if (from > to) continue;
        }
        xa = p[0] + from * (q[0] - p[0]);
        xb = p[0] + to * (q[0] - p[0]);
        if (!any) *x0 = *x1 = xa;
        any = 1;
        if (xa < *x0) *x0 = xa;
        if (xa > *x1) *x1 = xa;
        if (xb < *x0) *x0 = xb;
        if (xb > *x1) *x1 = xb;
    }
    return any;
}

/* One grid cell a triangle meets, in its bucket's list. */
typedef struct tt__tri_cell {
    int cx, cy;
    int tri;
    int next;               /* next entry of the bucket, -1 at its end */
} tt__tri_cell;

/* Triangles (6 doubles each in xy, the caller's) filed under the square
   cells of side `cell` they meet - exactly those, row by row, not their
   bounding boxes, so a long sliver takes a line of cells - in a hash table
   of cells, so the grid needs no bounds. */
typedef struct tt__tri_grid {
    const tt_allocator *al;
    const double *xy;
    double cell;
    int *bucket;            /* mask + 1 of them: first entry, -1 when empty */
    unsigned mask;
    tt__tri_cell *entry;
    int nentries, capacity;
    int *seen;              /* per triangle: the query that last tested it */
    int ntriangles, query;
} tt__tri_grid;

static void tt__tri_grid_free(tt__tri_grid *g)
{
    tt__free(g->al, g->bucket);
    tt__free(g->al, g->entry);
    tt__free(g->al, g->seen);
    g->bucket = NULL;
    g->entry = NULL;
    g->seen = NULL;
}

/* A grid for triangles 0 .. ntriangles - 1; 0 when out of memory (then
   nothing is held). */
static int tt__tri_grid_init(tt__tri_grid *g, const tt_allocator *al, const double *xy, int ntriangles, double cell)
{
    unsigned buckets = 64;
    int i;
    memset(g, 0, sizeof *g);
    g->al = al;
    g->xy = xy;
    g->cell = cell;
    g->ntriangles = ntriangles;
    while (buckets < (unsigned)ntriangles * 2u && buckets < (1u << 26)) buckets *= 2u;
    g->mask = buckets - 1u;
    g->bucket = TT__ALLOC(al, int, buckets);
    g->seen = TT__ALLOC(al, int, ntriangles);
    if (!g->bucket || !g->seen) {
        tt__tri_grid_free(g);
        return 0;
    }
    for (i = 0; i < (int)buckets; i++) g->bucket[i] = -1;
    for (i = 0; i < ntriangles; i++) g->seen[i] = 0;
    return 1;
}

static unsigned tt__tri_grid_bucket(const tt__tri_grid *g, int cx, int cy)
{
    return ((unsigned)cx * 73856093u ^ (unsigned)cy * 19349663u) & g->mask;
}

/* The cell index of coordinate x, kept inside int. */
static int tt__tri_grid_index(const tt__tri_grid *g, double x)
{
    double i = floor(x / g->cell);
    return i < -1e9 ? -1000000000 : (i > 1e9 ? 1000000000 : (int)i);
}

/* The rows of cells triangle t meets, and in row cy its columns. */
static void tt__tri_grid_rows(const tt__tri_grid *g, const double *t, int *cy0, int *cy1)
{
    double lo = t[1], hi = t[1];
    if (t[3] < lo) lo = t[3];
    if (t[3] > hi) hi = t[3];
    if (t[5] < lo) lo = t[5];
    if (t[5] > hi) hi = t[5];
    *cy0 = tt__tri_grid_index(g, lo);
    *cy1 = tt__tri_grid_index(g, hi);
}

static int tt__tri_grid_columns(const tt__tri_grid *g, const double *t, int cy, int *cx0, int *cx1)
{
    double x0, x1;
    if (!tt__triangle_slab(t, cy * g->cell, (cy + 1.0) * g->cell, &x0, &x1)) return 0;
    *cx0 = tt__tri_grid_index(g, x0);
    *cx1 = tt__tri_grid_index(g, x1);
    return 1;
}

/* File triangle tri under its cells; 0 when out of memory. */
static int tt__tri_grid_insert(tt__tri_grid *g, int tri)
{
    const double *t = g->xy + 6 * (size_t)tri;
    int cy, cy0, cy1, cx, cx0, cx1;
    tt__tri_grid_rows(g, t, &cy0, &cy1);
    for (cy = cy0; cy <= cy1; cy++) {
        if (!tt__tri_grid_columns(g, t, cy, &cx0, &cx1)) continue;
        for (cx = cx0; cx <= cx1; cx++) {
            unsigned b = tt__tri_grid_bucket(g, cx, cy);
            tt__tri_cell *e;
            if (g->nentries == g->capacity) {
                tt__tri_cell *grown =
                    (tt__tri_cell *)tt__grow(g->al, g->entry, &g->capacity, g->nentries + 1, sizeof(tt__tri_cell));
                if (!grown) return 0;
                g->entry = grown;
            }
            e = g->entry + g->nentries;
            e->cx = cx;
            e->cy = cy;
            e->tri = tri;
            e->next = g->bucket[b];
            g->bucket[b] = g->nentries++;
        }
    }
    return 1;
}

/* A filed triangle that overlaps triangle tri (of the same xy) by more than
   eps, or -1; each filed triangle is tested once however many cells it
   shares with tri. */
static int tt__tri_grid_overlap(tt__tri_grid *g, int tri, double eps)
{
    const double *t = g->xy + 6 * (size_t)tri;
    int cy, cy0, cy1, cx, cx0, cx1, e;
    if (g->query == INT_MAX) {
        /* The stamps wrap: forget them all once. */
        memset(g->seen, 0, sizeof(int) * (size_t)g->ntriangles);
        g->query = 0;
    }
    g->query++;
    tt__tri_grid_rows(g, t, &cy0, &cy1);
    for (cy = cy0; cy <= cy1; cy++) {
        if (!tt__tri_grid_columns(g, t, cy, &cx0, &cx1)) continue;
        for (cx = cx0; cx <= cx1; cx++)
            for (e = g->bucket[tt__tri_grid_bucket(g, cx, cy)]; e >= 0; e = g->entry[e].next) {
                const tt__tri_cell *c = g->entry + e;
                if (c->cx != cx || c->cy != cy || g->seen[c->tri] == g->query) continue;
                g->seen[c->tri] = g->query;
                if (tt__triangles_overlap(t, g->xy + 6 * (size_t)c->tri, eps)) return c->tri;
            }
    }
    return -1;
}

/* Empty the grid for the next set of triangles (its buckets reset through
   its own entries: time for what was filed, not for the table). */
static void tt__tri_grid_clear(tt__tri_grid *g)
{
    int e;
    for (e = 0; e < g->nentries; e++) g->bucket[tt__tri_grid_bucket(g, g->entry[e].cx, g->entry[e].cy)] = -1;
    g->nentries = 0;
}

/* ---- The chart atlas ---- */

/* u, v: an orthonormal basis of the plane perpendicular to the unit vector
   n, with u x v = n, so that counter-clockwise about n stays
   counter-clockwise in (u, v). u starts from the world axis least along n. */
static void tt__plane_frame(const double *n, double *u, double *v)
{
    int k, least = 0;
    for (k = 1; k < 3; k++)
        if (fabs(n[k]) < fabs(n[least])) least = k;
    u[0] = u[1] = u[2] = 0.0;
    u[least] = 1.0;
    tt__project3(u, n, u);
    tt__normalize3(u);
    tt__cross3(n, u, v);
}

/* A chart: faces members[first .. first + count - 1]; once shaped, its
   corners (xy) lie in [0, width] x [0, height], mesh units. */
typedef struct tt__chart {
    int first, count;
    double width, height;
} tt__chart;

/* Packing order: taller first, then wider, then by index (deterministic). */
typedef struct tt__chart_order {
    double height, width;
    int chart;
} tt__chart_order;

#define TT__CHART_BEFORE(a, b)                                                                                 \
    ((a).height > (b).height ||                                                                               \
     ((a).height == (b).height && ((a).width > (b).width || ((a).width == (b).width && (a).chart < (b).chart))))
TT__DEFINE_HEAPSORT_BY(tt__sort_chart_order, tt__chart_order, TT__CHART_BEFORE)

/* Face `face`'s corners projected on the plane (origin, u, v): 6 doubles. */
static void tt__chart_project(const tt_mesh *mesh, int face, const double *origin, const double *u, const double *v,
                              double *out)
{
    int k;
    for (k = 0; k < 3; k++) {
        const float *p = mesh->pos + 3 * (size_t)mesh->corner_vert[mesh->face_start[face] + k];
        double d[3];
        d[0] = p[0] - origin[0];
        d[1] = p[1] - origin[1];
        d[2] = p[2] - origin[2];
        out[2 * k] = tt__dot3(d, u);
        out[2 * k + 1] = tt__dot3(d, v);
    }
}

/* Bounds (lo x, lo y, hi x, hi y) of a chart's corners mapped by
   (x, y) -> (a x - b y, b x + a y). */
static void tt__chart_bounds(const double *xy, const int *faces, int count, double a, double b, double box[4])
{
    int i, k;
    box[0] = box[1] = 1e300;
    box[2] = box[3] = -1e300;
    for (i = 0; i < count; i++)
        for (k = 0; k < 3; k++) {
            const double *p = xy + 6 * (size_t)faces[i] + 2 * k;
            double x = a * p[0] - b * p[1], y = b * p[0] + a * p[1];
            if (x < box[0]) box[0] = x;
            if (y < box[1]) box[1] = y;
            if (x > box[2]) box[2] = x;
            if (y > box[3]) box[3] = y;
        }
}

/* Angles tried per quarter turn for a chart's smallest bounding box. */
#define TT__CHART_ANGLES 16

/* Scale a chart's projection to its surface area (the projection shrank
   each face by the cosine of its tilt: scaled back, the chart's density is
   its faces' mean), turn it to its smallest bounding box among
   TT__CHART_ANGLES angles (a quarter turn more when it is then taller than
   wide: shelves of flat boxes waste less), and move it to start at (0, 0).
   Turns and a positive scale keep every face's winding. */
static void tt__chart_shape(const double *area, const int *members, double *xy, tt__chart *chart)
{
    const int *faces = members + chart->first;
    double projected = 0.0, surface = 0.0, scale = 1.0, best = -1.0, best_angle = 0.0, a, b, box[4];
    int i, k;
    for (i = 0; i < chart->count; i++) {
        const double *t = xy + 6 * (size_t)faces[i];
        projected += 0.5 * fabs(tt__orient2(t[0], t[1], t[2], t[3], t[4], t[5]));
        surface += area[faces[i]];
    }
    if (projected > 0.0 && surface > 0.0) scale = sqrt(surface / projected);
    for (k = 0; k < TT__CHART_ANGLES; k++) {
        double angle = k * (0.5 * TT__PI) / TT__CHART_ANGLES, box_area;
        tt__chart_bounds(xy, faces, chart->count, cos(angle), sin(angle), box);
        box_area = (box[2] - box[0]) * (box[3] - box[1]);
        if (best < 0.0 || box_area < best) {
            best = box_area;
            best_angle = angle;
        }
    }
    a = cos(best_angle) * scale;
    b = sin(best_angle) * scale;
    tt__chart_bounds(xy, faces, chart->count, a, b, box);
    if (box[3] - box[1] > box[2] - box[0]) {
        double turned = a;   /* (a, b) turned a quarter: cos(t + 90) = -sin t, sin(t + 90) = cos t */
        a = -b;
        b = turned;
        tt__chart_bounds(xy, faces, chart->count, a, b, box);
    }
    for (i = 0; i < chart->count; i++)
        for (k = 0; k < 3; k++) {
            double *p = xy + 6 * (size_t)faces[i] + 2 * k, x = p[0];
            p[0] = a * x - b * p[1] - box[0];
            p[1] = b * x + a * p[1] - box[1];
        }
    chart->width = box[2] - box[0];
    chart->height = box[3] - box[1];
}

/* A chart's box at scale s (texels per mesh unit): the chart plus `gutter`
   texels on every side, whole texels, at least one. */
static double tt__chart_box(double extent, double s, int gutter)
{
    double texels = ceil(s * extent + 2.0 * gutter);
    return texels < 1.0 ? 1.0 : texels;
}

/* Shelf packing: the boxes in `order` left to right along a shelf, the next
   shelf below the tallest box of the last (image rows grow down). 1 when
   all fit in size x size; then (x, y), if given, get each chart's box's
   top-left texel. */
static int tt__pack_shelves(const tt__chart *charts, const tt__chart_order *order, int n, double s, int gutter,
                            int size, int *x, int *y)
{
    int i, at_x = 0, at_y = 0, shelf = 0;
    for (i = 0; i < n; i++) {
        const tt__chart *chart = charts + order[i].chart;
        double w = tt__chart_box(chart->width, s, gutter), h = tt__chart_box(chart->height, s, gutter);
        if (w > size || h > size) return 0;
        if (at_x + (int)w > size) {
            at_y += shelf;
            at_x = 0;
            shelf = 0;
        }
        if (at_y + (int)h > size) return 0;
        if (x) {
            x[order[i].chart] = at_x;
            y[order[i].chart] = at_y;
        }
        at_x += (int)w;
        if ((int)h > shelf) shelf = (int)h;
    }
    return 1;
}

/* The charts of the mesh (see tt_atlas_pack_charts): chart[f] for every
   face, members listing each chart's faces in the order they joined, xy
   their projections (6 per face). Returns the number of charts, or -1 when
   out of memory. */
static int tt__grow_charts(const tt_mesh *mesh, const double *normal, const double *area, tt__tri_grid *grid,
                           double eps, int *chart, int *tried, int *members, tt__chart *charts, double *xy)
{
    const double cos_cone = cos(TT_ATLAS_CHART_CONE * TT__PI / 180.0), up[3] = {0.0, 0.0, 1.0};
    int nf = mesh->nfaces, ncharts = 0, placed = 0, zero_area, seed, f, k;
    for (f = 0; f < nf; f++) {
        chart[f] = -1;
        tried[f] = -1;
    }
    /* Faces with an area seed the charts; a face of zero area has no normal
       and never overlaps, so it joins the first chart that reaches it, and
       one no chart reached (all its neighbours have zero area too) makes a
       chart of its own afterwards. */
    for (zero_area = 0; zero_area < 2; zero_area++)
        for (seed = 0; seed < nf; seed++) {
            const double *axis = zero_area ? up : normal + 3 * (size_t)seed;
            double u[3], v[3], origin[3];
            int c = ncharts, head;
            if (chart[seed] >= 0 || (area[seed] == 0.0) != zero_area) continue;
            ncharts++;
            tt__plane_frame(axis, u, v);
            tt__face_centroid(mesh, seed, origin);
            charts[c].first = placed;
            tt__chart_project(mesh, seed, origin, u, v, xy + 6 * (size_t)seed);
            if (!tt__tri_grid_insert(grid, seed)) return -1;
            chart[seed] = c;
            members[placed++] = seed;
            /* Breadth-first: the chart stays round, its border short. */
            for (head = charts[c].first; head < placed; head++) {
                int from = members[head];
                for (k = 0; k < 3; k++) {
                    int twin = mesh->twin[mesh->face_start[from] + k], face;
                    if (twin < 0) continue;
                    face = mesh->corner_face[twin];
                    if (chart[face] >= 0 || tried[face] == c) continue;
                    tried[face] = c;   /* a refusal stands: the chart only grows */
                    if (area[face] > 0.0 && tt__dot3(normal + 3 * (size_t)face, axis) < cos_cone) continue;
                    tt__chart_project(mesh, face, origin, u, v, xy + 6 * (size_t)face);
                    if (area[face] > 0.0 && tt__tri_grid_overlap(grid, face, eps) >= 0) continue;
                    if (!tt__tri_grid_insert(grid, face)) return -1;
                    chart[face] = c;
                    members[placed++] = face;
                }
            }
            charts[c].count = placed - charts[c].first;
            tt__tri_grid_clear(grid);
        }
    return ncharts;
}

/* Sec. 4 "rendering with a texture atlas", the charts made automatically;
   see the declaration for the method. The scale is bisected between a size
   at which every chart is under a millionth of a texel (when even that does
   not fit, nothing does) and the one at which the charts' boxes alone would
   fill the atlas. */
TTDEF tt_result tt_atlas_pack_charts(const tt_mesh *mesh, int size, int gutter, const tt_allocator *allocator,
                                     float *corner_uv, tt_chart_atlas_report *report, tt_error *error)
{
    const tt_allocator *al = allocator;
    double *normal = NULL, *area = NULL, *xy = NULL;
    int *chart = NULL, *tried = NULL, *members = NULL, *box_x = NULL, *box_y = NULL;
    tt__chart *charts = NULL;
    tt__chart_order *order = NULL;
    tt__tri_grid grid;
    double lo[3], hi[3], edges = 0.0, longest = 0.0, surface = 0.0, boxes = 0.0, largest = 0.0;
    double cell, diagonal, tiny, s_lo, s_hi;
    int nf, f, k, c, i, ncharts;
    tt_result result;

    tt__ok(error);
    if (report) memset(report, 0, sizeof *report);
    if (!mesh || !corner_uv)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "tt_atlas_pack_charts needs a mesh and an output array (got NULL)");
    if (tt__check_allocator(allocator, error) != TT_OK) return TT_ERROR_INVALID_ARGUMENT;
    if (size < 1 || size > TT_MAX_IMAGE_SIZE)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1, "atlas size %d is outside 1..%d", size,
                        TT_MAX_IMAGE_SIZE);
    if (gutter < 0)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1, "gutter %d is negative", gutter);
    nf = mesh->nfaces;
    if (tt__require_triangles(mesh, "the atlas packs triangles only", error) != TT_OK)
        return TT_ERROR_INVALID_ARGUMENT;

    memset(&grid, 0, sizeof grid);
    normal = TT__ALLOC(al, double, 3 * (size_t)nf);
    area = TT__ALLOC(al, double, nf);
    xy = TT__ALLOC(al, double, 6 * (size_t)nf);
    chart = TT__ALLOC(al, int, nf);
    tried = TT__ALLOC(al, int, nf);
    members = TT__ALLOC(al, int, nf);
    charts = TT__ALLOC(al, tt__chart, nf);
    order = TT__ALLOC(al, tt__chart_order, nf);
    box_x = TT__ALLOC(al, int, nf);
    box_y = TT__ALLOC(al, int, nf);
    if (!normal || !area || !xy || !chart || !tried || !members || !charts || !order || !box_x || !box_y ||
        !tt__tri_grid_init(&grid, al, xy, nf, 1.0))
        goto out_of_memory;

    /* The grid's cells: the mean edge, but no face across more than 32 of
       them (very uneven meshes), so every face meets a bounded number. */
    lo[0] = lo[1] = lo[2] = 1e300;
    hi[0] = hi[1] = hi[2] = -1e300;
    for (f = 0; f < nf; f++) {
        if (tt__face_normal_d(mesh, f, normal + 3 * (size_t)f)) area[f] = tt__face_area_d(mesh, f);
        else area[f] = 0.0;
        surface += area[f];
        for (k = 0; k < 3; k++) {
            const float *p = mesh->pos + 3 * (size_t)mesh->corner_vert[mesh->face_start[f] + k];
            const float *q = mesh->pos + 3 * (size_t)mesh->corner_vert[mesh->face_start[f] + (k + 1) % 3];
            double d[3], length;
            int j;
            tt__sub3f(q, p, d);
            length = tt__length3(d);
            edges += length;
            if (length > longest) longest = length;
            for (j = 0; j < 3; j++) {
                if (p[j] < lo[j]) lo[j] = p[j];
                if (p[j] > hi[j]) hi[j] = p[j];
            }
        }
    }
    cell = nf > 0 ? edges / (3.0 * nf) : 1.0;
    if (cell < longest / 32.0) cell = longest / 32.0;
    if (!(cell > 0.0)) cell = 1.0;
    grid.cell = cell;
    diagonal = nf > 0 ? sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                             (hi[2] - lo[2]) * (hi[2] - lo[2]))
                      : 1.0;
    /* Overlaps smaller than this are rounding (neighbours share an edge). */
    ncharts = tt__grow_charts(mesh, normal, area, &grid, 1e-9 * (diagonal > 0.0 ? diagonal : 1.0), chart, tried,
                              members, charts, xy);
    if (ncharts < 0) goto out_of_memory;

    for (c = 0; c < ncharts; c++) {
        tt__chart_shape(area, members, xy, charts + c);
        order[c].height = charts[c].height;
        order[c].width = charts[c].width;
        order[c].chart = c;
        boxes += charts[c].width * charts[c].height;
        if (charts[c].width > largest) largest = charts[c].width;
    }
    tt__sort_chart_order(order, ncharts);

    tiny = largest > 0.0 ? 1e-6 / largest : 1.0;
    if (!tt__pack_shelves(charts, order, ncharts, tiny, gutter, size, NULL, NULL)) {
        /* The smallest size that holds them: tiny boxes pack monotonically in the size. */
        int fits = TT_MAX_IMAGE_SIZE + 1, fails = size;
        if (tt__pack_shelves(charts, order, ncharts, tiny, gutter, TT_MAX_IMAGE_SIZE, NULL, NULL)) {
            fits = TT_MAX_IMAGE_SIZE;
            while (fits - fails > 1) {
                int mid = fails + (fits - fails) / 2;
                if (tt__pack_shelves(charts, order, ncharts, tiny, gutter, mid, NULL, NULL)) fits = mid;
                else fails = mid;
            }
            result = tt__fail(error, TT_ERROR_IMAGE_TOO_SMALL, -1, -1, -1, -1,
                              "%d charts need at least %d x %d texels each for gutter %d: they do not fit %d x %d, "
                              "the smallest size that works is %d (with the charts shrunk to nothing)",
                              ncharts, 2 * gutter + 1, 2 * gutter + 1, gutter, size, size, fits);
        } else {
            result = tt__fail(error, TT_ERROR_IMAGE_TOO_SMALL, -1, -1, -1, -1,
                              "%d charts need at least %d x %d texels each for gutter %d: more than the limit of %d "
                              "x %d holds; lower the gutter",
                              ncharts, 2 * gutter + 1, 2 * gutter + 1, gutter, TT_MAX_IMAGE_SIZE, TT_MAX_IMAGE_SIZE);
        }
        goto done;
    }
    s_lo = tiny;
    s_hi = boxes > 0.0 ? size / sqrt(boxes) : tiny;
    if (s_hi < s_lo) s_hi = s_lo;
    if (tt__pack_shelves(charts, order, ncharts, s_hi, gutter, size, NULL, NULL)) s_lo = s_hi;
    for (i = 0; i < 100 && s_hi - s_lo > 1e-6 * s_hi; i++) {
        double mid = 0.5 * (s_lo + s_hi);
        if (tt__pack_shelves(charts, order, ncharts, mid, gutter, size, NULL, NULL)) s_lo = mid;
        else s_hi = mid;
    }
    tt__pack_shelves(charts, order, ncharts, s_lo, gutter, size, box_x, box_y);

    for (c = 0; c < ncharts; c++)
        for (i = 0; i < charts[c].count; i++) {
            int face = members[charts[c].first + i];
            for (k = 0; k < 3; k++) {
                const double *p = xy + 6 * (size_t)face + 2 * k;
                int corner = mesh->face_start[face] + k;
                /* The chart's y grows up, image rows down: its top at the box's top. */
                double tx = box_x[c] + gutter + s_lo * p[0];
                double ty = box_y[c] + gutter + s_lo * (charts[c].height - p[1]);
                corner_uv[2 * (size_t)corner] = tt__clamp_f((float)(tx / size), 0.0f, 1.0f);
                corner_uv[2 * (size_t)corner + 1] = tt__clamp_f((float)(1.0 - ty / size), 0.0f, 1.0f);
            }
        }
    if (report) {
        report->ncharts = ncharts;
        report->texels_per_unit = s_lo;
        report->fill = s_lo * s_lo * surface / ((double)size * size);
    }
    result = tt__ok(error);
    goto done;

out_of_memory:
    result = tt__fail(error, TT_ERROR_OUT_OF_MEMORY, -1, -1, -1, -1, "out of memory making a chart atlas of %d faces",
                      nf);
done:
    tt__tri_grid_free(&grid);
    tt__free(al, normal);
    tt__free(al, area);
    tt__free(al, xy);
    tt__free(al, chart);
    tt__free(al, tried);
    tt__free(al, members);
    tt__free(al, charts);
    tt__free(al, order);
    tt__free(al, box_x);
    tt__free(al, box_y);
    return result;
}

TTDEF tt_result tt_uv_check(const tt_mesh *mesh, const float *corner_uv, const tt_allocator *allocator,
                            tt_uv_report *report, tt_error *error)
{
    const tt_allocator *al = allocator;
    double *xy = NULL;
    tt__tri_grid grid;
    int nf, f, k, positive = 0, negative = 0, side;
    tt_result result = TT_OK;

    tt__ok(error);
    if (!mesh || !corner_uv || !report)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "tt_uv_check needs a mesh, UVs and a report (got NULL)");
    if (tt__check_allocator(allocator, error) != TT_OK) return TT_ERROR_INVALID_ARGUMENT;
    memset(report, 0, sizeof *report);
    report->problem = TT_UV_USABLE;
    report->face = report->other_face = -1;
    nf = mesh->nfaces;
    if (tt__require_triangles(mesh, "the UV check takes triangles only", error) != TT_OK)
        return TT_ERROR_INVALID_ARGUMENT;
    for (f = 0; f < nf && report->problem == TT_UV_USABLE; f++)
        for (k = 0; k < 6; k++)
            if (!tt__is_finite(corner_uv[6 * (size_t)f + k])) {
                report->problem = TT_UV_NON_FINITE;
                report->face = f;
                break;
            }
    for (f = 0; f < nf && report->problem == TT_UV_USABLE; f++)
        for (k = 0; k < 6; k++)
            if (!(corner_uv[6 * (size_t)f + k] >= 0.0f && corner_uv[6 * (size_t)f + k] <= 1.0f)) {
                report->problem = TT_UV_OUTSIDE;
                report->face = f;
                break;
            }
    if (report->problem != TT_UV_USABLE) return TT_OK;

    xy = TT__ALLOC(al, double, 6 * (size_t)nf);
    if (!xy) goto out_of_memory;
    for (f = 0; f < nf; f++) {
        double *t = xy + 6 * (size_t)f, area2;
        for (k = 0; k < 6; k++) t[k] = corner_uv[6 * (size_t)f + k];
        area2 = tt__orient2(t[0], t[1], t[2], t[3], t[4], t[5]);
        positive += area2 > 0.0;
        negative += area2 < 0.0;
        if (area2 == 0.0 && report->problem == TT_UV_USABLE) {
            report->problem = TT_UV_DEGENERATE;
            report->face = f;
        }
    }
    /* Most triangles decide the winding; the rest are flipped. */
    side = positive >= negative ? 1 : -1;
    report->flipped_faces = side > 0 ? negative : positive;
    for (f = 0; f < nf && report->problem == TT_UV_USABLE; f++) {
        const double *t = xy + 6 * (size_t)f;
        if (tt__orient2(t[0], t[1], t[2], t[3], t[4], t[5]) * side < 0.0) {
            report->problem = TT_UV_FLIPPED;
            report->face = f;
        }
    }
    if (report->problem != TT_UV_USABLE) goto done;

    /* About one cell per triangle over the unit square. */
    if (!tt__tri_grid_init(&grid, al, xy, nf, 1.0 / tt__clamp_i((int)ceil(sqrt((double)nf)), 1, 4096)))
        goto out_of_memory;
    for (f = 0; f < nf; f++) {
        int other = tt__tri_grid_overlap(&grid, f, 1e-6);
        if (other >= 0) {
            report->problem = TT_UV_OVERLAP;
            report->face = other;
            report->other_face = f;
            break;
        }
        if (!tt__tri_grid_insert(&grid, f)) {
            tt__tri_grid_free(&grid);
            goto out_of_memory;
        }
    }
    tt__tri_grid_free(&grid);
    goto done;

out_of_memory:
    result = tt__fail(error, TT_ERROR_OUT_OF_MEMORY, -1, -1, -1, -1, "out of memory checking the UVs of %d faces", nf);
    memset(report, 0, sizeof *report);
    report->face = report->other_face = -1;
done:
    tt__free(al, xy);
    return result;
}

/* State of one face's bake, shared by its raster callbacks. */
typedef struct tt__bake {
    const tt_lapped *lapped;
    tt_image *const *patches;
    const int *items;           /* pairs (entry, patch) of this face, in paste order */
    int nitems;
    double x[3], y[3];          /* the face's atlas triangle, pixels */
    double inverse_area2;       /* 1 / twice its signed area */
    double gutter;              /* texels */
    int inside;                 /* 1: rasterising the triangle itself, 0: its gutter */
    float *state;               /* per texel: -1 inside a triangle, else distance of the gutter
                                   that wrote it, +infinity for empty */
    tt_image *atlas;
} tt__bake;

/* Paste item k of the face sampled at barycentric weights w (weights outside
   [0, 1] extend the paste's linear map across the face's edges). */
static void tt__bake_sample(const tt__bake *b, int k, const double w[3], float sample[4])
{
    const float *uv = b->lapped->uv + 6 * (size_t)b->items[2 * k];
    const tt_image *patch = b->patches[b->items[2 * k + 1]];
    double u = 0.0, v = 0.0, px, py;
    int i;
    for (i = 0; i < 3; i++) {
        u += w[i] * uv[2 * i];
        v += w[i] * uv[2 * i + 1];
    }
    /* The sampler clamps; clamping here first keeps the float conversion
       defined for far extrapolations. */
    px = u * patch->width;
    py = (1.0 - v) * patch->height;
    px = px < -1.0 ? -1.0 : (px > patch->width + 1.0 ? patch->width + 1.0 : px);
    py = py < -1.0 ? -1.0 : (py > patch->height + 1.0 ? patch->height + 1.0 : py);
    tt_image_sample_bilinear(patch, (float)px, (float)py, sample);
    if (b->lapped->fade) {
        /* premultiplied: the fade scales colour and alpha alike; clamped, as
           the gutter's extrapolated weights may carry it past [0, 1] */
        const float *fade = b->lapped->fade + 3 * (size_t)b->items[2 * k];
        double f = w[0] * fade[0] + w[1] * fade[1] + w[2] * fade[2];
        f = f < 0.0 ? 0.0 : (f > 1.0 ? 1.0 : f);
        for (i = 0; i < 4; i++) sample[i] = (float)(sample[i] * f);
    }
}

/* Pastes sampled from the top down before compositing, at most. */
#define TT__BAKE_CACHE 32

/* Composite the face's pastes at barycentric weights w (Sec. 4: the pastes
   drawn in order with "over"), premultiplied. A paste that is opaque here
   (alpha exactly 1) hides everything beneath it - "over" then gives the
   paste itself, exactly - so the walk goes down from the topmost paste and
   composites upward from the first opaque one: the same bits as drawing
   every paste, at the cost of the one or two on top instead of the face's
   whole overdraw. */
static void tt__bake_composite(const tt__bake *b, const double w[3], float out[4])
{
    float cache[TT__BAKE_CACHE][4];
    int n = b->nitems, k, cached = 0, opaque = 0;
    out[0] = out[1] = out[2] = out[3] = 0.0f;
    for (k = n - 1; k >= 0 && cached < TT__BAKE_CACHE && !opaque; k--) {
        tt__bake_sample(b, k, w, cache[cached]);
        opaque = cache[cached][3] == 1.0f;
        cached++;
    }
    if (opaque || cached == n) {
        while (cached > 0) tt_rgba_over(out, cache[--cached]);
        return;
    }
    for (k = 0; k < n; k++) {
        float sample[4];
        tt__bake_sample(b, k, w, sample);
        tt_rgba_over(out, sample);
    }
}

static void tt__bake_texel(int x, int y, const float barycentric[3], void *user_data)
{
    tt__bake *b = (tt__bake *)user_data;
    size_t texel = (size_t)y * (size_t)b->atlas->width + (size_t)x;
    double px = x + 0.5, py = y + 0.5, w[3];
    float distance = -1.0f;
    (void)barycentric;   /* those of the fan triangle in the gutter pass: recomputed for the face */
    /* Texels inside any triangle keep its colour. */
    if (!b->inside && b->state[texel] < 0.0f) return;
    w[0] = ((b->x[1] - px) * (b->y[2] - py) - (b->x[2] - px) * (b->y[1] - py)) * b->inverse_area2;
    w[1] = ((b->x[2] - px) * (b->y[0] - py) - (b->x[0] - px) * (b->y[2] - py)) * b->inverse_area2;
    w[2] = 1.0 - w[0] - w[1];
    if (!b->inside) {
        /* Between gutters the nearer triangle wins, the later face on ties. */
        double d = 0.0;
        if (w[0] < 0.0 || w[1] < 0.0 || w[2] < 0.0) {
            double d1 = tt__point_segment_distance(px, py, b->x[0], b->y[0], b->x[1], b->y[1]);
            double d2 = tt__point_segment_distance(px, py, b->x[1], b->y[1], b->x[2], b->y[2]);
            double d3 = tt__point_segment_distance(px, py, b->x[2], b->y[2], b->x[0], b->y[0]);
            d = d1 < d2 ? d1 : d2;
            d = d < d3 ? d : d3;
        }
        if (d > b->gutter || (float)d > b->state[texel]) return;
        distance = (float)d;
    }
    b->state[texel] = distance;
    tt__bake_composite(b, w, b->atlas->pixels + 4 * texel);
}

/* Keep the part of the convex polygon p (n vertices) where
   nx * x + ny * y <= limit; returns the new count (at most n + 1). */
static int tt__bake_clip(const double *p, int n, double nx, double ny, double limit, double *out)
{
    int i, count = 0;
    for (i = 0; i < n; i++) {
        const double *a = p + 2 * i, *c = p + 2 * ((i + 1) % n);
        double da = nx * a[0] + ny * a[1] - limit, dc = nx * c[0] + ny * c[1] - limit;
        if (da <= 0.0) {
            out[2 * count] = a[0];
            out[2 * count + 1] = a[1];
            count++;
        }
        if ((da < 0.0 && dc > 0.0) || (da > 0.0 && dc < 0.0)) {
            double t = da / (da - dc);
            out[2 * count] = a[0] + t * (c[0] - a[0]);
            out[2 * count + 1] = a[1] + t * (c[1] - a[1]);
            count++;
        }
    }
    return count;
}

/* The texels of one face's gutter: its triangle with every edge moved out by
   g, intersected with its bounding box grown by g (which cuts off the long
   mitre spikes of thin triangles) and with the image, rasterised as a fan;
   the callback keeps texels within g of the triangle. */
static void tt__bake_gutter(tt__bake *b)
{
    double poly[2 * 8], tmp[2 * 8], lo_x, hi_x, lo_y, hi_y, g = b->gutter;
    int n = 4, i, k;
    lo_x = hi_x = b->x[0];
    lo_y = hi_y = b->y[0];
    for (i = 1; i < 3; i++) {
        if (b->x[i] < lo_x) lo_x = b->x[i];
        if (b->x[i] > hi_x) hi_x = b->x[i];
        if (b->y[i] < lo_y) lo_y = b->y[i];
        if (b->y[i] > hi_y) hi_y = b->y[i];
    }
    lo_x = lo_x - g > 0.0 ? lo_x - g : 0.0;
    lo_y = lo_y - g > 0.0 ? lo_y - g : 0.0;
    hi_x = hi_x + g < b->atlas->width ? hi_x + g : (double)b->atlas->width;
    hi_y = hi_y + g < b->atlas->height ? hi_y + g : (double)b->atlas->height;
    if (!(lo_x < hi_x && lo_y < hi_y)) return;
    poly[0] = lo_x; poly[1] = lo_y;
    poly[2] = hi_x; poly[3] = lo_y;
    poly[4] = hi_x; poly[5] = hi_y;
    poly[6] = lo_x; poly[7] = hi_y;
    for (i = 0; i < 3 && n >= 3; i++) {
        int j = (i + 1) % 3, o = (i + 2) % 3;
        double nx = b->y[j] - b->y[i], ny = b->x[i] - b->x[j], length = sqrt(nx * nx + ny * ny);
        nx /= length;
        ny /= length;
        if (nx * (b->x[o] - b->x[i]) + ny * (b->y[o] - b->y[i]) > 0.0) { nx = -nx; ny = -ny; }
        n = tt__bake_clip(poly, n, nx, ny, nx * b->x[i] + ny * b->y[i] + g, tmp);
        memcpy(poly, tmp, (size_t)n * 2 * sizeof(double));
    }
    for (k = 1; k + 1 < n; k++) {
        float xy[6];
        xy[0] = (float)poly[0]; xy[1] = (float)poly[1];
        xy[2] = (float)poly[2 * k]; xy[3] = (float)poly[2 * k + 1];
        xy[4] = (float)poly[2 * k + 2]; xy[5] = (float)poly[2 * k + 3];
        tt_raster_triangle(xy, b->atlas->width, b->atlas->height, tt__bake_texel, b);
    }
}

/* A face whose atlas triangle is thinner than this (texels) gets no gutter of
   its own: extrapolating g texels across it would multiply its barycentrics,
   and their rounding, by g / height. The final fill covers its surroundings. */
#define TT__BAKE_MIN_HEIGHT (1.0 / 16.0)

/* Sec. 4 "rendering with a texture atlas": "the texture paste operations are
   composited into the atlas charts". Per face, its entries in paste order
   (a CSR list built once), composited at every texel of its atlas triangle
   and, extrapolated, of its gutter; then un-premultiplied, and every texel
   still empty takes the colour of the nearest written one (breadth-first over
   4-neighbours from all written texels at once, O(texels)) so that bilinear
   filtering and mipmaps at chart borders read chart colours (the sampling
   problems Sec. 4 lists for atlases). Temporary memory comes from the mesh's
   allocator, all of it before the atlas is touched. */
TTDEF tt_result tt_lapped_bake(const tt_mesh *mesh, const tt_lapped *lapped, tt_image *const *patches,
                               int npatches, const float *corner_uv, const tt_bake_options *options,
                               const tt_allocator *allocator, tt_image *atlas, tt_error *error)
{
    const tt_allocator *al = allocator;
    tt_bake_options opt;
    int gutter;
    tt_result result;
    tt__bake bake;
    int *start = NULL, *fill = NULL, *items = NULL, *queue = NULL;
    float *state = NULL;
    size_t texels, t, total = 0, head = 0, tail = 0;
    float empty = tt__infinity();
    int f, p, e, k, c, width, height;

    tt__ok(error);
    if (!mesh || !lapped || !patches || !corner_uv || !atlas)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "tt_lapped_bake needs a mesh, pastes, patches, UVs and an atlas (got NULL)");
    if (tt__check_allocator(allocator, error) != TT_OK) return TT_ERROR_INVALID_ARGUMENT;
    if (options) opt = *options;
    else memset(&opt, 0, sizeof opt);
    gutter = opt.gutter;
    if (!atlas->pixels || atlas->width <= 0 || atlas->height <= 0)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "the atlas is empty: create it with tt_image_create first");
    if (atlas->width > TT_MAX_IMAGE_SIZE || atlas->height > TT_MAX_IMAGE_SIZE)
        return tt__fail(error, TT_ERROR_TOO_LARGE, -1, -1, -1, -1, "the atlas is %d x %d texels, above %d",
                        atlas->width, atlas->height, TT_MAX_IMAGE_SIZE);
    if (gutter < 0)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1, "gutter %d is negative", gutter);
    if (npatches < 1)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1, "npatches is %d: need at least 1",
                        npatches);
    for (p = 0; p < npatches; p++)
        if (!patches[p] || !patches[p]->pixels || patches[p]->width <= 0 || patches[p]->height <= 0)
            return tt__fail_at(error, TT_ERROR_INVALID_ARGUMENT, p, -1, -1, "patch %d is NULL or empty", p);
    if (tt__require_triangles(mesh, "baking needs triangles", error) != TT_OK)
        return TT_ERROR_INVALID_ARGUMENT;
    for (c = 0; c < 2 * mesh->ncorners; c++)
        if (!tt__is_finite(corner_uv[c]))
            return tt__fail(error, TT_ERROR_NON_FINITE, mesh->corner_face[c / 2], c / 2, -1, -1,
                            "corner %d (face %d) has a non-finite atlas UV", c / 2, mesh->corner_face[c / 2]);
    if (lapped->npastes < 0 || lapped->nentries < 0 || (lapped->npastes > 0 && !lapped->pastes) ||
        (lapped->nentries > 0 && (!lapped->faces || !lapped->uv)))
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "the pastes are inconsistent: %d pastes, %d entries, some arrays NULL or counts negative",
                        lapped->npastes, lapped->nentries);
    for (e = 0; e < lapped->nentries; e++) {
        f = lapped->faces[e];
        if (f < 0 || f >= mesh->nfaces)
            return tt__fail_at(error, TT_ERROR_INDEX_OUT_OF_RANGE, e, -1, -1,
                               "entry %d names face %d, but the mesh has %d faces", e, f, mesh->nfaces);
        for (k = 0; k < 6; k++)
            if (!tt__is_finite(lapped->uv[6 * (size_t)e + k])) {
                tt__fail_at(error, TT_ERROR_NON_FINITE, e, -1, -1, "entry %d (face %d) has a non-finite paste UV", e,
                            f);
                if (error) error->face = f;
                return TT_ERROR_NON_FINITE;
            }
    }
    for (p = 0; p < lapped->npastes; p++) {
        const tt_paste *paste = lapped->pastes + p;
        if (paste->patch < 0 || paste->patch >= npatches)
            return tt__fail_at(error, TT_ERROR_INDEX_OUT_OF_RANGE, p, -1, -1,
                               "paste %d uses patch %d, but there are %d patches", p, paste->patch, npatches);
        if (paste->first < 0 || paste->nfaces < 0 || paste->first > lapped->nentries - paste->nfaces)
            return tt__fail_at(error, TT_ERROR_INDEX_OUT_OF_RANGE, p, -1, -1,
                               "paste %d has entries %d..%lld, but there are %d entries", p, paste->first,
                               (long long)paste->first + paste->nfaces - 1, lapped->nentries);
        total += (size_t)paste->nfaces;
        if (total > 0x3fffffff)
            return tt__fail(error, TT_ERROR_TOO_LARGE, -1, -1, -1, -1,
                            "the pastes draw more than %d face entries", 0x3fffffff);
    }

    width = atlas->width;
    height = atlas->height;
    texels = (size_t)width * (size_t)height;   /* <= 2^30 */
    start = TT__ALLOC(al, int, (size_t)mesh->nfaces + 1);
    fill = TT__ALLOC(al, int, mesh->nfaces);
    items = TT__ALLOC(al, int, 2 * total);
    state = TT__ALLOC(al, float, texels);
    queue = TT__ALLOC(al, int, texels);
    if (!start || !fill || !items || !state || !queue) {
        result = tt__fail(error, TT_ERROR_OUT_OF_MEMORY, -1, -1, -1, -1,
                          "out of memory baking %d faces into a %d x %d atlas", mesh->nfaces, width, height);
        goto done;
    }

    /* Entries by face, in paste order (bucket by face, stable). */
    memset(start, 0, ((size_t)mesh->nfaces + 1) * sizeof(int));
    for (p = 0; p < lapped->npastes; p++)
        for (e = lapped->pastes[p].first; e < lapped->pastes[p].first + lapped->pastes[p].nfaces; e++)
            start[lapped->faces[e] + 1]++;
    for (f = 0; f < mesh->nfaces; f++) {
        start[f + 1] += start[f];
        fill[f] = start[f];
    }
    for (p = 0; p < lapped->npastes; p++)
        for (e = lapped->pastes[p].first; e < lapped->pastes[p].first + lapped->pastes[p].nfaces; e++) {
            int slot = fill[lapped->faces[e]]++;
            items[2 * slot] = e;
            items[2 * slot + 1] = lapped->pastes[p].patch;
        }

    for (t = 0; t < texels; t++) state[t] = empty;
    memset(&bake, 0, sizeof bake);
    bake.lapped = lapped;
    bake.patches = patches;
    bake.state = state;
    bake.atlas = atlas;
    /* A gutter wider than the image reaches every texel anyway. */
    bake.gutter = gutter < width + height ? (double)gutter : (double)(width + height);

    /* Progress before each face, and 1 once every face is baked. */
    for (f = 0; f <= mesh->nfaces; f++) {
        float xy[6];
        double area2, longest = 0.0;
        if (opt.progress && opt.progress(f < mesh->nfaces ? (float)f / (float)mesh->nfaces : 1.0f,
                                         opt.progress_user_data)) {
            /* The atlas is half-written: clear it, so no caller mistakes it
               for a result. */
            memset(atlas->pixels, 0, texels * 4 * sizeof(float));
            result = tt__fail(error, TT_CANCELLED, -1, -1, -1, -1, "baking was cancelled at face %d of %d", f,
                              mesh->nfaces);
            goto done;
        }
        if (f == mesh->nfaces) break;
        for (k = 0; k < 3; k++) {
            int corner = mesh->face_start[f] + k;
            xy[2 * k] = corner_uv[2 * (size_t)corner] * (float)width;
            xy[2 * k + 1] = (1.0f - corner_uv[2 * (size_t)corner + 1]) * (float)height;
            bake.x[k] = xy[2 * k];
            bake.y[k] = xy[2 * k + 1];
        }
        area2 = (bake.x[1] - bake.x[0]) * (bake.y[2] - bake.y[0]) - (bake.x[2] - bake.x[0]) * (bake.y[1] - bake.y[0]);
        if (!(fabs(area2) > 0.0) || !tt__is_finite_d(area2)) continue;   /* no image: the fill covers it */
        bake.inverse_area2 = 1.0 / area2;
        bake.items = items + 2 * (size_t)start[f];
        bake.nitems = start[f + 1] - start[f];
        bake.inside = 1;
        tt_raster_triangle(xy, width, height, tt__bake_texel, &bake);
        if (bake.gutter <= 0.0) continue;
        for (k = 0; k < 3; k++) {
            double dx = bake.x[(k + 1) % 3] - bake.x[k], dy = bake.y[(k + 1) % 3] - bake.y[k];
            double length = sqrt(dx * dx + dy * dy);
            if (length > longest) longest = length;
        }
        if (fabs(area2) / longest < TT__BAKE_MIN_HEIGHT) continue;
        bake.inside = 0;
        tt__bake_gutter(&bake);
    }

    /* Straight alpha for the written texels; they seed the fill. */
    for (t = 0; t < texels; t++) {
        float *px = atlas->pixels + 4 * t;
        if (!(state[t] < empty)) continue;
        if (px[3] > 0.0f) {
            float inverse = 1.0f / px[3];
            px[0] *= inverse;
            px[1] *= inverse;
            px[2] *= inverse;
        }
        queue[tail++] = (int)t;
    }
    if (tail == 0) memset(atlas->pixels, 0, texels * 4 * sizeof(float));
    while (head < tail) {
        int from = queue[head++], x = from % width, y = from / width, side;
        for (side = 0; side < 4; side++) {
            int nx = x + (side == 0) - (side == 1), ny = y + (side == 2) - (side == 3), to;
            if (nx < 0 || nx >= width || ny < 0 || ny >= height) continue;
            to = ny * width + nx;
            if (state[to] < empty) continue;
            state[to] = -1.0f;
            memcpy(atlas->pixels + 4 * (size_t)to, atlas->pixels + 4 * (size_t)from, 4 * sizeof(float));
            queue[tail++] = to;
        }
    }
    result = tt__ok(error);

done:
    tt__free(al, start);
    tt__free(al, fill);
    tt__free(al, items);
    tt__free(al, state);
    tt__free(al, queue);
    return result;
}

/* ------------------------------------------------------------------------ */
/* 8. Hierarchical pattern mapping                                          */
/* ------------------------------------------------------------------------ */

/* ---- The face-cluster hierarchy (Soler et al. Sec. 3.1; spec D12-D14) ---- */

TT__DEFINE_HEAPSORT(tt__sort_ints, int)

/* The hierarchy builder's state. `region[f]` is face f's region at the level
   being processed (see the header: a cluster of that level, or a shallower
   leaf); a split writes its children's ids there once that level's control
   vertices and neighbours are known. */
typedef struct tt__hier {
    const tt_mesh *mesh;
    const tt_allocator *al;
    int nf, nv, branching;
    tt_rng rng;
    double *centroid;           /* 3 per face */
    double *step;               /* per corner: the dual step across its edge (tt__field_step), 0 on a boundary */
    double *farea;              /* per face */
    double *comp_area;          /* per component */
    int *region;                /* per face */
    int *vstart, *vcorner;      /* corners at vertex v: vcorner[vstart[v] .. vstart[v + 1] - 1] */
    unsigned char *vboundary;   /* per vertex: on a mesh boundary (an edge with one face) */
    unsigned char *vcount;      /* per vertex: regions around it at this level, "outside" included, capped at 3 */
    int *vstamp, *cstamp, *fstamp;  /* per vertex, corner, face: visited marks, compared with `stamp` */
    int stamp;
    double *dist;               /* per face: Dijkstra distance to the nearest seed */
    int *label;                 /* per face: the seed (child) it belongs to */
    int *best;                  /* per face of the parent being split: the kept split's labels */
    int *scratch;               /* 3 per face */
    tt__heap_item *heap;        /* 4 per face + 1: a Dijkstra from up to all faces, 3 pushes per face */
    int *loopv;                 /* per corner: one border loop's vertices */
    double *loops;              /* per corner: arc length from the loop's first vertex */
    unsigned char *loopc;       /* per corner: the loop vertex is a control vertex */
    tt_cluster *cl;             /* the output, grown */
    int ncl, cap_cl;
    int *faces, nfe, cap_fe;
    int *control, nctl, cap_ctl;
    int *nb, nnb, cap_nb;
    int *level_start, nlev, cap_lev;
} tt__hier;

/* Border half-edge of cluster `id`: its twin is missing or in another region. */
static int tt__hier_border(const tt__hier *H, int id, int c)
{
    int t = H->mesh->twin[c];
    return t < 0 || H->region[H->mesh->corner_face[t]] != id;
}

/* The border half-edge after border half-edge h of cluster id: turn around
   h's end vertex through the cluster's faces. */
static int tt__hier_next_border(const tt__hier *H, int id, int h)
{
    const tt_mesh *m = H->mesh;
    int x = tt_mesh_next(m, h), guard;
    for (guard = 0; guard < m->ncorners && !tt__hier_border(H, id, x); guard++) x = tt_mesh_next(m, m->twin[x]);
    return x;
}

/* Topology of cluster `id` (faces fl[0..n-1], region[] == id): its flags
   (TT_CLUSTER_DISC or 0) and its number of border loops. A disc has one
   border loop meeting no vertex twice and V - E + F = 1 (the faces are
   edge-connected by construction: components, and Voronoi cells whose faces
   each joined through a neighbour of the same cell). */
static unsigned tt__hier_topology(tt__hier *H, int id, const int *fl, int n, int *nloops)
{
    const tt_mesh *m = H->mesh;
    long v = 0, e2 = 0, border = 0, border_verts = 0;
    int i, c, loops = 0, vmark, bmark;
    vmark = ++H->stamp;
    bmark = ++H->stamp;
    for (i = 0; i < n; i++) {
        for (c = m->face_start[fl[i]]; c < m->face_start[fl[i] + 1]; c++) {
            int vert = m->corner_vert[c];
            if (H->vstamp[vert] != vmark && H->vstamp[vert] != bmark) { H->vstamp[vert] = vmark; v++; }
            if (tt__hier_border(H, id, c)) {
                e2 += 2;
                border++;
                if (H->vstamp[vert] != bmark) { H->vstamp[vert] = bmark; border_verts++; }
            } else {
                e2 += 1;
            }
        }
    }
    for (i = 0; i < n; i++) {
        for (c = m->face_start[fl[i]]; c < m->face_start[fl[i] + 1]; c++) {
            int h = c, guard;
            if (H->cstamp[c] == bmark || !tt__hier_border(H, id, c)) continue;
            loops++;
            for (guard = 0; guard <= m->ncorners && H->cstamp[h] != bmark; guard++) {
                H->cstamp[h] = bmark;
                h = tt__hier_next_border(H, id, h);
            }
        }
    }
    *nloops = loops;
    return (loops == 1 && border == border_verts && v - e2 / 2 + n == 1) ? (unsigned)TT_CLUSTER_DISC : 0u;
}

/* Relaxation rounds after the farthest-point seeds. */
#define TT__HIER_RELAX 1

/* Geodesic Voronoi split of parent p (faces fl[0..n-1], region[] == p) into
   k cells: farthest-point seeds, the first one random, each added by a
   Dijkstra from it that takes every face it brings closer. label[] gets the
   cells 0..k-1; each cell holds its seed and is edge-connected. */
/* Dijkstra over the faces of parent p from the faces already in the heap,
   staying within one cell when `within_cell` (label[] then fixed), else
   giving each face it brings closer the label of the face it came from. */
static void tt__hier_dijkstra(tt__hier *H, int p, int nheap, int within_cell)
{
    const tt_mesh *m = H->mesh;
    while (nheap > 0) {
        tt__heap_item top = tt__heap_pop(H->heap, &nheap);
        int g = top.value, c;
        if (top.key > H->dist[g]) continue;
        for (c = m->face_start[g]; c < m->face_start[g + 1]; c++) {
            int t = m->twin[c], h;
            double d;
            if (t < 0) continue;
            h = m->corner_face[t];
            if (H->region[h] != p || (within_cell && H->label[h] != H->label[g])) continue;
            d = top.key + H->step[c];
            if (d < H->dist[h]) {
                H->dist[h] = d;
                if (!within_cell) H->label[h] = H->label[g];
                tt__heap_push(H->heap, &nheap, d, h);
            }
        }
    }
}

static void tt__hier_voronoi(tt__hier *H, int p, const int *fl, int n, int k)
{
    const tt_mesh *m = H->mesh;
    int i, j, iter, seed = fl[tt_rng_below(&H->rng, (uint32_t)n)], smark = ++H->stamp;
    for (i = 0; i < n; i++) {
        H->dist[fl[i]] = HUGE_VAL;
        H->label[fl[i]] = -1;
    }
    for (j = 0; j < k; j++) {
        int nheap = 0;
        if (j > 0) {
            double far = -1.0;
            for (i = 0; i < n; i++)
                if (H->fstamp[fl[i]] != smark && H->dist[fl[i]] > far) { far = H->dist[fl[i]]; seed = fl[i]; }
        }
        H->fstamp[seed] = smark;
        H->dist[seed] = 0.0;
        H->label[seed] = j;
        tt__heap_push(H->heap, &nheap, 0.0, seed);
        tt__hier_dijkstra(H, p, nheap, 0);
    }
    /* Lloyd-like relaxation, for evener sizes (spec 1.1 step 3): move each
       seed to its cell's centre, the face farthest from the cell's border
       (ties: the smallest face index), and partition again. The seeds live
       in scratch[0..k-1], the centres' distances in loops[0..k-1]. */
    for (iter = 0; iter < TT__HIER_RELAX; iter++) {
        int nheap = 0, c;
        for (i = 0; i < n; i++) {
            int f = fl[i], border = 0;
            for (c = m->face_start[f]; c < m->face_start[f + 1]; c++) {
                int t = m->twin[c];
                border |= t < 0 || H->region[m->corner_face[t]] != p || H->label[m->corner_face[t]] != H->label[f];
            }
            H->dist[f] = border ? 0.0 : HUGE_VAL;
            if (border) tt__heap_push(H->heap, &nheap, 0.0, f);
        }
        tt__hier_dijkstra(H, p, nheap, 1);
        for (j = 0; j < k; j++) H->loops[j] = -1.0;
        for (i = 0; i < n; i++) {
            int f = fl[i], cell = H->label[f];
            if (H->dist[f] > H->loops[cell]) { H->loops[cell] = H->dist[f]; H->scratch[cell] = f; }
        }
        nheap = 0;
        for (i = 0; i < n; i++) H->dist[fl[i]] = HUGE_VAL;
        for (j = 0; j < k; j++) {
            H->dist[H->scratch[j]] = 0.0;
            H->label[H->scratch[j]] = j;
            tt__heap_push(H->heap, &nheap, 0.0, H->scratch[j]);
        }
        tt__hier_dijkstra(H, p, nheap, 0);
    }
}

/* Room for `more` clusters, face entries, control vertices or neighbours. */
static int tt__hier_reserve(tt__hier *H, int clusters, int faces, int control, int neighbours)
{
    void *g;
    if (H->ncl >= INT_MAX - clusters || H->nfe >= INT_MAX - faces || H->nctl >= INT_MAX - control ||
        H->nnb >= INT_MAX - neighbours)
        return 0;
    /* Each array exists (at least 64 entries) once reserved, even for 0. */
    if (!(g = tt__grow(H->al, H->cl, &H->cap_cl, H->ncl + clusters + 1, sizeof *H->cl))) return 0;
    H->cl = (tt_cluster *)g;
    if (!(g = tt__grow(H->al, H->faces, &H->cap_fe, H->nfe + faces + 1, sizeof *H->faces))) return 0;
    H->faces = (int *)g;
    if (!(g = tt__grow(H->al, H->control, &H->cap_ctl, H->nctl + control + 1, sizeof *H->control))) return 0;
    H->control = (int *)g;
    if (!(g = tt__grow(H->al, H->nb, &H->cap_nb, H->nnb + neighbours + 1, sizeof *H->nb))) return 0;
    H->nb = (int *)g;
    return 1;
}

/* Split cluster p (more than one face) into its children, appended. */
static int tt__hier_split(tt__hier *H, int p)
{
    tt_cluster P = H->cl[p];
    int n = P.nfaces, i, j, k, attempt, best_bad = INT_MAX, best_k = 0, base = H->ncl;
    double target = H->comp_area[P.component] / pow((double)H->branching, (double)(P.level + 1));
    double x = target > 0.0 ? P.area / target : 0.0;
    int *fl, *count;
    k = x < (double)n ? (int)floor(x + 0.5) : n;     /* NaN and infinity: n */
    k = tt__min_i(tt__max_i(k, 2), n);
    for (attempt = 0; attempt <= TT_CLUSTER_RESEEDS && k + attempt <= n; attempt++) {
        int bad = 0, nloops;
        fl = H->faces + P.first_face;
        tt__hier_voronoi(H, p, fl, n, k + attempt);
        for (i = 0; i < n; i++) H->region[fl[i]] = base + H->label[fl[i]];
        /* Each cell's faces, ascending, into scratch; its start in count. */
        count = H->scratch + n;
        for (j = 0; j <= k + attempt; j++) count[j] = 0;
        for (i = 0; i < n; i++) count[H->label[fl[i]] + 1]++;
        for (j = 0; j < k + attempt; j++) count[j + 1] += count[j];
        for (i = 0; i < n; i++) H->scratch[count[H->label[fl[i]]]++] = fl[i];
        for (j = 0, i = 0; j < k + attempt; j++) {
            int start = i;
            while (i < n && H->label[H->scratch[i]] == j) i++;
            if (!(tt__hier_topology(H, base + j, H->scratch + start, i - start, &nloops) & TT_CLUSTER_DISC)) bad++;
        }
        for (i = 0; i < n; i++) H->region[fl[i]] = p;
        if (bad < best_bad) {
            best_bad = bad;
            best_k = k + attempt;
            for (i = 0; i < n; i++) H->best[i] = H->label[fl[i]];
        }
        if (bad == 0) break;
    }
    if (!tt__hier_reserve(H, best_k, n, 0, 0)) return 0;
    fl = H->faces + P.first_face;
    count = H->scratch;
    for (j = 0; j <= best_k; j++) count[j] = 0;
    for (i = 0; i < n; i++) count[H->best[i] + 1]++;
    for (j = 0; j < best_k; j++) count[j + 1] += count[j];
    for (j = 0; j < best_k; j++) {
        tt_cluster *ch = &H->cl[base + j];
        memset(ch, 0, sizeof *ch);
        ch->level = P.level + 1;
        ch->parent = p;
        ch->first_child = -1;
        ch->first_face = H->nfe + count[j];
        ch->nfaces = count[j + 1] - count[j];
        ch->component = P.component;
    }
    for (i = 0; i < n; i++) {
        tt_cluster *ch = &H->cl[base + H->best[i]];
        H->faces[H->nfe + count[H->best[i]]++] = fl[i];
        H->region[fl[i]] = base + H->best[i];
        ch->area += H->farea[fl[i]];
    }
    H->nfe += n;
    H->ncl += best_k;
    H->cl[p].first_child = base;
    H->cl[p].nchildren = best_k;
    for (j = 0; j < best_k; j++) {
        tt_cluster *ch = &H->cl[base + j];
        ch->flags = tt__hier_topology(H, base + j, H->faces + ch->first_face, ch->nfaces, &ch->nloops);
    }
    return 1;
}

/* Control vertices of the border loop through border half-edge h0 of
   cluster id (spec D12), appended to H->control (room reserved by the
   caller: at most the loop's length); marks the loop's half-edges with
   `mark`. */
static void tt__hier_loop_control(tt__hier *H, int id, int h0, int mark, int single_face)
{
    const tt_mesh *m = H->mesh;
    int len = 0, h = h0, i, j, count = 0, target, first, guard;
    double perimeter = 0.0;
    for (guard = 0; guard <= m->ncorners && H->cstamp[h] != mark; guard++) {
        const float *a = m->pos + 3 * (size_t)m->corner_vert[h];
        const float *b = m->pos + 3 * (size_t)m->corner_vert[tt_mesh_next(m, h)];
        double d[3];
        H->cstamp[h] = mark;
        H->loopv[len] = m->corner_vert[h];
        H->loopc[len] = (unsigned char)(single_face || H->vcount[m->corner_vert[h]] >= 3);
        count += H->loopc[len];
        H->loops[len] = perimeter;
        tt__sub3f(b, a, d);
        perimeter += tt__length3(d);
        len++;
        h = tt__hier_next_border(H, id, h);
    }
    target = tt__min_i(len >= TT_CLUSTER_LONG_LOOP ? 4 : 3, len);
    if (count == 0) {
        /* At equal arc-length fractions j / target from the first vertex
           (equal index steps on a loop of zero length). */
        for (j = 0; j < target; j++) {
            double want = perimeter * j / target;
            i = 0;
            if (perimeter > 0.0) {
                while (i < len - 1 && H->loops[i] < want) i++;
            } else {
                i = (int)((long)len * j / target);
            }
            while (H->loopc[i]) i = (i + 1) % len;
            H->loopc[i] = 1;
            count++;
        }
    }
    while (count < target) {
        /* The vertex nearest the middle of the longest arc between
           consecutive control vertices that has a vertex inside. */
        int bi = -1, bj = -1, bk = -1;
        double barc = -1.0, mid, bdist = HUGE_VAL;
        for (i = 0; i < len; i++) {
            double arc;
            if (!H->loopc[i]) continue;
            j = (i + 1) % len;
            while (!H->loopc[j]) j = (j + 1) % len;
            if (j == (i + 1) % len) continue;
            arc = H->loops[j] - H->loops[i] + (j <= i ? perimeter : 0.0);
            if (arc > barc) { barc = arc; bi = i; bj = j; }
        }
        if (bi < 0) break;
        mid = H->loops[bi] + 0.5 * barc;
        for (i = (bi + 1) % len; i != bj; i = (i + 1) % len) {
            double at = H->loops[i] + (i <= bi ? perimeter : 0.0);
            if (fabs(at - mid) < bdist) { bdist = fabs(at - mid); bk = i; }
        }
        H->loopc[bk] = 1;
        count++;
    }
    for (first = 0; first < len && !H->loopc[first]; first++) {}
    for (i = 0; i < len; i++) {
        int at = (first + i) % len;
        if (H->loopc[at]) H->control[H->nctl++] = H->loopv[at];
    }
}

/* The neighbours, control vertices and mappable flag of the clusters
   ls .. le - 1 of one level, from region[] at that level. */
static int tt__hier_level(tt__hier *H, int ls, int le)
{
    const tt_mesh *m = H->mesh;
    int v, id, i, c;
    for (v = 0; v < H->nv; v++) {
        int r0 = -1, r1 = -1, n = H->vboundary[v];
        for (i = H->vstart[v]; i < H->vstart[v + 1] && n < 3; i++) {
            int r = H->region[m->corner_face[H->vcorner[i]]];
            if (r == r0 || r == r1) continue;
            if (r0 < 0) r0 = r; else if (r1 < 0) r1 = r;
            n++;
        }
        H->vcount[v] = (unsigned char)n;
    }
    for (id = ls; id < le; id++) {
        int n = H->cl[id].nfaces, nn = 0, unique = 0, mark;
        const int *fl = H->faces + H->cl[id].first_face;
        for (i = 0; i < n; i++)
            for (c = m->face_start[fl[i]]; c < m->face_start[fl[i] + 1]; c++)
                if (tt__hier_border(H, id, c) && m->twin[c] >= 0)
                    H->scratch[nn++] = H->region[m->corner_face[m->twin[c]]];
        tt__sort_ints(H->scratch, nn);
        for (i = 0; i < nn; i++)
            if (i == 0 || H->scratch[i] != H->scratch[i - 1]) H->scratch[unique++] = H->scratch[i];
        if (!tt__hier_reserve(H, 0, 0, 3 * n, unique)) return 0;
        fl = H->faces + H->cl[id].first_face;
        H->cl[id].first_neighbour = H->nnb;
        H->cl[id].nneighbours = unique;
        for (i = 0; i < unique; i++) H->nb[H->nnb++] = H->scratch[i];
        mark = ++H->stamp;
        H->cl[id].first_control = H->nctl;
        for (i = 0; i < n; i++)
            for (c = m->face_start[fl[i]]; c < m->face_start[fl[i] + 1]; c++)
                if (H->cstamp[c] != mark && tt__hier_border(H, id, c)) tt__hier_loop_control(H, id, c, mark, n == 1);
        H->cl[id].ncontrol = H->nctl - H->cl[id].first_control;
        if ((H->cl[id].flags & TT_CLUSTER_DISC) && H->cl[id].ncontrol >= 3) H->cl[id].flags |= TT_CLUSTER_MAPPABLE;
    }
    return 1;
}

static void tt__hier_release(tt__hier *H)
{
    const tt_allocator *al = H->al;
    tt__free(al, H->centroid);
    tt__free(al, H->step);
    tt__free(al, H->farea);
    tt__free(al, H->comp_area);
    tt__free(al, H->region);
    tt__free(al, H->vstart);
    tt__free(al, H->vcorner);
    tt__free(al, H->vboundary);
    tt__free(al, H->vcount);
    tt__free(al, H->vstamp);
    tt__free(al, H->cstamp);
    tt__free(al, H->fstamp);
    tt__free(al, H->dist);
    tt__free(al, H->label);
    tt__free(al, H->best);
    tt__free(al, H->scratch);
    tt__free(al, H->heap);
    tt__free(al, H->loopv);
    tt__free(al, H->loops);
    tt__free(al, H->loopc);
    tt__free(al, H->cl);
    tt__free(al, H->faces);
    tt__free(al, H->control);
    tt__free(al, H->nb);
    tt__free(al, H->level_start);
}

/* Level 0: one cluster per connected component (region[] holds the
   component ids), faces ascending. */
static int tt__hier_components(tt__hier *H, int ncomp)
{
    int f, j, *count = H->scratch;
    if (!tt__hier_reserve(H, ncomp, H->nf, 0, 0)) return 0;
    for (j = 0; j <= ncomp; j++) count[j] = 0;
    for (f = 0; f < H->nf; f++) count[H->region[f] + 1]++;
    for (j = 0; j < ncomp; j++) count[j + 1] += count[j];
    for (j = 0; j < ncomp; j++) {
        tt_cluster *C = &H->cl[j];
        memset(C, 0, sizeof *C);
        C->parent = C->first_child = -1;
        C->first_face = count[j];
        C->nfaces = count[j + 1] - count[j];
        C->component = j;
    }
    for (f = 0; f < H->nf; f++) {
        H->faces[count[H->region[f]]++] = f;
        H->cl[H->region[f]].area += H->farea[f];
    }
    H->nfe = H->nf;
    H->ncl = ncomp;
    for (j = 0; j < ncomp; j++) {
        tt_cluster *C = &H->cl[j];
        H->comp_area[j] = C->area;
        C->flags = tt__hier_topology(H, j, H->faces + C->first_face, C->nfaces, &C->nloops);
    }
    return 1;
}

TTDEF tt_result tt_cluster_hierarchy_build(const tt_mesh *mesh, const tt_cluster_options *options,
                                           const tt_allocator *allocator, tt_cluster_hierarchy **out,
                                           tt_error *error)
{
    tt__hier H;
    tt_cluster_hierarchy *hier;
    int f, c, v, ncomp = 0, level, branching;
    size_t nf, nc;

    if (out) *out = NULL;
    tt__ok(error);
    if (!mesh || !out)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "tt_cluster_hierarchy_build needs a mesh and an output (got NULL)");
    if (tt__check_allocator(allocator, error) != TT_OK) return TT_ERROR_INVALID_ARGUMENT;
    if (mesh->nfaces <= 0)
        return tt__fail(error, TT_ERROR_EMPTY_MESH, -1, -1, -1, -1, "the mesh has no faces to cluster");
    for (f = 0; f < mesh->nfaces; f++)
        if (mesh->face_start[f + 1] - mesh->face_start[f] != 3)
            return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, f, mesh->face_start[f], -1, -1,
                            "face %d has %d corners: the cluster hierarchy needs triangles (triangulate first)",
                            f, mesh->face_start[f + 1] - mesh->face_start[f]);
    branching = options && options->branching ? options->branching : TT_DEFAULT_CLUSTER_BRANCHING;
    if (branching < 2 || branching > 64)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "the cluster branching is %d: it must be 2..64 (0 for the default, %d)",
                        options->branching, TT_DEFAULT_CLUSTER_BRANCHING);

    memset(&H, 0, sizeof H);
    H.mesh = mesh;
    H.al = allocator;
    H.nf = mesh->nfaces;
    H.nv = mesh->nverts;
    H.branching = branching;
    tt_rng_seed(&H.rng, options ? options->seed : 0u, 0x48504du);   /* stream "HPM" */
    nf = (size_t)H.nf;
    nc = (size_t)mesh->ncorners;
    H.centroid = TT__ALLOC(allocator, double, 3 * nf);
    H.farea = TT__ALLOC(allocator, double, nf);
    H.step = TT__ALLOC(allocator, double, nc);
    H.comp_area = TT__ALLOC(allocator, double, nf);
    H.region = TT__ALLOC(allocator, int, nf);
    H.vstart = TT__ALLOC(allocator, int, (size_t)H.nv + 1);
    H.vcorner = TT__ALLOC(allocator, int, nc);
    H.vboundary = TT__ALLOC(allocator, unsigned char, (size_t)H.nv);
    H.vcount = TT__ALLOC(allocator, unsigned char, (size_t)H.nv);
    H.vstamp = TT__ALLOC(allocator, int, (size_t)H.nv);
    H.cstamp = TT__ALLOC(allocator, int, nc);
    H.fstamp = TT__ALLOC(allocator, int, nf);
    H.dist = TT__ALLOC(allocator, double, nf);
    H.label = TT__ALLOC(allocator, int, nf);
    H.best = TT__ALLOC(allocator, int, nf);
    H.scratch = TT__ALLOC(allocator, int, 3 * nf + 1);
    H.heap = TT__ALLOC(allocator, tt__heap_item, 4 * nf + 1);
    H.loopv = TT__ALLOC(allocator, int, nc);
    H.loops = TT__ALLOC(allocator, double, nc);
    H.loopc = TT__ALLOC(allocator, unsigned char, nc);
    if (!H.centroid || !H.step || !H.farea || !H.comp_area || !H.region || !H.vstart || !H.vcorner || !H.vboundary ||
        !H.vcount || !H.vstamp || !H.cstamp || !H.fstamp || !H.dist || !H.label || !H.best || !H.scratch ||
        !H.heap || !H.loopv || !H.loops || !H.loopc)
        goto oom;
    if (tt_mesh_components(mesh, allocator, H.region, &ncomp, NULL) != TT_OK) goto oom;

    for (f = 0; f < H.nf; f++) {
        const float *p0 = mesh->pos + 3 * (size_t)mesh->corner_vert[3 * (size_t)f];
        const float *p1 = mesh->pos + 3 * (size_t)mesh->corner_vert[3 * (size_t)f + 1];
        const float *p2 = mesh->pos + 3 * (size_t)mesh->corner_vert[3 * (size_t)f + 2];
        double e1[3], e2[3], n[3];
        int k;
        for (k = 0; k < 3; k++) H.centroid[3 * (size_t)f + k] = ((double)p0[k] + p1[k] + p2[k]) / 3.0;
        tt__sub3f(p1, p0, e1);
        tt__sub3f(p2, p0, e2);
        tt__cross3(e1, e2, n);
        H.farea[f] = 0.5 * tt__length3(n);
        H.fstamp[f] = 0;
    }
    for (c = 0; c < mesh->ncorners; c++)
        H.step[c] = mesh->twin[c] < 0 ? 0.0
                                      : tt__field_step(mesh, H.centroid, mesh->corner_face[c], c,
                                                       mesh->corner_face[mesh->twin[c]]);
    for (v = 0; v <= H.nv; v++) H.vstart[v] = 0;
    for (v = 0; v < H.nv; v++) H.vboundary[v] = 0, H.vstamp[v] = 0;
    for (c = 0; c < mesh->ncorners; c++) {
        H.vstart[mesh->corner_vert[c] + 1]++;
        H.cstamp[c] = 0;
        if (mesh->twin[c] < 0) {
            H.vboundary[mesh->corner_vert[c]] = 1;
            H.vboundary[mesh->corner_vert[tt_mesh_next(mesh, c)]] = 1;
        }
    }
    for (v = 0; v < H.nv; v++) H.vstart[v + 1] += H.vstart[v];
    for (c = 0; c < mesh->ncorners; c++) H.vcorner[H.vstart[mesh->corner_vert[c]]++] = c;
    for (v = H.nv; v > 0; v--) H.vstart[v] = H.vstart[v - 1];
    H.vstart[0] = 0;

    if (!tt__hier_components(&H, ncomp)) goto oom;
    for (level = 0;; level++) {
        int ls, le = H.ncl, id;
        int *g = (int *)tt__grow(allocator, H.level_start, &H.cap_lev, level + 2, sizeof(int));
        if (!g) goto oom;
        H.level_start = g;
        if (level == 0) H.level_start[0] = 0;
        ls = H.level_start[level];
        H.level_start[level + 1] = le;
        if (!tt__hier_level(&H, ls, le)) goto oom;
        for (id = ls; id < le; id++)
            if (H.cl[id].nfaces > 1 && !tt__hier_split(&H, id)) goto oom;
        if (H.ncl == le) break;
    }
    H.nlev = level + 1;

    hier = TT__ALLOC(allocator, tt_cluster_hierarchy, 1);
    if (!hier) goto oom;
    memset(hier, 0, sizeof *hier);
    hier->face_leaf = TT__ALLOC(allocator, int, nf);
    if (!hier->face_leaf) {
        tt__free(allocator, hier);
        goto oom;
    }
    for (c = 0; c < H.ncl; c++)
        if (H.cl[c].nfaces == 1) hier->face_leaf[H.faces[H.cl[c].first_face]] = c;
    hier->nclusters = H.ncl;
    hier->clusters = H.cl;
    hier->nlevels = H.nlev;
    hier->level_start = H.level_start;
    hier->nface_entries = H.nfe;
    hier->faces = H.faces;
    hier->ncontrol = H.nctl;
    hier->control = H.control;
    hier->nneighbour_entries = H.nnb;
    hier->neighbours = H.nb;
    hier->nfaces = H.nf;
    hier->ncomponents = ncomp;
    hier->allocator = tt__allocator_copy(allocator);
    H.cl = NULL;
    H.level_start = NULL;
    H.faces = H.control = H.nb = NULL;
    tt__hier_release(&H);
    *out = hier;
    return TT_OK;

oom:
    tt__hier_release(&H);
    return tt__fail(error, TT_ERROR_OUT_OF_MEMORY, -1, -1, -1, -1, "out of memory building the cluster hierarchy");
}

TTDEF void tt_cluster_hierarchy_free(tt_cluster_hierarchy *hierarchy)
{
    tt_allocator al;
    if (!hierarchy) return;
    al = hierarchy->allocator;
    tt__free(&al, hierarchy->clusters);
    tt__free(&al, hierarchy->level_start);
    tt__free(&al, hierarchy->faces);
    tt__free(&al, hierarchy->control);
    tt__free(&al, hierarchy->neighbours);
    tt__free(&al, hierarchy->face_leaf);
    tt__free(&al, hierarchy);
}

/* ---- Flattening (Sec. 3.2) ---- */

static int tt__int_compare(const void *a, const void *b)
{
    int x = *(const int *)a, y = *(const int *)b;
    return x < y ? -1 : (x > y ? 1 : 0);
}

/* Position of key in the ascending array a[0..n-1], or -1. */
static int tt__find_sorted(const int *a, int n, int key)
{
    int lo = 0, hi = n - 1;
    while (lo <= hi) {
        int mid = lo + (hi - lo) / 2;
        if (a[mid] == key) return mid;
        if (a[mid] < key) lo = mid + 1;
        else hi = mid - 1;
    }
    return -1;
}

/* The unit eigenvector of the smallest eigenvalue of the symmetric 3 x 3
   matrix m (destroyed), by cyclic Jacobi rotations. */
static void tt__sym3_min_vector(double m[3][3], double out[3])
{
    double v[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    int sweep, p, q, k, best = 0;
    for (sweep = 0; sweep < 50; sweep++) {
        double off = m[0][1] * m[0][1] + m[0][2] * m[0][2] + m[1][2] * m[1][2];
        double diag = m[0][0] * m[0][0] + m[1][1] * m[1][1] + m[2][2] * m[2][2];
        if (off <= 1e-30 * diag || off == 0) break;
        for (p = 0; p < 2; p++)
            for (q = p + 1; q < 3; q++) {
                double theta, t, c, s;
                if (m[p][q] == 0) continue;
                theta = (m[q][q] - m[p][p]) / (2 * m[p][q]);
                t = (theta >= 0 ? 1.0 : -1.0) / (fabs(theta) + sqrt(theta * theta + 1));
                c = 1 / sqrt(t * t + 1);
                s = t * c;
                for (k = 0; k < 3; k++) {
                    double a = m[k][p], b = m[k][q];
                    m[k][p] = c * a - s * b;
                    m[k][q] = s * a + c * b;
                }
                for (k = 0; k < 3; k++) {
                    double a = m[p][k], b = m[q][k];
                    m[p][k] = c * a - s * b;
                    m[q][k] = s * a + c * b;
                }
                for (k = 0; k < 3; k++) {
                    double a = v[k][p], b = v[k][q];
                    v[k][p] = c * a - s * b;
                    v[k][q] = s * a + c * b;
                }
            }
    }
    for (k = 1; k < 3; k++)
        if (m[k][k] < m[best][best]) best = k;
    for (k = 0; k < 3; k++) out[k] = v[k][best];
}

/* Whether the closed polygon xy[0..count-1] (2 doubles a point) is simple
   and counter-clockwise: positive signed area and no two non-adjacent
   edges meeting (touching counts). O(count^2). */
static int tt__polygon_simple_ccw(const double *xy, int count)
{
    double area = 0;
    int i, j;
    if (count < 3) return 0;
    for (i = 0; i < count; i++) {
        int n = (i + 1) % count;
        area += xy[2 * i] * xy[2 * n + 1] - xy[2 * n] * xy[2 * i + 1];
    }
    if (!(area > 0)) return 0;
    for (i = 0; i < count; i++) {
        int i2 = (i + 1) % count;
        double ax = xy[2 * i], ay = xy[2 * i + 1], bx = xy[2 * i2], by = xy[2 * i2 + 1];
        double minx = ax < bx ? ax : bx, maxx = ax < bx ? bx : ax, miny = ay < by ? ay : by, maxy = ay < by ? by : ay;
        if (ax == bx && ay == by) return 0;     /* a zero-length edge */
        for (j = i + 2; j < count; j++) {
            int j2 = (j + 1) % count;
            double cx = xy[2 * j], cy = xy[2 * j + 1], dx = xy[2 * j2], dy = xy[2 * j2 + 1];
            double o1, o2, o3, o4;
            if (j2 == i) continue;              /* adjacent through the closing edge */
            if ((cx < minx && dx < minx) || (cx > maxx && dx > maxx) || (cy < miny && dy < miny) ||
                (cy > maxy && dy > maxy))
                continue;
            o1 = tt__orient2(ax, ay, bx, by, cx, cy);
            o2 = tt__orient2(ax, ay, bx, by, dx, dy);
            o3 = tt__orient2(cx, cy, dx, dy, ax, ay);
            o4 = tt__orient2(cx, cy, dx, dy, bx, by);
            if (((o1 > 0 && o2 < 0) || (o1 < 0 && o2 > 0)) && ((o3 > 0 && o4 < 0) || (o3 < 0 && o4 > 0))) return 0;
            if ((o1 == 0 && tt__point_segment_distance(cx, cy, ax, ay, bx, by) == 0) ||
                (o2 == 0 && tt__point_segment_distance(dx, dy, ax, ay, bx, by) == 0) ||
                (o3 == 0 && tt__point_segment_distance(ax, ay, cx, cy, dx, dy) == 0) ||
                (o4 == 0 && tt__point_segment_distance(bx, by, cx, cy, dx, dy) == 0))
                return 0;
        }
    }
    return 1;
}

static void tt__flat_point(const tt_mesh *mesh, int v, double *out)
{
    out[0] = mesh->pos[3 * v];
    out[1] = mesh->pos[3 * v + 1];
    out[2] = mesh->pos[3 * v + 2];
}

TTDEF tt_result tt_flatten_cluster(const tt_mesh *mesh, const tt_cluster_hierarchy *hierarchy, int cluster,
                                   const tt_flatten_options *options, const tt_allocator *allocator,
                                   float *corner_uv, tt_flatten_report *report, tt_error *error)
{
    const tt_cluster *C;
    const int *faces, *ctl;
    double max_error = TT_DEFAULT_FLATTEN_MAX_ERROR, max_stretch = 0, tol = TT_DEFAULT_FLATTEN_CG_TOLERANCE;
    int border_mode = TT_FLATTEN_BORDER_PROJECTED, maxit = 0;
    int n, k, nv = 0, nb = 0, nunk = 0, nt = 0, i, j, p, first_flip = -1;
    int *lv = NULL, *cv = NULL, *next = NULL, *loop = NULL, *at = NULL, *unk = NULL;
    double *uv = NULL, *w = NULL, *q = NULL, *arc = NULL, *rhs = NULL, *x = NULL, *bxy = NULL;
    tt__weighted *keys = NULL;
    tt_triplet *trip = NULL;
    tt_sparse_matrix *A = NULL;
    tt_flatten_report rep;
    tt_result res = TT_OK;
    double area_vec[3] = {0, 0, 0}, centre[3] = {0, 0, 0}, cov[3][3], nrm[3], e1[3], e2[3];
    double surface = 0, mapped = 0, mean_w = 0, total_w = 0, p95 = 0.95;
    int nedges = 0;

    memset(&rep, 0, sizeof rep);
    if (report) *report = rep;
    tt__ok(error);
    if (!mesh || !hierarchy || !corner_uv)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "tt_flatten_cluster needs a mesh, a hierarchy and corner_uv (got NULL)");
    if (tt__check_allocator(allocator, error) != TT_OK) return TT_ERROR_INVALID_ARGUMENT;
    if (hierarchy->nfaces != mesh->nfaces)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "the hierarchy was built for %d faces but the mesh has %d", hierarchy->nfaces,
                        mesh->nfaces);
    if (cluster < 0 || cluster >= hierarchy->nclusters)
        return tt__fail_at(error, TT_ERROR_INDEX_OUT_OF_RANGE, cluster, -1, -1,
                           "cluster %d does not exist: the hierarchy has %d clusters", cluster,
                           hierarchy->nclusters);
    if (options) {
        if (options->max_error != 0) max_error = options->max_error;
        if (options->max_stretch != 0) max_stretch = options->max_stretch;
        if (options->cg_tolerance != 0) tol = options->cg_tolerance;
        border_mode = options->border;
        maxit = options->cg_max_iterations;
        if (!(max_error > 0) || !(max_stretch == 0 || max_stretch >= 1) || !(tol > 0 && tol < 1) ||
            (border_mode != TT_FLATTEN_BORDER_PROJECTED && border_mode != TT_FLATTEN_BORDER_CHORD) || maxit < 0)
            return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                            "flatten options out of range: max_error %g (> 0), max_stretch %g (0 or >= 1), "
                            "border %d (0 or 1), cg_tolerance %g (0 < t < 1), cg_max_iterations %d (>= 0)",
                            options->max_error, options->max_stretch, options->border, options->cg_tolerance,
                            options->cg_max_iterations);
    }
    C = &hierarchy->clusters[cluster];
    if (!(C->flags & TT_CLUSTER_MAPPABLE) || C->ncontrol < 3 || C->nloops != 1)
        return tt__fail_at(error, TT_ERROR_INVALID_ARGUMENT, cluster, -1, -1,
                           "cluster %d is not mappable (%s, %d border loops, %d control vertices): split it",
                           cluster, (C->flags & TT_CLUSTER_DISC) ? "a disc" : "not a disc", C->nloops,
                           C->ncontrol);
    n = C->nfaces;
    k = C->ncontrol;
    if (n < 1 || C->first_face < 0 || C->first_face > hierarchy->nface_entries - n || C->first_control < 0 ||
        C->first_control > hierarchy->ncontrol - k)
        return tt__fail_at(error, TT_ERROR_INVALID_ARGUMENT, cluster, -1, -1,
                           "cluster %d names faces or control vertices outside the hierarchy's arrays", cluster);
    faces = hierarchy->faces + C->first_face;
    ctl = hierarchy->control + C->first_control;
    for (i = 0; i < n; i++)
        if (faces[i] < 0 || faces[i] >= mesh->nfaces || (i > 0 && faces[i] <= faces[i - 1]) ||
            mesh->face_start[faces[i] + 1] - mesh->face_start[faces[i]] != 3)
            return tt__fail_at(error, TT_ERROR_INVALID_ARGUMENT, cluster, -1, -1,
                               "cluster %d lists face %d, which is out of range, out of order or not a triangle",
                               cluster, faces[i]);

    lv = TT__ALLOC(allocator, int, 6 * (size_t)n);
    cv = TT__ALLOC(allocator, int, 3 * (size_t)n);
    next = TT__ALLOC(allocator, int, 3 * (size_t)n);
    loop = TT__ALLOC(allocator, int, 3 * (size_t)n + 1);
    at = TT__ALLOC(allocator, int, 3 * (size_t)n);
    unk = TT__ALLOC(allocator, int, 3 * (size_t)n);
    uv = TT__ALLOC(allocator, double, 6 * (size_t)n);
    w = TT__ALLOC(allocator, double, 3 * (size_t)n);
    q = TT__ALLOC(allocator, double, 2 * (size_t)k);
    arc = TT__ALLOC(allocator, double, 3 * (size_t)n + 1);
    rhs = TT__ALLOC(allocator, double, 6 * (size_t)n);
    x = TT__ALLOC(allocator, double, 6 * (size_t)n);
    bxy = TT__ALLOC(allocator, double, 6 * (size_t)n);
    keys = TT__ALLOC(allocator, tt__weighted, (size_t)n);
    trip = TT__ALLOC(allocator, tt_triplet, 12 * (size_t)n);
    if (!lv || !cv || !next || !loop || !at || !unk || !uv || !w || !q || !arc || !rhs || !x || !bxy || !keys ||
        !trip)
        goto oom;

    /* Local vertices: the cluster's mesh vertices, ascending. */
    for (i = 0; i < n; i++)
        for (j = 0; j < 3; j++) lv[3 * i + j] = mesh->corner_vert[mesh->face_start[faces[i]] + j];
    qsort(lv, 3 * (size_t)n, sizeof(int), tt__int_compare);
    for (i = 0; i < 3 * n; i++)
        if (i == 0 || lv[i] != lv[nv - 1]) lv[nv++] = lv[i];
    for (i = 0; i < 3 * n; i++) cv[i] = tt__find_sorted(lv, nv, mesh->corner_vert[mesh->face_start[faces[i / 3]] + i % 3]);
    for (i = 0; i < nv; i++) next[i] = at[i] = -1;

    /* Border half-edges (twin outside the cluster) chain into the loop. */
    for (i = 0; i < 3 * n; i++) {
        int c = mesh->face_start[faces[i / 3]] + i % 3, t = mesh->twin[c];
        if (t >= 0 && tt__find_sorted(faces, n, mesh->corner_face[t]) >= 0) continue;
        if (next[cv[i]] >= 0) goto bad_border;
        next[cv[i]] = cv[3 * (i / 3) + (i % 3 + 1) % 3];
        nb++;
    }
    p = tt__find_sorted(lv, nv, ctl[0]);
    if (p < 0 || next[p] < 0) goto bad_border;
    for (i = 0; i < nb; i++) {
        if (at[p] >= 0) goto bad_border;
        at[p] = i;
        loop[i] = p;
        p = next[p];
        if (p < 0) goto bad_border;
    }
    if (p != loop[0]) goto bad_border;
    loop[nb] = loop[0];
    for (j = 0; j < k; j++) {
        int lj = tt__find_sorted(lv, nv, ctl[j]);
        if (lj < 0 || at[lj] < 0 || (j > 0 && at[lj] <= at[tt__find_sorted(lv, nv, ctl[j - 1])])) goto bad_border;
    }

    /* Surface area, area vector, arc lengths. */
    for (i = 0; i < n; i++) {
        double a[3], b[3], c3[3], e[3], f[3], cr[3];
        tt__flat_point(mesh, lv[cv[3 * i]], a);
        tt__flat_point(mesh, lv[cv[3 * i + 1]], b);
        tt__flat_point(mesh, lv[cv[3 * i + 2]], c3);
        for (j = 0; j < 3; j++) {
            e[j] = b[j] - a[j];
            f[j] = c3[j] - a[j];
        }
        tt__cross3(e, f, cr);
        surface += 0.5 * tt__length3(cr);
        for (j = 0; j < 3; j++) area_vec[j] += 0.5 * cr[j];
    }
    arc[0] = 0;
    for (i = 0; i < nb; i++) {
        double a[3], b[3], d[3];
        tt__flat_point(mesh, lv[loop[i]], a);
        tt__flat_point(mesh, lv[loop[i + 1]], b);
        for (j = 0; j < 3; j++) d[j] = b[j] - a[j];
        arc[i + 1] = arc[i] + tt__length3(d);
    }
    rep.surface_area = surface;
    rep.nborder = nb;
    rep.ninterior = nv - nb;

    /* The control polygon: PCA plane, oriented by the area vector (D10). */
    for (j = 0; j < k; j++) {
        double P[3];
        tt__flat_point(mesh, ctl[j], P);
        for (i = 0; i < 3; i++) centre[i] += P[i] / k;
    }
    memset(cov, 0, sizeof cov);
    for (j = 0; j < k; j++) {
        double P[3];
        int r, s;
        tt__flat_point(mesh, ctl[j], P);
        for (i = 0; i < 3; i++) P[i] -= centre[i];
        for (r = 0; r < 3; r++)
            for (s = 0; s < 3; s++) cov[r][s] += P[r] * P[s];
    }
    tt__sym3_min_vector(cov, nrm);
    if (tt__dot3(nrm, area_vec) < 0)
        for (i = 0; i < 3; i++) nrm[i] = -nrm[i];
    {
        int axis = 0;
        for (i = 1; i < 3; i++)
            if (fabs(nrm[i]) < fabs(nrm[axis])) axis = i;
        for (i = 0; i < 3; i++) e1[i] = (i == axis) - nrm[axis] * nrm[i];
        tt__normalize3(e1);
        tt__cross3(nrm, e1, e2);
    }
    for (j = 0; j < k; j++) {
        double P[3];
        tt__flat_point(mesh, ctl[j], P);
        for (i = 0; i < 3; i++) P[i] -= centre[i];
        q[2 * j] = tt__dot3(P, e1);
        q[2 * j + 1] = tt__dot3(P, e2);
    }
    for (p = 0; p < TT_FLATTEN_POLYGON_PASSES; p++)
        for (j = 0; j < k; j++) {
            int j2 = (j + 1) % k;
            double P[3], R[3], d[3], L3, L2, dx = q[2 * j2] - q[2 * j], dy = q[2 * j2 + 1] - q[2 * j + 1], corr;
            tt__flat_point(mesh, ctl[j], P);
            tt__flat_point(mesh, ctl[j2], R);
            for (i = 0; i < 3; i++) d[i] = R[i] - P[i];
            L3 = tt__length3(d);
            L2 = sqrt(dx * dx + dy * dy);
            if (!(L2 > 0)) continue;
            corr = (L2 - L3) / (2 * L2);
            q[2 * j] += corr * dx;
            q[2 * j + 1] += corr * dy;
            q[2 * j2] -= corr * dx;
            q[2 * j2 + 1] -= corr * dy;
        }
    if (!tt__polygon_simple_ccw(q, k)) {
        res = tt__fail_at(error, TT_ERROR_NOT_FLAT, cluster, -1, -1,
                          "cluster %d: its control polygon (%d vertices) flattens to a polygon that is not simple "
                          "and counter-clockwise",
                          cluster, k);
        goto done;
    }

    /* The border (options->border). */
    for (j = 0; j < k; j++) {
        int pa = at[tt__find_sorted(lv, nv, ctl[j])];
        int pb = j + 1 < k ? at[tt__find_sorted(lv, nv, ctl[j + 1])] : nb;
        int j2 = (j + 1) % k;
        double qax = q[2 * j], qay = q[2 * j + 1], qbx = q[2 * j2], qby = q[2 * j2 + 1];
        double pax, pay, pbx, pby, den, P[3];
        tt__flat_point(mesh, lv[loop[pa]], P);
        for (i = 0; i < 3; i++) P[i] -= centre[i];
        pax = tt__dot3(P, e1);
        pay = tt__dot3(P, e2);
        tt__flat_point(mesh, lv[loop[pb]], P);
        for (i = 0; i < 3; i++) P[i] -= centre[i];
        pbx = tt__dot3(P, e1);
        pby = tt__dot3(P, e2);
        den = (pbx - pax) * (pbx - pax) + (pby - pay) * (pby - pay);
        for (p = pa; p < pb; p++) {
            double *o = uv + 2 * loop[p];
            if (p == pa) {
                o[0] = qax;
                o[1] = qay;
            } else if (border_mode == TT_FLATTEN_BORDER_PROJECTED && den > 0) {
                /* z = (proj - pa) * (qb - qa) / (pb - pa) + qa, complex */
                double zx, zy, sx = qbx - qax, sy = qby - qay, tx = pbx - pax, ty = pby - pay, rx, ry;
                tt__flat_point(mesh, lv[loop[p]], P);
                for (i = 0; i < 3; i++) P[i] -= centre[i];
                zx = tt__dot3(P, e1) - pax;
                zy = tt__dot3(P, e2) - pay;
                rx = (sx * tx + sy * ty) / den;     /* (qb - qa) / (pb - pa) */
                ry = (sy * tx - sx * ty) / den;
                o[0] = qax + zx * rx - zy * ry;
                o[1] = qay + zx * ry + zy * rx;
            } else {
                double t = arc[pb] > arc[pa] ? (arc[p] - arc[pa]) / (arc[pb] - arc[pa]) : 0;
                o[0] = qax + t * (qbx - qax);
                o[1] = qay + t * (qby - qay);
            }
        }
    }
    if (border_mode == TT_FLATTEN_BORDER_PROJECTED) {
        for (p = 0; p < nb; p++) {
            bxy[2 * p] = uv[2 * loop[p]];
            bxy[2 * p + 1] = uv[2 * loop[p] + 1];
        }
        if (!tt__polygon_simple_ccw(bxy, nb)) {
            res = tt__fail_at(error, TT_ERROR_NOT_FLAT, cluster, -1, -1,
                              "cluster %d: its border (%d vertices) projects to a loop that is not simple and "
                              "counter-clockwise",
                              cluster, nb);
            goto done;
        }
    }
    rep.polygon_simple = 1;

    /* Cotangent weights, half-edge by half-edge, then per edge (D18). */
    for (i = 0; i < n; i++)
        for (j = 0; j < 3; j++) {
            double a[3], b[3], o[3], u[3], v[3], cr[3], len;
            int l;
            tt__flat_point(mesh, lv[cv[3 * i + j]], a);
            tt__flat_point(mesh, lv[cv[3 * i + (j + 1) % 3]], b);
            tt__flat_point(mesh, lv[cv[3 * i + (j + 2) % 3]], o);
            for (l = 0; l < 3; l++) {
                u[l] = a[l] - o[l];
                v[l] = b[l] - o[l];
            }
            tt__cross3(u, v, cr);
            len = tt__length3(cr);
            w[3 * i + j] = len > 0 ? 0.5 * tt__dot3(u, v) / len : 0;
        }
    for (i = 0; i < 3 * n; i++) {
        int c = mesh->face_start[faces[i / 3]] + i % 3, t = mesh->twin[c], tf;
        double W = w[i];
        if (t >= 0 && (tf = tt__find_sorted(faces, n, mesh->corner_face[t])) >= 0) {
            if (t < c) continue;
            W += w[3 * tf + (t - mesh->face_start[mesh->corner_face[t]])];
        }
        total_w += fabs(W);
        nedges++;
    }
    mean_w = nedges > 0 ? total_w / nedges : 0;
    for (i = 0; i < nv; i++) unk[i] = next[i] < 0 ? nunk++ : -1;
    for (i = 0; i < 2 * nunk; i++) rhs[i] = 0;
    for (i = 0; i < 3 * n; i++) {
        int c = mesh->face_start[faces[i / 3]] + i % 3, t = mesh->twin[c], tf, a = cv[i], b, side;
        double W = w[i];
        b = cv[3 * (i / 3) + (i % 3 + 1) % 3];
        if (t >= 0 && (tf = tt__find_sorted(faces, n, mesh->corner_face[t])) >= 0) {
            if (t < c) continue;
            W += w[3 * tf + (t - mesh->face_start[mesh->corner_face[t]])];
        }
        if (W < 1e-3 * mean_w) W = 1e-3 * mean_w;
        for (side = 0; side < 2; side++) {
            int s = side ? b : a, o = side ? a : b;
            if (unk[s] < 0) continue;
            trip[nt].row = trip[nt].col = unk[s];
            trip[nt++].value = W;
            if (unk[o] >= 0) {
                trip[nt].row = unk[s];
                trip[nt].col = unk[o];
                trip[nt++].value = -W;
            } else {
                rhs[unk[s]] += W * uv[2 * o];
                rhs[nunk + unk[s]] += W * uv[2 * o + 1];
            }
        }
    }
    if (nunk > 0) {
        tt_cg_options co;
        tt_cg_report cr;
        double mx = 0, my = 0;
        int d;
        for (p = 0; p < nb; p++) {
            mx += uv[2 * loop[p]] / nb;
            my += uv[2 * loop[p] + 1] / nb;
        }
        res = tt_sparse_from_triplets(nunk, nunk, trip, nt, allocator, &A, error);
        if (res != TT_OK) goto done;
        memset(&co, 0, sizeof co);
        co.tolerance = tol;
        co.max_iterations = maxit;
        for (d = 0; d < 2; d++) {
            double *xd = x + d * nunk;
            for (i = 0; i < nunk; i++) xd[i] = d ? my : mx;
            res = tt_cg_solve(A, rhs + d * nunk, &co, allocator, xd, &cr, error);
            rep.cg_iterations += cr.iterations;
            if (res != TT_OK) goto done;
        }
        for (i = 0; i < nv; i++)
            if (unk[i] >= 0) {
                uv[2 * i] = x[unk[i]];
                uv[2 * i + 1] = x[nunk + unk[i]];
            }
    }

    /* Measures (D9). */
    rep.mapped = 1;
    for (i = 0; i < n; i++) {
        double P0[3], P1[3], P2[3], e[3], f[3], cr[3], xa[3], l1, fx, fy, area3;
        const double *u0 = uv + 2 * cv[3 * i], *u1 = uv + 2 * cv[3 * i + 1], *u2 = uv + 2 * cv[3 * i + 2];
        double a2 = 0.5 * tt__orient2(u0[0], u0[1], u1[0], u1[1], u2[0], u2[1]);
        double J00, J01, J10, J11, E, F, G, H, Q, R, s1, s2;
        mapped += a2;
        if (!(a2 > 0)) {
            rep.flipped++;
            if (first_flip < 0) first_flip = faces[i];
        }
        tt__flat_point(mesh, lv[cv[3 * i]], P0);
        tt__flat_point(mesh, lv[cv[3 * i + 1]], P1);
        tt__flat_point(mesh, lv[cv[3 * i + 2]], P2);
        for (j = 0; j < 3; j++) {
            e[j] = P1[j] - P0[j];
            f[j] = P2[j] - P0[j];
        }
        tt__cross3(e, f, cr);
        area3 = 0.5 * tt__length3(cr);
        l1 = tt__length3(e);
        for (j = 0; j < 3; j++) xa[j] = e[j] / l1;
        fx = tt__dot3(f, xa);
        fy = 2 * area3 / l1;
        /* J = U P^-1, P = [[l1, fx], [0, fy]] */
        J00 = (u1[0] - u0[0]) / l1;
        J10 = (u1[1] - u0[1]) / l1;
        J01 = ((u2[0] - u0[0]) - J00 * fx) / fy;
        J11 = ((u2[1] - u0[1]) - J10 * fx) / fy;
        E = 0.5 * (J00 + J11);
        F = 0.5 * (J00 - J11);
        G = 0.5 * (J10 + J01);
        H = 0.5 * (J10 - J01);
        Q = sqrt(E * E + H * H);
        R = sqrt(F * F + G * G);
        s1 = Q + R;
        s2 = fabs(Q - R);
        keys[i].value = s2 > 1e-300 ? s1 / s2 : (double)tt__infinity();
        keys[i].weight = area3;
        if (keys[i].value > rep.max_stretch) rep.max_stretch = keys[i].value;
    }
    tt__weighted_percentiles(keys, n, &p95, 1, &rep.stretch_p95);
    rep.mapped_area = mapped;
    rep.r = mapped > 0 ? surface / mapped : (double)tt__infinity();
    rep.flattening_error = fabs(rep.r - 1);
    if (rep.flipped > 0) {
        res = tt__fail(error, TT_ERROR_NOT_FLAT, first_flip, -1, -1, -1,
                       "cluster %d folds: %d of its %d triangles flip, face %d first", cluster, rep.flipped, n,
                       first_flip);
        if (error) error->item = cluster;
        goto done;
    }
    if (rep.flattening_error > max_error) {
        res = tt__fail_at(error, TT_ERROR_NOT_FLAT, cluster, -1, -1,
                          "cluster %d has flattening error %.4g, above the allowed %.4g: split it", cluster,
                          rep.flattening_error, max_error);
        goto done;
    }
    if (max_stretch > 0 && rep.stretch_p95 > max_stretch) {
        res = tt__fail_at(error, TT_ERROR_NOT_FLAT, cluster, -1, -1,
                          "cluster %d has a 95th percentile stretch of %.4g, above the allowed %.4g: split it",
                          cluster, rep.stretch_p95, max_stretch);
        goto done;
    }
    for (i = 0; i < 3 * n; i++) {
        int c = mesh->face_start[faces[i / 3]] + i % 3;
        corner_uv[2 * c] = (float)uv[2 * cv[i]];
        corner_uv[2 * c + 1] = (float)uv[2 * cv[i] + 1];
    }
    goto done;

bad_border:
    res = tt__fail_at(error, TT_ERROR_INVALID_ARGUMENT, cluster, -1, -1,
                      "cluster %d: its border is not one loop through its control vertices in order "
                      "(a hierarchy not made by tt_cluster_hierarchy_build?)",
                      cluster);
    goto done;
oom:
    res = tt__fail_at(error, TT_ERROR_OUT_OF_MEMORY, cluster, -1, -1, "out of memory flattening cluster %d",
                      cluster);
done:
    if (report) *report = rep;
    tt_sparse_matrix_free(A);
    tt__free(allocator, lv);
    tt__free(allocator, cv);
    tt__free(allocator, next);
    tt__free(allocator, loop);
    tt__free(allocator, at);
    tt__free(allocator, unk);
    tt__free(allocator, uv);
    tt__free(allocator, w);
    tt__free(allocator, q);
    tt__free(allocator, arc);
    tt__free(allocator, rhs);
    tt__free(allocator, x);
    tt__free(allocator, bxy);
    tt__free(allocator, keys);
    tt__free(allocator, trip);
    return res;
}


/* ---- The pipeline (tt_hpm_map) ---- */

/* A textured neighbour of the cluster being placed, and the rigid map
   q = R(angle) (x / s) + shift that best takes its texture coordinates x
   (texels) of the shared vertices onto the cluster's flattened positions q
   (spec D16). */
typedef struct tt__hpm_owner {
    int cluster;
    int shared;                 /* shared border vertices */
    double cos_a, sin_a;        /* R(angle) */
    double shift[2];
    int valid;                  /* at least two distinct shared vertices */
} tt__hpm_owner;

typedef struct tt__hpm {
    const tt_mesh *mesh;
    const tt_allocator *al;
    tt_cluster_hierarchy *H;
    tt_rng rng;                 /* turns, starts */
    tt_rng place_rng;           /* the random-placement control's own stream: decisions do not change */
    double s;                   /* texels per world unit */
    double threshold, band, floor_px;
    int rotations, min_faces, toroidal;
    int copies;                 /* turned copies matched per fit (those within max_turn) */
    double angle[64];           /* their angles, radians: 0 first, then by growing |angle| */
    unsigned flags;
    tt_flatten_options fopt;
    /* the image in the matching colour space (D3) */
    int W, Hh, nch;
    float *full;                /* nch planes W x Hh */
    double sigma2;              /* mean per-channel variance */
    int f, ww, wh, P;           /* box factor, matching copy's size, FFT size */
    float *match;               /* nch planes ww x wh */
    tt_xcorr_texture **tex;     /* `copies` turned copies */
    double *xwork, *mask, *values;
    unsigned char *support;     /* P x P: 1 = the cluster's footprint, 2 = band */
    unsigned char *allowed_mem; /* copies x P x P */
    const unsigned char **allowed;
    float *dist;                /* P x P distance to the footprint, canvas texels */
    float *src;                 /* 2 x P x P: the neighbour's texel position shown at a band pixel */
    int *band_pixels, nband;
    /* the mesh's state */
    float *flat;                /* 2 * ncorners: flattened positions, world units */
    double *uv;                 /* 2 * ncorners: the fitted map, texels */
    double *out;                /* the random-placement control's map, or NULL */
    int *owner;                 /* per face: the textured cluster showing it, or -1 */
    int *in_c, *seen;           /* per face stamps */
    double *placed;             /* 2 * ncorners: each cluster's rigid placement, before its border work */
    double *vdisp;              /* 5 * nverts: displacement, its sums, for the interior re-solve */
    int *vmark;                 /* per vertex: stamp of the cluster it is inside (not on its border) */
    int stamp;
    unsigned char *state;       /* per cluster: 0 new, 1 done, 2 waiting */
    tt__heap_item **queue;
    int *qcount, *qcap;
    int *waiting, nwaiting, waitcap;
    tt__heap_item *heap;        /* the band search (3 * nfaces) */
    int *near_faces, nnear;
    tt__hpm_owner *owners;
    int nowners, ownercap;
    double *pairs;              /* per shared (vertex, owner): owner index, a.x, a.y, b.x, b.y */
    int npairs, paircap;
    int textured;
    tt_progress_fn progress;
    void *progress_user_data;
    tt_hpm_report rep;
    double error_sum;
} tt__hpm;

/* Bilinear sample of nch float planes (w x h, texel i covering [i, i+1)),
   clamped to the edge or wrapped. */
static void tt__hpm_sample(const float *planes, int w, int h, int nch, double x, double y, int wrap, double *out)
{
    double fx = x - 0.5, fy = y - 0.5, tx, ty;
    int x0, y0, x1, y1, c;
    size_t plane = (size_t)w * h;
    if (!(fx > -1e9 && fx < 1e9)) fx = 0;
    if (!(fy > -1e9 && fy < 1e9)) fy = 0;
    x0 = (int)floor(fx);
    y0 = (int)floor(fy);
    tx = fx - x0;
    ty = fy - y0;
    x1 = x0 + 1;
    y1 = y0 + 1;
    if (wrap) {
        x0 = ((x0 % w) + w) % w;
        x1 = ((x1 % w) + w) % w;
        y0 = ((y0 % h) + h) % h;
        y1 = ((y1 % h) + h) % h;
    } else {
        x0 = tt__clamp_i(x0, 0, w - 1);
        x1 = tt__clamp_i(x1, 0, w - 1);
        y0 = tt__clamp_i(y0, 0, h - 1);
        y1 = tt__clamp_i(y1, 0, h - 1);
    }
    for (c = 0; c < nch; c++) {
        const float *p = planes + c * plane;
        double top = p[(size_t)y0 * w + x0] * (1 - tx) + p[(size_t)y0 * w + x1] * tx;
        double bottom = p[(size_t)y1 * w + x0] * (1 - tx) + p[(size_t)y1 * w + x1] * tx;
        out[c] = top * (1 - ty) + bottom * ty;
    }
}

/* Step 1: the matching colour space, the matching copy and the cached
   spectra of its turned copies. */
static tt_result tt__hpm_prepare_image(tt__hpm *S, const tt_image *image, int match_size, tt_error *error)
{
    size_t n = (size_t)image->width * image->height, i, pp;
    int c, k, x, y, grey = 1, big;
    double mean[3] = {0, 0, 0}, var = 0;
    double *buffer = NULL;
    tt_result res = TT_OK;
    S->W = image->width;
    S->Hh = image->height;
    S->full = TT__ALLOC(S->al, float, 3 * n);
    if (!S->full) return tt__fail(error, TT_ERROR_OUT_OF_MEMORY, -1, -1, -1, -1, "out of memory (image copy)");
    for (i = 0; i < n; i++) {
        const float *p = image->pixels + 4 * i;
        double r, g, b;
        if (!tt__is_finite(p[0]) || !tt__is_finite(p[1]) || !tt__is_finite(p[2]))
            return tt__fail_at(error, TT_ERROR_NON_FINITE, -1, (int)(i / (size_t)image->width),
                               (int)(i % (size_t)image->width), "texel (%d, %d) of the image is not finite",
                               (int)(i % (size_t)image->width), (int)(i / (size_t)image->width));
        /* As displayed (D3, and as the seam measure compares them). */
        r = tt_linear_to_srgb(p[0]);
        g = tt_linear_to_srgb(p[1]);
        b = tt_linear_to_srgb(p[2]);
        S->full[i] = (float)(0.299 * r + 0.587 * g + 0.114 * b);
        S->full[n + i] = (float)(-0.168736 * r - 0.331264 * g + 0.5 * b);
        S->full[2 * n + i] = (float)(0.5 * r - 0.418688 * g - 0.081312 * b);
        if (fabs(S->full[n + i]) > 1e-4 || fabs(S->full[2 * n + i]) > 1e-4) grey = 0;
    }
    S->nch = grey ? 1 : 3; /* D32: no chroma planes for a grey image */
    for (c = 0; c < S->nch; c++) {
        for (i = 0; i < n; i++) mean[c] += S->full[c * n + i];
        mean[c] /= (double)n;
        for (i = 0; i < n; i++) var += (S->full[c * n + i] - mean[c]) * (S->full[c * n + i] - mean[c]);
    }
    S->sigma2 = var / ((double)n * S->nch);
    if (!(S->sigma2 > 1e-12)) S->sigma2 = 1e-12; /* a flat image: every fit is perfect */

    /* The matching copy: f x f box filter (D30). */
    big = tt__max_i(S->W, S->Hh);
    S->f = 1;
    while (big > match_size * S->f) S->f *= 2;
    S->ww = (S->W + S->f - 1) / S->f;
    S->wh = (S->Hh + S->f - 1) / S->f;
    S->match = TT__ALLOC(S->al, float, (size_t)S->nch * S->ww * S->wh);
    if (!S->match) return tt__fail(error, TT_ERROR_OUT_OF_MEMORY, -1, -1, -1, -1, "out of memory (image copy)");
    for (c = 0; c < S->nch; c++)
        for (y = 0; y < S->wh; y++)
            for (x = 0; x < S->ww; x++) {
                double sum = 0;
                int cnt = 0, a, b;
                for (b = y * S->f; b < tt__min_i((y + 1) * S->f, S->Hh); b++)
                    for (a = x * S->f; a < tt__min_i((x + 1) * S->f, S->W); a++) {
                        sum += S->full[c * n + (size_t)b * S->W + a];
                        cnt++;
                    }
                S->match[(size_t)c * S->ww * S->wh + (size_t)y * S->ww + x] = (float)(sum / cnt);
            }

    /* P: a turned copy fits (bounded), or two periods do (toroidal; D5). */
    {
        double need = S->toroidal ? 2.0 * tt__max_i(S->ww, S->wh)
                                  : sqrt((double)S->ww * S->ww + (double)S->wh * S->wh) + 2;
        S->P = 16;
        while (S->P < need) S->P *= 2;
    }
    pp = (size_t)S->P * S->P;
    S->tex = TT__ALLOC(S->al, tt_xcorr_texture *, (size_t)S->copies);
    if (S->tex)
        for (k = 0; k < S->copies; k++) S->tex[k] = NULL;
    buffer = TT__ALLOC(S->al, double, (size_t)S->nch * pp);
    if (!S->tex || !buffer) {
        tt__free(S->al, buffer);
        return tt__fail(error, TT_ERROR_OUT_OF_MEMORY, -1, -1, -1, -1, "out of memory (turned copies)");
    }
    for (k = 0; k < S->copies && res == TT_OK; k++) {
        double th = S->angle[k], ct = cos(th), st = sin(th);
        double cb = 0.5 * S->P, ctx = 0.5 * S->ww, cty = 0.5 * S->wh;
        for (y = 0; y < S->P; y++)
            for (x = 0; x < S->P; x++) {
                /* buffer point b -> matching copy R(-theta) (b - c_B) + c_T */
                double bx = x + 0.5 - cb, by = y + 0.5 - cb, v[3];
                double wx = ct * bx + st * by + ctx, wy = -st * bx + ct * by + cty;
                size_t at = (size_t)y * S->P + x;
                if (!S->toroidal && (wx < 0 || wy < 0 || wx > S->ww || wy > S->wh)) {
                    for (c = 0; c < S->nch; c++) buffer[c * pp + at] = 0;
                    continue;
                }
                tt__hpm_sample(S->match, S->ww, S->wh, S->nch, wx, wy, S->toroidal, v);
                for (c = 0; c < S->nch; c++) buffer[c * pp + at] = v[c];
            }
        res = tt_xcorr_texture_create(S->P, S->P, S->nch, buffer, S->al, &S->tex[k], error);
    }
    tt__free(S->al, buffer);
    if (res != TT_OK) return res;
    S->xwork = TT__ALLOC(S->al, double, S->tex[0]->best_work_size);
    S->mask = TT__ALLOC(S->al, double, pp);
    S->values = TT__ALLOC(S->al, double, (size_t)S->nch * pp);
    S->support = TT__ALLOC(S->al, unsigned char, pp);
    S->allowed_mem = TT__ALLOC(S->al, unsigned char, pp * (size_t)S->copies);
    S->allowed = TT__ALLOC(S->al, const unsigned char *, (size_t)S->copies);
    S->dist = TT__ALLOC(S->al, float, pp);
    S->src = TT__ALLOC(S->al, float, 2 * pp);
    S->band_pixels = TT__ALLOC(S->al, int, pp);
    if (!S->xwork || !S->mask || !S->values || !S->support || !S->allowed_mem || !S->allowed || !S->dist ||
        !S->src || !S->band_pixels)
        return tt__fail(error, TT_ERROR_OUT_OF_MEMORY, -1, -1, -1, -1, "out of memory (fit buffers)");
    for (k = 0; k < S->copies; k++) S->allowed[k] = S->allowed_mem + (size_t)k * pp;
    return TT_OK;
}

/* Mark cluster C's faces in in_c with a fresh stamp; returns it. */
static int tt__hpm_mark(tt__hpm *S, int C)
{
    const tt_cluster *cl = &S->H->clusters[C];
    int i;
    S->stamp++;
    for (i = 0; i < cl->nfaces; i++) S->in_c[S->H->faces[cl->first_face + i]] = S->stamp;
    return S->stamp;
}

/* 0: no face of C is textured, 1: some, 2: all. */
static int tt__hpm_textured_state(const tt__hpm *S, int C)
{
    const tt_cluster *cl = &S->H->clusters[C];
    int i, t = 0;
    for (i = 0; i < cl->nfaces; i++) t += S->owner[S->H->faces[cl->first_face + i]] >= 0;
    return t == 0 ? 0 : (t == cl->nfaces ? 2 : 1);
}

/* The queue key of C (D22): textured neighbouring regions (any level),
   then the textured share of its border. Smaller keys pop first. */
static double tt__hpm_key(tt__hpm *S, int C, int *count)
{
    const tt_mesh *m = S->mesh;
    const tt_cluster *cl = &S->H->clusters[C];
    int stamp = tt__hpm_mark(S, C), i, j, n = 0, seen[8], nseen = 0, border = 0, shared = 0;
    for (i = 0; i < cl->nfaces; i++) {
        int f = S->H->faces[cl->first_face + i];
        for (j = m->face_start[f]; j < m->face_start[f + 1]; j++) {
            int t = m->twin[j], g, o, k, dup = 0;
            if (t < 0) continue;
            g = m->corner_face[t];
            if (S->in_c[g] == stamp) continue;
            border++;
            o = S->owner[g];
            if (o < 0) continue;
            shared++;
            for (k = 0; k < nseen; k++) dup |= seen[k] == o;
            if (!dup) {
                n++;
                if (nseen < 8) seen[nseen++] = o;
            }
        }
    }
    *count = n;
    return -(n + (border > 0 ? 0.999 * shared / border : 0));
}

static int tt__hpm_push(tt__hpm *S, int level, int C)
{
    int count;
    double key;
    if (S->state[C] == 1) return 1;
    if (level >= S->H->nlevels) level = S->H->nlevels - 1;
    key = tt__hpm_key(S, C, &count);
    if (S->qcount[level] == S->qcap[level]) {
        int cap = S->qcap[level] ? 2 * S->qcap[level] : 64;
        tt__heap_item *q = (tt__heap_item *)tt__alloc_array(S->al, (size_t)cap, sizeof(tt__heap_item));
        if (!q) return 0;
        if (S->qcount[level]) memcpy(q, S->queue[level], (size_t)S->qcount[level] * sizeof *q);
        tt__free(S->al, S->queue[level]);
        S->queue[level] = q;
        S->qcap[level] = cap;
    }
    tt__heap_push(S->queue[level], &S->qcount[level], key, C);
    return 1;
}

/* Queue the children of C at the next level (a split). */
static int tt__hpm_split(tt__hpm *S, int C)
{
    const tt_cluster *cl = &S->H->clusters[C];
    int i;
    for (i = 0; i < cl->nchildren; i++)
        if (!tt__hpm_push(S, cl->level + 1, cl->first_child + i)) return 0;
    return 1;
}

/* q (texel-frame orientation: y mirrored so that a rotation keeps the UVs
   counter-clockwise with v up) of corner c after flattening. */
static void tt__hpm_q(const tt__hpm *S, int c, double *q)
{
    q[0] = S->flat[2 * c];
    q[1] = -(double)S->flat[2 * c + 1];
}

/* The textured neighbours of C and their rigid maps (D16). C's faces are
   marked in in_c with `stamp`. */
static int tt__hpm_owners(tt__hpm *S, int C, int stamp)
{
    const tt_mesh *m = S->mesh;
    const tt_cluster *cl = &S->H->clusters[C];
    int i, j, k, p;
    S->nowners = 0;
    S->npairs = 0;
    for (i = 0; i < cl->nfaces; i++) {
        int f = S->H->faces[cl->first_face + i];
        for (j = m->face_start[f]; j < m->face_start[f + 1]; j++) {
            int t = m->twin[j], v = m->corner_vert[j], start, h, local[16], nlocal = 0, guard = 0;
            double q[2];
            if (t >= 0 && S->in_c[m->corner_face[t]] == stamp) continue;
            /* j is a border half-edge: its origin v is a border vertex, met once. */
            tt__hpm_q(S, j, q);
            start = h = m->vert_corner[v];
            while (h >= 0 && guard++ <= m->ncorners) {
                int g = m->corner_face[h], o = S->owner[g], prev;
                if (S->in_c[g] != stamp && o >= 0) {
                    int dup = 0;
                    for (k = 0; k < nlocal; k++) dup |= local[k] == o;
                    if (!dup && nlocal < 16) {
                        int oi = -1;
                        local[nlocal++] = o;
                        for (k = 0; k < S->nowners; k++)
                            if (S->owners[k].cluster == o) oi = k;
                        if (oi < 0) {
                            if (S->nowners == S->ownercap) {
                                tt__hpm_owner *no = (tt__hpm_owner *)tt__grow(S->al, S->owners, &S->ownercap,
                                                                              S->nowners + 1, sizeof *no);
                                if (!no) return 0;
                                S->owners = no;
                            }
                            oi = S->nowners++;
                            memset(&S->owners[oi], 0, sizeof S->owners[oi]);
                            S->owners[oi].cluster = o;
                        }
                        S->owners[oi].shared++;
                        if (S->npairs == S->paircap) {
                            double *np = (double *)tt__grow(S->al, S->pairs, &S->paircap, S->npairs + 1,
                                                            5 * sizeof(double));
                            if (!np) return 0;
                            S->pairs = np;
                        }
                        p = 5 * S->npairs++;
                        S->pairs[p] = oi;
                        S->pairs[p + 1] = S->uv[2 * h] / S->s;
                        S->pairs[p + 2] = S->uv[2 * h + 1] / S->s;
                        S->pairs[p + 3] = q[0];
                        S->pairs[p + 4] = q[1];
                    }
                }
                prev = tt_mesh_prev(m, h);
                h = m->twin[prev];
                if (h == start) break;
            }
        }
    }
    /* 2D Procrustes per owner: centre both point sets, the angle is
       atan2(sum of cross products, sum of dot products). */
    for (k = 0; k < S->nowners; k++) {
        tt__hpm_owner *O = &S->owners[k];
        double ca[2] = {0, 0}, cb[2] = {0, 0}, dot = 0, cross = 0, spread = 0, len;
        for (p = 0; p < S->npairs; p++) {
            const double *r = S->pairs + 5 * p;
            if ((int)r[0] != k) continue;
            ca[0] += r[1] / O->shared;
            ca[1] += r[2] / O->shared;
            cb[0] += r[3] / O->shared;
            cb[1] += r[4] / O->shared;
        }
        for (p = 0; p < S->npairs; p++) {
            const double *r = S->pairs + 5 * p;
            double ax, ay, bx, by;
            if ((int)r[0] != k) continue;
            ax = r[1] - ca[0];
            ay = r[2] - ca[1];
            bx = r[3] - cb[0];
            by = r[4] - cb[1];
            dot += ax * bx + ay * by;
            cross += ax * by - ay * bx;
            spread += ax * ax + ay * ay;
        }
        len = sqrt(dot * dot + cross * cross);
        O->valid = O->shared >= 2 && spread > 0 && len > 0;
        if (!O->valid) continue;
        O->cos_a = dot / len;
        O->sin_a = cross / len;
        O->shift[0] = cb[0] - (O->cos_a * ca[0] - O->sin_a * ca[1]);
        O->shift[1] = cb[1] - (O->sin_a * ca[0] + O->cos_a * ca[1]);
    }
    return 1;
}

/* A placement x = s R(angle) q + shift, in texels. */
typedef struct tt__hpm_place {
    double cos_a, sin_a, shift[2];
} tt__hpm_place;

static void tt__hpm_apply(const tt__hpm *S, const tt__hpm_place *pl, const double *q, double *x)
{
    x[0] = S->s * (pl->cos_a * q[0] - pl->sin_a * q[1]) + pl->shift[0];
    x[1] = S->s * (pl->sin_a * q[0] + pl->cos_a * q[1]) + pl->shift[1];
}

/* Bounding box of C's corners under the rotation part of pl (shift 0). */
static void tt__hpm_bbox(const tt__hpm *S, int C, double cos_a, double sin_a, double *box)
{
    const tt_cluster *cl = &S->H->clusters[C];
    tt__hpm_place pl;
    int i, j;
    pl.cos_a = cos_a;
    pl.sin_a = sin_a;
    pl.shift[0] = pl.shift[1] = 0;
    box[0] = box[1] = 1e300;
    box[2] = box[3] = -1e300;
    for (i = 0; i < cl->nfaces; i++) {
        int f = S->H->faces[cl->first_face + i];
        for (j = S->mesh->face_start[f]; j < S->mesh->face_start[f + 1]; j++) {
            double q[2], x[2];
            tt__hpm_q(S, j, q);
            tt__hpm_apply(S, &pl, q, x);
            if (x[0] < box[0]) box[0] = x[0];
            if (x[1] < box[1]) box[1] = x[1];
            if (x[0] > box[2]) box[2] = x[0];
            if (x[1] > box[3]) box[3] = x[1];
        }
    }
}

/* A random place (a start, or the control's output): a random angle (0
   with TT_HPM_NO_RANDOM_TURN) and a random shift keeping the cluster one
   texel inside a bounded image, trying the other rotations' angles when it
   does not fit. Returns 0 when it fits at no angle. */
static int tt__hpm_random_place(tt__hpm *S, tt_rng *rng, int C, tt__hpm_place *pl)
{
    double a0 = (S->flags & TT_HPM_NO_RANDOM_TURN) ? 0 : TT__TWO_PI * tt_rng_float(rng);
    double ux = tt_rng_float(rng), uy = tt_rng_float(rng);
    int k;
    for (k = 0; k < S->rotations; k++) {
        double a = a0 + TT__TWO_PI * k / S->rotations, box[4];
        pl->cos_a = cos(a);
        pl->sin_a = sin(a);
        tt__hpm_bbox(S, C, pl->cos_a, pl->sin_a, box);
        if (S->toroidal) {
            pl->shift[0] = ux * S->W - 0.5 * (box[0] + box[2]);
            pl->shift[1] = uy * S->Hh - 0.5 * (box[1] + box[3]);
            return 1;
        }
        if (box[2] - box[0] <= S->W - 2 && box[3] - box[1] <= S->Hh - 2) {
            pl->shift[0] = 1 - box[0] + ux * (S->W - 2 - (box[2] - box[0]));
            pl->shift[1] = 1 - box[1] + uy * (S->Hh - 2 - (box[3] - box[1]));
            return 1;
        }
    }
    return 0;
}

/* Continue the map of C's best textured neighbour (most shared vertices,
   then the smaller cluster index): the inverse of its rigid map. */
static const tt__hpm_owner *tt__hpm_best_owner(const tt__hpm *S)
{
    const tt__hpm_owner *best = NULL;
    int k;
    for (k = 0; k < S->nowners; k++) {
        const tt__hpm_owner *O = &S->owners[k];
        if (!O->valid) continue;
        if (!best || O->shared > best->shared || (O->shared == best->shared && O->cluster < best->cluster))
            best = O;
    }
    return best;
}

static int tt__hpm_continue_place(const tt__hpm *S, int C, tt__hpm_place *pl)
{
    const tt__hpm_owner *best = tt__hpm_best_owner(S);
    if (!best) return 0;
    /* q = R(b) x / s + d  =>  x = s R(-b) (q - d) */
    pl->cos_a = best->cos_a;
    pl->sin_a = -best->sin_a;
    pl->shift[0] = -S->s * (pl->cos_a * best->shift[0] - pl->sin_a * best->shift[1]);
    pl->shift[1] = -S->s * (pl->sin_a * best->shift[0] + pl->cos_a * best->shift[1]);
    if (!S->toroidal) {
        /* a bounded image: only when the cluster stays a texel inside */
        double box[4];
        tt__hpm_bbox(S, C, pl->cos_a, pl->sin_a, box);
        if (box[0] + pl->shift[0] < 1 || box[1] + pl->shift[1] < 1 || box[2] + pl->shift[0] > S->W - 1 ||
            box[3] + pl->shift[1] > S->Hh - 1)
            return 0;
    }
    return 1;
}

typedef struct tt__hpm_raster {
    tt__hpm *S;
    double x[6];                /* the neighbour's texel positions of the three corners */
    double band;                /* canvas texels */
} tt__hpm_raster;

static void tt__hpm_raster_footprint(int x, int y, const float bary[3], void *user)
{
    tt__hpm_raster *r = (tt__hpm_raster *)user;
    (void)bary;
    r->S->support[(size_t)y * r->S->P + x] = 1;
}

static double tt__hpm_band_weight(double d)
{
    return 1.0 / (1.0 + d);
}

static void tt__hpm_raster_band(int x, int y, const float bary[3], void *user)
{
    tt__hpm_raster *r = (tt__hpm_raster *)user;
    tt__hpm *S = r->S;
    size_t at = (size_t)y * S->P + x, pp = (size_t)S->P * S->P;
    double sx, sy, v[3];
    int c;
    if (S->support[at] != 0 || S->dist[at] > r->band) return;
    sx = bary[0] * r->x[0] + bary[1] * r->x[2] + bary[2] * r->x[4];
    sy = bary[0] * r->x[1] + bary[1] * r->x[3] + bary[2] * r->x[5];
    tt__hpm_sample(S->match, S->ww, S->wh, S->nch, sx / S->f, sy / S->f, S->toroidal, v);
    for (c = 0; c < S->nch; c++) S->values[c * pp + at] = v[c];
    S->mask[at] = tt__hpm_band_weight(S->dist[at] * S->f);
    S->support[at] = 2;
    S->src[2 * at] = (float)sx;
    S->src[2 * at + 1] = (float)sy;
    S->band_pixels[S->nband++] = (int)at;
}

/* Distance (texels) of every canvas pixel to the footprint, by two
   chamfer passes (1, sqrt 2) over the w x h corner of the canvas. */
static void tt__hpm_distance(tt__hpm *S, int w, int h)
{
    const float diag = 1.41421356f;
    int x, y, P = S->P;
    for (y = 0; y < h; y++)
        for (x = 0; x < w; x++) S->dist[(size_t)y * P + x] = S->support[(size_t)y * P + x] == 1 ? 0.0f : 1e30f;
    for (y = 0; y < h; y++)
        for (x = 0; x < w; x++) {
            float *d = &S->dist[(size_t)y * P + x];
            if (x > 0 && d[-1] + 1 < *d) *d = d[-1] + 1;
            if (y > 0) {
                if (d[-P] + 1 < *d) *d = d[-P] + 1;
                if (x > 0 && d[-P - 1] + diag < *d) *d = d[-P - 1] + diag;
                if (x + 1 < w && d[-P + 1] + diag < *d) *d = d[-P + 1] + diag;
            }
        }
    for (y = h - 1; y >= 0; y--)
        for (x = w - 1; x >= 0; x--) {
            float *d = &S->dist[(size_t)y * P + x];
            if (x + 1 < w && d[1] + 1 < *d) *d = d[1] + 1;
            if (y + 1 < h) {
                if (d[P] + 1 < *d) *d = d[P] + 1;
                if (x + 1 < w && d[P + 1] + diag < *d) *d = d[P + 1] + diag;
                if (x > 0 && d[P - 1] + diag < *d) *d = d[P - 1] + diag;
            }
        }
}

/* The textured faces near C whose owner has a rigid map, by a Dijkstra
   over face centroids from the faces across C's border, up to `reach`
   world units. */
static void tt__hpm_near_faces(tt__hpm *S, int C, int stamp, double reach)
{
    const tt_mesh *m = S->mesh;
    const tt_cluster *cl = &S->H->clusters[C];
    int i, j, nheap = 0;
    S->nnear = 0;
    for (i = 0; i < cl->nfaces; i++) {
        int f = S->H->faces[cl->first_face + i];
        for (j = m->face_start[f]; j < m->face_start[f + 1]; j++) {
            int t = m->twin[j], g;
            if (t < 0) continue;
            g = m->corner_face[t];
            if (S->in_c[g] == stamp || S->owner[g] < 0 || S->seen[g] == stamp) continue;
            S->seen[g] = stamp;
            tt__heap_push(S->heap, &nheap, 0, g);
        }
    }
    while (nheap > 0) {
        tt__heap_item it = tt__heap_pop(S->heap, &nheap);
        int g = it.value, k, valid = 0;
        double cg[3] = {0, 0, 0};
        for (k = 0; k < S->nowners; k++)
            if (S->owners[k].cluster == S->owner[g]) valid = S->owners[k].valid;
        if (!valid) continue;
        S->near_faces[S->nnear++] = g;
        if (it.key > reach) continue;
        for (j = m->face_start[g]; j < m->face_start[g + 1]; j++) {
            const float *p = m->pos + 3 * m->corner_vert[j];
            cg[0] += p[0] / 3;
            cg[1] += p[1] / 3;
            cg[2] += p[2] / 3;
        }
        for (j = m->face_start[g]; j < m->face_start[g + 1]; j++) {
            int t = m->twin[j], h, l;
            double ch[3] = {0, 0, 0}, d[3];
            if (t < 0) continue;
            h = m->corner_face[t];
            if (S->in_c[h] == stamp || S->owner[h] < 0 || S->seen[h] == stamp) continue;
            S->seen[h] = stamp;
            for (l = m->face_start[h]; l < m->face_start[h + 1]; l++) {
                const float *p = m->pos + 3 * m->corner_vert[l];
                ch[0] += p[0] / 3;
                ch[1] += p[1] / 3;
                ch[2] += p[2] / 3;
            }
            for (l = 0; l < 3; l++) d[l] = ch[l] - cg[l];
            tt__heap_push(S->heap, &nheap, it.key + tt__length3(d), h);
        }
    }
}

/* The band width in image texels for cluster C (D15). */
static double tt__hpm_band_width(const tt__hpm *S, int C)
{
    double w;
    if (S->band > 0) return S->band;
    w = 0.2 * sqrt(S->H->clusters[C].area * S->s * S->s / TT__PI);
    return w < 3 ? 3 : (w > 24 ? 24 : w);
}

/* D28, orientation refinement: the copies are 360 / rotations degrees
   apart, so neighbouring patches of an anisotropic texture can disagree by
   up to half a step (9.5 degrees at 19). At the chosen offset the turn is
   refined by a golden-section search of the band's direct sum over +-half a
   step, turning the placement about the band's centre; a turn is kept only
   when it lowers the sum (an exact continuation stays exact) and keeps a
   bounded image's margin. Skipped with fewer than 4 orientations, where
   half a step is no small correction. Returns the band sum at the result.
   The band pixel at canvas index `at` shows, at the unrefined turn, the
   image at f (R(theta) (canvas + (mx, my)) + (ctx, cty)) + (dx, dy). */
#define TT__HPM_TURN_STEPS 10

static double tt__hpm_turn_sum(const tt__hpm *S, double delta, const double *pivot, double mx, double my, double ct,
                               double st, double ctx, double cty, int dx, int dy)
{
    double sum = 0, cd = cos(delta), sd = sin(delta), vb[3], vc[3];
    int i, c, P = S->P;
    for (i = 0; i < S->nband; i++) {
        int at = S->band_pixels[i];
        double cx = at % P + 0.5 + mx, cy = at / P + 0.5 + my;
        double x = S->f * (ct * cx + st * cy + ctx) + dx - pivot[0];
        double y = S->f * (-st * cx + ct * cy + cty) + dy - pivot[1];
        tt__hpm_sample(S->full, S->W, S->Hh, S->nch, S->src[2 * at], S->src[2 * at + 1], S->toroidal, vb);
        tt__hpm_sample(S->full, S->W, S->Hh, S->nch, cd * x - sd * y + pivot[0], sd * x + cd * y + pivot[1],
                       S->toroidal, vc);
        for (c = 0; c < S->nch; c++) sum += S->mask[at] * (vb[c] - vc[c]) * (vb[c] - vc[c]);
    }
    return sum;
}

/* pl turned by delta about pivot; 0 when it leaves a bounded image. */
static int tt__hpm_turned(const tt__hpm *S, int C, const tt__hpm_place *pl, double delta, const double *pivot,
                          tt__hpm_place *out)
{
    double cd = cos(delta), sd = sin(delta), box[4], x = pl->shift[0] - pivot[0], y = pl->shift[1] - pivot[1];
    out->cos_a = cd * pl->cos_a - sd * pl->sin_a;
    out->sin_a = sd * pl->cos_a + cd * pl->sin_a;
    out->shift[0] = cd * x - sd * y + pivot[0];
    out->shift[1] = sd * x + cd * y + pivot[1];
    if (S->toroidal) return 1;
    tt__hpm_bbox(S, C, out->cos_a, out->sin_a, box);
    return box[0] + out->shift[0] >= 1 && box[1] + out->shift[1] >= 1 && box[2] + out->shift[0] <= S->W - 1 &&
           box[3] + out->shift[1] <= S->Hh - 1;
}

static double tt__hpm_refine_turn(const tt__hpm *S, int C, tt__hpm_place *pl, double sum0, double mx, double my,
                                  double ct, double st, double ctx, double cty, int dx, int dy)
{
    const double golden = 0.6180339887498949;
    double half = TT__PI / S->rotations, pivot[2] = {0, 0}, weight = 0, lo, hi, a, b, fa, fb, best_delta = 0,
           best = sum0;
    int i, step, P = S->P;
    tt__hpm_place turned;
    if (S->rotations < 4 || S->nband == 0) return sum0;
    for (i = 0; i < S->nband; i++) {
        int at = S->band_pixels[i];
        double cx = at % P + 0.5 + mx, cy = at / P + 0.5 + my;
        pivot[0] += S->mask[at] * (S->f * (ct * cx + st * cy + ctx) + dx);
        pivot[1] += S->mask[at] * (S->f * (-st * cx + ct * cy + cty) + dy);
        weight += S->mask[at];
    }
    if (!(weight > 0)) return sum0;
    pivot[0] /= weight;
    pivot[1] /= weight;
    /* The band sum is taken with the placement's turn applied to the
       band's positions: turning the placement by delta about the pivot
       moves every position by the same turn. */
    lo = -half;
    hi = half;
    a = hi - golden * (hi - lo);
    b = lo + golden * (hi - lo);
    fa = tt__hpm_turned(S, C, pl, a, pivot, &turned) ? tt__hpm_turn_sum(S, a, pivot, mx, my, ct, st, ctx, cty, dx, dy)
                                                     : 1e300;
    fb = tt__hpm_turned(S, C, pl, b, pivot, &turned) ? tt__hpm_turn_sum(S, b, pivot, mx, my, ct, st, ctx, cty, dx, dy)
                                                     : 1e300;
    for (step = 0; step < TT__HPM_TURN_STEPS; step++) {
        if (fa < best) {
            best = fa;
            best_delta = a;
        }
        if (fb < best) {
            best = fb;
            best_delta = b;
        }
        if (fa <= fb) {
            hi = b;
            b = a;
            fb = fa;
            a = hi - golden * (hi - lo);
            fa = tt__hpm_turned(S, C, pl, a, pivot, &turned)
                     ? tt__hpm_turn_sum(S, a, pivot, mx, my, ct, st, ctx, cty, dx, dy)
                     : 1e300;
        } else {
            lo = a;
            a = b;
            fa = fb;
            b = lo + golden * (hi - lo);
            fb = tt__hpm_turned(S, C, pl, b, pivot, &turned)
                     ? tt__hpm_turn_sum(S, b, pivot, mx, my, ct, st, ctx, cty, dx, dy)
                     : 1e300;
        }
    }
    if (best_delta != 0 && tt__hpm_turned(S, C, pl, best_delta, pivot, &turned)) *pl = turned;
    else best = sum0;
    return best;
}

/* Step 3's allowed offsets, per turned copy (canvas cw x ch with C's
   support drawn): the support (footprint and band) stays on the grid
   without wrapping, and for a bounded image inside the turned image with
   a margin of one texel (D6). With a main neighbour whose continuation is
   at canvas offset cont (o: the canvas origin), the offsets within
   `exclusion` texels of it in copy 0 are left out (D8). Returns 0 when no
   offset is allowed. */
static int tt__hpm_allowed_offsets(tt__hpm *S, int cw, int ch, int has_cont, const double *cont, const double *o,
                                   double exclusion)
{
    double cb = 0.5 * S->P, ctx = 0.5 * S->ww, cty = 0.5 * S->wh;
    double m_w = 1.0 / S->f;
    size_t pp = (size_t)S->P * S->P;
    int i, j, k, P = S->P, maxx = 0, maxy = 0, any = 0;
    for (j = 0; j < ch; j++)
        for (i = 0; i < cw; i++)
            if (S->support[(size_t)j * P + i]) {
                if (i > maxx) maxx = i;
                if (j > maxy) maxy = j;
            }
    for (k = 0; k < S->copies; k++) {
        unsigned char *a = S->allowed_mem + (size_t)k * pp;
        double th = S->angle[k], ct = cos(th), st = sin(th);
        /* n' = R(theta) n for n = +x, -x, +y, -y; limits L - n.c_T */
        double nx[4], ny[4], lim[4], mx[4];
        int d, tx, ty;
        nx[0] = ct; ny[0] = st; lim[0] = S->ww - m_w - ctx;
        nx[1] = -ct; ny[1] = -st; lim[1] = -m_w + ctx;
        nx[2] = -st; ny[2] = ct; lim[2] = S->wh - m_w - cty;
        nx[3] = st; ny[3] = -ct; lim[3] = -m_w + cty;
        for (d = 0; d < 4; d++) mx[d] = -1e300;
        if (!S->toroidal)
            for (j = 0; j < ch; j++)
                for (i = 0; i < cw; i++)
                    if (S->support[(size_t)j * P + i])
                        for (d = 0; d < 4; d++) {
                            double v = nx[d] * (i - cb) + ny[d] * (j - cb) + (nx[d] > 0 ? nx[d] : 0) +
                                       (ny[d] > 0 ? ny[d] : 0);
                            if (v > mx[d]) mx[d] = v;
                        }
        memset(a, 0, pp);
        for (ty = 0; ty < P - maxy; ty++)
            for (tx = 0; tx < P - maxx; tx++) {
                int ok = 1;
                if (!S->toroidal)
                    for (d = 0; d < 4 && ok; d++) ok = nx[d] * tx + ny[d] * ty <= lim[d] - mx[d];
                a[(size_t)ty * P + tx] = (unsigned char)ok;
                any |= ok;
            }
    }
    /* D8: not the exact continuation of that neighbour (copy 0 at
       the offset that repeats its map), nor anything within the
       cluster's radius of it, which would show the same texels shifted
       a little; unless asked for (TT_HPM_NO_RANDOM_TURN). */
    if (has_cont && !(S->flags & TT_HPM_NO_RANDOM_TURN)) {
        double tcx = cont[0] / S->f + o[0] + cb - ctx, tcy = cont[1] / S->f + o[1] + cb - cty;
        double rad = exclusion, px = S->toroidal ? S->ww : 1e300, py = S->toroidal ? S->wh : 1e300;
        int tx, ty, a, b;
        if (S->toroidal) {
            /* copy 0 repeats with the image's period */
            tcx -= px * floor(tcx / px);
            tcy -= py * floor(tcy / py);
        }
        for (b = 0; b == 0 || (S->toroidal && tcy + (b - 1) * py - rad < P); b++)
            for (a = 0; a == 0 || (S->toroidal && tcx + (a - 1) * px - rad < P); a++) {
                double cx = tcx + (S->toroidal ? (a - 1) * px : 0), cy = tcy + (S->toroidal ? (b - 1) * py : 0);
                for (ty = (int)floor(cy - rad); ty <= (int)ceil(cy + rad); ty++)
                    for (tx = (int)floor(cx - rad); tx <= (int)ceil(cx + rad); tx++)
                        if (tx >= 0 && ty >= 0 && tx < P && ty < P &&
                            (tx - cx) * (tx - cx) + (ty - cy) * (ty - cy) <= rad * rad)
                            S->allowed_mem[(size_t)ty * P + tx] = 0;
            }
    }
    return any;
}

/* Steps 2 and 3: the band and the fit. Returns 1 with *pl and *eps when
   a fit was made, 0 when there is no band to fit (continue or start
   instead), -1 when there is no room for C in the image, -2 on
   TT_ERROR_OUT_OF_MEMORY-free failures reported in *res. */
static int tt__hpm_fit(tt__hpm *S, int C, int stamp, tt__hpm_place *pl, double *eps, tt_result *res,
                       tt_error *error)
{
    const tt_mesh *m = S->mesh;
    const tt_cluster *cl = &S->H->clusters[C];
    double s_w = S->s / S->f, area_px = cl->area * S->s * S->s, w_full, w_w, phi, cph, sph, box[4], o[2];
    double cont[2] = {0, 0};
    double cb = 0.5 * S->P, ctx = 0.5 * S->ww, cty = 0.5 * S->wh;
    size_t pp = (size_t)S->P * S->P;
    int cw, ch, i, j, k, P = S->P, best_k = -1, has_cont;
    tt__hpm_raster r;
    tt_xcorr_match match = {-1, -1, 0, 0, 0};
    tt_result xr;

    w_full = tt__hpm_band_width(S, C);
    w_w = w_full / S->f;
    if (w_w < 1.5) w_w = 1.5;
    /* The canvas is turned so that the texture of the neighbour sharing
       most vertices keeps its orientation in the turned copy 0: the
       orientation then propagates from patch to patch (Sec. 2.2) without
       the drift that a random turn of the frame would add at every fit. */
    {
        const tt__hpm_owner *best = tt__hpm_best_owner(S);
        cph = best ? best->cos_a : 1;
        sph = best ? -best->sin_a : 0;
        phi = atan2(sph, cph);
        if (best) {
            cont[0] = -S->s * (cph * best->shift[0] - sph * best->shift[1]);
            cont[1] = -S->s * (sph * best->shift[0] + cph * best->shift[1]);
        }
        has_cont = best != NULL;
    }
    /* The canvas: c = s_w R(phi) q - o. */
    tt__hpm_bbox(S, C, cph, sph, box);
    for (i = 0; i < 4; i++) box[i] /= S->f;
    o[0] = floor(box[0] - w_w - 3);
    o[1] = floor(box[1] - w_w - 3);
    if (has_cont) {
        /* Shift the canvas by a fraction of a texel so that the main
           neighbour's texel grid falls on the canvas grid: its continuation
           is then an integer offset (an exact match, D20), and every
           offset samples the copy where the neighbour's samples were. */
        o[0] -= (cont[0] / S->f + cb - ctx) - floor(cont[0] / S->f + cb - ctx);
        o[1] -= (cont[1] / S->f + cb - cty) - floor(cont[1] / S->f + cb - cty);
    }
    cw = (int)ceil(box[2] + w_w + 2 - o[0]);
    ch = (int)ceil(box[3] + w_w + 2 - o[1]);
    if (cw >= P || ch >= P) return -1;
    memset(S->support, 0, pp);
    memset(S->mask, 0, pp * sizeof(double));
    r.S = S;
    r.band = w_w;
    for (i = 0; i < cl->nfaces; i++) {
        int f = S->H->faces[cl->first_face + i];
        float xy[6];
        for (j = 0; j < 3; j++) {
            double q[2];
            tt__hpm_q(S, m->face_start[f] + j, q);
            xy[2 * j] = (float)(s_w * (cph * q[0] - sph * q[1]) - o[0]);
            xy[2 * j + 1] = (float)(s_w * (sph * q[0] + cph * q[1]) - o[1]);
        }
        tt_raster_triangle(xy, P, P, tt__hpm_raster_footprint, &r);
    }
    tt__hpm_distance(S, cw, ch);
    tt__hpm_near_faces(S, C, stamp, 2 * w_full / S->s);
    S->nband = 0;
    for (i = 0; i < S->nnear; i++) {
        int g = S->near_faces[i];
        const tt__hpm_owner *O = NULL;
        float xy[6];
        for (k = 0; k < S->nowners; k++)
            if (S->owners[k].cluster == S->owner[g]) O = &S->owners[k];
        for (j = 0; j < 3; j++) {
            int c = m->face_start[g] + j;
            double ax = S->uv[2 * c] / S->s, ay = S->uv[2 * c + 1] / S->s;
            double bx = O->cos_a * ax - O->sin_a * ay + O->shift[0], by = O->sin_a * ax + O->cos_a * ay + O->shift[1];
            r.x[2 * j] = S->uv[2 * c];
            r.x[2 * j + 1] = S->uv[2 * c + 1];
            xy[2 * j] = (float)(s_w * (cph * bx - sph * by) - o[0]);
            xy[2 * j + 1] = (float)(s_w * (sph * bx + cph * by) - o[1]);
        }
        tt_raster_triangle(xy, cw, ch, tt__hpm_raster_band, &r);
    }
    if (S->nband < 8) return 0;

    /* the exclusion disc: the cluster's radius, at least the band's width */
    if (!tt__hpm_allowed_offsets(S, cw, ch, has_cont, cont, o,
                                 sqrt(area_px / TT__PI) / S->f > w_w ? sqrt(area_px / TT__PI) / S->f : w_w))
        return -1;
    xr = tt_xcorr_masked_best((const tt_xcorr_texture *const *)S->tex, S->copies, S->mask, S->values,
                              S->allowed, S->xwork, &match, &best_k, error);
    if (xr == TT_ERROR_NOT_MEASURED) return -1;
    if (xr != TT_OK) {
        *res = xr;
        return -2;
    }

    /* The placement of the best offset, refined at full resolution by a
       direct sum over +-(f - 1) texels (D30). */
    {
        double th = S->angle[best_k], ct = cos(th), st = sin(th);
        double tx = match.x - o[0] - cb, ty = match.y - o[1] - cb, best = -1, vb[3], vc[3];
        double pbox[4];
        int dx, dy, bdx = 0, bdy = 0, reach = S->f - 1, c;
        pl->cos_a = cos(phi - th);
        pl->sin_a = sin(phi - th);
        pl->shift[0] = S->f * (ct * tx + st * ty + ctx);
        pl->shift[1] = S->f * (-st * tx + ct * ty + cty);
        tt__hpm_bbox(S, C, pl->cos_a, pl->sin_a, pbox);
        for (dy = -reach; dy <= reach; dy++)
            for (dx = -reach; dx <= reach; dx++) {
                double sum = 0;
                if (!S->toroidal && (pbox[0] + pl->shift[0] + dx < 1 || pbox[1] + pl->shift[1] + dy < 1 ||
                                     pbox[2] + pl->shift[0] + dx > S->W - 1 ||
                                     pbox[3] + pl->shift[1] + dy > S->Hh - 1))
                    continue;
                for (i = 0; i < S->nband; i++) {
                    int at = S->band_pixels[i];
                    double cx = at % P + 0.5 + match.x - cb, cy = at / P + 0.5 + match.y - cb;
                    double xcx = S->f * (ct * cx + st * cy + ctx) + dx, xcy = S->f * (-st * cx + ct * cy + cty) + dy;
                    tt__hpm_sample(S->full, S->W, S->Hh, S->nch, S->src[2 * at], S->src[2 * at + 1], S->toroidal,
                                   vb);
                    tt__hpm_sample(S->full, S->W, S->Hh, S->nch, xcx, xcy, S->toroidal, vc);
                    for (c = 0; c < S->nch; c++) sum += S->mask[at] * (vb[c] - vc[c]) * (vb[c] - vc[c]);
                }
                if (best < 0 || sum < best) {
                    best = sum;
                    bdx = dx;
                    bdy = dy;
                }
            }
        if (best < 0) return -1;
        pl->shift[0] += bdx;
        pl->shift[1] += bdy;
        best = tt__hpm_refine_turn(S, C, pl, best, match.x - cb, match.y - cb, ct, st, ctx, cty, bdx, bdy);
        *eps = best / ((double)S->nch * match.mask_sum) / (2 * S->sigma2);
    }
    S->rep.fits++;
    S->rep.fits_per_level[tt__min_i(cl->level, TT_HPM_MAX_LEVELS - 1)]++;
    return 1;
}

/* Step 5: C's corners get s R q + shift; for a toroidal image the whole
   cluster moves by periods so that its centre lies in the image. */
static void tt__hpm_write(tt__hpm *S, int C, const tt__hpm_place *pl, double *uv)
{
    const tt_cluster *cl = &S->H->clusters[C];
    double sum[2] = {0, 0}, px = 0, py = 0;
    int i, j, n = 0;
    for (i = 0; i < cl->nfaces; i++) {
        int f = S->H->faces[cl->first_face + i];
        for (j = S->mesh->face_start[f]; j < S->mesh->face_start[f + 1]; j++) {
            double q[2];
            tt__hpm_q(S, j, q);
            tt__hpm_apply(S, pl, q, uv + 2 * j);
            sum[0] += uv[2 * j];
            sum[1] += uv[2 * j + 1];
            n++;
        }
    }
    if (S->toroidal) {
        px = S->W * floor(sum[0] / n / S->W);
        py = S->Hh * floor(sum[1] / n / S->Hh);
        for (i = 0; i < cl->nfaces; i++) {
            int f = S->H->faces[cl->first_face + i];
            for (j = S->mesh->face_start[f]; j < S->mesh->face_start[f + 1]; j++) {
                uv[2 * j] -= px;
                uv[2 * j + 1] -= py;
            }
        }
    }
}

/* ---- The local relaxation along shared borders (Sec. 4.4, D25) ----

   After C is placed, at each vertex on its border with textured faces,
   C's texture coordinates there and then each textured neighbour's in
   turn are nudged by a few texels when that lowers the colour difference
   across the borders at the vertex: the difference is taken at 8 points of
   each such edge, half a texel on either side of it (where the eye and the
   seam measure look; tt__hpm_edge_mismatch), and moving the vertex moves
   the points of its edges by (1 - t) of the move - the hat weight of D25.
   Moving both sides, not only C's, halves what is left of the seams (0.30
   to 0.21 on cluster borders of a 20k torus); the neighbour's other
   borders at the vertex are in the sum, so they do not pay for it. Each
   side gets TT__HPM_RELAX_TRIALS random trials per pass, greedy, in
   TT__HPM_RELAX_PASSES passes of radius w/2, w/4, ... (w the band width):
   D25's radius w / 2^(depth + 1) is below a texel at the depths where most
   clusters map, so it would move nothing. A move is refused when a moved
   triangle would flip, shrink below a quarter of its area, or end up
   stretched (surface to texture) more than TT__HPM_RELAX_MAX_STRETCH and
   more than it was - the seams and the stretch measure pull against each
   other here, and 1.2 keeps the median stretch under 1.15 where most
   triangles are on a border - or when it would leave a bounded image's
   margin. The interior is not re-solved (D25's last step): the moves are a
   few texels and only the border triangles absorb them. Exact
   continuations are left alone. */
#define TT__HPM_RELAX_TRIALS 16
#define TT__HPM_RELAX_PASSES 4
#define TT__HPM_RELAX_SAMPLES 8
#define TT__HPM_RELAX_MAX_STRETCH 1.2
#define TT__HPM_RELAX_ACROSS 4.0

/* Colour mismatch along border half-edge h of C (twin in a textured face),
   summed over its sample points: the squared difference across the border,
   half a texel inside either face (D25's error, what the eye and the seam
   measure see), weighted TT__HPM_RELAX_ACROSS; plus what each side shows
   against the other side's map continued over the edge to the same place.
   The second part is 0 for an exact continuation, where the first is not
   (two places a texel apart differ), so a continuation stays one. */
static double tt__hpm_edge_mismatch(const tt__hpm *S, int h, double *continuation)
{
    const tt_mesh *m = S->mesh;
    int t = m->twin[h], side, i, c;
    int ends[2][3];     /* per side: corner at the edge's start, at its end, the apex */
    double across = 0, cont = 0, n[2][2];
    ends[0][0] = h;
    ends[0][1] = tt_mesh_next(m, h);
    ends[0][2] = tt_mesh_prev(m, h);
    ends[1][0] = tt_mesh_next(m, t); /* the twin runs the other way */
    ends[1][1] = t;
    ends[1][2] = tt_mesh_prev(m, t);
    for (side = 0; side < 2; side++) {
        const double *a = S->uv + 2 * ends[side][0], *b = S->uv + 2 * ends[side][1], *x = S->uv + 2 * ends[side][2];
        double ex = b[0] - a[0], ey = b[1] - a[1], len = sqrt(ex * ex + ey * ey);
        n[side][0] = n[side][1] = 0;
        if (len > 0) {
            n[side][0] = -ey / len;
            n[side][1] = ex / len;
            if (n[side][0] * (x[0] - a[0]) + n[side][1] * (x[1] - a[1]) < 0) {
                n[side][0] = -n[side][0];
                n[side][1] = -n[side][1];
            }
        }
    }
    for (i = 0; i < TT__HPM_RELAX_SAMPLES; i++) {
        double tt = (i + 0.5) / TT__HPM_RELAX_SAMPLES, in[2][3], out[2][3];
        for (side = 0; side < 2; side++) {
            const double *a = S->uv + 2 * ends[side][0], *b = S->uv + 2 * ends[side][1];
            double ex = a[0] + tt * (b[0] - a[0]), ey = a[1] + tt * (b[1] - a[1]);
            tt__hpm_sample(S->full, S->W, S->Hh, S->nch, ex + 0.5 * n[side][0], ey + 0.5 * n[side][1], S->toroidal,
                           in[side]);
            tt__hpm_sample(S->full, S->W, S->Hh, S->nch, ex - 0.5 * n[side][0], ey - 0.5 * n[side][1], S->toroidal,
                           out[side]);
        }
        for (c = 0; c < S->nch; c++) {
            across += (in[0][c] - in[1][c]) * (in[0][c] - in[1][c]);
            cont += (in[0][c] - out[1][c]) * (in[0][c] - out[1][c]) + (in[1][c] - out[0][c]) * (in[1][c] - out[0][c]);
        }
    }
    if (continuation) *continuation += cont;
    return TT__HPM_RELAX_ACROSS * across + cont;
}

/* 1 when texel positions a and b are the same point of the image (on a
   toroidal image, up to whole periods). */
static int tt__hpm_same_place(const tt__hpm *S, const double *a, const double *b)
{
    double dx = a[0] - b[0], dy = a[1] - b[1];
    if (S->toroidal) {
        dx -= S->W * floor(dx / S->W + 0.5);
        dy -= S->Hh * floor(dy / S->Hh + 0.5);
    }
    return fabs(dx) <= 1e-9 * (1 + fabs(a[0])) && fabs(dy) <= 1e-9 * (1 + fabs(a[1]));
}

/* 1 when half-edge c is a border: both faces textured and the map jumps
   across it. */
static int tt__hpm_is_border(const tt__hpm *S, int c)
{
    const tt_mesh *m = S->mesh;
    int t = m->twin[c];
    if (t < 0 || S->owner[m->corner_face[c]] < 0 || S->owner[m->corner_face[t]] < 0) return 0;
    return !tt__hpm_same_place(S, S->uv + 2 * c, S->uv + 2 * tt_mesh_next(m, t)) ||
           !tt__hpm_same_place(S, S->uv + 2 * tt_mesh_next(m, c), S->uv + 2 * t);
}

/* Twice the signed area of corner c's triangle in texels, and its stretch:
   the ratio of the singular values of its surface -> texture map (what
   the stretch measure reads). */
static double tt__hpm_tri_area(const tt__hpm *S, int c, double *stretch)
{
    const tt_mesh *m = S->mesh;
    int k0 = m->face_start[m->corner_face[c]], i;
    const float *p0 = m->pos + 3 * (size_t)m->corner_vert[k0], *p1 = m->pos + 3 * (size_t)m->corner_vert[k0 + 1],
                *p2 = m->pos + 3 * (size_t)m->corner_vert[k0 + 2];
    double e1[3], e2[3], cr[3], len, du[2][2], dq[2][2], det, a[2][2], big, small;
    tt__sub3f(p1, p0, e1);
    tt__sub3f(p2, p0, e2);
    tt__cross3(e1, e2, cr);
    len = tt__length3(e1);
    /* the triangle laid flat in its own plane: e1 along x */
    dq[0][0] = len;
    dq[0][1] = 0;
    dq[1][0] = len > 0 ? (e1[0] * e2[0] + e1[1] * e2[1] + e1[2] * e2[2]) / len : 0;
    dq[1][1] = len > 0 ? tt__length3(cr) / len : 0;
    for (i = 0; i < 2; i++) {
        du[i][0] = S->uv[2 * (k0 + i + 1)] - S->uv[2 * k0];
        du[i][1] = S->uv[2 * (k0 + i + 1) + 1] - S->uv[2 * k0 + 1];
    }
    det = dq[0][0] * dq[1][1] - dq[0][1] * dq[1][0];
    *stretch = tt__infinity();
    if (det != 0) {
        /* A = dU dQ^-1, columns: dU/dq_x, dU/dq_y */
        for (i = 0; i < 2; i++) {
            a[i][0] = (du[0][i] * dq[1][1] - du[1][i] * dq[0][1]) / det;
            a[i][1] = (du[1][i] * dq[0][0] - du[0][i] * dq[1][0]) / det;
        }
        tt__metric_eigenvalues(a[0][0] * a[0][0] + a[1][0] * a[1][0], a[0][0] * a[0][1] + a[1][0] * a[1][1],
                               a[0][1] * a[0][1] + a[1][1] * a[1][1], &big, &small);
        *stretch = tt__stretch_ratio(big, small);
    }
    return du[0][0] * du[1][1] - du[0][1] * du[1][0];
}

/* Every corner at vertex v (at most `room`), walking round it through the
   twins; returns the count. */
static int tt__hpm_ring(const tt_mesh *m, int v, int *corners, int room)
{
    int start = m->vert_corner[v], c = start, n = 0;
    if (start < 0) return 0;
    /* one way round, until the start again or a boundary */
    do {
        int t;
        corners[n++] = c;
        t = m->twin[tt_mesh_prev(m, c)];
        if (t < 0) break;
        c = t;
    } while (c != start && n < room);
    if (c != start || n == 1) {
        /* a boundary: the other way from the start */
        c = start;
        while (n < room) {
            int t = m->twin[c];
            if (t < 0) break;
            c = tt_mesh_next(m, t);
            if (c == start) break;
            corners[n++] = c;
        }
    }
    return n;
}

#define TT__HPM_RING_MAX 64

/* The mismatch of the border edges at v (ring corners[0..n-1]) that touch
   cluster K's faces; its continuation part in *continuation. */
static double tt__hpm_vertex_mismatch(const tt__hpm *S, const int *corners, int n, int K, double *continuation)
{
    const tt_mesh *m = S->mesh;
    double sum = 0;
    int i;
    for (i = 0; i < n; i++) {
        int c = corners[i], t = m->twin[c], a, b;
        if (t < 0) continue;
        a = S->owner[m->corner_face[c]];
        b = S->owner[m->corner_face[t]];
        if (a < 0 || b < 0 || a == b || (a != K && b != K)) continue;
        sum += tt__hpm_edge_mismatch(S, c, continuation);
    }
    return sum;
}

/* Relax the border between C (its faces already owned by C) and the
   textured faces round it: at each vertex of that border, C's map and
   then each neighbour's map there is nudged in turn. Returns 0 when out
   of memory. */
static int tt__hpm_relax(tt__hpm *S, int C)
{
    const tt_mesh *m = S->mesh;
    const tt_cluster *cl = &S->H->clusters[C];
    int *verts, nverts = 0, i, j, pass;
    double w = tt__hpm_band_width(S, C);
    verts = TT__ALLOC(S->al, int, 6 * (size_t)cl->nfaces);
    if (!verts) return 0;
    /* both ends of every edge C shares with a textured neighbour */
    for (i = 0; i < cl->nfaces; i++) {
        int f = S->H->faces[cl->first_face + i], c;
        for (c = m->face_start[f]; c < m->face_start[f + 1]; c++) {
            int t = m->twin[c];
            if (t >= 0 && S->owner[m->corner_face[t]] >= 0 && S->owner[m->corner_face[t]] != C) {
                verts[nverts++] = m->corner_vert[c];
                verts[nverts++] = m->corner_vert[tt_mesh_next(m, c)];
            }
        }
    }
    qsort(verts, (size_t)nverts, sizeof(int), tt__int_compare);
    for (i = j = 0; i < nverts; i++)
        if (j == 0 || verts[i] != verts[j - 1]) verts[j++] = verts[i];
    nverts = j;
    for (pass = 0; pass < TT__HPM_RELAX_PASSES && nverts > 0; pass++) {
        double radius = w / (2 << pass);
        if (radius < 0.25) break;
        for (i = 0; i < nverts; i++) {
            int ring[TT__HPM_RING_MAX], group[TT__HPM_RING_MAX], n, ngroups = 0, g, k;
            n = tt__hpm_ring(m, verts[i], ring, TT__HPM_RING_MAX);
            /* the clusters meeting at v, C first */
            group[ngroups++] = C;
            for (k = 0; k < n; k++) {
                int K = S->owner[m->corner_face[ring[k]]], seen = 0;
                for (g = 0; g < ngroups; g++) seen |= group[g] == K;
                if (K >= 0 && !seen) group[ngroups++] = K;
            }
            for (g = 0; g < ngroups; g++) {
                int K = group[g], trial, first = -1;
                double continued = 0, before = tt__hpm_vertex_mismatch(S, ring, n, K, &continued), old[2];
                /* no border here, or the exact continuation of the neighbour */
                if (continued <= 1e-12) continue;
                for (k = 0; k < n && first < 0; k++)
                    if (S->owner[m->corner_face[ring[k]]] == K) first = ring[k];
                old[0] = S->uv[2 * first];
                old[1] = S->uv[2 * first + 1];
                for (trial = 0; trial < TT__HPM_RELAX_TRIALS; trial++) {
                    double ang = TT__TWO_PI * tt_rng_float(&S->rng), r = radius * sqrt(tt_rng_float(&S->rng));
                    double nx = old[0] + r * cos(ang), ny = old[1] + r * sin(ang), after, area0, area1, st0, st;
                    int ok = 1;
                    if (!S->toroidal && (nx < 1 || ny < 1 || nx > S->W - 1 || ny > S->Hh - 1)) continue;
                    for (k = 0; k < n && ok; k++) {
                        int c = ring[k];
                        if (S->owner[m->corner_face[c]] != K) continue;
                        area0 = tt__hpm_tri_area(S, c, &st0);
                        S->uv[2 * c] = nx;
                        S->uv[2 * c + 1] = ny;
                        area1 = tt__hpm_tri_area(S, c, &st);
                        S->uv[2 * c] = old[0];
                        S->uv[2 * c + 1] = old[1];
                        ok = area0 * area1 > 0 && fabs(area1) >= 0.25 * fabs(area0) &&
                             st <= (st0 > TT__HPM_RELAX_MAX_STRETCH ? st0 : TT__HPM_RELAX_MAX_STRETCH);
                    }
                    if (!ok) continue;
                    for (k = 0; k < n; k++)
                        if (S->owner[m->corner_face[ring[k]]] == K) {
                            S->uv[2 * ring[k]] = nx;
                            S->uv[2 * ring[k] + 1] = ny;
                        }
                    after = tt__hpm_vertex_mismatch(S, ring, n, K, NULL);
                    if (after < before) {
                        before = after;
                        old[0] = nx;
                        old[1] = ny;
                    } else {
                        for (k = 0; k < n; k++)
                            if (S->owner[m->corner_face[ring[k]]] == K) {
                                S->uv[2 * ring[k]] = old[0];
                                S->uv[2 * ring[k] + 1] = old[1];
                            }
                    }
                }
            }
        }
    }
    tt__free(S->al, verts);
    return 1;
}

/* D17: the band that C's place was fitted to shows each textured
   neighbour N through its rigid map S_N (D16), and C's own flattening
   puts a shared border vertex a little away from where S_N puts it (the
   two flattenings differ): the image would then be cut at C's border
   texels away from where the matched band ends, a crack. So each shared
   vertex takes S_N's position, placed like the rest of C - for a cluster
   continuing N, exactly N's texture coordinates, a continuous border -
   unless that would flip, collapse or overstretch one of C's triangles
   there. N is the neighbour sharing most vertices with C among those at
   the vertex. */
static void tt__hpm_close_cracks(tt__hpm *S, int C, const tt__hpm_place *pl)
{
    const tt_mesh *m = S->mesh;
    const tt_cluster *cl = &S->H->clusters[C];
    int i, c;
    for (i = 0; i < cl->nfaces; i++) {
        int f = S->H->faces[cl->first_face + i];
        for (c = m->face_start[f]; c < m->face_start[f + 1]; c++) {
            int ring[TT__HPM_RING_MAX], n, k, o, from = -1, ok = 1;
            const tt__hpm_owner *N = NULL;
            double target[2], old[2], q[2], area0[TT__HPM_RING_MAX], st0[TT__HPM_RING_MAX], st;
            n = tt__hpm_ring(m, m->corner_vert[c], ring, TT__HPM_RING_MAX);
            for (k = 0; k < n; k++) {
                int K = S->owner[m->corner_face[ring[k]]];
                if (K < 0 || K == C) continue;
                for (o = 0; o < S->nowners; o++)
                    if (S->owners[o].cluster == K && S->owners[o].valid &&
                        (!N || S->owners[o].shared > N->shared)) {
                        N = &S->owners[o];
                        from = ring[k];
                    }
            }
            if (!N) continue;
            {
                double ax = S->uv[2 * from] / S->s, ay = S->uv[2 * from + 1] / S->s;
                q[0] = N->cos_a * ax - N->sin_a * ay + N->shift[0];
                q[1] = N->sin_a * ax + N->cos_a * ay + N->shift[1];
            }
            tt__hpm_apply(S, pl, q, target);
            old[0] = S->uv[2 * c];
            old[1] = S->uv[2 * c + 1];
            if (S->toroidal) {
                /* C was moved by whole periods when written */
                target[0] += S->W * floor((old[0] - target[0]) / S->W + 0.5);
                target[1] += S->Hh * floor((old[1] - target[1]) / S->Hh + 0.5);
            }
            if (target[0] == old[0] && target[1] == old[1]) continue;
            if (!S->toroidal && (target[0] < 1 || target[1] < 1 || target[0] > S->W - 1 || target[1] > S->Hh - 1))
                continue;
            for (k = 0; k < n; k++) area0[k] = tt__hpm_tri_area(S, ring[k], &st0[k]);
            for (k = 0; k < n; k++)
                if (S->owner[m->corner_face[ring[k]]] == C) {
                    S->uv[2 * ring[k]] = target[0];
                    S->uv[2 * ring[k] + 1] = target[1];
                }
            for (k = 0; k < n && ok; k++)
                if (S->owner[m->corner_face[ring[k]]] == C) {
                    double a = tt__hpm_tri_area(S, ring[k], &st);
                    ok = a * area0[k] > 0 && fabs(a) >= 0.25 * fabs(area0[k]) &&
                         st <= (st0[k] > TT__HPM_RELAX_MAX_STRETCH ? st0[k] : TT__HPM_RELAX_MAX_STRETCH);
                }
            if (!ok)
                for (k = 0; k < n; k++)
                    if (S->owner[m->corner_face[ring[k]]] == C) {
                        S->uv[2 * ring[k]] = old[0];
                        S->uv[2 * ring[k] + 1] = old[1];
                    }
        }
    }
}

/* D25's last step, the interior re-solve: the crack closing and the
   relaxation moved C's border vertices; carried by the border triangles
   alone, those moves would stretch them. So the displacement from C's
   rigid placement is spread into C's interior, each interior vertex
   taking the mean displacement of its neighbours (TT__HPM_SMOOTH_SWEEPS
   Jacobi sweeps of the Laplace equation, the border fixed): a few rings
   absorb the move instead of one. Undone if it would flip or collapse a
   triangle. */
#define TT__HPM_SMOOTH_SWEEPS 24

static void tt__hpm_smooth(tt__hpm *S, int C)
{
    const tt_mesh *m = S->mesh;
    const tt_cluster *cl = &S->H->clusters[C];
    double *d = S->vdisp; /* per vertex: displacement x, y; sums x, y; corners summed */
    int i, c, k, sweep, inside = ++S->stamp, moved = 0, undo = 0;
    for (i = 0; i < cl->nfaces; i++) {
        int f = S->H->faces[cl->first_face + i];
        for (c = m->face_start[f]; c < m->face_start[f + 1]; c++) S->vmark[m->corner_vert[c]] = inside;
    }
    for (i = 0; i < cl->nfaces; i++) {
        int f = S->H->faces[cl->first_face + i];
        for (c = m->face_start[f]; c < m->face_start[f + 1]; c++) {
            size_t v = (size_t)m->corner_vert[c];
            int e[2];
            e[0] = c;
            e[1] = tt_mesh_prev(m, c);
            /* an edge C does not have on both sides fixes both its ends */
            for (k = 0; k < 2; k++) {
                int t = m->twin[e[k]];
                if (t < 0 || S->owner[m->corner_face[t]] != C) {
                    S->vmark[m->corner_vert[e[k]]] = -1;
                    S->vmark[m->corner_vert[tt_mesh_next(m, e[k])]] = -1;
                }
            }
            d[5 * v] = S->uv[2 * c] - S->placed[2 * c];
            d[5 * v + 1] = S->uv[2 * c + 1] - S->placed[2 * c + 1];
            moved |= d[5 * v] != 0 || d[5 * v + 1] != 0;
        }
    }
    if (!moved) return;
    for (sweep = 0; sweep < TT__HPM_SMOOTH_SWEEPS; sweep++)
        for (k = 0; k < 3; k++)
            for (i = 0; i < cl->nfaces; i++) {
                int f = S->H->faces[cl->first_face + i];
                for (c = m->face_start[f]; c < m->face_start[f + 1]; c++) {
                    size_t v = (size_t)m->corner_vert[c], a = (size_t)m->corner_vert[tt_mesh_next(m, c)],
                           b = (size_t)m->corner_vert[tt_mesh_prev(m, c)];
                    if (S->vmark[v] != inside) continue;
                    if (k == 0) { /* clear the sums */
                        d[5 * v + 2] = d[5 * v + 3] = d[5 * v + 4] = 0;
                    } else if (k == 1) { /* add up the neighbours */
                        d[5 * v + 2] += d[5 * a] + d[5 * b];
                        d[5 * v + 3] += d[5 * a + 1] + d[5 * b + 1];
                        d[5 * v + 4] += 2;
                    } else { /* their mean */
                        d[5 * v] = d[5 * v + 2] / d[5 * v + 4];
                        d[5 * v + 1] = d[5 * v + 3] / d[5 * v + 4];
                    }
                }
            }
    for (i = 0; i < cl->nfaces; i++) {
        int f = S->H->faces[cl->first_face + i], first = m->face_start[f];
        const double *p0 = S->placed + 2 * first, *p1 = p0 + 2, *p2 = p0 + 4;
        double before = (p1[0] - p0[0]) * (p2[1] - p0[1]) - (p1[1] - p0[1]) * (p2[0] - p0[0]), after, st;
        for (c = first; c < m->face_start[f + 1]; c++) {
            size_t v = (size_t)m->corner_vert[c];
            if (S->vmark[v] != inside) continue;
            S->uv[2 * c] = S->placed[2 * c] + d[5 * v];
            S->uv[2 * c + 1] = S->placed[2 * c + 1] + d[5 * v + 1];
        }
        after = tt__hpm_tri_area(S, first, &st);
        undo |= !(after * before > 0 && fabs(after) >= 0.25 * fabs(before));
    }
    if (undo)
        for (i = 0; i < cl->nfaces; i++) {
            int f = S->H->faces[cl->first_face + i];
            for (c = m->face_start[f]; c < m->face_start[f + 1]; c++)
                if (S->vmark[m->corner_vert[c]] == inside) {
                    S->uv[2 * c] = S->placed[2 * c];
                    S->uv[2 * c + 1] = S->placed[2 * c + 1];
                }
        }
}

/* C is textured by placement pl: write its corners, record it, queue its
   same-level neighbours. */
static int tt__hpm_accept(tt__hpm *S, int C, const tt__hpm_place *pl)
{
    const tt_cluster *cl = &S->H->clusters[C];
    int i;
    tt__hpm_write(S, C, pl, S->uv);
    for (i = 0; i < cl->nfaces; i++) {
        int f = S->H->faces[cl->first_face + i], c;
        S->owner[f] = C;
        for (c = 2 * S->mesh->face_start[f]; c < 2 * S->mesh->face_start[f + 1]; c++) S->placed[c] = S->uv[c];
    }
    if (!(S->flags & TT_HPM_NO_RELAXATION)) {
        tt__hpm_close_cracks(S, C, pl);
        if (!tt__hpm_relax(S, C)) return 0;
        tt__hpm_smooth(S, C);
    }
    if (S->out) {
        tt__hpm_place rp;
        if (!tt__hpm_random_place(S, &S->place_rng, C, &rp)) rp = *pl;
        tt__hpm_write(S, C, &rp, S->out);
    }
    S->textured += cl->nfaces;
    S->rep.clusters++;
    S->rep.mapped_per_level[tt__min_i(cl->level, TT_HPM_MAX_LEVELS - 1)]++;
    for (i = 0; i < cl->nneighbours; i++) {
        int nb = S->H->neighbours[cl->first_neighbour + i];
        if (S->state[nb] != 1 && tt__hpm_textured_state(S, nb) == 0 && !tt__hpm_push(S, cl->level, nb)) return 0;
    }
    return 1;
}

/* One cluster taken from the queues (Sec. 2.2 step 2). Returns 1, or 0 on
   an error in *res. */
static int tt__hpm_process(tt__hpm *S, int C, int has_neighbours, tt_result *res, tt_error *error)
{
    const tt_cluster *cl = &S->H->clusters[C];
    double area_px = cl->area * S->s * S->s, eps = 0;
    int below_floor, at_floor, stamp, fit;
    tt__hpm_place pl;
    tt_result fr;
    tt_flatten_report frep;
    S->state[C] = 1;
    if (!(cl->flags & TT_CLUSTER_MAPPABLE)) return tt__hpm_split(S, C) ? 1 : (*res = TT_ERROR_OUT_OF_MEMORY, 0);
    fr = tt_flatten_cluster(S->mesh, S->H, C, &S->fopt, S->al, S->flat, &frep, NULL);
    if (fr == TT_ERROR_OUT_OF_MEMORY) {
        *res = tt__fail(error, fr, -1, -1, -1, -1, "out of memory flattening cluster %d", C);
        return 0;
    }
    if (fr != TT_OK) {
        /* Not flat (or a degenerate single face): split; a face that
           cannot be flattened shows its neighbours' texture at the end. */
        S->rep.not_flat++;
        if (cl->nchildren == 0) return 1;
        return tt__hpm_split(S, C) ? 1 : (*res = TT_ERROR_OUT_OF_MEMORY, 0);
    }
    below_floor = area_px < S->floor_px || cl->nfaces < S->min_faces;
    at_floor = cl->nchildren == 0 || area_px / cl->nchildren < S->floor_px ||
               cl->nfaces / cl->nchildren < S->min_faces;
    stamp = tt__hpm_mark(S, C);
    if (!tt__hpm_owners(S, C, stamp)) {
        *res = tt__fail(error, TT_ERROR_OUT_OF_MEMORY, -1, -1, -1, -1, "out of memory placing cluster %d", C);
        return 0;
    }
    fit = 0;
    if (has_neighbours && below_floor && tt__hpm_continue_place(S, C, &pl)) {
        S->rep.continued++;
        return tt__hpm_accept(S, C, &pl) ? 1 : (*res = TT_ERROR_OUT_OF_MEMORY, 0);
    }
    if (has_neighbours) {
        fit = tt__hpm_fit(S, C, stamp, &pl, &eps, res, error);
        if (fit == -2) return 0;
    }
    if (fit == 1) {
        if (eps <= S->threshold || at_floor) {
            if (eps <= S->threshold) {
                S->rep.accepted_fits++;
                S->rep.accepted_per_level[tt__min_i(cl->level, TT_HPM_MAX_LEVELS - 1)]++;
            } else {
                S->rep.floor_fits++;
            }
            S->error_sum += eps;
            if (eps > S->rep.max_error) S->rep.max_error = eps;
            return tt__hpm_accept(S, C, &pl) ? 1 : (*res = TT_ERROR_OUT_OF_MEMORY, 0);
        }
        S->rep.rejected_fits++;
        return tt__hpm_split(S, C) ? 1 : (*res = TT_ERROR_OUT_OF_MEMORY, 0);
    }
    if (fit == -1 && !at_floor) {
        S->rep.no_room++;
        return tt__hpm_split(S, C) ? 1 : (*res = TT_ERROR_OUT_OF_MEMORY, 0);
    }
    if (tt__hpm_continue_place(S, C, &pl)) {
        S->rep.continued++;
        return tt__hpm_accept(S, C, &pl) ? 1 : (*res = TT_ERROR_OUT_OF_MEMORY, 0);
    }
    if (tt__hpm_random_place(S, &S->rng, C, &pl)) {
        S->rep.starts++;
        return tt__hpm_accept(S, C, &pl) ? 1 : (*res = TT_ERROR_OUT_OF_MEMORY, 0);
    }
    S->rep.no_room++;
    if (cl->nchildren == 0) return 1;
    return tt__hpm_split(S, C) ? 1 : (*res = TT_ERROR_OUT_OF_MEMORY, 0);
}

/* The traversal (Sec. 2.2, D22). */
static tt_result tt__hpm_traverse(tt__hpm *S, tt_error *error)
{
    tt_result res = TT_OK;
    int level, next_start = 0;
    for (;;) {
        int C, count, l, others = 0;
        tt__heap_item it;
        for (level = 0; level < S->H->nlevels && S->qcount[level] == 0; level++) {}
        if (level == S->H->nlevels) {
            /* The queues are empty: a waiting cluster that now has a
               textured neighbour, else the first waiting one as a new
               start, else the first cluster never reached (D22). */
            int i, pick = -1, kept = 0;
            for (i = 0; i < S->nwaiting; i++) {
                int w = S->waiting[i];
                if (S->state[w] == 1) continue;
                S->waiting[kept++] = w;
                tt__hpm_key(S, w, &count);
                if (count > 0 || tt__hpm_textured_state(S, w) != 0) {
                    S->state[w] = 0;
                    if (!tt__hpm_push(S, S->H->clusters[w].level, w)) goto oom;
                    kept--;
                }
            }
            S->nwaiting = kept;
            for (level = 0; level < S->H->nlevels && S->qcount[level] == 0; level++) {}
            if (level < S->H->nlevels) continue;
            if (S->nwaiting > 0) {
                pick = S->waiting[0];
                for (i = 1; i < S->nwaiting; i++) S->waiting[i - 1] = S->waiting[i];
                S->nwaiting--;
                if (!tt__hpm_process(S, pick, 0, &res, error)) return res;
                continue;
            }
            while (next_start < S->H->nclusters && S->state[next_start] == 1) next_start++;
            if (next_start == S->H->nclusters) break;
            if (!tt__hpm_push(S, S->H->clusters[next_start].level, next_start)) goto oom;
            next_start++;
            continue;
        }
        it = tt__heap_pop(S->queue[level], &S->qcount[level]);
        C = it.value;
        if (S->state[C] == 1) continue;
        switch (tt__hpm_textured_state(S, C)) {
        case 2:
            S->state[C] = 1;
            continue;
        case 1:
            S->state[C] = 1;
            if (!tt__hpm_split(S, C)) goto oom;
            continue;
        default:
            break;
        }
        tt__hpm_key(S, C, &count);
        for (l = 0; l < S->H->nlevels; l++) others += S->qcount[l];
        if (count == 0 && others > 0) {
            /* No textured neighbour yet: wait, rather than start a region
               that nothing will continue. */
            if (S->state[C] != 2) {
                if (S->nwaiting == S->waitcap) {
                    int *nw = (int *)tt__grow(S->al, S->waiting, &S->waitcap, S->nwaiting + 1, sizeof(int));
                    if (!nw) goto oom;
                    S->waiting = nw;
                }
                S->waiting[S->nwaiting++] = C;
                S->state[C] = 2;
            }
            continue;
        }
        if (!tt__hpm_process(S, C, count > 0, &res, error)) return res;
        if (S->progress && S->progress((float)S->textured / S->mesh->nfaces, S->progress_user_data))
            return tt__fail(error, TT_CANCELLED, -1, -1, -1, -1, "hierarchical pattern mapping cancelled");
    }
    return TT_OK;
oom:
    return tt__fail(error, TT_ERROR_OUT_OF_MEMORY, -1, -1, -1, -1, "out of memory in the traversal");
}

/* Faces that could not be flattened (degenerate single faces): each
   corner takes the texture coordinate a textured face around its vertex
   gives it. */
/* The border choice, after the traversal: the fits and the relaxation
   choose where each cluster's map is placed, but the borders themselves
   stay where the hierarchy cut the mesh, and on a coarse mesh a border
   edge runs tens of texels straight through the pattern. So, as image
   quilting chooses its cut and not only its placement (spec section 4,
   "choose the band edges"), a face on a border may change sides: it shows
   the map of the neighbouring cluster across one of its edges instead -
   the neighbour's coordinates at the two shared vertices, the third
   unfolded isometrically from the surface (or the neighbour's own there,
   when it has one) - when that lowers the colour mismatch over the face's
   three edges (the edge it crosses becomes continuous, the others may
   become borders), without flipping, overstretching or leaving a bounded
   image. TT__HPM_BORDER_SWEEPS passes over the faces, in index order. The
   random-placement control gets the same partition, each moved face
   unfolded into its new cluster's random map, so both show the same
   clusters. */
#define TT__HPM_BORDER_SWEEPS 3

/* Face f's three corner positions if it showed the map of the face across
   its half-edge c (in array uv); 0 when that face is not usable. */
static int tt__hpm_face_as_neighbour(const tt__hpm *S, const double *uv, int c, double out[3][2])
{
    const tt_mesh *m = S->mesh;
    int t = m->twin[c], nc = tt_mesh_next(m, c), pc = tt_mesh_prev(m, c), K, ring[TT__HPM_RING_MAX], n, k;
    const double *a, *b, *g;
    double e[2], len, ex[3], ey[3], x, y, l3, cr[3], side;
    if (t < 0 || (K = S->owner[m->corner_face[t]]) < 0) return 0;
    a = uv + 2 * tt_mesh_next(m, t); /* at corner_vert[c] */
    b = uv + 2 * t;                  /* at corner_vert[nc] */
    g = uv + 2 * tt_mesh_prev(m, t);
    out[0][0] = a[0];
    out[0][1] = a[1];
    out[1][0] = b[0];
    out[1][1] = b[1];
    /* the neighbour's own coordinates at the third vertex, when it has some */
    n = tt__hpm_ring(m, m->corner_vert[pc], ring, TT__HPM_RING_MAX);
    for (k = 0; k < n; k++)
        if (m->corner_face[ring[k]] != m->corner_face[c] && S->owner[m->corner_face[ring[k]]] == K) {
            out[2][0] = uv[2 * ring[k]];
            out[2][1] = uv[2 * ring[k] + 1];
            return 1;
        }
    /* else unfolded across the edge, on the side away from the neighbour's
       third corner, at the scale of the neighbour's edge */
    e[0] = b[0] - a[0];
    e[1] = b[1] - a[1];
    len = sqrt(e[0] * e[0] + e[1] * e[1]);
    tt__sub3f(m->pos + 3 * (size_t)m->corner_vert[nc], m->pos + 3 * (size_t)m->corner_vert[c], ex);
    tt__sub3f(m->pos + 3 * (size_t)m->corner_vert[pc], m->pos + 3 * (size_t)m->corner_vert[c], ey);
    l3 = tt__length3(ex);
    if (!(len > 0) || !(l3 > 0)) return 0;
    x = tt__dot3(ex, ey) / l3;
    tt__cross3(ex, ey, cr);
    y = tt__length3(cr) / l3;
    side = e[0] * (g[1] - a[1]) - e[1] * (g[0] - a[0]) > 0 ? -1 : 1;
    x *= len / l3;
    y *= side * len / l3;
    out[2][0] = a[0] + (x * e[0] - y * e[1]) / len;
    out[2][1] = a[1] + (x * e[1] + y * e[0]) / len;
    return 1;
}

/* Mismatch over face f's edges to textured faces (0 where continuous). */
static double tt__hpm_face_mismatch(const tt__hpm *S, int f)
{
    const tt_mesh *m = S->mesh;
    double sum = 0;
    int c;
    for (c = m->face_start[f]; c < m->face_start[f + 1]; c++)
        if (tt__hpm_is_border(S, c)) sum += tt__hpm_edge_mismatch(S, c, NULL);
    return sum;
}

static void tt__hpm_choose_borders(tt__hpm *S)
{
    const tt_mesh *m = S->mesh;
    int sweep, f, c, k;
    for (sweep = 0; sweep < TT__HPM_BORDER_SWEEPS; sweep++) {
        int changed = 0;
        for (f = 0; f < m->nfaces; f++) {
            int first = m->face_start[f], best = -1, C = S->owner[f];
            double old[3][2], cand[3][2], keep[3][2], before, best_cost, st_old, st, unused;
            if (C < 0) continue;
            for (k = 0; k < 3; k++) {
                old[k][0] = S->uv[2 * (first + k)];
                old[k][1] = S->uv[2 * (first + k) + 1];
            }
            before = tt__hpm_face_mismatch(S, f);
            if (before <= 0) continue;
            best_cost = before * 0.95; /* a clear gain, not noise */
            (void)tt__hpm_tri_area(S, first, &st_old);
            for (c = first; c < first + 3; c++) {
                int t = m->twin[c], K, ok = 1, j;
                double area_n, area_f;
                if (t < 0 || (K = S->owner[m->corner_face[t]]) < 0 || K == C) continue;
                if (!tt__hpm_face_as_neighbour(S, S->uv, c, cand)) continue;
                /* cand is in the order c, next(c), prev(c) */
                for (j = 0; j < 3; j++) {
                    int at = first + (c - first + j) % 3;
                    S->uv[2 * at] = cand[j][0];
                    S->uv[2 * at + 1] = cand[j][1];
                    if (!S->toroidal && (cand[j][0] < 1 || cand[j][1] < 1 || cand[j][0] > S->W - 1 ||
                                         cand[j][1] > S->Hh - 1))
                        ok = 0;
                }
                area_f = tt__hpm_tri_area(S, first, &st);
                area_n = tt__hpm_tri_area(S, t, &unused);
                ok = ok && area_f * area_n > 0 && (st <= TT__HPM_RELAX_MAX_STRETCH || st <= st_old);
                if (ok) {
                    double cost = tt__hpm_face_mismatch(S, f);
                    if (cost < best_cost) {
                        best_cost = cost;
                        best = c;
                        for (j = 0; j < 3; j++) {
                            keep[j][0] = S->uv[2 * (first + j)];
                            keep[j][1] = S->uv[2 * (first + j) + 1];
                        }
                    }
                }
                for (k = 0; k < 3; k++) {
                    S->uv[2 * (first + k)] = old[k][0];
                    S->uv[2 * (first + k) + 1] = old[k][1];
                }
            }
            if (best < 0) continue;
            for (k = 0; k < 3; k++) {
                S->uv[2 * (first + k)] = keep[k][0];
                S->uv[2 * (first + k) + 1] = keep[k][1];
            }
            if (S->out && tt__hpm_face_as_neighbour(S, S->out, best, cand)) {
                /* the control follows where it can; where the random map
                   would leave the image or fold, the face keeps its own */
                const double *g0 = S->out + 2 * m->face_start[m->corner_face[m->twin[best]]];
                double area_g = (g0[2] - g0[0]) * (g0[5] - g0[1]) - (g0[3] - g0[1]) * (g0[4] - g0[0]);
                double area_c = (cand[1][0] - cand[0][0]) * (cand[2][1] - cand[0][1]) -
                                (cand[1][1] - cand[0][1]) * (cand[2][0] - cand[0][0]);
                int fits = area_g * area_c > 0;
                for (k = 0; k < 3; k++)
                    if (!S->toroidal && (cand[k][0] < 1 || cand[k][1] < 1 || cand[k][0] > S->W - 1 ||
                                         cand[k][1] > S->Hh - 1))
                        fits = 0;
                for (k = 0; k < 3 && fits; k++) {
                    int at = first + (best - first + k) % 3;
                    S->out[2 * at] = cand[k][0];
                    S->out[2 * at + 1] = cand[k][1];
                }
            }
            S->owner[f] = S->owner[m->corner_face[m->twin[best]]];
            S->rep.faces_moved++;
            changed = 1;
        }
        if (!changed) break;
    }
}

static void tt__hpm_leftovers(tt__hpm *S, double *uv)
{
    const tt_mesh *m = S->mesh;
    int f, j;
    for (f = 0; f < m->nfaces; f++) {
        if (S->owner[f] >= 0) continue;
        for (j = m->face_start[f]; j < m->face_start[f + 1]; j++) {
            int v = m->corner_vert[j], h = m->vert_corner[v], start = h, guard = 0, found = 0;
            while (h >= 0 && guard++ <= m->ncorners) {
                if (S->owner[m->corner_face[h]] >= 0) {
                    uv[2 * j] = uv[2 * h];
                    uv[2 * j + 1] = uv[2 * h + 1];
                    found = 1;
                    break;
                }
                h = m->twin[tt_mesh_prev(m, h)];
                if (h == start) break;
            }
            if (!found) {
                uv[2 * j] = 0.5 * S->W;
                uv[2 * j + 1] = 0.5 * S->Hh;
            }
        }
    }
}

static void tt__hpm_release(tt__hpm *S)
{
    int k;
    if (S->tex)
        for (k = 0; k < S->copies; k++) tt_xcorr_texture_free(S->tex[k]);
    if (S->queue)
        for (k = 0; k < S->H->nlevels; k++) tt__free(S->al, S->queue[k]);
    tt__free(S->al, S->tex);
    tt__free(S->al, S->queue);
    tt__free(S->al, S->qcount);
    tt__free(S->al, S->qcap);
    tt__free(S->al, S->full);
    tt__free(S->al, S->match);
    tt__free(S->al, S->xwork);
    tt__free(S->al, S->mask);
    tt__free(S->al, S->values);
    tt__free(S->al, S->support);
    tt__free(S->al, S->allowed_mem);
    tt__free(S->al, (void *)S->allowed);
    tt__free(S->al, S->dist);
    tt__free(S->al, S->src);
    tt__free(S->al, S->band_pixels);
    tt__free(S->al, S->flat);
    tt__free(S->al, S->uv);
    tt__free(S->al, S->out);
    tt__free(S->al, S->owner);
    tt__free(S->al, S->in_c);
    tt__free(S->al, S->seen);
    tt__free(S->al, S->placed);
    tt__free(S->al, S->vdisp);
    tt__free(S->al, S->vmark);
    tt__free(S->al, S->state);
    tt__free(S->al, S->waiting);
    tt__free(S->al, S->heap);
    tt__free(S->al, S->near_faces);
    tt__free(S->al, S->owners);
    tt__free(S->al, S->pairs);
    tt_cluster_hierarchy_free(S->H);
}

TTDEF tt_result tt_hpm_map(const tt_mesh *mesh, const tt_image *image, const tt_hpm_options *options,
                           const tt_allocator *allocator, float *corner_uv, int *face_cluster,
                           tt_hpm_report *report, tt_error *error)
{
    tt__hpm S;
    tt_hpm_options o;
    tt_cluster_options copt;
    tt_result res;
    double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300}, diag, total_area = 0;
    int i, f, match_size;

    memset(&S, 0, sizeof S);
    if (report) memset(report, 0, sizeof *report);
    tt__ok(error);
    if (!mesh || !image || !corner_uv)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "tt_hpm_map needs a mesh, an image and corner_uv (got NULL)");
    if (tt__check_allocator(allocator, error) != TT_OK) return TT_ERROR_INVALID_ARGUMENT;
    if (!image->pixels || image->width < 1 || image->height < 1)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1, "tt_hpm_map: the image is empty");
    if (mesh->nfaces < 1) return tt__fail(error, TT_ERROR_EMPTY_MESH, -1, -1, -1, -1, "the mesh has no faces");
    if (options)
        o = *options;
    else
        memset(&o, 0, sizeof o);
    match_size = o.match_size ? o.match_size : TT_DEFAULT_HPM_MATCH_SIZE;
    if (!(o.scale >= 0 && o.scale < 1e300) || !(o.threshold >= 0) || o.rotations < 0 || o.rotations > 64 ||
        !(o.max_turn >= 0 && o.max_turn <= 180) ||
        !(o.band >= 0 && o.band <= 1e6) || match_size < 16 || match_size > 512 ||
        (match_size & (match_size - 1)) != 0 || !(o.min_footprint >= 0 && o.min_footprint < 1e300) ||
        o.min_faces < 0 || (o.flags & ~15u) != 0 || !(o.max_flattening_error >= 0) ||
        (o.branching != 0 && (o.branching < 2 || o.branching > 64)))
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "hpm options out of range: scale %g (>= 0), threshold %g (>= 0), rotations %d (0..64), "
                        "max_turn %g (0..180), band %g (0..1e6), match_size %d (a power of two, 16..512), "
                        "min_footprint %g (>= 0), min_faces %d (>= 0), flags 0x%x, branching %d (0 or 2..64), "
                        "max_flattening_error %g (>= 0)",
                        o.scale, o.threshold, o.rotations, o.max_turn, o.band, match_size, o.min_footprint, o.min_faces,
                        o.flags, o.branching, o.max_flattening_error);
    for (f = 0; f < mesh->nfaces; f++) {
        const int *c = mesh->corner_vert + mesh->face_start[f];
        double e[3], g[3], cr[3];
        if (mesh->face_start[f + 1] - mesh->face_start[f] != 3)
            return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, f, -1, -1, -1,
                            "face %d has %d corners: hierarchical pattern mapping needs triangles", f,
                            mesh->face_start[f + 1] - mesh->face_start[f]);
        tt__sub3f(mesh->pos + 3 * c[1], mesh->pos + 3 * c[0], e);
        tt__sub3f(mesh->pos + 3 * c[2], mesh->pos + 3 * c[0], g);
        tt__cross3(e, g, cr);
        total_area += 0.5 * tt__length3(cr);
        for (i = 0; i < 3; i++) {
            int k;
            for (k = 0; k < 3; k++) {
                double v = mesh->pos[3 * c[i] + k];
                if (v < lo[k]) lo[k] = v;
                if (v > hi[k]) hi[k] = v;
            }
        }
    }
    if (!(total_area > 0))
        return tt__fail(error, TT_ERROR_ZERO_AREA_FACE, -1, -1, -1, -1,
                        "every face of the mesh has zero area: nothing to texture");
    diag = sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                (hi[2] - lo[2]) * (hi[2] - lo[2]));

    S.mesh = mesh;
    S.al = allocator;
    S.flags = o.flags;
    S.toroidal = (o.flags & TT_HPM_TOROIDAL) != 0;
    S.threshold = o.threshold > 0 ? o.threshold : TT_DEFAULT_HPM_THRESHOLD;
    S.rotations = o.rotations ? o.rotations : TT_DEFAULT_HPM_ROTATIONS;
    {
        /* The copies a fit tries: orientation k at 2 pi k / rotations when
           it turns no more than max_turn from the main neighbour (copy 0),
           in the order 0, +1, -1, +2, -2, ... so that ties (D33) keep the
           smaller turn. */
        double limit = (o.max_turn > 0 ? o.max_turn : TT_DEFAULT_HPM_MAX_TURN) * TT__PI / 180 + 1e-9;
        int step;
        S.copies = 0;
        S.angle[S.copies++] = 0;
        for (step = 1; 2 * step <= S.rotations; step++) {
            double a = TT__TWO_PI * step / S.rotations;
            if (a > limit) break;
            S.angle[S.copies++] = a;
            if (2 * step < S.rotations) S.angle[S.copies++] = -a;
        }
    }
    S.band = o.band;
    S.floor_px = o.min_footprint > 0 ? o.min_footprint : TT_DEFAULT_HPM_MIN_FOOTPRINT;
    S.min_faces = o.min_faces ? o.min_faces : TT_DEFAULT_HPM_MIN_FACES;
    S.s = image->width / (o.scale > 0 ? o.scale : diag / 4);
    S.fopt.max_error = o.max_flattening_error;
    S.progress = o.progress;
    S.progress_user_data = o.progress_user_data;
    tt_rng_seed(&S.rng, o.seed, 0x68706d);
    tt_rng_seed(&S.place_rng, o.seed, 0x706c6163);
    if (!(S.s > 0 && S.s < 1e300))
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "hpm: scale %g gives no texel density (the mesh's bounding box diagonal is %g)", o.scale,
                        diag);

    memset(&copt, 0, sizeof copt);
    copt.seed = o.seed;
    copt.branching = o.branching;
    res = tt_cluster_hierarchy_build(mesh, &copt, allocator, &S.H, error);
    if (res != TT_OK) return res;
    res = tt__hpm_prepare_image(&S, image, match_size, error);
    if (res != TT_OK) goto done;

    S.flat = TT__ALLOC(allocator, float, 2 * (size_t)mesh->ncorners);
    S.uv = TT__ALLOC(allocator, double, 2 * (size_t)mesh->ncorners);
    if (o.flags & TT_HPM_RANDOM_PLACEMENT) S.out = TT__ALLOC(allocator, double, 2 * (size_t)mesh->ncorners);
    S.owner = TT__ALLOC(allocator, int, (size_t)mesh->nfaces);
    S.in_c = TT__ALLOC(allocator, int, (size_t)mesh->nfaces);
    S.seen = TT__ALLOC(allocator, int, (size_t)mesh->nfaces);
    S.placed = TT__ALLOC(allocator, double, 2 * (size_t)mesh->ncorners);
    S.vdisp = TT__ALLOC(allocator, double, 5 * (size_t)mesh->nverts);
    S.vmark = TT__ALLOC(allocator, int, (size_t)mesh->nverts);
    S.state = TT__ALLOC(allocator, unsigned char, (size_t)S.H->nclusters);
    S.queue = TT__ALLOC(allocator, tt__heap_item *, (size_t)S.H->nlevels);
    if (S.queue)
        for (i = 0; i < S.H->nlevels; i++) S.queue[i] = NULL;
    S.qcount = TT__ALLOC(allocator, int, (size_t)S.H->nlevels);
    S.qcap = TT__ALLOC(allocator, int, (size_t)S.H->nlevels);
    S.heap = TT__ALLOC(allocator, tt__heap_item, 3 * (size_t)mesh->nfaces + 3);
    S.near_faces = TT__ALLOC(allocator, int, (size_t)mesh->nfaces);
    if (!S.flat || !S.uv || ((o.flags & TT_HPM_RANDOM_PLACEMENT) && !S.out) || !S.owner || !S.in_c || !S.seen ||
        !S.placed || !S.vdisp || !S.vmark || !S.state || !S.queue || !S.qcount || !S.qcap || !S.heap ||
        !S.near_faces) {
        res = tt__fail(error, TT_ERROR_OUT_OF_MEMORY, -1, -1, -1, -1, "out of memory (hpm state)");
        goto done;
    }
    for (f = 0; f < mesh->nfaces; f++) {
        S.owner[f] = -1;
        S.in_c[f] = S.seen[f] = 0;
    }
    for (i = 0; i < mesh->nverts; i++) S.vmark[i] = 0;
    memset(S.state, 0, (size_t)S.H->nclusters);
    for (i = 0; i < S.H->nlevels; i++) {
        S.queue[i] = NULL;
        S.qcount[i] = S.qcap[i] = 0;
    }
    for (i = 0; i < 2 * mesh->ncorners; i++) {
        S.uv[i] = 0;
        if (S.out) S.out[i] = 0;
    }
    res = tt__hpm_traverse(&S, error);
    if (res != TT_OK) goto done;
    if (!(o.flags & TT_HPM_NO_RELAXATION)) tt__hpm_choose_borders(&S);
    tt__hpm_leftovers(&S, S.uv);
    if (S.out) tt__hpm_leftovers(&S, S.out);
    {
        const double *x = S.out ? S.out : S.uv;
        for (i = 0; i < mesh->ncorners; i++) {
            corner_uv[2 * i] = (float)(x[2 * i] / S.W);
            corner_uv[2 * i + 1] = (float)(1 - x[2 * i + 1] / S.Hh);
        }
    }
    if (face_cluster)
        for (f = 0; f < mesh->nfaces; f++) face_cluster[f] = S.owner[f];
    S.rep.levels = S.H->nlevels;
    S.rep.texels_per_unit = S.s;
    S.rep.match_width = S.ww;
    S.rep.match_height = S.wh;
    S.rep.fft_size = S.P;
    S.rep.copies = S.copies;
    {
        int accepted = S.rep.accepted_fits + S.rep.floor_fits;
        S.rep.mean_error = accepted > 0 ? S.error_sum / accepted : 0;
    }
    if (report) *report = S.rep;
done:
    tt__hpm_release(&S);
    return res;
}

/* ------------------------------------------------------------------------ */
/* 9. Polycube + Wang tiles                                                 */
/* ------------------------------------------------------------------------ */

/* The grid being built (see the section's doc comment for its layout). */
#define TT__POLYCUBE_SEAL_CUBES 32  /* an open mesh's holes are sealed up to 2 cubes wide per 32 of resolution */
#define TT__POLYCUBE_SEAL_WINDING 0.9   /* the winding number inside a surface with small holes (a bowl: 0.5-0.9) */

typedef struct tt__voxels {
    int dims[3];
    int count;                  /* dims[0] * dims[1] * dims[2] <= TT_POLYCUBE_MAX_CUBES */
    double origin[3], h;
    double tie;                 /* tt__polycube_tie */
    unsigned char *occupied;    /* per cube: 1 in the polycube */
    unsigned char *hit;         /* per cube: the model's surface meets it */
    unsigned char *cell_hit;    /* per lattice point: the model meets the unit cell centred on it */
    int *queue;                 /* count entries of scratch: the fill's and the component search's queue */
    const tt_allocator *allocator;
} tt__voxels;

/* The tolerance of the tie rule (spec P3; see the doc comment): boxes are
   shrunk by it and triangles moved inward by twice it. It must exceed the
   rounding of the float input, or a face meant to lie on a lattice plane
   lands a rounding error on the wrong side of it: 1e-6 h, or 8 float ulps
   of the largest coordinate when that is more (a mesh far from the
   origin). */
static double tt__polycube_tie(const tt_mesh *mesh, double h)
{
    double largest = 0.0, tie;
    int i;
    for (i = 0; i < 3 * mesh->nverts; i++)
        if (fabs(mesh->pos[i]) > largest) largest = fabs(mesh->pos[i]);
    tie = 8.0 * largest / 16777216.0;
    return tie > 1e-6 * h ? tie : 1e-6 * h;
}

/* Akenine-Moeller's separating-axis test of a triangle against the box
   [-half, half]^3: v holds the corners relative to the box centre, n the
   triangle's normal. Overlap (touching included) unless some axis separates
   the projections: the 9 cross products of the box axes with the triangle's
   edges, the 3 box axes, the triangle's normal. A zero axis (an edge parallel
   to a box axis) projects everything to 0 and separates nothing. */
static int tt__triangle_box_overlap(const double v[3][3], const double n[3], double half)
{
    int a, e, k;
    for (e = 0; e < 3; e++) {
        const double *p = v[e], *q = v[(e + 1) % 3];
        double edge[3];
        edge[0] = q[0] - p[0]; edge[1] = q[1] - p[1]; edge[2] = q[2] - p[2];
        for (a = 0; a < 3; a++) {
            /* axis = e_a x edge */
            double axis[3], lo, hi, r;
            axis[a] = 0.0;
            axis[(a + 1) % 3] = -edge[(a + 2) % 3];
            axis[(a + 2) % 3] = edge[(a + 1) % 3];
            lo = hi = tt__dot3(axis, v[0]);
            for (k = 1; k < 3; k++) {
                double d = tt__dot3(axis, v[k]);
                if (d < lo) lo = d;
                if (d > hi) hi = d;
            }
            r = half * (fabs(axis[0]) + fabs(axis[1]) + fabs(axis[2]));
            if (lo > r || hi < -r) return 0;
        }
    }
    for (a = 0; a < 3; a++) {
        double lo = v[0][a], hi = v[0][a];
        for (k = 1; k < 3; k++) {
            if (v[k][a] < lo) lo = v[k][a];
            if (v[k][a] > hi) hi = v[k][a];
        }
        if (lo > half || hi < -half) return 0;
    }
    return fabs(tt__dot3(n, v[0])) <= half * (fabs(n[0]) + fabs(n[1]) + fabs(n[2]));
}

/* Mark in `mark` the boxes of side h, box (i, j, k) centred at
   origin + h * (i + 1/2, j + 1/2, k + 1/2) for i < dims[0] and so on, that
   the mesh's fan triangles meet under the tie rule. Returns the number of
   zero-area triangles skipped: twice the area below 1e-12 times the squared
   longest edge (collinear up to rounding). */
static int tt__polycube_voxelize(const tt_mesh *mesh, const double origin[3], double h, const int dims[3],
                                 double tie, unsigned char *mark)
{
    int f, zero_area = 0;
    double half = 0.5 * h - tie;
    for (f = 0; f < mesh->nfaces; f++) {
        int first = mesh->face_start[f], size = mesh->face_start[f + 1] - first, t;
        for (t = 1; t + 1 < size; t++) {
            const float *p[3];
            double e1[3], e2[3], n[3], len, longest, shifted[3][3], lo[3], hi[3], v[3][3], centre[3];
            int a, k, range_lo[3], range_hi[3], i, j, l;
            p[0] = mesh->pos + 3 * mesh->corner_vert[first];
            p[1] = mesh->pos + 3 * mesh->corner_vert[first + t];
            p[2] = mesh->pos + 3 * mesh->corner_vert[first + t + 1];
            tt__sub3f(p[1], p[0], e1);
            tt__sub3f(p[2], p[0], e2);
            tt__cross3(e1, e2, n);
            longest = tt__dot3(e1, e1);
            if (tt__dot3(e2, e2) > longest) longest = tt__dot3(e2, e2);
            {
                double e3[3];
                tt__sub3f(p[2], p[1], e3);
                if (tt__dot3(e3, e3) > longest) longest = tt__dot3(e3, e3);
            }
            len = tt__normalize3(n);
            if (!(len > 1e-12 * longest)) { zero_area++; continue; }
            for (k = 0; k < 3; k++)
                for (a = 0; a < 3; a++) {
                    shifted[k][a] = (double)p[k][a] - 2.0 * tie * n[a];
                    if (k == 0 || shifted[k][a] < lo[a]) lo[a] = shifted[k][a];
                    if (k == 0 || shifted[k][a] > hi[a]) hi[a] = shifted[k][a];
                }
            for (a = 0; a < 3; a++) {
                double first_box = floor((lo[a] - origin[a]) / h), last_box = floor((hi[a] - origin[a]) / h);
                range_lo[a] = first_box < 0.0 ? 0 : (first_box > dims[a] - 1 ? dims[a] : (int)first_box);
                range_hi[a] = last_box > dims[a] - 1 ? dims[a] - 1 : (last_box < 0.0 ? -1 : (int)last_box);
            }
            for (l = range_lo[2]; l <= range_hi[2]; l++)
                for (j = range_lo[1]; j <= range_hi[1]; j++)
                    for (i = range_lo[0]; i <= range_hi[0]; i++) {
                        int index = i + dims[0] * (j + dims[1] * l);
                        if (mark[index]) continue;
                        centre[0] = origin[0] + h * (i + 0.5);
                        centre[1] = origin[1] + h * (j + 0.5);
                        centre[2] = origin[2] + h * (l + 0.5);
                        for (k = 0; k < 3; k++)
                            for (a = 0; a < 3; a++) v[k][a] = shifted[k][a] - centre[a];
                        if (tt__triangle_box_overlap((const double(*)[3])v, n, half)) mark[index] = 1;
                    }
        }
    }
    return zero_area;
}

/* Breadth first through the faces of the cubes: from the seeds in
   vox->queue[0, seeds) (already labelled `to`), every cube labelled `from`
   that they reach is labelled `to`. Returns how many cubes are labelled
   `to` by then, the seeds included; vox->queue lists them in the order
   reached. */
static int tt__polycube_flood(tt__voxels *vox, unsigned char *label, unsigned char from, unsigned char to, int seeds)
{
    const int step[3] = {1, vox->dims[0], vox->dims[0] * vox->dims[1]};
    int head = 0, tail = seeds;
    while (head < tail) {
        int c = vox->queue[head++], a, rest = c, coord[3];
        coord[0] = rest % vox->dims[0]; rest /= vox->dims[0];
        coord[1] = rest % vox->dims[1];
        coord[2] = rest / vox->dims[1];
        for (a = 0; a < 3; a++) {
            if (coord[a] > 0 && label[c - step[a]] == from) {
                label[c - step[a]] = to;
                vox->queue[tail++] = c - step[a];
            }
            if (coord[a] + 1 < vox->dims[a] && label[c + step[a]] == from) {
                label[c + step[a]] = to;
                vox->queue[tail++] = c + step[a];
            }
        }
    }
    return tail;
}

/* Interior fill (spec P4): flood the exterior from cube 0 (padding, so
   empty, and the padding connects the whole outside) through 6-connected
   empty cubes; the empty cubes it does not reach become occupied. Returns
   how many. Uses vox->queue. */
static int tt__polycube_fill(tt__voxels *vox)
{
    int added = 0, i;
    unsigned char *occ = vox->occupied;
    occ[0] = 2;   /* 2 = empty and reached, for the duration of the flood */
    vox->queue[0] = 0;
    tt__polycube_flood(vox, occ, 0, 2, 1);
    for (i = 0; i < vox->count; i++) {
        if (occ[i] == 0) { occ[i] = 1; added++; }
        else if (occ[i] == 2) occ[i] = 0;
    }
    return added;
}

/* The generalised winding number of `mesh` at p: the solid angle its
   faces (fans from corner 0) span seen from p, over 4 pi (Van Oosterom and
   Strackee's formula per triangle). 1 inside a closed outward mesh, 0
   outside, near those across small holes. */
static double tt__winding_number(const tt_mesh *mesh, const double p[3])
{
    double total = 0.0;
    int f, k, i, a;
    for (f = 0; f < mesh->nfaces; f++) {
        const int first = mesh->face_start[f], n = mesh->face_start[f + 1] - first;
        for (k = 1; k + 1 < n; k++) {
            const int corner[3] = {first, first + k, first + k + 1};
            double r[3][3], length[3], across[3];
            for (i = 0; i < 3; i++) {
                for (a = 0; a < 3; a++) r[i][a] = mesh->pos[3 * mesh->corner_vert[corner[i]] + a] - p[a];
                length[i] = tt__length3(r[i]);
            }
            tt__cross3(r[1], r[2], across);
            total += 2.0 * atan2(tt__dot3(r[0], across), length[0] * length[1] * length[2] +
                                                             tt__dot3(r[0], r[1]) * length[2] +
                                                             tt__dot3(r[1], r[2]) * length[0] +
                                                             tt__dot3(r[2], r[0]) * length[1]);
        }
    }
    return total / (4.0 * TT__PI);
}

/* Every cube within Chebyshev distance `radius` of a cube labelled `from`
   in `source`, except the cubes of `walls` (NULL: none), is labelled `to`
   in `target` (which may not be `source`). */
static void tt__polycube_dilate(const tt__voxels *vox, const unsigned char *source, unsigned char from, int radius,
                                const unsigned char *walls, unsigned char *target, unsigned char to)
{
    int c, i, j, k;
    for (c = 0; c < vox->count; c++) {
        const int x = c % vox->dims[0], y = (c / vox->dims[0]) % vox->dims[1], z = c / (vox->dims[0] * vox->dims[1]);
        if (source[c] != from) continue;
        for (k = z - radius; k <= z + radius; k++)
            for (j = y - radius; j <= y + radius; j++)
                for (i = x - radius; i <= x + radius; i++) {
                    int id;
                    if (i < 0 || j < 0 || k < 0 || i >= vox->dims[0] || j >= vox->dims[1] || k >= vox->dims[2]) continue;
                    id = i + vox->dims[0] * (j + vox->dims[1] * k);
                    if (!walls || !walls[id]) target[id] = to;
                }
    }
}

/* Seals the holes of an open mesh (see "Interior" in the section's notes):
   fills the components of empty cubes that the exterior reaches only
   through gaps narrower than about 2 * radius cubes and that lie inside
   the mesh by its winding number. Returns the cubes filled, -1 when out of
   memory. Uses vox->queue. */
static int tt__polycube_seal(tt__voxels *vox, const tt_mesh *mesh, int radius)
{
    const int n = vox->count;
    unsigned char *state = NULL, *grown = NULL;
    int c, seeds = 0, added = 0, grow;
    for (c = 0; c < mesh->ncorners && mesh->twin[c] >= 0; c++) continue;
    if (c == mesh->ncorners) return 0;   /* no hole */
    state = TT__ALLOC(vox->allocator, unsigned char, n);
    grown = TT__ALLOC(vox->allocator, unsigned char, n);
    if (!state || !grown) {
        tt__free(vox->allocator, state);
        tt__free(vox->allocator, grown);
        return -1;
    }
    /* state: 1 within `radius` cubes of the polycube, 2 the exterior flooded around that (it cannot pass a
       hole that narrow), 0 the rest. */
    memset(state, 0, (size_t)n);
    tt__polycube_dilate(vox, vox->occupied, 1, radius, NULL, state, 1);
    for (c = 0; c < n; c++) {
        const int x = c % vox->dims[0], y = (c / vox->dims[0]) % vox->dims[1], z = c / (vox->dims[0] * vox->dims[1]);
        if ((x == 0 || y == 0 || z == 0 || x == vox->dims[0] - 1 || y == vox->dims[1] - 1 || z == vox->dims[2] - 1) &&
            !state[c]) {
            state[c] = 2;
            vox->queue[seeds++] = c;
        }
    }
    tt__polycube_flood(vox, state, 0, 2, seeds);
    /* Grown back by `radius` cubes through empty ones: the exterior up to the polycube again, except behind
       holes. */
    for (grow = 0; grow < radius; grow++) {
        memcpy(grown, state, (size_t)n);
        tt__polycube_dilate(vox, grown, 2, 1, vox->occupied, state, 2);
    }
    for (c = 0; c < n; c++)
        if (state[c] != 2) state[c] = vox->occupied[c] ? 1 : 0;
    /* Each component of what is left, filled when inside the mesh. */
    for (c = 0; c < n; c++) {
        int inside = 0, sample, reached, i;
        if (state[c]) continue;
        state[c] = 3;
        vox->queue[0] = c;
        reached = tt__polycube_flood(vox, state, 0, 3, 1);
        for (sample = 0; sample < 3; sample++) {
            const int cube = vox->queue[(int)((long)(reached - 1) * sample / 2)];
            const int x = cube % vox->dims[0], y = (cube / vox->dims[0]) % vox->dims[1];
            const int z = cube / (vox->dims[0] * vox->dims[1]);
            double centre[3];
            centre[0] = vox->origin[0] + vox->h * (x + 0.5);
            centre[1] = vox->origin[1] + vox->h * (y + 0.5);
            centre[2] = vox->origin[2] + vox->h * (z + 0.5);
            inside += fabs(tt__winding_number(mesh, centre)) > TT__POLYCUBE_SEAL_WINDING;
        }
        if (inside >= 2) {
            for (i = 0; i < reached; i++) vox->occupied[vox->queue[i]] = 1;
            added += reached;
        }
    }
    tt__free(vox->allocator, state);
    tt__free(vox->allocator, grown);
    return added;
}

/* The occupancy mask of the 8 cubes around lattice point (i, j, k): bit
   dx + 2 dy + 4 dz is cube (i - 1 + dx, j - 1 + dy, k - 1 + dz); cubes
   outside the grid count as empty. */
static int tt__polycube_mask(const tt__voxels *vox, int i, int j, int k)
{
    int mask = 0, bit;
    for (bit = 0; bit < 8; bit++) {
        int x = i - 1 + (bit & 1), y = j - 1 + ((bit >> 1) & 1), z = k - 1 + ((bit >> 2) & 1);
        if (x < 0 || y < 0 || z < 0 || x >= vox->dims[0] || y >= vox->dims[1] || z >= vox->dims[2]) continue;
        if (vox->occupied[x + vox->dims[0] * (y + vox->dims[1] * z)]) mask |= 1 << bit;
    }
    return mask;
}

/* Is S a disc inside the cell of a lattice point with this mask? Decided
   from the facelets themselves, independently of the C1/C2 rule: a facelet
   is the quarter of a cube face at the point, between two face-adjacent
   cubes of the block that differ; the 6 half-edges (spokes) from the point
   along +-x, +-y, +-z each lie between 4 cubes and 4 facelet slots. S is a
   disc iff there are facelets, every spoke carries 0 or 2 of them (an edge
   of a surface), and they are connected through the spokes (one fan). */
static int tt__polycube_mask_is_disc(int mask)
{
    int parent[12], facelets = 0, b, rest, spoke_axis, side, f, roots = 0;
    /* Facelet id: the axis b it crosses, and the other two bits of its cubes. */
    for (f = 0; f < 12; f++) parent[f] = f;
    for (b = 0; b < 3; b++)
        for (rest = 0; rest < 4; rest++) {
            int low = 0, m = 0, k;
            for (k = 0; k < 3; k++)
                if (k != b) low |= ((rest >> m++) & 1) << k;
            if (((mask >> low) & 1) != ((mask >> (low | 1 << b)) & 1)) facelets |= 1 << (4 * b + rest);
        }
    if (!facelets) return 0;
    for (spoke_axis = 0; spoke_axis < 3; spoke_axis++)
        for (side = 0; side < 2; side++) {
            int on[4], n = 0;
            for (b = 0; b < 3; b++) {
                if (b == spoke_axis) continue;
                for (rest = 0; rest < 4; rest++) {
                    /* The facelet's cubes have bit spoke_axis == side. */
                    int low = 0, m = 0, k;
                    for (k = 0; k < 3; k++)
                        if (k != b) low |= ((rest >> m++) & 1) << k;
                    if (((low >> spoke_axis) & 1) == side && (facelets >> (4 * b + rest) & 1)) on[n++] = 4 * b + rest;
                }
            }
            if (n != 0 && n != 2) return 0;
            if (n == 2) {
                int x = on[0], y = on[1];
                while (parent[x] != x) x = parent[x];
                while (parent[y] != y) y = parent[y];
                parent[x] = y;
            }
        }
    for (f = 0; f < 12; f++)
        if ((facelets >> f & 1) && parent[f] == f) roots++;
    return roots == 1;
}

/* The critical configurations of spec P6 in a block's mask. *kind gets 1 for
   C1 (a checkerboard around spoke `spoke_axis`, its cubes' bit on that axis
   `*side`), 2 for C2 (two antipodal cubes alone), 3 for its complement (two
   antipodal cubes empty); returns 0 when there is none. */
static int tt__polycube_mask_critical(int mask, int *spoke_axis, int *side)
{
    int axis, s, pop = 0, bit;
    for (axis = 0; axis < 3; axis++)
        for (s = 0; s < 2; s++) {
            /* The 4 cubes around the spoke, in cyclic order over the other two axes. */
            int b1 = (axis + 1) % 3, b2 = (axis + 2) % 3, base = s << axis;
            int c0 = (mask >> base) & 1, c1 = (mask >> (base | 1 << b1)) & 1;
            int c2 = (mask >> (base | 1 << b1 | 1 << b2)) & 1, c3 = (mask >> (base | 1 << b2)) & 1;
            if (c0 == c2 && c1 == c3 && c0 != c1) {
                if (spoke_axis) *spoke_axis = axis;
                if (side) *side = s;
                return 1;
            }
        }
    for (bit = 0; bit < 8; bit++) pop += (mask >> bit) & 1;
    for (bit = 0; bit < 4; bit++) {
        int pair = 1 << bit | 1 << (7 - bit);
        if (pop == 2 && mask == pair) return 2;
        if (pop == 6 && (mask & pair) == 0) return 3;
    }
    return 0;
}

/* How near cube `index` is to the model, at the grid's resolution (smaller
   is nearer): the surface meets it, then the number of its face neighbours
   the surface meets (see the doc comment). The repair asks only about
   cubes next to occupied ones, never in the grid's outer layer, so index
   +-1 stays in the cube's row. */
static int tt__polycube_farness(const tt__voxels *vox, int index)
{
    const int step[3] = {1, vox->dims[0], vox->dims[0] * vox->dims[1]};
    int a, near_faces = 0;
    for (a = 0; a < 3; a++) {
        if (index - step[a] >= 0 && vox->hit[index - step[a]]) near_faces++;
        if (index + step[a] < vox->count && vox->hit[index + step[a]]) near_faces++;
    }
    return (vox->hit[index] ? 0 : 8) + 6 - near_faces;
}

/* Linear index of the cube with bit `bit` of the block around lattice point (i, j, k). */
static int tt__polycube_block_cube(const tt__voxels *vox, int i, int j, int k, int bit)
{
    return (i - 1 + (bit & 1)) + vox->dims[0] * ((j - 1 + ((bit >> 1) & 1)) + vox->dims[1] * (k - 1 + (bit >> 2)));
}

/* Of two cubes, the one to occupy: the nearer, ties by the smaller index. */
static int tt__polycube_prefer(const tt__voxels *vox, int a, int b)
{
    int fa = tt__polycube_farness(vox, a), fb = tt__polycube_farness(vox, b);
    return fa < fb || (fa == fb && a < b) ? a : b;
}

/* Remove the critical configuration at lattice point (i, j, k), if any, by
   occupying cubes; returns the number added. */
static int tt__polycube_fix_point(tt__voxels *vox, int i, int j, int k, int *added_cubes)
{
    int spoke_axis = 0, side = 0, mask = tt__polycube_mask(vox, i, j, k), bit, n = 0, kind;
    /* Most points are outside or inside (mask 0 or 255) or on a disc: nothing to do. Otherwise the
       critical configuration (there is one: spec P6's equivalence, tested) says what to add. */
    if (mask == 0 || mask == 255 || tt__polycube_mask_is_disc(mask)) return 0;
    kind = tt__polycube_mask_critical(mask, &spoke_axis, &side);
    if (kind == 1) {
        int b1 = (spoke_axis + 1) % 3, b2 = (spoke_axis + 2) % 3, base = side << spoke_axis;
        int empty_a = (mask >> base) & 1 ? base | 1 << b1 : base;
        int empty_b = empty_a ^ (1 << b1 | 1 << b2);
        added_cubes[n++] = tt__polycube_prefer(vox, tt__polycube_block_cube(vox, i, j, k, empty_a),
                                               tt__polycube_block_cube(vox, i, j, k, empty_b));
    } else if (kind == 2) {
        /* A staircase from cube `from` to its antipode: three single-axis
           steps in one of 6 orders, the two cubes between occupied. */
        static const int order[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
        int from = 0, best = -1, best_cost = 0, p;
        while (!((mask >> from) & 1)) from++;
        for (p = 0; p < 6; p++) {
            int m1 = from ^ (1 << order[p][0]), m2 = m1 ^ (1 << order[p][1]);
            int cost = tt__polycube_farness(vox, tt__polycube_block_cube(vox, i, j, k, m1)) +
                       tt__polycube_farness(vox, tt__polycube_block_cube(vox, i, j, k, m2));
            if (best < 0 || cost < best_cost) { best = p; best_cost = cost; }
        }
        bit = from ^ (1 << order[best][0]);
        added_cubes[n++] = tt__polycube_block_cube(vox, i, j, k, bit);
        added_cubes[n++] = tt__polycube_block_cube(vox, i, j, k, bit ^ (1 << order[best][1]));
    } else if (kind == 3) {
        int empty = 0;
        while ((mask >> empty) & 1) empty++;
        added_cubes[n++] = tt__polycube_prefer(vox, tt__polycube_block_cube(vox, i, j, k, empty),
                                               tt__polycube_block_cube(vox, i, j, k, 7 - empty));
    }
    for (bit = 0; bit < n; bit++) vox->occupied[added_cubes[bit]] = 1;
    return n;
}

/* The lattice points still to check during the repair: a stack, and a flag
   per lattice point so that none is on it twice. */
typedef struct tt__repair_stack {
    int *points;
    int count, capacity;
    unsigned char *queued;
    int lattice[3];             /* lattice points per axis: dims + 1 */
} tt__repair_stack;

/* Fix lattice point (i, j, k) and queue the points around every cube that
   adds (their masks changed). Returns the cubes added, -1 when out of memory. */
static int tt__polycube_fix_and_queue(tt__voxels *vox, tt__repair_stack *s, int i, int j, int k)
{
    int cubes[2], n = tt__polycube_fix_point(vox, i, j, k, cubes), c, bit;
    for (c = 0; c < n; c++) {
        int rest = cubes[c], x, y, z;
        x = rest % vox->dims[0]; rest /= vox->dims[0];
        y = rest % vox->dims[1];
        z = rest / vox->dims[1];
        for (bit = 0; bit < 8; bit++) {
            int qx = x + (bit & 1), qy = y + ((bit >> 1) & 1), qz = z + (bit >> 2);
            int q = qx + s->lattice[0] * (qy + s->lattice[1] * qz);
            int *grown;
            /* Points on the grid's outer faces have cubes outside it: never critical. */
            if (s->queued[q] || qx < 1 || qy < 1 || qz < 1 || qx >= vox->dims[0] || qy >= vox->dims[1] ||
                qz >= vox->dims[2])
                continue;
            grown = (int *)tt__grow(vox->allocator, s->points, &s->capacity, s->count + 1, sizeof(int));
            if (!grown) return -1;
            s->points = grown;
            s->queued[q] = 1;
            s->points[s->count++] = q;
        }
    }
    return n;
}

/* Manifold repair (spec P6): every lattice point inside the grid is checked
   in order, and after each one the points whose blocks gained a cube are
   checked again (the stack) until none is critical, so at the end no
   critical configuration is left anywhere. Adds to *added. */
static tt_result tt__polycube_repair(tt__voxels *vox, int *added, tt_error *error)
{
    tt__repair_stack s;
    size_t points;
    int i, j, k, n = 0, out_of_memory;
    memset(&s, 0, sizeof s);
    s.lattice[0] = vox->dims[0] + 1; s.lattice[1] = vox->dims[1] + 1; s.lattice[2] = vox->dims[2] + 1;
    points = (size_t)s.lattice[0] * s.lattice[1] * s.lattice[2];
    s.queued = TT__ALLOC(vox->allocator, unsigned char, points);
    if (s.queued) memset(s.queued, 0, points);
    for (k = 1; s.queued && k < vox->dims[2] && n >= 0; k++)
        for (j = 1; j < vox->dims[1] && n >= 0; j++)
            for (i = 1; i < vox->dims[0] && n >= 0; i++) {
                n = tt__polycube_fix_and_queue(vox, &s, i, j, k);
                if (n > 0) *added += n;
                while (n >= 0 && s.count > 0) {
                    int point = s.points[--s.count], rest = point, x, y;
                    s.queued[point] = 0;
                    x = rest % s.lattice[0]; rest /= s.lattice[0];
                    y = rest % s.lattice[1];
                    n = tt__polycube_fix_and_queue(vox, &s, x, y, rest / s.lattice[1]);
                    if (n > 0) *added += n;
                }
            }
    out_of_memory = !s.queued || n < 0;
    tt__free(vox->allocator, s.points);
    tt__free(vox->allocator, s.queued);
    if (out_of_memory)
        return tt__fail(error, TT_ERROR_OUT_OF_MEMORY, -1, -1, -1, -1, "out of memory repairing the polycube");
    return TT_OK;
}

/* Connected components of the occupied cubes through their faces; with
   `labels`, each cube's component (0, 1, ... in index order; -1 for empty
   cubes). Uses vox->queue, and marks visited cubes 2 while it runs. */
static int tt__polycube_components(tt__voxels *vox, int *labels)
{
    unsigned char *occ = vox->occupied;
    int components = 0, start, i;
    for (start = 0; start < vox->count; start++) {
        int reached;
        if (occ[start] != 1) continue;
        occ[start] = 2;
        vox->queue[0] = start;
        reached = tt__polycube_flood(vox, occ, 1, 2, 1);
        for (i = 0; labels && i < reached; i++) labels[vox->queue[i]] = components;
        components++;
    }
    for (i = 0; i < vox->count; i++) {
        if (occ[i] == 2) occ[i] = 1;
        else if (labels) labels[i] = -1;
    }
    return components;
}

/* Euler characteristic of the polycube as a solid (the union of its closed
   cubes): V - E + F - C over the lattice points, edges, squares and cubes it
   contains, each edge, square and cube counted at its lowest lattice point
   from that point's mask. Once the repair has run, S bounds this solid as a
   closed 2-manifold, so chi(S) = 2 * this. */
static int tt__polycube_solid_chi(const tt__voxels *vox)
{
    int edge_bits[3] = {0, 0, 0}, square_bits[3] = {0, 0, 0}, bit, a, i, j, k, chi = 0;
    for (bit = 0; bit < 8; bit++)
        for (a = 0; a < 3; a++) {
            /* The edge from the point along +a lies between the block's cubes with bit a set; the square
               spanned from it across the other two axes b, c between those with bits b and c set. */
            if ((bit >> a) & 1) edge_bits[a] |= 1 << bit;
            if (((bit >> ((a + 1) % 3)) & 1) && ((bit >> ((a + 2) % 3)) & 1)) square_bits[a] |= 1 << bit;
        }
    for (k = 0; k <= vox->dims[2]; k++)
        for (j = 0; j <= vox->dims[1]; j++)
            for (i = 0; i <= vox->dims[0]; i++) {
                int mask = tt__polycube_mask(vox, i, j, k);
                if (!mask) continue;
                chi += 1;
                for (a = 0; a < 3; a++) chi += ((mask & square_bits[a]) != 0) - ((mask & edge_bits[a]) != 0);
                chi -= (mask >> 7) & 1;
            }
    return chi;
}

/* Remove the cubes marked removable (those of component `component` only,
   when labels is given), then repair and fill; returns whether the number
   of components and the Euler characteristic stayed `components` and
   `chi`. The cubes removed, repaired and filled go to *counts (3 ints). */
static tt_result tt__polycube_try_correction(tt__voxels *vox, const unsigned char *removable, const int *labels,
                                             int component, int components, int chi, int counts[3], int *kept,
                                             tt_error *error)
{
    int c;
    tt_result result;
    counts[0] = counts[1] = counts[2] = 0;
    for (c = 0; c < vox->count; c++)
        if (removable[c] && (!labels || labels[c] == component)) {
            vox->occupied[c] = 0;
            counts[0]++;
        }
    result = tt__polycube_repair(vox, &counts[1], error);
    if (result != TT_OK) return result;
    counts[2] = tt__polycube_fill(vox);
    *kept = tt__polycube_components(vox, NULL) == components && tt__polycube_solid_chi(vox) == chi;
    return TT_OK;
}

/* The correction step (Sec. 3.1 as read in spec P5; see the doc comment). */
static tt_result tt__polycube_correct(tt__voxels *vox, tt_polycube_report *report, tt_error *error)
{
    const int lattice[2] = {vox->dims[0] + 1, vox->dims[1] + 1};
    unsigned char *removable = TT__ALLOC(vox->allocator, unsigned char, vox->count);
    unsigned char *backup = TT__ALLOC(vox->allocator, unsigned char, vox->count);
    int *labels = NULL, components, chi, c, any = 0, counts[3], kept = 0, component;
    tt_result result = TT_OK;
    if (!removable || !backup) goto out_of_memory;
    components = tt__polycube_components(vox, NULL);
    chi = tt__polycube_solid_chi(vox);
    memcpy(backup, vox->occupied, (size_t)vox->count);
    for (c = 0; c < vox->count; c++) {
        int rest = c, x, y, z, bit;
        removable[c] = 0;
        if (!vox->occupied[c]) continue;
        x = rest % vox->dims[0]; rest /= vox->dims[0];
        y = rest % vox->dims[1];
        z = rest / vox->dims[1];
        for (bit = 0; bit < 8 && !removable[c]; bit++) {
            /* Corner point p of the cube; its cell holds part of S unless its whole block is occupied. */
            int px_ = x + (bit & 1), py = y + ((bit >> 1) & 1), pz = z + (bit >> 2);
            if (tt__polycube_mask(vox, px_, py, pz) != 255 && !vox->cell_hit[px_ + lattice[0] * (py + lattice[1] * pz)])
                removable[c] = 1;
        }
        any |= removable[c];
    }
    if (!any) goto done;
    /* All at once first: the usual case, one pass over the grid. */
    result = tt__polycube_try_correction(vox, removable, NULL, 0, components, chi, counts, &kept, error);
    if (result != TT_OK) goto done;
    if (kept) {
        report->removed += counts[0];
        report->repaired += counts[1];
        report->filled += counts[2];
        goto done;
    }
    memcpy(vox->occupied, backup, (size_t)vox->count);
    labels = TT__ALLOC(vox->allocator, int, vox->count);
    if (!labels) goto out_of_memory;
    tt__polycube_components(vox, labels);
    for (component = 0; component < components; component++) {
        for (c = 0; c < vox->count; c++)
            if (removable[c] && labels[c] == component) break;
        if (c == vox->count) continue;
        result = tt__polycube_try_correction(vox, removable, labels, component, components, chi, counts, &kept, error);
        if (result != TT_OK) goto done;
        if (kept) {
            report->removed += counts[0];
            report->repaired += counts[1];
            report->filled += counts[2];
            memcpy(backup, vox->occupied, (size_t)vox->count);
        } else {
            report->correction_reverted++;
            memcpy(vox->occupied, backup, (size_t)vox->count);
        }
    }
    goto done;
out_of_memory:
    result = tt__fail(error, TT_ERROR_OUT_OF_MEMORY, -1, -1, -1, -1, "out of memory correcting the polycube");
done:
    tt__free(vox->allocator, removable);
    tt__free(vox->allocator, backup);
    tt__free(vox->allocator, labels);
    return result;
}

TTDEF void tt_polycube_free(tt_polycube *polycube)
{
    tt_allocator allocator;
    if (!polycube) return;
    allocator = polycube->allocator;
    tt_mesh_free(polycube->surface);
    tt__free(&allocator, polycube->occupied);
    tt__free(&allocator, polycube->quad_cube);
    tt__free(&allocator, polycube->quad_side);
    tt__free(&allocator, polycube->vertex_lattice);
    tt__free(&allocator, polycube);
}

/* The corners of the quad on side `side` (0..5 = +x, -x, +y, -y, +z, -z) of
   cube (x, y, z), as lattice coordinates, corner 0 first, by the up rule of
   tt_polycube_build: v = s * e_up for side quads, -s * e_(up+1) for quads
   facing along up; u = v x n, so u x v = n and the corners run CCW seen
   from outside. */
static void tt__polycube_quad_corners(int x, int y, int z, int side, int up_axis, int up_sign, int corner[4][3])
{
    int normal_axis = side / 2, normal_sign = side % 2 ? -1 : 1, n[3] = {0, 0, 0}, u[3], v[3] = {0, 0, 0};
    int a, base[3];
    n[normal_axis] = normal_sign;
    if (normal_axis != up_axis) v[up_axis] = up_sign;
    else v[(up_axis + 1) % 3] = -up_sign;
    u[0] = v[1] * n[2] - v[2] * n[1];
    u[1] = v[2] * n[0] - v[0] * n[2];
    u[2] = v[0] * n[1] - v[1] * n[0];
    base[0] = x; base[1] = y; base[2] = z;
    for (a = 0; a < 3; a++) {
        /* The face lies in the plane of the cube's upper or lower side along n; corner 0 is its
           lowest corner along u and v. */
        if (a == normal_axis) base[a] += normal_sign > 0;
        else if (u[a] < 0 || v[a] < 0) base[a] += 1;
    }
    for (a = 0; a < 3; a++) {
        corner[0][a] = base[a];
        corner[1][a] = base[a] + u[a];
        corner[2][a] = base[a] + u[a] + v[a];
        corner[3][a] = base[a] + v[a];
    }
}

/* Extraction of S (spec P8): a quad per occupied cube face whose neighbour
   is empty, cubes in index order and sides in order within a cube, on the
   lattice points they use (numbered in order of first use), built as a
   strict mesh. */
static tt_result tt__polycube_extract(const tt__voxels *vox, int up_axis, int up_sign, tt_polycube *pc,
                                      tt_error *error)
{
    const int step[3] = {1, vox->dims[0], vox->dims[0] * vox->dims[1]};
    const int lattice[3] = {vox->dims[0] + 1, vox->dims[1] + 1, vox->dims[2] + 1};
    size_t points = (size_t)lattice[0] * lattice[1] * lattice[2];
    int *point_vertex = TT__ALLOC(vox->allocator, int, points), *indices = NULL, nquads = 0, nverts = 0, c, side;
    float *positions = NULL;
    tt_mesh_desc desc;
    tt_result result = TT_OK;
    size_t p;
    if (!point_vertex) goto out_of_memory;
    for (c = 0; c < vox->count; c++)
        for (side = 0; side < 6 && vox->occupied[c]; side++) {
            int neighbour = c + (side % 2 ? -step[side / 2] : step[side / 2]);
            nquads += !vox->occupied[neighbour];   /* the padding keeps neighbours inside the grid */
        }
    indices = TT__ALLOC(vox->allocator, int, (size_t)nquads * 4);
    pc->quad_cube = TT__ALLOC(vox->allocator, int, nquads);
    pc->quad_side = TT__ALLOC(vox->allocator, unsigned char, nquads);
    /* At most 4 new lattice points per quad. */
    positions = TT__ALLOC(vox->allocator, float, (size_t)nquads * 12);
    pc->vertex_lattice = TT__ALLOC(vox->allocator, int, (size_t)nquads * 4);
    if (!indices || !pc->quad_cube || !pc->quad_side || !positions || !pc->vertex_lattice) goto out_of_memory;
    for (p = 0; p < points; p++) point_vertex[p] = -1;
    nquads = 0;
    for (c = 0; c < vox->count; c++)
        for (side = 0; side < 6 && vox->occupied[c]; side++) {
            int neighbour = c + (side % 2 ? -step[side / 2] : step[side / 2]), corner[4][3], k, rest = c, x, y;
            if (vox->occupied[neighbour]) continue;
            x = rest % vox->dims[0]; rest /= vox->dims[0];
            y = rest % vox->dims[1];
            tt__polycube_quad_corners(x, y, rest / vox->dims[1], side, up_axis, up_sign, corner);
            for (k = 0; k < 4; k++) {
                int point = corner[k][0] + lattice[0] * (corner[k][1] + lattice[1] * corner[k][2]), a;
                if (point_vertex[point] < 0) {
                    for (a = 0; a < 3; a++) positions[3 * nverts + a] = (float)(vox->origin[a] + vox->h * corner[k][a]);
                    pc->vertex_lattice[nverts] = point;
                    point_vertex[point] = nverts++;
                }
                indices[4 * nquads + k] = point_vertex[point];
            }
            pc->quad_cube[nquads] = c;
            pc->quad_side[nquads++] = (unsigned char)side;
        }
    memset(&desc, 0, sizeof desc);
    desc.positions = positions;
    desc.nverts = nverts;
    desc.indices = indices;
    desc.nfaces = nquads;
    desc.fixed_face_size = 4;
    result = tt_mesh_build(&desc, vox->allocator, &pc->surface, error);
    goto done;
out_of_memory:
    result = tt__fail(error, TT_ERROR_OUT_OF_MEMORY, -1, -1, -1, -1, "out of memory extracting the polycube surface");
done:
    tt__free(vox->allocator, point_vertex);
    tt__free(vox->allocator, indices);
    tt__free(vox->allocator, positions);
    return result;
}

/* Options checked, and the grid of spec P2 laid out over the mesh's
   bounding box (see the doc comment). */
static tt_result tt__polycube_grid(const tt_mesh *mesh, const tt_polycube_options *options, tt__voxels *vox,
                                   int *resolution, tt_error *error)
{
    double lo[3] = {0.0, 0.0, 0.0}, hi[3] = {0.0, 0.0, 0.0}, longest = 0.0, cells = 1.0;
    int v, a, used = 0, n = options->resolution ? options->resolution : TT_POLYCUBE_DEFAULT_RESOLUTION;
    for (v = 0; v < mesh->nverts; v++) {
        const float *p = mesh->pos + 3 * v;
        if (mesh->vert_corner[v] < 0) continue;
        for (a = 0; a < 3; a++) {
            if (!tt__is_finite(p[a]))
                return tt__fail(error, TT_ERROR_NON_FINITE, -1, -1, v, -1, "vertex %d has a coordinate %g", v,
                                (double)p[a]);
            if (!used || p[a] < lo[a]) lo[a] = p[a];
            if (!used || p[a] > hi[a]) hi[a] = p[a];
        }
        used = 1;
    }
    for (a = 0; a < 3; a++)
        if (used && hi[a] - lo[a] > longest) longest = hi[a] - lo[a];
    if (!(longest > 0.0))
        return tt__fail(error, TT_ERROR_ZERO_AREA_FACE, -1, -1, -1, -1,
                        "all the mesh's vertices are at one point: there is no surface to voxelise");
    vox->h = options->cube_size > 0.0 ? options->cube_size : longest / n;
    vox->tie = tt__polycube_tie(mesh, vox->h);
    for (a = 0; a < 3; a++) {
        /* ceil with the tie rule's tolerance, so extent / h = N up to rounding gives N (the faces on
           the core's border then still fall inside it, moved by the tie rule) */
        double cubes = ceil((hi[a] - lo[a] - vox->tie) / vox->h);
        if (cubes < 1.0) cubes = 1.0;
        if (!(cubes <= TT_POLYCUBE_MAX_RESOLUTION))
            return tt__fail(error, TT_ERROR_TOO_LARGE, -1, -1, -1, -1,
                            "a cube size of %g makes %g cubes along axis %d, above the limit of %d", vox->h, cubes, a,
                            TT_POLYCUBE_MAX_RESOLUTION);
        if ((int)cubes > *resolution) *resolution = (int)cubes;
        vox->dims[a] = (int)cubes + 4;
        vox->origin[a] = 0.5 * (lo[a] + hi[a]) - vox->h * (0.5 * cubes + 2.0);
        cells *= vox->dims[a];
    }
    if (cells > TT_POLYCUBE_MAX_CUBES)
        return tt__fail(error, TT_ERROR_TOO_LARGE, -1, -1, -1, -1,
                        "the grid of %d x %d x %d cubes (padding included) exceeds the limit of %d cubes",
                        vox->dims[0], vox->dims[1], vox->dims[2], TT_POLYCUBE_MAX_CUBES);
    vox->count = (int)cells;
    return TT_OK;
}

static tt_result tt__polycube_check_options(const tt_polycube_options *o, tt_error *error)
{
    int a;
    if (o->flags & ~(unsigned)TT_POLYCUBE_NO_CORRECT)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1, "unknown polycube flags 0x%x", o->flags);
    if (o->resolution < 0)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "resolution must be 1..%d (0: %d), got %d", TT_POLYCUBE_MAX_RESOLUTION,
                        TT_POLYCUBE_DEFAULT_RESOLUTION, o->resolution);
    if (o->resolution > TT_POLYCUBE_MAX_RESOLUTION)
        return tt__fail(error, TT_ERROR_TOO_LARGE, -1, -1, -1, -1, "resolution %d is above the limit of %d",
                        o->resolution, TT_POLYCUBE_MAX_RESOLUTION);
    if (!tt__is_finite_d(o->cube_size))
        return tt__fail(error, TT_ERROR_NON_FINITE, -1, -1, -1, -1, "cube_size is %g", o->cube_size);
    if (o->cube_size < 0.0)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "cube_size must be above 0 (or 0: use the resolution), got %g", o->cube_size);
    for (a = 0; a < 3; a++)
        if (!tt__is_finite_d(o->up[a]))
            return tt__fail(error, TT_ERROR_NON_FINITE, -1, -1, -1, -1, "up[%d] is %g", a, o->up[a]);
    return TT_OK;
}

/* The surface's topology into the report, and the input's genus when it is
   defined (every component closed and manifold). */
static tt_result tt__polycube_genus(const tt_mesh *mesh, const tt_polycube *pc, const tt_allocator *allocator,
                                    tt_polycube_report *report, tt_error *error)
{
    tt_mesh_stats stats;
    tt_result result = tt_mesh_compute_stats(pc->surface, allocator, &stats, error);
    if (result != TT_OK) return result;
    report->components = stats.components;
    report->polycube_genus = stats.genus;
    result = tt_mesh_compute_stats(mesh, allocator, &stats, error);
    if (result != TT_OK) return result;
    report->mesh_genus = stats.boundary_edges == 0 && stats.nonmanifold_vertices == 0 ? stats.genus : -1;
    report->genus_differs = report->mesh_genus >= 0 && report->mesh_genus != report->polycube_genus;
    if (report->mesh_genus >= 0) {
        /* the signed volume of a closed mesh, by the divergence theorem over
           its faces' fans: negative when the faces wind inward */
        double volume = 0;
        int f, k;
        for (f = 0; f < mesh->nfaces; f++) {
            const float *p0 = mesh->pos + 3 * (size_t)mesh->corner_vert[mesh->face_start[f]];
            for (k = mesh->face_start[f] + 1; k + 1 < mesh->face_start[f + 1]; k++) {
                const float *p1 = mesh->pos + 3 * (size_t)mesh->corner_vert[k];
                const float *p2 = mesh->pos + 3 * (size_t)mesh->corner_vert[k + 1];
                double a[3], b[3], cr[3];
                tt__sub3f(p1, p0, a);
                tt__sub3f(p2, p0, b);
                tt__cross3(a, b, cr);
                /* (p0 - c) . ((p1 - p0) x (p2 - p0)) is 6 x the signed volume of
                   the tetrahedron (c, p0, p1, p2), c the first vertex; they add
                   up to the enclosed volume */
                volume += (p0[0] - mesh->pos[0]) * cr[0] + (p0[1] - mesh->pos[1]) * cr[1] +
                          (p0[2] - mesh->pos[2]) * cr[2];
            }
        }
        report->inside_out = volume < 0;
    }
    return TT_OK;
}

TTDEF tt_result tt_polycube_build(const tt_mesh *mesh, const tt_polycube_options *options,
                                  const tt_allocator *allocator, tt_polycube **out, tt_polycube_report *report,
                                  tt_error *error)
{
    tt_polycube_options defaults;
    tt_polycube_report local;
    tt__voxels vox;
    tt_polycube *pc = NULL;
    tt_result result = tt__ok(error);
    int up_axis = 1, up_sign = 1, a, c;
    if (!out) return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1, "out is NULL");
    *out = NULL;
    if (!report) report = &local;
    memset(report, 0, sizeof *report);
    if (!mesh) return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1, "the mesh is NULL");
    if (tt__check_allocator(allocator, error) != TT_OK) return TT_ERROR_INVALID_ARGUMENT;
    if (!options) {
        memset(&defaults, 0, sizeof defaults);
        options = &defaults;
    }
    if ((result = tt__polycube_check_options(options, error)) != TT_OK) return result;
    if (mesh->nfaces <= 0) return tt__fail(error, TT_ERROR_EMPTY_MESH, -1, -1, -1, -1, "the mesh has no faces");
    for (a = 0; a < 3; a++)
        if (fabs(options->up[a]) > fabs(options->up[up_axis]) ||
            (a < up_axis && fabs(options->up[a]) == fabs(options->up[up_axis]) && options->up[a] != 0.0))
            up_axis = a;
    if (options->up[up_axis] < 0.0) up_sign = -1;

    memset(&vox, 0, sizeof vox);
    vox.allocator = allocator;
    if ((result = tt__polycube_grid(mesh, options, &vox, &report->resolution, error)) != TT_OK) return result;
    pc = TT__ALLOC(allocator, tt_polycube, 1);
    vox.occupied = TT__ALLOC(allocator, unsigned char, vox.count);
    vox.hit = TT__ALLOC(allocator, unsigned char, vox.count);
    vox.cell_hit = TT__ALLOC(allocator, unsigned char, (size_t)(vox.dims[0] + 1) * (vox.dims[1] + 1) * (vox.dims[2] + 1));
    vox.queue = TT__ALLOC(allocator, int, vox.count);
    if (pc) {
        memset(pc, 0, sizeof *pc);
        pc->allocator = tt__allocator_copy(allocator);
    }
    if (!pc || !vox.occupied || !vox.hit || !vox.cell_hit || !vox.queue) {
        result = tt__fail(error, TT_ERROR_OUT_OF_MEMORY, -1, -1, -1, -1, "out of memory building the polycube");
        goto done;
    }
    pc->up_axis = up_axis;
    pc->up_sign = up_sign;

    /* Sec. 3.1 / spec P1-P3: the cubes the surface meets. */
    memset(vox.hit, 0, (size_t)vox.count);
    report->zero_area_triangles = tt__polycube_voxelize(mesh, vox.origin, vox.h, vox.dims, vox.tie, vox.hit);
    for (c = 0; c < vox.count && !vox.hit[c]; c++) {}
    if (c == vox.count) {
        result = tt__fail(error, TT_ERROR_ZERO_AREA_FACE, -1, -1, -1, -1,
                          "every face of the mesh has zero area: there is no surface to voxelise");
        goto done;
    }
    memcpy(vox.occupied, vox.hit, (size_t)vox.count);
    /* Spec P4, P6: filled, made manifold, filled again. */
    report->filled = tt__polycube_fill(&vox);
    if ((report->sealed = tt__polycube_seal(&vox, mesh, 1 + (report->resolution - 1) / TT__POLYCUBE_SEAL_CUBES)) < 0) {
        result = tt__fail(error, TT_ERROR_OUT_OF_MEMORY, -1, -1, -1, -1, "out of memory building the polycube");
        goto done;
    }
    report->filled += report->sealed;
    if ((result = tt__polycube_repair(&vox, &report->repaired, error)) != TT_OK) goto done;
    report->filled += tt__polycube_fill(&vox);
    /* Spec P5: the correction needs the unit cells centred on the lattice points that the model meets. */
    if (!(options->flags & TT_POLYCUBE_NO_CORRECT)) {
        double cell_origin[3];
        int cell_dims[3];
        for (a = 0; a < 3; a++) {
            cell_origin[a] = vox.origin[a] - 0.5 * vox.h;
            cell_dims[a] = vox.dims[a] + 1;
        }
        memset(vox.cell_hit, 0, (size_t)cell_dims[0] * cell_dims[1] * cell_dims[2]);
        tt__polycube_voxelize(mesh, cell_origin, vox.h, cell_dims, vox.tie, vox.cell_hit);
        if ((result = tt__polycube_correct(&vox, report, error)) != TT_OK) goto done;
    }
    /* Spec P8, P9: S. */
    if ((result = tt__polycube_extract(&vox, up_axis, up_sign, pc, error)) != TT_OK) goto done;
    if ((result = tt__polycube_genus(mesh, pc, allocator, report, error)) != TT_OK) goto done;
    for (a = 0; a < 3; a++) {
        pc->dims[a] = report->dims[a] = vox.dims[a];
        pc->origin[a] = vox.origin[a];
    }
    pc->h = report->cube_size = vox.h;
    for (c = 0; c < vox.count; c++) report->cubes += vox.occupied[c];
    report->quads = pc->surface->nfaces;
    pc->occupied = vox.occupied;
    vox.occupied = NULL;
done:
    tt__free(allocator, vox.occupied);
    tt__free(allocator, vox.hit);
    tt__free(allocator, vox.cell_hit);
    tt__free(allocator, vox.queue);
    if (result != TT_OK) {
        tt_polycube_free(pc);
        memset(report, 0, sizeof *report);
        return result;
    }
    *out = pc;
    return TT_OK;
}

TTDEF tt_result tt_polycube_edge_colors(const tt_polycube *polycube, int colors, int axis_palettes, uint64_t seed,
                                        int *edge_colors, tt_error *error)
{
    const tt_mesh *s;
    tt_rng rng;
    int palette[3][2], palette_size = 1, a, c;
    tt__ok(error);
    if (!polycube || !polycube->surface || !edge_colors)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "tt_polycube_edge_colors needs a polycube and edge_colors (got NULL)");
    if (colors < 1 || colors > TT_MAX_COLORS)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1, "colors must be 1..%d, got %d",
                        TT_MAX_COLORS, colors);
    s = polycube->surface;
    tt_rng_seed(&rng, seed, 0x706f6c79ull /* "poly" */);
    for (a = 0; a < 3; a++) {
        /* The paper's random 2 of the samples per axis group: the first drawn from all, the second
           from the others. */
        palette[a][0] = (int)tt_rng_below(&rng, (uint32_t)colors);
        palette[a][1] = colors > 1 ? (palette[a][0] + 1 + (int)tt_rng_below(&rng, (uint32_t)colors - 1)) % colors
                                   : palette[a][0];
    }
    if (axis_palettes && colors > 1) palette_size = 2;
    /* Edges in order of their first half-edge, as tt_assign_boundaries visits them. */
    for (c = 0; c < s->ncorners; c++) {
        int t = s->twin[c], k, from = polycube->vertex_lattice[s->corner_vert[c]];
        int to = polycube->vertex_lattice[s->corner_vert[tt_mesh_next(s, c)]], step = tt__abs_i(to - from);
        if (t >= 0 && t < c) continue;
        /* Lattice neighbours differ by 1 along x, dims[0] + 1 along y, more along z. */
        a = step == 1 ? 0 : (step == polycube->dims[0] + 1 ? 1 : 2);
        if (axis_palettes) k = palette[a][palette_size > 1 ? (int)tt_rng_below(&rng, 2u) : 0];
        else k = (int)tt_rng_below(&rng, (uint32_t)colors);
        edge_colors[c] = k;
        if (t >= 0) edge_colors[t] = k;
    }
    return TT_OK;
}

/* ---- Projection of the model's vertices onto S (Sec. 4; spec P11 step 2) ----
   Everything runs in lattice coordinates g = (p - origin) / h, where cube
   (i, j, k) is [i, i+1] x [j, j+1] x [k, k+1] and distances are in units
   of h. A facelet is named by its cube's linear index and its side
   (0..5 = +x, -x, +y, -y, +z, -z); S's quads are stored in that order
   (tt__polycube_extract), so (cube, side) order is quad index order and a
   quad is found by binary search in quad_cube: no lookup table to build. */

/* A candidate point of S: on facelet (cube, side), at `point`, `distance`
   from the vertex, with `agreement` = n_f . n_v. */
typedef struct tt__facelet_hit {
    int found;
    int cube, side;
    double point[3];
    double distance;
    double agreement;
} tt__facelet_hit;

/* n_f . n_v for a facelet on `side`; a vertex without a normal faces every
   side (reported as agreement 1). */
static double tt__polycube_agreement(int side, const double normal[3])
{
    if (normal[0] == 0.0 && normal[1] == 0.0 && normal[2] == 0.0) return 1.0;
    return side % 2 ? -normal[side / 2] : normal[side / 2];
}

/* The projection field at lattice point (i, j, k) for a vertex with this
   normal: the sum of the outward normals of the point's facelets that face
   the vertex's side, from the 8-cube mask. The cube of bit b lies below
   the point along axis a when bit a of b is 0, so its face through the
   point looks along +a; that face is a facelet when the cube across it
   (bit a flipped) is empty. */
static void tt__polycube_field_at(const tt__voxels *grid, int i, int j, int k, const double normal[3], double d[3])
{
    int mask = tt__polycube_mask(grid, i, j, k), bit, a;
    d[0] = d[1] = d[2] = 0.0;
    for (bit = 0; bit < 8; bit++) {
        if (!((mask >> bit) & 1)) continue;
        for (a = 0; a < 3; a++) {
            int below = !((bit >> a) & 1);
            if ((mask >> (bit ^ (1 << a))) & 1) continue;
            if (tt__polycube_agreement(2 * a + !below, normal) > 0.0) d[a] += below ? 1.0 : -1.0;
        }
    }
}

/* The field for a vertex with this normal, interpolated trilinearly at g
   (spec P11 step 1): continuous in g, and exactly the lattice values at
   lattice points. Zero outside the lattice. Not normalised. */
static void tt__polycube_field(const tt__voxels *grid, const double g[3], const double normal[3], double d[3])
{
    int base[3], corner, a;
    double f[3];
    d[0] = d[1] = d[2] = 0.0;
    for (a = 0; a < 3; a++) {
        if (!(g[a] >= 0.0 && g[a] <= grid->dims[a])) return;
        base[a] = tt__min_i((int)floor(g[a]), grid->dims[a] - 1);
        f[a] = g[a] - base[a];
    }
    for (corner = 0; corner < 8; corner++) {
        double weight = 1.0, at[3];
        for (a = 0; a < 3; a++) weight *= (corner >> a) & 1 ? f[a] : 1.0 - f[a];
        if (weight == 0.0) continue;
        tt__polycube_field_at(grid, base[0] + (corner & 1), base[1] + ((corner >> 1) & 1), base[2] + (corner >> 2),
                              normal, at);
        for (a = 0; a < 3; a++) d[a] += weight * at[a];
    }
}

/* Is candidate a better than b? Nearer; at equal distance the one facing
   v's side better; then the smaller (cube, side), i.e. the smaller quad
   index. */
static int tt__polycube_better(const tt__facelet_hit *a, const tt__facelet_hit *b)
{
    if (!b->found) return 1;
    if (a->distance != b->distance) return a->distance < b->distance;
    if (a->agreement != b->agreement) return a->agreement > b->agreement;
    if (a->cube != b->cube) return a->cube < b->cube;
    return a->side < b->side;
}

/* Among facelets that all contain the vertex (on a quad's edge or corner):
   is a better than b? The one facing v's side better, then the smaller
   quad index. */
static int tt__polycube_faces_better(const tt__facelet_hit *a, const tt__facelet_hit *b)
{
    if (!b->found) return 1;
    if (a->agreement != b->agreement) return a->agreement > b->agreement;
    if (a->cube != b->cube) return a->cube < b->cube;
    return a->side < b->side;
}

/* A ray from g along the unit vector dir, at most `limit` long, through the
   cubes by a 3D DDA (the next lattice plane crossed is the nearest of the
   three; ties cross the lowest axis first). S is where the ray passes
   between an occupied cube and an empty one; the facelet belongs to the
   occupied cube and looks toward the empty one. The first facelet facing
   the vertex's side goes into *hit. The padding keeps S away from the
   grid's border, so leaving the grid ends the search. */
static void tt__polycube_ray(const tt__voxels *grid, const double g[3], const double dir[3], const double normal[3],
                             double limit, tt__facelet_hit *hit)
{
    int cell[3], step[3], a, b;
    double next[3], delta[3];
    hit->found = 0;
    for (a = 0; a < 3; a++) {
        if (!(g[a] >= 0.0 && g[a] < grid->dims[a])) return;
        cell[a] = (int)floor(g[a]);
        step[a] = dir[a] > 0.0 ? 1 : (dir[a] < 0.0 ? -1 : 0);
        delta[a] = step[a] ? 1.0 / fabs(dir[a]) : HUGE_VAL;
        next[a] = step[a] > 0 ? (cell[a] + 1 - g[a]) * delta[a] : (step[a] < 0 ? (g[a] - cell[a]) * delta[a] : HUGE_VAL);
    }
    for (;;) {
        int from = cell[0] + grid->dims[0] * (cell[1] + grid->dims[1] * cell[2]), to, cube, side;
        double t;
        a = 0;
        if (next[1] < next[a]) a = 1;
        if (next[2] < next[a]) a = 2;
        t = next[a];
        if (t > limit) return;
        cell[a] += step[a];
        if (cell[a] < 0 || cell[a] >= grid->dims[a]) return;
        to = cell[0] + grid->dims[0] * (cell[1] + grid->dims[1] * cell[2]);
        next[a] += delta[a];
        if (grid->occupied[from] == grid->occupied[to]) continue;
        /* The facelet's normal points from the occupied cube into the empty one. */
        cube = grid->occupied[from] ? from : to;
        side = 2 * a + ((grid->occupied[from] ? step[a] : -step[a]) < 0);
        if (!(tt__polycube_agreement(side, normal) > 0.0)) continue;
        hit->found = 1;
        hit->cube = cube;
        hit->side = side;
        hit->distance = t;
        hit->agreement = tt__polycube_agreement(side, normal);
        for (b = 0; b < 3; b++) hit->point[b] = g[b] + t * dir[b];
        /* on the lattice plane exactly: the plane between the two cubes */
        hit->point[a] = step[a] > 0 ? cell[a] : cell[a] + 1;
        return;
    }
}

/* The closest point to g of the face on `side` of cube (x, y, z). */
static double tt__polycube_facelet_closest(const int cube[3], int side, const double g[3], double point[3])
{
    int a;
    double d[3];
    for (a = 0; a < 3; a++) {
        if (a == side / 2) point[a] = cube[a] + (side % 2 ? 0 : 1);
        else point[a] = g[a] < cube[a] ? cube[a] : (g[a] > cube[a] + 1 ? cube[a] + 1 : g[a]);
        d[a] = g[a] - point[a];
    }
    return tt__length3(d);
}

/* The facelets of the occupied cubes at Chebyshev distance `ring` from cube
   `center` (within the grid) as candidates: into *any (every facelet), into
   *facing (those facing the vertex's side) and into *touching (those
   facing its side closer than `touch`, the best facing first: on a quad's
   edge or corner several are). */
static void tt__polycube_scan_ring(const tt__voxels *grid, const int center[3], int ring, const double g[3],
                                   const double normal[3], double touch, tt__facelet_hit *any,
                                   tt__facelet_hit *facing, tt__facelet_hit *touching)
{
    int lo[3], hi[3], a, x, y, z, side;
    for (a = 0; a < 3; a++) {
        lo[a] = tt__max_i(center[a] - ring, 0);
        hi[a] = tt__min_i(center[a] + ring, grid->dims[a] - 1);
    }
    for (z = lo[2]; z <= hi[2]; z++)
        for (y = lo[1]; y <= hi[1]; y++) {
            /* Inside the shell's two faces along z and y only the two ends of each row are on it. */
            int whole_row = tt__abs_i(z - center[2]) == ring || tt__abs_i(y - center[1]) == ring;
            int x_step = whole_row || ring == 0 ? 1 : 2 * ring;
            for (x = whole_row ? lo[0] : center[0] - ring; x <= hi[0]; x += x_step) {
                int cube[3], index = x + grid->dims[0] * (y + grid->dims[1] * z);
                if (x < lo[0] || !grid->occupied[index]) continue;
                cube[0] = x; cube[1] = y; cube[2] = z;
                for (side = 0; side < 6; side++) {
                    int neighbour[3];
                    tt__facelet_hit candidate;
                    neighbour[0] = x; neighbour[1] = y; neighbour[2] = z;
                    neighbour[side / 2] += side % 2 ? -1 : 1;
                    if (neighbour[side / 2] >= 0 && neighbour[side / 2] < grid->dims[side / 2] &&
                        grid->occupied[neighbour[0] + grid->dims[0] * (neighbour[1] + grid->dims[1] * neighbour[2])])
                        continue;
                    candidate.found = 1;
                    candidate.cube = index;
                    candidate.side = side;
                    candidate.distance = tt__polycube_facelet_closest(cube, side, g, candidate.point);
                    candidate.agreement = tt__polycube_agreement(side, normal);
                    if (tt__polycube_better(&candidate, any)) *any = candidate;
                    if (candidate.agreement > 0.0 && tt__polycube_better(&candidate, facing)) *facing = candidate;
                    if (touching && candidate.distance < touch && candidate.agreement > 0.0 &&
                    tt__polycube_faces_better(&candidate, touching))
                        *touching = candidate;
                }
            }
        }
}

/* The cube nearest to g (g's own cube when inside the grid). */
static void tt__polycube_center(const tt__voxels *grid, const double g[3], int center[3])
{
    int a;
    for (a = 0; a < 3; a++) {
        double c = floor(g[a]);
        center[a] = c < 0.0 ? 0 : (c > grid->dims[a] - 1 ? grid->dims[a] - 1 : (int)c);
    }
}

/* The closest point of S among the facelets facing the vertex's side, if
   one lies within `reach`; else the plain closest point (*is_fallback
   set). Shells of cubes around g's cube, ring by ring: every cube of ring
   r + 1 is at least r away from g (g lies in the centre cube or, outside
   the grid, beyond the border the centre cube is on), so a candidate no
   farther than r is final once ring r is done. */
static tt__facelet_hit tt__polycube_nearest(const tt__voxels *grid, const double g[3], const double normal[3],
                                            double reach, int *is_fallback)
{
    tt__facelet_hit any, facing;
    int center[3], ring, last = 0, a;
    memset(&any, 0, sizeof any);
    memset(&facing, 0, sizeof facing);
    tt__polycube_center(grid, g, center);
    for (a = 0; a < 3; a++) last = tt__max_i(last, tt__max_i(center[a], grid->dims[a] - 1 - center[a]));
    *is_fallback = 0;
    for (ring = 0; ring <= last; ring++) {
        tt__polycube_scan_ring(grid, center, ring, g, normal, 0.0, &any, &facing, NULL);
        if (facing.found && facing.distance <= ring && facing.distance <= reach) return facing;
        if (ring >= reach && any.found && any.distance <= ring) break;
    }
    if (facing.found && facing.distance <= reach) return facing;
    *is_fallback = 1;
    return any;
}

/* The quad of facelet (cube, side): S's quads are sorted by cube, then
   side (checked by tt_polycube_project). -1 if there is none. */
static int tt__polycube_find_quad(const tt_polycube *pc, int cube, int side)
{
    int lo = 0, hi = pc->surface->nfaces;
    while (lo < hi) {
        int mid = lo + (hi - lo) / 2;
        if (pc->quad_cube[mid] < cube || (pc->quad_cube[mid] == cube && pc->quad_side[mid] < side)) lo = mid + 1;
        else hi = mid;
    }
    return lo < pc->surface->nfaces && pc->quad_cube[lo] == cube && pc->quad_side[lo] == side ? lo : -1;
}

/* A quad's corner 0 and its unit axes u (corner 0 -> 1) and v (0 -> 3), in
   lattice coordinates. */
static void tt__polycube_quad_frame(const tt_polycube *pc, int quad, int origin[3], int u[3], int v[3])
{
    const tt_mesh *s = pc->surface;
    int corner, k, a, at[3][3];
    const int order[3] = {0, 1, 3};
    for (k = 0; k < 3; k++) {
        int point;
        corner = s->face_start[quad] + order[k];
        point = pc->vertex_lattice[s->corner_vert[corner]];
        at[k][0] = point % (pc->dims[0] + 1);
        point /= pc->dims[0] + 1;
        at[k][1] = point % (pc->dims[1] + 1);
        at[k][2] = point / (pc->dims[1] + 1);
    }
    for (a = 0; a < 3; a++) {
        origin[a] = at[0][a];
        u[a] = at[1][a] - at[0][a];
        v[a] = at[2][a] - at[0][a];
    }
}

/* The surface point of a candidate. */
static tt_surface_point tt__polycube_surface_point(const tt_polycube *pc, int quad, const double point[3])
{
    tt_surface_point q;
    int origin[3], u[3], v[3], a;
    double s = 0.0, t = 0.0;
    tt__polycube_quad_frame(pc, quad, origin, u, v);
    for (a = 0; a < 3; a++) {
        s += (point[a] - origin[a]) * u[a];
        t += (point[a] - origin[a]) * v[a];
    }
    q.quad = quad;
    q.s = (float)(s < 0.0 ? 0.0 : (s > 1.0 ? 1.0 : s));
    q.t = (float)(t < 0.0 ? 0.0 : (t > 1.0 ? 1.0 : t));
    return q;
}

TTDEF void tt_polycube_point_position(const tt_polycube *polycube, tt_surface_point p, double xyz[3])
{
    int origin[3], u[3], v[3], a;
    TT_ASSERT(polycube && polycube->surface && xyz && p.quad >= 0 && p.quad < polycube->surface->nfaces);
    tt__polycube_quad_frame(polycube, p.quad, origin, u, v);
    for (a = 0; a < 3; a++)
        xyz[a] = polycube->origin[a] + polycube->h * (origin[a] + (double)p.s * u[a] + (double)p.t * v[a]);
}

/* Is the cube across side `side` of cube c empty (or outside the grid)? */
static int tt__polycube_neighbour_empty(const tt_polycube *pc, int c, int side)
{
    int at[3], a = side / 2;
    at[0] = c % pc->dims[0];
    at[1] = (c / pc->dims[0]) % pc->dims[1];
    at[2] = c / (pc->dims[0] * pc->dims[1]);
    at[a] += side % 2 ? -1 : 1;
    if (at[a] < 0 || at[a] >= pc->dims[a]) return 1;
    return !pc->occupied[at[0] + pc->dims[0] * (at[1] + pc->dims[1] * at[2])];
}

/* Does the polycube hold together: a surface of quads, sorted by (cube,
   side) without repeats, each on an exposed face of an occupied cube, and
   as many as there are exposed faces (so every exposed face has its
   quad)? O(cubes). */
static int tt__polycube_consistent(const tt_polycube *pc)
{
    int q, count, c, side, exposed = 0;
    if (!pc->surface || !pc->occupied || !pc->quad_cube || !pc->quad_side || !pc->vertex_lattice ||
        pc->surface->nfaces <= 0 || pc->dims[0] <= 0 || pc->dims[1] <= 0 || pc->dims[2] <= 0 || !(pc->h > 0.0))
        return 0;
    count = pc->dims[0] * pc->dims[1] * pc->dims[2];
    for (c = 0; c < count; c++)
        for (side = 0; side < 6 && pc->occupied[c]; side++)
            exposed += tt__polycube_neighbour_empty(pc, c, side);
    if (exposed != pc->surface->nfaces) return 0;
    for (q = 0; q < pc->surface->nfaces; q++) {
        if (pc->quad_cube[q] < 0 || pc->quad_cube[q] >= count || pc->quad_side[q] > 5 ||
            !pc->occupied[pc->quad_cube[q]] || !tt__polycube_neighbour_empty(pc, pc->quad_cube[q], pc->quad_side[q]) ||
            pc->surface->face_start[q + 1] - pc->surface->face_start[q] != 4)
            return 0;
        if (q > 0 && (pc->quad_cube[q] < pc->quad_cube[q - 1] ||
                      (pc->quad_cube[q] == pc->quad_cube[q - 1] && pc->quad_side[q] <= pc->quad_side[q - 1])))
            return 0;
    }
    return 1;
}

TTDEF tt_result tt_polycube_project(const tt_polycube *polycube, const tt_mesh *mesh, const tt_allocator *allocator,
                                    tt_surface_point *points, tt_polycube_projection_report *report,
                                    tt_error *error)
{
    /* Spec P11 step 2: the rays' reach, and "on S" */
    const double ray_reach = 3.0, on_surface = 1e-9;
    tt_polycube_projection_report local;
    tt__voxels grid;
    double *normals, distance_sum = 0.0;
    int v, f, a;
    tt__ok(error);
    if (!report) report = &local;
    memset(report, 0, sizeof *report);
    if (!polycube || !mesh || !points)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "tt_polycube_project needs a polycube, a mesh and points (got NULL)");
    if (tt__check_allocator(allocator, error) != TT_OK) return TT_ERROR_INVALID_ARGUMENT;
    if (mesh->nfaces <= 0) return tt__fail(error, TT_ERROR_EMPTY_MESH, -1, -1, -1, -1, "the mesh has no faces");
    if (!tt__polycube_consistent(polycube))
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "the polycube's surface has no quads or does not match its cubes: make it with "
                        "tt_polycube_build and leave it unchanged");
    for (v = 0; v < mesh->nverts; v++)
        for (a = 0; a < 3; a++)
            if (!tt__is_finite(mesh->pos[3 * v + a]))
                return tt__fail(error, TT_ERROR_NON_FINITE, -1, -1, v, -1, "vertex %d has a coordinate %g", v,
                                (double)mesh->pos[3 * v + a]);
    normals = TT__ALLOC(allocator, double, (size_t)mesh->nverts * 3);
    if (!normals)
        return tt__fail(error, TT_ERROR_OUT_OF_MEMORY, -1, -1, -1, -1, "out of memory projecting onto the polycube");

    /* n_v: the sum of the Newell vectors (twice the area times the normal) of the faces around v. */
    memset(normals, 0, sizeof(double) * 3 * (size_t)mesh->nverts);
    for (f = 0; f < mesh->nfaces; f++) {
        int begin = mesh->face_start[f], count = mesh->face_start[f + 1] - begin, c;
        double n[3], scale;
        tt__polygon_newell(mesh->pos, mesh->corner_vert + begin, count, n, &scale);
        for (c = begin; c < begin + count; c++)
            for (a = 0; a < 3; a++) normals[3 * mesh->corner_vert[c] + a] += n[a];
    }

    memset(&grid, 0, sizeof grid);
    for (a = 0; a < 3; a++) grid.dims[a] = polycube->dims[a];
    grid.count = grid.dims[0] * grid.dims[1] * grid.dims[2];
    grid.occupied = polycube->occupied;

    for (v = 0; v < mesh->nverts; v++) {
        double g[3], normal[3], d[3], *n = normals + 3 * v, gap[3];
        tt__facelet_hit chosen, along, against, any, facing, touching;
        int near_plane = 0, quad;
        for (a = 0; a < 3; a++) {
            g[a] = ((double)mesh->pos[3 * v + a] - polycube->origin[a]) / polycube->h;
            near_plane |= fabs(g[a] - floor(g[a] + 0.5)) < on_surface;
            normal[a] = n[a];
        }
        tt__normalize3(normal);
        chosen.found = 0;
        /* On S already: a point within 1e-9 h of a facelet is within 1e-9 h of a lattice plane, and the
           facelet's cube is at most one ring from g's. Only facelets facing v's side count, as for the
           rays: the rim of an open sheet lying on the side face of its slab goes to the slab's top. */
        if (near_plane) {
            int center[3], ring;
            any.found = facing.found = touching.found = 0;
            tt__polycube_center(&grid, g, center);
            for (ring = 0; ring <= 1; ring++)
                tt__polycube_scan_ring(&grid, center, ring, g, normal, on_surface, &any, &facing, &touching);
            if (touching.found) {
                chosen = touching;
                report->on_surface++;
            }
        }
        if (!chosen.found) {
            /* The rays along the field, or along n_v where the field vanishes. */
            tt__polycube_field(&grid, g, normal, d);
            if (tt__normalize3(d) < 1e-6)
                for (a = 0; a < 3; a++) d[a] = normal[a];
            along.found = against.found = 0;
            if (d[0] != 0.0 || d[1] != 0.0 || d[2] != 0.0) {
                tt__polycube_ray(&grid, g, d, normal, ray_reach, &along);
                for (a = 0; a < 3; a++) d[a] = -d[a];
                tt__polycube_ray(&grid, g, d, normal, ray_reach, &against);
            }
            if (along.found && (!against.found || along.distance <= against.distance)) chosen = along;
            else if (against.found) chosen = against;
            if (chosen.found) report->rays++;
        }
        if (!chosen.found) {
            int is_fallback;
            chosen = tt__polycube_nearest(&grid, g, normal, TT_POLYCUBE_PROJECT_SIDE_REACH, &is_fallback);
            if (is_fallback) report->fallbacks++;
            else report->nearest++;
        }
        quad = tt__polycube_find_quad(polycube, chosen.cube, chosen.side);
        TT_ASSERT(quad >= 0);   /* tt__polycube_consistent: every exposed face has its quad */
        points[v] = tt__polycube_surface_point(polycube, quad, chosen.point);
        for (a = 0; a < 3; a++) gap[a] = g[a] - chosen.point[a];
        chosen.distance = tt__length3(gap);
        distance_sum += chosen.distance;
        if (chosen.distance > report->max_distance) report->max_distance = chosen.distance;
    }
    report->mean_distance = mesh->nverts > 0 ? distance_sum / mesh->nverts : 0.0;
    tt__free(allocator, normals);
    return TT_OK;
}

/* ------------------------------------------------------------------------ */
/* Edge images on S (spec P11 step 3)                                       */
/* ------------------------------------------------------------------------ */

#define TT__EDGE_SNAP 1e-6              /* spec P11 step 4.5 */
#define TT__EDGE_EPS 1e-9               /* lengths in the unfolded plane, in units of h */
#define TT__EDGE_ANGLE_EPS 1e-9         /* the funnel's directions, radians */
#define TT__EDGE_SEARCH_BUDGET 200000   /* path steps per edge: a guard for large max_quads */
#define TT__EDGE_BEND_QUADS 6           /* paths of at most this many quads may bend at saddles */
#define TT__CORNER_QUADS 6              /* quads around a vertex of S: 3 to 6 */

/* Corner k (mod 4) of a quad in its own frame: (0,0), (1,0), (1,1), (0,1). */
static void tt__quad_corner_st(int k, int st[2])
{
    k &= 3;
    st[0] = k == 1 || k == 2;
    st[1] = k >= 2;
}

/* The corner of `quad` at S vertex `vertex`, or -1. */
static int tt__quad_corner_of(const tt_mesh *s, int quad, int vertex)
{
    int k;
    for (k = 0; k < 4; k++)
        if (s->corner_vert[s->face_start[quad] + k] == vertex) return k;
    return -1;
}

/* (x, y) turned by `turns` quarter turns counter-clockwise. */
static void tt__quarter_turns(int turns, double x, double y, double out[2])
{
    switch (turns & 3) {
    case 0: out[0] = x; out[1] = y; break;
    case 1: out[0] = -y; out[1] = x; break;
    case 2: out[0] = -x; out[1] = -y; break;
    default: out[0] = y; out[1] = -x; break;
    }
}

TTDEF void tt_quad_map_apply(tt_quad_map map, double s, double t, double out[2])
{
    TT_ASSERT(out && map.turns >= 0 && map.turns < 4);
    tt__quarter_turns(map.turns, s, t, out);
    out[0] += map.offset[0];
    out[1] += map.offset[1];
}

TTDEF tt_quad_map tt_quad_map_compose(tt_quad_map outer, tt_quad_map inner)
{
    tt_quad_map m;
    double shifted[2];
    TT_ASSERT(outer.turns >= 0 && outer.turns < 4 && inner.turns >= 0 && inner.turns < 4);
    tt_quad_map_apply(outer, inner.offset[0], inner.offset[1], shifted);
    m.turns = (outer.turns + inner.turns) & 3;
    m.offset[0] = (int)shifted[0];
    m.offset[1] = (int)shifted[1];
    return m;
}

TTDEF tt_quad_map tt_polycube_unfold(const tt_polycube *polycube, int halfedge)
{
    const tt_mesh *s;
    int twin, i, j, target[2], source[2];
    double turned[2];
    tt_quad_map m;
    TT_ASSERT(polycube && polycube->surface && halfedge >= 0 && halfedge < polycube->surface->ncorners);
    s = polycube->surface;
    twin = s->twin[halfedge];
    TT_ASSERT(twin >= 0);
    i = halfedge - s->face_start[s->corner_face[halfedge]];
    j = twin - s->face_start[s->corner_face[twin]];
    /* Half-edge k of a quad points along +s turned k quarter turns; the twin, turned into this frame, must
       point the opposite way: turns + j = i + 2. Then corner j of the far quad goes to corner i + 1 here. */
    m.turns = (i - j + 6) & 3;
    tt__quad_corner_st(i + 1, target);
    tt__quad_corner_st(j, source);
    tt__quarter_turns(m.turns, source[0], source[1], turned);
    m.offset[0] = target[0] - (int)turned[0];
    m.offset[1] = target[1] - (int)turned[1];
    return m;
}

static int tt__quad_map_equal(tt_quad_map a, tt_quad_map b)
{
    return a.turns == b.turns && a.offset[0] == b.offset[0] && a.offset[1] == b.offset[1];
}

/* The point of the chart `at` in the frame of the quad `map` places there. */
static void tt__quad_map_invert_point(tt_quad_map map, const double at[2], double st[2])
{
    tt__quarter_turns(4 - map.turns, at[0] - map.offset[0], at[1] - map.offset[1], st);
}

/* The search for one edge's path: the path grows from q_a's quad; every
   quad's frame is mapped into the plane of q_a's quad. */
typedef struct tt__edge_search {
    const tt_polycube *pc;
    double a[2];        /* q_a: in the plane, as its quad is the plane's frame */
    double b[2];        /* q_b in its own quad's frame */
    int quad_b, max_quads, steps;
    int quads[TT_POLYCUBE_EDGE_MAX_QUADS];
    int halfedges[TT_POLYCUBE_EDGE_MAX_QUADS];  /* halfedges[i] leaves quads[i] for quads[i + 1] */
    tt_quad_map maps[TT_POLYCUBE_EDGE_MAX_QUADS];
    int best_count;     /* quads of the best path so far; 0 = none */
    double best_length;
    tt_edge_crossing crossings[TT_POLYCUBE_EDGE_MAX_QUADS];        /* a path's, while it is judged */
    tt_edge_crossing best_crossings[TT_POLYCUBE_EDGE_MAX_QUADS];
} tt__edge_search;

/* The ends of half-edge h of S in the plane, through `map` (its quad's). */
static void tt__edge_in_plane(const tt_mesh *s, int h, tt_quad_map map, double e0[2], double e1[2])
{
    int k = h - s->face_start[s->corner_face[h]], st0[2], st1[2];
    tt__quad_corner_st(k, st0);
    tt__quad_corner_st(k + 1, st1);
    tt_quad_map_apply(map, st0[0], st0[1], e0);
    tt_quad_map_apply(map, st1[0], st1[1], e1);
}

/* One straight leg of a path in the plane, from p to q, crossing
   halfedges[first..last) (halfedges[i] leaves quad i, mapped into the plane
   by maps[i]); t runs from t0 at p to t1 at q. 0 when it does not cross
   exactly those edges in order. Each crossing must lie on the closed edge,
   the leg must leave the quad through it (or run along it, passing where
   it enters the edge), and t must not decrease: between two crossings the
   leg joins two points of one convex square, so it stays inside it. */
static int tt__edge_leg(const tt_mesh *s, const int *halfedges, const tt_quad_map *maps, int first, int last,
                        const double p[2], const double q[2], double t0, double t1, tt_edge_crossing *crossing)
{
    double d[2], dd, length, previous = 0.0, tolerance;
    int i;
    d[0] = q[0] - p[0];
    d[1] = q[1] - p[1];
    dd = d[0] * d[0] + d[1] * d[1];
    length = sqrt(dd);
    tolerance = TT__EDGE_EPS / (length > TT__EDGE_EPS ? length : TT__EDGE_EPS);   /* in the leg's parameter */
    for (i = first; i < last; i++) {
        double e0[2], e1[2], dir[2], normal[2], outward, gap, u, along, at[2];
        tt__edge_in_plane(s, halfedges[i], maps[i], e0, e1);
        dir[0] = e1[0] - e0[0];
        dir[1] = e1[1] - e0[1];
        normal[0] = dir[1];          /* the quad lies to the left of its CCW edge */
        normal[1] = -dir[0];
        outward = d[0] * normal[0] + d[1] * normal[1];
        gap = (e0[0] - p[0]) * normal[0] + (e0[1] - p[1]) * normal[1];
        if (outward > TT__EDGE_EPS) {
            u = gap / outward;
        } else if (fabs(outward) <= TT__EDGE_EPS && fabs(gap) <= TT__EDGE_EPS) {
            /* Along the edge's line: pass where the leg enters the edge, or at once if it is on it. */
            if (dd <= TT__EDGE_EPS * TT__EDGE_EPS) {
                u = previous;
            } else {
                double u0 = ((e0[0] - p[0]) * d[0] + (e0[1] - p[1]) * d[1]) / dd;
                double u1 = ((e1[0] - p[0]) * d[0] + (e1[1] - p[1]) * d[1]) / dd;
                u = u0 < u1 ? u0 : u1;
                if ((u0 > u1 ? u0 : u1) < previous - tolerance) return 0;
                if (u < previous) u = previous;
            }
        } else {
            return 0;
        }
        if (u < previous - tolerance || u > 1.0 + tolerance) return 0;
        u = u < previous ? previous : (u > 1.0 ? 1.0 : u);
        at[0] = p[0] + u * d[0];
        at[1] = p[1] + u * d[1];
        along = (at[0] - e0[0]) * dir[0] + (at[1] - e0[1]) * dir[1];
        if (along < -TT__EDGE_EPS || along > 1.0 + TT__EDGE_EPS) return 0;
        crossing[i].halfedge = halfedges[i];
        crossing[i].along = along < 0.0 ? 0.0 : (along > 1.0 ? 1.0 : along);
        crossing[i].t = t0 + u * (t1 - t0);
        previous = u;
    }
    return 1;
}

/* The number of quads around the S vertex that half-edge h leaves. */
static int tt__surface_valence(const tt_mesh *s, int h)
{
    int around = h, count = 0;
    do {
        int quad = s->corner_face[around];
        around = s->twin[s->face_start[quad] + ((around - s->face_start[quad] + 3) & 3)];
        count++;
    } while (around != h && count <= s->ncorners);
    return count;
}

/* The angle at the origin from x to y, -pi..pi. */
static double tt__turn_angle(const double x[2], const double y[2])
{
    return atan2(tt__orient2(0.0, 0.0, x[0], x[1], y[0], y[1]), x[0] * y[0] + x[1] * y[1]);
}

/* The angle between two vectors, 0..pi. */
static double tt__angle2(const double x[2], const double y[2])
{
    return fabs(tt__turn_angle(x, y));
}

/* The bends of a path (tt__edge_path_crossings): a choice, portal by
   portal, of where its straight legs end. Bend m is at vertex at[m] (in
   the plane), where the path crosses portals first[m]..end[m]-1 (the run of
   quads around the vertex, all crossed at one t). */
typedef struct tt__edge_bends {
    const tt_mesh *s;
    const int *halfedges;
    const tt_quad_map *maps;
    int portals, count, best_count;
    double a[2], b[2], length, best_length;     /* best_length starts as a bound: the search's best path */
    int first[TT__EDGE_BEND_QUADS], end[TT__EDGE_BEND_QUADS];
    int best_first[TT__EDGE_BEND_QUADS], best_end[TT__EDGE_BEND_QUADS];
    double at[TT__EDGE_BEND_QUADS][2], best_at[TT__EDGE_BEND_QUADS][2];
    tt_edge_crossing scratch[TT__EDGE_BEND_QUADS];
} tt__edge_bends;

/* Is bend m locally shortest, the path coming from `from` and going on to
   `to`? The angle on the run's side (from the way back, over the run's
   quads, to the way on) and the rest of the turn around the vertex must
   both be at least half a turn; only a saddle (more than 4 quads around
   it) has room for that. */
static int tt__edge_bend_holds(const tt__edge_bends *B, int m, const double from[2], const double to[2])
{
    const tt_mesh *s = B->s;
    const double *v = B->at[m];
    int h = B->halfedges[B->first[m]], quad = s->corner_face[h], k = h - s->face_start[quad], valence, i, outer;
    int corner = s->face_start[quad] + k, st[2];
    double back[2], on[2], edge_in[2], edge_out[2], run, point[2];
    /* The vertex is the first portal's start corner or the next one. */
    tt__quad_corner_st(k, st);
    tt_quad_map_apply(B->maps[B->first[m]], st[0], st[1], point);
    if (fabs(point[0] - v[0]) + fabs(point[1] - v[1]) > 0.5) corner = s->face_start[quad] + ((k + 1) & 3);
    valence = tt__surface_valence(s, corner);
    if (valence < 5) return 0;
    back[0] = from[0] - v[0];
    back[1] = from[1] - v[1];
    on[0] = to[0] - v[0];
    on[1] = to[1] - v[1];
    for (outer = 0; outer < 2; outer++) {
        double e0[2], e1[2], *edge = outer ? edge_out : edge_in;
        i = outer ? B->end[m] - 1 : B->first[m];
        tt__edge_in_plane(s, B->halfedges[i], B->maps[i], e0, e1);
        if (fabs(e0[0] - v[0]) + fabs(e0[1] - v[1]) < 0.5) {
            edge[0] = e1[0] - v[0];
            edge[1] = e1[1] - v[1];
        } else {
            edge[0] = e0[0] - v[0];
            edge[1] = e0[1] - v[1];
        }
    }
    run = tt__angle2(back, edge_in) + (B->end[m] - B->first[m] - 1) * 0.5 * TT__PI + tt__angle2(edge_out, on);
    return run >= TT__PI - TT__EDGE_ANGLE_EPS && valence * 0.5 * TT__PI - run >= TT__PI - TT__EDGE_ANGLE_EPS;
}

static double tt__distance2(const double p[2], const double q[2])
{
    return sqrt((q[0] - p[0]) * (q[0] - p[0]) + (q[1] - p[1]) * (q[1] - p[1]));
}

/* Does portal i of the path have vertex v (in the plane) as an end? */
static int tt__edge_portal_has(const tt__edge_bends *B, int i, const double v[2])
{
    double e0[2], e1[2];
    tt__edge_in_plane(B->s, B->halfedges[i], B->maps[i], e0, e1);
    return (e0[0] == v[0] && e0[1] == v[1]) || (e1[0] == v[0] && e1[1] == v[1]);
}

/* From portal i on, the current leg starting at p after portal `leg_first`
   (bends before it: B->count): end the leg at a vertex of portal i, or go
   on. At the last portal the leg goes to q_b; a complete choice whose legs
   all cross their portals and whose bends all hold is kept when shorter. */
static void tt__edge_bend_search(tt__edge_bends *B, int i, int leg_first, const double p[2])
{
    int end, j;
    if (i == B->portals) {
        double length = B->length + tt__distance2(p, B->b);
        if (B->count == 0 || length >= B->best_length - TT__EDGE_EPS) return;
        if (!tt__edge_leg(B->s, B->halfedges, B->maps, leg_first, B->portals, p, B->b, 0.0, 1.0, B->scratch) ||
            !tt__edge_bend_holds(B, B->count - 1, B->count > 1 ? B->at[B->count - 2] : B->a, B->b))
            return;
        B->best_count = B->count;
        B->best_length = length;
        memcpy(B->best_first, B->first, sizeof B->first);
        memcpy(B->best_end, B->end, sizeof B->end);
        memcpy(B->best_at, B->at, sizeof B->at);
        return;
    }
    tt__edge_bend_search(B, i + 1, leg_first, p);
    if (B->count == TT__EDGE_BEND_QUADS) return;
    for (end = 0; end < 2; end++) {
        const int h = B->halfedges[i], quad = B->s->corner_face[h];
        double e0[2], e1[2], *v = B->at[B->count], leg, kept_length = B->length;
        /* Only a saddle can hold a bend; and the path through v is at least as long as the straight line on. */
        if (tt__surface_valence(B->s, B->s->face_start[quad] + ((h - B->s->face_start[quad] + end) & 3)) < 5)
            continue;
        tt__edge_in_plane(B->s, h, B->maps[i], e0, e1);
        v[0] = end ? e1[0] : e0[0];
        v[1] = end ? e1[1] : e0[1];
        leg = tt__distance2(p, v);
        if (leg <= TT__EDGE_EPS || B->length + leg + tt__distance2(v, B->b) >= B->best_length - TT__EDGE_EPS ||
            !tt__edge_leg(B->s, B->halfedges, B->maps, leg_first, i, p, v, 0.0, 1.0, B->scratch))
            continue;
        if (B->count > 0 && !tt__edge_bend_holds(B, B->count - 1, B->count > 1 ? B->at[B->count - 2] : B->a, v))
            continue;
        B->first[B->count] = i;
        for (j = i + 1; j <= B->portals; j++) {
            if (j > i + 1 && !tt__edge_portal_has(B, j - 1, v)) break;
            B->end[B->count] = j;
            B->length = kept_length + leg;
            B->count++;
            tt__edge_bend_search(B, j, j, v);
            B->count--;
        }
        B->length = kept_length;
    }
}

/* Is the path of `count` quads leaving by halfedges[0..count-2] the image
   of the edge? Unfolded into q_a's plane it must be either straight from
   q_a to q_b (see tt__edge_leg), or - paths of at most
   TT__EDGE_BEND_QUADS quads only - straight legs meeting at
   saddle vertices of S (5 or 6 quads around them, more than a full turn),
   each bend passing around its vertex through a run of the path's quads
   (their edges crossed at the vertex, at one t), with at least half a turn
   on both sides: a shortest path, which on a saddle no straight one
   replaces (the staircases of a sphere are full of them). The shortest
   choice of bends wins. The crossings go to crossing[], the length to
   *length; t runs in proportion to the length along the path. */
static int tt__edge_path_crossings(const tt__edge_search *S, const int *halfedges, int count,
                                   tt_edge_crossing *crossing, double *length)
{
    const tt_mesh *s = S->pc->surface;
    tt_quad_map maps[TT_POLYCUBE_EDGE_MAX_QUADS];
    tt__edge_bends B;
    double b[2], walked = 0.0;
    int i, m;
    maps[0].turns = maps[0].offset[0] = maps[0].offset[1] = 0;
    for (i = 0; i + 1 < count; i++) maps[i + 1] = tt_quad_map_compose(maps[i], tt_polycube_unfold(S->pc, halfedges[i]));
    tt_quad_map_apply(maps[count - 1], S->b[0], S->b[1], b);
    if (tt__edge_leg(s, halfedges, maps, 0, count - 1, S->a, b, 0.0, 1.0, crossing)) {
        *length = tt__distance2(S->a, b);
        return 1;
    }
    if (count > TT__EDGE_BEND_QUADS) return 0;
    memset(&B, 0, sizeof B);
    B.s = s;
    B.halfedges = halfedges;
    B.maps = maps;
    B.portals = count - 1;
    B.a[0] = S->a[0];
    B.a[1] = S->a[1];
    B.b[0] = b[0];
    B.b[1] = b[1];
    /* Only a path no longer than the best so far can win (of equal ones, the one with fewer quads). */
    B.best_length = S->best_count ? S->best_length + 2.0 * TT__EDGE_EPS : HUGE_VAL;
    tt__edge_bend_search(&B, 0, 0, B.a);
    if (!B.best_count) return 0;
    /* The legs again, now with t: A, the bends, B, t in proportion to the length walked. */
    for (m = 0; m <= B.best_count; m++) {
        const double *from = m ? B.best_at[m - 1] : B.a, *to = m < B.best_count ? B.best_at[m] : B.b;
        int leg_first = m ? B.best_end[m - 1] : 0, leg_last = m < B.best_count ? B.best_first[m] : count - 1;
        double t0 = walked / B.best_length, t1;
        walked += tt__distance2(from, to);
        t1 = m < B.best_count ? walked / B.best_length : 1.0;
        tt__edge_leg(s, halfedges, maps, leg_first, leg_last, from, to, t0, t1, crossing);
        for (i = leg_last; m < B.best_count && i < B.best_end[m]; i++) {
            double e0[2], e1[2];
            tt__edge_in_plane(s, halfedges[i], maps[i], e0, e1);
            crossing[i].halfedge = halfedges[i];
            crossing[i].along = e0[0] == to[0] && e0[1] == to[1] ? 0.0 : 1.0;
            crossing[i].t = t1;
        }
    }
    *length = B.best_length;
    return 1;
}

/* The funnel: the directions from q_a through every edge crossed so far
   (angles relative to `reference`, in [lo, hi]); `has` once an edge not
   through q_a has narrowed it, `closed` once no straight segment from q_a
   crosses them all. A closed funnel ends a path only beyond
   TT__EDGE_BEND_QUADS quads, as shorter paths may bend at a
   saddle (tt__edge_path_crossings). */
typedef struct tt__edge_funnel {
    int has, closed;
    double reference, lo, hi;
} tt__edge_funnel;

/* Whether two points of S are the same (quad and bits of s and t). */
static int tt__same_point(tt_surface_point a, tt_surface_point b)
{
    return a.quad == b.quad && a.s == b.s && a.t == b.t;
}

/* The vertex of S that point p is on (a corner of its quad), or -1. */
static int tt__point_vertex(const tt_mesh *s, tt_surface_point p)
{
    if ((p.s != 0.0f && p.s != 1.0f) || (p.t != 0.0f && p.t != 1.0f)) return -1;
    return s->corner_vert[s->face_start[p.quad] + (p.t == 0.0f ? (p.s == 0.0f ? 0 : 1) : (p.s == 0.0f ? 3 : 2))];
}

/* Point p in the frame of `quad`: its own quad's, or, when p is a corner
   of S, that corner in any quad around it. 0 (p's own coordinates in st)
   when p does not lie in `quad`. */
static int tt__point_in_quad(const tt_mesh *s, tt_surface_point p, int quad, double st[2])
{
    const int vertex = tt__point_vertex(s, p);
    int corner, k[2];
    st[0] = p.s;
    st[1] = p.t;
    if (quad == p.quad) return 1;
    if (vertex < 0 || (corner = tt__quad_corner_of(s, quad, vertex)) < 0) return 0;
    tt__quad_corner_st(corner, k);
    st[0] = k[0];
    st[1] = k[1];
    return 1;
}

/* The quads point p lies in, p's own first, with p in each one's frame: one,
   or every quad around the corner of S that p is on. Returns the count. */
static int tt__quads_at_point(const tt_mesh *s, tt_surface_point p, int quads[TT__CORNER_QUADS],
                              double st[TT__CORNER_QUADS][2])
{
    const int vertex = tt__point_vertex(s, p);
    int n = 0, h, around;
    quads[0] = p.quad;
    st[0][0] = p.s;
    st[0][1] = p.t;
    if (vertex < 0) return 1;
    h = around = s->face_start[p.quad] + tt__quad_corner_of(s, p.quad, vertex);
    do {
        int quad = s->corner_face[around], k[2];
        tt__quad_corner_st(around - s->face_start[quad], k);
        quads[n] = quad;
        st[n][0] = k[0];
        st[n][1] = k[1];
        n++;
        around = s->twin[s->face_start[quad] + ((around - s->face_start[quad] + 3) & 3)];
    } while (around != h && n < TT__CORNER_QUADS);
    return n;
}

/* Grow the path from quads[depth - 1], depth first, half-edges in corner
   order; at q_b's quad judge it (tt__edge_path_crossings). */
static void tt__edge_search_from(tt__edge_search *S, int depth, tt__edge_funnel funnel)
{
    const tt_mesh *s = S->pc->surface;
    int quad = S->quads[depth - 1], k;
    if (quad == S->quad_b) {
        double length;
        if (tt__edge_path_crossings(S, S->halfedges, depth, S->crossings, &length) &&
            (!S->best_count || length < S->best_length - TT__EDGE_EPS ||
             (length <= S->best_length + TT__EDGE_EPS && depth < S->best_count))) {
            S->best_count = depth;
            S->best_length = length;
            memcpy(S->best_crossings, S->crossings, sizeof(tt_edge_crossing) * (size_t)(depth - 1));
        }
        return;
    }
    if (depth == S->max_quads) return;
    for (k = 0; k < 4; k++) {
        int h = s->face_start[quad] + k, next = s->corner_face[s->twin[h]], i, seen = 0;
        double e0[2], e1[2], d0[2], d1[2], inside;
        tt__edge_funnel narrowed = funnel;
        for (i = 0; i < depth && !seen; i++) seen = S->quads[i] == next;
        if (seen || ++S->steps > TT__EDGE_SEARCH_BUDGET) continue;
        tt__edge_in_plane(s, h, S->maps[depth - 1], e0, e1);
        if (S->best_count &&
            tt__point_segment_distance(S->a[0], S->a[1], e0[0], e0[1], e1[0], e1[1]) > S->best_length + TT__EDGE_EPS)
            continue;
        d0[0] = e0[0] - S->a[0];
        d0[1] = e0[1] - S->a[1];
        d1[0] = e1[0] - S->a[0];
        d1[1] = e1[1] - S->a[1];
        /* q_a's distance from the edge's line, positive on the quad's side (the edge has length 1). */
        inside = d0[0] * d1[1] - d0[1] * d1[0];
        if (inside < -TT__EDGE_EPS) narrowed.closed = 1;   /* a straight segment could only cross it before q_a */
        if (inside > TT__EDGE_EPS && !narrowed.closed) {
            double start = atan2(d0[1], d0[0]), width = atan2(inside, d0[0] * d1[0] + d0[1] * d1[1]);
            if (!funnel.has) {
                narrowed.has = 1;
                narrowed.reference = start + 0.5 * width;
                narrowed.lo = -0.5 * width;
                narrowed.hi = 0.5 * width;
            } else {
                /* Both the funnel and this edge's directions span less than half a turn, so they overlap
                   in at most one piece: here, or one turn lower. */
                double from = start - funnel.reference;
                while (from > TT__PI) from -= TT__TWO_PI;
                while (from <= -TT__PI) from += TT__TWO_PI;
                if (from > funnel.hi + TT__EDGE_ANGLE_EPS) from -= TT__TWO_PI;
                if (from > funnel.hi + TT__EDGE_ANGLE_EPS || from + width < funnel.lo - TT__EDGE_ANGLE_EPS) {
                    narrowed.closed = 1;
                } else {
                    if (from > narrowed.lo) narrowed.lo = from;
                    if (from + width < narrowed.hi) narrowed.hi = from + width;
                    if (narrowed.lo > narrowed.hi) narrowed.lo = narrowed.hi = 0.5 * (narrowed.lo + narrowed.hi);
                }
            }
        }
        if (narrowed.closed && depth + 1 > TT__EDGE_BEND_QUADS) continue;
        S->halfedges[depth - 1] = h;
        S->quads[depth] = next;
        S->maps[depth] = tt_quad_map_compose(S->maps[depth - 1], tt_polycube_unfold(S->pc, h));
        tt__edge_search_from(S, depth + 1, narrowed);
    }
}

/* The shortest path on S of the edge from point qa to point qb, searched
   from each quad at either end (an end on a corner of S lies in all of
   them; its own quad first, so that it keeps ties). Returns whether there
   is one; S->best_count and S->best_crossings hold it, ends[] the quads it
   starts and ends in, and S->a, S->b the ends in those quads' frames. */
static int tt__edge_find_path(tt__edge_search *S, tt_surface_point qa, tt_surface_point qb, int ends[2])
{
    const tt_mesh *s = S->pc->surface;
    int quads_a[TT__CORNER_QUADS], quads_b[TT__CORNER_QUADS], na, nb, ia, ib, best_a = 0, best_b = 0;
    double st_a[TT__CORNER_QUADS][2], st_b[TT__CORNER_QUADS][2];
    na = tt__quads_at_point(s, qa, quads_a, st_a);
    nb = tt__quads_at_point(s, qb, quads_b, st_b);
    S->best_count = 0;
    S->steps = 0;
    for (ia = 0; ia < na; ia++)
        for (ib = 0; ib < nb; ib++) {
            tt__edge_funnel funnel;
            int best_count = S->best_count;
            double best_length = S->best_length;
            S->a[0] = st_a[ia][0];
            S->a[1] = st_a[ia][1];
            S->b[0] = st_b[ib][0];
            S->b[1] = st_b[ib][1];
            S->quad_b = quads_b[ib];
            S->quads[0] = quads_a[ia];
            S->maps[0].turns = S->maps[0].offset[0] = S->maps[0].offset[1] = 0;
            memset(&funnel, 0, sizeof funnel);
            tt__edge_search_from(S, 1, funnel);
            if (S->best_count != best_count || S->best_length != best_length) {
                best_a = ia;
                best_b = ib;
            }
        }
    ends[0] = quads_a[best_a];
    ends[1] = quads_b[best_b];
    S->a[0] = st_a[best_a][0];
    S->a[1] = st_a[best_a][1];
    S->b[0] = st_b[best_b][0];
    S->b[1] = st_b[best_b][1];
    return S->best_count > 0;
}

static double tt__edge_snap(double x)
{
    return x < TT__EDGE_SNAP ? 0.0 : (x > 1.0 - TT__EDGE_SNAP ? 1.0 : x);
}

TTDEF void tt_polycube_edges_free(tt_polycube_edges *edges)
{
    tt_allocator allocator;
    if (!edges) return;
    allocator = edges->allocator;
    tt__free(&allocator, edges->edge_of_halfedge);
    tt__free(&allocator, edges->edge_vertices);
    tt__free(&allocator, edges->first_crossing);
    tt__free(&allocator, edges->crossings);
    tt__free(&allocator, edges->end_quads);
    tt__free(&allocator, edges->failed);
    tt__free(&allocator, edges);
}

/* tt_polycube_trace_edges, or, given the records `previous` made from the
   same mesh and the same points except those of the vertices flagged in
   `moved`, a copy of those records with only the edges at a moved vertex
   traced again. */
static tt_result tt__trace_edges(const tt_polycube *polycube, const tt_mesh *mesh, const tt_surface_point *points,
                                 int npoints, const tt_polycube_edge_options *options,
                                 const tt_allocator *allocator, const tt_polycube_edges *previous,
                                 const unsigned char *moved, tt_polycube_edges **out, tt_error *error)
{
    tt_polycube_edges *E = NULL;
    tt__edge_search *S = NULL;
    int max_quads = options && options->max_quads ? options->max_quads : TT_POLYCUBE_EDGE_DEFAULT_QUADS;
    int c, v, e, capacity = 0;
    tt__ok(error);
    if (out) *out = NULL;
    if (!polycube || !mesh || !points || !out)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "tt_polycube_trace_edges needs a polycube, a mesh, points and out (got NULL)");
    if (tt__check_allocator(allocator, error) != TT_OK) return TT_ERROR_INVALID_ARGUMENT;
    if (options && (options->max_quads < 0 || options->max_quads > TT_POLYCUBE_EDGE_MAX_QUADS))
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1, "max_quads %d is outside 0..%d",
                        options->max_quads, TT_POLYCUBE_EDGE_MAX_QUADS);
    if (mesh->nfaces <= 0) return tt__fail(error, TT_ERROR_EMPTY_MESH, -1, -1, -1, -1, "the mesh has no faces");
    if (npoints != mesh->nverts)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "%d points for a mesh of %d vertices: give one point per vertex", npoints, mesh->nverts);
    if (!tt__polycube_consistent(polycube))
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "the polycube's surface has no quads or does not match its cubes: make it with "
                        "tt_polycube_build and leave it unchanged");
    for (v = 0; v < npoints; v++)
        if (points[v].quad < 0 || points[v].quad >= polycube->surface->nfaces || !(points[v].s >= 0.0f) ||
            !(points[v].s <= 1.0f) || !(points[v].t >= 0.0f) || !(points[v].t <= 1.0f))
            return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, v, -1,
                            "the point of vertex %d (quad %d, s %g, t %g) is not on S: the quad must be one of "
                            "S's %d and s, t in [0, 1]", v, points[v].quad, (double)points[v].s,
                            (double)points[v].t, polycube->surface->nfaces);

    E = TT__ALLOC(allocator, tt_polycube_edges, 1);
    if (!E) goto out_of_memory;
    memset(E, 0, sizeof *E);
    E->allocator = tt__allocator_copy(allocator);
    S = TT__ALLOC(allocator, tt__edge_search, 1);
    if (!S) goto out_of_memory;
    /* One edge per twin pair, numbered in order of its first half-edge. */
    E->edge_of_halfedge = TT__ALLOC(allocator, int, mesh->ncorners);
    if (!E->edge_of_halfedge) goto out_of_memory;
    for (c = 0; c < mesh->ncorners; c++) {
        int twin = mesh->twin[c];
        E->edge_of_halfedge[c] = twin >= 0 && twin < c ? E->edge_of_halfedge[twin] : E->nedges++;
    }
    E->edge_vertices = TT__ALLOC(allocator, int, (size_t)E->nedges * 2);
    E->first_crossing = TT__ALLOC(allocator, int, (size_t)E->nedges + 1);
    E->failed = TT__ALLOC(allocator, unsigned char, E->nedges);
    E->end_quads = TT__ALLOC(allocator, int, (size_t)E->nedges * 2);
    if (!E->edge_vertices || !E->first_crossing || !E->failed || !E->end_quads) goto out_of_memory;
    for (c = 0; c < mesh->ncorners; c++) {
        int f = mesh->corner_face[c], next = c + 1 < mesh->face_start[f + 1] ? c + 1 : mesh->face_start[f];
        int from = mesh->corner_vert[c], to = mesh->corner_vert[next];
        e = E->edge_of_halfedge[c];
        E->edge_vertices[2 * e] = from < to ? from : to;
        E->edge_vertices[2 * e + 1] = from < to ? to : from;
    }

    memset(S, 0, sizeof *S);
    S->pc = polycube;
    S->max_quads = max_quads;
    for (e = 0; e < E->nedges; e++) {
        tt_surface_point qa = points[E->edge_vertices[2 * e]], qb = points[E->edge_vertices[2 * e + 1]];
        const tt_edge_crossing *crossing = S->best_crossings;
        int count, i;
        E->first_crossing[e] = E->ncrossings;
        if (previous && !moved[E->edge_vertices[2 * e]] && !moved[E->edge_vertices[2 * e + 1]]) {
            const int first = previous->first_crossing[e];
            count = previous->first_crossing[e + 1] - first;
            if (count > 0) {
                tt_edge_crossing *grown = (tt_edge_crossing *)tt__grow(allocator, E->crossings, &capacity,
                                                                       E->ncrossings + count, sizeof(tt_edge_crossing));
                if (!grown) goto out_of_memory;
                E->crossings = grown;
                memcpy(E->crossings + E->ncrossings, previous->crossings + first, sizeof(tt_edge_crossing) * (size_t)count);
                E->ncrossings += count;
            }
            E->end_quads[2 * e] = previous->end_quads[2 * e];
            E->end_quads[2 * e + 1] = previous->end_quads[2 * e + 1];
            E->failed[e] = previous->failed[e];
            E->nfailed += E->failed[e];
            continue;
        }
        E->failed[e] = !tt__edge_find_path(S, qa, qb, E->end_quads + 2 * e);
        if (E->failed[e]) {
            E->nfailed++;
            continue;
        }
        count = S->best_count - 1;
        if (count > 0) {
            tt_edge_crossing *grown = (tt_edge_crossing *)tt__grow(allocator, E->crossings, &capacity,
                                                                   E->ncrossings + count, sizeof(tt_edge_crossing));
            if (!grown) goto out_of_memory;
            E->crossings = grown;
        }
        {
            /* P11 step 4.5, once per edge: no zero-length piece next to a vertex or a quad corner. Besides t
               and along within TT__EDGE_SNAP of their ends, a crossing within TT__EDGE_SNAP h of either
               end of the edge - on S, or in space - is at that end (a vertex's point a float ulp off a quad
               corner gives a crossing there at a t far from 0, and its 3D point would round onto the
               vertex's), and one that close to the crossing before it is at that one's t. */
            const float *pa = mesh->pos + 3 * (size_t)E->edge_vertices[2 * e];
            const float *pb = mesh->pos + 3 * (size_t)E->edge_vertices[2 * e + 1];
            double b_plane[2], length3 = 0.0;
            tt_quad_map map;
            int a;
            for (a = 0; a < 3; a++) length3 += ((double)pb[a] - pa[a]) * ((double)pb[a] - pa[a]);
            length3 = sqrt(length3) / polycube->h;
            map.turns = map.offset[0] = map.offset[1] = 0;
            for (i = 0; i < count; i++) map = tt_quad_map_compose(map, tt_polycube_unfold(polycube, crossing[i].halfedge));
            tt_quad_map_apply(map, S->b[0], S->b[1], b_plane);
            map.turns = map.offset[0] = map.offset[1] = 0;
            for (i = 0; i < count; i++) {
                tt_edge_crossing snapped = crossing[i];
                double e0[2], e1[2], at[2];
                tt__edge_in_plane(polycube->surface, snapped.halfedge, map, e0, e1);
                at[0] = e0[0] + snapped.along * (e1[0] - e0[0]);
                at[1] = e0[1] + snapped.along * (e1[1] - e0[1]);
                snapped.along = tt__edge_snap(snapped.along);
                snapped.t = tt__edge_snap(snapped.t);
                if (tt__distance2(at, S->a) <= TT__EDGE_SNAP || snapped.t * length3 <= TT__EDGE_SNAP) snapped.t = 0.0;
                if (tt__distance2(at, b_plane) <= TT__EDGE_SNAP || (1.0 - snapped.t) * length3 <= TT__EDGE_SNAP)
                    snapped.t = 1.0;
                /* Two crossings this close pass one S vertex: one split point (their 3D points would round
                   to one). */
                if (i > 0 && (snapped.t - E->crossings[E->ncrossings - 1].t) * length3 <= TT__EDGE_SNAP)
                    snapped.t = E->crossings[E->ncrossings - 1].t;
                E->crossings[E->ncrossings++] = snapped;
                map = tt_quad_map_compose(map, tt_polycube_unfold(polycube, crossing[i].halfedge));
            }
        }
    }
    E->first_crossing[E->nedges] = E->ncrossings;
    tt__free(allocator, S);
    *out = E;
    return TT_OK;
out_of_memory:
    tt__free(allocator, S);
    tt_polycube_edges_free(E);
    return tt__fail(error, TT_ERROR_OUT_OF_MEMORY, -1, -1, -1, -1, "out of memory tracing the mesh's edges on S");
}

TTDEF tt_result tt_polycube_trace_edges(const tt_polycube *polycube, const tt_mesh *mesh,
                                        const tt_surface_point *points, int npoints,
                                        const tt_polycube_edge_options *options, const tt_allocator *allocator,
                                        tt_polycube_edges **out, tt_error *error)
{
    return tt__trace_edges(polycube, mesh, points, npoints, options, allocator, NULL, NULL, out, error);
}

/* *edges replaced by records whose edges at the points flagged in moved[]
   are traced again (tt__trace_edges); on failure *edges stays. */
static tt_result tt__retrace_moved(const tt_polycube *polycube, const tt_mesh *mesh, const tt_surface_point *points,
                                   const tt_polycube_edge_options *options, const tt_allocator *allocator,
                                   const unsigned char *moved, tt_polycube_edges **edges, tt_error *error)
{
    tt_polycube_edges *again = NULL;
    tt_result result = tt__trace_edges(polycube, mesh, points, mesh->nverts, options, allocator, *edges, moved, &again,
                                       error);
    if (result != TT_OK) return result;
    tt_polycube_edges_free(*edges);
    *edges = again;
    return TT_OK;
}

/* ---- The model refined (before spec P11 step 2) ---- */

/* The model refined for the split: its triangles halved along every edge
   longer than a bound until none is, so that a triangle spans few quads of
   S and holds at most about one vertex of S (a coarse model's large
   triangles would each hold several cone points, which no single chart or
   fan maps). Refined vertex v < mesh->nverts is input vertex v; each
   refined vertex interpolates at most 3 vertices of one input triangle
   (the midpoint of a midpoint stays on its triangle), and each refined
   triangle knows its input face. When no edge is too long, all four stay
   NULL: the model is the input. */
typedef struct tt__refined {
    tt_mesh *mesh;
    int *source;                /* 3 per vertex: input vertices... */
    double *weight;             /* ...and their weights */
    int *face;                  /* per triangle: its input face */
} tt__refined;

static void tt__refined_free(const tt_allocator *allocator, tt__refined *r)
{
    tt_mesh_free(r->mesh);
    tt__free(allocator, r->source);
    tt__free(allocator, r->weight);
    tt__free(allocator, r->face);
    memset(r, 0, sizeof *r);
}

/* The sources of the midpoint of refined vertices a and b: half of each,
   the same input vertices added up (at most 3 distinct: both lie on one
   input triangle). */
static void tt__refined_midpoint_sources(const int *source, const double *weight, int a, int b, int out_source[3],
                                         double out_weight[3])
{
    int n = 0, i, j, k;
    for (k = 0; k < 3; k++) {
        out_source[k] = source[3 * a];
        out_weight[k] = 0.0;
    }
    for (i = 0; i < 6; i++) {
        int v = source[3 * (i < 3 ? a : b) + i % 3];
        double w = 0.5 * weight[3 * (i < 3 ? a : b) + i % 3];
        if (w == 0.0) continue;
        for (j = 0; j < n && out_source[j] != v; j++) continue;
        if (j == n) {
            if (n == 3) continue;
            out_source[n++] = v;
        }
        out_weight[j] += w;
    }
}

#define TT__REFINE_MAX_TRIANGLES (1 << 24)   /* refining stops short of this many triangles */

static tt_result tt__polycube_refine(const tt_mesh *mesh, double longest, const tt_allocator *allocator,
                                     tt__refined *out, tt_error *error)
{
    float *positions = NULL;
    int *triangles = NULL, *faces = NULL, *source = NULL, *mid = NULL, *next_triangles = NULL, *next_faces = NULL;
    double *weight = NULL;
    int nverts = mesh->nverts, ntriangles = mesh->nfaces, vertex_capacity = 0, pass, c, v, f;
    tt_mesh *current = NULL;
    tt_result result = TT_OK;
    memset(out, 0, sizeof *out);
    /* Nothing to halve (a dense scan): the model is the input itself, out->mesh stays NULL. */
    for (c = 0; c < mesh->ncorners; c++) {
        double edge[3];
        tt__sub3f(mesh->pos + 3 * mesh->corner_vert[tt_mesh_next(mesh, c)], mesh->pos + 3 * mesh->corner_vert[c], edge);
        if (tt__length3(edge) > longest) break;
    }
    if (c == mesh->ncorners) return TT_OK;
    positions = (float *)tt__grow(allocator, NULL, &vertex_capacity, nverts > 0 ? nverts : 1, 3 * sizeof(float));
    source = TT__ALLOC(allocator, int, 3 * (size_t)vertex_capacity);
    weight = TT__ALLOC(allocator, double, 3 * (size_t)vertex_capacity);
    triangles = TT__ALLOC(allocator, int, 3 * (size_t)ntriangles);
    faces = TT__ALLOC(allocator, int, ntriangles);
    if (!positions || !source || !weight || !triangles || !faces) goto out_of_memory;
    memcpy(positions, mesh->pos, sizeof(float) * 3 * (size_t)nverts);
    for (v = 0; v < nverts; v++) {
        source[3 * v] = source[3 * v + 1] = source[3 * v + 2] = v;
        weight[3 * v] = 1.0;
        weight[3 * v + 1] = weight[3 * v + 2] = 0.0;
    }
    memcpy(triangles, mesh->corner_vert, sizeof(int) * 3 * (size_t)ntriangles);
    for (f = 0; f < ntriangles; f++) faces[f] = f;
    for (pass = 0;; pass++) {
        tt_mesh_desc desc;
        int marked = 0, next_count = 0;
        memset(&desc, 0, sizeof desc);
        desc.positions = positions;
        desc.nverts = nverts;
        desc.indices = triangles;
        desc.nfaces = ntriangles;
        desc.fixed_face_size = 3;
        desc.flags = mesh->flags & TT_MESH_PERMISSIVE;
        if ((result = tt_mesh_build(&desc, allocator, &current, error)) != TT_OK) goto failed;
        mid = TT__ALLOC(allocator, int, current->ncorners);
        if (!mid) goto out_of_memory;
        for (c = 0; c < current->ncorners; c++) {
            int a = current->corner_vert[c], b = current->corner_vert[tt_mesh_next(current, c)], twin = current->twin[c];
            double edge[3];
            int k;
            tt__sub3f(positions + 3 * b, positions + 3 * a, edge);
            mid[c] = -1;
            if (tt__length3(edge) <= longest) continue;
            marked++;
            if (twin >= 0 && twin < c) {
                mid[c] = mid[twin];
                continue;
            }
            if (nverts == vertex_capacity) {
                int capacity = vertex_capacity, *grown_source;
                float *grown_positions;
                double *grown_weight;
                if (nverts >= INT_MAX / 4) goto too_large;
                grown_positions = (float *)tt__grow(allocator, positions, &capacity, nverts + 1, 3 * sizeof(float));
                if (!grown_positions) goto out_of_memory;
                positions = grown_positions;
                capacity = vertex_capacity;
                grown_source = (int *)tt__grow(allocator, source, &capacity, nverts + 1, 3 * sizeof(int));
                if (!grown_source) goto out_of_memory;
                source = grown_source;
                capacity = vertex_capacity;
                grown_weight = (double *)tt__grow(allocator, weight, &capacity, nverts + 1, 3 * sizeof(double));
                if (!grown_weight) goto out_of_memory;
                weight = grown_weight;
                vertex_capacity = capacity;
            }
            for (k = 0; k < 3; k++)
                positions[3 * nverts + k] = (float)(0.5 * ((double)positions[3 * a + k] + positions[3 * b + k]));
            tt__refined_midpoint_sources(source, weight, a, b, source + 3 * nverts, weight + 3 * nverts);
            mid[c] = nverts++;
        }
        if (!marked || ntriangles > TT__REFINE_MAX_TRIANGLES / 4) break;
        if (ntriangles > (INT_MAX / 3) / 4) goto too_large;
        next_triangles = TT__ALLOC(allocator, int, 12 * (size_t)ntriangles);
        next_faces = TT__ALLOC(allocator, int, 4 * (size_t)ntriangles);
        if (!next_triangles || !next_faces) goto out_of_memory;
        for (f = 0; f < ntriangles; f++) {
            int r, split = 0, *t;
            const int *corner = triangles + 3 * f, *m = mid + 3 * f;
            for (r = 0; r < 3; r++) split += m[r] >= 0;
            /* Turn the triangle so its split edges come first: (a, b) always split when any is. */
            for (r = 0; r < 3 && split > 0 && split < 3; r++)
                if (m[r] >= 0 && m[(r + 2) % 3] < 0) break;
            if (split == 0 || split == 3) r = 0;
            {
                int a = corner[r], b = corner[(r + 1) % 3], cc = corner[(r + 2) % 3];
                int ab = m[r], bc = m[(r + 1) % 3], ca = m[(r + 2) % 3], add[12], n = 0, k;
                if (split == 0) {
                    add[n++] = a; add[n++] = b; add[n++] = cc;
                } else if (split == 1) {
                    add[n++] = a; add[n++] = ab; add[n++] = cc;
                    add[n++] = ab; add[n++] = b; add[n++] = cc;
                } else if (split == 2) {
                    /* (a, b) and (b, c) split: the corner at b, then the quad a, ab, bc, c by its shorter
                       diagonal. */
                    double diagonal_a[3], diagonal_c[3];
                    tt__sub3f(positions + 3 * a, positions + 3 * bc, diagonal_a);
                    tt__sub3f(positions + 3 * cc, positions + 3 * ab, diagonal_c);
                    add[n++] = ab; add[n++] = b; add[n++] = bc;
                    if (tt__length3(diagonal_a) <= tt__length3(diagonal_c)) {
                        add[n++] = a; add[n++] = ab; add[n++] = bc;
                        add[n++] = a; add[n++] = bc; add[n++] = cc;
                    } else {
                        add[n++] = a; add[n++] = ab; add[n++] = cc;
                        add[n++] = ab; add[n++] = bc; add[n++] = cc;
                    }
                } else {
                    add[n++] = a; add[n++] = ab; add[n++] = ca;
                    add[n++] = ab; add[n++] = b; add[n++] = bc;
                    add[n++] = ca; add[n++] = bc; add[n++] = cc;
                    add[n++] = ab; add[n++] = bc; add[n++] = ca;
                }
                t = next_triangles + 3 * next_count;
                memcpy(t, add, sizeof(int) * (size_t)n);
                for (k = 0; k < n / 3; k++) next_faces[next_count++] = faces[f];
            }
        }
        tt__free(allocator, triangles);
        tt__free(allocator, faces);
        tt__free(allocator, mid);
        tt_mesh_free(current);
        current = NULL;
        mid = NULL;
        triangles = next_triangles;
        faces = next_faces;
        next_triangles = next_faces = NULL;
        ntriangles = next_count;
    }
    tt__free(allocator, mid);
    tt__free(allocator, triangles);
    tt__free(allocator, positions);
    out->mesh = current;
    out->source = source;
    out->weight = weight;
    out->face = faces;
    return TT_OK;
too_large:
    result = tt__fail(error, TT_ERROR_TOO_LARGE, -1, -1, -1, -1,
                      "refining the model's triangles to edges of at most %g would pass %d vertices or "
                      "triangles: choose a larger max_edge or a coarser polycube", longest, INT_MAX / 4);
    goto failed;
out_of_memory:
    result = tt__fail(error, TT_ERROR_OUT_OF_MEMORY, -1, -1, -1, -1, "out of memory refining the model");
failed:
    tt_mesh_free(current);
    tt__free(allocator, mid);
    tt__free(allocator, next_triangles);
    tt__free(allocator, next_faces);
    tt__free(allocator, triangles);
    tt__free(allocator, faces);
    tt__free(allocator, positions);
    tt__free(allocator, source);
    tt__free(allocator, weight);
    return result;
}

/* ---- Relaxation of the points on S (spec P11 step 5) ---- */

#define TT__RELAX_RADIUS 4          /* steps across S's edges a vertex's local chart spans */
#define TT__RELAX_SEAT_RADIUS 2     /* the same around a neighbour's point, where a vertex may be re-seated */
#define TT__RELAX_CHART 96          /* quads a local chart holds at most */
#define TT__RELAX_SWEEPS 12         /* one-vertex sweeps before the untangling */
#define TT__UNTANGLE_SWEEPS 40      /* untangling sweeps over the vertices near folds */
#define TT__UNTANGLE_PATIENCE 6     /* sweeps without fewer bad triangles after which the rings double */
#define TT__UNTANGLE_RINGS 16       /* rings around the folds untangled at most */
#define TT__UNTANGLE_REGION 16      /* vertices per fold beyond which the region stops growing: the folds
                                       such a region leaves rarely open in a larger one, which costs more
                                       (the pig at 16: 0.25 s to 0.13 s, the same 3 fallbacks) */
#define TT__UNTANGLE_STAR 64        /* triangles around a vertex it untangles at most */
#define TT__UNTANGLE_EPSILON 0.01   /* Escobar et al.'s epsilon: det J below which delta grows */
#define TT__UNTANGLE_STEPS 10       /* descent steps per vertex and sweep */
#define TT__UNTANGLE_HALVINGS 20    /* halvings of a descent step before the vertex stops */
#define TT__RELAX_KERNEL_POINTS 64  /* a star's kernel polygon: its box's 4 corners and one per triangle */
#define TT__RELAX_KERNEL_MARGIN 1e-9    /* twice the least area (quad units) of a star triangle around a kernel point */

/* A local chart of S around a quad: the quads within `radius` steps
   across S's edges, found breadth first, each with the map of its frame into the
   centre quad's frame (the first way found: around a cone point of S the
   chart is cut where the search meets itself). */
typedef struct tt__relax_chart {
    int count, radius;  /* quads in it; the reach it was built with (around quad[0]) */
    int quad[TT__RELAX_CHART];
    tt_quad_map map[TT__RELAX_CHART];
    int cell[TT__RELAX_CHART][2];   /* the unit cell of the chart the quad covers */
    int *index_of;      /* per quad of S: its place in quad[], or -1 (all -1 outside the chart) */
    const tt_quad_map *unfold;  /* per half-edge of S: tt_polycube_unfold, made once */
} tt__relax_chart;

static void tt__relax_chart_build(const tt_polycube *pc, int centre, int radius, tt__relax_chart *c)
{
    const tt_mesh *s = pc->surface;
    int head = 0, ring_end, ring, i;
    double middle[2];
    if (c->count > 0 && c->quad[0] == centre && c->radius == radius) return;   /* built already */
    for (i = 0; i < c->count; i++) c->index_of[c->quad[i]] = -1;
    c->radius = radius;
    c->count = 1;
    c->quad[0] = centre;
    c->index_of[centre] = 0;
    c->map[0].turns = c->map[0].offset[0] = c->map[0].offset[1] = 0;
    c->cell[0][0] = c->cell[0][1] = 0;
    for (ring = 0; ring < radius; ring++) {
        ring_end = c->count;
        for (; head < ring_end; head++) {
            int k;
            for (k = 0; k < 4 && c->count < TT__RELAX_CHART; k++) {
                int h = s->face_start[c->quad[head]] + k, next = s->corner_face[s->twin[h]];
                if (c->index_of[next] >= 0) continue;
                c->index_of[next] = c->count;
                c->quad[c->count] = next;
                c->map[c->count] = tt_quad_map_compose(c->map[head], c->unfold[h]);
                tt_quad_map_apply(c->map[c->count], 0.5, 0.5, middle);
                c->cell[c->count][0] = (int)floor(middle[0]);
                c->cell[c->count][1] = (int)floor(middle[1]);
                c->count++;
            }
        }
    }
}

/* Point p of S in the chart; 0 when its quad is not in it. */
static int tt__relax_chart_place(const tt__relax_chart *c, tt_surface_point p, double at[2])
{
    int i = c->index_of[p.quad];
    if (i < 0) return 0;
    tt_quad_map_apply(c->map[i], p.s, p.t, at);
    return 1;
}

/* The point of S at chart place `at`: the first chart quad whose cell holds
   it. 0 when none does. */
static int tt__relax_chart_point(const tt__relax_chart *c, const double at[2], tt_surface_point *p)
{
    int i, x = (int)floor(at[0]), y = (int)floor(at[1]);
    for (i = 0; i < c->count; i++)
        if (c->cell[i][0] == x && c->cell[i][1] == y) {
            double st[2];
            tt__quad_map_invert_point(c->map[i], at, st);
            p->quad = c->quad[i];
            p->s = (float)(st[0] < 0.0 ? 0.0 : (st[0] > 1.0 ? 1.0 : st[0]));
            p->t = (float)(st[1] < 0.0 ? 0.0 : (st[1] > 1.0 ? 1.0 : st[1]));
            return 1;
        }
    return 0;
}

/* What the relaxation, the untangling and the re-seating share: each
   vertex's triangles, as the corners at it, two local charts (around a
   vertex, around a neighbour) with a quad index each, and the vertices
   whose triangles they judge. */
typedef struct tt__relax_context {
    int *first_triangle;        /* per vertex and one more: where its corners start in triangle_corners */
    int *triangle_corners;
    tt__relax_chart *chart, *around;
    int *index_of;              /* the two charts' quad indices, one after the other */
    tt_quad_map *unfold;        /* per half-edge of S: tt_polycube_unfold */
    const unsigned char *focus; /* per vertex: only triangles at a flagged vertex are judged; NULL = all */
} tt__relax_context;

static void tt__relax_context_free(const tt_allocator *allocator, tt__relax_context *x)
{
    tt__free(allocator, x->first_triangle);
    tt__free(allocator, x->triangle_corners);
    tt__free(allocator, x->chart);
    tt__free(allocator, x->index_of);
    tt__free(allocator, x->unfold);
    memset(x, 0, sizeof *x);
}

/* 0 when out of memory (nothing left allocated). */
static int tt__relax_context_init(const tt_polycube *pc, const tt_mesh *model, const tt_allocator *allocator,
                                  tt__relax_context *x)
{
    const int nverts = model->nverts, nquads = pc->surface->nfaces;
    int v, c, *next;
    memset(x, 0, sizeof *x);
    x->first_triangle = TT__ALLOC(allocator, int, (size_t)nverts + 1);
    x->triangle_corners = TT__ALLOC(allocator, int, model->ncorners > 0 ? model->ncorners : 1);
    x->chart = TT__ALLOC(allocator, tt__relax_chart, 2);
    x->index_of = TT__ALLOC(allocator, int, 2 * (size_t)nquads);
    x->unfold = TT__ALLOC(allocator, tt_quad_map, pc->surface->ncorners);
    next = TT__ALLOC(allocator, int, nverts > 0 ? nverts : 1);
    if (!x->first_triangle || !x->triangle_corners || !x->chart || !x->index_of || !x->unfold || !next) {
        tt__free(allocator, next);
        tt__relax_context_free(allocator, x);
        return 0;
    }
    for (c = 0; c < pc->surface->ncorners; c++) x->unfold[c] = tt_polycube_unfold(pc, c);
    x->around = x->chart + 1;
    for (c = 0; c < 2 * nquads; c++) x->index_of[c] = -1;
    x->chart->count = x->around->count = 0;
    x->chart->index_of = x->index_of;
    x->around->index_of = x->index_of + nquads;
    x->chart->unfold = x->around->unfold = x->unfold;
    memset(next, 0, sizeof(int) * (size_t)nverts);
    for (c = 0; c < model->ncorners; c++) next[model->corner_vert[c]]++;
    x->first_triangle[0] = 0;
    for (v = 0; v < nverts; v++) x->first_triangle[v + 1] = x->first_triangle[v] + next[v];
    for (v = 0; v < nverts; v++) next[v] = x->first_triangle[v];
    for (c = 0; c < model->ncorners; c++) x->triangle_corners[next[model->corner_vert[c]]++] = c;
    tt__free(allocator, next);
    return 1;
}

/* The point of S closest to model vertex v on the quads within
   TT__RELAX_SEAT_RADIUS of `quad` (the chart built into *around): v seated
   on the sheet of S there. */
static tt_surface_point tt__relax_seat(const tt_polycube *pc, const tt_mesh *model, int v, int quad,
                                       tt__relax_chart *around)
{
    tt_surface_point best;
    double lattice[3], nearest = HUGE_VAL;
    int a, q;
    for (a = 0; a < 3; a++) lattice[a] = ((double)model->pos[3 * v + a] - pc->origin[a]) / pc->h;
    tt__relax_chart_build(pc, quad, TT__RELAX_SEAT_RADIUS, around);
    best.quad = quad;
    best.s = best.t = 0.5f;
    for (q = 0; q < around->count; q++) {
        tt_surface_point p = tt__polycube_surface_point(pc, around->quad[q], lattice);
        double xyz[3], d2 = 0.0;
        tt_polycube_point_position(pc, p, xyz);
        for (a = 0; a < 3; a++) d2 += (xyz[a] - model->pos[3 * v + a]) * (xyz[a] - model->pos[3 * v + a]);
        if (d2 < nearest) {
            nearest = d2;
            best = p;
        }
    }
    return best;
}

/* Point p of S in the frame of quad `centre`: directly in the same quad,
   across one edge of S for a quad next to it, else through the local
   chart around `centre` (built into *scratch). 0 when it lies beyond. */
static int tt__relax_place_near(const tt_polycube *pc, int centre, tt_surface_point p, double at[2],
                                tt__relax_chart *scratch)
{
    const tt_mesh *s = pc->surface;
    int k;
    if (p.quad == centre) {
        at[0] = p.s;
        at[1] = p.t;
        return 1;
    }
    for (k = 0; k < 4; k++) {
        int h = s->face_start[centre] + k;
        if (s->corner_face[s->twin[h]] == p.quad) {
            tt_quad_map_apply(scratch->unfold[h], p.s, p.t, at);
            return 1;
        }
    }
    tt__relax_chart_build(pc, centre, TT__RELAX_RADIUS, scratch);
    return tt__relax_chart_place(scratch, p, at);
}

/* How badly vertex v sits among its triangles with its point at `at` in
   the chart around it: each triangle whose other points lie outside the
   chart (their edge has no short path on S) counts 2, each one turning
   clockwise on S (a fold) counts 1, and the folded area breaks ties, so a
   move that only shrinks a fold still counts as progress. */
static double tt__relax_badness(const tt_mesh *model, const tt_surface_point *points, const int *first_triangle,
                                const int *triangle_corners, int v, const tt__relax_chart *c, const double at[2])
{
    int i, bad = 0;
    double folded = 0.0;
    for (i = first_triangle[v]; i < first_triangle[v + 1]; i++) {
        int corner = triangle_corners[i], f = corner / 3, k = corner % 3;
        int u = model->corner_vert[3 * f + (k + 1) % 3], w = model->corner_vert[3 * f + (k + 2) % 3];
        double pu[2], pw[2], turn;
        if (!tt__relax_chart_place(c, points[u], pu) || !tt__relax_chart_place(c, points[w], pw)) {
            bad += 2;
            continue;
        }
        turn = tt__orient2(at[0], at[1], pu[0], pu[1], pw[0], pw[1]);
        if (turn <= 0.0) {
            bad++;
            folded -= turn;
        }
    }
    /* The count first; among equal counts, less folded area (in (0, 1), so it never outweighs a triangle). */
    return bad + 0.9 * folded / (1.0 + folded);
}

/* The centre (vertex mean) of the kernel of a vertex's star in a chart:
   the points p with every triangle (p, ring[2i], ring[2i + 1]) turning
   counter-clockwise by more than TT__RELAX_KERNEL_MARGIN, where
   no triangle of the star folds. The box around the ring clipped by one
   half-plane per triangle (Sutherland-Hodgman). 0 when the kernel is
   empty (or the star too large). */
static int tt__relax_kernel_centre(const double (*ring)[2], int ntriangles, double centre[2])
{
    double polygon[2][TT__RELAX_KERNEL_POINTS][2], lo[2] = {HUGE_VAL, HUGE_VAL}, hi[2] = {-HUGE_VAL, -HUGE_VAL};
    int n = 4, i, j, k, from = 0;
    if (ntriangles <= 0 || ntriangles + 4 > TT__RELAX_KERNEL_POINTS) return 0;
    for (i = 0; i < 2 * ntriangles; i++)
        for (k = 0; k < 2; k++) {
            if (ring[i][k] < lo[k]) lo[k] = ring[i][k];
            if (ring[i][k] > hi[k]) hi[k] = ring[i][k];
        }
    polygon[0][0][0] = lo[0]; polygon[0][0][1] = lo[1];
    polygon[0][1][0] = hi[0]; polygon[0][1][1] = lo[1];
    polygon[0][2][0] = hi[0]; polygon[0][2][1] = hi[1];
    polygon[0][3][0] = lo[0]; polygon[0][3][1] = hi[1];
    for (i = 0; i < ntriangles && n > 0; i++) {
        const double *a = ring[2 * i], *b = ring[2 * i + 1];
        double (*in)[2] = polygon[from], (*out)[2] = polygon[!from];
        int m = 0;
        for (j = 0; j < n; j++) {
            const double *p = in[j], *q = in[(j + 1) % n];
            double fp = tt__orient2(a[0], a[1], b[0], b[1], p[0], p[1]) - TT__RELAX_KERNEL_MARGIN;
            double fq = tt__orient2(a[0], a[1], b[0], b[1], q[0], q[1]) - TT__RELAX_KERNEL_MARGIN;
            if (fp >= 0.0) {
                out[m][0] = p[0];
                out[m][1] = p[1];
                m++;
            }
            if ((fp >= 0.0) != (fq >= 0.0)) {
                double u = fp / (fp - fq);
                out[m][0] = p[0] + u * (q[0] - p[0]);
                out[m][1] = p[1] + u * (q[1] - p[1]);
                m++;
            }
        }
        n = m;
        from = !from;
    }
    if (n < 3) return 0;
    centre[0] = centre[1] = 0.0;
    for (j = 0; j < n; j++) {
        centre[0] += polygon[from][j][0] / n;
        centre[1] += polygon[from][j][1] / n;
    }
    return 1;
}

/* Whether triangle t turns clockwise in the frames of all three of its
   points' quads. Around a cone of S the chart of one quad may show a
   triangle folded that lies flat on S, but not the charts of all three. */
static int tt__relax_folded_everywhere(const tt_polycube *pc, const tt_surface_point *points, const int *t,
                                       tt__relax_chart *scratch)
{
    int first, k;
    for (first = 1; first < 3; first++) {
        double at[3][2];
        at[0][0] = points[t[first]].s;
        at[0][1] = points[t[first]].t;
        for (k = 1; k < 3; k++)
            if (!tt__relax_place_near(pc, points[t[first]].quad, points[t[(first + k) % 3]], at[k], scratch)) return 0;
        if (tt__orient2(at[0][0], at[0][1], at[1][0], at[1][1], at[2][0], at[2][1]) > 0.0) return 0;
    }
    return 1;
}

/* Vertex v tried at `candidate`: its badness there (tt__relax_badness, in
   a chart around the candidate, built into *chart), which replaces *best
   when below *best_bad. points[v] is left as it was. */
static void tt__relax_try(const tt_polycube *pc, const tt_mesh *model, tt_surface_point *points,
                          const int *first_triangle, const int *triangle_corners, int v, tt_surface_point candidate,
                          tt__relax_chart *chart, double *best_bad, tt_surface_point *best)
{
    const tt_surface_point kept = points[v];
    double at[2], after;
    points[v] = candidate;
    tt__relax_chart_build(pc, candidate.quad, TT__RELAX_RADIUS, chart);
    tt__relax_chart_place(chart, candidate, at);
    after = tt__relax_badness(model, points, first_triangle, triangle_corners, v, chart, at);
    points[v] = kept;
    if (after < *best_bad - 1e-12) {
        *best_bad = after;
        *best = candidate;
    }
}

/* Flags the vertices of badly placed triangles in bad[] (cleared first)
   and returns how many triangles are: a triangle is judged in its first
   vertex's quad frame, the others' quads mapped in across one edge of S
   when they are next to it, else through a local chart (x->chart); it is
   bad when folded (not counter-clockwise) or out of the chart's reach.
   Only triangles at a vertex in x->focus are judged. */
static int tt__relax_mark_bad(const tt_polycube *pc, const tt_mesh *model, const tt_surface_point *points,
                              const tt__relax_context *x, int folds_only, unsigned char *bad)
{
    tt__relax_chart *scratch = x->chart;
    int c, count = 0;
    memset(bad, 0, (size_t)model->nverts);
    for (c = 0; c < model->ncorners; c += 3) {
        const int *t = model->corner_vert + c;
        double at[3][2];
        int k, placed = 1;
        if (x->focus && !x->focus[t[0]] && !x->focus[t[1]] && !x->focus[t[2]]) continue;
        at[0][0] = points[t[0]].s;
        at[0][1] = points[t[0]].t;
        for (k = 1; k < 3 && placed; k++) placed = tt__relax_place_near(pc, points[t[0]].quad, points[t[k]], at[k], scratch);
        if (placed && tt__orient2(at[0][0], at[0][1], at[1][0], at[1][1], at[2][0], at[2][1]) > 0.0) continue;
        if (folds_only && (!placed || !tt__relax_folded_everywhere(pc, points, t, scratch))) continue;
        bad[t[0]] = bad[t[1]] = bad[t[2]] = 1;
        count++;
    }
    return count;
}

/* Whether vertex v's point is its own 3D position (the model touches S
   there): such points never move. */
static int tt__relax_on_surface(const tt_polycube *pc, const tt_mesh *model, const tt_surface_point *points, int v)
{
    double here[3], d2 = 0.0;
    int a;
    tt_polycube_point_position(pc, points[v], here);
    for (a = 0; a < 3; a++) d2 += (here[a] - model->pos[3 * v + a]) * (here[a] - model->pos[3 * v + a]);
    return d2 <= 1e-18 * pc->h * pc->h;
}

/* A vertex's star for untangling: per triangle (v, a, b), a and b in the
   chart, and the inverse of the triangle's own shape (its 3D edges
   v -> a, v -> b laid flat, in cube units), which the map should keep. */
typedef struct tt__untangle_star {
    int n;
    double ring[TT__UNTANGLE_STAR][2][2];
    double inverse[TT__UNTANGLE_STAR][2][2];
} tt__untangle_star;

/* Sets triangle i's shape (edge v -> a, edge v -> b, in 2D); 0 when it has no area. */
static int tt__untangle_star_shape(tt__untangle_star *star, int i, const double shape[2][2])
{
    const double det = shape[0][0] * shape[1][1] - shape[1][0] * shape[0][1];
    if (!(det != 0.0)) return 0;
    star->inverse[i][0][0] = shape[1][1] / det;
    star->inverse[i][0][1] = -shape[1][0] / det;
    star->inverse[i][1][0] = -shape[0][1] / det;
    star->inverse[i][1][1] = shape[0][0] / det;
    return 1;
}

/* The untangling energy of Escobar et al. ("Simultaneous untangling and
   smoothing of tetrahedral meshes", CMAME 2003), in 2D, with v at x: per
   triangle, J maps its own shape onto the chart triangle (x, a, b) and
   costs |J|^2 / (2 h(det J)), h(s) = (s + sqrt(s^2 + delta2)) / 2. With
   delta2 > 0 it is finite for folded triangles and falls steeply toward
   unfolding them; unfolded, it is least where J is a similarity (1 per
   triangle). The gradient in x goes to gradient[2]; *folded counts the
   triangles with det J <= 0. */
static double tt__untangle_energy(const tt__untangle_star *star, const double x[2], double delta2,
                                  double gradient[2], int *folded)
{
    double energy = 0.0;
    int i;
    gradient[0] = gradient[1] = 0.0;
    *folded = 0;
    for (i = 0; i < star->n; i++) {
        const double *a = star->ring[i][0], *b = star->ring[i][1];
        /* J = [a - x, b - x] times the shape's inverse. */
        const double i00 = star->inverse[i][0][0], i01 = star->inverse[i][0][1];
        const double i10 = star->inverse[i][1][0], i11 = star->inverse[i][1][1];
        const double j00 = (a[0] - x[0]) * i00 + (b[0] - x[0]) * i10, j01 = (a[0] - x[0]) * i01 + (b[0] - x[0]) * i11;
        const double j10 = (a[1] - x[1]) * i00 + (b[1] - x[1]) * i10, j11 = (a[1] - x[1]) * i01 + (b[1] - x[1]) * i11;
        /* Moving x by e_k adds d = -(i00 + i10, i01 + i11) to row k of J. */
        const double d0 = -(i00 + i10), d1 = -(i01 + i11);
        const double det = j00 * j11 - j01 * j10, frobenius = j00 * j00 + j01 * j01 + j10 * j10 + j11 * j11;
        const double root = sqrt(det * det + delta2), h = 0.5 * (det + root);
        const double dh = root > 0.0 ? 0.5 * (1.0 + det / root) : 0.5;
        double dfrobenius[2], ddet[2];
        int k;
        *folded += det <= 0.0;
        dfrobenius[0] = 2.0 * (j00 * d0 + j01 * d1);
        dfrobenius[1] = 2.0 * (j10 * d0 + j11 * d1);
        ddet[0] = d0 * j11 - d1 * j10;
        ddet[1] = j00 * d1 - j01 * d0;
        energy += frobenius / (2.0 * h);
        for (k = 0; k < 2; k++) gradient[k] += dfrobenius[k] / (2.0 * h) - frobenius * dh * ddet[k] / (2.0 * h * h);
    }
    return energy;
}

/* One untangling step of vertex v: its star in a chart around its point,
   a few steepest-descent steps of tt__untangle_energy with halving step
   lengths; when `strict`, kept only if no more of its triangles fold than
   before. Returns 1 when v moved. */
static int tt__untangle_vertex(const tt_polycube *pc, const tt_mesh *model, tt_surface_point *points,
                               const int *first_triangle, const int *triangle_corners, int v, int strict,
                               tt__relax_chart *chart, tt__untangle_star *star)
{
    double x[2], gradient[2], energy, least_det = HUGE_VAL, delta2, reach = 0.0, step_length = 0.0;
    int i, step, folded_before, folded;
    tt_surface_point moved;
    if (first_triangle[v + 1] - first_triangle[v] > TT__UNTANGLE_STAR) return 0;
    tt__relax_chart_build(pc, points[v].quad, TT__RELAX_RADIUS, chart);
    tt__relax_chart_place(chart, points[v], x);
    star->n = 0;
    for (i = first_triangle[v]; i < first_triangle[v + 1]; i++) {
        const int corner = triangle_corners[i], f = corner / 3;
        const int a = model->corner_vert[3 * f + (corner % 3 + 1) % 3], b = model->corner_vert[3 * f + (corner % 3 + 2) % 3];
        double edge_a[3], edge_b[3], normal[3], along[3], across[3], length, shape[2][2];
        int k;
        if (!tt__relax_chart_place(chart, points[a], star->ring[star->n][0]) ||
            !tt__relax_chart_place(chart, points[b], star->ring[star->n][1]))
            return 0;
        for (k = 0; k < 3; k++) {
            edge_a[k] = ((double)model->pos[3 * a + k] - model->pos[3 * v + k]) / pc->h;
            edge_b[k] = ((double)model->pos[3 * b + k] - model->pos[3 * v + k]) / pc->h;
        }
        tt__cross3(edge_a, edge_b, normal);
        if (!((length = tt__length3(edge_a)) > 0.0) || !(tt__normalize3(normal) > 0.0)) return 0;
        for (k = 0; k < 3; k++) along[k] = edge_a[k] / length;
        tt__cross3(normal, along, across);
        shape[0][0] = length;
        shape[0][1] = 0.0;
        shape[1][0] = tt__dot3(edge_b, along);
        shape[1][1] = tt__dot3(edge_b, across);
        if (!tt__untangle_star_shape(star, star->n, (const double (*)[2])shape)) return 0;
        for (k = 0; k < 2; k++)
            reach = fmax(reach, fabs(star->ring[star->n][k][0] - x[0]) + fabs(star->ring[star->n][k][1] - x[1]));
        /* det J of this triangle, for delta below. */
        {
            const double turn = tt__orient2(x[0], x[1], star->ring[star->n][0][0], star->ring[star->n][0][1],
                                            star->ring[star->n][1][0], star->ring[star->n][1][1]);
            const double det = turn / (length * shape[1][1]);
            if (det < least_det) least_det = det;
        }
        star->n++;
    }
    /* Escobar et al.'s delta: 0 once nothing is near folding, else growing with the worst fold. */
    delta2 = least_det < TT__UNTANGLE_EPSILON ? TT__UNTANGLE_EPSILON * (TT__UNTANGLE_EPSILON - least_det) : 0.0;
    energy = tt__untangle_energy(star, x, delta2, gradient, &folded_before);
    for (step = 0; step < TT__UNTANGLE_STEPS; step++) {
        const double norm = sqrt(gradient[0] * gradient[0] + gradient[1] * gradient[1]);
        double trial[2], trial_gradient[2], trial_energy = energy;
        int halvings;
        if (!(norm > 0.0)) break;
        /* From twice the last step that helped: the first is as long as the star is wide. */
        step_length = step == 0 ? reach : 2.0 * step_length;
        for (halvings = 0; halvings < TT__UNTANGLE_HALVINGS; halvings++, step_length *= 0.5) {
            trial[0] = x[0] - step_length * gradient[0] / norm;
            trial[1] = x[1] - step_length * gradient[1] / norm;
            trial_energy = tt__untangle_energy(star, trial, delta2, trial_gradient, &folded);
            if (trial_energy < energy) break;
        }
        if (halvings == TT__UNTANGLE_HALVINGS) break;
        x[0] = trial[0];
        x[1] = trial[1];
        energy = trial_energy;
        gradient[0] = trial_gradient[0];
        gradient[1] = trial_gradient[1];
    }
    tt__untangle_energy(star, x, delta2, gradient, &folded);
    if ((strict && folded > folded_before) || !tt__relax_chart_point(chart, x, &moved)) return 0;
    if (tt__same_point(moved, points[v])) return 0;
    points[v] = moved;
    return 1;
}

/* Untangling sweeps over the vertices of folded triangles (those every
   one of the triangle's quads sees folded) and the vertices up to `rings`
   edges from them, each vertex a tt__untangle_vertex step, until no fold
   is left, nothing moves, or the folds have not become fewer for
   TT__UNTANGLE_PATIENCE sweeps even with TT__UNTANGLE_RINGS rings (or a
   region of TT__UNTANGLE_REGION vertices per fold). The
   rings start at 1 and double at each stall: a pleat (the model laid on a
   part of S twice, then back) opens only when the vertices around it move
   together, and a wide region from the start would move far more
   vertices than a small fold needs (the bunny at 16: 21 fallbacks with
   one ring, 11 with up to 16). Strict steps never fold more of a star;
   free ones may, on the way to opening a fold that a strict step cannot
   start on (the horse at 32: 156 folds left strictly, 46 freely), and then
   the points return to the sweep with the fewest folds (saved in
   best_sweep, nverts points). `active` holds nverts vertices. Returns the
   bad triangles left (tt__relax_mark_bad, every kind); the moves made go
   to *moves. */
static int tt__untangle(const tt_polycube *pc, const tt_mesh *model, tt_surface_point *points,
                        const tt__relax_context *x, int strict, tt__untangle_star *star, unsigned char *bad,
                        int *active, tt_surface_point *best_sweep, int *moves)
{
    const int *first_triangle = x->first_triangle, *triangle_corners = x->triangle_corners;
    const size_t size = sizeof *points * (size_t)model->nverts;
    int sweep, least = INT_MAX, stalled = 0, rings = 1, v, i, region = 0;
    for (sweep = 0; sweep < TT__UNTANGLE_SWEEPS; sweep++) {
        int moved = 0, nactive = 0, head, folds = tt__relax_mark_bad(pc, model, points, x, 1, bad);
        if (!folds) break;
        if (folds < least) {
            least = folds;
            stalled = 0;
            if (!strict) memcpy(best_sweep, points, size);
        } else if (++stalled == TT__UNTANGLE_PATIENCE) {
            if (rings == TT__UNTANGLE_RINGS || region > TT__UNTANGLE_REGION * folds) break;
            rings *= 2;
            stalled = 0;
        }
        /* The vertices within `rings` edges of a fold, breadth first; bad[v] - 1 is v's distance. */
        for (v = 0; v < model->nverts; v++)
            if (bad[v]) active[nactive++] = v;
        for (head = 0; head < nactive; head++) {
            const int u = active[head];
            if (bad[u] > rings) continue;
            for (i = first_triangle[u]; i < first_triangle[u + 1]; i++) {
                const int corner = triangle_corners[i], f = corner / 3;
                int k;
                for (k = 1; k < 3; k++) {
                    const int w = model->corner_vert[3 * f + (corner % 3 + k) % 3];
                    if (bad[w]) continue;
                    bad[w] = (unsigned char)(bad[u] + 1);
                    active[nactive++] = w;
                }
            }
        }
        region = nactive;
        for (v = 0; v < model->nverts; v++)
            if (bad[v] && !tt__relax_on_surface(pc, model, points, v))
                moved += tt__untangle_vertex(pc, model, points, first_triangle, triangle_corners, v, strict, x->chart,
                                             star);
        *moves += moved;
        if (!moved) break;
    }
    if (!strict && least < INT_MAX && tt__relax_mark_bad(pc, model, points, x, 1, bad) > least)
        memcpy(points, best_sweep, size);
    return tt__relax_mark_bad(pc, model, points, x, 0, bad);
}

/* Spec P11 step 5: points that leave a triangle folded on S or its edge
   without a short path (a vertex projected onto the wrong sheet, a fold
   in a concavity) are moved, a few sweeps over the vertices in order:
     - toward the mean of its neighbours' points (half way, or all the
       way), in a local chart of S around it, when they all lie in it;
     - else to the closest point to its 3D position on the quads around a
       neighbour's point (onto its neighbours' sheet);
     - into the centre of its star's kernel (tt__relax_kernel_centre);
   a move is kept only when it leaves the vertex's triangles less badly
   placed (tt__relax_badness). Vertices whose triangles are all fine never
   move, and the ones whose points lie on S (the model touches the
   polycube) stay. A patch folded all through defeats these moves (each
   vertex's ring is folded too), so then the vertices of folded triangles
   and their neighbours are untangled (tt__untangle), with strict steps
   and with free ones from the same start, keeping the result with fewer
   bad triangles. With `focus` (per vertex), only triangles at a flagged
   vertex are judged; NULL judges all. Returns the number of moves, -1
   when out of memory. */
static int tt__polycube_relax(const tt_polycube *pc, const tt_mesh *model, tt_surface_point *points,
                              const unsigned char *focus, const tt_allocator *allocator)
{
    tt__relax_context x;
    int *first_triangle, *triangle_corners, *active = NULL;
    unsigned char *bad = NULL;
    tt__relax_chart *chart, *around;
    tt__untangle_star *star = NULL;
    tt_surface_point *initial = NULL, *strict_points = NULL, *best_sweep = NULL;
    int v, sweep, moves = 0, nverts = model->nverts;
    if (!tt__relax_context_init(pc, model, allocator, &x)) return -1;
    x.focus = focus;
    first_triangle = x.first_triangle;
    triangle_corners = x.triangle_corners;
    chart = x.chart;
    around = x.around;
    bad = TT__ALLOC(allocator, unsigned char, nverts > 0 ? nverts : 1);
    star = TT__ALLOC(allocator, tt__untangle_star, 1);
    initial = TT__ALLOC(allocator, tt_surface_point, nverts > 0 ? nverts : 1);
    strict_points = TT__ALLOC(allocator, tt_surface_point, nverts > 0 ? nverts : 1);
    best_sweep = TT__ALLOC(allocator, tt_surface_point, nverts > 0 ? nverts : 1);
    active = TT__ALLOC(allocator, int, nverts > 0 ? nverts : 1);
    if (!bad || !star || !initial || !strict_points || !best_sweep || !active) {
        moves = -1;
        goto done;
    }
    for (sweep = 0; sweep < TT__RELAX_SWEEPS; sweep++) {
        int moved = 0;
        tt__relax_mark_bad(pc, model, points, &x, 0, bad);
        for (v = 0; v < nverts; v++) {
            /* v's ring in its chart: per triangle, the points of its other two vertices. */
            double at[2], mean[2] = {0.0, 0.0}, candidate_at[2], ring[2 * (TT__RELAX_KERNEL_POINTS - 4)][2];
            int i, n = 0, reachable = 1, step;
            double before, best_bad;
            tt_surface_point best, candidate;
            if (!bad[v] || tt__relax_on_surface(pc, model, points, v)) continue;
            tt__relax_chart_build(pc, points[v].quad, TT__RELAX_RADIUS, chart);
            tt__relax_chart_place(chart, points[v], at);
            before = best_bad = tt__relax_badness(model, points, first_triangle, triangle_corners, v, chart, at);
            if (before == 0) continue;
            best = points[v];
            for (i = first_triangle[v]; i < first_triangle[v + 1]; i++) {
                int corner = triangle_corners[i], f = corner / 3, k;
                for (k = 1; k < 3; k++) {
                    double pu[2];
                    if (tt__relax_chart_place(chart, points[model->corner_vert[3 * f + (corner % 3 + k) % 3]], pu)) {
                        mean[0] += pu[0];
                        mean[1] += pu[1];
                        if (n < 2 * (TT__RELAX_KERNEL_POINTS - 4)) memcpy(ring[n], pu, sizeof pu);
                        n++;
                    } else {
                        reachable = 0;
                    }
                }
            }
            for (step = 1; step <= 2 && reachable && n > 0; step++) {
                candidate_at[0] = at[0] + 0.5 * step * (mean[0] / n - at[0]);
                candidate_at[1] = at[1] + 0.5 * step * (mean[1] / n - at[1]);
                tt__relax_chart_build(pc, points[v].quad, TT__RELAX_RADIUS, chart);
                if (tt__relax_chart_point(chart, candidate_at, &candidate))
                    tt__relax_try(pc, model, points, first_triangle, triangle_corners, v, candidate, chart, &best_bad,
                                  &best);
            }
            if (reachable && n > 0 && n <= 2 * (TT__RELAX_KERNEL_POINTS - 4)) {
                /* Into the kernel of v's star, where none of its triangles folds (when its ring allows). */
                tt__relax_chart_build(pc, points[v].quad, TT__RELAX_RADIUS, chart);
                if (tt__relax_kernel_centre((const double (*)[2])ring, n / 2, candidate_at) &&
                    tt__relax_chart_point(chart, candidate_at, &candidate))
                    tt__relax_try(pc, model, points, first_triangle, triangle_corners, v, candidate, chart, &best_bad,
                                  &best);
            }
            if (!reachable || n == 0) {
                /* Onto a neighbour's sheet: the closest point to v on the quads around each neighbour's. */
                for (i = first_triangle[v]; i < first_triangle[v + 1]; i++) {
                    int corner = triangle_corners[i], f = corner / 3, k, j;
                    for (k = 1; k < 3; k++) {
                        int u = model->corner_vert[3 * f + (corner % 3 + k) % 3];
                        for (j = first_triangle[v]; j < i; j++) {
                            int other = triangle_corners[j];
                            if (model->corner_vert[3 * (other / 3) + (other % 3 + 1) % 3] == u ||
                                model->corner_vert[3 * (other / 3) + (other % 3 + 2) % 3] == u)
                                break;
                        }
                        if (j < i || (k == 2 && model->corner_vert[3 * f + (corner % 3 + 1) % 3] == u)) continue;
                        candidate = tt__relax_seat(pc, model, v, points[u].quad, around);
                        tt__relax_try(pc, model, points, first_triangle, triangle_corners, v, candidate, chart,
                                      &best_bad, &best);
                    }
                }
            }
            if (best_bad < before - 1e-12) {
                points[v] = best;
                moved++;
            }
        }
        moves += moved;
        if (!moved) break;
    }
    /* The folds these moves leave (a vertex whose ring is itself folded has no good place of its own):
       untangling, both ways (tt__untangle), keeping the one that leaves fewer bad triangles. */
    if (tt__relax_mark_bad(pc, model, points, &x, 1, bad)) {
        int strict_left, free_left, strict_moves = 0, free_moves = 0;
        memcpy(initial, points, sizeof *points * (size_t)nverts);
        strict_left = tt__untangle(pc, model, points, &x, 1, star, bad, active, NULL, &strict_moves);
        memcpy(strict_points, points, sizeof *points * (size_t)nverts);
        memcpy(points, initial, sizeof *points * (size_t)nverts);
        free_left = tt__untangle(pc, model, points, &x, 0, star, bad, active, best_sweep, &free_moves);
        if (strict_left <= free_left) memcpy(points, strict_points, sizeof *points * (size_t)nverts);
        moves += strict_left <= free_left ? strict_moves : free_moves;
    }
done:
    tt__relax_context_free(allocator, &x);
    tt__free(allocator, bad);
    tt__free(allocator, star);
    tt__free(allocator, initial);
    tt__free(allocator, strict_points);
    tt__free(allocator, best_sweep);
    tt__free(allocator, active);
    return moves;
}

/* The crossing of edge e's image nearest its end v, NULL when it has none. */
static const tt_edge_crossing *tt__edge_crossing_nearest(const tt_polycube_edges *edges, int e, int v)
{
    const int first = edges->first_crossing[e], last = edges->first_crossing[e + 1];
    if (first == last) return NULL;
    return &edges->crossings[edges->edge_vertices[2 * e] == v ? first : last - 1];
}

/* The S vertex through which the image of edge e first leaves its end v
   (its crossing nearest v lies on a corner of S), or -1. */
static int tt__edge_apex_from(const tt_mesh *s, const tt_polycube_edges *edges, int e, int v)
{
    const tt_edge_crossing *x = tt__edge_crossing_nearest(edges, e, v);
    if (!x || (x->along != 0.0 && x->along != 1.0)) return -1;
    return s->corner_vert[x->along == 0.0 ? x->halfedge : tt_mesh_next(s, x->halfedge)];
}

/* Two edges of a triangle leaving its vertex v through the same corner W of
   S (v's point lies just behind a saddle, and both straight images bend
   there) bound a region of zero area on S: the part of the triangle between
   them would map onto the segment v -> W, a piece with no texture area. v
   is moved onto W, where both edges then start, unless another point is
   there already (two vertices at one place would make the same kind of
   piece). Each point moved is flagged in moved_points[]. Returns the
   number of points moved, -1 when out of memory. */
static int tt__polycube_unspike(const tt_polycube *pc, const tt_mesh *model, const tt_polycube_edges *edges,
                                tt_surface_point *points, unsigned char *moved_points, const tt_allocator *allocator)
{
    const tt_mesh *s = pc->surface;
    unsigned char *taken = TT__ALLOC(allocator, unsigned char, s->nverts);
    int moved = 0, c, v;
    if (!taken) return -1;
    memset(taken, 0, (size_t)s->nverts);
    for (v = 0; v < model->nverts; v++)
        if ((c = tt__point_vertex(s, points[v])) >= 0) taken[c] = 1;
    for (c = 0; c < model->ncorners; c++) {
        const int e = edges->edge_of_halfedge[c];
        const int apex = tt__edge_apex_from(s, edges, e, (v = model->corner_vert[c]));
        int quad, st[2];
        if (apex < 0 || taken[apex] ||
            apex != tt__edge_apex_from(s, edges, edges->edge_of_halfedge[tt_mesh_prev(model, c)], v))
            continue;
        quad = s->corner_face[tt__edge_crossing_nearest(edges, e, v)->halfedge];
        tt__quad_corner_st(tt__quad_corner_of(s, quad, apex), st);
        points[v].quad = quad;
        points[v].s = (float)st[0];
        points[v].t = (float)st[1];
        taken[apex] = 1;
        moved_points[v] = 1;
        moved++;
    }
    tt__free(allocator, taken);
    return moved;
}

#define TT__RESEAT_ROUNDS 2     /* rounds of re-seating stray vertices and tracing their edges again */
#define TT__RESEAT_CYCLES 2     /* re-seatings, each followed by the relaxation */
#define TT__RESEAT_SEATS 16     /* seats (neighbours' quads) tried per vertex at most */
#define TT__RESEAT_FOCUS_RINGS 8    /* rings around the re-seated points the relaxation after them looks at */

/* How many of v's edges, counted once per triangle at v, find no path on
   S with the points as they are. */
static int tt__reseat_failures(tt__edge_search *S, const tt_mesh *model, const tt_surface_point *points,
                               const tt__relax_context *x, int v)
{
    int i, k, failures = 0, ends[2];
    for (i = x->first_triangle[v]; i < x->first_triangle[v + 1]; i++) {
        int corner = x->triangle_corners[i], f = corner / 3;
        for (k = 1; k < 3; k++) {
            int u = model->corner_vert[3 * f + (corner % 3 + k) % 3];
            failures += !(u < v ? tt__edge_find_path(S, points[u], points[v], ends)
                                : tt__edge_find_path(S, points[v], points[u], ends));
        }
    }
    return failures;
}

/* A vertex with an edge that finds no path on S (P11 step 7 would put both
   its triangles whole into one quad, a local seam) sits on another sheet
   of S than its neighbour: the closest point chose the far side of a part
   about a cube thick, or of a fold of S. The relaxation cannot see it
   (both points lie within its chart), so each such vertex is tried seated
   on the sheet of each neighbour (tt__relax_seat) and kept where fewest of
   its edges fail, then fewest of its triangles fold (tt__relax_badness),
   when that is better than where it is. Each point moved is flagged in
   moved_points[]. Returns the number moved, -1 when out of memory. */
static int tt__polycube_reseat(const tt_polycube *pc, const tt_mesh *model, const tt_polycube_edges *edges,
                               int max_quads, tt_surface_point *points, unsigned char *moved_points,
                               const tt_allocator *allocator)
{
    tt__relax_context x;
    tt__edge_search *S = TT__ALLOC(allocator, tt__edge_search, 1);
    unsigned char *stray = TT__ALLOC(allocator, unsigned char, model->nverts > 0 ? model->nverts : 1);
    int moved = 0, e, v;
    if (!S || !stray || !tt__relax_context_init(pc, model, allocator, &x)) {
        tt__free(allocator, S);
        tt__free(allocator, stray);
        return -1;
    }
    memset(S, 0, sizeof *S);
    S->pc = pc;
    S->max_quads = max_quads;
    memset(stray, 0, (size_t)model->nverts);
    for (e = 0; e < edges->nedges; e++)
        if (edges->failed[e]) stray[edges->edge_vertices[2 * e]] = stray[edges->edge_vertices[2 * e + 1]] = 1;
    for (v = 0; v < model->nverts; v++) {
        const tt_surface_point kept = points[v];
        tt_surface_point best = kept;
        double at[2], best_score;
        int i, k, tried[TT__RESEAT_SEATS], ntried = 0;
        if (!stray[v] || tt__relax_on_surface(pc, model, points, v)) continue;
        tt__relax_chart_build(pc, kept.quad, TT__RELAX_RADIUS, x.chart);
        tt__relax_chart_place(x.chart, kept, at);
        best_score = 2.0 * tt__reseat_failures(S, model, points, &x, v) +
                     tt__relax_badness(model, points, x.first_triangle, x.triangle_corners, v, x.chart, at);
        for (i = x.first_triangle[v]; i < x.first_triangle[v + 1]; i++) {
            int corner = x.triangle_corners[i], f = corner / 3;
            for (k = 1; k < 3; k++) {
                int u = model->corner_vert[3 * f + (corner % 3 + k) % 3], j;
                tt_surface_point candidate;
                double score;
                /* Neighbours in one quad give one seat. */
                for (j = 0; j < ntried && tried[j] != points[u].quad; j++) continue;
                if (j < ntried || ntried == TT__RESEAT_SEATS) continue;
                tried[ntried++] = points[u].quad;
                candidate = tt__relax_seat(pc, model, v, points[u].quad, x.around);
                if (tt__same_point(candidate, kept)) continue;
                points[v] = candidate;
                tt__relax_chart_build(pc, candidate.quad, TT__RELAX_RADIUS, x.chart);
                tt__relax_chart_place(x.chart, candidate, at);
                score = 2.0 * tt__reseat_failures(S, model, points, &x, v) +
                        tt__relax_badness(model, points, x.first_triangle, x.triangle_corners, v, x.chart, at);
                if (score < best_score - 1e-12) {
                    best_score = score;
                    best = candidate;
                }
            }
        }
        points[v] = best;
        if (!tt__same_point(best, kept)) {
            moved_points[v] = 1;
            moved++;
        }
    }
    tt__relax_context_free(allocator, &x);
    tt__free(allocator, S);
    tt__free(allocator, stray);
    return moved;
}

/* ---- The model split on S and its UVs (spec P11 steps 4, 6, 7) ---- */

#define TT__SPLIT_MATCH 1e-5        /* chart distance, in units of h, within which a clipped point is a known one:
                                       above the records' snap (1e-6), far below any real piece */
#define TT__SPLIT_AREA 1e-12        /* chart area below which a piece is empty */
#define TT__MAP_SNAP 1e-5f          /* a vertex's point this near a quad's edge (in quad units) is put on it */
#define TT__SPLIT_MAX_CELLS 4096    /* grid cells of a chart's box beyond which a triangle takes the fallback */

/* A point on a triangle's boundary (a model vertex or a split point of an
   edge) and the boundary segment from it to the next point: the quad the
   segment lies in, both ends in that quad's frame, the map of that frame
   into the triangle's chart, and the point in the chart. */
typedef struct tt__split_point {
    int vertex;                 /* output vertex */
    int quad;
    double a[2], b[2];
    tt_quad_map map;
    double at[2];
    int used;                   /* a corner of some piece (tt__split_pieces) */
} tt__split_point;

typedef struct tt__split_cell {
    int quad;                   /* -1: not known yet */
    tt_quad_map map;
} tt__split_cell;

/* A vertex of a piece while the chart triangle is clipped: a corner of the
   triangle, a cut of side `index` by the grid line x[axis] = bound, or a
   point inside (where two grid lines cross). */
enum { TT__CLIP_CORNER, TT__CLIP_SIDE, TT__CLIP_GRID };
typedef struct tt__clip_point {
    double p[2];
    int kind, index, axis;
    double bound;
} tt__clip_point;

typedef struct tt__split {
    const tt_polycube *pc;
    const tt_mesh *mesh;
    const tt_polycube_edges *edges;
    const tt_surface_point *points;
    const tt_allocator *allocator;
    tt_polycube_mapping *out;
    int vertex_capacity, triangle_capacity;
    int *crossing_vertex;       /* per crossing of the records: its output vertex, -1 until made */
    /* One triangle at a time: */
    int vert[3];
    double corner[3][2];        /* its vertices in the chart */
    tt__split_point *boundary;  /* vertex 0, edge 0's split points, vertex 1, ... */
    int nboundary, boundary_capacity;
    int side_start[3];          /* the boundary index of vertex k, where side k (vertex k to k + 1) starts */
    tt__split_cell *cells;      /* the chart's grid cells over the triangle's box */
    int cell_capacity, box[4];  /* first cell x, y; cells across, up */
    int *queue;
    int *grid_points;           /* grid points inside the triangle: x, y, output vertex */
    int ngrid, grid_capacity;
} tt__split;

/* A new output vertex interpolating up to three input vertices; -1 when out of memory. */
static int tt__split_vertex(tt__split *S, const int source[3], const double weight[3])
{
    tt_polycube_mapping *m = S->out;
    int capacity = S->vertex_capacity, k, a;
    double p[3] = {0.0, 0.0, 0.0};
    if (m->nverts >= INT_MAX / 3 - 1) return -1;
    if (m->nverts == capacity) {
        /* Each array grows from the same old capacity; a failure leaves the arrays as they were, all owned. */
        float *positions, *weights;
        int *sources;
        capacity = S->vertex_capacity;
        positions = (float *)tt__grow(S->allocator, m->positions, &capacity, m->nverts + 1, 3 * sizeof(float));
        if (!positions) return -1;
        m->positions = positions;
        capacity = S->vertex_capacity;
        sources = (int *)tt__grow(S->allocator, m->source, &capacity, m->nverts + 1, 3 * sizeof(int));
        if (!sources) return -1;
        m->source = sources;
        capacity = S->vertex_capacity;
        weights = (float *)tt__grow(S->allocator, m->weights, &capacity, m->nverts + 1, 3 * sizeof(float));
        if (!weights) return -1;
        m->weights = weights;
        S->vertex_capacity = capacity;
    }
    for (k = 0; k < 3; k++) {
        m->source[3 * m->nverts + k] = source[k];
        m->weights[3 * m->nverts + k] = (float)weight[k];
        for (a = 0; a < 3; a++) p[a] += weight[k] * S->mesh->pos[3 * source[k] + a];
    }
    for (a = 0; a < 3; a++) m->positions[3 * m->nverts + a] = (float)p[a];
    return m->nverts++;
}

/* A new output triangle in `quad`; 0 when out of memory. */
static int tt__split_triangle(tt__split *S, int face, int quad, const int vertex[3], double st[3][2])
{
    tt_polycube_mapping *m = S->out;
    int k;
    if (m->ntriangles >= INT_MAX / 6 - 1) return 0;
    if (m->ntriangles == S->triangle_capacity) {
        int capacity = S->triangle_capacity, *triangles, *faces;
        tt_surface_point *points;
        triangles = (int *)tt__grow(S->allocator, m->triangles, &capacity, m->ntriangles + 1, 3 * sizeof(int));
        if (!triangles) return 0;
        m->triangles = triangles;
        capacity = S->triangle_capacity;
        faces = (int *)tt__grow(S->allocator, m->triangle_face, &capacity, m->ntriangles + 1, sizeof(int));
        if (!faces) return 0;
        m->triangle_face = faces;
        capacity = S->triangle_capacity;
        points = (tt_surface_point *)tt__grow(S->allocator, m->corner_points, &capacity, m->ntriangles + 1,
                                              3 * sizeof(tt_surface_point));
        if (!points) return 0;
        m->corner_points = points;
        S->triangle_capacity = capacity;
    }
    for (k = 0; k < 3; k++) {
        tt_surface_point *p = &m->corner_points[3 * m->ntriangles + k];
        m->triangles[3 * m->ntriangles + k] = vertex[k];
        p->quad = quad;
        p->s = (float)(st[k][0] < 0.0 ? 0.0 : (st[k][0] > 1.0 ? 1.0 : st[k][0]));
        p->t = (float)(st[k][1] < 0.0 ? 0.0 : (st[k][1] > 1.0 ? 1.0 : st[k][1]));
    }
    m->triangle_face[m->ntriangles++] = face;
    return 1;
}

/* The output vertex of crossing j of edge e: the edge's end at t = 0 or 1,
   else one vertex per t (crossings at one t pass one S vertex), made the
   first time either triangle asks. -1 when out of memory. */
static int tt__split_crossing_vertex(tt__split *S, int e, int j)
{
    const tt_polycube_edges *E = S->edges;
    const int *ends = E->edge_vertices + 2 * e;
    double t = E->crossings[j].t;
    if (t == 0.0) return ends[0];
    if (t == 1.0) return ends[1];
    while (j > E->first_crossing[e] && E->crossings[j - 1].t == t) j--;
    if (S->crossing_vertex[j] < 0) {
        int source[3];
        double weight[3];
        source[0] = ends[0];
        source[1] = source[2] = ends[1];
        weight[0] = 1.0 - t;
        weight[1] = t;
        weight[2] = 0.0;
        S->crossing_vertex[j] = tt__split_vertex(S, source, weight);
    }
    return S->crossing_vertex[j];
}

/* Append boundary point `vertex`, its segment starting in `quad` at st; the
   segment before it (if any) ends at st_in in its own quad. */
static int tt__split_push(tt__split *S, int vertex, int quad, const double st_in[2], const double st[2])
{
    tt__split_point *p;
    tt__split_point *grown = (tt__split_point *)tt__grow(S->allocator, S->boundary, &S->boundary_capacity,
                                                         S->nboundary + 1, sizeof(tt__split_point));
    if (!grown) return 0;
    S->boundary = grown;
    if (S->nboundary > 0) {
        S->boundary[S->nboundary - 1].b[0] = st_in[0];
        S->boundary[S->nboundary - 1].b[1] = st_in[1];
    }
    p = &S->boundary[S->nboundary++];
    memset(p, 0, sizeof *p);
    p->vertex = vertex;
    p->quad = quad;
    p->a[0] = st[0];
    p->a[1] = st[1];
    return 1;
}

/* The edge of a quad's square (0..3: the half-edge from corner k to k + 1)
   that both points lie on, within TT__EDGE_SNAP (the points on S of model
   vertices are float), or -1. */
static int tt__square_edge_of(const double p[2], const double q[2])
{
    if (fabs(p[1]) <= TT__EDGE_SNAP && fabs(q[1]) <= TT__EDGE_SNAP) return 0;
    if (fabs(p[0] - 1.0) <= TT__EDGE_SNAP && fabs(q[0] - 1.0) <= TT__EDGE_SNAP) return 1;
    if (fabs(p[1] - 1.0) <= TT__EDGE_SNAP && fabs(q[1] - 1.0) <= TT__EDGE_SNAP) return 2;
    if (fabs(p[0]) <= TT__EDGE_SNAP && fabs(q[0]) <= TT__EDGE_SNAP) return 3;
    return -1;
}

/* The map of the next segment's quad into the chart, from the map of the
   segment before, at boundary point p (in the frame of the quad before):
   the same quad; the quad across the edge through p; or, where p is a
   corner, the quads met turning clockwise around it, i.e. through the
   triangle's side of the boundary (its interior lies to the left). 0 when
   the next quad is none of these. */
static int tt__split_next_map(const tt__split *S, int quad, tt_quad_map map, const double p[2], int next,
                              tt_quad_map *out)
{
    const tt_mesh *s = S->pc->surface;
    int k, corner = -1, turns;
    if (next == quad) {
        *out = map;
        return 1;
    }
    for (k = 0; k < 4; k++) {
        int st[2];
        tt__quad_corner_st(k, st);
        if (fabs(p[0] - st[0]) + fabs(p[1] - st[1]) <= TT__EDGE_SNAP) corner = k;
    }
    if (corner < 0) {
        for (k = 0; k < 4; k++) {
            int h = s->face_start[quad] + k;
            if (tt__square_edge_of(p, p) == k && s->corner_face[s->twin[h]] == next) {
                *out = tt_quad_map_compose(map, tt_polycube_unfold(S->pc, h));
                return 1;
            }
        }
        return 0;
    }
    /* Clockwise around the corner: across the half-edge leaving it. */
    for (turns = 0; turns < 8; turns++) {
        int h = s->face_start[quad] + corner, twin = s->twin[h];
        map = tt_quad_map_compose(map, tt_polycube_unfold(S->pc, h));
        quad = s->corner_face[twin];
        corner = (twin - s->face_start[quad] + 1) & 3;
        if (quad == next) {
            *out = map;
            return 1;
        }
    }
    return 0;
}

/* Triangle f's boundary: its vertices and the split points of its edges,
   in order, with their output vertices (made when new), and the segments
   between them in their quads, as the edge records give them (spec P11
   step 3). Then, for the chart:
     - the points one record puts at one place (a path passing a vertex of
       S, or leaving a model vertex that lies on a quad's edge) are one
       point: only the quad after them counts;
     - a segment along an edge of S lies in both quads there; the record
       picks one, the triangle needs the one on its side (to the left);
     - the segments' maps are chained from the first (the identity): the
       same quad, the quad across the edge through the point, or clockwise
       around a corner (tt__split_next_map).
   *linked is 1 when every step of that holds; *chart is 1 when, moreover,
   the chain comes back to the first quad in the same frame and every
   split point lies on the straight chart triangle (no cone point of S
   inside, no bend at a saddle). 0 when out of memory. */
static int tt__split_walk(tt__split *S, int f, int *linked, int *chart)
{
    const tt_mesh *mesh = S->mesh, *s = S->pc->surface;
    const tt_polycube_edges *E = S->edges;
    tt_quad_map identity, closing;
    const int last_edge = E->edge_of_halfedge[mesh->face_start[f] + 2];
    /* The quad the last edge reaches vertex 0 in, where the walk starts. */
    const int first_quad = E->end_quads[2 * last_edge + (E->edge_vertices[2 * last_edge] == S->vert[2])];
    int k, i, n, quad = first_quad, holds = 1;
    double st[2];
    identity.turns = identity.offset[0] = identity.offset[1] = 0;
    closing = identity;
    S->nboundary = 0;
    for (k = 0; k < 3; k++) {
        int v = S->vert[k], e = E->edge_of_halfedge[mesh->face_start[f] + k];
        int forward = E->edge_vertices[2 * e] == v, first = E->first_crossing[e];
        int count = E->first_crossing[e + 1] - first, leaves = E->end_quads[2 * e + !forward];
        /* The edge before reached v's point in `quad`, this one leaves it in `leaves`: both v's own quad,
           unless v is on a corner of S (tt_polycube_edges.end_quads). */
        holds = holds && !E->failed[e] && tt__point_in_quad(s, S->points[v], quad, st);
        if (!tt__split_push(S, v, quad, st, st)) return 0;
        if (leaves != quad) {
            double st_leaving[2];
            holds = holds && tt__point_in_quad(s, S->points[v], leaves, st_leaving);
            if (!tt__split_push(S, v, leaves, st, st_leaving)) return 0;
            quad = leaves;
        }
        for (i = 0; i < count; i++) {
            int j = forward ? first + i : first + count - 1 - i, vertex, kh, st0[2], st1[2];
            tt_edge_crossing x = E->crossings[j];
            int h = forward ? x.halfedge : s->twin[x.halfedge];
            double along = forward ? x.along : 1.0 - x.along, st_in[2];
            vertex = tt__split_crossing_vertex(S, e, j);
            if (vertex < 0) return 0;
            holds = holds && s->corner_face[h] == quad;
            kh = h - s->face_start[s->corner_face[h]];
            tt__quad_corner_st(kh, st0);
            tt__quad_corner_st(kh + 1, st1);
            st_in[0] = st0[0] + along * (st1[0] - st0[0]);
            st_in[1] = st0[1] + along * (st1[1] - st0[1]);
            quad = s->corner_face[s->twin[h]];
            kh = s->twin[h] - s->face_start[quad];
            tt__quad_corner_st(kh, st0);
            tt__quad_corner_st(kh + 1, st1);
            st[0] = st1[0] + along * (st0[0] - st1[0]);
            st[1] = st1[1] + along * (st0[1] - st1[1]);
            if (!tt__split_push(S, vertex, quad, st_in, st)) return 0;
        }
    }
    holds = holds && quad == first_quad && tt__point_in_quad(s, S->points[S->vert[0]], quad, st);
    S->boundary[S->nboundary - 1].b[0] = st[0];
    S->boundary[S->nboundary - 1].b[1] = st[1];
    *linked = *chart = 0;
    if (!holds) return 1;
    /* One point per place: a run of points with one output vertex keeps the first's place on the segment
       before and the last's segment after. */
    n = 0;
    for (i = 0; i < S->nboundary; i++) {
        if (n > 0 && S->boundary[n - 1].vertex == S->boundary[i].vertex) {
            S->boundary[n - 1].quad = S->boundary[i].quad;
            S->boundary[n - 1].a[0] = S->boundary[i].a[0];
            S->boundary[n - 1].a[1] = S->boundary[i].a[1];
            S->boundary[n - 1].b[0] = S->boundary[i].b[0];
            S->boundary[n - 1].b[1] = S->boundary[i].b[1];
            continue;
        }
        S->boundary[n++] = S->boundary[i];
    }
    /* The run around vertex 0 wraps: its last points' segments have no length. */
    while (n > 1 && S->boundary[n - 1].vertex == S->boundary[0].vertex) n--;
    S->nboundary = n;
    if (n < 3) return 1;
    /* Segments along an edge of S, on its far side: into the quad on the triangle's side. */
    for (i = 0; i < n; i++) {
        tt__split_point *p = &S->boundary[i];
        int edge = tt__square_edge_of(p->a, p->b), st0[2], st1[2];
        double along_edge;
        if (edge < 0) continue;
        tt__quad_corner_st(edge, st0);
        tt__quad_corner_st(edge + 1, st1);
        along_edge = (p->b[0] - p->a[0]) * (st1[0] - st0[0]) + (p->b[1] - p->a[1]) * (st1[1] - st0[1]);
        if (along_edge < 0.0) {
            int h = s->face_start[p->quad] + edge;
            tt_quad_map back = tt_polycube_unfold(S->pc, s->twin[h]);
            double a[2], b[2];
            tt_quad_map_apply(back, p->a[0], p->a[1], a);
            tt_quad_map_apply(back, p->b[0], p->b[1], b);
            p->quad = s->corner_face[s->twin[h]];
            p->a[0] = a[0];
            p->a[1] = a[1];
            p->b[0] = b[0];
            p->b[1] = b[1];
        }
    }
    /* The chain of maps. */
    S->boundary[0].map = identity;
    for (i = 1; i <= n; i++) {
        const tt__split_point *p = &S->boundary[i - 1];
        tt_quad_map next;
        if (!tt__split_next_map(S, p->quad, p->map, p->b, S->boundary[i % n].quad, &next)) return 1;
        if (i < n) S->boundary[i].map = next;
        else closing = next;
    }
    for (i = 0; i < n; i++) {
        tt__split_point *p = &S->boundary[i];
        double before[2];
        tt_quad_map_apply(p->map, p->a[0], p->a[1], p->at);
        tt_quad_map_apply(S->boundary[(i + n - 1) % n].map, S->boundary[(i + n - 1) % n].b[0],
                          S->boundary[(i + n - 1) % n].b[1], before);
        if (i > 0 && fabs(before[0] - p->at[0]) + fabs(before[1] - p->at[1]) > TT__SPLIT_MATCH) return 1;
    }
    *linked = 1;
    for (k = 0; k < 3; k++) {
        for (i = 0; i < n && S->boundary[i].vertex != S->vert[k]; i++) continue;
        if (i == n) return 1;
        S->side_start[k] = i;
        S->corner[k][0] = S->boundary[i].at[0];
        S->corner[k][1] = S->boundary[i].at[1];
    }
    if (S->side_start[0] != 0 || S->side_start[1] > S->side_start[2]) return 1;
    holds = tt__quad_map_equal(closing, identity);
    for (k = 0; k < 3 && holds; k++) {
        const double *a = S->corner[k], *b = S->corner[(k + 1) % 3];
        int end = k < 2 ? S->side_start[k + 1] : n;
        for (i = S->side_start[k] + 1; i < end && holds; i++)
            holds = tt__point_segment_distance(S->boundary[i].at[0], S->boundary[i].at[1], a[0], a[1], b[0], b[1]) <=
                    TT__SPLIT_MATCH;
    }
    *chart = holds;
    return 1;
}

/* The stretch of segment e0 -> e1 (in the chart) strictly inside the
   chart triangle (counter-clockwise), as the parameter interval's length. */
static double tt__split_inside_length(const tt__split *S, const double e0[2], const double e1[2])
{
    double lo = 0.0, hi = 1.0;
    int i;
    for (i = 0; i < 3; i++) {
        const double *a = S->corner[i], *b = S->corner[(i + 1) % 3];
        double f0 = tt__orient2(a[0], a[1], b[0], b[1], e0[0], e0[1]) - TT__SPLIT_AREA;
        double f1 = tt__orient2(a[0], a[1], b[0], b[1], e1[0], e1[1]) - TT__SPLIT_AREA;
        if (f0 <= 0.0 && f1 <= 0.0) return 0.0;
        if (f0 <= 0.0) {
            double u = f0 / (f0 - f1);
            if (u > lo) lo = u;
        } else if (f1 <= 0.0) {
            double u = f0 / (f0 - f1);
            if (u < hi) hi = u;
        }
    }
    return hi - lo;
}

static tt__split_cell *tt__split_cell_at(tt__split *S, tt_quad_map map)
{
    double centre[2];
    int x, y;
    tt_quad_map_apply(map, 0.5, 0.5, centre);
    x = (int)floor(centre[0]) - S->box[0];
    y = (int)floor(centre[1]) - S->box[1];
    if (x < 0 || y < 0 || x >= S->box[2] || y >= S->box[3]) return NULL;
    return &S->cells[x + S->box[2] * y];
}

/* Give the chart's cells their quads: the boundary's quads first, then
   across every side of S a known cell shares with a neighbour where the
   side passes through the triangle. 0 when two ways disagree: a cone point
   of S (3, 5 or 6 quads around it) inside the triangle. */
static int tt__split_cells(tt__split *S)
{
    const tt_mesh *s = S->pc->surface;
    int ncells = S->box[2] * S->box[3], head = 0, tail = 0, i, k;
    for (i = 0; i < ncells; i++) S->cells[i].quad = -1;
    for (i = 0; i < S->nboundary; i++) {
        tt__split_cell *cell = tt__split_cell_at(S, S->boundary[i].map);
        if (!cell) continue;
        if (cell->quad < 0) {
            cell->quad = S->boundary[i].quad;
            cell->map = S->boundary[i].map;
            S->queue[tail++] = (int)(cell - S->cells);
        } else if (cell->quad != S->boundary[i].quad || !tt__quad_map_equal(cell->map, S->boundary[i].map)) {
            return 0;
        }
    }
    while (head < tail) {
        tt__split_cell from = S->cells[S->queue[head++]];
        for (k = 0; k < 4; k++) {
            int h = s->face_start[from.quad] + k;
            double e0[2], e1[2];
            tt__split_cell *cell;
            tt_quad_map map;
            tt__edge_in_plane(s, h, from.map, e0, e1);
            if (tt__split_inside_length(S, e0, e1) <= TT__EDGE_EPS) continue;
            map = tt_quad_map_compose(from.map, tt_polycube_unfold(S->pc, h));
            cell = tt__split_cell_at(S, map);
            if (!cell) continue;
            if (cell->quad < 0) {
                cell->quad = s->corner_face[s->twin[h]];
                cell->map = map;
                S->queue[tail++] = (int)(cell - S->cells);
            } else if (cell->quad != s->corner_face[s->twin[h]] || !tt__quad_map_equal(cell->map, map)) {
                return 0;
            }
        }
    }
    return 1;
}

/* The sides of the chart triangle a clipped point lies on, as bits. */
static int tt__clip_sides(const tt__clip_point *c)
{
    if (c->kind == TT__CLIP_CORNER) return (1 << c->index) | (1 << ((c->index + 2) % 3));
    return c->kind == TT__CLIP_SIDE ? 1 << c->index : 0;
}

/* Sutherland-Hodgman: the part of polygon in[0..n) with sign * (x[axis] -
   bound) >= 0, into out; its size. A cut between two points on one side
   of the triangle is on that side; any other cut runs along an earlier
   grid line, so it is a grid point. */
static int tt__split_clip(const tt__clip_point *in, int n, int axis, double bound, double sign, tt__clip_point *out)
{
    int i, m = 0;
    for (i = 0; i < n; i++) {
        const tt__clip_point *p = &in[i], *q = &in[(i + 1) % n];
        double dp = sign * (p->p[axis] - bound), dq = sign * (q->p[axis] - bound);
        if (dp >= 0.0) out[m++] = *p;
        if ((dp < 0.0 && dq > 0.0) || (dp > 0.0 && dq < 0.0)) {
            double u = dp / (dp - dq);
            int common = tt__clip_sides(p) & tt__clip_sides(q), k;
            tt__clip_point *x = &out[m++];
            x->p[0] = p->p[0] + u * (q->p[0] - p->p[0]);
            x->p[1] = p->p[1] + u * (q->p[1] - p->p[1]);
            x->p[axis] = bound;
            x->kind = TT__CLIP_GRID;
            x->index = -1;
            x->axis = axis;
            x->bound = bound;
            for (k = 0; k < 3; k++)
                if (common & (1 << k)) {
                    x->kind = TT__CLIP_SIDE;
                    x->index = k;
                }
        }
    }
    return m;
}

static double tt__split_area(const tt__clip_point *p, int n)
{
    double area = 0.0;
    int i;
    for (i = 0; i < n; i++) area += p[i].p[0] * p[(i + 1) % n].p[1] - p[(i + 1) % n].p[0] * p[i].p[1];
    return 0.5 * area;
}

/* The output vertex of a piece's vertex, and its exact chart place, from
   the edge records where the piece meets the triangle's boundary:
     - a corner of the triangle is its vertex;
     - a cut of side k by a grid line is side k's split point on that line
       (the records put split points on S's edges, which are the chart's
       grid lines exactly), the nearest along it; a side's end on the line
       when no split point is (a vertex on S's edge);
     - a grid point is a boundary point lying on it (a record passing that
       corner of S) or else a vertex of its own, made once per triangle,
       interpolating the triangle's vertices with its barycentric
       coordinates in the chart; on a side it must be a boundary point.
   Marks the boundary points used. -1 when the records and the chart
   disagree, -2 when out of memory. */
static int tt__split_identify(tt__split *S, const tt__clip_point *c, double area2, double at[2])
{
    int i, x, y, k, best = -1;
    double weight[3], best_distance = HUGE_VAL;
    if (c->kind == TT__CLIP_CORNER) {
        i = S->side_start[c->index];
    } else if (c->kind == TT__CLIP_SIDE) {
        int first = S->side_start[c->index], end = c->index < 2 ? S->side_start[c->index + 1] : S->nboundary;
        int pass;
        for (pass = 0; pass < 2 && best < 0; pass++)
            for (i = pass ? first : first + 1; i <= (pass ? end : end - 1); i++) {
                const tt__split_point *q = &S->boundary[i % S->nboundary];
                double d = fabs(q->at[1 - c->axis] - c->p[1 - c->axis]);
                if (fabs(q->at[c->axis] - c->bound) <= 1e-9 && d < best_distance) {
                    best_distance = d;
                    best = i % S->nboundary;
                }
            }
        if (best < 0 || best_distance > TT__SPLIT_MATCH) return -1;
        i = best;
    } else {
        x = (int)floor(c->p[0] + 0.5);
        y = (int)floor(c->p[1] + 0.5);
        at[0] = x;
        at[1] = y;
        for (i = 0; i < S->nboundary; i++)
            if (fabs(S->boundary[i].at[0] - x) + fabs(S->boundary[i].at[1] - y) <= 1e-9) break;
        if (i == S->nboundary) {
            for (i = 0; i < S->ngrid; i++)
                if (S->grid_points[3 * i] == x && S->grid_points[3 * i + 1] == y) return S->grid_points[3 * i + 2];
            for (k = 0; k < 3; k++) {
                const double *a = S->corner[(k + 1) % 3], *b = S->corner[(k + 2) % 3];
                weight[k] = tt__orient2(a[0], a[1], b[0], b[1], at[0], at[1]) / area2;
                if (weight[k] <= TT__SPLIT_AREA) return -1;   /* on a side, where no record passes */
            }
            {
                int *grown = (int *)tt__grow(S->allocator, S->grid_points, &S->grid_capacity, 3 * (S->ngrid + 1),
                                             sizeof(int));
                if (!grown) return -2;
                S->grid_points = grown;
            }
            k = tt__split_vertex(S, S->vert, weight);
            if (k < 0) return -2;
            S->grid_points[3 * S->ngrid] = x;
            S->grid_points[3 * S->ngrid + 1] = y;
            S->grid_points[3 * S->ngrid + 2] = k;
            S->ngrid++;
            return k;
        }
    }
    S->boundary[i].used = 1;
    at[0] = S->boundary[i].at[0];
    at[1] = S->boundary[i].at[1];
    return S->boundary[i].vertex;
}

/* A convex piece (m output vertices at chart points `at`, in order) fanned
   into triangles of quad `cell`. The apex is a vertex from which no fan
   triangle is flat (points along one side of the piece are split points
   the neighbour shares: a flat triangle would drop them); when there is
   none, a new vertex at the piece's centroid. 0 when out of memory. */
static int tt__split_fan(tt__split *S, int f, const tt__split_cell *cell, const int *ids, double (*at)[2], int m,
                         double area2, int *pieces)
{
    int apex, i, j, centre = -1;
    double middle[2] = {0.0, 0.0};
    for (apex = 0; apex < m; apex++) {
        int flat = 0;
        for (i = 1; i + 1 < m && !flat; i++) {
            const double *a = at[apex], *b = at[(apex + i) % m], *c = at[(apex + i + 1) % m];
            flat = fabs(tt__orient2(a[0], a[1], b[0], b[1], c[0], c[1])) <= 2.0 * TT__SPLIT_AREA;
        }
        if (!flat) break;
    }
    if (apex == m) {
        double weight[3];
        int k;
        for (i = 0; i < m; i++) {
            middle[0] += at[i][0] / m;
            middle[1] += at[i][1] / m;
        }
        for (k = 0; k < 3; k++) {
            const double *a = S->corner[(k + 1) % 3], *b = S->corner[(k + 2) % 3];
            weight[k] = tt__orient2(a[0], a[1], b[0], b[1], middle[0], middle[1]) / area2;
        }
        centre = tt__split_vertex(S, S->vert, weight);
        if (centre < 0) return 0;
    }
    for (i = 0; i < (centre >= 0 ? m : m - 2); i++) {
        double st[3][2];
        int corners[3];
        const double *order[3];
        if (centre >= 0) {
            order[0] = middle;
            corners[0] = centre;
            order[1] = at[i];
            corners[1] = ids[i];
            order[2] = at[(i + 1) % m];
            corners[2] = ids[(i + 1) % m];
        } else {
            order[0] = at[apex];
            corners[0] = ids[apex];
            order[1] = at[(apex + i + 1) % m];
            corners[1] = ids[(apex + i + 1) % m];
            order[2] = at[(apex + i + 2) % m];
            corners[2] = ids[(apex + i + 2) % m];
        }
        for (j = 0; j < 3; j++) tt__quad_map_invert_point(cell->map, order[j], st[j]);
        if (!tt__split_triangle(S, f, cell->quad, corners, st)) return 0;
        (*pieces)++;
    }
    return 1;
}

/* Triangle f cut by the chart's grid into pieces, one per quad, each
   fanned into output triangles (P11 step 4). 1 when done, 0 when the chart
   does not allow it (the caller rolls back and takes the fallback), -1
   when out of memory. */
static int tt__split_pieces(tt__split *S, int f, int *pieces)
{
    double lo[2], hi[2], area2;
    int k, x, y, ncells, i;
    area2 = tt__orient2(S->corner[0][0], S->corner[0][1], S->corner[1][0], S->corner[1][1], S->corner[2][0],
                        S->corner[2][1]);
    /* A chart turning clockwise is a fold of the projection the relaxation could not open: its pieces would
       show the texture mirrored; the fallback does not. */
    if (area2 <= 2.0 * TT__SPLIT_AREA) return 0;
    for (k = 0; k < 2; k++) {
        lo[k] = hi[k] = S->corner[0][k];
        if (S->corner[1][k] < lo[k]) lo[k] = S->corner[1][k];
        if (S->corner[2][k] < lo[k]) lo[k] = S->corner[2][k];
        if (S->corner[1][k] > hi[k]) hi[k] = S->corner[1][k];
        if (S->corner[2][k] > hi[k]) hi[k] = S->corner[2][k];
        if (hi[k] - lo[k] > TT__SPLIT_MAX_CELLS) return 0;
        S->box[k] = (int)floor(lo[k]);
        S->box[k + 2] = (int)ceil(hi[k]) - S->box[k];
        if (S->box[k + 2] < 1) S->box[k + 2] = 1;
    }
    ncells = S->box[2] * S->box[3];
    if (ncells > TT__SPLIT_MAX_CELLS) return 0;
    if (ncells > S->cell_capacity) {
        tt__free(S->allocator, S->cells);
        tt__free(S->allocator, S->queue);
        S->cells = TT__ALLOC(S->allocator, tt__split_cell, ncells);
        S->queue = TT__ALLOC(S->allocator, int, ncells);
        S->cell_capacity = S->cells && S->queue ? ncells : 0;
        if (!S->cell_capacity) return -1;
    }
    if (!tt__split_cells(S)) return 0;
    S->ngrid = 0;
    *pieces = 0;
    for (i = 0; i < S->nboundary; i++) S->boundary[i].used = 0;
    for (y = 0; y < S->box[3]; y++) {
        for (x = 0; x < S->box[2]; x++) {
            const tt__split_cell *cell = &S->cells[x + S->box[2] * y];
            tt__clip_point poly[8], tmp[8];
            double X = S->box[0] + x, Y = S->box[1] + y, at[8][2];
            int n = 3, m = 0, ids[8];
            for (i = 0; i < 3; i++) {
                tmp[i].p[0] = S->corner[i][0];
                tmp[i].p[1] = S->corner[i][1];
                tmp[i].kind = TT__CLIP_CORNER;
                tmp[i].index = i;
            }
            n = tt__split_clip(tmp, n, 0, X, 1.0, poly);
            n = tt__split_clip(poly, n, 0, X + 1.0, -1.0, tmp);
            n = tt__split_clip(tmp, n, 1, Y, 1.0, poly);
            n = tt__split_clip(poly, n, 1, Y + 1.0, -1.0, tmp);
            if (n < 3 || fabs(tt__split_area(tmp, n)) <= TT__SPLIT_AREA) continue;
            if (cell->quad < 0) return 0;
            for (i = 0; i < n; i++) {
                double place[2];
                int id = tt__split_identify(S, &tmp[i], area2, place);
                if (id == -2) return -1;
                if (id < 0) return 0;
                if (m > 0 && ids[m - 1] == id) continue;
                at[m][0] = place[0];
                at[m][1] = place[1];
                ids[m++] = id;
            }
            if (m > 1 && ids[m - 1] == ids[0]) m--;
            if (m >= 3 && !tt__split_fan(S, f, cell, ids, at, m, area2, pieces)) return -1;
        }
    }
    /* Every split point of the records must be a corner of some piece, or the neighbour across would meet
       this triangle at a vertex it does not have. */
    for (i = 0; i < S->nboundary; i++)
        if (!S->boundary[i].used) return 0;
    return 1;
}

/* Boundary point i of a triangle (and the next, along the segment i ->
   i + 1 in point i's quad) relative to the S vertex at corner `corner_st`
   of that quad. */
static void tt__split_segment_from(const tt__split *S, int i, const int corner_st[2], double x[2], double y[2])
{
    const tt__split_point *p = &S->boundary[i];
    x[0] = p->a[0] - corner_st[0];
    x[1] = p->a[1] - corner_st[1];
    y[0] = p->b[0] - corner_st[0];
    y[1] = p->b[1] - corner_st[1];
}

/* The area of the 3D triangle of output vertices a, b and of point p. */
static double tt__split_area3(const tt__split *S, int a, int b, const double p[3])
{
    const float *x = S->out->positions + 3 * a, *y = S->out->positions + 3 * b;
    double u[3], v[3], n[3];
    int k;
    for (k = 0; k < 3; k++) {
        u[k] = (double)x[k] - p[k];
        v[k] = (double)y[k] - p[k];
    }
    tt__cross3(u, v, n);
    return 0.5 * tt__length3(n);
}

/* P11 step 4.3, for a triangle whose chart does not close or is not flat
   (a cone point of S inside it, or a bend at a saddle on an edge): when
   every quad its boundary passes is around one S vertex V, the triangle
   is the fan from V over its boundary, each boundary segment with V a
   triangle inside that segment's quad. It holds when the angles at V add
   up to V's full angle (a quarter turn per quad: V inside) or V is on the
   boundary, and no fan triangle of non-zero area on the model turns
   clockwise on S (the projection folds there). One of zero area on S is
   kept: where two edges of the triangle pass through V (a point next to a
   saddle of S, whose shortest paths to both sides run through it), the
   corner between them collapses onto a line, a sliver of stretched
   texture rather than the seam of the fallback. A V inside
   becomes a new output vertex at the boundary's mean value coordinates
   seen from V (exact where S is flat), so it lies on the triangle and the
   fan covers it exactly. 1 when done, 0 when no V works, -1 when out of
   memory. */
static int tt__split_star(tt__split *S, int f, double area, int *pieces)
{
    const tt_mesh *s = S->pc->surface;
    const int n = S->nboundary;
    int c, i, k;
    for (c = 0; c < 4; c++) {
        const int apex = s->corner_vert[s->face_start[S->boundary[0].quad] + c];
        int on_boundary = -1, holds = 1, centre = -1;
        double total = 0.0, sum = 0.0, weight[3] = {0.0, 0.0, 0.0}, position[3] = {0.0, 0.0, 0.0};
        for (i = 0; i < n && holds; i++) holds = tt__quad_corner_of(s, S->boundary[i].quad, apex) >= 0;
        if (!holds) continue;
        for (i = 0; i < n; i++) {
            int v[2];
            double x[2], y[2];
            tt__quad_corner_st(tt__quad_corner_of(s, S->boundary[i].quad, apex), v);
            tt__split_segment_from(S, i, v, x, y);
            if (fabs(x[0]) + fabs(x[1]) <= TT__SPLIT_MATCH) on_boundary = i;
            else if (fabs(y[0]) + fabs(y[1]) > TT__SPLIT_MATCH) total += tt__turn_angle(x, y);
        }
        if (on_boundary >= 0) {
            centre = S->boundary[on_boundary].vertex;
            for (k = 0; k < 3; k++) position[k] = S->out->positions[3 * centre + k];
        } else {
            if (fabs(total - tt__surface_valence(s, s->face_start[S->boundary[0].quad] + c) * 0.5 * TT__PI) > 1e-6)
                continue;
            /* Mean value coordinates: w_i = (tan(a_(i-1) / 2) + tan(a_i / 2)) / r_i, a_i the angle at V
               from boundary point i to i + 1, r_i the distance from V to point i. */
            for (i = 0; i < n; i++) {
                const int p = S->boundary[i].vertex;
                int v[2], j;
                double x[2], y[2], w;
                tt__quad_corner_st(tt__quad_corner_of(s, S->boundary[i].quad, apex), v);
                tt__split_segment_from(S, i, v, x, y);
                w = tan(0.5 * tt__turn_angle(x, y));
                tt__quad_corner_st(tt__quad_corner_of(s, S->boundary[(i + n - 1) % n].quad, apex), v);
                tt__split_segment_from(S, (i + n - 1) % n, v, y, x);
                w = (w + tan(0.5 * tt__turn_angle(y, x))) / sqrt(x[0] * x[0] + x[1] * x[1]);
                sum += w;
                for (j = 0; j < 3; j++)
                    for (k = 0; k < 3; k++)
                        if (S->out->source[3 * p + j] == S->vert[k]) {
                            weight[k] += w * S->out->weights[3 * p + j];
                            break;
                        }
            }
            if (!(sum > 0.0)) continue;
            for (k = 0; k < 3; k++) {
                int a;
                weight[k] /= sum;
                for (a = 0; a < 3; a++) position[a] += weight[k] * S->mesh->pos[3 * S->vert[k] + a];
            }
        }
        for (i = 0; i < n && holds; i++) {
            int v[2];
            double x[2], y[2];
            if (i == on_boundary || (i + 1) % n == on_boundary ||
                S->boundary[i].vertex == S->boundary[(i + 1) % n].vertex ||
                S->boundary[i].vertex == centre || S->boundary[(i + 1) % n].vertex == centre)
                continue;
            /* A fan triangle flat on the model would drop its boundary segment, which the neighbour has. */
            if (tt__split_area3(S, S->boundary[i].vertex, S->boundary[(i + 1) % n].vertex, position) <= 1e-9 * area) {
                holds = 0;
                break;
            }
            tt__quad_corner_st(tt__quad_corner_of(s, S->boundary[i].quad, apex), v);
            tt__split_segment_from(S, i, v, x, y);
            holds = tt__orient2(0.0, 0.0, x[0], x[1], y[0], y[1]) >= -TT__SPLIT_AREA;
        }
        if (!holds) continue;
        if (centre < 0 && (centre = tt__split_vertex(S, S->vert, weight)) < 0) return -1;
        *pieces = 0;
        for (i = 0; i < n; i++) {
            const tt__split_point *p = &S->boundary[i], *q = &S->boundary[(i + 1) % n];
            int corners[3], v[2];
            double st[3][2];
            corners[0] = centre;
            corners[1] = p->vertex;
            corners[2] = q->vertex;
            if (corners[0] == corners[1] || corners[1] == corners[2] || corners[0] == corners[2]) continue;
            tt__quad_corner_st(tt__quad_corner_of(s, p->quad, apex), v);
            st[0][0] = v[0];
            st[0][1] = v[1];
            st[1][0] = p->a[0];
            st[1][1] = p->a[1];
            st[2][0] = p->b[0];
            st[2][1] = p->b[1];
            if (!tt__split_triangle(S, f, p->quad, corners, st)) return -1;
            (*pieces)++;
        }
        return 1;
    }
    return 0;
}

/* P11 step 7: triangle f whole in one quad - of its vertices' quads, the
   one facing most like it - its boundary (vertices and split points, so
   the neighbours meet it) fanned from its centroid. The paper's clamped
   projection onto the quad would fold a triangle that faces away from
   the quad, or squash one that overhangs it; instead the triangle is laid
   flat in its own plane (turned so that its axis nearest the quad's s
   runs along s), at the model's scale where the quad has room, shrunk
   to fit where not, and placed over its centroid's projection: a local
   seam, but every piece keeps its turn. 0 when out of memory. */
static int tt__split_fallback(tt__split *S, int f)
{
    const tt_polycube *pc = S->pc;
    int quad = S->points[S->vert[0]].quad, ids[3], i, n = 0, centre = -1, k, a;
    double edge1[3], edge2[3], normal[3], axis_s[3], axis_w[3], corner0[3], corner1[3], centroid[3] = {0, 0, 0};
    double best = -HUGE_VAL, lo[2] = {0.0, 0.0}, hi[2] = {0.0, 0.0}, scale = 1.0, place[2], st[3][2];
    tt_surface_point q;
    tt__sub3f(S->mesh->pos + 3 * S->vert[1], S->mesh->pos + 3 * S->vert[0], edge1);
    tt__sub3f(S->mesh->pos + 3 * S->vert[2], S->mesh->pos + 3 * S->vert[0], edge2);
    tt__cross3(edge1, edge2, normal);
    for (k = 0; k < 3; k++) {
        int candidate = S->points[S->vert[k]].quad, side = pc->quad_side[candidate];
        double facing = (side % 2 ? -1.0 : 1.0) * normal[side / 2];
        if (facing > best) {
            best = facing;
            quad = candidate;
        }
    }
    for (i = 0; i < S->nboundary; i++) {
        int id = S->boundary[i].vertex;
        if (n > 0 && S->boundary[n - 1].vertex == id) continue;
        S->boundary[n++].vertex = id;
    }
    if (n > 1 && S->boundary[n - 1].vertex == S->boundary[0].vertex) n--;
    /* The triangle's frame: s along the quad's s laid into the plane (or along its first edge where the
       planes are square to each other), w a quarter turn on, counter-clockwise about the normal. */
    q.quad = quad;
    q.s = q.t = 0.0f;
    tt_polycube_point_position(pc, q, corner0);
    q.s = 1.0f;
    tt_polycube_point_position(pc, q, corner1);
    tt__normalize3(normal);
    for (a = 0; a < 3; a++) axis_s[a] = corner1[a] - corner0[a];
    for (a = 0; a < 3; a++) axis_s[a] -= tt__dot3(axis_s, normal) * normal[a];
    if (tt__normalize3(axis_s) < 1e-3 * pc->h) {
        for (a = 0; a < 3; a++) axis_s[a] = edge1[a];
        tt__normalize3(axis_s);
    }
    tt__cross3(normal, axis_s, axis_w);
    for (k = 0; k < 3; k++)
        for (a = 0; a < 3; a++) centroid[a] += S->mesh->pos[3 * S->vert[k] + a] / 3.0;
    for (i = 0; i < n; i++) {
        double d[3], x[2];
        for (a = 0; a < 3; a++) d[a] = ((double)S->out->positions[3 * S->boundary[i].vertex + a] - centroid[a]) / pc->h;
        x[0] = tt__dot3(d, axis_s);
        x[1] = tt__dot3(d, axis_w);
        S->boundary[i].at[0] = x[0];
        S->boundary[i].at[1] = x[1];
        for (a = 0; a < 2; a++) {
            if (x[a] < lo[a]) lo[a] = x[a];
            if (x[a] > hi[a]) hi[a] = x[a];
        }
    }
    for (a = 0; a < 2; a++)
        if (hi[a] - lo[a] > 0.0 && 1.0 / (hi[a] - lo[a]) < scale) scale = 1.0 / (hi[a] - lo[a]);
    {
        double lattice[3];
        for (a = 0; a < 3; a++) lattice[a] = (centroid[a] - pc->origin[a]) / pc->h;
        q = tt__polycube_surface_point(pc, quad, lattice);
        place[0] = q.s;
        place[1] = q.t;
    }
    for (a = 0; a < 2; a++) {
        if (place[a] + scale * lo[a] < 0.0) place[a] = -scale * lo[a];
        if (place[a] + scale * hi[a] > 1.0) place[a] = 1.0 - scale * hi[a];
    }
    if (n > 3) {
        double third[3] = {1.0 / 3.0, 1.0 / 3.0, 1.0 / 3.0};
        centre = tt__split_vertex(S, S->vert, third);
        if (centre < 0) return 0;
    }
    for (i = 0; i < (n > 3 ? n : 1); i++) {
        for (k = 0; k < 3; k++) {
            const int b = n > 3 ? (i + k - 1) % n : k;
            const double *x = n > 3 && k == 0 ? NULL : S->boundary[b].at;
            ids[k] = n > 3 && k == 0 ? centre : S->boundary[b].vertex;
            st[k][0] = place[0] + (x ? scale * x[0] : 0.0);
            st[k][1] = place[1] + (x ? scale * x[1] : 0.0);
        }
        if (!tt__split_triangle(S, f, quad, ids, st)) return 0;
    }
    return 1;
}

TTDEF void tt_polycube_mapping_free(tt_polycube_mapping *mapping)
{
    tt_allocator allocator;
    if (!mapping) return;
    allocator = mapping->allocator;
    tt__free(&allocator, mapping->positions);
    tt__free(&allocator, mapping->source);
    tt__free(&allocator, mapping->weights);
    tt__free(&allocator, mapping->triangles);
    tt__free(&allocator, mapping->triangle_face);
    tt__free(&allocator, mapping->corner_points);
    tt__free(&allocator, mapping);
}

TTDEF tt_result tt_polycube_map(const tt_polycube *polycube, const tt_mesh *mesh,
                                const tt_polycube_map_options *options, const tt_allocator *allocator,
                                tt_polycube_mapping **out, tt_polycube_map_report *report, tt_error *error)
{
    tt_polycube_map_report local;
    tt_polycube_edge_options edge_options;
    tt_surface_point *points = NULL, *earlier = NULL;
    unsigned char *moved = NULL, *focus = NULL;
    tt_polycube_edges *edges = NULL;
    const tt_mesh *model;
    tt__refined R;
    tt__split S;
    tt_result result;
    double longest;
    int f, v, j, tracing, cycle, moves, max_quads;
    tt__ok(error);
    if (out) *out = NULL;
    if (!report) report = &local;
    memset(report, 0, sizeof *report);
    memset(&S, 0, sizeof S);
    memset(&R, 0, sizeof R);
    if (!polycube || !mesh || !out)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "tt_polycube_map needs a polycube, a mesh and out (got NULL)");
    if (tt__check_allocator(allocator, error) != TT_OK) return TT_ERROR_INVALID_ARGUMENT;
    memset(&edge_options, 0, sizeof edge_options);
    if (options) edge_options.max_quads = options->max_quads;
    max_quads = edge_options.max_quads ? edge_options.max_quads : TT_POLYCUBE_EDGE_DEFAULT_QUADS;
    if (mesh->nfaces <= 0) return tt__fail(error, TT_ERROR_EMPTY_MESH, -1, -1, -1, -1, "the mesh has no faces");
    for (f = 0; f < mesh->nfaces; f++)
        if (mesh->face_start[f + 1] - mesh->face_start[f] != 3)
            return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, f, -1, -1, -1,
                            "face %d has %d corners: tt_polycube_map needs triangles (split the faces into fans "
                            "first)", f, mesh->face_start[f + 1] - mesh->face_start[f]);
    if (!tt__polycube_consistent(polycube))
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "the polycube's surface has no quads or does not match its cubes: make it with "
                        "tt_polycube_build and leave it unchanged");
    longest = options && options->max_edge != 0.0 ? options->max_edge : TT_POLYCUBE_MAP_DEFAULT_EDGE * polycube->h;
    if (!(longest > 0.0))
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "max_edge %g: give a length above 0 (0 for the default, HUGE_VAL for no refinement)",
                        options->max_edge);
    if ((result = tt__polycube_refine(mesh, longest, allocator, &R, error)) != TT_OK) goto failed;
    model = R.mesh ? R.mesh : mesh;
    report->triangles = model->nfaces;
    points = TT__ALLOC(allocator, tt_surface_point, model->nverts > 0 ? model->nverts : 1);
    if (!points) goto out_of_memory;
    if ((result = tt_polycube_project(polycube, model, allocator, points, &report->projection, error)) != TT_OK)
        goto failed;
    /* A point within TT__MAP_SNAP of a quad's edge is on it: the points are float (and the projection adds
       its rounding), and a model vertex on a lattice line (a CAD part's edge, a face in a lattice plane) must
       be on S's edge exactly, or the edges through that corner of S split next to it into slivers. */
    for (v = 0; v < model->nverts; v++) {
        points[v].s = points[v].s < TT__MAP_SNAP ? 0.0f : (points[v].s > 1.0f - TT__MAP_SNAP ? 1.0f : points[v].s);
        points[v].t = points[v].t < TT__MAP_SNAP ? 0.0f : (points[v].t > 1.0f - TT__MAP_SNAP ? 1.0f : points[v].t);
    }
    if ((report->relaxed = tt__polycube_relax(polycube, model, points, NULL, allocator)) < 0) goto out_of_memory;
    if ((result = tt_polycube_trace_edges(polycube, model, points, model->nverts, &edge_options, allocator, &edges,
                                          error)) != TT_OK)
        goto failed;
    if (!(earlier = TT__ALLOC(allocator, tt_surface_point, model->nverts)) ||
        !(moved = TT__ALLOC(allocator, unsigned char, model->nverts)) ||
        !(focus = TT__ALLOC(allocator, unsigned char, model->nverts)))
        goto out_of_memory;
    /* Vertices with an edge that finds no path are re-seated (tt__polycube_reseat) and their edges traced
       again, up to TT__RESEAT_ROUNDS times; the relaxation then opens the folds that leaves near them, and
       the edges at the points it moved are traced again. */
    for (cycle = 0; cycle < TT__RESEAT_CYCLES && edges->nfailed > 0; cycle++) {
        int reseated = 0, round, e;
        memset(focus, 0, (size_t)model->nverts);
        for (round = 0; round < TT__RESEAT_ROUNDS && edges->nfailed > 0; round++) {
            int n, failed_before = edges->nfailed;
            memset(moved, 0, (size_t)model->nverts);
            if ((n = tt__polycube_reseat(polycube, model, edges, max_quads, points, moved, allocator)) < 0)
                goto out_of_memory;
            if (!n) break;
            reseated += n;
            for (v = 0; v < model->nverts; v++) focus[v] |= moved[v];
            if ((result = tt__retrace_moved(polycube, model, points, &edge_options, allocator, moved, &edges,
                                            error)) != TT_OK)
                goto failed;
            if (edges->nfailed >= failed_before) break;
        }
        if (!reseated) break;
        /* The relaxation looks only near the re-seated points: elsewhere it has done what it can. */
        for (round = 0; round < TT__RESEAT_FOCUS_RINGS; round++) {
            for (e = 0; e < edges->nedges; e++) {
                const int a = edges->edge_vertices[2 * e], b = edges->edge_vertices[2 * e + 1];
                if (focus[a] == 1 && !focus[b]) focus[b] = 2;
                if (focus[b] == 1 && !focus[a]) focus[a] = 2;
            }
            for (v = 0; v < model->nverts; v++) focus[v] = focus[v] != 0;
        }
        memcpy(earlier, points, sizeof *points * (size_t)model->nverts);
        if ((moves = tt__polycube_relax(polycube, model, points, focus, allocator)) < 0) goto out_of_memory;
        report->relaxed += moves;
        for (v = 0; v < model->nverts; v++)
            moved[v] = !tt__same_point(points[v], earlier[v]);
        if ((result = tt__retrace_moved(polycube, model, points, &edge_options, allocator, moved, &edges, error)) !=
            TT_OK)
            goto failed;
    }
    /* Spikes (tt__polycube_unspike) are taken off and the edges at the moved points traced again; a
       vertex whose edges then find no path goes back where it was, and its edges are traced once more. */
    memcpy(earlier, points, sizeof *points * (size_t)model->nverts);
    memset(moved, 0, (size_t)model->nverts);
    for (tracing = 0; tracing < 2; tracing++) {
        int changed = 0, c;
        if (tracing == 0) {
            if ((changed = tt__polycube_unspike(polycube, model, edges, points, moved, allocator)) < 0)
                goto out_of_memory;
        } else {
            memset(moved, 0, (size_t)model->nverts);
            for (c = 0; c < model->ncorners; c++) {
                v = model->corner_vert[c];
                if (!edges->failed[edges->edge_of_halfedge[c]] || tt__same_point(points[v], earlier[v])) continue;
                points[v] = earlier[v];
                moved[v] = 1;
                changed = 1;
            }
        }
        if (!changed) break;
        if ((result = tt__retrace_moved(polycube, model, points, &edge_options, allocator, moved, &edges, error)) !=
            TT_OK)
            goto failed;
    }
    report->failed_edges = edges->nfailed;

    S.pc = polycube;
    S.mesh = model;
    S.edges = edges;
    S.points = points;
    S.allocator = allocator;
    S.out = TT__ALLOC(allocator, tt_polycube_mapping, 1);
    if (!S.out) goto out_of_memory;
    memset(S.out, 0, sizeof *S.out);
    S.out->allocator = tt__allocator_copy(allocator);
    S.crossing_vertex = TT__ALLOC(allocator, int, edges->ncrossings > 0 ? edges->ncrossings : 1);
    if (!S.crossing_vertex) goto out_of_memory;
    for (j = 0; j < edges->ncrossings; j++) S.crossing_vertex[j] = -1;
    for (v = 0; v < model->nverts; v++) {
        int source[3];
        double weight[3] = {1.0, 0.0, 0.0};
        source[0] = source[1] = source[2] = v;
        if (tt__split_vertex(&S, source, weight) < 0) goto out_of_memory;
    }
    for (f = 0; f < model->nfaces; f++) {
        int linked = 0, chart = 0, pieces = 0, done = 0, k, kept_vertices, kept_triangles;
        for (k = 0; k < 3; k++) S.vert[k] = model->corner_vert[3 * f + k];
        if (!tt__split_walk(&S, f, &linked, &chart)) goto out_of_memory;
        kept_vertices = S.out->nverts;
        kept_triangles = S.out->ntriangles;
        if (chart) {
            done = tt__split_pieces(&S, f, &pieces);
            if (done < 0) goto out_of_memory;
        }
        if (!done && linked) {
            double p0[3];
            S.out->nverts = kept_vertices;
            S.out->ntriangles = kept_triangles;
            for (k = 0; k < 3; k++) p0[k] = S.out->positions[3 * S.vert[0] + k];
            done = tt__split_star(&S, f, tt__split_area3(&S, S.vert[1], S.vert[2], p0), &pieces);
            if (done < 0) goto out_of_memory;
        }
        if (!done) {
            S.out->nverts = kept_vertices;
            S.out->ntriangles = kept_triangles;
            if (!tt__split_fallback(&S, f)) goto out_of_memory;
            report->fallback_triangles++;
        }
    }
    /* Back to the input: each output vertex's refined sources become input vertices (at most 3, all of one
       input triangle), each output triangle's refined face its input face. */
    for (v = 0; v < S.out->nverts && R.mesh; v++) {
        int source[3], n = 0, k, i;
        double weight[3] = {0.0, 0.0, 0.0};
        for (k = 0; k < 3; k++) {
            int r = S.out->source[3 * v + k];
            double w = S.out->weights[3 * v + k];
            for (i = 0; i < 3 && w != 0.0; i++) {
                int u = R.source[3 * r + i], m;
                double wu = w * R.weight[3 * r + i];
                if (wu == 0.0) continue;
                for (m = 0; m < n && source[m] != u; m++) continue;
                if (m == n) {
                    if (n == 3) continue;
                    source[n++] = u;
                }
                weight[m] += wu;
            }
        }
        for (k = n; k < 3; k++) source[k] = n ? source[0] : R.source[3 * S.out->source[3 * v]];
        for (k = 0; k < 3; k++) {
            S.out->source[3 * v + k] = source[k];
            S.out->weights[3 * v + k] = (float)weight[k];
        }
    }
    {
        int *outputs_of_face = TT__ALLOC(allocator, int, mesh->nfaces);
        if (!outputs_of_face) goto out_of_memory;
        memset(outputs_of_face, 0, sizeof(int) * (size_t)mesh->nfaces);
        for (j = 0; j < S.out->ntriangles; j++) {
            if (R.face) S.out->triangle_face[j] = R.face[S.out->triangle_face[j]];
            outputs_of_face[S.out->triangle_face[j]]++;
        }
        for (f = 0; f < mesh->nfaces; f++) report->split_triangles += outputs_of_face[f] > 1;
        tt__free(allocator, outputs_of_face);
    }
    for (j = 0; j < S.out->ntriangles; j++) {
        const tt_surface_point *p = S.out->corner_points + 3 * j;
        double turn = tt__orient2(p[0].s, p[0].t, p[1].s, p[1].t, p[2].s, p[2].t);
        report->flipped += turn < -TT__SPLIT_AREA;
        report->collapsed += fabs(turn) <= TT__SPLIT_AREA;
    }
    tt__free(allocator, S.crossing_vertex);
    tt__free(allocator, S.boundary);
    tt__free(allocator, S.cells);
    tt__free(allocator, S.queue);
    tt__free(allocator, S.grid_points);
    tt_polycube_edges_free(edges);
    tt__free(allocator, earlier);
    tt__free(allocator, moved);
    tt__free(allocator, focus);
    tt__free(allocator, points);
    tt__refined_free(allocator, &R);
    *out = S.out;
    return TT_OK;
out_of_memory:
    result = tt__fail(error, TT_ERROR_OUT_OF_MEMORY, -1, -1, -1, -1, "out of memory mapping the mesh onto S");
failed:
    tt__free(allocator, S.crossing_vertex);
    tt__free(allocator, S.boundary);
    tt__free(allocator, S.cells);
    tt__free(allocator, S.queue);
    tt__free(allocator, S.grid_points);
    tt_polycube_mapping_free(S.out);
    tt_polycube_edges_free(edges);
    tt__free(allocator, earlier);
    tt__free(allocator, moved);
    tt__free(allocator, focus);
    tt__free(allocator, points);
    tt__refined_free(allocator, &R);
    memset(report, 0, sizeof *report);
    return result;
}

TTDEF int tt_polycube_quad_upright(const tt_polycube *polycube, int quad)
{
    TT_ASSERT(polycube && polycube->surface && quad >= 0 && quad < polycube->surface->nfaces);
    return polycube->quad_side[quad] / 2 != polycube->up_axis;
}

TTDEF tt_result tt_polycube_upright_atlas(const tt_tileset *plain, const tt_tileset *upright, int level,
                                          const tt_allocator *allocator, tt_image **out_image, tt_error *error)
{
    const tt_image *left, *right;
    tt_result result;
    int k, row;
    tt__ok(error);
    if (out_image) *out_image = NULL;
    if (!plain || !upright || !out_image)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "tt_polycube_upright_atlas needs a plain and an upright tileset and out_image (got NULL)");
    if (tt__check_allocator(allocator, error) != TT_OK) return TT_ERROR_INVALID_ARGUMENT;
    if (plain->vertical_windows || !upright->vertical_windows)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "the first tileset must be plain and the second upright (tt_synth_options.upright)");
    if (plain->layout.colors != upright->layout.colors || plain->layout.tile_size != upright->layout.tile_size ||
        plain->layout.gutter != upright->layout.gutter)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "the tilesets' layouts differ (%d colors, %d texels, gutter %d against %d, %d, %d)",
                        plain->layout.colors, plain->layout.tile_size, plain->layout.gutter, upright->layout.colors,
                        upright->layout.tile_size, upright->layout.gutter);
    for (k = 0; k < plain->layout.colors; k++)
        if (plain->edge_windows[k].x != upright->edge_windows[k].x ||
            plain->edge_windows[k].y != upright->edge_windows[k].y)
            return tt__fail_at(error, TT_ERROR_INVALID_ARGUMENT, k, -1, -1,
                               "edge window %d differs between the tilesets: make the upright tiles with the plain "
                               "ones' edge_windows, or the tops and the walls do not meet", k);
    if (level < 0 || level >= plain->nlevels || level >= upright->nlevels)
        return tt__fail(error, TT_ERROR_INDEX_OUT_OF_RANGE, -1, -1, -1, -1,
                        "level %d: the tilesets have levels 0 to %d", level,
                        tt__min_i(plain->nlevels, upright->nlevels) - 1);
    left = &plain->levels[level];
    right = &upright->levels[level];
    if ((result = tt_image_create(2 * left->width, left->height, allocator, out_image, error)) != TT_OK)
        return result;
    for (row = 0; row < left->height; row++) {
        float *out = (*out_image)->pixels + (size_t)row * 2 * (size_t)left->width * 4;
        memcpy(out, left->pixels + (size_t)row * left->width * 4, (size_t)left->width * 4 * sizeof(float));
        memcpy(out + (size_t)left->width * 4, right->pixels + (size_t)row * right->width * 4,
               (size_t)right->width * 4 * sizeof(float));
    }
    return TT_OK;
}

/* tt_polycube_mapping_uvs and its upright form: `upright` puts the walls'
   tiles in the right half of a 2W x W atlas. */
static tt_result tt__polycube_mapping_uvs(const tt_polycube *polycube, const tt_polycube_mapping *mapping,
                                          const tt_tile_layout *layout, const uint8_t *corner_type, int upright,
                                          float *corner_uv, tt_error *error)
{
    tt_tile_layout resolved;
    tt_result result;
    int i, q;
    tt__ok(error);
    if (!polycube || !polycube->surface || !mapping || !layout || !corner_type || !corner_uv)
        return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, -1, -1, -1, -1,
                        "tt_polycube_mapping_uvs needs a polycube, a mapping, a layout, corner types and corner_uv "
                        "(got NULL)");
    if ((result = tt_tile_layout_resolve(layout, &resolved, error)) != TT_OK) return result;
    for (q = 0; q < polycube->surface->ncorners; q++)
        if (corner_type[q] >= 2 * resolved.colors)
            return tt__fail(error, TT_ERROR_INVALID_ARGUMENT, q / 4, q, -1, -1,
                            "corner %d of S has type %d, beyond the layout's %d types (2 per colour)", q,
                            corner_type[q], 2 * resolved.colors);
    for (i = 0; i < 3 * mapping->ntriangles; i++)
        if (mapping->corner_points[i].quad < 0 || mapping->corner_points[i].quad >= polycube->surface->nfaces)
            return tt__fail(error, TT_ERROR_INDEX_OUT_OF_RANGE, i / 3, i, -1, -1,
                            "corner %d of the mapping names quad %d; S has %d", i, mapping->corner_points[i].quad,
                            polycube->surface->nfaces);
    for (i = 0; i < 3 * mapping->ntriangles; i++) {
        const tt_surface_point p = mapping->corner_points[i];
        const uint8_t *types = corner_type + polycube->surface->face_start[p.quad];
        float low[2], high[2];
        tt_tile_corner_uv(&resolved, types, 0, low);
        tt_tile_corner_uv(&resolved, types, 2, high);
        corner_uv[2 * i] = low[0] + p.s * (high[0] - low[0]);
        corner_uv[2 * i + 1] = low[1] + p.t * (high[1] - low[1]);
        if (upright) corner_uv[2 * i] = 0.5f * (corner_uv[2 * i] + (float)tt_polycube_quad_upright(polycube, p.quad));
    }
    return TT_OK;
}

TTDEF tt_result tt_polycube_mapping_uvs(const tt_polycube *polycube, const tt_polycube_mapping *mapping,
                                        const tt_tile_layout *layout, const uint8_t *corner_type,
                                        float *corner_uv, tt_error *error)
{
    return tt__polycube_mapping_uvs(polycube, mapping, layout, corner_type, 0, corner_uv, error);
}

TTDEF tt_result tt_polycube_mapping_uvs_upright(const tt_polycube *polycube, const tt_polycube_mapping *mapping,
                                                const tt_tile_layout *layout, const uint8_t *corner_type,
                                                float *corner_uv, tt_error *error)
{
    return tt__polycube_mapping_uvs(polycube, mapping, layout, corner_type, 1, corner_uv, error);
}

#ifdef __cplusplus
}
#endif

#endif /* TILEDTEX_IMPLEMENTATION_INCLUDED */
#endif /* TILEDTEX_IMPLEMENTATION */

/*
------------------------------------------------------------------------------
MIT License

Copyright (c) 2026 the tiledtex authors

Permission is hereby granted, free of charge, to any person obtaining a copy of
this software and associated documentation files (the "Software"), to deal in
the Software without restriction, including without limitation the rights to
use, copy, modify, merge, publish, distribute, sublicense, and/or sell copies
of the Software, and to permit persons to whom the Software is furnished to do
so, subject to the following conditions:

The above copyright notice and this permission notice shall be included in all
copies or substantial portions of the Software.

THE SOFTWARE IS PROVIDED "AS IS", WITHOUT WARRANTY OF ANY KIND, EXPRESS OR
IMPLIED, INCLUDING BUT NOT LIMITED TO THE WARRANTIES OF MERCHANTABILITY,
FITNESS FOR A PARTICULAR PURPOSE AND NONINFRINGEMENT. IN NO EVENT SHALL THE
AUTHORS OR COPYRIGHT HOLDERS BE LIABLE FOR ANY CLAIM, DAMAGES OR OTHER
LIABILITY, WHETHER IN AN ACTION OF CONTRACT, TORT OR OTHERWISE, ARISING FROM,
OUT OF OR IN CONNECTION WITH THE SOFTWARE OR THE USE OR OTHER DEALINGS IN THE
SOFTWARE.
------------------------------------------------------------------------------
*/
