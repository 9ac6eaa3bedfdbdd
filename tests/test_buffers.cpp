// Rendering into the caller's buffers (pray_render_into), per-pixel outputs, the camera's rays,
// and textures from the host (pray_texture_rgb, pray_texture_register):
//   - a rectangle of the image is bit for bit the same pixels of pray_render's whole image,
//     under antialias, undersampling (whose tiles the rectangle cuts), threads and brute, in a
//     scene with shadows, a mirror, CSG and a texture; a stride leaves the gaps untouched;
//   - primitive, depth and normal are pray_intersect's first hit on pray_camera_ray's ray
//     through the pixel's centre; bad rectangles and buffers are refused with a message;
//   - a registered texture renders as the same image read from a TIFF file, also in untrusted
//     mode; registering again replaces, NULL removes; unregistered names are still files.
// Built with -DPRAY_NO_STDIO (see the case at the end) registered textures work without files.
#include <doctest/doctest.h>

#include "testkit.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include <sys/stat.h>

namespace {

pray_vec P3(double x, double y, double z) {
    pray_vec v;
    v.x = x;
    v.y = y;
    v.z = z;
    return v;
}
pray_rgb C3(double r, double g, double b) {
    pray_rgb c;
    c.r = r;
    c.g = g;
    c.b = b;
    return c;
}

struct Ctx {
    pray_ctx *c;
    Ctx() : c(pray_new()) {}
    ~Ctx() { pray_free(c); }
    Ctx(const Ctx &) = delete;
    Ctx &operator=(const Ctx &) = delete;
    operator pray_ctx *() const { return c; }
};

bool contains(const std::string &s, const std::string &part) { return s.find(part) != std::string::npos; }

// An n x n checker of two colours (green at half), values k / 255 (so that an 8-bit TIFF holds
// them exactly).
std::vector<float> checker(int n, float a, float b) {
    std::vector<float> px((size_t)n * n * 3);
    for (int y = 0; y < n; y++)
        for (int x = 0; x < n; x++)
            for (int k = 0; k < 3; k++)
                px[((size_t)y * n + x) * 3 + k] = ((x + y) % 2 ? a : b) * (k == 1 ? 0.5f : 1.0f);
    for (float &v : px) v = (float)(std::lround(v * 255) / 255.0);
    return px;
}

// A scene with something of everything the colour depends on: a textured floor (a host
// texture), a CSG solid, a mirror ball, shadows from two lights; and the background at the top.
struct Scene {
    pray_object *root = nullptr;
    pray_light *lights = nullptr;
    void build(pray_ctx *c) {
        std::vector<float> px = checker(8, 0.9f, 0.1f);
        pray_texture *t = pray_texture_rgb(c, 8, 8, px.data(), "checker");
        REQUIRE(t);
        pray_model *dark = pray_phong(c, C3(0.1, 0.1, 0.1), C3(0.2, 0.2, 0.2), C3(0.05, 0.05, 0.05), 10);
        pray_model *light = pray_phong(c, C3(0.9, 0.8, 0.6), C3(0.2, 0.2, 0.2), C3(0.05, 0.05, 0.05), 10);
        pray_model *tex = pray_tiff(c, dark, light, t);
        pray_model *red = pray_phong(c, C3(0.8, 0.1, 0.1), C3(0.5, 0.5, 0.5), C3(0.1, 0, 0), 20);
        pray_model *mir = pray_mirror(c, C3(0.7, 0.7, 0.7));
        pray_object *floor = pray_planemap(c, tex, P3(0, 0, -1), P3(0, 0, 1), P3(0.5, 0, 0), P3(0, 0.5, 0));
        pray_object *ball = pray_sphere(c, red, P3(-0.6, 0, -0.3), 0.7);
        pray_object *cut = pray_cylinder(c, red, P3(-0.6, 0, 0), P3(0, 1, 0), 0.3);
        pray_object *solid = pray_csg(c, PRAY_DIFFERENCE, ball, cut);
        pray_object *mball = pray_sphere(c, mir, P3(0.8, 0.5, -0.5), 0.5);
        pray_object *both = pray_csg(c, PRAY_UNION, solid, mball);
        root = pray_csg(c, PRAY_UNION, floor, both);
        REQUIRE(root);
        pray_light *a = pray_dirlight(c, C3(0.7, 0.7, 0.7), P3(1, 2, -2));
        pray_light *b = pray_pointlight(c, C3(0.4, 0.4, 0.5), P3(-2, -3, 2));
        lights = pray_light_add(c, a, b);
        REQUIRE(lights);
        for (void *h : {(void *)t, (void *)dark, (void *)light, (void *)tex, (void *)red, (void *)mir, (void *)floor,
                        (void *)ball, (void *)cut, (void *)solid, (void *)mball, (void *)both, (void *)a, (void *)b})
            pray_release(c, h);
        REQUIRE(pray_perspective(c, P3(1, 0, 0), P3(0, 0, -1), P3(0, -4, 0.5), P3(0, 0, -0.2)) == PRAY_OK);
        REQUIRE(pray_background(c, C3(0.2, 0.3, 0.6), C3(0.9, 0.9, 1)) == PRAY_OK);
    }
};

const int W = 100, H = 70;

// The last progress reported, and how often it went back.
struct Progress {
    int done = 0, total = 0, calls = 0, backwards = 0;
};
int on_progress(void *ud, int done, int total) {
    Progress &p = *static_cast<Progress *>(ud);
    p.backwards += done < p.done;
    p.done = done;
    p.total = total;
    p.calls++;
    return 0;
}

// pray_render's image with the settings given as name=value pairs.
std::vector<float> whole(pray_ctx *c, const Scene &s) {
    pray_image img;
    REQUIRE_MESSAGE(pray_render(c, s.root, s.lights, &img) == PRAY_OK, pray_error(c));
    REQUIRE(img.width == W);
    REQUIRE(img.height == H);
    std::vector<float> v(img.pixels, img.pixels + (size_t)W * H * 3);
    pray_image_free(c, &img);
    return v;
}

} // namespace

