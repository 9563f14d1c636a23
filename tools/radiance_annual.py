#!/usr/bin/env python3
"""A Radiance annual run of a heliodon scene, to set beside `heliodon annual`.

Usage: tools/radiance_annual.py SCENE.toml WEATHER.epw OUT_DIR [--heliodon BIN] [--ab 12] [--ad 20000] [--lw 2e-6] [--mf 1] [--hourly] [--spa-sun]

Radiance's binaries (oconv, rfluxmtx, rcontrib, gendaymtx, gendaylit,
dctimestep, rtrace, epw2wea) must be on PATH with RAYPATH set: `pip install
pyradiance` ships them. Nothing here is used by heliodon itself.

The method is the 2-phase with an exact direct sun (the DDS idea on the
2-phase):

    E = DC × S  −  DCd × Ssun  +  Esun

- DC: daylight coefficients of the sensors (rfluxmtx, Reinhart MF:--mf sky and
  ground, -ab/-ad as given) and S the EPW's skies with the sun in its patches
  (gendaymtx);
- DCd: the same with every opaque surface black and -ab 1 (what each sky
  patch gives straight through the glass), and Ssun the sun alone in patches
  (gendaymtx -d): the sun's direct part as the 2-phase smears it, taken out;
- Esun: the sun's direct light traced per hour (gendaylit's sun at the
  hour's middle, rtrace -ab 0), put back exactly. It is also what ASE counts.

Writes OUT_DIR/radiance_annual.csv in `heliodon annual --format csv`'s
columns (name,da300,udi_low,udi,udi_high,ase_hours; occupied 08:00-18:00,
area sensors the mean of their points) and prints the times of each step.
With --hourly it also writes OUT_DIR/radiance_hourly.csv in `annual --hourly`'s
columns (month,day,hour, then each sensor's lux), to pair hour by hour.
"""

import argparse
import datetime
import os
import re
import subprocess
import sys
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path


def run(args, **kw):
    result = subprocess.run(args, capture_output=True, **kw)
    if result.returncode != 0:
        sys.exit(f"{args[0]} failed: {result.stderr.decode(errors='replace').strip()}")
    return result.stdout


def site_of(scene_toml: Path):
    text = scene_toml.read_text()
    get = lambda key: float(re.search(rf"^{key}\s*=\s*(-?[\d.]+)", text, re.M).group(1))
    return get("latitude"), get("longitude"), get("timezone")


def lux_rows(text: str):
    """Rows of R G B irradiance → lux (Radiance's weights)."""
    out = []
    for line in text.strip().splitlines():
        values = [float(v) for v in line.split()]
        out.append([179 * (0.265 * values[i] + 0.670 * values[i + 1] + 0.065 * values[i + 2]) for i in range(0, len(values), 3)])
    return out


