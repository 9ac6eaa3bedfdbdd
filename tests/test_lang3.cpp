// Tests of version 3 of the PRAY language (section 12 of the language notes; the manual's
// "Procedures", "elseif", "paint", "spotlight" and "checker"): the scopes of procedures, their
// depth bound, elseif chains, paint against the same object built with the model, a spotlight's
// light against its formula at chosen angles, and checkered surfaces whose every pixel is one of
// two colours, the one the cell of the hit point has, however the object is moved, turned or
// stretched, under every acceleration setting.
#include <doctest/doctest.h>

#include "testkit.hpp"

#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

namespace {

using testkit::Frame;
using testkit::vec;

bool has(const std::string &s, const std::string &part) { return s.find(part) != std::string::npos; }

std::string num(long k) { return std::to_string(k); }

} // namespace

TEST_CASE("procedures: a body reads globals, never changes them; its assignments and parameters are its own") {
    const char *prog = "X = 1\n"
                       "Y = 10\n"
                       "define F(a)\n"
                       "  X = a\n"           // a local X from here
                       "  return X + Y\n"    // Y: the global
                       "enddefine\n"
                       "print F(5), X\n"
                       "Z = 7\n"
                       "define G()\n"
                       "  print Z\n"         // no local Z yet: the global
                       "  Z = 3\n"
                       "  print Z\n"
                       "  return Z\n"
                       "enddefine\n"
                       "print G(), Z\n"
                       "define H(X)\n"       // a parameter shadows the global
                       "  delete X\n"
                       "  return X\n"        // deleted: the global again
                       "enddefine\n"
                       "print H(99)\n";
    CHECK(testkit::printed(prog) == "15 1\n7\n3\n3 7\n1\n");
}

TEST_CASE("procedures: recursion, values of every type, calls as statements, return from loops") {
    const char *prog = "define Fact(n)\n"
                       "  if n <= 1\n"
                       "    return 1\n"
                       "  endif\n"
                       "  return n * Fact(n - 1)\n"
                       "enddefine\n"
                       "define First(n)\n"   // return ends the loop and the call
                       "  i = 0\n"
                       "  while true\n"
                       "    if i * i > n\n"
                       "      return i\n"
                       "    endif\n"
                       "    i = i + 1\n"
                       "  endwhile\n"
                       "enddefine\n"
                       "define Pair(s, p)\n"
                       "  print s, p\n"
                       "enddefine\n"
                       "define Ball(M, P)\n"
                       "  return sphere(M, P, 1) | sphere(M, P + <2, 0, 0>, 1)\n"
                       "enddefine\n"
                       "print Fact(10), First(50)\n"
                       "Pair(\"at\", [1, 2, 3])\n"
                       "print Ball(color({1}), [0, 0, 0]) | Ball(color({0}), [0, 5, 0])\n";
    CHECK(testkit::printed(prog) == "3.6288e+06 8\nat [1, 2, 3]\nobject (4 primitives)\n");
}

TEST_CASE("procedures: the depth bound counts calls with blocks and expressions, to the bound and one past it") {
    // Each call is one level, plus the expression it stands in; a body as deep as its deepest
    // block or expression: here 1. So with maxnest N, F(N - 2) makes N - 1 nested calls and fits.
    const std::string body = "define F(n)\n"
                             "  if n == 0\n"
                             "    return 0\n"
                             "  endif\n"
                             "  return F(n - 1) + 1\n"
                             "enddefine\n";
    for (int n : {10, 64, 256}) {
        testkit::Result ok = testkit::run(body + "print F(" + num(n - 2) + ")\n", {"maxnest=" + num(n)});
        CHECK_MESSAGE(ok.status == PRAY_OK, ok.error);
        CHECK(ok.printed == num(n - 2) + "\n");
        testkit::Result over = testkit::run(body + "print F(" + num(n - 1) + ")\n", {"maxnest=" + num(n)});
        CHECK(over.status == PRAY_ERR_LIMIT);
        CHECK(has(over.error, "test.ray:5:10: error: calls nested deeper than " + num(n) + " levels"));
        CHECK(has(over.error, "(option maxnest) (called from test.ray:5:10, "));
    }
}

