// Textures and text, through the public API (pray.hpp) and PRAY programs:
//   - the TIFF reader on a corpus written by INDEPENDENT tools (tests/make_tiffs.sh: python3 with
//     PIL writes the sources, libtiff's tiffcp converts each to both byte orders, strips and
//     tiles, no compression, PackBits, LZW with and without the predictor): every texel equals
//     the source's sample over its maximum, as a float;
//   - unsupported features refused with the file and the feature named; truncated, oversized and
//     malformed files refused with PRAY_ERR_IO or PRAY_ERR_LIMIT, never a crash (also a small
//     fixed-seed mutation fuzz); pray's own TIFFs read back identically;
//   - texture coordinates of planemap and spheremap at known points (docs: section 5), move,
//     transformed textured solids, bump maps (normals change, silhouettes do not);
//   - text solids: glyph pixels of the built-in font (tools/font6x9.txt) and of a TIFF atlas,
//     CSG with text, the grid against the brute-force reference;
//   - a missing texture file in a program: the statement's line, the file, no image.
// One test is skipped: a point reflection (scale -1) turns half-spaces inside out and mirrors a
// spheremap's longitudes, a bug of pray.cpp described at the test; run it with --no-skip.
// The tests run from the repository root (make_tiffs.sh and ./pray are found there). POSIX only.
#include <doctest/doctest.h>

