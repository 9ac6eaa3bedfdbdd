// Image sequences (option coherence, thesis 3.7; docs/acceleration.md, "Image sequences"):
//   - every frame of an animation is the same, float for float, with coherence 1 and 0: objects
//     that move, appear, disappear and change material, a shadow that moves over an unchanged
//     floor, glass and mirrors, textures, undersampling, antialiasing, 1 and 2 threads, a light
//     or the camera that moves (the frame is then traced in full);
//   - random animations against coherence 0;
//   - coherence is on: where a small object moves, most pixels of the frames after the first are
//     taken over (pray_stats), and none where the light moves.
#include <doctest/doctest.h>

#include "testkit.hpp"

#include <cstring>
#include <random>
#include <sstream>

namespace {

struct Run {
    std::vector<testkit::Frame> frames;
    pray_stats st;
};

// A 4 x 4 checker of two greys, registered as "checker".
void register_checker(pray_ctx *c) {
    float px[4 * 4 * 3];
    for (int y = 0; y < 4; y++)
        for (int x = 0; x < 4; x++)
            for (int k = 0; k < 3; k++) px[(y * 4 + x) * 3 + k] = (x + y) % 2 ? 0.9f : 0.15f + 0.1f * k;
    pray_texture *t = pray_texture_rgb(c, 4, 4, px, "checker");
    REQUIRE(t != nullptr);
    REQUIRE(pray_texture_register(c, "checker", t) == PRAY_OK);
    pray_release(c, t);
}

Run run(const std::string &program, const std::vector<std::string> &options) {
    Run r;
    pray_ctx *c = pray_new();
    register_checker(c);
    pray_set_frame(c, testkit::frame_sink, &r.frames);
    for (const std::string &o : options) {
        size_t eq = o.find('=');
        REQUIRE_MESSAGE(pray_option_fix(c, o.substr(0, eq).c_str(), o.substr(eq + 1).c_str()) == PRAY_OK, o);
    }
    pray_status st = pray_run_string(c, "coherence.ray", program.data(), program.size());
    REQUIRE_MESSAGE(st == PRAY_OK, std::string(pray_error(c)));
    pray_stats_get(c, &r.st);
    pray_free(c);
    return r;
}

std::string joined(const std::vector<std::string> &v) {
    std::string s;
    for (const std::string &x : v) s += x + " ";
    return s;
}

// The program's frames with coherence 1 are those with coherence 0, float for float.
Run same_frames(const std::string &program, std::vector<std::string> options) {
    std::vector<std::string> off = options, on = options;
    off.push_back("coherence=0");
    on.push_back("coherence=1");
    Run a = run(program, off), b = run(program, on);
    INFO("options: ", joined(options));
    REQUIRE(a.frames.size() == b.frames.size());
    for (size_t f = 0; f < a.frames.size(); f++) {
        INFO("frame ", f);
        REQUIRE(a.frames[f].pixels.size() == b.frames[f].pixels.size());
        size_t bad = 0, first = 0;
        for (size_t i = 0; i < a.frames[f].pixels.size(); i++)
            if (std::memcmp(&a.frames[f].pixels[i], &b.frames[f].pixels[i], sizeof(float)) != 0 && !bad++) first = i / 3;
        INFO("first pixel that differs: ", first % a.frames[f].width, ", ", first / a.frames[f].width);
        CHECK(bad == 0);
    }
    CHECK(a.st.pixels_reused == 0);
    double px = (double)b.frames[0].width * b.frames[0].height;
    CHECK(b.st.pixels_reused + b.st.pixels_retraced == px * b.st.frames_coherent);
    return b;
}

// A room: a textured floor, a wall, a glass ball, a mirror ball and a box, a lamp and the sun;
// `anim` is the body of a loop over frames F = 0 .. 3 that renders each frame.
std::string scene(const std::string &anim, int frames = 4) {
    std::ostringstream p;
    p << "Eye = [0.5, -8, 2]\n"
         "View = [0, 0, 0] - Eye\n"
         "X = 2.2*norm(View % <0, 0, 1>)\n"
         "Y = 2.2*norm(View % X)\n"
         "perspective X, Y, Eye, [0, 0, 0]\n"
         "background {0.2, 0.3, 0.4}, {0.5, 0.4, 0.3}\n"
         "Matte = phong({0.7, 0.6, 0.5}, {0.3}, 20)\n"
         "Red = phong({0.8, 0.2, 0.1}, {0.4}, 30)\n"
         "Glass = transparent({0.8, 0.9, 0.95}, 1.5) + phong({0}, {0.5}, 60)\n"
         "Mirror = mirror({0.7}) + phong({0.1}, {0}, 1)\n"
         "Check = tiff(phong({0.2}, {0}, 1), phong({0.9}, {0}, 1), \"checker\")\n"
         "Floor = planemap(Check, [0, 0, -1], <0, 0, 1>, <1, 0, 0>, <0, 1, 0>)\n"
         "Wall = plane(Matte, [0, 4, 0], <0, -1, 0>)\n"
         "Lens = sphere(Glass, [-1.5, 0, 0], 0.8)\n"
         "Ball = sphere(Mirror, [1.5, 1, 0], 0.7)\n"
         "Box = plane(Red, [0, 2, 0.5], <0, 0, 1>) & plane(Red, [0, 2, -1], <0, 0, -1>) & "
         "plane(Red, [0.4, 2, 0], <1, 0, 0>) & plane(Red, [-0.4, 2, 0], <-1, 0, 0>) & "
         "plane(Red, [0, 2.4, 0], <0, 1, 0>) & plane(Red, [0, 1.6, 0], <0, -1, 0>)\n"
         "Room = Floor | Wall | Lens | Ball | Box\n"
         "Lamp = pointlight({0.8}, [2, -3, 4])\n"
         "Sun = dirlight({0.4}, <0.3, 0.5, -1>)\n"
         "F = 0\n"
         "while F < "
      << frames << "\n"
      << anim << "\nF = F + 1\nendwhile\n";
    return p.str();
}

// Every option set of the checks: threads 1 and 2, antialias 1 and 2, undersampling off and on.
std::vector<std::vector<std::string>> option_sets(int w = 40, int h = 32) {
    std::vector<std::vector<std::string>> v;
    std::string size[2] = {"width=" + std::to_string(w), "height=" + std::to_string(h)};
    for (int t = 1; t <= 2; t++)
        for (int aa = 1; aa <= 2; aa++)
            for (int ad = 0; ad < 2; ad++)
                v.push_back({size[0], size[1], "threads=" + std::to_string(t), "antialias=" + std::to_string(aa),
                             ad ? "adaptive=0.05" : "adaptive=0"});
    return v;
}

void check_all(const std::string &program) {
    for (const auto &o : option_sets()) same_frames(program, o);
}

} // namespace

