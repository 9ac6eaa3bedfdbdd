// Limits and failures: every limit option at its value and one past it, untrusted mode, and the
// N-th allocation failing for every N until a program and a render complete.
#include <doctest/doctest.h>

#include "testkit.hpp"
#include "tempfiles.hpp"

#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#if defined(__unix__) || defined(__APPLE__)
#include <sys/wait.h>
#include <unistd.h>
#define HAVE_SYMLINK 1
#endif

using testkit::Result;

namespace {

std::string repeat(const std::string &s, int n) {
    std::string r;
    for (int i = 0; i < n; i++) r += s;
    return r;
}

std::string opt(const char *name, double v) {
    std::ostringstream o;
    o.precision(17);
    o << name << "=" << v;
    return o.str();
}

// Runs `prog` with option `name` at `limit` and at `limit - 1` (the program needs exactly
// `limit`): the first must succeed, the second fail with `message` somewhere in its error.
void at_and_past(const char *name, double limit, const std::string &prog, const std::string &message,
                 std::vector<std::string> more = {}) {
    std::string shown = name;
    CAPTURE(shown);
    CAPTURE(limit);
    std::vector<std::string> o = more;
    o.push_back(opt(name, limit));
    Result at = testkit::run(prog, o);
    CHECK_MESSAGE(at.status == PRAY_OK, at.error);
    o.back() = opt(name, limit - 1);
    Result past = testkit::run(prog, o);
    CHECK(past.status != PRAY_OK);
    CHECK_MESSAGE(past.error.find(message) != std::string::npos, past.error);
    CHECK(past.error.find(std::string("option ") + name) != std::string::npos);
}

const char *const TINY = "option \"width\", 2\noption \"height\", 2\n";

// A side x side TIFF of a sphere of radius r in a flat colour, written to each of `paths`.
void write_sphere_tiffs(const std::vector<std::string> &paths, int side, pray_rgb colour, double r) {
    pray_ctx *c = pray_new();
    pray_option(c, "width", side);
    pray_option(c, "height", side);
    pray_object *s = pray_sphere(c, pray_color(c, colour), pray_vec{0, 0, 0}, r);
    pray_image img;
    REQUIRE(pray_render(c, s, NULL, &img) == PRAY_OK);
    for (const std::string &p : paths) REQUIRE(pray_write_image(c, &img, p.c_str(), 8) == PRAY_OK);
    pray_image_free(c, &img);
    pray_release(c, s);
    pray_free(c);
}

} // namespace

TEST_CASE("limit maxsteps: a program of N statements runs with maxsteps N, stops at N - 1") {
    std::string prog = "I = 0\nwhile I < 10\n  I = I + 1\nendwhile\n";  // 1 + 11 tests + 10 bodies
    at_and_past("maxsteps", 22, prog, "error: the program was stopped after 21 statements");
    CHECK(testkit::run(prog, {"maxsteps=0"}).status == PRAY_OK);  // 0: no limit
}

TEST_CASE("limit maxnest: parentheses, calls and blocks at the depth allowed and one deeper") {
    for (int n : {2, 7, 256, 1024}) {
        CAPTURE(n);
        std::string paren = "X = " + repeat("(", n) + "1" + repeat(")", n) + "\nprint X\n";
        at_and_past("maxnest", n, paren, "expression nested deeper than " + std::to_string(n - 1) + (n == 2 ? " level " : " levels "));
        std::string ifs = repeat("if 1 then\n", n) + "print 2\n" + repeat("endif\n", n);
        at_and_past("maxnest", n, ifs, "blocks nested deeper than " + std::to_string(n - 1) + (n == 2 ? " level " : " levels "));
        std::string whiles = repeat("while 0\n", n) + repeat("endwhile\n", n);
        at_and_past("maxnest", n, whiles, "blocks nested deeper");
    }
    // the highest value the option takes is safe for the stack; one more is refused
    pray_ctx *c = pray_new();
    CHECK(pray_option(c, "maxnest", 1024) == PRAY_OK);
    CHECK(pray_option(c, "maxnest", 1025) == PRAY_ERR_ARG);
    pray_free(c);
    std::string sq = "X = " + repeat("sqrt(", 1024) + "1" + repeat(")", 1024) + "\nprint X\n";
    CHECK(testkit::run(sq, {"maxnest=1024"}).printed == "1\n");
}

#if defined(__unix__) || defined(__APPLE__)
TEST_CASE("limit maxnest: one bound on blocks, includes and expressions together, across files") {
    testkit::TempDir d;
    // k blocks around an include of a file with m blocks around an expression e deep: the
    // innermost parenthesis is at level k + 1 + m + e
    auto write = [&](int k, int m, int e) {
        testkit::spit(d / "main.ray", repeat("while I < 1\n", k) + "I = 1\ninclude \"inner.ray\"\n" + repeat("endwhile\n", k));
        testkit::spit(d / "inner.ray", repeat("if 1\n", m) + "print " + repeat("(", e) + "7" + repeat(")", e) + "\n" +
                                           repeat("endif\n", m));
    };
    auto run_at = [&](double maxnest, std::string *out) {
        pray_ctx *c = pray_new();
        pray_set_print(c, testkit::print_sink, out);
        pray_option(c, "maxnest", maxnest);
        std::string prog = "I = 0\ninclude \"main.ray\"\n";
        testkit::spit(d / "top.ray", prog);
        pray_status st = pray_run_file(c, (d / "top.ray").c_str());
        std::string err = st ? pray_error(c) : "";
        pray_free(c);
        return err;
    };
    struct Case { int k, m, e; } cases[] = {{3, 4, 5}, {0, 9, 0}, {9, 0, 0}, {100, 100, 55}};
    for (const Case &t : cases) {
        write(t.k, t.m, t.e);
        int total = 1 + t.k + 1 + t.m + t.e;  // (top.ray's include of main.ray is one level)
        CAPTURE(total);
        std::string out;
        CHECK(run_at(total, &out) == "");
        CHECK(out == "7\n");
        out.clear();
        std::string err = run_at(total - 1, &out);
        CHECK(out == "");
        CHECK_MESSAGE(err.find("nested deeper than " + std::to_string(total - 1) + " levels") != std::string::npos, err);
        CHECK_MESSAGE(err.find("(option maxnest)") != std::string::npos, err);
    }
    // the message names the levels around the part that went past the bound
    write(3, 4, 5);
    std::string out;
    CHECK(run_at(13, &out) == d / "inner.ray" + ":5:11: error: expression nested deeper than 13 levels, counting the "
                                                "9 levels around it (option maxnest) (included from " + d / "main.ray" +
                                                ":5, included from " + d / "top.ray" + ":2)");
    CHECK(run_at(8, &out) == d / "inner.ray" + ":4:1: error: blocks nested deeper than 8 levels, counting the 5 levels "
                                               "around them (option maxnest) (included from " + d / "main.ray" +
                                               ":5, included from " + d / "top.ray" + ":2)");
    CHECK(run_at(4, &out) == d / "main.ray" + ":5:1: error: includes nested deeper than 4 levels, counting the 3 levels "
                                              "around them (option maxnest) (included from " + d / "top.ray" + ":2)");
}

