//! The environment map as both backends read it: its texels in RGB9E5 (4 bytes each, so an
//! 8192x4096 map fits one 128 MiB binding) and the piecewise-constant distribution that
//! importance-samples it.
//!
//! The map is evaluated as Mitsuba 3's `envmap` evaluates it: bilinear between texels, with
//! column `j` centred at `u = (j + 0.5) / width` (wrapping around) and row `i` at
//! `v = i / (height - 1)` (row 0 on the +y pole, the last row on the -y pole). Its cells are
//! the patches between four texels: `width` columns by `height - 1` rows. A cell is chosen
//! with probability proportional to the mean luminance of its corners times its solid
//! angle, and a direction uniformly (in solid angle) within it, so the density is constant
//! over each cell.
//!
//! `distribution` holds, one after the other: the marginal CDF over cell rows
//! (`height - 1` values), the cosine of each texel row's polar angle (`height` values), and
//! per cell row the CDF over its columns (`width` values each). Each CDF ends at exactly 1;
//! a cell's probability is the difference of its CDF value and the one before.
//!
//! For the CPU backend each CDF also has a guide table (Chen and Asau's index table): as many
//! buckets as entries, bucket `k` holding the first entry whose value falls in bucket `k` or
//! later, so that a search starts from the bucket of `u` and ends within the next
//! bucket's entry: a step or two instead of a binary search's dozen dependent loads. The
//! result is the binary search's, exactly; the GPU keeps the plain search.

use glam::Vec3;
use pathlight_scene::HdrImage;

use crate::light_table::luminance;

/// Largest value RGB9E5 holds: (511 / 512) 2^16.
const RGB9E5_MAX: f32 = 65408.0;

/// The environment map's buffers: texels and distribution.
#[derive(Debug, Clone, PartialEq)]
pub struct EnvironmentData {
    /// Row-major RGB9E5 texels (row 0 at the top), each decoded value times
    /// [`texel_scale`] being the file's value. One zero texel when there is no map.
    pub texels: Vec<u32>,
    /// The sampling distribution (see the module documentation). One zero when there is
    /// no map.
    pub distribution: Vec<f32>,
    /// The CPU's guide tables of the distribution's CDFs: the marginal's (`height - 1 + 1`
    /// entries), then each cell row's (`width + 1` each). Empty when there is no map.
    pub guides: Vec<u16>,
}

/// The bucket of a CDF value or a random number `u` among `n` buckets: `floor(u n)`, at most
/// `n - 1`, in f32 as the search computes it (the guide table is built with this very
/// function, which makes its bounds exact).
#[inline(always)]
pub fn guide_bucket(u: f32, n: u32) -> u32 {
    ((u * n as f32) as u32).min(n - 1)
}

/// Builds the guide table of `cdf` (`n` entries): for each bucket `k` in `0 ..= n`, the first
/// entry whose bucket is `k` or later (`n - 1` past the last), so that the first entry
/// exceeding a `u` of bucket `k` lies in `guide[k] ..= guide[k + 1]`.
fn guide(cdf: &[f32]) -> Vec<u16> {
    let n = cdf.len() as u32;
    let mut out = Vec::with_capacity(cdf.len() + 1);
    let mut i = 0;
    for k in 0..=n {
        while i < n - 1 && guide_bucket(cdf[i as usize], n) < k {
            i += 1;
        }
        out.push(i as u16);
    }
    out
}

impl EnvironmentData {
    /// The buffers of a scene without a map: one placeholder value each.
    pub fn none() -> Self {
        Self {
            texels: vec![0],
            distribution: vec![0.0],
            guides: Vec::new(),
        }
    }

    /// Encodes `image` and builds its distribution.
    pub fn build(image: &HdrImage) -> Self {
        let scale = texel_scale(image.max);
        let texels: Vec<u32> = image
            .texels
            .iter()
            .map(|t| encode_rgb9e5(t.map(|c| c / scale)))
            .collect();
        let distribution = build_distribution(&texels, image.width, image.height);
        let (w, h) = (image.width as usize, image.height as usize);
        let rows = h - 1;
        let mut guides = guide(&distribution[..rows]);
        for row in 0..rows {
            let start = rows + h + row * w;
            guides.extend(guide(&distribution[start..start + w]));
        }
        Self {
            texels,
            distribution,
            guides,
        }
    }
}

