/* pray — a portable CSG ray tracer with the PRAY scene language.
   MIT License, see LICENSE. The manual follows the declarations below.

   Two files are the whole library: pray.hpp (this header) and pray.cpp.
       c++ -O2 -c pray.cpp                      the library
       c++ -O2 -DPRAY_MAIN pray.cpp -o pray     the command-line program
*/
#ifndef PRAY_HPP
#define PRAY_HPP

#define PRAY_VERSION_MAJOR 0
#define PRAY_VERSION_MINOR 4
#define PRAY_VERSION_PATCH 0
#define PRAY_VERSION_STRING "0.4.0"

/* ---------------------------------------------------------------------------------------------
   Configuration. Every macro is optional; define it on the command line or in a header named by
   PRAY_USER_CONFIG. None of them changes the layout of a type declared here.

   @@ PRAY_USER_CONFIG "file.h"   include this file first (a port's settings, see ports/)
   @@ PRAY_REAL float|double      arithmetic of the renderer (default double); the API is double
   @@ PRAY_NO_INTERP              leave out the PRAY interpreter (pray_run_* fail with PRAY_ERR_ARG)
   @@ PRAY_NO_STDIO               no file access: write images through callbacks only
   @@ PRAY_NO_PNG                 no PNG output even when <stb/stb_image_write.h> is present
   @@ PRAY_NO_THREADS             no threads (DOS, bare targets)
   @@ PRAY_NO_BUFFERS             no light or eye buffers (options lightbuffer and eyebuffer then
                                  change nothing); the images stay the same, byte for byte
   @@ PRAY_NO_SEQUENCES           no image-sequence coherence (option coherence then changes
                                  nothing): every frame is traced in full, to the same bytes
   @@ PRAY_NO_DEFAULT_ALLOC       no malloc-based allocator: pray_new_with must be given one
   @@ PRAY_MAX_ALLOC bytes        default memory cap of a context (0 = none)
   @@ PRAY_TEMP_SUFFIX ".tmp"     ends the temporary name a file is written under
   @@ PRAY_MAIN                   compile the command-line program (main) from pray.cpp
   ------------------------------------------------------------------------------------------- */
#ifdef PRAY_USER_CONFIG
#include PRAY_USER_CONFIG
#endif

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

/* ---------------------------------------------------------------------------------------------
   Status codes. The numbers are stable; the detail is in the context's message.
   ------------------------------------------------------------------------------------------- */
typedef enum pray_status {
    PRAY_OK = 0,
    PRAY_ERR_NOMEM = 1,   /* out of memory, or over the context's memory cap */
    PRAY_ERR_IO = 2,      /* a file could not be read or written */
    PRAY_ERR_SYNTAX = 3,  /* the PRAY program is malformed */
    PRAY_ERR_RUNTIME = 4, /* the PRAY program failed while running (type error, ...) */
    PRAY_ERR_LIMIT = 5,   /* a limit was reached (maxsteps, image size, ...) */
    PRAY_ERR_ARG = 6,     /* a bad argument to an API function */
    PRAY_ERR_CANCELLED = 7 /* stopped by pray_cancel or by the progress callback */
} pray_status;

/* The text of a status code ("ok", "out of memory", ...). Never NULL. */
const char *pray_status_text(pray_status s);
/* "0.4.0". */
const char *pray_version(void);
/* The configuration compiled in, e.g. "interp stdio png threads real=double". */
const char *pray_features(void);

/* ---------------------------------------------------------------------------------------------
   Plain types. Coordinates are world coordinates, Z up by convention of the default camera.
   ------------------------------------------------------------------------------------------- */
typedef struct pray_vec { double x, y, z; } pray_vec; /* a point or a vector */
typedef struct pray_rgb { double r, g, b; } pray_rgb; /* an intensity; 1 = full */

/* A rendered image: width*height pixels, 3 floats each (R, G, B), rows from the top.
   Values are linear and may exceed 1; writers clamp to [0, 1]. The pixels of an image that
   pray_render made belong to its context, like its handles: pray_image_free frees them early,
   pray_free at the latest. Images you fill yourself can be written (pray_write_*), never freed
   by pray. */
typedef struct pray_image {
    int width, height;
    float *pixels;
} pray_image;

/* Opaque handles. All belong to the context that made them and die with it; another context
   refuses them. */
typedef struct pray_ctx pray_ctx;       /* one context per thread of use */
typedef struct pray_object pray_object; /* a solid: a primitive or a CSG tree */
typedef struct pray_model pray_model;   /* a lighting model (material) */
typedef struct pray_light pray_light;   /* a set of light sources */
typedef struct pray_texture pray_texture; /* a decoded TIFF image, for textures and fonts */

/* Callbacks and the context they are called from. While a callback runs, its context is in the
   middle of a call, and what the callback may do with that context is:
   - allocator: nothing (it is called with the context's own bookkeeping half done);
   - print, warning and byte sinks (pray_write_fn): pray_cancel, pray_error, pray_option_get;
   - progress: pray_cancel only (it runs on the render's threads);
   - frame callback and render function: everything a host does between calls (build objects,
     set options, render with pray_render and pray_render_into, write images, pray_set_error),
     except pray_run_string and pray_run_file, which refuse with PRAY_ERR_ARG ("the context is
     running a program"): a program runs on a context one at a time;
   - never pray_free.
   The image a frame callback gets lives until the callback returns; the handles a render
   function gets (root, lights) belong to the running program and live until its run ends,
   unless the host takes a reference of its own (pray_retain).
   Other contexts may be used freely from any callback. */

/* Memory: like Lua's lua_Alloc. nsize == 0 frees ptr and returns NULL; otherwise returns a block
   of nsize bytes holding the first min(osize, nsize) bytes of ptr (ptr may be NULL), or NULL. */
typedef void *(*pray_alloc_fn)(void *ud, void *ptr, size_t osize, size_t nsize);
/* Output of the PRAY `print` statement, and any byte sink (image writers). */
typedef void (*pray_write_fn)(void *ud, const void *data, size_t n);
/* Progress of a render: rows done of rows total, after each band of a few rows (not while the
   scene is prepared). Called on any of the render's threads (the caller's or a worker), one
   call at a time, `done` increasing: it must be thread-safe, and must not call pray on the same
   context except pray_cancel. Return non-zero to cancel: the render fails with
   PRAY_ERR_CANCELLED ("cancelled by the progress callback"). */
typedef int (*pray_progress_fn)(void *ud, int done, int total);
/* A frame rendered by `rendertiff`. When set, it is called instead of writing the file; `name` is
   the file name the frame would have been written to. Return PRAY_OK to continue. */
typedef pray_status (*pray_frame_fn)(void *ud, const pray_image *img, const char *name);

