#!/bin/sh
# bench/coherence.sh - image sequences (option coherence, docs/acceleration.md): the time of a
# frame with and without it, on one thread, for animations where little moves and one where
# everything does. Prints a table for docs/benchmarks.md; never part of `make check`.
#
# The first frame of a program records a sample of its pixels, the second records all when the
# sample says that the third frame pays for it, and the frames after it take pixels over; see
# docs/acceleration.md. A frame's time is what `pray --stats` reports for it (preparing and
# rendering, on one thread); each run is made RUNS times (default 3) and the least time of each
# frame kept, so that other work on the machine counts as little as possible. With
# --instructions, a frame's cost is instead the instructions it took (valgrind's callgrind, in
# millions: from the end of the frame before, the first frame with the program's start), the
# same on every run. Every frame is compared with coherence=0's, byte for byte. Prints the cost
# of each frame, then a summary.
# Usage: bench/coherence.sh [RUNS] | bench/coherence.sh --instructions
set -e
cd "$(dirname "$0")/.."
PRAY=./pray
[ -x $PRAY ] || make -s pray
RUNS=${1:-3}
UNIT=ms
if [ "$1" = --instructions ]; then
  command -v valgrind > /dev/null || { echo "coherence: --instructions needs valgrind" >&2; exit 1; }
  UNIT="M instructions"
fi
OUT=$(mktemp -d)
trap 'rm -rf "$OUT"' EXIT

# The Room with everything in it moved a little each frame, lights and camera fixed.
sed '$d' examples/room.ray | sed '$d' > "$OUT/roomall.ray"
cat >> "$OUT/roomall.ray" <<'EOF'
Sun = dirlight({0.75, 0.7, 0.6}, <-0.45, -1, -0.75>)
option "output", "roomall###.ppm"
Frame = 0
while Frame < 8
  rendertiff Room . [0.01*Frame, 0, 0], Sun, Lamp1, Lamp2
  Frame = Frame + 1
endwhile
EOF

# frame_times FILE COHERENCE: the least time of each frame over RUNS runs, one a line, in ms
frame_times() {
  i=0
  : > "$OUT/all"
  while [ $i -lt "$RUNS" ]; do
    $PRAY --quiet --stats --threads 1 -D coherence=$2 -o "$OUT/f###.ppm" "$1" 2>&1 > /dev/null |
      awk '/^frame/ {k++; print k, 1000 * ($4 + $7)}' >> "$OUT/all"
    i=$((i + 1))
  done
  awk '{ if (!($1 in m) || $2 < m[$1]) m[$1] = $2; if ($1 > n) n = $1 } END {for (k = 1; k <= n; k++) print m[k]}' "$OUT/all"
}

# frame_instructions FILE COHERENCE: the instructions of each frame, one a line, in millions
# (callgrind writes what was counted after each frame into a file of its own: cg.1, cg.2, ...)
frame_instructions() {
  rm -rf "$OUT/cg"
  mkdir "$OUT/cg"
  valgrind -q --tool=callgrind --dump-after='*render_into*' --callgrind-out-file="$OUT/cg/cg" \
    $PRAY --quiet --threads 1 -D coherence=$2 -o "$OUT/cg/f###.ppm" "$1" > /dev/null 2>&1
  k=1
  while [ -f "$OUT/cg/cg.$k" ]; do
    awk '/^summary:/ {printf "%.1f\n", $2 / 1e6}' "$OUT/cg/cg.$k"
    k=$((k + 1))
  done
}

frame_cost() {
  if [ "$UNIT" = ms ]; then frame_times "$@"; else frame_instructions "$@"; fi
}

summary=""
for f in examples/roomball.ray examples/machine.ray examples/anim.ray "$OUT/roomall.ray"; do
  n=$(basename "$f" .ray)
  mkdir -p "$OUT/$n.0" "$OUT/$n.1"
  for c in 0 1; do
    $PRAY --quiet --stats --threads 1 -D coherence=$c -o "$OUT/$n.$c/f###.ppm" "$f" > /dev/null 2> "$OUT/$n.$c.txt"
  done
  for g in "$OUT/$n.0"/*.ppm; do cmp -s "$g" "$OUT/$n.1/$(basename "$g")" || { echo "coherence: $n: $(basename "$g") differs" >&2; exit 1; }; done
  frame_cost "$f" 0 > "$OUT/$n.t0"
  frame_cost "$f" 1 > "$OUT/$n.t1"
  awk '/^frame/ {print $(NF-2), $NF}' "$OUT/$n.1.txt" > "$OUT/$n.px"
  echo "$n: cost per frame ($UNIT), coherence=0 / coherence=1, and the pixels taken over"
  paste "$OUT/$n.t0" "$OUT/$n.t1" "$OUT/$n.px" | awk '{printf "  frame %d: %8.1f %8.1f  %5.1f %%\n", NR - 1, $1, $2, 100 * $3 / $4}'
  summary="$summary$(paste "$OUT/$n.t0" "$OUT/$n.t1" "$OUT/$n.px" | awk -v n=$n -v u="$UNIT" '
    NR > 2 {a += $1; b += $2; r += $3; p += $4; k++}
    NR <= 2 {a0 += $1; b0 += $2}
    END {printf "| %s | %d | %d | %.1f / %.1f %s | %.1f / %.1f %s | %.1fx | %.1f %% |\n", n, NR, $4, a0 / 2, b0 / 2, u, a / k, b / k, u, a / b, 100 * r / p}')
"
done
echo
echo "| animation | frames | pixels | first two frames, coherence=0 / 1 (a frame) | frames after them, coherence=0 / 1 (a frame) | faster | pixels taken over |"
echo "|---|---:|---:|---:|---:|---:|---:|"
printf "%s" "$summary"
