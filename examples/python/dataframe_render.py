#!/usr/bin/env python3
"""A pandas DataFrame from a CSV file (columns x, y[, z][, r, g, b]) rendered with dpoint.

    PYTHONPATH=build/python /usr/bin/python3 examples/python/dataframe_render.py points.csv picture.png

With no CSV given it makes one: 200,000 points of a helix 1,000 km from the origin, where float32
coordinates are 6 cm apart, and renders them with the mode dpoint picks for that view.
"""
import sys

import numpy as np
import pandas as pd

import dpoint

if len(sys.argv) > 1:
    frame = pd.read_csv(sys.argv[1])
else:
    t = np.linspace(0.0, 40.0 * np.pi, 200_000)
    frame = pd.DataFrame({"x": 1.0e6 + np.cos(t), "y": 2.0e6 + np.sin(t), "z": t / 40.0,
                          "r": (127 + 127 * np.cos(t)).astype(np.uint8), "g": 90, "b": 200})
points = dpoint.PointSet.from_dataframe(frame)
result = dpoint.render(points, width=800, height=600)
print(result)
print(f"mode {result.mode}: predicted error bound {result.predicted_bound_px:.3g} px")
result.save(sys.argv[2] if len(sys.argv) > 2 else "dataframe.png")
