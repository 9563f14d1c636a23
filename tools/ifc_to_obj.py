#!/usr/bin/env python3
"""Convert an IFC building model to the OBJ + MTL + scene.toml heliodon reads,
with IfcOpenShell (`pip install ifcopenshell`; not needed to build or test).

Usage:
  tools/ifc_to_obj.py MODEL.ifc OUT_DIR [--latitude 49.1 --longitude 8.4 --timezone 1]
                      [--spacing 0.5] [--transmittance 0.78]

Every product with a body is triangulated in world coordinates (metres, z
up), except spaces and openings. Faces take the surface style IfcOpenShell
reports: a transparent style becomes glass of visible transmittance
--transmittance (rendering transparency is not a photometric quantity; say
what the glazing is), an opaque one a diffuse reflectance from its colour
(Radiance's RGB weights, clamped to 0.05-0.9). An IfcWindow with no
transparent face at all (early-design exports draw a window as one plain
box) is glazed, and said so: one pane, the outline of its faces in the
plane of most area (the wall's opening has its own reveals). An IfcMember in
a transparent style (a curtain wall's mullions and transoms drawn in its
glazing's style) is an opaque frame, and said so. Each IfcSpace gets sensors 0.8 m
above its floor on a --spacing grid, 0.3 m in from the walls of its box,
named after the space (its LongName; see `space_names` where long names repeat):
a sensor grid where the space fills its box, otherwise the grid's points
over the space's floor, 0.3 m in from its edges too, as point sensors
`<space>/<k>` (an L-shaped corridor's box reaches into the rooms beside it;
a point 2 cm from a wall in the notch of such a space sees that wall as half
its view, and refines the wall's patches around it to a few centimetres).
A model with no IfcSpace (a design model exported before its rooms were
placed) gets point sensors over its floor slabs instead, where something
(a slab, a roof) covers them: 0.8 m above the slab's top, 0.3 m in from
its edges and 0.3 m clear of every wall, column, door or frame that
crosses that work plane, named after the storey and the slab. A model
whose slabs are all stair landings or roofs (Revit's Office_A: an
architect's export without the structure's slabs) has no floors under its
spaces: each space's underside becomes its floor (material space_floor,
reflectance 0.2), and that is said. The site's latitude and
longitude come from IfcSite when given there (0°, 0°, said so, where it gives
none: give --latitude and --longitude), and without --timezone the
standard time is that of the meridian nearest the longitude (said so: an
IFC site names no time zone, and UTC at Chicago puts noon at 6 a.m.).
"""
import argparse
import math
import os
import re
import sys

try:
    import ifcopenshell
    import ifcopenshell.geom
    import ifcopenshell.util.element
    import numpy as np
except ImportError:
    sys.exit("tools/ifc_to_obj.py needs IfcOpenShell: pip install ifcopenshell")

# Not things light meets: zones (an IFC4 IfcExternalSpatialElement is the
# volume around the building, a closed box over every façade), voids, notes.
SKIP = ("IfcSpace", "IfcExternalSpatialElement", "IfcSpatialZone", "IfcOpeningElement", "IfcAnnotation", "IfcGrid",
        "IfcVirtualElement")


def angle(parts):
    """IFC compound plane angle (degrees, minutes, seconds, millionths) to degrees."""
    if not parts:
        return None
    # IFC gives every part the angle's sign, so a longitude of -0° 7' 34"
    # has its sign in the minutes, not the degrees.
    sign = -1.0 if any(p < 0 for p in parts) else 1.0
    values = [abs(p) for p in parts] + [0, 0, 0, 0]
    return sign * (values[0] + values[1] / 60 + values[2] / 3600 + values[3] / 3.6e9)


def name_of(text):
    return re.sub(r"[^A-Za-z0-9_]+", "_", text or "").strip("_") or "unnamed"


def space_names(spaces):
    """Per IfcSpace, its name: the LongName where no other space has it; the
    Name and LongName where a few share it (two flats' "Living Room"); the
    Name where most do (a long name every space has names none)."""
    def count(values):
        seen = {}
        for v in values:
            seen[v] = seen.get(v, 0) + 1
        return seen
    longs = count(s.LongName for s in spaces)
    chosen = []
    for s in spaces:
        if s.LongName and longs[s.LongName] == 1:
            chosen.append(name_of(s.LongName))
        elif s.LongName and 2 * longs[s.LongName] <= len(spaces):
            chosen.append(name_of(f"{s.Name or ''} {s.LongName}"))
        else:
            chosen.append(name_of(s.Name or s.LongName))
    return chosen


