#!/usr/bin/env python3
"""Downscale an 8-bit RGB PNG by an integer factor (box filter), with the standard library only.

    tools/png_downscale.py IN.png OUT.png [FACTOR]      (FACTOR 2 by default)

docs/table2.md uses it to put `lattice table2`'s strips (a dozen 512 x 512 images side by side)
into the docs at half size; the crops beside them are the command's own, unscaled. Reads what
lattice writes: 8-bit RGB, not interlaced; anything else is refused."""
import struct
import sys
import zlib


def read_png(path):
    data = open(path, "rb").read()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        sys.exit(f"{path}: not a PNG")
    pos, idat, head = 8, b"", None
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + length]
        if kind == b"IHDR":
            head = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    w, h, depth, colour, _, _, interlace = head
    if depth != 8 or colour != 2 or interlace != 0:
        sys.exit(f"{path}: only 8-bit RGB, not interlaced")
    raw, stride, rows, prev = zlib.decompress(idat), 3 * w, [], bytearray(3 * w)
    for y in range(h):
        f, line = raw[y * (stride + 1)], bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for x in range(stride):
            a = line[x - 3] if x >= 3 else 0
            b, c = prev[x], (prev[x - 3] if x >= 3 else 0)
            if f == 1:
                line[x] = (line[x] + a) & 255
            elif f == 2:
                line[x] = (line[x] + b) & 255
            elif f == 3:
                line[x] = (line[x] + (a + b) // 2) & 255
            elif f == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[x] = (line[x] + (a if pa <= pb and pa <= pc else (b if pb <= pc else c))) & 255
        rows.append(line)
        prev = line
    return w, h, rows


def write_png(path, w, h, rows):
    def chunk(kind, body):
        return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body))
    raw = b"".join(b"\x00" + bytes(r) for r in rows)
    png = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0))
    open(path, "wb").write(png + chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b""))


def main():
    if len(sys.argv) not in (3, 4):
        sys.exit(__doc__)
    k = int(sys.argv[3]) if len(sys.argv) == 4 else 2
    w, h, rows = read_png(sys.argv[1])
    ow, oh = w // k, h // k
    out = []
    for y in range(oh):
        line = bytearray(3 * ow)
        for x in range(ow):
            for ch in range(3):
                s = sum(rows[y * k + j][3 * (x * k + i) + ch] for j in range(k) for i in range(k))
                line[3 * x + ch] = (s + k * k // 2) // (k * k)
        out.append(line)
    write_png(sys.argv[2], ow, oh, out)


if __name__ == "__main__":
    main()
