//! Structure-aware mutations of glTF files: the shipped samples' JSON (a `.gltf`, or a GLB's
//! JSON chunk) with numbers set to extremes, keys deleted, array elements dropped or
//! duplicated, values of another type, URIs pointing elsewhere; their buffers truncated or
//! corrupted; GLB chunk lengths wrong.

use std::path::{Path, PathBuf};

use pathlight_scene::gltf_scene;
use rand::Rng;
use rand::rngs::StdRng;
use serde_json::Value;

/// Numbers a mutation writes in place of one in the JSON.
const EXTREME_NUMBERS: [f64; 14] = [
    0.0,
    -1.0,
    1.0,
    1e38,
    -1e38,
    1e300,
    -0.0,
    0.5,
    1e-45,
    65535.0,
    2147483648.0,
    4294967296.0,
    18446744073709551615.0,
    -2147483649.0,
];

/// What a URI becomes.
const URIS: [&str; 7] = [
    "missing.bin",
    "data:application/octet-stream;base64,AAAA",
    "data:,",
    "data:application/octet-stream;base64,@@@@",
    "/etc/hostname",
    ".",
    "../../../../../../../../etc/passwd",
];

/// One sample: its folder (under `crates/scene/tests/data/gltf`) and its main file.
const SAMPLES: [(&str, &str); 8] = [
    ("BoxTextured-glTF-Binary", "BoxTextured.glb"),
    ("BoxTextured-glTF-Embedded", "BoxTextured.gltf"),
    ("cameras", "Cameras.gltf"),
    ("textureTransform", "TextureTransformTest.gltf"),
    ("Mesh_PrimitiveMode", "Mesh_PrimitiveMode_11.gltf"),
    ("Mesh_PrimitiveMode", "Mesh_PrimitiveMode_05.gltf"),
    ("PunctualLights", "lights.gltf"),
    ("MaterialLayers", "layers.gltf"),
];

/// A glTF case: the sample it mutates, its main file's name, and every file of its folder
/// (the main one mutated, perhaps a buffer too).
#[derive(Clone)]
pub struct GltfCase {
    /// The sample's folder.
    pub sample: &'static str,
    /// The file to open.
    pub main: &'static str,
    /// Every file of the case: name and bytes.
    pub files: Vec<(String, Vec<u8>)>,
}

/// The samples, unmutated: each folder's files read once.
pub fn corpus() -> Vec<GltfCase> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scene/tests/data/gltf");
    SAMPLES
        .iter()
        .map(|&(sample, main)| {
            let mut files: Vec<(String, Vec<u8>)> = std::fs::read_dir(root.join(sample))
                .unwrap()
                .map(|e| e.unwrap().path())
                .filter(|p| p.is_file())
                .map(|p| {
                    let name = p.file_name().unwrap().to_string_lossy().into_owned();
                    (name, std::fs::read(&p).unwrap())
                })
                .collect();
            files.sort();
            GltfCase {
                sample,
                main,
                files,
            }
        })
        .collect()
}

/// A mutation of one sample of `corpus`.
pub fn generate(corpus: &[GltfCase], rng: &mut StdRng) -> GltfCase {
    let mut case = corpus[rng.random_range(0..corpus.len())].clone();
    let (main, files) = (case.main, &mut case.files);
    let i = files.iter().position(|(name, _)| name == main).unwrap();
    let glb = main.ends_with(".glb");
    match rng.random_range(0..10) {
        // A buffer (or a GLB as bytes) truncated or with bytes overwritten.
        0 | 1 => {
            let buffers: Vec<usize> = (0..files.len())
                .filter(|&k| files[k].0.ends_with(".bin") || (glb && k == i))
                .collect();
            if buffers.is_empty() {
                files[i].1 = mutate_json_bytes(&files[i].1, rng);
            } else {
                let k = buffers[rng.random_range(0..buffers.len())];
                corrupt_bytes(&mut files[k].1, rng);
            }
        }
        // A GLB with its chunks' lengths wrong.
        2 if glb => wrong_glb_length(&mut files[i].1, rng),
        _ => {
            files[i].1 = if glb {
                mutate_glb_json(&files[i].1, rng)
            } else {
                mutate_json_bytes(&files[i].1, rng)
            };
        }
    }
    case
}

/// `json` (UTF-8 JSON text) with one to three structural mutations.
fn mutate_json_bytes(json: &[u8], rng: &mut StdRng) -> Vec<u8> {
    let Ok(mut value) = serde_json::from_slice::<Value>(json) else {
        return json.to_vec();
    };
    for _ in 0..rng.random_range(1..=3) {
        mutate_value(&mut value, rng);
    }
    serde_json::to_vec(&value).unwrap()
}

/// Every node of `value`'s tree as its path of keys and indices.
fn paths(value: &Value, path: &mut Vec<Step>, out: &mut Vec<Vec<Step>>) {
    out.push(path.clone());
    match value {
        Value::Object(map) => {
            for (key, child) in map {
                path.push(Step::Key(key.clone()));
                paths(child, path, out);
                path.pop();
            }
        }
        Value::Array(items) => {
            for (i, child) in items.iter().enumerate() {
                path.push(Step::Index(i));
                paths(child, path, out);
                path.pop();
            }
        }
        _ => {}
    }
}

/// One step down a JSON tree.
#[derive(Clone)]
enum Step {
    Key(String),
    Index(usize),
}

/// The node at `path`.
fn node<'a>(value: &'a mut Value, path: &[Step]) -> &'a mut Value {
    path.iter().fold(value, |v, step| match step {
        Step::Key(k) => &mut v[k.as_str()],
        Step::Index(i) => &mut v[*i],
    })
}

