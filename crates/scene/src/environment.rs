//! Light arriving from infinitely far away: a constant radiance, or an equirectangular
//! (latitude-longitude) HDR map oriented as Mitsuba 3's `envmap` emitter orients it
//! (`docs/scene-format.md` has the picture).

use std::path::Path;
use std::sync::Arc;

use glam::{DMat3, DVec3, Vec3};

use crate::error::SceneError;

/// Light arriving from infinitely far away.
#[derive(Debug, Clone, PartialEq)]
pub enum Environment {
    /// The same linear RGB radiance from every direction (zero: black).
    Constant(Vec3),
    /// An HDR map, scaled and turned about the up axis.
    Map(EnvironmentMap),
}

impl Default for Environment {
    fn default() -> Self {
        Self::Constant(Vec3::ZERO)
    }
}

impl Environment {
    /// `image` scaled by `strength` and turned by `rotation_deg` about +y; a map whose texels
    /// are all equal is the constant environment it equals (and is sampled as one: cosine-
    /// weighted, the ideal density for it).
    pub fn from_map(image: Arc<HdrImage>, strength: f32, rotation_deg: f32) -> Self {
        let first = image.texels[0];
        if image.texels.iter().all(|&t| t == first) {
            return Self::Constant(Vec3::from(first) * strength);
        }
        Self::Map(EnvironmentMap {
            image,
            strength,
            rotation_deg,
        })
    }

    /// This environment with `map` in place of it (strength 1, no turn) where given, and the
    /// map's strength and rotation set where given. `None` where a strength or rotation is
    /// given for a constant environment and no map: there is no map to scale or turn.
    pub fn with_map(
        &self,
        map: Option<Arc<HdrImage>>,
        strength: Option<f32>,
        rotation_deg: Option<f32>,
    ) -> Option<Self> {
        let (image, old_strength, old_rotation) = match (map, self) {
            (Some(image), _) => (image, 1.0, 0.0),
            (None, Self::Map(map)) => (map.image.clone(), map.strength, map.rotation_deg),
            (None, Self::Constant(_)) => {
                return (strength.is_none() && rotation_deg.is_none()).then(|| self.clone());
            }
        };
        Some(Self::from_map(
            image,
            strength.unwrap_or(old_strength),
            rotation_deg.unwrap_or(old_rotation),
        ))
    }
}

/// An equirectangular HDR map as the scene places it.
#[derive(Debug, Clone, PartialEq)]
pub struct EnvironmentMap {
    /// The decoded image.
    pub image: Arc<HdrImage>,
    /// Factor on every texel (Mitsuba's `scale`).
    pub strength: f32,
    /// Turn about the up (+y) axis in degrees, counter-clockwise seen from above (Mitsuba's
    /// `to_world` rotation about y by the same angle).
    pub rotation_deg: f32,
}

/// Smallest accepted map: Mitsuba's limit, 2 columns and 3 rows.
pub const MIN_MAP_SIZE: [u32; 2] = [2, 3];
/// Largest accepted map side, in texels.
pub const MAX_MAP_SIDE: u32 = 16384;

/// A decoded linear-RGB image: row 0 is the top (the +y pole of a map).
#[derive(Debug, Clone, PartialEq)]
pub struct HdrImage {
    /// Width in texels.
    pub width: u32,
    /// Height in texels.
    pub height: u32,
    /// Row-major linear RGB, every value finite and >= 0.
    pub texels: Vec<[f32; 3]>,
    /// The largest value of any channel.
    pub max: f32,
}

impl HdrImage {
    /// Reads an OpenEXR or Radiance `.hdr` file (or any format `image` decodes: 8-bit ones
    /// are sRGB-decoded). An OpenEXR file's `chromaticities` other than Rec. 709's are
    /// converted to Rec. 709 primaries as OpenEXR and Mitsuba 3 convert them (through XYZ,
    /// without adapting the white point). NaN and infinite texels are refused with their
    /// position; negative values (filtering ringing) are clamped to zero with a warning.
    pub fn open(path: &Path) -> Result<Self, SceneError> {
        let bytes = std::fs::read(path).map_err(|source| SceneError::Io {
            path: path.to_owned(),
            source,
        })?;
        Self::decode(&bytes, path)
    }

