#!/bin/sh
# The doctest part of `make test`: the quick test programs of build/quick/ (the test files built
# without optimisation; in pray_tests the library comes with test_internal.cpp) run in passes,
# each of which must run test cases and pass them all:
#   1. pray_tests: every test case of its files but test_accel.cpp, less the few that take
#      seconds (SLOW);
#   2. pray_tests: a light choice from test_accel.cpp (ACCEL): the acceleration against the
#      reference on degenerate trees and on a floor with solids, the eye's buffer, freezing,
#      threads and the statistics;
#   3. pray_tests_float: its test cases, the renderer in single precision (PRAY_REAL=float);
#   4. pray_tests_nostdio: test_buffers.cpp in a build without file access (PRAY_NO_STDIO).
# A filter that matches nothing would make a pass that cannot fail, so each pass must run at
# least a given number of test cases, and every pattern of ACCEL must name one.
#
#   sh tests/quick.sh [DIR]     the programs in DIR (build/quick); RUN is put before each one

dir=${1:-build/quick}
RUN=${RUN:-}
SLOW='reach: every voxel*,command line: SIGINT*,the N-th allocation fails*,limit maxtime*'
ACCEL='accel hits: degenerate roots*,accel hits: an unbounded floor*,accel eye buffer*,accel freezing*,accel threads*,accel stats*'

tmp=$(mktemp "${TMPDIR:-/tmp}/pray-quick.XXXXXX") || exit 2
trap 'rm -f "$tmp"' EXIT
trap 'exit 130' INT TERM

# count FILTER...: the test cases of $prog the filters select
count() {
    $RUN "$prog" --count "$@" 2>&1 | sed -n 's/.*passing the current filters: *\([0-9][0-9]*\).*/\1/p'
}

# pass LABEL MIN FILTER...: run the selection of $prog; at least MIN cases, all passed
pass() {
    label=$1
    min=$2
    shift 2
    n=$(count "$@")
    if [ -z "$n" ] || [ "$n" -lt "$min" ]; then
        echo "quick.sh: $label selects ${n:-no} test cases, fewer than $min: a filter no longer matches" >&2
        exit 1
    fi
    echo "== quick tests, $label ($n test cases)"
    $RUN "$prog" "$@" >"$tmp" 2>&1
    rc=$?
    if [ $rc != 0 ]; then
        cat "$tmp"
        echo "quick.sh: $label failed (exit status $rc)" >&2
        exit 1
    fi
    tail -n 1 "$tmp"
}

prog=$dir/pray_tests
pass "all but the acceleration" 250 -sfe='*test_accel.cpp' -tce="$SLOW"
# each pattern of ACCEL on its own must name a test case
old_ifs=$IFS
IFS=,
for p in $ACCEL; do
    IFS=$old_ifs
    n=$(count -sf='*test_accel.cpp' -tc="$p")
    if [ -z "$n" ] || [ "$n" -lt 1 ]; then
        echo "quick.sh: no test case of test_accel.cpp is named '$p'" >&2
        exit 1
    fi
done
IFS=$old_ifs
pass "acceleration" 6 -sf='*test_accel.cpp' -tc="$ACCEL"
prog=$dir/pray_tests_float
pass "PRAY_REAL=float" 25
prog=$dir/pray_tests_nostdio
pass "without file access (PRAY_NO_STDIO)" 5