def spa_angles(rows, latitude, longitude, timezone):
    """Per wea row: the sun's apparent altitude and azimuth (degrees west of
    south, Radiance's convention) by NREL SPA at the row's time."""
    import pandas as pd
    import pvlib

    times = [pd.Timestamp(2025, int(r.split()[0]), int(r.split()[1])) + pd.Timedelta(hours=float(r.split()[2])) for r in rows]
    index = pd.DatetimeIndex(times).tz_localize(datetime.timezone(datetime.timedelta(hours=timezone)))
    position = pvlib.solarposition.spa_python(index, latitude, longitude)
    return list(zip(position["apparent_elevation"], position["azimuth"] - 180.0))


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("scene", type=Path)
    parser.add_argument("weather", type=Path)
    parser.add_argument("out", type=Path)
    parser.add_argument("--heliodon", default="heliodon")
    # Positive -lw cuts rays below that weight: at -ab 6 -lw 5e-5 a corner
    # of the office read 13% under rtrace at the oracle's settings, at
    # -ab 12 -lw 2e-6 about 5%, the rest being the sky's patches.
    parser.add_argument("--ab", default="12")
    parser.add_argument("--ad", default="20000")
    parser.add_argument("--lw", default="2e-6")
    parser.add_argument("--mf", default="1", help="Reinhart MF of the sky patches (gendaymtx -m, rfluxmtx r<MF>)")
    parser.add_argument("--hourly", action="store_true")
    parser.add_argument("--spa-sun", action="store_true", help="the sun at NREL SPA's position (needs pvlib)")
    args = parser.parse_args()
    out = args.out
    out.mkdir(parents=True, exist_ok=True)
    times = {}
    started = time.time()

    run([args.heliodon, "export-radiance", str(args.scene), "--date", "2025-06-21", "--time", "12:00", "--out", str(out)])
    latitude, longitude, timezone = site_of(args.scene)
    # Radiance: longitude and meridian positive west.
    place = ["-a", str(latitude), "-o", str(-longitude), "-m", str(-15 * timezone)]
    wea = run(["epw2wea", str(args.weather), "/dev/stdout"]).decode()
    header, rows = [], []
    for line in wea.splitlines():
        (rows if line[:1].isdigit() else header).append(line)
    header = [f"latitude {latitude}" if h.startswith("latitude") else h for h in header]
    header = [f"longitude {-longitude}" if h.startswith("longitude") else h for h in header]
    header = [f"time_zone {-15 * timezone}" if h.startswith("time_zone") else h for h in header]
    (out / "site.wea").write_text("\n".join(header + rows) + "\n")

    sky = out / "sky_patches.rad"
    sky.write_text(
        "#@rfluxmtx h=u u=Y\nvoid glow groundglow 0 0 4 1 1 1 0\ngroundglow source ground 0 0 4 0 0 -1 180\n"
        f"#@rfluxmtx h=r{args.mf} u=Y\nvoid glow skyglow 0 0 4 1 1 1 0\nskyglow source skydome 0 0 4 0 0 1 180\n"
    )
    scene = (out / "scene.rad").read_text()
    black = re.sub(r"(void plastic \S+\n0\n0\n5) \S+ \S+ \S+", r"\1 0 0 0", scene)
    (out / "scene_black.rad").write_text(black)
    points = (out / "sensors.pts").read_text()

    t = time.time()
    for name, model, ab in [("dc", "scene.rad", args.ab), ("dcd", "scene_black.rad", "1")]:
        matrix = run(
            ["rfluxmtx", "-I+", "-ab", ab, "-ad", args.ad, "-lw", args.lw, "-faa", "-y", str(len(points.splitlines())), "-", str(sky), str(out / model)],
            input=points.encode(),
        )
        (out / f"{name}.mtx").write_bytes(matrix)
    times["daylight coefficients (2 × rfluxmtx)"] = time.time() - t

    t = time.time()
    for name, flags in [("sky", []), ("sun", ["-d"])]:
        (out / f"{name}.mtx").write_bytes(run(["gendaymtx", "-m", args.mf, *flags, str(out / "site.wea")]))
    total = lux_rows(run(["dctimestep", "-h", str(out / "dc.mtx"), str(out / "sky.mtx")]).decode())
    smeared = lux_rows(run(["dctimestep", "-h", str(out / "dcd.mtx"), str(out / "sun.mtx")]).decode())
    times["skies and products (gendaymtx, dctimestep)"] = time.time() - t

    # The sun alone, traced at each hour with direct normal irradiance.
    t = time.time()

    spa = spa_angles(rows, latitude, longitude, timezone) if args.spa_sun else None

    def direct(k):
        month, day, hour, dni, dhi = rows[k].split()[:5]
        if float(dni) <= 0:
            return None
        when = [month, day, hour, *place] if spa is None else ["-ang", *map(str, spa[k])]
        sun_sky = run(["gendaylit", *when, "-W", dni, dhi]).decode().splitlines()
        if not any(l.startswith("solar source sun") for l in sun_sky):
            return None
        start = next(i for i, l in enumerate(sun_sky) if l.startswith("void light solar"))
        end = next(i for i, l in enumerate(sun_sky) if l.startswith("solar source sun")) + 4
        rad = out / f"sun_{k}.rad"
        rad.write_text("\n".join(sun_sky[start:end]) + "\n")
        oct_path = out / f"sun_{k}.oct"
        oct_path.write_bytes(run(["oconv", str(rad), str(out / "scene.rad")]))
        lux = lux_rows(run(["rtrace", "-h", "-I", "-ab", "0", "-dt", "0", "-dc", "1", "-dj", "0", str(oct_path)], input=points.encode()).decode())
        rad.unlink()
        oct_path.unlink()
        return [row[0] for row in lux]

    with ThreadPoolExecutor(os.cpu_count() or 1) as pool:
        sun = list(pool.map(direct, range(len(rows))))
    times["exact direct sun (gendaylit, rtrace per hour)"] = time.time() - t

    # Columns of dctimestep's output are hours; rows are points.
    def lit_point(p, k):
        return total[p][k] - smeared[p][k] + (sun[k][p] if sun[k] else 0.0)

    counts = [(line.split()[0], int(line.split()[1])) for line in (out / "sensors.txt").read_text().splitlines()]
    occupied = [k for k in range(len(rows)) if 9 <= k % 24 + 1 <= 18]
    lines = ["name,da300,udi_low,udi,udi_high,ase_hours"]
    first = 0
    for name, count in counts:
        span = range(first, first + count)
        first += count

        def at(k):
            direct_sun = sum(sun[k][p] for p in span) / count if sun[k] else 0.0
            return max(sum(lit_point(p, k) for p in span) / count, 0.0), direct_sun

        values = [at(k) for k in occupied]
        share = lambda keep: 100.0 * sum(1 for v in values if keep(v[0])) / len(values)
        ase = sum(1 for v in values if v[1] >= 1000.0)
        lines.append(
            f"{name},{share(lambda v: v >= 300):.1f},{share(lambda v: v < 100):.1f},{share(lambda v: 100 <= v <= 3000):.1f},"
            f"{share(lambda v: v > 3000):.1f},{ase}"
        )
    (out / "radiance_annual.csv").write_text("\n".join(lines) + "\n")
    if args.hourly:
        hourly = ["month,day,hour," + ",".join(name for name, _ in counts)]
        for k, row in enumerate(rows):
            month, day = row.split()[:2]
            values, first = [], 0
            for _, count in counts:
                values.append(max(sum(lit_point(p, k) for p in range(first, first + count)) / count, 0.0))
                first += count
            hourly.append(f"{month},{day},{k % 24 + 1}," + ",".join(f"{v:.1f}" for v in values))
        (out / "radiance_hourly.csv").write_text("\n".join(hourly) + "\n")
    for step, seconds in times.items():
        print(f"{step}: {seconds:.1f} s")
    print(f"in all: {time.time() - started:.1f} s; wrote {out / 'radiance_annual.csv'}")


if __name__ == "__main__":
    main()