TEST_CASE("procedures: statements in bodies count against maxsteps; an error names every call") {
    testkit::Result r = testkit::run("define F(n)\n"
                                     "  i = 0\n"
                                     "  while i < n\n"
                                     "    i = i + 1\n"
                                     "  endwhile\n"
                                     "  return i\n"
                                     "enddefine\n"
                                     "print F(100)\n"
                                     "print F(1000)\n",
                                     {"maxsteps=500"});
    CHECK(r.status == PRAY_ERR_LIMIT);
    CHECK(r.printed == "100\n");
    CHECK(has(r.error, "(option maxsteps) (called from test.ray:9:7)"));
    CHECK(testkit::error_of("define A(x)\n  return sqrt(x)\nenddefine\ndefine B(x)\n  return A(x - 5)\nenddefine\n"
                            "print B(2)\n") ==
          "test.ray:2:10: error: sqrt of the negative number -3 (called from test.ray:5:10, called from test.ray:7:7)");
}

TEST_CASE("procedures: what is refused, before anything runs") {
    struct Case {
        const char *prog, *error;
    } cases[] = {
        {"print 1\nprint F(2)\ndefine G(a)\n  return a\nenddefine\n", "test.ray:2:7: error: unknown function 'F'; did you mean 'G'?"},
        {"define F(a, b)\n  return a\nenddefine\nprint 1\nprint F(1)\n", "test.ray:5:7: error: F takes 2 arguments, not 1"},
        {"print 1\ndefine F(a)\n  return a\nenddefine\ndefine F(b)\n  return b\nenddefine\n",
         "test.ray:5:8: error: 'F' is defined twice (first at test.ray:2:1)"},
        {"print 1\nwhile false\n  define F()\n    return 1\n  enddefine\nendwhile\n",
         "test.ray:3:3: error: 'define' stands only at the top level of a file, not inside a block"},
        {"print 1\nF = 2\ndefine F()\n  return 1\nenddefine\n",
         "test.ray:3:8: error: 'F' is the name of a variable and cannot be defined as a procedure"},
        {"print 1\ndefine F()\n  return 1\nenddefine\nF = 2\n", "test.ray:5:1: error: 'F' is a procedure and cannot be assigned to"},
        {"print 1\ndefine F()\n  return 1\n", "test.ray:2:1: error: 'define' without 'enddefine'"},
        {"print 1\nreturn 2\n", "test.ray:2:1: error: 'return' outside the body of a procedure"},
        {"print 1\ndefine F()\n  include \"a.ray\"\nenddefine\n",
         "test.ray:3:3: error: 'include' is not allowed in the body of a procedure"},
        {"print 1\nX = 2\nif X == 1\nelseif\nendif\n", "test.ray:4:7: error: 'elseif' needs a condition"},
    };
    for (const Case &k : cases) {
        testkit::Result r = testkit::run(k.prog);
        CHECK(r.status != PRAY_OK);
        CHECK(r.printed == "");  // (nothing ran)
        CHECK(r.error == k.error);
    }
    // A call before the define has run, found as it runs
    testkit::Result r = testkit::run("print 1\nprint F(2)\ndefine F(a)\n  return a\nenddefine\n");
    CHECK(r.printed == "1\n");
    CHECK(r.error == "test.ray:2:7: error: unknown function 'F' (a procedure is known once its define has run)");
    CHECK(testkit::error_of("define F(a)\n  print a\nenddefine\nX = F(1)\n") == "test.ray:4:5: error: F returned no value");
}