#include "testkit.hpp"
#include "tempfiles.hpp"

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <random>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace {

// =============================================================================================
// Helpers
// =============================================================================================
pray_vec V3(double x, double y, double z) {
    pray_vec v;
    v.x = x;
    v.y = y;
    v.z = z;
    return v;
}
pray_rgb RGB(double r, double g, double b) {
    pray_rgb c;
    c.r = r;
    c.g = g;
    c.b = b;
    return c;
}
pray_vec add(pray_vec a, pray_vec b) { return V3(a.x + b.x, a.y + b.y, a.z + b.z); }
pray_vec sub(pray_vec a, pray_vec b) { return V3(a.x - b.x, a.y - b.y, a.z - b.z); }
pray_vec mul(pray_vec a, double s) { return V3(a.x * s, a.y * s, a.z * s); }
double dot(pray_vec a, pray_vec b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
pray_vec cross(pray_vec a, pray_vec b) {
    return V3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
pray_vec unit(pray_vec a) { return mul(a, 1 / std::sqrt(dot(a, a))); }
double frac(double x) { return x - std::floor(x); }

// A context that is freed at the end of the scope.
struct Ctx {
    pray_ctx *c;
    Ctx() : c(pray_new()) {}
    ~Ctx() { pray_free(c); }
    Ctx(const Ctx &) = delete;
    Ctx &operator=(const Ctx &) = delete;
    operator pray_ctx *() const { return c; }
};

using testkit::TempDir;
using testkit::slurp;
using testkit::spit;
bool contains(const std::string &s, const std::string &part) { return s.find(part) != std::string::npos; }

// Run a shell command; its exit status (-1 when it did not exit normally) and its output.
int run_cmd(const std::string &cmd, std::string *out, bool with_stderr = true) {
    std::string full = cmd + (with_stderr ? " 2>&1" : "");
    FILE *p = popen(full.c_str(), "r");
    if (!p) return -1;
    std::string s;
    char buf[4096];
    size_t n;
    while ((n = fread(buf, 1, sizeof buf, p)) > 0) s.append(buf, n);
    int st = pclose(p);
    if (out) *out = s;
    return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}
std::string sq(const std::string &s) {
    std::string r = "'";
    for (char ch : s) r += ch == '\'' ? std::string("'\\''") : std::string(1, ch);
    return r + "'";
}

// ---- images and textures in memory ----
struct Img {
    int w = 0, h = 0;
    std::vector<float> px;  // RGB, rows from the top
    Img() {}
    Img(int w_, int h_) : w(w_), h(h_), px((size_t)w_ * h_ * 3, 0.0f) {}
    float &at(int x, int y, int ch) { return px[((size_t)y * w + x) * 3 + ch]; }
    float at(int x, int y, int ch) const { return px[((size_t)y * w + x) * 3 + ch]; }
    void set(int x, int y, double r, double g, double b) {
        at(x, y, 0) = (float)r;
        at(x, y, 1) = (float)g;
        at(x, y, 2) = (float)b;
    }
    pray_image view() const {
        pray_image m;
        m.width = w;
        m.height = h;
        m.pixels = const_cast<float *>(px.data());
        return m;
    }
};

void sink(void *ud, const void *data, size_t n) { static_cast<std::string *>(ud)->append((const char *)data, n); }

// pray's own TIFF of an image (8 or 16 bits).
std::string tiff_bytes(pray_ctx *c, const Img &img, int bits) {
    std::string s;
    pray_image m = img.view();
    REQUIRE(pray_write_tiff(c, &m, bits, sink, &s) == PRAY_OK);
    return s;
}
pray_texture *texture_of(pray_ctx *c, const Img &img, int bits = 16, const char *name = "mem.tif") {
    std::string s = tiff_bytes(c, img, bits);
    pray_texture *t = pray_texture_tiff(c, s.data(), s.size(), name);
    REQUIRE_MESSAGE(t != nullptr, pray_error(c));
    return t;
}

// A 4 x 4 texture whose 16 texels all differ: texel (i, j) = {85 i, 85 j, 17 (4 j + i)} / 255.
Img distinct4() {
    Img m(4, 4);
    for (int j = 0; j < 4; j++)
        for (int i = 0; i < 4; i++) m.set(i, j, 85 * i / 255.0, 85 * j / 255.0, 17 * (4 * j + i) / 255.0);
    return m;
}
// A texture that encodes its own coordinates: bilinear between texel centres gives back
// (s, t, 0.25) exactly, away from the seams where the image repeats.
const int RAMP = 32;
Img ramp() {
    Img m(RAMP, RAMP);
    for (int j = 0; j < RAMP; j++)
        for (int i = 0; i < RAMP; i++) m.set(i, j, (i + 0.5) / RAMP, (j + 0.5) / RAMP, 0.25);
    return m;
}
// Is coordinate u far enough from the seam of the repeating ramp to be checked?
bool off_seam(double u) {
    double f = frac(u);
    return f > 1.0 / RAMP && f < 1 - 1.0 / RAMP;
}

// ---- cameras and rendering ----
struct Cam {
    pray_vec X, Y, E, P;
    int W, H;
    // the primary ray of pixel (i, j): section 4 of the language
    void ray(int i, int j, pray_vec *o, pray_vec *d) const {
        double u = 2 * (i + 0.5) / W - 1, v = 2 * (j + 0.5) / H - 1;
        *o = add(E, add(mul(X, u), mul(Y, v)));
        *d = unit(sub(P, E));
    }
};

Img render(pray_ctx *c, const Cam &cam, pray_object *o, pray_light *l = nullptr, pray_rgb bg = RGB(0, 0, 0)) {
    REQUIRE(o != nullptr);
    REQUIRE(pray_option(c, "width", cam.W) == PRAY_OK);
    REQUIRE(pray_option(c, "height", cam.H) == PRAY_OK);
    REQUIRE(pray_parallel(c, cam.X, cam.Y, cam.E, cam.P) == PRAY_OK);
    REQUIRE(pray_background(c, bg, bg) == PRAY_OK);
    pray_image im;
    pray_status st = pray_render(c, o, l, &im);
    REQUIRE_MESSAGE(st == PRAY_OK, pray_error(c));
    Img r(im.width, im.height);
    std::copy(im.pixels, im.pixels + r.px.size(), r.px.begin());
    pray_image_free(c, &im);
    return r;
}

// The flat textured model: the rendered colour is the texture's colour (color models are unlit).
pray_model *flat_textured(pray_ctx *c, pray_texture *t) {
    pray_model *black = pray_color(c, RGB(0, 0, 0)), *white = pray_color(c, RGB(1, 1, 1));
    pray_model *m = pray_tiff(c, black, white, t);
    pray_release(c, black);
    pray_release(c, white);
    REQUIRE(m != nullptr);
    return m;
}

// Ray queries on a prepared solid.
struct Probe {
    pray_ctx *c;
    pray_scene *s;
    Probe(pray_ctx *c_, pray_object *o) : c(c_), s(pray_prepare(c_, o)) { REQUIRE_MESSAGE(s != nullptr, pray_error(c_)); }
    ~Probe() { pray_scene_free(c, s); }
    std::vector<pray_hit> hits(pray_vec o, pray_vec d, double tmax = HUGE_VAL) const {
        std::vector<pray_hit> h(64);
        int n = pray_intersect(c, s, o, d, tmax, h.data(), (int)h.size());
        REQUIRE(n >= 0);
        REQUIRE(n <= 64);
        h.resize((size_t)n);
        return h;
    }
};

bool close_to(double a, double b, double tol = 1e-6) { return std::fabs(a - b) <= tol; }

// Tolerance of colours that depend on hit points: float renders (PRAY_REAL=float) move them a little.
const double TOL = 2e-3;

// =============================================================================================
// The corpus of make_tiffs.sh (generated once per run of the tests)
// =============================================================================================
struct Expect {
    int w = 0, h = 0;
    std::vector<double> v;  // RGB per pixel, rows from the first row of the file
};

struct Corpus {
    std::unique_ptr<TempDir> dir;
    std::string why;  // why there is no corpus ("" when there is one)
    std::vector<std::pair<std::string, std::string>> files, bad;  // (file, source) / (file, word)
    std::map<std::string, Expect> expect;
    std::string path(const std::string &f) const { return *dir / f; }
};

std::string find_script() {
    const char *cands[] = {"tests/make_tiffs.sh", "make_tiffs.sh", "../tests/make_tiffs.sh"};
    for (const char *p : cands)
        if (fs::exists(p)) return p;
    std::string here = fs::path(__FILE__).parent_path().string();
    if (!here.empty() && fs::exists(here + "/make_tiffs.sh")) return here + "/make_tiffs.sh";
    return "";
}

std::string python_with_pil() {
    const char *cands[] = {"/usr/bin/python3", "python3"};
    for (const char *c : cands)
        if (run_cmd(std::string(c) + " -c 'import PIL.Image'", nullptr) == 0) return c;
    return "";
}

const Corpus &corpus() {
    static Corpus k;
    static bool done = false;
    if (done) return k;
    done = true;
    std::string script = find_script(), py = python_with_pil(), out;
    if (script.empty()) return k.why = "tests/make_tiffs.sh not found (run the tests from the repository root)", k;
    if (run_cmd("command -v tiffcp", nullptr) != 0)
        return k.why = "tiffcp not found: install libtiff-tools (make deps)", k;
    if (py.empty()) return k.why = "no python3 with PIL: install python3-pil (make deps)", k;
    k.dir.reset(new TempDir());
    int rc = run_cmd("sh " + sq(script) + " " + sq(k.dir->path) + " " + sq(py), &out);
    if (rc != 0) return k.why = "make_tiffs.sh failed (" + std::to_string(rc) + "): " + out, k;
    std::ifstream list(*k.dir / "corpus.txt");
    std::string f, s;
    while (list >> f >> s) k.files.push_back(std::make_pair(f, s));
    std::ifstream bad(*k.dir / "bad.txt");
    std::string line;
    while (std::getline(bad, line)) {
        size_t sp = line.find(' ');
        if (sp != std::string::npos) k.bad.push_back(std::make_pair(line.substr(0, sp), line.substr(sp + 1)));
    }
    for (const auto &e : k.files) {
        if (k.expect.count(e.second)) continue;
        Expect &x = k.expect[e.second];
        std::ifstream in(*k.dir / (e.second + ".expect"));
        in >> x.w >> x.h;
        x.v.resize((size_t)x.w * x.h * 3);
        for (double &d : x.v) in >> d;
        if (!in) return k.why = "cannot read " + e.second + ".expect", k;
    }
    return k;
}

// Compare a texture with expected pixels, float for float; "" when they agree, else the first
// difference.
std::string differs(const pray_texture *t, const Expect &x) {
    int w = -1, h = -1;
    pray_texture_size(t, &w, &h);
    if (w != x.w || h != x.h)
        return "size " + std::to_string(w) + "x" + std::to_string(h) + ", expected " + std::to_string(x.w) + "x" +
               std::to_string(x.h);
    for (int y = 0; y < h; y++)
        for (int i = 0; i < w; i++) {
            pray_rgb p = pray_texture_pixel(t, i, y);
            const double *e = &x.v[((size_t)y * w + i) * 3];
            double got[3] = {p.r, p.g, p.b};
            for (int ch = 0; ch < 3; ch++)
                if ((float)got[ch] != (float)e[ch]) {
                    char b[200];
                    std::snprintf(b, sizeof b, "texel (%d, %d) channel %d is %.9g, expected %.9g", i, y, ch, got[ch],
                                  e[ch]);
                    return b;
                }
        }
    return "";
}

#define CORPUS_OR_SKIP(k)                                                                                      \
    const Corpus &k = corpus();                                                                                \
    if (!k.why.empty()) {                                                                                      \
        MESSAGE("skipped: " << k.why);                                                                         \
        return;                                                                                                \
    }

} // namespace

// =============================================================================================
// The TIFF reader
// =============================================================================================

TEST_CASE("TIFF reader: a corpus written by libtiff's tiffcp decodes to the source pixels") {
    CORPUS_OR_SKIP(k);
    // every layout of the issue is there: 13 sources x 2 byte orders x 3-4 compressions x 4 layouts
    CHECK(k.files.size() == 13 * 2 * 4 * 4 - 4 * 2 * 4);
    std::map<std::string, int> seen;
    Ctx c;
    int ok = 0;
    for (const auto &e : k.files) {
        CAPTURE(e.first);
        for (const char *part : {"_B_", "_L_", "_none_", "_packbits_", "_lzw_", "_lzwp2_", "_r1", "_r7", "_r64", "_t16"})
            if (contains(e.first, part)) seen[part]++;
        pray_texture *t = pray_texture_file(c, k.path(e.first).c_str());
        CHECK_MESSAGE(t != nullptr, pray_error(c));
        if (!t) continue;
        std::string d = differs(t, k.expect.at(e.second));
        CHECK_MESSAGE(d == "", e.first << ": " << d);
        ok += d == "";
        pray_release(c, t);
    }
    for (const auto &s : seen) CHECK_MESSAGE(s.second >= 40, s.first);
    CHECK(seen.size() == 10);
    CHECK(ok == (int)k.files.size());
    // the sources as written by PIL and by hand
    for (const auto &s : k.expect) {
        CAPTURE(s.first);
        pray_texture *t = pray_texture_file(c, k.path(s.first + ".tif").c_str());
        REQUIRE_MESSAGE(t != nullptr, pray_error(c));
        CHECK(differs(t, s.second) == "");
        pray_release(c, t);
    }
}

TEST_CASE("TIFF reader: the same bytes from memory; a file is decoded once per context") {
    CORPUS_OR_SKIP(k);
    Ctx c;
    for (const char *f : {"rgb16_B_lzwp2_t16.tif", "pal4_L_packbits_r7.tif", "white1_B_lzw_r1.tif"}) {
        CAPTURE(f);
        std::string bytes = slurp(k.path(f));
        pray_texture *t = pray_texture_tiff(c, bytes.data(), bytes.size(), f);
        REQUIRE_MESSAGE(t != nullptr, pray_error(c));
        std::string src = std::string(f).substr(0, std::string(f).find('_'));
        CHECK(differs(t, k.expect.at(src)) == "");
        pray_release(c, t);
    }
    pray_texture *a = pray_texture_file(c, k.path("rgb8_L_none_r7.tif").c_str());
    pray_texture *b = pray_texture_file(c, k.path("rgb8_L_none_r7.tif").c_str());
    REQUIRE(a != nullptr);
    CHECK(a == b);
    pray_release(c, a);
    pray_release(c, b);
}

TEST_CASE("TIFF reader: unsupported features are refused naming the file and the feature") {
    CORPUS_OR_SKIP(k);
    CHECK(k.bad.size() == 8);
    for (const auto &e : k.bad) {
        Ctx c;
        std::string p = k.path(e.first);
        CAPTURE(p);
        pray_texture *t = pray_texture_file(c, p.c_str());
        CHECK(t == nullptr);
        CHECK(pray_last_status(c) == PRAY_ERR_IO);
        std::string msg = pray_error(c);
        CAPTURE(msg);
        CHECK(contains(msg, p));
        CHECK(contains(msg, e.second));
        CHECK(contains(msg, "unsupported"));
    }
}

namespace {

// ---- a TIFF built field by field, to break it on purpose ----
struct TiffBuilder {
    bool big = false;
    struct Entry {
        unsigned tag, type;
        std::vector<uint32_t> vals;
        bool raw = false;  // write count/value as given, whatever the values
        uint32_t count = 0, value = 0;
    };
    std::vector<Entry> entries;
    std::string data;  // the image data, at offset 8
    long ifd_override = -1;
    int count_override = -1;  // number of directory entries claimed

    void put16(std::string &s, size_t at, unsigned v) const {
        if (s.size() < at + 2) s.resize(at + 2);
        s[at + (big ? 0 : 1)] = (char)(v >> 8 & 255);
        s[at + (big ? 1 : 0)] = (char)(v & 255);
    }
    void put32(std::string &s, size_t at, uint32_t v) const {
        put16(s, at + (big ? 0 : 2), v >> 16);
        put16(s, at + (big ? 2 : 0), v & 0xFFFF);
    }
    TiffBuilder &tag(unsigned t, unsigned type, std::vector<uint32_t> v) {
        for (Entry &e : entries)
            if (e.tag == t) {
                e.type = type;
                e.vals = v;
                e.raw = false;
                return *this;
            }
        Entry e;
        e.tag = t;
        e.type = type;
        e.vals = v;
        entries.push_back(e);
        std::sort(entries.begin(), entries.end(), [](const Entry &a, const Entry &b) { return a.tag < b.tag; });
        return *this;
    }
    TiffBuilder &raw(unsigned t, unsigned type, uint32_t count, uint32_t value) {
        tag(t, type, {});
        for (Entry &e : entries)
            if (e.tag == t) {
                e.raw = true;
                e.count = count;
                e.value = value;
            }
        return *this;
    }
    TiffBuilder &drop(unsigned t) {
        entries.erase(std::remove_if(entries.begin(), entries.end(), [t](const Entry &e) { return e.tag == t; }),
                      entries.end());
        return *this;
    }
    std::string build() const {
        std::string s(8, '\0');
        s[0] = s[1] = big ? 'M' : 'I';
        put16(s, 2, 42);
        s += data;
        if (s.size() % 2) s += '\0';
        size_t ifd = s.size();
        put32(s, 4, ifd_override >= 0 ? (uint32_t)ifd_override : (uint32_t)ifd);
        size_t blobs = ifd + 2 + 12 * entries.size() + 4;
        s.resize(blobs, '\0');
        put16(s, ifd, count_override >= 0 ? (unsigned)count_override : (unsigned)entries.size());
        for (size_t i = 0; i < entries.size(); i++) {
            const Entry &e = entries[i];
            size_t at = ifd + 2 + 12 * i;
            put16(s, at, e.tag);
            put16(s, at + 2, e.type);
            if (e.raw) {
                put32(s, at + 4, e.count);
                put32(s, at + 8, e.value);
                continue;
            }
            put32(s, at + 4, (uint32_t)e.vals.size());
            size_t sz = e.type == 3 ? 2 : e.type == 1 ? 1 : 4;
            size_t where = at + 8;
            if (sz * e.vals.size() > 4) {
                where = s.size();
                put32(s, at + 8, (uint32_t)where);
                s.resize(where + sz * e.vals.size(), '\0');
            }
            for (size_t k = 0; k < e.vals.size(); k++) {
                if (sz == 1) s[where + k] = (char)e.vals[k];
                else if (sz == 2) put16(s, where + 2 * k, e.vals[k]);
                else put32(s, where + 4 * k, e.vals[k]);
            }
        }
        return s;
    }
};

// A valid 4 x 3 RGB image, 8 bits, one uncompressed strip: sample k is 20 k.
TiffBuilder base_tiff() {
    TiffBuilder b;
    for (int k = 0; k < 36; k++) b.data += (char)(20 * k % 256);
    b.tag(256, 3, {4}).tag(257, 3, {3}).tag(258, 3, {8, 8, 8}).tag(259, 3, {1}).tag(262, 3, {2});
    b.tag(273, 4, {8}).tag(277, 3, {3}).tag(278, 3, {3}).tag(279, 4, {36});
    return b;
}

// LZW codes packed most significant bit first, the code width growing one code early (TIFF).
std::string lzw_pack(const std::vector<int> &codes) {
    std::string out;
    uint32_t acc = 0;
    int nacc = 0, width = 9, next = 258;
    bool first = true;  // the first code after a clear adds no table entry
    for (int code : codes) {
        acc = acc << width | (uint32_t)code;
        nacc += width;
        while (nacc >= 8) {
            out += (char)(acc >> (nacc - 8) & 255);
            nacc -= 8;
        }
        if (code == 256) {
            width = 9;
            next = 258;
            first = true;
        } else if (code != 257) {
            if (!first && next < 4096) next++;
            first = false;
            if (next + 1 >= (1 << width) && width < 12) width++;
        }
    }
    if (nacc) out += (char)(acc << (8 - nacc) & 255);
    return out;
}

// The codes of a byte string sent as literals only (a valid if lazy encoder): clear, the
// bytes, end. The decoder still adds a table entry for every code after the first.
std::vector<int> lzw_literals(const std::string &bytes) {
    std::vector<int> codes{256};
    for (unsigned char ch : bytes) codes.push_back(ch);
    codes.push_back(257);
    return codes;
}

// The decode must fail cleanly: NULL, PRAY_ERR_IO or PRAY_ERR_LIMIT, a message naming the file.
void check_refused(const std::string &bytes, const char *what, pray_status want = PRAY_OK,
                   const char *word = nullptr) {
    Ctx c;
    pray_texture *t = pray_texture_tiff(c, bytes.data(), bytes.size(), "bad.tif");
    std::string msg = pray_error(c);
    INFO(what, ": ", msg);
    CHECK(t == nullptr);
    pray_status st = pray_last_status(c);
    CHECK((st == PRAY_ERR_IO || st == PRAY_ERR_LIMIT));
    if (want != PRAY_OK) CHECK(st == want);
    CHECK(contains(msg, "bad.tif"));
    if (word) CHECK(contains(msg, word));
    if (t) pray_release(c, t);
}

} // namespace

TEST_CASE("TIFF reader: files built by hand, LZW and PackBits written by hand") {
    Ctx c;
    for (int big = 0; big < 2; big++) {
        TiffBuilder b = base_tiff();
        b.big = big;
        std::string s = b.build();
        pray_texture *t = pray_texture_tiff(c, s.data(), s.size(), "hand.tif");
        REQUIRE_MESSAGE(t != nullptr, pray_error(c));
        for (int y = 0; y < 3; y++)
            for (int x = 0; x < 4; x++) {
                pray_rgb p = pray_texture_pixel(t, x, y);
                int k = (y * 4 + x) * 3;
                CHECK(p.r == (double)(float)((20 * k % 256) / 255.0));
                CHECK(p.g == (double)(float)((20 * (k + 1) % 256) / 255.0));
                CHECK(p.b == (double)(float)((20 * (k + 2) % 256) / 255.0));
            }
        // outside the image: black
        pray_rgb o = pray_texture_pixel(t, 4, 0);
        CHECK((o.r == 0 && o.g == 0 && o.b == 0));
        o = pray_texture_pixel(t, 0, -1);
        CHECK((o.r == 0 && o.g == 0 && o.b == 0));
        pray_release(c, t);
        // the same data as LZW, every byte sent as a literal code (the decoder still grows its table)
        b.tag(259, 3, {5});
        std::string lz = lzw_pack(lzw_literals(b.data));
        TiffBuilder l = b;
        l.data = lz;
        l.tag(279, 4, {(uint32_t)lz.size()});
        s = l.build();
        t = pray_texture_tiff(c, s.data(), s.size(), "hand-lzw.tif");
        REQUIRE_MESSAGE(t != nullptr, pray_error(c));
        for (int k = 0; k < 36; k++) {
            pray_rgb q = pray_texture_pixel(t, k / 3 % 4, k / 12);
            CHECK((k % 3 == 0 ? q.r : k % 3 == 1 ? q.g : q.b) == (double)(float)((20 * k % 256) / 255.0));
        }
        pray_release(c, t);
    }
    // a grey image of the bytes a b a b a b a ... coded with table entries: KwKwK included
    TiffBuilder g = base_tiff();
    g.tag(258, 3, {8}).tag(277, 3, {1}).tag(262, 3, {1}).tag(259, 3, {5});
    // 12 bytes 10 20 10 20 ...: codes 10, 20, 258 (10 20), 260 (10 20 10, not yet in the table when
    // it is read), 259 (20 10), 20, 258 (10 20)
    std::string lz = lzw_pack({256, 10, 20, 258, 260, 259, 20, 258, 257});
    g.data = lz;
    g.tag(279, 4, {(uint32_t)lz.size()});
    std::string s = g.build();
    pray_texture *t = pray_texture_tiff(c, s.data(), s.size(), "kwk.tif");
    REQUIRE_MESSAGE(t != nullptr, pray_error(c));
    for (int x = 0; x < 12; x++)
        CHECK(pray_texture_pixel(t, x % 4, x / 4).r == (double)(float)((x % 2 ? 20 : 10) / 255.0));
    pray_release(c, t);
    // PackBits by hand: repeats, a literal run, and the no-op -128 that libtiff never writes:
    // 5 5 5 5 | 7 8 | 9 9 9 9 9 9
    TiffBuilder p = g;
    p.tag(259, 3, {32773});
    p.data = std::string("\xfd\x05\x80\x01\x07\x08\x80\xfb\x09", 9);
    p.tag(279, 4, {9});
    s = p.build();
    t = pray_texture_tiff(c, s.data(), s.size(), "packbits.tif");
    REQUIRE_MESSAGE(t != nullptr, pray_error(c));
    const int want[12] = {5, 5, 5, 5, 7, 8, 9, 9, 9, 9, 9, 9};
    for (int x = 0; x < 12; x++) CHECK(pray_texture_pixel(t, x % 4, x / 4).g == (double)(float)(want[x] / 255.0));
    pray_release(c, t);
}

TEST_CASE("TIFF reader: malformed files are refused with PRAY_ERR_IO or PRAY_ERR_LIMIT") {
    const std::string good = base_tiff().build();
    SUBCASE("headers") {
        check_refused("", "empty");
        check_refused("II*", "three bytes");
        check_refused(std::string("II*\0", 4), "four bytes");
        check_refused("XX" + good.substr(2), "bad byte order mark", PRAY_ERR_IO, "not a TIFF");
        std::string m = good;
        m[2] = 43;
        check_refused(m, "magic 43", PRAY_ERR_IO, "BigTIFF");
        m[2] = 41;
        check_refused(m, "magic 41", PRAY_ERR_IO, "not a TIFF");
        check_refused(std::string(100, '\xff'), "noise");
        check_refused(std::string("MM\0*", 4) + good.substr(4), "a little-endian file that says MM");
    }
    SUBCASE("directory offsets") {
        for (long off : {0L, 4L, 7L, (long)good.size() - 1, (long)good.size(), 0xFFFFFFF0L, 0x7FFFFFFFL}) {
            TiffBuilder b = base_tiff();
            b.ifd_override = off;
            check_refused(b.build(), ("IFD offset " + std::to_string(off)).c_str());
        }
        TiffBuilder b = base_tiff();
        b.count_override = 1000;
        check_refused(b.build(), "1000 directory entries");
        b.count_override = 0;
        check_refused(b.build(), "no directory entries", PRAY_ERR_IO, "size");
    }
    SUBCASE("tags") {
        check_refused(base_tiff().drop(256).build(), "no width", PRAY_ERR_IO);
        check_refused(base_tiff().drop(262).build(), "no photometric", PRAY_ERR_IO);
        check_refused(base_tiff().drop(273).build(), "no strip offsets", PRAY_ERR_IO, "strip");
        check_refused(base_tiff().raw(273, 4, 1000, 8).build(), "strip offsets: 1000 values outside the file");
        check_refused(base_tiff().raw(273, 4, 0x40000000, 8).build(), "strip offsets: 2^30 values");
        check_refused(base_tiff().raw(273, 4, 0xFFFFFFFF, 8).build(), "strip offsets: 2^32-1 values");
        check_refused(base_tiff().raw(258, 3, 3, 0xFFFFFFF0).build(), "bits per sample stored past the end");
        check_refused(base_tiff().raw(273, 0, 1, 8).build(), "tag type 0");
        check_refused(base_tiff().raw(273, 13, 1, 8).build(), "tag type 13");
        check_refused(base_tiff().tag(273, 5, {8, 1}).build(), "strip offsets as a rational");
        check_refused(base_tiff().tag(278, 3, {1}).build(), "three strips, one offset", PRAY_ERR_IO, "strip");
    }
    SUBCASE("sizes") {
        check_refused(base_tiff().tag(256, 4, {0}).build(), "width 0", PRAY_ERR_IO);
        check_refused(base_tiff().tag(257, 4, {0}).build(), "height 0", PRAY_ERR_IO);
        check_refused(base_tiff().tag(256, 4, {65537}).build(), "width 65537", PRAY_ERR_IO);
        check_refused(base_tiff().tag(256, 4, {0xFFFFFFFF}).build(), "width 2^32-1", PRAY_ERR_IO);
        check_refused(base_tiff().tag(256, 4, {65536}).tag(257, 4, {65536}).build(), "65536 x 65536",
                      PRAY_ERR_LIMIT);
        check_refused(base_tiff().tag(256, 4, {30000}).tag(257, 4, {30000}).tag(278, 3, {1}).build(),
                      "30000 x 30000 in strips of one row", PRAY_ERR_LIMIT);
        // under the memory limit, but the data is missing
        check_refused(base_tiff().tag(256, 4, {1000}).tag(257, 4, {1000}).build(), "1000 x 1000 in 36 bytes",
                      PRAY_ERR_IO);
        // tiles
        TiffBuilder t = base_tiff();
        t.drop(273).drop(278).drop(279);
        t.tag(322, 3, {16}).tag(323, 3, {16}).tag(324, 4, {8}).tag(325, 4, {36});
        check_refused(t.build(), "a 16 x 16 tile in 36 bytes", PRAY_ERR_IO);
        check_refused(TiffBuilder(t).tag(322, 3, {0}).build(), "tile width 0", PRAY_ERR_IO, "tile");
        check_refused(TiffBuilder(t).drop(323).build(), "no tile length", PRAY_ERR_IO, "tile");
        check_refused(TiffBuilder(t).drop(324).build(), "no tile offsets", PRAY_ERR_IO, "tile");
        check_refused(TiffBuilder(t).tag(322, 4, {65536}).tag(323, 4, {65536}).build(), "65536 x 65536 tiles",
                      PRAY_ERR_LIMIT);
        check_refused(TiffBuilder(t).tag(322, 3, {1}).tag(323, 3, {1}).build(), "1 x 1 tiles, one offset",
                      PRAY_ERR_IO);
    }
    SUBCASE("blocks past the end") {
        uint32_t n = (uint32_t)good.size();
        check_refused(base_tiff().tag(273, 4, {n + 100}).build(), "strip offset past the end", PRAY_ERR_IO);
        check_refused(base_tiff().tag(273, 4, {n}).build(), "strip offset at the end", PRAY_ERR_IO);
        check_refused(base_tiff().tag(273, 4, {0xFFFFFFFF}).build(), "strip offset 2^32-1", PRAY_ERR_IO);
        check_refused(base_tiff().tag(279, 4, {0xFFFFFFFF}).build(), "strip byte count 2^32-1", PRAY_ERR_IO);
        check_refused(base_tiff().tag(279, 4, {n}).build(), "strip byte count past the end", PRAY_ERR_IO);
        check_refused(base_tiff().tag(279, 4, {35}).build(), "strip one byte short", PRAY_ERR_IO);
        check_refused(base_tiff().tag(273, 4, {n - 10}).drop(279).build(), "no byte counts, data past the end",
                      PRAY_ERR_IO);
    }
    SUBCASE("unsupported values") {
        struct {
            unsigned tag;
            std::vector<uint32_t> v;
            const char *word;
        } cases[] = {
            {258, {3, 3, 3}, "3 bits"},       {258, {32, 32, 32}, "32 bits"}, {258, {8, 16, 8}, "different"},
            {259, {7}, "JPEG compression (7)"}, {259, {8}, "Deflate compression (8)"}, {259, {2}, "CCITT fax compression (2)"},
            {259, {0}, "compression"},        {317, {3}, "predictor 3"},     {284, {2}, "separate"},
            {262, {5}, "photometric"},        {262, {6}, "photometric"},     {262, {32844}, "photometric"},
            {277, {2}, "samples"},            {277, {5}, "samples"},         {339, {3}, "floating-point samples"},
            {339, {2}, "signed integer samples"},    {262, {3}, "samples"},
        };
        for (const auto &k : cases) {
            std::string what = "tag " + std::to_string(k.tag) + " = " + std::to_string(k.v[0]);
            check_refused(base_tiff().tag(k.tag, 3, k.v).build(), what.c_str(), PRAY_ERR_IO, k.word);
        }
        check_refused(base_tiff().tag(262, 3, {3}).tag(277, 3, {1}).tag(258, 3, {8}).build(), "palette without a colour map",
                      PRAY_ERR_IO, "colour map");
        // a palette with a short colour map, RGB in 4 bits, a 16-bit palette, the predictor on 4 bits
        check_refused(base_tiff().tag(262, 3, {3}).tag(277, 3, {1}).tag(258, 3, {8}).tag(320, 3, std::vector<uint32_t>(700, 1)).build(),
                      "short colour map", PRAY_ERR_IO, "colour map");
        check_refused(base_tiff().tag(258, 3, {4, 4, 4}).build(), "RGB in 4 bits", PRAY_ERR_IO, "RGB");
        check_refused(base_tiff().tag(262, 3, {3}).tag(277, 3, {1}).tag(258, 3, {16}).tag(320, 3, std::vector<uint32_t>(3 * 65536, 1)).build(),
                      "16-bit palette", PRAY_ERR_IO, "palette");
        check_refused(base_tiff().tag(262, 3, {1}).tag(277, 3, {1}).tag(258, 3, {4}).tag(317, 3, {2}).build(),
                      "predictor on 4 bits", PRAY_ERR_IO, "predictor");
    }
    SUBCASE("corrupt PackBits and LZW") {
        TiffBuilder b = base_tiff();
        b.tag(259, 3, {32773});
        // a literal run of 128 bytes in a 36-byte strip; a run that needs more input than there is
        b.data = std::string("\x7f") + std::string(35, 'x');
        b.tag(279, 4, {36});
        check_refused(b.build(), "PackBits literal run past the input", PRAY_ERR_IO, "corrupt");
        b.data = std::string("\x81", 1);
        b.tag(279, 4, {1});
        check_refused(b.build(), "PackBits repeat without its byte", PRAY_ERR_IO, "corrupt");
        b.data = std::string("\x80\x80\x80\x80", 4);  // only no-ops
        b.tag(279, 4, {4});
        check_refused(b.build(), "PackBits no-ops only", PRAY_ERR_IO, "corrupt");
        b.data = std::string("\xdc\x07", 2) + std::string("\xdc\x07", 2);  // 37 + 37 bytes into 36
        b.tag(279, 4, {4});
        check_refused(b.build(), "PackBits repeat past the output", PRAY_ERR_IO, "corrupt");

        TiffBuilder l = base_tiff();
        l.tag(259, 3, {5});
        std::vector<int> codes = lzw_literals(l.data);
        auto with = [&](const std::string &d) {
            TiffBuilder x = l;
            x.data = d;
            x.tag(279, 4, {(uint32_t)d.size()});
            return x.build();
        };
        std::vector<int> c1 = codes;
        c1[1] = 300;  // a code not yet in the table
        check_refused(with(lzw_pack(c1)), "LZW: first code 300", PRAY_ERR_IO, "corrupt");
        std::vector<int> c2 = codes;
        c2[20] = 4000;
        check_refused(with(lzw_pack(c2)), "LZW: code 4000 in the middle", PRAY_ERR_IO, "corrupt");
        std::vector<int> c3 = codes;
        c3[2] = 259;  // the next code after one literal is 258; 259 is not there yet
        check_refused(with(lzw_pack(c3)), "LZW: a code one past the table", PRAY_ERR_IO, "corrupt");
        std::vector<int> c4(codes.begin(), codes.begin() + 20);
        c4.push_back(257);
        check_refused(with(lzw_pack(c4)), "LZW: ends early", PRAY_ERR_IO, "corrupt");
        check_refused(with(lzw_pack({256, 256, 256, 257})), "LZW: only clears", PRAY_ERR_IO, "corrupt");
        check_refused(with(std::string(60, '\xff')), "LZW: all ones", PRAY_ERR_IO, "corrupt");
        check_refused(with(""), "LZW: empty strip", PRAY_ERR_IO);
        check_refused(with(lzw_pack({256, 258, 257})), "LZW: clear then 258", PRAY_ERR_IO, "corrupt");
    }
}

TEST_CASE("TIFF reader: truncated files are refused, never half read") {
    std::vector<std::pair<std::string, std::string>> files;  // name, bytes
    {
        Ctx c;
        Img m(9, 7);
        for (size_t i = 0; i < m.px.size(); i++) m.px[i] = (float)((i * 37 % 256) / 255.0);
        files.push_back(std::make_pair("pray 8-bit", tiff_bytes(c, m, 8)));
        files.push_back(std::make_pair("pray 16-bit", tiff_bytes(c, m, 16)));
    }
    const Corpus &k = corpus();
    if (k.why.empty())
        for (const char *f : {"rgb8_L_lzw_r7.tif", "rgb16_B_none_t16.tif", "pal4_L_packbits_r1.tif",
                              "grey16_B_lzwp2_t16.tif", "bilevel1_L_lzw_r64.tif", "rgba8_B_packbits_r64.tif"})
            files.push_back(std::make_pair(f, slurp(k.path(f))));
    else
        MESSAGE("tiffcp files left out: " << k.why);
    for (const auto &f : files) {
        CAPTURE(f.first);
        Ctx c;
        pray_texture *whole = pray_texture_tiff(c, f.second.data(), f.second.size(), "whole.tif");
        REQUIRE_MESSAGE(whole != nullptr, pray_error(c));
        int refused = 0, bad_status = 0, read = 0, read_short = 0, wrong = 0;
        std::string first_bad;
        for (size_t n = 0; n < f.second.size(); n++) {
            std::string cut = f.second.substr(0, n);
            pray_texture *t = pray_texture_tiff(c, cut.data(), cut.size(), "cut.tif");
            if (!t) {
                pray_status st = pray_last_status(c);
                if (st == PRAY_ERR_IO || st == PRAY_ERR_LIMIT) refused++;
                else if (bad_status++ == 0) first_bad = std::to_string(n) + ": " + pray_error(c);
                pray_clear_error(c);
                continue;
            }
            // a shorter file that still decodes must decode to the same pixels
            read++;
            read_short += n + 4 < f.second.size();
            int w, h, W, H;
            pray_texture_size(t, &w, &h);
            pray_texture_size(whole, &W, &H);
            bool same = w == W && h == H;
            for (int y = 0; same && y < h; y++)
                for (int x = 0; same && x < w; x++) {
                    pray_rgb a = pray_texture_pixel(t, x, y), b = pray_texture_pixel(whole, x, y);
                    same = a.r == b.r && a.g == b.g && a.b == b.b;
                }
            wrong += !same;
            pray_release(c, t);
        }
        CHECK_MESSAGE(bad_status == 0, first_bad);
        CHECK(wrong == 0);
        // the image data ends the file (pray) or the directory does (tiffcp): no prefix is enough,
        // but for the directory's last field, the offset of the next directory, which is not read
        CHECK(read_short == 0);
        CHECK(refused + read == (int)f.second.size());
        pray_release(c, whole);
    }
}

TEST_CASE("TIFF reader: mutated files never crash it (fixed-seed fuzz)") {
    std::vector<std::string> seeds;
    {
        Ctx c;
        Img m(5, 4);
        for (size_t i = 0; i < m.px.size(); i++) m.px[i] = (float)((i * 53 % 256) / 255.0);
        seeds.push_back(tiff_bytes(c, m, 8));
        seeds.push_back(tiff_bytes(c, m, 16));
    }
    const Corpus &k = corpus();
    if (k.why.empty())
        for (const char *f : {"rgb8_L_lzw_r7.tif", "grey16_B_lzwp2_t16.tif", "pal4_L_packbits_r1.tif",
                              "white1_B_lzw_t16.tif", "rgba16_L_lzwp2_r64.tif", "pal8_B_packbits_t16.tif"})
            seeds.push_back(slurp(k.path(f)));
    std::mt19937 rng(20240601);
    int ok = 0, refused = 0, other = 0;
    std::string first_other;
    Ctx c;
    for (size_t s = 0; s < seeds.size(); s++)
        for (int iter = 0; iter < 250; iter++) {
            std::string b = seeds[s];
            int edits = 1 + (int)(rng() % 4);
            for (int e = 0; e < edits; e++) {
                size_t at = rng() % b.size();
                switch (rng() % 4) {
                case 0: b[at] = (char)(rng() & 255); break;
                case 1: b[at] ^= (char)(1 << (rng() % 8)); break;
                case 2: b[at] = (char)(rng() % 2 ? 0xFF : 0); break;
                default:  // the directory and the header are the interesting part of small files
                    at = rng() % std::min<size_t>(b.size(), 16);
                    b[at] = (char)(rng() & 255);
                }
            }
            if (rng() % 8 == 0) b.resize(rng() % b.size());
            pray_texture *t = pray_texture_tiff(c, b.data(), b.size(), "fuzz.tif");
            if (t) {
                ok++;
                int w, h;
                pray_texture_size(t, &w, &h);
                CHECK((w >= 1 && h >= 1 && w <= 65536 && h <= 65536));
                for (int y = 0; y < h && y < 64; y++)
                    for (int x = 0; x < w && x < 64; x++) {
                        pray_rgb p = pray_texture_pixel(t, x, y);
                        if (!(p.r >= 0 && p.r <= 1 && p.g >= 0 && p.g <= 1 && p.b >= 0 && p.b <= 1)) {
                            FAIL_CHECK("texel out of [0, 1] in mutation " << iter << " of seed " << s);
                            y = h;
                            break;
                        }
                    }
                pray_release(c, t);
            } else {
                pray_status st = pray_last_status(c);
                if (st == PRAY_ERR_IO || st == PRAY_ERR_LIMIT) refused++;
                else if (other++ == 0) first_other = pray_error(c);
                pray_clear_error(c);
            }
        }
    CHECK_MESSAGE(other == 0, first_other);
    CHECK(ok + refused == (int)seeds.size() * 250);
}

TEST_CASE("TIFF reader: every TIFF pray writes, pray reads back identically") {
    Ctx c;
    for (int bits : {8, 16}) {
        CAPTURE(bits);
        const double maxv = bits == 8 ? 255 : 65535;
        for (auto wh : {std::make_pair(1, 1), std::make_pair(1, 300), std::make_pair(300, 1), std::make_pair(37, 23)}) {
            CAPTURE(wh.first);
            CAPTURE(wh.second);
            Img m(wh.first, wh.second);
            std::mt19937 rng(7 + wh.first);
            std::vector<double> want(m.px.size());
            for (size_t i = 0; i < m.px.size(); i++) {
                switch (i % 5) {
                case 0: {  // exact sample values
                    unsigned k = (unsigned)(rng() % ((unsigned)maxv + 1));
                    m.px[i] = (float)(k / maxv);
                    want[i] = k / maxv;
                    break;
                }
                case 1: m.px[i] = -0.5f; want[i] = 0; break;  // clamped
                case 2: m.px[i] = 7.0f; want[i] = 1; break;
                default: {  // anything in between: the nearest sample value
                    float v = (float)((rng() % 1000000) / 1e6);
                    m.px[i] = v;
                    want[i] = std::floor(v * maxv + 0.5) / maxv;
                }
                }
            }
            std::string bytes = tiff_bytes(c, m, bits);
            pray_texture *t = pray_texture_tiff(c, bytes.data(), bytes.size(), "rt.tif");
            REQUIRE_MESSAGE(t != nullptr, pray_error(c));
            int w, h, bad = 0;
            pray_texture_size(t, &w, &h);
            REQUIRE(w == m.w);
            REQUIRE(h == m.h);
            Img back(w, h);
            for (int y = 0; y < h; y++)
                for (int x = 0; x < w; x++) {
                    pray_rgb p = pray_texture_pixel(t, x, y);
                    back.set(x, y, p.r, p.g, p.b);
                    double got[3] = {p.r, p.g, p.b};
                    for (int ch = 0; ch < 3; ch++) {
                        size_t i = ((size_t)y * w + x) * 3 + ch;
                        // exact where the value is a sample value; within half a step elsewhere
                        double tol = i % 5 <= 2 ? 0 : 0.5 / maxv + 1e-7;
                        if (i % 5 <= 2 ? (float)got[ch] != (float)want[i] : std::fabs(got[ch] - m.px[i]) > tol) bad++;
                    }
                }
            CHECK(bad == 0);
            // and what was read, written again, is the same file byte for byte
            CHECK(tiff_bytes(c, back, bits) == bytes);
            pray_release(c, t);
        }
    }
    // through a file: pray_write_image, then pray_texture_file
    TempDir d;
    Img m = distinct4();
    for (int bits : {8, 16}) {
        std::string p = d / ("rt" + std::to_string(bits) + ".tif");
        pray_image v = m.view();
        REQUIRE(pray_write_image(c, &v, p.c_str(), bits) == PRAY_OK);
        pray_texture *t = pray_texture_file(c, p.c_str());
        REQUIRE_MESSAGE(t != nullptr, pray_error(c));
        for (int y = 0; y < 4; y++)
            for (int x = 0; x < 4; x++) {
                pray_rgb q = pray_texture_pixel(t, x, y);
                CHECK(q.r == (double)(float)(85 * x / 255.0));
                CHECK(q.g == (double)(float)(85 * y / 255.0));
                CHECK(q.b == (double)(float)(17 * (4 * y + x) / 255.0));
            }
        pray_release(c, t);
    }
}

TEST_CASE("textures: missing and unreadable files through the API") {
    Ctx c;
    CHECK(pray_texture_file(c, "/nonexistent/dir/none.tif") == nullptr);
    CHECK(pray_last_status(c) == PRAY_ERR_IO);
    CHECK(contains(pray_error(c), "/nonexistent/dir/none.tif"));
    TempDir d;
    spit(d / "text.tif", "this is not a TIFF file at all\n");
    CHECK(pray_texture_file(c, (d / "text.tif").c_str()) == nullptr);
    CHECK(pray_last_status(c) == PRAY_ERR_IO);
    CHECK(contains(pray_error(c), d / "text.tif"));
    CHECK(pray_texture_file(c, d.path.c_str()) == nullptr);  // a directory
    pray_status st = pray_last_status(c);
    CHECK((st == PRAY_ERR_IO || st == PRAY_ERR_LIMIT));
    CHECK(pray_texture_file(c, "") == nullptr);
    CHECK(pray_texture_file(c, nullptr) == nullptr);
    CHECK(pray_texture_tiff(c, nullptr, 10, "x") == nullptr);
    // NULL texture: makers return NULL; no size
    pray_model *m = pray_color(c, RGB(1, 1, 1));
    CHECK(pray_tiff(c, m, m, nullptr) == nullptr);
    CHECK(pray_tiffbump(c, m, 1, nullptr) == nullptr);
    int w = 5, h = 5;
    pray_texture_size(nullptr, &w, &h);
    CHECK((w == 0 && h == 0));
    pray_release(c, m);
}

TEST_CASE("textures: a program in another directory finds a texture by an absolute or a relative name") {
    TempDir d;
    REQUIRE(std::system(("mkdir " + sq(d / "sub")).c_str()) == 0);
    std::vector<float> px = {0, 0.5f, 1};
    pray_image img = {1, 1, px.data()};
    Ctx c;
    REQUIRE(pray_write_image(c, &img, (d / "t.tif").c_str(), 8) == PRAY_OK);
    // the absolute name as written (not joined to the program's directory); "../t.tif" beside it
    for (const std::string &name : {d / "t.tif", std::string("../t.tif")}) {
        CAPTURE(name);
        spit(d / "sub/p.ray", "option \"width\", 2\noption \"height\", 2\noption \"output\", \"" + (d / "o.ppm") +
                                  "\"\nrendertiff sphere(tiff(color({1}), color({0}), \"" + name + "\"), [0, 0, 0], 9)\n");
        Ctx k;
        CHECK_MESSAGE(pray_run_file(k, (d / "sub/p.ray").c_str()) == PRAY_OK, pray_error(k));
    }
}

// =============================================================================================
// Texture coordinates
// =============================================================================================
namespace {

// Looking straight down -Z at the plane z = z0 from above: a W x W image covering
// [-half, half]^2; pixel (i, j) sees x = half (2(i + 1/2)/W - 1), y = half (2(j + 1/2)/W - 1).
Cam top_view(int W, double half, double z0 = 0) {
    return Cam{V3(half, 0, 0), V3(0, half, 0), V3(0, 0, z0 + 10), V3(0, 0, z0), W, W};
}

// The expected ramp colour at (s, t) and whether it may be checked (away from the seams).
void check_ramp(const Img &img, int i, int j, double s, double t, int *checked, int *bad, std::string *first) {
    if (!off_seam(s) || !off_seam(t)) return;
    (*checked)++;
    double e[3] = {frac(s), frac(t), 0.25};
    for (int ch = 0; ch < 3; ch++)
        if (std::fabs(img.at(i, j, ch) - e[ch]) > TOL) {
            if ((*bad)++ == 0) {
                char b[200];
                std::snprintf(b, sizeof b, "pixel (%d, %d): colour %.5f %.5f %.5f, expected s %.5f t %.5f", i, j,
                              img.at(i, j, 0), img.at(i, j, 1), img.at(i, j, 2), e[0], e[1]);
                *first = b;
            }
            return;
        }
}

// Rotation by ax about X, then ay about Y, then az about Z, degrees (the `.` of the language).
pray_vec rot_xyz(pray_vec v, pray_vec deg) {
    const double k = 3.14159265358979323846 / 180;
    double a = deg.x * k, b = deg.y * k, g = deg.z * k;
    v = V3(v.x, v.y * std::cos(a) - v.z * std::sin(a), v.y * std::sin(a) + v.z * std::cos(a));
    v = V3(v.x * std::cos(b) + v.z * std::sin(b), v.y, -v.x * std::sin(b) + v.z * std::cos(b));
    v = V3(v.x * std::cos(g) - v.y * std::sin(g), v.x * std::sin(g) + v.y * std::cos(g), v.z);
    return v;
}

// A planemap seen by a camera: every pixel checked against s = (x-P).U/|U|^2, t = (x-P).V/|V|^2.
void check_planemap(const Img &img, const Cam &cam, pray_vec P, pray_vec N, pray_vec U, pray_vec Vv, int min_checked) {
    int checked = 0, bad = 0;
    std::string first;
    for (int j = 0; j < cam.H; j++)
        for (int i = 0; i < cam.W; i++) {
            pray_vec o, d;
            cam.ray(i, j, &o, &d);
            double dn = dot(d, N);
            REQUIRE(dn < 0);
            pray_vec x = add(o, mul(d, dot(sub(P, o), N) / dn));
            double s = dot(sub(x, P), U) / dot(U, U), t = dot(sub(x, P), Vv) / dot(Vv, Vv);
            check_ramp(img, i, j, s, t, &checked, &bad, &first);
        }
    CHECK_MESSAGE(bad == 0, bad << " of " << checked << " pixels; first: " << first);
    CHECK(checked >= min_checked);
}

// Where a ray meets a sphere first (false when it misses or grazes).
bool sphere_hit(pray_vec o, pray_vec d, pray_vec C, double r, pray_vec *x, pray_vec *n) {
    pray_vec oc = sub(o, C);
    double b = dot(oc, d), c = dot(oc, oc) - r * r, disc = b * b - c;
    if (disc <= 0) return false;
    double t = -b - std::sqrt(disc);
    *x = add(o, mul(d, t));
    *n = mul(sub(*x, C), 1 / r);
    return true;
}

// The spheremap's coordinates of the unit normal n: U to the north pole, V to longitude 0;
// longitude grows from V towards U x V (right-handed about the north), t = polar angle from the
// south pole / 180 degrees.
void sphere_st(pray_vec n, pray_vec U, pray_vec Vv, double *s, double *t) {
    const double PI = 3.14159265358979323846;
    pray_vec north = unit(U), e0 = unit(sub(Vv, mul(north, dot(Vv, north)))), e90 = cross(north, e0);
    double lon = std::atan2(dot(n, e90), dot(n, e0));
    if (lon < 0) lon += 2 * PI;
    *s = lon / (2 * PI);
    *t = std::acos(std::max(-1.0, std::min(1.0, -dot(n, north)))) / PI;
}

void check_spheremap(const Img &img, const Cam &cam, pray_vec C, double r, pray_vec U, pray_vec Vv, int min_checked) {
    int checked = 0, bad = 0, hits = 0;
    std::string first;
    for (int j = 0; j < cam.H; j++)
        for (int i = 0; i < cam.W; i++) {
            pray_vec o, d, x, n;
            cam.ray(i, j, &o, &d);
            if (!sphere_hit(o, d, C, r, &x, &n)) continue;
            // well inside the silhouette and away from the poles, where the coordinates are steady
            if (-dot(n, d) < 0.3 || std::fabs(dot(n, unit(U))) > 0.95) continue;
            hits++;
            double s, t;
            sphere_st(n, U, Vv, &s, &t);
            check_ramp(img, i, j, s, t, &checked, &bad, &first);
        }
    CHECK_MESSAGE(bad == 0, bad << " of " << checked << " pixels; first: " << first);
    CHECK(checked >= min_checked);
}

} // namespace

TEST_CASE("textures: planemap texels at known points, t from the first row, repeating") {
    Ctx c;
    Img tex = distinct4();
    pray_texture *t = texture_of(c, tex, 8);
    // the texture as stored: rows from the first row of the file
    for (int y = 0; y < 4; y++)
        for (int x = 0; x < 4; x++) {
            pray_rgb p = pray_texture_pixel(t, x, y);
            CHECK(p.r == (double)tex.at(x, y, 0));
            CHECK(p.g == (double)tex.at(x, y, 1));
            CHECK(p.b == (double)tex.at(x, y, 2));
        }
    pray_model *m = flat_textured(c, t);
    // the plane z <= 0 with U = X, V = Y: one copy of the image per unit square; pixel (i, j) of a
    // 16 x 16 view of [-2, 2]^2 sees s = (i + 1/2)/4 - 2, t = (j + 1/2)/4 - 2: texel (i%4, j%4)
    // at its centre, 4 x 4 copies
    pray_object *o = pray_planemap(c, m, V3(0, 0, 0), V3(0, 0, 1), V3(1, 0, 0), V3(0, 1, 0));
    Img img = render(c, top_view(16, 2), o);
    int bad = 0;
    for (int j = 0; j < 16; j++)
        for (int i = 0; i < 16; i++)
            for (int ch = 0; ch < 3; ch++)
                if (std::fabs(img.at(i, j, ch) - tex.at(i % 4, j % 4, ch)) > 1e-3) {
                    if (bad++ < 5)
                        FAIL_CHECK("pixel (" << i << ", " << j << ") channel " << ch << ": " << img.at(i, j, ch)
                                             << ", expected texel (" << i % 4 << ", " << j % 4 << ") = "
                                             << tex.at(i % 4, j % 4, ch));
                }
    CHECK(bad == 0);
    // P moves the origin of the coordinates: P = (0.25, 0.5, 0) shifts by one texel in s, two in t
    pray_object *o2 = pray_planemap(c, m, V3(0.25, 0.5, 0), V3(0, 0, 1), V3(1, 0, 0), V3(0, 1, 0));
    Img img2 = render(c, top_view(16, 2), o2);
    bad = 0;
    for (int j = 0; j < 16; j++)
        for (int i = 0; i < 16; i++)
            for (int ch = 0; ch < 3; ch++)
                bad += std::fabs(img2.at(i, j, ch) - tex.at((i + 3) % 4, (j + 2) % 4, ch)) > 1e-3;
    CHECK(bad == 0);
    // bilinear and tiled: half a texel further on (P = (1/8, 1/8, 0)) every pixel sits where four
    // texels meet and is their mean, across the edges of the image too (texels 3 and 0 meet there)
    pray_object *o5 = pray_planemap(c, m, V3(0.125, 0.125, 0), V3(0, 0, 1), V3(1, 0, 0), V3(0, 1, 0));
    Img img5 = render(c, top_view(16, 2), o5);
    bad = 0;
    for (int j = 0; j < 16; j++)
        for (int i = 0; i < 16; i++)
            for (int ch = 0; ch < 3; ch++) {
                int i0 = (i + 3) % 4, i1 = i % 4, j0 = (j + 3) % 4, j1 = j % 4;
                double mean = (tex.at(i0, j0, ch) + tex.at(i1, j0, ch) + tex.at(i0, j1, ch) + tex.at(i1, j1, ch)) / 4;
                bad += std::fabs(img5.at(i, j, ch) - mean) > 1e-3;
            }
    CHECK(bad == 0);
    pray_release(c, o5);
    // U and V of length 2 stretch one copy over 2 x 2 units: the same texels seen from twice as far
    pray_object *o3 = pray_planemap(c, m, V3(0, 0, 0), V3(0, 0, 1), V3(2, 0, 0), V3(0, 2, 0));
    Img img3 = render(c, top_view(16, 4), o3);
    CHECK(std::equal(img3.px.begin(), img3.px.end(), img.px.begin(),
                     [](float a, float b) { return std::fabs(a - b) <= 1e-3; }));
    // tiff(M0, M1, F) is M0 (1 - c) + M1 c per channel
    pray_model *m0 = pray_color(c, RGB(0.2, 0.4, 0.6)), *m1 = pray_color(c, RGB(1, 0, 0.5));
    pray_model *blend = pray_tiff(c, m0, m1, t);
    pray_object *o4 = pray_planemap(c, blend, V3(0, 0, 0), V3(0, 0, 1), V3(1, 0, 0), V3(0, 1, 0));
    Img img4 = render(c, top_view(16, 2), o4);
    const double a0[3] = {0.2, 0.4, 0.6}, a1[3] = {1, 0, 0.5};
    bad = 0;
    for (int j = 0; j < 16; j++)
        for (int i = 0; i < 16; i++)
            for (int ch = 0; ch < 3; ch++) {
                double cv = tex.at(i % 4, j % 4, ch);
                bad += std::fabs(img4.at(i, j, ch) - (a0[ch] * (1 - cv) + a1[ch] * cv)) > 1e-3;
            }
    CHECK(bad == 0);
    pray_release(c, o4);
    pray_release(c, blend);
    pray_release(c, m0);
    pray_release(c, m1);
    pray_release(c, o);
    pray_release(c, o2);
    pray_release(c, o3);
    pray_release(c, m);
    pray_release(c, t);
}

TEST_CASE("textures: solids without coordinates read the image at (0, 0)") {
    // the manual: sphere, plane, cylinder and the boxes of text have (s, t) = (0, 0) everywhere;
    // bilinear and tiled, (0, 0) is where the corner texels (0,0), (3,0), (0,3), (3,3) meet
    Ctx c;
    Img tex = distinct4();
    pray_texture *t = texture_of(c, tex, 8);
    pray_model *m = flat_textured(c, t);
    double mean[3];
    for (int ch = 0; ch < 3; ch++)
        mean[ch] = (tex.at(0, 0, ch) + tex.at(3, 0, ch) + tex.at(0, 3, ch) + tex.at(3, 3, ch)) / 4;
    pray_object *objs[] = {pray_sphere(c, m, V3(0, 0, -1), 1.5), pray_plane(c, m, V3(0, 0, 0), V3(0.1, 0.2, 1)),
                           pray_cylinder(c, m, V3(0, 0, 0), V3(1, 1, 0), 1),
                           pray_text(c, m, "#", V3(-1.5, -1.5, 0), V3(3, 0, 0), V3(0, 3, 0), 1, nullptr, 1)};
    for (pray_object *o : objs) {
        // (the mean happens to be grey 0.5: a background that is not)
        Img img = render(c, top_view(16, 2), o, nullptr, RGB(0.9, 0.1, 0.3));
        int hit = 0, bad = 0;
        for (int j = 0; j < 16; j++)
            for (int i = 0; i < 16; i++) {
                if (img.at(i, j, 0) == 0.9f && img.at(i, j, 1) == 0.1f && img.at(i, j, 2) == 0.3f) continue;
                hit++;
                for (int ch = 0; ch < 3; ch++) bad += std::fabs(img.at(i, j, ch) - mean[ch]) > 1e-4;
            }
        CHECK(hit > 20);
        CHECK(bad == 0);
        pray_release(c, o);
    }
    pray_release(c, m);
    pray_release(c, t);
}

TEST_CASE("textures: planemap coordinates follow the formula for any P, U, V") {
    Ctx c;
    pray_texture *t = texture_of(c, ramp());
    pray_model *m = flat_textured(c, t);
    struct {
        pray_vec P, U, V;
    } cases[] = {
        {V3(0, 0, 0), V3(1, 0, 0), V3(0, 1, 0)},
        {V3(0.3, -0.2, 0), V3(0, 1.5, 0), V3(-0.75, 0, 0)},
        {V3(-0.1, 0.45, 0), V3(0.6, 0.6, 0), V3(-1.2, 1.2, 0)},
        // U and V with a component along the normal: only their projections count in (x-P).U
        {V3(0.2, 0.1, 0), V3(1, 0, 0.5), V3(0, 0.8, -0.3)},
    };
    for (const auto &k : cases) {
        CAPTURE(k.U.y);
        pray_object *o = pray_planemap(c, m, k.P, V3(0, 0, 1), k.U, k.V);
        Cam cam = top_view(48, 2);
        Img img = render(c, cam, o);
        check_planemap(img, cam, k.P, V3(0, 0, 1), k.U, k.V, 1000);
        pray_release(c, o);
    }
    pray_release(c, m);
    pray_release(c, t);
}

TEST_CASE("textures: move shifts the texture coordinates") {
    Ctx c;
    Img tex = distinct4();
    pray_texture *t = texture_of(c, tex, 8);
    pray_model *m = flat_textured(c, t);
    Cam cam = top_view(16, 2);  // one pixel per texel
    pray_object *o = pray_planemap(c, m, V3(0, 0, 0), V3(0, 0, 1), V3(1, 0, 0), V3(0, 1, 0));
    Img base = render(c, cam, o);
    struct {
        double x, y;
        int di, dj;  // the shifted render at (i, j) is the plain one at (i + di, j + dj)
    } cases[] = {{0.25, 0, 1, 0}, {0, 0.5, 0, 2}, {-0.25, 0.75, -1, 3}, {1, 2, 0, 0}, {-3, 0, 0, 0}, {1.75, -1.25, 7, -5}};
    for (const auto &k : cases) {
        CAPTURE(k.x);
        CAPTURE(k.y);
        pray_model *mm = pray_move(c, m, k.x, k.y);
        REQUIRE(mm != nullptr);
        pray_object *om = pray_planemap(c, mm, V3(0, 0, 0), V3(0, 0, 1), V3(1, 0, 0), V3(0, 1, 0));
        Img img = render(c, cam, om);
        int bad = 0, checked = 0;
        for (int j = 0; j < 16; j++)
            for (int i = 0; i < 16; i++) {
                int bi = i + k.di, bj = j + k.dj;
                if (bi < 0 || bj < 0 || bi >= 16 || bj >= 16) continue;
                checked++;
                for (int ch = 0; ch < 3; ch++) bad += std::fabs(img.at(i, j, ch) - base.at(bi, bj, ch)) > 1e-3;
                // and it is the texel the shifted coordinates name
                for (int ch = 0; ch < 3; ch++)
                    bad += std::fabs(img.at(i, j, ch) - tex.at(((i + k.di) % 4 + 4) % 4, ((j + k.dj) % 4 + 4) % 4, ch)) > 1e-3;
            }
        CHECK(bad == 0);
        CHECK(checked >= 90);
        pray_release(c, om);
        pray_release(c, mm);
    }
    // a move of a move adds up
    pray_model *m1 = pray_move(c, m, 0.25, 0), *m2 = pray_move(c, m1, 0.5, 0.25);
    pray_object *om = pray_planemap(c, m2, V3(0, 0, 0), V3(0, 0, 1), V3(1, 0, 0), V3(0, 1, 0));
    Img img = render(c, cam, om);
    int bad = 0;
    for (int j = 0; j < 15; j++)
        for (int i = 0; i < 13; i++)
            for (int ch = 0; ch < 3; ch++) bad += std::fabs(img.at(i, j, ch) - base.at(i + 3, j + 1, ch)) > 1e-3;
    CHECK(bad == 0);
    // move of non-finite amounts is refused
    CHECK(pray_move(c, m, NAN, 0) == nullptr);
    CHECK(pray_last_status(c) == PRAY_ERR_ARG);
    pray_release(c, om);
    pray_release(c, m1);
    pray_release(c, m2);
    pray_release(c, o);
    pray_release(c, m);
    pray_release(c, t);
}

TEST_CASE("textures: coordinates out of the range of numbers are refused where they are made, and never index memory") {
    Ctx c;
    Img tex = distinct4();
    pray_texture *t = texture_of(c, tex, 8);
    pray_model *m = flat_textured(c, t);
    // shifts that are each fine but add up beyond the range of numbers
    pray_model *m1 = pray_move(c, m, 1e308, 0);
    REQUIRE(m1 != nullptr);
    CHECK(pray_move(c, m1, 1e308, 0) == nullptr);
    CHECK(std::string(pray_error(c)) == "error: move: the shifts of nested moves add up to more than the range of numbers");
    pray_model *sum = pray_model_add(c, m1, m1);  // a sum keeps the larger shift of its parts
    REQUIRE(sum != nullptr);
    CHECK(pray_move(c, sum, 0, -1e308) == nullptr);
    // a map whose vector's squared length would underflow
    CHECK(pray_planemap(c, m, V3(0, 0, 0), V3(0, 0, 1), V3(1e-170, 0, 0), V3(0, 1, 0)) == nullptr);
    CHECK(std::string(pray_error(c)).find("planemap: the vectors' lengths must lie between") != std::string::npos);
    // a shift of 1e308 is still a texture: s is 1e308 wherever the plane is met, a whole number
    // as 2^60 + x is, so each row shows one colour, that of a shift by 2^60
    Cam cam = top_view(16, 2);
    pray_model *m2 = pray_move(c, m, std::ldexp(1.0, 60), 0);
    pray_object *o = pray_planemap(c, m1, V3(0, 0, 0), V3(0, 0, 1), V3(1, 0, 0), V3(0, 1, 0));
    pray_object *o2 = pray_planemap(c, m2, V3(0, 0, 0), V3(0, 0, 1), V3(1, 0, 0), V3(0, 1, 0));
    Img img = render(c, cam, o), img2 = render(c, cam, o2);
    CHECK(img.px == img2.px);
    for (int j = 0; j < 16; j++)
        for (int i = 1; i < 16; i++)
            for (int ch = 0; ch < 3; ch++) CHECK(img.at(i, j, ch) == img.at(0, j, ch));
    pray_release(c, o);
    pray_release(c, o2);
    pray_release(c, m2);
    pray_release(c, sum);
    pray_release(c, m1);
    pray_release(c, m);
    pray_release(c, t);
}

TEST_CASE("models: shared parts cost what they are, or are refused; shading is bounded by the parts") {
    Ctx c;
    Img tex = distinct4();
    pray_texture *t = texture_of(c, tex, 8);
    // a model without texture stays one set of coefficients however it is combined: `M = M + M`
    // forty times, with a move that moves nothing
    pray_model *flat = pray_color(c, RGB(0.5, 0.5, 0.5));
    pray_model *m = pray_move(c, flat, 0, 0);
    for (int i = 0; i < 40; i++) {
        pray_model *d = pray_model_add(c, m, m);
        REQUIRE(d != nullptr);
        pray_release(c, m);
        m = d;
    }
    pray_object *o = pray_planemap(c, m, V3(0, 0, 0), V3(0, 0, 1), V3(1, 0, 0), V3(0, 1, 0));
    Img img = render(c, top_view(4, 2), o);
    CHECK(img.at(1, 1, 0) == (float)std::ldexp(0.5, 40));
    pray_release(c, o);
    pray_release(c, m);
    pray_release(c, flat);
    // a textured model doubled: 3 parts, then 7, 15, ... 4095 after ten doublings: it shades as
    // the model scaled by 1024; one more part is allowed, two are refused
    pray_model *T = flat_textured(c, t);
    m = T;
    for (int i = 0; i < 10; i++) {
        pray_model *d = pray_model_add(c, m, m);
        REQUIRE(d != nullptr);
        if (m != T) pray_release(c, m);
        m = d;
    }
    pray_model *s = pray_model_scale(c, T, RGB(1024, 1024, 1024));
    pray_object *a = pray_planemap(c, m, V3(0, 0, 0), V3(0, 0, 1), V3(1, 0, 0), V3(0, 1, 0));
    pray_object *b = pray_planemap(c, s, V3(0, 0, 0), V3(0, 0, 1), V3(1, 0, 0), V3(0, 1, 0));
    Img ia = render(c, top_view(16, 2), a), ib = render(c, top_view(16, 2), b);
    CHECK(ia.px == ib.px);
    CHECK(ia.at(0, 0, 0) == 1024 * tex.at(0, 0, 0));
    // scalings of a textured model multiply when it is shaded: their product must be a number
    pray_model *big = pray_model_scale(c, T, RGB(1e200, 1e200, 1e200));
    REQUIRE(big != nullptr);
    CHECK(pray_model_scale(c, big, RGB(1e200, 1, 1)) == nullptr);
    CHECK(std::string(pray_error(c)) == "error: model scale: the coefficients are not finite");
    pray_model *huge = pray_model_scale(c, big, RGB(1e108, 1, 1));
    REQUIRE(huge != nullptr);
    CHECK(pray_model_add(c, huge, huge) == nullptr);
    CHECK(std::string(pray_error(c)) == "error: model sum: the coefficients are not finite");
    pray_release(c, huge);
    pray_release(c, big);
    pray_model *b1 = pray_tiffbump(c, m, 0, t);
    REQUIRE(b1 != nullptr);
    CHECK(pray_tiffbump(c, b1, 0, t) == nullptr);
    CHECK(pray_last_status(c) == PRAY_ERR_LIMIT);
    CHECK(std::string(pray_error(c)) == "error: model made of more than 4096 parts (each use of a shared part counts)");
    pray_release(c, b1);
    pray_release(c, a);
    pray_release(c, b);
    pray_release(c, m);
    pray_release(c, s);
    pray_release(c, T);
    pray_release(c, t);
}

TEST_CASE("textures: a transformed planemap carries its texture along") {
    Ctx c;
    pray_texture *t = texture_of(c, ramp());
    pray_model *m = flat_textured(c, t);
    const pray_vec P = V3(0.1, -0.3, 0), N = V3(0, 0, 1), U = V3(0.8, 0, 0), Vv = V3(0, 0.6, 0);
    pray_object *o = pray_planemap(c, m, P, N, U, Vv);
    struct {
        double s;
        pray_vec rot, move;
    } cases[] = {
        {1, V3(0, 0, 0), V3(0.37, -0.21, 0.5)},   // translation
        {2.5, V3(0, 0, 0), V3(0, 0, 0)},          // scale about the origin
        {0.4, V3(0, 0, 0), V3(0, 0, 0)},          // shrink
        {1, V3(0, 0, 35), V3(0, 0, 0)},           // rotation about the normal
        {1.7, V3(20, -15, 30), V3(0.3, -0.6, 0.25)},  // all three, tilted
    };
    for (const auto &k : cases) {
        CAPTURE(k.s);
        CAPTURE(k.rot.z);
        pray_object *a = pray_scale(c, o, k.s);
        pray_object *b = pray_rotate(c, a, k.rot);
        pray_object *x = pray_translate(c, b, k.move);
        REQUIRE(x != nullptr);
        // the same map applied to P, N, U and V
        pray_vec P2 = add(rot_xyz(mul(P, k.s), k.rot), k.move), N2 = rot_xyz(N, k.rot);
        pray_vec U2 = rot_xyz(mul(U, k.s), k.rot), V2 = rot_xyz(mul(Vv, k.s), k.rot);
        Cam cam = top_view(48, 2, k.move.z);
        Img img = render(c, cam, x);
        check_planemap(img, cam, P2, N2, U2, V2, 600);
        pray_release(c, a);
        pray_release(c, b);
        pray_release(c, x);
    }
    pray_release(c, o);
    pray_release(c, m);
    pray_release(c, t);
}

// A scale by -1 is the point reflection x -> -x: the solid and its texture must come along, so a
// mirrored camera sees the same picture. (It once turned every half-space inside out, and a
// spheremap's longitudes ran the wrong way after a reflection.)
TEST_CASE("textures: a point reflection (scale -1) carries solids and textures along") {
    Ctx c;
    pray_texture *t = texture_of(c, ramp());
    pray_model *m = flat_textured(c, t);
    pray_object *pm = pray_planemap(c, m, V3(0.1, -0.3, 0), V3(0, 0, 1), V3(0.8, 0, 0), V3(0, 0.6, 0));
    pray_object *sm = pray_spheremap(c, m, V3(0.2, 0.1, 0.3), 1, V3(0, 0, 1), V3(1, 0, 0));
    for (pray_object *o : {pm, sm}) {
        pray_object *r = pray_scale(c, o, -1);
        REQUIRE(r != nullptr);
        Cam cam{V3(1.3, 0, 0), V3(0, 1.3, 0), V3(0.2, 0.1, 10), V3(0.2, 0.1, 0), 40, 40};
        Cam mir{mul(cam.X, -1), mul(cam.Y, -1), mul(cam.E, -1), mul(cam.P, -1), 40, 40};
        Img a = render(c, cam, o), b = render(c, mir, r);
        int bad = 0;
        for (size_t i = 0; i < a.px.size(); i++) bad += std::fabs(a.px[i] - b.px[i]) > TOL;
        CHECK(bad == 0);
        // the mirrored ray enters the mirrored solid where the ray entered the solid
        Probe p(c, o), q(c, r);
        std::vector<pray_hit> h = p.hits(V3(0.5, 0.5, 10), V3(0, 0, -1)), k = q.hits(V3(-0.5, -0.5, -10), V3(0, 0, 1));
        REQUIRE(h.size() == k.size());
        for (size_t i = 0; i < h.size(); i++) {
            CHECK(close_to(h[i].t, k[i].t));
            CHECK(h[i].entering == k[i].entering);
            CHECK(close_to(h[i].normal.z, -k[i].normal.z));
        }
        pray_release(c, r);
    }
    pray_release(c, pm);
    pray_release(c, sm);
    pray_release(c, m);
    pray_release(c, t);
}

TEST_CASE("textures: spheremap coordinates: U to the north pole, V to longitude 0, t from south to north") {
    Ctx c;
    pray_texture *t = texture_of(c, ramp());
    pray_model *m = flat_textured(c, t);
    const pray_vec C = V3(0.2, -0.1, 0.3);
    const double r = 1.1;
    // U = +Z to the north, V = +X to longitude 0: longitude 90 is +Y
    pray_object *o = pray_spheremap(c, m, C, r, V3(0, 0, 2), V3(3, 0, 0));
    // explicit points: the centre pixel of a 33 x 33 parallel view along -D sees the point C + r D
    struct {
        pray_vec D;
        double s, t;
    } pts[] = {
        {V3(0, 1, 0), 0.25, 0.5},                          // longitude 90, equator
        {V3(-1, 0, 0), 0.5, 0.5},                          // longitude 180
        {V3(0, -1, 0), 0.75, 0.5},                         // longitude 270
        {unit(V3(1, 1, 1.4142135623730951)), 0.125, 0.75}, // longitude 45, latitude 45 north
        {unit(V3(-1, 1, -1.4142135623730951)), 0.375, 0.25},  // longitude 135, latitude 45 south
    };
    for (const auto &p : pts) {
        CAPTURE(p.s);
        CAPTURE(p.t);
        pray_vec side = std::fabs(p.D.z) > 0.9 ? V3(1, 0, 0) : V3(0, 0, 1);
        pray_vec X = mul(unit(cross(side, p.D)), 1.5), Y = mul(unit(cross(X, p.D)), 1.5);
        pray_vec at = add(C, mul(p.D, r));
        Cam cam{X, Y, add(at, mul(p.D, 10)), at, 33, 33};
        Img img = render(c, cam, o);
        CHECK(std::fabs(img.at(16, 16, 0) - p.s) < TOL);
        CHECK(std::fabs(img.at(16, 16, 1) - p.t) < TOL);
        CHECK(std::fabs(img.at(16, 16, 2) - 0.25) < TOL);
    }
    // every pixel of views from six directions
    pray_vec dirs[] = {V3(0, -1, 0), V3(1, 0, 0), V3(0, 1, 0), V3(-1, 0, 0), V3(0.3, -0.4, 0.8), V3(-0.2, 0.5, -0.9)};
    for (pray_vec D : dirs) {
        D = unit(D);
        CAPTURE(D.x);
        CAPTURE(D.y);
        pray_vec side = std::fabs(D.z) > 0.9 ? V3(1, 0, 0) : V3(0, 0, 1);
        pray_vec X = mul(unit(cross(side, D)), 1.3), Y = mul(unit(cross(X, D)), 1.3);
        Cam cam{X, Y, add(C, mul(D, 10)), C, 48, 48};
        Img img = render(c, cam, o);
        check_spheremap(img, cam, C, r, V3(0, 0, 2), V3(3, 0, 0), 500);
    }
    pray_release(c, o);
    // other frames: V need not be perpendicular to U (its part along U is ignored), any lengths
    struct {
        pray_vec U, V;
    } frames[] = {{V3(1, 0, 0), V3(0, 0, 1)}, {V3(0, -3, 0), V3(1, 0, 1)}, {V3(1, 1, 1), V3(1, -1, 0.5)}};
    for (const auto &f : frames) {
        pray_object *q = pray_spheremap(c, m, C, r, f.U, f.V);
        for (pray_vec D : {V3(0, -1, 0), V3(0.6, 0.3, 0.5)}) {
            D = unit(D);
            pray_vec X = mul(unit(cross(V3(0, 0, 1), D)), 1.3), Y = mul(unit(cross(X, D)), 1.3);
            Cam cam{X, Y, add(C, mul(D, 10)), C, 40, 40};
            Img img = render(c, cam, q);
            check_spheremap(img, cam, C, r, f.U, f.V, 300);
        }
        pray_release(c, q);
    }
    pray_release(c, m);
    pray_release(c, t);
}

TEST_CASE("textures: a transformed spheremap carries its texture along") {
    Ctx c;
    pray_texture *t = texture_of(c, ramp());
    pray_model *m = flat_textured(c, t);
    const pray_vec C = V3(0, 0, 0), U = V3(0, 0, 1), Vv = V3(1, 0, 0);
    pray_object *o = pray_spheremap(c, m, C, 1, U, Vv);
    pray_object *a = pray_scale(c, o, 0.7);
    pray_object *b = pray_rotate(c, a, V3(30, 0, 90));
    pray_object *x = pray_translate(c, b, V3(0.5, 0.25, -0.5));
    REQUIRE(x != nullptr);
    pray_vec C2 = V3(0.5, 0.25, -0.5), U2 = rot_xyz(U, V3(30, 0, 90)), V2 = rot_xyz(Vv, V3(30, 0, 90));
    for (pray_vec D : {V3(0, -1, 0), V3(1, 0, 0), V3(0.2, 0.3, 0.9)}) {
        D = unit(D);
        pray_vec X = mul(unit(cross(std::fabs(D.z) > 0.9 ? V3(1, 0, 0) : V3(0, 0, 1), D)), 0.9);
        pray_vec Y = mul(unit(cross(X, D)), 0.9);
        Cam cam{X, Y, add(C2, mul(D, 10)), C2, 40, 40};
        Img img = render(c, cam, x);
        check_spheremap(img, cam, C2, 0.7, U2, V2, 300);
    }
    pray_release(c, a);
    pray_release(c, b);
    pray_release(c, x);
    pray_release(c, o);
    pray_release(c, m);
    pray_release(c, t);
}

TEST_CASE("textures: planemap, spheremap, tiff and move in a PRAY program render as through the API") {
    Ctx c;
    TempDir d;
    std::string path = d / "ramp.tif";
    Img rm = ramp();
    pray_image v = rm.view();
    REQUIRE(pray_write_image(c, &v, path.c_str(), 16) == PRAY_OK);
    pray_texture *t = pray_texture_file(c, path.c_str());
    REQUIRE(t != nullptr);
    pray_model *flat = flat_textured(c, t);
    pray_model *moved = pray_move(c, flat, 0.3, -0.2);
    pray_object *o = pray_csg(c, PRAY_UNION,
                              pray_planemap(c, moved, V3(0.1, 0, -1), V3(0, 0, 1), V3(1.5, 0, 0), V3(0, 0.75, 0)),
                              pray_spheremap(c, flat, V3(0, 0, 0), 0.8, V3(0, 1, 1), V3(1, 0, 0)));
    Cam cam = top_view(40, 1.5);
    Img api = render(c, cam, o);
    std::string prog =
        "option \"width\", 40\noption \"height\", 40\n"
        "parallel <1.5, 0, 0>, <0, 1.5, 0>, [0, 0, 10], [0, 0, 0]\n"
        "F = tiff(color({0}), color({1}), \"" + path + "\")\n"
        "O = planemap(move(F, 0.3, -0.2), [0.1, 0, -1], <0, 0, 1>, <1.5, 0, 0>, <0, 0.75, 0>)\n"
        "S = spheremap(F, [0, 0, 0], 0.8, <0, 1, 1>, <1, 0, 0>)\n"
        "rendertiff O | S, none\n";
    testkit::Result r = testkit::run(prog);
    REQUIRE_MESSAGE(r.status == PRAY_OK, r.error);
    REQUIRE(r.frames.size() == 1);
    CHECK(r.frames[0].pixels == api.px);
    pray_release(c, o);
    pray_release(c, moved);
    pray_release(c, flat);
    pray_release(c, t);
}

// =============================================================================================
// Bump maps
// =============================================================================================
TEST_CASE("textures: a bump map changes the shading, not the silhouette") {
    Ctx c;
    // luminance waves along s and t
    Img bump(64, 32);
    for (int y = 0; y < 32; y++)
        for (int x = 0; x < 64; x++) {
            double g = 0.5 + 0.25 * std::sin(2 * 3.14159265358979 * 8 * x / 64) + 0.25 * std::cos(2 * 3.14159265358979 * 4 * y / 32);
            bump.set(x, y, g, g, g);
        }
    pray_texture *t = texture_of(c, bump);
    pray_model *ph = pray_phong(c, RGB(0.7, 0.7, 0.7), RGB(0.3, 0.3, 0.3), RGB(0.05, 0.05, 0.05), 8);
    pray_model *bm = pray_tiffbump(c, ph, 0.02, t);
    REQUIRE(bm != nullptr);
    pray_light *l = pray_dirlight(c, RGB(1, 1, 1), V3(-1, 2, -1));
    const pray_rgb bg = RGB(0.1, 0.5, 0.9);  // not grey: every pixel of the grey sphere differs from it
    const pray_vec C = V3(0, 0, 0), U = V3(0, 0, 1), Vv = V3(1, 0, 0);
    pray_object *plain = pray_spheremap(c, ph, C, 1, U, Vv);
    pray_object *bumped = pray_spheremap(c, bm, C, 1, U, Vv);
    pray_object *sphere = pray_sphere(c, ph, C, 1);
    for (pray_vec D : {V3(0, -1, 0), V3(0.5, -0.5, 0.7)}) {
        D = unit(D);
        pray_vec X = mul(unit(cross(V3(0, 0, 1), D)), 1.25), Y = mul(unit(cross(X, D)), 1.25);
        Cam cam{X, Y, mul(D, 10), C, 64, 64};
        Img a = render(c, cam, plain, l, bg), b = render(c, cam, bumped, l, bg), s = render(c, cam, sphere, l, bg);
        int hit_a = 0, differ_hit = 0, shading = 0, geometry = 0, same_as_plain = 0;
        for (int j = 0; j < 64; j++)
            for (int i = 0; i < 64; i++) {
                auto is_bg = [&](const Img &m) {
                    return m.at(i, j, 0) == (float)bg.r && m.at(i, j, 1) == (float)bg.g && m.at(i, j, 2) == (float)bg.b;
                };
                hit_a += !is_bg(a);
                differ_hit += is_bg(a) != is_bg(b);
                geometry += is_bg(a) != is_bg(s);
                if (!is_bg(a) && std::fabs(a.at(i, j, 0) - b.at(i, j, 0)) > 0.02) shading++;
                // the mapped sphere without a bump is the plain sphere
                for (int ch = 0; ch < 3; ch++) same_as_plain += a.at(i, j, ch) == s.at(i, j, ch);
            }
        CHECK(hit_a > 64 * 64 / 2);
        CHECK(differ_hit == 0);
        CHECK(geometry == 0);
        CHECK(same_as_plain == 64 * 64 * 3);
        CHECK(shading > hit_a / 4);

    }
    // a bump map of a flat texture changes nothing
    Img flat(8, 8);
    for (float &f : flat.px) f = 0.5f;
    pray_texture *ft = texture_of(c, flat);
    pray_model *fm = pray_tiffbump(c, ph, 5, ft);
    pray_object *fo = pray_spheremap(c, fm, C, 1, U, Vv);
    Cam cam{V3(1.25, 0, 0), V3(0, 0, -1.25), V3(0, -10, 0), C, 32, 32};
    CHECK(render(c, cam, fo, l, bg).px == render(c, cam, plain, l, bg).px);
    CHECK(pray_tiffbump(c, ph, INFINITY, t) == nullptr);
    pray_release(c, fo);
    pray_release(c, fm);
    pray_release(c, ft);
    pray_release(c, plain);
    pray_release(c, bumped);
    pray_release(c, sphere);
    pray_release(c, l);
    pray_release(c, bm);
    pray_release(c, ph);
    pray_release(c, t);
}

// =============================================================================================
// Text
// =============================================================================================
namespace {

// Glyphs of tools/font6x9.txt, rows from the top: rows 0-6 stand on the baseline, 7-8 hang below.
const char *GLYPH_I[9] = {".XXX.", "..X..", "..X..", "..X..", "..X..", "..X..", ".XXX.", ".....", "....."};
const char *GLYPH_L[9] = {"X....", "X....", "X....", "X....", "X....", "X....", "XXXXX", ".....", "....."};
const char *GLYPH_g[9] = {".....", ".....", ".XXXX", "X...X", "X...X", "X...X", ".XXXX", "....X", ".XXX."};


// Text in the plane z = 0 from the origin: one font pixel per unit (X = <cw, 0, 0> for a cell of cw
// columns, Y = <0, rows, 0>), extruded to z = 1. Checks every pixel of each glyph cell with rays
// straight down: ink is met at z = 1 (t = 9) and left at z = 0 (t = 10), empty pixels not at all.
void check_glyphs(const Probe &sc, const std::vector<const char *const *> &glyphs, double advance, int cols, int rows,
                  int ref) {
    int bad = 0, ink = 0;
    std::string first;
    for (size_t k = 0; k < glyphs.size(); k++)
        for (int r = 0; r < rows; r++)
            for (int col = 0; col < cols + 1; col++) {
                bool want = col < cols && glyphs[k][r][col] == 'X';
                double x = k * advance + col + 0.5, y = ref - 1 - r + 0.5;
                std::vector<pray_hit> h = sc.hits(V3(x, y, 10), V3(0, 0, -1));
                bool good = want ? h.size() == 2 && close_to(h[0].t, 9) && h[0].entering == 1 && close_to(h[0].normal.z, 1) &&
                                       close_to(h[1].t, 10) && h[1].entering == 0 && close_to(h[1].normal.z, -1)
                                 : h.empty();
                ink += want;
                if (!good && bad++ == 0)
                    first = "glyph " + std::to_string(k) + " row " + std::to_string(r) + " column " + std::to_string(col) +
                            (want ? " should be ink" : " should be empty") + ", hits " + std::to_string(h.size());
            }
    CHECK_MESSAGE(bad == 0, first);
    CHECK(ink > 0);
}

} // namespace

TEST_CASE("text: glyph solids of the built-in font") {
    Ctx c;
    pray_model *m = pray_color(c, RGB(1, 1, 1));
    // "IL": cells of 6 columns; the glyph height Y covers rows 0-6 (7 units)
    pray_object *txt = pray_text(c, m, "IL", V3(0, 0, 0), V3(6, 0, 0), V3(0, 7, 0), 1, nullptr, 1);
    REQUIRE_MESSAGE(txt != nullptr, pray_error(c));
    CHECK(pray_object_primitives(txt) > 0);
    {
        Probe sc(c, txt);
        check_glyphs(sc, {GLYPH_I, GLYPH_L}, 6, 5, 9, 7);
        // inside: from a point in the ink the first surface is left; from an empty pixel nothing
        std::vector<pray_hit> h = sc.hits(V3(2.5, 3.5, 0.5), V3(0, 0, 1));
        REQUIRE(h.size() == 1);
        CHECK(h[0].entering == 0);
        CHECK(close_to(h[0].t, 0.5));
        h = sc.hits(V3(2.5, 3.5, 0.5), unit(V3(0.05, 0.02, 1)));
        REQUIRE(h.size() >= 1);
        CHECK(h[0].entering == 0);
        CHECK(sc.hits(V3(1.5, 3.5, 0.5), V3(0, 0, 1)).empty());
        CHECK(sc.hits(V3(1.5, 3.5, 0.5), V3(0, 0, -1)).empty());
        // along row 6 of "IL" (y = 0.5), through the glyphs' boxes side by side: the faces they
        // share are no surfaces of the union
        h = sc.hits(V3(-5, 0.5, 0.5), V3(1, 0, 0));
        REQUIRE(h.size() == 4);
        CHECK((close_to(h[0].t, 6) && h[0].entering == 1 && close_to(h[0].normal.x, -1)));
        CHECK((close_to(h[1].t, 9) && h[1].entering == 0 && close_to(h[1].normal.x, 1)));
        CHECK((close_to(h[2].t, 11) && h[2].entering == 1));
        CHECK((close_to(h[3].t, 16) && h[3].entering == 0));
        // up column 2 of the I (x = 2.5): rows 0-6, y in [0, 7]
        h = sc.hits(V3(2.5, -5, 0.5), V3(0, 1, 0));
        REQUIRE(h.size() == 2);
        CHECK((close_to(h[0].t, 5) && close_to(h[1].t, 12)));
        // along the top row of the I (y = 6.5), x in [1, 4]; the L's column 0 at x in [6, 7]
        h = sc.hits(V3(-5, 6.5, 0.5), V3(1, 0, 0));
        REQUIRE(h.size() == 4);
        CHECK((close_to(h[0].t, 6) && close_to(h[1].t, 9) && close_to(h[2].t, 11) && close_to(h[3].t, 12)));
    }
    // spacing 2: the L starts 12 units along
    pray_object *wide = pray_text(c, m, "IL", V3(0, 0, 0), V3(6, 0, 0), V3(0, 7, 0), 1, nullptr, 2);
    {
        Probe sc(c, wide);
        CHECK(sc.hits(V3(6.5, 3.5, 10), V3(0, 0, -1)).empty());
        CHECK(sc.hits(V3(12.5, 3.5, 10), V3(0, 0, -1)).size() == 2);
    }
    // descenders hang below the baseline; spaces take an advance but no ink
    pray_object *g = pray_text(c, m, " g", V3(0, 0, 0), V3(6, 0, 0), V3(0, 7, 0), 1, nullptr, 1);
    {
        Probe sc(c, g);
        int bad = 0;
        for (int r = 0; r < 9; r++)
            for (int col = 0; col < 5; col++) {
                bool want = GLYPH_g[r][col] == 'X';
                std::vector<pray_hit> h = sc.hits(V3(6 + col + 0.5, 6 - r + 0.5, 10), V3(0, 0, -1));
                bad += want ? !(h.size() == 2 && close_to(h[0].t, 9)) : !h.empty();
            }
        CHECK(bad == 0);
        for (int col = 0; col < 6; col++)
            for (int r = 0; r < 9; r++) CHECK(sc.hits(V3(col + 0.5, 6 - r + 0.5, 10), V3(0, 0, -1)).empty());
    }
    // any placement: the glyph plane spanned by X and Y, extruded along norm(X % Y)
    pray_object *tilted = pray_text(c, m, "L", V3(1, 2, 3), V3(0, 3, 0), V3(0, 0, 3.5), 0.25, nullptr, 1);
    {
        // X = +Y*3 (a pixel is 0.5), Y = +Z*3.5 (a row is 0.5), thickness along +X
        Probe sc(c, tilted);
        std::vector<pray_hit> h = sc.hits(V3(10, 2 + 0.25, 3 + 0.25), V3(-1, 0, 0));  // row 6, column 0
        REQUIRE(h.size() == 2);
        CHECK(close_to(h[0].t, 10 - 1.25));
        CHECK(close_to(h[0].normal.x, 1));
        CHECK(close_to(h[1].t, 9));
        CHECK(sc.hits(V3(10, 2 + 0.75, 3 + 1.25), V3(-1, 0, 0)).empty());  // row 4, column 1
    }
    // bad arguments
    CHECK(pray_text(c, m, "x", V3(0, 0, 0), V3(1, 0, 0), V3(2, 0, 0), 1, nullptr, 1) == nullptr);
    CHECK(pray_text(c, m, "x", V3(0, 0, 0), V3(1, 0, 0), V3(0, 1, 0), 0, nullptr, 1) == nullptr);
    CHECK(pray_text(c, m, "x", V3(0, 0, 0), V3(1, 0, 0), V3(0, 1, 0), 1, nullptr, 0) == nullptr);
    CHECK(pray_last_status(c) == PRAY_ERR_ARG);
    // the empty string is the empty solid
    pray_object *none = pray_text(c, m, "", V3(0, 0, 0), V3(1, 0, 0), V3(0, 1, 0), 1, nullptr, 1);
    REQUIRE(none != nullptr);
    CHECK(pray_object_primitives(none) == 0);
    pray_release(c, none);
    pray_release(c, tilted);
    pray_release(c, g);
    pray_release(c, wide);
    pray_release(c, txt);
    pray_release(c, m);
}

TEST_CASE("text: engraved text, text in unions, intersections and complements") {
    Ctx c;
    pray_model *m = pray_color(c, RGB(1, 1, 1));
    pray_object *txt = pray_text(c, m, "IL", V3(0, 0, 0), V3(6, 0, 0), V3(0, 7, 0), 1, nullptr, 1);
    // a slab z in [-2, 0.5] minus the text (z in [0, 1]): grooves 0.5 deep
    pray_object *slab = pray_csg(c, PRAY_INTERSECTION, pray_plane(c, m, V3(0, 0, 0.5), V3(0, 0, 1)),
                                 pray_plane(c, m, V3(0, 0, -2), V3(0, 0, -1)));
    pray_object *engraved = pray_csg(c, PRAY_DIFFERENCE, slab, txt);
    REQUIRE(engraved != nullptr);
    {
        Probe sc(c, engraved);
        int bad = 0;
        const char *const *glyphs[2] = {GLYPH_I, GLYPH_L};
        for (int k = 0; k < 2; k++)
            for (int r = 0; r < 9; r++)
                for (int col = 0; col < 6; col++) {
                    bool ink = col < 5 && glyphs[k][r][col] == 'X';
                    std::vector<pray_hit> h = sc.hits(V3(6 * k + col + 0.5, 6 - r + 0.5, 10), V3(0, 0, -1));
                    // the first surface: the bottom of the groove (z = 0) or the face (z = 0.5)
                    bool good = !h.empty() && close_to(h[0].t, ink ? 10 : 9.5) && h[0].entering == 1 && close_to(h[0].normal.z, 1);
                    bad += !good;
                }
        CHECK(bad == 0);
        // into a groove sideways: from inside the groove of the I's stem, the walls at x = 2 and 3
        std::vector<pray_hit> h = sc.hits(V3(2.5, 3.5, 0.25), V3(1, 0, 0));
        REQUIRE(!h.empty());
        CHECK(close_to(h[0].t, 0.5));
        CHECK(h[0].entering == 1);
        CHECK(close_to(h[0].normal.x, -1));
    }
    // rendered: the grooves show as the text
    {
        pray_model *top = pray_color(c, RGB(1, 1, 1)), *bottom = pray_color(c, RGB(0, 0, 1));
        pray_object *t2 = pray_text(c, bottom, "IL", V3(0, 0, 0), V3(6, 0, 0), V3(0, 7, 0), 1, nullptr, 1);
        pray_object *s2 = pray_csg(c, PRAY_INTERSECTION, pray_plane(c, top, V3(0, 0, 0.5), V3(0, 0, 1)),
                                   pray_plane(c, top, V3(0, 0, -2), V3(0, 0, -1)));
        pray_object *e2 = pray_csg(c, PRAY_DIFFERENCE, s2, t2);
        // 12 x 9 pixels, one per font pixel: x in [0, 12], y in [-2, 7]
        Cam cam{V3(6, 0, 0), V3(0, -4.5, 0), V3(6, 2.5, 10), V3(6, 2.5, 0), 12, 9};
        Img img = render(c, cam, e2);
        int bad = 0;
        const char *const *glyphs[2] = {GLYPH_I, GLYPH_L};
        for (int j = 0; j < 9; j++)
            for (int i = 0; i < 12; i++) {
                int k = i / 6, col = i % 6;
                bool ink = col < 5 && glyphs[k][j][col] == 'X';  // image row j is font row j (y = 6.5 - j)
                bad += img.at(i, j, 0) != (ink ? 0.0f : 1.0f) || img.at(i, j, 2) != 1.0f;
            }
        CHECK(bad == 0);
        pray_release(c, t2);
        pray_release(c, s2);
        pray_release(c, e2);
        pray_release(c, top);
        pray_release(c, bottom);
    }
    // union with a ball, intersection with half-spaces
    pray_object *ball = pray_sphere(c, m, V3(20, 3.5, 0.5), 1);
    pray_object *uni = pray_csg(c, PRAY_UNION, txt, ball);
    {
        Probe sc(c, uni);
        check_glyphs(sc, {GLYPH_I, GLYPH_L}, 6, 5, 9, 7);
        std::vector<pray_hit> h = sc.hits(V3(20, 3.5, 10), V3(0, 0, -1));
        REQUIRE(h.size() == 2);
        CHECK(close_to(h[0].t, 8.5));
        h = sc.hits(V3(-5, 0.5, 0.5), V3(1, 0, 0));  // row 6 of I and L, then past the ball's bottom? no: y 0.5
        CHECK(h.size() == 4);
        h = sc.hits(V3(-5, 3.5, 0.5), V3(1, 0, 0));  // the I's stem, the L's stem, the ball
        REQUIRE(h.size() == 6);
        CHECK((close_to(h[0].t, 7) && close_to(h[1].t, 8) && close_to(h[2].t, 11) && close_to(h[3].t, 12) && close_to(h[4].t, 24) &&
               close_to(h[5].t, 26)));
    }
    pray_object *cut = pray_csg(c, PRAY_INTERSECTION, txt, pray_plane(c, m, V3(0, 0, 0.5), V3(0, 0, 1)));
    pray_object *half = pray_csg(c, PRAY_INTERSECTION, txt, pray_plane(c, m, V3(2.25, 0, 0), V3(1, 0, 0)));
    {
        Probe sc(c, cut);
        std::vector<pray_hit> h = sc.hits(V3(2.5, 3.5, 10), V3(0, 0, -1));
        REQUIRE(h.size() == 2);
        CHECK(close_to(h[0].t, 9.5));
        CHECK(close_to(h[1].t, 10));
        CHECK(sc.hits(V3(1.5, 3.5, 10), V3(0, 0, -1)).empty());
        Probe sh(c, half);
        CHECK(sh.hits(V3(1.5, 6.5, 10), V3(0, 0, -1)).size() == 2);  // I's top row, column 1
        CHECK(sh.hits(V3(2.5, 6.5, 10), V3(0, 0, -1)).empty());      // column 2: cut away
        CHECK(sh.hits(V3(6.5, 3.5, 10), V3(0, 0, -1)).empty());      // the L: cut away
        h = sh.hits(V3(-5, 6.5, 0.5), V3(1, 0, 0));
        REQUIRE(h.size() == 2);
        CHECK((close_to(h[0].t, 6) && close_to(h[1].t, 7.25)));
    }
    // the complement of text: everything but the glyphs
    pray_object *neg = pray_complement(c, txt);
    {
        Probe sc(c, neg);
        std::vector<pray_hit> h = sc.hits(V3(2.5, 3.5, 10), V3(0, 0, -1));
        REQUIRE(h.size() == 2);
        CHECK((h[0].entering == 0 && close_to(h[0].t, 9) && h[1].entering == 1 && close_to(h[1].t, 10)));
    }
    for (pray_object *o : {neg, cut, half, uni, ball, engraved, slab, txt}) pray_release(c, o);
    pray_release(c, m);
}

TEST_CASE("text: a font from a 16 x 16 TIFF atlas") {
    Ctx c;
    pray_model *m = pray_color(c, RGB(1, 1, 1));
    // an atlas of 8 x 8 cells, written by pray: white, a black 4 x 4 square in 'A', a grey (0.6,
    // light) pixel in 'B' that is not ink, and a full cell for ' ' (the atlas' space has ink)
    Img at(128, 128);
    for (float &f : at.px) f = 1;
    for (int y = 2; y < 6; y++)
        for (int x = 2; x < 6; x++) at.set((65 % 16) * 8 + x, (65 / 16) * 8 + y, 0, 0, 0);
    at.set((66 % 16) * 8 + 3, (66 / 16) * 8 + 3, 0.6, 0.6, 0.6);
    for (int y = 0; y < 8; y++)
        for (int x = 0; x < 8; x++) at.set((32 % 16) * 8 + x, (32 / 16) * 8 + y, 0.1, 0.1, 0.1);
    pray_texture *font = texture_of(c, at, 8);
    pray_object *a = pray_text(c, m, "A", V3(0, 0, 0), V3(8, 0, 0), V3(0, 8, 0), 1, font, 1);
    REQUIRE_MESSAGE(a != nullptr, pray_error(c));
    {
        Probe sc(c, a);
        int bad = 0;
        for (int y = 0; y < 8; y++)
            for (int x = 0; x < 9; x++) {
                // cell rows from the top: row r covers y in [7 - r, 8 - r]; the square is rows and
                // columns 2-5, i.e. x and y in [2, 6]
                bool want = x >= 2 && x < 6 && y >= 2 && y < 6;
                std::vector<pray_hit> h = sc.hits(V3(x + 0.5, y + 0.5, 10), V3(0, 0, -1));
                bad += want ? !(h.size() == 2 && close_to(h[0].t, 9) && close_to(h[1].t, 10)) : !h.empty();
            }
        CHECK(bad == 0);
        std::vector<pray_hit> h = sc.hits(V3(-5, 4, 0.5), V3(1, 0, 0));
        REQUIRE(h.size() == 2);
        CHECK((close_to(h[0].t, 7) && close_to(h[1].t, 11)));
    }
    pray_object *b = pray_text(c, m, "B", V3(0, 0, 0), V3(8, 0, 0), V3(0, 8, 0), 1, font, 1);
    REQUIRE(b != nullptr);
    CHECK(pray_object_primitives(b) == 0);
    pray_object *sp = pray_text(c, m, " A", V3(0, 0, 0), V3(8, 0, 0), V3(0, 8, 0), 1, font, 1);
    {
        Probe sc(c, sp);
        CHECK(sc.hits(V3(0.5, 0.5, 10), V3(0, 0, -1)).size() == 2);  // the atlas' space is a block
        CHECK(sc.hits(V3(8 + 2.5, 2.5, 10), V3(0, 0, -1)).size() == 2);
        CHECK(sc.hits(V3(8 + 1.5, 2.5, 10), V3(0, 0, -1)).empty());
    }
    // rendered: a square block
    Cam cam{V3(4, 0, 0), V3(0, -4, 0), V3(4, 4, 10), V3(4, 4, 0), 8, 8};
    Img img = render(c, cam, a);
    int bad = 0;
    for (int j = 0; j < 8; j++)
        for (int i = 0; i < 8; i++) {
            bool want = i >= 2 && i < 6 && j >= 2 && j < 6;
            bad += img.at(i, j, 1) != (want ? 1.0f : 0.0f);
        }
    CHECK(bad == 0);
    // an atlas smaller than 16 x 16 cells is refused
    Img tiny(8, 8);
    pray_texture *tt = texture_of(c, tiny, 8);
    CHECK(pray_text(c, m, "A", V3(0, 0, 0), V3(8, 0, 0), V3(0, 8, 0), 1, tt, 1) == nullptr);
    CHECK(pray_last_status(c) == PRAY_ERR_ARG);
    pray_release(c, tt);
    pray_release(c, sp);
    pray_release(c, b);
    pray_release(c, a);
    pray_release(c, font);
    pray_release(c, m);
}

TEST_CASE("text: a PIL-made atlas through a PRAY program renders 'A' as a square block") {
    CORPUS_OR_SKIP(k);
    std::string prog = "option \"width\", 8\noption \"height\", 8\n"
                       "parallel <4, 0, 0>, <0, -4, 0>, [4, 4, 10], [4, 4, 0]\n"
                       "T = text(color({1}), \"A\", [0, 0, 0], <8, 0, 0>, <0, 8, 0>, 1, \"" +
                       k.path("atlas.tif") + "\", 1)\n"
                       "rendertiff T, none\n";
    testkit::Result r = testkit::run(prog);
    REQUIRE_MESSAGE(r.status == PRAY_OK, r.error);
    REQUIRE(r.frames.size() == 1);
    int bad = 0;
    for (int j = 0; j < 8; j++)
        for (int i = 0; i < 8; i++) {
            bool want = i >= 2 && i < 6 && j >= 2 && j < 6;
            bad += r.frames[0].at(i, j, 0) != (want ? 1.0f : 0.0f);
        }
    CHECK(bad == 0);
}

TEST_CASE("text: hits and images with the grid equal the brute-force reference") {
    Ctx c;
    pray_model *m = pray_phong(c, RGB(0.6, 0.6, 0.6), RGB(0.3, 0.3, 0.3), RGB(0.1, 0.1, 0.1), 10);
    pray_object *txt = pray_text(c, m, "Hello, pray! 0123 gjq", V3(-10, 0, -1), V3(1, 0, 0), V3(0, 0, 1.2), 0.4, nullptr, 1.1);
    pray_object *txt2 = pray_text(c, m, "#@%&", V3(-3, -1, 1), V3(0.8, 0.3, 0), V3(0, 0.2, 1), 0.6, nullptr, 1);
    pray_object *all = pray_csg(c, PRAY_UNION, txt, txt2);
    REQUIRE(all != nullptr);
    REQUIRE(pray_option(c, "brute", 0) == PRAY_OK);
    pray_scene *fast = pray_prepare(c, all);
    REQUIRE(pray_option(c, "brute", 1) == PRAY_OK);
    pray_scene *ref = pray_prepare(c, all);
    REQUIRE(pray_option(c, "brute", 0) == PRAY_OK);
    REQUIRE(fast != nullptr);
    REQUIRE(ref != nullptr);
    std::mt19937 rng(99);
    auto u = [&](double a, double b) { return a + (b - a) * (rng() / 4294967296.0); };
    int rays = 0, with_hits = 0, bad = 0;
    std::string first;
    auto probe = [&](pray_vec o, pray_vec d, double tmax) {
        pray_hit a[128], b[128];
        int na = pray_intersect(c, fast, o, d, tmax, a, 128), nb = pray_intersect(c, ref, o, d, tmax, b, 128);
        rays++;
        with_hits += nb > 0;
        bool same = na == nb;
        for (int i = 0; same && i < std::min(na, 128); i++)
            same = a[i].t == b[i].t && a[i].primitive == b[i].primitive && a[i].entering == b[i].entering &&
                   a[i].normal.x == b[i].normal.x && a[i].normal.y == b[i].normal.y && a[i].normal.z == b[i].normal.z;
        if (!same && bad++ == 0) {
            char s[300];
            std::snprintf(s, sizeof s, "ray (%.17g, %.17g, %.17g) + t (%.17g, %.17g, %.17g): %d hits with the grid, %d brute",
                          o.x, o.y, o.z, d.x, d.y, d.z, na, nb);
            first = s;
        }
    };
    for (int i = 0; i < 300; i++) {  // random rays through the text's box
        pray_vec o = V3(u(-15, 15), u(-8, 8), u(-6, 6));
        pray_vec target = V3(u(-10, 14), u(-1.5, 1.5), u(-2, 2));
        probe(o, unit(sub(target, o)), i % 5 == 0 ? u(1, 20) : HUGE_VAL);
    }
    // axis-aligned rays through the first text's font pixels: centres, and edges where the glyph
    // boxes' faces meet; across the text (along its normal, -y) and along its rows (x)
    for (int i = 0; i < 200; i++) {
        int k = i % 21, col = (i / 21) % 6, row = i % 9;
        double x = -10 + 1.1 * k + (col + (i % 2 ? 0.5 : 0.0)) / 6, z = -1 + (6 - row + 0.5) * 1.2 / 7;
        probe(V3(x, -5, z), V3(0, 1, 0), HUGE_VAL);
        probe(V3(-20, i % 3 == 0 ? 0.0 : -0.2, z), V3(1, 0, 0), HUGE_VAL);
    }
    CHECK_MESSAGE(bad == 0, bad << " of " << rays << " rays differ; first: " << first);
    CHECK(with_hits > 50);
    pray_scene_free(c, fast);
    pray_scene_free(c, ref);
    // and the images, float for float
    pray_light *l = pray_dirlight(c, RGB(1, 1, 1), V3(1, 2, -1));
    Cam cam{V3(13, 0, 0), V3(0, 0, -4), V3(2, -20, 0), V3(2, 0, 0), 104, 32};
    Img g = render(c, cam, all, l, RGB(0.2, 0.2, 0.3));
    REQUIRE(pray_option(c, "brute", 1) == PRAY_OK);
    Img br = render(c, cam, all, l, RGB(0.2, 0.2, 0.3));
    CHECK(g.px == br.px);
    pray_release(c, l);
    pray_release(c, all);
    pray_release(c, txt);
    pray_release(c, txt2);
    pray_release(c, m);
}

// =============================================================================================
// Texture files in PRAY programs
// =============================================================================================
TEST_CASE("textures: a missing texture file stops the program on its line, naming the file") {
    const std::string head = "M = color({1})\noption \"width\", 4\noption \"height\", 4\n";
    struct {
        std::string stmt;
    } cases[] = {
        {"T = tiff(M, M, \"no-such-texture.tif\")\n"},
        {"T = tiffbump(M, 0.5, \"no-such-texture.tif\")\n"},
        {"T = text(M, \"Hi\", [0,0,0], <1,0,0>, <0,0,1>, 0.1, \"no-such-texture.tif\", 1)\n"},
    };
    for (const auto &k : cases) {
        CAPTURE(k.stmt);
        testkit::Result r = testkit::run(head + "print 1\n" + k.stmt + "print 2\nrendertiff sphere(M, [0,0,0], 1), none\n");
        CHECK(r.status != PRAY_OK);
        CHECK(contains(r.error, "test.ray:5:"));
        CHECK(contains(r.error, "no-such-texture.tif"));
        CHECK(r.printed == "1\n");
        CHECK(r.frames.empty());
    }
    // a file that is not a TIFF: the same, naming the file
    TempDir d;
    spit(d / "junk.tif", "GIF89a not a tiff");
    testkit::Result r = testkit::run(head + "T = tiff(M, M, \"" + (d / "junk.tif") + "\")\nrendertiff sphere(T, [0,0,0], 1), none\n");
    CHECK(r.status != PRAY_OK);
    CHECK(contains(r.error, "test.ray:4:"));
    CHECK(contains(r.error, "junk.tif"));
    CHECK(r.frames.empty());
}

// (skipped, not passed, when the program is not built: make builds it before make check)
TEST_CASE("textures: on the command line a missing texture exits with 1 and writes no image" *
          doctest::skip(!fs::exists(testkit::pray_program()))) {
    TempDir d;
    spit(d / "tex.ray", "M = color({1})\noption \"width\", 4\noption \"height\", 4\n"
                        "T = tiff(M, M, \"missing-wood.tif\")\nrendertiff sphere(T, [0,0,0], 1), none\n");
    std::string out;
    int rc = run_cmd(testkit::pray_shell() + " --quiet -o " + sq(d / "x.tif") + " " + sq(d / "tex.ray"), &out);
    CHECK(rc == 1);
    CHECK(contains(out, "tex.ray:4:"));
    CHECK(contains(out, "missing-wood.tif"));
    CHECK(d.listing() == "tex.ray");
    // a texture beside the program is found by its relative name, and then the image is written
    Img w(2, 2);
    for (float &f : w.px) f = 1;
    {
        Ctx c;
        pray_image v = w.view();
        REQUIRE(pray_write_image(c, &v, (d / "missing-wood.tif").c_str(), 8) == PRAY_OK);
    }
    rc = run_cmd(testkit::pray_shell() + " --quiet -o " + sq(d / "x.tif") + " " + sq(d / "tex.ray"), &out);
    CHECK_MESSAGE(rc == 0, out);
    CHECK(d.listing() == "missing-wood.tif tex.ray x.tif");
}

namespace {

// A grey 64 x 64 texture: texel (x, y) is v(x, y) in every channel.
template <class F>
std::vector<float> grey_texels(F v) {
    std::vector<float> px(64 * 64 * 3);
    for (int y = 0; y < 64; y++)
        for (int x = 0; x < 64; x++)
            for (int k = 0; k < 3; k++) px[(y * 64 + x) * 3 + k] = v(x, y);
    return px;
}

// A 64 x 64 texture of RGB pixels px written as `name` in d; its path in quotes, for a program.
std::string texture_file(const TempDir &d, const char *name, std::vector<float> &px, int bits) {
    pray_image tex;
    tex.width = tex.height = 64;
    tex.pixels = px.data();
    Ctx c;
    REQUIRE(pray_write_image(c, &tex, (d / name).c_str(), bits) == PRAY_OK);
    return "\"" + d / name + "\"";
}

// The texture written as `name` in d, and a program showing it head-on through a parallel
// camera over x, z in [-1, 1], the texture's corner at `corner`, one texel to a pixel at 64 x 64.
std::string texture_view(const TempDir &d, const char *name, std::vector<float> &px, int bits, const char *corner) {
    return std::string("parallel <1, 0, 0>, <0, 0, -1>, [0, -4, 0], [0, 0, 0]\n") + "M = tiff(color({0}), color({1}), " +
           texture_file(d, name, px, bits) + ")\nrendertiff planemap(M, " + corner + ", <0, -1, 0>, <2, 0, 0>, <0, 0, 2>), none\n";
}

} // namespace

TEST_CASE("undersampling keeps texture detail that falls between its samples") {
    // A white texture with one black row of texels, one texel to a pixel, seen head-on by a
    // parallel camera: the row lands on image row 21, between the rows of the coarse lattice
    // (every 4th pixel; with antialiasing, a sample of every pixel), where all lattice samples
    // are white.
    TempDir d;
    REQUIRE(!d.path.empty());
    std::vector<float> px(64 * 64 * 3, 1.0f);
    for (int x = 0; x < 64; x++)
        for (int k = 0; k < 3; k++) px[(10 * 64 + x) * 3 + k] = 0;
    std::string prog = texture_view(d, "line.tif", px, 8, "[0, 0, 0]");
    for (int aa : {1, 3}) {
        CAPTURE(aa);
        testkit::Sampled r = testkit::full_and_adaptive(prog, 64, 64, aa, 0.05);
        const std::vector<testkit::Frame> &frames = r.frames;
        const pray_stats *st = r.st;
        for (int x = 0; x < 64; x++) {
            CAPTURE(x);
            REQUIRE(frames[0].at(x, 21, 0) < 0.5f);  // the line is there in the full image
            REQUIRE(frames[0].at(x, 19, 0) == 1.0f);
            CHECK(frames[1].at(x, 21, 1) == frames[0].at(x, 21, 1));  // ... and with undersampling
        }
        CHECK(frames[1].pixels == frames[0].pixels);
        CHECK(st[1].rays_primary < st[0].rays_primary / 2);  // the white field is interpolated
    }
}

TEST_CASE("undersampling: a texture that only ramps between samples is interpolated") {
    // The same view of a texture that grows evenly from black to white across: between any two
    // lattice samples it stays within their values, so nothing is refined for the texture.
    TempDir d;
    REQUIRE(!d.path.empty());
    std::vector<float> px = grey_texels([](int x, int) { return (float)(x / 63.0); });
    // lattice samples 4 pixels apart differ by 4/63, under the threshold 0.08, while the texels
    // between them and their neighbours span 6/63, over it
    std::string prog = texture_view(d, "ramp.tif", px, 16, "[-1, 0, 0]");
    Ctx c;
    pray_option(c, "width", 64);
    pray_option(c, "height", 64);
    pray_option(c, "adaptive", 0.08);
    std::vector<testkit::Frame> frames;
    pray_set_frame(c, testkit::frame_sink, &frames);
    REQUIRE(pray_run_string(c, "ramp.ray", prog.data(), prog.size()) == PRAY_OK);
    pray_stats st;
    pray_stats_get(c, &st);
    REQUIRE(frames.size() == 1);
    CHECK(frames[0].at(63, 32, 0) - frames[0].at(0, 32, 0) > 0.9f);  // the whole ramp is in view
    CHECK(st.rays_primary < st.rays_primary_full / 6);  // 499 of 4096; refined for any spread: 1114
}

TEST_CASE("undersampling shades a lit textured surface sample by sample with the corners' light") {
    // A striped, bump-mapped face seen head-on, lit by a directional light and a point light. A
    // box out of view shades a quadrant of the face from the directional light: the shadow's
    // edges are straight and along the image's axes. Where the corners of a cell see the face
    // lit alike, its samples are shaded at their own points (texture, bumps, highlights) with
    // the corners' light; across the shadow's edges the cells are split down to samples. The
    // image is full sampling's, to rounding, for a fraction of the primary and shadow rays.
    TempDir d;
    REQUIRE(!d.path.empty());
    std::vector<float> px = grey_texels([](int x, int y) { return (x / 3 + y / 5) % 2 ? 1.0f : 0.2f; });
    std::string f = texture_file(d, "stripes.tif", px, 8);
    std::string prog =
        "parallel <1, 0, 0>, <0, 0, -1>, [0, -4, 0], [0, 0, 0]\n"
        "M = tiffbump(tiff(phong({0.1, 0.2, 0.1}, {0.4}, 20), phong({0.9, 0.8, 0.6}, {0.4}, 20), " + f + "), 0.01, " + f + ")\n"
        "Face = planemap(M, [-1, 0, -1], <0, -1, 0>, <2, 0, 0>, <0, 0, 2>)\n"
        "G = phong({0.5}, {0}, 1)\n"
        "Box = plane(G, [0, -2, 0], <0, -1, 0>) & plane(G, [0, -1.5, 0], <0, 1, 0>) & plane(G, [0, 0, 1.3], <0, 0, -1>) "
        "& plane(G, [0, 0, 5], <0, 0, 1>) & plane(G, [0.13, 0, 0], <1, 0, 0>) & plane(G, [-5, 0, 0], <-1, 0, 0>)\n"
        "rendertiff Face | Box, dirlight({0.7}, <0, 1, -1>), pointlight({0.5}, [0.3, -3, -0.2])\n";
    testkit::Sampled r = testkit::full_and_adaptive(prog, 64, 64, 2, 0.02);
    const std::vector<testkit::Frame> &frames = r.frames;
    const pray_stats *st = r.st;
    // the shadow is there: on average the part with x < 0.13 and z > -0.7 (upper left) is
    // darker than the rest
    float lit = 0, dark = 0;
    for (int y = 0; y < 64; y++)
        for (int x = 0; x < 64; x++) {
            bool shade = (x + 0.5) / 32 - 1 < 0.13 && 1 - (y + 0.5) / 32 > -0.7;
            (shade ? dark : lit) += frames[0].at(x, y, 0);
        }
    REQUIRE(dark / (0.565 * 0.85 * 4096) < 0.8 * lit / (4096 - 0.565 * 0.85 * 4096));
    float worst = 0;
    for (size_t i = 0; i < frames[0].pixels.size(); i++) {
        float e = std::fabs(frames[1].pixels[i] - frames[0].pixels[i]);
        worst = e > worst ? e : worst;
    }
    CHECK(worst < 1e-5f);
    CHECK(st[1].rays_primary * 3 < st[0].rays_primary);
    CHECK(st[1].rays_shadow * 3 < st[0].rays_shadow);
}
