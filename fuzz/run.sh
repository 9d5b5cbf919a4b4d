#!/bin/sh
# Runs both fuzz targets one after the other (one core each time), SECS seconds each.
#   fuzz/run.sh [SECS]          # default 420
# Needs cargo-fuzz; on a stable toolchain RUSTC_BOOTSTRAP=1 enables the nightly flags it uses.
set -eu
cd "$(dirname "$0")"
SECS=${1:-420}
export RUSTC_BOOTSTRAP=1
for t in gltf_json glb; do
    mkdir -p corpus/$t artifacts/$t
    cargo fuzz run -O $t corpus/$t -- \
        -max_total_time="$SECS" -rss_limit_mb=2048 -malloc_limit_mb=2048 -timeout=10 \
        -max_len=131072 -print_final_stats=1 > "fuzz-$t.log" 2>&1 || {
        echo "$t: FAILED (see fuzz/fuzz-$t.log and fuzz/artifacts/$t)"
    }
    tail -n 20 "fuzz-$t.log" | grep -E 'stat::|Done|SUMMARY|ERROR' || true
done