def pane(points, tris):
    """A window drawn as a solid, as one pane: the convex outline of its faces
    in the plane of most area (one face of a box; of a skylight drawn as
    stacked, overlapping sheets, the outline of the largest), as triangles
    (corner indices) facing that plane's way. The wall's opening has its own
    reveals; glass as a whole solid would be crossed twice or more."""
    planes = {}
    for t in range(len(tris) // 3):
        a, b, c = (points[tris[3 * t + k]] for k in range(3))
        u, v = [b[i] - a[i] for i in range(3)], [c[i] - a[i] for i in range(3)]
        n = [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]]
        length = sum(x * x for x in n) ** 0.5
        if length == 0:
            continue
        unit = [x / length for x in n]
        # The plane, to a degree and a centimetre.
        key = tuple(round(x * 60) for x in unit) + (round(sum(x * y for x, y in zip(unit, a)) * 100),)
        area, normal, corners = planes.get(key, (0.0, unit, set()))
        planes[key] = (area + 0.5 * length, normal, corners | {tris[3 * t + k] for k in range(3)})
    if not planes:
        return []
    _, n, corners = max(planes.values(), key=lambda p: p[0])
    # In-plane axes, then the outline (Andrew's monotone chain).
    helper = [1.0, 0.0, 0.0] if abs(n[0]) < 0.9 else [0.0, 1.0, 0.0]
    e1 = [n[1] * helper[2] - n[2] * helper[1], n[2] * helper[0] - n[0] * helper[2], n[0] * helper[1] - n[1] * helper[0]]
    e2 = [n[1] * e1[2] - n[2] * e1[1], n[2] * e1[0] - n[0] * e1[2], n[0] * e1[1] - n[1] * e1[0]]
    flat = sorted((sum(x * y for x, y in zip(points[k], e1)), sum(x * y for x, y in zip(points[k], e2)), k) for k in corners)

    def turn(o, a, b):
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])

    lower, upper = [], []
    for p in flat:
        while len(lower) >= 2 and turn(lower[-2], lower[-1], p) <= 1e-12:
            lower.pop()
        lower.append(p)
    for p in reversed(flat):
        while len(upper) >= 2 and turn(upper[-2], upper[-1], p) <= 1e-12:
            upper.pop()
        upper.append(p)
    outline = [p[2] for p in lower[:-1] + upper[:-1]]
    # Counter-clockwise about e1 × e2 = n: the fan faces the plane's way.
    return [(outline[0], outline[i], outline[i + 1]) for i in range(1, len(outline) - 1)]


def transparency(style):
    """A surface style's transparency (0 when none is given)."""
    return style.transparency if style is not None and style.transparency == style.transparency else 0.0


