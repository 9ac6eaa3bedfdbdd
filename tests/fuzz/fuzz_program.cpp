// libFuzzer harness: run the fuzz input as a PRAY program, through the public API only.
//
//   make fuzz                      build it and run it over tests/fuzz/corpus (FUZZ_SECONDS)
//   clang++ -g -O1 -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=undefined \
//       -I. tests/fuzz/fuzz_program.cpp pray.cpp -o build/fuzz/fuzz_program
//   build/fuzz/fuzz_program tests/fuzz/crashes/FILE   replay one input
//
// Every run gets small caps, fixed so that the program's own `option` statements cannot raise
// them: 8 x 8 pixels, ray depth 3, 20000 statements, 16 frames, one thread, 64 MiB of memory.
// `print` output is discarded and frames go to a callback, which encodes them as TIFF and PPM into
// memory: nothing is written to files.
//
// Texture files: at start-up the harness writes a 4 x 4 TIFF `t.tif` and a 16 x 16 font atlas
// `f.tif` into a temporary directory of its own (removed at exit), and runs every input as the
// program `DIR/fuzz.ray`, so that `tiff(M, M, "t.tif")` and `text(..., "f.tif", 1)` read them
// (beside the program); other names reach the file system through the same opener.
//
// Included files: an input may hold files besides the program, each after a line
// `//file NAME` (a comment to PRAY, so the whole input is a program too). The part before the
// first such line is the program; each part after one is written as DIR/NAME for the run and
// removed after it (at most 8 files; NAME of letters, digits, '_', '-' and '.', not starting
// with '.', at most 32 characters; other lines are left in the part before). So fuzzing reaches
// chains of `include`, files that include each other, and errors and limits across files.
//
// Besides the sanitizers, the harness checks what the API promises about failures: a failing
// run returns a known status and leaves a message; a message of a program error starts with
// "DIR/fuzz.ray:LINE:COL: error: ". A broken promise aborts, so libFuzzer reports it as a crash.
#include "../../pray.hpp"

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <string>

