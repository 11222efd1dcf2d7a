#!/usr/bin/env python3
"""The README's picture of `synth` (docs/synth/example_vs_synth.png): each example beside what
`synth` makes of it with its defaults (seed 0, `--head` the groom's own head), on that head, three
quarters from the front. Run with Debian's /usr/bin/python3 after a build:

    /usr/bin/python3 scripts/synth_picture.py [--out docs/synth/example_vs_synth.png]
"""
import argparse
import os
import struct
import subprocess
import sys
import tempfile
import zlib

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "build", "python"))
sys.path.insert(0, os.path.join(ROOT, "scripts"))
import vdbhair  # noqa: E402
from head_table import DATA  # noqa: E402

# title, hair, head mesh, synth's options beyond the defaults
EXAMPLES = [
    ("Ruby short", "hair/tressfx/ascii_v2/ruby_short_hair_16_guide.tfx", "scalp/tressfx/ruby_head.obj", ["--front", "z"]),
    ("TressFX free ponytail", "hair/tressfx/ascii_v2/hair_free_16_guide.tfx", "scalp/tressfx/head_max4.obj", []),
]


def write_png(path, rgba):
    """An 8-bit RGBA PNG (no filter), with the standard library alone."""
    h, w, _ = rgba.shape
    raw = b"".join(b"\x00" + rgba[y].tobytes() for y in range(h))

    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)

    with open(path + ".tmp", "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 6, 0, 0, 0)) +
                chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b""))
    os.replace(path + ".tmp", path)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--vdbhair", default=os.path.join(ROOT, "build", "bin", "vdbhair"))
    ap.add_argument("--out", default=os.path.join(ROOT, "docs", "synth", "example_vs_synth.png"))
    ap.add_argument("--size", type=int, default=560)
    args = ap.parse_args()
    tmp = tempfile.mkdtemp()
    panels = []
    for title, hair, head, opts in EXAMPLES:
        hair, head = os.path.join(DATA, hair), os.path.join(DATA, head)
        out = os.path.join(tmp, "synth.hair")
        subprocess.run([args.vdbhair, "synth", hair, "-o", out, "--head", head, "--seed", "0", "--quiet"] + opts, check=True)
        for strands, label in ((hair, "example: " + title), (out, "synth (defaults)")):
            panels.append(vdbhair.render(vdbhair.read(strands), width=args.size, height=args.size, head=head, title=label))
    write_png(args.out, np.concatenate(panels, axis=1))
    print(args.out)


if __name__ == "__main__":
    main()
