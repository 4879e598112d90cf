# SPDX-License-Identifier: Apache-2.0
"""Builds a Cambium scene export (`convergence --export-scene`) in Blender 3.4 for Cycles.

A measuring tool, not part of Cambium: run inside Blender, e.g.

    blender -b --factory-startup --python benchmarks/cycles/import_scene.py -- SCENE.json OUT.png [SPP]

which renders one image (PNG, the background composited in) to look at beside Cambium's.
cycles_convergence.py imports build_scene() from here.

What is the same as in Cambium: the geometry (triangles with their vertex normals; cone
segments as round Cycles curves through the same keys and radii, each segment a curve of
its own; prototypes placed by their instances, flattened into one mesh), the decoded
materials (diffuse, translucency, specular, emission, cpfg's ambient term seen by
camera rays only), the directional lights (delta suns of the same irradiance), the
uniform ambient environment seen by escaping secondary rays, the orthographic camera
and the path length. Approximations: the normalized Phong lobe becomes Cycles' GGX
glossy lobe of about the same width; cubic Hermite segments are sampled into Catmull-Rom
curves (8 pieces each); curve textures are looked up at v along the axis and an angle
about it measured from an arbitrary reference, not Cambium's s.
"""
import json
import math
import sys

import bpy
import numpy as np
from mathutils import Matrix

INHERIT = 0xFFFF
HERMITE_PIECES = 8


# ---- Geometry -------------------------------------------------------------------------

def _arr(values, width, dtype=np.float64):
    return np.asarray(values, dtype=dtype).reshape(-1, width) if width > 1 else \
        np.asarray(values, dtype=dtype)


def _placed_meshes(scene):
    """Every triangle of the scene and its placed prototypes: positions, normals, uvs,
    triangles, material, texture (numpy arrays)."""
    parts = []

    def add(mesh, transform=None, material=None, texture=None):
        if not mesh["material"]:
            return
        pos = _arr(mesh["positions"], 3)
        nrm = _arr(mesh["normals"], 3)
        uvs = _arr(mesh["uvs"], 2)
        tri = _arr(mesh["triangles"], 3, np.int64)
        mat = _arr(mesh["material"], 1, np.int64)
        tex = _arr(mesh["texture"], 1, np.int64) if mesh["texture"] else np.full(len(mat), -1)
        if transform is not None:
            m = np.asarray(transform, dtype=np.float64).reshape(4, 3).T  # columns: x y z t
            linear, offset = m[:, :3], m[:, 3]
            pos = pos @ linear.T + offset
            nrm = nrm @ np.linalg.inv(linear)  # normals by the inverse transpose
            length = np.linalg.norm(nrm, axis=1, keepdims=True)
            nrm = np.divide(nrm, length, out=np.zeros_like(nrm), where=length > 0)
            mat = np.where(mat == INHERIT, material, mat)
            tex = np.where(tex < 0, texture, tex)
        parts.append((pos, nrm, uvs, tri, mat, tex))

    add(scene["geometry"]["mesh"])
    for inst in scene["instances"]:
        proto = scene["prototypes"][inst["prototype"]]["geometry"]
        for kind in ("lines", "curves", "spheres", "discs"):
            if proto[kind]["material"]:
                raise SystemExit(f"import_scene: prototypes with {kind} are not supported")
        add(proto["mesh"], inst["transform"], inst["material"], inst["texture"])
    for kind in ("spheres", "discs"):
        if scene["geometry"][kind]["material"]:
            raise SystemExit(f"import_scene: {kind} are not supported yet")
    if not parts:
        return None
    offsets = np.cumsum([0] + [len(p[0]) for p in parts])
    return (np.concatenate([p[0] for p in parts]), np.concatenate([p[1] for p in parts]),
            np.concatenate([p[2] for p in parts]),
            np.concatenate([p[3] + offsets[i] for i, p in enumerate(parts)]),
            np.concatenate([p[4] for p in parts]), np.concatenate([p[5] for p in parts]))


