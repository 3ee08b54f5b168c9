//! The `auto` kernel: the megakernel and the wavefront timed in turn on whole passes of the
//! image, the faster kept. Which is faster depends on the device, the image size and how
//! long the scene's paths are (BENCHMARKS.md, "The wavefront split"), and both give the same
//! image bit for bit, so a render can take its first passes with either.

use std::time::Duration;

use crate::Kernel;

/// Timed steps of each kernel before the choice. A kernel's first step includes its first
/// use on the device, and a GPU fresh from idle runs the first steps at low clocks (an H100
/// took 4-5 times as long a pass for the first 25 ms of a `bench`), so each kernel's fastest
/// step counts, and the last steps come after about 100 ms of work.
const STEPS_EACH: usize = 3;
/// Time a step aims at: shorter passes are timed several to a step, so that the wait for
/// the device's answer (about 0.5 ms on an H200, as long as a 500x500 pass) and its jitter do
/// not decide.
const STEP_TARGET: Duration = Duration::from_millis(20);
/// Most passes in one step.
const MAX_STEP_PASSES: u32 = 64;

/// A trial under way: the best time a pass took with each kernel so far.
#[derive(Debug, Clone)]
pub struct KernelTrial {
    megakernel: Option<Duration>,
    wavefront: Option<Duration>,
    steps: usize,
    step_passes: u32,
}

impl Default for KernelTrial {
    fn default() -> Self {
        Self {
            megakernel: None,
            wavefront: None,
            steps: 0,
            step_passes: 1,
        }
    }
}

/// The outcome of a trial: the kernel kept and each kernel's best time a pass.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct KernelChoice {
    /// The faster kernel (the megakernel on a tie).
    pub kernel: Kernel,
    /// The megakernel's best time a pass.
    pub megakernel: Duration,
    /// The wavefront's best time a pass.
    pub wavefront: Duration,
}

impl KernelTrial {
    /// The kernel that renders the next step: the two alternate, the megakernel first.
    pub fn next(&self) -> Kernel {
        if self.steps.is_multiple_of(2) {
            Kernel::Megakernel
        } else {
            Kernel::Wavefront
        }
    }

    /// Whole passes the next step renders: one at first, then as many as the best pass so
    /// far fits in 20 ms (`STEP_TARGET`), at most 64 (`MAX_STEP_PASSES`).
    pub fn passes(&self) -> u32 {
        self.step_passes
    }

    /// Records the time of a step of [`Self::next`]'s kernel that rendered `passes` passes;
    /// once every step is timed, the choice.
    pub fn record(&mut self, elapsed: Duration, passes: u32) -> Option<KernelChoice> {
        let per_pass = elapsed / passes.max(1);
        let best = match self.next() {
            Kernel::Wavefront => &mut self.wavefront,
            _ => &mut self.megakernel,
        };
        *best = Some(best.map_or(per_pass, |b| b.min(per_pass)));
        self.steps += 1;
        let fastest = self.megakernel.into_iter().chain(self.wavefront).min();
        if let Some(fastest) = fastest {
            let fit = STEP_TARGET.as_secs_f64() / fastest.as_secs_f64().max(1e-9);
            self.step_passes = fit.clamp(1.0, f64::from(MAX_STEP_PASSES)) as u32;
        }
        if self.steps < 2 * STEPS_EACH {
            return None;
        }
        let (megakernel, wavefront) = (self.megakernel?, self.wavefront?);
        Some(KernelChoice {
            kernel: if wavefront < megakernel {
                Kernel::Wavefront
            } else {
                Kernel::Megakernel
            },
            megakernel,
            wavefront,
        })
    }
}

impl KernelChoice {
    /// The kernel and the times it was chosen by, for messages and reports.
    pub fn describe(&self) -> String {
        format!(
            "{} (auto: a pass took {:.3} ms with the megakernel, {:.3} ms with the wavefront)",
            self.kernel.name(),
            self.megakernel.as_secs_f64() * 1e3,
            self.wavefront.as_secs_f64() * 1e3
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ms(n: f64) -> Duration {
        Duration::from_secs_f64(n / 1e3)
    }

    /// Runs a trial on step times (each step as many passes as the trial asks for, each pass
    /// as long as given): the kernel and passes of each step and the outcome.
    fn choose(pass_ms: &[f64]) -> Vec<(Kernel, u32, Option<KernelChoice>)> {
        let mut trial = KernelTrial::default();
        pass_ms
            .iter()
            .map(|&t| {
                let (kernel, passes) = (trial.next(), trial.passes());
                (kernel, passes, trial.record(ms(t) * passes, passes))
            })
            .collect()
    }

    #[test]
    fn the_kernels_alternate_and_each_ones_best_pass_decides() {
        // The wavefront's first step is slow (its first use), its second the fastest of all.
        let steps = choose(&[10.0, 50.0, 9.0, 6.0, 9.5, 7.0]);
        let order: Vec<Kernel> = steps.iter().map(|s| s.0).collect();
        use Kernel::{Megakernel, Wavefront};
        assert_eq!(
            order,
            [
                Megakernel, Wavefront, Megakernel, Wavefront, Megakernel, Wavefront
            ]
        );
        assert!(steps[..5].iter().all(|s| s.2.is_none()));
        assert_eq!(
            steps[5].2,
            Some(KernelChoice {
                kernel: Wavefront,
                megakernel: ms(9.0),
                wavefront: ms(6.0),
            })
        );
    }

    #[test]
    fn clocks_rising_through_the_trial_do_not_decide() {
        // Every step faster than the one before: over the first two steps each the wavefront
        // (always second) would win; the third steps, at full clocks, show the megakernel
        // faster.
        let choice = choose(&[40.0, 50.0, 20.0, 15.0, 3.0, 4.0])[5].2.unwrap();
        assert_eq!(choice.kernel, Kernel::Megakernel);
    }

    #[test]
    fn short_passes_are_timed_several_to_a_step() {
        // 20 ms passes: one a step. 5 ms: four. 0.1 ms: at most 64.
        let passes = |t: f64| -> Vec<u32> { choose(&[t; 6]).iter().map(|s| s.1).collect() };
        assert_eq!(passes(20.0), [1; 6]);
        assert_eq!(passes(5.0), [1, 4, 4, 4, 4, 4]);
        assert_eq!(passes(0.1), [1, 64, 64, 64, 64, 64]);
        // A slow first use does not shrink the steps after a fast pass.
        let steps = choose(&[40.0, 2.0, 2.0, 2.0, 2.0, 2.0]);
        let passes: Vec<u32> = steps.iter().map(|s| s.1).collect();
        assert_eq!(passes, [1, 1, 10, 10, 10, 10]);
        // The times recorded are a pass's, not a step's.
        assert_eq!(steps[5].2.unwrap().megakernel, ms(2.0));
    }

    #[test]
    fn the_megakernel_is_kept_when_faster_or_tied() {
        let kernel = |t: &[f64]| choose(t)[5].2.unwrap().kernel;
        assert_eq!(kernel(&[5.0, 6.0, 7.0, 8.0, 9.0, 9.0]), Kernel::Megakernel);
        assert_eq!(kernel(&[5.0, 6.0, 7.0, 5.0, 9.0, 9.0]), Kernel::Megakernel);
    }

    #[test]
    fn the_choice_names_the_kernel_and_both_times() {
        let text = choose(&[2.0, 3.0, 2.0, 1.0, 2.0, 1.0])[5]
            .2
            .unwrap()
            .describe();
        assert_eq!(
            text,
            "wavefront (auto: a pass took 2.000 ms with the megakernel, 1.000 ms with the \
             wavefront)"
        );
    }
}
