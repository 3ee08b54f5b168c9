//! The seed's schedule: iterations of a fixed number of frames (one sample per pixel each);
//! after each, the viewer reports the iteration's frame rate and waits for a right click.

use std::time::Duration;

/// Where the schedule stands.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Phase {
    /// Rendering frames of the current iteration.
    Running,
    /// The current iteration finished; waiting for the next to be started.
    Waiting,
    /// Every iteration finished.
    Done,
}

/// An iteration that just finished.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Finished {
    /// Its number, from 1.
    pub iteration: u32,
    /// Its average frames per second (rendering time only, pauses excluded).
    pub fps: f64,
}

/// Iteration bookkeeping.
#[derive(Debug, Clone)]
pub struct Iterations {
    frames_per_iter: u32,
    iters: u32,
    /// Current iteration, from 1.
    current: u32,
    frames_in_current: u32,
    time_in_current: Duration,
    phase: Phase,
}

impl Iterations {
    /// A schedule of `iters` iterations of `frames_per_iter` frames (each at least 1),
    /// starting with iteration 1 running.
    pub fn new(frames_per_iter: u32, iters: u32) -> Self {
        Self {
            frames_per_iter: frames_per_iter.max(1),
            iters: iters.max(1),
            current: 1,
            frames_in_current: 0,
            time_in_current: Duration::ZERO,
            phase: Phase::Running,
        }
    }

    /// Where the schedule stands.
    pub fn phase(&self) -> Phase {
        self.phase
    }

    /// The current (or last finished) iteration, from 1, and the number of iterations.
    pub fn position(&self) -> (u32, u32) {
        (self.current, self.iters)
    }

    /// Frames the current iteration still lacks (none unless it is running).
    pub fn frames_left(&self) -> u32 {
        match self.phase {
            Phase::Running => self.frames_per_iter - self.frames_in_current,
            _ => 0,
        }
    }

    /// Average frames per second of the current iteration so far (0 before its first frame).
    pub fn fps(&self) -> f64 {
        if self.time_in_current.is_zero() {
            return 0.0;
        }
        f64::from(self.frames_in_current) / self.time_in_current.as_secs_f64()
    }

    /// Records rendering time spent on the current iteration.
    pub fn add_time(&mut self, elapsed: Duration) {
        if self.phase == Phase::Running {
            self.time_in_current += elapsed;
        }
    }

    /// Records a finished frame; returns the iteration it completed, if any.
    pub fn frame_done(&mut self) -> Option<Finished> {
        if self.phase != Phase::Running {
            return None;
        }
        self.frames_in_current += 1;
        if self.frames_in_current < self.frames_per_iter {
            return None;
        }
        self.phase = if self.current == self.iters {
            Phase::Done
        } else {
            Phase::Waiting
        };
        let seconds = self.time_in_current.as_secs_f64().max(1e-9);
        Some(Finished {
            iteration: self.current,
            fps: f64::from(self.frames_in_current) / seconds,
        })
    }

    /// Starts the next iteration if one is waiting; returns whether it did.
    pub fn start_next(&mut self) -> bool {
        if self.phase != Phase::Waiting {
            return false;
        }
        self.current += 1;
        self.frames_in_current = 0;
        self.time_in_current = Duration::ZERO;
        self.phase = Phase::Running;
        true
    }

    /// Back to iteration 1 with no frames (the image was restarted).
    pub fn restart(&mut self) {
        *self = Self::new(self.frames_per_iter, self.iters);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn iterations_finish_after_their_frames_and_wait() {
        let mut it = Iterations::new(3, 2);
        assert_eq!(it.phase(), Phase::Running);
        it.add_time(Duration::from_millis(300));
        assert_eq!(it.frame_done(), None);
        assert_eq!(it.frame_done(), None);
        assert!(
            (it.fps() - 2.0 / 0.3).abs() < 1e-9,
            "2 frames in 0.3 s so far"
        );
        let finished = it.frame_done().expect("the third frame ends iteration 1");
        assert_eq!(finished.iteration, 1);
        assert!((finished.fps - 10.0).abs() < 1e-9, "3 frames in 0.3 s");
        assert_eq!(it.phase(), Phase::Waiting);
        // Waiting: frames and time are not counted.
        assert_eq!(it.frame_done(), None);
        it.add_time(Duration::from_secs(100));
        assert!(it.start_next());
        assert_eq!(it.position(), (2, 2));
        it.add_time(Duration::from_millis(150));
        it.frame_done();
        it.frame_done();
        let finished = it.frame_done().unwrap();
        assert_eq!(finished.iteration, 2);
        assert!(
            (finished.fps - 20.0).abs() < 1e-9,
            "time from the wait is not counted"
        );
        assert_eq!(it.phase(), Phase::Done);
        assert!(!it.start_next(), "no iteration after the last");
    }

    #[test]
    fn start_next_only_when_waiting_and_restart_goes_back_to_one() {
        let mut it = Iterations::new(2, 8);
        assert!(!it.start_next(), "iteration 1 is still running");
        it.frame_done();
        it.frame_done();
        assert!(it.start_next());
        it.frame_done();
        it.restart();
        assert_eq!(it.position(), (1, 8));
        assert_eq!(it.phase(), Phase::Running);
        assert_eq!(it.frame_done(), None, "the restart cleared the frame count");
    }

    #[test]
    fn zero_sizes_are_raised_to_one() {
        let mut it = Iterations::new(0, 0);
        assert!(it.frame_done().is_some());
        assert_eq!(it.phase(), Phase::Done);
    }
}
