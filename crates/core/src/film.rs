//! The rendered image: mean linear radiance per pixel, made from either backend's running
//! sums, read from and written to OpenEXR, and compared with a reference.

use crate::accumulation::{Accumulation, SampleCursor};
use crate::gpu_types::{GpuAccumPixel, GpuAovPixel};

/// An image written beside a film's in one OpenEXR file ([`Film::encode_exr_layers`]).
#[derive(Debug, Clone, Copy)]
pub struct ExrLayer<'a> {
    /// The layer's name (`albedo`).
    pub name: &'a str,
    /// Its three channels' names (`R`, `G`, `B`, or `X`, `Y`, `Z` for a normal).
    pub channels: [&'a str; 3],
    /// The image, of the film's size.
    pub film: &'a Film,
}

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
    /// The mean of fixed-point sums ([`GpuAccumPixel`], both backends accumulate them) of a
    /// `width` x `height` image holding the samples `cursor` says.
    pub fn from_fixed_point(
        width: u32,
        height: u32,
        cursor: &SampleCursor,
        sums: &[GpuAccumPixel],
    ) -> Self {
        let counts: Vec<u32> = (0..height).map(|y| cursor.row_samples(y)).collect();
        Self::from_row_sums(width, &counts, sums)
    }

    /// The image of a render's accumulation.
    pub fn from_accumulation(width: u32, height: u32, accumulation: &Accumulation) -> Self {
        Self::from_fixed_point(width, height, &accumulation.cursor, &accumulation.sums)
    }

    /// The mean of fixed-point sums, row by row, where row `y` holds `counts[y]` samples per
    /// pixel (a pixel without samples is black); `spp` is the smallest count.
    pub fn from_row_sums(width: u32, counts: &[u32], sums: &[GpuAccumPixel]) -> Self {
        let pixels = sums
            .iter()
            .enumerate()
            .map(|(i, sum)| {
                let count = counts[i / width as usize];
                let scale = 1.0 / f64::from(count.max(1));
                [0, 1, 2].map(|c| (sum.channel_sum(c) * scale) as f32)
            })
            .collect();
        Self {
            width,
            height: counts.len() as u32,
            spp: counts.iter().copied().min().unwrap_or(0),
            pixels,
        }
    }

    /// The auxiliary images of a render's accumulation, albedo then shading normal (each
    /// pixel the mean of its samples), if it has them.
    pub fn aovs_from_accumulation(
        width: u32,
        height: u32,
        accumulation: &Accumulation,
    ) -> Option<(Self, Self)> {
        let counts: Vec<u32> = (0..height)
            .map(|y| accumulation.cursor.row_samples(y))
            .collect();
        Self::aovs_from_row_sums(width, &counts, &accumulation.aovs)
    }

    /// The auxiliary images, albedo then shading normal, of sums where row `y` holds
    /// `counts[y]` samples per pixel; `None` for no sums.
    pub fn aovs_from_row_sums(
        width: u32,
        counts: &[u32],
        aovs: &[GpuAovPixel],
    ) -> Option<(Self, Self)> {
        if aovs.is_empty() {
            return None;
        }
        let albedo: Vec<GpuAccumPixel> = aovs.iter().map(|a| a.albedo).collect();
        let normal: Vec<GpuAccumPixel> = aovs.iter().map(|a| a.normal).collect();
        let mut normal = Self::from_row_sums(width, counts, &normal);
        // Accumulated as (n + 1) / 2; a pixel without samples has no normal.
        for (i, p) in normal.pixels.iter_mut().enumerate() {
            if counts[i / width as usize] > 0 {
                *p = p.map(|c| 2.0 * c - 1.0);
            }
        }
        Some((Self::from_row_sums(width, counts, &albedo), normal))
    }

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

