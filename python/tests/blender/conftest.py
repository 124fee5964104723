"""Fixtures for the Blender add-on tests (pytest inside bpy from PyPI).

Environment (set by ctest; defaults for running pytest by hand):

* WC_BLENDER_WORK   a scratch folder, emptied first (default: a temp folder):
                    Blender's user resources (BLENDER_USER_RESOURCES, so the
                    user's own Blender settings are never touched), the zip,
                    the cache folders;
* WC_ADDON_PYTHON   the Python that runs tools/build_blender_addon.py; it needs
                    cffi (default: the repository's .venv/bin/python);
* WC_ADDON_LIBRARY  a built libwetcloth.so to bundle (default: the build
                    script builds one in build-blender/);
* WC_ADDON_BUILD_DIR the build script's --build-dir (its cffi wheel cache).
"""

import os
import shutil
import subprocess
import sys
import tempfile

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", ".."))

WORK = os.environ.get("WC_BLENDER_WORK") or tempfile.mkdtemp(prefix="wetcloth-blender-")
shutil.rmtree(WORK, ignore_errors=True)
os.makedirs(WORK)
os.environ["BLENDER_USER_RESOURCES"] = os.path.join(WORK, "user")

import bpy  # noqa: E402  (after BLENDER_USER_RESOURCES)
import pytest  # noqa: E402

MODULE = "bl_ext.user_default.wetcloth"


def build_zip():
    python = os.environ.get("WC_ADDON_PYTHON") or os.path.join(ROOT, ".venv", "bin", "python")
    cmd = [python, os.path.join(ROOT, "tools", "build_blender_addon.py"),
           "--out", os.path.join(WORK, "dist")]
    if os.environ.get("WC_ADDON_LIBRARY"):
        cmd += ["--library", os.environ["WC_ADDON_LIBRARY"]]
    if os.environ.get("WC_ADDON_BUILD_DIR"):
        cmd += ["--build-dir", os.environ["WC_ADDON_BUILD_DIR"]]
    r = subprocess.run(cmd, capture_output=True, text=True)
    assert r.returncode == 0, r.stdout + r.stderr
    path = r.stdout.strip().splitlines()[-1]
    assert os.path.isfile(path), r.stdout
    return path


@pytest.fixture(scope="session")
def addon_zip():
    return build_zip()


@pytest.fixture(scope="session")
def installed(addon_zip):
    """The zip installed and enabled through Blender's extension system."""
    r = bpy.ops.extensions.package_install_files(filepath=addon_zip, repo="user_default",
                                                 enable_on_install=True)
    assert r == {"FINISHED"}
    assert MODULE in bpy.context.preferences.addons.keys()
    yield sys.modules[MODULE]
    # Disabling through the extension system leaves no class registered, so
    # Blender exits cleanly (bpy hangs at exit, "Not freed memory blocks", when
    # a script leaves an Operator class registered).
    bpy.ops.preferences.addon_disable(module=MODULE)


@pytest.fixture
def empty_scene(installed):
    bpy.ops.wm.read_homefile(use_empty=True)
    scene = bpy.context.scene
    scene.frame_start, scene.frame_end = 1, 24
    scene.frame_set(1)
    return scene


@pytest.fixture
def project(empty_scene):
    """A fresh folder with the empty scene saved in it as shot.blend: its
    bakes go to <folder>/wetcloth_shot/."""
    path = tempfile.mkdtemp(prefix="project-", dir=WORK)
    bpy.ops.wm.save_as_mainfile(filepath=os.path.join(path, "shot.blend"))
    return path


@pytest.fixture
def cache_dir(project):
    """The folder the bakes of the saved scene go to."""
    return os.path.join(project, "wetcloth_shot") + os.sep
