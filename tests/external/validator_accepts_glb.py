"""The official Khronos glTF validator (npm gltf-validator) finds 0 errors and 0 warnings in the
GLB files dpoint writes: point sets (POINTS) and meshes (TRIANGLES), with the exact-position
attributes _POSITION_LOW and _POSITION_LOW2 and, for data beyond float32's range, a node scale."""
import json
import os
import struct
import subprocess
import sys

from common import check, dpoint, scratch, write_mesh_ply

exe, validator = sys.argv[1], sys.argv[2]
check(os.path.isdir(validator), f"validator not installed at {validator} (scripts/setup installs it)")
script = """
const v = require(process.argv[1]); const fs = require('fs');
v.validateBytes(new Uint8Array(fs.readFileSync(process.argv[2])))
 .then(r => console.log(JSON.stringify(r.issues)))
 .catch(e => { console.error(e); process.exit(1); });
"""
with scratch() as d:
    files = {}
    files["points"] = os.path.join(d, "points.glb")
    dpoint(exe, "generate", "random2d", "--count", "20000", "-o", files["points"])
    csv = os.path.join(d, "colored.csv")
    with open(csv, "w") as f:
        f.write("x,y,z,r,g,b\n")
        for i in range(1000):
            f.write(f"{1e8 + i * 1e-3!r},{i * 0.5!r},-3,{i % 7 / 7!r},0.25,1\n")
    files["colored points"] = os.path.join(d, "colored.glb")
    dpoint(exe, "convert", csv, "-o", files["colored points"])
    write_mesh_ply(os.path.join(d, "mesh.ply"))
    files["mesh"] = os.path.join(d, "mesh.glb")
    dpoint(exe, "convert", os.path.join(d, "mesh.ply"), "-o", files["mesh"])
    tiny = os.path.join(d, "tiny.csv")
    with open(tiny, "w") as f:
        f.write("x,y,z\n")
        for i in range(100):
            f.write(f"{(i - 50) * 1.25e-301!r},{1e-300 + i * 3e-317!r},{i * 1e290!r}\n")
    files["tiny and huge points"] = os.path.join(d, "tiny.glb")
    dpoint(exe, "convert", tiny, "-o", files["tiny and huge points"])
    # Every LAS field and extra byte as an application-specific attribute (issue #34): bytes and
    # shorts padded to 4, float32 as FLOAT, wider types as their bytes in unsigned shorts.
    corpus = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "..", "shared", "corpus")
    for las in ("las/extrabytes.las", "laz/rand1_6.las", "las/1_4_w_evlr.las"):
        files[las] = os.path.join(d, os.path.basename(las) + ".glb")
        dpoint(exe, "convert", os.path.join(corpus, las), "-o", files[las])
    attributes = {}
    for name, path in files.items():
        with open(path, "rb") as f:
            data = f.read()
        (json_length,) = struct.unpack_from("<I", data, 12)
        gltf = json.loads(data[20:20 + json_length])
        attributes[name] = set(gltf["meshes"][0]["primitives"][0]["attributes"])
        check("_POSITION_LOW" in attributes[name], f"{name}: no _POSITION_LOW: {attributes[name]}")
    check("_POSITION_LOW2" in attributes["points"], "random2d needs the third part, and it is missing")
    check({"_INTENSITY", "_CLASSIFICATION", "_GPS_TIME"} <= attributes["laz/rand1_6.las"],
          f"rand1_6: {attributes['laz/rand1_6.las']}")
    with open(files["tiny and huge points"], "rb") as f:
        data = f.read()
    gltf = json.loads(data[20:20 + struct.unpack_from("<I", data, 12)[0]])
    check("scale" in gltf["nodes"][0], "the 1e-300 set has no node scale")
    for name, path in files.items():
        out = subprocess.run(["node", "-e", script, validator, path], capture_output=True, text=True)
        check(out.returncode == 0, f"validator failed on {name}: {out.stderr}")
        issues = json.loads(out.stdout)
        report = json.dumps(issues["messages"])[:2000]
        check(issues["numErrors"] == 0, f"{name}: {issues['numErrors']} errors: {report}")
        check(issues["numWarnings"] == 0, f"{name}: {issues['numWarnings']} warnings: {report}")
        print(f"{name} ({', '.join(sorted(attributes[name]))}): 0 errors, 0 warnings, "
              f"{issues['numInfos']} infos, {issues['numHints']} hints")
