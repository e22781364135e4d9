#!/usr/bin/env python3
"""Build penumbra test scenes in the real Blender (PyPI package `bpy`) and write them with
Blender's own exporters.

    python3 -m venv /work/venv-bpy
    /work/venv-bpy/bin/pip install -r scripts/requirements-blender.txt   # bpy (Python 3.11)
    /work/venv-bpy/bin/python scripts/blender_scenes.py --out tests/data/blender

For each scene (suzanne, text, penumbra_text, primitives, torus_light) the script starts from an empty
factory scene, builds it and writes

* NAME.obj + NAME.mtl  `bpy.ops.wm.obj_export` (defaults: -Z forward, +Y up, modifiers
                       applied, faces not triangulated, no PBR extensions), but without
                       `vt`/`vn` (penumbra ignores them),
* NAME.glb             `bpy.ops.export_scene.gltf` (GLB, default +Y up, cameras, modifiers
                       applied),
* NAME.toml            a penumbra scene file naming NAME.obj, with the Blender camera converted
                       to the exported frame (Blender (x, y, z) -> (x, z, -y)),

and finally README.md with per-mesh statistics measured with bmesh on the evaluated (modifiers
applied) world-space meshes, the cameras, the versions and the file sizes.

Conventions (docs/scenes.md): metres, +y up in the files, lights are meshes whose material
emits (MTL `Ke`, glTF `emissiveFactor` x `KHR_materials_emissive_strength`); a light emits
only from the front (counter-clockwise) side of each face, so quad lights face down (a plane
rotated 180 degrees about X) and closed light meshes keep Blender's outward winding.

Every camera uses sensor_fit = 'VERTICAL' (sensor height 24 mm) and renders at 640 x 480, so its
vertical field of view is 2 atan(12 mm / lens) whatever the aspect, which is what the TOML's
`fov` and the glTF `yfov` hold.
"""

import argparse
import importlib.metadata
import json
import math
import os
import struct
import sys

import bpy  # first: it makes bmesh and mathutils importable
import bmesh
from mathutils import Vector

# Vertical field of view of every camera, degrees.
FOV_DEG = 40.0
SENSOR_HEIGHT_MM = 24.0
RES_X, RES_Y = 640, 480
# A face is counted as non-planar when a vertex is farther than this from its Newell plane.
PLANAR_EPS = 1e-6
# Max Angle of Limited Dissolve on the text. Blender's default, 5 degrees, makes the caps n-gons
# but no face non-planar: the sides are extruded (ruled), so wherever two side quads merge, the
# vertex between them is usually dissolved too and the result is again a planar quad (a chord).
# At 10 degrees a few side quads merge while the vertex between them stays, which gives
# non-planar side n-gons. The caps and the sides are separate pieces (Blender's conversion does
# not share their vertices) and the dissolve simplifies their common outline differently, which
# opens cracks between them. Measured with Blender 5.0.1 and the built-in font (n-gons,
# non-planar faces, widest crack): 5 deg: 17, 0, 0.57 mm; 7: 16, 0, 1.4 mm; 10: 19, 4, 2.3 mm;
# 12: 28, 13, 6.8 mm; 15: 53, 38, 7.9 mm.
TEXT_DISSOLVE_DEG = 10.0


# ---------------------------------------------------------------------------------------------
# Building blocks
# ---------------------------------------------------------------------------------------------


def reset():
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.unit_settings.system = 'METRIC'
    scene.unit_settings.scale_length = 1.0
    scene.render.resolution_x = RES_X
    scene.render.resolution_y = RES_Y
    scene.render.resolution_percentage = 100
    scene.render.pixel_aspect_x = 1.0
    scene.render.pixel_aspect_y = 1.0


def principled(name, base=None, emission=None):
    """A new material with Blender's default Principled BSDF. Only `base` (rgb) and, for lights,
    the emission (white colour, `emission` as Emission Strength) are changed."""
    mat = bpy.data.materials.new(name)
    if mat.node_tree is None:  # Blender < 5 creates materials without nodes
        mat.use_nodes = True
    bsdf = next(n for n in mat.node_tree.nodes if n.type == 'BSDF_PRINCIPLED')
    if base is not None:
        bsdf.inputs["Base Color"].default_value = (*base, 1.0)
        mat.diffuse_color = (*base, 1.0)
    if emission is not None:
        bsdf.inputs["Emission Color"].default_value = (1.0, 1.0, 1.0, 1.0)
        bsdf.inputs["Emission Strength"].default_value = emission
    return mat


def finish(obj, name, mat):
    obj.name = name
    obj.data.name = name
    obj.data.materials.clear()
    obj.data.materials.append(mat)
    return obj


def floor():
    bpy.ops.mesh.primitive_plane_add(size=6.0, location=(0.0, 0.0, 0.0))
    return finish(bpy.context.active_object, "Floor", principled("Floor", base=(0.5, 0.5, 0.5)))


