//! glTF import: the samples of Debian's `assimp-testmodels` (`tests/data/gltf`, provenance
//! in its README) load with the right geometry, cameras and materials, every malformed one
//! is refused naming the element, and hand-made files check node transforms, texture
//! transforms, data URIs and `[[gltf]]` in a scene file.

use std::path::{Path, PathBuf};

use base64::Engine;
use glam::{Mat4, Quat, Vec3, Vec4};
use pathlight_scene::{
    AlphaMode, Environment, LightKind, Model, Scene, SceneSource, Shape, TextureRef, TriangleMesh,
    gltf_scene, load_gltf, load_scene,
};

fn data(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/gltf")
        .join(path)
}

fn meshes(scene: &Scene) -> Vec<&TriangleMesh> {
    scene
        .objects
        .iter()
        .filter_map(|o| match &o.shape {
            Shape::Mesh(m) => Some(m),
            _ => None,
        })
        .collect()
}

fn area(mesh: &TriangleMesh) -> f32 {
    mesh.indices
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| mesh.positions[i as usize]);
            0.5 * (b - a).cross(c - a).length()
        })
        .sum()
}

#[test]
fn the_textured_box_loads_from_glb_and_from_data_uris_alike() {
    let glb = gltf_scene(&data("BoxTextured-glTF-Binary/BoxTextured.glb"), None).unwrap();
    let embedded = gltf_scene(&data("BoxTextured-glTF-Embedded/BoxTextured.gltf"), None).unwrap();
    for scene in [&glb, &embedded] {
        let meshes = meshes(scene);
        assert_eq!(meshes.len(), 1);
        assert_eq!(meshes[0].indices.len(), 12, "a box has 12 triangles");
        // A unit cube: 6 square faces of area 1.
        assert!((area(meshes[0]) - 6.0).abs() < 1e-4, "{}", area(meshes[0]));
        assert_eq!(scene.materials.len(), 1);
        let texture = scene.materials[0].texture.expect("a base colour texture");
        let image = &scene.textures[texture.texture as usize];
        assert_eq!((image.width, image.height), (211, 211));
        // No light in the file: the grey sky lights it.
        assert_eq!(scene.environment, Environment::Constant(Vec3::splat(0.8)));
    }
    assert_eq!(meshes(&glb)[0].positions, meshes(&embedded)[0].positions);
    assert_eq!(glb.textures, embedded.textures);
}

#[test]
fn a_model_without_cameras_is_framed_from_the_front() {
    let scene = gltf_scene(&data("BoxTextured-glTF-Binary/BoxTextured.glb"), None).unwrap();
    let c = &scene.camera;
    // The unit cube's centre is the origin; the camera looks at it from +z and above,
    // far enough that its bounding sphere (radius sqrt(3)/2) fills the 40 degree view.
    assert!(c.look_at.length() < 1e-5, "{}", c.look_at);
    let distance = c.position.length();
    let expected = 0.75f32.sqrt() / 20f32.to_radians().sin();
    assert!(
        (distance - expected).abs() < 1e-4,
        "{distance} vs {expected}"
    );
    assert!(c.position.z > 0.0 && c.position.y > 0.0);
    assert_eq!((c.width, c.height), (1280, 720));
}

#[test]
fn the_first_perspective_camera_is_used_and_others_by_number() {
    let path = data("cameras/Cameras.gltf");
    let scene = gltf_scene(&path, None).unwrap();
    let c = &scene.camera;
    // Node 1: translation (0.5, 0.5, 3), looking down -z, yfov 0.7 rad, aspect 1.
    assert!(c.position.distance(Vec3::new(0.5, 0.5, 3.0)) < 1e-6);
    assert!((c.look_at - c.position).normalize().distance(Vec3::NEG_Z) < 1e-6);
    assert!((c.fov_y_deg - 0.7f32.to_degrees()).abs() < 1e-4);
    assert_eq!(c.width, c.height);
    // The second camera is orthographic: skipped, so there is no camera 1.
    let err = gltf_scene(&path, Some(1)).unwrap_err().to_string();
    assert!(
        err.contains("has no camera 1: it has 1 perspective camera"),
        "{err}"
    );
    assert!(gltf_scene(&path, Some(0)).is_ok());
}

