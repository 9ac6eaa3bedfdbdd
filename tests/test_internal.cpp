// White-box tests: this file includes the implementation to reach its internal functions.
//
// What is tested here, from the language specification's point of view (docs/pray-language.md,
// section 5: every object is a closed regularised point set):
//   - ray/primitive intersection (prim_span) for spheres, half-spaces and infinite cylinders,
//     with exact parameters where the arithmetic is exact, and the self-primitive rule;
//   - the CSG status-tree sweep against an independent reference that classifies points along
//     the ray by evaluating set membership of the CSG tree directly (random trees, fixed seeds);
//   - coincident faces, complements, n-ary difference chains, tangent rays, folding of
//     `nothing` and `one`.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wsubobject-linkage"  // pray.cpp's types seen from another file
#endif
#include "../pray.cpp"

#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <random>
#include <string>
#include <vector>

namespace {

// Tolerances follow the renderer's precision: PRAY_REAL double (default) or float.
const double T_REL = sizeof(real) == sizeof(double) ? 1e-9 : 1e-4;

pray_vec t_vec(double x, double y, double z) {
    pray_vec v;
    v.x = x;
    v.y = y;
    v.z = z;
    return v;
}
pray_rgb t_rgb(double r, double g, double b) {
    pray_rgb c;
    c.r = r;
    c.g = g;
    c.b = b;
    return c;
}

// A ray with a unit direction (computed in double, then stored in render precision).
Ray t_ray(double ox, double oy, double oz, double dx, double dy, double dz) {
    double l = std::sqrt(dx * dx + dy * dy + dz * dz);
    Ray r;
    r.o = r3((real)ox, (real)oy, (real)oz);
    r.d = r3((real)(dx / l), (real)(dy / l), (real)(dz / l));
    return r;
}

bool t_close(double got, double want) { return std::fabs(got - want) <= T_REL * std::max(1.0, std::fabs(want)); }

// Every hit the sweep visits, in order.
struct TAllHits {
    std::vector<Hit> v;
    bool operator()(const Hit &h) {
        v.push_back(h);
        return v.size() < 10000;
    }
};

// A flattened scene of one object, with the scratch space of a sweep.
struct TScene {
    pray_ctx *c;
    Scene s;
    Scratch w;
    bool ok;
    TScene(pray_ctx *ctx, pray_object *o) : c(ctx), ok(false) {
        memset(&s, 0, sizeof s);
        memset(&w, 0, sizeof w);
        if (!o) return;
        if (scene_build(c, &s, o, NULL, false) != PRAY_OK) return;
        ok = scratch_init(c, &w, &s);
    }
    ~TScene() {
        scratch_release(c, &w);
        scene_release(c, &s);
    }
    // Hits by the status-tree sweep over all primitives (the brute-force reference), or, with
    // `accelerated`, by the path the renderer takes (grid, action lists, freezing, merging).
    bool accelerated = false;
    std::vector<Hit> hits(const Ray &r, int self = -1, real tmax = REAL_INF) {
        TAllHits a;
        if (ok && accelerated) find_hits(&s, &w, r, tmax, self, a);
        else if (ok) sweep(&s, &w, r, tmax, self, a);
        return a.v;
    }
    FirstHit first(const Ray &r, int self = -1, real tmax = REAL_INF) {
        FirstHit f;
        f.found = false;
        if (ok && accelerated) find_hits(&s, &w, r, tmax, self, f);
        else if (ok) sweep(&s, &w, r, tmax, self, f);
        return f;
    }
    // The primitive index whose material is m (primitives get distinct materials in tests).
    int prim_of(const pray_model *m) const {
        for (int i = 0; i < s.prims.n; i++)
            if (s.prims[i].mat == m) return i;
        return -1;
    }
};

// A context with one material per call, so that hits can be told apart by material.
struct TCtx {
    pray_ctx *c;
    TCtx() : c(pray_new()) {}
    ~TCtx() { pray_free(c); }
    pray_model *mat(double id) { return pray_color(c, t_rgb(id, 0, 0)); }
};

// The span of a single primitive, as flattened for rendering.
struct TSpan {
    int kind;
    real t0, t1;
};
TSpan t_span_of(pray_ctx *c, pray_object *o, const Ray &r, bool self = false) {
    TSpan sp;
    sp.kind = -1;
    sp.t0 = sp.t1 = 0;
    Scene s;
    if (!o || scene_build(c, &s, o, NULL, false) != PRAY_OK || s.prims.n != 1) return sp;
    sp.kind = prim_span(s.prims[0], r, self, &sp.t0, &sp.t1);
    scene_release(c, &s);
    return sp;
}

// ---------------------------------------------------------------------------------------------
// An independent reference: the CSG tree kept as plain data, membership evaluated directly.
// ---------------------------------------------------------------------------------------------
typedef long double tld;

struct RefPrim {
    int kind;  // O_SPHERE, O_PLANE, O_CYLINDER
    tld p[3];   // centre / point on the plane / point on the axis
    tld n[3];   // plane normal / cylinder axis (not necessarily unit)
    tld r;
};

struct RefNode {
    int kind;  // O_SPHERE..O_CYLINDER (then `prim`), O_ONE, O_NOTHING, O_UNION, O_INTER, O_DIFF, O_COMPL
    int prim;
    std::vector<int> kids;
};

struct RefTree {
    std::vector<RefPrim> prims;
    std::vector<RefNode> nodes;
    int root;
};

tld ref_dot(const tld *a, const tld *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

// Signed distance-like function: negative inside, zero on the surface (in length units).
tld ref_prim_f(const RefPrim &q, const tld *x) {
    tld v[3] = {x[0] - q.p[0], x[1] - q.p[1], x[2] - q.p[2]};
    switch (q.kind) {
    case O_SPHERE: return std::sqrt(ref_dot(v, v)) - q.r;
    case O_PLANE: return ref_dot(v, q.n) / std::sqrt(ref_dot(q.n, q.n));
    default: {
        tld a2 = ref_dot(q.n, q.n), s = ref_dot(v, q.n) / a2;
        tld w[3] = {v[0] - q.n[0] * s, v[1] - q.n[1] * s, v[2] - q.n[2] * s};
        return std::sqrt(ref_dot(w, w)) - q.r;
    }
    }
}

// Outward direction of the surface at x (not normalised).
void ref_prim_grad(const RefPrim &q, const tld *x, tld *g) {
    tld v[3] = {x[0] - q.p[0], x[1] - q.p[1], x[2] - q.p[2]};
    if (q.kind == O_PLANE) {
        for (int i = 0; i < 3; i++) g[i] = q.n[i];
    } else if (q.kind == O_SPHERE) {
        for (int i = 0; i < 3; i++) g[i] = v[i];
    } else {
        tld s = ref_dot(v, q.n) / ref_dot(q.n, q.n);
        for (int i = 0; i < 3; i++) g[i] = v[i] - q.n[i] * s;
    }
}

bool ref_prim_in(const RefPrim &q, const tld *x) {
    tld v[3] = {x[0] - q.p[0], x[1] - q.p[1], x[2] - q.p[2]};
    switch (q.kind) {
    case O_SPHERE: return ref_dot(v, v) < q.r * q.r;
    case O_PLANE: return ref_dot(v, q.n) < 0;
    default: {
        tld a2 = ref_dot(q.n, q.n), s = ref_dot(v, q.n) / a2;
        tld w[3] = {v[0] - q.n[0] * s, v[1] - q.n[1] * s, v[2] - q.n[2] * s};
        return ref_dot(w, w) < q.r * q.r;
    }
    }
}

bool ref_node_in(const RefTree &T, int k, const tld *x) {
    const RefNode &nd = T.nodes[k];
    switch (nd.kind) {
    case O_ONE: return true;
    case O_NOTHING: return false;
    case O_UNION:
        for (size_t i = 0; i < nd.kids.size(); i++)
            if (ref_node_in(T, nd.kids[i], x)) return true;
        return false;
    case O_INTER:
        for (size_t i = 0; i < nd.kids.size(); i++)
            if (!ref_node_in(T, nd.kids[i], x)) return false;
        return true;
    case O_DIFF:
        if (!ref_node_in(T, nd.kids[0], x)) return false;
        for (size_t i = 1; i < nd.kids.size(); i++)
            if (ref_node_in(T, nd.kids[i], x)) return false;
        return true;
    case O_COMPL: return !ref_node_in(T, nd.kids[0], x);
    default: return ref_prim_in(T.prims[nd.prim], x);
    }
}

// Where the ray meets the primitive's surface (all real roots, any sign), computed on its own.
void ref_prim_roots(const RefPrim &q, const tld *o, const tld *d, std::vector<tld> &out) {
    tld oc[3] = {o[0] - q.p[0], o[1] - q.p[1], o[2] - q.p[2]};
    tld a, b, c;
    if (q.kind == O_PLANE) {
        tld dn = ref_dot(d, q.n);
        if (dn != 0) out.push_back(-ref_dot(oc, q.n) / dn);
        return;
    }
    if (q.kind == O_SPHERE) {
        a = ref_dot(d, d);
        b = 2 * ref_dot(oc, d);
        c = ref_dot(oc, oc) - q.r * q.r;
    } else {
        tld a2 = ref_dot(q.n, q.n);
        tld so = ref_dot(oc, q.n) / a2, sd = ref_dot(d, q.n) / a2;
        tld op[3] = {oc[0] - q.n[0] * so, oc[1] - q.n[1] * so, oc[2] - q.n[2] * so};
        tld dp[3] = {d[0] - q.n[0] * sd, d[1] - q.n[1] * sd, d[2] - q.n[2] * sd};
        a = ref_dot(dp, dp);
        b = 2 * ref_dot(op, dp);
        c = ref_dot(op, op) - q.r * q.r;
        if (a == 0) return;
    }
    tld disc = b * b - 4 * a * c;
    if (disc < 0) return;
    tld h = std::sqrt(disc);
    out.push_back((-b - h) / (2 * a));
    out.push_back((-b + h) / (2 * a));
}

struct RefChange {
    tld t;
    bool enter;  // the ray enters the solid there
};

// Membership changes of the whole solid along the ray, for t > 0: membership is sampled at a
// fine regular lattice, at the midpoints between the primitives' own surface crossings and past
// the last of them; every change between two samples is located by bisection.
std::vector<RefChange> ref_changes(const RefTree &T, const tld *o, const tld *d) {
    std::vector<tld> roots;
    for (size_t i = 0; i < T.prims.size(); i++) ref_prim_roots(T.prims[i], o, d, roots);
    std::vector<tld> pos;
    for (size_t i = 0; i < roots.size(); i++)
        if (roots[i] > 0) pos.push_back(roots[i]);
    std::sort(pos.begin(), pos.end());
    std::vector<tld> ts;
    ts.push_back(0);
    const int N = 1000;
    const tld TMAX = 12;
    for (int i = 1; i <= N; i++) ts.push_back(TMAX * i / N);
    if (!pos.empty()) {
        ts.push_back(pos[0] / 2);
        for (size_t i = 0; i + 1 < pos.size(); i++) ts.push_back((pos[i] + pos[i + 1]) / 2);
        ts.push_back(pos.back() + 1);
        ts.push_back(pos.back() * 2 + 1);
    }
    std::sort(ts.begin(), ts.end());
    ts.erase(std::unique(ts.begin(), ts.end()), ts.end());
    std::vector<RefChange> out;
    tld x[3];
    std::vector<char> in(ts.size());
    for (size_t i = 0; i < ts.size(); i++) {
        for (int k = 0; k < 3; k++) x[k] = o[k] + ts[i] * d[k];
        in[i] = ref_node_in(T, T.root, x);
    }
    for (size_t i = 0; i + 1 < ts.size(); i++) {
        if (in[i] == in[i + 1]) continue;
        tld lo = ts[i], hi = ts[i + 1];
        for (int it = 0; it < 400; it++) {
            tld mid = (lo + hi) / 2;
            if (!(mid > lo && mid < hi)) break;
            for (int k = 0; k < 3; k++) x[k] = o[k] + mid * d[k];
            if ((char)ref_node_in(T, T.root, x) == in[i]) lo = mid;
            else hi = mid;
        }
        RefChange ch;
        ch.t = (lo + hi) / 2;
        ch.enter = in[i + 1] != 0;
        out.push_back(ch);
    }
    return out;
}

// Deterministic random numbers, the same on every platform (splitmix64).
struct TRng {
    uint64_t s;
    explicit TRng(uint64_t seed) : s(seed) {}
    uint64_t next() {
        uint64_t z = (s += 0x9E3779B97F4A7C15ull);
        z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
        z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
        return z ^ (z >> 31);
    }
    double u01() { return (double)(next() >> 11) * (1.0 / 9007199254740992.0); }
    double uni(double a, double b) { return a + (b - a) * u01(); }
    int below(int n) { return (int)(u01() * n); }
    void dir(double *v) {
        for (;;) {
            v[0] = uni(-1, 1);
            v[1] = uni(-1, 1);
            v[2] = uni(-1, 1);
            double l = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
            if (l > 0.01 && l <= 1) {
                l = std::sqrt(l);
                for (int i = 0; i < 3; i++) v[i] /= l;
                return;
            }
        }
    }
};

// A random tree built twice: as reference data and through the public API.
struct TTreeGen {
    TRng &g;
    RefTree &T;
    pray_ctx *c;
    std::vector<pray_model *> mats;  // material of reference primitive i

    int leaf(pray_object **obj) {
        RefNode nd;
        nd.prim = -1;
        double u = g.u01();
        if (u < 0.03) {
            nd.kind = O_ONE;
            *obj = pray_one(c, pray_color(c, t_rgb(-1, 0, 0)));
        } else if (u < 0.06) {
            nd.kind = O_NOTHING;
            *obj = pray_nothing(c);
        } else {
            RefPrim q;
            double p[3], n[3];
            int k = g.below(3);
            for (int i = 0; i < 3; i++) p[i] = g.uni(-1, 1);
            g.dir(n);
            double len = g.uni(0.5, 2);  // normals and axes need not be unit vectors
            for (int i = 0; i < 3; i++) {
                q.p[i] = p[i];
                q.n[i] = n[i] * len;
            }
            pray_model *m = pray_color(c, t_rgb((double)T.prims.size(), 0, 0));
            if (k == 0) {
                q.kind = O_SPHERE;
                q.r = g.uni(0.3, 1.0);
                *obj = pray_sphere(c, m, t_vec(p[0], p[1], p[2]), (double)q.r);
            } else if (k == 1) {
                q.kind = O_PLANE;
                q.r = 0;
                *obj = pray_plane(c, m, t_vec(p[0], p[1], p[2]), t_vec((double)q.n[0], (double)q.n[1], (double)q.n[2]));
            } else {
                q.kind = O_CYLINDER;
                q.r = g.uni(0.2, 0.7);
                *obj = pray_cylinder(c, m, t_vec(p[0], p[1], p[2]), t_vec((double)q.n[0], (double)q.n[1], (double)q.n[2]),
                                     (double)q.r);
            }
            nd.kind = q.kind;
            nd.prim = (int)T.prims.size();
            T.prims.push_back(q);
            mats.push_back(m);
        }
        T.nodes.push_back(nd);
        return (int)T.nodes.size() - 1;
    }

    int gen(int depth, pray_object **obj, bool top = false) {
        if (depth == 0 || (!top && g.u01() < 0.3)) return leaf(obj);
        double u = g.u01();
        RefNode nd;
        nd.prim = -1;
        nd.kind = u < 0.4 ? O_UNION : u < 0.6 ? O_INTER : u < 0.9 ? O_DIFF : O_COMPL;
        int nk = nd.kind == O_COMPL ? 1 : 2 + g.below(3);
        pray_object *acc = NULL;
        for (int i = 0; i < nk; i++) {
            pray_object *k = NULL;
            nd.kids.push_back(gen(depth - 1, &k));
            if (i == 0) acc = k;
            else acc = pray_csg(c, nd.kind == O_UNION ? PRAY_UNION : nd.kind == O_INTER ? PRAY_INTERSECTION : PRAY_DIFFERENCE,
                                acc, k);
        }
        if (nd.kind == O_COMPL) acc = pray_complement(c, acc);
        *obj = acc;
        T.nodes.push_back(nd);
        return (int)T.nodes.size() - 1;
    }
};

// Compare the sweep with the reference on one ray; returns "" when they agree.
std::string t_compare_ray(TScene &B, const RefTree &T, const std::vector<pray_model *> &mats, const double *o,
                        const double *d, int *nhits) {
    tld lo[3] = {o[0], o[1], o[2]}, ldd[3] = {d[0], d[1], d[2]};
    std::vector<RefChange> want = ref_changes(T, lo, ldd);
    Ray r;
    r.o = r3((real)o[0], (real)o[1], (real)o[2]);
    r.d = r3((real)d[0], (real)d[1], (real)d[2]);
    // (faces between two materials inside the solid, language 12, are no part of its boundary:
    // every primitive here has a material of its own)
    std::vector<Hit> all = B.hits(r), got;
    for (size_t i = 0; i < all.size(); i++)
        if (all[i].from < 0) got.push_back(all[i]);
    FirstHit f = B.first(r);
    *nhits = (int)got.size();
    char buf[512];
    if (got.size() != want.size()) {
        snprintf(buf, sizeof buf, "ray o=(%.17g,%.17g,%.17g) d=(%.17g,%.17g,%.17g): sweep has %d hits, reference %d (first: %g vs %g)",
                 o[0], o[1], o[2], d[0], d[1], d[2], (int)got.size(), (int)want.size(),
                 got.empty() ? -1.0 : (double)got[0].t, want.empty() ? -1.0 : (double)want[0].t);
        return buf;
    }
    if (f.found != !all.empty()) return "FirstHit disagrees with the full sweep";
    if (f.found && (f.h.t != all[0].t || f.h.prim != all[0].prim)) return "FirstHit is not the first hit";
    for (size_t i = 0; i < want.size(); i++) {
        const Hit &h = got[i];
        double tw = (double)want[i].t;
        if (!t_close((double)h.t, tw)) {
            snprintf(buf, sizeof buf, "hit %d: t %.17g, reference %.17g", (int)i, (double)h.t, tw);
            return buf;
        }
        if ((h.root_enter != 0) != want[i].enter) {
            snprintf(buf, sizeof buf, "hit %d at t %g: root_enter %d, reference %d", (int)i, tw, h.root_enter, (int)want[i].enter);
            return buf;
        }
        const pray_model *m = B.s.prims[h.prim].mat;
        int id = -1;
        for (size_t k = 0; k < mats.size(); k++)
            if (mats[k] == m) id = (int)k;
        if (id < 0) return "hit on a primitive of unknown material";
        tld x[3];
        for (int k = 0; k < 3; k++) x[k] = lo[k] + want[i].t * ldd[k];
        tld f = ref_prim_f(T.prims[id], x);
        if (std::fabs((double)f) > 1e-7) {
            snprintf(buf, sizeof buf, "hit %d at t %g: primitive %d's surface is %g away", (int)i, tw, id, (double)f);
            return buf;
        }
        tld gr[3];
        ref_prim_grad(T.prims[id], x, gr);
        tld dd = ref_dot(gr, ldd) / std::sqrt(ref_dot(gr, gr));
        if (std::fabs((double)dd) > 1e-6 && (h.prim_enter != 0) != (dd < 0)) {
            snprintf(buf, sizeof buf, "hit %d at t %g: prim_enter %d, but the ray goes %s primitive %d", (int)i, tw,
                     h.prim_enter, dd < 0 ? "into" : "out of", id);
            return buf;
        }
    }
    return "";
}

} // namespace

// =============================================================================================
// Ray/primitive intersection
// =============================================================================================
namespace {
struct PairLess {  // by key only: items of one key must keep their order
    bool operator()(const std::pair<int, int> &a, const std::pair<int, int> &b) const { return a.first < b.first; }
};
} // namespace

TEST_CASE("sort_items: the order of std::stable_sort, for every length up to 300 and a long one, few keys and many") {
    std::mt19937 rng(7);
    std::vector<size_t> lengths;
    for (size_t n = 0; n <= 300; n++) lengths.push_back(n);
    lengths.push_back(100003);
    for (size_t n : lengths)
        for (int keys : {3, 1000000}) {
            std::vector<std::pair<int, int>> a(n), tmp(n);
            for (size_t i = 0; i < n; i++) a[i] = std::make_pair((int)(rng() % keys), (int)i);
            std::vector<std::pair<int, int>> want = a;
            std::stable_sort(want.begin(), want.end(), PairLess());
            sort_items(a.data(), tmp.data(), n, PairLess());
            REQUIRE_MESSAGE(a == want, "length " << n << ", keys " << keys);
        }
}

TEST_CASE("decimal_exact: the bits of strtod for every number it converts, on random numbers of every shape") {
    std::mt19937_64 rng(11);
    auto same = [](const std::string &t) {
        double v = -1;
        if (!decimal_exact(t.c_str(), &v)) return true;  // (strtod's)
        double w = strtod(t.c_str(), nullptr);
        return std::memcmp(&v, &w, sizeof v) == 0;
    };
    const char *fixed[] = {"0", "0.0", "000.000", "1", "0.1", "0.3", ".5", "5.", "123456789012345", "1234567890123456",
                           "0.000000000000000000001", "1e22", "1e23", "9e22", "999999999999999e22", "1e-22",
                           "123456789012345e-22", "4.9e-324", "1.7976931348623157e308", "0.0000012345e+5", "7E-0",
                           "9007199254740993", "0.1e1", "100000000000000000000000", "3.141592653589793"};
    for (const char *t : fixed) CHECK_MESSAGE(same(t), t);
    int converted = 0;
    for (int i = 0; i < 200000; i++) {
        std::string t;
        int lead = (int)(rng() % 3), intd = (int)(rng() % 12), fracd = (int)(rng() % 12);
        for (int k = 0; k < lead; k++) t += '0';
        for (int k = 0; k < intd; k++) t += (char)('0' + rng() % 10);
        if (t.empty() || rng() % 2) {
            t += '.';
            for (int k = 0; k < fracd; k++) t += (char)('0' + rng() % 10);
            if (fracd == 0) t += '0';
        }
        if (rng() % 2) t += (rng() % 2 ? "e-" : "e") + std::to_string(rng() % 30);
        double v;
        converted += decimal_exact(t.c_str(), &v);
        REQUIRE_MESSAGE(same(t), t);
    }
    if (DOUBLE_ROUNDS_ONCE) CHECK(converted > 100000);  // (so that the comparisons above compare something)
}

TEST_CASE("prim_span: sphere, exact roots") {
    TCtx k;
    pray_object *s = pray_sphere(k.c, k.mat(1), t_vec(0, 0, 0), 2);
    TSpan sp = t_span_of(k.c, s, t_ray(-5, 0, 0, 1, 0, 0));
    CHECK(sp.kind == SPAN);
    CHECK(sp.t0 == 3);
    CHECK(sp.t1 == 7);

    pray_object *s2 = pray_sphere(k.c, k.mat(1), t_vec(1, 2, 3), 1);
    sp = t_span_of(k.c, s2, t_ray(1, 2, -2, 0, 0, 1));
    CHECK(sp.kind == SPAN);
    CHECK(sp.t0 == 4);
    CHECK(sp.t1 == 6);
    // from the inside: the near root is behind the origin
    sp = t_span_of(k.c, s2, t_ray(1, 2, 3, 0, -1, 0));
    CHECK(sp.kind == SPAN);
    CHECK(sp.t0 == -1);
    CHECK(sp.t1 == 1);
    // pointing away: both roots behind
    sp = t_span_of(k.c, s, t_ray(-5, 0, 0, -1, 0, 0));
    CHECK((sp.kind == SPAN_NONE || (sp.kind == SPAN && sp.t1 < 0)));
    // a miss
    sp = t_span_of(k.c, s, t_ray(-5, 2.5, 0, 1, 0, 0));
    CHECK(sp.kind == SPAN_NONE);
    // an oblique ray through the centre: roots at distance +-r from the centre
    sp = t_span_of(k.c, s, t_ray(-3, -4, 0, 3, 4, 0));
    CHECK(sp.kind == SPAN);
    CHECK(t_close(sp.t0, 3));
    CHECK(t_close(sp.t1, 7));
}

TEST_CASE("prim_span: half-space, both normal orientations and parallel rays") {
    TCtx k;
    // z <= 1
    pray_object *up = pray_plane(k.c, k.mat(1), t_vec(0, 0, 1), t_vec(0, 0, 1));
    // z >= 1 (outward normal -Z, given with length 3: only the direction matters)
    pray_object *down = pray_plane(k.c, k.mat(1), t_vec(7, -2, 1), t_vec(0, 0, -3));

    TSpan sp = t_span_of(k.c, up, t_ray(0, 0, 5, 0, 0, -1));  // from outside, going in
    CHECK(sp.kind == SPAN);
    CHECK(sp.t0 == 4);
    CHECK(std::isinf((double)sp.t1));
    CHECK(sp.t1 > 0);
    sp = t_span_of(k.c, up, t_ray(0, 0, -3, 0, 0, 1));  // from inside, going out
    CHECK(sp.kind == SPAN);
    CHECK(sp.t1 == 4);
    CHECK(std::isinf((double)sp.t0));
    CHECK(sp.t0 < 0);

    sp = t_span_of(k.c, down, t_ray(0, 0, 5, 0, 0, -1));  // from inside z >= 1, going out at z = 1
    CHECK(sp.kind == SPAN);
    CHECK(sp.t1 == 4);
    CHECK(sp.t0 < 0);
    sp = t_span_of(k.c, down, t_ray(3, 3, -3, 0, 0, 1));  // from outside, going in
    CHECK(sp.kind == SPAN);
    CHECK(sp.t0 == 4);
    CHECK(sp.t1 > 1e300);

    // parallel to the plane: inside is all of the ray, outside none of it
    sp = t_span_of(k.c, up, t_ray(0, 0, 0, 1, 0, 0));
    CHECK(sp.kind == SPAN_ALL);
    sp = t_span_of(k.c, up, t_ray(0, 0, 2, 0, 1, 0));
    CHECK(sp.kind == SPAN_NONE);
    sp = t_span_of(k.c, down, t_ray(0, 0, 0, 1, 0, 0));
    CHECK(sp.kind == SPAN_NONE);
    sp = t_span_of(k.c, down, t_ray(0, 0, 2, 0, 1, 0));
    CHECK(sp.kind == SPAN_ALL);

    // oblique: x + y <= 1, ray along X from the origin meets it at t = 1
    pray_object *ob = pray_plane(k.c, k.mat(1), t_vec(1, 0, 0), t_vec(1, 1, 0));
    sp = t_span_of(k.c, ob, t_ray(0, 0, 0, 1, 0, 0));
    CHECK(sp.kind == SPAN);
    CHECK(t_close(sp.t1, 1));
    CHECK(sp.t0 < 0);
}

TEST_CASE("prim_span: infinite cylinder") {
    TCtx k;
    // axis Z through the origin, radius 1; axis given with length 2
    pray_object *cy = pray_cylinder(k.c, k.mat(1), t_vec(0, 0, 0), t_vec(0, 0, 2), 1);
    TSpan sp = t_span_of(k.c, cy, t_ray(-3, 0, 5, 1, 0, 0));
    CHECK(sp.kind == SPAN);
    CHECK(sp.t0 == 2);
    CHECK(sp.t1 == 4);
    // parallel to the axis: inside all of it, outside none of it
    sp = t_span_of(k.c, cy, t_ray(0.5, 0.25, -7, 0, 0, 1));
    CHECK(sp.kind == SPAN_ALL);
    sp = t_span_of(k.c, cy, t_ray(0.5, 0.25, -7, 0, 0, -1));
    CHECK(sp.kind == SPAN_ALL);
    sp = t_span_of(k.c, cy, t_ray(2, 0, 0, 0, 0, 1));
    CHECK(sp.kind == SPAN_NONE);
    // oblique, at 45 degrees to the axis: the chord is sqrt(2) times longer
    sp = t_span_of(k.c, cy, t_ray(-3, 0, 0, 1, 0, 1));
    CHECK(sp.kind == SPAN);
    CHECK(t_close(sp.t0, 2 * std::sqrt(2.0)));
    CHECK(t_close(sp.t1, 4 * std::sqrt(2.0)));
    // an oblique miss
    sp = t_span_of(k.c, cy, t_ray(-3, 1.5, 0, 1, 0, 1));
    CHECK(sp.kind == SPAN_NONE);
    // a cylinder with a slanted axis through (1, 2, 3): a ray perpendicular to the axis through it
    pray_object *sl = pray_cylinder(k.c, k.mat(1), t_vec(1, 2, 3), t_vec(1, 1, 0), 0.5);
    sp = t_span_of(k.c, sl, t_ray(1 - 5, 2 + 5, 3, 1, -1, 0));
    CHECK(sp.kind == SPAN);
    CHECK(t_close(sp.t0, 5 * std::sqrt(2.0) - 0.5));
    CHECK(t_close(sp.t1, 5 * std::sqrt(2.0) + 0.5));
}

TEST_CASE("prim_span: the self-primitive rule") {
    TCtx k;
    pray_object *s = pray_sphere(k.c, k.mat(1), t_vec(0, 0, 0), 1);
    // starting on the surface, going in: [0, far root]
    TSpan sp = t_span_of(k.c, s, t_ray(1, 0, 0, -1, 0, 0), true);
    CHECK(sp.kind == SPAN);
    CHECK(sp.t0 == 0);
    CHECK(sp.t1 == 2);
    // going out: nothing
    sp = t_span_of(k.c, s, t_ray(1, 0, 0, 1, 0, 0), true);
    CHECK(sp.kind == SPAN_NONE);
    sp = t_span_of(k.c, s, t_ray(0, 0, 1, 0.6, 0, 0.8), true);
    CHECK(sp.kind == SPAN_NONE);

    pray_object *pl = pray_plane(k.c, k.mat(1), t_vec(0, 0, 0), t_vec(0, 0, 1));
    sp = t_span_of(k.c, pl, t_ray(0.3, 0.1, 0, 0, 0.6, -0.8), true);
    CHECK(sp.kind == SPAN);
    CHECK(sp.t0 == 0);
    CHECK(sp.t1 > 1e300);
    sp = t_span_of(k.c, pl, t_ray(0.3, 0.1, 0, 0, 0.6, 0.8), true);
    CHECK(sp.kind == SPAN_NONE);

    pray_object *cy = pray_cylinder(k.c, k.mat(1), t_vec(0, 0, 0), t_vec(0, 0, 1), 1);
    sp = t_span_of(k.c, cy, t_ray(-1, 0, 4, 1, 0, 0), true);
    CHECK(sp.kind == SPAN);
    CHECK(sp.t0 == 0);
    CHECK(sp.t1 == 2);
    sp = t_span_of(k.c, cy, t_ray(-1, 0, 4, -1, 0, 0), true);
    CHECK(sp.kind == SPAN_NONE);
}

TEST_CASE("sweep: rays leaving a sphere's surface (self) on random points, also where rounding misplaces them") {
    TCtx k;
    const double C[3] = {0.3, 0.7, -0.2}, R = 0.9;
    pray_object *s = pray_sphere(k.c, k.mat(1), t_vec(C[0], C[1], C[2]), R);
    pray_object *other = pray_sphere(k.c, k.mat(2), t_vec(5, 5, 5), 0.5);  // far away, never hit
    TScene B(k.c, pray_csg(k.c, PRAY_UNION, s, other));
    REQUIRE(B.ok);
    int self = B.prim_of(s->mat);
    REQUIRE(self >= 0);
    TRng g(7);
    int bad_in = 0, bad_out = 0;
    for (int i = 0; i < 300; i++) {
        double n[3], d[3];
        g.dir(n);
        double o[3] = {C[0] + R * n[0], C[1] + R * n[1], C[2] + R * n[2]};
        g.dir(d);
        double dn = d[0] * n[0] + d[1] * n[1] + d[2] * n[2];
        if (std::fabs(dn) < 0.05) continue;
        Ray r = t_ray(o[0], o[1], o[2], d[0], d[1], d[2]);
        std::vector<Hit> h = B.hits(r, self);
        if (dn < 0) {
            // inward: exactly one hit, leaving the sphere at the far root, chord 2 R |d.n|
            if (h.size() != 1 || !t_close((double)h[0].t, -2 * R * dn) || h[0].root_enter || h[0].prim != self) bad_in++;
        } else if (!h.empty()) {
            bad_out++;  // outward: nothing at all
        }
    }
    CHECK(bad_in == 0);
    CHECK(bad_out == 0);
}

TEST_CASE("sweep: tmax bounds the hits (shadow rays)") {
    TCtx k;
    TScene B(k.c, pray_sphere(k.c, k.mat(1), t_vec(0, 0, 0), 2));
    REQUIRE(B.ok);
    Ray r = t_ray(-5, 0, 0, 1, 0, 0);
    CHECK(B.hits(r, -1, 2).empty());
    std::vector<Hit> h = B.hits(r, -1, 5);
    REQUIRE(h.size() == 1);
    CHECK(h[0].t == 3);
    h = B.hits(r);
    REQUIRE(h.size() == 2);
    CHECK(h[0].t == 3);
    CHECK(h[0].root_enter == 1);
    CHECK(h[0].prim_enter == 1);
    CHECK(h[1].t == 7);
    CHECK(h[1].root_enter == 0);
    CHECK(h[1].prim_enter == 0);
}

// =============================================================================================
// CSG semantics of the status-tree sweep
// =============================================================================================
// Random trees and rays against the reference; options are "name=value" render options.
struct RandomRun {
    int rays = 0, rays_with_hits = 0, total_hits = 0, failures = 0, trees_with_nodes = 0, accelerated = 0;
    std::string first_failure;
};

RandomRun random_trees(const std::vector<std::string> &options, bool accelerated, int trees) {
    RandomRun R;
    TCtx k;
    for (size_t i = 0; i < options.size(); i++) {
        size_t eq = options[i].find('=');
        CHECK(pray_option(k.c, options[i].substr(0, eq).c_str(), atof(options[i].c_str() + eq + 1)) == PRAY_OK);
    }
    for (uint64_t seed = 1; seed <= (uint64_t)trees; seed++) {
        TRng g(seed * 1000003ull);
        RefTree T;
        TTreeGen gen = {g, T, k.c, std::vector<pray_model *>()};
        pray_object *obj = NULL;
        T.root = gen.gen(3, &obj, true);
        REQUIRE(obj != NULL);
        TScene B(k.c, obj);
        REQUIRE(B.ok);
        B.accelerated = accelerated;
        if (B.s.nodes.n > 0) R.trees_with_nodes++;
        if (B.s.accel) R.accelerated++;
        for (int i = 0; i < 8; i++) {
            double o[3], d[3];
            if (i % 2 == 0) {  // from outside, aimed into the busy region
                double u[3];
                g.dir(u);
                double tgt[3] = {g.uni(-0.8, 0.8), g.uni(-0.8, 0.8), g.uni(-0.8, 0.8)};
                for (int j = 0; j < 3; j++) o[j] = 4 * u[j];
                double l = 0;
                for (int j = 0; j < 3; j++) {
                    d[j] = tgt[j] - o[j];
                    l += d[j] * d[j];
                }
                l = std::sqrt(l);
                for (int j = 0; j < 3; j++) d[j] /= l;
            } else {  // from anywhere near, in any direction
                for (int j = 0; j < 3; j++) o[j] = g.uni(-1.5, 1.5);
                g.dir(d);
            }
            int nh = 0;
            std::string why = t_compare_ray(B, T, gen.mats, o, d, &nh);
            R.rays++;
            R.total_hits += nh;
            if (nh > 0) R.rays_with_hits++;
            if (!why.empty()) {
                R.failures++;
                if (R.first_failure.empty()) R.first_failure = "seed " + std::to_string(seed) + ": " + why;
            }
        }
    }
    return R;
}

TEST_CASE("sweep agrees with direct set membership on random CSG trees (fixed seeds)") {
    RandomRun R = random_trees({}, false, 100);
    CHECK_MESSAGE(R.failures == 0, R.first_failure);
    // the test means something only when the trees are varied and the rays meet them
    CHECK(R.rays == 800);
    CHECK(R.rays_with_hits >= 200);
    CHECK(R.total_hits >= 350);
    CHECK(R.trees_with_nodes >= 30);
    // the same without pruning and compaction of the flattened tree
    R = random_trees({"brute=1"}, false, 100);
    CHECK_MESSAGE(R.failures == 0, R.first_failure);
}

TEST_CASE("the accelerated path agrees with direct set membership on random CSG trees") {
    const std::vector<std::vector<std::string> > sets = {
        {}, {"grid=1"}, {"grid=4", "freeze=0"}, {"grid=7", "merge=0"}, {"grid=3", "bounds=0"}, {"grid=16"}};
    for (size_t i = 0; i < sets.size(); i++) {
        CAPTURE(i);
        RandomRun R = random_trees(sets[i], true, 40);
        CHECK_MESSAGE(R.failures == 0, R.first_failure);
        CHECK(R.rays == 320);
        if (!sets[i].empty()) CHECK(R.accelerated >= 30);  // a grid was built
    }
}

// Cube [-1, 1]^3 minus the box [0, 1] x [-0.5, 0.5]^2: the box's face x = 1 lies in the cube's
// face x = 1; the two planes are given by different points of that plane.
struct TNotch {
    pray_model *cm, *inner, *shared, *bm;
    pray_object *obj;
    TNotch(TCtx &k, pray_vec cube_pt, pray_vec box_pt) {
        cm = k.mat(1);
        inner = k.mat(2);
        shared = k.mat(3);
        bm = k.mat(4);
        pray_ctx *c = k.c;
        pray_object *cube = pray_plane(c, cm, cube_pt, t_vec(1, 0, 0));
        cube = pray_csg(c, PRAY_INTERSECTION, cube, pray_plane(c, cm, t_vec(-1, 0, 0), t_vec(-1, 0, 0)));
        cube = pray_csg(c, PRAY_INTERSECTION, cube, pray_plane(c, cm, t_vec(0, 1, 0), t_vec(0, 1, 0)));
        cube = pray_csg(c, PRAY_INTERSECTION, cube, pray_plane(c, cm, t_vec(0, -1, 0), t_vec(0, -1, 0)));
        cube = pray_csg(c, PRAY_INTERSECTION, cube, pray_plane(c, cm, t_vec(0, 0, 1), t_vec(0, 0, 1)));
        cube = pray_csg(c, PRAY_INTERSECTION, cube, pray_plane(c, cm, t_vec(0, 0, -1), t_vec(0, 0, -1)));
        pray_object *box = pray_plane(c, shared, box_pt, t_vec(1, 0, 0));
        box = pray_csg(c, PRAY_INTERSECTION, box, pray_plane(c, inner, t_vec(0, 0, 0), t_vec(-1, 0, 0)));
        box = pray_csg(c, PRAY_INTERSECTION, box, pray_plane(c, bm, t_vec(0, 0.5, 0), t_vec(0, 1, 0)));
        box = pray_csg(c, PRAY_INTERSECTION, box, pray_plane(c, bm, t_vec(0, -0.5, 0), t_vec(0, -1, 0)));
        box = pray_csg(c, PRAY_INTERSECTION, box, pray_plane(c, bm, t_vec(0, 0, 0.5), t_vec(0, 0, 1)));
        box = pray_csg(c, PRAY_INTERSECTION, box, pray_plane(c, bm, t_vec(0, 0, -0.5), t_vec(0, 0, -1)));
        obj = pray_csg(c, PRAY_DIFFERENCE, cube, box);
    }
};

TEST_CASE("list plans: a wall with a window, the window's box turned inside out as a group of the wall") {
    // A slab minus a box through it. Around the opening's edges a voxel holds two or three of the
    // box's planes, turned inside out: a union under the slab's intersection, which the flat
    // sweep takes as a group. Every list then has a plan, and rays through the wall at random
    // see what the reference sees.
    TCtx k;
    REQUIRE(pray_option(k.c, "grid", 6) == PRAY_OK);
    pray_ctx *c = k.c;
    auto box = [&](double x, double y, double z, pray_model *m) {
        pray_object *b = pray_plane(c, m, t_vec(x, y, z), t_vec(1, 0, 0));
        b = pray_csg(c, PRAY_INTERSECTION, b, pray_plane(c, m, t_vec(-x, -y, -z), t_vec(-1, 0, 0)));
        b = pray_csg(c, PRAY_INTERSECTION, b, pray_plane(c, m, t_vec(x, y, z), t_vec(0, 1, 0)));
        b = pray_csg(c, PRAY_INTERSECTION, b, pray_plane(c, m, t_vec(-x, -y, -z), t_vec(0, -1, 0)));
        b = pray_csg(c, PRAY_INTERSECTION, b, pray_plane(c, m, t_vec(x, y, z), t_vec(0, 0, 1)));
        return pray_csg(c, PRAY_INTERSECTION, b, pray_plane(c, m, t_vec(-x, -y, -z), t_vec(0, 0, -1)));
    };
    pray_object *wall = pray_csg(c, PRAY_DIFFERENCE, box(1, 0.1, 1, k.mat(1)), box(0.35, 0.5, 0.25, k.mat(2)));
    TScene B(c, wall);
    REQUIRE(B.ok);
    REQUIRE(B.s.accel);
    const Accel *A = B.s.accel;
    int with_groups = 0, without_plan = 0;
    for (int L = 1; L < A->off.n; L++) {
        if (A->plan_at[L] < 0) without_plan++;
        else if (A->plan[A->plan_at[L] + 2] > 0) with_groups++;
    }
    CHECK(without_plan == 0);
    CHECK(with_groups > 0);
    TRng g(5);
    int wrong = 0;
    for (int i = 0; i < 400; i++) {
        double o[3] = {g.uni(-1.2, 1.2), -3, g.uni(-1.2, 1.2)}, d[3] = {g.uni(-0.3, 0.3), 1, g.uni(-0.3, 0.3)};
        Ray r = t_ray(o[0], o[1], o[2], d[0], d[1], d[2]);
        B.accelerated = false;
        std::vector<Hit> want = B.hits(r);
        B.accelerated = true;
        std::vector<Hit> got = B.hits(r);
        bool same = want.size() == got.size();
        for (size_t j = 0; same && j < want.size(); j++)
            same = want[j].t == got[j].t && want[j].prim == got[j].prim && want[j].root_enter == got[j].root_enter;
        wrong += !same;
    }
    CHECK(wrong == 0);
}

TEST_CASE("difference: a face shared with the subtracted box is not visible") {
    TCtx k;
    SUBCASE("axis-aligned") {
        TNotch N(k, t_vec(1, 0, 0), t_vec(1, 0.3, -0.2));
        TScene B(k.c, N.obj);
        REQUIRE(B.ok);
        TRng g(11);
        int wrong = 0;
        for (int i = 0; i < 200; i++) {
            double y = g.uni(-0.45, 0.45), z = g.uni(-0.45, 0.45);
            double dy = g.uni(-0.05, 0.05), dz = g.uni(-0.05, 0.05);
            // from x = 5 towards -X, passing x = 1 within the box's face
            Ray r = t_ray(5, y - 4 * dy, z - 4 * dz, -1, dy, dz);
            FirstHit f = B.first(r);
            if (!f.found || B.s.prims[f.h.prim].mat != N.inner || !f.h.root_enter) wrong++;
            else {
                double x = (double)(r.o.x + r.d.x * f.h.t);
                if (std::fabs(x) > 1e-9) wrong++;
            }
        }
        CHECK(wrong == 0);
        // straight along -X: the first visible surface is the box's inner face at t = 5
        FirstHit f = B.first(t_ray(5, 0.1, 0.2, -1, 0, 0));
        REQUIRE(f.found);
        CHECK(f.h.t == 5);
        CHECK(B.s.prims[f.h.prim].mat == N.inner);
    }
    SUBCASE("rotated and moved: the two coincident planes are rounded differently") {
        // With these rotations the two x = 1 planes end up with offsets one ulp apart; with the
        // points swapped, either plane comes first along the ray.
        const double rots[4][3] = {{20, 31, 47}, {21, 31, 47}, {24, 31, 47}, {27, 31, 47}};
        int shared_hits = 0, wrong = 0, rays = 0;
        for (int swap = 0; swap < 2; swap++)
            for (int ri = 0; ri < 4; ri++) {
                pray_vec p1 = t_vec(1, 0, 0), p2 = t_vec(1, 0.3, -0.2);
                TNotch N(k, swap ? p2 : p1, swap ? p1 : p2);
                pray_vec rot = t_vec(rots[ri][0], rots[ri][1], rots[ri][2]);
                pray_vec mv = t_vec(0.3, -1.7, 2.9);
                TScene B(k.c, pray_translate(k.c, pray_rotate(k.c, N.obj, rot), mv));
                REQUIRE(B.ok);
                Xform f = xf_rotate(rot);
                TRng g(12 + ri);
                for (int i = 0; i < 100; i++) {
                    double y = g.uni(-0.45, 0.45), z = g.uni(-0.45, 0.45);
                    double dy = g.uni(-0.05, 0.05), dz = g.uni(-0.05, 0.05);
                    pray_vec o = vadd(xf_point(f, t_vec(5, y - 4 * dy, z - 4 * dz)), mv);
                    pray_vec d = xf_dir(f, t_vec(-1, dy, dz));
                    Ray r = t_ray(o.x, o.y, o.z, d.x, d.y, d.z);
                    FirstHit fh = B.first(r);
                    rays++;
                    if (!fh.found) wrong++;
                    else if (B.s.prims[fh.h.prim].mat != N.inner) {
                        wrong++;
                        if (B.s.prims[fh.h.prim].mat == N.shared || B.s.prims[fh.h.prim].mat == N.cm) shared_hits++;
                    }
                }
            }
        CHECK_MESSAGE(shared_hits == 0, "the shared face speckles: ", shared_hits, " of ", rays, " rays stop on it");
        CHECK(wrong == 0);
    }
}

TEST_CASE("difference: a solid minus itself is empty") {
    TCtx k;
    pray_object *s = pray_sphere(k.c, k.mat(1), t_vec(0.1, 0.2, 0.3), 1);
    TScene B(k.c, pray_csg(k.c, PRAY_DIFFERENCE, s, s));
    REQUIRE(B.ok);
    TRng g(3);
    int hits = 0;
    for (int i = 0; i < 100; i++) {
        double d[3];
        g.dir(d);
        hits += (int)B.hits(t_ray(-3 * d[0], -3 * d[1], -3 * d[2], d[0], d[1], d[2])).size();
    }
    CHECK(hits == 0);
}

TEST_CASE("complement: seen from outside the sphere and from inside it") {
    TCtx k;
    pray_model *m = k.mat(1);
    pray_object *s = pray_sphere(k.c, m, t_vec(0, 0, 0), 1);
    TScene B(k.c, pray_complement(k.c, s));
    REQUIRE(B.ok);
    // the camera is in the complement: nothing until the sphere, where the ray leaves the solid
    std::vector<Hit> h = B.hits(t_ray(0, -4, 0, 0, 1, 0));
    REQUIRE(h.size() == 2);
    CHECK(h[0].t == 3);
    CHECK(h[0].root_enter == 0);
    CHECK(h[0].prim_enter == 1);
    CHECK(B.s.prims[h[0].prim].mat == m);
    CHECK(h[1].t == 5);
    CHECK(h[1].root_enter == 1);
    // from inside the sphere (outside the complement): the ray enters the complement at t = 1
    FirstHit f = B.first(t_ray(0, 0, 0, 0.6, 0, 0.8));
    REQUIRE(f.found);
    CHECK(t_close((double)f.h.t, 1));
    CHECK(f.h.root_enter == 1);
    // a ray that misses the sphere stays inside the complement: no surface at all
    CHECK(B.hits(t_ray(0, -4, 1.5, 0, 1, 0)).empty());
    // --S is S
    TScene B2(k.c, pray_complement(k.c, pray_complement(k.c, s)));
    h = B2.hits(t_ray(0, -4, 0, 0, 1, 0));
    REQUIRE(h.size() == 2);
    CHECK(h[0].root_enter == 1);
    // A & -B is A - B
    pray_object *a = pray_sphere(k.c, k.mat(2), t_vec(-0.5, 0, 0), 1);
    TScene B3(k.c, pray_csg(k.c, PRAY_INTERSECTION, a, pray_complement(k.c, s)));
    h = B3.hits(t_ray(-5, 0, 0, 1, 0, 0));
    REQUIRE(h.size() == 2);
    CHECK(h[0].t == 3.5);
    CHECK(h[1].t == 4);
    CHECK(h[1].root_enter == 0);
    CHECK(B3.s.prims[h[1].prim].mat == m);
}

TEST_CASE("n-ary difference chains") {
    TCtx k;
    pray_model *big = k.mat(1), *h1 = k.mat(2), *h2 = k.mat(3), *h3 = k.mat(4);
    pray_object *A = pray_sphere(k.c, big, t_vec(0, 0, 0), 2);
    pray_object *B1 = pray_sphere(k.c, h1, t_vec(-1, 0, 0), 0.25);
    pray_object *B2 = pray_sphere(k.c, h2, t_vec(0, 0, 0), 0.5);
    pray_object *B3 = pray_sphere(k.c, h3, t_vec(1, 0, 0), 0.25);
    pray_object *chain = pray_csg(k.c, PRAY_DIFFERENCE, pray_csg(k.c, PRAY_DIFFERENCE, pray_csg(k.c, PRAY_DIFFERENCE, A, B1), B2), B3);
    TScene B(k.c, chain);
    REQUIRE(B.ok);
    // one node with four children: ((A \ B1) \ B2) \ B3
    CHECK(B.s.nodes.n == 1);
    CHECK(B.s.nodes[0].op == O_DIFF);
    CHECK(B.s.nodes[0].n == 4);
    std::vector<Hit> h = B.hits(t_ray(-5, 0, 0, 1, 0, 0));
    const double want_t[] = {3, 3.75, 4.25, 4.5, 5.5, 5.75, 6.25, 7};
    const pray_model *want_m[] = {big, h1, h1, h2, h2, h3, h3, big};
    REQUIRE(h.size() == 8);
    for (int i = 0; i < 8; i++) {
        CAPTURE(i);
        CHECK(h[i].t == want_t[i]);
        CHECK(h[i].root_enter == (i % 2 == 0 ? 1 : 0));
        CHECK(B.s.prims[h[i].prim].mat == want_m[i]);
    }
    // A \ (B2 \ B') is not ((A \ B2) \ B'): the inner difference gives back the core of B2
    pray_object *core = pray_sphere(k.c, k.mat(5), t_vec(0, 0, 0), 0.25);
    TScene N(k.c, pray_csg(k.c, PRAY_DIFFERENCE, A, pray_csg(k.c, PRAY_DIFFERENCE, B2, core)));
    REQUIRE(N.ok);
    h = N.hits(t_ray(-5, 0, 0, 1, 0, 0));
    const double want_n[] = {3, 4.5, 4.75, 5.25, 5.5, 7};
    REQUIRE(h.size() == 6);
    for (int i = 0; i < 6; i++) CHECK(h[i].t == want_n[i]);
}

TEST_CASE("a union grown in a loop is one node") {
    TCtx k;
    pray_object *all = pray_nothing(k.c);
    for (int i = 0; i < 1024; i++) {
        pray_object *s = pray_sphere(k.c, k.mat(i), t_vec(i, 0, 0), 0.25);
        pray_object *n = pray_csg(k.c, PRAY_UNION, all, s);
        pray_release(k.c, all);
        pray_release(k.c, s);
        all = n;
    }
    REQUIRE(all != NULL);
    CHECK(pray_object_primitives(all) == 1024);
    TScene B(k.c, all);
    REQUIRE(B.ok);
    CHECK(B.s.nodes.n == 1);
    CHECK(B.s.nodes[0].n == 1024);
    CHECK(B.s.prims.n == 1024);
    std::vector<Hit> h = B.hits(t_ray(-1, 0, 0, 1, 0, 0));
    CHECK(h.size() == 2048);
}

TEST_CASE("tangent rays produce no hit") {
    TCtx k;
    SUBCASE("sphere") {
        TScene B(k.c, pray_sphere(k.c, k.mat(1), t_vec(0, 0, 0), 1));
        CHECK(B.hits(t_ray(-5, 1, 0, 1, 0, 0)).empty());
        CHECK(B.hits(t_ray(-5, 0, -1, 1, 0, 0)).empty());
    }
    SUBCASE("cylinder") {
        TScene B(k.c, pray_cylinder(k.c, k.mat(1), t_vec(0, 0, 0), t_vec(0, 0, 1), 1));
        CHECK(B.hits(t_ray(-5, 1, 3, 1, 0, 0)).empty());
        CHECK(B.hits(t_ray(-5, -1, 3, 1, 0, 0)).empty());
    }
    SUBCASE("a ray lying in a half-space's boundary plane") {
        TScene B(k.c, pray_plane(k.c, k.mat(1), t_vec(0, 0, 1), t_vec(0, 0, 1)));
        CHECK(B.hits(t_ray(-5, 0, 1, 1, 0.5, 0)).empty());
    }
    SUBCASE("a ray gliding along a face and along an edge of a cube") {
        pray_model *m = k.mat(1);
        pray_object *c = pray_plane(k.c, m, t_vec(1, 0, 0), t_vec(1, 0, 0));
        c = pray_csg(k.c, PRAY_INTERSECTION, c, pray_plane(k.c, m, t_vec(-1, 0, 0), t_vec(-1, 0, 0)));
        c = pray_csg(k.c, PRAY_INTERSECTION, c, pray_plane(k.c, m, t_vec(0, 1, 0), t_vec(0, 1, 0)));
        c = pray_csg(k.c, PRAY_INTERSECTION, c, pray_plane(k.c, m, t_vec(0, -1, 0), t_vec(0, -1, 0)));
        c = pray_csg(k.c, PRAY_INTERSECTION, c, pray_plane(k.c, m, t_vec(0, 0, 1), t_vec(0, 0, 1)));
        c = pray_csg(k.c, PRAY_INTERSECTION, c, pray_plane(k.c, m, t_vec(0, 0, -1), t_vec(0, 0, -1)));
        TScene B(k.c, c);
        CHECK(B.hits(t_ray(-5, 0.2, 1, 1, 0, 0)).empty());  // in the face z = 1
        CHECK(B.hits(t_ray(-5, 1, 1, 1, 0, 0)).empty());    // along the edge y = z = 1
        CHECK(B.hits(t_ray(-5, 0.2, 0.5, 1, 0, 0)).size() == 2);
    }
    SUBCASE("touching a hole inside a solid adds nothing") {
        pray_model *m = k.mat(1), *hm = k.mat(2);
        pray_object *c = pray_plane(k.c, m, t_vec(1, 0, 0), t_vec(1, 0, 0));
        c = pray_csg(k.c, PRAY_INTERSECTION, c, pray_plane(k.c, m, t_vec(-1, 0, 0), t_vec(-1, 0, 0)));
        c = pray_csg(k.c, PRAY_INTERSECTION, c, pray_plane(k.c, m, t_vec(0, 1, 0), t_vec(0, 1, 0)));
        c = pray_csg(k.c, PRAY_INTERSECTION, c, pray_plane(k.c, m, t_vec(0, -1, 0), t_vec(0, -1, 0)));
        c = pray_csg(k.c, PRAY_INTERSECTION, c, pray_plane(k.c, m, t_vec(0, 0, 1), t_vec(0, 0, 1)));
        c = pray_csg(k.c, PRAY_INTERSECTION, c, pray_plane(k.c, m, t_vec(0, 0, -1), t_vec(0, 0, -1)));
        TScene B(k.c, pray_csg(k.c, PRAY_DIFFERENCE, c, pray_sphere(k.c, hm, t_vec(0, 0, 0), 0.5)));
        std::vector<Hit> h = B.hits(t_ray(-5, 0.5, 0, 1, 0, 0));
        REQUIRE(h.size() == 2);
        CHECK(h[0].t == 4);
        CHECK(h[1].t == 6);
    }
}

TEST_CASE("folding of nothing and one") {
    TCtx k;
    pray_model *m = k.mat(1);
    pray_object *s = pray_sphere(k.c, m, t_vec(0, 0, 0), 1);
    pray_object *s2 = pray_sphere(k.c, k.mat(2), t_vec(0.5, 0, 0), 1);
    pray_object *one = pray_one(k.c, k.mat(9));
    pray_object *none = pray_nothing(k.c);
    Ray r = t_ray(-5, 0, 0, 1, 0, 0);
    SUBCASE("union with one is all of space: no surface anywhere") {
        TScene B(k.c, pray_csg(k.c, PRAY_UNION, s, one));
        CHECK(B.s.root == E_ALL);
        CHECK(B.hits(r).empty());
        CHECK(B.hits(t_ray(0, 0, 0, 0, 0, 1)).empty());
        TScene B2(k.c, pray_csg(k.c, PRAY_UNION, pray_csg(k.c, PRAY_INTERSECTION, s, s2), one));
        CHECK(B2.hits(r).empty());
    }
    SUBCASE("nothing, and everything intersected with nothing") {
        TScene B(k.c, none);
        CHECK(B.hits(r).empty());
        TScene B2(k.c, pray_csg(k.c, PRAY_INTERSECTION, s, none));
        CHECK(B2.s.root == E_NONE);
        CHECK(B2.hits(r).empty());
        TScene B3(k.c, pray_csg(k.c, PRAY_DIFFERENCE, s, one));
        CHECK(B3.hits(r).empty());
        TScene B4(k.c, pray_csg(k.c, PRAY_DIFFERENCE, none, s));
        CHECK(B4.hits(r).empty());
        TScene B5(k.c, pray_complement(k.c, one));
        CHECK(B5.hits(r).empty());
    }
    SUBCASE("neutral elements leave the other operand as it is") {
        const pray_object *forms[] = {pray_csg(k.c, PRAY_UNION, s, none), pray_csg(k.c, PRAY_UNION, none, s),
                                      pray_csg(k.c, PRAY_INTERSECTION, s, one), pray_csg(k.c, PRAY_INTERSECTION, one, s),
                                      pray_csg(k.c, PRAY_DIFFERENCE, s, none),
                                      pray_csg(k.c, PRAY_UNION, s, pray_csg(k.c, PRAY_INTERSECTION, s2, none)),
                                      pray_csg(k.c, PRAY_INTERSECTION, s, pray_complement(k.c, none))};
        for (int i = 0; i < 7; i++) {
            CAPTURE(i);
            TScene B(k.c, (pray_object *)forms[i]);
            std::vector<Hit> h = B.hits(r);
            REQUIRE(h.size() == 2);
            CHECK(h[0].t == 4);
            CHECK(h[1].t == 6);
            CHECK(B.s.prims[h[0].prim].mat == m);
        }
    }
    SUBCASE("one minus others is the complement of their union") {
        TScene B(k.c, pray_csg(k.c, PRAY_DIFFERENCE, pray_csg(k.c, PRAY_DIFFERENCE, one, s), s2));
        REQUIRE(B.ok);
        std::vector<Hit> h = B.hits(r);
        REQUIRE(h.size() == 2);
        CHECK(h[0].t == 4);  // leaving all-space-minus-spheres at the first sphere
        CHECK(h[0].root_enter == 0);
        CHECK(h[1].t == 6.5);
        CHECK(h[1].root_enter == 1);
        TScene B2(k.c, pray_complement(k.c, none));
        CHECK(B2.s.root == E_ALL);
        CHECK(B2.hits(r).empty());
    }
}

TEST_CASE("box_exit: the same float as ray_box's exit for rays that start in the box, on its faces and corners too") {
    // The walk takes a ray that starts in the grid's box out of it with box_exit instead of
    // ray_box; the voxels it steps through end there, so the two must agree bit for bit.
    int checked = 0, on_face = 0, parallel = 0;
    for (uint64_t seed = 1; seed <= 4000; seed++) {
        CAPTURE(seed);
        TRng g(seed * 104729ull);
        real lo[3], hi[3];
        for (int l = 0; l < 3; l++) {
            lo[l] = (real)g.uni(-50, 50);
            hi[l] = lo[l] + (real)(g.below(8) == 0 ? 0 : g.uni(1e-3, 80));  // some boxes flat
        }
        double o[3], d[3];
        g.dir(d);
        bool face = false;
        for (int l = 0; l < 3; l++) {
            int k = g.below(6);  // on the low face, the high face, or between
            o[l] = k == 0 ? (double)lo[l] : k == 1 ? (double)hi[l] : (double)lo[l] + ((double)hi[l] - (double)lo[l]) * g.u01();
            face = face || k < 2;
            if (g.below(5) == 0) d[l] = 0;  // along a face
            else if (g.below(9) == 0) d[l] *= 1e-300;  // so nearly parallel that 1 / d overflows
        }
        if (d[0] == 0 && d[1] == 0 && d[2] == 0) d[seed % 3] = 1;
        Ray r;
        r.o = r3((real)o[0], (real)o[1], (real)o[2]);
        r.d = r3((real)d[0], (real)d[1], (real)d[2]);
        if (!in_box(r.o, lo, hi)) continue;  // (rounded out of a flat box's face)
        real inv[3], t0 = 0, t1 = 0;
        ray_inverse(r, inv);
        REQUIRE(ray_box(r, inv, lo, hi, &t0, &t1));
        CHECK(t0 <= 0);
        real e = box_exit(r, inv, lo, hi);
        CHECK(memcmp(&e, &t1, sizeof e) == 0);
        checked++;
        on_face += face;
        parallel += inv[0] == 0 || inv[1] == 0 || inv[2] == 0;
    }
    CHECK(checked > 3500);
    CHECK(on_face > 1000);
    CHECK(parallel > 1000);
    // a point outside, or not a number, is in no box
    real lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
    CHECK(in_box(r3(1, 1, 1), lo, hi));
    CHECK_FALSE(in_box(r3(1, 1, (real)1.0001), lo, hi));
    CHECK_FALSE(in_box(r3(0, (real)NAN, 0), lo, hi));
}

TEST_CASE("reach: every voxel's cube of its list, exactly as large as it can be (against counting)") {
    // Random grids of boxes of lists: the reach of each voxel is compared with a direct search,
    // the largest r such that every voxel within chessboard distance r (inside the grid) has
    // the voxel's list.
    pray_ctx *c = pray_new();
    for (uint64_t seed = 1; seed <= 40; seed++) {
        CAPTURE(seed);
        TRng g(seed * 7919ull);
        Grid a;
        memset(&a, 0, sizeof a);
        for (int l = 0; l < 3; l++) a.n[l] = 1 + g.below(seed % 4 == 0 ? 28 : 14);
        long nv = (long)a.n[0] * a.n[1] * a.n[2];
        std::vector<int> lists((size_t)nv, 0);
        int boxes = g.below(6);  // 0: one list everywhere
        for (int b = 0; b < boxes; b++) {
            int lo[3], hi[3];
            for (int l = 0; l < 3; l++) {
                lo[l] = g.below(a.n[l]);
                hi[l] = lo[l] + g.below(a.n[l] - lo[l]);
            }
            int L = 1 + g.below(3);
            for (int z = lo[2]; z <= hi[2]; z++)
                for (int y = lo[1]; y <= hi[1]; y++)
                    for (int x = lo[0]; x <= hi[0]; x++) lists[((size_t)z * a.n[1] + y) * a.n[0] + x] = L;
        }
        a.voxel = lists.data();
        REQUIRE(reach_build(c, &a));
        long wrong = 0;
        for (int z = 0; z < a.n[2]; z++)
            for (int y = 0; y < a.n[1]; y++)
                for (int x = 0; x < a.n[0]; x++) {
                    long v = ((long)z * a.n[1] + y) * a.n[0] + x;
                    int r = 0;  // grow the cube while it holds only this list: look at its new shell
                    for (bool same = true; same && r < 255;) {
                        int q = r + 1;
                        for (int dz = -q; dz <= q && same; dz++)
                            for (int dy = -q; dy <= q && same; dy++)
                                for (int dx = -q; dx <= q && same; dx += dz == -q || dz == q || dy == -q || dy == q ? 1 : 2 * q) {
                                    int u[3] = {x + dx, y + dy, z + dz};
                                    if (u[0] < 0 || u[1] < 0 || u[2] < 0 || u[0] >= a.n[0] || u[1] >= a.n[1] || u[2] >= a.n[2])
                                        continue;
                                    same = lists[((size_t)u[2] * a.n[1] + u[1]) * a.n[0] + u[0]] == lists[(size_t)v];
                                }
                        if (same) r = q;
                        if (q > a.n[0] && q > a.n[1] && q > a.n[2]) break;  // the whole grid: one list
                    }
                    bool whole = r >= a.n[0] && r >= a.n[1] && r >= a.n[2];
                    if (whole ? a.reach[v] < r : a.reach[v] != r) wrong++;
                }
        CHECK(wrong == 0);
        mem_free(c, a.reach);
    }
    pray_free(c);
}

TEST_CASE("blocker_of: the shadow cache's box holds the point, and the list it keeps holds in all of the box") {
    // A floor and a cluster of small balls in one voxel of a coarse grid, which gets a grid of
    // its own. The cache evaluates the kept list on any ray's stretch through the kept box, so
    // at every point of that box the deepest voxel (found here by plain arithmetic) must have
    // that list; a point where no voxel's list holds (outside the grid, or in the rest of a
    // voxel around its nested grid's box) keeps nothing.
    TCtx k;
    pray_ctx *c = k.c;
    REQUIRE(pray_option(c, "grid", 2) == PRAY_OK);
    REQUIRE(pray_option(c, "width", 256) == PRAY_OK);
    REQUIRE(pray_option(c, "height", 256) == PRAY_OK);
    pray_model *m = k.mat(1);
    pray_object *all = pray_plane(c, m, t_vec(0, 0, -0.6), t_vec(0, 0, 1));
    all = pray_csg(c, PRAY_UNION, all, pray_sphere(c, m, t_vec(3, 3, 3), 0.2));
    TRng g(11);
    for (int i = 0; i < 400; i++)
        all = pray_csg(c, PRAY_UNION, all, pray_sphere(c, m, t_vec(g.uni(0.2, 1), g.uni(0.2, 1), g.uni(0.2, 1)), 0.03));
    TScene B(c, all);
    REQUIRE(B.ok);
    REQUIRE(B.s.accel);
    const Accel *A = B.s.accel;
    REQUIRE(A->nested.n > 0);  // (setup)
    auto list_at = [&](const double *q) {  // the deepest voxel's list at q; -1: none
        const Grid *G = &A->g;
        for (;;) {
            int ix[3];
            for (int l = 0; l < 3; l++) {
                double v = (q[l] - (double)G->org[l]) / (double)G->h;
                if (!(v >= 0 && v < G->n[l])) return -1;
                ix[l] = (int)floor(v);
            }
            int L = G->voxel[((long)ix[2] * G->n[1] + ix[1]) * G->n[0] + ix[0]];
            if (L >= 0) return L;
            G = &A->nested[-1 - L];
        }
    };
    int kept = 0, deep = 0, wrong = 0;
    for (int i = 0; i < 3000; i++) {
        double p[3];
        for (int l = 0; l < 3; l++)  // half in the cluster, half anywhere around the scene
            p[l] = i % 2 ? g.uni(0.15, 1.05) : g.uni((double)A->g.org[l] - 1, (double)A->g.top[l] + 1);
        Blocker bk;
        int want = list_at(p);
        if (!blocker_of(A, r3((real)p[0], (real)p[1], (real)p[2]), &bk)) {
            wrong += want >= 0;
            continue;
        }
        kept++;
        deep += bk.hi[0] - bk.lo[0] < A->g.h;
        bool in = bk.list == want;
        for (int l = 0; l < 3; l++) in = in && bk.lo[l] <= p[l] && p[l] <= bk.hi[l];
        for (int j = 0; in && j < 20; j++) {
            double q[3];
            for (int l = 0; l < 3; l++) q[l] = (double)bk.lo[l] + (double)(bk.hi[l] - bk.lo[l]) * g.uni(0.001, 0.999);
            in = list_at(q) == bk.list;
        }
        wrong += !in;
    }
    CHECK(kept > 1000);  // (setup)
    CHECK(deep > 500);   // (setup: points in the nested grid)
    CHECK(wrong == 0);
}

TEST_CASE("texture pyramid: the range over texels holds every value a lookup between the coordinates takes") {
    pray_ctx *c = pray_new();
    for (uint64_t seed = 1; seed <= 30; seed++) {
        CAPTURE(seed);
        TRng g(seed * 104729ull);
        pray_texture tx;
        memset(&tx, 0, sizeof tx);
        tx.w = 1 + g.below(seed % 3 == 0 ? 70 : 17);
        tx.hgt = 1 + g.below(seed % 3 == 1 ? 70 : 17);
        std::vector<float> rgb((size_t)tx.w * tx.hgt * 3);
        for (size_t i = 0; i < rgb.size(); i++) rgb[i] = (float)g.u01();
        tx.rgb = rgb.data();
        REQUIRE(tex_pyramid(c, &tx));
        for (int q = 0; q < 200; q++) {
            double s0 = g.uni(-3, 3), t0 = g.uni(-3, 3);
            double s1 = s0 + (q % 4 == 0 ? g.uni(0, 2) : g.uni(0, 0.2)), t1 = t0 + (q % 4 == 1 ? g.uni(0, 2) : g.uni(0, 0.2));
            float mn[3], mx[3];
            tex_spread(&tx, s0, s1, t0, t1, mn, mx);
            // lookups on a fine lattice of the rectangle stay inside the range
            bool inside = true;
            for (int i = 0; i <= 12 && inside; i++)
                for (int j = 0; j <= 12 && inside; j++) {
                    pray_rgb v = tex_lookup(&tx, s0 + (s1 - s0) * i / 12, t0 + (t1 - t0) * j / 12);
                    double ch[3] = {v.r, v.g, v.b};
                    for (int l = 0; l < 3; l++) inside = inside && ch[l] >= mn[l] - 1e-6 && ch[l] <= mx[l] + 1e-6;
                }
            CHECK(inside);
            // and no wider than the texture
            for (int l = 0; l < 3; l++) CHECK((mn[l] >= 0 && mx[l] <= 1));
        }
        // a single texel's neighbourhood at level 0 is exact: the lookup at a texel's centre
        float mn[3], mx[3];
        int x = g.below(tx.w), y = g.below(tx.hgt);
        double s = (x + 0.5) / tx.w, t = (y + 0.5) / tx.hgt;
        tex_spread(&tx, s, s, t, t, mn, mx);
        const float *px = &rgb[((size_t)y * tx.w + x) * 3];
        for (int l = 0; l < 3; l++) CHECK((mn[l] <= px[l] && mx[l] >= px[l]));
        mem_free(c, tx.mm);
    }
    pray_free(c);
}

TEST_CASE("texture lookups are total: coordinates that are not finite numbers read texels, never beyond") {
    pray_ctx *c = pray_new();
    pray_texture tx;
    memset(&tx, 0, sizeof tx);
    tx.w = 3;
    tx.hgt = 5;
    std::vector<float> rgb((size_t)tx.w * tx.hgt * 3);
    for (size_t i = 0; i < rgb.size(); i++) rgb[i] = (float)(0.1 + 0.8 * (double)i / rgb.size());
    tx.rgb = rgb.data();
    REQUIRE(tex_pyramid(c, &tx));
    const double odd[] = {NAN, -NAN, INFINITY, -INFINITY, 1e308, -1e308, 1e300, -1e-20, 1 - 1e-17, 0, 2.5};
    for (double s : odd)
        for (double t : odd) {
            CAPTURE(s);
            CAPTURE(t);
            pray_rgb v = tex_lookup(&tx, s, t);
            double ch[3] = {v.r, v.g, v.b};
            for (int l = 0; l < 3; l++) CHECK((ch[l] >= 0.1 - 1e-6 && ch[l] <= 0.9 + 1e-6));
            double ss[4] = {s, s, s, s}, tt[4] = {t, t, t, t};
            (void)tex_beyond(&tx, ss, tt, 4, 0.5, 0.01);  // the range of a cell: no crash under the sanitizers
        }
    // a coordinate that is not a number reads as 0: the same as the lookup at 0
    pray_rgb a = tex_lookup(&tx, NAN, INFINITY), b = tex_lookup(&tx, 0, 0);
    CHECK((a.r == b.r && a.g == b.g && a.b == b.b));
    mem_free(c, tx.mm);
    pray_free(c);
}
