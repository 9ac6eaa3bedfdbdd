// Image files and the command line. Files written by pray are decoded by INDEPENDENT readers:
// python3 with PIL (Debian python3-pil), libtiff's tiffinfo (libtiff-tools), and a few lines of
// Python reading raw bytes. The command-line program ./pray is built by make before the tests
// run; the tests run from the repository root. POSIX only (mkdtemp, popen, wait status).
#include <doctest/doctest.h>

#include "../pray.hpp"
#include "testkit.hpp"
#include "tempfiles.hpp"

#include <signal.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace {

using testkit::TempDir;
using testkit::slurp;
using testkit::spit;

bool starts(const std::string &s, const std::string &prefix) { return s.compare(0, prefix.size(), prefix) == 0; }

bool exists(const std::string &path) {
    std::error_code ec;
    return fs::exists(path, ec);
}

// Run a shell command; returns its exit status (-1 when it did not exit normally) and, through
// `out`, what it wrote to standard output and standard error together.
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

// Single-quote a string for the shell.
std::string sq(const std::string &s) {
    std::string r = "'";
    for (char ch : s) r += ch == '\'' ? std::string("'\\''") : std::string(1, ch);
    return r + "'";
}

// A python3 that has PIL: the one on PATH, else the system's.
const std::string &python() {
    static std::string py;
    static bool done = false;
    if (!done) {
        done = true;
        const char *cands[] = {"python3", "/usr/bin/python3"};
        for (const char *c : cands)
            if (run_cmd(std::string(c) + " -c 'import PIL.Image'", NULL) == 0) {
                py = c;
                break;
            }
    }
    return py;
}

// The test image: 4 x 3 pixels with edge cases in the first row.
const int W = 4, H = 3;
std::vector<float> test_pixels() {
    std::vector<float> p(W * H * 3);
    for (int i = 0; i < W * H * 3; i++) p[i] = (float)(i / 35.0);
    const float row0[12] = {0.5f, 0.123f, 2.0f,
                            -1.0f, std::numeric_limits<float>::quiet_NaN(), 1.0f,
                            0.25f, 0.75f, 1e-9f,
                            std::numeric_limits<float>::infinity(), -std::numeric_limits<float>::infinity(), 0.999f};
    for (int i = 0; i < 12; i++) p[i] = row0[i];
    return p;
}

// Quantisation as the format promises: clamp to [0, 1] (NaN to 0), round to nearest.
unsigned q(float v, unsigned maxval) {
    if (!(v > 0)) return 0;
    if (v >= 1) return maxval;
    return (unsigned)std::floor((double)v * maxval + 0.5);
}

std::string expected_list(unsigned maxval) {
    std::vector<float> p = test_pixels();
    std::string s;
    for (int i = 0; i < W * H; i++) {
        char b[64];
        snprintf(b, sizeof b, "%s(%u, %u, %u)", i ? ", " : "", q(p[3 * i], maxval), q(p[3 * i + 1], maxval),
                 q(p[3 * i + 2], maxval));
        s += b;
    }
    return "[" + s + "]";
}

pray_status write_test_image(const std::string &path, int bits, pray_ctx **keep = NULL) {
    std::vector<float> p = test_pixels();
    pray_image img;
    img.width = W;
    img.height = H;
    img.pixels = p.data();
    pray_ctx *c = pray_new();
    pray_status st = pray_write_image(c, &img, path.c_str(), bits);
    if (keep) *keep = c;
    else pray_free(c);
    return st;
}

unsigned le16(const std::string &s, size_t at) {
    return (unsigned char)s[at] | (unsigned)(unsigned char)s[at + 1] << 8;
}
unsigned long le32(const std::string &s, size_t at) { return le16(s, at) | (unsigned long)le16(s, at + 2) << 16; }

const char *PIL_DUMP = "import sys\nfrom PIL import Image\nim = Image.open(sys.argv[1])\n"
                       "a = im.tile[0][3] if im.tile else ''\n"
                       "print(im.format, im.size, im.mode, a if isinstance(a, str) else a[0])\n"
                       "print(list(im.convert('RGB').getdata()))\n";

std::string pil_dump(const std::string &path) {
    REQUIRE_MESSAGE(!python().empty(), "no python3 with PIL (Debian: python3-pil)");
    std::string out;
    int rc = run_cmd(python() + " -c " + sq(PIL_DUMP) + " " + sq(path), &out);
    CHECK_MESSAGE(rc == 0, out);
    return out;
}

} // namespace

// =============================================================================================
// Files decoded by independent readers
// =============================================================================================
TEST_CASE("TIFF 8 bit: PIL reads it back, tiffinfo accepts it without warnings") {
    TempDir d;
    REQUIRE(!d.path.empty());
    std::string f = d / "a.tif";
    REQUIRE(write_test_image(f, 8) == PRAY_OK);
    std::string out = pil_dump(f);
    CHECK(out == "TIFF (4, 3) RGB RGB\n" + expected_list(255) + "\n");
    // the quantisation: 0.5 -> 128, > 1 -> 255, negative and NaN -> 0
    CHECK(out.find("[(128, 31, 255), (0, 0, 255), (64, 191, 0), (255, 0, 255)") != std::string::npos);
    std::string info;
    int rc = run_cmd("tiffinfo -D " + sq(f), &info);
    CHECK(rc == 0);
    INFO(info);
    CHECK(info.find("arning") == std::string::npos);
    CHECK(info.find("rror") == std::string::npos);
    CHECK(info.find("Image Width: 4 Image Length: 3") != std::string::npos);
    CHECK(info.find("Bits/Sample: 8") != std::string::npos);
    CHECK(info.find("Samples/Pixel: 3") != std::string::npos);
    CHECK(info.find("Photometric Interpretation: RGB color") != std::string::npos);
    CHECK(info.find("Compression Scheme: None") != std::string::npos);
    CHECK(d.listing() == "a.tif");  // no temporary file left
}

