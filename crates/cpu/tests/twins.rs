//! The CPU backend is the twin of the WGSL integrator file for file: `shaders/X.wgsl` is
//! `src/X.rs`. A Rust item that mirrors a WGSL one says so in its doc comment, ``Twin of
//! WGSL `name` ``, and the WGSL item names it back on a comment line right above it,
//! ``// CPU twin: `Item` `` (a method as `Type::method`). This test holds both sides to it:
//! every claim names an item declared in the same-named WGSL file that names the claimant
//! back, and every WGSL mark is claimed.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

/// `(file stem, Rust item, WGSL item)`.
type Pair = (String, String, String);

fn cpu_src() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("src")
}

fn shaders() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../gpu/shaders")
}

/// The identifiers quoted right after `marker` in `text` (as in ``Twin of WGSL `x` ``).
fn quoted_after(text: &str, marker: &str) -> Vec<String> {
    text.match_indices(marker)
        .filter_map(|(i, _)| {
            let rest = text[i + marker.len()..].trim_start().strip_prefix('`')?;
            let end = rest.find('`')?;
            Some(rest[..end].to_owned())
        })
        .collect()
}

/// The item a Rust line declares: `fn`, `struct`, `enum`, `const` or `type`, and its name.
fn rust_item(line: &str) -> Option<String> {
    let mut words = line.split_whitespace().skip_while(|w| w.starts_with("pub"));
    let mut keyword = words.next()?;
    if keyword == "const" && words.clone().next() == Some("fn") {
        keyword = words.next()?;
    }
    if !["fn", "struct", "enum", "const", "type"].contains(&keyword) {
        return None;
    }
    let name: String = words
        .next()?
        .chars()
        .take_while(|c| c.is_alphanumeric() || *c == '_')
        .collect();
    (!name.is_empty()).then_some(name)
}

/// The type an `impl` line implements for (`impl<'a> Foo<'a> {`, `impl Trait for Foo {`).
fn impl_type(line: &str) -> Option<String> {
    let rest = line.strip_prefix("impl")?;
    let rest = if rest.starts_with('<') {
        &rest[rest.find('>')? + 1..]
    } else {
        rest
    };
    let rest = rest.split(" for ").last()?;
    let name: String = rest
        .trim_start()
        .chars()
        .take_while(|c| c.is_alphanumeric() || *c == '_')
        .collect();
    (!name.is_empty()).then_some(name)
}

/// Every ``Twin of WGSL `name` `` claim of the CPU crate's sources.
fn rust_claims() -> BTreeSet<Pair> {
    let mut claims = BTreeSet::new();
    for entry in std::fs::read_dir(cpu_src()).unwrap() {
        let path = entry.unwrap().path();
        let stem = path.file_stem().unwrap().to_string_lossy().into_owned();
        let text = std::fs::read_to_string(&path).unwrap();
        let (mut implementing, mut doc) = (None, String::new());
        let mut in_attribute = false;
        for line in text.lines() {
            if line.starts_with("impl") {
                implementing = impl_type(line);
            } else if line.starts_with('}') {
                implementing = None;
            }
            let trimmed = line.trim_start();
            if let Some(comment) = trimmed.strip_prefix("///") {
                doc.push(' ');
                doc.push_str(comment.trim());
                continue;
            }
            // Attributes, also those rustfmt spreads over several lines.
            if in_attribute || trimmed.starts_with("#[") {
                in_attribute = !trimmed.ends_with(']');
                continue;
            }
            let names = quoted_after(&doc, "Twin of WGSL");
            if !names.is_empty() {
                let item = rust_item(trimmed)
                    .unwrap_or_else(|| panic!("{stem}.rs: a twin claim on {trimmed:?}"));
                let item = match (&implementing, line.starts_with("    ")) {
                    (Some(ty), true) => format!("{ty}::{item}"),
                    _ => item,
                };
                for name in names {
                    claims.insert((stem.clone(), item.clone(), name));
                }
            }
            doc.clear();
        }
    }
    claims
}

/// The items a WGSL file declares, each with the comment block right above it.
fn wgsl_items(text: &str) -> Vec<(String, String)> {
    let mut items = Vec::new();
    let mut comments = String::new();
    for line in text.lines() {
        if let Some(comment) = line.strip_prefix("//") {
            comments.push(' ');
            comments.push_str(comment.trim());
            continue;
        }
        let mut words = line.split_whitespace();
        if let (Some("fn" | "struct" | "const"), Some(name)) = (words.next(), words.next()) {
            let name: String = name
                .chars()
                .take_while(|c| c.is_alphanumeric() || *c == '_')
                .collect();
            items.push((name, comments.clone()));
        }
        comments.clear();
    }
    items
}

