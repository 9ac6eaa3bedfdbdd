// Parts of a render (docs/distributed.md): the render function of the API (pray_set_render),
// notes in image files, and the command line's --rows, --part, --frames and --join. Whatever the
// split, the stacked parts are the bytes of one whole render. The command-line cases run ./pray
// from the repository root (POSIX: mkdtemp, popen).
#include <doctest/doctest.h>

#include "../pray.hpp"
#include "testkit.hpp"
#include "tempfiles.hpp"

#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace {

typedef testkit::TempDir Dir;
using testkit::slurp;
using testkit::spit;

std::string q(const std::string &s) {
    std::string r = "'";
    for (char ch : s) r += ch == '\'' ? std::string("'\\''") : std::string(1, ch);
    return r + "'";
}

// Exit status of a shell command; *out gets its standard output and error.
int sh(const std::string &cmd, std::string *out = nullptr) {
    FILE *p = popen((cmd + " 2>&1").c_str(), "r");
    if (!p) return -1;
    std::string s;
    char buf[4096];
    size_t n;
    while ((n = fread(buf, 1, sizeof buf, p)) > 0) s.append(buf, n);
    int st = pclose(p);
    if (out) *out = s;
    return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

std::string pray_cmd(const std::string &args) { return testkit::pray_shell() + " --quiet " + args; }

bool have_pray() {
    std::error_code ec;
    return fs::exists(testkit::pray_program(), ec) && fs::exists("examples/anim.ray", ec);
}

// A scene with mirrors, refraction and fine detail, in three frames, for antialias and adaptive.
const char *SCENE =
    "perspective <1.5, 0, 0>, <0, 0, 1.125>, [0, -4, 0.5], [0, 0, 0]\n"
    "background {0.1, 0.2, 0.4}, {0.9}\n"
    "Floor = plane(phong({0.6, 0.6, 0.5}, {0.2}, 9), [0, 0, -0.6], <0, 0, 1>)\n"
    "Ball = sphere(mirror({0.6}) + phong({0.3, 0.1, 0.1}, {0.4}, 20), [0, 0, 0], 0.5)\n"
    "Glass = sphere(transparent({0.8}, 1.5), [0.8, -0.6, -0.2], 0.3)\n"
    "Cut = cylinder(phong({0.1, 0.7, 0.2}, {0.3}, 5), [-0.9, 0, 0], <0, 0, 1>, 0.3) - sphere(color({1}), [-0.9, -0.2, 0.2], 0.25)\n"
    "F = 0\n"
    "while F < 3\n"
    "  rendertiff Floor | Ball | Glass | Cut . [0.2 * F, 0, 0], pointlight({1}, [2, -3, 4]) + dirlight({0.3}, <-1, -1, 1>)\n"
    "  F = F + 1\n"
    "endwhile\n";

struct Captured {
    std::vector<testkit::Frame> frames;
    std::vector<int> numbers;  // pray_frames at each frame callback
    pray_ctx *c = nullptr;
};

pray_status capture(void *ud, const pray_image *img, const char *name) {
    Captured *cap = (Captured *)ud;
    cap->numbers.push_back(pray_frames(cap->c));
    return testkit::frame_sink(&cap->frames, img, name);
}

void set_options(pray_ctx *c) {
    pray_option(c, "width", 48);
    pray_option(c, "height", 36);
    pray_option(c, "antialias", 2);
    pray_option(c, "adaptive", 0.05);
}

// The whole run, rendered by pray.
std::vector<testkit::Frame> whole_run() {
    Captured cap;
    cap.c = pray_new();
    set_options(cap.c);
    pray_set_frame(cap.c, capture, &cap);
    REQUIRE(pray_run_string(cap.c, "scene.ray", SCENE, strlen(SCENE)) == PRAY_OK);
    pray_free(cap.c);
    return cap.frames;
}

// A render function that keeps frame `only` (-1: all) and of it rows y0 .. y1-1, rendered as two
// bands, as pray-mpi does: the program's tree stays whole for the second.
struct Rows {
    int only, y0, y1;
    std::vector<int> seen;
};
pray_status render_rows(void *ud, pray_ctx *c, pray_object *root, pray_light *lights, int frame, pray_image *out) {
    Rows *r = (Rows *)ud;
    r->seen.push_back(frame);
    if (r->only >= 0 && frame != r->only) return PRAY_OK;
    int w = (int)pray_option_get(c, "width");
    pray_status st = pray_image_new(c, w, r->y1 - r->y0, out);
    if (st != PRAY_OK) return st;
    int mid = (r->y0 + r->y1 + 1) / 2;
    pray_rect top = {0, r->y0, w, mid - r->y0}, rest = {0, mid, w, r->y1 - mid};
    pray_buffers b = {out->pixels, NULL, NULL, NULL, 0, NULL, NULL, 0};
    st = pray_render_into(c, root, lights, &top, &b);
    if (st != PRAY_OK || rest.height == 0) return st;
    b.rgb = out->pixels + (size_t)3 * w * top.height;
    return pray_render_into(c, root, lights, &rest, &b);
}

} // namespace

