// The stability envelope: where the numerical methods of pray hold and where they break, each
// property with a stated tolerance (docs/testing.md, "Stability envelope", has the table with the
// measured limits). Every test is built so that it can fail:
//   - coincident faces: every face has its own flat colour; an independent ray caster in long
//     double knows which face (or which set of exactly coincident faces) each pixel must show, and
//     a pixel of any other colour is a speckle;
//   - scaling by 2^k: the same program with every length multiplied, byte-identical images;
//     translation far from the origin: flat-coloured images compared pixel by pixel, every
//     difference must be an edge pixel showing a neighbour's surface (else a hole);
//   - self-intersection: secondary rays that meet the surface they start on darken or recolour
//     pixels whose exact values are known (shadow acne on lit faces, an extra T factor through
//     glass, light leaking through thin occluders);
//   - grazing and tangent rays: pray_intersect's hit/miss against an exact decision in long
//     double, for clearances from 1e-1 down to 1e-15 of the radius;
//   - the grid and every switch against --brute on the scaled, translated and coincident scenes
//     (images float for float, and adversarial rays hit for hit).
// The suite runs in double and in float (PRAY_REAL=float); where single precision cannot hold a
// range, the test states the float range and why. PRAY_STABILITY_WIDE=1 in the environment runs
// the exploration beyond the asserted ranges and prints where each property breaks: six cases
// named "(PRAY_STABILITY_WIDE)", measurements that assert nothing, which doctest reports as
// skipped without the variable.
#include <doctest/doctest.h>

#include "testkit.hpp"

#include <algorithm>
#include <cfloat>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace {

using testkit::Frame;

typedef long double LD;

bool float_build() { return std::strstr(pray_features(), "real=float") != nullptr; }
// the unit roundoff of the renderer's arithmetic
double real_eps() { return float_build() ? FLT_EPSILON : DBL_EPSILON; }
bool wide() {
    const char *e = std::getenv("PRAY_STABILITY_WIDE");
    return e && *e && std::strcmp(e, "0") != 0;
}

std::string num(double x) {
    char b[64];
    std::snprintf(b, sizeof b, "%.17g", x);
    return b;
}

struct V3 {
    double x, y, z;
};
V3 v3(double x, double y, double z) { return V3{x, y, z}; }
V3 operator+(V3 a, V3 b) { return v3(a.x + b.x, a.y + b.y, a.z + b.z); }
V3 operator-(V3 a, V3 b) { return v3(a.x - b.x, a.y - b.y, a.z - b.z); }
V3 operator*(V3 a, double s) { return v3(a.x * s, a.y * s, a.z * s); }
double dot(V3 a, V3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
V3 cross(V3 a, V3 b) { return v3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x); }
double len(V3 a) { return std::sqrt(dot(a, a)); }
V3 unit(V3 a) { return a * (1 / len(a)); }
pray_vec pv(V3 a) {
    pray_vec v;
    v.x = a.x;
    v.y = a.y;
    v.z = a.z;
    return v;
}
pray_rgb rgb(double r, double g, double b) {
    pray_rgb c;
    c.r = r;
    c.g = g;
    c.b = b;
    return c;
}
std::string pt(V3 a) { return "[" + num(a.x) + ", " + num(a.y) + ", " + num(a.z) + "]"; }
std::string vc(V3 a) { return "<" + num(a.x) + ", " + num(a.y) + ", " + num(a.z) + ">"; }

// Render a program that must produce exactly one frame.
Frame render_program(const std::string &program, const std::vector<std::string> &options = {}) {
    testkit::Result r = testkit::run(program, options, "stability.ray");
    if (r.status != PRAY_OK || r.frames.size() != 1) {
        FAIL_CHECK("the program failed: " << r.error << "\n" << program);
        return Frame();
    }
    return r.frames[0];
}

// PRAY_STABILITY_DUMP=dir: write the images the tests look at (PNG or TIFF), for a person to see.
void dump(const Frame &f, const std::string &name) {
    const char *dir = std::getenv("PRAY_STABILITY_DUMP");
    if (!dir || !*dir || f.width == 0) return;
    pray_ctx *c = pray_new();
    pray_image img;
    img.width = f.width;
    img.height = f.height;
    img.pixels = const_cast<float *>(f.pixels.data());
    std::string ext = std::strstr(pray_features(), "png") ? ".png" : ".tif";
    pray_write_image(c, &img, (std::string(dir) + "/" + name + ext).c_str(), 8);
    pray_free(c);
}
// pixels whose three floats are not bit for bit the same
long differing_pixels(const Frame &a, const Frame &b) {
    if (a.width != b.width || a.height != b.height) return -1;
    long n = 0;
    for (size_t i = 0; i < a.pixels.size(); i += 3)
        if (std::memcmp(&a.pixels[i], &b.pixels[i], 3 * sizeof(float)) != 0) n++;
    return n;
}

// The camera looking from `eye` at `look`; X to the right, Y down, both of length `half` (the
// half width of the view at the distance of `look`).
struct Camera {
    V3 x, y, eye, look;
};
Camera aim(V3 eye, V3 look, double half) {
    V3 view = look - eye;
    Camera c;
    c.x = unit(cross(view, v3(0, 0, 1))) * half;
    c.y = unit(cross(view, c.x)) * half;
    c.eye = eye;
    c.look = look;
    return c;
}
std::string perspective(const Camera &c) { return "perspective " + vc(c.x) + ", " + vc(c.y) + ", " + pt(c.eye) + ", " + pt(c.look) + "\n"; }
std::string size_options(int w, int h) {
    return "option \"width\", " + std::to_string(w) + "\noption \"height\", " + std::to_string(h) + "\n";
}

// ---------------------------------------------------------------------------------------------
// The test scene of the scaling and translation tests, as program text: every point goes through
// P (scaled by m, then moved by T), every length through L (scaled by m); directions, normals,
// angles and colours do not change. `flat`: every primitive gets its own flat colour (an image
// that is a map of the primitives), no lights; otherwise phong, mirrors, glass, shadows from a
// directional and a point light.
// ---------------------------------------------------------------------------------------------
struct Place {
    double m;
    V3 T;
    V3 P(double x, double y, double z) const { return v3(m * x + T.x, m * y + T.y, m * z + T.z); }
    double L(double r) const { return m * r; }
    V3 Lv(double x, double y, double z) const { return v3(m * x, m * y, m * z); }  // a point relative to a part
};

std::string test_scene(const Place &pl, bool flat, int w = 64, int h = 64) {
    int colour = 0;
    // a flat colour for each primitive: distinct, exact in float
    auto model = [&](const char *shaded) -> std::string {
        if (!flat) return shaded;
        int k = ++colour;
        return "color({" + num((k % 4 + 1) / 8.0) + ", " + num((k / 4 % 4 + 1) / 8.0) + ", " + num((k / 16 % 4 + 1) / 8.0) + "})";
    };
    std::ostringstream s;
    s << size_options(w, h);
    s << "background {0.2, 0.3, 0.5}, {0.6, 0.5, 0.4}\n";
    Camera cam = aim(v3(0.4, -6, 2.2), v3(0, 0, -0.2), 2.0);
    Camera sc;
    sc.x = cam.x * pl.m;
    sc.y = cam.y * pl.m;
    sc.eye = pl.P(cam.eye.x, cam.eye.y, cam.eye.z);
    sc.look = pl.P(cam.look.x, cam.look.y, cam.look.z);
    s << perspective(sc);
    s << "Red = phong({0.8, 0.2, 0.1}, {0.5}, {0.05}, 20)\n"
         "Blue = phong({0.2, 0.3, 0.8}, {0.3}, {0.05}, 10)\n"
         "Grey = phong({0.6}, {0}, {0.1}, 1) + mirror({0.25})\n"
         "Gold = phong({0.3, 0.25, 0.05}, {0.6}, 30) + mirror({0.5, 0.4, 0.1})\n"
         "Glass = transparent({0.8}, 1.5) + mirror({0.1}) + phong({0}, {0.6}, 40)\n";
    s << "Floor = plane(" << model("Grey") << ", " << pt(pl.P(0, 0, -1)) << ", <0, 0, 1>)\n";
    double hh = pl.L(0.55);
    s << "Cube = plane(" << model("Blue") << ", [" << num(hh) << ", 0, 0], <1, 0, 0>) & plane(" << model("Blue") << ", [" << num(-hh)
      << ", 0, 0], <-1, 0, 0>) & plane(" << model("Blue") << ", [0, " << num(hh) << ", 0], <0, 1, 0>) & plane(" << model("Blue") << ", [0, "
      << num(-hh) << ", 0], <0, -1, 0>) & plane(" << model("Blue") << ", [0, 0, " << num(hh) << "], <0, 0, 1>) & plane(" << model("Blue")
      << ", [0, 0, " << num(-hh) << "], <0, 0, -1>)\n";
    s << "Block = (Cube - cylinder(" << model("Red") << ", [0, 0, 0], <0.2, 1, 0.3>, " << num(pl.L(0.25)) << ")) . <15, 25, 35> . "
      << pt(pl.P(-1.1, 0.6, -0.3)) << "\n";
    s << "Ball = (sphere(" << model("Gold") << ", [0, 0, 0], " << num(pl.L(0.6)) << ") - sphere(" << model("Red") << ", "
      << pt(pl.Lv(0.35, -0.3, 0.35)) << ", " << num(pl.L(0.35)) << ")) . " << pt(pl.P(1.0, 0.4, -0.35)) << "\n";
    s << "Lens = (sphere(" << model("Glass") << ", " << pt(pl.Lv(0, 0, -0.6)) << ", " << num(pl.L(0.8)) << ") & sphere(" << model("Glass")
      << ", " << pt(pl.Lv(0, 0, 0.6)) << ", " << num(pl.L(0.8)) << ")) . <70, 0, 20> . " << pt(pl.P(0.1, -1.6, -0.2)) << "\n";
    s << "Rod = (cylinder(" << model("Red") << ", [0, 0, 0], <0, 0, 1>, " << num(pl.L(0.12)) << ") & plane(" << model("Red") << ", "
      << pt(pl.Lv(0, 0, 0.9)) << ", <0, 0, 1>) & plane(" << model("Red") << ", " << pt(pl.Lv(0, 0, -0.9))
      << ", <0, 0, -1>)) . <0, 30, -20> . " << pt(pl.P(0.3, 1.2, 0)) << "\n";
    s << "Tube = (cylinder(" << model("Blue") << ", " << pt(pl.P(-2, 2.5, -0.6)) << ", <1, -0.2, 0.05>, " << num(pl.L(0.3))
      << ") - cylinder(" << model("Red") << ", " << pt(pl.P(-2, 2.5, -0.6)) << ", <1, -0.2, 0.05>, " << num(pl.L(0.22)) << "))\n";
    s << "Scene = Floor | Block | Ball | Lens | Rod | Tube\n";
    if (flat)
        s << "rendertiff Scene, none\n";
    else
        s << "rendertiff Scene, dirlight({0.6}, <-1, 2, -3>), pointlight({0.5, 0.45, 0.4}, " << pt(pl.P(-2.5, -3, 3.5)) << ")\n";
    return s.str();
}

}  // namespace

// =============================================================================================
// Scaling the whole scene by powers of two
// =============================================================================================
// Multiplying every coordinate by 2^k changes no bit of any product, quotient or square root's
// significand, as long as nothing overflows, underflows or becomes subnormal: every ray
// parameter is scaled exactly, and every direction, normal, cosine and colour stays the same. So
// the images must be the same byte for byte. Asserted for k = -20 .. 20 in both builds (in float
// the squared lengths of the scene at 2^-20 are about 2^-44, far above FLT_MIN = 2^-126).
namespace {

struct ScaleRun {
    int k;
    bool ok;           // rendered
    long diff_shaded;  // pixels differing from k = 0 (-1: not rendered)
    long diff_flat;
    std::string error;
};

ScaleRun scale_run(int k, const Frame &ref_shaded, const Frame &ref_flat) {
    ScaleRun r;
    r.k = k;
    Place pl;
    pl.m = std::ldexp(1.0, k);
    pl.T = v3(0, 0, 0);
    testkit::Result a = testkit::run(test_scene(pl, false)), b = testkit::run(test_scene(pl, true));
    r.ok = a.status == PRAY_OK && b.status == PRAY_OK && a.frames.size() == 1 && b.frames.size() == 1;
    r.error = a.error.empty() ? b.error : a.error;
    r.diff_shaded = r.ok ? differing_pixels(ref_shaded, a.frames[0]) : -1;
    r.diff_flat = r.ok ? differing_pixels(ref_flat, b.frames[0]) : -1;
    return r;
}

}  // namespace

TEST_CASE("stability: the scene scaled by 2^k, k = -20 .. 20, camera and lights included, renders the same bytes") {
    Place unitp;
    unitp.m = 1;
    unitp.T = v3(0, 0, 0);
    Frame ref = render_program(test_scene(unitp, false)), ref_flat = render_program(test_scene(unitp, true));
    REQUIRE(ref.width == 64);
    REQUIRE(ref_flat.width == 64);
    dump(ref, "scale-shaded");
    dump(ref_flat, "scale-flat");
    // the scene is not trivial: many distinct colours, the background, every part visible
    std::set<std::vector<float>> colours;
    for (size_t i = 0; i < ref_flat.pixels.size(); i += 3)
        colours.insert(std::vector<float>(ref_flat.pixels.begin() + i, ref_flat.pixels.begin() + i + 3));
    CHECK(colours.size() >= 10);
    std::string bad;
    for (int k = -20; k <= 20; k++) {
        if (k == 0) continue;
        ScaleRun r = scale_run(k, ref, ref_flat);
        if (!r.ok || r.diff_shaded != 0 || r.diff_flat != 0)
            bad += "\n  k = " + std::to_string(k) + ": " +
                   (r.ok ? std::to_string(r.diff_shaded) + " shaded and " + std::to_string(r.diff_flat) + " flat pixels differ"
                         : "failed: " + r.error);
    }
    CHECK_MESSAGE(bad.empty(), "images differ from the scale 1:" << bad);
}

