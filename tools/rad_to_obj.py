#!/usr/bin/env python3
"""Convert Radiance scene files (polygons with plastic and glass materials) to
an OBJ + MTL pair heliodon reads, and write a scene.toml around them.

Usage:
  tools/rad_to_obj.py OUT_DIR materials.rad objects/*.rad [--points points.txt]
                      [--latitude 40.78 --longitude -73.97 --timezone -5]

Polygons are triangulated by ear clipping in their own plane (concave and
"keyhole" polygons, which Radiance models use for walls with openings, come
out right; a fan would overlap). `plastic` becomes `Kd` (its RGB), `glass`
becomes `d = 1 - transmittance`, its transmissivity turned back into the
transmittance at normal incidence that heliodon's `glass` takes (0.96 ->
0.88). Other primitives and materials are listed and skipped.
Points files (x y z dx dy dz per line) become point sensors named p00, p01...
Standard library only.
"""
import argparse
import os
import sys


def tokens(path):
    with open(path) as f:
        for line in f:
            line = line.split("#", 1)[0]
            yield from line.split()


def read_rad(paths):
    """Radiance primitives: (modifier, type, name, string args, int args, real args)."""
    out = []
    for path in paths:
        it = tokens(path)
        for modifier in it:
            if modifier.startswith("!"):
                raise SystemExit(f"{path}: commands (!...) are not supported")
            kind, name = next(it), next(it)
            args = []
            for _ in range(3):
                n = int(next(it))
                args.append([next(it) for _ in range(n)])
            out.append((modifier, kind, name, args[0], args[1], [float(x) for x in args[2]]))
    return out


def sub(a, b):
    return [a[0] - b[0], a[1] - b[1], a[2] - b[2]]


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def newell(points):
    n = [0.0, 0.0, 0.0]
    for i, p in enumerate(points):
        q = points[(i + 1) % len(points)]
        n[0] += (p[1] - q[1]) * (p[2] + q[2])
        n[1] += (p[2] - q[2]) * (p[0] + q[0])
        n[2] += (p[0] - q[0]) * (p[1] + q[1])
    return n


def area2(a, b, c):
    return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])


def signed_area(loop):
    return 0.5 * sum(loop[i][0] * loop[(i + 1) % len(loop)][1] - loop[(i + 1) % len(loop)][0] * loop[i][1] for i in range(len(loop)))


def ear_clip_2d(p2, idx):
    """Ear clipping of the counter-clockwise polygon p2[idx] (repeated points,
    as bridges to holes leave, are allowed). Index triples."""
    def inside(p, a, b, c):
        return area2(a, b, p) > 1e-12 and area2(b, c, p) > 1e-12 and area2(c, a, p) > 1e-12

    idx = list(idx)
    tris = []
    while len(idx) > 3:
        for k in range(len(idx)):
            i0, i1, i2 = idx[k - 1], idx[k], idx[(k + 1) % len(idx)]
            a, b, c = p2[i0], p2[i1], p2[i2]
            if area2(a, b, c) <= 1e-12:
                if abs(area2(a, b, c)) <= 1e-12 and (b == a or b == c or (b[0] - a[0]) * (c[0] - b[0]) + (b[1] - a[1]) * (c[1] - b[1]) >= 0):
                    del idx[k]  # a repeated or straight-through vertex
                    break
                continue
            if any(inside(p2[j], a, b, c) for j in idx if p2[j] not in (a, b, c)):
                continue
            tris.append((i0, i1, i2))
            del idx[k]
            break
        else:
            break  # no ear: degenerate input; what is left is dropped
    if len(idx) == 3 and area2(p2[idx[0]], p2[idx[1]], p2[idx[2]]) > 1e-12:
        tris.append(tuple(idx))
    return tris


def segments_cross(a, b, c, d):
    """Whether segments ab and cd cross at a point inside both."""
    d1, d2, d3, d4 = area2(c, d, a), area2(c, d, b), area2(a, b, c), area2(a, b, d)
    return ((d1 > 1e-12 and d2 < -1e-12) or (d1 < -1e-12 and d2 > 1e-12)) and ((d3 > 1e-12 and d4 < -1e-12) or (d3 < -1e-12 and d4 > 1e-12))