/// The power of two that texels are divided by before encoding, chosen so that the
/// brightest lies in [2^14, 2^15): far from RGB9E5's ceiling and using its whole range.
pub fn texel_scale(max: f32) -> f32 {
    if max > 0.0 {
        2f32.powi(max.log2().floor() as i32 - 14)
    } else {
        1.0
    }
}

/// Packs non-negative `rgb` into RGB9E5 (a shared 5-bit exponent, 9-bit mantissas, as
/// OpenGL's `EXT_texture_shared_exponent`), rounding to nearest.
pub fn encode_rgb9e5(rgb: [f32; 3]) -> u32 {
    let rgb = rgb.map(|c| c.clamp(0.0, RGB9E5_MAX));
    let max = rgb[0].max(rgb[1]).max(rgb[2]);
    if max < 2f32.powi(-25) {
        return 0;
    }
    // Shared exponent e with max < 2^(e - 15); mantissas in units of 2^(e - 24).
    let mut exponent = (max.log2().floor() as i32).max(-16) + 16;
    let mut unit = 2f64.powi(exponent - 24);
    if (f64::from(max) / unit + 0.5).floor() >= 512.0 {
        exponent += 1;
        unit *= 2.0;
    }
    let [r, g, b] = rgb.map(|c| ((f64::from(c) / unit + 0.5).floor() as u32).min(511));
    r | g << 9 | b << 18 | (exponent as u32) << 27
}

/// Unpacks an RGB9E5 texel: exactly `mantissa * 2^(exponent - 24)` per channel. Twin of
/// WGSL `decode_rgb9e5`.
#[inline(always)]
pub fn decode_rgb9e5(texel: u32) -> [f32; 3] {
    let unit = f32::from_bits(((texel >> 27) + 127 - 24) << 23);
    [0, 9, 18].map(|shift| ((texel >> shift) & 511) as f32 * unit)
}

/// A CDF (ending at exactly 1) of `weights`, or a uniform one when they sum to zero.
fn cdf(weights: &[f64]) -> Vec<f32> {
    let total: f64 = weights.iter().sum();
    let n = weights.len();
    let mut running = 0.0;
    let mut out: Vec<f32> = weights
        .iter()
        .enumerate()
        .map(|(i, w)| {
            running += w;
            if total > 0.0 {
                (running / total) as f32
            } else {
                ((i + 1) as f64 / n as f64) as f32
            }
        })
        .collect();
    out[n - 1] = 1.0;
    out
}

