//! Legal but extreme values never produce NaN or Inf: roughness 0 and 1, a roughness that
//! rounds to a smooth lobe, ior 1 and ior below 1, zero-area and tiny emitters, a camera
//! ray grazing a quad, and the environment. The raw samples of
//! the CPU twin are checked one by one (the film drops non-finite samples, so checking it
//! alone would prove nothing); the GPU, the same code, must then agree with it.

use pathlight_core::PreparedScene;
use pathlight_core::gpu_types::GpuRenderParams;
use pathlight_cpu::integrator::trace_path;
use pathlight_cpu::sampler::Sampler;
use pathlight_cpu::{CpuScene, Tracer};
use pathlight_scene::{Scene, SceneSource, load_scene};

use crate::common::{gpu_renderer, render, render_counting_dropped, render_cpu};

const SCENE: &str = r#"
color_space = "linear"
[camera]
position = [0, 0, 3]
look_at = [0, 0, 0]
fov_y = 60
resolution = [32, 32]
[render]
spp = 16
max_depth = 12
rr_depth = 3
[environment]
radiance = [0.5, 0.5, 0.5]
[materials.rough_one]
conductor = "aluminium"
specular_roughness = 1
[materials.nearly_smooth]
specular_rate = 0.5
specular_roughness = 0.01
[materials.ior_one]
refract_rate = 1
ior = 1
refract_roughness = 0.3
[materials.ior_below_one]
refract_rate = 0.7
ior = 0.6
[materials.rough_glass_full]
refract_rate = 1
refract_roughness = 1
[materials.glow]
color = [0, 0, 0]
emission = [5, 5, 5]
[[quad]]
name = "grazed floor"
material = "rough_one"
origin = [-2, 0, -2]
edge_u = [0, 0, 4]
edge_v = [4, 0, 0]
[[quad]]
name = "zero-area light"
material = "glow"
origin = [0, 1, 0]
edge_u = [1, 0, 0]
edge_v = [0, 0, 0]
[[quad]]
name = "facing light"
material = "glow"
origin = [-0.5, -0.5, 0]
edge_u = [1, 0, 0]
edge_v = [0, 1, 0]
[[sphere]]
name = "tiny light"
material = "glow"
center = [0.8, 0.8, 0]
radius = 0.0001
[[sphere]]
material = "nearly_smooth"
center = [-0.8, 0.5, -0.5]
radius = 0.4
[[sphere]]
material = "ior_one"
center = [0.8, -0.5, -0.5]
radius = 0.4
[[sphere]]
material = "ior_below_one"
center = [-0.8, -0.6, 0.3]
radius = 0.3
[[cylinder]]
material = "rough_glass_full"
p0 = [0.3, -1, 0.5]
p1 = [0.3, -0.2, 0.5]
radius = 0.2
"#;

/// The scene of extreme legal values above.
fn extreme_scene() -> Scene {
    load_scene(&SceneSource {
        name: "extreme".into(),
        text: SCENE,
        base_dir: ".".into(),
        embedded: &[],
    })
    .unwrap()
}

#[test]
fn extreme_values_give_finite_samples_on_both_backends() {
    let mut s = extreme_scene();
    // The camera looks along the floor plane: y = 0 exactly.
    s.camera.position.y = 0.0;
    s.camera.look_at.y = 0.0;
    let prepared = PreparedScene::new(&s).unwrap();
    let params = GpuRenderParams::new(&s.camera, &s.settings, &prepared.shading);
    let cpu_scene = CpuScene::new(&prepared);
    let mut tracer = Tracer::new(&cpu_scene);
    let mut nonzero = 0;
    for y in 0..32 {
        for x in 0..32 {
            for i in 0..16 {
                let sampler = Sampler::new(params.sampler, y * 32 + x, i, params.seed);
                let l = trace_path(&mut tracer, &cpu_scene, &params, x, y, sampler).radiance;
                assert!(
                    l.is_finite() && l.min_element() >= 0.0,
                    "pixel ({x}, {y}) sample {i}: {l}"
                );
                nonzero += usize::from(l.max_element() > 0.0);
            }
        }
    }
    assert!(
        nonzero > 8000,
        "the scene is lit: {nonzero} of 16384 samples carry light"
    );
    let cpu = render_cpu(&s);
    let gpu = render(&s);
    assert!(gpu.pixels.iter().flatten().all(|c| c.is_finite()));
    let (g, c) = (gpu.mean(), cpu.mean());
    for i in 0..3 {
        assert!(
            (g[i] - c[i]).abs() <= 0.01 * c[i],
            "GPU mean {g:?}, CPU mean {c:?}"
        );
    }
}

/// A sample that is not finite is dropped, not hidden: a scene whose light emits NaN (no
/// file can say so; a program can) makes both backends count every sample that saw it, and
/// the image stays finite.
#[test]
fn non_finite_samples_are_counted_on_both_backends() {
    let mut s = extreme_scene();
    s.camera.width = 16;
    s.camera.height = 16;
    s.settings.spp = 2;
    for m in &mut s.materials {
        if m.emission.max_element() > 0.0 {
            m.emission.x = f32::NAN;
        }
    }
    let prepared = PreparedScene::new(&s).unwrap();
    let mut cpu = pathlight_cpu::CpuRenderer::new(&prepared, &s.camera, &s.settings);
    let (cpu_film, cpu_dropped) = render_counting_dropped(&mut cpu, 2);
    let (gpu_film, gpu_dropped) = render_counting_dropped(&mut gpu_renderer(&s), 2);
    for (name, film, dropped) in [
        ("CPU", cpu_film, cpu_dropped),
        ("GPU", gpu_film, gpu_dropped),
    ] {
        assert!(dropped > 10, "{name}: {dropped} of 512 samples counted");
        assert!(
            film.pixels.iter().flatten().all(|c| c.is_finite()),
            "{name}"
        );
    }
}
