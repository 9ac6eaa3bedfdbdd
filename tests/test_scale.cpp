// Programs and scenes that are large: what they cost in memory (pray_stats' peaks by phase), that
// reading and running them takes time in proportion to their length, that a program is read a
// line at a time without losing the places of its errors, and that preparing a scene is not
// quadratic in its primitives or nodes.
#include <doctest/doctest.h>

#include "testkit.hpp"

#include <chrono>
#include <string>

namespace {

// n spheres written out one statement each, rendered at 16 x 16.
std::string spheres_program(int n) {
    std::string p = "M = color({1, 0.5, 0})\nAll = nothing\n";
    unsigned s = 12345;
    char line[160];
    for (int i = 0; i < n; i++) {
        double v[4];
        for (double &x : v) {
            s = s * 1103515245u + 12345u;
            x = (double)(s >> 8 & 0xFFFF) / 65536.0;
        }
        snprintf(line, sizeof line, "All = All | sphere(M, [%.4f, %.4f, %.4f], %.4f)\n", v[0] * 100 - 50,
                 v[1] * 100 - 50, v[2] * 100 - 50, 0.2 + v[3] * 0.5);
        p += line;
    }
    return p + "perspective <1,0,0>, <0,0,-1>, [0,-160,0], [0,0,0]\nrendertiff All, dirlight({1}, <1,-2,3>)\n";
}

struct Run {
    pray_status status;
    std::string error;
    pray_stats stats;
    double seconds;
};

Run run_stats(const std::string &program, int size = 16) {
    Run r;
    pray_ctx *c = pray_new();
    std::vector<testkit::Frame> frames;
    std::string out;
    pray_set_frame(c, testkit::frame_sink, &frames);
    pray_set_print(c, testkit::print_sink, &out);
    pray_option(c, "width", size);
    pray_option(c, "height", size);
    pray_option(c, "threads", 1);
    auto t0 = std::chrono::steady_clock::now();
    r.status = pray_run_string(c, "big.ray", program.data(), program.size());
    r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    r.error = r.status ? pray_error(c) : "";
    pray_stats_get(c, &r.stats);
    pray_free(c);
    return r;
}

double max_phase(const pray_stats &s) {
    double m = s.memory_parse;
    for (double v : {s.memory_run, s.memory_prepare, s.memory_accel, s.memory_render})
        if (v > m) m = v;
    return m;
}

} // namespace

TEST_CASE("memory: the peaks by phase of a scene of spheres are consistent and grow with the primitives") {
    Run small = run_stats(spheres_program(2000)), large = run_stats(spheres_program(8000));
    for (const Run *r : {&small, &large}) {
        REQUIRE_MESSAGE(r->status == PRAY_OK, r->error);
        const pray_stats &s = r->stats;
        CHECK(s.memory_parse > 0);
        CHECK(s.memory_run > 0);
        CHECK(s.memory_render > 0);
        // every phase holds what the one before kept: the values while the scene is prepared, the
        // prepared scene while its acceleration structure is built and while it is rendered
        CHECK(s.memory_prepare > s.memory_run);
        CHECK(s.memory_accel > 0);
        CHECK(s.memory_peak == max_phase(s));
        // the program is read a line at a time: reading holds far less than the values it makes
        CHECK(s.memory_parse < s.memory_run / 4);
        // bytes per primitive, everything included (values, prepared scene, grid)
        CHECK(s.memory_peak / s.primitives < 1500);
    }
    // four times the spheres: about four times the memory, not sixteen
    CHECK(large.stats.memory_peak < 5 * small.stats.memory_peak);
    CHECK(large.stats.memory_peak > 2 * small.stats.memory_peak);
}

