//! Beer-Lambert absorption inside a solid glTF material (`KHR_materials_volume`): a slab of
//! thickness d of a clear interface (ior 1: no reflection, no bending) with absorption
//! coefficient sigma, in a uniform sky of radiance 1, shows `exp(-sigma d / cos)` through
//! it, `cos` the cosine of the camera ray with the slab's normal, to 0.1%.

use glam::{Vec2, Vec3};
use pathlight_core::gpu_types::GpuRenderParams;
use pathlight_core::{PreparedScene, Renderer};
use pathlight_cpu::CpuRenderer;
use pathlight_cpu::camera::primary_ray;
use pathlight_scene::testing::{mesh_of, object, scene_of};
use pathlight_scene::{Camera, Environment, Material, MetalRough, Model, Shape};

/// The 12 triangles of the box from `lo` to `hi`, counter-clockwise seen from outside.
fn box_triangles(lo: Vec3, hi: Vec3) -> Vec<[Vec3; 3]> {
    let corner = |i: usize| {
        Vec3::new(
            if i & 1 != 0 { hi.x } else { lo.x },
            if i & 2 != 0 { hi.y } else { lo.y },
            if i & 4 != 0 { hi.z } else { lo.z },
        )
    };
    // Each face's corners in counter-clockwise order seen from outside.
    let faces = [
        [0, 4, 6, 2], // -x
        [1, 3, 7, 5], // +x
        [0, 1, 5, 4], // -y
        [2, 6, 7, 3], // +y
        [0, 2, 3, 1], // -z
        [4, 5, 7, 6], // +z
    ];
    faces
        .iter()
        .flat_map(|f| {
            let [a, b, c, d] = f.map(corner);
            [[a, b, c], [a, c, d]]
        })
        .collect()
}

#[test]
fn an_absorbing_slab_transmits_exp_of_minus_sigma_d() {
    let (thickness, sigma) = (0.5f32, Vec3::new(0.5, 1.0, 2.0));
    let slab = box_triangles(
        Vec3::new(-5.0, -5.0, -thickness / 2.0),
        Vec3::new(5.0, 5.0, thickness / 2.0),
    );
    let mut scene = scene_of(vec![object("slab", Shape::Mesh(mesh_of(&slab)))]);
    scene.materials[0] = Material::new(
        "absorbing",
        Vec3::ONE,
        Model::MetalRough(MetalRough {
            roughness: 0.0,
            transmission: 1.0,
            ior: 1.0,
            thin: false,
            attenuation: sigma,
            ..MetalRough::DEFAULT
        }),
    );
    scene.environment = Environment::Constant(Vec3::ONE);
    let size = 16;
    scene.camera = Camera {
        position: Vec3::Z * 4.0,
        look_at: Vec3::ZERO,
        up: Vec3::Y,
        // Narrow, so that the path length varies little within a pixel (the pixel jitter's
        // 16 samples would otherwise add their own error).
        fov_y_deg: 4.0,
        width: size,
        height: size,
        aperture_radius: 0.0,
        focus_distance: 4.0,
    };
    let prepared = PreparedScene::new(&scene).unwrap();
    let mut renderer = CpuRenderer::new(&prepared, &scene.camera, &scene.settings);
    renderer.advance(16).unwrap();
    let film = renderer.film().unwrap();
    let params = GpuRenderParams::new(&scene.camera, &scene.settings, &prepared.shading);
    let mut worst = 0.0f32;
    for y in 0..size {
        for x in 0..size {
            // The pixel's mean over 8 x 8 points of it.
            let mut want = Vec3::ZERO;
            for i in 0..64 {
                let film = Vec2::new(
                    x as f32 + ((i % 8) as f32 + 0.5) / 8.0,
                    y as f32 + ((i / 8) as f32 + 0.5) / 8.0,
                );
                let cos = -primary_ray(&params, film).dir.z;
                want += (-sigma * thickness / cos).exp();
            }
            want /= 64.0;
            let got = Vec3::from(film.pixel(x, y));
            let off = ((got - want).abs() / want).max_element();
            worst = worst.max(off);
            assert!(off < 1e-3, "pixel ({x}, {y}): {got} against {want}");
        }
    }
    println!("worst pixel {worst:.2e} relative");
    // Without absorption the slab is invisible.
    let Model::MetalRough(m) = &mut scene.materials[0].model else {
        unreachable!()
    };
    m.attenuation = Vec3::ZERO;
    let prepared = PreparedScene::new(&scene).unwrap();
    let mut renderer = CpuRenderer::new(&prepared, &scene.camera, &scene.settings);
    renderer.advance(4).unwrap();
    assert!(
        renderer
            .film()
            .unwrap()
            .pixels
            .iter()
            .all(|p| *p == [1.0; 3])
    );
}