impl Film {
    /// Reads a linear RGB OpenEXR file (`spp` is unknown and set to 0).
    pub fn read_exr(path: &std::path::Path) -> Result<Self, exr::error::Error> {
        use exr::prelude::*;
        let image = read_first_rgba_layer_from_file(
            path,
            |resolution, _| {
                let (w, h) = (resolution.width(), resolution.height());
                (w, vec![[0.0f32; 3]; w * h])
            },
            |(width, pixels), position, (r, g, b, _a): (f32, f32, f32, f32)| {
                pixels[position.y() * *width + position.x()] = [r, g, b];
            },
        )?;
        let size = image.layer_data.size;
        Ok(Self {
            width: size.width() as u32,
            height: size.height() as u32,
            spp: 0,
            pixels: image.layer_data.channel_data.pixels.1,
        })
    }

    /// The film as an 8-bit RGB PNG in memory, each channel mapped by `encode` (the sRGB
    /// curve for an image, `(n + 1) / 2` for a normal) and clamped to [0, 1].
    pub fn encode_png(&self, encode: impl Fn(f32) -> f32) -> Result<Vec<u8>, image::ImageError> {
        use image::ImageEncoder as _;
        let pixels: Vec<u8> = self
            .pixels
            .iter()
            .flat_map(|p| p.map(|c| (encode(c).clamp(0.0, 1.0) * 255.0 + 0.5) as u8))
            .collect();
        let mut bytes = Vec::new();
        image::codecs::png::PngEncoder::new(&mut bytes).write_image(
            &pixels,
            self.width,
            self.height,
            image::ExtendedColorType::Rgb8,
        )?;
        Ok(bytes)
    }

    /// The film encoded as 32-bit float linear RGB OpenEXR, in memory (written to disk by
    /// the caller, who decides how to replace a file safely).
    pub fn encode_exr(&self) -> Result<Vec<u8>, exr::error::Error> {
        use exr::prelude::*;
        let width = self.width as usize;
        let channels = SpecificChannels::rgb(|position: Vec2<usize>| {
            let [r, g, b] = self.pixels[position.y() * width + position.x()];
            (r, g, b)
        });
        // Chunks in increasing order: compressed in parallel, but written in one order, so
        // that the same image always gives the same bytes (renders are compared by bytes).
        let encoding = Encoding {
            line_order: LineOrder::Increasing,
            ..Encoding::FAST_LOSSLESS
        };
        let image = Image::from_encoded_channels((width, self.height as usize), encoding, channels);
        let mut bytes = Vec::new();
        image
            .write()
            .to_buffered(std::io::Cursor::new(&mut bytes))?;
        Ok(bytes)
    }

    /// The film as an OpenEXR file in memory whose main channels `R`, `G`, `B` are this
    /// film and whose other channels are `layers`' (`albedo.R`, `normal.X`, ...: Blender's
    /// and Cycles' naming), all 32-bit float, one part.
    pub fn encode_exr_layers(&self, layers: &[ExrLayer]) -> Result<Vec<u8>, exr::error::Error> {
        use exr::prelude::*;
        let plane =
            |film: &Film, c: usize| FlatSamples::F32(film.pixels.iter().map(|p| p[c]).collect());
        let mut channels: SmallVec<[AnyChannel<FlatSamples>; 4]> = SmallVec::new();
        for (c, name) in ["R", "G", "B"].into_iter().enumerate() {
            channels.push(AnyChannel::new(name, plane(self, c)));
        }
        for layer in layers {
            assert_eq!(
                (layer.film.width, layer.film.height),
                (self.width, self.height),
                "a layer has the film's size"
            );
            for (c, name) in layer.channels.into_iter().enumerate() {
                let full = format!("{}.{name}", layer.name);
                channels.push(AnyChannel::new(full.as_str(), plane(layer.film, c)));
            }
        }
        let encoding = Encoding {
            line_order: LineOrder::Increasing,
            ..Encoding::FAST_LOSSLESS
        };
        let size = (self.width as usize, self.height as usize);
        let layer = Layer::new(
            size,
            LayerAttributes::default(),
            encoding,
            AnyChannels::sort(channels),
        );
        let mut bytes = Vec::new();
        Image::from_layer(layer)
            .write()
            .to_buffered(std::io::Cursor::new(&mut bytes))?;
        Ok(bytes)
    }

