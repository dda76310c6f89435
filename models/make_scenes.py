"""Build every scene of the cloth simulator in Blender and export it as OBJ/MTL.

Run headless (Blender 3.4, factory settings, no .blend file involved):

    blender -b --factory-startup -P models/make_scenes.py -- [--out DIR] [SCENE ...]

SCENE is any of: skirt dice hanging skirt_hires tablecloth tablecloth_fine drape
twist heap two_cloths
(default: all). Each scene goes
to DIR/<scene>/<scene>.obj + .mtl + its PNG textures (DIR defaults to the folder
of this script). The textures are drawn here by a tiny PNG writer, so nothing is
random and a second run writes byte-identical files. After exporting, the script
reads each .obj back and checks names, face formats and extents, then prints a
summary (the tables in models/README.md come from it).

Figures in the script are in the OBJ's Y-up frame (what the simulator sees); the
helper `B()` turns them into Blender's Z-up frame, and the exporter turns them
back (forward -Z, up Y: OBJ (x, y, z) = Blender (x, z, -y)).
"""

import math
import os
import shutil
import struct
import sys
import zlib

import bmesh
import bpy
from mathutils import Matrix, Vector


# --------------------------------------------------------------------------- #
# small helpers
# --------------------------------------------------------------------------- #

def B(x, y, z):
    """OBJ (Y up) coordinates -> Blender (Z up) coordinates."""
    return Vector((x, -z, y))


def write_png(path, width, height, pixel):
    """Write an 8-bit RGB PNG; pixel(x, y) -> (r, g, b) with y = 0 at the BOTTOM
    (the UV convention of Blender and OBJ: v = 0 is the bottom row)."""
    raw = bytearray()
    for row in range(height):
        y = height - 1 - row  # PNG rows run top to bottom
        raw.append(0)  # filter: none
        for x in range(width):
            raw.extend(pixel(x, y))

    def chunk(tag, data):
        return (struct.pack(">I", len(data)) + tag + data
                + struct.pack(">I", zlib.crc32(tag + data) & 0xFFFFFFFF))

    png = (b"\x89PNG\r\n\x1a\n"
           + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0))
           + chunk(b"IDAT", zlib.compress(bytes(raw), 9))
           + chunk(b"IEND", b""))
    with open(path, "wb") as f:
        f.write(png)


def fresh_scene():
    bpy.ops.wm.read_factory_settings(use_empty=True)


def make_material(name, color, image_path=None, roughness=0.7, specular=0.3):
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    nodes = mat.node_tree.nodes
    bsdf = nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = (*color, 1.0)
    bsdf.inputs["Roughness"].default_value = roughness
    bsdf.inputs["Specular"].default_value = specular
    mat.diffuse_color = (*color, 1.0)
    if image_path is not None:
        tex = nodes.new("ShaderNodeTexImage")
        tex.image = bpy.data.images.load(image_path)
        mat.node_tree.links.new(tex.outputs["Color"], bsdf.inputs["Base Color"])
    return mat


def new_object(name, bm, material, smooth, auto_smooth=None):
    """auto_smooth: an angle in degrees; edges sharper than it keep flat normals
    (the exporter then writes split normals, e.g. a cylinder's rim)."""
    for f in bm.faces:
        f.smooth = smooth
    me = bpy.data.meshes.new(name)
    bm.to_mesh(me)
    bm.free()
    if auto_smooth is not None:
        me.use_auto_smooth = True
        me.auto_smooth_angle = math.radians(auto_smooth)
    me.materials.append(material)
    obj = bpy.data.objects.new(name, me)
    bpy.context.scene.collection.objects.link(obj)
    return obj


def grid(bm, uv, n, size, centre, u_repeat=1.0, triangulate=False):
    """An n x n-quad horizontal square grid (OBJ XZ plane), normals up (+Y)."""
    cx, cy, cz = centre
    vs = []
    for j in range(n + 1):  # along OBJ -z (Blender +y)
        row = []
        for i in range(n + 1):  # along x
            x = cx - size / 2 + size * i / n
            z = cz + size / 2 - size * j / n
            row.append(bm.verts.new(B(x, cy, z)))
        vs.append(row)
    for j in range(n):
        for i in range(n):
            corners = [(i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1)]
            f = bm.faces.new([vs[b][a] for a, b in corners])
            for loop, (a, b) in zip(f.loops, corners):
                loop[uv].uv = (u_repeat * a / n, u_repeat * b / n)
    if triangulate:
        # FIXED: every quad is cut along the same diagonal, the regular
        # triangular grid of the report's figure 3.
        bmesh.ops.triangulate(bm, faces=bm.faces[:], quad_method="FIXED",
                              ngon_method="BEAUTY")
    return vs


# --------------------------------------------------------------------------- #
# textures
# --------------------------------------------------------------------------- #

