#!/usr/bin/python3
"""The corpus table (issues #12, #13): every file of ../shared/corpus/ (the glTF-Validator's test
assets, the LAS files) and of Debian's assimp-testmodels that dpoint reads (glTF, GLB, PLY, LAS,
LAZ) goes through `dpoint convert FILE -o OUT.csv`, as a user would run it. Each must convert, or
be refused with one line on stderr naming the file and exit 2 (bad input) or 4 (resource limit),
within the time limit and leaving no output. For the validator's files the official verdict
(`X.report.json`, issues.numErrors) is counted beside.

Usage: bench/scripts/corpus_table.py build/dpoint [OUT.md]. Prints the Markdown table (and writes it to
OUT.md); exit 1 when any file broke the rule (the offenders are listed under the table).
"""
import json
import os
import subprocess
import sys
import tempfile
import time

top = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
exe = os.path.abspath(sys.argv[1])
out_md = sys.argv[2] if len(sys.argv) > 2 else None
shared = os.path.join(os.path.dirname(top), "shared", "corpus")
groups = [
    ("glTF-Validator test assets (../shared/corpus/gltf-validator)", os.path.join(shared, "gltf-validator"),
     (".gltf", ".glb")),
    ("LAS and LAZ (../shared/corpus/las)", os.path.join(shared, "las"), (".las", ".laz")),
    ("assimp-testmodels glTF 2 and 1 (/usr/share/assimp/models/glTF2, glTF)", None, (".gltf", ".glb")),
    ("assimp-testmodels PLY (/usr/share/assimp/models/PLY)", "/usr/share/assimp/models/PLY", (".ply",)),
]
LIMIT_S = 60


def files_of(folder, exts):
    found = []
    for root, _, names in os.walk(folder):
        found += [os.path.join(root, n) for n in names if n.lower().endswith(exts)]
    return sorted(found)


def verdict(path):
    report = path + ".report.json"
    if not os.path.exists(report):
        return None
    with open(report) as f:
        return json.load(f).get("issues", {}).get("numErrors")


rows, offenders, clean_refusals = [], [], []
work = tempfile.mkdtemp(prefix="dpoint-corpus-")
for name, folder, exts in groups:
    if folder is None:
        paths = files_of("/usr/share/assimp/models/glTF2", exts) + files_of("/usr/share/assimp/models/glTF", exts)
    else:
        paths = files_of(folder, exts)
    if not paths:
        rows.append((name, 0, 0, 0, 0, 0, "-", "-", "not installed"))
        continue
    converted = refused = broken = 0
    clean_refused = clean = 0
    slowest = 0.0
    for path in paths:
        out = os.path.join(work, "out.csv")
        start = time.monotonic()
        try:
            r = subprocess.run([exe, "convert", path, "-o", out, "--quiet"], capture_output=True, text=True,
                               errors="replace", timeout=LIMIT_S)
            code, err = r.returncode, r.stderr
        except subprocess.TimeoutExpired:
            code, err = "timeout", ""
        slowest = max(slowest, time.monotonic() - start)
        lines = [l for l in err.splitlines() if l.strip()]
        v = verdict(path)
        if v == 0:
            clean += 1
        if code == 0 and not lines and os.path.exists(out):
            converted += 1
        elif code in (2, 4) and len(lines) == 1 and path in lines[0] and not os.path.exists(out):
            refused += 1
            if v == 0 and "no points to convert" not in lines[0]:
                clean_refused += 1
                clean_refusals.append("%s: %s" % (os.path.relpath(path, folder or "/"), lines[0][len("dpoint: error: "):]
                                                  .replace(path + ": ", "")))
        else:
            broken += 1
            offenders.append("%s: exit %s, %d stderr line(s): %s" % (path, code, len(lines), " | ".join(lines)[:300]))
        if os.path.exists(out):
            os.remove(out)
    rows.append((name, len(paths), converted, refused, broken, clean, clean_refused, "%.2f s" % slowest, ""))

table = ["| corpus | files | converted | refused, one line, exit 2/4 | other (crash, hang, several lines, wrong code) |"
         " validator: 0 errors | of those, refused for another reason than 'no points' | slowest | note |",
         "| --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
for name, n, ok, ref, bad, clean, clean_ref, slow, note in rows:
    table.append("| %s | %d | %d | %d | %d | %s | %s | %s | %s |" % (
        name, n, ok, ref, bad, clean if "Validator" in name else "-", clean_ref if "Validator" in name else "-",
        slow, note))
text = "\n".join(table) + "\n"
if clean_refusals:
    text += ("\nRefused though the validator reports no error (tinygltf's own limits, or dpoint's rules on "
             "URIs and versions):\n\n" + "\n".join("- " + c for c in clean_refusals) + "\n")
if offenders:
    text += "\nOffenders:\n\n" + "\n".join("- " + o for o in offenders) + "\n"
print(text, end="")
if out_md:
    with open(out_md, "w") as f:
        f.write("# Corpus table (`bench/scripts/corpus_table.py build/dpoint`)\n\n" + text)
sys.exit(1 if offenders else 0)
