//! The auxiliary images a denoiser reads (albedo and shading normal of the first surface
//! that is not a perfect mirror or glass), on the CPU backend: exact where the answer is
//! known, unit normals facing the camera, and sums that resume exactly; computing them
//! leaves the colour as it was, bit for bit. (The GPU twin is compared with these in
//! `crates/gpu/tests/gpu/twin.rs`.)

use glam::{Vec2, Vec3};
use pathlight_core::gpu_types::GpuRenderParams;
use pathlight_core::{Film, PreparedScene, Renderer};
use pathlight_cpu::CpuRenderer;
use pathlight_cpu::camera::primary_ray;
use pathlight_scene::testing::{object, scene_of};
use pathlight_scene::{Environment, Lobes, Material, Model, Scene, Shape, load_scene_file};

fn repo() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// `scene` rendered to `spp` on the CPU backend.
fn renderer(scene: &Scene, spp: u32) -> CpuRenderer {
    let prepared = PreparedScene::new(scene).unwrap();
    let mut renderer = CpuRenderer::new(&prepared, &scene.camera, &scene.settings);
    while renderer.samples_done() < spp {
        renderer.advance(spp - renderer.samples_done()).unwrap();
    }
    renderer
}

/// `scene` rendered to `spp` with its auxiliary images: the renderer, the colour and the
/// albedo and normal images.
fn render(scene: &Scene, spp: u32) -> (CpuRenderer, Film, (Film, Film)) {
    let renderer = renderer(scene, spp);
    let (width, height) = renderer.size();
    let accumulation = renderer.accumulation().unwrap();
    let aovs = Film::aovs_from_accumulation(width, height, &accumulation).unwrap();
    let colour = renderer.film().unwrap();
    (renderer, colour, aovs)
}

/// A wall filling the view reads its reflectance as albedo and its normal, exactly, in every
/// pixel; a rough conductor reads its reflectance at normal incidence.
#[test]
fn a_wall_reads_its_reflectance_and_normal() {
    let wall = Shape::Quad {
        origin: Vec3::new(-5.0, -5.0, -1.0),
        edge_u: Vec3::new(10.0, 0.0, 0.0),
        edge_v: Vec3::new(0.0, 10.0, 0.0),
    };
    let mut scene = scene_of(vec![object("wall", wall)]);
    scene.environment = Environment::Constant(Vec3::ONE);
    scene.settings.aovs = true;
    let reflectance = Vec3::new(0.25, 0.5, 0.75);
    scene.materials[0] = Material::new("paint", reflectance, Model::Lobes(Lobes::DIFFUSE));
    let (_, _, (albedo, normal)) = render(&scene, 3);
    for (a, n) in albedo.pixels.iter().zip(&normal.pixels) {
        assert!(
            (Vec3::from(*a) - reflectance).abs().max_element() < 1e-6,
            "{a:?}"
        );
        assert!(
            (Vec3::from(*n) - Vec3::Z).abs().max_element() < 1e-6,
            "{n:?}"
        );
    }
    // A rough mirror of white Schlick F0 1 (the `metal` preset on a white base) reads 1.
    scene.materials[0] = Material::new(
        "metal",
        Vec3::ONE,
        Model::Lobes(Lobes::preset("metal").unwrap()),
    );
    let (_, _, (albedo, _)) = render(&scene, 2);
    assert!(
        albedo
            .pixels
            .iter()
            .all(|a| a.iter().all(|c| (c - 1.0).abs() < 1e-6))
    );
}

/// In a room of matte walls every pixel's normal has at most unit length (unit where the
/// pixel sees one surface), faces the camera, and computing the auxiliary images does not
/// change the colour.
#[test]
fn normals_are_unit_and_face_the_camera() {
    let mut scene = load_scene_file(&repo().join("scenes/refs/cornell-diffuse.toml")).unwrap();
    (scene.camera.width, scene.camera.height) = (24, 24);
    let plain_scene = scene.clone();
    scene.settings.aovs = true;
    let (_, colour, (_, normal)) = render(&scene, 4);
    let plain = renderer(&plain_scene, 4).film().unwrap();
    assert!(colour == plain, "the auxiliary images changed the colour");
    let params = GpuRenderParams::new(
        &scene.camera,
        &scene.settings,
        &PreparedScene::new(&scene).unwrap().shading,
    );
    let mut unit = 0;
    for y in 0..24 {
        for x in 0..24 {
            let n = Vec3::from(normal.pixel(x, y));
            let ray = primary_ray(&params, Vec2::new(x as f32 + 0.5, y as f32 + 0.5));
            assert!(n.length() <= 1.0 + 1e-5, "({x}, {y}): {n}");
            assert!(
                n.dot(ray.dir) < 0.0,
                "({x}, {y}): {n} does not face the camera"
            );
            unit += usize::from(n.length() > 0.999);
        }
    }
    // Only the pixels on an edge between two walls or boxes average two normals.
    assert!(unit * 10 >= 24 * 24 * 7, "only {unit} unit normals");
}

/// A render stopped mid-pass and resumed in another renderer has the uninterrupted one's
/// auxiliary images, bit for bit.
#[test]
fn resumed_auxiliary_images_equal_the_whole_ones() {
    let mut scene = load_scene_file(&repo().join("scenes/refs/cornell-spheres.toml")).unwrap();
    (scene.camera.width, scene.camera.height) = (16, 16);
    scene.settings.aovs = true;
    let (_, whole, whole_aovs) = render(&scene, 5);
    let (mut first, _, _) = render(&scene, 2);
    first.step_frame(std::time::Duration::ZERO).unwrap();
    let saved = first.accumulation().unwrap();
    assert!(saved.cursor.in_pass() && saved.has_aovs());
    let mut resumed = renderer(&scene, 0);
    resumed.resume(&saved).unwrap();
    while resumed.samples_done() < 5 {
        resumed.advance(5 - resumed.samples_done()).unwrap();
    }
    assert!(resumed.film().unwrap() == whole);
    let aovs = Film::aovs_from_accumulation(16, 16, &resumed.accumulation().unwrap()).unwrap();
    assert!(aovs == whole_aovs);
}