def _segments(scene):
    """Every cone and Hermite segment as a chain of (x, y, z, radius) points with its
    material, texture and per-point v: a list of (points[k, 4], v[k], material, texture)."""
    out = []
    lines = scene["geometry"]["lines"]
    keys = _arr(lines["keys"], 4)
    v = np.asarray(lines["v"]) if lines["v"] else np.zeros(len(keys))
    for i, first in enumerate(lines["segments"]):
        tex = lines["texture"][i] if lines["texture"] else -1
        out.append((keys[first:first + 2], v[first:first + 2], lines["material"][i], tex))
    curves = scene["geometry"]["curves"]
    pts = _arr(curves["points"], 4)
    tan = _arr(curves["tangents"], 4)
    v = np.asarray(curves["v"]) if curves["v"] else np.zeros(len(pts))
    t = np.linspace(0.0, 1.0, HERMITE_PIECES + 1)[:, None]
    h00, h10 = 2 * t**3 - 3 * t**2 + 1, t**3 - 2 * t**2 + t
    h01, h11 = -2 * t**3 + 3 * t**2, t**3 - t**2
    for i, first in enumerate(curves["segments"]):
        p0, p1, m0, m1 = pts[first], pts[first + 1], tan[first], tan[first + 1]
        chain = h00 * p0 + h10 * m0 + h01 * p1 + h11 * m1
        tex = curves["texture"][i] if curves["texture"] else -1
        out.append((chain, (1 - t[:, 0]) * v[first] + t[:, 0] * v[first + 1],
                    curves["material"][i], tex))
    return out


# ---- Materials ------------------------------------------------------------------------

def _roughness(exponent):
    """The GGX roughness whose lobe is about as wide as a normalized Phong lobe of this
    exponent: Phong n ~ Blinn-Phong 4n, Beckmann alpha = sqrt(2 / (4n + 2)), Cycles'
    roughness = sqrt(alpha)."""
    return math.sqrt(math.sqrt(2.0 / (4.0 * max(exponent, 0.0) + 2.0)))


def _material_table(scene):
    """Per cpfg material: the attribute values the shader reads."""
    table = []
    for m in scene["materials"]:
        if m["opacity"] < 1:
            raise SystemExit("import_scene: transparent materials are not supported yet")
        table.append({"kd": m["diffuse"], "ks": m["specular"], "trans": m["translucency"],
                      "rough": _roughness(m["exponent"]), "em": m["emission"],
                      "glow": m["ambient_glow"]})
    return table


def _emission_class(m):
    """0: no emission; 1: cpfg's ambient term only (camera rays; never a light);
    2: emissive (sampled as a light, as Cambium's area lights)."""
    if any(m["em"]):
        return 2
    return 1 if any(m["glow"]) else 0


