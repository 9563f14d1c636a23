#!/usr/bin/env python3
"""Radiance's 3-phase method on a heliodon scene with BSDF windows, to set
beside `heliodon sensors` (complex fenestration validation).

Usage: tools/radiance_threephase.py EXPORT_DIR [--cache DIR]

EXPORT_DIR is what `heliodon export-radiance SCENE --date --time --sky --out
EXPORT_DIR` wrote for a scene with one BSDF panel material (its windows a
`BSDF` material in scene.rad). Radiance's binaries (oconv, rfluxmtx,
rcontrib, dctimestep, rtrace, bsdf2klems) must be on PATH with RAYPATH set:
`pip install pyradiance` ships them. Nothing here is used by heliodon.

    E = V T (D s + sun) + E_rest

- V: rfluxmtx from the sensors (-I+) to the BSDF windows as receiver
  (Klems full basis, h=kf u=Z; the windows' normals point into the room, as
  exported), in the room with its plain glass; kept in --cache per geometry.
- D s: rfluxmtx -V+ from the same windows as sender to the exported sky's
  sky and ground glows without the sun: each incoming Klems patch's mean
  radiance of the hour's sky itself (the daylight matrix applied to the sky,
  with no Reinhart discretisation).
- sun: the sun in its own Klems patch (klems_full.cal's bin of its
  direction), E_n cos(theta) v / P_k, with P_k the patch's projected solid
  angle and v the share of window points that see the sun (overhangs);
  not genskyvec's three patches, which straddle patch boundaries.
- T: the BSDF file through dctimestep (a tensor tree converted to Klems
  with bsdf2klems first).
- E_rest: rtrace of the scene with the BSDF windows black (plain glass, the
  sun through it), at the settings of the export's run.sh.

The 3-phase method loses the light the room sends back to the BSDF windows
and they reflect into the room again (heliodon and rtrace keep it), so it
reads a little lower than both.

Writes EXPORT_DIR/threephase.csv (name,illuminance_lux; area sensors the mean
of their points) and EXPORT_DIR/threephase_parts.csv (through the BSDF
windows, the rest).
"""

import hashlib, math, os, re, subprocess, sys
import numpy as np


def sh(cmd, cwd):
    r = subprocess.run(cmd, shell=True, cwd=cwd, capture_output=True, text=True)
    if r.returncode:
        sys.exit(f'{cmd}: {r.stderr}')
    return r.stdout

def primitives(text):
    """Radiance primitives as (modifier, type, name, strings, ints, reals)."""
    toks = []
    for line in text.splitlines():
        line = line.split('#', 1)[0] if not line.lstrip().startswith('#') else ''
        toks += line.split()
    out, i = [], 0
    while i < len(toks):
        mod, typ, name = toks[i:i + 3]; i += 3
        ns = int(toks[i]); s = toks[i + 1:i + 1 + ns]; i += 1 + ns
        ni = int(toks[i]); n = toks[i + 1:i + 1 + ni]; i += 1 + ni
        nr = int(toks[i]); r = toks[i + 1:i + 1 + nr]; i += 1 + nr
        out.append((mod, typ, name, s, n, r))
    return out

def fmt(p):
    mod, typ, name, s, n, r = p
    return f"{mod} {typ} {name}\n{len(s)} {' '.join(s)}\n{len(n)} {' '.join(n)}\n{len(r)} {' '.join(r)}\n"

def read_matrix(text):
    """Radiance ASCII matrix -> array rows x cols x 3."""
    head, body = text.split('\n\n', 1) if '\n\n' in text else ('', text)
    cols = int(re.search(r'NCOLS=(\d+)', head).group(1))
    vals = np.array(body.split(), dtype=float)
    rows = len(vals) // (3 * cols)
    return vals.reshape(rows, cols, 3)

def write_matrix(path, m):
    rows, cols, _ = m.shape
    with open(path, 'w') as f:
        f.write(f'#?RADIANCE\nNROWS={rows}\nNCOLS={cols}\nNCOMP=3\nFORMAT=ascii\n\n')
        for r in range(rows):
            f.write('\t'.join(' '.join(f'{v:.8e}' for v in m[r, c]) for c in range(cols)) + '\n')

