#!/usr/bin/env bash
# Runs every test of the project on a fresh machine, installing what the tests need:
#   - Debian's Blender 3.4 (+ python3-numpy, Xvfb for its GUI) and the Khronos glTF validator and gltfpack (npm),
#   - a virtual environment .venv with PyPI's bpy (Blender 5.x as a Python module), numpy, pytest,
#     OpenEXR (reads the multi-layer EXRs of the pass tests), dask distributed and tesela-farm
#     (farm/, editable: the render-farm tests),
#     and pyoidn (its Open Image Denoise library, which the renderer loads at run time),
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
    if ! .venv/bin/python -c 'import distributed, tesela_farm' 2>/dev/null; then
        log "installing dask distributed and tesela-farm (farm/) into .venv"
        .venv/bin/pip install -q --disable-pip-version-check dask distributed -e farm
    fi
    if ! .venv/bin/python -c 'import importlib.metadata as m; m.version("pyoidn")' 2>/dev/null; then
        log "installing pyoidn (Open Image Denoise) into .venv"
        .venv/bin/pip install -q --disable-pip-version-check pyoidn \
            || echo "warning: pip could not install pyoidn; denoising tests will skip"
    fi
    if command -v npm >/dev/null && [[ ! -x .venv/node/node_modules/.bin/gltf_validator ]]; then
        log "installing the Khronos glTF validator (npm)"
        mkdir -p .venv/node
        npm install -s --prefix .venv/node gltf-validator >/dev/null 2>&1 \
            || echo "warning: npm could not install gltf-validator; validator tests will skip"
    fi
    if command -v npm >/dev/null && [[ ! -x .venv/node/node_modules/.bin/gltfpack ]]; then
        log "installing gltfpack, meshoptimizer's glTF packer (npm)"
        mkdir -p .venv/node
        npm install -s --prefix .venv/node gltfpack >/dev/null 2>&1 \
            || echo "warning: npm could not install gltfpack; meshopt file tests will skip"
    fi
fi

# The denoiser library for the tests and the renderer they start (unless one is chosen already).
if [[ -z "${TESELA_OIDN_LIB:-}" ]]; then
    OIDN_LIB="$(.venv/bin/python -c 'import importlib.util as u, os; s = u.find_spec("pyoidn")
print(os.path.join(os.path.dirname(s.origin), "oidn", "lib") if s else "")' 2>/dev/null || true)"
    if [[ -n "$OIDN_LIB" && -d "$OIDN_LIB" ]]; then
        export TESELA_OIDN_LIB="$OIDN_LIB"
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
export GLTFPACK="$ROOT/.venv/node/node_modules/.bin/gltfpack"
.venv/bin/python -m pytest -q tests/blender