TEST_CASE("procedures: quit in a body ends the run there") {
    testkit::Result r = testkit::run("define F()\n  print 1\n  quit\nenddefine\nprint 2 + F()\nprint 3\n");
    CHECK(r.status == PRAY_OK);
    CHECK(r.printed == "1\n");
}

TEST_CASE("elseif: the first true branch runs, else the else; a chain of 20 000 is a loop") {
    std::string prog = "define Name(k)\n"
                       "  if k == 1\n    return \"one\"\n"
                       "  elseif k == 2\n    return \"two\"\n"
                       "  elseif k == 2\n    return \"again\"\n"
                       "  else\n    return \"many\"\n"
                       "  endif\n"
                       "enddefine\n"
                       "print Name(1), Name(2), Name(7)\n";
    CHECK(testkit::printed(prog) == "one two many\n");
    std::string chain = "X = 19999\nif X == 0\n  print 0\n";
    for (int i = 1; i < 20000; i++) chain += "elseif X == " + num(i) + "\n  print " + num(i) + "\n";
    chain += "endif\n";
    CHECK(testkit::printed(chain) == "19999\n");
}

TEST_CASE("procedures: 1000 calls that build an object, against the same program written out") {
    std::string written = "All = nothing\n", called = "define Cell(i)\n  return sphere(color({1}), [i, 0, 0], 0.4) | "
                                                        "box(color({1}), [i, 1, 0], [i + 0.5, 1.5, 0.5])\nenddefine\nAll = nothing\n";
    for (int i = 0; i < 1000; i++) {
        written += "All = All | sphere(color({1}), [" + num(i) + ", 0, 0], 0.4) | box(color({1}), [" + num(i) + ", 1, 0], [" +
                   num(i) + " + 0.5, 1.5, 0.5])\n";
        called += "All = All | Cell(" + num(i) + ")\n";
    }
    written += "print All\n";
    called += "print All\n";
    CHECK(testkit::printed(written) == "object (2000 primitives)\n");
    CHECK(testkit::printed(called) == "object (2000 primitives)\n");
}

// ---- paint ----
namespace {

// A program's first frame at 48 x 36, rendered on a context with a 4 x 4 texture "tex" registered.
Frame textured_frame(const std::string &prog) {
    pray_ctx *c = pray_new();
    std::vector<float> px;
    for (int i = 0; i < 16; i++) px.insert(px.end(), {(float)(i % 4) / 3, (float)(i / 4) / 3, (float)(i % 3) / 2});
    pray_texture *t = pray_texture_rgb(c, 4, 4, px.data(), "tex");
    REQUIRE(pray_texture_register(c, "tex", t) == PRAY_OK);
    pray_texture_release(c, t);
    std::vector<Frame> frames;
    pray_option(c, "width", 48);
    pray_option(c, "height", 36);
    pray_set_frame(c, testkit::frame_sink, &frames);
    pray_status st = pray_run_string(c, "paint.ray", prog.data(), prog.size());
    REQUIRE_MESSAGE(st == PRAY_OK, pray_error(c));
    pray_free(c);
    REQUIRE(frames.size() == 1);
    return frames[0];
}

const char *PAINT_SCENE = "lookat [4, -7, 5], [0, 0, 0.5], <0, 0, 1>, 40\n"
                          "L = pointlight({0.9}, [3, -4, 8]) + dirlight({0.3}, <1, 2, -3>)\n"
                          "Tex = tiff(phong({0.9, 0.3, 0.2}, {0.4}, {0.1}, 20), phong({0.2, 0.4, 0.9}, {0.2}, {0.05}, 8), \"tex\")\n"
                          "Plain = color({0.5})\n"
                          "define Thing(M)\n"
                          "  S = sphere(M, [0, 0, 1], 1.2) | box(M, [-2, -1, 0], [2, 1, 0.8])\n"
                          "  return (S \\ rod(M, [0, -3, 0.5], [0, 3, 0.5], 0.4)) & cone(M, [0, 0, -1], 3, [0, 0, 3], 1)\n"
                          "enddefine\n";

} // namespace

