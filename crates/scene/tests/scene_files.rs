//! Scene files: every shipped scene loads, and every kind of bad input gives an error that
//! names the file and line (or the asset path) and the offending key or value.

use std::path::{Path, PathBuf};

use glam::Vec3;
use pathlight_scene::settings::{MAX_RESOLUTION, MAX_SPP};
use pathlight_scene::{
    Cone, Environment, LightKind, Lobes, Model, Scene, SceneError, SceneSource, Shape,
    default_scene, load_materials, load_scene, load_scene_file,
};

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn data() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data")
}

const CAMERA: &str =
    "[camera]\nposition = [0, 0, 3]\nlook_at = [0, 0, 0]\nfov_y = 40\nresolution = [32, 32]\n";

fn load(body: &str) -> Result<Scene, SceneError> {
    let text = format!("{CAMERA}{body}");
    load_scene(&SceneSource {
        name: "test.toml".into(),
        text: &text,
        base_dir: data(),
        embedded: &[],
    })
}

fn error(body: &str) -> String {
    load(body)
        .expect_err("this scene must be refused")
        .to_string()
}

#[test]
fn shipped_scenes_load() {
    let mut found = 0;
    for dir in ["scenes", "scenes/refs"] {
        for entry in std::fs::read_dir(repo().join(dir)).unwrap() {
            let path = entry.unwrap().path();
            if path.extension().is_some_and(|e| e == "toml") {
                let scene = load_scene_file(&path).unwrap_or_else(|e| panic!("{e}"));
                assert!(!scene.objects.is_empty(), "{}", path.display());
                found += 1;
            }
        }
    }
    assert_eq!(
        found, 28,
        "default + outdoor + layers + instances + eleven reference scenes + 13 furnace rings"
    );
}

#[test]
fn default_scene_has_the_room_two_lights_and_seven_models() {
    let scene = default_scene::load().unwrap();
    let emissive = |o: &&pathlight_scene::Object| {
        scene.materials[o.material as usize].emission.max_element() > 0.0
    };
    let lights: Vec<_> = scene.objects.iter().filter(emissive).collect();
    assert_eq!(lights.len(), 2);
    let count = |f: fn(&Shape) -> bool| scene.objects.iter().filter(|o| f(&o.shape)).count();
    assert_eq!(
        count(|s| matches!(s, Shape::Quad { .. })),
        7,
        "five walls and two lights"
    );
    assert_eq!(count(|s| matches!(s, Shape::Sphere { .. })), 3);
    assert_eq!(count(|s| matches!(s, Shape::Cylinder { .. })), 3);
    assert_eq!(count(|s| matches!(s, Shape::Mesh(_))), 1, "the vase");
    assert_eq!(scene.textures.len(), 1);
    assert_eq!(
        (scene.textures[0].width, scene.textures[0].height),
        (2048, 1024)
    );
    // The embedded copy is the same scene as the file on disk.
    let on_disk = load_scene_file(&repo().join("scenes/default.toml")).unwrap();
    assert_eq!(on_disk, scene);
}

#[test]
fn obj_mesh_loads_with_its_transform() {
    let scene = load(
        "[materials.m]\n[[mesh]]\nmaterial = \"m\"\nfile = \"tetra.obj\"\ntransform = { scale = 2, translate = [1, 0, 0] }\n",
    )
    .unwrap();
    let Shape::Mesh(mesh) = &scene.objects[0].shape else {
        panic!("not a mesh")
    };
    assert_eq!(mesh.indices.len(), 4);
    assert!(mesh.positions.contains(&glam::Vec3::new(3.0, 0.0, 0.0)));
    assert!(mesh.normals.iter().all(|n| (n.length() - 1.0).abs() < 1e-5));
}