# Klems full basis
THETA = [0, 5, 15, 25, 35, 45, 55, 65, 75, 90]
NPHI = [1, 8, 16, 20, 24, 24, 24, 16, 12]

def klems_bin(D, N, U):
    """klems_full.cal's kbin(N, U) for ray direction D (RHS = 1)."""
    D, N, U = map(np.asarray, (D, N, U))
    pol = math.degrees(math.acos(max(-1, min(1, -D @ N))))
    y = -D @ U + (N @ D) * (N @ U)
    x = -(D @ np.cross(U, N))
    azi = math.degrees(math.atan2(y, x)) % 360
    row = next(r for r in range(9) if pol < THETA[r + 1] or r == 8)
    inc = 360 / NPHI[row]
    k = math.floor((azi + .5 * inc) / inc) if azi < 360 - .5 * inc else 0
    return sum(NPHI[:row]) + k, row

def klems_proj_solid_angle(row):
    lo, hi = map(math.radians, THETA[row:row + 2])
    return math.pi * (math.sin(hi) ** 2 - math.sin(lo) ** 2) / NPHI[row]

def main():
    if len(sys.argv) < 2 or sys.argv[1].startswith('-'):
        sys.exit(__doc__)
    exp = os.path.abspath(sys.argv[1])
    cache = sys.argv[sys.argv.index('--cache') + 1] if '--cache' in sys.argv else os.path.join(exp, 'v_cache')
    os.makedirs(cache, exist_ok=True)
    prims = primitives(open(f'{exp}/scene.rad').read())
    bsdf = {p[2]: p[3][1] for p in prims if p[1] == 'BSDF'}
    assert len(bsdf) == 1, f'one BSDF material expected, found {list(bsdf)}'
    (mat, xml), = bsdf.items()
    windows = [p for p in prims if p[0] == mat]
    room = [p for p in prims if p[0] != mat and p[2] != mat]
    room_rad = ''.join(map(fmt, room))
    open(f'{exp}/tp_room.rad', 'w').write(room_rad)
    recv = '#@rfluxmtx h=kf u=Z\nvoid glow wglow\n0\n0\n4 1 1 1 0\n' + ''.join(fmt(('wglow',) + p[1:]) for p in windows)
    open(f'{exp}/tp_window.rad', 'w').write(recv)
    black = room_rad + 'void plastic tp_black\n0\n0\n5 0 0 0 0 0\n' + ''.join(fmt(('tp_black',) + p[1:]) for p in windows)
    open(f'{exp}/tp_black.rad', 'w').write(black)

    # V: per geometry and sensors (cached)
    pts = open(f'{exp}/sensors.pts').read()
    key = hashlib.sha1((room_rad + recv + pts).encode()).hexdigest()[:16]
    vfile = f'{cache}/{key}.vmx'
    if not os.path.exists(vfile):
        sh(f'rfluxmtx -I+ -ab 12 -ad 65536 -lw 1.5e-5 -faa - tp_window.rad tp_room.rad < sensors.pts > {vfile}.tmp && mv {vfile}.tmp {vfile}', exp)

    # Sky without its sun
    sky = primitives(open(f'{exp}/sky.rad').read())
    sun = next((p for p in sky if p[1] == 'source' and p[0] == 'solar'), None)
    solar = next((p for p in sky if p[1] == 'light' and p[2] == 'solar'), None)
    rest = [p for p in sky if p not in (sun, solar)]
    recv_sky = ''.join(fmt(p) for p in rest if p[1] != 'source')
    recv_sky += '#@rfluxmtx h=u u=Y\n' + ''.join(fmt(p) for p in rest if p[1] == 'source')
    open(f'{exp}/tp_sky.rad', 'w').write(recv_sky)
    send = recv.replace('wglow', 'wsend')
    open(f'{exp}/tp_send.rad', 'w').write(send)
    D = read_matrix(sh('rfluxmtx -V+ -ab 1 -ad 512 -lw 1e-4 -c 20000 -faa tp_send.rad tp_sky.rad tp_room.rad', exp))
    d = D.sum(axis=1, keepdims=True)  # sky + ground: 145 x 1 x 3

    # The sun in its own Klems patch
    corner = np.array([float(v) for v in windows[0][5][:9]]).reshape(3, 3)
    n = np.cross(corner[1] - corner[0], corner[2] - corner[0]); n /= np.linalg.norm(n)  # into the room
    sun_note = 'no sun'
    if sun is not None:
        s = np.array([float(v) for v in sun[5][:3]]); s /= np.linalg.norm(s)
        cos = -s @ n
        if cos > 0:
            angle = float(sun[5][3])
            omega = 2 * math.pi * (1 - math.cos(math.radians(angle / 2)))
            en = np.array([float(v) for v in solar[5][:3]]) * omega
            k, row = klems_bin(s, n, [0, 0, 1])
            # share of window points seeing the sun
            g = 24
            vis_pts = []
            for p in windows:
                a, b, c = np.array([float(v) for v in p[5][:9]]).reshape(3, 3)
                for i in range(g):
                    for j in range(g - i):
                        u, v = (i + 1 / 3) / g, (j + 1 / 3) / g
                        q = a + u * (b - a) + v * (c - a) - n * 1e-3
                        vis_pts.append(f'{q[0]} {q[1]} {q[2]} {s[0]} {s[1]} {s[2]}')
            open(f'{exp}/tp_vis.pts', 'w').write('\n'.join(vis_pts) + '\n')
            open(f'{exp}/tp_vis_sky.rad', 'w').write(f'void glow tp_sun\n0\n0\n4 1 1 1 0\ntp_sun source tp_s\n0\n0\n4 {s[0]} {s[1]} {s[2]} 2\n')
            sh('oconv tp_room.rad tp_vis_sky.rad > tp_vis.oct', exp)
            vis = np.array(sh('rtrace -h -ab 0 -ov tp_vis.oct < tp_vis.pts', exp).split(), dtype=float).reshape(-1, 3)[:, 0].mean()
            d[k, 0] += en * cos * vis / klems_proj_solid_angle(row)
            sun_note = f'sun in Klems patch {k} (row {row}), cos {cos:.3f}, visible {vis:.3f}'
    write_matrix(f'{exp}/tp_d.mtx', d)
    open(f'{exp}/tp_one.vec', 'w').write('#?RADIANCE\nNROWS=1\nNCOLS=1\nNCOMP=3\nFORMAT=ascii\n\n1 1 1\n')
    tmat = xml
    if 'TensorTree' in open(xml).read():
        tmat = f'{exp}/tp_klems.xml'
        sh(f'bsdf2klems {xml} > {tmat}', exp)
    E = read_matrix(sh(f'dctimestep {vfile} {tmat} tp_d.mtx tp_one.vec', exp)).reshape(-1, 3)

    # Everything else: rtrace with the BSDF windows black, the oracle's settings
    run = open(f'{exp}/run.sh').read()
    rt = re.search(r'rtrace .*?scene\.oct', run).group(0).replace('scene.oct', 'tp_black.oct')
    sh('oconv sky.rad tp_black.rad > tp_black.oct', exp)
    R = np.array(sh(f'{rt} < sensors.pts', exp).split(), dtype=float).reshape(-1, 3)

    lum = lambda a: 179 * (0.265 * a[:, 0] + 0.670 * a[:, 1] + 0.065 * a[:, 2])
    cfs, other = lum(E), lum(R)
    names = open(f'{exp}/names.csv').read().split()
    counts = [int(l.split()[1]) for l in open(f'{exp}/sensors.txt').read().splitlines()]
    with open(f'{exp}/threephase.csv', 'w') as f, open(f'{exp}/threephase_parts.csv', 'w') as g:
        f.write('name,illuminance_lux\n'); g.write('name,cfs_lux,other_lux\n')
        k = 0
        for name, c in zip(names, counts):
            f.write(f'{name},{(cfs[k:k + c] + other[k:k + c]).mean():.1f}\n')
            g.write(f'{name},{cfs[k:k + c].mean():.1f},{other[k:k + c].mean():.1f}\n')
            k += c
    print(exp.split('/')[-1], sun_note, xml.split('/')[-1])

main()
