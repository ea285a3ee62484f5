#!/usr/bin/python3
"""Recomputes random2d from its definition (splitmix64, u -> ((u >> 11) - 2^52) * 2^-52) and
compares with a dpoint CSV. Usage: check_random2d.py FILE.csv SEED"""
import sys

M = (1 << 64) - 1
def splitmix64_at(seed, i):
    z = (seed + (i + 1) * 0x9E3779B97F4A7C15) & M
    z = ((z ^ (z >> 30)) * 0xBF58476D1CE4E5B9) & M
    z = ((z ^ (z >> 27)) * 0x94D049BB133111EB) & M
    return z ^ (z >> 31)

def unit(u):
    return float((u >> 11) - (1 << 52)) * 2.0**-52

path, seed = sys.argv[1], int(sys.argv[2])
rows = open(path).read().splitlines()
assert rows[0] == 'x,y', rows[0]
for i, row in enumerate(rows[1:]):
    x, y = map(float, row.split(','))
    assert (x, y) == (unit(splitmix64_at(seed, 2 * i)), unit(splitmix64_at(seed, 2 * i + 1))), (i, row)
print(f'{len(rows) - 1} rows match')
