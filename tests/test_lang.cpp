// Tests of the PRAY language: lexer, operators, statements, errors, rendertiff frames and the
// sample programs of the thesis. Written from the language specification (pray-language.md of the
// project's shared notes): where pray.cpp and the specification disagree, these tests follow the
// specification. They run with the repository root as the current directory (examples/*.ray).
#include <doctest/doctest.h>

#include "testkit.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace {

// A failed run, with its message taken apart: "name:line:col: error: msg".
struct Failure {
    pray_status status = PRAY_OK;
    std::string text;  // the whole message
    bool formatted = false;  // it has the "name:line:col: error: " prefix
    int line = -1, col = -1;
    std::string msg;  // the part after "error: "
    std::string printed;
    size_t frames = 0;
    // "line:col", or what is wrong with the message
    std::string where() const {
        if (status == PRAY_OK) return "(no error)";
        if (!formatted) return "(not name:line:col: error: ...)";
        return std::to_string(line) + ":" + std::to_string(col);
    }
    std::string where_line() const {
        if (status == PRAY_OK) return "(no error)";
        if (!formatted) return "(not name:line:col: error: ...)";
        return std::to_string(line);
    }
};

// "" for a successful run, else its status and message.
std::string problem(const testkit::Result &r) {
    if (r.status == PRAY_OK) return "";
    return "status " + std::to_string((int)r.status) + ": " + r.error;
}

std::string where_is(int line, int col) { return std::to_string(line) + ":" + std::to_string(col); }

Failure split_error(const testkit::Result &r, const std::string &name) {
    Failure f;
    f.status = r.status;
    f.text = r.error;
    f.printed = r.printed;
    f.frames = r.frames.size();
    f.msg = r.error;
    std::string pre = name + ":";
    if (r.error.compare(0, pre.size(), pre) == 0) {
        int l = -1, c = -1, n = -1;
        if (std::sscanf(r.error.c_str() + pre.size(), "%d:%d: error: %n", &l, &c, &n) == 2 && n > 0 &&
            r.error.compare(pre.size() + (size_t)n - 7, 7, "error: ") == 0) {
            f.formatted = true;
            f.line = l;
            f.col = c;
            f.msg = r.error.substr(pre.size() + (size_t)n);
        }
    }
    return f;
}

Failure run_fail(const std::string &prog, const std::vector<std::string> &opts = {},
                 const char *name = "test.ray") {
    return split_error(testkit::run(prog, opts, name), name);
}

bool contains(const std::string &s, const std::string &part) { return s.find(part) != std::string::npos; }

std::string read_text(const char *path) {
    std::ifstream f(path, std::ios::binary);
    std::stringstream ss;
    ss << f.rdbuf();
    return ss.str();
}

bool frame_is(const testkit::Frame &f, float r, float g, float b) {
    for (int y = 0; y < f.height; y++)
        for (int x = 0; x < f.width; x++)
            if (f.at(x, y, 0) != r || f.at(x, y, 1) != g || f.at(x, y, 2) != b) return false;
    return f.width > 0 && f.height > 0;
}

} // namespace

// The program runs without an error and prints exactly `expected`.
#define CHECK_PRINTS(prog, expected)                                                                 \
    do {                                                                                             \
        testkit::Result r_ = testkit::run(prog);                                                     \
        INFO("program:\n" << (prog));                                                               \
        CHECK(problem(r_) == "");                                                                    \
        CHECK(r_.printed == (expected));                                                             \
    } while (0)

// The program fails with exactly "line:col: message" after "test.ray:" and before "error: ".
#define CHECK_ERROR(prog, L, C, message)                                                             \
    do {                                                                                             \
        Failure f_ = run_fail(prog);                                                                 \
        INFO("program:\n" << (prog));                                                               \
        INFO("error: " << f_.text);                                                                  \
        CHECK(f_.status != PRAY_OK);                                                                 \
        CHECK(f_.where() + " " + f_.msg == where_is(L, C) + " " + (message));                        \
    } while (0)

// The program fails at line:col with a message containing `part`.
#define CHECK_ERROR_HAS(prog, L, C, part)                                                            \
    do {                                                                                             \
        Failure f_ = run_fail(prog);                                                                 \
        INFO("program:\n" << (prog));                                                               \
        INFO("error: " << f_.text);                                                                  \
        CHECK(f_.where() == where_is(L, C));                                                         \
        CHECK(contains(f_.msg, part));                                                               \
    } while (0)

// The program fails on line L (any column) with a message containing `part`.
#define CHECK_ERROR_LINE(prog, L, part)                                                              \
    do {                                                                                             \
        Failure f_ = run_fail(prog);                                                                 \
        INFO("program:\n" << (prog));                                                               \
        INFO("error: " << f_.text);                                                                  \
        CHECK(f_.where_line() == std::to_string(L));                                                 \
        CHECK(contains(f_.msg, part));                                                               \
    } while (0)

// =============================================================================================
// Lexer
// =============================================================================================

TEST_CASE("lexer: comments") {
    CHECK_PRINTS("// a comment line\nprint 1\n", "1\n");
    CHECK_PRINTS("x = 1 // after an assignment\nprint x // after a print\n", "1\n");
    CHECK_PRINTS("print \"a // b\"\n", "a // b\n");
    CHECK_PRINTS("print \"//\" // the string is not a comment, this is\n", "//\n");
    CHECK_PRINTS("print 1//2\n", "1\n");
    CHECK_PRINTS("// P\xC5\x99\xC3\xADli\xC5\xA1 \xC5\xBElu\xC5\xA5ou\xC4\x8Dk\xC3\xBD k\xC5\xAF\xC5\x88\nprint 2\n",
                 "2\n");
    // a `\` inside a comment is not a continuation mark
    CHECK_PRINTS("print 1 // foo \\\nprint 2\n", "1\n2\n");
}

TEST_CASE("lexer: line continuation with \\ and the yen sign") {
    CHECK_PRINTS("print 1, \\\n 2\n", "1 2\n");
    CHECK_PRINTS("x = 1 + \\\n    2\nprint x\n", "3\n");
    CHECK_PRINTS("print 1, \\ // a comment after the mark\n 2\n", "1 2\n");
    CHECK_PRINTS("print 1, \xC2\xA5\n 2\n", "1 2\n");
    CHECK_PRINTS("print 1, \xC2\xA5 // a comment after the yen mark\n 2\n", "1 2\n");
    CHECK_PRINTS("print 1, \\\n 2, \\\n 3\n", "1 2 3\n");
    CHECK_PRINTS("print 1, \\\r\n 2\r\n", "1 2\n");
    // lines keep their numbers after a continuation
    CHECK_ERROR("print 1, \\\n 2\nx = 1 & nothing\n", 3, 7, "cannot apply '&' to number and object");
    CHECK_ERROR("x = 1 + \\\n  nothing\n", 1, 7, "cannot apply '+' to number and object");
    // a `\` that is not the last thing on its line is an operator, and inside a string a character
    CHECK_PRINTS("print 6 \\ 3\n", "5\n");
    CHECK_PRINTS("print \"a\\\"\nprint 2\n", "a\\\n2\n");
}

TEST_CASE("lexer: a continuation on the last line is an error") {
    CHECK_ERROR_HAS("print 1 \\", 1, 9, "continuation");
    CHECK_ERROR_HAS("print 1 \\\n", 1, 9, "continuation");
    CHECK_ERROR_HAS("print 1 \xC2\xA5\n", 1, 9, "continuation");
    CHECK_ERROR_HAS("print 0\nprint 1, \\ // comment\n", 2, 10, "continuation");
    Failure f = run_fail("print 0\nprint 1 \\\n");
    CHECK(f.printed == "");
}

TEST_CASE("lexer: CRLF line ends") {
    CHECK_PRINTS("print 1\r\nprint 2\r\n", "1\n2\n");
    CHECK_PRINTS("x = 5 // comment\r\nprint x\r\n", "5\n");
    CHECK_PRINTS("if 1 then\r\nprint \"yes\"\r\nendif\r\n", "yes\n");
    CHECK_ERROR("print 1\r\nx = 1 & nothing\r\n", 2, 7, "cannot apply '&' to number and object");
}

TEST_CASE("lexer: strings") {
    CHECK_PRINTS("print \"C:\\TEX\\WOOD.TIF\"\n", "C:\\TEX\\WOOD.TIF\n");
    CHECK_PRINTS("print \"say \"\"hi\"\"\"\n", "say \"hi\"\n");
    CHECK_PRINTS("print \"\"\"\"\n", "\"\n");
    CHECK_PRINTS("print \"\"\n", "\n");
    CHECK_PRINTS("print \"x\\n\"\n", "x\\n\n");
    CHECK_PRINTS("print \"\xC3\xA9\xC2\xA5\"\n", "\xC3\xA9\xC2\xA5\n");
    CHECK_PRINTS("print \"tab\there\"\n", "tab\there\n");
}

TEST_CASE("lexer: unterminated strings") {
    CHECK_ERROR("print \"abc\n", 1, 7, "unterminated string");
    CHECK_ERROR("print \"abc", 1, 7, "unterminated string");
    CHECK_ERROR("print 1\nprint \"abc\nprint 2\"\n", 2, 7, "unterminated string");
    CHECK_ERROR("print \"a\"\"\n", 1, 7, "unterminated string");
}

TEST_CASE("lexer: numbers") {
    CHECK_PRINTS("print 12, 12.36, .5, 1e-3, 2.5E+4\n", "12 12.36 0.5 0.001 25000\n");
    CHECK_PRINTS("print 1E3, 1e+2, 0.25, 007, 1.5e1\n", "1000 100 0.25 7 15\n");
    CHECK_PRINTS("print 2*.5\n", "1\n");
    CHECK_PRINTS("x = .5\nprint x\n", "0.5\n");
}

TEST_CASE("lexer: '1.' is the number 1 and the '.' operator") {
    CHECK_ERROR("print 1.<0,0,90>\n", 1, 8, "cannot apply '.' to number and vector");
    CHECK_ERROR("print 1.\n", 1, 9, "expected a value, found 'end of line'");
    CHECK_PRINTS("V = <1,0,0>\nprint V.<0,0,90>\n", "<0, 1, 0>\n");
    CHECK_PRINTS("P = [1,2,3]\nprint P.[1,1,1]\n", "[2, 3, 4]\n");
}

TEST_CASE("lexer: Cube.5 is an error; Cube . 5 and Cube.(5) work") {
    const char *setup = "M = color({1})\nCube = sphere(M, [0,0,0], 1)\n";
    Failure f = run_fail(std::string(setup) + "x = Cube.5\n");
    INFO(f.text);
    CHECK(f.status == PRAY_ERR_SYNTAX);
    CHECK(f.formatted);
    CHECK(f.line == 3);
    CHECK(f.col == 9);
    CHECK(contains(f.msg, ". 5"));
    CHECK(contains(f.msg, ".(5)"));
    CHECK(f.printed == "");
    CHECK_PRINTS(std::string(setup) + "print Cube . 5, Cube.(5), Cube . .5\n",
                 "object (1 primitive) object (1 primitive) object (1 primitive)\n");
    // the same rule for every value, and a .5 that follows a value with a blank
    CHECK_ERROR_HAS("x = 2\nprint x.5\n", 2, 8, ".(5)");
    CHECK_ERROR_HAS("x = 2\nprint x .5\n", 2, 9, ".(5)");
    CHECK_ERROR_HAS("print 1.5.2\n", 1, 10, ".(5)");
}

TEST_CASE("lexer: malformed numbers") {
    CHECK_ERROR_HAS("x = 1e\n", 1, 5, "malformed number");
    CHECK_ERROR_HAS("x = 1e+\n", 1, 5, "malformed number");
    CHECK_ERROR_HAS("x = 12abc\n", 1, 5, "malformed number");
    CHECK_ERROR_HAS("print 1, 2.5x\n", 1, 10, "malformed number");
    CHECK(run_fail("x = 12abc\n").status == PRAY_ERR_SYNTAX);
}

