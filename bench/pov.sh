#!/bin/sh
# bench/pov.sh - pray against POV-Ray 3.7: the Cube, Room, Fractal, CSG and Chess scenes rendered by
# both programs (bench/pov/*.pov are the POV-Ray versions), one thread, no anti-aliasing, at
# 256x256 and 1024x1024. Prints a table of CPU and wall times and their ratios, then the share
# of pixels where the two disagree about which object is visible (both rendered with flat
# colours; bench/pov/helper.py makes pray's flat copy and compares). docs/povray.md explains.
# Usage: bench/pov.sh [quick]     quick: 256x256 only, one run each
# RUNS=n sets how many times each timed render is repeated (the best is kept; default 3, quick 1).
# Installs povray (and Python's PIL) with apt-get when missing; builds ./pray if needed.
# Everything it writes goes to a temporary directory, removed at the end.
set -e
cd "$(dirname "$0")/.."
QUICK=${1:-}
case $QUICK in
  ''|quick) ;;
  *) echo "usage: bench/pov.sh [quick]" >&2; exit 2 ;;
esac
if [ "$QUICK" = quick ]; then SIZES=256; RUNS=${RUNS:-1}; else SIZES="256 1024"; RUNS=${RUNS:-3}; fi
SCENES="cube room fractal csg chess"
PY=/usr/bin/python3
[ -x $PY ] || PY=python3

missing=""
command -v povray >/dev/null 2>&1 || missing="$missing povray"
$PY -c 'import PIL' 2>/dev/null || missing="$missing python3-pil"
if [ -n "$missing" ]; then
  echo "installing:$missing" >&2
  if [ "$(id -u)" = 0 ]; then SUDO=; else SUDO=sudo; fi
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq $missing >/dev/null
fi
make -s pray
PRAY=$(pwd)/pray

OUT=$(mktemp -d)
trap 'rm -rf "$OUT"' EXIT
# POV-Ray reads and writes only where its I/O restrictions allow (the current directory, /tmp):
# it runs inside the temporary directory, on copies of the scene files.
cp bench/pov/*.pov bench/pov/pray.inc "$OUT"

H="$PY $(pwd)/bench/pov/helper.py"
pray_render() {  # pray_render PROGRAM SIZE OUTPUT: time it, "cpu wall" into $OUT/t
  $H time $RUNS "$OUT/t" "$PRAY" --quiet --threads 1 -D antialias=1 -s "$2x$2" -o "$3" "$1"
}
pov_render() {   # pov_render SCENE SIZE OUTPUT [Declare=...]: the same for POV-Ray
  s=$1; n=$2; o=$3; shift 3
  (cd "$OUT" && $H time $RUNS "$OUT/t" povray "+I$s.pov" "+O$o" "+W$n" "+H$n" -A +WT1 -D +FP \
    File_Gamma=1.0 "$@")
}

echo "pray against POV-Ray ($(povray --version 2>&1 | sed -n 's/^POV-Ray \([0-9.]*[0-9]\).*/\1/p')): one thread, no anti-aliasing; $(uname -m), $(nproc) cores"
echo "times in seconds: CPU (user + system) and wall clock of the whole process, best of $RUNS"
echo
printf '%-8s %5s | %8s %8s | %8s %8s | %8s %8s | %s\n' scene size "pray cpu" wall "POV cpu" wall "ratio" "(wall)" target
for n in $SIZES; do
  for s in $SCENES; do
    pray_render "examples/$s.ray" $n "$OUT/$s-$n-pray.ppm"; read pc pw < "$OUT/t"
    pov_render $s $n "$s-$n-pov.ppm"; read vc vw < "$OUT/t"
    target=""
    if [ $n = 1024 ]; then
      want=5; [ $s = cube ] && want=50
      target=$(awk -v r="$(awk -v a=$vc -v b=$pc 'BEGIN { print (b > 0 ? a / b : 0) }')" -v w=$want \
        'BEGIN { printf "%s %dx", (r >= w ? "met" : "NOT met"), w }')
    fi
    awk -v s=$s -v n=$n -v pc=$pc -v pw=$pw -v vc=$vc -v vw=$vw -v t="$target" 'BEGIN {
      printf "%-8s %5d | %8.3f %8.3f | %8.3f %8.3f | %7.1fx %7.1fx | %s\n", s, n, pc, pw, vc, vw,
        (pc > 0 ? vc / pc : 0), (pw > 0 ? vw / pw : 0), t }'
  done
done

echo
echo "flat colours: pixels where pray and POV-Ray see different objects (or one of them sees the"
echo "background); control: the same with POV-Ray's camera half a pixel off, at 256 only"
echo
printf '%-8s %5s | %9s %9s %8s | %s\n' scene size differing of share control
RUNS=1
for n in $SIZES; do
  for s in $SCENES; do
    [ $n = ${SIZES%% *} ] && $H flat "examples/$s.ray" "bench/pov/$s.pov" > "$OUT/$s-flat.ray"
    pray_render "$OUT/$s-flat.ray" $n "$OUT/$s-$n-flat-pray.ppm"
    pov_render $s $n "$s-$n-flat-pov.ppm" Declare=Flat=1
    $H compare "$OUT/$s-$n-flat-pray.ppm" "$OUT/$s-$n-flat-pov.ppm" > "$OUT/cmp"
    control=""
    if [ $n = 256 ]; then
      pov_render $s $n "$s-$n-nudge-pov.ppm" Declare=Flat=1 Declare=Nudge=0.5
      control=$($H compare "$OUT/$s-$n-flat-pray.ppm" "$OUT/$s-$n-nudge-pov.ppm" | awk '{ printf "%d (%s %%)", $1, substr($6, 2) }')
    fi
    awk -v s=$s -v n=$n -v c="$control" '{ printf "%-8s %5d | %9d %9d %6.3f %% | %s\n", s, n, $1, $3, 100 * $1 / $3, c }' "$OUT/cmp"
  done
done