namespace {

std::string dir;      // the harness's directory, holding t.tif and f.tif
std::string program;  // DIR/fuzz.ray: the name every input runs under

void remove_dir() {
    unlink((dir + "/t.tif").c_str());
    unlink((dir + "/f.tif").c_str());
    rmdir(dir.c_str());
}

// A width x height TIFF of stripes, written by pray itself.
void write_tiff(const std::string &path, int width, int height) {
    pray_ctx *c = pray_new();
    float *px = (float *)calloc((size_t)width * height * 3, sizeof(float));
    if (!c || !px) abort();
    for (int i = 0; i < width * height * 3; i++) px[i] = (float)((i / 3 % width + i / 3 / width) % 3) / 2;
    pray_image img = {width, height, px};
    if (pray_write_image(c, &img, path.c_str(), 8) != PRAY_OK) {
        fprintf(stderr, "fuzz_program: cannot write %s: %s\n", path.c_str(), pray_error(c));
        abort();
    }
    free(px);
    pray_free(c);
}

void byte_sink(void *ud, const void *data, size_t n) {
    const unsigned char *p = static_cast<const unsigned char *>(data);
    unsigned long *sum = static_cast<unsigned long *>(ud);
    for (size_t i = 0; i < n; i++) *sum += p[i];
}

pray_status frame_sink(void *ud, const pray_image *img, const char *name) {
    // Touch the image, so that a bad frame is found here by the sanitizers, and encode it (any
    // pixel values a program can make: huge, infinite, NaN) with the writers, into a byte sink.
    long *count = static_cast<long *>(ud);
    if (!img || !name || img->width != 8 || img->height != 8 || !img->pixels) abort();
    volatile float sum = 0;
    for (int i = 0; i < img->width * img->height * 3; i++) sum = sum + img->pixels[i];
    pray_ctx *w = pray_new();
    if (w) {
        unsigned long bytes = 0;
        int bits = *count % 2 ? 16 : 8;
        if (pray_write_tiff(w, img, bits, byte_sink, &bytes) != PRAY_OK ||
            pray_write_ppm(w, img, bits, byte_sink, &bytes) != PRAY_OK) {
            fprintf(stderr, "fuzz_program: writing a rendered frame failed: %s\n", pray_error(w));
            abort();
        }
        pray_free(w);
    }
    ++*count;
    return PRAY_OK;
}

void broken(const char *what, pray_status st, const char *msg) {
    fprintf(stderr, "fuzz_program: %s (status %d, message \"%s\")\n", what, (int)st, msg ? msg : "(null)");
    abort();
}

// "DIR/fuzz.ray:" digits ":" digits ": error: ", or the same with the name of a file the program
// included (any name: an include may name an absolute path)
bool has_place(const char *m) {
    std::string p = program + ":";
    if (strncmp(m, p.c_str(), p.size()) == 0) m += p.size();
    else {
        const char *e = strstr(m, ": error: ");
        if (!e || e == m) return false;
        const char *q = e;  // back over ":digits:digits"
        for (int part = 0; part < 2; part++) {
            while (q > m && q[-1] >= '0' && q[-1] <= '9') q--;
            if (q == m || *--q != ':') return false;
        }
        if (q == m) return false;
        m = q + 1;
    }
    for (int part = 0; part < 2; part++) {
        if (*m < '0' || *m > '9') return false;
        while (*m >= '0' && *m <= '9') m++;
        if (*m++ != ':') return false;
    }
    return strncmp(m, " error: ", 8) == 0 && m[8] != 0;
}

// The files of an input (see the top): program[0] is the program's text, files[i] NAME.
struct Split {
    std::string program;
    std::string names[8], texts[8];
    int n;
};
bool file_name_ok(const std::string &name) {
    if (name.empty() || name.size() > 32 || name[0] == '.') return false;
    for (size_t i = 0; i < name.size(); i++) {
        char ch = name[i];
        if (!((ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') || (ch >= '0' && ch <= '9') || ch == '_' ||
              ch == '-' || ch == '.'))
            return false;
    }
    return name != "t.tif" && name != "f.tif" && name != "fuzz.ray";
}
void split_input(const char *data, size_t size, Split *out) {
    out->n = 0;
    std::string *part = &out->program;
    size_t i = 0;
    while (i < size) {
        size_t e = i;
        while (e < size && data[e] != '\n') e++;
        std::string line(data + i, e - i);
        if (line.compare(0, 7, "//file ") == 0 && out->n < 8 && file_name_ok(line.substr(7))) {
            out->names[out->n] = line.substr(7);
            part = &out->texts[out->n++];
        } else {
            part->append(line);
            if (e < size) part->push_back('\n');
        }
        i = e + 1;
    }
}

} // namespace

extern "C" int LLVMFuzzerInitialize(int *, char ***) {
    char tmpl[] = "/tmp/pray-fuzz.XXXXXX";
    if (!mkdtemp(tmpl)) abort();
    dir = tmpl;
    program = dir + "/fuzz.ray";
    atexit(remove_dir);
    write_tiff(dir + "/t.tif", 4, 4);
    write_tiff(dir + "/f.tif", 64, 64);  // 16 x 16 cells of 4 x 4 pixels
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    pray_ctx *c = pray_new();
    if (!c) return 0;
    pray_set_memory_limit(c, (size_t)64 << 20);
    pray_set_print(c, NULL, NULL);
    long frames = 0;
    pray_set_frame(c, frame_sink, &frames);
    static const char *const caps[][2] = {
        {"maxsteps", "20000"}, {"width", "8"}, {"height", "8"}, {"depth", "3"}, {"threads", "1"}, {"maxframes", "16"},
    };
    for (size_t i = 0; i < sizeof caps / sizeof caps[0]; i++)
        if (pray_option_fix(c, caps[i][0], caps[i][1]) != PRAY_OK) broken("a cap was refused", pray_last_status(c), pray_error(c));

    Split parts;
    split_input((const char *)data, size, &parts);
    for (int i = 0; i < parts.n; i++) {
        FILE *f = fopen((dir + "/" + parts.names[i]).c_str(), "wb");
        if (!f) abort();
        fwrite(parts.texts[i].data(), 1, parts.texts[i].size(), f);
        fclose(f);
    }
    pray_status st = pray_run_string(c, program.c_str(), parts.program.data(), parts.program.size());
    for (int i = 0; i < parts.n; i++) unlink((dir + "/" + parts.names[i]).c_str());
    const char *msg = pray_error(c);
    if (!msg) broken("pray_error returned NULL", st, msg);
    if (st != PRAY_OK) {
        if (st < PRAY_ERR_NOMEM || st > PRAY_ERR_ARG) broken("unknown status", st, msg);
        if (!msg[0]) broken("a failure without a message", st, msg);
        if (!strstr(msg, "error: ")) broken("a message without 'error: '", st, msg);
        // Syntax and runtime errors are errors of the program: they name the place.
        if ((st == PRAY_ERR_SYNTAX || st == PRAY_ERR_RUNTIME) && !has_place(msg))
            broken("a program error without NAME:line:col", st, msg);
    }
    if (pray_frames(c) < 0) broken("negative frame count", st, msg);
    pray_free(c);
    return 0;
}