/// A mesh entry with `instances` places one shared copy of its triangles (in the OBJ file's
/// space) by its own transform and by each instance's, each an object with its name and
/// material; a placement beyond the coordinate limit or an unknown material names the line.
#[test]
fn a_mesh_with_instances_places_one_copy_many_times() {
    let scene = load(
        "[materials.m]\n[materials.n]\n\
         [[mesh]]\nname = \"tetra\"\nmaterial = \"m\"\nfile = \"tetra.obj\"\n\
         transform = { translate = [1, 0, 0] }\n\
         instances = [\n\
           { transform = { scale = 2 } },\n\
           { name = \"mirror\", material = \"n\", transform = { scale = [-1, 1, 1] } },\n\
         ]\n",
    )
    .unwrap();
    let names: Vec<&str> = scene.objects.iter().map(|o| o.name.as_str()).collect();
    assert_eq!(names, ["tetra", "tetra#1", "mirror"]);
    assert_eq!(
        scene.objects.iter().map(|o| o.material).collect::<Vec<_>>(),
        [0, 0, 1]
    );
    let placed: Vec<&pathlight_scene::Instance> = scene
        .objects
        .iter()
        .map(|o| match &o.shape {
            Shape::Instance(instance) => instance,
            other => panic!("not an instance: {other:?}"),
        })
        .collect();
    assert!(
        placed
            .iter()
            .all(|p| std::sync::Arc::ptr_eq(&p.mesh, &placed[0].mesh)),
        "one copy of the mesh"
    );
    assert_eq!(placed[0].mesh.indices.len(), 4);
    let corner = placed[0].mesh.positions[0];
    assert_eq!(
        placed[0].to_world.transform_point3(corner),
        corner + glam::Vec3::X
    );
    assert_eq!(placed[1].to_world.transform_point3(corner), corner * 2.0);
    assert!(placed[2].to_world.matrix3.determinant() < 0.0);
    let far = error(
        "[materials.m]\n[[mesh]]\nmaterial = \"m\"\nfile = \"tetra.obj\"\n\
         instances = [{ transform = { translate = [1e30, 0, 0] } }]\n",
    );
    assert!(
        far.contains("test.toml:7") && far.contains("instances[0]"),
        "{far}"
    );
    let unknown = error(
        "[materials.m]\n[[mesh]]\nmaterial = \"m\"\nfile = \"tetra.obj\"\n\
         instances = [{ material = \"nowhere\" }]\n",
    );
    assert!(unknown.contains("\"nowhere\" is not defined"), "{unknown}");
}

#[test]
fn syntax_errors_name_line_and_key() {
    let message = error("[materials.m]\ncolr = [1, 0, 0]\n");
    assert!(message.starts_with("test.toml:7:"), "{message}");
    assert!(message.contains("colr"), "{message}");
    let message = error("[[sphere]\n");
    assert!(message.starts_with("test.toml:6:"), "{message}");
    let message = error("[[sphere]]\nmaterial = \"m\"\ncenter = [0, 0]\nradius = 1\n");
    assert!(message.starts_with("test.toml:8:"), "{message}");
}

#[test]
fn unknown_material_names_the_shape_line() {
    let message =
        error("[materials.m]\n\n[[sphere]]\nmaterial = \"nope\"\ncenter = [0, 0, 0]\nradius = 1\n");
    assert!(message.starts_with("test.toml:8:"), "{message}");
    assert!(message.contains("\"nope\""), "{message}");
}

#[test]
fn missing_and_broken_assets_name_the_path() {
    let message = error("[materials.m]\ntexture = \"no-such.png\"\n");
    assert!(
        message.contains("no-such.png") && message.starts_with("test.toml:6:"),
        "{message}"
    );
    let message = error("[materials.m]\n[[mesh]]\nmaterial = \"m\"\nfile = \"missing.obj\"\n");
    assert!(message.contains("missing.obj"), "{message}");
    let message = error("[materials.m]\n[[mesh]]\nmaterial = \"m\"\nfile = \"broken.obj\"\n");
    assert!(message.contains("broken.obj"), "{message}");
    let message = error("[materials.m]\ntexture = \"tetra.obj\"\n");
    assert!(
        message.contains("tetra.obj") && message.contains("decode"),
        "{message}"
    );
    let err = load_scene_file(Path::new("/no/such/scene.toml"))
        .unwrap_err()
        .to_string();
    assert!(err.contains("/no/such/scene.toml"), "{err}");
}

