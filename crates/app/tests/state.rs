//! Renders that survive and scale, end to end on the CPU backend (the GPU backend's resume
//! and splits are checked in-process by `crates/gpu/tests/gpu/state.rs`): state files,
//! checkpoints, resuming after SIGINT, SIGTERM and SIGKILL, time limits, shards and merges,
//! each compared byte for byte with the image one uninterrupted render makes.

mod common;

use common::{send, stderr};

use std::path::Path;
use std::process::{Child, Command, Output, Stdio};
use std::time::{Duration, Instant};

fn pathlight(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_pathlight"))
        .args(args)
        .output()
        .expect("the binary runs")
}

/// The default scene, small, on the CPU backend.
const SMALL: [&str; 6] = ["--backend", "cpu", "--width", "24", "--height", "16"];

fn path(dir: &Path, name: &str) -> String {
    dir.join(name).to_str().unwrap().to_owned()
}

/// `pathlight render` with `SMALL` and `args`.
fn small<'a>(args: &[&'a str]) -> Vec<&'a str> {
    let mut all = vec!["render"];
    all.extend(SMALL);
    all.extend(args);
    all
}

/// Renders with `SMALL` and `args`; fails the test unless it succeeds.
fn render(args: &[&str]) -> String {
    let all = small(args);
    let output = pathlight(&all);
    let err = stderr(&output);
    assert!(output.status.success(), "{all:?}:\n{err}");
    err
}

fn fails(args: &[&str], needles: &[&str]) {
    let output = pathlight(args);
    let err = stderr(&output);
    assert_eq!(output.status.code(), Some(1), "{args:?}:\n{err}");
    for needle in needles {
        assert!(err.contains(needle), "{args:?}: {needle:?} not in\n{err}");
    }
}

fn bytes(path: &str) -> Vec<u8> {
    std::fs::read(path).unwrap_or_else(|err| panic!("{path}: {err}"))
}

#[test]
fn merges_of_any_split_equal_the_one_machine_render() {
    let dir = tempfile::tempdir().unwrap();
    let whole = path(dir.path(), "whole.exr");
    render(&["--spp", "7", "-o", &whole]);
    // With the auxiliary images too (the EXR's albedo and normal layers).
    let whole_aovs = path(dir.path(), "whole-aovs.exr");
    render(&["--spp", "7", "--aov", "albedo,normal", "-o", &whole_aovs]);
    for count in [1, 2, 3, 7] {
        let parts: Vec<String> = (0..count)
            .map(|i| {
                let part = path(dir.path(), &format!("part{i}of{count}.state"));
                render(&[
                    "--spp",
                    "7",
                    "--aov",
                    "albedo,normal",
                    "--shard",
                    &format!("{i}/{count}"),
                    "-o",
                    &part,
                ]);
                part
            })
            .collect();
        let merged_aovs = path(dir.path(), &format!("merged-aovs{count}.exr"));
        let mut args = vec!["merge", "--aov", "albedo,normal"];
        args.extend(parts.iter().map(String::as_str));
        args.extend(["-o", &merged_aovs]);
        let output = pathlight(&args);
        assert!(output.status.success(), "{}", stderr(&output));
        assert!(
            bytes(&merged_aovs) == bytes(&whole_aovs),
            "{count} parts, AOVs"
        );
        let merged = path(dir.path(), &format!("merged{count}.exr"));
        let mut args = vec!["merge"];
        args.extend(parts.iter().map(String::as_str));
        args.extend(["-o", &merged]);
        let output = pathlight(&args);
        assert!(output.status.success(), "{}", stderr(&output));
        assert!(bytes(&merged) == bytes(&whole), "{count} parts");
    }
    // `--samples` splits the same way, and a merge can make a state again.
    let (a, b) = (path(dir.path(), "a.state"), path(dir.path(), "b.state"));
    render(&["--spp", "7", "--samples", "0..4", "-o", &a]);
    render(&["--spp", "7", "--samples", "4..7", "-o", &b]);
    let ab = path(dir.path(), "ab.state");
    assert!(pathlight(&["merge", &a, &b, "-o", &ab]).status.success());
    let from_state = path(dir.path(), "from-state.exr");
    assert!(
        pathlight(&["merge", &ab, "-o", &from_state])
            .status
            .success()
    );
    assert!(bytes(&from_state) == bytes(&whole));
}

