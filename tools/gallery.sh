#!/bin/sh
# tools/gallery.sh - the gallery: every example rendered into docs/gallery/ (256 x 256 PNG unless
# the program sets its own size), with its --stats summary, written to docs/gallery.md; the
# pictures of the texture makers in the manual (docs/images/*.ray -> docs/images/*.png); and
# a check that the fast renderer and --brute give the same image of every scene (64 x 64 PPM).
# The views of the room are made from examples/room.ray by replacing its camera line with the
# view's line from its header; they go to out/views/. Run by `make gallery` (POSIX sh).
set -e
cd "$(dirname "$0")/.."
PRAY=${PRAY:-./pray}
SIZE=256x256
G=docs/gallery
V=out/views
PAGE=docs/gallery.md
[ -x "$PRAY" ] || make -s pray
[ -f examples/tex/font.tif ] || make -s textures
mkdir -p $G $V docs/images
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT

# view NAME LABEL: out/views/NAME.ray is room.ray with the camera line of the header's LABEL line
view() {
  line=$(sed -n "s|^// $2: *||p" examples/room.ray)
  [ -n "$line" ] || { echo "gallery: no '// $2:' line in examples/room.ray" >&2; exit 1; }
  grep -q '// CAMERA: the general view$' examples/room.ray || { echo "gallery: no CAMERA line in room.ray" >&2; exit 1; }
  { echo "// $1.ray - made by tools/gallery.sh from examples/room.ray: the $2"
    sed "s|^.*// CAMERA: the general view\$|$line   // CAMERA: the $2|" examples/room.ray; } > "$V/$1.ray"
}
view roomtop "top view"
view room1 "view 1"
view room2 "view 2"
view room3 "view 3"
view room4 "view 4"

# field NAME FILE: one number or phrase from a --stats report
field() {
  case $1 in
    prims) awk '/^primitives:/ {print $4}' "$2" ;;
    nodes) awk '/^primitives:/ {print $NF}' "$2" ;;
    grid)  awk '/^grid:/ {print $2 "x" $4 "x" $6 ", " $10 " lists, " $13 " areas"} /^grid: none/ {print "none"}' "$2" ;;
    rays)  awk '/^rays:/ {gsub(/,/, ""); print $3 " primary, " $9 " shadow, " $11 " reflected, " $13 " refracted"}' "$2" ;;
    time)  awk '/^time:/ {printf "%.3f", $3 + $6 + $9}' "$2" ;;
    split) awk '/^time:/ {print "parse " $3 " s, prepare " $6 " s, render " $9 " s, " $12 " threads"}' "$2" ;;
  esac
}

# The first sentence of the program's header comment, without "name.ray - ".
describe() {
  awk 'NR == 1 { if (!sub(/^\/\/ *[^ ]+\.ray - /, "")) exit; s = $0; next }
       /^\/\/ / && s !~ /\.( |$)/ { sub(/^\/\/ */, ""); s = s " " $0; next }
       { exit }
       END { i = index(s, ". "); if (i) s = substr(s, 1, i); print s }' "$1"
}

# brute FILE: "same" when the default and the --brute render agree byte for byte at 64 x 64
brute() {
  rm -f "$TMP"/a*.ppm "$TMP"/b*.ppm
  $PRAY --quiet -s 64x64 -o "$TMP/a.ppm" "$1" >/dev/null 2>&1 || { echo "error"; return; }
  $PRAY --quiet --brute -s 64x64 -o "$TMP/b.ppm" "$1" >/dev/null 2>&1 || { echo "brute error"; return; }
  r=same
  for a in "$TMP"/a*.ppm; do
    b="$TMP/b${a#"$TMP"/a}"
    cmp -s "$a" "$b" || r="DIFFERENT ($(basename "$a"))"
  done
  echo "$r"
}