TEST_CASE("pray_render_into: rectangles are bit for bit the pixels of the whole image, in every setting") {
    struct Setting {
        const char *name;
        double aa, adaptive, threads, brute;
    };
    const Setting settings[] = {
        {"plain", 1, 0, 1, 0},          {"antialias 2", 2, 0, 1, 0},         {"adaptive", 1, 0.05, 1, 0},
        {"adaptive, 2 threads", 1, 0.05, 2, 0}, {"antialias 2, adaptive", 2, 0.02, 2, 0},
        {"antialias 3, adaptive", 3, 0.02, 1, 0}, {"brute", 1, 0, 2, 1}, {"brute, adaptive", 2, 0.05, 1, 1},
    };
    // edges, corners, odd sizes, single pixels, and rectangles that start inside a tile of
    // undersampling (64 samples a side: 64, 32 or 21 pixels), on its first column (whose samples
    // the tile before hands on), or across bands
    const pray_rect rects[] = {{0, 0, W, H},  {0, 0, 1, 1},   {W - 1, H - 1, 1, 1}, {37, 23, 1, 1}, {3, 5, 7, 9},
                               {0, 10, W, 3}, {W - 13, 0, 13, H}, {17, 17, 33, 31}, {70, 40, 29, 29}, {65, 63, 1, 7},
                               {33, 21, 31, 43}, {64, 3, 20, 60}, {32, 30, 40, 20}, {42, 0, 5, H}, {63, 10, 2, 2},
                               {84, 1, 16, 50}};
    Ctx c;
    Scene s;
    s.build(c);
    pray_option(c, "width", W);
    pray_option(c, "height", H);
    for (const Setting &st : settings) {
        CAPTURE(st.name);
        pray_option(c, "antialias", st.aa);
        pray_option(c, "adaptive", st.adaptive);
        pray_option(c, "threads", st.threads);
        pray_option(c, "brute", st.brute);
        pray_stats before, after;
        pray_stats_get(c, &before);
        std::vector<float> full = whole(c, s);
        pray_stats_get(c, &after);
        if (st.adaptive > 0) {  // undersampling interpolates somewhere: the test means something
            CHECK(after.rays_primary - before.rays_primary < after.rays_primary_full - before.rays_primary_full);
        }
        for (const pray_rect &r : rects) {
            CAPTURE(r.x);
            CAPTURE(r.y);
            CAPTURE(r.width);
            CAPTURE(r.height);
            std::vector<float> part((size_t)r.width * r.height * 3, -1.0f);
            pray_buffers b = {part.data(), nullptr, nullptr, nullptr, 0, nullptr, nullptr, 0};
            REQUIRE_MESSAGE(pray_render_into(c, s.root, s.lights, &r, &b) == PRAY_OK, pray_error(c));
            int bad = 0;
            for (int y = 0; y < r.height; y++)
                for (int x = 0; x < r.width; x++)
                    bad += std::memcmp(&part[((size_t)y * r.width + x) * 3],
                                       &full[((size_t)(r.y + y) * W + r.x + x) * 3], 3 * sizeof(float)) != 0;
            CHECK(bad == 0);
        }
        // rect NULL: the whole image
        std::vector<float> all((size_t)W * H * 3);
        pray_buffers b = {all.data(), nullptr, nullptr, nullptr, 0, nullptr, nullptr, 0};
        REQUIRE(pray_render_into(c, s.root, s.lights, nullptr, &b) == PRAY_OK);
        CHECK(std::memcmp(all.data(), full.data(), all.size() * sizeof(float)) == 0);
    }
    pray_release(c, s.root);
    pray_release(c, s.lights);
}

TEST_CASE("pray_render_into: a stride leaves the gaps between rows untouched") {
    Ctx c;
    Scene s;
    s.build(c);
    pray_option(c, "width", W);
    pray_option(c, "height", H);
    pray_option(c, "adaptive", 0.05);
    std::vector<float> full = whole(c, s);
    const pray_rect r = {11, 7, 21, 13};
    const size_t stride = 29;
    const float mark = -123.5f;
    std::vector<float> rgb(stride * r.height * 3, mark), depth(stride * r.height, mark),
        normal(stride * r.height * 3, mark);
    std::vector<int> prim(stride * r.height, -77);
    pray_buffers b = {rgb.data(), prim.data(), depth.data(), normal.data(), stride, nullptr, nullptr, 0};
    Progress p;
    pray_set_progress(c, on_progress, &p);
    REQUIRE_MESSAGE(pray_render_into(c, s.root, s.lights, &r, &b) == PRAY_OK, pray_error(c));
    // progress counts the rectangle's rows: bands of 64 rows (undersampling) from row 0, so 1 call
    CHECK(p.calls == 1);
    CHECK(p.done == r.height);
    CHECK(p.total == r.height);
    CHECK(p.backwards == 0);
    int bad = 0, gaps = 0;
    for (int y = 0; y < r.height; y++)
        for (size_t x = 0; x < stride; x++) {
            size_t at = y * stride + x;
            if ((int)x < r.width) {
                bad += std::memcmp(&rgb[at * 3], &full[((size_t)(r.y + y) * W + r.x + x) * 3], 3 * sizeof(float)) != 0;
                bad += prim[at] == -77 || depth[at] == mark || normal[at * 3] == mark;
            } else {
                gaps += rgb[at * 3] != mark || rgb[at * 3 + 1] != mark || rgb[at * 3 + 2] != mark;
                gaps += prim[at] != -77 || depth[at] != mark;
                gaps += normal[at * 3] != mark || normal[at * 3 + 1] != mark || normal[at * 3 + 2] != mark;
            }
        }
    CHECK(bad == 0);
    CHECK(gaps == 0);
    pray_release(c, s.root);
    pray_release(c, s.lights);
}

TEST_CASE("pray_render_into: primitive, depth and normal are pray_intersect's first hit on pray_camera_ray's ray") {
    for (int parallel = 0; parallel < 2; parallel++) {
        CAPTURE(parallel);
        Ctx c;
        Scene s;
        s.build(c);
        if (parallel)
            REQUIRE(pray_parallel(c, P3(2.5, 0, 0), P3(0, 0, -1.8), P3(0, -4, 0), P3(0, 0, 0)) == PRAY_OK);
        pray_option(c, "width", W);
        pray_option(c, "height", H);
        pray_option(c, "antialias", 2);  // the colour's samples are not the centre's ray
        pray_option(c, "adaptive", 0.05);
        pray_option(c, "threads", 2);
        std::vector<int> prim((size_t)W * H);
        std::vector<float> depth((size_t)W * H), normal((size_t)W * H * 3);
        pray_buffers b = {nullptr, prim.data(), depth.data(), normal.data(), 0, nullptr, nullptr, 0};
        REQUIRE_MESSAGE(pray_render_into(c, s.root, s.lights, nullptr, &b) == PRAY_OK, pray_error(c));
        pray_scene *q = pray_prepare(c, s.root);
        REQUIRE(q);
        int bad = 0, background = 0, seen[5] = {0, 0, 0, 0, 0};
        for (int y = 0; y < H; y++)
            for (int x = 0; x < W; x++) {
                pray_vec o, d;
                REQUIRE(pray_camera_ray(c, x + 0.5, y + 0.5, &o, &d) == PRAY_OK);
                pray_hit h[1];
                int n = pray_intersect(c, q, o, d, HUGE_VAL, h, 1);
                REQUIRE(n >= 0);
                size_t at = (size_t)y * W + x;
                if (n == 0) {
                    background++;
                    bad += prim[at] != -1 || !(std::isinf(depth[at]) && depth[at] > 0);
                    bad += normal[at * 3] != 0 || normal[at * 3 + 1] != 0 || normal[at * 3 + 2] != 0;
                } else {
                    if (h[0].primitive >= 0 && h[0].primitive < 5) seen[h[0].primitive]++;
                    bad += prim[at] != h[0].primitive || depth[at] != (float)h[0].t;
                    bad += normal[at * 3] != (float)h[0].normal.x || normal[at * 3 + 1] != (float)h[0].normal.y ||
                           normal[at * 3 + 2] != (float)h[0].normal.z;
                }
                if (bad && bad < 3) FAIL_CHECK("pixel " << x << ", " << y);
            }
        CHECK(bad == 0);
        // the view holds the background, the floor (0), the ball (1), the hole cut in it (2) and the
        // mirror (3); the parallel one looks along the floor and through the hole
        CHECK(background > 100);
        CHECK(seen[0] > (parallel ? -1 : 100));
        CHECK(seen[1] > 100);
        CHECK(seen[2] > (parallel ? -1 : 0));
        CHECK(seen[3] > 50);
        // only the primitives: no colour traced
        pray_stats st0, st1;
        pray_stats_get(c, &st0);
        std::vector<int> prim2((size_t)W * H);
        pray_buffers b2 = {nullptr, prim2.data(), nullptr, nullptr, 0, nullptr, nullptr, 0};
        REQUIRE(pray_render_into(c, s.root, s.lights, nullptr, &b2) == PRAY_OK);
        pray_stats_get(c, &st1);
        CHECK(prim2 == prim);
        CHECK(st1.rays_primary == st0.rays_primary);
        CHECK(st1.rays_shadow == st0.rays_shadow);
        pray_scene_free(c, q);
        pray_release(c, s.root);
        pray_release(c, s.lights);
    }
}