TEST_CASE("memory: peaks are reset by each run; renders outside runs count their phases too") {
    pray_ctx *c = pray_new();
    std::vector<testkit::Frame> frames;
    pray_set_frame(c, testkit::frame_sink, &frames);
    pray_option(c, "width", 8);
    pray_option(c, "height", 8);
    std::string big = spheres_program(3000), tiny = "rendertiff sphere(color({1}), [0,0,0], 1), none\n";
    pray_stats a, b;
    REQUIRE(pray_run_string(c, "a.ray", big.data(), big.size()) == PRAY_OK);
    pray_stats_get(c, &a);
    REQUIRE(pray_run_string(c, "b.ray", tiny.data(), tiny.size()) == PRAY_OK);
    pray_stats_get(c, &b);
    CHECK(b.memory_peak > 0);
    CHECK(b.memory_peak < a.memory_peak / 10);
    pray_free(c);

    c = pray_new();
    pray_option(c, "width", 8);
    pray_option(c, "height", 8);
    pray_vec o = {0, 0, 0};
    pray_rgb w = {1, 1, 1};
    pray_object *s = pray_sphere(c, pray_color(c, w), o, 1);
    pray_image img;
    REQUIRE(pray_render(c, s, NULL, &img) == PRAY_OK);
    pray_stats_get(c, &a);
    CHECK(a.memory_run > 0);
    CHECK(a.memory_prepare >= a.memory_run);
    CHECK(a.memory_render >= a.memory_run);
    CHECK(a.memory_parse == 0);
    CHECK(a.memory_peak == max_phase(a));
    pray_free(c);
}

TEST_CASE("a program of 100 000 statements is read and run in proportion to its length") {
    std::string p;
    char line[80];
    for (int i = 0; i < 100000; i++) {
        snprintf(line, sizeof line, "X%d = %d * 2 + Y\n", i % 1000, i);
        if (i == 0) p += "Y = 1\n";
        p += line;
    }
    p += "print X999\n";
    Run r = run_stats(p);
    REQUIRE_MESSAGE(r.status == PRAY_OK, r.error);
    CHECK(r.seconds < 5);  // about 0.1 s on a desktop machine
    CHECK(r.stats.time_parse < 3);
    // only one line's tokens and one statement's tree at a time
    CHECK(r.stats.memory_parse < 512 * 1024);
    CHECK(r.stats.memory_run < 512 * 1024);

    // loops and blocks: a while of 20 000 statements, run twice
    std::string q = "I = 0\nwhile I < 2\n";
    for (int i = 0; i < 20000; i++) {
        snprintf(line, sizeof line, "  if I = %d\n    Z%d = I\n  endif\n", i % 3, i % 100);
        q += line;
    }
    q += "  I = I + 1\nendwhile\nprint I, Z0\n";
    r = run_stats(q);
    REQUIRE_MESSAGE(r.status == PRAY_OK, r.error);
    CHECK(r.seconds < 5);
}

TEST_CASE("errors of a program read a line at a time keep their places") {
    std::string lines;
    for (int i = 0; i < 30000; i++) lines += "A = 1 + 2\n";
    // a syntax error far down: nothing of the program runs, not even the print of line 1
    testkit::Result r = testkit::run("print \"hello\"\n" + lines + "B = (1 + \nprint 2\n");
    CHECK(r.printed == "");
    CHECK(r.status == PRAY_ERR_SYNTAX);
    CHECK(r.error == "test.ray:30002:10: error: expected a value, found 'end of line'");
    // an error of the characters anywhere is reported before a syntax error above it
    r = testkit::run("A = (\n" + lines + "B = \"unterminated\n");
    CHECK(r.error == "test.ray:30002:5: error: unterminated string");
    r = testkit::run("A = (\n" + lines + "B = 1 $ 2\n");
    CHECK(r.error == "test.ray:30002:7: error: unexpected character '$'");
    // continued lines, comments and blank lines count as the lexer sees them
    r = testkit::run(lines + "C = [1, 2,\\\n");
    CHECK(r.error == "test.ray:30001:11: error: line continuation at the end of the file");
    r = testkit::run("A = 1 + \\   // more\n  2 + \\\n  3\n// note\n\n" + lines + "print A\nB = A +\n");
    CHECK(r.error == "test.ray:30007:8: error: expected a value, found 'end of line'");
    CHECK(r.printed == "");
    // a runtime error after a long stretch of statements: what ran before it did run
    r = testkit::run("print 1\n" + lines + "print Undefined\nprint 3\n");
    CHECK(r.printed == "1\n");
    CHECK(r.error == "test.ray:30002:7: error: undefined variable 'Undefined'");
    // a block left open, a stray end of block
    r = testkit::run("while 1\n" + lines);
    CHECK(r.error == "test.ray:1:1: error: 'while' without 'endwhile'");
    r = testkit::run(lines + "endif\n");
    CHECK(r.error == "test.ray:30001:1: error: 'endif' without a matching 'if'");
    r = testkit::run("if 1\n" + lines + "endwhile\n");
    CHECK(r.error == "test.ray:30002:1: error: 'endwhile' where 'endif' was expected to close the 'if' of line 1");
    r = testkit::run("if 1\n" + lines + "else\nelse\nendif\n");
    CHECK(r.error == "test.ray:30003:1: error: 'else' where 'endif' was expected to close the 'if' of line 1");
}

