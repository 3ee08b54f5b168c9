#!/usr/bin/env python3
"""Writes crates/core/src/sheen_table.rs: the directional albedo E(cos_o, r) of the
KHR_materials_sheen "Charlie" BRDF with a white sheen colour, on a 32 x 32 grid, which
the metal-rough model's albedo scaling reads (crates/cpu/src/sheen.rs, sheen.wgsl).

The BRDF is the one both kernels evaluate: perceptual roughness r clamped to [0.07, 1],
alpha = r^2, D(h) = (2 + 1/alpha) sin(theta_h)^(1/alpha) / (2 pi), and the visibility
1 / ((1 + Lambda(cos_o) + Lambda(cos_i)) 4 cos_o cos_i) with Conty and Kulla's fitted
Lambda. Row i is r = i / 31, column j is cos_o = max((j / 31)^2, 1e-4) (denser near
grazing, where E changes fastest). Each entry is a
midpoint sum over 768 x 768 directions of the hemisphere, cos_i warped as s^2 to put
more of them near grazing, where the lobe lives; crates/core/src/sheen.rs's test
recomputes entries another way.

Usage: bench/.venv/bin/python tools/sheen_table.py   (needs numpy)
"""
import os

import numpy as np

N = 32
ROUGHNESS_MIN = 0.07
OUT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "crates", "core", "src", "sheen_table.rs")


def lambda_sheen(cos, alpha):
    t = (1.0 - alpha) ** 2

    def l(x):
        a = 21.5473 + (25.3245 - 21.5473) * t
        b = 3.82987 + (3.32435 - 3.82987) * t
        c = 0.19823 + (0.16801 - 0.19823) * t
        d = -1.97760 + (-1.27393 + 1.97760) * t
        e = -4.32054 + (-4.85967 + 4.32054) * t
        return a / (1.0 + b * np.power(x, c)) + d * x + e

    return np.where(cos < 0.5, np.exp(l(cos)), np.exp(2.0 * l(0.5) - l(1.0 - cos)))


def albedo(r, cos_o, n=768):
    alpha = max(r, ROUGHNESS_MIN) ** 2
    s = (np.arange(n) + 0.5) / n
    cos_i = s * s
    phi = (np.arange(n) + 0.5) / n * 2.0 * np.pi
    ci, ph = np.meshgrid(cos_i, phi, indexing="ij")
    si = np.sqrt(1.0 - ci * ci)
    wi = np.stack([si * np.cos(ph), si * np.sin(ph), ci], axis=-1)
    so = np.sqrt(1.0 - cos_o * cos_o)
    wo = np.array([so, 0.0, cos_o])
    h = wi + wo
    h /= np.linalg.norm(h, axis=-1, keepdims=True)
    sin2 = np.maximum(1.0 - h[..., 2] ** 2, 0.0)
    d = (2.0 + 1.0 / alpha) * np.power(sin2, 0.5 / alpha) / (2.0 * np.pi)
    f_cos = d / ((1.0 + lambda_sheen(cos_o, alpha) + lambda_sheen(ci, alpha)) * 4.0 * cos_o)
    # d(omega) = d(cos_i) d(phi), d(cos_i) = 2 s ds.
    weight = 2.0 * s[:, None] / n * (2.0 * np.pi / n)
    return float(np.sum(f_cos * weight))


def main():
    rows = []
    for i in range(N):
        r = i / (N - 1)
        rows.append([albedo(r, max((j / (N - 1)) ** 2, 1e-4)) for j in range(N)])
    with open(OUT, "w") as f:
        f.write("//! The sheen albedo table, written by `tools/sheen_table.py` (which states how).\n")
        f.write("//! Generated: edit the script, not this file.\n\n")
        f.write("/// Rows and columns of [`SHEEN_ALBEDO`].\n")
        f.write(f"pub const SHEEN_TABLE_SIZE: usize = {N};\n\n")
        f.write("/// The directional albedo of the white Charlie sheen BRDF: row `i` at perceptual\n")
        f.write("/// roughness `i / 31`, column `j` at `cos_o = (j / 31)^2` (at least 1e-4).\n")
        f.write("#[rustfmt::skip]\n")
        f.write(f"pub const SHEEN_ALBEDO: [f32; {N * N}] = [\n")
        for row in rows:
            f.write("    " + ", ".join(f"{v:.7}" for v in row) + ",\n")
        f.write("];\n")


if __name__ == "__main__":
    main()
