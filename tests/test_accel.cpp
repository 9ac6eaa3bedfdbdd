// The acceleration (thesis 3.3-3.6: uniform grid, per-voxel action lists, freezing, merging of
// voxels into areas, bounding boxes) against the brute-force reference, through the public API
// only (pray.hpp):
//   - the same hits (primitive, t, entering, side of the normal, number of hits) for every
//     combination of the switches grid x freeze x merge x bounds, on a few hundred random CSG
//     scenes with fixed seeds, each probed with adversarial rays (accel_scenes.hpp: voxel faces,
//     edges and corners, box corners, tangents, rays in faces, starting inside the grid, on box
//     boundaries and inside solids, with tmax limits);
//   - the same images, float for float, on example programs and on random scenes: small images
//     for every grid x freeze x merge x bounds, and images large enough that the light buffers
//     and the eye's buffer are built for every lightbuffer x eyebuffer x shadowcache x freeze x
//     merge x bounds (each such case checks that the buffers were built: else it would compare
//     nothing of them);
//   - freezing never increases the number of intersection tests;
//   - the statistics of the grid are plausible.
// A mismatch is a bug in the renderer: the failure message lists the first ones in full (scene
// and seed, options, ray, expected and actual hits), enough to reproduce each one.
#include <doctest/doctest.h>

#include "accel_scenes.hpp"
#include "testkit.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

