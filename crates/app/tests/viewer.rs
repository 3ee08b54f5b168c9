//! `pathlight view` end to end under a real X server: Xvfb, with xdotool for the mouse and
//! keys and ImageMagick's `import` for screenshots (Debian packages `xvfb`, `xdotool`,
//! `imagemagick`; `.ci/run` installs them). Each test runs on both backends: the GPU one on
//! whatever adapter presents to the window (lavapipe on CI), the CPU one on its own thread,
//! presenting through that adapter.

use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// Longest wait for a line; the first frame on a software adapter includes compiling the
/// integrator (about 10 s on lavapipe in a debug build).
const LINE_TIMEOUT: Duration = Duration::from_secs(240);

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn require(tool: &str) {
    let found = Command::new("sh")
        .args(["-c", &format!("command -v {tool}")])
        .output()
        .is_ok_and(|o| o.status.success());
    assert!(
        found,
        "{tool} is missing: install the Debian packages xvfb xdotool imagemagick (.ci/run does)"
    );
}

/// An Xvfb server on a free display number, stopped on drop.
struct XServer {
    display: String,
    process: Child,
}

impl XServer {
    fn start() -> Self {
        require("Xvfb");
        // Xvfb picks a free display number itself and writes it to standard output (tests
        // run in parallel: probing for a free number raced).
        let mut process = Command::new("Xvfb")
            .args([
                "-displayfd",
                "1",
                "-screen",
                "0",
                "320x240x24",
                "-nolisten",
                "tcp",
            ])
            .stdout(Stdio::piped())
            .stderr(Stdio::null())
            .spawn()
            .expect("Xvfb starts");
        let mut line = String::new();
        BufReader::new(process.stdout.take().unwrap())
            .read_line(&mut line)
            .expect("Xvfb writes its display number");
        let number: u32 = line
            .trim()
            .parse()
            .unwrap_or_else(|_| panic!("Xvfb wrote {line:?}, not a display number"));
        Self {
            display: format!(":{number}"),
            process,
        }
    }

    /// Runs an X client (xdotool, import) on this display; returns its stdout.
    fn run(&self, program: &str, args: &[&str]) -> String {
        require(program);
        let output = Command::new(program)
            .args(args)
            .env("DISPLAY", &self.display)
            .output()
            .unwrap_or_else(|err| panic!("{program} runs: {err}"));
        assert!(
            output.status.success(),
            "{program} {args:?}: {}",
            String::from_utf8_lossy(&output.stderr)
        );
        String::from_utf8_lossy(&output.stdout).into_owned()
    }
}

impl Drop for XServer {
    fn drop(&mut self) {
        let _ = self.process.kill();
        let _ = self.process.wait();
    }
}

/// The viewer process with its standard output collected line by line.
struct Viewer {
    process: Child,
    lines: Arc<Mutex<Vec<String>>>,
    stderr: Arc<Mutex<String>>,
}

impl Viewer {
    fn start(x: &XServer, scene: &Path, save_dir: &Path, backend: &str) -> Self {
        let mut process = Command::new(env!("CARGO_BIN_EXE_pathlight"))
            .args(["view", "--backend", backend])
            .arg(scene)
            .args(["--width", "64", "--height", "64", "--frames-per-iter", "3"])
            .args(["--iters", "2", "--save-dir"])
            .arg(save_dir)
            .env("DISPLAY", &x.display)
            .env_remove("WAYLAND_DISPLAY")
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .expect("the viewer starts");
        let lines = Arc::new(Mutex::new(Vec::new()));
        let sink = lines.clone();
        let stdout = process.stdout.take().unwrap();
        std::thread::spawn(move || {
            for line in BufReader::new(stdout).lines().map_while(Result::ok) {
                sink.lock().unwrap().push(line);
            }
        });
        let stderr = Arc::new(Mutex::new(String::new()));
        let sink = stderr.clone();
        let pipe = process.stderr.take().unwrap();
        std::thread::spawn(move || {
            for line in BufReader::new(pipe).lines().map_while(Result::ok) {
                sink.lock().unwrap().push_str(&(line + "\n"));
            }
        });
        Self {
            process,
            lines,
            stderr,
        }
    }

