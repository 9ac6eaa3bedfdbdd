// Shared helpers of the tests: run PRAY programs in memory and look at what they printed,
// rendered and reported. Tests may use C++11 (doctest needs it); the library is C++98.
#ifndef PRAY_TESTKIT_HPP
#define PRAY_TESTKIT_HPP

#include "../pray.hpp"

#include <cmath>
#include <cstdlib>
#include <string>
#include <vector>

namespace testkit {

// A vector of the API from its three components.
inline pray_vec vec(double x, double y, double z) {
    pray_vec v = {x, y, z};
    return v;
}

// The command-line program the tests start: $PRAY (CTest sets it to the program it built), else
// ./pray, where make builds it. pray_shell() is the same, quoted for the shell.
inline std::string pray_program() {
    const char *p = std::getenv("PRAY");
    return p && *p ? p : "./pray";
}
inline std::string pray_shell() {
    std::string q = "'";
    for (char ch : pray_program()) q += ch == '\'' ? std::string("'\\''") : std::string(1, ch);
    return q + "'";
}

struct Frame {
    std::string name;  // the file name rendertiff would have written
    int width = 0, height = 0;
    std::vector<float> pixels;  // RGB, rows from the top
    // Channel ch of pixel (x, y).
    float at(int x, int y, int ch) const { return pixels[((size_t)y * width + x) * 3 + ch]; }
};

struct Result {
    pray_status status = PRAY_OK;
    std::string printed;  // everything `print` wrote
    std::string error;    // pray_error() after the run ("" when it succeeded)
    std::vector<Frame> frames;
};

inline void print_sink(void *ud, const void *data, size_t n) {
    static_cast<std::string *>(ud)->append(static_cast<const char *>(data), n);
}

inline pray_status frame_sink(void *ud, const pray_image *img, const char *name) {
    Frame f;
    f.name = name;
    f.width = img->width;
    f.height = img->height;
    f.pixels.assign(img->pixels, img->pixels + (size_t)img->width * img->height * 3);
    static_cast<std::vector<Frame> *>(ud)->push_back(f);
    return PRAY_OK;
}

// Run a program held in a string. Frames are captured, not written. `options` are fixed
// "name=value" settings, as with -D on the command line.
inline Result run(const std::string &program, const std::vector<std::string> &options = {},
                  const char *name = "test.ray") {
    Result r;
    pray_ctx *c = pray_new();
    pray_set_print(c, print_sink, &r.printed);
    pray_set_frame(c, frame_sink, &r.frames);
    for (const std::string &o : options) {
        size_t eq = o.find('=');
        pray_option_fix(c, o.substr(0, eq).c_str(), o.substr(eq + 1).c_str());
    }
    r.status = pray_run_string(c, name, program.data(), program.size());
    if (r.status != PRAY_OK) r.error = pray_error(c);
    pray_free(c);
    return r;
}

// A program rendered at w x h with antialias aa twice: fully sampled (frames[0], st[0]), then
// undersampled with threshold th (frames[1], st[1]). Both runs must succeed.
struct Sampled {
    std::vector<Frame> frames;
    pray_stats st[2];
};
inline Sampled full_and_adaptive(const std::string &program, int w, int h, int aa, double th) {
    Sampled r;
    for (int on = 0; on < 2; on++) {
        pray_ctx *c = pray_new();
        pray_option(c, "width", w);
        pray_option(c, "height", h);
        pray_option(c, "antialias", aa);
        pray_option(c, "adaptive", on ? th : 0);
        pray_set_frame(c, frame_sink, &r.frames);
        pray_status st = pray_run_string(c, "sampled.ray", program.data(), program.size());
        REQUIRE_MESSAGE(st == PRAY_OK, pray_error(c));
        pray_stats_get(c, &r.st[on]);
        pray_free(c);
    }
    REQUIRE(r.frames.size() == 2);
    return r;
}

// Printed output of a program that must succeed ("" and a failed check otherwise).
inline std::string printed(const std::string &program) { return run(program).printed; }

// The error message of a program that must fail.
inline std::string error_of(const std::string &program) { return run(program).error; }

} // namespace testkit

#endif
