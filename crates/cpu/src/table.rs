//! A table of plain values read without bounds checks, for lookups computed for many lanes
//! side by side.

/// A non-empty table whose every read is clamped to its last entry instead of checked: a
/// load that cannot fail is one the compiler can gather for many lanes at once (a checked one
/// is a branch per lane). Callers read within the table; the clamp keeps any other index
/// there too.
#[derive(Debug, Clone, Copy)]
pub struct Table<'a, T> {
    values: &'a [T],
    last: u32,
}

impl<'a, T: Copy> Table<'a, T> {
    /// `values` as a table, or `fallback` where `values` is empty.
    pub fn new(values: &'a [T], fallback: &'a [T; 1]) -> Self {
        let values = if values.is_empty() { fallback } else { values };
        // Past 2^32 entries every u32 index is within the table.
        let last = u32::try_from(values.len() - 1).unwrap_or(u32::MAX);
        Self { values, last }
    }

    /// The values.
    #[inline(always)]
    pub fn values(&self) -> &'a [T] {
        self.values
    }

    /// Entry `i`, or the last entry when `i` is past it.
    #[inline(always)]
    pub fn at(&self, i: u32) -> T {
        // SAFETY: `values` is not empty and `last` is at most the index of its last entry
        // (`new`).
        unsafe { *self.values.get_unchecked(i.min(self.last) as usize) }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_within_the_table_and_clamps_past_it() {
        let t = Table::new(&[1.0f32, 2.0, 3.0], &[0.0]);
        assert_eq!(
            [0, 1, 2, 3, u32::MAX].map(|i| t.at(i)),
            [1.0, 2.0, 3.0, 3.0, 3.0]
        );
        let empty = Table::new(&[], &[7u16]);
        assert_eq!(
            (empty.at(0), empty.at(5), empty.values()),
            (7, 7, &[7u16][..])
        );
    }
}
