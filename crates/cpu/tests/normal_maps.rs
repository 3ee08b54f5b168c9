//! glTF normal maps the right way up: a texel tilted towards the top of the image tilts the
//! shading normal towards the top of the image in the world (glTF 2.0, 3.9.3: +Y is up in
//! the normal texture), whether the file ships `TANGENT` or pathlight generates MikkTSpace
//! tangents, and generated tangents carry the bitangent sign the file's have.

use std::path::{Path, PathBuf};

use glam::{Vec3, Vec4};
use pathlight_core::{Film, PreparedScene, Renderer};
use pathlight_cpu::CpuRenderer;
use pathlight_scene::{Environment, Scene, Shape, TriangleMesh, gltf_scene};

/// The tangent-space normal of the map's one texel: 30 degrees towards +Y, the image's top.
fn texel() -> Vec3 {
    let tilt = 30f32.to_radians();
    Vec3::new(0.0, tilt.sin(), tilt.cos())
}

/// A glTF file in `dir`: a 2 x 2 quad in the xy plane facing +z (the camera), the image's
/// top (v = 0) at +y, normal-mapped by a 1 x 1 PNG holding [`texel`]; with a `TANGENT`
/// attribute (+x, w = 1: bitangent cross(z, x) = +y, up in the image) when `tangents`.
fn quad_gltf(dir: &Path, tangents: bool) -> PathBuf {
    let positions: [[f32; 3]; 4] = [[-1., -1., 0.], [1., -1., 0.], [1., 1., 0.], [-1., 1., 0.]];
    let normals = [[0f32, 0., 1.]; 4];
    let uvs: [[f32; 2]; 4] = [[0., 1.], [1., 1.], [1., 0.], [0., 0.]];
    let tangent_values = [[1f32, 0., 0., 1.]; 4];
    let indices: [u16; 6] = [0, 1, 2, 0, 2, 3];
    let mut bin: Vec<u8> = Vec::new();
    let floats = |values: &[f32], bin: &mut Vec<u8>| {
        bin.extend(values.iter().flat_map(|v| v.to_le_bytes()));
    };
    floats(positions.as_flattened(), &mut bin);
    floats(normals.as_flattened(), &mut bin);
    floats(uvs.as_flattened(), &mut bin);
    floats(tangent_values.as_flattened(), &mut bin);
    bin.extend(indices.iter().flat_map(|i| i.to_le_bytes()));
    std::fs::write(dir.join("quad.bin"), &bin).unwrap();
    let [r, g, b] = (texel() * 0.5 + 0.5)
        .to_array()
        .map(|c| (c * 255.0).round() as u8);
    image::RgbImage::from_pixel(1, 1, image::Rgb([r, g, b]))
        .save(dir.join("normal.png"))
        .unwrap();
    let tangent_attribute = if tangents { r#", "TANGENT": 3"# } else { "" };
    let json = format!(
        r#"{{"asset": {{"version": "2.0"}}, "scene": 0, "scenes": [{{"nodes": [0]}}],
        "nodes": [{{"mesh": 0}}],
        "meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0, "NORMAL": 1,
            "TEXCOORD_0": 2{tangent_attribute}}}, "indices": 4, "material": 0}}]}}],
        "materials": [{{"normalTexture": {{"index": 0}},
            "pbrMetallicRoughness": {{"metallicFactor": 0, "roughnessFactor": 1}}}}],
        "textures": [{{"source": 0}}], "images": [{{"uri": "normal.png"}}],
        "buffers": [{{"byteLength": {}, "uri": "quad.bin"}}],
        "bufferViews": [{{"buffer": 0, "byteOffset": 0, "byteLength": 48}},
            {{"buffer": 0, "byteOffset": 48, "byteLength": 48}},
            {{"buffer": 0, "byteOffset": 96, "byteLength": 32}},
            {{"buffer": 0, "byteOffset": 128, "byteLength": 64}},
            {{"buffer": 0, "byteOffset": 192, "byteLength": 12}}],
        "accessors": [
            {{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
              "min": [-1, -1, 0], "max": [1, 1, 0]}},
            {{"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC3"}},
            {{"bufferView": 2, "componentType": 5126, "count": 4, "type": "VEC2"}},
            {{"bufferView": 3, "componentType": 5126, "count": 4, "type": "VEC4"}},
            {{"bufferView": 4, "componentType": 5123, "count": 6, "type": "SCALAR"}}]}}"#,
        bin.len()
    );
    let path = dir.join(if tangents {
        "shipped.gltf"
    } else {
        "generated.gltf"
    });
    std::fs::write(&path, json).unwrap();
    path
}

/// The file's one mesh.
fn mesh(scene: &Scene) -> &TriangleMesh {
    match &scene.objects[0].shape {
        Shape::Mesh(mesh) => mesh,
        other => panic!("not a mesh: {other:?}"),
    }
}

