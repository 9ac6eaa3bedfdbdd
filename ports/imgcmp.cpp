// imgcmp — compare two images written by pray (PPM P6 or baseline uncompressed RGB TIFF,
// 8 or 16 bits per sample), for ports/check.
//
//   c++ -O2 ports/imgcmp.cpp -o imgcmp
//   imgcmp [-s WxH] [-t LEVELS] [-p PERCENT] reference.ppm other.ppm
//
// Prints one line: "identical", or how many pixels differ, by how much at most. Exit status:
// 0 identical or within the tolerance (every channel within LEVELS (default 1) of the
// reference, on at most PERCENT (default 0.1) percent of the pixels), 1 over the tolerance,
// 2 a file missing, unreadable, of another size than -s WxH, or of another format.
// The reader is independent of pray's writers: TIFF tags are read in either byte order.
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

struct Image {
    long w, h;
    int bits;
    unsigned char *data;  // w*h*3 samples, 1 or 2 bytes each as in the file
    unsigned long size;
    bool big;             // 16-bit samples stored big-endian (PPM) or little (TIFF "II")
};

static unsigned char *slurp(const char *path, unsigned long *n) {
    FILE *f = fopen(path, "rb");
    if (!f) return NULL;
    unsigned long cap = 1 << 16, len = 0;
    unsigned char *b = (unsigned char *)malloc(cap);
    size_t got;
    while (b && (got = fread(b + len, 1, cap - len, f)) > 0) {
        len += got;
        if (len == cap) {
            unsigned char *nb = (unsigned char *)realloc(b, cap * 2);
            if (!nb) {
                free(b);
                b = NULL;
            }
            b = nb;
            cap *= 2;
        }
    }
    fclose(f);
    *n = len;
    return b;
}

static const char *ppm_token(const unsigned char *b, unsigned long n, unsigned long *i, long *v) {
    while (*i < n && (b[*i] == ' ' || b[*i] == '\n' || b[*i] == '\r' || b[*i] == '\t' || b[*i] == '#')) {
        if (b[*i] == '#')
            while (*i < n && b[*i] != '\n') ++*i;
        else
            ++*i;
    }
    if (*i >= n || b[*i] < '0' || b[*i] > '9') return "bad PPM header";
    *v = 0;
    while (*i < n && b[*i] >= '0' && b[*i] <= '9' && *v < 100000000) *v = *v * 10 + (b[(*i)++] - '0');
    return NULL;
}

static const char *read_ppm(const unsigned char *b, unsigned long n, Image *im) {
    unsigned long i = 2;
    long maxval;
    const char *e;
    if ((e = ppm_token(b, n, &i, &im->w)) || (e = ppm_token(b, n, &i, &im->h)) ||
        (e = ppm_token(b, n, &i, &maxval)))
        return e;
    if (i >= n) return "truncated PPM";
    i++;  // the single whitespace after maxval
    if (maxval != 255 && maxval != 65535) return "PPM maxval is neither 255 nor 65535";
    im->bits = maxval == 255 ? 8 : 16;
    im->big = true;
    unsigned long need = (unsigned long)im->w * im->h * 3 * (im->bits / 8);
    if (im->w < 1 || im->h < 1 || n - i < need) return "truncated PPM";
    im->data = (unsigned char *)b + i;
    im->size = need;
    return NULL;
}

static unsigned long get(const unsigned char *p, int bytes, bool be) {
    unsigned long v = 0;
    for (int k = 0; k < bytes; k++) v |= (unsigned long)p[be ? bytes - 1 - k : k] << (8 * k);
    return v;
}

