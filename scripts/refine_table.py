#!/usr/bin/env python3
"""Runs `vdbhair refine --json` on every shared hairstyle (../shared/data) with its head, and
prints the README's refinement table (markdown). Usage:

    scripts/refine_table.py [--levels N] [--mode consistent|field] [--vdbhair build/bin/vdbhair] [--render DIR]

With --render DIR, also renders before/after previews with the head into DIR.
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
DATA = os.path.join(os.path.dirname(ROOT), "shared", "data")

# (name, hair file, head mesh or None, extra render options)
STYLES = [
    ("straight", "hair/cyhair/straight.hair", "scalp/cem_yuksel/woman_head.ply", ["--up", "z", "--facing", "y"]),
    ("harolongo (wavy)", "hair/usc_data/harolongo.data", None, []),
    ("Ruby short", "hair/tressfx/ascii_v2/ruby_short_hair_16_guide.tfx", "scalp/tressfx/ruby_head.obj", []),
    ("Ruby long", "hair/tressfx/ascii_v2/ruby_long_hair_16_guide.tfx", "scalp/tressfx/ruby_head.obj", []),
    ("Curly_100", "hair/ply/Curly_100.ply", "scalp/ct2hair/Bangs_head.ply", []),
    ("Bangs_100", "hair/cyhair/Bangs_100.hair", "scalp/ct2hair/Bangs_head.ply", []),
    ("ponytail tail", "hair/tressfx/ascii_v2/hair_tail_16_guide.tfx", "scalp/tressfx/head_max4.obj", []),
    ("ponytail free", "hair/tressfx/ascii_v2/hair_free_16_guide.tfx", "scalp/tressfx/head_max4.obj", []),
    ("Ratboy mohawk", "hair/tressfx/binary_v4/Ratboy_mohawk.tfx", None, []),
    ("Sintel", "hair/tressfx/binary_v4/GEO-sintel_hair_emit.001-sintel_hair.tfx", "scalp/sintel/sintel.obj", []),
    ("HairNet blend", "hair/hairnet_convdata/strands00014_00035_00010.convdata", "scalp/usc_hairsalon/head_model.ply", []),
]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--levels", type=int, default=1)
    ap.add_argument("--mode", default="consistent")
    ap.add_argument("--vdbhair", default=os.path.join(ROOT, "build", "bin", "vdbhair"))
    ap.add_argument("--render")
    ap.add_argument("--width", type=int, default=400, help="width of the rendered previews")
    ap.add_argument("--head-voxel", type=float, default=0.0, help="voxel size of the head level sets (0: the scalp verb's default)")
    args = ap.parse_args()
    if not os.path.isdir(DATA):
        sys.exit("refine_table: %s not found" % DATA)
    tmp = tempfile.mkdtemp(prefix="vdbhair-refine-")
    print("| hairstyle | voxel | full length | leave hair | in head before → after | curvature kept (8 seg / vertex) | tips in place | displacement mean / p95 (voxels) | coherence before → after | corrected / left as they were |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    for name, hair, head, ropts in STYLES:
        path = os.path.join(DATA, hair)
        out = os.path.join(tmp, os.path.basename(hair) + ".hair")
        cmd = [args.vdbhair, "refine", path, "-o", out, "--measure", "--json", "--quiet", "--levels", str(args.levels), "--mode", args.mode]
        if head:
            headvdb = os.path.join(tmp, os.path.basename(head) + ".vdb")
            if not os.path.exists(headvdb):
                scmd = [args.vdbhair, "scalp", os.path.join(DATA, head), "-o", headvdb, "--quiet"]
                if args.head_voxel > 0:
                    scmd += ["--voxel-size", str(args.head_voxel)]
                r = subprocess.run(scmd, capture_output=True, text=True)
                if r.returncode != 0:
                    print("<!-- scalp failed for %s: %s -->" % (head, r.stderr.strip()))
                    headvdb = None
            if headvdb:
                cmd += ["--head", headvdb]
        r = subprocess.run(cmd, capture_output=True, text=True)
        if r.returncode != 0:
            print("| %s | failed: %s |" % (name, r.stderr.strip()))
            continue
        j = json.loads(r.stdout)
        row = [name, "%.3g" % j["voxel_size"], "%d / %d" % (j["full_length"], j["strands"]), str(j["left_hair_volume"]),
               "%d → %d" % (j["inside_head"]["before"], j["inside_head"]["after"]),
               "%.0f %% / %.0f %%" % (100 * j["curvature_kept"]["segments8"], 100 * j["curvature_kept"]["vertex"]),
               "%.1f %%" % (100 * j["tip_occupancy"]),
               "%.2f / %.2f" % (j["displacement_voxels"]["mean"], j["displacement_voxels"]["p95"]),
               "%.5f → %.5f" % (j["coherence"]["before"], j["coherence"]["after"]),
               "%s / %s" % (j.get("corrected_strands", "—"), sum(l.get("reverted_strands", 0) for l in j.get("per_level", [])))]
        print("| " + " | ".join(row) + " |")
        sys.stdout.flush()
        if args.render:
            os.makedirs(args.render, exist_ok=True)
            base = os.path.join(args.render, "_".join(name.split()[:2]).lower().replace("(", "").replace(")", ""))
            for tag, f in (("before", path), ("after", out)):
                rcmd = [args.vdbhair, "render", f, "-o", "%s_%s.png" % (base, tag), "--quiet", "--view", "three-quarter", "--width", str(args.width), "--height", str(args.width)] + ropts
                if head:
                    rcmd += ["--head", os.path.join(DATA, head)]
                subprocess.run(rcmd, capture_output=True, text=True)


if __name__ == "__main__":
    main()