#[test]
fn every_twin_claim_is_named_back_and_every_mark_is_claimed() {
    let claims = rust_claims();
    assert!(claims.len() > 40, "only {} claims found", claims.len());
    let mut marks = BTreeSet::new();
    let mut declared = BTreeSet::new();
    for entry in std::fs::read_dir(shaders()).unwrap() {
        let path = entry.unwrap().path();
        let stem = path.file_stem().unwrap().to_string_lossy().into_owned();
        for (name, comments) in wgsl_items(&std::fs::read_to_string(&path).unwrap()) {
            for rust in quoted_after(&comments, "CPU twin:") {
                marks.insert((stem.clone(), rust, name.clone()));
            }
            declared.insert((stem.clone(), name));
        }
    }
    for (file, rust, wgsl) in &claims {
        assert!(
            declared.contains(&(file.clone(), wgsl.clone())),
            "src/{file}.rs: `{rust}` claims to be the twin of `{wgsl}`, which shaders/{file}.wgsl does not declare"
        );
    }
    let unclaimed: Vec<_> = marks.difference(&claims).collect();
    let unmarked: Vec<_> = claims.difference(&marks).collect();
    assert!(
        unclaimed.is_empty(),
        "WGSL items name a CPU twin that does not claim them: {unclaimed:?}"
    );
    assert!(
        unmarked.is_empty(),
        "twin claims whose WGSL item does not name the claimant back: {unmarked:?}"
    );
}

/// The leading comment block of a file: its header.
fn header(text: &str, comment: &str) -> String {
    text.lines()
        .take_while(|line| line.starts_with(comment))
        .map(|line| line[comment.len()..].trim())
        .collect::<Vec<_>>()
        .join(" ")
}

/// Every WGSL file either names its twin file in its header (``CPU twin:
/// `crates/cpu/src/X.rs` ``), which exists and claims it back (``Twin of `X.wgsl` `` in its
/// module doc), or says why it has none in a marked header line (`No CPU twin: ...`, as
/// `scene.wgsl`, which only declares); and every CPU file that claims a WGSL twin has it.
/// Both folders are read, so a new file cannot be forgotten.
#[test]
fn every_wgsl_file_has_its_twin_file_or_says_why_not() {
    let mut twinned = BTreeSet::new();
    for entry in std::fs::read_dir(shaders()).unwrap() {
        let path = entry.unwrap().path();
        let stem = path.file_stem().unwrap().to_string_lossy().into_owned();
        let head = header(&std::fs::read_to_string(&path).unwrap(), "//");
        let twin = format!("CPU twin: `crates/cpu/src/{stem}.rs`");
        match (head.contains(&twin), head.contains("No CPU twin:")) {
            (true, false) => {
                let rust = cpu_src().join(format!("{stem}.rs"));
                let doc = std::fs::read_to_string(&rust)
                    .map(|text| header(&text, "//!"))
                    .unwrap_or_else(|_| {
                        panic!("shaders/{stem}.wgsl names src/{stem}.rs, which does not exist")
                    });
                assert!(
                    doc.contains(&format!("`{stem}.wgsl`"))
                        && doc.to_lowercase().contains("twin of"),
                    "src/{stem}.rs does not say it is the twin of `{stem}.wgsl` in its module doc"
                );
                twinned.insert(stem);
            }
            (false, true) => {}
            _ => panic!(
                "shaders/{stem}.wgsl: its header must name its twin ({twin}) or say `No CPU twin:` and why, not both"
            ),
        }
    }
    assert!(twinned.len() >= 15, "only {} twinned files", twinned.len());
    for entry in std::fs::read_dir(cpu_src()).unwrap() {
        let path = entry.unwrap().path();
        let stem = path.file_stem().unwrap().to_string_lossy().into_owned();
        let doc = header(&std::fs::read_to_string(&path).unwrap(), "//!");
        if doc.contains(&format!("`{stem}.wgsl`")) {
            assert!(
                twinned.contains(&stem),
                "src/{stem}.rs claims `{stem}.wgsl`, which does not name it as its twin"
            );
        }
    }
}

#[test]
fn the_parsers_read_the_convention() {
    assert_eq!(
        quoted_after(
            "x. Twin of WGSL `a_b` and Twin of WGSL\n `c`.",
            "Twin of WGSL"
        ),
        ["a_b", "c"]
    );
    assert_eq!(
        rust_item("pub(crate) fn enter(&self)").as_deref(),
        Some("enter")
    );
    assert_eq!(
        rust_item("pub const fn pcg_hash(v: u32)").as_deref(),
        Some("pcg_hash")
    );
    assert_eq!(rust_item("struct Hit {").as_deref(), Some("Hit"));
    assert_eq!(rust_item("let x = 1;"), None);
    assert_eq!(
        impl_type("impl<'a> Tracer<'a> {").as_deref(),
        Some("Tracer")
    );
    assert_eq!(
        impl_type("impl Renderer for CpuRenderer {").as_deref(),
        Some("CpuRenderer")
    );
    let items = wgsl_items("// A.\n// CPU twin: `x`.\nfn f(a: u32) {}\n\n// B.\nstruct S {}\n");
    assert_eq!(items[0], ("f".into(), " A. CPU twin: `x`.".into()));
    assert_eq!(items[1].0, "S");
}