/// The distribution of the module documentation over `texels` (`width` x `height`).
fn build_distribution(texels: &[u32], width: u32, height: u32) -> Vec<f32> {
    let (w, h) = (width as usize, height as usize);
    let lum: Vec<f64> = texels
        .iter()
        .map(|&t| f64::from(luminance(Vec3::from(decode_rgb9e5(t)))))
        .collect();
    let cos_theta: Vec<f32> = (0..h)
        .map(|i| (std::f64::consts::PI * i as f64 / (h - 1) as f64).cos() as f32)
        .collect();
    let mut rows = Vec::with_capacity(h - 1);
    let mut conditional = Vec::with_capacity(w * (h - 1));
    for i in 0..h - 1 {
        let band = f64::from(cos_theta[i]) - f64::from(cos_theta[i + 1]);
        let weights: Vec<f64> = (0..w)
            .map(|j| {
                let k = (j + 1) % w;
                let corners =
                    lum[i * w + j] + lum[i * w + k] + lum[(i + 1) * w + j] + lum[(i + 1) * w + k];
                0.25 * corners * band
            })
            .collect();
        rows.push(weights.iter().sum::<f64>());
        conditional.extend(cdf(&weights));
    }
    let mut out = cdf(&rows);
    out.extend(cos_theta);
    out.extend(conditional);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rgb9e5_round_trips_within_its_precision() {
        assert_eq!(decode_rgb9e5(encode_rgb9e5([0.0; 3])), [0.0; 3]);
        assert_eq!(
            decode_rgb9e5(encode_rgb9e5([1.0, 0.5, 0.25])),
            [1.0, 0.5, 0.25]
        );
        assert_eq!(
            decode_rgb9e5(encode_rgb9e5([RGB9E5_MAX; 3])),
            [RGB9E5_MAX; 3]
        );
        // The largest channel keeps 9 significant bits: relative error <= 2^-9.
        for v in [3.3e-5f32, 0.1, 0.7, 1.9999, 123.456, 30000.0] {
            let rgb = [v, v * 0.3, v * 0.01];
            let back = decode_rgb9e5(encode_rgb9e5(rgb));
            assert!((back[0] - v).abs() <= v / 512.0, "{v}: {back:?}");
            for c in 1..3 {
                assert!((back[c] - rgb[c]).abs() <= v / 512.0, "{v}: {back:?}");
            }
        }
        // Rounding up to 512 moves to the next exponent.
        assert_eq!(decode_rgb9e5(encode_rgb9e5([1.9999; 3])), [2.0; 3]);
    }

    #[test]
    fn texels_are_scaled_by_a_power_of_two_into_the_encodable_range() {
        assert_eq!(texel_scale(0.0), 1.0);
        assert_eq!(texel_scale(1.0), 2f32.powi(-14));
        assert_eq!(texel_scale(1e6), 2f32.powi(19 - 14));
        for max in [1e-6f32, 0.3, 1.0, 33952.0, 1e9] {
            let top = max / texel_scale(max);
            assert!((16384.0..32768.0).contains(&top), "{max}: {top}");
        }
    }

    #[test]
    fn the_distribution_favours_bright_cells_and_every_cdf_ends_at_one() {
        // 4 x 3 texels, one bright texel at column 2 of the middle row.
        let mut texels = vec![[0.1f32; 3]; 12];
        texels[4 + 2] = [100.0; 3];
        let image = HdrImage {
            width: 4,
            height: 3,
            max: 100.0,
            texels,
        };
        let data = EnvironmentData::build(&image);
        let d = &data.distribution;
        assert_eq!(d.len(), 2 + 3 + 2 * 4);
        // Marginal over the two cell rows: symmetric about the equator.
        assert_eq!(d[1], 1.0);
        assert!((d[0] - 0.5).abs() < 1e-6, "{d:?}");
        assert_eq!([d[2], d[4]], [1.0, -1.0]);
        assert!(d[3].abs() < 1e-7);
        // Cells touching column 2 (columns 1 and 2) take nearly everything.
        let row: Vec<f32> = d[5..9].to_vec();
        let pmf: Vec<f32> = (0..4)
            .map(|j| row[j] - if j == 0 { 0.0 } else { row[j - 1] })
            .collect();
        assert!(pmf[1] > 0.45 && pmf[2] > 0.45, "{pmf:?}");
        assert_eq!(row[3], 1.0);
    }

    /// Every guide-table window holds the first CDF entry exceeding `u`, for `u` swept
    /// finely over [0, 1) (bucket edges included) on a map with black rows and one bright
    /// texel, whose CDFs have long runs of equal values and single large steps.
    #[test]
    fn guide_windows_hold_the_first_entry_above_u() {
        let (width, height) = (37u32, 9u32);
        let mut texels = vec![[0.2f32; 3]; (width * height) as usize];
        for x in 0..width as usize {
            texels[x] = [0.0; 3];
            texels[3 * width as usize + x] = [0.0; 3];
        }
        texels[5 * width as usize + 11] = [500.0; 3];
        let image = HdrImage {
            width,
            height,
            max: 500.0,
            texels,
        };
        let data = EnvironmentData::build(&image);
        let rows = height - 1;
        let mut cdfs = vec![(0, rows, 0)];
        for row in 0..rows {
            cdfs.push((
                rows + height + row * width,
                width,
                rows + 1 + row * (width + 1),
            ));
        }
        assert_eq!(data.guides.len(), (rows + 1 + rows * (width + 1)) as usize);
        for (start, n, guide) in cdfs {
            let cdf = &data.distribution[start as usize..(start + n) as usize];
            for step in 0..4096u32 {
                let u = step as f32 / 4096.0;
                let first = cdf.iter().position(|v| *v > u).unwrap_or(n as usize - 1);
                let k = (guide + guide_bucket(u, n)) as usize;
                let window = data.guides[k] as usize..=data.guides[k + 1] as usize;
                assert!(
                    window.contains(&first),
                    "CDF at {start}, u {u}: {first} not in {window:?}"
                );
            }
        }
    }
}
