// The public API's contract: NULL arguments, handles of another context, ownership of images,
// and cancellation (pray_cancel, the progress callback).
#include <doctest/doctest.h>

#include "testkit.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <string>
#include <thread>
#include <vector>

#include <dirent.h>
#include <unistd.h>

namespace {

const pray_rgb GREY = {0.5, 0.5, 0.5}, WHITE = {1, 1, 1};
const pray_vec ORIGIN = {0, 0, 0}, UP = {0, 0, 1}, ONE = {1, 1, 1};

pray_object *ball(pray_ctx *c) {
    pray_model *m = pray_phong(c, GREY, GREY, GREY, 3);
    pray_object *o = pray_sphere(c, m, ORIGIN, 0.5);
    pray_release(c, m);
    return o;
}

std::vector<float> pixels_of(const pray_image &img) {
    return std::vector<float>(img.pixels, img.pixels + (size_t)img.width * img.height * 3);
}

// The names in a directory, . and .. left out.
std::vector<std::string> dir_names(const std::string &dir) {
    std::vector<std::string> v;
    DIR *d = opendir(dir.c_str());
    if (!d) return v;
    while (dirent *e = readdir(d))
        if (strcmp(e->d_name, ".") != 0 && strcmp(e->d_name, "..") != 0) v.push_back(e->d_name);
    closedir(d);
    return v;
}

std::string temp_dir() {
    char tmpl[] = "/tmp/pray_api_XXXXXX";
    const char *d = mkdtemp(tmpl);
    REQUIRE(d != nullptr);
    return d;
}

} // namespace

TEST_CASE("api: every function takes a NULL context and returns its error value") {
    pray_image img = {3, 4, (float *)&img};  // pray_render empties it even without a context
    pray_stats st;
    std::memset(&st, 0xff, sizeof st);
    CHECK(std::string(pray_error(nullptr)) == "error: no context");
    CHECK(pray_last_status(nullptr) == PRAY_ERR_ARG);
    CHECK(pray_temp_file(nullptr) == nullptr);
    CHECK(pray_frames(nullptr) == 0);
    CHECK(pray_option(nullptr, "width", 10) == PRAY_ERR_ARG);
    CHECK(pray_option_string(nullptr, "output", "a.tif") == PRAY_ERR_ARG);
    CHECK(pray_option_fix(nullptr, "width", "10") == PRAY_ERR_ARG);
    CHECK(std::isnan(pray_option_get(nullptr, "width")));
    CHECK(pray_run_string(nullptr, "a.ray", "print 1\n", 8) == PRAY_ERR_ARG);
    CHECK(pray_run_file(nullptr, "a.ray") == PRAY_ERR_ARG);
    CHECK(pray_phong(nullptr, GREY, GREY, GREY, 1) == nullptr);
    CHECK(pray_mirror(nullptr, GREY) == nullptr);
    CHECK(pray_transparent(nullptr, GREY, 1.5) == nullptr);
    CHECK(pray_color(nullptr, GREY) == nullptr);
    CHECK(pray_texture_file(nullptr, "a.tif") == nullptr);
    CHECK(pray_texture_tiff(nullptr, "II", 2, "a") == nullptr);
    CHECK(pray_nothing(nullptr) == nullptr);
    CHECK(pray_dirlight(nullptr, WHITE, ONE) == nullptr);
    CHECK(pray_pointlight(nullptr, WHITE, ONE) == nullptr);
    CHECK(pray_spotlight(nullptr, WHITE, ONE, UP, 10, 20) == nullptr);
    CHECK(pray_checker(nullptr, nullptr, nullptr, 1) == nullptr);
    CHECK(pray_paint(nullptr, nullptr, nullptr) == nullptr);
    CHECK(pray_perspective(nullptr, ONE, UP, ONE, ORIGIN) == PRAY_ERR_ARG);
    CHECK(pray_parallel(nullptr, ONE, UP, ONE, ORIGIN) == PRAY_ERR_ARG);
    CHECK(pray_lookat(nullptr, ONE, ORIGIN, UP, 40) == PRAY_ERR_ARG);
    CHECK(pray_background(nullptr, GREY, GREY) == PRAY_ERR_ARG);
    CHECK(pray_render(nullptr, nullptr, nullptr, &img) == PRAY_ERR_ARG);
    CHECK((img.width == 0 && img.height == 0 && img.pixels == nullptr));  // out is always emptied
    pray_stats_get(nullptr, &st);
    CHECK((st.primitives == 0 && st.rays_primary == 0 && st.threads == 0));
    CHECK(pray_prepare(nullptr, nullptr) == nullptr);
    pray_hit h;
    CHECK(pray_intersect(nullptr, nullptr, ORIGIN, UP, HUGE_VAL, &h, 1) == -1);
    CHECK(pray_write_image(nullptr, &img, "a.tif", 8) == PRAY_ERR_ARG);
    CHECK(pray_write_tiff(nullptr, &img, 8, nullptr, nullptr) == PRAY_ERR_ARG);
    CHECK(pray_write_ppm(nullptr, &img, 8, nullptr, nullptr) == PRAY_ERR_ARG);
    CHECK(pray_write_png(nullptr, &img, nullptr, nullptr) == PRAY_ERR_ARG);
    float rgb[3] = {0, 0, 0};
    pray_buffers bufs = {rgb, nullptr, nullptr, nullptr, 0, nullptr, nullptr, 0};
    CHECK(pray_render_into(nullptr, nullptr, nullptr, nullptr, &bufs) == PRAY_ERR_ARG);
    pray_vec ro, rd;
    CHECK(pray_camera_ray(nullptr, 0.5, 0.5, &ro, &rd) == PRAY_ERR_ARG);
    CHECK(pray_texture_rgb(nullptr, 1, 1, rgb, "t") == nullptr);
    CHECK(pray_texture_register(nullptr, "t", nullptr) == PRAY_ERR_ARG);
    CHECK(pray_write_image_note(nullptr, &img, "a.tif", 8, "n") == PRAY_ERR_ARG);
    pray_image made = {3, 4, (float *)&img};
    CHECK(pray_image_new(nullptr, 2, 2, &made) == PRAY_ERR_ARG);
    CHECK((made.width == 0 && made.height == 0 && made.pixels == nullptr));  // out is always emptied
    CHECK(pray_set_error(nullptr, PRAY_ERR_IO, "x") == PRAY_ERR_ARG);
    // the void ones do nothing
    pray_set_render(nullptr, nullptr, nullptr);
    pray_set_warning(nullptr, nullptr, nullptr);
    pray_free(nullptr);
    pray_clear_error(nullptr);
    pray_set_memory_limit(nullptr, 1);
    pray_set_untrusted(nullptr);
    pray_set_print(nullptr, nullptr, nullptr);
    pray_set_progress(nullptr, nullptr, nullptr);
    pray_set_frame(nullptr, nullptr, nullptr);
    pray_cancel(nullptr);
    pray_release(nullptr, &img);
    pray_object_release(nullptr, nullptr);
    pray_model_release(nullptr, nullptr);
    pray_light_release(nullptr, nullptr);
    pray_texture_release(nullptr, nullptr);
    pray_scene_free(nullptr, nullptr);
    pray_image_free(nullptr, &img);
    pray_stats_get(nullptr, nullptr);
    // functions of handles alone
    int w = 7, ht = 7;
    pray_texture_size(nullptr, &w, &ht);
    CHECK((w == 0 && ht == 0));
    pray_rgb px = pray_texture_pixel(nullptr, 0, 0);
    CHECK((px.r == 0 && px.g == 0 && px.b == 0));
    CHECK(pray_object_primitives(nullptr) == 0);
    // the functions of a context and handles, with a NULL context and real handles
    pray_ctx *c = pray_new();
    pray_model *m = pray_phong(c, GREY, GREY, GREY, 3);
    pray_object *o = pray_sphere(c, m, ORIGIN, 1);
    pray_light *l = pray_dirlight(c, WHITE, ONE);
    REQUIRE((m && o && l));
    CHECK(pray_sphere(nullptr, m, ORIGIN, 1) == nullptr);
    CHECK(pray_model_add(nullptr, m, m) == nullptr);
    CHECK(pray_csg(nullptr, PRAY_UNION, o, o) == nullptr);
    CHECK(pray_light_add(nullptr, l, l) == nullptr);
    CHECK(pray_prepare(nullptr, o) == nullptr);
    pray_release(nullptr, o);  // nothing happens: o is still there
    CHECK(pray_object_primitives(o) == 1);
    CHECK(pray_last_status(c) == PRAY_OK);
    pray_free(c);
}