/* ---------------------------------------------------------------------------------------------
   Conventions of every function below, unless its comment says otherwise:
   - A failing call returns a status other than PRAY_OK (makers: NULL; others -1 or NaN as said)
     and leaves its message in pray_error(ctx) and its status in pray_last_status(ctx).
   - A NULL context: PRAY_ERR_ARG, NULL, -1 or NaN; void functions do nothing. Nothing is
     recorded anywhere (pray_error(NULL) is "error: no context").
   - A NULL handle (object, model, light, texture, scene): the call fails; "pray_f: no model" is
     recorded only when no failure is recorded yet, so a chain of calls keeps the message of its
     first failure (clear it with pray_clear_error). Releases and frees ignore NULL. Other NULL
     pointers (names, texts, buffers, callbacks that are needed) fail with a message always.
   - A handle, scene or image of another context is refused: PRAY_ERR_ARG, "pray_f: the model
     belongs to another context"; it is left alone.
   - What pray returns (handles, scenes, images) belongs to the context and dies with pray_free at
     the latest. Strings returned are pray's, valid until the next call on the context.
   - A context is used by one thread at a time (pray_cancel excepted).
   ------------------------------------------------------------------------------------------- */
/* A new context with the default allocator (malloc). NULL when out of memory, or when built
   with PRAY_NO_DEFAULT_ALLOC. */
pray_ctx *pray_new(void);
/* A new context with your allocator; every byte pray uses goes through it. NULL when alloc is
   NULL or fails. */
pray_ctx *pray_new_with(pray_alloc_fn alloc, void *ud);
/* Free the context and all that is left of what was made in it: handles, prepared scenes and
   rendered images. Pointers to them are dangling from here on. */
void pray_free(pray_ctx *ctx);
/* The last error: "name:line:col: error: message" for program errors, "error: message" else.
   "" when there was none. Valid until the next call on the context. */
const char *pray_error(const pray_ctx *ctx);
/* Where in a program the last error is, as numbers: the name as the message shows it (valid
   until the next call on the context), *line and *col from 1. NULL, 0 and 0 when the last error
   has no place in a program (or there is none). line and col may be NULL. */
const char *pray_error_place(const pray_ctx *ctx, int *line, int *col);
/* The status of the last failing call (PRAY_OK if none failed since pray_clear_error). */
pray_status pray_last_status(const pray_ctx *ctx);
/* Forget the last error: status PRAY_OK, message "". */
void pray_clear_error(pray_ctx *ctx);
/* Cap the bytes a context may hold at once (0 = no cap). Over the cap, calls fail with
   PRAY_ERR_NOMEM. Option maxmem (MiB) can lower the cap further, never raise it. */
void pray_set_memory_limit(pray_ctx *ctx, size_t bytes);
/* Untrusted mode, for programs from elsewhere; it cannot be turned off. Every limit option gets a
   ceiling (lowered to it now; a higher value, or 0 where 0 means "no limit", is refused later):
   depth 16, gridmem 64, maxframes 1000, maxline 4096, maxmem 1024, maxnest 64, maxoutput 1024,
   maxpixels 16777216, maxprims 1048576, maxsteps 1000000, maxstring 4096, maxtime 600, texmem 64.
   Texture and
   font files, and the files of `include`, named by a program are read only from the program's
   directory (relative names without "..", opened one directory at a time without following any
   symbolic link; on Windows and DOS links inside the directory are followed); an `output` set by
   a program must be a plain file name. */
void pray_set_untrusted(pray_ctx *ctx);
/* Where `print` writes (default: standard output; NULL fn discards). Called on the calling
   thread, during pray_run_*. */
void pray_set_print(pray_ctx *ctx, pray_write_fn fn, void *ud);
/* Where warnings go (default: nowhere; the command-line program writes them to standard error):
   one line each, "name:line:col: warning: message\n". A run warns once when the camera's
   |X| : |Y| differs from width : height by more than 1 % (the picture would come out stretched),
   and at every frame whose eye point is inside the object rendered ("the eye is inside the
   rendered solid"). */
void pray_set_warning(pray_ctx *ctx, pray_write_fn fn, void *ud);
/* Progress callback for renders (default none). */
void pray_set_progress(pray_ctx *ctx, pray_progress_fn fn, void *ud);
/* Frame callback for `rendertiff` (default none: frames are written to files). The image passed
   to it is freed when it returns. pray_frames(ctx) is the frame's number in the run (from 0).
   With a render function (pray_set_render) it gets what that function made of the frame. */
void pray_set_frame(pray_ctx *ctx, pray_frame_fn fn, void *ud);
/* The temporary file an image is being written to now (see pray_write_image), else NULL. For a
   signal handler that removes it before the program dies: reading it is async-signal-safe. */
const char *pray_temp_file(const pray_ctx *ctx);
/* Stop the call running on the context: pray_run_string, pray_run_file, pray_render,
   pray_render_into, pray_prepare, pray_prepare_render, pray_render_prepared, pray_write_image,
   pray_write_image_note, pray_write_tiff, pray_write_ppm or pray_write_png. Safe from any thread
   and from a signal handler: it only sets a flag. The call stops at its next check (each statement
   of a program; each row of voxels while a scene is prepared; each row of an image rendered or
   written) with PRAY_ERR_CANCELLED, "error: cancelled" (with the place in a program). It leaves no
   file behind and no image; a byte sink has got part of one, to be thrown away. One of those calls
   starting clears the flag: a cancel made when none runs, or just before one starts, is forgotten.
   A host that must not lose one keeps its own flag too and checks it between calls. Other
   functions ignore the flag. */
void pray_cancel(pray_ctx *ctx);

/* ---------------------------------------------------------------------------------------------
   Options: the same names as the PRAY `option` statement. Those of the image: width, height
   (pixels, default 256), depth (ray depth, 5), cutoff (1: leave out rays that, all together,
   could move no sample by half a step of the output; 0: the whole ray tree), antialias (samples
   per pixel side, 1), adaptive (0), shadows (1/0, default 1), bits (8 or 16 per sample in
   TIFF/PPM files), and the string option output (file name of `rendertiff`; its extension picks
   the format). Of the machine: threads (0 = automatic).

   Diagnostic options, for measuring the acceleration and comparing it with the reference; an
   image never needs them, and every value gives the image of brute=1, byte for byte (manual,
   section 6): brute (1 = the brute-force reference renderer, 0), grid (voxels along the longest
   side; -1 = automatic, 0 = no grid), nest (levels of nested grids, 2), and the switches of one
   part each, 1 = on (the default) and 0 = off: freeze, merge, bounds, lightbuffer, eyebuffer,
   shadowcache, plans, coherence (1: a program's frame with the camera, lights and options of
   the frame before re-traces only the pixels whose rays could have met what changed; 0: every
   pixel).

   Limits (each refuses with a message naming the option; see "Limits" in the manual below): depth
   as above; maxsteps (statements a program may execute, 10000000; 0 = no limit), gridmem (MiB for
   the grid, 64), texmem (MiB for textures, 256); maxline (characters on one line of a program,
   65536), maxnest (nesting of blocks, includes and expressions together, 256, at most 1024),
   maxstring (bytes of a string, literal or built, 65536), maxprims (primitives one object stands
   for, 16777216), maxpixels (samples of one image: width x height x antialias^2, 1073741824),
   maxrays (rays one sample may take, primary, reflected and refracted, 65536), maxmem (MiB a
   context may hold, 0 = no cap), maxframes (frames of a run, 0 = no limit), maxoutput (MiB of
   image files a run writes, 0 = no limit), maxtime (seconds a run may take, 0 = no limit). maxline
   and maxnest apply when a program is read, so only the host or the command line can change them
   for that program.

   What the host sets here (options, camera, background) is where every program run starts;
   what a program sets lasts until the end of its run.
   ------------------------------------------------------------------------------------------- */
