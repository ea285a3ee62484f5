// Reference glTF reader for dpoint's tests: world-space vertex positions of every mesh instance in
// the default scene (else scene 0), through glTF-Transform, written as CSV x,y,z in double with
// the shortest round-trip digits.
//
//   node read_points.mjs IN.glb|IN.gltf [-o OUT.csv] [IN -o OUT ...] [--all-vertices]
//
// Several inputs, each with its -o, are read in turn by one node process (its start-up and the
// decoders' is most of a small model's time; the tests read some 60 files).
//
// Per primitive it writes the vertices the primitive references: each distinct index once, in
// increasing order, or every element of POSITION when it has no indices (dpoint's rule, issue #4).
// --all-vertices writes every POSITION element even when indexed. Compressed (Draco, meshopt),
// sparse and quantized accessors are decoded by glTF-Transform itself; getElement() applies the
// accessor's normalization, so the numbers are those the file means, not its stored integers.
import fs from 'node:fs';
import { load, num } from './modules.mjs';

const { MathUtils, NodeIO } = await load('@gltf-transform/core');
const { ALL_EXTENSIONS } = await load('@gltf-transform/extensions');
const draco3d = (await load('draco3dgltf')).default;
const { MeshoptDecoder } = await load('meshoptimizer');

function parseArgs(argv) {
  const usage = 'usage: read_points.mjs IN.glb [-o OUT.csv] [IN -o OUT ...] [--all-vertices]';
  const args = { jobs: [], allVertices: false };
  for (let i = 0; i < argv.length; i++) {
    if (argv[i] === '-o') {
      const job = args.jobs[args.jobs.length - 1];
      if (!job || job.output !== null || i + 1 >= argv.length) throw new Error(usage);
      job.output = argv[++i];
    } else if (argv[i] === '--all-vertices') args.allVertices = true;
    else args.jobs.push({ input: argv[i], output: null });
  }
  // Standard output takes one input only: several would run together there.
  if (!args.jobs.length || (args.jobs.length > 1 && args.jobs.some((job) => job.output === null))) throw new Error(usage);
  return args;
}

// Buffered text output: one write call per ~1 MB keeps large models fast.
function makeWriter(path) {
  const fd = path ? fs.openSync(path, 'w') : 1;
  let parts = [], size = 0;
  const flush = () => { fs.writeSync(fd, parts.join('')); parts = []; size = 0; };
  return {
    line(s) { parts.push(s); size += s.length; if (size > 1 << 20) flush(); },
    close() { flush(); if (path) fs.closeSync(fd); },
  };
}

// The vertex numbers a primitive uses, ascending and distinct (all of them when not indexed).
function usedVertices(primitive, count, allVertices) {
  const indices = primitive.getIndices();
  if (!indices || allVertices) return { count, at: (i) => i };
  const used = new Uint8Array(count);
  const array = indices.getArray();
  for (let i = 0; i < array.length; i++) {
    if (array[i] >= count) throw new Error(`index ${array[i]} out of range (${count} vertices)`);
    used[array[i]] = 1;
  }
  const list = [];
  for (let v = 0; v < count; v++) if (used[v]) list.push(v);
  return { count: list.length, at: (i) => list[i] };
}

// glTF-Transform keeps a node's `matrix` only as translation/rotation/scale it decomposes it
// into. A matrix written with 7 digits is not exactly a rotation times a scale, and that
// decomposition moved points of 2CylinderEngine.glb by 6e-9 of the model's size, so the
// matrices are taken from the file's JSON as written; nodes with TRS use glTF-Transform's
// composition T·R·S, with the quaternion divided by its length first: files hold rotations
// rounded to a few digits (cameras/Cameras.gltf: |q|² = 1.000003), and dpoint does not assume
// them unit (issue #4), where the bare formula would also scale by |q|².
function localMatrix(node, nodeIndex, matrices) {
  const matrix = matrices[nodeIndex.get(node)];
  if (matrix) return matrix;
  const q = node.getRotation();
  const length = Math.hypot(q[0], q[1], q[2], q[3]);
  const unit = length > 0 ? q.map((v) => v / length) : [0, 0, 0, 1];
  return MathUtils.compose(node.getTranslation(), unit, node.getScale(), new Array(16));
}