TEST_CASE("lexer: invalid UTF-8 and control characters") {
    CHECK_ERROR("print 1 \xFF\n", 1, 9, "invalid UTF-8 byte 0xFF");
    CHECK_ERROR("print \"a\xFF\"\n", 1, 9, "invalid UTF-8 byte 0xFF");
    CHECK_ERROR_HAS("print 1 // \xFF\n", 1, 12, "invalid UTF-8");
    CHECK_ERROR_HAS("print 1 \xC0\xAF\n", 1, 9, "invalid UTF-8");  // overlong
    CHECK_ERROR_HAS("print \x80\n", 1, 7, "invalid UTF-8");        // lone continuation byte
    CHECK_ERROR_HAS("print \"\xE2\x82\"\n", 1, 8, "invalid UTF-8");  // truncated sequence
    CHECK_ERROR("print 1\x01\n", 1, 8, "control character (code 1) in the program");
    CHECK_ERROR("print \"a\x01\"\n", 1, 9, "control character (code 1) in the program");
    CHECK_ERROR_HAS("print 1 \x7F\n", 1, 9, "control character");
    CHECK_ERROR_HAS(std::string("print 1\0\n", 9), 1, 8, "control character (code 0)");
    CHECK_ERROR_HAS("print 1\nprint 2\x1B\n", 2, 8, "control character");
    // a tab is a blank
    CHECK_PRINTS("print\t1,\t2\n", "1 2\n");
}

TEST_CASE("lexer: a UTF-8 byte order mark is accepted") {
    CHECK_PRINTS("\xEF\xBB\xBFprint 1\n", "1\n");
    CHECK_PRINTS("\xEF\xBB\xBF// comment\nprint 2\n", "2\n");
    // the mark is not a column
    CHECK_ERROR("\xEF\xBB\xBFx = 1 & nothing\n", 1, 7, "cannot apply '&' to number and object");
}

TEST_CASE("lexer: names are case-sensitive; predefined words are reserved") {
    CHECK_PRINTS("Sphere = 2\nPI = 3\n_x1 = 4\nprint Sphere, PI, _x1\n", "2 3 4\n");
    CHECK_PRINTS("x = 1\nX = 2\nprint x, X\n", "1 2\n");
    CHECK_ERROR("x = 1\nprint X\n", 2, 7, "undefined variable 'X'; did you mean 'x'?");
}

// =============================================================================================
// Values and operators
// =============================================================================================

TEST_CASE("print formats of every type") {
    CHECK_PRINTS("print 1.5, [1, 2, 3], <1, 2, 3>, {0.5}, \"s\"\n", "1.5 [1, 2, 3] <1, 2, 3> {0.5, 0.5, 0.5} s\n");
    CHECK_PRINTS("print {0.25, 0.5, 1}, 1e20, 1/3, -0.5\n", "{0.25, 0.5, 1} 1e+20 0.333333 -0.5\n");
    CHECK_PRINTS("print true, false, pi\n", "1 0 3.14159\n");
    CHECK_PRINTS("M = color({1})\nprint sphere(M, [0,0,0], 1), nothing, M\n",
                 "object (1 primitive) object (0 primitives) model\n");
    CHECK_PRINTS("M = color({1})\nS = sphere(M, [0,0,0], 1)\nprint S | S, S | S | S\n",
                 "object (2 primitives) object (3 primitives)\n");
    CHECK_PRINTS("print dirlight({1}, <1,1,1>), none\n", "light (1 source) light (0 sources)\n");
    CHECK_PRINTS("print dirlight({1}, <1,1,1>) | pointlight({1}, [0,0,1])\n", "light (2 sources)\n");
    CHECK_PRINTS("print phong({0.8, 0.1, 0.1}, {0.3}, 3), mirror({0.3}), transparent({1}, 1.5)\n",
                 "model model model\n");
    CHECK_PRINTS("print\n", "\n");
    CHECK_PRINTS("print 1, 2, 3\nprint\nprint \"a\", \"b\"\n", "1 2 3\n\na b\n");
}

TEST_CASE("unary operators") {
    CHECK_PRINTS("print -3, +3, -(-3), --3, - 2\n", "-3 3 3 3 -2\n");
    CHECK_PRINTS("print -<1, 2, 3>, +<1, 2, 3>\n", "<-1, -2, -3> <1, 2, 3>\n");
    CHECK_PRINTS("print -{0.5, 0.25, 1}, +{1}\n", "{-0.5, -0.25, -1} {1, 1, 1}\n");
    // the complement of an object
    CHECK_PRINTS("M = color({1})\nS = sphere(M, [0,0,0], 1)\nprint -S, --S, -(S | S)\n",
                 "object (1 primitive) object (1 primitive) object (2 primitives)\n");
    CHECK_PRINTS("M = color({1})\nprint -nothing, -one(M)\n", "object (0 primitives) object (0 primitives)\n");
    CHECK_ERROR("x = -\"a\"\n", 1, 5, "cannot apply unary '-' to a string");
    CHECK_ERROR_HAS("x = -[1, 2, 3]\n", 1, 5, "point");
    CHECK_ERROR_HAS("x = -none\n", 1, 5, "light");
    CHECK_ERROR_HAS("x = +nothing\n", 1, 5, "object");
}

TEST_CASE("number arithmetic") {
    CHECK_PRINTS("print 2 + 3, 5 - 7, 2 * 3, 7 / 2, 2 ^ 0.5, 10 ^ -1\n", "5 -2 6 3.5 1.41421 0.1\n");
    CHECK_PRINTS("print 7 % 3, -7 % 3, 7.5 % 2, 5.5 % -2\n", "1 -1 1.5 1.5\n");
    CHECK_PRINTS("print 2 ^ 10, 4 ^ 0.5, 2 ^ -2\n", "1024 2 0.25\n");
    CHECK_PRINTS("print sqrt(16), abs(-3), log(1), exp(0), norm(<3, 0, 4>)\n", "4 3 0 1 <0.6, 0, 0.8>\n");
}

TEST_CASE("'^' is right-associative; the others are left-associative") {
    CHECK_PRINTS("print 2 ^ 3 ^ 2\n", "512\n");
    CHECK_PRINTS("print 2^3^2\n", "512\n");
    CHECK_PRINTS("print 8 / 2 / 2, 10 - 3 - 2, 100 % 7 % 3, 3 > 2 > 1\n", "2 5 2 0\n");
    CHECK_PRINTS("print [1,0,0] . [1,0,0] . <0,0,90>\n", "[0, 2, 0]\n");
}

TEST_CASE("operator priorities") {
    CHECK_PRINTS("print -2 ^ 2\n", "4\n");  // unary minus binds tightest
    CHECK_PRINTS("print -2^2, 2 ^ -1\n", "4 0.5\n");
    CHECK_PRINTS("print 1 + 2 * 3, (1 + 2) * 3\n", "7 9\n");
    CHECK_PRINTS("print 2 * 3 ^ 2, 2 ^ 3 * 2\n", "18 16\n");
    CHECK_PRINTS("print 1 + 2 = 3, 2 * 2 # 4\n", "1 0\n");
    // '.' (level 2) binds tighter than '*' (level 4): 2 * 3 . 2 is 2 * (3 . 2)
    CHECK_ERROR("print 2 * 3 . 2\n", 1, 13, "cannot apply '.' to number and number");
    CHECK_PRINTS("print <1,0,0> . <0,0,90> * 2\n", "<0, 2, 0>\n");
    CHECK_PRINTS("print <1,0,0> * <1,0,0> . <0,0,90>\n", "0\n");
    CHECK_PRINTS("print [1,0,0] . 2 + <1,0,0>\n", "[3, 0, 0]\n");
    // '&' below the comparisons, '|' and '\' below '&'
    CHECK_PRINTS("print 2 > 1 & 1 < 2, 2 > 1 & 1 > 2\n", "1 0\n");
    CHECK_PRINTS("print 1 | 2 & 0, 6 \\ 3 & 1\n", "1 7\n");
    CHECK_PRINTS("print 1 = 1 & 2 = 2\n", "1\n");
    // an assignment's '=' is not a comparison, the one in its expression is
    CHECK_PRINTS("x = 2 = 2\nprint x\n", "1\n");
}

TEST_CASE("comparisons give 1 or 0") {
    CHECK_PRINTS("print 1 < 2, 2 < 1, 1 > 2, 2 > 1\n", "1 0 0 1\n");
    CHECK_PRINTS("print 2 <= 2, 3 <= 2, 2 >= 2, 1 >= 2\n", "1 0 1 0\n");
    CHECK_PRINTS("print 3 = 3, 3 = 4, 3 == 3, 3 == 4\n", "1 0 1 0\n");
    CHECK_PRINTS("print 3 # 4, 3 # 3\n", "1 0\n");
    CHECK_PRINTS("print \"abc\" = \"abc\", \"abc\" == \"abd\", \"a\" # \"b\", \"a\" # \"a\"\n", "1 0 1 0\n");
    CHECK_PRINTS("print \"\" = \"\", \"a\" = \"a \"\n", "1 0\n");
    // '<' starts a vector only where an operand is expected
    CHECK_PRINTS("print 0 < <1,0,0> * <1,0,0>, 1 <2\n", "1 1\n");
    CHECK_PRINTS("print <1, 2, (3 > 2)>, [1, (2 < 3), 4]\n", "<1, 2, 1> [1, 1, 4]\n");
    CHECK_ERROR_HAS("print [1, 2 < 3, 4]\n", 1, 13, "parenthes");
}

TEST_CASE("bitwise '&', '|', '\\' on the integer parts of numbers") {
    CHECK_PRINTS("print 6 & 3, 6 | 3, 6 \\ 3\n", "2 7 5\n");
    CHECK_PRINTS("print 6 \xC2\xA5 3\n", "5\n");
    CHECK_PRINTS("print 6.9 & 3.9, 12 | 3, 7.5 \\ 2.2\n", "2 15 5\n");
    CHECK_PRINTS("print 1 & 0, 0 | 0, 1 | 0\n", "0 0 1\n");
}

TEST_CASE("strings: concatenation and comparison") {
    CHECK_PRINTS("print \"a\" + 1.5\n", "a1.5\n");
    CHECK_PRINTS("print \"a\" + \"b\", \"n\" + 2.5E+4, \"x\" + 1e-3, \"q\" + 1/3\n", "ab n25000 x0.001 q0.333333\n");
    CHECK_PRINTS("print \"frame\" + 1 + \".tif\"\n", "frame1.tif\n");
    CHECK_PRINTS("s = \"\"\ns = s + \"ab\"\ns = s + 2\nprint s\n", "ab2\n");
    CHECK_ERROR("print \"b\" < \"a\"\n", 1, 11, "cannot apply '<' to string and string");
    CHECK_ERROR("print \"a\" - \"b\"\n", 1, 11, "cannot apply '-' to string and string");
}

TEST_CASE("points and vectors") {
    CHECK_PRINTS("print [1,2,3] + <1,1,1>, [1,2,3] - <1,1,1>, [1,2,3] - [1,1,1]\n", "[2, 3, 4] [0, 1, 2] <0, 1, 2>\n");
    CHECK_PRINTS("print <1,2,3> + <1,1,1>, <1,2,3> - <1,1,1>\n", "<2, 3, 4> <0, 1, 2>\n");
    CHECK_PRINTS("print <1,2,3> * 2, 2 * <1,2,3>, <2,4,6> / 2\n", "<2, 4, 6> <2, 4, 6> <1, 2, 3>\n");
    CHECK_PRINTS("print <1,2,3> * <4,5,6>\n", "32\n");  // dot product
    CHECK_PRINTS("print <1,0,0> % <0,1,0>, <0,1,0> % <1,0,0>\n", "<0, 0, 1> <0, 0, -1>\n");  // cross product
    CHECK_PRINTS("a = 2\nb = 3\nc = 4\nprint <a, b + 1, 2 * c>\n", "<2, 4, 8>\n");
    CHECK_ERROR("print [1,2,3] + [1,2,3]\n", 1, 15, "cannot apply '+' to point and point");
    CHECK_ERROR("print [1,2,3] * 2\n", 1, 15, "cannot apply '*' to point and number");
}

TEST_CASE("intensities") {
    CHECK_PRINTS("print {0.5} + {0.25, 0.5, 1}, {1} - {0.25, 0.5, 0.75}\n", "{0.75, 1, 1.5} {0.75, 0.5, 0.25}\n");
    CHECK_PRINTS("print {0.5, 1, 2} * {2}, {0.5, 1, 2} * 2\n", "{1, 2, 4} {1, 2, 4}\n");
    CHECK_PRINTS("print {0.5, 1, 2} * {1, 0.5, 0.25}\n", "{0.5, 0.5, 0.5}\n");
    CHECK_ERROR_HAS("print {1, 2}\n", 1, 7, "1 or 3");
}

