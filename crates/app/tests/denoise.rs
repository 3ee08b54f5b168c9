//! The auxiliary images and the denoiser end to end: `render --aov` writes EXR layers and
//! PNGs beside the image, `render --denoise` and `pathlight denoise` (on an EXR or a state)
//! write a denoised image that keeps the raw one, and without Open Image Denoise `--denoise`
//! fails before rendering with how to get it. (The denoising tests need OIDN installed:
//! `tools/get-oidn.sh`.)

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use pathlight_core::Film;

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// Runs `pathlight args` in the repository with the environment variables `env`.
fn pathlight_with(env: &[(&str, &str)], args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_pathlight"))
        .args(args)
        .envs(env.iter().copied())
        .current_dir(repo())
        .output()
        .expect("the binary runs")
}

fn stderr(output: &Output) -> String {
    String::from_utf8_lossy(&output.stderr).into_owned()
}

fn succeeds(args: &[&str]) -> String {
    let output = pathlight_with(&[], args);
    let err = stderr(&output);
    assert!(output.status.success(), "{args:?}:\n{err}");
    err
}

/// A 32x32, 4-spp render of the default scene on the CPU backend, with `extra` options.
fn render(out: &Path, extra: &[&str]) -> String {
    let mut args = vec![
        "render",
        "--backend",
        "cpu",
        "--width",
        "32",
        "--height",
        "32",
        "--spp",
        "4",
        "-o",
        out.to_str().unwrap(),
    ];
    args.extend(extra);
    succeeds(&args)
}

const AOV_LAYERS: [(&str, [&str; 3]); 3] = [
    ("albedo", ["R", "G", "B"]),
    ("normal", ["X", "Y", "Z"]),
    ("noisy", ["R", "G", "B"]),
];

#[test]
fn aovs_are_written_as_exr_layers_and_png_siblings() {
    let dir = tempfile::tempdir().unwrap();
    let exr = dir.path().join("out.exr");
    render(&exr, &["--aov", "albedo,normal"]);
    let (colour, layers) = Film::read_exr_layers(&exr, &AOV_LAYERS).unwrap();
    let [albedo, normal, noisy] = [0, 1, 2].map(|i| layers[i].clone());
    let (albedo, normal) = (albedo.expect("albedo.R/G/B"), normal.expect("normal.X/Y/Z"));
    assert!(noisy.is_none(), "no raw layer without --denoise");
    assert!(
        albedo
            .pixels
            .iter()
            .flatten()
            .all(|c| (0.0..=1.0).contains(c))
    );
    assert!(
        normal
            .pixels
            .iter()
            .flatten()
            .all(|c| (-1.0..=1.0).contains(c))
    );
    // The same image as without them.
    let plain = dir.path().join("plain.exr");
    render(&plain, &[]);
    assert!(Film::read_exr(&plain).unwrap().pixels == colour.pixels);

    let png = dir.path().join("out.png");
    render(&png, &["--aov", "normal"]);
    assert!(dir.path().join("out.normal.png").is_file());
    assert!(!dir.path().join("out.albedo.png").exists());
    let normals = image::open(dir.path().join("out.normal.png"))
        .unwrap()
        .to_rgb8();
    // The floor at the bottom faces up: (0, 1, 0) is (128, 255, 128) as (n + 1) / 2.
    let floor = normals.get_pixel(16, 30);
    assert!(floor[1] > 240 && floor[0].abs_diff(128) < 20, "{floor:?}");
}

#[test]
fn denoised_images_keep_the_raw_one_and_denoise_reads_exr_and_state() {
    let dir = tempfile::tempdir().unwrap();
    let exr = dir.path().join("dn.exr");
    let err = render(&exr, &["--denoise", "--aov", "albedo,normal"]);
    assert!(err.contains("denoiser: Open Image Denoise 2."), "{err}");
    let (denoised, layers) = Film::read_exr_layers(&exr, &AOV_LAYERS).unwrap();
    let noisy = layers[2].clone().expect("the raw image as noisy.R/G/B");
    assert!(denoised.pixels != noisy.pixels);
    // The denoised image is smoother: less difference between neighbouring pixels.
    let roughness = |f: &Film| {
        f.pixels
            .windows(2)
            .map(|w| (w[0][1] - w[1][1]).abs() as f64)
            .sum::<f64>()
    };
    assert!(roughness(&denoised) < roughness(&noisy));

    // The farm path: a state with its auxiliary images, denoised later.
    let state = dir.path().join("r.state");
    render(&state, &["--aov", "albedo,normal"]);
    let from_state = dir.path().join("from-state.exr");
    succeeds(&[
        "denoise",
        state.to_str().unwrap(),
        "-o",
        from_state.to_str().unwrap(),
    ]);
    let from_state = Film::read_exr(&from_state).unwrap();
    assert!(
        from_state.pixels == denoised.pixels,
        "the same guides, the same result"
    );
    // An EXR's layers guide it as well.
    let raw = dir.path().join("raw.exr");
    render(&raw, &["--aov", "albedo,normal"]);
    let from_exr = dir.path().join("from-exr.png");
    succeeds(&[
        "denoise",
        raw.to_str().unwrap(),
        "-o",
        from_exr.to_str().unwrap(),
        "--mode",
        "fast",
    ]);
    assert!(from_exr.is_file());
}

#[test]
fn without_oidn_denoising_fails_before_rendering_saying_how_to_get_it() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("never.png");
    let nowhere = dir.path().join("no-oidn");
    let output = pathlight_with(
        &[("PATHLIGHT_OIDN", nowhere.to_str().unwrap())],
        &[
            "render",
            "--backend",
            "cpu",
            "--spp",
            "1",
            "--denoise",
            "-o",
            out.to_str().unwrap(),
        ],
    );
    let err = stderr(&output);
    assert_eq!(output.status.code(), Some(1), "{err}");
    assert!(
        err.contains("Open Image Denoise 2 was not found") && err.contains("tools/get-oidn.sh"),
        "{err}"
    );
    assert!(
        err.contains("no-oidn"),
        "the places looked at are named: {err}"
    );
    assert!(!err.contains("rendered"), "nothing was rendered: {err}");
    assert!(!out.exists());
    // A state is not denoised: refused, saying what to do.
    let output = pathlight_with(&[], &["render", "--denoise", "-o", "x.state"]);
    assert!(stderr(&output).contains("pathlight denoise x.state"));
    assert!(!output.status.success());
}
