//! WGSL assembly: files joined into modules by their imports, whatever holds the files (the
//! crate's generated table, or `build.rs` reading `shaders/` itself).
//!
//! Each file states what it uses on lines of its own, before its declarations:
//! - `#import NAME` makes the declarations of `shaders/NAME.wgsl` available (its own imports
//!   first; each file is included once per module, dependencies before dependents);
//! - `#const NAME: TYPE` declares a constant whose value the host gives when it assembles
//!   the module (WGSL sizes function-scope arrays by constants only, so a size that depends
//!   on the scene is written into the source this way).
//!
//! `build.rs` includes this file too and validates every file and module with naga at build
//! time, so a shader error is a build error with its source span.

use std::fmt::Write as _;

/// The modules the renderer compiles: the path tracer (entry point `render`) and the
/// viewer's display pass.
pub const MODULES: [&str; 3] = ["integrator", "wavefront", "display"];

/// Values of every `#const` for checking the files and modules at build time (the traversal
/// stack of `bvh.wgsl`: 64 entries; a scene gets its own bound).
pub const DEFAULT_CONSTANTS: [(&str, u32); 1] = [("STACK_SIZE", 64)];

/// Why a module could not be assembled.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum AssemblyError {
    /// `#import` of a file that does not exist.
    UnknownImport {
        /// The importing file (or `<source>` for a module given as text).
        file: String,
        /// The name imported.
        name: String,
    },
    /// Files that import each other.
    Cycle(Vec<String>),
    /// A `#const` without a value.
    MissingConstant(String),
    /// A directive other than `#import` and `#const`, or a malformed one.
    BadDirective {
        /// The file.
        file: String,
        /// The line, 1-based.
        line: usize,
        /// Its text.
        text: String,
    },
}

impl std::fmt::Display for AssemblyError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::UnknownImport { file, name } => {
                write!(
                    f,
                    "{file}: #import {name}: no such file shaders/{name}.wgsl"
                )
            }
            Self::Cycle(chain) => write!(f, "import cycle: {}", chain.join(" -> ")),
            Self::MissingConstant(name) => write!(f, "#const {name} has no value"),
            Self::BadDirective { file, line, text } => {
                write!(f, "{file}:{line}: unknown directive {text:?}")
            }
        }
    }
}

impl std::error::Error for AssemblyError {}

/// The module made of `text` (WGSL with directives) and everything it imports, the text of
/// each file `name` being `files(name)`, with the `#const` values `constants`.
pub fn assemble_with(
    text: &str,
    files: &dyn Fn(&str) -> Option<&'static str>,
    constants: &[(&str, u32)],
) -> Result<String, AssemblyError> {
    let mut assembly = Assembly {
        out: String::new(),
        included: Vec::new(),
        chain: Vec::new(),
        files,
        constants,
    };
    assembly.include("<source>", text)?;
    Ok(assembly.out)
}

/// A module being assembled.
struct Assembly<'a> {
    out: String,
    /// Files already in `out`.
    included: Vec<String>,
    /// Files being included, outermost first (to find cycles).
    chain: Vec<String>,
    /// The text of each file, by name.
    files: &'a dyn Fn(&str) -> Option<&'static str>,
    /// Values of the `#const`s (others may be given: they are ignored).
    constants: &'a [(&'a str, u32)],
}

impl Assembly<'_> {
    /// Appends `text` (file `file`) after the files it imports.
    fn include(&mut self, file: &str, text: &str) -> Result<(), AssemblyError> {
        self.chain.push(file.to_owned());
        let mut body = String::new();
        for (index, line) in text.lines().enumerate() {
            let directive = line.trim_end();
            if let Some(name) = directive.strip_prefix("#import ") {
                let name = name.trim();
                self.import(file, name)?;
                // Keep the line count, so that errors in `out` point near their source.
                body.push_str("// (imported ");
                body.push_str(name);
                body.push_str(")\n");
            } else if let Some(declaration) = directive.strip_prefix("#const ") {
                let (name, ty) = declaration
                    .split_once(':')
                    .map(|(n, t)| (n.trim(), t.trim()))
                    .ok_or_else(|| AssemblyError::BadDirective {
                        file: file.to_owned(),
                        line: index + 1,
                        text: line.to_owned(),
                    })?;
                let (_, value) = self
                    .constants
                    .iter()
                    .find(|(n, _)| *n == name)
                    .ok_or_else(|| AssemblyError::MissingConstant(name.to_owned()))?;
                let _ = writeln!(body, "const {name}: {ty} = {value}u;");
            } else if directive.starts_with('#') {
                return Err(AssemblyError::BadDirective {
                    file: file.to_owned(),
                    line: index + 1,
                    text: line.to_owned(),
                });
            } else {
                body.push_str(line);
                body.push('\n');
            }
        }
        self.out.push_str(&body);
        self.chain.pop();
        Ok(())
    }

    /// Includes file `name`, imported by `file`, unless it is already in.
    fn import(&mut self, file: &str, name: &str) -> Result<(), AssemblyError> {
        if self.chain.iter().any(|f| f == name) {
            let mut cycle = self.chain.clone();
            cycle.push(name.to_owned());
            return Err(AssemblyError::Cycle(cycle));
        }
        if self.included.iter().any(|f| f == name) {
            return Ok(());
        }
        let text = (self.files)(name).ok_or_else(|| AssemblyError::UnknownImport {
            file: file.to_owned(),
            name: name.to_owned(),
        })?;
        self.include(name, text)?;
        self.included.push(name.to_owned());
        Ok(())
    }
}
