// Tests of version 2 of the PRAY language, its statements and functions: the lookat camera,
// include, floor ceil round min max, the new reserved words, and the warning when the eye is
// inside the rendered solid. Written from the specification (section 11 of the language notes).
// They write their include files into a temporary directory (POSIX mkdtemp).
#include <doctest/doctest.h>

#include "testkit.hpp"
#include "tempfiles.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include <sys/stat.h>
#include <unistd.h>

namespace {

bool has(const std::string &s, const std::string &part) { return s.find(part) != std::string::npos; }

// A run with the warnings captured too.
struct Run {
    testkit::Result r;
    std::string warned;
};
Run run_warned(const std::string &program, const char *name = "test.ray", int w = 32, int h = 32,
               bool untrusted = false) {
    Run out;
    pray_ctx *c = pray_new();
    if (untrusted) pray_set_untrusted(c);
    pray_option(c, "width", w);
    pray_option(c, "height", h);
    pray_set_print(c, testkit::print_sink, &out.r.printed);
    pray_set_frame(c, testkit::frame_sink, &out.r.frames);
    pray_set_warning(c, testkit::print_sink, &out.warned);
    out.r.status = pray_run_string(c, name, program.data(), program.size());
    if (out.r.status != PRAY_OK) out.r.error = pray_error(c);
    pray_free(c);
    return out;
}

// A directory of its own for the files a test writes, removed with what it holds.
struct Dir : testkit::TempDir {
    Dir() { REQUIRE(!path.empty()); }
    void mkdir(const std::string &name) { REQUIRE(std::filesystem::create_directory(*this / name)); }
    void write(const std::string &name, const std::string &text) { testkit::spit(*this / name, text); }
};

// A program file run as pray_run_file runs it.
testkit::Result run_file(const std::string &path, bool untrusted = false) {
    testkit::Result r;
    pray_ctx *c = pray_new();
    if (untrusted) pray_set_untrusted(c);
    pray_set_print(c, testkit::print_sink, &r.printed);
    pray_set_frame(c, testkit::frame_sink, &r.frames);
    r.status = pray_run_file(c, path.c_str());
    if (r.status != PRAY_OK) r.error = pray_error(c);
    pray_free(c);
    return r;
}

// Where the pixels of one colour are: their count and the centre of their box.
struct Blob {
    int n = 0, x0 = 1 << 30, x1 = -1, y0 = 1 << 30, y1 = -1;
    double cx() const { return (x0 + x1) / 2.0; }
    double cy() const { return (y0 + y1) / 2.0; }
    int w() const { return x1 - x0 + 1; }
    int h() const { return y1 - y0 + 1; }
};
Blob blob(const testkit::Frame &f, int ch) {
    Blob b;
    for (int y = 0; y < f.height; y++)
        for (int x = 0; x < f.width; x++)
            if (f.at(x, y, ch) > 0.5f) {
                b.n++;
                if (x < b.x0) b.x0 = x;
                if (x > b.x1) b.x1 = x;
                if (y < b.y0) b.y0 = y;
                if (y > b.y1) b.y1 = y;
            }
    return b;
}

const char *const TWO_BALLS = "R = color({1, 0, 0})\nB = color({0, 0, 1})\n"
                              "Balls = sphere(R, [2, 0, 0], 1) + sphere(B, [0, 0, 2], 1)\n";

} // namespace

// =============================================================================================
// Functions of numbers
// =============================================================================================

TEST_CASE("floor, ceil, round (halves away from zero), min, max") {
    CHECK(testkit::printed("print floor(2.5), floor(-2.5), floor(3), ceil(2.5), ceil(-2.5), ceil(-0.5)\n") ==
          "2 -3 3 3 -2 0\n");
    CHECK(testkit::printed("print round(2.5), round(-2.5), round(0.5), round(-0.5), round(1.4999), round(-1.5001)\n") ==
          "3 -3 1 -1 1 -2\n");
    // the largest number below 0.5 rounds down (floor(x + 0.5) would give 1); big numbers stay
    CHECK(testkit::printed("print round(0.49999999999999994), round(-0.49999999999999994)\n") == "0 0\n");
    CHECK(testkit::printed("print round(4503599627370497) - 4503599627370496, round(1e300) = 1e300\n") == "1 1\n");
    CHECK(testkit::printed("print min(3, -1), max(3, -1), min(2, 2), max(-0.5, -0.25), min(1e308, -1e308)\n") ==
          "-1 3 2 -0.25 -1e+308\n");
    CHECK(testkit::printed("x = 7\nprint max(min(x, 5), 0), floor(x / 2) + ceil(x / 2)\n") == "5 7\n");
}

