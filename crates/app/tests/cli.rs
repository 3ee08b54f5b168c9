//! The `pathlight` binary end to end: the issue's furnace command, PNG and EXR output, and
//! every class of bad input failing with a clear message and a non-zero status.

mod common;

use common::{send, stderr};

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn pathlight(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_pathlight"))
        .args(args)
        .current_dir(repo())
        .output()
        .expect("the binary runs")
}

fn fails_with(args: &[&str], needles: &[&str]) -> String {
    let output = pathlight(args);
    let err = stderr(&output);
    assert!(!output.status.success(), "{args:?} succeeded:\n{err}");
    assert_eq!(
        output.status.code(),
        Some(1),
        "{args:?}: a panic or signal?\n{err}"
    );
    for needle in needles {
        assert!(err.contains(needle), "{args:?}: {needle:?} not in:\n{err}");
    }
    err
}

/// The options of a 16x16 image on the CPU backend (for `render` and `bench`).
const SMALL_ON_CPU: [&str; 6] = ["--backend", "cpu", "--width", "16", "--height", "16"];

/// Renders `scene` 16x16 at 2 spp on the CPU backend with `extra` options into the EXR `out`,
/// which must succeed: what it printed and the image.
fn render_small(scene: &str, extra: &[&str], out: &Path) -> (String, pathlight_core::Film) {
    let mut args = vec!["render", scene, "--spp", "2"];
    args.extend(SMALL_ON_CPU);
    args.extend(extra);
    args.extend(["-o", out.to_str().unwrap()]);
    let output = pathlight(&args);
    let err = stderr(&output);
    assert!(output.status.success(), "{args:?}: {err}");
    (err, pathlight_core::Film::read_exr(out).unwrap())
}

/// Starts a 16x16 CPU render of the default scene at `spp` into `out`, stderr piped.
fn spawn_cpu_render(spp: &str, out: &Path) -> std::process::Child {
    Command::new(env!("CARGO_BIN_EXE_pathlight"))
        .arg("render")
        .args(SMALL_ON_CPU)
        .args(["--spp", spp, "-o"])
        .arg(out)
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap()
}

/// The issue's acceptance command: centre pixels 0.8 +- 0.01, background 1.0 +- 0.005.
#[test]
fn furnace_exr_reads_albedo_and_background() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("f.exr");
    let output = pathlight(&[
        "render",
        "scenes/refs/furnace-0.8.toml",
        "--spp",
        "64",
        "--width",
        "64",
        "--height",
        "64",
        "-o",
        out.to_str().unwrap(),
    ]);
    let err = stderr(&output);
    assert!(output.status.success(), "{err}");
    assert!(
        err.contains("adapter: ") || err.contains("backend: cpu backend"),
        "where it renders is printed:\n{err}"
    );
    let film = pathlight_core::Film::read_exr(&out).unwrap();
    let (width, pixels) = (film.width as usize, film.pixels);
    assert_eq!((width, pixels.len()), (64, 64 * 64));
    for y in 28..36 {
        for x in 28..36 {
            for c in pixels[y * 64 + x] {
                assert!((c - 0.8).abs() <= 0.01, "centre pixel ({x}, {y}) = {c}");
            }
        }
    }
    for (x, y) in [(0, 0), (63, 0), (0, 63), (63, 63), (2, 32), (61, 32)] {
        for c in pixels[y * 64 + x] {
            assert!(
                (c - 1.0).abs() <= 0.005,
                "background pixel ({x}, {y}) = {c}"
            );
        }
    }
}

