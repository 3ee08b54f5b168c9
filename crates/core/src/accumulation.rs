//! A render's running sums and the samples they hold: the sample cursor both renderers
//! advance the same way, and the accumulation a checkpoint keeps, a shard hands over and a
//! render resumes from.

use std::ops::Range;

use crate::error::RenderError;
use crate::gpu_types::{GpuAccumPixel, GpuAovPixel};

/// Which samples a render's pixels hold: from sample `first_sample`, `samples` whole passes
/// (one sample of every pixel each), and the pass under way in rows `0 .. rows_ahead`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct SampleCursor {
    /// Index of every pixel's first sample.
    pub first_sample: u32,
    /// Whole passes since the first sample.
    pub samples: u32,
    /// Rows `0 .. rows_ahead` hold one sample more (a pass in progress); 0 between passes.
    pub rows_ahead: u32,
}

impl SampleCursor {
    /// No sample yet; the first will be sample `first_sample`.
    pub fn starting_at(first_sample: u32) -> Self {
        Self {
            first_sample,
            samples: 0,
            rows_ahead: 0,
        }
    }

    /// Index of the sample the next pass adds to every pixel.
    pub fn next_sample(&self) -> u32 {
        self.first_sample + self.samples
    }

    /// Whether a pass is under way (some rows hold its sample, the others not yet).
    pub fn in_pass(&self) -> bool {
        self.rows_ahead > 0
    }

    /// Records `passes` whole passes, rendered between passes.
    pub fn add_passes(&mut self, passes: u32) {
        debug_assert!(!self.in_pass(), "whole passes are added between passes");
        self.samples += passes;
    }

    /// The next band of the pass under way in an image `height` rows high: `rows` rows (at
    /// least one, fewer at the bottom) from the first row without its sample.
    pub fn next_band(&self, rows: u32, height: u32) -> Range<u32> {
        self.rows_ahead..(self.rows_ahead + rows.max(1)).min(height)
    }

    /// Records that the rows up to `end` hold the pass's sample (`end` from
    /// [`Self::next_band`]); returns whether that completed the pass.
    pub fn add_band(&mut self, end: u32, height: u32) -> bool {
        if end < height {
            self.rows_ahead = end;
            return false;
        }
        self.rows_ahead = 0;
        self.samples += 1;
        true
    }

    /// Samples per pixel of row `y`.
    pub fn row_samples(&self, y: u32) -> u32 {
        self.samples + u32::from(y < self.rows_ahead)
    }
}

/// A render's running sums with the samples they hold: what a checkpoint keeps, what a
/// shard hands over, and what a render resumes from.
#[derive(Debug, Clone, PartialEq)]
pub struct Accumulation {
    /// The samples the sums hold.
    pub cursor: SampleCursor,
    /// The fixed-point sums, row by row.
    pub sums: Vec<GpuAccumPixel>,
    /// The auxiliary images' sums from the same samples, row by row; empty for a render
    /// without them.
    pub aovs: Vec<GpuAovPixel>,
}

impl Accumulation {
    /// No sample yet: the image empty (with empty auxiliary images when `aovs`), its first
    /// sample `first_sample`.
    pub fn empty(width: u32, height: u32, first_sample: u32, aovs: bool) -> Self {
        let pixels = (width * height) as usize;
        Self {
            cursor: SampleCursor::starting_at(first_sample),
            sums: vec![GpuAccumPixel::default(); pixels],
            aovs: vec![GpuAovPixel::default(); if aovs { pixels } else { 0 }],
        }
    }

    /// Whether it holds the auxiliary images.
    pub fn has_aovs(&self) -> bool {
        !self.aovs.is_empty()
    }

    /// Refuses sums that do not fit a `width` x `height` image rendered with auxiliary
    /// images or without (`aovs`).
    pub fn check_fits(&self, width: u32, height: u32, aovs: bool) -> Result<(), RenderError> {
        let pixels = width as usize * height as usize;
        if self.has_aovs() != aovs || (aovs && self.aovs.len() != pixels) {
            let has = |yes: bool| if yes { "with" } else { "without" };
            return Err(RenderError::Resume(format!(
                "sums {} auxiliary images do not fit a render {} them",
                has(self.has_aovs()),
                has(aovs)
            )));
        }
        let c = &self.cursor;
        if self.sums.len() != pixels || (c.in_pass() && c.rows_ahead >= height) {
            return Err(RenderError::Resume(format!(
                "{} sums with {} rows ahead do not fit a {width}x{height} image",
                self.sums.len(),
                c.rows_ahead
            )));
        }
        if u64::from(c.first_sample) + u64::from(c.samples) + 1 > u64::from(u32::MAX) {
            return Err(RenderError::Resume(format!(
                "samples {}..{} run past the last sample index",
                c.first_sample,
                u64::from(c.first_sample) + u64::from(c.samples)
            )));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::SampleCursor;

    /// Bands of a pass advance the rows ahead until the last completes the pass.
    #[test]
    fn bands_complete_a_pass_and_whole_passes_add_up() {
        let mut c = SampleCursor::starting_at(7);
        c.add_passes(3);
        assert_eq!((c.next_sample(), c.in_pass()), (10, false));
        let band = c.next_band(4, 10);
        assert_eq!(band, 0..4);
        assert!(!c.add_band(band.end, 10));
        assert_eq!((c.row_samples(3), c.row_samples(4)), (4, 3));
        let band = c.next_band(0, 10);
        assert_eq!(band, 4..5, "a band is at least a row");
        assert!(!c.add_band(band.end, 10));
        let band = c.next_band(100, 10);
        assert_eq!(band, 5..10, "and stops at the bottom");
        assert!(c.add_band(band.end, 10));
        assert_eq!(
            c,
            SampleCursor {
                first_sample: 7,
                samples: 4,
                rows_ahead: 0
            }
        );
    }
}
