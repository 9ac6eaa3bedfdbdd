// pray-mpi: one PRAY program rendered by many MPI processes, with the bytes of one `pray`.
// Build: make mpi (installs Debian's OpenMPI when it is missing), or by hand:
//     c++ -O3 -c pray.cpp -o pray.o && mpicxx -O3 -I. ports/mpi/pray-mpi.cpp pray.o -o pray-mpi
// Run:   mpirun -np 8 ./pray-mpi [options] scene.ray
//
// Written only against pray.hpp, as any host could be. Every rank runs the whole program; the
// frames are rendered by a render function (pray_set_render), so each rendertiff of the program
// asks it for the frame:
// - one image (a program with one frame): rank 0 hands out bands of rows, one at a time, to the
//   ranks that ask for work; each renders its bands with pray_render_into (a band is bit for bit
//   those rows of the whole image) and sends them back; rank 0 stacks them into the frame;
// - a sequence: rank 0 hands out whole frames the same way; every rank runs every statement, and
//   renders only the frames it was given.
// Rank 0 only hands out work and gathers (so run one rank more than the processors to keep
// busy); it returns each frame from the render function, and pray writes it as it would without
// MPI: its file name, format and bits, under a temporary name renamed when complete.
// A failure on any rank prints that rank's message and stops every rank (MPI_Abort) with the
// exit status pray would have: 1 program, 2 usage, 3 input/output.
#include <mpi.h>

#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "pray.hpp"

