#!/bin/sh
# bench/suite/run.sh - the benchmark suite (make suite; docs/benchmarks.md, "The suite").
# Generates the suite's scenes (bench/suite/gen.py) into a temporary directory and renders each
# with ./pray and with POV-Ray 3.7, one thread, no anti-aliasing; the gallery (examples/*.ray)
# too, POV-Ray only where bench/pov/ has a twin; and with Tachyon the scenes that have an NFF
# twin. Prints a table of CPU times (user + system of the whole process, best of RUNS, default
# 1), the ratios POV-Ray / pray and Tachyon / pray with their geometric means, and pray's
# intersection tests per ray (all the intersection tests of its render, from --stats, divided by
# all the rays it traced: primary, shadow, reflected and refracted).
# Usage: bench/suite/run.sh [--size N] [--quick] [--compare REF] [--only PATTERN] [--instructions] [--chart PNG] [--scaling]
#   --size N        image size N x N (default 512)
#   --quick         size 64, no POV-Ray nor Tachyon; checks that every scene renders byte for byte the same
#                   with pray's default options and with --brute (exits 1 on any difference);
#                   scenes of over 20000 primitives at half the size, to keep --brute short
#   --compare REF   also time REF, another pray binary, and check it writes the same images
#   --only PATTERN  only the scenes whose names match the shell pattern (e.g. 'csg-*')
#   --instructions  count pray's instructions (millions, under valgrind's callgrind) instead of
#                   timing it, and leave POV-Ray and Tachyon out: exact figures for deciding small
#                   differences with --compare on a machine whose timings are noisy
#   --chart PNG     also draw the tests per ray against the primitives, scene by scene, into PNG
#                   (bench/suite/perray.py; docs/images/bench-perray.png)
#   --scaling       instead of the suite: time and peak memory against 10^3 to 10^6 balls, pray and
#                   POV-Ray (bench/suite/scaling.py), drawn into docs/images/bench-scaling-pov.png
# Installs povray and tachyon-bin-nox with apt-get when missing (not for --quick nor
# --instructions), and python3-matplotlib for --chart and --scaling; builds ./pray if needed.
set -e
usage() { sed -n 's/^# Usage: //p' "$0" >&2; exit 2; }
SIZE= QUICK= REF= ONLY='*' INSTR= SCALING= CHART=
while [ $# -gt 0 ]; do
  case $1 in
    --size) [ $# -ge 2 ] || usage; SIZE=$2; shift 2 ;;
    --quick) QUICK=1; shift ;;
    --compare) [ $# -ge 2 ] || usage; REF=$2; shift 2 ;;
    --only) [ $# -ge 2 ] || usage; ONLY=$2; shift 2 ;;
    --instructions) INSTR=1; shift ;;
    --chart) [ $# -ge 2 ] || usage; CHART=$2; shift 2 ;;
    --scaling) SCALING=1; shift ;;
    *) usage ;;
  esac
