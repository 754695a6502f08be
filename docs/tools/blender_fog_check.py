"""Manual check: Blender imports frep's fog volume and renders it non-empty.

Debian's blender (3.4, 159 packages) is too heavy for CI, so this is run by hand (docs/cli.md, "Blender"):

    frep sample model.hf -b 1.2 --res 96 --store fog -O fog.vdb
    blender -b --factory-startup --python docs/tools/blender_fog_check.py -- fog.vdb [out.png]

It imports the .vdb as a Volume object, checks that it has the grid "density", gives it a
Principled Volume material, frames it with a camera, renders 128x128 with Cycles on a
transparent film and counts the pixels the volume covers. Exit 0 when more than 2 % of the
image is covered (a sphere of radius 1 at --res 96 -b 1.2 covers 13.4 % with Debian's blender
3.4.1, 2026-12-06), 1 otherwise.
"""
import sys

import bpy
from mathutils import Vector

argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
if not argv:
    sys.exit("usage: blender -b --python blender_fog_check.py -- fog.vdb [out.png]")
path = argv[0]
out = argv[1] if len(argv) > 1 else "/tmp/frep_fog_check.png"

bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene

bpy.ops.object.volume_import(filepath=path, align="WORLD", location=(0, 0, 0))
volume = bpy.context.active_object
volume.data.grids.load()
names = [g.name for g in volume.data.grids]
print("grids:", names)
if "density" not in names:
    sys.exit("FAIL: no grid named 'density' in %s (frep sample --store fog writes one)" % path)

material = bpy.data.materials.new("frep_fog")
material.use_nodes = True
nodes = material.node_tree.nodes
nodes.clear()
shader = nodes.new("ShaderNodeVolumePrincipled")
shader.inputs["Density"].default_value = 10.0
output = nodes.new("ShaderNodeOutputMaterial")
material.node_tree.links.new(shader.outputs["Volume"], output.inputs["Volume"])
volume.data.materials.append(material)

# Camera on -y looking at the volume's bounding box, far enough to see all of it.
corners = [volume.matrix_world @ Vector(c) for c in volume.bound_box]
centre = sum(corners, Vector()) / 8
radius = max((c - centre).length for c in corners)
if radius == 0:
    sys.exit("FAIL: the volume's bounding box is empty")
camera = bpy.data.objects.new("camera", bpy.data.cameras.new("camera"))
scene.collection.objects.link(camera)
camera.location = centre + Vector((0, -4 * radius, 0))
camera.rotation_euler = (Vector((0, 0, 0)) + (centre - camera.location)).to_track_quat("-Z", "Y").to_euler()
scene.camera = camera
sun = bpy.data.objects.new("sun", bpy.data.lights.new("sun", type="SUN"))
scene.collection.objects.link(sun)
sun.rotation_euler = (0.6, 0.2, 0.0)

scene.render.engine = "CYCLES"
scene.cycles.samples = 16
# Debian's blender is built without OpenImageDenoise, and Cycles' default denoiser fails the
# render there ("Build without OpenImageDenoiser"): 16 noisy samples are enough to count pixels.
scene.cycles.use_denoising = False
scene.cycles.use_preview_denoising = False
scene.render.film_transparent = True
scene.render.resolution_x = scene.render.resolution_y = 128
scene.render.resolution_percentage = 100
scene.render.image_settings.file_format = "PNG"
scene.render.image_settings.color_mode = "RGBA"
scene.render.filepath = out
bpy.ops.render.render(write_still=True)

image = bpy.data.images.load(out)
alpha = list(image.pixels)[3::4]
covered = sum(1 for a in alpha if a > 0.05) / len(alpha)
print("rendered %s: %.1f %% of the pixels covered by the volume" % (out, 100 * covered))
sys.exit(0 if covered > 0.02 else 1)
