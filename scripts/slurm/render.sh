#!/usr/bin/env bash
# Render one frame on a Slurm cluster as TILES crop tiles of one array job, then merge
# them bit for bit into OUT.exr and a PNG preview OUT.png. What `just slurm` runs after
# converting and compiling the scene.
#
#   scripts/slurm/render.sh SOUP KD OUT.exr TILES [kd2exr options…]
#
# The tiles are TILES equal row bands (scripts/slurm/tile.sbatch). Slurm hands each free
# CPU slot the next tile, so with several times more tiles than slots an expensive band
# (a mirror, many lights) delays one slot briefly instead of the whole frame. They are
# written to OUT.tiles/tile-NNNN.exr, their logs to OUT.tiles/logs/. A failed tile is
# resubmitted once; one that fails twice is named with its log and the script exits 1.
# `kd2exr merge` refuses tiles of another soup, tree, settings or window.
#
# Run it on a machine that submits to the cluster, with SOUP, KD, OUT and the kd2exr binary
# on a filesystem every node mounts. Environment: KD2EXR (default: target/release/kd2exr
# of this repository, else kd2exr on PATH), CPUS_PER_TASK (default 1), PARTITION,
# TIME_LIMIT, SBATCH_ARGS, POLL_SECONDS (scripts/slurm/array.sh).
set -euo pipefail

here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
die() {
    echo "slurm: error: $*" >&2
    exit 1
}
[ $# -ge 4 ] || die "usage: $0 SOUP KD OUT.exr TILES [kd2exr options…]"
soup=$(realpath "$1") kd=$(realpath "$2") out=$(realpath -m "$3") tiles=$4
shift 4
[ -f "$soup" ] || die "no soup at $soup"
[ -f "$kd" ] || die "no k-d tree at $kd"
[[ $out == *.exr ]] || die "the output $out must end in .exr"
[[ $tiles =~ ^[1-9][0-9]*$ ]] || die "TILES must be a positive number of tiles, not '$tiles'"
if [ -z "${KD2EXR:-}" ]; then
    KD2EXR=$here/../../target/release/kd2exr
    [ -x "$KD2EXR" ] || KD2EXR=$(command -v kd2exr) ||
        die "no kd2exr: build it (just build) or set KD2EXR"
fi
KD2EXR=$(realpath "$KD2EXR")
export KD2EXR

# The tiles need the frame size for their bands, and merge needs the preview exposure;
# everything else passes through to every tile unchanged.
# (clap puts an option's default on its own line or after its text: read the help as one line.)
default_of() {
    "$KD2EXR" --help | tr '\n' ' ' | sed -n "s/.*--$1 <[A-Z_]*>[^[]*\[default: \([^]]*\)\].*/\1/p"
}
width=$(default_of width) height=$(default_of height)
args=() merge_args=()
while [ $# -gt 0 ]; do
    case $1 in
    --width) width=${2:?--width needs a value} && shift ;;
    --width=*) width=${1#*=} ;;
    --height) height=${2:?--height needs a value} && shift ;;
    --height=*) height=${1#*=} ;;
    --exposure) merge_args+=(--exposure "${2:?--exposure needs a value}") && shift ;;
    --exposure=*) merge_args+=("$1") ;;
    --crop* | -o | --output* | --preview* | --threads* | --json)
        die "$1 is set per tile by the cluster render; leave it out" ;;
    *) args+=("$1") ;;
    esac
    shift
done
[[ $width =~ ^[0-9]+$ && $height =~ ^[0-9]+$ ]] || die "cannot tell the frame size ($width×$height)"
# Shell arithmetic reads a leading zero as octal: 0768 would be an error, 0100 would be 64.
width=$((10#$width)) height=$((10#$height))
[ "$tiles" -le "$height" ] || die "$tiles tiles of a $height-row frame would leave some empty"

base=${out%.exr}
tiledir=$base.tiles
KIND=tile
LOGDIR=$tiledir/logs
output_of() { printf '%s/tile-%04d.exr' "$tiledir" "$1"; }
# shellcheck source=scripts/slurm/array.sh
source "$here/array.sh"

mkdir -p "$tiledir"
# Tiles of an earlier run must not stand in for tiles that fail now.
rm -f "$tiledir"/tile-*.exr "$LOGDIR"/tile-*.log
start=$(date +%s.%N)
run_array "$tiles" "$here/tile.sbatch" "$soup" "$kd" "$tiledir" "$tiles" "$width" "$height" \
    "${args[@]}"
rendered=$(date +%s.%N)
parts=()
for i in $(seq 0 $((tiles - 1))); do parts+=("$(output_of "$i")"); done
"$KD2EXR" merge "${parts[@]}" -o "$out" --preview "$base.png" "${merge_args[@]}"
finished=$(date +%s.%N)
awk -v s="$start" -v r="$rendered" -v f="$finished" -v n="$tiles" -v w="$width" -v h="$height" \
    'BEGIN { printf "slurm: %d tiles of %d×%d rendered in %.2f s, merged in %.2f s\n", n, w, h, r - s, f - r }' >&2