def _shader(name, emission_class, texture=None, unlit=False, emitters_as_lights=True):
    """The one shader of every surface: Cambium's three lobes from attributes, plus
    emission (class 2) and the ambient term for camera rays (classes 1 and 2). Unlit
    (`render mode: filled`): the diffuse colour plus emission, and the path ends there.
    emitters_as_lights=False: emissive surfaces are found by BSDF rays only."""
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    nt = mat.node_tree
    nt.nodes.clear()
    n = nt.nodes.new
    link = nt.links.new

    def attr(name):
        node = n("ShaderNodeAttribute")
        node.attribute_name = name
        return node

    def math_node(op, a, b):
        node = n("ShaderNodeMath")
        node.operation = op
        for socket, value in zip(node.inputs, (a, b)):
            if isinstance(value, (int, float)):
                socket.default_value = value
            else:
                link(value, socket)
        return node.outputs[0]

    def scale(colour, factor):
        node = n("ShaderNodeVectorMath")
        node.operation = "SCALE"
        link(colour, node.inputs[0])
        link(factor, node.inputs["Scale"])
        return node.outputs[0]

    kd = attr("kd").outputs["Color"]
    if texture is not None:
        image = n("ShaderNodeTexImage")
        image.image = bpy.data.images.load(texture["file"], check_existing=True)
        image.interpolation = "Linear" if texture["linear_filter"] else "Closest"
        uv = _curve_texture_coordinates(nt) if texture.get("on_curves") else \
            n("ShaderNodeUVMap").outputs[0]
        link(uv, image.inputs["Vector"])
        if texture["decal"]:
            kd = image.outputs["Color"]
        else:
            mul = n("ShaderNodeMixRGB")
            mul.blend_type = "MULTIPLY"
            mul.inputs["Fac"].default_value = 1.0
            link(kd, mul.inputs[1])
            link(image.outputs["Color"], mul.inputs[2])
            kd = mul.outputs[0]
    def emission_plus(colour):
        """An emission shader of the `em` attribute plus `colour`."""
        total = n("ShaderNodeVectorMath")
        total.operation = "ADD"
        link(colour, total.inputs[0])
        link(attr("em").outputs["Color"], total.inputs[1])
        emission = n("ShaderNodeEmission")
        link(total.outputs[0], emission.inputs["Color"])
        return emission.outputs[0]

    if unlit:
        link(emission_plus(kd), n("ShaderNodeOutputMaterial").inputs["Surface"])
        mat.cycles.sample_as_light = False
        return mat
    ks = attr("ks").outputs["Color"]
    sep = n("ShaderNodeSeparateColor")
    link(ks, sep.inputs[0])
    max_ks = math_node("MAXIMUM", math_node("MAXIMUM", sep.outputs[0], sep.outputs[1]),
                       sep.outputs[2])
    keep = math_node("SUBTRACT", 1.0, max_ks)
    trans = attr("trans").outputs["Fac"]
    diffuse_share = math_node("MULTIPLY", keep, math_node("SUBTRACT", 1.0, trans))
    translucent_share = math_node("MULTIPLY", keep, trans)

    diffuse = n("ShaderNodeBsdfDiffuse")
    link(scale(kd, diffuse_share), diffuse.inputs["Color"])
    translucent = n("ShaderNodeBsdfTranslucent")
    link(scale(kd, translucent_share), translucent.inputs["Color"])
    glossy = n("ShaderNodeBsdfGlossy")
    glossy.distribution = "GGX"
    link(ks, glossy.inputs["Color"])
    link(attr("rough").outputs["Fac"], glossy.inputs["Roughness"])
    add1 = n("ShaderNodeAddShader")
    link(diffuse.outputs[0], add1.inputs[0])
    link(translucent.outputs[0], add1.inputs[1])
    surface = n("ShaderNodeAddShader")
    link(add1.outputs[0], surface.inputs[0])
    link(glossy.outputs[0], surface.inputs[1])
    result = surface.outputs[0]
    if emission_class:
        camera = n("ShaderNodeLightPath").outputs["Is Camera Ray"]
        glow = scale(attr("glow").outputs["Color"], camera)
        add = n("ShaderNodeAddShader")
        link(result, add.inputs[0])
        link(emission_plus(glow), add.inputs[1])
        result = add.outputs[0]
    out = n("ShaderNodeOutputMaterial")
    link(result, out.inputs["Surface"])
    # Only truly emissive surfaces are lights; the ambient term lights nothing (Cambium).
    mat.cycles.sample_as_light = emission_class == 2 and emitters_as_lights
    return mat


def _curve_texture_coordinates(nt):
    """(s, v) on a curve: v from the per-point attribute, s the angle of the normal about
    the tangent (from an arbitrary reference direction) over 2 pi."""
    n = nt.nodes.new
    link = nt.links.new
    geometry = n("ShaderNodeNewGeometry")
    ref = n("ShaderNodeVectorMath")
    ref.operation = "CROSS_PRODUCT"
    link(geometry.outputs["Tangent"], ref.inputs[0])
    ref.inputs[1].default_value = (0.577, 0.577, 0.577)
    b1 = n("ShaderNodeVectorMath")
    b1.operation = "NORMALIZE"
    link(ref.outputs[0], b1.inputs[0])
    b2 = n("ShaderNodeVectorMath")
    b2.operation = "CROSS_PRODUCT"
    link(geometry.outputs["Tangent"], b2.inputs[0])
    link(b1.outputs[0], b2.inputs[1])
    dots = []
    for basis in (b2, b1):
        d = n("ShaderNodeVectorMath")
        d.operation = "DOT_PRODUCT"
        link(geometry.outputs["Normal"], d.inputs[0])
        link(basis.outputs[0], d.inputs[1])
        dots.append(d.outputs["Value"])
    angle = n("ShaderNodeMath")
    angle.operation = "ARCTAN2"
    link(dots[0], angle.inputs[0])
    link(dots[1], angle.inputs[1])
    s = n("ShaderNodeMath")
    s.operation = "MULTIPLY_ADD"
    link(angle.outputs[0], s.inputs[0])
    s.inputs[1].default_value = 0.5 / math.pi
    s.inputs[2].default_value = 0.5
    v = n("ShaderNodeAttribute")
    v.attribute_name = "v"
    combine = n("ShaderNodeCombineXYZ")
    link(s.outputs[0], combine.inputs[0])
    link(v.outputs["Fac"], combine.inputs[1])
    return combine.outputs[0]


