#!/bin/sh
# The catalogue of bad inputs: run ./pray on every tests/bad/NNN-name.ray and compare its standard
# error and exit status with NNN-name.err exactly (first line: the exit status; the rest: the
# expected standard error). A failed run must leave no file behind.
#
#   tests/bad/run.sh                  all cases, with ./pray
#   PRAY=path/to/pray tests/bad/run.sh   another build of the program (make sanitize does this)
#   tests/bad/run.sh 012 cont         only the cases whose names contain one of the words
#   BLESS=1 tests/bad/run.sh ...      write NNN-name.err for cases that have none, from what pray
#                                     does now (never overwrites; read every new file before
#                                     committing it: a wrong message is a defect, not a result)
#
# Each case runs in an empty temporary directory holding only a copy of its .ray file (and of its
# files NNN-name.*.inc, which it may include), with that file on standard input and the arguments
# `-s 8x8 -o out.ppm NNN-name.ray`, or those of NNN-name.args (one line of words; @RAY@ stands
# for the case's file name). Messages therefore name the file as `NNN-name.ray`. Standard output
# is ignored.
# Needs only a POSIX shell; `timeout` is used when present (a case may take TIMEOUT seconds).

here=$(cd "$(dirname "$0")" && pwd)
: "${PRAY:=$here/../../pray}"
case $PRAY in /*) ;; *) PRAY=$(pwd)/$PRAY ;; esac
: "${TIMEOUT:=60}"
if [ ! -x "$PRAY" ]; then
    echo "run.sh: no program at $PRAY (make pray, or set PRAY=...)" >&2
    exit 2
fi
limit=
if command -v timeout >/dev/null 2>&1; then limit="timeout $TIMEOUT"; fi

tmp=$(mktemp -d "${TMPDIR:-/tmp}/pray-bad.XXXXXX") || exit 2
trap 'rm -rf "$tmp"' EXIT
trap 'exit 130' INT TERM

pass=0
failn=0
failed=
cd "$here" || exit 2
for ray in [0-9]*.ray; do
    case=${ray%.ray}
    if [ $# -gt 0 ]; then
        want=0
        for w in "$@"; do case $case in *"$w"*) want=1 ;; esac; done
        [ $want = 1 ] || continue
    fi
    err=$here/$case.err
    if [ -f "$here/$case.args" ]; then
        args=$(sed "s|@RAY@|$ray|g" "$here/$case.args")
    else
        args="-s 8x8 -o out.ppm $ray"
    fi
    rm -rf "$tmp/run"
    mkdir "$tmp/run"
    cp "$here/$ray" "$tmp/run/$ray"
    for inc in "$here/$case".*.inc; do
        [ -f "$inc" ] && cp "$inc" "$tmp/run/"
    done
    # The arguments are plain words: split them, without globbing.
    set -f
    (cd "$tmp/run" && $limit "$PRAY" $args <"$ray" >/dev/null 2>"$tmp/stderr")
    rc=$?
    set +f
    if [ ! -f "$err" ]; then
        if [ -n "$BLESS" ]; then
            { echo "$rc"; cat "$tmp/stderr"; } >"$err"
            echo "blessed $case: exit $rc"
            sed 's/^/    /' "$tmp/stderr"
        else
            echo "FAIL $case: no $case.err"
            failn=$((failn + 1))
            failed="$failed $case"
        fi
        continue
    fi
    why=
    exp_rc=$(sed -n 1p "$err")
    sed 1d "$err" >"$tmp/expected"
    if [ "$rc" != "$exp_rc" ]; then
        why="exit status $rc, expected $exp_rc"
        [ "$rc" = 124 ] && [ -n "$limit" ] && why="$why (timed out after $TIMEOUT s)"
    fi
    if ! cmp -s "$tmp/expected" "$tmp/stderr"; then
        why="${why:+$why; }standard error differs"
    fi
    if [ "$exp_rc" != 0 ]; then
        left=$(cd "$tmp/run" && ls -A | grep -v -x -F "$ray" | grep -v -x "$case\..*\.inc")
        [ -n "$left" ] && why="${why:+$why; }left files behind: $(echo $left)"
    fi
    if [ -z "$why" ]; then
        pass=$((pass + 1))
    else
        failn=$((failn + 1))
        failed="$failed $case"
        echo "FAIL $case: $why"
        if ! cmp -s "$tmp/expected" "$tmp/stderr"; then
            echo "  expected:"
            sed 's/^/    /' "$tmp/expected" | cut -c1-300
            echo "  actual:"
            sed 's/^/    /' "$tmp/stderr" | cut -c1-300
        fi
    fi
done
[ -n "$failed" ] && echo "failed:$failed"
echo "$pass passed, $failn failed"
[ "$failn" = 0 ]
