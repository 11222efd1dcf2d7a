#!/usr/bin/env python3
"""The README's reconstruction table: `vdbhair reconstruct` on real hairstyles from ../shared/data
at several guide shares, both methods (helicoid interpolation and point blending).

    scripts/reconstruct_table.py [--guides 5,10,25] [--vdbhair build/bin/vdbhair] [--render DIR]

With --render DIR, also renders the original and both reconstructions at 10 % guides side by side
(`vdbhair render --view three-quarter --head MESH`) into DIR.
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DATA = os.path.join(os.path.dirname(ROOT), "shared", "data")

# (name, hair file, head mesh or None, extra render options)
STYLES = [
    ("straight", "hair/cyhair/straight.hair", "scalp/cem_yuksel/woman_head.ply", ["--up", "z"]),
    ("harolongo (wavy)", "hair/usc_data/harolongo.data", None, []),
    ("Curly_100", "hair/ply/Curly_100.ply", "scalp/ct2hair/Bangs_head.ply", []),
    ("Ruby short", "hair/tressfx/ascii_v2/ruby_short_hair_16_guide.tfx", "scalp/tressfx/ruby_head.obj", []),
]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--guides", default="5,10,25")
    ap.add_argument("--vdbhair", default=os.path.join(ROOT, "build", "bin", "vdbhair"))
    ap.add_argument("--render")
    args = ap.parse_args()
    shares = [s.strip() for s in args.guides.split(",")]
    print("| style | strands | guides | fits: mean / pieces | helicoid: mean / p95 (interpolated) | points: mean / p95 (interpolated) | helicoid s | points s |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- |")
    tmp = tempfile.mkdtemp()
    for name, rel, head, ropts in STYLES:
        f = os.path.join(DATA, rel)
        if not os.path.exists(f):
            print("| %s | (missing: %s) |" % (name, rel))
            continue
        for share in shares:
            base = os.path.join(tmp, name.split()[0].lower() + "_" + share)
            cmd = [args.vdbhair, "reconstruct", f, "-o", base + "_helicoid.hair", "--guides", share + "%", "--json", "--quiet"]
            r = json.loads(subprocess.run(cmd, check=True, capture_output=True, text=True).stdout)
            h, p = r["frechet_relative"]["helicoid"], r["frechet_relative"]["points"]
            print("| %s | %d | %s %% (%d) | %.2f %% / %.1f | %.2f %% / %.2f %% | %.2f %% / %.2f %% | %.2f | %.2f |" % (
                name, r["strands"], share, r["guides"], 100 * r["fit"]["mean"], r["fit"]["pieces_per_strand"],
                100 * h["mean_interpolated"], 100 * h["p95_interpolated"], 100 * p["mean_interpolated"], 100 * p["p95_interpolated"],
                h["seconds"], p["seconds"]))
            sys.stdout.flush()
            if args.render and share == "10":
                os.makedirs(args.render, exist_ok=True)
                subprocess.run([args.vdbhair, "reconstruct", f, "-o", base + "_points.hair", "--guides", "10%", "--method", "points", "--quiet"], check=True)
                out = os.path.join(args.render, name.split()[0].lower())
                extra = ropts + (["--head", os.path.join(DATA, head)] if head else [])
                for tag, src in (("original", f), ("helicoid", base + "_helicoid.hair"), ("points", base + "_points.hair")):
                    subprocess.run([args.vdbhair, "render", src, "-o", "%s_%s.png" % (out, tag), "--quiet", "--view", "three-quarter",
                                    "--width", "360", "--height", "360"] + extra, check=True)


if __name__ == "__main__":
    main()