    /// Reads an OpenEXR file's main `R`, `G`, `B` channels and, for each of `wanted` (a
    /// layer's name and channel names), that layer when the file has all its channels.
    pub fn read_exr_layers(
        path: &std::path::Path,
        wanted: &[(&str, [&str; 3])],
    ) -> Result<(Self, Vec<Option<Self>>), exr::error::Error> {
        use exr::prelude::*;
        let image = read_first_flat_layer_from_file(path)?;
        let layer = &image.layer_data;
        let size = layer.size;
        let find = |name: &str| {
            layer
                .channel_data
                .list
                .iter()
                .find(|c| c.name.eq(name))
                .map(|c| &c.sample_data)
        };
        let film = |names: [String; 3]| -> Option<Self> {
            let planes: Vec<&FlatSamples> = names.iter().map(|n| find(n)).collect::<Option<_>>()?;
            let pixels = (0..size.area())
                .map(|i| [0, 1, 2].map(|c| planes[c].value_by_flat_index(i).to_f32()))
                .collect();
            Some(Self {
                width: size.width() as u32,
                height: size.height() as u32,
                spp: 0,
                pixels,
            })
        };
        let main = film(["R", "G", "B"].map(String::from))
            .ok_or_else(|| exr::error::Error::Invalid("it has no R, G and B channels".into()))?;
        let layers = wanted
            .iter()
            .map(|(name, channels)| film(channels.map(|c| format!("{name}.{c}"))))
            .collect();
        Ok((main, layers))
    }

    /// Box-downsamples by an integer `factor` (each output pixel is the mean of a
    /// `factor` x `factor` block; a box-filtered render at the smaller size has this mean).
    pub fn downsample(&self, factor: u32) -> Self {
        let (w, h) = (self.width / factor, self.height / factor);
        let mut pixels = vec![[0.0f32; 3]; (w * h) as usize];
        for y in 0..h {
            for x in 0..w {
                let mut sum = [0.0f64; 3];
                for dy in 0..factor {
                    for dx in 0..factor {
                        let p = self.pixel(x * factor + dx, y * factor + dy);
                        for c in 0..3 {
                            sum[c] += f64::from(p[c]);
                        }
                    }
                }
                let n = f64::from(factor * factor);
                pixels[(y * w + x) as usize] = sum.map(|s| (s / n) as f32);
            }
        }
        Self {
            width: w,
            height: h,
            spp: self.spp,
            pixels,
        }
    }

    /// Relative mean squared error against `reference` of the same size:
    /// mean over pixels and channels of (self - ref)^2 / (ref^2 + 0.01).
    pub fn relmse(&self, reference: &Film) -> f64 {
        assert_eq!(
            (self.width, self.height),
            (reference.width, reference.height)
        );
        let mut sum = 0.0f64;
        for (p, r) in self.pixels.iter().zip(&reference.pixels) {
            for c in 0..3 {
                let (t, r) = (f64::from(p[c]), f64::from(r[c]));
                sum += (t - r) * (t - r) / (r * r + 0.01);
            }
        }
        sum / (3 * self.pixels.len()) as f64
    }
}

#[cfg(test)]
mod tests {
    use super::Film;

    /// The same image encodes to the same bytes (its tiles are compressed in parallel; they
    /// were written in the order they finished, so equal renders compared unequal).
    #[test]
    fn exr_bytes_depend_only_on_the_image() {
        let (width, height) = (600, 400);
        let pixels = (0..width * height)
            .map(|i| {
                let v = ((i * 7919) % 1013) as f32 / 1013.0;
                [v, v * 0.5, 1.0 - v]
            })
            .collect();
        let film = Film {
            width,
            height,
            spp: 1,
            pixels,
        };
        let first = film.encode_exr().unwrap();
        for _ in 0..4 {
            assert!(film.encode_exr().unwrap() == first);
        }
    }
}