TEST_CASE("TIFF 16 bit: little-endian samples, read by PIL and decoded exactly by libtiff") {
    TempDir d;
    std::string f = d / "a16.tif";
    REQUIRE(write_test_image(f, 16) == PRAY_OK);
    std::string out = pil_dump(f);
    CHECK(out.rfind("TIFF (4, 3) RGB RGB;16L\n", 0) == 0);  // PIL sees 16-bit little-endian RGB
    // PIL hands out 8 bits: the high byte of every sample, within one
    std::vector<float> p = test_pixels();
    {
        std::string script = std::string("import sys\nfrom PIL import Image\n") +
                             "print(' '.join('%d %d %d' % px for px in Image.open(sys.argv[1]).convert('RGB').getdata()))\n";
        std::string vals;
        REQUIRE(run_cmd(python() + " -c " + sq(script) + " " + sq(f), &vals) == 0);
        std::istringstream in(vals);
        int bad = 0;
        for (int i = 0; i < W * H * 3; i++) {
            int v = -1;
            in >> v;
            if (std::abs(v - (int)(q(p[i], 65535) / 257.0 + 0.5)) > 1) bad++;
        }
        CHECK(bad == 0);
    }
    // libtiff's decoded strip, exactly (host byte order; this host is checked to be little-endian)
    std::string info;
    REQUIRE(run_cmd("tiffinfo -d " + sq(f), &info) == 0);
    CHECK(info.find("arning") == std::string::npos);
    CHECK(info.find("Bits/Sample: 16") != std::string::npos);
    size_t at = info.find("Strip 0:");
    REQUIRE(at != std::string::npos);
    std::istringstream hex(info.substr(at + 8));
    std::vector<unsigned> bytes;
    std::string tok;
    while (hex >> tok && bytes.size() < (size_t)W * H * 6) bytes.push_back((unsigned)std::stoul(tok, NULL, 16));
    REQUIRE(bytes.size() == (size_t)W * H * 6);
    const uint16_t probe = 1;
    bool little = *(const unsigned char *)&probe == 1;
    int bad = 0;
    for (int i = 0; i < W * H * 3; i++) {
        unsigned v = little ? bytes[2 * i] | bytes[2 * i + 1] << 8 : bytes[2 * i] << 8 | bytes[2 * i + 1];
        if (v != q(p[i], 65535)) bad++;
    }
    CHECK(bad == 0);
    CHECK(q(0.5f, 65535) == 32768);
}

TEST_CASE("TIFF: byte-exact header") {
    TempDir d;
    for (int bits : {8, 16}) {
        CAPTURE(bits);
        std::string f = d / ("h" + std::to_string(bits) + ".tif");
        REQUIRE(write_test_image(f, bits) == PRAY_OK);
        std::string s = slurp(f);
        REQUIRE(s.size() > 200);
        CHECK(starts(s, std::string("II*\0", 4)));
        unsigned long ifd = le32(s, 4);
        REQUIRE(ifd + 2 + 12 * 12 + 4 <= s.size());
        CHECK(le16(s, ifd) == 12);  // 12 tags
        unsigned prev = 0;
        unsigned long strip = 0, count = 0;
        std::vector<unsigned> tags;
        for (int i = 0; i < 12; i++) {
            size_t e = ifd + 2 + 12 * i;
            unsigned tag = le16(s, e), type = le16(s, e + 2);
            unsigned long n = le32(s, e + 4);
            tags.push_back(tag);
            CHECK(tag > prev);  // ascending, as TIFF requires
            prev = tag;
            unsigned long val = type == 3 && n == 1 ? le16(s, e + 8) : le32(s, e + 8);
            if (tag == 256) CHECK(val == (unsigned long)W);
            if (tag == 257) CHECK(val == (unsigned long)H);
            if (tag == 259) CHECK(val == 1);  // no compression
            if (tag == 262) CHECK(val == 2);  // RGB
            if (tag == 277) CHECK(val == 3);
            if (tag == 258) {
                CHECK(n == 3);
                for (int k = 0; k < 3; k++) CHECK(le16(s, val + 2 * k) == (unsigned)bits);
            }
            if (tag == 273) strip = val;
            if (tag == 279) count = val;
        }
        CHECK(le32(s, ifd + 2 + 12 * 12) == 0);  // one image only
        const unsigned want_tags[12] = {256, 257, 258, 259, 262, 273, 277, 278, 279, 282, 283, 296};
        CHECK(tags == std::vector<unsigned>(want_tags, want_tags + 12));
        CHECK(count == (unsigned long)W * H * 3 * (bits / 8));
        CHECK(strip + count == s.size());
        if (bits == 16) {
            // 0.5 -> 32768 = 0x8000 and 0.123 -> 8061 = 0x1F7D, low byte first
            CHECK((unsigned char)s[strip] == 0x00);
            CHECK((unsigned char)s[strip + 1] == 0x80);
            CHECK((unsigned char)s[strip + 2] == 0x7D);
            CHECK((unsigned char)s[strip + 3] == 0x1F);
        } else {
            CHECK((unsigned char)s[strip] == 128);
            CHECK((unsigned char)s[strip + 1] == 31);
            CHECK((unsigned char)s[strip + 2] == 255);
        }
    }
}

TEST_CASE("PPM 8 and 16 bit: byte-exact header, PIL and a raw reader agree") {
    TempDir d;
    std::string f8 = d / "a.ppm", f16 = d / "a16.ppm";
    REQUIRE(write_test_image(f8, 8) == PRAY_OK);
    REQUIRE(write_test_image(f16, 16) == PRAY_OK);
    std::string s8 = slurp(f8), s16 = slurp(f16);
    CHECK(starts(s8, "P6\n4 3\n255\n"));
    CHECK(s8.size() == 11 + (size_t)W * H * 3);
    CHECK(starts(s16, "P6\n4 3\n65535\n"));
    CHECK(s16.size() == 13 + (size_t)W * H * 6);
    // 16-bit PPM samples are big-endian: 0.5 -> 0x80 0x00
    REQUIRE(s16.size() > 16);
    CHECK((unsigned char)s16[13] == 0x80);
    CHECK((unsigned char)s16[14] == 0x00);
    CHECK((unsigned char)s16[15] == 0x1F);
    CHECK((unsigned char)s16[16] == 0x7D);

    std::string out = pil_dump(f8);
    CHECK(out == "PPM (4, 3) RGB RGB\n" + expected_list(255) + "\n");
    out = pil_dump(f16);
    CHECK(out.rfind("PPM (4, 3) RGB", 0) == 0);

    // a raw reader in Python: header tokens, then big-endian 16-bit samples
    std::string script = "import sys, struct\nb = open(sys.argv[1], 'rb').read()\n"
                         "t = b.split(None, 4)\nw, h, m = int(t[1]), int(t[2]), int(t[3])\n"
                         "d = t[4]\nprint(t[0].decode(), w, h, m, len(d))\n"
                         "print(list(struct.unpack('>%dH' % (w*h*3), d)))\n";
    std::string raw;
    REQUIRE(run_cmd(python() + " -c " + sq(script) + " " + sq(f16), &raw) == 0);
    std::vector<float> p = test_pixels();
    std::string want = "P6 4 3 65535 72\n[";
    for (int i = 0; i < W * H * 3; i++) want += (i ? ", " : "") + std::to_string(q(p[i], 65535));
    want += "]\n";
    CHECK(raw == want);
    CHECK(d.listing() == "a.ppm a16.ppm");
}

