#!/usr/bin/env python3
"""Mitsuba 3 references for pathlight's reference scenes, from pathlight's own scene files.

Converts scenes/refs/NAME.toml (the subset with an exact Mitsuba equivalent: quads, spheres,
OBJ meshes with scale + translate, emissive shapes as one-sided `area` emitters, two-sided
diffuse, smooth or GGX-rough conductors and dielectrics with alpha = roughness^2, glTF's
metal-rough metals (`principled` with metallic 1) and its diffuse base of specular strength 0,
a constant environment or an `envmap` with its scale and rotation about +y, a pinhole or a
`thinlens` camera, point lights, spot lights with a hard edge, directional suns) to a Mitsuba scene and either

  render NAME [--res 512] [--spp 1024]   writes scenes/refs/images/NAME.exr and .png: the
                                         2x2 box average of a res x res render (the
                                         convention of the images in scenes/refs/images)
  relmse NAME... [--res 128] [--spp 64] [--seeds 8]
                                         prints Mitsuba's own relMSE against the stored
                                         reference: mean over pixels and channels of
                                         (test - ref)^2 / (ref^2 + 0.01), ref box-downsampled
  time NAME... [--res 512] [--spp 64] [--repeats 3] [--save FILE.exr]
                                         render time alone (after one untimed render that
                                         compiles the kernels), median of the repeats, and
                                         samples/s; --save writes the last timed image
  relmse-of NAME FILE.exr...             prints the relMSE of each image (pathlight's or
                                         Mitsuba's) against the stored reference, the image
                                         box-downsampled to the reference's size

Needs: pip install mitsuba numpy; apt-get install libllvm19 (for llvm_ad_rgb, the default
variant; DRJIT_LIBLLVM_PATH is set to Debian's libLLVM.so.19.1 when it exists).
"""
import argparse
import json
import math
import os
import time
import tomllib

import numpy as np

LLVM19 = "/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1"
if "DRJIT_LIBLLVM_PATH" not in os.environ and os.path.exists(LLVM19):
    os.environ["DRJIT_LIBLLVM_PATH"] = LLVM19

REFS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "scenes", "refs")
PRESETS = {"gold": ([0.143036, 0.375307, 1.44205], [3.983, 2.38556, 1.60336]),
           "aluminium": ([1.6575, 0.880405, 0.521244], [9.22381, 6.2695, 4.837])}


def rgb(v):
    return {"type": "rgb", "value": [float(c) for c in v]}


# The seed's material presets (docs/scene-format.md): specular_rate, specular_tint,
# specular_roughness, refract_rate.
MATERIAL_PRESETS = {"metal": (1.0, 1.0, 0.15, 0.0), "plastic": (0.1, 0.0, 0.25, 0.0),
                    "wall": (0.0, 0.0, 0.0, 0.0), "glass": (0.0, 0.0, 0.0, 1.0),
                    "wood": (0.06, 0.0, 0.35, 0.0), "ceramic": (0.2, 0.0, 0.08, 0.0)}


def with_preset(m):
    if "preset" not in m:
        return m
    rate, tint, roughness, refract = MATERIAL_PRESETS[m["preset"]]
    defaults = {"specular_rate": rate, "specular_tint": tint, "specular_roughness": roughness,
                "refract_rate": refract}
    return {**defaults, **m}


def schlick_white(m):
    """The Schlick specular lobe when its colour is white (F0 = 1, so F = 1): Mitsuba's
    conductor with material "none"."""
    color = m.get("color", [0.8] * 3)
    if m.get("specular_tint", 0.0) != 0.0 and any(c != 1.0 for c in color):
        raise SystemExit("a tinted Schlick lobe has no exact Mitsuba equivalent")
    alpha = m.get("specular_roughness", 0.0) ** 2
    out = {"type": "conductor", "material": "none"}
    if alpha >= 1e-3:
        out.update(type="roughconductor", distribution="ggx", alpha=alpha)
    return out


def base_color(m):
    """The colour a material's BSDF starts from: its texture (8-bit images are sRGB-decoded by
    Mitsuba, bilinear, as pathlight does) or its colour."""
    if "texture" in m:
        return {"type": "bitmap", "filename": os.path.join(REFS, m["texture"]), "filter_type": "bilinear"}
    return rgb(m.get("color", [0.8] * 3))


def lambert(reflectance):
    """Mitsuba's two-sided Lambert of `reflectance`."""
    return {"type": "twosided", "bsdf": {"type": "diffuse", "reflectance": reflectance}}


