// LASzip's own decoder as judge (issue #35): npm's laz-perf (LASzip's codec compiled to WASM)
// decodes a .laz file and writes its point records, uncompressed and back to back, to OUT:
//
//   node lazperf_records.mjs IN.laz OUT.bin     (prints "format=F length=L count=N")
//
// Optionally --time R: decodes R times and prints the median decode time (ms) of the records
// alone, the file already in memory (the benchmark of bench/laz_decode.sh). laz-perf aborts the
// whole process on a corrupt file, so run one process per file.
import fs from 'node:fs';
import { createRequire } from 'node:module';
import path from 'node:path';
import { modulesDir } from './modules.mjs';

const args = process.argv.slice(2);
let repeats = 0;
const files = [];
for (let i = 0; i < args.length; i++) {
  if (args[i] === '--time') repeats = Number(args[++i]);
  else files.push(args[i]);
}
if (files.length !== 2) throw new Error('usage: lazperf_records.mjs IN.laz OUT.bin [--time R]');
const require = createRequire(path.join(modulesDir, 'resolve-from-here.js'));
let lazperf;
try {
  lazperf = require('laz-perf');
} catch (e) {
  throw new Error(`npm module laz-perf not found under ${modulesDir} (run scripts/setup)`);
}
const LazPerf = await lazperf.createLazPerf();
const bytes = fs.readFileSync(files[0]);
const filePtr = LazPerf._malloc(bytes.length);
LazPerf.HEAPU8.set(bytes, filePtr);

function decode(keep) {
  const laszip = new LazPerf.LASZip();
  laszip.open(filePtr, bytes.length);
  const count = laszip.getCount(), length = laszip.getPointLength(), format = laszip.getPointFormat();
  const pointPtr = LazPerf._malloc(length);
  const out = keep ? Buffer.alloc(count * length) : null;
  for (let i = 0; i < count; i++) {
    laszip.getPoint(pointPtr);
    if (keep) out.set(LazPerf.HEAPU8.subarray(pointPtr, pointPtr + length), i * length);
  }
  LazPerf._free(pointPtr);
  laszip.delete();
  return { count, length, format, out };
}

const { count, length, format, out } = decode(true);
fs.writeFileSync(files[1], out);
let line = `format=${format} length=${length} count=${count}`;
if (repeats > 0) {
  const times = [];
  for (let r = 0; r < repeats; r++) {
    const t0 = process.hrtime.bigint();
    decode(false);
    times.push(Number(process.hrtime.bigint() - t0) / 1e6);
  }
  times.sort((a, b) => a - b);
  line += ` median_ms=${times[Math.floor(times.length / 2)].toFixed(3)}`;
}
console.log(line);
LazPerf._free(filePtr);
