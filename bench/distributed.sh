#!/bin/sh
# bench/distributed.sh - one render spread over processes (docs/distributed.md): wall-clock
# time of one image against the number of processes, for threads of one pray, --part K/N bands
# run by GNU parallel and joined, and pray-mpi.
# Every way's file is compared with the single process's (cmp). Prints a table: wall-clock
# seconds and the CPU seconds of all the processes of each way.
#   bench/distributed.sh [SCENE [SIZE [ANTIALIAS]]]   default examples/room.ray 1024x1024 2
# Needs ./pray, ./pray-mpi (make mpi) and GNU parallel. Best of REPEAT runs (default 2).
# bench/distributed.py draws the table and the cost model for many nodes from this output.
set -e
cd "$(dirname "$0")/.."
SCENE=${1:-examples/room.ray}
SIZE=${2:-1024x1024}
AA=${3:-2}
REPEAT=${REPEAT:-2}
MPIRUN=${MPIRUN:-mpirun --oversubscribe --allow-run-as-root}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
opts="-q -s $SIZE -D antialias=$AA"

# best COMMAND...: "WALL CPU" of the run with the least wall-clock seconds of REPEAT runs (CPU:
# user and system seconds of every process it started)
best() {
    b=
    i=0
    while [ $i -lt "$REPEAT" ]; do
        /usr/bin/time -f "%e %U %S" -o "$tmp/time" sh -c "$*" >/dev/null 2>&1 || { echo "failed: $*" >&2; exit 1; }
        t=$(awk '{print $1, $2 + $3}' "$tmp/time")
        if [ -z "$b" ] || [ "$(echo "${t% *} < ${b% *}" | bc)" = 1 ]; then b=$t; fi
        i=$((i + 1))
    done
    echo "$b"
}
row() {  # way, processes, "wall cpu", file to compare
    same=same
    cmp -s "$4" "$tmp/one.tif" || same=DIFFERENT
    set -- "$1" "$2" ${3% *} ${3#* } "$4"
    printf '| %-38s | %2s | %6.2f | %5.2f | %6.2f | %s |\n' "$1" "$2" "$3" "$(awk "BEGIN { print ($3 > 0 ? $base / $3 : 0) }")" "$4" "$same"
}

echo "$SCENE at $SIZE, antialias $AA; $(nproc) processors, load average $(cut -d' ' -f1-3 /proc/loadavg); best of $REPEAT"
echo
echo "| how | processes | wall s | speed-up | CPU s | bytes |"
echo "|---|---:|---:|---:|---:|---|"
one=$(best ./pray $opts --threads 1 -o "$tmp/one.tif" "$SCENE")
base=${one% *}
row "pray, 1 thread" 1 "$one" "$tmp/one.tif"
t=$(best ./pray $opts --threads 2 -o "$tmp/t2.tif" "$SCENE")
row "pray, 2 threads" 1 "$t" "$tmp/t2.tif"
for n in 2 4 8; do
    t=$(best "rm -f $tmp/p*.tif; parallel -j 2 ./pray $opts --threads 1 --part {}/$n -o $tmp/p{}.tif $SCENE ::: \$(seq $n) && ./pray --join $tmp/par$n.tif $tmp/p*.tif")
    row "GNU parallel -j 2, --part K/$n, join" "$n" "$t" "$tmp/par$n.tif"
done
for np in 2 3 5; do
    t=$(best $MPIRUN -np $np ./pray-mpi $opts --threads 1 -o "$tmp/mpi$np.tif" "$SCENE")
    row "pray-mpi, rank 0 + $((np - 1)) worker(s)" "$np" "$t" "$tmp/mpi$np.tif"
done
echo
# the parts of one thread's time that every process pays again (docs/distributed.md)
./pray $opts --threads 1 --stats -o "$tmp/stats.tif" "$SCENE" 2>&1 | sed -n 's/^time: /pray --stats, one thread: /p'
echo "load average after: $(cut -d' ' -f1-3 /proc/loadavg)"
