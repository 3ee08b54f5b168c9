//! Point, spot and sun lights against their analytic irradiance, and a glTF file's punctual
//! lights where its nodes put them.
//!
//! A diffuse plane of albedo 0.5 (z = 0, facing the camera above it) lit by one light has
//! radiance `0.5 / pi E(x)` at `x`, `E` the light's irradiance there; rendered with direct
//! light only (`max_depth` 2), each pixel is compared with that radiance averaged over the
//! pixel (8 x 8 points of it, through the camera's own rays). The only noise is the pixel
//! jitter (and, for a sphere or a sun disk, the point on it), so the bars are tight: 1%.

use std::f32::consts::PI;
use std::path::Path;

use glam::{Vec2, Vec3};
use pathlight_core::gpu_types::GpuRenderParams;
use pathlight_core::{Film, PreparedScene, Renderer};
use pathlight_cpu::CpuRenderer;
use pathlight_cpu::camera::primary_ray;
use pathlight_scene::testing::{object, scene_of};
use pathlight_scene::{Camera, Cone, Light, LightKind, Scene, Shape, gltf_scene};

/// The plane's albedo (the test scenes' grey material).
const ALBEDO: f32 = 0.5;
/// Image edge, pixels.
const SIZE: u32 = 24;

/// The plane z = 0 lit by `light` alone, seen from (0, 0, 3), direct light only.
fn plane_lit_by(kind: LightKind, intensity: Vec3) -> Scene {
    let mut scene = scene_of(vec![object(
        "ground",
        Shape::Quad {
            origin: Vec3::new(-4.0, -4.0, 0.0),
            edge_u: Vec3::X * 8.0,
            edge_v: Vec3::Y * 8.0,
        },
    )]);
    scene.camera = Camera {
        position: Vec3::Z * 3.0,
        look_at: Vec3::ZERO,
        up: Vec3::Y,
        fov_y_deg: 50.0,
        width: SIZE,
        height: SIZE,
        aperture_radius: 0.0,
        focus_distance: 3.0,
    };
    scene.settings.max_depth = 2;
    scene.lights = vec![Light {
        name: "light".into(),
        intensity,
        kind,
    }];
    scene
}

/// `scene` rendered on the CPU at `spp`.
fn render(scene: &Scene, spp: u32) -> Film {
    let prepared = PreparedScene::new(scene).unwrap();
    let mut renderer = CpuRenderer::new(&prepared, &scene.camera, &scene.settings);
    while renderer.samples_done() < spp {
        renderer.advance(spp - renderer.samples_done()).unwrap();
    }
    renderer.film().unwrap()
}

/// Per pixel of `scene`'s camera, the plane's radiance `ALBEDO / pi * irradiance(x)` averaged
/// over 8 x 8 points of the pixel, and whether the irradiance is zero at some of them but
/// not all, here or in a neighbouring pixel (a pixel across or beside a hard edge).
fn expected(scene: &Scene, irradiance: impl Fn(Vec3) -> Vec3) -> Vec<(Vec3, bool)> {
    let prepared = PreparedScene::new(scene).unwrap();
    let params = GpuRenderParams::new(&scene.camera, &scene.settings, &prepared.shading);
    let n = 8;
    let mut out = Vec::new();
    for y in 0..SIZE {
        for x in 0..SIZE {
            let (mut sum, mut dark) = (Vec3::ZERO, 0);
            for i in 0..n * n {
                let film = Vec2::new(
                    x as f32 + ((i % n) as f32 + 0.5) / n as f32,
                    y as f32 + ((i / n) as f32 + 0.5) / n as f32,
                );
                let ray = primary_ray(&params, film);
                let (origin, dir) = (ray.origin, ray.dir);
                let e = irradiance(origin - origin.z / dir.z * dir);
                dark += usize::from(e == Vec3::ZERO);
                sum += e;
            }
            let across = dark > 0 && dark < (n * n) as usize;
            out.push((sum / (n * n) as f32 * (ALBEDO / PI), across));
        }
    }
    // An edge that clips a pixel's corner may pass between its points: a pixel beside one
    // found across an edge counts as across too.
    let size = SIZE as usize;
    let found: Vec<bool> = out.iter().map(|(_, across)| *across).collect();
    for (i, (_, across)) in out.iter_mut().enumerate() {
        let (x, y) = (i % size, i / size);
        *across = (y.saturating_sub(1)..(y + 2).min(size))
            .any(|ny| (x.saturating_sub(1)..(x + 2).min(size)).any(|nx| found[ny * size + nx]));
    }
    out
}

/// Checks every pixel of `film` against `expected` (pixels across a hard edge skipped):
/// within `tolerance` relative, plus 1e-4.
fn check(name: &str, film: &Film, expected: &[(Vec3, bool)], tolerance: f32) {
    let mut worst = (0.0f32, String::new());
    for (i, (want, across)) in expected.iter().enumerate() {
        if *across {
            continue;
        }
        let got = Vec3::from(film.pixels[i]);
        let off = ((got - *want).abs() / (tolerance * *want + 1e-4)).max_element();
        if off > worst.0 {
            worst = (off, format!("pixel {i}: {got} against {want}"));
        }
    }
    assert!(worst.0 <= 1.0, "{name}: {}", worst.1);
    println!("{name}: worst pixel at {:.2} of its tolerance", worst.0);
}

/// Irradiance on the plane z = 0 from a point light of `intensity` at `position`, times
/// `falloff` of the cosine of the angle off the light's axis -z.
fn point_irradiance(
    intensity: Vec3,
    position: Vec3,
    falloff: impl Fn(f32) -> f32,
) -> impl Fn(Vec3) -> Vec3 {
    move |x| {
        let d = position - x;
        let distance = d.length();
        let cos_axis = d.z / distance;
        intensity * falloff(cos_axis) * (d.z / distance) / (distance * distance)
    }
}