TEST_CASE("floor ceil round min max: wrong arguments") {
    CHECK(testkit::error_of("print min(1)\n") == "test.ray:1:7: error: min takes 2 arguments, not 1");
    CHECK(testkit::error_of("print max(1, 2, 3)\n") == "test.ray:1:7: error: max takes 2 arguments, not 3");
    CHECK(testkit::error_of("print floor()\n") == "test.ray:1:7: error: floor takes 1 argument, not 0");
    CHECK(testkit::error_of("print round(1, 2)\n") == "test.ray:1:7: error: round takes 1 argument, not 2");
    CHECK(testkit::error_of("print ceil(\"1\")\n") ==
          "test.ray:1:12: error: ceil: argument 1 must be a number, not a string");
    CHECK(testkit::error_of("print min(1, <1, 2, 3>)\n") ==
          "test.ray:1:14: error: min: argument 2 must be a number, not a vector");
    CHECK(testkit::error_of("print max(nothing, 1)\n") ==
          "test.ray:1:11: error: max: argument 1 must be a number, not an object");
}

TEST_CASE("the words of version 2 are reserved; a program of version 1 using them is told why") {
    const char *words[] = {"floor", "ceil", "round", "min", "max"};
    for (const char *w : words) {
        std::string word = w;
        CHECK(testkit::error_of(word + " = 1\n") ==
              "test.ray:1:1: error: '" + word +
                  "' is a reserved word and cannot be assigned to (a word of version 2 of the language: rename the "
                  "variable)");
        CHECK(testkit::error_of("x = " + word + " + 1\n") ==
              "test.ray:1:5: error: '" + word +
                  "' is a function: write it with its arguments in parentheses (a word of version 2 of the language: "
                  "rename the variable)");
    }
    CHECK(testkit::error_of("lookat = 1\n") ==
          "test.ray:1:1: error: 'lookat' is a reserved word and cannot be assigned to (a word of version 2 of the "
          "language: rename the variable)");
    CHECK(testkit::error_of("print include\n") ==
          "test.ray:1:7: error: 'include' is a reserved word and cannot be used here (a word of version 2 of the "
          "language: rename the variable)");
    // other reserved words keep their message
    CHECK(testkit::error_of("sin = 1\n") == "test.ray:1:1: error: 'sin' is a reserved word and cannot be assigned to");
    // names that only contain them are free
    CHECK(testkit::printed("floor1 = 1\nMax = 2\nminimum = 3\nprint floor1 + Max + minimum\n") == "6\n");
}

// =============================================================================================
// lookat
// =============================================================================================