TEST_CASE("api: a NULL handle gives NULL, with a message naming the call unless one is there") {
    pray_ctx *c = pray_new();
    pray_object *o = ball(c);
    pray_light *l = pray_dirlight(c, WHITE, ONE);
    pray_model *m = pray_color(c, GREY);
    struct Case {
        const char *message;
        std::function<const void *()> call;
        bool chain = true;  // a NULL handle: no new message after a failure
    };
    const Case cases[] = {
        {"error: pray_model_add: no model a", [&] { return (const void *)pray_model_add(c, nullptr, m); }},
        {"error: pray_model_add: no model b", [&] { return (const void *)pray_model_add(c, m, nullptr); }},
        {"error: pray_model_scale: no model", [&] { return (const void *)pray_model_scale(c, nullptr, GREY); }},
        {"error: pray_sphere: no model", [&] { return (const void *)pray_sphere(c, nullptr, ORIGIN, 1); }},
        {"error: pray_plane: no model", [&] { return (const void *)pray_plane(c, nullptr, ORIGIN, UP); }},
        {"error: pray_cylinder: no model", [&] { return (const void *)pray_cylinder(c, nullptr, ORIGIN, UP, 1); }},
        {"error: pray_one: no model", [&] { return (const void *)pray_one(c, nullptr); }},
        {"error: pray_planemap: no model",
         [&] { return (const void *)pray_planemap(c, nullptr, ORIGIN, UP, ONE, UP); }},
        {"error: pray_spheremap: no model",
         [&] { return (const void *)pray_spheremap(c, nullptr, ORIGIN, 1, UP, ONE); }},
        {"error: pray_tiff: no texture", [&] { return (const void *)pray_tiff(c, m, m, nullptr); }},
        {"error: pray_tiffbump: no model", [&] { return (const void *)pray_tiffbump(c, nullptr, 1, nullptr); }},
        {"error: pray_move: no model", [&] { return (const void *)pray_move(c, nullptr, 1, 1); }},
        {"error: pray_checker: no model m0", [&] { return (const void *)pray_checker(c, nullptr, m, 1); }},
        {"error: pray_checker: no model m1", [&] { return (const void *)pray_checker(c, m, nullptr, 1); }},
        {"error: pray_paint: no object", [&] { return (const void *)pray_paint(c, nullptr, m); }},
        {"error: pray_paint: no model", [&] { return (const void *)pray_paint(c, o, nullptr); }},
        {"error: pray_text: no model",
         [&] { return (const void *)pray_text(c, nullptr, "A", ORIGIN, ONE, UP, 1, nullptr, 1); }},
        {"error: pray_text: no text", [&] { return (const void *)pray_text(c, m, nullptr, ORIGIN, ONE, UP, 1, nullptr, 1); }, false},
        {"error: pray_csg: no object a", [&] { return (const void *)pray_csg(c, PRAY_UNION, nullptr, o); }},
        {"error: pray_csg: no object b", [&] { return (const void *)pray_csg(c, PRAY_UNION, o, nullptr); }},
        {"error: pray_complement: no object", [&] { return (const void *)pray_complement(c, nullptr); }},
        {"error: pray_scale: no object", [&] { return (const void *)pray_scale(c, nullptr, 2); }},
        {"error: pray_translate: no object", [&] { return (const void *)pray_translate(c, nullptr, ONE); }},
        {"error: pray_rotate: no object", [&] { return (const void *)pray_rotate(c, nullptr, ONE); }},
        {"error: pray_light_add: no light b", [&] { return (const void *)pray_light_add(c, l, nullptr); }},
        {"error: pray_light_scale: no light", [&] { return (const void *)pray_light_scale(c, nullptr, 2); }},
        {"error: pray_light_translate: no light", [&] { return (const void *)pray_light_translate(c, nullptr, ONE); }},
        {"error: pray_light_rotate: no light", [&] { return (const void *)pray_light_rotate(c, nullptr, ONE); }},
        {"error: pray_prepare: no object", [&] { return (const void *)pray_prepare(c, nullptr); }},
        {"error: pray_texture_file: no file name", [&] { return (const void *)pray_texture_file(c, nullptr); }, false},
        {"error: pray_texture_tiff: no data", [&] { return (const void *)pray_texture_tiff(c, nullptr, 4, "t"); }, false},
    };
    for (const Case &k : cases) {
        CAPTURE(k.message);
        pray_clear_error(c);
        CHECK(k.call() == nullptr);
        CHECK(pray_last_status(c) == PRAY_ERR_ARG);
        CHECK(std::string(pray_error(c)) == k.message);
        // the chain rule: after a failure, its message stays (other NULL arguments: a new one)
        pray_clear_error(c);
        CHECK(pray_sphere(c, m, ORIGIN, -1) == nullptr);
        std::string first = pray_error(c);
        CHECK(k.call() == nullptr);
        CHECK((std::string(pray_error(c)) == first) == k.chain);
    }
    // statuses, -1 and void functions
    pray_clear_error(c);
    pray_image img;
    CHECK(pray_render(c, o, l, nullptr) == PRAY_ERR_ARG);
    CHECK(std::string(pray_error(c)) == "error: pray_render: no image to render into");
    pray_clear_error(c);
    CHECK(pray_render(c, nullptr, l, &img) == PRAY_ERR_ARG);
    CHECK(std::string(pray_error(c)) == "error: no object to render");
    CHECK(img.pixels == nullptr);
    pray_clear_error(c);
    pray_vec d = {0, 0, -1}, from = {0, 0, 5};
    CHECK(pray_intersect(c, nullptr, from, d, HUGE_VAL, nullptr, 0) == -1);
    CHECK(std::string(pray_error(c)) == "error: pray_intersect: no scene");
    pray_scene *sc = pray_prepare(c, o);
    REQUIRE(sc);
    CHECK(pray_intersect(c, sc, from, d, HUGE_VAL, nullptr, 4) == -1);
    CHECK(std::string(pray_error(c)) == "error: pray_intersect: no room for the hits");
    CHECK(pray_intersect(c, sc, from, d, HUGE_VAL, nullptr, 0) == 2);  // counting needs no room
    pray_scene_free(c, sc);
    pray_clear_error(c);
    CHECK(pray_write_image(c, nullptr, "a.tif", 8) == PRAY_ERR_ARG);
    CHECK(std::string(pray_error(c)) == "error: not a valid image");
    CHECK(pray_option(c, nullptr, 1) == PRAY_ERR_ARG);
    CHECK(pray_option_string(c, "output", nullptr) == PRAY_ERR_ARG);
    CHECK(pray_option_fix(c, "width", nullptr) == PRAY_ERR_ARG);
    CHECK(std::isnan(pray_option_get(c, nullptr)));
    CHECK(pray_run_string(c, nullptr, nullptr, 0) == PRAY_ERR_ARG);
    CHECK(pray_run_file(c, nullptr) == PRAY_ERR_ARG);
    REQUIRE(pray_render(c, o, l, &img) == PRAY_OK);
    CHECK(pray_write_tiff(c, &img, 8, nullptr, nullptr) == PRAY_ERR_ARG);
    CHECK(std::string(pray_error(c)) == "error: pray_write_tiff: no write function");
    CHECK(pray_write_ppm(c, &img, 8, nullptr, nullptr) == PRAY_ERR_ARG);
    CHECK(std::string(pray_error(c)) == "error: pray_write_ppm: no write function");
    pray_clear_error(c);
    pray_release(c, nullptr);
    pray_object_release(c, nullptr);
    pray_scene_free(c, nullptr);
    pray_image_free(c, nullptr);
    pray_set_print(c, nullptr, nullptr);
    CHECK(pray_last_status(c) == PRAY_OK);
    pray_release(c, m);
    pray_release(c, l);
    pray_release(c, o);
    pray_free(c);  // (img dies with it)
}

