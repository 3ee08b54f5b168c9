//! `pathlight view`: the seed's interactive window. It renders the scene progressively in
//! iterations of frames (one sample per pixel each), waits for a right click between
//! iterations, turns a left-clicked object into a light, and lets the camera orbit, pan and
//! zoom. See README.md for every button and key.
//!
//! The window ([`window`]) turns events into actions ([`input`]); the viewer applies them
//! through the backend interface ([`frames`]): a camera move or a resize sets only the
//! camera, at preview size while it keeps moving ([`preview`]), a light toggle only the
//! materials. The GPU backend renders in the event loop; the CPU backend on a thread of its
//! own ([`cpu_frames`]), which wakes the loop with [`FrameReady`].

/// A line on standard output that never fails (the tests read these lines).
macro_rules! say {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let mut out = std::io::stdout();
        let _ = writeln!(out, $($arg)*);
        let _ = out.flush();
    }};
}

mod camera;
mod cpu_frames;
mod denoised;
mod frames;
mod input;
mod iterations;
mod picking;
mod preview;
mod title;
mod window;

use std::path::PathBuf;
use std::time::{Duration, Instant};

use anyhow::{Context as _, anyhow};
use pathlight_core::{PreparedScene, ToneMap};
use pathlight_scene::{Camera, Scene};
use winit::application::ApplicationHandler;
use winit::dpi::{PhysicalPosition, PhysicalSize};
use winit::event::WindowEvent;
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop, EventLoopProxy};
use winit::window::WindowId;

use crate::backend::load_scene;
use crate::cli::{DeviceArgs, ViewArgs};
use crate::output;
use camera::{Orbit, next_aperture};
use denoised::{Denoised, Moment};
use input::{Action, Pointer, key_action, wheel_action};
use iterations::{Iterations, Phase};
use picking::{LightSwitch, Picked, pick};
use preview::Preview;
use title::{RayRate, Title};
use window::ViewerWindow;

/// Longest time spent rendering between two presented images (a submission may overrun it).
const PRESENT_INTERVAL: Duration = Duration::from_millis(33);

/// The event the CPU backend's thread sends when it has rendered a band of rows.
#[derive(Debug, Clone, Copy)]
pub struct FrameReady;

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
    let event_loop = EventLoop::with_user_event().build().map_err(|err| {
        anyhow!(
            "cannot open a window ({err}). Render headless instead: \
             `pathlight render [SCENE] -o image.png`"
        )
    })?;
    let mut viewer = Viewer::new(scene, args, event_loop.create_proxy())?;
    event_loop
        .run_app(&mut viewer)
        .context("the window system failed")?;
    viewer.error.map_or(Ok(()), Err)
}

/// The viewer's state.
struct Viewer {
    /// The scene as loaded, with the camera and the lights as the user changed them.
    scene: Scene,
    /// The scene prepared once; its shading follows the light toggles.
    prepared: PreparedScene,
    orbit: Orbit,
    lights: LightSwitch,
    iterations: Iterations,
    tonemap: ToneMap,
    paused: bool,
    /// Previews while the camera moves.
    preview: Preview,
    /// Size of the frames the renderer renders now (the preview's while moving).
    rendering: (u32, u32),
    device: DeviceArgs,
    proxy: EventLoopProxy<FrameReady>,
    save_dir: PathBuf,
    pointer: Pointer,
    rays: RayRate,
    /// The denoised view (`D`).
    denoised: Denoised,
    /// Restarts of the image so far (a denoised image belongs to one).
    epoch: u64,
    window: Option<ViewerWindow>,
    error: Option<anyhow::Error>,
}

impl Viewer {
    fn new(
        mut scene: Scene,
        args: &ViewArgs,
        proxy: EventLoopProxy<FrameReady>,
    ) -> anyhow::Result<Self> {
        // With OIDN the renderer also accumulates the albedo and normal that guide it.
        let denoised = Denoised::new(pathlight_denoise::Denoiser::load());
        scene.settings.aovs = denoised.available();
        Ok(Self {
            preview: Preview::new(),
            rendering: (scene.camera.width, scene.camera.height),
            prepared: PreparedScene::new(&scene)?,
            orbit: Orbit::from_camera(&scene.camera),
            lights: LightSwitch::new(&scene, args.light_strength),
            iterations: Iterations::new(args.frames_per_iter, args.iters),
            scene,
            tonemap: ToneMap::default(),
            paused: false,
            device: args.device.clone(),
            proxy,
            save_dir: args.save_dir.clone(),
            pointer: Pointer::default(),
            rays: RayRate::new(),
            denoised,
            epoch: 0,
            window: None,
            error: None,
        })
    }