TEST_CASE("lookat: right is (P - E) % U, down is (P - E) % right: nothing is mirrored") {
    // looking along +Y with Z up: the ball at +X is on the right, the one at +Z at the top
    Run a = run_warned(std::string(TWO_BALLS) + "lookat [0, -10, 0], [0, 0, 0], <0, 0, 1>, 40\nrendertiff Balls, none\n");
    REQUIRE_MESSAGE(a.r.status == PRAY_OK, a.r.error);
    REQUIRE(a.r.frames.size() == 1);
    Blob red = blob(a.r.frames[0], 0), blue = blob(a.r.frames[0], 2);
    REQUIRE(red.n > 0);
    REQUIRE(blue.n > 0);
    CHECK(red.cx() > 20);  // right of the centre (15.5)
    CHECK(red.cy() == doctest::Approx(15.5).epsilon(0.05));
    CHECK(blue.cy() < 11);  // above it
    CHECK(blue.cx() == doctest::Approx(15.5).epsilon(0.05));
    // looking down from above with +Y up: +X right, +Y at the top
    Run b = run_warned("R = color({1, 0, 0})\nB = color({0, 0, 1})\nlookat [0, 0, 10], [0, 0, 0], <0, 1, 0>, 40\n"
                       "rendertiff sphere(R, [2, 0, 0], 1) + sphere(B, [0, 2, 0], 1), none\n");
    REQUIRE_MESSAGE(b.r.status == PRAY_OK, b.r.error);
    red = blob(b.r.frames[0], 0);
    blue = blob(b.r.frames[0], 2);
    CHECK(red.cx() > 20);
    CHECK(blue.cy() < 11);
    // the up vector need not be perpendicular, nor of unit length: only its side counts
    Run c = run_warned(std::string(TWO_BALLS) + "lookat [0, -10, 0], [0, 0, 0], <0, 3, 7>, 40\nrendertiff Balls, none\n");
    REQUIRE(c.r.status == PRAY_OK);
    CHECK(c.r.frames[0].pixels == a.r.frames[0].pixels);
    // U upside down: the picture turns by 180 degrees
    Run d = run_warned(std::string(TWO_BALLS) + "lookat [0, -10, 0], [0, 0, 0], <0, 0, -1>, 40\nrendertiff Balls, none\n");
    REQUIRE(d.r.status == PRAY_OK);
    red = blob(d.r.frames[0], 0);
    blue = blob(d.r.frames[0], 2);
    CHECK(red.cx() < 11);
    CHECK(blue.cy() > 20);
}

TEST_CASE("lookat: the angle is the horizontal field of view; it can stand in for the default camera") {
    // the default camera sees [-1, 1] at distance 4: an angle of 2 atan(1/4)
    const std::string scene = "S = sphere(color({1}), [0.3, 0, 0.2], 0.7) + sphere(color({0.5}), [-0.6, 1, -0.5], 0.4)\n"
                              "rendertiff S, none\n";
    Run def = run_warned(scene);
    Run la = run_warned("lookat [0, -4, 0], [0, 0, 0], <0, 0, 1>, 2 * arctan(0.25) * 180 / pi\n" + scene);
    REQUIRE(def.r.status == PRAY_OK);
    REQUIRE_MESSAGE(la.r.status == PRAY_OK, la.r.error);
    REQUIRE(la.r.frames.size() == 1);
    int differ = 0;
    for (size_t i = 0; i < def.r.frames[0].pixels.size(); i++)
        if (std::fabs(def.r.frames[0].pixels[i] - la.r.frames[0].pixels[i]) > 1e-6) differ++;
    CHECK(differ == 0);
    // the rays, through the API (in the renderer's precision, float or double): X = <1, 0, 0> and
    // Y = <0, 0, -1> scaled by height / width
    pray_ctx *c = pray_new();
    pray_option(c, "width", 200);
    pray_option(c, "height", 100);
    REQUIRE(pray_lookat(c, {0, -4, 0}, {0, 0, 0}, {0, 0, 1}, 2 * std::atan(0.25) * 180 / 3.14159265358979323846) == PRAY_OK);
    pray_vec o, d;
    REQUIRE(pray_camera_ray(c, 0, 0, &o, &d) == PRAY_OK);  // the top left corner: P - X - Y
    double len = std::sqrt(1 + 16 + 0.25);
    CHECK(o.x == 0);
    CHECK(o.y == -4);
    CHECK(d.x == doctest::Approx(-1 / len).epsilon(1e-6));
    CHECK(d.y == doctest::Approx(4 / len).epsilon(1e-6));
    CHECK(d.z == doctest::Approx(0.5 / len).epsilon(1e-6));
    // the size in force when the ray is made counts, not the one of the lookat call
    pray_option(c, "height", 400);
    REQUIRE(pray_camera_ray(c, 0, 0, &o, &d) == PRAY_OK);
    len = std::sqrt(1 + 16 + 4);
    CHECK(d.z == doctest::Approx(2 / len).epsilon(1e-6));
    // a perspective or parallel camera after it is itself again
    REQUIRE(pray_perspective(c, {1, 0, 0}, {0, 0, -1}, {0, -4, 0}, {0, 0, 0}) == PRAY_OK);
    REQUIRE(pray_camera_ray(c, 0, 0, &o, &d) == PRAY_OK);
    len = std::sqrt(1 + 16 + 1);
    CHECK(d.z == doctest::Approx(1 / len).epsilon(1e-6));
    pray_free(c);
}