TEST_CASE("limit maxnest: the deepest program the option allows runs on the stack of the smallest target (4 MB)") {
    // DJGPP's recipe gives pray 4 MB of stack (ports/djgpp); a 64-bit build needs more than the
    // 32-bit one. At the highest maxnest, each kind of nesting alone and mixed, with the deepest
    // CSG tree a program may build rendered at the innermost level, and the program of the
    // report that crashed (255 files, each 255 blocks deep around the next) past the bound.
    testkit::TempDir d;
    const std::string tree = "M = phong({0.8, 0.1, 0.1}, {0.3}, 3)\nO = sphere(M, [0, 0, 0], 0.5)\nK = 0\n"
                             "while K < 1990\n  O = sphere(M, [0.001*K, 0, 0], 0.5) - O\n  K = K + 1\nendwhile\n"
                             "L = dirlight({1}, <1, 1, 1>)\n";
    const std::string render = "rendertiff O + " + repeat("(", 900) + "nothing" + repeat(")", 900) + ", L\n";
    auto chain = [&](const std::string &stem, int files, int blocks, const std::string &inner) {
        for (int i = 0; i < files; i++) {
            std::string body = i + 1 < files ? "include \"" + stem + std::to_string(i + 1) + ".ray\"\n" : inner;
            testkit::spit(d / (stem + std::to_string(i) + ".ray"), repeat("if 1\n", blocks) + body + repeat("endif\n", blocks));
        }
    };
    auto pray_small_stack = [&](const std::string &prog, const std::string &opts) {
        std::string prog_path = std::filesystem::absolute(testkit::pray_program()).string();
        std::string cmd = "cd '" + d.path + "' && ulimit -s 4096 && '" + prog_path + "' --quiet -s 8x8 " +
                          opts + " -o out.ppm " + prog + " 2>&1";
        std::string out;
        FILE *p = popen(cmd.c_str(), "r");
        REQUIRE(p);
        char buf[4096];
        size_t n;
        while ((n = fread(buf, 1, sizeof buf, p)) > 0) out.append(buf, n);
        int rc = pclose(p);
        std::remove((d / "out.ppm").c_str());
        return std::to_string(WIFEXITED(rc) ? WEXITSTATUS(rc) : -1) + " " + out;
    };
    testkit::spit(d / "paren.ray", tree + "rendertiff O + " + repeat("(", 1024) + "nothing" + repeat(")", 1024) + ", L\n");
    CHECK(pray_small_stack("paren.ray", "-D maxnest=1024") == "0 ");
    testkit::spit(d / "blocks.ray", tree + repeat("while K > 0\n", 1024) + "K = 0\nrendertiff O, L\n" +
                                        repeat("endwhile\n", 1024));
    CHECK(pray_small_stack("blocks.ray", "-D maxnest=1024") == "0 ");
    chain("inc", 1025, 0, "rendertiff O, L\n");
    testkit::spit(d / "incs.ray", tree + "include \"inc1.ray\"\n");  // inc1 .. inc1024: 1024 levels
    CHECK(pray_small_stack("incs.ray", "-D maxnest=1024") == "0 ");
    chain("mix", 12, 40, render);  // 12 includes, 480 blocks around the render's 900 parentheses: too deep
    testkit::spit(d / "mix.ray", tree + "include \"mix0.ray\"\n");
    std::string r = pray_small_stack("mix.ray", "-D maxnest=1024");
    CHECK_MESSAGE(r.find("1 mix11.ray:41:") == 0, r);
    CHECK_MESSAGE(r.find("nested deeper than 1024 levels") != std::string::npos, r);
    chain("mixok", 3, 40, render);  // 3 includes and 120 blocks around 900 parentheses: 1023
    testkit::spit(d / "mixok.ray", tree + "include \"mixok0.ray\"\n");
    CHECK(pray_small_stack("mixok.ray", "-D maxnest=1024") == "0 ");
    // calls: 1022 nested calls of a procedure (each one level, the body one more) rendering at the
    // innermost, and one past the bound
    const std::string rec = "define R(n)\n  if n == 0\n    rendertiff O, L\n    return 0\n  endif\n  return R(n - 1)\nenddefine\n";
    testkit::spit(d / "calls.ray", tree + rec + "X = R(1022)\n");
    CHECK(pray_small_stack("calls.ray", "-D maxnest=1024") == "0 ");
    testkit::spit(d / "calls2.ray", tree + rec + "X = R(1023)\n");
    r = pray_small_stack("calls2.ray", "-D maxnest=1024");
    CHECK_MESSAGE(r.find("1 calls2.ray:14:10: error: calls nested deeper than 1024 levels") == 0, r);
    chain("crash", 255, 255, "print 1\n");
    r = pray_small_stack("crash0.ray", "");
    CHECK_MESSAGE(r.find("1 crash1.ray:1:1: error: blocks nested deeper than 256 levels") == 0, r);
}
#endif

TEST_CASE("limit maxsteps: every line an include reads counts as a statement") {
    testkit::TempDir d;
    // 1 + 3 statements, then 5 includes of a file of 10 lines with 2 statements each:
    // 4 + 5 * (1 + 10 + 2) = 69
    testkit::spit(d / "lib.ray", "// a library\n\n\n\n\n\n\n\nX = X + 1\nY = 2");
    testkit::spit(d / "main.ray", "X = 0\nI = 0\nwhile I < 5\ninclude \"lib.ray\"\nI = I + 1\nendwhile\nprint X\n");
    auto run_at = [&](double maxsteps, std::string *out) {
        pray_ctx *c = pray_new();
        pray_set_print(c, testkit::print_sink, out);
        pray_option(c, "maxsteps", maxsteps);
        pray_status st = pray_run_file(c, (d / "main.ray").c_str());
        std::string err = st ? pray_error(c) : "";
        pray_free(c);
        return err;
    };
    std::string out;
    // 1 + 1 + 6 tests of the loop + 5 * (include, 10 lines, 2 statements, I = I + 1) + print
    CHECK(run_at(1 + 1 + 6 + 5 * 14 + 1, &out) == "");
    CHECK(out == "5\n");
    // one less: the last print; 13 less: the fifth include's lines
    CHECK(run_at(1 + 1 + 6 + 5 * 14, &out).find("main.ray:7:1: error: the program was stopped after 78 statements (option maxsteps)") !=
          std::string::npos);
    CHECK(run_at(1 + 1 + 5 + 4 * 14 + 1 + 9, &out) ==
          d / "main.ray" + ":4:9: error: the program was stopped after 73 statements (option maxsteps; each line an include "
                           "reads counts as one)");
    // a file of comments read again and again stops as its statements would
    testkit::spit(d / "big.ray", repeat("// " + repeat("x", 60) + "\n", 20000));
    testkit::spit(d / "main.ray", "I = 0\nwhile 1\ninclude \"big.ray\"\nendwhile\n");
    pray_ctx *c = pray_new();
    pray_set_untrusted(c);
    CHECK(pray_run_file(c, (d / "main.ray").c_str()) == PRAY_ERR_LIMIT);
    CHECK(std::string(pray_error(c)).find("main.ray:3:9: error: the program was stopped after 1000000 statements") != std::string::npos);
    pray_free(c);
}

