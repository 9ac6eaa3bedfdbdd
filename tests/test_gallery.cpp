// Every example and gallery scene renders without error at a small size, and its image with the
// default acceleration is the image of the brute-force reference, float for float.
// The textured scenes need examples/tex/ (make textures; make check does it first), or tex/ in the
// current directory with the examples named by PRAY_EXAMPLES (CTest does that in the build tree).
#include <doctest/doctest.h>

#include "testkit.hpp"

#include <cstdlib>
#include <string>
#include <vector>

namespace {

std::vector<testkit::Frame> render(const std::string &path, bool brute) {
    std::vector<testkit::Frame> frames;
    pray_ctx *c = pray_new();
    pray_set_frame(c, testkit::frame_sink, &frames);
    std::string printed;
    pray_set_print(c, testkit::print_sink, &printed);
    pray_option_fix(c, "width", "20");
    pray_option_fix(c, "height", "16");
    pray_option_fix(c, "brute", brute ? "1" : "0");
    pray_status st = pray_run_file(c, path.c_str());
    std::string err = pray_error(c);
    pray_free(c);
    CHECK_MESSAGE(st == PRAY_OK, path << ": " << err);
    return frames;
}

} // namespace

TEST_CASE("gallery: every example renders, and equals the brute-force reference") {
    const char *scenes[] = {"anim",    "chess",  "csg",      "cube",   "fractal", "glass",    "glassab",
                            "holes",   "loop",   "machine",  "maketex", "mirror", "models",   "parallel",
                            "pc",      "rabbit", "redsph",   "room",   "roomball", "sign",    "spot",
                            "street",  "textures", "water"};
    const char *dir = std::getenv("PRAY_EXAMPLES");
    for (const char *n : scenes) {
        std::string path = std::string(dir ? dir : "examples/") + n + ".ray";
        std::vector<testkit::Frame> fast = render(path, false), ref = render(path, true);
        REQUIRE_MESSAGE(!fast.empty(), path);
        REQUIRE(fast.size() == ref.size());
        for (size_t i = 0; i < fast.size(); i++) CHECK_MESSAGE(fast[i].pixels == ref[i].pixels, path << " frame " << i);
    }
}