TEST_CASE("parts: a render function renders rows and skips frames; the rows are those of the whole run") {
    std::vector<testkit::Frame> whole = whole_run();
    REQUIRE(whole.size() == 3);
    const int cuts[] = {0, 5, 17, 18, 36};
    for (int only = 0; only < 3; only++) {
        std::vector<float> stacked;
        for (int i = 0; i < 4; i++) {
            Captured cap;
            Rows r = {only, cuts[i], cuts[i + 1], {}};
            cap.c = pray_new();
            set_options(cap.c);
            pray_set_render(cap.c, render_rows, &r);
            pray_set_frame(cap.c, capture, &cap);
            REQUIRE(pray_run_string(cap.c, "scene.ray", SCENE, strlen(SCENE)) == PRAY_OK);
            CHECK(pray_frames(cap.c) == 3);  // skipped frames count
            CHECK(r.seen == std::vector<int>({0, 1, 2}));
            pray_free(cap.c);
            // one frame reaches the frame callback, under the name of the whole run, as frame `only`
            REQUIRE(cap.frames.size() == 1);
            CHECK(cap.frames[0].name == whole[only].name);
            CHECK(cap.numbers[0] == only);
            CHECK(cap.frames[0].width == 48);
            CHECK(cap.frames[0].height == cuts[i + 1] - cuts[i]);
            stacked.insert(stacked.end(), cap.frames[0].pixels.begin(), cap.frames[0].pixels.end());
        }
        REQUIRE(stacked.size() == whole[only].pixels.size());
        CHECK(memcmp(stacked.data(), whole[only].pixels.data(), stacked.size() * sizeof(float)) == 0);
    }
}

namespace {
pray_status whole_frame(void *, pray_ctx *c, pray_object *root, pray_light *lights, int, pray_image *out) {
    return pray_render(c, root, lights, out);  // inside the render function: pray renders
}
pray_status refuse(void *, pray_ctx *c, pray_object *, pray_light *, int frame, pray_image *) {
    return frame == 1 ? pray_set_error(c, PRAY_ERR_LIMIT, "frame 1 is not wanted") : PRAY_OK;
}
pray_status silent(void *, pray_ctx *, pray_object *, pray_light *, int frame, pray_image *) {
    return frame == 2 ? PRAY_ERR_RUNTIME : PRAY_OK;
}
} // namespace

TEST_CASE("parts: a render function that renders everything, or fails with its message") {
    std::vector<testkit::Frame> whole = whole_run();
    Captured cap;
    cap.c = pray_new();
    set_options(cap.c);
    pray_set_render(cap.c, whole_frame, NULL);
    pray_set_frame(cap.c, capture, &cap);
    REQUIRE(pray_run_string(cap.c, "scene.ray", SCENE, strlen(SCENE)) == PRAY_OK);
    REQUIRE(cap.frames.size() == 3);
    for (int i = 0; i < 3; i++) CHECK(cap.frames[i].pixels == whole[i].pixels);
    // failures stop the program at its rendertiff, with the function's message
    pray_set_render(cap.c, refuse, NULL);
    CHECK(pray_run_string(cap.c, "scene.ray", SCENE, strlen(SCENE)) == PRAY_ERR_LIMIT);
    CHECK(std::string(pray_error(cap.c)) == "scene.ray:9:3: error: frame 1 is not wanted");
    pray_set_render(cap.c, silent, NULL);
    CHECK(pray_run_string(cap.c, "scene.ray", SCENE, strlen(SCENE)) == PRAY_ERR_RUNTIME);
    CHECK(std::string(pray_error(cap.c)) == "scene.ray:9:3: error: the render function failed");
    // outside a run, pray_render renders as always; NULL takes the function away
    pray_object *s = pray_sphere(cap.c, pray_color(cap.c, {1, 0, 0}), {0, 0, 0}, 0.5);
    pray_image img;
    CHECK(pray_render(cap.c, s, NULL, &img) == PRAY_OK);
    CHECK(img.width == 48);
    pray_set_render(cap.c, NULL, NULL);
    cap.frames.clear();
    REQUIRE(pray_run_string(cap.c, "scene.ray", SCENE, strlen(SCENE)) == PRAY_OK);
    CHECK(cap.frames.size() == 3);
    pray_free(cap.c);
}