/* Set a numeric option. Unknown names and bad values fail with PRAY_ERR_ARG. An option that was
   fixed by pray_option_fix keeps its fixed value and the call succeeds without effect. */
pray_status pray_option(pray_ctx *ctx, const char *name, double value);
/* Set the one string option, "output". */
pray_status pray_option_string(pray_ctx *ctx, const char *name, const char *value);
/* Set an option from its text (as `-D name=value` does) and fix it: later pray_option calls and
   `option` statements of programs no longer change it. This is how the command line wins. */
pray_status pray_option_fix(pray_ctx *ctx, const char *name, const char *value);
/* The value of a numeric option; NaN for an unknown name, "output" or a NULL argument. */
double pray_option_get(const pray_ctx *ctx, const char *name);

/* ---------------------------------------------------------------------------------------------
   Running PRAY programs.
   ------------------------------------------------------------------------------------------- */
/* Run a program held in memory. `name` is used in messages, for the default output name (name
   with its extension replaced by .tif) and as the place beside which texture files and the files
   of `include` are looked for (its directory). `text` need not be NUL-terminated. The whole
   program is checked before its first statement runs, so a malformed one runs none; it is then
   read again and run a statement at a time, holding only the current line's tokens and the
   current statement's tree. A file that `include` names (or the text registered under its name,
   pray_include_register) is read whole when the statement runs, checked, and run the same way;
   without file access (PRAY_NO_STDIO) including a name not registered is an error. */
pray_status pray_run_string(pray_ctx *ctx, const char *name, const char *text, size_t len);
/* Run a program file (a regular file; a FIFO, directory or device is refused); "-" reads
   standard input (named "stdin.ray" in messages). Reading stops at the first line longer than
   option maxline and holds to the memory cap, so an endless input ends in an error. Its images
   never replace it: an output naming the program file itself fails with PRAY_ERR_IO. */
pray_status pray_run_file(pray_ctx *ctx, const char *path);
/* The number of frames the last run rendered (0 for a NULL context); while a program runs, the
   frames it has rendered so far (so in a frame callback, the number of the frame, from 0). Frames
   a render function skipped count too. */
int pray_frames(const pray_ctx *ctx);

/* ---------------------------------------------------------------------------------------------
   Building scenes directly. Every maker returns a new handle, or NULL on error (see the
   conventions above: a NULL handle given to a maker keeps the message of the failure that made
   it, so a chain of calls can be checked once at its end). Handles are reference counted: what
   a maker makes holds the handles it was given, so you may release yours at once;
   pray_*_release drops yours, pray_free all.
   ------------------------------------------------------------------------------------------- */
/* Models. */
pray_model *pray_phong(pray_ctx *ctx, pray_rgb diffuse, pray_rgb specular, pray_rgb ambient,
                       double exponent);
pray_model *pray_mirror(pray_ctx *ctx, pray_rgb weight);
pray_model *pray_transparent(pray_ctx *ctx, pray_rgb weight, double index);
pray_model *pray_color(pray_ctx *ctx, pray_rgb colour);
pray_model *pray_model_add(pray_ctx *ctx, pray_model *a, pray_model *b);
pray_model *pray_model_scale(pray_ctx *ctx, pray_model *m, pray_rgb factor);

/* Textures: a TIFF file (a regular file, decoded once per context run, however often it is
   asked for), or TIFF data in memory (decoded at once; `name`, NULL for "texture", is used in
   messages). Baseline TIFF: bilevel, grey, palette, RGB(A); 1, 4, 8, 16 bits; strips or tiles;
   no compression, PackBits or LZW (with the horizontal predictor). */
pray_texture *pray_texture_file(pray_ctx *ctx, const char *path);
pray_texture *pray_texture_tiff(pray_ctx *ctx, const void *data, size_t size, const char *name);
/* Width and height of a texture in pixels (0 for NULL), and its colour at texel (x, y) (rows
   from the top; black for NULL or outside). Any context's texture, no context needed. */
void pray_texture_size(const pray_texture *tex, int *width, int *height);
pray_rgb pray_texture_pixel(const pray_texture *tex, int x, int y);
/* Textured models: m0 where the texture is 0 blended per channel into m1 where it is 1; m with
   its normal tilted by `amount` times the gradient of the texture's luminance; m with its texture
   coordinates shifted by (x, y) images. */
pray_model *pray_tiff(pray_ctx *ctx, pray_model *m0, pray_model *m1, pray_texture *tex);
pray_model *pray_tiffbump(pray_ctx *ctx, pray_model *m, double amount, pray_texture *tex);
pray_model *pray_move(pray_ctx *ctx, pray_model *m, double x, double y);
/* Language version 3, a checkered surface: m0 where floor(x/s) + floor(y/s) + floor(z/s) is even,
   m1 where it is odd (s > 0), (x, y, z) being the point in the coordinates of the primitive as it
   was made (or painted, pray_paint), so that the pattern moves, turns and stretches with it. On a
   face lying on a cell boundary the cell is that of the point a tiny step inside the solid: a
   floor at z = 0 shows whole squares. */
pray_model *pray_checker(pray_ctx *ctx, pray_model *m0, pray_model *m1, double s);

/* Solids. */
pray_object *pray_sphere(pray_ctx *ctx, pray_model *m, pray_vec centre, double radius);
pray_object *pray_plane(pray_ctx *ctx, pray_model *m, pray_vec point, pray_vec normal);
pray_object *pray_cylinder(pray_ctx *ctx, pray_model *m, pray_vec point, pray_vec axis,
                           double radius);
pray_object *pray_one(pray_ctx *ctx, pray_model *m);
/* Language version 2 (see the manual: box, rod, cone): an axis-aligned box with opposite corners
   p1 and p2 (each extent > 0); a finite cylinder with flat caps; a truncated cone from the disc
   of radius r1 around p1 to that of radius r2 around p2 (r1, r2 >= 0, not both 0); a torus with
   centre, axis, radius R to the tube's centre line and tube radius r (R > r > 0). Their texture
   coordinates are a planemap's at their first point along X and Y, carried along by every
   transformation. */
pray_object *pray_box(pray_ctx *ctx, pray_model *m, pray_vec p1, pray_vec p2);
pray_object *pray_rod(pray_ctx *ctx, pray_model *m, pray_vec p1, pray_vec p2, double radius);
pray_object *pray_cone(pray_ctx *ctx, pray_model *m, pray_vec p1, double r1, pray_vec p2, double r2);
pray_object *pray_torus(pray_ctx *ctx, pray_model *m, pray_vec centre, pray_vec axis, double R, double r);
/* A half-space and a ball with texture coordinates (see the language manual: planemap,
   spheremap). */
pray_object *pray_planemap(pray_ctx *ctx, pray_model *m, pray_vec point, pray_vec normal, pray_vec u,
                           pray_vec v);
pray_object *pray_spheremap(pray_ctx *ctx, pray_model *m, pray_vec centre, double radius, pray_vec north,
                            pray_vec zero_longitude);