TEST_CASE("limit maxtime: a run that takes longer stops with an error naming the option") {
    auto seconds_since = [](std::chrono::steady_clock::time_point t0) {
        return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    };
    // statements: an endless loop under no step limit
    pray_ctx *c = pray_new();
    pray_option(c, "maxsteps", 0);
    pray_option(c, "maxtime", 1);
    const char *loop = "I = 0\nwhile 1\n  I = I + 1\nendwhile\n";
    auto t0 = std::chrono::steady_clock::now();
    CHECK(pray_run_string(c, "t.ray", loop, strlen(loop)) == PRAY_ERR_LIMIT);
    double took = seconds_since(t0);
    CHECK(took >= 1);
    CHECK(took < 30);  // (a busy machine; the point is that it ends)
    std::string err = pray_error(c);
    CHECK_MESSAGE((err == "t.ray:3:3: error: the run was stopped after 1 second (option maxtime)" ||
                   err == "t.ray:2:1: error: the run was stopped after 1 second (option maxtime)"), err);
    // a render: many nested transparent shells on a large image, with one thread and with two
    // (about 11 s on a 2-core machine of 2026 without the limit)
    std::vector<testkit::Frame> frames;
    pray_set_frame(c, testkit::frame_sink, &frames);
    for (int threads : {1, 2}) {
        CAPTURE(threads);
        pray_option(c, "threads", threads);
        pray_option(c, "width", 2048);
        pray_option(c, "height", 2048);
        pray_option(c, "depth", 64);
        const char *shells = "M = transparent({0.99}, 1)\nO = nothing\nK = 1\nwhile K < 2000\n"
                             "  O = O | (sphere(M, [0, 0, 0], 0.001 * K) - sphere(M, [0, 0, 0], 0.001 * K - 0.0004))\n"
                             "  K = K + 1\nendwhile\nrendertiff O, dirlight({1}, <1, 1, 1>)\n";
        frames.clear();
        t0 = std::chrono::steady_clock::now();
        CHECK(pray_run_string(c, "s.ray", shells, strlen(shells)) == PRAY_ERR_LIMIT);
        took = seconds_since(t0);
        CHECK(took < 30);
        CHECK(std::string(pray_error(c)) == "s.ray:8:1: error: the run was stopped after 1 second (option maxtime)");
        CHECK(frames.empty());
    }
    // the same run with time enough succeeds; maxtime 0 is no limit
    pray_option(c, "width", 16);
    pray_option(c, "height", 16);
    const char *quick = "rendertiff sphere(phong({1}, {0}, 1), [0, 0, 0], 0.5), dirlight({1}, <1, 1, 1>)\n";
    CHECK(pray_run_string(c, "q.ray", quick, strlen(quick)) == PRAY_OK);
    pray_option(c, "maxtime", 0);
    CHECK(pray_run_string(c, "q.ray", quick, strlen(quick)) == PRAY_OK);
    CHECK(frames.size() == 2);
    pray_free(c);
}

TEST_CASE("limit maxline: a line of exactly maxline characters, and one more") {
    for (int n : {10, 100, 5000}) {
        std::string line = "print \"" + repeat("a", n - 8) + "\"";  // n characters
        REQUIRE(line.size() == (size_t)n);
        at_and_past("maxline", n, line + "\n", "1:" + std::to_string(n) + ": error: line longer than");
        // characters are counted, not bytes: e with acute accent is two bytes, one column
        std::string wide = "print \"" + repeat("\xc3\xa9", n - 8) + "\"";
        at_and_past("maxline", n, wide + "\n", "error: line longer than");
    }
    // the default takes 65536 characters
    std::string longest = "X = 1" + repeat(" ", 65531) + "\nprint X\n";
    CHECK(testkit::run(longest).printed == "1\n");
    CHECK(testkit::run(" " + longest).error == "test.ray:1:65537: error: line longer than 65536 characters (option maxline)");
}

TEST_CASE("limit maxline and maxmem while a program is read: a file or a stream that never ends") {
#if defined(__unix__) || defined(__APPLE__)
    // a program file is a regular file: a device that never ends is refused before it is read
    pray_ctx *c = pray_new();
    CHECK(pray_run_file(c, "/dev/zero") == PRAY_ERR_IO);
    CHECK(std::string(pray_error(c)) == "error: cannot read '/dev/zero': not a regular file");
    pray_free(c);
    // standard input ("-") may be a stream that never ends: reading stops just past the first
    // line over maxline, reported as for a finite file, and without a line limit the memory cap
    // ends it; one message, no empty line after it
    auto pray_cmd = [](const std::string &args) {
        std::string out;
        FILE *p = popen(("t=; command -v timeout >/dev/null && t='timeout 60'; $t " + testkit::pray_shell() + " " + args + " 2>&1").c_str(), "r");
        REQUIRE(p);
        char buf[4096];
        size_t n;
        while ((n = fread(buf, 1, sizeof buf, p)) > 0) out.append(buf, n);
        int rc = pclose(p);
        return std::to_string(WIFEXITED(rc) ? WEXITSTATUS(rc) : -1) + " " + out;
    };
    CHECK(pray_cmd("- </dev/zero") == "1 stdin.ray:1:65537: error: line longer than 65536 characters (option maxline)\n");
    CHECK(pray_cmd("--untrusted - </dev/zero") == "1 stdin.ray:1:4097: error: line longer than 4096 characters (option maxline)\n");
    CHECK(pray_cmd("-D maxline=1000000000 -D maxmem=16 - </dev/zero") ==
          "1 pray: error: out of memory: over the cap of 16 MiB (option maxmem)\n");
    CHECK(pray_cmd("-D maxline=1000000000 -D maxmem=16 /dev/zero") == "3 pray: error: cannot read '/dev/zero': not a regular file\n");
    CHECK(pray_cmd("- <examples/redsph.ray -s 4x4 -o limits_stdin.ppm") == "0 ");
    std::remove("limits_stdin.ppm");
#endif
}