def _set_attributes(data, domain, table, material_of_element):
    """Per-element copies of the material table's values as generic attributes."""
    for name in ("kd", "ks", "glow", "em"):
        values = np.asarray([table[m][name] + [1.0] for m in material_of_element],
                            dtype=np.float32)
        data.attributes.new(name, "FLOAT_COLOR", domain).data.foreach_set(
            "color", values.ravel())
    for name in ("trans", "rough"):
        values = np.asarray([table[m][name] for m in material_of_element], dtype=np.float32)
        data.attributes.new(name, "FLOAT", domain).data.foreach_set("value", values)


# ---- Building -------------------------------------------------------------------------

def _build_mesh(scene, table, shaders):
    meshes = _placed_meshes(scene)
    if meshes is None:
        return
    pos, nrm, uvs, tri, mat, tex = meshes
    if (tex >= 0).any():
        raise SystemExit("import_scene: textured triangles are not supported yet")
    me = bpy.data.meshes.new("plant_triangles")
    me.vertices.add(len(pos))
    me.vertices.foreach_set("co", pos.astype(np.float32).ravel())
    me.loops.add(3 * len(tri))
    me.loops.foreach_set("vertex_index", tri.astype(np.int32).ravel())
    me.polygons.add(len(tri))
    me.polygons.foreach_set("loop_start", np.arange(0, 3 * len(tri), 3, dtype=np.int32))
    me.polygons.foreach_set("loop_total", np.full(len(tri), 3, dtype=np.int32))
    smooth = scene["shading"] == "shaded"  # flat: every facet lit with its own normal
    me.polygons.foreach_set("use_smooth", np.full(len(tri), smooth, dtype=bool))
    classes = np.asarray([_emission_class(table[m]) for m in mat], dtype=np.int32)
    me.polygons.foreach_set("material_index", classes)
    me.update(calc_edges=True)
    if smooth:  # Cambium's vertex normals as custom split normals (its shading normals)
        me.use_auto_smooth = True
        me.normals_split_custom_set_from_vertices(nrm.astype(np.float32).tolist())
    _set_attributes(me, "FACE", table, mat)
    for c in range(3):
        me.materials.append(shaders[(c, None)])
    obj = bpy.data.objects.new("plant_triangles", me)
    bpy.context.scene.collection.objects.link(obj)


def _curves_node_group(source, material):
    """Geometry nodes for a hair-curves object: the edges of the mesh object `source`
    become curves with its `key_radius` attribute and `material` (Cycles renders a Curves object's curves
    as round curves; those a mesh object's modifier makes are not rendered)."""
    group = bpy.data.node_groups.new("segments_to_curves", "GeometryNodeTree")
    group.inputs.new("NodeSocketGeometry", "Geometry")
    group.outputs.new("NodeSocketGeometry", "Geometry")
    n = group.nodes.new
    link = group.links.new
    out = n("NodeGroupOutput")
    info = n("GeometryNodeObjectInfo")
    info.inputs["Object"].default_value = source
    to_curve = n("GeometryNodeMeshToCurve")
    radius = n("GeometryNodeInputNamedAttribute")
    radius.data_type = "FLOAT"
    radius.inputs["Name"].default_value = "key_radius"
    set_radius = n("GeometryNodeSetCurveRadius")
    link(info.outputs["Geometry"], to_curve.inputs["Mesh"])
    link(to_curve.outputs[0], set_radius.inputs["Curve"])
    # The Named Attribute node has one "Attribute" output per type; the float one is shown.
    value = next(o for o in radius.outputs if o.name == "Attribute" and o.enabled)
    link(value, set_radius.inputs["Radius"])
    set_material = n("GeometryNodeSetMaterial")
    set_material.inputs["Material"].default_value = material
    link(set_radius.outputs[0], set_material.inputs["Geometry"])
    link(set_material.outputs[0], out.inputs[0])
    return group


