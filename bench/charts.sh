#!/bin/sh
# bench/charts.sh - the speed-against-accuracy charts and the acceleration benchmarks drawn
# (docs/benchmarks.md, docs/images/bench-*.png). Run by `make charts` (POSIX sh).
# Installs python3-matplotlib and time when they are missing (Debian/Ubuntu), builds ./pray and the
# single-precision build/pray_float, then bench/charts.py renders, measures, prints the tables
# and draws the charts. The 16 x 16 references are cached in build/charts/ref/.
# Usage: bench/charts.sh [quick | plot | threads]
#   quick    a short check of the script: three scenes, small images, charts in build/charts/quick/
#   plot     redraw the charts and reprint the tables from build/charts/results.json
#   threads  measure one thread against two again (when the machine is quiet) and redraw
set -e
cd "$(dirname "$0")/.."
PY=${PYTHON:-python3}
[ -x /usr/bin/python3 ] && [ -z "$PYTHON" ] && PY=/usr/bin/python3
CXX=${CXX:-c++}

missing=
$PY -c 'import matplotlib, numpy, PIL' 2>/dev/null || missing="python3-matplotlib python3-numpy python3-pil"
[ -x /usr/bin/time ] || missing="$missing time"   # the peak memory of the scaling run
if [ -n "$missing" ]; then
  echo "charts: installing $missing" >&2
  if [ "$(id -u)" = 0 ]; then SUDO=; else SUDO=sudo; fi
  $SUDO apt-get update -qq
  # shellcheck disable=SC2086
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq $missing >/dev/null
fi

case ${1:-} in
  plot) exec $PY bench/charts.py --plot ;;
  threads) make -s pray; exec $PY bench/charts.py --threads ;;
  quick) ARGS=--quick ;;
  '') ARGS= ;;
  *) echo "usage: bench/charts.sh [quick | plot | threads]" >&2; exit 2 ;;
esac

make -s pray
[ -f examples/tex/font.tif ] || make -s textures
mkdir -p build/charts
# the single-precision build, the same flags as the Makefile's pray rule
if [ ! -x build/pray_float ] || [ -n "$(find pray.cpp pray.hpp -newer build/pray_float)" ]; then
  echo "charts: building build/pray_float (PRAY_REAL=float)" >&2
  $CXX -std=c++98 -O3 -fno-math-errno -Wall -Wextra -pedantic -fno-exceptions -fno-rtti -DPRAY_REAL=float -DPRAY_MAIN \
    pray.cpp -o build/pray_float -lm
fi
# shellcheck disable=SC2086
PRAY=./pray PRAY_FLOAT=build/pray_float $PY bench/charts.py $ARGS