TEST_CASE("transformations of points and vectors") {
    CHECK_PRINTS("print [1,2,3] . 2, <1,2,3> . -1\n", "[2, 4, 6] <-1, -2, -3>\n");
    CHECK_PRINTS("print [1,2,3] . [1,1,1]\n", "[2, 3, 4]\n");
    CHECK_PRINTS("print <1,2,3> . [1,1,1]\n", "<1, 2, 3>\n");  // a vector is not translated
    CHECK_PRINTS("print [1,0,0] . <0,0,90>, [1,0,0] . <0,0,90> . [1,1,1]\n", "[0, 1, 0] [1, 2, 1]\n");
    CHECK_PRINTS("print [1,2,3] . <90,0,0>\n", "[1, -3, 2]\n");
    CHECK_PRINTS("print <1,0,0> . <0,0,45>\n", "<0.707107, 0.707107, 0>\n");
}

TEST_CASE("rotations are right-handed, X then Y then Z, exact at multiples of 90 degrees") {
    CHECK_PRINTS("print <1,0,0> . <0,0,90>\n", "<0, 1, 0>\n");
    CHECK_PRINTS("print <0,1,0> . <0,0,90>\n", "<-1, 0, 0>\n");
    CHECK_PRINTS("print <0,0,1> . <90,0,0>\n", "<0, -1, 0>\n");
    CHECK_PRINTS("print <0,1,0> . <90,0,0>\n", "<0, 0, 1>\n");
    CHECK_PRINTS("print <1,0,0> . <0,90,0>\n", "<0, 0, -1>\n");
    CHECK_PRINTS("print <0,0,1> . <0,90,0>\n", "<1, 0, 0>\n");
    CHECK_PRINTS("print <1,0,0> . <0,0,-90>, <1,0,0> . <0,0,270>\n", "<0, -1, 0> <0, -1, 0>\n");
    CHECK_PRINTS("print <1,0,0> . <0,0,450>, <1,2,3> . <0,0,360>\n", "<0, 1, 0> <1, 2, 3>\n");
    // the order: X first, then Y, then Z
    CHECK_PRINTS("print <1,0,0> . <90,90,0>\n", "<0, 0, -1>\n");
    CHECK_PRINTS("print <0,1,0> . <90,0,90>\n", "<0, 0, 1>\n");
    CHECK_PRINTS("print <1,0,0> . <0,90,90>\n", "<0, 0, -1>\n");
    CHECK_PRINTS("print <1,2,3> . <90,90,90>\n", "<3, 2, -1>\n");
}

TEST_CASE("rotations by multiples of 90 degrees leave no negative zero") {
    // A 0 that belongs in the result is printed as 0, not -0.
    CHECK_PRINTS("print <1,0,0> . <0,0,180>\n", "<-1, 0, 0>\n");
    CHECK_PRINTS("print <1,0,0> . <0,180,0>\n", "<-1, 0, 0>\n");
    CHECK_PRINTS("print <0,1,0> . <0,180,0>\n", "<0, 1, 0>\n");
    CHECK_PRINTS("print <-1,0,0> . <180,0,0>\n", "<-1, 0, 0>\n");
    CHECK_PRINTS("print <-1,0,0> . <0,-90,0>\n", "<0, 0, -1>\n");
    CHECK_PRINTS("print <0,0,-1> . <0,0,180>\n", "<0, 0, -1>\n");
    CHECK_PRINTS("print <0,0,-1> . <270,0,0>\n", "<0, -1, 0>\n");
}

TEST_CASE("transformations of objects and lights") {
    const std::string s = "M = color({1})\nS = sphere(M, [0,0,0], 1)\nL = dirlight({1}, <1,0,0>)\nP = pointlight({1}, [0,0,1])\n";
    CHECK_PRINTS(s + "print S . 2, S . [1,0,0], S . <0,0,90>, (S | S | S) . 2\n",
                 "object (1 primitive) object (1 primitive) object (1 primitive) object (3 primitives)\n");
    CHECK_PRINTS(s + "print L . [1,1,1], L . <0,0,90>, L . 2, (L | P) . [1,2,3]\n",
                 "light (1 source) light (1 source) light (1 source) light (2 sources)\n");
    CHECK_ERROR(s + "x = S . 0\n", 5, 7, "cannot scale by 0");
    CHECK_ERROR_HAS("x = [1,2,3] . 0\n", 1, 13, "scale");
    CHECK_ERROR(s + "x = S . \"a\"\n", 5, 7, "cannot apply '.' to object and string");
    CHECK_ERROR(s + "x = M . 2\n", 5, 7, "cannot apply '.' to model and number");
}

TEST_CASE("transformations move what is rendered") {
    // 3x3 pixels: the ray of the centre pixel runs along +Y from the default eye [0,-4,0].
    std::vector<std::string> o = {"width=3", "height=3"};
    auto centre = [&](const std::string &obj) {
        testkit::Result r = testkit::run("M = color({1})\nrendertiff " + obj + ", none\n", o);
        INFO(obj << ": " << r.error);
        REQUIRE(r.status == PRAY_OK);
        REQUIRE(r.frames.size() == 1);
        return r.frames[0].at(1, 1, 0);
    };
    auto corner = [&](const std::string &obj) {
        testkit::Result r = testkit::run("M = color({1})\nrendertiff " + obj + ", none\n", o);
        INFO(obj << ": " << r.error);
        REQUIRE(r.status == PRAY_OK);
        REQUIRE(r.frames.size() == 1);
        return r.frames[0].at(0, 0, 0);
    };
    CHECK(centre("sphere(M, [0,0,0], 0.5)") == 1.0f);
    CHECK(centre("sphere(M, [0,0,0], 0.5) . [10,0,0]") == 0.0f);
    CHECK(centre("sphere(M, [10,0,0], 0.5)") == 0.0f);
    CHECK(centre("sphere(M, [10,0,0], 0.5) . <0,0,90>") == 1.0f);
    CHECK(corner("sphere(M, [0,0,0], 0.1)") == 0.0f);
    CHECK(corner("sphere(M, [0,0,0], 0.1) . 10") == 1.0f);
}

TEST_CASE("models: '*' by a number or an intensity, '+' of two models") {
    CHECK_PRINTS("M = phong({1}, {0}, 1)\nprint M * 2, M * {1, 0, 0}, M + mirror({0.3}), M + M\n",
                 "model model model model\n");
    std::vector<std::string> o = {"width=3", "height=3"};
    auto colour = [&](const std::string &model, float r, float g, float b) {
        testkit::Result res = testkit::run("rendertiff sphere(" + model + ", [0,0,0], 1), none\n", o);
        INFO(model << ": " << res.error);
        REQUIRE(res.status == PRAY_OK);
        REQUIRE(res.frames.size() == 1);
        const testkit::Frame &f = res.frames[0];
        CHECK(f.at(1, 1, 0) == doctest::Approx(r));
        CHECK(f.at(1, 1, 1) == doctest::Approx(g));
        CHECK(f.at(1, 1, 2) == doctest::Approx(b));
    };
    colour("color({0.5, 0.25, 1})", 0.5f, 0.25f, 1.0f);
    colour("color({0.5, 0.25, 1}) * 2", 1.0f, 0.5f, 2.0f);
    colour("color({1}) * {0.5, 0.25, 1}", 0.5f, 0.25f, 1.0f);
    colour("color({0.25}) + color({0.5, 0, 0.25})", 0.75f, 0.25f, 0.5f);
    CHECK_ERROR("M = color({1})\nx = M * M\n", 2, 7, "cannot apply '*' to model and model");
}

TEST_CASE("objects: CSG operators") {
    const std::string s = "M = color({1})\nS = sphere(M, [0,0,0], 1)\nT = sphere(M, [1,0,0], 1)\n";
    CHECK_PRINTS(s + "print S | T, S & T, S \\ T, S \xC2\xA5 T\n",
                 "object (2 primitives) object (2 primitives) object (2 primitives) object (2 primitives)\n");
    CHECK_PRINTS(s + "print S + T, S - T, S * T, S % T\n",
                 "object (2 primitives) object (2 primitives) object (2 primitives) object (2 primitives)\n");
    // nothing is neutral for '|', one(M) for '&'
    CHECK_PRINTS(s + "print S | nothing, nothing | S, one(M) & S, S & one(M), one(M)\n",
                 "object (1 primitive) object (1 primitive) object (1 primitive) object (1 primitive) object (0 primitives)\n");
    // chains
    CHECK_PRINTS(s + "print S | T | S | T, S & T & S, S \\ T \\ S \\ T \\ S, (S | T) | (S | T)\n",
                 "object (4 primitives) object (3 primitives) object (5 primitives) object (4 primitives)\n");
    CHECK_PRINTS(
        "W = color({1})\n"
        "o1 = plane(W, [-0.1, 0, 0], <-1, 0, 0>)\no2 = plane(W, [0.1, 0, 0], <1, 0, 0>)\n"
        "o3 = plane(W, [0, -0.1, 0], <0, -1, 0>)\no4 = plane(W, [0, 0.1, 0], <0, 1, 0>)\n"
        "o5 = plane(W, [0, 0, -0.1], <0, 0, -1>)\no6 = plane(W, [0, 0, 0.1], <0, 0, 1>)\n"
        "Cube = o1&o2&o3&o4&o5&o6\n"
        "Cyl = cylinder(W, [0,0,0], <0,0,1>, 0.05) & plane(W, [0,0,0.15], <0,0,1>) & plane(W, [0,0,-0.15], <0,0,-1>)\n"
        "print Cube, Cyl, Cube | Cyl, Cube % Cyl\n",
        "object (6 primitives) object (3 primitives) object (9 primitives) object (9 primitives)\n");
    // the operands are not changed by building a chain from them
    CHECK_PRINTS(s + "A = S | T\nB = A | S\nC = A | T | T\nprint A, B, C\n",
                 "object (2 primitives) object (3 primitives) object (4 primitives)\n");
}

TEST_CASE("objects: a chain built in a loop is one node and fast") {
    const char *prog =
        "M = color({1})\n"
        "All = nothing\n"
        "i = 0\n"
        "while i < 1024\n"
        "  All = All | sphere(M, [i, 0, 0], 0.5)\n"
        "  i = i + 1\n"
        "endwhile\n"
        "print All\n";
    auto t0 = std::chrono::steady_clock::now();
    CHECK_PRINTS(prog, "object (1024 primitives)\n");
    double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    CHECK(secs < 2.0);
    // Long chains of every operation: a tree thousands of levels deep is not what they build.
    auto chain = [](const char *start, const char *op, int n) {
        return std::string("M = color({1})\nAll = ") + start + "\ni = 0\nwhile i < " + std::to_string(n) +
               "\n  All = All " + op + " sphere(M, [i, 0, 0], 0.5)\n  i = i + 1\nendwhile\nprint All\n";
    };
    CHECK_PRINTS(chain("nothing", "|", 5000), "object (5000 primitives)\n");
    CHECK_PRINTS(chain("one(M)", "&", 5000), "object (5000 primitives)\n");
    CHECK_PRINTS(chain("sphere(M, [0,0,0], 2)", "\\", 5000), "object (5001 primitives)\n");
    CHECK_PRINTS(chain("sphere(M, [0,0,0], 2)", "-", 5000), "object (5001 primitives)\n");
    CHECK_PRINTS(chain("nothing", "+", 5000), "object (5000 primitives)\n");
    // and it renders
    testkit::Result r = testkit::run(chain("nothing", "|", 3000) + "rendertiff All, none\n", {"width=4", "height=4"});
    INFO(r.error);
    CHECK(r.status == PRAY_OK);
    CHECK(r.frames.size() == 1);
}