/* The characters of a UTF-8 string as a solid: glyph cells from `point` (baseline, left) along
   `advance` (one character), glyphs of height `up`, extruded by `thickness` along
   unit(advance x up); `font` NULL for the built-in font, else a 16 x 16 atlas of glyph cells
   in ASCII order (ink dark); `spacing` multiplies the advance (1 = the font's own). */
pray_object *pray_text(pray_ctx *ctx, pray_model *m, const char *text, pray_vec point, pray_vec advance,
                       pray_vec up, double thickness, pray_texture *font, double spacing);
pray_object *pray_nothing(pray_ctx *ctx);

typedef enum pray_op {
    PRAY_UNION = 0,
    PRAY_INTERSECTION = 1,
    PRAY_DIFFERENCE = 2
} pray_op;
/* a op b; chains of one operation become one n-ary node, as in the language. */
pray_object *pray_csg(pray_ctx *ctx, pray_op op, pray_object *a, pray_object *b);
pray_object *pray_complement(pray_ctx *ctx, pray_object *a);
/* The `.` transformations: uniform scale about the origin (s != 0), translation, and rotation by
   degrees about X, then Y, then Z. They return a new object; `a` is unchanged. */
pray_object *pray_scale(pray_ctx *ctx, pray_object *a, double s);
pray_object *pray_translate(pray_ctx *ctx, pray_object *a, pray_vec offset);
pray_object *pray_rotate(pray_ctx *ctx, pray_object *a, pray_vec degrees);
/* `stretch`: a scaled by the components of `factors` along the world axes X, Y, Z (none 0; a
   negative one mirrors). */
pray_object *pray_stretch(pray_ctx *ctx, pray_object *a, pray_vec factors);
/* Language version 3: a copy of `a` with model m on every primitive (shapes and texture
   coordinates unchanged); a checker in m takes the coordinates the primitives have now. */
pray_object *pray_paint(pray_ctx *ctx, pray_object *a, pray_model *m);
/* Primitives in the tree (what `print` shows as "object (N primitives)"); 0 for NULL. */
int pray_object_primitives(const pray_object *a);
/* The host's id of an object, as Embree's geometry ids and OSPRay's ids are: an int, not a
   pointer, so that it indexes the host's own table (of pointers, if it likes), fits an int buffer
   (pray_buffers.id) and means the same in another process (the parts of a distributed render).
   A primitive carries the id of the innermost object with an id that contains it: an id on a
   union is its parts' unless one has its own. pray_hit.id and pray_buffers.id report it, or
   PRAY_NO_ID where no object around the primitive has one. id >= 0 sets it, PRAY_NO_ID removes
   it; other negative ids are refused (PRAY_ERR_ARG). The id belongs to this handle: the `.`
   transformations, stretch and pray_paint make new objects without it, and a union (intersection) made of
   a union (intersection) without an id takes its parts instead of it, so set an id on a chain
   before making more of it. Scenes prepared before (pray_prepare, pray_prepare_render) keep the
   ids they were prepared with; the scene pray_render_into keeps is prepared again. */
#define PRAY_NO_ID (-2)
pray_status pray_object_set_id(pray_ctx *ctx, pray_object *obj, int id);
/* The id of an object (PRAY_NO_ID for none, or NULL). */
int pray_object_id(const pray_object *obj);

/* Lights. */
pray_light *pray_dirlight(pray_ctx *ctx, pray_rgb intensity, pray_vec direction);
pray_light *pray_pointlight(pray_ctx *ctx, pray_rgb intensity, pray_vec position);
/* Language version 3: a point light at `position` shining along `direction` (not zero): full
   intensity within a1 degrees of it, none beyond a2 degrees, and between them the share
   t^2 (3 - 2t), t = (a2 - angle) / (a2 - a1); 0 <= a1 <= a2 < 180 (a1 = a2: a sharp edge). */
pray_light *pray_spotlight(pray_ctx *ctx, pray_rgb intensity, pray_vec position, pray_vec direction, double a1,
                           double a2);
pray_light *pray_light_add(pray_ctx *ctx, pray_light *a, pray_light *b);
/* The `.` transformations of lights: point lights move, directions turn. */
pray_light *pray_light_scale(pray_ctx *ctx, pray_light *l, double s);
pray_light *pray_light_translate(pray_ctx *ctx, pray_light *l, pray_vec offset);
pray_light *pray_light_rotate(pray_ctx *ctx, pray_light *l, pray_vec degrees);

/* Drop your reference; the handle is freed when nothing made from it uses it. NULL is
   ignored; a handle of another context or of the wrong kind is refused (PRAY_ERR_ARG) and left
   alone. pray_release takes any of the four kinds and checks which it is (it cannot tell a
   freed handle from a live one: that is undefined, as for free). */
void pray_object_release(pray_ctx *ctx, pray_object *obj);
void pray_model_release(pray_ctx *ctx, pray_model *model);
void pray_light_release(pray_ctx *ctx, pray_light *light);
void pray_texture_release(pray_ctx *ctx, pray_texture *tex);
void pray_release(pray_ctx *ctx, void *handle);
/* Take one more reference to a handle of any of the four kinds: it lives until it has been
   released once more (or pray_free). So a host keeps what a callback lends it, such as the
   root and lights a render function gets from a running program, past the run. PRAY_ERR_ARG
   for NULL, a handle of another context or not a handle. */
pray_status pray_retain(pray_ctx *ctx, void *handle);

/* Camera and background, as the statements of the same names. pray_lookat: a perspective
   camera at `eye` looking at `point`, `up` (not parallel to point - eye) the image's up, `angle`
   the horizontal field of view in degrees (0 < angle < 180); its X and Y follow from the width
   and height in force when a frame is rendered, so its pixels are always square. */
pray_status pray_perspective(pray_ctx *ctx, pray_vec x, pray_vec y, pray_vec eye, pray_vec point);
pray_status pray_parallel(pray_ctx *ctx, pray_vec x, pray_vec y, pray_vec eye, pray_vec point);
pray_status pray_lookat(pray_ctx *ctx, pray_vec eye, pray_vec point, pray_vec up, double angle);
pray_status pray_background(pray_ctx *ctx, pray_rgb top, pray_rgb bottom);

/* ---------------------------------------------------------------------------------------------
   Rendering and images.
   ------------------------------------------------------------------------------------------- */
/* Statistics: totals over the renders of the current (or last) program run, or since the context
   was made for renders outside runs; primitives and nodes are those of the last render. */
