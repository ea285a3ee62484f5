"""dpoint's glTF reader against an independent one (issue #4): glTF-Transform (npm), driven by
tests/external/node/read_points.mjs, computes world-space positions in double for the same files.

1. Models from Debian's assimp-testmodels, plus one written here (a far-from-origin matrix/TRS
   hierarchy with non-uniform scale, a mesh instanced twice, an unreferenced vertex, a strided
   buffer and a mostly-zero POINTS accessor that `gltf-transform sparse` turns sparse): dpoint's
   points equal the reference's as sorted multisets within 1e-9 relative.
2. Variants of 2CylinderEngine.glb (and of the hand-made model) made by gltf-transform and
   gltfpack: dpoint equals the reference reader on THAT file within 1e-9, and the original within
   the variant's quantization step. meshopt (EXT_meshopt_compression, with or without a fallback
   buffer) and Draco (KHR_draco_mesh_compression) are decoded and compared like the others, and
   so is gltfpack -mi (EXT_mesh_gpu_instancing: the reference reader applies instance T·R·S too).
3. The Draco variant (gltf-transform draco: 14-bit positions) of every other model above, the
   same two ways, and assimp's own Draco model (draco/2CylinderEngine.gltf) against the reference.
   These variants are made by one node process (node/draco_variants.mjs, the CLI's own transform;
   it must write the CLI's very bytes for the engine), and the reference reader reads each batch of
   files in one process: node start-ups were two thirds of this test's minute.

"1e-9 relative" is per coordinate: |ours − theirs| ≤ 1e-9 · max(model extent, |theirs|), so points
near the origin of a large model are held to the model's scale, far ones to their own magnitude.
Usage: gltf_matches_reference_reader.py DPOINT GLTF_VALIDATOR_DIR [ASSIMP_MODELS_DIR]"""
import json
import os
import struct
import subprocess
import sys

from common import check, scratch
from gltf_compare import NODE_DIR, glb_json, match_sorted, node_tools_dir, read_xyz, reference_points_of, run_tool, within

exe, validator = sys.argv[1], sys.argv[2]
models_dir = sys.argv[3] if len(sys.argv) > 3 else "/usr/share/assimp/models/glTF2"
check(os.path.isdir(models_dir), f"{models_dir} missing (scripts/setup installs assimp-testmodels)")
modules = node_tools_dir(validator)
gltf_transform = os.path.join(modules, ".bin", "gltf-transform")
check(os.access(gltf_transform, os.X_OK), f"{gltf_transform} missing (scripts/setup installs @gltf-transform/cli)")
check(os.access("/usr/bin/gltfpack", os.X_OK), "gltfpack missing (scripts/setup installs it)")

REL = 1e-9
ENGINE = "2CylinderEngine-glTF-Binary/2CylinderEngine.glb"
MODELS = [
    ENGINE,                                              # 82 nodes, 76 matrices, meshes reused
    "ClearCoat-glTF/ClearCoatTest.gltf",                 # 50 nodes in a TRS hierarchy, 20k vertices
    "textureTransform/TextureTransformTest.gltf",        # many nodes sharing one mesh
    "BoxTextured-glTF-Binary/BoxTextured.glb",           # root matrix (Y-up rotation) above a child
    "BoxTextured-glTF-Embedded/BoxTextured.gltf",        # buffers as base64 data: URIs
    "cameras/Cameras.gltf",                              # TRS with rotation, camera nodes without mesh
    "glTF-Sample-Models/AnimatedMorphCube-glTF/AnimatedMorphCube.gltf",  # morph targets (ignored)
    "issue_3269/texcoord_crash.gltf",
    "draco/2CylinderEngine.gltf",                        # KHR_draco_mesh_compression, made by Draco's tools
] + [f"glTF-Asset-Generator/Mesh_PrimitiveMode/Mesh_PrimitiveMode_{i:02}.gltf" for i in range(16)]