#[test]
fn png_output_of_the_default_scene() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("seed.png");
    let output = pathlight(&[
        "render",
        "--spp",
        "2",
        "--width",
        "40",
        "--height",
        "30",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(output.status.success(), "{}", stderr(&output));
    let decoder = std::fs::read(&out).unwrap();
    assert_eq!(&decoder[1..4], b"PNG");
    // IHDR: width and height, big-endian, at bytes 16..24.
    assert_eq!(u32::from_be_bytes(decoder[16..20].try_into().unwrap()), 40);
    assert_eq!(u32::from_be_bytes(decoder[20..24].try_into().unwrap()), 30);
}

#[test]
fn missing_and_malformed_scene_files() {
    let err = fails_with(&["render", "no/such/scene.toml"], &["no/such/scene.toml"]);
    // The file's error names the system's reason, which is said once.
    let line = err.lines().find(|l| l.contains("scene.toml")).unwrap();
    let parts: Vec<&str> = line.split(": ").collect();
    assert!(
        parts.windows(2).all(|w| w[0] != w[1]),
        "a cause said twice: {line}"
    );
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("bad.toml");
    std::fs::write(
        &bad,
        "[camera]\nposition = [0, 0, 3]\nlook_at = [0, 0, 0]\nfov_y = 40\nzoom = 2\n",
    )
    .unwrap();
    fails_with(&["render", bad.to_str().unwrap()], &["bad.toml:5:", "zoom"]);
}

#[test]
fn absurd_sizes_are_refused_with_the_limit() {
    fails_with(&["render", "--width", "0"], &["1..=8192"]);
    fails_with(&["render", "--height", "100000"], &["1..=8192"]);
    fails_with(&["render", "--spp", "0"], &["spp = 0", "1..=1048576"]);
    fails_with(&["render", "--max-depth", "0"], &["max_depth = 0"]);
}

#[test]
fn bad_outputs_are_refused_before_rendering() {
    let err = fails_with(
        &["render", "-o", "/no/such/dir/out.png"],
        &["/no/such/dir/out.png", "not writable"],
    );
    let started = |err: &str| err.contains("adapter:") || err.contains("backend:");
    assert!(!started(&err), "rendering started:\n{err}");
    let err = fails_with(
        &["render", "-o", "out.jpg"],
        &["out.jpg", ".png or .exr", ".state"],
    );
    assert!(!started(&err), "rendering started:\n{err}");
}

#[test]
fn adapter_choice_errors_are_clear() {
    fails_with(
        &["render", "--spp", "1", "--adapter", "no-such-gpu"],
        &["no adapter matches \"no-such-gpu\"", "found:"],
    );
    // DX12 does not exist on Linux: the same as a machine without any adapter. The GPU
    // backend fails, saying what to install; the default renders on the CPU backend.
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("no-adapter.png");
    let render = |backend: &str| {
        Command::new(env!("CARGO_BIN_EXE_pathlight"))
            .args(["render", "--backend", backend, "--spp", "1"])
            .args(["--width", "16", "--height", "16", "-o"])
            .arg(&out)
            .env("WGPU_BACKEND", "dx12")
            .output()
            .unwrap()
    };
    let output = render("gpu");
    assert_eq!(output.status.code(), Some(1));
    let err = stderr(&output);
    assert!(
        err.contains("no GPU adapter found") && err.contains("mesa-vulkan-drivers"),
        "{err}"
    );
    assert!(!out.exists(), "a failed render leaves no empty file");
    let output = render("auto");
    let err = stderr(&output);
    assert!(output.status.success(), "{err}");
    assert!(
        err.contains("no hardware GPU found: using the CPU backend")
            && err.contains("no adapter for --backend gpu"),
        "{err}"
    );
    assert!(out.exists());
}

/// Whether `pathlight render --list-adapters` lists a hardware GPU (an adapter that is not
/// of type `Cpu`).
fn hardware_gpu_listed() -> bool {
    let output = pathlight(&["render", "--list-adapters"]);
    assert!(output.status.success(), "{}", stderr(&output));
    String::from_utf8_lossy(&output.stdout)
        .lines()
        .any(|line| !line.contains(", Cpu, "))
}

/// `--backend auto` (the default) renders on a hardware GPU when there is one, else on the
/// CPU backend, and says which and why. On CI (software adapters only) that is the CPU
/// backend.
#[test]
fn auto_backend_says_what_it_chose() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("auto.png");
    let output = pathlight(&[
        "render",
        "--width",
        "16",
        "--height",
        "16",
        "--spp",
        "1",
        "-o",
        out.to_str().unwrap(),
    ]);
    let err = stderr(&output);
    assert!(output.status.success(), "{err}");
    if hardware_gpu_listed() {
        assert!(
            err.contains("hardware GPU found: using the GPU backend on")
                && err.contains("adapter: "),
            "{err}"
        );
    } else {
        assert!(
            err.contains("no hardware GPU found: using the CPU backend (")
                && err.contains("--backend gpu forces")
                && err.contains("backend: cpu backend"),
            "{err}"
        );
    }
    let output = pathlight(&[
        "bench", "--width", "16", "--height", "16", "--frames", "1", "--warmup", "0", "--json",
    ]);
    assert!(output.status.success(), "{}", stderr(&output));
    let report: serde_json::Value = serde_json::from_slice(&output.stdout).expect("JSON");
    assert_eq!(report["backend_asked"], "auto");
    let expected = if hardware_gpu_listed() { "gpu" } else { "cpu" };
    assert_eq!(report["backend"], expected, "{report}");
}