#[test]
fn absurd_sizes_are_refused_with_the_limit() {
    for resolution in ["[0, 32]", "[32, 100000]"] {
        let text = CAMERA.replace("[32, 32]", resolution);
        let err = load_scene(&SceneSource {
            name: "r.toml".into(),
            text: &text,
            base_dir: data(),
            embedded: &[],
        })
        .unwrap_err()
        .to_string();
        assert!(err.contains(&MAX_RESOLUTION.to_string()), "{err}");
    }
    let err = error("[render]\nspp = 0\n");
    assert!(
        err.contains(&MAX_SPP.to_string()) && err.starts_with("test.toml:6:"),
        "{err}"
    );
    assert!(error("[render]\nmax_depth = 0\n").contains("max_depth"));
}

#[test]
fn out_of_range_material_parameters_are_refused() {
    let cases = [
        ("specular_rate = 0.7\nrefract_rate = 0.5", "exceeds 1"),
        ("ior = 0", "ior"),
        ("ior = -1.5", "ior"),
        ("specular_roughness = 1.5", "specular_roughness"),
        ("refract_roughness = -0.1", "refract_roughness"),
        ("emission = [1, -1, 0]", "emission"),
        ("color = [1.2, 0, 0]", "color"),
        ("conductor = \"unobtainium\"", "gold"),
        ("eta = [1, 1, 1]", "eta"),
    ];
    for (body, needle) in cases {
        let message = error(&format!("[materials.m]\n{body}\n"));
        assert!(message.starts_with("test.toml:6:"), "{body}: {message}");
        assert!(message.contains(needle), "{body}: {message}");
    }
}

/// `model` chooses the material model; without it a material is under the lobes, and a key
/// of another model is refused saying what to write.
#[test]
fn the_model_key_chooses_the_material_model() {
    let scene = load(
        "[materials.a]\nmodel = \"metal-rough\"\nmetallic = 1.0\nroughness = 0.2\n[materials.b]\nmodel = \"lobes\"\npreset = \"plastic\"\n[materials.c]\ncolor = [0.5, 0.5, 0.5]\n",
    )
    .unwrap();
    let model = |name: &str| {
        scene
            .materials
            .iter()
            .find(|m| m.name == name)
            .unwrap()
            .model
    };
    let Model::MetalRough(a) = model("a") else {
        panic!("a is metal-rough")
    };
    assert_eq!((a.metallic, a.roughness, a.transmission), (1.0, 0.2, 0.0));
    assert!(matches!(model("b"), Model::Lobes(l) if l.specular_rate == 0.1));
    assert_eq!(model("c"), Model::Lobes(Lobes::DIFFUSE));
    // The metal-rough keys of an older file, without `model`:
    let message = error("[materials.m]\nmetallic = 1.0\n");
    assert_eq!(
        message,
        "test.toml:6: materials.m.metallic: a key of the \"metal-rough\" model; without `model` \
         a material is \"lobes\": write model = \"metal-rough\" to use it"
    );
    let message = error("[materials.m]\nmodel = \"metal-rough\"\nspecular_rate = 0.5\n");
    assert!(
        message.contains("materials.m.specular_rate: a key of the \"lobes\" model; this material's model is \"metal-rough\""),
        "{message}"
    );
    let message = error("[materials.m]\nmodel = \"marble\"\n");
    assert!(
        message.starts_with("test.toml:7:") && message.contains("metal-rough"),
        "{message}"
    );
}

#[test]
fn seed_presets_give_defaults_that_keys_override() {
    let scene = load(
        "[materials.a]\npreset = \"metal\"\n[materials.b]\npreset = \"glass\"\nior = 1.33\n[materials.c]\npreset = \"ceramic\"\nspecular_rate = 0.5\n",
    )
    .unwrap();
    let m = |name: &str| match scene
        .materials
        .iter()
        .find(|m| m.name == name)
        .unwrap()
        .model
    {
        Model::Lobes(lobes) => lobes,
        Model::MetalRough(_) => panic!("{name} is not under the lobe model"),
    };
    assert_eq!((m("a").specular_rate, m("a").specular_tint), (1.0, 1.0));
    assert_eq!((m("b").refract_rate, m("b").ior), (1.0, 1.33));
    assert_eq!(m("c").specular_rate, 0.5);
    assert!(m("c").specular_roughness > 0.0);
    let message = error("[materials.m]\npreset = \"marble\"\n");
    assert!(
        message.starts_with("test.toml:6:") && message.contains("ceramic"),
        "{message}"
    );
}