TEST_CASE("long chains of every operator run with a flat stack") {
    // A chain is built and evaluated in a loop: before, 12000 terms overflowed the stack.
    auto chain = [](const std::string &head, const std::string &term, int n) {
        std::string p = "M = color({1})\nS = sphere(M, [0, 0, 0], 1)\nX = " + head;
        p.reserve(p.size() + term.size() * (size_t)n + 16);
        for (int i = 0; i < n; i++) p += term;
        return p + "\nprint X\n";
    };
    const std::vector<std::string> wide = {"maxline=1000000000"};
    auto prints = [&](const std::string &prog, const std::string &expected) {
        testkit::Result r = testkit::run(prog, wide);
        INFO(prog.substr(0, 120));
        CHECK(problem(r) == "");
        CHECK(r.printed == expected);
    };
    // a million terms: time and memory grow with the length only
    auto t0 = std::chrono::steady_clock::now();
    prints(chain("1", "+1", 1000000), "1e+06\n");
    CHECK(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() < 20.0);
    const int n = 100000;
    prints(chain("1", "-1", n), "-99999\n");
    for (const char *t : {"*1", "/1", "%2", "=1", "==1", "#0", "<2", ">0", "<=1", ">=1", "&1", "|0", "\\0"})
        prints(chain("1", t, n), "1\n");
    prints(chain("<1, 2, 3>", ".<0, 0, 0>", n), "<1, 2, 3>\n");
    prints(chain("<1, 2, 3>", " . 1", n), "<1, 2, 3>\n");
    prints(chain("[1, 2, 3]", "+<0, 0, 0>", n), "[1, 2, 3]\n");
    prints(chain("{0.5}", "*{1}", n), "{0.5, 0.5, 0.5}\n");
    prints(chain("\"a\"", "+\"\"", n), "a\n");
    for (const char *t : {"|S", "+S", "\\S", "-S", "%S"}) prints(chain("S", t, n), "object (100001 primitives)\n");
    for (const char *t : {"&S", "*S"}) prints(chain("S", t, n), "object (100001 primitives)\n");
    // mixed levels nest one chain in another, not one level per operator
    prints(chain("0", "+2*3-6", n), "0\n");
    // continued over lines of 1000 terms
    std::string cont = "X = 0";
    for (int line = 0; line < 100; line++) {
        cont += " \\\n";
        for (int i = 0; i < 1000; i++) cont += "+1";
    }
    prints(cont + "\nprint X\n", "100000\n");
    // an error at the end of a long chain names its operator
    std::string bad = "X = 1";
    for (int i = 0; i < n; i++) bad += "+1";
    Failure f = run_fail(bad + "+nothing+1\n", wide);
    CHECK(f.where() + " " + f.msg == where_is(1, 6 + 2 * n) + " cannot apply '+' to number and object");
    // '^' groups from the right and unary minus nests: both count as levels of maxnest
    std::string pow = "X = 1", neg = "X = ";
    for (int i = 0; i < 300; i++) pow += "^1", neg += "-";
    CHECK_ERROR(pow + "\n", 1, 518, "expression nested deeper than 256 levels (option maxnest)");
    CHECK_ERROR(neg + "1\n", 1, 261, "expression nested deeper than 256 levels (option maxnest)");
}

TEST_CASE("lights: '|' and '+' count sources; none has none") {
    const std::string s = "L = dirlight({1}, <1,1,1>)\nP = pointlight({1}, [0,0,1])\n";
    CHECK_PRINTS(s + "print L, P, none\n", "light (1 source) light (1 source) light (0 sources)\n");
    CHECK_PRINTS(s + "print L | P, L + P, L + P + L, L | P | L | P\n",
                 "light (2 sources) light (2 sources) light (3 sources) light (4 sources)\n");
    CHECK_PRINTS(s + "print none | L, L + none, none | none, none + none\n",
                 "light (1 source) light (1 source) light (0 sources) light (0 sources)\n");
    CHECK_PRINTS("print directionlight({1}, <1,1,1>)\n", "light (1 source)\n");
    CHECK_ERROR(s + "x = L & P\n", 3, 7, "cannot apply '&' to light and light");
}

TEST_CASE("type errors name both types and the operator's column") {
    const std::string s = "M = color({1})\nL = dirlight({1}, <1,1,1>)\n";
    CHECK_ERROR("x = 1 & nothing\n", 1, 7, "cannot apply '&' to number and object");
    CHECK_ERROR("x = nothing | 1\n", 1, 13, "cannot apply '|' to object and number");
    CHECK_ERROR("x = nothing \\ 2\n", 1, 13, "cannot apply '\\' to object and number");
    CHECK_ERROR("x = <1,2,3> * [1,2,3]\n", 1, 13, "cannot apply '*' to vector and point");
    CHECK_ERROR("x = {1} + <1,2,3>\n", 1, 9, "cannot apply '+' to intensity and vector");
    CHECK_ERROR("x = {1} * <1,1,1>\n", 1, 9, "cannot apply '*' to intensity and vector");
    CHECK_ERROR("x = none + nothing\n", 1, 10, "cannot apply '+' to light and object");
    CHECK_ERROR(s + "x = M + 1\n", 3, 7, "cannot apply '+' to model and number");
    CHECK_ERROR("x = 2 ^ <1,2,3>\n", 1, 7, "cannot apply '^' to number and vector");
    CHECK_ERROR("x = 1 / <1,2,3>\n", 1, 7, "cannot apply '/' to number and vector");
    CHECK_ERROR("x = 1 < \"a\"\n", 1, 7, "cannot apply '<' to number and string");
    CHECK_ERROR("x = nothing = nothing\n", 1, 13, "cannot apply '=' to object and object");
    CHECK_ERROR("x = 1 == \"1\"\n", 1, 7, "cannot apply '==' to number and string");
    CHECK_ERROR("x = 1 # [1,2,3]\n", 1, 7, "cannot apply '#' to number and point");
    CHECK_ERROR("x = \"a\" >= \"a\"\n", 1, 9, "cannot apply '>=' to string and string");
    CHECK_ERROR("x = 2 . 3\n", 1, 7, "cannot apply '.' to number and number");
    CHECK_ERROR("x = {1} % {1}\n", 1, 9, "cannot apply '%' to intensity and intensity");
    CHECK_ERROR("x = nothing * 2\n", 1, 13, "cannot apply '*' to object and number");
    CHECK_ERROR("x = \"a\" + nothing\n", 1, 9, "cannot apply '+' to string and object");
    CHECK_ERROR("x = \"a\" * 2\n", 1, 9, "cannot apply '*' to string and number");
    CHECK_ERROR("x = <1,2,3> + 1\n", 1, 13, "cannot apply '+' to vector and number");
    CHECK_ERROR(s + "x = L \\ L\n", 3, 7, "cannot apply '\\' to light and light");
    CHECK_ERROR("x = {1} - 1\n", 1, 9, "cannot apply '-' to intensity and number");
    CHECK_ERROR("x = 6 \xC2\xA5 nothing\n", 1, 7, "cannot apply '\\' to number and object");
    CHECK(run_fail("x = 1 & nothing\n").status == PRAY_ERR_RUNTIME);
}

// =============================================================================================
// Runtime errors
// =============================================================================================

TEST_CASE("runtime errors: arithmetic") {
    CHECK_ERROR("x = 1 / 0\n", 1, 7, "division by zero");
    CHECK_ERROR("print <1,2,3> / 0\n", 1, 15, "division by zero");
    CHECK_ERROR_HAS("x = 5 % 0\n", 1, 7, "division by zero");
    CHECK_ERROR_HAS("x = sqrt(-1)\n", 1, 5, "sqrt");
    CHECK_ERROR_HAS("x = log(-1)\n", 1, 5, "log");
    CHECK_ERROR_HAS("x = log(0)\n", 1, 5, "log");
    CHECK_ERROR_HAS("x = arcsin(2)\n", 1, 5, "arcsin");
    CHECK_ERROR("x = norm(<0,0,0>)\n", 1, 5, "norm of a zero vector");
    CHECK(run_fail("x = 1 / 0\n").status == PRAY_ERR_RUNTIME);
    // the program stops at the error, after what ran before it
    Failure f = run_fail("print 1\nprint 1 / 0\nprint 2\n");
    CHECK(f.printed == "1\n");
    CHECK(f.line == 2);
    CHECK(f.col == 9);
}

TEST_CASE("runtime errors: a result that is not finite, at the operator or call that made it") {
    CHECK_ERROR("x = 1 + 1e308 * 10 + 1\n", 1, 15, "1e+308 * 10 is not a finite number");
    CHECK_ERROR("x = 1e308 + 1e308\n", 1, 11, "1e+308 + 1e+308 is not a finite number");
    CHECK_ERROR("x = -1e308 - 1e308\n", 1, 12, "-1e+308 - 1e+308 is not a finite number");
    CHECK_ERROR("x = 1e300 / 1e-10\n", 1, 11, "1e+300 / 1e-10 is not a finite number");
    CHECK_ERROR("x = 10 ^ 400\n", 1, 8, "10 ^ 400 is not a finite number");
    CHECK_ERROR("x = 2 ^ 2 ^ 2 ^ 2 ^ 2\n", 1, 7, "2 ^ 65536 is not a finite number");
    CHECK_ERROR("x = exp(1000)\n", 1, 5, "exp(1000) is not a finite number");
    CHECK_ERROR("x = tan(1.5) * 1e308\n", 1, 14, "14.1014 * 1e+308 is not a finite number");
    CHECK_ERROR("x = abs(<1.7e308, 1.7e308, 0>)\n", 1, 5, "abs(<1.7e+308, 1.7e+308, 0>) is not a finite number");
    CHECK_ERROR("x = <1e308, 0, 0> + <1e308, 0, 0>\n", 1, 19, "<1e+308, 0, 0> + <1e+308, 0, 0> is not a finite vector");
    CHECK_ERROR("x = <1e308, 0, 0> - <-1e308, 0, 0>\n", 1, 19, "<1e+308, 0, 0> - <-1e+308, 0, 0> is not a finite vector");
    CHECK_ERROR("x = <1e200, 0, 0> * <1e200, 0, 0>\n", 1, 19, "<1e+200, 0, 0> * <1e+200, 0, 0> is not a finite number");
    CHECK_ERROR("x = <1e200, 0, 0> % <0, 1e200, 0>\n", 1, 19, "<1e+200, 0, 0> % <0, 1e+200, 0> is not a finite vector");
    CHECK_ERROR("x = <0, 1e300, 0> * 1e10\n", 1, 19, "<0, 1e+300, 0> * 1e+10 is not a finite vector");
    CHECK_ERROR("x = 1e10 * <0, 1e300, 0>\n", 1, 10, "1e+10 * <0, 1e+300, 0> is not a finite vector");
    CHECK_ERROR("x = <1, 1e308, 1> / 0.5\n", 1, 19, "<1, 1e+308, 1> / 0.5 is not a finite vector");
    CHECK_ERROR("x = [0, 1e308, 0] + <0, 1e308, 0>\n", 1, 19, "[0, 1e+308, 0] + <0, 1e+308, 0> is not a finite point");
    CHECK_ERROR("x = [1e300, 0, 0] . 1e300\n", 1, 19, "[1e+300, 0, 0] . 1e+300 is not a finite point");
    CHECK_ERROR("x = <1e300, 0, 0> . 1e300\n", 1, 19, "<1e+300, 0, 0> . 1e+300 is not a finite vector");
    CHECK_ERROR("x = {1e308} + {1e308}\n", 1, 13, "{1e+308, 1e+308, 1e+308} + {1e+308, 1e+308, 1e+308} is not a finite intensity");
    CHECK_ERROR("x = {1e308} * 10\n", 1, 13, "{1e+308, 1e+308, 1e+308} * 10 is not a finite intensity");
    CHECK_ERROR("x = {-1e308} - {1e308}\n", 1, 14, "{-1e+308, -1e+308, -1e+308} - {1e+308, 1e+308, 1e+308} is not a finite intensity");
    // so NaN never comes to be: inf - inf stops at the inf
    CHECK_ERROR("Inf = 1e308 * 10\nif Inf - Inf\n  print 1\nendif\n", 1, 13, "1e+308 * 10 is not a finite number");
    // models, lights and objects made from finite values by an operator
    CHECK_ERROR("M = color({10}) * 1e308\n", 1, 17, "model scale: the coefficients are not finite");
    CHECK_ERROR("M = 1e308 * color({10})\n", 1, 11, "model scale: the coefficients are not finite");
    CHECK_ERROR("M = color({1e308}) + color({1e308})\n", 1, 20, "model sum: the coefficients are not finite");
    CHECK_ERROR("L = pointlight({1}, [1e300, 0, 0]) . 1e300\n", 1, 36,
                "the transformation takes a light out of the range of numbers");
    CHECK_ERROR("L = dirlight({1}, <1, 0, 0>) . 1e-300 . 1e-300\n", 1, 39,
                "the transformation takes a light out of the range of numbers");
    CHECK_ERROR("M = color({1})\nS = sphere(M, [1e300, 0, 0], 1) . 1e300\n", 2, 33,
                "the transformation takes a primitive out of the range of numbers");
    // results up to the largest number stay as they are
    CHECK_PRINTS("print 1e308 + 7e307, -1e308 * 1.7, 1e-300 * 1e-300, 1e308 % 3 < 3, 2 ^ 1023 * 1.99\n",
                 "1.7e+308 -1.7e+308 0 1 1.7887e+308\n");
    CHECK_PRINTS("print <1e308, 0, 0> + <7e307, 0, 0>, abs(<1e308, 1e308, 0>), -<1.7e308, 0, 0>\n",
                 "<1.7e+308, 0, 0> 1.41421e+308 <-1.7e+308, 0, 0>\n");
}