/// A stderr that cannot be written (a closed pipe, `2>&1 | head -1`) neither panics nor
/// loses the image.
#[test]
fn unwritable_stderr_still_writes_the_image() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("quiet.png");
    // A pipe whose reading end is closed at once: every write to it fails with EPIPE.
    let mut child = spawn_cpu_render("1", &out);
    drop(child.stderr.take());
    let status = child.wait().unwrap();
    assert!(status.success(), "{status}");
    assert!(std::fs::metadata(&out).unwrap().len() > 0);
}

/// Ctrl-C (SIGINT) and SIGTERM (what `kill`, `timeout`, systemd and job schedulers send)
/// stop the render between batches; it writes what was rendered, replacing the previous
/// image, and exits with status 130 so that scripts can tell it from a finished render.
#[test]
fn interrupt_keeps_the_rendered_samples() {
    for signal in ["INT", "TERM"] {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("interrupted.png");
        std::fs::write(&out, "previous").unwrap();
        let child = spawn_cpu_render("1000000", &out);
        std::thread::sleep(std::time::Duration::from_millis(1500));
        send(signal, child.id());
        let output = child.wait_with_output().unwrap();
        let err = String::from_utf8_lossy(&output.stderr);
        assert_eq!(output.status.code(), Some(130), "{signal}: {err}");
        assert!(
            err.contains("interrupted: kept") && err.contains("wrote"),
            "{err}"
        );
        let image = image::open(&out).expect("a whole PNG").to_rgb8();
        assert_eq!(image.dimensions(), (16, 16));
    }
}

/// SIGKILL cannot be caught: a render killed before it writes leaves the previous image as
/// it was, and no stray file beside it.
#[test]
fn a_killed_render_leaves_the_previous_image() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("kept.png");
    std::fs::write(&out, "previous").unwrap();
    let child = spawn_cpu_render("1000000", &out);
    std::thread::sleep(std::time::Duration::from_millis(1500));
    send("KILL", child.id());
    child.wait_with_output().unwrap();
    assert_eq!(std::fs::read_to_string(&out).unwrap(), "previous");
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
}

/// A signal while the GPU is still being set up loses nothing either: the previous image
/// stays (or, had the render begun, is replaced by a whole one), never an empty file.
#[test]
fn a_signal_during_set_up_loses_nothing() {
    for signal in ["INT", "TERM"] {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("early.png");
        std::fs::write(&out, "previous").unwrap();
        let child = Command::new(env!("CARGO_BIN_EXE_pathlight"))
            .args([
                "render", "--width", "16", "--height", "16", "--spp", "100000", "-o",
            ])
            .arg(&out)
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap();
        std::thread::sleep(std::time::Duration::from_millis(100));
        send(signal, child.id());
        let output = child.wait_with_output().unwrap();
        let err = String::from_utf8_lossy(&output.stderr);
        assert_eq!(output.status.code(), Some(130), "{signal}: {err}");
        let bytes = std::fs::read(&out).unwrap();
        assert!(
            bytes == b"previous" || image::load_from_memory(&bytes).is_ok(),
            "{signal}: {} bytes that are neither the previous file nor a PNG\n{err}",
            bytes.len()
        );
    }
}

