#!/usr/bin/env python3
"""Writes examples/lights/stage.gltf: a small stage (floor, back wall, a gold sphere, a white
sphere, a red box, a blue ball) lit only by KHR_lights_punctual lights (a warm spot, a cool
point light and a dim sun), with a camera. Self-contained: the buffer is a data: URI.

Usage: python3 tools/stage_gltf.py   (no dependencies beyond the standard library)
"""
import base64
import json
import math
import os
import struct

OUT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "examples", "lights", "stage.gltf")


def normalize(v):
    n = math.sqrt(sum(c * c for c in v))
    return [c / n for c in v]


def look_rotation(direction):
    """The quaternion (x, y, z, w) turning -z to unit `direction` (the shortest arc)."""
    d = normalize(direction)
    a = [0.0, 0.0, -1.0]
    axis = [a[1] * d[2] - a[2] * d[1], a[2] * d[0] - a[0] * d[2], a[0] * d[1] - a[1] * d[0]]
    w = 1.0 + sum(x * y for x, y in zip(a, d))
    return normalize(axis + [w])


def uv_sphere(radius, segments=48, rings=24):
    positions, normals, indices = [], [], []
    for i in range(rings + 1):
        theta = math.pi * i / rings
        for j in range(segments + 1):
            phi = 2 * math.pi * j / segments
            n = [math.sin(theta) * math.cos(phi), math.cos(theta), math.sin(theta) * math.sin(phi)]
            normals.append(n)
            positions.append([radius * c for c in n])
    for i in range(rings):
        for j in range(segments):
            a, b = i * (segments + 1) + j, (i + 1) * (segments + 1) + j
            # At the poles one of the two triangles has no area.
            if i > 0:
                indices += [a, a + 1, b]
            if i < rings - 1:
                indices += [a + 1, b + 1, b]
    return positions, normals, indices


def box(half):
    positions, normals, indices = [], [], []
    for axis in range(3):
        for sign in (1, -1):
            n = [0.0, 0.0, 0.0]
            n[axis] = float(sign)
            u, v = [(axis + 1) % 3, (axis + 2) % 3]
            base = len(positions)
            for su, sv in ((-1, -1), (1, -1), (1, 1), (-1, 1)):
                p = [0.0, 0.0, 0.0]
                p[axis], p[u], p[v] = sign * half, su * half, sv * half
                positions.append(p)
                normals.append(n)
            quad = [base, base + 1, base + 2, base, base + 2, base + 3]
            indices += quad if sign > 0 else [quad[0], quad[2], quad[1], quad[3], quad[5], quad[4]]
    return positions, normals, indices


def quad(width, height):
    """A width x height rectangle in the xy plane facing +z, centred on the origin."""
    w, h = width / 2, height / 2
    return [[-w, -h, 0], [w, -h, 0], [w, h, 0], [-w, h, 0]], [[0, 0, 1]] * 4, [0, 1, 2, 0, 2, 3]


