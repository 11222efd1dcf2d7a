// Reads a .usda file with tinyusdz (TinyUSDZ compiled to WebAssembly, from the npm registry) and
// checks what it parsed against the counts vdbhair wrote:
//   node check_tinyusdz.mjs TINYUSDZ_DIR FILE.usda STRANDS VERTICES [WANT...]
// WANT: mpu=X (metersPerUnit), up=Y|Z, widths=constant|vertex, color=constant|vertex, width=X
// (the one constant width), each compared with what tinyusdz parsed.
// TINYUSDZ_DIR is the installed package (node_modules/tinyusdz). The package is built for the web:
// under node 20 it needs `process.type` set (so it does not take the node path it was not built
// for), `window = globalThis`, and the .wasm bytes handed to it.
import fs from 'node:fs';
import path from 'node:path';
import { pathToFileURL } from 'node:url';

const [dir, file, wantStrands, wantVertices, ...wants] = process.argv.slice(2);
const fail = (msg) => { console.log('FAIL: ' + msg); process.exit(1); };

process.type = 'renderer';
globalThis.window = globalThis;
const { default: createModule } = await import(pathToFileURL(path.join(dir, 'tinyusdz.js')).href);
const M = await createModule({ wasmBinary: fs.readFileSync(path.join(dir, 'tinyusdz.wasm')) });
const version = JSON.parse(fs.readFileSync(path.join(dir, 'package.json'), 'utf8')).version;
const bytes = new Uint8Array(fs.readFileSync(file));

// As a stage (the render-scene path three.js viewers use) and as a layer (its own parse tree).
const stage = new M.TinyUSDZLoaderNative();
if (!stage.loadFromBinary(bytes, file)) fail('tinyusdz cannot load the stage: ' + stage.error());
const root = stage.getDefaultRootNode();
if (!root || root.primName !== 'hair') fail('the default prim is ' + (root && root.primName) + ', expected hair');
const layer = new M.TinyUSDZLoaderNative();
if (!layer.loadAsLayerFromBinary(bytes, file)) fail('tinyusdz cannot parse the layer: ' + layer.error());

// tinyusdz prints the layer back from what it parsed: count from that text, not from the file.
const text = layer.layerToString();
const prim = text.match(/def BasisCurves "hair"\s*\{([\s\S]*?)\n\}/);
if (!prim) fail('tinyusdz did not parse a BasisCurves prim named hair:\n' + text.slice(0, 2000));
const body = prim[1];
const array = (re) => { const m = body.match(re); return m ? m[1] : null; };
const counts = array(/int\[\] curveVertexCounts = \[([^\]]*)\]/);
const points = array(/point3f\[\] points = \[([^\]]*)\]/);
if (counts === null || points === null) fail('tinyusdz has no curveVertexCounts or points');
const countList = counts.split(',').map(Number);
const sum = countList.reduce((a, b) => a + b, 0);
const nPoints = (points.match(/\(/g) || []).length;
const type = array(/uniform token type = "(\w+)"/);
const widths = body.match(/float\[\] widths = \[([^\]]*)\]\s*\(\s*interpolation = "(\w+)"/);
const color = body.match(/color3f\[\] primvars:displayColor = \[([^\]]*)\]\s*\(\s*interpolation = "(\w+)"/);
const upAxis = (text.match(/upAxis = "(\w)"/) || [])[1];
const mpu = (text.match(/metersPerUnit = ([0-9.e-]+)/) || [])[1];
console.log(`tinyusdz ${version} read BasisCurves "hair": type ${type}, ${countList.length} curves, ` +
            `curveVertexCounts summing to ${sum}, ${nPoints} points, widths ${widths ? widths[2] : 'none'}, ` +
            `displayColor ${color ? color[2] : 'none'}, upAxis ${upAxis}, metersPerUnit ${mpu}`);
if (type !== 'linear') fail('type is ' + type + ', expected linear');
if (countList.length !== Number(wantStrands)) fail(`${countList.length} curves, vdbhair wrote ${wantStrands}`);
if (sum !== Number(wantVertices) || nPoints !== Number(wantVertices)) fail(`${sum} counted and ${nPoints} points, vdbhair wrote ${wantVertices}`);
if (!widths || !color || !upAxis || !mpu) fail('widths, displayColor, upAxis or metersPerUnit missing');
const parsed = {mpu: mpu, up: upAxis, widths: widths[2], color: color[2],
                width: widths[2] === 'constant' ? widths[1].trim() : 'per vertex'};
for (const want of wants) {
  const [key, value] = want.split('=');
  if (!(key in parsed)) fail('unknown check ' + want);
  const got = parsed[key];
  const same = key === 'mpu' || key === 'width' ? Math.abs(Number(got) - Number(value)) <= 1e-6 * Math.abs(Number(value)) : got === value;
  if (!same) fail(`${key} is ${got} in tinyusdz's reading, expected ${value}`);
  console.log(`ok: ${key} = ${got}`);
}
console.log('ok: tinyusdz reads every curve and point vdbhair wrote');
