"""The official Khronos glTF validator (npm gltf-validator) finds 0 errors and 0 warnings in the
GLB files dpoint writes: point sets (POINTS) and meshes (TRIANGLES)."""
import json
import os
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
    for name, path in files.items():
        out = subprocess.run(["node", "-e", script, validator, path], capture_output=True, text=True)
        check(out.returncode == 0, f"validator failed on {name}: {out.stderr}")
        issues = json.loads(out.stdout)
        report = json.dumps(issues["messages"])[:2000]
        check(issues["numErrors"] == 0, f"{name}: {issues['numErrors']} errors: {report}")
        check(issues["numWarnings"] == 0, f"{name}: {issues['numWarnings']} warnings: {report}")
        print(f"{name}: 0 errors, 0 warnings, {issues['numInfos']} infos, {issues['numHints']} hints")