TEST_CASE("a program's own option statements do not change how it is read") {
    // maxstring and maxnest as the run started hold for every line, also after `option`
    std::string p = "option \"maxstring\", 4\noption \"maxnest\", 2\nA = \"long enough\"\nB = ((((1))))\nprint A, B\n";
    CHECK(testkit::printed(p) == "long enough 1\n");
    testkit::Result r = testkit::run(p, {"maxstring=10"});
    CHECK(r.error == "test.ray:3:5: error: string longer than 10 bytes (option maxstring)");
    r = testkit::run(p, {"maxnest=2"});
    CHECK(r.error == "test.ray:4:7: error: expression nested deeper than 2 levels (option maxnest)");
}

namespace {
// A while loop that builds a tree: `levels` times, `per` spheres and then `step`.
std::string tree_program(int levels, int per, const char *step, const char *start = "nothing") {
    char buf[700];
    snprintf(buf, sizeof buf,
             "M = color({1})\nAll = %s\nI = 0\nwhile I < %d\n  J = 0\n  U = nothing\n  while J < %d\n"
             "    U = U | sphere(M, [J %% 50, I %% 50, J / 50 + I / 50], 0.3)\n    J = J + 1\n  endwhile\n"
             "  %s\n  I = I + 1\nendwhile\n"
             "perspective <1,0,0>, <0,0,-1>, [25,-150,5], [25,25,5]\nrendertiff All, dirlight({1}, <1,-2,3>)\n",
             start, levels, per, step);
    return buf;
}
} // namespace

TEST_CASE("preparation is linear: chains built at either end, unions that pruned differences hide") {
    struct Case {
        const char *what;
        std::string program;
    } cases[] = {
        // appending and prepending to a chain of 40 000: one node, each step O(1)
        {"append", tree_program(400, 100, "All = All | U")},
        {"prepend", tree_program(400, 100, "All = U | All")},
        // 600 levels, each a difference whose subtracted sphere is far away (pruned): the unions
        // of all levels become one node; copied level by level they would be 600 x 15 000
        {"pruned differences", tree_program(600, 50, "All = (All | U) \\ sphere(M, [1000, 1000, 1000 + I], 0.1)")},
        // 600 levels of intersections with half-spaces that hold everything
        {"nested intersections", tree_program(600, 50, "All = (All | U) & plane(M, [0, 0, 1000 + I], <0, 0, 1>)")},
        // intersections that pruned differences hide: a ball with 30 000 holes, 600 levels deep
        {"pruned differences of intersections",
         tree_program(600, 50, "All = (All & -U) \\ sphere(M, [1000, 1000, 1000 + I], 0.1)", "sphere(M, [25, 25, 5], 60)")},
    };
    for (const Case &k : cases) {
        CAPTURE(k.what);
        Run r = run_stats(k.program);
        REQUIRE_MESSAGE(r.status == PRAY_OK, r.error);
        CHECK(r.seconds < 10);  // about 0.1 s on a desktop machine (quadratic: 10 s and more)
        CHECK(r.stats.primitives >= 30000);
        CHECK(r.stats.memory_peak / r.stats.primitives_declared < 1500);
        if (std::string(k.what) == "pruned differences") CHECK(r.stats.nodes == 1);
    }
    // the merged tree renders what the reference renders
    std::string small = tree_program(40, 10, "All = (All | U) \\ sphere(M, [1000, 1000, 1000 + I], 0.1)");
    testkit::Result a = testkit::run(small, {"width=24", "height=24"}),
                    b = testkit::run(small, {"width=24", "height=24", "brute=1"});
    REQUIRE(a.frames.size() == 1);
    REQUIRE(b.frames.size() == 1);
    CHECK(a.frames[0].pixels == b.frames[0].pixels);
}