    /// Decodes an image held in memory; `path` names it in errors.
    pub fn decode(bytes: &[u8], path: &Path) -> Result<Self, SceneError> {
        let asset = |message: String| SceneError::Asset {
            path: path.to_owned(),
            message,
        };
        let format = image::guess_format(bytes)
            .map_err(|err| asset(format!("cannot decode image: {err}")))?;
        let decoded = image::load_from_memory_with_format(bytes, format)
            .map_err(|err| asset(format!("cannot decode image: {err}")))?;
        let (width, height) = (decoded.width(), decoded.height());
        let [min_w, min_h] = MIN_MAP_SIZE;
        if width < min_w || height < min_h || width > MAX_MAP_SIDE || height > MAX_MAP_SIDE {
            return Err(asset(format!(
                "environment map is {width}x{height}; each side must lie in \
                 {min_w}..={MAX_MAP_SIDE} (width) and {min_h}..={MAX_MAP_SIDE} (height)"
            )));
        }
        // Integer formats (PNG, JPEG) are sRGB-encoded; float ones (EXR, HDR) linear.
        let linear = matches!(
            decoded.color(),
            image::ColorType::Rgb32F | image::ColorType::Rgba32F
        );
        let to_rec709 = if format == image::ImageFormat::OpenExr {
            exr_to_rec709(bytes)
        } else {
            None
        };
        let rgb = decoded.to_rgb32f();
        let mut texels = Vec::with_capacity(rgb.len() / 3);
        let mut negatives = 0usize;
        let mut max = 0.0f32;
        for (i, p) in rgb.pixels().enumerate() {
            let mut t = p.0;
            if !linear {
                t = t.map(crate::texture::srgb_to_linear);
            }
            if let Some(m) = to_rec709 {
                t = (m * DVec3::from(t.map(f64::from))).as_vec3().to_array();
            }
            if let Some(c) = t.iter().find(|c| !c.is_finite()) {
                let (x, y) = (i as u32 % width, i as u32 / width);
                return Err(asset(format!(
                    "texel ({x}, {y}) holds {c}: environment maps must be finite"
                )));
            }
            if t.iter().any(|&c| c < 0.0) {
                negatives += 1;
                t = t.map(|c| c.max(0.0));
            }
            max = max.max(t[0]).max(t[1]).max(t[2]);
            texels.push(t);
        }
        if negatives > 0 {
            log::warn!(
                "{}: {negatives} texels with negative values were clamped to 0",
                path.display()
            );
        }
        Ok(Self {
            width,
            height,
            texels,
            max,
        })
    }
}

/// Chromaticities (x, y) of red, green, blue and white: Rec. 709 / sRGB's.
const REC709: [[f64; 2]; 4] = [[0.64, 0.33], [0.30, 0.60], [0.15, 0.06], [0.3127, 0.3290]];

/// The matrix from an OpenEXR file's RGB to Rec. 709 RGB when its header names other
/// chromaticities (by Mitsuba's test: squared distances summing to 1e-6 or more).
fn exr_to_rec709(bytes: &[u8]) -> Option<DMat3> {
    let meta = exr::meta::MetaData::read_from_buffered(std::io::Cursor::new(bytes), false).ok()?;
    let c = meta.headers.first()?.shared_attributes.chromaticities?;
    let file = [c.red, c.green, c.blue, c.white].map(|v| [f64::from(v.x()), f64::from(v.y())]);
    let distance: f64 = file
        .iter()
        .zip(&REC709)
        .map(|(a, b)| (a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2))
        .sum();
    (distance >= 1e-6).then(|| rgb_to_xyz(&REC709).inverse() * rgb_to_xyz(&file))
}