TEST_CASE("api: handles, scenes and images of another context are refused") {
    pray_ctx *a = pray_new(), *b = pray_new();
    pray_model *m = pray_phong(b, GREY, GREY, GREY, 3);
    pray_object *o = pray_sphere(b, m, ORIGIN, 0.5);
    pray_light *l = pray_dirlight(b, WHITE, ONE);
    pray_scene *sc = pray_prepare(b, o);
    pray_image img;
    pray_option(b, "width", 8);
    pray_option(b, "height", 8);
    REQUIRE(pray_render(b, o, l, &img) == PRAY_OK);
    REQUIRE((m && o && l && sc));
    pray_model *ma = pray_color(a, GREY);
    pray_object *oa = pray_sphere(a, ma, ORIGIN, 1);
    pray_light *la = pray_dirlight(a, WHITE, ONE);
    struct Case {
        const char *message;
        std::function<bool()> refused;  // the call failed
    };
    const Case cases[] = {
        {"error: pray_model_add: the model b belongs to another context", [&] { return !pray_model_add(a, ma, m); }},
        {"error: pray_model_scale: the model belongs to another context", [&] { return !pray_model_scale(a, m, GREY); }},
        {"error: pray_sphere: the model belongs to another context", [&] { return !pray_sphere(a, m, ORIGIN, 1); }},
        {"error: pray_plane: the model belongs to another context", [&] { return !pray_plane(a, m, ORIGIN, UP); }},
        {"error: pray_cylinder: the model belongs to another context", [&] { return !pray_cylinder(a, m, ORIGIN, UP, 1); }},
        {"error: pray_one: the model belongs to another context", [&] { return !pray_one(a, m); }},
        {"error: pray_planemap: the model belongs to another context",
         [&] { return !pray_planemap(a, m, ORIGIN, UP, ONE, UP); }},
        {"error: pray_spheremap: the model belongs to another context",
         [&] { return !pray_spheremap(a, m, ORIGIN, 1, UP, ONE); }},
        {"error: pray_tiff: the model m0 belongs to another context", [&] { return !pray_tiff(a, m, ma, nullptr); }},
        {"error: pray_tiffbump: the model belongs to another context", [&] { return !pray_tiffbump(a, m, 1, nullptr); }},
        {"error: pray_move: the model belongs to another context", [&] { return !pray_move(a, m, 1, 1); }},
        {"error: pray_checker: the model m1 belongs to another context", [&] { return !pray_checker(a, ma, m, 1); }},
        {"error: pray_paint: the model belongs to another context", [&] { return !pray_paint(a, oa, m); }},
        {"error: pray_paint: the object belongs to another context", [&] { return !pray_paint(a, o, ma); }},
        {"error: pray_text: the model belongs to another context",
         [&] { return !pray_text(a, m, "A", ORIGIN, ONE, UP, 1, nullptr, 1); }},
        {"error: pray_csg: the object a belongs to another context", [&] { return !pray_csg(a, PRAY_UNION, o, oa); }},
        {"error: pray_csg: the object b belongs to another context", [&] { return !pray_csg(a, PRAY_DIFFERENCE, oa, o); }},
        {"error: pray_complement: the object belongs to another context", [&] { return !pray_complement(a, o); }},
        {"error: pray_scale: the object belongs to another context", [&] { return !pray_scale(a, o, 2); }},
        {"error: pray_translate: the object belongs to another context", [&] { return !pray_translate(a, o, ONE); }},
        {"error: pray_rotate: the object belongs to another context", [&] { return !pray_rotate(a, o, ONE); }},
        {"error: pray_light_add: the light a belongs to another context", [&] { return !pray_light_add(a, l, la); }},
        {"error: pray_light_scale: the light belongs to another context", [&] { return !pray_light_scale(a, l, 2); }},
        {"error: pray_light_translate: the light belongs to another context",
         [&] { return !pray_light_translate(a, l, ONE); }},
        {"error: pray_light_rotate: the light belongs to another context", [&] { return !pray_light_rotate(a, l, ONE); }},
        {"error: pray_prepare: the object belongs to another context", [&] { return !pray_prepare(a, o); }},
        {"error: pray_render: the object belongs to another context",
         [&] { pray_image x; return pray_render(a, o, la, &x) == PRAY_ERR_ARG && !x.pixels; }},
        {"error: pray_render: the light belongs to another context",
         [&] { pray_image x; return pray_render(a, oa, l, &x) == PRAY_ERR_ARG && !x.pixels; }},
        {"error: pray_render_into: the object belongs to another context",
         [&] { float px[3]; pray_buffers x = {px, nullptr, nullptr, nullptr, 0, nullptr, nullptr, 0}; pray_rect r = {0, 0, 1, 1};
               return pray_render_into(a, o, la, &r, &x) == PRAY_ERR_ARG; }},
        {"error: pray_render_into: the light belongs to another context",
         [&] { float px[3]; pray_buffers x = {px, nullptr, nullptr, nullptr, 0, nullptr, nullptr, 0}; pray_rect r = {0, 0, 1, 1};
               return pray_render_into(a, oa, l, &r, &x) == PRAY_ERR_ARG; }},
        {"error: pray_intersect: the scene belongs to another context",
         [&] { return pray_intersect(a, sc, ONE, UP, HUGE_VAL, nullptr, 0) == -1; }},
        {"error: pray_scene_free: the scene belongs to another context", [&] { pray_scene_free(a, sc); return true; }},
        {"error: pray_image_free: the image belongs to another context",
         [&] { pray_image_free(a, &img); return img.pixels != nullptr; }},
        {"error: pray_release: the handle belongs to another context", [&] { pray_release(a, o); return true; }},
        {"error: pray_object_release: the object belongs to another context",
         [&] { pray_object_release(a, o); return true; }},
        {"error: pray_model_release: the model belongs to another context",
         [&] { pray_model_release(a, m); return true; }},
        {"error: pray_light_release: the light belongs to another context",
         [&] { pray_light_release(a, l); return true; }},
    };
    for (const Case &k : cases) {
        CAPTURE(k.message);
        pray_clear_error(a);
        CHECK(k.refused());
        CHECK(pray_last_status(a) == PRAY_ERR_ARG);
        CHECK(std::string(pray_error(a)) == k.message);
    }
    // b's things are untouched: they still work in b
    CHECK(pray_last_status(b) == PRAY_OK);
    CHECK(pray_object_primitives(o) == 1);
    pray_vec from = {0, 0, 5}, down = {0, 0, -1};
    pray_hit hits[2];
    CHECK(pray_intersect(b, sc, from, down, HUGE_VAL, hits, 2) == 2);
    CHECK(hits[0].t == doctest::Approx(4.5));
    CHECK(img.width == 8);
    std::vector<float> before = pixels_of(img);
    pray_image again;
    REQUIRE(pray_render(b, o, l, &again) == PRAY_OK);
    CHECK(pixels_of(again) == before);
    // writing reads an image only: any context may write any image
    std::string tiff;
    CHECK(pray_write_tiff(a, &img, 8, testkit::print_sink, &tiff) == PRAY_OK);
    CHECK(tiff.size() == 8 + 2 + 12 * 12 + 4 + 6 + 16 + 8 * 8 * 3);
    // textures too
    pray_texture *t = pray_texture_tiff(b, tiff.data(), tiff.size(), "t");
    REQUIRE(t);
    const Case textures[] = {
        {"error: pray_tiff: the texture belongs to another context", [&] { return !pray_tiff(a, ma, ma, t); }},
        {"error: pray_tiffbump: the texture belongs to another context", [&] { return !pray_tiffbump(a, ma, 1, t); }},
        {"error: pray_text: the font belongs to another context",
         [&] { return !pray_text(a, ma, "A", ORIGIN, ONE, UP, 1, t, 1); }},
        {"error: pray_texture_register: the texture belongs to another context",
         [&] { return pray_texture_register(a, "t", t) == PRAY_ERR_ARG; }},
        {"error: pray_texture_release: the texture belongs to another context",
         [&] { pray_texture_release(a, t); return true; }},
    };
    for (const Case &k : textures) {
        CAPTURE(k.message);
        pray_clear_error(a);
        CHECK(k.refused());
        CHECK(std::string(pray_error(a)) == k.message);
    }
    int tw = 0, th = 0;
    pray_texture_size(t, &tw, &th);
    CHECK((tw == 8 && th == 8));
    // both contexts freed with all they made (under AddressSanitizer: no leak, no use after free)
    pray_free(a);
    pray_free(b);
}