TEST_CASE("paint: a CSG tree painted with a textured model is the tree built with it, moved or not") {
    std::string base = PAINT_SCENE;
    Frame built = textured_frame(base + "rendertiff Thing(Tex) . <0, 0, 20> . [0.3, 0, 0], L\n");
    Frame painted = textured_frame(base + "rendertiff paint(Thing(Plain) . <0, 0, 20> . [0.3, 0, 0], Tex), L\n");
    CHECK(built.pixels == painted.pixels);
    Frame plain = textured_frame(base + "rendertiff Thing(Plain) . <0, 0, 20> . [0.3, 0, 0], L\n");
    CHECK(built.pixels != plain.pixels);  // (the texture shows)
    // painting twice: the last paint wins
    Frame twice = textured_frame(base + "rendertiff paint(paint(Thing(Tex), Plain), Tex) . <0, 0, 20> . [0.3, 0, 0], L\n");
    CHECK(twice.pixels == built.pixels);
}

// ---- spotlight ----
namespace {

// The share of a spotlight's intensity at angle a (degrees) off its axis, from the manual.
double spot_share(double a, double a1, double a2) {
    if (a <= a1) return 1;
    if (a >= a2) return 0;
    double t = (a2 - a) / (a2 - a1);
    return t * t * (3 - 2 * t);
}

} // namespace

TEST_CASE("spotlight: the light on a floor is I x share(angle) x cos, at every pixel, for soft and sharp edges") {
    const double PI = 3.14159265358979323846;
    const double tol = std::strstr(pray_features(), "real=float") ? 2e-5 : 1e-6;  // (a float buffer)
    struct Spot {
        double a1, a2;
    } spots[] = {{15, 35}, {25, 25}, {0, 40}};
    for (const Spot &sp : spots) {
        pray_ctx *c = pray_new();
        const int W = 64, H = 48;
        pray_option(c, "width", W);
        pray_option(c, "height", H);
        pray_option(c, "adaptive", 0);
        REQUIRE(pray_lookat(c, vec(0, -6, 9), vec(0, 0.5, 0), vec(0, 0, 1), 60) == PRAY_OK);
        pray_rgb white = {1, 1, 1}, none = {0, 0, 0}, in = {0.8, 0.6, 0.4};
        pray_model *m = pray_phong(c, white, none, none, 1);
        pray_object *floor = pray_plane(c, m, vec(0, 0, 0), vec(0, 0, 1));
        pray_vec P = vec(0.5, 0, 4), D = vec(0.2, 0.3, -1);
        pray_light *l = pray_spotlight(c, in, P, D, sp.a1, sp.a2);
        REQUIRE(l);
        std::vector<float> rgb(W * H * 3);
        pray_buffers out = {rgb.data(), nullptr, nullptr, nullptr, 0, nullptr, nullptr, 0};
        REQUIRE_MESSAGE(pray_render_into(c, floor, l, nullptr, &out) == PRAY_OK, pray_error(c));
        int zones[3] = {0, 0, 0};
        double dl = std::sqrt(D.x * D.x + D.y * D.y + D.z * D.z);
        for (int y = 0; y < H; y++)
            for (int x = 0; x < W; x++) {
                pray_vec o, d;
                REQUIRE(pray_camera_ray(c, x + 0.5, y + 0.5, &o, &d) == PRAY_OK);
                if (!(d.z < 0)) continue;
                double t = -o.z / d.z;
                pray_vec h = vec(o.x + t * d.x, o.y + t * d.y, 0), v = vec(h.x - P.x, h.y - P.y, h.z - P.z);
                double lv = std::sqrt(v.x * v.x + v.y * v.y + v.z * v.z);
                double ca = (v.x * D.x + v.y * D.y + v.z * D.z) / (lv * dl);
                double angle = std::acos(std::max(-1.0, std::min(1.0, ca))) * 180 / PI;
                if (std::fabs(angle - sp.a1) < 0.01 || std::fabs(angle - sp.a2) < 0.01) continue;  // (at an edge)
                double share = spot_share(angle, sp.a1, sp.a2), cosi = -v.z / lv;
                zones[angle <= sp.a1 ? 0 : angle >= sp.a2 ? 2 : 1]++;
                const float *px = &rgb[(y * W + x) * 3];
                CHECK(std::fabs(px[0] - in.r * share * cosi) <= tol);
                CHECK(std::fabs(px[1] - in.g * share * cosi) <= tol);
                CHECK(std::fabs(px[2] - in.b * share * cosi) <= tol);
            }
        CHECK((zones[0] > 50) == (sp.a1 > 5));
        CHECK(zones[2] > 50);
        CHECK((zones[1] > 50) == (sp.a1 < sp.a2));
        pray_free(c);
    }
}