/// A full disk is an error, and the previous image stays whole (it used to be truncated,
/// and a small image could even be reported written). A tmpfs of 32 KiB filled up, in a
/// private mount namespace (`unshare`, util-linux), so the test needs no root.
#[test]
fn a_full_disk_keeps_the_previous_image() {
    let dir = tempfile::tempdir().unwrap();
    let script = r#"mount -t tmpfs -o size=32k tmpfs "$1" || exit 99
printf previous > "$1/out.png"
dd if=/dev/zero of="$1/fill" bs=1k count=64 2>/dev/null
"$2" render --backend cpu --width 64 --height 64 --spp 1 -o "$1/out.png" 2>"$1/../stderr"
echo "status=$?"
echo "content=$(cat "$1/out.png")"
ls -A "$1""#;
    let disk = dir.path().join("disk");
    std::fs::create_dir(&disk).unwrap();
    let output = Command::new("unshare")
        .args([
            "--user",
            "--map-root-user",
            "--mount",
            "sh",
            "-c",
            script,
            "sh",
        ])
        .arg(&disk)
        .arg(env!("CARGO_BIN_EXE_pathlight"))
        .output()
        .expect("unshare (util-linux) runs");
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(
        stdout.contains("status="),
        "the tmpfs could not be made: {output:?}"
    );
    let err = std::fs::read_to_string(dir.path().join("stderr")).unwrap();
    assert!(stdout.contains("status=1"), "{stdout}\n{err}");
    assert!(
        err.contains("No space left on device") && !err.contains("wrote"),
        "{err}"
    );
    assert!(stdout.contains("content=previous"), "{stdout}");
    assert_eq!(
        stdout.lines().filter(|l| l.starts_with('.')).count(),
        0,
        "{stdout}"
    );
}

#[test]
fn list_adapters_names_one() {
    let output = pathlight(&["render", "--list-adapters"]);
    assert!(output.status.success());
    assert!(!String::from_utf8_lossy(&output.stdout).trim().is_empty());
}

/// Without a display, `pathlight view` (and a bare `pathlight`) says so and points to
/// `pathlight render`, without opening anything.
#[test]
fn viewer_without_a_display_suggests_render() {
    for args in [&["view"][..], &[]] {
        let output = Command::new(env!("CARGO_BIN_EXE_pathlight"))
            .args(args)
            .env_remove("DISPLAY")
            .env_remove("WAYLAND_DISPLAY")
            .output()
            .unwrap();
        let err = stderr(&output);
        assert_eq!(output.status.code(), Some(1), "{args:?}:\n{err}");
        assert!(
            err.contains("no display") && err.contains("pathlight render"),
            "{args:?}:\n{err}"
        );
    }
}

/// `pathlight bench --json` (CPU backend, so it runs anywhere): the figures hang together.
#[test]
fn bench_reports_consistent_figures_as_json() {
    let mut args = vec!["bench"];
    args.extend(SMALL_ON_CPU);
    args.extend(["--frames", "3", "--warmup", "1", "--json"]);
    let output = pathlight(&args);
    assert!(output.status.success(), "{}", stderr(&output));
    let report: serde_json::Value = serde_json::from_slice(&output.stdout).expect("JSON");
    assert_eq!(report["backend"], "cpu");
    assert_eq!(report["backend_asked"], "cpu");
    let run = &report["runs"][0];
    assert_eq!(run["frames"], 3);
    assert_eq!(run["triangles"], 6208, "the default scene's vase");
    let number = |key: &str| run[key].as_f64().unwrap_or_else(|| panic!("{key}: {run}"));
    let (fps, seconds) = (number("fps"), number("seconds"));
    assert!(
        (fps * seconds - 3.0).abs() < 1e-6,
        "fps {fps} over {seconds} s"
    );
    assert!((number("samples_per_s") - fps * 256.0).abs() < 1e-6 * fps * 256.0);
    // Every sample traces its camera ray; at most two rays per segment of max_depth 8.
    let rays = number("rays_per_sample");
    assert!((1.0..=16.0).contains(&rays), "{rays} rays per sample");
    assert!(number("rays_per_s") > 0.0 && number("first_frame_s") > 0.0);
}

