"""pytest setup for the headless Blender tests.

* Without an importable ``bpy`` (Blender as a Python module) every test module here is reported as
  skipped, with the reason, instead of failing to import.
* The ``addon`` fixture registers the Tesela add-on for a test module (and unregisters it after,
  if the module registered it).
* The ``tesela_bin`` fixture finds the renderer: env ``TESELA_BIN``, else
  ``<repo>/target/release/tesela``. A missing binary skips the tests that need it, except under
  ``CI=true``, where it fails them.
"""

import os
import sys
from pathlib import Path

import pytest

HERE = Path(__file__).resolve().parent
REPO = HERE.parent.parent
if str(HERE) not in sys.path:
    sys.path.insert(0, str(HERE))

try:
    import bpy  # noqa: F401

    BPY_ERROR = None
except Exception as exc:  # ImportError, or a bpy build that cannot load here
    BPY_ERROR = f"{type(exc).__name__}: {exc}"


class _SkippedModule(pytest.Module):
    def collect(self):
        pytest.skip(f"Blender's Python module 'bpy' cannot be imported ({BPY_ERROR}); "
                    "install it with 'pip install bpy' (scripts/test.sh does)",
                    allow_module_level=True)


def pytest_pycollect_makemodule(module_path, parent):
    if BPY_ERROR is not None:
        return _SkippedModule.from_parent(parent, path=module_path)
    return None


def _truthy(value):
    return (value or "").strip().lower() in ("1", "true", "yes", "on")


@pytest.fixture(scope="session")
def tesela_bin():
    """Path of the tesela binary (env TESELA_BIN or <repo>/target/release/tesela)."""
    path = Path(os.environ.get("TESELA_BIN") or REPO / "target" / "release" / "tesela")
    if not (path.is_file() and os.access(path, os.X_OK)):
        msg = (f"tesela binary not found at {path} (build it with 'cargo build --release' "
               "or set TESELA_BIN)")
        if _truthy(os.environ.get("CI")):
            pytest.fail(msg)
        pytest.skip(msg)
    return path


@pytest.fixture(scope="module")
def addon():
    """The Tesela add-on registered while the module's tests run."""
    if str(REPO) not in sys.path:
        sys.path.insert(0, str(REPO))
    import blender_addon
    from blender_addon import engine as tesela_engine

    registered = tesela_engine.TeselaRenderEngine.is_registered
    if not registered:
        blender_addon.register()
    yield
    if not registered and tesela_engine.TeselaRenderEngine.is_registered:
        blender_addon.unregister()
