//! How much memory a scene's triangles need, against what the machine allows: checked before
//! a large scene is copied (a glTF file's placements) or prepared (its BVH and buffers), so
//! that a scene too large fails with a message naming its size instead of an abort.

use std::fmt;

/// Peak bytes a triangle costs from its file to the first frame on the CPU backend, rounded
/// up for the costliest kind: a mesh without tangents peaks at 134-161 (whole process;
/// `bench/first-frame.sh`'s 1M-16.8M-triangle GLBs, `bench/scenes/million-triangles.toml`
/// 148), a normal-mapped one keeps a vertex and a tangent a triangle corner (about 270).
pub const BYTES_PER_TRIANGLE: u64 = 280;

/// Bytes a placement of a shared mesh costs beyond its mesh, rounded up: its object in the
/// scene (name, shape) and in the backends (object record, transforms, top-level primitive
/// and its share of the top-level tree).
pub const BYTES_PER_INSTANCE: u64 = 512;

/// How much geometry a scene holds: the triangles it keeps (a shared mesh's once) and the
/// placements of shared meshes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct SceneSize {
    /// Triangles kept, each shared mesh's counted once.
    pub triangles: u64,
    /// Placements of shared meshes.
    pub instances: u64,
}

impl SceneSize {
    /// About the bytes the scene needs at its peak.
    pub fn bytes(&self) -> u64 {
        self.triangles
            .saturating_mul(BYTES_PER_TRIANGLE)
            .saturating_add(self.instances.saturating_mul(BYTES_PER_INSTANCE))
    }
}

impl fmt::Display for SceneSize {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} triangles", self.triangles)?;
        if self.instances > 0 {
            write!(f, " and {} instances", self.instances)?;
        }
        Ok(())
    }
}

/// The environment variable that sets the memory a scene may use: bytes, or a number with
/// the suffix K, M, G or T (powers of 1024). Without it, the memory available now.
pub const LIMIT_VARIABLE: &str = "PATHLIGHT_MEMORY_LIMIT";

/// What a scene may use, and where that figure comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Budget {
    /// Bytes.
    pub bytes: u64,
    /// Set by [`LIMIT_VARIABLE`] rather than measured.
    pub from_variable: bool,
}

impl Budget {
    /// The budget of this process: [`LIMIT_VARIABLE`] when set (an error names a value it
    /// cannot read), else the memory available (Linux's `MemAvailable`, less where a cgroup
    /// limits the process further); `None` where neither is known.
    pub fn of_this_process() -> Result<Option<Self>, String> {
        if let Ok(text) = std::env::var(LIMIT_VARIABLE) {
            return parse_bytes(&text)
                .map(|bytes| {
                    Some(Self {
                        bytes,
                        from_variable: true,
                    })
                })
                .ok_or_else(|| {
                    format!(
                        "{LIMIT_VARIABLE}={text:?} is not a number of bytes (e.g. 2G, 512M, 1000000)"
                    )
                });
        }
        let available = meminfo_available();
        let cgroup = cgroup_room();
        Ok(match (available, cgroup) {
            (Some(a), Some(c)) => Some(a.min(c)),
            (a, c) => a.or(c),
        }
        .map(|bytes| Self {
            bytes,
            from_variable: false,
        }))
    }

    /// Refuses a scene of `size` when it needs more than this budget: the message says
    /// how many bytes it needs and how many there are.
    pub fn check(&self, size: SceneSize) -> Result<(), String> {
        let needed = size.bytes();
        if needed <= self.bytes {
            return Ok(());
        }
        let source = if self.from_variable {
            format!("{LIMIT_VARIABLE} allows")
        } else {
            format!("the machine has available ({LIMIT_VARIABLE} sets another limit)")
        };
        let each = if size.instances > 0 {
            format!("about {BYTES_PER_TRIANGLE} bytes a triangle, {BYTES_PER_INSTANCE} an instance")
        } else {
            format!("about {BYTES_PER_TRIANGLE} bytes each")
        };
        Err(format!(
            "{size} need about {} ({each}), more than the {} {source}",
            Bytes(needed),
            Bytes(self.bytes)
        ))
    }
}

/// Checks a scene of `size` against this process's budget (nothing to check where none is
/// known).
pub fn check_size(size: SceneSize) -> Result<(), String> {
    match Budget::of_this_process()? {
        Some(budget) => budget.check(size),
        None => Ok(()),
    }
}

