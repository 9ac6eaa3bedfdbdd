#!/bin/sh
# make_tiffs.sh DIR [PYTHON] -- the TIFF corpus of tests/test_texture.cpp, written by tools that
# are not pray: python3 with PIL writes the source images (and, for the layouts PIL cannot
# write -- 4-bit grey and palette, 16-bit RGB(A), WhiteIsZero -- a plain uncompressed baseline
# TIFF is written byte by byte), then libtiff's tiffcp converts every source to both byte orders,
# strips and tiles, no compression, PackBits, LZW and LZW with the horizontal predictor.
#
# Writes into DIR:
#   SRC.tif, SRC.expect   a source image and its pixels as PIL (or the writer) has them:
#                         "W H" then one "r g b" line per pixel (rows from the first row of the
#                         file), each the sample value over its maximum, in %.17g
#   corpus.txt            "FILE SRC" lines: FILE must decode to the pixels of SRC.expect
#   bad.txt               "FILE WORD" lines: FILE must be refused with a message holding WORD
#   atlas.tif             a 16 x 16 font atlas of 8 x 8 cells: white, a black square for 'A'
# Exit status 0 when everything was written; 77 when tiffcp or PIL is missing.
set -eu
dir=$1
py=${2:-python3}
command -v tiffcp >/dev/null 2>&1 || { echo "make_tiffs.sh: tiffcp not found (package libtiff-tools)" >&2; exit 77; }
"$py" -c 'import PIL.Image' 2>/dev/null || { echo "make_tiffs.sh: $py has no PIL (package python3-pil)" >&2; exit 77; }
mkdir -p "$dir"
cd "$dir"

"$py" - <<'EOF'
import struct
from PIL import Image, ImageDraw

W, H = 45, 37  # not a multiple of the 16 x 16 tiles, nor of the strips

seed = [12345]
def rnd(n):
    seed[0] = (seed[0] * 1103515245 + 12345) & 0x7fffffff
    return (seed[0] >> 8) % n