TEST_CASE("the API still refuses the infinities and NaNs that programs can no longer make") {
    // bad inputs 091, 221-243, 253 and 261 reached these checks through 1e308*10 before overflow
    // became an error at the operator
    const double inf = HUGE_VAL, nan = HUGE_VAL - HUGE_VAL;
    const pray_vec o = {0, 0, 0}, z = {0, 0, 1}, far = {inf, 0, 0}, odd = {0, nan, 0};
    pray_ctx *c = pray_new();
    pray_model *m = pray_color(c, pray_rgb{1, 1, 1});
    auto refused = [&](const void *made, const std::string &message) {
        CHECK(made == nullptr);
        CHECK(std::string(pray_error(c)) == "error: " + message);
    };
    refused(pray_sphere(c, m, o, inf), "sphere: radius must be a positive number, not inf");
    refused(pray_sphere(c, m, o, nan), "sphere: radius must be a positive number, not nan");
    refused(pray_sphere(c, m, far, 1), "sphere: coordinates are not finite");
    refused(pray_cylinder(c, m, o, z, inf), "cylinder: radius must be a positive number, not inf");
    refused(pray_cylinder(c, m, o, pray_vec{0, 0, inf}, 1), "cylinder axis: coordinates are not finite");
    refused(pray_plane(c, m, odd, z), "plane: coordinates are not finite");
    refused(pray_dirlight(c, pray_rgb{inf, 1, 1}, z), "dirlight: intensity is not finite");
    refused(pray_pointlight(c, pray_rgb{1, 1, 1}, far), "pointlight: coordinates are not finite");
    refused(pray_phong(c, pray_rgb{1, 1, 1}, pray_rgb{1, 1, 1}, pray_rgb{0, 0, 0}, inf),
            "phong: exponent must be a number >= 0, not inf");
    refused(pray_phong(c, pray_rgb{inf, 1, 1}, pray_rgb{1, 1, 1}, pray_rgb{0, 0, 0}, 1), "phong: intensity is not finite");
    refused(pray_mirror(c, pray_rgb{inf, 1, 1}), "mirror: intensity is not finite");
    refused(pray_color(c, pray_rgb{nan, 1, 1}), "color: intensity is not finite");
    pray_object *s = pray_sphere(c, m, o, 1);
    REQUIRE(s);
    refused(pray_scale(c, s, inf), "scale factor must be a finite number other than 0, not inf");
    refused(pray_translate(c, s, far), "translation: coordinates are not finite");
    refused(pray_rotate(c, s, far), "rotation: coordinates are not finite");
    CHECK(pray_background(c, pray_rgb{inf, 1, 1}, pray_rgb{1, 1, 1}) == PRAY_ERR_ARG);
    CHECK(std::string(pray_error(c)) == "error: background: intensity is not finite");
    CHECK(pray_perspective(c, far, pray_vec{0, 0, -1}, pray_vec{0, -4, 0}, o) == PRAY_ERR_ARG);
    CHECK(std::string(pray_error(c)) == "error: perspective: coordinates are not finite");
    CHECK(pray_option(c, "width", nan) == PRAY_ERR_ARG);
    CHECK(std::string(pray_error(c)) == "error: option 'width': nan is out of range");
    pray_release(c, s);
    pray_release(c, m);
    pray_free(c);
}

TEST_CASE("runtime errors: derived values name the function and its argument") {
    const std::string m = "M = color({1})\n";
    CHECK_ERROR(m + "T = text(M, \"abc\", [0, 0, 0], <1, 0, 0>, <0, 0, 1>, 0.1, \"\", 1e308)\n", 2, 5,
                "text: X times the spacing 1e+308 takes character 3 out of the range of numbers");
    CHECK_ERROR(m + "T = text(M, \"a b\", [0, 0, 0], <1e15, 0, 0>, <0, 0, 1>, 0.1, \"\", 1e300)\n", 2, 5,
                "text: X times the spacing 1e+300 takes character 3 out of the range of numbers");
    // the axes themselves have the lengths of a texture map's vectors (narrower in single precision)
    std::string range = strstr(pray_features(), "real=float") ? "1e-18 and 1e+18" : "1e-150 and 1e+150";
    CHECK_ERROR(m + "T = text(M, \"ab\", [0, 0, 0], <1e308, 0, 0>, <0, 0, 1e308>, 0.1, \"\", 1)\n", 2, 5,
                "text: the vectors' lengths must lie between " + range);
    CHECK_ERROR(m + "T = text(M, \"ab\", [0, -1e308, 0], <1, 0, 0>, <0, 0, 1>, 1e308, \"\", 1)\n", 2, 5,
                "text: the thickness 1e+308 takes character 1 out of the range of numbers");
    // far, but in range
    CHECK_PRINTS(m + "T = text(M, \"ab\", [0, 0, 0], <1, 0, 0>, <0, 0, 1>, 0.1, \"\", 1e308)\nprint T\n",
                 "object (54 primitives)\n");
    // delete takes names, and a function or a constant is not one
    CHECK_ERROR("delete sphere\n", 1, 8, "'sphere' is a function, not a variable: only variables can be deleted");
    CHECK_ERROR("x = 1\ndelete x, pi\n", 2, 11, "'pi' is a reserved word, not a variable: only variables can be deleted");
    CHECK_ERROR("x = 1\ndelete x, cos(1)\n", 2, 11, "'cos' is a function, not a variable: only variables can be deleted");
    CHECK_ERROR("x = 1\ndelete x + sin\n", 2, 12, "'sin' is a function: write it with its arguments in parentheses");
    // an option name of any length is looked up, not cut
    char msg[300];
    std::string name(300, 'a'), opt = name + "=1";
    const char *opts[] = {opt.c_str()};
    CHECK(pray_render_file("examples/csg.ray", opts, 1, msg, sizeof msg) == PRAY_ERR_ARG);
    CHECK(std::string(msg) == "error: unknown option '" + name.substr(0, 60) + "...'");
}

TEST_CASE("runtime errors: undefined variables suggest a defined name") {
    CHECK_ERROR("Centre = [0,0,0]\nR = 1\nx = Center\n", 3, 5, "undefined variable 'Center'; did you mean 'Centre'?");
    CHECK_ERROR("Centre = [0,0,0]\nprint 1, Center\n", 2, 10, "undefined variable 'Center'; did you mean 'Centre'?");
    CHECK_ERROR("Alpha = 1\nprint Zeta\n", 2, 7, "undefined variable 'Zeta'");
    // a deleted name is not suggested
    CHECK_ERROR("Centre = 1\ndelete Centre\nprint Center\n", 3, 7, "undefined variable 'Center'");
    // an undefined name is only an error when it is read
    CHECK_PRINTS("if 0\nprint Undefined\nendif\nprint \"ok\"\n", "ok\n");
}

TEST_CASE("runtime errors: unknown functions suggest a builtin") {
    CHECK_ERROR("M = phono({1}, {1}, {1}, 3)\n", 1, 5, "unknown function 'phono'; did you mean 'phong'?");
    CHECK_ERROR_HAS("S = spere(M, [0,0,0], 1)\n", 1, 5, "did you mean 'sphere'?");
    CHECK_ERROR_HAS("x = 1\nprint x, sinn(1)\n", 2, 10, "unknown function 'sinn'");
    CHECK_ERROR_HAS("x = sphere\n", 1, 5, "function");
}

TEST_CASE("runtime errors: argument counts and types of functions") {
    CHECK_ERROR("M = color({1})\nS = sphere(M, <0,0,0>, 1)\n", 2, 15, "sphere: argument 2 must be a point, not a vector");
    CHECK_ERROR("S = sphere(1, [0,0,0], 1)\n", 1, 12, "sphere: argument 1 must be a model, not a number");
    CHECK_ERROR_HAS("M = phong({1}, {1})\n", 1, 5, "phong");
    CHECK_ERROR_HAS("M = phong({1}, {1}, {1}, {1}, 3)\n", 1, 5, "phong");
    CHECK_ERROR_HAS("M = color({1})\nx = sphere(M, [0,0,0])\n", 2, 5, "sphere");
    CHECK_ERROR_HAS("x = norm()\n", 1, 5, "norm");
    CHECK_ERROR("print norm(1)\n", 1, 12, "norm: argument 1 must be a vector, not a number");
    CHECK_ERROR("print sqrt(\"a\")\n", 1, 12, "sqrt: argument 1 must be a number, not a string");
    CHECK_ERROR("x = dirlight(<1,1,1>, <1,1,1>)\n", 1, 14, "dirlight: argument 1 must be an intensity, not a vector");
    CHECK_ERROR_HAS("x = phong({1}, {1}, \"e\")\n", 1, 21, "phong: argument 3");
    // phong with 3 and with 4 arguments
    CHECK_PRINTS("print phong({1}, {1}, 3), phong({1}, {1}, {0.1}, 3)\n", "model model\n");
}

TEST_CASE("phono is not a function but an ordinary name") {
    CHECK_PRINTS("phono = 1\nprint phono\n", "1\n");
    CHECK_ERROR_HAS("directionlight = 1\n", 1, 1, "reserved");  // the alias is predefined
}

TEST_CASE("the texture and text makers of the specification are functions") {
    const std::string m = "M = color({1})\n";
    CHECK_PRINTS(m + "print planemap(M, [0,0,0], <0,0,1>, <1,0,0>, <0,1,0>)\n", "object (1 primitive)\n");
    CHECK_PRINTS(m + "print spheremap(M, [0,0,0], 1, <0,0,1>, <1,0,0>)\n", "object (1 primitive)\n");
    CHECK_PRINTS(m + "print move(M, 0.5, 0.25)\n", "model\n");
    testkit::Result r = testkit::run(m + "print text(M, \"AB\", [0,0,0], <1,0,0>, <0,0,1>, 0.1, \"\", 1)\n");
    CHECK(problem(r) == "");
    CHECK(r.printed.compare(0, 8, "object (") == 0);
    // a missing texture file is a runtime error naming the statement's line and the file
    Failure f = run_fail(m + "T = tiff(M, M, \"no-such-texture.tif\")\nrendertiff sphere(T, [0,0,0], 1), none\n",
                         {"width=2", "height=2"});
    INFO(f.text);
    CHECK(f.status != PRAY_OK);
    CHECK((f.line == 2 || f.line == 3));
    CHECK(contains(f.msg, "no-such-texture.tif"));
    CHECK(f.frames == 0);
}

TEST_CASE("runtime errors: reserved words cannot be assigned") {
    CHECK_ERROR("sphere = 1\n", 1, 1, "'sphere' is a reserved word and cannot be assigned to");
    CHECK_ERROR("pi = 3\n", 1, 1, "'pi' is a reserved word and cannot be assigned to");
    CHECK_ERROR_HAS("true = 0\n", 1, 1, "reserved");
    CHECK_ERROR_HAS("nothing = 1\n", 1, 1, "reserved");
    CHECK_ERROR_HAS("if = 1\n", 1, 1, "reserved");
    CHECK_ERROR_HAS("then = 1\n", 1, 1, "reserved");
    CHECK_ERROR_HAS("print = 1\n", 1, 1, "reserved");
    CHECK_ERROR_HAS("x = 1\nrendertiff = 2\n", 2, 1, "reserved");
    CHECK_ERROR_HAS("x = then\n", 1, 5, "reserved");
    // nothing ran: the error is found before the program starts
    CHECK(run_fail("print 1\npi = 3\n").printed == "");
}

TEST_CASE("runtime errors: degenerate solids and transformations") {
    const std::string m = "M = color({1})\n";
    CHECK_ERROR_HAS(m + "S = sphere(M, [0,0,0], 0)\n", 2, 5, "radius");
    CHECK_ERROR_HAS(m + "S = sphere(M, [0,0,0], -1)\n", 2, 5, "radius");
    CHECK_ERROR_HAS(m + "S = cylinder(M, [0,0,0], <0,0,1>, -1)\n", 2, 5, "radius");
    CHECK_ERROR_HAS(m + "S = plane(M, [0,0,0], <0,0,0>)\n", 2, 5, "zero");
    CHECK_ERROR_HAS(m + "S = cylinder(M, [0,0,0], <0,0,0>, 1)\n", 2, 5, "zero");
    CHECK_ERROR(m + "S = sphere(M, [0,0,0], 1) . 0\n", 2, 27, "cannot scale by 0");
    CHECK(run_fail(m + "S = sphere(M, [0,0,0], 0)\n").status == PRAY_ERR_RUNTIME);
}

