//! Timestamps between the integrator's dispatches: one pass of the image profiled kernel by
//! kernel ([`crate::GpuRenderer::profile_pass`], `examples/kernel_times.rs`), where the
//! device has timestamp queries inside compute passes.

use std::time::Duration;

/// The features a device needs for it (requested where the adapter has them).
pub const FEATURES: wgpu::Features =
    wgpu::Features::TIMESTAMP_QUERY.union(wgpu::Features::TIMESTAMP_QUERY_INSIDE_PASSES);

/// A query set for the timestamps of one pass, and the dispatch each timestamp ends.
#[derive(Debug)]
pub struct DispatchTimes {
    set: wgpu::QuerySet,
    capacity: u32,
    /// Per timestamp written: the dispatch it ends, or `None` where a compute pass begins.
    labels: Vec<Option<String>>,
}

impl DispatchTimes {
    /// Room for `capacity` timestamps (at most `wgpu::QUERY_SET_MAX_QUERIES`).
    pub fn new(device: &wgpu::Device, capacity: u32) -> Self {
        let set = device.create_query_set(&wgpu::QuerySetDescriptor {
            label: Some("dispatch times"),
            ty: wgpu::QueryType::Timestamp,
            count: capacity,
        });
        Self {
            set,
            capacity,
            labels: Vec::new(),
        }
    }

    /// A timestamp where `pass` begins.
    pub fn begin(&mut self, pass: &mut wgpu::ComputePass) {
        self.write(pass, None);
    }

    /// A timestamp after the dispatch just recorded in `pass`, which `label` names.
    pub fn end(&mut self, pass: &mut wgpu::ComputePass, label: String) {
        self.write(pass, Some(label));
    }

    /// Writes the next timestamp; past the capacity, none (the durations then stop there).
    fn write(&mut self, pass: &mut wgpu::ComputePass, label: Option<String>) {
        let index = self.labels.len() as u32;
        if index < self.capacity {
            pass.write_timestamp(&self.set, index);
            self.labels.push(label);
        }
    }

    /// Bytes of the timestamps written, as [`Self::resolve`] copies them.
    pub fn size(&self) -> u64 {
        8 * self.labels.len() as u64
    }

    /// Copies the timestamps written into `buffer` (`QUERY_RESOLVE` usage, [`Self::size`]
    /// bytes at least).
    pub fn resolve(&self, encoder: &mut wgpu::CommandEncoder, buffer: &wgpu::Buffer) {
        encoder.resolve_query_set(&self.set, 0..self.labels.len() as u32, buffer, 0);
    }

    /// Each dispatch's time in order, named, from the timestamps `ticks` (as resolved) and
    /// the device's nanoseconds a tick.
    pub fn durations(&self, ticks: &[u64], period_ns: f32) -> Vec<(String, Duration)> {
        durations(&self.labels, ticks, period_ns)
    }
}

/// The time between each labelled timestamp and the one before it.
fn durations(labels: &[Option<String>], ticks: &[u64], period_ns: f32) -> Vec<(String, Duration)> {
    (1..labels.len().min(ticks.len()))
        .filter_map(|i| {
            let label = labels[i].as_ref()?;
            let nanos = ticks[i].saturating_sub(ticks[i - 1]) as f64 * f64::from(period_ns);
            Some((label.clone(), Duration::from_nanos(nanos.round() as u64)))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_dispatch_takes_the_time_since_the_timestamp_before_it() {
        let labels = [
            None,
            Some("start".to_string()),
            Some("trace 1".to_string()),
            None,
            Some("megakernel".to_string()),
        ];
        // Ticks of 2 ns; a new pass's first timestamp ends nothing.
        let ticks = [100, 150, 400, 1000, 1010];
        let times = durations(&labels, &ticks, 2.0);
        let expected: Vec<(String, Duration)> =
            [("start", 100), ("trace 1", 500), ("megakernel", 20)]
                .iter()
                .map(|&(l, ns)| (l.to_string(), Duration::from_nanos(ns)))
                .collect();
        assert_eq!(times, expected);
    }
}