TEST_CASE("coherence: a ball moving through the room, in front of the glass, the mirror and the lamp") {
    // its shadow moves over the unchanged floor and wall; the glass and the mirror show it
    check_all(scene("Mover = sphere(Red, [-3 + 1.6*F, -1.5 + 0.5*F, 0.2], 0.45)\n"
                    "rendertiff Room | Mover, Lamp, Sun"));
}

TEST_CASE("coherence: objects appear, disappear and change material") {
    check_all(scene("Obj = Room\n"
                    "if F % 2 = 1 then\n"
                    "  Obj = Obj | sphere(Matte, [0.5, -2, 0.3], 0.5)\n"
                    "endif\n"
                    "M = Matte\n"
                    "if F = 2 then\n"
                    "  M = Glass\n"
                    "endif\n"
                    "if F = 3 then\n"
                    "  M = tiff(Red, Mirror, \"checker\")\n"
                    "endif\n"
                    "rendertiff Obj | spheremap(M, [-0.5, -1, -0.5], 0.4, <0, 0.3, 1>, <1, 0, 0>), "
                    "Lamp, Sun"));
}

TEST_CASE("coherence: a part turning inside a difference, and parts added in front of the others") {
    // the box loses a turning slot; new balls come first in the union, so that every primitive
    // after them is numbered anew
    check_all(scene("Slot = (plane(Matte, [0, 0, 0.1], <0, 0, 1>) & plane(Matte, [0, 0, -0.1], <0, 0, -1>)) . <0, 30*F, 0> "
                    ". [0, 2, 0]\n"
                    "Extra = nothing\n"
                    "I = 0\n"
                    "while I < F\n"
                    "  Extra = Extra | sphere(Red, [-2 + 0.5*I, -2, 1], 0.2)\n"
                    "  I = I + 1\n"
                    "endwhile\n"
                    "rendertiff Extra | Floor | Wall | Lens | Ball | (Box - Slot), Lamp, Sun"));
}