TEST_CASE("parts: pray_image_new, pray_set_error and notes in image files") {
    Dir d;
    pray_ctx *c = pray_new();
    pray_image img;
    CHECK(pray_image_new(c, 0, 5, &img) == PRAY_ERR_ARG);
    CHECK(img.pixels == nullptr);
    CHECK(pray_image_new(c, 70000, 1, &img) == PRAY_ERR_ARG);
    CHECK(pray_image_new(c, 65536, 65536, &img) == PRAY_ERR_ARG);
    CHECK(pray_image_new(c, 5, 4, nullptr) == PRAY_ERR_ARG);
    CHECK(pray_image_new(nullptr, 5, 4, &img) == PRAY_ERR_ARG);
    REQUIRE(pray_image_new(c, 5, 4, &img) == PRAY_OK);
    CHECK(img.width == 5);
    CHECK(img.height == 4);
    for (int i = 0; i < 5 * 4 * 3; i++) {
        CHECK(img.pixels[i] == 0);
        img.pixels[i] = (float)(i % 7) / 6;
    }
    // a note changes the header only: TIFF gets an ImageDescription, PPM a comment line
    REQUIRE(pray_write_image(c, &img, (d / "a.tif").c_str(), 16) == PRAY_OK);
    REQUIRE(pray_write_image_note(c, &img, (d / "b.tif").c_str(), 16, "hello there") == PRAY_OK);
    std::string a = slurp(d / "a.tif"), b = slurp(d / "b.tif");
    CHECK(b.size() == a.size() + 12 + 12);
    CHECK(a.substr(a.size() - 120) == b.substr(b.size() - 120));
    CHECK(b.find(std::string("hello there\0", 12)) != std::string::npos);
    if (sh("command -v tiffinfo") == 0) {
        std::string info;
        CHECK(sh("tiffinfo " + q(d / "b.tif"), &info) == 0);
        CHECK(info.find("ImageDescription: hello there") != std::string::npos);
    }
    REQUIRE(pray_write_image(c, &img, (d / "a.ppm").c_str(), 8) == PRAY_OK);
    REQUIRE(pray_write_image_note(c, &img, (d / "b.ppm").c_str(), 8, "rows 0:4") == PRAY_OK);
    CHECK(slurp(d / "b.ppm") == "P6\n# rows 0:4\n" + slurp(d / "a.ppm").substr(3));
    // what a note cannot be
    CHECK(pray_write_image_note(c, &img, (d / "c.ppm").c_str(), 8, "two\nlines") == PRAY_ERR_ARG);
    CHECK(std::string(pray_error(c)) == "error: a note must be printable ASCII of at most 1000 characters");
    CHECK(pray_write_image_note(c, &img, (d / "c.ppm").c_str(), 8, std::string(1001, 'x').c_str()) == PRAY_ERR_ARG);
    CHECK(pray_write_image_note(c, &img, (d / "c.ppm").c_str(), 8, std::string(1000, 'x').c_str()) == PRAY_OK);
    CHECK(pray_write_image_note(c, &img, (d / "c.ppm").c_str(), 8, nullptr) == PRAY_ERR_ARG);
    if (std::string(pray_features()).find("png") != std::string::npos) {
        CHECK(pray_write_image_note(c, &img, (d / "c.png").c_str(), 8, "x") == PRAY_ERR_ARG);
        CHECK(std::string(pray_error(c)).find("notes go into TIFF and PPM files only") != std::string::npos);
    }
    CHECK(d.listing() == "a.ppm a.tif b.ppm b.tif c.ppm");
    pray_image_free(c, &img);
    // pray_set_error
    CHECK(pray_set_error(c, PRAY_ERR_IO, "the disk is full") == PRAY_ERR_IO);
    CHECK(std::string(pray_error(c)) == "error: the disk is full");
    CHECK(pray_last_status(c) == PRAY_ERR_IO);
    CHECK(pray_set_error(c, 99, nullptr) == PRAY_ERR_ARG);
    CHECK(std::string(pray_error(c)) == "error: bad argument");
    CHECK(pray_set_error(c, 12345, "unknown") == PRAY_ERR_ARG);
    CHECK(pray_set_error(c, -1, "negative") == PRAY_ERR_ARG);
    CHECK(std::string(pray_error(c)) == "error: negative");
    CHECK(pray_set_error(c, PRAY_ERR_CANCELLED, NULL) == PRAY_ERR_CANCELLED);
    CHECK(std::string(pray_error(c)) == "error: cancelled");
    CHECK(pray_set_error(c, PRAY_OK, "ignored") == PRAY_OK);
    CHECK(std::string(pray_error(c)) == "");
    CHECK(pray_set_error(nullptr, PRAY_ERR_IO, "x") == PRAY_ERR_ARG);
    pray_free(c);
}

