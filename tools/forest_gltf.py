#!/usr/bin/env python3
"""Writes a GLB that places one bumpy sphere (2 x segments x rings triangles) on a square
grid of `--placements` nodes, each turned and scaled at random, seen by a camera from a
corner of the field: the instancing benchmark (BENCHMARKS.md, "Instancing"). With --placements 1 it is one mesh of that size; the
default, 10,000 placements of a 10,000-triangle sphere, shows 100M triangles. --ply also
writes the sphere alone as a binary PLY, for Mitsuba 3 (bench/first-frame.sh).

    python3 tools/forest_gltf.py out.glb [--placements 10000] [--segments 100] [--rings 50]
                                 [--ply sphere.ply]
"""

import argparse
import json
import math
import random
import struct

import numpy as np


def bumpy_sphere(segments, rings):
    """Positions, normals and triangle indices of a unit sphere with bumps."""
    theta = np.linspace(0.0, math.pi, rings + 1)
    phi = np.linspace(0.0, 2.0 * math.pi, segments + 1)
    t, p = np.meshgrid(theta, phi, indexing="ij")
    r = 1.0 + 0.08 * np.sin(7.0 * t) * np.sin(9.0 * p)
    positions = np.stack(
        [r * np.sin(t) * np.cos(p), r * np.cos(t), r * np.sin(t) * np.sin(p)], axis=-1
    ).reshape(-1, 3)
    row = segments + 1
    i, j = np.meshgrid(np.arange(rings), np.arange(segments), indexing="ij")
    first = (i * row + j).reshape(-1).astype(np.uint32)
    quads = np.stack([first, first + 1, first + row, first + row + 1], axis=1)
    # Counter-clockwise seen from outside.
    indices = np.concatenate(
        [quads[:, [0, 1, 2]], quads[:, [1, 3, 2]]], axis=1
    ).reshape(-1, 3)
    # Vertex normals: the area-weighted face normals around each vertex (the seam's copies
    # of a vertex get the same sum, so shading shows no seam).
    corners = positions[indices]
    faces = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    keys = np.round(positions, 6)
    _, shared, = np.unique(keys, axis=0, return_inverse=True)
    shared = shared.reshape(-1)
    sums = np.zeros((shared.max() + 1, 3))
    for k in range(3):
        np.add.at(sums, shared[indices[:, k]], faces)
    normals = sums[shared]
    normals /= np.maximum(np.linalg.norm(normals, axis=1, keepdims=True), 1e-12)
    return positions.astype(np.float32), normals.astype(np.float32), indices