    /// Ends the event loop with `err` as the command's error.
    fn fail(&mut self, event_loop: &ActiveEventLoop, err: anyhow::Error) {
        self.error = Some(err);
        event_loop.exit();
    }

    /// The image starts over at iteration 1.
    fn restarted(&mut self) {
        self.iterations.restart();
        self.rays.restart();
        self.epoch += 1;
        if let Some(window) = &self.window {
            window.window.request_redraw();
        }
    }

    /// The camera moved (orbit, pan, zoom) or the window was resized: the renderer renders
    /// previews of the camera as the orbit and the window size have it now.
    fn camera_changed(&mut self) -> anyhow::Result<()> {
        self.orbit.apply(&mut self.scene.camera);
        let camera = self.preview.moved(Instant::now(), &self.scene.camera);
        self.set_camera(&camera, true)
    }

    /// Gives the renderer `camera` (a preview's or not) and starts the image over.
    fn set_camera(&mut self, camera: &Camera, preview: bool) -> anyhow::Result<()> {
        if let Some(window) = &mut self.window {
            window.frames.set_camera(camera, preview)?;
        }
        self.rendering = (camera.width, camera.height);
        self.restarted();
        Ok(())
    }

    /// When the pointer has rested, reports the previews and starts accumulating at full
    /// size.
    fn settle(&mut self, now: Instant) -> anyhow::Result<()> {
        if let Some(run) = self.preview.rested(now) {
            say!(
                "preview: {} frames at {}x{}, {:.1} fps",
                run.frames,
                run.width,
                run.height,
                run.fps
            );
            self.set_camera(&self.scene.camera.clone(), false)?;
        }
        Ok(())
    }

    fn wants_frames(&self) -> bool {
        !self.paused && (self.preview.is_moving() || self.iterations.phase() == Phase::Running)
    }

    /// Frames the renderer should render next: as many as the iteration lacks, or previews
    /// until the pointer rests.
    fn frames_wanted(&self) -> u32 {
        match (self.paused, self.preview.is_moving()) {
            (true, _) => 0,
            (false, true) => u32::MAX,
            (false, false) => self.iterations.frames_left(),
        }
    }

    /// Renders for up to [`PRESENT_INTERVAL`] (or collects what the CPU backend's thread
    /// rendered), counts the frames finished, then shows the image.
    fn redraw(&mut self) -> anyhow::Result<()> {
        let now = Instant::now();
        self.settle(now)?;
        let wanted = self.frames_wanted();
        let Some(window) = &mut self.window else {
            return Ok(());
        };
        let rendered = window.frames.render(wanted, PRESENT_INTERVAL)?;
        let pixels = u64::from(self.rendering.0) * u64::from(self.rendering.1);
        let moving = self.preview.is_moving();
        self.preview
            .timed(rendered.frames, rendered.time, pixels, Instant::now());
        let mut iteration_ended = false;
        if !moving {
            self.iterations.add_time(rendered.time);
            for _ in 0..rendered.frames {
                let Some(finished) = self.iterations.frame_done() else {
                    continue;
                };
                iteration_ended = true;
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
            }
        }
        if let Some(line) = self.denoised.collect() {
            say!("{line}");
        }
        let samples = window.frames.samples_done();
        let moment = match (
            iteration_ended,
            self.paused || self.iterations.phase() != Phase::Running,
        ) {
            (true, _) => Moment::IterationEnded,
            (false, true) => Moment::Idle,
            (false, false) => Moment::Rendering,
        };
        if !moving && self.denoised.due(self.epoch, samples, moment) {
            let proxy = self.proxy.clone();
            self.denoised.start(
                window.frames.accumulation()?,
                self.rendering,
                self.epoch,
                move || {
                    let _ = proxy.send_event(FrameReady);
                },
            );
        }
        let showing = self.denoised.showing(self.epoch);
        window.present(self.tonemap, showing.then_some(&mut self.denoised));
        let frames = &window.frames;
        self.rays.update(|| frames.rays_traced())?;
        let title = Title {
            spp: frames.samples_done(),
            iterations: &self.iterations,
            paused: self.paused,
            moving,
            rays: &self.rays,
            device: &frames.device(),
            tonemap: self.tonemap,
            shown: &match (showing, self.denoised.is_on()) {
                (true, _) => "denoised".to_string(),
                (false, true) => "raw (denoising)".to_string(),
                (false, false) => "raw".to_string(),
            },
        }
        .to_string();
        window.window.set_title(&title);
        Ok(())
    }

