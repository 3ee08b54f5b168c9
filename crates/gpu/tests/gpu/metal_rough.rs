//! glTF's metal-rough material and its textures on both backends: white furnaces where the
//! answer is exact, an alpha-masked quad that shades and shadows like the cut-out shape it
//! stands for, a normal map that shades like the vertex normals it encodes, and CPU/GPU
//! agreement on a scene using all of them.

use glam::Vec3A;
use glam::{Vec2, Vec3};
use pathlight_core::Film;
use pathlight_cpu::textures::srgb_to_linear;
use pathlight_scene::{
    AlphaMode, Environment, LayerTextures, Material, MetalRough, Model, Object, Scene, Shape,
    Texture, TextureRef, TriangleMesh, Wrap,
};

use crate::common::{render, render_cpu, scene};

/// A metal-rough material of base colour `color`.
fn metal_rough(name: &str, color: Vec3, pbr: MetalRough) -> Material {
    Material::new(name, color, Model::MetalRough(pbr))
}

/// White furnaces (constant radiance 1) where every path carries weight 1: a smooth white
/// metal (Schlick with F0 = 1 reflects everything), a smooth thin wall that transmits all
/// it does not reflect, and smooth solid glass (radiance scaled by 1/eta^2 going in and
/// eta^2 coming out), on both backends. The sphere must read 1: mean within 0.3%, pixels
/// within 0.02 (the glass loses what is still inside after max_depth 64: nothing visible).
/// A white sheen over a white Lambertian base reflects everything too (the extension's
/// albedo scaling), but its paths' weights vary: pixels within 0.1 at 16 spp.
#[test]
fn metal_rough_furnaces_read_one_on_both_backends() {
    let cases = [
        (
            "smooth white metal",
            MetalRough {
                metallic: 1.0,
                roughness: 0.0,
                ..MetalRough::DEFAULT
            },
            0.02,
        ),
        (
            "smooth white metal under a smooth clear coat",
            MetalRough {
                metallic: 1.0,
                roughness: 0.0,
                clearcoat: 1.0,
                ..MetalRough::DEFAULT
            },
            0.02,
        ),
        (
            "white sheen over white diffuse without specular",
            MetalRough {
                specular: 0.0,
                sheen_color: Vec3::ONE,
                sheen_roughness: 0.5,
                ..MetalRough::DEFAULT
            },
            0.1,
        ),
        (
            "smooth thin wall",
            MetalRough {
                roughness: 0.0,
                transmission: 1.0,
                ..MetalRough::DEFAULT
            },
            0.02,
        ),
        (
            "smooth solid glass",
            MetalRough {
                roughness: 0.0,
                transmission: 1.0,
                thin: false,
                ..MetalRough::DEFAULT
            },
            0.02,
        ),
    ];
    for (what, pbr, pixel_tolerance) in cases {
        let mut s = scene("refs/furnace-1.0.toml", 48, 16, 0);
        s.settings.max_depth = 64;
        s.materials[0] = metal_rough(what, Vec3::ONE, pbr);
        for (backend, film) in [("GPU", render(&s)), ("CPU", render_cpu(&s))] {
            let (mut sum, mut count, mut worst) = (0.0f64, 0usize, 0.0f64);
            for y in 0..48 {
                for x in 0..48 {
                    let r = ((x as f32 - 23.5).powi(2) + (y as f32 - 23.5).powi(2)).sqrt();
                    // The sphere's silhouette radius is about 16.5 pixels at 48 px.
                    if r < 14.0 {
                        for c in film.pixel(x, y) {
                            sum += f64::from(c);
                            count += 1;
                            worst = worst.max((f64::from(c) - 1.0).abs());
                        }
                    }
                }
            }
            let mean = sum / count as f64;
            println!("{what} ({backend}): mean {mean:.5}, worst pixel off by {worst:.4}");
            assert!(
                (mean - 1.0).abs() < 0.003,
                "{what} ({backend}): mean {mean}"
            );
            assert!(
                worst < pixel_tolerance,
                "{what} ({backend}): a pixel is off by {worst}"
            );
        }
    }
}