typedef struct pray_stats {
    long primitives_declared;        /* primitives in the object handed to the renderer */
    long primitives;                 /* ... kept after simplification */
    long nodes;                      /* CSG nodes after simplification */
    int grid[3];                     /* voxels along x, y, z (0 = no grid) */
    long voxels, lists, areas;       /* voxels; distinct action lists; areas of equal lists */
    double memory;                   /* bytes of the acceleration structure */
    double rays_primary, rays_shadow, rays_reflected, rays_refracted;
    double rays_primary_full;        /* primary rays without undersampling (option adaptive) */
    long lightbuf_voxels;            /* voxels of the light buffers (option lightbuffer) */
    double rays_lightbuf;            /* shadow rays answered by a light buffer's list */
    long eyebuf_voxels;              /* voxels of the eye's buffer (option eyebuffer) */
    double rays_eyebuf;              /* primary rays traced through the eye's buffer */
    double rays_shadowcache;         /* shadow rays stopped by the shadow cache (option shadowcache) */
    int threads;                     /* threads of the last render */
    double voxel_steps, area_moves;  /* traversal steps (a buffer's stretch is one); steps inside an area (no evaluation) */
    double set_inside, set_outside, checks; /* actions executed, by kind */
    double intersection_tests;       /* ray/primitive intersections computed */
    double frozen_skips;             /* checks skipped because the node was frozen */
    double time_parse, time_prepare, time_render; /* seconds */
    /* Memory: the most bytes the context held at once (every block pray allocated in it, with
       its bookkeeping), over the whole time and in each phase: reading the program (lexing and
       parsing it, before it runs); running it (its values and everything else outside the
       three phases after); preparing a scene (flattening and simplifying the tree); building
       its acceleration structure; rendering (the image and the renderer's scratch). A host's
       own calls count as running. */
    double memory_peak;
    double memory_parse, memory_run, memory_prepare, memory_accel, memory_render;
    long nested_grids, nested_voxels; /* grids nested in crowded voxels, and their voxels */
    /* Image sequences (option coherence): pixels of the run's frames taken over from the frame
       before, pixels traced, and the frames that took any over. */
    double pixels_reused, pixels_retraced;
    long frames_coherent;
} pray_stats;

/* Render `root` lit by `lights` (NULL = no light) with the context's camera, background and
   options into `out`. *out is always set: the image, or 0 x 0 and NULL pixels on failure (an
   image it held before is not freed). The image belongs to the context (pray_image_free).
   Called by a running program's rendertiff while a render function is set (pray_set_render),
   it calls that function instead, and gives what it made (0 x 0 for a skipped frame). */
pray_status pray_render(pray_ctx *ctx, pray_object *root, pray_light *lights, pray_image *out);
/* The statistics (all zero for a NULL context; nothing for a NULL out). */
void pray_stats_get(const pray_ctx *ctx, pray_stats *out);
/* Set every statistic to zero, so that the next pray_stats_get counts from here (a program's run
   starts its own totals without it). */
void pray_stats_reset(pray_ctx *ctx);

/* Ray queries, for picking and for checking the renderer: prepare a solid once with the
   context's options (grid, freeze, merge, bounds, brute), then ask for the surfaces a ray
   crosses. The surfaces are those of the whole solid, and the faces between two different
   materials inside it (the language's section 12), in order along the ray. */
typedef struct pray_scene pray_scene;
typedef struct pray_hit {
    double t;          /* the ray parameter: origin + t * unit(direction) */
    int primitive;     /* which primitive: its position among the primitives of the object as
                          declared, left to right, from 0 (the same whatever is simplified) */
    int entering;      /* 1 where the ray enters the solid, 0 where it leaves, 2 where it crosses
                          a face between two materials inside it (the language's section 12) */
    pray_vec normal;   /* unit normal facing out of the solid; on a face between two materials,
                          towards the one the ray leaves */
    pray_vec refracted; /* the unit direction the ray takes on through the surface by Snell's
                          law, as the renderer traces it: the ratio of the indices of the
                          material left and the one entered (empty space: 1); zero where the
                          surface lets no light through or reflects it all */
    int id;            /* the id of the innermost object with one around the primitive
                          (pray_object_set_id), else PRAY_NO_ID */
} pray_hit;
/* A prepared scene, or NULL. It keeps no reference to root: release root when you like. It
   belongs to the context (pray_scene_free frees it early). */
pray_scene *pray_prepare(pray_ctx *ctx, pray_object *root);
/* Up to max_hits hits with 0 < t < tmax (HUGE_VAL for all) in order into hits (NULL when
   max_hits is 0); returns how many there are in all (which may exceed max_hits), or -1 on
   error. */
int pray_intersect(pray_ctx *ctx, pray_scene *scene, pray_vec origin, pray_vec direction, double tmax,
                   pray_hit *hits, int max_hits);
/* Free a scene of this context (NULL is ignored). */
void pray_scene_free(pray_ctx *ctx, pray_scene *scene);
/* Free the pixels of an image pray_render made in this context and set *img to 0 x 0, NULL
   pixels: freeing it twice is harmless, a copy of the struct is not. An empty image is ignored;
   one of another context is refused; pixels pray did not allocate are undefined, as for free. */
void pray_image_free(pray_ctx *ctx, pray_image *img);

/* Write an image; the format comes from the extension: .tif/.tiff (bits 8 or 16), .ppm (bits 8
   or 16), .png (8 bits, when built with stb_image_write). The file is written under a temporary
   name beside it and renamed when complete; on failure nothing is left behind. The temporary
   file is new each time (".NAME.XXXXXX" + PRAY_TEMP_SUFFIX, NAME cut to 32 bytes; with
   PRAY_8_3_NAMES "NAXXXXXX" + the suffix, NA its first two characters), created
   exclusively and never through a link (POSIX, Windows, DJGPP; where only stdio is there, after
   checking that no such file exists), with mode 0666 less the umask. Option maxoutput counts the
   bytes written. Any image will do: yours, or one of any context. */
pray_status pray_write_image(pray_ctx *ctx, const pray_image *img, const char *path, int bits);
/* The same formats into a byte sink `fn` (needed), called on the calling thread. */
pray_status pray_write_tiff(pray_ctx *ctx, const pray_image *img, int bits, pray_write_fn fn,
                            void *ud);
pray_status pray_write_ppm(pray_ctx *ctx, const pray_image *img, int bits, pray_write_fn fn,
                           void *ud);
/* PNG (8 bits) into a byte sink; PRAY_ERR_ARG when the build has no PNG writer (pray_features
   lists "png" when it has). Its memory comes from the context and counts against its cap. */
pray_status pray_write_png(pray_ctx *ctx, const pray_image *img, pray_write_fn fn, void *ud);

/* One call: run a program file with optional fixed options ("name=value" strings) in a context of
   its own; the message (or "") is copied into `message` (may be NULL) of message_size bytes. */
pray_status pray_render_file(const char *program, const char *const *options, int noptions,
                             char *message, size_t message_size);

/* A note recorded in an image file: printable ASCII (32 to 126), at most PRAY_NOTE_MAX
   characters. TIFF keeps it as the ImageDescription (tag 270), PPM as a comment line after the
   magic number ("P6\n# NOTE\n..."); PNG files take none (PRAY_ERR_ARG). Otherwise as
   pray_write_image; the pixels are the same bytes. pray --rows writes its parts so
   (docs/distributed.md). */
#define PRAY_NOTE_MAX 1000
pray_status pray_write_image_note(pray_ctx *ctx, const pray_image *img, const char *path, int bits,
                                  const char *note);
/* A new image of width x height pixels, all black, that belongs to the context like one
   pray_render made (pray_image_free, pray_free). *out is always set (0 x 0 and NULL on failure).
   PRAY_ERR_ARG for a size pray cannot render (sides 1 to 65536, at most 2^28 pixels);
   PRAY_ERR_NOMEM over the context's memory cap. */