#[test]
fn colours_are_srgb_unless_the_file_says_linear() {
    let srgb = load("[materials.m]\ncolor = [0.5, 0.5, 0.5]\n").unwrap();
    assert!((srgb.materials[0].base_color.x - 0.214_041).abs() < 1e-5);
    let text =
        format!("color_space = \"linear\"\n{CAMERA}[materials.m]\ncolor = [0.5, 0.5, 0.5]\n");
    let linear = load_scene(&SceneSource {
        name: "l.toml".into(),
        text: &text,
        base_dir: data(),
        embedded: &[],
    })
    .unwrap();
    assert_eq!(linear.materials[0].base_color.x, 0.5);
}

/// Geometry whose boxes or areas would not be finite never reaches the BVH build (where it
/// panicked inside obvhs): non-finite or overflowing values in a transform, a revolve
/// profile, an OBJ file or a radius are refused with the file and line.
#[test]
fn non_finite_and_overflowing_geometry_is_refused_with_its_line() {
    let mesh = |file: &str, transform: &str| {
        format!("[materials.m]\n[[mesh]]\nmaterial = \"m\"\nfile = \"{file}\"\n{transform}")
    };
    for translate in ["nan", "inf", "-inf", "1e20"] {
        let message = error(&mesh(
            "tetra.obj",
            &format!("transform = {{ translate = [{translate}, 0, 0] }}\n"),
        ));
        assert!(
            message.starts_with("test.toml:7:") && message.contains("vertex 0"),
            "{translate}: {message}"
        );
    }
    let message = error(&mesh("overflowing.obj", ""));
    assert!(
        message.contains("overflowing.obj:3:") && message.contains("not a finite number"),
        "{message}"
    );
    let message = error(&mesh("nan-vertex.obj", ""));
    assert!(message.contains("nan-vertex.obj:3:"), "{message}");
    // Finite in the file, overflowing once revolved.
    let message = error(
        "[materials.m]\n[[revolve]]\nmaterial = \"m\"\nbase = [0, 0, 0]\n\
         profile = [[1e38, 0], [1e38, 1]]\n",
    );
    assert!(
        message.starts_with("test.toml:7:") && message.contains("profile"),
        "{message}"
    );
    let message = error(
        "[materials.m]\n[[revolve]]\nmaterial = \"m\"\naxis = [1e38, 1e38, 0]\nbase = [0, 0, 0]\nprofile = [[1, 0], [1, 1]]\n",
    );
    assert!(message.contains("axis"), "{message}");
    for radius in ["3e38", "inf", "nan", "0", "-1"] {
        let message = error(&format!(
            "[materials.m]\n[[sphere]]\nmaterial = \"m\"\ncenter = [0, 0, 0]\nradius = {radius}\n"
        ));
        assert!(
            message.starts_with("test.toml:7:") && message.contains("radius"),
            "{radius}: {message}"
        );
    }
}