TEST_CASE("lookat: square pixels at every image size, so -s never stretches, and no aspect warning") {
    const std::string prog = "lookat [0, -10, 0], [0, 0, 0], <0, 0, 1>, 30\nrendertiff sphere(color({1}), [0, 0, 0], 0.6), none\n";
    const int sizes[][2] = {{64, 64}, {96, 48}, {48, 96}, {100, 30}};
    double diameter = 0;
    for (const auto &s : sizes) {
        Run r = run_warned(prog, "test.ray", s[0], s[1]);
        REQUIRE_MESSAGE(r.r.status == PRAY_OK, r.r.error);
        CHECK(r.warned == "");
        Blob b = blob(r.r.frames[0], 0);
        INFO(s[0] << " x " << s[1]);
        CHECK(std::abs(b.w() - b.h()) <= 1);  // round, not an ellipse
        CHECK(b.cx() == doctest::Approx((s[0] - 1) / 2.0));
        CHECK(b.cy() == doctest::Approx((s[1] - 1) / 2.0));
        // the field of view is horizontal: the ball's share of the width stays the same
        double share = (double)b.w() / s[0];
        if (diameter == 0) diameter = share;
        CHECK(share == doctest::Approx(diameter).epsilon(0.05));
    }
    // -s W x H fixes the size over the program's own (pray_option_fix, as the command line does)
    const std::string sized = "option \"width\", 64\noption \"height\", 64\n" + prog;
    for (const char *wh : {"64x64", "120x40", "40x120"}) {
        int w = 0, h = 0;
        std::sscanf(wh, "%dx%d", &w, &h);
        testkit::Result r = testkit::run(sized, {"width=" + std::to_string(w), "height=" + std::to_string(h)});
        REQUIRE_MESSAGE(r.status == PRAY_OK, r.error);
        REQUIRE(r.frames.size() == 1);
        CHECK(r.frames[0].width == w);
        Blob b = blob(r.frames[0], 0);
        INFO(wh);
        CHECK(std::abs(b.w() - b.h()) <= 1);
        CHECK((double)b.w() / w == doctest::Approx(diameter).epsilon(0.05));
    }
    // the size may change between frames: each frame is square in its own size
    Run two = run_warned("lookat [0, -10, 0], [0, 0, 0], <0, 0, 1>, 30\nS = sphere(color({1}), [0, 0, 0], 0.6)\n"
                         "rendertiff S, none\noption \"width\", 80\nrendertiff S, none\n");
    REQUIRE(two.r.status == PRAY_OK);
    REQUIRE(two.r.frames.size() == 2);
    CHECK(two.r.frames[1].width == 80);
    Blob b = blob(two.r.frames[1], 0);
    CHECK(std::abs(b.w() - b.h()) <= 1);
    CHECK(two.warned == "");
}