// =============================================================================================
// Statements
// =============================================================================================

TEST_CASE("assignment and reassignment with a new type") {
    CHECK_PRINTS("X = 12.36\nX = 2*X+5\nprint X\nX = \"Text\"\nprint X\nX = <1,2,3>\nprint X\n",
                 "29.72\nText\n<1, 2, 3>\n");
    CHECK_PRINTS("x = 1\ny = x\nx = 2\nprint x, y\n", "2 1\n");
    CHECK_ERROR_HAS("x = 1\nx\n", 2, 1, "statement");
}

TEST_CASE("delete") {
    CHECK_ERROR("x = 1\ndelete x\nprint x\n", 3, 7, "undefined variable 'x'");
    CHECK_ERROR("delete y\n", 1, 8, "undefined variable 'y'");
    CHECK_PRINTS("x = 1\ny = 2\ndelete x, y\nprint 1\n", "1\n");
    CHECK_PRINTS("x = 1\ndelete x\nx = \"again\"\nprint x\n", "again\n");
    CHECK_ERROR_HAS("x = 1\ndelete x, x\n", 2, 11, "undefined variable 'x'");
    CHECK_ERROR_HAS("delete 1\n", 1, 8, "variable");
}

TEST_CASE("print writes its values separated by blanks") {
    CHECK_PRINTS("print 1, \"a\", <1, 2, 3>\n", "1 a <1, 2, 3>\n");
    CHECK_PRINTS("print\nprint\n", "\n\n");
    CHECK_PRINTS("print \"a\"\nprint\nprint \"b\"\n", "a\n\nb\n");
}

TEST_CASE("if, else, endif") {
    CHECK_PRINTS("if 1 then\nprint 1\nelse\nprint 2\nendif\n", "1\n");
    CHECK_PRINTS("if 0\nprint 1\nelse\nprint 2\nendif\n", "2\n");
    CHECK_PRINTS("if 0 then\nprint 1\nendif\nprint 3\n", "3\n");
    CHECK_PRINTS("if 2 > 1\nprint \"yes\"\nendif\n", "yes\n");
    CHECK_PRINTS("if -0.5\nprint \"nonzero is true\"\nendif\n", "nonzero is true\n");
    CHECK_PRINTS("x = 1\nif x = 1 & 2 > 1 then\nprint \"and\"\nendif\n", "and\n");
    CHECK_PRINTS("if 1\nendif\nprint \"empty block\"\n", "empty block\n");
    CHECK_ERROR_HAS("if \"a\"\nendif\n", 1, 4, "number");
}

TEST_CASE("nested blocks and while") {
    CHECK_PRINTS("i = 0\nwhile i < 3\nprint i\ni = i + 1\nendwhile\n", "0\n1\n2\n");
    CHECK_PRINTS("while 0\nprint 1\nendwhile\nprint 2\n", "2\n");
    CHECK_PRINTS(
        "i = 0\n"
        "while i < 4\n"
        "  if i % 2 = 0 then\n"
        "    if i = 0\n"
        "      print \"zero\"\n"
        "    else\n"
        "      print \"even\", i\n"
        "    endif\n"
        "  else\n"
        "    print \"odd\", i\n"
        "  endif\n"
        "  i = i + 1\n"
        "endwhile\n",
        "zero\nodd 1\neven 2\nodd 3\n");
    CHECK_PRINTS(
        "i = 0\nn = 0\n"
        "while i < 3\n"
        "  j = 0\n"
        "  while j < 4\n"
        "    n = n + 1\n"
        "    j = j + 1\n"
        "  endwhile\n"
        "  i = i + 1\n"
        "endwhile\n"
        "print n\n",
        "12\n");
}

TEST_CASE("quit ends the program with success") {
    testkit::Result r = testkit::run("print 1\nquit\nprint 2\n");
    CHECK(r.status == PRAY_OK);
    CHECK(r.error == "");
    CHECK(r.printed == "1\n");
    r = testkit::run(
        "i = 0\nwhile 1\n  i = i + 1\n  if i = 3\n    quit\n  endif\n  print i\nendwhile\nprint \"after\"\n");
    CHECK(r.status == PRAY_OK);
    CHECK(r.printed == "1\n2\n");
    r = testkit::run("quit\nrendertiff nothing, none\n", {"width=2", "height=2"});
    CHECK(r.status == PRAY_OK);
    CHECK(r.frames.empty());
}

TEST_CASE("background") {
    std::vector<std::string> o = {"width=4", "height=3"};
    testkit::Result r = testkit::run("rendertiff nothing, none\n", o);
    REQUIRE(r.status == PRAY_OK);
    REQUIRE(r.frames.size() == 1);
    CHECK(frame_is(r.frames[0], 0, 0, 0));  // the default background is {0}
    r = testkit::run("background {0.25, 0.5, 0.75}\nrendertiff nothing, none\n", o);
    REQUIRE(r.status == PRAY_OK);
    REQUIRE(r.frames.size() == 1);
    CHECK(frame_is(r.frames[0], 0.25f, 0.5f, 0.75f));
    CHECK(r.frames[0].at(1, 1, 0) == 0.25f);
    r = testkit::run("background {1, 0, 0}, {0, 0, 1}\nrendertiff nothing, none\n", o);
    REQUIRE(r.status == PRAY_OK);
    REQUIRE(r.frames.size() == 1);
    const testkit::Frame &f = r.frames[0];
    for (int x = 0; x < 4; x++) {
        CHECK(f.at(x, 0, 0) == doctest::Approx(1.0));  // top row: the first intensity
        CHECK(f.at(x, 0, 2) == doctest::Approx(0.0));
        CHECK(f.at(x, 2, 0) == doctest::Approx(0.0));  // bottom row: the second
        CHECK(f.at(x, 2, 2) == doctest::Approx(1.0));
    }
    CHECK_ERROR_HAS("background 1\n", 1, 12, "number");
    CHECK_ERROR_HAS("background {1}, 2\n", 1, 17, "number");
    CHECK_ERROR_HAS("background {1}, {0}, {1}\n", 1, 1, "background");
    CHECK_ERROR_HAS("background\n", 1, 11, "background");
}

TEST_CASE("perspective and parallel: argument types and degenerate cameras") {
    CHECK_PRINTS("perspective <1,0,0>, <0,0,-1>, [0,-4,0], [0,0,0]\nparallel <1,0,0>, <0,0,-1>, [0,-4,0], [0,0,0]\nprint 1\n",
                 "1\n");
    CHECK_ERROR_HAS("perspective [1,0,0], <0,0,-1>, [0,-4,0], [0,0,0]\n", 1, 13, "point");
    CHECK_ERROR_HAS("perspective <1,0,0>, 1, [0,-4,0], [0,0,0]\n", 1, 22, "number");
    CHECK_ERROR_HAS("perspective <1,0,0>, <0,0,-1>, <0,-4,0>, [0,0,0]\n", 1, 32, "vector");
    CHECK_ERROR_HAS("parallel <1,0,0>, <0,0,-1>, [0,-4,0], 5\n", 1, 39, "number");
    CHECK_ERROR_HAS("perspective <1,0,0>, <0,0,-1>, [0,-4,0]\n", 1, 1, "perspective");
    CHECK_ERROR_LINE("print 0\nperspective <0,0,0>, <0,0,-1>, [0,-4,0], [0,0,0]\n", 2, "zero");
    CHECK_ERROR_LINE("print 0\nperspective <1,0,0>, <2,0,0>, [0,-4,0], [0,0,0]\n", 2, "parallel");
    CHECK_ERROR_LINE("print 0\nperspective <1,0,0>, <0,0,-1>, [1,2,3], [1,2,3]\n", 2, "eye");
    CHECK_ERROR_LINE("print 0\nparallel <1,0,0>, <0,0,0>, [0,-4,0], [0,0,0]\n", 2, "zero");
    CHECK_ERROR_LINE("print 0\nparallel <1,0,0>, <-3,0,0>, [0,-4,0], [0,0,0]\n", 2, "parallel");
    CHECK_ERROR_LINE("print 0\nparallel <1,0,0>, <0,0,-1>, [0,0,0], [0,0,0]\n", 2, "eye");
}

TEST_CASE("option: names and values") {
    CHECK_PRINTS(
        "option \"width\", 16\noption \"height\", 16\noption \"depth\", 5\noption \"antialias\", 2\n"
        "option \"adaptive\", 0.1\noption \"grid\", 0\noption \"grid\", 8\noption \"freeze\", 0\n"
        "option \"merge\", 1\noption \"bounds\", 1\noption \"shadows\", 0\noption \"threads\", 0\n"
        "option \"maxsteps\", 100\noption \"output\", \"x.tif\"\noption \"bits\", 16\nprint \"ok\"\n",
        "ok\n");
    CHECK_ERROR_LINE("print 0\noption \"widht\", 10\n", 2, "unknown option 'widht'; did you mean 'width'?");
    CHECK_ERROR_LINE("option \"shadow\", 1\n", 1, "did you mean 'shadows'?");
    CHECK_ERROR_LINE("option \"zzzzzzzz\", 1\n", 1, "unknown option 'zzzzzzzz'");
    CHECK_ERROR_LINE("option \"width\", 0\n", 1, "width");
    CHECK_ERROR_LINE("option \"height\", -5\n", 1, "height");
    CHECK_ERROR_LINE("option \"width\", 1.5\n", 1, "width");
    CHECK_ERROR_LINE("option \"antialias\", 0\n", 1, "antialias");
    CHECK_ERROR_LINE("option \"shadows\", 2\n", 1, "shadows");
    CHECK_ERROR_LINE("option \"merge\", -1\n", 1, "merge");
    CHECK_ERROR_LINE("option \"bits\", 12\n", 1, "bits");
    CHECK_ERROR_LINE("option \"output\", 5\n", 1, "output");
    CHECK_ERROR_LINE("option \"width\", \"wide\"\n", 1, "width");
    CHECK_ERROR_LINE("option 1, 2\n", 1, "string");
    CHECK(run_fail("option \"widht\", 10\n").status == PRAY_ERR_RUNTIME);
}

TEST_CASE("maxsteps stops an endless loop with an error naming the line") {
    Failure f = run_fail("option \"maxsteps\", 1000\nwhile 1\nx = 1\nendwhile\n");
    INFO(f.text);
    CHECK(f.status == PRAY_ERR_LIMIT);
    CHECK(f.formatted);
    CHECK((f.line == 2 || f.line == 3));
    CHECK(contains(f.msg, "maxsteps"));
    f = run_fail("while 1\nendwhile\n", {"maxsteps=1000"});
    CHECK(f.status == PRAY_ERR_LIMIT);
    CHECK(f.line == 1);
    CHECK(contains(f.msg, "maxsteps"));
    // a program under the limit runs
    CHECK_PRINTS("option \"maxsteps\", 1000\ni = 0\nwhile i < 10\ni = i + 1\nendwhile\nprint i\n", "10\n");
}

TEST_CASE("options fixed by the host win over option statements") {
    testkit::Result r = testkit::run("option \"width\", 16\noption \"height\", 16\nrendertiff nothing, none\n", {"width=8"});
    INFO(r.error);
    REQUIRE(r.status == PRAY_OK);
    REQUIRE(r.frames.size() == 1);
    CHECK(r.frames[0].width == 8);
    CHECK(r.frames[0].height == 16);
    r = testkit::run("option \"output\", \"prog.tif\"\nrendertiff nothing, none\n", {"width=2", "height=2", "output=host.ppm"});
    REQUIRE(r.frames.size() == 1);
    CHECK(r.frames[0].name == "host.ppm");
}

TEST_CASE("a program without rendertiff only prints") {
    testkit::Result r = testkit::run("x = 2\nprint x * 21\n");
    CHECK(r.status == PRAY_OK);
    CHECK(r.printed == "42\n");
    CHECK(r.frames.empty());
    CHECK(r.error == "");
}

