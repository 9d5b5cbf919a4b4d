#!/usr/bin/env bash
# Build an installable zip of the Tesela Blender add-on.
#
#   scripts/build_addon.sh [--bundle] [--binary PATH] [--out DIR]
#
# --bundle     put the renderer binary (default target/release/tesela) into the add-on
#              (as tesela/bin/tesela), so that the add-on finds it without configuration.
# --binary P   the binary to bundle (implies --bundle).
# --out DIR    where to write the zip (default dist/).
#
# The zip holds one folder, tesela/, with __init__.py (bl_info, for Blender 3.4 - 4.1
# "Install add-on") and blender_manifest.toml (for Blender 4.2+ "Install from disk").
set -euo pipefail
ROOT="$(cd "$(dirname "$0")/.." && pwd)"
OUT="$ROOT/dist"
BUNDLE=0
BINARY="$ROOT/target/release/tesela"
while [ $# -gt 0 ]; do
  case "$1" in
    --bundle) BUNDLE=1; shift ;;
    --binary) BINARY="$2"; BUNDLE=1; shift 2 ;;
    --out) OUT="$2"; shift 2 ;;
    -h|--help) sed -n '2,13p' "$0"; exit 0 ;;
    *) echo "unknown option: $1" >&2; exit 2 ;;
  esac
done
VERSION="$(sed -n 's/^version = "\(.*\)"/\1/p' "$ROOT/blender_addon/blender_manifest.toml" | head -1)"
STAGE="$(mktemp -d)"
trap 'rm -rf "$STAGE"' EXIT
mkdir -p "$STAGE/tesela"
( cd "$ROOT/blender_addon" && find . -name '*.py' -o -name '*.toml' | grep -v __pycache__ ) |
  while read -r f; do mkdir -p "$STAGE/tesela/$(dirname "$f")"; cp "$ROOT/blender_addon/$f" "$STAGE/tesela/$f"; done
SUFFIX=""
if [ "$BUNDLE" = 1 ]; then
  if [ ! -x "$BINARY" ]; then
    echo "renderer binary not found at $BINARY (build it: cargo build --release)" >&2
    exit 1
  fi
  mkdir -p "$STAGE/tesela/bin"
  cp "$BINARY" "$STAGE/tesela/bin/tesela"
  chmod 755 "$STAGE/tesela/bin/tesela"
  # Blender 4.2+ extensions with a native binary declare their platform.
  case "$(uname -s)-$(uname -m)" in
    Linux-x86_64) PLATFORM="linux-x64" ;;
    Linux-aarch64) PLATFORM="linux-arm64" ;;
    Darwin-arm64) PLATFORM="macos-arm64" ;;
    Darwin-x86_64) PLATFORM="macos-x64" ;;
    *) PLATFORM="" ;;
  esac
  if [ -n "$PLATFORM" ]; then
    # (top-level key: it must come before the [permissions] table)
    sed -i "s/^\[permissions\]/platforms = [\"$PLATFORM\"]\n\n[permissions]/" "$STAGE/tesela/blender_manifest.toml"
  fi
  SUFFIX="-$(uname -s | tr '[:upper:]' '[:lower:]')-$(uname -m)"
fi
mkdir -p "$OUT"
ZIP="$OUT/tesela-blender-$VERSION$SUFFIX.zip"
rm -f "$ZIP"
python3 - "$STAGE" "$ZIP" <<'PY'
import os, sys, zipfile
stage, dest = sys.argv[1], sys.argv[2]
with zipfile.ZipFile(dest, "w", zipfile.ZIP_DEFLATED) as z:
    for root, dirs, files in os.walk(stage):
        dirs.sort()
        for name in sorted(files):
            full = os.path.join(root, name)
            info = zipfile.ZipInfo.from_file(full, os.path.relpath(full, stage))
            info.compress_type = zipfile.ZIP_DEFLATED
            with open(full, "rb") as f:
                z.writestr(info, f.read())  # keeps the executable bit of bin/tesela
PY
echo "$ZIP"