TEST_CASE("lookat: bad arguments") {
    CHECK(testkit::error_of("lookat [0,-4,0], [0,0,0], <0,0,1>\n") == "test.ray:1:1: error: 'lookat' takes 4 arguments, not 3");
    CHECK(testkit::error_of("lookat\n") == "test.ray:1:7: error: 'lookat' needs 4 arguments");
    CHECK(testkit::error_of("lookat <0,-4,0>, [0,0,0], <0,0,1>, 40\n") ==
          "test.ray:1:8: error: lookat: E must be a point, not a vector");
    CHECK(testkit::error_of("lookat [0,-4,0], [0,0,0], [0,0,1], 40\n") ==
          "test.ray:1:27: error: lookat: U must be a vector, not a point");
    CHECK(testkit::error_of("lookat [0,-4,0], [0,0,0], <0,0,1>, \"40\"\n") ==
          "test.ray:1:36: error: lookat: a must be a number, not a string");
    CHECK(testkit::error_of("print 1\nlookat [0,-4,0], [0,0,0], <0,3,0>, 40\n") ==
          "test.ray:2:1: error: lookat: the up direction U must not be parallel to P - E");
    CHECK(testkit::error_of("lookat [0,-4,0], [0,0,0], <0,-1e-300,0>, 40\n") ==
          "test.ray:1:1: error: lookat: the up direction U must not be parallel to P - E");
    CHECK(testkit::error_of("lookat [0,-4,0], [0,0,0], <0,0,0>, 40\n") ==
          "test.ray:1:1: error: lookat: the up direction U must not be a zero vector");
    CHECK(testkit::error_of("lookat [1,2,3], [1,2,3], <0,0,1>, 40\n") ==
          "test.ray:1:1: error: lookat: the eye and the point looked at must differ");
    for (const char *a : {"0", "180", "-10", "200"})
        CHECK(testkit::error_of(std::string("lookat [0,-4,0], [0,0,0], <0,0,1>, ") + a + "\n") ==
              std::string("test.ray:1:1: error: lookat: the angle ") + a + " must lie between 0 and 180 degrees");
    // tiny and huge but finite cameras are fine
    CHECK(testkit::run("lookat [0,-4e-200,0], [0,0,0], <0,0,1e-300>, 179.9\nprint 1\n").printed == "1\n");
    CHECK(testkit::run("lookat [0,-4e200,0], [1e200,0,0], <0,0,1e300>, 1e-9\nprint 1\n").printed == "1\n");
    // what programs cannot make, the API refuses
    pray_ctx *c = pray_new();
    double inf = HUGE_VAL, nan = std::nan("");
    CHECK(pray_lookat(c, {0, -4, 0}, {0, 0, 0}, {0, 0, 1}, nan) == PRAY_ERR_ARG);
    CHECK(std::string(pray_error(c)) == "error: lookat: coordinates are not finite");
    CHECK(pray_lookat(c, {0, -4, inf}, {0, 0, 0}, {0, 0, 1}, 40) == PRAY_ERR_ARG);
    CHECK(pray_lookat(c, {0, -1e308, 0}, {0, 1e308, 0}, {0, 0, 1}, 40) == PRAY_ERR_ARG);  // P - E overflows
    CHECK(std::string(pray_error(c)) == "error: lookat: coordinates are not finite");
    CHECK(pray_lookat(c, {0, -4, 0}, {0, 0, 0}, {0, nan, 1}, 40) == PRAY_ERR_ARG);
    CHECK(pray_lookat(nullptr, {0, -4, 0}, {0, 0, 0}, {0, 0, 1}, 40) == PRAY_ERR_ARG);
    // the host's lookat is where every run starts
    REQUIRE(pray_lookat(c, {0, -10, 0}, {0, 0, 0}, {0, 0, 1}, 40) == PRAY_OK);
    std::vector<testkit::Frame> frames;
    pray_set_frame(c, testkit::frame_sink, &frames);
    pray_option(c, "width", 32);
    pray_option(c, "height", 32);
    std::string prog = std::string(TWO_BALLS) + "rendertiff Balls, none\n";
    REQUIRE(pray_run_string(c, "host.ray", prog.data(), prog.size()) == PRAY_OK);
    REQUIRE(frames.size() == 1);
    CHECK(blob(frames[0], 0).cx() > 20);
    pray_free(c);
}

// =============================================================================================
// include
// =============================================================================================

