#!/usr/bin/python3
"""A quad-mesh PLY for the PLY reader's measurements: an N x N grid of vertices (x, y, sin)
and its (N-1)^2 quads, binary little-endian and ASCII, written with numpy (Debian's python3).

usage: /usr/bin/python3 bench/scripts/quad_mesh.py N BINARY.ply ASCII.ply
(N = 2001: 4,004,001 vertices, 4,000,000 quads, 164 MB and 336 MB)"""
import sys

import numpy as np

n = int(sys.argv[1])
j, k = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
positions = np.stack([j.ravel() * 0.001, k.ravel() * 0.001, np.sin(j.ravel() * 0.01)], axis=1).astype("<f8")
first = (j[:-1, :-1] * n + k[:-1, :-1]).ravel().astype("<u4")
quads = np.stack([first, first + 1, first + n + 1, first + n], axis=1)
header = (f"ply\nformat binary_little_endian 1.0\nelement vertex {len(positions)}\nproperty double x\n"
          f"property double y\nproperty double z\nelement face {len(quads)}\n"
          "property list uchar uint vertex_indices\nend_header\n")
rows = np.zeros(len(quads), dtype=[("count", "u1"), ("indices", "<u4", (4,))])
rows["count"] = 4
rows["indices"] = quads
with open(sys.argv[2], "wb") as f:
    f.write(header.encode())
    f.write(positions.tobytes())
    f.write(rows.tobytes())
with open(sys.argv[3], "w") as f:
    f.write(header.replace("binary_little_endian", "ascii"))
    np.savetxt(f, positions, fmt="%.17g")
    np.savetxt(f, np.hstack([np.full((len(quads), 1), 4), quads]), fmt="%d")