/// The quad `origin + s edge_u + t edge_v` as two triangles with (u, v) = (s, t), normals
/// `normal` and tangents along `edge_u` with w = -1: bitangent -cross(normal, edge_u), which
/// is -v (glTF's up in the image) when `edge_v` lies along cross(normal, edge_u).
fn quad(origin: Vec3, edge_u: Vec3, edge_v: Vec3, normal: Vec3) -> TriangleMesh {
    let corners = [Vec2::ZERO, Vec2::X, Vec2::ONE, Vec2::Y];
    TriangleMesh {
        positions: corners
            .iter()
            .map(|c| origin + c.x * edge_u + c.y * edge_v)
            .collect(),
        normals: vec![normal; 4],
        uvs: corners.to_vec(),
        indices: vec![[0, 1, 2], [0, 2, 3]],
        tangents: vec![edge_u.normalize().extend(-1.0); 6],
        colors: Vec::new(),
        flat: false,
    }
}

/// A texture of `width` x 1 texels, each `texel(x)` as RGBA8.
fn strip(width: u32, texel: impl Fn(u32) -> [u8; 4]) -> Texture {
    Texture {
        width,
        height: 1,
        texels: (0..width).map(|x| u32::from_le_bytes(texel(x))).collect(),
    }
}

/// A white floor (y = 0, 4 x 4) under a grey sky, seen from above, with a 2 x 2 quad at
/// height 0.5 over its centre made of `occluder`'s material, lit by an emissive quad high
/// above to one side so that the occluder casts a sharp-ish shadow.
fn shadow_scene(occluder: Shape, occluder_material: Material, textures: Vec<Texture>) -> Scene {
    let mut s = scene("refs/furnace-1.0.toml", 48, 8, 3);
    s.camera.position = Vec3::new(0.0, 5.0, 0.01);
    s.camera.look_at = Vec3::ZERO;
    s.environment = Environment::Constant(Vec3::splat(0.2));
    let floor = metal_rough("floor", Vec3::splat(0.8), MetalRough::DEFAULT);
    let mut light = metal_rough("light", Vec3::ZERO, MetalRough::DEFAULT);
    light.emission = Vec3::splat(20.0);
    s.materials = vec![floor, occluder_material, light];
    s.textures = textures;
    s.objects = vec![
        Object {
            name: "floor".into(),
            material: 0,
            shape: Shape::Mesh(quad(
                Vec3::new(-2.0, 0.0, 2.0),
                Vec3::new(4.0, 0.0, 0.0),
                Vec3::new(0.0, 0.0, -4.0),
                Vec3::Y,
            )),
        },
        Object {
            name: "occluder".into(),
            material: 1,
            shape: occluder,
        },
        Object {
            name: "light".into(),
            material: 2,
            shape: Shape::Mesh(quad(
                Vec3::new(0.5, 3.0, 0.5),
                Vec3::new(0.0, 0.0, -1.0),
                Vec3::new(1.0, 0.0, 0.0),
                Vec3::NEG_Y,
            )),
        },
    ];
    s
}

/// The share of pixels within 2% (relative) of each other, and the two means.
fn agreement(a: &Film, b: &Film) -> (f64, [f64; 3], [f64; 3]) {
    let close = a
        .pixels
        .iter()
        .zip(&b.pixels)
        .filter(|(p, q)| (0..3).all(|i| (p[i] - q[i]).abs() <= 0.02 * (1.0 + q[i].abs())))
        .count();
    (close as f64 / a.pixels.len() as f64, a.mean(), b.mean())
}