# Variants: (name, tool command with IN/OUT placeholders, quantization bits of POSITION or None for
# float32 data, extensions dpoint may refuse by name instead of decoding).
GT = [gltf_transform]
VARIANTS = [
    ("gltf-transform quantize", GT + ["quantize", "IN", "OUT"], 14, ()),
    ("gltf-transform meshopt", GT + ["meshopt", "IN", "OUT"], 14, ()),  # decoded, no fallback buffer
    ("gltf-transform draco", GT + ["draco", "IN", "OUT"], 14, ()),
    ("gltf-transform sparse", GT + ["sparse", "IN", "OUT"], None, ()),
    ("gltf-transform flatten", GT + ["flatten", "IN", "OUT"], None, ()),
    ("gltf-transform join", GT + ["join", "IN", "OUT"], None, ()),
    ("gltfpack", ["gltfpack", "-i", "IN", "-o", "OUT"], 14, ()),
    ("gltfpack -noq", ["gltfpack", "-i", "IN", "-o", "OUT", "-noq"], None, ()),
    ("gltfpack -cf", ["gltfpack", "-i", "IN", "-o", "OUT", "-cf"], 14, ()),  # has a fallback buffer
    ("gltfpack -c", ["gltfpack", "-i", "IN", "-o", "OUT", "-c"], 14, ()),    # meshopt, data-less fallback
    ("gltfpack -cc", ["gltfpack", "-i", "IN", "-o", "OUT", "-cc"], 14, ()),  # meshopt with filters
    # EXT_mesh_gpu_instancing: the engine's repeated meshes become instanced nodes.
    ("gltfpack -mi", ["gltfpack", "-i", "IN", "-o", "OUT", "-mi"], 14, ()),
    ("gltfpack -mi -noq", ["gltfpack", "-i", "IN", "-o", "OUT", "-mi", "-noq"], None, ()),
]
# gltfpack stores instance rotations as normalized shorts: each quaternion component is off by up
# to 2^-16, turning a point by up to about 2^-14 rad about its instance origin, which lies within
# the model's diagonal of it; 2^-13 · diagonal leaves room for the composition.
ROTATION_QUANTIZED = {"gltfpack -mi", "gltfpack -mi -noq"}


def write_hierarchy_glb(path):
    """A small GLB exercising transforms in double far from the origin (see the module comment)."""
    cube = [(x, y, z) for x in (-1.0, 1.0) for y in (-1.0, 1.0) for z in (-1.0, 1.0)] + [(9.0, 9.0, 9.0)]
    tris = [0, 1, 3, 0, 3, 2, 4, 6, 7, 4, 7, 5, 0, 4, 5, 0, 5, 1, 2, 3, 7, 2, 7, 6, 0, 2, 6, 0, 6, 4, 1, 5, 7, 1, 7, 3]
    dots = [(0.0, 0.0, 0.0)] * 24 + [(0.25 * i, 1.5 - i, 0.125 * i * i) for i in range(1, 7)]
    blob = b"".join(struct.pack("<3f", *p) for p in cube)                 # view 0, tight
    blob += struct.pack(f"<{len(tris)}H", *tris)                           # view 1
    blob += b"\0" * (-len(blob) % 4)
    dots_at = len(blob)
    blob += b"".join(struct.pack("<3f", *p) + b"\xee" * 4 for p in dots)  # view 2, stride 16
    s, c = 0.6, 0.8  # a rotation by atan(3/4) about z, exact in binary
    doc = {
        "asset": {"version": "2.0", "generator": "dpoint test"},
        "scene": 1,
        "scenes": [{"nodes": [4]}, {"nodes": [0]}],
        "nodes": [
            {"matrix": [c * 2, s * 2, 0, 0, -s * 0.5, c * 0.5, 0, 0, 0, 0, 3, 0, 6378137.25, -1234.5, 10.125, 1],
             "children": [1, 2]},
            {"mesh": 0, "translation": [10, 20, 30], "rotation": [0.5, 0.5, 0.5, 0.5], "scale": [1, 4, 0.25]},
            {"mesh": 0, "translation": [-7, 0, 0.5], "rotation": [0, 0.7071067811865476, 0, 0.7071067811865476],
             "children": [3]},
            {"mesh": 1, "scale": [1e-3, 1e-3, 1e-3], "translation": [0.1, 0.2, 0.3]},
            {"mesh": 0},  # in scene 0, which is not the default: must not appear
        ],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]},
                   {"primitives": [{"attributes": {"POSITION": 2}, "mode": 0}]}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": len(cube), "type": "VEC3",
             "min": [-1, -1, -1], "max": [9, 9, 9]},
            {"bufferView": 1, "componentType": 5123, "count": len(tris), "type": "SCALAR"},
            {"bufferView": 2, "componentType": 5126, "count": len(dots), "type": "VEC3",
             "min": [min(p[k] for p in dots) for k in range(3)], "max": [max(p[k] for p in dots) for k in range(3)]},
        ],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": 12 * len(cube), "target": 34962},
            {"buffer": 0, "byteOffset": 12 * len(cube), "byteLength": 2 * len(tris), "target": 34963},
            {"buffer": 0, "byteOffset": dots_at, "byteLength": 16 * len(dots), "byteStride": 16, "target": 34962},
        ],
        "buffers": [{"byteLength": len(blob)}],
    }
    text = json.dumps(doc).encode()
    text += b" " * (-len(text) % 4)
    with open(path, "wb") as f:
        f.write(struct.pack("<3I", 0x46546C67, 2, 12 + 8 + len(text) + 8 + len(blob)))
        f.write(struct.pack("<2I", len(text), 0x4E4F534A) + text)
        f.write(struct.pack("<2I", len(blob), 0x004E4942) + blob)


