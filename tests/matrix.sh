#!/bin/sh
# make matrix: compile pray.cpp under every configuration macro and language level with warnings
# as errors, with each compiler there is (g++, clang++, or CXX): every macro, and every port's
# configuration, at the oldest level (C++98) and the newest the compiler knows (C++23 or C++2b);
# the levels between with the default configuration. JOBS compiles run at once (default: CPUs).
# Each line: compiler, level, macros, ok or FAILED (then the compiler's messages).
cd "$(dirname "$0")/.." || exit 2
OPT=${OPT:--O3 -fno-math-errno}
FLAGS="$OPT -Wall -Wextra -pedantic -Werror -fno-exceptions -fno-rtti"
JOBS=${JOBS:-$(getconf _NPROCESSORS_ONLN 2>/dev/null || echo 2)}

if [ "$1" = one ]; then  # one configuration: one "compiler|level|macros" line
    IFS='|' read -r cxx std defs <<LINE
$2
LINE
    log=$(eval "$cxx $std $FLAGS $defs -c pray.cpp -o /dev/null" 2>&1)
    st=$?
    if [ $st = 0 ]; then r=ok; else r=FAILED; fi
    printf '%-8s %-12s %-52s %s\n' "$cxx" "$std" "$defs" "$r"
    [ $st = 0 ] || { printf '%s\n' "$log" | head -30; exit 1; }
    exit 0
fi

DEFS='
-DPRAY_REAL=float
-DPRAY_NO_INTERP
-DPRAY_NO_STDIO
-DPRAY_NO_PNG
-DPRAY_NO_THREADS
-DPRAY_NO_BUFFERS
-DPRAY_NO_SEQUENCES
-DPRAY_NO_DEFAULT_ALLOC
-DPRAY_MAX_ALLOC=1000000
-DPRAY_MAIN
-DPRAY_MAIN -DPRAY_REAL=float'
for h in ports/*/prayconf.h; do DEFS="$DEFS
-DPRAY_MAIN -DPRAY_USER_CONFIG='\"$h\"'"; done

compilers=${CXX_LIST:-$(for c in g++ clang++; do command -v $c >/dev/null 2>&1 && echo $c; done)}
[ -n "$compilers" ] || { echo "matrix: no compiler (g++ or clang++)"; exit 2; }
configs() {
    for cxx in $compilers; do
        newest=
        for s in -std=c++23 -std=c++2b; do
            if echo | $cxx $s -x c++ -E - >/dev/null 2>&1; then newest=$s; break; fi
        done
        for s in -std=c++98 -std=c++11 -std=c++17 -std=c++20 $newest; do echo "$cxx|$s|"; done
        for s in -std=c++98 ${newest:--std=c++20}; do
            printf '%s\n' "$DEFS" | while IFS= read -r d; do [ -n "$d" ] && echo "$cxx|$s|$d"; done
        done
    done
}
n=$(configs | wc -l)
echo "matrix: $n configurations, $JOBS at a time"
configs | tr '\n' '\0' | xargs -0 -n 1 -P "$JOBS" sh tests/matrix.sh one
st=$?
# Flags that let the compiler assume there are no infinities or NaN are refused with the reason;
# -fno-fast-math after them is enough.
for cxx in $compilers; do
    for f in -ffast-math -ffinite-math-only -Ofast; do
        log=$($cxx -std=c++98 $f -c pray.cpp -o /dev/null 2>&1)
        if [ $? != 0 ] && printf '%s\n' "$log" | grep -q 'needs IEEE infinities and NaN'; then r=refused; else r="FAILED (not refused)"; st=1; fi
        printf '%-8s %-12s %-52s %s\n' "$cxx" "-std=c++98" "$f" "$r"
    done
    if $cxx -std=c++98 -ffast-math -fno-fast-math -c pray.cpp -o /dev/null; then r=ok; else r=FAILED; st=1; fi
    printf '%-8s %-12s %-52s %s\n' "$cxx" "-std=c++98" "-ffast-math -fno-fast-math" "$r"
done
# The layers that compile out render the bytes of the default build: the thesis' CSG.RAY and an
# image sequence (whose later frames coherence takes over in part), every frame compared.
cxx=$(printf '%s\n' $compilers | head -n 1)
tmp=$(mktemp -d "${TMPDIR:-/tmp}/pray-matrix.XXXXXX") || exit 2
for d in '' -DPRAY_NO_BUFFERS -DPRAY_NO_SEQUENCES; do
    dir=$tmp/x$d
    mkdir -p "$dir"
    if ! $cxx -std=c++98 $OPT $d -DPRAY_MAIN pray.cpp -o "$dir/pray" -lm -lpthread; then st=1; continue; fi
    for f in csg anim; do "$dir/pray" --quiet -s 96x72 -o "$dir/$f.ppm" examples/$f.ray >/dev/null || st=1; done
    [ -z "$d" ] && continue
    r=ok
    for f in "$tmp/x"/*.ppm; do cmp -s "$f" "$dir/$(basename "$f")" || r="FAILED ($(basename "$f") differs)"; done
    [ "$(ls "$tmp/x" | wc -l)" = "$(ls "$dir" | wc -l)" ] || r="FAILED (other frames)"
    printf '%-8s %-12s %-52s %s\n' "$cxx" "-std=c++98" "$d: csg.ray, anim.ray" "renders the same bytes: $r"
    [ "$r" = ok ] || st=1
done
# A build without PNG says why when asked for one.
if $cxx -std=c++98 $OPT -DPRAY_NO_PNG -DPRAY_MAIN pray.cpp -o "$tmp/nopng" -lm -lpthread; then
    msg=$("$tmp/nopng" -q -o "$tmp/x.png" examples/csg.ray 2>&1)
    want="pray: error: option 'output': '$tmp/x.png': this pray writes no PNG: it was built with PRAY_NO_PNG; use .tif or .ppm"
    if [ "$msg" = "$want" ] && [ ! -e "$tmp/x.png" ]; then r=ok; else r="FAILED ($msg)"; st=1; fi
else
    r=FAILED
    st=1
fi
printf '%-8s %-12s %-52s %s\n' "$cxx" "-std=c++98" "-DPRAY_NO_PNG: -o x.png" "says why: $r"
rm -rf "$tmp"
[ $st = 0 ] && echo "matrix: all $n compiled without a warning" || echo "matrix: FAILED"
exit $st