/// The RGB to XYZ matrix of primaries and white `[r, g, b, w]` (white at luminance 1).
fn rgb_to_xyz(c: &[[f64; 2]; 4]) -> DMat3 {
    let xyz = |[x, y]: [f64; 2]| DVec3::new(x, y, 1.0 - x - y);
    let primaries = DMat3::from_cols(xyz(c[0]), xyz(c[1]), xyz(c[2]));
    let white = xyz(c[3]) / c[3][1];
    let s = primaries.inverse() * white;
    primaries * DMat3::from_diagonal(s)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A Radiance RGBE file of `w` x `h` texels, all `rgbe`.
    fn rgbe(w: u32, h: u32, rgbe: [u8; 4]) -> Vec<u8> {
        let mut out = format!("#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y {h} +X {w}\n").into_bytes();
        for _ in 0..w * h {
            out.extend_from_slice(&rgbe);
        }
        out
    }

    #[test]
    fn radiance_files_decode_to_linear_values() {
        // RGBE (128, 64, 32, 129): mantissas / 256 * 2^(129 - 128).
        let image = HdrImage::decode(&rgbe(4, 3, [128, 64, 32, 129]), Path::new("x.hdr")).unwrap();
        assert_eq!((image.width, image.height), (4, 3));
        assert_eq!(image.texels[5], [1.0, 0.5, 0.25]);
        assert_eq!(image.max, 1.0);
    }

    #[test]
    fn bad_maps_are_refused_with_the_file_and_the_reason() {
        let path = Path::new("sky.hdr");
        let err = HdrImage::decode(b"not an image", path)
            .unwrap_err()
            .to_string();
        assert!(err.starts_with("sky.hdr: cannot decode image"), "{err}");
        let err = HdrImage::decode(&rgbe(2, 2, [3, 3, 3, 128]), path)
            .unwrap_err()
            .to_string();
        assert!(err.contains("environment map is 2x2"), "{err}");
        let err = HdrImage::decode(&rgbe(4, 3, [3, 3, 3, 128])[..40], path)
            .unwrap_err()
            .to_string();
        assert!(err.starts_with("sky.hdr: cannot decode image"), "{err}");
    }

    #[test]
    fn chromaticities_convert_through_xyz_without_white_adaptation() {
        // Rec. 709 primaries with D65 white: the published sRGB to XYZ matrix.
        let m = rgb_to_xyz(&REC709);
        let published = DMat3::from_cols_array(&[
            0.4124, 0.2126, 0.0193, 0.3576, 0.7152, 0.1192, 0.1805, 0.0722, 0.9505,
        ]);
        assert!(m.abs_diff_eq(published, 2e-4), "{m}");
        // A file's white maps to its white's chromaticity expressed in Rec. 709: for a D50
        // white, warmer than (1, 1, 1) (no adaptation, as OpenEXR's RGBtoXYZ/XYZtoRGB).
        let mut d50 = REC709;
        d50[3] = [0.3457, 0.3585];
        let white = rgb_to_xyz(&REC709).inverse() * rgb_to_xyz(&d50) * DVec3::ONE;
        assert!(white.x > 1.05 && white.z < 0.8, "{white}");
    }

    #[test]
    fn a_map_of_equal_texels_is_a_constant_environment() {
        let image = |texels: Vec<[f32; 3]>| {
            Arc::new(HdrImage {
                width: 2,
                height: 3,
                max: 1.0,
                texels,
            })
        };
        let flat = Environment::from_map(image(vec![[1.0, 0.5, 0.25]; 6]), 2.0, 30.0);
        assert_eq!(flat, Environment::Constant(Vec3::new(2.0, 1.0, 0.5)));
        let mut texels = vec![[1.0, 0.5, 0.25]; 6];
        texels[3] = [0.0; 3];
        assert!(matches!(
            Environment::from_map(image(texels), 2.0, 30.0),
            Environment::Map(_)
        ));
    }
}
