#!/usr/bin/env bash
# Runs every test of the project on a fresh machine, installing what the tests need:
#   - Debian's Blender 3.4 (+ python3-numpy, Xvfb for its GUI) and the Khronos glTF validator (npm),
#   - a virtual environment .venv with PyPI's bpy (Blender 5.x as a Python module), numpy, pytest,
#     OpenEXR (reads the multi-layer EXRs of the pass tests),
# then: cargo fmt --check, cargo clippy -D warnings, cargo test, and pytest tests/blender.
# Set TESELA_SKIP_INSTALL=1 to skip the installation steps.
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT="$(pwd)"

log() { printf '\n== %s\n' "$*"; }

if [[ "${TESELA_SKIP_INSTALL:-0}" != 1 ]]; then
    if ! dpkg -s blender python3-numpy xvfb >/dev/null 2>&1; then
        log "installing Debian packages: blender python3-numpy xvfb"
        SUDO=""
        [[ "$(id -u)" != 0 ]] && SUDO="sudo"
        $SUDO apt-get update -qq
        DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq blender python3-numpy xvfb >/dev/null
    fi
    if [[ ! -x .venv/bin/python ]]; then
        log "creating .venv (bpy, numpy, pytest)"
        python3 -m venv .venv
    fi
    if ! .venv/bin/python -c 'import bpy, numpy, pytest, OpenEXR' 2>/dev/null; then
        .venv/bin/pip install -q --disable-pip-version-check bpy numpy pytest OpenEXR
    fi
    if command -v npm >/dev/null && [[ ! -x .venv/node/node_modules/.bin/gltf_validator ]]; then
        log "installing the Khronos glTF validator (npm)"
        mkdir -p .venv/node
        npm install -s --prefix .venv/node gltf-validator >/dev/null 2>&1 \
            || echo "warning: npm could not install gltf-validator; validator tests will skip"
    fi
fi

log "cargo fmt --check"
cargo fmt --check

log "cargo clippy --all-targets -- -D warnings"
cargo clippy -q --profile ci --all-targets -- -D warnings

log "cargo build --release"
cargo build -q --release

log "cargo test (optimized, profile ci)"
cargo test -q --profile ci

log "pytest tests/blender"
export TESELA_BIN="$ROOT/target/release/tesela"
export GLTF_VALIDATOR="$ROOT/.venv/node/node_modules/.bin/gltf_validator"
.venv/bin/python -m pytest -q tests/blender
