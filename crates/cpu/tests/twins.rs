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
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../render/shaders")
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
            if trimmed.starts_with("#[") {
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

#[test]
fn every_integrator_file_has_its_twin_file() {
    for stem in [
        "intersect",
        "bvh",
        "sampler",
        "sampling",
        "camera",
        "surface",
        "bsdf",
        "lights",
        "integrator",
        "display",
    ] {
        assert!(
            shaders().join(format!("{stem}.wgsl")).is_file(),
            "{stem}.wgsl"
        );
        assert!(
            cpu_src().join(format!("{stem}.rs")).is_file(),
            "src/{stem}.rs"
        );
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
