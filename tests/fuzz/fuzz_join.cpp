// libFuzzer harness for `pray --join`: the fuzz input is cut into row parts, which the command
// line's own main then joins.
//
//   make fuzz-join                 build it and run it over tests/fuzz/corpus_join (FUZZ_SECONDS)
//   build/fuzz/fuzz_join FILE      replay one input
//
// The join reader lives in the command-line program (section 16 of pray.cpp), so this harness,
// unlike the others, compiles pray.cpp itself with PRAY_MAIN and calls its main under another
// name. The input is cut at every "<part>" into at most 4 files p0.ppm ... p3.ppm (an input
// without one is one part) in a temporary directory of the harness's own, and
// `pray --join OUT p0.ppm ...` runs on them; OUT is out.ppm, out.tif or out.png by the input's
// length. The seeds (tests/fuzz/corpus_join) are parts that pray wrote, in TIFF and PPM, 8 and
// 16 bits, whole sets and sets with a part missing, joined by "<part>".
//
// Besides the sanitizers, the harness checks the command line's promises: the exit status is 0,
// 1 or 3; a failure prints one line "pray: error: ..." and leaves no file; a success writes OUT
// and leaves no temporary file. A broken promise aborts, so libFuzzer reports it as a crash.
#define PRAY_MAIN
#define main pray_main
#include "../../pray.cpp"
#undef main

#include <dirent.h>
#include <fcntl.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

namespace {

char g_dir[256];

// The names in the harness's directory (the parts removed before), joined by spaces; and remove
// them.
void leftovers(char *out, size_t n) {
    out[0] = 0;
    DIR *d = opendir(g_dir);
    if (!d) abort();
    while (struct dirent *e = readdir(d)) {
        const char *m = e->d_name;
        if (strcmp(m, ".") == 0 || strcmp(m, "..") == 0) continue;
        size_t k = strlen(out);
        snprintf(out + k, n - k, "%s%s", k ? " " : "", m);
        char path[600];
        snprintf(path, sizeof path, "%s/%s", g_dir, m);
        unlink(path);
    }
    closedir(d);
}

void fail_contract(const char *what, int rc, const char *err) {
    fprintf(stderr, "fuzz_join: %s (exit status %d, standard error \"%s\")\n", what, rc, err);
    abort();
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    if (!g_dir[0]) {
        const char *t = getenv("TMPDIR");
        snprintf(g_dir, sizeof g_dir, "%.200s/pray-fuzz-join.XXXXXX", t && *t ? t : "/tmp");
        if (!mkdtemp(g_dir)) abort();
    }
    // the parts
    static const char SEP[] = "<part>";
    const size_t seplen = sizeof SEP - 1;
    char names[4][300];
    int nparts = 0;
    size_t at = 0;
    while (nparts < 4) {
        size_t end = at;
        while (end < size && !(size - end >= seplen && memcmp(data + end, SEP, seplen) == 0)) end++;
        if (nparts == 3) end = size;  // the last part takes the rest
        snprintf(names[nparts], sizeof names[nparts], "%s/p%d.ppm", g_dir, nparts);
        FILE *f = fopen(names[nparts], "wb");
        if (!f || (end > at && fwrite(data + at, 1, end - at, f) != end - at) || fclose(f) != 0) abort();
        nparts++;
        if (end >= size) break;
        at = end + seplen;
    }
    static const char *const outs[] = {"out.ppm", "out.tif", PRAY_HAS_PNG ? "out.png" : "out.ppm"};
    char out[300];
    snprintf(out, sizeof out, "%s/%s", g_dir, outs[size % 3]);
    char join[] = "--join", prog[] = "pray";
    char *argv[8] = {prog, join, out, names[0], names[1], names[2], names[3], NULL};
    argv[3 + nparts] = NULL;
    // standard error into a file, for the checks
    char errpath[300];
    snprintf(errpath, sizeof errpath, "%s.err", g_dir);
    int fd = open(errpath, O_RDWR | O_CREAT | O_TRUNC, 0600), saved = dup(2);
    if (fd < 0 || saved < 0) abort();
    fflush(stderr);
    dup2(fd, 2);
    int rc = pray_main(3 + nparts, argv);
    fflush(stderr);
    dup2(saved, 2);
    close(saved);
    char err[2048];
    ssize_t got = pread(fd, err, sizeof err - 1, 0);
    close(fd);
    unlink(errpath);
    err[got > 0 ? got : 0] = 0;
    for (int i = 0; i < nparts; i++) unlink(names[i]);
    char left[1024];
    leftovers(left, sizeof left);
    if (rc != 0 && rc != 1 && rc != 3) fail_contract("unexpected exit status", rc, err);
    if (rc == 0) {
        if (err[0]) fail_contract("a message from a join that worked", rc, err);
        if (strcmp(left, outs[size % 3]) != 0) fail_contract("a join that worked left other files", rc, left);
    } else {
        const char *nl = strchr(err, '\n');
        if (strncmp(err, "pray: error: ", 13) != 0 || !err[13] || !nl || nl[1])
            fail_contract("a failure without one line \"pray: error: ...\"", rc, err);
        if (left[0]) fail_contract("a failed join left files", rc, left);
    }
    return 0;
}