def over_triangles(points, triangles):
    """Per (x, y) point (rows) and triangle (columns; the x and y of its
    corners count, a z is ignored): whether the point lies over the
    triangle, edges included, and its barycentric coordinates (u, v) there.
    Triangles seen edge-on from above hold no point."""
    pts = np.asarray(points, dtype=float).reshape(-1, 1, 2)
    tris = np.asarray(triangles, dtype=float)
    tris = tris.reshape(len(tris), 3, -1)[:, :, :2]
    a, b, c = tris[:, 0], tris[:, 1], tris[:, 2]
    det = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (c[:, 0] - a[:, 0]) * (b[:, 1] - a[:, 1])
    flat = np.abs(det) < 1e-12
    det = np.where(flat, 1.0, det)
    u = ((pts[..., 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (c[:, 0] - a[:, 0]) * (pts[..., 1] - a[:, 1])) / det
    v = ((b[:, 0] - a[:, 0]) * (pts[..., 1] - a[:, 1]) - (pts[..., 0] - a[:, 0]) * (b[:, 1] - a[:, 1])) / det
    over = (u >= -1e-9) & (v >= -1e-9) & (u + v <= 1 + 1e-9) & ~flat
    return over, u, v


def over_floor(points, floor):
    """Per (x, y) point: whether it lies over one of the floor's triangles."""
    over = np.zeros(len(points), dtype=bool)
    for start in range(0, len(points) if floor else 0, 256):
        over[start:start + 256] = over_triangles(points[start:start + 256], floor)[0].any(axis=1)
    return over


def inside_floor(points, floor, inset):
    """Per (x, y) point: whether it lies over the floor and `inset` in from
    its edges (it and eight points that far around it over the floor)."""
    around = [(inset * math.cos(k * math.pi / 4), inset * math.sin(k * math.pi / 4)) for k in range(8)]
    pts = np.asarray(points, dtype=float).reshape(-1, 2)
    inside = over_floor(pts, floor)
    for dx, dy in around:
        inside &= over_floor(pts + (dx, dy), floor)
    return inside


# Slabs that are no floor to read on.
NOT_FLOORS = ("ROOF", "LANDING")
# What stands in a room and keeps the floor's sensors clear of it, and what
# covers one (a floor with nothing over it is a terrace).
STANDING = ("IfcWall", "IfcColumn", "IfcDoor", "IfcWindow", "IfcCurtainWall", "IfcPlate", "IfcMember", "IfcRailing",
            "IfcStair", "IfcStairFlight", "IfcBuildingElementProxy", "IfcBeam")
COVERING = ("IfcSlab", "IfcRoof", "IfcCovering", "IfcPlate")
# The floor a space without a slab under it gets, and its reflectance
# (a mid-grey floor finish; the IES's default floor reflectance is 0.2).
MENDED_FLOOR = "space_floor"
MENDED_REFLECTANCE = 0.2
# Sensors keep this far (m) in from a floor's edges and clear of what stands on it.
CLEARANCE = 0.3
# The work plane's height (m) above the floor.
WORK_PLANE = 0.8


def clear_and_covered(points, height, standing, covering):
    """Per (x, y) point at `height`: whether it lies CLEARANCE or farther
    from every triangle of `standing` that crosses the plane z = height, and
    under a triangle of `covering` that passes more than CLEARANCE over it
    (a pitched roof's, whose eaves are lower, counts where it is high)."""
    pts = np.asarray(points, dtype=float).reshape(-1, 2)
    keep = np.ones(len(pts), dtype=bool)
    if len(pts) == 0:
        return keep
    tris = np.asarray(standing, dtype=float).reshape(-1, 3, 3)
    z = tris[:, :, 2]
    crossing = tris[(z.min(axis=1) < height) & (z.max(axis=1) > height)]
    # Each crossing triangle's cut by the plane: the two points where its edges cross it.
    ends = []
    for t in crossing:
        cut = []
        for i in range(3):
            a, b = t[i], t[(i + 1) % 3]
            if (a[2] - height) * (b[2] - height) < 0:
                f = (height - a[2]) / (b[2] - a[2])
                cut.append(a[:2] + f * (b[:2] - a[:2]))
        if len(cut) == 2:
            ends.append(cut)
    if ends:
        seg = np.asarray(ends)
        a, d = seg[:, 0], seg[:, 1] - seg[:, 0]
        length2 = np.maximum((d * d).sum(axis=1), 1e-12)
        for start in range(0, len(pts), 256):
            p = pts[start:start + 256, None, :]
            f = np.clip(((p - a) * d).sum(axis=2) / length2, 0.0, 1.0)
            gap = np.linalg.norm(p - (a + f[:, :, None] * d), axis=2).min(axis=1)
            keep[start:start + 256] &= gap >= CLEARANCE
    over = np.asarray(covering, dtype=float).reshape(-1, 3, 3)
    over = over[over[:, :, 2].max(axis=1) > height + CLEARANCE]
    covered = np.zeros(len(pts), dtype=bool)
    if len(over):
        z = over[:, :, 2]
        for start in range(0, len(pts), 256):
            inside, u, v = over_triangles(pts[start:start + 256], over)
            above = z[:, 0] + u * (z[:, 1] - z[:, 0]) + v * (z[:, 2] - z[:, 0]) > height + CLEARANCE
            covered[start:start + 256] = (inside & above).any(axis=1)
    return keep & covered


def floor_tops(points, tris):
    """A slab's top: its faces that look up, within 5 cm of the highest of
    them, as corners; and that height."""
    up = []
    for t in range(len(tris) // 3):
        a, b, c = (points[tris[3 * t + k]] for k in range(3))
        nz = (b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1])
        length = math.dist((0, 0, 0), [(b[1] - a[1]) * (c[2] - a[2]) - (b[2] - a[2]) * (c[1] - a[1]),
                                       (b[2] - a[2]) * (c[0] - a[0]) - (b[0] - a[0]) * (c[2] - a[2]), nz])
        if length > 0 and nz > 0.99 * length:
            up.append((a, b, c))
    if not up:
        return [], None
    top = max(p[2] for t in up for p in t)
    return [t for t in up if min(p[2] for p in t) > top - 0.05], top


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("ifc")
    ap.add_argument("out")
    ap.add_argument("--latitude", type=float)
    ap.add_argument("--longitude", type=float)
    ap.add_argument("--timezone", type=float)
    ap.add_argument("--spacing", type=float, default=0.5)
    ap.add_argument("--transmittance", type=float, default=0.78)
    a = ap.parse_args()
    model = ifcopenshell.open(a.ifc)
    settings = ifcopenshell.geom.settings()
    settings.set("use-world-coords", True)
    os.makedirs(a.out, exist_ok=True)
    vertices, faces, materials, spaces, skipped = [], {}, {}, [], {}
    # For a model without spaces: the floor slabs' tops, what stands and what covers.
    slab_tops, standing, covering = [], [], []
    names = dict(zip((s.id() for s in model.by_type("IfcSpace")), space_names(model.by_type("IfcSpace"))))
    glazed_windows = 0
    framed_members = set()
    # An export without floor slabs (only landings, or none) gets each
    # space's underside as its floor: without one the rooms read the
    # ground's light through a floor that is not there.
    slabs = model.by_type("IfcSlab")
    mend_floors = bool(model.by_type("IfcSpace")) and all(s.PredefinedType in NOT_FLOORS for s in slabs)
    mended = 0
    iterator = ifcopenshell.geom.iterator(settings, model)
    if not iterator.initialize():
        sys.exit(f"{a.ifc}: no geometry IfcOpenShell can read")
    while True:
        shape = iterator.get()
        product = model.by_id(shape.id)
        geometry = shape.geometry
        verts = geometry.verts
        points = [verts[k:k + 3] for k in range(0, len(verts), 3)]
        tris = geometry.faces
        corners = [[points[tris[3 * t + k]] for k in range(3)] for t in range(len(tris) // 3)]
        if product.is_a("IfcSpace"):
            if points:
                lo = [min(p[k] for p in points) for k in range(3)]
                hi = [max(p[k] for p in points) for k in range(3)]
                # The floor: the faces of the space's solid that face down.
                down = [c for c in corners
                        if (c[1][0] - c[0][0]) * (c[2][1] - c[0][1]) - (c[2][0] - c[0][0]) * (c[1][1] - c[0][1]) < 0]
                spaces.append((names[product.id()], lo, hi, [[p[:2] for p in c] for c in down]))
                # Its floor: the faces at the bottom of its solid, turned to face up.
                bottom = [c for c in down if max(p[2] for p in c) < lo[2] + 0.01]
                if mend_floors and bottom:
                    mended += 1
                    materials.setdefault(MENDED_FLOOR, ("Kd", MENDED_REFLECTANCE))
                    for c in bottom:
                        vertices.extend([c[0], c[2], c[1]])
                        faces.setdefault(MENDED_FLOOR, []).append((len(vertices) - 2, len(vertices) - 1, len(vertices)))
        elif product.is_a() in SKIP or any(product.is_a(kind) for kind in SKIP):
            skipped[product.is_a()] = skipped.get(product.is_a(), 0) + 1
        else:
            base = len(vertices)
            vertices.extend(points)
            if any(product.is_a(kind) for kind in STANDING):
                standing.extend(corners)
            if any(product.is_a(kind) for kind in COVERING):
                covering.extend(corners)
            if product.is_a("IfcSlab") and product.PredefinedType not in NOT_FLOORS:
                top, height = floor_tops(points, tris)
                if top:
                    storey = ifcopenshell.util.element.get_container(product)
                    slab_tops.append((name_of(f"{storey.Name if storey else ''} {product.Name or product.GlobalId}"), top, height))
            styles = geometry.materials
            ids = geometry.material_ids
            face_styles = [styles[ids[t]] if ids and ids[t] >= 0 and ids[t] < len(styles) else None for t in range(len(tris) // 3)]
            glaze_all = product.is_a("IfcWindow") and face_styles and all(transparency(st) <= 0.3 for st in face_styles)
            glazed_windows += bool(glaze_all)
            if glaze_all:
                materials.setdefault("window_glass", ("glass", a.transmittance))
                faces.setdefault("window_glass", []).extend(tuple(base + k + 1 for k in t) for t in pane(points, tris))
            for t in range(len(tris) // 3):
                style = face_styles[t]
                if glaze_all:
                    continue
                if style is None:
                    key = "default"
                    materials.setdefault(key, ("Kd", 0.5))
                else:
                    transparent = transparency(style)
                    diffuse = style.diffuse
                    colour = (diffuse.r(), diffuse.g(), diffuse.b()) if diffuse is not None else (0.6, 0.6, 0.6)
                    key = name_of(style.name)
                    # A mullion or transom drawn in its curtain wall's
                    # glazing style: a frame, not glass.
                    frame = transparent > 0.3 and product.is_a("IfcMember")
                    if frame:
                        key += "_frame"
                        framed_members.add(product.id())
                    if transparent > 0.3 and not frame:
                        key += "_glass"
                        materials.setdefault(key, ("glass", a.transmittance))
                    else:
                        rho = 0.265 * colour[0] + 0.670 * colour[1] + 0.065 * colour[2]
                        materials.setdefault(key, ("Kd", min(0.9, max(0.05, rho))))
                faces.setdefault(key, []).append(tuple(base + tris[3 * t + k] + 1 for k in range(3)))
        if not iterator.next():
            break
    with open(os.path.join(a.out, "model.mtl"), "w") as f:
        for name, (kind, value) in materials.items():
            if kind == "Kd":
                f.write(f"newmtl {name}\nKd {value:.3f} {value:.3f} {value:.3f}\n\n")
            else:
                f.write(f"newmtl {name}\nKd 0 0 0\nd {1.0 - value:.3f}\n\n")
    with open(os.path.join(a.out, "model.obj"), "w") as f:
        f.write(f"# {os.path.basename(a.ifc)} through IfcOpenShell\nmtllib model.mtl\n")
        for v in vertices:
            f.write(f"v {v[0]:.5f} {v[1]:.5f} {v[2]:.5f}\n")
        for name, tris in faces.items():
            f.write(f"usemtl {name}\n")
            for t in tris:
                f.write(f"f {t[0]} {t[1]} {t[2]}\n")
    site = next(iter(model.by_type("IfcSite")), None)
    def coordinate(given, ref):
        """The flag's value, else IfcSite's, else 0 and whether it fell to that."""
        if given is not None:
            return given, False
        if site and getattr(site, ref):
            return angle(getattr(site, ref)), False
        return 0.0, True
    (latitude, no_latitude), (longitude, no_longitude) = coordinate(a.latitude, "RefLatitude"), coordinate(a.longitude, "RefLongitude")
    unplaced = [name for name, missing in (("latitude", no_latitude), ("longitude", no_longitude)) if missing]
    if unplaced:
        # The sun at 0°, 0° is not the site's: say so, rather than answer for the equator.
        print(f"IfcSite gives no {' or '.join(unplaced)}: scene.toml puts the site at {latitude:.4f}°, {longitude:.4f}°; "
              f"give --latitude and --longitude for the building's own sun", file=sys.stderr)
    timezone = a.timezone
    if timezone is None:
        timezone = float(round(longitude / 15.0))
        print(f"timezone {timezone:+.0f} h: the meridian nearest longitude {longitude:.2f}° (give --timezone for the site's own)")
    with open(os.path.join(a.out, "scene.toml"), "w") as f:
        f.write(f'name = "{os.path.basename(a.ifc)}"\n\n[site]\nlatitude = {latitude:.4f}\nlongitude = {longitude:.4f}\n'
                f'timezone = {timezone}\n\n[model]\nobj = "model.obj"\n')
        used = set()
        partial = 0
        # Without spaces, the covered floors: (name, lo, hi, floor, which grid points to keep).
        floors = []
        if not any(hi[0] - lo[0] >= 2 * CLEARANCE + a.spacing and hi[1] - lo[1] >= 2 * CLEARANCE + a.spacing for _, lo, hi, _ in spaces):
            for name, top, height in slab_tops:
                lo = [min(p[k] for t in top for p in t) for k in range(2)] + [height]
                hi = [max(p[k] for t in top for p in t) for k in range(2)] + [height]
                floors.append((name, lo, hi, [[p[:2] for p in t] for t in top],
                               lambda pts, h=height + WORK_PLANE: clear_and_covered(pts, h, standing, covering)))
        floor_sensors = 0
        for name, lo, hi, floor, keep in [(*s, None) for s in spaces] + floors:
            if hi[0] - lo[0] < 2 * CLEARANCE + a.spacing or hi[1] - lo[1] < 2 * CLEARANCE + a.spacing:
                continue
            (x0, y0), (x1, y1), height = (lo[0] + CLEARANCE, lo[1] + CLEARANCE), (hi[0] - CLEARANCE, hi[1] - CLEARANCE), lo[2] + WORK_PLANE
            # The grid's points as heliodon places them: centres of spacing cells from min.
            nx, ny = int((x1 - x0) / a.spacing + 1e-9), int((y1 - y0) / a.spacing + 1e-9)
            points = [(x0 + (i + 0.5) * a.spacing, y0 + (j + 0.5) * a.spacing) for j in range(ny) for i in range(nx)]
            inside = list(np.flatnonzero(over_floor(points, floor)))
            whole = not floor or len(inside) == len(points)
            if keep is not None:
                inside = [k for k, ok in zip(inside, keep([points[k] for k in inside])) if ok]
                whole = False
            if not whole:
                inside = [k for k, ok in zip(inside, inside_floor([points[k] for k in inside], floor, CLEARANCE)) if ok]
                if not inside:
                    continue
            while name in used:
                name += "_"
            used.add(name)
            if whole:
                f.write(f'\n[[sensor_grids]]\nname = "{name}"\nmin = [{x0:.3f}, {y0:.3f}]\n'
                        f'max = [{x1:.3f}, {y1:.3f}]\nheight = {height:.3f}\nspacing = {a.spacing}\n')
                continue
            if keep is None:
                partial += 1
            else:
                floor_sensors += len(inside)
            for k in inside:
                x, y = points[k]
                f.write(f'\n[[sensors]]\nname = "{name}/{k}"\nposition = [{x:.3f}, {y:.3f}, {height:.3f}]\nnormal = [0.0, 0.0, 1.0]\n')
    for kind, count in sorted(skipped.items()):
        print(f"skipped {count} {kind}", file=sys.stderr)
    if glazed_windows:
        print(f"{glazed_windows} IfcWindow with no transparent face: glazed as one pane, the outline of their faces in the plane of most area (glass, transmittance {a.transmittance})",
              file=sys.stderr)
    if framed_members:
        print(f"{len(framed_members)} IfcMember in a transparent style (mullions and transoms drawn in the glazing's style): "
              "read as opaque frames, their reflectance from the style's colour", file=sys.stderr)
    if floors:
        print(f"no IfcSpace with room for sensors: {floor_sensors} point sensors over {len(used)} of {len(floors)} floor slabs "
              f"where something covers them, {WORK_PLANE} m above their tops, {CLEARANCE} m clear of their edges, walls and frames",
              file=sys.stderr)
    if not used:
        print("no IfcSpace with room for sensors: scene.toml has none; add [[sensor_grids]] or [[sensors]] to it", file=sys.stderr)
    if partial:
        print(f"{partial} spaces do not fill their box: point sensors over their floors instead of a grid", file=sys.stderr)
    if mended:
        what = f"no IfcSlab but {len(slabs)} stair landings or roofs" if slabs else "no IfcSlab"
        print(f"{what}: the spaces have no floors under them (an export without the structure's slabs?); "
              f"{mended} spaces get their underside as a floor, material {MENDED_FLOOR} of reflectance {MENDED_REFLECTANCE} "
              "(change it in model.mtl)", file=sys.stderr)
    print(f"{len(vertices)} vertices, {sum(len(v) for v in faces.values())} triangles, {len(materials)} materials, "
          f"{len(used)} {'floors' if floors else 'spaces'} with sensors -> {a.out}")


if __name__ == "__main__":
    main()
