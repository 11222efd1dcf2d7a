// Reads a .usda file with tinyusdz and checks vdbhair's world-space points against it:
//   node check_tinyusdz_world.mjs TINYUSDZ_DIR FILE.usda VDBHAIR.obj
// Each linear BasisCurves prim's points (as written in FILE.usda) are moved by the world matrix
// tinyusdz composed for the prim (its xformOps and its parents', row vectors as USD's), and must
// match the vertices vdbhair wrote to VDBHAIR.obj (`vdbhair convert FILE.usda VDBHAIR.obj`), in
// order, within 1e-4. The transforms are tinyusdz's; only the points are read from the text.
import fs from 'node:fs';
import path from 'node:path';
import { pathToFileURL } from 'node:url';

const [dir, file, obj] = process.argv.slice(2);
const fail = (msg) => { console.log('FAIL: ' + msg); process.exit(1); };

process.type = 'renderer';
globalThis.window = globalThis;
const { default: createModule } = await import(pathToFileURL(path.join(dir, 'tinyusdz.js')).href);
const M = await createModule({ wasmBinary: fs.readFileSync(path.join(dir, 'tinyusdz.wasm')) });
const bytes = new Uint8Array(fs.readFileSync(file));
const stage = new M.TinyUSDZLoaderNative();
if (!stage.loadFromBinary(bytes, file)) fail('tinyusdz cannot load the stage: ' + stage.error());

// The world matrix of every prim, by name (the fixture's names are unique).
const world = new Map();
const stack = [];
for (let i = 0; i < stage.numRootNodes(); ++i) stack.push(stage.getRootNode(i));
while (stack.length) {
  const node = stack.pop();
  world.set(node.primName, node.globalMatrix);
  for (const child of node.children || []) stack.push(child);
}

const text = fs.readFileSync(file, 'utf8');
const expected = [];
for (const m of text.matchAll(/def BasisCurves "(\w+)"[\s\S]*?point3f\[\] points = \[([^\]]*)\]/g)) {
  const g = world.get(m[1]);
  if (!g || g.length !== 16) fail(`tinyusdz has no world matrix for prim ${m[1]}`);
  for (const p of m[2].matchAll(/\(([^)]*)\)/g)) {
    const [x, y, z] = p[1].split(',').map(Number);
    expected.push([0, 1, 2].map((c) => x * g[c] + y * g[4 + c] + z * g[8 + c] + g[12 + c]));
  }
}
const got = fs.readFileSync(obj, 'utf8').split('\n').filter((l) => l.startsWith('v ')).map((l) => l.split(/\s+/).slice(1, 4).map(Number));
if (got.length !== expected.length) fail(`vdbhair wrote ${got.length} vertices, the file has ${expected.length}`);
let worst = 0;
for (let i = 0; i < got.length; ++i) {
  const d = Math.hypot(got[i][0] - expected[i][0], got[i][1] - expected[i][1], got[i][2] - expected[i][2]);
  if (d > 1e-4) fail(`vertex ${i}: vdbhair (${got[i].join(', ')}), tinyusdz (${expected[i].map((v) => v.toFixed(6)).join(', ')})`);
  worst = Math.max(worst, d);
}
console.log(`ok: tinyusdz's world matrices give vdbhair's ${got.length} points (largest difference ${worst.toExponential(2)})`);