def _build_curves(scene, table, shaders):
    """Each segment a curve of its own (cones: 2 points; Hermite: sampled), one object
    per shader so each carries one material."""
    groups = {}
    for chain, v, material, texture in _segments(scene):
        key = (_emission_class(table[material]), texture if texture >= 0 else None)
        groups.setdefault(key, []).append((chain, v, material))
    for key, segments in groups.items():
        points = np.concatenate([c for c, _, _ in segments])
        counts = [len(c) for c, _, _ in segments]
        starts = np.cumsum([0] + counts[:-1])
        edges = np.concatenate([np.stack([np.arange(s, s + k - 1), np.arange(s + 1, s + k)], 1)
                                for s, k in zip(starts, counts)])
        me = bpy.data.meshes.new("plant_segments")
        me.vertices.add(len(points))
        me.vertices.foreach_set("co", points[:, :3].astype(np.float32).ravel())
        me.edges.add(len(edges))
        me.edges.foreach_set("vertices", edges.astype(np.int32).ravel())
        me.attributes.new("key_radius", "FLOAT", "POINT").data.foreach_set(
            "value", points[:, 3].astype(np.float32))
        me.attributes.new("v", "FLOAT", "POINT").data.foreach_set(
            "value", np.concatenate([v for _, v, _ in segments]).astype(np.float32))
        _set_attributes(me, "POINT", table,
                        [m for c, _, m in segments for _ in range(len(c))])
        me.update()
        source = bpy.data.objects.new("plant_segments_source", me)  # not in the scene
        hair = bpy.data.hair_curves.new("plant_segments")
        hair.materials.append(shaders[key])
        obj = bpy.data.objects.new("plant_segments", hair)
        bpy.context.scene.collection.objects.link(obj)
        obj.modifiers.new("curves", "NODES").node_group = _curves_node_group(source, shaders[key])


def _build_camera(scene):
    cam = scene["camera"]
    data = bpy.data.cameras.new("camera")
    forward = np.asarray(cam["forward"])
    origin = np.asarray(cam["origin"])
    size = max(scene["width"], scene["height"]) * cam["pixel_size"]
    if cam["projection"] == "parallel":
        data.type = "ORTHO"
        data.ortho_scale = size
        # Rays start behind everything, as Cambium's parallel rays do.
        back = float(np.linalg.norm(origin - np.asarray(cam["scene_centre"]))) + \
            2 * cam["scene_radius"] + 1
    else:
        data.type = "PERSP"
        data.sensor_fit = "VERTICAL"
        data.angle_y = cam["fov_y_rad"]
        back = 0.0
    near = cam["clip_near"] if cam["clip_near"] is not None else -back
    far = cam["clip_far"] if cam["clip_far"] is not None else back + 4 * cam["scene_radius"]
    if scene.get("stage", {}).get("ground"):
        far = back + 4000 * cam["scene_radius"]  # the ground reaches the horizon in Cambium
    data.clip_start = max(1e-4 * size, back + near)
    data.clip_end = back + far
    obj = bpy.data.objects.new("camera", data)
    bpy.context.scene.collection.objects.link(obj)
    basis = np.column_stack([cam["right"], cam["up"], -forward])
    location = origin - forward * back
    matrix = np.eye(4)
    matrix[:3, :3] = basis
    matrix[:3, 3] = location
    obj.matrix_world = Matrix(matrix.tolist())
    bpy.context.scene.camera = obj


# A Cycles sun of strength S gives a surface facing it irradiance S (W/m^2); Cambium's
# light of colour c gives pi c.
SUN_STRENGTH_PER_COLOUR = math.pi