#[test]
fn merges_refuse_overlaps_gaps_and_other_renders_without_writing() {
    let dir = tempfile::tempdir().unwrap();
    let (a, b) = (path(dir.path(), "a.state"), path(dir.path(), "b.state"));
    render(&["--spp", "8", "--samples", "0..3", "-o", &a]);
    render(&["--spp", "8", "--samples", "2..5", "-o", &b]);
    let out = path(dir.path(), "out.exr");
    std::fs::write(&out, "previous").unwrap();
    fails(
        &["merge", &a, &b, "-o", &out],
        &["both hold samples 2..3 of row 0"],
    );
    let c = path(dir.path(), "c.state");
    render(&["--spp", "8", "--samples", "5..8", "-o", &c]);
    fails(
        &["merge", &a, &c, "-o", &out],
        &["lack samples 3..5 of every row", "--allow-gaps"],
    );
    assert_eq!(bytes(&out), b"previous", "a refused merge writes nothing");
    let output = pathlight(&["merge", &a, &c, "-o", &out, "--allow-gaps"]);
    assert!(output.status.success(), "{}", stderr(&output));
    assert_ne!(bytes(&out), b"previous");
    let other = path(dir.path(), "other.state");
    render(&[
        "--spp",
        "8",
        "--samples",
        "3..5",
        "--seed",
        "9",
        "-o",
        &other,
    ]);
    fails(
        &["merge", &a, &other, "-o", &out],
        &["seed 0 in", "a.state, 9 in", "other.state"],
    );
    // A corrupt, truncated or foreign file is named.
    let mut corrupt = bytes(&a);
    let middle = corrupt.len() / 2;
    corrupt[middle] ^= 1;
    let bad = path(dir.path(), "bad.state");
    std::fs::write(&bad, &corrupt).unwrap();
    fails(&["merge", &bad, &c, "-o", &out], &["bad.state", "checksum"]);
    std::fs::write(&bad, &bytes(&a)[..100]).unwrap();
    fails(&["merge", &bad, "-o", &out], &["bad.state", "corrupt"]);
    fails(
        &["merge", &out, "-o", &bad],
        &["out.exr", "not a pathlight state file"],
    );
    // Shard and sample arguments out of range.
    fails(
        &["render", "--spp", "8", "--samples", "4..9", "-o", &out],
        &["--samples 4..9 reaches past the spp (8)"],
    );
}

/// A CPU render of the default scene at 40x40.
const RENDER_40: [&str; 7] = [
    "render",
    "--backend",
    "cpu",
    "--width",
    "40",
    "--height",
    "40",
];

/// Starts a checkpointed CPU render of the default scene at 40x40 and `spp`.
fn spawn_checkpointed(spp: &str, checkpoint: &str, out: &str) -> Child {
    Command::new(env!("CARGO_BIN_EXE_pathlight"))
        .args(RENDER_40)
        .args([
            "--spp",
            spp,
            "--checkpoint",
            checkpoint,
            "--checkpoint-every",
            "0.2s",
        ])
        .args(["-o", out])
        .stderr(Stdio::piped())
        .spawn()
        .unwrap()
}

/// Waits until `file` exists (the first checkpoint).
fn wait_for(file: &str) {
    let started = Instant::now();
    while !Path::new(file).exists() {
        assert!(started.elapsed() < Duration::from_secs(120), "no {file}");
        std::thread::sleep(Duration::from_millis(20));
    }
}

