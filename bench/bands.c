/* bench/bands.c: the cost of rendering one image as bands of rows through the API, against the
   whole image at once. A grid of n x n balls on a floor, 256 x 256 pixels; each band is one
   pray_render_into call on the same context, and the bands' pixels must equal the whole image's.
   Then the camera turns (the eye stays): the context renders the new view with the scene it kept,
   against a new context that prepares it, and the two images must be equal.
     cc -O2 -I. bench/bands.c pray.o -lm -lpthread -o bands && ./bands [n] [bands]   (n = 100) */
#include "pray.hpp"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static double now(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

int main(int argc, char **argv) {
    int n = argc > 1 ? atoi(argv[1]) : 100, bands = argc > 2 ? atoi(argv[2]) : 32, W = 256, H = 256;
    pray_ctx *c = pray_new();
    pray_rgb white = {1, 1, 1}, grey = {0.6, 0.6, 0.6};
    pray_model *m = pray_phong(c, white, grey, grey, 20);
    pray_vec up = {0, 1, 0}, at0 = {0, 0, 0}, dir = {1, 2, 1}, eye = {(double)n, (double)n, 2.5 * n},
             mid = {0.5 * n, 0, 0.5 * n};
    pray_object *scene = pray_plane(c, m, at0, up);
    for (int i = 0; i < n; i++)
        for (int j = 0; j < n; j++) {
            pray_vec p = {i + 0.5, 0.4, j + 0.5};
            scene = pray_csg(c, PRAY_UNION, scene, pray_sphere(c, m, p, 0.4));
        }
    pray_light *l = pray_dirlight(c, white, dir);
    pray_lookat(c, eye, mid, up, 40);
    pray_option(c, "width", W);
    pray_option(c, "height", H);
    float *whole = (float *)malloc(sizeof(float) * 3 * W * H), *part = (float *)malloc(sizeof(float) * 3 * W * H);
    pray_buffers b;
    memset(&b, 0, sizeof b);
    b.rgb = whole;
    double t0 = now();
    if (pray_render_into(c, scene, l, NULL, &b) != PRAY_OK) return fprintf(stderr, "%s\n", pray_error(c)), 1;
    double t1 = now();
    for (int k = 0; k < bands; k++) {
        pray_rect r = {0, H * k / bands, W, H * (k + 1) / bands - H * k / bands};
        b.rgb = part + 3 * (size_t)W * r.y;
        b.stride = W;
        if (pray_render_into(c, scene, l, &r, &b) != PRAY_OK) return fprintf(stderr, "%s\n", pray_error(c)), 1;
    }
    double t2 = now();
    printf("%d balls, %d x %d: whole image %.3f s, %d bands %.3f s (%.2fx), pixels %s\n", n * n, W, H, t1 - t0,
           bands, t2 - t1, (t2 - t1) / (t1 - t0), memcmp(whole, part, sizeof(float) * 3 * W * H) ? "DIFFER" : "equal");
    {
        pray_vec look = {0.3 * n, 0, 0.6 * n};
        pray_ctx *d = pray_new();
        pray_object *sd = pray_plane(d, pray_phong(d, white, grey, grey, 20), at0, up);
        for (int i = 0; i < n; i++)
            for (int j = 0; j < n; j++) {
                pray_vec p = {i + 0.5, 0.4, j + 0.5};
                sd = pray_csg(d, PRAY_UNION, sd, pray_sphere(d, pray_phong(d, white, grey, grey, 20), p, 0.4));
            }
        pray_option(d, "width", W);
        pray_option(d, "height", H);
        pray_lookat(c, eye, look, up, 40);
        pray_lookat(d, eye, look, up, 40);
        b.rgb = whole;
        b.stride = 0;
        double t3 = now();
        if (pray_render_into(c, scene, l, NULL, &b) != PRAY_OK) return fprintf(stderr, "%s\n", pray_error(c)), 1;
        double t4 = now();
        b.rgb = part;
        if (pray_render_into(d, sd, pray_dirlight(d, white, dir), NULL, &b) != PRAY_OK)
            return fprintf(stderr, "%s\n", pray_error(d)), 1;
        double t5 = now();
        printf("the camera turned: the kept scene %.3f s, prepared again %.3f s (%.2fx), pixels %s\n", t4 - t3,
               t5 - t4, (t5 - t4) / (t4 - t3), memcmp(whole, part, sizeof(float) * 3 * W * H) ? "DIFFER" : "equal");
        pray_free(d);
    }
    pray_free(c);
    free(whole);
    free(part);
    return 0;
}