/// A byte count, written in the largest binary unit that keeps it at least 1.
pub struct Bytes(pub u64);

impl fmt::Display for Bytes {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let units = ["bytes", "KiB", "MiB", "GiB", "TiB"];
        let mut value = self.0 as f64;
        let mut unit = 0;
        while value >= 1024.0 && unit + 1 < units.len() {
            value /= 1024.0;
            unit += 1;
        }
        if unit == 0 {
            write!(f, "{} bytes", self.0)
        } else {
            write!(f, "{value:.1} {}", units[unit])
        }
    }
}

/// `text` as bytes: digits with an optional suffix K, M, G or T (powers of 1024, an optional
/// trailing `B` or `iB`).
fn parse_bytes(text: &str) -> Option<u64> {
    let t = text.trim();
    let t = t
        .strip_suffix("iB")
        .or_else(|| t.strip_suffix('B'))
        .unwrap_or(t);
    let (digits, shift) = match t.char_indices().last()? {
        (i, 'K' | 'k') => (&t[..i], 10),
        (i, 'M' | 'm') => (&t[..i], 20),
        (i, 'G' | 'g') => (&t[..i], 30),
        (i, 'T' | 't') => (&t[..i], 40),
        _ => (t, 0),
    };
    digits.trim().parse::<u64>().ok()?.checked_mul(1 << shift)
}

/// `MemAvailable` of `/proc/meminfo`, in bytes.
fn meminfo_available() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    kib.checked_mul(1024)
}

/// What the process's cgroup (v2) still allows: `memory.max` less `memory.current`; `None`
/// without a limit.
fn cgroup_room() -> Option<u64> {
    let own = std::fs::read_to_string("/proc/self/cgroup").ok()?;
    let path = own.lines().find_map(|l| l.strip_prefix("0::"))?;
    let dir = std::path::Path::new("/sys/fs/cgroup").join(path.trim_start_matches('/'));
    let read = |name: &str| std::fs::read_to_string(dir.join(name)).ok();
    let max: u64 = read("memory.max")?.trim().parse().ok()?;
    let current: u64 = read("memory.current")?.trim().parse().ok()?;
    Some(max.saturating_sub(current))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_read_with_binary_suffixes_and_refuse_nonsense() {
        assert_eq!(parse_bytes("1000000"), Some(1_000_000));
        assert_eq!(parse_bytes("512M"), Some(512 << 20));
        assert_eq!(parse_bytes("2G"), Some(2 << 30));
        assert_eq!(parse_bytes("2GiB"), Some(2 << 30));
        assert_eq!(parse_bytes(" 3 k "), Some(3 << 10));
        for bad in ["", "G", "lots", "-1G", "1.5G", "99999999999T"] {
            assert_eq!(parse_bytes(bad), None, "{bad}");
        }
    }

    #[test]
    fn a_budget_refuses_what_it_cannot_hold_saying_how_much() {
        let budget = Budget {
            bytes: 1 << 30,
            from_variable: true,
        };
        let triangles = |triangles| SceneSize {
            triangles,
            instances: 0,
        };
        assert!(
            budget
                .check(triangles((1 << 30) / BYTES_PER_TRIANGLE))
                .is_ok()
        );
        let message = budget.check(triangles(10_000_000)).unwrap_err();
        assert_eq!(
            message,
            "10000000 triangles need about 2.6 GiB (about 280 bytes each), more than the 1.0 GiB PATHLIGHT_MEMORY_LIMIT allows"
        );
        // A mesh of 10,000 triangles placed 10,000 times: its triangles once, and the
        // placements.
        let instanced = SceneSize {
            triangles: 10_000,
            instances: 10_000,
        };
        assert!(budget.check(instanced).is_ok());
        let many = SceneSize {
            triangles: 10_000,
            instances: 3_000_000,
        };
        assert_eq!(
            budget.check(many).unwrap_err(),
            "10000 triangles and 3000000 instances need about 1.4 GiB (about 280 bytes a triangle, 512 an instance), more than the 1.0 GiB PATHLIGHT_MEMORY_LIMIT allows"
        );
        assert_eq!(Bytes(1536).to_string(), "1.5 KiB");
        assert_eq!(Bytes(12).to_string(), "12 bytes");
    }
}