TEST_CASE("PNG: PIL reads it back") {
    pray_ctx *c = pray_new();
    bool png = std::string(pray_features()).find("png") != std::string::npos;
    pray_free(c);
    TempDir d;
    std::string f = d / "a.png";
    if (!png) {
        CHECK(write_test_image(f, 8) != PRAY_OK);  // no PNG in this build: an error, no file
        CHECK(d.listing() == "");
        return;
    }
    REQUIRE(write_test_image(f, 8) == PRAY_OK);
    CHECK(pil_dump(f) == "PNG (4, 3) RGB RGB\n" + expected_list(255) + "\n");
    CHECK(write_test_image(d / "b.png", 16) != PRAY_OK);  // PNG has 8 bits here
    CHECK(d.listing() == "a.png");
}

TEST_CASE("writers into a byte sink give the same bytes as the files") {
    TempDir d;
    std::vector<float> p = test_pixels();
    pray_image img;
    img.width = W;
    img.height = H;
    img.pixels = p.data();
    pray_ctx *c = pray_new();
    for (int bits : {8, 16}) {
        std::string tif, ppm;
        CHECK(pray_write_tiff(c, &img, bits, testkit::print_sink, &tif) == PRAY_OK);
        CHECK(pray_write_ppm(c, &img, bits, testkit::print_sink, &ppm) == PRAY_OK);
        REQUIRE(pray_write_image(c, &img, (d / "x.tif").c_str(), bits) == PRAY_OK);
        REQUIRE(pray_write_image(c, &img, (d / "x.ppm").c_str(), bits) == PRAY_OK);
        CHECK(slurp(d / "x.tif") == tif);
        CHECK(slurp(d / "x.ppm") == ppm);
    }
    // PNG: the same bytes through the sink as in the file, or refused by a build without it
    std::string png;
    pray_status st = pray_write_png(c, &img, testkit::print_sink, &png);
    if (std::strstr(pray_features(), "png")) {
        CHECK(st == PRAY_OK);
        REQUIRE(pray_write_image(c, &img, (d / "x.png").c_str(), 8) == PRAY_OK);
        CHECK(slurp(d / "x.png") == png);
        CHECK(starts(png, "\x89PNG\r\n\x1a\n"));
    } else {
        CHECK(st == PRAY_ERR_ARG);
        CHECK(png.empty());
    }
    // upper-case extensions and .tiff are TIFF too
    CHECK(pray_write_image(c, &img, (d / "y.TIF").c_str(), 8) == PRAY_OK);
    CHECK(pray_write_image(c, &img, (d / "y.tiff").c_str(), 8) == PRAY_OK);
    CHECK(starts(slurp(d / "y.TIF"), std::string("II*\0", 4)));
    CHECK(starts(slurp(d / "y.tiff"), std::string("II*\0", 4)));
    pray_free(c);
}

// =============================================================================================
// Failures leave nothing behind
// =============================================================================================
TEST_CASE("writing into a directory that does not exist fails with PRAY_ERR_IO and leaves nothing") {
    TempDir d;
    pray_ctx *c = NULL;
    for (const char *name : {"nodir/x.tif", "nodir/x.ppm", "nodir/x.png"}) {
        CAPTURE(name);
        pray_status st = write_test_image(d / name, 8, &c);
        if (std::string(name).find(".png") == std::string::npos || std::string(pray_features()).find("png") != std::string::npos) {
            CHECK(st == PRAY_ERR_IO);
            CHECK(std::string(pray_error(c)).find("nodir") != std::string::npos);
        } else {
            CHECK(st != PRAY_OK);
        }
        pray_free(c);
    }
    CHECK(d.listing() == "");
}

TEST_CASE("a target that cannot be replaced (a directory) fails and the temporary file is removed") {
    TempDir d;
    fs::create_directory(d / "x.ppm");
    pray_ctx *c = NULL;
    CHECK(write_test_image(d / "x.ppm", 8, &c) == PRAY_ERR_IO);
    CHECK(std::string(pray_error(c)) != "");
    pray_free(c);
    CHECK(d.listing() == "x.ppm");
    CHECK(fs::is_directory(d / "x.ppm"));
}

TEST_CASE("an unknown or missing extension is an error and writes nothing") {
    TempDir d;
    pray_ctx *c = NULL;
    for (const char *name : {"x.bmp", "x", "x.tif.gz", "x.jpg"}) {
        CAPTURE(name);
        CHECK(write_test_image(d / name, 8, &c) != PRAY_OK);
        CHECK(std::string(pray_error(c)) != "");
        pray_free(c);
    }
    // bits other than 8 and 16
    CHECK(write_test_image(d / "y.tif", 12, &c) != PRAY_OK);
    pray_free(c);
    CHECK(d.listing() == "");
}

TEST_CASE("a failed write leaves an existing file as it was") {
    TempDir d;
    std::string f = d / "keep.ppm";
    spit(f, "old contents");
    pray_ctx *c = NULL;
    CHECK(write_test_image(f, 12, &c) != PRAY_OK);
    pray_free(c);
    CHECK(slurp(f) == "old contents");
    CHECK(d.listing() == "keep.ppm");
    // a successful write replaces it whole
    REQUIRE(write_test_image(f, 8) == PRAY_OK);
    CHECK(starts(slurp(f), "P6\n4 3\n255\n"));
    CHECK(d.listing() == "keep.ppm");
}

TEST_CASE("rendertiff writes files: the output option, the default name, numbered frames") {
    TempDir d;
    pray_ctx *c = pray_new();
    std::string prog = "option \"width\", 3\noption \"height\", 2\noption \"output\", \"" + (d / "f.ppm") +
                       "\"\nrendertiff sphere(color({1}), [0, 0, 0], 1)\nrendertiff nothing\nrendertiff nothing\n";
    REQUIRE(pray_run_string(c, "f.ray", prog.data(), prog.size()) == PRAY_OK);
    CHECK(pray_frames(c) == 3);
    CHECK(d.listing() == "f.ppm f_0001.ppm f_0002.ppm");
    CHECK(starts(slurp(d / "f.ppm"), "P6\n3 2\n255\n"));
    std::string hashes = "option \"width\", 2\noption \"height\", 2\noption \"output\", \"" + (d / "anim###.ppm") +
                         "\"\nI = 0\nwhile I < 2\nrendertiff nothing\nI = I + 1\nendwhile\n";
    REQUIRE(pray_run_string(c, "anim.ray", hashes.data(), hashes.size()) == PRAY_OK);
    CHECK(exists(d / "anim000.ppm"));
    CHECK(exists(d / "anim001.ppm"));
    CHECK(!exists(d / "anim002.ppm"));
    // without the output option: the program's name with .tif
    std::string plain = "option \"width\", 2\noption \"height\", 2\nrendertiff nothing\n";
    std::string name = d / "scene.ray";
    REQUIRE(pray_run_string(c, name.c_str(), plain.data(), plain.size()) == PRAY_OK);
    CHECK(exists(d / "scene.tif"));
    CHECK(starts(slurp(d / "scene.tif"), std::string("II*\0", 4)));
    // bits 16 through the option
    std::string b16 = "option \"width\", 2\noption \"height\", 2\noption \"bits\", 16\noption \"output\", \"" + (d / "b.ppm") +
                      "\"\nrendertiff nothing\n";
    REQUIRE(pray_run_string(c, "b.ray", b16.data(), b16.size()) == PRAY_OK);
    CHECK(starts(slurp(d / "b.ppm"), "P6\n2 2\n65535\n"));
    pray_free(c);
}

