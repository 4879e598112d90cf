# SPDX-License-Identifier: Apache-2.0
"""Imports a mesh file Cambium wrote (.glb or .obj) into Blender and renders it with
Cycles, to look at: the check a person makes that an export arrives whole in another
program. Blender is a tool here, not a dependency (Debian: apt-get install blender).

    blender -b --factory-startup --python scripts/blender_import.py -- plant.glb out.png [SPP]

The camera looks at the imported objects' bounding box from the front (-z in cpfg's
frame, which Blender's importers turn to its own z-up one), a sun lights it from
behind the camera, and the world is a grey sky. Prints the counts of objects, meshes,
materials and images imported as one JSON line.
"""
import json
import math
import sys

import bpy
import numpy
from mathutils import Vector

# Debian's Blender 3.4 glTF importer still names numpy.bool, which bookworm's numpy 1.24
# removed: the alias it meant.
if not hasattr(numpy, "bool"):
    numpy.bool = bool

args = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
if len(args) < 2:
    raise SystemExit("usage: blender -b --python blender_import.py -- FILE.glb|FILE.obj OUT.png [SPP]")
source, image = args[0], args[1]
spp = int(args[2]) if len(args) > 2 else 16

bpy.ops.wm.read_factory_settings(use_empty=True)
if source.lower().endswith((".glb", ".gltf")):
    bpy.ops.import_scene.gltf(filepath=source)
elif source.lower().endswith(".obj"):
    bpy.ops.wm.obj_import(filepath=source)
else:
    raise SystemExit("blender_import.py: a .glb or .obj file")

meshes = [o for o in bpy.context.scene.objects if o.type == "MESH"]
if not meshes:
    raise SystemExit("blender_import.py: nothing imported")
corners = [o.matrix_world @ Vector(c) for o in meshes for c in o.bound_box]
low = Vector((min(c.x for c in corners), min(c.y for c in corners), min(c.z for c in corners)))
high = Vector((max(c.x for c in corners), max(c.y for c in corners), max(c.z for c in corners)))
centre, size = (low + high) / 2, max((high - low).length, 1e-6)

scene = bpy.context.scene
camera = bpy.data.objects.new("camera", bpy.data.cameras.new("camera"))
scene.collection.objects.link(camera)
camera.location = centre + Vector((0, -1.6 * size, 0.1 * size))
camera.rotation_euler = (math.radians(90) - math.atan2(0.1, 1.6), 0, 0)
camera.data.lens = 40
scene.camera = camera
sun = bpy.data.objects.new("sun", bpy.data.lights.new("sun", "SUN"))
sun.data.energy = 3
sun.rotation_euler = (math.radians(50), 0, math.radians(-30))
scene.collection.objects.link(sun)
world = bpy.data.worlds.new("sky")
world.use_nodes = True
world.node_tree.nodes["Background"].inputs["Color"].default_value = (0.6, 0.7, 0.8, 1)
scene.world = world
scene.render.engine = "CYCLES"
scene.cycles.samples = spp
scene.cycles.use_denoising = False  # Debian's Blender has no OpenImageDenoise
scene.cycles.device = "CPU"
scene.render.resolution_x, scene.render.resolution_y = 480, 480
scene.render.filepath = image
bpy.ops.render.render(write_still=True)
print(json.dumps({"objects": len(meshes), "meshes": len(bpy.data.meshes),
                  "materials": len(bpy.data.materials), "images": len(bpy.data.images)}))
