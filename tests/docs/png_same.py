#!/usr/bin/python3
"""Whether two PNG pictures show the same thing: the same size, and pixels that differ by at most
a rounding (what another CPU's software rasteriser may change). Used by tests/docs/doctest.lua for
the pictures the docs show next to the command that draws them.

Usage: png_same.py SHOWN DRAWN   exit 0 when the same, 1 when not (saying how), 2 on a bad file.
Only what the project's pictures use is read: 8-bit greyscale, RGB or RGBA, not interlaced.
"""
import struct
import sys
import zlib

import numpy as np


def read_png(path):
    data = open(path, "rb").read()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        raise ValueError("%s: not a PNG file" % path)
    at, idat, header = 8, [], None
    while at + 8 <= len(data):
        n, kind = struct.unpack(">I4s", data[at:at + 8])
        body = data[at + 8:at + 8 + n]
        if kind == b"IHDR":
            header = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat.append(body)
        elif kind == b"IEND":
            break
        at += 12 + n
    if header is None:
        raise ValueError("%s: no IHDR chunk" % path)
    width, height, depth, colour, _, _, interlace = header
    channels = {0: 1, 2: 3, 4: 2, 6: 4}.get(colour)
    if depth != 8 or channels is None or interlace:
        raise ValueError("%s: %d-bit colour type %d%s: only 8-bit grey, RGB or RGBA, not interlaced, is read"
                         % (path, depth, colour, ", interlaced" if interlace else ""))
    raw = np.frombuffer(zlib.decompress(b"".join(idat)), dtype=np.uint8)
    stride = width * channels
    if raw.size != height * (stride + 1):
        raise ValueError("%s: the image data has %d bytes; expected %d" % (path, raw.size, height * (stride + 1)))
    rows = raw.reshape(height, stride + 1)
    out = np.zeros((height, stride), dtype=np.int32)
    prev = [0] * stride
    bpp = channels
    for y in range(height):
        f, cur = rows[y, 0], rows[y, 1:].tolist()
        if f == 1:
            for x in range(bpp, stride):
                cur[x] = (cur[x] + cur[x - bpp]) & 255
        elif f == 2:
            cur = [(v + u) & 255 for v, u in zip(cur, prev)]
        elif f == 3:
            for x in range(stride):
                cur[x] = (cur[x] + (((cur[x - bpp] if x >= bpp else 0) + prev[x]) >> 1)) & 255
        elif f == 4:
            for x in range(stride):
                a = cur[x - bpp] if x >= bpp else 0
                b = prev[x]
                c = prev[x - bpp] if x >= bpp else 0
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                cur[x] = (cur[x] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        elif f != 0:
            raise ValueError("%s: row %d has filter type %d" % (path, y, f))
        out[y] = cur
        prev = cur
    return out.reshape(height, width, channels)


def main():
    if len(sys.argv) != 3:
        sys.stderr.write("usage: png_same.py SHOWN DRAWN\n")
        return 2
    try:
        a, b = read_png(sys.argv[1]), read_png(sys.argv[2])
    except (OSError, ValueError, zlib.error) as e:
        print(e)
        return 2
    if a.shape != b.shape:
        print("%s is %dx%d (%d channels), the command drew %dx%d (%d channels)"
              % (sys.argv[1], a.shape[1], a.shape[0], a.shape[2], b.shape[1], b.shape[0], b.shape[2]))
        return 1
    d = np.abs(a - b).max(axis=2)
    off = float((d > 24).mean())
    if off > 0.005 or float(d.mean()) > 2:
        print("%s differs from what the command draws now: %.2f%% of the pixels by more than 24 levels, "
              "%.2f levels on average" % (sys.argv[1], 100 * off, float(d.mean())))
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
