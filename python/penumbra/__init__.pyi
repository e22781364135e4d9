from typing import Any, Optional, Tuple

import numpy as np
import numpy.typing as npt

Vec3 = Tuple[float, float, float]

class Camera:
    """A camera: eye, target, up (world units) and the vertical field of view (degrees)."""

    eye: Vec3
    target: Vec3
    up: Vec3
    fov_deg: float
    def __init__(
        self, eye: Vec3, target: Vec3, up: Vec3 = (0.0, 1.0, 0.0), fov_deg: float = 45.0
    ) -> None: ...

class Scene:
    """A scene loaded once; renders leave it as it is."""

    @property
    def objects(self) -> list[str]:
        """The names of the scene's objects, in file order."""
    camera: Optional[Camera]
    def move(
        self,
        name: str,
        translate: Vec3 = (0.0, 0.0, 0.0),
        rotate_y: float = 0.0,
        pivot: Optional[Vec3] = None,
    ) -> None:
        """Moves one object rigidly, as `penumbra edit` does (rotation about +y, then translation)."""
    def render(
        self,
        method: str = "analytic",
        size: Tuple[int, int] = (320, 240),
        aa: int = 1,
        spp: Optional[int] = None,
        seed: int = 1,
        env: Optional[str] = None,
        derivative: Optional[Tuple[str, str]] = None,
        mask: bool = False,
    ) -> Any:
        """A float32 (h, w, 3) image, equal bit for bit to `penumbra render`'s PFM.

        With `derivative=(object, axis)` (axis tx, ty, tz or ry; `method="analytic"`):
        `(image, derivative)` as float64 (h, w, 3) arrays, the derivative exact, per scene unit
        or per radian (docs/derivatives.md); `mask=True` adds a float64 (h, w) array, 1 where
        a pixel is masked.

        The interpreter is released while it renders; Ctrl-C stops it (KeyboardInterrupt).
        """

    def probe(
        self,
        x: float,
        y: float,
        method: str = "analytic",
        size: Tuple[int, int] = (320, 240),
        spp: Optional[int] = None,
        seed: int = 1,
        env: Optional[str] = None,
    ) -> Recording:
        """The recording of the shading point at pixel (x, y), equal to `penumbra probe --gh-steps`'s dump."""

class Figure:
    """A figure: shown inline by notebooks (SVG), written as SVG, PDF or PNG."""

    @property
    def size(self) -> Tuple[int, int]: ...
    def svg(self) -> str: ...
    def _repr_svg_(self) -> str: ...
    def save(self, path: str) -> None:
        """Writes the figure as SVG, PDF or PNG, by the path's extension."""

class Recording:
    """The recording of one shading point."""

    @property
    def stages(self) -> list[str]:
        """The stages as the workbench's stepper labels them (stage N is stages[N - 1])."""
    def polygons(self, stage: int) -> list[npt.NDArray[np.float64]]:
        """The polygon stage N produces: one (n, 3) array per loop (unit directions in the
        shading frame; homogeneous plane points for a set difference)."""
    @property
    def radiance(self) -> Vec3: ...
    def to_json(self) -> str:
        """The debug dump, as `penumbra probe` writes it."""
    def figure(
        self,
        view: str = "sphere",
        stage: Optional[int] = None,
        style: str = "print",
        size: int = 800,
        difference: int = 0,
        fit: bool = False,
        light: Optional[str] = None,
    ) -> Figure:
        """A view (sphere, hemisphere, plane, light, bsp, environment) at the stepper's
        stage N; `light` names the light of the light and bsp views."""

def load_scene(name_or_path: str) -> Scene:
    """An embedded scene by name, or an OBJ, glTF or TOML scene file."""

def scenes() -> list[str]:
    """The names of the embedded scenes."""

def compare(
    image: npt.NDArray[np.float32],
    reference: npt.NDArray[np.float32],
    stderr: Optional[npt.NDArray[np.float32]] = None,
) -> dict:
    """The error metrics of `penumbra compare`."""

def stress(cases: int = 1000, seed: int = 1, rays: int = 256) -> dict:
    """`penumbra stress`'s report: random and adversarial cases against a ray-cast oracle."""

def bench(scene: Scene, **options: Any) -> list[dict]:
    """`penumbra bench`'s rows (method, spp, seconds, mae, rmse, relative_rmse, rmse_corrected,
    violations, fallbacks, peak_mb):
    those of `bench_report(scene, **options)`, which takes the same options."""

def bench_report(
    scene: Scene,
    size: Tuple[int, int] = (160, 120),
    ladder: list[int] = [1, 2, 4, 8, 16, 32, 64, 128, 256],
    methods: Optional[list[str]] = None,
    reference_spp: int = 4096,
    seed: int = 1,
    repeats: int = 2,
    aa: int = 1,
) -> dict:
    """`penumbra bench`'s whole report (its bench.json): scene, width, height, reference,
    rows, equal_time, speed_ratios."""

def bench_chart(report: dict, width: int = 900, height: int = 600) -> Figure:
    """The run time against RMSE chart of a `bench_report`, as `penumbra bench` draws it."""
