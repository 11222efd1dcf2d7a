#!/usr/bin/env python3
"""Targeted mutations of the size fields the pre-scan checks.  For each mutant:
prescan (must REJECT), then OpenVDB's own reader (`prescan --read`, what vdbhair
does) under ulimit -v 4 GiB and a 60 s timeout, to show what the mutation does
when nothing checks it.  Writes mut/results.tsv."""
import os, struct, subprocess, sys, collections
D = '/work/scratch51'
PRESCAN = f'{D}/prescan'
BASES = ['vh_points100.vdb', 'p_null_blosc.vdb', 'p_fx16_zip.vdb', 'p_null_none.vdb', 'c_blosc_mask.vdb',
         'c_zip.vdb', 'c_zip_mask.vdb', 'c_none.vdb', 'py_half.vdb', 'py_bool.vdb', 'py_levelset.vdb', 'c_stream.vdb']

def fields(path):
    out = subprocess.run([PRESCAN, '--list', path], capture_output=True, text=True, errors='replace').stdout
    assert 'ACCEPT' in out, out
    res = collections.defaultdict(list)
    for line in out.splitlines():
        if line.startswith('FIELD '):
            _, k, off, dest = line.split()
            res[k].append((int(off), int(dest)))
    return res

def pick(lst, n=3):
    if len(lst) <= n: return lst
    return [lst[0], lst[len(lst) // 2], lst[-1]]

def muts(kind, off, dest, data):
    u64 = lambda v: ('<q' if v < 0 else '<Q', v)
    cur32 = struct.unpack_from('<I', data, off)[0]
    if kind.startswith('chunk64'):
        cur = struct.unpack_from('<q', data, off)[0]
        vals = [-1000, 2**40, -(2**40), -(dest + 8), -2**63]
        vals += [dest + 17] if 'blosc' in kind else [dest + 1]
        if dest >= 8: vals.append(-(dest - 8))
        if dest > 0: vals.append(0)
        if cur > 0: vals += [cur + 1, cur - 1]
        return [(f'{kind}={v}', off, '<q', v) for v in vals]
    if kind == 'blosc':
        nb, bs, cb = struct.unpack_from('<III', data, off + 4)
        return [('blosc.nbytes+1', off + 4, '<I', nb + 1), ('blosc.nbytes=2^31', off + 4, '<I', 2**31),
                ('blosc.cbytes+1000', off + 12, '<I', cb + 1000), ('blosc.cbytes=2^31-1', off + 12, '<I', 2**31 - 1),
                ('blosc.blocksize=0', off + 8, '<I', 0)]
    if kind == 'page32':
        c = struct.unpack_from('<i', data, off)[0]
        r = [(f'page.c={v}', off, '<i', v) for v in (-1000, 2**30, 0, -2**31, c + 1)]
        if c > 0: r.append(('page.u=2^30', off + 4, '<i', 2**30))
        return r
    if kind == 'arraybytes':
        cur = struct.unpack_from('<Q', data, off)[0]
        return [(f'arraybytes={v}', off, '<Q', v) for v in (2**40, 0, 5, cur + 1, cur - 1)]
    if kind in ('voxel16', 'voxel16pass0'):
        cur = struct.unpack_from('<H', data, off)[0]
        return [(f'{kind}={v}', off, '<H', v) for v in (0xFFFE, 0, 10, (cur + 1) & 0xffff)]
    if kind == 'strlen':
        return [(f'strlen={v}', off, '<I', v) for v in (2**31, 0xFFFFFFFF, cur32 + 1)]
    if kind == 'metasize':
        return [(f'metasize={v}', off, '<I', v) for v in (2**31, cur32 + 1)]
    if kind == 'dlsize':
        return [(f'dlsize={v}', off, '<I', v) for v in (max(cur32 - 4, 1), 2**31)]
    if kind == 'metacount':
        return [('metacount=2^32-1', off, '<I', 2**32 - 1), ('metacount+1', off, '<I', cur32 + 1)]
    if kind == 'rootcounts':
        nc = struct.unpack_from('<I', data, off + 4)[0]
        return [('root.numTiles=2^32-1', off, '<I', 2**32 - 1), ('root.numChildren=2^32-1', off + 4, '<I', 2**32 - 1),
                ('root.numChildren+1', off + 4, '<I', nc + 1), ('root.numTiles+1', off, '<I', cur32 + 1)]
    if kind == 'desccount':
        cur = struct.unpack_from('<Q', data, off)[0]
        return [(f'desccount={v}', off, '<Q', v) for v in (2**40, cur + 1)]
    if kind == 'passes':
        cur = struct.unpack_from('<H', data, off)[0]
        return [(f'passes={v}', off, '<H', v) for v in (65535, 0, cur - 2, cur + 2)]
    if kind == 'nodemeta':
        cur = data[off]
        return [(f'nodemeta={v}', off, '<B', v) for v in (7, 200, 3 if cur != 3 else 0, 6 if cur != 6 else 0)]
    if kind == 'leafmask':
        return [('leafmask.bitflip', off + 5, '<B', data[off + 5] ^ 0x10)]
    return []

def run(cmd, timeout=60):
    try:
        p = subprocess.run(['bash', '-c', 'ulimit -v 4194304; exec "$@"', 'x'] + cmd, capture_output=True, text=True, errors='replace', timeout=timeout)
        rc = p.returncode
        txt = (p.stdout + p.stderr).strip().splitlines()
        last = txt[-1][:150] if txt else ''
        if rc < 0: return f'SIGNAL {-rc}', last
        return f'rc={rc}', last
    except subprocess.TimeoutExpired:
        return 'TIMEOUT', ''

def main():
    readAll = '--no-read' not in sys.argv
    rows = []
    for base in BASES:
        path = f'{D}/files/{base}'
        data = open(path, 'rb').read()
        fl = fields(path)
        for kind, lst in sorted(fl.items()):
            chosen = pick(lst) if kind != 'strlen' else pick(lst, 2)[:2]
            for i, (off, dest) in enumerate(chosen):
                for name, o, fmt, v in muts(kind, off, dest, data):
                    m = bytearray(data)
                    try: struct.pack_into(fmt, m, o, v)
                    except struct.error: continue
                    if bytes(m) == data: continue
                    mp = f'{D}/mut/{base[:-4]}__{name.replace("/", "_")}@{o}.vdb'
                    open(mp, 'wb').write(m)
                    ps = subprocess.run([PRESCAN, mp], capture_output=True, text=True, errors='replace').stdout.strip()
                    verdict = 'REJECT' if ps.startswith('REJECT') else 'ACCEPT'
                    why = ps.split(': ', 2)[-1][:120]
                    r, last = run([PRESCAN, '--read', mp]) if readAll else ('-', '')
                    rows.append((base, kind, name, o, verdict, why, r, last))
                    print('\t'.join(map(str, rows[-1])), flush=True)
                    os.remove(mp)
    with open(f'{D}/mut/results.tsv', 'w') as f:
        f.write('base\tkind\tmutation\toffset\tprescan\tprescan_reason\topenvdb_read\topenvdb_last_line\n')
        for r in rows: f.write('\t'.join(map(str, r)) + '\n')
    acc = [r for r in rows if r[4] == 'ACCEPT']
    print(f'{len(rows)} mutants, {len(rows) - len(acc)} rejected, {len(acc)} accepted')
    for r in acc: print('ACCEPTED:', r)

main()