TEST_CASE("stability (PRAY_STABILITY_WIDE): how far scaling by 2^k stays byte-identical"
          * doctest::skip(!wide())) {
    Place unitp;
    unitp.m = 1;
    unitp.T = v3(0, 0, 0);
    Frame ref = render_program(test_scene(unitp, false)), ref_flat = render_program(test_scene(unitp, true));
    for (int dir = -1; dir <= 1; dir += 2) {
        int last_same = 0, first_diff = 0;
        std::string firsts;
        int shown = 0;
        for (int k = dir; std::abs(k) <= 1100; k += dir) {
            ScaleRun r = scale_run(k, ref, ref_flat);
            bool same = r.ok && r.diff_shaded == 0 && r.diff_flat == 0;
            if (same && !first_diff) last_same = k;
            if (!same) {
                if (!first_diff) first_diff = k;
                if (shown++ < 6 || !r.ok)
                    firsts += "\n    k = " + std::to_string(k) + ": " +
                              (r.ok ? std::to_string(r.diff_shaded) + " shaded, " + std::to_string(r.diff_flat) + " flat pixels differ"
                                    : "fails: " + r.error);
                if (!r.ok) break;
            }
            // step faster once far inside the range that holds
            if (same && std::abs(k) >= 40 && std::abs(k) % 8 != 0 && first_diff == 0) continue;
        }
        MESSAGE(std::string(float_build() ? "float" : "double")
                << ", scale 2^k towards " << (dir < 0 ? "small" : "large") << ": identical through k = " << last_same
                << ", first difference at k = " << first_diff << firsts);
    }
}

// =============================================================================================
// Translating the whole scene far from the origin
// =============================================================================================
// Moving everything by T adds rounding of |T| units in the last place to every position, so
// pixels whose rays pass within about that distance of an edge may change sides. The flat image
// (a map of the primitives) of the moved scene is compared with the unmoved one: a differing
// pixel must be an edge pixel (a neighbour in the unmoved image shows another surface) and must
// show a surface of its neighbourhood; any other difference is a hole (or a speckle).
namespace {

struct MoveCount {
    long differ = 0, edge = 0, holes = 0;
    std::string first_hole;
    bool ok = true;
    std::string error;
};

// colour of pixel (x, y) as a key
std::vector<float> px(const Frame &f, int x, int y) {
    size_t i = ((size_t)y * f.width + x) * 3;
    return std::vector<float>(f.pixels.begin() + i, f.pixels.begin() + i + 3);
}

MoveCount compare_moved(const Frame &ref, const Frame &moved) {
    MoveCount m;
    for (int y = 0; y < ref.height; y++)
        for (int x = 0; x < ref.width; x++) {
            std::vector<float> a = px(ref, x, y), b = px(moved, x, y);
            if (a == b) continue;
            m.differ++;
            bool edge = false, seen = false;
            for (int dy = -1; dy <= 1; dy++)
                for (int dx = -1; dx <= 1; dx++) {
                    int u = x + dx, v = y + dy;
                    if (u < 0 || v < 0 || u >= ref.width || v >= ref.height) continue;
                    std::vector<float> n = px(ref, u, v);
                    if (n != a) edge = true;
                    if (n == b) seen = true;
                }
            if (edge && seen)
                m.edge++;
            else {
                m.holes++;
                if (m.first_hole.empty())
                    m.first_hole = "pixel (" + std::to_string(x) + ", " + std::to_string(y) + "): " + num(a[0]) + " " + num(a[1]) + " " +
                                   num(a[2]) + " became " + num(b[0]) + " " + num(b[1]) + " " + num(b[2]);
            }
        }
    return m;
}

const V3 MOVE_DIR = {0.6180339887, -0.3713906763, 0.2360679775};

MoveCount move_run(double dist, const Frame &ref_flat, int size) {
    Place pl;
    pl.m = 1;
    pl.T = MOVE_DIR * dist;
    testkit::Result r = testkit::run(test_scene(pl, true, size, size));
    MoveCount m;
    if (r.status != PRAY_OK || r.frames.size() != 1) {
        m.ok = false;
        m.error = r.error;
        return m;
    }
    m = compare_moved(ref_flat, r.frames[0]);
    return m;
}

// the largest change of a channel between two images of the same size
double max_channel_change(const Frame &a, const Frame &b) {
    double m = 0;
    for (size_t i = 0; i < a.pixels.size() && i < b.pixels.size(); i++) m = std::max(m, (double)std::fabs(a.pixels[i] - b.pixels[i]));
    return m;
}

Frame moved_shaded(double dist, int size) {
    Place pl;
    pl.m = 1;
    pl.T = MOVE_DIR * dist;
    return render_program(test_scene(pl, false, size, size));
}

}  // namespace

TEST_CASE("stability: the scene moved up to 1e6 units (double) or 1e4 units (float): no holes, differences only at edges") {
    // float: positions carry an absolute rounding of |T| * 2^-24; at |T| = 1e4 that is 6e-4 units,
    // a hundredth of a pixel here (a pixel is about 0.06 units wide at the scene); from |T| = 3e5
    // on, surfaces closer than that rounding (the tube's wall at a slant, the lens' rim) break up
    // into holes (docs/testing.md, "Stability envelope").
    const bool fl = float_build();
    const double max_dist = fl ? 1e4 : 1e6;
    // shaded images (phong, mirrors, glass, shadows): the largest change of a channel allowed;
    // double measured 6e-8 at 1e6; float 1.4e-3 at 1e3, 0.5 at 1e4 (a shadow edge moves by a pixel)
    const double shade_tol = fl ? 4.0 / 255 : 1e-6;
    const double shade_max_dist = fl ? 1e3 : 1e6;
    const int size = 64;
    Place unitp;
    unitp.m = 1;
    unitp.T = v3(0, 0, 0);
    Frame ref = render_program(test_scene(unitp, true, size, size)), ref_shaded = render_program(test_scene(unitp, false, size, size));
    REQUIRE(ref.width == size);
    REQUIRE(ref_shaded.width == size);
    std::string report, holes;
    for (double dist = 1; dist <= max_dist * 1.0001; dist *= 10) {
        for (double f : {1.0, 3.7}) {
            double d = dist * f;
            if (d > max_dist * 1.0001) continue;
            MoveCount m = move_run(d, ref, size);
            REQUIRE_MESSAGE(m.ok, m.error);
            report += "\n  |T| = " + num(d) + ": " + std::to_string(m.differ) + " pixels differ, " + std::to_string(m.edge) +
                      " at edges, " + std::to_string(m.holes) + " holes";
            if (m.holes) holes += "\n  |T| = " + num(d) + ": " + m.first_hole;
            // edges: at most 1% of the image
            CHECK_MESSAGE(m.edge <= size * size / 100, "|T| = " << d << ": " << m.edge << " edge pixels differ");
            if (d <= shade_max_dist * 1.0001) {
                double change = max_channel_change(ref_shaded, moved_shaded(d, size));
                report += ", shaded image: largest change " + num(change);
                CHECK_MESSAGE(change <= shade_tol, "|T| = " << d << ": a shaded pixel changed by " << change);
            }
        }
    }
    MESSAGE("moved scenes (" << std::string(fl ? "float" : "double") << "):" << report);
    CHECK_MESSAGE(holes.empty(), "holes or speckles in the moved scene:" << holes);
}

TEST_CASE("stability (PRAY_STABILITY_WIDE): how far the scene can be moved"
          * doctest::skip(!wide())) {
    const int size = 64;
    Place unitp;
    unitp.m = 1;
    unitp.T = v3(0, 0, 0);
    Frame ref = render_program(test_scene(unitp, true, size, size)), ref_shaded = render_program(test_scene(unitp, false, size, size));
    std::string report;
    for (double d = 1; d <= 1e15; d *= std::sqrt(10.0)) {
        MoveCount m = move_run(d, ref, size);
        report +=
            "\n  |T| = " + num(d) + ": " +
            (m.ok ? std::to_string(m.differ) + " differ, " + std::to_string(m.edge) + " at edges, " + std::to_string(m.holes) + " holes"
                  : "fails: " + m.error);
        if (m.ok) report += "; shaded: largest change " + num(max_channel_change(ref_shaded, moved_shaded(d, size)));
    }
    MESSAGE("moved scenes (" << std::string(float_build() ? "float" : "double") << "):" << report);
}

