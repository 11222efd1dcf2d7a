# Generate valid .vdb test files with pyopenvdb (Debian python3-openvdb 10.0.1).
import numpy as np, pyopenvdb as vdb, os
out = '/work/scratch51/files'
rng = np.random.default_rng(1)

ls = vdb.createLevelSetSphere(radius=20.0, center=(1.5, -2.0, 3.0), voxelSize=0.25)
ls.name = 'ls'
vdb.write(f'{out}/py_levelset.vdb', grids=[ls])

vec = vdb.Vec3SGrid((0.0, 0.0, 0.0)); vec.name = 'vel'
arr = rng.standard_normal((40, 37, 33, 3)).astype(np.float32)
vec.copyFromArray(arr, ijk=(-5, -9, 3))
vec.fill((100, 100, 100), (140, 140, 140), (1.0, 2.0, 3.0), active=True)   # tiles
vdb.write(f'{out}/py_vec3.vdb', grids=[vec])

b = vdb.BoolGrid(False); b.name = 'mask'
barr = rng.random((50, 21, 70)) > 0.6
b.copyFromArray(barr, ijk=(10, -30, 0))
b.fill((-300, -300, -300), (-200, -200, -200), True, active=True)
vdb.write(f'{out}/py_bool.vdb', grids=[b])

fog = vdb.FloatGrid(0.0); fog.name = 'density'
fog.copyFromArray(rng.random((64, 64, 64)).astype(np.float32), ijk=(0, 0, 0))
fog.gridClass = vdb.GridClass.FOG_VOLUME
vdb.write(f'{out}/py_multi.vdb', grids=[ls, vec, b, fog])

h = ls.deepCopy(); h.name = 'ls_half'; h.saveFloatAsHalf = True
hv = vec.deepCopy(); hv.name = 'vel_half'; hv.saveFloatAsHalf = True
vdb.write(f'{out}/py_half.vdb', grids=[h, hv])

e = vdb.FloatGrid(); e.name = 'empty'
vdb.write(f'{out}/py_empty.vdb', grids=[e])
for f in sorted(os.listdir(out)): print(f, os.path.getsize(f'{out}/{f}'))
