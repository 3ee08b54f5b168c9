//! Validates every WGSL file and module with naga at build time: each file assembled with
//! its imports alone (so a file that uses a declaration it does not import fails), and each
//! module the renderer compiles. Errors are printed with their source spans.

#[path = "src/wgsl.rs"]
mod wgsl;

fn main() {
    println!("cargo::rerun-if-changed=shaders");
    println!("cargo::rerun-if-changed=src/wgsl.rs");
    let names = wgsl::FILES.iter().map(|(name, _)| *name);
    let mut failures = Vec::new();
    for name in names.chain(wgsl::MODULES) {
        if let Err(message) = validate(name) {
            failures.push(message);
        }
    }
    if !failures.is_empty() {
        panic!("WGSL validation failed:\n\n{}", failures.join("\n\n"));
    }
}

/// Assembles `name` with its imports and validates the module.
fn validate(name: &str) -> Result<(), String> {
    let path = format!("shaders/{name}.wgsl (with its imports)");
    let source = wgsl::assemble(name, &wgsl::DEFAULT_CONSTANTS).map_err(|e| e.to_string())?;
    let module = naga::front::wgsl::parse_str(&source)
        .map_err(|e| e.emit_to_string_with_path(&source, &path))?;
    naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::default(),
    )
    .validate(&module)
    .map_err(|e| e.emit_to_string_with_path(&source, &path))?;
    Ok(())
}
