#!/usr/bin/env bash
# Render a list of frames on a Slurm cluster, one whole frame per task of one array job.
# What `just slurm-frames` runs after converting and compiling the scenes.
#
#   scripts/slurm/frames.sh FRAMES [kd2exr options…]
#
# FRAMES lists one frame per line, four tab-separated fields: SOUP KD OUT.exr OUT.png
# (scripts/slurm/frame.sbatch). The kd2exr options apply to every frame. Logs go to
# logs/frame-I.log beside FRAMES (I counts lines from 0); a frame that fails twice is named with
# its log and the script exits 1. Environment as for render.sh: KD2EXR, CPUS_PER_TASK,
# PARTITION, TIME_LIMIT, SBATCH_ARGS, POLL_SECONDS.
set -euo pipefail

here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
die() {
    echo "slurm: error: $*" >&2
    exit 1
}
[ $# -ge 1 ] || die "usage: $0 FRAMES [kd2exr options…]"
frames=$(realpath "$1")
shift
[ -s "$frames" ] || die "no frames listed in $frames"
for a in "$@"; do
    case $a in
    --crop* | -o | --output* | --preview* | --threads* | --json)
        die "$a is set per frame by the cluster render; leave it out" ;;
    esac
done
if [ -z "${KD2EXR:-}" ]; then
    KD2EXR=$here/../../target/release/kd2exr
    [ -x "$KD2EXR" ] || KD2EXR=$(command -v kd2exr) ||
        die "no kd2exr: build it (just build) or set KD2EXR"
fi
KD2EXR=$(realpath "$KD2EXR")
export KD2EXR

# Every line is checked before any output is cleared: `cut` passes a line without tabs
# through whole, and the outputs are deleted before the frames render.
bad=$(awk -F'\t' 'NF != 4 || $1 == "" || $2 == "" || $3 !~ /\.exr$/ || $4 !~ /\.png$/ {
    print NR; exit }' "$frames")
[ -z "$bad" ] || die "$frames:$bad: a frame is four tab-separated fields: SOUP KD OUT.exr OUT.png"
mapfile -t exrs < <(cut -f3 "$frames")
KIND=frame
LOGDIR=$(dirname "$frames")/logs
output_of() { echo "${exrs[$1]}"; }
# shellcheck source=scripts/slurm/array.sh
source "$here/array.sh"

rm -f "${exrs[@]}" "$LOGDIR"/frame-*.log
start=$(date +%s.%N)
run_array "${#exrs[@]}" "$here/frame.sbatch" "$frames" "$@"
awk -v s="$start" -v f="$(date +%s.%N)" -v n="${#exrs[@]}" \
    'BEGIN { printf "slurm: %d frames rendered in %.2f s\n", n, f - s }' >&2
printf '%s\n' "${exrs[@]}"