TEST_CASE("pray_camera_ray: the rays of pixel centres, as documented for the perspective camera") {
    // the default camera: eye [0, -4, 0] looking at the origin, X = <1, 0, 0>, Y = <0, 0, -1>
    // (rows grow downwards); the ray of image point (px, py) goes to P + uX + vY with
    // u = 2 px / W - 1, v = 2 py / H - 1
    Ctx c;
    pray_option(c, "width", 40);
    pray_option(c, "height", 20);
    pray_vec o, d;
    REQUIRE(pray_camera_ray(c, 20, 10, &o, &d) == PRAY_OK);
    CHECK(o.x == 0);
    CHECK(o.y == -4);
    CHECK(o.z == 0);
    CHECK(d.x == 0);
    CHECK(d.y == 1);
    CHECK(d.z == 0);
    REQUIRE(pray_camera_ray(c, 30, 0, &o, &d) == PRAY_OK);  // u = 0.5, v = -1: towards [0.5, 0, 1]
    double len = std::sqrt(0.25 + 16 + 1);
    CHECK(d.x == doctest::Approx(0.5 / len).epsilon(1e-6));  // (to float precision: PRAY_REAL=float)
    CHECK(d.y == doctest::Approx(4 / len).epsilon(1e-6));
    CHECK(d.z == doctest::Approx(1 / len).epsilon(1e-6));
    CHECK(pray_camera_ray(c, NAN, 0, &o, &d) == PRAY_ERR_ARG);
    CHECK(contains(pray_error(c), "not finite"));
    CHECK(pray_camera_ray(c, 0, 0, nullptr, &d) == PRAY_ERR_ARG);
    CHECK(pray_camera_ray(nullptr, 0, 0, &o, &d) == PRAY_ERR_ARG);
}

TEST_CASE("pray_render_into: bad rectangles, strides and buffers are refused with a message") {
    Ctx c;
    pray_option(c, "width", 20);
    pray_option(c, "height", 10);
    pray_object *o = pray_sphere(c, pray_color(c, C3(1, 0, 0)), P3(0, 0, 0), 1);
    REQUIRE(o);
    std::vector<float> rgb(20 * 10 * 3);
    pray_buffers b = {rgb.data(), nullptr, nullptr, nullptr, 0, nullptr, nullptr, 0};
    const pray_rect bad[] = {{-1, 0, 2, 2}, {0, -1, 2, 2}, {0, 0, 0, 2}, {0, 0, 2, 0}, {19, 0, 2, 1},
                             {0, 9, 1, 2},  {0, 0, 21, 10}, {5, 5, -3, 2}, {2147483647, 0, 1, 1}, {1, 1, 2147483647, 1}};
    for (const pray_rect &r : bad) {
        CAPTURE(r.x);
        CAPTURE(r.y);
        CAPTURE(r.width);
        CAPTURE(r.height);
        CHECK(pray_render_into(c, o, nullptr, &r, &b) == PRAY_ERR_ARG);
        CHECK(contains(pray_error(c), "is not inside the image of 20 x 10"));
    }
    pray_rect r = {2, 2, 5, 3};
    pray_buffers narrow = {rgb.data(), nullptr, nullptr, nullptr, 4, nullptr, nullptr, 0};
    CHECK(pray_render_into(c, o, nullptr, &r, &narrow) == PRAY_ERR_ARG);
    CHECK(std::string(pray_error(c)) == "error: pray_render_into: the stride 4 is less than the rectangle's width 5");
    pray_buffers none = {nullptr, nullptr, nullptr, nullptr, 0, nullptr, nullptr, 0};
    CHECK(pray_render_into(c, o, nullptr, &r, &none) == PRAY_ERR_ARG);
    CHECK(std::string(pray_error(c)) == "error: pray_render_into: every buffer is NULL");
    CHECK(pray_render_into(c, o, nullptr, &r, nullptr) == PRAY_ERR_ARG);
    CHECK(std::string(pray_error(c)) == "error: pray_render_into: no buffers");
    CHECK(pray_render_into(nullptr, o, nullptr, &r, &b) == PRAY_ERR_ARG);
    pray_clear_error(c);
    CHECK(pray_render_into(c, nullptr, nullptr, &r, &b) == PRAY_ERR_ARG);
    CHECK(std::string(pray_error(c)) == "error: no object to render");
    // the image's own limits hold as for pray_render
    pray_option(c, "maxpixels", 100);
    CHECK(pray_render_into(c, o, nullptr, &r, &b) == PRAY_ERR_LIMIT);
    CHECK(contains(pray_error(c), "option maxpixels"));
    pray_option(c, "maxpixels", 1e6);
    // the render's own memory comes from the context, under its cap
    pray_set_memory_limit(c, 1);
    CHECK(pray_render_into(c, o, nullptr, &r, &b) == PRAY_ERR_NOMEM);
    CHECK(contains(pray_error(c), "out of memory"));
    pray_set_memory_limit(c, 0);
    // a good call after the bad ones: the sphere's red where it is, 1 x 1
    pray_rect one = {10, 5, 1, 1};
    CHECK(pray_render_into(c, o, nullptr, &one, &b) == PRAY_OK);
    CHECK(rgb[0] == 1.0f);
    CHECK(rgb[1] == 0.0f);
    // flags other than PRAY_BUFFERS_SAMPLES
    b.flags = 2;
    CHECK(pray_render_into(c, o, nullptr, &one, &b) == PRAY_ERR_ARG);
    CHECK(std::string(pray_error(c)) == "error: pray_render_into: unknown flags 0x2");
    pray_release(c, o);
}

