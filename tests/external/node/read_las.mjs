// Reference LAS/LAZ reader for dpoint's tests (issue #13): @loaders.gl/las, whose laz-rs decoder
// reads LAS 1.0–1.4, point formats 0–10 and LAZ. Writes what it reads as text:
//
//   node read_las.mjs IN.las|IN.laz -o OUT.csv
//
//   #version=1.4 format=7 count=22600
//   x,y,z,red,green,blue        (red, green, blue only for formats with RGB)
//   637012.24,849028.31,431.66,49,45,28
//
// Positions come from the public LAZRsLoader with fp64 (loaders.gl computes X·scale + offset in
// double), written in the shortest text that reads back as the same double. Colours are the raw
// 16-bit values of the records: the public loader gives only 8-bit colours (c/256 or c, by its own
// guess), so they are taken from the decoder it is built on (its parseLASChunked), which hands out
// each record's fields as stored.
import fs from 'node:fs';
import { createRequire } from 'node:module';
import path from 'node:path';
import { pathToFileURL } from 'node:url';
import { modulesDir, num } from './modules.mjs';

function parseArgs(argv) {
  const args = { input: null, output: null };
  for (let i = 0; i < argv.length; i++) {
    if (argv[i] === '-o') args.output = argv[++i];
    else if (args.input === null) args.input = argv[i];
    else throw new Error(`unexpected argument ${argv[i]}`);
  }
  if (!args.input || !args.output) throw new Error('usage: read_las.mjs IN.las -o OUT.csv');
  return args;
}

// The package's ES module files, imported by path so that the loader, its decoder and its wasm
// glue are one set of module instances (the wasm is initialized once, below, for all of them).
function lasDist() {
  const require = createRequire(path.join(modulesDir, 'resolve-from-here.js'));
  try {
    return path.dirname(require.resolve('@loaders.gl/las'));
  } catch (e) {
    throw new Error(`npm module @loaders.gl/las not found under ${modulesDir} (run scripts/setup)`);
  }
}
const dist = lasDist();
const importDist = (file) => import(pathToFileURL(path.join(dist, file)).href);

// The loader fetches its wasm by URL, which node's fetch cannot do for files: hand it the bytes.
const { initSync } = await importDist('libs/laz-rs-wasm/laz_rs_wasm.js');
initSync({ module: fs.readFileSync(path.join(dist, 'libs/laz-rs-wasm/laz_rs_wasm_bg.wasm')) });
const { LAZRsLoader } = await importDist('index.js');
const { parseLASChunked } = await importDist('lib/laz-rs-wasm/parse-las.js');

const args = parseArgs(process.argv.slice(2));
const bytes = fs.readFileSync(args.input);
const buffer = () => bytes.buffer.slice(bytes.byteOffset, bytes.byteOffset + bytes.byteLength);

const mesh = await LAZRsLoader.parse(buffer(), { las: { fp64: true, skip: 1, colorDepth: 16 } });
const header = mesh.loaderData;
const count = mesh.header.vertexCount;
const positions = mesh.attributes.POSITION.value;
if (!(positions instanceof Float64Array)) throw new Error('loaders.gl did not return double positions');

const colors = header.hasColor ? new Uint16Array(count * 3) : null;
if (colors) {
  let at = 0;
  parseLASChunked(buffer(), 1, (decoder) => {
    for (let i = 0; i < decoder.pointsCount; i++, at++) colors.set(decoder.getPoint(i).color, 3 * at);
  });
  if (at !== count) throw new Error(`colours of ${at} points, positions of ${count}`);
}

const parts = [`#version=${header.versionAsString} format=${header.pointsFormatId} count=${count}\n`];
parts.push(colors ? 'x,y,z,red,green,blue\n' : 'x,y,z\n');
for (let i = 0; i < count; i++) {
  let line = `${num(positions[3 * i])},${num(positions[3 * i + 1])},${num(positions[3 * i + 2])}`;
  if (colors) line += `,${colors[3 * i]},${colors[3 * i + 1]},${colors[3 * i + 2]}`;
  parts.push(line + '\n');
}
fs.writeFileSync(args.output, parts.join(''));
