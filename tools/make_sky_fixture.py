#!/usr/bin/env python3
"""Writes tests/fixtures/sky_rtrace.csv: Radiance's own horizontal irradiance
from its skies (gensky and gendaylit, sun excluded), by rtrace -I on a point
facing up with one ambient bounce over the sky and ground glows (-ad 100000:
rtrace drifts at much higher -ad), for checking
heliodon's sky functions and its hemisphere integration.

Run once from the repository root (needs pyradiance): python3 tools/make_sky_fixture.py
"""
import csv
import os
import re
import subprocess
import tempfile

import pyradiance

BIN = os.path.join(os.path.dirname(pyradiance.__file__), "bin")
LIB = os.path.join(os.path.dirname(pyradiance.__file__), "lib")
GLOWS = """
skyfunc glow skyglow 0 0 4 1 1 1 0
skyglow source sky 0 0 4 0 0 1 180
skyfunc glow groundglow 0 0 4 1 1 1 0
groundglow source ground 0 0 4 0 0 -1 180
"""


def horizontal(generator_args):
    """rtrace's irradiance (W/m2) at a point facing up, and the generator's output."""
    sky = subprocess.run([os.path.join(BIN, generator_args[0])] + generator_args[1:], capture_output=True,
                         text=True, check=True).stdout
    # Keep the sun out (its light on the ground stays, as with +s): zero the solar source.
    sky = re.sub(r"(void light solar\n0\n0\n)3 .*\n", r"\g<1>3 0 0 0\n", sky)
    with tempfile.TemporaryDirectory() as tmp:
        rad = os.path.join(tmp, "sky.rad")
        with open(rad, "w") as f:
            f.write(sky + GLOWS)
        octree = subprocess.run([os.path.join(BIN, "oconv"), rad], capture_output=True, check=True).stdout
        oct_path = os.path.join(tmp, "sky.oct")
        with open(oct_path, "wb") as f:
            f.write(octree)
        env = dict(os.environ, RAYPATH=f".:{LIB}")
        out = subprocess.run([os.path.join(BIN, "rtrace"), "-h", "-I", "-ab", "1", "-ad", "100000", "-as", "0", "-aa", "0",
                              "-lw", "1e-9", oct_path], input="0 0 0 0 0 1\n", capture_output=True, text=True,
                             check=True, env=env).stdout
    r, g, b = (float(v) for v in out.split()[:3])
    return 0.265 * r + 0.670 * g + 0.065 * b


rows = []
for flag, name in [("+s", "clear"), ("+i", "intermediate"), ("-c", "overcast"), ("-u", "uniform")]:
    for alt in [5, 10, 20, 30, 45, 60, 75, 85]:
        rows.append([name, alt, 0, 0, 0, f"{horizontal(['gensky', '-ang', str(alt), '0', flag]):.5f}"])
for alt in [5, 20, 45, 75]:
    rows.append(["turbid", alt, 0, 0, 0, f"{horizontal(['gensky', '-ang', str(alt), '0', '+s', '-t', '5']):.5f}"])
for alt, dni, dhi in [(45, 700, 150), (20, 200, 100), (60, 850, 100), (30, 0, 200), (10, 300, 120), (70, 500, 300)]:
    e = horizontal(['gendaylit', '-ang', str(alt), '0', '-W', str(dni), str(dhi)])
    rows.append(["perez", alt, dni, dhi, 0, f"{e:.5f}"])
with open("tests/fixtures/sky_rtrace.csv", "w", newline="") as f:
    w = csv.writer(f)
    w.writerow(["sky", "altitude_deg", "dni", "dhi", "day", "horizontal_w_m2"])
    w.writerows(rows)
print(f"wrote {len(rows)} rows")
