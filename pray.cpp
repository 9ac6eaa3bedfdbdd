/* pray.cpp — the whole implementation of pray. MIT License, see LICENSE.

   Index (grep '\[SECTION\]'). Each section has a budget of lines, from its banner to the next
   one; tests/sections.sh checks them (docs/testing.md). A budget is lowered when a section
   shrinks, and raised only as a decision.
   section      budget  contents
   [SECTION] 1     500  Portability shims: configuration, real type, clock, terminal, files, threads
   [SECTION] 2     300  Context: allocator with a cap, status and messages
   [SECTION] 3     100  Tiny containers on the context allocator
   [SECTION] 4     200  Vector math and the `.` transformations
   [SECTION] 5     700  Scene values: models, lights, solids (reference counted handles)
   [SECTION] 6     150  Options
   [SECTION] 7    1165  Prepared scene: flattened n-ary CSG tree, boxes, simplification, snapping
   [SECTION] 8     450  Ray/primitive intersection; primitives in a frame (box, rod, cone, torus,
                          stretched)
   [SECTION] 9     450  CSG status-tree sweep (the brute-force reference, thesis 3.4)
   [SECTION] 9b   2942  Acceleration: action lists, uniform grid, traversal, freezing, areas (3.3-3.6)
                          [9b.1] the structure; building: [9b.2] lists and plans, [9b.3] the grid, areas
                          and jumps, [9b.4] light and eye buffers, [9b.5] accel_build; per ray: [9b.6]
                          list evaluation with freezing, [9b.7] stretch sources, [9b.8] the ray driver
   [SECTION] 9c    950  Reading files (programs, textures, fonts), TIFF reader and textures, the
                          built-in font
   [SECTION] 10   1250  Whitted shading, textured surfaces, the render driver (threads, undersampling)
   [SECTION] 10b   600  Image sequences (3.7): the regions a ray crosses, comparing a frame's scene
                          with the one before, records
   [SECTION] 11   1800  Image writers: TIFF, PPM, PNG; writing files safely; public functions
   [SECTION] 12    500  PRAY lexer
   [SECTION] 13   1100  PRAY parser
   [SECTION] 14   1650  PRAY interpreter: values, operators, builtins, statements
   [SECTION] 15    200  One-call helpers and the running of programs
   [SECTION] 16    800  Command-line program (PRAY_MAIN)
   The whole file: at most 15438 lines.
*/

// =============================================================================================
// [SECTION] 1 Portability shims
// =============================================================================================
#if defined(__unix__) || defined(__APPLE__)
#ifndef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L  // openat, O_NOFOLLOW, O_DIRECTORY
#endif
#ifndef _XOPEN_SOURCE
#define _XOPEN_SOURCE 700
#endif
#endif

#include "pray.hpp"

// wasm32-wasi (ports/wasm): the C library's <signal.h> is an emulation to be asked for (it
// gives sig_atomic_t and signal; the command-line program links -lwasi-emulated-signal).
#if defined(__wasi__) && !defined(_WASI_EMULATED_SIGNAL)
#define _WASI_EMULATED_SIGNAL
#endif

// No fused multiply-add behind our back: the same bits on every target (ports/README.md).
#if defined(__clang__)
#pragma STDC FP_CONTRACT OFF
#elif defined(__GNUC__)
#pragma GCC push_options
#pragma GCC optimize("fp-contract=off")
#endif

#include <ctype.h>
#include <errno.h>
#include <float.h>
#include <limits.h>
#include <math.h>
#include <signal.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#if PRAY_VERSION_MAJOR != 0 || PRAY_VERSION_MINOR != 4
#error "pray.cpp and pray.hpp are from different versions"
#endif

// pray relies on IEEE arithmetic: rays run to infinity, and a program's 10^400 or 0/0 is an error
// found by testing for infinities and NaN, which -ffast-math, -ffinite-math-only, -Ofast or /fp:fast
// allow the compiler to remove. Compile pray.cpp without them (with GCC and Clang, -fno-fast-math
// after the other flags undoes them; pray's CMake target adds it).
#if defined(__FAST_MATH__) || (defined(__FINITE_MATH_ONLY__) && __FINITE_MATH_ONLY__) || defined(_M_FP_FAST)
#error "pray.cpp needs IEEE infinities and NaN: compile it without -ffast-math, -ffinite-math-only, -Ofast or /fp:fast (add -fno-fast-math)"
#endif

#ifndef PRAY_REAL
#define PRAY_REAL double
#endif
#ifndef PRAY_MAX_ALLOC
#define PRAY_MAX_ALLOC 0
#endif
#ifndef PRAY_TEMP_SUFFIX
#define PRAY_TEMP_SUFFIX ".tmp"
#endif

// Invariants that only end-to-end tests would otherwise catch are stated with PRAY_ASSERT. They
// are checked when PRAY_CHECKS is defined (the tests' builds) and cost nothing otherwise; a host
// may define PRAY_ASSERT(x) itself to report a failure its own way.
#ifndef PRAY_ASSERT
#ifdef PRAY_CHECKS
#define PRAY_ASSERT(x) ((x) ? (void)0 : pray_assert_failed(__FILE__, __LINE__, #x))
#else
#define PRAY_ASSERT(x) ((void)0)
#endif
#endif

#ifdef PRAY_NO_INTERP
#define PRAY_HAS_INTERP 0
#else
#define PRAY_HAS_INTERP 1
#endif
#ifdef PRAY_NO_STDIO
#define PRAY_HAS_STDIO 0
#else
#define PRAY_HAS_STDIO 1
#endif
#ifdef PRAY_NO_DEFAULT_ALLOC
#define PRAY_HAS_DEFAULT_ALLOC 0
#else
#define PRAY_HAS_DEFAULT_ALLOC 1
#endif

// PNG output through the system's stb_image_write, when it is there. Its memory comes from the
// context writing the PNG (section 11: png_alloc); an allocation it cannot have ends the encoding
// there, so its own checks (asserts) are not needed.
#define PRAY_HAS_PNG 0
#ifdef PRAY_NO_PNG
#define PNG_MISSING "it was built with PRAY_NO_PNG"
#else  // (why a build has no PNG, for the messages)
#define PNG_MISSING "<stb/stb_image_write.h> was not found when it was built (Debian: libstb-dev)"
#endif
#if !defined(PRAY_NO_PNG) && defined(__has_include)
#if __has_include(<stb/stb_image_write.h>)
#undef PRAY_HAS_PNG
#define PRAY_HAS_PNG 1
#include <setjmp.h>
static void *png_alloc(void *p, size_t n);
#define STBIW_MALLOC(n) png_alloc(NULL, n)
#define STBIW_REALLOC(p, n) png_alloc(p, n)
#define STBIW_FREE(p) png_alloc(p, 0)
#define STBIW_ASSERT(x) ((void)0)
#define STB_IMAGE_WRITE_STATIC
#define STB_IMAGE_WRITE_IMPLEMENTATION
#define STBI_WRITE_NO_STDIO
#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpedantic"
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#pragma GCC diagnostic ignored "-Wsign-compare"
#pragma GCC diagnostic ignored "-Wold-style-cast"
#pragma GCC diagnostic ignored "-Wconversion"
#pragma GCC diagnostic ignored "-Wcast-qual"
#pragma GCC diagnostic ignored "-Wlong-long"
#pragma GCC diagnostic ignored "-Wimplicit-fallthrough"
#endif
#include <stb/stb_image_write.h>
#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif
#endif
#endif

#if defined(_WIN32)
#include <fcntl.h>
#include <io.h>
#include <sys/stat.h>
#include <windows.h>
#undef near  // 16-bit pointer words that windows.h still defines (to nothing)
#undef far
#elif defined(__unix__) || defined(__APPLE__) || defined(__DJGPP__)
#include <fcntl.h>
#if defined(__DJGPP__)
#include <io.h>  // setmode
#endif
#include <sys/stat.h>
#include <unistd.h>
#define PRAY_HAS_UNISTD 1
#endif

#if defined(PRAY_MAIN) && defined(__DJGPP__)
// CSG trees are walked recursively; DJGPP's default stack of 512 KB is too small for the deepest
// trees pray accepts.
#include <crt0.h>
unsigned _stklen = 4u * 1024 * 1024;
#endif

// Threads: Win32 or POSIX, or none (PRAY_NO_THREADS, and wherever neither is there: DOS).
#if defined(PRAY_NO_THREADS)
#define PRAY_HAS_THREADS 0
#elif defined(_WIN32)
#define PRAY_HAS_THREADS 1
#elif defined(PRAY_HAS_UNISTD) && defined(_POSIX_THREADS) && _POSIX_THREADS > 0
#include <pthread.h>
#define PRAY_HAS_THREADS 1
#if defined(__linux__)
#include <sched.h>  // sched_getaffinity (declared where the C library has GNU's extensions)
#endif
#else
#define PRAY_HAS_THREADS 0
#endif

namespace {

typedef PRAY_REAL real;
#if defined(__GNUC__)
#define PRAY_PRINTF(f, a) __attribute__((format(printf, f, a)))
#else
#define PRAY_PRINTF(f, a)
#endif
// A function that a recursion passes through but seldom runs keeps its stack frame to itself.
#if defined(__GNUC__)
#define PRAY_NOINLINE __attribute__((noinline))
#elif defined(_MSC_VER)
#define PRAY_NOINLINE __declspec(noinline)
#else
#define PRAY_NOINLINE
#endif
#define PRAY_STRINGIFY2(x) #x
#define PRAY_STRINGIFY(x) PRAY_STRINGIFY2(x)

#ifdef PRAY_CHECKS
// A broken invariant (PRAY_ASSERT): say where, and stop.
void pray_assert_failed(const char *file, int line, const char *what) {
#if PRAY_HAS_STDIO
    fprintf(stderr, "%s:%d: invariant broken: %s\n", file, line, what);
#else
    (void)file, (void)line, (void)what;
#endif
    abort();
}
#endif

// Wall-clock seconds, for statistics only.
double clock_seconds() {
#if defined(_WIN32)
    return (double)GetTickCount() / 1000.0;
#elif defined(__wasi__)  // no processor clock: clock() is only an emulation there
    struct timespec ts;
    return clock_gettime(CLOCK_MONOTONIC, &ts) == 0 ? (double)ts.tv_sec + ts.tv_nsec * 1e-9 : 0.0;
#elif defined(PRAY_HAS_UNISTD) && defined(_POSIX_TIMERS) && _POSIX_TIMERS > 0
    struct timespec ts;
    if (clock_gettime(CLOCK_MONOTONIC, &ts) == 0) return (double)ts.tv_sec + ts.tv_nsec * 1e-9;
    return (double)clock() / CLOCKS_PER_SEC;
#else
    return (double)clock() / CLOCKS_PER_SEC;
#endif
}

#if PRAY_HAS_STDIO
// Processor ticks, to vary a seed (temporary names).
unsigned long clock_ticks() {
#if defined(__wasi__)
    return (unsigned long)(clock_seconds() * 1e6);
#else
    return (unsigned long)clock();
#endif
}

// Replace `to` by `from`. Windows' rename refuses to overwrite, so remove the target first.
bool file_replace(const char *from, const char *to) {
#if defined(_WIN32) || defined(__DJGPP__)
    remove(to);
#endif
    return rename(from, to) == 0;
}
#endif

// Files by descriptor, so that a file is opened once and what was opened is checked (fstat):
// POSIX (open, openat, fstat, fdopen), DJGPP and Windows (open and fstat without links or
// openat). PRAY_FILES_AT: a name can be walked from a directory without following links.
// Elsewhere (PRAY_FILES_FD 0) only fopen: no check of the kind of file, no exclusive creation.
#if PRAY_HAS_STDIO && defined(_WIN32)
#define PRAY_FILES_FD 1
#define PRAY_FILES_AT 0
struct FileId {
    int valid;  // Windows gives no inode: files are compared by name
};
int fd_open(const char *path, int write) {
    return write ? _open(path, _O_WRONLY | _O_CREAT | _O_EXCL | _O_BINARY, _S_IREAD | _S_IWRITE)
                 : _open(path, _O_RDONLY | _O_BINARY);
}
void fd_close(int fd) { _close(fd); }
FILE *fd_stdio(int fd, const char *mode) { return _fdopen(fd, mode); }
// Is the open file a regular one? (Windows gives no inode: no identity.)
bool fd_regular(int fd, FileId *id) {
    struct _stat st;
    if (id) id->valid = 0;
    return _fstat(fd, &st) == 0 && (st.st_mode & _S_IFMT) == _S_IFREG;
}
bool name_id(const char *, FileId *id) { return (id->valid = 0) != 0; }
unsigned long process_id() { return (unsigned long)GetCurrentProcessId(); }
#elif PRAY_HAS_STDIO && defined(PRAY_HAS_UNISTD)
#define PRAY_FILES_FD 1
#ifndef O_BINARY
#define O_BINARY 0
#endif
#ifndef O_NOFOLLOW
#define O_NOFOLLOW 0
#endif
#ifndef O_NONBLOCK
#define O_NONBLOCK 0
#endif
#ifndef O_CLOEXEC
#define O_CLOEXEC 0
#endif
#if defined(AT_FDCWD) && defined(O_DIRECTORY) && O_NOFOLLOW != 0 && !defined(__DJGPP__)
#define PRAY_FILES_AT 1
#else
#define PRAY_FILES_AT 0
#endif
// DJGPP makes inode numbers up: files are compared by name there.
#if defined(__DJGPP__)
#define PRAY_FILE_IDS 0
#else
#define PRAY_FILE_IDS 1
#endif
struct FileId {
    int valid;  // 1 when dev and ino identify the file
    dev_t dev;
    ino_t ino;
};
// Reading never blocks in open (a FIFO would wait for a writer); creating is exclusive and never
// through a link, with mode 0666 less the umask, as fopen would.
int fd_open(const char *path, int write) {
    return write ? open(path, O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC | O_BINARY, 0666)
                 : open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_BINARY);
}
void fd_close(int fd) { close(fd); }
FILE *fd_stdio(int fd, const char *mode) { return fdopen(fd, mode); }
bool fd_regular(int fd, FileId *id) {
    struct stat st;
    if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) return false;
    if (id) {
        id->valid = PRAY_FILE_IDS;
        id->dev = st.st_dev;
        id->ino = st.st_ino;
    }
    return true;
}
#if PRAY_FILES_AT
// One step of a walk: `name` in directory `dir`, not followed if it is a link; a directory
// unless `last`.
int fd_open_at(int dir, const char *name, bool last) {
    return openat(dir, name, O_RDONLY | O_NOFOLLOW | O_CLOEXEC | (last ? O_NONBLOCK : O_DIRECTORY));
}
// Is `name` in directory `dir` a symbolic link? (Only to explain a walk that failed.)
bool is_link_at(int dir, const char *name) {
    struct stat st;
    return fstatat(dir, name, &st, AT_SYMLINK_NOFOLLOW) == 0 && S_ISLNK(st.st_mode);
}
#endif
// The identity of a file by name (following links), for comparing two names.
bool name_id(const char *path, FileId *id) {
    struct stat st;
    id->valid = 0;
    if (stat(path, &st) != 0) return false;
    id->valid = PRAY_FILE_IDS;
    id->dev = st.st_dev;
    id->ino = st.st_ino;
    return true;
}
// Which process this is, for unique temporary names.
unsigned long process_id() { return (unsigned long)getpid(); }
#else
#define PRAY_FILES_FD 0
#define PRAY_FILES_AT 0
struct FileId {
    int valid;
};
#if PRAY_HAS_STDIO
bool name_id(const char *, FileId *id) { return (id->valid = 0) != 0; }
unsigned long process_id() { return 0; }
#endif
#endif
#if PRAY_HAS_STDIO
bool same_id(const FileId &a, const FileId &b) {
#if PRAY_FILES_FD && !defined(_WIN32)
    return a.valid && b.valid && a.dev == b.dev && a.ino == b.ino;
#else
    (void)a;
    (void)b;
    return false;
#endif
}
#endif

#if defined(PRAY_MAIN)
bool stderr_is_terminal() {
#if defined(_WIN32)
    return _isatty(2) != 0;
#elif defined(PRAY_HAS_UNISTD)
    return isatty(2) != 0;
#else
    return false;
#endif
}
#endif

// A lock and a way to run a function on several threads at once.
struct Mutex {
#if PRAY_HAS_THREADS && defined(_WIN32)
    CRITICAL_SECTION m;
    void init() { InitializeCriticalSection(&m); }
    void lock() { EnterCriticalSection(&m); }
    void unlock() { LeaveCriticalSection(&m); }
    void destroy() { DeleteCriticalSection(&m); }
#elif PRAY_HAS_THREADS
    pthread_mutex_t m;
    void init() { pthread_mutex_init(&m, NULL); }
    void lock() { pthread_mutex_lock(&m); }
    void unlock() { pthread_mutex_unlock(&m); }
    void destroy() { pthread_mutex_destroy(&m); }
#else
    void init() {}
    void lock() {}
    void unlock() {}
    void destroy() {}
#endif
};

typedef void (*ThreadFn)(void *arg);

#if PRAY_HAS_THREADS && defined(_WIN32)
struct ThreadStart {
    ThreadFn fn;
    void *arg;
};
DWORD WINAPI thread_main(LPVOID p) {
    ThreadStart *t = (ThreadStart *)p;
    t->fn(t->arg);
    return 0;
}
#elif PRAY_HAS_THREADS
struct ThreadStart {
    ThreadFn fn;
    void *arg;
};
void *thread_main(void *p) {
    ThreadStart *t = (ThreadStart *)p;
    t->fn(t->arg);
    return NULL;
}
#endif

// Run fn(args[i]) for i < n, on n threads where possible (the caller's is one of them).
// `starts` has room for n entries. Where a thread cannot be started, the caller runs its share.
void run_parallel(int n, ThreadFn fn, void **args, void *starts) {
#if PRAY_HAS_THREADS
    ThreadStart *ts = (ThreadStart *)starts;
#if defined(_WIN32)
    HANDLE h[64];
#else
    pthread_t h[64];
#endif
    bool started[64];
    if (n > 64) n = 64;
    for (int i = 1; i < n; i++) {
        ts[i].fn = fn;
        ts[i].arg = args[i];
#if defined(_WIN32)
        h[i] = CreateThread(NULL, 0, thread_main, &ts[i], 0, NULL);
        started[i] = h[i] != NULL;
#else
        started[i] = pthread_create(&h[i], NULL, thread_main, &ts[i]) == 0;
#endif
    }
    fn(args[0]);
    for (int i = 1; i < n; i++) {
        if (!started[i]) {
            fn(args[i]);
            continue;
        }
#if defined(_WIN32)
        WaitForSingleObject(h[i], INFINITE);
        CloseHandle(h[i]);
#else
        pthread_join(h[i], NULL);
#endif
    }
#else
    (void)starts;
    for (int i = 0; i < n; i++) fn(args[i]);
#endif
}

// Processors to use when the option threads is 0 (automatic): those the process may run on (its
// affinity: taskset, a cpuset, Slurm's or mpirun's binding), as nproc counts them, where the
// system says; else the machine's.
int cpu_count() {
#if PRAY_HAS_THREADS && defined(_WIN32)
    DWORD_PTR mine = 0, all = 0;
    if (GetProcessAffinityMask(GetCurrentProcess(), &mine, &all) && mine) {
        int n = 0;
        for (; mine; mine &= mine - 1) n++;
        return n;
    }
    SYSTEM_INFO si;
    GetSystemInfo(&si);
    return (int)si.dwNumberOfProcessors;
#elif PRAY_HAS_THREADS && defined(_SC_NPROCESSORS_ONLN)
#if defined(__linux__) && defined(CPU_COUNT)
    cpu_set_t set;
    if (sched_getaffinity(0, sizeof set, &set) == 0 && CPU_COUNT(&set) > 0) return CPU_COUNT(&set);
#endif
    long n = sysconf(_SC_NPROCESSORS_ONLN);
    return n > 0 ? (int)n : 1;
#else
    return 1;
#endif
}

// Limits of one run (the robustness issue makes more of them options).
const int MAX_NESTING = 1024;       // blocks and parentheses: the highest value of option maxnest
const int MAX_TREE_DEPTH = 2000;    // CSG nodes along one path from the root
const long MAX_PRIMITIVES = 16777216; // the highest value of option maxprims
const int MAX_IMAGE_SIDE = 65536;   // pixels
const double MAX_IMAGE_PIXELS = 268435456.0;

// =============================================================================================
// [SECTION] 2 Context: allocator with a cap, status and messages
// =============================================================================================

// Every block carries this header, so a context can free all it ever made.
// The owner is how a handle or an image knows its context (it also keeps the payload 16-byte
// aligned on 64-bit targets).
struct Block {
    Block *prev, *next;
    size_t size;
    pray_ctx *owner;
};

struct Coherence;  // image sequences (10b): what a program's last frame left for its next
// A file a running program read (include, texture, font): its identity where files have one,
// and its name as opened (compared where they have none). No image may replace it (9c: is_input).
struct ReadFile {
    ReadFile *next;
    FileId id;
    char *name;
};

// A texture or a program text the host registered under a name (pray_texture_register,
// pray_include_register).
struct TexName {
    TexName *next;
    pray_texture *tex;
    char *name, *text;
    size_t len;
};

} // namespace

// Options by index; the table in section 6 has their names, defaults and ranges.
enum {
    OPT_ADAPTIVE, OPT_ANTIALIAS, OPT_BITS, OPT_BOUNDS, OPT_BRUTE, OPT_COHERENCE, OPT_CUTOFF, OPT_DEPTH, OPT_EYEBUFFER, OPT_FREEZE,
    OPT_GRID, OPT_GRIDMEM, OPT_HEIGHT, OPT_LIGHTBUFFER, OPT_MAXFRAMES, OPT_MAXLINE, OPT_MAXMEM, OPT_MAXNEST,
    OPT_MAXOUTPUT, OPT_MAXPIXELS, OPT_MAXPRIMS, OPT_MAXRAYS, OPT_MAXSTEPS, OPT_MAXSTRING, OPT_MAXTIME, OPT_MERGE, OPT_NEST, OPT_OUTPUT,
    OPT_PLANS, OPT_SHADOWCACHE, OPT_SHADOWS, OPT_TEXMEM, OPT_THREADS,
    OPT_WIDTH, OPT_COUNT
};

struct Options {
    double v[OPT_COUNT];
    char output[1024];
};

// Options, camera and background: what statements and API calls set before a render.
struct Setup {
    Options opt;
    int parallel;
    pray_vec cam_x, cam_y, cam_eye, cam_point;
    int lookat;  // cam_x and cam_y follow from these for the image's size (camera_axes)
    pray_vec cam_up;
    double cam_angle;
    pray_rgb bg_top, bg_bottom;
};

struct pray_ctx {
    pray_alloc_fn alloc;
    void *alloc_ud;
    size_t used, limit;  // limit: the smaller of the host's cap and option maxmem (0 = none)
    size_t peak;         // the most `used` has been since the phase began (mem_phase)
    size_t host_limit;   // what pray_set_memory_limit set
    int untrusted;       // pray_set_untrusted: limits have ceilings, files stay beside the program
    Block blocks;  // sentinel of the list of live blocks
    pray_status status;
    char msg[1024];
    int err_line, err_col;   // where in a program the last error is (0: nowhere), and in which file:
    char err_name[256];      // (pray_error_place)
    pray_write_fn print_fn;
    void *print_ud;
    int print_set;
    pray_progress_fn progress_fn;
    void *progress_ud;
    pray_frame_fn frame_fn;  // what a program's rendertiff hands its frame to (see frame_route)
    void *frame_ud;
    pray_frame_fn host_frame_fn;  // pray_set_frame
    void *host_frame_ud;
    pray_render_fn render_fn;     // pray_set_render: the host renders a program's frames
    void *render_ud;
    int in_render_fn;             // render_fn is running: pray_render inside it renders
    pray_write_fn warn_fn;  // pray_set_warning
    void *warn_ud;
    Setup cur;       // in force now
    Setup base;      // what the host set; every run starts from it and ends back at it
    int running;     // a program is running: its settings change `cur` only
    unsigned char fixed[OPT_COUNT];  // per option: set from the command line, programs cannot change it
    pray_stats stats;
    int frames;
    pray_texture *textures;  // files decoded in this run
    TexName *tex_names;      // textures registered by the host, looked up before files
    TexName *inc_names;      // and texts for include
    const char *run_dir;     // directory of the running program: the start of its name
    size_t run_dir_len;      // (0: the current directory), for texture files
    FileId prog_id;          // the program file being run, which no image may replace
    const char *prog_name;   // its name (compared where files have no identity)
    ReadFile *inputs;        // the files the last run read: includes, textures, fonts (note_input)
    char *volatile temp_name;  // the temporary file being written now (pray_temp_file)
    unsigned temp_serial;    // makes temporary names unique
    double written;          // bytes of image files written by this run (option maxoutput)
    pray_object *drop;       // given up by a program's rendertiff: released once flattened (scene_build)
    int eye_inside;          // the camera's eye is inside the solid last rendered (render_scene)
    int no_light, dark;      // no light reaches any surface the eye saw in it (render_scene);
                             // dark: the same of the last frame rendered, kept
    volatile sig_atomic_t cancel;  // CANCEL_*: the running call stops at its next check
    int calls;               // cancellable public calls running (a run renders and writes)
    double started;          // when the outermost of them started (option maxtime)
    Coherence *coh;          // image sequences (option coherence): the frame before, or NULL
    struct Prepared *prep;   // the scene pray_render_into prepared last, outside runs, or NULL
};

namespace {

#if PRAY_HAS_DEFAULT_ALLOC
void *default_alloc(void *, void *ptr, size_t, size_t nsize) {
    if (nsize == 0) {
        free(ptr);
        return NULL;
    }
    return realloc(ptr, nsize);
}
#endif

// Record an error "error: ..." and return its status.
pray_status fail(pray_ctx *c, pray_status s, const char *fmt, ...) PRAY_PRINTF(3, 4);
pray_status fail(pray_ctx *c, pray_status s, const char *fmt, ...) {
    va_list ap;
    va_start(ap, fmt);
    char tmp[900];
    vsnprintf(tmp, sizeof tmp, fmt, ap);
    va_end(ap);
    c->status = s;
    c->err_line = c->err_col = 0;
    snprintf(c->msg, sizeof c->msg, "error: %s", tmp);
    return s;
}

pray_status fail_nomem(pray_ctx *c) {
    return fail(c, PRAY_ERR_NOMEM, "out of memory");
}

// Why the running call stops: pray_cancel (from any thread or a signal handler), or the time
// of option maxtime spent. The flag is an atomic where the compiler has them, so that a host's
// thread sanitizer sees no race, and lock-free, so that a signal handler may set it.
enum { CANCEL_NONE, CANCEL_HOST, CANCEL_TIME };
inline int cancel_flag(const pray_ctx *c) {
#if defined(__GNUC__) || defined(__clang__)
    return __atomic_load_n(&c->cancel, __ATOMIC_RELAXED);
#else
    return c->cancel;
#endif
}
inline void cancel_set(pray_ctx *c, int why) {
#if defined(__GNUC__) || defined(__clang__)
    __atomic_store_n(&c->cancel, (sig_atomic_t)why, __ATOMIC_RELAXED);
#else
    c->cancel = (sig_atomic_t)why;
#endif
}

// A public call that pray_cancel can stop, between call_enter and call_leave. The outermost one
// forgets a cancel made before it started and starts the clock of option maxtime; the work checks
// `cancelled` in its loops (statements, voxels, rows of the image) and `over_time` where it is
// long (statements, rows).
// (Entered and left by hand, not by a destructor: then pray.cpp needs no C++ runtime, however it
// is compiled; a cleanup on the way out of a function would need the exception personality.)
void call_enter(pray_ctx *c) {
    if (c->calls++ == 0) {
        cancel_set(c, CANCEL_NONE);
        c->started = clock_seconds();
    }
}
void call_leave(pray_ctx *c) { c->calls--; }
inline bool cancelled(const pray_ctx *c) { return cancel_flag(c) != CANCEL_NONE; }
// The run has taken longer than option maxtime allows: every check of `cancelled` stops it.
bool over_time(pray_ctx *c) {
    double lim = c->cur.opt.v[OPT_MAXTIME];
    if (lim > 0 && c->calls > 0 && clock_seconds() - c->started > lim) cancel_set(c, CANCEL_TIME);
    return cancelled(c);
}
const char *cancel_text(const pray_ctx *c, char *buf, size_t size) {
    if (cancel_flag(c) != CANCEL_TIME) return "cancelled";
    double lim = c->cur.opt.v[OPT_MAXTIME];
    snprintf(buf, size, "the run was stopped after %.0f second%s (option maxtime)", lim, lim == 1 ? "" : "s");
    return buf;
}
pray_status cancel_status(const pray_ctx *c) {
    return cancel_flag(c) == CANCEL_TIME ? PRAY_ERR_LIMIT : PRAY_ERR_CANCELLED;
}
pray_status fail_cancelled(pray_ctx *c) {
    char buf[80];
    return fail(c, cancel_status(c), "%s", cancel_text(c, buf, sizeof buf));
}

// The context's cap: the host's, lowered by option maxmem (MiB) when that is set.
void apply_memory_cap(pray_ctx *c) {
    size_t cap = c->host_limit;
    double mib = c->cur.opt.v[OPT_MAXMEM];
    if (mib > 0 && mib * 1048576.0 < (double)((size_t)-1 / 2)) {
        size_t b = (size_t)(mib * 1048576.0);
        if (cap == 0 || b < cap) cap = b;
    }
    c->limit = cap;
}

// A block into a list of blocks (after its sentinel), and out of the list it is in.
void block_link(Block *list, Block *b) {
    b->prev = list;
    b->next = list->next;
    list->next->prev = b;
    list->next = b;
}
void block_unlink(Block *b) {
    b->prev->next = b->next;
    b->next->prev = b->prev;
}

void *mem_alloc(pray_ctx *c, size_t n) {
    if (n > (size_t)-1 / 2) {
        fail_nomem(c);
        return NULL;
    }
    if (c->limit && c->used + n + sizeof(Block) > c->limit) {
        if (c->limit != c->host_limit)
            fail(c, PRAY_ERR_NOMEM, "out of memory: over the cap of %.0f MiB (option maxmem)", c->cur.opt.v[OPT_MAXMEM]);
        else fail(c, PRAY_ERR_NOMEM, "out of memory: over the context's cap of %lu bytes", (unsigned long)c->limit);
        return NULL;
    }
    Block *b = (Block *)c->alloc(c->alloc_ud, NULL, 0, sizeof(Block) + n);
    if (!b) {
        fail_nomem(c);
        return NULL;
    }
    b->size = n;
    b->owner = c;
    block_link(&c->blocks, b);
    c->used += n + sizeof(Block);
    if (c->used > c->peak) c->peak = c->used;
    return b + 1;
}

void *mem_zalloc(pray_ctx *c, size_t n) {
    void *p = mem_alloc(c, n);
    if (p) memset(p, 0, n);
    return p;
}

// The context a block of mem_alloc belongs to.
inline const pray_ctx *owner_of(const void *p) { return ((const Block *)p - 1)->owner; }

void mem_free(pray_ctx *c, void *p) {
    if (!p) return;
    Block *b = (Block *)p - 1;
    block_unlink(b);
    c->used -= b->size + sizeof(Block);
    c->alloc(c->alloc_ud, b, sizeof(Block) + b->size, 0);
}

// Grow (or shrink) a block; on failure the old block stays valid and NULL is returned.
void *mem_realloc(pray_ctx *c, void *p, size_t n) {
    if (!p) return mem_alloc(c, n);
    Block *b = (Block *)p - 1;
    void *q = mem_alloc(c, n);
    if (!q) return NULL;
    memcpy(q, p, b->size < n ? b->size : n);
    mem_free(c, p);
    return q;
}

// Where a scene's bytes go (pray_stats): the phase that began at the last call ends now; the
// most the context held during it goes into *phase (when more than what is there) and into the
// peak of all phases. The next phase begins with what is held now.
enum MemPhase { MEM_PARSE, MEM_RUN, MEM_PREPARE, MEM_ACCEL, MEM_RENDER };
void mem_phase(pray_ctx *c, MemPhase phase) {
    double *field[] = {&c->stats.memory_parse, &c->stats.memory_run, &c->stats.memory_prepare,
                       &c->stats.memory_accel, &c->stats.memory_render};
    double most = (double)c->peak;
    if (most > *field[phase]) *field[phase] = most;
    if (most > c->stats.memory_peak) c->stats.memory_peak = most;
    c->peak = c->used;
}

char *mem_strdup(pray_ctx *c, const char *s, size_t n) {
    char *p = (char *)mem_alloc(c, n + 1);
    if (!p) return NULL;
    memcpy(p, s, n);
    p[n] = 0;
    return p;
}

// =============================================================================================
// [SECTION] 3 Tiny containers on the context allocator (for plain-old-data elements)
// =============================================================================================
template <class T> struct Array {
    T *p;
    int n, cap;
    void init() {
        p = NULL;
        n = cap = 0;
    }
    bool reserve(pray_ctx *c, int want) {
        if (want <= cap) return true;
        int nc = cap ? cap : 8;
        while (nc < want) {
            if (nc > INT_MAX / 2) {
                fail_nomem(c);
                return false;
            }
            nc *= 2;
        }
        T *q = (T *)mem_realloc(c, p, (size_t)nc * sizeof(T));
        if (!q) return false;
        p = q;
        cap = nc;
        return true;
    }
    // Room for exactly `want` (no more), when that is more than there is.
    bool reserve_exact(pray_ctx *c, int want) {
        if (want <= cap) return true;
        T *q = (T *)mem_realloc(c, p, (size_t)want * sizeof(T));
        if (!q) return false;
        p = q;
        cap = want;
        return true;
    }
    bool push(pray_ctx *c, const T &v) {
        if (n == cap && !reserve(c, n + 1)) return false;
        p[n++] = v;
        return true;
    }
    void release(pray_ctx *c) {
        mem_free(c, p);
        init();
    }
    T &operator[](int i) { return p[i]; }
    const T &operator[](int i) const { return p[i]; }
};

// A growing text buffer, NUL-terminated.
struct Text {
    Array<char> a;
    void init() { a.init(); }
    bool add(pray_ctx *c, const char *s, size_t n) {
        if (n >= (size_t)(INT_MAX - a.n)) return fail_nomem(c), false;  // over 2 GiB
        if (!a.reserve(c, a.n + (int)n + 1)) return false;
        memcpy(a.p + a.n, s, n);
        a.n += (int)n;
        a.p[a.n] = 0;
        return true;
    }
    bool adds(pray_ctx *c, const char *s) { return add(c, s, strlen(s)); }
    const char *str() const { return a.p ? a.p : ""; }
};

// Sort n items by `less` (a strict weak order; items it leaves unordered keep their order),
// with tmp (room for n) as scratch: a merge sort of runs sorted by insertion, the comparison
// inlined. For the large sorts of preparation, where qsort's comparison through a pointer cost
// more than the sorting itself.
template <class T, class Less> void sort_items(T *a, T *tmp, size_t n, Less less) {
    const size_t RUN = 16;
    for (size_t i = 0; i < n; i += RUN) {
        size_t e = i + RUN < n ? i + RUN : n;
        for (size_t j = i + 1; j < e; j++) {
            T x = a[j];
            size_t k = j;
            for (; k > i && less(x, a[k - 1]); k--) a[k] = a[k - 1];
            a[k] = x;
        }
    }
    T *src = a, *dst = tmp;
    for (size_t w = RUN; w < n; w *= 2) {
        for (size_t lo = 0; lo < n; lo += 2 * w) {
            size_t mid = n - lo > w ? lo + w : n, hi = n - lo > 2 * w ? lo + 2 * w : n, i = lo, j = mid, k = lo;
            while (i < mid && j < hi) dst[k++] = less(src[j], src[i]) ? src[j++] : src[i++];
            while (i < mid) dst[k++] = src[i++];
            while (j < hi) dst[k++] = src[j++];
        }
        T *t = src;
        src = dst;
        dst = t;
    }
    for (size_t i = 0; src != a && i < n; i++) a[i] = src[i];
}

// =============================================================================================
// [SECTION] 4 Vector math and the `.` transformations
// =============================================================================================
pray_vec vmake(double x, double y, double z) {
    pray_vec v;
    v.x = x;
    v.y = y;
    v.z = z;
    return v;
}
pray_vec vadd(pray_vec a, pray_vec b) { return vmake(a.x + b.x, a.y + b.y, a.z + b.z); }
pray_vec vsub(pray_vec a, pray_vec b) { return vmake(a.x - b.x, a.y - b.y, a.z - b.z); }
pray_vec vmul(pray_vec a, double s) { return vmake(a.x * s, a.y * s, a.z * s); }
double vdot(pray_vec a, pray_vec b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
pray_vec vcross(pray_vec a, pray_vec b) {
    return vmake(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
// Length and direction, scaled first so that neither overflows nor underflows in between.
double vmaxabs(pray_vec a) {
    double m = fabs(a.x);
    if (fabs(a.y) > m) m = fabs(a.y);
    if (fabs(a.z) > m) m = fabs(a.z);
    return m;
}
double vlen(pray_vec a) {
    double m = vmaxabs(a);
    if (!(m > 0) || m - m != 0) return m;  // zero, or not finite
    pray_vec b = {a.x / m, a.y / m, a.z / m};
    return m * sqrt(b.x * b.x + b.y * b.y + b.z * b.z);
}
// The unit vector along a; the zero vector when a is zero or not finite.
pray_vec vunit(pray_vec a) {
    double m = vmaxabs(a);
    pray_vec z = {0, 0, 0};
    if (!(m > 0) || m - m != 0) return z;
    pray_vec b = {a.x / m, a.y / m, a.z / m};
    double l = sqrt(b.x * b.x + b.y * b.y + b.z * b.z);
    pray_vec u = {b.x / l, b.y / l, b.z / l};
    return u;
}
bool vfinite(pray_vec a) {
    return a.x - a.x == 0 && a.y - a.y == 0 && a.z - a.z == 0;  // false for NaN and infinity
}
bool finite_num(double x) { return x - x == 0; }
// The lengths a texture map's vectors (and a text's axes) may have: their squared lengths stay
// normal finite numbers in the renderer's precision, which texture coordinates divide by.
const double MAP_LEN_MIN = sizeof(real) < sizeof(double) ? 1e-18 : 1e-150;
const double MAP_LEN_MAX = 1 / MAP_LEN_MIN;
bool map_len_ok(pray_vec a) {
    double m = vmaxabs(a);
    return m >= MAP_LEN_MIN && m <= MAP_LEN_MAX;
}
// NaN without its sign, so that messages say "nan" on every C library.
double nan_clean(double x) { return x != x ? fabs(x) : x; }

pray_rgb cmake(double r, double g, double b) {
    pray_rgb c;
    c.r = r;
    c.g = g;
    c.b = b;
    return c;
}
pray_rgb cadd(pray_rgb a, pray_rgb b) { return cmake(a.r + b.r, a.g + b.g, a.b + b.b); }
pray_rgb cmul(pray_rgb a, pray_rgb b) { return cmake(a.r * b.r, a.g * b.g, a.b * b.b); }
pray_rgb cscale(pray_rgb a, double s) { return cmake(a.r * s, a.g * s, a.b * s); }
bool cfinite(pray_rgb a) { return finite_num(a.r) && finite_num(a.g) && finite_num(a.b); }
bool czero(pray_rgb a) { return a.r == 0 && a.g == 0 && a.b == 0; }
bool same_rgb(pray_rgb a, pray_rgb b) { return a.r == b.r && a.g == b.g && a.b == b.b; }
// No channel differs by more than th.
bool rgb_near(pray_rgb a, pray_rgb b, double th) {
    return fabs(a.r - b.r) <= th && fabs(a.g - b.g) <= th && fabs(a.b - b.b) <= th;
}

double cbrt_pos(double x) { return x > 0 ? pow(x, 1.0 / 3.0) : 0; }

// Sine and cosine of an angle in degrees, exact at whole multiples of 90 degrees.
void sincos_deg(double deg, double *s, double *c) {
    double r = fmod(deg, 360.0);
    if (r < 0) r += 360.0;
    if (r == 0) {
        *s = 0;
        *c = 1;
    } else if (r == 90) {
        *s = 1;
        *c = 0;
    } else if (r == 180) {
        *s = 0;
        *c = -1;
    } else if (r == 270) {
        *s = -1;
        *c = 0;
    } else {
        double a = r * (3.14159265358979323846 / 180.0);
        *s = sin(a);
        *c = cos(a);
    }
}

// An affine map x -> m x + t: m is a multiple of a rotation for the maps `.` makes; `stretch`
// and the frames of primitives (pray_object::fr) make general ones.
struct Xform {
    double m[3][3];
    pray_vec t;
};

Xform xf_identity() {
    Xform f;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) f.m[i][j] = i == j ? 1.0 : 0.0;
    f.t = vmake(0, 0, 0);
    return f;
}
Xform xf_scale(double s) {
    Xform f = xf_identity();
    for (int i = 0; i < 3; i++) f.m[i][i] = s;
    return f;
}
Xform xf_translate(pray_vec v) {
    Xform f = xf_identity();
    f.t = v;
    return f;
}
// Rotation by ax about X, then ay about Y, then az about Z (right-handed, degrees).
Xform xf_rotate(pray_vec deg) {
    double sx, cx, sy, cy, sz, cz;
    sincos_deg(deg.x, &sx, &cx);
    sincos_deg(deg.y, &sy, &cy);
    sincos_deg(deg.z, &sz, &cz);
    // Rz * Ry * Rx, multiplied out; products of exact 0/±1 stay exact.
    Xform f = xf_identity();
    f.m[0][0] = cz * cy;
    f.m[0][1] = cz * sy * sx - sz * cx;
    f.m[0][2] = cz * sy * cx + sz * sx;
    f.m[1][0] = sz * cy;
    f.m[1][1] = sz * sy * sx + cz * cx;
    f.m[1][2] = sz * sy * cx - cz * sx;
    f.m[2][0] = -sy;
    f.m[2][1] = cy * sx;
    f.m[2][2] = cy * cx;
    return f;
}
pray_vec xf_dir(const Xform &f, pray_vec v) {
    return vmake(f.m[0][0] * v.x + f.m[0][1] * v.y + f.m[0][2] * v.z,
                 f.m[1][0] * v.x + f.m[1][1] * v.y + f.m[1][2] * v.z,
                 f.m[2][0] * v.x + f.m[2][1] * v.y + f.m[2][2] * v.z);
}
pray_vec xf_point(const Xform &f, pray_vec p) { return vadd(xf_dir(f, p), f.t); }
// The scale factor of the map (m = s R with R a rotation; s may be negative).
double xf_scale_of(const Xform &f) {
    double d = f.m[0][0] * (f.m[1][1] * f.m[2][2] - f.m[1][2] * f.m[2][1]) -
               f.m[0][1] * (f.m[1][0] * f.m[2][2] - f.m[1][2] * f.m[2][0]) +
               f.m[0][2] * (f.m[1][0] * f.m[2][1] - f.m[1][1] * f.m[2][0]);
    double s = sqrt(f.m[0][0] * f.m[0][0] + f.m[1][0] * f.m[1][0] + f.m[2][0] * f.m[2][0]);
    return d < 0 ? -s : s;
}
// f after g: x -> f(g(x)).
Xform xf_compose(const Xform &f, const Xform &g) {
    Xform h;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) h.m[i][j] = f.m[i][0] * g.m[0][j] + f.m[i][1] * g.m[1][j] + f.m[i][2] * g.m[2][j];
    h.t = xf_point(f, g.t);
    return h;
}
Xform xf_stretch(pray_vec v) {
    Xform f = xf_identity();
    f.m[0][0] = v.x;
    f.m[1][1] = v.y;
    f.m[2][2] = v.z;
    return f;
}
// The inverse of f's linear part (its translation left zero); false when it has none in the
// range of numbers.
bool xf_inverse(const Xform &f, Xform *g) {
    const double(*m)[3] = f.m;
    double c[3][3];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {  // cofactor of m[j][i]: the adjugate, transposed as it goes
            int j1 = (j + 1) % 3, j2 = (j + 2) % 3, i1 = (i + 1) % 3, i2 = (i + 2) % 3;
            c[i][j] = m[j1][i1] * m[j2][i2] - m[j1][i2] * m[j2][i1];
        }
    double det = m[0][0] * c[0][0] + m[0][1] * c[1][0] + m[0][2] * c[2][0];
    *g = xf_identity();
    bool ok = det != 0 && finite_num(det);
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            g->m[i][j] = ok ? c[i][j] / det : 0;
            ok = ok && finite_num(g->m[i][j]);
        }
    return ok;
}
// Normals transform with the inverse transpose; for s R that is R / s, which points the same way
// as s R n: a reflection (s < 0) turns a half-space's outward normal along with the space.
pray_vec xf_normal(const Xform &f, pray_vec n) { return xf_dir(f, n); }

} // namespace

// =============================================================================================
// [SECTION] 5 Scene values: models, lights, solids (reference counted handles)
// =============================================================================================
namespace {
enum HandleKind { H_OBJECT = 1, H_MODEL, H_LIGHT, H_KIDS, H_STRING, H_TEXTURE };
// Models: plain coefficients, or a tree of textured parts evaluated where a ray hits.
enum ModelKind { M_FLAT, M_TEX, M_BUMP, M_MOVE, M_SUM, M_SCALE, M_CHECK };
// Texture coordinates of a primitive: none, a plane's, a sphere's.
enum MapKind { MAP_NONE, MAP_PLANE, MAP_SPHERE };
const int MAX_MODEL_DEPTH = 256;
// The parts a model is evaluated through, each use of a shared part counted: what shading one
// point costs at most (`M = M + M` forty times would otherwise be 2^40 parts).
const int MAX_MODEL_PARTS = 4096;
// Every handle begins with this; HANDLE_MAGIC tells a live handle from other memory (pray_release).
const unsigned HANDLE_MAGIC = 0x70726179u;  // "pray"
struct Handle {
    int refs;
    int kind;
    unsigned magic;
};
enum ObjKind {
    O_SPHERE, O_PLANE, O_CYLINDER, O_BOX, O_ROD, O_CONE, O_TORUS,  // primitives
    O_ONE, O_NOTHING, O_UNION, O_INTER, O_DIFF, O_COMPL
};
inline bool is_prim(int kind) { return kind <= O_TORUS; }
// Texture coordinates of a primitive (planemap, spheremap): its U and V vectors. Kept apart, as
// few primitives have them.
struct MapInfo {
    int kind;      // MapKind
    int mirrored;  // a spheremap reflected by a negative scale: longitudes run the other way
    pray_vec u, v;
};
struct LightSrc {
    int point;  // 1: point light at v; 0: directional light travelling along v
    pray_rgb intensity;
    pray_vec v;
    int spot;     // a point light that shines along d: fully within a1 degrees of it, not beyond a2
    pray_vec d;
    double a1, a2;
};
struct Kids;
} // namespace

struct pray_model {
    Handle h;
    pray_rgb diffuse, specular, ambient, emit, reflect, transmit;
    double exponent, index;
    int has_exponent, has_index;
    // M_TEX: a (where the texture is 0) and b (where it is 1) blended by tex; M_BUMP: a with its
    // normal tilted by amount x the texture's luminance gradient; M_MOVE: a with its texture
    // coordinates shifted by (dx, dy); M_SUM: a + b; M_SCALE: a x factor; M_CHECK: a where the
    // cells of side `amount` of the primitive's pattern coordinates have an even sum, else b.
    int kind, depth;
    pray_model *a, *b;
    struct pray_texture *tex;
    double amount, dx, dy;
    pray_rgb factor;
    // Not M_FLAT: the most any component of its transmit weight can be, in magnitude; the
    // parts it is evaluated through (MAX_MODEL_PARTS); the most its texture coordinates are
    // shifted along any path of moves; no mirror and no transparency anywhere (model_lit_only);
    // the pyramids of its textures are built (model_pyramids).
    double clear, parts, shift;
    int lit_only, pyramids, checks;  // checks: an M_CHECK anywhere
    double most[3];  // not M_FLAT: model_most
};

// A decoded texture image: RGB floats, rows from the first row of the file.
struct pray_texture {
    Handle h;
    int w, hgt;
    float *rgb;
    float *mm;  // undersampling: the smallest and largest values of blocks of texels (tex_pyramid)
    char *name;
    pray_texture *next;  // the context's cache of loaded files
};

struct pray_light {
    Handle h;
    int n;
    LightSrc *src;
};

// A solid. Primitives use p, v, r (a cone also r2: the radius at v; a torus r2: the tube's
// radius), in the frame fr when they have one; nodes use kids->k[k0 .. k0+nkids). Chains of one operation
// share one Kids array that grows at either end, so `All = All | s` and `All = s | All` in a loop
// cost O(1) per step and build one node.
struct pray_object {
    Handle h;
    int kind;
    pray_model *mat;
    pray_vec p, v;
    double r, r2;
    MapInfo *map;    // texture coordinates, or NULL
    // The primitive's own frame: p, v, r and map are in local coordinates, which fr maps to the
    // world. NULL: they are in the world. box, rod, cone and torus always have one; a sphere or a
    // cylinder gets one when stretched. (A half-space is stretched exactly without one.)
    Xform *fr;
    // A primitive whose model has a checker: the map from its pattern's coordinates (the world's
    // when it was made or painted) to the world. NULL: the world's (not moved since).
    Xform *pat;
    Kids *kids;
    int nkids, k0;
    long nprims;
    int depth;
    int uid;  // the host's id (pray_object_set_id), or PRAY_NO_ID
};

namespace {
struct Kids {
    Handle h;
    int lo, used, cap;  // k[lo .. used) hold children, of one node or of several sharing the array
    pray_object **k;
};
inline pray_object *kid(const pray_object *o, int i) { return o->kids->k[o->k0 + i]; }

void *handle_new(pray_ctx *c, size_t size, int kind) {
    Handle *h = (Handle *)mem_zalloc(c, size);
    if (!h) return NULL;
    h->refs = 1;
    h->kind = kind;
    h->magic = HANDLE_MAGIC;
    return h;
}
void retain(void *p) {
    if (p) ((Handle *)p)->refs++;
}

void release_handle(pray_ctx *c, void *p) {
    if (!p) return;
    Handle *h = (Handle *)p;
    if (--h->refs > 0) return;
    switch (h->kind) {
    case H_OBJECT: {
        pray_object *o = (pray_object *)p;
        release_handle(c, o->mat);
        release_handle(c, o->kids);
        mem_free(c, o->map);
        mem_free(c, o->fr);
        mem_free(c, o->pat);
        break;
    }
    case H_KIDS: {
        Kids *k = (Kids *)p;
        for (int i = k->lo; i < k->used; i++) release_handle(c, k->k[i]);
        mem_free(c, k->k);
        break;
    }
    case H_LIGHT: mem_free(c, ((pray_light *)p)->src); break;
    case H_MODEL: {
        pray_model *m = (pray_model *)p;
        release_handle(c, m->a);
        release_handle(c, m->b);
        release_handle(c, m->tex);
        break;
    }
    case H_TEXTURE: {
        pray_texture *t = (pray_texture *)p;
        mem_free(c, t->rgb);
        mem_free(c, t->mm);
        mem_free(c, t->name);
        break;
    }
    default: break;
    }
    h->magic = 0;
    mem_free(c, p);
}

pray_model *model_new(pray_ctx *c) {
    pray_model *m = (pray_model *)handle_new(c, sizeof(pray_model), H_MODEL);
    if (m) m->depth = 1;
    return m;
}

pray_light *light_new(pray_ctx *c, int n) {
    pray_light *l = (pray_light *)handle_new(c, sizeof(pray_light), H_LIGHT);
    if (!l) return NULL;
    if (n > 0) {
        l->src = (LightSrc *)mem_zalloc(c, sizeof(LightSrc) * (size_t)n);
        if (!l->src) {
            mem_free(c, l);
            return NULL;
        }
    }
    l->n = n;
    return l;
}

pray_object *obj_new(pray_ctx *c, int kind, pray_model *m) {
    pray_object *o = (pray_object *)handle_new(c, sizeof(pray_object), H_OBJECT);
    if (!o) return NULL;
    o->kind = kind;
    o->mat = m;
    retain(m);
    o->nprims = is_prim(kind) ? 1 : 0;
    o->depth = 1;
    o->uid = PRAY_NO_ID;
    return o;
}

// The pattern of primitive a, moved by f, for its copy o (a checker moves with its primitive);
// false when out of memory.
bool pat_carry(pray_ctx *c, pray_object *o, const pray_object *a, const Xform &f) {
    if (!a->mat || !a->mat->checks) return true;
    o->pat = (Xform *)mem_alloc(c, sizeof(Xform));
    if (o->pat) *o->pat = a->pat ? xf_compose(f, *a->pat) : f;
    return o->pat != NULL;
}

// Give primitive o texture coordinates; false when out of memory.
bool obj_map(pray_ctx *c, pray_object *o, int kind, pray_vec u, pray_vec v, int mirrored) {
    MapInfo *m = (MapInfo *)mem_alloc(c, sizeof(MapInfo));
    if (!m) return false;
    m->kind = kind;
    m->mirrored = mirrored;
    m->u = u;
    m->v = v;
    o->map = m;
    return true;
}

Kids *kids_new(pray_ctx *c, int cap) {
    Kids *k = (Kids *)handle_new(c, sizeof(Kids), H_KIDS);
    if (!k) return NULL;
    k->k = (pray_object **)mem_alloc(c, sizeof(pray_object *) * (size_t)cap);
    if (!k->k) {
        mem_free(c, k);
        return NULL;
    }
    k->cap = cap;
    return k;
}

bool is_node(int kind) { return kind >= O_UNION; }

// The n-ary node `op` over the parts of a and b: a's children when a is already an `op` chain
// (for difference only the left side chains), else a itself; likewise b for union and
// intersection.
pray_object *csg_make(pray_ctx *c, int op, pray_object *a, pray_object *b) {
    bool sa = a->kind == op && a->uid == PRAY_NO_ID;  // (a chain with an id stays a part: its id is its parts')
    bool sb = b->kind == op && op != O_DIFF && b->uid == PRAY_NO_ID;
    int na = sa ? a->nkids : 1, nb = sb ? b->nkids : 1;
    int depth = (sa ? a->depth : a->depth + 1);
    int db = sb ? b->depth : b->depth + 1;
    if (db > depth) depth = db;
    if (depth > MAX_TREE_DEPTH) {
        fail(c, PRAY_ERR_LIMIT, "object nested deeper than %d levels", MAX_TREE_DEPTH);
        return NULL;
    }
    if (na > INT_MAX / 4 - nb) {
        fail_nomem(c);
        return NULL;
    }
    // a tree may use one part many times over; what it stands for must stay renderable
    double lim = c->cur.opt.v[OPT_MAXPRIMS];
    if ((double)a->nprims + (double)b->nprims > lim) {
        fail(c, PRAY_ERR_LIMIT, "object of more than %.0f primitive%s (option maxprims)", lim, lim == 1 ? "" : "s");
        return NULL;
    }
    pray_object *o = obj_new(c, op, NULL);
    if (!o) return NULL;
    // The array holds one reference to each child in it, whichever objects share it.
    Kids *k;
    int k0;
    if (sa && a->k0 + a->nkids == a->kids->used && a->kids->cap - a->kids->used >= nb) {
        k = a->kids;  // append in place: a still sees only its own children
        k0 = a->k0;
        retain(k);
        for (int i = 0; i < nb; i++) {
            pray_object *x = sb ? kid(b, i) : b;
            k->k[k->used++] = x;
            retain(x);
        }
    } else if (sb && b->k0 == b->kids->lo && b->kids->lo >= na) {
        k = b->kids;  // prepend in place: likewise b
        k0 = b->k0 - na;
        retain(k);
        for (int i = 0; i < na; i++) {
            pray_object *x = sa ? kid(a, i) : a;
            k->k[k0 + i] = x;
            retain(x);
        }
        k->lo = k0;
    } else {  // a new array, with its room at the end that grew (the back when neither did)
        int cap = 2 * (na + nb);
        if (cap < 4) cap = 4;
        k = kids_new(c, cap);
        if (!k) {
            mem_free(c, o);
            return NULL;
        }
        k0 = sb && !sa ? cap - (na + nb) : 0;
        for (int i = 0; i < na + nb; i++) {
            pray_object *x = i < na ? (sa ? kid(a, i) : a) : (sb ? kid(b, i - na) : b);
            k->k[k0 + i] = x;
            retain(x);
        }
        k->lo = k0;
        k->used = k0 + na + nb;
    }
    o->kids = k;
    o->k0 = k0;
    o->nkids = na + nb;
    o->nprims = a->nprims + b->nprims;
    o->depth = depth;
    return o;
}

pray_object *csg_op(pray_ctx *c, int op, pray_object *a, pray_object *b) {
    // Neutral elements: nothing for union (and subtracted nothing), one for intersection.
    if (op == O_UNION && a->kind == O_NOTHING) return retain(b), b;
    if ((op == O_UNION || op == O_DIFF) && b->kind == O_NOTHING) return retain(a), a;
    if (op == O_INTER && a->kind == O_ONE) return retain(b), b;
    if (op == O_INTER && b->kind == O_ONE) return retain(a), a;
    return csg_make(c, op, a, b);
}

pray_object *complement_of(pray_ctx *c, pray_object *a) {
    if (a->kind == O_COMPL) {
        retain(kid(a, 0));
        return kid(a, 0);
    }
    if (a->kind == O_NOTHING) return obj_new(c, O_ONE, NULL);
    if (a->kind == O_ONE) return obj_new(c, O_NOTHING, NULL);
    if (a->depth + 1 > MAX_TREE_DEPTH) {
        fail(c, PRAY_ERR_LIMIT, "object nested deeper than %d levels", MAX_TREE_DEPTH);
        return NULL;
    }
    pray_object *o = obj_new(c, O_COMPL, NULL);
    if (!o) return NULL;
    o->kids = kids_new(c, 1);
    if (!o->kids) {
        mem_free(c, o);
        return NULL;
    }
    o->kids->k[0] = a;
    o->kids->used = 1;
    retain(a);
    o->nkids = 1;
    o->nprims = a->nprims;
    o->depth = a->depth + 1;
    return o;
}

// Whether a frame maps into the range of numbers and back (render precision included).
bool frame_ok(const Xform &f) {
    Xform g;
    if (!vfinite(f.t) || !xf_inverse(f, &g)) return false;
    double big = sizeof(real) < sizeof(double) ? 1e30 : 1e300;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            if (!(fabs(f.m[i][j]) < big && fabs(g.m[i][j]) < big)) return false;
    return vmaxabs(f.t) < big;
}

// A copy of primitive a (which has a frame, or is given one) with f applied to its frame: its
// local parameters and texture coordinates stay as they are.
// Primitive a (or `one`, `nothing`) copied in model m: shape, texture coordinates; no frame, no pattern.
pray_object *prim_copy(pray_ctx *c, const pray_object *a, pray_model *m) {
    pray_object *o = obj_new(c, a->kind, m);
    if (!o) return NULL;
    o->p = a->p;
    o->v = a->v;
    o->r = a->r;
    o->r2 = a->r2;
    if (a->map && !obj_map(c, o, a->map->kind, a->map->u, a->map->v, a->map->mirrored)) {
        release_handle(c, o);
        return NULL;
    }
    return o;
}

pray_object *obj_reframe(pray_ctx *c, const pray_object *a, const Xform &f, const char *what) {
    pray_object *o = prim_copy(c, a, a->mat);
    if (!o) return NULL;
    o->fr = (Xform *)mem_alloc(c, sizeof(Xform));
    if (!o->fr || !pat_carry(c, o, a, f)) {
        release_handle(c, o);
        return NULL;
    }
    *o->fr = a->fr ? xf_compose(f, *a->fr) : f;
    if (!frame_ok(*o->fr)) {
        release_handle(c, o);
        fail(c, PRAY_ERR_ARG, "%s takes a primitive out of the range of numbers", what);
        return NULL;
    }
    return o;
}

// Node o of a copy of tree a: its children made by fn(c, child, arg); o, or NULL (o freed).
pray_object *copy_kids(pray_ctx *c, pray_object *o, const pray_object *a,
                       pray_object *(*fn)(pray_ctx *, pray_object *, const void *), const void *arg) {
    o->kids = kids_new(c, a->nkids);
    for (int i = 0; o->kids && i < a->nkids; i++) {
        pray_object *k = fn(c, kid(a, i), arg);
        if (!k) break;
        o->kids->k[o->kids->used++] = k;
    }
    if (!o->kids || o->kids->used < a->nkids) {
        release_handle(c, o);
        return NULL;
    }
    o->nkids = a->nkids;
    o->nprims = a->nprims;
    o->depth = a->depth;
    return o;
}

pray_object *obj_transform(pray_ctx *c, pray_object *a, const Xform &f);
pray_object *obj_stretch(pray_ctx *c, pray_object *a, pray_vec v);
pray_object *transform_kid(pray_ctx *c, pray_object *a, const void *f) { return obj_transform(c, a, *(const Xform *)f); }
pray_object *stretch_kid(pray_ctx *c, pray_object *a, const void *v) { return obj_stretch(c, a, *(const pray_vec *)v); }

// A copy of the tree with the map applied to every primitive.
pray_object *obj_transform(pray_ctx *c, pray_object *a, const Xform &f) {
    if (a->fr) return obj_reframe(c, a, f, "the transformation");
    pray_object *o = obj_new(c, a->kind, a->mat);
    if (!o) return NULL;
    double s = fabs(xf_scale_of(f));
    switch (a->kind) {
    case O_SPHERE:
        o->p = xf_point(f, a->p);
        o->r = a->r * s;
        break;
    case O_PLANE:  // directions are turned, not scaled, so that their lengths stay in range
        o->p = xf_point(f, a->p);
        o->v = vmul(xf_normal(f, a->v), 1.0 / s);
        break;
    default: break;
    }
    bool map_ok = true;
    if (!pat_carry(c, o, a, f)) {
        release_handle(c, o);
        return NULL;
    }
    if (a->map) {  // texture coordinates go with the solid, scale included
        if (!obj_map(c, o, a->map->kind, xf_dir(f, a->map->u), xf_dir(f, a->map->v),
                     a->map->mirrored ^ (xf_scale_of(f) < 0))) {
            release_handle(c, o);
            return NULL;
        }
        map_ok = map_len_ok(o->map->u) && map_len_ok(o->map->v);
    }
    switch (a->kind) {
    case O_CYLINDER:
        o->p = xf_point(f, a->p);
        o->v = vmul(xf_dir(f, a->v), 1.0 / s);
        o->r = a->r * s;
        break;
    default: break;
    }
    if (is_prim(a->kind) &&
        (!map_ok || !vfinite(o->p) || !vfinite(o->v) || !finite_num(o->r) || (a->kind != O_PLANE && !(o->r > 0)) ||
         (a->kind != O_SPHERE && vlen(o->v) == 0))) {
        release_handle(c, o);
        fail(c, PRAY_ERR_ARG, "the transformation takes a primitive out of the range of numbers");
        return NULL;
    }
    return is_node(a->kind) ? copy_kids(c, o, a, transform_kid, &f) : o;
}

// A copy of the tree scaled by the components of v along the world axes (none of them 0).
// Half-spaces stay half-spaces: their normals turn by the inverse of the map, and a planemap's
// vectors so that each point keeps its texture coordinates. Other primitives take the map into
// their frames.
pray_object *obj_stretch(pray_ctx *c, pray_object *a, pray_vec v) {
    if (is_prim(a->kind) && a->kind != O_PLANE) return obj_reframe(c, a, xf_stretch(v), "stretch");
    if (!is_node(a->kind) && a->kind != O_PLANE) return obj_new(c, a->kind, a->mat);  // one, nothing
    pray_object *o = obj_new(c, a->kind, a->mat);
    if (!o) return NULL;
    if (a->kind == O_PLANE) {
        o->p = vmake(a->p.x * v.x, a->p.y * v.y, a->p.z * v.z);
        o->v = vunit(vmake(a->v.x / v.x, a->v.y / v.y, a->v.z / v.z));
        if (!pat_carry(c, o, a, xf_stretch(v))) {
            release_handle(c, o);
            return NULL;
        }
        bool ok = vfinite(o->p) && vlen(o->v) > 0;
        if (ok && a->map) {
            // s = (x - p).u / |u|^2 for x = S y: u' = w |u|^2 / |w|^2 with w = S^-1 u
            pray_vec uv[2] = {a->map->u, a->map->v};
            for (int i = 0; i < 2; i++) {
                pray_vec w = vmake(uv[i].x / v.x, uv[i].y / v.y, uv[i].z / v.z);
                double lu = vlen(uv[i]), lw = vlen(w);
                uv[i] = vmul(w, (lu / lw) * (lu / lw));
            }
            if (!obj_map(c, o, MAP_PLANE, uv[0], uv[1], 0)) {
                release_handle(c, o);
                return NULL;
            }
            ok = map_len_ok(uv[0]) && map_len_ok(uv[1]) && vfinite(uv[0]) && vfinite(uv[1]);
        }
        if (!ok) {
            release_handle(c, o);
            fail(c, PRAY_ERR_ARG, "stretch takes a primitive out of the range of numbers");
            return NULL;
        }
        return o;
    }
    return copy_kids(c, o, a, stretch_kid, &v);
}

// A copy of the tree with model m on every primitive (and `one`): shapes, frames and texture
// coordinates stay; a checker in m takes the world's coordinates as they are now.
pray_object *paint_kid(pray_ctx *c, pray_object *a, const void *m);
pray_object *obj_paint(pray_ctx *c, pray_object *a, pray_model *m) {
    if (is_node(a->kind)) {
        pray_object *o = obj_new(c, a->kind, NULL);
        return o ? copy_kids(c, o, a, paint_kid, m) : NULL;
    }
    pray_object *o = prim_copy(c, a, a->kind == O_NOTHING ? NULL : m);
    if (o && a->fr && !(o->fr = (Xform *)mem_alloc(c, sizeof(Xform)))) {
        release_handle(c, o);
        return NULL;
    }
    if (o && a->fr) *o->fr = *a->fr;
    return o;
}
pray_object *paint_kid(pray_ctx *c, pray_object *a, const void *m) { return obj_paint(c, a, (pray_model *)m); }

pray_light *light_transform(pray_ctx *c, const pray_light *a, const Xform &f) {
    pray_light *l = light_new(c, a->n);
    if (!l) return NULL;
    for (int i = 0; i < a->n; i++) {
        l->src[i] = a->src[i];
        l->src[i].v = a->src[i].point ? xf_point(f, a->src[i].v) : xf_dir(f, a->src[i].v);
        l->src[i].d = xf_dir(f, a->src[i].d);
        if (!vfinite(l->src[i].v) || (!l->src[i].point && vmaxabs(l->src[i].v) == 0) ||
            (l->src[i].spot && (!vfinite(l->src[i].d) || vmaxabs(l->src[i].d) == 0))) {
            release_handle(c, l);
            fail(c, PRAY_ERR_ARG, "the transformation takes a light out of the range of numbers");
            return NULL;
        }
    }
    return l;
}

pray_light *light_union(pray_ctx *c, const pray_light *a, const pray_light *b) {
    if (a->n > INT_MAX / 2 - b->n) {
        fail_nomem(c);
        return NULL;
    }
    pray_light *l = light_new(c, a->n + b->n);
    if (!l) return NULL;
    for (int i = 0; i < a->n; i++) l->src[i] = a->src[i];
    for (int i = 0; i < b->n; i++) l->src[a->n + i] = b->src[i];
    return l;
}

inline double rgb_maxabs(pray_rgb v) {
    double r = fabs(v.r), g = fabs(v.g), b = fabs(v.b);
    return r > g ? (r > b ? r : b) : (g > b ? g : b);
}

// The most any component of the model's transmit weight can be anywhere, in magnitude.
double model_clear(const pray_model *m) { return m->kind == M_FLAT ? rgb_maxabs(m->transmit) : m->clear; }

// The most a model's coefficients can be anywhere, in magnitude, in any channel: MOST_OWN the
// light of its own (emit + ambient), MOST_LIT what it makes of a light's (diffuse + specular),
// MOST_PASS what it passes on to the rays it spawns (reflect + transmit). A texture's blend
// weights lie between 0 and 1, so a blend is at most the larger of its two models.
enum { MOST_OWN, MOST_LIT, MOST_PASS };
double model_most(const pray_model *m, int i) {
    if (m->kind != M_FLAT) return m->most[i];
    if (i == MOST_OWN) return rgb_maxabs(m->emit) + rgb_maxabs(m->ambient);
    if (i == MOST_LIT) return rgb_maxabs(m->diffuse) + rgb_maxabs(m->specular);
    return rgb_maxabs(m->reflect) + rgb_maxabs(m->transmit);
}

double model_parts(const pray_model *m) { return m->kind == M_FLAT ? 1 : m->parts; }
double model_shift(const pray_model *m) { return m->kind == M_FLAT ? 0 : m->shift; }

// Whether a model's look at a point follows from the light arriving there and the model's
// coefficients at the point's texture coordinates: no mirror and no transparency (their rays
// would see other parts of the scene). Bump maps are fine: they only turn the normal.
bool model_lit_only(const pray_model *m) {
    if (m->kind == M_FLAT) return czero(m->reflect) && czero(m->transmit);
    return m->lit_only != 0;
}

// A model node of the given kind over a and b (b may be NULL); `shift`: how far an M_MOVE moves.
pray_model *model_node(pray_ctx *c, int kind, pray_model *a, pray_model *b, double shift = 0) {
    int depth = 1 + (a->depth > (b ? b->depth : 0) ? a->depth : b->depth);
    if (depth > MAX_MODEL_DEPTH) {
        fail(c, PRAY_ERR_LIMIT, "model nested deeper than %d levels", MAX_MODEL_DEPTH);
        return NULL;
    }
    double parts = 1 + model_parts(a) + (b ? model_parts(b) : 0);
    if (parts > MAX_MODEL_PARTS) {
        fail(c, PRAY_ERR_LIMIT, "model made of more than %d parts (each use of a shared part counts)", MAX_MODEL_PARTS);
        return NULL;
    }
    double sa = model_shift(a), sb = b ? model_shift(b) : 0;
    shift += sa > sb ? sa : sb;
    if (!finite_num(shift)) {
        fail(c, PRAY_ERR_ARG, "move: the shifts of nested moves add up to more than the range of numbers");
        return NULL;
    }
    pray_model *m = model_new(c);
    if (!m) return NULL;
    m->kind = kind;
    m->depth = depth;
    m->a = a;
    m->b = b;
    retain(a);
    retain(b);
    m->has_exponent = a->has_exponent || (b && b->has_exponent);
    m->has_index = a->has_index || (b && b->has_index);
    // (a texture's blend weights are at most 1; M_SCALE multiplies by its factor's largest)
    m->clear = model_clear(a) + (b ? model_clear(b) : 0);
    m->parts = parts;
    m->shift = shift;
    m->lit_only = model_lit_only(a) && (!b || model_lit_only(b));
    m->checks = kind == M_CHECK || a->checks || (b && b->checks);
    for (int i = 0; i < 3; i++) {
        double ma = model_most(a, i), mb = b ? model_most(b, i) : 0;
        m->most[i] = kind == M_SUM ? ma + mb : ma > mb ? ma : mb;
    }
    return m;
}

// A model made by a sum or a scale whose coefficients (a textured model's: their bounds,
// model_most) left the range of numbers: freed, and the error. Returns m when it is good.
pray_model *model_checked(pray_ctx *c, pray_model *m, const char *what) {
    if (!m) return NULL;
    if (m->kind == M_FLAT ? cfinite(m->diffuse) && cfinite(m->specular) && cfinite(m->ambient) && cfinite(m->emit) &&
                                cfinite(m->reflect) && cfinite(m->transmit)
                          : finite_num(m->most[0]) && finite_num(m->most[1]) && finite_num(m->most[2]) && finite_num(m->clear))
        return m;
    release_handle(c, m);
    fail(c, PRAY_ERR_ARG, "%s: the coefficients are not finite", what);
    return NULL;
}

pray_model *model_sum(pray_ctx *c, pray_model *a, pray_model *b) {
    if (a->kind != M_FLAT || b->kind != M_FLAT) return model_checked(c, model_node(c, M_SUM, a, b), "model sum");
    pray_model *m = model_new(c);
    if (!m) return NULL;
    m->diffuse = cadd(a->diffuse, b->diffuse);
    m->specular = cadd(a->specular, b->specular);
    m->ambient = cadd(a->ambient, b->ambient);
    m->emit = cadd(a->emit, b->emit);
    m->reflect = cadd(a->reflect, b->reflect);
    m->transmit = cadd(a->transmit, b->transmit);
    m->has_exponent = a->has_exponent || b->has_exponent;
    m->exponent = a->has_exponent ? a->exponent : b->exponent;
    m->has_index = a->has_index || b->has_index;
    m->index = a->has_index ? a->index : b->index;
    return model_checked(c, m, "model sum");
}

pray_model *model_times(pray_ctx *c, pray_model *a, pray_rgb f) {
    if (a->kind != M_FLAT) {
        pray_model *m = model_node(c, M_SCALE, a, NULL);
        if (!m) return NULL;
        m->factor = f;
        m->clear *= rgb_maxabs(f);
        for (int i = 0; i < 3; i++) m->most[i] *= rgb_maxabs(f);
        return model_checked(c, m, "model scale");
    }
    pray_model *m = model_new(c);
    if (!m) return NULL;
    *m = *a;
    m->h.refs = 1;
    m->diffuse = cmul(a->diffuse, f);
    m->specular = cmul(a->specular, f);
    m->ambient = cmul(a->ambient, f);
    m->emit = cmul(a->emit, f);
    m->reflect = cmul(a->reflect, f);
    m->transmit = cmul(a->transmit, f);
    return model_checked(c, m, "model scale");
}

// =============================================================================================
// [SECTION] 6 Options
// =============================================================================================
struct OptDef {
    const char *name;
    double def, lo, hi;
    int integer;
    double untrusted;  // the highest value allowed in untrusted mode (0: no ceiling)
};
// Alphabetical, in the order of the OPT_ enumeration. grid -1 means "automatic". The max* options
// and depth, gridmem and texmem are the limits of a run (pray.hpp, "Limits"). brute, grid, nest,
// freeze, merge, bounds, lightbuffer, eyebuffer, shadowcache, plans and coherence are diagnostic
// (pray.hpp, "Options"; --help): they change how fast an image is made, never the image.
const OptDef OPTS[OPT_COUNT] = {
    {"adaptive", 0, 0, 1e9, 0, 0},
    {"antialias", 1, 1, 64, 1, 0},
    {"bits", 8, 8, 16, 1, 0},
    {"bounds", 1, 0, 1, 1, 0},
    {"brute", 0, 0, 1, 1, 0},
    {"coherence", 1, 0, 1, 1, 0},
    {"cutoff", 1, 0, 1, 1, 0},
    {"depth", 5, 1, 64, 1, 16},
    {"eyebuffer", 1, 0, 1, 1, 0},
    {"freeze", 1, 0, 1, 1, 0},
    {"grid", -1, -1, 4096, 1, 0},
    {"gridmem", 64, 1, 65536, 1, 64},
    {"height", 256, 1, MAX_IMAGE_SIDE, 1, 0},
    {"lightbuffer", 1, 0, 1, 1, 0},
    {"maxframes", 0, 0, 1e9, 1, 1000},
    {"maxline", 65536, 1, 1e9, 1, 4096},
    {"maxmem", 0, 0, 1e9, 1, 1024},
    {"maxnest", 256, 1, MAX_NESTING, 1, 64},
    {"maxoutput", 0, 0, 1e9, 1, 1024},
    {"maxpixels", 1073741824.0, 1, 1e15, 1, 16777216.0},
    {"maxprims", MAX_PRIMITIVES, 1, MAX_PRIMITIVES, 1, 1048576},
    {"maxrays", 65536, 1, 1e9, 1, 256},
    {"maxsteps", 1e7, 0, 1e15, 1, 1e6},
    {"maxstring", 65536, 1, 16777216, 1, 4096},
    {"maxtime", 0, 0, 1e9, 1, 600},
    {"merge", 1, 0, 1, 1, 0},
    {"nest", 2, 0, 4, 1, 0},
    {"output", 0, 0, 0, 0, 0},
    {"plans", 1, 0, 1, 1, 0},
    {"shadowcache", 1, 0, 1, 1, 0},
    {"shadows", 1, 0, 1, 1, 0},
    {"texmem", 256, 1, 65536, 1, 64},
    {"threads", 0, 0, 1024, 1, 0},
    {"width", 256, 1, MAX_IMAGE_SIDE, 1, 0},
};

int opt_find(const char *name) {
    for (int i = 0; i < OPT_COUNT; i++)
        if (strcmp(OPTS[i].name, name) == 0) return i;
    return -1;
}

// A name as messages show it: long ones cut after 60 characters.
struct Shown {
    char buf[72];
    explicit Shown(const char *name) {
        size_t n = strlen(name);
        if (n <= 60) snprintf(buf, sizeof buf, "%s", name);
        else snprintf(buf, sizeof buf, "%.60s...", name);
    }
    const char *operator*() const { return buf; }
};

// A file's name as messages show it: a long one keeps its end, after "...", so that a message
// has room for its place and reason.
struct ShownPath {
    char buf[200];
    explicit ShownPath(const char *path) {
        size_t n = strlen(path), keep = sizeof buf - 4;
        if (n < sizeof buf) {
            memcpy(buf, path, n + 1);
            return;
        }
        const char *t = path + n - keep;
        while ((*t & 0xC0) == 0x80) t++;  // not in the middle of a UTF-8 character
        snprintf(buf, sizeof buf, "...%s", t);
    }
    const char *operator*() const { return buf; }
};

int levenshtein(const char *a, const char *b) {
    int la = (int)strlen(a), lb = (int)strlen(b);
    if (la > 64 || lb > 64) return 99;
    int d[65][65];
    for (int i = 0; i <= la; i++) d[i][0] = i;
    for (int j = 0; j <= lb; j++) d[0][j] = j;
    for (int i = 1; i <= la; i++)
        for (int j = 1; j <= lb; j++) {
            int x = d[i - 1][j - 1] + (a[i - 1] != b[j - 1]);
            if (d[i - 1][j] + 1 < x) x = d[i - 1][j] + 1;
            if (d[i][j - 1] + 1 < x) x = d[i][j - 1] + 1;
            d[i][j] = x;
        }
    return d[la][lb];
}

// Keeps the closest of the candidate names offered to it, for "did you mean" hints.
struct Suggest {
    const char *want;
    const char *best;
    int dist;
    void init(const char *w) {
        want = w;
        best = NULL;
        dist = 3;
    }
    void offer(const char *name) {
        int d = levenshtein(want, name);
        int lim = strlen(want) <= 3 ? 1 : 2;
        if (d <= lim && d < dist) {
            dist = d;
            best = name;
        }
    }
};

// Check a value for option i; returns NULL when good, else what is wrong.
const char *opt_check(int i, double v) {
    const OptDef &d = OPTS[i];
    if (!finite_num(v) || v < d.lo || v > d.hi) return "out of range";
    if (d.integer && v != floor(v)) return "not a whole number";
    if (i == OPT_BITS && v != 8 && v != 16) return "not 8 or 16";
    return NULL;
}

void setup_default(Setup *s) {
    memset(s, 0, sizeof *s);
    for (int i = 0; i < OPT_COUNT; i++) s->opt.v[i] = OPTS[i].def;
    s->cam_x = vmake(1, 0, 0);
    s->cam_y = vmake(0, 0, -1);
    s->cam_eye = vmake(0, -4, 0);
}

int opt_int(const pray_ctx *c, int i) { return (int)c->cur.opt.v[i]; }

pray_status opt_unknown(pray_ctx *c, const char *name) {
    Suggest s;
    s.init(name);
    for (int i = 0; i < OPT_COUNT; i++) s.offer(OPTS[i].name);
    if (s.best) return fail(c, PRAY_ERR_ARG, "unknown option '%s'; did you mean '%s'?", *Shown(name), s.best);
    return fail(c, PRAY_ERR_ARG, "unknown option '%s'", *Shown(name));
}

} // namespace

// =============================================================================================
// [SECTION] 7 Prepared scene: flattened n-ary CSG tree, primitives in render precision
// =============================================================================================
namespace {

struct R3 {
    real x, y, z;
};
inline R3 r3(real x, real y, real z) {
    R3 v = {x, y, z};
    return v;
}
typedef real R3::*Axis;  // one of a vector's components
inline R3 r3of(pray_vec v) { return r3((real)v.x, (real)v.y, (real)v.z); }
inline R3 operator+(R3 a, R3 b) { return r3(a.x + b.x, a.y + b.y, a.z + b.z); }
inline R3 operator-(R3 a, R3 b) { return r3(a.x - b.x, a.y - b.y, a.z - b.z); }
inline R3 operator*(R3 a, real s) { return r3(a.x * s, a.y * s, a.z * s); }
inline real dot(R3 a, R3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline real absmax(R3 a) {
    real x = a.x < 0 ? -a.x : a.x, y = a.y < 0 ? -a.y : a.y, z = a.z < 0 ? -a.z : a.z;
    return x > y ? (x > z ? x : z) : (y > z ? y : z);
}
inline R3 cross(R3 a, R3 b) { return r3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x); }
inline R3 unit(R3 a) {
    real l = (real)sqrt((double)dot(a, a));
    return l > 0 ? a * ((real)1 / l) : a;
}

// Element codes of the flattened tree: primitive i is 2i, node j is 2j+1; two constants stand
// for a subtree that folded to all of space or to nothing.
const real REAL_BIG = (real)HUGE_VAL;

// The relative rounding of `real` (one unit in the last place of 1).
const double REAL_EPS = sizeof(real) == sizeof(float) ? FLT_EPSILON : DBL_EPSILON;
// The snapping tolerance: values this many units in the last place apart (of the largest
// magnitude involved) differ by rounding, not by design. Coincident surfaces within it are made
// identical (snap_coincident), and a box is widened by as much to hold its solid after rounding.
const double SNAP_ULPS = 8;
const int E_ALL = -1;
const int E_NONE = -2;
inline bool e_is_node(int e) { return (e & 1) != 0; }
inline int e_index(int e) { return e >> 1; }

// An axis-aligned box; sides may be infinite. Empty when lo > hi on some axis.
struct Box {
    real lo[3], hi[3];
};

// Texture coordinates of a primitive: origin p (the primitive's), U and V vectors. Apart from
// the primitive, as few have them; each in a block of its own, so that a primitive's pointer
// stays valid while the scene's arrays grow.
struct PrimMap {
    R3 u, v;
    int mirrored;  // longitudes of a spheremap run the other way
    R3 pt, pinv[3];  // a model with a checker: the pattern's coordinates of world x, pinv (x - pt)
};

// A primitive's own frame in render precision (local = inv (x - t)), and what the primitive
// has there beyond Prim's parameters. Apart from the primitive, as few have one.
struct PrimFrame {
    R3 t;           // the world point of the local origin
    R3 inv[3];      // rows of the linear map world -> local
    R3 fwd[3];      // rows of the linear map local -> world
    R3 lo, hi;      // a box's corners
    real h, k, rt;  // rod, cone: the axis' length; cone: slope (r2 - r1) / h; torus: tube radius
    int plain;      // the frame is the world's: rays need no mapping
};
// Kinds of prepared primitives beside ObjKind's: a sphere and a cylinder in a frame.
enum { P_ELLIPSOID = O_COMPL + 1, P_ECYLINDER };

struct Prim {
    int kind;           // O_SPHERE, O_PLANE, O_CYLINDER; in a frame (fr): O_BOX, O_ROD, O_CONE,
                        // O_TORUS, P_ELLIPSOID, P_ECYLINDER
    Axis axis;          // a plane whose normal lies along an axis: that component; else none
    Box box;            // contains the solid
    R3 p;               // centre, point on the plane, point on the axis
    R3 n;               // unit outward normal of a plane, unit axis of a cylinder
    real r, r2, d;      // radius, radius squared, plane offset n.p
    const pray_model *mat;
    int map;            // MapKind; with tm: the texture coordinates (NULL for MAP_NONE)
    const PrimMap *tm;
    const PrimFrame *fr;  // framed kinds: p, n, r are local (NULL for the others)
    int id;             // position among the declared primitives, left to right
    int uid;            // the host's id of the innermost object with one around it (PRAY_NO_ID)
    int surf;           // the same number for primitives snapped to exactly one surface (twins)
    int parent;         // node index, -1 for the root
    unsigned char first;  // first child of a difference
    unsigned char settles;  // 1: being outside for good decides the parent, 2: inside (3.5)
    unsigned char owns;     // may fill the solid with its material (owner): no complement, later
                            // child of a difference or earlier one of an intersection above it
};

struct Node {
    int op;      // O_UNION, O_INTER, O_DIFF, O_COMPL
    int n;       // children: Scene::kids[k0 .. k0+n)
    int k0;
    int parent;
    unsigned char first;
    Box box;     // contains the solid (infinite for complements)
};

struct Light {
    int point;
    R3 v;        // position, or unit direction towards the light
    pray_rgb intensity;
    int spot;    // a spotlight: along unit d, full within a1 degrees, nothing beyond a2
    R3 d;
    double a1, a2;
};

struct Accel;

struct Scene {
    Array<Prim> prims;
    Array<PrimMap *> maps;  // the primitives' PrimMap blocks
    Array<PrimFrame *> frames;  // and PrimFrame blocks
    int models_held;        // each primitive holds a reference to its model (scene_hold_models)
    Array<Node> nodes;
    Array<int> kids;  // element codes of the nodes' children
    int root;
    int prune;        // drop parts that bounds show cannot matter
    int leaves;       // primitives met so far while flattening
    int uid;          // the id of the innermost object with one, around what is flattened
    int tori;         // tori among the primitives (each may cross a ray four times)
    int iface;        // two different materials may fill the solid (scene_interfaces)
    Accel *accel;     // NULL: the brute-force reference
    Array<Light> lights;
    int parallel;
    R3 eye, point, cx, cy, dir;
    R3 keye, kpoint, kcx, kcy;  // the perspective camera scaled by a power of two near 1/size
    int width, height, depth, shadows, antialias;
    double adaptive;  // the undersampling threshold (option adaptive)
    pray_rgb bg_top, bg_bottom;
    // The ray tree's cut-off (ray_most): the most a ray with k levels left can bring back, for
    // k = 0 .. depth, and the least a ray must be able to add to its sample to be traced (0:
    // every ray is traced). maxrays: the rays one sample may take.
    double most[65], cut;
    long maxrays;
};

// Does primitive p have the surface of primitive `self` (the one a secondary ray starts on)?
inline bool twin(const Scene *s, int p, int self) {
    return self >= 0 && s->prims[p].surf == s->prims[self].surf;
}

void accel_release(pray_ctx *c, Accel *a);

void scene_release(pray_ctx *c, Scene *s) {
    accel_release(c, s->accel);
    s->accel = NULL;
    s->kids.release(c);
    s->nodes.release(c);
    s->lights.release(c);
    for (int i = 0; i < s->maps.n; i++) mem_free(c, s->maps[i]);
    s->maps.release(c);
    for (int i = 0; i < s->frames.n; i++) mem_free(c, s->frames[i]);
    s->frames.release(c);
    if (s->models_held)
        for (int i = 0; i < s->prims.n; i++) release_handle(c, (pray_model *)s->prims[i].mat);
    s->models_held = 0;
    s->prims.release(c);
}

void set_parent(Scene *s, int e, int parent, bool first) {
    if (e_is_node(e)) {
        s->nodes[e_index(e)].parent = parent;
        s->nodes[e_index(e)].first = first;
    } else {
        s->prims[e_index(e)].parent = parent;
        s->prims[e_index(e)].first = first;
    }
}

// ---- boxes ----
Box box_all() {
    Box b;
    for (int i = 0; i < 3; i++) {
        b.lo[i] = -REAL_BIG;
        b.hi[i] = REAL_BIG;
    }
    return b;
}
bool box_empty(const Box &b) {
    return b.lo[0] > b.hi[0] || b.lo[1] > b.hi[1] || b.lo[2] > b.hi[2];
}
bool box_finite(const Box &b) {
    for (int i = 0; i < 3; i++)
        if (b.lo[i] <= -REAL_BIG || b.hi[i] >= REAL_BIG) return false;
    return true;
}
bool box_overlap(const Box &a, const Box &b) {
    for (int i = 0; i < 3; i++)
        if (a.hi[i] < b.lo[i] || b.hi[i] < a.lo[i]) return false;
    return true;
}
void box_hull(Box *a, const Box &b) {
    for (int i = 0; i < 3; i++) {
        if (b.lo[i] < a->lo[i]) a->lo[i] = b.lo[i];
        if (b.hi[i] > a->hi[i]) a->hi[i] = b.hi[i];
    }
}
void box_clip(Box *a, const Box &b) {
    for (int i = 0; i < 3; i++) {
        if (b.lo[i] > a->lo[i]) a->lo[i] = b.lo[i];
        if (b.hi[i] < a->hi[i]) a->hi[i] = b.hi[i];
    }
}
real comp(R3 v, int i) { return i == 0 ? v.x : i == 1 ? v.y : v.z; }

// A box must contain its solid also after rounding in `real`: widen finite sides by a few units
// in the last place of the largest coordinate involved.
void box_pad(Box *b, double scale) {
    for (int i = 0; i < 3; i++) {
        double lo = b->lo[i] > -REAL_BIG ? fabs((double)b->lo[i]) : 0, hi = b->hi[i] < REAL_BIG ? fabs((double)b->hi[i]) : 0;
        double pad = SNAP_ULPS * REAL_EPS * ((lo > hi ? lo : hi) + scale);  // (of the finite ends)
        if (b->lo[i] > -REAL_BIG) b->lo[i] = (real)((double)b->lo[i] - pad);
        if (b->hi[i] < REAL_BIG) b->hi[i] = (real)((double)b->hi[i] + pad);
    }
}

Box prim_box(const Prim &q) {
    Box b = box_all();
    for (int i = 0; i < 3; i++) {
        real p = comp(q.p, i), n = comp(q.n, i);
        if (q.kind == O_SPHERE) {
            b.lo[i] = p - q.r;
            b.hi[i] = p + q.r;
        } else if (q.kind == O_CYLINDER) {
            if (n == 0) {  // the axis is perpendicular to this coordinate axis
                b.lo[i] = p - q.r;
                b.hi[i] = p + q.r;
            }
        } else {
            // a half-space is bounded on one side only when its normal is a coordinate axis
            int others = (comp(q.n, (i + 1) % 3) == 0) + (comp(q.n, (i + 2) % 3) == 0);
            if (others == 2 && n > 0) b.hi[i] = q.d / n;
            if (others == 2 && n < 0) b.lo[i] = q.d / n;
        }
    }
    box_pad(&b, (double)q.r + fabs((double)q.p.x) + fabs((double)q.p.y) + fabs((double)q.p.z));
    return b;
}

// Shrink box `b` to the box of the convex polyhedron { x : n.x <= d for the planes } within it:
// the planes of an intersection in any orientation (a tilted cube, a prism) get an exact box.
// Vertices are triples of constraints (the planes and the box sides) that meet all the others.
void polyhedron_box(const Scene *s, const int *kids, int n, Box *b) {
    double N[64][3], D[64];
    int m = 0;
    for (int k = 0; k < n && m < 40; k++) {
        if (e_is_node(kids[k]) || s->prims[e_index(kids[k])].kind != O_PLANE) continue;
        const Prim &q = s->prims[e_index(kids[k])];
        N[m][0] = q.n.x;
        N[m][1] = q.n.y;
        N[m][2] = q.n.z;
        D[m++] = q.d;
    }
    if (m < 2 || m >= 40) return;
    // unbounded sides stand in at a distance far beyond everything else in sight (vertices of
    // nearly parallel planes reach |D| / 1e-12); a scene too large for that keeps its plain box
    double big = 0;
    for (int i = 0; i < m; i++)
        if (fabs(D[i]) > big) big = fabs(D[i]);
    for (int i = 0; i < 3; i++) {
        if (b->hi[i] < REAL_BIG && fabs((double)b->hi[i]) > big) big = fabs((double)b->hi[i]);
        if (b->lo[i] > -REAL_BIG && fabs((double)b->lo[i]) > big) big = fabs((double)b->lo[i]);
    }
    if (big > 1e250) return;
    const double BIG = big * 1e16 > 1e30 ? big * 1e16 : 1e30;
    for (int i = 0; i < 3; i++) {  // the box sides, infinite ones at a huge distance
        N[m][0] = N[m][1] = N[m][2] = 0;
        N[m][i] = 1;
        D[m++] = b->hi[i] >= REAL_BIG ? BIG : (double)b->hi[i];
        N[m][0] = N[m][1] = N[m][2] = 0;
        N[m][i] = -1;
        D[m++] = b->lo[i] <= -REAL_BIG ? BIG : -(double)b->lo[i];
    }
    double lo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
    int found = 0;
    for (int i = 0; i < m; i++)
        for (int j = i + 1; j < m; j++)
            for (int k = j + 1; k < m; k++) {
                const double *a = N[i], *bb = N[j], *cc = N[k];
                double c0 = bb[1] * cc[2] - bb[2] * cc[1], c1 = bb[2] * cc[0] - bb[0] * cc[2],
                       c2 = bb[0] * cc[1] - bb[1] * cc[0];
                double det = a[0] * c0 + a[1] * c1 + a[2] * c2;
                if (fabs(det) < 1e-12) continue;
                // Cramer's rule
                double x[3];
                double r0 = D[i], r1 = D[j], r2 = D[k];
                x[0] = (r0 * c0 + r1 * (cc[1] * a[2] - cc[2] * a[1]) + r2 * (a[1] * bb[2] - a[2] * bb[1])) / det;
                x[1] = (r0 * c1 + r1 * (cc[2] * a[0] - cc[0] * a[2]) + r2 * (a[2] * bb[0] - a[0] * bb[2])) / det;
                x[2] = (r0 * c2 + r1 * (cc[0] * a[1] - cc[1] * a[0]) + r2 * (a[0] * bb[1] - a[1] * bb[0])) / det;
                bool ok = true;
                for (int l = 0; l < m && ok; l++) {
                    double v = N[l][0] * x[0] + N[l][1] * x[1] + N[l][2] * x[2] - D[l];
                    ok = v <= 1e-9 * (fabs(D[l]) + fabs(x[0]) + fabs(x[1]) + fabs(x[2]) + 1);
                }
                if (!ok) continue;
                found = 1;
                for (int l = 0; l < 3; l++) {
                    if (x[l] < lo[l]) lo[l] = x[l];
                    if (x[l] > hi[l]) hi[l] = x[l];
                }
            }
    if (!found) return;  // numerically empty: keep the plain box, never fold on this evidence
    const double rel = sizeof(real) == sizeof(float) ? 64 * REAL_EPS : 1e-9;
    for (int l = 0; l < 3; l++) {
        double pad = rel * (fabs(lo[l]) + fabs(hi[l]) + 1);
        // (a float build keeps a side that float cannot hold)
        double top = sizeof(real) == sizeof(float) ? FLT_MAX : DBL_MAX;
        if (lo[l] > -BIG / 2 && lo[l] - pad > (double)b->lo[l] && lo[l] - pad > -top) b->lo[l] = (real)(lo[l] - pad);
        if (hi[l] < BIG / 2 && hi[l] + pad < (double)b->hi[l] && hi[l] + pad < top) b->hi[l] = (real)(hi[l] + pad);
    }
}

// An intersection of a cylinder with half-spaces that cut its axis on both sides (a rod, a
// capped tube in any direction) lies in the piece of the cylinder between the farthest points
// of the axis that the cylinder's sections in those planes reach: shrink box `b` to that piece's
// box. (A half-space cuts the axis at t = (d - n.p) / (n.a); its section reaches r |n x a| / |n.a|
// further along the axis; planes within about 6 degrees of the axis are left out.)
void capped_cylinder_box(const Scene *s, const int *kids, int n, Box *b) {
    for (int k = 0; k < n; k++) {
        if (e_is_node(kids[k]) || s->prims[e_index(kids[k])].kind != O_CYLINDER) continue;
        const Prim &cy = s->prims[e_index(kids[k])];
        double r = (double)cy.r, t0 = -HUGE_VAL, t1 = HUGE_VAL, slack = 0;
        for (int j = 0; j < n; j++) {
            if (e_is_node(kids[j]) || s->prims[e_index(kids[j])].kind != O_PLANE) continue;
            const Prim &q = s->prims[e_index(kids[j])];
            double c = (double)q.n.x * cy.n.x + (double)q.n.y * cy.n.y + (double)q.n.z * cy.n.z;
            if (fabs(c) < 0.1) continue;
            double h = (double)q.n.x * cy.p.x + (double)q.n.y * cy.p.y + (double)q.n.z * cy.p.z;
            double t = ((double)q.d - h + r * sqrt(1 - c * c > 0 ? 1 - c * c : 0)) / c;
            slack += 64 * REAL_EPS * (fabs((double)q.d) + fabs(h) + r) / fabs(c);
            if (c > 0 && t < t1) t1 = t;
            if (c < 0 && t > t0) t0 = t;
        }
        if (!(t0 > -HUGE_VAL && t1 < HUGE_VAL && t0 <= t1)) continue;
        t0 -= slack;
        t1 += slack;
        Box cb;
        for (int l = 0; l < 3; l++) {
            double a = (double)comp(cy.n, l), p = (double)comp(cy.p, l);
            double e = r * sqrt(1 - a * a > 0 ? 1 - a * a : 0) + slack, x0 = p + a * t0, x1 = p + a * t1;
            cb.lo[l] = (real)((x0 < x1 ? x0 : x1) - e);
            cb.hi[l] = (real)((x0 < x1 ? x1 : x0) + e);
        }
        box_pad(&cb, r + fabs(t0) + fabs(t1) + fabs((double)cy.p.x) + fabs((double)cy.p.y) + fabs((double)cy.p.z));
        box_clip(b, cb);
    }
}

// The frame block of primitive q made from object o's frame, with the parameters of its kind;
// false when out of memory.
bool prim_frame(pray_ctx *c, Scene *s, const pray_object *o, Prim *q) {
    PrimFrame *f = (PrimFrame *)mem_zalloc(c, sizeof(PrimFrame));
    if (!f || !s->frames.push(c, f)) {
        mem_free(c, f);
        return false;
    }
    Xform g;
    xf_inverse(*o->fr, &g);  // (frame_ok has checked it)
    f->t = r3of(o->fr->t);
    for (int i = 0; i < 3; i++) {
        f->inv[i] = r3((real)g.m[i][0], (real)g.m[i][1], (real)g.m[i][2]);
        f->fwd[i] = r3((real)o->fr->m[i][0], (real)o->fr->m[i][1], (real)o->fr->m[i][2]);
    }
    // a box only moved (the frame a translation): its corners and texture origin are moved
    // instead, and rays need no mapping
    Xform id = xf_identity();
    id.t = o->fr->t;
    bool moved_box = o->kind == O_BOX && memcmp(&id, o->fr, sizeof id) == 0;
    if (moved_box) {
        q->p = r3of(vadd(o->p, o->fr->t));
        f->t = r3(0, 0, 0);
    }
    f->plain = moved_box || (vmaxabs(o->fr->t) == 0 && memcmp(&id, o->fr, sizeof id) == 0);
    pray_vec axis = vsub(o->v, o->p);
    double h = vlen(axis);
    switch (o->kind) {
    case O_SPHERE: q->kind = P_ELLIPSOID; break;
    case O_CYLINDER: q->kind = P_ECYLINDER; break;
    case O_BOX: {
        pray_vec t = moved_box ? o->fr->t : vmake(0, 0, 0), a = vadd(o->p, t), b = vadd(o->v, t);
        f->lo = r3of(vmake(a.x < b.x ? a.x : b.x, a.y < b.y ? a.y : b.y, a.z < b.z ? a.z : b.z));
        f->hi = r3of(vmake(a.x < b.x ? b.x : a.x, a.y < b.y ? b.y : a.y, a.z < b.z ? b.z : a.z));
        break;
    }
    case O_ROD:
    case O_CONE:
        q->n = r3of(vunit(axis));
        q->r = (real)o->r;
        f->h = (real)h;
        f->k = (real)((o->r2 - o->r) / h);
        break;
    case O_TORUS:
        q->n = r3of(vunit(o->v));
        q->r = (real)o->r;
        f->rt = (real)o->r2;
        break;
    default: break;
    }
    q->fr = f;
    return true;
}

// The world box of a primitive in a frame: its local extent along each world axis. (A disc of
// radius r across unit axis a reaches r |e - a (e.a)| along the world axis whose row of the
// frame's map is e.)
Box frame_box(const Prim &q, const Xform &fr) {
    Box b;
    const PrimFrame &f = *q.fr;
    double a[3] = {q.n.x, q.n.y, q.n.z}, scale = 0;
    for (int i = 0; i < 3; i++) {
        const double *e = fr.m[i];
        double ea = e[0] * a[0] + e[1] * a[1] + e[2] * a[2];
        double disc = sqrt(fabs(e[0] * e[0] + e[1] * e[1] + e[2] * e[2] - ea * ea));
        double len = sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]);
        double ti = (double)comp(f.t, i);  // (a moved box: 0, its corners moved)
        double lo, hi, p = e[0] * q.p.x + e[1] * q.p.y + e[2] * q.p.z + ti;
        switch (q.kind) {
        case P_ELLIPSOID: lo = p - q.r * len, hi = p + q.r * len; break;
        case P_ECYLINDER:
            lo = ea == 0 ? p - q.r * disc : -HUGE_VAL;
            hi = ea == 0 ? p + q.r * disc : HUGE_VAL;
            break;
        case O_BOX: {
            lo = hi = ti;
            double l3[3] = {f.lo.x, f.lo.y, f.lo.z}, h3[3] = {f.hi.x, f.hi.y, f.hi.z};
            for (int j = 0; j < 3; j++) {
                double u = e[j] * l3[j], v = e[j] * h3[j];
                lo += u < v ? u : v;
                hi += u < v ? v : u;
            }
            break;
        }
        case O_ROD:
        case O_CONE: {
            double r2 = q.kind == O_ROD ? (double)q.r : (double)q.r + (double)f.k * (double)f.h;
            double p2 = p + ea * (double)f.h;
            lo = p - q.r * disc;
            hi = p + q.r * disc;
            if (p2 - r2 * disc < lo) lo = p2 - r2 * disc;
            if (p2 + r2 * disc > hi) hi = p2 + r2 * disc;
            break;
        }
        default: {  // torus
            double ext = ((double)q.r + (double)f.rt) * disc + (double)f.rt * fabs(ea);
            lo = p - ext;
            hi = p + ext;
        }
        }
        b.lo[i] = (real)lo;
        b.hi[i] = (real)hi;
        if (lo > -HUGE_VAL && fabs(lo) > scale) scale = fabs(lo);
        if (hi < HUGE_VAL && fabs(hi) > scale) scale = fabs(hi);
    }
    // points reach the local frame and back with the rounding of both maps: pad by as much
    double mf = 0, mi = 0;
    for (int i = 0; i < 3; i++) {
        double lf = sqrt((double)dot(f.fwd[i], f.fwd[i])), li = sqrt((double)dot(f.inv[i], f.inv[i]));
        mf = lf > mf ? lf : mf;
        mi = li > mi ? li : mi;
    }
    box_pad(&b, 4 * scale * mf * mi);
    return b;
}

const Box &elem_box(const Scene *s, int e) {
    return e_is_node(e) ? s->nodes[e_index(e)].box : s->prims[e_index(e)].box;
}

// A node over the given children; returns its element code, or -3 when out of memory.
int add_node(pray_ctx *c, Scene *s, int op, const int *kids, int n) {
    Node nd;
    memset(&nd, 0, sizeof nd);
    nd.op = op;
    nd.n = n;
    nd.k0 = s->kids.n;
    nd.parent = -1;
    if (op == O_INTER) {
        nd.box = box_all();
        for (int i = 0; i < n; i++) box_clip(&nd.box, elem_box(s, kids[i]));
        polyhedron_box(s, kids, n, &nd.box);
        capped_cylinder_box(s, kids, n, &nd.box);
    } else if (op == O_UNION) {
        for (int l = 0; l < 3; l++) {
            nd.box.lo[l] = REAL_BIG;
            nd.box.hi[l] = -REAL_BIG;
        }
        for (int i = 0; i < n; i++) box_hull(&nd.box, elem_box(s, kids[i]));
    } else if (op == O_DIFF) {
        nd.box = elem_box(s, kids[0]);
    } else {
        nd.box = box_all();
    }
    for (int i = 0; i < n; i++)
        if (!s->kids.push(c, kids[i])) return -3;
    if (!s->nodes.push(c, nd)) return -3;
    for (int i = 0; i < n; i++) set_parent(s, kids[i], s->nodes.n - 1, i == 0);
    return 2 * (s->nodes.n - 1) + 1;
}

int flatten(pray_ctx *c, Scene *s, const pray_object *o);

// Add element e as a child of an `op` node being built: a node of the same operation (for a
// difference, only as its first child) gives its children instead, so chains stay one node.
// Unions and intersections are left nested here and merged by merge_chains: a union that a
// pruned difference hides at every level of a deep tree would otherwise be copied into the level
// above, again and again (time and memory quadratic in the tree's size).
bool add_kid(pray_ctx *c, Scene *s, Array<int> *kids, int op, int e) {
    if (e >= 0 && e_is_node(e)) {
        const Node &nd = s->nodes[e_index(e)];
        if (nd.op == op && op == O_DIFF && kids->n == 0) {
            if (!kids->reserve(c, kids->n + nd.n)) return false;
            for (int i = 0; i < nd.n; i++) kids->push(c, s->kids[nd.k0 + i]);
            return true;
        }
    }
    return kids->push(c, e);
}

// The component a plane's normal has alone (the normal lies along that axis), or none.
Axis plane_axis(R3 n) {
    if (n.y == 0 && n.z == 0) return &R3::x;
    if (n.x == 0 && n.z == 0) return &R3::y;
    if (n.x == 0 && n.y == 0) return &R3::z;
    return 0;
}

// Flatten the object into the scene's arrays in post-order (children before parents), folding
// `one` and `nothing` away and merging chains; with s->prune, also dropping what bounds prove
// cannot matter (not under a complement: all of space, that a union's later children fill with
// their materials, language 12). Parts left out stay without a parent until scene_compact.
// Returns the element code, or -3 when out of memory.
int flatten_in(pray_ctx *c, Scene *s, const pray_object *o);
int flatten(pray_ctx *c, Scene *s, const pray_object *o) {  // (with the id around each part)
    int outer = s->uid;
    s->uid = o->uid != PRAY_NO_ID ? o->uid : outer;
    int e = flatten_in(c, s, o);
    s->uid = outer;
    return e;
}
int flatten_in(pray_ctx *c, Scene *s, const pray_object *o) {
    switch (o->kind) {
    case O_ONE: return E_ALL;
    case O_NOTHING: return E_NONE;
    case O_SPHERE:
    case O_PLANE:
    case O_CYLINDER:
    case O_BOX:
    case O_ROD:
    case O_CONE:
    case O_TORUS: {
        Prim q = Prim();  // zeros, and no axis
        q.kind = o->kind;
        q.p = r3of(o->p);
        q.mat = o->mat;
        q.parent = -1;
        q.id = s->leaves++;
        q.uid = s->uid;
        if (o->map || o->mat->checks) {
            PrimMap *m = (PrimMap *)mem_zalloc(c, sizeof(PrimMap));
            if (!m || !s->maps.push(c, m)) {
                mem_free(c, m);
                return -3;
            }
            if (o->map) {
                m->u = r3of(o->map->u);
                m->v = r3of(o->map->v);
                m->mirrored = o->map->mirrored;
                q.map = o->map->kind;
            }
            Xform inv = xf_identity();
            if (o->pat) xf_inverse(*o->pat, &inv);  // (its moves had inverses)
            m->pt = r3of(o->pat ? o->pat->t : vmake(0, 0, 0));
            for (int i = 0; i < 3; i++) m->pinv[i] = r3of(vmake(inv.m[i][0], inv.m[i][1], inv.m[i][2]));
            q.tm = m;
        }
        if (o->kind == O_SPHERE) {
            q.r = (real)o->r;
        } else if (o->kind == O_PLANE) {
            q.n = r3of(vunit(o->v));
            q.d = dot(q.n, q.p);
            q.axis = plane_axis(q.n);
        } else if (o->kind == O_CYLINDER) {
            q.n = r3of(vunit(o->v));
            q.r = (real)o->r;
        }
        if (o->fr && !prim_frame(c, s, o, &q)) return -3;
        s->tori += o->kind == O_TORUS;
        q.r2 = q.r * q.r;
        q.box = q.fr ? frame_box(q, *o->fr) : prim_box(q);
        if (!s->prims.push(c, q)) return -3;
        retain((void *)q.mat);  // (the tree may go before the scene: scene_build)
        return 2 * (s->prims.n - 1);
    }
    default: break;
    }
    Array<int> kids;
    kids.init();
    int op = o->kind, prune = s->prune;
    int result = -4;  // undecided
    s->prune = prune && op != O_COMPL;
    for (int i = 0; i < o->nkids; i++) {
        if (result != -4) {  // decided: the rest is not needed, but keeps its primitives' numbers
            s->leaves += (int)kid(o, i)->nprims;
            continue;
        }
        int e = flatten(c, s, kid(o, i));
        if (e == -3) result = -3;
        else if (op == O_UNION) {
            if (e == E_ALL) result = E_ALL;
            else if (e != E_NONE && !add_kid(c, s, &kids, op, e)) result = -3;
        } else if (op == O_INTER) {
            if (e == E_NONE) result = E_NONE;
            else if (e != E_ALL && !add_kid(c, s, &kids, op, e)) result = -3;
        } else if (op == O_DIFF) {
            if (i == 0 && e == E_NONE) result = E_NONE;
            else if (i > 0 && e == E_ALL) result = E_NONE;
            else if (i > 0 && e == E_NONE) continue;
            else if (i > 0 && s->prune && kids[0] != E_ALL && !box_overlap(elem_box(s, kids[0]), elem_box(s, e)))
                continue;  // a subtracted part that cannot touch the base
            else if (!add_kid(c, s, &kids, op, e)) result = -3;
        } else {  // complement
            if (e == E_ALL) result = E_NONE;
            else if (e == E_NONE) result = E_ALL;
            else if (!kids.push(c, e)) result = -3;
        }
    }
    s->prune = prune;
    if (result == -4 && op == O_INTER && s->prune) {
        Box b = box_all();
        for (int i = 0; i < kids.n; i++) box_clip(&b, elem_box(s, kids[i]));
        if (box_empty(b)) result = E_NONE;  // parts whose boxes cannot meet
    }
    if (result == -4) {
        if (op == O_DIFF && kids[0] == E_ALL) {
            // all of space minus the others is the complement of their union
            if (kids.n == 1) result = E_ALL;
            else {
                int e = kids.n == 2 ? kids[1] : add_node(c, s, O_UNION, kids.p + 1, kids.n - 1);
                result = e == -3 ? -3 : add_node(c, s, O_COMPL, &e, 1);
            }
        } else if (kids.n == 0) result = op == O_INTER ? E_ALL : E_NONE;
        else if (kids.n == 1 && op != O_COMPL) result = kids[0];
        else result = add_node(c, s, op, kids.p, kids.n);
    }
    kids.release(c);
    return result;
}

// Surfaces that are meant to coincide (a face of A on a face of B in A \ B) but were computed
// along different paths differ in their last bits, and would speckle. Primitives of one kind whose
// surfaces agree to within a few units in the last place are given exactly the same parameters
// (opposite normals exactly negated), so their crossings get exactly the same t.
struct SnapKey {
    int prim;
    int sign;     // +1, or -1 when the normal was flipped to its canonical orientation
    double v[8];  // kind, then the canonical parameters
};

// Keys in order of their components, then of their primitives' numbers.
struct SnapKeyLess {
    bool operator()(const SnapKey &a, const SnapKey &b) const {
        for (int i = 0; i < 8; i++)
            if (a.v[i] != b.v[i]) return a.v[i] < b.v[i];
        return a.prim < b.prim;
    }
};

void snap_key(const Prim &q, SnapKey *k) {
    double n[3] = {q.n.x, q.n.y, q.n.z}, p[3] = {q.p.x, q.p.y, q.p.z};
    k->sign = 1;
    k->v[0] = q.kind;
    k->v[5] = k->v[6] = k->v[7] = 0;
    if (q.kind == O_SPHERE) {
        for (int i = 0; i < 3; i++) k->v[1 + i] = p[i];
        k->v[4] = q.r;
        return;
    }
    int big = 0;  // canonical orientation: the largest component positive
    for (int i = 1; i < 3; i++)
        if (fabs(n[i]) > fabs(n[big])) big = i;
    if (n[big] < 0) k->sign = -1;
    for (int i = 0; i < 3; i++) k->v[1 + i] = n[i] * k->sign;
    if (q.kind == O_PLANE) {
        k->v[4] = q.d * k->sign;
    } else {  // cylinder: the radius, then the point of the axis nearest the origin
        double t = p[0] * n[0] + p[1] * n[1] + p[2] * n[2];
        k->v[4] = q.r;
        for (int i = 0; i < 3; i++) k->v[5 + i] = p[i] - t * n[i];
    }
}

// Within a few units in the last place of the largest coordinate involved: rounding, not design.
bool snap_close(const Prim &a, const Prim &b, int sa, int sb) {
    double m = 0;
    const Prim *both[2] = {&a, &b};
    for (int k = 0; k < 2; k++) {
        const Prim &q = *both[k];
        double v[5] = {(double)q.p.x, (double)q.p.y, (double)q.p.z, (double)q.r, (double)q.d};
        for (int i = 0; i < 5; i++)
            if (fabs(v[i]) > m) m = fabs(v[i]);
    }
    double tol = SNAP_ULPS * REAL_EPS * m;
    R3 na = a.n * (real)sa, nb = b.n * (real)sb;
    R3 dp = a.p - b.p;
    if (a.kind == O_SPHERE)
        return fabs((double)dp.x) <= tol && fabs((double)dp.y) <= tol && fabs((double)dp.z) <= tol &&
               fabs((double)(a.r - b.r)) <= tol;
    R3 dn = na - nb;
    const double ntol = SNAP_ULPS * REAL_EPS;
    if (fabs((double)dn.x) > ntol || fabs((double)dn.y) > ntol || fabs((double)dn.z) > ntol) return false;
    if (a.kind == O_PLANE) return fabs((double)(a.d * (real)sa - b.d * (real)sb)) <= tol;
    R3 perp = dp - na * dot(dp, na);  // axes: the same line within tolerance
    return fabs((double)(a.r - b.r)) <= tol && fabs((double)perp.x) <= tol && fabs((double)perp.y) <= tol &&
           fabs((double)perp.z) <= tol;
}

// The largest magnitude among a primitive's parameters: the scale of its rounding.
double prim_scale(const Prim &q) {
    double v[5] = {(double)q.p.x, (double)q.p.y, (double)q.p.z, (double)q.r, (double)q.d}, m = 0;
    for (int i = 0; i < 5; i++)
        if (fabs(v[i]) > m) m = fabs(v[i]);
    return m;
}

// One key component of one primitive, for sorting the components one at a time.
struct SnapComp {
    double kind, v;
    int prim;
};
struct SnapCompLess {
    bool operator()(const SnapComp &a, const SnapComp &b) const {
        if (a.kind != b.kind) return a.kind < b.kind;
        if (a.v != b.v) return a.v < b.v;
        return a.prim < b.prim;
    }
};

bool same_key(const SnapKey &a, const SnapKey &b) {
    for (int i = 0; i < 8; i++)
        if (a.v[i] != b.v[i]) return false;
    return true;
}

// Coincident surfaces that differ by rounding get identical parameters. Sorting whole keys is
// not enough: two planes one unit in the last place apart in x may sort far from each other when
// other planes share one of their x values. So each key component is first rounded to a
// representative (values within tolerance of a run's first value take that value); then keys
// that became equal are neighbours, and the parameters of each group are snapped to its first.
pray_status snap_coincident(pray_ctx *c, Scene *s) {
    int n = s->prims.n;
    if (n == 1) s->prims[0].surf = 0;
    if (n < 2) return PRAY_OK;
    SnapKey *k = (SnapKey *)mem_alloc(c, sizeof(SnapKey) * (size_t)n);
    SnapComp *o = (SnapComp *)mem_alloc(c, sizeof(SnapComp) * 2 * (size_t)n);  // (and the sort's scratch)
    double *scale = (double *)mem_alloc(c, sizeof(double) * (size_t)n);
    if (!k || !o || !scale) {
        mem_free(c, k);
        mem_free(c, o);
        mem_free(c, scale);
        return c->status;
    }
    for (int i = 0; i < n; i++) {
        k[i].prim = i;
        snap_key(s->prims[i], &k[i]);
        scale[i] = prim_scale(s->prims[i]);
        s->prims[i].surf = i;
    }
    for (int comp = 1; comp < 8; comp++) {
        bool one = true;  // (one value for all, such as a sphere's 0 after its radius: nothing to round)
        for (int i = 1; i < n && one; i++) one = k[i].v[comp] == k[0].v[comp];
        if (one) continue;
        for (int i = 0; i < n; i++) {
            o[i].kind = k[i].v[0];
            o[i].v = k[i].v[comp];
            o[i].prim = i;
        }
        sort_items(o, o + n, (size_t)n, SnapCompLess());
        for (int i = 0; i < n;) {
            const SnapComp &a = o[i];
            int j = i + 1;
            for (; j < n && o[j].kind == a.kind; j++) {
                // normals and axes are unit vectors: absolute; positions relative to their scale
                bool unit = a.kind != (double)O_SPHERE && comp <= 3;
                double m = scale[a.prim] > scale[o[j].prim] ? scale[a.prim] : scale[o[j].prim];
                if (o[j].v - a.v > SNAP_ULPS * REAL_EPS * (unit ? 1 : m)) break;
                k[o[j].prim].v[comp] = a.v;
            }
            i = j;
        }
    }
    mem_free(c, o);
    mem_free(c, scale);
    o = NULL;
    scale = NULL;
    SnapKey *tmp = (SnapKey *)mem_alloc(c, sizeof(SnapKey) * (size_t)n);
    if (!tmp) {
        mem_free(c, k);
        return c->status;
    }
    sort_items(k, tmp, (size_t)n, SnapKeyLess());
    mem_free(c, tmp);
    for (int i = 0; i < n;) {
        const Prim &a = s->prims[k[i].prim];
        int j = i + 1;
        for (; j < n && same_key(k[i], k[j]); j++) {
            Prim &b = s->prims[k[j].prim];
            if (a.fr || !snap_close(a, b, k[i].sign, k[j].sign)) continue;  // (not in frames)
            int f = k[i].sign * k[j].sign;  // +1 same orientation, -1 opposite
            b.surf = a.surf;                // twins from now on
            if (a.kind != O_PLANE) b.p = a.p;  // a plane's point is its texture origin only
            b.r = a.r;
            b.r2 = a.r2;
            b.n = a.n * (real)f;
            b.d = a.d * (real)f;
            b.axis = a.axis;
        }
        i = j;
    }
    mem_free(c, k);
    return PRAY_OK;
}

// Unions that are children of unions, and intersections of intersections, give their children
// to the node above (as flattening does for a difference's first child, add_kid): each child is
// moved once, to the topmost node of its chain, so the work is linear. The merged lists go to
// the end of s->kids; what they leave behind is dropped by scene_compact. A merged union's box
// is the hull of its children's either way; a merged intersection's is made again from its whole
// list, as for one built at once (add_node).
inline bool chains(const Scene *s, int op, int e) {
    return (op == O_UNION || op == O_INTER) && e_is_node(e) && s->nodes[e_index(e)].op == op;
}
pray_status merge_chains(pray_ctx *c, Scene *s) {
    bool any = false;
    for (int j = 0; j < s->nodes.n && !any; j++) {
        const Node &nd = s->nodes[j];
        for (int i = 0; i < nd.n && !any; i++) any = chains(s, nd.op, s->kids[nd.k0 + i]);
    }
    if (!any || s->root < 0 || !e_is_node(s->root)) return PRAY_OK;
    Array<int> todo, stack, list;  // nodes to visit; a chain's walk: (node, next child); its new list
    todo.init();
    stack.init();
    list.init();
    bool ok = todo.push(c, e_index(s->root));
    while (ok && todo.n) {
        int j = todo[--todo.n];
        int op = s->nodes[j].op;
        list.n = 0;
        ok = stack.push(c, j) && stack.push(c, 0);
        bool merged = false;
        while (ok && stack.n) {
            int m = stack[stack.n - 2], k = stack[stack.n - 1];
            if (k == s->nodes[m].n) {
                stack.n -= 2;
                continue;
            }
            stack[stack.n - 1] = k + 1;
            int e = s->kids[s->nodes[m].k0 + k];
            if (chains(s, op, e)) {
                merged = true;
                ok = stack.push(c, e_index(e)) && stack.push(c, 0);
            } else {
                ok = list.push(c, e) && (!e_is_node(e) || todo.push(c, e_index(e)));
            }
        }
        if (ok && merged) {
            int k0 = s->kids.n;
            for (int i = 0; i < list.n && ok; i++) ok = s->kids.push(c, list[i]);
            s->nodes[j].k0 = k0;
            s->nodes[j].n = list.n;
            if (ok && op == O_INTER) {
                Box &b = s->nodes[j].box;
                b = box_all();
                for (int i = 0; i < list.n; i++) box_clip(&b, elem_box(s, list[i]));
                polyhedron_box(s, s->kids.p + k0, list.n, &b);
            }
        }
    }
    todo.release(c);
    stack.release(c);
    list.release(c);
    return ok ? PRAY_OK : c->status;
}

// Parents and `settles` of a compacted scene.
void scene_link(Scene *s) {
    Array<Prim> &prims = s->prims;
    Array<Node> &nodes = s->nodes;
    for (int i = 0; i < prims.n; i++) prims[i].parent = -1;
    for (int j = 0; j < nodes.n; j++) nodes[j].parent = -1;
    for (int j = 0; j < nodes.n; j++)
        for (int i = 0; i < nodes[j].n; i++) {
            int e = s->kids[nodes[j].k0 + i];
            if (e_is_node(e)) {
                nodes[e_index(e)].parent = j;
                nodes[e_index(e)].first = i == 0;
            } else {
                prims[e_index(e)].parent = j;
                prims[e_index(e)].first = i == 0;
            }
        }
    for (int i = 0; i < prims.n; i++) {
        const Prim &q = prims[i];
        int op = q.parent < 0 ? O_COMPL : nodes[q.parent].op;  // the root: either decides
        prims[i].settles = (unsigned char)(op == O_UNION ? 2 : op == O_INTER ? 1 : op == O_DIFF ? (q.first ? 1 : 2) : 3);
    }
}

// scene_compact in place, without a second copy of the scene: possible when the post-order
// from the root meets the elements in the order they were flattened in (it does: flattening
// is a post-order walk too, and folding, merging and pruning only leave elements out). `num`
// gives the new numbers (prims, then nodes; -1 for those left out). False when the order
// differs.
bool compact_in_place(pray_ctx *c, Scene *s, const int *num, int root) {
    int np = s->prims.n, nn = s->nodes.n;
    int last = -1;
    for (int i = 0; i < np; i++)
        if (num[i] >= 0) {
            if (num[i] <= last) return false;
            last = num[i];
        }
    last = -1;
    for (int j = 0; j < nn; j++)
        if (num[np + j] >= 0) {
            if (num[np + j] <= last) return false;
            last = num[np + j];
        }
    for (int j = 1; j < nn; j++)  // each node's children follow those of the nodes before it
        if (s->nodes[j].k0 < s->nodes[j - 1].k0 + s->nodes[j - 1].n) return false;
    int pc = 0, nc = 0, w = 0;
    for (int i = 0; i < np; i++)
        if (num[i] >= 0) s->prims[pc++] = s->prims[i];
        else release_handle(c, (pray_model *)s->prims[i].mat);
    for (int j = 0; j < nn; j++) {
        if (num[np + j] < 0) continue;
        Node nd = s->nodes[j];
        for (int k = 0; k < nd.n; k++) {  // (w <= nd.k0 + k: copied forwards, never over what is still to read)
            int e = s->kids[nd.k0 + k];
            s->kids[w + k] = e_is_node(e) ? 2 * num[np + e_index(e)] + 1 : 2 * num[e_index(e)];
        }
        nd.k0 = w;
        w += nd.n;
        s->nodes[nc++] = nd;
    }
    s->prims.n = pc;
    s->nodes.n = nc;
    s->kids.n = w;
    s->root = e_is_node(root) ? 2 * num[np + e_index(root)] + 1 : 2 * num[e_index(root)];
    scene_link(s);
    return true;
}

// Keep only what the root reaches, renumbered in post-order (flattening leaves folded and
// pruned parts behind).
pray_status scene_compact(pray_ctx *c, Scene *s) {
    if (s->root < 0) {
        for (int i = 0; i < s->prims.n; i++) release_handle(c, (pray_model *)s->prims[i].mat);
        s->prims.n = s->nodes.n = s->kids.n = 0;
        return PRAY_OK;
    }
    {
        // the new numbers, by a post-order walk from the root with a stack of (element, next child)
        int np = s->prims.n, nn = s->nodes.n;
        int *num = (int *)mem_alloc(c, sizeof(int) * ((size_t)np + (size_t)nn));
        Array<int> stack;
        stack.init();
        if (!num) return c->status;
        for (int i = 0; i < np + nn; i++) num[i] = -1;
        int pc = 0, nc = 0;
        bool ok = stack.push(c, s->root) && stack.push(c, 0);
        while (ok && stack.n) {
            int e = stack[stack.n - 2], k = stack[stack.n - 1];
            if (e_is_node(e)) {
                const Node &nd = s->nodes[e_index(e)];
                if (k < nd.n) {
                    stack[stack.n - 1] = k + 1;
                    ok = stack.push(c, s->kids[nd.k0 + k]) && stack.push(c, 0);
                    continue;
                }
                num[np + e_index(e)] = nc++;
            } else {
                num[e_index(e)] = pc++;
            }
            stack.n -= 2;
        }
        stack.release(c);
        bool done = ok && compact_in_place(c, s, num, s->root);
        mem_free(c, num);
        if (!ok) return c->status;
        if (done) return PRAY_OK;
    }
    Array<Prim> prims;
    Array<Node> nodes;
    Array<int> kids, stack, done;
    prims.init();
    nodes.init();
    kids.init();
    stack.init();
    done.init();
    pray_status st = PRAY_OK;
    // iterative post-order: `stack` holds (element, next child) pairs; `done` the new codes of
    // finished elements whose parent is not finished yet
    if (!stack.push(c, s->root) || !stack.push(c, 0)) st = c->status;
    while (st == PRAY_OK && stack.n) {
        int e = stack[stack.n - 2], k = stack[stack.n - 1];
        int code;
        if (!e_is_node(e)) {
            Prim q = s->prims[e_index(e)];
            q.parent = -1;
            if (!prims.push(c, q)) st = c->status;
            code = 2 * (prims.n - 1);
        } else {
            const Node &nd = s->nodes[e_index(e)];
            if (k < nd.n) {
                stack[stack.n - 1] = k + 1;
                if (!stack.push(c, s->kids[nd.k0 + k]) || !stack.push(c, 0)) st = c->status;
                continue;
            }
            Node m = nd;
            m.k0 = kids.n;
            m.parent = -1;
            for (int i = 0; i < nd.n && st == PRAY_OK; i++)
                if (!kids.push(c, done[done.n - nd.n + i])) st = c->status;
            done.n -= nd.n;
            if (!nodes.push(c, m)) st = c->status;
            code = 2 * (nodes.n - 1) + 1;
        }
        stack.n -= 2;
        if (st == PRAY_OK && !done.push(c, code)) st = c->status;
    }
    if (st == PRAY_OK) {
        for (int i = 0; i < prims.n; i++) retain((void *)prims[i].mat);  // what is left out lets go
        for (int i = 0; i < s->prims.n; i++) release_handle(c, (pray_model *)s->prims[i].mat);
        s->prims.release(c);
        s->nodes.release(c);
        s->kids.release(c);
        s->prims = prims;
        s->nodes = nodes;
        s->kids = kids;
        s->root = done[0];
        scene_link(s);
    } else {
        prims.release(c);
        nodes.release(c);
        kids.release(c);
    }
    stack.release(c);
    done.release(c);
    return st;
}

// ---- where materials meet (language 12) ----
// Values compared by their bits (here, and between the frames of a sequence, 10b).
inline bool same_bytes(const void *a, const void *b, size_t n) { return memcmp(a, b, n) == 0; }
inline bool same_rgb_bits(pray_rgb a, pray_rgb b) { return same_bytes(&a, &b, sizeof a); }

bool tex_same(const pray_texture *a, const pray_texture *b) {
    if (a == b) return true;
    return a && b && a->w == b->w && a->hgt == b->hgt &&
           same_bytes(a->rgb, b->rgb, sizeof(float) * 3 * (size_t)a->w * (size_t)a->hgt);
}

// Two models alike in every coefficient, texture (its texels) and part.
bool model_same(const pray_model *a, const pray_model *b) {
    if (a == b) return true;
    if (!a || !b || a->kind != b->kind || a->has_exponent != b->has_exponent || a->has_index != b->has_index)
        return false;
    const pray_rgb *x[7] = {&a->diffuse, &a->specular, &a->ambient, &a->emit, &a->reflect, &a->transmit, &a->factor};
    const pray_rgb *y[7] = {&b->diffuse, &b->specular, &b->ambient, &b->emit, &b->reflect, &b->transmit, &b->factor};
    for (int i = 0; i < 7; i++)
        if (!same_rgb_bits(*x[i], *y[i])) return false;
    double u[5] = {a->exponent, a->index, a->amount, a->dx, a->dy}, v[5] = {b->exponent, b->index, b->amount, b->dx, b->dy};
    return same_bytes(u, v, sizeof u) && tex_same(a->tex, b->tex) && model_same(a->a, b->a) && model_same(a->b, b->b);
}


// The solids of two primitives neither overlap nor touch but at a point, for certain: spheres,
// and a sphere or a box against a half-space whose normal is along an axis (so that balls
// resting on a floor or on one another, and boxes above it, are apart). False: perhaps not.
bool solids_apart(const Prim &a, const Prim &b) {
    if (b.kind == O_PLANE && a.kind != O_PLANE) return solids_apart(b, a);
    if (a.kind == O_SPHERE && b.kind == O_SPHERE && !a.fr && !b.fr) {
        R3 v = a.p - b.p;
        real r = a.r + b.r;
        return dot(v, v) >= r * r;
    }
    if (a.kind != O_PLANE) return false;
    if (b.kind == O_SPHERE && !b.fr) return dot(a.n, b.p) - a.d >= b.r;
    if (!a.axis) return false;
    int l = a.axis == &R3::x ? 0 : a.axis == &R3::y ? 1 : 2;
    real n = a.n.*a.axis;  // (the half-space is n x_l <= d; the box's nearest point to it)
    return (n > 0 ? n * b.box.lo[l] : n * b.box.hi[l]) >= a.d;
}

// Two primitives of different materials (language 12: models that differ as values).
inline bool other_material(const Scene *s, int p, int q) {
    return s->prims[p].mat != s->prims[q].mat && !model_same(s->prims[p].mat, s->prims[q].mat);
}

// Each primitive's box into out[], with `clip` clipped by the boxes of all its ancestors: a
// primitive matters only there, since outside a node's box the node is outside, and so is what
// its primitives alone would make of it. False when out of memory.
bool prim_boxes(pray_ctx *c, const Scene *s, Box *out, bool clip) {
    Box *nb = clip ? (Box *)mem_alloc(c, sizeof(Box) * (size_t)(s->nodes.n + 1)) : NULL;
    if (clip && !nb) return false;
    for (int j = s->nodes.n - 1; clip && j >= 0; j--) {  // parents before children
        nb[j] = s->nodes[j].box;
        if (s->nodes[j].parent >= 0) box_clip(&nb[j], nb[s->nodes[j].parent]);
    }
    for (int i = 0; i < s->prims.n; i++) {
        out[i] = s->prims[i].box;
        if (clip && s->prims[i].parent >= 0) box_clip(&out[i], nb[s->prims[i].parent]);
    }
    mem_free(c, nb);
    return true;
}

// The child whose material fills a node wherever the node holds the point (language 12): a
// difference's first, an intersection's last that is not a complement; -1 for a union (the
// last child holding the point: owner) and a complement (no primitive's material).
int fill_child(const Scene *s, const Node &nd) {
    if (nd.op != O_DIFF && nd.op != O_INTER) return -1;
    const int *k = &s->kids[nd.k0];
    int i = nd.op == O_DIFF ? 0 : nd.n - 1;
    while (nd.op == O_INTER && i > 0 && e_is_node(k[i]) && s->nodes[e_index(k[i])].op == O_COMPL) i--;
    return i;
}

// Prim::owns, from the root down (a parent is numbered after its children), as owner (section
// 9) descends: every child of a union, the one that fills a difference or an intersection
// (fill_child), nothing under a complement. `own`: per node, zeroed.
void scene_owners(Scene *s, unsigned char *own) {
    for (int i = 0; i < s->prims.n; i++) s->prims[i].owns = s->root == 2 * i;
    if (e_is_node(s->root)) own[e_index(s->root)] = 1;
    for (int j = s->nodes.n - 1; j >= 0; j--) {
        const Node &nd = s->nodes[j];
        const int *k = &s->kids[nd.k0];
        int fill = fill_child(s, nd);
        for (int i = 0; own[j] && nd.op != O_COMPL && i < nd.n; i++) {
            if (nd.op != O_UNION && i != fill) continue;
            if (e_is_node(k[i])) own[e_index(k[i])] = 1;
            else s->prims[e_index(k[i])].owns = 1;
        }
    }
}

// Scene::iface: may two primitives of different materials (models that differ as values) fill
// the solid (Prim::owns)? Only then can it have a face between two materials; the lists find
// where (lb_mixed).
pray_status scene_interfaces(pray_ctx *c, Scene *s) {
    unsigned char *own = (unsigned char *)mem_zalloc(c, (size_t)s->nodes.n + 1);
    if (!own) return c->status;
    scene_owners(s, own);
    mem_free(c, own);
    int n = s->prims.n, k = 0;
    while (k < n && !s->prims[k].owns) k++;
    int m = k + 1;
    while (m < n && !(s->prims[m].owns && other_material(s, m, k))) m++;
    s->iface = m < n;
    return PRAY_OK;
}

// =============================================================================================
// [SECTION] 8 Ray/primitive intersection; primitives in a frame (box, rod, cone, torus, stretched)
// =============================================================================================
const real REAL_INF = (real)HUGE_VAL;

struct Ray {
    R3 o, d;  // d is a unit vector
};

// SPAN2: two intervals, [t0, t1] and then [t2, t3] (a torus; where the caller asks for the
// second, else a span it cannot take: an evaluation that can takes over).
enum { SPAN_NONE, SPAN_ALL, SPAN, SPAN2 };

int framed_span(const Prim &q, const Ray &ray, bool self, real *t0, real *t1, real *t23);

// The parameter interval [t0, t1] of the ray inside the primitive (t0 may be -inf, t1 +inf).
// `self`: the ray starts on this primitive's surface; its crossing there is known by identity
// and left out, and which side the ray goes to decides its status at the start.
// (t23: where a torus puts its second interval; NULL for callers that take one interval only.)
inline int prim_span(const Prim &q, const Ray &ray, bool self, real *t0, real *t1, real *t23 = 0) {
    switch (q.kind) {
    case O_SPHERE: {
        R3 oc = ray.o - q.p;
        real b = dot(oc, ray.d);
        if (self) {
            if (b >= 0) return SPAN_NONE;
            *t0 = 0;
            *t1 = -2 * b;
            return SPAN;
        }
        R3 perp = oc - ray.d * b;  // closest approach, without the cancellation of b*b - c
        real h2 = q.r2 - dot(perp, perp);
        if (h2 < 0) return SPAN_NONE;
        real h = (real)sqrt((double)h2);
        *t0 = -b - h;
        *t1 = -b + h;
        return SPAN;
    }
    case O_PLANE: {
        // (a normal along an axis: the dot products' only term that is not zero, the same value)
        real dn, s0;
        if (q.axis) {
            dn = q.n.*q.axis * ray.d.*q.axis;
            s0 = q.n.*q.axis * ray.o.*q.axis - q.d;
        } else {
            dn = dot(q.n, ray.d);
            s0 = dot(q.n, ray.o) - q.d;
        }
        if (self) {
            if (dn >= 0) return SPAN_NONE;
            *t0 = 0;
            *t1 = REAL_INF;
            return SPAN;
        }
        if (dn == 0) return s0 < 0 ? SPAN_ALL : SPAN_NONE;
        real t = -s0 / dn;
        if (dn < 0) {
            *t0 = t;
            *t1 = REAL_INF;
        } else {
            *t0 = -REAL_INF;
            *t1 = t;
        }
        return SPAN;
    }
    case O_CYLINDER: {
        R3 oc = ray.o - q.p;
        R3 op = oc - q.n * dot(oc, q.n);
        R3 dp = ray.d - q.n * dot(ray.d, q.n);
        real a = dot(dp, dp);
        if (self) {
            real b = dot(op, dp);
            if (a == 0 || b >= 0) return SPAN_NONE;
            *t0 = 0;
            *t1 = -2 * b / a;
            return SPAN;
        }
        if (a == 0) return dot(op, op) < q.r2 ? SPAN_ALL : SPAN_NONE;
        real tc = -dot(op, dp) / a;
        R3 m = op + dp * tc;
        real h2 = (q.r2 - dot(m, m)) / a;
        if (h2 < 0) return SPAN_NONE;
        real h = (real)sqrt((double)h2);
        *t0 = tc - h;
        *t1 = tc + h;
        return SPAN;
    }
    default: return framed_span(q, ray, self, t0, t1, t23);
    }
}

// ---- primitives in a frame: the ray mapped into it (its direction no longer a unit vector;
// the parameter t is the same in both) ----
inline R3 to_local(const PrimFrame &f, R3 x) {
    R3 v = x - f.t;
    return r3(dot(f.inv[0], v), dot(f.inv[1], v), dot(f.inv[2], v));
}
inline R3 dir_local(const PrimFrame &f, R3 d) { return r3(dot(f.inv[0], d), dot(f.inv[1], d), dot(f.inv[2], d)); }
inline R3 dir_world(const PrimFrame &f, R3 d) { return r3(dot(f.fwd[0], d), dot(f.fwd[1], d), dot(f.fwd[2], d)); }
// A local normal n as a world one: by the inverse transpose, which keeps it on the outer side
// also when the frame mirrors.
inline R3 normal_world(const PrimFrame &f, R3 n) { return unit(f.inv[0] * n.x + f.inv[1] * n.y + f.inv[2] * n.z); }

// [t0, t1] of the ray within lo <= o + t d <= hi along one direction (o, d: along it); false
// when empty. The bounds are exclusive as a half-space's are: a ray in the plane is outside.
inline bool slab(real o, real d, real lo, real hi, real *t0, real *t1) {
    if (d == 0) return o > lo && o < hi;
    real a = (lo - o) / d, b = (hi - o) / d;
    if (a > b) {
        real x = a;
        a = b;
        b = x;
    }
    if (a > *t0) *t0 = a;
    if (b < *t1) *t1 = b;
    return *t0 <= *t1;
}

// The interval where A t^2 + 2 B t + C <= 0 that lies within [*t0, *t1] (narrowed to it); the
// quadric's other piece when it has two (A < 0) is the one that meets less of [*t0, *t1].
int quadric_span(real A, real B, real C, real *t0, real *t1) {
    real lo = *t0, hi = *t1, a, b;
    if (A == 0) {  // 2 B t + C <= 0
        if (B == 0) return C <= 0 ? SPAN : SPAN_NONE;
        real t = -C / (2 * B);
        if (B > 0) a = -REAL_INF, b = t;
        else a = t, b = REAL_INF;
    } else {
        real disc = B * B - A * C;
        if (disc < 0) return A < 0 ? SPAN : SPAN_NONE;
        real sq = (real)sqrt((double)disc);
        real k = B > 0 ? -(B + sq) : -B + sq;  // no cancellation: the roots are k / A and C / k
        real r0 = k / A, r1 = k != 0 ? C / k : r0;
        if (r0 > r1) {
            real x = r0;
            r0 = r1;
            r1 = x;
        }
        if (A > 0) a = r0, b = r1;
        else {  // (-inf, r0] and [r1, inf)
            real l0 = (r0 < hi ? r0 : hi) - lo, l1 = hi - (r1 > lo ? r1 : lo);
            if (l0 >= l1) a = -REAL_INF, b = r0;
            else a = r1, b = REAL_INF;
        }
    }
    if (a > lo) *t0 = a;
    if (b < hi) *t1 = b;
    return *t0 <= *t1 ? SPAN : SPAN_NONE;
}

// The real roots of the depressed quartic x^4 + c2 x^2 + c1 x + c0 where it changes sign, in
// increasing order: 0, 2 or 4 of them, where it turns negative and positive again in turn.
// Each lies alone between two extremes (roots of the derivative, a cubic solved in closed form
// and polished), where it is bracketed and refined by Newton steps kept in the bracket.
int quartic_roots(double c2, double c1, double c0, double *root) {
    // the extremes: 4 x^3 + 2 c2 x + c1 = 0, i.e. x^3 + P x + Q = 0
    double P = c2 / 2, Q = c1 / 4, ext[3];
    int ne;
    double D = (Q / 2) * (Q / 2) + (P / 3) * (P / 3) * (P / 3);
    if (D > 0) {
        double A = cbrt_pos(fabs(Q) / 2 + sqrt(D));
        if (Q > 0) A = -A;
        ext[0] = A != 0 ? A - P / (3 * A) : 0;
        ne = 1;
    } else {
        double m = 2 * sqrt(-P / 3), c = m > 0 ? 3 * Q / (P * m) : 0;
        double th = acos(c > 1 ? 1 : c < -1 ? -1 : c) / 3;
        for (int k = 0; k < 3; k++) ext[k] = m * cos(th - 2.0943951023931954923 * k);
        ne = 3;
    }
    for (int k = 0; k < ne; k++)
        for (int it = 0; it < 2; it++) {  // polish
            double x = ext[k], g = 3 * x * x + P;
            if (g != 0) ext[k] = x - ((x * x + P) * x + Q) / g;
        }
    for (int i = 1; i < ne; i++)  // sort
        for (int j = i; j > 0 && ext[j] < ext[j - 1]; j--) {
            double x = ext[j];
            ext[j] = ext[j - 1];
            ext[j - 1] = x;
        }
    double B = 1 + (fabs(c2) > fabs(c1) ? fabs(c2) : fabs(c1));
    if (fabs(c0) + 1 > B) B = fabs(c0) + 1;
    double pts[5];
    int np = 0;
    pts[np++] = -B;
    for (int k = 0; k < ne; k++)
        if (ext[k] > -B && ext[k] < B) pts[np++] = ext[k];
    pts[np++] = B;
    int n = 0;
    for (int i = 0; i + 1 < np; i++) {
        double lo = pts[i], hi = pts[i + 1];
        double flo = ((lo * lo + c2) * lo + c1) * lo + c0, fhi = ((hi * hi + c2) * hi + c1) * hi + c0;
        if ((flo < 0) == (fhi < 0)) continue;
        bool down = flo >= 0;  // f falls through the root: entering
        double x = (lo + hi) / 2;
        for (int it = 0; it < 200; it++) {
            double fx = ((x * x + c2) * x + c1) * x + c0;
            if (fx == 0) break;
            if ((fx < 0) == down) hi = x;
            else lo = x;
            double g = (4 * x * x + 2 * c2) * x + c1, y = g != 0 ? x - fx / g : lo;
            if (!(y > lo && y < hi)) y = lo + (hi - lo) / 2;  // Newton left the bracket: halve it
            if (y == x || !(hi - lo > 0) || y == lo || y == hi) {
                x = y;
                break;
            }
            x = y;
        }
        root[n++] = x;
    }
    return n & ~1;  // (in pairs: the quartic is positive far out on both sides)
}

// The torus: centre p, unit axis n, radius r to the tube's centre line, tube radius f.rt. The
// ray is taken in units of r from its point nearest the centre, so that the quartic's
// coefficients are of order 1 whatever the torus' size and distance; a ray that passes farther
// than r + rt from the centre misses. `self`: the crossing nearest the origin is the ray's start.
int torus_span(const Prim &q, R3 o, R3 d, bool self, real *t) {
    const PrimFrame &f = *q.fr;
    double R = (double)q.r, rt = (double)f.rt / R;
    double dv[3] = {(double)d.x, (double)d.y, (double)d.z}, ov[3], nv[3] = {(double)q.n.x, (double)q.n.y, (double)q.n.z};
    R3 oc = o - q.p;
    ov[0] = (double)oc.x / R;
    ov[1] = (double)oc.y / R;
    ov[2] = (double)oc.z / R;
    double dl = sqrt(dv[0] * dv[0] + dv[1] * dv[1] + dv[2] * dv[2]);
    if (!(dl > 0)) return SPAN_NONE;
    for (int i = 0; i < 3; i++) dv[i] /= dl;  // x = o + s d, t = (s + sc) R / dl
    double sc = -(ov[0] * dv[0] + ov[1] * dv[1] + ov[2] * dv[2]);
    for (int i = 0; i < 3; i++) ov[i] += sc * dv[i];
    double oo = ov[0] * ov[0] + ov[1] * ov[1] + ov[2] * ov[2];
    if (oo >= (1 + rt) * (1 + rt)) return SPAN_NONE;
    double on = ov[0] * nv[0] + ov[1] * nv[1] + ov[2] * nv[2], dn = dv[0] * nv[0] + dv[1] * nv[1] + dv[2] * nv[2];
    double k = oo + 1 - rt * rt;
    // (s^2 + k)^2 = 4 |(o + s d) across the axis|^2, with o.d = 0
    double c2 = 2 * k - 4 * (1 - dn * dn), c1 = 8 * on * dn, c0 = k * k - 4 * (oo - on * on);
    double root[4];
    int n = quartic_roots(c2, c1, c0, root);
    if (n == 0) return SPAN_NONE;
    double scale = R / dl;
    real tt[4];
    for (int i = 0; i < n; i++) tt[i] = (real)((root[i] + sc) * scale);
    if (self) {  // the root nearest 0 is the start: the ray is inside after it when it enters there
        int b = 0;
        for (int i = 1; i < n; i++)
            if (fabs((double)tt[i]) < fabs((double)tt[b])) b = i;
        tt[b] = 0;
        for (int i = 0; i < n; i++)  // (rounding may leave an earlier root just past 0)
            if (i < b && tt[i] > 0) tt[i] = 0;
    }
    if (n == 4 && !(tt[1] < tt[2])) {  // intervals that touch (a ray grazing the hole's rim): one
        tt[1] = tt[3];
        n = 2;
    }
    for (int i = 0; i < n; i++) t[i] = tt[i];
    return n == 2 ? SPAN : SPAN2;
}

int framed_span(const Prim &q, const Ray &ray, bool self, real *t0, real *t1, real *t23) {
    const PrimFrame &f = *q.fr;
    R3 o = ray.o, d = ray.d;
    if (!f.plain) o = to_local(f, o), d = dir_local(f, d);
    if (q.kind == O_TORUS) {
        real t[4] = {0, 0, 0, 0};
        int k = torus_span(q, o, d, self, t);
        *t0 = t[0];
        *t1 = t[1];
        if (k == SPAN2 && t23) {
            t23[0] = t[2];
            t23[1] = t[3];
        }
        return k;
    }
    int k = SPAN;
    *t0 = -REAL_INF;
    *t1 = REAL_INF;
    switch (q.kind) {
    case O_BOX:
        if (!slab(o.x, d.x, f.lo.x, f.hi.x, t0, t1) || !slab(o.y, d.y, f.lo.y, f.hi.y, t0, t1) ||
            !slab(o.z, d.z, f.lo.z, f.hi.z, t0, t1))
            k = SPAN_NONE;
        break;
    case P_ELLIPSOID:
    case P_ECYLINDER:
    case O_ROD:
    case O_CONE: {
        // along the local direction made a unit vector (t = s / dl), so that the quadric's
        // coefficients neither overflow nor underflow
        real dl = (real)sqrt((double)dot(d, d));
        if (!(dl > 0)) return SPAN_NONE;
        d = d * ((real)1 / dl);
        R3 oc = o - q.p;
        real so = 0, sd = 0;
        if (q.kind != P_ELLIPSOID) {
            so = dot(oc, q.n);
            sd = dot(d, q.n);
            oc = oc - q.n * so;
            d = d - q.n * sd;
        }
        if ((q.kind == O_ROD || q.kind == O_CONE) && !slab(so, sd, 0, f.h, t0, t1)) {
            k = SPAN_NONE;
            break;
        }
        real ro = q.r, rd = 0;  // the radius at the origin's level, and its change along t
        if (q.kind == O_CONE) {
            ro = q.r + f.k * so;
            rd = f.k * sd;
        }
        // |oc + s d|^2 - (ro + s rd)^2 <= 0 (d across the axis is taken as 0 where its square
        // would lose its precision: a ray along the axis)
        const real DD_MIN = sizeof(real) < sizeof(double) ? (real)1e-30 : (real)1e-290;
        real dd = dot(d, d);
        if (dd < DD_MIN) dd = 0;
        if (dd == 0 && rd == 0) {
            if (!(dot(oc, oc) < ro * ro)) k = SPAN_NONE;
            else if (q.kind == P_ECYLINDER) k = SPAN_ALL;
        } else
            k = quadric_span(dd - rd * rd, dot(oc, d) - ro * rd, dot(oc, oc) - ro * ro, t0, t1);
        *t0 /= dl;
        *t1 /= dl;
        break;
    }
    default: k = SPAN_NONE; break;
    }
    if (self) {  // the span's end at the ray's origin is its crossing there: inward or not
        if (k != SPAN || !(*t1 > -*t0)) return SPAN_NONE;
        *t0 = 0;
    }
    return k;
}

// Whether world point x lies inside a primitive in a frame (strictly, as its spans count it);
// false for the torus, which is not convex (so its corners say nothing of a box between them).
bool framed_inside(const Prim &q, R3 x) {
    const PrimFrame &f = *q.fr;
    R3 l = to_local(f, x), v = l - q.p;
    switch (q.kind) {
    case O_BOX: return l.x > f.lo.x && l.x < f.hi.x && l.y > f.lo.y && l.y < f.hi.y && l.z > f.lo.z && l.z < f.hi.z;
    case P_ELLIPSOID: return dot(v, v) < q.r2;
    case P_ECYLINDER:
    case O_ROD:
    case O_CONE: {
        real s = dot(v, q.n), r = q.kind == O_CONE ? q.r + f.k * s : q.r;
        R3 perp = v - q.n * s;
        return (q.kind == P_ECYLINDER || (s > 0 && s < f.h)) && dot(perp, perp) < r * r;
    }
    default: return false;  // (a torus is not convex)
    }
}

// Outward unit normal of a primitive in a frame at local point x on its surface: of the part
// of its surface that x is nearest to.
R3 framed_normal(const Prim &q, R3 x) {
    const PrimFrame &f = *q.fr;
    switch (q.kind) {
    case O_BOX: {
        real best = REAL_INF;
        R3 n = r3(0, 0, 0);
        for (int i = 0; i < 3; i++) {
            real v = comp(x, i), dl = (real)fabs((double)(v - comp(f.lo, i))), dh = (real)fabs((double)(v - comp(f.hi, i)));
            if (dl < best) best = dl, n = r3(i == 0 ? -1 : 0, i == 1 ? -1 : 0, i == 2 ? -1 : 0);
            if (dh < best) best = dh, n = r3(i == 0 ? 1 : 0, i == 1 ? 1 : 0, i == 2 ? 1 : 0);
        }
        return n;
    }
    case P_ELLIPSOID: return x - q.p;
    case P_ECYLINDER:
    case O_ROD:
    case O_CONE: {
        R3 v = x - q.p;
        real s = dot(v, q.n);
        R3 perp = v - q.n * s;
        if (q.kind == P_ECYLINDER) return perp;
        real r = q.kind == O_CONE ? q.r + f.k * s : q.r, k = q.kind == O_CONE ? f.k : 0;
        // distance to the side along its normal, against the caps'
        real side = ((real)sqrt((double)dot(perp, perp)) - r) / (real)sqrt((double)(1 + k * k));
        side = (real)fabs((double)side);
        real c0 = (real)fabs((double)s), c1 = (real)fabs((double)(s - f.h));
        if (c0 <= c1 && c0 < side) return q.n * (real)-1;
        if (c1 < c0 && c1 < side) return q.n;
        R3 n = unit(perp) - q.n * k;
        return dot(n, n) > 0 ? n : q.n * (real)(s < f.h / 2 ? -1 : 1);
    }
    default: {  // torus: away from the nearest point of the tube's centre line
        R3 v = x - q.p;
        R3 rho = v - q.n * dot(v, q.n);
        real l = (real)sqrt((double)dot(rho, rho));
        return l > 0 ? v - rho * (q.r / l) : q.n * (real)(dot(v, q.n) < 0 ? -1 : 1);
    }
    }
}

// Outward unit normal of the primitive at point x on its surface.
R3 prim_normal(const Prim &q, R3 x) {
    switch (q.kind) {
    case O_SPHERE: return unit(x - q.p);
    case O_PLANE: return q.n;
    case O_CYLINDER: {
        R3 v = x - q.p;
        return unit(v - q.n * dot(v, q.n));
    }
    default: return normal_world(*q.fr, framed_normal(q, to_local(*q.fr, x)));
    }
}

// =============================================================================================
// [SECTION] 9 CSG status-tree sweep (the brute-force reference, thesis 3.4)
// =============================================================================================
// Along a ray every primitive contributes its status at the start and its crossings. Every node
// keeps a count of children inside; crossings are swept in increasing t, and a status change
// propagates up only while a node's status changes. The root changing is a visible surface.
struct Cross {
    real t;
    int prim;
    int enter;
};

// Image sequences (10b): while a pixel is traced, the regions of space its rays cross are set in
// its record: bits over the cells of a grid over the scene's finite parts (and where they go),
// and bit 0 for all space outside the grid's box.
// A frame's records lie interleaved: word i of the records of COH_BLOCK units in a row (so that
// the next frame reads the words it needs only, a block of units after another), and a unit's
// record is written there while its rays are traced, word i at i * COH_BLOCK (coh_word).
const size_t COH_BLOCK = 32;
struct RegionGrid {
    double lo[3], hi[3], h[3];  // the box, and the sides of a cell
    double inv[3];              // 1 / h
    int n, base;                // cells along each axis; the bit of the first
};
struct Regions {
    RegionGrid g;
    int words;        // unsigned words of a record
    double round[3];  // what rounding may move a ray's point by, at most (coh_mark)
};

struct Counters {
    double rays[4];  // primary, shadow, reflected, refracted
    double tests;
    double steps, moves, set_in, set_out, checks, frozen;
    double lbuf;  // shadow rays answered by a light buffer
    double ebuf;  // primary rays answered by the eye's buffer
    double cache; // shadow rays answered by the shadow cache
    double notes, cells;  // image sequences: rays and region cells noted in records (10b)
};
enum { RAY_PRIMARY, RAY_SHADOW, RAY_REFLECT, RAY_REFRACT };

struct Span {
    real t0, t1;
    unsigned stamp;  // the ray it belongs to
    int kind;
};

// An intersection as one solid along the ray (eval_list's plain evaluation, eval_flat).
struct Hull {
    real t0, t1;  // its latest entry and earliest exit so far
    int prim;     // the member entered last, -1: none yet
    int enter;    // 0: that member is a half-space turned inside out (the ray leaves the half-space)
    int tie;      // two members entered at that same t
    int need, have;  // the flat sweep: its members, and those the ray is in
    int fixed;    // its node's status is fixed for the ray: 1 outside, 2 inside (plan_fixed)
};

// The shadow cache's voxel for a light (shadow_probe): a voxel of the grid, or of a grid nested
// in it, as its box within the voxels above it, and its list; list -1: none.
struct Blocker {
    real lo[3], hi[3];
    int list;
};

struct Scratch {
    Cross *cross;
    Hull *hull;  // per solid of a list with a plan (at most one per node)
    unsigned char *pstat, *nstat, *nfirst;
    int *cnt;
    Counters k;
    // per ray, stamped with the ray number (thesis 3.5: no explicit unfreezing)
    unsigned ray;
    Span *span;                     // per primitive: its interval along the ray, once per ray
    real *span2;                    // per primitive: a torus' second interval (NULL without tori)
    unsigned *nfrozen;              // frozen for this ray: an ancestor's status is fixed
    unsigned *nfixed;               // status known for the rest of this ray ...
    unsigned char *nfixval;         // ... and its value
    int root_fixed;                 // the root's status cannot change any more on this ray
    Blocker *blocker;               // per light: the shadow cache's voxel (shadow_probe)
    // image sequences (10b): the record of the pixel being traced (NULL: none kept) and its regions
    unsigned *rbits;
    const struct Regions *rg;
};

// Empty the shadow cache. Each band of the image starts with it empty, so that what the cache
// does (and so the statistics) does not depend on which thread rendered the band before.
void shadow_cache_clear(const Scene *s, Scratch *w) {
    for (int i = 0; i < s->lights.n; i++) w->blocker[i].list = -1;
}

// What threads write all the time stays off the cache lines of other threads' data: every
// per-thread block gets this much slack behind it.
const size_t LINE_SLACK = 128;

void *thread_alloc(pray_ctx *c, size_t n) { return mem_zalloc(c, n + LINE_SLACK); }

bool scratch_init(pray_ctx *c, Scratch *w, const Scene *s) {
    memset(w, 0, sizeof *w);
    size_t np = (size_t)s->prims.n + 1, nn = (size_t)s->nodes.n + 1;
    w->cross = (Cross *)thread_alloc(c, sizeof(Cross) * 2 * (np + (size_t)s->tori));
    if (s->tori) w->span2 = (real *)thread_alloc(c, sizeof(real) * 2 * np);
    w->hull = (Hull *)thread_alloc(c, sizeof(Hull) * nn);
    w->pstat = (unsigned char *)thread_alloc(c, np);
    w->nstat = (unsigned char *)thread_alloc(c, nn);
    w->nfirst = (unsigned char *)thread_alloc(c, nn);
    w->cnt = (int *)thread_alloc(c, sizeof(int) * nn);
    w->span = (Span *)thread_alloc(c, sizeof(Span) * np);
    w->nfrozen = (unsigned *)thread_alloc(c, sizeof(unsigned) * nn);
    w->nfixed = (unsigned *)thread_alloc(c, sizeof(unsigned) * nn);
    w->nfixval = (unsigned char *)thread_alloc(c, nn);
    w->blocker = (Blocker *)thread_alloc(c, sizeof(Blocker) * (size_t)(s->lights.n + 1));
    if (w->blocker) shadow_cache_clear(s, w);
    return w->blocker && w->cross && (w->span2 || !s->tori) && w->hull && w->pstat && w->nstat && w->nfirst && w->cnt && w->span &&
           w->nfrozen && w->nfixed && w->nfixval;
}

void scratch_release(pray_ctx *c, Scratch *w) {
    mem_free(c, w->span);
    mem_free(c, w->span2);
    mem_free(c, w->nfrozen);
    mem_free(c, w->nfixed);
    mem_free(c, w->nfixval);
    mem_free(c, w->blocker);
    mem_free(c, w->cross);
    mem_free(c, w->hull);
    mem_free(c, w->pstat);
    mem_free(c, w->nstat);
    mem_free(c, w->nfirst);
    mem_free(c, w->cnt);
}

inline bool node_status(const Node &nd, int cnt, int first) {
    switch (nd.op) {
    case O_UNION: return cnt > 0;
    case O_INTER: return cnt == nd.n;
    case O_DIFF: return first && cnt == 0;
    default: return cnt == 0;  // complement
    }
}

// Element `e` changed to status `st`: update the counts upwards while statuses change. Returns
// true when the root's status changed. (Parts folded away during flattening have no parent and
// are not the root: they change nothing.)
bool propagate(const Scene *s, Scratch *w, int e, bool st) {
    for (;;) {
        int p;
        bool first;
        if (e_is_node(e)) {
            p = s->nodes[e_index(e)].parent;
            first = s->nodes[e_index(e)].first != 0;
        } else {
            p = s->prims[e_index(e)].parent;
            first = s->prims[e_index(e)].first != 0;
        }
        if (p < 0) return e == s->root;
        const Node &nd = s->nodes[p];
        bool old = w->nstat[p] != 0;
        if (first && nd.op == O_DIFF) w->nfirst[p] = st;
        else w->cnt[p] += st ? 1 : -1;
        bool now = node_status(nd, w->cnt[p], w->nfirst[p]);
        if (now == old) return false;
        w->nstat[p] = now;
        st = now;
        e = 2 * p + 1;
    }
}

int cross_cmp(const void *pa, const void *pb) {
    const Cross *a = (const Cross *)pa, *b = (const Cross *)pb;
    if (a->t < b->t) return -1;
    if (a->t > b->t) return 1;
    if (a->prim != b->prim) return a->prim < b->prim ? -1 : 1;
    return b->enter - a->enter;
}

// Sort crossings by cross_cmp: insertion sort for the few crossings of most sweeps.
void sort_crossings(Cross *x, int n) {
    if (n > 16) {
        qsort(x, (size_t)n, sizeof(Cross), cross_cmp);
        return;
    }
    for (int i = 1; i < n; i++) {
        Cross v = x[i];
        int j = i;
        for (; j > 0 && cross_cmp(&v, &x[j - 1]) < 0; j--) x[j] = x[j - 1];
        x[j] = v;
    }
}

struct Hit {
    real t;
    int prim;
    int mat;   // the primitive whose model shades the surface: prim, or on a face between two
               // materials inside the solid (language 12) the one whose material is entered
    int from;  // on such a face, the primitive whose material the ray leaves; else -1
    unsigned char prim_enter;  // the ray enters the primitive there
    unsigned char root_enter;  // the ray enters the whole solid there (1 too on a face between materials)
};

// A hit where the whole solid is entered or left: shaded with the primitive's own model.
inline Hit solid_hit(real t, int prim, int prim_enter, bool root_enter) {
    Hit h;
    h.t = t;
    h.prim = h.mat = prim;
    h.prim_enter = (unsigned char)prim_enter;
    h.root_enter = root_enter;
    h.from = -1;
    return h;
}

// The primitive whose material fills the solid where the ray is, the root being inside
// (language 12): in a union the last child the ray is in, in an intersection its last child
// that is not a complement, in a difference its first; -1 in a complement (no primitive puts
// the point there). Reads the statuses of a full sweep (section 9).
int owner(const Scene *s, const Scratch *w) {
    int e = s->root;
    while (e_is_node(e)) {
        const Node &nd = s->nodes[e_index(e)];
        const int *k = &s->kids[nd.k0];
        int i = nd.op == O_UNION ? nd.n - 1 : fill_child(s, nd);
        if (nd.op == O_UNION)
            for (; i >= 0; i--)
                if (e_is_node(k[i]) ? w->nstat[e_index(k[i])] : w->pstat[e_index(k[i])]) break;
        if (i < 0) return -1;
        e = k[i];
    }
    return e_index(e);
}

// owner in the region of a list with materials (9b).
int owner_mixed(const Scene *s, const Scratch *w, const int *d);

// A crossing of a primitive at t, when t is in (a, b] and before tmax: noted for a sweep
// (`prim`: the primitive, or its place in a list with a plan, 9b).
inline void add_cross(Scratch *w, int *nc, real t, int prim, int enter, real a, real b, real tmax) {
    if (!(t > a && t <= b && t < tmax)) return;
    Cross &x = w->cross[(*nc)++];
    x.t = t;
    x.prim = prim;
    x.enter = enter;
}

int elem_parent(const Scene *s, int e) {
    return e_is_node(e) ? s->nodes[e_index(e)].parent : s->prims[e_index(e)].parent;
}
bool elem_first(const Scene *s, int e) {
    return (e_is_node(e) ? s->nodes[e_index(e)].first : s->prims[e_index(e)].first) != 0;
}

// Element e is inside: count it in its parent (bump, 9b: unless the parent's status is fixed).
inline void tally(const Scene *s, Scratch *w, int e) {
    int p = elem_parent(s, e);
    if (p < 0) return;
    if (elem_first(s, e) && s->nodes[p].op == O_DIFF) w->nfirst[p] = 1;
    else w->cnt[p]++;
}

// Primitive p's status just after a, from its span (kind; t: its ends, a torus' second
// interval after them), counted in its parent when inside; its crossings in (a, b] before tmax
// are noted.
inline void prim_at(const Scene *s, Scratch *w, int p, int kind, const real *t, real a, real b, real tmax, int *nc) {
    bool in = kind == SPAN_ALL;
    for (int j = 0; (kind == SPAN || kind == SPAN2) && j < (kind == SPAN2 ? 4 : 2); j += 2) {
        in = in || (t[j] <= a && a < t[j + 1]);
        add_cross(w, nc, t[j], p, 1, a, b, tmax);
        add_cross(w, nc, t[j + 1], p, 0, a, b, tmax);
    }
    w->pstat[p] = in;
    if (in) tally(s, w, 2 * p);
}

// The start of a sweep: the status of every primitive and node at the start of the ray (just
// after it, for a start on a surface) into w, and the crossings in (0, tmax) into w->cross
// (*ncross of them, unsorted). Returns the root's status. The root must be an element.
bool sweep_start(const Scene *s, Scratch *w, const Ray &ray, real tmax, int self, int *ncross) {
    int nc = 0;
    int np = s->prims.n;
    for (int j = 0; j < s->nodes.n; j++) w->cnt[j] = 0, w->nfirst[j] = 0;
    for (int i = 0; i < np; i++) {
        real t[4] = {0, 0, 0, 0};
        w->k.tests += 1;
        int k = prim_span(s->prims[i], ray, twin(s, i, self), &t[0], &t[1], &t[2]);
        prim_at(s, w, i, k, t, 0, REAL_INF, tmax, &nc);
    }
    for (int j = 0; j < s->nodes.n; j++) {
        w->nstat[j] = node_status(s->nodes[j], w->cnt[j], w->nfirst[j]);
        if (w->nstat[j]) tally(s, w, 2 * j + 1);
    }
    *ncross = nc;
    return e_is_node(s->root) ? w->nstat[e_index(s->root)] != 0 : w->pstat[e_index(s->root)] != 0;
}

// Is the start of the ray inside the solid? Exact, as every sweep begins: one test per primitive.
bool starts_inside(const Scene *s, Scratch *w, const Ray &ray) {
    int nc;
    if (s->root < 0) return s->root == E_ALL;
    // a point outside the solid's box is outside the solid (a parallel camera's rays, mostly)
    const Box &b = elem_box(s, s->root);
    real o[3] = {ray.o.x, ray.o.y, ray.o.z};
    for (int l = 0; l < 3; l++)
        if (o[l] < b.lo[l] || o[l] > b.hi[l]) return false;
    return sweep_start(s, w, ray, 0, -1, &nc);
}

Ray camera_ray(const Scene *s, real u, real v);

// May a primary ray of the render start inside the solid? Any point of a parallel camera's
// window in the solid's box; a perspective camera's eye inside it along the view or along one of
// the window's corners (starts_inside: an eye on a face has the solid on one side of it, which
// holds a corner's ray if it holds any of the image's). -1 when out of memory.
int primaries_inside(pray_ctx *c, const Scene *s) {
    if (s->root < 0) return s->root == E_ALL;
    const Box &b = elem_box(s, s->root);
    for (int l = 0; s->parallel && l < 3; l++) {
        real e = comp(s->eye, l), r = (real)(fabs(comp(s->cx, l)) + fabs(comp(s->cy, l)));
        if (e + r < b.lo[l] || e - r > b.hi[l]) return 0;
    }
    if (s->parallel) return 1;
    Scratch w;
    int in = scratch_init(c, &w, s) ? 0 : -1;
    for (int k = 0; k < 5 && in == 0; k++) {  // (the window's four corners, then its centre)
        real u = k < 4 ? (real)(k & 1 ? 1 : -1) : 0, v = k < 4 ? (real)(k & 2 ? 1 : -1) : 0;
        in = starts_inside(s, &w, camera_ray(s, u, v));
    }
    scratch_release(c, &w);
    return in;
}

// The face where materials meet at the crossings [g0, g1) of a sweep, all at one t, the ray
// going from the material of primitive `was` into that of `mat`: the last crossing whose status
// its primitive took and that changed its parent's status (CROSS_MOVED) or is a face of `was`
// or `mat`. (A crossing that changes nothing above it is no face of the solid there; so a
// list's region, which leaves out what is under a node outside, takes the same one.)
const int CROSS_MOVED = 2;  // a flag of Cross::enter, set by sweep_crossings

int face_of(const Scratch *w, int g0, int g1, int was, int mat) {
    for (int k = g1 - 1; k >= g0; k--) {
        const Cross &x = w->cross[k];
        if ((w->pstat[x.prim] != 0) == ((x.enter & 1) != 0) && ((x.enter & CROSS_MOVED) || x.prim == was || x.prim == mat))
            return k;
    }
    return g0;
}

// The crossings w->cross[0, nc) in order, from the statuses at their start (the root's: `root`):
// each change of the root's status is a hit, and where materials meet (Scene::iface) each change
// of the material the ray is in while inside (owner, or owner_mixed in list `mixed`) is a hit
// on a face between two materials. Counts the hits visited in *hits; true when `visit` stopped.
// The reference's and the lists with materials' (eval_mixed, 9b) one loop.
template <class Visit>
bool sweep_crossings(const Scene *s, Scratch *w, int nc, bool root, Visit &visit, int *hits, const int *mixed = NULL) {
    if (nc > 1) sort_crossings(w->cross, nc);
    int mat = !s->iface || !root ? -1 : mixed ? owner_mixed(s, w, mixed) : owner(s, w);
    for (int i = 0; i < nc;) {
        real t = w->cross[i].t;
        bool before = root;
        int last = -1, moved = -1, g0 = i;
        for (; i < nc && w->cross[i].t == t; i++) {
            Cross &x = w->cross[i];
            bool st = x.enter != 0;
            if ((w->pstat[x.prim] != 0) == st) continue;
            w->pstat[x.prim] = st;
            moved = i;
            int p = s->prims[x.prim].parent;
            bool was_in = p >= 0 && w->nstat[p];
            if (propagate(s, w, 2 * x.prim, st)) {
                root = !root;
                last = i;
            }
            if (p < 0 || (w->nstat[p] != 0) != was_in) x.enter |= CROSS_MOVED;
        }
        if (root != before && last >= 0) {
            ++*hits;
            if (!visit(solid_hit(t, w->cross[last].prim, w->cross[last].enter & 1, root))) return true;
        }
        if (!s->iface || moved < 0) continue;
        int was = mat;
        mat = !root ? -1 : mixed ? owner_mixed(s, w, mixed) : owner(s, w);
        if (root && before && was >= 0 && mat >= 0 && other_material(s, was, mat)) {
            // a face between two materials inside the solid: a surface of the one entered
            const Cross &x = w->cross[face_of(w, g0, i, was, mat)];
            Hit h = solid_hit(t, x.prim, x.enter & 1, true);
            h.mat = mat;
            h.from = was;
            ++*hits;
            if (!visit(h)) return true;
        }
    }
    return false;
}

// Visit the visible surfaces along the ray in (0, tmax) in order; `visit` returns false to stop.
// Returns the number of hits visited.
template <class Visit>
int sweep(const Scene *s, Scratch *w, const Ray &ray, real tmax, int self, Visit &visit) {
    if (s->root < 0) return 0;
    int nc = 0, hits = 0;
    bool root = sweep_start(s, w, ray, tmax, self, &nc);
    sweep_crossings(s, w, nc, root, visit, &hits);
    return hits;
}

struct FirstHit {
    Hit h;
    bool found;
    bool operator()(const Hit &x) {
        h = x;
        found = true;
        return false;
    }
};

// Transmission along a shadow ray: the product of the transmit weights of every surface
// crossed, each of the material it shows (Hit::mat: on a face between two materials, the one
// entered, as for any ray); stops at the first opaque one, at t.
pray_rgb transmit_at(const Scene *s, const Ray &ray, const Hit &x);

struct ShadowHit {
    const Scene *s;
    const Ray *ray;
    pray_rgb f;
    real t;
    bool operator()(const Hit &x) {
        f = cmul(f, transmit_at(s, *ray, x));
        if (!czero(f)) return true;
        t = x.t;
        return false;
    }
};

// Where a visitor stopped its ray (image sequences, 10b): at its hit, or nowhere.
inline real visit_end(const FirstHit &v) { return v.found ? v.h.t : REAL_INF; }
inline real visit_end(const ShadowHit &v) { return czero(v.f) ? v.t : REAL_INF; }
template <class Visit>
inline real visit_end(const Visit &) { return REAL_INF; }

// =============================================================================================
// [SECTION] 9b Acceleration: action lists, uniform grid, traversal, freezing, areas (3.3-3.6)
// =============================================================================================
// Building (once per scene) and tracing (per ray) are apart:
//   [9b.1] The structure: classes, action lists, the grid, light buffers; lookups both use
//   [9b.2] Building: action lists, plans, the region-to-list builder
//   [9b.3] Building: the grid, areas and jumps
//   [9b.4] Building: light buffers and the eye's buffer
//   [9b.5] Building: the whole structure (accel_build)
//   [9b.6] Per ray: list evaluation with freezing (the one list evaluator)
//   [9b.7] Per ray: stretch sources (grid walk, light buffer voxel, eye buffer cell)
//   [9b.8] Per ray: the ray driver, the shadow cache, the entry points
// ---- [9b.1] The structure: classes, action lists, the grid, light buffers; lookups both use ----
// Classes of a node against a region of space (thesis 3.4).
enum { CL_OUT = 0, CL_IN = 1, CL_BD = 2 };

// One face of a light buffer: cells in (u, v), slabs in depth w. A directional light has one,
// whose frame has e[2] towards the light: u, v, w are a point's coordinates in the frame, and a
// zone runs from its slab to the buffer's end (`top`). A point light has six, one per axis and
// sign, e[2] pointing away from the light: w is the distance along e[2], u and v the
// coordinates along e[0], e[1] over w; a zone is the cell's pyramid from the light to the end
// of its slab.
struct LightFace {
    R3 e[3];
    real lo[3], h[3], inv[3];  // the grid: the low corner, the sides and their reciprocals
    int n[3];                  // cells along u, v; slabs (0: a face without voxels)
    int base;                  // the face's first voxel in LightBuf::list
    int cbase;                 // the eye's buffer: the face's first cell in LightBuf::runs
};

// The eye's buffer (option eyebuffer) is a point light's buffer at the perspective camera's eye
// whose voxels keep the list of their own piece of the cell, between the slab's two depths: a
// primary ray stays in one cell and walks its slabs outwards.
struct LightBuf {
    int point, faces;
    int pieces;                // 1: the eye's buffer
    R3 o;                      // the light's position (a point light), or the eye
    real top;                  // a directional light: w where the zones end, past the grid
    LightFace f[6];
    int *list;                 // per voxel: its list; -1: the ray walks the grid
    // The eye's buffer: per cell, where its runs start (and, after the last cell, where they
    // end); then the runs, each a list and the slab where it ends, in order from the eye. A cell
    // whose primary rays walk the grid has one run of list -1.
    int *runs, nruns;
};

// An action list, stored in Accel::data at off[L]:
//   [na, np, set_inside, set_outside, 0, na x (node, count, first), np x primitive]
// The active nodes are listed children first; `count` and `first` are the node's children that
// are constant in the region, summed up: the thesis' "set inside" / "set outside" actions of
// one node done at once. Then the "check" actions: the active primitives. List 0 is the empty
// list of a region where the root is constant, so nothing can be hit there.
// A list with materials (lb_mixed: two materials may meet in the region, language 12) has its
// length as fifth number, and after the primitives its materials' part, which eval_mixed
// evaluates as the reference does:
//   [na, na x (node, count, first, children), the children's lists]
// Every node the region touches is listed, children first, but what is under a node outside
// there; `count` and `first` sum up its children that are inside and not to be checked; at
// `children` (from the part's start) its children to check, in the order owner_mixed reads
// them (lb_mixed_list). Where the root is inside throughout, the list before that part is
// empty.
const int LIST_HEAD = 5;  // the numbers before the nodes
inline const int *list_prims(const int *d) { return d + LIST_HEAD + 3 * d[0]; }
inline int list_len(const int *d) { return d[4] ? d[4] : LIST_HEAD + 3 * d[0] + d[1]; }

// A uniform grid of cubic voxels. A voxel that holds many primitives to check has a grid of its
// own, nested in it (Accel::nested), whose voxels are classed in turn: fine where the scene is
// crowded, coarse where it is empty.
struct Grid {
    int n[3];          // voxels per axis; all 0 without a grid
    real org[3], h;    // low corner of the grid and side of a voxel
    real top[3];       // high corner of the grid
    real inv_h;        // 1 / h
    int *voxel;        // per voxel, x fastest: its list; -1 - g: the nested grid g
    unsigned char *reach;  // per voxel: how far around it every voxel has its list (see reach_build)
    int rest;          // a nested grid: the list of its voxel outside the grid's box
};

struct Accel {
    Grid g;            // the grid over the scene
    Array<Grid> nested;
    Array<int> data, off;
    Array<int> plan_at;  // per list: where its plan starts in `plan`, -1 when it has none (list_plan)
    Array<int> plan;
    int outer;         // list of the space outside the grid (everything without a grid)
    int freeze, merge, bounds;
    int mixed;              // some list has materials (LIST_HEAD)
    // The lists find faces between materials (lb_mixed); a render's leave them out (left_out, where
    // two may meet) when none of its rays can be inside the solid (accel_build).
    int faces, left_out;
    int cache;              // option shadowcache
    LightBuf *lbuf;         // per light, then the eye's; or NULL (options lightbuffer, eyebuffer)
    int nlbuf;              // the lights'
    const LightBuf *eye;    // &lbuf[nlbuf] when the eye has a buffer
    long areas;
    double memory;
};

void accel_release(pray_ctx *c, Accel *a) {
    if (!a) return;
    for (int i = -1; i < a->nested.n; i++) {
        mem_free(c, (i < 0 ? a->g : a->nested[i]).voxel);
        mem_free(c, (i < 0 ? a->g : a->nested[i]).reach);
    }
    a->nested.release(c);
    a->data.release(c);
    a->off.release(c);
    a->plan_at.release(c);
    a->plan.release(c);
    for (int i = 0; a->lbuf && i <= a->nlbuf; i++) {
        mem_free(c, a->lbuf[i].list);
        mem_free(c, a->lbuf[i].runs);
    }
    mem_free(c, a->lbuf);
    mem_free(c, a);
}

// The voxel that holds the point: its coordinates in ix; false when it is outside the grid.
bool voxel_of(const Grid &G, R3 p, int *ix) {
    for (int l = 0; l < 3; l++) {
        real g = (comp(p, l) - G.org[l]) * G.inv_h;
        if (!(g >= 0 && g < (real)G.n[l])) return false;
        ix[l] = (int)g;
    }
    return true;
}
inline long voxel_index(const Grid &G, const int *ix) { return ((long)ix[2] * G.n[1] + ix[1]) * G.n[0] + ix[0]; }

// The box of the voxels from i0 to i1 - 1 along each axis, widened by the margin.
void voxels_box(const Grid &G, const int *i0, const int *i1, double margin, real *lo, real *hi) {
    for (int l = 0; l < 3; l++) {
        lo[l] = (real)((double)G.org[l] + i0[l] * (double)G.h - margin);
        hi[l] = (real)((double)G.org[l] + i1[l] * (double)G.h + margin);
    }
}

// The face of a point light's buffer that holds direction m (from the light): its largest
// component's axis and sign.
inline int cube_face(R3 m) {
    real ax = m.x < 0 ? -m.x : m.x, ay = m.y < 0 ? -m.y : m.y, az = m.z < 0 ? -m.z : m.z;
    int a = ax >= ay && ax >= az ? 0 : ay >= az ? 1 : 2;
    return 2 * a + (comp(m, a) < 0);
}

// A point light's zones (and the eye's) are widened by this share of a cell, and a point is
// looked up in the cells widened by as much: so a point rounded just past a cell's edge (u = 1
// in one face, -1 in the next) still belongs to the cell it is given.
const real CELL_SLACK = (real)0.25;

// The cell of face F at (u, v) (a point light's u and v are over w), the face's cells widened
// by `slack` cells and clamped: 1 and *cell set; 0 when (u, v) is beside the cells; -1 when not
// a number.
inline int face_cell(const LightFace &F, real u, real v, real slack, int *cell) {
    real g[2] = {u, v};
    int i[2];
    for (int l = 0; l < 2; l++) {
        real k = (g[l] - F.lo[l]) * F.inv[l];
        if (k != k) return -1;
        if (!(k >= -slack && k < (real)F.n[l] + slack)) return 0;
        i[l] = k < 0 ? 0 : k < (real)F.n[l] ? (int)k : F.n[l] - 1;
    }
    *cell = i[1] * F.n[0] + i[0];
    return 1;
}

// ---- [9b.2] Building: action lists, plans, the region-to-list builder ----
int classify_framed(const Prim &q, const real *lo, const real *hi);

// Class of a primitive against a closed box.
int classify_prim(const Prim &q, const real *lo, const real *hi) {
    real cen[3], half[3];
    for (int i = 0; i < 3; i++) {
        cen[i] = (lo[i] + hi[i]) / 2;
        half[i] = (hi[i] - lo[i]) / 2;
    }
    R3 c = r3(cen[0], cen[1], cen[2]);
    switch (q.kind) {
    default: return classify_framed(q, lo, hi);
    case O_SPHERE: {
        real near2 = 0, far2 = 0;
        for (int i = 0; i < 3; i++) {
            real d = (real)fabs((double)(cen[i] - comp(q.p, i)));
            real dn = d - half[i] > 0 ? d - half[i] : 0, df = d + half[i];
            near2 += dn * dn;
            far2 += df * df;
        }
        if (near2 > q.r2) return CL_OUT;
        if (far2 < q.r2) return CL_IN;
        return CL_BD;
    }
    case O_PLANE: {
        real sc = dot(q.n, c) - q.d;
        real rad = (real)fabs((double)q.n.x) * half[0] + (real)fabs((double)q.n.y) * half[1] +
                   (real)fabs((double)q.n.z) * half[2];
        if (sc - rad > 0) return CL_OUT;
        if (sc + rad < 0) return CL_IN;
        return CL_BD;
    }
    case O_CYLINDER: {  // exact inside (convex: all corners), conservative outside
        bool all_in = true;
        for (int k = 0; k < 8 && all_in; k++) {
            R3 x = r3(k & 1 ? hi[0] : lo[0], k & 2 ? hi[1] : lo[1], k & 4 ? hi[2] : lo[2]) - q.p;
            R3 perp = x - q.n * dot(x, q.n);
            all_in = dot(perp, perp) < q.r2;
        }
        if (all_in) return CL_IN;
        R3 x = c - q.p;
        R3 perp = x - q.n * dot(x, q.n);
        real rad = (real)sqrt((double)(half[0] * half[0] + half[1] * half[1] + half[2] * half[2]));
        real dist = (real)sqrt((double)dot(perp, perp));
        if (dist > q.r + rad) return CL_OUT;
        return CL_BD;
    }
    }
}

// Class of a primitive in a frame against a closed box: outside when clear of its bounds,
// inside when it is convex and holds every corner.
int classify_framed(const Prim &q, const real *lo, const real *hi) {
    for (int i = 0; i < 3; i++)
        if (hi[i] < q.box.lo[i] || q.box.hi[i] < lo[i]) return CL_OUT;
    for (int k = 0; k < 8; k++)
        if (!framed_inside(q, r3(k & 1 ? hi[0] : lo[0], k & 2 ? hi[1] : lo[1], k & 4 ? hi[2] : lo[2]))) return CL_BD;
    return CL_IN;
}

// Builds action lists from the classes of the primitives a region touches; all others are
// outside there. Bottom-up over the touched nodes, then top-down over the active part.
struct ListBuilder {
    pray_ctx *c;
    const Scene *s;
    Accel *a;
    unsigned char *dflt;   // class of each element when all primitives are outside, by code
    int *pos;              // position of each element among its parent's children, by code
    int *base_in;          // per node: children inside by default (a difference: not its first)
    unsigned stamp, *mark; // per node: touched in the current region
    int *acc_in, *acc_bd;  // per node: children inside / on the boundary
    unsigned char *first_cls, *cls;  // per node: class of the first child; class (by code)
    int *head, *next;      // per node: touched children (a list through `next`, by code)
    Array<int> touched, out, hash, mix;
    Array<int> rprims;           // lb_region: the region's primitives ...
    Array<unsigned char> rcls;   // ... and their classes there
    real rlo[3], rhi[3], rbox;   // the region's box, for lb_mixed (rbox 0: not a box)
    const Box *obox;             // per primitive, where it may fill the solid (lb_mixed)
};

int node_class(const Node &nd, int in, int bd, int first) {
    switch (nd.op) {
    case O_UNION: return in > 0 ? CL_IN : bd > 0 ? CL_BD : CL_OUT;
    case O_INTER: return in + bd < nd.n ? CL_OUT : bd > 0 ? CL_BD : CL_IN;
    case O_DIFF:
        if (first == CL_OUT || in > 0) return CL_OUT;
        return first == CL_IN && bd == 0 ? CL_IN : CL_BD;
    default: return first == CL_BD ? CL_BD : first == CL_IN ? CL_OUT : CL_IN;  // complement
    }
}

bool lb_init(ListBuilder &b, pray_ctx *c, const Scene *s, Accel *a) {
    memset(&b, 0, sizeof b);
    b.c = c;
    b.s = s;
    b.a = a;
    size_t ne = 2 * (size_t)(s->prims.n > s->nodes.n ? s->prims.n : s->nodes.n) + 2, nn = (size_t)s->nodes.n + 1;
    b.dflt = (unsigned char *)mem_zalloc(c, ne);
    b.pos = (int *)mem_zalloc(c, sizeof(int) * ne);
    b.cls = (unsigned char *)mem_zalloc(c, ne);
    b.next = (int *)mem_zalloc(c, sizeof(int) * ne);
    b.base_in = (int *)mem_zalloc(c, sizeof(int) * nn);
    b.mark = (unsigned *)mem_zalloc(c, sizeof(unsigned) * nn);
    b.acc_in = (int *)mem_zalloc(c, sizeof(int) * nn);
    b.acc_bd = (int *)mem_zalloc(c, sizeof(int) * nn);
    b.first_cls = (unsigned char *)mem_zalloc(c, nn);
    b.head = (int *)mem_zalloc(c, sizeof(int) * nn);
    b.touched.init();
    b.out.init();
    b.mix.init();
    b.hash.init();
    b.rprims.init();
    b.rcls.init();
    if (!b.dflt || !b.pos || !b.cls || !b.next || !b.base_in || !b.mark || !b.acc_in || !b.acc_bd || !b.first_cls || !b.head)
        return false;
    for (int j = 0; j < s->nodes.n; j++) {  // children before parents
        const Node &nd = s->nodes[j];
        int in = 0, first = CL_OUT;
        for (int i = 0; i < nd.n; i++) {
            int k = s->kids[nd.k0 + i];
            b.pos[k] = i;
            if (i == 0 && (nd.op == O_DIFF || nd.op == O_COMPL)) first = b.dflt[k];
            else in += b.dflt[k] == CL_IN;
        }
        b.base_in[j] = in;
        b.dflt[2 * j + 1] = (unsigned char)node_class(nd, in, 0, first);
    }
    return true;
}

void lb_release(ListBuilder &b) {
    pray_ctx *c = b.c;
    mem_free(c, b.dflt);
    mem_free(c, b.pos);
    mem_free(c, b.cls);
    mem_free(c, b.next);
    mem_free(c, b.base_in);
    mem_free(c, b.mark);
    mem_free(c, b.acc_in);
    mem_free(c, b.acc_bd);
    mem_free(c, b.first_cls);
    mem_free(c, b.head);
    b.touched.release(c);
    b.out.release(c);
    b.mix.release(c);
    b.hash.release(c);
    b.rprims.release(c);
    b.rcls.release(c);
}

int int_cmp(const void *pa, const void *pb) {
    int a = *(const int *)pa, b = *(const int *)pb;
    return a < b ? -1 : a > b;
}

// Record that element e has class cl in the current region.
void lb_contribute(ListBuilder &b, int e, int cl) {
    b.cls[e] = (unsigned char)cl;
    int p = elem_parent(b.s, e);
    if (p < 0) return;
    const Node &nd = b.s->nodes[p];
    b.next[e] = b.head[p];
    b.head[p] = e;
    if (elem_first(b.s, e) && (nd.op == O_DIFF || nd.op == O_COMPL)) b.first_cls[p] = (unsigned char)cl;
    else {
        b.acc_in[p] += (cl == CL_IN) - (b.dflt[e] == CL_IN);
        b.acc_bd[p] += cl == CL_BD;
    }
}

// Store the list in b.out (deduplicated); returns its number.
int lb_store(ListBuilder &b) {
    Accel *a = b.a;
    int n = b.out.n;
    unsigned h = 2166136261u;
    for (int i = 0; i < n; i++) h = (h ^ (unsigned)b.out[i]) * 16777619u;
    if (2 * (a->off.n + 1) > b.hash.n) {  // grow the table
        int size = b.hash.n ? 2 * b.hash.n : 1024;
        Array<int> nh;
        nh.init();
        if (!nh.reserve(b.c, size)) return -1;
        nh.n = size;
        memset(nh.p, 0, sizeof(int) * (size_t)size);
        for (int L = 1; L < a->off.n; L++) {
            const int *d = a->data.p + a->off[L];
            int len = list_len(d);
            unsigned g = 2166136261u;
            for (int i = 0; i < len; i++) g = (g ^ (unsigned)d[i]) * 16777619u;
            unsigned k = g & (unsigned)(size - 1);
            while (nh[(int)k]) k = (k + 1) & (unsigned)(size - 1);
            nh[(int)k] = L;
        }
        b.hash.release(b.c);
        b.hash = nh;
    }
    unsigned k = h & (unsigned)(b.hash.n - 1);
    for (; b.hash[(int)k]; k = (k + 1) & (unsigned)(b.hash.n - 1)) {
        int L = b.hash[(int)k];
        const int *d = a->data.p + a->off[L];
        if (list_len(d) == n && memcmp(d, b.out.p, sizeof(int) * (size_t)n) == 0) return L;
    }
    if (!a->off.push(b.c, a->data.n) || !a->data.reserve(b.c, a->data.n + n)) return -1;
    memcpy(a->data.p + a->data.n, b.out.p, sizeof(int) * (size_t)n);
    a->data.n += n;
    b.hash[(int)k] = a->off.n - 1;
    return a->off.n - 1;
}

// May primitive p fill the solid with its material somewhere in the region (lb_list has classed
// its ancestors there)? It must be able to (Prim::owns), and no ancestor may be outside there.
bool lb_owns(const ListBuilder &b, int p) {
    if (!b.s->prims[p].owns) return false;
    for (int j = b.s->prims[p].parent; j >= 0; j = b.s->nodes[j].parent)
        if (b.cls[2 * j + 1] == CL_OUT) return false;
    return true;
}

// Where materials meet (Scene::iface): may two primitives of the region that may fill the solid
// there (lb_owns), of different materials, meet in it? (Their boxes overlap within the region's,
// and they are not apart for certain; a region crowded past MIXED_PAIRS primitives that may is
// taken to be mixed, without trying every pair.) -1 when out of memory.
const int MIXED_PAIRS = 64;

int lb_mixed(ListBuilder &b, const int *prims, int n) {
    const Scene *s = b.s;
    Array<int> &own = b.mix;  // (lb_mixed_list fills it after)
    own.n = 0;
    for (int i = 0; i < n; i++)
        if (lb_owns(b, prims[i]) && !own.push(b.c, prims[i])) return -1;
    int m = 1;
    while (m < own.n && !other_material(s, own[0], own[m])) m++;
    if (m >= own.n) return 0;
    if (own.n > MIXED_PAIRS) return 1;
    for (int i = 0; i < own.n; i++)
        for (int j = i + 1; j < own.n; j++) {
            const Box &pb = b.obox[own[i]], &qb = b.obox[own[j]];
            bool meet = true;
            for (int l = 0; l < 3 && meet; l++) {
                real lo = pb.lo[l] > qb.lo[l] ? pb.lo[l] : qb.lo[l];
                real hi = pb.hi[l] < qb.hi[l] ? pb.hi[l] : qb.hi[l];
                if (b.rbox) lo = lo > b.rlo[l] ? lo : b.rlo[l], hi = hi < b.rhi[l] ? hi : b.rhi[l];
                meet = lo <= hi;
            }
            if (meet && other_material(s, own[i], own[j]) && !solids_apart(s->prims[own[i]], s->prims[own[j]])) return 1;
        }
    return 0;
}

// The materials' part of a region's list (see LIST_HEAD) into b.mix, once lb_list has classed
// the nodes it touches (b.touched, sorted: children first, the root last) and linked each one's
// touched children. What is under a node outside in the region decides nothing there and is
// left out; a primitive inside the whole region is counted in its parent, and named only where
// owner_mixed may stop at it. A node's children, in the order owner_mixed reads them: a union's
// by position from the last, an intersection's or a difference's the one that fills it first;
// each a listed node's 2 * entry + 1, a primitive to check 2 * index, one inside the whole
// region -2 - index, -1 a child not listed but inside anyway (through a complement). False when
// out of memory.
bool lb_mixed_list(ListBuilder &b) {
    const Scene *s = b.s;
    Array<int> &kept = b.out, &x = b.mix;  // (lb_active fills b.out after)
    kept.n = x.n = 0;
    bool ok = true;
    for (int i = b.touched.n - 1; i >= 0; i--) {  // (parents first)
        int q = s->nodes[b.touched[i]].parent;
        if (q >= 0 && b.cls[2 * q + 1] == CL_OUT) b.cls[2 * b.touched[i] + 1] = CL_OUT;
    }
    for (int i = 0; ok && i < b.touched.n; i++)
        if (b.cls[2 * b.touched[i] + 1] != CL_OUT) ok = kept.push(b.c, b.touched[i]);
    int na = kept.n;
    for (int i = 0; ok && i < 1 + 4 * na; i++) ok = x.push(b.c, 0);
    PRAY_ASSERT(!ok || kept[na - 1] == e_index(s->root));
    for (int i = 0; ok && i < na; i++) {
        int p = kept[i];
        const Node &nd = s->nodes[p];
        const int *kid = &s->kids[nd.k0];
        bool lead = nd.op == O_DIFF || nd.op == O_COMPL, first_touched = false;
        int cnt = nd.op == O_COMPL ? 0 : b.base_in[p], first = 0, at = x.n;
        int one = fill_child(s, nd), fill = one >= 0 ? kid[one] : -2;  // (-2: no element)
        ok = x.push(b.c, 0);
        for (int k = b.head[p]; ok && k >= 0; k = b.next[k]) {
            bool in_prim = !e_is_node(k) && b.cls[k] == CL_IN;
            if (k == kid[0] && lead) {
                first_touched = true;
                if (nd.op == O_DIFF) first = in_prim;
                else cnt = in_prim;
            } else cnt += in_prim - (b.dflt[k] == CL_IN);
            if (b.cls[k] != CL_OUT && (nd.op == O_UNION || !in_prim || k == fill)) ok = x.push(b.c, k);
        }
        if (!first_touched && nd.op == O_DIFF) first = b.dflt[kid[0]] == CL_IN;
        if (!first_touched && nd.op == O_COMPL) cnt = b.dflt[kid[0]] == CL_IN;
        bool fill_listed = false;  // (an intersection or a difference filled by an untouched child: -1)
        for (int k = at + 1; k < x.n; k++) fill_listed = fill_listed || x[k] == fill;
        if (ok && (nd.op == O_INTER || nd.op == O_DIFF) && !fill_listed) ok = x.push(b.c, -1);
        for (int j = 0; ok && nd.op == O_UNION && b.dflt[2 * p + 1] == CL_IN && j < nd.n; j++) {
            bool touched = false;  // (a union inside by default: rare, every child looked at)
            for (int k = b.head[p]; k >= 0 && !touched; k = b.next[k]) touched = k == kid[j];
            if (!touched && b.dflt[kid[j]] == CL_IN) ok = x.push(b.c, kid[j]);
        }
        int m = ok ? x.n - at - 1 : 0, *ch = x.p + at + 1;
        for (int j = 1; j < m; j++)  // (insertion sorts: a node's children in a region are few)
            for (int k = j; k > 0; k--) {
                bool before = nd.op == O_UNION ? b.pos[ch[k]] > b.pos[ch[k - 1]] : ch[k] == fill || ch[k] == -1;
                if (!before) break;
                int t = ch[k];
                ch[k] = ch[k - 1];
                ch[k - 1] = t;
            }
        for (int j = 0; j < m; j++) {
            int e = ch[j], key = e_index(e);
            if (e < 0) continue;
            const int *f = e_is_node(e) ? (const int *)bsearch(&key, kept.p, (size_t)na, sizeof(int), int_cmp) : NULL;
            ch[j] = e_is_node(e) ? (f ? 2 * (int)(f - kept.p) + 1 : -1) : b.cls[e] == CL_IN ? -2 - key : e;
        }
        x[at] = m;
        int *en = x.p + 1 + 4 * i;
        en[0] = p, en[1] = cnt, en[2] = first, en[3] = at;
    }
    if (ok) x[0] = na;
    return ok;
}

bool lb_active(ListBuilder &b);

// The list of a region, given the primitives it touches and their classes there.
int lb_list(ListBuilder &b, const int *prims, const unsigned char *classes, int n) {
    const Scene *s = b.s;
    b.stamp++;
    b.touched.n = 0;
    int root_cls = s->root >= 0 ? (int)b.dflt[s->root] : (int)CL_OUT;
    for (int i = 0; i < n; i++) {  // touch the ancestors
        for (int p = s->prims[prims[i]].parent; p >= 0 && b.mark[p] != b.stamp; p = s->nodes[p].parent) {
            b.mark[p] = b.stamp;
            b.acc_in[p] = b.base_in[p];
            b.acc_bd[p] = 0;
            b.head[p] = -1;
            const Node &nd = s->nodes[p];
            b.first_cls[p] = (nd.op == O_DIFF || nd.op == O_COMPL) ? b.dflt[s->kids[nd.k0]] : (unsigned char)CL_OUT;
            if (!b.touched.push(b.c, p)) return -1;
        }
    }
    for (int i = 0; i < n; i++) {
        int e = 2 * prims[i];
        lb_contribute(b, e, classes[i]);
        if (e == s->root) root_cls = classes[i];
    }
    if (b.touched.n > 1) qsort(b.touched.p, (size_t)b.touched.n, sizeof(int), int_cmp);
    for (int i = 0; i < b.touched.n; i++) {
        int p = b.touched[i];
        int cl = node_class(s->nodes[p], b.acc_in[p], b.acc_bd[p], b.first_cls[p]);
        lb_contribute(b, 2 * p + 1, cl);
        if (2 * p + 1 == s->root) root_cls = cl;
    }
    int mixed = root_cls != CL_OUT && b.a->faces ? lb_mixed(b, prims, n) : 0;
    if (mixed < 0 || (mixed && !lb_mixed_list(b))) return -1;
    if (!mixed && root_cls != CL_BD) return 0;
    if (root_cls != CL_BD) {  // (inside throughout: nothing to check but the materials)
        b.out.n = 0;
        for (int i = 0; i < LIST_HEAD; i++)
            if (!b.out.push(b.c, 0)) return -1;
    } else if (!lb_active(b))
        return -1;
    for (int i = 0; mixed && i < b.mix.n; i++)
        if (!b.out.push(b.c, b.mix[i])) return -1;
    if (mixed) b.out[4] = b.out.n, b.a->mixed = 1;
    return lb_store(b);
}

// The list of the region lb_list has classed into b.out: the active part, boundary nodes reached
// from the root through boundary nodes.
bool lb_active(ListBuilder &b) {
    const Scene *s = b.s;
    b.out.n = 0;
    int h[LIST_HEAD] = {0, 0, 0, 0, 0};  // na, np, set inside, set outside, 0
    for (int i = 0; i < LIST_HEAD; i++)
        if (!b.out.push(b.c, 0)) return false;
    Array<int> &stk = b.touched;  // reused: the touched nodes are done with
    stk.n = 0;
    if (!stk.push(b.c, s->root)) return false;
    Array<int> nodes, prims_out;
    nodes.init();
    prims_out.init();
    bool ok = true;
    while (ok && stk.n) {
        int e = stk[--stk.n];
        if (!e_is_node(e)) {
            ok = prims_out.push(b.c, e_index(e));
            continue;
        }
        int p = e_index(e);
        ok = nodes.push(b.c, p);
        for (int k = b.head[p]; ok && k >= 0; k = b.next[k])
            if (b.cls[k] == CL_BD) ok = stk.push(b.c, k);
    }
    if (ok) {
        if (nodes.n > 1) qsort(nodes.p, (size_t)nodes.n, sizeof(int), int_cmp);
        if (prims_out.n > 1) qsort(prims_out.p, (size_t)prims_out.n, sizeof(int), int_cmp);
        for (int i = 0; ok && i < nodes.n; i++) {
            int p = nodes[i];
            const Node &nd = s->nodes[p];
            int cnt = nd.op == O_COMPL ? 0 : b.acc_in[p];
            int first = nd.op == O_DIFF && b.first_cls[p] == CL_IN;
            h[0]++;
            h[2] += cnt + first;
            // children outside by default need no action in the counting representation; those
            // the region touches and finds outside are the "set outside" actions
            for (int k = b.head[p]; k >= 0; k = b.next[k]) h[3] += b.cls[k] == CL_OUT;
            ok = b.out.push(b.c, p) && b.out.push(b.c, cnt) && b.out.push(b.c, first);
        }
        for (int i = 0; ok && i < prims_out.n; i++) {
            h[1]++;
            ok = b.out.push(b.c, prims_out[i]);
        }
    }
    nodes.release(b.c);
    prims_out.release(b.c);
    if (!ok) return false;
    for (int i = 0; i < LIST_HEAD; i++) b.out[i] = h[i];
    return true;
}

// The primitives of a region and their classes there, into b.rprims and b.rcls, for lb_list:
// each candidate classed by `cl` (a functor, by primitive), those outside left out. Every region
// that gets a list (a voxel, a light buffer's zone, the space around the grid) is gathered
// here. False when out of memory.
template <class Classify>
bool lb_region(ListBuilder &b, const int *cand, int n, const Classify &cl) {
    b.rprims.n = b.rcls.n = 0;
    for (int k = 0; k < n; k++) {
        int x = cl(cand[k]);
        if (x != CL_OUT && !(b.rprims.push(b.c, cand[k]) && b.rcls.push(b.c, (unsigned char)x))) return false;
    }
    return true;
}

// Classes in a closed box (a voxel, widened by the margin).
struct BoxClass {
    const Scene *s;
    real lo[3], hi[3];
    int operator()(int i) const { return classify_prim(s->prims[i], lo, hi); }
};

// Classes in the space around the grid's box (or everywhere without a grid): a primitive that
// reaches outside the box's inside is on the boundary there, any other outside.
struct OuterClass {
    const Accel *a;
    const Box *eff;  // where bounds place each primitive
    int operator()(int i) const {
        const Box &bx = eff[i];
        if (box_empty(bx)) return CL_OUT;
        bool inside = a->g.n[0] > 0;
        for (int l = 0; l < 3 && inside; l++) inside = bx.lo[l] > a->g.org[l] && bx.hi[l] < a->g.top[l];
        return inside ? CL_OUT : CL_BD;
    }
};

// A list has a plan when its root, in the list's region, is a union of solids, each a primitive
// or an intersection of primitives, any of them turned inside out (eval_flat). It is plain when
// only half-spaces are turned inside out: then a ray enters and leaves each solid once (boxes,
// slabs, capped cylinders, the inside of a room's box taken from a solid block); else it is
// holed (a shell: a ball minus a smaller ball). Each primitive is followed up to the root. A node
// with one active child passes it on, turned inside out by a complement, or by a difference when
// the child is not the first (the first child is then inside for the whole region: an active
// node is on its boundary). A node with more is a union or an intersection (a difference: its
// first child and the others turned inside out), the one turned into the other by an odd number
// of inversions above it. An intersection right under the unions starts a solid, which the
// intersections under it join; a union under a solid starts a group (a wall with a window: the
// wall's block minus the opening's box, which turned inside out is a union), which the unions
// under it join; an intersection under a group leaves the list without a plan. A solid with a
// group is holed. Appends to `plan` the number of solids, 1 when holed, the number of groups;
// per primitive of the list, (solid + 1) * 4 + (2 when decisive) + (1 when turned inside out),
// solid -1 standing alone (a member is decisive when its being outside for good fixes its solid:
// fix_solid); when there are groups, per primitive its group or -1, then per group its solid;
// per solid, its node and
// 1 when it is turned inside out above that node (the solid's inside is then the node's outside:
// a node's status fixed for the ray fixes its solid's, plan_fixed). Returns where that starts,
// or -1 (appending nothing) when the list has no plan, -2 when out of memory. `kids`, `solid`:
// per node scratch, 0 and -1 on entry and left so.
const int PLAN_DEPTH = 64;  // deeper trees are evaluated in full
const int PLAN_HEAD = 3;    // a plan's numbers before the primitives'

int list_plan(pray_ctx *c, const Scene *s, const int *d, int *kids, int *solid, Array<int> *plan) {
    int na = d[0], np = d[1];
    const int *nodes = d + LIST_HEAD, *prims = list_prims(d);
    for (int i = 0; i < na; i++)
        if (s->nodes[nodes[3 * i]].parent >= 0) kids[s->nodes[nodes[3 * i]].parent]++;
    for (int i = 0; i < np; i++)
        if (s->prims[prims[i]].parent >= 0) kids[s->prims[prims[i]].parent]++;
    int base = plan->n, ns = 0, ng = 0;
    bool holed = false;
    Array<int> solids, group, gsolid;  // per solid: its node, inverted above it; per primitive; per group
    solids.init();
    group.init();
    gsolid.init();
    bool mem = np == 0 || (plan->push(c, 0) && plan->push(c, 0) && plan->push(c, 0)), ok = np > 0 && mem;
    for (int i = 0; ok && s->tori && i < np; i++) ok = s->prims[prims[i]].kind != O_TORUS;  // (two intervals)
    for (int i = 0; ok && i < np; i++) {
        int path[PLAN_DEPTH], n = 0;  // the ancestors, the root last
        for (int p = s->prims[prims[i]].parent; ok && p >= 0; p = s->nodes[p].parent) {
            ok = n < PLAN_DEPTH;
            if (ok) path[n++] = p;
        }
        bool inv = false;
        int k = -1, g = -1;  // the solid, -1 while under unions only; the group
        for (int m = n - 1; ok && m >= 0; m--) {
            int j = path[m];
            const Node &nd = s->nodes[j];
            int child = m > 0 ? 2 * path[m - 1] + 1 : 2 * prims[i];
            if (kids[j] > 1) {
                bool inter = (nd.op != O_UNION) != inv;
                ok = !(inter && g >= 0);
                if (inter && k < 0) {
                    if (solid[j] < 0) {
                        solid[j] = ns++;
                        mem = solids.push(c, j) && solids.push(c, inv);
                        ok = mem;
                    }
                    k = solid[j];
                } else if (!inter && k >= 0 && g < 0) {
                    if (solid[j] < 0) {
                        solid[j] = ng++;
                        mem = gsolid.push(c, k);
                        ok = mem;
                    }
                    g = solid[j];
                }
            }
            if (nd.op == O_COMPL || (nd.op == O_DIFF && !elem_first(s, child))) inv = !inv;
        }
        holed = holed || (inv && s->prims[prims[i]].kind != O_PLANE);
        // decisive: the member outside for good fixes its solid's node for good, as settling
        // would (not when it stands under a node whose other children, constant in this region,
        // may change along the ray, such as a union)
        bool decisive = ok && k >= 0;
        for (int m = 0, e = 2 * prims[i], v = inv; decisive; m++) {
            const Node &nd = s->nodes[path[m]];
            bool first = elem_first(s, e);
            int fix = nd.op == O_UNION ? (v ? 1 : -1) : nd.op == O_INTER ? (v ? -1 : 0)
                    : nd.op == O_DIFF ? ((first ? !v : v) ? 0 : -1) : !v;
            decisive = fix >= 0;
            if (path[m] == solids[2 * k]) break;
            v = fix;
            e = 2 * path[m] + 1;
        }
        if (ok) mem = ok = plan->push(c, (k + 1) * 4 + decisive * 2 + inv) && group.push(c, g);
    }
    for (int i = 0; ok && ng > 0 && i < np; i++) mem = ok = plan->push(c, group[i]);
    for (int i = 0; ok && i < ng; i++) mem = ok = plan->push(c, gsolid[i]);
    for (int i = 0; ok && i < solids.n; i++) mem = ok = plan->push(c, solids[i]);
    solids.release(c);
    group.release(c);
    gsolid.release(c);
    for (int i = 0; i < na; i++) {
        int j = nodes[3 * i];
        solid[j] = -1;
        kids[j] = 0;  // the parents of a list's primitives and nodes are its nodes
    }
    if (!ok) {
        plan->n = base;
        return mem ? -1 : -2;
    }
    plan->p[base] = ns;
    plan->p[base + 1] = holed || ng > 0;
    plan->p[base + 2] = ng;
    return base;
}

// A plain list: one with a plan and no holes (list_plan).
inline bool list_plain(const Accel *A, int L) { return A->plan_at[L] >= 0 && !A->plan.p[A->plan_at[L] + 1]; }

// ---- [9b.3] Building: the grid, areas and jumps ----
// Voxels along the longest axis when the grid option is automatic. Measured on the benchmark
// scenes (docs/benchmarks.md): about 4 voxels per primitive plus a floor of 4096 voxels is near
// the best for CSG scenes of 200 to 1000 primitives; the building cost grows with the voxels, so
// they are capped by half the primary rays. A handful of primitives is fastest without a grid.
// `fill` is the share of the cube over the longest side that the grid's box takes (each side
// counted at least 1/16 of the longest), so that a flat scene gets that many voxels too.
int auto_grid(int bounded, double rays, double fill) {
    if (bounded < 8) return 0;
    double v = 4.0 * bounded + 4096;
    if (v > rays / 2) v = rays / 2;
    int n = (int)ceil(cbrt_pos(v / fill));
    return n < 4 ? 4 : n > 1024 ? 1024 : n;
}

// Smallest and largest of each voxel's value and its two neighbours along axis `l` (fewer at the
// grid's edge), in place.
void window3(int *mn, int *mx, const int *n, int l) {
    long st = l == 0 ? 1 : l == 1 ? n[0] : (long)n[0] * n[1];
    long nv = (long)n[0] * n[1] * n[2];
    for (long v0 = 0; v0 < nv; v0++) {
        if (v0 / st % n[l] != 0) continue;  // the first voxel of a line along l
        int pmn = mn[v0], pmx = mx[v0];
        for (int i = 0; i < n[l]; i++) {
            long v = v0 + i * st;
            int cmn = mn[v], cmx = mx[v];
            int nmn = i + 1 < n[l] ? mn[v + st] : cmn, nmx = i + 1 < n[l] ? mx[v + st] : cmx;
            mn[v] = pmn < cmn ? (pmn < nmn ? pmn : nmn) : (cmn < nmn ? cmn : nmn);
            mx[v] = pmx > cmx ? (pmx > nmx ? pmx : nmx) : (cmx > nmx ? cmx : nmx);
            pmn = cmn;
            pmx = cmx;
        }
    }
}

// Voxel v of a grid nx x ny x ... in the same grid with a border of one voxel all round.
long bordered(long v, int nx, int ny) {
    return ((v / nx / ny + 1) * (ny + 2) + v / nx % ny + 1) * (nx + 2) + v % nx + 1;
}

// Merging into areas (3.6) makes crossing an area cheap; jumps make it cheaper still. reach[v]
// is the chessboard distance from voxel v to the nearest voxel with a neighbour of another list
// (at most 255; the grid's edge does not count): every voxel within that distance of v has v's
// list, so a ray in v goes on to where it leaves that cube of voxels without looking at them.
bool reach_build(pray_ctx *c, Grid *a) {
    const int nx = a->n[0], ny = a->n[1], nz = a->n[2];
    const long nv = (long)nx * ny * nz;
    const long px = nx + 2, py = ny + 2, np = px * py * (nz + 2);  // with a border of one voxel
    a->reach = (unsigned char *)mem_alloc(c, (size_t)nv);
    int *mn = (int *)mem_alloc(c, sizeof(int) * (size_t)nv), *mx = (int *)mem_alloc(c, sizeof(int) * (size_t)nv);
    unsigned char *r = (unsigned char *)mem_alloc(c, (size_t)np);
    bool ok = a->reach && mn && mx && r;
    if (ok) {
        // 0 where the 3 x 3 x 3 voxels around hold more than one list (a separable filter)
        memcpy(mn, a->voxel, sizeof(int) * (size_t)nv);
        memcpy(mx, a->voxel, sizeof(int) * (size_t)nv);
        for (int l = 0; l < 3; l++) window3(mn, mx, a->n, l);
        memset(r, 255, (size_t)np);  // the border: the grid's edge is no boundary
        for (long v = 0; v < nv; v++) r[bordered(v, nx, ny)] = mn[v] == mx[v] ? 255 : 0;
        // the chessboard distance to those voxels: a raster pass forwards over the 13 neighbours
        // visited before, then one backwards (exact for this distance)
        long off[13];
        int k = 0;
        for (int dz = -1; dz <= 0; dz++)
            for (int dy = -1; dy <= 1; dy++)
                for (int dx = -1; dx <= 1; dx++)
                    if (dz < 0 || dy < 0 || (dy == 0 && dx < 0)) off[k++] = (dz * py + dy) * px + dx;
        for (int pass = 0; pass < 2; pass++)
            for (int z = 1; z <= nz; z++)
                for (int y = 1; y <= ny; y++)
                    for (int x = 1; x <= nx; x++) {
                        int zz = pass == 0 ? z : nz + 1 - z, yy = pass == 0 ? y : ny + 1 - y, xx = pass == 0 ? x : nx + 1 - x;
                        long q = ((long)zz * py + yy) * px + xx;
                        int d = r[q];
                        for (int i = 0; i < 13; i++) {
                            int e = r[pass == 0 ? q + off[i] : q - off[i]] + 1;
                            d = e < d ? e : d;
                        }
                        r[q] = (unsigned char)d;
                    }
        for (long v = 0; v < nv; v++) a->reach[v] = r[bordered(v, nx, ny)];
    }
    mem_free(c, mn);
    mem_free(c, mx);
    mem_free(c, r);
    return ok;
}

// The voxels of G that box bx, widened by the margin, meets: lo[l] to hi[l] along each axis
// (false when none).
bool voxel_range(const Grid &G, const Box &bx, double margin, int *lo, int *hi) {
    for (int l = 0; l < 3; l++) {
        double gl = ((double)bx.lo[l] - margin - (double)G.org[l]) / (double)G.h;
        double gh = ((double)bx.hi[l] + margin - (double)G.org[l]) / (double)G.h;
        lo[l] = gl < 0 ? 0 : gl >= G.n[l] ? G.n[l] : (int)floor(gl);
        hi[l] = gh < 0 ? -1 : gh >= G.n[l] ? G.n[l] - 1 : (int)floor(gh);
        if (lo[l] > hi[l]) return false;
    }
    return true;
}

// How many voxels of G the boxes of primitives ids[0 .. n) (NULL: 0 .. n) meet, all together.
double voxel_refs(const Grid &G, const Box *eff, const int *ids, int n, double margin) {
    double refs = 0;
    for (int i = 0; i < n; i++) {
        int lo[3], hi[3];
        if (voxel_range(G, eff[ids ? ids[i] : i], margin, lo, hi))
            refs += (double)(hi[0] - lo[0] + 1) * (hi[1] - lo[1] + 1) * (hi[2] - lo[2] + 1);
    }
    return refs;
}

// The items of each cell of a grid of dim[0] x dim[1] x dim[2] cells, x fastest, as
// cand[start[v] .. start[v + 1]), in two passes (count, then fill): `range(k, &id, lo, hi)`
// gives item k's number and the cells it meets, lo[l] to hi[l] along each axis (false: none).
template <class Range>
bool bucket(pray_ctx *c, const int *dim, int n, const Range &range, Array<int> &cand, Array<int> &start) {
    long nv = (long)dim[0] * dim[1] * dim[2];
    start.n = cand.n = 0;
    if (!start.reserve(c, (int)nv + 1)) return false;
    start.n = (int)nv + 1;
    memset(start.p, 0, sizeof(int) * (size_t)(nv + 1));
    for (int pass = 0; pass < 2; pass++) {
        for (int k = 0; k < n; k++) {
            if (over_time(c)) {
                fail_cancelled(c);
                return false;
            }
            int i, lo[3], hi[3];
            if (!range(k, &i, lo, hi)) continue;
            for (int z = lo[2]; z <= hi[2]; z++)
                for (int y = lo[1]; y <= hi[1]; y++)
                    for (int x = lo[0]; x <= hi[0]; x++) {
                        int v = (z * dim[1] + y) * dim[0] + x;
                        if (pass == 0) start[v + 1]++;
                        else cand[start[v]++] = i;
                    }
        }
        if (pass == 0) {
            for (long v = 0; v < nv; v++) start[(int)v + 1] += start[(int)v];
            if (!cand.reserve(c, start[(int)nv] + 1)) return false;
            cand.n = start[(int)nv];
        } else {
            for (long v = nv; v > 0; v--) start[(int)v] = start[(int)v - 1];
            start[0] = 0;
        }
    }
    return true;
}

// The voxels of G that the boxes of primitives ids[0 .. n) (0 .. n - 1 when NULL) meet, widened
// by the margin (voxel_range), for bucket.
struct VoxelRange {
    const Grid &G;
    const Box *eff;
    const int *ids;
    double margin;
    VoxelRange(const Grid &G_, const Box *eff_, const int *ids_, double margin_) : G(G_), eff(eff_), ids(ids_), margin(margin_) {}
    bool operator()(int k, int *i, int *lo, int *hi) const {
        *i = ids ? ids[k] : k;
        return voxel_range(G, eff[*i], margin, lo, hi);
    }
};

// What the grids of a scene are built with: where bounds place each primitive, the rounding of a
// position per step of a walk (the margins grow with the steps of the walks above a grid), and
// how many voxels nested grids may still take.
struct GridPlan {
    const Box *eff;
    const int *obj;  // per primitive: its object (NEST_OBJECTS)
    double round;
    double budget;
};

// A voxel with more objects to check than this gets a grid of its own (option nest: how many
// levels deep). An object is a primitive, or the intersection it is part of (with the
// intersections above that one): a box of six half-spaces is one object, since finer voxels
// would not part its faces. The nested grid covers the box that holds those primitives within
// the voxel, with about 4 voxels per object to check (as auto_grid), at most 32 a side; the rest
// of the voxel has the voxel's list without them (Grid::rest). A primitive that crosses the
// whole voxel along some axis (a floor, a wall, a long rod) is no part of a crowd: the box leaves
// it out, and the rest of the voxel checks it, unless that would crowd the rest.
const int NEST_OBJECTS = 8;
// Nested grids have at most this many voxels for each primitive of the scene, all together; and
// a nested grid is built only where it separates the voxel's primitives: its voxels reach, on
// average, at most this share of the primitives the voxel has to check.
const double NEST_PER_PRIM = 64, NEST_SEPARATES = 0.5;

bool grid_lists(ListBuilder &b, Grid &G, GridPlan &gp, const Array<int> &cand, const Array<int> &start, double margin,
                int steps, int depth);

// Per primitive, its object: the highest node above it through intersections alone (a box of
// half-spaces), or else the primitive (numbered after the nodes); NULL when out of memory.
int *nest_objects(pray_ctx *c, const Scene *s) {
    int np = s->prims.n, nn = s->nodes.n, *top = (int *)mem_alloc(c, sizeof(int) * (size_t)(np + nn + 1));
    for (int j = nn - 1; top && j >= 0; j--) {  // parents before children
        int pa = s->nodes[j].parent;
        top[np + j] = s->nodes[j].op != O_INTER ? -1 : pa >= 0 && top[np + pa] >= 0 ? top[np + pa] : j;
    }
    for (int i = 0; top && i < np; i++) {
        int pa = s->prims[i].parent;
        top[i] = pa >= 0 && top[np + pa] >= 0 ? top[np + pa] : nn + i;
    }
    return top;
}

// Box bx widened by wid, within the voxel [v0, v1]: lo, hi; whether it crosses the voxel along
// some axis.
bool nest_clip(const Box &bx, double wid, const double *v0, const double *v1, double *lo, double *hi) {
    bool crosses = false;
    for (int l = 0; l < 3; l++) {
        double a = (double)bx.lo[l] - wid, z = (double)bx.hi[l] + wid;
        crosses = crosses || (a <= v0[l] && z >= v1[l]);
        lo[l] = a > v0[l] ? a : v0[l];
        hi[l] = z < v1[l] ? z : v1[l];
    }
    return crosses;
}

// Whether box bx widened by wid lies within [lo, hi] inside the voxel [v0, v1].
bool nest_holds(const Box &bx, double wid, const double *v0, const double *v1, const double *lo, const double *hi) {
    double plo[3], phi[3];
    nest_clip(bx, wid, v0, v1, plo, phi);
    for (int l = 0; l < 3; l++)
        if (!(plo[l] >= lo[l] && phi[l] <= hi[l])) return false;
    return true;
}

// The box of a nested grid in the voxel [v0, v1]: of the primitives to check (b.rprims, b.rcls)
// whose boxes do not cross the voxel, when the others are few enough for the rest of the voxel
// (at most NEST_OBJECTS primitives, not objects, outside that box), else of them all. Their
// boxes are widened by wid; the box is within the voxel, and false when it is empty.
bool nest_box(const ListBuilder &b, const Box *eff, double wid, const double *v0, const double *v1, double *lo,
              double *hi) {
    double alo[3], ahi[3], plo[3], phi[3];
    for (int l = 0; l < 3; l++) alo[l] = lo[l] = HUGE_VAL, ahi[l] = hi[l] = -HUGE_VAL;
    int local = 0;
    for (int i = 0; i < b.rprims.n; i++) {
        if (b.rcls[i] != CL_BD) continue;
        bool crosses = nest_clip(eff[b.rprims[i]], wid, v0, v1, plo, phi);
        local += !crosses;
        for (int l = 0; l < 3; l++) {
            alo[l] = plo[l] < alo[l] ? plo[l] : alo[l];
            ahi[l] = phi[l] > ahi[l] ? phi[l] : ahi[l];
            lo[l] = !crosses && plo[l] < lo[l] ? plo[l] : lo[l];
            hi[l] = !crosses && phi[l] > hi[l] ? phi[l] : hi[l];
        }
    }
    int out = 0;
    for (int i = 0; local > 0 && i < b.rprims.n; i++)
        if (b.rcls[i] == CL_BD && !nest_holds(eff[b.rprims[i]], wid, v0, v1, lo, hi)) out++;
    bool all = local == 0 || out > NEST_OBJECTS;
    for (int l = 0; l < 3; l++) {
        if (all) lo[l] = alo[l], hi[l] = ahi[l];
        if (!(hi[l] > lo[l])) return false;
    }
    return true;
}

// A grid of its own for voxel ix of G, whose candidates are ids[0 .. n) and which has `checks`
// primitives in `objs` objects to check (classed in the voxel: b.rprims, b.rcls): its index in
// Accel::nested; -1 when it is not worth it or does not fit the budget; -2 on failure.
int nest_build(ListBuilder &b, const Grid &G, const int *ix, GridPlan &gp, const int *ids, int n, int checks, int objs,
               int steps, int depth) {
    pray_ctx *c = b.c;
    // the box of the primitives to check, widened by the most a nested grid's margin can be
    // (m <= 32 below), within the voxel
    double wid = (double)G.h * 1e-6 + gp.round * (steps + 36), v0[3], v1[3], lo[3], hi[3], ext = 0, vol = 1;
    for (int l = 0; l < 3; l++) {
        v0[l] = (double)G.org[l] + ix[l] * (double)G.h;
        v1[l] = v0[l] + (double)G.h;
    }
    if (!nest_box(b, gp.eff, wid, v0, v1, lo, hi)) return -1;
    for (int l = 0; l < 3; l++) ext = hi[l] - lo[l] > ext ? hi[l] - lo[l] : ext;
    for (int l = 0; l < 3; l++) vol *= hi[l] - lo[l] > ext / 16 ? hi[l] - lo[l] : ext / 16;
    // cubic voxels, about 4 per object to check, fewer while the budget is short
    Grid S;
    memset(&S, 0, sizeof S);
    double h = cbrt_pos(vol / (4.0 * objs)), nv = 0;
    h = h > ext / 32 ? h : ext / 32;
    for (;;) {
        nv = 1;
        for (int l = 0; l < 3; l++) {
            double k = ceil((hi[l] - lo[l]) / h);
            S.n[l] = k < 1 ? 1 : (int)k;
            nv *= S.n[l];
        }
        if (nv <= gp.budget || nv < 8) break;
        h *= 1.25;
    }
    if (nv < 8 || nv > gp.budget) return -1;
    S.h = (real)h;
    S.inv_h = (real)1 / S.h;
    for (int l = 0; l < 3; l++) {
        S.org[l] = (real)((lo[l] + hi[l]) / 2 - S.n[l] * h / 2);
        S.top[l] = (real)((double)S.org[l] + S.n[l] * h);
    }
    int m = S.n[0] > S.n[1] ? S.n[0] : S.n[1];
    steps += (m > S.n[2] ? m : S.n[2]) + 4;
    double margin = (double)S.h * 1e-6 + gp.round * steps;
    if (margin > (double)S.h / 4) return -1;  // (b.rprims and b.rcls left as they are)
    // (a crowd all in the same place is not separated)
    if (voxel_refs(S, gp.eff, ids, n, margin) > NEST_SEPARATES * checks * nv) return -1;
    // the rest of the voxel: what is inside it all, and the primitives to check that reach
    // out of the box
    Array<int> rp, cand, start;
    Array<unsigned char> rc;
    rp.init();
    rc.init();
    cand.init();
    start.init();
    bool ok = rp.reserve(c, b.rprims.n + 1) && rc.reserve(c, b.rprims.n + 1);
    for (int i = 0; ok && i < b.rprims.n; i++)
        if (b.rcls[i] != CL_BD || !nest_holds(gp.eff[b.rprims[i]], wid, v0, v1, lo, hi))
            rp.p[rp.n++] = b.rprims[i], rc.p[rc.n++] = b.rcls[i];
    S.rest = ok ? lb_list(b, rp.p, rc.p, rp.n) : -1;
    ok = S.rest >= 0;
    gp.budget -= nv;
    S.voxel = ok ? (int *)mem_zalloc(c, sizeof(int) * (size_t)nv) : NULL;
    ok = S.voxel && bucket(c, S.n, n, VoxelRange(S, gp.eff, ids, margin), cand, start) &&
         grid_lists(b, S, gp, cand, start, margin, steps, depth) && b.a->nested.push(c, S);
    rp.release(c);
    rc.release(c);
    cand.release(c);
    start.release(c);
    if (ok) return b.a->nested.n - 1;
    mem_free(c, S.voxel);
    mem_free(c, S.reach);
    return -2;
}

// The lists of G's voxels from their candidates, classed in the voxels widened by the margin
// (`steps`: of the walks down to G); a crowded voxel gets a nested grid while `depth` allows.
bool grid_lists(ListBuilder &b, Grid &G, GridPlan &gp, const Array<int> &cand, const Array<int> &start, double margin,
                int steps, int depth) {
    for (int z = 0; z < G.n[2]; z++)
        for (int y = 0; y < G.n[1]; y++) {
            if (over_time(b.c)) {
                fail_cancelled(b.c);
                return false;
            }
            for (int x = 0; x < G.n[0]; x++) {
                int ix[3] = {x, y, z}, ix1[3] = {x + 1, y + 1, z + 1};
                long v = voxel_index(G, ix);
                int k0 = start[(int)v], k1 = start[(int)v + 1];
                BoxClass in;
                in.s = b.s;
                voxels_box(G, ix, ix1, margin, in.lo, in.hi);
                if (!lb_region(b, cand.p + k0, k1 - k0, in)) return false;
                int checks = 0, objs = 0;
                for (int i = 0, o = -1; i < b.rcls.n; i++)  // (an object's primitives are numbered together)
                    if (b.rcls[i] == CL_BD) checks++, objs += gp.obj[b.rprims[i]] != o, o = gp.obj[b.rprims[i]];
                int g = depth > 0 && objs > NEST_OBJECTS ? nest_build(b, G, ix, gp, cand.p + k0, k1 - k0, checks, objs, steps, depth - 1) : -1;
                if (g == -2) return false;
                if (g >= 0) {
                    G.voxel[v] = -1 - g;
                    continue;
                }
                for (int l = 0; l < 3; l++) b.rlo[l] = in.lo[l], b.rhi[l] = in.hi[l];
                b.rbox = 1;
                int L = lb_list(b, b.rprims.p, b.rcls.p, b.rprims.n);
                b.rbox = 0;
                if (L < 0) return false;
                G.voxel[v] = L;
            }
        }
    return reach_build(b.c, &G);
}

// Areas of G (3.6): connected voxels with the same list, counted into *areas (statistics).
bool grid_areas(pray_ctx *c, const Grid &G, long *areas) {
    long nv = (long)G.n[0] * G.n[1] * G.n[2];
    Array<int> q;
    q.init();
    unsigned char *seen = (unsigned char *)mem_zalloc(c, (size_t)nv + 1);
    bool ok = seen != NULL;
    for (long v0 = 0; ok && v0 < nv; v0++) {
        if (seen[v0]) continue;
        ++*areas;
        seen[v0] = 1;
        q.n = 0;
        ok = q.push(c, (int)v0);
        while (ok && q.n) {
            long v = q[--q.n];
            int x = (int)(v % G.n[0]), y = (int)(v / G.n[0] % G.n[1]), z = (int)(v / G.n[0] / G.n[1]);
            int nb[6][3] = {{x - 1, y, z}, {x + 1, y, z}, {x, y - 1, z}, {x, y + 1, z}, {x, y, z - 1}, {x, y, z + 1}};
            for (int k = 0; ok && k < 6; k++) {
                if (nb[k][0] < 0 || nb[k][1] < 0 || nb[k][2] < 0 || nb[k][0] >= G.n[0] || nb[k][1] >= G.n[1] || nb[k][2] >= G.n[2])
                    continue;
                long u = voxel_index(G, nb[k]);
                if (seen[u] || G.voxel[u] != G.voxel[v0]) continue;
                seen[u] = 1;
                ok = q.push(c, (int)u);
            }
        }
    }
    mem_free(c, seen);
    q.release(c);
    return ok;
}

// ---- [9b.4] Building: light buffers and the eye's buffer ----
// (Haines and Greenberg's light buffer, in the survey [Woo90].)
// A shadow ray runs from a surface point to its light. Around each light the directions are
// cut into cells (across a directional light: columns), and each cell into slabs by distance
// from the light; a voxel of this light-space grid keeps the action list of its zone, the part
// of the cell between the voxel and the light, which holds every shadow ray that starts in the
// voxel. Such a ray evaluates that one list instead of walking the grid. The zones are classed
// like the grid's voxels, with a margin for rounding.
#ifndef PRAY_NO_BUFFERS  // (a build without them: their options change nothing)

// The squared distance from point p to box bx (0 inside it).
inline real box_dist2(const Box &bx, R3 p) {
    real d2 = 0;
    for (int l = 0; l < 3; l++) {
        real c = comp(p, l), e = bx.lo[l] - c > 0 ? bx.lo[l] - c : c - bx.hi[l] > 0 ? c - bx.hi[l] : 0;
        d2 += e * e;
    }
    return d2;
}

// A convex zone: {x : n[i].x <= d[i]}, the hull of v[0 .. nv); with a ball of radius r around c
// joined to it (a point light's neighbourhood, where the pyramids meet; r = 0: none).
struct Zone {
    int np, nv;
    R3 n[6], v[8];
    real d[6];
    R3 c;
    real r;
    real lo[3], hi[3];  // the hull's box (zone_hull)
};

// Sets the box of zone z's hull from its vertices.
void zone_hull(Zone *z) {
    for (int l = 0; l < 3; l++) {
        z->lo[l] = REAL_BIG, z->hi[l] = -REAL_BIG;
        for (int k = 0; k < z->nv; k++) {
            real x = comp(z->v[k], l);
            z->lo[l] = x < z->lo[l] ? x : z->lo[l];
            z->hi[l] = x > z->hi[l] ? x : z->hi[l];
        }
    }
}

// Class of primitive q, which bounds place in box bx, against a zone: conservative, like
// classify_prim (outside only when it misses the zone, inside only when it holds all of it).
int classify_zone(const Prim &q, const Box &bx, const Zone &z) {
    bool out = false;  // clear of the hull's box or beyond one of the polytope's planes
    for (int l = 0; l < 3 && !out; l++) out = z.hi[l] < bx.lo[l] || bx.hi[l] < z.lo[l];
    for (int i = 0; i < z.np && !out; i++) {
        real lo = 0;  // the least n.x over the box
        for (int l = 0; l < 3; l++) {
            real nl = comp(z.n[i], l);  // (no 0 x infinity: a box may be unbounded)
            lo += nl * (nl > 0 ? bx.lo[l] : nl < 0 ? bx.hi[l] : 0);
        }
        out = lo > z.d[i];
    }
    bool out_ball = z.r == 0 || box_dist2(bx, z.c) > z.r * z.r;
    bool in = true;  // every vertex inside the solid (then all of the polytope, which is convex)
    switch (q.kind) {
    case O_SPHERE: {
        for (int i = 0; i < z.np && !out; i++) out = dot(z.n[i], q.p) - z.d[i] > q.r;
        for (int k = 0; k < z.nv && in; k++) in = dot(z.v[k] - q.p, z.v[k] - q.p) < q.r2;
        real dc = (real)sqrt((double)dot(z.c - q.p, z.c - q.p));
        out_ball = out_ball || dc > q.r + z.r;
        in = in && (z.r == 0 || dc + z.r < q.r);
        break;
    }
    case O_PLANE: {
        bool all_out = true;
        for (int k = 0; k < z.nv; k++) {
            real sd = dot(q.n, z.v[k]) - q.d;
            in = in && sd < 0;
            all_out = all_out && sd > 0;
        }
        out = out || all_out;
        real sc = dot(q.n, z.c) - q.d;
        out_ball = out_ball || sc > z.r;
        in = in && (z.r == 0 || sc < -z.r);
        break;
    }
    case O_CYLINDER: {
        for (int k = 0; k < z.nv && in; k++) {
            R3 x = z.v[k] - q.p;
            R3 perp = x - q.n * dot(x, q.n);
            in = dot(perp, perp) < q.r2;
        }
        R3 x = z.c - q.p;
        R3 perp = x - q.n * dot(x, q.n);
        in = in && (z.r == 0 || (real)sqrt((double)dot(perp, perp)) + z.r < q.r);
        break;
    }
    default:  // in a frame: inside when convex and holding every vertex (no ball)
        for (int k = 0; k < z.nv && in; k++) in = framed_inside(q, z.v[k]);
        in = in && z.r == 0;
    }
    if (out && out_ball) return CL_OUT;
    return in ? CL_IN : CL_BD;
}

// Classes in a zone of a light buffer, for primitives whose depths (key: per primitive, the
// least and the most w of its box) meet the zone's [w0, w1].
struct ZoneClass {
    const Scene *s;
    const Box *eff;  // where bounds place each primitive
    const real *key;
    real w0, w1;
    Zone z;
    int operator()(int i) const {
        if (!(key[2 * i] <= w1 && key[2 * i + 1] >= w0)) return CL_OUT;
        return classify_zone(s->prims[i], eff[i], z);
    }
};

// Near a point light, where that widening is less than the rounding of a point, a ball around
// the light of this radius joins every zone (`eps`: the widening in u and v).
inline real tip_ball(real margin, real eps) {
    real r = margin * (real)2.6 / eps;
    return r > margin ? r : margin;
}

// The zone of voxel (iu, iv, k) of face F, widened by the margin (a point light's cells by
// eps, its ball of radius r). A piece of the eye's buffer also has a near side, unless it
// reaches the eye.
void lightbuf_zone(const LightBuf &B, const LightFace &F, int iu, int iv, int k, real margin, real eps, real r, Zone *z) {
    const R3 *e = F.e;
    real u[2], v[2];
    if (!B.point) {
        u[0] = F.lo[0] + (real)iu * F.h[0] - margin;
        u[1] = F.lo[0] + (real)(iu + 1) * F.h[0] + margin;
        v[0] = F.lo[1] + (real)iv * F.h[1] - margin;
        v[1] = F.lo[1] + (real)(iv + 1) * F.h[1] + margin;
        real w[2] = {F.lo[2] + (real)k * F.h[2] - margin, B.top + margin};
        z->np = 6;
        for (int l = 0; l < 3; l++) {
            real lo = l == 0 ? u[0] : l == 1 ? v[0] : w[0], hi = l == 0 ? u[1] : l == 1 ? v[1] : w[1];
            z->n[2 * l] = e[l];
            z->d[2 * l] = hi;
            z->n[2 * l + 1] = e[l] * (real)-1;
            z->d[2 * l + 1] = -lo;
        }
        z->nv = 8;
        for (int i = 0; i < 8; i++) z->v[i] = e[0] * u[i & 1] + e[1] * v[i >> 1 & 1] + e[2] * w[i >> 2];
        z->c = r3(0, 0, 0);
        z->r = 0;
        zone_hull(z);
        return;
    }
    u[0] = F.lo[0] + (real)iu * F.h[0] - eps;
    u[1] = F.lo[0] + (real)(iu + 1) * F.h[0] + eps;
    v[0] = F.lo[1] + (real)iv * F.h[1] - eps;
    v[1] = F.lo[1] + (real)(iv + 1) * F.h[1] + eps;
    real far = F.lo[2] + (real)(k + 1) * F.h[2] + margin;
    z->np = 5;
    z->n[0] = unit(e[2] * u[0] - e[0]);
    z->n[1] = unit(e[0] - e[2] * u[1]);
    z->n[2] = unit(e[2] * v[0] - e[1]);
    z->n[3] = unit(e[1] - e[2] * v[1]);
    z->n[4] = e[2];
    for (int i = 0; i < 4; i++) z->d[i] = dot(z->n[i], B.o);
    z->d[4] = dot(e[2], B.o) + far;
    z->nv = 5;
    z->v[0] = B.o;
    for (int i = 0; i < 4; i++) z->v[1 + i] = B.o + (e[2] + e[0] * u[i & 1] + e[1] * v[i >> 1]) * far;
    z->c = B.o;
    z->r = r;
    real near = F.lo[2] + (real)k * F.h[2] - margin;
    if (!B.pieces || !(near > 0)) {
        zone_hull(z);
        return;
    }
    z->np = 6;
    z->n[5] = e[2] * (real)-1;
    z->d[5] = -(dot(e[2], B.o) + near);
    z->nv = 8;
    for (int i = 0; i < 4; i++) {
        R3 edge = e[2] + e[0] * u[i & 1] + e[1] * v[i >> 1];
        z->v[i] = B.o + edge * near;
        z->v[4 + i] = B.o + edge * far;
    }
    z->r = 0;
    zone_hull(z);
}

// The depths w between which zone k of face F lies, widened by the margin: its slab's for a
// piece of the eye's buffer; from a point light to the slab's far side; from the slab to the
// buffer's end (past the grid) for a directional light.
inline void zone_depths(const LightBuf &B, const LightFace &F, int k, real margin, real *w0, real *w1) {
    *w0 = B.point && !B.pieces ? -REAL_BIG : F.lo[2] + (real)k * F.h[2] - margin;
    *w1 = !B.point ? REAL_BIG : F.lo[2] + (real)(k + 1) * F.h[2] + margin;
}

// The box in the face's coordinates (u, v, w), projected for a point light: *lo, *hi over its
// corners. Returns whether a corner is not in front of a point light's face.
bool face_extent(const LightBuf &B, const LightFace &F, const Box &bx, real *lo, real *hi) {
    bool behind = false;
    for (int l = 0; l < 3; l++) lo[l] = REAL_BIG, hi[l] = -REAL_BIG;
    for (int k = 0; k < 8; k++) {
        R3 x = r3(k & 1 ? bx.hi[0] : bx.lo[0], k & 2 ? bx.hi[1] : bx.lo[1], k & 4 ? bx.hi[2] : bx.lo[2]) - B.o;
        real g[3] = {dot(x, F.e[0]), dot(x, F.e[1]), dot(x, F.e[2])};
        if (B.point) {
            behind = behind || !(g[2] > 0);
            if (g[2] > 0) g[0] /= g[2], g[1] /= g[2];
        }
        for (int l = 0; l < 3; l++) {
            lo[l] = g[l] < lo[l] ? g[l] : lo[l];
            hi[l] = g[l] > hi[l] ? g[l] : hi[l];
        }
    }
    return behind;
}

// A voxel whose zone meets more primitives than this is left to the grid, which stops at the
// first blocker instead of testing everything between the point and the light. A piece of the
// eye's buffer may meet half as many: a primary ray evaluates several (beyond that the Room's
// primary rays made a fifth more intersection tests than through the grid).
const int LB_MAX_CAND = 64;

// The eye's buffer as runs (LightBuf::runs): the slabs of a cell with the same list, one after
// the other, become one run, which a primary ray crosses in one step. Its voxels' lists are not
// kept. A buffer without a cell to give is dropped.
bool eye_runs(pray_ctx *c, LightBuf &B, int cells) {
    Array<int> r;
    r.init();
    bool ok = r.reserve(c, cells + 1), any = false;
    r.n = cells + 1;
    for (int fi = 0; ok && fi < B.faces; fi++) {
        const LightFace &F = B.f[fi];
        int stride = F.n[0] * F.n[1];
        for (int cel = 0; ok && F.n[2] > 0 && cel < stride; cel++) {
            const int *col = B.list + F.base + cel;
            int first = r[F.cbase + cel] = r.n;
            any = any || col[0] >= 0;
            for (int k = 0; ok && k < F.n[2]; k++) {
                if (r.n > first && r[r.n - 2] == col[k * stride]) r[r.n - 1] = k + 1;
                else ok = r.push(c, col[k * stride]) && r.push(c, k + 1);
            }
        }
    }
    if (ok) r[cells] = r.n;
    mem_free(c, B.list);
    B.list = NULL;
    B.runs = r.p;
    B.nruns = r.n;
    if (!any) B.faces = 0;
    return ok;
}

// A buffer is built when the image has at least this many pixels (samples) per voxel of it: a
// voxel costs about as much to build as a few rays save. On the Fractal at 256 x 256 the light
// buffers (49 300 voxels for 65 536 pixels) made the picture 40 % slower; at 512 x 512 they
// were even, and at 1024 x 1024 they save a fifth.
const int RAYS_PER_VOXEL = 8;

// Face fi of a point light's cube of directions: e[2] along axis fi / 2, away from the light
// (towards -1 for odd fi), e[0] and e[1] the next two axes.
void point_face(int fi, LightFace *F) {
    int ax = fi / 2;
    real sg = fi & 1 ? (real)-1 : (real)1;
    R3 unitv[3] = {r3(1, 0, 0), r3(0, 1, 0), r3(0, 0, 1)};
    F->e[2] = unitv[ax] * sg;
    F->e[0] = unitv[(ax + 1) % 3];
    F->e[1] = unitv[(ax + 2) % 3];
}

// The cells of a face that each primitive's footprint covers (per primitive u0, u1, v0, v1), for
// bucket.
struct Footprint {
    const int *foot;
    explicit Footprint(const int *foot_) : foot(foot_) {}
    bool operator()(int k, int *i, int *lo, int *hi) const {
        const int *ft = foot + 4 * k;
        *i = k;
        lo[0] = ft[0], hi[0] = ft[1], lo[1] = ft[2], hi[1] = ft[3], lo[2] = hi[2] = 0;
        return lo[0] <= hi[0] && lo[1] <= hi[1];
    }
};

// Each primitive's cells on face F (foot: the first and last along u, then v; none when first >
// last) and its depths from the light (key: nearest and farthest), which decide its slabs. A
// point light's primitives within r of it, and unbounded ones, reach every cell and depth; wid
// widens the footprints (a point light's: eps, else the margin).
void face_footprints(const LightBuf &B, const LightFace &F, const Box *eff, int np, real r, real wid, real *key,
                     int *foot) {
    for (int i = 0; i < np; i++) {
        const Box &bx = eff[i];
        int *ft = foot + 4 * i;
        ft[0] = 0, ft[1] = F.n[0] - 1, ft[2] = 0, ft[3] = F.n[1] - 1;
        key[2 * i] = -REAL_BIG;
        key[2 * i + 1] = REAL_BIG;
        if (box_empty(bx)) {
            ft[0] = 1, ft[1] = 0;
            continue;
        }
        if (!box_finite(bx)) continue;
        if (B.point && box_dist2(bx, B.o) <= r * r) continue;
        real lo[3], hi[3];
        bool behind = face_extent(B, F, bx, lo, hi);
        if (B.point && !(hi[2] > 0)) {  // behind the face: no zone reaches it
            ft[0] = 1, ft[1] = 0;
            continue;
        }
        key[2 * i + 1] = hi[2];
        if (B.point && behind) continue;
        key[2 * i] = lo[2];
        for (int l = 0; l < 2; l++) {
            double g0 = ((double)(lo[l] - wid) - (double)F.lo[l]) / (double)F.h[l];
            double g1 = ((double)(hi[l] + wid) - (double)F.lo[l]) / (double)F.h[l];
            ft[2 * l] = g0 < 0 ? 0 : g0 >= F.n[l] ? F.n[l] : (int)g0;
            ft[2 * l + 1] = g1 < 0 ? -1 : g1 >= F.n[l] ? F.n[l] - 1 : (int)g1;
        }
    }
}

// Face F (number fi) of buffer B: its axes (across a directional light, towards it: `toward`),
// the part of the grid's box it sees, and its cells and slabs of about `cell`; false when the box
// is behind it.
bool face_layout(LightBuf &B, LightFace &F, int fi, R3 toward, const Grid &g, real cell, real margin) {
    if (!B.point) {
        F.e[2] = toward;
        real ax = (real)fabs((double)toward.x), ay = (real)fabs((double)toward.y), az = (real)fabs((double)toward.z);
        R3 least = ax <= ay && ax <= az ? r3(1, 0, 0) : ay <= az ? r3(0, 1, 0) : r3(0, 0, 1);
        F.e[0] = unit(cross(F.e[2], least));
        F.e[1] = cross(F.e[2], F.e[0]);
    } else point_face(fi, &F);
    // the grid's box in the face's coordinates
    Box grid;
    for (int l = 0; l < 3; l++) grid.lo[l] = g.org[l], grid.hi[l] = g.top[l];
    real lo[3], hi[3];
    bool behind = face_extent(B, F, grid, lo, hi);
    if (B.point) {
        if (!(hi[2] > 0)) return false;  // the box is behind the face
        if (behind) lo[0] = lo[1] = -1, hi[0] = hi[1] = 1, lo[2] = 0;
        if (B.pieces) {  // the pieces hold the box whatever the rounding of a ray's depth
            lo[2] = lo[2] - margin > 0 ? lo[2] - margin : 0;
            hi[2] += margin;
        }
        for (int l = 0; l < 2; l++) {
            lo[l] = lo[l] < -1 ? -1 : lo[l];
            hi[l] = hi[l] > 1 ? 1 : hi[l];
        }
        real mid = (lo[2] + hi[2]) / 2;
        F.h[0] = F.h[1] = cell / mid;
        F.h[2] = cell;
    } else {
        for (int l = 0; l < 3; l++) lo[l] -= margin, hi[l] += margin;
        F.h[0] = F.h[1] = F.h[2] = cell;
        B.top = hi[2];
    }
    for (int l = 0; l < 3; l++) {
        double n = ceil((double)(hi[l] - lo[l]) / (double)F.h[l]);
        F.n[l] = n < 1 ? 1 : n > 256 ? 256 : (int)n;
        F.h[l] = (hi[l] - lo[l]) / (real)F.n[l];
        if (!(F.h[l] > 0)) F.h[l] = cell;
        F.inv[l] = (real)1 / F.h[l];
        F.lo[l] = lo[l];
    }
    return true;
}

// Build the light buffers: cells and slabs about `cell` wide where the grid's box is, and lists
// for the space between each voxel and its light. `eff`: where
// bounds place each primitive; `margin`: how far rounding may move a point (the grid's).
// `lights`, `eye`: which buffers to build; `rays`: the primary rays of the image.
bool lightbuf_build(ListBuilder &b, const Box *eff, real cell, real margin, bool lights, bool eye, double rays) {
    pray_ctx *c = b.c;
    const Scene *s = b.s;
    Accel *a = b.a;
    int nl = s->lights.n, np = s->prims.n;
    a->lbuf = (LightBuf *)mem_zalloc(c, sizeof(LightBuf) * (size_t)(nl + 1));
    if (!a->lbuf) return false;
    a->nlbuf = nl;
    Array<int> start, cand, seen;
    Array<unsigned char> seen_cls;
    Array<real> key;
    Array<int> foot;  // per primitive: u0, u1, v0, v1 (u0 > u1: not on this face)
    start.init();
    cand.init();
    seen.init();
    seen_cls.init();
    key.init();
    foot.init();
    bool ok = key.reserve(c, 2 * np + 2) && foot.reserve(c, 4 * np + 4);
    for (int li = 0; ok && li <= nl; li++) {
        LightBuf &B = a->lbuf[li];
        if (li == nl ? !eye : !lights) continue;
        B.pieces = li == nl;
        B.point = B.pieces || s->lights[li].point;
        B.faces = B.point ? 6 : 1;
        B.o = B.pieces ? s->eye : B.point ? s->lights[li].v : r3(0, 0, 0);
        long total = 0, cells = 0;
        real eps = 0, r = 0;
        for (int fi = 0; fi < B.faces; fi++) {
            LightFace &F = B.f[fi];
            if (!face_layout(B, F, fi, B.point ? r3(0, 0, 0) : s->lights[li].v, a->g, cell, margin)) continue;
            F.base = (int)total;
            total += (long)F.n[0] * F.n[1] * F.n[2];
            F.cbase = (int)cells;
            cells += (long)F.n[0] * F.n[1];
        }
        // (a point light's cells are widened by CELL_SLACK; near the light, where that is less
        // than the margin, the ball takes over)
        if ((double)total * RAYS_PER_VOXEL > rays) {  // a small image: not worth it
            B.faces = 0;
            continue;
        }
        if (B.point) {
            eps = REAL_BIG;
            for (int fi = 0; fi < 6; fi++)
                if (B.f[fi].n[2] > 0 && B.f[fi].h[0] * CELL_SLACK < eps) eps = B.f[fi].h[0] * CELL_SLACK;
            r = tip_ball(margin, eps);
        }
        B.list = (int *)mem_alloc(c, sizeof(int) * (size_t)(total + 1));
        ok = B.list != NULL;
        for (int fi = 0; ok && fi < B.faces; fi++) {
            LightFace &F = B.f[fi];
            if (F.n[2] == 0) continue;
            // each primitive's cells (its footprint) and its depths, which decide its slabs
            key.n = 2 * np;
            foot.n = 4 * np;
            face_footprints(B, F, eff, np, r, B.point ? eps : margin, key.p, foot.p);
            // candidates per cell
            int ncell = F.n[0] * F.n[1], dim[3] = {F.n[0], F.n[1], 1};
            ok = bucket(c, dim, np, Footprint(foot.p), cand, start);
            if (!ok) break;
            // a face whose cells meet many primitives on average is left to the grid (and
            // costs no time to build)
            // (the eye's pieces are each only a slab deep)
            bool crowded = !B.pieces && start[ncell] > (double)ncell * LB_MAX_CAND / 2;
            for (int cel = 0; ok && cel < ncell; cel++) {
                if (over_time(c)) {
                    fail_cancelled(c);
                    ok = false;
                    break;
                }
                int *col = B.list + F.base + cel, stride = F.n[0] * F.n[1];  // the cell's voxels
                bool whole = true;  // first the zones that meet few enough primitives: -2
                int most = B.pieces ? LB_MAX_CAND / 2 : LB_MAX_CAND;
                for (int k = 0; k < F.n[2] && (whole || !B.pieces); k++) {
                    real w0, w1;
                    zone_depths(B, F, k, margin, &w0, &w1);
                    int many = 0;  // (counted only up to the limit)
                    for (int j = start[cel]; !crowded && many <= most && j < start[cel + 1]; j++)
                        many += key[2 * cand[j]] <= w1 && key[2 * cand[j] + 1] >= w0;
                    col[k * stride] = crowded || many > most ? -1 : -2;
                    whole = whole && col[k * stride] == -2;
                }
                if (B.pieces && !whole) {  // a primary ray walks all of its cell's pieces, or the grid
                    for (int k = 0; k < F.n[2]; k++) col[k * stride] = -1;
                    continue;
                }
                for (int k = 0, last = -1; ok && k < F.n[2]; k++) {
                    int &out = col[k * stride];
                    if (out == -1) continue;
                    real w0, w1;
                    zone_depths(B, F, k, margin, &w0, &w1);
                    ZoneClass in;
                    in.s = s;
                    in.eff = eff;
                    in.key = key.p;
                    in.w0 = w0;
                    in.w1 = w1;
                    lightbuf_zone(B, F, cel % F.n[0], cel / F.n[0], k, margin, eps, r, &in.z);
                    ok = lb_region(b, cand.p + start[cel], start[cel + 1] - start[cel], in);
                    const Array<int> &prims = b.rprims;
                    const Array<unsigned char> &cls = b.rcls;
                    // the next slab's zone often meets the same: then it has the same list
                    // (no memcmp/memcpy of an empty list: its pointer may still be null)
                    if (last >= 0 && prims.n == seen.n &&
                        (prims.n == 0 || (memcmp(prims.p, seen.p, sizeof(int) * (size_t)prims.n) == 0 &&
                                          memcmp(cls.p, seen_cls.p, (size_t)cls.n) == 0))) {
                        out = last;
                        continue;
                    }
                    out = ok ? lb_list(b, prims.p, cls.p, prims.n) : -1;
                    ok = out >= 0 && seen.reserve(c, prims.n + 1) && seen_cls.reserve(c, prims.n + 1);
                    if (!ok) break;
                    seen.n = seen_cls.n = prims.n;
                    if (prims.n) {
                        memcpy(seen.p, prims.p, sizeof(int) * (size_t)prims.n);
                        memcpy(seen_cls.p, cls.p, (size_t)cls.n);
                    }
                    last = out;
                }
            }
        }
        if (ok && B.pieces) ok = eye_runs(c, B, (int)cells);
    }
    start.release(c);
    cand.release(c);
    seen.release(c);
    seen_cls.release(c);
    key.release(c);
    foot.release(c);
    return ok;
}
#endif  // PRAY_NO_BUFFERS

// ---- [9b.5] Building: the whole structure ----
// The measure of a box that sizes a grid (auto_grid): the cube of its longest side times its
// fill, each side counted at least 1/16 of the longest.
double grid_measure(const Box &bx) {
    double ext = 0, m = 1;
    for (int l = 0; l < 3; l++) ext = (double)(bx.hi[l] - bx.lo[l]) > ext ? (double)(bx.hi[l] - bx.lo[l]) : ext;
    for (int l = 0; l < 3; l++) m *= (double)(bx.hi[l] - bx.lo[l]) > ext / 16 ? (double)(bx.hi[l] - bx.lo[l]) : ext / 16;
    return m;
}

// The k-th smallest of x[0 .. n) (x reordered).
real select_kth(real *x, int n, int k) {
    int lo = 0, hi = n - 1;
    while (lo < hi) {
        real pv = x[(lo + hi) / 2];
        int i = lo, j = hi;
        while (i <= j) {
            while (x[i] < pv) i++;
            while (pv < x[j]) j--;
            if (i <= j) {
                real t = x[i];
                x[i++] = x[j];
                x[j--] = t;
            }
        }
        if (k <= j) hi = j;
        else if (k >= i) lo = i;
        else break;
    }
    return x[k];
}

// A few parts far from all the others (moons beside a crowded scene) would stretch the grid's box
// and its voxels a thousandfold, leaving the crowd to nested grids and every ray that misses it
// a long walk through empty voxels. Such parts are left out of the box: a ray meets them in the
// list of the space outside it (one test each), and the crowd has a grid of its own size. Of
// the LONE_MAX parts farthest from the median of the parts' centres, the fewest that leave a
// box of least measure (each more halving it) are left out, when that box is at least
// LONE_SHRINK times smaller than the hull of them all.
const int LONE_MAX = 8;
const double LONE_SHRINK = 1000;

// The grid's box: the hull of the parts' boxes, but for the lone ones (the box is empty without
// parts); false on failure.
bool grid_region(pray_ctx *c, const Array<Box> &parts, Box *region) {
    int n = parts.n, far[LONE_MAX], nfar = 0;
    Box all, rest;
    for (int l = 0; l < 3; l++) all.lo[l] = rest.lo[l] = REAL_BIG, all.hi[l] = rest.hi[l] = -REAL_BIG;
    for (int i = 0; i < n; i++) box_hull(&all, parts[i]);
    *region = all;
    if (n <= 2 * LONE_MAX) return true;
    // A box LONE_SHRINK times smaller is at most 0.64 of the hull along the hull's longest axis
    // (the measure counts the other sides at least 1/16 of the longest): so a slab of 0.18 of it
    // at one end or the other meets only lone parts. Most scenes fail this at once.
    int ax = 0, ends[2] = {0, 0};
    for (int l = 1; l < 3; l++) ax = all.hi[l] - all.lo[l] > all.hi[ax] - all.lo[ax] ? l : ax;
    real cut = (all.hi[ax] - all.lo[ax]) * (real)0.18;
    for (int i = 0; i < n && (ends[0] <= LONE_MAX || ends[1] <= LONE_MAX); i++) {
        ends[0] += parts[i].lo[ax] < all.lo[ax] + cut;
        ends[1] += parts[i].hi[ax] > all.hi[ax] - cut;
    }
    if (ends[0] > LONE_MAX && ends[1] > LONE_MAX) return true;
    Array<real> x;
    x.init();
    if (!x.reserve(c, n)) return false;
    real mid[3];
    for (int l = 0; l < 3; l++) {
        for (int i = 0; i < n; i++) x.p[i] = (parts[i].lo[l] + parts[i].hi[l]) / 2;
        mid[l] = select_kth(x.p, n, n / 2);
    }
    // the parts farthest from the median (by the largest distance along an axis), farthest first
    for (int i = 0; i < n; i++) {
        real d = 0;
        for (int l = 0; l < 3; l++) {
            real e = parts[i].lo[l] - mid[l] > mid[l] - parts[i].hi[l] ? parts[i].lo[l] - mid[l] : mid[l] - parts[i].hi[l];
            d = e > d ? e : d;
        }
        x.p[i] = d;
        int k = nfar;  // its place among them
        while (k > 0 && x.p[far[k - 1]] < d) k--;
        if (k == LONE_MAX) continue;
        nfar += nfar < LONE_MAX;
        for (int j = nfar - 1; j > k; j--) far[j] = far[j - 1];
        far[k] = i;
    }
    // the box without the first k of them, for each k
    Box hull[LONE_MAX + 1];
    for (int i = 0; i < n; i++) {
        bool lone = false;  // (the distance first: only a tie with the last of them is looked up)
        for (int k = 0; nfar > 0 && x.p[i] >= x.p[far[nfar - 1]] && k < nfar; k++) lone = lone || far[k] == i;
        if (!lone) box_hull(&rest, parts[i]);
    }
    hull[nfar] = rest;
    for (int k = nfar - 1; k >= 0; k--) {
        hull[k] = hull[k + 1];
        box_hull(&hull[k], parts[far[k]]);
    }
    int best = 0;
    for (int k = 1; k <= nfar; k++)
        if (grid_measure(hull[k]) * 2 < grid_measure(hull[best])) best = k;
    if (grid_measure(hull[best]) * LONE_SHRINK <= grid_measure(all)) *region = hull[best];
    x.release(c);
    return true;
}

// The lists' plans (option plans 0: every list is evaluated in full).
pray_status accel_plans(pray_ctx *c, const Scene *s, Accel *a) {
    bool plans = opt_int(c, OPT_PLANS) != 0;
    int nn = s->nodes.n + 1;
    int *kids = (int *)mem_zalloc(c, sizeof(int) * (size_t)nn);
    int *solid = (int *)mem_alloc(c, sizeof(int) * (size_t)nn);
    pray_status st = kids && solid ? PRAY_OK : c->status;
    for (int j = 0; st == PRAY_OK && j < nn; j++) solid[j] = -1;
    for (int L = 0; st == PRAY_OK && L < a->off.n; L++) {
        if (over_time(c)) {
            st = fail_cancelled(c);
            break;
        }
        int where = plans ? list_plan(c, s, a->data.p + a->off[L], kids, solid, &a->plan) : -1;
        if (where == -2 || !a->plan_at.push(c, where))
            st = c->status;
    }
    mem_free(c, kids);
    mem_free(c, solid);
    return st;
}

// What the structure holds, into its memory and the statistics; once it is `built`, a light
// buffer without a list to give is dropped (it costs nothing), and a voxel whose list is not
// plain is left to the grid.
void accel_account(pray_ctx *c, Accel *a, bool built) {
    long lbv = 0, ebv = 0, eruns = 0;  // the light buffers' voxels, the eye's, its runs' numbers
    for (int i = 0; built && a->lbuf && i <= a->nlbuf; i++) {
        LightBuf &B = a->lbuf[i];
        long nv = 0;
        for (int f = 0; f < B.faces; f++) nv += (long)B.f[f].n[0] * B.f[f].n[1] * B.f[f].n[2];
        (B.pieces ? ebv : lbv) += nv;
        if (B.pieces) {
            eruns += B.nruns;
            continue;
        }
        bool any = false;  // a buffer without a list to give is dropped, and costs nothing
        for (long v = 0; v < nv; v++) {
            // a list answers a shadow ray in one evaluation when it is plain; else walking
            // the grid, which stops at the first blocker, is cheaper
            if (B.list[v] > 0 && !list_plain(a, B.list[v])) B.list[v] = -1;
            any = any || B.list[v] >= 0;
        }
        if (!any) B.faces = 0;
    }
    a->eye = a->lbuf && a->lbuf[a->nlbuf].faces ? &a->lbuf[a->nlbuf] : NULL;
    long nv = (long)a->g.n[0] * a->g.n[1] * a->g.n[2];
    long nested = 0;
    for (int i = 0; i < a->nested.n; i++) nested += (long)a->nested[i].n[0] * a->nested[i].n[1] * a->nested[i].n[2];
    a->memory = (double)sizeof(Accel) + (double)(nv + nested) * (sizeof(int) + 1) +
                (double)a->nested.cap * sizeof(Grid) + (double)a->data.cap * sizeof(int) +
                (double)a->off.cap * sizeof(int) + (double)(a->plan_at.cap + a->plan.cap) * sizeof(int) +
                (double)(a->lbuf ? a->nlbuf + 1 : 0) * sizeof(LightBuf) +
                (double)(lbv + eruns) * sizeof(int);
    c->stats.lightbuf_voxels = lbv;
    c->stats.eyebuf_voxels = ebv;
    c->stats.grid[0] = a->g.n[0];
    c->stats.grid[1] = a->g.n[1];
    c->stats.grid[2] = a->g.n[2];
    c->stats.voxels = nv;
    c->stats.nested_grids = a->nested.n;
    c->stats.nested_voxels = nested;
    c->stats.lists = a->off.n - 1;
    c->stats.areas = a->areas;
    c->stats.memory = a->memory;
}

// The grid's box (accel_build): with bounds, the finite boxes of the scene's parts (a union of a
// floor and furniture: the furniture's); otherwise, or when that finds nothing, the finite boxes
// of the primitives; in both cases but for a few lone ones far from the rest (grid_region).
// stk: room for a stack.
pray_status grid_box(pray_ctx *c, const Scene *s, bool bounds, Array<int> &stk, Box *region) {
    pray_status st = PRAY_OK;
    int np = s->prims.n;
    for (int l = 0; l < 3; l++) region->lo[l] = REAL_BIG, region->hi[l] = -REAL_BIG;
    Array<Box> parts;  // their finite boxes
    parts.init();
    if (!parts.reserve(c, np + s->nodes.n + 1)) st = c->status;
    if (st == PRAY_OK && bounds && s->root >= 0) {
        stk.n = 0;
        if (!stk.push(c, s->root)) st = c->status;
        while (st == PRAY_OK && stk.n) {
            int e = stk[--stk.n];
            const Box &bx = elem_box(s, e);
            if (e_is_node(e) && s->nodes[e_index(e)].op == O_UNION) {  // (its box: their hull)
                const Node &nd = s->nodes[e_index(e)];
                for (int i = 0; i < nd.n && st == PRAY_OK; i++)
                    if (!stk.push(c, s->kids[nd.k0 + i])) st = c->status;
            } else if (box_finite(bx)) {
                if (!box_empty(bx) && !parts.push(c, bx)) st = c->status;
            } else if (e_is_node(e) && s->nodes[e_index(e)].op == O_DIFF) {
                if (!stk.push(c, s->kids[s->nodes[e_index(e)].k0])) st = c->status;
            }
        }
    }
    for (int i = 0; st == PRAY_OK && parts.n == 0 && i < np; i++)
        if (box_finite(s->prims[i].box) && !parts.push(c, s->prims[i].box)) st = c->status;
    if (st == PRAY_OK && !grid_region(c, parts, region)) st = c->status;
    parts.release(c);
    if (bounds && s->root >= 0) box_clip(region, elem_box(s, s->root));
    return st;
}

// Build the acceleration structure: the lists of the grid's voxels and of the space around it,
// and the buffers of the lights and, for a render (`render`), of the eye.
pray_status accel_build(pray_ctx *c, Scene *s, bool render) {
    Accel *a = (Accel *)mem_zalloc(c, sizeof(Accel));
    if (!a) return c->status;
    s->accel = a;
    a->data.init();
    a->off.init();
    a->plan_at.init();
    a->plan.init();
    a->nested.init();
    a->freeze = opt_int(c, OPT_FREEZE);
    a->merge = opt_int(c, OPT_MERGE);
    // (the shadow cache's answer is the reference's when no surface lets more light through
    // than it receives: see shadow_probe)
    a->cache = opt_int(c, OPT_SHADOWCACHE);
    for (int i = 0; a->cache && i < s->prims.n; i++) a->cache = model_clear(s->prims[i].mat) <= 1;
    a->bounds = opt_int(c, OPT_BOUNDS);
    // (a render's ray is inside the solid only past a surface letting light through, or at start)
    bool lit = !render;
    for (int i = 0; s->iface && !lit && i < s->prims.n; i++) lit = model_clear(s->prims[i].mat) != 0;
    int inside = s->iface && !lit ? primaries_inside(c, s) : 1;
    if (inside < 0) return c->status;
    a->faces = s->iface && inside;
    a->left_out = s->iface && !inside;
    if (!a->off.push(c, 0)) return c->status;  // list 0: nothing can be hit
    for (int i = 0; i < LIST_HEAD; i++)
        if (!a->data.push(c, 0)) return c->status;
    ListBuilder b;
    if (!lb_init(b, c, s, a)) {
        lb_release(b);
        return c->status;
    }
    pray_status st = PRAY_OK;
    int np = s->prims.n;
    Box region;
    if (st == PRAY_OK && grid_box(c, s, a->bounds != 0, b.touched, &region)) st = c->status;
    int bounded = 0;  // primitives that reach into the grid's box
    for (int i = 0; i < np && !box_empty(region); i++) bounded += box_overlap(s->prims[i].box, region);
    double ext = 0, fill = 1;
    for (int l = 0; !box_empty(region) && l < 3; l++)
        if ((double)(region.hi[l] - region.lo[l]) > ext) ext = (double)(region.hi[l] - region.lo[l]);
    for (int l = 0; ext > 0 && l < 3; l++) {
        double f = (double)(region.hi[l] - region.lo[l]) / ext;
        fill *= f > 1.0 / 16 ? f : 1.0 / 16;
    }
    // the image's primary rays (samples): they size the grid and decide the buffers
    double aa = opt_int(c, OPT_ANTIALIAS), rays = (double)opt_int(c, OPT_WIDTH) * opt_int(c, OPT_HEIGHT) * aa * aa;
    int want = opt_int(c, OPT_GRID);
    if (want < 0) want = auto_grid(bounded, rays, fill);
    if (box_empty(region) || bounded == 0 || s->root < 0) want = 0;
    if (!(ext > 0) || !finite_num(ext)) want = 0;
    // voxels are cubes; the margin keeps classification safe from rounding in the traversal
    double mag = 0;
    for (int l = 0; want > 0 && l < 3; l++) {
        double m = fabs((double)region.lo[l]) > fabs((double)region.hi[l]) ? fabs((double)region.lo[l]) : fabs((double)region.hi[l]);
        if (m > mag) mag = m;
    }
    // With bounds, each primitive is placed in the grid by the intersection of the boxes from
    // it up to the root (prim_boxes); lists with materials always look there (lb_mixed).
    Box *eff = (Box *)mem_alloc(c, sizeof(Box) * (size_t)(np + 1)), *clipped = NULL;
    if (!eff || !prim_boxes(c, s, eff, a->bounds != 0)) st = c->status;
    else if (s->iface && !a->bounds && !((clipped = (Box *)mem_alloc(c, sizeof(Box) * (size_t)(np + 1))) &&
                                         prim_boxes(c, s, clipped, true)))
        st = c->status;
    b.obox = clipped ? clipped : eff;
    Array<int> cand, start;
    cand.init();
    start.init();
    // The layout: cubic voxels, a margin that keeps classification safe from rounding in the
    // traversal, the grid centred on the region. The voxel table and the references to the
    // primitives must fit the budget (option gridmem): otherwise the grid is made coarser.
    double budget = opt_int(c, OPT_GRIDMEM) * 1048576.0, margin = 0;
    long nv = 0;
    while (want > 0 && st == PRAY_OK) {
        a->g.h = (real)(ext / want);
        a->g.inv_h = (real)1 / a->g.h;
        margin = (double)a->g.h * 1e-6 + 64 * REAL_EPS * (mag + ext) * (want + 4);
        // far from the origin in low precision the voxels would be smaller than the rounding of
        // the positions: then no grid
        if (margin > (double)a->g.h / 4) {
            want = 0;
            break;
        }
        double vox = 1;
        for (int l = 0; l < 3; l++) {
            double len = (double)(region.hi[l] - region.lo[l]) + 2 * margin;
            a->g.n[l] = (int)ceil(len / (double)a->g.h);
            if (a->g.n[l] < 1) a->g.n[l] = 1;
            a->g.org[l] = (real)((double)(region.lo[l] + region.hi[l]) / 2 - a->g.n[l] * (double)a->g.h / 2);
            vox *= a->g.n[l];
        }
        double refs = vox <= 268435456.0 ? voxel_refs(a->g, eff, NULL, np, margin) : 0;
        if (vox <= 268435456.0 && refs <= 64.0 * 1048576 && (2 * vox + refs) * sizeof(int) + vox <= budget) {
            nv = (long)vox;
            break;
        }
        want = want > 1 ? (int)(want * 0.8) : 0;
    }
    if (want <= 0 || st != PRAY_OK) a->g.n[0] = a->g.n[1] = a->g.n[2] = 0;
    if (want > 0 && st == PRAY_OK) {
        for (int l = 0; l < 3; l++) a->g.top[l] = (real)((double)a->g.org[l] + a->g.n[l] * (double)a->g.h);
        a->g.voxel = (int *)mem_zalloc(c, sizeof(int) * (size_t)nv);
        // nested grids take what the budget leaves, and no more than NEST_PER_PRIM voxels for
        // each primitive: the scene decides, never the image
        GridPlan gp;
        gp.eff = eff;
        gp.obj = nest_objects(c, s);
        gp.round = 64 * REAL_EPS * (mag + ext);
        gp.budget = (budget - (double)nv * (2 * sizeof(int) + 1)) / 16;
        gp.budget = gp.budget < NEST_PER_PRIM * np ? gp.budget : NEST_PER_PRIM * np;
        if (!gp.obj || !a->g.voxel || !bucket(c, a->g.n, np, VoxelRange(a->g, eff, NULL, margin), cand, start) ||
            !grid_lists(b, a->g, gp, cand, start, margin, want + 4, opt_int(c, OPT_NEST)))
            st = c->status;
        for (int i = -1; st == PRAY_OK && i < a->nested.n; i++)
            if (!grid_areas(c, i < 0 ? a->g : a->nested[i], &a->areas)) st = c->status;
        mem_free(c, (void *)gp.obj);
    }
    // the space outside the grid (or everything): primitives not inside the grid's box are active
    if (st == PRAY_OK) {
        OuterClass out;
        out.a = a;
        out.eff = eff;
        cand.n = 0;
        for (int i = 0; i < np && st == PRAY_OK; i++)
            if (!cand.push(c, i)) st = c->status;
        a->outer = st == PRAY_OK && lb_region(b, cand.p, cand.n, out) ? lb_list(b, b.rprims.p, b.rcls.p, b.rprims.n) : -1;
        if (a->outer < 0) st = c->status;
    }
#ifndef PRAY_NO_BUFFERS
    bool lights = opt_int(c, OPT_SHADOWS) && opt_int(c, OPT_LIGHTBUFFER) && s->lights.n > 0;
    bool eye = render && opt_int(c, OPT_EYEBUFFER) && !s->parallel;
    if (st == PRAY_OK && a->g.n[0] > 0 && (lights || eye) && !lightbuf_build(b, eff, a->g.h, (real)margin, lights, eye, rays))
        st = c->status;
#else
    (void)render;
#endif
    cand.release(c);
    start.release(c);
    mem_free(c, eff);
    mem_free(c, clipped);
    lb_release(b);
    if (st == PRAY_OK) st = accel_plans(c, s, a);
    accel_account(c, a, st == PRAY_OK);
    return st;
}

// ---- [9b.6] Per ray: list evaluation with freezing (the one list evaluator) ----
// The primitive's interval along the current ray, computed at most once per ray.
inline const Span &span_get(const Scene *s, Scratch *w, const Ray &ray, int p, int self) {
    Span &sp = w->span[p];
    if (sp.stamp != w->ray) {
        sp.stamp = w->ray;
        w->k.tests += 1;
        sp.kind = prim_span(s->prims[p], ray, twin(s, p, self), &sp.t0, &sp.t1, w->span2 ? w->span2 + 2 * p : NULL);
    }
    return sp;
}

// Frozen for this ray (3.5): the status of the parent is fixed, or the parent is frozen. The
// signal reaches a node's subnodes lazily: each evaluation passes it down its active nodes, so
// fixing a node costs one stamp however large its subtree.
inline bool frozen(const Scratch *w, int parent) {
    return parent >= 0 && (w->nfixed[parent] == w->ray || w->nfrozen[parent] == w->ray);
}

// The root keeps status st for the rest of the ray: nothing further can be seen on it, but where
// materials meet a face between two may still come inside the solid.
inline void root_settles(const Scene *s, Scratch *w, bool st) {
    if (!st || !s->accel->mixed) w->root_fixed = 1;
}

// Element e is known to keep status st for the rest of the ray: tell its parent, which may then
// know its own status for good and freeze its other children (3.5).
void settle(const Scene *s, Scratch *w, int e, bool st) {
    for (;;) {
        int p = elem_parent(s, e);
        if (p < 0) {
            if (e == s->root) root_settles(s, w, st);
            return;
        }
        if (frozen(w, p) || w->nfixed[p] == w->ray) return;
        const Node &nd = s->nodes[p];
        bool first = elem_first(s, e);
        int fix = -1;
        switch (nd.op) {
        case O_UNION: fix = st ? 1 : -1; break;
        case O_INTER: fix = st ? -1 : 0; break;
        case O_DIFF: fix = (first ? !st : st) ? 0 : -1; break;
        default: fix = !st; break;
        }
        if (fix < 0) return;
        w->nfixed[p] = w->ray;
        w->nfixval[p] = (unsigned char)fix;
        if (2 * p + 1 == s->root) {  // no need to freeze
            root_settles(s, w, fix != 0);
            return;
        }
        e = 2 * p + 1;
        st = fix != 0;
    }
}

// Primitive p, with status `in` at a and the span (kind, t0, t1), keeps that status for the rest
// of the ray: settle it when that decides its parent (Prim::settles).
inline void settle_prim(const Scene *s, Scratch *w, int p, bool in, int kind, real t0, real t1, real a) {
    if ((s->prims[p].settles & (in ? 2 : 1)) && (kind != SPAN || t1 <= a || (t0 <= a && t1 >= REAL_INF)))
        settle(s, w, 2 * p, in);
}

// Like propagate (section 9), but a node whose status is fixed for the ray stops the change.
bool propagate_live(const Scene *s, Scratch *w, int e, bool st) {
    for (;;) {
        int p = elem_parent(s, e);
        if (p < 0) return e == s->root;
        if (w->nfixed[p] == w->ray) return false;
        const Node &nd = s->nodes[p];
        bool old = w->nstat[p] != 0;
        if (elem_first(s, e) && nd.op == O_DIFF) w->nfirst[p] = st;
        else w->cnt[p] += st ? 1 : -1;
        bool now = node_status(nd, w->cnt[p], w->nfirst[p]);
        if (now == old) return false;
        w->nstat[p] = now;
        st = now;
        e = 2 * p + 1;
    }
}

inline void bump(const Scene *s, Scratch *w, int e) {
    int p = elem_parent(s, e);
    if (p >= 0 && w->nfixed[p] != w->ray) tally(s, w, e);
}

// The solids of a plan (list_plan) whose node's status is fixed for this ray: Hull::fixed 1 when
// the solid is outside for good, 2 inside; 0 not fixed. Their members are frozen.
inline void plan_fixed(Scratch *w, const int *solids, int k) {
    int j = solids[2 * k];
    w->hull[k].fixed = w->nfixed[j] != w->ray ? 0 : 1 + ((w->nfixval[j] != 0) != (solids[2 * k + 1] != 0));
}

// A primitive of a plan: its solid, -1 standing alone, and whether it is turned inside out.
inline int plan_solid(const int *code, int i) { return (code[i] >> 2) - 1; }

// Solid k of a plan is outside for the rest of the ray (one of its members is): its node's
// status is fixed for the ray (3.5), which freezes its members here and in every later list.
// (A solid is an intersection of its members, so one member decides, at whatever depth of the
// tree it stands.)
inline void fix_solid(const Scene *s, Scratch *w, const int *solids, int k) {
    int j = solids[2 * k];
    w->nfixed[j] = w->ray;
    w->nfixval[j] = (unsigned char)solids[2 * k + 1];
    w->hull[k].fixed = 1;
    if (2 * j + 1 == s->root) root_settles(s, w, solids[2 * k + 1] != 0);
}

// The flat sweep of a list with a plan (list_plan), holed or not, on the part (a, b] of the ray
// (and t < tmax): each group is inside where the ray is in one of its members, each solid where
// it is in all of its members, the root where it is in one solid or more. The crossings are taken
// in order, and each changes one primitive, perhaps its group, perhaps its solid, perhaps the
// root. A solid whose node is fixed for the ray keeps its status and its members are frozen
// (3.5); primitives standing alone are not settled here (they have nothing under them to
// freeze). Returns true when `visit` stopped or nothing further can be seen.
template <class Visit>
bool eval_flat(const Scene *s, const Accel *A, Scratch *w, const Ray &ray, const int *prims, int np, const int *plan,
               real a, real b, real tmax, int self, Visit &visit) {
    int ns = plan[0], ng = plan[2];
    const int *code = plan + PLAN_HEAD, *group = ng ? code + np : NULL, *gsolid = code + 2 * np,
              *solids = code + (ng ? 2 * np + ng : np);
    const bool freeze = A->freeze != 0;
    Hull *hull = w->hull, *gh = hull + ns;  // (the groups' counts after the solids')
    bool fixed = false;  // some solid is fixed (then its members are skipped)
    for (int k = 0; k < ns; k++) {
        hull[k].need = hull[k].have = 0;
        plan_fixed(w, solids, k);
        fixed = fixed || hull[k].fixed;
    }
    for (int g = 0; g < ng; g++) gh[g].have = 0;
    int in = 0, nc = 0;  // solids (and primitives standing alone) the ray is in
    for (int i = 0; i < np; i++) {
        int p = prims[i], c = code[i], k = plan_solid(code, i);
        if (fixed && k >= 0 && hull[k].fixed) {
            w->k.frozen += 1;
            continue;
        }
        const Span &sp = span_get(s, w, ray, p, self);
        bool st = (sp.kind == SPAN_ALL || (sp.kind == SPAN && sp.t0 <= a && a < sp.t1)) != (c & 1);
        if (k < 0) in += st;
        else if (group && group[i] >= 0) gh[group[i]].have += st;  // a group is in when a member is
        else {
            // a decisive member outside for the rest of the ray: its solid too
            if (!st && (c & 2) && freeze && (sp.kind != SPAN || (c & 1 ? sp.t0 <= a && sp.t1 >= REAL_INF : sp.t1 <= a))) {
                fix_solid(s, w, solids, k);
                if (w->root_fixed) return true;  // the root keeps its status from a on
                fixed = true;
                continue;
            }
            hull[k].need++, hull[k].have += st;
        }
        if (sp.kind != SPAN) continue;
        add_cross(w, &nc, sp.t0, i, 1, a, b, tmax);  // (the list's position: its plan)
        add_cross(w, &nc, sp.t1, i, 0, a, b, tmax);
    }
    if (nc == 0) return false;
    for (int g = 0; g < ng; g++) hull[gsolid[g]].need++, hull[gsolid[g]].have += gh[g].have > 0;
    for (int k = 0; k < ns; k++) in += hull[k].fixed ? hull[k].fixed == 2 : hull[k].need == hull[k].have;
    // (the list's primitives are in the order of their numbers, so the crossings sort as the
    // full evaluation's do)
    if (nc > 1) sort_crossings(w->cross, nc);
    bool root = in > 0;
    for (int j = 0; j < nc;) {
        real t = w->cross[j].t;
        bool before = root;
        int last = -1;  // crossings at the same t together, as in the full evaluation
        for (; j < nc && w->cross[j].t == t; j++) {
            const Cross &x = w->cross[j];
            int i = x.prim, c = code[i], k = plan_solid(code, i), st = (x.enter != 0) != (c & 1) ? 1 : -1;
            if (k < 0) in += st;
            else {
                Hull &u = hull[k];
                if (fixed && u.fixed) continue;
                if (group && group[i] >= 0) {  // the group's member: the group changes, or nothing
                    Hull &G = gh[group[i]];
                    bool gwas = G.have > 0;
                    G.have += st;
                    if (gwas == (G.have > 0)) continue;
                }
                bool was = u.have == u.need;
                u.have += st;
                if (was != (u.have == u.need)) in += was ? -1 : 1;
            }
            if ((in > 0) != root) root = !root, last = j;
            if (st < 0 && (c & 2) && freeze && (!(c & 1) || w->span[prims[i]].t1 >= REAL_INF)) {
                fix_solid(s, w, solids, k);  // (left for good: it is entered once at most)
                fixed = true;
            }
        }
        if (root != before && last >= 0 && !visit(solid_hit(t, prims[w->cross[last].prim], w->cross[last].enter, root)))
            return true;
        if (w->root_fixed) return true;
    }
    return false;
}

// The nearest entry of a plain list (list_plan): a union of solids, none inside for the whole
// region. While the ray is outside them all, the first visible surface is the nearest entry.
// An intersection is entered at the latest entry of its members and left at the earliest exit;
// a half-space turned inside out is entered where the ray leaves the half-space. A solid whose
// node is fixed for the ray is outside for good, or the flat sweep decides; its members are
// frozen (3.5). Returns 1 when `visit` stopped or nothing further can be seen, 0 when nothing
// is entered in (a, b], -1 when the flat sweep must decide from *a on (a solid inside at a,
// entries at the same t, a grazing touch, or the visitor going on through the solid entered).
// (Primitives standing alone are not settled: they have nothing under them to freeze.)
template <class Visit>
int eval_plain(const Scene *s, const Accel *A, Scratch *w, const Ray &ray, const int *prims, int np, const int *plan,
               real *pa, real b, real tmax, int self, Visit &visit) {
    int ns = plan[0];
    const int *code = plan + PLAN_HEAD, *solids = code + np;  // (a plain plan has no groups)
    real a = *pa;
    const bool freeze = A->freeze != 0;
    Hull *hull = w->hull;
    bool fixed = false;  // some solid is fixed (then its members are skipped)
    for (int k = 0; k < ns; k++) {
        Hull &u = hull[k];
        u.t0 = -REAL_INF;
        u.t1 = REAL_INF;
        u.prim = -1;
        u.enter = 1;
        u.tie = 0;
        plan_fixed(w, solids, k);
        if (u.fixed == 2) return -1;
        if (u.fixed) u.t1 = -REAL_INF, fixed = true;
    }
    int first = -1, first_enter = 1;
    real tf = 0;
    for (int i = 0; i < np + ns; i++) {
        int p, kind, enter;
        real t0 = 0, t1 = 0;
        bool tie = false;
        if (i < np) {  // the primitives: the members of intersections are gathered first
            int k = plan_solid(code, i);
            if (fixed && k >= 0 && hull[k].fixed) {
                w->k.frozen += 1;
                continue;
            }
            // (computed afresh, not through span_get: cheaper than its book-keeping here)
            p = prims[i];
            w->k.tests += 1;
            kind = prim_span(s->prims[p], ray, twin(s, p, self), &t0, &t1);
            enter = !(code[i] & 1);
            if (!enter) {  // a half-space (one end of its span infinite) turned inside out
                if (kind != SPAN) kind = kind == SPAN_ALL ? SPAN_NONE : SPAN_ALL;
                else if (t0 == -REAL_INF) t0 = t1, t1 = REAL_INF;
                else t1 = t0, t0 = -REAL_INF;
            }
            if (k >= 0) {
                Hull &u = hull[k];
                if (freeze && (code[i] & 2) && (kind == SPAN_NONE || (kind == SPAN && t1 <= a))) {
                    fix_solid(s, w, solids, k);  // a member outside for the rest of the ray
                    if (w->root_fixed) return 1;
                    u.t1 = -REAL_INF;
                    fixed = true;
                    continue;
                }
                if (kind == SPAN_NONE) u.t1 = -REAL_INF;
                if (kind != SPAN) continue;
                if (t0 == u.t0) u.tie = 1;
                if (t0 > u.t0) u.t0 = t0, u.prim = p, u.enter = enter, u.tie = 0;
                if (t1 < u.t1) u.t1 = t1;
                continue;
            }
        } else {  // then the intersections, as solids
            const Hull &u = hull[i - np];
            p = u.prim;
            enter = u.enter;
            t0 = u.t0;
            t1 = u.t1;
            tie = u.tie != 0;
            kind = t0 <= t1 ? SPAN : SPAN_NONE;  // inside from -infinity when no member is entered
        }
        if (kind == SPAN_NONE || (kind == SPAN && t1 <= a)) continue;
        if (kind != SPAN || !(t0 > a)) return -1;  // inside at a
        if (t0 > b || !(t0 < tmax) || (first >= 0 && t0 > tf)) continue;
        if (!(t1 > t0) || tie || (first >= 0 && t0 == tf)) return -1;
        first = p;
        first_enter = enter;
        tf = t0;
    }
    if (first < 0) return 0;
    if (!visit(solid_hit(tf, first, first_enter, true))) return 1;
    *pa = tf;  // the visitor goes on through the solid: the rest by the flat sweep
    return -1;
}

// The full evaluation of a list (3.4, 3.5): initialise the active part of the status tree at a,
// then sweep the crossings in (a, b] (and t < tmax), freezing what settles. Returns true when
// `visit` stopped or nothing further can be seen.
template <class Visit>
bool eval_full(const Scene *s, const Accel *A, Scratch *w, const Ray &ray, const int *d, real a, real b, real tmax,
               int self, Visit &visit) {
    int na = d[0], np = d[1];
    const int *nodes = d + LIST_HEAD, *prims = list_prims(d);
    for (int i = na - 1; i >= 0; i--) {  // parents first: pass freezing down
        int j = nodes[3 * i];
        w->cnt[j] = nodes[3 * i + 1];
        w->nfirst[j] = (unsigned char)nodes[3 * i + 2];
        if (frozen(w, s->nodes[j].parent)) w->nfrozen[j] = w->ray;
    }
    // check actions: the primitive's status at a and its crossings in (a, b]; a primitive that
    // keeps its status for the rest of the ray is settled (3.5), which may freeze others
    int nc = 0;
    for (int i = 0; i < np; i++) {
        int p = prims[i];
        if (frozen(w, s->prims[p].parent)) {
            w->k.frozen += 1;
            continue;
        }
        const Span &sp = span_get(s, w, ray, p, self);
        int kind = sp.kind;
        real t0 = sp.t0, t1 = sp.t1;
        bool in = kind == SPAN_ALL || (kind == SPAN && t0 <= a && a < t1);
        if (kind == SPAN2) {  // a torus: two intervals; it settles after the second (settle_prim)
            const real *t23 = w->span2 + 2 * p;
            in = (t0 <= a && a < t1) || (t23[0] <= a && a < t23[1]);
            real t[4] = {t0, t1, t23[0], t23[1]};
            for (int j = 0; j < 4; j++) add_cross(w, &nc, t[j], p, !(j & 1), a, b, tmax);
            kind = SPAN;
            t0 = t23[0];
            t1 = t23[1];
        }
        w->pstat[p] = in;
        if (kind == SPAN && sp.kind == SPAN) {
            add_cross(w, &nc, t0, p, 1, a, b, tmax);
            add_cross(w, &nc, t1, p, 0, a, b, tmax);
        }
        if (A->freeze) settle_prim(s, w, p, in, kind, t0, t1, a);
        if (in) bump(s, w, 2 * p);
    }
    if (w->root_fixed) return true;  // the root keeps its status from a on
    if (nc == 0) return false;       // nothing crosses in (a, b]: the root keeps its status
    for (int i = 0; i < na; i++) {
        int j = nodes[3 * i];
        if (w->nfrozen[j] == w->ray) continue;
        bool st = w->nfixed[j] == w->ray ? w->nfixval[j] != 0 : node_status(s->nodes[j], w->cnt[j], w->nfirst[j]);
        w->nstat[j] = st;
        if (st) bump(s, w, 2 * j + 1);
    }
    bool root = e_is_node(s->root) ? w->nstat[e_index(s->root)] != 0 : w->pstat[e_index(s->root)] != 0;
    if (nc > 1) sort_crossings(w->cross, nc);
    for (int i = 0; i < nc;) {
        real t = w->cross[i].t;
        bool before = root;
        int last = -1;
        for (; i < nc && w->cross[i].t == t; i++) {
            const Cross &x = w->cross[i];
            if (frozen(w, s->prims[x.prim].parent)) continue;
            bool st = x.enter != 0;
            if ((w->pstat[x.prim] != 0) == st) continue;
            w->pstat[x.prim] = st;
            if (propagate_live(s, w, 2 * x.prim, st)) {
                root = !root;
                last = i;
            }
            // (a torus left for good: at the end of its second interval)
            const Span &sp = w->span[x.prim];
            if (A->freeze && (s->prims[x.prim].settles & (st ? 2 : 1)) &&
                (!st ? sp.kind != SPAN2 || x.t >= w->span2[2 * x.prim + 1] : sp.t1 >= REAL_INF))
                settle(s, w, 2 * x.prim, st);
        }
        if (root != before && last >= 0 && !visit(solid_hit(t, w->cross[last].prim, w->cross[last].enter, root)))
            return true;
        if (w->root_fixed) return true;
    }
    return false;
}

// owner in the region of a list with materials, from its materials' part x (LIST_HEAD), which
// lists every element the region touches with the children owner looks at (lb_mixed_list):
// from the root, its last entry.
int owner_mixed(const Scene *s, const Scratch *w, const int *x) {
    const int *nodes = x + 1;
    for (int i = x[0] - 1;;) {
        const int *ch = x + nodes[4 * i + 3];
        int op = s->nodes[nodes[4 * i]].op, next = -1;
        for (int k = 1; k <= ch[0] && next == -1 && op != O_COMPL; k++) {
            int c = ch[k];
            if (c == -1) return -1;  // (inside only through a complement)
            if (op != O_UNION || c < -1 || (c & 1 ? w->nstat[nodes[4 * (c >> 1)]] : w->pstat[c >> 1])) next = c;
        }
        if (next == -1) return -1;
        if (next < -1) return -2 - next;
        if (!(next & 1)) return next >> 1;
        i = next >> 1;
    }
}

// The evaluation of a list with materials d (LIST_HEAD) on (a, b], from where a plain plan's
// nearest entry left off (eval_list): the reference's sweep on the region. Every element
// of its materials' part gets its status at a from the spans of its primitives (and of those
// inside the whole region, counted); every element left out keeps the status it has in the whole
// region. Freezing is not used: a face between two materials may come while the root's status
// is fixed.
template <class Visit>
PRAY_NOINLINE bool eval_mixed(const Scene *s, Scratch *w, const Ray &ray, const int *d, real a, real b, real tmax,
                              int self, Visit &visit) {
    const int *x = list_prims(d) + d[1], *nodes = x + 1;
    int na = x[0], nc = 0, hits = 0;
    for (int i = 0; i < na; i++) {
        int j = nodes[4 * i];
        w->cnt[j] = nodes[4 * i + 1];
        w->nfirst[j] = (unsigned char)nodes[4 * i + 2];
    }
    for (int i = 0; i < na; i++) {  // (the primitives to check: in the children's lists)
        const int *ch = x + nodes[4 * i + 3];
        for (int k = 1; k <= ch[0]; k++) {
            if (ch[k] < 0 || (ch[k] & 1)) continue;
            int p = ch[k] >> 1;
            const Span &sp = span_get(s, w, ray, p, self);
            real t[4] = {sp.t0, sp.t1, 0, 0};
            if (sp.kind == SPAN2) t[2] = w->span2[2 * p], t[3] = w->span2[2 * p + 1];
            prim_at(s, w, p, sp.kind, t, a, b, tmax, &nc);
        }
    }
    for (int i = 0; i < na; i++) {  // (children first)
        int j = nodes[4 * i];
        w->nstat[j] = node_status(s->nodes[j], w->cnt[j], w->nfirst[j]);
        if (w->nstat[j]) tally(s, w, 2 * j + 1);
    }
    bool root = w->nstat[e_index(s->root)] != 0;  // (the root is a node: two primitives meet)
    return sweep_crossings(s, w, nc, root, visit, &hits, x);
}

// Evaluate list L on the part (a, b] of the ray (and t < tmax): the one list evaluator. A list
// with a plan takes its shortcuts, the nearest entry when it is plain, else (or when the visitor
// goes on from there) the flat sweep, or a list with materials its sweep; any other is evaluated
// in full. All but the materials' sweep freeze what settles (3.5). Returns true when `visit`
// stopped or nothing further can be seen on the ray.
template <class Visit>
bool eval_list(const Scene *s, const Accel *A, Scratch *w, const Ray &ray, int L, real a, real b, real tmax,
               int self, Visit &visit) {
    if (L == 0) return false;
    const int *d = A->data.p + A->off[L];
    w->k.checks += d[1];
    w->k.set_in += d[2];
    w->k.set_out += d[3];
    int at = A->plan_at[L];
    const int *plan = at >= 0 ? A->plan.p + at : NULL;
    if (plan && !plan[1]) {
        int r = eval_plain(s, A, w, ray, list_prims(d), d[1], plan, &a, b, tmax, self, visit);
        if (r >= 0) return r != 0;
    }
    if (d[4]) return eval_mixed(s, w, ray, d, a, b, tmax, self, visit);
    if (!plan) return eval_full(s, A, w, ray, d, a, b, tmax, self, visit);
    return eval_flat(s, A, w, ray, list_prims(d), d[1], plan, a, b, tmax, self, visit);
}

// ---- [9b.7] Per ray: stretch sources (grid walk, light buffer voxel, eye buffer cell) ----
// Where the ray meets the box: [*t0, *t1]; false when it misses. `inv` holds the reciprocals
// of the direction's components, 0 for a ray parallel to that axis.
bool ray_box(const Ray &r, const real *inv, const real *lo, const real *hi, real *t0, real *t1) {
    real a = -REAL_INF, b = REAL_INF;
    for (int l = 0; l < 3; l++) {
        real o = comp(r.o, l);
        if (inv[l] == 0) {
            if (o < lo[l] || o > hi[l]) return false;
            continue;
        }
        real u = (lo[l] - o) * inv[l], v = (hi[l] - o) * inv[l];
        real n = u < v ? u : v, f = u < v ? v : u;
        a = n > a ? n : a;
        b = f < b ? f : b;
    }
    *t0 = a;
    *t1 = b;
    return a <= b;
}

// Point p in the box [lo, hi] (false when not a number).
inline bool in_box(R3 p, const real *lo, const real *hi) {
    return p.x >= lo[0] && p.x <= hi[0] && p.y >= lo[1] && p.y <= hi[1] && p.z >= lo[2] && p.z <= hi[2];
}

// Where a ray that starts in the box [lo, hi] (in_box) leaves it: ray_box's *t1, the same float,
// without its call; its *t0 is at most 0 then.
inline real box_exit(const Ray &r, const real *inv, const real *lo, const real *hi) {
    real b = REAL_INF;
    for (int l = 0; l < 3; l++) {
        real f = ((inv[l] > 0 ? hi[l] : lo[l]) - comp(r.o, l)) * inv[l];
        b = inv[l] != 0 && f < b ? f : b;
    }
    return b;
}

// The reciprocals of the direction's components for ray_box: 0 for a ray parallel to that axis
// (1 / 0 is infinite), or so nearly that 1 / d overflows.
inline void ray_inverse(const Ray &ray, real *inv) {
    for (int l = 0; l < 3; l++) {
        real q = (real)1 / comp(ray.d, l);
        inv[l] = q - q == 0 ? q : 0;
    }
}

// The smallest of three distances and its axis, ties to the later axis (selects, not branches:
// the choice is a coin toss for a branch predictor).
inline real nearest(const real *v, int *axis) {
    int ax = 0;
    real near = v[0];
    if (v[1] <= near) ax = 1, near = v[1];
    if (v[2] <= near) ax = 2, near = v[2];
    *axis = ax;
    return near;
}

// A source covers a part (ta, tb] of the ray inside the grid's box, and cuts it into stretches
// with their lists: span() finds the part (false when the ray misses it), walk() gives the
// stretches from ta to tb to `out`, and returns true when `out` stopped.

// The grid (3.3, 3.6): leading-axis traversal through the voxels, an area of equal lists (and
// the voxels a jump crosses) being one stretch.
struct GridSource {
    const Accel *A;
    const Grid &G;
    const Ray &ray;
    real inv[3];  // the direction's reciprocals (ray_inverse)
    // the direction's components (0 along an axis the ray is parallel to) and their signs: worked
    // out by span() for a ray that meets the grid's box, and handed to the walks of nested grids
    mutable real dir[3];
    mutable int step[3];
    GridSource(const Accel *A_, const Ray &ray_) : A(A_), G(A_->g), ray(ray_) { ray_inverse(ray, inv); }
    // a nested grid's, for the same ray
    GridSource(const GridSource &up, const Grid &G_) : A(up.A), G(G_), ray(up.ray) {
        for (int l = 0; l < 3; l++) inv[l] = up.inv[l], dir[l] = up.dir[l], step[l] = up.step[l];
    }
    bool span(real *ta, real *tb) const {
        *ta = 0;
        if (in_box(ray.o, G.org, G.top)) *tb = box_exit(ray, inv, G.org, G.top);
        else if (!ray_box(ray, inv, G.org, G.top, ta, tb)) return false;
        if (!(*tb > 0)) return false;
        for (int l = 0; l < 3; l++) {
            dir[l] = inv[l] == 0 ? 0 : comp(ray.d, l);
            step[l] = dir[l] > 0 ? 1 : dir[l] < 0 ? -1 : 0;
        }
        return true;
    }
    template <class Out>
    bool walk(Out &out, real t, real tend) const;
};

// A stretch of one list, the empty list passed over.
template <class Out>
inline bool rest_stretch(Out &out, int L, real a, real b) {
    if (L > 0) return out(L, a, b);
    out.pass(a, b);
    return false;
}

// The boundaries of the three axes come at regular intervals along the ray; the next voxel is
// across the nearest one. Distances are kept as ray parameters (the leading-axis distance over
// the leading component of the direction), so a step is two comparisons and one addition. With
// merging, a voxel with the list of the one before is a move, not a new stretch; and a voxel
// whose reach is r (reach_build) lets the ray jump to where it leaves the cube of voxels within r.
template <class Out>
bool GridSource::walk(Out &out, real t, real tend) const {
    R3 p = ray.o + ray.d * t;
    int ix[3], left[3];      // left: voxels ahead along each axis inside the grid
    real next[3], delta[3];
    for (int l = 0; l < 3; l++) {
        real g = (comp(p, l) - G.org[l]) * G.inv_h;  // clamped before the cast
        ix[l] = !(g > 0) ? 0 : g >= (real)G.n[l] ? G.n[l] - 1 : (int)g;
        left[l] = step[l] > 0 ? G.n[l] - 1 - ix[l] : step[l] < 0 ? ix[l] : 0;
        next[l] = step[l] == 0 ? REAL_INF : (G.org[l] + (real)(ix[l] + (step[l] > 0)) * G.h - comp(ray.o, l)) * inv[l];
        delta[l] = G.h * (inv[l] < 0 ? -inv[l] : inv[l]);
    }
    int run = -1;  // the list of the area being crossed
    real run_a = t;
    long at = voxel_index(G, ix);  // the voxel the ray is in
    long stride[3];  // a step along each axis, in voxels
    stride[0] = step[0];
    stride[1] = (long)step[1] * G.n[0];
    stride[2] = (long)step[2] * G.n[0] * G.n[1];
    bool merge = A->merge != 0;
    long steps = 0, moves = 0;  // counted here, added to the counters once per ray
    bool stopped = false;
    for (;;) {
        PRAY_ASSERT(at >= 0 && at < (long)G.n[0] * G.n[1] * G.n[2]);
        int L = G.voxel[at];
        steps++;
        if (L < 0) {  // a grid of its own: its walk up to where the ray leaves this voxel
            if (run == 0) out.pass(run_a, t);
            else if (run > 0 && out(run, run_a, t)) {
                stopped = true;
                break;
            }
            // (before and after its box, the rest of the voxel)
            int ax;
            real near = nearest(next, &ax), exit = near < tend ? near : tend, ta, tb;
            exit = exit > t ? exit : t;
            const Grid &N = A->nested[-1 - L];
            if (!ray_box(ray, inv, N.org, N.top, &ta, &tb)) ta = tb = exit;
            ta = ta > t ? ta : t;
            tb = tb < exit ? tb : exit;
            if (!(ta < tb)) ta = tb = exit;
            GridSource sub(*this, N);
            if ((ta > t && rest_stretch(out, N.rest, t, ta)) || (ta < tb && sub.walk(out, ta, tb)) ||
                (tb < exit && rest_stretch(out, N.rest, tb, exit))) {
                stopped = true;
                break;
            }
            run = -1;
            run_a = exit;
        } else if (L == run && merge) {
            moves++;  // same list: a move, no evaluation
        } else {
            if (run == 0) out.pass(run_a, t);
            else if (run > 0 && out(run, run_a, t)) {
                stopped = true;
                break;
            }
            run = L;
            run_a = t;
        }
        int r = merge ? G.reach[at] : 0;
        int ax;
        if (r < 2) {
            real near = nearest(next, &ax);
            real exit = near < tend ? near : tend;
            t = exit > t ? exit : t;
            if (exit >= tend) break;
            if (--left[ax] < 0) break;
            at += stride[ax];
            next[ax] += delta[ax];
            continue;
        }
        // a jump: every voxel within r of this one has its list; go to where the ray leaves
        // that cube, m[l] voxels further along axis l at most
        int m[3];
        real e[3];
        for (int l = 0; l < 3; l++) {
            m[l] = left[l] < r ? left[l] : r;
            // (delta may be infinite for a direction of ~1e-308: no 0 x infinity)
            e[l] = m[l] > 0 ? next[l] + (real)m[l] * delta[l] : next[l];  // no step along l: infinite
        }
        real near = nearest(e, &ax);
        real exit = near < tend ? near : tend;
        t = exit > t ? exit : t;
        if (exit >= tend) break;
        // across the boundary of axis ax; along the others, across the boundaries before it
        for (int l = 0; l < 3; l++) {
            int k = m[l] + 1;
            if (l != ax) {  // (slope: voxels per unit of t)
                real slope = (dir[l] < 0 ? -dir[l] : dir[l]) * G.inv_h, f = (near - next[l]) * slope;
                k = step[l] == 0 || !(f >= 0) ? 0 : f < (real)m[l] ? (int)f + 1 : m[l];
            }
            if (k == 0) continue;
            left[l] -= k;
            at += stride[l] * k;
            next[l] += (real)k * delta[l];
        }
        if (left[ax] < 0) break;
    }
    out.w->k.steps += (double)steps;
    out.w->k.moves += (double)moves;
    // the last stretch ends where the ray leaves the grid's box, whatever rounding the stepping
    // gathered, so that it meets the stretch after the grid without a gap
    if (stopped) return true;
    if (run > 0) return out(run, run_a, tend);
    out.pass(run_a, tend);
    return false;
}

// The list for a shadow ray from x towards the buffer's light, and the part (*ta, *tb] of the
// ray in that list's zone; before and after it the ray is outside the grid's box, where the
// outer list holds. `outer` alone when the ray misses the grid's box; -1 when x is in no voxel's
// reach (then the grid is walked).
inline int lightbuf_find(const LightBuf &B, int outer, R3 x, real tmax, real *ta, real *tb) {
    if (B.faces == 0) return -1;
    R3 m = x - B.o;
    const LightFace &F = B.f[B.point ? cube_face(m) : 0];
    real g[3] = {dot(m, F.e[0]), dot(m, F.e[1]), dot(m, F.e[2])};
    *ta = 0;
    *tb = tmax;
    if (B.point) {
        if (!(g[2] > 0)) return -1;  // at the light, or not a number
        if (F.n[2] == 0) return outer;
        real k = (real)1 / g[2];
        g[0] *= k;
        g[1] *= k;
    }
    // (a point light's zones are widened: CELL_SLACK)
    int cell, in = face_cell(F, g[0], g[1], B.point ? CELL_SLACK : 0, &cell);
    if (in <= 0) return in < 0 ? -1 : outer;  // not a number; beside the grid's box
    real k = (g[2] - F.lo[2]) * F.inv[2];
    if (k != k) return -1;
    int slab;
    if (!B.point) {  // w grows towards the light
        if (!(k < (real)F.n[2])) return outer;  // past the box already
        *tb = B.top - g[2];
        slab = k < 0 ? 0 : (int)k;
        if (k < 0) *ta = F.lo[2] - g[2];  // below the box: reaches it there
    } else {         // w shrinks towards the light
        if (k < 0) return outer;  // between the light and the box
        slab = k < (real)F.n[2] ? (int)k : F.n[2] - 1;
        if (!(k < (real)F.n[2])) *ta = tmax * ((real)1 - (F.lo[2] + (real)F.n[2] * F.h[2]) / g[2]);  // beyond it
    }
    return B.list[F.base + slab * F.n[1] * F.n[0] + cell];
}

// A light buffer's voxel (lightbuf_find): one list for the whole part of a shadow ray in the
// voxel's zone, found before the ray starts.
struct ZoneSource {
    int L;
    real ta, tb;
    bool span(real *a, real *b) const {
        *a = ta;
        *b = tb;
        return true;
    }
    template <class Out>
    bool walk(Out &out, real a, real b) const {
        out.w->k.steps += 1;  // (a step, as a voxel's)
        return out(L, a, b);
    }
};

// A cell of the eye's buffer: a primary ray stays in the cell and crosses its runs, slab by slab
// outwards; all of the grid's box lies between the first slab and the last.
struct EyeSource {
    const LightFace *F;
    const int *run, *end;  // the cell's runs
    real inv;              // 1 / the ray's depth per unit of t
    bool span(real *a, real *b) const {
        *a = F->lo[2] * inv;
        *b = (F->lo[2] + (real)end[-1] * F->h[2]) * inv;
        return true;
    }
    template <class Out>
    bool walk(Out &out, real t, real tb) const {
        for (const int *r = run; r < end && t < tb; r += 2) {
            real next = r + 2 < end ? (F->lo[2] + (real)r[1] * F->h[2]) * inv : tb;
            next = next < tb ? next : tb;
            out.w->k.steps += 1;  // (a step, as a voxel's: image sequences weigh tracing by them)
            if (out(r[0], t, next)) return true;
            t = next;
        }
        return false;
    }
};

// ---- [9b.8] Per ray: the ray driver, the shadow cache, the entry points ----
// A new ray: a new stamp for what is kept per ray (3.5: no explicit unfreezing).
void ray_begin(const Scene *s, Scratch *w) {
    w->ray++;
    if (w->ray == 0) {  // the stamps wrapped around: clear them
        for (int i = 0; i < s->prims.n; i++) w->span[i].stamp = 0;
        memset(w->nfrozen, 0, sizeof(unsigned) * (size_t)s->nodes.n);
        memset(w->nfixed, 0, sizeof(unsigned) * (size_t)s->nodes.n);
        w->ray = 1;
    }
    w->root_fixed = 0;
}

// Where a ray's stretches go: the one list evaluator, in order along the ray. Each stretch
// (a, b] starts where the one before ended. operator() returns true when the visitor stopped or
// nothing further can be seen.
template <class Visit>
struct Stretches {
    const Scene *s;
    Scratch *w;
    const Ray &ray;
    real tmax;
    int self;
    Visit &visit;
    real at;  // where the last stretch ended
    Stretches(const Scene *s_, Scratch *w_, const Ray &ray_, real tmax_, int self_, Visit &visit_)
        : s(s_), w(w_), ray(ray_), tmax(tmax_), self(self_), visit(visit_), at(0) {}
    bool operator()(int L, real a, real b) {
        PRAY_ASSERT(a == at && a <= b && L >= 0 && L < s->accel->off.n);
        at = b;
        return eval_list(s, s->accel, w, ray, L, a, b, tmax, self, visit);
    }
    // a stretch of the empty list 0, where nothing can be hit
    void pass(real a, real b) {
        PRAY_ASSERT(a == at && a <= b);
        at = b;
        (void)a;
    }
};

// The lists of a ray that drive (below) has begun: give the list evaluator the outer list up to the part the source covers, that part's stretches, and the outer list
// after it, up to tmax. Without a grid, the outer list holds everything: with bounds, a node
// whose box the ray misses is outside for the whole ray first. Returns true when the visitor
// stopped or nothing further can be seen.
template <class Visit, class Source>
bool drive_lists(const Scene *s, Scratch *w, const Ray &ray, real tmax, const Source *src, Stretches<Visit> &out) {
    const Accel *A = s->accel;
    real ta = 0, tb = 0;
    if (!src || !src->span(&ta, &tb) || !(tb > 0) || !(ta < tmax)) {
        if (A->bounds && A->g.n[0] == 0) {
            real inv[3];
            ray_inverse(ray, inv);
            for (int j = s->nodes.n - 1; j >= 0; j--) {  // (parents first)
                const Node &nd = s->nodes[j];
                // a frozen node is still fixed by its own box, which a list with a plan reads
                if (frozen(w, nd.parent)) w->nfrozen[j] = w->ray;
                if (w->nfixed[j] == w->ray || !box_finite(nd.box)) continue;
                real t0, t1;
                if (ray_box(ray, inv, nd.box.lo, nd.box.hi, &t0, &t1) && t1 > 0 && t0 < tmax) continue;
                w->nfixed[j] = w->ray;
                w->nfixval[j] = 0;
                if (A->freeze) settle(s, w, 2 * j + 1, false);
            }
        }
        return out(A->outer, 0, tmax);
    }
    ta = ta > 0 ? ta : 0;
    tb = tb < tmax ? tb : tmax;
    if (ta > 0 && out(A->outer, 0, ta)) return true;
    if (src->walk(out, ta, tb)) return true;
    return tb < tmax && out(A->outer, tb, tmax);
}

// Notes in the record of the pixel being traced the regions that the part (0, end] of the ray
// crosses (section 10b).
void region_note(Scratch *w, const Ray &ray, real end);

// The one way a ray reaches the accelerated scene (drive_lists); a pixel being traced for an
// image sequence notes the part of the ray the lists were evaluated on, up to where the visitor
// stopped: what it brought back depends on nothing else.
template <class Visit, class Source>
bool drive(const Scene *s, Scratch *w, const Ray &ray, real tmax, int self, Visit &visit, const Source *src) {
    if (s->root < 0) {
        if (w->rbits) region_note(w, ray, tmax);
        return true;
    }
    ray_begin(s, w);
    Stretches<Visit> out(s, w, ray, tmax, self, visit);
    bool done = drive_lists(s, w, ray, tmax, src, out);
    if (w->rbits) {
        real e = visit_end(visit);
        region_note(w, ray, e < out.at ? e : out.at);
    }
    return done;
}

// All hits along the ray in (0, tmax), by the reference or the accelerated path.
template <class Visit>
void find_hits(const Scene *s, Scratch *w, const Ray &ray, real tmax, int self, Visit &visit) {
    if (!s->accel) {
        sweep(s, w, ray, tmax, self, visit);
        return;
    }
    if (s->accel->g.n[0] == 0) {
        drive(s, w, ray, tmax, self, visit, (const GridSource *)NULL);
        return;
    }
    GridSource grid(s->accel, ray);
    drive(s, w, ray, tmax, self, visit, &grid);
}

// The shadow cache (option shadowcache): the voxel where the last shadow ray towards the same
// light met an opaque surface (Scratch::blocker) is likely to hold one that stops this ray too.
// Its list, evaluated on the ray's stretch through it, decides (true) when what it lets through
// there is zero; else the ray is traced as usual. What the whole ray lets through is a product
// of the same factors and more, in order. When no factor is more than 1 in magnitude (the
// cache is off otherwise), rounding is monotonic and the product starts at 1, so the whole
// ray's product is at most the stretch's at every step: zero too. The probe is a ray of its own
// (ray_begin): it starts in the middle of the ray, where what was settled before is unknown.
bool shadow_probe(const Scene *s, Scratch *w, const Ray &ray, real tmax, int self, int light, ShadowHit &visit) {
    const Accel *A = s->accel;
    const Blocker &bk = w->blocker[light];
    real inv[3], ta, tb;
    ray_inverse(ray, inv);
    if (!ray_box(ray, inv, bk.lo, bk.hi, &ta, &tb)) return false;
    ta = ta > 0 ? ta : 0;
    tb = tb < tmax ? tb : tmax;
    if (!(ta < tb)) return false;
    ray_begin(s, w);
    ShadowHit probe = visit;
    probe.f = cmake(1, 1, 1);
    eval_list(s, A, w, ray, bk.list, ta, tb, tmax, self, probe);
    if (!czero(probe.f)) return false;
    if (w->rbits) region_note(w, ray, tb);  // (the whole ray lets through no more than (ta, tb])
    w->k.cache += 1;
    visit.f = probe.f;
    return true;
}

// The voxel that holds point p in the deepest grid there, for the shadow cache: false when p is
// outside the grid, or in the rest of a voxel around its nested grid's box (which is no box).
// A nested grid's box may reach out of its voxel, where its lists do not hold: the box kept is
// the voxel's within the voxels above it.
bool blocker_of(const Accel *A, R3 p, Blocker *bk) {
    const Grid *G = &A->g;
    for (int l = 0; l < 3; l++) bk->lo[l] = -REAL_INF, bk->hi[l] = REAL_INF;
    for (;;) {
        int ix[3];
        if (!voxel_of(*G, p, ix)) return false;
        for (int l = 0; l < 3; l++) {
            real lo = G->org[l] + (real)ix[l] * G->h, hi = lo + G->h;
            bk->lo[l] = lo > bk->lo[l] ? lo : bk->lo[l];
            bk->hi[l] = hi < bk->hi[l] ? hi : bk->hi[l];
        }
        int L = G->voxel[voxel_index(*G, ix)];
        if (L >= 0) {
            bk->list = L;
            return true;
        }
        G = &A->nested[-1 - L];
    }
}

// The hits along a shadow ray towards light `light`: the shadow cache's answer when it has one;
// else through the light buffer's voxel when the ray starts in one; else as any other ray.
void shadow_hits(const Scene *s, Scratch *w, const Ray &ray, real tmax, int self, int light, ShadowHit &visit) {
    const Accel *A = s->accel;
    if (!A || A->g.n[0] == 0) {
        find_hits(s, w, ray, tmax, self, visit);
        return;
    }
    Blocker *bk = w->blocker + light;
    if (A->cache && bk->list >= 0 && shadow_probe(s, w, ray, tmax, self, light, visit)) return;
    ZoneSource zone;
    zone.L = A->lbuf ? lightbuf_find(A->lbuf[light], A->outer, ray.o, tmax, &zone.ta, &zone.tb) : -1;
    if (zone.L >= 0) {  // (the outer list alone when the ray misses the grid's box)
        w->k.lbuf += 1;
        drive(s, w, ray, tmax, self, visit, &zone);
    } else find_hits(s, w, ray, tmax, self, visit);
    if (A->cache && !(czero(visit.f) && blocker_of(A, ray.o + ray.d * visit.t, bk))) bk->list = -1;
}

// The hits along a primary ray, which starts at the eye: through the cell of the eye's buffer
// that holds its direction, when the eye has a buffer and the cell has runs; else as any other
// ray.
template <class Visit>
void primary_hits(const Scene *s, Scratch *w, const Ray &ray, real tmax, Visit &visit) {
    const Accel *A = s->accel;
    const LightBuf *B = A ? A->eye : NULL;
    const LightFace *F = B ? &B->f[cube_face(ray.d)] : NULL;
    real g2 = F ? dot(ray.d, F->e[2]) : 0;
    if (!F || !(g2 > 0) || ray.o.x != B->o.x || ray.o.y != B->o.y || ray.o.z != B->o.z) {
        find_hits(s, w, ray, tmax, -1, visit);
        return;
    }
    EyeSource eye;
    eye.F = F;
    eye.run = eye.end = NULL;  // no runs: the ray misses the grid's box
    eye.inv = (real)1 / g2;
    if (F->n[2] > 0) {
        int cell, in = face_cell(*F, dot(ray.d, F->e[0]) / g2, dot(ray.d, F->e[1]) / g2, CELL_SLACK, &cell);
        if (in > 0) {
            eye.run = B->runs + B->runs[F->cbase + cell];
            eye.end = B->runs + B->runs[F->cbase + cell + 1];
        }
        if (in < 0 || (eye.run && eye.run[0] < 0)) {
            find_hits(s, w, ray, tmax, -1, visit);
            return;
        }
    }
    w->k.ebuf += 1;
    drive(s, w, ray, tmax, -1, visit, eye.run ? &eye : NULL);
}

// =============================================================================================
// [SECTION] 9c Reading files; TIFF reader and textures: baseline TIFF in both byte orders for textures and fonts
// =============================================================================================
// Bilevel, greyscale, palette, RGB and RGBA; 1, 4, 8 and 16 bits per sample; strips and tiles;
// no compression, PackBits, LZW with or without the horizontal predictor. Every offset and size
// is checked against the file; anything else is refused with the feature it lacks.
namespace {

struct TiffIn {
    pray_ctx *c;
    const char *name;
    const unsigned char *p;
    size_t n;
    int big;  // "MM": big-endian
    pray_status err(const char *fmt, ...) PRAY_PRINTF(2, 3);
    unsigned u16(size_t at) const {
        return big ? (unsigned)p[at] << 8 | p[at + 1] : (unsigned)p[at + 1] << 8 | p[at];
    }
    unsigned long u32(size_t at) const {
        return big ? (unsigned long)u16(at) << 16 | u16(at + 2) : (unsigned long)u16(at + 2) << 16 | u16(at);
    }
};

pray_status TiffIn::err(const char *fmt, ...) {
    va_list ap;
    va_start(ap, fmt);
    char tmp[600];
    vsnprintf(tmp, sizeof tmp, fmt, ap);
    va_end(ap);
    return fail(c, PRAY_ERR_IO, "%s: %s", name, tmp);
}

struct TiffTag {
    unsigned type;
    unsigned long count, value;  // value: the value itself when it fits in 4 bytes, else its offset
    size_t at;                   // where the entry's value field is
    int present;
};

// Tags read, by number.
enum {
    TT_WIDTH = 256, TT_LENGTH = 257, TT_BPS = 258, TT_COMPRESSION = 259, TT_PHOTOMETRIC = 262,
    TT_STRIPOFFSETS = 273, TT_SPP = 277, TT_ROWSPERSTRIP = 278, TT_STRIPBYTES = 279, TT_PLANAR = 284,
    TT_PREDICTOR = 317, TT_COLORMAP = 320, TT_TILEWIDTH = 322, TT_TILELENGTH = 323, TT_TILEOFFSETS = 324,
    TT_TILEBYTES = 325, TT_EXTRASAMPLES = 338, TT_SAMPLEFORMAT = 339
};
const unsigned TIFF_TAGS[] = {TT_WIDTH, TT_LENGTH, TT_BPS, TT_COMPRESSION, TT_PHOTOMETRIC, TT_STRIPOFFSETS,
                              TT_SPP, TT_ROWSPERSTRIP, TT_STRIPBYTES, TT_PLANAR, TT_PREDICTOR, TT_COLORMAP,
                              TT_TILEWIDTH, TT_TILELENGTH, TT_TILEOFFSETS, TT_TILEBYTES, TT_EXTRASAMPLES,
                              TT_SAMPLEFORMAT};
const int NTIFF_TAGS = (int)(sizeof TIFF_TAGS / sizeof TIFF_TAGS[0]);

size_t tiff_type_size(unsigned type) {
    switch (type) {
    case 1: case 2: case 6: case 7: return 1;  // BYTE ASCII SBYTE UNDEFINED
    case 3: case 8: return 2;                  // SHORT SSHORT
    case 4: case 9: case 11: return 4;         // LONG SLONG FLOAT
    case 5: case 10: case 12: return 8;        // RATIONAL SRATIONAL DOUBLE
    default: return 0;
    }
}

// Value i of an integer tag; false when it is not there or not an integer.
bool tiff_value(const TiffIn &in, const TiffTag &t, unsigned long i, unsigned long *v) {
    if (!t.present || i >= t.count) return false;
    size_t sz = tiff_type_size(t.type);
    if (t.type != 1 && t.type != 3 && t.type != 4) return false;
    size_t base = t.count * sz <= 4 ? t.at : (size_t)t.value;
    size_t at = base + (size_t)i * sz;
    if (at + sz > in.n) return false;
    *v = sz == 1 ? in.p[at] : sz == 2 ? in.u16(at) : in.u32(at);
    return true;
}

// PackBits: literal runs and repeats, into exactly `want` bytes.
bool unpackbits(const unsigned char *src, size_t n, unsigned char *dst, size_t want) {
    size_t i = 0, o = 0;
    while (o < want) {
        if (i >= n) return false;
        int k = (signed char)src[i++];
        if (k >= 0) {
            size_t len = (size_t)k + 1;
            if (i + len > n || o + len > want) return false;
            memcpy(dst + o, src + i, len);
            i += len;
            o += len;
        } else if (k != -128) {
            size_t len = (size_t)(1 - k);
            if (i >= n || o + len > want) return false;
            memset(dst + o, src[i++], len);
            o += len;
        }
    }
    return true;
}

// LZW as TIFF has it: codes of 9 to 12 bits, most significant bit first, 256 clears, 257 ends,
// the code width grows one code early.
bool unlzw(pray_ctx *c, const unsigned char *src, size_t n, unsigned char *dst, size_t want) {
    struct Entry {
        unsigned short prefix, len;
        unsigned char first, last;
    };
    Entry *tab = (Entry *)mem_alloc(c, sizeof(Entry) * 4096);
    if (!tab) return false;
    for (int i = 0; i < 256; i++) {
        tab[i].prefix = 0xFFFF;
        tab[i].len = 1;
        tab[i].first = tab[i].last = (unsigned char)i;
    }
    size_t o = 0, bitpos = 0, nbits = n * 8;
    int width = 9, next = 258, prev = -1;
    bool ok = true;
    for (;;) {
        if (bitpos + (size_t)width > nbits) break;  // ran out: the strip ends without 257
        int code = 0;
        for (int b = 0; b < width; b++, bitpos++) code = code << 1 | (src[bitpos >> 3] >> (7 - (bitpos & 7)) & 1);
        if (code == 257) break;
        if (code == 256) {
            width = 9;
            next = 258;
            prev = -1;
            continue;
        }
        int out;  // the code whose string goes out
        if (code < next && (code < 256 || code >= 258)) {
            out = code;
            if (prev >= 0 && next < 4096) {
                tab[next].prefix = (unsigned short)prev;
                tab[next].len = (unsigned short)(tab[prev].len + 1);
                tab[next].first = tab[prev].first;
                tab[next].last = tab[code].first;
                next++;
            }
        } else if (code == next && prev >= 0 && next < 4096) {
            tab[next].prefix = (unsigned short)prev;
            tab[next].len = (unsigned short)(tab[prev].len + 1);
            tab[next].first = tab[prev].first;
            tab[next].last = tab[prev].first;
            out = next++;
        } else {
            ok = false;
            break;
        }
        size_t len = tab[out].len;
        if (o + len > want) len = want - o;  // extra data at the end of a strip is ignored
        // write the string backwards from its end
        int k = out;
        size_t skip = tab[out].len - len;
        for (size_t q = 0; q < skip; q++) k = tab[k].prefix;
        for (size_t q = len; q > 0; q--) {
            dst[o + q - 1] = tab[k].last;
            k = tab[k].prefix;
        }
        o += len;
        prev = code;
        if (next + 1 >= (1 << width) && width < 12) width++;
        if (o >= want) break;
    }
    mem_free(c, tab);
    return ok && o == want;
}

// A decoded texture: RGB floats, rows from the first row of the file.
struct TexImage {
    int w, h;
    float *rgb;
};

// The directory's `count` entries at ifd: the tags pray reads, checked against the file.
pray_status tiff_tags(TiffIn &in, unsigned long ifd, unsigned count, TiffTag *tags) {
    memset(tags, 0, sizeof(TiffTag) * NTIFF_TAGS);
    for (unsigned e = 0; e < count; e++) {
        size_t at = (size_t)ifd + 2 + (size_t)e * 12;
        unsigned tag = in.u16(at);
        for (int k = 0; k < NTIFF_TAGS; k++) {
            if (TIFF_TAGS[k] != tag) continue;
            TiffTag &t = tags[k];
            t.type = in.u16(at + 2);
            t.count = in.u32(at + 4);
            t.at = at + 8;
            t.value = in.u32(at + 8);
            size_t sz = tiff_type_size(t.type);
            if (!sz) return in.err("tag %u has an unknown type %u", tag, t.type);
            if (t.count > in.n) return in.err("tag %u claims %lu values", tag, t.count);
            if (t.count * sz > 4 && (t.value > in.n || t.count * sz > in.n - t.value))
                return in.err("the values of tag %u lie outside the file", tag);
            t.present = 1;
        }
    }
    return PRAY_OK;
}

// The name of a compression pray does not read.
const char *tiff_compression(unsigned long comp) {
    return comp == 2 || comp == 3 || comp == 4 ? "CCITT fax" : comp == 6 || comp == 7 ? "JPEG"
           : comp == 8 || comp == 32946 ? "Deflate" : comp == 34925 ? "LZMA"
           : comp == 50000 ? "Zstandard" : comp == 50001 ? "WebP" : "an unknown method";
}

// What a block's samples are, for tiff_block.
struct TiffPixels {
    unsigned long width, height, spp, bps, photo, colors, maxv, bw, bh;
    const TiffTag *cmap;
    float *rgb;
};

// Block (bx, by) of `rows` rows of rowbytes each into the image: the horizontal differences of
// predictor 2 undone (pred), then each pixel's colour.
void tiff_block(const TiffIn &in, const TiffPixels &f, unsigned char *block, size_t rows, size_t rowbytes,
                unsigned long bx, unsigned long by, unsigned long pred) {
    const unsigned long spp = f.spp, bps = f.bps, bw = f.bw, maxv = f.maxv;
    if (pred == 2)
        for (size_t r = 0; r < rows; r++) {
            unsigned char *row = block + r * rowbytes;
            if (bps == 8) {
                for (size_t i = spp; i < bw * spp; i++) row[i] = (unsigned char)(row[i] + row[i - spp]);
            } else {
                for (size_t i = spp; i < bw * spp; i++) {
                    unsigned char *a = row + 2 * i, *b = row + 2 * (i - spp);
                    unsigned v = in.big ? ((unsigned)a[0] << 8 | a[1]) + ((unsigned)b[0] << 8 | b[1])
                                        : ((unsigned)a[1] << 8 | a[0]) + ((unsigned)b[1] << 8 | b[0]);
                    a[in.big ? 0 : 1] = (unsigned char)(v >> 8 & 255);
                    a[in.big ? 1 : 0] = (unsigned char)(v & 255);
                }
            }
        }
    for (size_t r = 0; r < rows; r++) {
        unsigned long y = by * f.bh + r;
        if (y >= f.height) break;
        const unsigned char *row = block + r * rowbytes;
        for (unsigned long x0 = 0; x0 < bw; x0++) {
            unsigned long x = bx * bw + x0;
            if (x >= f.width) break;
            unsigned long v[4] = {0, 0, 0, 0};
            for (unsigned long q = 0; q < f.colors; q++) {
                size_t bit = (size_t)(x0 * spp + q) * bps;
                if (bps == 16) {
                    const unsigned char *a = row + bit / 8;
                    v[q] = in.big ? ((unsigned long)a[0] << 8 | a[1]) : ((unsigned long)a[1] << 8 | a[0]);
                } else if (bps == 8) v[q] = row[bit / 8];
                else v[q] = (unsigned long)(row[bit / 8] >> (8 - bps - bit % 8)) & maxv;
            }
            float *o = f.rgb + ((size_t)y * f.width + x) * 3;
            if (f.photo == 3) {
                unsigned long r0 = 0, g0 = 0, b0 = 0;
                tiff_value(in, *f.cmap, v[0], &r0);
                tiff_value(in, *f.cmap, v[0] + maxv + 1, &g0);
                tiff_value(in, *f.cmap, v[0] + 2 * (maxv + 1), &b0);
                o[0] = (float)(r0 / 65535.0);
                o[1] = (float)(g0 / 65535.0);
                o[2] = (float)(b0 / 65535.0);
            } else if (f.photo == 2) {
                for (int q = 0; q < 3; q++) o[q] = (float)((double)v[q] / maxv);
            } else {
                double g = (double)v[0] / maxv;
                if (f.photo == 0) g = 1 - g;  // white is zero
                o[0] = o[1] = o[2] = (float)g;
            }
        }
    }
}

pray_status tiff_decode(pray_ctx *c, const char *name, const unsigned char *p, size_t n, double max_bytes,
                        TexImage *img) {
    TiffIn in;
    in.c = c;
    in.name = name;
    in.p = p;
    in.n = n;
    img->rgb = NULL;
    if (n < 8) return in.err("not a TIFF file (too short)");
    if (p[0] == 'I' && p[1] == 'I') in.big = 0;
    else if (p[0] == 'M' && p[1] == 'M') in.big = 1;
    else return in.err("not a TIFF file");
    unsigned magic = in.u16(2);
    if (magic == 43) return in.err("unsupported TIFF: BigTIFF");
    if (magic != 42) return in.err("not a TIFF file");
    unsigned long ifd = in.u32(4);
    if (ifd < 8 || ifd + 2 > n) return in.err("the directory offset %lu is outside the file", ifd);
    unsigned count = in.u16((size_t)ifd);
    if ((size_t)ifd + 2 + (size_t)count * 12 > n) return in.err("the directory runs past the end of the file");
    TiffTag tags[NTIFF_TAGS];
    if (tiff_tags(in, ifd, count, tags)) return c->status;
    struct Idx {
        static int of(unsigned x) {
            for (int k = 0; k < NTIFF_TAGS; k++)
                if (TIFF_TAGS[k] == x) return k;
            return 0;
        }
    };
    unsigned long width = 0, height = 0, spp = 1, bps = 1, comp = 1, photo = 9, planar = 1, pred = 1;
    unsigned long fmt = 1;
    if (!tiff_value(in, tags[Idx::of(TT_WIDTH)], 0, &width) || !tiff_value(in, tags[Idx::of(TT_LENGTH)], 0, &height))
        return in.err("no image size");
    tiff_value(in, tags[Idx::of(TT_SPP)], 0, &spp);
    tiff_value(in, tags[Idx::of(TT_BPS)], 0, &bps);
    tiff_value(in, tags[Idx::of(TT_COMPRESSION)], 0, &comp);
    if (!tiff_value(in, tags[Idx::of(TT_PHOTOMETRIC)], 0, &photo)) return in.err("no photometric interpretation");
    tiff_value(in, tags[Idx::of(TT_PLANAR)], 0, &planar);
    tiff_value(in, tags[Idx::of(TT_PREDICTOR)], 0, &pred);
    tiff_value(in, tags[Idx::of(TT_SAMPLEFORMAT)], 0, &fmt);
    if (width < 1 || height < 1 || width > 65536 || height > 65536)
        return in.err("image size %lu x %lu is out of range", width, height);
    for (unsigned long i = 1; i < spp; i++) {
        unsigned long b;
        if (tiff_value(in, tags[Idx::of(TT_BPS)], i, &b) && b != bps)
            return in.err("unsupported TIFF: samples of different sizes");
    }
    if (fmt == 3) return in.err("unsupported TIFF: floating-point samples");
    if (fmt == 2) return in.err("unsupported TIFF: signed integer samples");
    if (fmt != 1) return in.err("unsupported TIFF: sample format %lu (only unsigned integers)", fmt);
    if (bps != 1 && bps != 4 && bps != 8 && bps != 16)
        return in.err("unsupported TIFF: %lu bits per sample", bps);
    if (comp != 1 && comp != 5 && comp != 32773)
        return in.err("unsupported TIFF: %s compression (%lu)", tiff_compression(comp), comp);
    if (pred != 1 && pred != 2) return in.err("unsupported TIFF: predictor %lu", pred);
    if (pred == 2 && bps != 8 && bps != 16) return in.err("unsupported TIFF: predictor with %lu bits", bps);
    if (spp > 1 && planar != 1) return in.err("unsupported TIFF: separate colour planes");
    unsigned long colors;  // samples that make the colour; the rest are extra (alpha)
    if (photo == 0 || photo == 1) colors = 1;
    else if (photo == 2) colors = 3;
    else if (photo == 3) colors = 1;
    else return in.err("unsupported TIFF: photometric interpretation %lu", photo);
    if (spp < colors || spp > colors + 1) return in.err("unsupported TIFF: %lu samples per pixel", spp);
    if (photo == 2 && bps < 8) return in.err("unsupported TIFF: RGB with %lu bits", bps);
    if (photo == 3 && bps == 16) return in.err("unsupported TIFF: palette with 16 bits");
    unsigned long maxv = (1ul << bps) - 1;
    const TiffTag &cmap = tags[Idx::of(TT_COLORMAP)];
    if (photo == 3 && (!cmap.present || cmap.count < 3 * (maxv + 1))) return in.err("palette image without a colour map");
    if ((double)width * height * 3 * sizeof(float) > max_bytes)
        return fail(c, PRAY_ERR_LIMIT, "%s: a %lu x %lu texture is over the texture memory limit (option texmem)", name,
                    width, height);
    // the blocks: strips or tiles
    bool tiled = tags[Idx::of(TT_TILEWIDTH)].present;
    unsigned long bw = width, bh = height;
    const TiffTag *offs, *cnts;
    if (tiled) {
        if (!tiff_value(in, tags[Idx::of(TT_TILEWIDTH)], 0, &bw) || !tiff_value(in, tags[Idx::of(TT_TILELENGTH)], 0, &bh) ||
            bw < 1 || bh < 1 || bw > 65536 || bh > 65536)
            return in.err("bad tile size");
        offs = &tags[Idx::of(TT_TILEOFFSETS)];
        cnts = &tags[Idx::of(TT_TILEBYTES)];
    } else {
        unsigned long rps = height;
        if (tiff_value(in, tags[Idx::of(TT_ROWSPERSTRIP)], 0, &rps) && rps < height && rps > 0) bh = rps;
        offs = &tags[Idx::of(TT_STRIPOFFSETS)];
        cnts = &tags[Idx::of(TT_STRIPBYTES)];
    }
    unsigned long across = (width + bw - 1) / bw, down = (height + bh - 1) / bh;
    if (!offs->present || offs->count < across * down) return in.err("missing %s offsets", tiled ? "tile" : "strip");
    size_t rowbytes = (size_t)((bw * spp * bps + 7) / 8);
    size_t blockbytes = rowbytes * bh;
    if ((double)blockbytes > max_bytes) return fail(c, PRAY_ERR_LIMIT, "%s: blocks too large", name);
    unsigned char *block = (unsigned char *)mem_alloc(c, blockbytes ? blockbytes : 1);
    float *rgb = (float *)mem_alloc(c, sizeof(float) * 3 * (size_t)width * (size_t)height);
    if (!block || !rgb) {
        mem_free(c, block);
        mem_free(c, rgb);
        return c->status;
    }
    TiffPixels px = {width, height, spp, bps, photo, colors, maxv, bw, bh, &cmap, rgb};
    pray_status st = PRAY_OK;
    for (unsigned long by = 0; by < down && st == PRAY_OK; by++)
        for (unsigned long bx = 0; bx < across && st == PRAY_OK; bx++) {
            unsigned long k = by * across + bx, off, len;
            if (!tiff_value(in, *offs, k, &off)) {
                st = in.err("bad block offset");
                break;
            }
            if (!cnts->present) len = comp == 1 ? (unsigned long)blockbytes : (unsigned long)(n > off ? n - off : 0);
            else if (!tiff_value(in, *cnts, k, &len)) {
                st = in.err("bad block size");
                break;
            }
            if (off > n || len > n - off) {
                st = in.err("block %lu lies outside the file (truncated?)", k);
                break;
            }
            // strips at the bottom may be shorter
            size_t rows = tiled ? bh : (by == down - 1 ? height - by * bh : bh);
            size_t want = rowbytes * rows;
            const unsigned char *src = p + off;
            bool ok;
            if (comp == 1) {
                ok = len >= want;
                if (ok) memcpy(block, src, want);
            } else if (comp == 32773) ok = unpackbits(src, len, block, want);
            else {
                ok = unlzw(c, src, len, block, want);
                if (!ok && c->status == PRAY_ERR_NOMEM) {
                    st = c->status;
                    break;
                }
            }
            if (!ok) {
                st = in.err("block %lu is truncated or corrupt", k);
                break;
            }
            tiff_block(in, px, block, rows, rowbytes, bx, by, pred);
        }
    mem_free(c, block);
    if (st != PRAY_OK) {
        mem_free(c, rgb);
        return st;
    }
    img->w = (int)width;
    img->h = (int)height;
    img->rgb = rgb;
    return PRAY_OK;
}

} // namespace

namespace {

// Where an untrusted program may name a file: a relative path without ".." or drive, read only
// beside the program. NULL when `path` is fine, else why not.
const char *untrusted_path_problem(const char *path) {
    if (!path[0]) return "an empty name";
    if (path[0] == '/' || path[0] == '\\' || strchr(path, ':')) return "not a relative name";
    for (const char *q = path; *q;) {
        const char *e = q;
        while (*e && *e != '/' && *e != '\\') e++;
        if (e - q == 2 && q[0] == '.' && q[1] == '.') return "a name with '..'";
        q = *e ? e + 1 : e;
    }
    return NULL;
}

// How a file named by a program or a host is looked for (open_read).
enum { FIND_AS_NAMED, FIND_BESIDE, FIND_CONFINED };

#if PRAY_HAS_STDIO
#if PRAY_FILES_AT
// Open `name` (NUL-terminated, modified) from directory `dir` ("" = the current one) one
// component at a time, never following a link: a name that was swapped for a link between a
// check and an open cannot lead elsewhere, since the open is the check. -1 on failure (errno);
// `*link` is set when a component is a symbolic link, `*at` to that component unless it is the
// last.
int open_confined(const char *dir, char *name, bool *link, const char **at) {
    int d = open(dir[0] ? dir : ".", O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    for (char *q = name; d >= 0;) {
        char *e = q;
        while (*e && *e != '/') e++;
        bool last = *e == 0;
        *e = 0;
        if (!*q && !last) {  // "a//b"
            q = e + 1;
            continue;
        }
        const char *step = *q ? q : ".";
        int next = fd_open_at(d, step, last);
        int err = errno;
        if (next < 0 && (err == ELOOP || is_link_at(d, step))) {  // ELOOP: a link when opened
            *link = true;
            *at = last ? NULL : step;
        }
        fd_close(d);
        errno = err;
        if (next < 0 || last) return next;
        d = next;
        q = e + 1;
    }
    return -1;
}
#endif

// Is `path` the file opened as `name` with identity `id`? By identity where files have one, else
// by name.
bool same_file(const char *path, const FileId &id, const char *name) {
    FileId pid;
    if (id.valid) return name_id(path, &pid) && same_id(pid, id);
    const char *a = path, *b = name;
    while (a[0] == '.' && (a[1] == '/' || a[1] == '\\')) a += 2;
    while (b[0] == '.' && (b[1] == '/' || b[1] == '\\')) b += 2;
#if defined(_WIN32) || defined(__DJGPP__)
    for (; *a && *b; a++, b++) {
        int x = *a == '\\' ? '/' : tolower((unsigned char)*a), y = *b == '\\' ? '/' : tolower((unsigned char)*b);
        if (x != y) return false;
    }
    return *a == *b;
#else
    return strcmp(a, b) == 0;
#endif
}

// Record a file the running program opened, once. False when out of memory.
bool note_input(pray_ctx *c, const char *name, const FileId &id) {
    for (ReadFile *r = c->inputs; r; r = r->next)
        if (id.valid ? same_id(id, r->id) : strcmp(name, r->name) == 0) return true;
    ReadFile *r = (ReadFile *)mem_alloc(c, sizeof(ReadFile));
    char *nm = r ? mem_strdup(c, name, strlen(name)) : NULL;
    if (!nm) {
        mem_free(c, r);
        return false;
    }
    r->next = c->inputs;
    r->id = id;
    r->name = nm;
    c->inputs = r;
    return true;
}

// Would writing `path` replace a file the running program read?
bool is_input(pray_ctx *c, const char *path) {
    for (ReadFile *r = c->inputs; r; r = r->next)
        if (same_file(path, r->id, r->name)) return true;
    return false;
}

// The one way pray opens a file to read: programs, textures, fonts, included files and the parts
// of --join. The file is opened once (without waiting on a FIFO) and must be a regular file; `id`
// (may be NULL) gets its identity where the system has one. While a program runs, the file is
// recorded as one it read (note_input). `dir` (dlen bytes, ending in a separator) is the program's directory: FIND_BESIDE
// looks for a relative name as written, then beside the program; FIND_CONFINED beside the program
// only, without following links where the system allows (PRAY_FILES_AT; elsewhere links are
// followed). `*path` gets the name opened (context memory, also on failure: free with mem_free).
// NULL on failure, message set.
FILE *open_read(pray_ctx *c, const char *dir, size_t dlen, const char *name, int how, char **path, FileId *id) {
    FileId own;
    if (!id) id = &own;
    id->valid = 0;
    size_t n = strlen(name);
    char *p = (char *)mem_alloc(c, 2 * (dlen + n + 2));  // the path, and room for a walk
    *path = p;
    if (!p) return NULL;
    memcpy(p, dir, dlen);
    memcpy(p + dlen, name, n + 1);
    bool relative = name[0] && name[0] != '/' && name[0] != '\\' && name[1] != ':';
    const char *first = how == FIND_CONFINED ? p : p + dlen;  // as written first,
    bool beside = how == FIND_BESIDE && relative && dlen;       // then beside the program
    bool link = false;
    const char *at = NULL;
    int err = 0;
#if PRAY_FILES_FD
    int fd = -1;
    if (how == FIND_CONFINED) {
#if PRAY_FILES_AT
        char *walk = p + dlen + n + 1;
        memcpy(walk, dir, dlen);
        walk[dlen] = 0;
        memcpy(walk + dlen + 1, name, n + 1);
        errno = 0;
        fd = open_confined(walk, walk + dlen + 1, &link, &at);
#else
        errno = 0;
        fd = fd_open(p, 0);
#endif
    } else {
        errno = 0;
        fd = fd_open(first, 0);
        if (fd < 0 && errno == ENOENT && beside) {
            fd = fd_open(p, 0);
            if (fd >= 0 || errno != ENOENT) first = p;  // else: named as written
        }
    }
    err = errno ? errno : ENOENT;
    if (fd >= 0 && !fd_regular(fd, id)) {
        fd_close(fd);
        fail(c, PRAY_ERR_IO, "cannot read '%s': not a regular file", *ShownPath(first));
        return NULL;
    }
    FILE *f = fd >= 0 ? fd_stdio(fd, "rb") : NULL;
    if (fd >= 0 && !f) {
        err = errno ? errno : EIO;
        fd_close(fd);
    }
#else
    if (id) id->valid = 0;
    errno = 0;
    FILE *f = fopen(first, "rb");
    if (!f && beside && errno == ENOENT) {
        f = fopen(p, "rb");
        if (f || errno != ENOENT) first = p;
    }
    err = errno ? errno : ENOENT;
#endif
    if (link)
        fail(c, PRAY_ERR_IO, "untrusted program: '%s' %s%s%s; files are read from the program's directory only, "
             "and links are not followed", *Shown(name), at ? "passes through the symbolic link '" : "is a symbolic link",
             at ? *Shown(at) : "", at ? "'" : "");
    else if (!f) fail(c, PRAY_ERR_IO, "cannot open '%s': %s", *ShownPath(first), strerror(err));
    if (first != p) memmove(p, first, strlen(first) + 1);
    if (f && c->running && !note_input(c, p, *id)) {
        fclose(f);
        return NULL;
    }
    return f;
}

// Read an open file whole through the context's allocator (NUL-terminated; free with mem_free)
// and close it; at most max_bytes (option texmem) when that is not negative. NULL on failure.
unsigned char *read_all(pray_ctx *c, FILE *f, const char *path, size_t *n, double max_bytes) {
    Text t;
    t.init();
    char buf[8192];
    size_t got;
    bool ok = true;
    while (ok && (got = fread(buf, 1, sizeof buf, f)) > 0) {
        if (max_bytes >= 0 && (double)t.a.n + got > max_bytes) {
            fail(c, PRAY_ERR_LIMIT, "'%s' is over the texture memory limit (option texmem)", *ShownPath(path));
            ok = false;
        } else
            ok = t.add(c, buf, got);
    }
    if (ok && ferror(f)) ok = fail(c, PRAY_ERR_IO, "cannot read '%s'", *ShownPath(path)) == PRAY_OK;
    fclose(f);
    if (ok && !t.a.p) ok = t.add(c, "", 0);  // an empty file: still a (NUL-terminated) buffer
    if (!ok) {
        t.a.release(c);
        return NULL;
    }
    *n = (size_t)t.a.n;
    return (unsigned char *)t.a.p;
}
#endif

pray_texture *texture_make(pray_ctx *c, const char *name, const unsigned char *data, size_t n) {
    TexImage img = {0, 0, NULL};
    double cap = c->cur.opt.v[OPT_TEXMEM] * 1048576.0;
    if (tiff_decode(c, *ShownPath(name), data, n, cap, &img)) return NULL;
    pray_texture *t = (pray_texture *)handle_new(c, sizeof(pray_texture), H_TEXTURE);
    char *nm = t ? mem_strdup(c, name, strlen(name)) : NULL;
    if (!t || !nm) {
        mem_free(c, t);
        mem_free(c, img.rgb);
        return NULL;
    }
    t->w = img.w;
    t->hgt = img.h;
    t->rgb = img.rgb;
    t->name = nm;
    return t;
}

// A texture file (found as `how` says, open_read), decoded once per context run however often
// it is used.
pray_texture *texture_file(pray_ctx *c, const char *dir, size_t dlen, const char *name, int how) {
#if PRAY_HAS_STDIO
    char *path = NULL;
    FILE *f = open_read(c, dir, dlen, name, how, &path, NULL);
    pray_texture *t = f ? c->textures : NULL;
    while (t && strcmp(t->name, path) != 0) t = t->next;
    if (t) {
        fclose(f);
        retain(t);
    } else if (f) {
        size_t n = 0;
        unsigned char *data = read_all(c, f, path, &n, c->cur.opt.v[OPT_TEXMEM] * 1048576.0);
        t = data ? texture_make(c, path, data, n) : NULL;
        mem_free(c, data);
        if (t) {
            t->next = c->textures;  // the cache holds one reference
            c->textures = t;
            retain(t);
        }
    }
    mem_free(c, path);
    return t;
#else
    (void)dir;
    (void)dlen;
    (void)name;
    (void)how;
    fail(c, PRAY_ERR_IO, "this build has no file access");
    return NULL;
#endif
}

// What a run leaves for the next one to start afresh: its decoded textures, and the record of the
// files it read.
void texture_cache_clear(pray_ctx *c) {
    while (c->textures) {
        pray_texture *t = c->textures;
        c->textures = t->next;
        release_handle(c, t);
    }
#if PRAY_HAS_STDIO
    while (c->inputs) {
        ReadFile *r = c->inputs;
        c->inputs = r->next;
        mem_free(c, r->name);
        mem_free(c, r);
    }
#endif
}

// Where the host's registration of exactly `name` is kept in the list `at` (c->tex_names,
// c->inc_names), else where a new one would go: the end of the list.
TexName **name_at(TexName **at, const char *name) {
    while (*at && strcmp((*at)->name, name) != 0) at = &(*at)->next;
    return at;
}
// A new registration of `name` put at *at (the end of its list), or NULL when out of memory.
TexName *name_add(pray_ctx *c, TexName **at, const char *name) {
    TexName *e = (TexName *)mem_zalloc(c, sizeof(TexName));
    if (e && !(e->name = mem_strdup(c, name, strlen(name)))) mem_free(c, e), e = NULL;
    return e ? *at = e : NULL;
}
void name_drop(pray_ctx *c, TexName **at) {  // (the texture released)
    TexName *e = *at;
    *at = e->next;
    mem_free(c, e->text);
    mem_free(c, e->name);
    mem_free(c, e);
}

// The place of coordinate u within the repeating image, in [0, 1); 0 for a coordinate that is
// not a finite number, so that no coordinate whatever reaches beyond the texels.
inline double tex_wrap(double u) {
    double f = u - floor(u);
    return f >= 0 && f < 1 ? f : 0;
}

// Colour of the texture at (s, t): bilinear between texel centres, the image repeating.
pray_rgb tex_lookup(const pray_texture *tx, double s, double t) {
    double x = tex_wrap(s) * tx->w - 0.5, y = tex_wrap(t) * tx->hgt - 0.5;
    double fx0 = floor(x), fy0 = floor(y);
    double fx = x - fx0, fy = y - fy0;
    int x0 = (int)fx0, y0 = (int)fy0;
    int x1 = x0 + 1, y1 = y0 + 1;
    if (x0 < 0) x0 += tx->w;
    if (y0 < 0) y0 += tx->hgt;
    if (x1 >= tx->w) x1 -= tx->w;
    if (y1 >= tx->hgt) y1 -= tx->hgt;
    const float *a = tx->rgb + ((size_t)y0 * tx->w + x0) * 3, *b = tx->rgb + ((size_t)y0 * tx->w + x1) * 3;
    const float *cc = tx->rgb + ((size_t)y1 * tx->w + x0) * 3, *d = tx->rgb + ((size_t)y1 * tx->w + x1) * 3;
    double v[3];
    for (int i = 0; i < 3; i++)
        v[i] = (a[i] * (1 - fx) + b[i] * fx) * (1 - fy) + (cc[i] * (1 - fx) + d[i] * fx) * fy;
    return cmake(v[0], v[1], v[2]);
}

double tex_luminance(const pray_texture *tx, double s, double t) {
    pray_rgb c = tex_lookup(tx, s, t);
    return 0.2126 * c.r + 0.7152 * c.g + 0.0722 * c.b;
}

// ---- how much a texture varies over a region (undersampling looks for detail between samples) ----
// tx->mm holds levels 1, 2, ... of blocks of 2^k x 2^k texels, each block its smallest and
// largest value of each channel (6 floats); level 0 is the texels themselves.
int mm_blocks(int n, int k) { return (n + (1 << k) - 1) >> k; }

bool tex_pyramid(pray_ctx *c, pray_texture *tx) {
    if (tx->mm) return true;
    size_t total = 0;
    for (int k = 1; k == 1 || mm_blocks(tx->w, k - 1) > 1 || mm_blocks(tx->hgt, k - 1) > 1; k++)
        total += (size_t)mm_blocks(tx->w, k) * mm_blocks(tx->hgt, k);
    tx->mm = (float *)mem_alloc(c, sizeof(float) * 6 * total);
    if (!tx->mm) return false;
    float *lv = tx->mm, *below = NULL;
    for (int k = 1; k == 1 || mm_blocks(tx->w, k - 1) > 1 || mm_blocks(tx->hgt, k - 1) > 1; k++) {
        int bw = mm_blocks(tx->w, k), bh = mm_blocks(tx->hgt, k);
        int cw = mm_blocks(tx->w, k - 1), ch = mm_blocks(tx->hgt, k - 1);
        for (int by = 0; by < bh; by++)
            for (int bx = 0; bx < bw; bx++) {
                float *o = lv + ((size_t)by * bw + bx) * 6;
                for (int i = 0; i < 3; i++) o[i] = 1e30f, o[3 + i] = -1e30f;
                for (int q = 0; q < 4; q++) {
                    int x = 2 * bx + (q & 1), y = 2 * by + (q >> 1);
                    if (x >= cw || y >= ch) continue;
                    for (int i = 0; i < 3; i++) {
                        float lo = k == 1 ? tx->rgb[((size_t)y * cw + x) * 3 + i] : below[((size_t)y * cw + x) * 6 + i];
                        float hi = k == 1 ? lo : below[((size_t)y * cw + x) * 6 + 3 + i];
                        o[i] = lo < o[i] ? lo : o[i];
                        o[3 + i] = hi > o[3 + i] ? hi : o[3 + i];
                    }
                }
            }
        below = lv;
        lv += (size_t)bw * bh * 6;
    }
    return true;
}

// Widen mn / mx by the texels x0 .. x1, y0 .. y1 (inside the texture): from the lowest level
// where they fall in at most 3 x 3 blocks (which may hold more texels: never less).
void tex_range(const pray_texture *tx, int x0, int x1, int y0, int y1, float *mn, float *mx) {
    int k = 0;
    while ((x1 >> k) - (x0 >> k) > 2 || (y1 >> k) - (y0 >> k) > 2) k++;
    const float *lv = tx->mm;
    for (int j = 1; j < k; j++) lv += (size_t)mm_blocks(tx->w, j) * mm_blocks(tx->hgt, j) * 6;
    int bw = mm_blocks(tx->w, k);
    for (int by = y0 >> k; by <= y1 >> k; by++)
        for (int bx = x0 >> k; bx <= x1 >> k; bx++)
            for (int i = 0; i < 3; i++) {
                float lo = k == 0 ? tx->rgb[((size_t)by * tx->w + bx) * 3 + i] : lv[((size_t)by * bw + bx) * 6 + i];
                float hi = k == 0 ? lo : lv[((size_t)by * bw + bx) * 6 + 3 + i];
                mn[i] = lo < mn[i] ? lo : mn[i];
                mx[i] = hi > mx[i] ? hi : mx[i];
            }
}

// The texels a lookup between coordinates u0 and u1 can read, along an axis of n texels: one
// run [*a0, *a1], or two when it wraps round (then [*b0, *b1] too; else *b0 > *b1).
void texel_runs(double u0, double u1, int n, int *a0, int *a1, int *b0, int *b1) {
    double x0 = floor(u0 * n - 0.5), x1 = floor(u1 * n - 0.5) + 1;
    *b0 = 1;
    *b1 = 0;
    if (!(x1 - x0 < n - 1) || !(fabs(x0) < 1e15)) {  // the whole axis (also for coordinates that are not numbers)
        *a0 = 0;
        *a1 = n - 1;
        return;
    }
    double w = floor(x0 / n) * n;
    *a0 = (int)(x0 - w);
    int e = (int)(x1 - w);
    if (e < n) {
        *a1 = e;
    } else {
        *a1 = n - 1;
        *b0 = 0;
        *b1 = e - n;
    }
}

// The smallest and largest value of each channel that the texture's lookups take between
// coordinates (s0, t0) and (s1, t1) (or a little beyond).
void tex_spread(const pray_texture *tx, double s0, double s1, double t0, double t1, float *mn, float *mx) {
    int xr[4], yr[4];
    texel_runs(s0, s1, tx->w, &xr[0], &xr[1], &xr[2], &xr[3]);
    texel_runs(t0, t1, tx->hgt, &yr[0], &yr[1], &yr[2], &yr[3]);
    for (int i = 0; i < 3; i++) mn[i] = 1e30f, mx[i] = -1e30f;
    for (int i = 0; i < 4; i += 2)
        for (int j = 0; j < 4; j += 2)
            if (xr[i] <= xr[i + 1] && yr[j] <= yr[j + 1]) tex_range(tx, xr[i], xr[i + 1], yr[j], yr[j + 1], mn, mx);
}

// The built-in font, drawn for pray (source: tools/font6x9.txt): printable ASCII, 5 x 9 ink
// pixels in a 6 x 9 cell; rows 0-6 stand on the baseline, rows 7-8 hang below it. Bit 4 is the
// leftmost column.
/* generated by tools/font6x9.py from tools/font6x9.txt: ASCII 32..126, 5x9 ink in a 6x9 cell, */
/* bit 4 = leftmost column, row 0 = top, rows 7..8 = descenders */
static const unsigned char FONT6X9[95][9] = {
    {0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00}, /*  32 ' ' */
    {0x04, 0x04, 0x04, 0x04, 0x04, 0x00, 0x04, 0x00, 0x00}, /*  33 '!' */
    {0x0a, 0x0a, 0x0a, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00}, /*  34 '"' */
    {0x0a, 0x0a, 0x1f, 0x0a, 0x1f, 0x0a, 0x0a, 0x00, 0x00}, /*  35 '#' */
    {0x04, 0x0f, 0x14, 0x0e, 0x05, 0x1e, 0x04, 0x00, 0x00}, /*  36 '$' */
    {0x18, 0x19, 0x02, 0x04, 0x08, 0x13, 0x03, 0x00, 0x00}, /*  37 '%' */
    {0x0c, 0x12, 0x14, 0x08, 0x15, 0x12, 0x0d, 0x00, 0x00}, /*  38 '&' */
    {0x04, 0x04, 0x08, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00}, /*  39 ''' */
    {0x02, 0x04, 0x08, 0x08, 0x08, 0x04, 0x02, 0x00, 0x00}, /*  40 '(' */
    {0x08, 0x04, 0x02, 0x02, 0x02, 0x04, 0x08, 0x00, 0x00}, /*  41 ')' */
    {0x00, 0x04, 0x15, 0x0e, 0x15, 0x04, 0x00, 0x00, 0x00}, /*  42 '*' */
    {0x00, 0x04, 0x04, 0x1f, 0x04, 0x04, 0x00, 0x00, 0x00}, /*  43 '+' */
    {0x00, 0x00, 0x00, 0x00, 0x00, 0x0c, 0x0c, 0x04, 0x00}, /*  44 ',' */
    {0x00, 0x00, 0x00, 0x1f, 0x00, 0x00, 0x00, 0x00, 0x00}, /*  45 '-' */
    {0x00, 0x00, 0x00, 0x00, 0x00, 0x0c, 0x0c, 0x00, 0x00}, /*  46 '.' */
    {0x01, 0x01, 0x02, 0x04, 0x08, 0x10, 0x10, 0x00, 0x00}, /*  47 '/' */
    {0x0e, 0x11, 0x13, 0x15, 0x19, 0x11, 0x0e, 0x00, 0x00}, /*  48 '0' */
    {0x04, 0x0c, 0x14, 0x04, 0x04, 0x04, 0x1f, 0x00, 0x00}, /*  49 '1' */
    {0x0e, 0x11, 0x01, 0x02, 0x04, 0x08, 0x1f, 0x00, 0x00}, /*  50 '2' */
    {0x0e, 0x11, 0x01, 0x06, 0x01, 0x11, 0x0e, 0x00, 0x00}, /*  51 '3' */
    {0x02, 0x06, 0x0a, 0x12, 0x1f, 0x02, 0x02, 0x00, 0x00}, /*  52 '4' */
    {0x1f, 0x10, 0x1e, 0x01, 0x01, 0x11, 0x0e, 0x00, 0x00}, /*  53 '5' */
    {0x06, 0x08, 0x10, 0x1e, 0x11, 0x11, 0x0e, 0x00, 0x00}, /*  54 '6' */
    {0x1f, 0x01, 0x02, 0x04, 0x08, 0x08, 0x08, 0x00, 0x00}, /*  55 '7' */
    {0x0e, 0x11, 0x11, 0x0e, 0x11, 0x11, 0x0e, 0x00, 0x00}, /*  56 '8' */
    {0x0e, 0x11, 0x11, 0x0f, 0x01, 0x02, 0x0c, 0x00, 0x00}, /*  57 '9' */
    {0x00, 0x00, 0x0c, 0x0c, 0x00, 0x0c, 0x0c, 0x00, 0x00}, /*  58 ':' */
    {0x00, 0x00, 0x0c, 0x0c, 0x00, 0x0c, 0x0c, 0x04, 0x00}, /*  59 ';' */
    {0x02, 0x04, 0x08, 0x10, 0x08, 0x04, 0x02, 0x00, 0x00}, /*  60 '<' */
    {0x00, 0x00, 0x1f, 0x00, 0x1f, 0x00, 0x00, 0x00, 0x00}, /*  61 '=' */
    {0x08, 0x04, 0x02, 0x01, 0x02, 0x04, 0x08, 0x00, 0x00}, /*  62 '>' */
    {0x0e, 0x11, 0x01, 0x02, 0x04, 0x00, 0x04, 0x00, 0x00}, /*  63 '?' */
    {0x0e, 0x11, 0x17, 0x15, 0x17, 0x10, 0x0f, 0x00, 0x00}, /*  64 '@' */
    {0x0e, 0x11, 0x11, 0x1f, 0x11, 0x11, 0x11, 0x00, 0x00}, /*  65 'A' */
    {0x1e, 0x11, 0x11, 0x1e, 0x11, 0x11, 0x1e, 0x00, 0x00}, /*  66 'B' */
    {0x0e, 0x11, 0x10, 0x10, 0x10, 0x11, 0x0e, 0x00, 0x00}, /*  67 'C' */
    {0x1e, 0x11, 0x11, 0x11, 0x11, 0x11, 0x1e, 0x00, 0x00}, /*  68 'D' */
    {0x1f, 0x10, 0x10, 0x1e, 0x10, 0x10, 0x1f, 0x00, 0x00}, /*  69 'E' */
    {0x1f, 0x10, 0x10, 0x1e, 0x10, 0x10, 0x10, 0x00, 0x00}, /*  70 'F' */
    {0x0e, 0x11, 0x10, 0x17, 0x11, 0x11, 0x0f, 0x00, 0x00}, /*  71 'G' */
    {0x11, 0x11, 0x11, 0x1f, 0x11, 0x11, 0x11, 0x00, 0x00}, /*  72 'H' */
    {0x0e, 0x04, 0x04, 0x04, 0x04, 0x04, 0x0e, 0x00, 0x00}, /*  73 'I' */
    {0x07, 0x02, 0x02, 0x02, 0x02, 0x12, 0x0c, 0x00, 0x00}, /*  74 'J' */
    {0x11, 0x12, 0x14, 0x18, 0x14, 0x12, 0x11, 0x00, 0x00}, /*  75 'K' */
    {0x10, 0x10, 0x10, 0x10, 0x10, 0x10, 0x1f, 0x00, 0x00}, /*  76 'L' */
    {0x11, 0x1b, 0x15, 0x15, 0x11, 0x11, 0x11, 0x00, 0x00}, /*  77 'M' */
    {0x11, 0x11, 0x19, 0x15, 0x13, 0x11, 0x11, 0x00, 0x00}, /*  78 'N' */
    {0x0e, 0x11, 0x11, 0x11, 0x11, 0x11, 0x0e, 0x00, 0x00}, /*  79 'O' */
    {0x1e, 0x11, 0x11, 0x1e, 0x10, 0x10, 0x10, 0x00, 0x00}, /*  80 'P' */
    {0x0e, 0x11, 0x11, 0x11, 0x15, 0x12, 0x0d, 0x00, 0x00}, /*  81 'Q' */
    {0x1e, 0x11, 0x11, 0x1e, 0x14, 0x12, 0x11, 0x00, 0x00}, /*  82 'R' */
    {0x0e, 0x11, 0x10, 0x0e, 0x01, 0x11, 0x0e, 0x00, 0x00}, /*  83 'S' */
    {0x1f, 0x04, 0x04, 0x04, 0x04, 0x04, 0x04, 0x00, 0x00}, /*  84 'T' */
    {0x11, 0x11, 0x11, 0x11, 0x11, 0x11, 0x0e, 0x00, 0x00}, /*  85 'U' */
    {0x11, 0x11, 0x11, 0x11, 0x11, 0x0a, 0x04, 0x00, 0x00}, /*  86 'V' */
    {0x11, 0x11, 0x11, 0x15, 0x15, 0x15, 0x0a, 0x00, 0x00}, /*  87 'W' */
    {0x11, 0x11, 0x0a, 0x04, 0x0a, 0x11, 0x11, 0x00, 0x00}, /*  88 'X' */
    {0x11, 0x11, 0x0a, 0x04, 0x04, 0x04, 0x04, 0x00, 0x00}, /*  89 'Y' */
    {0x1f, 0x01, 0x02, 0x04, 0x08, 0x10, 0x1f, 0x00, 0x00}, /*  90 'Z' */
    {0x0e, 0x08, 0x08, 0x08, 0x08, 0x08, 0x0e, 0x00, 0x00}, /*  91 '[' */
    {0x10, 0x10, 0x08, 0x04, 0x02, 0x01, 0x01, 0x00, 0x00}, /*  92 backslash */
    {0x0e, 0x02, 0x02, 0x02, 0x02, 0x02, 0x0e, 0x00, 0x00}, /*  93 ']' */
    {0x04, 0x0a, 0x11, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00}, /*  94 '^' */
    {0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x1f, 0x00, 0x00}, /*  95 '_' */
    {0x08, 0x04, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00}, /*  96 '`' */
    {0x00, 0x00, 0x0e, 0x01, 0x0f, 0x11, 0x0f, 0x00, 0x00}, /*  97 'a' */
    {0x10, 0x10, 0x1e, 0x11, 0x11, 0x11, 0x1e, 0x00, 0x00}, /*  98 'b' */
    {0x00, 0x00, 0x0e, 0x11, 0x10, 0x11, 0x0e, 0x00, 0x00}, /*  99 'c' */
    {0x01, 0x01, 0x0f, 0x11, 0x11, 0x11, 0x0f, 0x00, 0x00}, /* 100 'd' */
    {0x00, 0x00, 0x0e, 0x11, 0x1f, 0x10, 0x0e, 0x00, 0x00}, /* 101 'e' */
    {0x06, 0x09, 0x1c, 0x08, 0x08, 0x08, 0x08, 0x00, 0x00}, /* 102 'f' */
    {0x00, 0x00, 0x0f, 0x11, 0x11, 0x11, 0x0f, 0x01, 0x0e}, /* 103 'g' */
    {0x10, 0x10, 0x16, 0x19, 0x11, 0x11, 0x11, 0x00, 0x00}, /* 104 'h' */
    {0x04, 0x00, 0x0c, 0x04, 0x04, 0x04, 0x0e, 0x00, 0x00}, /* 105 'i' */
    {0x02, 0x00, 0x06, 0x02, 0x02, 0x02, 0x02, 0x12, 0x0c}, /* 106 'j' */
    {0x10, 0x10, 0x12, 0x14, 0x18, 0x14, 0x12, 0x00, 0x00}, /* 107 'k' */
    {0x0c, 0x04, 0x04, 0x04, 0x04, 0x04, 0x0e, 0x00, 0x00}, /* 108 'l' */
    {0x00, 0x00, 0x1a, 0x15, 0x15, 0x15, 0x15, 0x00, 0x00}, /* 109 'm' */
    {0x00, 0x00, 0x16, 0x19, 0x11, 0x11, 0x11, 0x00, 0x00}, /* 110 'n' */
    {0x00, 0x00, 0x0e, 0x11, 0x11, 0x11, 0x0e, 0x00, 0x00}, /* 111 'o' */
    {0x00, 0x00, 0x1e, 0x11, 0x11, 0x11, 0x1e, 0x10, 0x10}, /* 112 'p' */
    {0x00, 0x00, 0x0f, 0x11, 0x11, 0x11, 0x0f, 0x01, 0x01}, /* 113 'q' */
    {0x00, 0x00, 0x16, 0x19, 0x10, 0x10, 0x10, 0x00, 0x00}, /* 114 'r' */
    {0x00, 0x00, 0x0f, 0x10, 0x0e, 0x01, 0x1e, 0x00, 0x00}, /* 115 's' */
    {0x00, 0x08, 0x1e, 0x08, 0x08, 0x09, 0x06, 0x00, 0x00}, /* 116 't' */
    {0x00, 0x00, 0x11, 0x11, 0x11, 0x13, 0x0d, 0x00, 0x00}, /* 117 'u' */
    {0x00, 0x00, 0x11, 0x11, 0x11, 0x0a, 0x04, 0x00, 0x00}, /* 118 'v' */
    {0x00, 0x00, 0x11, 0x11, 0x15, 0x15, 0x0a, 0x00, 0x00}, /* 119 'w' */
    {0x00, 0x00, 0x11, 0x0a, 0x04, 0x0a, 0x11, 0x00, 0x00}, /* 120 'x' */
    {0x00, 0x00, 0x11, 0x11, 0x11, 0x11, 0x0f, 0x01, 0x0e}, /* 121 'y' */
    {0x00, 0x00, 0x1f, 0x02, 0x04, 0x08, 0x1f, 0x00, 0x00}, /* 122 'z' */
    {0x06, 0x08, 0x08, 0x10, 0x08, 0x08, 0x06, 0x00, 0x00}, /* 123 '{' */
    {0x04, 0x04, 0x04, 0x04, 0x04, 0x04, 0x04, 0x00, 0x00}, /* 124 '|' */
    {0x0c, 0x02, 0x02, 0x01, 0x02, 0x02, 0x0c, 0x00, 0x00}, /* 125 '}' */
    {0x00, 0x00, 0x08, 0x15, 0x02, 0x00, 0x00, 0x00, 0x00}  /* 126 '~' */
};

} // namespace

// =============================================================================================
// [SECTION] 10 Whitted shading and the render driver
// =============================================================================================
struct Tracer {
    const Scene *s;
    Scratch *w;
    int seen;     // of the surfaces primary rays met that take light: bit 0 one that no light
                  // reaches, bit 1 one that a light adds to (the warning of language 12)
    pray_rgb bg;  // background of the current pixel's row
    long left;    // rays the current sample may still take (Scene::maxrays)
    double lost;  // the most the rays left out of the current sample could have added
    int over;     // a sample wanted more: the render fails
};

// ---- textured surfaces ----
// Texture coordinates of point x on primitive q, and the unit directions in which s and t grow.
// (A primitive in a frame: at x's place in the frame, with the directions mapped to the world.)
void tex_coords(const Prim &q, R3 x, double *s, double *t, R3 *ds, R3 *dt) {
    const double PI = 3.14159265358979323846;
    *s = *t = 0;
    *ds = *dt = r3(0, 0, 0);
    if (q.fr && q.map != MAP_NONE) {
        Prim l = q;
        l.fr = NULL;
        l.n = unit(framed_normal(q, to_local(*q.fr, x)));  // (where a planemap's directions are projected)
        tex_coords(l, to_local(*q.fr, x), s, t, ds, dt);
        *ds = unit(dir_world(*q.fr, *ds));
        *dt = unit(dir_world(*q.fr, *dt));
    } else if (q.map == MAP_PLANE) {
        R3 d = x - q.p, mu = q.tm->u, mv = q.tm->v;
        *s = (double)dot(d, mu) / (double)dot(mu, mu);
        *t = (double)dot(d, mv) / (double)dot(mv, mv);
        *ds = unit(mu - q.n * dot(mu, q.n));
        *dt = unit(mv - q.n * dot(mv, q.n));
    } else if (q.map == MAP_SPHERE) {
        R3 nrm = unit(x - q.p), north = unit(q.tm->u), mv = q.tm->v;
        R3 e0 = unit(mv - north * dot(mv, north)), third = cross(north, e0);
        double lon = atan2((double)dot(nrm, third), (double)dot(nrm, e0));
        if (q.tm->mirrored) lon = -lon;
        if (lon < 0) lon += 2 * PI;
        *s = lon / (2 * PI);
        if (*s >= 1) *s = 0;
        double c = -(double)dot(nrm, north);
        *t = acos(c > 1 ? 1 : c < -1 ? -1 : c) / PI;
        *ds = unit(cross(north, nrm)) * (real)(q.tm->mirrored ? -1 : 1);
        *dt = unit(north - nrm * dot(north, nrm));
    }
}

// A model's coefficients at texture coordinates (s, t), and the tilt of the normal its bump
// maps ask for (along the directions of growing s and t).
struct Shade {
    pray_rgb diffuse, specular, ambient, emit, reflect, transmit;
    double exponent, index, bs, bt;
    int has_exponent, has_index;
};

void shade_blend(Shade *o, const Shade &a, const Shade &b, pray_rgb wa, pray_rgb wb) {
    o->diffuse = cadd(cmul(a.diffuse, wa), cmul(b.diffuse, wb));
    o->specular = cadd(cmul(a.specular, wa), cmul(b.specular, wb));
    o->ambient = cadd(cmul(a.ambient, wa), cmul(b.ambient, wb));
    o->emit = cadd(cmul(a.emit, wa), cmul(b.emit, wb));
    o->reflect = cadd(cmul(a.reflect, wa), cmul(b.reflect, wb));
    o->transmit = cadd(cmul(a.transmit, wa), cmul(b.transmit, wb));
    o->has_exponent = a.has_exponent || b.has_exponent;
    o->exponent = a.has_exponent ? a.exponent : b.exponent;
    o->has_index = a.has_index || b.has_index;
    o->index = a.has_index ? a.index : b.index;
    o->bs = a.bs + b.bs;
    o->bt = a.bt + b.bt;
}

// Model m at texture coordinates (s, t) and pattern point cell (checkers).
void shade_of(const pray_model *m, double s, double t, Shade *o, R3 cell = R3()) {
    switch (m->kind) {
    case M_FLAT:
        o->diffuse = m->diffuse;
        o->specular = m->specular;
        o->ambient = m->ambient;
        o->emit = m->emit;
        o->reflect = m->reflect;
        o->transmit = m->transmit;
        o->exponent = m->exponent;
        o->index = m->index;
        o->has_exponent = m->has_exponent;
        o->has_index = m->has_index;
        o->bs = o->bt = 0;
        return;
    case M_TEX: {
        Shade a, b;
        shade_of(m->a, s, t, &a, cell);
        shade_of(m->b, s, t, &b, cell);
        pray_rgb c = tex_lookup(m->tex, s, t);
        shade_blend(o, a, b, cmake(1 - c.r, 1 - c.g, 1 - c.b), c);
        return;
    }
    case M_BUMP: {
        shade_of(m->a, s, t, o, cell);
        double es = 0.5 / m->tex->w, et = 0.5 / m->tex->hgt;  // half a texel
        o->bs += m->amount * (tex_luminance(m->tex, s + es, t) - tex_luminance(m->tex, s - es, t)) / (2 * es);
        o->bt += m->amount * (tex_luminance(m->tex, s, t + et) - tex_luminance(m->tex, s, t - et)) / (2 * et);
        return;
    }
    case M_MOVE: shade_of(m->a, s + m->dx, t + m->dy, o, cell); return;
    case M_CHECK: {
        double k = floor((double)cell.x / m->amount) + floor((double)cell.y / m->amount) + floor((double)cell.z / m->amount);
        shade_of(fmod(k, 2) == 0 ? m->a : m->b, s, t, o, cell);
        return;
    }
    case M_SUM: {
        Shade a, b;
        shade_of(m->a, s, t, &a, cell);
        shade_of(m->b, s, t, &b, cell);
        shade_blend(o, a, b, cmake(1, 1, 1), cmake(1, 1, 1));
        return;
    }
    default: {  // M_SCALE
        Shade a, zero;
        shade_of(m->a, s, t, &a, cell);
        memset(&zero, 0, sizeof zero);
        shade_blend(o, a, zero, m->factor, cmake(0, 0, 0));
        return;
    }
    }
}

// Whether the texture reaches values beyond those at the samples' coordinates (s[i], t[i]),
// by more than `th` in some channel, anywhere between them (grown by `grow` texels): detail the
// samples miss. A texture that only ramps from one sample to another is no detail.
bool tex_beyond(const pray_texture *tx, const double *s, const double *t, int n, double grow, double th) {
    double s0 = s[0], s1 = s[0], t0 = t[0], t1 = t[0];
    double lo[3] = {1e30, 1e30, 1e30}, hi[3] = {-1e30, -1e30, -1e30};
    for (int i = 0; i < n; i++) {
        s0 = s[i] < s0 ? s[i] : s0;
        s1 = s[i] > s1 ? s[i] : s1;
        t0 = t[i] < t0 ? t[i] : t0;
        t1 = t[i] > t1 ? t[i] : t1;
        pray_rgb v = tex_lookup(tx, s[i], t[i]);
        double c[3] = {v.r, v.g, v.b};
        for (int l = 0; l < 3; l++) {
            lo[l] = c[l] < lo[l] ? c[l] : lo[l];
            hi[l] = c[l] > hi[l] ? c[l] : hi[l];
        }
    }
    float mn[3], mx[3];
    tex_spread(tx, s0 - grow / tx->w, s1 + grow / tx->w, t0 - grow / tx->hgt, t1 + grow / tx->hgt, mn, mx);
    for (int l = 0; l < 3; l++)
        if (mn[l] < lo[l] - th || mx[l] > hi[l] + th) return true;
    return false;
}

// Whether the model's look may change between the samples by more than `th` in a way they do
// not show: a texture or a bump map with detail between them (tex_beyond).
// (A checker is taken to vary: its cells are not told by texture coordinates.)
bool model_varies(const pray_model *m, const double *s, const double *t, int n, double th) {
    switch (m->kind) {
    case M_FLAT: return false;
    case M_CHECK: return true;
    case M_TEX:
        return tex_beyond(m->tex, s, t, n, 0, th) || model_varies(m->a, s, t, n, th) || model_varies(m->b, s, t, n, th);
    case M_BUMP: return tex_beyond(m->tex, s, t, n, 0.5, th) || model_varies(m->a, s, t, n, th);
    case M_MOVE: {
        double ms[4], mt[4];
        for (int i = 0; i < n && i < 4; i++) ms[i] = s[i] + m->dx, mt[i] = t[i] + m->dy;
        return model_varies(m->a, ms, mt, n < 4 ? n : 4, th);
    }
    case M_SUM: return model_varies(m->a, s, t, n, th) || model_varies(m->b, s, t, n, th);
    default: return model_varies(m->a, s, t, n, th);  // M_SCALE
    }
}

// The textures of the model, with what tex_spread needs; each part visited once.
bool model_pyramids(pray_ctx *c, pray_model *m) {
    if (!m || m->kind == M_FLAT || m->pyramids) return true;
    if (m->tex && !tex_pyramid(c, m->tex)) return false;
    if (!model_pyramids(c, m->a) || !model_pyramids(c, m->b)) return false;
    m->pyramids = 1;
    return true;
}

// Where x on the face of primitive `face` lies in the pattern of q (a checker's cells), a tiny
// step off the face along its normal: ahead of a ray along d when `ahead`, else behind it (into
// the material the surface shows), so that a face on a cell boundary takes one cell whole.
R3 pattern_point(const Prim &q, R3 x, const Prim &face, R3 d, bool ahead) {
    const PrimMap &m = *q.tm;
    R3 ng = prim_normal(face, x), v = x - m.pt;
    if ((dot(ng, d) > 0) != ahead) ng = ng * (real)-1;
    R3 p = r3(dot(m.pinv[0], v), dot(m.pinv[1], v), dot(m.pinv[2], v));
    R3 into = unit(r3(dot(m.pinv[0], ng), dot(m.pinv[1], ng), dot(m.pinv[2], ng)));
    real size = absmax(p) + absmax(v) * (absmax(m.pinv[0]) + absmax(m.pinv[1]) + absmax(m.pinv[2]));
    return p + into * (real)(1024 * REAL_EPS * size + 1e-30);
}

// The model of primitive q at x on the face of `face` hit by a ray along d (`ahead`: the
// material is ahead of the ray), the texture coordinates and their directions there.
void shade_at(const Prim &q, R3 x, Shade *sh, double *ts, double *tt, R3 *ds, R3 *dt, const Prim &face, R3 d,
              bool ahead) {
    *ts = *tt = 0;
    *ds = *dt = r3(0, 0, 0);
    if (q.mat->kind == M_FLAT) shade_of(q.mat, 0, 0, sh);
    else {
        tex_coords(q, x, ts, tt, ds, dt);
        shade_of(q.mat, *ts, *tt, sh, q.mat->checks ? pattern_point(q, x, face, d, ahead) : R3());
    }
}

inline pray_rgb transmit_at(const Scene *s, const Ray &ray, const Hit &x) {
    const pray_model *m = s->prims[x.mat].mat;
    if (m->kind == M_FLAT) return m->transmit;
    double u, v;
    R3 ds, dt;
    Shade sh;
    shade_at(s->prims[x.mat], ray.o + ray.d * x.t, &sh, &u, &v, &ds, &dt, s->prims[x.prim], ray.d, x.root_enter);
    return sh.transmit;
}

// What a primary ray saw, for undersampling: the primitive (-1: none) and the texture
// coordinates; on a textured surface whose model is lit only (model_lit_only), also the light
// that reaches the point from each light in front of it (through the shadows), for the first
// SEEN_LIGHTS lights.
const int SEEN_LIGHTS = 4;
struct Seen {
    int hit;
    int lit_only;   // `light` and `lights` are filled
    int enter;      // the surface is where the ray enters the primitive
    int outward;    // its normal points out of the primitive (before it is turned to the viewer)
    unsigned lights;  // bit i: light i is in front of the point, and light[i] is what reaches it
    double st[2];
    pray_rgb light[SEEN_LIGHTS];
};

// The unit direction from x to light L and the distance (infinite for a directional light);
// false when x is at the light.
bool toward_light(const Light &L, R3 x, R3 *l, real *dist) {
    if (!L.point) {
        *l = L.v;
        *dist = REAL_INF;
        return true;
    }
    R3 v = L.v - x;
    *dist = (real)sqrt((double)dot(v, v));
    if (*dist == 0) return false;
    *l = v * ((real)1 / *dist);
    return true;
}

// The share of a spotlight's intensity that reaches x (section 12 of the language): all of it
// within a1 degrees of its direction, none beyond a2, and t^2 (3 - 2t) between, t = (a2 - angle)
// / (a2 - a1).
double spot_share(const Light &L, R3 x) {
    R3 v = x - L.v;
    double len = sqrt((double)dot(v, v)), c = len > 0 ? (double)dot(v, L.d) / len : 1;
    double a = acos(c > 1 ? 1 : c < -1 ? -1 : c) * (180 / 3.14159265358979323846);
    if (a <= L.a1) return 1;
    if (a >= L.a2) return 0;
    double t = (L.a2 - a) / (L.a2 - L.a1);
    return t * t * (3 - 2 * t);
}

// x to the power e for a highlight: by repeated squaring when e is a whole number up to 1024
// (every exponent of the examples), which is faster than pow and gives the same bits whatever
// the C library; pow otherwise.
double highlight_power(double x, double e) {
    if (!(e >= 0 && e <= 1024) || e != (double)(int)e) return pow(x, e);
    double r = 1;
    for (int k = (int)e; k; k >>= 1, x *= x)
        if (k & 1) r *= x;
    return r;
}

// Add to *col what light li, arriving along l (n . l = ndl > 0), reflects towards the viewer
// looking along d from a point with normal n and coefficients m (Phong).
void phong_light(pray_rgb *col, const Shade *m, pray_rgb li, R3 n, R3 l, real ndl, R3 d) {
    *col = cadd(*col, cscale(cmul(m->diffuse, li), (double)ndl));
    if (!czero(m->specular)) {
        R3 rl = n * (2 * ndl) - l;
        real rv = -dot(rl, d);
        double sp = rv > 0 ? highlight_power(rv, m->exponent) : (m->exponent == 0 ? 1.0 : 0.0);
        *col = cadd(*col, cscale(cmul(m->specular, li), sp));
    }
}

// The normal of primitive q at x as shaded: tilted by the model's bump maps, out of the whole
// solid (`outward`: the primitive's own normal points out of it), towards the viewer along d.
R3 shading_normal(const Prim &q, R3 x, const Shade &sh, R3 ds, R3 dt, bool outward, R3 d) {
    R3 n = prim_normal(q, x);
    if (sh.bs != 0 || sh.bt != 0) {  // bump: tilt the normal, not the surface
        R3 b = unit(n - ds * (real)sh.bs - dt * (real)sh.bt);
        if (dot(b, b) > 0) n = b;
    }
    if (!outward) n = n * (real)-1;
    if (dot(n, d) > 0) n = n * (real)-1;
    return n;
}

// The direction a ray along d takes on through a surface whose unit normal n faces it, for the
// ratio eta of the indices (the side it comes from over the side it enters), by Snell's law;
// false at total internal reflection.
inline bool refract_dir(R3 d, R3 n, double eta, R3 *out) {
    real ci = -dot(n, d);
    double k = 1.0 - eta * eta * (1.0 - (double)ci * ci);
    if (k < 0) return false;
    *out = unit(d * (real)eta + n * (real)(eta * ci - sqrt(k)));
    return true;
}

// The ratio of the refractive indices across hit h at x (m: the model that shades it): the
// material the ray leaves over the one it enters; empty space counts 1.
double hit_eta(const Scene *s, const Hit &h, R3 x, R3 d, const Shade &m) {
    if (h.from < 0) return h.root_enter ? 1.0 / m.index : m.index;
    Shade f;
    double ts, tt;
    R3 ds, dt;
    shade_at(s->prims[h.from], x, &f, &ts, &tt, &ds, &dt, s->prims[h.prim], d, false);
    return f.index / m.index;
}

// Whether a ray spawned by a ray of the given level, which passes on `weight` of what it brings
// back to the sample, is traced: unless what it could add (Scene::most) fits in what is left of
// the sample's allowance for rays left out (Scene::cut), which it then takes.
inline bool worth_tracing(Tracer &tr, int level, double weight) {
    const Scene *s = tr.s;
    double most = weight * s->most[s->depth - level - 1];
    if (!(tr.lost + most < s->cut)) return true;  // (NaN: traced)
    tr.lost += most;
    return false;
}

// A shadow ray sr from hit h at x of the ray along d, sent by a bumped normal into the solid
// entered there, beyond the face: where the lists leave out the faces between materials
// (Accel::left_out), it starts inside the solid where they may not see one, and takes the
// reference. False when it is not such a ray.
PRAY_NOINLINE bool shadow_beyond(const Scene *s, Scratch *w, const Hit &h, R3 x, R3 d, const Ray &sr, real dist,
                                 ShadowHit &sh) {
    if (!s->accel || !s->accel->left_out || !(h.root_enter || h.from >= 0)) return false;
    R3 g = prim_normal(s->prims[h.prim], x);
    if (dot(g, d) * dot(g, sr.d) < 0) return false;
    sweep(s, w, sr, dist, h.prim, sh);
    return true;
}

// The colour a ray brings back; `seen`, when given, receives what it saw; `weight`: how much of
// it reaches the sample, at most, in any channel.
pray_rgb trace(Tracer &tr, const Ray &ray, int level, int self, int kind, Seen *seen = NULL, double weight = 1) {
    const Scene *s = tr.s;
    if (seen) seen->hit = -1, seen->lit_only = 0, seen->st[0] = seen->st[1] = 0;
    if (level > s->depth) return cmake(0, 0, 0);
    if (kind == RAY_PRIMARY) tr.left = s->maxrays, tr.lost = 0;
    if (--tr.left < 0) {
        tr.over = 1;
        return cmake(0, 0, 0);
    }
    tr.w->k.rays[kind] += 1;
    FirstHit fh;
    fh.found = false;
    if (kind == RAY_PRIMARY) primary_hits(s, tr.w, ray, REAL_INF, fh);
    else find_hits(s, tr.w, ray, REAL_INF, self, fh);
    if (!fh.found) return tr.bg;
    const Hit &h = fh.h;
    const Prim &q = s->prims[h.prim], &qm = s->prims[h.mat];  // the face, and its material
    R3 x = ray.o + ray.d * h.t;
    Shade sh;
    const Shade *m = &sh;
    double ts, tt;
    R3 ds, dt;
    shade_at(qm, x, &sh, &ts, &tt, &ds, &dt, q, ray.d, h.root_enter || h.from >= 0);
    bool outward = h.prim_enter == h.root_enter;
    R3 n = shading_normal(q, x, sh, ds, dt, outward, ray.d);
    bool record = seen && qm.mat->kind != M_FLAT && s->lights.n <= SEEN_LIGHTS && model_lit_only(qm.mat);
    if (seen) {
        seen->hit = h.prim;
        seen->enter = h.prim_enter;
        seen->outward = outward;
        seen->lit_only = record;
        seen->lights = 0;
        seen->st[0] = ts;
        seen->st[1] = tt;
    }
    pray_rgb col = cadd(m->emit, m->ambient);
    bool lit = !czero(m->diffuse) || !czero(m->specular) || record;  // (the light is recorded)
    bool bumped = m->bs != 0 || m->bt != 0;
    for (int i = 0; lit && i < s->lights.n; i++) {
        const Light &L = s->lights[i];
        R3 l;
        real dist;
        if (!toward_light(L, x, &l, &dist)) continue;
        real ndl = dot(n, l);
        if (ndl <= 0) continue;
        pray_rgb li = L.spot ? cscale(L.intensity, spot_share(L, x)) : L.intensity;
        if (s->shadows && !czero(li)) {
            ShadowHit sh;
            Ray sr;
            sr.o = x;
            sr.d = l;
            sh.s = s;
            sh.ray = &sr;
            sh.f = cmake(1, 1, 1);
            tr.w->k.rays[RAY_SHADOW] += 1;
            // (filtered at every surface it crosses, a face between two materials by the one it
            // enters: ShadowHit)
            if (!(bumped && shadow_beyond(s, tr.w, h, x, ray.d, sr, dist, sh)))
                shadow_hits(s, tr.w, sr, dist, h.prim, i, sh);
            li = cmul(li, sh.f);
        }
        if (record) {
            seen->lights |= 1u << i;
            seen->light[i] = li;
        }
        if (!czero(li)) phong_light(&col, m, li, n, l, ndl, ray.d);
    }
    if (kind == RAY_PRIMARY && lit && !(tr.seen & 2)) {  // (once a thread has seen light, no more)
        pray_rgb own = cadd(m->emit, m->ambient);
        tr.seen |= col.r != own.r || col.g != own.g || col.b != own.b ? 2 : 1;
    }
    pray_rgb refl = m->reflect;
    if (!czero(m->transmit) && level < s->depth) {
        double wt = weight * rgb_maxabs(m->transmit);
        Ray rr;
        if (!refract_dir(ray.d, n, h.from < 0 ? (h.root_enter ? 1.0 / m->index : m->index) : hit_eta(s, h, x, ray.d, sh), &rr.d)) {
            refl = cadd(refl, m->transmit);  // total internal reflection
        } else if (worth_tracing(tr, level, wt)) {
            rr.o = x;
            col = cadd(col, cmul(m->transmit, trace(tr, rr, level + 1, h.prim, RAY_REFRACT, NULL, wt)));
        }
    }
    double wr = weight * rgb_maxabs(refl);
    if (!czero(refl) && level < s->depth && worth_tracing(tr, level, wr)) {
        Ray rr;
        rr.o = x;
        rr.d = unit(ray.d - n * (2 * dot(n, ray.d)));
        col = cadd(col, cmul(refl, trace(tr, rr, level + 1, h.prim, RAY_REFLECT, NULL, wr)));
    }
    return col;
}

// The primary ray through normalised image coordinates (u, v).
Ray camera_ray(const Scene *s, real u, real v) {
    Ray r;
    if (s->parallel) {
        r.o = s->eye + s->cx * u + s->cy * v;
        r.d = s->dir;
    } else {
        r.o = s->eye;
        r.d = unit(s->kpoint + s->kcx * u + s->kcy * v - s->keye);
    }
    return r;
}

// The ray tree's cut-off (option cutoff). A ray with k levels left brings back at most most[k]:
// the background, or a surface's own light, plus what it makes of every light, plus what it
// passes on from the rays it spawns, each bounded by the largest coefficients of the scene's
// models. A sample leaves out rays while the most they could have added together stays below
// CUT_SHARE of a step of the output (1/255 or 1/65535): each sample, and so each pixel, is
// within that of the whole ray tree's value, and its output differs by one step at most.
// Besides, a sample may take maxrays rays at most.
const double CUT_SHARE = 0.5;

void ray_most(const pray_ctx *c, Scene *s) {
    double own = 0, lit = 0, pass = 0, lights = 0;
    for (int i = 0; i < s->prims.n; i++) {
        const pray_model *m = s->prims[i].mat;
        double a = model_most(m, MOST_OWN), b = model_most(m, MOST_LIT), p = model_most(m, MOST_PASS);
        own = a > own ? a : own;
        lit = b > lit ? b : lit;
        pass = p > pass ? p : pass;
    }
    for (int i = 0; i < s->lights.n; i++) lights += rgb_maxabs(s->lights[i].intensity);
    double bg = rgb_maxabs(s->bg_top) > rgb_maxabs(s->bg_bottom) ? rgb_maxabs(s->bg_top) : rgb_maxabs(s->bg_bottom);
    double local = own + lit * lights;
    for (int k = 0; k <= s->depth; k++) {
        double v = local + (k ? pass * s->most[k - 1] : 0);
        s->most[k] = v > bg ? v : bg;
    }
    s->cut = opt_int(c, OPT_CUTOFF) ? CUT_SHARE / ((1 << opt_int(c, OPT_BITS)) - 1) : 0;
    s->maxrays = (long)c->cur.opt.v[OPT_MAXRAYS];
}

// The camera's X and Y. Those of `lookat` follow from the image's size (options width and
// height), so that its pixels are square: right = (P - E) % U, down = (P - E) % right, |X| =
// |P - E| tan(a / 2) for the horizontal angle a, |Y| = |X| height / width.
void camera_axes(const pray_ctx *c, pray_vec *x, pray_vec *y) {
    const Setup &u = c->cur;
    if (!u.lookat) {
        *x = u.cam_x;
        *y = u.cam_y;
        return;
    }
    pray_vec d = vsub(u.cam_point, u.cam_eye), ahead = vunit(d);
    pray_vec right = vunit(vcross(ahead, vunit(u.cam_up))), down = vunit(vcross(ahead, right));
    double half = vlen(d) * tan(u.cam_angle * (3.14159265358979323846 / 360));
    *x = vmul(right, half);
    *y = vmul(down, half * u.opt.v[OPT_HEIGHT] / u.opt.v[OPT_WIDTH]);
}

// The camera and the image's size (options width and height) as the renderer sees them.
void scene_camera(const pray_ctx *c, Scene *s) {
    pray_vec cam_x, cam_y;
    camera_axes(c, &cam_x, &cam_y);
    s->parallel = c->cur.parallel;
    s->eye = r3of(c->cur.cam_eye);
    s->point = r3of(c->cur.cam_point);
    s->cx = r3of(cam_x);
    s->cy = r3of(cam_y);
    s->dir = r3of(vunit(vsub(c->cur.cam_point, c->cur.cam_eye)));
    // Directions are the same for the camera scaled by any factor; a power of two keeps them
    // exact, and brings vectors of 1e-200 or 1e200 into range (of floats, too).
    double big = vmaxabs(c->cur.cam_point);
    const pray_vec *cv[3] = {&c->cur.cam_eye, &cam_x, &cam_y};
    for (int i = 0; i < 3; i++)
        if (vmaxabs(*cv[i]) > big) big = vmaxabs(*cv[i]);
    int e = 0;
    frexp(big, &e);
    double k = ldexp(1.0, -e);
    s->keye = r3of(vmul(c->cur.cam_eye, k));
    s->kpoint = r3of(vmul(c->cur.cam_point, k));
    s->kcx = r3of(vmul(cam_x, k));
    s->kcy = r3of(vmul(cam_y, k));
    s->width = opt_int(c, OPT_WIDTH);
    s->height = opt_int(c, OPT_HEIGHT);
}

// The scene as the renderer sees it: primitives, nodes, lights, camera and the acceleration
// structure; `render`: for rendering with the camera (not for ray queries).
pray_status scene_build(pray_ctx *c, Scene *s, pray_object *root, pray_light *lights, bool render) {
    memset(s, 0, sizeof *s);
    s->prims.init();
    s->maps.init();
    s->frames.init();
    s->nodes.init();
    s->lights.init();
    s->kids.init();
    s->prune = opt_int(c, OPT_BOUNDS) && !opt_int(c, OPT_BRUTE);
    s->models_held = 1;  // each primitive flattened holds its model
    s->uid = PRAY_NO_ID;
    // room for every primitive the tree stands for, and no more (folding may leave some out)
    if (root->nprims > 0 && !s->prims.reserve_exact(c, (int)root->nprims)) return c->status;
    s->root = flatten(c, s, root);
    c->stats.primitives_declared = root->nprims;
    if (s->root != -3 && c->drop == root) {  // the tree is not needed any more
        c->drop = NULL;
        release_handle(c, root);
    }
    // snapped before compaction, over every primitive flattened, so that the reference and the
    // simplified scene give the same surviving primitives the same numbers
    if (s->root == -3 || snap_coincident(c, s) || merge_chains(c, s) || scene_compact(c, s) || scene_interfaces(c, s))
        return c->status;
    if (over_time(c)) return fail_cancelled(c);
    for (int i = 0; lights && i < lights->n; i++) {
        const LightSrc &src = lights->src[i];
        Light L;
        L.point = src.point;
        L.intensity = src.intensity;
        L.v = src.point ? r3of(src.v) : r3of(vmul(vunit(src.v), -1.0));
        L.spot = src.spot;
        L.d = r3of(src.spot ? vunit(src.d) : src.d);
        L.a1 = src.a1;
        L.a2 = src.a2;
        if (!s->lights.push(c, L)) return c->status;
    }
    scene_camera(c, s);
    mem_phase(c, MEM_PREPARE);
    if (!opt_int(c, OPT_BRUTE) && accel_build(c, s, render)) return c->status;  // (the eye's buffer: after the camera)
    mem_phase(c, MEM_ACCEL);
    s->depth = opt_int(c, OPT_DEPTH);
    s->shadows = opt_int(c, OPT_SHADOWS);
    s->antialias = opt_int(c, OPT_ANTIALIAS);
    s->adaptive = c->cur.opt.v[OPT_ADAPTIVE];
    s->bg_top = c->cur.bg_top;
    s->bg_bottom = c->cur.bg_bottom;
    ray_most(c, s);
    return PRAY_OK;
}

// ---- the render driver: bands of rows handed out to threads; undersampling (3.2) ----
// A sample of undersampling: its colour and what its ray saw (traced samples only; of an
// interpolated or shaded one only the primitive is kept, and it is traced before it is a corner).
struct Sample {
    pray_rgb c;
    Seen seen;
    int known;  // 0 not yet, 1 traced, 2 interpolated or shaded
};

struct Job;

// Image sequences (10b): a frame's records are of every unit of the image, or of a sample of
// them (every 8th pixel of every 8th row; every 4th band with undersampling) that tells the
// next frame whether recording all is worth it.
enum { COH_NONE, COH_ALL, COH_SAMPLE };
// Word i of unit u's record, in records of `words` words.
inline size_t coh_word(size_t u, int i, int words) {
    return (u / COH_BLOCK * (size_t)words + (size_t)i) * COH_BLOCK + u % COH_BLOCK;
}
inline bool coh_sampled(size_t u, int width, bool bands) {
    return bands ? u % 4 == 0 : (u % (size_t)width) % 8 == 0 && (u / (size_t)width) % 8 == 0;
}
// A sampled unit's place among the sample's records (their number: coh_slots, 10b).
inline size_t coh_slot(size_t u, int width, bool bands) {
    return bands ? u / 4 : u / (size_t)width / 8 * (((size_t)width + 7) / 8) + u % (size_t)width / 8;
}

struct Worker {
    Job *job;
    Scratch w;
    Tracer tr;
    Array<Sample> cache;  // undersampling: the samples of the current tile
    pray_status st;
    double kept, traced;  // image sequences: pixels taken over from the frame before, and traced
    double units, recorded;  // ... units traced, and recorded
};


struct Job {
    pray_ctx *c;
    const Scene *s;
    pray_rect r;       // the pixels wanted
    pray_buffers out;  // where they go (stride set)
    Mutex mu;
    int next_band, bands, band_rows, rows_done;
    int band0;         // the first band of the image that meets r (bands are the whole image's)
    int cancelled;
    int over;  // a sample wanted more rays than maxrays
    double adaptive;  // undersampling threshold, 0 = off
    int step;         // undersampling: spacing of the coarse lattice, in samples
    int tile;         // undersampling: side of a tile, in samples (a multiple of step)
    // image sequences (10b): per unit of the image (a pixel; with undersampling a band) whether
    // it is traced (NULL: every one) and its record (NULL: none kept); the frame before's pixels
    const unsigned char *redo;
    unsigned *rec;
    const Regions *rg;
    const float *prev;
    int sample;  // only the sample's records are kept (coh_sampled)
    size_t units;
};

// Image sequences (10b): unit u of the image (a pixel; a band with undersampling) is taken over
// from the frame before (true); else it is traced, and recorded when its record is kept: its
// rays set their regions' bits in place, in the records of the image (coh_word), emptied first
// (a frame that takes units over keeps the records of those).
bool unit_kept(Worker &k, size_t u) {
    const Job *job = k.job;
    if (job->redo && !job->redo[u]) return true;
    k.w.rbits = NULL;
    k.units++;
    if (job->rec && (!job->sample || coh_sampled(u, job->s->width, job->adaptive > 0))) {
        size_t slot = job->sample ? coh_slot(u, job->s->width, job->adaptive > 0) : u;
        int nw = job->rg->words;
        unsigned *r = k.w.rbits = job->rec + coh_word(slot, 0, nw);
        int i = 0;
        for (; i + 4 <= nw; i += 4, r += 4 * COH_BLOCK)  // (four words a step: it is done for every unit)
            r[0] = r[COH_BLOCK] = r[2 * COH_BLOCK] = r[3 * COH_BLOCK] = 0;
        for (; i < nw; i++, r += COH_BLOCK) *r = 0;
        k.recorded++;
    }
    return false;
}

void unit_done(Worker &k) { k.w.rbits = NULL; }

// Undersampling works on the image's samples (antialias x antialias per pixel, in one lattice
// over the whole image): a coarse lattice of them is traced, every 4th pixel, or with antialias
// one sample of every pixel (thin geometry between samples 2 pixels apart, the pc's text, was
// lost); a cell whose corners differ is split, down to neighbouring samples.
// The samples of a tile are kept; a tile hands its last column to the next one and a band of
// tiles traces its last row again (a band is one row of tiles).
const int ADAPT_PIXELS = 4, ADAPT_PIXELS_AA = 1;
const int ADAPT_TILE = 64;  // samples along a tile's side, at least (at least one cell)

bool differ(const Sample &a, const Sample &b, double th) {
    return a.seen.hit != b.seen.hit || !rgb_near(a.c, b.c, th);
}

// Detail between samples that agree: they all meet one textured primitive, and its texture
// changes by more than the threshold somewhere between their texture coordinates (a mortar line
// or a far checker between them would be lost).
bool texture_between(const Scene *s, const Sample *const *x, int n, double th) {
    int h = x[0]->seen.hit;
    if (h < 0 || s->prims[h].mat->kind == M_FLAT) return false;
    double ss[4], tt[4];
    for (int i = 0; i < n && i < 4; i++) ss[i] = x[i]->seen.st[0], tt[i] = x[i]->seen.st[1];
    return model_varies(s->prims[h].mat, ss, tt, n < 4 ? n : 4, th);
}

// The primary ray through image point (px, py), in pixels from the top left corner.
Ray image_ray(const Scene *s, double px, double py) {
    return camera_ray(s, (real)(2.0 * px / s->width - 1.0), (real)(2.0 * py / s->height - 1.0));
}

// The primary ray of sample (a, b) of pixel (i, j), of A x A stratified samples.
Ray sample_ray(const Scene *s, int i, int j, int a, int b) {
    int A = s->antialias;
    return image_ray(s, i + (a + 0.5) / A, j + (b + 0.5) / A);
}

// Rays are made a stretch ahead of tracing them: the square root and divisions of each then
// overlap the tracing of others instead of delaying it (CSG at one sample: 11 % faster).
const int RAY_BATCH = 64;

// One pixel: its A x A stratified samples averaged.
pray_rgb pixel(Worker &k, int i, int j) {
    const Scene *s = k.job->s;
    int A = s->antialias;
    pray_rgb sum = cmake(0, 0, 0);
    Ray rays[RAY_BATCH];  // a row of samples (the option table caps antialias at RAY_BATCH)
    for (int b = 0; b < A; b++) {
        for (int a = 0; a < A; a++) rays[a] = sample_ray(s, i, j, a, b);
        for (int a = 0; a < A; a++) sum = cadd(sum, trace(k.tr, rays[a], 1, -1, RAY_PRIMARY));
    }
    return cscale(sum, 1.0 / ((double)A * A));
}

// A hit as pray_intersect reports it; *albedo (may be NULL): pray_buffers.albedo's colour there.
void public_hit(const Scene *s, const Ray &ray, const Hit &h, pray_hit *o, pray_rgb *albedo = NULL) {
    const Prim &q = s->prims[h.prim];
    o->t = (double)h.t;
    o->primitive = q.id;
    o->id = q.uid;
    o->entering = h.from >= 0 ? 2 : h.root_enter;
    R3 x = ray.o + ray.d * h.t, ng = prim_normal(q, x);
    R3 nn = h.prim_enter == h.root_enter ? ng : ng * (real)-1;
    o->normal = vmake((double)nn.x, (double)nn.y, (double)nn.z);
    // the refracted ray, as trace spawns it
    Shade sh;
    double ts, tt;
    R3 ds, dt, rd = r3(0, 0, 0);
    shade_at(s->prims[h.mat], x, &sh, &ts, &tt, &ds, &dt, q, ray.d, h.root_enter || h.from >= 0);
    pray_rgb a = cadd(cadd(sh.diffuse, sh.emit), cadd(sh.reflect, sh.transmit));
    if (albedo) *albedo = cmake(a.r < 1 ? a.r : 1, a.g < 1 ? a.g : 1, a.b < 1 ? a.b : 1);
    if (!czero(sh.transmit)) {
        R3 n = shading_normal(q, x, sh, ds, dt, h.prim_enter == h.root_enter, ray.d);
        if (!refract_dir(ray.d, n, hit_eta(s, h, x, ray.d, sh), &rd)) rd = r3(0, 0, 0);
    }
    o->refracted = vmake((double)rd.x, (double)rd.y, (double)rd.z);
}

// Where pixel (i, j) of the image is kept in the caller's buffers, in pixels.
size_t out_index(const Job *job, int i, int j) {
    return (size_t)(j - job->r.y) * job->out.stride + (size_t)(i - job->r.x);
}

void put_pixel(const Job *job, int i, int j, pray_rgb c) {
    float *px = job->out.rgb + out_index(job, i, j) * 3;
    px[0] = (float)c.r;
    px[1] = (float)c.g;
    px[2] = (float)c.b;
}

// Pixels i0 .. i1-1 of row j as the frame before had them (image sequences; the whole image).
void put_kept(const Job *job, int i0, int i1, int j) {
    memcpy(job->out.rgb + out_index(job, i0, j) * 3, job->prev + ((size_t)j * job->s->width + i0) * 3,
           sizeof(float) * 3 * (size_t)(i1 - i0));
}

// pray_intersect's first hit on ray (its direction made unit again as pray_intersect does) into
// *h, and its albedo; the background's: primitive and id -1, t infinite, normal and albedo 0.
void first_hit(Worker &k, Ray ray, pray_hit *h, pray_rgb *albedo) {
    ray.d = unit(ray.d);
    FirstHit fh;
    fh.found = false;
    find_hits(k.job->s, &k.w, ray, REAL_INF, -1, fh);
    h->primitive = h->id = -1;
    h->t = HUGE_VAL;
    h->normal = vmake(0, 0, 0);
    *albedo = cmake(0, 0, 0);
    if (fh.found) public_hit(k.job->s, ray, fh.h, h, albedo);
}

bool extra_outputs(const pray_buffers &b) { return b.primitive || b.depth || b.normal || b.id || b.albedo; }

void put_float3(float *buf, size_t at, double x, double y, double z) {
    if (buf) buf[at * 3] = (float)x, buf[at * 3 + 1] = (float)y, buf[at * 3 + 2] = (float)z;
}

// The per-pixel outputs of pixel (i, j): the first hit on the ray through its centre
// (pray_camera_ray's); with PRAY_BUFFERS_SAMPLES, normal and albedo are the means over its samples.
void put_first_hit(Worker &k, int i, int j) {
    const Job *job = k.job;
    pray_hit h, e;
    pray_rgb al, ea;
    first_hit(k, image_ray(job->s, i + 0.5, j + 0.5), &h, &al);
    int A = job->out.flags & PRAY_BUFFERS_SAMPLES ? job->s->antialias : 1;
    if (A > 1 && (job->out.normal || job->out.albedo)) {
        h.normal = vmake(0, 0, 0);
        al = cmake(0, 0, 0);
        for (int b = 0; b < A; b++)
            for (int a = 0; a < A; a++) {
                first_hit(k, sample_ray(job->s, i, j, a, b), &e, &ea);
                h.normal = vadd(h.normal, e.normal);
                al = cadd(al, ea);
            }
        h.normal = vmul(h.normal, 1.0 / ((double)A * A));
        al = cscale(al, 1.0 / ((double)A * A));
    }
    size_t at = out_index(job, i, j);
    if (job->out.primitive) job->out.primitive[at] = h.primitive;
    if (job->out.id) job->out.id[at] = h.id;
    if (job->out.depth) job->out.depth[at] = (float)h.t;
    put_float3(job->out.normal, at, h.normal.x, h.normal.y, h.normal.z);
    put_float3(job->out.albedo, at, al.r, al.g, al.b);
}

void set_row_background(Worker &k, int j) {
    const Scene *s = k.job->s;
    double f = s->height > 1 ? (double)j / (s->height - 1) : 0.0;
    k.tr.bg = cadd(s->bg_top, cscale(cadd(s->bg_bottom, cscale(s->bg_top, -1)), f));
}

// Undersampling: the tile whose top left sample is (X0, Y0); sample (x, y) is sample
// (x mod A, y mod A) of pixel (x / A, y / A).
struct Tile {
    int X0, Y0;
};

// Where the tile keeps its sample (x, y) (a row of samples runs on from there).
Sample *tile_at(Worker &k, const Tile &t, int x, int y) {
    return &k.cache[(y - t.Y0) * (k.job->tile + 1) + (x - t.X0)];
}

// The sample (x, y) of the tile, traced when it is not known yet.
Sample &tile_sample(Worker &k, const Tile &t, int x, int y) {
    const Scene *s = k.job->s;
    int A = s->antialias;
    Sample &v = *tile_at(k, t, x, y);
    if (v.known != 1) {
        set_row_background(k, y / A);
        v.c = trace(k.tr, sample_ray(s, x / A, y / A, x % A, y % A), 1, -1, RAY_PRIMARY, &v.seen);
        v.known = 1;
    }
    return v;
}

// A cell whose corners see one textured primitive, on the same side, whose model is lit only,
// lit alike at all four (the same lights in front, and what reaches the corners from each
// differs by no more than the threshold): each sample in between is shaded at its own point of
// the primitive, with its own texture, bumps and highlights, and the light the corners receive,
// interpolated. No ray goes past the primitive: where only the texture changes, the cell costs
// a ray-primitive test per sample instead of a ray and its shadow rays.
bool shade_cell(Worker &k, const Tile &t, int x0, int y0, int x1, int y1, const Sample *const *c) {
    double th = k.job->adaptive;
    const Seen &c0 = c[0]->seen;
    for (int i = 0; i < 4; i++) {
        const Seen &a = c[i]->seen;
        if (!a.lit_only || a.hit != c0.hit || a.enter != c0.enter || a.outward != c0.outward || a.lights != c0.lights)
            return false;
        for (int l = 0; l < SEEN_LIGHTS; l++)
            for (int j = 0; j < i && (a.lights >> l & 1); j++)
                if (!rgb_near(a.light[l], c[j]->seen.light[l], th)) return false;
    }
    const Scene *s = k.job->s;
    const Prim &q = s->prims[c0.hit];
    int A = s->antialias;
    double sx = 1.0 / (x1 - x0 > 0 ? x1 - x0 : 1), sy = 1.0 / (y1 - y0 > 0 ? y1 - y0 : 1);
    for (int y = y0; y <= y1; y++)
        for (int x = x0; x <= x1; x++) {
            Sample &v = *tile_at(k, t, x, y);
            if (v.known) continue;
            Ray r = sample_ray(s, x / A, y / A, x % A, y % A);
            real t0, t1;
            k.w.k.tests += 1;
            int kind = prim_span(q, r, false, &t0, &t1);
            real at = c0.enter ? t0 : t1;
            if (kind != SPAN || !(at > 0) || !(at < REAL_INF)) {  // not where the corners are: trace it
                tile_sample(k, t, x, y);
                continue;
            }
            R3 p = r.o + r.d * at, ds, dt;
            double ts, tt;
            Shade sh;
            shade_at(q, p, &sh, &ts, &tt, &ds, &dt, q, r.d, c0.enter != 0);
            R3 n = shading_normal(q, p, sh, ds, dt, c0.outward != 0, r.d);
            double fx = (x - x0) * sx, fy = (y - y0) * sy;
            double w[4] = {(1 - fx) * (1 - fy), fx * (1 - fy), (1 - fx) * fy, fx * fy};
            pray_rgb col = cadd(sh.emit, sh.ambient);
            bool lit = !czero(sh.diffuse) || !czero(sh.specular), traced = false;
            for (int i = 0; lit && i < s->lights.n; i++) {
                R3 l;
                real dist;
                if (!toward_light(s->lights[i], p, &l, &dist)) continue;
                real ndl = dot(n, l);
                if (ndl <= 0) continue;
                if (!(c0.lights >> i & 1)) {  // a light the corners do not see: trace the sample
                    tile_sample(k, t, x, y);
                    traced = true;
                    break;
                }
                pray_rgb li = cmake(0, 0, 0);
                for (int j = 0; j < 4; j++) li = cadd(li, cscale(c[j]->seen.light[i], w[j]));
                if (!czero(li)) phong_light(&col, &sh, li, n, l, ndl, r.d);
            }
            if (traced) continue;
            v.c = col;
            v.seen.hit = c0.hit;
            v.known = 2;
        }
    return true;
}

// Fill the cell with corner samples (x0, y0) .. (x1, y1): interpolate when its corners agree,
// shade it when they differ only in their texture, else split it.
void refine(Worker &k, const Tile &t, int x0, int y0, int x1, int y1) {
    const Sample &c00 = tile_sample(k, t, x0, y0), &c10 = tile_sample(k, t, x1, y0);
    const Sample &c01 = tile_sample(k, t, x0, y1), &c11 = tile_sample(k, t, x1, y1);
    double th = k.job->adaptive;
    if (x1 - x0 <= 1 && y1 - y0 <= 1) return;
    const Sample *corner[4] = {&c00, &c10, &c01, &c11};
    bool smooth = !differ(c00, c10, th) && !differ(c00, c01, th) && !differ(c00, c11, th) && !differ(c10, c01, th) &&
                  !differ(c10, c11, th) && !differ(c01, c11, th) && !texture_between(k.job->s, corner, 4, th);
    if (!smooth && shade_cell(k, t, x0, y0, x1, y1, corner)) return;
    if (smooth) {
        bool flat = same_rgb(c00.c, c10.c) && same_rgb(c00.c, c01.c) && same_rgb(c00.c, c11.c);
        double sx = x1 > x0 ? 1.0 / (x1 - x0) : 0, sy = y1 > y0 ? 1.0 / (y1 - y0) : 0;
        for (int y = y0; y <= y1; y++) {
            double fy = (y - y0) * sy;
            pray_rgb l = cadd(cscale(c00.c, 1 - fy), cscale(c01.c, fy));  // down the cell's sides
            pray_rgb r = cadd(cscale(c10.c, 1 - fy), cscale(c11.c, fy));
            Sample *row = tile_at(k, t, x0, y);
            for (int x = x0; x <= x1; x++) {
                Sample &v = row[x - x0];
                if (v.known) continue;
                double fx = (x - x0) * sx;
                v.c = flat ? c00.c : cadd(cscale(l, 1 - fx), cscale(r, fx));  // equal corners: exact
                v.seen.hit = c00.seen.hit;  // (a sample interpolated is traced before it is a corner)
                v.known = 2;
            }
        }
        return;
    }
    int xm = (x0 + x1) / 2, ym = (y0 + y1) / 2;
    if (x1 - x0 <= 1) {
        refine(k, t, x0, y0, x1, ym);
        refine(k, t, x0, ym, x1, y1);
    } else if (y1 - y0 <= 1) {
        refine(k, t, x0, y0, xm, y1);
        refine(k, t, xm, y0, x1, y1);
    } else {
        refine(k, t, x0, y0, xm, ym);
        refine(k, t, xm, y0, x1, ym);
        refine(k, t, x0, ym, xm, y1);
        refine(k, t, xm, ym, x1, y1);
    }
}

// Undersampling: a band of tiles, left to right. Its pixels are averages of their samples, in
// the order of pixel(): where every sample is traced, the same colour as full sampling.
// Only the band's pixels in the rectangle wanted are written, and only the tiles that hold them
// are sampled, after the tile before them: a tile's samples depend on nothing before it but the
// column it is handed, and that column's values come from its own tile's samples only (its
// cells are decided by their traced corners, and the first cell to reach a sample sets it).
// So the rectangle's samples are those of the whole image.
void adaptive_band(Worker &k, int y0, int y1) {
    const Job *job = k.job;
    const Scene *s = job->s;
    int A = s->antialias, T = job->tile, S = job->step, n = T + 1;
    int SW = s->width * A, SH = s->height * A;
    int ry0 = y0 > job->r.y ? y0 : job->r.y, ry1 = y1 < job->r.y + job->r.height ? y1 : job->r.y + job->r.height;
    int rx0 = job->r.x, rx1 = job->r.x + job->r.width;
    int first = job->r.x * A / T;  // the tile that holds the rectangle's first column
    Tile t;
    t.Y0 = y0 * A;
    int Y1 = t.Y0 + T < SH - 1 ? t.Y0 + T : SH - 1;  // the band's last row of samples
    for (int q = 0; q < n * n; q++) k.cache[q].known = 0;
    for (t.X0 = (first > 0 ? first - 1 : 0) * T;; t.X0 += T) {
        int X1 = t.X0 + T < SW - 1 ? t.X0 + T : SW - 1;
        for (int cy = t.Y0;; cy += S) {
            int yl = cy + S < Y1 ? cy + S : Y1;
            for (int cx = t.X0;; cx += S) {
                int xl = cx + S < X1 ? cx + S : X1;
                refine(k, t, cx, cy, xl, yl);
                if (xl == X1) break;
            }
            if (yl == Y1) break;
        }
        int i0 = t.X0 / A, i1 = X1 == SW - 1 ? s->width : (t.X0 + T) / A;
        i0 = i0 > rx0 ? i0 : rx0;
        i1 = i1 < rx1 ? i1 : rx1;
        for (int j = ry0; j < ry1; j++)
            for (int i = i0; i < i1; i++) {
                pray_rgb sum = cmake(0, 0, 0);
                for (int y = j * A; y < j * A + A; y++) {
                    const Sample *row = tile_at(k, t, i * A, y);
                    for (int a = 0; a < A; a++) sum = cadd(sum, row[a].c);
                }
                put_pixel(job, i, j, cscale(sum, 1.0 / ((double)A * A)));
            }
        if (X1 == SW - 1 || i1 == rx1 || over_time(job->c)) break;  // (pray_cancel, maxtime: checked per tile)
        for (int y = 0; y < n; y++)  // the last column is the next tile's first
            for (int x = 0; x < n; x++) {
                Sample &v = k.cache[y * n + x];
                if (x == 0) v = k.cache[y * n + T];
                else v.known = 0;
            }
    }
}

// The rows of band `band` (of the whole image) that lie in the rectangle wanted: [*y0, *y1).
void band_rows_in(const Job *job, int band, int *y0, int *y1) {
    int a = band * job->band_rows, b = a + job->band_rows;
    *y0 = a > job->r.y ? a : job->r.y;
    *y1 = b < job->r.y + job->r.height ? b : job->r.y + job->r.height;
}

void render_band(Worker &k, int band) {
    Job *job = k.job;
    const Scene *s = job->s;
    int x0 = job->r.x, x1 = job->r.x + job->r.width, y0, y1;
    band_rows_in(job, band, &y0, &y1);
    shadow_cache_clear(s, k.tr.w);
    if (extra_outputs(job->out))
        for (int j = y0; j < y1; j++)
            for (int i = x0; i < x1; i++) put_first_hit(k, i, j);
    if (!job->out.rgb) return;
    if (job->adaptive > 0) {  // (the whole band: its tiles are sampled from the top)
        int b0 = band * job->band_rows, b1 = b0 + job->band_rows;
        double px = (double)(y1 - y0) * (x1 - x0);
        if (unit_kept(k, (size_t)band)) {  // (a band depends on nothing outside it)
            for (int j = y0; j < y1; j++) put_kept(job, x0, x1, j);
            k.kept += px;
            return;
        }
        k.traced += px;
        adaptive_band(k, b0, b1 < s->height ? b1 : s->height);
        unit_done(k);
        return;
    }
    Ray rays[RAY_BATCH];
    for (int j = y0; j < y1 && !over_time(job->c); j++) {
        set_row_background(k, j);
        size_t u = (size_t)j * s->width;  // (image sequences: the whole image is rendered)
        if (s->antialias > 1) {  // pixel() makes each row of samples ahead
            for (int i = x0; i < x1 && !over_time(job->c); i++)
                if (unit_kept(k, u + i)) put_kept(job, i, i + 1, j), k.kept++;
                else put_pixel(job, i, j, pixel(k, i, j)), k.traced++, unit_done(k);
            continue;
        }
        for (int i0 = x0; i0 < x1 && !over_time(job->c); i0 += RAY_BATCH) {
            int n = x1 - i0 < RAY_BATCH ? x1 - i0 : RAY_BATCH;
            for (int q = 0; q < n; q++) rays[q] = sample_ray(s, i0 + q, j, 0, 0);
            for (int q = 0; q < n; q++)
                if (unit_kept(k, u + i0 + q)) put_kept(job, i0 + q, i0 + q + 1, j), k.kept++;
                else put_pixel(job, i0 + q, j, trace(k.tr, rays[q], 1, -1, RAY_PRIMARY)), k.traced++, unit_done(k);
        }
    }
}

void worker_main(void *arg) {
    Worker &k = *(Worker *)arg;
    Job *job = k.job;
    for (;;) {
        job->mu.lock();
        int band = job->cancelled ? job->bands : job->next_band++;
        job->mu.unlock();
        if (band >= job->bands) return;
        render_band(k, job->band0 + band);
        job->mu.lock();
        if (k.tr.over) job->cancelled = job->over = 1;
        if (over_time(job->c)) job->cancelled = 1;
        int y0, y1;
        band_rows_in(job, job->band0 + band, &y0, &y1);
        job->rows_done += y1 - y0;
        pray_ctx *c = job->c;
        if (!job->cancelled && c->progress_fn && c->progress_fn(c->progress_ud, job->rows_done, job->r.height))
            job->cancelled = 1;
        job->mu.unlock();
    }
}

Worker &worker_at(char *buf, size_t stride, int i) { return *(Worker *)(buf + LINE_SLACK + (size_t)i * stride); }

// Image sequences (10b) weigh what tracing and recording a unit take by the operations counted
// while it is traced (Counters), each at the instructions it takes on average (x86-64, -O3,
// measured with callgrind over the example scenes; within a fifth on each): a ray (with its
// pixel and shading), an intersection test, a voxel step, an action of a list; a ray noted in
// a record (with its walk's setting out), a cell of the grid it crosses, a word of a record
// emptied; taking a unit over, and testing one word of its record for change.
const double COH_RAY_WORK = 530, COH_TEST_WORK = 100, COH_STEP_WORK = 100, COH_ACTION_WORK = 25;
const double COH_NOTE_WORK = 200, COH_CELL_WORK = 10;

double trace_work(const Counters &k) {
    double rays = k.rays[0] + k.rays[1] + k.rays[2] + k.rays[3];
    return COH_RAY_WORK * rays + COH_TEST_WORK * k.tests + COH_STEP_WORK * k.steps +
           COH_ACTION_WORK * (k.set_in + k.set_out + k.checks);
}
double record_work(const Counters &k) { return COH_NOTE_WORK * k.notes + COH_CELL_WORK * k.cells; }

// What a frame of an image sequence takes over from the frame before (10b): per unit of the image
// (a pixel; with undersampling a band of rows) whether it is traced again (redo NULL: all
// are), its record (rec NULL: none is kept) over the regions rg, and the frame before's pixels.
// The render driver adds what the frame's tracing and recording took (coh_keep).
struct CohPlan {
    unsigned char *redo;
    unsigned *rec;
    const Regions *rg;
    const float *prev;
    int sample;  // only a sample of the units is recorded (coh_sampled)
    int record;  // what is recorded: COH_NONE, COH_ALL, COH_SAMPLE (10b)
    size_t units;
    double traced, work;     // units traced, and their work (trace_work)
    double recorded, rwork;  // units recorded, and the work of recording them (record_work)
};

// The rows of a band of the render driver: a band of tiles with undersampling.
int band_rows_of(const Scene *s, bool rgb) {
    int step = s->antialias * (s->antialias > 1 ? ADAPT_PIXELS_AA : ADAPT_PIXELS);
    int tile = step * (ADAPT_TILE > step ? ADAPT_TILE / step : 1);
    return rgb && s->adaptive > 0 ? tile / s->antialias : 4;
}

// Render the rectangle r of the image into the buffers (stride set); `plan`: what an image
// sequence's frame takes over from the one before (NULL: nothing).
pray_status render_scene(pray_ctx *c, const Scene *s, const pray_rect &r, const pray_buffers &out,
                         CohPlan *plan) {
    int nt = opt_int(c, OPT_THREADS);
    if (nt <= 0) nt = cpu_count();
    if (!PRAY_HAS_THREADS || nt < 1) nt = 1;
    if (nt > 64) nt = 64;
    Job job;
    memset(&job, 0, sizeof job);
    job.c = c;
    job.s = s;
    job.r = r;
    job.out = out;
    job.adaptive = out.rgb ? s->adaptive : 0;
    job.step = s->antialias * (s->antialias > 1 ? ADAPT_PIXELS_AA : ADAPT_PIXELS);
    job.tile = job.step * (ADAPT_TILE > job.step ? ADAPT_TILE / job.step : 1);
    job.band_rows = band_rows_of(s, out.rgb != NULL);
    if (plan) {
        job.redo = plan->redo;
        job.rec = plan->rec;
        job.rg = plan->rg;
        job.prev = plan->prev;
        job.sample = plan->sample;
        job.units = plan->units;
    }
    for (int i = 0; job.adaptive > 0 && i < s->prims.n; i++)  // undersampling looks into textures
        if (!model_pyramids(c, (pray_model *)s->prims[i].mat)) return c->status;  // (marks the parts done)
    job.band0 = r.y / job.band_rows;
    job.bands = (r.y + r.height - 1) / job.band_rows - job.band0 + 1;
    if (nt > job.bands) nt = job.bands;
    // everything a thread needs is allocated here, before any starts: the context's allocator
    // is used by one thread only
    // one Worker per thread, each on cache lines of its own (its counters change with every ray)
    const size_t stride = (sizeof(Worker) + LINE_SLACK - 1) / LINE_SLACK * LINE_SLACK + LINE_SLACK;
    char *wbuf = (char *)mem_zalloc(c, stride * (size_t)nt + LINE_SLACK);
    void **args = (void **)mem_zalloc(c, sizeof(void *) * (size_t)nt);
    void *starts = mem_zalloc(c, 64 * sizeof(void *) * 2);
    pray_status st = wbuf && args && starts ? PRAY_OK : c->status;
    if (st == PRAY_OK) {  // where the eye is (a frame warns when it is inside the solid)
        Scratch w;
        Ray eye;
        eye.o = s->eye;
        eye.d = s->dir;
        if (scratch_init(c, &w, s)) c->eye_inside = starts_inside(s, &w, eye);
        else st = c->status;
        scratch_release(c, &w);
    }
    int made = 0, seen = 0;  // (Tracer::seen of all threads)
    for (; st == PRAY_OK && made < nt; made++) {
        Worker &k = worker_at(wbuf, stride, made);
        k.job = &job;
        k.cache.init();
        if (!scratch_init(c, &k.w, s)) st = c->status;
        else if (job.adaptive > 0 && !k.cache.reserve(c, (job.tile + 1) * (job.tile + 1))) st = c->status;
        k.tr.s = s;
        k.tr.w = &k.w;
        k.w.rg = job.rg;
        args[made] = &k;
    }
    if (st == PRAY_OK) {
        job.mu.init();
        run_parallel(nt, worker_main, args, starts);
        job.mu.destroy();
        if (job.over)
            st = fail(c, PRAY_ERR_LIMIT, "a sample of the image needs more than %ld ray%s (option maxrays)", s->maxrays,
                      s->maxrays == 1 ? "" : "s");
        else if (job.cancelled)
            st = cancelled(c) ? fail_cancelled(c) : fail(c, PRAY_ERR_CANCELLED, "cancelled by the progress callback");
    }
    for (int i = 0; wbuf && i < made; i++) {
        const Counters &k = worker_at(wbuf, stride, i).w.k;
        c->stats.rays_primary += k.rays[RAY_PRIMARY];
        c->stats.rays_shadow += k.rays[RAY_SHADOW];
        c->stats.rays_reflected += k.rays[RAY_REFLECT];
        c->stats.rays_refracted += k.rays[RAY_REFRACT];
        c->stats.intersection_tests += k.tests;
        c->stats.voxel_steps += k.steps;
        c->stats.area_moves += k.moves;
        c->stats.set_inside += k.set_in;
        c->stats.set_outside += k.set_out;
        c->stats.checks += k.checks;
        c->stats.frozen_skips += k.frozen;
        c->stats.rays_lightbuf += k.lbuf;
        c->stats.rays_eyebuf += k.ebuf;
        c->stats.rays_shadowcache += k.cache;
        seen |= worker_at(wbuf, stride, i).tr.seen;
        if (job.redo) {
            c->stats.pixels_reused += worker_at(wbuf, stride, i).kept;
            c->stats.pixels_retraced += worker_at(wbuf, stride, i).traced;
        }
        if (plan) {  // (what tracing and recording took, for the next frame's plan)
            plan->work += trace_work(k);
            plan->rwork += record_work(k);
            plan->recorded += worker_at(wbuf, stride, i).recorded;
            plan->traced += worker_at(wbuf, stride, i).units;
        }
        scratch_release(c, &worker_at(wbuf, stride, i).w);
        worker_at(wbuf, stride, i).cache.release(c);
    }
    if (out.rgb) c->stats.rays_primary_full += (double)r.width * r.height * s->antialias * s->antialias;
    if (job.redo && st == PRAY_OK) c->stats.frames_coherent += 1;
    // no light reaches anything the eye sees (a frame that takes pixels over from the frame
    // before, which had the same lights and camera, keeps that frame's answer for them)
    if (st == PRAY_OK)
        c->no_light = c->dark = s->lights.n > 0 && !(seen & 2) && ((seen & 1) || job.redo) && (!job.redo || c->dark);
    c->stats.threads = nt;
    mem_free(c, wbuf);
    mem_free(c, args);
    mem_free(c, starts);
    return st;
}

// =============================================================================================
// [SECTION] 10b Image sequences (thesis 3.7): what changed between frames, what to trace again
// =============================================================================================
// A program's frame with the camera, lights, image and options of the frame before takes over
// every pixel whose rays cannot have met anything that changed. While a pixel is traced, the
// ray driver (9b.8) notes in the pixel's record the regions of space its rays crossed
// (region_note, below): cells of a grid over the scene's finite parts, and bit 0 for all space
// outside the grid's box. The next frame compares its prepared scene with the frame before's,
// by value (coh_diff), and marks the cells that the boxes of what changed reach, in both
// scenes (coh_mark). A pixel whose record meets no marked cell has the same rays and the
// same colour; the others are traced again. With undersampling the unit is the band of rows
// the render driver samples alone. The records of a frame are at most COH_BYTES; a frame that
// cannot have them is traced in full (docs/acceleration.md, "Image sequences").
#ifndef PRAY_NO_SEQUENCES  // (a build without them: option coherence changes nothing)
const double COH_WORD_WORK = 2, COH_KEEP_WORK = 30, COH_HIT_WORK = 4;  // (with COH_RAY_WORK ..., section 10)
// Recording pays only when the next frame saves this many times what it costs (coh_plan): the
// weights are good to a fifth, and the share of units to trace again is the frame before's.
const double COH_MARGIN = 1.5;
inline size_t coh_slots(size_t units, int width, bool bands) {
    return bands ? (units + 3) / 4 : (units / (size_t)width + 7) / 8 * (((size_t)width + 7) / 8);
}
inline bool same_real(real a, real b) { return same_bytes(&a, &b, sizeof a); }
inline bool same_r3(R3 a, R3 b) { return same_real(a.x, b.x) && same_real(a.y, b.y) && same_real(a.z, b.z); }
const double COH_BYTES = 64.0 * 1048576;  // the records of a frame at most
const int COH_CELLS = 12;                 // cells along an axis at most (4 at least)

struct Coherence {
    int valid;        // `prev`, `opt` and `hull` are the last frame's
    Scene prev;       // its prepared scene, without the acceleration structure
    Options opt;      // its options
    Box hull;         // the box of its finite parts
    int recorded;     // `rec` and `img` are the last frame's too: COH_ALL or COH_SAMPLE
    double t, r;      // the work of tracing a unit, of recording one (coh_keep; trace_work)
    Regions rg;       // the cells its records are made of
    unsigned *rec;    // units x rg.words (coh_word)
    size_t units;     // pixels, or with undersampling bands
    size_t recbytes;  // bytes at rec: of all units' records, or of the sample's (coh_slot)
    float *img;       // its pixels, RGB
    size_t imgsize;   // floats at img
};

void coh_release(pray_ctx *c) {
    Coherence *h = c->coh;
    if (!h) return;
    if (h->valid) scene_release(c, &h->prev);
    mem_free(c, h->rec);
    mem_free(c, h->img);
    mem_free(c, h);
    c->coh = NULL;
}

// ---- noting the regions a ray crosses (the ray driver calls region_note) ----
// The part [*ta, *tb] of the ray inside the grid's box; false when none. (inv: 1 / d)
bool region_clip(const RegionGrid &g, const double *o, const double *d, const double *inv, double *ta, double *tb) {
    for (int a = 0; a < 3; a++) {
        if (d[a] == 0) {
            if (o[a] < g.lo[a] || o[a] > g.hi[a]) return false;
            continue;
        }
        double t0 = (g.lo[a] - o[a]) * inv[a], t1 = (g.hi[a] - o[a]) * inv[a];
        if (t0 > t1) {
            double x = t0;
            t0 = t1;
            t1 = x;
        }
        if (t0 > *ta) *ta = t0;
        if (t1 < *tb) *tb = t1;
    }
    return *ta <= *tb;
}

// The cell along an axis of grid coordinate x (in cells from the grid's low side), clamped.
inline int region_cell(double x, int n) { return !(x >= 0) ? 0 : x >= n ? n - 1 : (int)x; }

// Set the bits of the grid's cells that the part [ta, tb] (inside its box) of the ray crosses,
// cell by cell (Amanatides and Woo's walk) from the cell at ta to the cell at tb. The steps
// along each axis are counted out beforehand, so that a step needs no test of the grid's
// bounds or of tb, and rounding can never take the walk out of the grid. Returns the number of
// cells set.
int region_walk(const RegionGrid &g, const double *o, const double *d, const double *inv, double ta, double tb,
                unsigned *bits) {
    int n = g.n, id = g.base, steps = 0, left[3], move[3];
    double next[3], delta[3];
    for (int a = 0, stride = 1; a < 3; a++, stride *= n) {
        double O = (o[a] - g.lo[a]) * g.inv[a], D = d[a] * g.inv[a], dt = g.h[a] * inv[a];  // (dt: 1 / D)
        int c0 = region_cell(O + D * ta, n), c1 = region_cell(O + D * tb, n);
        id += c0 * stride;
        if (D > 0) left[a] = c1 - c0, move[a] = stride, next[a] = (c0 + 1 - O) * dt, delta[a] = dt;
        else left[a] = c0 - c1, move[a] = -stride, next[a] = (c0 - O) * dt, delta[a] = -dt;
        if (!(left[a] > 0)) left[a] = 0, next[a] = HUGE_VAL;  // (also an axis the ray is parallel to)
        steps += left[a];
    }
    int cells = steps + 1;
    for (;;) {
        bits[(id >> 5) * COH_BLOCK] |= 1u << (id & 31);
        if (!steps--) break;
        int a = next[0] < next[1] ? (next[0] < next[2] ? 0 : 2) : (next[1] < next[2] ? 1 : 2);
        id += move[a];
        next[a] = --left[a] ? next[a] + delta[a] : HUGE_VAL;
    }
    return cells;
}

// Set in the record of the pixel being traced the regions that the part (0, end] of the ray
// crosses: the grid's cells where it is in the grid's box, and bit 0 where it is outside. A
// walk rounded past a corner of cells misses a sliver of a cell there; the boxes of what
// changed are widened by more than that (coh_mark).
void region_note(Scratch *w, const Ray &ray, real end) {
    const RegionGrid &g = w->rg->g;
    unsigned *bits = w->rbits;
    double o[3] = {(double)ray.o.x, (double)ray.o.y, (double)ray.o.z};
    double d[3] = {(double)ray.d.x, (double)ray.d.y, (double)ray.d.z};
    double inv[3];
    for (int a = 0; a < 3; a++) inv[a] = d[a] != 0 ? 1 / d[a] : 0;
    double ta = 0, tb = (double)end;
    w->k.notes += 1;
    bool in = region_clip(g, o, d, inv, &ta, &tb);
    if (!in || ta > 0 || tb < (double)end) bits[0] |= 1u;
    if (in) w->k.cells += region_walk(g, o, d, inv, ta, tb, bits);
}

// ---- comparing two prepared scenes by value ----
// A primitive's surface, its texture coordinates and its model (not its number, nor its twins).
bool prim_same(const Prim &a, const Prim &b) {
    if (a.kind != b.kind || a.axis != b.axis || a.map != b.map || !a.tm != !b.tm) return false;
    if (!same_r3(a.p, b.p) || !same_r3(a.n, b.n) || !same_real(a.r, b.r) || !same_real(a.r2, b.r2) ||
        !same_real(a.d, b.d) || !same_bytes(&a.box, &b.box, sizeof a.box))
        return false;
    if (a.tm && (!same_r3(a.tm->u, b.tm->u) || !same_r3(a.tm->v, b.tm->v) || a.tm->mirrored != b.tm->mirrored ||
                 !same_bytes(&a.tm->pt, &b.tm->pt, sizeof(R3) * 4)))
        return false;
    if (!a.fr != !b.fr) return false;
    if (a.fr) {  // (a solid turned within its own box: the same box, another frame)
        const PrimFrame &f = *a.fr, &g = *b.fr;
        for (int k = 0; k < 3; k++)
            if (!same_r3(f.inv[k], g.inv[k]) || !same_r3(f.fwd[k], g.fwd[k])) return false;
        if (!same_r3(f.t, g.t) || !same_r3(f.lo, g.lo) || !same_r3(f.hi, g.hi) || !same_real(f.h, g.h) ||
            !same_real(f.k, g.k) || !same_real(f.rt, g.rt) || f.plain != g.plain)
            return false;
    }
    return model_same(a.mat, b.mat);
}

inline unsigned fnv(unsigned h, const void *p, size_t n) {
    const unsigned char *b = (const unsigned char *)p;
    for (size_t i = 0; i < n; i++) h = (h ^ b[i]) * 16777619u;
    return h;
}

// Per element of a prepared scene (numbered in post-order, so a subtree's primitives and nodes
// are runs of numbers): a hash of its value, and per node its subtree's first primitive and its
// numbers of primitives and nodes.
struct SceneIx {
    unsigned *ph, *nh;
    int *p0, *pc, *nc;
};

bool scene_ix(pray_ctx *c, const Scene *s, SceneIx *x) {
    size_t np = (size_t)s->prims.n + 1, nn = (size_t)s->nodes.n + 1;
    x->ph = (unsigned *)mem_alloc(c, sizeof(unsigned) * np);
    x->nh = x->ph ? (unsigned *)mem_alloc(c, sizeof(unsigned) * nn) : NULL;
    x->p0 = x->nh ? (int *)mem_alloc(c, sizeof(int) * 3 * nn) : NULL;
    if (!x->p0) return false;
    x->pc = x->p0 + nn;
    x->nc = x->pc + nn;
    for (int i = 0; i < s->prims.n; i++) {
        const Prim &q = s->prims[i];
        unsigned h = fnv(2166136261u, &q.kind, sizeof q.kind);
        real v[8] = {q.p.x, q.p.y, q.p.z, q.n.x, q.n.y, q.n.z, q.r, q.d};
        h = fnv(h, v, sizeof v);
        if (q.mat->kind == M_FLAT) h = fnv(h, &q.mat->diffuse, sizeof(pray_rgb) * 6);
        x->ph[i] = h;
    }
    for (int j = 0; j < s->nodes.n; j++) {  // (children before their parents)
        const Node &nd = s->nodes[j];
        unsigned h = fnv(2166136261u, &nd.op, sizeof nd.op);
        int pc = 0, nc = 1;
        for (int k = 0; k < nd.n; k++) {
            int e = s->kids[nd.k0 + k], i = e_index(e);
            unsigned kh = e_is_node(e) ? x->nh[i] + 1 : x->ph[i];
            h = fnv(h, &kh, sizeof kh);
            if (k == 0) x->p0[j] = e_is_node(e) ? x->p0[i] : i;
            pc += e_is_node(e) ? x->pc[i] : 1;
            nc += e_is_node(e) ? x->nc[i] : 0;
        }
        x->nh[j] = h;
        x->pc[j] = pc;
        x->nc[j] = nc;
    }
    return true;
}

void scene_ix_free(pray_ctx *c, SceneIx *x) {
    mem_free(c, x->ph);
    mem_free(c, x->nh);
    mem_free(c, x->p0);
}

struct CohDiff {
    const Scene *s[2];  // the frame before, this frame
    SceneIx x[2];
    Array<int> pairs;   // twins' numbers (surf) of the primitives found alike: before, now
};

inline unsigned elem_hash(const CohDiff &d, int w, int e) { return e_is_node(e) ? d.x[w].nh[e_index(e)] + 1 : d.x[w].ph[e_index(e)]; }

// Element a of the frame before and b of this frame are alike: the same tree of the same
// primitives, numbered alike. Their primitives' twins are noted (coh_twins).
bool elem_same(pray_ctx *c, CohDiff &d, int a, int b) {
    if (a < 0 || b < 0) return a == b;
    if (e_is_node(a) != e_is_node(b) || elem_hash(d, 0, a) != elem_hash(d, 1, b)) return false;
    const Scene *A = d.s[0], *B = d.s[1];
    int pa = e_index(a), pb = e_index(b), np = 1, na = 0, nb = 0, nn = 0;
    if (e_is_node(a)) {
        const SceneIx &x = d.x[0], &y = d.x[1];
        if (x.pc[pa] != y.pc[pb] || x.nc[pa] != y.nc[pb]) return false;
        np = x.pc[pa];
        nn = x.nc[pa];
        na = pa - nn + 1;
        nb = pb - nn + 1;
        pa = x.p0[pa];
        pb = y.p0[pb];
    }
    for (int k = 0; k < np; k++)
        if (!prim_same(A->prims[pa + k], B->prims[pb + k])) return false;
    for (int k = 0; k < nn; k++) {
        const Node &u = A->nodes[na + k], &v = B->nodes[nb + k];
        if (u.op != v.op || u.n != v.n) return false;
        for (int i = 0; i < u.n; i++) {
            int ea = A->kids[u.k0 + i], eb = B->kids[v.k0 + i];
            if (e_is_node(ea) != e_is_node(eb)) return false;
            int ra = e_index(ea) - (e_is_node(ea) ? na : pa), rb = e_index(eb) - (e_is_node(eb) ? nb : pb);
            if (ra != rb) return false;
        }
    }
    for (int k = 0; k < np; k++)
        if (!d.pairs.push(c, A->prims[pa + k].surf) || !d.pairs.push(c, B->prims[pb + k].surf)) return false;
    return true;
}

// The cells of grid g that box b (widened by eps) reaches, set in `dirty`; false when b
// reaches out of the grid's box.
bool grid_mark(const RegionGrid &g, unsigned *dirty, const Box &b, const double *eps) {
    int lo[3], hi[3];
    bool inside = true, none = false;
    for (int a = 0; a < 3; a++) {
        double l = (double)b.lo[a] - eps[a], u = (double)b.hi[a] + eps[a];
        if (l < g.lo[a] || u > g.hi[a]) inside = false;
        if (u < g.lo[a] || l > g.hi[a]) none = true;
        double fl = floor((l - g.lo[a]) / g.h[a]), fu = floor((u - g.lo[a]) / g.h[a]);
        lo[a] = fl < 0 ? 0 : fl >= g.n ? g.n - 1 : (int)fl;
        hi[a] = fu < 0 ? 0 : fu >= g.n ? g.n - 1 : (int)fu;
    }
    for (int z = lo[2]; z <= hi[2] && !none; z++)
        for (int y = lo[1]; y <= hi[1]; y++)
            for (int x = lo[0]; x <= hi[0]; x++) {
                int id = g.base + x + g.n * (y + g.n * z);
                dirty[id >> 5] |= 1u << (id & 31);
            }
    return inside;
}

// Mark the regions that box b within box `clip` reaches (an empty box is nothing): the grid's
// cells, and bit 0 when it reaches out of the grid's box. The box is widened by an eighth of a
// cell and by rounding.
void coh_mark(const Regions &R, unsigned *dirty, const Box &box, const Box &clip) {
    Box b = box;
    box_clip(&b, clip);
    if (box_empty(b)) return;
    double eps[3];
    for (int a = 0; a < 3; a++) eps[a] = R.g.h[a] / 8 + R.round[a];
    if (!grid_mark(R.g, dirty, b, eps)) dirty[0] |= 1u;
}

inline const Box *elem_box_or_all(const Scene *s, int e, Box *all) {
    if (e >= 0) return &elem_box(s, e);
    *all = box_all();
    return all;
}

// Mark in `dirty` (coh_mark) where the frame before and this frame may differ: a subtree that
// is not alike in both marks its boxes in both. The membership of a node in space follows from
// its children's, so a node of the same operation and number of children passes the question
// on to each pair of children, within the hull of the two nodes' boxes (outside it, the node is
// outside in both frames); a union (or a difference with the same first child) whose children
// were added or removed pairs those alike in order, and marks the others. Pairs are taken in
// order, so primitives alike keep their order (ties at one distance are taken in the order of
// primitive numbers). False when out of memory.
bool coh_diff(pray_ctx *c, CohDiff &d, const Regions &g, unsigned *dirty) {
    const Scene *A = d.s[0], *B = d.s[1];
    Array<int> st;
    Array<Box> clips;  // per pair on the stack: where its difference lies
    st.init();
    clips.init();
    bool ok = st.push(c, A->root) && st.push(c, B->root) && clips.push(c, box_all());
    const int LOOK = 256;  // children looked ahead for one alike
    while (ok && st.n) {
        int b = st[--st.n], a = st[--st.n];
        Box clip = clips[--clips.n];
        if (elem_same(c, d, a, b)) continue;
        if (c->status != PRAY_OK) break;
        if (a >= 0 && b >= 0 && e_is_node(a) && e_is_node(b)) {
            const Node &u = A->nodes[e_index(a)], &v = B->nodes[e_index(b)];
            if (u.op == v.op && u.n == v.n) {
                Box in = u.box;
                box_hull(&in, v.box);
                box_clip(&in, clip);
                for (int k = 0; k < u.n && ok; k++)
                    ok = st.push(c, A->kids[u.k0 + k]) && st.push(c, B->kids[v.k0 + k]) && clips.push(c, in);
                continue;
            }
            int k0 = u.op == O_DIFF ? 1 : 0;
            if (u.op == v.op && (u.op == O_UNION || (u.op == O_DIFF && elem_same(c, d, A->kids[u.k0], B->kids[v.k0])))) {
                int j = k0;
                for (int i = k0; i < u.n && ok; i++) {
                    int ea = A->kids[u.k0 + i], m = j, end = v.n < j + LOOK ? v.n : j + LOOK;
                    unsigned ha = elem_hash(d, 0, ea);
                    for (; m < end; m++)
                        if (elem_hash(d, 1, B->kids[v.k0 + m]) == ha && elem_same(c, d, ea, B->kids[v.k0 + m])) break;
                    if (m == end) {
                        coh_mark(g, dirty, elem_box(A, ea), clip);
                        continue;
                    }
                    for (; j < m; j++) coh_mark(g, dirty, elem_box(B, B->kids[v.k0 + j]), clip);
                    j = m + 1;
                }
                for (; j < v.n; j++) coh_mark(g, dirty, elem_box(B, B->kids[v.k0 + j]), clip);
                continue;
            }
        }
        Box all;
        coh_mark(g, dirty, *elem_box_or_all(A, a, &all), clip);
        coh_mark(g, dirty, *elem_box_or_all(B, b, &all), clip);
    }
    st.release(c);
    clips.release(c);
    return ok && c->status == PRAY_OK;
}

int pair_cmp(const void *pa, const void *pb) {
    const int *a = (const int *)pa, *b = (const int *)pb;
    return a[0] != b[0] ? (a[0] < b[0] ? -1 : 1) : a[1] != b[1] ? (a[1] < b[1] ? -1 : 1) : 0;
}

// Primitives alike are twins (one surface, 7) of each other in both frames or in neither:
// whether a shadow ray leaving one ignores another must not change.
bool coh_twins(CohDiff &d) {
    int n = d.pairs.n / 2;
    for (int pass = 0; n > 1 && pass < 2; pass++) {  // (no pairs: the array may have no storage)
        qsort(d.pairs.p, (size_t)n, 2 * sizeof(int), pair_cmp);
        for (int i = 1; i < n; i++)
            if (d.pairs[2 * i] == d.pairs[2 * i - 2] && d.pairs[2 * i + 1] != d.pairs[2 * i - 1]) return false;
        for (int i = 0; i < n; i++) {  // (the other way round)
            int t = d.pairs[2 * i];
            d.pairs[2 * i] = d.pairs[2 * i + 1];
            d.pairs[2 * i + 1] = t;
        }
    }
    return true;
}

// ---- the frame's plan ----
// The camera, lights, image and the bounds of every ray's worth (Scene::most) are the same.
bool coh_same_view(const Scene *a, const Scene *b) {
    if (a->parallel != b->parallel || a->width != b->width || a->height != b->height || a->depth != b->depth ||
        a->shadows != b->shadows || a->antialias != b->antialias || a->maxrays != b->maxrays ||
        a->lights.n != b->lights.n || (a->root < 0) != (b->root < 0))
        return false;
    const R3 *u[9] = {&a->eye, &a->point, &a->cx, &a->cy, &a->dir, &a->keye, &a->kpoint, &a->kcx, &a->kcy};
    const R3 *v[9] = {&b->eye, &b->point, &b->cx, &b->cy, &b->dir, &b->keye, &b->kpoint, &b->kcx, &b->kcy};
    for (int i = 0; i < 9; i++)
        if (!same_r3(*u[i], *v[i])) return false;
    for (int i = 0; i < a->lights.n; i++) {
        const Light &p = a->lights[i], &q = b->lights[i];
        if (p.point != q.point || !same_r3(p.v, q.v) || !same_rgb_bits(p.intensity, q.intensity) || p.spot != q.spot ||
            !same_r3(p.d, q.d) || !same_bytes(&p.a1, &q.a1, sizeof p.a1) || !same_bytes(&p.a2, &q.a2, sizeof p.a2))
            return false;
    }
    return same_rgb_bits(a->bg_top, b->bg_top) && same_rgb_bits(a->bg_bottom, b->bg_bottom) &&
           same_bytes(a->most, b->most, sizeof(double) * (size_t)(a->depth + 1)) && same_bytes(&a->cut, &b->cut, sizeof a->cut);
}

// The box of the scene's finite parts (empty when it has none).
Box finite_hull(const Scene *s) {
    Box h;
    for (int l = 0; l < 3; l++) {
        h.lo[l] = REAL_BIG;
        h.hi[l] = -REAL_BIG;
    }
    for (int i = 0; i < s->prims.n; i++)
        if (box_finite(s->prims[i].box) && !box_empty(s->prims[i].box)) box_hull(&h, s->prims[i].box);
    for (int j = 0; j < s->nodes.n; j++)
        if (box_finite(s->nodes[j].box) && !box_empty(s->nodes[j].box)) box_hull(&h, s->nodes[j].box);
    return h;
}

// Regions around box b: the grid over b grown by `slack` times its largest side, as many cells
// as the budget COH_BYTES gives `units` records (false when fewer than 4 a side). What rounding
// may move a point by is taken for points as far out as b grown on every side by its size.
bool coh_regions(Regions *R, Box b, size_t units, double slack) {
    if (box_empty(b))
        for (int l = 0; l < 3; l++) b.lo[l] = -1, b.hi[l] = 1;
    double m = 0;
    for (int l = 0; l < 3; l++) m = (double)b.hi[l] - b.lo[l] > m ? (double)b.hi[l] - b.lo[l] : m;
    if (!(m > 0)) m = 1;
    int n = COH_CELLS;
    while (n >= 4 && (double)units * ((1 + n * n * n + 31) / 32) * sizeof(unsigned) > COH_BYTES) n--;
    if (n < 4) return false;
    R->words = (1 + n * n * n + 31) / 32;
    RegionGrid &g = R->g;
    g.n = n;
    g.base = 1;
    for (int l = 0; l < 3; l++) {
        double e = (double)b.hi[l] - b.lo[l], far = e > m / 2 ? e : m / 2;
        g.lo[l] = (double)b.lo[l] - m * slack;
        g.hi[l] = (double)b.hi[l] + m * slack;
        g.h[l] = (g.hi[l] - g.lo[l]) / g.n;
        if (!(g.h[l] > 0) || !finite_num(g.h[l])) return false;
        g.inv[l] = 1 / g.h[l];
        R->round[l] = 1024 * REAL_EPS * (fabs((double)b.lo[l] - far) + fabs((double)b.hi[l] + far));
    }
    return true;
}

// The plan of a program's frame (CohPlan). A frame like the one before in all but its scene
// (the same camera, lights, image and options) compares the two scenes (coh_diff) and finds the
// share p of units whose records meet what changed: among all units when the frame before
// recorded every one, else among the sample's. What pays follows from a model of the work in
// instructions, with no clock in it (so that runs are alike): t, tracing a unit, and r,
// recording one, from what the frame before counted (trace_work, record_work; t of the last
// frame traced in full), and k, taking a unit over with the test of its record's words marked.
//   - With records of every unit the frame takes the others over when p t + k < t, and traces
//     those again; else it is traced in full.
//   - If the next frame finds the same share changed, it saves s = t - p (t + r) - k a unit.
//     The frame records (every unit when it is traced in full, the units traced again when it
//     takes the others over) when s is more than COH_MARGIN times what that recording costs
//     now (r, or p r a unit): the next frame alone pays for it, so recording does not slow an
//     animation down even when the animation ends there. Else a frame traced in full records
//     only the sample, at a cost of a per cent or two of its rays, and one that takes units over
//     records nothing (the next frame is traced in full, and records the sample).
// So an animation in which everything moves, or the camera, a program's single frame and one
// whose units cost little more to trace than to record are never recorded in full. A frame
// traced in full gets new cells, over this frame, the one before and where things go on
// moving. Records that the budget (COH_BYTES) or the context's memory cap has no room for (they
// may take half of what the cap leaves) are not made: the frame is traced in full. An
// allocation that fails is out of memory, as anywhere else.
pray_status coh_plan(pray_ctx *c, const Scene *s, CohPlan *plan) {
    memset(plan, 0, sizeof *plan);
    pray_status st0 = c->status;
    Coherence *h = c->coh;
    if (!h) h = c->coh = (Coherence *)mem_zalloc(c, sizeof(Coherence));
    if (!h) return c->status;
    bool bands = s->adaptive > 0;
    size_t units = (size_t)s->width * s->height;
    if (bands) {
        int rows = band_rows_of(s, true);
        units = (size_t)((s->height + rows - 1) / rows);
    }
    Options o = c->cur.opt;
    o.v[OPT_THREADS] = h->opt.v[OPT_THREADS];  // (the image does not depend on them)
    bool same = h->valid && same_bytes(o.v, h->opt.v, sizeof o.v) && coh_same_view(&h->prev, s);
    bool tried = same && h->recorded != COH_NONE && h->units == units;
    unsigned *dirty = tried ? (unsigned *)mem_zalloc(c, sizeof(unsigned) * 2 * (size_t)h->rg.words) : NULL;
    bool known = false;  // where the frames differ
    if (dirty) {
        CohDiff d;
        d.s[0] = &h->prev;
        d.s[1] = s;
        d.pairs.init();
        bool ix0 = scene_ix(c, d.s[0], &d.x[0]), ix1 = ix0 && scene_ix(c, s, &d.x[1]);
        known = ix1 && coh_diff(c, d, h->rg, dirty) && coh_twins(d);
        if (ix0) scene_ix_free(c, &d.x[0]);
        if (ix1) scene_ix_free(c, &d.x[1]);
        d.pairs.release(c);
    }
    bool all = h->recorded == COH_ALL;
    if (known && all) plan->redo = (unsigned char *)mem_alloc(c, units);
    int record = COH_SAMPLE;
    if (known) {  // a unit is traced again when its record meets a cell marked
        size_t again = 0, n = 0;
        int nw = h->rg.words, nd = 0;
        for (int k = 0; k < nw; k++)  // (the words marked, in place at the front)
            if (dirty[k]) dirty[nd] = dirty[k], dirty[nw + nd++] = (unsigned)k;
        n = all ? units : coh_slots(units, s->width, bands);  // (records of all units, or the sample's)
        unsigned char *hit = plan->redo ? plan->redo : (unsigned char *)mem_zalloc(c, n);
        if (plan->redo) memset(hit, 0, n);
        for (size_t b = 0; b < n && hit; b += COH_BLOCK) {  // (a block of units at a time)
            size_t m = n - b < COH_BLOCK ? n - b : COH_BLOCK;
            for (int k = 0; k < nd; k++) {
                const unsigned *r = h->rec + coh_word(b, (int)dirty[nw + k], nw), x = dirty[k];
                for (size_t j = 0; j < m; j++) hit[b + j] |= (r[j] & x) != 0;
            }
        }
        for (size_t u = 0; u < n && hit; u++) again += hit[u];
        if (hit != plan->redo) mem_free(c, hit);
        double p = n ? (double)again / n : 1, keep = COH_KEEP_WORK + COH_HIT_WORK * nd;
        if (plan->redo && !(p * h->t + keep < h->t)) {  // (taking over would cost more: traced in full)
            mem_free(c, plan->redo);
            plan->redo = NULL;
        }
        // the next frame, if it traces the same share again and records it, saves per unit
        // what tracing costs less that share of tracing and recording and what taking over
        // costs; this frame records every unit, or the units it traces again
        double saved = h->t - p * (h->t + h->r) - keep, cost = plan->redo ? p * h->r : h->r;
        if (saved > COH_MARGIN * cost) record = COH_ALL;
        else if (plan->redo) record = COH_NONE;
    }
    mem_free(c, dirty);
    if (!plan->redo) {  // new cells: this frame, the one before and the next
        Box b = finite_hull(s), cur = b;
        if (h->valid && !box_empty(h->hull) && !box_empty(cur)) {
            Box next;
            for (int l = 0; l < 3; l++) {
                next.lo[l] = 2 * cur.lo[l] - h->hull.lo[l];
                next.hi[l] = 2 * cur.hi[l] - h->hull.hi[l];
            }
            box_hull(&b, h->hull);
            if (!box_empty(next) && box_finite(next)) box_hull(&b, next);
        }
        // (a sample's grid reaches further: it tells whether the next frame is worth
        // recording, also when something moves out of this frame's box)
        Regions g;
        memset(&g, 0, sizeof g);
        if (!coh_regions(&g, b, units, record == COH_ALL ? 1.0 / 32 : 0.5)) record = COH_NONE;
        size_t slots = record == COH_ALL ? units : coh_slots(units, s->width, bands);
        size_t bytes = sizeof(unsigned) * (size_t)g.words * ((slots + COH_BLOCK - 1) / COH_BLOCK * COH_BLOCK);
        if (record != COH_NONE && (!h->rec || h->recbytes != bytes)) {
            mem_free(c, h->rec);
            h->rec = NULL;
            double img = record == COH_ALL ? sizeof(float) * 3.0 * (double)s->width * s->height : 0;
            if (c->limit && (double)c->used + 2 * ((double)bytes + img) > (double)c->limit) record = COH_NONE;
            else h->rec = (unsigned *)mem_alloc(c, bytes);
            h->recbytes = h->rec ? bytes : 0;
        }
        h->rg = g;
        h->units = units;
        if (!h->rec) record = COH_NONE;
    }
    if (c->status != st0) {  // out of memory
        mem_free(c, plan->redo);
        memset(plan, 0, sizeof *plan);
        return c->status;
    }
    h->recorded = COH_NONE;  // (until coh_keep)
    plan->record = record;
    plan->prev = plan->redo ? h->img : NULL;
    if (record == COH_NONE) return PRAY_OK;
    plan->rec = h->rec;
    plan->units = units;
    plan->rg = &h->rg;
    plan->sample = record == COH_SAMPLE;
    return PRAY_OK;
}

// After a program's frame: keep its scene (taken from *s, without its acceleration structure)
// and options for the next, and its pixels when it was recorded.
pray_status coh_keep(pray_ctx *c, Scene *s, const float *img, const CohPlan *plan) {
    Coherence *h = c->coh;
    if (!h) return PRAY_OK;
    int recorded = plan->record;
    if (!plan->redo && plan->traced > 0) h->t = plan->work / plan->traced;
    if (plan->recorded > 0) h->r = plan->rwork / plan->recorded + COH_WORD_WORK * h->rg.words;
    size_t n = (size_t)s->width * s->height * 3;
    if (recorded == COH_ALL && (!h->img || h->imgsize != n)) {
        mem_free(c, h->img);
        h->imgsize = 0;
        if (c->limit && (double)c->used + 2.0 * sizeof(float) * n > (double)c->limit) recorded = COH_SAMPLE;
        else if (!(h->img = (float *)mem_alloc(c, sizeof(float) * n))) return c->status;
        else h->imgsize = n;
    }
    if (recorded == COH_ALL) memcpy(h->img, img, sizeof(float) * n);
    if (h->valid) scene_release(c, &h->prev);
    h->hull = finite_hull(s);
    accel_release(c, s->accel);
    s->accel = NULL;
    h->prev = *s;
    memset(s, 0, sizeof *s);
    s->prims.init();
    s->maps.init();
    s->nodes.init();
    s->lights.init();
    s->kids.init();
    h->opt = c->cur.opt;
    h->valid = 1;
    h->recorded = recorded;
    return PRAY_OK;
}
#else
inline void coh_release(pray_ctx *) {}
void region_note(Scratch *, const Ray &, real) {}
#endif  // PRAY_NO_SEQUENCES
} // namespace

// =============================================================================================
// [SECTION] 11 Image writers: TIFF, PPM, PNG; writing files safely
// =============================================================================================
namespace {

struct Sink {
    pray_write_fn fn;
    void *ud;
    void put(const void *p, size_t n) { fn(ud, p, n); }
};

inline unsigned quantize(double v, unsigned maxval) {
    if (!(v > 0)) return 0;  // also NaN
    if (v >= 1) return maxval;
    return (unsigned)(v * maxval + 0.5);  // in double: the same on x87 and SSE
}

// Little-endian ("II") byte layout, written byte by byte so every host writes the same file.
void le16(unsigned char *p, unsigned v) {
    p[0] = (unsigned char)(v & 255);
    p[1] = (unsigned char)(v >> 8 & 255);
}
void le32(unsigned char *p, unsigned long v) {
    le16(p, (unsigned)(v & 0xFFFF));
    le16(p + 2, (unsigned)(v >> 16 & 0xFFFF));
}

bool image_ok(pray_ctx *c, const pray_image *img) {
    if (!img || !img->pixels || img->width < 1 || img->height < 1 || img->width > MAX_IMAGE_SIDE ||
        img->height > MAX_IMAGE_SIDE) {
        fail(c, PRAY_ERR_ARG, "not a valid image");
        return false;
    }
    return true;
}

// Baseline TIFF 6.0: one strip, RGB, uncompressed, 8 or 16 bits per sample. A note (printable
// ASCII, see pray_write_image_note) becomes the ImageDescription, between the resolutions and the
// samples; without one the file is the same but for that tag.
pray_status write_tiff(pray_ctx *c, const pray_image *img, int bits, Sink &out, const char *note = NULL) {
    const unsigned long nlen = note ? (unsigned long)strlen(note) + 1 : 0;
    const int ntags = note ? 13 : 12;
    const unsigned long ifd = 8, bps = ifd + 2 + ntags * 12 + 4, xres = bps + 6, yres = xres + 8, desc = yres + 8,
                        data = desc + nlen;
    unsigned long W = (unsigned long)img->width, H = (unsigned long)img->height;
    unsigned long bytes = W * H * 3 * (bits / 8);
    unsigned char h[8 + 2 + 13 * 12 + 4 + 6 + 16];
    memset(h, 0, sizeof h);
    h[0] = 'I';
    h[1] = 'I';
    le16(h + 2, 42);
    le32(h + 4, ifd);
    le16(h + ifd, (unsigned)ntags);
    // tag, type (2 ASCII, 3 SHORT, 4 LONG, 5 RATIONAL), count, value or offset
    static const unsigned short tags[13][2] = {
        {256, 4}, {257, 4}, {258, 3}, {259, 3}, {262, 3}, {270, 2}, {273, 4},
        {277, 3}, {278, 4}, {279, 4}, {282, 5}, {283, 5}, {296, 3}};
    unsigned long vals[13] = {W, H, bps, 1, 2, desc, data, 3, H, bytes, xres, yres, 2};
    unsigned long counts[13] = {1, 1, 3, 1, 1, nlen, 1, 1, 1, 1, 1, 1, 1};
    for (int i = 0, k = 0; i < 13; i++) {
        if (tags[i][0] == 270 && !note) continue;
        unsigned char *e = h + ifd + 2 + 12 * k++;
        le16(e, tags[i][0]);
        le16(e + 2, tags[i][1]);
        le32(e + 4, counts[i]);
        if (tags[i][1] == 3 && counts[i] == 1) le16(e + 8, (unsigned)vals[i]);
        else le32(e + 8, vals[i]);
    }
    le32(h + ifd + 2 + ntags * 12, 0);  // no further IFD
    for (int i = 0; i < 3; i++) le16(h + bps + 2 * i, (unsigned)bits);
    le32(h + xres, 72);
    le32(h + xres + 4, 1);
    le32(h + yres, 72);
    le32(h + yres + 4, 1);
    size_t rowbytes = (size_t)W * 3 * (bits / 8);
    unsigned char *row = (unsigned char *)mem_alloc(c, rowbytes);
    if (!row) return c->status;
    out.put(h, desc);
    if (note) out.put(note, nlen);  // with its NUL, as ASCII fields end
    for (unsigned long y = 0; y < H; y++) {
        if (cancelled(c)) return mem_free(c, row), fail_cancelled(c);
        const float *px = img->pixels + (size_t)y * W * 3;
        for (size_t i = 0; i < (size_t)W * 3; i++) {
            if (bits == 8) row[i] = (unsigned char)quantize(px[i], 255);
            else le16(row + 2 * i, quantize(px[i], 65535));
        }
        out.put(row, rowbytes);
    }
    mem_free(c, row);
    return PRAY_OK;
}

// Binary PPM (P6); 16-bit samples are big-endian, as the format says. A note is a comment line
// after the magic number: "P6\n# NOTE\n...".
pray_status write_ppm(pray_ctx *c, const pray_image *img, int bits, Sink &out, const char *note = NULL) {
    char head[64];
    int n = snprintf(head, sizeof head, "%d %d\n%u\n", img->width, img->height,
                     bits == 8 ? 255u : 65535u);
    size_t rowbytes = (size_t)img->width * 3 * (bits / 8);
    unsigned char *row = (unsigned char *)mem_alloc(c, rowbytes);
    if (!row) return c->status;
    out.put("P6\n", 3);
    if (note) {
        out.put("# ", 2);
        out.put(note, strlen(note));
        out.put("\n", 1);
    }
    out.put(head, (size_t)n);
    for (int y = 0; y < img->height; y++) {
        if (cancelled(c)) return mem_free(c, row), fail_cancelled(c);
        const float *px = img->pixels + (size_t)y * img->width * 3;
        for (size_t i = 0; i < (size_t)img->width * 3; i++) {
            if (bits == 8) row[i] = (unsigned char)quantize(px[i], 255);
            else {
                unsigned v = quantize(px[i], 65535);
                row[2 * i] = (unsigned char)(v >> 8);
                row[2 * i + 1] = (unsigned char)(v & 255);
            }
        }
        out.put(row, rowbytes);
    }
    mem_free(c, row);
    return PRAY_OK;
}

#if PRAY_HAS_PNG
void png_sink(void *ud, void *data, int size) {
    Sink *s = (Sink *)ud;
    s->put(data, (size_t)size);
}

// The PNG being encoded on this thread: its context, the blocks the encoder holds (a list of
// their own, so a failed encoding can free them all), and where to go when an allocation fails.
struct PngEncoding {
    pray_ctx *c;
    Block held;
    jmp_buf failed;
};
#if !PRAY_HAS_THREADS
PngEncoding *png_now;
#elif __cplusplus >= 201103L
thread_local PngEncoding *png_now;
#elif defined(_MSC_VER)
__declspec(thread) PngEncoding *png_now;
#else
__thread PngEncoding *png_now;
#endif

void png_hold(PngEncoding *e, void *p) {
    Block *b = (Block *)p - 1;  // from the context's list to the encoding's
    block_unlink(b);
    block_link(&e->held, b);
}

pray_status write_png(pray_ctx *c, const pray_image *img, Sink &out) {
    size_t n = (size_t)img->width * img->height * 3;
    unsigned char *buf = (unsigned char *)mem_alloc(c, n);
    if (!buf) return c->status;
    for (size_t i = 0; i < n; i++) buf[i] = (unsigned char)quantize(img->pixels[i], 255);
    if (cancelled(c)) return mem_free(c, buf), fail_cancelled(c);
    PngEncoding e;
    e.c = c;
    e.held.next = e.held.prev = &e.held;
    png_now = &e;
    // Called through a volatile pointer: never inlined here, where its locals would be live across the setjmp.
    int (*volatile encode)(stbi_write_func *, void *, int, int, int, const void *, int) = stbi_write_png_to_func;
    int ok = 0, stopped = 0;
    if (!setjmp(e.failed)) ok = encode(png_sink, &out, img->width, img->height, 3, buf, img->width * 3);
    else stopped = 1;  // png_alloc: out of memory or cancelled, the message is in the context
    png_now = NULL;
    while (e.held.next != &e.held) mem_free(c, e.held.next + 1);
    mem_free(c, buf);
    if (stopped) return c->status;
    return ok ? PRAY_OK : fail(c, PRAY_ERR_NOMEM, "PNG encoder failed");
}
#endif

enum { FMT_NONE, FMT_TIFF, FMT_PPM, FMT_PNG };

int ascii_lower(int ch) { return ch >= 'A' && ch <= 'Z' ? ch + 32 : ch; }
bool same_nocase(const char *a, const char *b) {
    for (; *a && *b; a++, b++)
        if (ascii_lower((unsigned char)*a) != ascii_lower((unsigned char)*b)) return false;
    return *a == *b;
}

// The extension of a file name (the part after its last '.'), or NULL.
const char *file_ext(const char *path) {
    const char *dot = NULL;
    for (const char *p = path; *p; p++) {
        if (*p == '/' || *p == '\\' || *p == ':') dot = NULL;
        else if (*p == '.') dot = p;
    }
    return dot ? dot + 1 : NULL;
}

int image_format(const char *path) {
    const char *e = file_ext(path);
    if (!e) return FMT_NONE;
    if (same_nocase(e, "tif") || same_nocase(e, "tiff")) return FMT_TIFF;
    if (same_nocase(e, "ppm")) return FMT_PPM;
    if (same_nocase(e, "png")) return FMT_PNG;
    return FMT_NONE;
}

#if PRAY_HAS_STDIO
pray_status write_format(pray_ctx *c, const pray_image *img, int fmt, int bits, Sink &out, const char *note) {
    if (fmt == FMT_TIFF) return write_tiff(c, img, bits, out, note);
    if (fmt == FMT_PPM) return write_ppm(c, img, bits, out, note);
#if PRAY_HAS_PNG
    if (fmt == FMT_PNG) return write_png(c, img, out);
#endif
    return fail(c, PRAY_ERR_ARG, "this build cannot write that format");
}
#endif

#if PRAY_HAS_STDIO
// A file being written: stops at the first error, or where the bytes would pass `room`.
struct FileSink {
    FILE *f;
    int err;  // errno of the first failure; -1: over the room
    double bytes, room;
};
void file_put(void *ud, const void *p, size_t n) {
    FileSink *s = (FileSink *)ud;
    if (!s->err && s->bytes + n > s->room) s->err = -1;
    if (!s->err && n && fwrite(p, 1, n, s->f) != n) s->err = errno ? errno : EIO;
    s->bytes += n;
}

// Is `path` the program being run? By identity where files have one, else by name.
bool is_program(pray_ctx *c, const char *path) { return c->prog_name && same_file(path, c->prog_id, c->prog_name); }

// Create a temporary file beside `path`, exclusively, never through a link, under a name no
// other writer uses: ".NAME.XXXXXX" + PRAY_TEMP_SUFFIX (NAME: the file's name, cut to 32 bytes,
// so that a name of 255 bytes still has one), or with PRAY_8_3_NAMES "NAXXXXXX" + the suffix
// ("CS4F0Q2Z.$$$"). `*tmp` gets the name (context memory). NULL on failure (errno set).
FILE *create_temp(pray_ctx *c, const char *path, char **tmp) {
    size_t n = strlen(path), d = n;
    while (d > 0 && path[d - 1] != '/' && path[d - 1] != '\\' && path[d - 1] != ':') d--;
    size_t keep = n - d;
#ifdef PRAY_8_3_NAMES
    keep = (size_t)(file_ext(path) - 1 - (path + d));
    if (keep > 2) keep = 2;
    const char *lead = "", *dot = "";
#else
    if (keep > 32) keep = 32;
    while (keep > 0 && (path[d + keep] & 0xC0) == 0x80) keep--;  // whole UTF-8 characters
    const char *lead = ".", *dot = ".";
#endif
    *tmp = (char *)mem_alloc(c, d + keep + 16 + sizeof PRAY_TEMP_SUFFIX);
    if (!*tmp) return NULL;
    FILE *f = NULL;
    errno = EEXIST;
    for (int tries = 0; !f && errno == EEXIST && tries < 100; tries++) {
        unsigned long h = process_id() * 2654435761u ^ (unsigned long)(size_t)c ^ clock_ticks() * 40503u;
        h = h * 31 + c->temp_serial++ * 2246822519u;
        char id[7];
        for (int i = 0; i < 6; i++, h /= 36) id[i] = "0123456789ABCDEFGHIJKLMNOPQRSTUVWXYZ"[h % 36];
        id[6] = 0;
        snprintf(*tmp, d + keep + 16 + sizeof PRAY_TEMP_SUFFIX, "%.*s%s%.*s%s%s%s", (int)d, path, lead, (int)keep,
                 path + d, dot, id, PRAY_TEMP_SUFFIX);
        errno = 0;
        // named before it exists: a signal from here on finds the name (pray_temp_file); one
        // that comes before the file does removes nothing
        c->temp_name = *tmp;
#if PRAY_FILES_FD
        int fd = fd_open(*tmp, 1);
        if (fd >= 0 && !(f = fd_stdio(fd, "wb"))) {
            int e = errno;
            fd_close(fd);
            remove(*tmp);
            errno = e ? e : EIO;
        }
#else
        FILE *there = fopen(*tmp, "rb");  // no exclusive creation here: look first
        if (there) {
            fclose(there);
            errno = EEXIST;
        } else
            f = fopen(*tmp, "wb");
#endif
        if (!f) c->temp_name = NULL;
    }
    return f;
}
#endif

} // namespace

#if PRAY_HAS_PNG
// stb_image_write's malloc (p NULL), realloc and free (n 0), on the context of png_now; where
// the encoder grows its buffers, it can be cancelled.
static void *png_alloc(void *p, size_t n) {
    PngEncoding *e = png_now;
    if (!n) {
        mem_free(e->c, p);
        return NULL;
    }
    if (cancelled(e->c)) {
        fail_cancelled(e->c);
        longjmp(e->failed, 1);
    }
    void *q = mem_realloc(e->c, p, n);
    if (!q) longjmp(e->failed, 1);
    png_hold(e, q);
    return q;
}
#endif


// ---------------------------------------------------------------------------------------------
// Public functions of sections 2 to 11
// ---------------------------------------------------------------------------------------------
const char *pray_status_text(pray_status s) {
    switch (s) {
    case PRAY_OK: return "ok";
    case PRAY_ERR_NOMEM: return "out of memory";
    case PRAY_ERR_IO: return "input/output error";
    case PRAY_ERR_SYNTAX: return "syntax error";
    case PRAY_ERR_RUNTIME: return "runtime error";
    case PRAY_ERR_LIMIT: return "limit reached";
    case PRAY_ERR_ARG: return "bad argument";
    case PRAY_ERR_CANCELLED: return "cancelled";
    }
    return "unknown status";
}

const char *pray_version(void) { return PRAY_VERSION_STRING; }

const char *pray_features(void) {
    return ""
#if PRAY_HAS_INTERP
           "interp "
#endif
#if PRAY_HAS_STDIO
           "stdio "
#endif
#if PRAY_HAS_PNG
           "png "
#endif
#if PRAY_HAS_THREADS
           "threads "
#endif
#ifndef PRAY_NO_BUFFERS
           "buffers "
#endif
#ifndef PRAY_NO_SEQUENCES
           "sequences "
#endif
           "real=" PRAY_STRINGIFY(PRAY_REAL);
}

pray_ctx *pray_new_with(pray_alloc_fn alloc, void *ud) {
    if (!alloc) return NULL;
    pray_ctx *c = (pray_ctx *)alloc(ud, NULL, 0, sizeof(pray_ctx));
    if (!c) return NULL;
    memset(c, 0, sizeof *c);
    c->alloc = alloc;
    c->alloc_ud = ud;
    c->limit = PRAY_MAX_ALLOC;
    c->blocks.next = c->blocks.prev = &c->blocks;
    setup_default(&c->cur);
    c->base = c->cur;
    return c;
}

pray_ctx *pray_new(void) {
#if PRAY_HAS_DEFAULT_ALLOC
    return pray_new_with(default_alloc, NULL);
#else
    return NULL;
#endif
}

void pray_free(pray_ctx *c) {
    if (!c) return;
    while (c->blocks.next != &c->blocks) mem_free(c, c->blocks.next + 1);
    c->alloc(c->alloc_ud, c, sizeof(pray_ctx), 0);
}

const char *pray_error(const pray_ctx *c) { return c ? c->msg : "error: no context"; }
const char *pray_temp_file(const pray_ctx *c) { return c ? c->temp_name : NULL; }
pray_status pray_last_status(const pray_ctx *c) { return c ? c->status : PRAY_ERR_ARG; }
void pray_clear_error(pray_ctx *c) {
    if (!c) return;
    c->status = PRAY_OK;
    c->msg[0] = 0;
    c->err_line = c->err_col = 0;
}
const char *pray_error_place(const pray_ctx *c, int *line, int *col) {
    bool at = c && c->status != PRAY_OK && c->err_line > 0;
    if (line) *line = at ? c->err_line : 0;
    if (col) *col = at ? c->err_col : 0;
    return at ? c->err_name : NULL;
}
void pray_set_memory_limit(pray_ctx *c, size_t bytes) {
    if (!c) return;
    c->host_limit = bytes;
    apply_memory_cap(c);
}

void pray_set_untrusted(pray_ctx *c) {
    if (!c) return;
    c->untrusted = 1;
    for (int i = 0; i < OPT_COUNT; i++) {
        double top = OPTS[i].untrusted;
        if (top > 0 && (c->base.opt.v[i] == 0 || c->base.opt.v[i] > top)) c->base.opt.v[i] = top;
    }
    if (!c->running) c->cur = c->base;
    apply_memory_cap(c);
}
void pray_set_warning(pray_ctx *c, pray_write_fn fn, void *ud) {
    if (!c) return;
    c->warn_fn = fn;
    c->warn_ud = ud;
}
void pray_set_print(pray_ctx *c, pray_write_fn fn, void *ud) {
    if (!c) return;
    c->print_fn = fn;
    c->print_ud = ud;
    c->print_set = 1;
}
void pray_set_progress(pray_ctx *c, pray_progress_fn fn, void *ud) {
    if (!c) return;
    c->progress_fn = fn;
    c->progress_ud = ud;
}
namespace {
// A frame of a program whose rendering the host does (pray_set_render): none when it left the
// image empty, else the host's frame callback or the file, as without it.
pray_status frame_of_host(void *ud, const pray_image *img, const char *name) {
    pray_ctx *c = (pray_ctx *)ud;
    if (!img->pixels) return PRAY_OK;
    if (c->host_frame_fn) return c->host_frame_fn(c->host_frame_ud, img, name);
    return pray_write_image(c, img, name, opt_int(c, OPT_BITS));
}
// What a program's rendertiff hands its frame to (frame_fn): the host's callback, or
// frame_of_host while the host renders the frames.
void frame_route(pray_ctx *c) {
    c->frame_fn = c->render_fn ? frame_of_host : c->host_frame_fn;
    c->frame_ud = c->render_fn ? (void *)c : c->host_frame_ud;
}
} // namespace

void pray_set_frame(pray_ctx *c, pray_frame_fn fn, void *ud) {
    if (!c) return;
    c->host_frame_fn = fn;
    c->host_frame_ud = ud;
    frame_route(c);
}
void pray_set_render(pray_ctx *c, pray_render_fn fn, void *ud) {
    if (!c) return;
    c->render_fn = fn;
    c->render_ud = ud;
    frame_route(c);
}

void pray_cancel(pray_ctx *c) {
    if (c) cancel_set(c, CANCEL_HOST);
}

pray_status pray_option(pray_ctx *c, const char *name, double value) {
    if (!c) return PRAY_ERR_ARG;
    int i = name ? opt_find(name) : -1;
    if (i < 0) return opt_unknown(c, name ? name : "");
    if (i == OPT_OUTPUT) return fail(c, PRAY_ERR_ARG, "option 'output' takes a string");
    const char *why = opt_check(i, value);
    if (why) return fail(c, PRAY_ERR_ARG, "option '%s': %g is %s", name, nan_clean(value), why);
    double top = OPTS[i].untrusted;
    if (c->untrusted && top > 0 && (value == 0 || value > top))
        return fail(c, PRAY_ERR_ARG, "option '%s': %.15g%s is above %.15g, the ceiling in untrusted mode", name, value,
                    value == 0 ? " (no limit)" : "", top);
    if (c->fixed[i]) return PRAY_OK;
    double w = i == OPT_WIDTH ? value : c->cur.opt.v[OPT_WIDTH], h = i == OPT_HEIGHT ? value : c->cur.opt.v[OPT_HEIGHT];
    if (w * h > MAX_IMAGE_PIXELS)
        return fail(c, PRAY_ERR_ARG, "image of %.0f x %.0f pixels is too large", w, h);
    c->cur.opt.v[i] = value;
    if (!c->running) c->base = c->cur;
    if (i == OPT_MAXMEM) apply_memory_cap(c);
    return PRAY_OK;
}

pray_status pray_option_string(pray_ctx *c, const char *name, const char *value) {
    if (!c) return PRAY_ERR_ARG;
    int i = name ? opt_find(name) : -1;
    if (i < 0) return opt_unknown(c, name ? name : "");
    if (i != OPT_OUTPUT) return fail(c, PRAY_ERR_ARG, "option '%s' takes a number", name);
    if (!value || !*value) return fail(c, PRAY_ERR_ARG, "option 'output': empty file name");
    if (strlen(value) >= sizeof c->cur.opt.output)
        return fail(c, PRAY_ERR_ARG, "option 'output': file name too long");
    int fmt = image_format(value);
    if (fmt == FMT_PNG && !PRAY_HAS_PNG)
        return fail(c, PRAY_ERR_ARG, "option 'output': '%s': this pray writes no PNG: " PNG_MISSING "; use .tif or .ppm", value);
    if (fmt == FMT_NONE)
        return fail(c, PRAY_ERR_ARG, "option 'output': cannot tell the image format of '%s' (use .tif, .ppm%s)", value,
                    PRAY_HAS_PNG ? " or .png" : "");
    if (c->untrusted && c->running && (untrusted_path_problem(value) || strchr(value, '/') || strchr(value, '\\')))
        return fail(c, PRAY_ERR_ARG, "option 'output': an untrusted program may name a file, not a directory ('%s')",
                    value);
    if (!c->fixed[i]) strcpy(c->cur.opt.output, value);
    if (!c->running) c->base = c->cur;
    return PRAY_OK;
}

pray_status pray_option_fix(pray_ctx *c, const char *name, const char *text) {
    if (!c) return PRAY_ERR_ARG;
    int i = name ? opt_find(name) : -1;
    if (i < 0) return opt_unknown(c, name ? name : "");
    c->fixed[i] = 0;
    pray_status st;
    if (i == OPT_OUTPUT) st = pray_option_string(c, name, text);
    else {
        char *end = NULL;
        double v = text ? strtod(text, &end) : 0;
        if (!text || end == text || *end)
            return fail(c, PRAY_ERR_ARG, "option '%s': '%s' is not a number", name, text ? *Shown(text) : "");
        st = pray_option(c, name, v);
    }
    if (st == PRAY_OK) c->fixed[i] = 1;
    return st;
}

double pray_option_get(const pray_ctx *c, const char *name) {
    int i = c && name ? opt_find(name) : -1;
    if (i < 0 || i == OPT_OUTPUT) return HUGE_VAL - HUGE_VAL;
    return c->cur.opt.v[i];
}

namespace {
// A handle given to the public function `fn` as its `what`: false when it is NULL, not a live
// handle of that kind (any of the four for kind 0), or made by another context. For NULL the
// message "fn: no what" is recorded only when no failure is recorded yet (the chain rule: the
// message of the failure that made the NULL is kept).
bool handle_ok(pray_ctx *c, const void *p, int kind, const char *fn, const char *what) {
    if (!p) {
        if (c->status == PRAY_OK) fail(c, PRAY_ERR_ARG, "%s: no %s", fn, what);
        return false;
    }
    const Handle *h = (const Handle *)p;
    if (h->magic != HANDLE_MAGIC || (kind ? h->kind != kind : h->kind == H_KIDS || h->kind == H_STRING))
        return fail(c, PRAY_ERR_ARG, "%s: the %s is not a live handle of its kind", fn, what), false;
    if (owner_of(p) != c) return fail(c, PRAY_ERR_ARG, "%s: the %s belongs to another context", fn, what), false;
    return true;
}
bool model_ok(pray_ctx *c, const pray_model *m, const char *fn, const char *what = "model") {
    return handle_ok(c, m, H_MODEL, fn, what);
}
bool object_ok(pray_ctx *c, const pray_object *o, const char *fn, const char *what = "object") {
    return handle_ok(c, o, H_OBJECT, fn, what);
}
bool light_ok(pray_ctx *c, const pray_light *l, const char *fn, const char *what = "light") {
    return handle_ok(c, l, H_LIGHT, fn, what);
}

bool bad_rgb(pray_ctx *c, pray_rgb v, const char *what) {
    if (cfinite(v)) return false;
    fail(c, PRAY_ERR_ARG, "%s: intensity is not finite", what);
    return true;
}
bool bad_vec(pray_ctx *c, pray_vec v, const char *what, bool nonzero) {
    if (!vfinite(v)) return fail(c, PRAY_ERR_ARG, "%s: coordinates are not finite", what), true;
    if (nonzero && v.x == 0 && v.y == 0 && v.z == 0) return fail(c, PRAY_ERR_ARG, "%s: zero-length vector", what), true;
    return false;
}
bool bad_radius(pray_ctx *c, double r, const char *what) {
    if (finite_num(r) && r > 0) return false;
    fail(c, PRAY_ERR_ARG, "%s: radius must be a positive number, not %g", what, nan_clean(r));
    return true;
}
} // namespace

pray_model *pray_phong(pray_ctx *c, pray_rgb d, pray_rgb s, pray_rgb a, double e) {
    if (!c || bad_rgb(c, d, "phong") || bad_rgb(c, s, "phong") || bad_rgb(c, a, "phong")) return NULL;
    if (!finite_num(e) || e < 0)
        return fail(c, PRAY_ERR_ARG, "phong: exponent must be a number >= 0, not %g", e), (pray_model *)NULL;
    pray_model *m = model_new(c);
    if (!m) return NULL;
    m->diffuse = d;
    m->specular = s;
    m->ambient = a;
    m->exponent = e;
    m->has_exponent = 1;
    return m;
}

pray_model *pray_mirror(pray_ctx *c, pray_rgb w) {
    if (!c || bad_rgb(c, w, "mirror")) return NULL;
    pray_model *m = model_new(c);
    if (m) m->reflect = w;
    return m;
}

pray_model *pray_transparent(pray_ctx *c, pray_rgb w, double index) {
    if (!c || bad_rgb(c, w, "transparent")) return NULL;
    if (!finite_num(index) || index <= 0)
        return fail(c, PRAY_ERR_ARG, "transparent: refraction index must be > 0, not %g", index), (pray_model *)NULL;
    pray_model *m = model_new(c);
    if (!m) return NULL;
    m->transmit = w;
    m->index = index;
    m->has_index = 1;
    return m;
}

pray_model *pray_color(pray_ctx *c, pray_rgb col) {
    if (!c || bad_rgb(c, col, "color")) return NULL;
    pray_model *m = model_new(c);
    if (m) m->emit = col;
    return m;
}

pray_model *pray_model_add(pray_ctx *c, pray_model *a, pray_model *b) {
    if (!c || !model_ok(c, a, "pray_model_add", "model a") || !model_ok(c, b, "pray_model_add", "model b")) return NULL;
    return model_sum(c, a, b);
}

pray_model *pray_model_scale(pray_ctx *c, pray_model *m, pray_rgb f) {
    if (!c || !model_ok(c, m, "pray_model_scale") || bad_rgb(c, f, "model scale")) return NULL;
    return model_times(c, m, f);
}

pray_object *pray_sphere(pray_ctx *c, pray_model *m, pray_vec centre, double r) {
    if (!c || !model_ok(c, m, "pray_sphere") || bad_vec(c, centre, "sphere", false) || bad_radius(c, r, "sphere"))
        return NULL;
    pray_object *o = obj_new(c, O_SPHERE, m);
    if (!o) return NULL;
    o->p = centre;
    o->r = r;
    return o;
}

pray_object *pray_plane(pray_ctx *c, pray_model *m, pray_vec point, pray_vec normal) {
    if (!c || !model_ok(c, m, "pray_plane") || bad_vec(c, point, "plane", false) ||
        bad_vec(c, normal, "plane normal", true))
        return NULL;
    pray_object *o = obj_new(c, O_PLANE, m);
    if (!o) return NULL;
    o->p = point;
    o->v = normal;
    return o;
}

pray_object *pray_cylinder(pray_ctx *c, pray_model *m, pray_vec point, pray_vec axis, double r) {
    if (!c || !model_ok(c, m, "pray_cylinder") || bad_vec(c, point, "cylinder", false) ||
        bad_vec(c, axis, "cylinder axis", true) ||
        bad_radius(c, r, "cylinder"))
        return NULL;
    pray_object *o = obj_new(c, O_CYLINDER, m);
    if (!o) return NULL;
    o->p = point;
    o->v = axis;
    o->r = r;
    return o;
}

namespace {
// A primitive of the version-2 kinds: in its own frame (the world's, to begin with), with the
// texture coordinates of a planemap at p along X and Y.
pray_object *framed_new(pray_ctx *c, int kind, pray_model *m, pray_vec p, pray_vec v, double r, double r2) {
    pray_object *o = obj_new(c, kind, m);
    if (!o) return NULL;
    o->p = p;
    o->v = v;
    o->r = r;
    o->r2 = r2;
    o->fr = (Xform *)mem_alloc(c, sizeof(Xform));
    if (!o->fr || !obj_map(c, o, MAP_PLANE, vmake(1, 0, 0), vmake(0, 1, 0), 0)) {
        release_handle(c, o);
        return NULL;
    }
    *o->fr = xf_identity();
    return o;
}
// The ends of an axis: finite, and far enough apart for its direction to be known.
bool bad_axis(pray_ctx *c, pray_vec p1, pray_vec p2, const char *what) {
    if (bad_vec(c, p1, what, false) || bad_vec(c, p2, what, false)) return true;
    pray_vec a = vsub(p2, p1);
    if (!vfinite(a)) return fail(c, PRAY_ERR_ARG, "%s: the axis is longer than the range of numbers", what), true;
    if (vmaxabs(a) <= 1e-12 * (vmaxabs(p1) + vmaxabs(p2)))
        return fail(c, PRAY_ERR_ARG, "%s: the two points must be distinct", what), true;
    return false;
}
} // namespace

pray_object *pray_box(pray_ctx *c, pray_model *m, pray_vec p1, pray_vec p2) {
    if (!c || !model_ok(c, m, "pray_box") || bad_vec(c, p1, "box", false) || bad_vec(c, p2, "box", false)) return NULL;
    pray_vec d = vsub(p2, p1);
    double e[3] = {fabs(d.x), fabs(d.y), fabs(d.z)}, a[3] = {fabs(p1.x) + fabs(p2.x), fabs(p1.y) + fabs(p2.y), fabs(p1.z) + fabs(p2.z)};
    for (int i = 0; i < 3; i++)
        if (!(e[i] > 1e-12 * a[i]) || !finite_num(e[i])) {
            double u = i == 0 ? p1.x : i == 1 ? p1.y : p1.z;
            if (e[i] == 0) fail(c, PRAY_ERR_ARG, "box: the corners must differ in every coordinate (both have %c = %g)", "xyz"[i], u);
            else if (finite_num(e[i]))
                fail(c, PRAY_ERR_ARG, "box: the corners are too close in %c to tell apart (%g apart at %g)", "xyz"[i], e[i], u);
            else fail(c, PRAY_ERR_ARG, "box: the extent in %c is beyond the range of numbers", "xyz"[i]);
            return NULL;
        }
    return framed_new(c, O_BOX, m, p1, p2, 0, 0);
}

pray_object *pray_rod(pray_ctx *c, pray_model *m, pray_vec p1, pray_vec p2, double r) {
    if (!c || !model_ok(c, m, "pray_rod") || bad_axis(c, p1, p2, "rod") || bad_radius(c, r, "rod")) return NULL;
    return framed_new(c, O_ROD, m, p1, p2, r, r);
}

pray_object *pray_cone(pray_ctx *c, pray_model *m, pray_vec p1, double r1, pray_vec p2, double r2) {
    if (!c || !model_ok(c, m, "pray_cone") || bad_axis(c, p1, p2, "cone")) return NULL;
    if (!finite_num(r1) || !finite_num(r2) || r1 < 0 || r2 < 0 || (r1 == 0 && r2 == 0)) {
        fail(c, PRAY_ERR_ARG, "cone: the radii must be numbers >= 0, not both 0, not %g and %g", nan_clean(r1),
             nan_clean(r2));
        return NULL;
    }
    return framed_new(c, O_CONE, m, p1, p2, r1, r2);
}

pray_object *pray_torus(pray_ctx *c, pray_model *m, pray_vec centre, pray_vec axis, double R, double r) {
    if (!c || !model_ok(c, m, "pray_torus") || bad_vec(c, centre, "torus", false) || bad_vec(c, axis, "torus axis", true))
        return NULL;
    if (!finite_num(R) || !finite_num(r) || !(r > 0) || !(R > r)) {
        fail(c, PRAY_ERR_ARG, "torus: the radii must be numbers with R > r > 0, not R = %g and r = %g", nan_clean(R),
             nan_clean(r));
        return NULL;
    }
    if (!finite_num(R + r))
        return fail(c, PRAY_ERR_ARG, "torus: R + r is beyond the range of numbers"), (pray_object *)NULL;
    return framed_new(c, O_TORUS, m, centre, vunit(axis), R, r);
}

pray_object *pray_one(pray_ctx *c, pray_model *m) {
    return c && model_ok(c, m, "pray_one") ? obj_new(c, O_ONE, m) : NULL;
}

namespace {
bool bad_pair(pray_ctx *c, pray_vec u, pray_vec v, const char *what) {
    if (bad_vec(c, u, what, true) || bad_vec(c, v, what, true)) return true;
    if (!map_len_ok(u) || !map_len_ok(v))
        return fail(c, PRAY_ERR_ARG, "%s: the vectors' lengths must lie between %g and %g", what, MAP_LEN_MIN, MAP_LEN_MAX), true;
    if (vlen(vcross(vunit(u), vunit(v))) <= 1e-12)
        return fail(c, PRAY_ERR_ARG, "%s: the two vectors must not be parallel", what), true;
    return false;
}
} // namespace

pray_object *pray_planemap(pray_ctx *c, pray_model *m, pray_vec point, pray_vec normal, pray_vec u, pray_vec v) {
    if (!c || !model_ok(c, m, "pray_planemap") || bad_pair(c, u, v, "planemap")) return NULL;
    pray_object *o = pray_plane(c, m, point, normal);
    if (o && !obj_map(c, o, MAP_PLANE, u, v, 0)) {
        release_handle(c, o);
        return NULL;
    }
    return o;
}

pray_object *pray_spheremap(pray_ctx *c, pray_model *m, pray_vec centre, double r, pray_vec north, pray_vec zero) {
    if (!c || !model_ok(c, m, "pray_spheremap") || bad_pair(c, north, zero, "spheremap")) return NULL;
    pray_object *o = pray_sphere(c, m, centre, r);
    if (o && !obj_map(c, o, MAP_SPHERE, north, zero, 0)) {
        release_handle(c, o);
        return NULL;
    }
    return o;
}

pray_texture *pray_texture_file(pray_ctx *c, const char *path) {
    if (!c || !path || !*path) {
        if (c) fail(c, PRAY_ERR_ARG, "pray_texture_file: no file name");
        return NULL;
    }
    return texture_file(c, "", 0, path, FIND_AS_NAMED);
}

pray_texture *pray_texture_tiff(pray_ctx *c, const void *data, size_t n, const char *name) {
    if (!c) return NULL;
    if (!data) return fail(c, PRAY_ERR_ARG, "pray_texture_tiff: no data"), (pray_texture *)NULL;
    return texture_make(c, name ? name : "texture", (const unsigned char *)data, n);
}

pray_texture *pray_texture_rgb(pray_ctx *c, int w, int h, const float *rgb, const char *name) {
    if (!c) return NULL;
    if (!rgb) return fail(c, PRAY_ERR_ARG, "pray_texture_rgb: no pixels"), (pray_texture *)NULL;
    if (w < 1 || h < 1 || w > 65536 || h > 65536) {
        fail(c, PRAY_ERR_ARG, "pray_texture_rgb: image size %d x %d is out of range (1 to 65536 a side)", w, h);
        return NULL;
    }
    size_t n = (size_t)w * (size_t)h * 3;
    if ((double)n * sizeof(float) > c->cur.opt.v[OPT_TEXMEM] * 1048576.0) {
        fail(c, PRAY_ERR_LIMIT, "pray_texture_rgb: a %d x %d texture is over the texture memory limit (option texmem)",
             w, h);
        return NULL;
    }
    for (size_t i = 0; i < n; i++)
        if (!(rgb[i] >= 0 && rgb[i] <= 1)) {
            fail(c, PRAY_ERR_ARG, "pray_texture_rgb: value %lu (pixel %lu, %lu) is %g, not in 0 .. 1",
                 (unsigned long)(i % 3), (unsigned long)(i / 3 % (size_t)w), (unsigned long)(i / 3 / (size_t)w),
                 (double)rgb[i]);
            return NULL;
        }
    pray_texture *t = (pray_texture *)handle_new(c, sizeof(pray_texture), H_TEXTURE);
    float *px = t ? (float *)mem_alloc(c, n * sizeof(float)) : NULL;
    if (!name) name = "texture";
    char *nm = px ? mem_strdup(c, name, strlen(name)) : NULL;
    if (!nm) {
        mem_free(c, px);
        mem_free(c, t);
        return NULL;
    }
    memcpy(px, rgb, n * sizeof(float));
    t->w = w;
    t->hgt = h;
    t->rgb = px;
    t->name = nm;
    return t;
}

pray_status pray_texture_register(pray_ctx *c, const char *name, pray_texture *t) {
    if (!c) return PRAY_ERR_ARG;
    if (!name || !*name) return fail(c, PRAY_ERR_ARG, "pray_texture_register: no name");
    if (t && !handle_ok(c, t, H_TEXTURE, "pray_texture_register", "texture")) return c->status;
    TexName **at = name_at(&c->tex_names, name), *e = *at;
    if (!e && t && !(e = name_add(c, at, name))) return c->status;
    if (!e) return PRAY_OK;  // removing a name that is not registered
    retain(t);
    release_handle(c, e->tex);
    e->tex = t;
    if (!t) name_drop(c, at);
    return PRAY_OK;
}

pray_status pray_include_register(pray_ctx *c, const char *name, const char *text, size_t len) {
    if (!c) return PRAY_ERR_ARG;
    if (!name || !*name) return fail(c, PRAY_ERR_ARG, "pray_include_register: no name");
    TexName **at = name_at(&c->inc_names, name), *e = *at;
    char *copy = text ? mem_strdup(c, text, len) : NULL;
    if ((text && !copy) || (!e && text && !(e = name_add(c, at, name)))) return mem_free(c, copy), c->status;
    if (!e) return PRAY_OK;
    mem_free(c, e->text);
    e->text = copy;
    e->len = len;
    if (!text) name_drop(c, at);
    return PRAY_OK;
}

void pray_texture_size(const pray_texture *t, int *w, int *h) {
    if (w) *w = t ? t->w : 0;
    if (h) *h = t ? t->hgt : 0;
}

pray_rgb pray_texture_pixel(const pray_texture *t, int x, int y) {
    if (!t || x < 0 || y < 0 || x >= t->w || y >= t->hgt) return cmake(0, 0, 0);
    const float *p = t->rgb + ((size_t)y * t->w + x) * 3;
    return cmake(p[0], p[1], p[2]);
}

pray_model *pray_tiff(pray_ctx *c, pray_model *m0, pray_model *m1, pray_texture *t) {
    if (!c || !model_ok(c, m0, "pray_tiff", "model m0") || !model_ok(c, m1, "pray_tiff", "model m1") ||
        !handle_ok(c, t, H_TEXTURE, "pray_tiff", "texture"))
        return NULL;
    pray_model *m = model_node(c, M_TEX, m0, m1);
    if (m) {
        m->tex = t;
        retain(t);
    }
    return m;
}

pray_model *pray_tiffbump(pray_ctx *c, pray_model *a, double amount, pray_texture *t) {
    if (!c || !model_ok(c, a, "pray_tiffbump") || !handle_ok(c, t, H_TEXTURE, "pray_tiffbump", "texture")) return NULL;
    if (!finite_num(amount)) return fail(c, PRAY_ERR_ARG, "tiffbump: the amount is not finite"), (pray_model *)NULL;
    pray_model *m = model_node(c, M_BUMP, a, NULL);
    if (m) {
        m->tex = t;
        m->amount = amount;
        retain(t);
    }
    return m;
}

pray_model *pray_move(pray_ctx *c, pray_model *a, double x, double y) {
    if (!c || !model_ok(c, a, "pray_move")) return NULL;
    if (!finite_num(x) || !finite_num(y))
        return fail(c, PRAY_ERR_ARG, "move: the shift is not finite"), (pray_model *)NULL;
    if (a->kind == M_FLAT) return retain(a), a;  // no texture to move
    pray_model *m = model_node(c, M_MOVE, a, NULL, fabs(x) > fabs(y) ? fabs(x) : fabs(y));
    if (m) {
        m->dx = x;
        m->dy = y;
    }
    return m;
}

namespace {
// The half-space through q with outward normal n, as part of a glyph box.
pray_object *glyph_face(pray_ctx *c, pray_model *m, pray_vec q, pray_vec n) { return pray_plane(c, m, q, n); }

// Ink of a glyph pixel: the built-in font, or a 16 x 16 atlas texture (ink dark).
bool glyph_ink(const pray_texture *font, int code, int row, int col, int cw, int ch) {
    if (!font) return col < 5 && (FONT6X9[code - 32][row] >> (4 - col) & 1) != 0;
    int x = (code % 16) * cw + col, y = (code / 16) * ch + row;
    const float *p = font->rgb + ((size_t)y * font->w + x) * 3;
    return 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2] < 0.5;
}
} // namespace

pray_object *pray_text(pray_ctx *c, pray_model *m, const char *text, pray_vec P, pray_vec X, pray_vec Y, double h,
                       pray_texture *font, double spacing) {
    if (!c || !model_ok(c, m, "pray_text") || (font && !handle_ok(c, font, H_TEXTURE, "pray_text", "font")))
        return NULL;
    if (!text) return fail(c, PRAY_ERR_ARG, "pray_text: no text"), (pray_object *)NULL;
    if (bad_vec(c, P, "text", false) || bad_pair(c, X, Y, "text")) return NULL;
    if (!finite_num(h) || h <= 0)
        return fail(c, PRAY_ERR_ARG, "text: the thickness must be a positive number, not %g", h), (pray_object *)NULL;
    if (!finite_num(spacing) || spacing <= 0)
        return fail(c, PRAY_ERR_ARG, "text: the spacing must be a positive number, not %g", spacing), (pray_object *)NULL;
    int cw = 6, ch = 9, ref = 7;  // cell columns and rows; rows of the glyph height Y
    if (font) {
        cw = font->w / 16;
        ch = font->hgt / 16;
        ref = ch;
        if (cw < 1 || ch < 1)
            return fail(c, PRAY_ERR_ARG, "text: the font image %s is smaller than 16 x 16 cells", font->name), (pray_object *)NULL;
        if (cw > 64 || ch > 64)
            return fail(c, PRAY_ERR_LIMIT, "text: the font's cells are over 64 pixels"), (pray_object *)NULL;
    }
    pray_vec n = vunit(vcross(vunit(X), vunit(Y)));
    pray_vec nx = vunit(vcross(vunit(Y), n)), ny = vunit(vcross(n, vunit(X)));
    pray_vec back = vmul(n, -1), front = n, left = vmul(nx, -1), down = vmul(ny, -1);
    pray_object *all = pray_nothing(c);
    unsigned char used[64][64];
    int k = 0;
    for (const unsigned char *p = (const unsigned char *)text; all && *p; k++) {
        int code = *p;
        if (code < 0x80) p++;
        else {  // one '?' for a multi-byte character
            code = '?';
            p++;
            while ((*p & 0xC0) == 0x80) p++;
        }
        if (code < 32 || code > 126) code = '?';
        if (code == ' ' && !font) continue;
        pray_vec origin = vadd(P, vmul(X, k * spacing));
        if (!vfinite(origin)) {  // finite arguments, but too far: say which one, not "plane"
            fail(c, PRAY_ERR_ARG, "text: X times the spacing %g takes character %d out of the range of numbers", spacing,
                 k + 1);
            release_handle(c, all);
            return NULL;
        }
        memset(used, 0, sizeof used);
        for (int r = 0; all && r < ch; r++)
            for (int col = 0; all && col < cw; col++) {
                if (used[r][col] || !glyph_ink(font, code, r, col, cw, ch)) continue;
                // the largest rectangle from here: right along the row, then down while full
                int c1 = col;
                while (c1 + 1 < cw && !used[r][c1 + 1] && glyph_ink(font, code, r, c1 + 1, cw, ch)) c1++;
                int r1 = r;
                for (bool full = true; full && r1 + 1 < ch;) {
                    for (int q = col; q <= c1 && full; q++)
                        full = !used[r1 + 1][q] && glyph_ink(font, code, r1 + 1, q, cw, ch);
                    if (full) r1++;
                }
                for (int rr = r; rr <= r1; rr++)
                    for (int q = col; q <= c1; q++) used[rr][q] = 1;
                double x0 = (double)col / cw, x1 = (double)(c1 + 1) / cw;
                double y0 = (double)(ref - 1 - r1) / ref, y1 = (double)(ref - r) / ref;
                pray_vec a = vadd(origin, vadd(vmul(X, x0), vmul(Y, y0)));
                pray_vec b = vadd(origin, vadd(vmul(X, x1), vmul(Y, y1))), top = vadd(a, vmul(n, h));
                if (!vfinite(a) || !vfinite(b) || !vfinite(top)) {
                    char what[64];
                    if (vfinite(a) && vfinite(b)) snprintf(what, sizeof what, "the thickness %g takes", h);
                    else snprintf(what, sizeof what, "X and Y take");
                    fail(c, PRAY_ERR_ARG, "text: %s character %d out of the range of numbers", what, k + 1);
                    release_handle(c, all);
                    return NULL;
                }
                pray_object *box = glyph_face(c, m, a, left);
                pray_object *parts[5] = {glyph_face(c, m, b, nx), glyph_face(c, m, a, down), glyph_face(c, m, b, ny),
                                         glyph_face(c, m, a, back), glyph_face(c, m, top, front)};
                for (int i = 0; i < 5; i++) {
                    pray_object *x = pray_csg(c, PRAY_INTERSECTION, box, parts[i]);
                    release_handle(c, box);
                    release_handle(c, parts[i]);
                    box = x;
                }
                pray_object *u = pray_csg(c, PRAY_UNION, all, box);
                release_handle(c, all);
                release_handle(c, box);
                all = u;
            }
    }
    return all;
}
pray_object *pray_nothing(pray_ctx *c) { return c ? obj_new(c, O_NOTHING, NULL) : NULL; }

pray_object *pray_csg(pray_ctx *c, pray_op op, pray_object *a, pray_object *b) {
    if (!c || !object_ok(c, a, "pray_csg", "object a") || !object_ok(c, b, "pray_csg", "object b")) return NULL;
    int k = op == PRAY_UNION ? O_UNION : op == PRAY_INTERSECTION ? O_INTER : op == PRAY_DIFFERENCE ? O_DIFF : -1;
    if (k < 0) return fail(c, PRAY_ERR_ARG, "unknown CSG operation %d", (int)op), (pray_object *)NULL;
    return csg_op(c, k, a, b);
}

pray_object *pray_complement(pray_ctx *c, pray_object *a) {
    return c && object_ok(c, a, "pray_complement") ? complement_of(c, a) : NULL;
}

pray_object *pray_scale(pray_ctx *c, pray_object *a, double s) {
    if (!c || !object_ok(c, a, "pray_scale")) return NULL;
    if (!finite_num(s) || s == 0)
        return fail(c, PRAY_ERR_ARG, "scale factor must be a finite number other than 0, not %g", s), (pray_object *)NULL;
    return obj_transform(c, a, xf_scale(s));
}
pray_object *pray_translate(pray_ctx *c, pray_object *a, pray_vec v) {
    if (!c || !object_ok(c, a, "pray_translate") || bad_vec(c, v, "translation", false)) return NULL;
    return obj_transform(c, a, xf_translate(v));
}
pray_object *pray_rotate(pray_ctx *c, pray_object *a, pray_vec deg) {
    if (!c || !object_ok(c, a, "pray_rotate") || bad_vec(c, deg, "rotation", false)) return NULL;
    return obj_transform(c, a, xf_rotate(deg));
}
pray_object *pray_stretch(pray_ctx *c, pray_object *a, pray_vec v) {
    if (!c || !object_ok(c, a, "pray_stretch") || bad_vec(c, v, "stretch", false)) return NULL;
    if (v.x == 0 || v.y == 0 || v.z == 0)
        return fail(c, PRAY_ERR_ARG, "stretch: the factors must not be 0, not <%g, %g, %g>", v.x, v.y, v.z), (pray_object *)NULL;
    return obj_stretch(c, a, v);
}
pray_object *pray_paint(pray_ctx *c, pray_object *a, pray_model *m) {
    if (!c || !object_ok(c, a, "pray_paint") || !model_ok(c, m, "pray_paint")) return NULL;
    return obj_paint(c, a, m);
}
pray_model *pray_checker(pray_ctx *c, pray_model *m0, pray_model *m1, double s) {
    if (!c || !model_ok(c, m0, "pray_checker", "model m0") || !model_ok(c, m1, "pray_checker", "model m1")) return NULL;
    if (!(finite_num(s) && s > 0)) {
        fail(c, PRAY_ERR_ARG, "checker: the size of a cell must be a number > 0, not %g", nan_clean(s));
        return NULL;
    }
    pray_model *m = model_node(c, M_CHECK, m0, m1);
    if (m) m->amount = s;
    return m;
}
int pray_object_primitives(const pray_object *a) {
    return a ? (a->nprims > INT_MAX ? INT_MAX : (int)a->nprims) : 0;
}

pray_light *pray_dirlight(pray_ctx *c, pray_rgb i, pray_vec d) {
    if (!c || bad_rgb(c, i, "dirlight") || bad_vec(c, d, "dirlight direction", true)) return NULL;
    pray_light *l = light_new(c, 1);
    if (!l) return NULL;
    l->src[0].point = 0;
    l->src[0].intensity = i;
    l->src[0].v = d;
    return l;
}
pray_light *pray_pointlight(pray_ctx *c, pray_rgb i, pray_vec p) {
    if (!c || bad_rgb(c, i, "pointlight") || bad_vec(c, p, "pointlight", false)) return NULL;
    pray_light *l = light_new(c, 1);
    if (!l) return NULL;
    l->src[0].point = 1;
    l->src[0].intensity = i;
    l->src[0].v = p;
    return l;
}
pray_light *pray_spotlight(pray_ctx *c, pray_rgb i, pray_vec p, pray_vec d, double a1, double a2) {
    if (!c) return NULL;
    if (bad_rgb(c, i, "spotlight") || bad_vec(c, p, "spotlight", false) || bad_vec(c, d, "spotlight direction", true))
        return NULL;
    if (!(a1 >= 0 && a1 <= a2 && a2 < 180)) {
        fail(c, PRAY_ERR_ARG, "spotlight: the angles must be 0 <= a1 <= a2 < 180 degrees, not %g and %g", nan_clean(a1),
             nan_clean(a2));
        return NULL;
    }
    pray_light *l = pray_pointlight(c, i, p);
    if (!l) return NULL;
    l->src[0].spot = 1;
    l->src[0].d = d;
    l->src[0].a1 = a1;
    l->src[0].a2 = a2;
    return l;
}
pray_light *pray_light_add(pray_ctx *c, pray_light *a, pray_light *b) {
    if (!c || !light_ok(c, a, "pray_light_add", "light a") || !light_ok(c, b, "pray_light_add", "light b")) return NULL;
    return light_union(c, a, b);
}
pray_light *pray_light_scale(pray_ctx *c, pray_light *l, double s) {
    if (!c || !light_ok(c, l, "pray_light_scale")) return NULL;
    if (!finite_num(s) || s == 0)
        return fail(c, PRAY_ERR_ARG, "scale factor must be a finite number other than 0, not %g", s), (pray_light *)NULL;
    return light_transform(c, l, xf_scale(s));
}
pray_light *pray_light_translate(pray_ctx *c, pray_light *l, pray_vec v) {
    if (!c || !light_ok(c, l, "pray_light_translate") || bad_vec(c, v, "translation", false)) return NULL;
    return light_transform(c, l, xf_translate(v));
}
pray_light *pray_light_rotate(pray_ctx *c, pray_light *l, pray_vec deg) {
    if (!c || !light_ok(c, l, "pray_light_rotate") || bad_vec(c, deg, "rotation", false)) return NULL;
    return light_transform(c, l, xf_rotate(deg));
}

// Releases: NULL is ignored; a handle of the wrong kind or of another context is refused with a
// message and left alone.
void pray_release(pray_ctx *c, void *h) {
    if (c && h && handle_ok(c, h, 0, "pray_release", "handle")) release_handle(c, h);
}
void pray_object_release(pray_ctx *c, pray_object *o) {
    if (c && o && object_ok(c, o, "pray_object_release")) release_handle(c, o);
}
void pray_model_release(pray_ctx *c, pray_model *m) {
    if (c && m && model_ok(c, m, "pray_model_release")) release_handle(c, m);
}
void pray_light_release(pray_ctx *c, pray_light *l) {
    if (c && l && light_ok(c, l, "pray_light_release")) release_handle(c, l);
}
void pray_texture_release(pray_ctx *c, pray_texture *t) {
    if (c && t && handle_ok(c, t, H_TEXTURE, "pray_texture_release", "texture")) release_handle(c, t);
}
pray_status pray_retain(pray_ctx *c, void *h) {
    if (!c) return PRAY_ERR_ARG;
    if (!h) return fail(c, PRAY_ERR_ARG, "pray_retain: no handle");
    if (!handle_ok(c, h, 0, "pray_retain", "handle")) return c->status;
    retain(h);
    return PRAY_OK;
}

namespace {
// What is wrong with a camera, or NULL.
const char *camera_problem(bool parallel, pray_vec x, pray_vec y, pray_vec e, pray_vec p) {
    if (!vfinite(x) || !vfinite(y) || !vfinite(e) || !vfinite(p)) return "coordinates are not finite";
    if (vmaxabs(x) == 0 || vmaxabs(y) == 0) return "X and Y must not be zero vectors";
    pray_vec cr = vcross(vunit(x), vunit(y));
    if (vlen(cr) <= 1e-12) return "X and Y must not be parallel";
    pray_vec v = vsub(p, e);
    if (vmaxabs(v) == 0) return "the eye and the point looked at must differ";
    if (parallel && fabs(vdot(vunit(cr), vunit(v))) <= 1e-12)
        return "the view direction must not lie in the plane of X and Y";
    return NULL;
}

pray_status set_camera(pray_ctx *c, int parallel, pray_vec x, pray_vec y, pray_vec e, pray_vec p) {
    const char *why = camera_problem(parallel != 0, x, y, e, p);
    if (why) return fail(c, PRAY_ERR_ARG, "%s: %s", parallel ? "parallel" : "perspective", why);
    c->cur.parallel = parallel;
    c->cur.lookat = 0;
    c->cur.cam_x = x;
    c->cur.cam_y = y;
    c->cur.cam_eye = e;
    c->cur.cam_point = p;
    if (!c->running) c->base = c->cur;
    return PRAY_OK;
}
} // namespace

pray_status pray_lookat(pray_ctx *c, pray_vec e, pray_vec p, pray_vec up, double angle) {
    if (!c) return PRAY_ERR_ARG;
    const char *why = NULL;
    pray_vec d = vsub(p, e);
    if (!vfinite(e) || !vfinite(p) || !vfinite(up) || !vfinite(d) || !finite_num(angle))
        why = "coordinates are not finite";
    else if (vmaxabs(d) == 0) why = "the eye and the point looked at must differ";
    else if (vmaxabs(up) == 0) why = "the up direction U must not be a zero vector";
    else if (vlen(vcross(vunit(d), vunit(up))) <= 1e-12) why = "the up direction U must not be parallel to P - E";
    else if (!(angle > 0 && angle < 180)) return fail(c, PRAY_ERR_ARG, "lookat: the angle %g must lie between 0 and 180 degrees", angle);
    if (why) return fail(c, PRAY_ERR_ARG, "lookat: %s", why);
    c->cur.parallel = 0;
    c->cur.lookat = 1;
    c->cur.cam_eye = e;
    c->cur.cam_point = p;
    c->cur.cam_up = up;
    c->cur.cam_angle = angle;
    camera_axes(c, &c->cur.cam_x, &c->cur.cam_y);  // (for the size in force now; a render sizes them again)
    if (!c->running) c->base = c->cur;
    return PRAY_OK;
}

pray_status pray_perspective(pray_ctx *c, pray_vec x, pray_vec y, pray_vec e, pray_vec p) {
    if (!c) return PRAY_ERR_ARG;
    return set_camera(c, 0, x, y, e, p);
}
pray_status pray_parallel(pray_ctx *c, pray_vec x, pray_vec y, pray_vec e, pray_vec p) {
    if (!c) return PRAY_ERR_ARG;
    return set_camera(c, 1, x, y, e, p);
}
pray_status pray_background(pray_ctx *c, pray_rgb top, pray_rgb bottom) {
    if (!c) return PRAY_ERR_ARG;
    if (bad_rgb(c, top, "background") || bad_rgb(c, bottom, "background")) return c->status;
    c->cur.bg_top = top;
    c->cur.bg_bottom = bottom;
    if (!c->running) c->base = c->cur;
    return PRAY_OK;
}

namespace {
// The image of the context's options may be rendered (its size and samples within the limits).
pray_status image_limits(pray_ctx *c) {
    int W = opt_int(c, OPT_WIDTH), H = opt_int(c, OPT_HEIGHT);
    if ((double)W * H > MAX_IMAGE_PIXELS)
        return fail(c, PRAY_ERR_LIMIT, "image of %d x %d pixels is too large", W, H);
    double aa = c->cur.opt.v[OPT_ANTIALIAS], lim = c->cur.opt.v[OPT_MAXPIXELS];
    if ((double)W * H * aa * aa > lim) {
        char how[40] = "";
        if (aa > 1) snprintf(how, sizeof how, " with antialias %.0f", aa);
        return fail(c, PRAY_ERR_LIMIT, "image of %d x %d pixels%s is over the limit of %.0f sample%s (option maxpixels)",
                    W, H, how, lim, lim == 1 ? "" : "s");
    }
    return PRAY_OK;
}

} // namespace
// The scene pray_render_into prepared last outside a program's run (or in a render function),
// for the next render of the same root and lights with the same options, camera and background
// (a host's bands, tiles and passes): it holds a reference to both, so that neither can be freed
// and its address taken by another while it is kept. A render of another scene, the start and
// end of a run, and pray_free drop it.
struct Prepared {
    pray_object *root;
    pray_light *lights;
    Setup setup;
    Scene s;
};
namespace {

void prepared_drop(pray_ctx *c) {
    Prepared *p = c->prep;
    if (!p) return;
    c->prep = NULL;
    scene_release(c, &p->s);
    release_handle(c, p->root);
    if (p->lights) release_handle(c, p->lights);
    mem_free(c, p);
}

// A kept scene whose setup differs from the context's in the camera alone takes the new camera:
// of its preparation only the eye's buffer depends on the camera (on the eye's place and on the
// kind of camera, not on where it looks), so it stays unless those changed; and lists that leave
// out faces between materials (Accel::left_out) stay while no primary ray starts inside the
// solid.
pray_status recamera(pray_ctx *c, Prepared *p) {
    Setup t;
    const Setup &n = c->cur;
    memcpy(&t, &p->setup, sizeof t);
    t.parallel = n.parallel, t.cam_x = n.cam_x, t.cam_y = n.cam_y, t.cam_eye = n.cam_eye, t.cam_point = n.cam_point;
    t.lookat = n.lookat, t.cam_up = n.cam_up, t.cam_angle = n.cam_angle;
    bool eye = p->s.accel && p->s.accel->eye && memcmp(&n.cam_eye, &p->setup.cam_eye, sizeof n.cam_eye) != 0;
    if (memcmp(&t, &n, sizeof t) != 0 || n.parallel != p->setup.parallel || eye) return PRAY_OK;
    scene_camera(c, &p->s);
    int in = p->s.accel && p->s.accel->left_out ? primaries_inside(c, &p->s) : 0;
    if (in < 0) return c->status;
    if (!in) memcpy(&p->setup, &n, sizeof t);  // (else dropped)
    return PRAY_OK;
}

// The one way to render: rectangle r of the image into the buffers (stride set), both checked;
// with the scene kept from the render before when it is the same (Prepared), or differs in the
// camera alone (recamera).
pray_status render_into(pray_ctx *c, pray_object *root, pray_light *lights, const pray_rect &r,
                        const pray_buffers &out) {
    double t0 = clock_seconds();
    mem_phase(c, MEM_RUN);
    Prepared *p = c->prep;
    bool keep = (!c->running || c->in_render_fn) && c->drop != root;
    if (p && keep && p->root == root && p->lights == lights && recamera(c, p)) return c->status;
    if (p && !(keep && p->root == root && p->lights == lights && memcmp(&p->setup, &c->cur, sizeof(Setup)) == 0)) {
        prepared_drop(c);  // (before another is built: the two need not fit at once)
        p = NULL;
    }
    Scene own;
    memset(&own, 0, sizeof own);
    pray_status st = p ? PRAY_OK : scene_build(c, &own, root, lights, true);
    if (!p && st == PRAY_OK && keep) {
        p = (Prepared *)mem_alloc(c, sizeof(Prepared));
        if (!p) st = c->status;
        else {
            p->root = root;
            p->lights = lights;
            memcpy(&p->setup, &c->cur, sizeof(Setup));
            p->s = own;  // (moved)
            memset(&own, 0, sizeof own);
            retain(root);
            if (lights) retain(lights);
            c->prep = p;
        }
    }
    Scene &s = p ? p->s : own;
    double t1 = clock_seconds();
    if (st == PRAY_OK) {
        c->stats.primitives = s.prims.n;
        c->stats.nodes = s.nodes.n;
        // a program's frame of the whole image, in colour only, may take over from the one before
        CohPlan plan;
        memset(&plan, 0, sizeof plan);
#ifndef PRAY_NO_SEQUENCES
        bool coh = !p && opt_int(c, OPT_COHERENCE) && c->running && s.accel && out.rgb && !extra_outputs(out) &&
                   r.x == 0 && r.y == 0 && r.width == s.width && r.height == s.height &&
                   out.stride == (size_t)s.width;
        if (coh) st = coh_plan(c, &s, &plan);
        else coh_release(c);
        if (st == PRAY_OK) st = render_scene(c, &s, r, out, &plan);
        mem_free(c, plan.redo);
        if (st == PRAY_OK && coh) st = coh_keep(c, &s, out.rgb, &plan);
        if (st != PRAY_OK || !coh) coh_release(c);
#else
        coh_release(c);  // (nothing to release)
        st = render_scene(c, &s, r, out, &plan);
#endif
    }
    c->stats.time_prepare += t1 - t0;
    c->stats.time_render += clock_seconds() - t1;
    scene_release(c, &own);
    mem_phase(c, st == PRAY_OK ? MEM_RENDER : MEM_PREPARE);  // (what the scene held is counted)
    return st;
}
// What pray_render and pray_render_into check of the scene.
bool scene_ok(pray_ctx *c, pray_object *root, pray_light *lights, const char *fn) {
    if (!root) {
        if (c->status == PRAY_OK) fail(c, PRAY_ERR_ARG, "no object to render");
        return false;
    }
    return object_ok(c, root, fn, "object") && (!lights || light_ok(c, lights, fn, "light"));
}
} // namespace

// pray_render's work, between call_enter and call_leave
static pray_status render_call(pray_ctx *c, pray_object *root, pray_light *lights, pray_image *out) {
    if (!out) return fail(c, PRAY_ERR_ARG, "pray_render: no image to render into");
    if (c->render_fn && c->running && !c->in_render_fn) {  // a program's frame, rendered by the host
        c->in_render_fn = 1;
        pray_status st = c->render_fn(c->render_ud, c, root, lights, c->frames, out);
        c->in_render_fn = 0;
        if (st == PRAY_OK && !out->pixels && out->width == 0 && out->height == 0) return PRAY_OK;  // skipped
        if (st == PRAY_OK) {
            // the frame must be an image of this context, as pray_render or pray_image_new make
            // them: its pixels are freed with it (a host's buffer, or another context's, is not)
            size_t need = out->width > 0 && out->height > 0 ? sizeof(float) * 3 * (size_t)out->width * (size_t)out->height : 0;
            if (out->pixels && need && owner_of(out->pixels) == c && ((const Block *)out->pixels - 1)->size >= need)
                return PRAY_OK;
            out->width = out->height = 0;
            out->pixels = NULL;
            return fail(c, PRAY_ERR_ARG, "the render function gave an image that is not one of this context's "
                        "(pray_render, pray_image_new)");
        }
        pray_image_free(c, out);
        if (c->status == PRAY_OK || !c->msg[0]) fail(c, st, "the render function failed");
        return c->status = st;
    }
    if (!scene_ok(c, root, lights, "pray_render") || image_limits(c)) return c->status;
    int W = opt_int(c, OPT_WIDTH), H = opt_int(c, OPT_HEIGHT);
    pray_rect r = {0, 0, W, H};
    pray_buffers b = {NULL, NULL, NULL, NULL, (size_t)W, NULL, NULL, 0};
    b.rgb = (float *)mem_alloc(c, sizeof(float) * 3 * (size_t)W * (size_t)H);  // (every pixel is written)
    if (!b.rgb) return c->status;
    out->pixels = b.rgb;
    out->width = W;
    out->height = H;
    pray_status st = render_into(c, root, lights, r, b);
    if (st != PRAY_OK) pray_image_free(c, out);
    return st;
}

pray_status pray_render(pray_ctx *c, pray_object *root, pray_light *lights, pray_image *out) {
    if (out) {
        out->width = out->height = 0;
        out->pixels = NULL;
    }
    if (!c) return PRAY_ERR_ARG;
    call_enter(c);
    pray_status r = render_call(c, root, lights, out);
    call_leave(c);
    return r;
}

// The rectangle (NULL: the whole W x H image) and the buffers of pray_render_into and
// pray_render_prepared (fn), checked, into *r and *b (the stride set).
static pray_status render_target(pray_ctx *c, const char *fn, int W, int H, const pray_rect *rect,
                                 const pray_buffers *out, pray_rect *r, pray_buffers *b) {
    pray_rect all = {0, 0, W, H};
    *r = rect ? *rect : all;
    if (r->width < 1 || r->height < 1 || r->x < 0 || r->y < 0 || r->x > W - r->width || r->y > H - r->height)
        return fail(c, PRAY_ERR_ARG, "%s: the rectangle of %d x %d pixels at (%d, %d) is not inside the image of %d x %d",
                    fn, r->width, r->height, r->x, r->y, W, H);
    *b = *out;
    if (b->flags & ~PRAY_BUFFERS_SAMPLES) return fail(c, PRAY_ERR_ARG, "%s: unknown flags %#x", fn, (unsigned)b->flags);
    if (b->stride == 0) b->stride = (size_t)r->width;
    if (b->stride < (size_t)r->width)
        return fail(c, PRAY_ERR_ARG, "%s: the stride %lu is less than the rectangle's width %d", fn,
                    (unsigned long)b->stride, r->width);
    if (b->stride > (size_t)-1 / 3 / (size_t)r->height)
        return fail(c, PRAY_ERR_ARG, "%s: the stride %lu is too large", fn, (unsigned long)b->stride);
    return PRAY_OK;
}

// pray_render_into's work, between call_enter and call_leave
static pray_status render_into_call(pray_ctx *c, pray_object *root, pray_light *lights, const pray_rect *rect,
                                    const pray_buffers *out) {
    if (!out) return fail(c, PRAY_ERR_ARG, "pray_render_into: no buffers");
    if (!out->rgb && !extra_outputs(*out)) return fail(c, PRAY_ERR_ARG, "pray_render_into: every buffer is NULL");
    if (!scene_ok(c, root, lights, "pray_render_into") || image_limits(c)) return c->status;
    pray_rect r;
    pray_buffers b;
    if (render_target(c, "pray_render_into", opt_int(c, OPT_WIDTH), opt_int(c, OPT_HEIGHT), rect, out, &r, &b))
        return c->status;
    return render_into(c, root, lights, r, b);
}

pray_status pray_render_into(pray_ctx *c, pray_object *root, pray_light *lights, const pray_rect *rect,
                             const pray_buffers *out) {
    if (!c) return PRAY_ERR_ARG;
    call_enter(c);
    pray_status r = render_into_call(c, root, lights, rect, out);
    call_leave(c);
    return r;
}

pray_status pray_camera_ray(pray_ctx *c, double px, double py, pray_vec *origin, pray_vec *dir) {
    if (!c) return PRAY_ERR_ARG;
    if (!origin || !dir) return fail(c, PRAY_ERR_ARG, "pray_camera_ray: no place for the ray");
    if (!finite_num(px) || !finite_num(py)) return fail(c, PRAY_ERR_ARG, "pray_camera_ray: the point is not finite");
    Scene s;
    memset(&s, 0, sizeof s);
    scene_camera(c, &s);
    Ray r = image_ray(&s, px, py);
    *origin = vmake((double)r.o.x, (double)r.o.y, (double)r.o.z);
    *dir = vmake((double)r.d.x, (double)r.d.y, (double)r.d.z);
    return PRAY_OK;
}

void pray_stats_get(const pray_ctx *c, pray_stats *out) {
    if (!out) return;
    if (c) *out = c->stats;
    else memset(out, 0, sizeof *out);
}
void pray_stats_reset(pray_ctx *c) {
    if (c) memset(&c->stats, 0, sizeof c->stats);
}
pray_status pray_object_set_id(pray_ctx *c, pray_object *o, int id) {
    if (!c || !object_ok(c, o, "pray_object_set_id")) return c ? c->status : PRAY_ERR_ARG;
    if (id < 0 && id != PRAY_NO_ID)
        return fail(c, PRAY_ERR_ARG, "pray_object_set_id: an id must be >= 0 or PRAY_NO_ID, not %d", id);
    o->uid = id;
    prepared_drop(c);  // (the scene kept holds the ids it was prepared with)
    return PRAY_OK;
}
int pray_object_id(const pray_object *o) { return o ? o->uid : PRAY_NO_ID; }

struct pray_scene {
    Scene s;
    Scratch w;    // pray_intersect's
    int render;   // prepared for rendering (pray_prepare_render)
    Accel *all;   // pray_intersect's lists, where the render's leave faces out (Accel::left_out)
};

// pray_prepare's and pray_prepare_render's work, between call_enter and call_leave
static pray_scene *prepare_call(pray_ctx *c, pray_object *root, pray_light *lights, bool render) {
    pray_scene *q = (pray_scene *)mem_zalloc(c, sizeof(pray_scene));
    if (!q) return NULL;
    q->render = render;
    if (scene_build(c, &q->s, root, lights, render) || !scratch_init(c, &q->w, &q->s)) {
        pray_scene_free(c, q);
        return NULL;
    }
    return q;
}

pray_scene *pray_prepare_render(pray_ctx *c, pray_object *root, pray_light *lights) {
    if (!c || !scene_ok(c, root, lights, "pray_prepare_render") || image_limits(c)) return NULL;
    call_enter(c);
    pray_scene *r = prepare_call(c, root, lights, true);
    call_leave(c);
    return r;
}

// pray_render_prepared's work, between call_enter and call_leave
static pray_status render_prepared_call(pray_ctx *c, const pray_scene *q, const pray_rect *rect,
                                        const pray_buffers *out) {
    if (!q) return c->status != PRAY_OK ? c->status : fail(c, PRAY_ERR_ARG, "pray_render_prepared: no scene");
    if (!q->render)
        return fail(c, PRAY_ERR_ARG, "pray_render_prepared: the scene was prepared for ray queries (pray_prepare)");
    if (!out || (!out->rgb && !extra_outputs(*out))) return fail(c, PRAY_ERR_ARG, "pray_render_prepared: no buffers");
    pray_rect r;
    pray_buffers b;
    if (render_target(c, "pray_render_prepared", q->s.width, q->s.height, rect, out, &r, &b)) return c->status;
    double t0 = clock_seconds();
    CohPlan none;
    memset(&none, 0, sizeof none);
    c->stats.primitives = q->s.prims.n;
    c->stats.nodes = q->s.nodes.n;
    pray_status st = render_scene(c, &q->s, r, b, &none);
    c->stats.time_render += clock_seconds() - t0;
    return st;
}

pray_status pray_render_prepared(pray_ctx *c, const pray_scene *scene, const pray_rect *rect,
                                 const pray_buffers *out) {
    if (!c) return PRAY_ERR_ARG;
    call_enter(c);
    pray_status r = render_prepared_call(c, scene, rect, out);
    call_leave(c);
    return r;
}

pray_scene *pray_prepare(pray_ctx *c, pray_object *root) {
    if (!c || !object_ok(c, root, "pray_prepare")) return NULL;
    call_enter(c);
    pray_scene *r = prepare_call(c, root, NULL, false);
    call_leave(c);
    return r;
}

namespace {
struct CollectHits {
    const Scene *s;
    Ray ray;
    pray_hit *out;
    int max, n;
    bool operator()(const Hit &h) {
        if (n < max) public_hit(s, ray, h, &out[n]);
        n++;
        return true;
    }
};
} // namespace

int pray_intersect(pray_ctx *c, pray_scene *q, pray_vec origin, pray_vec dir, double tmax, pray_hit *hits,
                   int max_hits) {
    if (!c) return -1;
    if (!q) {  // (the chain rule, as for handles)
        if (c->status == PRAY_OK) fail(c, PRAY_ERR_ARG, "pray_intersect: no scene");
        return -1;
    }
    if (owner_of(q) != c) return fail(c, PRAY_ERR_ARG, "pray_intersect: the scene belongs to another context"), -1;
    if (max_hits > 0 && !hits) return fail(c, PRAY_ERR_ARG, "pray_intersect: no room for the hits"), -1;
    // the direction brought to the size of 1: a tiny or a huge one is a direction too
    double m = fabs(dir.x) > fabs(dir.y) ? fabs(dir.x) : fabs(dir.y);
    m = fabs(dir.z) > m ? fabs(dir.z) : m;
    if (!vfinite(origin) || !vfinite(dir) || m == 0 || tmax != tmax)
        return fail(c, PRAY_ERR_ARG, "pray_intersect: the ray must have a finite origin and a finite, non-zero direction"), -1;
    int e = 0;  // (a direction of ordinary size is left as it is, bit for bit)
    if (m < 1e-18 || m > 1e18) frexp(m, &e);
    pray_vec d = {ldexp(dir.x, -e), ldexp(dir.y, -e), ldexp(dir.z, -e)};
    CollectHits ch;
    ch.s = &q->s;
    ch.ray.o = r3of(origin);
    ch.ray.d = unit(r3of(d));
    ch.out = hits;
    ch.max = max_hits;
    ch.n = 0;
    real t = tmax >= HUGE_VAL ? REAL_INF : (real)tmax;
    const Scene *s = &q->s;
    Scene all;  // (the scene with lists of every face: built at the first query that needs them)
    if (q->s.accel && q->s.accel->left_out) {
        memcpy(&all, &q->s, sizeof all);
        all.accel = q->all;
        if (!q->all && accel_build(c, &all, false)) {
            accel_release(c, all.accel);
            return -1;
        }
        q->all = all.accel;
        s = &all;
    }
    find_hits(s, &q->w, ch.ray, t, -1, ch);
    return ch.n;
}

void pray_scene_free(pray_ctx *c, pray_scene *q) {
    if (!c || !q) return;
    if (owner_of(q) != c) {
        fail(c, PRAY_ERR_ARG, "pray_scene_free: the scene belongs to another context");
        return;
    }
    scratch_release(c, &q->w);
    scene_release(c, &q->s);
    accel_release(c, q->all);
    mem_free(c, q);
}

void pray_image_free(pray_ctx *c, pray_image *img) {
    if (!c || !img) return;
    if (img->pixels && owner_of(img->pixels) != c) {
        fail(c, PRAY_ERR_ARG, "pray_image_free: the image belongs to another context");
        return;
    }
    mem_free(c, img->pixels);
    img->pixels = NULL;
    img->width = img->height = 0;
}

// pray_write_tiff, pray_write_ppm and pray_write_png (fmt): an image into a byte sink.
static pray_status write_sink(pray_ctx *c, const pray_image *img, int bits, pray_write_fn fn, void *ud, int fmt) {
    if (!c) return PRAY_ERR_ARG;
    const char *name = fmt == FMT_TIFF ? "pray_write_tiff" : fmt == FMT_PPM ? "pray_write_ppm" : "pray_write_png";
    Sink sink = {fn, ud};
    pray_status st;
    call_enter(c);
    if (!image_ok(c, img)) st = c->status;
    else if (!fn) st = fail(c, PRAY_ERR_ARG, "%s: no write function", name);
    else if (bits != 8 && bits != 16) st = fail(c, PRAY_ERR_ARG, "bits must be 8 or 16");
    else if (fmt == FMT_TIFF) st = write_tiff(c, img, bits, sink);
    else if (fmt == FMT_PPM) st = write_ppm(c, img, bits, sink);
#if PRAY_HAS_PNG
    else st = write_png(c, img, sink);
#else
    else st = fail(c, PRAY_ERR_ARG, "pray_write_png: this pray writes no PNG: " PNG_MISSING);
#endif
    call_leave(c);
    return st;
}
pray_status pray_write_tiff(pray_ctx *c, const pray_image *img, int bits, pray_write_fn fn, void *ud) {
    return write_sink(c, img, bits, fn, ud, FMT_TIFF);
}
pray_status pray_write_ppm(pray_ctx *c, const pray_image *img, int bits, pray_write_fn fn, void *ud) {
    return write_sink(c, img, bits, fn, ud, FMT_PPM);
}
pray_status pray_write_png(pray_ctx *c, const pray_image *img, pray_write_fn fn, void *ud) {
    return write_sink(c, img, 8, fn, ud, FMT_PNG);
}

namespace {
// pray_write_image and pray_write_image_note: the one way files are written.
pray_status write_image_file(pray_ctx *c, const pray_image *img, const char *path, int bits, const char *note) {
    if (!image_ok(c, img)) return c->status;
    if (!path || !*path) return fail(c, PRAY_ERR_ARG, "no file name");
    if (bits != 8 && bits != 16) return fail(c, PRAY_ERR_ARG, "bits must be 8 or 16");
    int fmt = image_format(path);
    if (fmt == FMT_PNG && !PRAY_HAS_PNG)
        return fail(c, PRAY_ERR_ARG, "'%s': this pray writes no PNG: " PNG_MISSING "; use .tif or .ppm", path);
    if (fmt == FMT_NONE)
        return fail(c, PRAY_ERR_ARG, "cannot tell the image format of '%s' (use .tif, .ppm%s)", path,
                    PRAY_HAS_PNG ? " or .png" : "");
    if (fmt == FMT_PNG && bits != 8) return fail(c, PRAY_ERR_ARG, "PNG output has 8 bits only");
    if (note) {
        if (fmt == FMT_PNG)
            return fail(c, PRAY_ERR_ARG, "cannot write a note into '%s': notes go into TIFF and PPM files only",
                        path);
        size_t i = 0;
        for (; note[i]; i++)
            if ((unsigned char)note[i] < 32 || (unsigned char)note[i] > 126 || i >= PRAY_NOTE_MAX) break;
        if (note[i]) return fail(c, PRAY_ERR_ARG, "a note must be printable ASCII of at most %d characters",
                                 PRAY_NOTE_MAX);
    }
#if PRAY_HAS_STDIO
    if (is_program(c, path))
        return fail(c, PRAY_ERR_IO, "cannot write '%s': it is the program being run (choose another output name)",
                    *ShownPath(path));
    if (c->running && is_input(c, path))
        return fail(c, PRAY_ERR_IO, "cannot write '%s': the program reads it (choose another output name)",
                    *ShownPath(path));
    // written under a temporary name, then renamed: the file is whole or not there
    char *tmp = NULL;
    FileSink fs;
    errno = 0;
    fs.f = create_temp(c, path, &tmp);
    if (!fs.f && !tmp) return c->status;
    fs.err = fs.f ? 0 : (errno ? errno : EIO);
    fs.bytes = 0;
    double mib = c->cur.opt.v[OPT_MAXOUTPUT];
    fs.room = mib > 0 ? mib * 1048576.0 - c->written : HUGE_VAL;
    pray_status st = PRAY_OK;
    if (fs.f) {  // (create_temp has named it for pray_temp_file: a signal handler may remove it)
        Sink s = {file_put, &fs};
        st = write_format(c, img, fmt, bits, s, note);
        if (fflush(fs.f) != 0 && !fs.err) fs.err = errno ? errno : EIO;
        if (fclose(fs.f) != 0 && !fs.err) fs.err = errno ? errno : EIO;
        if (st == PRAY_OK && !fs.err && !file_replace(tmp, path)) fs.err = errno ? errno : EIO;
        if (st != PRAY_OK || fs.err) remove(tmp);
        c->temp_name = NULL;
    }
    if (st == PRAY_OK && fs.err == -1)
        st = fail(c, PRAY_ERR_LIMIT, "'%s' would take the images written over %.0f MiB (option maxoutput)",
                  *ShownPath(path), mib);
    else if (st == PRAY_OK && fs.err)
        st = fail(c, PRAY_ERR_IO, "cannot write '%s': %s", *ShownPath(path), strerror(fs.err));
    if (st == PRAY_OK) c->written += fs.bytes;
    mem_free(c, tmp);
    return st;
#else
    return fail(c, PRAY_ERR_IO, "this build has no file access");
#endif
}
} // namespace

// pray_write_image (note NULL, `noted` false) and pray_write_image_note.
static pray_status write_file(pray_ctx *c, const pray_image *img, const char *path, int bits, const char *note,
                              bool noted) {
    if (!c) return PRAY_ERR_ARG;
    call_enter(c);
    pray_status r = noted && !note ? fail(c, PRAY_ERR_ARG, "pray_write_image_note: no note")
                                   : write_image_file(c, img, path, bits, note);
    call_leave(c);
    return r;
}
pray_status pray_write_image(pray_ctx *c, const pray_image *img, const char *path, int bits) {
    return write_file(c, img, path, bits, NULL, false);
}
pray_status pray_write_image_note(pray_ctx *c, const pray_image *img, const char *path, int bits, const char *note) {
    return write_file(c, img, path, bits, note, true);
}

pray_status pray_image_bytes(pray_ctx *c, const pray_image *img, int channels, unsigned char *out) {
    if (!c) return PRAY_ERR_ARG;
    if (!image_ok(c, img)) return c->status;
    bool srgb = channels >= PRAY_BYTES_SRGB;
    channels -= srgb ? PRAY_BYTES_SRGB : 0;
    if ((channels != 3 && channels != 4) || !out)
        return fail(c, PRAY_ERR_ARG, "pray_image_bytes: %s", out ? "channels must be 3 or 4 (+ PRAY_BYTES_SRGB)" : "no buffer");
    size_t n = (size_t)img->width * (size_t)img->height;
    for (size_t i = 0; i < n; i++, out += channels) {
        for (int k = 0; k < 3; k++) {
            double v = img->pixels[3 * i + k];
            if (srgb && v > 0 && v < 1) v = v <= 0.0031308 ? 12.92 * v : 1.055 * pow(v, 1 / 2.4) - 0.055;
            out[k] = (unsigned char)quantize(v, 255);
        }
        if (channels == 4) out[3] = 255;
    }
    return PRAY_OK;
}

pray_status pray_image_new(pray_ctx *c, int width, int height, pray_image *out) {
    if (out) {
        out->width = out->height = 0;
        out->pixels = NULL;
    }
    if (!c) return PRAY_ERR_ARG;
    if (!out) return fail(c, PRAY_ERR_ARG, "pray_image_new: no image to make");
    if (width < 1 || height < 1 || width > MAX_IMAGE_SIDE || height > MAX_IMAGE_SIDE ||
        (double)width * height > MAX_IMAGE_PIXELS)
        return fail(c, PRAY_ERR_ARG, "pray_image_new: no image can be %d x %d pixels", width, height);
    float *p = (float *)mem_zalloc(c, sizeof(float) * 3 * (size_t)width * (size_t)height);
    if (!p) return c->status;
    out->pixels = p;
    out->width = width;
    out->height = height;
    return PRAY_OK;
}

pray_status pray_set_error(pray_ctx *c, int code, const char *message) {
    if (!c) return PRAY_ERR_ARG;
    if (code == PRAY_OK) return pray_clear_error(c), PRAY_OK;
    // (an int: in C++ a value outside the enumeration cannot be a pray_status)
    pray_status status = code >= PRAY_ERR_NOMEM && code <= PRAY_ERR_CANCELLED ? (pray_status)code : PRAY_ERR_ARG;
    return fail(c, status, "%s", message ? message : pray_status_text(status));
}

#if PRAY_HAS_INTERP
// =============================================================================================
// [SECTION] 12 PRAY lexer
// =============================================================================================
namespace {

// Memory for pieces of a program (a statement's syntax tree, a line's names and strings, the
// names of variables), freed all at once: at the end of a run, or by reset for the next piece.
struct Arena {
    Array<char *> chunks;
    size_t left, size0;  // size0: of the first chunk, which reset keeps
    char *next;
    void init() {
        chunks.init();
        left = size0 = 0;
        next = NULL;
    }
    void *get(pray_ctx *c, size_t n) {
        n = (n + 15) & ~(size_t)15;
        if (n > left) {
            size_t sz = n > 16384 ? n : 16384;
            char *p = (char *)mem_alloc(c, sz);
            if (!p) return NULL;
            if (!chunks.push(c, p)) {
                mem_free(c, p);
                return NULL;
            }
            if (chunks.n == 1) size0 = sz;
            next = p;
            left = sz;
        }
        void *r = next;
        next += n;
        left -= n;
        memset(r, 0, n);
        return r;
    }
    // Everything given out so far is forgotten; the first chunk stays for what comes next.
    void reset(pray_ctx *c) {
        if (!chunks.n) return;
        for (int i = 1; i < chunks.n; i++) mem_free(c, chunks[i]);
        chunks.n = 1;
        next = chunks[0];
        left = size0;
    }
    void release(pray_ctx *c) {
        for (int i = 0; i < chunks.n; i++) mem_free(c, chunks[i]);
        chunks.release(c);
        left = 0;
    }
};

enum { T_EOF, T_NL, T_NUM, T_STR, T_NAME, T_OP };
// Two-character operators get codes of their own; `¥` lexes as '\\'.
enum { OP_EQ2 = 'E', OP_LE = 'L', OP_GE = 'G' };

struct Tok {
    int kind, op, line, col;
    double num;
    const char *s;  // name or decoded string (NUL-terminated, in the arena)
    int n;          // its length
    int dotnum;     // a number written with a leading '.'
};

// The lexer hands out one line at a time (lex_line): the parser never holds the tokens of more
// than the line it is reading, so a program of any length is read in little memory.
struct Lexer {
    pray_ctx *c;
    const char *name;
    const unsigned char *p, *end;
    int line, col;
    Arena *text;       // the names and strings of the tokens in toks
    Array<Tok> toks;   // the tokens of the current line
    double maxstring;  // option maxstring as the run started: literals are checked against it
    int at_end;        // toks ends with T_EOF
    int failed;        // lex_line found an error
};

pray_status perr(pray_ctx *c, const char *name, int line, int col, pray_status s, const char *fmt, ...)
    PRAY_PRINTF(6, 7);
pray_status perr(pray_ctx *c, const char *name, int line, int col, pray_status s, const char *fmt, ...) {
    va_list ap;
    va_start(ap, fmt);
    char tmp[800];
    vsnprintf(tmp, sizeof tmp, fmt, ap);
    va_end(ap);
    c->status = s;
    snprintf(c->msg, sizeof c->msg, "%s:%d:%d: error: %s", *ShownPath(name), line, col, tmp);
    snprintf(c->err_name, sizeof c->err_name, "%s", *ShownPath(name));
    c->err_line = line;
    c->err_col = col;
    return s;
}

// Length of the valid UTF-8 sequence at p, or 0.
int utf8_len(const unsigned char *p, const unsigned char *end) {
    unsigned b = p[0];
    int n;
    unsigned min;
    if (b < 0x80) return 1;
    if (b >= 0xC2 && b <= 0xDF) n = 2, min = 0x80;
    else if (b >= 0xE0 && b <= 0xEF) n = 3, min = 0x800;
    else if (b >= 0xF0 && b <= 0xF4) n = 4, min = 0x10000;
    else return 0;
    if (end - p < n) return 0;
    unsigned long cp = b & (0x7F >> n);
    for (int i = 1; i < n; i++) {
        if ((p[i] & 0xC0) != 0x80) return 0;
        cp = cp << 6 | (p[i] & 0x3F);
    }
    if (cp < min || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF)) return 0;
    return n;
}

bool is_yen(const unsigned char *p, const unsigned char *end) {
    return end - p >= 2 && p[0] == 0xC2 && p[1] == 0xA5;
}
bool is_alpha(int ch) { return (ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') || ch == '_'; }
bool is_digit(int ch) { return ch >= '0' && ch <= '9'; }

pray_status lex_err(Lexer &L, const char *fmt, const char *arg) {
    return perr(L.c, L.name, L.line, L.col, PRAY_ERR_SYNTAX, fmt, arg);
}

// Advance over n bytes of one character.
void lex_adv(Lexer &L, int n) {
    L.p += n;
    L.col++;
}

// Check the byte at L.p as part of a comment or string: valid UTF-8, no control characters.
pray_status lex_text_char(Lexer &L, int *n) {
    unsigned b = *L.p;
    if (b < 0x20 && b != '\t') {
        char code[8];
        snprintf(code, sizeof code, "%u", b);
        return lex_err(L, "control character (code %s) in the program", code);
    }
    *n = utf8_len(L.p, L.end);
    if (!*n) {
        char code[8];
        snprintf(code, sizeof code, "0x%02X", b);
        return lex_err(L, "invalid UTF-8 byte %s", code);
    }
    return PRAY_OK;
}

bool at_line_end(const Lexer &L, const unsigned char *q) {
    return q >= L.end || *q == '\n' || (*q == '\r' && q + 1 < L.end && q[1] == '\n');
}

// Skip a comment up to (not including) the line end.
pray_status lex_comment(Lexer &L) {
    while (!at_line_end(L, L.p)) {
        int n;
        if (*L.p == '\r') return lex_err(L, "carriage return without a line feed%s", "");
        pray_status st = lex_text_char(L, &n);
        if (st) return st;
        lex_adv(L, n);
    }
    return PRAY_OK;
}

void lex_newline(Lexer &L) {
    if (L.p < L.end && *L.p == '\r') L.p++;
    if (L.p < L.end && *L.p == '\n') L.p++;
    L.line++;
    L.col = 1;
}

bool push_tok(Lexer &L, int kind, int op, int line, int col) {
    Tok t;
    memset(&t, 0, sizeof t);
    t.kind = kind;
    t.op = op;
    t.line = line;
    t.col = col;
    return L.toks.push(L.c, t);
}

// Where double arithmetic rounds each operation once, to double (not through a wider register,
// as the x87 does), a decimal number of at most 15 significant digits times or over a power of
// ten up to 1e22 is converted exactly as strtod does, by one multiplication or division of two
// exact doubles (Clinger's fast path): most numbers of a program, at a fraction of strtod's cost.
#if (defined(FLT_EVAL_METHOD) && FLT_EVAL_METHOD == 0) || (defined(__FLT_EVAL_METHOD__) && __FLT_EVAL_METHOD__ == 0) || \
    defined(_M_X64) || defined(_M_ARM64)
const bool DOUBLE_ROUNDS_ONCE = true;
#else
const bool DOUBLE_ROUNDS_ONCE = false;
#endif

// The value of a number as the lexer takes it (digits, a fraction, an exponent) when the fast
// path gives it; false when strtod must.
bool decimal_exact(const char *t, double *v) {
    static const double TEN[23] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,  1e8,  1e9,  1e10, 1e11,
                                   1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};
    if (!DOUBLE_ROUNDS_ONCE) return false;
    double m = 0;  // the significant digits, an integer below 1e15: exact
    int digits = 0, scale = 0;
    bool frac = false;
    for (; *t && *t != 'e' && *t != 'E'; t++) {
        if (*t == '.') {
            frac = true;
            continue;
        }
        if (digits == 0 && *t == '0') {  // (leading zeros are not significant)
            scale -= frac;
            continue;
        }
        if (++digits > 15) return false;
        m = m * 10 + (*t - '0');
        scale -= frac;
    }
    if (*t) {  // the exponent: a sign and digits (lex_number checked them)
        t++;
        bool neg = *t == '-';
        if (*t == '+' || *t == '-') t++;
        int e = 0;
        for (; *t; t++)
            if ((e = e * 10 + (*t - '0')) > 400) return false;
        scale += neg ? -e : e;
    }
    if (m == 0) *v = 0;
    else if (scale >= 0 && scale <= 22) *v = m * TEN[scale];
    else if (scale < 0 && scale >= -22) *v = m / TEN[-scale];
    else return false;
    return true;
}

pray_status lex_number(Lexer &L) {
    const unsigned char *s = L.p;
    int line = L.line, col = L.col;
    int dotnum = *s == '.';
    const unsigned char *q = s;
    while (q < L.end && is_digit(*q)) q++;
    if (q + 1 < L.end && *q == '.' && is_digit(q[1])) {
        q++;
        while (q < L.end && is_digit(*q)) q++;
    }
    if (q < L.end && (*q == 'e' || *q == 'E')) {
        const unsigned char *e = q + 1;
        if (e < L.end && (*e == '+' || *e == '-')) e++;
        if (e >= L.end || !is_digit(*e))
            return perr(L.c, L.name, line, col, PRAY_ERR_SYNTAX, "malformed number: exponent without digits");
        while (e < L.end && is_digit(*e)) e++;
        q = e;
    }
    if (q < L.end && (is_alpha(*q) || is_digit(*q)))
        return perr(L.c, L.name, line, col, PRAY_ERR_SYNTAX, "malformed number: '%c' after the digits", *q);
    char buf[400];
    size_t n = (size_t)(q - s);
    if (n >= sizeof buf) return perr(L.c, L.name, line, col, PRAY_ERR_SYNTAX, "number too long");
    memcpy(buf, s, n);
    buf[n] = 0;
    double v;
    if (!decimal_exact(buf, &v)) v = strtod(buf, NULL);
    if (!finite_num(v)) return perr(L.c, L.name, line, col, PRAY_ERR_SYNTAX, "number out of range: %s", buf);
    L.col += (int)n;
    L.p = q;
    if (!push_tok(L, T_NUM, 0, line, col)) return L.c->status;
    L.toks[L.toks.n - 1].num = v;
    L.toks[L.toks.n - 1].dotnum = dotnum;
    return PRAY_OK;
}

pray_status lex_string(Lexer &L) {
    int line = L.line, col = L.col;
    lex_adv(L, 1);
    Text t;
    t.init();
    pray_status st = PRAY_OK;
    for (;;) {
        if (at_line_end(L, L.p)) {
            st = perr(L.c, L.name, line, col, PRAY_ERR_SYNTAX, "unterminated string");
            break;
        }
        if (*L.p == '\r') {
            st = lex_err(L, "carriage return without a line feed%s", "");
            break;
        }
        if (*L.p == '"') {
            if (L.p + 1 < L.end && L.p[1] == '"') {
                if (!t.add(L.c, "\"", 1)) {
                    st = L.c->status;
                    break;
                }
                lex_adv(L, 1);
                lex_adv(L, 1);
                continue;
            }
            lex_adv(L, 1);
            break;
        }
        int n;
        st = lex_text_char(L, &n);
        if (st) break;
        if ((double)t.a.n + n > L.maxstring) {
            st = perr(L.c, L.name, line, col, PRAY_ERR_LIMIT, "string longer than %.0f byte%s (option maxstring)",
                      L.maxstring, L.maxstring == 1 ? "" : "s");
            break;
        }
        if (!t.add(L.c, (const char *)L.p, (size_t)n)) {
            st = L.c->status;
            break;
        }
        lex_adv(L, n);
    }
    if (st == PRAY_OK) {
        char *s = (char *)L.text->get(L.c, (size_t)t.a.n + 1);
        if (!s || !push_tok(L, T_STR, 0, line, col)) st = L.c->status;
        else {
            memcpy(s, t.str(), (size_t)t.a.n + 1);
            L.toks[L.toks.n - 1].s = s;
            L.toks[L.toks.n - 1].n = t.a.n;
        }
    }
    t.a.release(L.c);
    return st;
}

// A continuation mark is a `\` or `¥` followed on its line only by blanks or a comment.
bool is_continuation(const Lexer &L, int marklen) {
    const unsigned char *q = L.p + marklen;
    while (q < L.end && (*q == ' ' || *q == '\t')) q++;
    return at_line_end(L, q) || (q + 1 < L.end && q[0] == '/' && q[1] == '/');
}

// Option maxline: a program with a longer line is refused before it is read, at the first
// character past the limit (characters counted as the lexer's columns count them).
pray_status check_line_lengths(Lexer &L) {
    double lim = L.c->cur.opt.v[OPT_MAXLINE];
    int line = 1;
    double col = 0;
    for (const unsigned char *q = L.p; q < L.end; q++) {
        if (*q == '\n') {
            line++;
            col = 0;
        } else if ((*q & 0xC0) != 0x80 && ++col > lim) {
            return perr(L.c, L.name, line, (int)col, PRAY_ERR_LIMIT, "line longer than %.0f character%s (option maxline)",
                        lim, lim == 1 ? "" : "s");
        }
    }
    return PRAY_OK;
}

// The tokens of one line up to its T_NL (a continued line is one line); at the end of the
// program T_NL and T_EOF.
pray_status lex_tokens(Lexer &L) {
    while (L.p < L.end) {
        unsigned ch = *L.p;
        if (ch == ' ' || ch == '\t') {
            lex_adv(L, 1);
            continue;
        }
        if (ch == '\n' || (ch == '\r' && L.p + 1 < L.end && L.p[1] == '\n')) {
            if (!push_tok(L, T_NL, 0, L.line, L.col)) return L.c->status;
            lex_newline(L);
            return PRAY_OK;
        }
        if (ch == '/' && L.p + 1 < L.end && L.p[1] == '/') {
            pray_status st = lex_comment(L);
            if (st) return st;
            continue;
        }
        int yen = is_yen(L.p, L.end);
        if ((ch == '\\' || yen) && is_continuation(L, yen ? 2 : 1)) {
            int line = L.line, col = L.col;
            lex_adv(L, yen ? 2 : 1);
            while (L.p < L.end && (*L.p == ' ' || *L.p == '\t')) lex_adv(L, 1);
            pray_status st = lex_comment(L);
            if (st) return st;
            if (L.p >= L.end)
                return perr(L.c, L.name, line, col, PRAY_ERR_SYNTAX, "line continuation at the end of the file");
            lex_newline(L);
            if (L.p >= L.end)
                return perr(L.c, L.name, line, col, PRAY_ERR_SYNTAX, "line continuation at the end of the file");
            continue;
        }
        if (is_digit((int)ch) || (ch == '.' && L.p + 1 < L.end && is_digit(L.p[1]))) {
            pray_status st = lex_number(L);
            if (st) return st;
            continue;
        }
        if (is_alpha((int)ch)) {
            const unsigned char *s = L.p;
            int col = L.col;
            while (L.p < L.end && (is_alpha(*L.p) || is_digit(*L.p))) lex_adv(L, 1);
            int n = (int)(L.p - s);
            char *name = (char *)L.text->get(L.c, (size_t)n + 1);
            if (!name || !push_tok(L, T_NAME, 0, L.line, col)) return L.c->status;
            memcpy(name, s, (size_t)n);
            L.toks[L.toks.n - 1].s = name;
            L.toks[L.toks.n - 1].n = n;
            continue;
        }
        if (ch == '"') {
            pray_status st = lex_string(L);
            if (st) return st;
            continue;
        }
        int op = 0, len = 1;
        if (yen) op = '\\', len = 2;
        else if (ch == '=' && L.p + 1 < L.end && L.p[1] == '=') op = OP_EQ2, len = 2;
        else if (ch == '<' && L.p + 1 < L.end && L.p[1] == '=') op = OP_LE, len = 2;
        else if (ch == '>' && L.p + 1 < L.end && L.p[1] == '=') op = OP_GE, len = 2;
        else if (strchr("+-*/%^.=#<>&|\\()[]{},", (int)ch) && ch) op = (int)ch;
        if (op) {
            if (!push_tok(L, T_OP, op, L.line, L.col)) return L.c->status;
            L.p += len;
            L.col++;
            if (len == 2 && !yen) L.col++;
            continue;
        }
        if (ch == '\r') return lex_err(L, "carriage return without a line feed%s", "");
        if (ch < 0x20 || ch == 0x7F) {
            char code[8];
            snprintf(code, sizeof code, "%u", ch);
            return lex_err(L, "control character (code %s) in the program", code);
        }
        int n = utf8_len(L.p, L.end);
        if (!n) {
            char code[8];
            snprintf(code, sizeof code, "0x%02X", ch);
            return lex_err(L, "invalid UTF-8 byte %s", code);
        }
        char what[8];
        memcpy(what, L.p, (size_t)n);
        what[n] = 0;
        if (ch == '!') return lex_err(L, "unexpected character '%s' (PRAY writes 'not equal' as '#')", what);
        if (ch == ';') return lex_err(L, "unexpected character '%s' (one statement per line, no ';')", what);
        if (n == 1) return lex_err(L, "unexpected character '%s'", what);
        unsigned long cp = L.p[0] & (0x7F >> n);
        for (int i = 1; i < n; i++) cp = cp << 6 | (L.p[i] & 0x3F);
        char msg[64];
        snprintf(msg, sizeof msg, "unexpected character '%s' (U+%04lX)", what, cp);
        return lex_err(L, "%s", msg);
    }
    if (!push_tok(L, T_NL, 0, L.line, L.col) || !push_tok(L, T_EOF, 0, L.line, L.col)) return L.c->status;
    L.at_end = 1;
    return PRAY_OK;
}

// The next line's tokens replace the current line's.
pray_status lex_line(Lexer &L) {
    L.toks.n = 0;
    L.text->reset(L.c);
    if (L.at_end) return push_tok(L, T_EOF, 0, L.line, L.col) ? PRAY_OK : L.c->status;
    pray_status st = lex_tokens(L);
    if (st) L.failed = 1;
    return st;
}

// Start reading the program from its beginning, the first time with the check of its lines'
// lengths: the first line's tokens.
pray_status lex_start(Lexer &L, const char *text, size_t len, bool check) {
    L.p = (const unsigned char *)text;
    L.end = L.p + len;
    L.line = 1;
    L.col = 1;
    L.at_end = L.failed = 0;
    // a UTF-8 byte order mark is allowed at the start
    if (len >= 3 && L.p[0] == 0xEF && L.p[1] == 0xBB && L.p[2] == 0xBF) L.p += 3;
    if (check && check_line_lengths(L)) {
        L.failed = 1;
        return L.c->status;
    }
    return lex_line(L);
}

} // namespace

// =============================================================================================
// [SECTION] 13 PRAY parser
// =============================================================================================
namespace {

enum { EX_NUM, EX_STR, EX_VAR, EX_CONST, EX_CALL, EX_UNARY, EX_BINARY, EX_CHAIN, EX_POINT, EX_VECTOR, EX_INTENS,
       EX_PCALL, EX_LOCAL };
enum { C_TRUE, C_FALSE, C_NOTHING, C_NONE, C_PI };

struct Expr {
    int kind, op, line, col;  // op: an operator; of EX_PCALL its depth in the statement; of EX_LOCAL the global slot
    double num;
    const char *s;  // string literal or variable name
    int n;          // string length; variable slot; constant; builtin index; procedure; local
    Expr *a, *b, *c;
    Expr **args;
    int nargs;
};

enum {
    ST_ASSIGN, ST_DELETE, ST_PRINT, ST_IF, ST_WHILE, ST_QUIT, ST_BACKGROUND, ST_PERSPECTIVE,
    ST_PARALLEL, ST_OPTION, ST_RENDER, ST_LOOKAT, ST_INCLUDE, ST_DEFINE, ST_RETURN, ST_CALL, ST_BRANCH
};

// An `if` holds a branch (ST_BRANCH: its statements in body) per condition args[i] of `if` and
// `elseif`, and the statements of `else` in els: a chain of elseif is a loop, not nested ifs.
struct Stmt {
    int kind, line, col;
    int slot;  // assignment target: a variable, or in a procedure's body (local) a local
    int local;
    Expr **args;
    int nargs;
    Stmt **body, **els;
    int nbody, nels;
};

// A procedure (define NAME(...) ... enddefine): its name is known from the first time it is read;
// it is defined (callable) once its define statement has run. Its body lives as long as the run.
struct Proc {
    const char *name, *file;  // (the run's names)
    int line, col;            // of the define
    int nparams, nlocals;     // the parameters are locals 0 .. nparams-1
    int deep;                 // the levels of blocks and expressions its body nests, at most
    Stmt **body;
    int nbody;
    int seen;     // a define of it has been read
    int defined;  // its define has run
};

// A call of a procedure in the file being checked: known, and with the right number of arguments,
// once the whole file is read (it may call a procedure defined further down).
struct CallSite {
    int proc, nargs, line, col;
};

struct Builtin;
const Builtin *builtin_find(const char *name);
int builtin_index(const Builtin *b);
int builtin_min(const Builtin *b);
int builtin_max(const Builtin *b);
const char *builtin_name(int i);
int builtin_count();

const char *const KEYWORDS[] = {"if", "then", "else", "elseif", "endif", "while", "endwhile", "background",
                                "define", "enddefine", "return", "delete", "include", "lookat", "option",
                                "parallel", "perspective", "print", "quit", "rendertiff", "true", "false",
                                "nothing", "none", "pi"};

// The words versions 2 and 3 of the language added: an older program may have used them as
// names, so its error says why the name is refused now.
const char *version2_note(const char *s) {
    static const char *const words[] = {"box", "ceil", "cone", "floor", "include", "lookat", "max", "min", "rod",
                                        "round", "stretch", "torus", "checker", "define", "elseif", "enddefine",
                                        "paint", "return", "spotlight"};
    for (size_t i = 0; i < sizeof words / sizeof words[0]; i++)
        if (strcmp(words[i], s) == 0)
            return i < 12 ? " (a word of version 2 of the language: rename the variable)"
                          : " (a word of version 3 of the language: rename the variable)";
    return "";
}

// Variable names are interned at parse time; a variable is a slot.
struct Var {
    const char *name;
};
// A table of names (variables, procedures), hashed: programs written by generators may have many
// thousands of them. hash: open addressing, index + 1, 0 = empty; size a power of two.
struct Names {
    Array<Var> list;
    Array<int> hash;
};


struct Parser {
    pray_ctx *c;
    const char *name;
    Lexer *L;    // the tokens of the current line: t[0 .. L->toks.n)
    Tok *t;
    int pos;
    // One bound, option maxnest, on the whole depth of the run: the levels around the file
    // being read (the blocks and includes that led to it), its blocks, and the expression read.
    int depth;   // nesting of parentheses, literals, calls, unary operators, powers
    int blocks;  // nesting of if and while, counted from `base`
    int base;    // the levels around this file: 0 for the program
    double maxnest;  // option maxnest as the run started
    Arena *arena;    // the syntax tree of the statement being read
    Arena *names;    // the names of variables, for the whole run
    Names *vars;       // the variables; a variable's index is its slot
    int included;      // reading a file that `include` named (the variables are the program's)
    int run;           // reading to run (else to check)
    Names *pnames;           // the names of the run's procedures
    Array<Proc> *procs;      // the procedures, by the index of their names
    Array<CallSite> *sites;  // checking: the calls of procedures read so far in this file
    Arena *keep;             // running: where the bodies of procedures go (they live as long as the run)
    int in_proc;             // reading the body of a define
    int peak;                // the deepest level (blocks and expression) reached in that body
    int includes;            // the file has an include statement
};

// Past the T_NL at the current position: the tokens of the next line, when it takes them.
// Only here does the parser leave a line, so a token of the line before is never looked at
// again (the lexer reuses their memory).
pray_status next_line(Parser &P) {
    P.pos++;
    if (P.pos < P.L->toks.n) return PRAY_OK;
    pray_status st = lex_line(*P.L);
    P.t = P.L->toks.p;
    P.pos = 0;
    return st;
}

Tok &cur(Parser &P) { return P.t[P.pos]; }
bool is_op(const Tok &t, int op) { return t.kind == T_OP && t.op == op; }
bool is_word(const Tok &t, const char *w) { return t.kind == T_NAME && strcmp(t.s, w) == 0; }

pray_status syn(Parser &P, const Tok &t, const char *fmt, ...) PRAY_PRINTF(3, 4);
pray_status syn(Parser &P, const Tok &t, const char *fmt, ...) {
    va_list ap;
    va_start(ap, fmt);
    char tmp[800];
    vsnprintf(tmp, sizeof tmp, fmt, ap);
    va_end(ap);
    return perr(P.c, P.name, t.line, t.col, PRAY_ERR_SYNTAX, "%s", tmp);
}

// How a token reads in a message.
const char *tok_text(const Tok &t, char *buf, size_t n) {
    switch (t.kind) {
    case T_EOF: return "end of file";
    case T_NL: return "end of line";
    case T_NUM: snprintf(buf, n, "%g", t.num); return buf;
    case T_STR: return "a string";
    case T_NAME: snprintf(buf, n, "%.60s", t.s); return buf;
    default:
        if (t.op == OP_EQ2) return "==";
        if (t.op == OP_LE) return "<=";
        if (t.op == OP_GE) return ">=";
        buf[0] = (char)t.op;
        buf[1] = 0;
        return buf;
    }
}

pray_status expect_op(Parser &P, int op, const char *what) {
    if (is_op(cur(P), op)) {
        P.pos++;
        return PRAY_OK;
    }
    char buf[80], msg[160];
    snprintf(msg, sizeof msg, "expected %s, found '%s'", what, tok_text(cur(P), buf, sizeof buf));
    return syn(P, cur(P), "%s", msg);
}

// Every predefined word (keyword, constant, function) starts with a lower-case letter.
inline bool may_be_predefined(const char *s) { return *s >= 'a' && *s <= 'z'; }

bool is_reserved(const char *s) {
    if (!may_be_predefined(s)) return false;
    for (size_t i = 0; i < sizeof KEYWORDS / sizeof KEYWORDS[0]; i++)
        if (strcmp(KEYWORDS[i], s) == 0) return true;
    return builtin_find(s) != NULL;
}

unsigned name_hash(const char *s) {
    unsigned h = 2166136261u;
    for (; *s; s++) h = (h ^ (unsigned char)*s) * 16777619u;
    return h;
}

// The index of `name` in the table, or -1 (then *at is where it would go; the hash is not empty).
int name_find(const Names &t, const char *name, unsigned *at = NULL) {
    const Array<int> &h = t.hash;
    if (h.n == 0) return -1;
    unsigned k = name_hash(name) & (unsigned)(h.n - 1);
    for (; h[(int)k]; k = (k + 1) & (unsigned)(h.n - 1))
        if (strcmp(t.list[h[(int)k] - 1].name, name) == 0) return h[(int)k] - 1;
    if (at) *at = k;
    return -1;
}

// The index of `name` in the table, made on first sight (the name kept in the run's names).
int name_slot(Parser &P, Names &t, const char *name) {
    Array<int> &h = t.hash;
    if (2 * (t.list.n + 1) > h.n) {  // grow and rehash
        int size = h.n ? 2 * h.n : 64;
        Array<int> nh;
        nh.init();
        if (!nh.reserve(P.c, size)) return -1;
        nh.n = size;
        memset(nh.p, 0, sizeof(int) * (size_t)size);
        for (int i = 0; i < t.list.n; i++) {
            unsigned k = name_hash(t.list[i].name) & (unsigned)(size - 1);
            while (nh[(int)k]) k = (k + 1) & (unsigned)(size - 1);
            nh[(int)k] = i + 1;
        }
        h.release(P.c);
        h = nh;
    }
    unsigned k = 0;
    int found = name_find(t, name, &k);
    if (found >= 0) return found;
    Var v;
    size_t len = strlen(name);
    char *kept = (char *)P.names->get(P.c, len + 1);
    if (!kept) return -1;
    memcpy(kept, name, len + 1);
    v.name = kept;
    if (!t.list.push(P.c, v)) return -1;
    h[(int)k] = t.list.n;
    return t.list.n - 1;
}
inline int var_find(Parser &P, const char *name) { return name_find(*P.vars, name); }
inline int var_slot(Parser &P, const char *name) { return name_slot(P, *P.vars, name); }

Expr *new_expr(Parser &P, int kind, const Tok &t) {
    Expr *e = (Expr *)P.arena->get(P.c, sizeof(Expr));
    if (!e) return NULL;
    e->kind = kind;
    e->line = t.line;
    e->col = t.col;
    return e;
}

Expr *parse_expr(Parser &P);
Expr *parse_additive(Parser &P);

// args -> expr { ',' expr }   (the list of a call or a statement)
bool parse_list(Parser &P, Array<Expr *> *out, bool additive) {
    for (;;) {
        Expr *e = additive ? parse_additive(P) : parse_expr(P);
        if (!e || !out->push(P.c, e)) return false;
        if (!is_op(cur(P), ',')) return true;
        P.pos++;
    }
}

Expr **freeze_list(Parser &P, Array<Expr *> &a) {
    Expr **p = (Expr **)P.arena->get(P.c, sizeof(Expr *) * (size_t)(a.n ? a.n : 1));
    if (p && a.n) memcpy(p, a.p, sizeof(Expr *) * (size_t)a.n);
    return p;
}

// literal -> '[' add ',' add ',' add ']' | '<' add ',' add ',' add '>' | '{' add [',' add ',' add] '}'
bool enter(Parser &P, const Tok *at = NULL);

Expr *parse_literal(Parser &P, int kind, int close, const char *what) {
    Tok &open = cur(P);
    if (!enter(P)) return NULL;
    P.pos++;
    Expr *e = new_expr(P, kind, open);
    if (!e) return NULL;
    Expr *x[3] = {NULL, NULL, NULL};
    int n = 0;
    for (;;) {
        if (n == 3) {
            char msg[80];
            snprintf(msg, sizeof msg, "%s has at most 3 components", what);
            syn(P, cur(P), "%s", msg);
            return NULL;
        }
        x[n] = parse_additive(P);
        if (!x[n]) return NULL;
        n++;
        if (is_op(cur(P), ',')) {
            P.pos++;
            continue;
        }
        break;
    }
    if (!is_op(cur(P), close)) {
        char buf[80], msg[200];
        snprintf(msg, sizeof msg, "expected ',' or '%c' in %s, found '%s'%s", close, what,
                 tok_text(cur(P), buf, sizeof buf),
                 close == '>' || close == ']' || close == '}'
                     ? " (a comparison inside a literal must be in parentheses)"
                     : "");
        syn(P, cur(P), "%s", msg);
        return NULL;
    }
    P.pos++;
    if (!(n == 3 || (kind == EX_INTENS && n == 1))) {
        char msg[120];
        snprintf(msg, sizeof msg, "%s needs %s components, not %d", what,
                 kind == EX_INTENS ? "1 or 3" : "3", n);
        perr(P.c, P.name, open.line, open.col, PRAY_ERR_SYNTAX, "%s", msg);
        return NULL;
    }
    e->a = x[0];
    e->b = n == 3 ? x[1] : x[0];
    e->c = n == 3 ? x[2] : x[0];
    P.depth--;
    return e;
}

// The arguments of a call, from the '(' after its name t: a node of the kind, its arguments in
// args, a level of maxnest deeper than the expression around it (e->op).
Expr *call_args(Parser &P, const Tok &t, int kind) {
    if (!enter(P, &t)) return NULL;
    P.pos++;
    Expr *e = new_expr(P, kind, t);
    if (!e) return NULL;
    e->op = P.depth;
    Array<Expr *> args;
    args.init();
    bool ok = true;
    if (!is_op(cur(P), ')')) ok = parse_list(P, &args, false);
    if (ok && expect_op(P, ')', "',' or ')' after an argument")) ok = false;
    if (ok) {
        e->args = freeze_list(P, args);
        e->nargs = args.n;
        ok = e->args != NULL;
    }
    args.release(P.c);
    P.depth--;
    return ok ? e : NULL;
}

// The procedure of that name, or -1.
inline int proc_find(Parser &P, const char *name) { return name_find(*P.pnames, name); }

// The procedure of that name, made on first sight (a call may come before its define); -1: no memory.
int proc_index(Parser &P, const char *name) {
    int i = name_slot(P, *P.pnames, name);
    if (i < 0 || i < P.procs->n) return i;
    Proc p;
    memset(&p, 0, sizeof p);
    p.name = P.pnames->list[i].name;
    return P.procs->push(P.c, p) ? i : -1;
}

// NAME '(' [args] ')' of a procedure; checked when the file is read whole (check_calls).
Expr *parse_pcall(Parser &P, const Tok &t) {
    Expr *e = call_args(P, t, EX_PCALL);
    if (!e || (e->n = proc_index(P, t.s)) < 0) return NULL;
    e->s = (*P.procs)[e->n].name;
    CallSite site = {e->n, e->nargs, t.line, t.col};
    return P.run || P.sites->push(P.c, site) ? e : NULL;
}

// "unknown function 'F'", with the builtin or procedure it may have meant.
pray_status unknown_function(pray_ctx *c, pray_status st, const char *file, int line, int col, const char *name,
                             const Array<Proc> &procs, bool later) {
    Suggest sg;
    sg.init(name);
    for (int i = 0; i < builtin_count(); i++) sg.offer(builtin_name(i));
    for (int i = 0; i < procs.n; i++)
        if (procs[i].seen && strcmp(procs[i].name, name) != 0) sg.offer(procs[i].name);
    return perr(c, file, line, col, st, "unknown function '%s'%s%s%s", *Shown(name),
                later ? " (a procedure is known once its define has run)" : sg.best ? "; did you mean '" : "",
                later ? "" : sg.best ? sg.best : "", !later && sg.best ? "'?" : "");
}

// The file read whole: every procedure it calls is defined in it or in a file read before, with
// as many parameters as the call has arguments (a file that includes others is checked as it
// runs, since they may define what it calls).
pray_status check_calls(Parser &P) {
    for (int i = 0; i < P.sites->n; i++) {
        const CallSite &s = (*P.sites)[i];
        const Proc &p = (*P.procs)[s.proc];
        if (!p.seen && !P.includes)
            return unknown_function(P.c, PRAY_ERR_SYNTAX, P.name, s.line, s.col, p.name, *P.procs, false);
        if (p.seen && p.nparams != s.nargs)
            return perr(P.c, P.name, s.line, s.col, PRAY_ERR_SYNTAX, "%s takes %d argument%s, not %d", p.name,
                        p.nparams, p.nparams == 1 ? "" : "s", s.nargs);
    }
    return PRAY_OK;
}

// primary -> NUMBER | STRING | NAME | NAME '(' [args] ')' | '(' expr ')' | literal
Expr *parse_primary(Parser &P) {
    Tok &t = cur(P);
    char buf[80];
    if (t.kind == T_NUM) {
        P.pos++;
        Expr *e = new_expr(P, EX_NUM, t);
        if (e) e->num = t.num;
        return e;
    }
    if (t.kind == T_STR) {
        P.pos++;
        Expr *e = new_expr(P, EX_STR, t);
        char *str = e ? (char *)P.arena->get(P.c, (size_t)t.n + 1) : NULL;
        if (!str) return NULL;
        memcpy(str, t.s, (size_t)t.n + 1);
        e->s = str;
        e->n = t.n;
        return e;
    }
    if (t.kind == T_NAME) {
        P.pos++;
        static const char *const consts[] = {"true", "false", "nothing", "none", "pi"};
        for (int i = 0; i < 5 && may_be_predefined(t.s); i++)
            if (strcmp(t.s, consts[i]) == 0) {
                Expr *e = new_expr(P, EX_CONST, t);
                if (e) e->n = i;
                return e;
            }
        const Builtin *b = may_be_predefined(t.s) ? builtin_find(t.s) : NULL;
        if (b) {
            if (!is_op(cur(P), '(')) {
                syn(P, t, "'%s' is a function: write it with its arguments in parentheses%s", t.s, version2_note(t.s));
                return NULL;
            }
            Expr *e = call_args(P, t, EX_CALL);
            if (!e) return NULL;
            e->n = builtin_index(b);
            e->s = builtin_name(e->n);
            int lo = builtin_min(b), hi = builtin_max(b);
            if (e->nargs < lo || e->nargs > hi) {
                char msg[160];
                if (lo == hi) snprintf(msg, sizeof msg, "%s takes %d argument%s, not %d", t.s, lo, lo == 1 ? "" : "s", e->nargs);
                else snprintf(msg, sizeof msg, "%s takes %d to %d arguments, not %d", t.s, lo, hi, e->nargs);
                syn(P, t, "%s", msg);
                return NULL;
            }
            return e;
        }
        if (is_reserved(t.s)) {
            syn(P, t, "'%s' is a reserved word and cannot be used here%s", t.s, version2_note(t.s));
            return NULL;
        }
        if (is_op(cur(P), '(')) return parse_pcall(P, t);
        int pi = proc_find(P, t.s);
        if (pi >= 0 && (*P.procs)[pi].seen) {
            syn(P, t, "'%s' is a procedure: call it with its arguments in parentheses", t.s);
            return NULL;
        }
        Expr *e = new_expr(P, EX_VAR, t);
        if (!e) return NULL;
        e->n = var_slot(P, t.s);
        if (e->n < 0) return NULL;
        e->s = P.vars->list[e->n].name;
        return e;
    }
    if (is_op(t, '(')) {
        if (!enter(P)) return NULL;
        P.pos++;
        Expr *e = parse_expr(P);
        if (!e || expect_op(P, ')', "')'")) return NULL;
        P.depth--;
        return e;
    }
    if (is_op(t, '[')) return parse_literal(P, EX_POINT, ']', "a point");
    if (is_op(t, '<')) return parse_literal(P, EX_VECTOR, '>', "a vector");
    if (is_op(t, '{')) return parse_literal(P, EX_INTENS, '}', "an intensity");
    syn(P, t, "expected a value, found '%s'", tok_text(t, buf, sizeof buf));
    return NULL;
}

// The message of a run nested deeper than maxnest: `what` went past the bound, with `around`
// levels of other kinds (blocks, includes) outside it.
const char *nest_message(char *msg, size_t size, const char *what, double lim, int around) {
    int n = snprintf(msg, size, "%s nested deeper than %.0f level%s", what, lim, lim == 1 ? "" : "s");
    if (around > 0 && n > 0 && (size_t)n < size)
        n += snprintf(msg + n, size - (size_t)n, ", counting the %d level%s around %s", around, around == 1 ? "" : "s",
                      strcmp(what, "expression") == 0 ? "it" : "them");
    if (n > 0 && (size_t)n < size) snprintf(msg + n, size - (size_t)n, " (option maxnest)");
    return msg;
}

// One level deeper, at token `at` (default: the current token).
bool enter(Parser &P, const Tok *at) {
    if (P.depth + 1 + P.blocks > P.peak) P.peak = P.depth + 1 + P.blocks;
    if (++P.depth + P.blocks > P.maxnest) {
        char msg[160];
        syn(P, at ? *at : cur(P), "%s", nest_message(msg, sizeof msg, "expression", P.maxnest, P.blocks));
        return false;
    }
    return true;
}

Expr *binary(Parser &P, const Tok &op, Expr *a, Expr *b) {
    if (!a || !b) return NULL;
    Expr *e = new_expr(P, EX_BINARY, op);
    if (!e) return NULL;
    e->op = op.op;
    e->a = a;
    e->b = b;
    return e;
}

// unary -> ('+' | '-') unary | primary
Expr *parse_unary(Parser &P) {
    Expr *r;
    Tok &t = cur(P);
    if (is_op(t, '+') || is_op(t, '-')) {
        if (!enter(P)) return NULL;
        P.pos++;
        Expr *a = parse_unary(P);
        P.depth--;
        r = a ? new_expr(P, EX_UNARY, t) : NULL;
        if (r) {
            r->op = t.op;
            r->a = a;
        }
    } else {
        r = parse_primary(P);
        if (r && cur(P).kind == T_NUM && cur(P).dotnum) {
            syn(P, cur(P), "a number starting with '.' cannot follow a value; for a transformation "
                           "write 'X . 5' or 'X.(5)'");
            r = NULL;
        }
    }
    return r;
}

// A run of operators of one level that group from the left, `A op B op C ...`, is one EX_CHAIN
// node: args[0] is A, args[i] (i > 0) the i-th operator, an EX_BINARY node with its right operand
// in b. A chain of any length is built here and evaluated in a loop, never by recursion per
// operator, so the stack stays flat however long it is.
Expr *parse_chain(Parser &P, Expr *(*operand)(Parser &), bool (*match)(const Tok &)) {
    Expr *a = operand(P);
    if (!a || !match(cur(P))) return a;
    Expr *e = new_expr(P, EX_CHAIN, cur(P));
    Array<Expr *> list;
    list.init();
    bool ok = e && list.push(P.c, a);
    while (ok && match(cur(P))) {
        Expr *op = new_expr(P, EX_BINARY, cur(P));
        ok = op != NULL;
        if (ok) {
            op->op = cur(P).op;
            P.pos++;
            op->b = operand(P);
            ok = op->b && list.push(P.c, op);
        }
    }
    if (ok) {
        e->args = freeze_list(P, list);
        e->nargs = list.n;
        e->line = list[list.n - 1]->line;  // the chain as a whole is placed at its last operator
        e->col = list[list.n - 1]->col;
        ok = e->args != NULL;
    }
    list.release(P.c);
    return ok ? e : NULL;
}

bool is_dot(const Tok &t) { return is_op(t, '.'); }
bool is_mulop(const Tok &t) { return is_op(t, '*') || is_op(t, '/') || is_op(t, '%'); }
bool is_addop(const Tok &t) { return is_op(t, '+') || is_op(t, '-'); }
bool is_cmp(const Tok &t) {
    return t.kind == T_OP && (t.op == '=' || t.op == OP_EQ2 || t.op == '#' || t.op == '<' ||
                              t.op == '>' || t.op == OP_LE || t.op == OP_GE);
}
bool is_and(const Tok &t) { return is_op(t, '&'); }
bool is_orop(const Tok &t) { return is_op(t, '|') || is_op(t, '\\'); }

// transform -> unary { '.' unary }
Expr *parse_transform(Parser &P) { return parse_chain(P, parse_unary, is_dot); }

// power -> transform [ '^' power ]   (right-associative; each '^' is a level of maxnest)
Expr *parse_power(Parser &P) {
    Expr *a = parse_transform(P);
    if (a && is_op(cur(P), '^')) {
        if (!enter(P)) return NULL;
        Tok &op = cur(P);
        P.pos++;
        a = binary(P, op, a, parse_power(P));
        P.depth--;
    }
    return a;
}

// multiplicative -> power { ('*' | '/' | '%') power }
Expr *parse_mul(Parser &P) { return parse_chain(P, parse_power, is_mulop); }

// additive -> multiplicative { ('+' | '-') multiplicative }
Expr *parse_additive(Parser &P) { return parse_chain(P, parse_mul, is_addop); }

// comparison -> additive { cmp additive }
Expr *parse_cmp(Parser &P) { return parse_chain(P, parse_additive, is_cmp); }

// and -> comparison { '&' comparison }
Expr *parse_and(Parser &P) { return parse_chain(P, parse_cmp, is_and); }

// expr -> and { ('|' | '\' | '¥') and }
Expr *parse_expr(Parser &P) { return parse_chain(P, parse_and, is_orop); }

pray_status end_of_line(Parser &P) {
    if (cur(P).kind == T_NL) return next_line(P);
    char buf[80];
    return syn(P, cur(P), "expected end of line, found '%s'", tok_text(cur(P), buf, sizeof buf));
}

Stmt *new_stmt(Parser &P, int kind, const Tok &t) {
    Stmt *s = (Stmt *)P.arena->get(P.c, sizeof(Stmt));
    if (!s) return NULL;
    s->kind = kind;
    s->line = t.line;
    s->col = t.col;
    return s;
}

// The word that ends a block ('else', 'elseif', 'endif', 'endwhile', 'enddefine') at the current
// token, or NULL.
const char *block_end(Parser &P) {
    static const char *const ends[] = {"else", "elseif", "endif", "endwhile", "enddefine"};
    for (int i = 0; i < 5; i++)
        if (is_word(cur(P), ends[i])) return ends[i];
    return NULL;
}

// The word that opens the block an end word closes.
const char *block_opener(const char *end) {
    return strcmp(end, "endwhile") == 0 ? "while" : strcmp(end, "enddefine") == 0 ? "define" : "if";
}

bool parse_block(Parser &P, Array<Stmt *> *out, const char **stop);

// The statement's arguments: exactly n (n > 0), or between lo and hi.
bool stmt_args(Parser &P, Stmt *s, const Tok &word, int lo, int hi) {
    Array<Expr *> args;
    args.init();
    bool ok = true;
    if (cur(P).kind == T_NL) {
        if (lo > 0) {
            char msg[120];
            if (hi > 1000) snprintf(msg, sizeof msg, "'%s' needs at least %d argument%s", word.s, lo, lo == 1 ? "" : "s");
            else if (hi > lo) snprintf(msg, sizeof msg, "'%s' needs %d or %d arguments", word.s, lo, hi);
            else snprintf(msg, sizeof msg, "'%s' needs %d argument%s", word.s, lo, lo == 1 ? "" : "s");
            syn(P, cur(P), "%s", msg);
            ok = false;
        }
    } else
        ok = parse_list(P, &args, false);
    if (ok && (args.n < lo || args.n > hi)) {
        char msg[160];
        if (lo == hi) snprintf(msg, sizeof msg, "'%s' takes %d argument%s, not %d", word.s, lo, lo == 1 ? "" : "s", args.n);
        else if (hi > 1000) snprintf(msg, sizeof msg, "'%s' takes at least %d argument%s", word.s, lo, lo == 1 ? "" : "s");
        else snprintf(msg, sizeof msg, "'%s' takes %d or %d arguments, not %d", word.s, lo, hi, args.n);
        syn(P, word, "%s", msg);
        ok = false;
    }
    if (ok) {
        s->args = freeze_list(P, args);
        s->nargs = args.n;
        ok = s->args != NULL;
    }
    args.release(P.c);
    return ok;
}

Stmt **freeze_stmts(Parser &P, Array<Stmt *> &a) {
    Stmt **p = (Stmt **)P.arena->get(P.c, sizeof(Stmt *) * (size_t)(a.n ? a.n : 1));
    if (p && a.n) memcpy(p, a.p, sizeof(Stmt *) * (size_t)a.n);
    return p;
}

// include "F", alone on its line (t: the word).
Stmt *parse_include(Parser &P, const Tok &t) {
    const Tok &f = P.t[P.pos + 1];
    if (f.kind != T_STR) {
        syn(P, f.kind == T_NL ? t : f, "'include' takes a file name in double quotes: include \"F\"");
        return NULL;
    }
    if (f.line != t.line || f.n == 0) {
        syn(P, f, f.n ? "'include' stands alone on its line: the file name must be on the line of 'include'"
                      : "'include' takes a file name, not an empty string");
        return NULL;
    }
    Stmt *s = new_stmt(P, ST_INCLUDE, t);
    if (!s) return NULL;
    P.pos++;
    Expr *e = parse_primary(P);
    s->args = e ? (Expr **)P.arena->get(P.c, sizeof(Expr *)) : NULL;
    if (!s->args) return NULL;
    s->args[0] = e;
    s->nargs = 1;
    if (cur(P).kind != T_NL) {
        char buf[80];
        syn(P, cur(P), "'include' stands alone on its line: expected end of line after the file name, found '%s'",
            tok_text(cur(P), buf, sizeof buf));
        return NULL;
    }
    return next_line(P) ? NULL : s;
}

// The statements of a block, up to the word that ends it (*stop), into *body and *n.
bool parse_body(Parser &P, Stmt ***body, int *n, const char **stop) {
    Array<Stmt *> a;
    a.init();
    bool ok = parse_block(P, &a, stop);
    if (ok) {
        *body = freeze_stmts(P, a);
        *n = a.n;
        ok = *body != NULL;
    }
    a.release(P.c);
    return ok;
}

// if COND [then] ... [else ...] endif, or while COND ... endwhile (t: the word).
Stmt *parse_block_statement(Parser &P, const Tok &t) {
    bool is_if = is_word(t, "if");
    Tok word = t;  // (the block takes the lines after this one's)
    word.s = is_if ? "if" : "while";
    Stmt *s = new_stmt(P, is_if ? ST_IF : ST_WHILE, word);
    if (!s) return NULL;
    P.pos++;
    // the condition and statements of the block; of an if, of each elseif too (a branch each)
    Array<Expr *> conds;
    Array<Stmt *> branches;
    conds.init();
    branches.init();
    const char *stop = NULL;
    bool ok = true;
    do {
        if (stop) P.pos++;  // (past 'elseif')
        Stmt *b = is_if ? new_stmt(P, ST_BRANCH, cur(P)) : s;
        ok = b && cur(P).kind != T_NL;
        if (b && !ok) syn(P, cur(P), "'%s' needs a condition", stop ? stop : word.s);
        Expr *cond = ok ? parse_expr(P) : NULL;
        ok = cond && conds.push(P.c, cond) && (!is_if || branches.push(P.c, b));
        if (ok && is_word(cur(P), "then")) P.pos += is_if;
        ok = ok && !end_of_line(P);
        if (ok && ++P.blocks > P.maxnest) {
            char msg[160];
            syn(P, word, "%s", nest_message(msg, sizeof msg, "blocks", P.maxnest, P.base));
            ok = false;
        }
        if (P.blocks > P.peak) P.peak = P.blocks;
        ok = ok && parse_body(P, &b->body, &b->nbody, &stop);
        P.blocks -= ok;
    } while (ok && is_if && stop && strcmp(stop, "elseif") == 0);
    P.blocks++;  // (the else's statements, if any, and the end of the block)
    if (ok) {
        s->args = freeze_list(P, conds);
        s->nargs = conds.n;
        if (is_if) s->body = freeze_stmts(P, branches), s->nbody = branches.n;
        ok = s->args && s->body;
    }
    conds.release(P.c);
    branches.release(P.c);
    if (!ok) return NULL;
    if (is_if && stop && strcmp(stop, "else") == 0) {
        P.pos++;
        if (end_of_line(P) || !parse_body(P, &s->els, &s->nels, &stop)) return NULL;
    }
    const char *want = is_if ? "endif" : "endwhile";
    if (!stop || strcmp(stop, want) != 0) {
        char msg[200];
        if (stop)
            snprintf(msg, sizeof msg, "'%s' where '%s' was expected to close the '%s' of line %d",
                     stop, want, word.s, word.line);
        else
            snprintf(msg, sizeof msg, "'%s' without '%s'", word.s, want);
        if (stop) syn(P, cur(P), "%s", msg);
        else syn(P, word, "%s", msg);
        return NULL;
    }
    P.pos++;
    P.blocks--;
    return end_of_line(P) ? NULL : s;
}

// The variables of a procedure's body: its parameters (locals[0 .. nparams)), then every name
// the body assigns or deletes, are the call's own; reads of them look there first.
struct Locals {
    Array<int> slots;  // the global slot of each local's name
    int *of;           // by global slot: the local, or -1
};
bool add_local(pray_ctx *c, Locals &L, int slot) {
    if (L.of[slot] >= 0) return true;
    L.of[slot] = L.slots.n;
    return L.slots.push(c, slot);
}
bool collect_locals(pray_ctx *c, Locals &L, Stmt **body, int n) {
    for (int i = 0; i < n; i++) {
        const Stmt *s = body[i];
        if (s->kind == ST_ASSIGN && !add_local(c, L, s->slot)) return false;
        for (int k = 0; s->kind == ST_DELETE && k < s->nargs; k++)
            if (!add_local(c, L, s->args[k]->n)) return false;
        if (!collect_locals(c, L, s->body, s->nbody) || !collect_locals(c, L, s->els, s->nels)) return false;
    }
    return true;
}
void localize(const Locals &L, Expr *e) {
    if (!e) return;
    if (e->kind == EX_VAR && L.of[e->n] >= 0) {
        e->kind = EX_LOCAL;
        e->op = e->n;
        e->n = L.of[e->n];
    }
    localize(L, e->a);
    if (e->b != e->a) localize(L, e->b);
    if (e->c != e->a) localize(L, e->c);
    for (int i = 0; i < e->nargs; i++) localize(L, e->args[i]);
}
void localize(const Locals &L, Stmt **body, int n) {
    for (int i = 0; i < n; i++) {
        Stmt *s = body[i];
        if (s->kind == ST_ASSIGN) {
            s->local = 1;
            s->slot = L.of[s->slot];
        }
        for (int k = 0; k < s->nargs; k++) localize(L, s->args[k]);
        localize(L, s->body, s->nbody);
        localize(L, s->els, s->nels);
    }
}

// define NAME(P1, ..., Pn) ... enddefine, at the top level of a file (t: the word). Checking, it
// makes the procedure known (seen); running, its body is kept for the run (P.keep).
Stmt *parse_define(Parser &P, const Tok &word) {
    Tok t = word;  // (the body takes the lines after this one's)
    if (P.in_proc || P.blocks != P.base) {
        syn(P, t, "'define' stands only at the top level of a file, not inside %s", P.in_proc ? "another define" : "a block");
        return NULL;
    }
    const Tok &nm = P.t[P.pos + 1];
    if (nm.kind != T_NAME) {
        syn(P, nm.kind == T_NL ? t : nm, "'define' takes a name and parameters: define NAME(P1, ..., Pn)");
        return NULL;
    }
    if (is_reserved(nm.s)) {
        syn(P, nm, "'%s' is %s and cannot be defined%s", nm.s, builtin_find(nm.s) ? "a function" : "a reserved word",
            version2_note(nm.s));
        return NULL;
    }
    if (!P.run && var_find(P, nm.s) >= 0) {
        syn(P, nm, "'%s' is the name of a variable and cannot be defined as a procedure", nm.s);
        return NULL;
    }
    int idx = proc_index(P, nm.s);
    if (idx < 0) return NULL;
    if (!P.run && (*P.procs)[idx].seen) {
        const Proc &p = (*P.procs)[idx];
        syn(P, nm, "'%s' is defined twice (first at %s:%d:%d)", nm.s, *ShownPath(p.file), p.line, p.col);
        return NULL;
    }
    P.pos += 2;
    if (expect_op(P, '(', "'(' after the name of the procedure")) return NULL;
    Locals L;
    L.slots.init();
    L.of = NULL;
    bool ok = true;
    while (ok && !is_op(cur(P), ')')) {
        const Tok &a = cur(P);
        int pi = a.kind == T_NAME ? proc_find(P, a.s) : -1;
        char buf[80];
        bool bad = a.kind != T_NAME || is_reserved(a.s) || (pi >= 0 && (*P.procs)[pi].seen);
        if (a.kind != T_NAME) syn(P, a, "expected the name of a parameter, found '%s'", tok_text(a, buf, sizeof buf));
        else if (bad)
            syn(P, a, "'%s' is %s and cannot be a parameter", a.s,
                pi >= 0 ? "a procedure" : builtin_find(a.s) ? "a function" : "a reserved word");
        int slot = bad ? -1 : var_slot(P, a.s);
        for (int i = 0; slot >= 0 && i < L.slots.n; i++)
            if (L.slots[i] == slot) slot = -1, syn(P, a, "'%s' is the name of two parameters", a.s);
        ok = slot >= 0 && L.slots.push(P.c, slot);
        P.pos++;
        if (ok && !is_op(cur(P), ')')) ok = !expect_op(P, ',', "',' or ')' after a parameter");
    }
    int nparams = L.slots.n;
    Stmt *s = ok && !expect_op(P, ')', "')'") && !end_of_line(P) ? new_stmt(P, ST_DEFINE, t) : NULL;
    Stmt **body = NULL;
    int nbody = 0, blocks = P.blocks, peak = P.peak;
    const char *stop = NULL;
    Arena *outer = P.arena;
    if (s) {
        s->slot = idx;
        if (P.run) P.arena = P.keep;
        P.in_proc = 1;
        P.blocks = P.peak = 0;
        ok = parse_body(P, &body, &nbody, &stop);
        P.in_proc = 0;
        P.blocks = blocks;
        P.arena = outer;
    }
    if (s && ok && (!stop || strcmp(stop, "enddefine") != 0)) {
        if (stop) syn(P, cur(P), "'%s' where 'enddefine' was expected to close the 'define' of line %d", stop, t.line);
        else syn(P, t, "'define' without 'enddefine'");
        ok = false;
    }
    if (s && ok) {
        L.of = (int *)mem_alloc(P.c, sizeof(int) * (size_t)(P.vars->list.n + 1));
        for (int i = 0; L.of && i <= P.vars->list.n; i++) L.of[i] = -1;
        for (int i = 0; L.of && i < L.slots.n; i++) L.of[L.slots[i]] = i;
        ok = L.of && collect_locals(P.c, L, body, nbody);
    }
    if (s && ok) {
        localize(L, body, nbody);
        Proc &p = (*P.procs)[idx];
        size_t len = strlen(P.name);
        char *file = (char *)P.names->get(P.c, len + 1);
        ok = file != NULL;
        if (ok) memcpy(file, P.name, len + 1);
        p.file = file;
        p.line = t.line;
        p.col = t.col;
        p.nparams = nparams;
        p.nlocals = L.slots.n;
        p.deep = P.peak;
        p.seen = 1;
        if (P.run) p.body = body, p.nbody = nbody;
        s->body = body;  // (for note_uses)
        s->nbody = nbody;
        P.pos++;
    }
    P.peak = peak;
    mem_free(P.c, L.of);
    L.slots.release(P.c);
    return s && ok && !end_of_line(P) ? s : NULL;
}

// statement -> NAME '=' expr | 'delete' NAME {',' NAME} | 'print' args | 'quit'
//            | 'if' expr ['then'] NL block ['else' NL block] 'endif'
//            | 'while' expr NL block 'endwhile' | 'background' expr [',' expr]
//            | ('perspective' | 'parallel') expr ',' expr ',' expr ',' expr
//            | 'option' expr ',' expr | 'rendertiff' expr {',' expr}
Stmt *parse_statement(Parser &P) {
    Tok &t = cur(P);
    char buf[80];
    if (t.kind != T_NAME) {
        syn(P, t, "expected a statement, found '%s'", tok_text(t, buf, sizeof buf));
        return NULL;
    }
    Stmt *s = NULL;
    if (is_op(P.t[P.pos + 1], '=')) {
        if (is_reserved(t.s)) {
            syn(P, t, "'%s' is a reserved word and cannot be assigned to%s", t.s, version2_note(t.s));
            return NULL;
        }
        int pi = proc_find(P, t.s);
        if (pi >= 0 && (*P.procs)[pi].seen) {
            syn(P, t, "'%s' is a procedure and cannot be assigned to", t.s);
            return NULL;
        }
        s = new_stmt(P, ST_ASSIGN, t);
        if (!s) return NULL;
        s->slot = var_slot(P, t.s);
        P.pos += 2;
        Expr *e = parse_expr(P);
        if (!e || s->slot < 0) return NULL;
        s->args = (Expr **)P.arena->get(P.c, sizeof(Expr *));
        if (!s->args) return NULL;
        s->args[0] = e;
        s->nargs = 1;
        return end_of_line(P) ? NULL : s;
    }
    struct Word {
        const char *w;
        int kind, lo, hi;
    };
    static const Word words[] = {
        {"background", ST_BACKGROUND, 1, 2}, {"delete", ST_DELETE, 1, 1 << 20},
        {"lookat", ST_LOOKAT, 4, 4},
        {"option", ST_OPTION, 2, 2},         {"parallel", ST_PARALLEL, 4, 4},
        {"perspective", ST_PERSPECTIVE, 4, 4}, {"print", ST_PRINT, 0, 1 << 20},
        {"quit", ST_QUIT, 0, 0},             {"rendertiff", ST_RENDER, 1, 1 << 20},
    };
    for (size_t i = 0; i < sizeof words / sizeof words[0]; i++) {
        if (strcmp(t.s, words[i].w) != 0) continue;
        s = new_stmt(P, words[i].kind, t);
        if (!s) return NULL;
        P.pos++;
        // 'delete' takes names: a function's or a constant's name is not read as a value
        for (int k = P.pos, depth = 0; s->kind == ST_DELETE && P.t[k].kind != T_NL; k++) {
            const Tok &a = P.t[k];
            if (a.kind == T_OP && strchr("([{", a.op)) depth++;
            if (a.kind == T_OP && strchr(")]}", a.op)) depth--;
            bool first = k == P.pos || (depth == 0 && is_op(P.t[k - 1], ','));
            if (first && a.kind == T_NAME && is_reserved(a.s)) {
                syn(P, a, "'%s' is %s, not a variable: only variables can be deleted", a.s,
                    builtin_find(a.s) ? "a function" : "a reserved word");
                return NULL;
            }
        }
        if (!stmt_args(P, s, t, words[i].lo, words[i].hi)) return NULL;
        if (s->kind == ST_DELETE)
            for (int k = 0; k < s->nargs; k++)
                if (s->args[k]->kind != EX_VAR) {
                    perr(P.c, P.name, s->args[k]->line, s->args[k]->col, PRAY_ERR_SYNTAX,
                         "'delete' takes variable names");
                    return NULL;
                }
        return end_of_line(P) ? NULL : s;
    }
    if (is_word(t, "include") && P.in_proc) {
        syn(P, t, "'include' is not allowed in the body of a procedure");
        return NULL;
    }
    if (is_word(t, "include")) {
        P.includes = 1;
        return parse_include(P, t);
    }
    if (is_word(t, "if") || is_word(t, "while")) return parse_block_statement(P, t);
    if (is_word(t, "define")) return parse_define(P, t);
    if (is_word(t, "return")) {
        if (!P.in_proc) {
            syn(P, t, "'return' outside the body of a procedure");
            return NULL;
        }
        s = new_stmt(P, ST_RETURN, t);
        P.pos++;
        return s && stmt_args(P, s, t, 0, 1) && !end_of_line(P) ? s : NULL;
    }
    if (!is_reserved(t.s) && is_op(P.t[P.pos + 1], '(')) {  // a call of a procedure, as a statement
        s = new_stmt(P, ST_CALL, t);
        if (!s) return NULL;
        P.pos++;
        Expr *e = parse_pcall(P, t);
        s->args = e ? (Expr **)P.arena->get(P.c, sizeof(Expr *)) : NULL;
        if (!s->args) return NULL;
        s->args[0] = e;
        s->nargs = 1;
        return end_of_line(P) ? NULL : s;
    }
    if (block_end(P)) {
        syn(P, t, "'%s' without a matching '%s'", t.s, block_opener(t.s));
        return NULL;
    }
    if (is_word(t, "then")) {
        syn(P, t, "'then' belongs on the line of its 'if'");
        return NULL;
    }
    if (P.t[P.pos + 1].kind == T_NL && !is_reserved(t.s)) {
        char msg[320];
        snprintf(msg, sizeof msg, "'%s' alone is not a statement (did you mean an assignment '%s = ...'?)",
                 *Shown(t.s), *Shown(t.s));
        syn(P, t, "%s", msg);
        return NULL;
    }
    Suggest sg;
    sg.init(t.s);
    static const char *const stmts[] = {"background", "delete", "include", "lookat", "option", "parallel",
                                        "perspective", "print", "quit", "rendertiff", "if", "while"};
    for (size_t i = 0; i < sizeof stmts / sizeof stmts[0]; i++) sg.offer(stmts[i]);
    char msg[200];
    if (sg.best) snprintf(msg, sizeof msg, "unknown statement '%s'; did you mean '%s'?", t.s, sg.best);
    else snprintf(msg, sizeof msg, "expected a statement or an assignment, found '%s'", t.s);
    syn(P, t, "%s", msg);
    return NULL;
}

// block -> { statement NL }  up to 'else', 'endif', 'endwhile' or the end of the file
bool parse_block(Parser &P, Array<Stmt *> *out, const char **stop) {
    *stop = NULL;
    for (;;) {
        Tok &t = cur(P);
        if (t.kind == T_EOF) return true;
        if (t.kind == T_NL) {
            if (next_line(P)) return false;
            continue;
        }
        if ((*stop = block_end(P)) != NULL) return true;
        Stmt *s = parse_statement(P);
        if (!s || !out->push(P.c, s)) return false;
    }
}

} // namespace

// =============================================================================================
// [SECTION] 14 PRAY interpreter: values, operators, builtins, statements
// =============================================================================================
namespace {

enum { V_NONE, V_NUM, V_POINT, V_VECTOR, V_INTENS, V_LIGHT, V_MODEL, V_OBJECT, V_STRING };
const char *const TYPE_NAMES[] = {"nothing", "number", "point", "vector", "intensity",
                                  "light", "model", "object", "string"};

struct Str {
    Handle h;
    int n;
    char *s;
};

struct Value {
    int t;
    double v[3];
    void *ref;  // light, model, object or string
};

struct NameCount {
    char *name;
    int frames;
};

// A file being read: the program, or a file an `include` named.
struct IncFile {
    char *name;  // (owned, except the program's)
    FileId id;
    int line;    // the line of the include statement reading the next file
};

struct Interp {
    pray_ctx *c;
    const char *name;  // the file being read: the program, or an included file
    const char *prog;  // the program's name (its frames are named after it)
    Parser *parser;    // the program's: names of variables and their hash, maxnest, maxstring
    Array<IncFile> files;  // the files being read: [0] the program, then each included one
    int include_last;  // the last statement of the top level with an include in it, -1: none
    int depth;         // the blocks and includes around the statement running (option maxnest)
    int chained;       // the error's message has the places of the includes that led to it
    Names vars;
    Array<Value> vals;  // by variable slot
    // Values no statement after will use are released (release_dead): last[slot] is the last
    // statement of the top level that names the slot; `order` the slots by it, `dead` how many of
    // them are released; dropped[slot]: released so (still a name with a value, for messages).
    Array<int> last, order;
    Array<unsigned char> dropped;
    int dead;
    const void *top;  // the statement of the top level running now, and its number
    int top_index;
    double steps;
    unsigned ticks;  // statements, for a look at the clock every 1024 (option maxtime)
    int quit;
    int frames;
    Array<NameCount> names;  // output names used so far, and their frames
    int warned_aspect;       // the run has said that its pixels are not square
    Array<Proc> procs;       // the procedures, by the index calls name them with
    Value *frame;            // the locals of the call running, NULL at the top level
    Value ret;               // what `return` gave, while `returning`
    int returning;
    int called;              // the error's message has the places of this many calls that led to it
    size_t chain_end;        // where the eighth of them ends in the message
};

Value vnum(double x) {
    Value v;
    memset(&v, 0, sizeof v);
    v.t = V_NUM;
    v.v[0] = x;
    return v;
}
Value vtriple(int t, double x, double y, double z) {
    Value v = vnum(x);
    v.t = t;
    v.v[1] = y;
    v.v[2] = z;
    return v;
}
Value vref(int t, void *ref) {  // takes over the reference
    Value v = vnum(0);
    v.t = t;
    v.ref = ref;
    return v;
}
pray_vec vec_of(const Value &v) { return vmake(v.v[0], v.v[1], v.v[2]); }
pray_rgb rgb_of(const Value &v) { return cmake(v.v[0], v.v[1], v.v[2]); }
Value of_vec(int t, pray_vec p) { return vtriple(t, p.x, p.y, p.z); }
Value of_rgb(pray_rgb c) { return vtriple(V_INTENS, c.r, c.g, c.b); }

void vrelease(Interp &I, Value &v) {
    if (v.ref) release_handle(I.c, v.ref);
    v.ref = NULL;
    v.t = V_NONE;
}

pray_status rerr(Interp &I, const Expr *e, pray_status s, const char *fmt, ...) PRAY_PRINTF(4, 5);
pray_status rerr(Interp &I, const Expr *e, pray_status s, const char *fmt, ...) {
    va_list ap;
    va_start(ap, fmt);
    char tmp[800];
    vsnprintf(tmp, sizeof tmp, fmt, ap);
    va_end(ap);
    return perr(I.c, I.name, e->line, e->col, s, "%s", tmp);
}

// An API call failed: put the place in front of its message.
PRAY_NOINLINE pray_status api_err(Interp &I, int line, int col) {
    pray_ctx *c = I.c;
    char tmp[1024];
    const char *m = c->msg;
    if (strncmp(m, "error: ", 7) == 0) m += 7;
    snprintf(tmp, sizeof tmp, "%s", m);
    pray_status s = c->status == PRAY_ERR_ARG ? PRAY_ERR_RUNTIME : c->status;
    if (s == PRAY_OK) s = PRAY_ERR_RUNTIME;
    return perr(c, I.name, line, col, s, "%s", tmp);
}

Str *str_new(pray_ctx *c, const char *s, size_t n) {
    if (n > 1u << 24) {
        fail(c, PRAY_ERR_LIMIT, "string longer than %u bytes", 1u << 24);
        return NULL;
    }
    Str *p = (Str *)handle_new(c, sizeof(Str), H_STRING);
    if (!p) return NULL;
    p->s = mem_strdup(c, s, n);
    if (!p->s) {
        mem_free(c, p);
        return NULL;
    }
    p->n = (int)n;
    return p;
}

void fmt_num(char *buf, size_t n, double x) {
    if (x == 0) x = 0;  // no "-0"
    snprintf(buf, n, "%g", x);
}

// Text of a value other than a string as `print` writes it.
void value_short(const Value &v, char *buf, size_t n) {
    switch (v.t) {
    case V_NUM: fmt_num(buf, n, v.v[0]); break;
    case V_POINT:
    case V_VECTOR:
    case V_INTENS: {
        char a[40], b[40], d[40];
        fmt_num(a, sizeof a, v.v[0]);
        fmt_num(b, sizeof b, v.v[1]);
        fmt_num(d, sizeof d, v.v[2]);
        const char *o = v.t == V_POINT ? "[" : v.t == V_VECTOR ? "<" : "{";
        const char *e = v.t == V_POINT ? "]" : v.t == V_VECTOR ? ">" : "}";
        snprintf(buf, n, "%s%s, %s, %s%s", o, a, b, d, e);
        break;
    }
    case V_OBJECT: {
        long k = ((pray_object *)v.ref)->nprims;
        snprintf(buf, n, "object (%ld primitive%s)", k, k == 1 ? "" : "s");
        break;
    }
    case V_LIGHT: {
        int k = ((pray_light *)v.ref)->n;
        snprintf(buf, n, "light (%d source%s)", k, k == 1 ? "" : "s");
        break;
    }
    case V_MODEL: snprintf(buf, n, "model"); break;
    case V_STRING: snprintf(buf, n, "a string"); break;
    default: snprintf(buf, n, "nothing"); break;
    }
}

// Text of a value as `print` writes it.
bool value_text(pray_ctx *c, const Value &v, Text *out) {
    if (v.t == V_STRING) return out->add(c, ((Str *)v.ref)->s, (size_t)((Str *)v.ref)->n);
    char buf[128];
    value_short(v, buf, sizeof buf);
    return out->adds(c, buf);
}

pray_status eval(Interp &I, const Expr *e, Value *out);

// ---- builtins ----
typedef pray_status (*BuiltinFn)(Interp &I, const Expr *call, Value *a, Value *out);
struct Builtin {
    const char *name;
    int lo, hi;
    BuiltinFn fn;
};

pray_status want(Interp &I, const Expr *call, Value *a, int i, int type) {
    if (a[i].t == type) return PRAY_OK;
    return rerr(I, call->args[i], PRAY_ERR_RUNTIME, "%s: argument %d must be %s %s, not %s %s", call->s,
                i + 1, type == V_INTENS || type == V_OBJECT ? "an" : "a", TYPE_NAMES[type],
                a[i].t == V_INTENS || a[i].t == V_OBJECT ? "an" : "a", TYPE_NAMES[a[i].t]);
}

// Wrap the handle an API call returned, or report its error at the call.
pray_status made(Interp &I, const Expr *call, int type, void *h, Value *out) {
    if (!h) return api_err(I, call->line, call->col);
    *out = vref(type, h);
    return PRAY_OK;
}

pray_status math1(Interp &I, const Expr *call, Value *a, Value *out, double (*f)(double)) {
    if (want(I, call, a, 0, V_NUM)) return I.c->status;
    *out = vnum(f(a[0].v[0]));
    return PRAY_OK;
}

pray_status bi_abs(Interp &I, const Expr *call, Value *a, Value *out) {
    if (a[0].t == V_VECTOR) {
        *out = vnum(vlen(vec_of(a[0])));
        return PRAY_OK;
    }
    return math1(I, call, a, out, fabs);
}
pray_status bi_arccos(Interp &I, const Expr *call, Value *a, Value *out) {
    if (a[0].t == V_NUM && fabs(a[0].v[0]) > 1)
        return rerr(I, call, PRAY_ERR_RUNTIME, "arccos of %g: the argument must lie in [-1, 1]", a[0].v[0]);
    return math1(I, call, a, out, acos);
}
pray_status bi_arcsin(Interp &I, const Expr *call, Value *a, Value *out) {
    if (a[0].t == V_NUM && fabs(a[0].v[0]) > 1)
        return rerr(I, call, PRAY_ERR_RUNTIME, "arcsin of %g: the argument must lie in [-1, 1]", a[0].v[0]);
    return math1(I, call, a, out, asin);
}
pray_status bi_arctan(Interp &I, const Expr *call, Value *a, Value *out) { return math1(I, call, a, out, atan); }
pray_status bi_arctan2(Interp &I, const Expr *call, Value *a, Value *out) {
    if (want(I, call, a, 0, V_NUM) || want(I, call, a, 1, V_NUM)) return I.c->status;
    *out = vnum(atan2(a[0].v[0], a[1].v[0]));
    return PRAY_OK;
}
pray_status bi_color(Interp &I, const Expr *call, Value *a, Value *out) {
    if (want(I, call, a, 0, V_INTENS)) return I.c->status;
    return made(I, call, V_MODEL, pray_color(I.c, rgb_of(a[0])), out);
}
pray_status bi_cos(Interp &I, const Expr *call, Value *a, Value *out) { return math1(I, call, a, out, cos); }
pray_status bi_cylinder(Interp &I, const Expr *call, Value *a, Value *out) {
    if (want(I, call, a, 0, V_MODEL) || want(I, call, a, 1, V_POINT) || want(I, call, a, 2, V_VECTOR) ||
        want(I, call, a, 3, V_NUM))
        return I.c->status;
    return made(I, call, V_OBJECT,
                pray_cylinder(I.c, (pray_model *)a[0].ref, vec_of(a[1]), vec_of(a[2]), a[3].v[0]), out);
}
pray_status bi_box(Interp &I, const Expr *call, Value *a, Value *out) {
    if (want(I, call, a, 0, V_MODEL) || want(I, call, a, 1, V_POINT) || want(I, call, a, 2, V_POINT))
        return I.c->status;
    return made(I, call, V_OBJECT, pray_box(I.c, (pray_model *)a[0].ref, vec_of(a[1]), vec_of(a[2])), out);
}
pray_status bi_cone(Interp &I, const Expr *call, Value *a, Value *out) {
    if (want(I, call, a, 0, V_MODEL) || want(I, call, a, 1, V_POINT) || want(I, call, a, 2, V_NUM) ||
        want(I, call, a, 3, V_POINT) || want(I, call, a, 4, V_NUM))
        return I.c->status;
    return made(I, call, V_OBJECT,
                pray_cone(I.c, (pray_model *)a[0].ref, vec_of(a[1]), a[2].v[0], vec_of(a[3]), a[4].v[0]), out);
}
pray_status bi_rod(Interp &I, const Expr *call, Value *a, Value *out) {
    if (want(I, call, a, 0, V_MODEL) || want(I, call, a, 1, V_POINT) || want(I, call, a, 2, V_POINT) ||
        want(I, call, a, 3, V_NUM))
        return I.c->status;
    return made(I, call, V_OBJECT, pray_rod(I.c, (pray_model *)a[0].ref, vec_of(a[1]), vec_of(a[2]), a[3].v[0]), out);
}
pray_status bi_stretch(Interp &I, const Expr *call, Value *a, Value *out) {
    if (want(I, call, a, 0, V_OBJECT) || want(I, call, a, 1, V_VECTOR)) return I.c->status;
    return made(I, call, V_OBJECT, pray_stretch(I.c, (pray_object *)a[0].ref, vec_of(a[1])), out);
}
pray_status bi_torus(Interp &I, const Expr *call, Value *a, Value *out) {
    if (want(I, call, a, 0, V_MODEL) || want(I, call, a, 1, V_POINT) || want(I, call, a, 2, V_VECTOR) ||
        want(I, call, a, 3, V_NUM) || want(I, call, a, 4, V_NUM))
        return I.c->status;
    return made(I, call, V_OBJECT,
                pray_torus(I.c, (pray_model *)a[0].ref, vec_of(a[1]), vec_of(a[2]), a[3].v[0], a[4].v[0]), out);
}
pray_status bi_dirlight(Interp &I, const Expr *call, Value *a, Value *out) {
    if (want(I, call, a, 0, V_INTENS) || want(I, call, a, 1, V_VECTOR)) return I.c->status;
    return made(I, call, V_LIGHT, pray_dirlight(I.c, rgb_of(a[0]), vec_of(a[1])), out);
}
pray_status bi_exp(Interp &I, const Expr *call, Value *a, Value *out) { return math1(I, call, a, out, exp); }
pray_status bi_log(Interp &I, const Expr *call, Value *a, Value *out) {
    if (a[0].t == V_NUM && !(a[0].v[0] > 0))
        return rerr(I, call, PRAY_ERR_RUNTIME, "log of %g: the argument must be positive", a[0].v[0]);
    return math1(I, call, a, out, log);
}
pray_status bi_mirror(Interp &I, const Expr *call, Value *a, Value *out) {
    if (want(I, call, a, 0, V_INTENS)) return I.c->status;
    return made(I, call, V_MODEL, pray_mirror(I.c, rgb_of(a[0])), out);
}
pray_status bi_norm(Interp &I, const Expr *call, Value *a, Value *out) {
    if (want(I, call, a, 0, V_VECTOR)) return I.c->status;
    double m = vmaxabs(vec_of(a[0]));
    if (m == 0) return rerr(I, call, PRAY_ERR_RUNTIME, "norm of a zero vector");
    if (!finite_num(m)) return rerr(I, call, PRAY_ERR_RUNTIME, "norm of a vector that is not finite");
    *out = of_vec(V_VECTOR, vunit(vec_of(a[0])));
    return PRAY_OK;
}
pray_status bi_one(Interp &I, const Expr *call, Value *a, Value *out) {
    if (want(I, call, a, 0, V_MODEL)) return I.c->status;
    return made(I, call, V_OBJECT, pray_one(I.c, (pray_model *)a[0].ref), out);
}
pray_status bi_phong(Interp &I, const Expr *call, Value *a, Value *out) {
    int n = call->nargs;
    for (int i = 0; i < n - 1; i++)
        if (want(I, call, a, i, V_INTENS)) return I.c->status;
    if (want(I, call, a, n - 1, V_NUM)) return I.c->status;
    pray_rgb amb = n == 4 ? rgb_of(a[2]) : cmake(0, 0, 0);
    return made(I, call, V_MODEL, pray_phong(I.c, rgb_of(a[0]), rgb_of(a[1]), amb, a[n - 1].v[0]), out);
}
pray_status bi_plane(Interp &I, const Expr *call, Value *a, Value *out) {
    if (want(I, call, a, 0, V_MODEL) || want(I, call, a, 1, V_POINT) || want(I, call, a, 2, V_VECTOR))
        return I.c->status;
    return made(I, call, V_OBJECT, pray_plane(I.c, (pray_model *)a[0].ref, vec_of(a[1]), vec_of(a[2])), out);
}
pray_status bi_spotlight(Interp &I, const Expr *call, Value *a, Value *out) {
    if (want(I, call, a, 0, V_INTENS) || want(I, call, a, 1, V_POINT) || want(I, call, a, 2, V_VECTOR) ||
        want(I, call, a, 3, V_NUM) || want(I, call, a, 4, V_NUM))
        return I.c->status;
    return made(I, call, V_LIGHT, pray_spotlight(I.c, rgb_of(a[0]), vec_of(a[1]), vec_of(a[2]), a[3].v[0], a[4].v[0]), out);
}
pray_status bi_checker(Interp &I, const Expr *call, Value *a, Value *out) {
    if (want(I, call, a, 0, V_MODEL) || want(I, call, a, 1, V_MODEL) || want(I, call, a, 2, V_NUM)) return I.c->status;
    return made(I, call, V_MODEL, pray_checker(I.c, (pray_model *)a[0].ref, (pray_model *)a[1].ref, a[2].v[0]), out);
}
pray_status bi_paint(Interp &I, const Expr *call, Value *a, Value *out) {
    if (want(I, call, a, 0, V_OBJECT) || want(I, call, a, 1, V_MODEL)) return I.c->status;
    return made(I, call, V_OBJECT, pray_paint(I.c, (pray_object *)a[0].ref, (pray_model *)a[1].ref), out);
}
pray_status bi_pointlight(Interp &I, const Expr *call, Value *a, Value *out) {
    if (want(I, call, a, 0, V_INTENS) || want(I, call, a, 1, V_POINT)) return I.c->status;
    return made(I, call, V_LIGHT, pray_pointlight(I.c, rgb_of(a[0]), vec_of(a[1])), out);
}
pray_status bi_sin(Interp &I, const Expr *call, Value *a, Value *out) { return math1(I, call, a, out, sin); }
pray_status bi_sphere(Interp &I, const Expr *call, Value *a, Value *out) {
    if (want(I, call, a, 0, V_MODEL) || want(I, call, a, 1, V_POINT) || want(I, call, a, 2, V_NUM))
        return I.c->status;
    return made(I, call, V_OBJECT, pray_sphere(I.c, (pray_model *)a[0].ref, vec_of(a[1]), a[2].v[0]), out);
}
pray_status bi_sqrt(Interp &I, const Expr *call, Value *a, Value *out) {
    if (a[0].t == V_NUM && a[0].v[0] < 0)
        return rerr(I, call, PRAY_ERR_RUNTIME, "sqrt of the negative number %g", a[0].v[0]);
    return math1(I, call, a, out, sqrt);
}
pray_status bi_tan(Interp &I, const Expr *call, Value *a, Value *out) { return math1(I, call, a, out, tan); }
// Halves away from zero (C99's round, which C++98 lacks): x - floor(x) is exact.
double round_half_away(double x) {
    if (x < 0) return -round_half_away(-x);
    double f = floor(x);
    return x - f >= 0.5 ? f + 1 : f;
}
pray_status bi_floor(Interp &I, const Expr *call, Value *a, Value *out) { return math1(I, call, a, out, floor); }
pray_status bi_ceil(Interp &I, const Expr *call, Value *a, Value *out) { return math1(I, call, a, out, ceil); }
pray_status bi_round(Interp &I, const Expr *call, Value *a, Value *out) {
    return math1(I, call, a, out, round_half_away);
}
pray_status bi_min(Interp &I, const Expr *call, Value *a, Value *out) {
    if (want(I, call, a, 0, V_NUM) || want(I, call, a, 1, V_NUM)) return I.c->status;
    *out = vnum(a[1].v[0] < a[0].v[0] ? a[1].v[0] : a[0].v[0]);
    return PRAY_OK;
}
pray_status bi_max(Interp &I, const Expr *call, Value *a, Value *out) {
    if (want(I, call, a, 0, V_NUM) || want(I, call, a, 1, V_NUM)) return I.c->status;
    *out = vnum(a[1].v[0] > a[0].v[0] ? a[1].v[0] : a[0].v[0]);
    return PRAY_OK;
}
pray_status bi_transparent(Interp &I, const Expr *call, Value *a, Value *out) {
    if (want(I, call, a, 0, V_INTENS) || want(I, call, a, 1, V_NUM)) return I.c->status;
    return made(I, call, V_MODEL, pray_transparent(I.c, rgb_of(a[0]), a[1].v[0]), out);
}
pray_status bi_planemap(Interp &I, const Expr *call, Value *a, Value *out) {
    if (want(I, call, a, 0, V_MODEL) || want(I, call, a, 1, V_POINT) || want(I, call, a, 2, V_VECTOR) ||
        want(I, call, a, 3, V_VECTOR) || want(I, call, a, 4, V_VECTOR))
        return I.c->status;
    return made(I, call, V_OBJECT,
                pray_planemap(I.c, (pray_model *)a[0].ref, vec_of(a[1]), vec_of(a[2]), vec_of(a[3]), vec_of(a[4])), out);
}
pray_status bi_spheremap(Interp &I, const Expr *call, Value *a, Value *out) {
    if (want(I, call, a, 0, V_MODEL) || want(I, call, a, 1, V_POINT) || want(I, call, a, 2, V_NUM) ||
        want(I, call, a, 3, V_VECTOR) || want(I, call, a, 4, V_VECTOR))
        return I.c->status;
    return made(I, call, V_OBJECT,
                pray_spheremap(I.c, (pray_model *)a[0].ref, vec_of(a[1]), a[2].v[0], vec_of(a[3]), vec_of(a[4])), out);
}

// A texture named by the program: one the host registered under that name, else a file as
// written, else beside the program. An untrusted program's files are read beside it only
// (open_read). Errors name the call.
pray_texture *program_texture(Interp &I, const Expr *call, const Value &name) {
    pray_ctx *c = I.c;
    const char *path = ((const Str *)name.ref)->s;
    TexName *reg = *name_at(&c->tex_names, path);
    if (reg) {
        retain(reg->tex);
        return reg->tex;
    }
    const char *why = c->untrusted ? untrusted_path_problem(path) : NULL;
    if (why) {
        rerr(I, call, PRAY_ERR_RUNTIME, "untrusted program: '%s' is %s; files are read from the program's "
             "directory only", *Shown(path), why);
        return NULL;
    }
    pray_texture *t = texture_file(c, c->run_dir ? c->run_dir : "", c->run_dir_len, path, c->untrusted ? FIND_CONFINED : FIND_BESIDE);
    if (!t && api_err(I, call->line, call->col) == PRAY_ERR_IO) c->status = PRAY_ERR_RUNTIME;
    return t;
}

pray_status bi_tiff(Interp &I, const Expr *call, Value *a, Value *out) {
    if (want(I, call, a, 0, V_MODEL) || want(I, call, a, 1, V_MODEL) || want(I, call, a, 2, V_STRING))
        return I.c->status;
    pray_texture *t = program_texture(I, call, a[2]);
    if (!t) return I.c->status;
    pray_model *m = pray_tiff(I.c, (pray_model *)a[0].ref, (pray_model *)a[1].ref, t);
    release_handle(I.c, t);
    return made(I, call, V_MODEL, m, out);
}
pray_status bi_tiffbump(Interp &I, const Expr *call, Value *a, Value *out) {
    if (want(I, call, a, 0, V_MODEL) || want(I, call, a, 1, V_NUM) || want(I, call, a, 2, V_STRING))
        return I.c->status;
    pray_texture *t = program_texture(I, call, a[2]);
    if (!t) return I.c->status;
    pray_model *m = pray_tiffbump(I.c, (pray_model *)a[0].ref, a[1].v[0], t);
    release_handle(I.c, t);
    return made(I, call, V_MODEL, m, out);
}
pray_status bi_move(Interp &I, const Expr *call, Value *a, Value *out) {
    if (want(I, call, a, 0, V_MODEL) || want(I, call, a, 1, V_NUM) || want(I, call, a, 2, V_NUM)) return I.c->status;
    return made(I, call, V_MODEL, pray_move(I.c, (pray_model *)a[0].ref, a[1].v[0], a[2].v[0]), out);
}
pray_status bi_text(Interp &I, const Expr *call, Value *a, Value *out) {
    static const int types[8] = {V_MODEL, V_STRING, V_POINT, V_VECTOR, V_VECTOR, V_NUM, V_STRING, V_NUM};
    for (int i = 0; i < 8; i++)
        if (want(I, call, a, i, types[i])) return I.c->status;
    pray_texture *font = NULL;
    if (((const Str *)a[6].ref)->n > 0) {
        font = program_texture(I, call, a[6]);
        if (!font) return I.c->status;
    }
    pray_object *o = pray_text(I.c, (pray_model *)a[0].ref, ((const Str *)a[1].ref)->s, vec_of(a[2]), vec_of(a[3]),
                               vec_of(a[4]), a[5].v[0], font, a[7].v[0]);
    release_handle(I.c, font);
    return made(I, call, V_OBJECT, o, out);
}

// Alphabetical, as in appendix A of the thesis.
const Builtin BUILTINS[] = {
    {"abs", 1, 1, bi_abs},           {"arccos", 1, 1, bi_arccos},
    {"arcsin", 1, 1, bi_arcsin},     {"arctan", 1, 1, bi_arctan},
    {"arctan2", 2, 2, bi_arctan2},   {"box", 3, 3, bi_box},
    {"ceil", 1, 1, bi_ceil},         {"checker", 3, 3, bi_checker},
    {"color", 1, 1, bi_color},
    {"cone", 5, 5, bi_cone},
    {"cos", 1, 1, bi_cos},           {"cylinder", 4, 4, bi_cylinder},
    {"directionlight", 2, 2, bi_dirlight}, {"dirlight", 2, 2, bi_dirlight},
    {"exp", 1, 1, bi_exp},           {"floor", 1, 1, bi_floor},
    {"log", 1, 1, bi_log},           {"max", 2, 2, bi_max},
    {"min", 2, 2, bi_min},
    {"mirror", 1, 1, bi_mirror},     {"move", 3, 3, bi_move},
    {"norm", 1, 1, bi_norm},         {"one", 1, 1, bi_one},
    {"paint", 2, 2, bi_paint},
    {"phong", 3, 4, bi_phong},       {"plane", 3, 3, bi_plane},
    {"planemap", 5, 5, bi_planemap}, {"pointlight", 2, 2, bi_pointlight},
    {"rod", 4, 4, bi_rod},           {"round", 1, 1, bi_round},
    {"sin", 1, 1, bi_sin},           {"sphere", 3, 3, bi_sphere},
    {"spheremap", 5, 5, bi_spheremap}, {"spotlight", 5, 5, bi_spotlight},
    {"sqrt", 1, 1, bi_sqrt},
    {"stretch", 2, 2, bi_stretch},
    {"tan", 1, 1, bi_tan},           {"text", 8, 8, bi_text},
    {"tiff", 3, 3, bi_tiff},         {"tiffbump", 3, 3, bi_tiffbump},
    {"torus", 5, 5, bi_torus},
    {"transparent", 2, 2, bi_transparent},
};
const int NBUILTINS = (int)(sizeof BUILTINS / sizeof BUILTINS[0]);

// The table is in alphabetical order: found by halving (every name of a program is looked up).
const Builtin *builtin_find(const char *name) {
    int lo = 0, hi = NBUILTINS - 1;
    while (lo <= hi) {
        int mid = (lo + hi) / 2, d = strcmp(BUILTINS[mid].name, name);
        if (d == 0) return &BUILTINS[mid];
        if (d < 0) lo = mid + 1;
        else hi = mid - 1;
    }
    return NULL;
}
int builtin_index(const Builtin *b) { return (int)(b - BUILTINS); }
int builtin_min(const Builtin *b) { return b->lo; }
int builtin_max(const Builtin *b) { return b->hi; }
const char *builtin_name(int i) { return BUILTINS[i].name; }
int builtin_count() { return NBUILTINS; }

// ---- operators ----
pray_status type_err(Interp &I, const Expr *e, const char *op, const Value &a, const Value &b) {
    return rerr(I, e, PRAY_ERR_RUNTIME, "cannot apply '%s' to %s and %s", op, TYPE_NAMES[a.t], TYPE_NAMES[b.t]);
}

const char *op_name(int op) {
    switch (op) {
    case OP_EQ2: return "==";
    case OP_LE: return "<=";
    case OP_GE: return ">=";
    case '+': return "+";
    case '-': return "-";
    case '*': return "*";
    case '/': return "/";
    case '%': return "%";
    case '^': return "^";
    case '.': return ".";
    case '=': return "=";
    case '#': return "#";
    case '<': return "<";
    case '>': return ">";
    case '&': return "&";
    case '|': return "|";
    default: return "\\";
    }
}

pray_status bitwise(Interp &I, const Expr *e, double x, double y, Value *out) {
    double ix = x < 0 ? ceil(x) : floor(x), iy = y < 0 ? ceil(y) : floor(y);
    if (fabs(ix) > 2147483647.0 || fabs(iy) > 2147483647.0)
        return rerr(I, e, PRAY_ERR_RUNTIME, "'%s' works on whole numbers up to 2147483647", op_name(e->op));
    long a = (long)ix, b = (long)iy, r;
    if (e->op == '&') r = a & b;
    else if (e->op == '|') r = a | b;
    else r = a ^ b;
    *out = vnum((double)r);
    return PRAY_OK;
}

pray_status transform(Interp &I, const Expr *e, const Value &a, const Value &b, Value *out) {
    Xform f;
    if (b.t == V_NUM) {
        if (b.v[0] == 0 || !finite_num(b.v[0]))
            return rerr(I, e, PRAY_ERR_RUNTIME, "cannot scale by %g", b.v[0]);
        f = xf_scale(b.v[0]);
    } else if (b.t == V_POINT) {
        if (!vfinite(vec_of(b))) return rerr(I, e, PRAY_ERR_RUNTIME, "translation is not finite");
        f = xf_translate(vec_of(b));
    } else if (b.t == V_VECTOR) {
        if (!vfinite(vec_of(b))) return rerr(I, e, PRAY_ERR_RUNTIME, "rotation is not finite");
        f = xf_rotate(vec_of(b));
    } else
        return type_err(I, e, ".", a, b);
    switch (a.t) {
    case V_OBJECT: {
        pray_object *o = obj_transform(I.c, (pray_object *)a.ref, f);
        return o ? (*out = vref(V_OBJECT, o), PRAY_OK) : api_err(I, e->line, e->col);
    }
    case V_LIGHT: {
        pray_light *l = light_transform(I.c, (pray_light *)a.ref, f);
        return l ? (*out = vref(V_LIGHT, l), PRAY_OK) : api_err(I, e->line, e->col);
    }
    case V_POINT: *out = of_vec(V_POINT, xf_point(f, vec_of(a))); return PRAY_OK;
    case V_VECTOR: *out = of_vec(V_VECTOR, xf_dir(f, vec_of(a))); return PRAY_OK;
    default: return type_err(I, e, ".", a, b);
    }
}

pray_status object_op(Interp &I, const Expr *e, int op, const Value &a, const Value &b, Value *out) {
    pray_object *o = csg_op(I.c, op, (pray_object *)a.ref, (pray_object *)b.ref);
    if (!o) return api_err(I, e->line, e->col);
    *out = vref(V_OBJECT, o);
    return PRAY_OK;
}

pray_status concat(Interp &I, const Expr *e, const Value &a, const Value &b, Value *out) {
    Text t;
    t.init();
    bool ok = value_text(I.c, a, &t) && value_text(I.c, b, &t);
    double lim = I.c->cur.opt.v[OPT_MAXSTRING];
    if (ok && t.a.n > lim) {
        t.a.release(I.c);
        return rerr(I, e, PRAY_ERR_LIMIT, "string longer than %.0f byte%s (option maxstring)", lim, lim == 1 ? "" : "s");
    }
    Str *s = ok ? str_new(I.c, t.str(), (size_t)t.a.n) : NULL;
    t.a.release(I.c);
    if (!s) return api_err(I, e->line, e->col);
    *out = vref(V_STRING, s);
    return PRAY_OK;
}

pray_status binop(Interp &I, const Expr *e, const Value &a, const Value &b, Value *out) {
    int op = e->op, ta = a.t, tb = b.t;
    double x = a.v[0], y = b.v[0];
    bool nn = ta == V_NUM && tb == V_NUM;
    switch (op) {
    case '.': return transform(I, e, a, b, out);
    case '^':
        if (!nn) break;
        return *out = vnum(pow(x, y)), PRAY_OK;
    case '*':
        if (nn) return *out = vnum(x * y), PRAY_OK;
        if (ta == V_VECTOR && tb == V_NUM) return *out = of_vec(V_VECTOR, vmul(vec_of(a), y)), PRAY_OK;
        if (ta == V_NUM && tb == V_VECTOR) return *out = of_vec(V_VECTOR, vmul(vec_of(b), x)), PRAY_OK;
        if (ta == V_VECTOR && tb == V_VECTOR) return *out = vnum(vdot(vec_of(a), vec_of(b))), PRAY_OK;
        if (ta == V_INTENS && tb == V_INTENS) return *out = of_rgb(cmul(rgb_of(a), rgb_of(b))), PRAY_OK;
        if (ta == V_INTENS && tb == V_NUM) return *out = of_rgb(cscale(rgb_of(a), y)), PRAY_OK;
        if (ta == V_NUM && tb == V_INTENS) return *out = of_rgb(cscale(rgb_of(b), x)), PRAY_OK;
        if (ta == V_MODEL && (tb == V_NUM || tb == V_INTENS)) {
            pray_rgb f = tb == V_NUM ? cmake(y, y, y) : rgb_of(b);
            return made(I, e, V_MODEL, pray_model_scale(I.c, (pray_model *)a.ref, f), out);
        }
        if (tb == V_MODEL && (ta == V_NUM || ta == V_INTENS)) {
            pray_rgb f = ta == V_NUM ? cmake(x, x, x) : rgb_of(a);
            return made(I, e, V_MODEL, pray_model_scale(I.c, (pray_model *)b.ref, f), out);
        }
        if (ta == V_OBJECT && tb == V_OBJECT) return object_op(I, e, O_INTER, a, b, out);
        break;
    case '/':
        if ((ta == V_NUM || ta == V_VECTOR || ta == V_INTENS) && tb == V_NUM) {
            if (y == 0) return rerr(I, e, PRAY_ERR_RUNTIME, "division by zero");
            *out = a;
            for (int i = 0; i < 3; i++) out->v[i] = a.v[i] / y;
            return PRAY_OK;
        }
        break;
    case '%':
        if (nn) {
            if (y == 0) return rerr(I, e, PRAY_ERR_RUNTIME, "division by zero in '%%'");
            return *out = vnum(fmod(x, y)), PRAY_OK;
        }
        if (ta == V_VECTOR && tb == V_VECTOR) return *out = of_vec(V_VECTOR, vcross(vec_of(a), vec_of(b))), PRAY_OK;
        if (ta == V_OBJECT && tb == V_OBJECT) return object_op(I, e, O_DIFF, a, b, out);
        break;
    case '+':
        if (nn) return *out = vnum(x + y), PRAY_OK;
        if (ta == V_POINT && tb == V_VECTOR) return *out = of_vec(V_POINT, vadd(vec_of(a), vec_of(b))), PRAY_OK;
        if (ta == V_VECTOR && tb == V_POINT) return *out = of_vec(V_POINT, vadd(vec_of(a), vec_of(b))), PRAY_OK;
        if (ta == V_VECTOR && tb == V_VECTOR) return *out = of_vec(V_VECTOR, vadd(vec_of(a), vec_of(b))), PRAY_OK;
        if (ta == V_INTENS && tb == V_INTENS) return *out = of_rgb(cadd(rgb_of(a), rgb_of(b))), PRAY_OK;
        if (ta == V_MODEL && tb == V_MODEL)
            return made(I, e, V_MODEL, pray_model_add(I.c, (pray_model *)a.ref, (pray_model *)b.ref), out);
        if (ta == V_OBJECT && tb == V_OBJECT) return object_op(I, e, O_UNION, a, b, out);
        if (ta == V_LIGHT && tb == V_LIGHT)
            return made(I, e, V_LIGHT, pray_light_add(I.c, (pray_light *)a.ref, (pray_light *)b.ref), out);
        if ((ta == V_STRING && (tb == V_STRING || tb == V_NUM)) || (ta == V_NUM && tb == V_STRING))
            return concat(I, e, a, b, out);
        break;
    case '-':
        if (nn) return *out = vnum(x - y), PRAY_OK;
        if (ta == V_POINT && tb == V_VECTOR) return *out = of_vec(V_POINT, vsub(vec_of(a), vec_of(b))), PRAY_OK;
        if (ta == V_POINT && tb == V_POINT) return *out = of_vec(V_VECTOR, vsub(vec_of(a), vec_of(b))), PRAY_OK;
        if (ta == V_VECTOR && tb == V_VECTOR) return *out = of_vec(V_VECTOR, vsub(vec_of(a), vec_of(b))), PRAY_OK;
        if (ta == V_INTENS && tb == V_INTENS) return *out = of_rgb(cadd(rgb_of(a), cscale(rgb_of(b), -1))), PRAY_OK;
        if (ta == V_OBJECT && tb == V_OBJECT) return object_op(I, e, O_DIFF, a, b, out);
        break;
    case '=':
    case OP_EQ2:
    case '#':
        if (nn) return *out = vnum((x == y) == (op != '#') ? 1 : 0), PRAY_OK;
        if (ta == V_STRING && tb == V_STRING) {
            const Str *p = (const Str *)a.ref, *q = (const Str *)b.ref;
            bool eq = p->n == q->n && memcmp(p->s, q->s, (size_t)p->n) == 0;
            return *out = vnum(eq == (op != '#') ? 1 : 0), PRAY_OK;
        }
        break;
    case '<': if (nn) return *out = vnum(x < y), PRAY_OK; break;
    case '>': if (nn) return *out = vnum(x > y), PRAY_OK; break;
    case OP_LE: if (nn) return *out = vnum(x <= y), PRAY_OK; break;
    case OP_GE: if (nn) return *out = vnum(x >= y), PRAY_OK; break;
    case '&':
        if (nn) return bitwise(I, e, x, y, out);
        if (ta == V_OBJECT && tb == V_OBJECT) return object_op(I, e, O_INTER, a, b, out);
        break;
    case '|':
        if (nn) return bitwise(I, e, x, y, out);
        if (ta == V_OBJECT && tb == V_OBJECT) return object_op(I, e, O_UNION, a, b, out);
        if (ta == V_LIGHT && tb == V_LIGHT)
            return made(I, e, V_LIGHT, pray_light_add(I.c, (pray_light *)a.ref, (pray_light *)b.ref), out);
        break;
    default:  // '\\'
        if (nn) return bitwise(I, e, x, y, out);
        if (ta == V_OBJECT && tb == V_OBJECT) return object_op(I, e, O_DIFF, a, b, out);
        break;
    }
    return type_err(I, e, op_name(op), a, b);
}

// A number, point, vector or intensity with a component that is not finite.
bool not_finite(const Value &v) {
    int n = v.t == V_NUM ? 1 : v.t == V_POINT || v.t == V_VECTOR || v.t == V_INTENS ? 3 : 0;
    for (int i = 0; i < n; i++)
        if (!finite_num(v.v[i])) return true;
    return false;
}

// The rule of all arithmetic: a result that is not finite (an overflow, or a NaN such as
// (-8) ^ 0.5) is an error at the operator or the call that made it, "A op B is not a finite
// number" or "f(A) is not a finite number", with the operands (numbers, points, vectors,
// intensities) as print writes them. So values are finite everywhere else.
pray_status not_finite_err(Interp &I, const Expr *e, const Value *a, int n, const Value &r) {
    bool call = e->kind == EX_CALL;
    char what[600], v[128];
    size_t k = call ? (size_t)snprintf(what, sizeof what, "%s(", e->s) : 0;
    for (int i = 0; i < n && k < 400; i++) {
        value_short(a[i], v, sizeof v);
        if (i > 0 && call) k += (size_t)snprintf(what + k, sizeof what - k, ", ");
        else if (i > 0) k += (size_t)snprintf(what + k, sizeof what - k, " %s ", op_name(e->op));
        k += (size_t)snprintf(what + k, sizeof what - k, "%s", v);
    }
    if (call && k < 400) snprintf(what + k, sizeof what - k, ")");
    return rerr(I, e, PRAY_ERR_RUNTIME, "%s is not a finite %s", what, TYPE_NAMES[r.t]);
}

// Apply the binary operator e to a and b (both released) into out.
pray_status operate(Interp &I, const Expr *e, Value &a, Value &b, Value *out) {
    pray_status st = binop(I, e, a, b, out);
    if (st == PRAY_OK && not_finite(*out)) {
        Value ab[2] = {a, b};
        st = not_finite_err(I, e, ab, 2, *out);
        vrelease(I, *out);
    }
    vrelease(I, a);
    vrelease(I, b);
    return st;
}

pray_status eval_num(Interp &I, const Expr *e, double *x) {
    Value v;
    if (eval(I, e, &v)) return I.c->status;
    if (v.t != V_NUM) {
        pray_status s = rerr(I, e, PRAY_ERR_RUNTIME, "expected a number here, not %s %s",
                             v.t == V_INTENS || v.t == V_OBJECT ? "an" : "a", TYPE_NAMES[v.t]);
        vrelease(I, v);
        return s;
    }
    *x = v.v[0];
    return PRAY_OK;
}

pray_status undefined_var(Interp &I, const Expr *e) {
    Suggest sg;
    sg.init(e->s);
    for (int i = 0; i < I.vars.list.n; i++)
        if (I.vals[i].t != V_NONE || (i < I.dropped.n && I.dropped[i])) sg.offer(I.vars.list[i].name);
    if (sg.best)
        return rerr(I, e, PRAY_ERR_RUNTIME, "undefined variable '%s'; did you mean '%s'?", *Shown(e->s), sg.best);
    return rerr(I, e, PRAY_ERR_RUNTIME, "undefined variable '%s'", *Shown(e->s));
}

pray_status exec_block(Interp &I, Stmt **body, int n);

// An error inside a procedure's body: its message gets the place of each call that led there,
// the innermost first, as an include's (include_chain); past the eighth, how many more.
PRAY_NOINLINE void called_from(Interp &I, const Expr *e) {
    char *m = I.c->msg;
    size_t size = sizeof I.c->msg, n = I.called ? I.chain_end - 1 : strlen(m);  // (before the ')')
    if (++I.called <= 8) {
        snprintf(m + n, size - n, "%scalled from %s:%d:%d)", I.called > 1 ? ", " : " (", *ShownPath(I.name), e->line, e->col);
        I.chain_end = strlen(m);
    } else
        snprintf(m + n, size - n, ", and %d more)", I.called - 8);
}

// A call of a procedure: the arguments are evaluated where the call is, the body runs in a scope
// of its own; *out is what its `return` gave. `want`: the call is a value, so a body that ends
// without one is an error. A `quit` in a body called for a value ends the run from there: the
// evaluations around it unwind with an error status that read_statements takes back.
PRAY_NOINLINE pray_status call_proc(Interp &I, const Expr *e, Value *out, bool want) {
    pray_ctx *c = I.c;
    const Proc &p = I.procs[e->n];
    memset(out, 0, sizeof *out);
    if (!p.defined) return unknown_function(c, PRAY_ERR_RUNTIME, I.name, e->line, e->col, e->s, I.procs, p.seen);
    if (e->nargs != p.nparams)
        return rerr(I, e, PRAY_ERR_RUNTIME, "%s takes %d argument%s, not %d", e->s, p.nparams, p.nparams == 1 ? "" : "s",
                    e->nargs);
    double lim = I.parser->maxnest;
    if (I.depth + e->op + p.deep > lim) {
        char msg[160];
        return rerr(I, e, PRAY_ERR_LIMIT, "%s", nest_message(msg, sizeof msg, "calls", lim, I.depth + e->op - 1));
    }
    Value *frame = (Value *)mem_zalloc(c, sizeof(Value) * (size_t)(p.nlocals + 1));
    if (!frame) return api_err(I, e->line, e->col);
    pray_status st = PRAY_OK;
    for (int i = 0; i < p.nparams && st == PRAY_OK; i++) st = eval(I, e->args[i], &frame[i]);
    if (st == PRAY_OK) {
        Value *outer = I.frame;
        const char *name = I.name;
        I.frame = frame;
        I.name = p.file;
        I.depth += e->op;
        st = exec_block(I, p.body, p.nbody);
        I.frame = outer;
        I.name = name;
        I.depth -= e->op;
        if (st && !I.quit) called_from(I, e);
        else if (I.quit) st = want ? (c->status = PRAY_ERR_RUNTIME) : PRAY_OK;
        else if (I.ret.t == V_NONE && want)
            st = rerr(I, e, PRAY_ERR_RUNTIME, "%s returned no value", e->s);
        *out = I.ret;
        memset(&I.ret, 0, sizeof I.ret);
        I.returning = 0;
        if (st) vrelease(I, *out);
    }
    for (int i = 0; i < p.nlocals; i++) vrelease(I, frame[i]);
    mem_free(c, frame);
    return st;
}

pray_status eval(Interp &I, const Expr *e, Value *out) {
    memset(out, 0, sizeof *out);
    switch (e->kind) {
    case EX_NUM: *out = vnum(e->num); return PRAY_OK;
    case EX_STR: {
        Str *s = str_new(I.c, e->s, (size_t)e->n);
        if (!s) return api_err(I, e->line, e->col);
        *out = vref(V_STRING, s);
        return PRAY_OK;
    }
    case EX_CONST:
        switch (e->n) {
        case C_TRUE: *out = vnum(1); return PRAY_OK;
        case C_FALSE: *out = vnum(0); return PRAY_OK;
        case C_PI: *out = vnum(3.14159265358979323846); return PRAY_OK;
        case C_NOTHING: {
            pray_object *o = pray_nothing(I.c);
            return o ? (*out = vref(V_OBJECT, o), PRAY_OK) : api_err(I, e->line, e->col);
        }
        default: {
            pray_light *l = light_new(I.c, 0);
            return l ? (*out = vref(V_LIGHT, l), PRAY_OK) : api_err(I, e->line, e->col);
        }
        }
    case EX_PCALL: return call_proc(I, e, out, true);
    case EX_LOCAL:
    case EX_VAR: {
        bool local = e->kind == EX_LOCAL && I.frame && I.frame[e->n].t != V_NONE;
        const Value &v = local ? I.frame[e->n] : I.vals[e->kind == EX_LOCAL ? e->op : e->n];
        if (v.t == V_NONE) return undefined_var(I, e);
        *out = v;
        retain(out->ref);
        return PRAY_OK;
    }
    case EX_POINT:
    case EX_VECTOR:
    case EX_INTENS: {
        double x, y, z;
        if (eval_num(I, e->a, &x) || eval_num(I, e->b, &y) || eval_num(I, e->c, &z)) return I.c->status;
        *out = vtriple(e->kind == EX_POINT ? V_POINT : e->kind == EX_VECTOR ? V_VECTOR : V_INTENS, x, y, z);
        return PRAY_OK;
    }
    case EX_CALL: {
        Value args[8];
        int n = e->nargs;
        pray_status st = PRAY_OK;
        int done = 0;
        for (; done < n && st == PRAY_OK; done++) st = eval(I, e->args[done], &args[done]);
        if (st == PRAY_OK) st = BUILTINS[e->n].fn(I, e, args, out);
        if (st == PRAY_OK && not_finite(*out)) {
            st = not_finite_err(I, e, args, n, *out);
            vrelease(I, *out);
        }
        for (int i = 0; i < done; i++) vrelease(I, args[i]);
        return st;
    }
    case EX_UNARY: {
        Value a;
        if (eval(I, e->a, &a)) return I.c->status;
        if (e->op == '-' && a.t == V_OBJECT) {
            pray_object *o = complement_of(I.c, (pray_object *)a.ref);
            vrelease(I, a);
            return o ? (*out = vref(V_OBJECT, o), PRAY_OK) : api_err(I, e->line, e->col);
        }
        if (a.t != V_NUM && a.t != V_VECTOR && a.t != V_INTENS) {
            pray_status s = rerr(I, e, PRAY_ERR_RUNTIME, "cannot apply unary '%c' to %s %s", e->op,
                                 a.t == V_INTENS || a.t == V_OBJECT ? "an" : "a", TYPE_NAMES[a.t]);
            vrelease(I, a);
            return s;
        }
        *out = a;
        if (e->op == '-')
            for (int i = 0; i < 3; i++) out->v[i] = -a.v[i];
        return PRAY_OK;
    }
    case EX_CHAIN: {  // A op B op C ...: from the left, in a loop
        if (eval(I, e->args[0], out)) return I.c->status;
        for (int i = 1; i < e->nargs; i++) {
            Value a = *out, b;
            memset(out, 0, sizeof *out);
            if (eval(I, e->args[i]->b, &b)) {
                vrelease(I, a);
                return I.c->status;
            }
            if (operate(I, e->args[i], a, b, out)) return I.c->status;
        }
        return PRAY_OK;
    }
    default: {  // binary: '^'
        Value a, b;
        if (eval(I, e->a, &a)) return I.c->status;
        if (eval(I, e->b, &b)) {
            vrelease(I, a);
            return I.c->status;
        }
        return operate(I, e, a, b, out);
    }
    }
}

// ---- statements ----
// The file name of frame `frame`: a run of '#' becomes the zero-padded number; otherwise frames
// after the first get _0001, _0002, ... before the extension.
void frame_name(char *out, size_t n, const char *base, int frame) {
    const char *hash = strchr(base, '#');
    if (hash) {
        int run = 0;
        while (hash[run] == '#') run++;
        snprintf(out, n, "%.*s%0*d%s", (int)(hash - base), base, run, frame, hash + run);
        return;
    }
    if (frame == 0) {
        snprintf(out, n, "%s", base);
        return;
    }
    const char *ext = file_ext(base);
    int keep = ext ? (int)(ext - 1 - base) : (int)strlen(base);
#ifdef PRAY_8_3_NAMES
    // NAME_NNNN stays within 8 characters: the name is cut to 3 after its directory
    const char *dir = base;
    for (const char *q = base; q < base + keep; q++)
        if (*q == '/' || *q == '\\' || *q == ':') dir = q + 1;
    if (keep - (int)(dir - base) > 3) keep = (int)(dir - base) + 3;
#endif
    if (ext) snprintf(out, n, "%.*s_%04d.%s", keep, base, frame, ext);
    else snprintf(out, n, "%.*s_%04d", keep, base, frame);
}

// A warning at statement s: "name:line:col: warning: text".
void warn(Interp &I, const Stmt *s, const char *text) {
    pray_ctx *c = I.c;
    if (!c->warn_fn) return;
    char line[400];
    int n = snprintf(line, sizeof line, "%s:%d:%d: warning: %s\n", *ShownPath(I.name), s->line, s->col, text);
    if (n > 0) c->warn_fn(c->warn_ud, line, (size_t)n < sizeof line ? (size_t)n : sizeof line - 1);
}

// Once a run: the camera's |X| : |Y| is not the image's width : height, so its pixels are not
// square and the picture comes out stretched (more than 1 % either way). Never for `lookat`,
// whose pixels are square for every size.
void warn_aspect(Interp &I, const Stmt *s) {
    pray_ctx *c = I.c;
    double w = c->cur.opt.v[OPT_WIDTH], h = c->cur.opt.v[OPT_HEIGHT];
    double stretch = vlen(c->cur.cam_x) / vlen(c->cur.cam_y) * h / w;
    if (!c->warn_fn || I.warned_aspect || c->cur.lookat || (stretch < 1.01 && stretch > 1 / 1.01)) return;
    I.warned_aspect = 1;
    char line[400];
    int n = snprintf(line, sizeof line,
                     "%s:%d:%d: warning: the image is %.0f x %.0f pixels but the camera's |X| : |Y| is %.4g : 1, "
                     "so the picture is stretched %s (make |X| / |Y| equal to width / height)\n",
                     *ShownPath(I.name), s->line, s->col, w, h, vlen(c->cur.cam_x) / vlen(c->cur.cam_y),
                     stretch < 1 ? "sideways" : "vertically");
    if (n > 0) c->warn_fn(c->warn_ud, line, (size_t)n < sizeof line ? (size_t)n : sizeof line - 1);
}

PRAY_NOINLINE pray_status exec_render(Interp &I, const Stmt *s, Value *a) {
    pray_ctx *c = I.c;
    if (a[0].t != V_OBJECT)
        return rerr(I, s->args[0], PRAY_ERR_RUNTIME, "rendertiff: the first argument must be an object, not %s %s",
                    a[0].t == V_INTENS ? "an" : "a", TYPE_NAMES[a[0].t]);
    pray_light *all = light_new(c, 0);
    if (!all) return api_err(I, s->line, s->col);
    for (int i = 1; i < s->nargs; i++) {
        if (a[i].t != V_LIGHT) {
            release_handle(c, all);
            return rerr(I, s->args[i], PRAY_ERR_RUNTIME, "rendertiff: argument %d must be a light, not %s %s",
                        i + 1, a[i].t == V_INTENS || a[i].t == V_OBJECT ? "an" : "a", TYPE_NAMES[a[i].t]);
        }
        pray_light *l = light_union(c, all, (pray_light *)a[i].ref);
        release_handle(c, all);
        if (!l) return api_err(I, s->line, s->col);
        all = l;
    }
    double most = c->cur.opt.v[OPT_MAXFRAMES];
    if (most > 0 && I.frames >= most) {
        release_handle(c, all);
        fail(c, PRAY_ERR_LIMIT, "more than %.0f frame%s (option maxframes)", most, most == 1 ? "" : "s");
        return api_err(I, s->line, s->col);
    }
    // the output option, else the program's name with .tif; the frame's name adds _NNNN
    const char *ext = file_ext(I.prog);
    size_t keep = c->cur.opt.output[0] ? strlen(c->cur.opt.output) : ext ? (size_t)(ext - 1 - I.prog) : strlen(I.prog);
    char *base = (char *)mem_alloc(c, keep + 5), *name = base ? (char *)mem_alloc(c, keep + 40) : NULL;
    if (!name) {
        mem_free(c, base);
        release_handle(c, all);
        return api_err(I, s->line, s->col);
    }
    if (c->cur.opt.output[0]) memcpy(base, c->cur.opt.output, keep + 1);
    else snprintf(base, keep + 5, "%.*s.tif", (int)keep, I.prog);
    // frames are numbered per output name: a program that names each image gets those names
    int slot = 0;
    while (slot < I.names.n && strcmp(I.names[slot].name, base) != 0) slot++;
    if (slot == I.names.n) {
        NameCount nc;
        nc.name = mem_strdup(c, base, strlen(base));
        nc.frames = 0;
        if (!nc.name || !I.names.push(c, nc)) {
            mem_free(c, nc.name);
            mem_free(c, base);
            mem_free(c, name);
            release_handle(c, all);
            return api_err(I, s->line, s->col);
        }
    }
    frame_name(name, keep + 40, base, I.names[slot].frames);
    warn_aspect(I, s);
    pray_image img;
    // this reference to the object is given up once the scene is flattened: when no variable
    // holds it any more, its tree is freed before the rest of the scene is built (not when the
    // host renders the frame: it may render the tree more than once, a band at a time)
    c->drop = c->render_fn ? NULL : (pray_object *)a[0].ref;
    c->eye_inside = c->no_light = 0;
    pray_status st = pray_render(c, (pray_object *)a[0].ref, all, &img);
    if (st == PRAY_OK && c->eye_inside) warn(I, s, "the eye is inside the rendered solid");
    if (st == PRAY_OK && c->no_light) warn(I, s, "no light reaches anything the eye sees");
    if (c->drop == NULL && !c->render_fn) a[0].ref = NULL, a[0].t = V_NONE;
    c->drop = NULL;
    release_handle(c, all);
    if (st) {
        mem_free(c, base);
        mem_free(c, name);
        return api_err(I, s->line, s->col);
    }
    if (c->frame_fn) st = c->frame_fn(c->frame_ud, &img, name);
    else st = pray_write_image(c, &img, name, opt_int(c, OPT_BITS));
    pray_image_free(c, &img);
    mem_free(c, base);
    mem_free(c, name);
    if (st) {
        if (c->frame_fn && c->msg[0] == 0) fail(c, st, "frame callback failed");
        pray_status keep = c->status;
        api_err(I, s->line, s->col);
        return c->status = keep == PRAY_ERR_ARG ? PRAY_ERR_RUNTIME : keep;
    }
    I.names[slot].frames++;
    I.frames++;
    c->frames = I.frames;
    return PRAY_OK;
}

void print_out(pray_ctx *c, const char *s, size_t n) {
    if (c->print_set) {
        if (c->print_fn) c->print_fn(c->print_ud, s, n);
        return;
    }
#if PRAY_HAS_STDIO
    fwrite(s, 1, n, stdout);
#endif
}

pray_status exec_block(Interp &I, Stmt **body, int n);

// Release the values of the variables that no statement after the top level's statement k names.
void release_dead(Interp &I, int k) {
    while (I.dead < I.order.n && I.last[I.order[I.dead]] <= k) {
        int slot = I.order[I.dead++];
        if (slot < I.vals.n && I.vals[slot].t != V_NONE) {
            vrelease(I, I.vals[slot]);
            I.dropped[slot] = 1;
        }
    }
}

pray_status step(Interp &I, const Stmt *s) {
    if ((++I.ticks & 1023) == 0 ? over_time(I.c) : cancelled(I.c)) {
        char buf[80];
        return perr(I.c, I.name, s->line, s->col, cancel_status(I.c), "%s", cancel_text(I.c, buf, sizeof buf));
    }
    I.steps += 1;
    double lim = I.c->cur.opt.v[OPT_MAXSTEPS];
    if (lim > 0 && I.steps > lim)
        return perr(I.c, I.name, s->line, s->col, PRAY_ERR_LIMIT,
                    "the program was stopped after %.0f statement%s (option maxsteps)", lim, lim == 1 ? "" : "s");
    return PRAY_OK;
}

pray_status read_statements(Parser &P, const char *text, size_t len, Interp *I, bool run, double *parse_time);
#if PRAY_HAS_STDIO
bool read_program(pray_ctx *c, FILE *f, Text *t);
#endif

// An error inside an included file: its message gets the place of each include that led there,
// the innermost first: "b.ray:3:1: error: ... (included from a.ray:2, included from main.ray:7)".
PRAY_NOINLINE void include_chain(Interp &I) {
    if (I.chained) return;
    I.chained = 1;
    char *m = I.c->msg;
    size_t n = strlen(m), size = sizeof I.c->msg;
    bool open = I.called && n > 0 && m[n - 1] == ')';  // after the calls' places, in their parentheses
    n -= open;
    for (int i = I.files.n - 2; i >= 0 && n + 1 < size; i--)
        n += (size_t)snprintf(m + n, size - n, "%sincluded from %s:%d%s", i == I.files.n - 2 && !open ? " (" : ", ",
                              *ShownPath(I.files[i].name), I.files[i].line, i == 0 ? ")" : "");
}

// File `path` is being read already, as I.files[loop]: a file that includes itself.
PRAY_NOINLINE pray_status include_loop(Interp &I, const char *path, int loop) {
    bool through = loop < I.files.n - 1;
    return fail(I.c, PRAY_ERR_RUNTIME, "'%s' includes itself%s%s%s", *ShownPath(path), through ? " through '" : "",
                through ? *ShownPath(I.files[loop + 1].name) : "", through ? "'" : "");
}

// Reading a file costs the run a statement (option maxsteps) for each of its lines, however few
// statements they hold: an include of a long file in a loop is bounded as its statements are.
pray_status include_steps(Interp &I, const char *text, size_t n) {
    double lines = n > 0 && text[n - 1] != '\n' ? 1 : 0;
    for (const char *p = text; (p = (const char *)memchr(p, '\n', n - (size_t)(p - text))) != NULL; p++) lines++;
    I.steps += lines;
    double lim = I.c->cur.opt.v[OPT_MAXSTEPS];
    if (lim > 0 && I.steps > lim)
        return fail(I.c, PRAY_ERR_LIMIT, "the program was stopped after %.0f statement%s (option maxsteps; each line "
                    "an include reads counts as one)", lim, lim == 1 ? "" : "s");
    return PRAY_OK;
}

#if !PRAY_HAS_STDIO
inline bool same_id(const FileId &, const FileId &) { return false; }  // (includes are the host's texts)
#endif

// The file include "F" names, opened beside the file naming it: *path its name as opened, *id its
// identity, its text into *t (NULL: the file is not open, c->status says why).
FILE *include_file(Interp &I, const Expr *f, char **path, FileId *id, Text *t) {
#if !PRAY_HAS_STDIO
    (void)path, (void)id, (void)t;
    rerr(I, f, PRAY_ERR_RUNTIME, "include: this build has no file access");
    return NULL;
#else
    pray_ctx *c = I.c;
    // the name beside the including file; an untrusted program's, from the program's directory (a
    // text the host registered is beside its name, which must then obey the same rules)
    bool in_dir = c->untrusted && c->run_dir && strncmp(I.name, c->run_dir, c->run_dir_len) == 0;
    size_t dlen = 0, from = in_dir ? c->run_dir_len : 0;
    for (size_t i = 0; I.name[i]; i++)
        if (I.name[i] == '/' || I.name[i] == '\\' || I.name[i] == ':') dlen = i + 1;
    bool relative = f->s[0] && f->s[0] != '/' && f->s[0] != '\\' && f->s[1] != ':';
    if (!relative || from > dlen) dlen = from = 0;
    size_t n = strlen(f->s);
    char *rel = (char *)mem_alloc(c, dlen - from + n + 1);
    if (!rel) return NULL;
    memcpy(rel, I.name + from, dlen - from);
    memcpy(rel + dlen - from, f->s, n + 1);
    const char *named = untrusted_path_problem(f->s) ? f->s : rel, *why = c->untrusted ? untrusted_path_problem(named) : NULL;
    if (why) {
        rerr(I, f, PRAY_ERR_RUNTIME, "untrusted program: '%s' is %s; files are read from the program's "
             "directory only", *Shown(named), why);
        return mem_free(c, rel), (FILE *)NULL;
    }
    FILE *in = c->untrusted ? open_read(c, c->run_dir, c->run_dir_len, rel, FIND_CONFINED, path, id)
                            : open_read(c, "", 0, rel, FIND_AS_NAMED, path, id);
    mem_free(c, rel);
    if (in && (!read_program(c, in, t) || (ferror(in) && fail(c, PRAY_ERR_IO, "cannot read '%s'", *ShownPath(*path)))))
        fclose(in), in = NULL;
    return in;
#endif
}

// include "F": the statements of the text the host registered as F, else of file F read beside
// the file that names it, run here as the program's own are (checked whole first, then read and
// run a statement at a time).
PRAY_NOINLINE pray_status exec_include(Interp &I, const Stmt *s) {
    pray_ctx *c = I.c;
    const Expr *f = s->args[0];
    if (I.depth + 1 > I.parser->maxnest) {
        char msg[160];
        return perr(c, I.name, s->line, s->col, PRAY_ERR_LIMIT, "%s",
                    nest_message(msg, sizeof msg, "includes", I.parser->maxnest, I.depth - (I.files.n - 1)));
    }
    TexName *reg = *name_at(&c->inc_names, f->s);
    char *path = NULL;
    FileId id;
    memset(&id, 0, sizeof id);
    Text t;
    t.init();
    FILE *in = NULL;
    bool ok = reg ? (path = mem_strdup(c, f->s, strlen(f->s))) && t.add(c, reg->text, reg->len)
                  : (in = include_file(I, f, &path, &id, &t)) != NULL;
    if (in) fclose(in);
    int loop = -1;
    for (int i = 0; ok && i < I.files.n && loop < 0; i++)
        if (same_id(id, I.files[i].id) || strcmp(path, I.files[i].name) == 0) loop = i;
    pray_status st = !ok ? c->status : loop >= 0 ? include_loop(I, path, loop) : include_steps(I, t.str(), (size_t)t.a.n);
    IncFile nf;
    nf.name = path;
    nf.id = id;
    nf.line = 0;
    if (st == PRAY_OK && !I.files.push(c, nf)) st = c->status;
    if (st) {  // (a message without a place gets the include's)
        mem_free(c, path);
        t.a.release(c);
        if (strncmp(c->msg, "error: ", 7) == 0 && api_err(I, f->line, f->col) == PRAY_ERR_IO) c->status = PRAY_ERR_RUNTIME;
        return c->status;
    }
    I.files[I.files.n - 2].line = s->line;
    // a parser of its own, on the program's variables (on the heap: includes nest this function)
    struct Reader {
        Arena tree, words;
        Lexer L;
        Parser Q;
    } *r = (Reader *)mem_zalloc(c, sizeof(Reader));
    if (r) {
        r->tree.init();
        r->words.init();
        r->L.c = c;
        r->L.name = path;
        r->L.text = &r->words;
        r->L.toks.init();
        r->L.maxstring = I.parser->L->maxstring;
        r->Q = *I.parser;
        r->Q.name = path;
        r->Q.L = &r->L;
        r->Q.arena = &r->tree;
        r->Q.included = 1;
        r->Q.base = ++I.depth;
        const char *outer = I.name;
        I.name = path;
        double parse_time = 0;
        st = read_statements(r->Q, t.str(), (size_t)t.a.n, &I, false, &parse_time);
        if (st == PRAY_OK) {
            r->tree.reset(c);
            st = read_statements(r->Q, t.str(), (size_t)t.a.n, &I, true, &parse_time);
        }
        c->stats.time_parse += parse_time;
        I.name = outer;
        I.depth--;
        r->L.toks.release(c);
        r->tree.release(c);
        r->words.release(c);
        mem_free(c, r);
    } else
        st = api_err(I, f->line, f->col);
    if (st) include_chain(I);
    I.files.n--;
    mem_free(c, path);
    t.a.release(c);
    return st;
}

pray_status exec(Interp &I, const Stmt *s) {
    if (step(I, s)) return I.c->status;
    pray_ctx *c = I.c;
    switch (s->kind) {
    case ST_INCLUDE:
        if (exec_include(I, s)) include_chain(I);
        return c->status;
    case ST_ASSIGN: {
        Value v;
        if (eval(I, s->args[0], &v)) return c->status;
        Value &to = s->local ? I.frame[s->slot] : I.vals[s->slot];
        vrelease(I, to);
        to = v;
        return PRAY_OK;
    }
    case ST_DELETE:
        for (int i = 0; i < s->nargs; i++) {
            const Expr *e = s->args[i];
            Value &v = e->kind == EX_LOCAL ? I.frame[e->n] : I.vals[e->n];
            if (v.t == V_NONE) return undefined_var(I, e);
            vrelease(I, v);
        }
        return PRAY_OK;
    case ST_QUIT: I.quit = 1; return PRAY_OK;
    case ST_DEFINE: I.procs[s->slot].defined = 1; return PRAY_OK;
    case ST_RETURN: {  // (the value is kept apart until the call takes it: calls in it return too)
        Value v;
        if (s->nargs && eval(I, s->args[0], &v)) return c->status;
        I.ret = s->nargs ? v : I.ret;
        I.returning = 1;
        return PRAY_OK;
    }
    case ST_CALL: {
        Value v;
        pray_status st = call_proc(I, s->args[0], &v, false);
        vrelease(I, v);
        return st;
    }
    case ST_IF: {
        int k = 0;
        for (double x = 0; k < s->nargs && x == 0; k += x == 0)
            if (eval_num(I, s->args[k], &x)) return c->status;
        I.depth++;
        pray_status st = k < s->nargs ? exec_block(I, s->body[k]->body, s->body[k]->nbody) : exec_block(I, s->els, s->nels);
        I.depth--;
        return st;
    }
    case ST_WHILE:
        for (bool first = true;; first = false) {
            if (!first && step(I, s)) return c->status;
            double x;
            if (eval_num(I, s->args[0], &x)) return c->status;
            if (x == 0) return PRAY_OK;
            I.depth++;
            pray_status st = exec_block(I, s->body, s->nbody);
            I.depth--;
            if (st || I.quit || I.returning) return c->status;
        }
    default: break;
    }
    // statements with evaluated arguments
    Value a[8];
    Value *args = a;
    int n = s->nargs;
    if (n > 8) {
        args = (Value *)mem_zalloc(c, sizeof(Value) * (size_t)n);
        if (!args) return api_err(I, s->line, s->col);
    }
    pray_status st = PRAY_OK;
    int done = 0;
    for (; done < n && st == PRAY_OK; done++) st = eval(I, s->args[done], &args[done]);
    if (st == PRAY_OK && s->kind == ST_RENDER && s == I.top) release_dead(I, I.top_index);  // before the render
    if (st == PRAY_OK) {
        switch (s->kind) {
        case ST_PRINT: {
            Text t;
            t.init();
            bool ok = true;
            for (int i = 0; i < n && ok; i++) ok = (i == 0 || t.adds(c, " ")) && value_text(c, args[i], &t);
            if (ok) ok = t.adds(c, "\n");
            if (ok) print_out(c, t.str(), (size_t)t.a.n);
            else st = api_err(I, s->line, s->col);
            t.a.release(c);
            break;
        }
        case ST_BACKGROUND:
            for (int i = 0; i < n && st == PRAY_OK; i++)
                if (args[i].t != V_INTENS)
                    st = rerr(I, s->args[i], PRAY_ERR_RUNTIME, "background takes intensities, not %s %s",
                              args[i].t == V_OBJECT ? "an" : "a", TYPE_NAMES[args[i].t]);
            if (st == PRAY_OK && pray_background(c, rgb_of(args[0]), rgb_of(args[n - 1])))
                st = api_err(I, s->line, s->col);
            break;
        case ST_PERSPECTIVE:
        case ST_PARALLEL: {
            static const int types[4] = {V_VECTOR, V_VECTOR, V_POINT, V_POINT};
            static const char *const what[4] = {"X", "Y", "E", "P"};
            for (int i = 0; i < 4 && st == PRAY_OK; i++)
                if (args[i].t != types[i])
                    st = rerr(I, s->args[i], PRAY_ERR_RUNTIME, "%s: %s must be a %s, not %s %s",
                              s->kind == ST_PARALLEL ? "parallel" : "perspective", what[i], TYPE_NAMES[types[i]],
                              args[i].t == V_INTENS || args[i].t == V_OBJECT ? "an" : "a", TYPE_NAMES[args[i].t]);
            if (st == PRAY_OK &&
                set_camera(c, s->kind == ST_PARALLEL, vec_of(args[0]), vec_of(args[1]), vec_of(args[2]), vec_of(args[3])))
                st = api_err(I, s->line, s->col);
            break;
        }
        case ST_LOOKAT: {
            static const int types[4] = {V_POINT, V_POINT, V_VECTOR, V_NUM};
            static const char *const what[4] = {"E", "P", "U", "a"};
            for (int i = 0; i < 4 && st == PRAY_OK; i++)
                if (args[i].t != types[i])
                    st = rerr(I, s->args[i], PRAY_ERR_RUNTIME, "lookat: %s must be a %s, not %s %s", what[i],
                              TYPE_NAMES[types[i]], args[i].t == V_INTENS || args[i].t == V_OBJECT ? "an" : "a",
                              TYPE_NAMES[args[i].t]);
            if (st == PRAY_OK && pray_lookat(c, vec_of(args[0]), vec_of(args[1]), vec_of(args[2]), args[3].v[0]))
                st = api_err(I, s->line, s->col);
            break;
        }
        case ST_OPTION:
            if (args[0].t != V_STRING)
                st = rerr(I, s->args[0], PRAY_ERR_RUNTIME, "option: the name must be a string, as in option \"width\", 640");
            else {
                const char *nm = ((Str *)args[0].ref)->s;
                if (args[1].t == V_STRING) st = pray_option_string(c, nm, ((Str *)args[1].ref)->s);
                else if (args[1].t == V_NUM) st = pray_option(c, nm, args[1].v[0]);
                else st = fail(c, PRAY_ERR_ARG, "option '%s': the value must be a number or a string", nm);
                if (st) st = api_err(I, s->line, s->col);
            }
            break;
        case ST_RENDER: st = exec_render(I, s, args); break;
        default: break;
        }
    }
    for (int i = 0; i < done; i++) vrelease(I, args[i]);
    if (args != a) mem_free(c, args);
    return st;
}

pray_status exec_block(Interp &I, Stmt **body, int n) {
    for (int i = 0; i < n && !I.quit && !I.returning; i++)
        if (exec(I, body[i])) return I.c->status;
    return PRAY_OK;
}

// The variables that statement k of the top level names (I.last).
bool note_uses(Interp &I, const Expr *e, int k);
bool note_slot(Interp &I, int slot, int k) {
    if (slot >= I.last.n) {
        if (!I.last.reserve(I.c, slot + 1)) return false;
        while (I.last.n <= slot) I.last.p[I.last.n++] = -1;
    }
    if (I.last[slot] < k) I.last[slot] = k;
    return true;
}
bool note_uses(Interp &I, const Expr *e, int k) {
    if (!e) return true;
    if ((e->kind == EX_VAR || e->kind == EX_LOCAL) && !note_slot(I, e->kind == EX_VAR ? e->n : e->op, k)) return false;
    if (!note_uses(I, e->a, k) || (e->b != e->a && !note_uses(I, e->b, k)) || (e->c != e->a && !note_uses(I, e->c, k)))
        return false;
    for (int i = 0; i < e->nargs; i++)
        if (!note_uses(I, e->args[i], k)) return false;
    return true;
}
bool note_uses(Interp &I, const Stmt *s, int k) {
    if (s->kind == ST_ASSIGN && !s->local && !note_slot(I, s->slot, k)) return false;
    if (s->kind == ST_INCLUDE) I.include_last = k;  // an included file may name any variable
    if (s->kind == ST_DEFINE) k = INT_MAX;  // a body may be called by any statement after
    for (int i = 0; i < s->nargs; i++)
        if (!note_uses(I, s->args[i], k)) return false;
    for (int i = 0; i < s->nbody; i++)
        if (!note_uses(I, s->body[i], k)) return false;
    for (int i = 0; i < s->nels; i++)
        if (!note_uses(I, s->els[i], k)) return false;
    return true;
}

struct SlotLast {
    int last, slot;
};
int slot_last_cmp(const void *pa, const void *pb) {
    const SlotLast *a = (const SlotLast *)pa, *b = (const SlotLast *)pb;
    if (a->last != b->last) return a->last < b->last ? -1 : 1;
    return a->slot - b->slot;
}

// I.order: the slots in the order in which they die (by I.last).
bool order_slots(Interp &I) {
    int n = I.vars.list.n;
    if (!I.last.reserve(I.c, n)) return false;
    while (I.last.n < n) I.last.p[I.last.n++] = -1;  // (every slot was named; kept safe all the same)
    SlotLast *sl = (SlotLast *)mem_alloc(I.c, sizeof(SlotLast) * (size_t)n);
    if (!sl || !I.order.reserve(I.c, n) || !I.dropped.reserve(I.c, n)) {
        mem_free(I.c, sl);
        return false;
    }
    for (int i = 0; i < n; i++) {
        if (I.last[i] < I.include_last) I.last[i] = I.include_last;
        sl[i].last = I.last[i];
        sl[i].slot = i;
    }
    qsort(sl, (size_t)n, sizeof(SlotLast), slot_last_cmp);
    for (int i = 0; i < n; i++) I.order.p[i] = sl[i].slot;
    I.order.n = n;
    memset(I.dropped.p, 0, (size_t)n);
    I.dropped.n = n;
    mem_free(I.c, sl);
    return true;
}

// Read the program from its start, one statement of the top level at a time; only that
// statement's tree and its current line's tokens are held. Without `run` the program is only
// checked, so that a malformed program runs none of its statements, and the variables each
// statement names are noted; with it each statement runs as soon as it is read, and the values
// of variables that no statement after it names are released. *parse_time: seconds spent
// reading.
PRAY_NOINLINE pray_status read_statements(Parser &P, const char *text, size_t len, Interp *I, bool run,
                                         double *parse_time) {
    pray_ctx *c = P.c;
    int k = 0;  // statements of the top level read so far
    double t0 = clock_seconds();
    P.depth = 0;
    P.blocks = P.base;
    P.run = run;
    P.includes = 0;
    Array<CallSite> sites;
    sites.init();
    P.sites = &sites;
    pray_status st = lex_start(*P.L, text, len, !run);
    P.t = P.L->toks.p;
    P.pos = 0;
    while (st == PRAY_OK) {
        if (cur(P).kind == T_EOF) break;
        if (cur(P).kind == T_NL) {
            st = next_line(P);
            continue;
        }
        const char *stop = block_end(P);
        if (stop) {
            st = syn(P, cur(P), "'%s' without a matching '%s'", stop, block_opener(stop));
            break;
        }
        Stmt *s = parse_statement(P);
        if (!s) {
            st = c->status;
            break;
        }
        if (!run && !P.included && !note_uses(*I, s, k)) {
            st = c->status;
            break;
        }
        if (run) {
            if (I->vars.list.n > I->vals.n) {  // (the check found every name already)
                if (!I->vals.reserve(c, I->vars.list.n)) {
                    st = c->status;
                    break;
                }
                memset(I->vals.p + I->vals.n, 0, sizeof(Value) * (size_t)(I->vars.list.n - I->vals.n));
                I->vals.n = I->vars.list.n;
            }
            double t1 = clock_seconds();
            *parse_time += t1 - t0;
            if (!P.included) {  // (an included file's values are the program's: they live on)
                I->top = s;
                I->top_index = k;
            }
            st = exec(*I, s);
            if (st && I->quit) st = c->status = PRAY_OK;  // (a quit in a call unwinds as an error)
            if (st == PRAY_OK && !P.included) release_dead(*I, k);
            t0 = clock_seconds();
            if (I->quit) break;
        }
        k++;
        P.arena->reset(c);
    }
    if (st == PRAY_OK && !run) st = check_calls(P);
    sites.release(c);
    *parse_time += clock_seconds() - t0;
    if (st && !run && !P.L->failed) {
        // the program is wrong: an error of its characters, anywhere, is the one to report
        // (as when the whole text is lexed first); else this one
        // (the message is kept off the stack: included files nest this function)
        pray_status first = st;
        char *msg = mem_strdup(c, c->msg, strlen(c->msg));
        while (!P.L->at_end && lex_line(*P.L) == PRAY_OK) {
        }
        if (P.L->failed) {
            mem_free(c, msg);
            return c->status;
        }
        c->status = first;
        if (msg) snprintf(c->msg, sizeof c->msg, "%s", msg);
        mem_free(c, msg);
    }
    return st;
}

pray_status run_program(pray_ctx *c, const char *name, const char *text, size_t len) {
    Arena tree, words, names;  // a statement's syntax tree; a line's names and strings; variables' names
    tree.init();
    words.init();
    names.init();
    Lexer L;
    memset(&L, 0, sizeof L);
    L.c = c;
    L.name = name;
    L.text = &words;
    L.toks.init();
    L.maxstring = c->cur.opt.v[OPT_MAXSTRING];
    Interp I;
    memset(&I, 0, sizeof I);
    I.c = c;
    I.name = I.prog = name;
    I.vars.list.init();
    I.vars.hash.init();
    I.vals.init();
    I.files.init();
    I.procs.init();
    I.include_last = -1;
    Arena keep;  // the bodies of procedures
    keep.init();
    Parser P;
    memset(&P, 0, sizeof P);
    P.c = c;
    P.name = name;
    P.L = &L;
    P.maxnest = c->cur.opt.v[OPT_MAXNEST];
    P.arena = &tree;
    P.names = &names;
    P.vars = &I.vars;
    Names pnames;  // (the procedures' names)
    pnames.list.init();
    pnames.hash.init();
    P.pnames = &pnames;
    P.procs = &I.procs;
    P.keep = &keep;
    I.parser = &P;
    IncFile prog;
    prog.name = (char *)name;
    prog.id = c->prog_id;
    prog.line = 0;
    pray_status st = I.files.push(c, prog) ? PRAY_OK : c->status;
    // first the whole program is checked, then it is read again and run statement by statement
    double parse_time = 0;
    I.last.init();
    I.order.init();
    I.dropped.init();
    if (st == PRAY_OK) st = read_statements(P, text, len, &I, false, &parse_time);
    int nvars = I.vars.list.n;
    if (st == PRAY_OK && nvars && (!I.vals.reserve(c, nvars) || !order_slots(I))) st = c->status;
    mem_phase(c, MEM_PARSE);
    if (st == PRAY_OK) {
        if (nvars) memset(I.vals.p, 0, sizeof(Value) * (size_t)nvars);
        I.vals.n = nvars;
        tree.reset(c);
        st = read_statements(P, text, len, &I, true, &parse_time);
    }
    c->stats.time_parse += parse_time;
    mem_phase(c, MEM_RUN);
    for (int i = 0; i < I.vals.n; i++) vrelease(I, I.vals[i]);
    vrelease(I, I.ret);
    I.vals.release(c);
    I.procs.release(c);
    keep.release(c);
    I.last.release(c);
    I.order.release(c);
    I.dropped.release(c);
    for (int i = 0; i < I.names.n; i++) mem_free(c, I.names[i].name);
    I.names.release(c);
    I.vars.list.release(c);
    I.vars.hash.release(c);
    pnames.list.release(c);
    pnames.hash.release(c);
    I.files.release(c);
    L.toks.release(c);
    tree.release(c);
    words.release(c);
    names.release(c);
    return st;
}

} // namespace
#endif // PRAY_HAS_INTERP

// =============================================================================================
// [SECTION] 15 One-call helpers and the running of programs
// =============================================================================================
namespace {
// A run starts from what the host set (the defaults, unless it set more) and ends back there.
void reset_run(pray_ctx *c) {
    c->cur = c->base;
    texture_cache_clear(c);  // files are read again by the next run
    memset(&c->stats, 0, sizeof c->stats);
    c->peak = c->used;
    c->frames = 0;
    c->written = 0;
    c->status = PRAY_OK;
    c->msg[0] = 0;
}
} // namespace

// A context runs one program at a time: a frame callback or render function that starts another
// on it would reset the one that called it.
pray_status refuse_nested_run(pray_ctx *c) { return fail(c, PRAY_ERR_ARG, "the context is running a program"); }

// pray_run_string's work, between call_enter and call_leave
static pray_status run_string_call(pray_ctx *c, const char *name, const char *text, size_t len) {
    reset_run(c);
    if (!text) return fail(c, PRAY_ERR_ARG, "no program text");
#if PRAY_HAS_INTERP
    const char *nm = name && *name ? name : "pray";
    // texture files named by the program are also looked for beside it: in the directory of its name
    c->run_dir = nm;
    c->run_dir_len = 0;
    for (size_t i = 0; nm[i]; i++)
        if (nm[i] == '/' || nm[i] == '\\' || nm[i] == ':') c->run_dir_len = i + 1;
    prepared_drop(c);  // (a run prepares its own frames, kept only for a render function's parts)
    c->running = 1;
    pray_status st = run_program(c, nm, text, len);
    prepared_drop(c);
    coh_release(c);
    c->running = 0;
    c->run_dir = NULL;
    c->run_dir_len = 0;
    c->cur = c->base;
    apply_memory_cap(c);
    return st;
#else
    (void)name;
    (void)len;
    return fail(c, PRAY_ERR_ARG, "this build has no PRAY interpreter");
#endif
}

pray_status pray_run_string(pray_ctx *c, const char *name, const char *text, size_t len) {
    if (!c) return PRAY_ERR_ARG;
    if (c->running) return refuse_nested_run(c);
    call_enter(c);
    pray_status r = run_string_call(c, name, text, len);
    call_leave(c);
    return r;
}

#if PRAY_HAS_STDIO
namespace {
// Read a program into t, on the context's allocator: its memory cap holds as for everything else.
// Reading stops at a line longer than option maxline + 1 characters (counted as the lexer counts
// them, a byte order mark included): the lexer then reports that line as it would in the whole
// file, and an input that never ends (/dev/zero, a pipe) ends there.
bool read_program(pray_ctx *c, FILE *f, Text *t) {
    double lim = c->cur.opt.v[OPT_MAXLINE] + 1, col = 0;
    char buf[8192];
    size_t n;
    while ((n = fread(buf, 1, sizeof buf, f)) > 0) {
        if (!t->add(c, buf, n)) return false;
        for (size_t i = 0; i < n; i++) {
            if (buf[i] == '\n') col = 0;
            else if ((buf[i] & 0xC0) != 0x80 && ++col > lim) return true;
        }
    }
    return true;
}
} // namespace
#endif

// A path of "-" reads standard input, named stdin.ray in messages.
// pray_run_file's work, between call_enter and call_leave
static pray_status run_file_call(pray_ctx *c, const char *path) {
    if (!path) return fail(c, PRAY_ERR_ARG, "no program file");
#if PRAY_HAS_STDIO
    bool in = strcmp(path, "-") == 0;
    char *opened = NULL;
    FileId id;
    id.valid = 0;
    FILE *f = in ? stdin : open_read(c, "", 0, path, FIND_AS_NAMED, &opened, &id);
    mem_free(c, opened);
    if (!f) return c->status;
    Text t;
    t.init();
    // a file whose size is known is read into a buffer of that size (it is held while it runs)
    long size = -1;
    bool bad = false;
    if (!in && fseek(f, 0, SEEK_END) == 0) {
        size = ftell(f);
        bad = fseek(f, 0, SEEK_SET) != 0;
    }
    // (only where it fits under the cap: else reading finds what is wrong, a long line or the cap)
    if (size > 0 && size < INT_MAX - 1 && (c->limit == 0 || (size_t)size + 65536 < c->limit - c->used) &&
        !t.a.reserve_exact(c, (int)size + 1))
        pray_clear_error(c);  // read as it comes
    bool ok = bad || read_program(c, f, &t);
    bad = bad || ferror(f) != 0;
    if (!in) fclose(f);
    pray_status st;
    if (!ok) st = c->status;
    else if (bad) st = fail(c, PRAY_ERR_IO, "cannot read '%s'", *ShownPath(path));
    else {
        c->prog_id = id;  // no image may replace the program (pray_write_image)
        c->prog_name = in ? NULL : path;
        st = pray_run_string(c, in ? "stdin.ray" : path, t.str(), (size_t)t.a.n);
        c->prog_id.valid = 0;
        c->prog_name = NULL;
    }
    t.a.release(c);
    return st;
#else
    return fail(c, PRAY_ERR_IO, "this build has no file access");
#endif
}

pray_status pray_run_file(pray_ctx *c, const char *path) {
    if (!c) return PRAY_ERR_ARG;
    if (c->running) return refuse_nested_run(c);
    call_enter(c);
    pray_status r = run_file_call(c, path);
    call_leave(c);
    return r;
}

int pray_frames(const pray_ctx *c) { return c ? c->frames : 0; }

pray_status pray_render_file(const char *program, const char *const *options, int noptions, char *message,
                             size_t message_size) {
    pray_ctx *c = pray_new();
    if (!c) {
        if (message && message_size) snprintf(message, message_size, "error: out of memory");
        return PRAY_ERR_NOMEM;
    }
    pray_status st = PRAY_OK;
    for (int i = 0; i < noptions && st == PRAY_OK; i++) {
        const char *eq = options[i] ? strchr(options[i], '=') : NULL;
        if (!eq || eq == options[i]) {
            st = fail(c, PRAY_ERR_ARG, "option '%s' is not of the form name=value", options[i] ? *Shown(options[i]) : "");
            break;
        }
        char *name = mem_strdup(c, options[i], (size_t)(eq - options[i]));
        st = name ? pray_option_fix(c, name, eq + 1) : c->status;
        mem_free(c, name);
    }
    if (st == PRAY_OK) st = pray_run_file(c, program);
    if (message && message_size) snprintf(message, message_size, "%s", c->msg);
    pray_free(c);
    return st;
}

#ifdef PRAY_MAIN
// =============================================================================================
// [SECTION] 16 Command-line program (the public API; files opened and compared as the library does)
// =============================================================================================
#if !PRAY_HAS_INTERP || !PRAY_HAS_STDIO
#error "the command-line program needs the interpreter and stdio"
#endif
#include <signal.h>

namespace {

#if PRAY_HAS_PNG
#define PRAY_FORMATS ".tif, .ppm or .png"
#else
#define PRAY_FORMATS ".tif or .ppm"
#endif
const char *const USAGE =
    "usage: pray [options] program.ray\n"
    "       pray --join OUT PART...\n"
    "Render a PRAY program, or stack the row parts that --rows or --part wrote into the\n"
    "image OUT. Options:\n"
    "  -o FILE          output file (" PRAY_FORMATS "); same as -D output=FILE;\n"
    "                   -o - writes PPM to standard output (`print` then goes to standard error)\n"
    "  -s WxH           image size in pixels; same as -D width=W -D height=H\n"
    "  -D name=value    set an option of the language; wins over `option` in the program\n"
    "  --stats          print statistics of the rendering to standard error\n"
    "  --threads N      threads to render with (0 = automatic)\n"
    "  --untrusted      tighter limits; the program reads files beside it only\n"
    "  --rows A:B       render only rows A to B-1 of every image (a row part, .tif or .ppm)\n"
    "  --part K/N       render only the K-th of N bands of rows of equal height (K from 1)\n"
    "  --frames A:B     write only frames A to B-1 of the program (from 0)\n"
    "  --quiet          no progress bar, no warnings\n"
    "  --version        print the version and the features compiled in\n"
    "  --help           print this text\n"
    "A program of '-' is read from standard input.\n"
    "\n"
    "Options of the language, for -D name=value or `option` in the program:\n"
    "  the image        width height output bits antialias adaptive depth cutoff shadows\n"
    "  the machine      threads\n"
    "  limits           maxsteps maxnest maxline maxstring maxprims maxpixels maxrays\n"
    "                   maxmem maxframes maxoutput maxtime gridmem texmem\n"
    "\n"
    "Diagnostic options, to measure the acceleration or compare it with the reference;\n"
    "an image never needs them, and it stays the same byte for byte whatever they are:\n"
    "  --brute          the brute-force reference renderer; same as -D brute=1\n"
    "  -D grid=N        N voxels along the longest side (0: no grid; -1: automatic)\n"
    "  -D nest=N        levels of finer grids in crowded voxels (0 to 4; 2)\n"
    "  -D freeze=0      no freezing of CSG nodes whose status can no longer change\n"
    "  -D merge=0       no areas of neighbouring voxels with the same action lists\n"
    "  -D bounds=0      no bounding boxes around the parts of the CSG tree\n"
    "  -D lightbuffer=0 shadow rays walk the grid, not the lists around each light\n"
    "  -D eyebuffer=0   primary rays walk the grid, not the lists around the eye\n"
    "  -D shadowcache=0 shadow rays do not first try the voxel that stopped the last one\n"
    "  -D plans=0       every action list is evaluated in full, without shortcuts\n"
    "  -D coherence=0   every frame of a sequence is traced in full\n"
    "\n"
    "Exit status: 0 ok, 1 error in the program, 2 usage, 3 input/output error.\n";

int usage_error(const char *fmt, const char *arg) {
    fprintf(stderr, "pray: ");
    fprintf(stderr, fmt, arg);
    fprintf(stderr, "\n%s", "run 'pray --help' for the options\n");
    return 2;
}

int progress_bar(void *, int done, int total) {
    int width = 40, fill = (int)((double)done / total * width);
    char bar[64];
    for (int i = 0; i < width; i++) bar[i] = i < fill ? '#' : '.';
    bar[width] = 0;
    fprintf(stderr, "\r[%s] %3d%%", bar, (int)(100.0 * done / total));
    if (done == total) fprintf(stderr, "\r%*s\r", width + 8, "");
    fflush(stderr);
    return 0;
}

void to_stderr(void *, const void *p, size_t n) { fwrite(p, 1, n, stderr); }

int exit_code(pray_status st) {
    switch (st) {
    case PRAY_OK: return 0;
    case PRAY_ERR_IO: return 3;
    case PRAY_ERR_ARG: return 2;
    default: return 1;
    }
}

void print_stats(pray_ctx *c) {
    pray_stats s;
    pray_stats_get(c, &s);
    fprintf(stderr,
            "primitives: %ld declared, %ld kept; nodes %ld\n"
            "grid: %d x %d x %d = %ld voxels and %ld in %ld nested grids, %ld distinct lists, %ld areas, %.0f bytes\n"
            "rays: primary %.0f (of %.0f without undersampling), shadow %.0f, reflected %.0f, refracted %.0f\n"
            "light buffers: %ld voxels; shadow rays from them %.0f\n"
            "eye buffer: %ld voxels; primary rays from it %.0f\n"
            "shadow cache: shadow rays it stopped %.0f\n"
            "traversal: %.0f voxel steps, %.0f area moves\n"
            "actions: set inside %.0f, set outside %.0f, check %.0f (frozen skips %.0f)\n"
            "intersection tests %.0f\n"
            "time: parse %.3f s, prepare %.3f s, render %.3f s on %d thread%s\n"
            "memory: peak %.0f bytes; by phase: parse %.0f, run %.0f, prepare %.0f, acceleration %.0f, render %.0f\n",
            s.primitives_declared, s.primitives, s.nodes, s.grid[0], s.grid[1], s.grid[2], s.voxels, s.nested_voxels, s.nested_grids, s.lists,
            s.areas, s.memory, s.rays_primary, s.rays_primary_full, s.rays_shadow, s.rays_reflected, s.rays_refracted, s.lightbuf_voxels, s.rays_lightbuf, s.eyebuf_voxels, s.rays_eyebuf, s.rays_shadowcache, s.voxel_steps,
            s.area_moves, s.set_inside, s.set_outside, s.checks, s.frozen_skips, s.intersection_tests,
            s.time_parse, s.time_prepare, s.time_render, s.threads, s.threads == 1 ? "" : "s", s.memory_peak,
            s.memory_parse, s.memory_run, s.memory_prepare, s.memory_accel, s.memory_render);
    if (s.pixels_reused + s.pixels_retraced > 0)
        fprintf(stderr, "coherence: %ld of %d frames took pixels over from the frame before: %.0f pixels reused, %.0f traced\n",
                s.frames_coherent, pray_frames(c), s.pixels_reused, s.pixels_retraced);
}

// --stats: a line per frame of a program, before it is written: its time and the pixels it took
// over from the frame before (option coherence).
struct FrameLog {
    pray_ctx *c;
    pray_stats last;
};
pray_status log_frame(void *ud, const pray_image *img, const char *name) {
    FrameLog *g = (FrameLog *)ud;
    pray_stats s;
    pray_stats_get(g->c, &s);
    fprintf(stderr, "frame %s: prepare %.3f s, render %.3f s; pixels reused %.0f of %.0f\n", name,
            s.time_prepare - g->last.time_prepare, s.time_render - g->last.time_render,
            s.pixels_reused - g->last.pixels_reused, (double)img->width * img->height);
    g->last = s;
    return pray_write_image(g->c, img, name, (int)pray_option_get(g->c, "bits"));
}

// ---- parts of a render: --rows, --part, --frames (docs/distributed.md) ----
// A row part is an image file of rows A to B-1 whose note (TIFF ImageDescription, PPM comment)
// says where they belong: "pray-part rows=A:B height=H frame=F id=X". X tells the renders apart:
// a hash of the program's bytes and of the options that shape the image. --join reads it back.
#define PART_NOTE "pray-part rows=%d:%d height=%d frame=%d id=%16s"

struct Split {
    pray_ctx *c;
    int row0, row1;      // --rows (row1 0: not given)
    int k, n;            // --part K/N (n 0: not given)
    int frame0, frame1;  // --frames (frame1 0: not given)
    int rendered;        // frames of the range met by the run
    int y0, y1, height, frame;  // the rows of the frame being written, of an image of `height`
    char id[17];
};

// Parse "A:B" (sep ':') or "K/N" (sep '/') of non-negative numbers below 2^30.
bool parse_pair(const char *t, char sep, int *a, int *b) {
    long v[2];
    for (int i = 0; i < 2; i++) {
        if (*t < '0' || *t > '9') return false;
        v[i] = 0;
        while (*t >= '0' && *t <= '9') {
            v[i] = v[i] * 10 + (*t++ - '0');
            if (v[i] >= 1L << 30) return false;
        }
        if (*t++ != (i == 0 ? sep : 0)) return false;
    }
    *a = (int)v[0];
    *b = (int)v[1];
    return true;
}

// Instead of rendering a program's frame (pray_set_render): skip it outside --frames, render only
// the rows of --rows or --part.
pray_status render_part(void *ud, pray_ctx *c, pray_object *root, pray_light *lights, int frame, pray_image *out) {
    Split *sp = (Split *)ud;
    if (sp->frame1 && (frame < sp->frame0 || frame >= sp->frame1)) return PRAY_OK;
    sp->rendered++;
    if (!sp->row1 && !sp->n) return pray_render(c, root, lights, out);
    int W = (int)pray_option_get(c, "width"), H = (int)pray_option_get(c, "height");
    char msg[200];
    if (sp->n) {
        if (sp->n > H) {
            snprintf(msg, sizeof msg, "--part %d/%d: an image of %d row%s cannot be cut into %d parts", sp->k, sp->n,
                     H, H == 1 ? "" : "s", sp->n);
            return pray_set_error(c, PRAY_ERR_ARG, msg);
        }
        sp->y0 = (int)((unsigned long)(sp->k - 1) * (unsigned long)H / (unsigned long)sp->n);
        sp->y1 = (int)((unsigned long)sp->k * (unsigned long)H / (unsigned long)sp->n);
    } else {
        if (sp->row1 > H) {
            snprintf(msg, sizeof msg, "--rows %d:%d is not inside the image of %d row%s", sp->row0, sp->row1, H,
                     H == 1 ? "" : "s");
            return pray_set_error(c, PRAY_ERR_ARG, msg);
        }
        sp->y0 = sp->row0;
        sp->y1 = sp->row1;
    }
    sp->height = H;
    sp->frame = frame;
    pray_rect r = {0, sp->y0, W, sp->y1 - sp->y0};
    pray_status st = pray_image_new(c, W, r.height, out);
    if (st != PRAY_OK) return st;
    pray_buffers b = {NULL, NULL, NULL, NULL, 0, NULL, NULL, 0};
    b.rgb = out->pixels;
    return pray_render_into(c, root, lights, &r, &b);
}

// A row part rendered by render_part, written with its note.
pray_status write_part(void *ud, const pray_image *img, const char *name) {
    Split *sp = (Split *)ud;
    pray_ctx *c = sp->c;
    char note[200];
    size_t n = strlen(name);
    if (n >= 4 && (strcmp(name + n - 4, ".png") == 0 || strcmp(name + n - 4, ".PNG") == 0)) {
        char msg[PRAY_NOTE_MAX + 100];
        snprintf(msg, sizeof msg, "row parts are written as .tif or .ppm, not as '%.900s' (--join makes the PNG)",
                 name);
        return pray_set_error(c, PRAY_ERR_ARG, msg);
    }
    snprintf(note, sizeof note, PART_NOTE, sp->y0, sp->y1, sp->height, sp->frame, sp->id);
    return pray_write_image_note(c, img, name, (int)pray_option_get(c, "bits"), note);
}

// -o -: each frame to standard output as PPM, one after another (a stream netpbm tools read).
void to_stdout(void *, const void *p, size_t n) { fwrite(p, 1, n, stdout); }
pray_status write_stdout(void *ud, const pray_image *img, const char *) {
    pray_ctx *c = (pray_ctx *)ud;
    pray_status st = pray_write_ppm(c, img, (int)pray_option_get(c, "bits"), to_stdout, NULL);
    if (st == PRAY_OK && (fflush(stdout) != 0 || ferror(stdout)))
        st = pray_set_error(c, PRAY_ERR_IO, "cannot write the image to standard output");
    return st;
}

// FNV-1a, twice with different starts: 16 hexadecimal digits for the part's id.
void hash_bytes(unsigned long h[2], const void *p, size_t n) {
    const unsigned char *b = (const unsigned char *)p;
    for (size_t i = 0; i < n; i++)
        for (int j = 0; j < 2; j++) h[j] = ((h[j] ^ b[i]) * 16777619UL) & 0xFFFFFFFFUL;
}

// The id of a render: the program's bytes and the arguments that shape its images (not -o,
// --threads, --quiet, --stats, nor the choice of rows and frames). The program is opened as the
// run will open it (open_read: no waiting on a FIFO, no endless device); when that fails, the run
// says why.
void render_id(pray_ctx *c, char out[17], const char *program, int argc, char **argv) {
    unsigned long h[2] = {2166136261UL, 3735928559UL};
    char *opened = NULL;
    FILE *f = strcmp(program, "-") == 0 ? NULL : open_read(c, "", 0, program, FIND_AS_NAMED, &opened, NULL);
    mem_free(c, opened);
    pray_clear_error(c);
    if (f) {
        char buf[8192];
        size_t n;
        while ((n = fread(buf, 1, sizeof buf, f)) > 0) hash_bytes(h, buf, n);
        fclose(f);
    }
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        if (strcmp(a, "--quiet") == 0 || strcmp(a, "-q") == 0 || strcmp(a, "--stats") == 0) continue;
        if (strcmp(a, "-o") == 0 || strcmp(a, "--threads") == 0 || strcmp(a, "--rows") == 0 ||
            strcmp(a, "--part") == 0 || strcmp(a, "--frames") == 0) {
            i++;
            continue;
        }
        if (a == program) continue;
        if (strcmp(a, "-D") == 0 && i + 1 < argc &&
            (strncmp(argv[i + 1], "output=", 7) == 0 || strncmp(argv[i + 1], "threads=", 8) == 0)) {
            i++;
            continue;
        }
        hash_bytes(h, a, strlen(a) + 1);
    }
    snprintf(out, 17, "%08lx%08lx", h[0], h[1]);
}

// ---- pray --join OUT PART... ----
struct Part {
    const char *name;
    FileId id;            // which no output may replace
    unsigned char *file;  // the whole file
    const unsigned char *samples;
    int width, rows, bits, big_endian;
    int row0, row1, height, frame;
    char id_text[17];
};

unsigned rd16(const unsigned char *p) { return (unsigned)p[0] | (unsigned)p[1] << 8; }
unsigned long rd32(const unsigned char *p) { return (unsigned long)rd16(p) | (unsigned long)rd16(p + 2) << 16; }

// The most a part's header takes, its note included: the samples start within this many bytes.
const size_t PART_HEAD = 2048;

// Read a part written by pray --rows: a TIFF or PPM file as pray writes them, with its note. It
// is opened as programs are (open_read: a regular file, no waiting on a FIFO); its header is read
// first, and then no more than the samples it claims. Returns 0, or the exit status after
// printing the error.
int read_part(pray_ctx *c, Part *pt) {
    char *opened = NULL;
    FILE *f = open_read(c, "", 0, pt->name, FIND_AS_NAMED, &opened, &pt->id);
    mem_free(c, opened);
    if (!f) {
        fprintf(stderr, "pray: %s\n", pray_error(c));
        return exit_code(pray_last_status(c));
    }
    unsigned char buf[PART_HEAD];
    size_t size = fread(buf, 1, sizeof buf, f);
    if (ferror(f)) {
        fclose(f);
        fprintf(stderr, "pray: error: cannot read '%s': %s\n", pt->name, strerror(errno ? errno : EIO));
        return 3;
    }
    char note[PRAY_NOTE_MAX + 1] = "";
    size_t data = 0;
    int maxval = 0;
    double whole = 0;
    if (size >= 8 && memcmp(buf, "II*\0", 4) == 0) {  // TIFF: the tags pray writes
        unsigned long ifd = rd32(buf + 4), tiff_data = 0, bytes = 0, desc = 0, desc_n = 0, bps_at = 0;
        unsigned comp = 0, photo = 0, spp = 0;
        if (ifd > size || size - ifd < 2) goto not_pray;
        unsigned nt = rd16(buf + ifd);
        if ((size - ifd - 2) / 12 < nt + 1UL) goto not_pray;  // the entries and the next offset
        for (unsigned i = 0; i < nt; i++) {
            const unsigned char *e = buf + ifd + 2 + 12 * i;
            unsigned tag = rd16(e), type = rd16(e + 2);
            unsigned long count = rd32(e + 4), v = type == 3 && count == 1 ? rd16(e + 8) : rd32(e + 8);
            switch (tag) {
            case 256: pt->width = v > 65536 ? 0 : (int)v; break;
            case 257: pt->rows = v > 65536 ? 0 : (int)v; break;
            case 258: bps_at = count == 3 ? v : 0; break;
            case 259: comp = (unsigned)v; break;
            case 262: photo = (unsigned)v; break;
            case 270: desc = v, desc_n = type == 2 ? count : 0; break;
            case 273: tiff_data = v; break;
            case 277: spp = (unsigned)v; break;
            case 279: bytes = v; break;
            }
        }
        if (comp != 1 || photo != 2 || spp != 3 || !bps_at || bps_at > size || size - bps_at < 6) goto not_pray;
        pt->bits = (int)rd16(buf + bps_at);
        if (rd16(buf + bps_at + 2) != (unsigned)pt->bits || rd16(buf + bps_at + 4) != (unsigned)pt->bits) goto not_pray;
        if (desc_n > 1 && desc_n <= PRAY_NOTE_MAX + 1 && desc <= size && desc_n <= size - desc &&
            buf[desc + desc_n - 1] == 0)
            memcpy(note, buf + desc, desc_n);
        data = tiff_data;
        if (pt->width < 1 || pt->rows < 1 || pt->width > 65536 || pt->rows > 65536 ||
            (pt->bits != 8 && pt->bits != 16) || (double)bytes != (double)pt->width * pt->rows * 3 * (pt->bits / 8))
            goto not_pray;
    } else if (size >= 3 && memcmp(buf, "P6\n", 3) == 0) {  // PPM: "P6\n# NOTE\nW H\nMAX\n"
        size_t i = 3;
        if (i + 2 <= size && buf[i] == '#' && buf[i + 1] == ' ') {
            size_t j = i + 2;
            while (j < size && buf[j] != '\n' && j - i - 2 < PRAY_NOTE_MAX) j++;
            if (j >= size || buf[j] != '\n') goto not_pray;
            memcpy(note, buf + i + 2, j - i - 2);
            note[j - i - 2] = 0;
            i = j + 1;
        }
        int head = 0;
        char text[64];
        size_t k = 0;
        while (i + k < size && k < sizeof text - 1 && head < 2) {
            text[k] = (char)buf[i + k];
            if (text[k++] == '\n') head++;
        }
        text[k] = 0;
        int used = 0;
        if (head != 2 || sscanf(text, "%d %d\n%d\n%n", &pt->width, &pt->rows, &maxval, &used) != 3 ||
            used != (int)k || (maxval != 255 && maxval != 65535) || pt->width < 1 || pt->rows < 1 ||
            pt->width > 65536 || pt->rows > 65536)
            goto not_pray;
        pt->bits = maxval == 255 ? 8 : 16;
        pt->big_endian = 1;
        data = i + k;
    } else
        goto not_pray;
    // the whole file: the header and the samples it claims, no more and no less
    whole = (double)data + (double)pt->width * pt->rows * 3 * (pt->bits / 8);
    if (data > size || whole > (double)(size_t)-1 / 2) goto not_pray;
    {
        long end = fseek(f, 0, SEEK_END) == 0 ? ftell(f) : -1;
        if (end >= 0 && (double)end != whole) {
            fclose(f);
            if ((double)end < whole)
                fprintf(stderr, "pray: error: '%s' is cut short: its header says %.0f bytes, the file has %ld\n",
                        pt->name, whole, end);
            else
                fprintf(stderr, "pray: error: '%s' has %ld bytes, more than the %.0f its header says\n", pt->name,
                        end, whole);
            return 1;
        }
        size_t n = (size_t)whole;
        pt->file = (unsigned char *)malloc(n + 1);
        if (!pt->file) {
            fclose(f);
            fprintf(stderr, "pray: error: out of memory reading '%s'\n", pt->name);
            return 1;
        }
        size_t got = fseek(f, 0, SEEK_SET) == 0 ? fread(pt->file, 1, n + 1, f) : 0;
        int bad = ferror(f);
        fclose(f);
        if (bad || got != n) {
            fprintf(stderr, "pray: error: cannot read '%s': %s\n", pt->name,
                    bad ? strerror(errno ? errno : EIO) : "its size changed while it was read");
            return 3;
        }
        pt->samples = pt->file + data;
    }
    {
        int used = 0;
        if (!note[0]) {
            fprintf(stderr, "pray: error: '%s' is not a row part: it has no note of its rows (pray --rows or --part "
                    "writes them)\n", pt->name);
            return 1;
        }
        for (char *ch = note; *ch; ch++)
            if (*ch < 32 || *ch > 126) *ch = '?';  // shown in the message below
        if (sscanf(note, PART_NOTE "%n", &pt->row0, &pt->row1, &pt->height, &pt->frame, pt->id_text, &used) != 5 ||
            used != (int)strlen(note) || strlen(pt->id_text) != 16 || pt->row0 < 0 || pt->row1 <= pt->row0 ||
            pt->row1 > pt->height || pt->frame < 0) {
            fprintf(stderr, "pray: error: '%s' is not a row part: its note is '%s'\n", pt->name, note);
            return 1;
        }
        if (pt->rows != pt->row1 - pt->row0) {
            fprintf(stderr, "pray: error: '%s' holds %d row%s, but its note says rows %d:%d\n", pt->name, pt->rows,
                    pt->rows == 1 ? "" : "s", pt->row0, pt->row1);
            return 1;
        }
    }
    return 0;
not_pray:
    fclose(f);
    fprintf(stderr, "pray: error: '%s' is not a TIFF or PPM file as pray writes them\n", pt->name);
    return 1;
}

// Stack the parts into one image and write it to `out` (through pray_write_image: a temporary
// file renamed when complete). Every check comes before anything is written.
int join_parts(pray_ctx *c, const char *out, char **names, int n) {
    Part *p = (Part *)calloc((size_t)n, sizeof(Part));
    int *order = (int *)malloc(sizeof(int) * (size_t)n);
    int rc = 0;
    if (!p || !order) {
        fprintf(stderr, "pray: error: out of memory\n");
        rc = 1;
    }
    for (int i = 0; i < n && rc == 0; i++) {
        p[i].name = names[i];
        rc = read_part(c, &p[i]);
    }
    for (int i = 0; i < n && rc == 0; i++)  // the output may not replace a part
        if (same_file(out, p[i].id, p[i].name)) {
            fprintf(stderr, "pray: error: cannot write '%s': it is the part '%s' (choose another output name)\n", out,
                    p[i].name);
            rc = 3;
        }
    for (int i = 1; i < n && rc == 0; i++) {
        const Part &a = p[0], &b = p[i];
        if (b.width != a.width || b.bits != a.bits || b.height != a.height || b.frame != a.frame ||
            strcmp(b.id_text, a.id_text) != 0) {
            fprintf(stderr, "pray: error: '%s' and '%s' are parts of different images: ", a.name, b.name);
            if (b.width != a.width) fprintf(stderr, "%d and %d pixels wide\n", a.width, b.width);
            else if (b.bits != a.bits) fprintf(stderr, "%d and %d bits\n", a.bits, b.bits);
            else if (b.height != a.height) fprintf(stderr, "of %d and %d rows\n", a.height, b.height);
            else if (b.frame != a.frame) fprintf(stderr, "frames %d and %d\n", a.frame, b.frame);
            else fprintf(stderr, "renders %s and %s (another program or other options)\n", a.id_text, b.id_text);
            rc = 1;
        }
    }
    if (rc == 0) {  // in order of their first rows; then no gap, no overlap, all rows
        for (int i = 0; i < n; i++) {
            int j = i;
            while (j > 0 && p[order[j - 1]].row0 > p[i].row0) {
                order[j] = order[j - 1];
                j--;
            }
            order[j] = i;
        }
        int next = 0;
        for (int i = 0; i < n && rc == 0; i++) {
            const Part &q = p[order[i]];
            if (q.row0 > next) {
                fprintf(stderr, "pray: error: rows %d:%d of the image are missing (no part holds them)\n", next, q.row0);
                rc = 1;
            } else if (q.row0 < next) {
                const Part &prev = p[order[i - 1]];
                fprintf(stderr, "pray: error: '%s' (rows %d:%d) and '%s' (rows %d:%d) overlap\n", prev.name, prev.row0,
                        prev.row1, q.name, q.row0, q.row1);
                rc = 1;
            }
            next = q.row1;
        }
        if (rc == 0 && next < p[0].height) {
            fprintf(stderr, "pray: error: rows %d:%d of the image are missing (no part holds them)\n", next,
                    p[0].height);
            rc = 1;
        }
    }
    pray_image img = {0, 0, NULL};
    if (rc == 0) {
        size_t n_out = strlen(out);
        if (p[0].bits != 8 && n_out >= 4 && (strcmp(out + n_out - 4, ".png") == 0 || strcmp(out + n_out - 4, ".PNG") == 0)) {
            fprintf(stderr, "pray: error: the parts have 16 bits per sample and PNG holds 8: join them into a .tif or "
                    ".ppm\n");
            rc = 1;
        }
    }
    if (rc == 0 && pray_image_new(c, p[0].width, p[0].height, &img) != PRAY_OK) {
        fprintf(stderr, "pray: %s\n", pray_error(c));
        rc = 1;
    }
    for (int i = 0; i < n && rc == 0; i++) {
        const Part &q = p[i];
        float *px = img.pixels + (size_t)q.row0 * (size_t)q.width * 3;
        size_t m = (size_t)q.rows * (size_t)q.width * 3;
        for (size_t k = 0; k < m; k++) {
            unsigned v;
            if (q.bits == 8) v = q.samples[k];
            else if (q.big_endian) v = (unsigned)q.samples[2 * k] << 8 | q.samples[2 * k + 1];
            else v = rd16(q.samples + 2 * k);
            // the sample's value, which the writers quantise back to the same sample
            px[k] = (float)(v / (q.bits == 8 ? 255.0 : 65535.0));
        }
    }
    if (rc == 0) {
        pray_status st = pray_write_image(c, &img, out, p[0].bits);
        if (st != PRAY_OK) {
            fprintf(stderr, "pray: %s\n", pray_error(c));
            rc = exit_code(st);
        }
    }
    pray_image_free(c, &img);
    for (int i = 0; p && i < n; i++) free(p[i].file);
    free(p);
    free(order);
    return rc;
}

// A signal that ends pray while an image is written (SIGINT, SIGTERM, SIGHUP, SIGQUIT): remove
// its temporary file, then die of the signal as the default would. Only async-signal-safe calls.
pray_ctx *volatile the_ctx;
extern "C" void on_signal(int sig) {
    const char *t = the_ctx ? pray_temp_file(the_ctx) : NULL;
#if defined(PRAY_HAS_UNISTD)
    if (t) unlink(t);
#else
    if (t) remove(t);
#endif
    signal(sig, SIG_DFL);
    raise(sig);
}

// Catch those signals during a run of `c` (c NULL: give them back their default). Systems without
// some of them (DOS, Windows) catch the others.
void catch_signals(pray_ctx *c) {
    void (*h)(int) = c ? on_signal : SIG_DFL;
    if (c) the_ctx = c;
    signal(SIGINT, h);
    signal(SIGTERM, h);
#ifdef SIGHUP
    signal(SIGHUP, h);
#endif
#ifdef SIGQUIT
    signal(SIGQUIT, h);
#endif
    if (!c) the_ctx = NULL;
}

} // namespace

// The command line's program run: its callbacks (standard output, progress, warnings, parts,
// frames, statistics) and the exit status.
int run_program_main(pray_ctx *c, const char *program, const char *output, bool stats, bool quiet, Split &sp,
                     int argc, char **argv) {
    bool piped = output && strcmp(output, "-") == 0;
    if (piped && (sp.row1 || sp.n)) return usage_error("-o - writes whole images: not with --rows or --part%s", "");
    if (piped) {  // (and `print` goes to standard error, out of the images' way)
#if defined(_WIN32)
        _setmode(_fileno(stdout), _O_BINARY);
#elif defined(__DJGPP__)
        setmode(fileno(stdout), O_BINARY);
#endif
        pray_set_frame(c, write_stdout, c);
        pray_set_print(c, to_stderr, NULL);
    }
    if (!quiet && stderr_is_terminal()) pray_set_progress(c, progress_bar, NULL);
    if (!quiet) pray_set_warning(c, to_stderr, NULL);
    if (sp.row1 || sp.n || sp.frame1) pray_set_render(c, render_part, &sp);
    if (sp.row1 || sp.n) {
        render_id(c, sp.id, program, argc, argv);
        pray_set_frame(c, write_part, &sp);
    }
    FrameLog flog;
    memset(&flog, 0, sizeof flog);
    flog.c = c;
    if (stats && !sp.row1 && !sp.n) pray_set_frame(c, log_frame, &flog);
    catch_signals(c);
    pray_status st = pray_run_file(c, program);
    catch_signals(NULL);
    int rc = 0;
    if (st != PRAY_OK) {
        const char *m = pray_error(c);
        if (strncmp(m, "error: ", 7) == 0) fprintf(stderr, "pray: %s\n", m);
        else fprintf(stderr, "%s\n", m);
        rc = exit_code(st);
        if (st == PRAY_ERR_ARG) rc = 1;  // a bad option value inside the program
    } else if (sp.frame1 && !sp.rendered) {
        if (pray_frames(c) == 0)
            fprintf(stderr, "pray: error: --frames %d:%d selects no frame: the program renders none\n", sp.frame0,
                    sp.frame1);
        else
            fprintf(stderr, "pray: error: --frames %d:%d selects no frame: the program renders frames 0:%d\n", sp.frame0,
                    sp.frame1, pray_frames(c));
        rc = 1;
    } else if (stats)
        print_stats(c);
    return rc;
}

int main(int argc, char **argv) {
#ifdef SIGXFSZ
    // a file over the size limit (ulimit -f): a write error (EFBIG) like any other, not death
    signal(SIGXFSZ, SIG_IGN);
#endif
    pray_ctx *c = pray_new();
    if (!c) {
        fprintf(stderr, "pray: error: out of memory\n");
        return 1;
    }
    const char *program = NULL, *output = NULL;  // output: as -o or -D output= named it
    int stats = 0, quiet = 0, rc = 0;
    Split sp;
    memset(&sp, 0, sizeof sp);
    sp.c = c;
    if (argc > 1 && strcmp(argv[1], "--join") == 0) {
        if (argc < 4) rc = usage_error("--join takes the output file and the parts: --join OUT PART...%s", "");
        else {
            for (int i = 3; i < argc && rc == 0; i++)
                if (argv[i][0] == '-' && argv[i][1]) rc = usage_error("--join takes file names only, not '%s'", argv[i]);
            catch_signals(c);
            if (rc == 0) rc = join_parts(c, argv[2], argv + 3, argc - 3);
            catch_signals(NULL);
        }
        pray_free(c);
        return rc;
    }
    for (int i = 1; i < argc && rc == 0; i++) {
        const char *a = argv[i];
        const char *next = i + 1 < argc ? argv[i + 1] : NULL;
        pray_status st = PRAY_OK;
        if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0) {
            fputs(USAGE, stdout);
            pray_free(c);
            return 0;
        } else if (strcmp(a, "--version") == 0) {
            printf("pray %s (%s)\n", pray_version(), pray_features());
            pray_free(c);
            return 0;
        } else if (strcmp(a, "--stats") == 0) stats = 1;
        else if (strcmp(a, "--quiet") == 0 || strcmp(a, "-q") == 0) quiet = 1;
        else if (strcmp(a, "--brute") == 0) st = pray_option_fix(c, "brute", "1");
        else if (strcmp(a, "--untrusted") == 0) pray_set_untrusted(c);
        else if (strcmp(a, "--join") == 0) {
            rc = usage_error("--join comes first: pray --join OUT PART...%s", "");
            break;
        } else if (strcmp(a, "--rows") == 0 || strcmp(a, "--part") == 0 || strcmp(a, "--frames") == 0) {
            if (!next) {
                rc = usage_error("option %s needs a value", a);
                break;
            }
            i++;
            int x = 0, y = 0;
            if (a[2] == 'p') {
                if (!parse_pair(next, '/', &x, &y) || x < 1 || y < 1 || x > y) {
                    rc = usage_error("--part takes K/N, the K-th of N bands of rows with K from 1 to N, as in --part 1/4, "
                                     "not '%s'", next);
                    break;
                }
                sp.k = x, sp.n = y;
            } else if (!parse_pair(next, ':', &x, &y) || x >= y) {
                rc = usage_error(a[2] == 'r' ? "--rows takes A:B, rows A to B-1 with A < B counted from 0, as in "
                                               "--rows 0:64, not '%s'"
                                             : "--frames takes A:B, frames A to B-1 with A < B counted from 0, as in "
                                               "--frames 0:10, not '%s'", next);
                break;
            } else if (a[2] == 'r') sp.row0 = x, sp.row1 = y;
            else sp.frame0 = x, sp.frame1 = y;
            if (sp.row1 && sp.n) {
                rc = usage_error("give --rows or --part, not both%s", "");
                break;
            }
        }
        else if (strcmp(a, "-o") == 0 || strcmp(a, "--threads") == 0 || strcmp(a, "-s") == 0 ||
                 strcmp(a, "-D") == 0) {
            if (!next) {
                rc = usage_error("option %s needs a value", a);
                break;
            }
            i++;
            if (a[1] == 'o') {
                if (strcmp(next, "-") != 0) st = pray_option_fix(c, "output", next);
                output = next;
            }
            else if (a[1] == '-') st = pray_option_fix(c, "threads", next);
            else if (a[1] == 's') {
                char w[32], h[32];
                const char *x = strchr(next, 'x');
                if (!x || x == next || !x[1] || x - next > 30 || strlen(x + 1) > 30) {
                    rc = usage_error("-s takes WIDTHxHEIGHT, as in -s 640x480, not '%s'", next);
                    break;
                }
                memcpy(w, next, (size_t)(x - next));
                w[x - next] = 0;
                strcpy(h, x + 1);
                st = pray_option_fix(c, "width", w);
                if (st == PRAY_OK) st = pray_option_fix(c, "height", h);
            } else {
                const char *eq = strchr(next, '=');
                if (!eq || eq == next) {
                    rc = usage_error("-D takes name=value, not '%s'", next);
                    break;
                }
                char *name = (char *)malloc((size_t)(eq - next) + 1);
                if (!name) {
                    fprintf(stderr, "pray: error: out of memory\n");
                    rc = 1;
                    break;
                }
                memcpy(name, next, (size_t)(eq - next));
                name[eq - next] = 0;
                st = pray_option_fix(c, name, eq + 1);
                if (strcmp(name, "output") == 0) output = eq + 1;
                free(name);
            }
        } else if (a[0] == '-' && a[1] != 0) {
            rc = usage_error("unknown option '%s'", a);
            break;
        } else if (program) {
            rc = usage_error("only one program, please ('%s' is the second)", a);
            break;
        } else
            program = a;
        if (st != PRAY_OK) {
            fprintf(stderr, "pray: %s\n", pray_error(c));
            rc = 2;
        }
    }
    if (rc == 0 && !program) rc = usage_error("no program given%s", "");
    if (rc == 0 && output && image_format(output) == FMT_PNG && pray_option_get(c, "bits") != 8) {
        fprintf(stderr, "pray: error: option 'bits': %.0f, but PNG output has 8 bits only ('%s': use .tif or .ppm)\n",
                pray_option_get(c, "bits"), *ShownPath(output));
        rc = 2;
    }
    if (rc != 0) {
        pray_free(c);
        return rc;
    }
    rc = run_program_main(c, program, output, stats != 0, quiet != 0, sp, argc, argv);
    fflush(stdout);
    pray_free(c);
    return rc;
}
#endif // PRAY_MAIN

#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC pop_options
#endif