TEST_CASE("coherence: solids of version 2 turning within their own boxes, textured") {
    // the boxes the cube and the ring fill stay the same from frame to frame; their frames and
    // so their texture coordinates do not
    check_all(scene("Cube = box(Check, [-0.4, -0.4, -0.4], [0.4, 0.4, 0.4]) . <0, 0, 90*F> . [0, -1.5, 0.2]\n"
                    "Ring = torus(Check, [0, 0, 0], <0, 0, 1>, 0.6, 0.2) . <0, 0, 45*F> . [-1, -2, 0.5]\n"
                    "Egg = stretch(sphere(Check, [0, 0, 0], 0.3), <1, 1 + 0.25*F, 1>) . [1.2, -2, 0.6]\n"
                    "rendertiff Room | Cube | Ring | Egg, Lamp, Sun"));
}

TEST_CASE("coherence: frames of nothing") {
    // (no primitive to pair between the frames)
    same_frames("rendertiff nothing, none\nrendertiff nothing, none\nrendertiff nothing, none\n", {"width=8", "height=8"});
}

TEST_CASE("coherence: a light, the camera or an option that changes: the frame is traced in full") {
    std::string p = scene("if F = 1 then\n"
                          "  Lamp = pointlight({0.8}, [2, -3, 4.5])\n"
                          "endif\n"
                          "if F = 2 then\n"
                          "  perspective X, Y, Eye + <0.1, 0, 0>, [0, 0, 0]\n"
                          "endif\n"
                          "if F = 3 then\n"
                          "  option \"depth\", 3\n"
                          "endif\n"
                          "rendertiff Room, Lamp, Sun",
                          5);
    Run r = same_frames(p, {"width=40", "height=32", "threads=1"});
    // frames 1, 2 and 3 change the light, the camera and an option; frame 4 is like frame 3
    // and is recorded, for a frame 5 that does not come
    CHECK(r.st.pixels_reused == 0);
    CHECK(r.st.pixels_retraced == 0);
    CHECK(r.st.frames_coherent == 0);
}

TEST_CASE("coherence: a frame like the one before takes over every pixel") {
    // the first frame records a sample only (a program may have no other); the second, like
    // it, is recorded in full, and the third takes it over
    Run r = same_frames(scene("rendertiff Room, Lamp, Sun", 3), {"width=40", "height=32", "threads=2"});
    CHECK(r.st.pixels_reused == 40 * 32);
    CHECK(r.st.pixels_retraced == 0);
    CHECK(r.st.frames_coherent == 1);
}

TEST_CASE("coherence: when everything moves, no frame takes any pixel over") {
    Run r = same_frames(scene("rendertiff Room . [0.05*F, 0, 0], Lamp, Sun", 6), {"width=40", "height=32"});
    CHECK(r.st.pixels_reused == 0);
    CHECK(r.st.frames_coherent == 0);
}

TEST_CASE("coherence: where a small ball moves, most pixels are taken over") {
    for (int aa = 1; aa <= 2; aa++) {
        Run r = same_frames(scene("rendertiff Room | sphere(Red, [-2.2 + 0.2*F, -1, 0.9], 0.15), Lamp, Sun", 4),
                            {"width=64", "height=48", "threads=1", "antialias=" + std::to_string(aa)});
        double later = 2.0 * 64 * 48;  // the pixels of the frames after the second
        INFO("antialias ", aa, ": reused ", r.st.pixels_reused, " of ", later);
        CHECK(r.st.frames_coherent == 2);
        CHECK(r.st.pixels_reused + r.st.pixels_retraced == later);
        CHECK(r.st.pixels_reused > 0.6 * later);
    }
}

