// The npm `copc` package (copc.js, the reader of viewer.copc.io) as judge of COPC files (issue #35):
// opens each file with Copc.create, walks the hierarchy from the root page through every child page
// (Copc.loadHierarchyPage) and decodes every node (Copc.loadPointDataView, laz-perf underneath).
// Fails (exit 1) unless every node's points lie in its node's cube (within half a scale step),
// every node's point count is what its chunk decodes to, every node but the root has its parent,
// and the counts add up to the header's point count. Prints one summary line per file:
//
//   node copc_walk.mjs FILE.copc.laz...
//   FILE: format=7 points=22600 nodes=9 pages=1 levels=[1,8] spacing=... wkt="PROJCS[..." (or null)
import path from 'node:path';
import { createRequire } from 'node:module';
import { modulesDir } from './modules.mjs';

const require = createRequire(path.join(modulesDir, 'resolve-from-here.js'));
let Copc;
try {
  ({ Copc } = require('copc'));
} catch (e) {
  throw new Error(`npm module copc not found under ${modulesDir} (run scripts/setup)`);
}

function fail(file, message) {
  console.error(`${file}: ${message}`);
  process.exitCode = 1;
}

async function walk(file) {
  const copc = await Copc.create(file);
  const { header, info } = copc;
  const [cx0, cy0, cz0, cx1] = info.cube;
  const edge = cx1 - cx0;
  const nodes = {};
  let pages = 0;
  const queue = [info.rootHierarchyPage];
  const seen = new Set();
  while (queue.length > 0) {
    const page = queue.shift();
    if (seen.has(page.pageOffset)) return fail(file, `hierarchy page at byte ${page.pageOffset} read twice`);
    seen.add(page.pageOffset);
    ++pages;
    const h = await Copc.loadHierarchyPage(file, page);
    for (const [key, child] of Object.entries(h.pages)) queue.push(child);
    for (const [key, node] of Object.entries(h.nodes)) {
      if (key in nodes) return fail(file, `node ${key} has two entries`);
      nodes[key] = node;
    }
  }
  if (!('0-0-0-0' in nodes)) return fail(file, 'no root node 0-0-0-0');
  let total = 0;
  const levels = [];
  const half = header.scale.map((s) => Math.abs(s) / 2);
  for (const [key, node] of Object.entries(nodes)) {
    const [d, x, y, z] = key.split('-').map(Number);
    if (d > 0 && !(`${d - 1}-${x >> 1}-${y >> 1}-${z >> 1}` in nodes)) return fail(file, `node ${key} has no parent`);
    levels[d] = (levels[d] || 0) + 1;
    total += node.pointCount;
    if (node.pointCount === 0) continue;
    const view = await Copc.loadPointDataView(file, copc, node);
    if (view.pointCount !== node.pointCount)
      return fail(file, `node ${key}: ${view.pointCount} points decoded, the hierarchy says ${node.pointCount}`);
    const size = edge / 2 ** d;
    const lo = [cx0 + x * size, cy0 + y * size, cz0 + z * size];
    const get = ['X', 'Y', 'Z'].map((n) => view.getter(n));
    for (let i = 0; i < view.pointCount; ++i) {
      for (let a = 0; a < 3; ++a) {
        const v = get[a](i);
        if (v < lo[a] - half[a] || v > lo[a] + size + half[a])
          return fail(file, `node ${key} point ${i}: ${'XYZ'[a]}=${v} outside [${lo[a]}, ${lo[a] + size}]`);
      }
    }
  }
  if (total !== header.pointCount)
    return fail(file, `the nodes hold ${total} points, the header says ${header.pointCount}`);
  const count = Object.keys(nodes).length;
  console.log(`${path.basename(file)}: format=${header.pointDataRecordFormat} points=${total} nodes=${count} ` +
              `pages=${pages} levels=[${Array.from(levels, (n) => n || 0).join(',')}] spacing=${info.spacing} ` +
              `wkt=${JSON.stringify(copc.wkt ?? null)}`);
}

const files = process.argv.slice(2);
if (files.length === 0) throw new Error('usage: copc_walk.mjs FILE.copc.laz...');
for (const file of files) {
  try {
    await walk(file);
  } catch (e) {
    fail(file, `copc.js failed: ${e.message}`);
  }
}