// =============================================================================================
// The command line: --rows, --part, --frames, --join
// =============================================================================================
TEST_CASE("command line: --rows and --part of every frame, --join gives the bytes of the whole render") {
    REQUIRE_MESSAGE(have_pray(), "./pray or examples/ missing: run from the repository root after make");
    Dir d;
    spit(d / "scene.ray", SCENE);
    std::string opts = "-s 48x36 -D antialias=2 -D adaptive=0.05 ", out;
    REQUIRE(sh(pray_cmd(opts + "-o " + q(d / "w.tif") + " " + q(d / "scene.ray")), &out) == 0);
    // uneven bands by --rows, in TIFF; then 4 equal bands by --part, in 16-bit PPM
    const char *rows[] = {"0:5", "5:17", "17:18", "18:36"};
    for (int i = 0; i < 4; i++)
        REQUIRE(sh(pray_cmd(opts + "--rows " + rows[i] + " -o " + q(d / ("r" + std::to_string(i) + ".tif")) + " " +
                            q(d / "scene.ray")), &out) == 0);
    REQUIRE(sh(pray_cmd(opts + "-D bits=16 -o " + q(d / "w.ppm") + " " + q(d / "scene.ray")), &out) == 0);
    for (int k = 1; k <= 4; k++)
        REQUIRE(sh(pray_cmd(opts + "-D bits=16 --part " + std::to_string(k) + "/4 -o " +
                            q(d / ("p" + std::to_string(k) + ".ppm")) + " " + q(d / "scene.ray")), &out) == 0);
    CHECK(slurp(d / "r1.tif").find("pray-part rows=5:17 height=36 frame=0 id=") != std::string::npos);
    CHECK(slurp(d / "p2_0002.ppm").substr(0, 39) == "P6\n# pray-part rows=9:18 height=36 fram");
    for (const char *f : {"", "_0001", "_0002"}) {
        std::string sfx = f;
        // given in any order
        REQUIRE(sh(testkit::pray_shell() + " --join " + q(d / ("j" + sfx + ".tif")) + " " + q(d / ("r3" + sfx + ".tif")) +
                   " " + q(d / ("r0" + sfx + ".tif")) + " " + q(d / ("r2" + sfx + ".tif")) + " " +
                   q(d / ("r1" + sfx + ".tif")), &out) == 0);
        CHECK(out == "");
        CHECK(slurp(d / ("j" + sfx + ".tif")) == slurp(d / ("w" + sfx + ".tif")));
        REQUIRE(sh(testkit::pray_shell() + " --join " + q(d / ("j" + sfx + ".ppm")) + " " + q(d / ("p1" + sfx + ".ppm")) +
                   " " + q(d / ("p2" + sfx + ".ppm")) + " " + q(d / ("p3" + sfx + ".ppm")) + " " +
                   q(d / ("p4" + sfx + ".ppm")), &out) == 0);
        CHECK(slurp(d / ("j" + sfx + ".ppm")) == slurp(d / ("w" + sfx + ".ppm")));
    }
    // 8-bit parts joined into another format: the bytes pray writes in that format
    REQUIRE(sh(testkit::pray_shell() + " --join " + q(d / "x.ppm") + " " + q(d / "r0.tif") + " " + q(d / "r1.tif") + " " +
               q(d / "r2.tif") + " " + q(d / "r3.tif"), &out) == 0);
    REQUIRE(sh(pray_cmd(opts + "-o " + q(d / "w8.ppm") + " " + q(d / "scene.ray")), &out) == 0);
    CHECK(slurp(d / "x.ppm") == slurp(d / "w8.ppm"));
}