/// A quad whose texture's left half has alpha 0 (MASK, cutoff 0.5) shades and shadows as
/// the right half alone does: the same image but for pixels on the cut (CPU and GPU), and
/// one clearly unlike the whole quad's (so the test can fail). So does a quad whose vertex
/// colours' alpha (`COLOR_0`) runs from 0 on its left edge to 1 on its right.
#[test]
fn an_alpha_masked_quad_casts_the_shadow_of_its_opaque_part() {
    let edge_u = Vec3::new(2.0, 0.0, 0.0);
    let edge_v = Vec3::new(0.0, 0.0, -2.0);
    let origin = Vec3::new(-1.0, 0.5, 1.0);
    // 16 texels: 8 transparent, 8 opaque; bilinear alpha crosses 0.5 at u = 0.5 exactly.
    let mask = strip(16, |x| [255, 255, 255, if x < 8 { 0 } else { 255 }]);
    let mut masked = metal_rough("masked", Vec3::splat(0.5), MetalRough::DEFAULT);
    masked.alpha = AlphaMode::Mask(0.5);
    masked.texture = Some(TextureRef {
        texture: 0,
        transform: TextureRef::IDENTITY,
        wrap: [Wrap::Clamp; 2],
    });
    let cut_material = metal_rough("cut", Vec3::splat(0.5), MetalRough::DEFAULT);
    let masked_scene = shadow_scene(
        Shape::Mesh(quad(origin, edge_u, edge_v, Vec3::Y)),
        masked,
        vec![mask],
    );
    let cut_scene = shadow_scene(
        Shape::Mesh(quad(origin + 0.5 * edge_u, 0.5 * edge_u, edge_v, Vec3::Y)),
        cut_material.clone(),
        Vec::new(),
    );
    let whole_scene = shadow_scene(
        Shape::Mesh(quad(origin, edge_u, edge_v, Vec3::Y)),
        cut_material,
        Vec::new(),
    );
    let mut faded = quad(origin, edge_u, edge_v, Vec3::Y);
    faded.colors = [0.0, 1.0, 1.0, 0.0].map(|a| Vec3::ONE.extend(a)).to_vec();
    let mut by_vertices = metal_rough("by vertices", Vec3::splat(0.5), MetalRough::DEFAULT);
    by_vertices.alpha = AlphaMode::Mask(0.5);
    let faded_scene = shadow_scene(Shape::Mesh(faded), by_vertices, Vec::new());
    let cut = render_cpu(&cut_scene);
    for (backend, film) in [
        ("CPU", render_cpu(&masked_scene)),
        ("GPU", render(&masked_scene)),
        ("CPU, vertex alpha", render_cpu(&faded_scene)),
        ("GPU, vertex alpha", render(&faded_scene)),
    ] {
        let (share, a, b) = agreement(&film, &cut);
        println!("masked ({backend}) vs cut: {share:.4} of pixels agree; means {a:?} vs {b:?}");
        assert!(share >= 0.95, "{backend}: only {share} of pixels agree");
        assert!(
            (a[1] - b[1]).abs() <= 0.01 * b[1],
            "{backend}: means {a:?} vs {b:?}"
        );
    }
    let (share, _, _) = agreement(&render_cpu(&whole_scene), &cut);
    assert!(
        share < 0.9,
        "the whole quad looks like the cut one ({share})"
    );
}