static const char *read_tiff(const unsigned char *b, unsigned long n, Image *im) {
    if (n < 8) return "truncated TIFF";
    bool be = b[0] == 'M';
    if (get(b + 2, 2, be) != 42) return "not a TIFF";
    unsigned long ifd = get(b + 4, 4, be);
    if (ifd + 2 > n) return "bad TIFF IFD offset";
    unsigned long count = get(b + ifd, 2, be), off = 0, bytes = 0, nstrips = 0;
    long spp = 1, comp = 1, photo = -1;
    im->bits = 0;
    im->w = im->h = 0;
    if (ifd + 2 + count * 12 > n) return "truncated TIFF IFD";
    for (unsigned long k = 0; k < count; k++) {
        const unsigned char *e = b + ifd + 2 + 12 * k;
        unsigned long tag = get(e, 2, be), type = get(e + 2, 2, be), cnt = get(e + 4, 4, be);
        int sz = type == 3 ? 2 : 4;
        unsigned long val = cnt * sz <= 4 ? get(e + 8, sz, be) : 0, ptr = get(e + 8, 4, be);
        switch (tag) {
        case 256: im->w = (long)val; break;
        case 257: im->h = (long)val; break;
        case 258:
            if (cnt == 1) im->bits = (int)val;
            else if (ptr + 2 <= n) im->bits = (int)get(b + ptr, 2, be);
            break;
        case 259: comp = (long)val; break;
        case 262: photo = (long)val; break;
        case 273: off = cnt == 1 ? val : (ptr + 4 <= n ? get(b + ptr, sz, be) : n); nstrips = cnt; break;
        case 277: spp = (long)val; break;
        case 279: bytes = cnt == 1 ? val : 0; break;
        }
    }
    if (comp != 1 || spp != 3 || photo != 2 || (im->bits != 8 && im->bits != 16))
        return "not an uncompressed 8/16-bit RGB TIFF";
    if (nstrips != 1) return "TIFF with more than one strip (not pray's writer)";
    unsigned long need = (unsigned long)im->w * im->h * 3 * (im->bits / 8);
    if (im->w < 1 || im->h < 1 || bytes < need || off > n || n - off < need) return "truncated TIFF";
    im->data = (unsigned char *)b + off;
    im->size = need;
    im->big = be;
    return NULL;
}

static const char *load(const char *path, Image *im, unsigned char **buf, unsigned long *len) {
    unsigned long &n = *len;
    n = 0;
    *buf = slurp(path, &n);
    if (!*buf) return "cannot read the file";
    if (n >= 2 && (*buf)[0] == 'P' && (*buf)[1] == '6') return read_ppm(*buf, n, im);
    if (n >= 4 && (((*buf)[0] == 'I' && (*buf)[1] == 'I') || ((*buf)[0] == 'M' && (*buf)[1] == 'M')))
        return read_tiff(*buf, n, im);
    return "neither PPM (P6) nor TIFF";
}

static int usage() {
    fprintf(stderr, "usage: imgcmp [-s WxH] [-t LEVELS] [-p PERCENT] reference other\n");
    return 2;
}

int main(int argc, char **argv) {
    long want_w = 0, want_h = 0, tol = 1;
    double pct = 0.1;
    int i = 1;
    for (; i + 1 < argc && argv[i][0] == '-'; i += 2) {
        if (strcmp(argv[i], "-s") == 0) {
            if (sscanf(argv[i + 1], "%ldx%ld", &want_w, &want_h) != 2) return usage();
        } else if (strcmp(argv[i], "-t") == 0)
            tol = atol(argv[i + 1]);
        else if (strcmp(argv[i], "-p") == 0)
            pct = atof(argv[i + 1]);
        else
            return usage();
    }
    if (argc - i != 2) return usage();
    Image a, b;
    unsigned char *ba = NULL, *bb = NULL;
    unsigned long na = 0, nb = 0;
    const char *e;
    if ((e = load(argv[i], &a, &ba, &na))) {
        printf("%s: %s\n", argv[i], e);
        return 2;
    }
    if ((e = load(argv[i + 1], &b, &bb, &nb))) {
        printf("%s: %s\n", argv[i + 1], e);
        return 2;
    }
    if (want_w && (a.w != want_w || a.h != want_h || b.w != want_w || b.h != want_h)) {
        printf("size %ldx%ld and %ldx%ld, expected %ldx%ld\n", a.w, a.h, b.w, b.h, want_w, want_h);
        return 2;
    }
    if (a.w != b.w || a.h != b.h || a.bits != b.bits) {
        printf("size differs: %ldx%ld/%d against %ldx%ld/%d\n", b.w, b.h, b.bits, a.w, a.h, a.bits);
        return 2;
    }
    long pixels = a.w * a.h, differ = 0, maxd = 0;
    int bytes = a.bits / 8;
    for (long p = 0; p < pixels; p++) {
        long d = 0;
        for (int c = 0; c < 3; c++) {
            long k = (p * 3 + c) * bytes;
            long va = (long)get(a.data + k, bytes, a.big), vb = (long)get(b.data + k, bytes, b.big);
            long x = va > vb ? va - vb : vb - va;
            if (x > d) d = x;
        }
        if (d) differ++;
        if (d > maxd) maxd = d;
    }
    bool same = na == nb && memcmp(ba, bb, na) == 0;  // the whole files, byte for byte
    double share = 100.0 * differ / pixels;
    if (differ == 0)
        printf("%s\n", same ? "identical" : "same pixels, files differ");
    else
        printf("%ld of %ld pixels differ (%.3f%%), by at most %ld\n", differ, pixels, share, maxd);
    free(ba);
    free(bb);
    return differ == 0 || (maxd <= tol && share <= pct) ? 0 : 1;
}
