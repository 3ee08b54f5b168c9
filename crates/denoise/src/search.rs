//! Where OIDN is looked for.

use std::path::{Path, PathBuf};

/// The file name of OIDN 2's library on this system.
#[cfg(target_os = "linux")]
pub const LIBRARY: &str = "libOpenImageDenoise.so.2";
/// The file name of OIDN 2's library on this system.
#[cfg(target_os = "macos")]
pub const LIBRARY: &str = "libOpenImageDenoise.2.dylib";
/// The file name of OIDN 2's library on this system.
#[cfg(target_os = "windows")]
pub const LIBRARY: &str = "OpenImageDenoise.dll";
/// The file name of OIDN 2's library on this system.
#[cfg(not(any(target_os = "linux", target_os = "macos", target_os = "windows")))]
pub const LIBRARY: &str = "libOpenImageDenoise.so.2";

/// The paths OIDN's library is looked for at, in order: with `PATHLIGHT_OIDN` set, only
/// there (a folder holding `lib/LIBRARY` or `LIBRARY`, or the file itself); otherwise where
/// `tools/get-oidn.sh` installs it (`$XDG_DATA_HOME/pathlight/oidn/lib`, by default
/// `~/.local/share/pathlight/oidn/lib`), beside the executable (`oidn/lib`), then the bare
/// name, which the system's loader looks up (`LD_LIBRARY_PATH`, the system's folders).
pub fn candidates() -> Vec<PathBuf> {
    let var = |name: &str| std::env::var_os(name).filter(|v| !v.is_empty());
    if let Some(given) = var("PATHLIGHT_OIDN") {
        return in_folder(Path::new(&given));
    }
    let mut out = Vec::new();
    let data = var("XDG_DATA_HOME")
        .map(PathBuf::from)
        .or_else(|| var("HOME").map(|home| Path::new(&home).join(".local/share")));
    if let Some(data) = data {
        out.push(data.join("pathlight/oidn/lib").join(LIBRARY));
    }
    if let Some(dir) = std::env::current_exe()
        .ok()
        .and_then(|e| e.parent().map(Path::to_owned))
    {
        out.push(dir.join("oidn/lib").join(LIBRARY));
    }
    out.push(PathBuf::from(LIBRARY));
    out
}

/// The library as `given` names it: a file, or a folder holding `lib/LIBRARY` or
/// `LIBRARY`.
fn in_folder(given: &Path) -> Vec<PathBuf> {
    if given.is_file() {
        return vec![given.to_owned()];
    }
    vec![given.join("lib").join(LIBRARY), given.join(LIBRARY)]
}

#[cfg(test)]
mod tests {
    use super::{LIBRARY, in_folder};

    #[test]
    fn a_folder_is_searched_in_its_lib_folder_then_itself() {
        let dir = std::path::Path::new("/nowhere/oidn");
        assert_eq!(
            in_folder(dir),
            [dir.join("lib").join(LIBRARY), dir.join(LIBRARY)]
        );
    }
}
