#!/bin/sh
# One render spread over processes gives the bytes of one ./pray (docs/distributed.md):
#   - pray-mpi on 3 ranks (rows of one image; frames of a sequence; each forced both ways),
#   - --part K/N of every example stacked again by --join, and --frames,
#   - the GNU parallel recipe and the Slurm script tools/pray-slurm.sh (its tasks run here with
#     SLURM_ARRAY_TASK_ID set),
#   - failures: every rank stops, with the message of the rank that failed, nothing written,
#   - and signals: pray-mpi killed by SIGINT, SIGTERM, SIGHUP or SIGQUIT at points spread over a
#     run leaves no temporary file and never a part of the image.
# Every examples/*.ray but redsphx.ray (the thesis' program with its mistakes, an error by
# design) at SIZE pixels with antialias 2 and adaptive undersampling on.
#
#   sh tests/distributed.sh       (make check-mpi: builds ./pray and ./pray-mpi first)
# PRAY, PRAY_MPI, MPIRUN and SIZE may be set; MPIRUN's default runs 3 ranks, as root too; each
# run of it may take TIMEOUT seconds (300).
set -u
cd "$(dirname "$0")/.." || exit 2
: "${PRAY:=./pray}"
: "${PRAY_MPI:=./pray-mpi}"
: "${SIZE:=96x72}"
: "${MPIRUN:=mpirun --oversubscribe --allow-run-as-root -np 3}"
# a run that hangs fails the check instead of holding it
if command -v timeout >/dev/null 2>&1; then MPIRUN="timeout ${TIMEOUT:-300} $MPIRUN"; fi
# containers often forbid the cross-process memory copy of OpenMPI's shared-memory transport
: "${OMPI_MCA_btl_vader_single_copy_mechanism:=none}"
export OMPI_MCA_btl_vader_single_copy_mechanism
OPTS="-s $SIZE -D antialias=2 -D adaptive=0.1 --threads 1"
tmp=$(mktemp -d "${TMPDIR:-/tmp}/pray-dist.XXXXXX") || exit 2
trap 'rm -rf "$tmp"' EXIT
trap 'exit 130' INT TERM
pass=0
failn=0
ok() { pass=$((pass + 1)); }
bad() {
    failn=$((failn + 1))
    echo "FAIL $*"
}
# The files of directory $1 and $2 are the same files, byte for byte (and there are some).
same_dirs() {
    n=0
    for f in "$1"/*; do
        [ -f "$f" ] || continue
        n=$((n + 1))
        if ! cmp -s "$f" "$2/$(basename "$f")"; then
            echo "    $(basename "$f") differs" >&2
            return 1
        fi
    done
    [ "$n" -gt 0 ] && [ "$n" = "$(ls "$2" | wc -l)" ]
}
# Join the parts $1/part*_FRAME.tif (and $1/part*.tif for frame 0) of every frame of $2 into $3.
join_frames() {
    for w in "$2"/*; do
        b=$(basename "$w" .tif)
        suffix=${b#x}
        "$PRAY" --join "$3/x$suffix.tif" $(ls "$1"/part*.tif | grep "part[0-9]*$suffix\.tif$") || return 1
    done
}

echo "== pray-mpi, --part + --join and --frames on every example ($SIZE, antialias 2, adaptive)"
for ray in examples/*.ray; do
    name=$(basename "$ray" .ray)
    [ "$name" = redsphx ] && continue
    d=$tmp/$name
    mkdir -p "$d/one" "$d/mpi" "$d/parts" "$d/joined"
    if ! "$PRAY" -q $OPTS -o "$d/one/x.tif" "$ray" >/dev/null 2>"$d/err"; then
        bad "$name: ./pray failed: $(cat "$d/err")"
        continue
    fi
    if $MPIRUN "$PRAY_MPI" -q $OPTS -o "$d/mpi/x.tif" "$ray" >/dev/null 2>"$d/err" && same_dirs "$d/one" "$d/mpi"; then
        ok
    else
        bad "$name: pray-mpi on 3 ranks: $(cat "$d/err")"
    fi
    for k in 1 2 3; do "$PRAY" -q $OPTS --part "$k/3" -o "$d/parts/part$k.tif" "$ray" >/dev/null 2>&1; done
    if join_frames "$d/parts" "$d/one" "$d/joined" && same_dirs "$d/one" "$d/joined"; then
        ok
    else
        bad "$name: --part K/3 and --join"
    fi
    frames=$(ls "$d/one" | wc -l)
    echo "$name: $frames frame(s), the same bytes from pray-mpi and from --part + --join"
done

echo "== a sequence: examples/anim.ray, frames and rows over the ranks, --frames"
d=$tmp/anim
for split in rows frames; do
    rm -rf "$d/$split" && mkdir -p "$d/$split"
    if $MPIRUN "$PRAY_MPI" -q $OPTS --split $split -o "$d/$split/x.tif" examples/anim.ray >/dev/null 2>"$d/err" &&
        same_dirs "$d/one" "$d/$split"; then
        ok
    else
        bad "anim: pray-mpi --split $split: $(cat "$d/err")"
    fi
done
mkdir -p "$d/frames12"
"$PRAY" -q $OPTS --frames 1:3 -o "$d/frames12/x.tif" examples/anim.ray >/dev/null 2>&1
if [ "$(ls "$d/frames12")" = "$(printf 'x_0001.tif\nx_0002.tif')" ] &&
    cmp -s "$d/frames12/x_0001.tif" "$d/one/x_0001.tif" && cmp -s "$d/frames12/x_0002.tif" "$d/one/x_0002.tif"; then
    ok
else
    bad "anim: --frames 1:3 wrote $(ls "$d/frames12" | tr '\n' ' ')"
fi
for np in 1 2 4; do
    rm -rf "$d/np" && mkdir -p "$d/np"
    if ${MPIRUN%-np 3} -np $np "$PRAY_MPI" -q $OPTS -o "$d/np/x.tif" examples/anim.ray >/dev/null 2>"$d/err" &&
        same_dirs "$d/one" "$d/np"; then
        ok
    else
        bad "anim: pray-mpi on $np ranks: $(cat "$d/err")"
    fi
done

echo "== the GNU parallel recipe: 8 parts of examples/csg.ray, then --join"
d=$tmp/parallel
mkdir -p "$d"
if command -v parallel >/dev/null 2>&1; then
    "$PRAY" -q -s 256x256 -D antialias=2 -o "$d/whole.png" examples/csg.ray
    parallel "$PRAY" -q -s 256x256 -D antialias=2 --part {}/8 -o "$d/part{}.tif" examples/csg.ray ::: 1 2 3 4 5 6 7 8
    if "$PRAY" --join "$d/csg.png" "$d"/part*.tif && cmp -s "$d/whole.png" "$d/csg.png"; then
        ok
    else
        bad "GNU parallel: the joined PNG differs"
    fi
else
    bad "GNU parallel is not installed (make check-mpi installs it)"
fi

echo "== the Slurm script tools/pray-slurm.sh, its tasks run here"
d=$tmp/slurm
mkdir -p "$d"
"$PRAY" -q -s 128x96 -D adaptive=0.1 -o "$d/whole.ppm" examples/room.ray >/dev/null 2>&1
for k in 1 2 3 4 5; do
    SLURM_ARRAY_TASK_ID=$k SLURM_ARRAY_TASK_COUNT=5 PRAY=$PRAY sh tools/pray-slurm.sh examples/room.ray "$d/room.ppm" \
        -s 128x96 -D adaptive=0.1 >/dev/null 2>&1
done
if PRAY=$PRAY sh tools/pray-slurm.sh examples/room.ray "$d/room.ppm" >/dev/null && cmp -s "$d/whole.ppm" "$d/room.ppm" &&
    [ ! -e "$d/room.ppm.parts" ]; then
    ok
else
    bad "Slurm script: rows"
fi
for k in 0 1 2 3 4; do  # (an array counted from 0)
    SLURM_ARRAY_TASK_ID=$k SLURM_ARRAY_TASK_MIN=0 SLURM_ARRAY_TASK_COUNT=5 PRAY=$PRAY sh tools/pray-slurm.sh \
        examples/room.ray "$d/zero.ppm" -s 128x96 -D adaptive=0.1 >/dev/null 2>&1
done
if PRAY=$PRAY sh tools/pray-slurm.sh examples/room.ray "$d/zero.ppm" >/dev/null && cmp -s "$d/whole.ppm" "$d/zero.ppm"; then
    ok
else
    bad "Slurm script: rows of an array counted from 0"
fi
mkdir -p "$d/seq"
for k in 0 1 2; do
    SLURM_ARRAY_TASK_ID=$k SPLIT=frames PRAY=$PRAY sh tools/pray-slurm.sh examples/anim.ray "$d/seq/x.tif" $OPTS >/dev/null 2>&1
done
if same_dirs "$tmp/anim/one" "$d/seq"; then ok; else bad "Slurm script: frames"; fi

echo "== failures: every rank stops, with the failing rank's message; nothing is written"
d=$tmp/fail
mkdir -p "$d/out"
printf 'S = sphere(color({1}), [0, 0, 0], 0.5)\nrendertiff S, nothing_here\n' >"$d/bad.ray"
$MPIRUN "$PRAY_MPI" -q -s 8x8 -o "$d/out/x.tif" "$d/bad.ray" >/dev/null 2>"$d/err"
rc=$?
if [ $rc = 1 ] && [ "$(grep -c 'error:' "$d/err")" = 1 ] && grep -q "bad.ray:2:" "$d/err" && [ -z "$(ls "$d/out")" ]; then
    ok
else
    bad "an error in the program: exit $rc, $(cat "$d/err")"
fi
$MPIRUN "$PRAY_MPI" -q -s 8x8 -o "$d/out/x.tif" "$d/missing.ray" >/dev/null 2>"$d/err"
rc=$?
if [ $rc = 3 ] && [ "$(grep -c 'error:' "$d/err")" = 1 ] && [ -z "$(ls "$d/out")" ]; then
    ok
else
    bad "a missing program: exit $rc, $(cat "$d/err")"
fi
# the image is rendered on ranks 1 and 2; writing fails on rank 0 alone
$MPIRUN "$PRAY_MPI" -q -s 16x16 -o "$d/out/nodir/x.tif" examples/redsph.ray >/dev/null 2>"$d/err"
rc=$?
if [ $rc = 3 ] && [ "$(grep -c 'error:' "$d/err")" = 1 ] && grep -q "redsph.ray:9:1: error: cannot write" "$d/err" &&
    [ -z "$(ls "$d/out")" ]; then
    ok
else
    bad "a write that fails on rank 0: exit $rc, $(cat "$d/err")"
fi
# a render that fails on the ranks that render (over maxpixels), not in the first pass
"$PRAY" -q -s 16x16 -D maxpixels=100 -o "$d/out/y.tif" examples/redsph.ray 2>"$d/err1"
rc1=$?
$MPIRUN "$PRAY_MPI" -q -s 16x16 -D maxpixels=100 -o "$d/out/x.tif" examples/redsph.ray >/dev/null 2>"$d/err"
rc=$?
if [ $rc1 = 1 ] && [ $rc = 1 ] && grep -q "pray-mpi: rank [12]: .*over the limit" "$d/err" && [ -z "$(ls "$d/out")" ]; then
    ok
else
    bad "a render failing on a worker: exit $rc (pray: $rc1), $(cat "$d/err")"
fi

echo "== signals: SIGINT, SIGTERM, SIGHUP or SIGQUIT while rank 0 writes leave no temporary file"
d=$tmp/sig
mkdir -p "$d"
printf 'rendertiff nothing\n' >"$d/p.ray"
sig_run() { "$PRAY_MPI" -q -s 2000x2000 -D bits=16 -o "$d/out.ppm" "$d/p.ray" >/dev/null 2>&1; }
t0=$(date +%s%N)
sig_run
t1=$(date +%s%N)
rm -f "$d/out.ppm"
ms=$(((t1 - t0) / 1000000))
killed=0
for sig in INT TERM HUP QUIT; do
    for k in 1 2 3 4 5 6; do
        (ulimit -c 0; exec "$PRAY_MPI" -q -s 2000x2000 -D bits=16 -o "$d/out.ppm" "$d/p.ray") >/dev/null 2>&1 &
        pid=$!
        sleep "$(awk "BEGIN { print $ms * $k / 7000 }")"
        kill -$sig $pid 2>/dev/null
        wait $pid 2>/dev/null
        [ $? -gt 128 ] && killed=$((killed + 1))
        left=$(ls -A "$d" | grep '\.tmp$')
        if [ -n "$left" ]; then
            bad "SIG$sig at $k/7 of a run of $ms ms left $left"
            rm -f "$d"/.*.tmp
        elif [ -f "$d/out.ppm" ] && [ "$(wc -c <"$d/out.ppm")" != $((6 * 2000 * 2000 + 19)) ]; then
            bad "SIG$sig at $k/7 of a run of $ms ms left a part of the image"
        else
            ok
        fi
        rm -f "$d/out.ppm"
    done
done
[ $killed -gt 0 ] || bad "no run of $ms ms was killed by a signal"

echo "distributed: $pass passed, $failn failed"
[ $failn = 0 ]
