#!/usr/bin/env python3
"""How noisy the light engine's indirect light is in a picture.

Compares a picture drawn at the default settings with a converged reference
of the same view (`heliodon render ... --quality 16 --hdr REF.hdr`): the
relative RMS luminance difference per pixel, over the pixels the engine's rays
draw. Pixels drawn alike in both (the sky, the views through glass) are left
out; so are pixels darker than a thousandth of the reference's mean.

Usage:
  heliodon render SCENE --date D --time T --out a.png --hdr a.hdr
  heliodon render SCENE --date D --time T --out b.png --hdr b.hdr --quality 16
  tools/indirect_noise.py a.hdr b.hdr [--map errors.ppm]

--map writes the signed error per pixel (red brighter, blue darker than the
reference, full colour at 10%). Needs numpy and Radiance's pvalue on PATH
(pip install pyradiance: its binaries are in the wheel's bin folder).
"""

import argparse
import subprocess
import sys

import numpy as np


def luminance(path):
    """The picture's luminance (Radiance's brightness), as rows × columns."""
    try:
        head = subprocess.run(["pvalue", "-h", "-o", "-b", "-d", path], capture_output=True, text=True, check=True).stdout.split("\n")
    except (OSError, subprocess.CalledProcessError) as error:
        sys.exit(f"error: {path}: cannot read the picture with pvalue: {error}")
    # The first line is the resolution string: -Y rows +X columns.
    size = head[0].split()
    rows, columns = int(size[1]), int(size[3])
    values = np.array([float(v) for v in head[1:] if v.strip()])
    if values.size != rows * columns:
        sys.exit(f"error: {path}: {values.size} pixels where {rows} × {columns} were announced")
    return values.reshape(rows, columns)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("default")
    parser.add_argument("reference")
    parser.add_argument("--map", help="write the signed error map here (PPM)")
    args = parser.parse_args()
    a, b = luminance(args.default), luminance(args.reference)
    if a.shape != b.shape:
        sys.exit(f"error: {args.default} is {a.shape[1]} × {a.shape[0]}, {args.reference} is {b.shape[1]} × {b.shape[0]}")
    drawn = (a != b) & (b > 1e-3 * b.mean())
    error = np.where(drawn, (a - b) / np.where(drawn, b, 1.0), 0.0)
    rms = np.sqrt(np.mean(error[drawn] ** 2))
    print(f"{drawn.sum()} of {a.size} pixels: relative RMS {100 * rms:.2f}%, mean {100 * (a[drawn].sum() / b[drawn].sum() - 1):+.2f}%")
    if args.map:
        e = np.clip(error / 0.1, -1.0, 1.0)
        rgb = np.stack([128 + 127 * e, 128 - 127 * np.abs(e), 128 - 127 * e], axis=-1).astype(np.uint8)
        rgb[~drawn] = 0
        with open(args.map, "wb") as f:
            f.write(f"P6 {a.shape[1]} {a.shape[0]} 255\n".encode())
            f.write(rgb.tobytes())


if __name__ == "__main__":
    main()
