"""penumbra: analytic soft shadows from polyhedral area lights, from Python.

Scenes load from an embedded name or a file, render to numpy arrays equal bit for bit to
``penumbra render``'s PFM, and compare as ``penumbra compare`` does.
"""

from ._penumbra import (
    Camera,
    Figure,
    Recording,
    Scene,
    bench_chart,
    bench_report,
    compare,
    load_scene,
    scenes,
    stress,
)


def bench(scene, **options):
    """`penumbra bench`'s rows as dicts (scene, method, spp, seconds, mae, rmse,
    relative_rmse, rmse_corrected, violations, fallbacks, peak_mb), ready for
    `pandas.DataFrame`: the rows of `bench_report(scene, **options)`, which takes the same
    arguments."""
    return bench_report(scene, **options)["rows"]


__all__ = [
    "Camera",
    "Figure",
    "Recording",
    "Scene",
    "bench",
    "bench_chart",
    "bench_report",
    "compare",
    "load_scene",
    "scenes",
    "stress",
]