def _add_sun(name, toward_light, irradiance, angle=0.0):
    """A Cycles sun giving `irradiance` (RGB) to a surface facing it, shining from
    `toward_light`, its disk `angle` radians across."""
    data = bpy.data.lights.new(name, "SUN")
    data.angle = angle
    peak = max(irradiance)
    data.color = [c / peak for c in irradiance] if peak > 0 else (0, 0, 0)
    data.energy = peak
    data.cycles.cast_shadow = True
    obj = bpy.data.objects.new(name, data)
    bpy.context.scene.collection.objects.link(obj)
    z = np.asarray(toward_light, dtype=np.float64)  # the sun shines along -z
    z /= np.linalg.norm(z)
    x = np.cross([0.0, 1.0, 0.0] if abs(z[1]) < 0.9 else [1.0, 0.0, 0.0], z)
    x /= np.linalg.norm(x)
    y = np.cross(z, x)
    matrix = np.eye(4)
    matrix[:3, :3] = np.column_stack([x, y, z])
    obj.matrix_world = Matrix(matrix.tolist())


def _build_lights(scene):
    for i, light in enumerate(scene["lights"]):
        if light["kind"] != "directional":
            raise SystemExit("import_scene: only directional lights are supported yet")
        _add_sun(f"sun{i}", light["toward_light"],
                 [SUN_STRENGTH_PER_COLOUR * c for c in light["colour"]])


def _build_sky_sun(scene):
    """The --sky's sun (its dome is the stage's map): a lamp of the disk's solid angle
    whose irradiance at normal incidence is the disk's radiance times that solid angle."""
    sun = scene["stage"].get("sun")
    if sun is None:
        return
    omega = sun["solid_angle"]
    angle = 2 * math.acos(1 - omega / (2 * math.pi))
    _add_sun("sky_sun", sun["toward_sun"], [omega * r for r in sun["radiance"]], angle)


def _build_world(scene):
    world = bpy.data.worlds.new("ambient")
    world.use_nodes = True
    nt = world.node_tree
    nt.nodes.clear()
    mix = nt.nodes.new("ShaderNodeMixRGB")
    mix.inputs[1].default_value = list(scene["ambient_radiance"]) + [1.0]
    mix.inputs[2].default_value = list(scene["background"]) + [1.0]
    nt.links.new(nt.nodes.new("ShaderNodeLightPath").outputs["Is Camera Ray"], mix.inputs[0])
    background = nt.nodes.new("ShaderNodeBackground")
    nt.links.new(mix.outputs[0], background.inputs["Color"])
    out = nt.nodes.new("ShaderNodeOutputWorld")
    nt.links.new(background.outputs[0], out.inputs["Surface"])
    # Cambium leaves a uniform environment to BSDF sampling alone.
    world.cycles.sampling_method = "NONE"
    bpy.context.scene.world = world


def _build_staged_world(scene):
    """A staged still's environment: the lat-long map of `stage.environment` (Cambium's
    --env: nearest texel; the scene is turned to the map's frame, _turn_to_map_frame),
    importance-sampled as Cambium samples it;
    camera rays see it too where Cambium shows it (--background env, or any perspective
    view), else the view's background. Without a map, the uniform ambient (_build_world)."""
    stage = scene["stage"]
    env = stage["environment"]
    if env is None:
        _build_world(scene)
        return
    if env["rotation_deg"]:
        raise SystemExit("import_scene: a rotated --env map is not supported yet")
    world = bpy.data.worlds.new("environment")
    world.use_nodes = True
    nt = world.node_tree
    nt.nodes.clear()
    n, link = nt.nodes.new, nt.links.new
    texture = n("ShaderNodeTexEnvironment")
    texture.image = bpy.data.images.load(env["map"], check_existing=True)
    texture.image.colorspace_settings.name = "Linear"
    texture.interpolation = "Closest"
    texture.projection = "EQUIRECTANGULAR"
    colour = texture.outputs["Color"]
    if not (stage["backdrop"] == "environment" or scene["camera"]["projection"] == "perspective"):
        mix = n("ShaderNodeMixRGB")
        link(colour, mix.inputs[1])
        mix.inputs[2].default_value = list(scene["background"]) + [1.0]
        link(n("ShaderNodeLightPath").outputs["Is Camera Ray"], mix.inputs[0])
        colour = mix.outputs[0]
    background = n("ShaderNodeBackground")
    background.inputs["Strength"].default_value = env["scale"]
    link(colour, background.inputs["Color"])
    link(background.outputs[0], n("ShaderNodeOutputWorld").inputs["Surface"])
    world.cycles.sampling_method = "MANUAL"  # one importance cell per texel, as Cambium
    world.cycles.sample_map_resolution = texture.image.size[0]
    bpy.context.scene.world = world


