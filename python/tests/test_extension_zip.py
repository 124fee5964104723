"""A Blender extension zip for this platform, checked in the platform's own
Python without Blender: what it holds, and that its cffi wheel and its
library load and simulate the way the installed extension loads them
(Blender installs the wheel, then the add-on imports its `wetcloth`
subpackage, which loads the library beside it).

    WC_ADDON_ZIP=dist/wetcloth-0.2.0-windows_x64.zip python -m pytest test_extension_zip.py

scripts/test-windows.sh runs it in Windows' CPython under wine (ctest
python_extension_zip of the Windows build). The Linux zip is tested inside
Blender itself (python/tests/blender).
"""

import json
import os
import re
import subprocess
import sys
import zipfile

import pytest

ZIP = os.environ.get("WC_ADDON_ZIP", "")

# What this Python's platform is called by Blender, the library's name in
# the package, and the cffi wheel's platform tag.
if sys.platform == "win32":
    PLATFORM, LIBRARY, WHEEL_TAG = "windows-x64", "wetcloth.dll", "win_amd64"
elif sys.platform == "darwin":
    import platform as _platform
    arm = _platform.machine() == "arm64"
    PLATFORM = "macos-arm64" if arm else "macos-x64"
    LIBRARY, WHEEL_TAG = "libwetcloth.dylib", "arm64" if arm else "x86_64"
else:
    PLATFORM, LIBRARY, WHEEL_TAG = "linux-x64", "libwetcloth.so", "x86_64"


@pytest.fixture(scope="module")
def zipped():
    assert ZIP and os.path.isfile(ZIP), "WC_ADDON_ZIP=%r is not a file" % ZIP
    with zipfile.ZipFile(ZIP) as z:
        return z.namelist(), z.read("blender_manifest.toml").decode()


def test_name_manifest_and_contents(zipped):
    names, manifest = zipped
    assert os.path.basename(ZIP).endswith("-%s.zip" % PLATFORM.replace("-", "_"))
    assert 'platforms = ["%s"]' % PLATFORM in manifest
    wheels = [n for n in names if n.startswith("wheels/")]
    assert len(wheels) == 1, wheels
    assert re.match(r"wheels/cffi-[0-9.]+-cp311-cp311-.*%s.*\.whl$" % WHEEL_TAG, wheels[0]), wheels
    assert 'wheels = ["./%s"]' % wheels[0] in manifest
    for name in ("__init__.py", "bake.py", "wetcloth/__init__.py", "wetcloth/_ffi.py",
                 "wetcloth/_lib.py", "wetcloth/" + LIBRARY):
        assert name in names, name
    if PLATFORM != "linux-x64":
        # linked so that it needs nothing beside it
        assert not [n for n in names if n.startswith("wetcloth/libs/")]


def test_bundled_cffi_and_library_load_and_simulate(tmp_path, zipped):
    names, _ = zipped
    addon = tmp_path / "addon"
    with zipfile.ZipFile(ZIP) as z:
        z.extractall(addon)
    wheel_dir = tmp_path / "wheel"
    wheel = [n for n in names if n.startswith("wheels/")][0]
    with zipfile.ZipFile(addon / wheel) as w:
        w.extractall(wheel_dir)
    # A fresh interpreter that sees the bundled wheel first (-E: no
    # PYTHONPATH, so not the staged package of the build either); numpy
    # comes from the Python itself, as Blender's bundles it.
    code = r"""
import json, os, sys
sys.path[:0] = [sys.argv[1], sys.argv[2]]
import _cffi_backend
import wetcloth
world = wetcloth.World(gravity=(0.0, 0.0, -9.81))
cloth = world.add_grid_cloth(8, 8, size=(0.5, 0.5), center=(0.0, 0.0, 1.0))
cloth.pin([0, 7])
for frame in range(6):
    world.advance(1.0 / 24)
p = cloth.positions
print(json.dumps({"cffi": _cffi_backend.__file__, "library": wetcloth.library_path,
                  "version": wetcloth.__version__, "z_min": float(p[:, 2].min()),
                  "z_pins": [float(p[0, 2]), float(p[7, 2])]}))
"""
    r = subprocess.run([sys.executable, "-E", "-s", "-c", code, str(wheel_dir), str(addon)],
                       capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stdout + r.stderr
    out = json.loads(r.stdout.strip().splitlines()[-1])
    assert os.path.realpath(out["cffi"]).startswith(os.path.realpath(str(wheel_dir)))
    assert os.path.realpath(out["library"]) == os.path.realpath(str(addon / "wetcloth" / LIBRARY))
    assert out["version"] == re.search(r'(?m)^version = "(.*)"$', zipped[1]).group(1)
    # the pinned corners stay, the rest falls (a quarter second: ~0.3 m)
    assert out["z_pins"] == [1.0, 1.0]
    assert 0.5 < out["z_min"] < 0.98