TEST_CASE("command line: --frames writes the frames asked for, under the names of the whole run") {
    REQUIRE_MESSAGE(have_pray(), "./pray or examples/ missing: run from the repository root after make");
    Dir d;
    std::string out, opts = "-s 64x48 -D antialias=2 -D adaptive=0.1 ";
    REQUIRE(sh(pray_cmd(opts + "-o " + q(d / "a###.tif") + " examples/anim.ray"), &out) == 0);
    REQUIRE(sh(pray_cmd(opts + "--frames 1:2 -o " + q(d / "b###.tif") + " examples/anim.ray"), &out) == 0);
    CHECK(out.find("frame 2 turned") != std::string::npos);  // every statement ran
    CHECK(d.listing() == "a000.tif a001.tif a002.tif b001.tif");
    CHECK(slurp(d / "b001.tif") == slurp(d / "a001.tif"));
    // --frames with --part: rows of the frames asked for
    REQUIRE(sh(pray_cmd(opts + "--frames 2:9 --part 2/2 -o " + q(d / "c###.tif") + " examples/anim.ray"), &out) == 0);
    CHECK(d.listing() == "a000.tif a001.tif a002.tif b001.tif c002.tif");
    CHECK(slurp(d / "c002.tif").find("pray-part rows=24:48 height=48 frame=2 id=") != std::string::npos);
    // no frame at all in the range: an error
    CHECK(sh(pray_cmd(opts + "--frames 3:5 -o " + q(d / "e###.tif") + " examples/anim.ray"), &out) == 1);
    CHECK(out.find("pray: error: --frames 3:5 selects no frame: the program renders frames 0:3\n") != std::string::npos);
    CHECK(d.listing() == "a000.tif a001.tif a002.tif b001.tif c002.tif");
}

