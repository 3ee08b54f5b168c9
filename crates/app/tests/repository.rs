//! The repository cites only what it holds: every path named in a source file, a shader, a
//! document or a script (quoted in backticks, or a Markdown link) exists, and no file cites
//! the product specification or other documents that live outside the repository.

use std::path::{Path, PathBuf};

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// Text files of the repository that may cite paths (build outputs and hidden folders but
/// `.ci` left out).
fn text_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        if path.is_dir() {
            if name != "target" && (!name.starts_with('.') || name == ".ci") {
                text_files(&path, out);
            }
        } else if name == "run"
            || ["rs", "wgsl", "md", "toml", "sh", "py"]
                .iter()
                .any(|ext| name.ends_with(&format!(".{ext}")))
        {
            out.push(path);
        }
    }
}

/// Folders a cited path may start with: the repository's own, or a crate's.
const ROOTS: [&str; 13] = [
    "crates/",
    "scenes/",
    "docs/",
    "bench/",
    "tools/",
    "assets/",
    "examples/",
    ".ci/",
    "src/",
    "shaders/",
    "tests/",
    "view/",
    "images/",
];

/// The paths `text` cites: backticked tokens that start with one of [`ROOTS`] (or `./`,
/// `../`), and the targets of Markdown links that are not URLs or anchors. Patterns are
/// left out: tokens with `*`, `<`, `{`, or an upper-case placeholder file name (`X.rs`,
/// `NAME.wgsl`).
fn cited_paths(text: &str) -> Vec<String> {
    let mut cited = Vec::new();
    for (i, token) in text.split('`').enumerate() {
        let is_path = i % 2 == 1
            && !token.contains(char::is_whitespace)
            && (ROOTS.iter().any(|r| token.starts_with(r))
                || token.starts_with("./")
                || token.starts_with("../"));
        if is_path {
            cited.push(token.to_owned());
        }
    }
    for (i, _) in text.match_indices("](") {
        let rest = &text[i + 2..];
        if let Some(end) = rest.find(')') {
            let target = &rest[..end];
            let url_or_item =
                target.contains("://") || target.contains("::") || target.starts_with('#');
            if !url_or_item && target.contains(['/', '.']) {
                cited.push(target.split('#').next().unwrap_or(target).to_owned());
            }
        }
    }
    cited.retain(|path| {
        let stem = Path::new(path.trim_end_matches('/'))
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        let placeholder = !stem.is_empty() && stem.chars().all(|c| c.is_ascii_uppercase());
        !path.contains(['*', '<', '{']) && !placeholder
    });
    cited
}

/// The crate folder holding `file`, if any.
fn crate_of(file: &Path) -> Option<PathBuf> {
    file.ancestors()
        .find(|dir| {
            dir.join("Cargo.toml").is_file() && dir.parent().is_some_and(|p| p.ends_with("crates"))
        })
        .map(Path::to_owned)
}

#[test]
fn every_cited_path_exists() {
    let root = repo();
    let mut files = Vec::new();
    text_files(&root, &mut files);
    assert!(files.len() > 50, "only {} files found", files.len());
    let mut missing = Vec::new();
    let mut checked = 0;
    let this = Path::new(file!()).file_name().unwrap().to_owned();
    for file in files.iter().filter(|f| f.file_name() != Some(&this)) {
        let text = std::fs::read_to_string(file).unwrap();
        let dir = file.parent().unwrap();
        for path in cited_paths(&text) {
            let bases = [Some(root.clone()), Some(dir.to_owned()), crate_of(file)];
            let exists = bases
                .iter()
                .flatten()
                .any(|base| base.join(path.trim_end_matches('/')).exists());
            checked += 1;
            if !exists {
                let shown = file
                    .strip_prefix(&root)
                    .unwrap_or(file)
                    .display()
                    .to_string();
                missing.push(format!("{shown}: `{path}`"));
            }
        }
    }
    assert!(checked > 50, "only {checked} cited paths found");
    assert!(
        missing.is_empty(),
        "cited paths that do not exist:\n{}",
        missing.join("\n")
    );
}

#[test]
fn no_file_cites_documents_outside_the_repository() {
    let root = repo();
    let mut files = Vec::new();
    text_files(&root, &mut files);
    let this = Path::new(file!()).file_name().unwrap().to_owned();
    let mut found = Vec::new();
    for file in files.iter().filter(|f| f.file_name() != Some(&this)) {
        let text = std::fs::read_to_string(file).unwrap();
        for (n, line) in text.lines().enumerate() {
            if ["seed-report", "shared/refs", "../shared"]
                .iter()
                .any(|outside| line.contains(outside))
                || cites_the_spec(line)
            {
                let shown = file
                    .strip_prefix(&root)
                    .unwrap_or(file)
                    .display()
                    .to_string();
                found.push(format!("{shown}:{}: {line}", n + 1));
            }
        }
    }
    assert!(
        found.is_empty(),
        "citations of documents the repository does not hold:\n{}",
        found.join("\n")
    );
}

/// A document's headings, each with its line number (lines inside code fences left out).
fn headings(text: &str) -> Vec<(usize, &str)> {
    let mut fenced = false;
    let mut found = Vec::new();
    for (n, line) in text.lines().enumerate() {
        if line.starts_with("```") {
            fenced = !fenced;
        } else if !fenced && line.starts_with('#') {
            found.push((n + 1, line));
        }
    }
    found
}

#[test]
fn no_document_repeats_a_heading() {
    // A section pasted twice (once the whole of BENCHMARKS.md was) shows as a heading said
    // twice in one document.
    let root = repo();
    let mut files = Vec::new();
    text_files(&root, &mut files);
    let mut repeated = Vec::new();
    let mut checked = 0;
    for file in files
        .iter()
        .filter(|f| f.extension() == Some("md".as_ref()))
    {
        let text = std::fs::read_to_string(file).unwrap();
        let mut seen = std::collections::HashMap::new();
        for (n, heading) in headings(&text) {
            checked += 1;
            if let Some(first) = seen.insert(heading, n) {
                let shown = file.strip_prefix(&root).unwrap_or(file).display();
                repeated.push(format!("{shown}:{n}: {heading} (also line {first})"));
            }
        }
    }
    assert!(checked > 100, "only {checked} headings found");
    assert!(
        repeated.is_empty(),
        "headings said twice in one document:\n{}",
        repeated.join("\n")
    );
}

#[test]
fn the_heading_reader_skips_code_fences() {
    let text = "# Title\n```sh\n# a comment\n```\n## Part\n";
    assert_eq!(headings(text), [(1, "# Title"), (5, "## Part")]);
}

#[test]
fn the_citation_reader_finds_paths_and_skips_patterns() {
    let text = "see `crates/core/src/bvh.rs`, `shaders/X.wgsl`, `scenes/*.toml`, `a b/c`, \
                [format](docs/scene-format.md#top) and [web](https://wgpu.rs)";
    assert_eq!(
        cited_paths(text),
        ["crates/core/src/bvh.rs", "docs/scene-format.md"]
    );
}

/// Whether `line` names the SPEC as a word (not inside a name such as `TEXTURE_SPECULAR`).
fn cites_the_spec(line: &str) -> bool {
    let word = |c: Option<char>| c.is_some_and(|c| c.is_alphanumeric() || c == '_');
    line.match_indices("SPEC").any(|(i, m)| {
        !word(line[..i].chars().next_back()) && !word(line[i + m.len()..].chars().next())
    })
}