TEST_CASE("spotlight: moved and turned as a light: its position and its direction") {
    const char *scene = "lookat [0, -6, 6], [0, 0, 0], <0, 0, 1>, 50\n"
                        "F = plane(phong({1}, {0}, {0}, 1), [0, 0, 0], <0, 0, 1>)\n";
    testkit::Result a = testkit::run(std::string(scene) + "rendertiff F, spotlight({1}, [1, 0, 3], <0, 0, -1>, 10, 20)\n",
                                     {"width=40", "height=30"});
    testkit::Result b = testkit::run(std::string(scene) + "rendertiff F, spotlight({1}, [-3, 0, 0], <3, 0, 0>, 10, 20) . <0, 90, 0> . [1, 0, 0]\n",
                                     {"width=40", "height=30"});
    REQUIRE(a.frames.size() == 1);
    REQUIRE(b.frames.size() == 1);
    double most = 0;
    for (size_t i = 0; i < a.frames[0].pixels.size(); i++) most = std::max(most, std::fabs((double)a.frames[0].pixels[i] - b.frames[0].pixels[i]));
    CHECK(most < 1e-4);
}

// ---- checker ----
namespace {

struct Setting {
    const char *name;
    double value;
};
const Setting SETTINGS[] = {{"brute", 0}, {"brute", 1}, {"grid", 0}, {"grid", 1}, {"grid", 7}, {"grid", 40},
                            {"freeze", 0}, {"merge", 0}, {"bounds", 0}, {"nest", 0}, {"plans", 0}};

// A placement of the checkered solid: what it does to the solid, and its inverse on points.
struct Placement {
    const char *name;
    pray_vec rot, move, stretch;  // stretch first, then turn (X, then Y, then Z), then move
};

pray_vec rotate_axis(pray_vec p, int axis, double deg) {
    double a = deg * 3.14159265358979323846 / 180, c = std::cos(a), s = std::sin(a);
    if (axis == 0) return vec(p.x, c * p.y - s * p.z, s * p.y + c * p.z);
    if (axis == 1) return vec(c * p.x + s * p.z, p.y, -s * p.x + c * p.z);
    return vec(c * p.x - s * p.y, s * p.x + c * p.y, p.z);
}

// A world point back in the coordinates the solid was made in.
pray_vec unplace(const Placement &pl, pray_vec p) {
    p = vec(p.x - pl.move.x, p.y - pl.move.y, p.z - pl.move.z);
    p = rotate_axis(p, 2, -pl.rot.z);
    p = rotate_axis(p, 1, -pl.rot.y);
    p = rotate_axis(p, 0, -pl.rot.x);
    return vec(p.x / pl.stretch.x, p.y / pl.stretch.y, p.z / pl.stretch.z);
}

// A normal in the coordinates the solid was made in (normals map by the transpose of the map).
pray_vec unplace_normal(const Placement &pl, pray_vec n) {
    n = rotate_axis(n, 2, -pl.rot.z);
    n = rotate_axis(n, 1, -pl.rot.y);
    n = rotate_axis(n, 0, -pl.rot.x);
    n = vec(n.x * pl.stretch.x, n.y * pl.stretch.y, n.z * pl.stretch.z);
    double l = std::sqrt(n.x * n.x + n.y * n.y + n.z * n.z);
    return vec(n.x / l, n.y / l, n.z / l);
}

// The sum of the cell numbers of the point a step inside the solid from hit point q (outward
// unit normal n there, both in the solid's own coordinates; cells of side s), in *sum. False when
// the hit is too near an edge between cells to tell: a boundary crossing the surface there, or
// one that the step would cross. A face lying on a boundary (within rounding) is judged: the
// cell behind it is the one the renderer must show.
bool judge_cell(pray_vec q, pray_vec n, double s, bool fl, double *sum) {
    const double err = fl ? 1e-4 : 1e-11, edge = fl ? 2e-3 : 1e-6, step = 16 * err;
    double qs[3] = {q.x, q.y, q.z}, ns[3] = {n.x, n.y, n.z};
    *sum = 0;
    for (int k = 0; k < 3; k++) {
        double u = qs[k] - std::floor(qs[k] / s + 0.5) * s;  // from the nearest boundary
        bool across = std::fabs(ns[k]) >= 0.5;
        if (std::fabs(u) <= err ? !across : !across ? std::fabs(u) < edge : u / ns[k] > 0 && u / ns[k] < 2 * step)
            return false;
        *sum += std::floor((qs[k] - ns[k] * step) / s);
    }
    return true;
}

pray_object *place(pray_ctx *c, const Placement &pl, pray_object *o) {
    pray_object *s = pray_stretch(c, o, pl.stretch);
    pray_object *r = pray_rotate(c, s, pl.rot);
    pray_object *m = pray_translate(c, r, pl.move);
    pray_object_release(c, s);
    pray_object_release(c, r);
    return m;
}

} // namespace