/// Values that were silently accepted: an array with more elements than the key takes (the
/// rest was dropped), a non-finite texture rotation, two objects of one name.
#[test]
fn extra_elements_bad_rotations_and_duplicate_names_are_refused() {
    let sphere = |extra: &str| {
        format!(
            "[materials.m]\n[[sphere]]\nmaterial = \"m\"\ncenter = [0, 0, 0]\nradius = 1\n{extra}"
        )
    };
    let message = error("[materials.m]\ncolor = [0.5, 0.5, 0.5, 0.5]\n");
    assert!(
        message.contains("invalid length 4") && message.starts_with("test.toml:7:"),
        "{message}"
    );
    let message =
        error("[materials.m]\n[[revolve]]\nmaterial = \"m\"\nprofile = [[1, 0, 9], [1, 1]]\n");
    assert!(message.contains("invalid length 3"), "{message}");
    let message = error(
        "[materials.m]\n[[mesh]]\nmaterial = \"m\"\nfile = \"tetra.obj\"\ntransform = { scale = [1, 1, 1, 1] }\n",
    );
    assert!(message.contains("scale"), "{message}");
    let text = CAMERA.replace("[32, 32]", "[32, 32, 7]");
    let source = SceneSource {
        name: "r.toml".into(),
        text: &text,
        base_dir: data(),
        embedded: &[],
    };
    let message = load_scene(&source).unwrap_err().to_string();
    assert!(message.contains("invalid length 3"), "{message}");
    for rotation in ["nan", "inf"] {
        let message = error(&sphere(&format!("texture_rotation = {rotation}\n")));
        assert!(
            message.contains("texture_rotation"),
            "{rotation}: {message}"
        );
    }
    let twice = "[materials.m]\n[[sphere]]\nname = \"ball\"\nmaterial = \"m\"\ncenter = [0, 0, 0]\nradius = 1\n\
                 [[quad]]\nname = \"ball\"\nmaterial = \"m\"\norigin = [0, 0, 0]\nedge_u = [1, 0, 0]\nedge_v = [0, 1, 0]\n";
    let message = error(twice);
    assert!(
        message.contains("\"ball\"") && message.contains("line"),
        "{message}"
    );
}

#[test]
fn environment_maps_load_with_strength_and_rotation() {
    let scene = load("[environment]\nmap = \"sky.exr\"\nstrength = 2\nrotation = -30\n").unwrap();
    let Environment::Map(map) = &scene.environment else {
        panic!("{:?}", scene.environment);
    };
    assert_eq!((map.image.width, map.image.height), (4, 3));
    assert_eq!((map.strength, map.rotation_deg), (2.0, -30.0));
    // Row 1, column 2 of the file: x 0.1 + y.
    assert_eq!(map.image.texels[4 + 2], [1.2, 0.5, 0.25]);
    // A map of equal texels is the constant environment it equals.
    let scene = load("[environment]\nmap = \"constant.exr\"\nstrength = 4\n").unwrap();
    assert_eq!(
        scene.environment,
        Environment::Constant(glam::Vec3::new(2.0, 1.0, 0.5))
    );
}

#[test]
fn bad_environments_and_lenses_are_refused_with_line_or_texel() {
    for (body, wanted) in [
        (
            "[environment]\nmap = \"no-such.exr\"\n",
            "test.toml:6: environment.map: cannot read",
        ),
        (
            "[environment]\nmap = \"tetra.obj\"\n",
            "tetra.obj: cannot decode image",
        ),
        (
            "[environment]\nmap = \"nan.exr\"\n",
            "nan.exr: texel (2, 1) holds NaN",
        ),
        (
            "[environment]\nmap = \"inf.exr\"\n",
            "inf.exr: texel (3, 2) holds inf",
        ),
        (
            "[environment]\nradiance = [1, 1, 1]\nmap = \"sky.exr\"\n",
            "test.toml:6: [environment] needs exactly one of",
        ),
        (
            "[environment]\n",
            "test.toml:6: [environment] needs exactly one of",
        ),
        (
            "[environment]\nmap = \"sky.exr\"\nstrength = -1\n",
            "environment.strength = -1 must be finite and >= 0",
        ),
        (
            "[environment]\nradiance = [1, 1, 1]\nrotation = 3\n",
            "apply to a `map`",
        ),
    ] {
        let message = error(body);
        assert!(message.contains(wanted), "{body:?}: {message}");
    }
    let lens = |keys: &str| {
        let text =
            format!("[camera]\nposition = [0, 0, 3]\nlook_at = [0, 0, 0]\nfov_y = 40\n{keys}\n");
        load_scene(&SceneSource {
            name: "lens.toml".into(),
            text: &text,
            base_dir: data(),
            embedded: &[],
        })
    };
    for (keys, wanted) in [
        (
            "aperture_radius = -0.1",
            "lens.toml:1: camera.aperture_radius = -0.1 must be >= 0",
        ),
        (
            "focus_distance = 0",
            "lens.toml:1: camera.focus_distance = 0 must be > 0",
        ),
        (
            "focus_distance = -2",
            "camera.focus_distance = -2 must be > 0",
        ),
    ] {
        let message = lens(keys).unwrap_err().to_string();
        assert!(message.contains(wanted), "{keys}: {message}");
    }
    let camera = lens("aperture_radius = 0.1").unwrap().camera;
    assert_eq!((camera.aperture_radius, camera.focus_distance), (0.1, 3.0));
}