def quad_light(name, location, radiance, size=1.0, tilt_deg=(0.0, 0.0)):
    """A square light facing down: a plane (normal +Z) turned 180 degrees about X, then tilted
    by tilt_deg about the (world) Y and Z axes (Euler XYZ)."""
    rot = (math.pi, math.radians(tilt_deg[0]), math.radians(tilt_deg[1]))
    bpy.ops.mesh.primitive_plane_add(size=size, location=location, rotation=rot)
    return finish(bpy.context.active_object, name, principled(name, emission=radiance))


def add_camera(eye, target):
    """A camera at `eye` looking at `target` with +Z up (no roll)."""
    data = bpy.data.cameras.new("Camera")
    data.sensor_fit = 'VERTICAL'
    data.sensor_height = SENSOR_HEIGHT_MM
    data.lens = 0.5 * SENSOR_HEIGHT_MM / math.tan(math.radians(FOV_DEG) / 2.0)
    cam = bpy.data.objects.new("Camera", data)
    bpy.context.scene.collection.objects.link(cam)
    cam.location = eye
    cam.rotation_euler = (Vector(target) - Vector(eye)).to_track_quat('-Z', 'Y').to_euler()
    bpy.context.scene.camera = cam
    cam["penumbra_eye"] = list(eye)
    cam["penumbra_target"] = list(target)
    return cam


def uv_sphere(radius, location):
    """Blender's UV sphere (32 segments, 16 rings). Blender 5.0.1's primitive_uv_sphere_add
    gives the same vertices and the same faces (each with the same loop order) on every call,
    but in a different face and edge order, so the faces and edges are sorted by their vertex
    indices (nothing else changes) to make the exported files reproducible."""
    bpy.ops.mesh.primitive_uv_sphere_add(radius=radius, location=location)
    obj = bpy.context.active_object
    bm = bmesh.new()
    bm.from_mesh(obj.data)
    for seq in (bm.faces, bm.edges):
        keys = {elem: tuple(sorted(v.index for v in elem.verts)) for elem in seq}
        rank = {k: i for i, k in enumerate(sorted(keys.values()))}
        seq.sort(key=lambda elem: rank[keys[elem]])
    bm.to_mesh(obj.data)
    bm.free()
    return obj


def face_towards(obj, point, front=Vector((0.0, -1.0, 0.0))):
    """Turn obj about Z so that its local `front` direction (Suzanne looks along -Y) points
    horizontally at `point`."""
    d = Vector(point) - obj.location
    want = math.atan2(d.y, d.x)
    have = math.atan2(front.y, front.x)
    obj.rotation_euler.z = want - have


# ---------------------------------------------------------------------------------------------
# Scenes (Blender coordinates: Z up, metres)
# ---------------------------------------------------------------------------------------------


def scene_suzanne():
    floor()
    bpy.ops.mesh.primitive_monkey_add(size=0.8, location=(0.0, 0.0, 0.9))
    monkey = finish(bpy.context.active_object, "Suzanne",
                    principled("Suzanne", base=(0.8, 0.45, 0.2)))
    sub = monkey.modifiers.new("Subdivision", 'SUBSURF')
    sub.levels = 2
    sub.render_levels = 2
    eye = (2.2, -3.0, 1.7)
    face_towards(monkey, eye)
    quad_light("Light", (0.3, 0.2, 2.3), radiance=5.0, tilt_deg=(15.0, 10.0))
    add_camera(eye, (0.0, 0.0, 0.7))
    return "Blender's monkey (Subdivision Surface level 2, applied by the exporters) floating "\
           "about 0.5 m above a 6 m floor, lit by a tilted 1 m quad light."


def extruded_text(body, size, location, rotation, dissolve_deg, base):
    """Blender's built-in font: `body` at `size`, extruded 0.05, centred horizontally,
    converted to a mesh and simplified by Limited Dissolve at `dissolve_deg` over the whole
    mesh. Not merge-by-distance: the caps and the sides stay separate pieces, as Blender makes
    them."""
    bpy.ops.object.text_add(location=location, rotation=rotation)
    text = bpy.context.active_object
    text.data.body = body
    text.data.size = size
    text.data.extrude = 0.05
    text.data.align_x = 'CENTER'
    bpy.ops.object.convert(target='MESH')
    text = bpy.context.active_object
    bpy.ops.object.mode_set(mode='EDIT')
    bpy.ops.mesh.select_all(action='SELECT')
    bpy.ops.mesh.dissolve_limited(angle_limit=math.radians(dissolve_deg))  # delimit NORMAL
    bpy.ops.object.mode_set(mode='OBJECT')
    return finish(text, "Text", principled("Text", base=base))


