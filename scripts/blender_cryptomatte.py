# SPDX-License-Identifier: Apache-2.0
"""Picks organs out of a Cambium EXR (`--organ-masks`) with Blender's own Cryptomatte
compositing node, and checks its matte against the one the Cryptomatte specification
gives from the EXR's ranks and manifest (read here independently, through oiiotool): the
check that a compositor reads the masks as Cambium means them. Blender and oiiotool are
tools here, not dependencies (Debian: apt-get install blender openimageio-tools).

    blender -b --factory-startup --python scripts/blender_cryptomatte.py -- \\
        plant.exr CryptoOrgan "L 12" ["F 3" ...]

Prints one JSON line: the layer, the names, the pixels, both mattes' sums and their
largest difference in a pixel; exits 1 when that exceeds 1e-4.
"""
import json
import os
import re
import struct
import subprocess
import sys
import tempfile

import bpy
import numpy

args = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
if len(args) < 3:
    raise SystemExit("usage: blender -b --python blender_cryptomatte.py -- PLANT.exr LAYER NAME [NAME ...]")
source, layer, names = os.path.abspath(args[0]), args[1], args[2:]
work = tempfile.mkdtemp(prefix="cambium_cryptomatte_")
INFO = subprocess.run(["oiiotool", "--info", "-v", source], capture_output=True, text=True, check=True).stdout


def pixels_of(path):
    """An EXR's RGBA as Blender loads it, rows bottom to top."""
    image = bpy.data.images.load(path)
    image.colorspace_settings.name = "Non-Color"
    values = numpy.array(image.pixels[:], dtype=numpy.float64)  # loads the file: size is known after
    w, h = image.size
    return values.reshape(h, w, image.channels)


def blender_matte():
    """The Matte output of Blender's Cryptomatte node for the names."""
    image = bpy.data.images.load(source)
    scene = bpy.context.scene
    # a multilayer image has no pixels of its own to tell its size: oiiotool's header does
    size = re.search(r":\s+(\d+) x\s+(\d+),", INFO)
    scene.render.resolution_x, scene.render.resolution_y = int(size.group(1)), int(size.group(2))
    scene.render.resolution_percentage = 100
    scene.use_nodes = True
    tree = scene.node_tree
    for node in list(tree.nodes):
        tree.nodes.remove(node)
    crypto = tree.nodes.new("CompositorNodeCryptomatteV2")
    crypto.source = "IMAGE"
    crypto.image = image
    crypto.layer_name = layer
    crypto.matte_id = ",".join(names)
    composite = tree.nodes.new("CompositorNodeComposite")
    tree.links.new(crypto.outputs["Matte"], composite.inputs["Image"])
    settings = scene.render.image_settings
    settings.file_format, settings.color_depth, settings.color_mode = "OPEN_EXR", "32", "RGBA"
    scene.view_settings.view_transform = "Standard"
    scene.render.filepath = os.path.join(work, "matte.exr")
    for obj in list(bpy.data.objects):
        bpy.data.objects.remove(obj)
    bpy.ops.render.render(write_still=True)
    return pixels_of(scene.render.filepath)[:, :, 0]


def float_id(hex_hash):
    """The id as stored: the hash's bits as a float, bit 23 flipped where the exponent
    would be all zeros or all ones."""
    bits = int(hex_hash, 16)
    if (bits >> 23) & 0xFF in (0, 255):
        bits ^= 1 << 23
    return struct.unpack("<f", struct.pack("<I", bits))[0]


def specification_matte():
    """Sum of the ranks' coverages whose id is one of the names' (the EXR read by oiiotool)."""
    info = INFO
    key = None
    for k, name in re.findall(r'cryptomatte/(\w+)/name: "([^"]*)"', info):
        if name == layer:
            key = k
    if key is None:
        raise SystemExit(f"{source}: no Cryptomatte layer {layer}")
    manifest = json.loads(re.search(rf'cryptomatte/{key}/manifest: "(.*)"\n', info).group(1).replace('\\"', '"'))
    ids = [numpy.float32(float_id(manifest[n])) for n in names]
    matte = None
    for rank in range(3):
        channels = ",".join(f"{layer}{rank:02d}.{c}" for c in "RGBA")
        path = os.path.join(work, f"rank{rank}.exr")
        subprocess.run(["oiiotool", source, "--ch", channels, "--chnames", "R,G,B,A", "-d", "float", "-o", path],
                       check=True)
        px = pixels_of(path).astype(numpy.float32)
        for id_channel, coverage in ((0, 1), (2, 3)):
            hit = numpy.isin(px[:, :, id_channel], ids)
            part = numpy.where(hit, px[:, :, coverage], 0).astype(numpy.float64)
            matte = part if matte is None else matte + part
    return matte


blender = blender_matte()
specification = specification_matte()
difference = float(numpy.abs(blender - specification).max())
print(json.dumps({"layer": layer, "names": names, "pixels": int(blender.size),
                  "blender_matte_sum": round(float(blender.sum()), 4),
                  "specification_matte_sum": round(float(specification.sum()), 4),
                  "max_pixel_difference": difference}))
sys.exit(0 if difference <= 1e-4 else 1)
