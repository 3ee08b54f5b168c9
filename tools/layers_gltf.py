#!/usr/bin/env python3
"""Writes crates/scene/tests/data/gltf/MaterialLayers/layers.gltf: two quads side by side
facing a camera, with vertex colours (COLOR_0, normalised bytes) and a 2 x 2 texture, in two
materials that use every material extension pathlight reads with its textures: a velvet
(KHR_materials_sheen, colour and roughness textures, one with KHR_texture_transform) and a
coated, tinted, partly transmitting paint (KHR_materials_clearcoat with its textures and normal map,
KHR_materials_specular with its textures, KHR_materials_transmission with its texture,
KHR_materials_volume, KHR_materials_ior). Self-contained: buffer and image are data: URIs.

Usage: python3 tools/layers_gltf.py   (no dependencies beyond the standard library)
"""
import base64
import json
import os
import struct
import zlib

OUT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "crates", "scene", "tests",
                   "data", "gltf", "MaterialLayers", "layers.gltf")


def png(width, height, rgba):
    """A PNG of RGBA8 rows (bytes), no filtering."""
    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))
    raw = b"".join(b"\x00" + rgba[y * width * 4:(y + 1) * width * 4] for y in range(height))
    header = struct.pack(">IIBBBBB", width, height, 8, 6, 0, 0, 0)
    return b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b"")


def quad(x0):
    positions = [(x0, -1, 0), (x0 + 2, -1, 0), (x0 + 2, 1, 0), (x0, 1, 0)]
    normals = [(0, 0, 1)] * 4
    uvs = [(0, 1), (1, 1), (1, 0), (0, 0)]
    colors = [(255, 255, 255, 255), (255, 200, 150, 255), (150, 200, 255, 255), (255, 255, 255, 255)]
    return positions, normals, uvs, colors


def main():
    buffer = b""
    views, accessors, primitives = [], [], []

    def add(data, target=None):
        nonlocal buffer
        while len(buffer) % 4:
            buffer += b"\x00"
        view = {"buffer": 0, "byteOffset": len(buffer), "byteLength": len(data)}
        if target:
            view["target"] = target
        views.append(view)
        buffer += data
        return len(views) - 1

    for material, x0 in [(0, -2.1), (1, 0.1)]:
        positions, normals, uvs, colors = quad(x0)
        attributes = {}
        for name, values, fmt, kind, extra in [
            ("POSITION", positions, "<3f", "VEC3", {}),
            ("NORMAL", normals, "<3f", "VEC3", {}),
            ("TEXCOORD_0", uvs, "<2f", "VEC2", {}),
        ]:
            view = add(b"".join(struct.pack(fmt, *v) for v in values), 34962)
            accessor = {"bufferView": view, "componentType": 5126, "count": 4, "type": kind}
            if name == "POSITION":
                accessor["min"] = [min(p[i] for p in positions) for i in range(3)]
                accessor["max"] = [max(p[i] for p in positions) for i in range(3)]
            accessors.append(accessor)
            attributes[name] = len(accessors) - 1
        view = add(b"".join(struct.pack("<4B", *c) for c in colors), 34962)
        accessors.append({"bufferView": view, "componentType": 5121, "normalized": True, "count": 4,
                          "type": "VEC4"})
        attributes["COLOR_0"] = len(accessors) - 1
        view = add(struct.pack("<6H", 0, 1, 2, 0, 2, 3), 34963)
        accessors.append({"bufferView": view, "componentType": 5123, "count": 6, "type": "SCALAR"})
        primitives.append({"attributes": attributes, "indices": len(accessors) - 1, "material": material})

    image = png(2, 2, bytes([255, 255, 255, 255, 200, 120, 60, 90, 120, 200, 90, 160, 60, 60, 200, 220]))
    texture = {"index": 0}
    moved = {"index": 0, "extensions": {"KHR_texture_transform": {"offset": [0.5, 0], "scale": [2, 2]}}}
    gltf = {
        "asset": {"version": "2.0", "generator": "tools/layers_gltf.py (pathlight's tests)"},
        "extensionsUsed": ["KHR_materials_sheen", "KHR_materials_clearcoat", "KHR_materials_specular",
                           "KHR_materials_transmission", "KHR_materials_volume", "KHR_materials_ior",
                           "KHR_texture_transform"],
        "scene": 0,
        "scenes": [{"nodes": [0, 1]}],
        "nodes": [{"mesh": 0}, {"camera": 0, "translation": [0, 0, 4.5]}],
        "cameras": [{"type": "perspective", "perspective": {"yfov": 0.7, "aspectRatio": 2.0, "znear": 0.1}}],
        "meshes": [{"primitives": primitives}],
        "materials": [
            {"name": "velvet",
             "pbrMetallicRoughness": {"baseColorFactor": [0.3, 0.05, 0.1, 1], "metallicFactor": 0,
                                      "roughnessFactor": 0.9},
             "extensions": {"KHR_materials_sheen": {
                 "sheenColorFactor": [1.0, 0.8, 0.9], "sheenRoughnessFactor": 0.5,
                 "sheenColorTexture": texture, "sheenRoughnessTexture": moved}}},
            {"name": "coated paint",
             "pbrMetallicRoughness": {"baseColorFactor": [0.1, 0.3, 0.8, 1], "baseColorTexture": texture,
                                      "metallicFactor": 0.2, "roughnessFactor": 0.5},
             "extensions": {
                 "KHR_materials_clearcoat": {"clearcoatFactor": 1.0, "clearcoatTexture": texture,
                                             "clearcoatRoughnessFactor": 0.3,
                                             "clearcoatRoughnessTexture": moved,
                                             "clearcoatNormalTexture": {"index": 0, "scale": 0.5}},
                 "KHR_materials_specular": {"specularFactor": 0.8, "specularTexture": texture,
                                            "specularColorFactor": [1, 0.9, 0.8],
                                            "specularColorTexture": texture},
                 "KHR_materials_transmission": {"transmissionFactor": 0.4, "transmissionTexture": texture},
                 "KHR_materials_volume": {"thicknessFactor": 0.1, "attenuationColor": [0.9, 0.5, 0.3],
                                          "attenuationDistance": 0.5},
                 "KHR_materials_ior": {"ior": 1.45}}},
        ],
        "textures": [{"source": 0, "sampler": 0}],
        "samplers": [{"magFilter": 9729, "minFilter": 9729, "wrapS": 10497, "wrapT": 10497}],
        "images": [{"uri": "data:image/png;base64," + base64.b64encode(image).decode()}],
        "buffers": [{"byteLength": len(buffer),
                     "uri": "data:application/octet-stream;base64," + base64.b64encode(buffer).decode()}],
        "bufferViews": views,
        "accessors": accessors,
    }
    with open(OUT, "w") as f:
        json.dump(gltf, f, indent=1)
        f.write("\n")


if __name__ == "__main__":
    main()
