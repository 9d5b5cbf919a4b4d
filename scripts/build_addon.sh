#!/usr/bin/env bash
# Build an installable zip of the Tesela Blender add-on.
#
#   scripts/build_addon.sh [--bundle] [--binary PATH] [--oidn DIR] [--out DIR]
#
# --bundle     put the renderer binary (default target/release/tesela) into the add-on
#              (as tesela/bin/tesela), so that the add-on finds it without configuration,
#              and Open Image Denoise's CPU libraries beside it (tesela/lib, where the
#              renderer looks); without them the bundle renders without denoising.
# --binary P   the binary to bundle (implies --bundle).
# --oidn DIR   the folder holding libOpenImageDenoise (default: $TESELA_OIDN_LIB, else the
#              pyoidn wheel in .venv; see the README's "Denoising").
# --out DIR    where to write the zip (default dist/).
#
# The zip holds one folder, tesela/, with __init__.py (bl_info, for Blender 3.4 - 4.1
# "Install add-on") and blender_manifest.toml (for Blender 4.2+ "Install from disk").
set -euo pipefail
ROOT="$(cd "$(dirname "$0")/.." && pwd)"
OUT="$ROOT/dist"
BUNDLE=0
BINARY="$ROOT/target/release/tesela"
OIDN_DIR="${TESELA_OIDN_LIB:-}"
while [ $# -gt 0 ]; do
  case "$1" in
    --bundle) BUNDLE=1; shift ;;
    --binary) BINARY="$2"; BUNDLE=1; shift 2 ;;
    --oidn) OIDN_DIR="$2"; shift 2 ;;
    --out) OUT="$2"; shift 2 ;;
    -h|--help) sed -n '2,17p' "$0"; exit 0 ;;
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
  # Open Image Denoise: the API library, its core (with the trained weights), the CPU device
  # and TBB; the GPU devices of the wheel are left out (large, and need their runtimes).
  [ -f "$OIDN_DIR" ] && OIDN_DIR="$(dirname "$OIDN_DIR")"
  if [ -z "$OIDN_DIR" ]; then
    OIDN_DIR="$(ls -d "$ROOT"/.venv/lib/python3*/site-packages/pyoidn/oidn/lib 2>/dev/null | head -1 || true)"
  fi
  case "$(uname -s)" in
    Darwin) OIDN_FILES="libOpenImageDenoise.2.dylib libOpenImageDenoise_core.*dylib libOpenImageDenoise_device_cpu.*dylib libtbb.12.dylib" ;;
    *) OIDN_FILES="libOpenImageDenoise.so.2 libOpenImageDenoise_core.so.* libOpenImageDenoise_device_cpu.so.* libtbb.so.12" ;;
  esac
  if [ -n "$OIDN_DIR" ] && [ -d "$OIDN_DIR" ]; then
    mkdir -p "$STAGE/tesela/lib"
    for pattern in $OIDN_FILES; do
      found=0
      for f in "$OIDN_DIR"/$pattern; do
        [ -f "$f" ] || continue
        cp -L "$f" "$STAGE/tesela/lib/"
        found=1
      done
      [ "$found" = 1 ] || { echo "Open Image Denoise: $pattern not found in $OIDN_DIR" >&2; exit 1; }
    done
    echo "bundled Open Image Denoise from $OIDN_DIR" >&2
  else
    echo "warning: Open Image Denoise not found (pip install pyoidn into .venv, or --oidn DIR);" \
      "the bundle renders without denoising" >&2
  fi
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