TEST_CASE("limit maxstring: literals and strings built by +") {
    at_and_past("maxstring", 5, "print \"abcde\"\n", "1:7: error: string longer than 4 bytes");
    at_and_past("maxstring", 6, "print \"abc\" + \"def\"\n", "1:13: error: string longer than 5 bytes");
    at_and_past("maxstring", 3, "print \"a\" + 12\n", "error: string longer than 2 bytes");  // a number as %g
    // doubling stops at the limit with the message, not out of memory
    Result r = testkit::run("S = \"x\"\nwhile 1\n  S = S + S\nendwhile\n", {"maxstring=1000"});
    CHECK(r.error == "test.ray:3:9: error: string longer than 1000 bytes (option maxstring)");
    pray_ctx *c = pray_new();
    CHECK(pray_option(c, "maxstring", 16777216) == PRAY_OK);
    CHECK(pray_option(c, "maxstring", 16777217) == PRAY_ERR_ARG);
    pray_free(c);
}

TEST_CASE("limit maxprims: an object standing for N primitives") {
    std::string prog = std::string(TINY) + "M = color({1})\nO = sphere(M, [0, 0, 0], 1)\n"
                                           "I = 1\nwhile I < 12\n  O = O | sphere(M, [I, 0, 0], 1)\n  I = I + 1\nendwhile\n"
                                           "rendertiff O\n";
    at_and_past("maxprims", 12, prog, "error: object of more than 11 primitives");
    // shared parts count each time they are used
    std::string shared = "M = color({1})\nS = sphere(M, [0, 0, 0], 1)\nT = S | S\nU = T | T\nV = U & U\n";
    at_and_past("maxprims", 8, shared, "5:7: error: object of more than 7 primitives");
}

TEST_CASE("limit maxpixels: samples of an image, antialias counted") {
    std::string prog = "option \"width\", 10\noption \"height\", 7\nrendertiff sphere(color({1}), [0, 0, 0], 1)\n";
    at_and_past("maxpixels", 70, prog, "error: image of 10 x 7 pixels is over the limit of 69 samples");
    at_and_past("maxpixels", 630, prog, "error: image of 10 x 7 pixels with antialias 3 is over the limit of 629 samples",
                {"antialias=3"});
    // the API gets the same answer from pray_render
    pray_ctx *c = pray_new();
    pray_option(c, "width", 4);
    pray_option(c, "height", 4);
    pray_option(c, "maxpixels", 15);
    pray_object *s = pray_sphere(c, pray_color(c, pray_rgb{1, 1, 1}), pray_vec{0, 0, 0}, 1);
    pray_image img;
    CHECK(pray_render(c, s, NULL, &img) == PRAY_ERR_LIMIT);
    pray_option(c, "maxpixels", 16);
    REQUIRE(pray_render(c, s, NULL, &img) == PRAY_OK);
    pray_image_free(c, &img);
    pray_release(c, s);
    pray_free(c);
}

TEST_CASE("limit maxframes: N frames with maxframes N, the one after refused before it is rendered") {
    std::string prog = std::string(TINY) + "rendertiff nothing\nrendertiff nothing\nrendertiff nothing\nprint 1\n";
    at_and_past("maxframes", 3, prog, "5:1: error: more than 2 frames (option maxframes)");
    Result r = testkit::run(prog, {"maxframes=2"});
    CHECK(r.status == PRAY_ERR_LIMIT);
    CHECK(r.frames.size() == 2);
    CHECK(testkit::run(prog, {"maxframes=0"}).printed == "1\n");  // 0: no limit
    // an endless loop of frames stops at the limit
    r = testkit::run(std::string(TINY) + "while 1\n  rendertiff nothing\nendwhile\n", {"maxframes=50"});
    CHECK(r.error == "test.ray:4:3: error: more than 50 frames (option maxframes)");
    CHECK(r.frames.size() == 50);
}

TEST_CASE("limit maxoutput: image files up to N MiB, not a byte more, and nothing half written") {
    const std::string dir = "limits_output";
    REQUIRE(std::system(("rm -rf " + dir + " && mkdir " + dir).c_str()) == 0);
    // a 1285 x 272 8-bit PPM is 16 bytes of header and 1048560 of samples: exactly 1 MiB
    std::string one = "option \"width\", 1285\noption \"height\", 272\noption \"output\", \"" + dir + "/a.ppm\"\n"
                      "rendertiff nothing\n";
    std::string more = one + "option \"width\", 1\noption \"height\", 1\noption \"output\", \"" + dir + "/b.ppm\"\n"
                       "rendertiff nothing\n";
    auto run = [&](const std::string &prog, const char *limit, std::string *err) {
        pray_ctx *c = pray_new();
        pray_option_fix(c, "maxoutput", limit);
        pray_status st = pray_run_string(c, "out.ray", prog.data(), prog.size());
        *err = pray_error(c);
        pray_free(c);
        return st;
    };
    auto listing = [&]() {
        std::string out;
        FILE *p = popen(("ls -A " + dir).c_str(), "r");
        char buf[256];
        while (p && fgets(buf, sizeof buf, p)) out += buf;
        if (p) pclose(p);
        return out;
    };
    std::string err;
    CHECK(run(one, "1", &err) == PRAY_OK);
    std::ifstream a((dir + "/a.ppm").c_str(), std::ios::binary | std::ios::ate);
    CHECK((long)a.tellg() == 1048576L);
    CHECK(run(more, "1", &err) == PRAY_ERR_LIMIT);  // one byte more is refused
    CHECK(err == "out.ray:8:1: error: '" + dir + "/b.ppm' would take the images written over 1 MiB (option maxoutput)");
    CHECK(listing() == "a.ppm\n");  // the second file is not there, nor its temporary file
    CHECK(run(more, "2", &err) == PRAY_OK);
    CHECK(listing() == "a.ppm\nb.ppm\n");
    CHECK(run(more, "0", &err) == PRAY_OK);  // 0: no limit
    // a file over the limit by itself is not left half written
    REQUIRE(std::system(("rm -f " + dir + "/*").c_str()) == 0);
    pray_ctx *k = pray_new();
    CHECK(pray_option(k, "maxoutput", 0.5) == PRAY_ERR_ARG);  // whole MiB only
    pray_free(k);
    std::string big = "option \"width\", 1400\noption \"height\", 272\noption \"output\", \"" + dir + "/c.tif\"\n"
                      "rendertiff nothing\n";
    CHECK(run(big, "1", &err) == PRAY_ERR_LIMIT);
    CHECK(listing() == "");
    REQUIRE(std::system(("rm -rf " + dir).c_str()) == 0);
}

