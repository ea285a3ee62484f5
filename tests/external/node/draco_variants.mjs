// Draco variants of glTF models for dpoint's tests, several in one node process: what
// `gltf-transform draco IN OUT.glb` writes (the CLI's own transform, draco() with its defaults:
// edgebreaker, 14-bit positions; then unpartition() for a GLB), without a node start-up and a
// Draco encoder set-up per model (0.7 s each; the tests make some 25).
//
//   node draco_variants.mjs IN OUT.glb [IN OUT.glb ...]
import { load } from './modules.mjs';

const { NodeIO } = await load('@gltf-transform/core');
const { ALL_EXTENSIONS } = await load('@gltf-transform/extensions');
const { draco, unpartition } = await load('@gltf-transform/functions');
const draco3d = (await load('draco3dgltf')).default;
const { MeshoptDecoder } = await load('meshoptimizer');

const args = process.argv.slice(2);
if (!args.length || args.length % 2 || args.some((a, i) => i % 2 && !a.endsWith('.glb')))
  throw new Error('usage: draco_variants.mjs IN OUT.glb [IN OUT.glb ...]');
await MeshoptDecoder.ready;
const io = new NodeIO()
  .registerExtensions(ALL_EXTENSIONS)
  .registerDependencies({
    'draco3d.decoder': await draco3d.createDecoderModule(),
    'draco3d.encoder': await draco3d.createEncoderModule(),
    'meshopt.decoder': MeshoptDecoder,
  });
for (let i = 0; i < args.length; i += 2) {
  const document = await io.read(args[i]);
  // As the CLI does: a compressed input is decoded, then compressed again.
  for (const name of ['KHR_draco_mesh_compression', 'EXT_meshopt_compression'])
    if (document.hasExtension(name)) document.disposeExtension(name);
  await document.transform(draco(), unpartition());
  await io.write(args[i + 1], document);
}
