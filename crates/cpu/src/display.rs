//! The viewer's display on the CPU: twin of `display.wgsl`. It turns the running sums into
//! 8-bit sRGB pixels of the window's size, which the viewer copies straight into the
//! window's surface: on a machine without a GPU, the software adapter would spend more time
//! running the display shader than the CPU backend spends on a band of rows.

use std::sync::LazyLock;

use glam::{Mat3A, Vec3A};
use pathlight_core::ToneMap;
use pathlight_core::gpu_types::GpuAccumPixel;

/// An image to display: fixed-point running sums, row by row (WGSL `DisplayParams` and
/// `pixels`).
#[derive(Debug, Clone, Copy)]
pub struct DisplayImage<'a> {
    /// The sums.
    pub pixels: &'a [GpuAccumPixel],
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Samples per pixel in rows `rows_ahead ..`.
    pub samples: u32,
    /// Rows holding one sample more (a pass in progress).
    pub rows_ahead: u32,
}

/// Byte order of a surface's 8-bit pixels.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ChannelOrder {
    /// Red, green, blue, alpha.
    Rgba,
    /// Blue, green, red, alpha.
    Bgra,
}

/// Narkowicz's fit of the ACES filmic curve. Twin of WGSL `aces`.
pub fn aces(x: Vec3A) -> Vec3A {
    ((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14)).clamp(Vec3A::ZERO, Vec3A::ONE)
}

/// AgX with its default look. Twin of WGSL `agx`.
pub fn agx(color: Vec3A) -> Vec3A {
    let inset = Mat3A::from_cols_array(&[
        0.842_479_06,
        0.042_328_24,
        0.042_375_655,
        0.078_433_6,
        0.878_468_6,
        0.078_433_6,
        0.079_223_745,
        0.079_166_13,
        0.879_143,
    ]);
    let outset = Mat3A::from_cols_array(&[
        1.196_879,
        -0.052_896_85,
        -0.052_971_635,
        -0.098_020_88,
        1.151_903_1,
        -0.098_043_45,
        -0.099_029_74,
        -0.098_961_18,
        1.151_073_7,
    ]);
    let (min_ev, max_ev) = (-12.473_93_f32, 4.026_069_f32);
    let x = inset * color.max(Vec3A::splat(1e-10));
    let x = ((Vec3A::new(x.x.log2(), x.y.log2(), x.z.log2()) - min_ev) / (max_ev - min_ev))
        .clamp(Vec3A::ZERO, Vec3A::ONE);
    let x2 = x * x;
    let x4 = x2 * x2;
    let s =
        15.5 * x4 * x2 - 40.14 * x4 * x + 31.96 * x4 - 6.868 * x2 * x + 0.4298 * x2 + 0.1191 * x
            - 0.00232;
    let linear = (outset * s).max(Vec3A::ZERO);
    Vec3A::new(linear.x.powf(2.2), linear.y.powf(2.2), linear.z.powf(2.2))
        .clamp(Vec3A::ZERO, Vec3A::ONE)
}

/// The sRGB transfer curve on [0, 1]. Twin of WGSL `srgb_encode`.
pub fn srgb_encode(c: Vec3A) -> Vec3A {
    let x = c.clamp(Vec3A::ZERO, Vec3A::ONE);
    let encode = |v: f32| {
        if v <= 0.003_130_8 {
            12.92 * v
        } else {
            1.055 * v.powf(1.0 / 2.4) - 0.055
        }
    };
    Vec3A::new(encode(x.x), encode(x.y), encode(x.z))
}

/// The displayed linear colour of pixel (x, y): the mean of its samples through
/// `tonemap`. Twin of WGSL `fragment_main` (before the sRGB curve).
pub fn display_color(image: &DisplayImage, x: u32, y: u32, tonemap: ToneMap) -> Vec3A {
    let count = image.samples + u32::from(y < image.rows_ahead);
    if count == 0 {
        return Vec3A::ZERO;
    }
    let p = image.pixels[(y * image.width + x) as usize];
    let hi = Vec3A::new(p.hi[0] as f32, p.hi[1] as f32, p.hi[2] as f32);
    let lo = Vec3A::new(p.lo[0] as f32, p.lo[1] as f32, p.lo[2] as f32);
    let color = (hi + lo * (1.0 / 4_294_967_296.0)) / count as f32;
    match tonemap {
        ToneMap::Aces => aces(color),
        ToneMap::Agx => agx(color),
        ToneMap::Clamp => color.clamp(Vec3A::ZERO, Vec3A::ONE),
    }
}

