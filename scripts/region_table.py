#!/usr/bin/env python3
"""synth's per-region figures against the example's (issue 49: every per-region statistic within
10 % of the example's), on every groom of ../shared/data that has a head, over several seeds.

    PYTHONPATH=build/python /usr/bin/python3 scripts/region_table.py [--vdbhair build/bin/vdbhair] [--seeds 0,1,2]
        [--only NAME,NAME] [--out DIR] [--verbose] [-- EXTRA SYNTH OPTIONS]

Each run is `vdbhair synth EXAMPLE --head HEAD --seed S --json` (the groom's own axes as
scripts/head_table.py gives them; Ruby's short hair with --front z, where its hairline alone does
not say); its report's "regions" sets every figure of the output beside the example's
(vdbhair/synth/StyleRegions.h). A figure is within when:
- share, length p25/p50/p75, turning, curl amplitude: |output - example| <= 10 % of the example's;
- lift: the same, or within 0.01 (a share of strands: 0 against 0.004 is not a signature lost);
- flow: the report's flow_difference (the distance between the two mean directions) <= 0.1;
- inside the head: the output's share of vertices inside <= the example's + 0.001.
Prints the global checks that fail per run, the failing figures per region with --verbose, and
the count within. With --out, reports are kept there and a run whose report is there is not run
again (so a table over options can be built up run by run).
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile
from concurrent.futures import ThreadPoolExecutor

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import head_table as ht  # noqa: E402  (the grooms, their heads and axes)

FIGURES = ["share", "length_p25", "length_p50", "length_p75", "lift", "turning", "curl_amplitude"]
FRONT = {"ruby_short": ["--front", "z"]}


def synth(args, out, name, seed):
    hair, head, up = ht.GROOMS[name]
    report = os.path.join(out, "%s_%d.json" % (name, seed))
    if not os.path.exists(report):
        cmd = [args.vdbhair, "synth", os.path.join(ht.DATA, hair), "-o", os.path.join(out, "%s_%d.hair" % (name, seed)),
               "--head", os.path.join(ht.DATA, head), "--seed", str(seed), "--json", "--quiet"]
        cmd += (["--up", up] if up != "y" else []) + FRONT.get(name, []) + args.extra
        r = subprocess.run(cmd, capture_output=True, text=True)
        if r.returncode:
            sys.exit("region_table: %s failed: %s" % (" ".join(cmd), r.stderr.strip()))
        with open(report, "w") as f:
            f.write(r.stdout)
    with open(report) as f:
        return json.load(f)


def within(figure, example, output):
    floor = 0.01 if figure == "lift" else 1e-12
    return abs(output - example) <= 0.1 * abs(example) + floor


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--vdbhair", default=os.path.join(ht.ROOT, "build", "bin", "vdbhair"))
    p.add_argument("--seeds", default="0,1,2")
    p.add_argument("--only", default="")
    p.add_argument("--out", default="")
    p.add_argument("--verbose", action="store_true")
    p.add_argument("extra", nargs="*", help="more synth options, after --")
    args = p.parse_args()
    if not os.path.isdir(ht.DATA):
        print("region_table: skipped: no shared data at %s" % ht.DATA)
        return
    names = [n for n in ht.GROOMS if not args.only or n in args.only.split(",")]
    seeds = [int(s) for s in args.seeds.split(",")]
    out = args.out or tempfile.mkdtemp(prefix="region_table_")
    os.makedirs(out, exist_ok=True)
    jobs = [(n, s) for n in names for s in seeds]
    with ThreadPoolExecutor(2) as pool:
        reports = list(pool.map(lambda job: synth(args, out, *job), jobs))
    total = good = failed_runs = 0
    failures = {}
    for (name, seed), rep in zip(jobs, reports):
        bad = sorted(k for k, v in rep["checks"].items() if not v)
        if bad:
            failed_runs += 1
            print("%s seed %d: global checks failing: %s" % (name, seed, ", ".join(bad)))
        for region in ["crown", "fringe", "sides", "back"]:
            R = rep["regions"][region]
            if R is None:
                continue
            checks = [(f, within(f, R[f]["example"], R[f]["output"]), "%s %.3g -> %.3g" % (f, R[f]["example"], R[f]["output"]))
                      for f in FIGURES]
            checks += [("flow", R["flow_difference"] <= 0.1, "flow difference %.2f" % R["flow_difference"]),
                       ("inside", R["inside_head"]["output"] <= R["inside_head"]["example"] + 1e-3,
                        "inside %.3f -> %.3f" % (R["inside_head"]["example"], R["inside_head"]["output"]))]
            row = []
            for key, ok, text in checks:
                if not ok:
                    row.append(text)
                    failures[key] = failures.get(key, 0) + 1
                total, good = total + 1, good + ok
            if row and args.verbose:
                print("  %s seed %d %s: %s" % (name, seed, region, "; ".join(row)))
    print("%d of %d region figures within (%d grooms x %d seeds); runs with a global check failing: %d of %d"
          % (good, total, len(names), len(seeds), failed_runs, len(jobs)))
    print("failing: " + ", ".join("%s %d" % kv for kv in sorted(failures.items(), key=lambda kv: -kv[1])))
    print("reports in %s" % out)


if __name__ == "__main__":
    main()