    fn output(&self) -> String {
        format!(
            "stdout:\n{}\nstderr:\n{}",
            self.lines.lock().unwrap().join("\n"),
            self.stderr.lock().unwrap()
        )
    }

    /// Waits for the `n`-th line (from 1) starting with `prefix`; returns it.
    fn wait_for(&mut self, prefix: &str, n: usize) -> String {
        let started = Instant::now();
        loop {
            let found = self
                .lines
                .lock()
                .unwrap()
                .iter()
                .filter(|l| l.starts_with(prefix))
                .nth(n - 1)
                .cloned();
            if let Some(line) = found {
                return line;
            }
            if let Ok(Some(status)) = self.process.try_wait() {
                panic!(
                    "the viewer exited ({status}) before {prefix:?}\n{}",
                    self.output()
                );
            }
            assert!(
                started.elapsed() < LINE_TIMEOUT,
                "no {prefix:?} after {LINE_TIMEOUT:?}\n{}",
                self.output()
            );
            std::thread::sleep(Duration::from_millis(50));
        }
    }

    fn count(&self, prefix: &str) -> usize {
        let lines = self.lines.lock().unwrap();
        lines.iter().filter(|l| l.starts_with(prefix)).count()
    }
}

impl Drop for Viewer {
    fn drop(&mut self) {
        let _ = self.process.kill();
        let _ = self.process.wait();
    }
}

/// Presses `S` and returns the PNG the viewer says it saved. (Under load the X server can
/// deliver one press as two, which save twice: the first new "saved" line is this press's.)
fn save(x: &XServer, viewer: &mut Viewer) -> PathBuf {
    let saves = viewer.count("saved");
    x.run("xdotool", &["key", "s"]);
    let line = viewer.wait_for("saved", saves + 1);
    PathBuf::from(line.split_whitespace().nth(1).expect("saved PNG and EXR"))
}

/// Mean 8-bit RGB over the 5x5 pixels around (x, y) of a PNG.
fn patch_mean(png: &Path, x: u32, y: u32) -> f64 {
    let image = image::open(png)
        .unwrap_or_else(|err| panic!("{}: {err}", png.display()))
        .to_rgb8();
    let mut sum = 0.0;
    for py in y - 2..=y + 2 {
        for px in x - 2..=x + 2 {
            sum += image
                .get_pixel(px, py)
                .0
                .iter()
                .map(|&c| f64::from(c))
                .sum::<f64>()
                / 3.0;
        }
    }
    sum / 25.0
}

/// A screenshot of window `id` as a PNG in `dir`.
fn screenshot(x: &XServer, id: &str, dir: &Path, name: &str) -> PathBuf {
    let path = dir.join(name);
    x.run("import", &["-window", id, path.to_str().unwrap()]);
    path
}

/// The Cornell box of the references with a diffuse ball named "ball" in the middle; at
/// 64x64 the ball's centre is at pixel (32, 42).
fn ball_scene(dir: &Path) -> PathBuf {
    let room = std::fs::read_to_string(repo().join("scenes/refs/cornell-diffuse.toml")).unwrap();
    let scene = format!(
        "{room}\n[[sphere]]\nname = \"ball\"\nmaterial = \"white\"\ncenter = [0, -0.4, 0]\nradius = 0.5\n"
    );
    let path = dir.join("ball.toml");
    std::fs::write(&path, scene).unwrap();
    path
}

#[test]
fn viewer_on_the_gpu_backend() {
    iterates_waits_for_right_clicks_picks_saves_and_drags("gpu");
}

#[test]
fn viewer_on_the_cpu_backend() {
    iterates_waits_for_right_clicks_picks_saves_and_drags("cpu");
}