/// Rounds linear values in [0, 1] to 8-bit sRGB codes as `srgb_encode` and a unorm8 store
/// would, without a power per channel: a coarse table gives a first code, the exact
/// boundaries between codes the rest.
struct Srgb8 {
    /// Linear value at which each code gives way to the next.
    boundaries: [f32; 255],
    /// The code of `i / COARSE`.
    coarse: Vec<u8>,
}

/// Steps of the coarse table.
const COARSE: usize = 4096;

/// The table, built once.
static SRGB8: LazyLock<Srgb8> = LazyLock::new(Srgb8::new);

impl Srgb8 {
    fn new() -> Self {
        let decode = |v: f64| {
            if v <= 0.04045 {
                v / 12.92
            } else {
                ((v + 0.055) / 1.055).powf(2.4)
            }
        };
        let boundaries = std::array::from_fn(|c| decode((c as f64 + 0.5) / 255.0) as f32);
        let coarse = (0..=COARSE)
            .map(|i| {
                let x = i as f32 / COARSE as f32;
                boundaries.iter().take_while(|&&b| x >= b).count() as u8
            })
            .collect();
        Self { boundaries, coarse }
    }

    fn code(&self, linear: f32) -> u8 {
        let x = linear.clamp(0.0, 1.0);
        let mut code = self.coarse[(x * COARSE as f32) as usize];
        while code < 255 && x >= self.boundaries[code as usize] {
            code += 1;
        }
        code
    }
}

/// The CPU's display: `image` scaled (nearest pixel, as the display pass samples it) to
/// the window through a tone mapper, as 8-bit sRGB. The image's own pixels are kept and
/// a row is mapped again only when its sample count changed (each band of rows the
/// renderer adds changes only its own rows).
#[derive(Debug, Default)]
pub struct CpuDisplay {
    /// What the kept pixels were made for: image, size, tone mapper and byte order.
    made_for: Option<(u64, u32, u32, ToneMap, ChannelOrder)>,
    /// Per image row, the sample count its pixels were mapped with.
    row_counts: Vec<Option<u32>>,
    /// The image's pixels, mapped.
    texels: Vec<[u8; 4]>,
}

impl CpuDisplay {
    /// Nothing kept yet.
    pub fn new() -> Self {
        Self::default()
    }

    /// Fills `out` with `image` (whose sums change only by samples added, until `image_id`
    /// changes) at `target` (width, height) through `tonemap`, as 8-bit sRGB in `order`,
    /// opaque.
    pub fn pixels(
        &mut self,
        image: &DisplayImage,
        image_id: u64,
        tonemap: ToneMap,
        target: (u32, u32),
        order: ChannelOrder,
        out: &mut Vec<u8>,
    ) {
        let (width, height) = (image.width.max(1), image.height.max(1));
        let made_for = Some((image_id, width, height, tonemap, order));
        if self.made_for != made_for {
            self.made_for = made_for;
            self.row_counts = vec![None; height as usize];
            self.texels = vec![[0, 0, 0, 255]; (width * height) as usize];
        }
        for y in 0..height {
            let count = image.samples + u32::from(y < image.rows_ahead);
            if self.row_counts[y as usize] == Some(count) {
                continue;
            }
            self.row_counts[y as usize] = Some(count);
            let row = &mut self.texels[(y * width) as usize..((y + 1) * width) as usize];
            for (x, texel) in row.iter_mut().enumerate() {
                *texel = display_texel(image, x as u32, y, tonemap, order);
            }
        }
        // The display pass reads the pixel under the target pixel's centre.
        let source = |t: u32, size: u32, target: u32| {
            (((t as f32 + 0.5) * size as f32 / target.max(1) as f32) as u32).min(size - 1)
        };
        let columns: Vec<u32> = (0..target.0).map(|x| source(x, width, target.0)).collect();
        let stride = target.0 as usize * 4;
        out.clear();
        out.resize(stride * target.1 as usize, 0);
        let mut last_y = None;
        for ty in 0..target.1 as usize {
            let y = source(ty as u32, height, target.1);
            let (done, rest) = out.split_at_mut(ty * stride);
            let row = &mut rest[..stride];
            if last_y == Some(y) {
                row.copy_from_slice(&done[done.len() - stride..]);
                continue;
            }
            last_y = Some(y);
            let texels = &self.texels[(y * width) as usize..];
            for (dst, &x) in row.chunks_exact_mut(4).zip(&columns) {
                dst.copy_from_slice(&texels[x as usize]);
            }
        }
    }
}