#[test]
fn lights_load_with_their_placement_and_units() {
    let scene = load(
        "[[light]]\ntype = \"point\"\nposition = [1, 2, 3]\ncolor = [1, 1, 0]\nintensity = 4\n\
         [[light]]\nname = \"key\"\ntype = \"spot\"\nposition = [0, 2, 0]\nlook_at = [0, 0, 0]\n\
         intensity = 10\ninner_angle = 10\nouter_angle = 30\nradius = 0.1\n\
         [[light]]\ntype = \"sun\"\ndirection = [0, -2, 0]\nintensity = 3\nangular_diameter = 0.53\n",
    )
    .unwrap();
    assert_eq!(scene.lights.len(), 3);
    let [point, spot, sun] = [0, 1, 2].map(|i| &scene.lights[i]);
    assert_eq!(point.name, "light0");
    assert_eq!(point.intensity, Vec3::new(4.0, 4.0, 0.0));
    assert_eq!(
        point.kind,
        LightKind::Point {
            position: Vec3::new(1.0, 2.0, 3.0),
            radius: 0.0,
            cone: None
        }
    );
    assert_eq!(spot.name, "key");
    assert_eq!(
        spot.kind,
        LightKind::Point {
            position: Vec3::new(0.0, 2.0, 0.0),
            radius: 0.1,
            cone: Some(Cone {
                axis: Vec3::NEG_Y,
                inner_deg: 10.0,
                outer_deg: 30.0
            })
        }
    );
    assert_eq!(sun.intensity, Vec3::splat(3.0));
    assert_eq!(
        sun.kind,
        LightKind::Sun {
            direction: Vec3::NEG_Y,
            angular_diameter_deg: 0.53
        }
    );
    // sRGB colours are decoded as material colours are.
    let srgb = load("[[light]]\ntype = \"point\"\nposition = [0, 1, 0]\ncolor = [0.5, 0.5, 0.5]\nintensity = 1\n")
        .unwrap();
    assert!((srgb.lights[0].intensity.x - 0.214).abs() < 1e-3);
}