def scene_text():
    floor()
    extruded_text("BOP8", 0.6, (0.0, 0.0, 0.01), (math.radians(90.0), 0.0, 0.0),
                  TEXT_DISSOLVE_DEG, (0.2, 0.4, 0.8))
    quad_light("Light", (0.2, 0.8, 2.0), radiance=4.0)
    add_camera((1.2, -3.2, 1.4), (0.0, 0.0, 0.3))
    return "The text 'BOP8' (built-in font, size 0.6, extrude 0.05) converted to a mesh "\
           f"(no merge by distance), Limited Dissolve ({TEXT_DISSOLVE_DEG:g} degrees) on the "\
           "whole mesh: non-convex n-gon caps, split by bridge edges at the holes, and "\
           "non-planar side n-gons; upright, baseline 1 cm above the floor (the round "\
           "letters dip to 5.6 mm), lit by a 1 m quad light."


def scene_penumbra_text():
    floor()
    # Lying flat (Blender's text is made in the XY plane), its baseline through the origin
    # (Blender's default vertical alignment), 0.6 m above the floor; Blender's default
    # dissolve angle: keyhole n-gon caps (a bridge edge into each hole), open seams.
    extruded_text("penumbra", 1.0, (0.0, 0.0, 0.6), (0.0, 0.0, 0.0), 5.0, (0.8, 0.8, 0.8))
    light = quad_light("Light", (0.0, 0.0, 2.4), radiance=4.0)
    light.scale = (1.6, 0.8, 1.0)
    bpy.ops.object.transform_apply(location=False, rotation=False, scale=True)
    # The camera of the report: file frame eye (0, 4, 4.8), target (0, 0.3, -0.2).
    add_camera((0.0, -4.8, 4.0), (0.0, 0.2, 0.3))
    return "The word 'penumbra' (built-in font, size 1, extrude 0.05, centred) converted to a "\
           "mesh, Limited Dissolve (5 degrees, Blender's default) on the whole mesh: keyhole "\
           "n-gon caps, open seams; lying flat 0.6 m above the floor under a 1.6 m x 0.8 m "\
           "quad light 2.4 m up."


def scene_primitives():
    floor()
    default = principled("Default")  # nothing changed: Blender's default Principled BSDF
    bpy.ops.mesh.primitive_cube_add(size=0.4, location=(-0.9, 0.3, 0.2))
    finish(bpy.context.active_object, "Cube", default)
    finish(uv_sphere(0.2, (-0.3, 0.5, 0.2)), "UVSphere", default)
    bpy.ops.mesh.primitive_ico_sphere_add(radius=0.2, location=(0.3, 0.5, 0.2))
    finish(bpy.context.active_object, "IcoSphere", default)
    bpy.ops.mesh.primitive_cylinder_add(radius=0.2, depth=0.4, location=(0.9, 0.3, 0.2))
    finish(bpy.context.active_object, "Cylinder", default)
    bpy.ops.mesh.primitive_cone_add(radius1=0.2, depth=0.4, location=(-0.5, -0.4, 0.2))
    finish(bpy.context.active_object, "Cone", default)
    bpy.ops.mesh.primitive_torus_add(major_radius=0.15, minor_radius=0.05,
                                     location=(0.5, -0.4, 0.05))
    finish(bpy.context.active_object, "Torus", default)
    quad_light("Light", (0.0, 0.3, 2.0), radiance=4.0)
    bpy.ops.mesh.primitive_cylinder_add(vertices=24, radius=0.05, depth=1.0,
                                        location=(0.0, -0.6, 1.5),
                                        rotation=(0.0, math.radians(90.0), 0.0))
    finish(bpy.context.active_object, "TubeLight", principled("TubeLight", emission=5.0))
    add_camera((2.0, -3.0, 1.8), (0.0, 0.0, 0.2))
    return "Blender's default primitives (cube, UV sphere, ico sphere, cylinder, cone, torus; "\
           "default segment counts, about 0.4 m) with the untouched default material, lit by "\
           "a 1 m quad light and a horizontal closed cylinder light (r 0.05 m, 1 m, 24 "\
           "segments)."


def scene_torus_light():
    floor()
    bpy.ops.mesh.primitive_torus_add(major_radius=0.5, minor_radius=0.12,
                                     location=(0.0, 0.0, 1.2),
                                     rotation=(math.radians(20.0), 0.0, 0.0))
    finish(bpy.context.active_object, "TorusLight", principled("TorusLight", emission=2.0))
    bpy.ops.mesh.primitive_cube_add(size=0.4, location=(-0.35, 0.15, 0.2))
    finish(bpy.context.active_object, "Cube", principled("Cube", base=(0.7, 0.7, 0.7)))
    finish(uv_sphere(0.25, (0.4, -0.2, 0.25)), "Sphere",
           principled("Sphere", base=(0.7, 0.3, 0.3)))
    add_camera((2.4, -2.8, 1.9), (0.0, 0.0, 0.5))
    return "An emissive torus (major 0.5 m, minor 0.12 m, 48 x 12) tilted 20 degrees, 1.2 m "\
           "above the floor: a closed non-convex light, over a cube and a UV sphere."


