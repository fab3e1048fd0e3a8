#!/usr/bin/env python3
"""One square of several 8-bit RGB PNGs, magnified by pixel replication (no filtering, so every
pixel is seen as rendered), side by side 4 grey pixels apart, as `lattice table2`'s crops are;
standard library only.

    tools/png_crops.py OUT.png X Y SIZE SCALE IN.png...

docs/filtering.md uses it for the crops of exact mode, point-sampled and filtered lattices and
the ground truth side by side (the commands are there)."""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from png_downscale import read_png, write_png  # noqa: E402


def main():
    if len(sys.argv) < 7:
        sys.exit(__doc__)
    try:
        out, x0, y0, size, scale = sys.argv[1], *map(int, sys.argv[2:6])
    except ValueError:
        sys.exit(__doc__)
    if size < 1 or scale < 1:
        sys.exit("SIZE and SCALE must be at least 1")
    images = [read_png(p) for p in sys.argv[6:]]
    for path, (w, h, _) in zip(sys.argv[6:], images):
        if x0 < 0 or y0 < 0 or x0 + size > w or y0 + size > h:
            sys.exit(f"{path}: the square ({x0}, {y0}) + {size} is not inside its {w} x {h} pixels")
    side, gap = size * scale, 4
    width = len(images) * side + (len(images) - 1) * gap
    rows = [bytearray([128] * (3 * width)) for _ in range(side)]
    for k, (_, _, src) in enumerate(images):
        left = k * (side + gap)
        for y in range(side):
            line = src[y0 + y // scale]
            for x in range(side):
                p = 3 * (x0 + x // scale)
                rows[y][3 * (left + x):3 * (left + x) + 3] = line[p:p + 3]
    write_png(out, width, side, rows)


if __name__ == "__main__":
    main()
