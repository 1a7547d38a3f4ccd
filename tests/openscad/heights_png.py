"""Writes heights.png, the PNG heightmap of surface.scad (run once; the file is committed).

A 12 x 9 RGB image: a red-green ramp across, a blue ramp down and a bright spot,
so every channel weighs in OpenSCAD's luma (0.2126 R + 0.7152 G + 0.0722 B) and
the top row (the largest y in OpenSCAD) differs from the bottom one.
"""
from pathlib import Path

import imageio.v3 as iio
import numpy as np


def main() -> None:
    rows, columns = 9, 12
    i, j = np.meshgrid(np.arange(rows), np.arange(columns), indexing="ij")
    red = 20 + 235 * j / (columns - 1)
    green = 30 + 150 * (1 - j / (columns - 1)) * (i / (rows - 1))
    blue = 255 * (1 - i / (rows - 1))
    spot = 120 * np.exp(-((i - 2) ** 2 + (j - 8) ** 2) / 3.0)
    image = np.stack([red, np.minimum(green + spot, 255), blue], axis=-1)
    iio.imwrite(Path(__file__).with_name("heights.png"), np.round(image).astype(np.uint8))


if __name__ == "__main__":
    main()
