//! Mutation fuzzing of scene files and meshes, and of glTF files (structure-aware: `fuzz/gltf.rs`):
//! every mutated input is either refused with an error or loaded, prepared (BVH and all) and
//! rendered, in time; none panics or spins.
//!
//! The suite runs a few thousand seeded cases. A long run:
//! `PATHLIGHT_FUZZ_CASES=100000 cargo test --release -p pathlight-cpu --test fuzz`
//! (`PATHLIGHT_FUZZ_SEED` picks another sequence). A failing case is written to
//! `target/fuzz-failure.toml` (and `.obj`), or `target/fuzz-failure-gltf/`, with its seed.

use std::io::Cursor;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::Path;
use std::sync::mpsc;
use std::time::{Duration, Instant};

use pathlight_core::{PreparedScene, Renderer};
use pathlight_cpu::CpuRenderer;
use pathlight_scene::{Scene, SceneSource, load_scene};
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};

#[path = "fuzz/gltf.rs"]
mod gltf;

/// Scene-file cases in the test suite (seeded, so every run tries the same ones).
const SUITE_CASES: u64 = 2000;
/// glTF cases in the test suite.
const GLTF_SUITE_CASES: u64 = 1000;
/// Longest a case may take, load to rendered image.
const CASE_LIMIT: Duration = Duration::from_secs(20);
/// Numbers a mutation writes in place of one in the file.
const EXTREME_NUMBERS: [&str; 14] = [
    "0",
    "-1",
    "1",
    "1e38",
    "-1e38",
    "nan",
    "inf",
    "-inf",
    "1e-45",
    "2147483648",
    "4294967296",
    "-0.0",
    "1e300",
    "0.5",
];