TEST_CASE("coherence: a scene cheap to trace: frames recorded in full, in part, not at all, and sampled again") {
    // A pixel of this scene costs little more to trace than to record. Frames 0 and 1 are alike
    // (frame 1 is recorded in full), frames 2 and 3 move the small ball (they take pixels over
    // and record those traced again), frame 4 moves the large one, which fills most of the
    // records' cells (it takes pixels over but recording them would not pay), frame 5 is traced
    // in full and sampled, frame 6 is recorded in full again.
    std::ostringstream p;
    p << "option \"width\", 80\noption \"height\", 60\n"
         "perspective <2.4, 0, 0>, <0, 0, 1.8>, [0, -6, 1], [0, 0, 0]\nbackground {0.7, 0.8, 0.9}\n"
         "Paint = phong({0.8, 0.3, 0.1}, {0.4}, 25)\nGround = phong({0.5, 0.55, 0.45}, {0}, 1)\n"
         "Floor = plane(Ground, [0, 0, -1], <0, 0, 1>)\nSun = dirlight({1}, <0.5, 1, -1>)\n";
    const double big[7] = {0, 0, 0, 0, 0.3, 0.3, 0.3}, small[7] = {0, 0, 0.3, 0.6, 0.6, 0.9, 1.2};
    for (int f = 0; f < 7; f++)
        p << "rendertiff Floor | sphere(Paint, [" << big[f] << ", 0, 0], 1) | sphere(Paint, [" << -2 + small[f]
          << ", -1, -0.7], 0.3) | sphere(Ground, [3.5, 4, 0], 1) | sphere(Ground, [-4, 4, 2], 1), Sun\n";
    for (int t = 1; t <= 2; t++) same_frames(p.str(), {"threads=" + std::to_string(t)});
    same_frames(p.str(), {"adaptive=0.05"});
}

