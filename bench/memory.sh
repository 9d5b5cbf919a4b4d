#!/bin/sh
# Peak memory of a render of a large scene (issue 4): writes the Cornell box with a displaced
# sphere of TRIANGLES triangles (default 10 million) as a .glb, renders a small image with
# /usr/bin/time -v, and prints the peak resident set size and the bytes per triangle.
#
#   bench/memory.sh [TRIANGLES] [WIDTH] [INSTANCES]   # e.g. bench/memory.sh 10000000 64
#
# The target is 3 GiB for 10 million triangles. With INSTANCES > 1 the sphere of TRIANGLES
# triangles is placed INSTANCES times (EXT_mesh_gpu_instancing): the scatter case is
# `bench/memory.sh 5000 64 2000` (target 200 MB), the forest `bench/memory.sh 10000 64 100000`.
# Set KEEP=1 to keep the scene file.
set -eu
cd "$(dirname "$0")/.."
TRIS=${1:-10000000}
WIDTH=${2:-64}
INSTANCES=${3:-1}
DIR=$(mktemp -d "${TMPDIR:-/tmp}/tesela-memory.XXXXXX")
trap '[ "${KEEP:-0}" = 1 ] || rm -rf "$DIR"' EXIT INT TERM

cargo build --release --quiet --bin tesela --example big_scene
target/release/examples/big_scene "$DIR/big.glb" "$TRIS" "$INSTANCES"
# Loading alone (`tesela info`), then the full render (load + BVH build + render).
/usr/bin/time -v target/release/tesela info "$DIR/big.glb" > "$DIR/info.txt" 2> "$DIR/time-info.txt"
N=$(sed -n 's/.*triangles placed: \([0-9]*\).*/\1/p' "$DIR/info.txt")
LOAD_KB=$(sed -n 's/.*Maximum resident set size (kbytes): \([0-9]*\).*/\1/p' "$DIR/time-info.txt")

/usr/bin/time -v target/release/tesela render "$DIR/big.glb" -o "$DIR/big.png" \
    --width "$WIDTH" --height "$WIDTH" --spp 1 --threads 2 2> "$DIR/time.txt" || {
    cat "$DIR/time.txt" >&2
    exit 1
}
grep '^tesela:' "$DIR/time.txt" || true
KB=$(sed -n 's/.*Maximum resident set size (kbytes): \([0-9]*\).*/\1/p' "$DIR/time.txt")
SECS=$(sed -n 's/.*Elapsed (wall clock) time (h:mm:ss or m:ss): \(.*\)/\1/p' "$DIR/time.txt")
awk -v kb="$KB" -v lkb="$LOAD_KB" -v n="$N" -v t="$SECS" 'BEGIN {
    printf "triangles: %d\npeak RSS, loading only: %.0f MiB (%.1f bytes per triangle)\n", n, lkb / 1024, lkb * 1024 / n
    printf "peak RSS: %.0f MiB (%.2f GiB)\nbytes per triangle: %.1f\nwall time: %s\n",
        kb / 1024, kb / 1048576, kb * 1024 / n, t
    if (kb > 3 * 1048576) { print "OVER the 3 GiB budget"; exit 1 }
}'