def main():
    buffer = bytearray()
    views, accessors, meshes = [], [], []

    def add(data, fmt, target):
        while len(buffer) % 4:
            buffer.append(0)
        start = len(buffer)
        for item in data:
            buffer.extend(struct.pack(fmt, *item) if isinstance(item, list) else struct.pack(fmt, item))
        views.append({"buffer": 0, "byteOffset": start, "byteLength": len(buffer) - start, "target": target})
        return len(views) - 1

    def mesh(name, geometry, material):
        positions, normals, indices = geometry
        lo = [min(p[k] for p in positions) for k in range(3)]
        hi = [max(p[k] for p in positions) for k in range(3)]
        accessors.append({"bufferView": add(positions, "<3f", 34962), "componentType": 5126,
                          "count": len(positions), "type": "VEC3", "min": lo, "max": hi})
        accessors.append({"bufferView": add(normals, "<3f", 34962), "componentType": 5126,
                          "count": len(normals), "type": "VEC3"})
        accessors.append({"bufferView": add(indices, "<I", 34963), "componentType": 5125,
                          "count": len(indices), "type": "SCALAR"})
        n = len(accessors)
        meshes.append({"name": name, "primitives": [{"attributes": {"POSITION": n - 3, "NORMAL": n - 2},
                                                      "indices": n - 1, "material": material}]})
        return len(meshes) - 1

    def material(name, color, metallic, roughness):
        return {"name": name, "pbrMetallicRoughness": {"baseColorFactor": color + [1.0],
                                                       "metallicFactor": metallic, "roughnessFactor": roughness}}

    materials = [material("floor", [0.6, 0.6, 0.6], 0.0, 0.8), material("wall", [0.55, 0.55, 0.6], 0.0, 0.9),
                 material("gold", [1.0, 0.78, 0.34], 1.0, 0.45), material("white", [0.9, 0.9, 0.9], 0.0, 0.5),
                 material("red", [0.7, 0.12, 0.1], 0.0, 0.5), material("blue", [0.15, 0.3, 0.8], 0.0, 0.2)]
    floor = mesh("floor", quad(16, 8), 0)
    wall = mesh("wall", quad(16, 5), 1)
    sphere = mesh("sphere", uv_sphere(0.6), 2)
    white = mesh("white sphere", uv_sphere(0.6), 3)
    cube = mesh("box", box(0.45), 4)
    ball = mesh("ball", uv_sphere(0.3), 5)
    spot_position, spot_target = [-2.6, 3.6, 2.6], [-0.5, 0.2, 0.0]
    camera_position, camera_target = [0.0, 1.9, 6.2], [0.0, 0.65, 0.0]
    half = math.radians(15)
    nodes = [
        {"name": "floor", "mesh": floor, "rotation": [-math.sin(math.pi / 4), 0, 0, math.cos(math.pi / 4)]},
        {"name": "wall", "mesh": wall, "translation": [0, 2.5, -2.5]},
        {"name": "gold sphere", "mesh": sphere, "translation": [-1.25, 0.6, 0.0]},
        {"name": "white sphere", "mesh": white, "translation": [1.35, 0.6, -0.4]},
        {"name": "box", "mesh": cube, "translation": [0.1, 0.45, -1.2],
         "rotation": [0, math.sin(half), 0, math.cos(half)]},
        {"name": "ball", "mesh": ball, "translation": [0.35, 0.3, 0.9]},
        {"name": "key light", "translation": spot_position,
         "rotation": look_rotation([t - p for t, p in zip(spot_target, spot_position)]),
         "extensions": {"KHR_lights_punctual": {"light": 0}}},
        {"name": "fill light", "translation": [2.6, 1.6, 1.8], "extensions": {"KHR_lights_punctual": {"light": 1}}},
        {"name": "sun", "rotation": look_rotation([0.45, -1.0, -0.35]),
         "extensions": {"KHR_lights_punctual": {"light": 2}}},
        {"name": "camera", "translation": camera_position, "camera": 0,
         "rotation": look_rotation([t - p for t, p in zip(camera_target, camera_position)])},
    ]
    doc = {
        "asset": {"version": "2.0", "generator": "pathlight tools/stage_gltf.py"},
        "extensionsUsed": ["KHR_lights_punctual"],
        "extensions": {"KHR_lights_punctual": {"lights": [
            {"name": "key", "type": "spot", "color": [1.0, 0.8, 0.6], "intensity": 40.0,
             "spot": {"innerConeAngle": 0.2, "outerConeAngle": 0.42}},
            {"name": "fill", "type": "point", "color": [0.55, 0.7, 1.0], "intensity": 3.0},
            {"name": "sun", "type": "directional", "color": [1.0, 0.95, 0.85], "intensity": 0.8}]}},
        "scene": 0,
        "scenes": [{"nodes": list(range(len(nodes)))}],
        "nodes": nodes,
        "cameras": [{"type": "perspective", "perspective": {"yfov": 0.62, "aspectRatio": 16 / 9, "znear": 0.1}}],
        "meshes": meshes,
        "materials": materials,
        "buffers": [{"byteLength": len(buffer),
                     "uri": "data:application/octet-stream;base64," + base64.b64encode(bytes(buffer)).decode()}],
        "bufferViews": views,
        "accessors": accessors,
    }
    with open(OUT, "w") as f:
        json.dump(doc, f, indent=1)
        f.write("\n")
    print(OUT)


if __name__ == "__main__":
    main()
