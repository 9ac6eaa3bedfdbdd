#!/bin/sh
# bench/coherence.sh - image sequences (option coherence, docs/acceleration.md): the time of a
# frame with and without it, on one thread, for animations where little moves and one where
# everything does. Prints a table for docs/benchmarks.md; never part of `make check`.
#
# A frame is recorded only when the frame before had the same camera, lights and options, so
# the first two frames are traced in full either way; the frames after them are what coherence
# is for. Their time is the CPU time (user + system) of the whole run less that of a run that
# renders only the first two (--frames 0:2, the program still runs in full), divided by their
# number: the interpreter and the writing of files are in both. Each run is made RUNS times
# (default 3) and the least time kept, so that other work on the machine counts as little as
# possible. Every frame is compared with coherence=0's, byte for byte.
# Usage: bench/coherence.sh [RUNS]
set -e
cd "$(dirname "$0")/.."
PRAY=./pray
[ -x $PRAY ] || make -s pray
RUNS=${1:-3}
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

# cpu FILE OPTIONS...: the least CPU seconds of RUNS runs
cpu() {
  f=$1
  shift
  best=
  i=0
  while [ $i -lt "$RUNS" ]; do
    /usr/bin/time -f '%U %S' -o "$OUT/t" $PRAY --quiet --threads 1 "$@" "$f" > /dev/null
    t=$(awk '{print $1 + $2}' "$OUT/t")
    if [ -z "$best" ]; then best=$t; else best=$(echo "$best $t" | awk '{print ($2 < $1) ? $2 : $1}'); fi
    i=$((i + 1))
  done
  echo "$best"
}

echo "| animation | frames | pixels | per frame after the second, coherence=0 | coherence=1 | faster | pixels reused |"
echo "|---|---:|---:|---:|---:|---:|---:|"
for f in examples/roomball.ray examples/machine.ray examples/anim.ray "$OUT/roomall.ray"; do
  n=$(basename "$f" .ray)
  mkdir -p "$OUT/$n.0" "$OUT/$n.1"
  for c in 0 1; do
    $PRAY --quiet --stats --threads 1 -D coherence=$c -o "$OUT/$n.$c/f###.ppm" "$f" > /dev/null 2> "$OUT/$n.$c.txt"
  done
  for g in "$OUT/$n.0"/*.ppm; do cmp -s "$g" "$OUT/$n.1/$(basename "$g")" || { echo "coherence: $n: $(basename "$g") differs" >&2; exit 1; }; done
  frames=$(ls "$OUT/$n.0" | wc -l)
  size=$(awk '/^frame/ {print $NF; exit}' "$OUT/$n.1.txt")
  reused=$(awk -v s="$size" -v n="$frames" '/^frame/ {k++; if (k > 2) r += $(NF-2)} END {printf "%.1f %%", 100 * r / (s * (n - 2))}' "$OUT/$n.1.txt")
  for c in 0 1; do
    all=$(cpu "$f" -D coherence=$c -o "$OUT/$n.$c/f###.ppm")
    two=$(cpu "$f" -D coherence=$c --frames 0:2 -o "$OUT/$n.$c/f###.ppm")
    eval "t$c=\$(echo $all $two $frames | awk '{printf \"%.4f\", (\$1 - \$2) / (\$3 - 2)}')"
  done
  echo "$n $frames $size $t0 $t1 $reused" | awk '{printf "| %s | %d | %d | %.1f ms | %.1f ms | %.2fx | %s %s |\n", $1, $2, $3, 1000 * $4, 1000 * $5, $4 / $5, $6, $7}'
done
