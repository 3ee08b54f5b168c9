//! Click-to-light: the object under the cursor, found by the renderer's own code (the CPU
//! twins of the WGSL camera ray and traversal, on the same BVH), and turning it into a
//! light and back.

use std::collections::HashMap;

use glam::{Vec2, Vec3};
use pathlight_core::PreparedScene;
use pathlight_core::gpu_types::GpuRenderParams;
use pathlight_cpu::camera::primary_ray;
use pathlight_cpu::{CpuScene, Tracer};
use pathlight_scene::Scene;

/// Emission strength when the scene has no emitter to compare with.
const FALLBACK_STRENGTH: f32 = 10.0;

/// The nearest surface under a point of the image.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Picked {
    /// Index into `scene.objects`.
    pub object: usize,
    /// Distance of the hit point from the eye along the view direction (a focus distance).
    pub depth: f32,
}

/// The nearest object of `prepared` (the scene prepared) under image point (x, y) (pixels
/// from the top-left corner, fractions allowed) seen through the pinhole at the lens
/// centre, if any.
pub fn pick(scene: &Scene, prepared: &PreparedScene, x: f32, y: f32) -> Option<Picked> {
    let params = GpuRenderParams::new(&scene.camera, &scene.settings, &prepared.shading);
    let ray = primary_ray(&params, Vec2::new(x, y));
    let view = CpuScene::new(prepared);
    let hit = Tracer::new(&view).intersect(&ray, 1e30)?;
    Some(Picked {
        object: hit.object as usize,
        depth: hit.t * ray.dir.dot(Vec3::from(params.camera.forward)),
    })
}

/// Turns objects into lights and back, remembering each one's own material.
#[derive(Debug)]
pub struct LightSwitch {
    /// Emitted radiance of a lit object per unit of its base colour.
    strength: f32,
    /// Object index to the material it had before it was toggled.
    saved: HashMap<usize, u32>,
}

impl LightSwitch {
    /// A switch lighting objects at `strength` times their base colour; without a strength,
    /// as bright as the scene's brightest emitter (per channel), so a lit object is clearly
    /// a light of the scene's kind.
    pub fn new(scene: &Scene, strength: Option<f32>) -> Self {
        let brightest = scene
            .materials
            .iter()
            .map(|m| m.emission.max_element())
            .fold(0.0, f32::max);
        let strength = strength.unwrap_or(if brightest > 0.0 {
            brightest
        } else {
            FALLBACK_STRENGTH
        });
        Self {
            strength,
            saved: HashMap::new(),
        }
    }