TEST_CASE("command line: bad splits and parts that do not belong together: a clear error, nothing written") {
    REQUIRE_MESSAGE(have_pray(), "./pray or examples/ missing: run from the repository root after make");
    Dir d;
    std::string out;
    std::string usage = "\nrun 'pray --help' for the options\n";
    struct Bad {
        const char *args;
        int rc;
        const char *message;
    } bad[] = {
        {"--rows 5:3", 2, "pray: --rows takes A:B, rows A to B-1 with A < B counted from 0, as in --rows 0:64, not '5:3'"},
        {"--rows 4:4", 2, "pray: --rows takes A:B, rows A to B-1 with A < B counted from 0, as in --rows 0:64, not '4:4'"},
        {"--rows -1:3", 2, "pray: --rows takes A:B, rows A to B-1 with A < B counted from 0, as in --rows 0:64, not '-1:3'"},
        {"--rows 1:2x", 2, "pray: --rows takes A:B, rows A to B-1 with A < B counted from 0, as in --rows 0:64, not '1:2x'"},
        {"--part 0/4", 2, "pray: --part takes K/N, the K-th of N bands of rows with K from 1 to N, as in --part 1/4, not '0/4'"},
        {"--part 5/4", 2, "pray: --part takes K/N, the K-th of N bands of rows with K from 1 to N, as in --part 1/4, not '5/4'"},
        {"--part 1/0", 2, "pray: --part takes K/N, the K-th of N bands of rows with K from 1 to N, as in --part 1/4, not '1/0'"},
        {"--frames 2:1", 2, "pray: --frames takes A:B, frames A to B-1 with A < B counted from 0, as in --frames 0:10, not '2:1'"},
        {"--rows 0:4 --part 1/2", 2, "pray: give --rows or --part, not both"},
        {"--rows", 2, "pray: option --rows needs a value"},
    };
    for (const Bad &b : bad) {
        CAPTURE(b.args);
        CHECK(sh(testkit::pray_shell() + " -s 8x8 -o " + q(d / "x.tif") + " examples/redsph.ray " + b.args, &out) ==
              b.rc);
        CHECK(out == std::string(b.message) + usage);
    }
    // rows that the image does not have, found when the frame is rendered
    CHECK(sh(pray_cmd("-s 8x8 --rows 4:9 -o " + q(d / "x.tif") + " examples/redsph.ray"), &out) == 1);
    CHECK(out == "examples/redsph.ray:9:1: error: --rows 4:9 is not inside the image of 8 rows\n");
    CHECK(sh(pray_cmd("-s 8x8 --part 3/9 -o " + q(d / "x.tif") + " examples/redsph.ray"), &out) == 1);
    CHECK(out == "examples/redsph.ray:9:1: error: --part 3/9: an image of 8 rows cannot be cut into 9 parts\n");
    if (std::string(pray_features()).find("png") != std::string::npos) {
        CHECK(sh(pray_cmd("-s 8x8 --part 1/2 -o " + q(d / "x.png") + " examples/redsph.ray"), &out) == 1);
        CHECK(out.find("error: row parts are written as .tif or .ppm, not as '") != std::string::npos);
    }
    CHECK(d.listing() == "");

    // parts to join: 32 rows of csg.ray in 4 parts; others of other widths, frames, programs
    std::string csg = " examples/csg.ray";
    for (int k = 1; k <= 4; k++)
        REQUIRE(sh(pray_cmd("-s 32x32 --part " + std::to_string(k) + "/4 -o " + q(d / ("p" + std::to_string(k) + ".tif")) +
                            csg), &out) == 0);
    REQUIRE(sh(pray_cmd("-s 32x32 --rows 4:12 -o " + q(d / "over.tif") + csg), &out) == 0);
    REQUIRE(sh(pray_cmd("-s 33x32 --part 4/4 -o " + q(d / "wide.tif") + csg), &out) == 0);
    REQUIRE(sh(pray_cmd("-s 32x32 -D bits=16 --part 4/4 -o " + q(d / "bits.tif") + csg), &out) == 0);
    REQUIRE(sh(pray_cmd("-s 32x32 -D antialias=2 --part 4/4 -o " + q(d / "aa.tif") + csg), &out) == 0);
    REQUIRE(sh(pray_cmd("-s 32x32 --part 4/4 -o " + q(d / "other.tif") + " examples/redsph.ray"), &out) == 0);
    REQUIRE(sh(pray_cmd("-s 32x40 --part 4/4 -o " + q(d / "tall.tif") + csg), &out) == 0);
    REQUIRE(sh(pray_cmd("-s 32x32 --part 4/4 -o " + q(d / "f###.tif") + " examples/anim.ray >/dev/null"), &out) == 0);
    REQUIRE(sh(pray_cmd("-s 32x32 -o " + q(d / "plain.tif") + csg), &out) == 0);
    spit(d / "junk.tif", "II*\0 not much of a TIFF");
    std::string p123 = " " + q(d / "p1.tif") + " " + q(d / "p2.tif") + " " + q(d / "p3.tif");
    std::string before = d.listing();
    struct Join {
        std::string parts;
        int rc;
        std::string message;
    } joins[] = {
        {p123, 1, "pray: error: rows 24:32 of the image are missing (no part holds them)\n"},
        {" " + q(d / "p1.tif") + " " + q(d / "p3.tif") + " " + q(d / "p4.tif"), 1,
         "pray: error: rows 8:16 of the image are missing (no part holds them)\n"},
        {" " + q(d / "p2.tif") + " " + q(d / "p3.tif") + " " + q(d / "p4.tif"), 1,
         "pray: error: rows 0:8 of the image are missing (no part holds them)\n"},
        {p123 + " " + q(d / "p4.tif") + " " + q(d / "over.tif"), 1,
         "pray: error: '" + d / "p1.tif" + "' (rows 0:8) and '" + d / "over.tif" + "' (rows 4:12) overlap\n"},
        {p123 + " " + q(d / "wide.tif"), 1,
         "pray: error: '" + d / "p1.tif" + "' and '" + d / "wide.tif" + "' are parts of different images: 32 and 33 pixels wide\n"},
        {p123 + " " + q(d / "bits.tif"), 1,
         "pray: error: '" + d / "p1.tif" + "' and '" + d / "bits.tif" + "' are parts of different images: 8 and 16 bits\n"},
        {p123 + " " + q(d / "tall.tif"), 1,
         "pray: error: '" + d / "p1.tif" + "' and '" + d / "tall.tif" + "' are parts of different images: of 32 and 40 rows\n"},
        {p123 + " " + q(d / "f002.tif"), 1,
         "pray: error: '" + d / "p1.tif" + "' and '" + d / "f002.tif" + "' are parts of different images: frames 0 and 2\n"},
        {p123 + " " + q(d / "plain.tif"), 1,
         "pray: error: '" + d / "plain.tif" + "' is not a row part: it has no note of its rows (pray --rows or --part writes them)\n"},
        {p123 + " " + q(d / "junk.tif"), 1, "pray: error: '" + d / "junk.tif" + "' is not a TIFF or PPM file as pray writes them\n"},
        {p123 + " " + q(d / "none.tif"), 3, "pray: error: cannot open '" + d / "none.tif" + "': No such file or directory\n"},
    };
    for (const Join &j : joins) {
        CAPTURE(j.parts);
        CHECK(sh(testkit::pray_shell() + " --join " + q(d / "out.tif") + j.parts, &out) == j.rc);
        CHECK(out == j.message);
    }
    for (const char *other : {"aa.tif", "other.tif"}) {  // another render: the same sizes, another id
        CHECK(sh(testkit::pray_shell() + " --join " + q(d / "out.tif") + p123 + " " + q(d / other), &out) == 1);
        CHECK(out.find("are parts of different images: renders ") != std::string::npos);
        CHECK(out.find("(another program or other options)") != std::string::npos);
    }
    CHECK(sh(testkit::pray_shell() + " --join " + q(d / "out.png") + p123 + " " + q(d / "bits.tif"), &out) == 1);
    CHECK(sh(testkit::pray_shell() + " --join " + q(d / "out.tif"), &out) == 2);
    CHECK(out == "pray: --join takes the output file and the parts: --join OUT PART..." + usage);
    CHECK(sh(testkit::pray_shell() + " --join " + q(d / "out.tif") + " -q" + p123, &out) == 2);
    CHECK(sh(testkit::pray_shell() + " -q --join " + q(d / "out.tif") + p123, &out) == 2);
    CHECK(out == "pray: --join comes first: pray --join OUT PART..." + usage);
    CHECK(sh(testkit::pray_shell() + " --join " + q(d / "out.xyz") + p123 + " " + q(d / "p4.tif"), &out) == 2);
    CHECK(out.find("cannot tell the image format of") != std::string::npos);
    CHECK(d.listing() == before);
    // and the good join, for contrast
    CHECK(sh(testkit::pray_shell() + " --join " + q(d / "out.tif") + p123 + " " + q(d / "p4.tif"), &out) == 0);
    REQUIRE(sh(pray_cmd("-s 32x32 -o " + q(d / "whole.tif") + csg), &out) == 0);
    CHECK(slurp(d / "out.tif") == slurp(d / "whole.tif"));
}

