"""Type stubs of pathlight's extension module (re-exported by ``pathlight``)."""

import os
from typing import Any, Mapping, Optional, Sequence, TypedDict, Union

from typing_extensions import Unpack

import numpy as np
import numpy.typing as npt

__version__: str

Image = npt.NDArray[np.float32]
"""A float32 array of shape (height, width, 3): linear RGB, row 0 at the top."""

PathLike = Union[str, "os.PathLike[str]"]

class SceneError(ValueError):
    """A scene that cannot be loaded or a value it refuses; the message names the file,
    line or key, as the ``pathlight`` program's does."""

class RenderError(RuntimeError):
    """Rendering failed: no device, a state file that does not fit, no denoiser."""

class Camera(TypedDict):
    position: list[float]
    look_at: list[float]
    up: list[float]
    fov_y: float
    width: int
    height: int
    aperture_radius: float
    focus_distance: float

class CameraKeys(TypedDict, total=False):
    """What ``set_camera`` changes (``None``: unchanged)."""

    position: Optional[Sequence[float]]
    look_at: Optional[Sequence[float]]
    up: Optional[Sequence[float]]
    fov_y: Optional[float]
    width: Optional[int]
    height: Optional[int]
    aperture_radius: Optional[float]
    focus_distance: Optional[float]

class Scene:
    """A scene from a scene file, a glTF file or Python data (``load``). Its camera and (for
    a scene file's or data's scene) its materials change between renders; its geometry is
    prepared (the BVH built) once, on its first render."""

    @property
    def camera(self) -> Camera:
        """The camera (a copy: change it with ``set_camera``)."""
    def set_camera(self, **keys: Unpack[CameraKeys]) -> None:
        """Moves, turns or resizes the camera; keys left out keep their values. A focus
        distance that was the distance to ``look_at`` follows a moved camera or target.
        Raises ValueError for a camera the scene file would refuse."""
    def set_environment(
        self,
        *,
        map: Optional[PathLike] = None,
        radiance: Optional[Sequence[float]] = None,
        strength: Optional[float] = None,
        rotation: Optional[float] = None,
    ) -> None:
        """Changes the light from far away: an HDR ``map`` (``.hdr`` or ``.exr``; strength 1
        and no turn unless given), a constant ``radiance`` (linear RGB; zero: none), or the
        current map's ``strength`` and ``rotation`` (degrees about +y) alone, as the scene
        file's ``[environment]`` and ``pathlight render --env`` give them."""
    @property
    def materials(self) -> list[str]:
        """The materials' names, in the scene's order."""
    def set_material(self, name: str, **keys: Any) -> None:
        """Changes the keys of material ``name`` as the scene file's ``[materials.NAME]``
        has them (``None`` removes a key), checked as the scene file's are. Raises KeyError
        for an unknown name, SceneError for a refused value (the scene unchanged), and
        SceneError for a glTF file's scene, whose materials do not change."""
    @property
    def spp(self) -> int:
        """Samples per pixel the scene asks for (``[render] spp``)."""

class Renderer:
    """A progressive render of a copy of ``scene``: ``step`` adds samples (the GIL released;
    Ctrl-C raises KeyboardInterrupt within a fraction of a second, the samples so far kept),
    ``image`` returns the mean so far. Arguments left out take the scene's values."""

    def __init__(
        self,
        scene: Scene,
        *,
        backend: str = "auto",
        seed: Optional[int] = None,
        width: Optional[int] = None,
        height: Optional[int] = None,
        max_depth: Optional[int] = None,
        aovs: bool = False,
        first_sample: int = 0,
    ) -> None:
        """``backend``: "auto" (a hardware GPU when there is one, else the CPU backend),
        "gpu" or "cpu". ``aovs``: accumulate the albedo and normal images too.
        ``first_sample``: start at that sample index (one shard of a render of several,
        merged with ``merge``)."""
    def step(self, spp: int = 1) -> int:
        """Adds ``spp`` samples to every pixel; returns the samples per pixel held."""
    def image(self) -> Image:
        """The image so far."""
    def albedo(self) -> Image:
        """The albedo image so far (a renderer made with ``aovs=True``)."""
    def normal(self) -> Image:
        """The shading normal image so far, components in [-1, 1] (``aovs=True``)."""
    @property
    def samples(self) -> int:
        """Samples per pixel held."""
    @property
    def backend_name(self) -> str:
        """"cpu" or "gpu"."""
    @property
    def device(self) -> str:
        """Where it renders, in words."""
    @property
    def camera(self) -> Camera:
        """The renderer's camera."""
    def set_camera(self, **keys: Unpack[CameraKeys]) -> None:
        """As ``Scene.set_camera``, and the image starts again."""
    def set_material(self, name: str, **keys: Any) -> None:
        """As ``Scene.set_material``, and the image starts again."""
    def restart(self) -> None:
        """Empties the image: the next sample is the first again."""
    def save_state(self, path: PathLike) -> None:
        """Writes the render's exact sums to a state file (as ``pathlight render -o
        x.state`` does), replacing a file there only once all of it is written."""
    def resume(self, path: PathLike) -> None:
        """Replaces the image with a state file's (of the same scene, camera and settings,
        from Python or the ``pathlight`` program) to go on from it; RenderError otherwise."""

def load(
    source: Union[PathLike, Mapping[str, Any]],
    base_dir: Optional[PathLike] = None,
    camera: Optional[int] = None,
) -> Scene:
    """A scene file (``.toml``), a glTF file (``.gltf``, ``.glb``: ``camera`` chooses one of
    its cameras; without lights of its own it gets a grey sky, as ``pathlight render``
    gives it), or a dict with the scene file's keys (relative asset paths from ``base_dir``,
    the working folder by default)."""

def default_scene() -> Scene:
    """The built-in default scene."""

def render(
    scene: Scene,
    spp: Optional[int] = None,
    seed: Optional[int] = None,
    width: Optional[int] = None,
    height: Optional[int] = None,
    backend: str = "auto",
    max_depth: Optional[int] = None,
) -> Image:
    """Renders ``scene`` (arguments left out take the scene's values) and returns the
    image. The same scene, settings and backend give the same image, bit for bit, as
    ``pathlight render`` writes to an EXR file."""

def merge(paths: Sequence[PathLike], output: Optional[PathLike] = None) -> Image:
    """Sums state files (shards of one render, a render and its resumption) exactly and
    returns their image; with ``output``, writes the merged state there too."""

def read_exr(path: PathLike) -> Image:
    """An OpenEXR image, as ``pathlight render -o image.exr`` writes it."""

def write_image(path: PathLike, image: Image) -> None:
    """Writes ``image`` as its extension says, the bytes ``pathlight render`` writes for
    the same image: ``.png`` (8-bit, the sRGB curve, clamped) or ``.exr`` (32-bit float).
    A file there is replaced only once the new one is whole."""

def denoise(
    color: Image,
    albedo: Optional[Image] = None,
    normal: Optional[Image] = None,
    mode: str = "final",
) -> Image:
    """``color`` denoised by Open Image Denoise (``tools/get-oidn.sh`` installs it, or
    ``PATHLIGHT_OIDN`` names its folder), guided by ``albedo`` and ``normal`` when given;
    ``mode``: "final" or "fast"."""