#[test]
fn a_point_light_gives_the_inverse_square_irradiance() {
    let (intensity, position) = (Vec3::new(2.0, 1.0, 0.5), Vec3::new(0.4, -0.3, 1.0));
    let want = point_irradiance(intensity, position, |_| 1.0);
    for radius in [0.0, 0.3] {
        // A sphere of radius r and radiance I / (pi r^2) gives the same irradiance as the
        // point wherever it lies wholly above the horizon (everywhere here).
        let scene = plane_lit_by(
            LightKind::Point {
                position,
                radius,
                cone: None,
            },
            intensity,
        );
        check(
            &format!("point light of radius {radius}"),
            &render(&scene, 64),
            &expected(&scene, &want),
            0.01,
        );
    }
}

#[test]
fn a_spot_light_falls_off_as_gltf_says() {
    let (intensity, position) = (Vec3::new(3.0, 2.0, 1.0), Vec3::new(0.2, 0.1, 1.2));
    for (inner, outer) in [(15.0f32, 30.0f32), (25.0, 25.0)] {
        let (cos_inner, cos_outer) = (inner.to_radians().cos(), outer.to_radians().cos());
        // glTF's KHR_lights_punctual: the square of the linear step in the cosine.
        let falloff = move |cos: f32| {
            if cos_inner > cos_outer {
                ((cos - cos_outer) / (cos_inner - cos_outer))
                    .clamp(0.0, 1.0)
                    .powi(2)
            } else if cos > cos_outer {
                1.0
            } else {
                0.0
            }
        };
        let scene = plane_lit_by(
            LightKind::Point {
                position,
                radius: 0.0,
                cone: Some(Cone {
                    axis: Vec3::NEG_Z,
                    inner_deg: inner,
                    outer_deg: outer,
                }),
            },
            intensity,
        );
        let want = expected(&scene, point_irradiance(intensity, position, falloff));
        let film = render(&scene, 64);
        check(&format!("spot {inner}-{outer}"), &film, &want, 0.01);
        // No light at all beyond the cone.
        let outside: Vec<usize> = (0..want.len())
            .filter(|&i| want[i] == (Vec3::ZERO, false))
            .collect();
        assert!(
            outside.len() > 100,
            "spot {inner}-{outer}: the cone fills the image"
        );
        for i in outside {
            assert_eq!(film.pixels[i], [0.0; 3], "spot {inner}-{outer}: pixel {i}");
        }
    }
}

#[test]
fn a_sun_gives_its_irradiance_with_or_without_a_disk() {
    let irradiance = Vec3::new(1.5, 1.2, 0.9);
    let direction = Vec3::new(0.3, 0.2, -1.0).normalize();
    for diameter in [0.0, 20.0] {
        // A disk of radiance E / (pi sin^2 a) wholly above the horizon gives E cos(theta).
        let scene = plane_lit_by(
            LightKind::Sun {
                direction,
                angular_diameter_deg: diameter,
            },
            irradiance,
        );
        let want = expected(&scene, |_| irradiance * -direction.z);
        check(
            &format!("sun of {diameter} degrees"),
            &render(&scene, 64),
            &want,
            0.01,
        );
    }
}

/// Pixel (column, row) of the point (x, y, 0) seen by the test file's camera: at z = 6,
/// looking down -z, vertical field of view 0.9 rad, square image of `size`.
fn pixel_of(x: f32, y: f32, size: u32) -> usize {
    let half = 6.0 * 0.45f32.tan();
    let column = ((x / half * 0.5 + 0.5) * size as f32) as usize;
    let row = ((0.5 - y / half * 0.5) * size as f32) as usize;
    row * size as usize + column
}

#[test]
fn gltf_lights_light_the_pixels_their_nodes_put_them_over() {
    // crates/scene/tests/data/gltf/PunctualLights (its README): a lamp at (-1.5, 0, 0.5), a
    // narrow spot at (1.5, 1, 1) shining down, a sun of 2 W/m^2 at 60 degrees from the
    // ground's normal.
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../scene/tests/data/gltf/PunctualLights/lights.gltf");
    let mut scene = gltf_scene(&path, None).unwrap();
    let size = 48;
    (scene.camera.width, scene.camera.height) = (size, size);
    scene.settings.max_depth = 2;
    let film = render(&scene, 64);
    let value = |x: f32, y: f32| Vec3::from(film.pixels[pixel_of(x, y, size)]).element_sum() / 3.0;
    // Far from the lamp and the spot, the sun alone: the ground's albedo (about 0.78 for
    // glTF's base 0.8 at roughness 1) / pi times 2 cos(60 deg).
    let sun = value(-2.5, -2.5);
    let corners = [value(2.5, -2.5), value(-2.5, 2.5), value(0.0, -2.5)];
    for c in corners {
        assert!(
            (c / sun - 1.0).abs() < 0.03,
            "sunlit ground {c} against {sun}"
        );
    }
    assert!((0.2..0.27).contains(&sun), "the sun alone gives {sun}");
    // Under the lamp (irradiance 1 / 0.5^2 = 4 there): far brighter, and orange.
    let lamp = film.pixels[pixel_of(-1.5, 0.0, size)];
    assert!(lamp[0] > 3.0 * sun && lamp[0] > 1.5 * lamp[2], "{lamp:?}");
    // Under the spot (20 W/sr from 1 up) and just outside its 0.2 rad cone.
    let spot = value(1.5, 1.0);
    assert!(spot > 10.0 * sun, "under the spot: {spot} against {sun}");
    let beside = value(1.5, 1.5);
    assert!(
        (beside / sun - 1.0).abs() < 0.05,
        "beside the spot: {beside}"
    );
}