SCENES = {
    "suzanne": scene_suzanne,
    "text": scene_text,
    "penumbra_text": scene_penumbra_text,
    "primitives": scene_primitives,
    "torus_light": scene_torus_light,
}


# ---------------------------------------------------------------------------------------------
# Measurements
# ---------------------------------------------------------------------------------------------


def to_export(p):
    """Blender (x, y, z) -> the exporters' default +Y-up frame (x, z, -y)."""
    return (p[0], p[2], -p[1])


def sub3(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def polygon_stats(pts):
    """(Newell area vector, max distance of a vertex from the plane through the centroid with
    the Newell normal, convex?) of one polygon, in f64."""
    n = len(pts)
    area = [0.0, 0.0, 0.0]
    for i in range(n):
        c = cross(pts[i], pts[(i + 1) % n])
        area = [area[0] + 0.5 * c[0], area[1] + 0.5 * c[1], area[2] + 0.5 * c[2]]
    length = math.sqrt(dot(area, area))
    if length == 0.0:
        return area, float("inf"), False
    u = [a / length for a in area]
    cen = [sum(p[k] for p in pts) / n for k in range(3)]
    dev = max(abs(dot(sub3(p, cen), u)) for p in pts)
    convex = True
    for i in range(n):
        a, b, c = pts[i - 1], pts[i], pts[(i + 1) % n]
        turn = dot(cross(sub3(b, a), sub3(c, b)), u)
        if turn < -1e-9:
            convex = False
    return area, dev, convex


def stats_from_faces(faces):
    """faces: list of lists of points. Returns a dict of statistics (no edge counts)."""
    tri = quad = ngon = 0
    nonplanar = nonconvex = 0
    maxdev = 0.0
    triangles = 0
    maxverts = 0
    for pts in faces:
        k = len(pts)
        maxverts = max(maxverts, k)
        tri += k == 3
        quad += k == 4
        ngon += k > 4
        triangles += k - 2
        _, dev, convex = polygon_stats(pts)
        if dev > PLANAR_EPS:
            nonplanar += 1
        maxdev = max(maxdev, dev)
        nonconvex += not convex
    return dict(faces=len(faces), tri=tri, quad=quad, ngon=ngon, max_verts=maxverts,
                triangles=triangles, nonplanar=nonplanar, max_dev=maxdev, nonconvex=nonconvex)


def mesh_stats(obj, depsgraph):
    """Statistics of the evaluated mesh (modifiers applied) in world space, f64 maths."""
    bm = bmesh.new()
    bm.from_object(obj, depsgraph)
    m = obj.matrix_world
    rows = [[m[i][j] for j in range(4)] for i in range(3)]

    def world(co):
        return tuple(rows[i][0] * co.x + rows[i][1] * co.y + rows[i][2] * co.z + rows[i][3]
                     for i in range(3))

    pos = {v.index: world(v.co) for v in bm.verts}
    faces = [[pos[v.index] for v in f.verts] for f in bm.faces]
    s = stats_from_faces(faces)
    boundary = nonmanifold = wire = flipped = 0
    for e in bm.edges:
        k = len(e.link_faces)
        if k == 0:
            wire += 1
        elif k == 1:
            boundary += 1
        elif k > 2:
            nonmanifold += 1
        else:
            l0, l1 = e.link_loops
            if l0.vert == l1.vert:  # both faces run along the edge the same way
                flipped += 1
    # Distinct vertices at identical positions (e.g. unmerged seams).
    seen = {}
    dup = 0
    for p in pos.values():
        key = tuple(round(c, 7) for c in p)
        dup += key in seen
        seen[key] = True
    volume = None
    if boundary == 0 and nonmanifold == 0 and wire == 0:
        vol = 0.0
        for pts in faces:
            for i in range(1, len(pts) - 1):
                vol += dot(pts[0], cross(pts[i], pts[i + 1])) / 6.0
        volume = vol
    s.update(verts=len(bm.verts), edges=len(bm.edges), boundary=boundary,
             nonmanifold=nonmanifold, wire=wire, inconsistent=flipped, dup_verts=dup,
             volume=volume)
    # Front normal of a single-face light, in the exported frame.
    if len(faces) == 1:
        area, _, _ = polygon_stats([to_export(p) for p in faces[0]])
        ln = math.sqrt(dot(area, area))
        s["normal"] = tuple(a / ln for a in area)
    bm.free()
    return s


def seam_report(obj, depsgraph):
    """Where the separately built pieces of a mesh (the text's caps and sides) should meet:
    boundary vertices with no other vertex at their position lie on another piece's boundary
    edge (a T-junction) or off it (a crack; its width is the distance)."""
    bm = bmesh.new()
    bm.from_object(obj, depsgraph)
    bm.transform(obj.matrix_world)
    key = {v.index: tuple(round(c, 6) for c in v.co) for v in bm.verts}
    count = {}
    for k in key.values():
        count[k] = count.get(k, 0) + 1
    bedges = [e for e in bm.edges if len(e.link_faces) == 1]
    lonely = {v.index: tuple(v.co) for e in bedges for v in e.verts if count[key[v.index]] == 1}
    segs = [(tuple(e.verts[0].co), tuple(e.verts[1].co), {key[v.index] for v in e.verts})
            for e in bedges]
    tjunction, gaps = 0, []
    for vi, p in lonely.items():
        best = float("inf")
        for a, b, ends in segs:
            if key[vi] in ends:
                continue
            ab, ap = sub3(b, a), sub3(p, a)
            t = max(0.0, min(1.0, dot(ap, ab) / dot(ab, ab)))
            d = sub3(ap, (ab[0] * t, ab[1] * t, ab[2] * t))
            best = min(best, math.sqrt(dot(d, d)))
        if best < 1e-6:
            tjunction += 1
        else:
            gaps.append(best)
    bm.free()
    return dict(boundary_edges=len(bedges), lonely_verts=len(lonely), tjunction=tjunction,
                cracks=len(gaps), max_crack=max(gaps, default=0.0))


def material_summary(mat):
    bsdf = next(n for n in mat.node_tree.nodes if n.type == 'BSDF_PRINCIPLED')
    out = {}
    for key in ("Base Color", "Metallic", "Roughness", "IOR", "Specular IOR Level",
                "Emission Color", "Emission Strength"):
        v = bsdf.inputs[key].default_value
        out[key] = [round(x, 6) for x in v] if hasattr(v, "__len__") else round(v, 6)
    return out


def read_obj(path):
    """Parse the exported OBJ: objects -> (faces as point lists, usemtl names)."""
    verts = []
    objects = {}
    order = []
    cur = None
    with open(path) as fh:
        for line in fh:
            t = line.split()
            if not t:
                continue
            if t[0] == "v":
                verts.append(tuple(float(x) for x in t[1:4]))
            elif t[0] == "o":
                cur = " ".join(t[1:])
                objects[cur] = {"faces": [], "mtl": []}
                order.append(cur)
            elif t[0] == "usemtl":
                objects[cur]["mtl"].append(" ".join(t[1:]))
            elif t[0] == "f":
                idx = [int(x.split("/")[0]) for x in t[1:]]
                objects[cur]["faces"].append([verts[i - 1 if i > 0 else i] for i in idx])
    return order, objects


def read_mtl(path):
    """{material name: [statements]} of an MTL file."""
    mats, cur = {}, None
    with open(path) as fh:
        for line in fh:
            t = line.strip()
            if not t or t.startswith("#"):
                continue
            if t.startswith("newmtl "):
                cur = t[7:]
                mats[cur] = []
            elif cur is not None:
                mats[cur].append(t)
    return mats


def read_glb_json(path):
    with open(path, "rb") as fh:
        data = fh.read()
    magic, version, length = struct.unpack_from("<III", data, 0)
    assert magic == 0x46546C67 and version == 2 and length == len(data), path
    clen, ctype = struct.unpack_from("<II", data, 12)
    assert ctype == 0x4E4F534A  # JSON
    return json.loads(data[20:20 + clen])


def quat_rotate(q, v):
    """Rotate v by the glTF quaternion q = [x, y, z, w]."""
    x, y, z, w = q
    u = (x, y, z)
    t = cross(u, v)
    t = (2 * t[0], 2 * t[1], 2 * t[2])
    c = cross(u, t)
    return (v[0] + w * t[0] + c[0], v[1] + w * t[1] + c[1], v[2] + w * t[2] + c[2])


# ---------------------------------------------------------------------------------------------
# Output
# ---------------------------------------------------------------------------------------------


def fmt(x):
    """A short decimal for the TOML (f64 round-trip is not needed: 9 significant digits)."""
    s = f"{x:.9g}"
    return "0" if s in ("-0", "0") else s


def vec(v):
    return "[" + ", ".join(fmt(x) for x in v) + "]"


def write_toml(path, name, description, cam_info, object_names):
    lines = [
        f"# penumbra scene '{name}', generated by scripts/blender_scenes.py with Blender "
        f"{bpy.app.version_string}; do not edit.",
        f"# {description}",
        f"# Camera: Blender camera '{cam_info['blender_name']}', sensor_fit VERTICAL, sensor "
        f"height {SENSOR_HEIGHT_MM:g} mm, lens {cam_info['lens']:.6f} mm, {RES_X} x {RES_Y}: "
        f"vertical fov 2 atan(12 / lens) = {cam_info['fov']:.7f} degrees (f32 lens; "
        "written rounded to 1e-5 degrees).",
        "# Blender (x, y, z) -> file (x, z, -y), as the OBJ and glTF exporters write it.",
        "",
        "[camera]",
        f"eye = {vec(cam_info['eye'])}",
        f"target = {vec(cam_info['target'])}",
        "up = [0, 1, 0]",
        f"fov = {fmt(round(cam_info['fov'], 5))}",
        # The glTF camera's aspectRatio: a narrower --size keeps the horizontal field of view.
        f"aspect = {RES_X / RES_Y!r}",
        "",
    ]
    for obj_name in object_names:
        lines += ["[[object]]", f'obj = "{name}.obj"', f'name = "{obj_name}"']
        if obj_name == "Floor":
            lines.append("occluder = false")
        lines.append("")
    with open(path, "w") as fh:
        fh.write("\n".join(lines))


def build(name, out_dir):
    reset()
    description = SCENES[name]()
    scene = bpy.context.scene
    depsgraph = bpy.context.evaluated_depsgraph_get()
    cam = scene.camera
    eye_b = tuple(cam["penumbra_eye"])
    target_b = tuple(cam["penumbra_target"])
    # The camera as Blender holds it (f32): its position and its -Z axis must give the same view.
    loc = cam.matrix_world.translation
    axis = -cam.matrix_world.col[2].xyz
    assert (loc - Vector(eye_b)).length < 1e-6, (loc, eye_b)
    assert axis.angle(Vector(target_b) - loc) < 1e-6, "camera does not look at its target"
    fov = math.degrees(cam.data.angle_y)
    cam_info = dict(blender_name=cam.name, lens=cam.data.lens, fov=fov,
                    blender_eye=eye_b, blender_target=target_b,
                    eye=to_export(eye_b), target=to_export(target_b))

    stats = {}
    seams = {}
    materials = {}
    for obj in sorted(scene.objects, key=lambda o: o.name):
        if obj.type != 'MESH':
            continue
        stats[obj.name] = mesh_stats(obj, depsgraph)
        if stats[obj.name]["dup_verts"]:
            seams[obj.name] = seam_report(obj, depsgraph)
        for slot in obj.material_slots:
            materials[slot.material.name] = material_summary(slot.material)

    obj_path = os.path.join(out_dir, name + ".obj")
    glb_path = os.path.join(out_dir, name + ".glb")
    bpy.ops.wm.obj_export(filepath=obj_path, check_existing=False, export_uv=False,
                          export_normals=False, export_materials=True,
                          export_triangulated_mesh=False, apply_modifiers=True)
    bpy.ops.export_scene.gltf(filepath=glb_path, check_existing=False, export_format='GLB',
                              export_cameras=True, export_apply=True)

    order, objects = read_obj(obj_path)
    file_stats = {o: stats_from_faces(objects[o]["faces"]) for o in order}
    write_toml(os.path.join(out_dir, name + ".toml"), name, description, cam_info, order)
    return dict(name=name, description=description, camera=cam_info, stats=stats,
                seams=seams, materials=materials, obj_order=order, obj_stats=file_stats,
                obj_mtl={o: objects[o]["mtl"] for o in order})


def glb_summary(path, cam_info):
    """Cameras, materials and the camera node of a GLB, and the camera direction check."""
    js = read_glb_json(path)
    cam_nodes = [n for n in js.get("nodes", []) if "camera" in n]
    check = None
    if cam_nodes:
        node = cam_nodes[0]
        fwd = quat_rotate(node.get("rotation", [0, 0, 0, 1]), (0.0, 0.0, -1.0))
        want = sub3(cam_info["target"], cam_info["eye"])
        wl = math.sqrt(dot(want, want))
        cosang = dot(fwd, want) / wl
        pos = node.get("translation", [0, 0, 0])
        check = dict(node=node, forward=fwd,
                     angle_to_toml_deg=math.degrees(math.acos(min(1.0, cosang))),
                     eye_error=math.sqrt(dot(sub3(pos, cam_info["eye"]),
                                             sub3(pos, cam_info["eye"]))))
    return dict(cameras=js.get("cameras"), materials=js.get("materials"),
                extensionsUsed=js.get("extensionsUsed"), asset=js.get("asset"),
                camera_node=check)


def stats_table(results):
    head = ("| scene | object | verts | faces | tri | quad | n-gon (max n) | triangles | "
            "non-planar > 1e-6 | max plane dist | non-convex | boundary edges | "
            "non-manifold edges | closed, volume | light front normal (file frame) |")
    rows = [head, "|" + "---|" * 15]
    for r in results:
        for obj, s in r["stats"].items():
            vol = ("open" if s["volume"] is None else f"closed, {s['volume']:+.5f} m³")
            extra = []
            if s["wire"]:
                extra.append(f"{s['wire']} wire")
            if s["inconsistent"]:
                extra.append(f"{s['inconsistent']} inconsistently wound")
            if s["dup_verts"]:
                extra.append(f"{s['dup_verts']} coincident verts")
            nm = str(s["nonmanifold"]) + (" (" + ", ".join(extra) + ")" if extra else "")
            normal = vec([round(x, 4) for x in s["normal"]]) if "normal" in s else ""
            rows.append(
                f"| {r['name']} | {obj} | {s['verts']} | {s['faces']} | {s['tri']} | "
                f"{s['quad']} | {s['ngon']} ({s['max_verts']}) | {s['triangles']} | "
                f"{s['nonplanar']} | {s['max_dev']:.3g} | {s['nonconvex']} | "
                f"{s['boundary']} | {nm} | {vol} | {normal} |")
    return "\n".join(rows)


def obj_table(results):
    rows = ["| scene | object (`o`) | usemtl | faces | tri | quad | n-gon | triangles | "
            "non-planar > 1e-6 | max plane dist |", "|" + "---|" * 10]
    for r in results:
        for o in r["obj_order"]:
            s = r["obj_stats"][o]
            rows.append(f"| {r['name']} | {o} | {', '.join(r['obj_mtl'][o])} | {s['faces']} | "
                        f"{s['tri']} | {s['quad']} | {s['ngon']} | {s['triangles']} | "
                        f"{s['nonplanar']} | {s['max_dev']:.3g} |")
    return "\n".join(rows)


def write_readme(out_dir, results, glbs, command):
    bpy_version = importlib.metadata.version("bpy")
    files = sorted(f for f in os.listdir(out_dir) if f != "README.md")
    sizes = [(f, os.path.getsize(os.path.join(out_dir, f))) for f in files]
    total = sum(s for _, s in sizes)
    L = [
        "# Blender-exported test scenes",
        "",
        "Generated by `scripts/blender_scenes.py`; do not edit by hand. Regenerate with",
        "",
        "```sh",
        "python3 -m venv /work/venv-bpy && /work/venv-bpy/bin/pip install bpy",
        command,
        "```",
        "",
        f"* Blender `{bpy.app.version_string}` (`bpy.app.version_string`), PyPI `bpy` "
        f"{bpy_version}, Python {sys.version.split()[0]}.",
        "* Each scene starts from `bpy.ops.wm.read_factory_settings(use_empty=True)`.",
        "* The UV spheres' faces and edges are sorted by vertex indices after creation: "
        "Blender 5.0.1's `primitive_uv_sphere_add` gives them in a different order on every "
        "call (same vertices, same faces and loops), which would make the files differ "
        "from run to run.",
        "* `NAME.obj` + `NAME.mtl`: `bpy.ops.wm.obj_export(export_uv=False, "
        "export_normals=False, export_materials=True, export_triangulated_mesh=False, "
        "apply_modifiers=True)`, otherwise defaults (forward -Z, up +Y, scale 1, "
        "`export_pbr_extensions=False`).",
        "* `NAME.glb`: `bpy.ops.export_scene.gltf(export_format='GLB', export_cameras=True, "
        "export_apply=True)`, otherwise defaults (+Y up, normals and UVs written).",
        "* `NAME.toml`: penumbra scene file naming `NAME.obj` (one `[[object]]` per OBJ `o`, "
        "the floor with `occluder = false`) with the Blender camera in the exported frame, "
        "Blender (x, y, z) -> (x, z, -y).",
        "* Units: metres; floor 6 m x 6 m at height 0. Lights are meshes with a Principled BSDF "
        "whose Emission Color is white and whose Emission Strength is the radiance. Quad lights "
        "are planes turned 180 degrees about X (front facing down); closed lights keep "
        "Blender's outward winding.",
        f"* Cameras: sensor_fit `VERTICAL`, sensor height {SENSOR_HEIGHT_MM:g} mm, lens "
        f"12 / tan(20 degrees) mm, render {RES_X} x {RES_Y} (aspect 4:3): vertical fov "
        f"{FOV_DEG:g} degrees (Blender stores the lens as f32; `angle_y` below).",
        "",
        "## Scenes and cameras",
        "",
    ]
    for r, g in zip(results, glbs):
        c = r["camera"]
        L += [f"### {r['name']}", "", r["description"], "",
              f"* Blender camera: location {vec([round(x, 6) for x in c['blender_eye']])}, "
              f"looking at {vec(c['blender_target'])}, lens {c['lens']:.6f} mm, "
              f"angle_y {c['fov']:.7f} degrees.",
              f"* Exported frame (TOML): eye {vec([round(x, 6) for x in c['eye']])}, target "
              f"{vec(c['target'])}, up [0, 1, 0], fov {round(c['fov'], 5):g}."]
        for obj, sr in r["seams"].items():
            L.append(f"* `{obj}` is built of separate pieces (caps and sides share positions, "
                     f"not vertices): {sr['boundary_edges']} boundary edges; "
                     f"{sr['lonely_verts']} boundary vertices have no twin at their position, "
                     f"{sr['tjunction']} of them on another piece's edge (T-junctions), "
                     f"{sr['cracks']} off it (cracks, up to {sr['max_crack']:.3g} m wide).")
        if g["cameras"]:
            p = g["cameras"][0]["perspective"]
            L.append(f"* glTF: `aspectRatio` {p.get('aspectRatio')}, `yfov` {p.get('yfov')} "
                     f"rad = {math.degrees(p['yfov']):.6f} degrees; the camera node's -z "
                     f"is {g['camera_node']['angle_to_toml_deg']:.2g} degrees from the TOML's "
                     f"view direction, its translation "
                     f"{g['camera_node']['eye_error']:.2g} m from the TOML's eye.")
        L.append("")
    L += [
        "## Meshes as Blender holds them",
        "",
        "Measured with bmesh on the evaluated meshes (modifiers applied) in world space, in f64. "
        "Non-planar: a vertex farther than 1e-6 m from the plane through the face's centroid "
        "with Newell's normal. Non-convex: a corner turning the wrong way about that normal. "
        "Boundary edges have one face, non-manifold edges three or more. Triangles = "
        "sum(n - 2). Volume (closed meshes) is positive when the faces wind outward. Front "
        "normal: Newell normal of a one-face light in the exported (+y up) frame.",
        "",
        stats_table(results),
        "",
        "## Faces as written in the OBJ files",
        "",
        "Parsed back from the OBJ (6 decimals, so a planar face can be off its plane by a few "
        "1e-7 m).",
        "",
        obj_table(results),
        "",
        "## Materials as written",
        "",
        "Every material is a Principled BSDF with Blender's defaults (roughness 0.5, IOR 1.5, "
        "Specular IOR Level 0.5, metallic 0) except the base colour and, for lights, Emission "
        "Color white and Emission Strength = radiance; `Default` (primitives) is untouched. "
        "The OBJ exporter (without PBR extensions) writes Ns = 1000 (1 - roughness)^2 and "
        "Ks = Specular IOR Level; the glTF exporter writes the factors.",
        "",
        "| scene | material | MTL | glTF |",
        "|---|---|---|---|",
    ]
    for r, g in zip(results, glbs):
        mtl = read_mtl(os.path.join(out_dir, r["name"] + ".mtl"))
        gl = {m.get("name"): m for m in g["materials"] or []}
        for m in sorted(mtl):
            js = json.dumps({k: v for k, v in gl.get(m, {}).items() if k != "name"},
                            separators=(",", ":"))
            js = js.replace("0.800000011920929", "0.8").replace("0.699999988079071", "0.7")
            L.append(f"| {r['name']} | {m} | {'; '.join(mtl[m])} | `{js}` |")
    L += [
        "",
        "## Files",
        "",
        "| file | bytes |",
        "|---|---|",
    ]
    L += [f"| {f} | {s} |" for f, s in sizes]
    L += [f"| total (without this README) | {total} |", ""]
    with open(os.path.join(out_dir, "README.md"), "w") as fh:
        fh.write("\n".join(L))
    return sizes, total


def main():
    argv = sys.argv[1:]
    if "--" in argv:  # also runnable as `blender -b -P blender_scenes.py -- --out DIR`
        argv = argv[argv.index("--") + 1:]
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", required=True, help="output directory")
    ap.add_argument("--scene", action="append", choices=sorted(SCENES),
                    help="only these scenes (default: all); README.md is written only "
                         "for a full run")
    args = ap.parse_args(argv)
    os.makedirs(args.out, exist_ok=True)
    names = args.scene or list(SCENES)
    results, glbs = [], []
    for name in names:
        print(f"== {name}", flush=True)
        r = build(name, args.out)
        g = glb_summary(os.path.join(args.out, name + ".glb"), r["camera"])
        results.append(r)
        glbs.append(g)
        print("materials (node values):", json.dumps(r["materials"], indent=1))
        print("glTF cameras:", json.dumps(g["cameras"]))
        print("glTF camera node check:", g["camera_node"])
    print(stats_table(results))
    print(obj_table(results))
    if not args.scene:
        command = "/work/venv-bpy/bin/python scripts/blender_scenes.py --out tests/data/blender"
        sizes, total = write_readme(args.out, results, glbs, command)
        for f, s in sizes:
            print(f"{s:>10}  {f}")
        print(f"{total:>10}  total")


if __name__ == "__main__":
    main()
