#!/usr/bin/env python3
"""Demo of the Blender add-on: builds a small .blend headlessly (a wet cloth
draped over a ball next to a dry one), bakes both with the add-on and
renders one still with Cycles on the CPU.

    .venv-blender/bin/python tools/blender_demo.py [--out out/blender-demo]
        [--image docs/images/blender_demo.png] [--frames 48] [--samples 32]

Runs inside bpy (scripts/venv-blender.sh makes .venv-blender/). The add-on
zip is built with tools/build_blender_addon.py by the Python of .venv/ (it
needs cffi) and installed into a temporary Blender user folder, as a user
would install it. Writes OUT/wet_cloth_demo.blend, its bakes in
OUT/wetcloth_wet_cloth_demo/ and the
image.
"""

import argparse
import os
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "blender-demo"))
    ap.add_argument("--image", default=os.path.join(ROOT, "docs", "images", "blender_demo.png"))
    ap.add_argument("--frames", type=int, default=48)
    ap.add_argument("--samples", type=int, default=32)
    ap.add_argument("--resolution", type=int, nargs=2, default=(960, 540))
    ap.add_argument("--addon-python", default=os.path.join(ROOT, ".venv", "bin", "python"),
                    help="Python with cffi that builds the add-on zip")
    args = ap.parse_args()
    out = os.path.abspath(args.out)
    os.makedirs(out, exist_ok=True)

    user = tempfile.mkdtemp(prefix="wetcloth-blender-user-")
    os.environ["BLENDER_USER_RESOURCES"] = user
    r = subprocess.run([args.addon_python, os.path.join(ROOT, "tools", "build_blender_addon.py"),
                        "--out", os.path.join(user, "dist")], capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(r.stdout + r.stderr)
    zip_path = r.stdout.strip().splitlines()[-1]

    import bpy  # after BLENDER_USER_RESOURCES

    bpy.ops.extensions.package_install_files(filepath=zip_path, repo="user_default",
                                             enable_on_install=True)
    module = "bl_ext.user_default.wetcloth"
    try:
        build_and_bake(bpy, out, args)
        render(bpy, args)
        bpy.ops.wm.save_as_mainfile(filepath=os.path.join(out, "wet_cloth_demo.blend"))
    finally:
        bpy.ops.preferences.addon_disable(module=module)
    print("demo: wrote %s and %s" % (os.path.join(out, "wet_cloth_demo.blend"), args.image))


def material(bpy, name, color, wet_color=None):
    """A principled material; with wet_color, the baked wetness attribute
    darkens it and makes it glossier (the thesis' §3.4 suggestion)."""
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    nodes, links = m.node_tree.nodes, m.node_tree.links
    bsdf = nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = (*color, 1.0)
    bsdf.inputs["Roughness"].default_value = 0.8
    if wet_color is not None:
        attr = nodes.new("ShaderNodeAttribute")
        attr.attribute_name = "wet_cloth_wetness"
        mix = nodes.new("ShaderNodeMix")
        mix.data_type = "RGBA"
        mix.inputs["A"].default_value = (*color, 1.0)
        mix.inputs["B"].default_value = (*wet_color, 1.0)
        links.new(attr.outputs["Fac"], mix.inputs["Factor"])
        links.new(mix.outputs["Result"], bsdf.inputs["Base Color"])
        rough = nodes.new("ShaderNodeMapRange")
        rough.inputs["To Min"].default_value = 0.8
        rough.inputs["To Max"].default_value = 0.35
        links.new(attr.outputs["Fac"], rough.inputs["Value"])
        links.new(rough.outputs["Result"], bsdf.inputs["Roughness"])
    return m


def build_and_bake(bpy, out, args):
    bpy.ops.wm.read_homefile(use_empty=True)
    scene = bpy.context.scene
    scene.frame_start, scene.frame_end = 1, args.frames
    scene.render.fps = 24
    grey = material(bpy, "Ball", (0.55, 0.55, 0.58))
    floor_mat = material(bpy, "Floor", (0.35, 0.33, 0.30))
    cloth_mat = material(bpy, "Cloth", (0.50, 0.30, 0.16), wet_color=(0.16, 0.07, 0.03))

    bpy.ops.mesh.primitive_plane_add(size=6.0, location=(0.0, 0.0, -0.32))
    bpy.context.object.data.materials.append(floor_mat)
    # saved first, so that the bakes go next to it (out/blender-demo/wetcloth_wet_cloth_demo/)
    bpy.ops.wm.save_as_mainfile(filepath=os.path.join(out, "wet_cloth_demo.blend"))
    for x, wetness, name in ((-0.65, 0.0, "Dry"), (0.65, 1.0, "Wet")):
        bpy.ops.mesh.primitive_uv_sphere_add(segments=32, ring_count=16, radius=0.3,
                                             location=(x, 0.0, 0.0))
        ball = bpy.context.object
        ball.name = name + " Ball"
        bpy.ops.object.shade_smooth()
        ball.data.materials.append(grey)
        ball.modifiers.new("Collision", "COLLISION")
        bpy.ops.mesh.primitive_plane_add(size=1.0, location=(x, 0.0, 0.6))
        cloth = bpy.context.object
        cloth.name = name + " Cloth"
        bpy.ops.object.mode_set(mode="EDIT")
        bpy.ops.mesh.subdivide(number_cuts=24)
        bpy.ops.object.mode_set(mode="OBJECT")
        bpy.ops.object.shade_smooth()
        cloth.data.materials.append(cloth_mat)
        s = cloth.wet_cloth
        s.enabled = True
        s.wetness = wetness
        # each cloth collides with its own ball only
        coll = bpy.data.collections.new(name + " Colliders")
        scene.collection.children.link(coll)
        coll.objects.link(ball)
        s.collision_collection = coll
        t0 = time.perf_counter()
        with bpy.context.temp_override(active_object=cloth, object=cloth):
            bpy.ops.wetcloth.bake()
        print("demo: baked %s (%d vertices): %s, %.1f s" % (
            cloth.name, len(cloth.data.vertices), s.bake_info, time.perf_counter() - t0))
        solid = cloth.modifiers.new("Solidify", "SOLIDIFY")  # after the cache: render only
        solid.thickness = 0.006


def render(bpy, args):
    scene = bpy.context.scene
    scene.frame_set(scene.frame_end)
    cam_data = bpy.data.cameras.new("Camera")
    cam = bpy.data.objects.new("Camera", cam_data)
    scene.collection.objects.link(cam)
    cam.location = (0.0, -3.0, 0.9)
    cam.rotation_euler = (1.35, 0.0, 0.0)
    cam_data.lens = 45
    scene.camera = cam
    sun_data = bpy.data.lights.new("Sun", "SUN")
    sun_data.energy = 3.0
    sun_data.angle = 0.2
    sun = bpy.data.objects.new("Sun", sun_data)
    sun.rotation_euler = (0.7, 0.2, 0.6)
    scene.collection.objects.link(sun)
    world = bpy.data.worlds.new("World")
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (0.6, 0.65, 0.7, 1.0)
    world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.6
    scene.world = world
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = args.samples
    scene.cycles.use_denoising = True
    scene.render.resolution_x, scene.render.resolution_y = args.resolution
    scene.render.resolution_percentage = 100
    scene.render.image_settings.file_format = "PNG"
    scene.render.filepath = os.path.abspath(args.image)
    os.makedirs(os.path.dirname(scene.render.filepath), exist_ok=True)
    t0 = time.perf_counter()
    bpy.ops.render.render(write_still=True)
    print("demo: rendered frame %d in %.1f s" % (scene.frame_current, time.perf_counter() - t0))


if __name__ == "__main__":
    main()