namespace {
// A random animation: solids of random kinds and materials, some of which move, turn, change
// material, appear or disappear from one frame to the next; now and then the lamp moves.
std::string random_animation(std::mt19937 &rng, int frames) {
    std::uniform_real_distribution<double> u(-1, 1);
    auto num = [&](double a, double b) { return a + (b - a) * (u(rng) + 1) / 2; };
    const char *mats[] = {"Matte", "Red", "Glass", "Mirror", "Check"};
    int n = 4 + (int)(rng() % 6);
    struct Obj {
        int kind, mat, shown;
        double x, y, z, r, turn;
    };
    std::vector<Obj> objs(n);
    for (Obj &o : objs) {
        o.kind = (int)(rng() % 3);
        o.mat = (int)(rng() % 5);
        o.shown = rng() % 5 != 0;
        o.x = num(-2, 2), o.y = num(-2, 2), o.z = num(-0.5, 1), o.r = num(0.2, 0.6), o.turn = num(0, 90);
    }
    std::ostringstream p;
    p << "Eye = [0.3, -7, 2.5]\nView = [0, 0, 0] - Eye\nX = 2.4*norm(View % <0, 0, 1>)\nY = 2.4*norm(View % X)\n"
         "perspective X, Y, Eye, [0, 0, 0]\nbackground {0.3, 0.4, 0.5}\n"
         "Matte = phong({0.7, 0.6, 0.5}, {0.3}, 20)\nRed = phong({0.8, 0.2, 0.1}, {0.4}, 30)\n"
         "Glass = transparent({0.8, 0.9, 0.95}, 1.4) + phong({0}, {0.5}, 60)\n"
         "Mirror = mirror({0.6}) + phong({0.2}, {0}, 1)\n"
         "Check = tiff(phong({0.2}, {0}, 1), phong({0.9}, {0}, 1), \"checker\")\n"
         "Floor = planemap(Check, [0, 0, -1], <0, 0, 1>, <0.7, 0, 0>, <0, 0.7, 0>)\n";
    double lamp[3] = {2, -3, 4};
    for (int f = 0; f < frames; f++) {
        for (Obj &o : objs) {
            unsigned k = rng() % 16;
            if (k == 0) o.shown = !o.shown;
            else if (k == 1) o.mat = (int)(rng() % 5);
            else if (k <= 3) o.x += num(-0.5, 0.5), o.y += num(-0.5, 0.5);
            else if (k == 4) o.turn += num(-40, 40);
        }
        if (rng() % 8 == 0) lamp[0] += num(-1, 1);
        p << "Obj = Floor\n";
        for (const Obj &o : objs) {
            if (!o.shown) continue;
            std::ostringstream at;
            at << "[" << o.x << ", " << o.y << ", " << o.z << "]";
            const char *m = mats[o.mat];
            p << "Obj = Obj | ";
            if (o.kind == 0) p << "sphere(" << m << ", " << at.str() << ", " << o.r << ")\n";
            else if (o.kind == 1)  // a block, turned
                p << "((plane(" << m << ", [0, 0, " << o.r << "], <0, 0, 1>) & plane(" << m << ", [0, 0, " << -o.r
                  << "], <0, 0, -1>) & plane(" << m << ", [" << o.r << ", 0, 0], <1, 0, 0>) & plane(" << m << ", [" << -o.r
                  << ", 0, 0], <-1, 0, 0>) & plane(" << m << ", [0, " << o.r << ", 0], <0, 1, 0>) & plane(" << m
                  << ", [0, " << -o.r << ", 0], <0, -1, 0>)) . <0, 0, " << o.turn << "> . " << at.str() << ")\n";
            else  // a capped tube with a hole
                p << "(((cylinder(" << m << ", [0, 0, 0], <0, 0, 1>, " << o.r << ") & plane(" << m << ", [0, 0, " << o.r
                  << "], <0, 0, 1>) & plane(" << m << ", [0, 0, " << -o.r << "], <0, 0, -1>)) - cylinder(" << m
                  << ", [0, 0, 0], <1, 0, 0>, " << o.r / 2 << ")) . <" << o.turn << ", 0, 0> . " << at.str() << ")\n";
        }
        p << "rendertiff Obj, pointlight({0.8}, [" << lamp[0] << ", " << lamp[1] << ", " << lamp[2]
          << "]), dirlight({0.3}, <0.2, 0.6, -1>)\n";
    }
    return p.str();
}
} // namespace

TEST_CASE("coherence: random animations give the frames of coherence 0") {
    std::mt19937 rng(27);
    auto sets = option_sets(36, 28);
    long coherent = 0;
    for (int i = 0; i < 24; i++) {
        std::string p = random_animation(rng, 6);
        INFO("animation ", i, ":\n", p);
        coherent += same_frames(p, sets[i % sets.size()]).st.frames_coherent;
    }
    MESSAGE("frames that took pixels over: ", coherent);
    CHECK(coherent >= 16);  // (the animations do test something)
}

TEST_CASE("coherence: records the memory cap has no room for are not made, and the frames are the same") {
    // 200 x 160 pixels' records are 7 MiB; the cap of 4 MiB leaves room for the render only
    std::string p = scene("rendertiff Room | sphere(Red, [-2.2 + 0.2*F, -1, 0.9], 0.15), Lamp, Sun", 4);
    Run r = same_frames(p, {"width=200", "height=160", "threads=1", "maxmem=4"});
    CHECK(r.st.pixels_reused == 0);
    Run big = same_frames(p, {"width=200", "height=160", "threads=1", "maxmem=64"});
    CHECK(big.st.pixels_reused > 0);
}

TEST_CASE("coherence: the pixels taken over do not depend on the number of threads") {
    std::string p = scene("rendertiff Room | sphere(Red, [-2.2 + 0.3*F, -1, 0.9], 0.2), Lamp, Sun", 5);
    double reused[3];
    for (int t = 1; t <= 3; t++) reused[t - 1] = same_frames(p, {"width=48", "height=40", "threads=" + std::to_string(t)}).st.pixels_reused;
    CHECK(reused[0] > 0);
    CHECK(reused[1] == reused[0]);
    CHECK(reused[2] == reused[0]);
}
