//! The viewer's title bar: samples per pixel, iteration, frame rate, rays per second, the
//! adapter and the tone mapper.

use std::time::{Duration, Instant};

use pathlight_core::ToneMap;

use crate::view::iterations::{Iterations, Phase};

/// Interval between rays-per-second measurements.
const INTERVAL: Duration = Duration::from_millis(500);

/// Rays per second over the last interval.
#[derive(Debug)]
pub struct RayRate {
    since: Instant,
    rays_at_start: u64,
    per_second: f64,
}

impl RayRate {
    /// A rate measured from now.
    pub fn new() -> Self {
        Self {
            since: Instant::now(),
            rays_at_start: 0,
            per_second: 0.0,
        }
    }

    /// The renderer restarted its ray count.
    pub fn restart(&mut self) {
        self.rays_at_start = 0;
    }

    /// Measures again, counting the rays with `rays_traced`, when an interval has passed
    /// since the last measurement.
    pub fn update(
        &mut self,
        rays_traced: impl FnOnce() -> anyhow::Result<u64>,
    ) -> anyhow::Result<()> {
        let elapsed = self.since.elapsed();
        if elapsed >= INTERVAL {
            let rays = rays_traced()?;
            self.per_second =
                rays.saturating_sub(self.rays_at_start) as f64 / elapsed.as_secs_f64();
            self.since = Instant::now();
            self.rays_at_start = rays;
        }
        Ok(())
    }
}

/// What the title shows.
pub struct Title<'a> {
    /// Whole samples per pixel.
    pub spp: u32,
    /// The schedule.
    pub iterations: &'a Iterations,
    /// Whether rendering is paused.
    pub paused: bool,
    /// Whether the camera is moving (previews).
    pub moving: bool,
    /// Rays per second.
    pub rays: &'a RayRate,
    /// Where it renders.
    pub device: &'a str,
    /// The display's tone mapper.
    pub tonemap: ToneMap,
    /// Which image is shown: `raw`, or the denoised one's samples (`denoised 64 spp`).
    pub shown: &'a str,
}

impl std::fmt::Display for Title<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let (iteration, iters) = self.iterations.position();
        let state = match (self.paused, self.iterations.phase()) {
            (true, _) => " | paused (Space)".to_string(),
            _ if self.moving => " | preview".to_string(),
            (false, Phase::Waiting) => format!(" | right-click for iteration {}", iteration + 1),
            (false, Phase::Done) => " | done".to_string(),
            (false, Phase::Running) => String::new(),
        };
        let fps = self.iterations.fps();
        let fps = if fps < 10.0 {
            format!("{fps:.2}")
        } else {
            format!("{fps:.0}")
        };
        write!(
            f,
            "pathlight | {} spp | iter {iteration}/{iters} | {fps} fps | {:.1} M rays/s | {} | {} | {}{state}",
            self.spp,
            self.rays.per_second / 1e6,
            self.device,
            self.tonemap.name(),
            self.shown,
        )
    }
}