/// Bad bench and view options are refused with the value named.
#[test]
fn bench_and_view_refuse_bad_options() {
    fails_with(
        &[
            "bench",
            "--backend",
            "cpu",
            "--without",
            "teapot",
            "--frames",
            "1",
        ],
        &["\"teapot\"", "vase"],
    );
    fails_with(
        &[
            "bench",
            "--backend",
            "cpu",
            "--accel",
            "brute-force",
            "--frames",
            "1",
        ],
        &["brute-force", "GPU backend"],
    );
    fails_with(
        &[
            "bench",
            "--backend",
            "cpu",
            "--gpu-kernel",
            "wavefront",
            "--frames",
            "1",
        ],
        &["--gpu-kernel wavefront", "GPU backend"],
    );
    for strength in ["-1", "0", "nan"] {
        let output = pathlight(&["view", "--light-strength", strength]);
        let err = stderr(&output);
        assert_eq!(
            output.status.code(),
            Some(2),
            "{strength}: clap's usage error\n{err}"
        );
        assert!(err.contains("positive finite number"), "{strength}:\n{err}");
    }
    // A render's time limit of zero stopped before the first sample, wrote nothing and
    // exited 0: now a usage error, and no file.
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("zero.png");
    let mut args = vec!["render", "scenes/refs/furnace-0.8.toml"];
    args.extend(SMALL_ON_CPU);
    args.extend(["--time-limit", "0s", "-o", out.to_str().unwrap()]);
    let output = pathlight(&args);
    let err = stderr(&output);
    assert_eq!(output.status.code(), Some(2), "clap's usage error\n{err}");
    assert!(err.contains("must be above zero"), "{err}");
    assert!(!out.exists());
    // An infinite or absurd time limit panicked converting to a Duration.
    for limit in ["inf", "1e300", "nan", "-1"] {
        let output = pathlight(&["bench", "--backend", "cpu", "--time-limit", limit]);
        let err = stderr(&output);
        assert_eq!(
            output.status.code(),
            Some(2),
            "{limit}: clap's usage error\n{err}"
        );
        assert!(err.contains("is not a duration"), "{limit}:\n{err}");
    }
}

/// `--sampler` replaces the scene's sampler: `sobol` (the default) gives the image the scene
/// gives, bit for bit; `independent` another one.
#[test]
fn sampler_option_overrides_the_scene() {
    let dir = tempfile::tempdir().unwrap();
    let render = |sampler: Option<&str>| {
        let out = dir
            .path()
            .join(format!("{}.exr", sampler.unwrap_or("scene")));
        let mut args = vec!["render"];
        args.extend(SMALL_ON_CPU);
        args.extend(["--spp", "4", "-o", out.to_str().unwrap()]);
        args.extend(sampler.map(|s| ["--sampler", s]).into_iter().flatten());
        let output = pathlight(&args);
        assert!(output.status.success(), "{}", stderr(&output));
        pathlight_core::Film::read_exr(&out).unwrap().pixels
    };
    let scene = render(None);
    assert_eq!(render(Some("sobol")), scene);
    assert_ne!(render(Some("independent")), scene);
    let output = pathlight(&["render", "--sampler", "halton"]);
    let err = stderr(&output);
    assert_eq!(output.status.code(), Some(2), "clap's usage error\n{err}");
    assert!(
        err.contains("'halton'") && err.contains("sobol, independent"),
        "{err}"
    );
}

/// `--env` lights a scene with a map: the furnace's background then reads the map (the
/// scene file's constant 1 is replaced), `--env-strength` scales it, and the lens options
/// apply; bad values name themselves.
#[test]
fn env_and_lens_options_replace_the_scenes() {
    let dir = tempfile::tempdir().unwrap();
    let render = |extra: &[&str], name: &str| {
        render_small(
            "scenes/refs/furnace-0.8.toml",
            extra,
            &dir.path().join(name),
        )
        .1
    };
    let plain = render(&[], "plain.exr");
    assert_eq!(plain.pixel(0, 0), [1.0; 3]);
    let sky = render(&["--env", "assets/env/city.exr"], "sky.exr");
    let brighter = render(
        &["--env", "assets/env/city.exr", "--env-strength", "2"],
        "brighter.exr",
    );
    let corner = sky.pixel(0, 0);
    assert!(
        corner != [1.0; 3] && corner.iter().all(|c| *c > 0.0),
        "{corner:?}"
    );
    for (twice, once) in brighter.pixel(0, 0).iter().zip(corner) {
        assert!((twice - 2.0 * once).abs() <= 1e-5 * once);
    }
    let lens = render(&["--aperture", "0.2", "--focus-distance", "1"], "lens.exr");
    assert!(lens.pixels != plain.pixels);
    let zero = render(&["--aperture", "0", "--focus-distance", "9"], "zero.exr");
    assert!(
        zero.pixels == plain.pixels,
        "a lens of radius 0 is the pinhole"
    );
    for (args, needles) in [
        (vec!["--env", "no/such.exr"], vec!["no/such.exr"]),
        (
            vec!["--env", "Cargo.toml"],
            vec!["Cargo.toml", "cannot decode image"],
        ),
        (
            vec!["--env-rotation", "10"],
            vec!["--env-rotation need an environment map"],
        ),
        (
            vec!["--aperture", "-1"],
            vec!["--aperture = -1 must be >= 0 and at most 1e15"],
        ),
        // The limits a scene file's lens is held to (one check serves both).
        (
            vec!["--aperture", "1e30"],
            vec!["--aperture = 1000000000000000000000000000000 must be >= 0 and at most 1e15"],
        ),
        (
            vec!["--focus-distance", "0"],
            vec!["--focus-distance = 0 must be > 0 and at most 1e15"],
        ),
        (
            vec!["--env-strength", "-2"],
            vec!["--env-strength = -2 must be finite and >= 0"],
        ),
    ] {
        let mut all = vec!["render", "scenes/refs/furnace-0.8.toml"];
        all.extend(SMALL_ON_CPU);
        all.extend(args);
        all.extend(["-o", "/tmp/never-written.png"]);
        fails_with(&all, &needles);
    }
}