# The scenes: file|title[|description, where the program's first line does not give one]. First the thesis' appendix B in its order, then the other examples.
cat > "$TMP/list" <<'EOF'
examples/csg.ray|B.1 CSG operations|The thesis' own program CSG.RAY (appendix B), run as printed.
examples/rabbit.ray|B.2 Rabbit
examples/cube.ray|B.3 Cube
examples/fractal.ray|B.4 Fractal
examples/pc.ray|B.5 Personal computer
examples/glassab.ray|B.6 Glass abstraction
out/views/roomtop.ray|B.7 Room (top view)
examples/room.ray|B.8 Room (general view)
out/views/room1.ray|B.9 Room (view 1)
out/views/room2.ray|B.10 Room (view 2)
out/views/room3.ray|B.11 Room (view 3)
out/views/room4.ray|B.12 Room (view 4)
examples/textures.ray|Textures
examples/sign.ray|Text
examples/maketex.ray|The textures
examples/glass.ray|Glass
examples/mirror.ray|Mirror
examples/parallel.ray|Parallel camera
examples/street.ray|A street (lookat, include)
examples/holes.ray|Holes
examples/loop.ray|Loops
examples/models.ray|Lighting models
examples/anim.ray|Animation
examples/roomball.ray|A ball rolling through the Room (image-sequence coherence)
examples/machine.ray|A turning flywheel (image-sequence coherence)
examples/redsph.ray|The red sphere
examples/chess.ray|Chess
examples/water.ray|A glass of water on a table
examples/spot.ray|Spotlights
examples/redsphx.ray|The red sphere as printed|The red sphere of the thesis' appendix A exactly as printed, slips included.
EOF
# every example must be in the list
for f in examples/*.ray; do
  grep -q "^$f|" "$TMP/list" || { echo "gallery: $f is not in the gallery's list" >&2; exit 1; }
done

threads=$(getconf _NPROCESSORS_ONLN 2>/dev/null || echo "?")
{
  echo "# Gallery"
  echo
  echo "Every example program rendered by pray, with what \`pray --stats\` reports. The page and its"
  echo "pictures are made by \`make gallery\` (tools/gallery.sh); do not edit them by hand. The pictures"
  echo "are 256 x 256 unless the program sets its own size. Times are in seconds, on the machine that"
  echo "last ran the gallery: $(uname -m), $threads processors. \"--brute\" tells whether the image"
  echo "rendered with every acceleration (grid, areas, freezing, bounds) equals, byte for byte, the"
  echo "image of the brute-force reference renderer (both at 64 x 64)."
  echo
  echo "The first twelve are our own versions of the sample scenes of the thesis' appendix B (figures"
  echo "B.1-B.12); only the captions of most of the originals are known. The views of the room are"
  echo "examples/room.ray with its camera line replaced by one of the lines in its header. The"
  echo "textured scenes need the textures of \`make textures\` (examples/maketex.ray)."
  echo
  echo "| scene | program | primitives | time (s) | --brute |"
  echo "|---|---|---:|---:|---|"
} > "$TMP/head.md"
: > "$TMP/body.md"

while IFS='|' read -r f title d; do
  [ -n "$d" ] || d=$(describe "$f")
  n=$(basename "$f" .ray)
  rm -f "$G/$n.png" "$G/${n}"_[0-9][0-9][0-9][0-9].png
  size="-s $SIZE"
  grep -q '^option "width"' "$f" && size=
  printf '%-10s' "$n" >&2
  set +e
  # shellcheck disable=SC2086
  $PRAY --quiet --stats $size -o "$G/$n.png" "$f" > "$TMP/out.txt" 2> "$TMP/stats.txt"
  rc=$?
  set -e
  anchor=$(echo "$title" | tr 'A-Z' 'a-z' | sed 's/[^a-z0-9 -]//g; s/ /-/g')
  src=$f
  case $f in out/*) src="examples/room.ray";; esac
  if [ $rc -ne 0 ]; then
    if [ "$n" = redsphx ]; then  # an error on purpose
      msg=$(head -n 1 "$TMP/stats.txt")
      echo " error, as intended" >&2
      echo "| [$title](#$anchor) | $n.ray | - | - | - |" >> "$TMP/head.md"
      { echo "## $title"
        echo
        echo "\`$f\`: $d It stops with an error and writes no image:"
        echo
        echo '```'
        echo "$msg"
        echo '```'
        echo; } >> "$TMP/body.md"
      continue
    fi
    echo " FAILED:" >&2
    cat "$TMP/stats.txt" >&2
    exit 1
  fi
  same=$(brute "$f")
  t=$(field time "$TMP/stats.txt")
  echo " $t s, brute: $same" >&2
  echo "| [$title](#$anchor) | $n.ray | $(field prims "$TMP/stats.txt") | $t | $same |" >> "$TMP/head.md"
  {
    echo "## $title"
    echo
    if [ "$src" = "$f" ]; then echo "\`$f\`: $d"
    else echo "\`$f\`, made from \`examples/room.ray\` by the gallery: the room seen from another place."; fi
    echo
    for p in "$G/$n.png" "$G/${n}"_[0-9][0-9][0-9][0-9].png; do
      [ -f "$p" ] || continue
      w=$(od -An -j16 -N4 -tu1 "$p" | awk '{print $1*16777216 + $2*65536 + $3*256 + $4}')
      if [ "$w" -gt 256 ]; then echo "<img src=\"gallery/$(basename "$p")\" width=\"256\" alt=\"$n\">"
      else echo "![$n](gallery/$(basename "$p"))"; fi
    done
    echo
    echo "| primitives | nodes | grid | rays | time |"
    echo "|---:|---:|---|---|---|"
    echo "| $(field prims "$TMP/stats.txt") | $(field nodes "$TMP/stats.txt") | $(field grid "$TMP/stats.txt") | $(field rays "$TMP/stats.txt") | $(field split "$TMP/stats.txt") |"
    echo
    [ -s "$TMP/out.txt" ] && { echo "The program prints:"; echo; echo '```'; cat "$TMP/out.txt"; echo '```'; echo; }
    case $n in anim|maketex) echo "The statistics of a program that renders several frames are the totals of all its frames, the primitives those of the last frame."; echo;; esac
  } >> "$TMP/body.md"
done < "$TMP/list"

{ cat "$TMP/head.md"; echo; cat "$TMP/body.md"; } > "$PAGE"
echo "gallery: $PAGE" >&2

# The manual's pictures of the texture makers.
for f in docs/images/*.ray; do
  n=$(basename "$f" .ray)
  printf '%-10s' "$n" >&2
  $PRAY --quiet -s 192x192 -o "docs/images/$n.png" "$f"
  echo " -> docs/images/$n.png, brute: $(brute "$f")" >&2
done