TEST_CASE("syntax errors are reported before anything runs") {
    Failure f = run_fail("print 1\nprint 2\nx = (\n");
    CHECK(f.status == PRAY_ERR_SYNTAX);
    CHECK(f.printed == "");
    CHECK(f.line == 3);
    CHECK(f.col == 6);
    f = run_fail("print 1\nrendertiff nothing, none\nprint 1 2\n", {"width=2", "height=2"});
    CHECK(f.printed == "");
    CHECK(f.frames == 0);
    CHECK(f.line == 3);
    CHECK(f.col == 9);
    CHECK_ERROR_HAS("print (1\n", 1, 9, "')'");
    CHECK_ERROR_HAS("print 1)\n", 1, 8, "end of line");
    CHECK_ERROR_HAS("print 1,\n", 1, 9, "value");
    CHECK_ERROR_HAS("prnt 1\n", 1, 1, "'print'");
    CHECK_ERROR_HAS("print 1 != 2\n", 1, 9, "#");
    CHECK_ERROR_HAS("print 1 ; print 2\n", 1, 9, ";");
}

TEST_CASE("blocks: missing and stray endif, else, endwhile") {
    CHECK_ERROR_HAS("if 1\nprint 1\n", 1, 1, "endif");
    CHECK_ERROR_HAS("if 1\nprint 1\nelse\nprint 2\n", 1, 1, "endif");
    CHECK_ERROR_HAS("while 1\nprint 1\n", 1, 1, "endwhile");
    CHECK_ERROR_HAS("print 1\nendif\n", 2, 1, "endif");
    CHECK_ERROR_HAS("print 1\nelse\nprint 2\n", 2, 1, "else");
    CHECK_ERROR_HAS("endwhile\n", 1, 1, "endwhile");
    CHECK_ERROR_HAS("if 1\nprint 1\nendwhile\n", 3, 1, "endwhile");
    CHECK_ERROR_HAS("while 1\nprint 1\nendif\n", 3, 1, "endif");
    CHECK_ERROR_HAS("if 1\nelse\nelse\nendif\n", 3, 1, "else");
    CHECK_ERROR_HAS("while 1\nelse\nendwhile\n", 2, 1, "else");
    CHECK_ERROR_HAS("if\nendif\n", 1, 3, "condition");
    CHECK(run_fail("print 1\nif 1\nprint 2\n").printed == "");
}

// =============================================================================================
// rendertiff frames
// =============================================================================================

TEST_CASE("rendertiff: frame names and sizes") {
    std::vector<std::string> o = {"width=4", "height=2"};
    testkit::Result r = testkit::run("rendertiff nothing, none\nrendertiff nothing, none\nrendertiff nothing\n", o);
    INFO(r.error);
    REQUIRE(r.status == PRAY_OK);
    REQUIRE(r.frames.size() == 3);
    CHECK(r.frames[0].name == "test.tif");
    CHECK(r.frames[1].name == "test_0001.tif");
    CHECK(r.frames[2].name == "test_0002.tif");
    CHECK(r.frames[0].width == 4);
    CHECK(r.frames[0].height == 2);
    r = testkit::run("rendertiff nothing, none\n", o, "scene.ray");
    REQUIRE(r.frames.size() == 1);
    CHECK(r.frames[0].name == "scene.tif");
    r = testkit::run("option \"output\", \"anim###.ppm\"\nrendertiff nothing, none\nrendertiff nothing, none\n", o);
    REQUIRE(r.frames.size() == 2);
    CHECK(r.frames[0].name == "anim000.ppm");
    CHECK(r.frames[1].name == "anim001.ppm");
    r = testkit::run("rendertiff nothing, none\nrendertiff nothing, none\n", {"width=2", "height=2", "output=out.ppm"});
    REQUIRE(r.frames.size() == 2);
    CHECK(r.frames[0].name == "out.ppm");
    CHECK(r.frames[1].name == "out_0001.ppm");
    r = testkit::run("rendertiff nothing, none\n", o, "prog");
    REQUIRE(r.frames.size() == 1);
    CHECK(r.frames[0].name == "prog.tif");
    r = testkit::run("rendertiff nothing, none\n", o, "dir.v2/prog");
    REQUIRE(r.frames.size() == 1);
    CHECK(r.frames[0].name == "dir.v2/prog.tif");
    r = testkit::run("option \"output\", \"a#.ppm\"\nrendertiff nothing, none\nrendertiff nothing, none\n", o);
    REQUIRE(r.frames.size() == 2);
    CHECK(r.frames[0].name == "a0.ppm");
    CHECK(r.frames[1].name == "a1.ppm");
    r = testkit::run("option \"width\", 5\noption \"height\", 3\nrendertiff nothing, none\n");
    REQUIRE(r.frames.size() == 1);
    CHECK(r.frames[0].width == 5);
    CHECK(r.frames[0].height == 3);
    CHECK(r.frames[0].pixels.size() == 5u * 3u * 3u);
    // frames in a loop
    r = testkit::run("i = 0\nwhile i < 3\nrendertiff nothing, none\ni = i + 1\nendwhile\n", o);
    REQUIRE(r.frames.size() == 3);
    CHECK(r.frames[2].name == "test_0002.tif");
}

TEST_CASE("rendertiff: arguments") {
    std::vector<std::string> o = {"width=2", "height=2"};
    testkit::Result r = testkit::run("background {0.5}\nrendertiff nothing, none\n", o);
    REQUIRE(r.frames.size() == 1);
    CHECK(frame_is(r.frames[0], 0.5f, 0.5f, 0.5f));
    r = testkit::run("L = dirlight({1}, <1,1,1>)\nrendertiff nothing, L, none, L | L\n", o);
    CHECK(r.status == PRAY_OK);
    CHECK(r.frames.size() == 1);
    Failure f = run_fail("print 0\nrendertiff nothing, 1\n", o);
    CHECK(f.line == 2);
    CHECK(f.col == 21);
    CHECK(contains(f.msg, "light"));
    CHECK(f.frames == 0);
    f = run_fail("rendertiff nothing, none, {1}\n", o);
    CHECK(f.col == 27);
    CHECK(contains(f.msg, "light"));
    f = run_fail("rendertiff 1, none\n", o);
    CHECK(f.col == 12);
    CHECK(contains(f.msg, "object"));
    f = run_fail("rendertiff dirlight({1}, <1,1,1>)\n", o);
    CHECK(f.formatted);
    CHECK(contains(f.msg, "object"));
}

TEST_CASE("the default camera looks along +Y from [0,-4,0] with Z up") {
    // 3x3 pixels: a small sphere above the view centre shows in the top middle pixel only.
    testkit::Result r = testkit::run("rendertiff sphere(color({1}), [0, 0, 0.75], 0.25), none\n", {"width=3", "height=3"});
    INFO(r.error);
    REQUIRE(r.status == PRAY_OK);
    REQUIRE(r.frames.size() == 1);
    const testkit::Frame &f = r.frames[0];
    CHECK(f.at(1, 0, 0) == 1.0f);
    CHECK(f.at(1, 1, 0) == 0.0f);
    CHECK(f.at(1, 2, 0) == 0.0f);
    CHECK(f.at(0, 0, 0) == 0.0f);
    CHECK(f.at(2, 0, 0) == 0.0f);
}

// =============================================================================================
// The sample programs
// =============================================================================================

TEST_CASE("the thesis' red sphere as printed fails on line 5 and suggests Centre") {
    std::string text = read_text("examples/redsphx.ray");
    REQUIRE(!text.empty());
    Failure f = run_fail(text, {}, "redsphx.ray");
    INFO(f.text);
    CHECK(f.status == PRAY_ERR_RUNTIME);
    CHECK(f.formatted);
    CHECK(f.line == 5);
    CHECK(f.col == 29);
    CHECK(f.msg == "undefined variable 'Center'; did you mean 'Centre'?");
    CHECK(f.frames == 0);
    // the same through pray_run_file: the path names the program
    pray_ctx *c = pray_new();
    std::vector<testkit::Frame> frames;
    pray_set_frame(c, testkit::frame_sink, &frames);
    CHECK(pray_run_file(c, "examples/redsphx.ray") == PRAY_ERR_RUNTIME);
    CHECK(std::string(pray_error(c)) ==
          "examples/redsphx.ray:5:29: error: undefined variable 'Center'; did you mean 'Centre'?");
    CHECK(frames.empty());
    CHECK(pray_frames(c) == 0);
    pray_free(c);
}

TEST_CASE("the corrected red sphere renders one frame") {
    pray_ctx *c = pray_new();
    std::vector<testkit::Frame> frames;
    pray_set_frame(c, testkit::frame_sink, &frames);
    pray_status st = pray_run_file(c, "examples/redsph.ray");
    INFO(pray_error(c));
    CHECK(st == PRAY_OK);
    CHECK(pray_frames(c) == 1);
    REQUIRE(frames.size() == 1);
    CHECK(frames[0].name == "examples/redsph.tif");
    CHECK(frames[0].width == 256);
    CHECK(frames[0].height == 256);
    // the centre of the image is the lit red sphere
    float r = frames[0].at(128, 128, 0), g = frames[0].at(128, 128, 1), b = frames[0].at(128, 128, 2);
    CHECK(r > 0.1f);
    CHECK(r > 2 * g);
    CHECK(r > 2 * b);
    CHECK(frames[0].at(0, 0, 0) == 0.0f);  // the default background
    pray_free(c);
}

TEST_CASE("CSG.RAY of the thesis runs unchanged and renders one frame") {
    std::string text = read_text("examples/csg.ray");
    REQUIRE(!text.empty());
    CHECK(contains(text, "Dif = Cube%Cylinder"));
    testkit::Result r = testkit::run(text, {"width=64", "height=64"}, "csg.ray");
    INFO(r.error);
    CHECK(r.status == PRAY_OK);
    REQUIRE(r.frames.size() == 1);
    CHECK(r.frames[0].name == "csg.tif");
    CHECK(r.frames[0].width == 64);
    CHECK(r.frames[0].height == 64);
    bool lit = false;
    for (float v : r.frames[0].pixels) lit = lit || v > 0.05f;
    CHECK(lit);
}

// =============================================================================================
// Error message format
// =============================================================================================

TEST_CASE("every error starts with name:line:col: error: ") {
    const char *programs[] = {
        "x = 1 &\n",                          // syntax
        "x = 1 & nothing\n",                  // type
        "print Undefined\n",                  // undefined variable
        "x = \"abc\n",                        // lexer
        "print 1 \\",                         // continuation
        "option \"nope\", 1\n",               // option
        "x = 1 / 0\n",                        // arithmetic
        "x = sphere(color({1}), [0,0,0], 0)\n",  // API error
        "perspective <1,0,0>, <1,0,0>, [0,-4,0], [0,0,0]\n",
        "rendertiff 1\n",
        "if 1\n",
        "endif\n",
    };
    for (const char *p : programs) {
        for (const char *name : {"test.ray", "my scene.ray", "dir/x.ray"}) {
            Failure f = run_fail(p, {"maxsteps=1000"}, name);
            INFO("program: " << p);
            INFO("error: " << f.text);
            CHECK(f.status != PRAY_OK);
            CHECK((f.formatted && f.line >= 1 && f.col >= 1 && !f.msg.empty()));
        }
    }
    // a successful run leaves no message
    CHECK(testkit::run("print 1\n").error == "");
}

// ---------------------------------------------------------------------------------------------
// Language version 2: box, rod, cone, torus, stretch.
// ---------------------------------------------------------------------------------------------
namespace {
// A white solid (its own light) on black, seen from eye E towards the origin, 96 x 72 pixels;
// every length multiplied by `s`.
std::vector<bool> silhouette(const std::string &solid, double s = 1, int *count = nullptr) {
    char cam[400];
    std::snprintf(cam, sizeof cam,
                  "option \"width\", 96\noption \"height\", 72\nS = %.17g\n"
                  "perspective <2.4 * S, 0, 0>, <0, 0, -1.8 * S>, [0.3 * S, -7 * S, 0.2 * S], [0, 0, 0]\n"
                  "M = color({1})\n",
                  s);
    testkit::Result r = testkit::run(std::string(cam) + "rendertiff (" + solid + ") . S, dirlight({1}, <0, 1, 0>)\n");
    std::vector<bool> m;
    if (r.status != PRAY_OK || r.frames.empty()) {
        FAIL_CHECK(r.error);
        return m;
    }
    const testkit::Frame &f = r.frames[0];
    int n = 0;
    for (int y = 0; y < f.height; y++)
        for (int x = 0; x < f.width; x++) {
            m.push_back(f.at(x, y, 0) > 0.5f);
            n += m.back();
        }
    if (count) *count = n;
    return m;
}
int differing(const std::vector<bool> &a, const std::vector<bool> &b) {
    int n = 0;
    for (size_t i = 0; i < a.size() && i < b.size(); i++) n += a[i] != b[i];
    return a.size() == b.size() ? n : 1 << 30;
}
} // namespace