TEST_CASE("a failed program or render writes no image") {
    TempDir d;
    pray_ctx *c = pray_new();
    const std::string out = "option \"width\", 2\noption \"height\", 2\noption \"output\", \"" + (d / "x.ppm") + "\"\n";
    const char *bad[] = {
        "rendertiff sphere(color({1}), [0, 0, 0], 1), 5\n",        // a number where a light belongs
        "rendertiff 5\n",                                          // not an object
        "S = sphere(color({1}), [0, 0, 0], 1)\nrendertiff S, Lite\n",  // undefined variable
    };
    for (const char *b : bad) {
        CAPTURE(b);
        std::string prog = out + b;
        CHECK(pray_run_string(c, "bad.ray", prog.data(), prog.size()) != PRAY_OK);
        CHECK(std::string(pray_error(c)).find("bad.ray:") != std::string::npos);
    }
    // out of memory during the render
    pray_set_memory_limit(c, 20000);
    std::string big = "option \"width\", 200\noption \"height\", 200\noption \"output\", \"" + (d / "y.ppm") +
                      "\"\nrendertiff sphere(color({1}), [0, 0, 0], 1)\n";
    CHECK(pray_run_string(c, "big.ray", big.data(), big.size()) != PRAY_OK);
    pray_free(c);
    CHECK(d.listing() == "");
}

// =============================================================================================
// The command line
// =============================================================================================
namespace {
bool have_pray() { return exists(testkit::pray_program()) && exists("examples/csg.ray"); }
const char *NO_PRAY = "./pray or examples/ missing: run the tests from the repository root after make";
} // namespace

TEST_CASE("command line: renders CSG.RAY, exit status 0") {
    REQUIRE_MESSAGE(have_pray(), NO_PRAY);
    TempDir d;
    std::string out;
    int rc = run_cmd(testkit::pray_shell() + " --quiet -s 32x32 -o " + sq(d / "x.ppm") + " examples/csg.ray", &out);
    CHECK_MESSAGE(rc == 0, out);
    std::string s = slurp(d / "x.ppm");
    CHECK(starts(s, "P6\n32 32\n255\n"));
    CHECK(s.size() == 13 + 32 * 32 * 3);
    CHECK(d.listing() == "x.ppm");
    // the same without --quiet: no terminal, so no progress bar either
    rc = run_cmd(testkit::pray_shell() + " -s 32x32 -o " + sq(d / "y.tif") + " examples/csg.ray", &out);
    CHECK(rc == 0);
    CHECK(out == "");
    CHECK(starts(slurp(d / "y.tif"), std::string("II*\0", 4)));
    // the picture: PIL sees a 32x32 image, not all one colour
    std::string pix = pil_dump(d / "x.ppm");
    CHECK(pix.rfind("PPM (32, 32) RGB", 0) == 0);
    CHECK(pix.find("(0, 0, 0)") != std::string::npos);
}

TEST_CASE("command line: a program error exits with 1, names the place and writes nothing") {
    REQUIRE_MESSAGE(have_pray(), NO_PRAY);
    TempDir d;
    std::string out;
    int rc = run_cmd(testkit::pray_shell() + " -s 8x8 -o " + sq(d / "x.ppm") + " examples/redsphx.ray", &out);
    CHECK(rc == 1);
    CHECK(out.find("redsphx.ray:5:") != std::string::npos);
    CHECK(out.find("Centre") != std::string::npos);
    CHECK(d.listing() == "");
    // the message is "file:line:col: error: ..." on standard error; nothing on standard output
    std::string only_out;
    CHECK(run_cmd(testkit::pray_shell() + " -s 8x8 -o " + sq(d / "x.ppm") + " examples/redsphx.ray 2>/dev/null", &only_out, false) == 1);
    CHECK(only_out == "");
    std::string only_err;
    CHECK(run_cmd(testkit::pray_shell() + " -s 8x8 -o " + sq(d / "x.ppm") + " examples/redsphx.ray 2>&1 >/dev/null", &only_err, false) == 1);
    size_t at = only_err.find("redsphx.ray:5:");
    REQUIRE(at != std::string::npos);
    size_t col_end = only_err.find(':', at + 14);
    REQUIRE(col_end != std::string::npos);
    std::string col = only_err.substr(at + 14, col_end - at - 14);
    CHECK(!col.empty());
    CHECK(col.find_first_not_of("0123456789") == std::string::npos);
    CHECK(only_err.compare(col_end, 9, ": error: ") == 0);
    // an error in rendertiff itself, after an image name was chosen
    spit(d / "bad.ray", "option \"width\", 4\noption \"height\", 4\nrendertiff sphere(color({1}), [0, 0, 0], 1), 5\n");
    rc = run_cmd(testkit::pray_shell() + " -o " + sq(d / "y.ppm") + " " + sq(d / "bad.ray"), &out);
    CHECK(rc == 1);
    CHECK(out.find("bad.ray:3:") != std::string::npos);
    CHECK(d.listing() == "bad.ray");
}

TEST_CASE("command line: usage errors exit with 2") {
    REQUIRE_MESSAGE(have_pray(), NO_PRAY);
    TempDir d;
    const char *cases[] = {"--frobnicate examples/csg.ray", "-s 10 examples/csg.ray", "-s 10x examples/csg.ray",
                           "-s x10 examples/csg.ray", "-D width examples/csg.ray", "", "-o", "examples/csg.ray examples/csg.ray",
                           "-D width=abc examples/csg.ray", "-D nosuch=1 examples/csg.ray", "--threads x examples/csg.ray"};
    for (const char *a : cases) {
        CAPTURE(a);
        std::string out;
        int rc = run_cmd(testkit::pray_shell() + " -o " + sq(d / "x.ppm") + " " + a, &out);
        CHECK(rc == 2);
        CHECK(out != "");
    }
    CHECK(d.listing() == "");
}