TEST_CASE("api: releases check the kind of handle") {
    pray_ctx *c = pray_new();
    pray_model *m = pray_color(c, GREY);
    pray_object *o = pray_sphere(c, m, ORIGIN, 1);
    pray_scene *sc = pray_prepare(c, o);
    REQUIRE(sc);
    pray_object_release(c, (pray_object *)m);
    CHECK(std::string(pray_error(c)) == "error: pray_object_release: the object is not a live handle of its kind");
    pray_clear_error(c);
    pray_light_release(c, (pray_light *)o);
    CHECK(std::string(pray_error(c)) == "error: pray_light_release: the light is not a live handle of its kind");
    pray_clear_error(c);
    pray_release(c, sc);  // a scene is not a handle: pray_scene_free frees it
    CHECK(std::string(pray_error(c)) == "error: pray_release: the handle is not a live handle of its kind");
    pray_clear_error(c);
    pray_csg(c, PRAY_UNION, (pray_object *)m, o);
    CHECK(std::string(pray_error(c)) == "error: pray_csg: the object a is not a live handle of its kind");
    pray_model_release(c, m);  // o keeps its own reference to the model
    CHECK(pray_last_status(c) == PRAY_ERR_ARG);  // (the error before, not a new one)
    pray_clear_error(c);
    pray_object_release(c, o);
    pray_scene_free(c, sc);
    CHECK(pray_last_status(c) == PRAY_OK);
    pray_free(c);
}

TEST_CASE("api: images belong to their context") {
    pray_ctx *c = pray_new();
    pray_option(c, "width", 16);
    pray_option(c, "height", 16);
    pray_object *o = ball(c);
    pray_image kept, freed;
    REQUIRE(pray_render(c, o, nullptr, &kept) == PRAY_OK);
    REQUIRE(pray_render(c, o, nullptr, &freed) == PRAY_OK);
    pray_image_free(c, &freed);
    CHECK((freed.width == 0 && freed.height == 0 && freed.pixels == nullptr));
    pray_image_free(c, &freed);  // twice: harmless, the struct was zeroed
    CHECK(pray_last_status(c) == PRAY_OK);
    CHECK(kept.pixels[0] >= 0);
    pray_free(c);  // frees `kept` and `o`: under AddressSanitizer, nothing leaks
}

namespace {
struct Cancel {
    pray_ctx *c = nullptr;
    int calls = 0, at = -1;  // pray_cancel on the at-th call
};
int cancel_progress(void *ud, int, int) { return ++((Cancel *)ud)->calls == 1; }
// An allocator that cancels on its at-th call: deterministic cancellation inside any work.
void *cancel_alloc(void *ud, void *p, size_t, size_t n) {
    Cancel *k = (Cancel *)ud;
    if (n && k->at >= 0 && ++k->calls == k->at) pray_cancel(k->c);
    if (n == 0) {
        free(p);
        return nullptr;
    }
    return realloc(p, n);
}
void cancel_print(void *ud, const void *, size_t) { pray_cancel(((Cancel *)ud)->c); }

const char *SCENE = "M = phong({0.8, 0.2, 0.2}, {0.3}, {0.1}, 5)\n"
                    "S = sphere(M, [0, 0, 0], 0.5)\n"
                    "i = 0\n"
                    "while i < 40\n"
                    "  S = S | sphere(M, [i / 40 - 0.5, 0, 0.3], 0.05)\n"
                    "  i = i + 1\n"
                    "endwhile\n"
                    "L = dirlight({1}, <1, 1, 1>)\n";
} // namespace

TEST_CASE("api: cancelling from the progress callback stops the render and leaves no file") {
    std::string dir = temp_dir(), name = dir + "/scene.ray";
    std::string prog = std::string(SCENE) + "rendertiff S, L\nprint \"after\"\n";
    pray_ctx *c = pray_new();
    Cancel k;
    std::string printed;
    pray_set_print(c, testkit::print_sink, &printed);
    pray_set_progress(c, cancel_progress, &k);
    pray_option(c, "width", 64);
    pray_option(c, "height", 64);
    CHECK(pray_run_string(c, name.c_str(), prog.data(), prog.size()) == PRAY_ERR_CANCELLED);
    CHECK(std::string(pray_error(c)) == name + ":9:1: error: cancelled by the progress callback");
    CHECK(k.calls == 1);
    CHECK(printed == "");
    CHECK(pray_frames(c) == 0);
    CHECK(dir_names(dir).empty());
    CHECK(std::string(pray_status_text(PRAY_ERR_CANCELLED)) == "cancelled");
    // the same context renders again when the callback lets it
    pray_set_progress(c, nullptr, nullptr);
    CHECK(pray_run_string(c, name.c_str(), prog.data(), prog.size()) == PRAY_OK);
    CHECK(dir_names(dir) == std::vector<std::string>{"scene.tif"});
    remove((dir + "/scene.tif").c_str());
    rmdir(dir.c_str());
    pray_free(c);
}

TEST_CASE("api: pray_cancel stops a program, a preparation, a render and a file being written") {
    std::string prog = std::string(SCENE) + "print 1\nprint 2\n";
    Cancel k;
    pray_ctx *c = pray_new_with(cancel_alloc, &k);
    k.c = c;
    SUBCASE("a cancel made before the call is forgotten when it starts") {
        pray_cancel(c);
        std::string printed;
        pray_set_print(c, testkit::print_sink, &printed);
        CHECK(pray_run_string(c, "a.ray", prog.data(), prog.size()) == PRAY_OK);
        CHECK(printed == "1\n2\n");
    }
    SUBCASE("a program stops at its next statement") {
        pray_set_print(c, cancel_print, &k);
        CHECK(pray_run_string(c, "a.ray", prog.data(), prog.size()) == PRAY_ERR_CANCELLED);
        CHECK(std::string(pray_error(c)) == "a.ray:10:1: error: cancelled");
    }
    pray_object *o = ball(c);
    pray_light *l = pray_dirlight(c, WHITE, ONE);
    pray_option(c, "width", 32);
    pray_option(c, "height", 32);
    pray_option(c, "threads", 2);
    SUBCASE("preparing a scene, and the render of it, at every allocation") {
        // each allocation of the call in turn: the call stops with the cancel, or ends before
        // it comes (the last allocations are the image's and the workers')
        for (double adaptive : {0.0, 0.1}) {
        CAPTURE(adaptive);
        pray_option(c, "adaptive", adaptive);
        int stopped = 0, total = 0;
        for (int at = 1; at < 400; at++) {
            pray_image img;
            k.calls = 0;
            k.at = at;
            pray_status st = pray_render(c, o, l, &img);
            k.at = -1;
            if (k.calls < at) break;  // the call made fewer allocations than that
            total++;
            CAPTURE(at);
            if (st == PRAY_ERR_CANCELLED) {
                stopped++;
                CHECK(std::string(pray_error(c)) == "error: cancelled");
                CHECK(img.pixels == nullptr);
            } else CHECK(st == PRAY_OK);
            pray_image_free(c, &img);
        }
        CHECK(total > 10);
        CHECK(stopped == total);  // every allocation comes before a check
        }
        pray_scene *sc = nullptr;
        k.calls = 0;
        k.at = 3;
        sc = pray_prepare(c, o);
        k.at = -1;
        CHECK(sc == nullptr);
        CHECK(pray_last_status(c) == PRAY_ERR_CANCELLED);
    }
    SUBCASE("writing a file: nothing is left") {
        std::string dir = temp_dir();
        pray_image img;
        REQUIRE(pray_render(c, o, l, &img) == PRAY_OK);
        k.calls = 0;
        k.at = 2;  // the temporary name, then the writer's row
        CHECK(pray_write_image(c, &img, (dir + "/x.ppm").c_str(), 8) == PRAY_ERR_CANCELLED);
        k.at = -1;
        CHECK(dir_names(dir).empty());
        CHECK(pray_write_image(c, &img, (dir + "/x.ppm").c_str(), 8) == PRAY_OK);
        CHECK(dir_names(dir) == std::vector<std::string>{"x.ppm"});
        remove((dir + "/x.ppm").c_str());
        rmdir(dir.c_str());
        // a byte sink has what was written before the cancel: the header and no row
        std::string got;
        auto sink = [](void *ud, const void *, size_t n) {
            Cancel *x = (Cancel *)ud;
            x->calls += (int)n;
            pray_cancel(x->c);
        };
        k.calls = 0;
        CHECK(pray_write_ppm(c, &img, 8, sink, &k) == PRAY_ERR_CANCELLED);
        CHECK(k.calls == (int)strlen("P6\n32 32\n255\n"));
        CHECK(std::string(pray_error(c)) == "error: cancelled");
        // PNG: the encoder stops where it asks for memory next, and frees what it held
        if (std::strstr(pray_features(), "png")) {
            std::string whole;
            REQUIRE(pray_write_png(c, &img, testkit::print_sink, &whole) == PRAY_OK);
            int stopped = 0, total = 0;
            for (int at = 1; at < 1000; at++) {
                std::string png;
                k.calls = 0;
                k.at = at;
                pray_status st = pray_write_png(c, &img, testkit::print_sink, &png);
                k.at = -1;
                if (k.calls < at) break;
                total++;
                CAPTURE(at);
                if (st == PRAY_ERR_CANCELLED) {
                    stopped++;
                    CHECK(std::string(pray_error(c)) == "error: cancelled");
                } else {
                    CHECK(st == PRAY_OK);
                    CHECK(png == whole);
                }
            }
            CHECK(total >= 3);
            CHECK(stopped >= total - 1);  // a cancel at the last allocation comes after the last check
            std::string again;
            CHECK(pray_write_png(c, &img, testkit::print_sink, &again) == PRAY_OK);
            CHECK(again == whole);
        }
    }
    pray_free(c);
}