// ---------------------------------------------------------------------------------------------
// The host's ids of objects, albedo, outputs that follow the samples
// ---------------------------------------------------------------------------------------------
TEST_CASE("pray_object_set_id: the innermost id around a primitive, in pray_hit and in the id buffer") {
    Ctx c;
    pray_option(c, "width", W);
    pray_option(c, "height", H);
    pray_option(c, "antialias", 2);
    pray_option(c, "threads", 2);
    // the scene of the other cases, with ids: the floor 10, the cut ball 20 around its hole's 21;
    // the mirror ball has none
    pray_model *red = pray_phong(c, C3(0.8, 0.1, 0.1), C3(0.5, 0.5, 0.5), C3(0.1, 0, 0), 20);
    pray_object *floor = pray_plane(c, red, P3(0, 0, -1), P3(0, 0, 1));
    pray_object *ball = pray_sphere(c, red, P3(-0.6, 0, -0.3), 0.7);
    pray_object *cut = pray_cylinder(c, red, P3(-0.6, 0, 0), P3(0, 1, 0), 0.3);
    pray_object *solid = pray_csg(c, PRAY_DIFFERENCE, ball, cut);
    pray_object *mball = pray_sphere(c, pray_mirror(c, C3(0.7, 0.7, 0.7)), P3(0.8, 0.5, -0.5), 0.5);
    pray_object *root = pray_csg(c, PRAY_UNION, floor, pray_csg(c, PRAY_UNION, solid, mball));
    REQUIRE(root);
    CHECK(pray_object_id(floor) == PRAY_NO_ID);
    CHECK(pray_object_id(nullptr) == PRAY_NO_ID);
    REQUIRE(pray_object_set_id(c, floor, 10) == PRAY_OK);
    REQUIRE(pray_object_set_id(c, solid, 20) == PRAY_OK);
    REQUIRE(pray_object_set_id(c, cut, 21) == PRAY_OK);
    CHECK(pray_object_id(solid) == 20);
    CHECK(pray_object_set_id(c, cut, -3) == PRAY_ERR_ARG);
    CHECK(contains(pray_error(c), "pray_object_set_id: an id must be >= 0 or PRAY_NO_ID, not -3"));
    CHECK(pray_object_id(cut) == 21);
    CHECK(pray_object_set_id(c, nullptr, 1) == PRAY_ERR_ARG);
    REQUIRE(pray_perspective(c, P3(1, 0, 0), P3(0, 0, -1), P3(0, -4, 0.5), P3(0, 0, -0.2)) == PRAY_OK);
    const int expect[4] = {10, 20, 21, PRAY_NO_ID};  // by primitive, in declared order
    std::vector<int> prim((size_t)W * H), id((size_t)W * H);
    pray_buffers b = {nullptr, prim.data(), nullptr, nullptr, 0, id.data(), nullptr, 0};
    REQUIRE_MESSAGE(pray_render_into(c, root, nullptr, nullptr, &b) == PRAY_OK, pray_error(c));
    pray_scene *q = pray_prepare(c, root);
    REQUIRE(q);
    int bad = 0, seen[4] = {0, 0, 0, 0}, background = 0;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            pray_vec o, d;
            REQUIRE(pray_camera_ray(c, x + 0.5, y + 0.5, &o, &d) == PRAY_OK);
            pray_hit h[1];
            int n = pray_intersect(c, q, o, d, HUGE_VAL, h, 1);
            size_t at = (size_t)y * W + x;
            if (n == 0) {
                background++;
                bad += id[at] != -1;
                continue;
            }
            REQUIRE(h[0].primitive >= 0);
            REQUIRE(h[0].primitive < 4);
            seen[h[0].primitive]++;
            bad += h[0].id != expect[h[0].primitive] || id[at] != h[0].id || prim[at] != h[0].primitive;
        }
    CHECK(bad == 0);
    CHECK(background > 100);
    for (int k = 0; k < 4; k++) CHECK(seen[k] > 0);
    pray_scene_free(c, q);
    // an id set later: the kept preparation is made again with it; PRAY_NO_ID removes one
    REQUIRE(pray_object_set_id(c, mball, 30) == PRAY_OK);
    REQUIRE(pray_object_set_id(c, cut, PRAY_NO_ID) == PRAY_OK);
    std::vector<int> id2((size_t)W * H);
    b.primitive = nullptr;
    b.id = id2.data();
    REQUIRE(pray_render_into(c, root, nullptr, nullptr, &b) == PRAY_OK);
    const int expect2[4] = {10, 20, 20, 30};
    int changed = 0;
    bad = 0;
    for (size_t at = 0; at < id2.size(); at++) {
        bad += prim[at] < 0 ? id2[at] != -1 : id2[at] != expect2[prim[at]];
        changed += id2[at] != id[at];
    }
    CHECK(bad == 0);
    CHECK(changed > 50);
    // a scene prepared for rendering gives the same ids, and keeps them when an id changes after
    pray_scene *qr = pray_prepare_render(c, root, nullptr);
    REQUIRE(qr);
    REQUIRE(pray_object_set_id(c, floor, 11) == PRAY_OK);
    std::vector<int> id3((size_t)W * H);
    b.id = id3.data();
    REQUIRE(pray_render_prepared(c, qr, nullptr, &b) == PRAY_OK);
    CHECK(id3 == id2);
    pray_scene_free(c, qr);
    for (void *h : {(void *)red, (void *)floor, (void *)ball, (void *)cut, (void *)solid, (void *)mball, (void *)root})
        pray_release(c, h);
}

TEST_CASE("pray_object_set_id: a union with an id keeps it when more is added; transformations make new objects") {
    Ctx c;
    pray_model *m = pray_color(c, C3(1, 1, 1));
    pray_object *a = pray_sphere(c, m, P3(0, 0, 0), 1), *bb = pray_sphere(c, m, P3(3, 0, 0), 1);
    pray_object *cc = pray_sphere(c, m, P3(6, 0, 0), 1);
    pray_object *ab = pray_csg(c, PRAY_UNION, a, bb);
    REQUIRE(pray_object_set_id(c, ab, 5) == PRAY_OK);
    pray_object *abc = pray_csg(c, PRAY_UNION, ab, cc);
    pray_object *moved = pray_translate(c, ab, P3(0, 0, 10));
    REQUIRE(abc);
    REQUIRE(moved);
    CHECK(pray_object_id(moved) == PRAY_NO_ID);
    pray_scene *q = pray_prepare(c, abc);
    REQUIRE(q);
    const int expect[3] = {5, 5, PRAY_NO_ID};
    for (int k = 0; k < 3; k++) {
        pray_hit h[1];
        REQUIRE(pray_intersect(c, q, P3(3.0 * k, -5, 0), P3(0, 1, 0), HUGE_VAL, h, 1) == 2);
        CHECK(h[0].primitive == k);
        CHECK(h[0].id == expect[k]);
    }
    pray_scene_free(c, q);
    // ids of a program's objects, set by a render function before it renders them
    pray_set_render(c, [](void *, pray_ctx *cx, pray_object *root, pray_light *lights, int, pray_image *out) {
        pray_object_set_id(cx, root, 7);
        int ids[4];
        pray_buffers bf = {nullptr, nullptr, nullptr, nullptr, 0, ids, nullptr, 0};
        pray_rect r = {0, 0, 2, 2};
        pray_status st = pray_render_into(cx, root, lights, &r, &bf);
        out->width = out->height = 0;
        return st == PRAY_OK && ids[0] == 7 ? PRAY_OK : PRAY_ERR_RUNTIME;
    }, nullptr);
    const char prog[] = "option \"width\", 4\noption \"height\", 4\nrendertiff sphere(color({1}), [0, 0, 0], 5), none\n";
    CHECK(pray_run_string(c, "ids.ray", prog, sizeof prog - 1) == PRAY_OK);
    for (void *h : {(void *)m, (void *)a, (void *)bb, (void *)cc, (void *)ab, (void *)abc, (void *)moved})
        pray_release(c, h);
}