#[test]
fn resumed_renders_equal_the_uninterrupted_one() {
    let dir = tempfile::tempdir().unwrap();
    // Long enough (about 2 s on 2 cores) that the signal, 0.3 s after the first checkpoint,
    // always arrives mid-render.
    let spp = "1200";
    let whole = path(dir.path(), "whole.exr");
    let mut args = RENDER_40.to_vec();
    args.extend(["--spp", spp, "-o", &whole]);
    let output = pathlight(&args);
    assert!(output.status.success(), "{}", stderr(&output));
    for signal in ["INT", "TERM", "KILL"] {
        let checkpoint = path(dir.path(), &format!("{signal}.state"));
        let out = path(dir.path(), &format!("{signal}.exr"));
        let mut child = spawn_checkpointed(spp, &checkpoint, &out);
        wait_for(&checkpoint);
        std::thread::sleep(Duration::from_millis(300));
        send(signal, child.id());
        let status = child.wait().unwrap();
        if signal == "KILL" {
            assert_eq!(status.code(), None, "killed");
        } else {
            assert_eq!(status.code(), Some(130), "{signal}: {status}");
        }
        let output = Command::new(env!("CARGO_BIN_EXE_pathlight"))
            .args(RENDER_40)
            .args(["--resume", &checkpoint, "-o", &out])
            .output()
            .unwrap();
        let err = stderr(&output);
        assert!(output.status.success(), "{signal}: {err}");
        assert!(
            err.contains("resuming at sample"),
            "{signal}: the render was done\n{err}"
        );
        assert!(
            bytes(&out) == bytes(&whole),
            "{signal}: resumed != uninterrupted"
        );
    }
}

#[test]
fn resuming_refuses_another_render_and_a_target_already_passed() {
    let dir = tempfile::tempdir().unwrap();
    let state = path(dir.path(), "s.state");
    render(&["--spp", "4", "-o", &state]);
    let out = path(dir.path(), "out.exr");
    let mut taller = RENDER_40.to_vec();
    taller.extend(["--resume", &state, "-o", &out]);
    fails(
        &taller,
        &["s.state", "image size 24x16 in", "40x40 in this render"],
    );
    fails(
        &small(&["--max-depth", "3", "--resume", &state, "-o", &out]),
        &["max_depth 8 in", "3 in this render"],
    );
    fails(
        &small(&["--resume", &state, "--spp", "2", "-o", &out]),
        &["cannot resume", "to 2 spp", "samples 0..4 already"],
    );
    // A checkpoint must be a state; a shard count needs a shard.
    fails(
        &small(&["--checkpoint", "c.png", "-o", &out]),
        &["--checkpoint c.png", ".state"],
    );
    let output = pathlight(&small(&["--shard-count", "4", "-o", &out]));
    assert_eq!(output.status.code(), Some(2), "clap's usage error");
    assert!(stderr(&output).contains("--shard"), "{}", stderr(&output));
    // A finished state resumed to more samples equals rendering them at once.
    render(&["--resume", &state, "--spp", "6", "-o", &out]);
    let whole = path(dir.path(), "whole.exr");
    render(&["--spp", "6", "-o", &whole]);
    assert!(bytes(&out) == bytes(&whole));
}

#[test]
fn a_time_limit_writes_what_was_rendered_and_succeeds() {
    let dir = tempfile::tempdir().unwrap();
    let (out, checkpoint) = (path(dir.path(), "t.png"), path(dir.path(), "t.state"));
    let err = render(&[
        "--spp",
        "1000000",
        "--time-limit",
        "1s",
        "--checkpoint",
        &checkpoint,
        "-o",
        &out,
    ]);
    assert!(err.contains("time limit reached: kept"), "{err}");
    assert!(Path::new(&out).exists() && Path::new(&checkpoint).exists());
    // The checkpoint resumes (for another second) from where the limit stopped it.
    let err = render(&["--resume", &checkpoint, "--time-limit", "1s", "-o", &out]);
    assert!(err.contains("resuming at sample"), "{err}");
}
