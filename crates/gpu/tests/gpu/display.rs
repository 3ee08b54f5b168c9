//! The display pass (`display.wgsl`) and its CPU twin (`pathlight_cpu::display`, which the
//! viewer runs on the CPU backend) show the same pixels: the same means, the same nearest
//! pixel when scaling, the same tone mappers and sRGB curve, within one 8-bit code.

use pathlight_core::ToneMap;
use pathlight_core::gpu_types::GpuAccumPixel;
use pathlight_cpu::display::{ChannelOrder, CpuDisplay, DisplayImage};
use pathlight_gpu::display::{DisplayPass, DisplaySource};
use rand::{Rng, SeedableRng};
use wgpu::util::DeviceExt;

use crate::common::context;

/// Draws `image` with the display pass into an RGBA8 texture of `size`; returns its bytes.
fn draw_on_gpu(image: &DisplayImage, tonemap: ToneMap, size: (u32, u32)) -> Vec<u8> {
    let ctx = context();
    let device = &ctx.device;
    let format = wgpu::TextureFormat::Rgba8Unorm;
    let pass = DisplayPass::new(device, format).unwrap();
    let pixels = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("sums"),
        contents: bytemuck::cast_slice(image.pixels),
        usage: wgpu::BufferUsages::STORAGE,
    });
    let extent = wgpu::Extent3d {
        width: size.0,
        height: size.1,
        depth_or_array_layers: 1,
    };
    let texture = device.create_texture(&wgpu::TextureDescriptor {
        label: Some("target"),
        size: extent,
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
        view_formats: &[],
    });
    let source = DisplaySource {
        pixels: &pixels,
        width: image.width,
        height: image.height,
        samples: image.samples,
        rows_ahead: image.rows_ahead,
    };
    let view = texture.create_view(&Default::default());
    pass.draw(ctx, source, &view, size, tonemap);
    // Rows of a buffer copy are aligned to 256 bytes.
    let stride = (size.0 * 4).div_ceil(256) * 256;
    let readback = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("readback"),
        size: u64::from(stride * size.1),
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        mapped_at_creation: false,
    });
    let mut encoder = device.create_command_encoder(&Default::default());
    encoder.copy_texture_to_buffer(
        texture.as_image_copy(),
        wgpu::TexelCopyBufferInfo {
            buffer: &readback,
            layout: wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(stride),
                rows_per_image: None,
            },
        },
        extent,
    );
    ctx.queue.submit([encoder.finish()]);
    readback
        .slice(..)
        .map_async(wgpu::MapMode::Read, |r| r.unwrap());
    device.poll(wgpu::PollType::wait_indefinitely()).unwrap();
    let data = readback.slice(..).get_mapped_range().unwrap();
    data.chunks(stride as usize)
        .flat_map(|row| &row[..size.0 as usize * 4])
        .copied()
        .collect()
}

#[test]
fn the_cpu_display_shows_what_the_display_pass_shows() {
    let (width, height) = (24, 10);
    let mut rng = rand::rngs::StdRng::seed_from_u64(7);
    // Sums of 3 or 4 samples spanning black to far over white, with fractions.
    let pixels: Vec<GpuAccumPixel> = (0..width * height)
        .map(|_| {
            let scale = [0.01, 0.3, 1.0, 3.0, 40.0][rng.random_range(0..5)];
            let hi = std::array::from_fn(|_| (rng.random::<f32>() * scale) as u32);
            let lo = std::array::from_fn(|_| rng.random::<u32>());
            GpuAccumPixel { hi, lo }
        })
        .collect();
    let image = DisplayImage {
        pixels: &pixels,
        width,
        height,
        samples: 3,
        rows_ahead: 4,
    };
    let mut display = CpuDisplay::new();
    let mut cpu = Vec::new();
    for tonemap in [ToneMap::Clamp, ToneMap::Aces, ToneMap::Agx] {
        // The window's size, and a larger one (the preview's upscaling) at a ratio that is
        // not whole.
        for size in [(width, height), (60, 27)] {
            let gpu = draw_on_gpu(&image, tonemap, size);
            display.pixels(&image, 0, tonemap, size, ChannelOrder::Rgba, &mut cpu);
            assert_eq!(gpu.len(), cpu.len());
            let worst = gpu
                .iter()
                .zip(&cpu)
                .map(|(g, c)| g.abs_diff(*c))
                .max()
                .unwrap();
            assert!(
                worst <= 1,
                "{tonemap:?} at {size:?}: codes differ by up to {worst}"
            );
        }
    }
}