TEST_CASE("pray_buffers.albedo: the model's colour, flat or from a texture") {
    Ctx c;
    pray_option(c, "width", 40);
    pray_option(c, "height", 40);
    // a red Phong ball lit from the front, on a flat-coloured textured wall behind it
    // 2 x 2 squares of 2 x 2 texels: between the centres of a square's texels its colour is exact
    std::vector<float> px(4 * 4 * 3);
    for (int y = 0; y < 4; y++)
        for (int x = 0; x < 4; x++)
            for (int k = 0; k < 3; k++) px[(y * 4 + x) * 3 + k] = (x / 2 + y / 2) % 2 ? 0.25f * (k + 1) : 0.9f - 0.3f * k;
    pray_texture *t = pray_texture_rgb(c, 4, 4, px.data(), "squares");
    pray_model *wall = pray_tiff(c, pray_color(c, C3(0, 0, 0)), pray_color(c, C3(1, 1, 1)), t);
    pray_model *red = pray_phong(c, C3(0.8, 0.1, 0.2), C3(0.5, 0.5, 0.5), C3(0.1, 0, 0), 20);
    pray_object *ball = pray_sphere(c, red, P3(0, 0, 0), 0.5);
    // the wall y = 2 facing the eye, 4 x 4 texels across its 40 pixels: texels of 10 pixels
    pray_object *back = pray_planemap(c, wall, P3(-1, 2, -1), P3(0, -1, 0), P3(0.5, 0, 0), P3(0, 0, 0.5));
    pray_object *root = pray_csg(c, PRAY_UNION, ball, back);
    REQUIRE(root);
    REQUIRE(pray_parallel(c, P3(1, 0, 0), P3(0, 0, -1), P3(0, -4, 0), P3(0, 0, 0)) == PRAY_OK);
    std::vector<float> rgb(40 * 40 * 3), albedo(40 * 40 * 3);
    std::vector<int> prim(40 * 40);
    pray_buffers b = {rgb.data(), prim.data(), nullptr, nullptr, 0, nullptr, albedo.data(), 0};
    REQUIRE_MESSAGE(pray_render_into(c, root, pray_dirlight(c, C3(1, 1, 1), P3(0, 1, 0)), nullptr, &b) == PRAY_OK,
                    pray_error(c));
    int on_ball = 0, on_wall = 0, texel = 0, bad = 0;
    for (size_t at = 0; at < prim.size(); at++) {
        const float *a = &albedo[at * 3], *col = &rgb[at * 3];
        if (prim[at] == 0) {  // the ball: its diffuse colour, whatever the light makes of it
            on_ball++;
            bad += a[0] != 0.8f || a[1] != 0.1f || a[2] != 0.2f;
        } else {  // the wall: its colour (unlit: what the image shows), the texture's
            REQUIRE(prim[at] == 1);
            on_wall++;
            bad += a[0] != col[0] || a[1] != col[1] || a[2] != col[2];
            for (size_t k = 0; k < px.size(); k += 3)
                if (a[0] == px[k] && a[1] == px[k + 1] && a[2] == px[k + 2]) {
                    texel++;  // exactly a texel's colour (between texel centres it is a blend)
                    break;
                }
        }
    }
    CHECK(bad == 0);
    CHECK(on_ball > 200);
    CHECK(on_wall > 200);
    CHECK(texel > 100);
    pray_release(c, root);
}

TEST_CASE("PRAY_BUFFERS_SAMPLES: normal and albedo are the means over the samples of pray_camera_ray") {
    Ctx c;
    const int A = 3, N = 24;
    pray_option(c, "width", N);
    pray_option(c, "height", N);
    pray_option(c, "antialias", A);
    pray_object *ball = pray_sphere(c, pray_phong(c, C3(0.8, 0.1, 0.2), C3(0, 0, 0), C3(0, 0, 0), 1), P3(0, 0, 0), 0.7);
    pray_object *floor = pray_plane(c, pray_phong(c, C3(0.2, 0.6, 0.3), C3(0, 0, 0), C3(0, 0, 0), 1), P3(0, 0, -0.6), P3(0, 0, 1));
    pray_object *root = pray_csg(c, PRAY_UNION, ball, floor);
    REQUIRE(root);
    REQUIRE(pray_perspective(c, P3(1, 0, 0), P3(0, 0, -1), P3(0, -4, 0.5), P3(0, 0, -0.2)) == PRAY_OK);
    pray_scene *q = pray_prepare(c, root);
    REQUIRE(q);
    for (int adaptive = 0; adaptive < 2; adaptive++) {
        CAPTURE(adaptive);
        pray_option(c, "adaptive", adaptive ? 0.05 : 0);
        std::vector<float> normal(N * N * 3), albedo(N * N * 3), centre(N * N * 3), depth(N * N), depth0(N * N);
        std::vector<int> id(N * N), id0(N * N);
        pray_buffers b = {nullptr, nullptr, depth.data(), normal.data(), 0, id.data(), albedo.data(), PRAY_BUFFERS_SAMPLES};
        REQUIRE_MESSAGE(pray_render_into(c, root, nullptr, nullptr, &b) == PRAY_OK, pray_error(c));
        pray_buffers b0 = {nullptr, nullptr, depth0.data(), centre.data(), 0, id0.data(), nullptr, 0};
        REQUIRE(pray_render_into(c, root, nullptr, nullptr, &b0) == PRAY_OK);
        CHECK(depth == depth0);  // depth and ids stay the centre's
        CHECK(id == id0);
        int bad = 0, edges = 0;
        for (int y = 0; y < N; y++)
            for (int x = 0; x < N; x++) {
                double n[3] = {0, 0, 0}, al[3] = {0, 0, 0};
                int kinds = 0, last = -2;
                for (int sb = 0; sb < A; sb++)
                    for (int sa = 0; sa < A; sa++) {
                        pray_vec o, d;
                        REQUIRE(pray_camera_ray(c, x + (sa + 0.5) / A, y + (sb + 0.5) / A, &o, &d) == PRAY_OK);
                        pray_hit h[1];
                        int hits = pray_intersect(c, q, o, d, HUGE_VAL, h, 1);
                        int p = hits > 0 ? h[0].primitive : -1;
                        kinds += p != last && last != -2;
                        last = p;
                        if (hits > 0) {
                            n[0] += h[0].normal.x, n[1] += h[0].normal.y, n[2] += h[0].normal.z;
                            static const double diffuse[2][3] = {{0.8, 0.1, 0.2}, {0.2, 0.6, 0.3}};
                            for (int k = 0; k < 3; k++) al[k] += diffuse[p][k];
                        }
                    }
                edges += kinds > 0;
                size_t at = (size_t)y * N + x;
                for (int k = 0; k < 3; k++) {
                    bad += std::fabs(normal[at * 3 + k] - n[k] / (A * A)) > 1e-6;
                    bad += std::fabs(albedo[at * 3 + k] - al[k] / (A * A)) > 1e-6;
                }
                if (bad && bad < 3) FAIL_CHECK("pixel " << x << ", " << y);
            }
        CHECK(bad == 0);
        CHECK(edges > 20);       // pixels whose samples see different things (where the means matter)
        CHECK(normal != centre); // and there the means are not the centre's normal
    }
    pray_scene_free(c, q);
    pray_release(c, root);
}