TEST_CASE("checker: every pixel is one of its two colours, the one of the hit point's cell, moved, turned, stretched") {
    const bool fl = std::strstr(pray_features(), "real=float") != nullptr;
    const Placement placements[] = {
        {"as made", vec(0, 0, 0), vec(0, 0, 0), vec(1, 1, 1)},
        {"moved", vec(0, 0, 0), vec(0.3, -0.2, 0), vec(1, 1, 1)},
        {"turned", vec(0, 0, 30), vec(0.25, 0, 0), vec(1, 1, 1)},
        {"tilted", vec(15, -10, 40), vec(0, 0, 0.2), vec(1, 1, 1)},
        {"stretched", vec(0, 0, 20), vec(0, 0, 0), vec(1.5, 0.7, 1)},
    };
    const pray_rgb A = {0.9f, 0.1f, 0.2f}, B = {0.1f, 0.3f, 0.8f}, BG = {0, 1, 0};
    const int W = 48, H = 36;
    for (const Placement &pl : placements)
        for (int kind = 0; kind < 3; kind++)
            for (const Setting &st : SETTINGS) {
                CAPTURE(pl.name);
                CAPTURE(kind);
                CAPTURE(st.name);
                CAPTURE(st.value);
                pray_ctx *c = pray_new();
                pray_option(c, "width", W);
                pray_option(c, "height", H);
                pray_option(c, "adaptive", 0);
                pray_option(c, st.name, st.value);
                REQUIRE(pray_lookat(c, vec(1.5, -6, 4.5), vec(0, 0, 0), vec(0, 0, 1), 55) == PRAY_OK);
                pray_background(c, BG, BG);
                pray_model *a = pray_color(c, A), *b = pray_color(c, B);
                pray_model *m = pray_checker(c, a, b, 0.5);
                // a floor at z = 0, a box whose every face lies on cell boundaries, and a ball
                pray_object *o = kind == 0   ? pray_plane(c, m, vec(0, 0, 0), vec(0, 0, 1))
                                 : kind == 1 ? pray_box(c, m, vec(-2, -1.5, -1), vec(1.5, 2, 0))
                                             : pray_sphere(c, m, vec(0.2, 0.1, 0.3), 1.7);
                pray_object *root = place(c, pl, o);
                REQUIRE(root);
                pray_scene *sc = pray_prepare_render(c, root, nullptr);
                REQUIRE_MESSAGE(sc, pray_error(c));
                std::vector<float> rgb(W * H * 3);
                pray_buffers out = {rgb.data(), nullptr, nullptr, nullptr, 0, nullptr, nullptr, 0};
                REQUIRE(pray_render_prepared(c, sc, nullptr, &out) == PRAY_OK);
                int seen[2] = {0, 0}, wrong = 0;
                for (int y = 0; y < H; y++)
                    for (int x = 0; x < W; x++) {
                        const float *px = &rgb[(y * W + x) * 3];
                        bool isa = px[0] == A.r && px[1] == A.g && px[2] == A.b, isb = px[0] == B.r && px[1] == B.g && px[2] == B.b;
                        bool isbg = px[0] == BG.r && px[1] == BG.g && px[2] == BG.b;
                        REQUIRE((isa || isb || isbg));
                        pray_vec ro, rd;
                        REQUIRE(pray_camera_ray(c, x + 0.5, y + 0.5, &ro, &rd) == PRAY_OK);
                        pray_hit h;
                        if (pray_intersect(c, sc, ro, rd, HUGE_VAL, &h, 1) < 1) {
                            CHECK(isbg);
                            continue;
                        }
                        // the cell a step inside the solid: judged unless the hit is at an edge
                        // between cells (judge_cell)
                        pray_vec hit = vec(ro.x + h.t * rd.x, ro.y + h.t * rd.y, ro.z + h.t * rd.z);
                        double sum;
                        if (!judge_cell(unplace(pl, hit), unplace_normal(pl, h.normal), 0.5, fl, &sum)) continue;
                        bool even = std::fmod(sum, 2.0) == 0;
                        seen[even ? 0 : 1]++;
                        wrong += even ? !isa : !isb;
                    }
                CHECK(wrong == 0);
                CHECK(seen[0] > 20);
                CHECK(seen[1] > 20);
                pray_scene_free(c, sc);
                pray_free(c);
            }
}

