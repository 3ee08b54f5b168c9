"""pathlight: a physically based, progressive path tracer, rendering into NumPy arrays.

    import pathlight
    scene = pathlight.load("scenes/refs/cornell-spheres.toml")
    image = pathlight.render(scene, spp=64)   # float32, (height, width, 3), linear RGB

Scenes come from scene files (``.toml``), glTF files (``.gltf``, ``.glb``) or dicts with the
scene file's keys (``pathlight.load({...})``); ``pathlight.default_scene()`` is the built-in
one. A :class:`Renderer` renders progressively (``step``, ``image``), changes the camera and
materials between images, and saves and resumes state files that ``merge`` sums exactly, as
the ``pathlight`` program's do.
"""

from __future__ import annotations

import os as _os
from typing import Optional as _Optional
from typing import Union as _Union

import numpy as _np
import numpy.typing as _npt

from ._pathlight import (
    RenderError,
    Renderer,
    Scene,
    SceneError,
    __version__,
    default_scene,
    load,
    merge,
    read_exr,
    render,
)
from ._pathlight import denoise as _denoise
from ._pathlight import write_image as _write_image

__all__ = [
    "RenderError",
    "Renderer",
    "Scene",
    "SceneError",
    "__version__",
    "default_scene",
    "denoise",
    "load",
    "merge",
    "read_exr",
    "render",
    "write_image",
]


def write_image(path: _Union[str, _os.PathLike], image: _npt.ArrayLike) -> None:
    """Writes ``image`` (any float array of shape (height, width, 3), linear RGB) as the
    extension of ``path`` says, the bytes ``pathlight render`` writes for the same image:
    ``.png`` (8-bit, the sRGB curve, clamped) or ``.exr`` (32-bit float)."""
    _write_image(path, _np.asarray(image, dtype=_np.float32))


def denoise(
    color: _npt.ArrayLike,
    albedo: _Optional[_npt.ArrayLike] = None,
    normal: _Optional[_npt.ArrayLike] = None,
    mode: str = "final",
) -> _npt.NDArray[_np.float32]:
    """``color`` (shape (height, width, 3), linear RGB) denoised by Open Image Denoise,
    guided by ``albedo`` and ``normal`` when given; ``mode``: "final" or "fast"."""

    def as_image(a: _Optional[_npt.ArrayLike]) -> _Optional[_npt.NDArray[_np.float32]]:
        return None if a is None else _np.asarray(a, dtype=_np.float32)

    return _denoise(as_image(color), as_image(albedo), as_image(normal), mode)