TEST_CASE("include: the statements of a file, run in place on the same variables") {
    Dir d;
    d.mkdir("lib");
    d.write("main.ray", "M = 5\ninclude \"lib/a.ray\"\nprint \"main\", A, B\n"
                        "i = 0\nwhile i < 2\n  include \"lib/b.ray\"\n  i = i + 1\nendwhile\nif 0\n  include \"missing.ray\"\nendif\n"
                        "print \"end\", B\n");
    d.write("lib/a.ray", "print \"a\", M\nA = M * 2\ninclude \"b.ray\"  // beside a.ray\n");
    d.write("lib/b.ray", "\xEF\xBB\xBF// a byte order mark, CRLF lines\r\nB = B + 1\r\nprint \"b\", B\r\n");
    d.write("lib/B0.ray", "");
    // B is undefined at first: b.ray reads it
    testkit::Result r = run_file(d / "main.ray");
    CHECK(r.status == PRAY_ERR_RUNTIME);
    CHECK(r.error == d / "lib/b.ray" + ":2:5: error: undefined variable 'B'; did you mean 'M'? (included from " +
                         d / "lib/a.ray" + ":3, included from " + d / "main.ray" + ":2)");
    CHECK(r.printed == "a 5\n");
    d.write("main2.ray", "B = 0\ninclude \"main.ray\"\n");
    // (main.ray includes nothing of main2.ray: no loop)
    r = run_file(d / "main2.ray");
    REQUIRE_MESSAGE(r.status == PRAY_OK, r.error);
    CHECK(r.printed == "a 5\nb 1\nmain 10 1\nb 2\nb 3\nend 3\n");
    // an empty file is fine
    d.write("main3.ray", "include \"lib/B0.ray\"\nprint 1\n");
    r = run_file(d / "main3.ray");
    CHECK(r.printed == "1\n");
}

TEST_CASE("include: values live on for included files; frames are named after the program") {
    Dir d;
    // M and S are named by no statement of the program after the include: the included file
    // uses them, so they must not be released before
    d.write("scene.ray", "M = color({1})\nS = sphere(M, [0, 0, 0], 1)\nprint 0\ninclude \"render.ray\"\nprint 2\n");
    d.write("render.ray", "option \"width\", 8\noption \"height\", 8\nrendertiff S, none\nT = S\nprint 1\n");
    testkit::Result r = run_file(d / "scene.ray");
    REQUIRE_MESSAGE(r.status == PRAY_OK, r.error);
    CHECK(r.printed == "0\n1\n2\n");
    REQUIRE(r.frames.size() == 1);
    CHECK(r.frames[0].name == d / "scene.tif");
    CHECK(r.frames[0].at(4, 4, 0) == 1.0f);
    // quit in an included file ends the program
    d.write("q.ray", "print 1\ninclude \"quit.ray\"\nprint 3\n");
    d.write("quit.ray", "print 2\nquit\nprint 9\n");
    r = run_file(d / "q.ray");
    CHECK(r.status == PRAY_OK);
    CHECK(r.printed == "1\n2\n");
    // a syntax error anywhere in an included file: none of its statements runs
    d.write("s.ray", "print 1\ninclude \"bad.ray\"\nprint 3\n");
    d.write("bad.ray", "print 2\nx = (1\n");
    r = run_file(d / "s.ray");
    CHECK(r.printed == "1\n");
    CHECK(r.error == d / "bad.ray" + ":2:7: error: expected ')', found 'end of line' (included from " + d / "s.ray" + ":2)");
}

TEST_CASE("include: pray_run_string looks beside the program's name") {
    Dir d;
    d.write("part.ray", "print \"part\"\n");
    std::string prog = "include \"part.ray\"\n";
    pray_ctx *c = pray_new();
    std::string out;
    pray_set_print(c, testkit::print_sink, &out);
    std::string name = d / "virtual.ray";
    CHECK(pray_run_string(c, name.c_str(), prog.data(), prog.size()) == PRAY_OK);
    CHECK(out == "part\n");
    CHECK(pray_run_string(c, "elsewhere.ray", prog.data(), prog.size()) == PRAY_ERR_RUNTIME);
    CHECK(std::string(pray_error(c)) == "elsewhere.ray:1:9: error: cannot open 'part.ray': No such file or directory");
    pray_free(c);
}

