"""libwetcloth from Python: wet cloth as a mass-spring system.

    import wetcloth
    world = wetcloth.World(gravity=(0.0, 0.0, -9.81))
    cloth = world.add_grid_cloth(20, 20, center=(0.0, 0.0, 0.6), wetness=1.0)
    world.add_sphere((0.0, 0.0, 0.0), 0.3)
    for frame in range(48):
        world.advance(1.0 / 24)
    print(cloth.positions, cloth.stuck.sum())

A cffi ABI-mode binding: nothing is compiled at import. The shared library
ships inside this package (``pip install .`` puts it there); the
environment variable WETCLOTH_LIBRARY overrides where it is loaded from.
See docs/python.md.
"""

from . import _core, _lib
from ._ffi import ffi

lib, library_path = _lib.load(__path__)
Material = _core._init(lib)

from ._core import (Cloth, ConvexCollider, MeshCollider, WetclothError,  # noqa: E402
                    World)

#: Version of the loaded library, "major.minor.patch".
__version__ = ffi.string(lib.wc_version_string()).decode()

__all__ = ["World", "Material", "Cloth", "MeshCollider", "ConvexCollider", "WetclothError",
           "ffi", "lib", "library_path", "__version__"]
