#!/usr/bin/env python3
"""Strands that `synth` stands off the head (issue 49): every groom of ../shared/data that has a
head, seeds 0-2, with the groom's own head; measured by NumPy from the files synth wrote.

    PYTHONPATH=build/python /usr/bin/python3 scripts/standing_strands.py [--vdbhair build/bin/vdbhair]

Per groom and seed, two counts of output strands, along the head's up axis (the report's frame):
- above the top: the strand's highest point is more than 0.1 head radii above the example's highest;
- rising: the strand rises above its own root 0.1 head radii more than any example strand does.
The same groom list and options as scripts/head_table.py.
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from head_table import DATA, GROOMS, ROOT  # noqa: E402

import vdbhair  # noqa: E402


def strands(path):
    s = vdbhair.read(path)
    p, o = np.asarray(s.positions, dtype=np.float64), np.asarray(s.offsets, dtype=np.int64)
    return [p[o[i]:o[i + 1]] for i in range(len(o) - 1)]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--vdbhair", default=os.path.join(ROOT, "build", "bin", "vdbhair"))
    args = ap.parse_args()
    tmp = tempfile.mkdtemp()
    print("| groom | above the top, seeds 0/1/2 | rising, seeds 0/1/2 |")
    print("| --- | --- | --- |")
    for name, (hair_rel, head_rel, up) in GROOMS.items():
        hair, head = os.path.join(DATA, hair_rel), os.path.join(DATA, head_rel)
        if not (os.path.exists(hair) and os.path.exists(head)):
            print("| %s | (missing data) | |" % name)
            continue
        example = strands(hair)
        opts = ["--up", up] if up != "y" else []
        if name == "ruby_short":
            opts += ["--front", "z"]  # its hairline does not reach the nape (docs/synthesis.md)
        above, rising = [], []
        for seed in (0, 1, 2):
            out = os.path.join(tmp, name + ".hair")
            r = subprocess.run([args.vdbhair, "synth", hair, "-o", out, "--head", head, "--seed", str(seed), "--json", "--quiet"] + opts,
                               capture_output=True, text=True, check=True)
            frame = json.loads(r.stdout)["regions"]["frame"]
            c, u, radius = np.array(frame["center"]), np.array(frame["up"]), frame["radius"]
            top = max(float(((p - c) @ u).max()) for p in example)
            rise = max(float(((p - p[0]) @ u).max()) for p in example)
            new = strands(out)
            above.append(sum(float(((p - c) @ u).max()) > top + 0.1 * radius for p in new))
            rising.append(sum(float(((p - p[0]) @ u).max()) > rise + 0.1 * radius for p in new))
        print("| %s | %s | %s |" % (name, " / ".join(map(str, above)), " / ".join(map(str, rising))))
        sys.stdout.flush()


if __name__ == "__main__":
    main()
