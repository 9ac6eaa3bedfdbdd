// Random CSG scenes for the acceleration tests (test_accel.cpp), built through the public API
// only, together with a record of their geometry from which adversarial rays are made: rays
// along the (predicted) faces, edges and corners of the grid's voxels, through the corners of
// primitives' boxes, tangent to spheres and cylinders, lying in the faces of boxes, starting
// inside solids and on box boundaries. Everything is driven by a fixed-seed generator, so a
// failing case can be reproduced from its seed alone.
#ifndef PRAY_ACCEL_SCENES_HPP
#define PRAY_ACCEL_SCENES_HPP

#include "../pray.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

namespace accel_scenes {

// ---- small vector helpers ----
inline pray_vec V(double x, double y, double z) {
    pray_vec v;
    v.x = x;
    v.y = y;
    v.z = z;
    return v;
}
inline pray_vec add(pray_vec a, pray_vec b) { return V(a.x + b.x, a.y + b.y, a.z + b.z); }
inline pray_vec sub(pray_vec a, pray_vec b) { return V(a.x - b.x, a.y - b.y, a.z - b.z); }
inline pray_vec mul(pray_vec a, double s) { return V(a.x * s, a.y * s, a.z * s); }
inline double dot(pray_vec a, pray_vec b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline pray_vec cross(pray_vec a, pray_vec b) {
    return V(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
inline double len(pray_vec a) { return std::sqrt(dot(a, a)); }
inline pray_vec unit(pray_vec a) { return mul(a, 1.0 / len(a)); }
inline double comp(pray_vec a, int i) { return i == 0 ? a.x : i == 1 ? a.y : a.z; }
inline void set_comp(pray_vec &a, int i, double v) { (i == 0 ? a.x : i == 1 ? a.y : a.z) = v; }
inline pray_vec axis_vec(int i, double s = 1) { return V(i == 0 ? s : 0, i == 1 ? s : 0, i == 2 ? s : 0); }

// ---- deterministic random numbers (splitmix64: the same sequence on every platform) ----
struct Rng {
    uint64_t s;
    explicit Rng(uint64_t seed) : s(seed * 0x9E3779B97F4A7C15ull + 0x1234567ull) {}
    uint64_t next() {
        uint64_t z = (s += 0x9E3779B97F4A7C15ull);
        z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
        z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
        return z ^ (z >> 31);
    }
    double uni() { return (double)(next() >> 11) * (1.0 / 9007199254740992.0); }  // [0, 1)
    double range(double a, double b) { return a + (b - a) * uni(); }
    int below(int n) { return (int)(next() % (uint64_t)n); }
    bool chance(double p) { return uni() < p; }
    double sign() { return chance(0.5) ? 1.0 : -1.0; }
    pray_vec in_box(pray_vec lo, pray_vec hi) {
        return V(range(lo.x, hi.x), range(lo.y, hi.y), range(lo.z, hi.z));
    }
    pray_vec dir() {  // a random unit vector
        for (;;) {
            pray_vec v = V(range(-1, 1), range(-1, 1), range(-1, 1));
            double l = len(v);
            if (l > 0.1 && l <= 1) return mul(v, 1 / l);
        }
    }
};

// ---- the record of a scene's geometry ----
struct Sphere {
    pray_vec c;
    double r;
};
struct Cylinder {
    pray_vec p, a;  // a point of the axis, the unit axis
    double r;
};
struct Plane {
    pray_vec p, n;  // a point of the boundary, the unit outward normal
};
struct BoxRec {           // a box made of six half-spaces (axis-aligned or tilted)
    pray_vec c, u[3];     // centre, unit edge directions
    double h[3];          // half sizes
    pray_vec corner(int k) const {
        pray_vec x = c;
        for (int i = 0; i < 3; i++) x = add(x, mul(u[i], (k >> i & 1) ? h[i] : -h[i]));
        return x;
    }
};

// A point on a primitive's surface and a direction tangent to it there: along an edge of a box,
// a rod's side or a cap's rim, a cone's side line, an ellipsoid's silhouette, a torus' outline.
struct Graze {
    pray_vec p, d;
};

// An affine map x -> m x + t, as the generator builds the version-2 primitives' placements.
struct Aff {
    double m[3][3];
    pray_vec t;
    pray_vec dir(pray_vec d) const {
        return V(m[0][0] * d.x + m[0][1] * d.y + m[0][2] * d.z, m[1][0] * d.x + m[1][1] * d.y + m[1][2] * d.z,
                 m[2][0] * d.x + m[2][1] * d.y + m[2][2] * d.z);
    }
    pray_vec pt(pray_vec p) const { return add(dir(p), t); }
};
inline Aff aff_id() {
    Aff a = {{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}, {0, 0, 0}};
    return a;
}
// f after a
inline Aff aff_then(const Aff &a, const Aff &f) {
    Aff h;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) h.m[i][j] = f.m[i][0] * a.m[0][j] + f.m[i][1] * a.m[1][j] + f.m[i][2] * a.m[2][j];
    h.t = f.pt(a.t);
    return h;
}
inline Aff aff_diag(pray_vec v) {
    Aff a = aff_id();
    a.m[0][0] = v.x;
    a.m[1][1] = v.y;
    a.m[2][2] = v.z;
    return a;
}
// Rotation by degrees about X, then Y, then Z, as pray_rotate turns.
inline Aff aff_rot(pray_vec deg) {
    const double k = 3.14159265358979323846 / 180;
    double sx = std::sin(deg.x * k), cx = std::cos(deg.x * k), sy = std::sin(deg.y * k), cy = std::cos(deg.y * k),
           sz = std::sin(deg.z * k), cz = std::cos(deg.z * k);
    Aff f = {{{cz * cy, cz * sy * sx - sz * cx, cz * sy * cx + sz * sx},
              {sz * cy, sz * sy * sx + cz * cx, sz * sy * cx - cz * sx},
              {-sy, cy * sx, cy * cx}},
             {0, 0, 0}};
    return f;
}

struct Scene {
    std::string label;  // what it is and its seed
    pray_object *root = nullptr;
    std::vector<Sphere> spheres;
    std::vector<Cylinder> cylinders;
    std::vector<Plane> planes;
    std::vector<BoxRec> boxes;
    std::vector<Graze> grazes;  // of the version-2 primitives, stretched ones and tori
    int nprims = 0;
    double scale = 1;         // the scene's unit (1, or far from 1 for the scaled scenes)
    pray_vec offset{0, 0, 0};  // ... and its placement
    // where rays are aimed: the part of space the scene's finite parts occupy
    pray_vec lo{-1, -1, -1}, hi{1, 1, 1};
};

// Guesses of the box the renderer's grid covers: around the primitives whose own boxes are
// finite (spheres), or (with_boxes) also around the boxes made of half-spaces (with bounds, the
// finite boxes of the scene's parts). False when there is nothing finite.
inline bool finite_region(const Scene &s, pray_vec *lo, pray_vec *hi, bool with_boxes = false) {
    *lo = V(HUGE_VAL, HUGE_VAL, HUGE_VAL);
    *hi = V(-HUGE_VAL, -HUGE_VAL, -HUGE_VAL);
    bool any = false;
    auto grow = [&](pray_vec p, double r) {
        any = true;
        for (int l = 0; l < 3; l++) {
            set_comp(*lo, l, std::min(comp(*lo, l), comp(p, l) - r));
            set_comp(*hi, l, std::max(comp(*hi, l), comp(p, l) + r));
        }
    };
    for (const Sphere &q : s.spheres) grow(q.c, q.r);
    if (with_boxes)
        for (const BoxRec &b : s.boxes)
            for (int k = 0; k < 8; k++) grow(b.corner(k), 0);
    return any;
}

// The planes of a grid of N voxels along the longest side of the region, placed as the renderer
// places it (centred on the region, cubical voxels, one voxel more where the side is an exact
// multiple). Only a guess used to aim rays: the tests never depend on it being right.
struct GridGuess {
    int n[3];
    double org[3], h;
    double face(int axis, int k) const { return org[axis] + k * h; }
};
inline bool guess_grid(pray_vec lo, pray_vec hi, int N, GridGuess *g) {
    double ext = 0;
    for (int l = 0; l < 3; l++) ext = std::max(ext, comp(hi, l) - comp(lo, l));
    if (!(ext > 0) || N <= 0) return false;
    g->h = ext / N;
    double margin = g->h * 1e-6;
    for (int l = 0; l < 3; l++) {
        double L = comp(hi, l) - comp(lo, l) + 2 * margin;
        g->n[l] = std::max(1, (int)std::ceil(L / g->h));
        g->org[l] = (comp(lo, l) + comp(hi, l)) / 2 - g->n[l] * g->h / 2;
    }
    return true;
}
inline int guess_auto_grid(int bounded) {
    if (bounded < 8) return 0;
    int n = (int)std::ceil(2.0 * std::cbrt((double)bounded));
    return n < 4 ? 4 : n > 160 ? 160 : n;
}

// ---- the generator ----
class Gen {
public:
    Gen(pray_ctx *c, uint64_t seed) : rng(seed), c_(c) {
        pray_rgb d = {0.7, 0.5, 0.3}, s = {0.2, 0.2, 0.2}, a = {0, 0, 0};
        m_ = pray_phong(c, d, s, a, 10);
    }
    Rng rng;
    Scene sc;

    // Scene coordinates of a point / a length given in unit coordinates.
    pray_vec P(pray_vec u) const { return add(mul(u, sc.scale), sc.offset); }
    double L(double u) const { return u * sc.scale; }

    // A coordinate in [a, b], half of the time on a multiple of 1/8 or 1/16.
    double coord(double a, double b) {
        double x = rng.range(a, b);
        int k = rng.below(4);
        if (k == 0) return std::round(x * 8) / 8;
        if (k == 1) return std::round(x * 16) / 16;
        return x;
    }
    double radius(double a, double b) {
        double r = rng.range(a, b);
        if (rng.chance(0.5)) r = std::max(1.0 / 16, std::round(r * 16) / 16);
        return r;
    }

    // Primitives, in unit coordinates.
    pray_object *sphere(pray_vec c, double r) {
        Sphere q = {P(c), L(r)};
        sc.spheres.push_back(q);
        sc.nprims++;
        if (rng.chance(0.1) && sc.scale == 1) {  // built at the origin and moved there by '.'
            pray_object *o = pray_sphere(c_, m(), V(0, 0, 0), r);
            return pray_translate(c_, o, c);
        }
        return pray_sphere(c_, m(), q.c, q.r);
    }
    pray_object *plane(pray_vec p, pray_vec n) {
        Plane q = {P(p), unit(n)};
        sc.planes.push_back(q);
        sc.nprims++;
        return pray_plane(c_, m(), q.p, n);
    }
    pray_object *cylinder(pray_vec p, pray_vec a, double r) {
        Cylinder q = {P(p), unit(a), L(r)};
        sc.cylinders.push_back(q);
        sc.nprims++;
        return pray_cylinder(c_, m(), q.p, a, q.r);
    }
    // A box of six half-spaces: centre c, unit edge directions u (orthonormal), half sizes h.
    pray_object *box(pray_vec c, const pray_vec u[3], const double h[3]) {
        BoxRec b;
        b.c = P(c);
        for (int i = 0; i < 3; i++) {
            b.u[i] = u[i];
            b.h[i] = L(h[i]);
        }
        sc.boxes.push_back(b);
        int order[6] = {0, 1, 2, 3, 4, 5};
        for (int i = 5; i > 0; i--) std::swap(order[i], order[rng.below(i + 1)]);
        pray_object *acc = nullptr;
        for (int k = 0; k < 6; k++) {
            int i = order[k] / 2;
            double s = order[k] % 2 ? 1.0 : -1.0;
            pray_object *pl = plane(add(c, mul(u[i], s * h[i])), mul(u[i], s));
            acc = acc ? pray_csg(c_, PRAY_INTERSECTION, acc, pl) : pl;
        }
        return acc;
    }
    pray_object *axis_box(pray_vec lo, pray_vec hi) {
        pray_vec u[3] = {V(1, 0, 0), V(0, 1, 0), V(0, 0, 1)};
        double h[3] = {(hi.x - lo.x) / 2, (hi.y - lo.y) / 2, (hi.z - lo.z) / 2};
        return box(mul(add(lo, hi), 0.5), u, h);
    }
    // An orthonormal frame in a random orientation.
    void frame(pray_vec u[3]) {
        u[0] = rng.dir();
        pray_vec t = rng.dir();
        u[1] = unit(sub(t, mul(u[0], dot(t, u[0]))));
        u[2] = cross(u[0], u[1]);
    }

    // A random leaf: one primitive or a small solid made of several, near the focus point.
    pray_vec focus{0, 0, 0};
    double spread = 1;
    pray_vec point(double a, double b) {  // a point near the focus: a, b scaled by the spread
        return V(coord(focus.x + a * spread, focus.x + b * spread), coord(focus.y + a * spread, focus.y + b * spread),
                 coord(focus.z + a * spread, focus.z + b * spread));
    }
    double shapes = 0;  // the share of leaves that are version-2 primitives (shape)
    pray_object *leaf() {
        if (shapes > 0 && rng.chance(shapes)) return shape();
        int k = rng.below(16);
        if (k < 5) return sphere(point(-1, 1), radius(0.1, 0.7));
        if (k < 7) {  // axis-aligned cube or box
            pray_vec lo = point(-1, 0.6), hi = add(lo, V(radius(0.15, 0.9), radius(0.15, 0.9), radius(0.15, 0.9)));
            if (rng.chance(0.3)) hi = add(lo, V(0.5, 0.5, 0.5));
            return axis_box(lo, hi);
        }
        if (k < 9) {  // tilted box
            pray_vec u[3];
            frame(u);
            double h[3] = {radius(0.1, 0.5), radius(0.1, 0.5), radius(0.1, 0.5)};
            return box(point(-0.8, 0.8), u, h);
        }
        if (k < 12) {  // cylinder: axis-aligned or oblique, infinite or capped
            bool aligned = rng.chance(0.6);
            int ax = rng.below(3);
            pray_vec a = aligned ? axis_vec(ax, rng.sign()) : rng.dir();
            pray_vec p = point(-0.8, 0.8);
            double r = radius(0.08, 0.5);
            pray_object *cyl = cylinder(p, a, r);
            if (rng.chance(0.5)) return cyl;
            double h = radius(0.1, 0.8);
            pray_object *cap1 = plane(add(p, mul(a, h)), a);
            pray_object *cap2 = plane(sub(p, mul(a, h)), mul(a, -1));
            return pray_csg(c_, PRAY_INTERSECTION, pray_csg(c_, PRAY_INTERSECTION, cyl, cap1), cap2);
        }
        if (k < 14) {  // a half-space, axis-aligned or in any orientation
            pray_vec n = rng.chance(0.5) ? axis_vec(rng.below(3), rng.sign()) : rng.dir();
            return plane(point(-0.8, 0.8), n);
        }
        if (k == 14) {  // a slab between two parallel planes
            pray_vec n = rng.chance(0.5) ? axis_vec(rng.below(3), 1) : rng.dir();
            pray_vec p = point(-0.5, 0.5);
            double h = radius(0.1, 0.4);
            return pray_csg(c_, PRAY_INTERSECTION, plane(add(p, mul(n, h)), n), plane(sub(p, mul(n, h)), mul(n, -1)));
        }
        // a sphere with a cylindrical hole
        pray_vec cc = point(-0.8, 0.8);
        double r = radius(0.2, 0.6);
        pray_object *s = sphere(cc, r);
        pray_vec a = rng.chance(0.5) ? axis_vec(rng.below(3), 1) : rng.dir();
        return pray_csg(c_, PRAY_DIFFERENCE, s, cylinder(cc, a, r * rng.range(0.2, 0.7)));
    }

    // A version-2 primitive (box, rod, cone, torus) or a stretched sphere or capped cylinder,
    // placed by random stretches (negative ones mirror), rotations, scales and translations, in
    // that order or with a stretch after a rotation (which shears); its grazing rays recorded.
    pray_object *shape() {
        int k = rng.below(6);
        std::vector<Graze> loc;
        pray_object *o = nullptr;
        pray_vec p1 = point(-0.6, 0.6);
        auto side = [&](pray_vec a) {  // a unit vector perpendicular to unit a
            pray_vec u = cross(a, rng.dir());
            return unit(u);
        };
        auto axis = [&]() { return rng.chance(0.5) ? axis_vec(rng.below(3), rng.sign()) : rng.dir(); };
        if (k == 0) {  // box, its corners in any order
            pray_vec p2 = add(p1, V(rng.sign() * radius(0.1, 0.8), rng.sign() * radius(0.1, 0.8), rng.sign() * radius(0.1, 0.8)));
            o = pray_box(c_, m(), p1, p2);
            for (int i = 0; i < 4; i++) {
                pray_vec c = V(rng.chance(0.5) ? p1.x : p2.x, rng.chance(0.5) ? p1.y : p2.y, rng.chance(0.5) ? p1.z : p2.z);
                pray_vec d = axis_vec(rng.below(3), rng.sign());
                if (i == 3) d = V(rng.sign(), rng.sign(), 0);  // across a face, through the corner
                loc.push_back(Graze{c, d});
            }
        } else if (k == 1 || k == 2) {  // rod, cone (sometimes pointed at either end)
            pray_vec a = axis();
            double h = radius(0.2, 1.2), r1 = radius(0.05, 0.5), r2 = k == 1 ? r1 : radius(0.05, 0.5);
            if (k == 2 && rng.chance(0.3)) (rng.chance(0.5) ? r1 : r2) = 0;
            pray_vec p2 = add(p1, mul(a, h));
            o = k == 1 ? pray_rod(c_, m(), p1, p2, r1) : pray_cone(c_, m(), p1, r1, p2, r2);
            for (int i = 0; i < 4; i++) {
                pray_vec u = side(a), w = cross(a, u);
                pray_vec e1 = add(p1, mul(u, r1)), e2 = add(p2, mul(u, r2));
                if (i == 0) loc.push_back(Graze{e1, sub(e2, e1)});                      // the side line
                if (i == 1) loc.push_back(Graze{rng.chance(0.5) ? e1 : e2, w});         // a rim
                if (i == 2) loc.push_back(Graze{add(mul(e1, 0.5), mul(e2, 0.5)), w});  // the side
                if (i == 3) loc.push_back(Graze{rng.chance(0.5) ? p1 : p2, add(u, mul(w, rng.range(-1, 1)))});  // a cap
            }
        } else if (k == 3) {  // a sphere, stretched below into an ellipsoid
            double r = radius(0.1, 0.6);
            o = pray_sphere(c_, m(), p1, r);
            for (int i = 0; i < 3; i++) {
                pray_vec u = rng.dir();
                loc.push_back(Graze{add(p1, mul(u, r)), side(u)});
            }
        } else if (k == 4) {  // a capped cylinder, stretched below
            pray_vec a = axis();
            double r = radius(0.08, 0.5), h = radius(0.1, 0.6);
            o = pray_csg(c_, PRAY_INTERSECTION, pray_cylinder(c_, m(), p1, a, r),
                         pray_csg(c_, PRAY_INTERSECTION, pray_plane(c_, m(), add(p1, mul(a, h)), a),
                                  pray_plane(c_, m(), sub(p1, mul(a, h)), mul(a, -1))));
            sc.nprims += 2;
            pray_vec u = side(a);
            loc.push_back(Graze{add(p1, mul(u, r)), a});
            loc.push_back(Graze{add(add(p1, mul(u, r)), mul(a, h)), cross(a, u)});
        } else {  // torus
            pray_vec a = axis();
            double R = radius(0.2, 0.6), r = R * rng.range(0.1, 0.9);
            o = pray_torus(c_, m(), p1, a, R, r);
            pray_vec u = side(a), w = cross(a, u);
            loc.push_back(Graze{add(p1, mul(u, R + r)), w});                   // the outline
            loc.push_back(Graze{add(p1, mul(u, R - r)), w});                   // the hole's rim
            loc.push_back(Graze{add(add(p1, mul(u, R)), mul(a, r)), u});      // across the top
            loc.push_back(Graze{add(add(p1, mul(u, R)), mul(a, r)), w});      // along the top
            loc.push_back(Graze{add(p1, mul(a, r)), u});                      // over the hole
        }
        sc.nprims++;
        Aff f = aff_id();
        auto stretch = [&]() {
            static const double fs[] = {0.5, 2, -1, 1.5, -0.7, 3, 0.25, -2};
            pray_vec v = V(fs[rng.below(8)], fs[rng.below(8)], fs[rng.below(8)]);
            if (rng.chance(0.3)) set_comp(v, rng.below(3), 1);
            o = pray_stretch(c_, o, v);
            f = aff_then(f, aff_diag(v));
        };
        if (k == 3 || k == 4 || rng.chance(0.6)) stretch();
        if (rng.chance(0.5)) {
            pray_vec deg = V(rng.range(-180, 180), rng.range(-180, 180), rng.range(-180, 180));
            if (rng.chance(0.3)) deg = V(90 * rng.below(4), 90 * rng.below(4), 0);
            o = pray_rotate(c_, o, deg);
            f = aff_then(f, aff_rot(deg));
            if (rng.chance(0.3)) stretch();
        }
        if (rng.chance(0.2)) {
            double s = rng.chance(0.5) ? 0.5 : -0.8;
            o = pray_scale(c_, o, s);
            f = aff_then(f, aff_diag(V(s, s, s)));
        }
        if (sc.scale != 1 || rng.chance(0.3)) {  // to the scene's scale and place (as P and L do)
            o = pray_scale(c_, o, sc.scale);
            f = aff_then(f, aff_diag(V(sc.scale, sc.scale, sc.scale)));
            o = pray_translate(c_, o, sc.offset);
            Aff t = aff_id();
            t.t = sc.offset;
            f = aff_then(f, t);
        }
        for (const Graze &g : loc) sc.grazes.push_back(Graze{f.pt(g.p), f.dir(g.d)});
        return o;
    }

    // A random tree: n-ary unions, intersections and differences (chains of pray_csg),
    // complements, nested `depth` levels deep; sometimes `nothing` and `one` to be folded.
    // Subtrees are placed around a focus point that moves less and less deep down, so that the
    // parts of intersections and differences overlap often. At most max_prims primitives.
    int max_prims = 1 << 30;
    pray_object *tree(int depth) {
        if (depth <= 0 || rng.chance(0.25) || sc.nprims >= max_prims) {
            pray_object *o = leaf();
            if (rng.chance(0.1)) o = pray_complement(c_, o);
            return o;
        }
        double w = rng.uni();
        int op = w < 0.45 ? PRAY_UNION : w < 0.75 ? PRAY_DIFFERENCE : PRAY_INTERSECTION;
        int n = 2 + rng.below(3);
        pray_vec f0 = focus;
        double s0 = spread;
        focus = add(f0, mul(V(rng.range(-1, 1), rng.range(-1, 1), rng.range(-1, 1)), 0.5 * s0));
        spread = s0 * 0.6;
        pray_object *acc = tree(depth - 1);
        for (int i = 1; i < n; i++) {
            pray_object *k = tree(depth - 1);
            if (op == PRAY_DIFFERENCE && rng.chance(0.3)) {
                // (a - b) - c chains; also a - (b - c) nesting
                acc = pray_csg(c_, PRAY_DIFFERENCE, acc, k);
            } else {
                acc = pray_csg(c_, (pray_op)op, acc, k);
            }
        }
        if (rng.chance(0.04)) acc = pray_csg(c_, PRAY_UNION, acc, pray_nothing(c_));
        if (rng.chance(0.04)) acc = pray_csg(c_, PRAY_INTERSECTION, acc, pray_one(c_, m()));
        if (rng.chance(0.12)) acc = pray_complement(c_, acc);
        focus = f0;
        spread = s0;
        return acc;
    }

    // The primitives' models: one for all, or each picked at random among `mats` when given
    // (scenes where different materials touch and overlap).
    std::vector<pray_model *> mats;
    pray_model *m() { return mats.empty() ? m_ : mats[rng.below((int)mats.size())]; }

    pray_ctx *c_;
    pray_model *m_;
};

// Where rays are aimed: the box of the finite parts recorded (spheres, boxes' corners, points on
// cylinders' axes and on planes), padded; in scene coordinates.
inline void aim_region(Scene &s) {
    pray_vec lo = V(HUGE_VAL, HUGE_VAL, HUGE_VAL), hi = V(-HUGE_VAL, -HUGE_VAL, -HUGE_VAL);
    auto grow = [&](pray_vec p, double r) {
        for (int l = 0; l < 3; l++) {
            set_comp(lo, l, std::min(comp(lo, l), comp(p, l) - r));
            set_comp(hi, l, std::max(comp(hi, l), comp(p, l) + r));
        }
    };
    for (const Sphere &q : s.spheres) grow(q.c, q.r);
    for (const BoxRec &b : s.boxes)
        for (int k = 0; k < 8; k++) grow(b.corner(k), 0);
    for (const Cylinder &q : s.cylinders) grow(q.p, q.r);
    for (const Plane &q : s.planes) grow(q.p, 0);
    for (const Graze &q : s.grazes) grow(q.p, 0);
    if (!(lo.x <= hi.x)) {
        lo = s.offset;
        hi = s.offset;
    }
    double pad = 0.05 * s.scale;
    s.lo = sub(lo, V(pad, pad, pad));
    s.hi = add(hi, V(pad, pad, pad));
}

// The kinds of generated scenes.
enum Kind {
    K_RANDOM,       // a random tree, 2 to 4 levels
    K_MANY,         // a union of 100 to 400 small spheres minus a few solids
    K_LATTICE,      // spheres on a lattice, touching their neighbours, minus a box
    K_BLOCKS,       // axis-aligned unit-fraction cubes sharing faces, with differences
    K_FLOOR,        // an unbounded floor with spheres and boxes on it (lists outside the grid)
    K_SCALED,       // a random tree scaled far from 1 and moved far from the origin
    K_CLUSTER,      // a dense cluster of small solids and a few far away (nested grids)
    K_SHAPES        // a random tree of version-2 primitives and stretched ones with the others
};

inline const char *kind_name(int k) {
    static const char *names[] = {"random", "many", "lattice", "blocks", "floor", "scaled", "cluster", "shapes"};
    return names[k];
}

// Build scene `seed` of kind `kind` in context c.
inline Scene make_scene(pray_ctx *c, int kind, uint64_t seed, const std::vector<pray_model *> *mats = nullptr) {
    Gen g(c, seed * 7919 + (uint64_t)kind);
    if (mats) g.mats = *mats;
    Rng &r = g.rng;
    pray_object *root = nullptr;
    switch (kind) {
    case K_RANDOM:
    default: {
        int depth = 2 + r.below(3);
        g.max_prims = 40;
        root = g.tree(depth);
        // make sure some spheres exist sometimes, so the grid has a finite region to cover
        if (r.chance(0.5)) root = pray_csg(c, PRAY_UNION, root, g.sphere(g.point(-1, 1), g.radius(0.1, 0.4)));
        break;
    }
    case K_MANY: {
        int n = 100 + r.below(301);
        double rmax = n > 250 ? 0.08 : 0.12;
        for (int i = 0; i < n; i++) {
            pray_object *s = g.sphere(g.point(-1, 1), g.radius(0.02, rmax));
            root = root ? pray_csg(c, PRAY_UNION, root, s) : s;
        }
        int m = 1 + r.below(4);
        for (int i = 0; i < m; i++) {
            pray_object *k = r.chance(0.5) ? g.sphere(g.point(-0.7, 0.7), g.radius(0.2, 0.5)) : g.leaf();
            root = pray_csg(c, PRAY_DIFFERENCE, root, k);
        }
        if (r.chance(0.3)) root = pray_csg(c, PRAY_INTERSECTION, root, g.plane(g.point(-0.3, 0.3), r.dir()));
        break;
    }
    case K_LATTICE: {
        int n = 3 + r.below(4);
        double step = 2.0 / n, rad = step / 2;  // touching spheres
        if (r.chance(0.3)) rad = step / 4;
        for (int i = 0; i < n; i++)
            for (int j = 0; j < n; j++)
                for (int k = 0; k < n; k++) {
                    if (r.chance(0.2)) continue;
                    pray_vec cc = V(-1 + step * (i + 0.5), -1 + step * (j + 0.5), -1 + step * (k + 0.5));
                    pray_object *s = g.sphere(cc, rad);
                    root = root ? pray_csg(c, PRAY_UNION, root, s) : s;
                }
        if (!root) root = g.sphere(V(0, 0, 0), 0.5);
        if (r.chance(0.7)) root = pray_csg(c, PRAY_DIFFERENCE, root, g.axis_box(V(-0.5, -0.5, -0.5), V(0.5, 0.5, 1.5)));
        if (r.chance(0.5)) root = pray_csg(c, PRAY_INTERSECTION, root, g.cylinder(V(0, 0, 0), V(0, 0, 1), 0.9));
        break;
    }
    case K_BLOCKS: {
        int n = 4 + r.below(10);
        for (int i = 0; i < n; i++) {
            pray_vec lo = V(std::floor(r.range(-4, 3)) / 4, std::floor(r.range(-4, 3)) / 4, std::floor(r.range(-4, 3)) / 4);
            pray_vec hi = add(lo, V(0.25 * (1 + r.below(3)), 0.25 * (1 + r.below(3)), 0.25 * (1 + r.below(3))));
            pray_object *b = g.axis_box(lo, hi);
            if (!root) root = b;
            else root = pray_csg(c, r.chance(0.3) ? PRAY_DIFFERENCE : PRAY_UNION, root, b);
        }
        // spheres centred on block corners, so the grid has a finite region of simple fractions
        for (int i = 0; i < 3; i++) {
            pray_object *s = g.sphere(V(std::floor(r.range(-4, 4)) / 4, std::floor(r.range(-4, 4)) / 4,
                                        std::floor(r.range(-4, 4)) / 4),
                                      0.25);
            root = pray_csg(c, r.chance(0.5) ? PRAY_UNION : PRAY_DIFFERENCE, root, s);
        }
        break;
    }
    case K_FLOOR: {
        root = g.plane(V(0, 0, -1), V(0, 0, 1));
        int n = 3 + r.below(20);
        for (int i = 0; i < n; i++) {
            pray_object *o = r.chance(0.6) ? g.sphere(g.point(-1, 1), g.radius(0.05, 0.4)) : g.leaf();
            root = pray_csg(c, PRAY_UNION, root, o);
        }
        if (r.chance(0.5)) root = pray_csg(c, PRAY_DIFFERENCE, root, g.sphere(g.point(-1, 1), 0.5));
        break;
    }
    case K_SCALED: {
        static const double scales[] = {1e-3, 1e-2, 1e3, 1e4, 1e6};
        static const double offs[] = {0, 1, 1e3, 1e5};
        g.sc.scale = scales[r.below(5)];
        double o = offs[r.below(4)] * (g.sc.scale < 1 ? 1 : g.sc.scale);
        g.sc.offset = V(o, -o / 2, o / 4);
        // scaled scenes are built of the primitives that the generator scales itself
        int n = 3 + r.below(30);
        for (int i = 0; i < n; i++) {
            pray_object *s;
            int k = r.below(4);
            if (k < 2) s = g.sphere(g.point(-1, 1), g.radius(0.05, 0.5));
            else if (k == 2) s = g.cylinder(g.point(-1, 1), r.chance(0.5) ? axis_vec(r.below(3), 1) : r.dir(), g.radius(0.05, 0.3));
            else s = g.plane(g.point(-1, 1), r.dir());
            if (!root) root = s;
            else root = pray_csg(c, r.chance(0.5) ? PRAY_UNION : r.chance(0.6) ? PRAY_DIFFERENCE : PRAY_INTERSECTION, root, s);
        }
        break;
    }
    case K_SHAPES: {
        // mostly at unit scale; some scenes scaled far from 1 and moved far from the origin
        static const double scales[] = {1, 1, 1, 1e-3, 1e3, 1e5};
        g.sc.scale = scales[r.below(6)];
        if (g.sc.scale != 1) g.sc.offset = mul(V(1, -0.5, 0.25), g.sc.scale * (r.chance(0.5) ? 0 : 1e3));
        g.shapes = 0.6;
        g.max_prims = 40;
        root = g.tree(2 + r.below(3));
        if (r.chance(0.5)) root = pray_csg(c, PRAY_UNION, root, g.shape());
        break;
    }
    case K_CLUSTER: {
        // 150 to 400 small leaves (spheres, boxes, rods in any direction, holed balls) packed
        // in a ball, minus a few solids; one to three spheres 10 to 200 cluster widths away; often
        // an unbounded floor and unbounded thin rods
        g.spread = 0.12;
        int n = 150 + r.below(251);
        for (int i = 0; i < n; i++) {
            g.focus = V(r.range(-1, 1), r.range(-1, 1), r.range(-1, 1));
            pray_object *o = r.chance(0.4) ? g.sphere(g.point(-1, 1), g.radius(0.02, 0.1)) : g.leaf();
            root = root ? pray_csg(c, PRAY_UNION, root, o) : o;
        }
        g.focus = V(0, 0, 0);
        g.spread = 1;
        for (int i = 0, m = 1 + r.below(3); i < m; i++) {
            pray_object *k = g.sphere(g.point(-0.6, 0.6), g.radius(0.2, 0.5));
            root = pray_csg(c, PRAY_DIFFERENCE, root, k);
        }
        for (int i = 0, m = 1 + r.below(3); i < m; i++) {
            pray_object *far = g.sphere(mul(r.dir(), r.range(20, 400)), g.radius(0.2, 2));
            root = pray_csg(c, PRAY_UNION, root, far);
        }
        // what crosses the crowded voxels whole and is no part of the crowd: a floor under the
        // cluster or through it, and thin rods along the axes through it
        if (r.chance(0.6)) root = pray_csg(c, PRAY_UNION, root, g.plane(V(0, 0, r.range(-1.5, 0.5)), V(0, 0, r.chance(0.8) ? 1 : -1)));
        for (int i = 0, m = r.below(4); i < m; i++)
            root = pray_csg(c, PRAY_UNION, root, g.cylinder(g.point(-0.8, 0.8), axis_vec(r.below(3), 1), g.radius(0.01, 0.05)));
        break;
    }
    }
    g.sc.root = root;
    char buf[96];
    std::snprintf(buf, sizeof buf, "%s scene, seed %llu", kind_name(kind), (unsigned long long)seed);
    g.sc.label = buf;
    aim_region(g.sc);
    return g.sc;
}

} // namespace accel_scenes

#endif