done
if [ -n "$REF" ]; then
  case $REF in /*) ;; *) REF=$(pwd)/$REF ;; esac
  [ -x "$REF" ] || { echo "run.sh: $REF is not an executable" >&2; exit 2; }
fi
case $CHART in ''|/*) ;; *) CHART=$(pwd)/$CHART ;; esac
[ -n "$SIZE" ] || { [ -n "$QUICK" ] && SIZE=64 || SIZE=512; }
case $SIZE in ''|*[!0-9]*|0*) usage ;; esac
RUNS=${RUNS:-1}
cd "$(dirname "$0")/../.."
PY=/usr/bin/python3
[ -x $PY ] || PY=python3

if [ -n "$INSTR" ] && ! command -v valgrind >/dev/null 2>&1; then
  echo "run.sh: --instructions needs valgrind (apt-get install valgrind)" >&2; exit 2
fi
missing=
if [ -z "$QUICK" ] && [ -z "$INSTR" ] && [ -z "$SCALING" ]; then
  command -v povray >/dev/null 2>&1 || missing=povray
  command -v tachyon >/dev/null 2>&1 || missing="$missing tachyon-bin-nox"
elif [ -n "$SCALING" ] && ! command -v povray >/dev/null 2>&1; then missing=povray; fi
if [ -n "$SCALING" ]; then
  [ -x /usr/bin/time ] || missing="$missing time"
fi
if [ -n "$SCALING$CHART" ] && ! $PY -c 'import matplotlib' 2>/dev/null; then
  missing="$missing python3-matplotlib"
fi
if [ -n "$missing" ]; then
  echo "installing:$missing" >&2
  if [ "$(id -u)" = 0 ]; then SUDO=; else SUDO=sudo; fi
  $SUDO apt-get update -qq
  # shellcheck disable=SC2086
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq $missing >/dev/null
fi
make -s pray textures >/dev/null
if [ -n "$SCALING" ]; then
  exec $PY bench/suite/scaling.py --size "$SIZE" --runs "$RUNS" --chart docs/images/bench-scaling-pov.png
fi
PRAY=$(pwd)/pray

OUT=$(mktemp -d)
trap 'rm -rf "$OUT"' EXIT
$PY bench/suite/gen.py "$OUT"
# POV-Ray reads and writes only where its I/O restrictions allow: it runs inside $OUT, with the
# twins' include files and a copy of the examples' textures (tex/, which some twins read)
cp bench/pov/*.inc "$OUT"
mkdir "$OUT/tex" && cp examples/tex/*.tif "$OUT/tex"
for f in examples/*.ray; do
  n=$(basename "$f" .ray)
  case $n in redsphx|maketex) continue ;; esac
  echo "gallery-$n -" >> "$OUT/scenes"
  if [ -f "bench/pov/$n.pov" ]; then cp "bench/pov/$n.pov" "$OUT/gallery-$n.pov"; fi
done
mkdir "$OUT/new" "$OUT/ref" "$OUT/brute"

H="$PY $(pwd)/bench/pov/helper.py"
program() {  # the PRAY program of scene $1 (the gallery's stay where their textures are)
  case $1 in gallery-*) echo "examples/${1#gallery-}.ray" ;; *) echo "$OUT/$1.ray" ;; esac
}
render() {   # render BINARY SCENE DIR [OPTIONS]: time it, "cpu wall" into $OUT/t (--instructions:
             # millions of instructions)
  b=$1; s=$2; d=$3; shift 3
  if [ -n "$INSTR" ]; then
    valgrind --tool=callgrind --callgrind-out-file="$OUT/cg" "$b" --quiet --stats --threads 1 \
      -D antialias=1 -s "${N}x$N" -o "$OUT/$d/$s.ppm" "$@" "$(program $s)" >"$OUT/t.out" 2>&1
    awk '/^summary:/ { printf "%.1f 0\n", $2 / 1e6 }' "$OUT/cg" > "$OUT/t"
    return
  fi
  $H time $RUNS "$OUT/t" "$b" --quiet --stats --threads 1 -D antialias=1 -s "${N}x$N" \
    -o "$OUT/$d/$s.ppm" "$@" "$(program $s)"
}
perray() {   # intersection tests per ray of the last render, from its --stats (in $OUT/t.out)
  awk '/^rays:/ { for (i = 2; i < NF; i++) if ($i ~ /^(primary|shadow|reflected|refracted)$/) {
                    v = $(i + 1); sub(/,$/, "", v); r += v } }
       /^intersection tests / { n += $3 }
       END { printf "%.1f", (r > 0 ? n / r : 0) }' "$OUT/t.out"
}
same() {     # same SCENE DIR1 DIR2: every frame of the scene identical in both directories
  for f in "$OUT/$2/$1.ppm" "$OUT/$2/$1"_[0-9]*.ppm; do
    [ -f "$f" ] || continue
    cmp -s "$f" "$OUT/$3/${f##*/}" || return 1
  done
}
secs() { cut -d' ' -f1 "$OUT/t"; }
ratio() { awk -v a="$1" -v b="$2" 'BEGIN { print (a > 0 && b > 0 ? a / b : 0) }'; }

if [ -n "$INSTR" ]; then
  echo "pray's instructions (millions, callgrind): ${SIZE}x$SIZE, one thread, no anti-aliasing"
  printf '%-18s %7s %8s %9s' scene prims pray tests/ray
elif [ -n "$QUICK" ]; then
  echo "pray's default against --brute: ${SIZE}x$SIZE (over 20000 primitives: half), one thread; CPU seconds"
  printf '%-18s %7s %8s %9s %8s' scene prims pray tests/ray brute