/// Pixel (x, y) of `image` as 8-bit sRGB in `order`, opaque.
fn display_texel(
    image: &DisplayImage,
    x: u32,
    y: u32,
    tonemap: ToneMap,
    order: ChannelOrder,
) -> [u8; 4] {
    let c = if image.pixels.is_empty() {
        Vec3A::ZERO
    } else {
        display_color(image, x, y, tonemap)
    };
    let [r, g, b] = [c.x, c.y, c.z].map(|v| SRGB8.code(v));
    match order {
        ChannelOrder::Rgba => [r, g, b, 255],
        ChannelOrder::Bgra => [b, g, r, 255],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_codes_round_the_curve_exactly() {
        let srgb = Srgb8::new();
        for i in 0..=100_000 {
            let x = i as f32 / 100_000.0;
            let exact = (f64::from(srgb_encode(Vec3A::splat(x)).x) * 255.0).round();
            let code = f64::from(srgb.code(x));
            // At a boundary the f32 curve may round either way.
            assert!((code - exact).abs() <= 1.0, "{x}: {code} vs {exact}");
        }
        assert_eq!(srgb.code(-1.0), 0);
        assert_eq!(srgb.code(f32::NAN), 0);
        assert_eq!(srgb.code(0.5), 188, "0.5 is sRGB 187.5 rounded up");
        assert_eq!(srgb.code(7.0), 255);
    }

    #[test]
    fn pixels_are_means_scaled_to_the_target() {
        // 2 x 1 image, 2 samples: sums 1.0 and 0.25 per channel; the first row is one
        // sample ahead.
        let sum = |v: f64| GpuAccumPixel {
            hi: [v as u32; 4],
            lo: [((v.fract()) * 4_294_967_296.0) as u32; 4],
        };
        let pixels = [sum(1.0), sum(0.25)];
        let image = DisplayImage {
            pixels: &pixels,
            width: 2,
            height: 1,
            samples: 1,
            rows_ahead: 1,
        };
        let mut out = Vec::new();
        let mut display = CpuDisplay::new();
        display.pixels(
            &image,
            0,
            ToneMap::Clamp,
            (4, 2),
            ChannelOrder::Bgra,
            &mut out,
        );
        assert_eq!(out.len(), 4 * 2 * 4);
        let srgb = Srgb8::new();
        let (a, b) = (srgb.code(0.5), srgb.code(0.125));
        let row = [a, a, a, 255, a, a, a, 255, b, b, b, 255, b, b, b, 255];
        assert_eq!(out[..16], row, "each source pixel covers two target pixels");
        assert_eq!(out[16..], row, "and two rows");
        // The same counts: the kept pixels, even though the sums changed (they only change
        // with the count).
        let doubled = [sum(2.0), sum(0.5)];
        let again = DisplayImage {
            pixels: &doubled,
            ..image
        };
        display.pixels(
            &again,
            0,
            ToneMap::Clamp,
            (4, 2),
            ChannelOrder::Bgra,
            &mut out,
        );
        assert_eq!(out[..16], row);
        // A new count, or a new image, maps the row again.
        let more = DisplayImage {
            samples: 3,
            ..again
        };
        display.pixels(
            &more,
            0,
            ToneMap::Clamp,
            (2, 1),
            ChannelOrder::Rgba,
            &mut out,
        );
        assert_eq!(out, [a, a, a, 255, b, b, b, 255]);
        display.pixels(
            &again,
            1,
            ToneMap::Clamp,
            (2, 1),
            ChannelOrder::Rgba,
            &mut out,
        );
        let c = srgb.code(1.0);
        assert_eq!(out[..4], [c, c, c, 255], "2.0 over 2 samples, clamped");
    }
}
