//! The viewer's window: its surface on the GPU, the renderer on the same device, and
//! presenting the image through the display pass.

use std::sync::Arc;
use std::time::Duration;

use anyhow::anyhow;
use pathlight_core::{PreparedScene, Renderer};
use pathlight_render::context::describe;
use pathlight_render::display::{DisplayPass, ToneMap};
use pathlight_render::{Accel, GpuContext, GpuRenderer};
use pathlight_scene::Scene;
use winit::dpi::PhysicalSize;
use winit::event_loop::ActiveEventLoop;
use winit::window::Window;

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
    /// The renderer, on the device that presents to the window.
    pub renderer: GpuRenderer,
    display: DisplayPass,
    /// The adapter's name, for the title bar.
    pub adapter: String,
    /// Aimed-for time of one submission on this adapter.
    pub submission_target: Duration,
}

impl ViewerWindow {
    /// Opens a window of the scene's image size on the preferred adapter (or the one named
    /// `adapter`) that can present to it, and a renderer of `prepared` there. The scene's
    /// image size becomes the window's (it may open at another size than asked).
    pub fn open(
        event_loop: &ActiveEventLoop,
        adapter: Option<&str>,
        scene: &mut Scene,
        prepared: &PreparedScene,
    ) -> anyhow::Result<Self> {
        let attributes = Window::default_attributes()
            .with_title("pathlight")
            .with_inner_size(PhysicalSize::new(scene.camera.width, scene.camera.height));
        let window = Arc::new(event_loop.create_window(attributes)?);
        let (ctx, surface) = GpuContext::for_window(adapter, window.clone())?;
        say!("adapter: {}", describe(&ctx.adapter_info));
        let caps = surface.get_capabilities(&ctx.adapter);
        let size = window.inner_size();
        let config = surface_config(&caps, size)?;
        surface.configure(&ctx.device, &config);
        scene.camera.width = size.width.max(1);
        scene.camera.height = size.height.max(1);
        let renderer =
            GpuRenderer::new(&ctx, prepared, &scene.camera, &scene.settings, Accel::Bvh)?;
        let display = DisplayPass::new(&ctx.device, config.format)?;
        Ok(Self {
            window,
            surface,
            config,
            renderer,
            display,
            adapter: ctx.adapter_info.name.clone(),
            submission_target: match ctx.adapter_info.device_type {
                wgpu::DeviceType::Cpu => SUBMISSION_TARGET_ON_CPU,
                _ => SUBMISSION_TARGET,
            },
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
        self.surface
            .configure(&self.renderer.context().device, &self.config);
    }

    /// Shows the renderer's current image through `tonemap`. A lost or outdated surface is
    /// configured again and the window asked to redraw.
    pub fn present(&mut self, tonemap: ToneMap) {
        let frame = match self.surface.get_current_texture() {
            wgpu::CurrentSurfaceTexture::Success(frame)
            | wgpu::CurrentSurfaceTexture::Suboptimal(frame) => frame,
            wgpu::CurrentSurfaceTexture::Outdated | wgpu::CurrentSurfaceTexture::Lost => {
                self.surface
                    .configure(&self.renderer.context().device, &self.config);
                self.window.request_redraw();
                return;
            }
            other => {
                // Timeout or occluded: try again on the next redraw.
                log::debug!("no surface texture: {other:?}");
                return;
            }
        };
        let view = frame.texture.create_view(&Default::default());
        self.display.draw(
            &self.renderer,
            &view,
            (self.config.width, self.config.height),
            tonemap,
        );
        self.renderer.context().queue.present(frame);
    }

    /// The renderer as the backend interface.
    pub fn renderer(&mut self) -> &mut dyn Renderer {
        &mut self.renderer
    }
}

/// The surface configuration: a non-sRGB 8-bit format when there is one (the display
/// pass applies the sRGB curve itself), and a present mode that does not hold rendering
/// back to the display's refresh when one exists.
fn surface_config(
    caps: &wgpu::SurfaceCapabilities,
    size: PhysicalSize<u32>,
) -> anyhow::Result<wgpu::SurfaceConfiguration> {
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
    Ok(wgpu::SurfaceConfiguration {
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
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
    })
}
