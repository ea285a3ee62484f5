#!/usr/bin/python3
"""The fill and artefact measures of tests/viewer/picture_metrics.h for a PNG: prints
'gaps G% | artefacts A%' of the 7x7-closed drawn area (background: black)."""
import sys
import zlib

import numpy as np
from numpy.lib.stride_tricks import sliding_window_view as window


def read_png(path):
    """8-bit RGB or RGBA, non-interlaced, rows filtered none, sub or up (what dpoint writes)."""
    data = open(path, 'rb').read()
    pos, idat, width, height, channels = 8, b'', 0, 0, 0
    while pos < len(data):
        length = int.from_bytes(data[pos:pos + 4], 'big')
        kind, body = data[pos + 4:pos + 8], data[pos + 8:pos + 8 + length]
        if kind == b'IHDR':
            width, height = int.from_bytes(body[0:4], 'big'), int.from_bytes(body[4:8], 'big')
            channels = {2: 3, 6: 4}[body[9]]
        elif kind == b'IDAT':
            idat += body
        pos += 12 + length
    raw = zlib.decompress(idat)
    stride = width * channels
    out = np.zeros((height, stride), np.uint8)
    previous = np.zeros(stride, np.int32)
    for y in range(height):
        kind, line = raw[y * (stride + 1)], np.frombuffer(raw, np.uint8, stride, y * (stride + 1) + 1).astype(np.int32)
        if kind == 0:
            row = line
        elif kind == 1:  # sub: a running sum per channel (dpoint writes every row so)
            row = np.cumsum(line.reshape(-1, channels), axis=0).reshape(-1) & 255
        elif kind == 2:
            row = (line + previous) & 255
        else:
            raise SystemExit(f'{path}: PNG filter {kind} not read here (dpoint writes sub)')
        out[y] = row
        previous = row
    return out.reshape(height, width, channels)[:, :, :3]


def measures(rgb):
    drawn = np.any(rgb != 0, axis=2)
    dilated = window(np.pad(drawn, 3), (7, 7)).any(axis=(2, 3))
    closed = window(np.pad(dilated, 3, constant_values=True), (7, 7)).all(axis=(2, 3))
    luminance = rgb.astype(np.int64) @ np.array([299, 587, 114])
    median = np.median(window(np.pad(luminance, 2, mode='edge'), (5, 5)).reshape(luminance.shape + (25,)), axis=2)
    ring = window(np.pad(drawn, 1, mode='edge'), (3, 3)).sum(axis=(2, 3)) - drawn
    outline = closed & drawn & (2 * luminance < median)
    isolated = closed & ~drawn & (ring >= 6)
    gaps = closed & ~drawn
    total = max(int(closed.sum()), 1)
    return gaps.sum() / total, (outline.sum() + isolated.sum()) / total


if __name__ == '__main__':
    g, a = measures(read_png(sys.argv[1]))
    print(f'{100 * g:.2f}% | {100 * a:.2f}%')