TEST_CASE("api: pray_cancel from another thread stops an endless program and a long render promptly") {
    pray_ctx *c = pray_new();
    std::atomic<bool> go{false};
    auto canceller = [&] {
        while (!go) std::this_thread::yield();
        std::this_thread::sleep_for(std::chrono::milliseconds(100));
        pray_cancel(c);
    };
    typedef std::chrono::steady_clock Clock;
    {
        const char *prog = "i = 0\nwhile 1\n  i = i + 1\nendwhile\n";
        pray_option(c, "maxsteps", 2e8);  // seconds of work: a cancel that fails ends, in a limit
        std::thread t(canceller);
        go = true;
        Clock::time_point t0 = Clock::now();
        pray_status st = pray_run_string(c, "loop.ray", prog, strlen(prog));
        double s = std::chrono::duration<double>(Clock::now() - t0).count();
        t.join();
        CHECK(st == PRAY_ERR_CANCELLED);
        std::string e = pray_error(c);
        CHECK(e.find("loop.ray:") == 0);
        CHECK(e.find(": error: cancelled") != std::string::npos);
        CHECK(s < 5);
    }
    pray_object *o = ball(c);
    pray_light *l = pray_dirlight(c, WHITE, ONE);
    {
        // far more work than 100 ms: 2048 x 2048 pixels, 16 samples each
        pray_option(c, "width", 2048);
        pray_option(c, "height", 2048);
        pray_option(c, "antialias", 4);
        go = false;
        std::thread t(canceller);
        go = true;
        Clock::time_point t0 = Clock::now();
        pray_image img;
        pray_status st = pray_render(c, o, l, &img);
        double s = std::chrono::duration<double>(Clock::now() - t0).count();
        t.join();
        CHECK(st == PRAY_ERR_CANCELLED);
        CHECK(std::string(pray_error(c)) == "error: cancelled");
        CHECK(img.pixels == nullptr);
        CHECK(s < 5);
    }
    // the context works as before: the same image as a fresh context's
    pray_option(c, "width", 24);
    pray_option(c, "height", 24);
    pray_option(c, "antialias", 1);
    pray_image mine, fresh;
    REQUIRE(pray_render(c, o, l, &mine) == PRAY_OK);
    pray_ctx *f = pray_new();
    pray_option(f, "width", 24);
    pray_option(f, "height", 24);
    pray_object *fo = ball(f);
    pray_light *fl = pray_dirlight(f, WHITE, ONE);
    REQUIRE(pray_render(f, fo, fl, &fresh) == PRAY_OK);
    CHECK(pixels_of(mine) == pixels_of(fresh));
    pray_free(f);
    pray_free(c);
}

TEST_CASE("api: a prepared scene needs nothing it was made from") {
    pray_ctx *c = pray_new();
    pray_model *m = pray_phong(c, GREY, GREY, GREY, 3);
    pray_model *glass = pray_transparent(c, GREY, 1.5);
    pray_object *a = pray_sphere(c, m, ORIGIN, 0.5), *b = pray_sphere(c, glass, ONE, 0.5);
    pray_object *both = pray_csg(c, PRAY_UNION, a, b);
    pray_scene *sc = pray_prepare(c, both);
    REQUIRE(sc);
    pray_object_release(c, a);
    pray_object_release(c, b);
    pray_object_release(c, both);
    pray_model_release(c, m);
    pray_model_release(c, glass);
    pray_vec from = {0, 0, 5}, down = {0, 0, -1};
    pray_hit hits[2];
    CHECK(pray_intersect(c, sc, from, down, HUGE_VAL, hits, 2) == 2);
    CHECK(hits[1].t == doctest::Approx(5.5));
    CHECK(hits[1].entering == 0);
    pray_scene_free(c, sc);
    CHECK(pray_last_status(c) == PRAY_OK);
    pray_free(c);
}

TEST_CASE("api: a ray's direction may be tiny or huge; only the zero vector is refused") {
    pray_ctx *c = pray_new();
    pray_object *o = ball(c);
    pray_scene *sc = pray_prepare(c, o);
    REQUIRE(sc);
    pray_vec from = {0.1, 0.2, 5};
    pray_hit want[2], got[2];
    pray_vec down = {0, 0, -1};
    REQUIRE(pray_intersect(c, sc, from, down, HUGE_VAL, want, 2) == 2);
    const double scales[] = {4.9e-324, 1e-310, 1e-200, 1e200, 1.7e308};
    for (double k : scales) {
        CAPTURE(k);
        pray_vec d = {0, 0, -k};
        REQUIRE(pray_intersect(c, sc, from, d, HUGE_VAL, got, 2) == 2);
        for (int i = 0; i < 2; i++) {
            CHECK(got[i].t == doctest::Approx(want[i].t).epsilon(1e-6));
            CHECK(got[i].entering == want[i].entering);
        }
    }
    // all three components huge: their squares would overflow
    pray_vec diag = {-1.5e308, -1.5e308, -1.5e308}, unit_diag = {-1, -1, -1};
    pray_vec far = {2, 2, 2};
    REQUIRE(pray_intersect(c, sc, far, unit_diag, HUGE_VAL, want, 2) == 2);
    REQUIRE(pray_intersect(c, sc, far, diag, HUGE_VAL, got, 2) == 2);
    CHECK(got[0].t == doctest::Approx(want[0].t).epsilon(1e-6));  // (the same direction to rounding)
    pray_vec zero = {0, 0, 0}, nan_dir = {0, 0, NAN};
    CHECK(pray_intersect(c, sc, from, zero, HUGE_VAL, got, 2) == -1);
    CHECK(std::string(pray_error(c)) ==
          "error: pray_intersect: the ray must have a finite origin and a finite, non-zero direction");
    CHECK(pray_intersect(c, sc, from, nan_dir, HUGE_VAL, got, 2) == -1);
    pray_scene_free(c, sc);
    pray_release(c, o);
    pray_free(c);
}

