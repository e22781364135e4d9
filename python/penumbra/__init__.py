"""penumbra: analytic soft shadows from polyhedral area lights, from Python.

Scenes load from an embedded name or a file, render to numpy arrays equal bit for bit to
``penumbra render``'s PFM, and compare as ``penumbra compare`` does.
"""

from ._penumbra import (
    Camera,
    Figure,
    Recording,
    Scene,
    bench,
    bench_chart,
    bench_report,
    compare,
    load_scene,
    scenes,
    stress,
)

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