def metal_rough(name, m):
    """glTF's metal-rough model where Mitsuba states it exactly: a metal (metallic 1) is
    `principled`'s metallic lobe (GGX, separable Smith, Schlick Fresnel from the base colour);
    a dielectric of specular strength 0 is its diffuse base alone, Lambert's."""
    plain = {"metallic", "roughness", "specular", "color", "texture", "model"}
    if set(m) - plain:
        raise SystemExit(f"{name}: {sorted(set(m) - plain)} of metal-rough are not converted")
    if "texture" in m and m.get("color", [0.8] * 3) != [1.0] * 3:
        raise SystemExit(f"{name}: a texture times a colour other than [1, 1, 1] is not converted")
    base = base_color(m)
    if m.get("metallic", 0.0) == 1.0:
        return {"type": "principled", "base_color": base, "metallic": 1.0,
                "roughness": m.get("roughness", 1.0), "spec_tint": 0.0}
    if m.get("metallic", 0.0) == 0.0 and m.get("specular", 1.0) == 0.0:
        return lambert(base)
    raise SystemExit(f"{name}: metal-rough with metallic {m.get('metallic', 0.0)} and specular "
                     f"{m.get('specular', 1.0)} has no exact Mitsuba equivalent (metallic 1, or 0 with specular 0)")


def bsdf(name, m):
    if m.get("model") == "metal-rough":
        return metal_rough(name, m)
    m = with_preset(m)
    rate = m.get("specular_rate", 0.0)
    if 0.0 < rate and m.get("refract_rate", 0.0) == 0.0 and "conductor" not in m and "eta" not in m:
        if rate == 1.0:
            return schlick_white(m)
        diffuse = bsdf(name, {k: v for k, v in m.items() if k not in ("specular_rate", "preset")})
        return {"type": "blendbsdf", "weight": rate, "bsdf_0": diffuse, "bsdf_1": schlick_white(m)}
    if m.get("color_space_srgb"):
        raise SystemExit(f"{name}: use color_space = \"linear\" for Mitsuba references")
    alpha_s = m.get("specular_roughness", 0.0) ** 2
    alpha_t = m.get("refract_roughness", 0.0) ** 2
    if "emission" in m:
        return {"type": "diffuse", "reflectance": rgb([0, 0, 0])}
    if "conductor" in m or "eta" in m:
        eta, k = PRESETS[m["conductor"]] if "conductor" in m else (m["eta"], m["k"])
        out = {"type": "conductor", "eta": rgb(eta), "k": rgb(k)}
        if alpha_s >= 1e-3:
            out.update(type="roughconductor", distribution="ggx", alpha=alpha_s)
        return out
    if m.get("refract_rate", 0.0) == 1.0:
        out = {"type": "dielectric", "int_ior": m.get("ior", 1.5), "ext_ior": 1.0}
        if alpha_t >= 1e-3:
            out.update(type="roughdielectric", distribution="ggx", alpha=alpha_t)
        return out
    if m.get("specular_rate", 0.0) == 0.0 and m.get("refract_rate", 0.0) == 0.0:
        return lambert(base_color(m))
    raise SystemExit(f"material {name} has no exact Mitsuba equivalent")