TEST_CASE("include: loops, missing files, nesting deeper than maxnest, bad statements") {
    Dir d;
    d.write("self.ray", "print 1\ninclude \"self.ray\"\n");
    testkit::Result r = run_file(d / "self.ray");
    CHECK(r.status == PRAY_ERR_RUNTIME);
    CHECK(r.error == d / "self.ray" + ":2:9: error: '" + d / "self.ray" + "' includes itself");
    CHECK(r.printed == "1\n");
    d.mkdir("sub");
    d.write("a.ray", "include \"sub/b.ray\"\n");
    d.write("sub/b.ray", "include \"c.ray\"\n");
    d.write("sub/c.ray", "x = 1\ninclude \"../a.ray\"\n");
    r = run_file(d / "a.ray");
    CHECK(r.error == d / "sub/c.ray" + ":2:9: error: '" + d / "sub/../a.ray" + "' includes itself through '" +
                         d / "sub/b.ray" + "' (included from " + d / "sub/b.ray" + ":1, included from " + d / "a.ray" +
                         ":1)");
    // missing, a directory
    d.write("m.ray", "\n  include \"nope.ray\"\n");
    r = run_file(d / "m.ray");
    CHECK(r.status == PRAY_ERR_RUNTIME);
    CHECK(r.error == d / "m.ray" + ":2:11: error: cannot open '" + d / "nope.ray" + "': No such file or directory");
    d.write("dir.ray", "include \"sub\"\n");
    r = run_file(d / "dir.ray");
    CHECK(r.error == d / "dir.ray" + ":1:9: error: cannot read '" + d / "sub" + "': not a regular file");
    // a chain of includes, each file including the next: maxnest deep is fine, one more is not
    for (int i = 0; i < 5; i++)
        d.write("n" + std::to_string(i) + ".ray", i < 4 ? "include \"n" + std::to_string(i + 1) + ".ray\"\n" : "print 4\n");
    pray_ctx *c = pray_new();
    std::string out;
    pray_set_print(c, testkit::print_sink, &out);
    pray_option(c, "maxnest", 4);
    CHECK(pray_run_file(c, (d / "n0.ray").c_str()) == PRAY_OK);
    CHECK(out == "4\n");
    pray_option(c, "maxnest", 3);
    CHECK(pray_run_file(c, (d / "n0.ray").c_str()) == PRAY_ERR_LIMIT);
    CHECK(std::string(pray_error(c)) == d / "n3.ray" + ":1:1: error: includes nested deeper than 3 levels (option maxnest) "
                                                      "(included from " + d / "n2.ray" + ":1, included from " +
                                            d / "n1.ray" + ":1, included from " + d / "n0.ray" + ":1)");
    pray_free(c);
    // the statement
    CHECK(testkit::error_of("include x.ray\n") == "test.ray:1:9: error: 'include' takes a file name in double quotes: include \"F\"");
    CHECK(testkit::error_of("include\n") == "test.ray:1:1: error: 'include' takes a file name in double quotes: include \"F\"");
    CHECK(testkit::error_of("include \"a\" + \"b\"\n") ==
          "test.ray:1:13: error: 'include' stands alone on its line: expected end of line after the file name, found '+'");
    CHECK(testkit::error_of("include \"a\", \"b\"\n") ==
          "test.ray:1:12: error: 'include' stands alone on its line: expected end of line after the file name, found ','");
    CHECK(testkit::error_of("include \\\n \"a.ray\"\n") ==
          "test.ray:2:2: error: 'include' stands alone on its line: the file name must be on the line of 'include'");
    CHECK(testkit::error_of("print 1\ninclude \"\"\n") == "test.ray:2:9: error: 'include' takes a file name, not an empty string");
    CHECK(testkit::error_of("x = 1 include \"a.ray\"\n") == "test.ray:1:7: error: expected end of line, found 'include'");
    CHECK(testkit::error_of("include = 2\n").find("'include' is a reserved word") != std::string::npos);
}