    /// Toggles object `object` between its own material and a light (an emitter of the
    /// scene is switched off instead); returns whether it emits now.
    pub fn toggle(&mut self, scene: &mut Scene, object: usize) -> bool {
        let current = scene.objects[object].material;
        if let Some(original) = self.saved.remove(&object) {
            scene.objects[object].material = original;
        } else {
            let own = &scene.materials[current as usize];
            let mut switched = own.clone();
            switched.emission = if own.emission.max_element() > 0.0 {
                Vec3::ZERO
            } else {
                let color = match own.texture {
                    Some(t) => scene.textures[t.texture as usize].mean_linear(),
                    None => own.base_color,
                };
                color * self.strength
            };
            switched.name = format!("{} (toggled)", own.name);
            scene.materials.push(switched);
            scene.objects[object].material = (scene.materials.len() - 1) as u32;
            self.saved.insert(object, current);
        }
        let material = &scene.materials[scene.objects[object].material as usize];
        material.emission.max_element() > 0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use pathlight_scene::default_scene;

    fn index_of(scene: &Scene, name: &str) -> usize {
        scene.objects.iter().position(|o| o.name == name).unwrap()
    }

    /// The image point where the camera sees `p`.
    fn project(scene: &Scene, p: Vec3) -> (f32, f32) {
        let c = pathlight_core::gpu_types::GpuCamera::new(&scene.camera);
        let d = p - Vec3::from(c.position);
        let forward = Vec3::from(c.forward);
        let (right, up) = (Vec3::from(c.right), Vec3::from(c.up));
        let d = d / d.dot(forward);
        let ndc_x = (d - forward).dot(right) / right.length_squared();
        let ndc_y = (d - forward).dot(up) / up.length_squared();
        (
            (ndc_x + 1.0) * 0.5 * scene.camera.width as f32,
            (1.0 - ndc_y) * 0.5 * scene.camera.height as f32,
        )
    }

    #[test]
    fn picks_the_nearest_object_under_the_point() {
        let scene = default_scene::load().unwrap();
        let prepared = PreparedScene::new(&scene).unwrap();
        for (name, centre) in [
            ("gold sphere", Vec3::new(0.2, 0.6, -2.4)),
            ("earth", Vec3::new(-1.2, 0.5, -2.05)),
            ("glass sphere", Vec3::new(0.5, 0.33, -1.05)),
        ] {
            let (x, y) = project(&scene, centre);
            let picked =
                pick(&scene, &prepared, x, y).map(|p| scene.objects[p.object].name.clone());
            assert_eq!(picked.as_deref(), Some(name), "at ({x}, {y})");
        }
        // The top-left corner sees the ceiling or a wall, never a model.
        let corner =
            pick(&scene, &prepared, 0.5, 0.5).map(|p| scene.objects[p.object].name.clone());
        assert!(
            corner
                .as_ref()
                .is_some_and(|n| n.contains("wall") || n == "ceiling"),
            "{corner:?}"
        );
    }

    #[test]
    fn toggling_lights_an_object_and_restores_its_material() {
        let mut scene = default_scene::load().unwrap();
        let own = scene.clone();
        let mut switch = LightSwitch::new(&scene, None);
        let vase = index_of(&scene, "vase");
        assert!(switch.toggle(&mut scene, vase), "the vase becomes a light");
        let lit = &scene.materials[scene.objects[vase].material as usize];
        let base = own.materials[own.objects[vase].material as usize].base_color;
        // As bright as the scene's brightest emitter (16) times its base colour.
        assert!(
            (lit.emission - base * 16.0).length() < 1e-4,
            "{:?}",
            lit.emission
        );
        assert_eq!(
            lit.model,
            own.materials[own.objects[vase].material as usize].model
        );
        let prepared = PreparedScene::new(&own).unwrap();
        let lights = |s: &Scene| prepared.shading_of(s).light_count;
        assert!(lights(&scene) > lights(&own));
        assert!(
            !switch.toggle(&mut scene, vase),
            "a second click turns it off"
        );
        assert_eq!(scene.objects[vase].material, own.objects[vase].material);
    }

    #[test]
    fn a_scene_light_is_switched_off_and_back_on() {
        let mut scene = default_scene::load().unwrap();
        let mut switch = LightSwitch::new(&scene, Some(5.0));
        let light = index_of(&scene, "left light");
        assert!(!switch.toggle(&mut scene, light));
        assert!(switch.toggle(&mut scene, light));
        let m = &scene.materials[scene.objects[light].material as usize];
        assert_eq!(m.emission, Vec3::new(16.0, 15.0, 13.0));
    }

    #[test]
    fn a_textured_object_glows_in_its_mean_texture_colour() {
        let mut scene = default_scene::load().unwrap();
        let mut switch = LightSwitch::new(&scene, Some(2.0));
        let earth = index_of(&scene, "earth");
        assert!(switch.toggle(&mut scene, earth));
        let e = scene.materials[scene.objects[earth].material as usize].emission;
        // The Blue Marble is dark blue on average: blue dominates, all channels well under 2.
        assert!(
            e.z > e.x && e.max_element() < 1.0 && e.min_element() > 0.0,
            "{e}"
        );
    }

    /// Clicking one placement of a shared mesh picks that placement, and lighting it makes
    /// it alone a light: the other placements of the mesh stay as they were.
    #[test]
    fn picking_an_instance_lights_that_placement_alone() {
        let path =
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/instances.toml");
        let mut scene = pathlight_scene::load_scene_file(&path).unwrap();
        let prepared = PreparedScene::new(&scene).unwrap();
        let gold = index_of(&scene, "gold gem");
        let (x, y) = project(&scene, Vec3::new(-0.45, -0.55, -0.45));
        let picked = pick(&scene, &prepared, x, y).map(|p| p.object);
        assert_eq!(picked, Some(gold), "at ({x}, {y})");
        let mut switch = LightSwitch::new(&scene, Some(3.0));
        assert!(switch.toggle(&mut scene, gold));
        let shading = prepared.shading_of(&scene);
        let lit: std::collections::BTreeSet<u32> = shading
            .lights
            .iter()
            .filter(|l| l.kind == pathlight_core::gpu_types::LIGHT_AREA)
            .map(|l| l.index)
            .collect();
        let names: Vec<&str> = lit
            .iter()
            .map(|&i| scene.objects[i as usize].name.as_str())
            .collect();
        assert_eq!(names, ["light", "gold gem", "lantern"]);
        let entries = |object: usize| {
            shading
                .lights
                .iter()
                .filter(|l| l.index == object as u32)
                .count()
        };
        assert_eq!(entries(gold), 8, "one entry per triangle of the placement");
    }
}