TEST_CASE("every function name is known as one (names are looked up by halving an ordered table)") {
    const char *names[] = {"abs", "arccos", "arcsin", "arctan", "arctan2", "box", "ceil", "color", "cone", "cos",
                           "cylinder", "directionlight", "dirlight", "exp", "floor", "log", "max", "min", "mirror",
                           "move", "norm", "one", "phong", "plane", "planemap", "pointlight", "rod", "round", "sin",
                           "sphere", "spheremap", "sqrt", "stretch", "tan", "text", "tiff", "tiffbump", "torus",
                           "transparent"};
    const std::string v2 = " box ceil cone floor max min rod round stretch torus ";
    for (const char *n : names) {
        CAPTURE(n);
        // (a name of version 2 may be a variable of a program of version 1)
        std::string note = v2.find(std::string(" ") + n + " ") != std::string::npos
                               ? " (a word of version 2 of the language: rename the variable)"
                               : "";
        CHECK(testkit::error_of(std::string("X = ") + n + "\n") ==
              std::string("test.ray:1:5: error: '") + n + "' is a function: write it with its arguments in parentheses" + note);
    }
    // names around them are variables
    CHECK(testkit::printed("aba = 1\nzz = 2\nsphere2 = 3\nSphere = 4\nprint aba, zz, sphere2, Sphere\n") == "1 2 3 4\n");
}

TEST_CASE("values that no later statement names are released; a rendered tree goes once flattened") {
    // the spheres' values are not named after the rendertiff: the render holds none of them
    std::string p = spheres_program(6000);
    Run dead = run_stats(p), alive = run_stats(p + "print All\n");
    REQUIRE_MESSAGE(dead.status == PRAY_OK, dead.error);
    REQUIRE_MESSAGE(alive.status == PRAY_OK, alive.error);
    // a sphere's value costs over 100 bytes: kept, every phase after the run holds them
    CHECK(alive.stats.memory_render > dead.stats.memory_render + 100.0 * 6000);
    CHECK(alive.stats.memory_accel > dead.stats.memory_accel + 100.0 * 6000);
    CHECK(dead.stats.memory_render < dead.stats.memory_prepare);

    // the same images whichever values go when; a message still suggests a released name
    const char *twice = "M = color({1, 0.5, 0})\nBall = sphere(M, [0, 0, 0], 1)\n"
                        "rendertiff Ball | sphere(M, [0.5, 0, 0.5], 0.5), none\nrendertiff Ball, none\n"
                        "I = 0\nwhile I < 2\n  rendertiff Ball, none\n  I = I + 1\nendwhile\nprint Bal\n";
    testkit::Result r = testkit::run(twice, {"width=8", "height=8"});
    CHECK(r.error == "test.ray:10:7: error: undefined variable 'Bal'; did you mean 'Ball'?");
    REQUIRE(r.frames.size() == 4);
    CHECK(r.frames[1].pixels == r.frames[2].pixels);
    CHECK(r.frames[1].pixels == r.frames[3].pixels);
    CHECK(r.frames[0].pixels != r.frames[1].pixels);
    CHECK(r.frames[1].at(4, 4, 0) == 1.0f);  // the model of the released tree is still there
    CHECK(r.frames[1].at(4, 4, 1) == 0.5f);
    r = testkit::run("A = sphere(color({1}), [0, 0, 0], 1)\nrendertiff A, none\nA = 2\nprint A\n", {"width=8", "height=8"});
    CHECK(r.printed == "2\n");
    CHECK(r.frames.size() == 1);
}