/// One mutation of a random node: a number set to an extreme, a key deleted, an array
/// element dropped or duplicated, a value of another type, a URI pointing elsewhere.
fn mutate_value(value: &mut Value, rng: &mut StdRng) {
    let mut all = Vec::new();
    paths(value, &mut Vec::new(), &mut all);
    // Numbers and URIs are what the interesting mutations touch: favour them.
    let numbers: Vec<&Vec<Step>> = all
        .iter()
        .filter(|p| node(&mut value.clone(), p).is_number())
        .collect();
    let target = if !numbers.is_empty() && rng.random_bool(0.5) {
        numbers[rng.random_range(0..numbers.len())].clone()
    } else {
        all[rng.random_range(0..all.len())].clone()
    };
    let (parent_path, last) = match target.split_last() {
        Some((last, parent)) => (parent.to_vec(), Some(last.clone())),
        None => (Vec::new(), None),
    };
    let is_uri = matches!(&last, Some(Step::Key(k)) if k == "uri");
    let here = node(value, &target);
    match rng.random_range(0..8) {
        _ if here.is_number() && rng.random_bool(0.8) => {
            let n = EXTREME_NUMBERS[rng.random_range(0..EXTREME_NUMBERS.len())];
            *here = serde_json::Number::from_f64(n).map_or(Value::Null, Value::Number);
            if n.fract() == 0.0 && n.abs() < 1.8e19 && rng.random_bool(0.5) {
                *here = if n >= 0.0 {
                    Value::from(n as u64)
                } else {
                    Value::from(n as i64)
                };
            }
        }
        _ if is_uri => *here = Value::from(URIS[rng.random_range(0..URIS.len())]),
        0 | 1 => match (node(value, &parent_path), last) {
            (Value::Object(map), Some(Step::Key(k))) => {
                map.remove(&k);
            }
            (Value::Array(items), Some(Step::Index(i))) => {
                items.remove(i);
            }
            _ => {}
        },
        2 => {
            if let (Value::Array(items), Some(Step::Index(i))) = (node(value, &parent_path), last) {
                let copy = items[i].clone();
                items.insert(i, copy);
            }
        }
        _ => {
            let others = [
                Value::from("x"),
                Value::Array(Vec::new()),
                Value::Object(Default::default()),
                Value::Null,
                Value::from(true),
                Value::from(3),
            ];
            *here = others[rng.random_range(0..others.len())].clone();
        }
    }
}

/// `bytes` truncated, or with a few bytes overwritten.
fn corrupt_bytes(bytes: &mut Vec<u8>, rng: &mut StdRng) {
    if bytes.is_empty() || rng.random_bool(0.5) {
        let keep = rng.random_range(0..=bytes.len());
        bytes.truncate(keep);
    } else {
        for _ in 0..rng.random_range(1..=8) {
            let at = rng.random_range(0..bytes.len());
            bytes[at] = rng.random();
        }
    }
}

/// The GLB's JSON chunk mutated and the file rebuilt (lengths consistent).
fn mutate_glb_json(glb: &[u8], rng: &mut StdRng) -> Vec<u8> {
    let Some((json, rest)) = split_glb(glb) else {
        return glb.to_vec();
    };
    let mut json = mutate_json_bytes(json, rng);
    while !json.len().is_multiple_of(4) {
        json.push(b' ');
    }
    let mut out = glb[..12].to_vec();
    out.extend((json.len() as u32).to_le_bytes());
    out.extend(b"JSON");
    out.extend(&json);
    out.extend(rest);
    let total = out.len() as u32;
    out[8..12].copy_from_slice(&total.to_le_bytes());
    out
}

/// A GLB's JSON chunk and what follows it, if the header holds together.
fn split_glb(glb: &[u8]) -> Option<(&[u8], &[u8])> {
    let length = u32::from_le_bytes(glb.get(12..16)?.try_into().ok()?) as usize;
    let json = glb.get(20..20 + length)?;
    Some((json, &glb[20 + length..]))
}

/// One of the GLB's length fields (the file's, the JSON chunk's, the binary chunk's) set
/// to a wrong value.
fn wrong_glb_length(glb: &mut [u8], rng: &mut StdRng) {
    let json_length = glb
        .get(12..16)
        .map_or(0, |b| u32::from_le_bytes(b.try_into().unwrap()) as usize);
    let fields = [8usize, 12, 20 + json_length];
    let at = fields[rng.random_range(0..fields.len())];
    let value: u32 = match rng.random_range(0..4) {
        0 => 0,
        1 => u32::MAX,
        2 => rng.random_range(0..glb.len() as u32 * 2),
        _ => 3,
    };
    if let Some(field) = glb.get_mut(at..at + 4) {
        field.copy_from_slice(&value.to_le_bytes());
    }
}

/// Writes the case's files to a fresh folder, opens the main one as a scene, prepares it
/// and renders it at 4x4, 1 spp; `Err` is a refusal.
pub fn run(case: &GltfCase) -> Result<(), String> {
    let dir = tempfile::tempdir().unwrap();
    for (name, bytes) in &case.files {
        std::fs::write(dir.path().join(name), bytes).unwrap();
    }
    let scene = gltf_scene(&dir.path().join(case.main), None).map_err(|e| e.to_string())?;
    super::render_tiny(scene)
}

/// Saves the case's files under `target/fuzz-failure-gltf/`; returns the main file's path.
pub fn save(case: &GltfCase, target: &Path) -> PathBuf {
    let dir = target.join("fuzz-failure-gltf");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    for (name, bytes) in &case.files {
        std::fs::write(dir.join(name), bytes).unwrap();
    }
    dir.join(case.main)
}