def value(x, y, c, maxv):
    """Sample c of pixel (x, y): smooth ramps on the left (runs for PackBits and LZW), noise in
    the middle (many LZW codes: the code width reaches 12 bits and the table is cleared), flat
    blocks on the right, and the extremes 0 and maxv in the first row."""
    if y == 0:
        return (0, maxv, maxv // 2, 1)[(x + c) % 4]
    if x < 15:
        return (x * 7 + y * 3 + c * 11) * maxv // (15 * 7 + 37 * 3 + 33)
    if x < 32:
        return rnd(maxv + 1)
    return ((x // 5 + y // 6 + c) % 3) * maxv // 2

def expect(name, rows):
    with open(name + ".expect", "w") as f:
        f.write("%d %d\n" % (W, H))
        for r in rows:
            f.write("%.17g %.17g %.17g\n" % r)

# ---- sources written by PIL, expected pixels read back by PIL ----
def pil_source(name, mode, channels, maxv):
    if mode == "P":
        im = Image.new("P", (W, H))
        pal = [rnd(256) for _ in range(768)]
        pal[0:6] = [0, 0, 0, 255, 255, 255]
        im.putpalette(pal)
    else:
        im = Image.new(mode, (W, H))
    for y in range(H):
        for x in range(W):
            vals = [value(x, y, c, maxv) for c in range(channels)]
            if mode == "1":
                im.putpixel((x, y), 255 if vals[0] else 0)
            elif channels == 1:
                im.putpixel((x, y), vals[0])
            else:
                im.putpixel((x, y), tuple(vals))
    im.save(name + ".tif")
    back = Image.open(name + ".tif")
    back.load()
    rows = []
    if mode == "P":
        cmap = back.tag_v2[320]
        n = len(cmap) // 3
    for y in range(H):
        for x in range(W):
            p = back.getpixel((x, y))
            if mode == "P":
                rows.append((cmap[p] / 65535.0, cmap[n + p] / 65535.0, cmap[2 * n + p] / 65535.0))
            elif mode in ("RGB", "RGBA"):
                rows.append((p[0] / maxv, p[1] / maxv, p[2] / maxv))
            elif mode == "LA":
                rows.append((p[0] / maxv,) * 3)
            elif mode == "1":
                rows.append((1.0 if p else 0.0,) * 3)  # PIL has 0 and 255
            else:
                rows.append((p / maxv,) * 3)
    expect(name, rows)

pil_source("rgb8", "RGB", 3, 255)
pil_source("rgba8", "RGBA", 4, 255)
pil_source("grey8", "L", 1, 255)
pil_source("greya8", "LA", 2, 255)
pil_source("grey16", "I;16", 1, 65535)
pil_source("bilevel1", "1", 1, 1)
pil_source("pal8", "P", 1, 255)

# ---- sources PIL cannot write: a baseline TIFF, one uncompressed strip, little-endian ----
def raw_tiff(path, bps, spp, photometric, data, colormap=None, extra=None, more=()):
    tags = list(more) + [(256, 4, [W]), (257, 4, [H]), (258, 3, [bps] * spp), (259, 3, [1]),
            (262, 3, [photometric]), (273, 4, [0]), (277, 3, [spp]), (278, 4, [H]),
            (279, 4, [len(data)])]
    if colormap is not None:
        tags.append((320, 3, colormap))
    if extra is not None:
        tags.append((338, 3, [extra]))
    tags.sort()
    ifd = 8
    blob_at = ifd + 2 + 12 * len(tags) + 4
    blobs = b""
    entries = b""
    data_at = None
    for tag, typ, vals in tags:
        size = 2 if typ == 3 else 4
        packed = b"".join(struct.pack("<H" if typ == 3 else "<I", v) for v in vals)
        if tag == 273:
            entries += struct.pack("<HHI", tag, typ, 1)
            data_at = len(entries)
            entries += b"\0\0\0\0"
            continue
        if len(packed) <= 4:
            entries += struct.pack("<HHI", tag, typ, len(vals)) + packed.ljust(4, b"\0")
        else:
            entries += struct.pack("<HHII", tag, typ, len(vals), blob_at + len(blobs))
            blobs += packed
            if len(blobs) % 2:
                blobs += b"\0"
    data_off = blob_at + len(blobs)
    entries = entries[:data_at] + struct.pack("<I", data_off) + entries[data_at + 4:]
    out = b"II" + struct.pack("<HI", 42, ifd) + struct.pack("<H", len(tags)) + entries + b"\0\0\0\0" + blobs + data
    with open(path, "wb") as f:
        f.write(out)

def packed_rows(samples_of, bps, spp):
    """Rows of samples packed most significant bit first, each row padded to a byte."""
    out = bytearray()
    for y in range(H):
        bits, nbits = 0, 0
        row = bytearray()
        for x in range(W):
            for v in samples_of(x, y):
                if bps == 16:
                    row += struct.pack("<H", v)
                    continue
                bits = bits << bps | v
                nbits += bps
                while nbits >= 8:
                    row.append(bits >> (nbits - 8) & 255)
                    nbits -= 8
        if nbits:
            row.append(bits << (8 - nbits) & 255)
        out += row
    return bytes(out)

def hand_source(name, bps, spp, photometric, colors, colormap=None, extra=None):
    maxv = (1 << bps) - 1
    samples = {}
    for y in range(H):
        for x in range(W):
            samples[x, y] = [value(x, y, c, maxv) for c in range(spp)]
    raw_tiff(name + ".tif", bps, spp, photometric, packed_rows(lambda x, y: samples[x, y], bps, spp),
             colormap, extra)
    rows = []
    for y in range(H):
        for x in range(W):
            v = samples[x, y]
            if photometric == 3:
                n = maxv + 1
                rows.append(tuple(colormap[k * n + v[0]] / 65535.0 for k in range(3)))
            elif photometric == 2:
                rows.append(tuple(v[k] / maxv for k in range(3)))
            elif photometric == 0:
                rows.append((1 - v[0] / maxv,) * 3)
            else:
                rows.append((v[0] / maxv,) * 3)
    expect(name, rows)

hand_source("rgb16", 16, 3, 2, 3)
hand_source("rgba16", 16, 4, 2, 3, extra=2)
hand_source("grey4", 4, 1, 1, 1)
hand_source("pal4", 4, 1, 3, 1, colormap=[rnd(65536) for _ in range(48)])
hand_source("white8", 8, 1, 0, 1)
hand_source("white1", 1, 1, 0, 1)

# ---- refused: features pray does not read ----
im = Image.new("F", (W, H))
for y in range(H):
    for x in range(W):
        im.putpixel((x, y), x / W)
im.save("bad_float.tif")
Image.new("CMYK", (W, H), (10, 20, 30, 40)).save("bad_cmyk.tif")
raw_tiff("bad_int16s.tif", 16, 1, 1, bytes(W * 2 * H), more=[(339, 3, [2])])  # signed
raw_tiff("bad_grey2.tif", 2, 1, 1, bytes(((W * 2 + 7) // 8) * H))

# ---- the font atlas: 16 x 16 cells of 8 x 8 pixels, ink (black) only in 'A' ----
atlas = Image.new("L", (128, 128), 255)
ax, ay = (65 % 16) * 8, (65 // 16) * 8
ImageDraw.Draw(atlas).rectangle([ax + 2, ay + 2, ax + 5, ay + 5], fill=0)
atlas.save("atlas.tif")
EOF

: >corpus.txt
# one background job per source (tiffcp starts in a few milliseconds, but 384 of them add up)
convert() {
  src=$1 comps=$2
  for order in B L; do
    for comp in $comps; do
      for layout in r1 r7 r64 t16; do
        case $layout in
          r1) lo="-r 1" ;; r7) lo="-r 7" ;; r64) lo="-r 64" ;; t16) lo="-t -w 16 -l 16" ;;
        esac
        out="${src}_${order}_$(echo "$comp" | tr : p)_$layout.tif"
        # shellcheck disable=SC2086
        tiffcp -"$order" -c "$comp" $lo "$src.tif" "$out" || { echo "tiffcp failed: $out" >&2; exit 1; }
        echo "$out $src"
      done
    done
  done >"$src.list"
}
sources="rgb8 rgba8 grey8 greya8 grey16 bilevel1 pal8 rgb16 rgba16 grey4 pal4 white8 white1"
pids=""
for src in $sources; do
  case $src in
    bilevel1|white1|grey4|pal4) convert "$src" "none packbits lzw" & ;;  # no predictor below 8 bits
    *) convert "$src" "none packbits lzw lzw:2" & ;;
  esac
  pids="$pids $!"
done
for p in $pids; do wait "$p"; done
for src in $sources; do cat "$src.list" >>corpus.txt; done

tiffcp -c jpeg rgb8.tif bad_jpeg.tif
tiffcp -c zip rgb8.tif bad_zip.tif
tiffcp -p separate rgb8.tif bad_separate.tif
tiffcp -8 rgb8.tif bad_bigtiff.tif
cat >bad.txt <<'EOF'
bad_jpeg.tif JPEG compression (7)
bad_zip.tif Deflate compression (8)
bad_separate.tif separate
bad_bigtiff.tif BigTIFF
bad_float.tif floating-point samples
bad_cmyk.tif photometric
bad_int16s.tif signed integer samples
bad_grey2.tif 2 bits
EOF