// =============================================================================================
// Coincident faces
// =============================================================================================
// Solids of half-spaces whose faces coincide by design (A \ B and A & B sharing faces, boxes that
// touch, cubes built from shared half-spaces and their complements), built along different
// rounding paths (parts moved and turned separately, the turn split in two), then turned and
// moved as a whole. Every half-space has its own flat colour. An independent ray caster in long
// double follows each pixel's ray through the half-spaces and the set expression, and knows
// where the ray first enters the solid, and through which face or set of exactly coincident
// faces. A pixel is a speckle when
//   - it shows a colour that is not one of those faces' (or not the background where the ray
//     misses), or
//   - among the pixels whose rays enter through the same set of coincident faces, it shows
//     another face than the rest (pray breaks ties between coincident faces by a fixed rule).
// Pixels whose rays pass so close to an edge that the rounding of the renderer (a generous bound
// of 32 units in the last place of the magnitudes involved, divided by the cosine to the face)
// could change the order of two different faces are not judged.
namespace {

struct Op {
    int kind;  // 0: move by v, 1: turn by v (degrees about X, then Y, then Z)
    V3 v;
};
Op move(V3 v) { return Op{0, v}; }
Op turn(V3 v) { return Op{1, v}; }

std::string ops_text(const std::vector<Op> &ops) {
    std::string s;
    for (const Op &o : ops) s += " . " + (o.kind == 0 ? pt(o.v) : vc(o.v));
    return s;
}

struct LV {
    LD x, y, z;
};
LD ldot(LV a, LV b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
LV lv(V3 a) { return LV{(LD)a.x, (LD)a.y, (LD)a.z}; }

// the rotation of `.` in exact arithmetic (long double): about X, then Y, then Z
LV rotate_ld(LV p, V3 deg) {
    const LD pi = 3.141592653589793238462643383279502884L;
    LD a[3] = {(LD)deg.x * pi / 180, (LD)deg.y * pi / 180, (LD)deg.z * pi / 180};
    LD s, c, y, z, x;
    s = std::sin(a[0]), c = std::cos(a[0]);
    y = c * p.y - s * p.z, z = s * p.y + c * p.z;
    p.y = y, p.z = z;
    s = std::sin(a[1]), c = std::cos(a[1]);
    x = c * p.x + s * p.z, z = -s * p.x + c * p.z;
    p.x = x, p.z = z;
    s = std::sin(a[2]), c = std::cos(a[2]);
    x = c * p.x - s * p.y, y = s * p.x + c * p.y;
    p.x = x, p.y = y;
    return p;
}

struct HS {  // the half-space N.x <= D
    std::string name;
    V3 p, n;  // as written in the program
    int colour;
    std::vector<Op> ops;  // its own transformations
    LV N;
    LD D;
};

struct Coincident {
    std::string name;
    std::vector<HS> hs;
    std::string defs;  // program lines defining the parts from the half-spaces
    std::string expr;  // the solid, from the names
    std::function<bool(const std::vector<char> &)> inside;
    std::vector<Op> global;  // applied to the whole solid
    V3 shift;                // the oracle works in coordinates moved back by the final move
};

// flat colours: never black (the background), exact in float
V3 face_colour(int k) { return v3((k % 5 + 1) / 8.0, (k / 5 % 5 + 1) / 8.0, (k / 25 % 5 + 1) / 8.0); }
int colour_id(const Frame &f, int x, int y, int ncolours) {
    float r = f.at(x, y, 0), g = f.at(x, y, 1), b = f.at(x, y, 2);
    if (r == 0 && g == 0 && b == 0) return -1;  // background
    for (int k = 0; k < ncolours; k++) {
        V3 c = face_colour(k);
        if (r == (float)c.x && g == (float)c.y && b == (float)c.z) return k;
    }
    return -2;  // no face's colour
}

int add_hs(Coincident &s, const std::string &name, V3 p, V3 n, std::vector<Op> ops = {}) {
    HS h;
    h.name = name;
    h.p = p;
    h.n = n;
    h.colour = (int)s.hs.size();
    h.ops = ops;
    s.hs.push_back(h);
    return h.colour;
}

// A box of six half-spaces centred at the origin with half sizes hx, hy, hz, then `ops`;
// returns the index of its first half-space and defines `name` in the program.
int add_box(Coincident &s, const std::string &name, double hx, double hy, double hz, std::vector<Op> ops = {}) {
    int first = (int)s.hs.size();
    add_hs(s, name + "xh", v3(hx, 0, 0), v3(1, 0, 0), ops);
    add_hs(s, name + "xl", v3(-hx, 0, 0), v3(-1, 0, 0), ops);
    add_hs(s, name + "yh", v3(0, hy, 0), v3(0, 1, 0), ops);
    add_hs(s, name + "yl", v3(0, -hy, 0), v3(0, -1, 0), ops);
    add_hs(s, name + "zh", v3(0, 0, hz), v3(0, 0, 1), ops);
    add_hs(s, name + "zl", v3(0, 0, -hz), v3(0, 0, -1), ops);
    s.defs += name + " = " + name + "xh & " + name + "xl & " + name + "yh & " + name + "yl & " + name + "zh & " + name + "zl\n";
    return first;
}
bool in_box(const std::vector<char> &st, int first) {
    for (int i = 0; i < 6; i++)
        if (!st[first + i]) return false;
    return true;
}

// Final half-spaces in long double: the half-space's own operations, then the global ones.
// The final move of the whole solid is left out: the oracle works relative to it, so that
// coincident faces far from the origin stay coincident in long double too.
void finish(Coincident &s) {
    s.shift = v3(0, 0, 0);
    std::vector<Op> global = s.global;
    if (!global.empty() && global.back().kind == 0) {
        s.shift = global.back().v;
        global.pop_back();
    }
    for (HS &h : s.hs) {
        LV p = lv(h.p), n = lv(h.n);
        LD l = std::sqrt(ldot(n, n));
        n = LV{n.x / l, n.y / l, n.z / l};
        std::vector<Op> all = h.ops;
        all.insert(all.end(), global.begin(), global.end());
        for (const Op &o : all) {
            if (o.kind == 0) {
                p.x += o.v.x, p.y += o.v.y, p.z += o.v.z;
            } else {
                p = rotate_ld(p, o.v);
                n = rotate_ld(n, o.v);
            }
        }
        h.N = n;
        h.D = ldot(n, p);
    }
}

std::string coincident_program(const Coincident &s, const Camera &cam, int size) {
    std::string t = size_options(size, size) + "background {0}\n" + perspective(cam);
    for (const HS &h : s.hs) {
        if (h.name.empty()) continue;  // the oracle's own copy of a moved half-space
        V3 c = face_colour(h.colour);
        t += h.name + " = plane(color({" + num(c.x) + ", " + num(c.y) + ", " + num(c.z) + "}), " + pt(h.p) + ", " + vc(h.n) + ")" +
             ops_text(h.ops) + "\n";
    }
    t += s.defs;
    t += "S = (" + s.expr + ")" + ops_text(s.global) + "\n";
    t += "rendertiff S, none\n";
    return t;
}

// The scenes. `rot` turns the whole solid and `T` moves it. With `separate`, the two boxes are
// turned separately instead, B's turn split into two steps about Z (the same rotation, but
// normals that differ from A's in their last bits), and the cubes of shared half-spaces are left
// out (sharing makes their rounding the same).
std::vector<Coincident> coincident_scenes(V3 rot, V3 T, bool separate = false) {
    std::vector<Coincident> v;
    V3 half = v3(rot.x, rot.y, rot.z / 2), zhalf = v3(0, 0, rot.z / 2);
    // A (half size 1) and B (half sizes h, placed at o), turned together or separately
    auto two_boxes = [&](Coincident &s, V3 h, V3 o) {
        std::vector<Op> oa, ob = {move(o)};
        if (separate) {
            oa.push_back(turn(rot));
            ob.push_back(turn(half));
            ob.push_back(turn(zhalf));
        } else
            s.global.push_back(turn(rot));
        s.global.push_back(move(T));
        int a = add_box(s, "A", 1, 1, 1, oa);
        add_box(s, "B", h.x, h.y, h.z, ob);
        return a;
    };
    const char *suffix = separate ? ", parts turned separately" : "";
    {  // A \ B: a corner notch; B shares three faces with A (same orientation)
        Coincident s;
        s.name = std::string("notch A \\ B") + suffix;
        int a = two_boxes(s, v3(0.5, 0.5, 0.5), v3(0.5, -0.5, 0.5)), b = a + 6;
        s.expr = "A \\ B";
        s.inside = [a, b](const std::vector<char> &st) { return in_box(st, a) && !in_box(st, b); };
        v.push_back(s);
    }
    {  // A \ B: a slot right through; B shares four faces with A
        Coincident s;
        s.name = std::string("slot A \\ B") + suffix;
        int a = two_boxes(s, v3(0.2, 1, 1), v3(0.1, 0, 0)), b = a + 6;
        s.expr = "A \\ B";
        s.inside = [a, b](const std::vector<char> &st) { return in_box(st, a) && !in_box(st, b); };
        v.push_back(s);
    }
    {  // A & B: B shares four faces with A
        Coincident s;
        s.name = std::string("A & B") + suffix;
        int a = two_boxes(s, v3(1, 1, 1), v3(1, 0, 0)), b = a + 6;
        s.expr = "A & B";
        s.inside = [a, b](const std::vector<char> &st) { return in_box(st, a) && in_box(st, b); };
        v.push_back(s);
    }
    {  // boxes touching along a face (opposite orientations): A \ B is A, A | B one solid
        Coincident s;
        s.name = std::string("touching A \\ B") + suffix;
        int a = two_boxes(s, v3(0.5, 0.5, 0.5), v3(1.5, 0.2, -0.1)), b = a + 6;
        s.expr = "A \\ B";
        s.inside = [a, b](const std::vector<char> &st) { return in_box(st, a) && !in_box(st, b); };
        v.push_back(s);
        s.name = std::string("touching A | B") + suffix;
        s.expr = "A | B";
        s.inside = [a, b](const std::vector<char> &st) { return in_box(st, a) || in_box(st, b); };
        v.push_back(s);
    }
    if (!separate) {
        auto global = [&](Coincident &s) {
            s.global.push_back(turn(rot));
            s.global.push_back(move(T));
        };
        {  // three cubes in a row built from shared half-spaces and their complements
            Coincident s;
            int xl = add_hs(s, "XL", v3(-1.5, 0, 0), v3(-1, 0, 0)), x1 = add_hs(s, "X1", v3(-0.5, 0, 0), v3(1, 0, 0)),
                x2 = add_hs(s, "X2", v3(0.5, 0, 0), v3(1, 0, 0)), xr = add_hs(s, "XR", v3(1.5, 0, 0), v3(1, 0, 0)),
                yl = add_hs(s, "YL", v3(0, -0.5, 0), v3(0, -1, 0)), yh = add_hs(s, "YH", v3(0, 0.5, 0), v3(0, 1, 0)),
                zl = add_hs(s, "ZL", v3(0, 0, -0.5), v3(0, 0, -1)), zh = add_hs(s, "ZH", v3(0, 0, 0.5), v3(0, 0, 1));
            s.defs = "YZ = YL & YH & ZL & ZH\nC1 = XL & X1 & YZ\nC2 = -X1 & X2 & YZ\nC3 = -X2 & XR & YZ\n";
            auto yz = [=](const std::vector<char> &st) { return st[yl] && st[yh] && st[zl] && st[zh]; };
            auto c1 = [=](const std::vector<char> &st) { return st[xl] && st[x1] && yz(st); };
            auto c2 = [=](const std::vector<char> &st) { return !st[x1] && st[x2] && yz(st); };
            auto c3 = [=](const std::vector<char> &st) { return !st[x2] && st[xr] && yz(st); };
            global(s);
            s.name = "shared half-spaces C1 | C2 | C3";
            s.expr = "C1 | C2 | C3";
            s.inside = [=](const std::vector<char> &st) { return c1(st) || c2(st) || c3(st); };
            v.push_back(s);
            s.name = "shared half-spaces (C1 | C2 | C3) \\ C2";
            s.expr = "(C1 | C2 | C3) \\ C2";
            s.inside = [=](const std::vector<char> &st) { return (c1(st) || c2(st) || c3(st)) && !c2(st); };
            v.push_back(s);
            // C2 moved half a unit along Y and Z: its X planes are new primitives on the old planes
            s.name = "shared half-spaces (C1 | C2 | C3) \\ moved C2";
            s.expr = "(C1 | C2 | C3) \\ (C2 . [0, 0.5, 0.5])";
            // C2 . [0, 0.5, 0.5]: -X1 & X2 and the moved YZ slab, whose four half-spaces the oracle
            // keeps as copies at the end of its list (the program makes them by moving C2)
            s.inside = [=](const std::vector<char> &st) {
                size_t k = st.size() - 4;
                bool moved_c2 = !st[x1] && st[x2] && st[k] && st[k + 1] && st[k + 2] && st[k + 3];
                return (c1(st) || c2(st) || c3(st)) && !moved_c2;
            };
            v.push_back(s);
            Coincident &m = v.back();
            for (const char *nm : {"YL", "YH", "ZL", "ZH"}) {
                HS h = m.hs[nm[0] == 'Y' ? (nm[1] == 'L' ? yl : yh) : (nm[1] == 'L' ? zl : zh)];
                h.name = "";  // not in the program
                h.ops.push_back(move(v3(0, 0.5, 0.5)));
                m.hs.push_back(h);
            }
        }
    }
    for (Coincident &s : v) finish(s);
    return v;
}

// units in the last place of the renderer's rounding allowed between two faces before a pixel is
// too close to an edge to be judged (a bound, not an estimate; the exploration lowers it)
double g_margin = 32;

struct SpeckleCount {
    long judged = 0, skipped = 0, speckles = 0, background = 0, oracle_errors = 0;
    std::vector<std::string> first;
};

// Judge one image of scene s seen by camera cam.
void judge(const Coincident &s, const Camera &cam, const Frame &f, SpeckleCount &out, const std::string &label) {
    const int W = f.width, H = f.height;
    const double eps = real_eps();
    // in the oracle's coordinates (moved back by s.shift); the magnitudes the renderer rounds
    // are those of the world coordinates
    LV E = LV{(LD)cam.eye.x - s.shift.x, (LD)cam.eye.y - s.shift.y, (LD)cam.eye.z - s.shift.z};
    LV look = LV{(LD)cam.look.x - s.shift.x, (LD)cam.look.y - s.shift.y, (LD)cam.look.z - s.shift.z};
    LD mag = len(cam.eye) + len(s.shift) + 4;
    const int n = (int)s.hs.size();
    std::map<std::vector<int>, std::map<int, int>> by_group;  // coincident set -> colour -> pixels
    struct PixelCase {
        int x, y;
        std::vector<int> group;
        int got;
    };
    std::vector<PixelCase> cases;
    for (int j = 0; j < H; j++)
        for (int i = 0; i < W; i++) {
            double u = 2.0 * (i + 0.5) / W - 1.0, v = 2.0 * (j + 0.5) / H - 1.0;
            LV d = LV{look.x + u * (LD)cam.x.x + v * (LD)cam.y.x - E.x, look.y + u * (LD)cam.x.y + v * (LD)cam.y.y - E.y,
                      look.z + u * (LD)cam.x.z + v * (LD)cam.y.z - E.z};
            LD dl = std::sqrt(ldot(d, d));
            d = LV{d.x / dl, d.y / dl, d.z / dl};
            struct X {
                LD t, err;
                int hs;
                bool enter;
            };
            std::vector<X> xs;
            std::vector<char> st(n);
            for (int k = 0; k < n; k++) {
                const HS &h = s.hs[k];
                LD dn = ldot(h.N, d), s0 = ldot(h.N, E) - h.D;
                if (dn == 0) {
                    st[k] = s0 < 0;
                    continue;
                }
                LD t = -s0 / dn;
                bool enter = dn < 0;
                st[k] = enter ? t < 0 : t > 0;
                if (t > 0) xs.push_back(X{t, g_margin * (LD)eps * (mag + std::fabs(h.D) + t) / std::fabs(dn), k, enter});
            }
            std::sort(xs.begin(), xs.end(), [](const X &a, const X &b) { return a.t < b.t; });
            // groups of exactly coincident crossings
            std::vector<std::pair<size_t, size_t>> groups;
            for (size_t a = 0; a < xs.size();) {
                size_t b = a + 1;
                while (b < xs.size() && xs[b].t - xs[a].t <= 1e-12L * (xs[a].t + 1)) b++;
                groups.push_back(std::make_pair(a, b));
                a = b;
            }
            auto gerr = [&](size_t g) {
                LD e = 0;
                for (size_t q = groups[g].first; q < groups[g].second; q++) e = std::max(e, xs[q].err);
                return e;
            };
            bool in = s.inside(st), ambiguous = false;
            int hit = -1;
            if (in) out.oracle_errors++;  // the camera inside the solid: a mistake of the test
            for (size_t g = 0; g < groups.size() && hit < 0; g++) {
                for (size_t q = groups[g].first; q < groups[g].second; q++) st[xs[q].hs] = xs[q].enter;
                if (s.inside(st)) hit = (int)g;
            }
            // too close to a neighbouring event to be sure of the order
            size_t last = hit >= 0 ? (size_t)hit + 1 : groups.size() - 1;
            for (size_t g = 0; g + 1 < groups.size() && g < last + 1 && g + 1 <= last + 1; g++)
                if (xs[groups[g + 1].first].t - xs[groups[g].first].t <= gerr(g) + gerr(g + 1)) ambiguous = true;
            if (ambiguous) {
                out.skipped++;
                continue;
            }
            out.judged++;
            int got = colour_id(f, i, j, n);
            // the faces of the group whose crossing the entry needs: with all the group's other
            // crossings done but not this one's, the ray would still be outside
            std::vector<int> group;
            if (hit >= 0)
                for (size_t q = groups[hit].first; q < groups[hit].second; q++) {
                    std::vector<char> without = st;
                    without[xs[q].hs] = !xs[q].enter;
                    if (!s.inside(without)) group.push_back(s.hs[xs[q].hs].colour);
                }
            std::sort(group.begin(), group.end());
            if (hit >= 0 && group.empty()) out.oracle_errors++;  // an entry needing no face
            if (hit < 0) out.background++;
            bool allowed = hit < 0 ? got == -1 : std::find(group.begin(), group.end(), got) != group.end();
            if (!allowed) {
                out.speckles++;
                if (out.first.size() < 8) {
                    std::string g;
                    for (int k : group) g += " " + (s.hs[k].name.empty() ? "moved copy" : s.hs[k].name);
                    out.first.push_back(label + ", pixel (" + std::to_string(i) + ", " + std::to_string(j) + "): shows " +
                                        (got == -1   ? std::string("the background")
                                         : got == -2 ? std::string("an unknown colour")
                                                     : s.hs[got].name) +
                                        ", expected " + (hit < 0 ? std::string("the background") : "one of" + g));
                }
                continue;
            }
            if (hit >= 0 && group.size() > 1) {
                by_group[group][got]++;
                cases.push_back(PixelCase{i, j, group, got});
            }
        }
    // one face per set of coincident faces
    for (const PixelCase &c : cases) {
        const std::map<int, int> &m = by_group[c.group];
        int best = -1, bestn = -1;
        for (auto &kv : m)
            if (kv.second > bestn) best = kv.first, bestn = kv.second;
        if (c.got != best) {
            out.speckles++;
            if (out.first.size() < 8)
                out.first.push_back(label + ", pixel (" + std::to_string(c.x) + ", " + std::to_string(c.y) + "): shows " +
                                    s.hs[c.got].name + " where the rest of its coincident faces show " + s.hs[best].name);
        }
    }
}

std::vector<V3> view_directions() {
    return {v3(1, -2, 1.5), v3(-1.5, -1, 0.8), v3(2, 1, -1), v3(-0.5, 2, 2), v3(0.3, -1, -0.4), v3(-2, 0.7, -1.3)};
}

SpeckleCount coincident_run(const std::vector<V3> &rots, const std::vector<V3> &moves, bool separate, int size,
                            const std::vector<std::string> &options, std::string *per_scene = nullptr) {
    SpeckleCount total;
    std::map<std::string, long> speckles_by_scene;
    for (V3 rot : rots)
        for (V3 T : moves)
            for (const Coincident &s : coincident_scenes(rot, T, separate))
                for (V3 dir : view_directions()) {
                    LV c = lv(v3(0, 0, 0));
                    for (const Op &o : s.global) {
                        if (o.kind == 0) c.x += o.v.x, c.y += o.v.y, c.z += o.v.z;
                    }
                    V3 look = v3((double)c.x, (double)c.y, (double)c.z);
                    Camera cam = aim(look + unit(dir) * 7, look, 1.9);
                    Frame f = render_program(coincident_program(s, cam, size), options);
                    if (f.width != size) continue;
                    std::string label = s.name + ", turned " + vc(rot) + ", moved " + pt(T) + ", seen from " + vc(dir);
                    long before = total.speckles;
                    judge(s, cam, f, total, label);
                    speckles_by_scene[s.name] += total.speckles - before;
                    dump(f, "coincident-" + std::to_string(speckles_by_scene.size()) + "-" + std::to_string(total.judged));
                }
    if (per_scene)
        for (auto &kv : speckles_by_scene) *per_scene += "\n    " + kv.first + ": " + std::to_string(kv.second);
    return total;
}

std::string speckle_text(const SpeckleCount &c) {
    std::string s = std::to_string(c.judged) + " pixels judged (" + std::to_string(c.background) + " background), " +
                    std::to_string(c.skipped) + " too close to an edge, " + std::to_string(c.speckles) + " speckles";
    for (const std::string &f : c.first) s += "\n  - " + f;
    return s;
}

}  // namespace

TEST_CASE("stability: coincident faces (A \\ B, A & B, touching boxes, cubes of shared half-spaces) show no speckle, from six "
          "views, turned and moved as a whole") {
    const std::vector<V3> rots = {v3(0, 0, 0), v3(10, 20, 30), v3(-37, 51, 163)};
    const std::vector<V3> moves = {v3(0, 0, 0), v3(0.1, 0.2, 0.3), v3(12.3, -45.6, 7.89), v3(1000.1, -2000.2, 500.3)};
    std::string per;
    SpeckleCount c = coincident_run(rots, moves, false, 48, {}, &per);
    MESSAGE(speckle_text(c) << "\n  speckles by scene:" << per);
    CHECK(c.judged > 100000);
    CHECK(c.oracle_errors == 0);
    // float: the positions 2000 units from the origin round to 1e-4, and pixels within a few
    // times that of an edge are not judged
    CHECK(c.skipped < c.judged / (float_build() ? 5 : 100));
    CHECK_MESSAGE(c.speckles == 0, speckle_text(c));
}

// Defect S1 (docs/testing.md; fixed: key components are rounded to representatives first): snapping compared only neighbours in the lexicographic
// order of (normal, offset), so two coincident faces whose normals differ in the last bit are
// kept apart by a parallel face at another offset that sorts between them (the opposite face of
// B), and are never snapped: A \ B and A & B with B turned in two steps speckle all over the
// shared faces (double build; in float the normals round to the same numbers).
TEST_CASE("stability: coincident faces of boxes turned separately (B's turn in two steps) show no speckle") {
    const std::vector<V3> rots = {v3(10, 20, 30), v3(-37, 51, 163)};
    const std::vector<V3> moves = {v3(0, 0, 0), v3(12.3, -45.6, 7.89)};
    std::string per;
    SpeckleCount c = coincident_run(rots, moves, true, 48, {}, &per);
    MESSAGE(speckle_text(c) << "\n  speckles by scene:" << per);
    CHECK(c.judged > 20000);
    CHECK(c.oracle_errors == 0);
    CHECK_MESSAGE(c.speckles == 0, speckle_text(c));
}

TEST_CASE("stability (PRAY_STABILITY_WIDE): coincident faces moved far from the origin"
          * doctest::skip(!wide())) {
    std::string report;
    g_margin = 2;  // judge closer to the edges: a speckle there may be an edge's honest rounding
    for (double d = 1e3; d <= 1e15; d *= 10) {
        SpeckleCount c = coincident_run({v3(10, 20, 30)}, {MOVE_DIR * d}, false, 48, {});
        report += "\n  |T| = " + num(d) + ": " + std::to_string(c.judged) + " judged, " + std::to_string(c.skipped) + " near edges, " +
                  std::to_string(c.speckles) + " speckles";
        if (!c.first.empty()) report += " (" + c.first[0] + ")";
    }
    g_margin = 32;
    MESSAGE("coincident faces (" << std::string(float_build() ? "float" : "double") << "), turned <10, 20, 30>, margin 2 ulps:" << report);
}

// =============================================================================================
// Self-intersection: secondary rays must not meet the surface they start on
// =============================================================================================
// pray gives a secondary ray the primitive it starts on and leaves that primitive's crossing at
// the start out by identity (pray.hpp, 6.). These tests look at what a self-hit would do to
// pixels whose values are known exactly, at radii (sizes) R from 1e-3 to 1e6, the solids placed
// at a fixed point Q = (0.3, 0.7, -0.2) (so that small solids sit where the coordinates are large
// compared with them) and seen by a parallel camera:
//   - shadow acne: a lit diffuse sphere and a lit tilted box, one light; every pixel facing the
//     light by more than 0.05 must be ambient + diffuse * N.L (a self-hit leaves the ambient);
//   - refraction exits: glass (weight T = 0.5) against a plain background C: a sphere (n = 1.5),
//     a tilted cube (n = 1), a thin shell of thickness R/1000 (n = 1) and a thin tilted plate of
//     thickness R/1000 (n = 1.5): every pixel must be T^2 C or T^4 C, as many surfaces as the ray
//     crosses (a self-hit adds a factor T, a missed exit removes one);
//   - thin occluders: an opaque plate of thickness R/1000 above a floor: the floor in its shadow
//     must be ambient only (a shadow ray slipping between the plate's faces leaks light), and the
//     plate's lit top must be lit.
namespace {

const V3 ANCHOR = {0.3, 0.7, -0.2};
const V3 SKY = {0.8, 0.6, 0.4};  // the background of the glass scenes

struct Expect {
    bool judged;
    V3 colour;
};

// a parallel camera looking along `dir` at the point `at`, window half size `half`
struct Ortho {
    V3 x, y, eye, at;
};
Ortho ortho(V3 at, V3 dir, double half, double back) {
    Ortho c;
    V3 d = unit(dir);
    V3 up = std::fabs(d.z) > 0.9 ? v3(0, 1, 0) : v3(0, 0, 1);
    c.x = unit(cross(d, up)) * half;
    c.y = unit(cross(d, c.x)) * half;
    c.eye = at - d * back;
    c.at = at;
    return c;
}
struct SelfScene {
    std::string name, program;
    Ortho cam;                                 // the program's camera
    std::function<Expect(LV o, LV d)> oracle;  // from the pixel's ray
    double tol;                                // per channel
};

std::string ortho_text(const Ortho &c) { return "parallel " + vc(c.x) + ", " + vc(c.y) + ", " + pt(c.eye) + ", " + pt(c.at) + "\n"; }

LV lsub(LV a, LV b) { return LV{a.x - b.x, a.y - b.y, a.z - b.z}; }
LV ladd(LV a, LV b) { return LV{a.x + b.x, a.y + b.y, a.z + b.z}; }
LV lmul(LV a, LD s) { return LV{a.x * s, a.y * s, a.z * s}; }
LV lunit(LV a) { return lmul(a, 1 / std::sqrt(ldot(a, a))); }
LV lcross(LV a, LV b) { return LV{a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }

// the ray through a sphere: the parameter of entry, or -1; `rel` the closest approach over r
LD sphere_entry(LV o, LV d, LV c, LD r, LD *rel) {
    LV oc = lsub(o, c);
    LD b = ldot(oc, d);
    LV perp = lsub(oc, lmul(d, b));
    LD q = std::sqrt(ldot(perp, perp));
    *rel = q / r;
    if (q >= r) return -1;
    return -b - std::sqrt(r * r - q * q);
}

// A convex polyhedron of planes N.x <= D (unit N): the entry parameter and face, or -1; `margin`
// the distance (along the ray) from the entry to the nearest other event that would make it an
// edge, relative to the size `size`.
struct Planes {
    std::vector<LV> N;
    std::vector<LD> D;
};
LD convex_entry(const Planes &P, LV o, LV d, int *face, LD *edge) {
    LD t0 = -1e300L, t1 = 1e300L, second = -1e300L;
    *face = -1;
    for (size_t k = 0; k < P.N.size(); k++) {
        LD dn = ldot(P.N[k], d), s0 = ldot(P.N[k], o) - P.D[k];
        if (dn == 0) {
            if (s0 >= 0) return -1;
            continue;
        }
        LD t = -s0 / dn;
        if (dn < 0) {
            if (t > t0)
                second = t0, t0 = t, *face = (int)k;
            else if (t > second)
                second = t;
        } else if (t < t1)
            t1 = t;
    }
    if (t0 >= t1) return -1;
    *edge = std::min(t0 - second, t1 - t0);
    return t0;
}

// a box of half sizes h turned by `deg` about its centre c, as planes
Planes box_planes(V3 c, V3 h, V3 deg) {
    Planes P;
    V3 axes[3] = {v3(1, 0, 0), v3(0, 1, 0), v3(0, 0, 1)};
    double hs[3] = {h.x, h.y, h.z};
    for (int a = 0; a < 3; a++)
        for (int s = -1; s <= 1; s += 2) {
            LV n = rotate_ld(lv(axes[a] * s), deg);
            P.N.push_back(n);
            P.D.push_back(ldot(n, lv(c)) + hs[a]);
        }
    return P;
}
std::string box_text(const std::string &model, V3 c, V3 h, V3 deg) {
    return "((plane(" + model + ", [" + num(h.x) + ", 0, 0], <1, 0, 0>) & plane(" + model + ", [" + num(-h.x) +
           ", 0, 0], <-1, 0, 0>) & plane(" + model + ", [0, " + num(h.y) + ", 0], <0, 1, 0>) & plane(" + model + ", [0, " + num(-h.y) +
           ", 0], <0, -1, 0>) & plane(" + model + ", [0, 0, " + num(h.z) + "], <0, 0, 1>) & plane(" + model + ", [0, 0, " + num(-h.z) +
           "], <0, 0, -1>)) . " + vc(deg) + " . " + pt(c) + ")";
}

const V3 LIGHT = {-0.35, 0.5, -0.8};  // the direction the light travels
const char *DIFFUSE = "phong({0.5}, {0}, {0.1}, 1)";

V3 lit(LV n) {
    LV l = lunit(lmul(lv(LIGHT), -1));
    LD nl = ldot(n, l);
    double v = 0.1 + 0.5 * (double)(nl > 0 ? nl : 0);
    return v3(v, v, v);
}

std::vector<SelfScene> self_scenes(double R, double thin = 1e-3) {
    std::vector<SelfScene> v;
    const V3 Q = ANCHOR;
    const double tol_shade = 2e-3;
    std::string head = "background {0}\n";
    std::string glass_head = "background " + std::string("{") + num(SKY.x) + ", " + num(SKY.y) + ", " + num(SKY.z) + "}\n";
    auto light = [](void) { return "dirlight({1}, " + vc(LIGHT) + ")"; };
    {  // a lit sphere seen from the side of the light
        Ortho cam = ortho(Q, v3(-0.2, 1, -0.6), 1.1 * R, 4 * R);
        SelfScene s;
        s.cam = cam;
        s.name = "acne: lit sphere";
        s.program = head + ortho_text(cam) + "rendertiff sphere(" + DIFFUSE + ", " + pt(Q) + ", " + num(R) + "), " + light() + "\n";
        LV c = lv(Q);
        LD r = R;
        s.oracle = [c, r](LV o, LV d) {
            LD rel, t = sphere_entry(o, d, c, r, &rel);
            if (t < 0 || rel > 0.98) return Expect{false, V3{0, 0, 0}};
            LV n = lunit(lsub(ladd(o, lmul(d, t)), c));
            LD nl = ldot(n, lunit(lmul(lv(LIGHT), -1)));
            if (std::fabs(nl) < 0.05) return Expect{false, V3{0, 0, 0}};  // near the terminator
            return Expect{true, lit(n)};
        };
        s.tol = tol_shade;
        v.push_back(s);
    }
    {  // a lit tilted box
        Ortho cam = ortho(Q, v3(-0.2, 1, -0.6), 1.1 * R, 4 * R);
        V3 h = v3(0.6 * R, 0.45 * R, 0.5 * R), deg = v3(20, 30, 40);
        Planes P = box_planes(Q, h, deg);
        SelfScene s;
        s.cam = cam;
        s.name = "acne: lit tilted box";
        s.program = head + ortho_text(cam) + "rendertiff " + box_text(DIFFUSE, v3(0, 0, 0), h, deg) + " . " + pt(Q) + ", " + light() + "\n";
        s.oracle = [P, R](LV o, LV d) {
            int f;
            LD edge, t = convex_entry(P, o, d, &f, &edge);
            if (t < 0 || edge < 0.01L * R) return Expect{false, V3{0, 0, 0}};
            LD nl = ldot(P.N[f], lunit(lmul(lv(LIGHT), -1)));
            if (std::fabs(nl) < 0.05) return Expect{false, V3{0, 0, 0}};
            return Expect{true, lit(P.N[f])};
        };
        s.tol = tol_shade;
        v.push_back(s);
    }
    const double T = 0.5;  // the glass' weight
    auto glass_colour = [T](int crossings) {
        double f = std::pow(T, crossings);
        return v3(f * SKY.x, f * SKY.y, f * SKY.z);
    };
    {  // a glass sphere, n = 1.5: two crossings for every ray through it
        Ortho cam = ortho(Q, v3(0.3, 1, 0.2), 1.1 * R, 4 * R);
        SelfScene s;
        s.cam = cam;
        s.name = "refraction: glass sphere n = 1.5";
        s.program =
            glass_head + ortho_text(cam) + "rendertiff sphere(transparent({" + num(T) + "}, 1.5), " + pt(Q) + ", " + num(R) + "), none\n";
        LV c = lv(Q);
        LD r = R;
        s.oracle = [c, r, glass_colour](LV o, LV d) {
            LD rel, t = sphere_entry(o, d, c, r, &rel);
            if (rel > 0.98 && rel < 1.02) return Expect{false, V3{0, 0, 0}};
            return Expect{true, glass_colour(t < 0 ? 0 : 2)};
        };
        s.tol = 1e-6;
        v.push_back(s);
    }
    {  // a tilted glass cube, n = 1 (no total internal reflection): two crossings
        Ortho cam = ortho(Q, v3(0.3, 1, 0.2), 1.1 * R, 4 * R);
        V3 h = v3(0.6 * R, 0.6 * R, 0.6 * R), deg = v3(35, -20, 15);
        Planes P = box_planes(Q, h, deg);
        SelfScene s;
        s.cam = cam;
        s.name = "refraction: tilted glass cube n = 1";
        s.program = glass_head + ortho_text(cam) + "rendertiff " + box_text("transparent({" + num(T) + "}, 1)", v3(0, 0, 0), h, deg) +
                    " . " + pt(Q) + ", none\n";
        s.oracle = [P, R, glass_colour](LV o, LV d) {
            int f;
            LD edge, t = convex_entry(P, o, d, &f, &edge);
            if (t >= 0 && edge < 0.01L * R) return Expect{false, V3{0, 0, 0}};
            if (t < 0) {  // also not judged just outside an edge
                LV o2 = o;
                for (int k = 0; k < 4; k++) {
                    LV n = lunit(lcross(d, LV{(LD)(k == 0) - (k == 1), (LD)(k == 2) - (k == 3), 0.5L}));
                    int f2;
                    LD e2;
                    if (convex_entry(P, ladd(o2, lmul(n, 0.01L * R)), d, &f2, &e2) >= 0) return Expect{false, V3{0, 0, 0}};
                }
            }
            return Expect{true, glass_colour(t < 0 ? 0 : 2)};
        };
        s.tol = 1e-6;
        v.push_back(s);
    }
    {  // a thin glass shell, n = 1: four crossings through the hollow, two through the wall only
        Ortho cam = ortho(Q, v3(0.3, 1, 0.2), 1.1 * R, 4 * R);
        double ri = R * (1 - thin);
        SelfScene s;
        s.cam = cam;
        s.name = "refraction: thin glass shell n = 1";
        s.program = glass_head + ortho_text(cam) + "G = transparent({" + num(T) + "}, 1)\nrendertiff sphere(G, " + pt(Q) + ", " + num(R) +
                    ") - sphere(G, " + pt(Q) + ", " + num(ri) + "), none\n";
        LV c = lv(Q);
        LD r = R, rin = ri;
        s.oracle = [c, r, rin, glass_colour](LV o, LV d) {
            LD rel, t = sphere_entry(o, d, c, r, &rel);
            LD q = rel * r;
            if (std::fabs(q - r) < 0.02L * r || std::fabs(q - rin) < 0.02L * r) return Expect{false, V3{0, 0, 0}};
            return Expect{true, glass_colour(t < 0 ? 0 : q < rin ? 4 : 2)};
        };
        s.tol = 1e-6;
        v.push_back(s);
    }
    {  // a thin tilted glass plate, n = 1.5: its faces are parallel, so no total reflection
        Ortho cam = ortho(Q, v3(0.3, 1, 0.2), 1.1 * R, 4 * R);
        V3 h = v3(0.8 * R, thin * R / 2, 0.8 * R), deg = v3(25, 0, 30);
        Planes P = box_planes(Q, h, deg);
        SelfScene s;
        s.cam = cam;
        s.name = "refraction: thin glass plate n = 1.5";
        s.program = glass_head + ortho_text(cam) + "rendertiff " + box_text("transparent({" + num(T) + "}, 1.5)", v3(0, 0, 0), h, deg) +
                    " . " + pt(Q) + ", none\n";
        // judged where the ray enters through a large face far from the rim (it enters a smaller
        // plate of the same thickness), or misses by far
        Planes rim = box_planes(Q, v3(0.7 * R, h.y, 0.7 * R), deg), outer = box_planes(Q, v3(0.9 * R, h.y, 0.9 * R), deg);
        s.oracle = [P, rim, outer, glass_colour](LV o, LV d) {
            int f;
            LD e;
            bool inner = convex_entry(rim, o, d, &f, &e) >= 0, near = convex_entry(outer, o, d, &f, &e) >= 0;
            if (inner) return Expect{true, glass_colour(2)};
            if (!near) return Expect{true, glass_colour(0)};
            return Expect{false, V3{0, 0, 0}};
        };
        s.tol = 1e-6;
        v.push_back(s);
    }
    {  // a thin opaque plate above a floor, lit from above: its shadow, and its lit top
        Ortho cam = ortho(Q, v3(0.5, 0.8, -1), 1.6 * R, 4 * R);
        V3 pc = Q + v3(0, 0, 0.5 * R), h = v3(0.6 * R, 0.6 * R, thin * R / 2), deg = v3(8, -5, 20);
        Planes P = box_planes(pc, h, deg);
        double floor_z = Q.z - 0.5 * R;
        SelfScene s;
        s.cam = cam;
        s.name = "thin occluder: plate above a floor";
        s.program = head + ortho_text(cam) + "rendertiff plane(" + DIFFUSE + ", " + pt(v3(Q.x, Q.y, floor_z)) + ", <0, 0, 1>) | " +
                    box_text(DIFFUSE, v3(0, 0, 0), h, deg) + " . " + pt(pc) + ", " + light() + "\n";
        // plates of the same thickness: a ray entering the smaller one crosses both large faces
        // of the real one; a ray missing the larger one misses the real one
        Planes rim = box_planes(pc, v3(0.5 * R, 0.5 * R, h.z), deg), outer = box_planes(pc, v3(0.7 * R, 0.7 * R, h.z), deg);
        s.oracle = [P, rim, outer, floor_z](LV o, LV d) {
            int f;
            LD edge, t = convex_entry(P, o, d, &f, &edge);
            if (t >= 0) {  // the plate: judge its top, away from the rim
                int f2;
                LD e2;
                if (P.N[f].z > 0.9L && convex_entry(rim, o, d, &f2, &e2) >= 0) return Expect{true, lit(P.N[f])};
                return Expect{false, V3{0, 0, 0}};
            }
            LD tf = ((LD)floor_z - o.z) / d.z;
            LV x = ladd(o, lmul(d, tf));
            LV up = lunit(lmul(lv(LIGHT), -1));
            int f2;
            LD e2;
            // the shadow ray from the floor: through the plate's inner part, or clear of its outer part
            if (convex_entry(rim, x, up, &f2, &e2) >= 0) return Expect{true, v3(0.1, 0.1, 0.1)};
            if (convex_entry(outer, x, up, &f2, &e2) < 0 && convex_entry(outer, o, d, &f2, &e2) < 0) return Expect{true, lit(LV{0, 0, 1})};
            return Expect{false, V3{0, 0, 0}};
        };
        s.tol = tol_shade;
        v.push_back(s);
    }
    return v;
}

struct SelfCount {
    long judged = 0, wrong = 0;
    std::string first;
};

SelfCount self_run(const SelfScene &s, int size, const std::string &label) {
    SelfCount c;
    Frame f = render_program(size_options(size, size) + s.program);
    if (f.width != size) {
        c.wrong = -1;
        return c;
    }
    std::string file = "self-" + label;
    for (char &ch : file)
        if (!std::isalnum((unsigned char)ch) && ch != '.' && ch != '-') ch = '_';
    dump(f, file);
    const Ortho &cam = s.cam;
    LV d = lunit(lsub(lv(cam.at), lv(cam.eye)));
    for (int j = 0; j < size; j++)
        for (int i = 0; i < size; i++) {
            double u = 2.0 * (i + 0.5) / size - 1.0, v = 2.0 * (j + 0.5) / size - 1.0;
            LV o = ladd(ladd(lv(cam.eye), lmul(lv(cam.x), u)), lmul(lv(cam.y), v));
            Expect e = s.oracle(o, d);
            if (!e.judged) continue;
            c.judged++;
            double err = std::max(std::fabs(f.at(i, j, 0) - e.colour.x),
                                  std::max(std::fabs(f.at(i, j, 1) - e.colour.y), std::fabs(f.at(i, j, 2) - e.colour.z)));
            if (err > s.tol) {
                if (!c.wrong++)
                    c.first = "pixel (" + std::to_string(i) + ", " + std::to_string(j) + ") is " + num(f.at(i, j, 0)) + " " +
                              num(f.at(i, j, 1)) + " " + num(f.at(i, j, 2)) + ", expected " + num(e.colour.x) + " " + num(e.colour.y) +
                              " " + num(e.colour.z);
            }
        }
    return c;
}

}  // namespace

TEST_CASE("stability: no self-intersection of shadow, refracted and thin-occluder rays at radii 1e-3 .. 1e6") {
    // float: a solid of radius R at Q, |Q| = 0.8, is placed to within 2^-24 |Q|; at R = 1e-3 its
    // thin parts (R/1000 = 1e-6) are still 16 units in the last place thick
    std::string report, failures;
    for (double R = 1e-3; R <= 1e6 * 1.0001; R *= 10) {
        for (const SelfScene &s : self_scenes(R)) {
            SelfCount c = self_run(s, 48, s.name + "-" + num(R));
            report +=
                "\n  R = " + num(R) + ", " + s.name + ": " + std::to_string(c.judged) + " judged, " + std::to_string(c.wrong) + " wrong";
            CHECK_MESSAGE(c.judged > 200, "R = " << R << ", " << s.name << ": only " << c.judged << " pixels judged");
            if (c.wrong)
                failures += "\n  R = " + num(R) + ", " + s.name + ": " + std::to_string(c.wrong) + " wrong pixels, first " + c.first;
        }
    }
    MESSAGE(report);
    CHECK_MESSAGE(failures.empty(), "self-intersections:" << failures);
}

// Defect S2 (docs/testing.md; fixed: twins, primitives of the same surface, all count as the start): a shadow (or reflected) ray starting on a face that the
// union shares with another part of the union is not protected from that other part: the twin
// face, snapped to the same plane, finds the start a unit in the last place inside and the ray
// "leaves" the solid at t ~ 1e-16, a hit that shadows the point. Shadow acne on part of the
// shared face, in both builds.
TEST_CASE("stability: no shadow acne on a face shared by two parts of a union, R = 1e-3 .. 1e6") {
    std::string report, failures;
    for (double R = 1e-3; R <= 1e6 * 1.0001; R *= 10) {
        const V3 Q = ANCHOR, deg = v3(10, 20, 30);
        Ortho cam = ortho(Q, v3(-0.2, 1, -0.6), 1.1 * R, 4 * R);
        // two boxes overlapping in x, the same top and bottom: the top face is shared where they overlap
        V3 ha = v3(0.4 * R, 0.5 * R, 0.4 * R), ca = v3(-0.2 * R, 0, 0), hb = v3(0.4 * R, 0.4 * R, 0.4 * R), cb = v3(0.2 * R, 0.1 * R, 0);
        std::vector<Planes> P;
        for (int k = 0; k < 2; k++) {
            V3 c = k ? cb : ca, h = k ? hb : ha;
            Planes b;
            V3 axes[3] = {v3(1, 0, 0), v3(0, 1, 0), v3(0, 0, 1)};
            double hs[3] = {h.x, h.y, h.z};
            for (int a = 0; a < 3; a++)
                for (int sg = -1; sg <= 1; sg += 2) {
                    LV n = rotate_ld(lv(axes[a] * sg), deg);
                    LV pc = rotate_ld(lv(c), deg);
                    b.N.push_back(n);
                    b.D.push_back(ldot(n, ladd(pc, lv(Q))) + hs[a]);
                }
            P.push_back(b);
        }
        SelfScene s;
        s.cam = cam;
        s.name = "acne: union of two boxes sharing their top face";
        s.program = "background {0}\n" + ortho_text(cam) + "rendertiff (" + box_text(DIFFUSE, ca, ha, v3(0, 0, 0)) + " | " +
                    box_text(DIFFUSE, cb, hb, v3(0, 0, 0)) + ") . " + vc(deg) + " . " + pt(Q) + ", dirlight({1}, " + vc(LIGHT) + ")\n";
        s.tol = 2e-3;
        s.oracle = [P, R](LV o, LV d) {
            LD best = -1, edge_best = 0;
            int fb = -1;
            for (const Planes &b : P) {
                int f;
                LD e, t = convex_entry(b, o, d, &f, &e);
                if (t < 0) continue;
                if (best < 0 || t < best - 1e-9L * R)
                    best = t, fb = f, edge_best = e;
                else if (std::fabs(t - best) <= 1e-9L * R)
                    edge_best = std::min(edge_best, e);
            }
            if (best < 0 || edge_best < 0.01L * R) return Expect{false, V3{0, 0, 0}};
            LV n = P[0].N[fb];
            LD nl = ldot(n, lunit(lmul(lv(LIGHT), -1)));
            if (std::fabs(nl) < 0.05) return Expect{false, V3{0, 0, 0}};
            return Expect{true, lit(n)};
        };
        SelfCount c = self_run(s, 48, "union-" + num(R));
        report += "\n  R = " + num(R) + ": " + std::to_string(c.judged) + " judged, " + std::to_string(c.wrong) + " wrong";
        CHECK(c.judged > 200);
        if (c.wrong) failures += "\n  R = " + num(R) + ": " + std::to_string(c.wrong) + " acne pixels, first " + c.first;
    }
    MESSAGE(report);
    CHECK_MESSAGE(failures.empty(), "shadow acne on the shared face:" << failures);
}

TEST_CASE("stability (PRAY_STABILITY_WIDE): self-intersection at radii 1e-16 .. 1e16 and thicknesses down to 1e-15"
          * doctest::skip(!wide())) {
    std::string report;
    auto sweep = [&](const std::string &what, const std::vector<std::pair<double, double>> &cases) {
        std::map<std::string, std::string> first_bad, last_good;
        for (auto rc : cases)
            for (const SelfScene &s : self_scenes(rc.first, rc.second)) {
                SelfCount c = self_run(s, 48, "wide");
                std::string at = "R = " + num(rc.first) + " thin = " + num(rc.second);
                if (c.wrong && !first_bad.count(s.name))
                    first_bad[s.name] =
                        at + " (" + std::to_string(c.wrong) + " of " + std::to_string(c.judged) + " wrong: " + c.first + ")";
                if (!c.wrong && !first_bad.count(s.name)) last_good[s.name] = at;
            }
        report += "\n  " + what + ":";
        for (auto &kv : last_good)
            report += "\n    " + kv.first + ": holds through " + kv.second +
                      (first_bad.count(kv.first) ? ", breaks at " + first_bad[kv.first] : "");
        for (auto &kv : first_bad)
            if (!last_good.count(kv.first)) report += "\n    " + kv.first + ": breaks at once, " + kv.second;
    };
    std::vector<std::pair<double, double>> up, down, thin;
    for (double R = 1; R <= 1e16 * 1.0001; R *= 10) up.push_back(std::make_pair(R, 1e-3));
    for (double R = 1; R >= 1e-16 * 0.9999; R /= 10) down.push_back(std::make_pair(R, 1e-3));
    for (double t = 1e-3; t >= 1e-16; t /= 10) thin.push_back(std::make_pair(1.0, t));
    sweep("radius growing from 1", up);
    sweep("radius shrinking from 1", down);
    sweep("thickness shrinking from R/1e3 (R = 1)", thin);
    MESSAGE("self-intersection (" << std::string(float_build() ? "float" : "double") << "):" << report);
}

// =============================================================================================
// Grazing and tangent rays: hit or miss against an exact decision
// =============================================================================================
// Rays passing a sphere's centre, or a cylinder's axis, at r (1 + delta), for delta from +-1e-1
// down to +-1e-17, from origins 3 to 1000 radii away, the solids at the origin or far from it.
// The reference decides hit or miss from the very doubles handed to pray_intersect, in long
// double: the distance of the line from the centre (|(c - o) x d| / |d|) or from the axis
// (|(p - o) . (d x a)| / |d x a|, or for rays parallel to the axis the distance of o from it),
// compared with r. Its own rounding is bounded (a few units of 2^-64 times the lengths
// involved); rays within that bound of tangency are undecided and not counted. pray must agree
// wherever |delta| exceeds its own rounding: K units of roundoff of the largest coordinate
// involved (|o|, |c|, |o - c|, r; over the sine of the angle to a cylinder's axis), over r, with
// K measured (docs/testing.md). Rays nearly along the axis cross it at 1e-2 .. 1e-6 radians.
namespace {

struct Graze {
    int kind;  // 0 sphere, 1 cylinder across, 2 cylinder along the axis, 3 cylinder nearly along
    V3 o, d, c, a;
    double r;
    double target;   // the delta aimed at
    double cap = 0;  // kind 2: the cylinder is cut to |(x - c) . a| <= cap, and the ray starts before it
};

struct Rng64 {
    unsigned long long s;
    explicit Rng64(unsigned long long seed) : s(seed * 0x9E3779B97F4A7C15ull + 12345) {}
    unsigned long long next() {
        unsigned long long z = (s += 0x9E3779B97F4A7C15ull);
        z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
        z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
        return z ^ (z >> 31);
    }
    double uni() { return (double)(next() >> 11) * (1.0 / 9007199254740992.0); }
    double range(double a, double b) { return a + (b - a) * uni(); }
    V3 dir() {
        for (;;) {
            V3 v = v3(range(-1, 1), range(-1, 1), range(-1, 1));
            double l = len(v);
            if (l > 0.1 && l <= 1) return v * (1 / l);
        }
    }
};

// exact (long double) signed clearance over r: > 0 misses, < 0 hits; *undecided when the
// reference's own rounding could change the sign
LD graze_exact(const Graze &g, bool *undecided) {
    const LD u = std::ldexp((LD)1, -LDBL_MANT_DIG + 1);
    LV o = lv(g.o), d = lv(g.d), c = lv(g.c);
    LD dist, bound;
    if (g.kind == 0) {
        LV v = lsub(c, o), x = lcross(v, d);
        LD dl = std::sqrt(ldot(d, d)), vl = std::sqrt(ldot(v, v));
        dist = std::sqrt(ldot(x, x)) / dl;
        bound = 16 * u * (vl + std::fabs((LD)g.c.x) + std::fabs((LD)g.c.y) + std::fabs((LD)g.c.z) + (LD)g.r);
    } else {
        LV a = lv(g.a), v = lsub(c, o), x = lcross(d, a);
        LD xl = std::sqrt(ldot(x, x)), vl = std::sqrt(ldot(v, v));
        if (xl == 0) {  // parallel: the distance of o from the axis
            LV y = lcross(v, a);
            dist = std::sqrt(ldot(y, y)) / std::sqrt(ldot(a, a));
            bound = 16 * u * (vl + (LD)g.r);
        } else {
            dist = std::fabs(ldot(v, x)) / xl;
            LD sn = xl / std::sqrt(ldot(d, d) * ldot(a, a));
            bound = 16 * u * (vl + (LD)g.r) / sn;
        }
    }
    LD rel = (dist - (LD)g.r) / (LD)g.r;
    *undecided = std::fabs(rel) * (LD)g.r <= bound;
    return rel;
}

// A ray from `o` passing `c` at r (1 + delta); for cylinders the closest approach to the axis
// line through c along a.
Graze make_graze(Rng64 &rng, int kind, double r, double dist, V3 centre, double delta) {
    Graze g;
    g.kind = kind;
    g.r = r;
    g.c = centre;
    g.target = delta;
    double q = r * (1 + delta);
    if (kind == 0) {
        V3 v = rng.dir();
        g.o = centre - v * dist;  // c - o = v * dist
        V3 w = unit(cross(v, rng.dir()));
        double s = q / dist, co = std::sqrt(1 - s * s);
        // the line through o along co v + s w passes c at dist * s = q
        g.d = v * co + w * s;
        g.a = v3(0, 0, 0);
    } else {
        g.a = rng.dir();
        V3 u = unit(cross(g.a, rng.dir())), w = cross(g.a, u);
        if (kind == 1 || kind == 3) {
            // the closest point of the axis: c; the ray crosses the line c + q u along a
            // direction in the plane of w and a, at an angle of at least 0.1 to the axis
            // (kind 1) or of 1e-2 .. 1e-6 radians to the axis itself (kind 3)
            double ang = kind == 1 ? rng.range(0.1, 1.5) * (rng.uni() < 0.5 ? 1 : -1) : std::pow(10.0, -rng.range(2, 6));
            g.d = kind == 1 ? w * std::cos(ang) + g.a * std::sin(ang) : g.a * std::cos(ang) + w * std::sin(ang);
            g.o = centre + u * q - g.d * dist;
        } else {
            // parallel to the axis, at distance q from it: the direction is the axis itself; the
            // cylinder is cut by two caps, and the ray enters through the near one or misses it
            g.d = g.a;
            g.cap = dist;
            g.o = centre + u * q - g.a * (2 * dist + rng.range(0, dist));
        }
    }
    return g;
}

// pray's answer: does the ray enter the solid (any hit)?
int pray_hits(const Graze &g, bool use_brute, pray_ctx *ctx) {
    pray_model *m = pray_color(ctx, rgb(1, 1, 1));
    pray_object *s = g.kind == 0 ? pray_sphere(ctx, m, pv(g.c), g.r) : pray_cylinder(ctx, m, pv(g.c), pv(g.a), g.r);
    if (g.cap > 0) {
        V3 an = unit(g.a);
        s = pray_csg(ctx, PRAY_INTERSECTION, s, pray_plane(ctx, m, pv(g.c + an * g.cap), pv(g.a)));
        s = pray_csg(ctx, PRAY_INTERSECTION, s, pray_plane(ctx, m, pv(g.c - an * g.cap), pv(g.a * -1)));
    }
    if (!s) return -1;
    pray_option(ctx, "brute", use_brute ? 1 : 0);
    pray_scene *q = pray_prepare(ctx, s);
    if (!q) return -1;
    pray_hit h[4];
    int n = pray_intersect(ctx, q, pv(g.o), pv(g.d), HUGE_VAL, h, 4);
    pray_scene_free(ctx, q);
    pray_release(ctx, s);
    pray_release(ctx, m);
    return n;
}

struct GrazeStats {
    long rays = 0, undecided = 0, judged = 0, disagree = 0;
    double worst_k = 0;  // the largest |delta| r / (eps * magnitude) among disagreements
    std::string first;
};

const char *graze_kind(int k) {
    return k == 0   ? "sphere"
           : k == 1 ? "cylinder, across"
           : k == 2 ? "cylinder (capped), along the axis"
                    : "cylinder, nearly along the axis";
}

// magnitude of the coordinates pray rounds for this ray; for a ray crossing a cylinder's axis at
// a small angle, divided by the sine of the angle: the point of closest approach is that much
// less well defined
double graze_mag(const Graze &g) {
    double m = std::max(std::max(len(g.o), len(g.c)), std::max(len(g.o - g.c), g.r));
    if (g.kind == 1 || g.kind == 3) m /= len(cross(unit(g.d), unit(g.a)));
    return m;
}

void graze_check(pray_ctx *ctx, const Graze &g, double k_tol, GrazeStats &st) {
    st.rays++;
    long before = st.disagree;
    bool und;
    LD rel = graze_exact(g, &und);
    if (und) {
        st.undecided++;
        return;
    }
    bool want = rel < 0;
    const double eps = real_eps();
    double k = (double)std::fabs(rel) * g.r / (eps * graze_mag(g));
    for (int b = 0; b < 2; b++) {
        int n = pray_hits(g, b == 1, ctx);
        if (n < 0) {
            st.disagree++;
            if (st.first.empty()) st.first = std::string("pray failed: ") + pray_error(ctx);
            continue;
        }
        if (g.kind == 2 && n > 0 && n != 2) {  // a capped cylinder from outside: 0 or 2 hits
            st.disagree++;
            continue;
        }
        bool got = n > 0;
        if (got == want) continue;
        if (k < k_tol) {  // within pray's rounding: either answer is right
            continue;
        }
        st.disagree++;
        st.worst_k = std::max(st.worst_k, k);
        if (st.first.empty()) {
            char b2[600];
            std::snprintf(
                b2, sizeof b2,
                "%s%s r=%.17g c=(%.17g, %.17g, %.17g) a=(%.17g, %.17g, %.17g) o=(%.17g, %.17g, %.17g) d=(%.17g, %.17g, %.17g): exact "
                "clearance %.3Lg r (%s), pray %d hits",
                graze_kind(g.kind), b ? " (brute)" : "", g.r, g.c.x, g.c.y, g.c.z, g.a.x, g.a.y, g.a.z, g.o.x, g.o.y, g.o.z, g.d.x, g.d.y,
                g.d.z, rel, want ? "hit" : "miss", n);
            st.first = b2;
        }
    }
    if (st.disagree > before) st.disagree = before + 1;  // brute and the default: one ray
    st.judged++;
}

}  // namespace

namespace {

// every configuration: kind x radius x distance x placement x delta, a few random rays each
template <class F> void graze_sweep(F f) {
    Rng64 rng(20261123);
    const double radii[] = {1e-3, 1, 1e3};
    const double dists[] = {3, 30, 1000};
    for (int kind = 0; kind < 4; kind++)
        for (double r : radii)
            for (double dr : dists)
                for (int place = 0; place < 3; place++) {
                    // at the origin; 100 radii away; at a fixed point far from small solids
                    V3 c = place == 0 ? v3(0, 0, 0) : place == 1 ? v3(61.8, -37.1, 23.6) * r : v3(1000.3, -500.7, 250.1);
                    for (int e = 1; e <= 17; e++)
                        for (int sg = -1; sg <= 1; sg += 2)
                            for (int rep = 0; rep < 3; rep++) {
                                double delta = sg * std::pow(10.0, -e) * rng.range(1, 9.9);
                                f(make_graze(rng, kind, r, dr * r, c, delta));
                            }
                }
}

}  // namespace

TEST_CASE("stability: grazing and tangent rays on spheres and cylinders: hit or miss as the exact (long double) answer") {
    // pray must agree wherever the clearance exceeds K units of roundoff (DBL_EPSILON or
    // FLT_EPSILON) of the largest coordinate involved (over the sine of the angle to a
    // cylinder's axis); over this sweep every disagreement was within 0.37 (double) and 0.35
    // (float) of them (PRAY_STABILITY_WIDE prints it); asserted with K = 2
    const double K = 2;
    pray_ctx *ctx = pray_new();
    REQUIRE(ctx);
    GrazeStats st[4];
    graze_sweep([&](const Graze &g) { graze_check(ctx, g, K, st[g.kind]); });
    std::string report, failures;
    for (int k = 0; k < 4; k++) {
        report += std::string("\n  ") + graze_kind(k) + ": " + std::to_string(st[k].rays) + " rays, " + std::to_string(st[k].undecided) +
                  " undecided by long double, " + std::to_string(st[k].judged) + " judged, " + std::to_string(st[k].disagree) + " disagree";
        if (st[k].disagree) failures += std::string("\n  ") + graze_kind(k) + ": " + st[k].first;
        CHECK(st[k].judged > 1000);
    }
    MESSAGE(report);
    CHECK_MESSAGE(failures.empty(), "pray disagrees with the exact answer beyond " << K << " units in the last place:" << failures);
    // exactly tangent, axis-aligned (exact in floating point): no hit
    for (double r : {1e-3, 1.0, 1e3}) {
        Graze g;
        g.kind = 0;
        g.r = r;
        g.c = v3(0.25 * r, -0.5 * r, 0.75 * r);
        g.o = g.c + v3(-5 * r, 0, r);
        g.d = v3(1, 0, 0);
        g.a = v3(0, 0, 0);
        CHECK(pray_hits(g, false, ctx) == 0);
        CHECK(pray_hits(g, true, ctx) == 0);
        g.kind = 2;  // along a cylinder's surface
        g.a = v3(1, 0, 0);
        CHECK(pray_hits(g, false, ctx) == 0);
        CHECK(pray_hits(g, true, ctx) == 0);
        g.kind = 1;  // across a cylinder, touching it
        g.a = v3(0, 1, 0);
        CHECK(pray_hits(g, false, ctx) == 0);
        CHECK(pray_hits(g, true, ctx) == 0);
    }
    pray_free(ctx);
}

TEST_CASE("stability (PRAY_STABILITY_WIDE): how close to tangency pray's hit or miss is right"
          * doctest::skip(!wide())) {
    pray_ctx *ctx = pray_new();
    // per kind and exponent of delta: rays judged and disagreeing; the largest K of a disagreement
    std::map<int, std::map<int, std::pair<long, long>>> table;
    GrazeStats st[4];
    graze_sweep([&](const Graze &g) {
        long before = st[g.kind].disagree;
        graze_check(ctx, g, 0, st[g.kind]);
        int e = (int)std::lround(-std::log10(std::fabs(g.target)) - 0.5);
        table[g.kind][e].first++;
        table[g.kind][e].second += st[g.kind].disagree - before;
    });
    std::string report;
    for (int k = 0; k < 4; k++) {
        report += std::string("\n  ") + graze_kind(k) + ": largest K of a disagreement " + num(st[k].worst_k) +
                  "; by |delta| (disagreeing / rays):";
        for (auto &kv : table[k])
            report += " 1e-" + std::to_string(kv.first) + ": " + std::to_string(kv.second.second) + "/" + std::to_string(kv.second.first);
        if (!st[k].first.empty()) report += "\n    first: " + st[k].first;
    }
    MESSAGE("grazing rays (" << std::string(float_build() ? "float" : "double") << "):" << report);
    pray_free(ctx);
}

// =============================================================================================
// The grid and every switch against --brute, on the scaled, moved and coincident scenes
// =============================================================================================
// tests/test_accel.cpp compares every combination of grid x freeze x merge x bounds with the
// brute-force reference on random scenes (those of K_SCALED scaled by 1e-3 .. 1e6 and moved up to
// 1e11) and on the examples. Added here: the scenes of this file, whose coordinates are scaled by
// 2^k and moved far away, and whose faces coincide: their images float for float (with shadows,
// mirrors and glass, so secondary rays too), and adversarial rays hit for hit (the same count,
// primitives, sides and ray parameters, bit for bit).
namespace {

const int SWITCH_GRIDS[] = {0, 1, 2, 3, 5, 8, 16, -1};

struct Switches {
    int grid, freeze, merge, bounds;
    std::string text() const {
        return "grid=" + std::to_string(grid) + " freeze=" + std::to_string(freeze) + " merge=" + std::to_string(merge) +
               " bounds=" + std::to_string(bounds);
    }
    std::vector<std::string> fixed() const {
        return {"brute=0", "grid=" + std::to_string(grid), "freeze=" + std::to_string(freeze), "merge=" + std::to_string(merge),
                "bounds=" + std::to_string(bounds)};
    }
};
std::vector<Switches> every_switch() {
    std::vector<Switches> v;
    for (int g : SWITCH_GRIDS)
        for (int f = 0; f < 2; f++)
            for (int m = 0; m < 2; m++)
                for (int b = 0; b < 2; b++) v.push_back(Switches{g, f, m, b});
    return v;
}

// every switch combination renders the program as --brute does; returns the differences
std::string images_against_brute(const std::string &program, const std::string &label, long *renders) {
    testkit::Result ref = testkit::run(program, {"brute=1"});
    if (ref.status != PRAY_OK || ref.frames.size() != 1) return "\n  " + label + ": --brute failed: " + ref.error;
    std::string bad;
    int shown = 0;
    for (const Switches &sw : every_switch()) {
        testkit::Result r = testkit::run(program, sw.fixed());
        ++*renders;
        long d = r.status == PRAY_OK && r.frames.size() == 1 ? differing_pixels(ref.frames[0], r.frames[0]) : -1;
        if (d != 0 && shown++ < 4)
            bad += "\n  " + label + ", " + sw.text() + ": " +
                   (d < 0 ? "failed: " + r.error : std::to_string(d) + " pixels differ from --brute");
    }
    if (shown > 4) bad += "\n  " + label + ": ... " + std::to_string(shown) + " combinations differ";
    return bad;
}

// The scene of test_scene() built through the API (for pray_prepare), with two parts that have
// coincident faces, and the features adversarial rays are aimed at.
struct Feature {
    int kind;  // 0 sphere (c, r), 1 plane face (c on it, n normal, u in it), 2 point (c), 3 cylinder (c on axis, n axis, r)
    V3 c, n, u;
    double r;
};
struct ApiScene {
    pray_object *root = nullptr;
    std::vector<Feature> features;
    V3 lo, hi;  // where the scene is
};

V3 rot_d(V3 p, V3 deg) {
    LV q = rotate_ld(lv(p), deg);
    return v3((double)q.x, (double)q.y, (double)q.z);
}

pray_object *api_box(pray_ctx *c, pray_model *m, V3 h) {
    pray_object *b = nullptr;
    V3 n[6] = {v3(1, 0, 0), v3(-1, 0, 0), v3(0, 1, 0), v3(0, -1, 0), v3(0, 0, 1), v3(0, 0, -1)};
    double hs[6] = {h.x, h.x, h.y, h.y, h.z, h.z};
    for (int k = 0; k < 6; k++) {
        pray_object *p = pray_plane(c, m, pv(n[k] * hs[k]), pv(n[k]));
        b = b ? pray_csg(c, PRAY_INTERSECTION, b, p) : p;
    }
    return b;
}

ApiScene api_test_scene(pray_ctx *c, const Place &pl) {
    ApiScene s;
    pray_model *m = pray_phong(c, rgb(0.6, 0.6, 0.6), rgb(0.2, 0.2, 0.2), rgb(0.1, 0.1, 0.1), 10);
    auto add = [&](pray_object *o) { s.root = s.root ? pray_csg(c, PRAY_UNION, s.root, o) : o; };
    auto box_features = [&](V3 h, V3 deg, V3 at) {
        V3 axes[3] = {v3(1, 0, 0), v3(0, 1, 0), v3(0, 0, 1)};
        double hs[3] = {h.x, h.y, h.z};
        for (int a = 0; a < 3; a++)
            for (int sg = -1; sg <= 1; sg += 2) {
                Feature f;
                f.kind = 1;
                f.n = rot_d(axes[a] * sg, deg);
                f.c = rot_d(axes[a] * (sg * hs[a]), deg) + at;
                f.u = rot_d(axes[(a + 1) % 3], deg);
                f.r = 0;
                s.features.push_back(f);
            }
        for (int k = 0; k < 8; k++) {
            Feature f;
            f.kind = 2;
            f.c = rot_d(v3(k & 1 ? h.x : -h.x, k & 2 ? h.y : -h.y, k & 4 ? h.z : -h.z), deg) + at;
            f.n = f.u = v3(0, 0, 0);
            f.r = 0;
            s.features.push_back(f);
        }
    };
    auto sphere_feature = [&](V3 ctr, double r) {
        Feature f;
        f.kind = 0;
        f.c = ctr;
        f.r = r;
        f.n = f.u = v3(0, 0, 0);
        s.features.push_back(f);
    };
    auto cylinder_feature = [&](V3 p, V3 axis, double r) {
        Feature f;
        f.kind = 3;
        f.c = p;
        f.n = unit(axis);
        f.r = r;
        f.u = v3(0, 0, 0);
        s.features.push_back(f);
    };
    // floor
    add(pray_plane(c, m, pv(pl.P(0, 0, -1)), pv(v3(0, 0, 1))));
    {
        Feature f;
        f.kind = 1;
        f.c = pl.P(0, 0, -1);
        f.n = v3(0, 0, 1);
        f.u = v3(1, 0, 0);
        f.r = 0;
        s.features.push_back(f);
    }
    // block: a cube minus a cylinder, turned and moved
    {
        V3 h = v3(pl.L(0.55), pl.L(0.55), pl.L(0.55)), deg = v3(15, 25, 35), at = pl.P(-1.1, 0.6, -0.3);
        pray_object *b =
            pray_csg(c, PRAY_DIFFERENCE, api_box(c, m, h), pray_cylinder(c, m, pv(v3(0, 0, 0)), pv(v3(0.2, 1, 0.3)), pl.L(0.25)));
        add(pray_translate(c, pray_rotate(c, b, pv(deg)), pv(at)));
        box_features(h, deg, at);
        cylinder_feature(at, rot_d(v3(0.2, 1, 0.3), deg), pl.L(0.25));
    }
    // ball minus ball
    {
        V3 at = pl.P(1.0, 0.4, -0.35);
        pray_object *b = pray_csg(c, PRAY_DIFFERENCE, pray_sphere(c, m, pv(v3(0, 0, 0)), pl.L(0.6)),
                                  pray_sphere(c, m, pv(pl.Lv(0.35, -0.3, 0.35)), pl.L(0.35)));
        add(pray_translate(c, b, pv(at)));
        sphere_feature(at, pl.L(0.6));
        sphere_feature(at + pl.Lv(0.35, -0.3, 0.35), pl.L(0.35));
    }
    // lens
    {
        V3 deg = v3(70, 0, 20), at = pl.P(0.1, -1.6, -0.2);
        pray_object *b = pray_csg(c, PRAY_INTERSECTION, pray_sphere(c, m, pv(pl.Lv(0, 0, -0.6)), pl.L(0.8)),
                                  pray_sphere(c, m, pv(pl.Lv(0, 0, 0.6)), pl.L(0.8)));
        add(pray_translate(c, pray_rotate(c, b, pv(deg)), pv(at)));
        sphere_feature(rot_d(pl.Lv(0, 0, -0.6), deg) + at, pl.L(0.8));
        sphere_feature(rot_d(pl.Lv(0, 0, 0.6), deg) + at, pl.L(0.8));
    }
    // rod: a capped cylinder
    {
        V3 deg = v3(0, 30, -20), at = pl.P(0.3, 1.2, 0);
        pray_object *b = pray_csg(c, PRAY_INTERSECTION, pray_cylinder(c, m, pv(v3(0, 0, 0)), pv(v3(0, 0, 1)), pl.L(0.12)),
                                  pray_plane(c, m, pv(pl.Lv(0, 0, 0.9)), pv(v3(0, 0, 1))));
        b = pray_csg(c, PRAY_INTERSECTION, b, pray_plane(c, m, pv(pl.Lv(0, 0, -0.9)), pv(v3(0, 0, -1))));
        add(pray_translate(c, pray_rotate(c, b, pv(deg)), pv(at)));
        cylinder_feature(at, rot_d(v3(0, 0, 1), deg), pl.L(0.12));
    }
    // a notch: A \ B, B sharing three faces with A, B turned in two steps
    {
        V3 deg = v3(10, 20, 30), at = pl.P(-0.4, 2.2, 0.7);
        pray_object *a = pray_rotate(c, api_box(c, m, v3(pl.L(0.4), pl.L(0.4), pl.L(0.4))), pv(deg));
        pray_object *b = pray_translate(c, api_box(c, m, v3(pl.L(0.2), pl.L(0.2), pl.L(0.2))), pv(pl.Lv(0.2, -0.2, 0.2)));
        b = pray_rotate(c, pray_rotate(c, b, pv(v3(10, 20, 15))), pv(v3(0, 0, 15)));
        add(pray_translate(c, pray_csg(c, PRAY_DIFFERENCE, a, b), pv(at)));
        box_features(v3(pl.L(0.4), pl.L(0.4), pl.L(0.4)), deg, at);
    }
    // a union of two boxes sharing their top face
    {
        V3 deg = v3(-5, 10, 40), at = pl.P(1.6, 1.9, -0.5);
        pray_object *a = pray_translate(c, api_box(c, m, v3(pl.L(0.3), pl.L(0.25), pl.L(0.2))), pv(pl.Lv(-0.15, 0, 0)));
        pray_object *b = pray_translate(c, api_box(c, m, v3(pl.L(0.3), pl.L(0.2), pl.L(0.2))), pv(pl.Lv(0.15, 0.05, 0)));
        add(pray_translate(c, pray_rotate(c, pray_csg(c, PRAY_UNION, a, b), pv(deg)), pv(at)));
        box_features(v3(pl.L(0.3), pl.L(0.25), pl.L(0.2)), deg, at + rot_d(pl.Lv(-0.15, 0, 0), deg));
    }
    s.lo = pl.P(-2.5, -2.5, -1.2);
    s.hi = pl.P(2.5, 3, 1.5);
    return s;
}

struct Probe {
    V3 o, d;
    double tmax;
    std::string kind;
};

std::vector<Probe> adversarial_rays(const ApiScene &s, Rng64 &rng) {
    std::vector<Probe> v;
    V3 C = (s.lo + s.hi) * 0.5;
    double ext = len(s.hi - s.lo), far = 2 * ext;
    auto push = [&](V3 o, V3 d, const char *k) {
        if (len(d) > 0) v.push_back(Probe{o, d, HUGE_VAL, k});
    };
    auto axis = [&](int a, double sg) { return v3(a == 0 ? sg : 0, a == 1 ? sg : 0, a == 2 ? sg : 0); };
    for (const Feature &f : s.features) {
        if (f.kind == 0) {  // tangent to the sphere, from outside and from its box's corner
            for (int i = 0; i < 3; i++) {
                V3 d = rng.dir(), u = unit(cross(d, rng.dir()));
                push(f.c + u * f.r - d * far, d, "tangent to a sphere");
            }
            push(f.c + v3(f.r, f.r, f.r), v3(-1, -1, -1), "through a sphere's box corner");
            push(f.c, rng.dir(), "from a sphere's centre");
        } else if (f.kind == 1) {  // in the face's plane, and through it at a grazing angle
            V3 w = cross(f.n, f.u);
            push(f.c - f.u * far, f.u, "in a face");
            push(f.c - (f.u + w) * far, f.u + w, "in a face, diagonal");
            push(f.c - (f.u - f.n * 1e-9) * far, f.u - f.n * 1e-9, "grazing a face");
        } else if (f.kind == 2) {  // through a corner, from several directions, and along the axes
            for (int i = 0; i < 2; i++) {
                V3 d = rng.dir();
                push(f.c - d * far, d, "through a corner");
            }
            int a = (int)(rng.next() % 3);
            push(f.c - axis(a, 1) * far, axis(a, 1), "axis-parallel through a corner");
            push(f.c, v3(1, 1, 1), "from a corner");
        } else {  // along the cylinder's surface, and tangent across it
            V3 u = unit(cross(f.n, rng.dir()));
            push(f.c + u * f.r - f.n * far, f.n, "along a cylinder's surface");
            V3 w = cross(f.n, u);
            push(f.c + u * f.r - w * far, w, "tangent across a cylinder");
        }
    }
    for (int i = 0; i < 40; i++) {  // random rays from outside into the scene, and axis-parallel rays
        V3 t = v3(rng.range(s.lo.x, s.hi.x), rng.range(s.lo.y, s.hi.y), rng.range(s.lo.z, s.hi.z));
        V3 o = C + rng.dir() * far;
        push(o, t - o, "random");
        int a = (int)(rng.next() % 3);
        V3 p = t;
        if (a == 0) p.x = s.lo.x - ext;
        if (a == 1) p.y = s.lo.y - ext;
        if (a == 2) p.z = s.lo.z - ext;
        push(p, axis(a, 1), "axis-parallel");
    }
    return v;
}

std::string fmt_hit_list(int n, const pray_hit *h, int shown) {
    std::string s = std::to_string(n) + " hits";
    for (int i = 0; i < n && i < shown; i++) {
        char b[96];
        std::snprintf(b, sizeof b, " [t=%.17g prim %d %s]", h[i].t, h[i].primitive, h[i].entering ? "in" : "out");
        s += b;
    }
    return s;
}

// every switch combination against --brute on the adversarial rays of one scene
std::string rays_against_brute(const Place &pl, const std::string &label, long *comparisons) {
    pray_ctx *c = pray_new();
    ApiScene s = api_test_scene(c, pl);
    if (!s.root) {
        std::string e = pray_error(c);
        pray_free(c);
        return "\n  " + label + ": the scene failed: " + e;
    }
    Rng64 rng(77);
    std::vector<Probe> rays = adversarial_rays(s, rng);
    const int MAXH = 32;
    pray_option(c, "brute", 1);
    pray_scene *ref = pray_prepare(c, s.root);
    if (!ref) {
        std::string e = pray_error(c);
        pray_free(c);
        return "\n  " + label + ": --brute failed to prepare: " + e;
    }
    // shadow-like copies: the same ray ending exactly at one of its hits
    const size_t n0 = rays.size();
    for (size_t i = 0; i < n0; i++) {
        pray_hit h[MAXH];
        int n = pray_intersect(c, ref, pv(rays[i].o), pv(rays[i].d), rays[i].tmax, h, MAXH);
        if (n > 0 && rng.uni() < 0.3) {
            Probe p = rays[i];
            p.tmax = h[(int)(rng.next() % (unsigned)std::min(n, MAXH))].t;
            p.kind += ", tmax at a hit";
            rays.push_back(p);
        }
    }
    std::vector<std::vector<pray_hit>> want2(rays.size(), std::vector<pray_hit>(MAXH));
    std::vector<int> wn2(rays.size());
    for (size_t i = 0; i < rays.size(); i++)
        wn2[i] = pray_intersect(c, ref, pv(rays[i].o), pv(rays[i].d), rays[i].tmax, want2[i].data(), MAXH);
    pray_scene_free(c, ref);
    std::string bad;
    int shown = 0;
    for (const Switches &sw : every_switch()) {
        pray_option(c, "brute", 0);
        pray_option(c, "grid", sw.grid);
        pray_option(c, "freeze", sw.freeze);
        pray_option(c, "merge", sw.merge);
        pray_option(c, "bounds", sw.bounds);
        pray_scene *q = pray_prepare(c, s.root);
        if (!q) {
            bad += "\n  " + label + ", " + sw.text() + ": prepare failed: " + pray_error(c);
            continue;
        }
        for (size_t i = 0; i < rays.size(); i++) {
            std::vector<pray_hit> h(MAXH);
            int n = pray_intersect(c, q, pv(rays[i].o), pv(rays[i].d), rays[i].tmax, h.data(), MAXH);
            ++*comparisons;
            bool same = n == wn2[i];
            for (int k = 0; same && k < n && k < MAXH; k++)
                same = h[k].primitive == want2[i][k].primitive && h[k].entering == want2[i][k].entering && h[k].t == want2[i][k].t;
            if (!same && shown++ < 6) {
                char b[400];
                std::snprintf(b, sizeof b, "o=(%.17g, %.17g, %.17g) d=(%.17g, %.17g, %.17g) tmax=%.17g", rays[i].o.x, rays[i].o.y,
                              rays[i].o.z, rays[i].d.x, rays[i].d.y, rays[i].d.z, rays[i].tmax);
                bad += "\n  " + label + ", " + sw.text() + ", " + rays[i].kind + " ray " + b + "\n      --brute " +
                       fmt_hit_list(wn2[i], want2[i].data(), 6) + "\n      got     " + fmt_hit_list(n, h.data(), 6);
            }
        }
        pray_scene_free(c, q);
    }
    if (shown > 6) bad += "\n  " + label + ": " + std::to_string(shown) + " mismatches in all";
    pray_free(c);
    return bad;
}

}  // namespace

TEST_CASE("stability: every switch gives --brute's images and hits on the scaled, moved and coincident scenes") {
    const bool fl = float_build();
    long renders = 0, comparisons = 0;
    std::string bad;
    // images: the shaded scene scaled by 2^-20 and 2^20, moved by 1e3 and 1e6 (float: 1e3, 1e4);
    // two coincident scenes
    std::vector<std::pair<Place, std::string>> places;
    for (int k : {-20, 20}) places.push_back(std::make_pair(Place{std::ldexp(1.0, k), v3(0, 0, 0)}, "scaled by 2^" + std::to_string(k)));
    for (double d : {1e3, fl ? 1e4 : 1e6}) places.push_back(std::make_pair(Place{1, MOVE_DIR * d}, "moved by " + num(d)));
    for (auto &p : places) bad += images_against_brute(test_scene(p.first, false, 24, 24), p.second, &renders);
    {
        std::vector<Coincident> cs = coincident_scenes(v3(10, 20, 30), v3(12.3, -45.6, 7.89));
        Camera cam = aim(v3(12.3, -45.6, 7.89) + unit(v3(1, -2, 1.5)) * 7, v3(12.3, -45.6, 7.89), 1.9);
        for (size_t i = 0; i < cs.size(); i += 3) bad += images_against_brute(coincident_program(cs[i], cam, 24), cs[i].name, &renders);
    }
    // rays: the same scene through the API, with a notch and a union sharing a face, at those
    // scales and places
    places.push_back(std::make_pair(Place{1, v3(0, 0, 0)}, "unit"));
    for (auto &p : places) bad += rays_against_brute(p.first, p.second, &comparisons);
    MESSAGE(renders << " renders and " << comparisons << " ray comparisons against --brute");
    CHECK(renders > 300);
    CHECK(comparisons > 50000);
    CHECK_MESSAGE(bad.empty(), "differences from --brute:" << bad);
}

// Defect S3 (docs/testing.md, reported): the box of an intersection of tilted half-spaces is
// found from the vertices of the polyhedron cut by stand-in planes at +-1e30 (polyhedron_box, BIG)
// where a side of its box is unbounded. A solid reaching beyond 1e30 gets a box cut there, too
// small on the other axes, and the grid (with bounds) drops the part of it outside: at scale
// 2^101 the scene of these tests loses 3 pixels of its tilted cube against --brute (2^100 and
// 2^102 are fine). The float build cannot reach 1e30 with this scene (its squares overflow from
// 2^55 on) and checks 2^40 .. 2^48 instead. Fixed: the stand-in planes are placed relative to the
// scene's own size.
TEST_CASE("stability: every switch gives --brute's image with coordinates near 1e30 (scale 2^96 .. 2^104; float: 2^40 .. 2^48)") {
    const int k0 = float_build() ? 40 : 96;
    long renders = 0;
    std::string bad;
    for (int k = k0; k <= k0 + 8; k++) {
        Place pl{std::ldexp(1.0, k), v3(0, 0, 0)};
        std::string program = test_scene(pl, true, 64, 64);
        testkit::Result ref = testkit::run(program, {"brute=1"}), def = testkit::run(program);
        renders += 2;
        REQUIRE(ref.frames.size() == 1);
        REQUIRE(def.frames.size() == 1);
        long d = differing_pixels(ref.frames[0], def.frames[0]);
        if (d) bad += "\n  2^" + std::to_string(k) + ": " + std::to_string(d) + " pixels differ from --brute with the default switches";
    }
    CHECK_MESSAGE(bad.empty(), "differences from --brute:" << bad);
}

TEST_CASE("stability (PRAY_STABILITY_WIDE): switches against --brute at extreme scales and distances"
          * doctest::skip(!wide())) {
    std::string report;
    const bool fl = float_build();
    std::vector<int> ks =
        fl ? std::vector<int>{-60, -50, -40, 40, 50, 54} : std::vector<int>{-500, -200, -100, -60, 60, 100, 101, 102, 200, 500};
    for (int k : ks) {
        long renders = 0, comparisons = 0;
        Place pl{std::ldexp(1.0, k), v3(0, 0, 0)};
        std::string b = images_against_brute(test_scene(pl, false, 24, 24), "2^" + std::to_string(k), &renders) +
                        rays_against_brute(pl, "2^" + std::to_string(k), &comparisons);
        report += "\n  scale 2^" + std::to_string(k) + ": " + (b.empty() ? std::string("same as --brute") : b);
    }
    for (double d = 1e7; d <= 1e13; d *= 10) {
        if (fl && d > 1e7) break;
        long renders = 0, comparisons = 0;
        Place pl{1, MOVE_DIR * d};
        std::string b = images_against_brute(test_scene(pl, false, 24, 24), "moved " + num(d), &renders) +
                        rays_against_brute(pl, "moved " + num(d), &comparisons);
        report += "\n  moved by " + num(d) + ": " + (b.empty() ? std::string("same as --brute") : b);
    }
    MESSAGE("switches against --brute (" << std::string(fl ? "float" : "double") << "):" << report);
}

// ---------------------------------------------------------------------------------------------
// The torus at every scale: its quartic is solved in units of its radius from the ray's point
// nearest its centre, so that neither its size nor its distance from the origin nor the ray's
// origin costs accuracy. Each hit is checked against the torus' own equation in long double
// (its distance from the tube's centre line minus the tube's radius), and rays aimed through
// the tube's centre line must hit, those passing beside the torus' outer circle must not.
// ---------------------------------------------------------------------------------------------
TEST_CASE("stability: torus hits lie on the torus, R = 1e-4 .. 1e6, far from the origin, from near and far") {
    const bool fl = float_build();
    const double tol = fl ? 3e-5 : 1e-10;  // of the torus' size R
    double worst = 0;
    long rays = 0, hits = 0, missed = 0, false_hits = 0;
    uint64_t seed = 12345;
    auto uni = [&]() {
        seed = seed * 6364136223846793005ULL + 1442695040888963407ULL;
        return (double)(seed >> 11) / 9007199254740992.0;
    };
    for (double R : {1e-4, 1e-2, 1.0, 1e3, 1e6}) {
        for (double off : {0.0, 1e3, 1e6}) {
            if (fl && off > 0 && off / R > 1e4) continue;  // float: the torus smaller than the rounding of its place
            for (double ratio : {0.05, 0.3, 0.9}) {
                pray_ctx *c = pray_new();
                pray_model *m = pray_color(c, pray_rgb{1, 1, 1});
                double r = R * ratio;
                pray_vec C = {off, -off / 2, off / 3}, A = {0.3, -0.5, 1};
                double al = std::sqrt(0.09 + 0.25 + 1);
                double a[3] = {0.3 / al, -0.5 / al, 1 / al};
                // two unit vectors across the axis
                double u[3] = {1, 0, -a[0] / a[2]}, ul = std::sqrt(1 + u[2] * u[2]);
                for (double &x : u) x /= ul;
                double w[3] = {a[1] * u[2] - a[2] * u[1], a[2] * u[0] - a[0] * u[2], a[0] * u[1] - a[1] * u[0]};
                pray_object *t = pray_torus(c, m, C, A, R, r);
                REQUIRE(t);
                pray_scene *q = pray_prepare(c, t);
                REQUIRE(q);
                for (int i = 0; i < 200; i++) {
                    // a target: on the tube's centre line (must hit), or beyond the outer circle
                    double ang = 2 * 3.141592653589793 * uni();
                    bool far = i % 4 == 3;
                    double rad = far ? R + r * (1.0 + 1e-3 + uni()) : R;
                    double T[3], dir[3];
                    for (int k = 0; k < 3; k++)
                        T[k] = (&C.x)[k] + rad * (std::cos(ang) * u[k] + std::sin(ang) * w[k]);
                    // from near (a few R) or far (1e4 R), in a random direction; beside the outer
                    // circle, along its tangent so that the ray stays outside
                    double dist = R * (i % 2 ? 3 + 5 * uni() : 1e4);
                    double d[3] = {uni() - 0.5, uni() - 0.5, uni() - 0.5};
                    if (far)
                        for (int k = 0; k < 3; k++) d[k] = -std::sin(ang) * u[k] + std::cos(ang) * w[k];
                    double dl = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
                    for (int k = 0; k < 3; k++) dir[k] = d[k] / dl;
                    pray_vec o = {T[0] - dist * dir[0], T[1] - dist * dir[1], T[2] - dist * dir[2]};
                    pray_vec dv = {dir[0], dir[1], dir[2]};
                    pray_hit h[8];
                    int n = pray_intersect(c, q, o, dv, HUGE_VAL, h, 8);
                    rays++;
                    if (far) {
                        false_hits += n > 0;
                        continue;
                    }
                    missed += n == 0;
                    for (int k = 0; k < n && k < 8; k++) {
                        hits++;
                        long double x[3];
                        for (int l = 0; l < 3; l++) x[l] = (long double)(&o.x)[l] + (long double)h[k].t * (&dv.x)[l] - (&C.x)[l];
                        long double ax = x[0] * a[0] + x[1] * a[1] + x[2] * a[2];
                        long double px[3] = {x[0] - ax * a[0], x[1] - ax * a[1], x[2] - ax * a[2]};
                        long double rho = std::sqrt(px[0] * px[0] + px[1] * px[1] + px[2] * px[2]);
                        long double e = std::fabs(std::sqrt((rho - R) * (rho - R) + ax * ax) - r);
                        // (beside its own accuracy, the rounding of the place of the hit in the world)
                        double rel = (double)(e / (R + 64 * real_eps() / tol * (std::fabs(off) + (fl ? dist : 0))));
                        worst = std::max(worst, rel);
                        if (!(rel <= tol)) {
                            CHECK_MESSAGE(rel <= tol, "R " << R << " r " << r << " offset " << off << " ray " << i
                                                           << ": hit " << k << " off the surface by " << rel << " R");
                        }
                    }
                }
                pray_scene_free(c, q);
                pray_release(c, t);
                pray_release(c, m);
                pray_free(c);
            }
        }
    }
    MESSAGE("torus (" << std::string(fl ? "float" : "double") << "): " << rays << " rays, " << hits << " hits, largest distance from the surface "
                      << worst << " R; missed " << missed << ", hit beside it " << false_hits);
    CHECK(missed == 0);
    CHECK(false_hits == 0);
}
