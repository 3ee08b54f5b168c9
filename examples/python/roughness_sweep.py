"""Sweeps the roughness of the gold sphere of a reference scene and writes the images side by
side: one Renderer, the scene prepared (its BVH built) once, a material changed between
images.

    pip install ./python
    python examples/python/roughness_sweep.py [--spp 64] [--size 192] [-o sweep.png]
"""

import argparse
import time
from pathlib import Path

import numpy as np

import pathlight

SCENE = Path(__file__).resolve().parents[2] / "scenes" / "refs" / "cornell-materials.toml"


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--spp", type=int, default=64, help="samples per pixel per image")
    parser.add_argument("--size", type=int, default=192, help="width and height of each image")
    parser.add_argument("--roughness", type=float, nargs="+", default=[0.05, 0.2, 0.4, 0.7, 1.0])
    parser.add_argument("--backend", default="auto", choices=["auto", "gpu", "cpu"])
    parser.add_argument("-o", "--output", default="sweep.png", help=".png or .exr")
    args = parser.parse_args()

    scene = pathlight.load(SCENE)
    renderer = pathlight.Renderer(scene, backend=args.backend, width=args.size,
                                  height=args.size)
    print(f"rendering on {renderer.device}")
    images = []
    for roughness in args.roughness:
        started = time.perf_counter()
        renderer.set_material("rough_gold", specular_roughness=roughness)
        renderer.step(args.spp)
        images.append(renderer.image())
        print(f"roughness {roughness}: {time.perf_counter() - started:.2f} s")
    pathlight.write_image(args.output, np.concatenate(images, axis=1))
    print(f"wrote {args.output}")


if __name__ == "__main__":
    main()
