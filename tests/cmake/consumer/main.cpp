// A program that uses pray through CMake or pkg-config (tests/cmake/run.sh builds it): it renders
// a red sphere of flat colour on a blue background, 9 x 9 pixels, and checks two pixels exactly.
#include <pray.hpp>

#include <cstdio>

int main() {
    pray_ctx *c = pray_new();
    pray_rgb red = {1, 0, 0}, blue = {0, 0, 1};
    pray_vec centre = {0, 0, 0};
    pray_image img;
    pray_option(c, "width", 9);
    pray_option(c, "height", 9);
    pray_background(c, blue, blue);
    pray_object *ball = pray_sphere(c, pray_color(c, red), centre, 0.5);
    if (pray_render(c, ball, NULL, &img) != PRAY_OK) {
        std::fprintf(stderr, "consumer: %s\n", pray_error(c));
        return 1;
    }
    const float *mid = img.pixels + (4 * 9 + 4) * 3, *corner = img.pixels;
    bool ok = img.width == 9 && img.height == 9 && mid[0] == 1 && mid[1] == 0 && mid[2] == 0 &&
              corner[0] == 0 && corner[1] == 0 && corner[2] == 1;
    std::printf("pray %s (%s): centre %g %g %g, corner %g %g %g: %s\n", pray_version(), pray_features(), mid[0],
                mid[1], mid[2], corner[0], corner[1], corner[2], ok ? "ok" : "WRONG");
    pray_image_free(c, &img);
    pray_free(c);
    return ok ? 0 : 1;
}