#[test]
fn gltf_files_render_directly_and_camera_numbers_are_checked() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("box.png");
    let glb = "crates/scene/tests/data/gltf/BoxTextured-glTF-Binary/BoxTextured.glb";
    let output = pathlight(&[
        "render",
        glb,
        "--backend",
        "cpu",
        "--width",
        "16",
        "--height",
        "9",
        "--spp",
        "2",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let image = image::open(&out).unwrap().to_rgb8();
    assert_eq!(image.dimensions(), (16, 9));
    // The cube fills the middle (textured, not the grey sky at the corners).
    let (centre, corner) = (image.get_pixel(8, 4), image.get_pixel(0, 0));
    assert_ne!(centre, corner);
    fails_with(
        &["render", glb, "--camera", "0", "-o", out.to_str().unwrap()],
        &[
            "BoxTextured.glb",
            "has no camera 0: it has 0 perspective camera(s)",
        ],
    );
    fails_with(
        &["render", "scenes/default.toml", "--camera", "0"],
        &["--camera chooses a camera of a glTF file"],
    );
    fails_with(
        &[
            "render",
            "crates/scene/tests/data/gltf/RecursiveNodes/RecursiveNodes.gltf",
        ],
        &["RecursiveNodes.gltf: node 0: is its own ancestor"],
    );
}

/// `PATHLIGHT_CPU_LEVEL` runs the CPU backend at the level it names (the report says which)
/// with the same image bit for bit as the best level; a level this CPU cannot run, or no
/// level at all, is refused naming the levels there are.
#[test]
fn the_cpu_level_variable_picks_the_level_and_keeps_the_image() {
    let dir = tempfile::tempdir().unwrap();
    let render = |level: Option<&str>, name: &str| {
        let out = dir.path().join(name);
        let mut command = Command::new(env!("CARGO_BIN_EXE_pathlight"));
        command
            .args(["render", "scenes/refs/cornell-spheres.toml", "--spp", "2"])
            .args(SMALL_ON_CPU)
            .arg("-o")
            .arg(&out)
            .current_dir(repo());
        match level {
            Some(level) => command.env("PATHLIGHT_CPU_LEVEL", level),
            None => command.env_remove("PATHLIGHT_CPU_LEVEL"),
        };
        let output = command.output().unwrap();
        (output, out)
    };
    let (best, best_image) = render(None, "best.exr");
    assert!(best.status.success(), "{}", stderr(&best));
    let (baseline, baseline_image) = render(Some("baseline"), "baseline.exr");
    let err = stderr(&baseline);
    assert!(baseline.status.success(), "{err}");
    assert!(
        err.contains("cpu backend, ") && err.contains(", baseline"),
        "{err}"
    );
    assert_eq!(
        std::fs::read(&best_image).unwrap(),
        std::fs::read(&baseline_image).unwrap(),
        "the levels' images differ"
    );
    let (refused, _) = render(Some("x86-64-v9"), "refused.exr");
    let err = stderr(&refused);
    assert_eq!(refused.status.code(), Some(1), "{err}");
    assert!(
        err.contains("PATHLIGHT_CPU_LEVEL=x86-64-v9") && err.contains("baseline"),
        "{err}"
    );
}

/// A glTF file opened on its own is lit by the grey sky even when it has emitters (glTF
/// viewers light a model), saying so; `--no-default-env` leaves its emitters alone; the flag
/// is refused for a TOML scene and beside `--env`; a file with punctual lights gets no sky.
#[test]
fn a_gltf_file_opens_lit_unless_told_otherwise() {
    let dir = tempfile::tempdir().unwrap();
    let positions: [f32; 9] = [-1.0, -1.0, 0.0, 1.0, -1.0, 0.0, 0.0, 1.0, 0.0];
    let bytes: Vec<u8> = positions.iter().flat_map(|v| v.to_le_bytes()).collect();
    std::fs::write(dir.path().join("panel.bin"), bytes).unwrap();
    let gltf = dir.path().join("panel.gltf");
    std::fs::write(
        &gltf,
        r#"{"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "material": 0}]}],
        "materials": [{"emissiveFactor": [1, 1, 1]}],
        "buffers": [{"byteLength": 36, "uri": "panel.bin"}],
        "bufferViews": [{"buffer": 0, "byteLength": 36}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
            "min": [-1, -1, 0], "max": [1, 1, 0]}]}"#,
    )
    .unwrap();
    let render = |extra: &[&str], name: &str| {
        render_small(gltf.to_str().unwrap(), extra, &dir.path().join(name))
    };
    let (err, lit) = render(&[], "lit.exr");
    assert!(
        err.contains(
            "lighting: a uniform grey sky of radiance 0.8 and the file's emissive material ("
        ),
        "{err}"
    );
    assert_eq!(lit.pixels[0], [0.8; 3], "the corner sees the sky");
    let (err, alone) = render(&["--no-default-env"], "alone.exr");
    assert!(
        err.contains("lighting: the file's emissive material alone"),
        "{err}"
    );
    assert_eq!(alone.pixels[0], [0.0; 3], "no sky");
    assert!(
        alone.pixels.iter().any(|p| p[0] > 0.5),
        "the panel still shows"
    );
    fails_with(
        &["render", "scenes/refs/furnace-0.8.toml", "--no-default-env"],
        &["--no-default-env", "glTF"],
    );
    fails_with(
        &[
            "render",
            gltf.to_str().unwrap(),
            "--no-default-env",
            "--env",
            "assets/env/city.exr",
        ],
        &["--no-default-env and --env"],
    );
    // A file that places punctual lights is lit by them alone: no sky behind its ground.
    let lights = "crates/scene/tests/data/gltf/PunctualLights/lights.gltf";
    let (err, lit) = render_small(lights, &[], &dir.path().join("lights.exr"));
    assert!(
        err.contains("lighting: the file's 3 punctual lights, no sky"),
        "{err}"
    );
    // Extensions pathlight does not read are named in one warning; one the file requires
    // refuses it.
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../..")
            .join(lights),
    )
    .unwrap()
    .replace(
        r#""extensionsUsed": ["#,
        r#""extensionsUsed": ["KHR_materials_iridescence", "EXT_made_up", "#,
    );
    let unsupported = dir.path().join("unsupported.gltf");
    std::fs::write(&unsupported, &text).unwrap();
    let (err, _) = render_small(
        unsupported.to_str().unwrap(),
        &[],
        &dir.path().join("unsupported.exr"),
    );
    assert!(
        err.contains(
            "uses glTF extensions pathlight does not support, which are ignored: \
             KHR_materials_iridescence, EXT_made_up"
        ),
        "{err}"
    );
    let required = text.replacen(
        r#""extensions": {"#,
        r#""extensionsRequired": ["EXT_made_up"], "extensions": {"#,
        1,
    );
    std::fs::write(&unsupported, required).unwrap();
    fails_with(
        &["render", unsupported.to_str().unwrap()],
        &[r#"extensionsRequired[0] = "EXT_made_up": Unsupported extension"#],
    );
    // The ground under a sun of 2 W/m^2 at 60 degrees: about 0.78 x 2 x 0.5 / pi.
    let mean = lit.mean()[0];
    assert!((0.15..0.5).contains(&mean), "mean {mean}");
}