namespace {

using namespace accel_scenes;

// ---- option combinations ----
const int GRIDS[] = {0, 1, 2, 3, 5, 8, 16, -1};
const int NGRIDS = sizeof GRIDS / sizeof GRIDS[0];

// The thesis' switches (grid, freeze, merge, bounds; brute: the reference) and the three
// methods of shadow and primary rays (light buffers, the eye's buffer, the shadow cache), each
// on by default.
struct Opts {
    int brute, grid, freeze, merge, bounds;
    int lightbuffer = 1, eyebuffer = 1, shadowcache = 1, plans = 1;
    // (the four methods only where they are off)
    std::string text() const {
        if (brute) return "brute=1";
        std::string s;
        for (auto &o : fixed())
            if (o != "brute=0" && o != "lightbuffer=1" && o != "eyebuffer=1" && o != "shadowcache=1" && o != "plans=1")
                s += (s.empty() ? "" : " ") + o;
        return s;
    }
    // as fixed options of a program run
    std::vector<std::string> fixed() const {
        std::vector<std::string> v;
        v.push_back("brute=" + std::to_string(brute));
        v.push_back("grid=" + std::to_string(grid));
        v.push_back("freeze=" + std::to_string(freeze));
        v.push_back("merge=" + std::to_string(merge));
        v.push_back("bounds=" + std::to_string(bounds));
        v.push_back("lightbuffer=" + std::to_string(lightbuffer));
        v.push_back("eyebuffer=" + std::to_string(eyebuffer));
        v.push_back("shadowcache=" + std::to_string(shadowcache));
        v.push_back("plans=" + std::to_string(plans));
        return v;
    }
};

Opts reference() { return Opts{1, -1, 1, 1, 1}; }

// grid x freeze x merge x bounds, the other switches on; and grid x freeze with plans=0 (every
// list evaluated in full)
std::vector<Opts> all_combinations() {
    std::vector<Opts> v;
    for (int g = 0; g < NGRIDS; g++)
        for (int f = 0; f < 2; f++) {
            for (int m = 0; m < 2; m++)
                for (int b = 0; b < 2; b++) v.push_back(Opts{0, GRIDS[g], f, m, b});
            v.push_back(Opts{0, GRIDS[g], f, 1, 1, 1, 1, 1, 0});
        }
    return v;
}

// Intersection tests of renders side by side, freeze=0 and freeze=1 of each other setting:
// freezing must never add any.
struct FreezeTally {
    std::map<std::string, std::pair<double, double> > tests;  // by the setting with freeze=0
    void add(const Opts &o, double t) {
        Opts k = o;
        k.freeze = 0;
        (o.freeze ? tests[k.text()].second : tests[k.text()].first) = t;
    }
    // the settings where freeze=1 made more intersection tests than freeze=0, into `problems`
    long violations(const std::string &label, std::vector<std::string> &problems) const {
        long n = 0;
        for (auto &e : tests)
            if (e.second.second > e.second.first) {
                n++;
                if (problems.size() < 40)
                    problems.push_back(label + ", " + e.first + ": " + std::to_string((long)e.second.second) +
                                       " intersection tests with freeze=1, " + std::to_string((long)e.second.first) +
                                       " with freeze=0");
            }
        return n;
    }
};

// lightbuffer x eyebuffer x shadowcache x freeze x merge, and x bounds or with bounds=1, at one
// grid; the first is the defaults (all on)
std::vector<Opts> buffer_combinations(int grid, bool with_bounds) {
    std::vector<Opts> v;
    for (int lb : {1, 0})
        for (int eb : {1, 0})
            for (int sc : {1, 0})
                for (int f : {1, 0})
                    for (int m : {1, 0})
                        for (int b : {1, 0})
                            if (b || with_bounds) v.push_back(Opts{0, grid, f, m, b, lb, eb, sc});
    return v;
}

// All eight, every time: options set on a context persist.
bool apply(pray_ctx *c, const Opts &o) {
    return pray_option(c, "brute", o.brute) == PRAY_OK && pray_option(c, "grid", o.grid) == PRAY_OK &&
           pray_option(c, "freeze", o.freeze) == PRAY_OK && pray_option(c, "merge", o.merge) == PRAY_OK &&
           pray_option(c, "bounds", o.bounds) == PRAY_OK && pray_option(c, "lightbuffer", o.lightbuffer) == PRAY_OK &&
           pray_option(c, "eyebuffer", o.eyebuffer) == PRAY_OK && pray_option(c, "shadowcache", o.shadowcache) == PRAY_OK &&
           pray_option(c, "plans", o.plans) == PRAY_OK;
}

// ---- rays ----
enum RayKind {
    R_RANDOM, R_AXIS, R_GRID_EDGE, R_GRID_FACE, R_GRID_CORNER, R_GRID_SLOPE, R_FRACTION, R_BOX_CORNER,
    R_IN_GRID, R_ON_BOX, R_IN_SOLID, R_TANGENT_SPHERE, R_TANGENT_CYL, R_ALONG_CYL, R_IN_FACE, R_TMAX,
    R_TMAX_HIT, R_NEAR_AXIS, R_TMAX_GRID, R_GRID_EXIT, R_GRAZE, R_NKINDS
};
const char *ray_kind_name(int k) {
    static const char *n[] = {"random", "axis-parallel", "along grid edge", "in grid face", "grid corner diagonal",
                              "grid corner slope", "on 1/8,1/16 fractions", "through box corner",
                              "starting inside grid", "starting on box boundary", "starting inside solid",
                              "tangent to sphere", "tangent to cylinder", "along cylinder surface",
                              "in a plane face", "tmax limit", "tmax at a hit", "nearly axis-parallel",
                              "tmax at a grid corner", "crossing a face where it leaves the grid",
                              "grazing an edge, a rim, a side or an outline"};
    return n[k];
}

struct RayCase {
    pray_vec o, d;
    double tmax;
    int kind;
};

std::string fmt_vec(pray_vec v) {
    char b[128];
    std::snprintf(b, sizeof b, "(%.17g, %.17g, %.17g)", v.x, v.y, v.z);
    return b;
}

std::string fmt_ray(const RayCase &r) {
    std::string s = std::string(ray_kind_name(r.kind)) + " ray o=" + fmt_vec(r.o) + " d=" + fmt_vec(r.d);
    char b[64];
    if (r.tmax < HUGE_VAL) {
        std::snprintf(b, sizeof b, " tmax=%.17g", r.tmax);
        s += b;
    }
    return s;
}

// Adversarial rays for a scene.
std::vector<RayCase> make_rays(const Scene &s, Rng &rng) {
    std::vector<RayCase> v;
    pray_vec lo = s.lo, hi = s.hi, C = mul(add(lo, hi), 0.5);
    double ext = std::max(hi.x - lo.x, std::max(hi.y - lo.y, hi.z - lo.z));
    double far = 3 * ext;
    auto push = [&](pray_vec o, pray_vec d, int kind, double tmax = HUGE_VAL) {
        if (len(d) == 0) return;
        RayCase r = {o, d, tmax, kind};
        v.push_back(r);
    };
    auto axis_dir = [&]() { return axis_vec(rng.below(3), rng.sign()); };
    auto diag_dir = [&]() {  // (+-1, +-1, +-1) or (+-1, +-1, 0) in some order
        pray_vec d = V(rng.sign(), rng.sign(), rng.sign());
        if (rng.chance(0.4)) set_comp(d, rng.below(3), 0);
        return d;
    };
    auto fraction = [&](int l) {  // a coordinate on a multiple of 1/8 or 1/16 of the extent
        int den = rng.chance(0.5) ? 8 : 16;
        return comp(lo, l) + ext * rng.below(den + 1) / den;
    };

    // random rays from outside, aimed into the scene's box or at the centre of a part
    for (int i = 0; i < 16; i++) {
        pray_vec o = add(C, mul(rng.dir(), far));
        pray_vec t = rng.in_box(lo, hi);
        if (i % 2 && !s.spheres.empty()) t = s.spheres[rng.below((int)s.spheres.size())].c;
        if (i % 4 == 3 && !s.boxes.empty()) t = s.boxes[rng.below((int)s.boxes.size())].c;
        push(o, sub(t, o), R_RANDOM);
    }
    // axis-parallel rays, from outside and from inside
    for (int i = 0; i < 16; i++) {
        int a = rng.below(3);
        pray_vec o = rng.in_box(lo, hi);
        for (int l = 0; l < 3; l++)
            if (rng.chance(0.5)) set_comp(o, l, fraction(l));
        double sg = rng.sign();
        if (rng.chance(0.5)) set_comp(o, a, comp(C, a) - sg * far);
        push(o, axis_vec(a, sg), R_AXIS);
    }
    // on the guessed planes of the grid's voxels, for every grid size tested
    pray_vec glo = lo, ghi = hi, blo, bhi;
    bool have_grid = finite_region(s, &glo, &ghi);
    if (!have_grid) glo = lo, ghi = hi;
    std::vector<std::pair<pray_vec, pray_vec>> regions;
    if (have_grid) regions.push_back(std::make_pair(glo, ghi));
    if (finite_region(s, &blo, &bhi, true) && (!have_grid || len(sub(blo, glo)) + len(sub(bhi, ghi)) > 0))
        regions.push_back(std::make_pair(blo, bhi));
    for (size_t ri = 0; ri < regions.size(); ri++) {
        int sizes[] = {1, 2, 3, 5, 8, 16, guess_auto_grid((int)(s.spheres.size() + 6 * s.boxes.size()))};
        for (int N : sizes) {
            GridGuess g;
            if (!guess_grid(regions[ri].first, regions[ri].second, N, &g)) continue;
            bool half = regions.size() > 1 && rng.chance(0.5);  // two guesses: half the rays each
            auto face = [&](int l) { return g.face(l, rng.below(g.n[l] + 1)); };
            auto corner = [&]() { return V(face(0), face(1), face(2)); };
            // along an edge: two coordinates on faces, parallel to the third axis
            for (int i = half; i < 2; i++) {
                int a = rng.below(3);
                pray_vec o = corner();
                double sg = rng.sign();
                if (rng.chance(0.5)) set_comp(o, a, comp(o, a) - sg * (g.n[a] + 1) * g.h);  // from outside
                push(o, axis_vec(a, sg), R_GRID_EDGE);
            }
            // in a face: one coordinate on a face, the direction in that plane
            for (int i = half; i < 2; i++) {
                int b = rng.below(3);
                pray_vec o = rng.in_box(V(g.org[0], g.org[1], g.org[2]),
                                        V(g.face(0, g.n[0]), g.face(1, g.n[1]), g.face(2, g.n[2])));
                set_comp(o, b, face(b));
                pray_vec d = rng.dir();
                set_comp(d, b, 0);
                if (rng.chance(0.5)) d = diag_dir(), set_comp(d, b, 0);
                if (rng.chance(0.5)) o = sub(o, mul(unit(d), far));
                push(o, d, R_GRID_FACE);
            }
            // diagonals of the cubical voxels: through a corner of every voxel they cross
            for (int i = half; i < 2; i++) {
                pray_vec P = corner();
                pray_vec d = diag_dir();
                int m = rng.below(4);
                double back = m == 3 ? (g.n[0] + g.n[1] + g.n[2] + 1) * g.h : m * g.h;
                push(sub(P, mul(d, back)), d, R_GRID_CORNER);
            }
            // diagonals ending exactly at a corner of a voxel (tmax), from inside the grid
            {
                pray_vec P = corner();
                pray_vec d = diag_dir();
                int k = 1 + rng.below(3);
                push(P, d, R_TMAX_GRID, k * g.h * len(d));
            }
            // leaving (or entering) the grid's box exactly where the ray crosses a face of an
            // axis-aligned box: the last stretch in the grid and the one after it must meet
            for (int i = 0; i < 2 && !s.boxes.empty(); i++) {
                const BoxRec &b = s.boxes[rng.below((int)s.boxes.size())];
                int l = rng.below(3), m = (l + 1 + rng.below(2)) % 3, q = 3 - l - m, k = -1;
                for (int j = 0; j < 3; j++)
                    if (std::fabs(comp(b.u[j], m)) == 1) k = j;
                if (k < 0) continue;  // a tilted box
                bool high = rng.chance(0.5);
                pray_vec P = V(0, 0, 0);
                set_comp(P, l, high ? g.face(l, g.n[l]) : g.face(l, 0));
                set_comp(P, m, comp(b.c, m) + rng.sign() * b.h[k]);
                set_comp(P, q, rng.chance(0.5) ? face(q) : comp(b.c, q) + rng.range(-1, 1) * ext / 4);
                pray_vec d = rng.chance(0.5) ? diag_dir() : rng.dir();
                if (comp(d, l) == 0) set_comp(d, l, 1);
                double out = high ? 1 : -1;  // leaving the grid through P, mostly
                if (rng.chance(0.75) ? comp(d, l) * out < 0 : comp(d, l) * out > 0) set_comp(d, l, -comp(d, l));
                push(sub(P, mul(unit(d), rng.range(0.25, 2) * ext)), d, R_GRID_EXIT);
            }
            // small integer slopes through a corner: through corners and edges periodically
            {
                pray_vec P = corner();
                pray_vec d = V(rng.sign() * (1 + rng.below(3)), rng.sign() * (1 + rng.below(3)), rng.sign() * rng.below(3));
                int p[3] = {0, 1, 2};
                for (int k = 2; k > 0; k--) std::swap(p[k], p[rng.below(k + 1)]);
                d = V(comp(d, p[0]), comp(d, p[1]), comp(d, p[2]));
                push(rng.chance(0.5) ? P : sub(P, mul(d, 2 * far / len(d))), d, R_GRID_SLOPE);
            }
        }
    }
    // on simple fractions of the scene's extent
    for (int i = 0; i < 14; i++) {
        pray_vec o = V(fraction(0), fraction(1), fraction(2));
        pray_vec d = rng.chance(0.5) ? axis_dir() : diag_dir();
        if (rng.chance(0.5)) o = sub(o, mul(unit(d), far));
        push(o, d, R_FRACTION);
    }
    // through the corners of primitives' boxes (boxes of six half-spaces, spheres' boxes)
    std::vector<pray_vec> corners;
    for (const BoxRec &b : s.boxes)
        for (int k = 0; k < 8; k++) corners.push_back(b.corner(k));
    for (const Sphere &q : s.spheres)
        if (corners.size() < 4000)
            for (int k = 0; k < 8; k++)
                corners.push_back(V(q.c.x + (k & 1 ? q.r : -q.r), q.c.y + (k & 2 ? q.r : -q.r), q.c.z + (k & 4 ? q.r : -q.r)));
    for (int i = 0; i < 14 && !corners.empty(); i++) {
        pray_vec P = corners[rng.below((int)corners.size())];
        int m = rng.below(3);
        pray_vec d = m == 0 ? rng.dir() : m == 1 ? axis_dir() : diag_dir();
        push(rng.chance(0.3) ? P : sub(P, mul(unit(d), far)), d, R_BOX_CORNER);
    }
    // starting inside the grid's region
    for (int i = 0; i < 8; i++) {
        pray_vec o = rng.in_box(glo, ghi);
        push(o, rng.chance(0.3) ? axis_dir() : rng.dir(), R_IN_GRID);
    }
    // starting exactly on a primitive's box boundary
    for (int i = 0; i < 8 && !s.spheres.empty(); i++) {
        const Sphere &q = s.spheres[rng.below((int)s.spheres.size())];
        pray_vec o = add(q.c, V(rng.range(-q.r, q.r), rng.range(-q.r, q.r), rng.range(-q.r, q.r)));
        int l = rng.below(3);
        set_comp(o, l, comp(q.c, l) + rng.sign() * q.r);
        push(o, rng.chance(0.3) ? axis_dir() : rng.dir(), R_ON_BOX);
    }
    for (int i = 0; i < 4 && !s.boxes.empty(); i++) {
        const BoxRec &b = s.boxes[rng.below((int)s.boxes.size())];
        pray_vec o = b.c;
        for (int k = 0; k < 3; k++) o = add(o, mul(b.u[k], rng.range(-b.h[k], b.h[k])));
        int k = rng.below(3);
        o = add(o, mul(b.u[k], rng.sign() * b.h[k] - dot(sub(o, b.c), b.u[k])));
        push(o, rng.chance(0.3) ? axis_dir() : rng.dir(), R_ON_BOX);
    }
    // starting inside solids
    for (int i = 0; i < 8; i++) {
        int w = rng.below(3);
        pray_vec o;
        if (w == 0 && !s.spheres.empty()) o = s.spheres[rng.below((int)s.spheres.size())].c;
        else if (w == 1 && !s.boxes.empty()) o = s.boxes[rng.below((int)s.boxes.size())].c;
        else if (!s.cylinders.empty()) {
            const Cylinder &q = s.cylinders[rng.below((int)s.cylinders.size())];
            o = add(q.p, mul(q.a, rng.range(-0.5, 0.5) * s.scale));
        } else
            o = rng.in_box(lo, hi);
        push(o, rng.chance(0.3) ? axis_dir() : rng.dir(), R_IN_SOLID);
    }
    // tangent to spheres: the line passes at exactly the radius from the centre
    for (int i = 0; i < 12 && !s.spheres.empty(); i++) {
        const Sphere &q = s.spheres[rng.below((int)s.spheres.size())];
        pray_vec d, u;
        if (rng.chance(0.5)) {  // axis-aligned: exact in floating point
            int a = rng.below(3), b = (a + 1 + rng.below(2)) % 3;
            d = axis_vec(a, rng.sign());
            u = axis_vec(b, rng.sign());
        } else {
            d = rng.dir();
            u = unit(cross(d, rng.dir()));
        }
        pray_vec o = add(q.c, mul(u, q.r));
        if (rng.chance(0.7)) o = sub(o, mul(d, far));
        push(o, d, R_TANGENT_SPHERE);
    }
    // tangent to cylinders, and lying on a cylinder's surface (parallel to the axis)
    for (int i = 0; i < 10 && !s.cylinders.empty(); i++) {
        const Cylinder &q = s.cylinders[rng.below((int)s.cylinders.size())];
        pray_vec t = rng.dir();
        pray_vec u = unit(cross(q.a, t));             // perpendicular to the axis
        pray_vec w = cross(q.a, u);                   // the third direction
        if (i % 3 == 2) {
            pray_vec o = add(add(q.p, mul(u, q.r)), mul(q.a, rng.range(-1, 1) * s.scale));
            push(o, mul(q.a, rng.sign()), R_ALONG_CYL);
            continue;
        }
        // axis-aligned cylinders with axis-aligned tangents: exact
        int ax = -1;
        for (int l = 0; l < 3; l++)
            if (std::fabs(comp(q.a, l)) == 1) ax = l;
        if (ax >= 0 && rng.chance(0.6)) {
            int b = (ax + 1 + rng.below(2)) % 3, c2 = 3 - ax - b;
            u = axis_vec(b, rng.sign());
            w = axis_vec(c2, 1);
        }
        double ang = rng.chance(0.5) ? 0 : rng.range(-1.2, 1.2);
        pray_vec d = add(mul(w, std::cos(ang)), mul(q.a, std::sin(ang)));
        pray_vec o = add(q.p, mul(u, q.r));
        if (rng.chance(0.7)) o = sub(o, mul(d, far));
        push(o, d, R_TANGENT_CYL);
    }
    // lying in a face of a box, or in a plane
    for (int i = 0; i < 8 && (!s.boxes.empty() || !s.planes.empty()); i++) {
        if (!s.boxes.empty() && rng.chance(0.7)) {
            const BoxRec &b = s.boxes[rng.below((int)s.boxes.size())];
            int k = rng.below(3), k1 = (k + 1) % 3, k2 = (k + 2) % 3;
            pray_vec o = add(b.c, mul(b.u[k], rng.sign() * b.h[k]));
            o = add(o, mul(b.u[k1], rng.range(-1.5, 1.5) * b.h[k1]));
            pray_vec d = rng.chance(0.5) ? b.u[k2] : add(mul(b.u[k1], rng.range(-1, 1)), mul(b.u[k2], rng.range(-1, 1)));
            if (rng.chance(0.5)) o = sub(o, mul(unit(d), far));
            push(o, d, R_IN_FACE);
        } else if (!s.planes.empty()) {
            const Plane &q = s.planes[rng.below((int)s.planes.size())];
            pray_vec d = unit(cross(q.n, rng.dir()));
            push(sub(q.p, mul(d, far)), d, R_IN_FACE);
        }
    }
    // nearly parallel to an axis: the other components tiny, down to subnormal numbers, and
    // just above them, where a voxel's width over the component overflows
    for (int i = 0; i < 8; i++) {
        static const double tiny[] = {1e-9, 1e-17, 1e-200, 1e-306, 3e-308, 4e-310};
        int a = rng.below(3);
        pray_vec d = axis_vec(a, rng.sign());
        for (int l = 0; l < 3; l++)
            if (l != a && rng.chance(0.7)) set_comp(d, l, rng.sign() * tiny[rng.below(6)]);
        pray_vec o = rng.in_box(lo, hi);
        if (rng.chance(0.5)) set_comp(o, (a + 1) % 3, fraction((a + 1) % 3));
        if (rng.chance(0.5)) set_comp(o, a, comp(C, a) - comp(d, a) * far);
        push(o, d, R_NEAR_AXIS);
    }
    // grazing the version-2 primitives (and stretched ones): along an edge or a side line,
    // tangent to a rim, a side or an outline; from far, from the point, or a hair beside it
    for (int i = 0; i < 24 && !s.grazes.empty(); i++) {
        const Graze &g = s.grazes[rng.below((int)s.grazes.size())];
        pray_vec o = g.p;
        if (rng.chance(0.2)) o = add(o, mul(rng.dir(), 1e-9 * s.scale));
        push(rng.chance(0.3) ? o : sub(o, mul(unit(g.d), far)), g.d, R_GRAZE);
    }
    // tmax limits (shadow-like)
    size_t n0 = v.size();
    for (int i = 0; i < 14 && n0; i++) {
        RayCase r = v[rng.below((int)n0)];
        r.tmax = rng.range(0, 2 * far);
        r.kind = R_TMAX;
        v.push_back(r);
    }
    return v;
}

// ---- hits ----
const int MAXH = 64;

struct Hits {
    int n = 0;
    std::vector<pray_hit> h;
};

Hits intersect(pray_ctx *c, pray_scene *q, const RayCase &r) {
    Hits out;
    out.h.resize(MAXH);
    out.n = pray_intersect(c, q, r.o, r.d, r.tmax, out.h.data(), MAXH);
    out.h.resize(out.n < 0 ? 0 : std::min(out.n, MAXH));
    return out;
}

bool same_t(double a, double b) { return std::fabs(a - b) <= 1e-9 * (1 + std::fabs(a)); }

// The normal points out of the whole solid: the same primitive at the same t gives it the same
// way round, so the sign of their dot product tells a wrong side.
bool same_hits(const Hits &a, const Hits &b) {
    if (a.n != b.n) return false;
    for (size_t i = 0; i < a.h.size(); i++)
        if (a.h[i].primitive != b.h[i].primitive || a.h[i].entering != b.h[i].entering || !same_t(a.h[i].t, b.h[i].t) ||
            !(dot(a.h[i].normal, b.h[i].normal) > 0))
            return false;
    return true;
}

std::string fmt_hits(const Hits &a) {
    std::ostringstream s;
    s << a.n << " hit" << (a.n == 1 ? "" : "s");
    size_t shown = std::min<size_t>(a.h.size(), 12);
    for (size_t i = 0; i < shown; i++) {
        char b[160];
        const pray_vec &n = a.h[i].normal;
        std::snprintf(b, sizeof b, " [t=%.17g prim %d %s n=(%.3g %.3g %.3g)]", a.h[i].t, a.h[i].primitive,
                      a.h[i].entering ? "in" : "out", n.x, n.y, n.z);
        s << b;
    }
    if (a.h.size() > shown) s << " ...";
    return s.str();
}

// ---- the collection of mismatches ----
// The first mismatching (scene, ray) pairs are kept in full, each with the option combinations
// that fail on it (the hits shown are those of the first one); then counts by kind.
struct Report {
    long scenes = 0, rays = 0, rays_hitting = 0, hits = 0, comparisons = 0, mismatches = 0, failed_prepares = 0;
    long nested = 0;  // preparations that nested grids (so that the scenes test them)
    long faces = 0;   // the reference's hits on faces between two materials
    struct Case {
        std::string where, want, got, options;
        int count = 0;
    };
    std::vector<Case> first;
    std::map<std::string, long> by_options, by_ray, by_scene;
    void add(const std::string &scene, const std::string &kind_of_scene, const Opts &o, const RayCase &r,
             const Hits &want, const Hits &got) {
        mismatches++;
        by_options[o.text()]++;
        by_ray[ray_kind_name(r.kind)]++;
        by_scene[kind_of_scene]++;
        std::string where = scene + ", " + fmt_ray(r);
        for (Case &k : first)
            if (k.where == where) {
                if (++k.count <= 16) k.options += "; " + o.text();
                return;
            }
        if (first.size() >= 12) return;
        Case k;
        k.where = where;
        k.want = fmt_hits(want);
        k.got = fmt_hits(got);
        k.options = o.text();
        k.count = 1;
        first.push_back(k);
    }
    std::string summary() const {
        std::ostringstream s;
        s << scenes << " scenes, " << rays << " rays (" << rays_hitting << " with hits, " << hits << " hits), "
          << comparisons << " comparisons, " << mismatches << " mismatches, " << failed_prepares << " failed prepares";
        return s.str();
    }
    std::string text() const {
        std::ostringstream s;
        s << summary();
        if (!mismatches) return s.str();
        s << "\nmismatches by scene kind:";
        for (auto &kv : by_scene) s << " " << kv.first << "=" << kv.second;
        s << "\nmismatches by ray kind:";
        for (auto &kv : by_ray) s << " [" << kv.first << "]=" << kv.second;
        s << "\nmismatches by options:";
        for (auto &kv : by_options) s << "\n    " << kv.first << ": " << kv.second;
        s << "\nfirst mismatching rays:";
        for (const Case &k : first)
            s << "\n  - " << k.where << "\n      expected " << k.want << "\n      actual   " << k.got << "\n      with "
              << k.count << " option combination" << (k.count == 1 ? "" : "s") << ": " << k.options
              << (k.count > 17 ? "; ..." : "");
        return s.str();
    }
};

// Opaque, glass, water, a clear solid of index 1 and a mirror, for the primitives of a mixed scene.
std::vector<pray_model *> mixed_models(pray_ctx *c) {
    pray_rgb d = {0.7, 0.5, 0.3}, s = {0.2, 0.2, 0.2}, z = {0, 0, 0}, t = {0.8, 0.85, 0.9}, one = {1, 1, 1};
    pray_rgb m = {0.6, 0.6, 0.6};
    return {pray_phong(c, d, s, z, 10), pray_model_add(c, pray_transparent(c, t, 1.5), pray_phong(c, z, s, z, 40)),
            pray_transparent(c, t, 1.33), pray_transparent(c, one, 1), pray_model_add(c, pray_mirror(c, m), pray_phong(c, z, s, z, 20))};
}

// Compare every switch combination with the reference on one scene.
void check_scene(int kind, uint64_t seed, Report &rep, bool mixed) {
    pray_ctx *c = pray_new();
    REQUIRE(c);
    std::vector<pray_model *> mats = mixed_models(c);
    Scene s = make_scene(c, kind, seed, mixed ? &mats : nullptr);
    INFO(s.label);
    CHECK_MESSAGE(s.root != nullptr, std::string(pray_error(c)));
    if (!s.root) {
        pray_free(c);
        return;
    }
    Rng rng(seed * 31 + 7 + (uint64_t)kind * 1000003);
    std::vector<RayCase> rays = make_rays(s, rng);
    // the reference
    REQUIRE(apply(c, reference()));
    pray_scene *ref = pray_prepare(c, s.root);
    CHECK_MESSAGE(ref != nullptr, std::string(pray_error(c)));
    if (!ref) {
        rep.failed_prepares++;
        pray_free(c);
        return;
    }
    std::vector<Hits> want;
    for (const RayCase &r : rays) want.push_back(intersect(c, ref, r));
    // shadow-like rays ending exactly at a surface (the hit at tmax is not counted)
    size_t nbase = rays.size();
    for (size_t i = 0, added = 0; i < nbase && added < 16; i++) {
        if (want[i].h.empty() || rng.chance(0.6)) continue;
        RayCase r = rays[i];
        r.kind = R_TMAX_HIT;
        r.tmax = want[i].h[rng.below((int)want[i].h.size())].t;
        rays.push_back(r);
        want.push_back(intersect(c, ref, r));
        added++;
    }
    for (size_t i = 0; i < rays.size(); i++)
        if (want[i].n < 0) {
            FAIL_CHECK("the reference failed on " << fmt_ray(rays[i]) << ": " << std::string(pray_error(c)));
            want[i].n = 0;
        }
    pray_scene_free(c, ref);
    for (const Hits &h : want) {
        rep.rays_hitting += h.n > 0;
        rep.hits += h.n;
        for (const pray_hit &x : h.h) rep.faces += x.entering == 2;
    }
    rep.scenes++;
    rep.rays += (long)rays.size();
    for (const Opts &o : all_combinations()) {
        REQUIRE(apply(c, o));
        pray_scene *q = pray_prepare(c, s.root);
        if (!q) {
            rep.failed_prepares++;
            FAIL_CHECK(s.label << ", " << o.text() << ": pray_prepare failed: " << std::string(pray_error(c)));
            continue;
        }
        pray_stats st;
        pray_stats_get(c, &st);
        rep.nested += st.nested_grids > 0;
        for (size_t i = 0; i < rays.size(); i++) {
            Hits got = intersect(c, q, rays[i]);
            rep.comparisons++;
            if (!same_hits(want[i], got)) rep.add(s.label, kind_name(kind), o, rays[i], want[i], got);
        }
        pray_scene_free(c, q);
    }
    pray_free(c);
}

// PRAY_ACCEL_SCALE=k in the environment runs k times as many scenes (a longer soak than the
// default run of `make check`; the seeds go on from the default ones).
int scale_from_env() {
    const char *e = std::getenv("PRAY_ACCEL_SCALE");
    int k = e ? std::atoi(e) : 1;
    return k < 1 ? 1 : k;
}

void run_kind(int kind, int first_seed, int count, Report &total, bool mixed = false) {
    count *= scale_from_env();
    Report rep;
    auto t0 = std::chrono::steady_clock::now();
    for (int i = 0; i < count; i++) check_scene(kind, (uint64_t)(first_seed + i), rep, mixed);
    double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    MESSAGE(std::string(kind_name(kind)) << std::string(mixed ? " scenes of mixed materials (" : " scenes (") << secs << " s): " << rep.summary() << ", " << rep.nested << " with nested grids"
                                     << (mixed ? ", " + std::to_string(rep.faces) + " hits on faces between materials" : std::string()));
    CHECK_MESSAGE(rep.mismatches == 0, rep.text());
    CHECK(rep.failed_prepares == 0);
    if (kind == K_CLUSTER) CHECK_MESSAGE(rep.nested > 0, "no scene nested a grid: the test would not test them");
    if (mixed) CHECK_MESSAGE(rep.faces > 10, rep.faces << " hits on faces between materials: too few to test them");
    total.scenes += rep.scenes;
    total.rays += rep.rays;
    total.rays_hitting += rep.rays_hitting;
    total.hits += rep.hits;
    total.comparisons += rep.comparisons;
    total.mismatches += rep.mismatches;
}

Report g_total;

} // namespace