TEST_CASE("version 2: box, rod, cone and torus are one primitive each; stretch keeps the count") {
    const std::string m = "M = color({1})\n";
    CHECK_PRINTS(m + "print box(M, [0, 0, 0], [1, 2, 3]), rod(M, [0, 0, 0], [0, 0, 1], 1)\n",
                 "object (1 primitive) object (1 primitive)\n");
    CHECK_PRINTS(m + "print cone(M, [0, 0, 0], 1, [0, 0, 1], 0), torus(M, [0, 0, 0], <0, 0, 1>, 1, 0.5)\n",
                 "object (1 primitive) object (1 primitive)\n");
    CHECK_PRINTS(m + "print stretch(sphere(M, [0, 0, 0], 1) | plane(M, [0, 0, 0], <1, 1, 0>), <1, 2, -3>)\n",
                 "object (2 primitives)\n");
}

TEST_CASE("version 2: a box, a rod and a cone look as the solids they stand for") {
    int n = 0;
    // corners in any order
    std::vector<bool> box = silhouette("box(M, [-1, -0.5, -0.7], [0.8, 0.6, 0.9])", 1, &n);
    CHECK(n > 500);
    CHECK(differing(box, silhouette("box(M, [0.8, -0.5, 0.9], [-1, 0.6, -0.7])")) == 0);
    std::vector<bool> planes = silhouette(
        "plane(M, [-1, 0, 0], <-1, 0, 0>) & plane(M, [0.8, 0, 0], <1, 0, 0>) & plane(M, [0, -0.5, 0], <0, -1, 0>) & "
        "plane(M, [0, 0.6, 0], <0, 1, 0>) & plane(M, [0, 0, -0.7], <0, 0, -1>) & plane(M, [0, 0, 0.9], <0, 0, 1>)");
    CHECK(differing(box, planes) <= 2);
    std::vector<bool> rod = silhouette("rod(M, [-0.5, -0.2, -0.6], [0.7, 0.4, 0.8], 0.4)", 1, &n);
    CHECK(n > 300);
    std::vector<bool> capped = silhouette(
        "cylinder(M, [-0.5, -0.2, -0.6], <1.2, 0.6, 1.4>, 0.4) & plane(M, [0.7, 0.4, 0.8], <1.2, 0.6, 1.4>) & "
        "plane(M, [-0.5, -0.2, -0.6], <-1.2, -0.6, -1.4>)");
    CHECK(differing(rod, capped) <= 4);
    // a cone with equal radii is a rod; a pointed one is smaller than its frustum
    CHECK(differing(rod, silhouette("cone(M, [-0.5, -0.2, -0.6], 0.4, [0.7, 0.4, 0.8], 0.4)")) <= 4);
    int pointed = 0, frustum = 0;
    silhouette("cone(M, [0, 0, -1], 0.8, [0, 0, 1], 0)", 1, &pointed);
    silhouette("cone(M, [0, 0, -1], 0.8, [0, 0, 1], 0.3)", 1, &frustum);
    CHECK(pointed > 200);
    CHECK(pointed < frustum);
}

TEST_CASE("version 2: stretch mirrors without turning normals in, and keeps boxes and half-spaces exact") {
    // a ball and a box symmetric about the origin, mirrored: the same picture, lit the same way
    const std::string lit = "option \"width\", 48\noption \"height\", 36\n"
                            "perspective <2.4, 0, 0>, <0, 0, -1.8>, [0.3, -7, 0.2], [0, 0, 0]\n"
                            "M = phong({0.8, 0.3, 0.1}, {0.4}, {0.1}, 20)\n";
    for (const char *solid : {"sphere(M, [0, 0, 0], 1)", "box(M, [-1, -1, -1], [1, 1, 1])",
                              "torus(M, [0, 0, 0], <0, 0, 1>, 1, 0.4)"}) {
        testkit::Result a = testkit::run(lit + "rendertiff " + solid + ", dirlight({1}, <1, 2, -1>)\n");
        testkit::Result b = testkit::run(lit + "rendertiff stretch(" + solid + ", <-1, 1, -1>), dirlight({1}, <1, 2, -1>)\n");
        REQUIRE(a.status == PRAY_OK);
        REQUIRE(b.status == PRAY_OK);
        double worst = 0;
        for (size_t i = 0; i < a.frames[0].pixels.size(); i++)
            worst = std::max(worst, (double)std::fabs(a.frames[0].pixels[i] - b.frames[0].pixels[i]));
        INFO(solid);
        CHECK(worst < 1e-3);
    }
    // a stretched ball is the ellipsoid; a stretched box the box of the stretched corners; a
    // stretched slab the slab between the stretched planes
    CHECK(differing(silhouette("stretch(sphere(M, [0, 0, 0], 0.5), <2, 1.5, 0.8>)"),
                    silhouette("stretch(sphere(M, [0, 0, 0], 0.5), <-2, 1.5, -0.8>)")) <= 2);
    CHECK(differing(silhouette("stretch(box(M, [-0.5, -0.5, -0.5], [0.5, 0.25, 0.5]), <2, -1, 1.5>)"),
                    silhouette("box(M, [-1, -0.25, -0.75], [1, 0.5, 0.75])")) == 0);
    CHECK(differing(silhouette("stretch(plane(M, [0, 0, 0.5], <0, 1, 1>) & plane(M, [0, 0, -0.5], <0, -1, -1>) & "
                               "sphere(M, [0, 0, 0], 1.2), <1, 1, 1>)"),
                    silhouette("plane(M, [0, 0, 0.5], <0, 1, 1>) & plane(M, [0, 0, -0.5], <0, -1, -1>) & "
                               "sphere(M, [0, 0, 0], 1.2)")) == 0);
    int ell = 0, ball = 0;
    silhouette("stretch(sphere(M, [0, 0, 0], 0.5), <2, 1, 1>)", 1, &ell);
    silhouette("sphere(M, [0, 0, 0], 0.5)", 1, &ball);
    CHECK(std::fabs(ell - 2.0 * ball) < 0.06 * ball);  // twice as wide, as high
}

TEST_CASE("version 2: a torus looks the same from 1e-4 to 1e5 of its size") {
    const std::string solid = "torus(M, [0.1, 0, 0], <0.2, 0.5, 1>, 1, 0.3) - torus(M, [0.1, 0, 0], <0, 0, 1>, 1, 0.25) . [0.9, 0, 0]";
    int n = 0;
    std::vector<bool> unit = silhouette(solid, 1, &n);
    CHECK(n > 400);
    for (double s : {1e-4, 1e-2, 1e3, 1e5}) {
        INFO("scale " << s);
        CHECK(differing(unit, silhouette(solid, s)) <= 3);
    }
}

TEST_CASE("version 2: the API refuses infinities, NaNs and degenerate sizes of the new makers") {
    const double inf = HUGE_VAL, nan = HUGE_VAL - HUGE_VAL;
    const pray_vec o = {0, 0, 0}, z = {0, 0, 1}, far = {inf, 0, 0}, odd = {0, nan, 0};
    pray_ctx *c = pray_new();
    pray_model *m = pray_color(c, pray_rgb{1, 1, 1});
    auto refused = [&](const void *made, const std::string &message) {
        CHECK(made == nullptr);
        CHECK(std::string(pray_error(c)) == "error: " + message);
    };
    refused(pray_box(c, m, o, far), "box: coordinates are not finite");
    refused(pray_box(c, m, odd, z), "box: coordinates are not finite");
    refused(pray_box(c, m, o, pray_vec{1, 1, 0}), "box: the corners must differ in every coordinate (both have z = 0)");
    refused(pray_rod(c, m, o, z, nan), "rod: radius must be a positive number, not nan");
    refused(pray_rod(c, m, o, far, 1), "rod: coordinates are not finite");
    refused(pray_cone(c, m, o, inf, z, 1), "cone: the radii must be numbers >= 0, not both 0, not inf and 1");
    refused(pray_cone(c, m, o, 1, z, nan), "cone: the radii must be numbers >= 0, not both 0, not 1 and nan");
    refused(pray_torus(c, m, o, z, inf, 1), "torus: the radii must be numbers with R > r > 0, not R = inf and r = 1");
    refused(pray_torus(c, m, o, z, 1, nan), "torus: the radii must be numbers with R > r > 0, not R = 1 and r = nan");
    refused(pray_torus(c, m, o, odd, 1, 0.5), "torus axis: coordinates are not finite");
    pray_object *s = pray_sphere(c, m, o, 1);
    REQUIRE(s);
    refused(pray_stretch(c, s, far), "stretch: coordinates are not finite");
    refused(pray_stretch(c, s, pray_vec{1, nan, 1}), "stretch: coordinates are not finite");
    refused(pray_stretch(c, s, pray_vec{1, 1, 0}), "stretch: the factors must not be 0, not <1, 1, 0>");
    // (frames stay within what the renderer's precision holds)
    const double big = std::strstr(pray_features(), "real=float") ? 1e25 : 1e200;
    pray_object *e = pray_stretch(c, s, pray_vec{big, 1, 1});
    REQUIRE(e);
    refused(pray_scale(c, e, big), "the transformation takes a primitive out of the range of numbers");
    pray_release(c, e);
    pray_release(c, s);
    pray_release(c, m);
    pray_free(c);
}

TEST_CASE("version 2: a box's texture coordinates are a planemap's at its first corner, and stretch carries both alike") {
    // a 2 x 2 checker, seen straight from above: the top face of the box against a planemap
    // through the first corner's X and Y, at the box's top, cutting a taller box
    auto render = [](const std::string &solid) {
        pray_ctx *c = pray_new();
        float rgb[12] = {0, 0, 0, 1, 1, 1, 1, 1, 1, 0, 0, 0};
        pray_texture *t = pray_texture_rgb(c, 2, 2, rgb, "checker");
        REQUIRE(pray_texture_register(c, "checker", t) == PRAY_OK);
        pray_release(c, t);
        std::vector<testkit::Frame> frames;
        pray_set_frame(c, testkit::frame_sink, &frames);
        std::string prog = "option \"width\", 64\noption \"height\", 64\n"
                           "parallel <2, 0, 0>, <0, -2, 0>, [0.1, 0.1, 9], [0.1, 0.1, 0]\n"
                           "T = tiff(color({0.1}), color({0.9}), \"checker\")\nG = color({0.5})\n"
                           "rendertiff " + solid + ", none\n";
        pray_status st = pray_run_string(c, "tex.ray", prog.data(), prog.size());
        CHECK_MESSAGE(st == PRAY_OK, pray_error(c));
        pray_free(c);
        return frames.empty() ? testkit::Frame() : frames[0];
    };
    const std::string box = "box(T, [-0.7, 0.6, 0.5], [0.9, -0.4, -0.3])";
    const std::string map = "(planemap(T, [-0.7, 0.6, 0.5], <0, 0, 1>, <1, 0, 0>, <0, 1, 0>) & box(G, [-0.7, -0.4, -0.3], [0.9, 0.6, 2]))";
    for (const char *how : {"", " . <0, 0, 30>", " . 0.5", " . [0.3, -0.2, 0]"}) {
        for (const char *st : {"", "<2, 1.5, 1>", "<-1.2, 0.7, 1>"}) {
            auto wrap = [&](const std::string &o) {
                std::string x = *st ? "stretch(" + o + ", " + st + ")" : o;
                return "(" + x + how + ")";
            };
            testkit::Frame a = render(wrap(box)), b = render(wrap(map));
            REQUIRE(a.width == 64);
            REQUIRE(b.width == 64);
            int differ = 0, textured = 0;
            for (int i = 0; i < 64 * 64; i++) {
                float va = a.pixels[3 * i], vb = b.pixels[3 * i];
                textured += va > 0.05f && va < 0.95f;
                differ += std::fabs(va - vb) > 1e-4f;
            }
            INFO("stretch " << std::string(st) << ", then" << std::string(how));
            CHECK(textured > 40);
            CHECK(differ <= (*st || *how ? 12 : 0));  // (pixels on the checker's edges, by rounding)
        }
    }
}
