//! Click-to-light (SPEC S5): the object under the cursor, found by the renderer's own
//! intersection code (the CPU twin of the WGSL traversal, on the same BVH), and turning it
//! into a light and back.

use std::collections::HashMap;

use glam::Vec3;
use pathlight_core::frame::frame_params;
use pathlight_core::trace::Ray;
use pathlight_core::{GpuScene, Scene};

/// Emission strength when the scene has no emitter to compare with.
const FALLBACK_STRENGTH: f32 = 10.0;

/// Index into `scene.objects` of the nearest object under image point (x, y) (pixels from
/// the top-left corner, fractions allowed), if any.
pub fn pick(scene: &Scene, gpu_scene: &GpuScene, x: f32, y: f32) -> Option<usize> {
    let p = frame_params(scene, gpu_scene);
    let ndc_x = 2.0 * x / p.width as f32 - 1.0;
    let ndc_y = 1.0 - 2.0 * y / p.height as f32;
    let dir = Vec3::from(p.camera_forward)
        + ndc_x * Vec3::from(p.camera_right)
        + ndc_y * Vec3::from(p.camera_up);
    let ray = Ray {
        origin: p.camera_position.into(),
        dir: dir.normalize(),
    };
    let hit = gpu_scene.intersect(&ray, 1e30)?;
    Some(hit.object as usize)
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
                    Some(t) => scene.textures[t as usize].mean_linear(),
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
    use pathlight_core::default_scene;

    fn index_of(scene: &Scene, name: &str) -> usize {
        scene.objects.iter().position(|o| o.name == name).unwrap()
    }

    /// The image point where the camera sees `p`.
    fn project(scene: &Scene, gpu: &GpuScene, p: Vec3) -> (f32, f32) {
        let f = frame_params(scene, gpu);
        let d = p - Vec3::from(f.camera_position);
        let forward = Vec3::from(f.camera_forward);
        let (right, up) = (Vec3::from(f.camera_right), Vec3::from(f.camera_up));
        let d = d / d.dot(forward);
        let ndc_x = (d - forward).dot(right) / right.length_squared();
        let ndc_y = (d - forward).dot(up) / up.length_squared();
        (
            (ndc_x + 1.0) * 0.5 * f.width as f32,
            (1.0 - ndc_y) * 0.5 * f.height as f32,
        )
    }

    #[test]
    fn picks_the_nearest_object_under_the_point() {
        let scene = default_scene::load().unwrap();
        let gpu = GpuScene::build(&scene);
        for (name, centre) in [
            ("gold sphere", Vec3::new(0.2, 0.6, -2.4)),
            ("earth", Vec3::new(-1.2, 0.5, -2.05)),
            ("glass sphere", Vec3::new(0.5, 0.33, -1.05)),
        ] {
            let (x, y) = project(&scene, &gpu, centre);
            let picked = pick(&scene, &gpu, x, y).map(|i| scene.objects[i].name.clone());
            assert_eq!(picked.as_deref(), Some(name), "at ({x}, {y})");
        }
        // The top-left corner sees the ceiling or a wall, never a model.
        let corner = pick(&scene, &gpu, 0.5, 0.5).map(|i| scene.objects[i].name.clone());
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
            lit.lobes,
            own.materials[own.objects[vase].material as usize].lobes
        );
        assert!(GpuScene::build(&scene).light_count > GpuScene::build(&own).light_count);
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
}