/// A normal map of one texel holding the tangent-space normal (sin 40deg, 0, cos 40deg)
/// shades a quad as vertex normals tilted by 40 degrees towards its tangent do: the same
/// image on both backends up to float rounding (the texel's 8-bit value is what the vertex
/// normals use), and unlike the untilted quad's; so does the same map as a clear coat's
/// own normal map (`KHR_materials_clearcoat`'s `clearcoatNormalTexture`) on a coat over
/// black. Paths of two segments: the camera sees the
/// quad from above, lit by the emitter; a longer path could meet the quad from a grazing
/// side, where a mapped normal that would mirror it into the quad is turned back
/// (`valid_reflection_normal`) and vertex normals are not.
#[test]
fn a_normal_map_shades_like_the_normals_it_encodes() {
    let texel = [
        (0.5 + 0.5 * 40f32.to_radians().sin()) * 255.0,
        127.5,
        (0.5 + 0.5 * 40f32.to_radians().cos()) * 255.0,
    ]
    .map(|c| c.round() as u8);
    let decoded = Vec3::from(texel.map(|c| f32::from(c) / 255.0 * 2.0 - 1.0));
    let map = strip(1, |_| [texel[0], texel[1], texel[2], 255]);
    let (origin, edge_u, edge_v) = (
        Vec3::new(-1.0, 0.5, 1.0),
        Vec3::new(2.0, 0.0, 0.0),
        Vec3::new(0.0, 0.0, -2.0),
    );
    // Tangent +x, bitangent -cross(n, t) = -cross(y, x) = +z = the direction of -v.
    let tilted = (decoded.x * Vec3::X + decoded.y * Vec3::Z + decoded.z * Vec3::Y).normalize();
    let mapped_material = {
        let mut m = metal_rough("mapped", Vec3::splat(0.7), MetalRough::DEFAULT);
        m.normal_texture = Some(TextureRef {
            texture: 0,
            transform: TextureRef::IDENTITY,
            wrap: [Wrap::Repeat; 2],
        });
        m
    };
    let plain = metal_rough("plain", Vec3::splat(0.7), MetalRough::DEFAULT);
    let mut mapped = shadow_scene(
        Shape::Mesh(quad(origin, edge_u, edge_v, Vec3::Y)),
        mapped_material,
        vec![map],
    );
    let mut by_normals_mesh = quad(origin, edge_u, edge_v, tilted);
    by_normals_mesh.tangents.clear();
    let mut by_normals = shadow_scene(Shape::Mesh(by_normals_mesh), plain.clone(), Vec::new());
    let mut untilted = shadow_scene(
        Shape::Mesh(quad(origin, edge_u, edge_v, Vec3::Y)),
        plain,
        Vec::new(),
    );
    for s in [&mut mapped, &mut by_normals, &mut untilted] {
        s.settings.max_depth = 2;
    }
    let reference = render_cpu(&by_normals);
    for (backend, film) in [("CPU", render_cpu(&mapped)), ("GPU", render(&mapped))] {
        let (share, a, b) = agreement(&film, &reference);
        println!("normal map ({backend}) vs vertex normals: {share:.4} agree; {a:?} vs {b:?}");
        assert!(share >= 0.99, "{backend}: only {share} of pixels agree");
    }
    let (share, _, _) = agreement(&render_cpu(&untilted), &reference);
    assert!(
        share < 0.9,
        "the tilt does not show ({share} of pixels agree)"
    );
    // The coat's own normal map: a black base without specular reflection under a rough
    // coat, the map on the coat alone, shades as the coat over the tilted vertex normals.
    let coat_only = MetalRough {
        specular: 0.0,
        clearcoat: 1.0,
        clearcoat_roughness: 0.5,
        ..MetalRough::DEFAULT
    };
    let mut coat_mapped = coat_only;
    coat_mapped.textures.clearcoat_normal = Some(TextureRef {
        texture: 0,
        transform: TextureRef::IDENTITY,
        wrap: [Wrap::Repeat; 2],
    });
    let map = strip(1, |_| [texel[0], texel[1], texel[2], 255]);
    let mut coat_scenes = [
        shadow_scene(
            Shape::Mesh(quad(origin, edge_u, edge_v, Vec3::Y)),
            metal_rough("coat mapped", Vec3::ZERO, coat_mapped),
            vec![map],
        ),
        shadow_scene(
            Shape::Mesh({
                let mut m = quad(origin, edge_u, edge_v, tilted);
                m.tangents.clear();
                m
            }),
            metal_rough("coat on tilted normals", Vec3::ZERO, coat_only),
            Vec::new(),
        ),
        shadow_scene(
            Shape::Mesh(quad(origin, edge_u, edge_v, Vec3::Y)),
            metal_rough("coat untilted", Vec3::ZERO, coat_only),
            Vec::new(),
        ),
    ];
    for s in &mut coat_scenes {
        s.settings.max_depth = 2;
    }
    let [coat_mapped, coat_tilted, coat_untilted] = coat_scenes;
    let reference = render_cpu(&coat_tilted);
    for (backend, film) in [
        ("CPU", render_cpu(&coat_mapped)),
        ("GPU", render(&coat_mapped)),
    ] {
        let (share, a, b) = agreement(&film, &reference);
        println!("coat normal map ({backend}) vs vertex normals: {share:.4} agree; {a:?} vs {b:?}");
        // The same radiance, sampled differently: directions drawn for the (black) base
        // follow the base's normal, which only the mapped case keeps untilted. So noise,
        // not the mean, differs in a few pixels.
        assert!(share >= 0.95, "{backend}: only {share} of pixels agree");
        assert!(
            (a[0] - b[0]).abs() <= 0.01 * b[0],
            "{backend}: means {a:?} vs {b:?}"
        );
    }
    let (share, _, _) = agreement(&render_cpu(&coat_untilted), &reference);
    assert!(
        share < 0.9,
        "the coat's tilt does not show ({share} of pixels agree)"
    );
}

