// Sampling and threads: supersampling, undersampling (option adaptive), any number of threads.
#include <doctest/doctest.h>

#include "testkit.hpp"

#include <fstream>
#include <sstream>

namespace {

std::string file_text(const char *path) {
    std::ifstream f(path, std::ios::binary);
    std::stringstream ss;
    ss << f.rdbuf();
    return ss.str();
}

testkit::Frame one_frame(const std::string &program, const std::vector<std::string> &opts) {
    testkit::Result r = testkit::run(program, opts);
    REQUIRE_MESSAGE(r.status == PRAY_OK, r.error);
    REQUIRE(r.frames.size() >= 1);
    return r.frames[0];
}

} // namespace

TEST_CASE("images are identical for 1, 2, 3 and 8 threads") {
    const char *scenes[] = {"examples/csg.ray", "examples/glass.ray", "examples/holes.ray", "examples/fractal.ray"};
    for (const char *path : scenes) {
        std::string prog = file_text(path);
        REQUIRE(!prog.empty());
        testkit::Frame one = one_frame(prog, {"width=61", "height=37", "threads=1"});
        for (const char *t : {"threads=2", "threads=3", "threads=8"}) {
            testkit::Frame f = one_frame(prog, {"width=61", "height=37", t});
            CHECK_MESSAGE(f.pixels == one.pixels, path << " with " << t);
        }
        // with undersampling and supersampling too: the bands do not depend on the threads
        testkit::Frame a1 = one_frame(prog, {"width=61", "height=37", "threads=1", "adaptive=0.05", "antialias=3"});
        testkit::Frame a3 = one_frame(prog, {"width=61", "height=37", "threads=3", "adaptive=0.05", "antialias=3"});
        CHECK_MESSAGE(a1.pixels == a3.pixels, path << " adaptive");
    }
}

TEST_CASE("supersampling: exact coverage of a flat-coloured half-plane edge") {
    // A flat white face y = 0, cut at x = 0.02, seen head-on by a parallel camera: the pixel
    // column straddling the cut gets exactly the share of its samples on the white side.
    std::string prog =
        "parallel <1, 0, 0>, <0, 0, -1>, [0, -4, 0], [0, 0, 0]\n"
        "W = color({1})\n"
        "rendertiff plane(W, [0, 0, 0], <0, -1, 0>) & plane(W, [0.02, 0, 0], <1, 0, 0>), none\n";
    // 10 pixels across [-1, 1]: pixel 5 spans x in [0, 0.2]; the edge at 0.02 is 1/10 into it.
    for (int a : {1, 2, 4, 5, 10}) {
        testkit::Frame f = one_frame(prog, {"width=10", "height=1", "antialias=" + std::to_string(a)});
        int covered = 0;  // samples of pixel 5 with x = (a' + 0.5) / A * 0.2 < 0.02
        for (int s = 0; s < a; s++)
            if ((s + 0.5) / a * 0.2 < 0.02) covered++;
        CHECK(f.at(4, 0, 0) == 1.0f);
        CHECK(f.at(5, 0, 0) == doctest::Approx((double)covered / a).epsilon(1e-6));
        CHECK(f.at(6, 0, 0) == 0.0f);
    }
}

TEST_CASE("undersampling: off by default, fewer primary rays when on, exact where nothing changes") {
    std::string prog = file_text("examples/csg.ray");
    pray_ctx *c = pray_new();
    pray_option(c, "width", 64);
    pray_option(c, "height", 64);
    std::vector<testkit::Frame> frames;
    pray_set_frame(c, testkit::frame_sink, &frames);
    REQUIRE(pray_run_string(c, "csg.ray", prog.data(), prog.size()) == PRAY_OK);
    pray_stats full;
    pray_stats_get(c, &full);
    CHECK(full.rays_primary == 64 * 64);
    CHECK(full.rays_primary_full == 64 * 64);
    pray_option(c, "adaptive", 0.05);
    REQUIRE(pray_run_string(c, "csg.ray", prog.data(), prog.size()) == PRAY_OK);
    pray_stats ad;
    pray_stats_get(c, &ad);
    CHECK(ad.rays_primary_full == 64 * 64);
    CHECK(ad.rays_primary < full.rays_primary / 2);
    REQUIRE(frames.size() == 2);
    // the background far from the objects is interpolated between equal samples: exact
    CHECK(frames[1].at(0, 0, 0) == frames[0].at(0, 0, 0));
    CHECK(frames[1].at(63, 63, 2) == frames[0].at(63, 63, 2));
    pray_free(c);
}

TEST_CASE("undersampling refines edges down to single samples: flat colours come out as fully sampled") {
    // A flat white rectangle on black, head-on, its sides between samples. A cell of the lattice
    // whose corners all see the face lies on it, one whose corners all see the background lies
    // off it (the face is convex and larger than a cell), and the cells across a side are split
    // down to neighbouring samples: every sample ends up as full sampling traces it. The image
    // is several tiles wide and several bands high.
    std::string prog =
        "parallel <1, 0, 0>, <0, 0, -1>, [0, -4, 0], [0, 0, 0]\n"
        "W = color({1})\n"
        "rendertiff plane(W, [0, 0, 0], <0, -1, 0>) & plane(W, [0.37, 0, 0], <1, 0, 0>) & "
        "plane(W, [-0.41, 0, 0], <-1, 0, 0>) & plane(W, [0, 0, 0.29], <0, 0, 1>) & "
        "plane(W, [0, 0, -0.53], <0, 0, -1>), none\n";
    for (int aa : {1, 3, 4}) {
        CAPTURE(aa);
        testkit::Sampled r = testkit::full_and_adaptive(prog, 90, 70, aa, 0.02);
        const std::vector<testkit::Frame> &frames = r.frames;
        const pray_stats *st = r.st;
        REQUIRE(frames[0].at(45, 35, 0) == 1.0f);  // the face is in view, and its sides cut pixels
        REQUIRE(frames[0].at(0, 0, 0) == 0.0f);
        int partial = 0;
        for (float v : frames[0].pixels) partial += v > 0 && v < 1;
        REQUIRE(partial > (aa > 1 ? 0 : -1));
        CHECK(frames[1].pixels == frames[0].pixels);
        CHECK(st[1].rays_primary * (aa == 1 ? 3 : 6) < st[0].rays_primary);  // about one ray a pixel
    }
}

TEST_CASE("undersampling with threshold 0 is full sampling: the same image, every primary ray") {
    for (const char *file : {"examples/csg.ray", "examples/glass.ray", "examples/holes.ray"}) {
        CAPTURE(file);
        std::string prog = file_text(file);
        for (const char *aa : {"antialias=1", "antialias=3"}) {
            CAPTURE(aa);
            testkit::Result plain = testkit::run(prog, {"width=40", "height=30", aa});
            testkit::Result zero = testkit::run(prog, {"width=40", "height=30", aa, "adaptive=0"});
            testkit::Result on = testkit::run(prog, {"width=40", "height=30", aa, "adaptive=0.02"});
            REQUIRE(plain.frames.size() == 1);
            REQUIRE(zero.frames.size() == 1);
            REQUIRE(on.frames.size() == 1);
            CHECK(zero.frames[0].pixels == plain.frames[0].pixels);
            CHECK(on.frames[0].pixels != plain.frames[0].pixels);  // so the comparison can fail
        }
    }
}