def write_ply(path, positions, normals, indices):
    """`positions`, `normals` and `indices` as a binary little-endian PLY."""
    vertices = np.concatenate([positions, normals], axis=1).astype("<f4")
    faces = np.zeros(len(indices), dtype=[("n", "u1"), ("v", "<u4", (3,))])
    faces["n"] = 3
    faces["v"] = indices
    header = (
        "ply\nformat binary_little_endian 1.0\n"
        f"element vertex {len(vertices)}\n"
        "property float x\nproperty float y\nproperty float z\n"
        "property float nx\nproperty float ny\nproperty float nz\n"
        f"element face {len(faces)}\n"
        "property list uchar uint vertex_indices\nend_header\n"
    )
    with open(path, "wb") as out:
        out.write(header.encode())
        out.write(vertices.tobytes())
        out.write(faces.tobytes())


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("output")
    parser.add_argument("--placements", type=int, default=10_000)
    parser.add_argument("--segments", type=int, default=100)
    parser.add_argument("--rings", type=int, default=50)
    parser.add_argument("--ply", help="also write the sphere alone to this PLY file")
    args = parser.parse_args()
    positions, normals, indices = bumpy_sphere(args.segments, args.rings)
    if args.ply:
        write_ply(args.ply, positions, normals, indices)
    blobs = [positions.tobytes(), normals.tobytes(), indices.astype(np.uint32).tobytes()]
    views, offset = [], 0
    for blob in blobs:
        views.append({"buffer": 0, "byteOffset": offset, "byteLength": len(blob)})
        offset += (len(blob) + 3) // 4 * 4
    binary = b"".join(blob + b"\0" * ((4 - len(blob) % 4) % 4) for blob in blobs)
    side = math.ceil(math.sqrt(args.placements))
    rng = random.Random(1)
    nodes = []
    for k in range(args.placements):
        axis = [rng.uniform(-1, 1) for _ in range(3)]
        norm = math.sqrt(sum(a * a for a in axis)) or 1.0
        angle = rng.uniform(0, 2 * math.pi)
        s = math.sin(angle / 2) / norm
        node = {"mesh": 0}
        if args.placements > 1:
            node["translation"] = [2.5 * (k % side - side / 2), 0.0, 2.5 * (k // side - side / 2)]
            node["rotation"] = [axis[0] * s, axis[1] * s, axis[2] * s, math.cos(angle / 2)]
            node["scale"] = [rng.uniform(0.6, 1.0)] * 3
        nodes.append(node)
    cameras = []
    if args.placements > 1:
        # From a corner of the field, 3 units up, looking across it at its middle.
        half = 2.5 * side / 2
        eye = [-half - 2.0, 3.0, -half - 2.0]
        d = [-e for e in eye]
        length = math.sqrt(sum(c * c for c in d))
        d = [c / length for c in d]
        yaw, pitch = math.atan2(-d[0], -d[2]), math.asin(d[1])
        qy = [0.0, math.sin(yaw / 2), 0.0, math.cos(yaw / 2)]
        qx = [math.sin(pitch / 2), 0.0, 0.0, math.cos(pitch / 2)]
        rotation = [  # qy * qx
            qy[3] * qx[0] + qy[0] * qx[3] + qy[1] * qx[2] - qy[2] * qx[1],
            qy[3] * qx[1] - qy[0] * qx[2] + qy[1] * qx[3] + qy[2] * qx[0],
            qy[3] * qx[2] + qy[0] * qx[1] - qy[1] * qx[0] + qy[2] * qx[3],
            qy[3] * qx[3] - qy[0] * qx[0] - qy[1] * qx[1] - qy[2] * qx[2],
        ]
        nodes.append({"camera": 0, "translation": eye, "rotation": rotation})
        cameras = [{"type": "perspective",
                    "perspective": {"yfov": 0.7, "znear": 0.1, "aspectRatio": 1.0}}]
    document = {
        "asset": {"version": "2.0", "generator": "pathlight tools/forest_gltf.py"},
        "scene": 0,
        "scenes": [{"nodes": list(range(len(nodes)))}],
        "nodes": nodes,
        **({"cameras": cameras} if cameras else {}),
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1}, "indices": 2}]}],
        "buffers": [{"byteLength": len(binary)}],
        "bufferViews": views,
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": len(positions), "type": "VEC3",
             "min": positions.min(axis=0).tolist(), "max": positions.max(axis=0).tolist()},
            {"bufferView": 1, "componentType": 5126, "count": len(normals), "type": "VEC3"},
            {"bufferView": 2, "componentType": 5125, "count": indices.size, "type": "SCALAR"},
        ],
    }
    text = json.dumps(document, separators=(",", ":")).encode()
    text += b" " * ((4 - len(text) % 4) % 4)
    with open(args.output, "wb") as out:
        out.write(struct.pack("<III", 0x46546C67, 2, 12 + 8 + len(text) + 8 + len(binary)))
        out.write(struct.pack("<II", len(text), 0x4E4F534A) + text)
        out.write(struct.pack("<II", len(binary), 0x004E4942) + binary)
    print(f"{args.output}: {len(indices)} triangles placed {args.placements} times")


if __name__ == "__main__":
    main()
