/* embed.c — pray used from C: build the thesis' red sphere through the API, render it into
   memory and write it as PPM.

   Build:  c++ -O2 -c pray.cpp && cc -O2 -I. -c examples/embed.c && c++ embed.o pray.o -o embed
   Run:    ./embed red.ppm
*/
#include <stdio.h>

#include "pray.hpp"

static pray_rgb rgb(double r, double g, double b) {
    pray_rgb c;
    c.r = r;
    c.g = g;
    c.b = b;
    return c;
}

static pray_vec vec(double x, double y, double z) {
    pray_vec v;
    v.x = x;
    v.y = y;
    v.z = z;
    return v;
}

int main(int argc, char **argv) {
    const char *out = argc > 1 ? argv[1] : "embed.ppm";
    pray_ctx *c = pray_new();
    pray_model *red;
    pray_object *sphere;
    pray_light *light;
    pray_image img;
    pray_status st;
    if (!c) return 1;
    pray_option(c, "width", 128);
    pray_option(c, "height", 128);
    red = pray_phong(c, rgb(0.8, 0.1, 0.1), rgb(0.3, 0.3, 0.3), rgb(0, 0, 0), 3);
    sphere = pray_sphere(c, red, vec(0, 0, 0), 0.2);
    light = pray_dirlight(c, rgb(1, 1, 1), vec(1, 1, 1));
    st = pray_render(c, sphere, light, &img);
    if (st == PRAY_OK) {
        /* the centre pixel, as the renderer computed it */
        const float *px = img.pixels + ((size_t)64 * img.width + 64) * 3;
        printf("centre pixel: %.4f %.4f %.4f\n", px[0], px[1], px[2]);
        st = pray_write_image(c, &img, out, 8);
        pray_image_free(c, &img);
    }
    if (st != PRAY_OK) fprintf(stderr, "embed: %s\n", pray_error(c));
    pray_free(c);
    return st == PRAY_OK ? 0 : 1;
}