TEST_CASE("limit depth: rays between two mirrors stop at the depth, and 64 is the most") {
    // the camera stands between two parallel mirrors, looking at one of them: every primary ray
    // is reflected depth - 1 times (the whole ray tree: the scene is black, so the cut-off would
    // leave out every reflection)
    std::string prog = "option \"width\", 1\noption \"height\", 1\nparallel <0.1, 0, 0>, <0, 0, -0.1>, [0, 0, 0], [0, 1, 0]\n"
                       "M = mirror({1})\nA = plane(M, [0, 1, 0], <0, 1, 0>) & plane(M, [0, -1, 0], <0, -1, 0>)\n"
                       "rendertiff -A\n";
    for (int d : {1, 2, 5, 64}) {
        CAPTURE(d);
        pray_ctx *c = pray_new();
        pray_set_frame(c, [](void *, const pray_image *, const char *) { return PRAY_OK; }, NULL);
        REQUIRE(pray_option(c, "depth", d) == PRAY_OK);
        REQUIRE(pray_option(c, "cutoff", 0) == PRAY_OK);
        REQUIRE(pray_run_string(c, "m.ray", prog.data(), prog.size()) == PRAY_OK);
        pray_stats st;
        pray_stats_get(c, &st);
        CHECK(st.rays_primary == 1);
        CHECK(st.rays_reflected == d - 1);
        pray_free(c);
    }
    CHECK(testkit::run("option \"depth\", 65\n").error == "test.ray:1:1: error: option 'depth': 65 is out of range");
}

TEST_CASE("limit maxrays: a sample takes at most maxrays rays; at the value the image is whole") {
    // the eye inside a mirror ball, depth 8: every sample takes exactly 8 rays (1 primary, 7
    // reflected), with a lit surface so that every reflection adds to the image
    std::string prog = "option \"width\", 4\noption \"height\", 4\noption \"depth\", 8\n"
                       "Ball = -sphere(mirror({0.5}) + phong({0.3}, {0}, 1), [0, 0, 0], 10)\n"
                       "rendertiff Ball, pointlight({1}, [0, 0, 0])\n";
    testkit::Result at = testkit::run(prog, {"maxrays=8", "cutoff=0"});
    REQUIRE(at.error == "");
    REQUIRE(at.frames.size() == 1);
    testkit::Result whole = testkit::run(prog, {"cutoff=0"});
    REQUIRE(whole.frames.size() == 1);
    CHECK(at.frames[0].pixels == whole.frames[0].pixels);
    testkit::Result past = testkit::run(prog, {"maxrays=7", "cutoff=0"});
    CHECK(past.status == PRAY_ERR_LIMIT);
    CHECK(past.error == "test.ray:5:1: error: a sample of the image needs more than 7 rays (option maxrays)");
    CHECK(past.frames.empty());
}

TEST_CASE("limit gridmem: the grid's tables stay within the budget") {
    std::string prog = "option \"width\", 8\noption \"height\", 8\nM = color({1})\nO = sphere(M, [0, 0, 0], 0.01)\n"
                       "I = 1\nwhile I < 400\n  O = O | sphere(M, [sin(I), cos(I * 1.3), sin(I * 0.7)], 0.01)\n  I = I + 1\n"
                       "endwhile\nrendertiff O\n";
    for (int mib : {1, 2, 8}) {
        CAPTURE(mib);
        pray_ctx *c = pray_new();
        pray_set_frame(c, [](void *, const pray_image *, const char *) { return PRAY_OK; }, NULL);
        pray_option(c, "gridmem", mib);
        pray_option(c, "grid", 4096);  // asks for far more than the budget
        REQUIRE(pray_run_string(c, "g.ray", prog.data(), prog.size()) == PRAY_OK);
        pray_stats st;
        pray_stats_get(c, &st);
        CHECK(st.memory > 0);
        CHECK(st.memory <= (double)mib * 1048576.0);
        pray_free(c);
    }
}

TEST_CASE("limit texmem and maxmem: a texture over the budget, a context over its memory") {
    // a 640 x 640 8-bit RGB TIFF: 1.2 MB, over texmem 1; decoded it needs less than 16 MiB
    write_sphere_tiffs({"limits_big.tif"}, 640, pray_rgb{1, 0.5, 0.25}, 1);
    std::string prog = std::string(TINY) + "M = color({1})\nT = tiff(M, M, \"limits_big.tif\")\n"
                                           "rendertiff planemap(T, [0, 0, 0], <1, 0, 0>, <0, 1, 0>, <0, 0, 1>)\n";
    Result r = testkit::run(prog, {"texmem=1"});
    CHECK(r.error == "test.ray:4:5: error: 'limits_big.tif' is over the texture memory limit (option texmem)");
    CHECK(testkit::run(prog, {"texmem=16"}).status == PRAY_OK);
    // maxmem: 2 MiB do not hold the decoded texture
    r = testkit::run(prog, {"maxmem=2", "texmem=16"});
    CHECK(r.status == PRAY_ERR_NOMEM);
    CHECK(r.error.find("out of memory") != std::string::npos);
    CHECK(testkit::run(prog, {"maxmem=64", "texmem=16"}).status == PRAY_OK);
    std::remove("limits_big.tif");
    // maxmem lowers the host's cap, never raises it
    pray_ctx *c = pray_new();
    pray_set_memory_limit(c, 100000);
    pray_option(c, "maxmem", 64);
    pray_option(c, "width", 256);
    pray_option(c, "height", 256);
    pray_object *s = pray_sphere(c, pray_color(c, pray_rgb{1, 1, 1}), pray_vec{0, 0, 0}, 1);
    pray_image img;
    CHECK(pray_render(c, s, NULL, &img) == PRAY_ERR_NOMEM);
    pray_set_memory_limit(c, 0);
    REQUIRE(pray_render(c, s, NULL, &img) == PRAY_OK);
    pray_image_free(c, &img);
    pray_option(c, "maxmem", 1);
    pray_option(c, "width", 512);
    CHECK(pray_render(c, s, NULL, &img) == PRAY_ERR_NOMEM);  // 512 x 256 floats: 1.5 MiB
    pray_release(c, s);
    pray_free(c);
}

// ---------------------------------------------------------------------------------------------
// Untrusted mode
// ---------------------------------------------------------------------------------------------
namespace {
void write_text(const std::string &path, const std::string &text) {
    std::ofstream f(path.c_str(), std::ios::binary);
    f << text;
}
} // namespace