/// A mirror-smooth metal quad (Schlick F0 0.9) bumped by a steep normal map (normals tilted
/// 70 degrees, eight ways round) under a uniform sky of radiance 1, seen at a slant: where a
/// mapped normal would mirror the view into the quad, the normal is turned back
/// (`valid_reflection_normal`), so that every pixel reads the sky times the Fresnel, at least
/// 0.9, on both backends: no black rims.
#[test]
fn a_steep_normal_map_on_a_mirror_leaves_no_black_rims() {
    let tilt = 70f32.to_radians();
    let map = strip(8, |x| {
        let phi = x as f32 * std::f32::consts::FRAC_PI_4;
        let n = Vec3::new(tilt.sin() * phi.cos(), tilt.sin() * phi.sin(), tilt.cos());
        let [r, g, b] = (n * 0.5 + 0.5)
            .to_array()
            .map(|c| (c * 255.0).round() as u8);
        [r, g, b, 255]
    });
    let mut mirror = metal_rough(
        "mirror",
        Vec3::splat(0.9),
        MetalRough {
            metallic: 1.0,
            roughness: 0.0,
            ..MetalRough::DEFAULT
        },
    );
    mirror.normal_texture = Some(TextureRef {
        texture: 0,
        transform: TextureRef::IDENTITY,
        wrap: [Wrap::Repeat; 2],
    });
    let mut s = scene("refs/furnace-1.0.toml", 48, 4, 5);
    s.camera.position = Vec3::new(0.0, 1.0, 2.5);
    s.camera.look_at = Vec3::new(0.0, 0.0, -0.5);
    s.environment = Environment::Constant(Vec3::ONE);
    s.materials = vec![mirror];
    s.textures = vec![map];
    s.objects = vec![Object {
        name: "mirror".into(),
        material: 0,
        shape: Shape::Mesh(quad(
            Vec3::new(-3.0, 0.0, 3.0),
            Vec3::new(6.0, 0.0, 0.0),
            Vec3::new(0.0, 0.0, -6.0),
            Vec3::Y,
        )),
    }];
    for (backend, film) in [("CPU", render_cpu(&s)), ("GPU", render(&s))] {
        let darkest = film
            .pixels
            .iter()
            .map(|p| p.iter().copied().fold(f32::INFINITY, f32::min))
            .fold(f32::INFINITY, f32::min);
        println!("{backend}: darkest pixel {darkest}");
        assert!(darkest >= 0.9 - 1e-4, "{backend}: a pixel reads {darkest}");
    }
}