// ---------------------------------------------------------------------------------------------
// Host textures
// ---------------------------------------------------------------------------------------------
namespace {

// A program that views a planemap textured with `name` head-on, then the image it rendered.
std::string texture_program(const std::string &name) {
    return "option \"width\", 32\noption \"height\", 32\n"
           "parallel <1, 0, 0>, <0, 0, -1>, [0, -4, 0], [0, 0, 0]\n"
           "M = tiff(color({0.1, 0.2, 0.3}), color({1, 0.9, 0.8}), \"" + name + "\")\n"
           "rendertiff planemap(M, [-1, 0, -1], <0, -1, 0>, <0.5, 0, 0>, <0, 0, 0.5>), none\n";
}

// The error of a program that names a texture file that is not there (or, without file access,
// any file).
bool file_error(const std::string &error, const std::string &name) {
#ifdef PRAY_NO_STDIO
    (void)name;
    return contains(error, "this build has no file access");
#else
    return contains(error, "cannot open '" + name + "'");
#endif
}

testkit::Result run_in(pray_ctx *c, const std::string &prog) {
    testkit::Result r;
    pray_set_frame(c, testkit::frame_sink, &r.frames);
    r.status = pray_run_string(c, "scene.ray", prog.data(), prog.size());
    if (r.status != PRAY_OK) r.error = pray_error(c);
    return r;
}

} // namespace

TEST_CASE("pray_texture_rgb: the pixels as given, rows from the top; bad pixels and sizes are refused") {
    Ctx c;
    std::vector<float> px = checker(8, 0.9f, 0.1f);
    px[(2 * 8 + 5) * 3 + 2] = 0.25f;
    pray_texture *t = pray_texture_rgb(c, 8, 8, px.data(), "checker");
    REQUIRE(t);
    int w = 0, h = 0;
    pray_texture_size(t, &w, &h);
    CHECK(w == 8);
    CHECK(h == 8);
    CHECK(pray_texture_pixel(t, 5, 2).b == 0.25);
    CHECK(pray_texture_pixel(t, 0, 0).r == (double)px[0]);
    CHECK(pray_texture_pixel(t, 1, 0).g == (double)px[4]);
    pray_release(c, t);
    CHECK(pray_texture_rgb(c, 8, 8, nullptr, nullptr) == nullptr);
    CHECK(std::string(pray_error(c)) == "error: pray_texture_rgb: no pixels");
    CHECK(pray_texture_rgb(c, 0, 8, px.data(), nullptr) == nullptr);
    CHECK(std::string(pray_error(c)) == "error: pray_texture_rgb: image size 0 x 8 is out of range (1 to 65536 a side)");
    CHECK(pray_texture_rgb(c, 8, 65537, px.data(), nullptr) == nullptr);
    CHECK(pray_last_status(c) == PRAY_ERR_ARG);
    px[(3 * 8 + 1) * 3 + 1] = 1.5f;
    CHECK(pray_texture_rgb(c, 8, 8, px.data(), nullptr) == nullptr);
    CHECK(std::string(pray_error(c)) == "error: pray_texture_rgb: value 1 (pixel 1, 3) is 1.5, not in 0 .. 1");
    px[(3 * 8 + 1) * 3 + 1] = NAN;
    CHECK(pray_texture_rgb(c, 8, 8, px.data(), nullptr) == nullptr);
    CHECK(pray_last_status(c) == PRAY_ERR_ARG);
    pray_option(c, "texmem", 1);  // 1 MiB: 512 x 512 x 12 bytes is 3 MiB
    std::vector<float> big(512 * 512 * 3, 0.5f);
    CHECK(pray_texture_rgb(c, 512, 512, big.data(), nullptr) == nullptr);
    CHECK(pray_last_status(c) == PRAY_ERR_LIMIT);
    CHECK(contains(pray_error(c), "option texmem"));
    CHECK(pray_texture_rgb(nullptr, 8, 8, px.data(), nullptr) == nullptr);
}

TEST_CASE("pray_texture_register: programs find registered names first; replace, remove, untrusted") {
    std::vector<float> px = checker(8, 0.9f, 0.1f), px2 = checker(8, 0.3f, 0.7f);
    Ctx c;
    pray_texture *t = pray_texture_rgb(c, 8, 8, px.data(), "checker");
    pray_texture *t2 = pray_texture_rgb(c, 8, 8, px2.data(), "other");
    REQUIRE(t);
    REQUIRE(t2);
    std::string prog = texture_program("checker");
    // not registered: a file name, and there is no such file
    testkit::Result r0 = run_in(c, prog);
    CHECK(r0.status == PRAY_ERR_RUNTIME);
    CHECK(contains(r0.error, "scene.ray:4:"));
    CHECK(file_error(r0.error, "checker"));
    REQUIRE(pray_texture_register(c, "checker", t) == PRAY_OK);
    pray_release(c, t);  // the context keeps its own reference
    testkit::Result r1 = run_in(c, prog);
    REQUIRE_MESSAGE(r1.status == PRAY_OK, r1.error);
    REQUIRE(r1.frames.size() == 1);
    // the texture is there: a texel to a pixel, the top left pixel differs from the one right of it
    CHECK(r1.frames[0].at(0, 0, 0) != r1.frames[0].at(1, 0, 0));
    testkit::Result again = run_in(c, prog);  // registrations last across runs
    REQUIRE(again.status == PRAY_OK);
    CHECK(again.frames[0].pixels == r1.frames[0].pixels);
    // registering the name again replaces the texture
    REQUIRE(pray_texture_register(c, "checker", t2) == PRAY_OK);
    testkit::Result r2 = run_in(c, prog);
    REQUIRE(r2.status == PRAY_OK);
    CHECK(r2.frames[0].pixels != r1.frames[0].pixels);
    // ... which renders as t2 under its own name
    REQUIRE(pray_texture_register(c, "other name/../with odd parts", t2) == PRAY_OK);
    testkit::Result r3 = run_in(c, texture_program("other name/../with odd parts"));
    REQUIRE_MESSAGE(r3.status == PRAY_OK, r3.error);
    CHECK(r3.frames[0].pixels == r2.frames[0].pixels);
    // exact names only
    testkit::Result r4 = run_in(c, texture_program("Checker"));
    CHECK(r4.status == PRAY_ERR_RUNTIME);
    CHECK(file_error(r4.error, "Checker"));
    // untrusted: a registered name is no file access, whatever it looks like
    REQUIRE(pray_texture_register(c, "/textures/../checker.tif", t2) == PRAY_OK);
    pray_set_untrusted(c);
    testkit::Result r5 = run_in(c, texture_program("/textures/../checker.tif"));
    REQUIRE_MESSAGE(r5.status == PRAY_OK, r5.error);
    CHECK(r5.frames[0].pixels == r2.frames[0].pixels);
    testkit::Result r6 = run_in(c, texture_program("/textures/../unregistered.tif"));
    CHECK(r6.status == PRAY_ERR_RUNTIME);
    CHECK(contains(r6.error, "untrusted program: '/textures/../unregistered.tif' is not a relative name"));
    // removing: NULL; the name is a file name again
    REQUIRE(pray_texture_register(c, "checker", nullptr) == PRAY_OK);
    REQUIRE(pray_texture_register(c, "never registered", nullptr) == PRAY_OK);
    testkit::Result r7 = run_in(c, prog);
    CHECK(r7.status == PRAY_ERR_RUNTIME);
    CHECK(file_error(r7.error, "checker"));
    // bad arguments
    CHECK(pray_texture_register(c, nullptr, t2) == PRAY_ERR_ARG);
    CHECK(std::string(pray_error(c)) == "error: pray_texture_register: no name");
    CHECK(pray_texture_register(c, "", t2) == PRAY_ERR_ARG);
    CHECK(pray_texture_register(nullptr, "x", t2) == PRAY_ERR_ARG);
    pray_release(c, t2);
}