TEST_CASE("checker: inside textures, sums and nested checkers, and as a transparent model") {
    // checker(checker(A, B, 1), C, 2): a cell of side 2 holds 8 of side 1 (checked by print of
    // the colours along a line through the API would need more API; the image is compared with
    // the same pattern made of boxes)
    const char *pre = "lookat [0.5, 0.5, 10], [0.5, 0.5, 0], <0, 1, 0>, 60\n"
                      "A = color({1, 0, 0})\nB = color({0, 0, 1})\nC = color({0, 1, 0})\n";
    testkit::Result nested = testkit::run(std::string(pre) + "rendertiff plane(checker(checker(A, B, 1), C, 2), [0, 0, 0], <0, 0, 1>), none\n",
                                          {"width=40", "height=40", "adaptive=0"});
    std::string boxes = std::string(pre) + "All = nothing\ni = -8\nwhile i < 8\n  j = -8\n  while j < 8\n"
                                           "    M = C\n"
                                           "    if (floor(i / 2) + floor(j / 2) + -1) % 2 == 0\n"
                                           "      M = A\n"
                                           "      if (i + j + -1) % 2 # 0\n        M = B\n      endif\n"
                                           "    endif\n"
                                           "    All = All | box(M, [i, j, -1], [i + 1, j + 1, 0])\n"
                                           "    j = j + 1\n  endwhile\n  i = i + 1\nendwhile\nrendertiff All, none\n";
    testkit::Result made = testkit::run(boxes, {"width=40", "height=40", "adaptive=0"});
    REQUIRE_MESSAGE(nested.status == PRAY_OK, nested.error);
    REQUIRE_MESSAGE(made.status == PRAY_OK, made.error);
    int differ = 0;
    for (size_t i = 0; i < nested.frames[0].pixels.size(); i++) differ += nested.frames[0].pixels[i] != made.frames[0].pixels[i];
    CHECK(differ == 0);
}