    /// Saves the current image as PNG and EXR under the next free name.
    fn save(&mut self) -> anyhow::Result<()> {
        let Some(window) = &mut self.window else {
            return Ok(());
        };
        let film = window.frames.film()?;
        if film.spp == 0 {
            say!("nothing to save yet: no frame finished");
            return Ok(());
        }
        // What is shown: the denoised image when the view shows one.
        let (film, what) = match self.denoised.shown_film(self.epoch) {
            Some(denoised) => (denoised.clone(), ", denoised"),
            None => (film, ""),
        };
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
            "saved {} and {} ({} spp{what})",
            png.display(),
            exr.display(),
            film.spp
        );
        Ok(())
    }

    /// The surface under window point `at` (the window's pixels scaled to the image's);
    /// nothing before the window opens.
    fn pick_at(&self, at: PhysicalPosition<f64>) -> Option<Picked> {
        let size = self.window.as_ref()?.window.inner_size();
        let (width, height) = (self.scene.camera.width, self.scene.camera.height);
        let x = at.x as f32 * width as f32 / size.width.max(1) as f32;
        let y = at.y as f32 * height as f32 / size.height.max(1) as f32;
        pick(&self.scene, &self.prepared, x, y)
    }

    /// A left click at window point `at`: toggles the object there between a light and
    /// its material, and gives the renderer the new materials.
    fn click(&mut self, at: PhysicalPosition<f64>) -> anyhow::Result<()> {
        let Some(picked) = self.pick_at(at) else {
            say!("picked nothing");
            return Ok(());
        };
        let object = picked.object;
        let on = self.lights.toggle(&mut self.scene, object);
        say!(
            "picked {}: light {}",
            self.scene.objects[object].name,
            if on { "on" } else { "off" }
        );
        self.prepared.shading = self.prepared.shading_of(&self.scene);
        if let Some(window) = &mut self.window {
            window.frames.set_materials(&self.prepared.shading)?;
        }
        self.restarted();
        Ok(())
    }

    /// Focuses the lens on the surface under window point `at`.
    fn focus(&mut self, at: PhysicalPosition<f64>) -> anyhow::Result<()> {
        let Some(picked) = self.pick_at(at) else {
            say!("nothing to focus on");
            return Ok(());
        };
        self.scene.camera.focus_distance = picked.depth;
        say!(
            "focused on {} at distance {}",
            self.scene.objects[picked.object].name,
            picked.depth
        );
        self.lens_changed()
    }

    /// Starts the image over with the scene camera's new lens.
    fn lens_changed(&mut self) -> anyhow::Result<()> {
        let camera = self.scene.camera.clone();
        self.set_camera(&camera, false)
    }

    fn act(&mut self, event_loop: &ActiveEventLoop, action: Action) -> anyhow::Result<()> {
        match action {
            Action::Quit => event_loop.exit(),
            Action::TogglePause => {
                self.paused = !self.paused;
                say!("{}", if self.paused { "paused" } else { "resumed" });
            }
            Action::Save => self.save()?,
            Action::Restart => {
                say!("restarted");
                if let Some(window) = &mut self.window {
                    window.frames.restart();
                }
                self.restarted();
            }
            Action::CycleTonemap => {
                self.tonemap = self.tonemap.next();
                say!("tone mapping: {}", self.tonemap.name());
            }
            Action::ToggleDenoised => match self.denoised.toggle() {
                Ok(on) => say!("denoised view {}", if on { "on" } else { "off" }),
                Err(why) => say!("no denoised view: {why}"),
            },
            Action::NextIteration => {
                if self.iterations.start_next() {
                    let (iteration, iters) = self.iterations.position();
                    say!("iter {iteration} of {iters} started");
                }
            }
            Action::Click(at) => self.click(at)?,
            Action::Focus(at) => self.focus(at)?,
            Action::Aperture(factor) => {
                let camera = &mut self.scene.camera;
                camera.aperture_radius = next_aperture(camera, factor);
                say!("aperture radius {}", camera.aperture_radius);
                self.lens_changed()?;
            }
            Action::Orbit(dx, dy) => {
                self.orbit.orbit(dx, dy);
                self.camera_changed()?;
            }
            Action::Pan(dx, dy) => {
                let height = self.window.as_ref().map_or(1, |w| w.height()) as f32;
                self.orbit.pan(dx, dy, height, self.scene.camera.fov_y_deg);
                self.camera_changed()?;
            }
            Action::Zoom(steps) => {
                self.orbit.zoom(steps);
                self.camera_changed()?;
            }
        }
        if let Some(window) = &self.window {
            window.window.request_redraw();
        }
        Ok(())
    }

    fn resized(&mut self, size: PhysicalSize<u32>) -> anyhow::Result<()> {
        if let Some(window) = &mut self.window {
            window.resize(size);
        }
        let camera = &mut self.scene.camera;
        if (size.width, size.height) != (camera.width, camera.height) {
            camera.width = size.width;
            camera.height = size.height;
            self.camera_changed()?;
        }
        Ok(())
    }

    fn window_event(
        &mut self,
        event_loop: &ActiveEventLoop,
        event: WindowEvent,
    ) -> anyhow::Result<()> {
        let action = match event {
            WindowEvent::CloseRequested => Some(Action::Quit),
            WindowEvent::Resized(size) if size.width > 0 && size.height > 0 => {
                self.resized(size)?;
                None
            }
            WindowEvent::RedrawRequested => {
                self.redraw()?;
                None
            }
            WindowEvent::KeyboardInput { event, .. } => key_action(&event, self.pointer.position()),
            WindowEvent::ModifiersChanged(modifiers) => {
                self.pointer.set_modifiers(modifiers.state());
                None
            }
            WindowEvent::CursorMoved { position, .. } => self.pointer.moved(position),
            WindowEvent::MouseInput { state, button, .. } => self.pointer.button(state, button),
            WindowEvent::MouseWheel { delta, .. } => Some(wheel_action(delta)),
            _ => None,
        };
        match action {
            Some(action) => self.act(event_loop, action),
            None => Ok(()),
        }
    }
}

