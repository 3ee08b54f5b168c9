//! The `auto` kernel: the megakernel and the wavefront timed in turn on whole passes of the
//! image, the faster kept. Which is faster depends on the device, the image size and how
//! long the scene's paths are (BENCHMARKS.md, "The wavefront split"), and both give the same
//! image bit for bit, so a render can take its first passes with either.

use std::time::Duration;

use crate::Kernel;

/// Timed passes of each kernel before the choice. A kernel's first pass includes its first
/// use on the device, so each kernel's faster pass counts.
const PASSES_EACH: usize = 2;

/// A trial under way: the best pass time of each kernel so far.
#[derive(Debug, Clone, Default)]
pub struct KernelTrial {
    megakernel: Option<Duration>,
    wavefront: Option<Duration>,
    passes: usize,
}

/// The outcome of a trial: the kernel kept and each kernel's best pass.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct KernelChoice {
    /// The faster kernel (the megakernel on a tie).
    pub kernel: Kernel,
    /// The megakernel's best pass.
    pub megakernel: Duration,
    /// The wavefront's best pass.
    pub wavefront: Duration,
}

impl KernelTrial {
    /// The kernel that renders the next timed pass: the two alternate, the megakernel first.
    pub fn next(&self) -> Kernel {
        if self.passes.is_multiple_of(2) {
            Kernel::Megakernel
        } else {
            Kernel::Wavefront
        }
    }

    /// Records the time of the pass [`Self::next`] named; once every pass is timed, the
    /// choice.
    pub fn record(&mut self, elapsed: Duration) -> Option<KernelChoice> {
        let best = match self.next() {
            Kernel::Wavefront => &mut self.wavefront,
            _ => &mut self.megakernel,
        };
        *best = Some(best.map_or(elapsed, |b| b.min(elapsed)));
        self.passes += 1;
        if self.passes < 2 * PASSES_EACH {
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

    fn ms(n: u64) -> Duration {
        Duration::from_millis(n)
    }

    /// Runs a trial on pass times in the order the passes are rendered.
    fn choose(times: &[u64]) -> Vec<(Kernel, Option<KernelChoice>)> {
        let mut trial = KernelTrial::default();
        times
            .iter()
            .map(|&t| (trial.next(), trial.record(ms(t))))
            .collect()
    }

    #[test]
    fn the_kernels_alternate_and_each_ones_best_pass_decides() {
        // The wavefront's first pass is slow (its first use), its second the fastest of all.
        let steps = choose(&[10, 50, 9, 6]);
        let order: Vec<Kernel> = steps.iter().map(|(k, _)| *k).collect();
        use Kernel::{Megakernel, Wavefront};
        assert_eq!(order, [Megakernel, Wavefront, Megakernel, Wavefront]);
        assert!(steps[..3].iter().all(|(_, c)| c.is_none()));
        assert_eq!(
            steps[3].1,
            Some(KernelChoice {
                kernel: Wavefront,
                megakernel: ms(9),
                wavefront: ms(6),
            })
        );
    }

    #[test]
    fn the_megakernel_is_kept_when_faster_or_tied() {
        assert_eq!(
            choose(&[5, 6, 7, 8])[3].1.unwrap().kernel,
            Kernel::Megakernel
        );
        assert_eq!(
            choose(&[5, 6, 7, 5])[3].1.unwrap().kernel,
            Kernel::Megakernel
        );
    }

    #[test]
    fn the_choice_names_the_kernel_and_both_times() {
        let text = choose(&[2, 3, 2, 1])[3].1.unwrap().describe();
        assert_eq!(
            text,
            "wavefront (auto: a pass took 2.000 ms with the megakernel, 1.000 ms with the \
             wavefront)"
        );
    }
}
