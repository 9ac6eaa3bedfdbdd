#!/bin/sh
# bench/run.sh - the acceleration benchmarks: the thesis' Table 3.6.1 rebuilt on our versions of
# its scenes, and a scaling run (time and memory against the number of primitives).
# Prints tables; never part of `make check`. Usage: bench/run.sh [quick]
set -e
cd "$(dirname "$0")/.."
PRAY=./pray
[ -x $PRAY ] || make -s pray
QUICK=${1:-}
SIZE=256x256
OUT=$(mktemp -d)
trap 'rm -rf "$OUT"' EXIT

# stat NAME FILE: a number from a --stats report
stat() {
  case $1 in
    prep)   awk '/^time:/ {print $6}' "$2" ;;
    render) awk '/^time:/ {print $9}' "$2" ;;
    tests)  awk '/^intersection tests/ {print $3}' "$2" ;;
    steps)  awk '/^traversal:/ {print $2}' "$2" ;;
    moves)  awk '/^traversal:/ {print $5}' "$2" ;;
    frozen) awk '/^actions:/ {gsub(/\)/,""); print $NF}' "$2" ;;
    grid)   awk '/^grid:/ {print $2 "x" $4 "x" $6}' "$2" ;;
    lists)  awk '/^grid:/ {print $10}' "$2" ;;
    areas)  awk '/^grid:/ {print $13}' "$2" ;;
    mem)    awk '/^grid:/ {printf "%.1f", $15 / 1048576}' "$2" ;;
    prims)  awk '/^primitives:/ {print $4}' "$2" ;;
  esac
}

run() {  # run FILE LABEL OPTIONS...: render and keep the --stats report
  f=$1; label=$2; shift 2
  $PRAY --quiet --stats --threads 1 -s $SIZE -o "$OUT/$label.ppm" "$@" "$f" > /dev/null 2> "$OUT/$label.txt"
}

echo "Table 3.6.1 rebuilt: $SIZE, one thread, times in seconds ($(uname -m), $(nproc) cores)"
echo
printf '%-8s %6s | %9s %9s %9s %9s %9s | %9s %9s %9s %9s %8s\n' scene prims prep grid+frz grid gridless+frz gridless brute tests:grid tests:none frozen lists
for s in cube room fractal; do
  f=examples/$s.ray
  [ -f $f ] || continue
  run $f g1 -D grid=-1 -D freeze=1
  run $f g0 -D grid=-1 -D freeze=0
  run $f n1 -D grid=0 -D freeze=1
  run $f n0 -D grid=0 -D freeze=0
  if [ -z "$QUICK" ]; then run $f b --brute; br=$(stat render $OUT/b.txt); else br=-; fi
  for k in g1 g0 n1 n0; do cmp -s $OUT/$k.ppm $OUT/g1.ppm || echo "warning: $s $k differs from grid+freeze"; done
  printf '%-8s %6s | %9s %9s %9s %9s %9s | %9s %9s %9s %9s %8s\n' $s "$(stat prims $OUT/g1.txt)" \
    "$(stat prep $OUT/g1.txt)" "$(stat render $OUT/g1.txt)" "$(stat render $OUT/g0.txt)" \
    "$(stat render $OUT/n1.txt)" "$(stat render $OUT/n0.txt)" "$br" \
    "$(stat tests $OUT/g1.txt)" "$(stat tests $OUT/n0.txt)" "$(stat frozen $OUT/g1.txt)" "$(stat lists $OUT/g1.txt)"
done

if [ -z "$QUICK" ]; then
  SIZE=512x512
  run examples/fractal.ray fg; run examples/fractal.ray fb --brute
  awk -v g="$(stat render $OUT/fg.txt)" -v b="$(stat render $OUT/fb.txt)" \
    'BEGIN { printf "\nfractal at 512x512: grid %.3f s, reference %.3f s: %.1f times faster\n", g, b, b / g }'
  SIZE=256x256
fi

echo
echo "Scaling: N random spheres minus a sphere and a cylinder, 128x128"
echo
SIZE=128x128  # the scaling run renders smaller images, so the reference finishes
printf '%7s | %9s %9s %10s %9s %8s | %9s %10s\n' N prep grid peakMiB structMiB grid brute bruteMiB
max=65536; [ -n "$QUICK" ] && max=4096
n=16
: > "$OUT/fit.txt"
while [ $n -le $max ]; do
  { echo "N = $n"; cat bench/spheres.ray; } > "$OUT/s.ray"
  /usr/bin/time -f '%M' -o "$OUT/mem" $PRAY --quiet --stats --threads 1 -s $SIZE -o "$OUT/s.ppm" "$OUT/s.ray" > /dev/null 2> "$OUT/g.txt"
  gt=$(stat render $OUT/g.txt)
  peak=$(awk '{printf "%.1f", $1 / 1024}' "$OUT/mem")
  if [ $n -le 4096 ] && [ -z "$QUICK" -o $n -le 1024 ]; then
    /usr/bin/time -f '%M' -o "$OUT/bmem" $PRAY --quiet --stats --threads 1 --brute -s $SIZE -o "$OUT/b.ppm" "$OUT/s.ray" > /dev/null 2> "$OUT/b.txt"
    bt=$(stat render $OUT/b.txt); bm=$(awk '{printf "%.1f", $1 / 1024}' "$OUT/bmem")
    cmp -s "$OUT/s.ppm" "$OUT/b.ppm" || echo "warning: N=$n grid and brute images differ"
  else bt=-; bm=-; fi
  printf '%7d | %9s %9s %10s %9s %8s | %9s %10s\n' $n "$(stat prep $OUT/g.txt)" "$gt" "$peak" "$(stat mem $OUT/g.txt)" "$(stat grid $OUT/g.txt)" "$bt" "$bm"
  echo "$n $gt" >> "$OUT/fit.txt"
  n=$((n * 4))
done
awk '$2 > 0 { x = log($1); y = log($2); n++; sx += x; sy += y; sxx += x*x; sxy += x*y }
     END { if (n > 1) printf "\nfitted exponent of grid render time against N: %.2f (1.00 would be linear)\n", (n*sxy - sx*sy) / (n*sxx - sx*sx) }' "$OUT/fit.txt"
