#!/usr/bin/env python3
"""Checks what `render: curvature with a legend, guides on top` says, on the PNGs vdbhair wrote
(plain Python: zlib decodes PNG; no imaging package needed).

  check_legend.py CURVATURE.png PLAIN.png NO_GUIDES.png

CURVATURE: --color-by curvature --guides G; PLAIN: the same with --color-by root (no legend);
NO_GUIDES: the same as CURVATURE without --guides.
- The legend: CURVATURE has a colour bar (a block at least 6 pixels wide and a quarter of the
  height tall whose rows are each one colour and take at least 12 colours from end to end) in
  its right part; PLAIN has none.
- Guides on top: the pixels where CURVATURE and NO_GUIDES differ are there, and most of them
  are the guides' red.
Prints "ok: ..." and exits 0, or says what failed and exits 1.
"""
import struct
import sys
import zlib


def read_png(path):
    data = open(path, "rb").read()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        raise SystemExit(f"{path}: not a PNG")
    pos, idat, width = 8, b"", None
    while pos < len(data):
        (length,) = struct.unpack(">I", data[pos:pos + 4])
        kind, body = data[pos + 4:pos + 8], data[pos + 8:pos + 8 + length]
        pos += 12 + length
        if kind == b"IHDR":
            width, height, depth, color, _, _, interlace = struct.unpack(">IIBBBBB", body)
            if depth != 8 or color not in (2, 6) or interlace:
                raise SystemExit(f"{path}: expected 8-bit RGB(A), non-interlaced (depth {depth}, colour type {color})")
            channels = 3 if color == 2 else 4
        elif kind == b"IDAT":
            idat += body
    raw = zlib.decompress(idat)
    stride = width * channels
    rows, prev = [], bytearray(stride)
    for y in range(height):
        f, line = raw[y * (stride + 1)], bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - channels] if i >= channels else 0
            b, c = prev[i], prev[i - channels] if i >= channels else 0
            if f == 1:
                line[i] = (line[i] + a) & 255
            elif f == 2:
                line[i] = (line[i] + b) & 255
            elif f == 3:
                line[i] = (line[i] + (a + b) // 2) & 255
            elif f == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        rows.append([tuple(line[x * channels:x * channels + 3]) for x in range(width)])
        prev = line
    return width, height, rows


def colour_bar(width, height, rows):
    """(x, y0, y1, colours) of a colour bar in the right half, or None."""
    need = max(8, height // 4)
    for x in range(width // 2, width - 6):
        run_start, colours = None, set()
        for y in range(height + 1):
            ok = y < height and rows[y][x] != (255, 255, 255) and all(rows[y][x + k] == rows[y][x] for k in range(1, 6))
            if ok:
                if run_start is None:
                    run_start, colours = y, set()
                colours.add(rows[y][x])
            else:
                if run_start is not None and y - run_start >= need and len(colours) >= 12:
                    return x, run_start, y, len(colours)
                run_start = None
    return None


def main():
    curvature, plain, no_guides = (read_png(p) for p in sys.argv[1:4])
    bar = colour_bar(*curvature)
    if not bar:
        raise SystemExit(f"{sys.argv[1]}: no colour bar (legend) in the right half")
    if colour_bar(*plain):
        raise SystemExit(f"{sys.argv[2]}: a colour bar where --color-by root draws no legend (the check finds hair as a legend)")
    w, h, a = curvature
    _, _, b = no_guides
    differ = [(a[y][x], b[y][x]) for y in range(h) for x in range(w) if a[y][x] != b[y][x]]
    red = sum(1 for (r, g, bl), _ in differ if r > g + 80 and r > bl + 80)
    if len(differ) < 50:
        raise SystemExit(f"--guides changed only {len(differ)} pixels")
    if red < 0.5 * len(differ):
        raise SystemExit(f"--guides changed {len(differ)} pixels but only {red} are the guides' red: not drawn on top")
    x, y0, y1, n = bar
    print(f"ok: legend at x = {x}, rows {y0}-{y1} ({n} colours); guides changed {len(differ)} pixels, {red} of them red")


if __name__ == "__main__":
    main()