/// A glTF file that uses every material extension pathlight reads, with their textures and
/// vertex colours (`MaterialLayers/layers.gltf`), renders without a warning, and its two
/// materials come out unlike each other and the grey sky.
#[test]
fn a_gltf_file_with_every_supported_material_extension_renders_without_warnings() {
    let dir = tempfile::tempdir().unwrap();
    let (err, film) = render_small(
        "crates/scene/tests/data/gltf/MaterialLayers/layers.gltf",
        &[],
        &dir.path().join("layers.exr"),
    );
    assert!(
        !err.contains("WARN") && !err.contains("ignored"),
        "warned:\n{err}"
    );
    // The camera's 2:1 view fitted into 16x16: the velvet left, the paint right, sky corners.
    let [velvet, paint, sky] = [film.pixel(4, 8), film.pixel(11, 8), film.pixel(0, 0)];
    assert!(
        velvet[0] > velvet[2],
        "the velvet is not red-pink: {velvet:?}"
    );
    assert!(paint[2] > paint[0], "the paint is not blue: {paint:?}");
    assert!((sky[1] - 0.8).abs() < 0.05, "the sky: {sky:?}");
}

/// A glTF file placing one triangle 400 times keeps it once, as 400 instances, and needs
/// about 280 + 400 x 512 bytes: a `PATHLIGHT_MEMORY_LIMIT` below that refuses it before
/// reading it, naming the file, the meshes, placements, triangles, instances and bytes (exit
/// status 1, no abort); one above renders it; a limit that is not a size is refused naming
/// the variable.
#[test]
fn a_gltf_too_large_for_the_memory_limit_is_refused_saying_how_large() {
    let dir = tempfile::tempdir().unwrap();
    let positions: [f32; 9] = [-1.0, -1.0, 0.0, 1.0, -1.0, 0.0, 0.0, 1.0, 0.0];
    let bytes: Vec<u8> = positions.iter().flat_map(|v| v.to_le_bytes()).collect();
    std::fs::write(dir.path().join("panel.bin"), bytes).unwrap();
    let nodes: Vec<String> = (0..400)
        .map(|i| format!(r#"{{"mesh": 0, "translation": [{}, 0, -5]}}"#, i % 20))
        .collect();
    let gltf = dir.path().join("many.gltf");
    std::fs::write(
        &gltf,
        format!(
            r#"{{"asset": {{"version": "2.0"}}, "scene": 0,
            "scenes": [{{"nodes": [{}]}}], "nodes": [{}],
            "meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0}}}}]}}],
            "buffers": [{{"byteLength": 36, "uri": "panel.bin"}}],
            "bufferViews": [{{"buffer": 0, "byteLength": 36}}],
            "accessors": [{{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                "min": [-1, -1, 0], "max": [1, 1, 0]}}]}}"#,
            (0..400)
                .map(|i| i.to_string())
                .collect::<Vec<_>>()
                .join(", "),
            nodes.join(", ")
        ),
    )
    .unwrap();
    let render = |limit: &str| {
        Command::new(env!("CARGO_BIN_EXE_pathlight"))
            .args(["render", gltf.to_str().unwrap(), "--spp", "1"])
            .args(SMALL_ON_CPU)
            .arg("-o")
            .arg(dir.path().join("many.png"))
            .env("PATHLIGHT_MEMORY_LIMIT", limit)
            .current_dir(repo())
            .output()
            .unwrap()
    };
    let refused = render("64K");
    let err = stderr(&refused);
    assert_eq!(refused.status.code(), Some(1), "{err}");
    assert!(
        err.contains("many.gltf: scene 0: places 1 meshes 400 times: 1 triangles and 400 instances need about 200.3 KiB (about 280 bytes a triangle, 512 an instance), more than the 64.0 KiB PATHLIGHT_MEMORY_LIMIT allows"),
        "{err}"
    );
    let rendered = render("1M");
    assert!(rendered.status.success(), "{}", stderr(&rendered));
    let nonsense = render("plenty");
    let err = stderr(&nonsense);
    assert_eq!(nonsense.status.code(), Some(1), "{err}");
    assert!(
        err.contains("PATHLIGHT_MEMORY_LIMIT=\"plenty\" is not a number of bytes"),
        "{err}"
    );
}