def ear_clip(points):
    """Triangles (index triples, the polygon's winding) of a polygon as
    Radiance reads it (even-odd): a "keyhole" whose seam returns through
    repeated vertices is split into its loops, loops inside the largest are
    holes, and the holes are bridged into the outline before ear clipping."""
    n = newell(points)
    axis = max(range(3), key=lambda k: abs(n[k]))
    u, v = [(1, 2), (2, 0), (0, 1)][axis]
    p2 = [(p[u], p[v]) for p in points]
    # Split at repeated vertices into loops.
    loops, path = [], []
    for i, p in enumerate(p2):
        hit = next((k for k, j in enumerate(path) if p2[j] == p), None)
        if hit is None:
            path.append(i)
        else:
            loops.append(path[hit:])
            path = path[: hit + 1]
    loops.append(path)
    loops = [lp for lp in loops if len(lp) >= 3 and abs(signed_area([p2[j] for j in lp])) > 1e-12]
    if not loops:
        return []
    loops.sort(key=lambda lp: -abs(signed_area([p2[j] for j in lp])))
    outer, holes = loops[0], loops[1:]
    winding = 1.0 if signed_area([p2[j] for j in outer]) > 0 else -1.0
    # Work counter-clockwise: the outline CCW, holes CW.
    if winding < 0:
        p2 = [(x, -y) for x, y in p2]
    outer = outer if signed_area([p2[j] for j in outer]) > 0 else outer[::-1]
    ring = list(outer)
    for hole in sorted(holes, key=lambda h: -max(p2[j][0] for j in h)):
        hole = hole if signed_area([p2[j] for j in hole]) < 0 else hole[::-1]
        start = max(range(len(hole)), key=lambda k: p2[hole[k]][0])
        h = hole[start]
        edges = [(ring[k], ring[(k + 1) % len(ring)]) for k in range(len(ring))] + [(hole[k], hole[(k + 1) % len(hole)]) for k in range(len(hole))]
        for k in sorted(range(len(ring)), key=lambda k: (p2[ring[k]][0] - p2[h][0]) ** 2 + (p2[ring[k]][1] - p2[h][1]) ** 2):
            o = ring[k]
            if not any(segments_cross(p2[h], p2[o], p2[e0], p2[e1]) for e0, e1 in edges if o not in (e0, e1) and h not in (e0, e1)):
                ring = ring[: k + 1] + hole[start:] + hole[:start] + [h] + ring[k:]
                break
    return ear_clip_2d(p2, ring)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("out")
    ap.add_argument("rad", nargs="+")
    ap.add_argument("--points")
    ap.add_argument("--latitude", type=float, default=40.78)
    ap.add_argument("--longitude", type=float, default=-73.97)
    ap.add_argument("--timezone", type=float, default=-5.0)
    ap.add_argument("--name", default="converted from Radiance")
    a = ap.parse_args()
    prims = read_rad(a.rad)
    materials = {}
    for mod, kind, name, _s, _i, real in prims:
        if kind == "plastic":
            materials[name] = ("Kd", real[:3])
        elif kind == "glass":
            tn = sum(real[:3]) / 3.0
            # Transmittance at normal incidence from Radiance's transmissivity
            # tn: two surfaces of reflectance R = ((n - 1) / (n + 1))^2, n = 1.52.
            r = ((1.52 - 1.0) / (1.52 + 1.0)) ** 2
            materials[name] = ("glass", tn * (1.0 - r) ** 2 / (1.0 - r * r * tn * tn))
    os.makedirs(a.out, exist_ok=True)
    vertices, faces, skipped = [], {}, {}
    for mod, kind, name, _s, _i, real in prims:
        if kind in ("plastic", "glass"):
            continue
        if kind != "polygon":
            skipped[kind] = skipped.get(kind, 0) + 1
            continue
        if mod not in materials:
            skipped[f"polygon of {mod}"] = skipped.get(f"polygon of {mod}", 0) + 1
            continue
        pts = [real[k:k + 3] for k in range(0, len(real), 3)]
        base = len(vertices)
        vertices.extend(pts)
        for t in ear_clip(pts):
            faces.setdefault(mod, []).append(tuple(base + k + 1 for k in t))
    with open(os.path.join(a.out, "model.mtl"), "w") as f:
        for name, (kind, value) in materials.items():
            if kind == "Kd":
                f.write(f"newmtl {name}\nKd {value[0]} {value[1]} {value[2]}\n\n")
            else:
                f.write(f"newmtl {name}\nKd 0 0 0\nd {1.0 - value:.6f}\n\n")
    with open(os.path.join(a.out, "model.obj"), "w") as f:
        f.write("mtllib model.mtl\n")
        for v in vertices:
            f.write(f"v {v[0]:.6f} {v[1]:.6f} {v[2]:.6f}\n")
        for mod, fs in faces.items():
            f.write(f"usemtl {mod}\n")
            for t in fs:
                f.write(f"f {t[0]} {t[1]} {t[2]}\n")
    with open(os.path.join(a.out, "scene.toml"), "w") as f:
        f.write(f'name = "{a.name}"\n\n[site]\nlatitude = {a.latitude}\nlongitude = {a.longitude}\ntimezone = {a.timezone}\n\n'
                '[model]\nobj = "model.obj"\n')
        if a.points:
            with open(a.points) as p:
                rows = [list(map(float, line.split()[:6])) for line in p if len(line.split()) >= 6]
            for k, r in enumerate(rows):
                f.write(f'\n[[sensors]]\nname = "p{k:02d}"\nposition = [{r[0]}, {r[1]}, {r[2]}]\nnormal = [{r[3]}, {r[4]}, {r[5]}]\n')
    for kind, count in skipped.items():
        print(f"skipped {count} {kind}", file=sys.stderr)
    print(f"{len(vertices)} vertices, {sum(len(v) for v in faces.values())} triangles, {len(materials)} materials -> {a.out}")


if __name__ == "__main__":
    main()