namespace {

const char *const USAGE =
    "usage: mpirun -np P pray-mpi [options] program.ray\n"
    "Render a PRAY program on P processes: rank 0 hands out rows (one image) or frames (a\n"
    "sequence) and writes the images; the files are those pray writes. Options as pray's:\n"
    "  -o FILE          output file (.tif, .ppm or .png); same as -D output=FILE\n"
    "  -s WxH           image size in pixels; same as -D width=W -D height=H\n"
    "  -D name=value    set an option of the language; wins over `option` in the program\n"
    "  --brute          the brute-force reference renderer\n"
    "  --threads N      threads of each process (0 = automatic)\n"
    "  --untrusted      tighter limits; the program reads files beside it only\n"
    "  --split rows|frames  hand out rows or frames (default: rows for one image, frames\n"
    "                   for a sequence)\n"
    "  --quiet          no warnings (pray-mpi draws no progress bar)\n"
    "  --help           print this text\n"
    "Exit status: 0 ok, 1 error in the program, 2 usage, 3 input/output error.\n";

enum { TAG_ASK = 1, TAG_RESULT = 2, TAG_DATA = 3, TAG_REPLY = 4 };
enum { GIVE_BAND = 1, GIVE_FRAME = 2, NO_MORE = 3 };

int rank, nranks;

// SIGINT, SIGTERM, SIGHUP and SIGQUIT (mpirun passes them on) while rank 0 writes an image: remove
// the temporary file, then die of the signal, as pray does.
pray_ctx *volatile the_ctx;
extern "C" void on_signal(int sig) {
    const char *t = the_ctx ? pray_temp_file(the_ctx) : NULL;
    if (t) unlink(t);
    signal(sig, SIG_DFL);
    raise(sig);
}
void catch_signals(pray_ctx *c) {
    void (*h)(int) = c ? on_signal : SIG_DFL;
    if (c) the_ctx = c;
    const int sigs[] = {SIGINT, SIGTERM, SIGHUP, SIGQUIT};
    for (int i = 0; i < 4; i++) signal(sigs[i], h);
    if (!c) the_ctx = NULL;
}

int exit_code(pray_status st) {
    switch (st) {
    case PRAY_OK: return 0;
    case PRAY_ERR_IO: return 3;
    default: return 1;
    }
}

// pray's way of showing a message ("pray-mpi: error: ..." or "name:line:col: error: ..."), with
// the rank when it is not rank 0.
void show_error(const char *m) {
    if (rank) fprintf(stderr, "pray-mpi: rank %d: %s\n", rank, m);
    else if (strncmp(m, "error: ", 7) == 0) fprintf(stderr, "pray-mpi: %s\n", m);
    else fprintf(stderr, "%s\n", m);
    fflush(stderr);
}

// Stop every rank: this rank's message, then MPI_Abort with the exit status.
void die(pray_ctx *c, pray_status st) {
    show_error(pray_error(c));
    MPI_Abort(MPI_COMM_WORLD, exit_code(st) ? exit_code(st) : 1);
    exit(1);
}

// Rank 0 waits for a message without spinning (a blocking receive may poll a processor at full
// speed): it sleeps between looks, from 20 microseconds up to 2 milliseconds while none comes.
void wait_message(MPI_Status *s) {
    long nap = 20000;
    for (;;) {
        int flag = 0;
        MPI_Iprobe(MPI_ANY_SOURCE, MPI_ANY_TAG, MPI_COMM_WORLD, &flag, s);
        if (flag) return;
        struct timespec ts = {0, nap};
        nanosleep(&ts, NULL);
        if (nap < 2000000) nap *= 2;
    }
}

// Every rank waits here, sleeping, until all have come: no rank ends (MPI_Finalize) while
// another may still fail and stop them all (MPI_Abort).
void all_done() {
    MPI_Request r;
    MPI_Ibarrier(MPI_COMM_WORLD, &r);
    long nap = 20000;
    for (;;) {
        int flag = 0;
        MPI_Test(&r, &flag, MPI_STATUS_IGNORE);
        if (flag) return;
        struct timespec ts = {0, nap};
        nanosleep(&ts, NULL);
        if (nap < 2000000) nap *= 2;
    }
}

void send_reply(int to, int kind, int a, int b) {
    int m[4] = {kind, a, b, 0};
    MPI_Send(m, 4, MPI_INT, to, TAG_REPLY, MPI_COMM_WORLD);
}

// ---- rank 0: hands out work, gathers, returns each frame to be written ----
struct Master {
    int rows_mode, nframes;
    // rows: the frame being gathered
    int frame, width, height, next_row, rows_in;
    float *pixels;
    int *told_done;    // per rank: the last frame it was told is done (rows), or 1 if stopped (frames)
    int *waiting;      // per rank: the frame it asked for, not yet answered (-1: none)
    // frames
    int next_frame;
    float **frames;    // frames arrived ahead of their turn
    int *fw, *fh;
};

// The next band of rows: large first, smaller towards the end (guided self-scheduling), so the
// ranks finish together and a band costs few preparations of the scene.
int band_rows(const Master &m) {
    int workers = nranks - 1, left = m.height - m.next_row;
    int b = (left + 2 * workers - 1) / (2 * workers), least = m.height / (8 * workers);
    if (least < 1) least = 1;
    if (b < least) b = least;
    return b < left ? b : left;
}

// Answer a rank that asks for work of frame `want` (rows), or for a frame (frames).
void answer(Master &m, int who, int want) {
    if (!m.rows_mode) {
        if (m.next_frame < m.nframes) send_reply(who, GIVE_FRAME, m.next_frame++, 0);
        else {
            send_reply(who, NO_MORE, 0, 0);
            m.told_done[who] = 1;
        }
        return;
    }
    if (want > m.frame) {
        m.waiting[who] = want;  // a frame rank 0 has not come to yet: answered when it has
        return;
    }
    if (want == m.frame && m.pixels && m.next_row < m.height) {
        int b = band_rows(m);
        send_reply(who, GIVE_BAND, m.next_row, m.next_row + b);
        m.next_row += b;
        return;
    }
    send_reply(who, NO_MORE, want, 0);  // a frame whose bands are all given out
    m.told_done[who] = want;
}

// Take one message: a request, or a result (with its pixels) that also asks for more.
void serve_one(Master &m, pray_ctx *c) {
    MPI_Status s;
    wait_message(&s);
    int h[4], who = s.MPI_SOURCE;
    MPI_Recv(h, 4, MPI_INT, who, s.MPI_TAG, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
    if (s.MPI_TAG == TAG_RESULT) {
        if (m.rows_mode) {  // {frame, y0, y1, width}
            if (h[0] != m.frame || !m.pixels || h[3] != m.width || h[1] < 0 || h[2] > m.height || h[1] >= h[2]) {
                pray_set_error(c, PRAY_ERR_RUNTIME, "rank 0: a band that does not belong to the frame");
                die(c, PRAY_ERR_RUNTIME);
            }
            int n = (h[2] - h[1]) * m.width * 3;
            MPI_Recv(m.pixels + (size_t)h[1] * m.width * 3, n, MPI_FLOAT, who, TAG_DATA, MPI_COMM_WORLD,
                     MPI_STATUS_IGNORE);
            m.rows_in += h[2] - h[1];
        } else {  // {frame, width, height}
            size_t n = (size_t)h[1] * (size_t)h[2] * 3;
            float *p = (float *)malloc(n * sizeof(float));
            if (!p || h[0] < 0 || h[0] >= m.nframes) {
                pray_set_error(c, PRAY_ERR_NOMEM, p ? "rank 0: a frame that is not of the program" : "out of memory");
                die(c, PRAY_ERR_NOMEM);
            }
            MPI_Recv(p, (int)n, MPI_FLOAT, who, TAG_DATA, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
            m.frames[h[0]] = p;
            m.fw[h[0]] = h[1];
            m.fh[h[0]] = h[2];
        }
    }
    answer(m, who, h[0]);
}

pray_status master_render(void *ud, pray_ctx *c, pray_object *, pray_light *, int frame, pray_image *out) {
    Master &m = *(Master *)ud;
    int W = (int)pray_option_get(c, "width"), H = (int)pray_option_get(c, "height");
    if (m.rows_mode) {
        pray_status st = pray_image_new(c, W, H, out);
        if (st != PRAY_OK) return st;
        m.frame = frame;
        m.width = W;
        m.height = H;
        m.pixels = out->pixels;
        m.next_row = m.rows_in = 0;
        for (int r = 1; r < nranks; r++)  // those who asked for this frame before rank 0 came to it
            if (m.waiting[r] == frame) {
                m.waiting[r] = -1;
                answer(m, r, frame);
            }
        while (m.rows_in < H) serve_one(m, c);
        m.pixels = NULL;
        return PRAY_OK;
    }
    while (!m.frames[frame]) serve_one(m, c);
    if (m.fw[frame] != W || m.fh[frame] != H)
        return pray_set_error(c, PRAY_ERR_RUNTIME, "a worker rendered the frame at another size");
    pray_status st = pray_image_new(c, W, H, out);
    if (st == PRAY_OK) memcpy(out->pixels, m.frames[frame], sizeof(float) * 3 * (size_t)W * (size_t)H);
    free(m.frames[frame]);
    m.frames[frame] = NULL;
    return st;
}

// ---- ranks 1 ... P-1: ask for work, render it, send it ----
struct Worker {
    int rows_mode;
    int next_frame;  // frames: the frame given to this rank (-1: none any more)
};

void ask(int frame) {
    int m[4] = {frame, 0, 0, 0};
    MPI_Send(m, 4, MPI_INT, 0, TAG_ASK, MPI_COMM_WORLD);
}
void get_reply(int r[4]) { MPI_Recv(r, 4, MPI_INT, 0, TAG_REPLY, MPI_COMM_WORLD, MPI_STATUS_IGNORE); }

pray_status worker_render(void *ud, pray_ctx *c, pray_object *root, pray_light *lights, int frame,
                          pray_image *) {
    Worker &w = *(Worker *)ud;
    int W = (int)pray_option_get(c, "width"), H = (int)pray_option_get(c, "height");
    pray_buffers b = {NULL, NULL, NULL, NULL, 0, NULL, NULL, 0};
    if (w.rows_mode) {
        ask(frame);
        float *band = NULL;
        for (;;) {
            int r[4];
            get_reply(r);
            if (r[0] != GIVE_BAND) break;
            pray_rect rect = {0, r[1], W, r[2] - r[1]};
            float *nb = (float *)realloc(band, sizeof(float) * 3 * (size_t)W * (size_t)rect.height);
            if (!nb) {
                free(band);
                return pray_set_error(c, PRAY_ERR_NOMEM, "out of memory");
            }
            band = nb;
            b.rgb = band;
            pray_status st = pray_render_into(c, root, lights, &rect, &b);
            if (st != PRAY_OK) {
                free(band);
                return st;
            }
            int h[4] = {frame, r[1], r[2], W};
            MPI_Send(h, 4, MPI_INT, 0, TAG_RESULT, MPI_COMM_WORLD);
            MPI_Send(band, 3 * W * rect.height, MPI_FLOAT, 0, TAG_DATA, MPI_COMM_WORLD);
        }
        free(band);
        return PRAY_OK;  // nothing to write here: rank 0 writes the frame
    }
    if (frame != w.next_frame) return PRAY_OK;  // another rank's frame
    pray_image img;
    pray_status st = pray_render(c, root, lights, &img);
    if (st != PRAY_OK) return st;
    int h[4] = {frame, W, H, 0};
    MPI_Send(h, 4, MPI_INT, 0, TAG_RESULT, MPI_COMM_WORLD);
    MPI_Send(img.pixels, 3 * W * H, MPI_FLOAT, 0, TAG_DATA, MPI_COMM_WORLD);
    pray_image_free(c, &img);
    int r[4];
    get_reply(r);
    w.next_frame = r[0] == GIVE_FRAME ? r[1] : -1;
    return PRAY_OK;
}

// The first pass: every rank runs the program without rendering, to count its frames and to
// find the program's errors, which every rank finds alike.
pray_status skip_frame(void *, pray_ctx *, pray_object *, pray_light *, int, pray_image *) { return PRAY_OK; }

void to_stderr(void *, const void *p, size_t n) { fwrite(p, 1, n, stderr); }
void to_stdout(void *, const void *p, size_t n) { fwrite(p, 1, n, stdout); }

int usage(const char *fmt, const char *arg) {
    if (rank == 0) {
        fprintf(stderr, "pray-mpi: ");
        fprintf(stderr, fmt, arg);
        fprintf(stderr, "\nrun 'pray-mpi --help' for the options\n");
    }
    return 2;
}

int run(int argc, char **argv) {
    pray_ctx *c = pray_new();
    if (!c) {
        fprintf(stderr, "pray-mpi: error: out of memory\n");
        return 1;
    }
    const char *program = NULL;
    int split = 0;  // 0 automatic, 1 rows, 2 frames
    int quiet = 0;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i], *next = i + 1 < argc ? argv[i + 1] : NULL;
        pray_status st = PRAY_OK;
        if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0) {
            if (rank == 0) fputs(USAGE, stdout);
            pray_free(c);
            return 0;
        } else if (strcmp(a, "--quiet") == 0 || strcmp(a, "-q") == 0) quiet = 1;
        else if (strcmp(a, "--brute") == 0) st = pray_option_fix(c, "brute", "1");
        else if (strcmp(a, "--untrusted") == 0) pray_set_untrusted(c);
        else if (!strcmp(a, "-o") || !strcmp(a, "-s") || !strcmp(a, "-D") || !strcmp(a, "--threads") ||
                 !strcmp(a, "--split")) {
            if (!next) {
                pray_free(c);
                return usage("option %s needs a value", a);
            }
            i++;
            if (!strcmp(a, "-o")) st = pray_option_fix(c, "output", next);
            else if (!strcmp(a, "--threads")) st = pray_option_fix(c, "threads", next);
            else if (!strcmp(a, "--split")) {
                if (!strcmp(next, "rows")) split = 1;
                else if (!strcmp(next, "frames")) split = 2;
                else {
                    pray_free(c);
                    return usage("--split takes rows or frames, not '%s'", next);
                }
            } else {
                char name[64];
                const char *sep = strchr(next, a[1] == 's' ? 'x' : '=');
                if (!sep || sep == next || !sep[1] || sep - next >= (long)sizeof name) {
                    pray_free(c);
                    return usage(a[1] == 's' ? "-s takes WIDTHxHEIGHT, as in -s 640x480, not '%s'"
                                             : "-D takes name=value, not '%s'", next);
                }
                memcpy(name, next, (size_t)(sep - next));
                name[sep - next] = 0;
                if (a[1] == 's') {
                    st = pray_option_fix(c, "width", name);
                    if (st == PRAY_OK) st = pray_option_fix(c, "height", sep + 1);
                } else
                    st = pray_option_fix(c, name, sep + 1);
            }
        } else if (a[0] == '-' && a[1]) {
            pray_free(c);
            return usage("unknown option '%s'", a);
        } else if (program) {
            pray_free(c);
            return usage("only one program, please ('%s' is the second)", a);
        } else
            program = a;
        if (st != PRAY_OK) {
            if (rank == 0) fprintf(stderr, "pray-mpi: %s\n", pray_error(c));
            pray_free(c);
            return 2;
        }
    }
    if (!program) {
        pray_free(c);
        return usage("no program given%s", "");
    }
    if (strcmp(program, "-") == 0) {
        pray_free(c);
        return usage("the program must be a file that every rank reads, not '%s'", "-");
    }