TEST_CASE("command line: unreadable program or unwritable output exits with 3") {
    REQUIRE_MESSAGE(have_pray(), NO_PRAY);
    TempDir d;
    std::string out;
    int rc = run_cmd(testkit::pray_shell() + " -o " + sq(d / "x.ppm") + " " + sq(d / "missing.ray"), &out);
    CHECK(rc == 3);
    CHECK(out.find("missing.ray") != std::string::npos);
    rc = run_cmd(testkit::pray_shell() + " -s 8x8 -o " + sq(d / "nodir/x.ppm") + " examples/csg.ray", &out);
    CHECK(rc == 3);
    CHECK(out.find("nodir") != std::string::npos);
    CHECK(d.listing() == "");
}

TEST_CASE("command line: --version and --help exit with 0") {
    REQUIRE_MESSAGE(have_pray(), NO_PRAY);
    std::string out;
    CHECK(run_cmd(testkit::pray_shell() + " --version", &out) == 0);
    CHECK(out.find(PRAY_VERSION_STRING) != std::string::npos);
    CHECK(run_cmd(testkit::pray_shell() + " --help", &out) == 0);
    CHECK(out.find("usage") != std::string::npos);
    CHECK(out.find("-D") != std::string::npos);
}

TEST_CASE("a camera whose |X| : |Y| is not width : height: one warning a run, on standard error") {
    // the API: the warning goes where pray_set_warning says, once however many frames
    const std::string prog = "option \"width\", 40\noption \"height\", 20\nS = sphere(color({1}), [0, 0, 0], 1)\n"
                             "rendertiff S\nrendertiff S\n";
    pray_ctx *c = pray_new();
    std::string warned;
    pray_set_warning(c, testkit::print_sink, &warned);
    pray_set_frame(c, [](void *, const pray_image *, const char *) { return PRAY_OK; }, NULL);
    REQUIRE(pray_run_string(c, "s.ray", prog.data(), prog.size()) == PRAY_OK);
    CHECK(warned == "s.ray:4:1: warning: the image is 40 x 20 pixels but the camera's |X| : |Y| is 1 : 1, so the "
                    "picture is stretched sideways (make |X| / |Y| equal to width / height)\n");
    // in step (|X| = 2 |Y|), or within 1 %: nothing
    warned.clear();
    const std::string fits = "option \"width\", 40\noption \"height\", 20\n"
                             "perspective <2, 0, 0>, <0, 0, -1>, [0, -4, 0], [0, 0, 0]\nrendertiff sphere(color({1}), [0, 0, 0], 1)\n"
                             "perspective <1.009, 0, 0>, <0, 0, -0.5>, [0, -4, 0], [0, 0, 0]\nrendertiff sphere(color({1}), [0, 0, 0], 1)\n";
    REQUIRE(pray_run_string(c, "f.ray", fits.data(), fits.size()) == PRAY_OK);
    CHECK(warned == "");
    // taller than the camera: stretched vertically
    const std::string tall = "option \"height\", 40\noption \"width\", 20\nrendertiff sphere(color({1}), [0, 0, 0], 1)\n";
    REQUIRE(pray_run_string(c, "t.ray", tall.data(), tall.size()) == PRAY_OK);
    CHECK(warned.find("t.ray:3:1: warning: the image is 20 x 40 pixels but the camera's |X| : |Y| is 1 : 1, so the "
                      "picture is stretched vertically") == 0);
    pray_free(c);

    // the command line: on standard error, the image is still written, exit status 0
    REQUIRE_MESSAGE(have_pray(), NO_PRAY);
    TempDir d;
    std::string err;
    CHECK(run_cmd(testkit::pray_shell() + " -s 64x32 -o " + sq(d / "x.ppm") + " examples/redsph.ray 2>&1 >/dev/null", &err, false) == 0);
    CHECK(err == "examples/redsph.ray:9:1: warning: the image is 64 x 32 pixels but the camera's |X| : |Y| is 1 : 1, "
                 "so the picture is stretched sideways (make |X| / |Y| equal to width / height)\n");
    CHECK(d.listing() == "x.ppm");
    CHECK(run_cmd(testkit::pray_shell() + " -s 64x64 -o " + sq(d / "y.ppm") + " examples/redsph.ray 2>&1 >/dev/null", &err, false) == 0);
    CHECK(err == "");
    // --quiet: no warnings (N copies from N processes of a parallel run), the image the same
    CHECK(run_cmd(testkit::pray_shell() + " --quiet -s 64x32 -o " + sq(d / "z.ppm") + " examples/redsph.ray 2>&1 >/dev/null", &err, false) == 0);
    CHECK(err == "");
    CHECK(slurp(d / "z.ppm") == slurp(d / "x.ppm"));
}

TEST_CASE("command line: -o - writes PPM to standard output, and print goes to standard error") {
    REQUIRE_MESSAGE(have_pray(), NO_PRAY);
    TempDir d;
    spit(d / "p.ray", "print \"hello\"\nrendertiff sphere(color({1, 0.5, 0}), [0, 0, 0], 0.5)\n"
                      "rendertiff sphere(color({0, 0, 1}), [0, 0, 0], 0.5)\n");
    std::string out, err;
    CHECK(run_cmd("(" + testkit::pray_shell() + " -s 8x8 -o - " + sq(d / "p.ray") + " 2>" + sq(d / "err.txt") + " >" +
                      sq(d / "out.ppm") + ")", &out) == 0);
    CHECK(slurp(d / "err.txt") == "hello\n");
    CHECK(run_cmd(testkit::pray_shell() + " -s 8x8 -o " + sq(d / "f.ppm") + " " + sq(d / "p.ray"), &out) == 0);
    // the two frames, one after the other: the files the run writes, f.ppm and f_0001.ppm
    std::string s = slurp(d / "out.ppm"), f = slurp(d / "f.ppm"), g = slurp(d / "f_0001.ppm");
    CHECK(s == f + g);
    CHECK(f != g);
    CHECK(s.compare(0, 11, "P6\n8 8\n255\n") == 0);
    // not with row parts
    CHECK(run_cmd(testkit::pray_shell() + " -o - --rows 0:4 " + sq(d / "p.ray"), &out) == 2);
    CHECK(out.find("-o - writes whole images") != std::string::npos);
}

