//! The WGSL of the crate: every file under `shaders/` (a table `build.rs` generates from the
//! folder), joined into modules by their imports (the private `assembly` module).

mod assembly;

pub use assembly::{AssemblyError, DEFAULT_CONSTANTS, MODULES};

include!(concat!(env!("OUT_DIR"), "/shader_files.rs"));

/// The text of file `name` (`shaders/NAME.wgsl`).
pub fn source(name: &str) -> Option<&'static str> {
    FILES.iter().find(|(n, _)| *n == name).map(|(_, s)| *s)
}

/// The module made of file `name` and everything it imports, with the `#const` values
/// `constants`.
pub fn assemble(name: &str, constants: &[(&str, u32)]) -> Result<String, AssemblyError> {
    assemble_source(&format!("#import {name}\n"), constants)
}

/// The module made of `text` (WGSL with directives, e.g. a test's pass) and everything it
/// imports, with the `#const` values `constants`.
pub fn assemble_source(text: &str, constants: &[(&str, u32)]) -> Result<String, AssemblyError> {
    assembly::assemble_with(text, &source, constants)
}