TEST_CASE("untrusted mode: every limit gets its ceiling; higher values and 'no limit' are refused") {
    const struct {
        const char *name;
        double ceiling;
    } ceilings[] = {{"depth", 16},         {"gridmem", 64},           {"maxframes", 1000},
                    {"maxline", 4096},     {"maxmem", 1024},          {"maxnest", 64},
                    {"maxoutput", 1024},   {"maxpixels", 16777216},   {"maxprims", 1048576},
                    {"maxrays", 256},      {"maxsteps", 1000000},     {"maxstring", 4096},
                    {"maxtime", 600},      {"texmem", 64}};
    pray_ctx *c = pray_new();
    pray_option(c, "maxsteps", 0);
    pray_option(c, "depth", 3);
    pray_set_untrusted(c);
    CHECK(pray_option_get(c, "depth") == 3);  // already below its ceiling: kept
    for (const auto &k : ceilings) {
        CAPTURE(k.name);
        if (strcmp(k.name, "depth") != 0) CHECK(pray_option_get(c, k.name) <= k.ceiling);
        CHECK(pray_option(c, k.name, k.ceiling) == PRAY_OK);
        CHECK(pray_option(c, k.name, k.ceiling + 1) == PRAY_ERR_ARG);
        CHECK(std::string(pray_error(c)).find("ceiling in untrusted mode") != std::string::npos);
        CHECK(pray_option_get(c, k.name) == k.ceiling);
    }
    CHECK(pray_option_get(c, "maxsteps") == 1000000);
    CHECK(pray_option(c, "maxsteps", 0) == PRAY_ERR_ARG);
    CHECK(std::string(pray_error(c)) == "error: option 'maxsteps': 0 (no limit) is above 1000000, the ceiling in untrusted mode");
    CHECK(pray_option(c, "maxmem", 0) == PRAY_ERR_ARG);
    CHECK(pray_option(c, "maxtime", 0) == PRAY_ERR_ARG);
    // a program meets the same ceilings
    const char *prog = "option \"maxsteps\", 2000000\n";
    CHECK(pray_run_string(c, "u.ray", prog, strlen(prog)) != PRAY_OK);
    CHECK(std::string(pray_error(c)).find("u.ray:1:1: error: option 'maxsteps'") == 0);
    prog = "option \"maxsteps\", 10\nI = 0\nwhile 1\n  I = I + 1\nendwhile\n";  // lower is fine
    CHECK(pray_run_string(c, "u.ray", prog, strlen(prog)) == PRAY_ERR_LIMIT);
    CHECK(std::string(pray_error(c)).find("stopped after 10 statements") != std::string::npos);
    pray_free(c);
}

TEST_CASE("untrusted mode: files only from the program's directory") {
    // a directory with a program, a texture beside it, one in a subdirectory, one outside
    const std::string dir = "limits_untrusted";
    std::string clean = "rm -rf " + dir;
    REQUIRE(std::system(clean.c_str()) == 0);
    REQUIRE(std::system(("mkdir -p " + dir + "/sub").c_str()) == 0);
    write_sphere_tiffs({dir + "/red.tif", dir + "/sub/red.tif", "limits_outside.tif"}, 4, pray_rgb{1, 0, 0}, 9);
#ifdef HAVE_SYMLINK
    REQUIRE(symlink("../limits_outside.tif", (dir + "/link.tif").c_str()) == 0);
    REQUIRE(symlink("red.tif", (dir + "/inlink.tif").c_str()) == 0);
    REQUIRE(symlink("sub", (dir + "/sublink").c_str()) == 0);
#endif
    auto run = [&](const std::string &file, bool untrusted, const std::string &output = "") {
        std::string prog = std::string(TINY) + "M = color({1})\nT = tiff(M, M, \"" + file + "\")\n";
        if (!output.empty()) prog += "option \"output\", \"" + output + "\"\n";
        write_text(dir + "/p.ray", prog);
        pray_ctx *k = pray_new();
        pray_set_frame(k, [](void *, const pray_image *, const char *) { return PRAY_OK; }, NULL);
        if (untrusted) pray_set_untrusted(k);
        pray_status st = pray_run_file(k, (dir + "/p.ray").c_str());
        std::string e = st == PRAY_OK ? "" : pray_error(k);
        pray_free(k);
        return e;
    };
    const std::string where = dir + "/p.ray:4:5: error: untrusted program: '";
    CHECK(run("red.tif", true) == "");
    CHECK(run("sub/red.tif", true) == "");
    CHECK(run("../limits_outside.tif", true) == where + "../limits_outside.tif' is a name with '..'; files are read from the program's directory only");
    CHECK(run("sub/../../limits_outside.tif", true).find("is a name with '..'") != std::string::npos);
    CHECK(run("/etc/passwd", true) == where + "/etc/passwd' is not a relative name; files are read from the program's directory only");
    CHECK(run("C:/x.tif", true).find("is not a relative name") != std::string::npos);
    CHECK(run("", true).find("is an empty name") != std::string::npos);
#ifdef HAVE_SYMLINK
    // no link is followed, wherever it leads: the name is walked from the program's directory
    const std::string tail = "; files are read from the program's directory only, and links are not followed";
    CHECK(run("link.tif", true) == where + "link.tif' is a symbolic link" + tail);
    CHECK(run("inlink.tif", true) == where + "inlink.tif' is a symbolic link" + tail);
    CHECK(run("sublink/red.tif", true) == where + "sublink/red.tif' passes through the symbolic link 'sublink'" + tail);
    CHECK(run("sub//red.tif", true) == "");
    CHECK(run("link.tif", false) == "");  // trusted: read wherever the link leads
    CHECK(run("sublink/red.tif", false) == "");
#endif
    // not a regular file
    CHECK(run(".", true) == dir + "/p.ray:4:5: error: cannot read '" + dir + "/.': not a regular file");
    CHECK(run("sub", false) == dir + "/p.ray:4:5: error: cannot read '" + dir + "/sub': not a regular file");
    CHECK(run("../limits_outside.tif", false) == "");
    // a file in the current directory is not looked for when untrusted
    CHECK(run("limits_outside.tif", true).find("cannot open") != std::string::npos);
    CHECK(run("limits_outside.tif", false) == "");
    // outputs: a plain name only
    CHECK(run("red.tif", true, "x.tif") == "");
    CHECK(run("red.tif", true, "sub/x.tif").find("option 'output': an untrusted program may name a file, not a directory") != std::string::npos);
    CHECK(run("red.tif", true, "../x.tif").find("not a directory") != std::string::npos);
    CHECK(run("red.tif", false, "sub/x.tif") == "");
    REQUIRE(std::system(clean.c_str()) == 0);
    std::remove("limits_outside.tif");
}

