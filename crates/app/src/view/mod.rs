//! `pathlight view`: the seed's interactive window. It renders the scene progressively in
//! iterations of frames (one sample per pixel each), waits for a right click between
//! iterations, turns a left-clicked object into a light, and lets the camera orbit, pan and
//! zoom. See README.md for every button and key.
//!
//! The window ([`window`]) turns events into actions ([`input`]); the viewer applies them
//! through the backend interface: a camera move or a resize sets only the camera, a light
//! toggle only the materials.

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
mod input;
mod iterations;
mod picking;
mod title;
mod window;

use std::path::PathBuf;
use std::time::{Duration, Instant};

use anyhow::{Context as _, anyhow};
use pathlight_core::PreparedScene;
use pathlight_render::display::ToneMap;
use pathlight_scene::Scene;
use winit::application::ApplicationHandler;
use winit::dpi::{PhysicalPosition, PhysicalSize};
use winit::event::WindowEvent;
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::window::WindowId;

use crate::backend::load_scene;
use crate::cli::ViewArgs;
use crate::output;
use camera::Orbit;
use input::{Action, Pointer, key_action, wheel_action};
use iterations::{Iterations, Phase};
use picking::{LightSwitch, pick};
use title::{RayRate, Title};
use window::ViewerWindow;

/// Longest time spent rendering between two presented images (a submission may overrun it).
const PRESENT_INTERVAL: Duration = Duration::from_millis(33);

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
    let mut viewer = Viewer::new(scene, args)?;
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
    adapter_name: Option<String>,
    save_dir: PathBuf,
    pointer: Pointer,
    rays: RayRate,
    window: Option<ViewerWindow>,
    error: Option<anyhow::Error>,
}

impl Viewer {
    fn new(scene: Scene, args: &ViewArgs) -> anyhow::Result<Self> {
        Ok(Self {
            prepared: PreparedScene::new(&scene)?,
            orbit: Orbit::from_camera(&scene.camera),
            lights: LightSwitch::new(&scene, args.light_strength),
            iterations: Iterations::new(args.frames_per_iter, args.iters),
            scene,
            tonemap: ToneMap::default(),
            paused: false,
            adapter_name: args.adapter.clone(),
            save_dir: args.save_dir.clone(),
            pointer: Pointer::default(),
            rays: RayRate::new(),
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
        if let Some(window) = &self.window {
            window.window.request_redraw();
        }
    }

    /// Gives the renderer the camera as the orbit (and the window size) has it now.
    fn camera_changed(&mut self) -> anyhow::Result<()> {
        self.orbit.apply(&mut self.scene.camera);
        if let Some(window) = &mut self.window {
            window.renderer().set_camera(&self.scene.camera)?;
        }
        self.restarted();
        Ok(())
    }

    fn wants_frames(&self) -> bool {
        !self.paused && self.iterations.phase() == Phase::Running
    }

    /// Renders for up to [`PRESENT_INTERVAL`], then shows the image.
    fn redraw(&mut self) -> anyhow::Result<()> {
        let rendering = self.wants_frames();
        let Some(window) = &mut self.window else {
            return Ok(());
        };
        if rendering {
            let started = Instant::now();
            let target = window.submission_target;
            while started.elapsed() < PRESENT_INTERVAL {
                let piece = Instant::now();
                let frame_done = window.renderer().step_frame(target)?;
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
        window.present(self.tonemap);
        self.rays.update(window.renderer())?;
        let title = Title {
            spp: window.renderer().samples_done(),
            iterations: &self.iterations,
            paused: self.paused,
            rays: &self.rays,
            device: &window.adapter,
            tonemap: self.tonemap,
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
        let film = window.renderer().film()?;
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

    /// A left click at window point `at`: toggles the object there between a light and
    /// its material, and gives the renderer the new materials.
    fn click(&mut self, at: PhysicalPosition<f64>) -> anyhow::Result<()> {
        let Some(window) = &mut self.window else {
            return Ok(());
        };
        let size = window.window.inner_size();
        let (width, height) = (self.scene.camera.width, self.scene.camera.height);
        let x = at.x as f32 * width as f32 / size.width.max(1) as f32;
        let y = at.y as f32 * height as f32 / size.height.max(1) as f32;
        let Some(object) = pick(&self.scene, &self.prepared, x, y) else {
            say!("picked nothing");
            return Ok(());
        };
        let on = self.lights.toggle(&mut self.scene, object);
        say!(
            "picked {}: light {}",
            self.scene.objects[object].name,
            if on { "on" } else { "off" }
        );
        self.prepared.shading = self.prepared.shading_of(&self.scene);
        window.renderer().set_materials(&self.prepared.shading)?;
        self.restarted();
        Ok(())
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
                    window.renderer().restart();
                }
                self.restarted();
            }
            Action::CycleTonemap => {
                self.tonemap = self.tonemap.next();
                say!("tone mapping: {}", self.tonemap.name());
            }
            Action::NextIteration => {
                if self.iterations.start_next() {
                    let (iteration, iters) = self.iterations.position();
                    say!("iter {iteration} of {iters} started");
                }
            }
            Action::Click(at) => self.click(at)?,
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
            WindowEvent::KeyboardInput { event, .. } => key_action(&event),
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

impl ApplicationHandler for Viewer {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.window.is_some() {
            return;
        }
        let adapter = self.adapter_name.clone();
        match ViewerWindow::open(
            event_loop,
            adapter.as_deref(),
            &mut self.scene,
            &self.prepared,
        ) {
            Ok(window) => {
                window.window.request_redraw();
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

    fn about_to_wait(&mut self, event_loop: &ActiveEventLoop) {
        event_loop.set_control_flow(ControlFlow::Wait);
        if self.wants_frames()
            && let Some(window) = &self.window
        {
            window.window.request_redraw();
        }
    }
}
