//! The viewer's window: its surface on an adapter that can present to it, the renderer on
//! the backend chosen (on the same device, or the CPU backend on its own thread), and
//! presenting the image through the display pass.

use std::sync::Arc;
use std::time::Duration;

use anyhow::anyhow;
use pathlight_core::{PreparedScene, Renderer, ToneMap};
use pathlight_cpu::display::ChannelOrder;
use pathlight_gpu::context::{auto_choice, describe, is_hardware};
use pathlight_gpu::display::DisplayPass;
use pathlight_gpu::{Accel, GpuContext, GpuRenderer};
use pathlight_scene::Scene;
use winit::dpi::PhysicalSize;
use winit::event_loop::{ActiveEventLoop, EventLoopProxy};
use winit::window::Window;

use crate::backend::{cpu_renderer, explain};
use crate::cli::{Backend, DeviceArgs};
use crate::view::FrameReady;
use crate::view::cpu_frames::CpuFrames;
use crate::view::denoised::Denoised;
use crate::view::frames::{Frames, GpuFrames, Target};

/// Aimed-for GPU time of one submission on a GPU, so the window never freezes.
const SUBMISSION_TARGET: Duration = Duration::from_millis(20);
/// The same on a CPU adapter (lavapipe), where each submission costs about 20 ms more than
/// its work: bands of 20 ms halved the frame rate, bands of 100 ms cost a fifth.
const SUBMISSION_TARGET_ON_CPU: Duration = Duration::from_millis(100);

/// What lives only while the window exists.
pub struct ViewerWindow {
    /// The window.
    pub window: Arc<Window>,
    surface: wgpu::Surface<'static>,
    config: wgpu::SurfaceConfiguration,
    /// The device that presents.
    ctx: GpuContext,
    /// The renderer, on the backend chosen.
    pub frames: Box<dyn Frames>,
    display: DisplayPass,
    /// The byte order of the surface's 8-bit pixels, when the CPU may copy them into it.
    direct: Option<ChannelOrder>,
}

impl ViewerWindow {
    /// Opens a window of the scene's image size on the preferred adapter (or the one named
    /// by `device`) that can present to it, and a renderer of `prepared` on the backend
    /// `device` asks for; `proxy` wakes the event loop when the CPU backend has rendered.
    /// The scene's image size becomes the window's (it may open at another size than
    /// asked).
    pub fn open(
        event_loop: &ActiveEventLoop,
        device: &DeviceArgs,
        proxy: EventLoopProxy<FrameReady>,
        scene: &mut Scene,
        prepared: &PreparedScene,
    ) -> anyhow::Result<Self> {
        let attributes = Window::default_attributes()
            .with_title("pathlight")
            .with_inner_size(PhysicalSize::new(scene.camera.width, scene.camera.height));
        let window = Arc::new(event_loop.create_window(attributes)?);
        let (ctx, surface) = GpuContext::for_window(device.adapter.as_deref(), window.clone())?;
        say!("adapter: {}", describe(&ctx.adapter_info));
        let caps = surface.get_capabilities(&ctx.adapter);
        let size = window.inner_size();
        let (config, direct) = surface_config(&caps, size)?;
        surface.configure(&ctx.device, &config);
        scene.camera.width = size.width.max(1);
        scene.camera.height = size.height.max(1);
        let info = &ctx.adapter_info;
        let on_gpu = match device.backend {
            Backend::Gpu => true,
            Backend::Cpu => false,
            Backend::Auto => device.adapter.is_some() || is_hardware(info),
        };
        if device.backend == Backend::Auto && device.adapter.is_none() {
            let adapters = [info.clone()];
            say!("{}", explain(auto_choice(&adapters), &adapters));
        }
        let frames: Box<dyn Frames> = if on_gpu {
            let renderer =
                GpuRenderer::new(&ctx, prepared, &scene.camera, &scene.settings, Accel::Bvh)?;
            let target = match info.device_type {
                wgpu::DeviceType::Cpu => SUBMISSION_TARGET_ON_CPU,
                _ => SUBMISSION_TARGET,
            };
            Box::new(GpuFrames::new(renderer, target))
        } else {
            let renderer = cpu_renderer(scene, prepared)?;
            say!(
                "backend: {}, presenting on {}",
                renderer.device(),
                info.name
            );
            let notify = move || {
                // The event loop has ended when this fails: nothing to wake.
                let _ = proxy.send_event(FrameReady);
            };
            Box::new(CpuFrames::start(renderer, notify)?)
        };
        let display = DisplayPass::new(&ctx.device, config.format)?;
        Ok(Self {
            window,
            surface,
            config,
            ctx,
            frames,
            display,
            direct,
        })
    }