def convert(model, out_csv):
    """dpoint convert; returns (exit code, stderr)."""
    result = subprocess.run([exe, "convert", model, "-o", out_csv, "--quiet"], capture_output=True, text=True)
    return result.returncode, result.stderr.strip()


def compare_models(models, work):
    """dpoint and the reference agree on each of `models` (one node run reads them all); returns
    the reference's points of each."""
    stems = [os.path.join(work, os.path.basename(model)) for model in models]
    references = reference_points_of(modules, [(model, stem + ".ref.csv") for model, stem in zip(models, stems)])
    for model, stem, theirs in zip(models, stems, references):
        code, err = convert(model, stem + ".csv")
        check(code == 0, f"dpoint convert {model} failed ({code}): {err}")
        ok, message = match_sorted(read_xyz(stem + ".csv"), theirs, REL)
        check(ok, f"{model}: {message}")
        shown = os.path.relpath(model, models_dir) if model.startswith(models_dir) else os.path.basename(model)
        print(f"match  {shown}: {message}")
    return references


def variant_path(original, name, work):
    tag = name.replace(" ", "_").replace("-", "")
    return os.path.join(work, f"{os.path.basename(original)}.{tag}.glb")


def make_draco_variants(pairs):
    """`gltf-transform draco ORIGINAL VARIANT` for each pair, made by one node process
    (draco_variants.mjs: the CLI's own transform) instead of a CLI start-up per model."""
    argv = ["node", os.path.join(NODE_DIR, "draco_variants.mjs")]
    for original, variant in pairs:
        argv += [original, variant]
    run_tool(argv, dict(os.environ, DPOINT_NODE_MODULES=modules))


