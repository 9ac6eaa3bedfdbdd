// Built with ThreadSanitizer by `make tsan`: one scene prepared for rendering on one context
// (pray_prepare_render) and rendered at once by four contexts, each on a thread of its own
// (pray_render_prepared), a band each, glass and textures-free shading on two render threads
// apiece. A data race is a failure (TSan exits non-zero); so are bands that differ from the one
// render of the whole image.
#include "../../pray.hpp"

#include <pthread.h>
#include <stdio.h>
#include <string.h>

namespace {

const int W = 96, H = 64, N = 4;

struct Band {
    const pray_scene *scene;
    float *rgb;
    pray_status st;
    int k;
};

void *render_band(void *arg) {
    Band *b = (Band *)arg;
    pray_ctx *c = pray_new();
    pray_option(c, "threads", 2);
    pray_rect r = {0, H * b->k / N, W, H * (b->k + 1) / N - H * b->k / N};
    pray_buffers out = {b->rgb + (size_t)3 * W * r.y, NULL, NULL, NULL, W, NULL, NULL, 0};
    b->st = pray_render_prepared(c, b->scene, &r, &out);
    if (b->st != PRAY_OK) fprintf(stderr, "band %d: %s\n", b->k, pray_error(c));
    pray_free(c);
    return NULL;
}

} // namespace

int main() {
    pray_ctx *c = pray_new();
    pray_rgb red = {0.8, 0.2, 0.1}, grey = {0.3, 0.3, 0.3}, clear = {0.8, 0.9, 0.9}, white = {1, 1, 1};
    pray_model *m = pray_phong(c, red, grey, grey, 10), *g = pray_model_add(c, pray_transparent(c, clear, 1.5), pray_phong(c, grey, grey, grey, 30));
    pray_vec o = {0, 0, 0}, up = {0, 0, 1}, p = {0.6, 0.2, 0.4}, eye = {3, -2, 1.5}, d = {1, -1, 2}, floor_at = {0, 0, -0.5};
    pray_object *scene = pray_csg(c, PRAY_UNION, pray_plane(c, m, floor_at, up), pray_sphere(c, g, o, 0.5));
    scene = pray_csg(c, PRAY_UNION, scene, pray_sphere(c, m, p, 0.3));
    pray_light *l = pray_dirlight(c, white, d);
    pray_lookat(c, eye, o, up, 40);
    pray_option(c, "width", W);
    pray_option(c, "height", H);
    pray_option(c, "antialias", 2);
    static float whole[3 * W * H], bands[3 * W * H];
    pray_buffers all = {whole, NULL, NULL, NULL, 0, NULL, NULL, 0};
    if (pray_render_into(c, scene, l, NULL, &all) != PRAY_OK) return fprintf(stderr, "%s\n", pray_error(c)), 1;
    pray_scene *q = pray_prepare_render(c, scene, l);
    if (!q) return fprintf(stderr, "%s\n", pray_error(c)), 1;
    pthread_t t[N];
    Band b[N];
    for (int k = 0; k < N; k++) {
        b[k].scene = q;
        b[k].rgb = bands;
        b[k].k = k;
        pthread_create(&t[k], NULL, render_band, &b[k]);
    }
    int bad = 0;
    for (int k = 0; k < N; k++) {
        pthread_join(t[k], NULL);
        bad += b[k].st != PRAY_OK;
    }
    if (!bad && memcmp(whole, bands, sizeof whole) != 0) {
        fprintf(stderr, "the bands differ from the whole image\n");
        bad = 1;
    }
    pray_free(c);
    if (!bad) printf("tsan: %d contexts rendered one prepared scene at once, equal to one render\n", N);
    return bad != 0;
}
