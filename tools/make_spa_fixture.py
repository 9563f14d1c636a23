#!/usr/bin/env python3
"""Writes tests/fixtures/spa_pvlib.csv: sun positions from pvlib's spa_python
(NREL SPA, delta_t=None: ΔT from pvlib's calculate_deltat) for seeded random
sites and local standard times, to check heliodon's SPA against.

Run once from the repository root (needs pvlib): python3 tools/make_spa_fixture.py
"""
import csv
import random

import pandas as pd
import pvlib

random.seed(20261121)
rows = []
for case in range(80):
    lat = round(random.uniform(-89.0, 89.0), 4)
    lon = round(random.uniform(-180.0, 180.0), 4)
    tz = max(-12, min(14, round(lon / 15.0) + random.choice([-1, 0, 0, 1])))
    year = random.randint(1950, 2049)
    month = random.randint(1, 12)
    day = random.randint(1, 28)
    seconds = random.randint(0, 86399)
    elevation, pressure, temperature = 0.0, 1013.25, 12.0
    if case % 4 == 3:  # some sites with their own altitude and weather
        elevation = round(random.uniform(0, 4000), 1)
        pressure = round(1013.25 * (1 - 2.25577e-5 * elevation) ** 5.25588, 2)
        temperature = round(random.uniform(-20, 35), 1)
    local = pd.Timestamp(year=year, month=month, day=day, tz=f"Etc/GMT{-tz:+d}") + pd.Timedelta(seconds=seconds)
    pos = pvlib.solarposition.spa_python(
        pd.DatetimeIndex([local]), lat, lon, altitude=elevation, pressure=pressure * 100.0,
        temperature=temperature, delta_t=None)
    rows.append([lat, lon, tz, elevation, pressure, temperature, local.strftime("%Y-%m-%d"),
                 local.strftime("%H:%M:%S"), f"{pos['apparent_elevation'].iloc[0]:.8f}",
                 f"{pos['azimuth'].iloc[0]:.8f}"])
with open("tests/fixtures/spa_pvlib.csv", "w", newline="") as f:
    w = csv.writer(f)
    w.writerow(["latitude", "longitude", "timezone", "elevation", "pressure", "temperature", "date", "time",
                "altitude_deg", "azimuth_deg"])
    w.writerows(rows)
print(f"wrote {len(rows)} cases")
