//! `pathlight view`: the seed's interactive window. It renders the scene progressively in
//! iterations of frames (one sample per pixel each), waits for a right click between
//! iterations, turns a left-clicked object into a light, and lets the camera orbit, pan and
//! zoom. See README.md for every button and key.

mod camera;
mod iterations;
mod picking;

use std::io::Write as _;
use std::path::PathBuf;
use std::sync::Arc;
use std::time::{Duration, Instant};

use anyhow::{Context as _, anyhow};
use pathlight_core::{GpuScene, Scene};
use pathlight_render::context::describe;
use pathlight_render::display::{DisplayPass, ToneMap};
use pathlight_render::{GpuContext, ProgressiveRenderer};
use winit::application::ApplicationHandler;
use winit::dpi::{PhysicalPosition, PhysicalSize};
use winit::event::{ElementState, KeyEvent, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::keyboard::{Key, ModifiersState, NamedKey};
use winit::window::{Window, WindowId};

use crate::cli::ViewArgs;
use crate::output;
use crate::setup::load_scene;
use camera::Orbit;
use iterations::{Iterations, Phase};
use picking::{LightSwitch, pick};

/// Aimed-for GPU time of one submission on a GPU, so the window never freezes.
const SUBMISSION_TARGET: Duration = Duration::from_millis(20);
/// The same on a CPU adapter (lavapipe), where each submission costs about 20 ms more than
/// its work: bands of 20 ms halved the frame rate, bands of 100 ms cost a fifth.
const SUBMISSION_TARGET_ON_CPU: Duration = Duration::from_millis(100);
/// Longest time spent rendering between two presented images (a submission may overrun it).
const PRESENT_INTERVAL: Duration = Duration::from_millis(33);
/// Interval between title-bar updates.
const TITLE_INTERVAL: Duration = Duration::from_millis(500);
/// Pointer travel (pixels) that turns a press into a drag instead of a click.
const DRAG_THRESHOLD: f64 = 4.0;

/// A line on standard output that never fails (the tests read these lines).
macro_rules! say {
    ($($arg:tt)*) => {{
        let mut out = std::io::stdout();
        let _ = writeln!(out, $($arg)*);
        let _ = out.flush();
    }};
}

/// Whether a display server is reachable, as far as the environment tells (Unix without
/// macOS); elsewhere the window system answers.
fn display_available() -> bool {
    if cfg!(all(unix, not(target_os = "macos"))) {
        ["DISPLAY", "WAYLAND_DISPLAY"]
            .iter()
            .any(|v| std::env::var_os(v).is_some_and(|s| !s.is_empty()))
    } else {
        true
    }
}

/// The error for a machine without a display.
fn no_display() -> anyhow::Error {
    anyhow!(
        "no display: the viewer needs a window ($DISPLAY and $WAYLAND_DISPLAY are unset). \
         Render headless instead: `pathlight render [SCENE] -o image.png`"
    )
}

/// Runs the command.
pub fn run(args: &ViewArgs) -> anyhow::Result<()> {
    if !display_available() {
        return Err(no_display());
    }
    let scene = load_scene(&args.scene)?;
    let event_loop = EventLoop::new().map_err(|err| {
        anyhow!(
            "cannot open a window ({err}). Render headless instead: \
             `pathlight render [SCENE] -o image.png`"
        )
    })?;
    let mut viewer = Viewer::new(scene, args);
    event_loop
        .run_app(&mut viewer)
        .context("the window system failed")?;
    viewer.error.map_or(Ok(()), Err)
}

/// What lives only while the window exists.
struct Gpu {
    window: Arc<Window>,
    surface: wgpu::Surface<'static>,
    config: wgpu::SurfaceConfiguration,
    renderer: ProgressiveRenderer,
    display: DisplayPass,
    adapter: String,
    /// Aimed-for time of one submission on this adapter.
    submission_target: Duration,
}

/// Pointer state for clicks and drags.
#[derive(Debug, Default)]
struct Pointer {
    position: PhysicalPosition<f64>,
    /// Where the left or middle button went down, and whether it has become a drag.
    pressed_at: Option<PhysicalPosition<f64>>,
    dragging: bool,
    left: bool,
    middle: bool,
    modifiers: ModifiersState,
}

/// Rays per second over the last title interval.
#[derive(Debug)]
struct RayRate {
    since: Instant,
    rays_at_start: u64,
    per_second: f64,
}

/// The viewer's state.
struct Viewer {
    scene: Scene,
    gpu_scene: GpuScene,
    orbit: Orbit,
    lights: LightSwitch,
    iterations: Iterations,
    tonemap: ToneMap,
    paused: bool,
    adapter_name: Option<String>,
    save_dir: PathBuf,
    pointer: Pointer,
    ray_rate: RayRate,
    gpu: Option<Gpu>,
    error: Option<anyhow::Error>,
}

impl Viewer {
    fn new(scene: Scene, args: &ViewArgs) -> Self {
        Self {
            gpu_scene: GpuScene::build(&scene),
            orbit: Orbit::from_camera(&scene.camera),
            lights: LightSwitch::new(&scene, args.light_strength),
            iterations: Iterations::new(args.frames_per_iter, args.iters),
            scene,
            tonemap: ToneMap::default(),
            paused: false,
            adapter_name: args.adapter.clone(),
            save_dir: args.save_dir.clone(),
            pointer: Pointer::default(),
            ray_rate: RayRate {
                since: Instant::now(),
                rays_at_start: 0,
                per_second: 0.0,
            },
            gpu: None,
            error: None,
        }
    }

    /// Ends the event loop with `err` as the command's error.
    fn fail(&mut self, event_loop: &ActiveEventLoop, err: anyhow::Error) {
        self.error = Some(err);
        event_loop.exit();
    }

    fn open_window(&mut self, event_loop: &ActiveEventLoop) -> anyhow::Result<Gpu> {
        let camera = &self.scene.camera;
        let attributes = Window::default_attributes()
            .with_title("pathlight")
            .with_inner_size(PhysicalSize::new(camera.width, camera.height));
        let window = Arc::new(event_loop.create_window(attributes)?);
        let (ctx, surface) = GpuContext::for_window(self.adapter_name.as_deref(), window.clone())?;
        let adapter = describe(&ctx.adapter_info);
        say!("adapter: {adapter}");
        let caps = surface.get_capabilities(&ctx.adapter);
        let size = window.inner_size();
        let config = surface_config(&caps, size)?;
        surface.configure(&ctx.device, &config);
        // The window may open at another size than asked (a tiling window manager).
        self.resize_camera(size);
        let renderer = ProgressiveRenderer::new(&ctx, &self.scene, &self.gpu_scene)?;
        let display = DisplayPass::new(&ctx.device, config.format)?;
        Ok(Gpu {
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

    /// Sets the image size to the window's.
    fn resize_camera(&mut self, size: PhysicalSize<u32>) {
        self.scene.camera.width = size.width.max(1);
        self.scene.camera.height = size.height.max(1);
    }

    /// Uploads the changed scene (camera, size or lights) and starts the image over.
    fn restart(&mut self, rebuild: bool) -> anyhow::Result<()> {
        self.orbit.apply(&mut self.scene.camera);
        if rebuild {
            self.gpu_scene = GpuScene::build(&self.scene);
        }
        if let Some(gpu) = &mut self.gpu {
            gpu.renderer.set_scene(&self.scene, &self.gpu_scene)?;
            gpu.window.request_redraw();
        }
        self.iterations.restart();
        self.ray_rate.rays_at_start = 0;
        Ok(())
    }

    fn wants_frames(&self) -> bool {
        !self.paused && self.iterations.phase() == Phase::Running
    }

    /// Renders for up to [`PRESENT_INTERVAL`], then shows the image.
    fn redraw(&mut self) -> anyhow::Result<()> {
        let rendering = self.wants_frames();
        let Some(gpu) = &mut self.gpu else {
            return Ok(());
        };
        if rendering {
            let started = Instant::now();
            while started.elapsed() < PRESENT_INTERVAL {
                let piece = Instant::now();
                let frame_done = gpu.renderer.step_frame(gpu.submission_target)?;
                self.iterations.add_time(piece.elapsed());
                if !frame_done {
                    continue;
                }
                if let Some(finished) = self.iterations.frame_done() {
                    say!(
                        "iter {} finished, {:.2} fps",
                        finished.iteration,
                        finished.fps
                    );
                    match self.iterations.phase() {
                        Phase::Waiting => {
                            say!("right-click for iteration {}", finished.iteration + 1)
                        }
                        _ => say!("all {} iterations finished", finished.iteration),
                    }
                    break;
                }
            }
        }
        let frame = match gpu.surface.get_current_texture() {
            wgpu::CurrentSurfaceTexture::Success(frame)
            | wgpu::CurrentSurfaceTexture::Suboptimal(frame) => frame,
            wgpu::CurrentSurfaceTexture::Outdated | wgpu::CurrentSurfaceTexture::Lost => {
                gpu.surface
                    .configure(&gpu.renderer.context().device, &gpu.config);
                gpu.window.request_redraw();
                return Ok(());
            }
            other => {
                // Timeout or occluded: try again on the next redraw.
                log::debug!("no surface texture: {other:?}");
                return Ok(());
            }
        };
        let view = frame.texture.create_view(&Default::default());
        gpu.display.draw(
            &gpu.renderer,
            &view,
            (gpu.config.width, gpu.config.height),
            self.tonemap,
        );
        gpu.renderer.context().queue.present(frame);
        self.update_title()?;
        Ok(())
    }

    fn update_title(&mut self) -> anyhow::Result<()> {
        let Some(gpu) = &self.gpu else {
            return Ok(());
        };
        let rate = &mut self.ray_rate;
        let elapsed = rate.since.elapsed();
        if elapsed >= TITLE_INTERVAL {
            let rays = gpu.renderer.rays_traced()?;
            rate.per_second =
                rays.saturating_sub(rate.rays_at_start) as f64 / elapsed.as_secs_f64();
            rate.since = Instant::now();
            rate.rays_at_start = rays;
        }
        let (iteration, iters) = self.iterations.position();
        let state = match (self.paused, self.iterations.phase()) {
            (true, _) => " | paused (Space)".to_string(),
            (false, Phase::Waiting) => format!(" | right-click for iteration {}", iteration + 1),
            (false, Phase::Done) => " | done".to_string(),
            (false, Phase::Running) => String::new(),
        };
        let fps = self.iterations.fps();
        gpu.window.set_title(&format!(
            "pathlight | {} spp | iter {iteration}/{iters} | {} fps | {:.1} M rays/s | {} | {}{state}",
            gpu.renderer.samples_done(),
            if fps < 10.0 { format!("{fps:.2}") } else { format!("{fps:.0}") },
            rate.per_second / 1e6,
            gpu.adapter,
            self.tonemap.name(),
        ));
        Ok(())
    }

    /// Saves the current image as PNG and EXR under the next free name.
    fn save(&self) -> anyhow::Result<()> {
        let Some(gpu) = &self.gpu else {
            return Ok(());
        };
        let film = gpu.renderer.read_film()?;
        if film.spp == 0 {
            say!("nothing to save yet: no frame finished");
            return Ok(());
        }
        let stem = (1..)
            .map(|n| self.save_dir.join(format!("pathlight-view-{n:03}")))
            .find(|stem| {
                !stem.with_extension("png").exists() && !stem.with_extension("exr").exists()
            })
            .expect("some name is free");
        let (png, exr) = (stem.with_extension("png"), stem.with_extension("exr"));
        output::write(&film, &png)?;
        output::write(&film, &exr)?;
        say!(
            "saved {} and {} ({} spp)",
            png.display(),
            exr.display(),
            film.spp
        );
        Ok(())
    }

    /// Left click at the pointer: toggles the object there between a light and its material.
    fn click(&mut self) -> anyhow::Result<()> {
        let Some(gpu) = &self.gpu else {
            return Ok(());
        };
        let size = gpu.window.inner_size();
        let (width, height) = (self.scene.camera.width, self.scene.camera.height);
        let x = self.pointer.position.x as f32 * width as f32 / size.width.max(1) as f32;
        let y = self.pointer.position.y as f32 * height as f32 / size.height.max(1) as f32;
        let Some(object) = pick(&self.scene, &self.gpu_scene, x, y) else {
            say!("picked nothing");
            return Ok(());
        };
        let on = self.lights.toggle(&mut self.scene, object);
        say!(
            "picked {}: light {}",
            self.scene.objects[object].name,
            if on { "on" } else { "off" }
        );
        self.restart(true)
    }

    fn key(&mut self, event_loop: &ActiveEventLoop, event: &KeyEvent) -> anyhow::Result<()> {
        if event.state != ElementState::Pressed || event.repeat {
            return Ok(());
        }
        match &event.logical_key {
            Key::Named(NamedKey::Escape) => event_loop.exit(),
            Key::Named(NamedKey::Space) => {
                self.paused = !self.paused;
                say!("{}", if self.paused { "paused" } else { "resumed" });
            }
            Key::Character(c) => match c.to_lowercase().as_str() {
                "s" => self.save()?,
                "r" => {
                    say!("restarted");
                    self.restart(false)?;
                }
                "t" => {
                    self.tonemap = self.tonemap.next();
                    say!("tone mapping: {}", self.tonemap.name());
                }
                _ => {}
            },
            _ => {}
        }
        if let Some(gpu) = &self.gpu {
            gpu.window.request_redraw();
        }
        Ok(())
    }

    fn pointer_moved(&mut self, position: PhysicalPosition<f64>) -> anyhow::Result<()> {
        let (dx, dy) = (
            position.x - self.pointer.position.x,
            position.y - self.pointer.position.y,
        );
        self.pointer.position = position;
        let Some(start) = self.pointer.pressed_at else {
            return Ok(());
        };
        if !self.pointer.dragging {
            let travel = (position.x - start.x).hypot(position.y - start.y);
            if travel < DRAG_THRESHOLD {
                return Ok(());
            }
            self.pointer.dragging = true;
        }
        let pan = self.pointer.middle || self.pointer.modifiers.shift_key();
        if pan {
            let height = self.gpu.as_ref().map_or(1, |g| g.config.height) as f32;
            self.orbit
                .pan(dx as f32, dy as f32, height, self.scene.camera.fov_y_deg);
        } else if self.pointer.left {
            self.orbit.orbit(dx as f32, dy as f32);
        }
        self.restart(false)
    }

    fn button(&mut self, state: ElementState, button: MouseButton) -> anyhow::Result<()> {
        let pressed = state == ElementState::Pressed;
        match button {
            MouseButton::Left | MouseButton::Middle => {
                if button == MouseButton::Left {
                    self.pointer.left = pressed;
                } else {
                    self.pointer.middle = pressed;
                }
                if pressed {
                    self.pointer.pressed_at = Some(self.pointer.position);
                    self.pointer.dragging = false;
                } else {
                    let was_click = !self.pointer.dragging && self.pointer.pressed_at.is_some();
                    self.pointer.pressed_at = None;
                    self.pointer.dragging = false;
                    if was_click && button == MouseButton::Left {
                        self.click()?;
                    }
                }
            }
            MouseButton::Right if pressed && self.iterations.start_next() => {
                let (iteration, iters) = self.iterations.position();
                say!("iter {iteration} of {iters} started");
                if let Some(gpu) = &self.gpu {
                    gpu.window.request_redraw();
                }
            }
            _ => {}
        }
        Ok(())
    }

    fn window_event(
        &mut self,
        event_loop: &ActiveEventLoop,
        event: WindowEvent,
    ) -> anyhow::Result<()> {
        match event {
            WindowEvent::CloseRequested => event_loop.exit(),
            WindowEvent::Resized(size) if size.width > 0 && size.height > 0 => {
                let same = (size.width, size.height)
                    == (self.scene.camera.width, self.scene.camera.height);
                if let Some(gpu) = &mut self.gpu {
                    gpu.config.width = size.width;
                    gpu.config.height = size.height;
                    gpu.surface
                        .configure(&gpu.renderer.context().device, &gpu.config);
                }
                if !same {
                    self.resize_camera(size);
                    self.restart(false)?;
                }
            }
            WindowEvent::RedrawRequested => self.redraw()?,
            WindowEvent::KeyboardInput { event, .. } => self.key(event_loop, &event)?,
            WindowEvent::ModifiersChanged(modifiers) => self.pointer.modifiers = modifiers.state(),
            WindowEvent::CursorMoved { position, .. } => self.pointer_moved(position)?,
            WindowEvent::MouseInput { state, button, .. } => self.button(state, button)?,
            WindowEvent::MouseWheel { delta, .. } => {
                let steps = match delta {
                    MouseScrollDelta::LineDelta(_, y) => y,
                    MouseScrollDelta::PixelDelta(p) => p.y as f32 / 40.0,
                };
                self.orbit.zoom(steps);
                self.restart(false)?;
            }
            _ => {}
        }
        Ok(())
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

impl ApplicationHandler for Viewer {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.gpu.is_some() {
            return;
        }
        match self.open_window(event_loop) {
            Ok(gpu) => {
                gpu.window.request_redraw();
                self.gpu = Some(gpu);
            }
            Err(err) => self.fail(event_loop, err),
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _id: WindowId, event: WindowEvent) {
        if let Err(err) = Viewer::window_event(self, event_loop, event) {
            self.fail(event_loop, err);
        }
    }

    fn about_to_wait(&mut self, event_loop: &ActiveEventLoop) {
        event_loop.set_control_flow(ControlFlow::Wait);
        if self.wants_frames()
            && let Some(gpu) = &self.gpu
        {
            gpu.window.request_redraw();
        }
    }
}