def compare_variants(jobs):
    """Each job is (original, original_points, variant name, bits, extensions it may refuse, variant
    file, made already). dpoint reads each variant; one node run reads them all for the reference.
    Returns each job's extensionsRequired, None where dpoint refused the file cleanly."""
    required_of, compared = [], []
    for original, original_points, name, bits, may_refuse, variant in jobs:
        required = glb_json(variant).get("extensionsRequired", [])
        code, err = convert(variant, variant + ".csv")
        refusable = [e for e in may_refuse if e in required]
        if code != 0 and refusable:
            # A clean refusal: exit 2, one line, naming the extension dpoint does not decode.
            check(code == 2, f"{name}: refused with exit {code}, not 2: {err}")
            check(len(err.splitlines()) == 1 and refusable[0] in err,
                  f"{name}: the refusal must be one line naming {refusable[0]}: {err}")
            print(f"skip   {os.path.basename(original)} {name}: refused cleanly ({err})")
            required_of.append(None)
            continue
        check(code == 0, f"{name} (requires {required}): dpoint convert failed ({code}): {err}")
        required_of.append(required)
        compared.append((original, original_points, name, bits, variant, required))
    references = reference_points_of(modules, [(job[4], job[4] + ".ref.csv") for job in compared])
    for (original, original_points, name, bits, variant, required), theirs in zip(compared, references):
        ours = read_xyz(variant + ".csv")
        ok, message = match_sorted(ours, theirs, REL)
        check(ok, f"{name}: against the reference reader on the same file: {message}")
        # Quantized: a coordinate moves at most half a step of `bits` over its mesh's box, which lies in
        # the model's box (rotation can mix three components, hence the model's diagonal). Float data
        # re-baked by flatten/join/gltfpack: float32 rounding of world coordinates.
        lo, hi = original_points.min(axis=0), original_points.max(axis=0)
        diagonal = float(((hi - lo) ** 2).sum() ** 0.5)
        magnitude = float(abs(original_points).max())
        step = diagonal / (2 ** bits - 1) if bits else 2.0 ** -23 * max(magnitude, diagonal)
        if name in ROTATION_QUANTIZED:
            check("EXT_mesh_gpu_instancing" in required, f"{name}: made no instanced nodes ({required})")
            step += diagonal * 2.0 ** -13
        ok2, message2 = within(ours, original_points, step)
        check(ok2, f"{name}: against the original model: {message2}")
        print(f"match  {os.path.basename(original)} {name}: {message}; original {message2}")
    return required_of


def tool_variants(original, original_points, variants, work):
    """The jobs of compare_variants for `variants` of `original`, each file made by its tool."""
    jobs = []
    for name, command, bits, may_refuse in variants:
        variant = variant_path(original, name, work)
        run_tool([variant if a == "OUT" else original if a == "IN" else a for a in command])
        jobs.append((original, original_points, name, bits, may_refuse, variant))
    return jobs


with scratch() as work:
    hierarchy = os.path.join(work, "hierarchy.glb")
    write_hierarchy_glb(hierarchy)
    models = [os.path.join(models_dir, relative) for relative in MODELS]
    references = compare_models(models + [hierarchy], work)
    points_of = dict(zip(models + [hierarchy], references))
    hierarchy_points = points_of[hierarchy]
    check(len(hierarchy_points) == 2 * 8 + 30, f"hierarchy.glb: reference gives {len(hierarchy_points)} points")

    engine = os.path.join(models_dir, ENGINE)
    jobs = tool_variants(engine, points_of[engine], VARIANTS, work)
    jobs += tool_variants(hierarchy, hierarchy_points, VARIANTS[:4], work)
    draco = next(v for v in VARIANTS if v[0] == "gltf-transform draco")
    others = [m for m, relative in zip(models, MODELS) if relative not in (ENGINE, "draco/2CylinderEngine.gltf")]
    made = [variant_path(m, draco[0], work) for m in others]
    # The engine once more, beside the CLI's variant of it: the script must write the CLI's very bytes.
    engine_again = os.path.join(work, "engine-draco-by-script.glb")
    make_draco_variants(list(zip(others, made)) + [(engine, engine_again)])
    with open(engine_again, "rb") as a, open(variant_path(engine, draco[0], work), "rb") as b:
        check(a.read() == b.read(), f"draco_variants.mjs and gltf-transform draco wrote different files for {ENGINE}")
    first_other = len(jobs)
    jobs += [(m, points_of[m], draco[0], draco[2], draco[3], v) for m, v in zip(others, made)]
    required_of = compare_variants(jobs)
    compressed = [os.path.relpath(m, models_dir) for m, required in zip(others, required_of[first_other:])
                  if required is not None and "KHR_draco_mesh_compression" in required]
    # gltf-transform compresses triangle primitives only; the point and line modes stay plain.
    print(f"draco  {len(compressed)} of {len(MODELS) - 2} further models came out Draco-compressed")
    check(len(compressed) >= 10, f"only {compressed} were Draco-compressed")
    # The point of the hand-made model's sparse variant: a POSITION accessor really is sparse.
    sparse = glb_json(os.path.join(work, "hierarchy.glb.gltftransform_sparse.glb"))
    check(any("sparse" in a for a in sparse["accessors"]), "gltf-transform sparse made no sparse accessor")
