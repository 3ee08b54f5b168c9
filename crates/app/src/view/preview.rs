//! A camera that follows the mouse: while the camera moves (a drag, the wheel, a resize),
//! the viewer renders cheap previews, fewer pixels at one sample each, upscaled, sized from
//! the speed measured so far to keep up with the pointer; when the pointer rests, full
//! resolution accumulation starts over.

use std::time::{Duration, Instant};

use pathlight_scene::Camera;

/// Time without a camera move after which the pointer counts as resting.
pub const REST: Duration = Duration::from_millis(200);
/// Aimed-for rendering time of one preview frame.
const FRAME_TIME: Duration = Duration::from_millis(40);
/// Largest divisor of the width and height (1/256 of the pixels).
const MAX_DIVISOR: u32 = 16;
/// Divisor before any frame has been timed.
const FIRST_DIVISOR: u32 = 4;

/// What one run of previews did, reported when the pointer rests.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PreviewRun {
    /// Preview frames finished.
    pub frames: u32,
    /// Their size in pixels (the last one's).
    pub width: u32,
    /// Their height in pixels.
    pub height: u32,
    /// Preview frames per second, from the first move to the last frame.
    pub fps: f64,
}

/// The preview's state and the speed it is sized from.
#[derive(Debug)]
pub struct Preview {
    /// When the camera first and last moved in this run; `None` at rest.
    moving: Option<(Instant, Instant)>,
    frames: u32,
    last_frame: Option<Instant>,
    size: (u32, u32),
    /// Measured rendering seconds per pixel per sample.
    pixel_seconds: Option<f64>,
    /// Rendering time of the frame in progress so far (a frame may take many calls).
    pending: Duration,
}

impl Preview {
    /// At rest, with no speed measured.
    pub fn new() -> Self {
        Self {
            moving: None,
            frames: 0,
            last_frame: None,
            size: (0, 0),
            pixel_seconds: None,
            pending: Duration::ZERO,
        }
    }

    /// Whether previews are being rendered.
    pub fn is_moving(&self) -> bool {
        self.moving.is_some()
    }

    /// When the pointer will count as resting if the camera does not move again.
    pub fn rest_at(&self) -> Option<Instant> {
        self.moving.map(|(_, last)| last + REST)
    }

    /// The camera moved at `now`: the preview camera of `full` (the camera at full size),
    /// with its size divided so that a frame takes about [`FRAME_TIME`].
    pub fn moved(&mut self, now: Instant, full: &Camera) -> Camera {
        let first = self.moving.map_or(now, |(first, _)| first);
        if self.moving.is_none() {
            self.frames = 0;
            self.last_frame = None;
        }
        self.moving = Some((first, now));
        // The frame in progress is abandoned.
        self.pending = Duration::ZERO;
        let divisor = self.divisor(full.width, full.height);
        let mut camera = full.clone();
        camera.width = full.width.div_ceil(divisor);
        camera.height = full.height.div_ceil(divisor);
        self.size = (camera.width, camera.height);
        camera
    }

    /// The divisor of the width and height that makes a frame of `width` x `height` take
    /// about [`FRAME_TIME`] at the measured speed.
    fn divisor(&self, width: u32, height: u32) -> u32 {
        let Some(seconds) = self.pixel_seconds else {
            return FIRST_DIVISOR;
        };
        let full = seconds * f64::from(width) * f64::from(height);
        let ratio = (full / FRAME_TIME.as_secs_f64()).sqrt().ceil();
        (ratio as u32).clamp(1, MAX_DIVISOR)
    }

    /// `frames` frames of `pixels` pixels each were finished after `time` more rendering:
    /// the speed previews are sized from (time without a finished frame counts towards the
    /// next). Preview frames (when moving) also count towards the run.
    pub fn timed(&mut self, frames: u32, time: Duration, pixels: u64, now: Instant) {
        self.pending += time;
        if frames == 0 {
            return;
        }
        let time = std::mem::take(&mut self.pending);
        let per_pixel = time.as_secs_f64() / (f64::from(frames) * pixels.max(1) as f64);
        self.pixel_seconds = Some(per_pixel);
        if self.moving.is_some() {
            self.frames += frames;
            self.last_frame = Some(now);
        }
    }

    /// Ends the run if the pointer has rested since [`REST`] before `now`; returns what the
    /// run did.
    pub fn rested(&mut self, now: Instant) -> Option<PreviewRun> {
        let (first, last) = self.moving?;
        if now < last + REST {
            return None;
        }
        self.moving = None;
        let span = self.last_frame.map_or(0.0, |t| (t - first).as_secs_f64());
        Some(PreviewRun {
            frames: self.frames,
            width: self.size.0,
            height: self.size.1,
            fps: if span > 0.0 {
                f64::from(self.frames) / span
            } else {
                0.0
            },
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn camera(width: u32, height: u32) -> Camera {
        let mut scene = pathlight_scene::default_scene::load().unwrap();
        scene.camera.width = width;
        scene.camera.height = height;
        scene.camera
    }

    #[test]
    fn previews_are_sized_from_the_measured_speed() {
        let t0 = Instant::now();
        let full = camera(500, 500);
        let mut preview = Preview::new();
        // Before any timing: a quarter of the width and height.
        let first = preview.moved(t0, &full);
        assert_eq!((first.width, first.height), (125, 125));
        assert_eq!(first.position, full.position);
        // 8 full frames per second (0.125 s each): 1/4 of the pixels take 31 ms.
        preview.timed(1, Duration::from_millis(125), 250_000, t0);
        assert_eq!(preview.moved(t0, &full).width, 250);
        // A fast GPU: full size. A slow adapter: the smallest preview, also when its frames
        // take many calls.
        preview.timed(1, Duration::from_millis(2), 250_000, t0);
        assert_eq!(preview.moved(t0, &full).width, 500);
        for _ in 0..600 {
            preview.timed(0, Duration::from_millis(100), 250_000, t0);
        }
        preview.timed(1, Duration::from_millis(100), 250_000, t0);
        let smallest = preview.moved(t0, &full);
        assert_eq!(
            (smallest.width, smallest.height),
            (32, 32),
            "500/16 rounded up"
        );
    }

    #[test]
    fn a_run_ends_when_the_pointer_rests_and_reports_its_rate() {
        let t0 = Instant::now();
        let ms = |n| t0 + Duration::from_millis(n);
        let full = camera(64, 48);
        let mut preview = Preview::new();
        assert!(!preview.is_moving());
        preview.moved(t0, &full);
        for n in 1..=10 {
            preview.timed(1, Duration::from_millis(20), 16 * 12, ms(50 * n));
            preview.moved(ms(50 * n), &full);
        }
        assert!(preview.is_moving());
        assert_eq!(preview.rest_at(), Some(ms(500) + REST));
        assert_eq!(preview.rested(ms(600)), None, "moved 100 ms ago");
        let run = preview.rested(ms(700)).expect("rested 200 ms");
        assert_eq!(run.frames, 10);
        assert!(
            (run.fps - 20.0).abs() < 1e-9,
            "10 frames in 0.5 s: {}",
            run.fps
        );
        assert!(!preview.is_moving());
        // Frames at rest are not preview frames.
        preview.timed(3, Duration::from_millis(60), 64 * 48, ms(800));
        preview.moved(ms(900), &full);
        assert_eq!(preview.rested(ms(1200)).unwrap().frames, 0);
    }
}