namespace {
// What a frame callback or a render function tried on the context that called it.
struct Nested {
    pray_ctx *other = nullptr;  // a second context, for an image that is not the caller's
    int calls = 0;
    std::vector<pray_status> refused;
    std::vector<std::string> messages;
    bool give_foreign = false;
};
const char *const TWO_FRAMES = "O = sphere(phong({1}, {0}, 1), [0, 0, 0], 0.5)\nrendertiff O\nrendertiff O\n";

void try_nested_run(Nested *n, pray_ctx *c) {
    n->calls++;
    const char *prog = "print 1\n";
    n->refused.push_back(pray_run_string(c, "inner.ray", prog, strlen(prog)));
    n->messages.push_back(pray_error(c));
    n->refused.push_back(pray_run_file(c, "examples/redsph.ray"));
}
pray_status frame_runs(void *ud, const pray_image *, const char *) {
    Nested *n = (Nested *)ud;
    try_nested_run(n, n->other);
    return PRAY_OK;
}
pray_status render_runs(void *ud, pray_ctx *c, pray_object *root, pray_light *lights, int, pray_image *out) {
    Nested *n = (Nested *)ud;
    try_nested_run(n, c);
    if (n->give_foreign) return pray_image_new(n->other, 4, 4, out);
    return pray_render(c, root, lights, out);
}
} // namespace

TEST_CASE("api: callbacks cannot start a run on the context running a program, nor give another's image") {
    Nested n;
    n.other = pray_new();  // (the frame callback gets no context: it is told the one it runs on)
    pray_ctx *c = n.other;
    pray_option(c, "width", 4);
    pray_option(c, "height", 4);
    // a frame callback: both frames arrive, each nested run is refused
    pray_set_frame(c, frame_runs, &n);
    CHECK(pray_run_string(c, "outer.ray", TWO_FRAMES, strlen(TWO_FRAMES)) == PRAY_OK);
    CHECK(n.calls == 2);
    CHECK(n.refused == std::vector<pray_status>(4, PRAY_ERR_ARG));
    CHECK(n.messages[0] == "error: the context is running a program");
    // a render function: both frames go through it (the nested run did not reset the outer one)
    pray_ctx *d = pray_new();
    pray_option(d, "width", 4);
    pray_option(d, "height", 4);
    Nested m;
    m.other = c;
    std::vector<testkit::Frame> frames;
    pray_set_frame(d, testkit::frame_sink, &frames);
    pray_set_render(d, render_runs, &m);
    CHECK(pray_run_string(d, "outer.ray", TWO_FRAMES, strlen(TWO_FRAMES)) == PRAY_OK);
    CHECK(m.calls == 2);
    CHECK(m.refused == std::vector<pray_status>(4, PRAY_ERR_ARG));
    CHECK(frames.size() == 2);
    // an image of another context is refused: the program stops there and no frame is taken
    m = Nested();
    m.other = c;
    m.give_foreign = true;
    frames.clear();
    CHECK(pray_run_string(d, "outer.ray", TWO_FRAMES, strlen(TWO_FRAMES)) == PRAY_ERR_RUNTIME);
    CHECK(std::string(pray_error(d)) == "outer.ray:2:1: error: the render function gave an image that is not one "
                                        "of this context's (pray_render, pray_image_new)");
    CHECK(frames.empty());
    CHECK(m.calls == 1);
    pray_free(d);
    pray_free(c);
}

namespace {
// A render function that keeps the program's scene: renders the frame, then takes references
// to its root and lights.
struct Kept {
    pray_object *root = nullptr;
    pray_light *lights = nullptr;
    std::vector<float> seen;  // the frame as rendered inside the run
};
pray_status keep_scene(void *ud, pray_ctx *c, pray_object *root, pray_light *lights, int, pray_image *out) {
    Kept *k = (Kept *)ud;
    pray_status st = pray_render(c, root, lights, out);
    if (st == PRAY_OK) k->seen = pixels_of(*out);
    if (st == PRAY_OK && (pray_retain(c, root) != PRAY_OK || pray_retain(c, lights) != PRAY_OK)) st = PRAY_ERR_ARG;
    k->root = root;
    k->lights = lights;
    return st;
}
} // namespace

TEST_CASE("api: pray_retain keeps a program's scene past its run, to render again with another camera") {
    pray_ctx *c = pray_new();
    pray_option(c, "width", 24);
    pray_option(c, "height", 24);
    Kept k;
    std::vector<testkit::Frame> frames;
    pray_set_frame(c, testkit::frame_sink, &frames);
    pray_set_render(c, keep_scene, &k);
    const char *prog = "M = phong({0.8, 0.2, 0.1}, {0.3}, 8)\n"
                       "O = (sphere(M, [0, 0, 0], 0.5) | box(M, [-0.9, -0.9, -0.9], [-0.4, -0.4, -0.4])) - sphere(M, [0.3, 0.3, 0.3], 0.3)\n"
                       "rendertiff O, dirlight({1}, <1, 1, 1>) + pointlight({0.5}, [2, -1, 3])\n"
                       "O = nothing\n";  // (the program lets go of its own)
    REQUIRE(pray_run_string(c, "kept.ray", prog, strlen(prog)) == PRAY_OK);
    REQUIRE(frames.size() == 1);
    REQUIRE(k.root);
    pray_set_render(c, nullptr, nullptr);
    // the same camera: the same pixels; another camera: another picture of the same scene
    pray_image img;
    REQUIRE(pray_render(c, k.root, k.lights, &img) == PRAY_OK);
    CHECK(pixels_of(img) == k.seen);
    pray_image_free(c, &img);
    pray_vec eye = {3, -2, 1}, at = {0, 0, 0}, up = {0, 0, 1};
    REQUIRE(pray_lookat(c, eye, at, up, 40) == PRAY_OK);
    REQUIRE(pray_render(c, k.root, k.lights, &img) == PRAY_OK);
    CHECK(pixels_of(img) != k.seen);
    float most = 0;
    for (float v : pixels_of(img)) most = std::max(most, v);
    CHECK(most > 0.2f);  // (the scene is there)
    pray_image_free(c, &img);
    pray_object_release(c, k.root);
    pray_light_release(c, k.lights);
    CHECK(pray_retain(c, nullptr) == PRAY_ERR_ARG);
    pray_ctx *d = pray_new();
    pray_object *o = ball(d);
    CHECK(pray_retain(c, o) == PRAY_ERR_ARG);  // another context's
    CHECK(std::string(pray_error(c)) == "error: pray_retain: the handle belongs to another context");
    pray_free(d);
    pray_free(c);
}

namespace {
// A scene of the test below on context c: 0 a ball and a box, 1 two balls; lights 0 and 1.
pray_object *scene_of(pray_ctx *c, int which) {
    pray_rgb red = {0.8, 0.2, 0.1};
    pray_model *m = pray_phong(c, red, GREY, GREY, 8);
    pray_vec p = {0.3, -0.2, 0.1}, q = {-0.6, 0.1, -0.3}, lo = {-0.9, -0.9, -0.9}, hi = {-0.2, -0.3, 0.4};
    pray_object *o = pray_csg(c, PRAY_UNION, pray_sphere(c, m, p, 0.5),
                              which == 0 ? pray_box(c, m, lo, hi) : pray_sphere(c, m, q, 0.35));
    pray_release(c, m);
    return o;
}
pray_light *light_of(pray_ctx *c, int which) {
    pray_vec d = {1, 1, 1}, at = {2, -1, 3};
    return which == 0 ? pray_dirlight(c, WHITE, d) : pray_pointlight(c, GREY, at);
}
// The settings of step k of the test below, and those of the steps before it.
void settings_of(pray_ctx *c, int k) {
    pray_option(c, "width", 40);
    pray_option(c, "height", 30);
    if (k >= 2) pray_option(c, "shadows", 0);
    if (k >= 3) {
        pray_vec eye = {3, -2, 1}, up = {0, 0, 1};
        pray_lookat(c, eye, ORIGIN, up, 40);
    }
    if (k >= 4) {
        pray_rgb top = {0.2, 0.3, 0.9}, bottom = {0.9, 0.8, 0.2};
        pray_background(c, top, bottom);
    }
}
std::vector<float> render_rect(pray_ctx *c, pray_object *o, pray_light *l, int bands) {
    std::vector<float> px((size_t)40 * 30 * 3);
    for (int b = 0; b < bands; b++) {
        pray_rect r = {0, 30 * b / bands, 40, 30 * (b + 1) / bands - 30 * b / bands};
        pray_buffers out = {px.data() + (size_t)3 * 40 * r.y, nullptr, nullptr, nullptr, 40, nullptr, nullptr, 0};
        REQUIRE(pray_render_into(c, o, l, &r, &out) == PRAY_OK);
    }
    return px;
}
} // namespace

