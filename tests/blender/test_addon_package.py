"""The installable zip (scripts/build_addon.sh): installs as a 4.2+ extension in Blender 5
(bpy, in a subprocess with private user folders) and as a legacy add-on in Blender 3.4, and
the add-on then finds the renderer bundled inside it (here: the fake renderer, bundled with
--binary) without any configuration.
"""

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

HERE = Path(__file__).resolve().parent
REPO = HERE.parent.parent
FAKE = HERE / "fake_renderer.py"
BLENDER34 = os.environ.get("TESELA_BLENDER") or shutil.which("blender")

SCRIPT = r'''
import os, sys, bpy
zipf, legacy = sys.argv[-2], sys.argv[-1] == "legacy"
if legacy:
    bpy.ops.preferences.addon_install(filepath=zipf)
    import addon_utils
    addon_utils.enable("tesela", default_set=True)
else:
    bpy.ops.extensions.package_install_files(filepath=zipf, repo="user_default",
                                             enable_on_install=True)
sc = bpy.context.scene
for ob in list(sc.objects):
    if ob.type != "CAMERA":
        bpy.data.objects.remove(ob, do_unlink=True)
if sc.camera is None:
    cam = bpy.data.objects.new("Cam", bpy.data.cameras.new("Cam"))
    sc.collection.objects.link(cam)
    sc.camera = cam
sc.render.engine = "TESELA"
sc.render.resolution_x = sc.render.resolution_y = 8
sc.render.resolution_percentage = 100
mod = sys.modules[[m for m in sys.modules if m.endswith("tesela.preferences")][0]]
path, tried = mod.find_renderer()
print("TESELA_FOUND", path)
bpy.ops.render.render()
print("TESELA_RENDERED")
'''


def build_zip(out):
    r = subprocess.run([str(REPO / "scripts" / "build_addon.sh"), "--binary", str(FAKE),
                        "--out", str(out)], capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    return Path(r.stdout.strip().splitlines()[-1])


def isolated_env(tmp_path):
    env = dict(os.environ)
    for k in ("TESELA_BINARY", "TESELA_BIN", "BLENDER_USER_SCRIPTS"):
        env.pop(k, None)
    env["HOME"] = str(tmp_path / "home")
    env["BLENDER_USER_RESOURCES"] = str(tmp_path / "user resources")
    env["BLENDER_USER_CONFIG"] = str(tmp_path / "user resources" / "config")
    env["BLENDER_USER_SCRIPTS"] = str(tmp_path / "user resources" / "scripts")
    env["PATH"] = "/usr/bin:/bin"  # no tesela on PATH
    return env


def check(out, tmp_path):
    assert "TESELA_RENDERED" in out, out[-4000:]
    found = [ln for ln in out.splitlines() if ln.startswith("TESELA_FOUND")][0]
    assert found.endswith(os.path.join("tesela", "bin", "tesela")), found
    assert str(tmp_path) in found  # the copy inside the installed add-on


def test_zip_installs_as_extension_in_blender5(tmp_path):
    z = build_zip(tmp_path / "dist")
    script = tmp_path / "install.py"
    script.write_text(SCRIPT)
    r = subprocess.run([sys.executable, str(script), str(z), "extension"], env=isolated_env(tmp_path),
                       capture_output=True, text=True, timeout=300)
    check(r.stdout + r.stderr, tmp_path)


@pytest.mark.skipif(BLENDER34 is None, reason="no 'blender' executable")
def test_zip_installs_as_legacy_addon_in_blender34(tmp_path):
    z = build_zip(tmp_path / "dist")
    script = tmp_path / "install.py"
    script.write_text(SCRIPT)
    r = subprocess.run([BLENDER34, "-b", "--factory-startup", "--python", str(script), "--", str(z),
                        "legacy"], env=isolated_env(tmp_path), capture_output=True, text=True,
                       timeout=300)
    check(r.stdout + r.stderr, tmp_path)
