// libFuzzer harness for the TIFF reader: the fuzz input is written to a file, which two small
// PRAY programs then use as a texture (tiff, tiffbump, planemap, spheremap) and as a font atlas
// (text), rendered at 8 x 8. Public API only.
//
//   make fuzz-tiff                 build it and run it over tests/fuzz/corpus_tiff (FUZZ_SECONDS)
//   build/fuzz/fuzz_tiff FILE      replay one input
//
// Caps, fixed against the programs: 8 x 8 pixels, depth 3, one thread, textures of at most
// 16 MiB decoded (option texmem), 64 MiB per context. A failure must carry a message naming the
// program's place ("tiff.ray:LINE:COL: error: ..."); anything else aborts.
#include "../../pray.hpp"

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

namespace {

char g_path[64];

pray_status frame_sink(void *, const pray_image *img, const char *) {
    if (!img || img->width != 8 || img->height != 8 || !img->pixels) abort();
    volatile float sum = 0;
    for (int i = 0; i < 8 * 8 * 3; i++) sum = sum + img->pixels[i];
    return PRAY_OK;
}

bool has_place(const char *m, const char *name) {
    size_t n = strlen(name);
    if (strncmp(m, name, n) != 0 || m[n] != ':') return false;
    m += n + 1;
    for (int part = 0; part < 2; part++) {
        if (*m < '0' || *m > '9') return false;
        while (*m >= '0' && *m <= '9') m++;
        if (*m++ != ':') return false;
    }
    return strncmp(m, " error: ", 8) == 0 && m[8] != 0;
}

// Run `text` with every @F@ replaced by the file's name.
void run(const char *name, const char *text) {
    char prog[2048];
    size_t n = 0;
    for (const char *p = text; *p && n + sizeof g_path < sizeof prog;) {
        if (strncmp(p, "@F@", 3) == 0) {
            n += (size_t)snprintf(prog + n, sizeof prog - n, "%s", g_path);
            p += 3;
        } else
            prog[n++] = *p++;
    }
    prog[n] = 0;
    pray_ctx *c = pray_new();
    if (!c) return;
    pray_set_memory_limit(c, (size_t)64 << 20);
    pray_set_print(c, NULL, NULL);
    pray_set_frame(c, frame_sink, NULL);
    static const char *const caps[][2] = {
        {"maxsteps", "1000"}, {"width", "8"}, {"height", "8"}, {"depth", "3"}, {"threads", "1"}, {"texmem", "16"},
    };
    for (size_t i = 0; i < sizeof caps / sizeof caps[0]; i++)
        if (pray_option_fix(c, caps[i][0], caps[i][1]) != PRAY_OK) abort();
    pray_status st = pray_run_string(c, name, prog, strlen(prog));
    const char *msg = pray_error(c);
    if (st != PRAY_OK && (st == PRAY_ERR_SYNTAX || !msg || !has_place(msg, name))) {
        fprintf(stderr, "fuzz_tiff: status %d, message \"%s\"\n", (int)st, msg ? msg : "(null)");
        abort();
    }
    pray_free(c);
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    if (!g_path[0]) {
        const char *dir = getenv("TMPDIR");
        snprintf(g_path, sizeof g_path, "%.40s/pray-fuzz-%ld.tif", dir && *dir ? dir : "/tmp", (long)getpid());
    }
    FILE *f = fopen(g_path, "wb");
    if (!f) abort();
    if (size && fwrite(data, 1, size, f) != size) abort();
    if (fclose(f) != 0) abort();
    // As a texture: tiff on a plane behind, tiffbump on a sphere in front.
    run("tiff.ray",
        "T = tiff(color({0}), color({1}), \"@F@\")\n"
        "B = tiffbump(phong({0.6}, {0.3}, 10), 0.05, \"@F@\")\n"
        "P = planemap(T, [0, 0.5, 0], <0, -1, 0>, <0.7, 0, 0>, <0, 0, 0.7>)\n"
        "S = spheremap(move(B, 0.25, 0.5), [0, 0, 0], 0.6, <0, 0, 1>, <1, 0, 0>)\n"
        "rendertiff P | S, dirlight({1}, <1, 1, -1>)\n");
    // As a font atlas.
    run("font.ray",
        "rendertiff text(color({1}), \"Ag~\", [-1, 0, -0.2], <0.6, 0, 0>, <0, 0, 0.6>, 0.1, \"@F@\", 1), none\n");
    return 0;
}
