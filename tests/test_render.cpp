// Rendering through the public API and through PRAY programs (frames captured, not written):
// shading terms on tiny scenes whose pixel values are known exactly (docs/pray-language.md,
// sections 4 and 6), cameras and background, the API and the language building the same image,
// threads, allocators and memory limits.
#include <doctest/doctest.h>

#include "testkit.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

namespace {

using testkit::Frame;
using testkit::vec;
using testkit::Result;

pray_rgb rgb3(double r, double g, double b) {
    pray_rgb c;
    c.r = r;
    c.g = g;
    c.b = b;
    return c;
}

// The first frame of a program that must render exactly one frame.
Frame frame_of(const std::string &program, const std::vector<std::string> &options = {}) {
    Result r = testkit::run(program, options);
    INFO("program:\n", program);
    CHECK_MESSAGE(r.status == PRAY_OK, r.error);
    CHECK(r.frames.size() == 1);
    if (r.frames.empty()) return Frame();
    return r.frames[0];
}

// A 1x1 image seen by the default camera (eye [0,-4,0] looking along +Y at the origin).
const char *ONE = "option \"width\", 1\noption \"height\", 1\n";

// Pixel (x, y) is exactly (r, g, b) as floats.
void check_exact(const Frame &f, int x, int y, double r, double g, double b) {
    REQUIRE(f.width > x);
    REQUIRE(f.height > y);
    CAPTURE(x);
    CAPTURE(y);
    CHECK(f.at(x, y, 0) == (float)r);
    CHECK(f.at(x, y, 1) == (float)g);
    CHECK(f.at(x, y, 2) == (float)b);
}

// Pixel (x, y) is (r, g, b) to float precision (the renderer computes in double, stores floats).
void check_near(const Frame &f, int x, int y, double r, double g, double b, double tol = 1e-6) {
    REQUIRE(f.width > x);
    REQUIRE(f.height > y);
    CAPTURE(x);
    CAPTURE(y);
    CHECK(std::fabs(f.at(x, y, 0) - r) <= tol);
    CHECK(std::fabs(f.at(x, y, 1) - g) <= tol);
    CHECK(std::fabs(f.at(x, y, 2) - b) <= tol);
}

std::string read_file(const char *path) {
    std::ifstream in(path, std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

// A plane facing the default camera: the half-space y >= 0, outward normal -Y.
std::string facing_plane(const std::string &model) { return "plane(" + model + ", [0, 0, 0], <0, -1, 0>)"; }

} // namespace

// =============================================================================================
// Shading terms with exactly known values
// =============================================================================================
TEST_CASE("color(): a sphere filling the centre pixel shows exactly its colour, lit or not") {
    Frame f = frame_of(std::string(ONE) + "background {0.9}\n"
                                          "rendertiff sphere(color({0.25, 0.5, 0.75}), [0, 0, 0], 1)\n");
    check_exact(f, 0, 0, 0.25, 0.5, 0.75);
    // lights and a shadow-casting sphere change nothing: no lighting, no shadows
    f = frame_of(std::string(ONE) + "background {0.9}\n"
                                    "S = sphere(color({0.25, 0.5, 0.75}), [0, 0, 0], 1)\n"
                                    "Blocker = sphere(phong({1}, {0}, 1), [0, 0, 3], 0.5)\n"
                                    "rendertiff S | Blocker, dirlight({1}, <0, 0, -1>), pointlight({2}, [0, -3, 0])\n");
    check_exact(f, 0, 0, 0.25, 0.5, 0.75);
    // 3x3: the centre pixel hits a small sphere, the corners see the background
    f = frame_of("option \"width\", 3\noption \"height\", 3\nbackground {0.9, 0.8, 0.7}\n"
                 "rendertiff sphere(color({0.25, 0.5, 0.75}), [0, 0, 0], 0.5)\n");
    check_exact(f, 1, 1, 0.25, 0.5, 0.75);
    check_exact(f, 0, 0, 0.9, 0.8, 0.7);
    check_exact(f, 2, 2, 0.9, 0.8, 0.7);
}

TEST_CASE("phong: diffuse term C*I*(N.L) on a plane facing the camera") {
    // light travelling along the view direction: N.L = 1
    Frame f = frame_of(std::string(ONE) + "rendertiff " + facing_plane("phong({0.5, 0.25, 0.125}, {0}, 1)") +
                       ", dirlight({1, 0.5, 2}, <0, 1, 0>)\n");
    check_exact(f, 0, 0, 0.5, 0.125, 0.25);
    // light from above-front at 45 degrees: N.L = 1/sqrt(2)
    f = frame_of(std::string(ONE) + "rendertiff " + facing_plane("phong({0.5, 0.25, 0.125}, {0}, 1)") +
                 ", dirlight({1}, <0, 1, -1>)\n");
    double nl = 1 / std::sqrt(2.0);
    check_near(f, 0, 0, 0.5 * nl, 0.25 * nl, 0.125 * nl);
    // light from behind the surface: nothing
    f = frame_of(std::string(ONE) + "rendertiff " + facing_plane("phong({0.5, 0.25, 0.125}, {0}, 1)") +
                 ", dirlight({1}, <0, -1, 0>)\n");
    check_exact(f, 0, 0, 0, 0, 0);
}

TEST_CASE("phong: N.L computed at every pixel under a point light") {
    // default camera, 5x3 image; the plane y = 0 faces the camera; the point light is off-centre
    Frame f = frame_of("option \"width\", 5\noption \"height\", 3\n"
                       "rendertiff " +
                       facing_plane("phong({0.8, 0.6, 0.4}, {0}, 1)") + ", pointlight({1, 0.5, 1}, [0.7, -1.5, -0.4])\n");
    REQUIRE(f.width == 5);
    REQUIRE(f.height == 3);
    for (int j = 0; j < 3; j++)
        for (int i = 0; i < 5; i++) {
            double u = 2 * (i + 0.5) / 5 - 1, v = 2 * (j + 0.5) / 3 - 1;
            // ray from (0,-4,0) through P + uX + vY = (u, 0, -v): hits y = 0 exactly there
            double x[3] = {u, 0, -v};
            double L[3] = {0.7 - x[0], -1.5 - x[1], -0.4 - x[2]};
            double len = std::sqrt(L[0] * L[0] + L[1] * L[1] + L[2] * L[2]);
            double nl = -L[1] / len;  // N = (0, -1, 0)
            check_near(f, i, j, 0.8 * nl, 0.6 * 0.5 * nl, 0.4 * nl);
        }
}

TEST_CASE("phong: ambient is added once, lit or unlit") {
    std::string P = facing_plane("phong({0.5}, {0}, {0.125, 0.25, 0.0625}, 1)");
    Frame f = frame_of(std::string(ONE) + "rendertiff " + P + "\n");
    check_exact(f, 0, 0, 0.125, 0.25, 0.0625);
    f = frame_of(std::string(ONE) + "rendertiff " + P + ", none\n");
    check_exact(f, 0, 0, 0.125, 0.25, 0.0625);
    f = frame_of(std::string(ONE) + "rendertiff " + P + ", dirlight({0.5}, <0, 1, 0>), dirlight({0.25}, <0, 1, 0>)\n");
    check_exact(f, 0, 0, 0.125 + 0.25 + 0.125, 0.25 + 0.25 + 0.125, 0.0625 + 0.25 + 0.125);
}

TEST_CASE("phong: specular term S*I*max(0, R.V)^E") {
    // at the mirror direction R = V: the full S*I
    Frame f = frame_of(std::string(ONE) + "rendertiff " + facing_plane("phong({0.5}, {0.25, 0.125, 0}, {0.125}, 7)") +
                       ", dirlight({1}, <0, 1, 0>)\n");
    check_exact(f, 0, 0, 0.5 + 0.25 + 0.125, 0.5 + 0.125 + 0.125, 0.5 + 0 + 0.125);
    // light 30 degrees off the normal: N.L = cos 30, R.V = cos 30 (V is the normal here)
    f = frame_of(std::string(ONE) + "rendertiff " + facing_plane("phong({0.5}, {0.25}, 3)") +
                 ", dirlight({1}, <0, sqrt(3), -1>)\n");
    double c30 = std::sqrt(3.0) / 2;
    double want = 0.5 * c30 + 0.25 * std::pow(c30, 3);
    check_near(f, 0, 0, want, want, want);
    // the exponent matters
    f = frame_of(std::string(ONE) + "rendertiff " + facing_plane("phong({0}, {1}, 20)") + ", dirlight({1}, <0, sqrt(3), -1>)\n");
    want = std::pow(c30, 20);
    check_near(f, 0, 0, want, want, want);
    // whole exponents are taken by repeated squaring, others by pow: both give c30^E
    f = frame_of(std::string(ONE) + "rendertiff " + facing_plane("phong({0}, {1}, 2.5)") + ", dirlight({1}, <0, sqrt(3), -1>)\n");
    want = std::pow(c30, 2.5);
    check_near(f, 0, 0, want, want, want);
    f = frame_of(std::string(ONE) + "rendertiff " + facing_plane("phong({0}, {1}, 1000)") + ", dirlight({1}, <0, sqrt(3), -1>)\n");
    want = std::pow(c30, 1000);  // 5e-63: black, not the 1 of a power left undone
    check_near(f, 0, 0, want, want, want);
}

TEST_CASE("shadows: an occluder between the plane and the light leaves the ambient term only") {
    // light from above-front; the occluder sits on the shadow ray from the origin, off the view ray
    std::string P = facing_plane("phong({0.5}, {0}, {0.125}, 1)");
    std::string L = "dirlight({1}, <0, 1, -1>)";
    double lit = 0.125 + 0.5 / std::sqrt(2.0);
    Frame f = frame_of(std::string(ONE) + "rendertiff " + P + ", " + L + "\n");
    check_near(f, 0, 0, lit, lit, lit);
    std::string occ = "sphere(phong({0.3}, {0}, 1), [0, -1, 1], 0.3)";
    f = frame_of(std::string(ONE) + "rendertiff " + P + " | " + occ + ", " + L + "\n");
    check_exact(f, 0, 0, 0.125, 0.125, 0.125);
    // the option shadows 0 removes them; the command line's -D does the same
    f = frame_of(std::string(ONE) + "option \"shadows\", 0\nrendertiff " + P + " | " + occ + ", " + L + "\n");
    check_near(f, 0, 0, lit, lit, lit);
    f = frame_of(std::string(ONE) + "rendertiff " + P + " | " + occ + ", " + L + "\n", {"shadows=0"});
    check_near(f, 0, 0, lit, lit, lit);
    // a directional light is shadowed by an occluder however far along it
    f = frame_of(std::string(ONE) + "rendertiff " + P + " | sphere(phong({0.3}, {0}, 1), [0, -1000, 1000], 10), " + L + "\n");
    check_exact(f, 0, 0, 0.125, 0.125, 0.125);
    // a point light in front of the occluder is not shadowed by it
    f = frame_of(std::string(ONE) + "rendertiff " + P + " | " + occ + ", pointlight({1}, [0, -0.5, 0.5])\n");
    check_near(f, 0, 0, lit, lit, lit);
}

TEST_CASE("shadows through transparent solids: T at every surface crossed") {
    std::string P = facing_plane("phong({0.5}, {0}, {0.125}, 1)");
    std::string L = "dirlight({1}, <0, 1, -1>)";
    double d = 0.5 / std::sqrt(2.0);
    Frame f = frame_of(std::string(ONE) + "rendertiff " + P + " | sphere(transparent({0.5}, 1), [0, -1, 1], 0.3), " + L + "\n");
    check_near(f, 0, 0, 0.125 + 0.25 * d, 0.125 + 0.25 * d, 0.125 + 0.25 * d);
    // per channel, and two spheres in a row: T^4
    f = frame_of(std::string(ONE) + "G = transparent({0.5, 0.25, 1}, 1.5)\nrendertiff " + P +
                 " | sphere(G, [0, -1, 1], 0.3) | sphere(G, [0, -2, 2], 0.3), " + L + "\n");
    check_near(f, 0, 0, 0.125 + 0.0625 * d, 0.125 + std::pow(0.25, 4) * d, 0.125 + d);
}

TEST_CASE("mirror: a mirror plane shows a color() sphere exactly") {
    std::string S = "sphere(color({0.25, 0.5, 0.75}), [0, -10, 0], 1)";  // behind the camera
    Frame f = frame_of(std::string(ONE) + "background {0.9}\nrendertiff " + facing_plane("mirror({1})") + " | " + S + "\n");
    check_exact(f, 0, 0, 0.25, 0.5, 0.75);
    f = frame_of(std::string(ONE) + "background {0.9}\nrendertiff " + facing_plane("mirror({0.5, 1, 0.25})") + " | " + S + "\n");
    check_exact(f, 0, 0, 0.125, 0.5, 0.1875);
    // a reflected ray that meets nothing returns the background
    f = frame_of(std::string(ONE) + "background {0.5, 0.25, 1}\nrendertiff " + facing_plane("mirror({0.5})") + "\n");
    check_exact(f, 0, 0, 0.25, 0.125, 0.5);
}

TEST_CASE("depth: level 1 is the eye ray, deeper rays contribute nothing") {
    std::string M = facing_plane("mirror({1})") + " | sphere(color({0.25, 0.5, 0.75}), [0, -10, 0], 1)";
    Frame f = frame_of(std::string(ONE) + "background {0.9}\noption \"depth\", 1\nrendertiff " + M + "\n");
    check_exact(f, 0, 0, 0, 0, 0);  // black, not the background
    f = frame_of(std::string(ONE) + "background {0.9}\noption \"depth\", 2\nrendertiff " + M + "\n");
    check_exact(f, 0, 0, 0.25, 0.5, 0.75);
    // two mirrors facing each other, each with a colour of its own: one colour per level
    std::string PP = facing_plane("color({0.125, 0, 0}) + mirror({1})") +
                     " | sphere(color({0, 0.25, 0}) + mirror({1}), [0, -10, 0], 1)";
    const double want[6][2] = {{0, 0}, {0.125, 0}, {0.125, 0.25}, {0.25, 0.25}, {0.25, 0.5}, {0.375, 0.5}};
    for (int depth = 1; depth <= 5; depth++) {
        CAPTURE(depth);
        f = frame_of(std::string(ONE) + "background {0.9}\noption \"depth\", " + std::to_string(depth) + "\nrendertiff " + PP + "\n");
        check_exact(f, 0, 0, want[depth][0], want[depth][1], 0);
    }
    // the default depth is 5
    f = frame_of(std::string(ONE) + "background {0.9}\nrendertiff " + PP + "\n");
    check_exact(f, 0, 0, 0.375, 0.5, 0);
}

TEST_CASE("cutoff: the rays left out move no sample by half an output step; cutoff 0 traces the whole tree") {
    // glass balls that reflect and pass light between two mirror walls, under bright lights: a
    // deep ray tree whose far branches add little
    std::string prog = "option \"width\", 40\noption \"height\", 30\noption \"depth\", 12\nbackground {0.3, 0.4, 0.9}, {1.5}\n"
                       "G = transparent({0.7, 0.8, 0.9}, 1.5) + mirror({0.2}) + phong({0.05}, {0.9}, 40)\n"
                       "W = mirror({0.8, 0.9, 0.7}) + phong({0.1, 0.05, 0}, {0.3}, 10)\n"
                       "S = sphere(G, [-0.6, 0, 0], 0.5) | sphere(G, [0.6, 0.5, 0.2], 0.45) | (sphere(G, [0, 1.5, -0.3], 0.6) - sphere(G, [0, 1.2, -0.3], 0.3))\n"
                       "S = S | -plane(W, [0, 3, 0], <0, 1, 0>) | plane(W, [0, -6, 0], <0, 1, 0>) | plane(phong({0.6}, {0.2}, 5), [0, 0, -1], <0, 0, 1>)\n"
                       "rendertiff S, pointlight({2.5, 2, 2}, [1, -3, 3]) | dirlight({0.8}, <-1, 1, -2>)\n";
    struct Run {
        std::vector<float> px;
        double secondary;
    };
    auto render = [&](int cutoff, int bits) {
        Run r;
        std::vector<testkit::Frame> frames;
        pray_ctx *c = pray_new();
        pray_set_frame(c, testkit::frame_sink, &frames);
        pray_option(c, "cutoff", cutoff);
        pray_option(c, "bits", bits);
        REQUIRE(pray_run_string(c, "cut.ray", prog.data(), prog.size()) == PRAY_OK);
        pray_stats st;
        pray_stats_get(c, &st);
        r.secondary = st.rays_reflected + st.rays_refracted;
        pray_free(c);
        REQUIRE(frames.size() == 1);
        r.px = frames[0].pixels;
        return r;
    };
    Run whole = render(0, 8);
    CHECK(render(0, 16).px == whole.px);  // without the cut-off the bits change nothing
    for (int bits : {8, 16}) {
        CAPTURE(bits);
        double step = 1.0 / ((1 << bits) - 1);
        Run cut = render(1, bits);
        REQUIRE(cut.secondary < whole.secondary);  // (rays were left out: the checks below mean something)
        double worst = 0;
        int moved = 0;
        for (size_t i = 0; i < whole.px.size(); i++) {
            double d = std::fabs((double)cut.px[i] - whole.px[i]);
            worst = d > worst ? d : worst;
            auto q = [&](float v) { return v <= 0 ? 0L : v >= 1 ? (long)((1 << bits) - 1) : (long)((double)v * ((1 << bits) - 1) + 0.5); };
            long dq = q(cut.px[i]) - q(whole.px[i]);
            CHECK(std::labs(dq) <= 1);
            moved += dq != 0;
        }
        CHECK(worst < 0.5 * step * (1 + 1e-6));  // (float pixels: a relative hair of rounding)
        MESSAGE("bits " << bits << ": secondary rays " << cut.secondary << " of " << whole.secondary << ", largest change "
                        << worst / step << " step, " << moved << " of " << whole.px.size() << " channels moved by one step");
    }
}

TEST_CASE("transparent with index 1: the object behind, times T at each surface") {
    std::string Behind = "sphere(color({0.25, 0.5, 1}), [0, 5, 0], 1)";
    Frame f = frame_of(std::string(ONE) + "background {0.9}\nrendertiff sphere(transparent({0.5, 0.25, 1}, 1), [0, 0, 0], 1) | " +
                       Behind + "\n");
    check_exact(f, 0, 0, 0.25 * 0.25, 0.5 * 0.0625, 1);
    // the eye inside the glass: one surface only
    f = frame_of(std::string(ONE) + "background {0.9}\nperspective <1, 0, 0>, <0, 0, -1>, [0, 0, 0], [0, 1, 0]\n"
                                    "rendertiff sphere(transparent({0.5, 0.25, 1}, 1), [0, 0, 0], 2) | " +
                 Behind + "\n");
    check_exact(f, 0, 0, 0.125, 0.125, 1);
}

TEST_CASE("transparent: total internal reflection sends the transmitted weight into the reflection") {
    // The eye is inside glass (z <= 0, index 2) and looks up at 60 degrees from the normal: past
    // the critical angle (30 degrees) nothing leaves; the reflection meets a colour cavity.
    std::string cam = "perspective <0, 1, 0>, <0.5, 0, -sqrt(3)/2>, [0, 0, -1], [sqrt(3)/2, 0, -0.5]\n";
    std::string cavity = "sphere(color({0.25, 0.5, 0.75}), [2*sqrt(3), 0, -1], 0.5)";
    Frame f = frame_of(std::string(ONE) + "background {1}\n" + cam + "rendertiff plane(transparent({0.5}, 2), [0, 0, 0], <0, 0, 1>) - " +
                       cavity + "\n");
    check_near(f, 0, 0, 0.125, 0.25, 0.375);
    // with index 1 the ray leaves straight: the background through one surface
    f = frame_of(std::string(ONE) + "background {1}\n" + cam + "rendertiff plane(transparent({0.5}, 1), [0, 0, 0], <0, 0, 1>) - " +
                 cavity + "\n");
    check_near(f, 0, 0, 0.5, 0.5, 0.5);
}

TEST_CASE("background: one colour, and the vertical blend from the top row to the bottom row") {
    Frame f = frame_of("option \"width\", 2\noption \"height\", 3\nrendertiff nothing\n");
    for (int j = 0; j < 3; j++)
        for (int i = 0; i < 2; i++) check_exact(f, i, j, 0, 0, 0);  // default {0}
    f = frame_of("option \"width\", 2\noption \"height\", 3\nbackground {0.3, 0.6, 0.9}\nrendertiff nothing\n");
    for (int j = 0; j < 3; j++)
        for (int i = 0; i < 2; i++) check_exact(f, i, j, 0.3, 0.6, 0.9);
    f = frame_of("option \"width\", 2\noption \"height\", 5\nbackground {0.1, 0.2, 0.3}, {0.7, 0.5, 0.9}\nrendertiff nothing\n");
    REQUIRE(f.height == 5);
    for (int i = 0; i < 2; i++) {
        check_exact(f, i, 0, 0.1, 0.2, 0.3);
        check_exact(f, i, 4, 0.7, 0.5, 0.9);
        for (int j = 1; j < 4; j++) {
            double s = j / 4.0;
            check_near(f, i, j, 0.1 + 0.6 * s, 0.2 + 0.3 * s, 0.3 + 0.6 * s);
        }
    }
}

TEST_CASE("models combine: sums add coefficients, products scale them") {
    Frame f = frame_of(std::string(ONE) + "rendertiff sphere(color({0.25, 0, 0.5}) + color({0.5, 0.25, 0}), [0, 0, 0], 1)\n");
    check_exact(f, 0, 0, 0.75, 0.25, 0.5);
    f = frame_of(std::string(ONE) + "rendertiff sphere(color({0.5}) * {1, 0.5, 0.25}, [0, 0, 0], 1)\n");
    check_exact(f, 0, 0, 0.5, 0.25, 0.125);
    f = frame_of(std::string(ONE) + "rendertiff " + facing_plane("phong({0.5}, {0}, 1) + color({0.25})") +
                 ", dirlight({1}, <0, 1, 0>)\n");
    check_exact(f, 0, 0, 0.75, 0.75, 0.75);
    f = frame_of(std::string(ONE) + "rendertiff " + facing_plane("phong({0.5}, {0.25}, {0.125}, 7) * 0.5") +
                 ", dirlight({1}, <0, 1, 0>)\n");
    check_exact(f, 0, 0, 0.4375, 0.4375, 0.4375);
    // phong + mirror: both terms (the point light sits between the plane and the sphere, which
    // would otherwise shadow the plane)
    f = frame_of(std::string(ONE) + "background {0.9}\nrendertiff " + facing_plane("phong({0.5}, {0}, 1) + mirror({0.5})") +
                 " | sphere(color({0.25, 0.5, 0.75}), [0, -10, 0], 1), pointlight({0.5}, [0, -2, 0])\n");
    check_exact(f, 0, 0, 0.25 + 0.125, 0.25 + 0.25, 0.25 + 0.375);
    // both operands carry an exponent: the left one's is kept
    double c30 = std::sqrt(3.0) / 2;
    f = frame_of(std::string(ONE) + "rendertiff " + facing_plane("phong({0}, {1}, 2) + phong({0}, {0}, 40)") +
                 ", dirlight({1}, <0, sqrt(3), -1>)\n");
    check_near(f, 0, 0, c30 * c30, c30 * c30, c30 * c30);
}

// =============================================================================================
// Cameras
// =============================================================================================
TEST_CASE("perspective: pixel centres at u = 2(i+1/2)/W - 1, v = 2(j+1/2)/H - 1, v growing down") {
    // Y = <0,0,1>: down the image is +Z. Spheres on the rays of pixel (3, 0) and pixel (0, 1).
    Frame f = frame_of("option \"width\", 4\noption \"height\", 2\nbackground {0.9}\n"
                       "perspective <1, 0, 0>, <0, 0, 1>, [0, -4, 0], [0, 0, 0]\n"
                       "rendertiff sphere(color({1, 0, 0}), [0.75, 0, -0.5], 0.1) | sphere(color({0, 1, 0}), [-0.75, 0, 0.5], 0.1)\n");
    REQUIRE(f.width == 4);
    REQUIRE(f.height == 2);
    for (int j = 0; j < 2; j++)
        for (int i = 0; i < 4; i++) {
            if (i == 3 && j == 0) check_exact(f, i, j, 1, 0, 0);
            else if (i == 0 && j == 1) check_exact(f, i, j, 0, 1, 0);
            else check_exact(f, i, j, 0.9, 0.9, 0.9);
        }
    // the same through the API
    pray_ctx *c = pray_new();
    pray_option(c, "width", 4);
    pray_option(c, "height", 2);
    pray_background(c, rgb3(0.9, 0.9, 0.9), rgb3(0.9, 0.9, 0.9));
    REQUIRE(pray_perspective(c, vec(1, 0, 0), vec(0, 0, 1), vec(0, -4, 0), vec(0, 0, 0)) == PRAY_OK);
    pray_object *o = pray_csg(c, PRAY_UNION, pray_sphere(c, pray_color(c, rgb3(1, 0, 0)), vec(0.75, 0, -0.5), 0.1),
                              pray_sphere(c, pray_color(c, rgb3(0, 1, 0)), vec(-0.75, 0, 0.5), 0.1));
    pray_image img;
    REQUIRE(pray_render(c, o, NULL, &img) == PRAY_OK);
    Frame g;
    g.width = img.width;
    g.height = img.height;
    g.pixels.assign(img.pixels, img.pixels + 4 * 2 * 3);
    CHECK(g.pixels == f.pixels);
    pray_image_free(c, &img);
    pray_free(c);
}

TEST_CASE("perspective: the default camera looks along +Y with Z up") {
    // pixel (0, 0) is top left: a sphere up and to the left of the origin
    Frame f = frame_of("option \"width\", 2\noption \"height\", 2\n"
                       "rendertiff sphere(color({1}), [-0.5, 0, 0.5], 0.2)\n");
    check_exact(f, 0, 0, 1, 1, 1);
    check_exact(f, 1, 0, 0, 0, 0);
    check_exact(f, 0, 1, 0, 0, 0);
    check_exact(f, 1, 1, 0, 0, 0);
}

TEST_CASE("parallel: the ray of (u, v) starts at E + uX + vY, along norm(P - E)") {
    Frame f = frame_of("option \"width\", 4\noption \"height\", 4\nbackground {0.9}\n"
                       "parallel <1, 0, 0>, <0, 0, -1>, [0, -4, 0], [0, 0, 0]\n"
                       "rendertiff sphere(color({1, 0, 0}), [-0.25, 7, -0.25], 0.1) | sphere(color({0, 0, 1}), [0.75, -2, 0.75], 0.1)\n");
    REQUIRE(f.width == 4);
    for (int j = 0; j < 4; j++)
        for (int i = 0; i < 4; i++) {
            if (i == 1 && j == 2) check_exact(f, i, j, 1, 0, 0);
            else if (i == 3 && j == 0) check_exact(f, i, j, 0, 0, 1);
            else check_exact(f, i, j, 0.9, 0.9, 0.9);
        }
    // an oblique parallel view: eye off the axis, the direction from E to P
    f = frame_of("option \"width\", 3\noption \"height\", 3\nbackground {0.9}\n"
                 "parallel <1, 0, 0>, <0, 0, -1>, [1, -3, 2], [1, 0, 2]\n"
                 "rendertiff sphere(color({0, 1, 0}), [1 + 2/3, 5, 2 + 2/3], 0.1)\n");
    check_exact(f, 2, 0, 0, 1, 0);
    check_exact(f, 1, 1, 0.9, 0.9, 0.9);
}

// =============================================================================================
// Lights
// =============================================================================================
TEST_CASE("pointlight: no fall-off with distance") {
    std::string P = facing_plane("phong({0.5}, {0}, 1)");
    Frame near = frame_of(std::string(ONE) + "rendertiff " + P + ", pointlight({1, 0.5, 0.25}, [0, -2, 0])\n");
    check_exact(near, 0, 0, 0.5, 0.25, 0.125);
    Frame far = frame_of(std::string(ONE) + "rendertiff " + P + ", pointlight({1, 0.5, 0.25}, [0, -3.5, 0])\n");
    check_exact(far, 0, 0, 0.5, 0.25, 0.125);
    // behind the eye, far away: still the same
    Frame farther = frame_of(std::string(ONE) + "rendertiff " + P + ", pointlight({1, 0.5, 0.25}, [0, -1000, 0])\n");
    check_exact(farther, 0, 0, 0.5, 0.25, 0.125);
}

TEST_CASE("two lights add; lights combine with | and +") {
    std::string P = facing_plane("phong({0.5}, {0}, {0.0625}, 1)");
    Frame f = frame_of(std::string(ONE) + "rendertiff " + P + ", pointlight({0.5}, [0, -2, 0]), dirlight({0.25, 0.5, 1}, <0, 1, 0>)\n");
    check_exact(f, 0, 0, 0.0625 + 0.25 + 0.125, 0.0625 + 0.25 + 0.25, 0.0625 + 0.25 + 0.5);
    Frame g = frame_of(std::string(ONE) + "rendertiff " + P + ", pointlight({0.5}, [0, -2, 0]) | dirlight({0.25, 0.5, 1}, <0, 1, 0>)\n");
    CHECK(g.pixels == f.pixels);
    Frame h = frame_of(std::string(ONE) + "L = none\nL = L + pointlight({0.5}, [0, -2, 0])\nL = L + dirlight({0.25, 0.5, 1}, <0, 1, 0>)\n"
                                          "rendertiff " +
                       P + ", L\n");
    CHECK(h.pixels == f.pixels);
}

// =============================================================================================
// The API and the language build the same image
// =============================================================================================
namespace {
pray_vec v_sub(pray_vec a, pray_vec b) { return vec(a.x - b.x, a.y - b.y, a.z - b.z); }
pray_vec v_mul(pray_vec a, double s) { return vec(a.x * s, a.y * s, a.z * s); }
pray_vec v_cross(pray_vec a, pray_vec b) {
    return vec(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
pray_vec v_norm(pray_vec a) { return v_mul(a, 1.0 / std::sqrt(a.x * a.x + a.y * a.y + a.z * a.z)); }

// CSG.RAY of the thesis (examples/csg.ray), built through the API.
pray_object *csg_ray_scene(pray_ctx *c, pray_light **light) {
    pray_vec X = vec(1, 0, 0), Eye = vec(2, -5, 2), Point = vec(0.5, 0.5, 0.5);
    pray_vec View = v_sub(Point, Eye);
    pray_vec Y = v_mul(v_norm(v_cross(X, View)), -1.1);
    X = v_mul(v_norm(v_cross(Y, View)), 1.1);
    if (pray_perspective(c, X, Y, Eye, Point) != PRAY_OK) return NULL;
    *light = pray_dirlight(c, rgb3(1, 1, 1), vec(-0.3, 0.6, -0.4));
    pray_model *White = pray_phong(c, rgb3(0.6, 0.6, 0.6), rgb3(0.3, 0.3, 0.3), rgb3(0.1, 0.1, 0.1), 10);
    pray_object *o1 = pray_plane(c, White, vec(-0.1, 0, 0), vec(-1, 0, 0));
    pray_object *o2 = pray_plane(c, White, vec(0.1, 0, 0), vec(1, 0, 0));
    pray_object *o3 = pray_plane(c, White, vec(0, -0.1, 0), vec(0, -1, 0));
    pray_object *o4 = pray_plane(c, White, vec(0, 0.1, 0), vec(0, 1, 0));
    pray_object *o5 = pray_plane(c, White, vec(0, 0, -0.1), vec(0, 0, -1));
    pray_object *o6 = pray_plane(c, White, vec(0, 0, 0.1), vec(0, 0, 1));
    pray_object *Cube = o1;
    pray_object *rest[] = {o2, o3, o4, o5, o6};
    for (int i = 0; i < 5; i++) Cube = pray_csg(c, PRAY_INTERSECTION, Cube, rest[i]);
    pray_object *o7 = pray_cylinder(c, White, vec(0, 0, 0), vec(0, 0, 1), 0.05);
    pray_object *o8 = pray_plane(c, White, vec(0, 0, 0.15), vec(0, 0, 1));
    pray_object *o9 = pray_plane(c, White, vec(0, 0, -0.15), vec(0, 0, -1));
    pray_object *Cylinder = pray_csg(c, PRAY_INTERSECTION, pray_csg(c, PRAY_INTERSECTION, o7, o8), o9);
    pray_object *Uni = pray_csg(c, PRAY_UNION, Cube, Cylinder);
    pray_object *Int = pray_csg(c, PRAY_INTERSECTION, Cube, Cylinder);
    pray_object *Dif = pray_csg(c, PRAY_DIFFERENCE, Cube, Cylinder);
    pray_object *Ope = pray_csg(c, PRAY_UNION, pray_csg(c, PRAY_UNION, pray_translate(c, Uni, vec(-0.3, 0, 0)), Dif),
                                pray_translate(c, Int, vec(0.25, 0, 0)));
    pray_object *Pri = pray_csg(c, PRAY_UNION, pray_translate(c, Cube, vec(-0.15, 0, 0.4)),
                                pray_translate(c, Cylinder, vec(0.2, 0, 0.4)));
    return pray_translate(c, pray_scale(c, pray_csg(c, PRAY_UNION, Ope, Pri), 1.3), vec(0.55, 0.5, 0.25));
}

Frame render_api_csg(int w, int h) {
    Frame f;
    pray_ctx *c = pray_new();
    pray_option(c, "width", w);
    pray_option(c, "height", h);
    pray_light *light = NULL;
    pray_object *root = csg_ray_scene(c, &light);
    pray_image img;
    if (root && light && pray_render(c, root, light, &img) == PRAY_OK) {
        f.width = img.width;
        f.height = img.height;
        f.pixels.assign(img.pixels, img.pixels + (size_t)img.width * img.height * 3);
        pray_image_free(c, &img);
    } else {
        f.name = pray_error(c);
    }
    pray_free(c);
    return f;
}
} // namespace

TEST_CASE("CSG.RAY built through the API renders the same image as the program") {
    std::string prog = read_file("examples/csg.ray");
    REQUIRE_MESSAGE(!prog.empty(), "examples/csg.ray not found: run the tests from the repository root");
    Frame want = frame_of(prog, {"width=64", "height=64"});
    Frame got = render_api_csg(64, 64);
    INFO(got.name);
    REQUIRE(got.width == 64);
    REQUIRE(got.height == 64);
    REQUIRE(want.pixels.size() == got.pixels.size());
    size_t differ = 0, first = (size_t)-1;
    for (size_t i = 0; i < got.pixels.size(); i++)
        if (got.pixels[i] != want.pixels[i]) {
            differ++;
            if (first == (size_t)-1) first = i;
        }
    CHECK_MESSAGE(differ == 0, differ, " floats differ, the first at index ", first);
    // and the picture is not empty: the white solids are lit
    int lit = 0;
    for (size_t i = 0; i < got.pixels.size(); i += 3)
        if (got.pixels[i] > 0.2f) lit++;
    CHECK(lit > 200);
}

TEST_CASE("two contexts on two threads render the same images as one after the other") {
    std::string csg = read_file("examples/csg.ray");
    std::string glass = read_file("examples/glass.ray");
    REQUIRE(!csg.empty());
    REQUIRE(!glass.empty());
    std::vector<std::string> opts = {"width=40", "height=30"};
    Result a1 = testkit::run(csg, opts), b1 = testkit::run(glass, opts);
    REQUIRE(a1.status == PRAY_OK);
    REQUIRE(b1.status == PRAY_OK);
    Result a2, b2;
    Frame c2;
    std::thread ta([&] { a2 = testkit::run(csg, opts); });
    std::thread tb([&] { b2 = testkit::run(glass, opts); });
    std::thread tc([&] { c2 = render_api_csg(40, 30); });
    ta.join();
    tb.join();
    tc.join();
    REQUIRE(a2.frames.size() == 1);
    REQUIRE(b2.frames.size() == 1);
    CHECK(a2.frames[0].pixels == a1.frames[0].pixels);
    CHECK(b2.frames[0].pixels == b1.frames[0].pixels);
    CHECK(c2.pixels == a1.frames[0].pixels);
    CHECK(a1.frames[0].pixels != b1.frames[0].pixels);
}

// =============================================================================================
// Memory
// =============================================================================================
namespace {
struct Counter {
    long long live = 0;         // bytes held now
    long blocks = 0;            // blocks held now
    long long total = 0;        // allocations made
    long bad_osize = 0;         // frees or resizes that gave a wrong old size
    std::map<void *, size_t> sizes;
};

void *counting_alloc(void *ud, void *ptr, size_t osize, size_t nsize) {
    Counter *k = static_cast<Counter *>(ud);
    if (ptr) {
        std::map<void *, size_t>::iterator it = k->sizes.find(ptr);
        if (it == k->sizes.end() || it->second != osize) k->bad_osize++;
        if (it != k->sizes.end()) {
            k->live -= (long long)it->second;
            k->blocks--;
            k->sizes.erase(it);
        }
    }
    if (nsize == 0) {
        std::free(ptr);
        return NULL;
    }
    void *p = std::realloc(ptr, nsize);
    if (!p) return NULL;
    k->sizes[p] = nsize;
    k->live += (long long)nsize;
    k->blocks++;
    k->total++;
    return p;
}

void discard(void *, const void *, size_t) {}
pray_status keep_frame(void *ud, const pray_image *img, const char *) {
    *static_cast<int *>(ud) += img->width * img->height;
    return PRAY_OK;
}
} // namespace

TEST_CASE("pray_new_with: every byte goes back to the allocator at pray_free") {
    Counter k;
    pray_ctx *c = pray_new_with(counting_alloc, &k);
    REQUIRE(c != NULL);
    CHECK(k.blocks >= 1);
    // a program with prints, a render and an error afterwards
    std::string prog = read_file("examples/csg.ray");
    int pixels = 0;
    pray_set_print(c, discard, NULL);
    pray_set_frame(c, keep_frame, &pixels);
    pray_option_fix(c, "width", "16");
    pray_option_fix(c, "height", "16");
    CHECK(pray_run_string(c, "csg.ray", prog.data(), prog.size()) == PRAY_OK);
    CHECK(pixels == 256);
    const char *bad = "X = 1\nprint X + Y\n";
    CHECK(pray_run_string(c, "bad.ray", bad, strlen(bad)) != PRAY_OK);
    // the API: objects, a render, an image written to a sink, some handles released, most not
    pray_light *light = NULL;
    pray_object *root = csg_ray_scene(c, &light);
    REQUIRE(root != NULL);
    pray_image img;
    REQUIRE(pray_render(c, root, light, &img) == PRAY_OK);
    CHECK(pray_write_ppm(c, &img, 16, discard, NULL) == PRAY_OK);
    CHECK(pray_write_tiff(c, &img, 8, discard, NULL) == PRAY_OK);
    pray_image_free(c, &img);
    pray_release(c, root);
    CHECK(k.live > 0);
    pray_free(c);
    CHECK(k.live == 0);
    CHECK(k.blocks == 0);
    CHECK(k.bad_osize == 0);
    CHECK(k.total > 10);
}

TEST_CASE("a memory limit makes a render fail with PRAY_ERR_NOMEM and a message") {
    pray_ctx *c = pray_new();
    pray_option(c, "width", 64);
    pray_option(c, "height", 64);
    pray_object *s = pray_sphere(c, pray_color(c, rgb3(1, 0, 0)), vec(0, 0, 0), 1);
    REQUIRE(s != NULL);
    pray_set_memory_limit(c, 8192);  // the 64 x 64 float image alone needs 48 KiB
    pray_image img;
    img.pixels = (float *)&img;  // must be reset by the failing call
    CHECK(pray_render(c, s, NULL, &img) == PRAY_ERR_NOMEM);
    CHECK(img.pixels == NULL);
    CHECK(std::string(pray_error(c)).find("memory") != std::string::npos);
    CHECK(pray_last_status(c) == PRAY_ERR_NOMEM);
    // the context is still good: lift the cap and render
    pray_set_memory_limit(c, 0);
    REQUIRE(pray_render(c, s, NULL, &img) == PRAY_OK);
    CHECK(img.pixels[(32 * 64 + 32) * 3] == 1.0f);
    pray_image_free(c, &img);
    pray_free(c);
}

TEST_CASE("memory limits from tiny to enough: every run ends in OK or NOMEM and frees everything") {
    std::string prog = read_file("examples/csg.ray");
    REQUIRE(!prog.empty());
    int ok = 0, nomem = 0, other = 0, leaks = 0, no_message = 0;
    for (size_t limit = 256; limit <= 256 * 1024; limit += 1024) {
        Counter k;
        pray_ctx *c = pray_new_with(counting_alloc, &k);
        REQUIRE(c != NULL);
        int pixels = 0;
        pray_set_print(c, discard, NULL);
        pray_set_frame(c, keep_frame, &pixels);
        pray_option_fix(c, "width", "8");
        pray_option_fix(c, "height", "8");
        pray_set_memory_limit(c, limit);
        pray_status st = pray_run_string(c, "csg.ray", prog.data(), prog.size());
        if (st == PRAY_OK) ok++;
        else if (st == PRAY_ERR_NOMEM) {
            nomem++;
            if (std::string(pray_error(c)).find("memory") == std::string::npos) no_message++;
        } else {
            other++;
            MESSAGE("limit ", limit, ": status ", (int)st, " ", pray_error(c));
        }
        pray_free(c);
        if (k.live != 0 || k.blocks != 0) leaks++;
    }
    CHECK(other == 0);
    CHECK(leaks == 0);
    CHECK(no_message == 0);
    CHECK(nomem > 0);
    CHECK(ok > 0);
}

// =============================================================================================
// More of the specification
// =============================================================================================
TEST_CASE("complement: the camera inside -S sees the sphere's surface, in the sphere's material") {
    Frame f = frame_of("option \"width\", 3\noption \"height\", 3\nbackground {0.9}\n"
                       "rendertiff -sphere(color({0.25, 0.5, 0.75}), [0, 0, 0], 0.5)\n");
    check_exact(f, 1, 1, 0.25, 0.5, 0.75);
    check_exact(f, 0, 0, 0.9, 0.9, 0.9);  // a ray that misses the sphere meets no surface
    // A & -B: the bite shows B's material
    f = frame_of(std::string(ONE) + "background {0.9}\n"
                                    "rendertiff sphere(color({1, 0, 0}), [0, 0, 0], 1) & -sphere(color({0, 0, 1}), [0, -1, 0], 0.5)\n");
    check_exact(f, 0, 0, 0, 0, 1);
}

TEST_CASE("antialias: A x A samples per pixel, at the centres of the sub-pixels, averaged") {
    // 1x1 image, antialias 2: the four samples pass through (+-0.5, 0, -+0.5); one small sphere
    // sits on the top-left sample's ray, one on the bottom-right's
    Frame f = frame_of(std::string(ONE) + "option \"antialias\", 2\nbackground {0}\n"
                                          "rendertiff sphere(color({1, 0, 0}), [-0.5, 0, 0.5], 0.1) | sphere(color({0, 0.5, 0}), [0.5, 0, -0.5], 0.1)\n");
    check_exact(f, 0, 0, 0.25, 0.125, 0);
    // antialias over a uniform colour changes nothing
    f = frame_of(std::string(ONE) + "option \"antialias\", 3\nrendertiff sphere(color({0.25, 0.5, 0.75}), [0, 0, 0], 3)\n");
    check_exact(f, 0, 0, 0.25, 0.5, 0.75);
}

TEST_CASE("accelerated renders give the images of the brute-force reference") {
    const char *files[] = {"examples/csg.ray", "examples/holes.ray", "examples/glass.ray", "examples/parallel.ray"};
    const char *const modes[][2] = {{"grid=0", "bounds=1"}, {"freeze=0", "merge=0"}, {"bounds=0", "grid=8"},
                                    {"grid=32", "freeze=1"}, {"merge=1", "bounds=1"}};
    for (const char *file : files) {
        CAPTURE(file);
        std::string prog = read_file(file);
        REQUIRE(!prog.empty());
        Result ref = testkit::run(prog, {"width=48", "height=36", "brute=1"});
        REQUIRE(ref.status == PRAY_OK);
        REQUIRE(ref.frames.size() == 1);
        for (const auto &m : modes) {
            CAPTURE(m[0]);
            CAPTURE(m[1]);
            Result r = testkit::run(prog, {"width=48", "height=36", m[0], m[1]});
            REQUIRE(r.status == PRAY_OK);
            REQUIRE(r.frames.size() == 1);
            int differ = 0;
            for (size_t i = 0; i < r.frames[0].pixels.size(); i++)
                if (std::fabs(r.frames[0].pixels[i] - ref.frames[0].pixels[i]) > 1e-5f) differ++;
            CHECK(differ == 0);
        }
    }
}