pray_status pray_image_new(pray_ctx *ctx, int width, int height, pray_image *out);
/* The image as 8-bit samples into the caller's buffer, rows from the top, `channels` bytes a
   pixel: 3 (R, G, B) or 4 (R, G, B and 255): exactly the samples an 8-bit file of it holds
   (pray_write_image: PPM, TIFF and PNG alike), which are linear in the light (value x 255,
   rounded). With PRAY_BYTES_SRGB added to channels (3 + PRAY_BYTES_SRGB, 4 + PRAY_BYTES_SRGB)
   the samples are encoded with the sRGB curve instead, as displays and denoisers of 8-bit
   colour expect: 12.92 v up to v = 0.0031308, else 1.055 v^(1/2.4) - 0.055, then x 255 rounded
   (values below 0 and above 1 taken as 0 and 1). out must hold width x height x channels bytes.
   PRAY_ERR_ARG for an image that is not valid, channels not one of those four, or a NULL out. */
#define PRAY_BYTES_SRGB 256
pray_status pray_image_bytes(pray_ctx *ctx, const pray_image *img, int channels, unsigned char *out);
/* Record an error as pray's own calls do: status `status`, message "error: " + message (NULL:
   the status's text); returns status. For callbacks (render, frame) that fail with a message of
   their own. PRAY_OK clears the error (pray_clear_error); any other int that is not one of the
   codes above becomes PRAY_ERR_ARG (the status is an int so that every value is defined). */
pray_status pray_set_error(pray_ctx *ctx, int status, const char *message);

/* ---------------------------------------------------------------------------------------------
   Parts of a render, for spreading one over processes or machines (docs/distributed.md).
   A rectangle of rows rendered with pray_render_into below is bit for bit those rows of the
   whole image, whatever antialias, adaptive and the threads do; stacking the parts of every
   process in order gives the bytes of one process rendering all. For a program, the host renders
   the frames itself: every statement runs as usual, and each rendertiff calls the host, which
   renders what it wants of the frame (rows, or nothing) and says what becomes of it.
   ------------------------------------------------------------------------------------------- */
/* Called by each `rendertiff` of a program run on the context, instead of rendering the frame;
   `frame` is its number in the run from 0 (frames the host skipped count too, so numbers and
   file names are those of the whole run). It renders with the calls above on ctx (pray_render,
   pray_render_into: inside the function they render as without it; the frame's width and
   height are pray_option_get(ctx, "width") and "height") and sets *out (0 x 0 when called):
   - to an image of the context (pray_render, pray_image_new; any size): the frame, handed to
     the frame callback, or without one written to its file as pray would (option bits);
   - or leaves it 0 x 0: the frame is skipped, nothing is written and no frame callback called.
   Return PRAY_OK, or a failure's status: the program stops there, with the context's message
   (pray_set_error) or "the render function failed". */
typedef pray_status (*pray_render_fn)(void *ud, pray_ctx *ctx, pray_object *root, pray_light *lights,
                                      int frame, pray_image *out);
/* Set the render function of programs run on the context (NULL: pray renders, the default). */
void pray_set_render(pray_ctx *ctx, pray_render_fn fn, void *ud);

/* ---------------------------------------------------------------------------------------------
   Rendering into your own buffers, per-pixel outputs, host textures.
   ------------------------------------------------------------------------------------------- */
/* A rectangle of the image in pixels: columns x .. x+width-1, rows y .. y+height-1, row 0 at
   the top. */
typedef struct pray_rect { int x, y, width, height; } pray_rect;
/* Where pray_render_into writes: any of the six buffers may be NULL (not wanted), not all of
   them. Pixel (x, y) of the rectangle is at element y*stride + x of every buffer (times 3 for
   rgb, normal and albedo); nothing between rows is written. The caller owns the buffers. Zero
   the struct (or give every member) and set what you want.
   The per-pixel outputs (primitive, id, depth, normal, albedo) are those of the first surface
   met by the primary ray through the pixel's centre, pray_camera_ray(ctx, x + 0.5, y + 0.5, ...)
   in image pixels: exactly pray_intersect's first hit for that ray on a scene prepared with the
   same options, whatever antialias and adaptive do for the colour. With flags
   PRAY_BUFFERS_SAMPLES, normal and albedo are instead the means over the antialias x antialias
   sample rays of the pixel (pray_camera_ray's rays, as the colour's: with option adaptive, those
   its colour is traced or interpolated from), the background's counting as 0, 0, 0, so that a
   denoiser gets them averaged as the colour is; primitive, id and depth stay the centre's (they
   cannot be averaged). With antialias 1 both ways are the same. */
#define PRAY_BUFFERS_SAMPLES 1
typedef struct pray_buffers {
    float *rgb;       /* 3 floats per pixel: the colour, as pray_render's */
    int *primitive;   /* the primitive seen (as pray_hit.primitive: declared order); -1: background */
    float *depth;     /* its pray_hit.t (distance along the ray); +infinity for the background */
    float *normal;    /* 3 floats per pixel: its pray_hit.normal; 0, 0, 0 for the background */
    size_t stride;    /* pixels from one row to the next in every buffer: 0 = the rectangle's
                         width, else at least that */
    int *id;          /* its pray_hit.id (pray_object_set_id; PRAY_NO_ID: none); -1: background */
    float *albedo;    /* 3 floats per pixel: the colour of the surface as its shading takes it
                         at that point, textures included: the model's diffuse + flat colour
                         (color) + mirror weight + transparency weight, each channel at most 1;
                         0, 0, 0 for the background */
    int flags;        /* 0, or PRAY_BUFFERS_SAMPLES (above); other bits are refused */
} pray_buffers;
/* Render as pray_render does, into the caller's buffers: the image of the context's width and
   height options, or only the rectangle `rect` of it (NULL = the whole image). A rectangle's
   colours are bit for bit those of the same pixels of the whole image, for every option and
   any number of threads. Memory besides the buffers comes from the context. Errors:
   PRAY_ERR_ARG (no context or buffers, all buffers NULL, a rectangle not inside the image, a
   stride less than its width), and those of pray_render; on error the buffers hold partial
   results.
   Prepared once, rendered many times: outside a program's run (and in a render function), the
   context keeps the scene pray_render_into and pray_render prepared (flattened, simplified, with
   its grid), and the next render of the same root and lights with the same options, camera and
   background uses it again, so that bands, tiles and passes cost what the whole image costs. It
   holds a reference to root and lights meanwhile (releasing yours is safe). Of the preparation
   only the eye's buffer and, for a solid of several materials that lets no light through, the
   faces between them depend on the camera. So a new camera of the same kind (parallel or
   perspective) keeps it, taking the new camera, when the eye stays where it was (the camera
   turned about its eye) or the scene has no eye's buffer (option eyebuffer 0, a parallel
   camera, or too few samples for one: pray_stats.eyebuf_voxels 0), unless primary rays of the
   new camera start inside such a solid prepared without those faces. Rendering another scene or
   lights, changing an option or the background, any other new camera, setting an id
   (pray_object_set_id), the start or the end of a program's run, or pray_free drops it. To
   render one scene from several threads at once, see pray_prepare_render. */