else
  echo "pray against POV-Ray $(povray --version 2>&1 | sed -n 's/^POV-Ray \([0-9.]*[0-9]\).*/\1/p') and Tachyon $(dpkg-query -W -f '${Version}' tachyon-bin-nox 2>/dev/null | sed 's/[~+].*//'): ${SIZE}x$SIZE, one thread, no anti-aliasing; CPU seconds (user + system), best of $RUNS"
  printf '%-18s %7s %8s %9s %8s %9s %8s %9s' scene prims pray tests/ray POV-Ray POV/pray Tachyon Tach/pray
fi
[ -n "$REF" ] && printf ' %8s %9s' REF pray/REF
echo
bad=0
while read -r s prims; do
  case $s in $ONLY) ;; *) continue ;; esac
  if [ "$prims" = - ]; then
    $PRAY --quiet --stats --threads 1 -s 8x8 -o "$OUT/stats.ppm" "$(program $s)" >/dev/null 2>"$OUT/stats"
    prims=$(awk '/^primitives:/ { print $2; exit }' "$OUT/stats")
  fi
  N=$SIZE
  if [ -n "$QUICK" ] && [ "$prims" -gt 20000 ]; then N=$((SIZE / 2)); fi
  render "$PRAY" $s new; t=$(secs)
  line=$(printf '%-18s %7s %8.3f %9s' $s "$prims" "$t" "$(perray)")
  if [ -n "$QUICK" ]; then
    render "$PRAY" $s brute --brute
    if same $s new brute; then c=""; else c="  DIFFERENT with --brute"; bad=1; fi
    line="$line $(printf '%8.3f' "$(secs)")"
  elif [ -n "$INSTR" ]; then
    :
  elif [ -f "$OUT/$s.pov" ]; then
    (cd "$OUT" && $H time $RUNS "$OUT/t" povray "+I$s.pov" "+O$s-pov.ppm" "+W$SIZE" "+H$SIZE" \
      -A +WT1 -D +FP File_Gamma=1.0)
    v=$(secs)
    line="$line $(printf '%8.3f %9.2f' "$v" "$(ratio "$v" "$t")")"
    echo "$v $t" >> "$OUT/ratios"
  else
    line="$line $(printf '%8s %9s' - -)"
  fi
  if [ -n "$QUICK$INSTR" ]; then
    :
  elif [ -f "$OUT/$s.nff" ]; then
    # Tachyon: one thread, no anti-aliasing, the ray depth of pray and POV-Ray (5)
    (cd "$OUT" && $H time $RUNS "$OUT/t" tachyon "$s.nff" -numthreads 1 -res "$SIZE" "$SIZE" \
      -raydepth 5 -aasamples 0 -format PPM -o "$s-tachyon.ppm")
    v=$(secs)
    line="$line $(printf '%8.3f %9.2f' "$v" "$(ratio "$v" "$t")")"
    echo "$v $t" >> "$OUT/tratios"
  else
    line="$line $(printf '%8s %9s' - -)"
  fi
  if [ -n "$REF" ]; then
    render "$REF" $s ref; r=$(secs)
    line="$line $(printf '%8.3f %9.2f' "$r" "$(ratio "$t" "$r")")"
    echo "$t $r" >> "$OUT/refratios"
    same $s new ref || { c="$c  DIFFERENT from REF"; bad=1; }
  fi
  echo "$line$c"
  echo "$line" >> "$OUT/table"
done < "$OUT/scenes"

geomean() {  # geomean FILE LABEL: the geometric mean of the ratios $1/$2 of the file's lines
  [ -f "$1" ] && awk -v l="$2" '$1 > 0 && $2 > 0 { s += log($1 / $2); n++ }
    END { printf "geometric mean of %s over %d scenes: %.2f\n", l, n, exp(s / n) }' "$1"
}
echo
geomean "$OUT/ratios" POV/pray || true
geomean "$OUT/tratios" Tachyon/pray || true
geomean "$OUT/refratios" pray/REF || true
if [ -n "$CHART" ] && [ -f "$OUT/table" ]; then
  $PY bench/suite/perray.py "$OUT/table" "$CHART" && echo "chart of tests per ray: $CHART"
fi
if [ $bad != 0 ]; then echo "FAILED: some images differ" >&2; exit 1; fi