# Cambium's frame is +y up and its map's u = 0 along +z, a quarter turn along -x
# (render/environment.h); Blender's equirectangular lookup is +z up, u = 0 along -x, a
# quarter turn along +y: Cambium's (x, y, z) is Blender's (-z, -x, y).
CAMBIUM_TO_MAP_FRAME = Matrix(((0, 0, -1, 0), (-1, 0, 0, 0), (0, 1, 0, 0), (0, 0, 0, 1)))


def _turn_to_map_frame():
    """Turns the whole scene (geometry, camera, lights) into Blender's map frame rather
    than turning the map's lookup: Cycles tabulates the world for importance sampling
    in its own lat-long frame, which then lines up with the map's texels (a turned lookup
    splits the small sun among the table's cells, and the sun then comes as fireflies)."""
    for obj in bpy.context.scene.collection.objects:
        obj.matrix_world = CAMBIUM_TO_MAP_FRAME @ obj.matrix_world


def _build_ground(scene):
    """Cambium's --ground: the plane y = height, infinite there; here a square 2000 scene
    radii wide under the plant (its far edge lies well under a pixel from the horizon),
    diffuse of the decoded ground colour (unlit views: that colour), seen from both sides."""
    ground = scene["stage"]["ground"]
    if ground is None:
        return
    cx, _, cz = scene["camera"]["scene_centre"]
    half = 1000.0 * max(scene["camera"]["scene_radius"], 1e-3)
    y = ground["height"]
    me = bpy.data.meshes.new("ground")
    me.from_pydata([(cx - half, y, cz - half), (cx + half, y, cz - half),
                    (cx + half, y, cz + half), (cx - half, y, cz + half)], [],
                   [(0, 3, 2, 1)])  # counter-clockwise seen from +y: the normal is +y
    me.update()
    mat = bpy.data.materials.new("ground")
    mat.use_nodes = True
    nt = mat.node_tree
    nt.nodes.clear()
    # An unlit view (`render mode: filled`) draws the ground in its flat colour too.
    unlit = scene["shading"] == "unlit"
    surface = nt.nodes.new("ShaderNodeEmission" if unlit else "ShaderNodeBsdfDiffuse")
    surface.inputs["Color"].default_value = list(ground["diffuse"]) + [1.0]
    nt.links.new(surface.outputs[0], nt.nodes.new("ShaderNodeOutputMaterial").inputs["Surface"])
    mat.cycles.sample_as_light = False
    me.materials.append(mat)
    obj = bpy.data.objects.new("ground", me)
    bpy.context.scene.collection.objects.link(obj)


def configure(scene, threads=2):
    """Cycles as Cambium renders: CPU, fixed thread count, no adaptive sampling, no
    denoising or clamping, a one-pixel box filter, the same path length."""
    s = bpy.context.scene
    s.render.engine = "CYCLES"
    s.cycles.device = "CPU"
    s.render.resolution_x = scene["width"]
    s.render.resolution_y = scene["height"]
    s.render.resolution_percentage = 100
    s.render.threads_mode = "FIXED"
    s.render.threads = threads
    s.render.use_persistent_data = True
    s.render.film_transparent = True
    s.cycles.use_adaptive_sampling = False
    s.cycles.use_denoising = False
    s.cycles.sample_clamp_direct = 0.0
    s.cycles.sample_clamp_indirect = 0.0
    s.cycles.blur_glossy = 0.0
    s.cycles.pixel_filter_type = "BOX"
    s.cycles.filter_width = 1.0
    bounces = scene["max_depth"] - 1  # Cambium counts path segments
    s.cycles.max_bounces = bounces
    for kind in ("diffuse", "glossy", "transmission", "volume"):
        setattr(s.cycles, f"{kind}_bounces", bounces)
    s.cycles.transparent_max_bounces = bounces
    s.cycles.caustics_reflective = True
    s.cycles.caustics_refractive = True
    s.cycles_curves.shape = "THICK"
    s.view_settings.view_transform = "Standard"
    s.view_settings.look = "None"
    s.render.image_settings.file_format = "OPEN_EXR"
    s.render.image_settings.color_depth = "32"
    s.render.image_settings.color_mode = "RGBA"