pray_status pray_render_into(pray_ctx *ctx, pray_object *root, pray_light *lights, const pray_rect *rect,
                             const pray_buffers *out);
/* A scene prepared for rendering, with the context's options, camera and background as they are
   now, as pray_render_into prepares it; NULL on error (those of pray_render_into). pray_intersect
   takes it too (where the render's lists leave out the faces between materials that no ray of
   it can meet, the first query builds them, once). It belongs to the context (pray_scene_free,
   pray_free), which must outlive every render of it; it keeps no reference to root or lights. */
pray_scene *pray_prepare_render(pray_ctx *ctx, pray_object *root, pray_light *lights);
/* Render rectangle `rect` (NULL: the whole image) of a scene from pray_prepare_render into the
   caller's buffers, as pray_render_into would with the options, camera and background the scene
   was prepared with (this context's option threads excepted): the same bits. The scene is only
   read, and may belong to another context: several contexts, each on a thread of its own, may
   render one scene at once, with no preparing again and no locks. This context gives the memory
   of the render, its statistics, progress and cancelling. Errors: PRAY_ERR_ARG (no scene, one
   prepared by pray_prepare, buffers or a rectangle as for pray_render_into); those of
   pray_render. */
pray_status pray_render_prepared(pray_ctx *ctx, const pray_scene *scene, const pray_rect *rect,
                                 const pray_buffers *out);
/* The primary ray through image point (px, py), in pixels from the image's top left corner
   (a pixel's centre is at x + 0.5, y + 0.5), for the context's camera and width and height
   options: *origin (the eye; for a parallel camera the point on the image plane) and *dir (a
   unit vector). The render's primary rays are exactly these: with antialias A, sample (a, b)
   of pixel (x, y) is the ray of point (x + (a + 0.5) / A, y + (b + 0.5) / A). PRAY_ERR_ARG for
   a NULL argument or a point that is not finite. */
pray_status pray_camera_ray(pray_ctx *ctx, double px, double py, pray_vec *origin, pray_vec *dir);

/* A texture from pixels in memory: width x height pixels, 3 floats each (R, G, B in 0 .. 1), rows
   from the top, copied; `name` (NULL: "texture") is used in messages. Like a texture file it may
   take at most option texmem MiB; sides are 1 to 65536. NULL on error (PRAY_ERR_ARG: NULL
   pixels, a bad size, a value that is not in 0 .. 1; PRAY_ERR_LIMIT: over texmem;
   PRAY_ERR_NOMEM). Release it with pray_texture_release. */
pray_texture *pray_texture_rgb(pray_ctx *ctx, int width, int height, const float *rgb, const char *name);
/* Register `tex` under `name`: a program's texture and font names (tiff, tiffbump, text) are
   looked up first among the registered names, by exact string match before any path handling,
   and then as files. So a registered name needs no file access: it works in builds with
   PRAY_NO_STDIO and in untrusted mode. The context keeps a reference until the name is
   registered again (which replaces it), removed (tex NULL; a name not registered is fine) or the
   context is freed; registrations last across runs. A registered texture was checked against
   texmem when it was made and is not counted again by runs. PRAY_ERR_ARG for a NULL context, a
   NULL or empty name, or a texture of another context. */
pray_status pray_texture_register(pray_ctx *ctx, const char *name, pray_texture *tex);
/* Register program text under `name` for `include`, as textures are: `include "F"` looks F up
   first among the registered names, by exact string match of F as written, before any path
   handling, and then as a file beside the including one. So a program that includes needs no
   file access: it works with PRAY_NO_STDIO and in untrusted mode. The text (len bytes, need not
   be NUL-terminated) is copied; it is read as a file would be, with the same limits (maxnest,
   maxline, maxstring, a statement of maxsteps for each line), and its errors name it
   ("name:line:col: error: ...", "included from ..."); an include in it is looked up the same
   way, a file beside `name`. Registrations last across runs until the name is registered again
   (which replaces the text), removed (text NULL; a name not registered is fine) or the context
   is freed. PRAY_ERR_ARG for a NULL or empty name; PRAY_ERR_NOMEM. */
pray_status pray_include_register(pray_ctx *ctx, const char *name, const char *text, size_t len);

#ifdef __cplusplus
}
#endif

#endif /* PRAY_HPP */

