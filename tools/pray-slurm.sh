#!/bin/sh
# pray on a Slurm cluster: one image cut into bands of rows by a job array, joined by a second
# job; or a sequence of frames, one array task per frame (docs/distributed.md).
#
#   One image in 16 bands (the join runs when every band is done):
#     jid=$(sbatch --parsable --array=1-16 tools/pray-slurm.sh scene.ray scene.tif -s 4096x4096)
#     sbatch --dependency=afterok:$jid tools/pray-slurm.sh scene.ray scene.tif -s 4096x4096
#   A sequence of 240 frames, one task each (no join):
#     SPLIT=frames sbatch --array=0-239 tools/pray-slurm.sh anim.ray 'anim####.tif'
#
# Arguments: the program, the output file, then any options of pray (the same in every task).
# An array task (SLURM_ARRAY_TASK_ID set) renders its part:
#   SPLIT=rows (default): band K of N, K = SLURM_ARRAY_TASK_ID counted from the array's first
#     index (SLURM_ARRAY_TASK_MIN: --array=1-16 and --array=0-15 alike), N = PARTS or
#     SLURM_ARRAY_TASK_COUNT; written to OUT.parts/partK.tif (.ppm when OUT is a .ppm);
#   SPLIT=frames: frame K of the program (from 0), written where pray writes it.
# Without SLURM_ARRAY_TASK_ID (the second job) it joins OUT.parts/* into OUT and removes them;
# pray --join refuses parts that are missing, overlap or belong to another render.
# PRAY names the program (default: pray in the directory above this script's, else pray on the
# PATH; sbatch runs a copy of the script from its spool directory, so export PRAY or put pray on
# the PATH there).
# Each task asks for 4 CPUs (change --cpus-per-task, or give sbatch -c) and renders with as many
# threads as Slurm gave it (SLURM_CPUS_PER_TASK; pray would also count the CPUs it is bound to).
#SBATCH --job-name=pray
#SBATCH --ntasks=1
#SBATCH --cpus-per-task=4
#SBATCH --output=pray-%A_%a.log
set -eu
if [ $# -lt 2 ]; then
    echo "usage: pray-slurm.sh PROGRAM OUT [pray options...] (see the comment at its top)" >&2
    exit 2
fi
prog=$1
out=$2
shift 2
if [ -z "${PRAY:-}" ]; then
    here=$(cd "$(dirname "$0")/.." 2>/dev/null && pwd) || here=
    if [ -n "$here" ] && [ -x "$here/pray" ]; then PRAY=$here/pray; else PRAY=pray; fi
fi
case $out in *.ppm | *.PPM) ext=ppm ;; *) ext=tif ;; esac
parts=$out.parts

if [ -n "${SLURM_ARRAY_TASK_ID:-}" ]; then
    k=$SLURM_ARRAY_TASK_ID
    if [ "${SPLIT:-rows}" = frames ]; then
        exec "$PRAY" --quiet --threads "${SLURM_CPUS_PER_TASK:-0}" --frames "$k:$((k + 1))" -o "$out" "$@" "$prog"
    fi
    k=$((k - ${SLURM_ARRAY_TASK_MIN:-1} + 1))
    n=${PARTS:-${SLURM_ARRAY_TASK_COUNT:-}}
    if [ -z "$n" ]; then
        echo "pray-slurm.sh: set PARTS to the number of bands (Slurm sets SLURM_ARRAY_TASK_COUNT)" >&2
        exit 2
    fi
    mkdir -p "$parts"
    exec "$PRAY" --quiet --threads "${SLURM_CPUS_PER_TASK:-0}" --part "$k/$n" -o "$parts/part$k.$ext" "$@" "$prog"
fi

# the join
if [ ! -d "$parts" ]; then
    echo "pray-slurm.sh: no parts in $parts (run the array first)" >&2
    exit 3
fi
"$PRAY" --join "$out" "$parts"/part*."$ext"
rm -rf "$parts"