#[test]
fn strips_fans_and_lists_draw_the_same_square() {
    for n in ["04", "05", "06", "11", "12"] {
        let file = format!("Mesh_PrimitiveMode/Mesh_PrimitiveMode_{n}.gltf");
        let scene = gltf_scene(&data(&file), None).unwrap();
        let mesh = meshes(&scene)[0];
        assert_eq!(mesh.indices.len(), 2, "{file}");
        assert!(
            (area(mesh) - 1.0).abs() < 1e-5,
            "{file}: area {}",
            area(mesh)
        );
        // Counter-clockwise from the front: every triangle faces +z.
        for t in &mesh.indices {
            let [a, b, c] = t.map(|i| mesh.positions[i as usize]);
            assert!((b - a).cross(c - a).z > 0.0, "{file}: {t:?} faces away");
        }
    }
    // Points and lines are skipped, which leaves nothing to render.
    for n in ["00", "01"] {
        let file = format!("Mesh_PrimitiveMode/Mesh_PrimitiveMode_{n}.gltf");
        let err = gltf_scene(&data(&file), None).unwrap_err().to_string();
        assert!(
            err.contains("holds no triangles to render"),
            "{file}: {err}"
        );
    }
}

#[test]
fn every_malformed_sample_is_refused_naming_the_element() {
    let cases = [
        (
            "IndexOutOfRange/IndexOutOfRange.gltf",
            "mesh 0 primitive 0: index 255 is out of range: the primitive has 24 vertices",
        ),
        (
            "IndexOutOfRange/AllIndicesOutOfRange.gltf",
            "index 65535 is out of range",
        ),
        (
            "RecursiveNodes/RecursiveNodes.gltf",
            "node 0: is its own ancestor",
        ),
        ("wrongTypes/badArray.gltf", "expected a sequence at line 44"),
        (
            "wrongTypes/badExtension.gltf",
            "expected struct TextureTransform at line 130",
        ),
        ("wrongTypes/badNumber.gltf", "expected f32 at line 132"),
        ("wrongTypes/badObject.gltf", "at line 125"),
        ("wrongTypes/badString.gltf", "expected a string at line 12"),
        ("wrongTypes/badUint.gltf", "at line 128"),
        (
            "BoxWithInfinites-glTF-Binary/BoxWithInfinites.glb",
            "POSITION\"].min",
        ),
        ("SchemaFailures/sceneWrongType.gltf", "at line 6"),
        ("MissingBin/BoxTextured.gltf", "buffer 0: cannot read"),
        ("TestNoRootNode/NoScene.gltf", "scene: Index out of bounds"),
        (
            "TestNoRootNode/SceneWithoutNodes.gltf",
            "missing field `nodes`",
        ),
        ("IncorrectVertexArrays/Cube.gltf", "meshes[1].primitives[0]"),
    ];
    for (file, expected) in cases {
        let err = gltf_scene(&data(file), None).unwrap_err().to_string();
        assert!(
            err.contains(file),
            "{file}: the error names the file: {err}"
        );
        assert!(err.contains(expected), "{file}: {err}");
    }
}

/// A glTF file with one triangle (positions only, in a data URI) under `nodes_json`.
fn triangle_gltf(dir: &Path, nodes_json: &str, positions: &[[f32; 3]; 3]) -> PathBuf {
    let bytes: Vec<u8> = positions
        .iter()
        .flatten()
        .flat_map(|v| v.to_le_bytes())
        .collect();
    let uri = format!(
        "data:application/octet-stream;base64,{}",
        base64::engine::general_purpose::STANDARD.encode(&bytes)
    );
    let json = format!(
        r#"{{"asset": {{"version": "2.0"}}, "scene": 0, "scenes": [{{"nodes": [0]}}],
        "nodes": {nodes_json},
        "meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0}}}}]}}],
        "buffers": [{{"byteLength": 36, "uri": "{uri}"}}],
        "bufferViews": [{{"buffer": 0, "byteLength": 36}}],
        "accessors": [{{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
            "min": [-10, -10, -10], "max": [10, 10, 10]}}]}}"#
    );
    let path = dir.join("triangle.gltf");
    std::fs::write(&path, json).unwrap();
    path
}