TEST_CASE("include: an untrusted program's includes are confined like its texture files") {
    Dir d;
    d.mkdir("sub");
    d.write("ok.ray", "include \"sub/a.ray\"\n");
    d.write("sub/a.ray", "include \"b.ray\"\n");
    d.write("sub/b.ray", "print \"b\"\n");
    testkit::Result r = run_file(d / "ok.ray", true);
    REQUIRE_MESSAGE(r.status == PRAY_OK, r.error);
    CHECK(r.printed == "b\n");
    d.write("sub/up.ray", "include \"../ok.ray\"\n");
    d.write("up.ray", "include \"sub/up.ray\"\n");
    r = run_file(d / "up.ray", true);
    CHECK(r.status == PRAY_ERR_RUNTIME);
    CHECK(r.error == d / "sub/up.ray" + ":1:9: error: untrusted program: '../ok.ray' is a name with '..'; files are read "
                                        "from the program's directory only (included from " + d / "up.ray" + ":1)");
    d.write("abs.ray", "include \"" + d / "ok.ray" + "\"\n");
    r = run_file(d / "abs.ray", true);
    CHECK(has(r.error, "is not a relative name; files are read from the program's directory only"));
    // trusted, the same files are read
    r = run_file(d / "up.ray");
    CHECK(r.status == PRAY_OK);
    CHECK(r.printed == "b\n");
    // links are not followed
    REQUIRE(symlink((d / "sub/b.ray").c_str(), (d / "link.ray").c_str()) == 0);
    d.write("viaLink.ray", "include \"link.ray\"\n");
    r = run_file(d / "viaLink.ray", true);
    CHECK(r.error == d / "viaLink.ray" + ":1:9: error: untrusted program: 'link.ray' is a symbolic link; files are read from "
                                         "the program's directory only, and links are not followed");
    r = run_file(d / "viaLink.ray");
    CHECK(r.printed == "b\n");
}

// =============================================================================================
// The eye inside the rendered solid
// =============================================================================================

TEST_CASE("a warning once a frame when the eye is inside the rendered solid, never an error") {
    const std::string prog = "M = color({1})\n"
                             "Wall = plane(M, [0, 5, 0], <0, -1, 0>)\n"  // y >= 5: behind the ball, facing the eye
                             "rendertiff Wall, none\n"
                             "rendertiff -Wall, none\n"  // the wall turned the wrong way: all space on the eye's side
                             "rendertiff sphere(M, [0, -4, 0], 1) - sphere(M, [0, -4, 0], 0.5), none\n"  // in its hole
                             "rendertiff sphere(M, [0, -4, 0], 1), none\n"
                             "rendertiff one(M), none\n"
                             "rendertiff nothing, none\n"
                             "rendertiff (sphere(M, [0, -4, 0], 1) & plane(M, [0, -3.5, 0], <0, 1, 0>)) . [0, 0, 0], none\n";
    Run r = run_warned(prog, "eye.ray", 8, 8);
    REQUIRE_MESSAGE(r.r.status == PRAY_OK, r.r.error);
    CHECK(r.r.frames.size() == 7);
    CHECK(r.warned == "eye.ray:4:1: warning: the eye is inside the rendered solid\n"
                      "eye.ray:6:1: warning: the eye is inside the rendered solid\n"
                      "eye.ray:7:1: warning: the eye is inside the rendered solid\n"
                      "eye.ray:9:1: warning: the eye is inside the rendered solid\n");
    // every frame that has its eye inside says so; a parallel camera's eye counts the same
    Run two = run_warned("S = sphere(color({1}), [0, 0, 0], 10)\nrendertiff S\nrendertiff S\n"
                         "parallel <1,0,0>, <0,0,-1>, [0,-4,0], [0,0,0]\nrendertiff S\n",
                         "two.ray", 4, 4);
    CHECK(two.warned == "two.ray:2:1: warning: the eye is inside the rendered solid\n"
                        "two.ray:3:1: warning: the eye is inside the rendered solid\n"
                        "two.ray:5:1: warning: the eye is inside the rendered solid\n");
    // with the grid, brute force, and the eye's buffer off: the same
    for (const char *o : {"brute", "eyebuffer", "grid"}) {
        std::string p = std::string("option \"") + o + "\", " + (std::string(o) == "brute" ? "1" : "0") + "\n" + prog;
        Run x = run_warned(p, "eye.ray", 8, 8);
        CHECK(x.r.status == PRAY_OK);
        CHECK(std::count(x.warned.begin(), x.warned.end(), '\n') == 4);
    }
}
