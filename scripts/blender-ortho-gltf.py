# blender-ortho-gltf.py — a Blender scene with an orthographic camera, rendered by Cycles and
# exported as glTF by Blender's own exporter, into tests/data/blender-ortho/ (optional
# tooling: the files are committed; valo builds and tests without Python or Blender).
# test_analytic orthographic_blender_gltf renders the glTF with valo and compares where
# the objects are with Cycles' image: how a user's exported orthographic camera frames.
#
#   blender -b --factory-startup --python scripts/blender-ortho-gltf.py
#   (Debian's blender needs python3-numpy for its glTF exporter)
#
# The scene: Suzanne, a cube and a UV sphere under a white world of strength 1, an
# orthographic camera of ortho_scale 5 (so the glTF has xmag 2.5, ymag 1.5625) on a
# 160 x 100 film; Cycles at 256 samples, box filter of width 1, Standard view transform.
import math, os
import bpy

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
OUT = os.path.join(ROOT, "tests", "data", "blender-ortho")
os.makedirs(OUT, exist_ok=True)
bpy.ops.wm.read_factory_settings(use_empty=True)
sc = bpy.context.scene
sc.render.engine = "CYCLES"
sc.cycles.samples = 256
sc.cycles.use_denoising = False
sc.cycles.use_adaptive_sampling = False
sc.cycles.pixel_filter_type = "BOX"
sc.cycles.filter_width = 1.0
sc.render.resolution_x, sc.render.resolution_y, sc.render.resolution_percentage = 160, 100, 100
sc.view_settings.view_transform = "Standard"
sc.render.image_settings.file_format = "OPEN_EXR"
sc.render.image_settings.color_depth = "32"
world = bpy.data.worlds.new("world")
world.use_nodes = True
world.node_tree.nodes["Background"].inputs[0].default_value = (1, 1, 1, 1)
world.node_tree.nodes["Background"].inputs[1].default_value = 1.0
sc.world = world
bpy.ops.mesh.primitive_monkey_add(location=(0, 0, 0))
bpy.ops.mesh.primitive_cube_add(size=0.6, location=(1.8, 0.4, -0.5))
bpy.ops.mesh.primitive_uv_sphere_add(radius=0.5, location=(-1.9, -0.3, 0.2))
cam = bpy.data.cameras.new("cam")
cam.type = "ORTHO"
cam.ortho_scale = 5.0
cam_ob = bpy.data.objects.new("cam", cam)
sc.collection.objects.link(cam_ob)
sc.camera = cam_ob
cam_ob.location = (3, -6, 2.5)
cam_ob.rotation_euler = (math.radians(72), 0, math.radians(26))
sc.render.filepath = os.path.join(OUT, "cycles.exr")
bpy.ops.render.render(write_still=True)
bpy.ops.export_scene.gltf(filepath=os.path.join(OUT, "scene.gltf"), export_format="GLTF_SEPARATE", export_cameras=True)
print("wrote %s (Blender %s)" % (OUT, bpy.app.version_string))