def checker_texture(path, cols, rows, cell, c0, c1):
    def pixel(x, y):
        return c0 if ((x // cell) + (y // cell)) % 2 == 0 else c1
    write_png(path, cols * cell, rows * cell, pixel)


def tiles_texture(path, tiles=10, cell=32):
    """Floor tiles: light stone squares with darker grout lines."""
    grout = (92, 88, 80)
    stones = [(196, 190, 176), (178, 172, 158)]

    def pixel(x, y):
        cx, cy = x % cell, y % cell
        if cx < 2 or cy < 2:
            return grout
        return stones[((x // cell) + (y // cell)) % 2]
    write_png(path, tiles * cell, tiles * cell, pixel)


def gingham_texture(path, bands, cell, colour, white):
    """Gingham: `bands` stripes each way, every other one coloured; where two
    coloured stripes cross the colour is full, where one crosses white it is half."""
    half = tuple((a + b) // 2 for a, b in zip(colour, white))

    def pixel(x, y):
        n = (x // cell) % 2 + (y // cell) % 2
        return (white, half, colour)[n]
    write_png(path, bands * cell, bands * cell, pixel)


# Pip positions on a unit face (u right, v up) for the faces 1..6.
PIPS = {
    1: [(0.5, 0.5)],
    2: [(0.25, 0.75), (0.75, 0.25)],
    3: [(0.25, 0.75), (0.5, 0.5), (0.75, 0.25)],
    4: [(0.25, 0.25), (0.25, 0.75), (0.75, 0.25), (0.75, 0.75)],
    5: [(0.25, 0.25), (0.25, 0.75), (0.5, 0.5), (0.75, 0.25), (0.75, 0.75)],
    6: [(0.25, 0.2), (0.25, 0.5), (0.25, 0.8), (0.75, 0.2), (0.75, 0.5), (0.75, 0.8)],
}
DIE_CELL = 128          # pixels per die face in the atlas
DIE_COLS, DIE_ROWS = 3, 2


def die_cell_origin(face):
    """Atlas cell (in UV space, v up) of die face 1..6: 1 2 3 on the top row."""
    k = face - 1
    return (k % DIE_COLS) / DIE_COLS, (DIE_ROWS - 1 - k // DIE_COLS) / DIE_ROWS


def die_texture(path):
    ivory, border, pip, red = (240, 236, 222), (150, 146, 134), (24, 24, 28), (180, 20, 30)
    w, h = DIE_COLS * DIE_CELL, DIE_ROWS * DIE_CELL
    r2 = (0.1 * DIE_CELL) ** 2

    def pixel(x, y):
        col, row = x // DIE_CELL, y // DIE_CELL
        face = (DIE_ROWS - 1 - row) * DIE_COLS + col + 1
        lx, ly = x % DIE_CELL, y % DIE_CELL
        if min(lx, ly, DIE_CELL - 1 - lx, DIE_CELL - 1 - ly) < 3:
            return border
        for px, py in PIPS[face]:
            dx, dy = lx + 0.5 - px * DIE_CELL, ly + 0.5 - py * DIE_CELL
            if dx * dx + dy * dy <= r2 * (2.0 if face == 1 else 1.0):
                return red if face == 1 else pip
        return ivory
    write_png(path, w, h, pixel)


# --------------------------------------------------------------------------- #
# scene 1: skirt above a sphere above a floor
# --------------------------------------------------------------------------- #

SPHERE_CENTRE = (0.04, -1.08, 0.03)
SPHERE_RADIUS = 0.85
FLOOR_Y = -2.33


def skirt_mesh(segments, quad_bands, centre_xz=(0.04, 0.13), y_top=1.06, y_bottom=0.02,
               r_top=0.3, r_bottom=1.5):
    """An open cone like the 2016 'Cone': `quad_bands` bands of quads from the hem
    upwards and one band of pentagons at the top (the top ring has a vertex at
    each segment's middle too), as the 2016 export had (256 quads + 32 pentagons
    for 32 segments and 8 quad bands). Normals point outwards.
    The centre is 0.1 off the sphere's axis (in z), so the skirt slips off."""
    bm = bmesh.new()
    uv = bm.loops.layers.uv.new("UVMap")
    rings = quad_bands + 1                  # full rings of `segments` vertices
    bands = quad_bands + 1                  # plus the pentagon band
    cx, cz = centre_xz

    def point(t, angle):
        # t = 0 at the hem, 1 at the top; straight slant, evenly spaced rings
        r = r_bottom + (r_top - r_bottom) * t
        y = y_bottom + (y_top - y_bottom) * t
        return B(cx + r * math.cos(angle), y, cz - r * math.sin(angle))

    ring = []
    for k in range(rings):
        t = k / bands
        ring.append([bm.verts.new(point(t, 2 * math.pi * j / segments)) for j in range(segments)])
    top = [bm.verts.new(point(1.0, 2 * math.pi * h / (2 * segments))) for h in range(2 * segments)]

    def face(verts, uvs):
        f = bm.faces.new(verts)
        for loop, c in zip(f.loops, uvs):
            loop[uv].uv = c

    for k in range(quad_bands):
        v0, v1 = k / bands, (k + 1) / bands
        for j in range(segments):
            j1 = (j + 1) % segments
            u0, u1 = j / segments, (j + 1) / segments  # the seam gets u = 1, not 0
            face([ring[k][j], ring[k][j1], ring[k + 1][j1], ring[k + 1][j]],
                 [(u0, v0), (u1, v0), (u1, v1), (u0, v1)])
    k = quad_bands
    v0 = k / bands
    for j in range(segments):
        j1 = (j + 1) % segments
        u0, um, u1 = j / segments, (j + 0.5) / segments, (j + 1) / segments
        face([ring[k][j], ring[k][j1], top[(2 * j + 2) % (2 * segments)], top[2 * j + 1], top[2 * j]],
             [(u0, v0), (u1, v0), (u1, 1.0), (um, 1.0), (u0, 1.0)])

    # Outward normals: each face points away from the skirt's axis.
    bm.normal_update()
    axis = B(cx, 0.0, cz)
    for f in bm.faces:
        c = f.calc_center_median()
        radial = Vector((c.x - axis.x, c.y - axis.y, 0.0))
        assert f.normal.dot(radial) > 0.0, "skirt face points inwards"
    return bm


def build_skirt(out_dir, name, segments, quad_bands):
    fresh_scene()
    os.makedirs(out_dir, exist_ok=True)
    cloth_png = os.path.join(out_dir, "skirt_checker.png")
    floor_png = os.path.join(out_dir, "floor_tiles.png")
    # 16 x 4 checks of 32 px around x along the skirt (u spans the circumference)
    checker_texture(cloth_png, 16, 4, 32, (200, 40, 50), (245, 235, 215))
    tiles_texture(floor_png)

    bm = skirt_mesh(segments, quad_bands)
    new_object("Skirt", bm, make_material("SkirtCloth", (0.8, 0.2, 0.2), cloth_png), smooth=True)

    bm = bmesh.new()
    bm.loops.layers.uv.new("UVMap")
    bmesh.ops.create_icosphere(bm, subdivisions=2, radius=SPHERE_RADIUS,
                               matrix=Matrix.Translation(B(*SPHERE_CENTRE)), calc_uvs=True)
    new_object("Sphere", bm, make_material("SphereGrey", (0.55, 0.56, 0.6), roughness=0.4),
               smooth=True)

    bm = bmesh.new()
    uv = bm.loops.layers.uv.new("UVMap")
    grid(bm, uv, 18, 20.0, (0.0, FLOOR_Y, 0.0))
    new_object("Floor", bm, make_material("FloorTiles", (0.75, 0.73, 0.68), floor_png),
               smooth=False)
    return export(out_dir, name)


# --------------------------------------------------------------------------- #
# scene 2: two dice above a plane
# --------------------------------------------------------------------------- #

DIE_EDGE = 0.5
# outward normal (OBJ frame) -> die face number; opposite faces sum to 7
DIE_FACES = {(0, 1, 0): 1, (0, -1, 0): 6, (0, 0, 1): 2, (0, 0, -1): 5, (1, 0, 0): 3, (-1, 0, 0): 4}


def die_mesh(centre, rotation):
    """A cube of 8 vertices; each face's UVs cover one cell of the die atlas,
    oriented so the face reads correctly seen from outside."""
    bm = bmesh.new()
    uv = bm.loops.layers.uv.new("UVMap")
    bmesh.ops.create_cube(bm, size=DIE_EDGE)
    bm.normal_update()
    half = DIE_EDGE / 2
    inset = 2.0 / (DIE_COLS * DIE_CELL)  # stay off the cell's edge: no bleeding
    for f in bm.faces:
        n = f.normal  # Blender frame
        n_obj = (round(n.x), round(n.z), round(-n.y))
        face = DIE_FACES[n_obj]
        # tangent frame on the face: u x v = n (counter-clockwise seen from outside)
        up = Vector((0, 0, 1)) if abs(n.z) < 0.5 else Vector((0, 1, 0))
        tu = up.cross(n).normalized()
        tv = n.cross(tu)
        ou, ov = die_cell_origin(face)
        cw, ch = 1.0 / DIE_COLS, 1.0 / DIE_ROWS
        for loop in f.loops:
            p = loop.vert.co
            s = (p.dot(tu) / half + 1) / 2
            t = (p.dot(tv) / half + 1) / 2
            loop[uv].uv = (ou + inset + s * (cw - 2 * inset), ov + inset + t * (ch - 2 * inset))
    bmesh.ops.transform(bm, matrix=Matrix.Translation(B(*centre)) @ rotation, verts=bm.verts)
    return bm


def build_dice(out_dir, name):
    fresh_scene()
    os.makedirs(out_dir, exist_ok=True)
    die_png = os.path.join(out_dir, "die_faces.png")
    plane_png = os.path.join(out_dir, "plane_tiles.png")
    die_texture(die_png)
    tiles_texture(plane_png, tiles=6)
    die_mat = make_material("DieFaces", (0.94, 0.92, 0.87), die_png, roughness=0.3)

    # tilted 35 deg about one axis and 20 deg about another: lands on an edge and tumbles
    tilt = (Matrix.Rotation(math.radians(35.0), 4, "X") @ Matrix.Rotation(math.radians(20.0), 4, "Y"))
    new_object("RollingDie", die_mesh((-0.9, 1.6, 0.2), tilt), die_mat, smooth=False)
    new_object("Die", die_mesh((0.8, 1.0, -0.3), Matrix.Identity(4)), die_mat, smooth=False)

    bm = bmesh.new()
    uv = bm.loops.layers.uv.new("UVMap")
    grid(bm, uv, 1, 6.0, (0.0, 0.0, 0.0))
    new_object("Plane", bm, make_material("PlaneTiles", (0.7, 0.7, 0.65), plane_png),
               smooth=False)
    return export(out_dir, name)


# --------------------------------------------------------------------------- #
# scene 3: a square cloth hanging from its two back corners
# --------------------------------------------------------------------------- #

PIN_CORNERS = [(-1.0, 1.0, -1.0), (1.0, 1.0, -1.0)]
PIN_SIZE = 4e-4  # the pin triangles stay well within 1e-3 of their corner


def build_hanging(out_dir, name):
    fresh_scene()
    os.makedirs(out_dir, exist_ok=True)
    cloth_png = os.path.join(out_dir, "cloth_checker.png")
    checker_texture(cloth_png, 8, 8, 32, (40, 90, 170), (235, 235, 225))

    bm = bmesh.new()
    uv = bm.loops.layers.uv.new("UVMap")
    grid(bm, uv, 20, 2.0, (0.0, 1.0, 0.0), triangulate=True)
    new_object("Cloth", bm, make_material("ClothChecker", (0.2, 0.4, 0.7), cloth_png),
               smooth=True)

    # One tiny triangle at each pinned corner; the converter pins the cloth mass
    # nearest to each of these vertices.
    bm = bmesh.new()
    uv = bm.loops.layers.uv.new("UVMap")
    for x, y, z in PIN_CORNERS:
        inward = -1.0 if x > 0 else 1.0  # towards the cloth, in x and in +z
        corners = [(x, y, z), (x + inward * PIN_SIZE, y, z), (x, y, z + PIN_SIZE)]
        if inward > 0:  # keep the normal up (+Y) on both triangles
            corners = [corners[0], corners[2], corners[1]]
        f = bm.faces.new([bm.verts.new(B(*c)) for c in corners])
        for loop, c in zip(f.loops, [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0)]):
            loop[uv].uv = c
    new_object("Cloth_pins", bm, make_material("PinMarker", (0.9, 0.1, 0.1)), smooth=False)
    return export(out_dir, name)


# --------------------------------------------------------------------------- #
# scene 4: a square tablecloth over a round table
# --------------------------------------------------------------------------- #

TABLE_TOP_Y = 0.75        # the table top's upper surface
TABLE_RADIUS = 1.0
TABLE_THICKNESS = 0.04
TABLE_SEGMENTS = 64
PEDESTAL_RADIUS = 0.08
PEDESTAL_SEGMENTS = 32
TABLECLOTH_SIZE = 3.0
TABLECLOTH_Y = 0.80       # 5 cm above the table top
TABLE_FLOOR_SIZE = 8.0


def cylinder(radius, y0, y1, segments):
    """A closed vertical cylinder (OBJ y0 .. y1 on the Y axis): quads around,
    each cap a fan of triangles around a centre vertex; normals outwards."""
    bm = bmesh.new()
    bm.loops.layers.uv.new("UVMap")
    bmesh.ops.create_cone(bm, cap_ends=True, cap_tris=True, segments=segments,
                          radius1=radius, radius2=radius, depth=y1 - y0,
                          matrix=Matrix.Translation(B(0.0, (y0 + y1) / 2, 0.0)), calc_uvs=True)
    assert all(e.is_manifold and not e.is_boundary for e in bm.edges), "cylinder not closed"
    return bm


def build_tablecloth(out_dir, name, n):
    fresh_scene()
    os.makedirs(out_dir, exist_ok=True)
    cloth_png = os.path.join(out_dir, "tablecloth_gingham.png")
    floor_png = os.path.join(out_dir, "floor_tiles.png")
    # 40 stripes each way over the 3 m cloth: 7.5 cm, one quad of the 40 x 40 grid
    gingham_texture(cloth_png, 40, 8, (170, 30, 45), (248, 244, 236))
    tiles_texture(floor_png, tiles=8)  # 1 m tiles

    bm = bmesh.new()
    uv = bm.loops.layers.uv.new("UVMap")
    grid(bm, uv, n, TABLECLOTH_SIZE, (0.0, TABLECLOTH_Y, 0.0))
    new_object("Tablecloth", bm, make_material("TableclothGingham", (0.8, 0.35, 0.35), cloth_png),
               smooth=True)

    wood = make_material("TableWood", (0.42, 0.27, 0.15), roughness=0.5)
    new_object("TableTop", cylinder(TABLE_RADIUS, TABLE_TOP_Y - TABLE_THICKNESS, TABLE_TOP_Y,
                                    TABLE_SEGMENTS), wood, smooth=True, auto_smooth=30.0)
    new_object("Pedestal", cylinder(PEDESTAL_RADIUS, 0.0, TABLE_TOP_Y - TABLE_THICKNESS,
                                    PEDESTAL_SEGMENTS), wood, smooth=True, auto_smooth=30.0)

    bm = bmesh.new()
    uv = bm.loops.layers.uv.new("UVMap")
    grid(bm, uv, 8, TABLE_FLOOR_SIZE, (0.0, 0.0, 0.0))
    new_object("Floor", bm, make_material("FloorTiles", (0.75, 0.73, 0.68), floor_png),
               smooth=False)
    return export(out_dir, name)


# --------------------------------------------------------------------------- #
# scene 5: a square cloth dropped on Suzanne (non-convex: eyes, ears)
# --------------------------------------------------------------------------- #

SUZANNE_WIDTH = 1.1       # ear to ear (x), after the subdivision
DRAPE_CLOTH_SIZE = 2.0
DRAPE_GAP = 0.15          # the cloth starts 0.15 .. 0.16 above Suzanne's highest point
DRAPE_FLOOR_SIZE = 4.0


def suzanne_mesh():
    """Blender's Suzanne, closed, subdivided once, lying on her back (face up, +Y)
    on the floor, centred on the Y axis, triangulated; normals outwards."""
    bpy.ops.mesh.primitive_monkey_add(size=2.0)
    obj = bpy.context.active_object
    bm = bmesh.new()
    bm.from_mesh(obj.data)
    # Suzanne is three islands: the head (open at the eyes) and two eyeballs
    # (open domes). Drop the eyeballs and close the eye holes: two sockets.
    islands, seen = [], set()
    for v in bm.verts:
        if v in seen:
            continue
        seen.add(v)
        island, stack = [], [v]
        while stack:
            a = stack.pop()
            island.append(a)
            for e in a.link_edges:
                b = e.other_vert(a)
                if b not in seen:
                    seen.add(b)
                    stack.append(b)
        islands.append(island)
    islands.sort(key=len)
    assert len(islands) == 3, [len(i) for i in islands]
    bmesh.ops.delete(bm, geom=islands[0] + islands[1], context="VERTS")
    filled = bmesh.ops.holes_fill(bm, edges=[e for e in bm.edges if e.is_boundary], sides=0)
    assert len(filled["faces"]) == 2, len(filled["faces"])
    bmesh.ops.poke(bm, faces=filled["faces"])  # a fan, not a 13-gon, under the subdivision
    bmesh.ops.recalc_face_normals(bm, faces=bm.faces[:])
    assert all(e.is_manifold and not e.is_boundary for e in bm.edges), "Suzanne not closed"
    bm.to_mesh(obj.data)
    bm.free()

    # One level of Catmull-Clark, applied.
    mod = obj.modifiers.new("Subdivision", "SUBSURF")
    mod.levels = mod.render_levels = 1
    me = bpy.data.meshes.new_from_object(obj.evaluated_get(bpy.context.evaluated_depsgraph_get()))
    bm = bmesh.new()
    bm.from_mesh(me)
    bpy.data.objects.remove(obj)
    bpy.data.meshes.remove(me)

    # Face up: Blender's Suzanne looks along -Y (Blender); turn her onto her back.
    bmesh.ops.transform(bm, matrix=Matrix.Rotation(math.radians(-90.0), 4, "X"), verts=bm.verts)
    lo = [min(v.co[i] for v in bm.verts) for i in range(3)]
    hi = [max(v.co[i] for v in bm.verts) for i in range(3)]
    s = SUZANNE_WIDTH / (hi[0] - lo[0])
    shift = Vector((-(lo[0] + hi[0]) / 2, -(lo[1] + hi[1]) / 2, -lo[2])) * s
    bmesh.ops.transform(bm, matrix=Matrix.Translation(shift) @ Matrix.Scale(s, 4), verts=bm.verts)
    bmesh.ops.triangulate(bm, faces=bm.faces[:], quad_method="BEAUTY", ngon_method="BEAUTY")
    bm.normal_update()
    assert all(e.is_manifold and not e.is_boundary for e in bm.edges), "Suzanne not closed"
    return bm


def tiled_floor(size, floor_png):
    """A square floor at y = 0, 4 x 4 quads, with the tile texture."""
    bm = bmesh.new()
    uv = bm.loops.layers.uv.new("UVMap")
    grid(bm, uv, 4, size, (0.0, 0.0, 0.0))
    new_object("Floor", bm, make_material("FloorTiles", (0.75, 0.73, 0.68), floor_png),
               smooth=False)


def build_drape(out_dir, name):
    fresh_scene()
    os.makedirs(out_dir, exist_ok=True)
    cloth_png = os.path.join(out_dir, "drape_checker.png")
    floor_png = os.path.join(out_dir, "floor_tiles.png")
    # 16 x 16 checks of 12.5 cm over the 2 m cloth
    checker_texture(cloth_png, 16, 16, 16, (230, 140, 30), (245, 240, 225))
    tiles_texture(floor_png, tiles=8)  # 0.5 m tiles

    bm = suzanne_mesh()
    top = max(v.co.z for v in bm.verts)  # Blender z = OBJ y
    new_object("Suzanne", bm, make_material("SuzanneGrey", (0.55, 0.56, 0.6), roughness=0.4),
               smooth=True)
    cloth_y = math.ceil((top + DRAPE_GAP) * 100.0) / 100.0

    bm = bmesh.new()
    uv = bm.loops.layers.uv.new("UVMap")
    grid(bm, uv, 50, DRAPE_CLOTH_SIZE, (0.0, cloth_y, 0.0))
    new_object("Cloth", bm, make_material("DrapeChecker", (0.9, 0.55, 0.12), cloth_png),
               smooth=True)

    tiled_floor(DRAPE_FLOOR_SIZE, floor_png)
    return export(out_dir, name)


# --------------------------------------------------------------------------- #
# self-contact stress scenes: a twisted square, a strip that heaps, two cloths
# --------------------------------------------------------------------------- #

TWIST_SIZE = 1.0
TWIST_N = 40              # quads a side: 2.5 cm
TWIST_Y = 1.0


def build_twist(out_dir, name):
    """A square cloth whose two opposite edges (x = -0.5 and x = +0.5) are pinned;
    the scene's pin_spin turns them in opposite senses about the x axis."""
    fresh_scene()
    os.makedirs(out_dir, exist_ok=True)
    cloth_png = os.path.join(out_dir, "twist_checker.png")
    checker_texture(cloth_png, 10, 10, 16, (200, 50, 60), (240, 236, 222))

    bm = bmesh.new()
    uv = bm.loops.layers.uv.new("UVMap")
    grid(bm, uv, TWIST_N, TWIST_SIZE, (0.0, TWIST_Y, 0.0), triangulate=True)
    new_object("Cloth", bm, make_material("TwistChecker", (0.8, 0.25, 0.3), cloth_png),
               smooth=True)

    # Along each pinned edge a strip PIN_SIZE wide: one vertex on every edge vertex
    # of the cloth and one PIN_SIZE inwards, whose nearest cloth mass is the same
    # edge vertex (the grid spacing is 2.5 cm).
    bm = bmesh.new()
    uv = bm.loops.layers.uv.new("UVMap")
    h = TWIST_SIZE / 2
    for edge_x in (-h, h):
        inner = edge_x - PIN_SIZE if edge_x > 0 else edge_x + PIN_SIZE
        xa, xb = min(edge_x, inner), max(edge_x, inner)
        zs = [h - TWIST_SIZE * k / TWIST_N for k in range(TWIST_N + 1)]  # decreasing z
        left = [bm.verts.new(B(xa, TWIST_Y, z)) for z in zs]
        right = [bm.verts.new(B(xb, TWIST_Y, z)) for z in zs]
        for k in range(TWIST_N):
            # the grid's winding: (xa, z_k), (xb, z_k), (xb, z_k+1), (xa, z_k+1) faces up
            f = bm.faces.new([left[k], right[k], right[k + 1], left[k + 1]])
            for loop, c in zip(f.loops, [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)]):
                loop[uv].uv = c
    new_object("Cloth_pins", bm, make_material("PinMarker", (0.9, 0.1, 0.1)), smooth=False)
    return export(out_dir, name)


HEAP_WIDTH = 0.25
HEAP_LENGTH = 3.0
HEAP_QUADS = (10, 120)    # across, along: 2.5 cm
HEAP_BOTTOM = 0.3         # its lower end above the floor
HEAP_TILT = 10.0          # degrees from vertical, its top towards -z
HEAP_FLOOR_SIZE = 4.0


def build_heap(out_dir, name):
    """A long strip hanging straight down but for a small tilt, its lower end
    0.3 m above a floor: let go, it lands end first and folds onto itself."""
    fresh_scene()
    os.makedirs(out_dir, exist_ok=True)
    cloth_png = os.path.join(out_dir, "heap_stripes.png")
    floor_png = os.path.join(out_dir, "floor_tiles.png")
    # 2 x 24 checks: 12.5 cm each, so the folds show
    checker_texture(cloth_png, 2, 24, 16, (40, 140, 90), (238, 236, 220))
    tiles_texture(floor_png, tiles=8)  # 0.5 m tiles

    bm = bmesh.new()
    uv = bm.loops.layers.uv.new("UVMap")
    na, nl = HEAP_QUADS
    tilt = math.radians(HEAP_TILT)
    vs = []
    for j in range(nl + 1):  # from the lower end up
        s = HEAP_LENGTH * j / nl
        vs.append([bm.verts.new(B(-HEAP_WIDTH / 2 + HEAP_WIDTH * i / na,
                                  HEAP_BOTTOM + s * math.cos(tilt), -s * math.sin(tilt)))
                   for i in range(na + 1)])
    for j in range(nl):
        for i in range(na):
            corners = [(i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1)]
            f = bm.faces.new([vs[b][a] for a, b in corners])
            for loop, (a, b) in zip(f.loops, corners):
                loop[uv].uv = (a / na, b / nl)
    new_object("Strip", bm, make_material("HeapStripes", (0.2, 0.55, 0.35), cloth_png),
               smooth=True)

    tiled_floor(HEAP_FLOOR_SIZE, floor_png)
    return export(out_dir, name)


TWO_SIZE = 1.0
TWO_N = 30                # quads a side
TWO_LOWER_Y = 0.9
TWO_UPPER_Y = 1.2         # 0.3 m above the lower cloth, turned 45 degrees about Y
TWO_BOX = 0.5             # a cube on the floor, its top at y = 0.5
TWO_FLOOR_SIZE = 4.0


def build_two_cloths(out_dir, name):
    """Two square cloths, one above the other (the upper turned 45 degrees),
    above a box on a floor: both drape over the box and over each other."""
    fresh_scene()
    os.makedirs(out_dir, exist_ok=True)
    lower_png = os.path.join(out_dir, "lower_checker.png")
    upper_png = os.path.join(out_dir, "upper_checker.png")
    floor_png = os.path.join(out_dir, "floor_tiles.png")
    checker_texture(lower_png, 10, 10, 16, (40, 90, 170), (235, 235, 225))
    checker_texture(upper_png, 10, 10, 16, (230, 140, 30), (245, 240, 225))
    tiles_texture(floor_png, tiles=8)  # 0.5 m tiles

    bm = bmesh.new()
    uv = bm.loops.layers.uv.new("UVMap")
    grid(bm, uv, TWO_N, TWO_SIZE, (0.0, TWO_LOWER_Y, 0.0))
    new_object("LowerCloth", bm, make_material("LowerChecker", (0.2, 0.4, 0.7), lower_png),
               smooth=True)

    bm = bmesh.new()
    uv = bm.loops.layers.uv.new("UVMap")
    grid(bm, uv, TWO_N, TWO_SIZE, (0.0, 0.0, 0.0))
    # 45 degrees about the vertical (Blender's z), then up to its height
    bmesh.ops.rotate(bm, verts=bm.verts[:], cent=B(0.0, 0.0, 0.0),
                     matrix=Matrix.Rotation(math.radians(45.0), 3, "Z"))
    bmesh.ops.translate(bm, verts=bm.verts[:], vec=B(0.0, TWO_UPPER_Y, 0.0))
    new_object("UpperCloth", bm, make_material("UpperChecker", (0.9, 0.55, 0.12), upper_png),
               smooth=True)

    bm = bmesh.new()
    bm.loops.layers.uv.new("UVMap")
    bmesh.ops.create_cube(bm, size=TWO_BOX, matrix=Matrix.Translation(B(0.0, TWO_BOX / 2, 0.0)),
                          calc_uvs=True)
    new_object("Box", bm, make_material("BoxGrey", (0.55, 0.56, 0.6), roughness=0.4), smooth=False)

    tiled_floor(TWO_FLOOR_SIZE, floor_png)
    return export(out_dir, name)


# --------------------------------------------------------------------------- #
# export and check
# --------------------------------------------------------------------------- #

def export(out_dir, name):
    path = os.path.join(out_dir, name + ".obj")
    bpy.ops.wm.obj_export(filepath=path, export_materials=True, path_mode="RELATIVE",
                          export_selected_objects=False, export_uv=True, export_normals=True,
                          export_triangulated_mesh=False, apply_modifiers=True,
                          forward_axis="NEGATIVE_Z", up_axis="Y")
    return check_obj(path)


def check_obj(path):
    """Read the export back: every face v/vt/vn, names, counts, extents."""
    objects = {}
    order = []
    cur = None
    nv = 0
    normals = []
    mtllib = None
    with open(path) as f:
        for line in f:
            parts = line.split()
            if not parts:
                continue
            if parts[0] == "mtllib":
                mtllib = parts[1]
            elif parts[0] == "o":
                cur = {"v": [], "faces": 0, "tris": 0, "sizes": {}, "mtl": set(),
                       "v0": nv, "f": [], "vn": normals}
                objects[parts[1]] = cur
                order.append(parts[1])
            elif parts[0] == "v":
                nv += 1
                cur["v"].append(tuple(float(c) for c in parts[1:4]))
            elif parts[0] == "vn":
                normals.append(tuple(float(c) for c in parts[1:4]))
            elif parts[0] == "usemtl":
                cur["mtl"].add(parts[1])
            elif parts[0] == "f":
                corners = parts[1:]
                for c in corners:
                    idx = c.split("/")
                    assert len(idx) == 3 and all(idx), f"{path}: face corner '{c}' is not v/vt/vn"
                # (vertex index in this object, normal index in the file), 0-based
                cur["f"].append([(int(c.split("/")[0]) - 1 - cur["v0"], int(c.split("/")[2]) - 1)
                                 for c in corners])
                cur["faces"] += 1
                cur["tris"] += len(corners) - 2
                cur["sizes"][len(corners)] = cur["sizes"].get(len(corners), 0) + 1
    assert mtllib is not None, f"{path}: no mtllib"
    mtl_path = os.path.join(os.path.dirname(path), mtllib)
    with open(mtl_path) as f:
        for line in f:
            parts = line.split()
            if parts and parts[0] == "map_Kd":
                tex = os.path.join(os.path.dirname(path), parts[-1])
                assert not os.path.isabs(parts[-1]), f"{mtl_path}: absolute texture path"
                assert os.path.isfile(tex), f"{mtl_path}: missing texture {tex}"
    summary = []
    for name in order:
        o = objects[name]
        lo = [min(v[i] for v in o["v"]) for i in range(3)]
        hi = [max(v[i] for v in o["v"]) for i in range(3)]
        summary.append((name, len(o["v"]), o["faces"], o["tris"], dict(sorted(o["sizes"].items())),
                        lo, hi, sorted(o["mtl"])))
    return path, summary, objects


def face_normal(vs, face):
    """Newell's normal of a face (its winding, counter-clockwise seen from the front)."""
    n = [0.0, 0.0, 0.0]
    for (a, _), (b, _) in zip(face, face[1:] + face[:1]):
        p, q = vs[a], vs[b]
        n[0] += (p[1] - q[1]) * (p[2] + q[2])
        n[1] += (p[2] - q[2]) * (p[0] + q[0])
        n[2] += (p[0] - q[0]) * (p[1] + q[1])
    return n


def check_closed_outward(objects, name):
    """A closed collider: every edge in exactly two faces, once each way (closed,
    consistently wound), a positive volume (wound outwards) and every face's
    normals (vn) on the side of its winding."""
    o = objects[name]
    vs, faces = o["v"], o["f"]
    directed = {}
    for face in faces:
        for (a, _), (b, _) in zip(face, face[1:] + face[:1]):
            directed[(a, b)] = directed.get((a, b), 0) + 1
    assert all(c == 1 for c in directed.values()), f"{name}: an edge twice the same way"
    assert all((b, a) in directed for a, b in directed), f"{name}: open (a boundary edge)"
    volume = 0.0
    for face in faces:
        p0 = vs[face[0][0]]
        for (b, _), (c, _) in zip(face[1:-1], face[2:]):
            p1, p2 = vs[b], vs[c]
            volume += (p0[0] * (p1[1] * p2[2] - p1[2] * p2[1])
                       - p0[1] * (p1[0] * p2[2] - p1[2] * p2[0])
                       + p0[2] * (p1[0] * p2[1] - p1[1] * p2[0])) / 6.0
    assert volume > 0.0, f"{name}: faces point inwards (volume {volume})"
    for face in faces:
        n = face_normal(vs, face)
        m = [sum(o["vn"][k][i] for _, k in face) for i in range(3)]
        assert sum(a * b for a, b in zip(n, m)) > 0.0, f"{name}: a face's vn against its winding"
    return volume


def check_flat_up(objects, name, y):
    """A horizontal sheet at height y, every face wound and shaded up (+Y)."""
    o = objects[name]
    assert all(abs(v[1] - y) < 1e-5 for v in o["v"]), (name, y)
    for face in o["f"]:
        assert face_normal(o["v"], face)[1] > 0.0, f"{name}: a face points down"
        assert all(o["vn"][k] == (0.0, 1.0, 0.0) for _, k in face), f"{name}: vn not +Y"


def verify(scene, objects):
    """Scene-specific checks of the exported (Y-up) coordinates."""
    def ext(name):
        vs = objects[name]["v"]
        return ([min(v[i] for v in vs) for i in range(3)], [max(v[i] for v in vs) for i in range(3)])

    def near(a, b, tol=1e-4):
        return abs(a - b) < tol

    if scene.startswith("skirt"):
        assert set(objects) == {"Skirt", "Sphere", "Floor"}, sorted(objects)
        lo, hi = ext("Skirt")
        assert abs(hi[1] - 1.06) < 1e-4 and abs(lo[1] - 0.02) < 1e-4, (lo, hi)  # Y is up
        lo, hi = ext("Floor")
        assert abs(lo[1] - FLOOR_Y) < 1e-5 and abs(hi[1] - FLOOR_Y) < 1e-5
        assert len(objects["Floor"]["v"]) == 19 * 19
        lo, hi = ext("Sphere")
        c = [(a + b) / 2 for a, b in zip(lo, hi)]
        assert all(abs(a - b) < 0.05 for a, b in zip(c, SPHERE_CENTRE)), c
        check_closed_outward(objects, "Sphere")
    elif scene == "dice":
        assert set(objects) == {"RollingDie", "Die", "Plane"}, sorted(objects)
        for d in ("RollingDie", "Die"):
            assert len(objects[d]["v"]) == 8
            lo, _ = ext(d)
            assert 0.5 <= lo[1] <= 1.5, (d, lo)
            check_closed_outward(objects, d)
        a, b = ext("RollingDie"), ext("Die")
        assert any(a[1][i] < b[0][i] or b[1][i] < a[0][i] for i in range(3)), "dice overlap"
    elif scene == "hanging":
        assert set(objects) == {"Cloth", "Cloth_pins"}, sorted(objects)
        assert len(objects["Cloth"]["v"]) == 21 * 21
        assert objects["Cloth"]["sizes"] == {3: 800}, objects["Cloth"]["sizes"]
        assert all(abs(v[1] - 1.0) < 1e-6 for v in objects["Cloth"]["v"])
        for p in objects["Cloth_pins"]["v"]:
            d = min(math.dist(p, c) for c in PIN_CORNERS)
            assert d < 1e-3, (p, d)
        for c in PIN_CORNERS:  # the corners are cloth vertices
            assert min(math.dist(v, c) for v in objects["Cloth"]["v"]) < 1e-6, c
    elif scene.startswith("tablecloth"):
        n = 80 if scene == "tablecloth_fine" else 40
        assert set(objects) == {"Tablecloth", "TableTop", "Pedestal", "Floor"}, sorted(objects)
        assert len(objects["Tablecloth"]["v"]) == (n + 1) ** 2
        assert objects["Tablecloth"]["sizes"] == {4: n * n}, objects["Tablecloth"]["sizes"]
        check_flat_up(objects, "Tablecloth", TABLECLOTH_Y)
        lo, hi = ext("Tablecloth")
        h = TABLECLOTH_SIZE / 2
        assert all(near(c, -h) for c in (lo[0], lo[2])) and all(near(c, h) for c in (hi[0], hi[2]))
        lo, hi = ext("TableTop")
        assert near(hi[1], TABLE_TOP_Y) and near(lo[1], TABLE_TOP_Y - TABLE_THICKNESS), (lo, hi)
        r = max(math.hypot(v[0], v[2]) for v in objects["TableTop"]["v"])
        assert near(r, TABLE_RADIUS), r
        lo, hi = ext("Pedestal")
        assert near(lo[1], 0.0) and near(hi[1], TABLE_TOP_Y - TABLE_THICKNESS), (lo, hi)
        for c in ("TableTop", "Pedestal"):
            check_closed_outward(objects, c)
        check_flat_up(objects, "Floor", 0.0)
        lo, hi = ext("Floor")
        assert near(lo[0], -TABLE_FLOOR_SIZE / 2) and near(hi[2], TABLE_FLOOR_SIZE / 2)
    elif scene == "drape":
        assert set(objects) == {"Cloth", "Suzanne", "Floor"}, sorted(objects)
        assert len(objects["Cloth"]["v"]) == 51 * 51
        assert objects["Cloth"]["sizes"] == {4: 2500}, objects["Cloth"]["sizes"]
        lo, hi = ext("Suzanne")
        assert 1.0 <= hi[0] - lo[0] <= 1.2, (lo, hi)
        assert near(lo[1], 0.0), lo  # on the floor
        assert abs(lo[0] + hi[0]) < 1e-4 and abs(lo[2] + hi[2]) < 1e-4, (lo, hi)  # centred
        check_closed_outward(objects, "Suzanne")
        cloth_y = objects["Cloth"]["v"][0][1]
        assert 0.1 <= cloth_y - hi[1] <= 0.2, (cloth_y, hi[1])
        check_flat_up(objects, "Cloth", cloth_y)
        lo, hi = ext("Cloth")
        h = DRAPE_CLOTH_SIZE / 2
        assert all(near(c, -h) for c in (lo[0], lo[2])) and all(near(c, h) for c in (hi[0], hi[2]))
        check_flat_up(objects, "Floor", 0.0)
    elif scene == "twist":
        assert set(objects) == {"Cloth", "Cloth_pins"}, sorted(objects)
        n = TWIST_N
        assert len(objects["Cloth"]["v"]) == (n + 1) ** 2
        assert objects["Cloth"]["sizes"] == {3: 2 * n * n}, objects["Cloth"]["sizes"]
        check_flat_up(objects, "Cloth", TWIST_Y)
        check_flat_up(objects, "Cloth_pins", TWIST_Y)
        h = TWIST_SIZE / 2
        cloth = objects["Cloth"]["v"]
        edge = [v for v in cloth if near(abs(v[0]), h, 1e-6)]
        assert len(edge) == 2 * (n + 1), len(edge)
        for p in objects["Cloth_pins"]["v"]:  # nearest cloth vertex: one on a pinned edge
            nearest = min(cloth, key=lambda v: math.dist(v, p))
            assert near(abs(nearest[0]), h, 1e-6) and math.dist(nearest, p) < 1e-3, (p, nearest)
        pinned = {min(range(len(cloth)), key=lambda i: math.dist(cloth[i], p))
                  for p in objects["Cloth_pins"]["v"]}
        assert len(pinned) == 2 * (n + 1), len(pinned)  # every edge vertex, none else
    elif scene == "heap":
        assert set(objects) == {"Strip", "Floor"}, sorted(objects)
        na, nl = HEAP_QUADS
        assert len(objects["Strip"]["v"]) == (na + 1) * (nl + 1)
        assert objects["Strip"]["sizes"] == {4: na * nl}, objects["Strip"]["sizes"]
        lo, hi = ext("Strip")
        assert near(lo[1], HEAP_BOTTOM) and near(hi[0] - lo[0], HEAP_WIDTH), (lo, hi)
        tilt = math.radians(HEAP_TILT)
        assert near(hi[1], HEAP_BOTTOM + HEAP_LENGTH * math.cos(tilt)), hi
        check_flat_up(objects, "Floor", 0.0)
    elif scene == "two_cloths":
        assert set(objects) == {"LowerCloth", "UpperCloth", "Box", "Floor"}, sorted(objects)
        for c, y in (("LowerCloth", TWO_LOWER_Y), ("UpperCloth", TWO_UPPER_Y)):
            assert len(objects[c]["v"]) == (TWO_N + 1) ** 2
            assert objects[c]["sizes"] == {4: TWO_N * TWO_N}, objects[c]["sizes"]
            check_flat_up(objects, c, y)
        h = TWO_SIZE / 2
        lo, hi = ext("LowerCloth")
        assert all(near(c, -h) for c in (lo[0], lo[2])) and all(near(c, h) for c in (hi[0], hi[2]))
        lo, hi = ext("UpperCloth")  # turned 45 degrees: its corners on the axes
        assert all(near(c, -h * math.sqrt(2.0)) for c in (lo[0], lo[2])), lo
        lo, hi = ext("Box")
        assert near(lo[1], 0.0) and near(hi[1], TWO_BOX) and near(hi[0], TWO_BOX / 2), (lo, hi)
        check_closed_outward(objects, "Box")
        check_flat_up(objects, "Floor", 0.0)


def main():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    out = os.path.dirname(os.path.abspath(__file__))
    scenes = []
    it = iter(argv)
    for a in it:
        if a == "--out":
            out = os.path.abspath(next(it))
        else:
            scenes.append(a)
    builders = {
        "skirt": lambda d: build_skirt(d, "skirt", 32, 8),
        "dice": lambda d: build_dice(d, "dice"),
        "hanging": lambda d: build_hanging(d, "hanging"),
        # the same scene with a 128 x 129-ring skirt (16640 vertices) for performance work
        "skirt_hires": lambda d: build_skirt(d, "skirt_hires", 128, 127),
        "tablecloth": lambda d: build_tablecloth(d, "tablecloth", 40),
        # the same table with an 81 x 81 tablecloth
        "tablecloth_fine": lambda d: build_tablecloth(d, "tablecloth_fine", 80),
        "drape": lambda d: build_drape(d, "drape"),
        # self-contact stress scenes
        "twist": lambda d: build_twist(d, "twist"),
        "heap": lambda d: build_heap(d, "heap"),
        "two_cloths": lambda d: build_two_cloths(d, "two_cloths"),
    }
    scenes = scenes or list(builders)
    for s in scenes:
        if s not in builders:
            print(f"make_scenes.py: unknown scene '{s}' (known: {' '.join(builders)})", file=sys.stderr)
            sys.exit(2)
    for s in scenes:
        # Build in a scratch folder and move it into place only once every check
        # passed: a failed run leaves the committed exports untouched.
        final = os.path.join(out, s)
        scratch = os.path.join(out, "." + s + ".tmp")
        shutil.rmtree(scratch, ignore_errors=True)
        try:
            path, summary, objects = builders[s](scratch)
            verify(s, objects)
        except BaseException:
            shutil.rmtree(scratch, ignore_errors=True)
            raise
        shutil.rmtree(final, ignore_errors=True)
        os.replace(scratch, final)
        path = os.path.join(final, os.path.basename(path))
        print(f"\n{os.path.relpath(path, out)}")
        print("| object | vertices | faces | triangles | face sizes | min (x, y, z) | max (x, y, z) | material |")
        print("|---|---|---|---|---|---|---|---|")
        for name, nv, nf, nt, sizes, lo, hi, mtl in summary:
            sz = ", ".join(f"{v}x{k}-gon" for k, v in sizes.items())
            fmt = lambda p: "(" + ", ".join(f"{c:.3f}" for c in p) + ")"
            print(f"| {name} | {nv} | {nf} | {nt} | {sz} | {fmt(lo)} | {fmt(hi)} | {', '.join(mtl)} |")


try:
    main()
except AssertionError as e:
    print(f"make_scenes.py: check failed: {e}", file=sys.stderr)
    sys.exit(1)
except Exception as e:  # Blender would otherwise print a trace and exit 0
    print(f"make_scenes.py: {type(e).__name__}: {e}", file=sys.stderr)
    sys.exit(1)
