#!/usr/bin/env python3
"""Random mutations (byte flips, random 1/2/4/8-byte values at random offsets) of small
valid files.  Every mutant the pre-scan ACCEPTS is read by OpenVDB (`prescan --read`,
ulimit -v 4 GiB, 60 s); with --valgrind the first N accepted ones also run under
valgrind memcheck.  A crash, timeout or memcheck error on an accepted mutant is a gap."""
import random, struct, subprocess, sys, os
D = '/work/scratch51'
rng = random.Random(int(os.environ.get('SEED', '20240601')))
BASES = {'vh_points100.vdb': 800, 'vh_field.vdb': 400, 'c_blosc_mask.vdb': 300, 'p_fx16_zip.vdb': 300, 'py_half.vdb': 200, 'py_bool.vdb': 200, 'c_stream.vdb': 200}
VALGRIND = int(sys.argv[1]) if len(sys.argv) > 1 else 0
os.makedirs(f'{D}/mut/fuzz', exist_ok=True)
stats = {}
gaps = []
vg_done = 0
for base, n in BASES.items():
    data = open(f'{D}/files/{base}', 'rb').read()
    acc = rej = 0
    for i in range(n):
        m = bytearray(data)
        off = rng.randrange(len(m))
        how = rng.choice(['flip', 'u8', 'u16', 'u32', 'u64', 'neg64'])
        if how == 'flip': m[off] ^= 1 << rng.randrange(8)
        else:
            w = {'u8': 1, 'u16': 2, 'u32': 4, 'u64': 8, 'neg64': 8}[how]
            off = min(off, len(m) - w)
            val = rng.getrandbits(8 * w) if how != 'neg64' else (-rng.randrange(1, 1 << 20)) & (2**64 - 1)
            m[off:off + w] = val.to_bytes(w, 'little')
        p = f'{D}/mut/fuzz/{base[:-4]}_{i}_{how}@{off}.vdb'
        open(p, 'wb').write(m)
        ps = subprocess.run([f'{D}/prescan', p], capture_output=True, text=True, errors='replace').stdout
        if ps.startswith('REJECT'):
            rej += 1; os.remove(p); continue
        acc += 1
        try:
            r = subprocess.run(['bash', '-c', f'ulimit -v 4194304; exec {D}/prescan --read "{p}"'], capture_output=True, text=True, errors='replace', timeout=60)
            st = f'SIGNAL {-r.returncode}' if r.returncode < 0 else f'rc={r.returncode}'
        except subprocess.TimeoutExpired:
            st = 'TIMEOUT'
        try:
            r2 = subprocess.run(['bash', '-c', f'ulimit -v 4194304; exec {D}/prescan --read-stream "{p}"'], capture_output=True, text=True, errors='replace', timeout=60)
            st2 = f'SIGNAL {-r2.returncode}' if r2.returncode < 0 else f'rc={r2.returncode}'
        except subprocess.TimeoutExpired:
            st2 = 'TIMEOUT'
        if st2.startswith('SIGNAL') or st2 == 'TIMEOUT': gaps.append(f'{base} {how}@{off}: io::Stream path {st2}')
        line = f'{base} {how}@{off}: accepted; io::Stream read {st2}; OpenVDB read {st} {(r.stdout.strip().splitlines() or [""])[-1][:100] if st != "TIMEOUT" else ""}'
        if st.startswith('SIGNAL') or st == 'TIMEOUT': gaps.append(line)
        if vg_done < VALGRIND:
            vg_done += 1
            v = subprocess.run(['valgrind', '-q', '--error-exitcode=99', f'{D}/prescan', '--read', p], capture_output=True, text=True, errors='replace')
            if v.returncode == 99 or v.returncode < 0:
                gaps.append(line + ' VALGRIND: ' + ' | '.join(l for l in v.stderr.splitlines() if 'Invalid' in l or 'uninitialised' in l)[:300])
            line += f'; valgrind rc={v.returncode}'
        print(line, flush=True)
        os.remove(p)
    stats[base] = (n, rej, acc)
print('SUMMARY', stats)
print('GAPS', len(gaps))
for g in gaps: print('GAP', g)
