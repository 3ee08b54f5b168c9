//! Progress of a render: an indicatif bar on a terminal, plain lines otherwise.

use std::io::IsTerminal;
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressStyle};

/// Reports samples per pixel done out of a total, with samples/s and ETA.
#[derive(Debug)]
pub struct Progress {
    bar: Option<ProgressBar>,
    total_spp: u32,
    pixels: u64,
    started: Instant,
    last_line: Instant,
}

/// Interval between plain progress lines.
const LINE_INTERVAL: Duration = Duration::from_secs(2);

impl Progress {
    /// Starts reporting a render of `total_spp` over `pixels` pixels.
    pub fn new(total_spp: u32, pixels: u64) -> Self {
        let bar = std::io::stderr().is_terminal().then(|| {
            let bar = ProgressBar::new(u64::from(total_spp));
            bar.set_style(
                ProgressStyle::with_template(
                    "{bar:40.cyan/blue} {pos}/{len} spp  {msg}  elapsed {elapsed}  ETA {eta}",
                )
                .expect("the template is valid"),
            );
            bar
        });
        let now = Instant::now();
        Self {
            bar,
            total_spp,
            pixels,
            started: now,
            last_line: now,
        }
    }

    /// Samples (pixel samples, not spp) per second so far.
    pub fn samples_per_second(&self, spp_done: u32) -> f64 {
        (self.pixels * u64::from(spp_done)) as f64 / self.started.elapsed().as_secs_f64().max(1e-9)
    }

    /// Records that `spp_done` samples per pixel are finished.
    pub fn update(&mut self, spp_done: u32) {
        let rate = format!("{:.2} M samples/s", self.samples_per_second(spp_done) / 1e6);
        match &self.bar {
            Some(bar) => {
                bar.set_position(u64::from(spp_done));
                bar.set_message(rate);
            }
            None => {
                if self.last_line.elapsed() >= LINE_INTERVAL || spp_done == self.total_spp {
                    self.last_line = Instant::now();
                    note!(
                        "rendered {spp_done}/{} spp ({:.0}%), {rate}",
                        self.total_spp,
                        100.0 * f64::from(spp_done) / f64::from(self.total_spp)
                    );
                }
            }
        }
    }

    /// Removes the bar.
    pub fn finish(&self) {
        if let Some(bar) = &self.bar {
            bar.finish_and_clear();
        }
    }
}