/* =============================================================================================
   MANUAL
   =============================================================================================

   1. About
   pray renders scenes described as CSG (constructive solid geometry) trees of half-spaces,
   spheres and infinite cylinders, with Whitted ray tracing: Phong shading, shadows, mirrors and
   refraction. Scenes come from PRAY programs (the language of Pavel Zemcik's 1995 thesis
   "Realistic Rendering", fixed by docs/pray-language.md) or from the calls above.

   2. Building
   Copy pray.hpp and pray.cpp into your project and compile pray.cpp with it. It needs a C++98
   compiler and the C library's math; no exceptions or RTTI, and no C++ runtime whatever the
   flags: `c++ -c pray.cpp` then `cc app.c pray.o -lm` (plus -lpthread where the C library keeps
   threads apart) links a C program. It refuses -ffast-math and its kin (it needs infinities and
   NaN). `-DPRAY_MAIN` adds main().
   With CMake: add_subdirectory of pray's directory or find_package(pray), then link the target
   pray::pray; an installed pray is also known to pkg-config as "pray" (README.md).

   3. A host program
   Everything a context makes belongs to it: objects, models, lights, textures, prepared scenes
   and rendered images. pray_free frees all that is left of them; pray_image_free,
   pray_scene_free and the releases free one earlier. Copy the pixels of an image that must
   outlive its context, or render into your own buffers (pray_render_into, below). A NULL from a failed call passes through the calls it is given to, so
   one check at the end finds the first failure's message:
       #include <stdio.h>
       #include "pray.hpp"
       int main(void) {
           pray_rgb red = {0.8, 0.1, 0.1}, grey = {0.3, 0.3, 0.3};
           pray_rgb black = {0, 0, 0}, white = {1, 1, 1};
           pray_vec centre = {0, 0, 0}, towards = {1, 1, 1};
           pray_ctx *c = pray_new();
           pray_model *m = pray_phong(c, red, grey, black, 3);
           pray_object *s = pray_sphere(c, m, centre, 0.2);
           pray_light *l = pray_dirlight(c, white, towards);
           pray_image img;
           int ok = pray_render(c, s, l, &img) == PRAY_OK &&
                    pray_write_image(c, &img, "red.tif", 8) == PRAY_OK;
           if (!ok) fprintf(stderr, "%s\n", pray_error(c));
           pray_free(c);
           return ok ? 0 : 1;
       }
   Running the same scene as a program: pray_run_string(c, "red.ray", text, strlen(text)).
   A host that keeps the pixels itself renders into its own buffers, here a 4 x 4 rectangle of
   the image with the primitive seen at each pixel and the id the host gave its object (for
   picking), and lends a program a texture from memory and the text of an include under names:
       #include <stdio.h>
       #include <string.h>
       #include "pray.hpp"
       int main(void) {
           static float rgb[4 * 4 * 3], checker[2 * 2 * 3] = {1, 1, 1, 0, 0, 0, 0, 0, 0, 1, 1, 1};
           static int seen[4 * 4], ids[4 * 4];
           pray_rect r = {30, 30, 4, 4};
           pray_buffers out = {NULL, NULL, NULL, NULL, 0, NULL, NULL, 0};
           pray_rgb white = {1, 1, 1};
           pray_vec centre = {0, 0, 0};
           const char *part = "M = tiff(color({0}), color({1}), \"checker\")\n";
           const char *prog = "include \"material.ray\"\n"
                              "rendertiff spheremap(M, [0, 0, 0], 0.5, <0, 0, 1>, <1, 0, 0>), none\n";
           pray_ctx *c = pray_new();
           pray_object *s = pray_sphere(c, pray_color(c, white), centre, 0.5);
           pray_texture *t = pray_texture_rgb(c, 2, 2, checker, "checker");
           int ok;
           out.rgb = rgb;
           out.primitive = seen;
           out.id = ids;
           pray_option(c, "width", 64);
           pray_option(c, "height", 64);
           ok = pray_object_set_id(c, s, 7) == PRAY_OK &&
                pray_render_into(c, s, NULL, &r, &out) == PRAY_OK && seen[0] == 0 && ids[0] == 7;
           pray_option_string(c, "output", "checker.ppm");
           ok = ok && pray_texture_register(c, "checker", t) == PRAY_OK &&
                pray_include_register(c, "material.ray", part, strlen(part)) == PRAY_OK &&
                pray_run_string(c, "checker.ray", prog, strlen(prog)) == PRAY_OK;
           if (!ok) fprintf(stderr, "%s\n", pray_error(c));
           pray_free(c);
           return ok ? 0 : 1;
       }
   Every indented block of this manual that starts with #include is a whole program, compiled
   as C and as C++ and run by the tests.

   4. Errors
   Every failing call returns a status (or NULL) and leaves "where: error: what" in
   pray_error(ctx). Program errors carry "name:line:col". pray never calls exit or abort.
   A NULL argument, or a handle of another context, is refused with a status, never a crash
   (see the conventions before the declarations).

   5. Threads and cancelling
   A context is used by one thread at a time; two contexts may render at once. No global state
   (while a PNG is encoded, the encoding thread keeps a pointer to its context in thread-local
   storage, for the encoder's allocations).
   A render runs on option threads threads, the caller's among them. The progress callback is
   called on any of them, one call at a time; it must not call pray on the context, except
   pray_cancel. pray_cancel may be called from any thread or a signal handler while a program
   runs, a scene is prepared, or an image is rendered or written: the call returns
   PRAY_ERR_CANCELLED within a statement, a row of voxels or a row of pixels. Nothing is left
   half made (frames a program finished before stay) and the context works as before. The flag
   is cleared when such a call starts, so a cancel made between calls is forgotten.

   6. Rendering, and how it is made fast
   A ray's visible surface is found by sweeping the crossings of the primitives along it through
   an n-ary CSG status tree (thesis 3.4). Option brute=1 does exactly that for every primitive:
   the reference. By default the scene is simplified, a uniform grid of voxels with per-voxel
   action lists is built (thesis 3.3-3.6: leading-axis traversal, set/check actions, freezing,
   areas), bounding boxes prune what cannot be met, light buffers answer shadow rays from one
   list per voxel around each light (and, in the box around a point light where its shadow
   rays end, from one list per direction; a shadow ray passes over lists of clear surfaces
   only), and primary rays walk the lists of the eye's buffer, a grid of
   pyramids around a perspective camera's eye; a shadow ray first tries the voxel where the
   last one towards its light was stopped. Options grid, freeze, merge, bounds, plans,
   lightbuffer, eyebuffer and shadowcache switch the parts on and off; every setting gives the
   image of brute=1, byte for byte.
   docs/acceleration.md explains the methods, docs/benchmarks.md measures them.
   Secondary rays know the primitive they start on and never meet it again at their origin;
   nor any primitive of exactly the same surface (faces shared by parts, snapped to be equal).

   7. The language
   docs/pray-language.md is the full manual; pray-language.md of the specification fixes it.
   A program is lines of statements; values are numbers, points [x,y,z], vectors <x,y,z>,
   intensities {r,g,b}, lights, models, objects and strings. A program:
       RedSurface = phong({0.8, 0.1, 0.1}, {0.3, 0.3, 0.3}, 3)
       Light = dirlight({1}, norm(<1, 1, 1>))
       Centre = [0, 0, 0]
       Sphere = sphere(RedSurface, Centre, 0.2)
       rendertiff Sphere, Light
   Statements: NAME = expr, delete, print, if/then/else/endif, while/endwhile, quit, background,
   perspective, parallel, option, rendertiff. Operators from the highest priority: unary + -
   (on objects: complement), . (scale, translate, rotate), ^, * / %, + -, comparisons
   = == # < > <= >=, &, | \ (objects: union and difference; numbers: bitwise). A result that
   is not a finite number (overflow) is an error at its operator or function.

   8. Limits
   Every limit of a run is an option with a default (the command line sets it with -D):
       option     limits                                        default      untrusted
       maxsteps   statements a program executes, and each line   10000000     1000000
                  an include reads (0 = none)
       maxnest    nesting of blocks, includes and expressions    256          64
                  together, across files
       maxline    characters on one line of a program            65536        4096
       maxstring  bytes of one string (literal or built by +)    65536        4096
       maxprims   primitives one object stands for               16777216     1048576
       maxpixels  samples of an image (width*height*antialias^2) 1073741824   16777216
       maxrays    rays of one sample (eye, reflected, refracted) 65536        256
       depth      ray recursion depth                            5 (at most 64)  16
       gridmem    MiB for the grid's tables                      64           64
       texmem     MiB for the textures of a run                  256          64
       maxmem     MiB the context may hold (0 = no cap)          0            1024
       maxframes  frames a run renders (0 = no limit)            0            1000
       maxoutput  MiB of image files a run writes (0 = none)     0            1024
       maxtime    seconds a run takes (0 = no limit)             0            600
   maxline and maxnest are read when a program is read. Fixed limits besides: images up to
   65536 pixels a side and 2^28 pixels, CSG trees up to 2000 levels, models up to 256 levels
   and, with textures, 4096 parts (each use of a shared part counted).
   pray_set_memory_limit caps a context's bytes as maxmem does; over a cap, calls fail with
   PRAY_ERR_NOMEM ("out of memory"), never abort, and leave the context usable.
   pray_set_untrusted (--untrusted) turns the last column into ceilings and keeps a program's
   files in its own directory.

   9. Status codes
   PRAY_OK 0, PRAY_ERR_NOMEM 1, PRAY_ERR_IO 2, PRAY_ERR_SYNTAX 3, PRAY_ERR_RUNTIME 4,
   PRAY_ERR_LIMIT 5, PRAY_ERR_ARG 6, PRAY_ERR_CANCELLED 7 (pray_cancel or the progress
   callback; never a limit). The command line exits with 0 (ok), 1 (error in the program),
   2 (usage) or 3 (input/output); it does not cancel: Ctrl-C removes the file being written and
   ends it.
*/