// ---------------------------------------------------------------------------------------------
// Program text from the host for include
// ---------------------------------------------------------------------------------------------
namespace {
const std::string PART = "Ball = sphere(phong({0.8, 0.2, 0.1}, {0.3}, 10), [0, 0, 0.1], 0.5)\n"
                         "L = dirlight({1}, norm(<1, -1, 1>))\n";
std::string main_program(const std::string &part) {
    return "option \"width\", 24\noption \"height\", 16\n" + part + "rendertiff Ball | plane(color({0.2}), "
           "[0, 0, -0.5], <0, 0, 1>), L\n";
}
bool reg(pray_ctx *c, const char *name, const std::string &text) {
    return pray_include_register(c, name, text.data(), text.size()) == PRAY_OK;
}
} // namespace

TEST_CASE("pray_include_register: an include of a registered text renders as the text written in place") {
    testkit::Result inlined;
    {
        Ctx c;
        inlined = run_in(c, main_program(PART));
        REQUIRE_MESSAGE(inlined.status == PRAY_OK, inlined.error);
    }
    Ctx c;
    REQUIRE(reg(c, "parts/ball.ray", PART + "junk past the length"));
    REQUIRE(reg(c, "parts/ball.ray", PART));  // again: replaced
    testkit::Result r = run_in(c, main_program("include \"parts/ball.ray\"\n"));
    REQUIRE_MESSAGE(r.status == PRAY_OK, r.error);
    REQUIRE(r.frames.size() == 1);
    CHECK(r.frames[0].pixels == inlined.frames[0].pixels);
    // an include inside a registered text is looked up the same way
    REQUIRE(reg(c, "outer", "include \"parts/ball.ray\"\n"));
    testkit::Result nested = run_in(c, main_program("include \"outer\"\n"));
    REQUIRE_MESSAGE(nested.status == PRAY_OK, nested.error);
    CHECK(nested.frames[0].pixels == inlined.frames[0].pixels);
    // untrusted: a registered name needs no file access, whatever its form
    pray_set_untrusted(c);
    REQUIRE(reg(c, "../up/ball.ray", PART));
    testkit::Result up = run_in(c, main_program("include \"../up/ball.ray\"\n"));
    REQUIRE_MESSAGE(up.status == PRAY_OK, up.error);
    CHECK(up.frames[0].pixels == inlined.frames[0].pixels);
    // a file it includes is beside its name, which must then keep to the program's directory
    REQUIRE(reg(c, "../up/more.ray", "include \"next.ray\"\n"));
    testkit::Result out = run_in(c, "include \"../up/more.ray\"\n");
    CHECK(out.status == PRAY_ERR_RUNTIME);
#ifdef PRAY_NO_STDIO
    CHECK(contains(out.error, "include: this build has no file access"));
#else
    CHECK(contains(out.error, "untrusted program: '../up/next.ray' is a name with '..'"));
#endif
    // removed: include looks for a file (none here; without file access, none at all)
    REQUIRE(pray_include_register(c, "parts/ball.ray", nullptr, 0) == PRAY_OK);
    REQUIRE(pray_include_register(c, "never registered", nullptr, 0) == PRAY_OK);
    testkit::Result gone = run_in(c, main_program("include \"parts/ball.ray\"\n"));
    CHECK(gone.status == PRAY_ERR_RUNTIME);
    CHECK(contains(gone.error, "scene.ray:3:9: error: "));
    CHECK(pray_include_register(c, "", "x = 1\n", 6) == PRAY_ERR_ARG);
    CHECK(pray_include_register(c, nullptr, "x = 1\n", 6) == PRAY_ERR_ARG);
    CHECK(std::string(pray_error(c)) == "error: pray_include_register: no name");
    CHECK(pray_include_register(nullptr, "a", "x = 1\n", 6) == PRAY_ERR_ARG);
}

TEST_CASE("pray_include_register: errors name the text; the limits of include hold") {
    Ctx c;
    REQUIRE(reg(c, "bad.ray", "x = 1\ny = x / 0\n"));
    testkit::Result r = run_in(c, "a = 1\ninclude \"bad.ray\"\n");
    CHECK(r.status == PRAY_ERR_RUNTIME);
    CHECK(r.error.rfind("bad.ray:2:", 0) == 0);
    CHECK(contains(r.error, "(included from scene.ray:2)"));
    REQUIRE(reg(c, "syntax.ray", "x = (1\n"));
    testkit::Result syn = run_in(c, "include \"syntax.ray\"\n");
    CHECK(syn.status == PRAY_ERR_SYNTAX);
    CHECK(syn.error.rfind("syntax.ray:1:", 0) == 0);
    REQUIRE(reg(c, "loop.ray", "include \"loop.ray\"\n"));
    testkit::Result loop = run_in(c, "include \"loop.ray\"\n");
    CHECK(loop.status == PRAY_ERR_RUNTIME);
    CHECK(contains(loop.error, "'loop.ray' includes itself"));
    // each line read costs a statement (maxsteps); nesting counts against maxnest
    REQUIRE(reg(c, "long.ray", std::string(50, '\n') + "x = 1\n"));
    pray_option_fix(c, "maxsteps", "40");
    testkit::Result steps = run_in(c, "include \"long.ray\"\n");
    CHECK(steps.status == PRAY_ERR_LIMIT);
    CHECK(contains(steps.error, "each line an include reads counts as one"));
    pray_option_fix(c, "maxsteps", "0");
    pray_option_fix(c, "maxnest", "3");
    REQUIRE(reg(c, "n1", "include \"n2\"\n"));
    REQUIRE(reg(c, "n2", "include \"n3\"\n"));
    REQUIRE(reg(c, "n3", "include \"n4\"\n"));
    REQUIRE(reg(c, "n4", "x = 1\n"));
    testkit::Result deep = run_in(c, "include \"n1\"\n");
    CHECK(deep.status == PRAY_ERR_LIMIT);
    CHECK(contains(deep.error, "option maxnest"));
    pray_option_fix(c, "maxline", "20");
    REQUIRE(reg(c, "wide.ray", "x = 1 + 2 + 3 + 4 + 5 + 6\n"));
    testkit::Result wide = run_in(c, "include \"wide.ray\"\n");
    CHECK(wide.status == PRAY_ERR_LIMIT);
    CHECK(wide.error.rfind("wide.ray:1:", 0) == 0);
}

