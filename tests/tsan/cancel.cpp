// Built with ThreadSanitizer by `make tsan`: a render on two threads cancelled from another
// thread (pray_cancel), and two contexts rendering at once. A data race is a failure (TSan
// exits non-zero); so is a render that was not cancelled.
#include "../../pray.hpp"

#include <pthread.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

namespace {

const char *const SCENE =
    "M = transparent({0.9}, 1.2)\n"
    "O = nothing\n"
    "K = 1\n"
    "while K < 60\n"
    "  O = O | (sphere(M, [0, 0, 0], 0.01 * K) - sphere(M, [0, 0, 0], 0.01 * K - 0.004))\n"
    "  K = K + 1\n"
    "endwhile\n"
    "rendertiff O, dirlight({1}, <1, 1, 1>)\n";

struct Run {
    pray_ctx *c;
    pray_status st;
};

pray_status drop_frame(void *, const pray_image *, const char *) { return PRAY_OK; }

void *run(void *arg) {
    Run *r = (Run *)arg;
    r->st = pray_run_string(r->c, "tsan.ray", SCENE, strlen(SCENE));
    return NULL;
}

pray_ctx *context(int side) {
    pray_ctx *c = pray_new();
    pray_option(c, "threads", 2);
    pray_option(c, "width", side);
    pray_option(c, "height", side);
    pray_set_frame(c, drop_frame, NULL);
    return c;
}

} // namespace

int main() {
    int failed = 0;
    // cancelled from another thread while it renders
    Run a = {context(2048), PRAY_OK};
    pthread_t t;
    pthread_create(&t, NULL, run, &a);
    usleep(300000);
    pray_cancel(a.c);
    pthread_join(t, NULL);
    if (a.st != PRAY_ERR_CANCELLED) {
        fprintf(stderr, "tsan: the render was not cancelled: %s\n", pray_error(a.c));
        failed = 1;
    }
    pray_free(a.c);
    // two contexts at once, each on two threads
    Run b = {context(64), PRAY_OK}, d = {context(64), PRAY_OK};
    pthread_t tb, td;
    pthread_create(&tb, NULL, run, &b);
    pthread_create(&td, NULL, run, &d);
    pthread_join(tb, NULL);
    pthread_join(td, NULL);
    if (b.st != PRAY_OK || d.st != PRAY_OK) {
        fprintf(stderr, "tsan: %s / %s\n", pray_error(b.c), pray_error(d.c));
        failed = 1;
    }
    pray_free(b.c);
    pray_free(d.c);
    if (!failed) printf("tsan: cancel from another thread and two contexts at once: no race\n");
    return failed;
}