/// The extensions' textures (transmission, specular and its colour, clear coat and its
/// roughness, sheen colour and roughness) multiply their factors in glTF's channels, sRGB
/// for colours: a sphere under a sky of radiance 1 with a one-texel texture in every slot
/// renders as the same material with the texel folded into its factors (99% of pixels
/// within 2%, on each backend), the two backends agree on it, and it differs from the
/// material without its textures (so that the test can fail).
#[test]
fn the_extensions_textures_multiply_their_factors_on_both_backends() {
    let [r, g, b, a] = [200u8, 120, 60, 90];
    let linear = |v: u8| f32::from(v) / 255.0;
    let srgb = Vec3::from(srgb_to_linear(Vec3A::new(linear(r), linear(g), linear(b))));
    let plain = MetalRough {
        roughness: 0.4,
        transmission: 0.5,
        specular: 0.9,
        specular_color: Vec3::new(1.0, 0.8, 0.6),
        clearcoat: 0.8,
        clearcoat_roughness: 0.5,
        sheen_color: Vec3::new(0.9, 0.7, 0.5),
        sheen_roughness: 0.6,
        ..MetalRough::DEFAULT
    };
    let slot = Some(TextureRef {
        texture: 0,
        transform: TextureRef::IDENTITY,
        wrap: [Wrap::Repeat; 2],
    });
    let textured = MetalRough {
        textures: LayerTextures {
            transmission: slot,
            specular: slot,
            specular_color: slot,
            clearcoat: slot,
            clearcoat_roughness: slot,
            sheen_color: slot,
            sheen_roughness: slot,
            clearcoat_normal: None,
        },
        ..plain
    };
    let folded = MetalRough {
        transmission: plain.transmission * linear(r),
        specular: plain.specular * linear(a),
        specular_color: plain.specular_color * srgb,
        clearcoat: plain.clearcoat * linear(r),
        clearcoat_roughness: plain.clearcoat_roughness * linear(g),
        sheen_color: plain.sheen_color * srgb,
        sheen_roughness: plain.sheen_roughness * linear(a),
        ..plain
    };
    let sphere = |pbr: MetalRough| {
        let mut s = scene("refs/furnace-1.0.toml", 48, 8, 2);
        s.materials[0] = metal_rough("sphere", Vec3::new(0.3, 0.5, 0.8), pbr);
        s.textures = vec![strip(1, |_| [r, g, b, a])];
        s
    };
    let expected = render_cpu(&sphere(folded));
    let cpu = render_cpu(&sphere(textured));
    let gpu = render(&sphere(textured));
    for (backend, film, reference) in [
        ("CPU", &cpu, expected.clone()),
        ("GPU", &gpu, render(&sphere(folded))),
    ] {
        let (share, a, b) = agreement(film, &reference);
        println!("{backend}: textured vs folded factors: {share:.4} agree; {a:?} vs {b:?}");
        assert!(share >= 0.99, "{backend}: only {share} of pixels agree");
    }
    let (share, a, b) = agreement(&gpu, &cpu);
    println!("GPU vs CPU: {share:.4} agree; {a:?} vs {b:?}");
    assert!(
        share >= 0.95,
        "the twins differ: only {share} of pixels agree"
    );
    let (share, _, _) = agreement(&render_cpu(&sphere(plain)), &expected);
    assert!(
        share < 0.9,
        "the textures do not show ({share} of pixels agree)"
    );
}

/// A base colour texture is decoded from sRGB texel by texel before its bilinear filter, as
/// sRGB texture formats and Mitsuba's bitmap texture filter: a sphere under a sky of
/// radiance 1, textured with black and white texels in turn (a stripe each, 256 around it,
/// two to eight a pixel), renders as the same sphere of base colour 0.5 without a texture
/// (the filter's mean between the texels; image means within 1%, on each backend), and not
/// as one of the mean of sRGB's curve over [0, 1] (0.31), which a filter before the
/// decoding gives.
#[test]
fn srgb_textures_are_filtered_in_linear_light_on_both_backends() {
    let sphere = |color: f32, texture: bool| {
        let mut s = scene("refs/furnace-1.0.toml", 64, 16, 2);
        s.materials[0] = metal_rough("sphere", Vec3::splat(color), MetalRough::DEFAULT);
        if texture {
            s.materials[0].texture = Some(TextureRef {
                texture: 0,
                transform: TextureRef::IDENTITY,
                wrap: [Wrap::Repeat; 2],
            });
            s.textures = vec![strip(256, |x| {
                let v = if x % 2 == 0 { 0 } else { 255 };
                [v, v, v, 255]
            })];
        }
        s
    };
    let srgb_curve_mean = 0.31;
    for (backend, render) in [("CPU", render_cpu as fn(&Scene) -> Film), ("GPU", render)] {
        let mean = |s: &Scene| render(s).mean()[1];
        let textured = mean(&sphere(1.0, true));
        let flat = mean(&sphere(0.5, false));
        let filtered_before_decoding = mean(&sphere(srgb_curve_mean, false));
        println!(
            "{backend}: textured {textured:.4}, base 0.5 {flat:.4}, base {srgb_curve_mean} \
             {filtered_before_decoding:.4}"
        );
        assert!(
            (textured - flat).abs() <= 0.01 * flat,
            "{backend}: the textured sphere's mean {textured} is not base 0.5's {flat}"
        );
        assert!(
            (filtered_before_decoding - flat).abs() > 0.05 * flat,
            "{backend}: the test cannot tell the filters apart"
        );
    }
}

