from typing import Optional, Tuple

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
    def render(
        self,
        method: str = "analytic",
        size: Tuple[int, int] = (320, 240),
        aa: int = 1,
        spp: Optional[int] = None,
        seed: int = 1,
        env: Optional[str] = None,
    ) -> npt.NDArray[np.float32]:
        """A float32 (h, w, 3) image, equal bit for bit to `penumbra render`'s PFM."""

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
