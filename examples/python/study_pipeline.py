#!/usr/bin/env python3
"""The float-vs-double study's pipeline in a few lines: its seed-exact Mandelbulb, moved to the
Earth's radius, rendered in float32 and in native double, and each mode's error against the exact
reference.

    PYTHONPATH=build/python /usr/bin/python3 examples/python/study_pipeline.py [--resolution 100]
"""
import argparse

import dpoint

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("--resolution", type=int, default=100, help="grid points per axis (the study: 100..400)")
parser.add_argument("--out", default="", help="also write each mode's measured picture as OUT-MODE.png (1-px "
                    "points, as the error is measured) and the default preview as OUT-preview.png")
args = parser.parse_args()

# The study's generator, bit for bit (--variant seed), its points moved by exact double sums.
bulb = dpoint.generate("mandelbulb", resolution=args.resolution, variant="seed", offset=(6.371e6, 0, 0))
print(f"{len(bulb)} points, x from {bulb.positions[:, 0].min():.6f} to {bulb.positions[:, 0].max():.6f} m")

print(f"{'mode':8} {'bound px':>10} {'max px':>10} {'p99 px':>10} {'rms px':>10} {'gpu ms':>8}")
with dpoint.Renderer() as renderer:  # one Vulkan device for both renders
    for mode in ("fp32", "native"):
        result = renderer.render(bulb, mode, width=1920, height=1080, error=True)
        e = result.error_px
        print(f"{mode:8} {result.predicted_bound_px:10.3g} {e['max']:10.3g} {e['p99']:10.3g} {e['rms']:10.3g} "
              f"{result.gpu_ms[0]:8.2f}")
        if args.out:
            result.save(f"{args.out}-{mode}.png")
    if args.out:  # the picture a user looks at: point size and shading auto
        renderer.render(bulb, "native", width=1920, height=1080).save(f"{args.out}-preview.png")