def to_mitsuba(scene, res, spp):
    import mitsuba as mi
    T = mi.ScalarTransform4f
    if scene.get("color_space") != "linear":
        raise SystemExit("reference scenes must use color_space = \"linear\"")
    cam = scene["camera"]
    render = scene.get("render", {})
    sensor_type = "perspective"
    lens = {}
    if cam.get("aperture_radius", 0.0) > 0.0:
        focus = cam.get("focus_distance", float(np.linalg.norm(np.subtract(cam["look_at"], cam["position"]))))
        sensor_type = "thinlens"
        lens = {"aperture_radius": cam["aperture_radius"], "focus_distance": focus}
    out = {
        "type": "scene",
        "integrator": {"type": "path", "max_depth": render.get("max_depth", 8),
                       "rr_depth": render.get("rr_depth", 5), "hide_emitters": False},
        "sensor": {
            "type": sensor_type, "fov": cam["fov_y"], "fov_axis": "y", **lens,
            "to_world": T().look_at(origin=cam["position"], target=cam["look_at"], up=cam.get("up", [0, 1, 0])),
            "film": {"type": "hdrfilm", "width": res, "height": res, "pixel_format": "rgb",
                     "rfilter": {"type": "box"}},
            "sampler": {"type": "independent", "sample_count": spp},
        },
    }
    env = scene.get("environment")
    if env and "map" in env:
        # pathlight's map convention is Mitsuba's, its rotation Mitsuba's to_world about +y.
        out["environment"] = {"type": "envmap", "filename": os.path.join(REFS, env["map"]),
                              "scale": env.get("strength", 1.0),
                              "to_world": T().rotate([0, 1, 0], env.get("rotation", 0.0))}
    elif env:
        out["environment"] = {"type": "constant", "radiance": rgb(env["radiance"])}
    materials = scene["materials"]

    def attach(shape, mat_name):
        m = materials[mat_name]
        shape["bsdf"] = bsdf(mat_name, m)
        if "emission" in m:
            shape["emitter"] = {"type": "area", "radiance": rgb(m["emission"])}
        return shape

    for i, q in enumerate(scene.get("quad", [])):
        u, v, o = (np.array(q[k], float) for k in ("edge_u", "edge_v", "origin"))
        n = np.cross(u, v)
        n /= np.linalg.norm(n)
        m = np.eye(4)
        m[:3, 0], m[:3, 1], m[:3, 2], m[:3, 3] = u / 2, v / 2, n, o + (u + v) / 2
        out[f"quad{i}"] = attach({"type": "rectangle", "to_world": T(m)}, q["material"])
    for i, s in enumerate(scene.get("sphere", [])):
        # Mitsuba's sphere: u = atan2(y, x) / 2pi from local +x, v = angle from local +z / pi.
        # pathlight's: v from +y, u = 0.5 + (atan2(x, z) + rotation) / 2pi. They agree when
        # local x, y, z are world -z, -x, +y, turned about y by the texture rotation.
        rot = math.radians(s.get("texture_rotation", 0.0))
        c, sn = math.cos(rot), math.sin(rot)
        r = s["radius"]
        m = np.eye(4)
        # Then Mitsuba's phi = atan2(n.ly, n.lx) = atan2(n.x, n.z) + rot + pi, as required.
        lx = np.array([sn, 0.0, -c])
        ly = np.array([-c, 0.0, -sn])
        m[:3, 0], m[:3, 1], m[:3, 2], m[:3, 3] = lx * r, ly * r, np.array([0.0, r, 0.0]), s["center"]
        out[f"sphere{i}"] = attach({"type": "sphere", "to_world": T(m)}, s["material"])
    for i, mesh in enumerate(scene.get("mesh", [])):
        t = mesh.get("transform", {})
        if any(t.get("rotate", [0, 0, 0])):
            raise SystemExit("mesh rotation is not converted")
        scale = t.get("scale", 1.0)
        to_world = T().translate(t.get("translate", [0, 0, 0])) @ T().scale(scale if isinstance(scale, list) else [scale] * 3)
        shape = {"type": "obj", "filename": os.path.join(REFS, mesh["file"]), "to_world": to_world,
                 "face_normals": mesh.get("shading") == "flat"}
        out[f"mesh{i}"] = attach(shape, mesh["material"])
    for kind in ("cylinder", "revolve"):
        if scene.get(kind):
            raise SystemExit(f"{kind} shapes are not converted")
    for i, light in enumerate(scene.get("light", [])):
        out[f"light{i}"] = emitter(light)
    return out


def emitter(light):
    """A [[light]] as Mitsuba's point, spot or directional emitter (the kinds with an exact
    equivalent: no radius, no sun disk, a spot with a hard edge)."""
    import mitsuba as mi
    T = mi.ScalarTransform4f
    strength = rgb(np.array(light.get("color", [1, 1, 1]), float) * light["intensity"])
    if light.get("radius", 0.0) or light.get("angular_diameter", 0.0):
        raise SystemExit("lights with a radius or a sun disk are not converted")
    if light["type"] == "point":
        return {"type": "point", "position": light["position"], "intensity": strength}
    if light["type"] == "sun":
        return {"type": "directional", "direction": light["direction"], "irradiance": strength}
    outer = light.get("outer_angle", 45.0)
    if light.get("inner_angle", 0.0) != outer:
        # Mitsuba's falloff is linear in the angle, glTF's (pathlight's) quadratic in a step
        # of the cosine: only the hard edge is the same.
        raise SystemExit("spot lights are converted with inner_angle = outer_angle only")
    position = np.array(light["position"], float)
    axis = np.array(light["direction"], float) if "direction" in light else np.array(light["look_at"], float) - position
    up = [0, 1, 0] if abs(axis[1]) < 0.99 * np.linalg.norm(axis) else [1, 0, 0]
    return {"type": "spot", "intensity": strength, "cutoff_angle": outer, "beam_width": outer,
            "to_world": T().look_at(origin=position.tolist(), target=(position + axis).tolist(), up=up)}


