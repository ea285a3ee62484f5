#!/usr/bin/python3
"""Makes earth_offset_mm.csv: a 10x10x10 grid with 1 mm spacing at x = 6.378e6 m (the Earth's
radius), coloured by position: the offset hard case of DESIGN §7, small enough to commit."""
with open("earth_offset_mm.csv", "w") as f:
    f.write("x,y,z,r,g,b\n")
    for i in range(10):
        for j in range(10):
            for k in range(10):
                x, y, z = 6.378e6 + i * 1e-3, j * 1e-3, k * 1e-3
                f.write(f"{x!r},{y!r},{z!r},{i / 9!r},{j / 9!r},{k / 9!r}\n")