#[test]
fn node_transforms_compose_parent_first_and_mirrors_keep_the_front() {
    let dir = tempfile::tempdir().unwrap();
    let corners = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    // Parent: translate (1, 2, 3) and turn 90 degrees about y; child: scale (2, -1, 1)
    // (a mirror) by matrix, holding the mesh.
    let (x, y, z, w) = (
        0.0,
        std::f32::consts::FRAC_1_SQRT_2,
        0.0,
        std::f32::consts::FRAC_1_SQRT_2,
    );
    let nodes = format!(
        r#"[{{"translation": [1, 2, 3], "rotation": [{x}, {y}, {z}, {w}], "children": [1]}},
           {{"matrix": [2,0,0,0, 0,-1,0,0, 0,0,1,0, 0,0,0,1], "mesh": 0}}]"#
    );
    let path = triangle_gltf(dir.path(), &nodes, &corners);
    let model = load_gltf(&path, Mat4::IDENTITY).unwrap();
    let Shape::Mesh(mesh) = &model.objects[0].shape else {
        panic!("a mesh")
    };
    let world = Mat4::from_rotation_translation(
        Quat::from_rotation_y(std::f32::consts::FRAC_PI_2),
        Vec3::new(1.0, 2.0, 3.0),
    ) * Mat4::from_scale(Vec3::new(2.0, -1.0, 1.0));
    for (i, corner) in corners.iter().enumerate() {
        let expected = world.transform_point3(Vec3::from(*corner));
        assert!(
            mesh.positions[i].distance(expected) < 1e-5,
            "{} vs {expected}",
            mesh.positions[i]
        );
    }
    // By hand: (0,1,0) -> scale (0,-1,0) -> turn (0,-1,0) -> move (1,1,3).
    assert!(mesh.positions[2].distance(Vec3::new(1.0, 1.0, 3.0)) < 1e-5);
    // The mirror reversed the corners, so the front (counter-clockwise in the file, +z
    // there) is the image of +z: the turn sends it to +x.
    let [a, b, c] = mesh.indices[0].map(|i| mesh.positions[i as usize]);
    let front = (b - a).cross(c - a).normalize();
    assert!(front.distance(Vec3::X) < 1e-5, "{front}");
    // No normals in the file: flat shading, as glTF requires.
    assert!(mesh.flat);
    // A placement from the scene file applies after the file's own.
    let moved = load_gltf(&path, Mat4::from_translation(Vec3::Y)).unwrap();
    let Shape::Mesh(moved) = &moved.objects[0].shape else {
        panic!("a mesh")
    };
    assert!(moved.positions[2].distance(Vec3::new(1.0, 2.0, 3.0)) < 1e-5);
}

#[test]
fn bad_hand_made_files_name_the_element() {
    let dir = tempfile::tempdir().unwrap();
    let corners = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [f32::NAN, 1.0, 0.0]];
    let path = triangle_gltf(dir.path(), r#"[{"mesh": 0}]"#, &corners);
    let err = load_gltf(&path, Mat4::IDENTITY).unwrap_err().to_string();
    assert!(
        err.contains("mesh 0 primitive 0: vertex 2 has position"),
        "{err}"
    );
    // A buffer view beyond its buffer.
    let text = std::fs::read_to_string(&path).unwrap().replace(
        r#""byteLength": 36}]"#,
        r#""byteLength": 36, "byteOffset": 12}]"#,
    );
    std::fs::write(&path, text).unwrap();
    let err = load_gltf(&path, Mat4::IDENTITY).unwrap_err().to_string();
    assert!(
        err.contains("POSITION (accessor 0): buffer view 0 lies outside its buffer"),
        "{err}"
    );
    let err = load_gltf(&dir.path().join("absent.glb"), Mat4::IDENTITY)
        .unwrap_err()
        .to_string();
    assert!(err.contains("absent.glb"), "{err}");
    std::fs::write(dir.path().join("junk.glb"), b"glTF\x02\x00\x00\x00junk").unwrap();
    let err = load_gltf(&dir.path().join("junk.glb"), Mat4::IDENTITY)
        .unwrap_err()
        .to_string();
    assert!(err.contains("junk.glb: not a valid glTF file"), "{err}");
}

