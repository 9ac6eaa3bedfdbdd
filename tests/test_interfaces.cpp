// Faces where two materials meet (docs/pray-language.md, "Where materials meet"): a glass on a
// table shows the table, a clear solid of index 1 is invisible wherever it stands, faces between
// regions of one material vanish, and a ray between two transparent materials bends by the ratio
// of their indices. Oracles that need no other renderer: the same scene without the clear solid,
// one box for two, Snell's law on the directions pray_intersect reports.
#include <doctest/doctest.h>

#include "testkit.hpp"

#include <cmath>
#include <cstring>
#include <string>
#include <vector>

namespace {

using testkit::Frame;
using testkit::vec;

double dot(pray_vec a, pray_vec b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
pray_vec cross(pray_vec a, pray_vec b) { return vec(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x); }
double len(pray_vec a) { return std::sqrt(dot(a, a)); }

// The tolerance of directions and distances: the renderer's precision (PRAY_REAL double or float).
double tol() { return std::strstr(pray_features(), "real=float") ? 1e-5 : 1e-12; }

// The largest difference between two frames, in output steps of 8 bits; -1 when their sizes
// differ.
double steps_apart(const Frame &a, const Frame &b) {
    if (a.width != b.width || a.height != b.height) return -1;
    double m = 0;
    for (size_t i = 0; i < a.pixels.size(); i++) m = std::max(m, std::fabs((double)a.pixels[i] - b.pixels[i]) * 255);
    return m;
}

// Pixels whose 8-bit outputs differ.
long pixels_apart(const Frame &a, const Frame &b) {
    long n = 0;
    for (size_t i = 0; i < a.pixels.size(); i += 3)
        for (int ch = 0; ch < 3; ch++)
            if (std::lround(a.pixels[i + ch] * 255) != std::lround(b.pixels[i + ch] * 255)) {
                n++;
                break;
            }
    return n;
}

// A program's frames at 64 x 48 with fixed options; the run must succeed.
std::vector<Frame> frames_of(const std::string &prog, std::vector<std::string> opts = {}) {
    opts.push_back("width=64");
    opts.push_back("height=48");
    testkit::Result r = testkit::run(prog, opts);
    REQUIRE_MESSAGE(r.status == PRAY_OK, r.error);
    return r.frames;
}

const char *CAMERA = "lookat [3, -6, 4], [0, 0, 0.4], <0, 0, 1>, 40\n"
                     "background {0.2, 0.3, 0.4}\n"
                     "Table = phong({0.8, 0.7, 0.5}, {0.3}, {0.1}, 20)\n"
                     "Floor = plane(Table, [0, 0, 0], <0, 0, 1>)\n"
                     "L = pointlight({0.7}, [-3, -4, 6]) + dirlight({0.4}, <1, 2, -3>)\n";

const std::vector<std::vector<std::string>> SETTINGS = {{}, {"brute=1"}, {"grid=6", "plans=0"}, {"grid=3", "freeze=0"}};

// The program's two frames, under every setting, within one output step of each other.
void check_frames_alike(const std::string &prog) {
    for (const auto &o : SETTINGS) {
        CAPTURE(o.size() ? o[0] : std::string("default"));
        std::vector<Frame> f = frames_of(prog, o);
        REQUIRE(f.size() == 2);
        CHECK(steps_apart(f[0], f[1]) <= 1);
    }
}

} // namespace

TEST_CASE("interfaces: a clear solid of index 1 standing on a floor and sunk into it renders as the floor alone") {
    // a block standing on the floor, a rod half sunk into it, a ball sunk to its middle; the floor
    // written last wins where they overlap it, so that what is under its face is floor
    std::string prog = std::string(CAMERA) +
                       "Clear = transparent({1}, 1)\n"
                       "Block = box(Clear, [-1.2, -1, 0], [0.3, 0.4, 1.2])\n"
                       "Rod = rod(Clear, [1, 0.5, -0.5], [1, 0.5, 1], 0.4)\n"
                       "Ball = sphere(Clear, [-0.3, -1.6, 0], 0.5)\n"
                       "rendertiff Block | Rod | Ball | Floor, L\n"
                       "rendertiff Floor, L\n";
    check_frames_alike(prog);
}

TEST_CASE("interfaces: what stands inside a clear solid of index 1 casts its own shadow") {
    // a matte ball and a rod inside a clear block that stands on the floor, the rod on the
    // block's floor: the block is invisible, so the image is theirs alone, shadows and all (a
    // face between two materials stops or filters a shadow ray as any surface does); a tinted
    // slab apart on the floor casts its tinted shadow in both
    std::string parts = "Ball = sphere(Table, [-0.5, -0.4, 0.6], 0.4)\n"
                        "Rod = rod(Table, [0.6, 0.2, 0], [0.6, 0.2, 1.1], 0.15)\n"
                        "Tint = box(transparent({0.3, 0.9, 0.5}, 1), [-2, 1, 0], [-1, 1.1, 1.3])\n";
    std::string prog = std::string(CAMERA) + parts +
                       "Block = box(transparent({1}, 1), [-1.2, -1, 0], [1, 0.5, 1.5])\n"
                       "rendertiff Block | Ball | Rod | Tint | Floor, L\n"
                       "rendertiff Ball | Rod | Tint | Floor, L\n";
    check_frames_alike(prog);
}

TEST_CASE("interfaces: two glass boxes of one material sharing a face render as one box") {
    // the halves' models are equal values made apart (two handles)
    std::string prog = std::string(CAMERA) + "G1 = transparent({0.9}, 1.5) + phong({0}, {0.6}, 60)\n"
                                             "G2 = transparent({0.9}, 1.5) + phong({0}, {0.6}, 60)\n"
                                             "rendertiff box(G1, [-1, -1, 0.5], [1, 0.5, 1.2]) | Floor, L\n"
                                             "rendertiff box(G1, [-1, -1, 0.5], [0, 0.5, 1.2]) | box(G2, [0, -1, 0.5], [1, 0.5, 1.2]) | "
                                             "Floor, L\n";
    for (const auto &o : SETTINGS) {
        CAPTURE(o.size() ? o[0] : std::string("default"));
        std::vector<Frame> f = frames_of(prog, o);
        REQUIRE(f.size() == 2);
        CHECK(pixels_apart(f[0], f[1]) == 0);
    }
}

namespace {

// The hits of a ray through a prepared scene.
std::vector<pray_hit> hits_of(pray_ctx *c, pray_scene *s, pray_vec o, pray_vec d) {
    std::vector<pray_hit> h(16);
    int n = pray_intersect(c, s, o, d, HUGE_VAL, h.data(), (int)h.size());
    REQUIRE(n >= 0);
    REQUIRE(n <= 16);
    h.resize((size_t)n);
    return h;
}

// The sines of the angles of the ray along d and of its refracted ray r against the normal n;
// checks that the three lie in one plane and that r goes on through the surface.
void snell_sines(pray_vec d, pray_vec n, pray_vec r, double *s1, double *s2) {
    CHECK(len(r) == doctest::Approx(1).epsilon(tol()));
    CHECK(std::fabs(dot(cross(d, n), r)) < tol());
    CHECK(dot(r, n) * dot(d, n) > 0);
    *s1 = len(cross(d, n)) / len(d) / len(n);
    *s2 = len(cross(r, n)) / len(n);
}

} // namespace

TEST_CASE("interfaces: a face between boxes of one material is none; between two materials it is a surface") {
    pray_ctx *c = pray_new();
    REQUIRE(c);
    pray_rgb t = {0.9, 0.9, 0.9};
    pray_model *g1 = pray_transparent(c, t, 1.5), *g2 = pray_transparent(c, t, 1.5), *g3 = pray_transparent(c, t, 1.4);
    for (pray_model *m : {g2, g3}) {
        pray_object *root = pray_csg(c, PRAY_UNION, pray_box(c, g1, vec(-1, -1, -1), vec(0, 1, 1)), pray_box(c, m, vec(0, -1, -1), vec(1, 1, 1)));
        pray_scene *s = pray_prepare(c, root);
        REQUIRE(s);
        std::vector<pray_hit> h = hits_of(c, s, vec(-3, 0.1, 0.2), vec(1, 0, 0));
        if (m == g2) {  // equal values made apart: one material, one solid
            REQUIRE(h.size() == 2);
            CHECK(h[0].t == 2);
            CHECK(h[1].t == 4);
        } else {
            REQUIRE(h.size() == 3);
            CHECK(h[1].t == 3);
            CHECK(h[1].entering == 2);
            CHECK(h[1].normal.x == -1);  // towards the material left
        }
        pray_scene_free(c, s);
    }
    pray_free(c);
}

TEST_CASE("interfaces: a slab inside a slab of the same index is invisible at the face between them") {
    pray_ctx *c = pray_new();
    REQUIRE(c);
    // two models of index 1.5, different values (the inner one has a highlight of zero exponent 2)
    pray_rgb one = {1, 1, 1}, z = {0, 0, 0};
    pray_model *outer = pray_transparent(c, one, 1.5);
    pray_model *inner = pray_model_add(c, pray_transparent(c, one, 1.5), pray_phong(c, z, z, z, 2));
    pray_object *root = pray_csg(c, PRAY_UNION, pray_box(c, outer, vec(-2, -2, -1), vec(2, 2, 1)),
                                 pray_box(c, inner, vec(-1, -1, -0.5), vec(1, 1, 0.5)));
    pray_scene *s = pray_prepare(c, root);
    REQUIRE(s);
    pray_vec d = vec(0.3, 0.2, -1);
    d = vec(d.x / len(d), d.y / len(d), d.z / len(d));
    std::vector<pray_hit> h = hits_of(c, s, vec(0, 0, 3), d);
    REQUIRE(h.size() == 4);  // into the outer slab, into the inner one, out of it, out of the outer
    CHECK(h[0].entering == 1);
    CHECK(h[1].entering == 2);
    CHECK(h[2].entering == 2);
    CHECK(h[3].entering == 0);
    CHECK(h[1].t == doctest::Approx(0.5 * len(vec(0.3, 0.2, -1)) * 5));
    for (int k = 1; k <= 2; k++) {  // the ratio 1.5 / 1.5: straight on
        CHECK(h[k].refracted.x == doctest::Approx(d.x).epsilon(tol()));
        CHECK(h[k].refracted.y == doctest::Approx(d.y).epsilon(tol()));
        CHECK(h[k].refracted.z == doctest::Approx(d.z).epsilon(tol()));
    }
    CHECK(dot(h[1].normal, d) < 0);  // facing the material left
    pray_free(c);
}

TEST_CASE("interfaces: water in a glass bends at the inner wall by Snell's law with 1.33 / 1.5") {
    pray_ctx *c = pray_new();
    REQUIRE(c);
    pray_rgb t = {0.9, 0.9, 0.9};
    pray_model *glass = pray_transparent(c, t, 1.5), *water = pray_transparent(c, t, 1.33);
    // a glass of wall 0.2 and bottom 0.2 on the origin, water to 1.5 inside, written after it
    pray_object *cup = pray_csg(c, PRAY_DIFFERENCE, pray_rod(c, glass, vec(0, 0, 0), vec(0, 0, 2), 1),
                                pray_rod(c, glass, vec(0, 0, 0.2), vec(0, 0, 3), 0.8));
    pray_object *root = pray_csg(c, PRAY_UNION, cup, pray_rod(c, water, vec(0, 0, 0.2), vec(0, 0, 1.5), 0.8));
    pray_scene *s = pray_prepare(c, root);
    REQUIRE(s);
    for (double a : {0.0, 0.3, 0.6, 0.9}) {
        CAPTURE(a);
        // from inside the wall at (0.9, 0, 1) towards the axis, tilted down by a
        pray_vec d = vec(-std::cos(a), 0.1, -std::sin(a));
        std::vector<pray_hit> h = hits_of(c, s, vec(0.9, 0, 1), d);
        REQUIRE(h.size() >= 2);
        CHECK(h[0].entering == 2);  // glass -> water at the inner wall, x = 0.8
        double u = h[0].t / len(d);  // (t is along the unit direction)
        pray_vec p = vec(0.9 + u * d.x, u * d.y, 1 + u * d.z);
        double r = std::hypot(p.x, p.y);
        CHECK(r == doctest::Approx(0.8).epsilon(tol()));
        CHECK(h[0].normal.x == doctest::Approx(p.x / r).epsilon(100 * tol()));  // the wall's, out of the glass
        CHECK(h[0].normal.y == doctest::Approx(p.y / r).epsilon(100 * tol()));
        double s1, s2;
        snell_sines(d, h[0].normal, h[0].refracted, &s1, &s2);
        CHECK(std::fabs(1.5 * s1 - 1.33 * s2) < tol());
        CHECK(s2 > s1);
        // and back: from the water into the glass, where the ray may be reflected whole
        pray_vec e = vec(std::cos(a), 0.1, -std::sin(a) * 0.5);
        std::vector<pray_hit> k = hits_of(c, s, vec(0, 0, 1), e);
        REQUIRE(k.size() >= 2);
        CHECK(k[0].entering == 2);
        snell_sines(e, k[0].normal, k[0].refracted, &s1, &s2);
        CHECK(std::fabs(1.33 * s1 - 1.5 * s2) < tol());
    }
    // where the water meets air: its own index, the glass's at the glass
    std::vector<pray_hit> up = hits_of(c, s, vec(0.3, 0, 1), vec(0, 0, 1));
    REQUIRE(up.size() == 1);
    CHECK(up[0].entering == 0);
    pray_free(c);
}

TEST_CASE("interfaces: a glass standing on a table shows the table through it") {
    // through the glass the eye sees the table, dimmed by what the glass lets through (0.9 at
    // each face) and not to half of it anywhere
    std::string prog = std::string(CAMERA) + "Glass = transparent({0.9}, 1.5)\n"
                                             "rendertiff box(Glass, [-1, -1, 0], [1, 0.5, 1.2]) | Floor, L\n"
                                             "rendertiff Floor, L\n";
    for (const auto &o : SETTINGS) {
        std::vector<Frame> f = frames_of(prog, o);
        REQUIRE(f.size() == 2);
        long dim = 0, seen = 0;
        for (int y = 0; y < 48; y++)
            for (int x = 0; x < 64; x++) {
                if (f[0].at(x, y, 0) == f[1].at(x, y, 0)) continue;  // (not through the glass)
                seen++;
                dim += f[0].at(x, y, 0) < 0.5f * f[1].at(x, y, 0);  // (0.9 at each of 2 or 3 faces)
            }
        CHECK(seen > 500);
        CHECK(dim == 0);
    }
}

TEST_CASE("interfaces: a warning once a frame when no light reaches anything the eye sees") {
    std::string head = std::string(CAMERA) + "Ball = sphere(Table, [0, 0, 1], 1)\n";
    pray_ctx *c = pray_new();
    REQUIRE(c);
    pray_option(c, "width", 16);
    pray_option(c, "height", 16);
    std::string warned;
    std::vector<Frame> frames;
    pray_set_warning(c, testkit::print_sink, &warned);
    pray_set_frame(c, testkit::frame_sink, &frames);
    // the sun travels up, away from everything; then down; a lamp under the floor; no light;
    // only the background seen
    std::string prog = head + "rendertiff Ball | Floor, dirlight({1}, <0, 0, 1>)\n"
                              "rendertiff Ball | Floor, dirlight({1}, <0, 0, -1>)\n"
                              "rendertiff Ball | Floor, pointlight({1}, [0, 0, -3])\n"
                              "rendertiff Ball | Floor, none\n"
                              "rendertiff Ball . [0, 0, 50], dirlight({1}, <0, 0, 1>)\n"
                              "rendertiff Ball | Floor, dirlight({1}, <0, 0, 1>) + dirlight({1}, <0, 0, 1>)\n";
    REQUIRE_MESSAGE(pray_run_string(c, "dark.ray", prog.data(), prog.size()) == PRAY_OK, pray_error(c));
    CHECK(warned == "dark.ray:7:1: warning: no light reaches anything the eye sees\n"
                    "dark.ray:9:1: warning: no light reaches anything the eye sees\n"
                    "dark.ray:12:1: warning: no light reaches anything the eye sees\n");
    CHECK(frames.size() == 6);
    pray_free(c);
}

namespace {

// pray_render's image of the context's camera, with option brute as given: its pixels.
std::vector<float> render_pixels(pray_ctx *c, pray_object *root, pray_light *lights, bool brute) {
    REQUIRE(pray_option(c, "brute", brute ? 1 : 0) == PRAY_OK);
    pray_image img;
    REQUIRE_MESSAGE(pray_render(c, root, lights, &img) == PRAY_OK, pray_error(c));
    std::vector<float> px(img.pixels, img.pixels + 3 * (size_t)img.width * img.height);
    pray_image_free(c, &img);
    return px;
}

// Pixels whose colours differ.
long pixels_differing(const std::vector<float> &a, const std::vector<float> &b) {
    long n = 0;
    for (size_t i = 0; i + 2 < a.size() && a.size() == b.size(); i += 3)
        n += a[i] != b[i] || a[i + 1] != b[i + 1] || a[i + 2] != b[i + 2];
    return a.size() == b.size() ? n : -1;
}

} // namespace

TEST_CASE("interfaces: faces between materials that let no light through, left out of a render's lists, "
          "where a ray starts inside the solid: the eye, a parallel window, bumped shadow rays, a moved eye, queries") {
    // A bumped red block sunk into a floor and a blue one standing on it, sharing the face x = 0,
    // a lamp inside the blue one just under its top: a render's lists leave out the face between them (no ray from
    // outside the solid can meet it), yet every ray that starts inside sees it as --brute does.
    pray_ctx *c = pray_new();
    REQUIRE(c);
    pray_option(c, "width", 40);
    pray_option(c, "height", 30);
    float bumps[16 * 16 * 3];
    unsigned r = 12345;
    for (float &v : bumps) v = (float)((r = r * 1103515245u + 12345u) >> 16 & 255) / 255.0f;
    pray_texture *tex = pray_texture_rgb(c, 16, 16, bumps, "bumps");
    pray_rgb red = {0.8, 0.2, 0.2}, blue = {0.2, 0.3, 0.8}, grey = {0.5, 0.5, 0.5}, spec = {0.3, 0.3, 0.3};
    pray_model *mr = pray_tiffbump(c, pray_phong(c, red, spec, grey, 20), 0.6, tex);
    pray_model *mb = pray_phong(c, blue, spec, grey, 20), *mf = pray_phong(c, grey, spec, grey, 5);
    pray_object *root = pray_csg(c, PRAY_UNION, pray_box(c, mr, vec(-1, -1, -0.3), vec(0, 1, 1)), pray_box(c, mb, vec(0, -1, 0), vec(1, 1, 1)));
    root = pray_csg(c, PRAY_UNION, pray_plane(c, mf, vec(0, 0, 0), vec(0, 0, 1)), root);  // (the red block wins under the floor)
    pray_rgb lamp = {0.9, 0.9, 0.9}, sun = {0.5, 0.5, 0.5};
    pray_light *lights = pray_light_add(c, pray_pointlight(c, lamp, vec(0.5, 0, 0.9)), pray_dirlight(c, sun, vec(1, 0.5, -2)));
    REQUIRE(root);
    REQUIRE(lights);
    struct Camera {
        const char *what;
        bool parallel;
        pray_vec eye, point;
    } cams[] = {
        {"outside, looking at the bumped top", false, vec(-2.5, -3, 3), vec(0, 0, 0.8)},
        {"the eye inside the red block", false, vec(-0.5, 0.2, 0.5), vec(1, 0, 0.5)},
        {"a parallel window through both blocks", true, vec(-0.5, 0, 0.6), vec(1, 0, 0.6)},
        {"the eye on the floor, looking a little up", false, vec(-0.5, -4, 0), vec(0, 0, 0.3)},
    };
    for (const Camera &k : cams) {
        CAPTURE(k.what);
        if (k.parallel) REQUIRE(pray_parallel(c, vec(0, 1.5, 0), vec(0, 0, 1.1), k.eye, k.point) == PRAY_OK);
        else REQUIRE(pray_lookat(c, k.eye, k.point, vec(0, 0, 1), 60) == PRAY_OK);
        std::vector<float> want = render_pixels(c, root, lights, true), got = render_pixels(c, root, lights, false);
        CHECK(pixels_differing(want, got) == 0);
        // the eye moved inside after a render from outside (kept, its lists built for that
        // camera: after one with brute, which keeps none): the scene kept is not taken for it
        if (k.parallel) continue;
        REQUIRE(pray_lookat(c, vec(-2.5, -3, 3), vec(0, 0, 0.8), vec(0, 0, 1), 60) == PRAY_OK);
        render_pixels(c, root, lights, true);
        render_pixels(c, root, lights, false);
        REQUIRE(pray_lookat(c, k.eye, k.point, vec(0, 0, 1), 60) == PRAY_OK);
        CHECK(pixels_differing(want, render_pixels(c, root, lights, false)) == 0);
    }
    // ray queries on a scene prepared for a render from outside see the face between the blocks
    REQUIRE(pray_option(c, "brute", 0) == PRAY_OK);
    REQUIRE(pray_lookat(c, vec(-2.5, -3, 3), vec(0, 0, 0.8), vec(0, 0, 1), 60) == PRAY_OK);
    pray_scene *s = pray_prepare_render(c, root, lights);
    REQUIRE(s);
    std::vector<pray_hit> h = hits_of(c, s, vec(-2, 0.3, 0.5), vec(1, 0, 0));
    REQUIRE(h.size() == 3);
    CHECK(h[1].entering == 2);
    CHECK(h[1].t == 2);
    h = hits_of(c, s, vec(-0.5, 0.3, 0.5), vec(1, 0, 0));
    REQUIRE(h.size() == 2);
    CHECK(h[0].entering == 2);
    pray_free(c);
}

TEST_CASE("interfaces: all of space as a complement of nothing the bounds can see, then two balls of two materials: "
          "the face between the balls, as --brute finds it") {
    // the complement of two balls' intersection (empty: their boxes are apart) is all of space;
    // the balls written after it fill it with their materials where they are, so that where they
    // meet is a face, while the rest of space has no material and no face
    pray_ctx *c = pray_new();
    REQUIRE(c);
    pray_rgb red = {0.8, 0.2, 0.2}, blue = {0.2, 0.3, 0.8}, z = {0, 0, 0};
    pray_model *mr = pray_phong(c, red, z, z, 10), *mb = pray_phong(c, blue, z, z, 10);
    pray_object *none = pray_csg(c, PRAY_INTERSECTION, pray_sphere(c, mr, vec(-5, 0, 0), 1), pray_sphere(c, mr, vec(5, 0, 0), 1));
    pray_object *root = pray_csg(c, PRAY_UNION, pray_complement(c, none), pray_sphere(c, mr, vec(0, 0, 0), 1));
    root = pray_csg(c, PRAY_UNION, root, pray_sphere(c, mb, vec(1, 0, 0), 1));
    REQUIRE(root);
    std::vector<std::vector<pray_hit>> got;
    for (int brute : {1, 0}) {
        REQUIRE(pray_option(c, "brute", brute) == PRAY_OK);
        pray_scene *s = pray_prepare(c, root);
        REQUIRE(s);
        got.push_back(hits_of(c, s, vec(-3, 0.2, 0), vec(1, 0, 0)));
        pray_scene_free(c, s);
    }
    REQUIRE(got[0].size() == 1);
    CHECK(got[0][0].entering == 2);  // red into blue, at x = 1 - sqrt(1 - 0.04)
    CHECK(got[0][0].t == doctest::Approx(3 + 1 - std::sqrt(0.96)));
    REQUIRE(got[1].size() == 1);
    CHECK(got[1][0].entering == 2);
    CHECK(got[1][0].t == got[0][0].t);
    CHECK(got[1][0].primitive == got[0][0].primitive);
    pray_free(c);
}
