//! Instancing on the CPU backend: a scene whose meshes are placed as instances renders as the
//! same scene with every placement copied into the world, and a light on an instance lights
//! only that placement.

use std::path::Path;

use pathlight_core::{Film, PreparedScene, Renderer};
use pathlight_cpu::CpuRenderer;
use pathlight_scene::testing::flattened;
use pathlight_scene::{Scene, Shape, load_scene_file};

/// `scenes/instances.toml` at `size` x `size`, `spp` samples per pixel, with auxiliary images.
fn instances_scene(size: u32, spp: u32) -> Scene {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/instances.toml");
    let mut scene = load_scene_file(&path).unwrap();
    scene.camera.width = size;
    scene.camera.height = size;
    scene.settings.spp = spp;
    scene.settings.aovs = true;
    scene
}

/// The colour and the normal image of `scene` on the CPU backend.
fn render(scene: &Scene) -> (Film, Film) {
    let prepared = PreparedScene::new(scene).unwrap();
    let mut renderer = CpuRenderer::new(&prepared, &scene.camera, &scene.settings);
    while renderer.samples_done() < scene.settings.spp {
        renderer
            .advance(scene.settings.spp - renderer.samples_done())
            .unwrap();
    }
    let accumulation = renderer.accumulation().unwrap();
    let (w, h) = (scene.camera.width, scene.camera.height);
    let color = Film::from_accumulation(w, h, &accumulation);
    (
        color,
        Film::aovs_from_accumulation(w, h, &accumulation).unwrap().1,
    )
}

/// The instances (rotated, scaled unevenly, one mirrored, smooth normals) look as their
/// flattened copies: the same samples give the same image up to the rounding of the
/// placements (a hit moved by about 1e-6, which may flip a rare discrete choice). The
/// emitting instance is dimmed here: its triangles' light-table entries come in another
/// order than the flattened copy's (each tree's leaf order), so the same sample picks
/// another triangle; `an_emitting_instance_lights_as_its_flattened_copy` compares it.
#[test]
fn instances_render_as_their_meshes_flattened() {
    let mut scene = instances_scene(48, 8);
    let lantern = scene
        .objects
        .iter()
        .position(|o| o.name == "lantern")
        .unwrap();
    scene.objects[lantern].material = scene.objects[0].material;
    let placed = scene
        .objects
        .iter()
        .filter(|o| matches!(o.shape, Shape::Instance(_)))
        .count();
    assert_eq!(placed, 11, "the scene places its mesh 11 times");
    let mut flat = scene.clone();
    flat.objects = flattened(&scene.objects);
    let ((color, normal), (flat_color, flat_normal)) = (render(&scene), render(&flat));
    let close = |a: &Film, b: &Film, tolerance: f32| {
        a.pixels
            .iter()
            .zip(&b.pixels)
            .filter(|(p, q)| (0..3).all(|i| (p[i] - q[i]).abs() <= tolerance * (1.0 + q[i].abs())))
            .count()
    };
    let pixels = color.pixels.len();
    // Measured: every normal and every colour pixel agree.
    let normals = close(&normal, &flat_normal, 1e-3);
    assert_eq!(normals, pixels, "{normals} of {pixels} normals agree");
    let colors = close(&color, &flat_color, 1e-3);
    assert!(
        colors * 100 >= 99 * pixels,
        "{colors} of {pixels} colours agree"
    );
    let (a, b) = (color.mean(), flat_color.mean());
    for i in 0..3 {
        assert!((a[i] - b[i]).abs() <= 0.01 * b[i], "means {a:?} and {b:?}");
    }
}

/// An emitting instance is a light of the scene as its flattened copy is: its triangles'
/// entries in the light table are chosen as often (their placed areas), and the picture it
/// lights has the same mean.
#[test]
fn an_emitting_instance_lights_as_its_flattened_copy() {
    let scene = instances_scene(32, 128);
    let mut flat = scene.clone();
    flat.objects = flattened(&scene.objects);
    let lantern = scene
        .objects
        .iter()
        .position(|o| o.name == "lantern")
        .unwrap() as u32;
    let pmfs = |scene: &Scene| {
        let prepared = PreparedScene::new(scene).unwrap();
        let mut pmfs: Vec<f32> = prepared
            .shading
            .lights
            .iter()
            .filter(|l| l.index == lantern)
            .map(|l| l.pmf)
            .collect();
        pmfs.sort_by(f32::total_cmp);
        pmfs
    };
    let (placed, copied) = (pmfs(&scene), pmfs(&flat));
    assert_eq!(placed.len(), 8, "one entry per triangle of the octahedron");
    for (a, b) in placed.iter().zip(&copied) {
        assert!((a - b).abs() <= 1e-5 * b, "pmf {a} vs {b}");
    }
    let (a, b) = (render(&scene).0.mean(), render(&flat).0.mean());
    // Measured: 0.1% apart at most.
    for i in 0..3 {
        assert!((a[i] - b[i]).abs() <= 0.01 * b[i], "means {a:?} and {b:?}");
    }
}