/// What the `gltf` crate itself panics on (found by `crates/cpu/tests/fuzz.rs`) is refused
/// first, naming the element.
#[test]
fn files_that_crash_the_gltf_crate_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let refused = |name: &str, bytes: &[u8]| {
        let path = dir.path().join(name);
        std::fs::write(&path, bytes).unwrap();
        load_gltf(&path, Mat4::IDENTITY).unwrap_err().to_string()
    };
    // A GLB header whose length is shorter than the header (an unchecked subtraction).
    let mut glb = std::fs::read(data("BoxTextured-glTF-Binary/BoxTextured.glb")).unwrap();
    glb[8..12].copy_from_slice(&3u32.to_le_bytes());
    let err = refused("short.glb", &glb);
    assert!(
        err.contains("GLB header: its length 3 is shorter than the 12-byte header"),
        "{err}"
    );
    // A POSITION naming an accessor the file lacks (validation looks it up unchecked).
    let path = triangle_gltf(dir.path(), r#"[{"mesh": 0}]"#, &[[0.0; 3]; 3]);
    let text = std::fs::read_to_string(&path).unwrap();
    let err = refused(
        "position.gltf",
        text.replace(r#""POSITION": 0"#, r#""POSITION": 7"#)
            .as_bytes(),
    );
    assert!(
        err.contains("mesh 0 primitive 0: POSITION names accessor 7, but the file has 1"),
        "{err}"
    );
    // An image with neither a URI nor a buffer view with a MIME type (unwrapped).
    let text = std::fs::read_to_string(data("BoxTextured-glTF-Embedded/BoxTextured.gltf")).unwrap();
    let images = text.find(r#""images""#).unwrap();
    let uri = images + text[images..].find(r#""uri""#).unwrap();
    let broken = format!("{}\"name\"{}", &text[..uri], &text[uri + 5..]);
    let err = refused("image.gltf", broken.as_bytes());
    assert!(
        err.contains("image 0: needs a uri, or a bufferView with a mimeType"),
        "{err}"
    );
}

#[test]
fn texture_transforms_and_samplers_are_read() {
    let scene = gltf_scene(&data("textureTransform/TextureTransformTest.gltf"), None).unwrap();
    // The rotation quad: rotation 0.392699 rad about the origin, nothing else.
    let rotated = scene
        .materials
        .iter()
        .filter_map(|m| m.texture)
        .find(|t| t.transform[0][1] != 0.0)
        .expect("a rotated texture");
    // The file's number (pi / 8 rounded to 6 digits).
    #[allow(clippy::approx_constant)]
    let (s, c) = 0.392_699f32.sin_cos();
    let expected = [[c, s, 0.0], [-s, c, 0.0]];
    for (row, want) in rotated.transform.iter().zip(expected) {
        for (a, b) in row.iter().zip(want) {
            assert!(
                (a - b).abs() < 1e-6,
                "{:?} vs {expected:?}",
                rotated.transform
            );
        }
    }
    // The file's sampler clamps both axes.
    assert_eq!(rotated.wrap, [pathlight_scene::Wrap::Clamp; 2]);
    assert!(matches!(scene.materials[0].model, Model::MetalRough(_)));
    assert_eq!(scene.materials[0].alpha, AlphaMode::Opaque);
}

#[test]
fn gltf_entries_mix_with_other_shapes_in_a_scene_file() {
    let dir = data("BoxTextured-glTF-Binary");
    let text = r#"
[camera]
position = [0, 1, 4]
look_at = [0, 0, 0]
fov_y = 40
resolution = [64, 64]

[materials.floor]
color = [0.5, 0.5, 0.5]

[materials.shiny]
model = "metal-rough"
metallic = 1.0
roughness = 0.2
color = [0.9, 0.7, 0.3]

[[quad]]
material = "floor"
origin = [-2, -0.5, 2]
edge_u = [4, 0, 0]
edge_v = [0, 0, -4]

[[sphere]]
material = "shiny"
center = [1.5, 0, 0]
radius = 0.5

[[gltf]]
file = "BoxTextured.glb"
transform = { translate = [-1, 0, 0], scale = 0.5 }
"#;
    let scene = load_scene(&SceneSource {
        name: "mixed.toml".into(),
        text,
        base_dir: dir,
        embedded: &[],
    })
    .unwrap();
    assert_eq!(scene.objects.len(), 3);
    assert_eq!(scene.materials.len(), 3);
    let cube = &scene.objects[2];
    assert_eq!(
        cube.material, 2,
        "the file's material comes after the scene's"
    );
    let texture = scene.materials[2].texture.unwrap();
    assert_eq!(texture.texture, 0);
    let Shape::Mesh(mesh) = &cube.shape else {
        panic!("a mesh")
    };
    let (lo, hi) = mesh
        .positions
        .iter()
        .fold((Vec3::MAX, Vec3::MIN), |(lo, hi), &p| {
            (lo.min(p), hi.max(p))
        });
    assert!(lo.distance(Vec3::new(-1.25, -0.25, -0.25)) < 1e-5, "{lo}");
    assert!(hi.distance(Vec3::new(-0.75, 0.25, 0.25)) < 1e-5, "{hi}");
    let Model::MetalRough(shiny) = scene.materials[1].model else {
        panic!("metal-rough from the TOML keys");
    };
    assert_eq!((shiny.metallic, shiny.roughness), (1.0, 0.2));
    let bad = text.replace("BoxTextured.glb", "absent.glb");
    let err = load_scene(&SceneSource {
        name: "mixed.toml".into(),
        text: &bad,
        base_dir: data("BoxTextured-glTF-Binary"),
        embedded: &[],
    })
    .unwrap_err()
    .to_string();
    assert!(
        err.starts_with("mixed.toml:28: gltf.file: cannot read"),
        "{err}"
    );
}

/// A mesh placed by several nodes (one of them mirroring, one reached through a parent) is
/// read once and placed by each as an instance of one shared copy: every placement where its
/// node puts it, none disturbed by the others' transforms.
#[test]
fn a_mesh_placed_many_times_lands_where_each_node_puts_it() {
    let dir = tempfile::tempdir().unwrap();
    let corners = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    let nodes = r#"[{"children": [1, 2, 3]},
        {"translation": [10, 0, 0], "mesh": 0},
        {"matrix": [-1,0,0,0, 0,1,0,0, 0,0,1,0, 20,0,0,1], "mesh": 0},
        {"translation": [0, 5, 0], "children": [4]},
        {"translation": [30, 0, 0], "mesh": 0}]"#;
    let path = triangle_gltf(dir.path(), nodes, &corners);
    let model = load_gltf(&path, Mat4::IDENTITY).unwrap();
    let placements = [
        Mat4::from_translation(Vec3::new(10.0, 0.0, 0.0)),
        Mat4::from_translation(Vec3::new(20.0, 0.0, 0.0))
            * Mat4::from_scale(Vec3::new(-1.0, 1.0, 1.0)),
        Mat4::from_translation(Vec3::new(30.0, 5.0, 0.0)),
    ];
    assert_eq!(model.objects.len(), placements.len());
    let shared: Vec<&pathlight_scene::Instance> = model
        .objects
        .iter()
        .map(|o| match &o.shape {
            Shape::Instance(instance) => instance,
            other => panic!("{}: not an instance: {other:?}", o.name),
        })
        .collect();
    assert!(
        shared
            .iter()
            .all(|i| std::sync::Arc::ptr_eq(&i.mesh, &shared[0].mesh)),
        "one copy of the mesh"
    );
    for ((object, world), instance) in model.objects.iter().zip(placements).zip(shared) {
        let mesh = instance.flattened();
        let mut expected: Vec<Vec3> = corners
            .iter()
            .map(|c| world.transform_point3(Vec3::from(*c)))
            .collect();
        let mut got = mesh.positions.clone();
        let key = |v: &Vec3| (v.x * 1e3) as i64 * 1_000_000 + (v.y * 1e3) as i64;
        expected.sort_by_key(key);
        got.sort_by_key(key);
        for (g, e) in got.iter().zip(&expected) {
            assert!(g.distance(*e) < 1e-5, "{}: {g} vs {e}", object.name);
        }
    }
}

#[test]
fn punctual_lights_are_placed_by_their_nodes() {
    let path = data("PunctualLights/lights.gltf");
    let scene = gltf_scene(&path, None).unwrap();
    // A file that places lights opens without the default sky.
    assert_eq!(scene.environment, Environment::Constant(Vec3::ZERO));
    let names: Vec<&str> = scene.lights.iter().map(|l| l.name.as_str()).collect();
    assert_eq!(names, ["lights/lamp", "lights/spot", "lights/sun"]);
    let [lamp, spot, sun] = [0, 1, 2].map(|i| &scene.lights[i]);
    // Candela and lux read one to one as W/sr and W/m^2, times the colour.
    assert_eq!(lamp.intensity, Vec3::new(1.0, 0.5, 0.25));
    assert_eq!(
        lamp.kind,
        LightKind::Point {
            position: Vec3::new(-1.5, 0.0, 0.5),
            radius: 0.0,
            cone: None
        }
    );
    assert_eq!(spot.intensity, Vec3::splat(20.0));
    let LightKind::Point {
        position,
        cone: Some(cone),
        ..
    } = spot.kind
    else {
        panic!("the spot light has no cone: {spot:?}")
    };
    assert_eq!(position, Vec3::new(1.5, 1.0, 1.0));
    assert_eq!(cone.axis, Vec3::NEG_Z);
    assert!((cone.inner_deg - 0.1f32.to_degrees()).abs() < 1e-4);
    assert!((cone.outer_deg - 0.2f32.to_degrees()).abs() < 1e-4);
    assert_eq!(sun.intensity, Vec3::splat(2.0));
    let LightKind::Sun {
        direction,
        angular_diameter_deg,
    } = sun.kind
    else {
        panic!("the sun is not a sun: {sun:?}")
    };
    assert!(direction.distance(Vec3::new(0.0, 0.866_025_4, -0.5)) < 1e-5);
    assert_eq!(angular_diameter_deg, 0.0);
    // Placed by a scene file, the lights move with the file's transform.
    let text = format!(
        "[camera]\nposition = [0, 0, 9]\nlook_at = [0, 0, 0]\nfov_y = 40\n\
         [[gltf]]\nfile = {:?}\ntransform = {{ translate = [0, 0, 2], rotate = [0, 0, 90] }}\n",
        path.display().to_string()
    );
    let placed = load_scene(&SceneSource {
        name: "placed.toml".into(),
        text: &text,
        base_dir: PathBuf::new(),
        embedded: &[],
    })
    .unwrap();
    let LightKind::Point { position, .. } = placed.lights[0].kind else {
        panic!("{:?}", placed.lights[0])
    };
    assert!(
        position.distance(Vec3::new(0.0, -1.5, 2.5)) < 1e-5,
        "{position}"
    );
}

#[test]
fn bad_punctual_lights_are_refused_naming_the_node() {
    let dir = tempfile::tempdir().unwrap();
    let file = |from: &str, to: &str| {
        let path = dir.path().join("bad.gltf");
        let text = std::fs::read_to_string(data("PunctualLights/lights.gltf")).unwrap();
        assert!(text.contains(from), "{from}");
        std::fs::write(&path, text.replace(from, to)).unwrap();
        gltf_scene(&path, None).unwrap_err().to_string()
    };
    let message = file(r#""innerConeAngle": 0.1"#, r#""innerConeAngle": 0.5"#);
    assert!(
        message.contains("node 2: light 1: cone angles 0.5 and 0.2"),
        "{message}"
    );
    let message = file(r#""intensity": 1.0"#, r#""intensity": -3.0"#);
    assert!(message.contains("node 1: light 0: colour"), "{message}");
}

#[test]
fn specular_clearcoat_and_volume_factors_are_read() {
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(data("PunctualLights/lights.gltf"))
        .unwrap()
        .replacen(
            r#""pbrMetallicRoughness": {"#,
            r#""extensions": {"KHR_materials_specular": {"specularFactor": 0.3,
                "specularColorFactor": [1, 0.5, 0.25]}, "KHR_materials_clearcoat":
                {"clearcoatFactor": 0.7, "clearcoatRoughnessFactor": 0.2},
                "KHR_materials_volume": {"thicknessFactor": 1, "attenuationDistance": 2,
                "attenuationColor": [0.5, 1, 0]}},
                "pbrMetallicRoughness": {"#,
            1,
        )
        .replace(
            r#""extensionsUsed": ["#,
            r#""extensionsUsed": ["KHR_materials_specular", "KHR_materials_clearcoat",
                "KHR_materials_volume", "#,
        );
    let path = dir.path().join("specular.gltf");
    std::fs::write(&path, text).unwrap();
    let scene = gltf_scene(&path, None).unwrap();
    let Model::MetalRough(m) = &scene.materials[0].model else {
        panic!("{:?}", scene.materials[0])
    };
    assert_eq!(m.specular, 0.3);
    assert_eq!(m.specular_color, Vec3::new(1.0, 0.5, 0.25));
    assert_eq!((m.clearcoat, m.clearcoat_roughness), (0.7, 0.2));
    // Beer-Lambert from the volume: -ln(colour) / distance, a black channel absorbing all.
    assert!(!m.thin);
    assert!(
        (m.attenuation.x - 2f32.ln() / 2.0).abs() < 1e-6,
        "{}",
        m.attenuation
    );
    assert_eq!((m.attenuation.y, m.attenuation.z), (0.0, 1e30));
    // Without the extension: glTF's plain dielectric.
    let plain = gltf_scene(&data("PunctualLights/lights.gltf"), None).unwrap();
    let Model::MetalRough(m) = &plain.materials[0].model else {
        panic!("{:?}", plain.materials[0])
    };
    assert_eq!((m.specular, m.specular_color), (1.0, Vec3::ONE));
    assert_eq!((m.clearcoat, m.clearcoat_roughness), (0.0, 0.0));
    assert_eq!(m.attenuation, Vec3::ZERO);
}

/// `KHR_materials_sheen` and the extensions' textures: factors read, textures placed in
/// their slots with their own `texCoord` and `KHR_texture_transform` (also those the `gltf`
/// crate does not read: the clear coat's and the sheen's), an index past the file's
/// textures refused naming the material and key, and no warning about a supported one.
#[test]
fn sheen_and_the_extensions_textures_are_read() {
    let dir = tempfile::tempdir().unwrap();
    let original =
        std::fs::read_to_string(data("BoxTextured-glTF-Embedded/BoxTextured.gltf")).unwrap();
    let extensions = r#""extensions": {
        "KHR_materials_sheen": {"sheenColorFactor": [0.9, 0.5, 0.1], "sheenRoughnessFactor": 0.4,
            "sheenColorTexture": {"index": 0}, "sheenRoughnessTexture": {"index": 0,
            "extensions": {"KHR_texture_transform": {"offset": [0.5, 0], "scale": [2, 2]}}}},
        "KHR_materials_clearcoat": {"clearcoatFactor": 0.6, "clearcoatTexture": {"index": 0},
            "clearcoatRoughnessTexture": {"index": 0},
            "clearcoatNormalTexture": {"index": 0, "scale": 0.5}},
        "KHR_materials_transmission": {"transmissionFactor": 0.5,
            "transmissionTexture": {"index": 0}},
        "KHR_materials_specular": {"specularTexture": {"index": 0},
            "specularColorTexture": {"index": 0}}},
        "pbrMetallicRoughness": {"#;
    let write = |text: String| {
        let path = dir.path().join("layers.gltf");
        std::fs::write(&path, text).unwrap();
        path
    };
    let path = write(original.replacen(r#""pbrMetallicRoughness": {"#, extensions, 1));
    let scene = gltf_scene(&path, None).unwrap();
    let Model::MetalRough(m) = &scene.materials[0].model else {
        panic!("{:?}", scene.materials[0])
    };
    assert_eq!(m.sheen_color, Vec3::new(0.9, 0.5, 0.1));
    assert_eq!((m.sheen_roughness, m.clearcoat), (0.4, 0.6));
    assert_eq!(m.clearcoat_normal_scale, 0.5);
    let t = m.textures;
    for (name, slot) in [
        ("transmission", t.transmission),
        ("specular", t.specular),
        ("specular colour", t.specular_color),
        ("clear coat", t.clearcoat),
        ("clear coat roughness", t.clearcoat_roughness),
        ("clear coat normal", t.clearcoat_normal),
        ("sheen colour", t.sheen_color),
    ] {
        let slot = slot.unwrap_or_else(|| panic!("no {name} texture"));
        assert_eq!(slot.texture, 0, "{name}");
        assert_eq!(slot.transform, TextureRef::IDENTITY, "{name}");
    }
    let shifted = t.sheen_roughness.expect("no sheen roughness texture");
    assert_eq!(shifted.transform, [[2.0, 0.0, 0.5], [0.0, 2.0, 0.0]]);
    // One image, decoded once for all its uses.
    assert_eq!(scene.textures.len(), 1);
    let bad = write(original.replacen(
        r#""pbrMetallicRoughness": {"#,
        &extensions.replace(
            r#""clearcoatTexture": {"index": 0}"#,
            r#""clearcoatTexture": {"index": 7}"#,
        ),
        1,
    ));
    let message = gltf_scene(&bad, None).unwrap_err().to_string();
    assert!(
        message.contains("material 0: KHR_materials_clearcoat.clearcoatTexture: names no texture"),
        "{message}"
    );
}

/// `COLOR_0` as normalised bytes (VEC4) or floats (VEC3, alpha 1) becomes the mesh's linear
/// vertex colours; a colour accessor of another shape is refused naming the primitive.
#[test]
fn vertex_colours_are_read() {
    let dir = tempfile::tempdir().unwrap();
    let positions: Vec<u8> = [[0.0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]
        .iter()
        .flatten()
        .flat_map(|v| v.to_le_bytes())
        .collect();
    let write = |colors: Vec<u8>, accessor: &str| {
        let bytes: Vec<u8> = positions
            .iter()
            .copied()
            .chain(colors.iter().copied())
            .collect();
        let uri = format!(
            "data:application/octet-stream;base64,{}",
            base64::engine::general_purpose::STANDARD.encode(&bytes)
        );
        let json = format!(
            r#"{{"asset": {{"version": "2.0"}}, "scene": 0, "scenes": [{{"nodes": [0]}}],
            "nodes": [{{"mesh": 0}}],
            "meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0, "COLOR_0": 1}}}}]}}],
            "buffers": [{{"byteLength": {}, "uri": "{uri}"}}],
            "bufferViews": [{{"buffer": 0, "byteLength": 36}},
                {{"buffer": 0, "byteOffset": 36, "byteLength": {}}}],
            "accessors": [{{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                "min": [0, 0, 0], "max": [1, 1, 0]}}, {accessor}]}}"#,
            bytes.len(),
            colors.len()
        );
        let path = dir.path().join("colours.gltf");
        std::fs::write(&path, json).unwrap();
        gltf_scene(&path, None)
    };
    let mesh = |scene: &Scene| match &scene.objects[0].shape {
        Shape::Mesh(m) => m.clone(),
        other => panic!("{other:?}"),
    };
    let bytes = write(
        vec![255, 0, 0, 255, 0, 255, 0, 128, 0, 0, 255, 0],
        r#"{"bufferView": 1, "componentType": 5121, "normalized": true, "count": 3, "type": "VEC4"}"#,
    )
    .unwrap();
    assert_eq!(
        mesh(&bytes).colors,
        vec![
            Vec4::new(1.0, 0.0, 0.0, 1.0),
            Vec4::new(0.0, 1.0, 0.0, 128.0 / 255.0),
            Vec4::new(0.0, 0.0, 1.0, 0.0)
        ]
    );
    let floats: Vec<u8> = [0.5f32, 0.25, 0.125, 1.0, 1.0, 1.0, 0.0, 0.0, 0.0]
        .iter()
        .flat_map(|v| v.to_le_bytes())
        .collect();
    let floats = write(
        floats,
        r#"{"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC3"}"#,
    )
    .unwrap();
    assert_eq!(mesh(&floats).colors[0], Vec4::new(0.5, 0.25, 0.125, 1.0));
    let message = write(
        vec![0; 6],
        r#"{"bufferView": 1, "componentType": 5121, "normalized": true, "count": 3, "type": "VEC2"}"#,
    )
    .unwrap_err()
    .to_string();
    assert!(
        message.contains("mesh 0 primitive 0: COLOR_0 is neither VEC3 nor VEC4"),
        "{message}"
    );
}
