/* ports/wasm/glue.cpp — the functions the playground's workers call in libpray.wasm
   (ports/wasm/playground/worker.js), on top of pray's C API.

   One context at a time: pg_new makes it (untrusted, with a memory cap), pg_texture lends it a
   texture under the name a program uses, pg_include a program text for `include`, pg_option fixes an option as `-D name=value` does,
   pg_run runs a program and renders only band K of N of every frame (`pray --part K/N`),
   a few rows at a time, each handed to the page through the imported function pg_rows as
   8-bit RGBA samples: the bytes of an 8-bit image file of the same rows.
   Imported from the page (module "env"): pg_rows, pg_print. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../../pray.hpp"

#define PG_EXPORT(name) __attribute__((export_name(#name)))
#define PG_IMPORT(name) __attribute__((import_module("env"), import_name(#name)))

extern "C" {
/* Rows y .. y+n-1 of frame `frame` (width x height pixels), 4 bytes a pixel, at rgba. */
PG_IMPORT(pg_rows) void pg_rows(int frame, int y, int n, int width, int height, const unsigned char *rgba);
/* Bytes a program printed. */
PG_IMPORT(pg_print) void pg_print(const char *text, int n);
}

namespace {

pray_ctx *ctx;
int part_k = 1, part_n = 1;
char stats_text[2048];

const int ROWS_AT_ONCE = 4;  // rows rendered by one call, handed to the page together

void print_to_page(void *, const void *data, size_t n) { pg_print((const char *)data, (int)n); }

// The render function: band K of N of the frame, ROWS_AT_ONCE rows at a time.
pray_status render_band(void *, pray_ctx *c, pray_object *root, pray_light *lights, int frame, pray_image *out) {
    int W = (int)pray_option_get(c, "width"), H = (int)pray_option_get(c, "height");
    (void)out;  // left 0 x 0: the frame is the page's, no file is written
    if (part_n > H) {
        char msg[120];
        snprintf(msg, sizeof msg, "an image of %d rows cannot be cut into %d bands", H, part_n);
        return pray_set_error(c, PRAY_ERR_ARG, msg);
    }
    int y0 = (int)((unsigned long)(part_k - 1) * (unsigned long)H / (unsigned long)part_n);
    int y1 = (int)((unsigned long)part_k * (unsigned long)H / (unsigned long)part_n);
    size_t most = (size_t)W * ROWS_AT_ONCE;
    float *rgb = (float *)malloc(most * 3 * sizeof(float));
    unsigned char *bytes = (unsigned char *)malloc(most * 4);
    if (!rgb || !bytes) {
        free(rgb);
        free(bytes);
        return pray_set_error(c, PRAY_ERR_NOMEM, NULL);
    }
    pray_status st = PRAY_OK;
    for (int y = y0; y < y1 && st == PRAY_OK; y += ROWS_AT_ONCE) {
        int n = y1 - y < ROWS_AT_ONCE ? y1 - y : ROWS_AT_ONCE;
        pray_rect r = {0, y, W, n};
        pray_buffers b = {rgb, NULL, NULL, NULL, 0, NULL, NULL, 0};
        pray_image img = {W, n, rgb};
        st = pray_render_into(c, root, lights, &r, &b);
        if (st == PRAY_OK) st = pray_image_bytes(c, &img, 4, bytes);
        if (st == PRAY_OK) pg_rows(frame, y, n, W, H, bytes);
    }
    free(rgb);
    free(bytes);
    return st;
}

} // namespace

extern "C" {

/* Bytes for the page to fill (programs, names, textures); pg_free gives them back. */
PG_EXPORT(pg_alloc) void *pg_alloc(int n) { return malloc(n > 0 ? (size_t)n : 1); }
PG_EXPORT(pg_free) void pg_free(void *p) { free(p); }

/* A new context (the one before is freed): untrusted, at most memcap bytes (0: untrusted's
   own cap), printing to the page. 0 on success, else a status. */
PG_EXPORT(pg_new) int pg_new(double memcap) {
    pray_free(ctx);
    ctx = pray_new();
    if (!ctx) return PRAY_ERR_NOMEM;
    pray_set_untrusted(ctx);
    if (memcap > 0) pray_set_memory_limit(ctx, (size_t)memcap);
    pray_set_print(ctx, print_to_page, NULL);
    pray_set_render(ctx, render_band, NULL);
    return PRAY_OK;
}

/* Lend the context a TIFF texture under `name` (as `tiff` and `text` name it). */
PG_EXPORT(pg_texture) int pg_texture(const char *name, const void *data, int size) {
    pray_texture *t = pray_texture_tiff(ctx, data, (size_t)size, name);
    if (!t) return pray_last_status(ctx);
    pray_status st = pray_texture_register(ctx, name, t);
    pray_texture_release(ctx, t);
    return st;
}

/* Lend the context the program text[0 .. len) for `include "name"`. */
PG_EXPORT(pg_include) int pg_include(const char *name, const char *text, int len) {
    return pray_include_register(ctx, name, text, (size_t)len);
}

/* Fix option `name` to the text `value`, as the command line's -D does. */
PG_EXPORT(pg_option) int pg_option(const char *name, const char *value) {
    return pray_option_fix(ctx, name, value);
}

/* Run the program text[0 .. len) named `name`, rendering band k of n of every frame.
   Returns the status; pg_error and pg_error_line/col tell what went wrong. */
PG_EXPORT(pg_run) int pg_run(const char *name, const char *text, int len, int k, int n) {
    if (!ctx) return PRAY_ERR_ARG;
    if (n < 1 || k < 1 || k > n) return pray_set_error(ctx, PRAY_ERR_ARG, "band k of n: 1 <= k <= n");
    part_k = k;
    part_n = n;
    return pray_run_string(ctx, name, text, (size_t)len);
}

PG_EXPORT(pg_error) const char *pg_error(void) { return pray_error(ctx); }
PG_EXPORT(pg_error_line) int pg_error_line(void) {
    int line = 0;
    pray_error_place(ctx, &line, NULL);
    return line;
}
PG_EXPORT(pg_error_col) int pg_error_col(void) {
    int col = 0;
    pray_error_place(ctx, NULL, &col);
    return col;
}
PG_EXPORT(pg_frames) int pg_frames(void) { return pray_frames(ctx); }
PG_EXPORT(pg_version) const char *pg_version(void) { return pray_version(); }

/* The statistics of the last run, as `pray --stats` prints them. */
PG_EXPORT(pg_stats) const char *pg_stats(void) {
    pray_stats s;
    pray_stats_get(ctx, &s);
    snprintf(stats_text, sizeof stats_text,
             "primitives: %ld declared, %ld kept; nodes %ld\n"
             "grid: %d x %d x %d = %ld voxels and %ld in %ld nested grids, %ld distinct lists, %ld areas, %.0f bytes\n"
             "rays: primary %.0f (of %.0f without undersampling), shadow %.0f, reflected %.0f, refracted %.0f\n"
             "intersection tests %.0f\n"
             "time: parse %.3f s, prepare %.3f s, render %.3f s\n"
             "memory: peak %.0f bytes\n",
             s.primitives_declared, s.primitives, s.nodes, s.grid[0], s.grid[1], s.grid[2], s.voxels, s.nested_voxels,
             s.nested_grids, s.lists, s.areas, s.memory, s.rays_primary, s.rays_primary_full, s.rays_shadow,
             s.rays_reflected, s.rays_refracted, s.intersection_tests, s.time_parse, s.time_prepare, s.time_render,
             s.memory_peak);
    return stats_text;
}

}  // extern "C"