def build_scene(path, threads=2, emitters_as_lights=True):
    """Empties Blender's scene and builds the exported one in it. emitters_as_lights:
    emissive primitives are sampled as lights (as Cambium's area lights are)."""
    with open(path) as f:
        scene = json.load(f)
    if scene.get("format") != "cambium-scene-1":
        raise SystemExit(f"import_scene: {path} is not a cambium-scene-1 export")
    if scene["line_radius_in_pixels"]:
        raise SystemExit("import_scene: only lines of world-unit widths are supported")
    bpy.ops.wm.read_factory_settings(use_empty=True)
    table = _material_table(scene)
    unlit = scene["shading"] == "unlit"
    shaders = {}
    for c in range(3):
        shaders[(c, None)] = _shader(f"cambium_{c}", c, unlit=unlit,
                                     emitters_as_lights=emitters_as_lights)
    for i, texture in enumerate(scene["textures"]):
        for c in range(3):
            shaders[(c, i)] = _shader(f"cambium_{c}_tex{i}", c, dict(texture, on_curves=True),
                                      unlit, emitters_as_lights)
    _build_mesh(scene, table, shaders)
    _build_curves(scene, table, shaders)
    _build_camera(scene)
    _build_lights(scene)
    if "stage" in scene:
        _build_ground(scene)
        _build_staged_world(scene)
        if scene["stage"]["environment"] is not None:
            _build_sky_sun(scene)
            _turn_to_map_frame()
    else:
        _build_world(scene)
    configure(scene, threads)
    if "stage" in scene:  # the ground and the map fill the frame: an opaque film
        bpy.context.scene.render.film_transparent = False
    return scene


def render_exr(path, spp, seed=0):
    s = bpy.context.scene
    s.cycles.samples = spp
    s.cycles.seed = seed
    s.render.filepath = path
    bpy.ops.render.render(write_still=True)


def read_exr(path):
    """RGBA floats, rows bottom to top (Blender's order)."""
    image = bpy.data.images.load(path, check_existing=False)
    image.colorspace_settings.name = "Non-Color"
    pixels = np.empty(image.size[0] * image.size[1] * 4, dtype=np.float32)
    image.pixels.foreach_get(pixels)
    bpy.data.images.remove(image)
    return pixels.reshape(-1, 4)


def write_png(rgba, width, height, background, path):
    """The linear premultiplied image over the background, sRGB-encoded, as a PNG."""
    rgb = rgba[:, :3] + (1 - rgba[:, 3:4]) * np.asarray(background, dtype=np.float32)
    rgb = np.clip(rgb, 0, 1)
    srgb = np.where(rgb <= 0.0031308, 12.92 * rgb, 1.055 * np.power(rgb, 1 / 2.4) - 0.055)
    image = bpy.data.images.new("preview", width, height, alpha=True)
    image.colorspace_settings.name = "Non-Color"
    out = np.concatenate([srgb, np.ones((len(srgb), 1), np.float32)], 1)
    image.pixels.foreach_set(out.ravel())
    image.filepath_raw = path
    image.file_format = "PNG"
    image.save()


if __name__ == "__main__":
    args = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    if len(args) < 2:
        raise SystemExit("usage: blender -b --factory-startup --python import_scene.py -- "
                         "SCENE.json OUT.png [SPP]")
    exported = build_scene(args[0])
    exr = args[1] + ".exr"
    render_exr(exr, int(args[2]) if len(args) > 2 else 64)
    write_png(read_exr(exr), exported["width"], exported["height"], exported["background"],
              args[1])
