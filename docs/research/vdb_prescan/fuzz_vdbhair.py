#!/usr/bin/env python3
"""Mutants of vh_points100.vdb that the pre-scan ACCEPTS, fed to `vdbhair convert` (ulimit -v 4 GiB):
what is left after byte bounds (value semantics: voxel offsets vs array sizes, transform, ...)."""
import random, subprocess, os, collections
D = '/work/scratch51'
rng = random.Random(31337)
data = open(f'{D}/files/vh_points100.vdb', 'rb').read()
res = collections.Counter(); bad = []
os.makedirs(f'{D}/mut/vh', exist_ok=True)
for i in range(600):
    m = bytearray(data)
    off = rng.randrange(len(m)); w = rng.choice([1, 2, 4])
    off = min(off, len(m) - w)
    m[off:off + w] = rng.getrandbits(8 * w).to_bytes(w, 'little')
    p = f'{D}/mut/vh/m{i}@{off}.vdb'; open(p, 'wb').write(m)
    if subprocess.run([f'{D}/prescan', p], capture_output=True, text=True, errors='replace').stdout.startswith('REJECT'):
        res['prescan reject'] += 1; os.remove(p); continue
    try:
        r = subprocess.run(['bash', '-c', f'ulimit -v 4194304; exec /work/main/build/bin/vdbhair convert -q "{p}" {D}/mut/vh/out.hair'],
                           capture_output=True, text=True, errors='replace', timeout=60)
        st = f'SIGNAL {-r.returncode}' if r.returncode < 0 else f'rc={r.returncode}'
    except subprocess.TimeoutExpired:
        st = 'TIMEOUT'; r = None
    res['accepted, vdbhair ' + st] += 1
    if st.startswith('SIGNAL') or st == 'TIMEOUT':
        bad.append(f'{p}: {st}: {(r.stderr.strip().splitlines() or [""])[-1][:200] if r else ""}')
    else:
        os.remove(p)
print(dict(res))
for b in bad: print('BAD', b)