// ---- random scenes ----
TEST_CASE("random scenes with spotlights and checkers: every acceleration setting renders --brute's floats") {
    unsigned long long seed = 12345;
    auto rnd = [&seed]() {
        seed = seed * 6364136223846793005ULL + 1442695040888963407ULL;
        return (double)(seed >> 11) / 9007199254740992.0;
    };
    auto f = [](double v) {
        char b[32];
        std::snprintf(b, sizeof b, "%.4f", v);
        return std::string(b);
    };
    for (int scene = 0; scene < 24; scene++) {
        std::string p = "lookat [" + f(4 * rnd() - 2) + ", -8, " + f(3 + 3 * rnd()) + "], [0, 0, 0.5], <0, 0, 1>, 50\n";
        p += "M0 = phong({" + f(rnd()) + ", " + f(rnd()) + ", 0.3}, {0.4}, {0.05}, 20)\n";
        p += "M1 = phong({0.2, " + f(rnd()) + ", " + f(rnd()) + "}, {0.1}, {0.02}, 5)\n";
        p += "G = transparent({0.8}, 1.4) + phong({0}, {0.5}, 40)\n";
        p += "K = checker(M0, M1, " + f(0.25 + rnd()) + ")\n";
        p += "All = plane(checker(M1, M0, 1), [0, 0, 0], <0, 0, 1>)\n";
        for (int i = 0; i < 12; i++) {
            std::string at = "[" + f(6 * rnd() - 3) + ", " + f(6 * rnd() - 3) + ", " + f(2 * rnd()) + "]";
            int k = (int)(rnd() * 4);
            std::string m = rnd() < 0.3 ? "G" : rnd() < 0.5 ? "K" : "M0";
            if (k == 0) p += "All = All | sphere(" + m + ", " + at + ", " + f(0.3 + 0.7 * rnd()) + ")\n";
            if (k == 1) p += "All = All | box(" + m + ", " + at + ", " + at + " + <1, 0.5, 1>) . <0, 0, " + f(90 * rnd()) + ">\n";
            if (k == 2) p += "All = All | paint(rod(M1, " + at + ", " + at + " + <0, 0, 1.5>, 0.3), K)\n";
            if (k == 3) p += "All = All \\ sphere(M1, " + at + ", 0.6)\n";
        }
        p += "L = spotlight({0.9}, [" + f(4 * rnd() - 2) + ", -2, 6], <0, 0.3, -1>, " + f(10 + 10 * rnd()) + ", " + f(25 + 10 * rnd()) +
             ") + spotlight({0.5, 0.4, 0.3}, [4, 3, 5], <-1, -1, -1>, 20, 20) + pointlight({0.2}, [-5, -5, 9])\n";
        p += "rendertiff All, L\n";
        CAPTURE(p);
        testkit::Result ref = testkit::run(p, {"width=40", "height=30", "brute=1"});
        REQUIRE_MESSAGE(ref.status == PRAY_OK, ref.error);
        for (const Setting &st : SETTINGS) {
            if (std::strcmp(st.name, "brute") == 0) continue;
            testkit::Result r = testkit::run(p, {"width=40", "height=30", std::string(st.name) + "=" + f(st.value)});
            REQUIRE_MESSAGE(r.status == PRAY_OK, r.error);
            CAPTURE(st.name);
            CHECK(r.frames[0].pixels == ref.frames[0].pixels);
        }
    }
}