/// A scene file of the corpus and the mesh it names, if any.
struct Seed {
    name: &'static str,
    text: String,
    obj: Option<(&'static str, String)>,
}

/// The corpus: the default scene and the reference scenes that name a mesh or a texture.
fn corpus() -> Vec<Seed> {
    let scenes = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
    let read = |path: &str| std::fs::read_to_string(scenes.join(path)).unwrap();
    vec![
        Seed {
            name: "default.toml",
            text: read("default.toml"),
            obj: None,
        },
        Seed {
            name: "refs/cornell-materials.toml",
            text: read("refs/cornell-materials.toml"),
            obj: Some(("octahedron.obj", read("refs/octahedron.obj"))),
        },
        Seed {
            name: "refs/textured-sphere.toml",
            text: read("refs/textured-sphere.toml"),
            obj: None,
        },
    ]
}

/// A 2x2 PNG standing in for every texture (decoding the real one would dominate the time).
fn tiny_texture() -> Vec<u8> {
    let image =
        image::RgbImage::from_fn(2, 2, |x, y| image::Rgb([x as u8 * 200, y as u8 * 200, 90]));
    let mut bytes = Cursor::new(Vec::new());
    image.write_to(&mut bytes, image::ImageFormat::Png).unwrap();
    bytes.into_inner()
}

/// `text` with one to three mutations: a number replaced by an extreme one, a line deleted,
/// duplicated or swapped with another, or the text truncated.
fn mutate(text: &str, rng: &mut StdRng) -> String {
    let mut lines: Vec<String> = text.lines().map(str::to_owned).collect();
    for _ in 0..rng.random_range(1..=3) {
        if lines.is_empty() {
            break;
        }
        let i = rng.random_range(0..lines.len());
        match rng.random_range(0..10) {
            0 => {
                lines.remove(i);
            }
            1 => {
                let line = lines[i].clone();
                lines.insert(i, line);
            }
            2 => {
                let j = rng.random_range(0..lines.len());
                lines.swap(i, j);
            }
            3 => {
                let joined = lines.join("\n");
                let mut cut = rng.random_range(0..=joined.len());
                while !joined.is_char_boundary(cut) {
                    cut -= 1;
                }
                lines = joined[..cut].lines().map(str::to_owned).collect();
            }
            _ => {
                let extreme = EXTREME_NUMBERS[rng.random_range(0..EXTREME_NUMBERS.len())];
                lines[i] = replace_a_number(&lines[i], extreme, rng);
            }
        }
    }
    lines.join("\n")
}

/// `line` with one of its numbers (chosen at random) replaced by `extreme`.
fn replace_a_number(line: &str, extreme: &str, rng: &mut StdRng) -> String {
    let bytes = line.as_bytes();
    let mut numbers = Vec::new();
    let mut i = 0;
    while i < bytes.len() {
        let starts = bytes[i].is_ascii_digit()
            || (bytes[i] == b'-' && bytes.get(i + 1).is_some_and(u8::is_ascii_digit));
        let inside_word = i > 0 && (bytes[i - 1].is_ascii_alphanumeric() || bytes[i - 1] == b'_');
        if starts && !inside_word {
            let start = i;
            i += 1;
            while i < bytes.len()
                && matches!(bytes[i], b'0'..=b'9' | b'.' | b'e' | b'E' | b'-' | b'+')
            {
                i += 1;
            }
            numbers.push(start..i);
        } else {
            i += 1;
        }
    }
    if numbers.is_empty() {
        return line.to_owned();
    }
    let range = numbers[rng.random_range(0..numbers.len())].clone();
    format!("{}{extreme}{}", &line[..range.start], &line[range.end..])
}

/// Loads, prepares and renders one mutated case at 4x4, 1 spp; `Err` is a refusal.
fn run_case(text: &str, obj: Option<(&str, &str)>, texture: &[u8]) -> Result<(), String> {
    let mut embedded: Vec<(&str, &[u8])> = vec![
        ("../assets/earth.jpg", texture),
        ("../../assets/earth.jpg", texture),
    ];
    if let Some((name, obj)) = obj {
        embedded.push((name, obj.as_bytes()));
    }
    let scene = load_scene(&SceneSource {
        name: "fuzz case".into(),
        text,
        base_dir: Default::default(),
        embedded: &embedded,
    })
    .map_err(|e| e.to_string())?;
    render_tiny(scene)
}

/// Prepares and renders `scene` at 4x4, 1 spp (`max_depth` at most 6); `Err` is a refusal.
fn render_tiny(mut scene: Scene) -> Result<(), String> {
    scene.camera.width = 4;
    scene.camera.height = 4;
    scene.settings.max_depth = scene.settings.max_depth.min(6);
    let prepared = PreparedScene::new(&scene).map_err(|e| e.to_string())?;
    let mut renderer = CpuRenderer::new(&prepared, &scene.camera, &scene.settings);
    renderer.advance(1).map_err(|e| e.to_string())?;
    let film = renderer.film().map_err(|e| e.to_string())?;
    assert_eq!(film.pixels.len(), 16);
    Ok(())
}

/// What became of the cases: refused, rendered.
#[derive(Default, Debug)]
struct Outcomes {
    refused: u64,
    rendered: u64,
}

/// Runs `cases` cases from `seed` on a worker thread: `generate` makes each, `run` loads and
/// renders it (`Err`: refused). Fails on a panic or a case over [`CASE_LIMIT`], after `save`
/// has written the case under `target/` (it returns where).
fn fuzz<C: Clone + Send + 'static>(
    seed: u64,
    cases: u64,
    mut generate: impl FnMut(&mut StdRng) -> C + Send + 'static,
    run: impl Fn(&C) -> Result<(), String> + Send + 'static,
    save: impl Fn(&C) -> String,
) -> Outcomes {
    let (sender, receiver) = mpsc::channel();
    let worker = std::thread::spawn(move || {
        let mut rng = StdRng::seed_from_u64(seed);
        for case in 0..cases {
            let input = generate(&mut rng);
            sender.send(Err((case, input.clone()))).unwrap();
            let result = catch_unwind(AssertUnwindSafe(|| run(&input)));
            sender.send(Ok(result.map(|r| r.is_ok()))).unwrap();
        }
    });
    let mut outcomes = Outcomes::default();
    let mut current = None;
    let fail = |(case, input): (u64, C), what: &str| -> ! {
        let saved = save(&input);
        panic!("fuzz case {case} of seed {seed} {what}; saved to {saved}");
    };
    loop {
        let limit = if current.is_some() {
            CASE_LIMIT
        } else {
            Duration::from_secs(600)
        };
        match receiver.recv_timeout(limit) {
            Ok(Err(case)) => current = Some((case, Instant::now())),
            Ok(Ok(Ok(true))) => outcomes.rendered += 1,
            Ok(Ok(Ok(false))) => outcomes.refused += 1,
            Ok(Ok(Err(_))) => fail(current.take().unwrap().0, "panicked"),
            Err(mpsc::RecvTimeoutError::Timeout) => {
                let (case, started) = current.take().unwrap();
                fail(case, &format!("ran {:.0?}", started.elapsed()));
            }
            Err(mpsc::RecvTimeoutError::Disconnected) => break,
        }
    }
    worker.join().unwrap();
    outcomes
}