TEST_CASE("untrusted mode: a texture swapped for a link while it is opened never leads out (1000 runs)") {
#ifdef HAVE_SYMLINK
    // t.tif is, in turn, a link to a file outside (not a TIFF: reading it would say so) and a
    // hard link to the TIFF beside the program; each swap is one rename, so the name always exists
    const std::string dir = "limits_race";
    REQUIRE(std::system(("rm -rf " + dir + " && mkdir " + dir).c_str()) == 0);
    write_sphere_tiffs({dir + "/real.tif"}, 4, pray_rgb{1, 0, 0}, 9);
    write_text("limits_race_outside.txt", "a secret outside the program's directory\n");
    write_text(dir + "/p.ray", "M = color({1})\nT = tiff(M, M, \"t.tif\")\n");
    REQUIRE(link((dir + "/real.tif").c_str(), (dir + "/t.tif").c_str()) == 0);
    std::atomic<bool> stop(false);
    std::thread swapper([&] {
        const std::string l = dir + "/swap.l", r = dir + "/swap.r", t = dir + "/t.tif";
        while (!stop) {
            if (symlink("../limits_race_outside.txt", l.c_str()) == 0) rename(l.c_str(), t.c_str());
            if (link((dir + "/real.tif").c_str(), r.c_str()) == 0) rename(r.c_str(), t.c_str());
        }
    });
    int ok = 0, refused = 0, other = 0;
    std::string odd;
    for (int i = 0; i < 1000; i++) {
        pray_ctx *c = pray_new();
        pray_set_untrusted(c);
        if (pray_run_file(c, (dir + "/p.ray").c_str()) == PRAY_OK) ok++;
        else if (std::string(pray_error(c)).find("'t.tif' is a symbolic link") != std::string::npos) refused++;
        else {
            other++;
            odd = pray_error(c);
        }
        pray_free(c);
    }
    stop = true;
    swapper.join();
    CAPTURE(odd);
    CHECK(other == 0);  // before the walk without links: 13 to 204 of 1000 read the file outside
    CHECK(ok > 0);
    CHECK(refused > 0);
    MESSAGE("read the TIFF ", ok, " times, refused the link ", refused, " times");
    REQUIRE(std::system(("rm -rf " + dir).c_str()) == 0);
    std::remove("limits_race_outside.txt");
#endif
}

TEST_CASE("long names: a program under a path of 600 bytes, texture names of 1100, nothing is cut") {
    const std::string dir = "limits_long";
    REQUIRE(std::system(("rm -rf " + dir + " && mkdir -p " + dir + "/d").c_str()) == 0);
    write_sphere_tiffs({dir + "/d/lp.tif", dir + "/d/red.tif"}, 4, pray_rgb{1, 0, 0}, 9);
    write_text("lp.tif", "a file of the same name in the current directory\n");
    write_text(dir + "/d/red", "the file a name cut at 1100 bytes would open\n");
    auto run = [&](const std::string &prog_path, const std::string &tex, bool untrusted) {
        write_text(dir + "/d/p.ray", "M = color({1})\nT = tiff(M, M, \"" + tex + "\")\n");
        pray_ctx *c = pray_new();
        if (untrusted) pray_set_untrusted(c);
        pray_status st = pray_run_file(c, prog_path.c_str());
        std::string e = st == PRAY_OK ? "" : pray_error(c);
        pray_free(c);
        return e;
    };
    // (1) the program's directory is longer than 512 bytes: its textures are still beside it
    std::string far = dir + "/d/" + repeat("./", 300) + "p.ray";
    CHECK(run(far, "lp.tif", true) == "");
    // (2) a texture name that made "directory + name" 1100 bytes, cut to ".../red"
    std::string near = dir + "/d/p.ray";
    std::string name = "." + repeat("/", 1099 - (int)(dir + "/d/").size() - 4) + "red.tif";
    CHECK(run(near, name, true) == "");
    CHECK(run(near, name, false) == "");
    // (3) a name the system cannot take fails with its reason, not with another file
    std::string huge = repeat("x", 5000) + ".tif";
    std::string e = run(near, huge, false);
    CHECK(e.find("File name too long") != std::string::npos);
    // (4) the message keeps the place and the reason: the path is shortened, from its start
    std::string farther = dir + "/d/" + repeat("./", 520) + "p.ray";
    e = run(farther, "nosuch.tif", false);
    CHECK(e.find("...") == 0);
    CHECK(e.size() < 300);
    CHECK(e.find("/./p.ray:2:5: error: cannot open 'nosuch.tif': No such file or directory") != std::string::npos);
    e = run(farther, "nosuch.tif", true);  // untrusted: the name beside the program, shortened
    CHECK(e.find("/./p.ray:2:5: error: cannot open '...") != std::string::npos);
    CHECK(e.find("/./nosuch.tif': No such file or directory") != std::string::npos);
    REQUIRE(std::system(("rm -rf " + dir).c_str()) == 0);
    std::remove("lp.tif");
}

