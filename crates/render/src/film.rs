//! The rendered image: mean linear radiance per pixel.

/// Mean linear RGB radiance per pixel, row 0 at the top.
#[derive(Debug, Clone, PartialEq)]
pub struct Film {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Samples per pixel averaged into every pixel.
    pub spp: u32,
    /// Row-major pixels.
    pub pixels: Vec<[f32; 3]>,
}

impl Film {
    /// The pixel at column `x`, row `y`.
    pub fn pixel(&self, x: u32, y: u32) -> [f32; 3] {
        self.pixels[(y * self.width + x) as usize]
    }

    /// Mean of every channel over the whole image (in f64).
    pub fn mean(&self) -> [f64; 3] {
        let mut sum = [0.0f64; 3];
        for p in &self.pixels {
            for c in 0..3 {
                sum[c] += f64::from(p[c]);
            }
        }
        sum.map(|s| s / self.pixels.len().max(1) as f64)
    }
}