/// A mutated scene case: the corpus file, its text and its mesh.
type SceneCase = (&'static str, String, Option<(&'static str, String)>);

/// The target folder, where failing cases are saved.
fn target() -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../target")
}

/// The number of cases and the seed: `PATHLIGHT_FUZZ_CASES` (default `suite`) and
/// `PATHLIGHT_FUZZ_SEED` (default 1).
fn cases_and_seed(suite: u64) -> (u64, u64) {
    let env = |name: &str| std::env::var(name).ok().map(|v| v.parse::<u64>().unwrap());
    (
        env("PATHLIGHT_FUZZ_CASES").unwrap_or(suite),
        env("PATHLIGHT_FUZZ_SEED").unwrap_or(1),
    )
}

/// Reports what became of the cases and checks that at least one in `one_in` rendered (else
/// the render path goes untested).
fn report(what: &str, cases: u64, started: Instant, outcomes: &Outcomes, one_in: u64) {
    eprintln!(
        "{what}: {cases} cases in {:.1?}: {} rendered, {} refused",
        started.elapsed(),
        outcomes.rendered,
        outcomes.refused
    );
    assert!(
        outcomes.rendered * one_in > cases,
        "{what}: only {} of {cases} mutated cases rendered",
        outcomes.rendered
    );
}

#[test]
fn mutated_scenes_and_meshes_are_refused_or_rendered() {
    let (cases, seed) = cases_and_seed(SUITE_CASES);
    let started = Instant::now();
    let corpus = corpus();
    let texture = tiny_texture();
    let generate = move |rng: &mut StdRng| -> SceneCase {
        let original = &corpus[rng.random_range(0..corpus.len())];
        let mutate_obj = original.obj.is_some() && rng.random_bool(0.3);
        let text = if mutate_obj && rng.random_bool(0.5) {
            original.text.clone()
        } else {
            mutate(&original.text, rng)
        };
        let obj = original.obj.as_ref().map(|(name, obj)| {
            let obj = if mutate_obj {
                mutate(obj, rng)
            } else {
                obj.clone()
            };
            (*name, obj)
        });
        (original.name, text, obj)
    };
    let run = move |(_, text, obj): &SceneCase| {
        run_case(text, obj.as_ref().map(|(n, o)| (*n, o.as_str())), &texture)
    };
    let save = |(name, text, obj): &SceneCase| {
        std::fs::write(target().join("fuzz-failure.toml"), text).unwrap();
        if let Some((_, obj)) = obj {
            std::fs::write(target().join("fuzz-failure.obj"), obj).unwrap();
        }
        format!("target/fuzz-failure.toml (a mutation of {name})")
    };
    let outcomes = fuzz(seed, cases, generate, run, save);
    report("scene files", cases, started, &outcomes, 5);
}

#[test]
fn mutated_gltf_files_are_refused_or_rendered() {
    let (cases, seed) = cases_and_seed(GLTF_SUITE_CASES);
    let started = Instant::now();
    let corpus = gltf::corpus();
    let outcomes = fuzz(
        seed,
        cases,
        move |rng| gltf::generate(&corpus, rng),
        gltf::run,
        |case| {
            let saved = gltf::save(case, &target());
            format!("{} (a mutation of {})", saved.display(), case.sample)
        },
    );
    // glTF is strict (an index or count out of range is an error), so fewer render.
    report("glTF files", cases, started, &outcomes, 8);
}