TEST_CASE("api: pray_render_into reuses the scene it prepared only for the same scene, lights, options, camera and background") {
    // each step on one context, in bands (the second band on reuses the first's preparation),
    // against a fresh context with the same settings rendering the whole image
    pray_ctx *c = pray_new();
    pray_object *o = scene_of(c, 0);
    pray_light *l = light_of(c, 0);
    std::vector<std::vector<float>> seen;
    for (int k = 0; k < 8; k++) {
        CAPTURE(k);
        settings_of(c, k);
        int which = k >= 6 ? 1 : 0, lit = k >= 5 ? 1 : 0;
        if (k == 5) {  // other lights
            pray_light_release(c, l);
            l = light_of(c, 1);
        }
        if (k == 6) {  // another scene, made right after the kept one is let go (it may take its address)
            pray_object_release(c, o);
            o = scene_of(c, 1);
        }
        std::vector<float> got = render_rect(c, o, l, k == 0 ? 1 : 6);
        pray_ctx *d = pray_new();
        settings_of(d, k);
        pray_object *od = scene_of(d, which);
        pray_light *ld = light_of(d, lit);
        CHECK(got == render_rect(d, od, ld, 1));
        pray_free(d);
        seen.push_back(got);
    }
    CHECK(seen[1] == seen[0]);  // (steps 1 and 7 change nothing: the kept scene is used)
    for (int k = 2; k < 7; k++) CHECK(seen[k] != seen[k - 1]);  // (every other step changes the picture)
    CHECK(seen[7] == seen[6]);
    // a program run on the context after: as on a fresh one
    const char *prog = "rendertiff sphere(phong({0.2, 0.7, 0.3}, {0.3}, 5), [0, 0, 0], 0.6), dirlight({1}, <0, 0, 1>)\n";
    std::vector<testkit::Frame> a, b;
    pray_set_frame(c, testkit::frame_sink, &a);
    REQUIRE(pray_run_string(c, "p.ray", prog, strlen(prog)) == PRAY_OK);
    pray_ctx *d = pray_new();
    settings_of(d, 7);
    pray_set_frame(d, testkit::frame_sink, &b);
    REQUIRE(pray_run_string(d, "p.ray", prog, strlen(prog)) == PRAY_OK);
    REQUIRE(a.size() == 1);
    REQUIRE(b.size() == 1);
    CHECK(a[0].pixels == b[0].pixels);
    pray_free(d);
    // and the scene kept from before is rendered again as it was
    CHECK(render_rect(c, o, l, 3) == seen[7]);
    pray_object_release(c, o);
    pray_light_release(c, l);
    pray_free(c);
}

namespace {
// Balls on a floor, and step k of the cameras of the test below (with the settings it needs).
pray_object *balls_of(pray_ctx *c) {
    pray_rgb red = {0.8, 0.2, 0.1};
    pray_model *m = pray_phong(c, red, GREY, GREY, 8);
    pray_vec at = {0, 0, 0}, up = {0, 0, 1};
    pray_object *o = pray_plane(c, m, at, up);
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 4; j++) {
            pray_vec p = {i - 2.0, j - 2.0, 0.4};
            o = pray_csg(c, PRAY_UNION, o, pray_sphere(c, m, p, 0.4));
        }
    pray_release(c, m);
    return o;
}
void camera_of(pray_ctx *c, int k) {
    pray_option(c, "width", 128);
    pray_option(c, "height", 96);
    pray_option(c, "antialias", 4);  // (samples enough for the eye's buffer)
    pray_option(c, "eyebuffer", k >= 3 ? 0 : 1);
    pray_vec eye = {k < 2 ? -7.0 : k < 4 ? 3.0 : 8.0, -9, 3}, look = {k == 0 ? 0.0 : 2.0, 1, 0}, up = {0, 0, 1}, y = {0, 0, -4};
    pray_vec x = {4, 0, 0};
    if (k == 5) pray_parallel(c, x, y, eye, look);
    else pray_lookat(c, eye, look, up, 50);
}
} // namespace

TEST_CASE("api: pray_render_into keeps its preparation for a camera turned about its eye, or moved without an eye's buffer") {
    // step: 0 the first view; 1 turned (kept); 2 the eye moved, which its buffer depends on (prepared
    // again); 3 option eyebuffer 0 (prepared again, the same picture); 4 the eye moved, no eye's
    // buffer (kept); 5 a parallel camera (prepared again). Each against a fresh context, bit for bit.
    const bool kept[6] = {false, true, false, false, true, false};
    pray_ctx *c = pray_new();
    pray_object *o = balls_of(c);
    pray_light *l = light_of(c, 1);
    std::vector<float> before;
    for (int k = 0; k < 6; k++) {
        CAPTURE(k);
        camera_of(c, k);
        pray_stats_reset(c);
        std::vector<float> px((size_t)128 * 96 * 3), fresh(px.size());
        pray_buffers out = {px.data(), nullptr, nullptr, nullptr, 0, nullptr, nullptr, 0};
        REQUIRE(pray_render_into(c, o, l, nullptr, &out) == PRAY_OK);
        pray_stats st;
        pray_stats_get(c, &st);
        CHECK((st.memory_accel == 0) == kept[k]);  // (no structure built: the kept one was used)
        if (k == 0) REQUIRE(st.eyebuf_voxels > 0);  // (so that moving the eye matters)
        pray_ctx *d = pray_new();
        camera_of(d, k);
        pray_object *od = balls_of(d);
        out.rgb = fresh.data();
        REQUIRE(pray_render_into(d, od, light_of(d, 1), nullptr, &out) == PRAY_OK);
        CHECK(px == fresh);
        CHECK((px != before) == (k != 3));
        before = px;
        pray_free(d);
    }
    pray_free(c);
}

TEST_CASE("api: a scene prepared for rendering is rendered by other contexts on their threads, to the same bits") {
    pray_ctx *c = pray_new();
    settings_of(c, 4);
    pray_option(c, "antialias", 2);
    pray_option(c, "adaptive", 0.05);  // (undersampling: bands of tiles, from the scene's options)
    pray_object *o = scene_of(c, 0);
    pray_light *l = light_of(c, 1);
    std::vector<float> whole = render_rect(c, o, l, 1);
    pray_scene *q = pray_prepare_render(c, o, l);
    REQUIRE(q);
    pray_object_release(c, o);  // (the scene needs neither)
    pray_light_release(c, l);
    // four contexts at once, with other options of their own: the scene's are those it was made with
    std::vector<float> bands(whole.size());
    std::vector<std::thread> threads;
    std::atomic<int> failed(0);
    for (int k = 0; k < 4; k++)
        threads.emplace_back([&, k] {
            pray_ctx *d = pray_new();
            pray_option(d, "width", 8);
            pray_option(d, "antialias", 1);
            pray_option(d, "threads", 1 + k % 2);
            pray_rect r = {0, 30 * k / 4, 40, 30 * (k + 1) / 4 - 30 * k / 4};
            pray_buffers out = {bands.data() + (size_t)3 * 40 * r.y, nullptr, nullptr, nullptr, 40, nullptr, nullptr, 0};
            if (pray_render_prepared(d, q, &r, &out) != PRAY_OK) failed++;
            pray_free(d);
        });
    for (auto &t : threads) t.join();
    CHECK(failed == 0);
    CHECK(bands == whole);
    // its own context queries it as any prepared scene
    pray_hit h;
    pray_vec from = {3, -2, 1}, towards = {-3, 2, -1};
    CHECK(pray_intersect(c, q, from, towards, HUGE_VAL, &h, 1) >= 1);
    // what it refuses
    pray_ctx *d = pray_new();
    pray_buffers none = {nullptr, nullptr, nullptr, nullptr, 0, nullptr, nullptr, 0};
    pray_buffers one = {bands.data(), nullptr, nullptr, nullptr, 0, nullptr, nullptr, 0};
    pray_rect outside = {0, 20, 40, 11};
    CHECK(pray_render_prepared(d, nullptr, nullptr, &one) == PRAY_ERR_ARG);
    CHECK(std::string(pray_error(d)) == "error: pray_render_prepared: no scene");
    pray_clear_error(d);
    CHECK(pray_render_prepared(d, q, nullptr, &none) == PRAY_ERR_ARG);
    CHECK(std::string(pray_error(d)) == "error: pray_render_prepared: no buffers");
    pray_clear_error(d);
    CHECK(pray_render_prepared(d, q, &outside, &one) == PRAY_ERR_ARG);
    CHECK(std::string(pray_error(d)) == "error: pray_render_prepared: the rectangle of 40 x 11 pixels at (0, 20) is "
                                        "not inside the image of 40 x 30");
    pray_clear_error(d);
    pray_object *b = ball(c);
    pray_scene *queries = pray_prepare(c, b);
    CHECK(pray_render_prepared(d, queries, nullptr, &one) == PRAY_ERR_ARG);
    CHECK(std::string(pray_error(d)) == "error: pray_render_prepared: the scene was prepared for ray queries (pray_prepare)");
    CHECK(pray_render_prepared(nullptr, q, nullptr, &one) == PRAY_ERR_ARG);
    CHECK(pray_prepare_render(c, nullptr, nullptr) == nullptr);
    pray_free(d);
    pray_object_release(c, b);
    pray_free(c);
}