TEST_CASE("command line: -D and -s win over the program's options") {
    REQUIRE_MESSAGE(have_pray(), NO_PRAY);
    TempDir d;
    spit(d / "w.ray", "option \"width\", 64\noption \"height\", 8\noption \"output\", \"" + (d / "prog.ppm") +
                          "\"\nrendertiff sphere(color({1}), [0, 0, 0], 1)\n");
    std::string out;
    int rc = run_cmd(testkit::pray_shell() + " -D width=16 -o " + sq(d / "w.ppm") + " " + sq(d / "w.ray"), &out);
    CHECK_MESSAGE(rc == 0, out);
    CHECK(starts(slurp(d / "w.ppm"), "P6\n16 8\n255\n"));
    CHECK(!exists(d / "prog.ppm"));  // -o wins over the output option
    rc = run_cmd(testkit::pray_shell() + " -s 5x6 -D bits=16 -o " + sq(d / "s.ppm") + " " + sq(d / "w.ray"), &out);
    CHECK_MESSAGE(rc == 0, out);
    CHECK(starts(slurp(d / "s.ppm"), "P6\n5 6\n65535\n"));
    // without -o the program's output option holds
    rc = run_cmd(testkit::pray_shell() + " -D height=3 " + sq(d / "w.ray"), &out);
    CHECK_MESSAGE(rc == 0, out);
    CHECK(starts(slurp(d / "prog.ppm"), "P6\n64 3\n255\n"));
}

// =============================================================================================
// Writing and reading files safely (hostile names, links, FIFOs, races, signals)
// =============================================================================================
namespace {
// The names in a directory that look like a temporary file of pray (".NAME.XXXXXX.tmp").
std::string temporaries(const TempDir &d) {
    std::string s;
    for (const fs::directory_entry &e : fs::directory_iterator(d.path)) {
        std::string n = e.path().filename().string();
        if (n.size() > 4 && n.compare(n.size() - 4, 4, ".tmp") == 0) s += n + " ";
    }
    return s;
}

// A whole 8-bit PPM: its header's size and its length agree. Returns the width, or 0.
int whole_ppm(const std::string &bytes) {
    int w = 0, h = 0, n = 0;
    if (sscanf(bytes.c_str(), "P6\n%d %d\n255\n%n", &w, &h, &n) != 2 || n == 0) return 0;
    return bytes.size() == (size_t)n + 3u * w * h ? w : 0;
}
} // namespace

TEST_CASE("the temporary file is new, unique and no link: a planted link is neither followed nor renamed") {
    TempDir d;
    spit(d / "victim.txt", "victim");
    fs::create_symlink("victim.txt", d / "out.ppm.tmp");   // the temporary name pray once used
    fs::create_symlink("victim.txt", d / "link.ppm");      // an output that is a link
    REQUIRE(write_test_image(d / "out.ppm", 8) == PRAY_OK);
    REQUIRE(write_test_image(d / "link.ppm", 8) == PRAY_OK);
    CHECK(slurp(d / "victim.txt") == "victim");
    CHECK(fs::is_symlink(d / "out.ppm.tmp"));
    CHECK(!fs::is_symlink(d / "out.ppm"));
    CHECK(!fs::is_symlink(d / "link.ppm"));  // the link is replaced, not what it points to
    CHECK(whole_ppm(slurp(d / "link.ppm")) == W);
    CHECK(d.listing() == "link.ppm out.ppm out.ppm.tmp victim.txt");
    // the same through the command line in untrusted mode
    REQUIRE_MESSAGE(have_pray(), NO_PRAY);
    spit(d / "p.ray", "rendertiff sphere(color({1}), [0, 0, 0], 1)\n");
    fs::create_symlink("victim.txt", d / "u.ppm.tmp");
    std::string out;
    CHECK(run_cmd("cd " + sq(d.path) + " && " + fs::absolute(testkit::pray_program()).string() + " --untrusted -s 8x8 -o u.ppm p.ray", &out) == 0);
    CHECK(slurp(d / "victim.txt") == "victim");
    CHECK(whole_ppm(slurp(d / "u.ppm")) == 8);
}

TEST_CASE("the file is made with the permissions fopen would give: 0666 less the umask") {
    TempDir d;
    for (mode_t mask : {(mode_t)022, (mode_t)077, (mode_t)002}) {
        CAPTURE(mask);
        mode_t old = umask(mask);
        pray_status st = write_test_image(d / "m.ppm", 8);
        umask(old);
        REQUIRE(st == PRAY_OK);
        struct stat sb;
        REQUIRE(stat((d / "m.ppm").c_str(), &sb) == 0);
        CHECK((sb.st_mode & 0777) == (0666 & ~mask));
        fs::remove(d / "m.ppm");
    }
}

TEST_CASE("a name of 255 bytes can be written: the temporary name is shorter") {
    TempDir d;
    std::string name = std::string(251, 'n') + ".ppm";
    REQUIRE(write_test_image(d / name, 8) == PRAY_OK);
    CHECK(whole_ppm(slurp(d / name)) == W);
    pray_ctx *c = NULL;
    CHECK(write_test_image(d / ("n" + name), 8, &c) == PRAY_ERR_IO);  // 256: the system's limit
    CHECK(std::string(pray_error(c)).find("File name too long") != std::string::npos);
    pray_free(c);
    CHECK(d.listing() == name);
}

TEST_CASE("command line: renders to one output at once leave one whole image (8 at a time, 4 rounds)") {
    REQUIRE_MESSAGE(have_pray(), NO_PRAY);
    TempDir d;
    // (a camera of 1.51 : 1, within 1 % of every width : 400 below, so no warning either)
    spit(d / "p.ray", "perspective <1.51, 0, 0>, <0, 0, -1>, [0, -4, 0], [0, 0, 0]\n"
                      "rendertiff sphere(color({1}), [0, 0, 0], 1)\n");
    // eight widths: a file that mixes two renders has a header that does not fit its length (with
    // one temporary name for all, runs failed to rename or left such a file in each round)
    std::string script = "cd " + sq(d.path) + " && for w in 601 602 603 604 605 606 607 608; do (" +
                         fs::absolute(testkit::pray_program()).string() + " -s ${w}x400 -o out.ppm p.ray || echo FAILED $w) & done; wait";
    for (int round = 0; round < 4; round++) {
        CAPTURE(round);
        std::string out;
        run_cmd(script, &out);
        CHECK(out == "");
        int w = whole_ppm(slurp(d / "out.ppm"));
        CHECK(w >= 601);
        CHECK(w <= 608);
        CHECK(d.listing() == "out.ppm p.ray");
    }
}