#ifndef PRAY_NO_STDIO
TEST_CASE("pray_include_register: the same bytes as the file; registered names come first") {
    char dir[] = "/tmp/pray_include_XXXXXX";
    REQUIRE(mkdtemp(dir));
    std::string sub = std::string(dir) + "/parts", file = sub + "/ball.ray";
    REQUIRE(mkdir(sub.c_str(), 0700) == 0);
    FILE *f = std::fopen(file.c_str(), "wb");
    REQUIRE(f);
    std::fputs(PART.c_str(), f);
    std::fclose(f);
    std::string prog = main_program("include \"parts/ball.ray\"\n"), name = std::string(dir) + "/scene.ray";
    testkit::Result from_file, from_host, first;
    {
        Ctx c;
        pray_set_frame(c, testkit::frame_sink, &from_file.frames);
        REQUIRE_MESSAGE(pray_run_string(c, name.c_str(), prog.data(), prog.size()) == PRAY_OK, pray_error(c));
    }
    {
        Ctx c;
        REQUIRE(reg(c, "parts/ball.ray", PART));
        from_host = run_in(c, prog);
        REQUIRE_MESSAGE(from_host.status == PRAY_OK, from_host.error);
        // beside a file of the same name, the registered text is read
        REQUIRE(reg(c, "parts/ball.ray", "Ball = sphere(color({1}), [0, 0, 0], 0.2)\nL = none\n"));
        pray_set_frame(c, testkit::frame_sink, &first.frames);
        REQUIRE_MESSAGE(pray_run_string(c, name.c_str(), prog.data(), prog.size()) == PRAY_OK, pray_error(c));
    }
    REQUIRE(from_file.frames.size() == 1);
    REQUIRE(from_host.frames.size() == 1);
    CHECK(from_host.frames[0].pixels == from_file.frames[0].pixels);
    CHECK(first.frames[0].pixels != from_file.frames[0].pixels);
    std::remove(file.c_str());
    std::remove(sub.c_str());
    std::remove(dir);
}

TEST_CASE("pray_texture_register: a registered image renders as the same image read from a TIFF file") {
    std::vector<float> px = checker(8, 0.9f, 0.1f);
    char dir[] = "/tmp/pray_buffers_XXXXXX";
    REQUIRE(mkdtemp(dir));
    std::string file = std::string(dir) + "/checker.tif";
    std::vector<testkit::Frame> from_file;
    {
        Ctx c;
        pray_image img;
        img.width = img.height = 8;
        img.pixels = px.data();
        REQUIRE(pray_write_image(c, &img, file.c_str(), 8) == PRAY_OK);
        pray_texture *back = pray_texture_file(c, file.c_str());  // the file holds the pixels exactly
        REQUIRE(back);
        for (int y = 0; y < 8; y++)
            for (int x = 0; x < 8; x++) CHECK(pray_texture_pixel(back, x, y).g == (double)px[(y * 8 + x) * 3 + 1]);
        pray_release(c, back);
        testkit::Result r = run_in(c, texture_program(file));
        REQUIRE_MESSAGE(r.status == PRAY_OK, r.error);
        from_file = r.frames;
    }
    for (const char *adaptive : {"0", "0.05"}) {
        CAPTURE(adaptive);
        Ctx c;
        pray_option_fix(c, "adaptive", adaptive);
        pray_texture *t = pray_texture_rgb(c, 8, 8, px.data(), "checker");
        REQUIRE(pray_texture_register(c, "checker", t) == PRAY_OK);
        pray_release(c, t);
        testkit::Result r = run_in(c, texture_program("checker"));
        REQUIRE_MESSAGE(r.status == PRAY_OK, r.error);
        REQUIRE(r.frames.size() == 1);
        CHECK(r.frames[0].pixels == from_file[0].pixels);
    }
    std::remove(file.c_str());
    std::remove(dir);
}

TEST_CASE("pray_texture_register: a registered font atlas for text()") {
    // 16 x 16 cells of 2 x 2 pixels, white, but the cell of 'A' (row 4, column 1) black: a block
    std::vector<float> px(32 * 32 * 3, 1.0f);
    for (int y = 8; y < 10; y++)
        for (int x = 2; x < 4; x++)
            for (int k = 0; k < 3; k++) px[(y * 32 + x) * 3 + k] = 0;
    const std::string prog = "option \"width\", 16\noption \"height\", 16\n"
                             "rendertiff text(color({1}), \"A\", [-0.5, 0, -0.5], <1, 0, 0>, <0, 0, 1>, 0.1, "
                             "\"font\", 1), none\n";
    Ctx c;
    pray_texture *t = pray_texture_rgb(c, 32, 32, px.data(), "font");
    REQUIRE(pray_texture_register(c, "font", t) == PRAY_OK);
    pray_release(c, t);
    testkit::Result r = run_in(c, prog);
    REQUIRE_MESSAGE(r.status == PRAY_OK, r.error);
    // the block fills [-0.5, 0.5] x [-0.5, 0.5]: the centre is white, the corner background
    CHECK(r.frames[0].at(8, 8, 0) == 1.0f);
    CHECK(r.frames[0].at(0, 0, 0) == 0.0f);
}
#else
TEST_CASE("PRAY_NO_STDIO: registered textures work without file access") {
    std::vector<float> px = checker(8, 0.9f, 0.1f);
    Ctx c;
    pray_texture *t = pray_texture_rgb(c, 8, 8, px.data(), "checker");
    REQUIRE(pray_texture_register(c, "checker", t) == PRAY_OK);
    pray_release(c, t);
    testkit::Result r = run_in(c, texture_program("checker"));
    REQUIRE_MESSAGE(r.status == PRAY_OK, r.error);
    REQUIRE(r.frames.size() == 1);
    CHECK(r.frames[0].at(0, 0, 0) != r.frames[0].at(1, 0, 0));
    testkit::Result r2 = run_in(c, texture_program("unregistered.tif"));
    CHECK(r2.status == PRAY_ERR_RUNTIME);
    CHECK(contains(r2.error, "this build has no file access"));
    // include of a name not registered would read a file: an error at the statement, after what
    // ran before it
    testkit::Result r3 = run_in(c, "x = 1\ninclude \"part.ray\"\n");
    CHECK(r3.status == PRAY_ERR_RUNTIME);
    CHECK(r3.error == "scene.ray:2:9: error: include: this build has no file access");
}
#endif