// ---------------------------------------------------------------------------------------------
// Identical hits: reference vs every combination of grid x freeze x merge x bounds, and grid x
// freeze with plans=0.
// ---------------------------------------------------------------------------------------------
TEST_CASE("accel hits: random CSG trees of spheres, half-spaces, boxes, cylinders (140 seeds)") {
    run_kind(K_RANDOM, 1, 140, g_total);
}
TEST_CASE("accel hits: many small spheres in a union minus a few solids (12 seeds)") {
    run_kind(K_MANY, 1, 12, g_total);
}
TEST_CASE("accel hits: lattices of touching spheres (15 seeds)") { run_kind(K_LATTICE, 1, 15, g_total); }
TEST_CASE("accel hits: blocks sharing faces, on quarter units (20 seeds)") { run_kind(K_BLOCKS, 1, 20, g_total); }
TEST_CASE("accel hits: an unbounded floor with solids on it (15 seeds)") { run_kind(K_FLOOR, 1, 15, g_total); }
TEST_CASE("accel hits: dense clusters of small solids with a few far away, a floor and rods, where grids nest (8 seeds)") {
    run_kind(K_CLUSTER, 1, 8, g_total);
}
TEST_CASE("accel hits: boxes, rods, cones, tori, stretched and mirrored solids with the others, grazed (60 seeds)") {
    run_kind(K_SHAPES, 1, 60, g_total);
}
TEST_CASE("accel hits: primitives of several materials touching and overlapping, with the faces between them "
          "(random 40, blocks 20, floor 15, shapes 20 seeds)") {
    run_kind(K_RANDOM, 1, 40, g_total, true);
    run_kind(K_BLOCKS, 1, 20, g_total, true);
    run_kind(K_FLOOR, 1, 15, g_total, true);
    run_kind(K_SHAPES, 1, 20, g_total, true);
}
TEST_CASE("accel hits: scenes scaled from 1e-3 to 1e6 and moved far from the origin (20 seeds)") {
    run_kind(K_SCALED, 1, 20, g_total);
    MESSAGE("all scene kinds so far: " << g_total.summary());
}

// ---------------------------------------------------------------------------------------------
// Identical images and fewer intersection tests with freezing: the example programs.
// ---------------------------------------------------------------------------------------------
namespace {

// A program run with fixed options, its frames and statistics.
struct Run {
    pray_status status = PRAY_OK;
    std::string error;
    std::vector<testkit::Frame> frames;
    pray_stats stats;
};

Run run_program(const std::string &name, const std::string &text, const std::vector<std::string> &options) {
    Run r;
    std::memset(&r.stats, 0, sizeof r.stats);
    pray_ctx *c = pray_new();
    REQUIRE(c);
    pray_set_print(c, nullptr, nullptr);
    pray_set_frame(c, testkit::frame_sink, &r.frames);
    for (const std::string &o : options) {
        size_t eq = o.find('=');
        pray_status st = pray_option_fix(c, o.substr(0, eq).c_str(), o.substr(eq + 1).c_str());
        CHECK_MESSAGE(st == PRAY_OK, o << ": " << std::string(pray_error(c)));
    }
    r.status = pray_run_string(c, name.c_str(), text.data(), text.size());
    if (r.status != PRAY_OK) r.error = pray_error(c);
    pray_stats_get(c, &r.stats);
    pray_free(c);
    return r;
}

bool read_file(const std::string &path, std::string *out) {
    std::ifstream f(path, std::ios::binary);
    if (!f) return false;
    std::ostringstream s;
    s << f.rdbuf();
    *out = s.str();
    return true;
}

// An example program, read from examples/ next to the tests' working directory.
bool read_example(const std::string &name, std::string *text) {
    for (const char *dir : {"examples/", "../examples/", "../../examples/"})
        if (read_file(std::string(dir) + name, text)) return true;
    FAIL_CHECK("cannot read examples/" << name << " (run the tests from the repository's top directory)");
    return false;
}

// The example programs that render quickly at 48 x 48 with every grid (not redsphx.ray, which is
// an error on purpose; room.ray, fractal.ray and cube.ray are in the buffers' cases below).
std::vector<std::pair<std::string, std::string>> example_programs() {
    static const char *names[] = {"anim.ray", "csg.ray", "glass.ray", "holes.ray", "loop.ray",
                                  "mirror.ray", "models.ray", "parallel.ray", "redsph.ray"};
    std::vector<std::pair<std::string, std::string>> v;
    for (const char *n : names) {
        std::string text;
        if (read_example(n, &text)) v.push_back(std::make_pair(std::string(n), text));
    }
    return v;
}

// "" when the frames are identical, float for float; else what differs.
std::string frame_difference(const std::vector<testkit::Frame> &want, const std::vector<testkit::Frame> &got) {
    std::ostringstream s;
    if (want.size() != got.size()) {
        s << want.size() << " frames expected, " << got.size() << " rendered";
        return s.str();
    }
    for (size_t k = 0; k < want.size(); k++) {
        const testkit::Frame &a = want[k], &b = got[k];
        if (a.width != b.width || a.height != b.height) {
            s << "frame " << k << ": " << a.width << "x" << a.height << " expected, " << b.width << "x" << b.height;
            return s.str();
        }
        long diff = 0;
        std::ostringstream first;
        for (int y = 0; y < a.height; y++)
            for (int x = 0; x < a.width; x++)
                for (int ch = 0; ch < 3; ch++) {
                    float u = a.at(x, y, ch), v = b.at(x, y, ch);
                    if (std::memcmp(&u, &v, sizeof u) == 0) continue;
                    if (diff++ < 4) {
                        char buf[160];
                        std::snprintf(buf, sizeof buf, " (%d,%d) channel %d: %.9g expected, %.9g", x, y, ch, u, v);
                        first << buf;
                    }
                }
        if (diff) {
            s << "frame " << k << ": " << diff << " samples differ;" << first.str();
            return s.str();
        }
    }
    return "";
}

} // namespace