def load(name):
    with open(os.path.join(REFS, name + ".toml"), "rb") as f:
        return tomllib.load(f)


def downsample(image, size):
    factor = image.shape[0] // size
    return image.reshape(size, factor, size, factor, 3).mean(axis=(1, 3))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("command", choices=["render", "relmse", "time", "relmse-of"])
    ap.add_argument("names", nargs="+")
    ap.add_argument("--res", type=int)
    ap.add_argument("--spp", type=int)
    ap.add_argument("--seeds", type=int, default=8)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--variant", default="llvm_ad_rgb")
    ap.add_argument("--save")
    a = ap.parse_args()
    import mitsuba as mi
    mi.set_variant(a.variant)
    if a.command == "relmse-of":
        name, files = a.names[0], a.names[1:]
        ref = np.asarray(mi.Bitmap(os.path.join(REFS, "images", name + ".exr")), np.float64)[..., :3]
        for f in files:
            img = downsample(np.asarray(mi.Bitmap(f), np.float64)[..., :3], ref.shape[0])
            value = float(np.mean((img - ref) ** 2 / (ref ** 2 + 0.01)))
            print(json.dumps({"scene": name, "image": f, "relmse": round(value, 6)}), flush=True)
        return
    for name in a.names:
        scene = load(name)
        if a.command == "render":
            res, spp, pass_spp = a.res or 512, a.spp or 1024, 64
            mts = mi.load_dict(to_mitsuba(scene, res, pass_spp))
            t0 = time.perf_counter()
            acc = sum(np.asarray(mi.render(mts, spp=pass_spp, seed=i), np.float64) for i in range(spp // pass_spp))
            img = downsample(acc / (spp // pass_spp), res // 2).astype(np.float32)
            exr = os.path.join(REFS, "images", name + ".exr")
            mi.Bitmap(img, mi.Bitmap.PixelFormat.RGB).write(exr)
            mi.Bitmap(img, mi.Bitmap.PixelFormat.RGB).convert(
                mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.UInt8, srgb_gamma=True).write(exr[:-4] + ".png")
            print(json.dumps({"scene": name, "variant": a.variant, "res": res, "spp": spp,
                              "seconds": round(time.perf_counter() - t0, 1), "exr": exr}), flush=True)
        elif a.command == "time":
            res, spp = a.res or 512, a.spp or 64
            mts = mi.load_dict(to_mitsuba(scene, res, spp))
            np.asarray(mi.render(mts, spp=spp, seed=0))
            times = []
            for seed in range(1, a.repeats + 1):
                t0 = time.perf_counter()
                img = np.asarray(mi.render(mts, spp=spp, seed=seed))
                times.append(time.perf_counter() - t0)
            if a.save:
                mi.Bitmap(img[..., :3].astype(np.float32), mi.Bitmap.PixelFormat.RGB).write(a.save)
            seconds = float(np.median(times))
            print(json.dumps({"scene": name, "variant": a.variant, "res": res, "spp": spp,
                              "seconds": [round(t, 3) for t in times], "median_seconds": round(seconds, 3),
                              "samples_per_second": round(res * res * spp / seconds)}), flush=True)
        else:
            res, spp = a.res or 128, a.spp or 64
            ref = downsample(np.asarray(mi.Bitmap(os.path.join(REFS, "images", name + ".exr")), np.float64)[..., :3], res)
            mts = mi.load_dict(to_mitsuba(scene, res, spp))
            values = []
            for seed in range(a.seeds):
                img = np.asarray(mi.render(mts, spp=spp, seed=seed), np.float64)[..., :3]
                values.append(float(np.mean((img - ref) ** 2 / (ref ** 2 + 0.01))))
            print(json.dumps({"scene": name, "variant": a.variant, "res": res, "spp": spp,
                              "relmse": [round(v, 6) for v in values],
                              "mean_relmse": round(float(np.mean(values)), 6)}), flush=True)


if __name__ == "__main__":
    main()
