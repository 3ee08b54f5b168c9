//! The GPU integrator against its CPU twin: the same samples of the same pixels through the
//! same code give the same image, up to float differences that may flip a rare discrete
//! choice (lobe, roulette). Checked on every material and emitter kind, and on the
//! auxiliary images.

use glam::Vec3;
use pathlight_core::{Film, PreparedScene, Renderer};
use pathlight_scene::{LightKind, MetalRough, Model, Scene};

use crate::common::{gpu_renderer, render, render_cpu, render_to, scene};

#[test]
fn gpu_and_cpu_render_the_same_image() {
    // Per scene: how close a pixel must be (relative, over 1 + its value). The sun of
    // env-sun is a steep function of direction (30000 beside 10 one texel away), and the
    // software adapter's atan2, acos, sin and cos differ from the CPU's by about 1e-4 rad
    // there: up to 1% in the pixels it lights (0.1% seen directly); the image means agree
    // to 1e-4.
    for (name, tolerance) in [
        ("refs/cornell-spheres.toml", 1e-3),
        ("refs/cornell-materials.toml", 1e-3),
        ("refs/env-sun.toml", 1e-2),
        ("refs/cornell-dof.toml", 1e-3),
        ("default.toml", 1e-3),
        ("refs/lights.toml", 1e-3),
        ("instances.toml", 1e-3),
        ("soft lights", 1e-3),
    ] {
        let s = if name == "soft lights" {
            soft_lights()
        } else {
            scene(name, 40, 4, 2)
        };
        let gpu = render(&s);
        let cpu = render_cpu(&s);
        let close = gpu
            .pixels
            .iter()
            .zip(&cpu.pixels)
            .filter(|(g, c)| (0..3).all(|i| (g[i] - c[i]).abs() <= tolerance * (1.0 + c[i].abs())))
            .count();
        // Measured at 40x40, 4 spp: 1600, 1600, 1600, 1600 and 1595 of 1600 pixels agree (and
        // the lights scenes: see the output).
        println!("{name}: {close} of {} pixels agree", gpu.pixels.len());
        assert!(
            close * 100 >= 99 * gpu.pixels.len(),
            "{name}: only {close} of {} pixels agree",
            gpu.pixels.len()
        );
        let (g, c) = (gpu.mean(), cpu.mean());
        for i in 0..3 {
            assert!(
                (g[i] - c[i]).abs() <= 0.01 * c[i],
                "{name}: GPU mean {g:?}, CPU mean {c:?}"
            );
        }
    }
}

/// The lights reference scene with every light made soft: the point light a sphere, the
/// spot's edge smooth (and its light from a sphere too), the sun a disk of 5 degrees; and
/// its white sphere a glTF dielectric with a coloured `KHR_materials_specular`, its blue one
/// a sheen under a clear coat, its gold one solid glass that absorbs (`KHR_materials_volume`).
fn soft_lights() -> Scene {
    let mut s = scene("refs/lights.toml", 40, 4, 2);
    let white = s.materials.iter_mut().find(|m| m.name == "white").unwrap();
    white.model = Model::MetalRough(MetalRough {
        roughness: 0.4,
        specular: 0.6,
        specular_color: Vec3::new(1.0, 0.5, 2.0),
        ..MetalRough::DEFAULT
    });
    let gold = s.materials.iter_mut().find(|m| m.name == "gold").unwrap();
    gold.model = Model::MetalRough(MetalRough {
        roughness: 0.1,
        transmission: 1.0,
        thin: false,
        attenuation: Vec3::new(0.3, 1.0, 3.0),
        ..MetalRough::DEFAULT
    });
    let blue = s.materials.iter_mut().find(|m| m.name == "blue").unwrap();
    blue.model = Model::MetalRough(MetalRough {
        roughness: 0.8,
        clearcoat: 1.0,
        clearcoat_roughness: 0.2,
        sheen_color: Vec3::new(1.0, 0.6, 0.3),
        sheen_roughness: 0.3,
        ..MetalRough::DEFAULT
    });
    for light in &mut s.lights {
        match &mut light.kind {
            LightKind::Point { radius, cone, .. } => {
                *radius = 0.2;
                if let Some(cone) = cone {
                    cone.inner_deg = 10.0;
                }
            }
            LightKind::Sun {
                angular_diameter_deg,
                ..
            } => *angular_diameter_deg = 5.0,
        }
    }
    s
}

/// With auxiliary images the colour is the same bit for bit, and the auxiliary images of the
/// two backends agree as the colour does (the albedo and normal of the same first surfaces).
#[test]
fn gpu_and_cpu_render_the_same_auxiliary_images() {
    for name in ["default.toml", "refs/cornell-materials.toml"] {
        let plain = scene(name, 32, 2, 5);
        let mut s = plain.clone();
        s.settings.aovs = true;
        let mut gpu = gpu_renderer(&s);
        let colour = render_to(&mut gpu, 2);
        assert!(colour == render(&plain), "{name}: the colour changed");
        let gpu = Film::aovs_from_accumulation(32, 32, &gpu.accumulation().unwrap()).unwrap();
        let prepared = PreparedScene::new(&s).unwrap();
        let mut cpu = pathlight_cpu::CpuRenderer::new(&prepared, &s.camera, &s.settings);
        render_to(&mut cpu, 2);
        let cpu = Film::aovs_from_accumulation(32, 32, &cpu.accumulation().unwrap()).unwrap();
        for (what, g, c) in [("albedo", &gpu.0, &cpu.0), ("normal", &gpu.1, &cpu.1)] {
            let close = g
                .pixels
                .iter()
                .zip(&c.pixels)
                .filter(|(g, c)| (0..3).all(|i| (g[i] - c[i]).abs() <= 1e-3))
                .count();
            println!("{name}, {what}: {close} of {} pixels agree", g.pixels.len());
            assert!(
                close * 100 >= 99 * g.pixels.len(),
                "{name}, {what}: only {close} of {} pixels agree",
                g.pixels.len()
            );
        }
    }
}