/// Vertex colours (`COLOR_0`) multiply the base colour: a white quad whose corners carry a
/// colour shades as a quad of that base colour (99% of pixels within 2%, CPU and GPU), and a
/// quad whose colour runs from black to white across it is dark on one side and bright on
/// the other.
#[test]
fn vertex_colours_multiply_the_base_colour_on_both_backends() {
    let edge_u = Vec3::new(2.0, 0.0, 0.0);
    let edge_v = Vec3::new(0.0, 0.0, -2.0);
    let origin = Vec3::new(-1.0, 0.5, 1.0);
    // A colour 8 bits keep exactly (sRGB bytes 200, 120, 60).
    let color = Vec3::from(srgb_to_linear(Vec3A::new(200.0, 120.0, 60.0) / 255.0));
    let mut coloured = quad(origin, edge_u, edge_v, Vec3::Y);
    coloured.colors = vec![color.extend(1.0); 4];
    let white = metal_rough("white", Vec3::ONE, MetalRough::DEFAULT);
    let tinted = metal_rough("tinted", color, MetalRough::DEFAULT);
    let by_vertices = shadow_scene(Shape::Mesh(coloured), white.clone(), Vec::new());
    let by_material = shadow_scene(
        Shape::Mesh(quad(origin, edge_u, edge_v, Vec3::Y)),
        tinted,
        Vec::new(),
    );
    for (backend, film, reference) in [
        ("CPU", render_cpu(&by_vertices), render_cpu(&by_material)),
        ("GPU", render(&by_vertices), render(&by_material)),
    ] {
        let (share, a, b) = agreement(&film, &reference);
        println!("vertex colours ({backend}) vs base colour: {share:.4} agree; {a:?} vs {b:?}");
        assert!(share >= 0.99, "{backend}: only {share} of pixels agree");
    }
    let mut ramp = quad(origin, edge_u, edge_v, Vec3::Y);
    ramp.colors = [0.0, 1.0, 1.0, 0.0]
        .map(|c| Vec3::splat(c).extend(1.0))
        .to_vec();
    let ramp = shadow_scene(Shape::Mesh(ramp), white, Vec::new());
    for (backend, film) in [("CPU", render_cpu(&ramp)), ("GPU", render(&ramp))] {
        // Seen from above, +x is to the right: the quad's u runs left to right.
        let (left, right) = (film.pixel(16, 24)[1], film.pixel(31, 24)[1]);
        assert!(left < 0.5 * right, "{backend}: left {left}, right {right}");
    }
}

/// `MaterialLayers/layers.gltf` (every material extension pathlight reads, their textures,
/// vertex colours) renders alike on both backends: 99% of pixels within 2%.
#[test]
fn the_material_layers_sample_renders_alike_on_both_backends() {
    let path =
        crate::common::repo().join("crates/scene/tests/data/gltf/MaterialLayers/layers.gltf");
    let model = pathlight_scene::gltf_scene(&path, None).unwrap();
    let mut s = model;
    s.camera.width = 48;
    s.camera.height = 24;
    s.settings.spp = 4;
    let (cpu, gpu) = (render_cpu(&s), render(&s));
    let (share, a, b) = agreement(&gpu, &cpu);
    println!("layers.gltf, GPU vs CPU: {share:.4} agree; {a:?} vs {b:?}");
    assert!(share >= 0.99, "only {share} of pixels agree");
}