    /// The surface's height in pixels.
    pub fn height(&self) -> u32 {
        self.config.height
    }

    /// Resizes the surface to the window's new size.
    pub fn resize(&mut self, size: PhysicalSize<u32>) {
        self.config.width = size.width;
        self.config.height = size.height;
        self.surface.configure(&self.ctx.device, &self.config);
    }

    /// Shows the renderer's current image through `tonemap`, or `denoised`'s image in its
    /// place. A lost or outdated surface is configured again and the window asked to redraw.
    pub fn present(&mut self, tonemap: ToneMap, denoised: Option<&mut Denoised>) {
        let frame = match self.surface.get_current_texture() {
            wgpu::CurrentSurfaceTexture::Success(frame)
            | wgpu::CurrentSurfaceTexture::Suboptimal(frame) => frame,
            wgpu::CurrentSurfaceTexture::Outdated | wgpu::CurrentSurfaceTexture::Lost => {
                self.surface.configure(&self.ctx.device, &self.config);
                self.window.request_redraw();
                return;
            }
            other => {
                // Timeout or occluded: try again on the next redraw.
                log::debug!("no surface texture: {other:?}");
                return;
            }
        };
        let target = Target {
            ctx: &self.ctx,
            display: &self.display,
            texture: &frame.texture,
            size: (self.config.width, self.config.height),
            direct: self.direct,
            tonemap,
        };
        match denoised {
            Some(denoised) => denoised.draw(&target),
            None => self.frames.draw(&target),
        }
        self.ctx.queue.present(frame);
    }
}

/// The surface configuration: a non-sRGB 8-bit format when there is one (the display
/// pass applies the sRGB curve itself), copies into it allowed where they are (the CPU
/// backend's pixels), and a present mode that does not hold rendering back to the
/// display's refresh when one exists. Returns the byte order of copied pixels, when they
/// can be copied.
fn surface_config(
    caps: &wgpu::SurfaceCapabilities,
    size: PhysicalSize<u32>,
) -> anyhow::Result<(wgpu::SurfaceConfiguration, Option<ChannelOrder>)> {
    let format = caps
        .formats
        .iter()
        .copied()
        .find(|f| {
            matches!(
                f,
                wgpu::TextureFormat::Bgra8Unorm | wgpu::TextureFormat::Rgba8Unorm
            )
        })
        .or_else(|| caps.formats.first().copied())
        .ok_or_else(|| anyhow!("the window's surface offers no texture format"))?;
    let present_mode = [wgpu::PresentMode::Mailbox, wgpu::PresentMode::Immediate]
        .into_iter()
        .find(|m| caps.present_modes.contains(m))
        .unwrap_or(wgpu::PresentMode::Fifo);
    // The CPU writes sRGB-encoded bytes: right for a UNORM format, whose bytes the display
    // shows as they are, and for an sRGB one, whose bytes are sRGB-encoded.
    let order = match format.remove_srgb_suffix() {
        wgpu::TextureFormat::Rgba8Unorm => Some(ChannelOrder::Rgba),
        wgpu::TextureFormat::Bgra8Unorm => Some(ChannelOrder::Bgra),
        _ => None,
    };
    let copies = caps.usages.contains(wgpu::TextureUsages::COPY_DST);
    let direct = order.filter(|_| copies);
    let usage = if copies {
        wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_DST
    } else {
        wgpu::TextureUsages::RENDER_ATTACHMENT
    };
    let config = wgpu::SurfaceConfiguration {
        usage,
        format,
        width: size.width.max(1),
        height: size.height.max(1),
        present_mode,
        desired_maximum_frame_latency: 2,
        alpha_mode: caps
            .alpha_modes
            .first()
            .copied()
            .unwrap_or(wgpu::CompositeAlphaMode::Auto),
        view_formats: vec![],
        color_space: wgpu::SurfaceColorSpace::Auto,
    };
    Ok((config, direct))
}