TEST_CASE("command line: SIGINT, SIGTERM, SIGHUP or SIGQUIT while writing removes the temporary file (80 runs)") {
    REQUIRE_MESSAGE(have_pray(), NO_PRAY);
    TempDir d;
    spit(d / "p.ray", "rendertiff nothing\n");
    std::string prog = fs::absolute(testkit::pray_program()).string(), out = d / "out.ppm", ray = d / "p.ray";
    // a closed terminal or a dropped ssh (SIGHUP) and Ctrl-\ (SIGQUIT) end pray as SIGINT and SIGTERM do
    const int sigs[] = {SIGINT, SIGTERM, SIGHUP, SIGQUIT};
    const char *const names[] = {"SIGINT", "SIGTERM", "SIGHUP", "SIGQUIT"};
    // the test's own handlers (doctest's) must not run in a child before it becomes ./pray:
    // the signals wait, blocked, until the child has their default disposition
    sigset_t all, before;
    sigemptyset(&all);
    for (int s : sigs) sigaddset(&all, s);
    sigprocmask(SIG_BLOCK, &all, &before);
    auto start = [&]() {
        pid_t pid = fork();
        if (pid == 0) {
            for (int s : sigs) signal(s, SIG_DFL);
            struct rlimit none = {0, 0};  // SIGQUIT dumps no core
            setrlimit(RLIMIT_CORE, &none);
            sigprocmask(SIG_UNBLOCK, &all, NULL);
            execl(prog.c_str(), "pray", "--quiet", "-s", "1200x1200", "-D", "bits=16", "-o", out.c_str(), ray.c_str(),
                  (char *)NULL);
            _exit(127);
        }
        return pid;
    };
    // how long one run takes, to kill the others at any point of it
    auto t0 = std::chrono::steady_clock::now();
    pid_t pid = start();
    int status = 0;
    waitpid(pid, &status, 0);
    CHECK(WIFEXITED(status));
    CHECK(WEXITSTATUS(status) == 0);
    long total = (long)std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::steady_clock::now() - t0).count();
    fs::remove(out);
    srand(12345);
    int killed[4] = {0, 0, 0, 0}, finished = 0;
    for (int i = 0; i < 80; i++) {
        CAPTURE(i);
        CAPTURE(names[i % 4]);
        pid = start();
        REQUIRE(pid > 0);
        usleep((useconds_t)(rand() % (total + 1)));
        kill(pid, sigs[i % 4]);
        waitpid(pid, &status, 0);
        if (WIFSIGNALED(status)) {
            killed[i % 4]++;
            CHECK(WTERMSIG(status) == sigs[i % 4]);  // died of the signal
        } else
            finished++;
        CHECK(temporaries(d) == "");
        if (exists(out)) {
            CHECK(slurp(out).size() == 19u + 6u * 1200 * 1200);  // only ever a whole image
            fs::remove(out);
        }
    }
    sigprocmask(SIG_SETMASK, &before, NULL);
    MESSAGE("killed by SIGINT ", killed[0], ", SIGTERM ", killed[1], ", SIGHUP ", killed[2], ", SIGQUIT ", killed[3],
            "; finished ", finished, " of 80 runs of ", total / 1000, " ms");
    for (int k = 0; k < 4; k++) {
        CAPTURE(names[k]);
        CHECK(killed[k] > 3);
    }
}

TEST_CASE("command line: a file over the size limit (ulimit -f, SIGXFSZ) is a write error, nothing left") {
    REQUIRE_MESSAGE(have_pray(), NO_PRAY);
    TempDir d;
    spit(d / "p.ray", "rendertiff nothing\n");
    const std::string prog = fs::absolute(testkit::pray_program()).string();
    std::string out;
    // 200 blocks of 512 bytes: the 600 x 600 image of 1 MiB does not fit, the part of 8 rows does
    const std::string limit = "cd " + sq(d.path) + " && ulimit -f 200 && ";
    CHECK(run_cmd(limit + prog + " --quiet -s 600x600 -o out.ppm p.ray", &out) == 3);
    CHECK(out == "p.ray:1:1: error: cannot write 'out.ppm': File too large\n");
    CHECK(d.listing() == "p.ray");
    // a part small enough, one too large, and --join of two parts too large together
    CHECK(run_cmd(limit + prog + " --quiet -s 600x600 --rows 0:8 -o a.ppm p.ray", &out) == 0);
    CHECK(run_cmd(limit + prog + " --quiet -s 600x600 --rows 8:600 -o b.ppm p.ray", &out) == 3);
    CHECK(out == "p.ray:1:1: error: cannot write 'b.ppm': File too large\n");
    CHECK(run_cmd("cd " + sq(d.path) + " && " + prog + " --quiet -s 600x600 --rows 8:600 -o b.ppm p.ray", &out) == 0);
    CHECK(run_cmd(limit + prog + " --join out.ppm a.ppm b.ppm", &out) == 3);
    CHECK(out == "pray: error: cannot write 'out.ppm': File too large\n");
    CHECK(d.listing() == "a.ppm b.ppm p.ray");
}

TEST_CASE("command line: pray refuses to write over its own program") {
    REQUIRE_MESSAGE(have_pray(), NO_PRAY);
    TempDir d;
    const std::string prog = "rendertiff sphere(color({1}), [0, 0, 0], 1)\n";
    spit(d / "p.ppm", prog);
    spit(d / "scene.tif", prog);
    fs::create_symlink("p.ppm", d / "alias.ppm");
    std::string out;
    CHECK(run_cmd(testkit::pray_shell() + " -s 8x8 -o " + sq(d / "p.ppm") + " " + sq(d / "p.ppm"), &out) == 3);
    CHECK(out == d / "p.ppm" + ":1:1: error: cannot write '" + (d / "p.ppm") +
                     "': it is the program being run (choose another output name)\n");
    // another name for the same file
    CHECK(run_cmd(testkit::pray_shell() + " -s 8x8 -o " + sq(d / "alias.ppm") + " " + sq(d / "p.ppm"), &out) == 3);
    CHECK(run_cmd("cd " + sq(d.path) + " && " + fs::absolute(testkit::pray_program()).string() + " -s 8x8 -o ./p.ppm p.ppm", &out) == 3);
    // the default name of scene.tif is scene.tif
    CHECK(run_cmd(testkit::pray_shell() + " -s 8x8 " + sq(d / "scene.tif"), &out) == 3);
    CHECK(out.find("it is the program being run") != std::string::npos);
    CHECK(slurp(d / "p.ppm") == prog);
    CHECK(slurp(d / "scene.tif") == prog);
    CHECK(d.listing() == "alias.ppm p.ppm scene.tif");
    // another output is fine
    CHECK(run_cmd(testkit::pray_shell() + " -s 8x8 -o " + sq(d / "q.ppm") + " " + sq(d / "p.ppm"), &out) == 0);
}