TEST_CASE("api: an image as 8-bit samples in the host's buffer holds the bytes of its 8-bit file") {
    pray_ctx *c = pray_new();
    pray_image img;
    REQUIRE(pray_image_new(c, 7, 5, &img) == PRAY_OK);
    for (int i = 0; i < 7 * 5 * 3; i++) img.pixels[i] = (float)((i * 37) % 101) / 97.0f - 0.02f;  // (below 0, over 1)
    img.pixels[4] = 0.5f / 255;  // (a sample halfway between two steps)
    std::string ppm;
    pray_write_fn sink = [](void *ud, const void *p, size_t n) { static_cast<std::string *>(ud)->append((const char *)p, n); };
    REQUIRE(pray_write_ppm(c, &img, 8, sink, &ppm) == PRAY_OK);
    std::vector<unsigned char> rgb(7 * 5 * 3), rgba(7 * 5 * 4);
    REQUIRE(pray_image_bytes(c, &img, 3, rgb.data()) == PRAY_OK);
    REQUIRE(pray_image_bytes(c, &img, 4, rgba.data()) == PRAY_OK);
    const std::string head = "P6\n7 5\n255\n";
    REQUIRE(ppm.size() == head.size() + rgb.size());
    CHECK(std::string(rgb.begin(), rgb.end()) == ppm.substr(head.size()));
    for (int i = 0; i < 7 * 5; i++) {
        CHECK(rgba[4 * i + 3] == 255);
        for (int k = 0; k < 3; k++) CHECK(rgba[4 * i + k] == rgb[3 * i + k]);
    }
    CHECK(rgb[0] == 0);  // (-0.02: black)
    CHECK(rgb[4] == 1);
    // sRGB: the curve of IEC 61966-2-1 at exact points (0.5 -> 0.7354 -> 188; 0.002 -> 0.02584 -> 7;
    // 0.2 -> 0.4845 -> 124), and the alpha channel
    float keep[3] = {img.pixels[0], img.pixels[1], img.pixels[2]};
    img.pixels[0] = 0.5f, img.pixels[1] = 0.002f, img.pixels[2] = 0.2f;
    std::vector<unsigned char> srgb(7 * 5 * 4);
    REQUIRE(pray_image_bytes(c, &img, 4 + PRAY_BYTES_SRGB, srgb.data()) == PRAY_OK);
    CHECK((srgb[0] == 188 && srgb[1] == 7 && srgb[2] == 124 && srgb[3] == 255));
    for (int i = 3; i < 7 * 5 * 3; i++) {  // the others: the curve of the same samples
        double v = img.pixels[i], e = v <= 0 ? 0 : v >= 1 ? 1 : v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1 / 2.4) - 0.055;
        CHECK(srgb[i / 3 * 4 + i % 3] == (unsigned char)(e * 255 + 0.5));
    }
    REQUIRE(pray_image_bytes(c, &img, 3 + PRAY_BYTES_SRGB, rgb.data()) == PRAY_OK);
    CHECK((rgb[0] == 188 && rgb[1] == 7 && rgb[2] == 124));
    img.pixels[0] = keep[0], img.pixels[1] = keep[1], img.pixels[2] = keep[2];
    CHECK(pray_image_bytes(c, &img, 2, rgb.data()) == PRAY_ERR_ARG);
    CHECK(std::string(pray_error(c)) == "error: pray_image_bytes: channels must be 3 or 4 (+ PRAY_BYTES_SRGB)");
    CHECK(pray_image_bytes(c, &img, 5 + PRAY_BYTES_SRGB, rgb.data()) == PRAY_ERR_ARG);
    CHECK(pray_image_bytes(c, &img, 3, nullptr) == PRAY_ERR_ARG);
    CHECK(pray_image_bytes(c, nullptr, 3, rgb.data()) == PRAY_ERR_ARG);
    CHECK(pray_image_bytes(nullptr, &img, 3, rgb.data()) == PRAY_ERR_ARG);
    pray_image_free(c, &img);
    pray_free(c);
}

TEST_CASE("api: the place of a program's error as numbers, and statistics counted again from zero") {
    pray_ctx *c = pray_new();
    int line = -1, col = -1;
    CHECK(pray_error_place(c, &line, &col) == nullptr);
    CHECK(line == 0);
    CHECK(col == 0);
    const char *prog = "A = 1\nB = 2\nC = A +  nothing_here\n";
    REQUIRE(pray_run_string(c, "p.ray", prog, strlen(prog)) != PRAY_OK);
    const char *name = pray_error_place(c, &line, &col);
    REQUIRE(name);
    CHECK(std::string(name) == "p.ray");
    CHECK(line == 3);
    CHECK(col == 10);
    CHECK(std::string(pray_error(c)).compare(0, 12, "p.ray:3:10: ") == 0);
    CHECK(pray_error_place(c, nullptr, nullptr) == std::string("p.ray"));
    // an error with no place in a program, and none at all
    pray_clear_error(c);
    CHECK(pray_sphere(c, nullptr, ORIGIN, 1) == nullptr);
    CHECK(pray_error_place(c, &line, &col) == nullptr);
    CHECK(line == 0);
    pray_clear_error(c);
    REQUIRE(pray_run_string(c, "q.ray", "X = 1 +\n", 8) != PRAY_OK);
    CHECK(pray_error_place(c, &line, &col) != nullptr);
    pray_clear_error(c);
    CHECK(pray_error_place(c, &line, &col) == nullptr);
    // statistics: a render's, then zero, then the next render's alone (as a fresh context's)
    pray_option(c, "width", 16);
    pray_option(c, "height", 16);
    pray_object *o = ball(c);
    pray_light *l = pray_dirlight(c, WHITE, ONE);
    pray_image img;
    REQUIRE(pray_render(c, o, l, &img) == PRAY_OK);
    pray_image_free(c, &img);
    pray_stats s;
    pray_stats_get(c, &s);
    CHECK(s.rays_primary == 256);
    pray_stats_reset(c);
    pray_stats_get(c, &s);
    CHECK(s.rays_primary == 0);
    CHECK(s.primitives == 0);
    CHECK(s.time_render == 0);
    REQUIRE(pray_render(c, o, l, &img) == PRAY_OK);
    pray_image_free(c, &img);
    pray_stats_get(c, &s);
    CHECK(s.rays_primary == 256);
    CHECK(s.rays_shadow > 0);
    pray_stats_reset(nullptr);
    CHECK(pray_error_place(nullptr, &line, &col) == nullptr);
    CHECK(pray_prepare_render(nullptr, o, l) == nullptr);
    pray_object_release(c, o);
    pray_light_release(c, l);
    pray_free(c);
}