    // First pass: count the frames; a failure on any rank is reported by the first that failed.
    pray_set_print(c, NULL, NULL);
    pray_set_render(c, skip_frame, NULL);
    pray_status st = pray_run_file(c, program);
    int nframes = pray_frames(c);
    int failed = st != PRAY_OK ? rank : nranks, first = nranks;
    MPI_Allreduce(&failed, &first, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
    if (first < nranks) {
        int code = exit_code(st);
        if (rank == first) show_error(pray_error(c));
        MPI_Bcast(&code, 1, MPI_INT, first, MPI_COMM_WORLD);
        pray_free(c);
        return code;
    }
    int rows_mode = split ? split == 1 : nframes <= 1;

    // Second pass: the render.
    Master m;
    Worker w;
    memset(&m, 0, sizeof m);
    memset(&w, 0, sizeof w);
    if (rank == 0) {
        pray_set_print(c, to_stdout, NULL);  // rank 0 prints what the program prints, as pray
        if (!quiet) pray_set_warning(c, to_stderr, NULL);
    }
    if (nranks == 1) {
        pray_set_render(c, NULL, NULL);  // one process: pray alone
    } else if (rank == 0) {
        m.rows_mode = rows_mode;
        m.nframes = nframes;
        m.frame = -1;
        m.told_done = (int *)calloc((size_t)nranks, sizeof(int));
        m.waiting = (int *)malloc(sizeof(int) * (size_t)nranks);
        m.frames = (float **)calloc((size_t)nframes + 1, sizeof(float *));
        m.fw = (int *)calloc((size_t)nframes + 1, sizeof(int));
        m.fh = (int *)calloc((size_t)nframes + 1, sizeof(int));
        if (!m.told_done || !m.waiting || !m.frames || !m.fw || !m.fh) {
            pray_set_error(c, PRAY_ERR_NOMEM, "out of memory");
            die(c, PRAY_ERR_NOMEM);
        }
        for (int r = 0; r < nranks; r++) m.waiting[r] = -1, m.told_done[r] = -1;
        pray_set_render(c, master_render, &m);
    } else {
        w.rows_mode = rows_mode;
        w.next_frame = -1;
        if (!rows_mode && nframes > 0) {  // the first frame of this rank
            int r[4];
            ask(0);
            get_reply(r);
            w.next_frame = r[0] == GIVE_FRAME ? r[1] : -1;
        }
        pray_set_render(c, worker_render, &w);
    }
    if (rank == 0) catch_signals(c);
    st = pray_run_file(c, program);
    if (rank == 0) catch_signals(NULL);
    if (st != PRAY_OK) die(c, st);
    if (rank == 0 && nranks > 1) {
        // every rank gets its last answer: rows, "done" for the last frame; frames, "no more"
        int last = nframes - 1;
        for (;;) {
            int all = 1;
            for (int r = 1; r < nranks; r++)
                if (rows_mode ? m.told_done[r] < last : m.told_done[r] != 1) all = 0;
            if (all || nframes == 0) break;
            serve_one(m, c);
        }
        free(m.told_done);
        free(m.waiting);
        free(m.frames);
        free(m.fw);
        free(m.fh);
    }
    pray_free(c);
    all_done();
    return 0;
}

} // namespace

int main(int argc, char **argv) {
    signal(SIGXFSZ, SIG_IGN);  // a file over the size limit (ulimit -f): a write error, as in pray
    MPI_Init(&argc, &argv);
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &nranks);
    int rc = run(argc, argv);
    fflush(stdout);
    MPI_Finalize();
    return rc;
}