TEST_CASE("command line: --join opens parts as programs, reads no more than their headers claim, never writes over one") {
    Dir d;
    std::string out;
    for (const char *k : {"1", "2"})
        REQUIRE(sh(pray_cmd(std::string("-s 16x16 --part ") + k + "/2 -o " + q(d / (std::string("p") + k + ".ppm")) +
                            " examples/csg.ray"), &out) == 0);
    REQUIRE(sh(pray_cmd("-s 16x16 --part 2/2 -o " + q(d / "p2.tif") + " examples/csg.ray"), &out) == 0);
    const std::string p1 = slurp(d / "p1.ppm"), p2 = slurp(d / "p2.ppm"), t2 = slurp(d / "p2.tif");
    REQUIRE(p2.size() == 16 * 8 * 3 + p2.find("\n255\n") + 5);
    // what is not a regular file is refused at once: a FIFO (which waited for a writer for ever),
    // a device that never ends (which grew memory until the allocator failed), a directory
    REQUIRE(mkfifo((d / "fifo.ppm").c_str(), 0600) == 0);
    fs::create_directory(d / "dir.ppm");
    for (std::string part : {d / "fifo.ppm", std::string("/dev/zero"), d / "dir.ppm"}) {
        CAPTURE(part);
        CHECK(sh("timeout 20 " + testkit::pray_shell() + " --join " + q(d / "out.ppm") + " " + q(d / "p1.ppm") + " " +
                     q(part), &out) == 3);
        CHECK(out == "pray: error: cannot read '" + part + "': not a regular file\n");
    }
    // the same as the program of --part and --rows, whose id is a hash of its bytes
    REQUIRE(mkfifo((d / "fifo.ray").c_str(), 0600) == 0);
    for (const char *split : {"--part 1/2", "--rows 0:4"}) {
        CAPTURE(split);
        CHECK(sh("timeout 20 " + pray_cmd(std::string("-s 8x8 ") + split + " -o " + q(d / "x.ppm") + " " +
                                          q(d / "fifo.ray")), &out) == 3);
        CHECK(out == "pray: error: cannot read '" + d / "fifo.ray" + "': not a regular file\n");
    }
    fs::remove(d / "fifo.ray");
    // a part cut short or longer than its header says (in both formats)
    spit(d / "short.ppm", p2.substr(0, p2.size() - 1));
    spit(d / "long.ppm", p2 + "x");
    spit(d / "short.tif", t2.substr(0, t2.size() - 7));
    spit(d / "long.tif", t2 + std::string(100000, 'x'));
    struct Size {
        const char *name;
        std::string message;
    } sizes[] = {
        {"short.ppm", "is cut short: its header says " + std::to_string(p2.size()) + " bytes, the file has " +
                          std::to_string(p2.size() - 1)},
        {"long.ppm", "has " + std::to_string(p2.size() + 1) + " bytes, more than the " + std::to_string(p2.size()) +
                         " its header says"},
        {"short.tif", "is cut short: its header says " + std::to_string(t2.size()) + " bytes, the file has " +
                          std::to_string(t2.size() - 7)},
        {"long.tif", "has " + std::to_string(t2.size() + 100000) + " bytes, more than the " +
                         std::to_string(t2.size()) + " its header says"},
    };
    for (const Size &z : sizes) {
        CAPTURE(z.name);
        CHECK(sh(testkit::pray_shell() + " --join " + q(d / "out.ppm") + " " + q(d / "p1.ppm") + " " + q(d / z.name),
                 &out) == 1);
        CHECK(out == "pray: error: '" + d / z.name + "' " + z.message + "\n");
    }
    // the output may not replace a part: by name, by another name of the same file, through a link
    fs::create_symlink("p1.ppm", d / "alias.ppm");
    fs::create_hard_link(d / "p2.ppm", d / "hard.ppm");
    struct Over {
        std::string out, parts, part;
    } overs[] = {
        {d / "p1.ppm", q(d / "p1.ppm") + " " + q(d / "p1.ppm") + " " + q(d / "p2.ppm"), d / "p1.ppm"},
        {d / "p2.ppm", q(d / "p1.ppm") + " " + q(d / "p2.ppm"), d / "p2.ppm"},
        {d.path + "/./p2.ppm", q(d / "p1.ppm") + " " + q(d / "p2.ppm"), d / "p2.ppm"},
        {d / "alias.ppm", q(d / "p1.ppm") + " " + q(d / "p2.ppm"), d / "p1.ppm"},
        {d / "hard.ppm", q(d / "p1.ppm") + " " + q(d / "p2.ppm"), d / "p2.ppm"},
    };
    for (const Over &o : overs) {
        CAPTURE(o.out);
        CHECK(sh(testkit::pray_shell() + " --join " + q(o.out) + " " + o.parts, &out) == 3);
        CHECK(out == "pray: error: cannot write '" + o.out + "': it is the part '" + o.part +
                         "' (choose another output name)\n");
    }
    CHECK(slurp(d / "p1.ppm") == p1);
    CHECK(slurp(d / "p2.ppm") == p2);
    CHECK(d.listing() == "alias.ppm dir.ppm fifo.ppm hard.ppm long.ppm long.tif p1.ppm p2.ppm p2.tif short.ppm short.tif");
    // the good join: the parts untouched, in either format
    CHECK(sh(testkit::pray_shell() + " --join " + q(d / "out.ppm") + " " + q(d / "p1.ppm") + " " + q(d / "p2.tif"), &out) == 0);
    CHECK(out == "");
    REQUIRE(sh(pray_cmd("-s 16x16 -o " + q(d / "whole.ppm") + " examples/csg.ray"), &out) == 0);
    CHECK(slurp(d / "out.ppm") == slurp(d / "whole.ppm"));
}