TEST_CASE("command line: no output replaces a file the program read (an include, a texture)") {
    REQUIRE_MESSAGE(have_pray(), NO_PRAY);
    TempDir d;
    const std::string cd = "cd " + sq(d.path) + " && " + fs::absolute(testkit::pray_program()).string() + " -s 8x8 ";
    std::string out;
    spit(d / "bg.ray", "rendertiff nothing\n");
    REQUIRE(run_cmd(cd + "-o tex.tif bg.ray", &out) == 0);
    const std::string tex = slurp(d / "tex.tif");
    spit(d / "lib.ppm", "S = sphere(color({1}), [0, 0, 0], 1)\n");
    spit(d / "mid.ray", "include \"lib.ppm\"\n");
    spit(d / "p.ray", "include \"lib.ppm\"\nrendertiff S, none\n");
    spit(d / "q.ray", "include \"mid.ray\"\nrendertiff S, none\n");
    spit(d / "t.ray", "T = tiff(color({0}), color({1}), \"tex.tif\")\n"
                      "rendertiff planemap(T, [0, 0, 0], <0, 0, 1>, <1, 0, 0>, <0, 1, 0>), none\n");
    fs::create_hard_link(d / "lib.ppm", d / "hard.ppm");
    const std::string refused = "': the program reads it (choose another output name)\n";
    struct Case {
        const char *args;
        std::string message;
    } cases[] = {
        {"-o lib.ppm p.ray", "p.ray:2:1: error: cannot write 'lib.ppm" + refused},
        {"-o ./lib.ppm p.ray", "p.ray:2:1: error: cannot write './lib.ppm" + refused},
        {"-o hard.ppm p.ray", "p.ray:2:1: error: cannot write 'hard.ppm" + refused},  // the same file
        {"--untrusted -o lib.ppm p.ray", "p.ray:2:1: error: cannot write 'lib.ppm" + refused},
        {"-o lib.ppm q.ray", "q.ray:2:1: error: cannot write 'lib.ppm" + refused},  // included by an include
        {"-o tex.tif t.ray", "t.ray:2:1: error: cannot write 'tex.tif" + refused},  // a texture
    };
    for (const Case &k : cases) {
        CAPTURE(k.args);
        CHECK(run_cmd(cd + k.args, &out) == 3);
        CHECK(out == k.message);
    }
    CHECK(slurp(d / "lib.ppm") == "S = sphere(color({1}), [0, 0, 0], 1)\n");
    CHECK(slurp(d / "tex.tif") == tex);
    CHECK(d.listing() == "bg.ray hard.ppm lib.ppm mid.ray p.ray q.ray t.ray tex.tif");
    // another output is fine, and what one run read binds no later run of the same context
    CHECK(run_cmd(cd + "-o other.ppm p.ray", &out) == 0);
    pray_ctx *c = pray_new();
    REQUIRE(c);
    REQUIRE(pray_option_fix(c, "width", "4") == PRAY_OK);
    REQUIRE(pray_option_fix(c, "height", "4") == PRAY_OK);
    REQUIRE(pray_option_fix(c, "output", (d / "lib.ppm").c_str()) == PRAY_OK);
    CHECK(pray_run_file(c, (d / "p.ray").c_str()) == PRAY_ERR_IO);
    CHECK(std::string(pray_error(c)).find(refused.substr(3, 20)) != std::string::npos);
    CHECK(pray_run_file(c, (d / "bg.ray").c_str()) == PRAY_OK);
    CHECK(whole_ppm(slurp(d / "lib.ppm")) == 4);
    pray_free(c);
}

TEST_CASE("command line: 16 bits with a PNG output is an error of the options (exit 2), found before the program runs") {
    REQUIRE_MESSAGE(have_pray(), NO_PRAY);
    if (std::string(pray_features()).find("png") == std::string::npos) return;
    TempDir d;
    spit(d / "p.ray", "print \"ran\"\nrendertiff nothing\n");
    const std::string cd = "cd " + sq(d.path) + " && " + fs::absolute(testkit::pray_program()).string() + " -s 8x8 ";
    std::string out;
    for (const char *args : {"-D bits=16 -o x.png", "-o x.png -D bits=16", "-D output=x.PNG -D bits=16"}) {
        CAPTURE(args);
        CHECK(run_cmd(cd + args + " p.ray", &out) == 2);
        std::string name = strstr(args, "PNG") ? "x.PNG" : "x.png";
        CHECK(out == "pray: error: option 'bits': 16, but PNG output has 8 bits only ('" + name + "': use .tif or .ppm)\n");
    }
    // a program's own option is found where it renders
    spit(d / "q.ray", "option \"bits\", 16\nrendertiff nothing\n");
    CHECK(run_cmd(cd + "-o x.png q.ray", &out) == 1);
    CHECK(out == "q.ray:2:1: error: PNG output has 8 bits only\n");
    CHECK(run_cmd(cd + "-D bits=16 -o x.tif p.ray", &out) == 0);
    CHECK(d.listing() == "p.ray q.ray x.tif");
}

TEST_CASE("command line: a FIFO, a directory or a device as program or texture is an error, never a hang") {
    REQUIRE_MESSAGE(have_pray(), NO_PRAY);
    TempDir d;
    REQUIRE(mkfifo((d / "fifo.tif").c_str(), 0600) == 0);
    REQUIRE(mkfifo((d / "fifo.ray").c_str(), 0600) == 0);
    const std::string pray = "timeout 20 " + fs::absolute(testkit::pray_program()).string() + " -s 8x8 -o out.ppm ";
    const char *textures[] = {"fifo.tif", ".", "/dev/zero", "/dev/null"};
    for (const char *t : textures)
        for (const char *mode : {"", "--untrusted "}) {
            CAPTURE(t);
            CAPTURE(mode);
            spit(d / "p.ray", std::string("T = tiff(color({0}), color({1}), \"") + t + "\")\n");
            std::string out;
            int rc = run_cmd("cd " + sq(d.path) + " && " + pray + mode + "p.ray", &out);
            if (*mode && t[0] == '/') {
                CHECK(rc == 1);  // untrusted: an absolute name is refused before any open
                CHECK(out.find("is not a relative name") != std::string::npos);
                continue;
            }
            CHECK(rc == 1);
            CHECK(out == std::string("p.ray:1:5: error: cannot read '") + t + "': not a regular file\n");
        }
    for (const char *p : {"fifo.ray", ".", "/dev/null"}) {
        CAPTURE(p);
        std::string out;
        CHECK(run_cmd("cd " + sq(d.path) + " && " + pray + p, &out) == 3);
        CHECK(out == std::string("pray: error: cannot read '") + p + "': not a regular file\n");
    }
    CHECK(d.listing() == "fifo.ray fifo.tif p.ray");
}
