"""Build a parabolic CCFL lamp reflector in Blender and export it as glTF 2.0 and OBJ.

Run headless by tools/cad/export-reflector.sh:

    blender -b --factory-startup --python tools/cad/make_reflector.py -- OUT_DIR

Writes OUT_DIR/reflector.gltf (+ reflector.bin) and OUT_DIR/reflector.obj
(+ reflector.mtl): one mesh object, "lamp_reflector_trough", with one material,
"lamp_reflector" (blutrace's tag for it).

The part: a parabolic trough for one CCFL on the x = 0 edge of an edge-lit light guide
(the guide lies at x >= 0, 0 <= z <= T; see scenes/cad-reflector/scene.toml, generated
by tools/scenegen/src/scenes/cad_reflector.rs, whose constants must match these). In the
xz plane the parabola opens towards +x with its focus on the lamp's axis, so lamp light
is sent into the guide's edge nearly parallel to x. Its lips end LIP_GAP short of the
edge face: the upper lip at the guide's front face height (z = T), where a flat strip
continues it to the guide's edge, the lower lip on the reflector sheet (z = -SHEET_GAP).
Flat end caps at y = 0 and y = W close the trough and the air gap in front of it. The
curve is cut into SEGMENTS equal steps of the polar angle about the focus (finest at the
vertex, where it is closest to the lamp); everything is triangulated before export so
both files hold the same triangles.

Conventions: the glTF file is exported with Blender's defaults, as a user would: metres
(Blender's unit and glTF's) and +Y up (Blender turns its Z-up model so that its +Z becomes
glTF's +Y), so scene.toml loads it with blutrace's glTF defaults (units = "m", up = "y")
and no scale or rotation. The OBJ exporter writes 6 decimals, a micrometre in metres, so
the OBJ is written in millimetres (global_scale = 1000) in the model's own axes (z up =
towards the viewer; forward_axis='Y', up_axis='Z', the identity) and scene-obj.toml loads
it with the OBJ defaults (mm, z up). The object's origin is on the lamp axis at
mid-length (x_f, W/2, z_c): the glTF node carries that translation and its vertices are
relative to it; the OBJ exporter writes world coordinates.
"""

import math
import os
import sys

import bmesh
import bpy

# Dimensions in mm (converted to metres below). Keep in sync with
# tools/scenegen/src/scenes/cad_reflector.rs.
T = 6.5  # light guide thickness
W = 120.0  # light guide width along y = reflector length
LIP_GAP = 0.3  # air gap between the lips and the guide's edge face (x = 0)
SHEET_GAP = 0.2  # reflector sheet below the guide's back face
FOCAL = 1.2  # focal length of the parabola
SEGMENTS = 192  # steps along the curve
MM = 1e-3  # metres per mm

Z_LO, Z_HI = -SHEET_GAP, T
ZC = 0.5 * (Z_LO + Z_HI)  # axis height: midway between the lips
HALF = 0.5 * (Z_HI - Z_LO)  # half aperture
X_VERTEX = -LIP_GAP - HALF * HALF / (4.0 * FOCAL)
X_FOCUS = X_VERTEX + FOCAL


def profile():
    """The curve (x, z) from the upper lip round the vertex to the lower lip."""
    # Polar form about the focus: r = 2f / (1 - cos(phi)), phi from +x.
    lip_dx = -LIP_GAP - X_FOCUS
    phi_top = math.atan2(HALF, lip_dx)
    pts = []
    for k in range(SEGMENTS + 1):
        if k == 0:
            pts.append((-LIP_GAP, Z_HI))
        elif k == SEGMENTS:
            pts.append((-LIP_GAP, Z_LO))
        else:
            phi = phi_top + (2.0 * math.pi - 2.0 * phi_top) * k / SEGMENTS
            r = 2.0 * FOCAL / (1.0 - math.cos(phi))
            pts.append((X_FOCUS + r * math.cos(phi), ZC + r * math.sin(phi)))
    return pts


def build_mesh():
    """Vertices (mm, world) and faces of the trough, lip strip and end caps."""
    curve = profile()
    n = len(curve)
    verts = []
    for y in (0.0, W):
        verts += [(x, y, z) for (x, z) in curve]
    # Edge corners of the air gap in front of the lips: (0, y, Z_LO), (0, y, Z_HI).
    gap0 = len(verts)
    verts += [(0.0, 0.0, Z_LO), (0.0, 0.0, Z_HI), (0.0, W, Z_LO), (0.0, W, Z_HI)]
    faces = []
    # Trough: quads between the two copies of the curve.
    for k in range(n - 1):
        faces.append((k, k + 1, n + k + 1, n + k))
    # Upper lip strip over the air gap, from the lip (x = -LIP_GAP) to the guide's edge.
    faces.append((0, n, gap0 + 3, gap0 + 1))
    # End caps: the curve plus the gap's two corners, one polygon per end.
    faces.append(tuple(range(n)) + (gap0, gap0 + 1))
    faces.append(tuple(n + k for k in range(n)) + (gap0 + 2, gap0 + 3))
    return verts, faces


def main():
    argv = sys.argv[sys.argv.index("--") + 1 :] if "--" in sys.argv else []
    if len(argv) != 1:
        sys.exit("usage: blender -b --factory-startup --python make_reflector.py -- OUT_DIR")
    out = os.path.abspath(argv[0])
    os.makedirs(out, exist_ok=True)

    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.unit_settings.system = "METRIC"
    scene.unit_settings.length_unit = "MILLIMETERS"

    verts, faces = build_mesh()
    origin = (X_FOCUS, 0.5 * W, ZC)
    local = [tuple((v[i] - origin[i]) * MM for i in range(3)) for v in verts]
    mesh = bpy.data.meshes.new("lamp_reflector_trough")
    mesh.from_pydata(local, [], faces)
    mesh.validate()
    bm = bmesh.new()
    bm.from_mesh(mesh)
    # Consistent winding (the reflector is two-sided in blutrace; this is for viewers).
    bmesh.ops.recalc_face_normals(bm, faces=bm.faces)
    bmesh.ops.triangulate(bm, faces=bm.faces, quad_method="BEAUTY", ngon_method="BEAUTY")
    bm.to_mesh(mesh)
    bm.free()

    material = bpy.data.materials.new("lamp_reflector")
    material.diffuse_color = (0.85, 0.85, 0.8, 1.0)
    mesh.materials.append(material)

    obj = bpy.data.objects.new("lamp_reflector_trough", mesh)
    obj.location = tuple(c * MM for c in origin)
    scene.collection.objects.link(obj)

    bpy.ops.export_scene.gltf(
        filepath=os.path.join(out, "reflector.gltf"),
        export_format="GLTF_SEPARATE",
        export_apply=True,
        export_normals=False,
        export_texcoords=False,
        export_colors=False,
        export_materials="EXPORT",
        export_cameras=False,
        export_lights=False,
        export_extras=False,
        export_animations=False,
    )
    bpy.ops.wm.obj_export(
        filepath=os.path.join(out, "reflector.obj"),
        forward_axis="Y",
        up_axis="Z",
        global_scale=1000.0,
        apply_modifiers=True,
        export_uv=False,
        export_normals=False,
        export_colors=False,
        export_materials=True,
        export_triangulated_mesh=True,
        export_object_groups=False,
        export_material_groups=False,
    )
    print(
        f"make_reflector: {len(mesh.polygons)} triangles, focus (x, z) = "
        f"({X_FOCUS:.6f}, {ZC:.6f}) mm, vertex x = {X_VERTEX:.6f} mm -> {out}"
    )


main()
