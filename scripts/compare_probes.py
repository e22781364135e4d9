#!/usr/bin/env python3
"""The radiance of two builds, pixel by pixel in f64, from `penumbra probe`.

    scripts/compare_probes.py OLD_BINARY NEW_BINARY SCENE [STEP] [SIZE]

Probes every STEP-th pixel (default 4) of a SIZE x SIZE image (default 64) with both binaries
and prints the largest absolute and relative difference of the radiance, and how many pixels'
recordings (the new binary's) took a set difference as a hole, and how many two holes. The images penumbra writes are
f32; a change meant to move results by rounding only is checked here, in f64.
"""
import json
import os
import subprocess
import sys
import tempfile


def radiance(binary, scene, size, x, y, out):
    subprocess.run(
        [binary, "probe", scene, "--size", f"{size}x{size}", "--pixel", f"{x},{y}",
         "--json", out],
        capture_output=True, check=True)
    with open(out) as f:
        return json.load(f)


def main():
    if len(sys.argv) < 4:
        sys.exit(__doc__)
    old, new, scene = sys.argv[1:4]
    step = int(sys.argv[4]) if len(sys.argv) > 4 else 4
    size = int(sys.argv[5]) if len(sys.argv) > 5 else 64
    out = os.path.join(tempfile.mkdtemp(), "probe.json")
    worst_rel = worst_abs = 0.0
    pixels = holes = two_holes = 0
    for y in range(0, size, step):
        for x in range(0, size, step):
            a = radiance(old, scene, size, x, y, out)["radiance"]
            d = radiance(new, scene, size, x, y, out)
            pixels += 1
            per_light = [sum(sd.get("method") == "Hole" for sd in lr["set_differences"])
                         for lr in d["recording"]["lights"]]
            holes += any(n > 0 for n in per_light)
            two_holes += any(n > 1 for n in per_light)
            for p, q in zip(a, d["radiance"]):
                worst_abs = max(worst_abs, abs(p - q))
                m = max(abs(p), abs(q))
                if m > 0:
                    worst_rel = max(worst_rel, abs(p - q) / m)
    print(f"{scene}: {pixels} pixels, {holes} with a hole difference ({two_holes} with two), "
          f"max abs difference {worst_abs:.3e}, max relative {worst_rel:.3e}")


if __name__ == "__main__":
    main()