// ---------------------------------------------------------------------------------------------
// The N-th allocation fails
// ---------------------------------------------------------------------------------------------
namespace {
struct Failing {
    long countdown = 0;  // the allocation that fails (1 = the next one); 0 = none
    long made = 0;       // allocations and growths asked for
    long live = 0;       // blocks held
    bool failed = false;
    std::map<void *, size_t> sizes;
};

void *failing_alloc(void *ud, void *ptr, size_t, size_t nsize) {
    Failing *f = static_cast<Failing *>(ud);
    if (nsize == 0) {
        if (ptr && f->sizes.erase(ptr)) f->live--;
        std::free(ptr);
        return NULL;
    }
    f->made++;
    if (f->countdown && --f->countdown == 0) {
        f->failed = true;
        return NULL;
    }
    void *p = std::realloc(ptr, nsize);
    if (!p) return NULL;
    if (ptr && f->sizes.erase(ptr)) f->live--;
    f->sizes[p] = nsize;
    f->live++;
    return p;
}

void no_print(void *, const void *, size_t) {}

// One program and one API render under an allocator failing at allocation n (0: never).
// Returns the status of the first failing step, OK when everything completed.
pray_status exercise(Failing &f, const std::string &prog, int threads) {
    pray_ctx *c = pray_new_with(failing_alloc, &f);
    if (!c) return PRAY_ERR_NOMEM;
    pray_set_print(c, no_print, NULL);
    pray_set_frame(c, [](void *, const pray_image *, const char *) { return PRAY_OK; }, NULL);
    pray_option(c, "threads", threads);
    pray_status st = pray_run_string(c, "alloc.ray", prog.data(), prog.size());
    if (st == PRAY_OK) {
        // the API: objects, a render with antialias and undersampling, both writers
        pray_model *m = pray_phong(c, pray_rgb{0.8f, 0.2f, 0.2f}, pray_rgb{0.3f, 0.3f, 0.3f}, pray_rgb{0.1f, 0.1f, 0.1f}, 5);
        pray_object *a = pray_sphere(c, m, pray_vec{0, 0, 0}, 1);
        pray_object *b = pray_cylinder(c, m, pray_vec{0, 0, 0}, pray_vec{0, 0, 1}, 0.3);
        pray_object *d = a && b ? pray_csg(c, PRAY_DIFFERENCE, a, b) : NULL;
        pray_light *l = pray_dirlight(c, pray_rgb{1, 1, 1}, pray_vec{1, -1, 1});
        pray_image img;
        img.pixels = NULL;
        if (!d || !l) st = pray_last_status(c);
        else if ((st = pray_option(c, "antialias", 2)) == PRAY_OK && (st = pray_option(c, "adaptive", 0.1)) == PRAY_OK)
            st = pray_render(c, d, l, &img);
        if (st == PRAY_OK) st = pray_write_tiff(c, &img, 8, no_print, NULL);
        if (st == PRAY_OK) st = pray_write_ppm(c, &img, 16, no_print, NULL);
        if (st == PRAY_OK && std::strstr(pray_features(), "png")) st = pray_write_png(c, &img, no_print, NULL);
        // a scene of two opaque materials prepared for a render (whose lists leave out the face
        // between them), and a query on it (which builds them)
        pray_model *m2 = pray_phong(c, pray_rgb{0.2f, 0.2f, 0.8f}, pray_rgb{0, 0, 0}, pray_rgb{0, 0, 0}, 5);
        pray_object *e = m2 ? pray_sphere(c, m2, pray_vec{0.5, 0, 0}, 0.6) : NULL, *de = d && e ? pray_csg(c, PRAY_UNION, d, e) : NULL;
        if (st == PRAY_OK) {
            pray_scene *q = de ? pray_prepare_render(c, de, l) : NULL;
            pray_hit h[4];
            if (!q || pray_intersect(c, q, pray_vec{-3, 0.1, 0}, pray_vec{1, 0, 0}, HUGE_VAL, h, 4) < 0) st = pray_last_status(c);
            pray_scene_free(c, q);
        }
        pray_release(c, m2);
        pray_release(c, e);
        pray_release(c, de);
        pray_image_free(c, &img);
        pray_release(c, m);
        pray_release(c, a);
        pray_release(c, b);
        pray_release(c, d);
        pray_release(c, l);
    }
    if (st != PRAY_OK && st != PRAY_ERR_NOMEM) MESSAGE("status ", (int)st, ": ", pray_error(c));
    if (st == PRAY_ERR_NOMEM) CHECK(std::string(pray_error(c)).find("out of memory") != std::string::npos);
    pray_free(c);
    return st;
}
} // namespace

TEST_CASE("the N-th allocation fails, for every N: out of memory, no leak, until everything completes") {
    // a program touching every kind of value, CSG, text, textures, lights, strings, a render
    std::string prog = std::string("option \"width\", 6\noption \"height\", 5\noption \"antialias\", 2\n") +
                       "S = \"name\" + 7\nprint S, [1, 2, 3], <1, 0, 0>, {0.5}\n"
                       "M = phong({0.8, 0.2, 0.2}, {0.3}, {0.1}, 5) + mirror({0.2})\n"
                       "G = transparent({0.5}, 1.5)\n"
                       "O = sphere(M, [0, 0, 0], 1) - cylinder(G, [0, 0, 0], <0, 0, 1>, 0.3)\n"
                       "O = O | plane(color({0.2}), [0, 0, -1], <0, 0, 1>) & -sphere(M, [2, 0, 0], 0.5)\n"
                       "T = text(M, \"Hi\", [-1, 0, 1], <0.2, 0, 0>, <0, 0, 0.3>, 0.05, \"\", 1)\n"
                       "O = (O | T).<1, 1, 1>.[0.1, 0, 0]\n"
                       "L = dirlight({1}, <1, -1, 1>) + pointlight({0.5}, [0, -3, 2])\n"
                       "I = 0\nwhile I < 2\n  rendertiff O, L\n  I = I + 1\nendwhile\n";
    for (int threads : {1, 2}) {
        CAPTURE(threads);
        Failing whole;
        REQUIRE(exercise(whole, prog, threads) == PRAY_OK);
        REQUIRE(whole.live == 0);
        long total = whole.made;
        MESSAGE("allocations in one complete run with ", threads, " thread(s): ", total);
        int ok = 0, nomem = 0, other = 0, leaks = 0, not_failed = 0;
        // with one thread every N; with two (allocation order varies) a spread of N
        // every N with one thread; with two (the order of allocations varies) every 7th, and
        // one N far enough past the end to complete
        std::vector<long> ns;
        for (long n = 1; n <= total + 1; n += threads == 1 ? 1 : 7) ns.push_back(n);
        if (threads > 1) ns.push_back(total + 200);
        for (long n : ns) {
            Failing f;
            f.countdown = n;
            pray_status st = exercise(f, prog, threads);
            if (f.live != 0) {
                leaks++;
                MESSAGE("N = ", n, ": ", f.live, " blocks not freed");
            }
            if (st == PRAY_OK) {
                ok++;
                if (f.failed) not_failed++;  // a failed allocation must not go unnoticed
            } else if (st == PRAY_ERR_NOMEM) nomem++;
            else {
                other++;
                MESSAGE("N = ", n, ": status ", (int)st);
            }
        }
        CHECK(leaks == 0);
        CHECK(other == 0);
        CHECK(not_failed == 0);
        CHECK(nomem >= (threads == 1 ? total : total / 7) - 1);
        CHECK(ok >= 1);
    }
}

#if defined(__linux__)
TEST_CASE("threads=0 counts the processors the process may run on (its affinity), not the machine's") {
    std::string out;
    FILE *p = popen(("command -v taskset >/dev/null || exit 0; taskset -c 0 " + testkit::pray_shell() +
                     " --stats --threads 0 -s 16x16 -o limits_affinity.ppm examples/redsph.ray 2>&1")
                        .c_str(),
                    "r");
    REQUIRE(p);
    char buf[4096];
    size_t n;
    while ((n = fread(buf, 1, sizeof buf, p)) > 0) out.append(buf, n);
    pclose(p);
    std::remove("limits_affinity.ppm");
    if (out.empty()) return;  // (no taskset here)
    CHECK_MESSAGE(out.find(" on 1 thread\n") != std::string::npos, out);
    CHECK_MESSAGE(out.find(" threads\n") == std::string::npos, out);
}
#endif
