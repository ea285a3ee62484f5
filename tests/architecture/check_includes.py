#!/usr/bin/env python3
"""The arrows of docs/architecture.md, checked on the includes as they stand.

Each room may include itself and the rooms listed for it below; anything else is an include that
runs upward or sideways, and fails the test with FILE:LINE. Generated headers (shaders/*.h,
cli/version.h) are build outputs, not rooms. Usage: check_includes.py REPO_ROOT
"""
import os
import re
import sys

# room -> rooms it may include (besides itself). Keep in step with docs/architecture.md.
ALLOWED = {
    "core": set(),
    "ops": {"core"},
    "converters": {"core", "ops"},
    "image": {"core", "ops"},
    "vulkan": {"core"},
    "generators": {"core", "vulkan"},
    "viewer": {"core", "ops", "converters", "image", "vulkan"},
    "bench": {"core", "ops", "converters", "image", "vulkan", "viewer"},
    "cli": {"core", "ops", "converters", "image", "vulkan", "generators", "viewer", "bench"},
    "python": {"core", "ops", "converters", "image", "vulkan", "generators", "viewer", "bench", "cli"},
}
GENERATED = {"shaders"}
INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"/]+)/[^"]+"')


def main() -> int:
    root = sys.argv[1] if len(sys.argv) > 1 else "."
    bad, checked = [], 0
    for room, allowed in ALLOWED.items():
        folder = os.path.join(root, room)
        if not os.path.isdir(folder):
            bad.append(f"{room}/: the room is missing")
            continue
        for dirpath, _, names in os.walk(folder):
            for name in sorted(names):
                if not name.endswith((".h", ".cpp")):
                    continue
                path = os.path.join(dirpath, name)
                with open(path, encoding="utf-8") as f:
                    for number, line in enumerate(f, 1):
                        m = INCLUDE.match(line)
                        if not m:
                            continue
                        checked += 1
                        target = m.group(1)
                        if target == room or target in allowed or target in GENERATED:
                            continue
                        if room in ("cli", "python") and line.strip().endswith('"cli/version.h"'):
                            continue
                        rel = os.path.relpath(path, root)
                        bad.append(f"{rel}:{number}: {room}/ may not include {target}/ ({line.strip()})")
    for b in bad:
        print(b)
    print(f"{checked} includes checked, {len(bad)} against the arrows")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
