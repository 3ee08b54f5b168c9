#!/usr/bin/env python3
"""Mitsuba 3's own relMSE against the stored references, at a given size and spp.

The bar pathlight's tests hold themselves to ("at most 1.2x what Mitsuba itself gets") comes
from this script. It uses the reference toolkit's scene conversion (`mitsuba_scenes.py`,
in the directory given) so Mitsuba renders exactly the reference scene, renders it with
several seeds, and prints one JSON line per scene with the relMSE of each seed and their
mean, where relMSE = mean over pixels and channels of (test - ref)^2 / (ref^2 + 0.01), and
ref is the stored 256x256 reference box-downsampled to the test size.

Usage:
  pip install mitsuba numpy; apt-get install libllvm19
  python tools/mitsuba_relmse.py REFS_DIR NAME... [--res 128] [--spp 64] [--seeds 4]
REFS_DIR is the directory holding mitsuba_scenes.py and scenes/ (the team's shared/refs).
"""
import argparse
import json
import os
import sys

import numpy as np


def downsample(image, size):
    factor = image.shape[0] // size
    return image.reshape(size, factor, size, factor, 3).mean(axis=(1, 3))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("refs_dir")
    ap.add_argument("names", nargs="+")
    ap.add_argument("--res", type=int, default=128)
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--seeds", type=int, default=4)
    ap.add_argument("--variant", default="llvm_ad_rgb")
    ap.add_argument("--images", default=os.path.join(os.path.dirname(__file__), "..", "scenes", "refs", "images"))
    a = ap.parse_args()
    sys.path.insert(0, os.path.abspath(a.refs_dir))
    import mitsuba_scenes as ms

    mi = ms._set_variant(a.variant)
    for name in a.names:
        ref = np.asarray(mi.Bitmap(os.path.join(a.images, name + ".exr")), np.float64)[..., :3]
        ref = downsample(ref, a.res)
        scene = mi.load_dict(ms.to_mitsuba(ms.load_json(name), a.res, a.spp))
        values = []
        for seed in range(a.seeds):
            img = np.asarray(mi.render(scene, spp=a.spp, seed=seed), np.float64)[..., :3]
            values.append(float(np.mean((img - ref) ** 2 / (ref ** 2 + 0.01))))
        print(json.dumps({"scene": name, "variant": a.variant, "res": a.res, "spp": a.spp,
                          "relmse": [round(v, 6) for v in values],
                          "mean_relmse": round(float(np.mean(values)), 6)}), flush=True)


if __name__ == "__main__":
    main()