#[test]
fn bad_lights_are_refused_with_line_and_key() {
    for (body, wanted) in [
        (
            "[[light]]\ntype = \"lamp\"\nintensity = 1\n",
            "unknown variant `lamp`",
        ),
        ("[[light]]\ntype = \"point\"\n", "missing field `intensity`"),
        (
            "[[light]]\ntype = \"point\"\nintensity = 1\n",
            "test.toml:6: a point light needs light.position",
        ),
        (
            "[[light]]\ntype = \"point\"\nposition = [0, 1, 0]\nintensity = -1\n",
            "test.toml:6: light.intensity = -1 must be finite and >= 0",
        ),
        (
            "[[light]]\ntype = \"point\"\nposition = [0, 1, 0]\nintensity = 1\ndirection = [0, -1, 0]\n",
            "light.direction does not apply to a point light",
        ),
        (
            "[[light]]\ntype = \"sun\"\nintensity = 1\nposition = [0, 1, 0]\ndirection = [0, -1, 0]\n",
            "light.position does not apply to a sun light",
        ),
        (
            "[[light]]\ntype = \"sun\"\nintensity = 1\n",
            "a sun light needs light.direction",
        ),
        (
            "[[light]]\ntype = \"sun\"\nintensity = 1\ndirection = [0, 0, 0]\n",
            "light.direction must not be zero",
        ),
        (
            "[[light]]\ntype = \"sun\"\nintensity = 1\ndirection = [0, -1, 0]\nangular_diameter = 90\n",
            "light.angular_diameter = 90 must lie in [0, 60] degrees",
        ),
        (
            "[[light]]\ntype = \"spot\"\nintensity = 1\nposition = [0, 1, 0]\n",
            "a spot light needs light.direction or light.look_at",
        ),
        (
            "[[light]]\ntype = \"spot\"\nintensity = 1\nposition = [0, 1, 0]\nlook_at = [0, 1, 0]\n",
            "light.look_at equals light.position",
        ),
        (
            "[[light]]\ntype = \"spot\"\nintensity = 1\nposition = [0, 1, 0]\nlook_at = [0, 0, 0]\ndirection = [0, -1, 0]\n",
            "takes one of light.direction and light.look_at",
        ),
        (
            "[[light]]\ntype = \"spot\"\nintensity = 1\nposition = [0, 1, 0]\nlook_at = [0, 0, 0]\nouter_angle = 20\ninner_angle = 30\n",
            "light.inner_angle = 30 must lie in [0, 20] degrees",
        ),
        (
            "[[light]]\ntype = \"spot\"\nintensity = 1\nposition = [0, 1, 0]\nlook_at = [0, 0, 0]\nouter_angle = 0\n",
            "light.outer_angle must be above 0",
        ),
        (
            "[[light]]\ntype = \"point\"\nposition = [0, 1, 0]\nintensity = 1\nradius = -1\n",
            "radius",
        ),
        (
            "[[light]]\ntype = \"point\"\nposition = [0, 1, 0]\nintensity = 1\ncolor = [2, 1, 1]\n",
            "sRGB colours lie in [0, 1]",
        ),
        (
            "[[light]]\ntype = \"point\"\nposition = [0, 1e30, 0]\nintensity = 1\n",
            "light.position",
        ),
    ] {
        let message = error(body);
        assert!(message.contains(wanted), "{body:?}: {message}");
    }
}

#[test]
fn materials_load_alone_as_the_whole_scene_loads_them() {
    // The default scene: a textured material among plain ones, and placed shapes after.
    let source = SceneSource {
        name: "<default scene>".into(),
        text: default_scene::TEXT,
        base_dir: PathBuf::new(),
        embedded: default_scene::ASSETS,
    };
    let scene = load_scene(&source).unwrap();
    let materials = load_materials(&source).unwrap();
    assert_eq!(materials, scene.materials);
    assert!(materials.iter().any(|m| m.texture.is_some()));
    // A bad value is refused as the whole scene's loader refuses it.
    let text = default_scene::TEXT.replace("[materials.floor]", "[materials.floor]\nior = -1");
    let bad = SceneSource {
        text: &text,
        ..source
    };
    let message = load_materials(&bad).unwrap_err().to_string();
    assert_eq!(message, load_scene(&bad).unwrap_err().to_string());
    assert!(message.contains("materials.floor.ior"), "{message}");
}

#[test]
fn a_camera_that_cannot_see_is_refused_naming_the_key() {
    let camera = |position: &str, up: &str, fov: &str| {
        let text = format!(
            "[camera]\nposition = {position}\nlook_at = [0, 0, 0]\nup = {up}\nfov_y = {fov}\n\
             resolution = [8, 8]\n"
        );
        load_scene(&SceneSource {
            name: "test.toml".into(),
            text: &text,
            base_dir: data(),
            embedded: &[],
        })
        .expect_err("this camera must be refused")
        .to_string()
    };
    let at_origin = camera("[0, 0, 0]", "[0, 1, 0]", "40");
    assert!(
        at_origin.contains("test.toml:1: camera.look_at equals camera.position"),
        "{at_origin}"
    );
    let up_along = camera("[0, 3, 0]", "[0, 1, 0]", "40");
    assert!(
        up_along.contains("camera.up is parallel to the view direction"),
        "{up_along}"
    );
    let flat = camera("[0, 0, 3]", "[0, 1, 0]", "180");
    assert!(
        flat.contains("camera.fov_y = 180 must lie strictly between 0 and 180"),
        "{flat}"
    );
}
