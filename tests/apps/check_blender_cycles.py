"""Renders a vdbhair field with Blender's Cycles (headless) and checks that the direction grid
reaches the shader:
    blender -b --python-exit-code 1 --python check_blender_cycles.py -- FIELD.vdb GRID [OUT.png]
The volume's emission colour is an Attribute node reading GRID (absolute value of each component,
so every direction shows); the frame is rendered small with Cycles on the CPU and must have
pixels brighter than the empty background. Blender's Cycles reserves the attribute name
'tangent' (UV tangents), so GRID must be another name, such as hair_direction."""
import sys

import bpy

args = sys.argv[sys.argv.index("--") + 1:]
path, grid = args[0], args[1]
out = args[2] if len(args) > 2 else "/tmp/vdbhair_cycles.png"

bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene
bpy.ops.object.volume_import(filepath=path)
obj = bpy.context.selected_objects[0]
volume = obj.data
volume.grids.load()
names = [g.name for g in volume.grids]
print("grids in Blender:", names)
if grid not in names:
    raise SystemExit("FAIL: no grid %s in %s" % (grid, names))

# Emission = |direction| from the grid; no density scattering, so only the attribute shows.
mat = bpy.data.materials.new("vdbhair_direction")
mat.use_nodes = True
nodes, links = mat.node_tree.nodes, mat.node_tree.links
nodes.clear()
attr = nodes.new("ShaderNodeAttribute")
attr.attribute_name = grid
absolute = nodes.new("ShaderNodeVectorMath")
absolute.operation = "ABSOLUTE"
emission = nodes.new("ShaderNodeEmission")
emission.inputs["Strength"].default_value = 5.0
output = nodes.new("ShaderNodeOutputMaterial")
links.new(attr.outputs["Vector"], absolute.inputs[0])
links.new(absolute.outputs["Vector"], emission.inputs["Color"])
links.new(emission.outputs["Emission"], output.inputs["Volume"])
obj.data.materials.append(mat)

# A camera that frames the volume's bounds.
from mathutils import Vector
corners = [obj.matrix_world @ Vector(c) for c in obj.bound_box]
center = sum(corners, Vector()) / 8.0
size = max((c - center).length for c in corners)
cam_data = bpy.data.cameras.new("cam")
cam = bpy.data.objects.new("cam", cam_data)
scene.collection.objects.link(cam)
cam.location = center + Vector((0.0, -3.0 * size, 0.0))
cam.rotation_euler = (1.5708, 0.0, 0.0)
scene.camera = cam

scene.render.engine = "CYCLES"
scene.cycles.device = "CPU"
scene.cycles.samples = 4
scene.cycles.use_denoising = False
scene.render.resolution_x = scene.render.resolution_y = 48
scene.render.resolution_percentage = 100
scene.render.filepath = out
scene.render.image_settings.file_format = "PNG"
if scene.world is None:
    scene.world = bpy.data.worlds.new("world")
scene.world.color = (0.0, 0.0, 0.0)
bpy.ops.render.render(write_still=True)

image = bpy.data.images.load(out)
pixels = list(image.pixels)
lit = sum(1 for i in range(0, len(pixels), 4) if max(pixels[i:i + 3]) > 0.02)
print("Cycles rendered %s: %d of %d pixels show the grid '%s'" % (out, lit, len(pixels) // 4, grid))
if lit == 0:
    raise SystemExit("FAIL: the grid '%s' does not reach Cycles' shader (an all-black frame)" % grid)
print("ok: Cycles reads the vector grid '%s' in a shader" % grid)
