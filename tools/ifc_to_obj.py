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
(Radiance's RGB weights, clamped to 0.05-0.9). Each IfcSpace gets a sensor
grid 0.8 m above its floor, 0.3 m in from its walls, named after the space.
The site's latitude and longitude come from IfcSite when given there.
"""
import argparse
import os
import re
import sys

try:
    import ifcopenshell
    import ifcopenshell.geom
except ImportError:
    sys.exit("tools/ifc_to_obj.py needs IfcOpenShell: pip install ifcopenshell")

SKIP = ("IfcSpace", "IfcOpeningElement", "IfcAnnotation", "IfcGrid", "IfcVirtualElement")


def angle(parts):
    """IFC compound plane angle (degrees, minutes, seconds, millionths) to degrees."""
    if not parts:
        return None
    sign = -1.0 if parts[0] < 0 else 1.0
    values = [abs(p) for p in parts] + [0, 0, 0, 0]
    return sign * (values[0] + values[1] / 60 + values[2] / 3600 + values[3] / 3.6e9)


def name_of(text):
    return re.sub(r"[^A-Za-z0-9_]+", "_", text or "").strip("_") or "unnamed"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("ifc")
    ap.add_argument("out")
    ap.add_argument("--latitude", type=float)
    ap.add_argument("--longitude", type=float)
    ap.add_argument("--timezone", type=float, default=0.0)
    ap.add_argument("--spacing", type=float, default=0.5)
    ap.add_argument("--transmittance", type=float, default=0.78)
    a = ap.parse_args()
    model = ifcopenshell.open(a.ifc)
    settings = ifcopenshell.geom.settings()
    settings.set("use-world-coords", True)
    os.makedirs(a.out, exist_ok=True)
    vertices, faces, materials, spaces, skipped = [], {}, {}, [], {}
    iterator = ifcopenshell.geom.iterator(settings, model)
    if not iterator.initialize():
        sys.exit(f"{a.ifc}: no geometry IfcOpenShell can read")
    while True:
        shape = iterator.get()
        product = model.by_id(shape.id)
        geometry = shape.geometry
        verts = geometry.verts
        points = [verts[k:k + 3] for k in range(0, len(verts), 3)]
        if product.is_a("IfcSpace"):
            if points:
                lo = [min(p[k] for p in points) for k in range(3)]
                hi = [max(p[k] for p in points) for k in range(3)]
                spaces.append((name_of(product.LongName or product.Name), lo, hi))
        elif product.is_a() in SKIP or any(product.is_a(kind) for kind in SKIP):
            skipped[product.is_a()] = skipped.get(product.is_a(), 0) + 1
        else:
            base = len(vertices)
            vertices.extend(points)
            styles = geometry.materials
            ids = geometry.material_ids
            tris = geometry.faces
            for t in range(len(tris) // 3):
                style = styles[ids[t]] if ids and ids[t] >= 0 and ids[t] < len(styles) else None
                if style is None:
                    key = "default"
                    materials.setdefault(key, ("Kd", 0.5))
                else:
                    transparent = style.transparency if style.transparency == style.transparency else 0.0
                    diffuse = style.diffuse
                    colour = (diffuse.r(), diffuse.g(), diffuse.b()) if diffuse is not None else (0.6, 0.6, 0.6)
                    key = name_of(style.name)
                    if transparent > 0.3:
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
    latitude = a.latitude if a.latitude is not None else (angle(site.RefLatitude) if site and site.RefLatitude else 0.0)
    longitude = a.longitude if a.longitude is not None else (angle(site.RefLongitude) if site and site.RefLongitude else 0.0)
    with open(os.path.join(a.out, "scene.toml"), "w") as f:
        f.write(f'name = "{os.path.basename(a.ifc)}"\n\n[site]\nlatitude = {latitude:.4f}\nlongitude = {longitude:.4f}\n'
                f'timezone = {a.timezone}\n\n[model]\nobj = "model.obj"\n')
        used = set()
        for name, lo, hi in spaces:
            if hi[0] - lo[0] < 0.6 + a.spacing or hi[1] - lo[1] < 0.6 + a.spacing:
                continue
            while name in used:
                name += "_"
            used.add(name)
            f.write(f'\n[[sensor_grids]]\nname = "{name}"\nmin = [{lo[0] + 0.3:.3f}, {lo[1] + 0.3:.3f}]\n'
                    f'max = [{hi[0] - 0.3:.3f}, {hi[1] - 0.3:.3f}]\nheight = {lo[2] + 0.8:.3f}\nspacing = {a.spacing}\n')
    for kind, count in sorted(skipped.items()):
        print(f"skipped {count} {kind}", file=sys.stderr)
    print(f"{len(vertices)} vertices, {sum(len(v) for v in faces.values())} triangles, {len(materials)} materials, "
          f"{len(used)} sensor grids -> {a.out}")


if __name__ == "__main__":
    main()