// (lightbuffer, eyebuffer and shadowcache stay on, their default. At 48 x 48 the light buffers and
// the eye's buffer are built only on the coarsest grids (1 to 5 voxels along the longest side),
// where the image has enough samples per voxel of a buffer; the buffers' cases below use larger
// images and switch them.)
TEST_CASE("accel images: nine examples at 48 x 48, every grid x freeze x merge x bounds, and plans=0, the same floats as "
          "--brute; freezing never adds intersection tests") {
    auto t0 = std::chrono::steady_clock::now();
    long runs = 0, image_mismatches = 0, freeze_violations = 0;
    std::vector<std::string> problems;
    for (auto &ex : example_programs()) {
        CAPTURE(ex.first);
        std::vector<std::string> size = {"width=48", "height=48"};
        std::vector<std::string> ropts = size;
        for (auto &o : reference().fixed()) ropts.push_back(o);
        Run ref = run_program(ex.first, ex.second, ropts);
        REQUIRE_MESSAGE(ref.status == PRAY_OK, ref.error);
        REQUIRE(!ref.frames.empty());
        CHECK(ref.frames[0].width == 48);
        CHECK(ref.frames[0].height == 48);
        CHECK(ref.frames.size() == (ex.first == "anim.ray" ? 3u : 1u));
        runs++;
        FreezeTally tests;
        for (const Opts &o : all_combinations()) {
            std::vector<std::string> opts = size;
            for (auto &x : o.fixed()) opts.push_back(x);
            Run r = run_program(ex.first, ex.second, opts);
            runs++;
            CHECK_MESSAGE(r.status == PRAY_OK, ex.first << ", " << o.text() << ": " << r.error);
            std::string d = frame_difference(ref.frames, r.frames);
            if (!d.empty()) {
                image_mismatches++;
                if (problems.size() < 20) problems.push_back(ex.first + ", " + o.text() + ": " + d);
            }
            tests.add(o, r.stats.intersection_tests);
        }
        freeze_violations += tests.violations(ex.first, problems);
    }
    double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::string all;
    for (auto &p : problems) all += "\n  - " + p;
    MESSAGE(runs << " program runs, " << image_mismatches << " differing images, " << freeze_violations
                 << " freeze violations, " << secs << " s");
    CHECK_MESSAGE(image_mismatches == 0, image_mismatches << " runs whose frames differ from brute=1:" << all);
    CHECK_MESSAGE(freeze_violations == 0, freeze_violations << " cases where freezing added intersection tests:" << all);
}