/// The normal image (auxiliary) of `scene` seen from the front, 8 x 8, 2 spp, CPU backend.
fn normals(mut scene: Scene) -> Film {
    scene.camera.width = 8;
    scene.camera.height = 8;
    scene.settings.spp = 2;
    scene.settings.aovs = true;
    scene.environment = Environment::Constant(Vec3::ONE);
    let prepared = PreparedScene::new(&scene).unwrap();
    let mut renderer = CpuRenderer::new(&prepared, &scene.camera, &scene.settings);
    while renderer.samples_done() < 2 {
        renderer.advance(2 - renderer.samples_done()).unwrap();
    }
    let accumulation = renderer.accumulation().unwrap();
    Film::aovs_from_accumulation(8, 8, &accumulation).unwrap().1
}

#[test]
fn a_normal_map_tilted_up_the_image_tilts_the_normal_up_in_the_world() {
    let dir = tempfile::tempdir().unwrap();
    let decoded = {
        let [r, g, b] = (texel() * 0.5 + 0.5)
            .to_array()
            .map(|c| f32::from((c * 255.0).round() as u8) / 255.0 * 2.0 - 1.0);
        Vec3::new(r, g, b).normalize()
    };
    for tangents in [true, false] {
        let scene = gltf_scene(&quad_gltf(dir.path(), tangents), None).unwrap();
        assert_eq!(scene.camera.look_at.z, 0.0, "framed from the front");
        let film = normals(scene);
        // The centre pixel sees the quad (the camera frames it).
        let centre = Vec3::from(film.pixels[4 * 8 + 4]);
        assert!(
            centre.distance(decoded) < 1e-3,
            "tangents {}: normal {centre}, expected {decoded}",
            if tangents { "shipped" } else { "generated" }
        );
    }
}

#[test]
fn generated_tangents_match_the_files_direction_and_sign() {
    let dir = tempfile::tempdir().unwrap();
    let shipped = gltf_scene(&quad_gltf(dir.path(), true), None).unwrap();
    let generated = gltf_scene(&quad_gltf(dir.path(), false), None).unwrap();
    let (a, b) = (&mesh(&shipped).tangents, &mesh(&generated).tangents);
    assert_eq!(a.len(), 6);
    assert_eq!(a.len(), b.len());
    for (i, (s, g)) in a.iter().zip(b).enumerate() {
        assert_eq!(*s, Vec4::new(1.0, 0.0, 0.0, 1.0), "corner {i}");
        assert!(
            s.distance(*g) < 1e-5,
            "corner {i}: shipped {s}, generated {g}"
        );
    }
}

/// The normal-mapped quad placed as instances (turned, scaled unevenly, mirrored) bends its
/// normals as its flattened copies do: tangents placed corner by corner, a mirroring
/// placement's bitangent turned over.
#[test]
fn instances_bend_normals_as_their_flattened_copies() {
    let dir = tempfile::tempdir().unwrap();
    let scene = gltf_scene(&quad_gltf(dir.path(), true), None).unwrap();
    let quad = std::sync::Arc::new(mesh(&scene).clone());
    let turn = glam::Quat::from_rotation_y(0.4) * glam::Quat::from_rotation_z(0.3);
    for scale in [Vec3::new(1.0, 0.6, 1.0), Vec3::new(-0.8, 0.6, 1.0)] {
        let mut placed = scene.clone();
        placed.objects[0].shape = Shape::Instance(pathlight_scene::Instance {
            mesh: quad.clone(),
            to_world: glam::Affine3A::from_scale_rotation_translation(scale, turn, Vec3::ZERO),
        });
        let mut flat = placed.clone();
        flat.objects = pathlight_scene::testing::flattened(&placed.objects);
        let to_world = glam::Affine3A::from_scale_rotation_translation(scale, turn, Vec3::ZERO);
        let face = (to_world.matrix3.inverse().transpose() * glam::Vec3A::Z).normalize();
        let (a, b) = (normals(placed), normals(flat));
        // The map tilts the normal 30 degrees off the face wherever the quad is seen.
        let bent = a
            .pixels
            .iter()
            .filter(|p| {
                let n = glam::Vec3A::from(Vec3::from(**p));
                n.length() > 0.5 && n.dot(face).abs() < 0.95
            })
            .count();
        assert!(bent >= 8, "scale {scale}: {bent} pixels see a bent normal");
        for (i, (p, q)) in a.pixels.iter().zip(&b.pixels).enumerate() {
            let (p, q) = (Vec3::from(*p), Vec3::from(*q));
            assert!(p.distance(q) < 1e-3, "scale {scale}: pixel {i}: {p} vs {q}");
        }
    }
}