fn iterates_waits_for_right_clicks_picks_saves_and_drags(backend: &str) {
    let x = XServer::start();
    let dir = tempfile::tempdir().unwrap();
    let mut viewer = Viewer::start(&x, &ball_scene(dir.path()), dir.path(), backend);
    let expected = match backend {
        "cpu" => "backend: cpu backend",
        _ => "adapter: ",
    };
    assert!(viewer.wait_for(expected, 1).starts_with(expected));

    // Iteration 1 runs at once and reports its frame rate.
    let line = viewer.wait_for("iter 1 finished", 1);
    assert!(line.ends_with("fps"), "{line}");
    let fps: f64 = line.split_whitespace().nth(3).unwrap().parse().unwrap();
    assert!(fps > 0.0, "{line}");

    // No second iteration until a right click.
    std::thread::sleep(Duration::from_secs(3));
    assert_eq!(viewer.count("iter 2"), 0, "{}", viewer.output());
    let window = x
        .run("xdotool", &["search", "--sync", "--name", "^pathlight"])
        .lines()
        .next()
        .expect("the viewer's window")
        .to_string();
    let title = x.run("xdotool", &["getwindowname", &window]);
    assert!(
        title.contains("iter 1/2") && title.contains("right-click"),
        "{title}"
    );
    if backend == "cpu" {
        assert!(
            title.contains("cpu backend"),
            "the title names the backend: {title}"
        );
    }
    x.run(
        "xdotool",
        &["mousemove", "--window", &window, "10", "10", "click", "3"],
    );
    viewer.wait_for("iter 2 finished", 1);
    assert!(viewer.output().contains("all 2 iterations finished"));

    // `S` saves PNG and EXR.
    x.run("xdotool", &["windowfocus", "--sync", &window]);
    let before_png = save(&x, &mut viewer);
    assert_eq!(
        before_png,
        dir.path().join("pathlight-view-001.png"),
        "{}",
        viewer.output()
    );
    assert!(before_png.exists() && before_png.with_extension("exr").exists());
    let before_screen = screenshot(&x, &window, dir.path(), "before.png");

    // A left click on the ball turns it into a light and restarts the image. The first
    // iteration counted from the lines printed so far: whatever restarted the image before
    // (a window event) must not stand for the one after the pick.
    let finished = viewer.count("iter 1 finished");
    x.run(
        "xdotool",
        &["mousemove", "--window", &window, "32", "42", "click", "1"],
    );
    assert_eq!(viewer.wait_for("picked", 1), "picked ball: light on");
    viewer.wait_for("iter 1 finished", finished + 1);
    let after_png = save(&x, &mut viewer);
    let after_screen = screenshot(&x, &window, dir.path(), "after.png");
    for (before, after) in [(&before_png, &after_png), (&before_screen, &after_screen)] {
        let (b, a) = (patch_mean(before, 32, 42), patch_mean(after, 32, 42));
        // Diffuse grey before; an emitter of 0.73 x 17 clamps to white after.
        assert!(
            b < 200.0 && a > 245.0,
            "{}: ball {b:.0} -> {a:.0}\n{}",
            after.display(),
            viewer.output()
        );
        // The rest of the room brightens but stays a room: a wall corner is not white.
        assert!(patch_mean(after, 4, 4) < 250.0);
    }

    // A drag shows previews while the pointer moves, then accumulates again.
    let mut drag = vec![
        "mousemove",
        "--window",
        &window,
        "20",
        "20",
        "mousedown",
        "1",
    ];
    let steps: Vec<String> = (1..=12).map(|i| (20 + 2 * i).to_string()).collect();
    for step in &steps {
        drag.extend([
            "mousemove",
            "--window",
            &window,
            step,
            "20",
            "sleep",
            "0.05",
        ]);
    }
    drag.extend(["mouseup", "1"]);
    x.run("xdotool", &drag);
    let line = viewer.wait_for("preview:", 1);
    let frames: u32 = line.split_whitespace().nth(1).unwrap().parse().unwrap();
    assert!(frames >= 1, "{line}");
    let size = line
        .split_whitespace()
        .nth(4)
        .unwrap()
        .trim_end_matches(',');
    let (w, h) = size.split_once('x').unwrap();
    let (w, h): (u32, u32) = (w.parse().unwrap(), h.parse().unwrap());
    assert!((1..=64).contains(&w) && (1..=64).contains(&h), "{line}");
    viewer.wait_for("iter 1 finished", finished + 2);

    // `F` focuses the lens on the surface under the pointer, `]` opens the lens, `[` closes
    // it again, ctrl + left click focuses too; each says so and restarts.
    x.run("xdotool", &["mousemove", "--window", &window, "32", "32"]);
    x.run("xdotool", &["key", "f"]);
    let line = viewer.wait_for("focused on ", 1);
    let depth: f32 = line.rsplit(' ').next().unwrap().parse().unwrap();
    assert!(depth > 1.0 && depth < 5.0, "{line}");
    x.run("xdotool", &["key", "bracketright"]);
    let line = viewer.wait_for("aperture radius ", 1);
    let radius: f32 = line.rsplit(' ').next().unwrap().parse().unwrap();
    assert!((radius - 0.005 * depth).abs() < 1e-4, "{line}");
    x.run("xdotool", &["key", "bracketleft"]);
    assert_eq!(viewer.wait_for("aperture radius ", 2), "aperture radius 0");
    x.run(
        "xdotool",
        &["keydown", "ctrl", "click", "1", "keyup", "ctrl"],
    );
    assert!(
        viewer
            .wait_for("focused on ", 2)
            .ends_with(&format!(" {depth}"))
    );

    // `D` shows the denoised image (the accumulation paused, so that only the view
    // changes), and again the raw one.
    x.run("xdotool", &["key", "space"]);
    viewer.wait_for("paused", 1);
    std::thread::sleep(Duration::from_millis(300));
    let raw = screenshot(&x, &window, dir.path(), "raw.png");
    x.run("xdotool", &["key", "d"]);
    assert_eq!(viewer.wait_for("denoised view", 1), "denoised view on");
    viewer.wait_for("denoising done:", 1);
    std::thread::sleep(Duration::from_millis(300));
    let title = x.run("xdotool", &["getwindowname", &window]);
    assert!(title.contains("| denoised"), "{title}");
    let denoised = screenshot(&x, &window, dir.path(), "denoised.png");
    x.run("xdotool", &["key", "d"]);
    assert_eq!(viewer.wait_for("denoised view", 2), "denoised view off");
    std::thread::sleep(Duration::from_millis(300));
    let raw_again = screenshot(&x, &window, dir.path(), "raw-again.png");
    let difference = |a: &Path, b: &Path| {
        let (a, b) = (
            image::open(a).unwrap().to_rgb8(),
            image::open(b).unwrap().to_rgb8(),
        );
        let sum: u64 = a
            .pixels()
            .zip(b.pixels())
            .flat_map(|(p, q)| {
                p.0.into_iter()
                    .zip(q.0)
                    .map(|(x, y)| u64::from(x.abs_diff(y)))
            })
            .sum();
        sum as f64 / (3 * a.width() * a.height()) as f64
    };
    let (changed, restored) = (difference(&raw, &denoised), difference(&raw, &raw_again));
    println!(
        "{backend}: denoised differs from raw by {changed:.2} levels, raw again by {restored:.2}"
    );
    assert!(
        changed > 1.0 && restored < 0.1,
        "denoised differs from raw by {changed:.2} levels, raw again by {restored:.2}"
    );
    x.run("xdotool", &["key", "space"]);

    // `Esc` quits cleanly.
    x.run("xdotool", &["key", "Escape"]);
    let started = Instant::now();
    let status = loop {
        if let Some(status) = viewer.process.try_wait().unwrap() {
            break status;
        }
        assert!(
            started.elapsed() < Duration::from_secs(30),
            "Esc did not quit"
        );
        std::thread::sleep(Duration::from_millis(50));
    };
    assert!(status.success(), "{status}\n{}", viewer.output());
}