TEST_CASE("accel freezing: each evaluation path freezes: fewer intersection tests than freeze=0, the same image") {
    // Three scenes whose lists take each path of the list evaluator: a block minus cylinders
    // (holed plans: the flat sweep), a field of boxes of half-spaces (plain plans: the nearest
    // entry), and a block minus boxes (a union under the block: no plan, the full evaluation).
    // A ray that leaves a solid for good fixes its node, and its other members are skipped.
    const std::string head = "perspective <1.6, 0, 0>, <0, 0, -1.6>, [0.3, -5, 1.2], [0, 0, 0]\n"
                             "M = phong({0.7}, {0.2}, {0.1}, 10)\n";
    // Bx = the box of half side R around [X, Y, Z]
    const std::string box = "Bx = plane(M, [X + R, Y, Z], <1, 0, 0>) & plane(M, [X - R, Y, Z], <-1, 0, 0>) & "
                            "plane(M, [X, Y + R, Z], <0, 1, 0>) & plane(M, [X, Y - R, Z], <0, -1, 0>) & "
                            "plane(M, [X, Y, Z + R], <0, 0, 1>) & plane(M, [X, Y, Z - R], <0, 0, -1>)\n";
    const std::string tail = "rendertiff S | plane(M, [0, 0, -1.5], <0, 0, 1>), dirlight({0.8}, <-0.5, 1, -1.5>)\n";
    const std::string block = "X = 0\nY = 0\nZ = 0\nR = 1\n" + box + "S = Bx\n";
    struct Case {
        std::string name, body;
    } cases[] = {
        {"block minus cylinders",
         block + "I = 0\nwhile I < 5\n  A = -0.8 + 0.4*I\n  J = 0\n  while J < 5\n"
                 "    B = -0.8 + 0.4*J\n    S = S - cylinder(M, [A, 0, B], <0, 1, 0>, 0.1) - cylinder(M, [0, A, B], <1, 0, 0>, 0.1)\n"
                 "    J = J + 1\n  endwhile\n  I = I + 1\nendwhile\n"},
        {"field of boxes",
         "S = nothing\nR = 0.12\nI = 0\nwhile I < 8\n  J = 0\n  while J < 8\n"
         "    X = -1.4 + 0.4*I\n    Y = 0.2*((I + J) % 3)\n    Z = -1.4 + 0.4*J\n  " + box +
         "    S = S | Bx\n    J = J + 1\n  endwhile\n  I = I + 1\nendwhile\n"},
        {"block minus boxes",
         block + "R = 0.15\nI = 0\nwhile I < 4\n  J = 0\n  while J < 4\n"
                 "    X = -0.75 + 0.5*I\n    Z = -0.75 + 0.5*J\n    Y = -1\n  " + box + "    S = S - Bx\n"
                 "    Y = 1\n  " + box + "    S = S - Bx\n    J = J + 1\n  endwhile\n  I = I + 1\nendwhile\n"},
    };
    // (with plans=0 every list takes the full evaluation)
    for (int plans : {1, 0}) {
        for (const Case &k : cases) {
            CAPTURE(k.name);
            CAPTURE(plans);
            std::string prog = head + k.body + tail;
            std::vector<std::string> size = {"width=64", "height=64", "plans=" + std::to_string(plans)};
            Run on = run_program(k.name, prog, size);
            std::vector<std::string> off_opts = size;
            off_opts.push_back("freeze=0");
            Run off = run_program(k.name, prog, off_opts);
            REQUIRE_MESSAGE(on.status == PRAY_OK, on.error);
            REQUIRE_MESSAGE(off.status == PRAY_OK, off.error);
            CHECK(frame_difference(off.frames, on.frames) == "");
            CHECK(on.stats.frozen_skips > 0);
            CHECK(off.stats.frozen_skips == 0);
            CHECK(on.stats.intersection_tests < off.stats.intersection_tests);
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Random scenes rendered through pray_render: the same images, fewer tests with freezing.
// ---------------------------------------------------------------------------------------------
namespace {

struct Render {
    pray_status status = PRAY_OK;
    std::string error;
    std::vector<testkit::Frame> frames;  // one
    pray_stats stats;                    // of this render alone (differences of the totals)
};

Render render(pray_ctx *c, pray_object *root, pray_light *lights, const Opts &o, int size) {
    Render r;
    REQUIRE(apply(c, o));
    REQUIRE(pray_option(c, "width", size) == PRAY_OK);
    REQUIRE(pray_option(c, "height", size) == PRAY_OK);
    pray_stats before, after;
    pray_stats_get(c, &before);
    pray_image img;
    r.status = pray_render(c, root, lights, &img);
    pray_stats_get(c, &after);
    r.stats = after;
    r.stats.intersection_tests = after.intersection_tests - before.intersection_tests;
    r.stats.voxel_steps = after.voxel_steps - before.voxel_steps;
    r.stats.area_moves = after.area_moves - before.area_moves;
    r.stats.checks = after.checks - before.checks;
    r.stats.rays_primary = after.rays_primary - before.rays_primary;
    r.stats.rays_shadow = after.rays_shadow - before.rays_shadow;
    r.stats.rays_lightbuf = after.rays_lightbuf - before.rays_lightbuf;
    r.stats.rays_eyebuf = after.rays_eyebuf - before.rays_eyebuf;
    r.stats.rays_shadowcache = after.rays_shadowcache - before.rays_shadowcache;
    if (r.status != PRAY_OK) {
        r.error = pray_error(c);
        return r;
    }
    testkit::frame_sink(&r.frames, &img, "render");
    pray_image_free(c, &img);
    return r;
}

// A generated scene of the image tests: its kind and seed; mixed: its primitives of several
// materials (mixed_models), so that different materials touch and overlap.
struct Pick {
    int kind, seed;
    int mixed = 0;
};


pray_light *some_lights(pray_ctx *c) {
    pray_rgb w = {0.7, 0.7, 0.7}, w2 = {0.4, 0.4, 0.4};
    return pray_light_add(c, pray_dirlight(c, w, V(1, 2, -3)), pray_pointlight(c, w2, V(-2, -3, 2)));
}

// fn(c, s) for each picked scene, made in a context of its own, with the scene's label in the
// message of every check fn makes.
template <size_t N, class Fn> void each_pick(const Pick (&picks)[N], Fn fn) {
    for (const Pick &pk : picks) {
        pray_ctx *c = pray_new();
        REQUIRE(c);
        std::vector<pray_model *> mats = mixed_models(c);
        Scene s = make_scene(c, pk.kind, (uint64_t)pk.seed, pk.mixed ? &mats : nullptr);
        if (pk.mixed) s.label += ", mixed materials";
        CAPTURE(s.label);
        REQUIRE_MESSAGE(s.root, std::string(pray_error(c)));
        fn(c, s);
        pray_free(c);
    }
}

} // namespace

// (40 x 40, the three methods on: the buffers only on the coarsest grids, as above)
TEST_CASE("accel images: random scenes at 40 x 40, every grid x freeze x merge x bounds, and plans=0, the same floats as "
          "--brute; freezing never adds intersection tests") {
    const Pick picks[] = {{K_RANDOM, 3}, {K_RANDOM, 17}, {K_RANDOM, 42}, {K_RANDOM, 77}, {K_RANDOM, 101},
                          {K_MANY, 2},   {K_MANY, 5},    {K_LATTICE, 1}, {K_LATTICE, 4}, {K_BLOCKS, 3},
                          {K_BLOCKS, 12}, {K_FLOOR, 2},  {K_FLOOR, 9},   {K_SHAPES, 3},  {K_SHAPES, 8},
                          {K_RANDOM, 3, 1}, {K_RANDOM, 42, 1}, {K_RANDOM, 77, 1}, {K_MANY, 2, 1}, {K_LATTICE, 4, 1},
                          {K_BLOCKS, 3, 1}, {K_BLOCKS, 12, 1}, {K_FLOOR, 2, 1}, {K_FLOOR, 9, 1}, {K_SHAPES, 8, 1}};
    auto t0 = std::chrono::steady_clock::now();
    long renders = 0, image_mismatches = 0, freeze_violations = 0;
    std::vector<std::string> problems;
    each_pick(picks, [&](pray_ctx *c, const Scene &s) {
        pray_light *lights = some_lights(c);
        REQUIRE(lights);
        Render ref = render(c, s.root, lights, reference(), 40);
        REQUIRE_MESSAGE(ref.status == PRAY_OK, ref.error);
        renders++;
        FreezeTally tests;
        for (const Opts &o : all_combinations()) {
            Render r = render(c, s.root, lights, o, 40);
            renders++;
            CHECK_MESSAGE(r.status == PRAY_OK, s.label << ", " << o.text() << ": " << r.error);
            std::string d = frame_difference(ref.frames, r.frames);
            if (!d.empty()) {
                image_mismatches++;
                if (problems.size() < 20) problems.push_back(s.label + ", " + o.text() + ": " + d);
            }
            tests.add(o, r.stats.intersection_tests);
        }
        freeze_violations += tests.violations(s.label, problems);
    });
    double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::string all;
    for (auto &p : problems) all += "\n  - " + p;
    MESSAGE(renders << " renders of random scenes, " << image_mismatches << " differing images, " << freeze_violations
                    << " freeze violations, " << secs << " s");
    CHECK_MESSAGE(image_mismatches == 0, image_mismatches << " renders differ from brute=1:" << all);
    CHECK_MESSAGE(freeze_violations == 0, freeze_violations << " cases where freezing added intersection tests:" << all);
}

// ---------------------------------------------------------------------------------------------
// Statistics.
// ---------------------------------------------------------------------------------------------
namespace {

// 300 small spheres crowded into one corner and one sphere in the opposite corner: the grid
// between them is empty space, crossed by many rays.
pray_object *corner_cluster(pray_ctx *c, int *declared) {
    pray_rgb d = {0.6, 0.6, 0.6}, z = {0, 0, 0};
    pray_model *m = pray_phong(c, d, z, z, 1);
    Rng rng(2024);
    pray_object *root = nullptr;
    for (int i = 0; i < 300; i++) {
        pray_object *s = pray_sphere(c, m, V(rng.range(-1, -0.5), rng.range(-1, -0.5), rng.range(-1, -0.5)), rng.range(0.02, 0.06));
        root = root ? pray_csg(c, PRAY_UNION, root, s) : s;
    }
    root = pray_csg(c, PRAY_UNION, root, pray_sphere(c, m, V(0.8, 0.8, 0.8), 0.15));
    *declared = 301;
    return root;
}

std::string stats_text(const pray_stats &s) {
    char b[512];
    std::snprintf(b, sizeof b,
                  "primitives %ld declared %ld kept, nodes %ld, grid %d x %d x %d = %ld voxels, %ld lists, %ld areas, "
                  "memory %.0f, rays %.0f/%.0f, steps %.0f, moves %.0f, checks %.0f, tests %.0f, frozen %.0f",
                  s.primitives_declared, s.primitives, s.nodes, s.grid[0], s.grid[1], s.grid[2], s.voxels, s.lists,
                  s.areas, s.memory, s.rays_primary, s.rays_shadow, s.voxel_steps, s.area_moves, s.checks,
                  s.intersection_tests, s.frozen_skips);
    return b;
}

} // namespace

TEST_CASE("accel stats: a grid has voxels, lists and areas; merging moves through empty space; no grid has none") {
    pray_ctx *c = pray_new();
    REQUIRE(c);
    int declared = 0;
    pray_object *root = corner_cluster(c, &declared);
    REQUIRE(root);
    pray_light *lights = some_lights(c);
    for (int g : {16, 5, -1}) {
        for (int merge = 0; merge < 2; merge++) {
            Opts o{0, g, 1, merge, 1};
            Render r = render(c, root, lights, o, 32);
            const pray_stats &s = r.stats;
            INFO(o.text(), ": ", stats_text(s));
            REQUIRE(r.status == PRAY_OK);
            CHECK(s.grid[0] > 0);
            CHECK(s.grid[1] > 0);
            CHECK(s.grid[2] > 0);
            if (g > 0) CHECK(std::max(s.grid[0], std::max(s.grid[1], s.grid[2])) >= g);
            CHECK(s.voxels == (long)s.grid[0] * s.grid[1] * s.grid[2]);
            CHECK(s.lists >= 1);
            CHECK(s.areas >= 1);
            CHECK(s.areas <= s.voxels + s.nested_voxels);
            CHECK(s.memory > 0);
            CHECK(s.primitives_declared == declared);
            CHECK(s.primitives_declared >= s.primitives);
            CHECK(s.primitives >= 1);
            CHECK(s.nodes >= 1);
            CHECK(s.rays_primary == 32 * 32);
            CHECK(s.voxel_steps > 0);
            CHECK(s.checks > 0);
            CHECK(s.intersection_tests > 0);
            if (merge) {
                CHECK(s.area_moves > 0);
                CHECK(s.area_moves <= s.voxel_steps);
            } else
                CHECK(s.area_moves == 0);
        }
    }
    // no grid: grid=0, and the reference
    for (const Opts &o : {Opts{0, 0, 1, 1, 1}, Opts{0, 0, 0, 0, 0}}) {
        Render r = render(c, root, lights, o, 32);
        const pray_stats &s = r.stats;
        INFO(o.text(), ": ", stats_text(s));
        REQUIRE(r.status == PRAY_OK);
        CHECK(s.grid[0] == 0);
        CHECK(s.grid[1] == 0);
        CHECK(s.grid[2] == 0);
        CHECK(s.voxels == 0);
        CHECK(s.voxel_steps == 0);
        CHECK(s.area_moves == 0);
        CHECK(s.primitives_declared >= s.primitives);
        CHECK(s.intersection_tests > 0);
    }
    pray_free(c);
    pray_ctx *b = pray_new();  // a fresh context: the reference builds no grid at all
    REQUIRE(b);
    root = corner_cluster(b, &declared);
    Render r = render(b, root, nullptr, reference(), 16);
    INFO("brute=1: ", stats_text(r.stats));
    REQUIRE(r.status == PRAY_OK);
    CHECK(r.stats.grid[0] == 0);
    CHECK(r.stats.grid[1] == 0);
    CHECK(r.stats.grid[2] == 0);
    CHECK(r.stats.voxels == 0);
    CHECK(r.stats.primitives_declared == declared);
    CHECK(r.stats.primitives_declared >= r.stats.primitives);
    // every primitive is tested on every ray by the reference
    CHECK(r.stats.intersection_tests >= r.stats.rays_primary * r.stats.primitives);
    pray_free(b);
}

// A PRAY loop that adds n balls of model M to All, at random X, Y, Z in [0, 1) (a Lehmer
// generator seeded with 7); `where` is the sphere's point and radius written with them.
static std::string random_balls(int n, const std::string &where) {
    return "S = 7\nN = 0\nwhile N < " + std::to_string(n) +
           "\n"
           "  S = (S*16807) % 2147483647\n"
           "  X = S/2147483647\n"
           "  S = (S*16807) % 2147483647\n"
           "  Y = S/2147483647\n"
           "  S = (S*16807) % 2147483647\n"
           "  Z = S/2147483647\n"
           "  All = All | sphere(M, " + where + ")\n"
           "  N = N + 1\n"
           "endwhile\n";
}

TEST_CASE("accel stats: a layer of balls over a floor is divided as finely as without the floor") {
    // 300 small balls in a flat layer in a corner of a voxel, which the floor crosses: the nested
    // grid covers the layer's box, not the floor's, and has the voxels it has without the floor
    const std::string program =
        "M = phong({0.6}, {0.3}, {0.1}, 10)\n"
        "All = sphere(M, [0.8, 0.8, 0.8], 0.15)\n"
        + random_balls(300, "[-0.9 + 0.5*X, -0.9 + 0.5*Y, -0.7 + 0.1*Z], 0.02") +
        "FLOOR\n"
        "perspective <1, 0, 0>, <0, 0.8, 0.6>, [0, -3, 2.5], [0, 0, 0]\n"
        "rendertiff All, dirlight({1}, <1, 2, -3>)\n";
    const std::vector<std::string> options = {"grid=2", "nest=1", "width=64", "height=64"};
    Run runs[2];
    for (int floor = 0; floor < 2; floor++) {
        std::string text = program;
        text.replace(text.find("FLOOR"), 5, floor ? "All = All | plane(M, [0, 0, -0.75], <0, 0, 1>)" : "");
        runs[floor] = run_program("layer.ray", text, options);
        INFO("floor ", floor, ": ", stats_text(runs[floor].stats));
        REQUIRE(runs[floor].status == PRAY_OK);
        CHECK(runs[floor].stats.nested_grids > 0);
    }
    CHECK(runs[1].stats.nested_grids == runs[0].stats.nested_grids);
    CHECK(runs[1].stats.nested_voxels == runs[0].stats.nested_voxels);
    // and the image is the reference's
    std::vector<std::string> brute = options;
    brute.push_back("brute=1");
    std::string text = program;
    text.replace(text.find("FLOOR"), 5, "All = All | plane(M, [0, 0, -0.75], <0, 0, 1>)");
    Run ref = run_program("layer.ray", text, brute);
    REQUIRE(ref.status == PRAY_OK);
    CHECK(frame_difference(ref.frames, runs[1].frames) == "");
}

TEST_CASE("accel stats: a crowd of boxes of six half-spaces nests like the same boxes made by box") {
    // 150 small cubes in one corner of a voxel, each an intersection of six half-spaces or one
    // `box`: an object is the node above its half-spaces, so the nested grids are the same
    std::string program = "M = phong({0.6}, {0.3}, {0.1}, 10)\nAll = sphere(M, [0.8, 0.8, 0.8], 0.15)\n" +
                          random_balls(150, "[-0.9 + 0.5*X, -0.9 + 0.5*Y, -0.9 + 0.5*Z], 0.02");
    program += "perspective <1, 0, 0>, <0, 0.8, 0.6>, [0, -3, 2.5], [0, 0, 0]\n"
               "rendertiff All | plane(M, [0, 0, -0.95], <0, 0, 1>), dirlight({1}, <1, 2, -3>)\n";
    const std::string ball = "All = All | sphere(M, [-0.9 + 0.5*X, -0.9 + 0.5*Y, -0.9 + 0.5*Z], 0.02)\n";
    const std::string made[2] = {
        "R = 0.02\nP = [-0.9 + 0.5*X, -0.9 + 0.5*Y, -0.9 + 0.5*Z]\n"
        "All = All | (plane(M, P + <R, 0, 0>, <1, 0, 0>) & plane(M, P - <R, 0, 0>, <-1, 0, 0>) & "
        "plane(M, P + <0, R, 0>, <0, 1, 0>) & plane(M, P - <0, R, 0>, <0, -1, 0>) & "
        "plane(M, P + <0, 0, R>, <0, 0, 1>) & plane(M, P - <0, 0, R>, <0, 0, -1>))\n",
        "All = All | box(M, [-0.92 + 0.5*X, -0.92 + 0.5*Y, -0.92 + 0.5*Z], [-0.88 + 0.5*X, -0.88 + 0.5*Y, -0.88 + 0.5*Z])\n"};
    const std::vector<std::string> options = {"grid=2", "nest=1", "width=64", "height=64"};
    Run runs[2];
    for (int k = 0; k < 2; k++) {
        std::string text = program;
        text.replace(text.find(ball), ball.size(), made[k]);
        runs[k] = run_program("cubes.ray", text, options);
        INFO("made by ", k ? "box" : "half-spaces", ": ", stats_text(runs[k].stats));
        REQUIRE(runs[k].status == PRAY_OK);
        CHECK(runs[k].stats.nested_grids > 0);
        std::vector<std::string> brute = options;
        brute.push_back("brute=1");
        Run ref = run_program("cubes.ray", text, brute);
        REQUIRE(ref.status == PRAY_OK);
        CHECK(frame_difference(ref.frames, runs[k].frames) == "");
    }
    CHECK(runs[0].stats.nested_grids == runs[1].stats.nested_grids);
    CHECK(runs[0].stats.nested_voxels == runs[1].stats.nested_voxels);
}

TEST_CASE("accel stats: a few parts far from a cluster are left out of the grid's box") {
    // 400 balls in a unit cube and three moons (one of them a difference) a thousand units away,
    // in view: the grid covers the balls as without the moons, which the outer list holds
    const std::string program =
        "M = phong({0.6}, {0.3}, {0.1}, 10)\n"
        "All = nothing\n"
        + random_balls(400, "[X, Y, Z], 0.04") +
        "MOONS\n"
        "perspective <1.2, 0, 0>, <0, 0, 1.2>, [0.5, -3, 0.5], [0.5, 0, 0.5]\n"
        "rendertiff All, dirlight({1}, <1, -2, 3>)\n";
    const std::string moons = "All = All | (sphere(M, [-200, 1000, 0], 60) - sphere(M, [-200, 960, 0], 40)) "
                              "| sphere(M, [150, 1100, 100], 50) | sphere(M, [0, 900, -150], 30)";
    const std::vector<std::string> options = {"width=64", "height=64"};
    Run runs[2];
    for (int with = 0; with < 2; with++) {
        std::string text = program;
        text.replace(text.find("MOONS"), 5, with ? moons : "");
        runs[with] = run_program("moons.ray", text, options);
        INFO("moons ", with, ": ", stats_text(runs[with].stats));
        REQUIRE(runs[with].status == PRAY_OK);
    }
    for (int l = 0; l < 3; l++) CHECK(runs[1].stats.grid[l] == runs[0].stats.grid[l]);
    CHECK(runs[1].stats.nested_grids == runs[0].stats.nested_grids);
    // and the image is the reference's, with and without bounds
    for (int bounds = 0; bounds < 2; bounds++) {
        std::vector<std::string> opts = options;
        opts.push_back(bounds ? "bounds=1" : "bounds=0");
        std::string text = program;
        text.replace(text.find("MOONS"), 5, moons);
        Run run = run_program("moons.ray", text, opts);
        opts.push_back("brute=1");
        Run ref = run_program("moons.ray", text, opts);
        REQUIRE(run.status == PRAY_OK);
        REQUIRE(ref.status == PRAY_OK);
        CHECK(frame_difference(ref.frames, run.frames) == "");
    }
}

TEST_CASE("accel stats: of a program run; parts that cannot matter are not kept") {
    // A sphere minus a sphere far away: with bounds the subtracted part is dropped.
    const std::string program =
        "M = phong({0.5}, {0}, 1)\n"
        "A = sphere(M, [0, 0, 0], 0.5) - sphere(M, [3, 0, 0], 0.5)\n"
        "B = A | sphere(M, [0.5, 0, 0.5], 0.2) | sphere(M, [-0.5, 0, 0.5], 0.2) | sphere(M, [0, 0.5, -0.5], 0.2)\n"
        "rendertiff B | sphere(M, [0.9, 0.9, 0.9], 0.1), dirlight({1}, <1, 1, -1>)\n";
    for (int bounds = 0; bounds < 2; bounds++) {
        Run r = run_program("stats.ray", program, {"width=24", "height=24", "grid=6", "merge=1", "freeze=1", "brute=0",
                                                    "bounds=" + std::to_string(bounds)});
        INFO("bounds=", bounds, ": ", stats_text(r.stats));
        REQUIRE_MESSAGE(r.status == PRAY_OK, r.error);
        CHECK(r.stats.primitives_declared == 6);
        CHECK(r.stats.primitives_declared >= r.stats.primitives);
        if (bounds) CHECK(r.stats.primitives < r.stats.primitives_declared);
        CHECK(r.stats.grid[0] > 0);
        CHECK(r.stats.voxels == (long)r.stats.grid[0] * r.stats.grid[1] * r.stats.grid[2]);
        CHECK(r.stats.lists >= 1);
        CHECK(r.stats.areas >= 1);
        CHECK(r.stats.rays_primary == 24 * 24);
        CHECK(r.stats.voxel_steps > 0);
    }
    Run r = run_program("stats.ray", program, {"width=24", "height=24", "grid=0", "brute=0"});
    INFO("grid=0: ", stats_text(r.stats));
    REQUIRE_MESSAGE(r.status == PRAY_OK, r.error);
    CHECK(r.stats.grid[0] == 0);
    CHECK(r.stats.grid[1] == 0);
    CHECK(r.stats.grid[2] == 0);
    CHECK(r.stats.voxels == 0);
}

// ---------------------------------------------------------------------------------------------
// The methods of shadow and primary rays, each with its option: light buffers (a list per voxel
// of a buffer around each light), the eye's buffer (the same around a perspective camera's eye,
// for primary rays) and the shadow cache (a shadow ray first tries the voxel where the last one
// was stopped). On or off, the images are the reference's, float for float, with the lights
// outside the scene, inside its grid and amid its objects. A buffer is built only for an image
// with enough samples per voxel of the buffer: the cases use image sizes and grids where they
// are, and check that they were, which checks the cases' setup (without the buffers they would
// compare nothing of them), not how often the buffers answer.
// ---------------------------------------------------------------------------------------------
namespace {

// Renders of scenes with one switch off and on, compared float for float with the reference's.
struct SwitchTally {
    long renders = 0, mismatches = 0;
    double used = 0;                    // rays the switched method answered
    std::vector<std::string> problems;  // the first 20
};

// Of the renders with a switch on: how many had a grid; how many built a buffer (which takes a
// grid: a scene of one unbounded primitive, or of nothing, has none).
struct Built {
    long grid = 0, buffer = 0;
    void add(const Built &b) { grid += b.grid, buffer += b.buffer; }
    // (setup) the buffer was built wherever it could be
    void check(const std::string &label) const {
        if (grid) CHECK_MESSAGE(buffer > 0, label << ": (setup) no render built a buffer");
    }
};

// A scene rendered with the switch `sw` (named `option`) off and on at each grid size. With the
// switch off, `counted` (the rays the method answered) and `built` (the voxels of its buffer;
// null for the shadow cache) stay 0: the option is obeyed.
Built render_switched(pray_ctx *c, pray_object *root, pray_light *lights, const Render &ref, int Opts::*sw,
                     const char *option, double pray_stats::*counted, long pray_stats::*built,
                     std::initializer_list<int> grids, int size, const std::string &label, SwitchTally &t) {
    Built n;
    for (int grid : grids) {
        for (int on = 0; on < 2; on++) {
            Opts o{0, grid, 1, 1, 1};
            o.*sw = on;
            std::string what = label + ", grid=" + std::to_string(grid) + " " + option + "=" + std::to_string(on);
            Render r = render(c, root, lights, o, size);
            t.renders++;
            CHECK_MESSAGE(r.status == PRAY_OK, what << ": " << r.error);
            if (on) {
                t.used += r.stats.*counted;
                n.grid += r.stats.grid[0] > 0;
                n.buffer += built && r.stats.*built > 0;
            } else {
                CHECK_MESSAGE(r.stats.*counted == 0, what);
                if (built) CHECK_MESSAGE(r.stats.*built == 0, what);
            }
            std::string d = frame_difference(ref.frames, r.frames);
            if (!d.empty() && ++t.mismatches <= 20) t.problems.push_back(what + ": " + d);
        }
    }
    return n;
}

void check_tally(const SwitchTally &t, const char *option) {
    std::string all;
    for (auto &p : t.problems) all += "\n  - " + p;
    MESSAGE(t.renders << " renders with " << std::string(option) << " 0 and 1, " << t.mismatches << " differing from brute=1");
    CHECK_MESSAGE(t.mismatches == 0, t.mismatches << " renders differ from brute=1:" << all);
}

// Renders of picked random scenes under four lights, with a switch of shadow rays off and on,
// tallied against the reference: a directional light, a point light far outside, one inside
// the grid's box, and one on the scene's centre (amid or inside the objects). With `built`,
// each scene with a grid must have built a buffer at one of the grids at least.
template <size_t N>
void shadow_switch_picks(const Pick (&picks)[N], int Opts::*sw, const char *option, double pray_stats::*counted,
                         long pray_stats::*built, std::initializer_list<int> grids, int size, SwitchTally &t) {
    pray_rgb w = {0.6, 0.6, 0.6}, w2 = {0.5, 0.4, 0.3};
    each_pick(picks, [&](pray_ctx *c, const Scene &s) {
        pray_vec lo = s.lo, hi = s.hi, mid = mul(add(lo, hi), 0.5), ext = sub(hi, lo);
        pray_light *lights = pray_light_add(
            c, pray_light_add(c, pray_dirlight(c, w, V(1, 2, -3)), pray_pointlight(c, w2, add(hi, ext))),
            pray_light_add(c, pray_pointlight(c, w2, add(lo, mul(ext, 0.3))), pray_pointlight(c, w2, mid)));
        REQUIRE(lights);
        Render ref = render(c, s.root, lights, reference(), size);
        REQUIRE_MESSAGE(ref.status == PRAY_OK, ref.error);
        Built n = render_switched(c, s.root, lights, ref, sw, option, counted, built, grids, size, s.label, t);
        if (built) n.check(s.label);
    });
    check_tally(t, option);
}

// The field of spheres of the buffers' tests: 400 small balls on a plane, the camera's vectors
// (for `perspective` or `parallel`) looking down on it at 45 degrees; the lights are added.
const char *const FIELD_CAMERA = " <1.2, 0, 0>, <0, 0.85, 0.85>, [0, -3, 3], [0, 0, 0]\n";
const char *const FIELD =
    "M = phong({0.7}, {0.3}, 20)\nAll = nothing\nI = 0\nwhile I < 400\n"
    "  All = All | sphere(M, [(I % 20 - 9.5) * 0.1, ((I - I % 20) / 20 - 9.5) * 0.1, 0.05 * (I % 7)], 0.04)\n"
    "  I = I + 1\nendwhile\n";

// A program run with a switch on (its default), off, and as the reference: both images must be
// the reference's.
struct Switched {
    Run on, off;
};

Switched run_switched(const std::string &program, std::vector<std::string> opts, const char *option) {
    Switched r;
    r.on = run_program("field.ray", program, opts);
    opts.push_back(std::string(option) + "=0");
    r.off = run_program("field.ray", program, opts);
    opts.back() = "brute=1";
    Run brute = run_program("field.ray", program, opts);
    REQUIRE_MESSAGE(r.on.status == PRAY_OK, r.on.error);
    REQUIRE_MESSAGE(r.off.status == PRAY_OK, r.off.error);
    REQUIRE_MESSAGE(brute.status == PRAY_OK, brute.error);
    CHECK(frame_difference(brute.frames, r.on.frames) == "");
    CHECK(frame_difference(brute.frames, r.off.frames) == "");
    return r;
}

} // namespace

TEST_CASE("accel light buffers: lightbuffer=0 and 1 give the reference's image, lights outside, inside and amid "
          "the objects; a field of spheres under the sun and a lamp") {
    const Pick picks[] = {{K_RANDOM, 5},  {K_RANDOM, 23}, {K_RANDOM, 64}, {K_MANY, 1},   {K_MANY, 7},
                          {K_LATTICE, 2}, {K_LATTICE, 9}, {K_BLOCKS, 4},  {K_FLOOR, 3},  {K_FLOOR, 11},
                          {K_SCALED, 2},  {K_SCALED, 6},  {K_SCALED, 13}, {K_SHAPES, 5}};
    SwitchTally t;
    // (128 x 128 and coarse grids: a buffer is built for images with enough pixels per voxel)
    shadow_switch_picks(picks, &Opts::lightbuffer, "lightbuffer", &pray_stats::rays_lightbuf, &pray_stats::lightbuf_voxels,
                        {3, 5, 8}, 128, t);

    std::string program = std::string("perspective") + FIELD_CAMERA + FIELD +
                          "rendertiff All, dirlight({0.7}, <1, 2, -3>), pointlight({0.5}, [0.5, 0.5, 3])\n";
    // (a coarse grid, as in the eye's buffer's case below: buffers of few voxels)
    Switched r = run_switched(program, {"width=160", "height=160", "shadows=1", "grid=12"}, "lightbuffer");
    INFO("lightbuffer=1: ", stats_text(r.on.stats), "; lightbuffer=0: ", stats_text(r.off.stats));
    CHECK(r.on.stats.lightbuf_voxels > 0);  // (setup)
    CHECK(r.on.stats.rays_shadow > 1000);   // (setup)
    CHECK(r.off.stats.lightbuf_voxels == 0);
    CHECK(r.off.stats.rays_lightbuf == 0);
}

TEST_CASE("accel shadow cache: shadowcache=0 and 1 give the reference's image, through glass and with lights amid "
          "the objects; a table and a pane of glass over a field of spheres; a cluster in nested grids") {
    const Pick picks[] = {{K_RANDOM, 30}, {K_RANDOM, 41}, {K_RANDOM, 64}, {K_RANDOM, 66}, {K_MANY, 4},  {K_LATTICE, 3},
                          {K_BLOCKS, 7},  {K_FLOOR, 5},   {K_FLOOR, 12},  {K_SCALED, 2},  {K_SCALED, 6},
                          {K_SHAPES, 11}, {K_CLUSTER, 2}, {K_CLUSTER, 5}, {K_RANDOM, 30, 1}, {K_BLOCKS, 7, 1},
                          {K_FLOOR, 5, 1}, {K_CLUSTER, 2, 1}};
    SwitchTally t;
    // (the lamps amid the objects end their shadow rays in voxels that hold surfaces beyond them)
    shadow_switch_picks(picks, &Opts::shadowcache, "shadowcache", &pray_stats::rays_shadowcache, nullptr, {3, 8}, 64, t);
    CHECK_MESSAGE(t.used > 0, "(setup) the cache stopped no shadow ray: the comparison does not cover it");

    // A table, and a pane of coloured glass with a bar across it, over the field of spheres on
    // a floor, under the sun and a lamp: the cache holds the table and the bar; the pane, though
    // its glass is in the bar's voxels, lets light through. The lamp hangs just over the table,
    // in voxels that hold its top.
    auto box = [](const char *m, const char *lo, const char *hi) {
        std::string b;
        for (int k = 0; k < 6; k++)
            b += std::string(k ? " & " : "") + "plane(" + m + ", " + (k & 1 ? lo : hi) + ", <" + (k / 2 == 0 ? "1, 0, 0" : k / 2 == 1 ? "0, 1, 0" : "0, 0, 1") + "> * " + (k & 1 ? "-1" : "1") + ")";
        return b;
    };
    std::string program = std::string("perspective") + FIELD_CAMERA + FIELD +
                          "G = transparent({0.9, 0.6, 0.3}, 1) + phong({0.1}, {0.2}, 10)\n"
                          "T = " + box("M", "[-0.6, -0.6, 0.4]", "[0.3, 0.5, 0.45]") + "\n" +
                          "P = " + box("G", "[0.4, -0.9, 0.5]", "[0.9, 0.2, 0.52]") + "\n" +
                          "B = " + box("M", "[0.62, -0.9, 0.5]", "[0.68, 0.2, 0.52]") + "\n" +
                          "F = " + box("M", "[-1.2, -1.2, -0.1]", "[1.2, 1.2, -0.04]") + "\n" +
                          "rendertiff All | T | P | B | F, dirlight({0.7}, <0.3, -1, -1>), pointlight({0.5}, [-0.1, 0, 0.5])\n";
    // (without light buffers, which would answer those shadow rays first)
    Switched r = run_switched(program, {"width=160", "height=160", "shadows=1", "grid=12", "lightbuffer=0"}, "shadowcache");
    INFO("shadowcache=1: ", stats_text(r.on.stats), "; shadow rays stopped by the cache ", r.on.stats.rays_shadowcache);
    CHECK(r.on.stats.rays_shadow > 10000);    // (setup)
    CHECK(r.on.stats.rays_shadowcache > 0);   // (setup)
    CHECK(r.off.stats.rays_shadowcache == 0);

    // A glass that gives out more light than it takes in (1.5 times) could make the product of
    // a long shadow ray overflow before it meets the opaque surface, which the cache would have
    // stopped at once: the images could differ, so no cache in such a scene. (An image that
    // shows it takes hundreds of panes; the rule is checked instead.)
    std::string bright = program;
    const std::string pane = "transparent({0.9, 0.6, 0.3}";
    bright.replace(bright.find(pane), pane.size(), "transparent({0.9, 1.5, 0.3}");
    REQUIRE(bright != program);
    Switched b = run_switched(bright, {"width=160", "height=160", "shadows=1", "grid=12", "lightbuffer=0"}, "shadowcache");
    CHECK(b.on.stats.rays_shadow > 10000);  // (setup)
    CHECK(b.on.stats.rays_shadowcache == 0);

    // A cluster of 1000 small balls in two voxels, each with a grid of its own: the cache keeps
    // voxels of nested grids (where that box's list holds: test_internal, blocker_of)
    const std::string cluster =
        "M = phong({0.6}, {0.3}, {0.1}, 10)\n"
        "All = sphere(M, [3, 3, 3], 0.15)\n"
        + random_balls(1000, "[-0.5 + X, -0.5 + Y, -0.5 + Z], 0.04") +
        "perspective <0.6, 0, 0>, <0, 0.5, 0.4>, [0, -3, 1], [0, 0, 0]\n"
        "rendertiff All, dirlight({1}, <1, 2, -3>)\n";
    Switched n = run_switched(cluster, {"width=64", "height=64", "shadows=1", "grid=2"}, "shadowcache");
    INFO("shadowcache=1: ", stats_text(n.on.stats), "; shadow rays stopped by the cache ", n.on.stats.rays_shadowcache);
    CHECK(n.on.stats.nested_grids > 0);  // (setup)
}

TEST_CASE("accel threads: the counts of a render are the same for 1, 2, 3 and 8 threads") {
    // Each band of the image starts with the shadow cache empty, not with what the thread's
    // last band left in it: what the cache does, and so every count, is the same whichever
    // thread renders which band. (Before, the floor scenes' counts changed from run to run.)
    const Pick picks[] = {{K_FLOOR, 2}, {K_FLOOR, 5}, {K_FLOOR, 9}, {K_RANDOM, 30}, {K_BLOCKS, 7}};
    long renders = 0;
    each_pick(picks, [&](pray_ctx *c, const Scene &s) {
        pray_light *lights = some_lights(c);
        REQUIRE(lights);
        auto with = [&](int threads, int grid) {  // a render with that many threads
            REQUIRE(pray_option(c, "threads", threads) == PRAY_OK);
            Render r = render(c, s.root, lights, Opts{0, grid, 1, 1, 1}, 40);
            REQUIRE_MESSAGE(r.status == PRAY_OK, r.error);
            return r;
        };
        for (int grid : {1, 2, 3}) {
            Render one = with(1, grid);
            for (int threads : {2, 3, 8}) {
                Render more = with(threads, grid);
                renders++;
                CAPTURE(grid);
                CAPTURE(threads);
                CHECK(frame_difference(one.frames, more.frames) == "");
                CHECK(more.stats.rays_shadowcache == one.stats.rays_shadowcache);
                CHECK(more.stats.intersection_tests == one.stats.intersection_tests);
                CHECK(more.stats.voxel_steps == one.stats.voxel_steps);
            }
        }
    });
    MESSAGE(renders << " renders with 2, 3 and 8 threads compared with one thread");
}

TEST_CASE("accel eye buffer: eyebuffer=0 and 1 give the reference's image from eyes outside, inside, on the edge of "
          "and far from the grid's box; a field of spheres; none for a parallel camera") {
    const Pick picks[] = {{K_RANDOM, 4},  {K_RANDOM, 31}, {K_MANY, 3},   {K_MANY, 8},   {K_LATTICE, 5},
                          {K_BLOCKS, 6},  {K_FLOOR, 4},   {K_FLOOR, 13}, {K_SCALED, 3}, {K_SCALED, 9}, {K_SHAPES, 6},
                          {K_RANDOM, 31, 1}, {K_BLOCKS, 6, 1}, {K_FLOOR, 13, 1}};
    SwitchTally t;
    each_pick(picks, [&](pray_ctx *c, const Scene &s) {
        pray_light *lights = some_lights(c);
        REQUIRE(lights);
        pray_vec lo = s.lo, hi = s.hi, mid = mul(add(lo, hi), 0.5), size = sub(hi, lo);
        double big = std::max(size.x, std::max(size.y, size.z));
        struct Eye {
            const char *name;
            pray_vec at;
        };
        // (a corner of the box: on three of its faces, and on the edges of the buffer's faces)
        const Eye eyes[] = {{"outside", add(mid, V(0.3 * big, -2.5 * big, 0.8 * big))},
                            {"amid the objects", add(mid, mul(size, 0.1))},
                            {"on a corner of the box", lo},
                            {"far away", add(mid, V(-300 * big, -500 * big, 200 * big))}};
        Built built;
        for (const Eye &e : eyes) {
            pray_vec look = sub(mid, e.at);
            if (dot(look, look) < 1e-6 * big * big) look = V(0, big, 0);
            pray_vec side = cross(look, V(0, 0, 1));
            if (dot(side, side) < 1e-12 * dot(look, look)) side = cross(look, V(1, 0, 0));
            pray_vec x = mul(unit(side), 0.6 * big), y = mul(unit(cross(look, x)), 0.6 * big);
            REQUIRE(pray_perspective(c, x, y, e.at, add(e.at, mul(unit(look), big))) == PRAY_OK);
            Render ref = render(c, s.root, lights, reference(), 64);
            REQUIRE_MESSAGE(ref.status == PRAY_OK, ref.error);
            built.add(render_switched(c, s.root, lights, ref, &Opts::eyebuffer, "eyebuffer", &pray_stats::rays_eyebuf,
                                     &pray_stats::eyebuf_voxels, {3, 8}, 64, s.label + ", eye " + e.name, t));
        }
        built.check(s.label);
    });
    check_tally(t, "eyebuffer");

    // A field of spheres seen from above; and through a parallel projection, which has no eye
    // (its rays are parallel): no eye's buffer.
    std::string field = std::string(FIELD_CAMERA) + FIELD + "rendertiff All, dirlight({0.7}, <1, 2, -3>)\n";
    // (a coarse grid: the buffer's cells are as wide as its voxels, and this image has pixels
    // enough for that many)
    const std::vector<std::string> opts = {"width=160", "height=160", "shadows=0", "grid=12"};
    Switched r = run_switched("perspective" + field, opts, "eyebuffer");
    INFO("eyebuffer=1: ", stats_text(r.on.stats), "; eyebuffer=0: ", stats_text(r.off.stats));
    CHECK(r.on.stats.eyebuf_voxels > 0);  // (setup)
    CHECK(r.off.stats.eyebuf_voxels == 0);
    CHECK(r.off.stats.rays_eyebuf == 0);
    Switched par = run_switched("parallel" + field, opts, "eyebuffer");
    CHECK(par.on.stats.eyebuf_voxels == 0);
    CHECK(par.on.stats.rays_eyebuf == 0);
}

// ---------------------------------------------------------------------------------------------
// The buffers where they are built, with everything switched: example programs and random
// scenes, each rendered with every combination of lightbuffer x eyebuffer x shadowcache x
// freeze x merge (x bounds for the random scenes), the same floats as --brute; freezing never
// adds intersection tests.
// ---------------------------------------------------------------------------------------------
namespace {

struct NetTally {
    long renders = 0, mismatches = 0, freeze_violations = 0;
    std::vector<std::string> problems;  // the first 30
    void problem(const std::string &p) {
        if (problems.size() < 30) problems.push_back(p);
    }
};

// Renders `label` with each of `combos` (run(o) returns a Run or a Render) and compares it with
// the reference's frames; each combination with freeze=1 against the same with freeze=0. Returns
// the statistics of the first combination (all on, the defaults).
template <class Fn>
pray_stats compare_combinations(const std::string &label, const std::vector<testkit::Frame> &ref,
                                const std::vector<Opts> &combos, Fn run, NetTally &t) {
    pray_stats first;
    std::memset(&first, 0, sizeof first);
    std::map<std::string, double> tests[2];  // per freeze: by the other options
    for (size_t i = 0; i < combos.size(); i++) {
        const Opts &o = combos[i];
        auto r = run(o);
        t.renders++;
        CHECK_MESSAGE(r.status == PRAY_OK, label << ", " << o.text() << ": " << r.error);
        if (i == 0) first = r.stats;
        std::string d = frame_difference(ref, r.frames);
        if (!d.empty()) {
            t.mismatches++;
            t.problem(label + ", " + o.text() + ": " + d);
        }
        Opts k = o;
        k.freeze = 0;
        tests[o.freeze][k.text()] = r.stats.intersection_tests;
    }
    for (auto &f : tests[1]) {
        auto u = tests[0].find(f.first);
        if (u == tests[0].end() || f.second <= u->second) continue;
        t.freeze_violations++;
        char buf[120];
        std::snprintf(buf, sizeof buf, ": %.0f intersection tests with freeze=1, %.0f with freeze=0", f.second, u->second);
        t.problem(label + ", " + f.first + buf);
    }
    return first;
}

void check_net(const NetTally &t, double secs) {
    std::string all;
    for (auto &p : t.problems) all += "\n  - " + p;
    MESSAGE(t.renders << " renders, " << t.mismatches << " differing images, " << t.freeze_violations
                      << " freeze violations, " << secs << " s");
    CHECK_MESSAGE(t.mismatches == 0, t.mismatches << " renders differ from brute=1:" << all);
    CHECK_MESSAGE(t.freeze_violations == 0, t.freeze_violations << " cases where freezing added intersection tests:" << all);
}

// A program of the net: its name, text, and which buffers its default render must build.
struct NetProgram {
    std::string name, text;
    bool light, eye;
};

// Each program at size x size with the combinations of buffer_combinations(grid, with_bounds); in
// the first (the defaults) the buffers must have been built.
void program_net(const std::vector<NetProgram> &programs, int size, int grid, bool with_bounds, NetTally &t) {
    std::vector<std::string> dims = {"width=" + std::to_string(size), "height=" + std::to_string(size)};
    for (const NetProgram &p : programs) {
        CAPTURE(p.name);
        std::vector<std::string> ropts = dims;
        for (auto &o : reference().fixed()) ropts.push_back(o);
        Run ref = run_program(p.name, p.text, ropts);
        REQUIRE_MESSAGE(ref.status == PRAY_OK, ref.error);
        REQUIRE(!ref.frames.empty());
        CHECK(ref.frames[0].width == size);
        pray_stats on = compare_combinations(p.name, ref.frames, buffer_combinations(grid, with_bounds), [&](const Opts &o) {
            std::vector<std::string> opts = dims;
            for (auto &x : o.fixed()) opts.push_back(x);
            return run_program(p.name, p.text, opts);
        }, t);
        INFO("defaults: ", stats_text(on));
        if (p.light) CHECK_MESSAGE(on.lightbuf_voxels > 0, p.name << ": (setup) no light buffer built");
        if (p.eye) CHECK_MESSAGE(on.eyebuf_voxels > 0, p.name << ": (setup) no eye's buffer built");
    }
}

std::vector<NetProgram> examples_of(std::initializer_list<NetProgram> list) {
    std::vector<NetProgram> v;
    for (NetProgram p : list)
        if (read_example(p.name, &p.text)) v.push_back(p);
    return v;
}

// A point light in a lamp: a shade of thin fabric (a ball minus a smaller ball minus the
// half-space under its middle) around a bulb, over the field of spheres, all inside a room (a
// hollow ball), so that shadow rays come to the light from every side: through the shade, and
// through its opening. `bulb`: what the bulb lets through.
std::string lamp_program(const char *bulb) {
    return std::string("perspective") + FIELD_CAMERA + FIELD +
           "Shade = transparent({0.6, 0.5, 0.4}, 1) + phong({0.5}, {0.1}, 5)\n"
           "S = [0.2, 0.1, 0.6]\n"
           "Lamp = sphere(Shade, S, 0.26) - sphere(Shade, S, 0.245) - plane(Shade, S, <0, 0, 1>)"
           " | sphere(color({1}) + transparent(" + bulb + ", 1), S, 0.05)\n"
           "Room = -sphere(phong({0.6, 0.6, 0.5}, {0}, 1), [0, 0, 0.5], 5)\n"
           "rendertiff All | Lamp | Room, pointlight({0.8}, S)\n";
}

} // namespace

// (bounds=1 only: the random scenes' case below switches it)
TEST_CASE("accel buffers: examples at 160 x 160 on a grid of 8, where the buffers are built, every lightbuffer x "
          "eyebuffer x shadowcache x freeze x merge: the same floats as --brute; freezing never adds tests") {
    auto t0 = std::chrono::steady_clock::now();
    // (room.ray: its eye is amid the grid, whose buffer would have too many voxels for this
    // image; parallel.ray: a parallel camera has no eye's buffer; anim.ray: three frames)
    std::vector<NetProgram> programs = examples_of({{"room.ray", "", true, false},
                                                    {"fractal.ray", "", true, true},
                                                    {"glass.ray", "", true, true},
                                                    {"cube.ray", "", true, true},
                                                    {"csg.ray", "", true, true},
                                                    {"holes.ray", "", true, true},
                                                    {"mirror.ray", "", true, true},
                                                    {"models.ray", "", true, true},
                                                    {"anim.ray", "", true, true},
                                                    {"parallel.ray", "", true, false}});
    programs.push_back({"lamp (clear bulb)", lamp_program("{1}"), true, true});
    programs.push_back({"lamp (dim bulb)", lamp_program("{0.97}"), true, true});
    programs.push_back({"field", std::string("perspective") + FIELD_CAMERA + FIELD +
                                     "rendertiff All, dirlight({0.7}, <1, 2, -3>), pointlight({0.5}, [0.5, 0.5, 3])\n",
                        true, true});
    NetTally t;
    program_net(programs, 160, 8, false, t);
    check_net(t, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
}

// (the automatic grid is finer for larger images: these sizes are the smallest where it builds
// both buffers of these programs)
TEST_CASE("accel buffers: examples at 384 and 512 pixels square with the automatic grid, where the buffers are "
          "built, every lightbuffer x eyebuffer x shadowcache x freeze x merge: the same floats as --brute") {
    auto t0 = std::chrono::steady_clock::now();
    NetTally t;
    program_net(examples_of({{"cube.ray", "", true, true}}), 384, -1, false, t);
    program_net(examples_of({{"fractal.ray", "", true, true}, {"csg.ray", "", true, true}}), 512, -1, false, t);
    check_net(t, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
}

TEST_CASE("accel buffers: random scenes at 128 x 128 under the sun and lamps outside, inside the grid's box and amid "
          "the objects, every lightbuffer x eyebuffer x shadowcache x freeze x merge x bounds: the same floats as --brute") {
    const Pick picks[] = {{K_RANDOM, 5},  {K_RANDOM, 42}, {K_RANDOM, 77}, {K_MANY, 2},  {K_MANY, 7},   {K_LATTICE, 4},
                          {K_BLOCKS, 7},  {K_BLOCKS, 12}, {K_FLOOR, 3},   {K_FLOOR, 9}, {K_SCALED, 2}, {K_SCALED, 6},
                          {K_RANDOM, 42, 1}, {K_BLOCKS, 12, 1}, {K_FLOOR, 9, 1}, {K_SCALED, 2, 1}};
    auto t0 = std::chrono::steady_clock::now();
    NetTally t;
    pray_rgb w = {0.6, 0.6, 0.6}, w2 = {0.5, 0.4, 0.3};
    each_pick(picks, [&](pray_ctx *c, const Scene &s) {
        pray_vec lo = s.lo, hi = s.hi, mid = mul(add(lo, hi), 0.5), ext = sub(hi, lo);
        double big = std::max(ext.x, std::max(ext.y, ext.z));
        pray_light *lights = pray_light_add(
            c, pray_light_add(c, pray_dirlight(c, w, V(1, 2, -3)), pray_pointlight(c, w2, add(hi, ext))),
            pray_light_add(c, pray_pointlight(c, w2, add(lo, mul(ext, 0.3))), pray_pointlight(c, w2, mid)));
        REQUIRE(lights);
        // the eye outside the grid's box, looking at its centre
        pray_vec eye = add(mid, V(0.3 * big, -2.5 * big, 0.8 * big)), look = sub(mid, eye);
        pray_vec x = mul(unit(cross(look, V(0, 0, 1))), 0.6 * big);
        pray_vec y = mul(unit(cross(look, x)), 0.6 * big);
        REQUIRE(pray_perspective(c, x, y, eye, mid) == PRAY_OK);
        Render ref = render(c, s.root, lights, reference(), 128);
        REQUIRE_MESSAGE(ref.status == PRAY_OK, ref.error);
        pray_stats on = compare_combinations(s.label, ref.frames, buffer_combinations(5, true), [&](const Opts &o) {
            return render(c, s.root, lights, o, 128);
        }, t);
        INFO("defaults: ", stats_text(on));
        CHECK_MESSAGE(on.lightbuf_voxels > 0, "(setup) no light buffer built");
        CHECK_MESSAGE(on.eyebuf_voxels > 0, "(setup) no eye's buffer built");
    });
    check_net(t, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
}

TEST_CASE("accel hits: degenerate roots (nothing, one, complements, a lone primitive) with every combination") {
    pray_ctx *c = pray_new();
    REQUIRE(c);
    pray_rgb d = {0.5, 0.5, 0.5}, z = {0, 0, 0};
    pray_model *m = pray_phong(c, d, z, z, 1);
    struct Case {
        const char *name;
        pray_object *root;
    };
    pray_object *ball = pray_sphere(c, m, V(0.25, 0, 0), 0.5);
    const Case cases[] = {
        {"nothing", pray_nothing(c)},
        {"one", pray_one(c, m)},
        {"complement of nothing", pray_complement(c, pray_nothing(c))},
        {"a lone sphere", ball},
        {"a lone half-space", pray_plane(c, m, V(0, 0, 0.125), V(0, 0, 1))},
        {"a lone cylinder", pray_cylinder(c, m, V(0, 0, 0), V(0, 1, 0), 0.25)},
        {"complement of a sphere", pray_complement(c, ball)},
        {"sphere minus one", pray_csg(c, PRAY_DIFFERENCE, ball, pray_one(c, m))},
        {"sphere and nothing", pray_csg(c, PRAY_INTERSECTION, ball, pray_nothing(c))},
        {"sphere minus itself", pray_csg(c, PRAY_DIFFERENCE, ball, ball)},
        {"one minus a sphere", pray_csg(c, PRAY_DIFFERENCE, pray_one(c, m), ball)},
        {"sphere minus a far sphere", pray_csg(c, PRAY_DIFFERENCE, ball, pray_sphere(c, m, V(5, 0, 0), 0.5))},
        {"two far apart spheres intersected", pray_csg(c, PRAY_INTERSECTION, ball, pray_sphere(c, m, V(-5, 0, 0), 0.5))},
    };
    RayCase rays[] = {
        {V(-3, 0, 0), V(1, 0, 0), HUGE_VAL, R_AXIS},      {V(0.25, -3, 0.5), V(0, 1, 0), HUGE_VAL, R_TANGENT_SPHERE},
        {V(0.25, 0, 0), V(0, 0, 1), HUGE_VAL, R_IN_SOLID}, {V(-3, -3, -3), V(1, 1, 1), HUGE_VAL, R_GRID_CORNER},
        {V(-3, 0, 0.125), V(1, 0, 0), HUGE_VAL, R_IN_FACE}, {V(0.25, 0, 0), V(1, 0, 0), 0.5, R_TMAX_HIT},
    };
    long mismatches = 0;
    std::vector<std::string> first;
    for (const Case &k : cases) {
        CAPTURE(k.name);
        REQUIRE(k.root);
        REQUIRE(apply(c, reference()));
        pray_scene *ref = pray_prepare(c, k.root);
        REQUIRE_MESSAGE(ref, std::string(pray_error(c)));
        std::vector<Hits> want;
        for (const RayCase &r : rays) {
            want.push_back(intersect(c, ref, r));
            CHECK(want.back().n >= 0);
        }
        pray_scene_free(c, ref);
        // the reference itself, where the answer is plain
        std::string name = k.name;
        if (name == "a lone sphere") {
            REQUIRE(want[0].n == 2);
            CHECK(same_t(want[0].h[0].t, 2.75));
            CHECK(same_t(want[0].h[1].t, 3.75));
            CHECK(want[0].h[0].entering == 1);
            CHECK(want[0].h[1].entering == 0);
            CHECK(want[0].h[0].primitive == 0);
            CHECK(want[1].n == 0);  // tangent
        }
        if (name == "nothing" || name == "one" || name == "sphere minus itself" || name == "sphere and nothing" ||
            name == "two far apart spheres intersected")
            for (const Hits &h : want) CHECK(h.n == 0);
        if (name == "sphere minus a far sphere") CHECK(want[0].n == 2);
        if (name == "complement of a sphere") {
            REQUIRE(want[0].n == 2);
            CHECK(want[0].h[0].entering == 0);
        }
        for (const Opts &o : all_combinations()) {
            REQUIRE(apply(c, o));
            pray_scene *q = pray_prepare(c, k.root);
            CHECK_MESSAGE(q, o.text() << ": " << std::string(pray_error(c)));
            if (!q) continue;
            for (size_t i = 0; i < sizeof rays / sizeof rays[0]; i++) {
                Hits got = intersect(c, q, rays[i]);
                if (!same_hits(want[i], got) && ++mismatches <= 10)
                    first.push_back(std::string(k.name) + ", " + o.text() + ", " + fmt_ray(rays[i]) + "\n      expected " +
                                    fmt_hits(want[i]) + "\n      actual   " + fmt_hits(got));
            }
            pray_scene_free(c, q);
        }
    }
    std::string all;
    for (auto &f : first) all += "\n  - " + f;
    CHECK_MESSAGE(mismatches == 0, mismatches << " mismatches:" << all);
    pray_free(c);
}
