#!/usr/bin/env python3
"""The issue's scenario: chunk-size fields of a 100-strand points .vdb (vdbhair convert
output) set to -1000 or 2^40, then `vdbhair convert` (ulimit -v 4 GiB) and the pre-scan."""
import struct, subprocess, os
D = '/work/scratch51'
base = f'{D}/files/vh_points100.vdb'
data = open(base, 'rb').read()
out = subprocess.run([f'{D}/prescan', '--list', base], capture_output=True, text=True, errors='replace').stdout
fields = [l.split() for l in out.splitlines() if l.startswith('FIELD ')]
targets = [(k, int(o)) for _, k, o, _ in fields if k in ('chunk64blosc', 'page32', 'voxel16', 'arraybytes')]
os.makedirs(f'{D}/mut/issue', exist_ok=True)
for kind, off in targets:
    for v in (-1000, 2**40):
        fmt = {'chunk64blosc': '<q', 'page32': '<i', 'voxel16': '<H', 'arraybytes': '<Q'}[kind]
        try: m = bytearray(data); struct.pack_into(fmt, m, off, v)
        except struct.error: continue
        p = f'{D}/mut/issue/{kind}@{off}={v}.vdb'
        open(p, 'wb').write(m)
        ps = subprocess.run([f'{D}/prescan', p], capture_output=True, text=True, errors='replace').stdout.strip()
        try:
            r = subprocess.run(['bash', '-c', f'ulimit -v 4194304; exec /work/main/build/bin/vdbhair convert -q "{p}" {D}/mut/issue/out.hair'],
                               capture_output=True, text=True, errors='replace', timeout=60)
            st = f'SIGNAL {-r.returncode}' if r.returncode < 0 else f'rc={r.returncode}'
            msg = (r.stderr.strip().splitlines() or [''])[-1][:140]
        except subprocess.TimeoutExpired:
            st, msg = 'TIMEOUT', ''
        print(f'{kind}@{off}={v}\tprescan: {ps.split(": ", 2)[-1][:100]}\tvdbhair convert: {st} {msg}')
