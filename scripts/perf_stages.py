#!/usr/bin/env python3
"""Where a camera sample's time goes, by stage of the analytic pipeline (docs/speed.md).

    scripts/perf_stages.py BINARY SCENE [--size 256x256] [--aa 4] [--freq 2000]

Records `BINARY render SCENE` under `perf record --call-graph dwarf` and gives every sample
to the first stage, in the order of STAGES, with a frame anywhere on its call stack (inlined
frames included): libm's atan2 under the LTC integral counts as the LTC integral, and the LTC
integral under the invariant's check as the invariant. Prints each
stage's share and its CPU time per camera sample in ns (samples / frequency / camera samples).
Needs Linux `perf` (Debian: linux-perf) and a binary with debug information (the release
profile keeps it)."""
import argparse, collections, os, re, subprocess, sys, tempfile

STAGES = [
    ("invariant check", r"shading::invariant::"),
    ("set difference", r"set_difference::|hole_difference::|geometry::spherical::overlap::|ProjectionPlane::(re)?project|subtract_planar|settle_hole|sampled_region"),
    ("horizon clip", r"horizon::clip_to_horizon"),
    ("tree lookup", r"SilhouetteBsp::lookup|bsp_hoisted::|bsp_nonconvex::|silhouette_tree::"),
    ("silhouette", r"geometry::silhouette|spherical_polygon\b|shading::outline::|windowed_silhouette|exact_silhouette|contour_pieces|quantitative_invisibility|edge_hierarchy|tile_candidates|near_convex|silhouette_walk"),
    ("GetBetween", r"get_between"),
    ("LTC integral", r"integrate_lobes|edge_integral|form_factor|ltc::"),
    ("camera ray and BVH", r"accel::bvh|Bvh::|camera::|ray_triangle|primary_hit|TileHits"),
    ("image accumulation and output", r"raster::|image_io|miniz|exr::|Image::|png::|write_"),
    ("shading (frame, lights, occluder loop)", r"shading::"),
    ("tiles and threads", r"render::|rayon"),
]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("binary")
    ap.add_argument("scene")
    ap.add_argument("--size", default="256x256")
    ap.add_argument("--aa", type=int, default=4)
    ap.add_argument("--freq", type=int, default=2000)
    a = ap.parse_args()
    w, h = map(int, a.size.split("x"))
    camera_samples = w * h * a.aa * a.aa
    with tempfile.TemporaryDirectory() as tmp:
        data = os.path.join(tmp, "perf.data")
        subprocess.run(
            ["perf", "record", "-q", "-o", data, "--call-graph", "dwarf,16384", "-F",
             str(a.freq), a.binary, "render", a.scene, "--size", a.size, "--aa", str(a.aa),
             "--out", os.path.join(tmp, "image.pfm")],
            check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        script = subprocess.run(["perf", "script", "-i", data], check=True,
                                capture_output=True, text=True).stdout
    pats = [(n, re.compile(p)) for n, p in STAGES]
    counts, total, stack = collections.Counter(), 0, []

    def flush():
        nonlocal total
        if not stack:
            return
        total += 1
        for n, p in pats:
            if any(p.search(frame) for frame in stack):
                counts[n] += 1
                return
        counts["other (start-up, loading, kernel)"] += 1

    for line in script.splitlines():
        if not line.strip():
            flush()
            stack = []
        elif line[0] in " \t":
            parts = line.strip().split(None, 1)
            if len(parts) == 2:
                stack.append(parts[1])
        else:
            flush()
            stack = []
    flush()
    print(f"{a.scene}: {a.size} --aa {a.aa}, {camera_samples} camera samples, "
          f"{total} perf samples at {a.freq} Hz")
    print(f"| stage | share | ns per camera sample |")
    print(f"|---|---|---|")
    for n, _ in STAGES + [("other (start-up, loading, kernel)", None)]:
        c = counts.get(n, 0)
        ns = c / a.freq * 1e9 / camera_samples
        print(f"| {n} | {100 * c / max(total, 1):.1f} % | {ns:.0f} |")
    print(f"| total | 100 % | {total / a.freq * 1e9 / camera_samples:.0f} |")


if __name__ == "__main__":
    sys.exit(main())