// Column-major 4x4 product a·b in double.
function multiply(a, b) {
  const r = new Array(16);
  for (let col = 0; col < 4; col++)
    for (let row = 0; row < 4; row++) {
      let sum = 0;
      for (let k = 0; k < 4; k++) sum += a[k * 4 + row] * b[col * 4 + k];
      r[col * 4 + row] = sum;
    }
  return r;
}

function worldMatrix(node, nodeIndex, matrices) {
  const local = localMatrix(node, nodeIndex, matrices);
  const parent = node.getParentNode();
  return parent ? multiply(worldMatrix(parent, nodeIndex, matrices), local) : local;
}

// EXT_mesh_gpu_instancing: one matrix T·R·S per instance (quaternion divided by its length, as
// for nodes), or null when the node is not instanced. getElement() applies normalization.
function instanceMatrices(node) {
  const instancing = node.getExtension('EXT_mesh_gpu_instancing');
  if (!instancing) return null;
  const t = instancing.getAttribute('TRANSLATION');
  const r = instancing.getAttribute('ROTATION');
  const s = instancing.getAttribute('SCALE');
  const first = t || r || s;
  if (!first) throw new Error('EXT_mesh_gpu_instancing without TRANSLATION, ROTATION or SCALE');
  const matrices = [];
  for (let i = 0; i < first.getCount(); i++) {
    const tv = t ? t.getElement(i, [0, 0, 0]) : [0, 0, 0];
    const q = r ? r.getElement(i, [0, 0, 0, 0]) : [0, 0, 0, 1];
    const sv = s ? s.getElement(i, [0, 0, 0]) : [1, 1, 1];
    const length = Math.hypot(q[0], q[1], q[2], q[3]);
    matrices.push(MathUtils.compose(tv, q.map((v) => v / length), sv, new Array(16)));
  }
  return matrices;
}

function writeInstance(node, world, out, allVertices) {
  const instances = instanceMatrices(node);
  if (!instances) return writeMesh(node, world, out, allVertices);
  for (const instance of instances) writeMesh(node, multiply(world, instance), out, allVertices);
}

function writeMesh(node, m, out, allVertices) {
  if (node.getSkin()) process.stderr.write('read_points: skinned mesh placed by its node matrix\n');
  const p = [0, 0, 0];
  for (const primitive of node.getMesh().listPrimitives()) {
    const position = primitive.getAttribute('POSITION');
    if (!position) continue;
    const vertices = usedVertices(primitive, position.getCount(), allVertices);
    for (let i = 0; i < vertices.count; i++) {
      position.getElement(vertices.at(i), p);
      const x = m[0] * p[0] + m[4] * p[1] + m[8] * p[2] + m[12];
      const y = m[1] * p[0] + m[5] * p[1] + m[9] * p[2] + m[13];
      const z = m[2] * p[0] + m[6] * p[1] + m[10] * p[2] + m[14];
      out.line(`${num(x)},${num(y)},${num(z)}\n`);
    }
  }
}

async function readPoints(io, input, output, allVertices) {
  const json = await io.readAsJSON(input);
  const matrices = (json.json.nodes || []).map((n) => (n.matrix ? n.matrix.slice() : null));
  const document = await io.readJSON(json);
  const root = document.getRoot();
  const nodeIndex = new Map(root.listNodes().map((node, i) => [node, i]));  // JSON order
  if (nodeIndex.size !== matrices.length) throw new Error(`${input}: node list differs from the JSON`);
  const scene = root.getDefaultScene() || root.listScenes()[0];
  if (!scene) throw new Error(`${input}: no scene`);
  const out = makeWriter(output);
  out.line('x,y,z\n');
  scene.traverse((node) => {
    if (node.getMesh()) writeInstance(node, worldMatrix(node, nodeIndex, matrices), out, allVertices);
  });
  out.close();
}

const args = parseArgs(process.argv.slice(2));
await MeshoptDecoder.ready;
const io = new NodeIO()
  .registerExtensions(ALL_EXTENSIONS)
  .registerDependencies({
    'draco3d.decoder': await draco3d.createDecoderModule(),
    'meshopt.decoder': MeshoptDecoder,
  });
for (const job of args.jobs) await readPoints(io, job.input, job.output, args.allVertices);
