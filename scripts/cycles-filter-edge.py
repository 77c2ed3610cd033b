# cycles-filter-edge.py — Blender Cycles' renders of the pixel-filter edge scene of
# tests/test_analytic.c (pixel_filter_cycles): an orthographic view, one scene unit per
# pixel on a 16 x 16 film, of an emitting half-plane (radiance 1, x >= 0.3, z = -1) whose
# edge crosses the film at x = 8.3 pixels, through Cycles' Blackman-Harris filter of width
# 1.5 (its default) and its box of width 1. Writes tests/data/filters/cycles-edge-NAME.exr
# (optional tooling: the EXRs are committed; valo builds and tests without Python).
#
#   blender -b --factory-startup --python scripts/cycles-filter-edge.py
#
# Conventions matched: Cycles' orthographic camera with ortho_scale 16 covers 16 units on
# a square film as valo's "height": 16; an Emission shader of strength 1 is radiance 1;
# no world light; 4096 samples, no adaptive sampling, no denoising, the Standard view
# transform, 32-bit float EXR.
import os, sys
import bpy

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
OUT = os.path.join(ROOT, "tests", "data", "filters")


def scene(filter_type, width):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    sc = bpy.context.scene
    sc.render.engine = "CYCLES"
    sc.cycles.device = "CPU"
    sc.cycles.samples = 4096
    sc.cycles.use_adaptive_sampling = False
    sc.cycles.use_denoising = False
    sc.cycles.pixel_filter_type = filter_type
    sc.cycles.filter_width = width
    sc.cycles.seed = 1
    sc.render.resolution_x = sc.render.resolution_y = 16
    sc.render.resolution_percentage = 100
    sc.view_settings.view_transform = "Standard"
    sc.render.image_settings.file_format = "OPEN_EXR"
    sc.render.image_settings.color_depth = "32"
    world = bpy.data.worlds.new("world")
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs[1].default_value = 0.0
    sc.world = world
    mesh = bpy.data.meshes.new("half")
    mesh.from_pydata([(0.3, -100, -1), (100, -100, -1), (100, 100, -1), (0.3, 100, -1)], [], [(0, 1, 2, 3)])
    sc.collection.objects.link(bpy.data.objects.new("half", mesh))
    mat = bpy.data.materials.new("lamp")
    mat.use_nodes = True
    nodes = mat.node_tree.nodes
    nodes.clear()
    emission = nodes.new("ShaderNodeEmission")
    emission.inputs[1].default_value = 1.0
    out = nodes.new("ShaderNodeOutputMaterial")
    mat.node_tree.links.new(emission.outputs[0], out.inputs[0])
    mesh.materials.append(mat)
    cam = bpy.data.cameras.new("camera")
    cam.type = "ORTHO"
    cam.ortho_scale = 16
    cam_ob = bpy.data.objects.new("camera", cam)
    sc.collection.objects.link(cam_ob)
    sc.camera = cam_ob
    return sc


os.makedirs(OUT, exist_ok=True)
for name, filter_type, width in [("blackman-harris", "BLACKMAN_HARRIS", 1.5), ("box", "BOX", 1.0)]:
    sc = scene(filter_type, width)
    sc.render.filepath = os.path.join(OUT, "cycles-edge-%s.exr" % name)
    bpy.ops.render.render(write_still=True)
    print("wrote %s (Blender %s)" % (sc.render.filepath, bpy.app.version_string), file=sys.stderr)