impl ApplicationHandler<FrameReady> for Viewer {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.window.is_some() {
            return;
        }
        match ViewerWindow::open(
            event_loop,
            &self.device,
            self.proxy.clone(),
            &mut self.scene,
            &self.prepared,
        ) {
            Ok(window) => {
                window.window.request_redraw();
                self.rendering = (self.scene.camera.width, self.scene.camera.height);
                self.window = Some(window);
            }
            Err(err) => self.fail(event_loop, err),
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _id: WindowId, event: WindowEvent) {
        if let Err(err) = Viewer::window_event(self, event_loop, event) {
            self.fail(event_loop, err);
        }
    }

    fn user_event(&mut self, _event_loop: &ActiveEventLoop, _event: FrameReady) {
        if let Some(window) = &self.window {
            window.window.request_redraw();
        }
    }

    fn about_to_wait(&mut self, event_loop: &ActiveEventLoop) {
        let Some(window) = &self.window else {
            return;
        };
        // Wake when the pointer will count as resting, to start accumulating.
        let rest = self.preview.rest_at();
        event_loop.set_control_flow(rest.map_or(ControlFlow::Wait, ControlFlow::WaitUntil));
        let rested = rest.is_some_and(|at| Instant::now() >= at);
        // The GPU backend renders in the loop; the CPU backend's thread wakes it.
        if rested || (self.wants_frames() && window.frames.polled()) {
            window.window.request_redraw();
        }
    }
}
