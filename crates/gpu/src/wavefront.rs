//! The integrator as a wavefront: kernels over queues of paths (`shaders/wavefront.wgsl`),
//! one segment of every path at a time.

use pathlight_core::RenderError;

use crate::IntegratorKernel;
use crate::dispatch_times::DispatchTimes;
use crate::pipeline::{bind_buffers, create_compute_pipeline, storage_entry};

/// The kernels' entry points in `wavefront.wgsl`.
pub const WAVEFRONT_ENTRY_POINTS: [&str; 4] = ["wf_start", "wf_trace", "wf_shade", "wf_finish"];
/// Workgroup edge of the start and finish kernels (`@workgroup_size(8, 8)`).
const WORKGROUP: u32 = 8;
/// Lanes of the queue kernels' workgroups (`@workgroup_size(64)`).
const QUEUE_WORKGROUP: u32 = 64;
/// Word of `queue_counts` holding the sample of the batch.
const COUNT_SAMPLE: u64 = 6;
/// Paths a wave holds at least (device limits permitting): an image with fewer pixels gets
/// several samples of each in one wave, so the fixed cost of a segment's dispatches is
/// shared (160 MiB of path state, 208 MiB with auxiliary images).
const WAVE_PATHS: u64 = 1 << 20;
/// vec4s of a path's state, without and with auxiliary images (`F_*` in the shader).
const FIELDS: u64 = 10;
const FIELDS_WITH_AOVS: u64 = 13;

/// Rows of a `width` x `height` image one wave holds on a device with `limits`, each path's
/// state `fields` vec4s: the whole image, or several samples of it when it is small, as the
/// limits allow; or why the device cannot hold one row. `width` is at least 1 (the scene's
/// settings refuse a resolution outside 1..=`MAX_RESOLUTION`).
fn wave_rows(
    limits: &wgpu::Limits,
    (width, height): (u32, u32),
    fields: u64,
) -> Result<u32, RenderError> {
    // The trace kernel's workgroups: at most 1 + ceil(shadows / 64) + ceil(extensions / 64)
    // <= 3 + paths / 32, under the limit of a dispatch; the state under a binding's.
    let by_dispatch = u64::from(
        limits
            .max_compute_workgroups_per_dimension
            .saturating_sub(3)
            / 2,
    ) * u64::from(QUEUE_WORKGROUP);
    let by_binding = limits.max_storage_buffer_binding_size / (fields * 16);
    let paths = (u64::from(width) * u64::from(height)).max(WAVE_PATHS);
    let rows = paths.min(by_dispatch).min(by_binding) / u64::from(width);
    if rows == 0 {
        return Err(RenderError::Limits(format!(
            "a row of {width} pixels does not fit the wavefront's path state on this device \
             (at most {} paths); use the megakernel",
            by_dispatch.min(by_binding)
        )));
    }
    // At most WAVE_PATHS or the image's pixels, whichever is more: below 2^32 rows.
    Ok(rows as u32)
}

/// The wavefront kernels of a scene and the path state they share.
#[derive(Debug)]
pub struct Wavefront {
    start: wgpu::ComputePipeline,
    trace: wgpu::ComputePipeline,
    shade: wgpu::ComputePipeline,
    finish: wgpu::ComputePipeline,
    bind_group: wgpu::BindGroup,
    /// The queue counters (`queue_counts`).
    counts: wgpu::Buffer,
    /// The two buffers of dispatch arguments (`next_dispatch`) and a bind group of each.
    dispatches: [wgpu::Buffer; 2],
    dispatch_groups: [wgpu::BindGroup; 2],
    /// Rows one wave holds: the path state has room for that many rows' paths (or for
    /// `rows / band` samples of a band of rows).
    rows: u32,
}

impl Wavefront {
    /// The kernels of `kernel` (the assembled `wavefront` module), and path state for waves
    /// of whole rows of a `width` x `height` image (with auxiliary images or not), as many
    /// rows as the device's limits allow, or why it cannot hold one row.
    pub fn new(
        device: &wgpu::Device,
        kernel: &IntegratorKernel,
        scene_layout: &wgpu::BindGroupLayout,
        frame_layout: &wgpu::BindGroupLayout,
        (width, height): (u32, u32),
        aovs: bool,
    ) -> Result<Self, RenderError> {
        let fields = if aovs { FIELDS_WITH_AOVS } else { FIELDS };
        let rows = wave_rows(&device.limits(), (width, height), fields)?;
        let capacity = rows * width;
        let mut constants = kernel.constants.clone();
        constants.push(("CAPACITY", f64::from(capacity)));
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("wavefront layout"),
            entries: &[
                storage_entry(0, false),
                storage_entry(1, false),
                storage_entry(2, false),
                storage_entry(3, false),
            ],
        });
        let dispatch_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("wavefront dispatch layout"),
            entries: &[storage_entry(0, false)],
        });
        let layouts = [scene_layout, frame_layout, &layout, &dispatch_layout];
        let pipeline = |entry: &str| {
            create_compute_pipeline(device, entry, &kernel.source, entry, &layouts, &constants)
        };
        let state_size = fields * u64::from(capacity) * 16;
        let buffer = |label: &str, size: u64, usage: wgpu::BufferUsages| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size,
                usage,
                mapped_at_creation: false,
            })
        };
        use wgpu::BufferUsages as Usage;
        let paths = buffer("path state", state_size, Usage::STORAGE);
        let queues = buffer("path queues", 4 * u64::from(capacity) * 4, Usage::STORAGE);
        let counts = buffer("queue counts", 8 * 4, Usage::STORAGE | Usage::COPY_DST);
        let bind_group = bind_buffers(
            device,
            "wavefront",
            &layout,
            &[&paths, &queues, &counts, &counts],
        );
        let dispatches = [0, 1].map(|_| {
            buffer(
                "wavefront dispatches",
                8 * 4,
                Usage::STORAGE | Usage::INDIRECT,
            )
        });
        let dispatch_groups = [0, 1].map(|k| {
            bind_buffers(
                device,
                "wavefront dispatches",
                &dispatch_layout,
                &[&dispatches[k]],
            )
        });

        Ok(Self {
            start: pipeline("wf_start")?,
            trace: pipeline("wf_trace")?,
            shade: pipeline("wf_shade")?,
            finish: pipeline("wf_finish")?,
            bind_group,
            counts,
            dispatches,
            dispatch_groups,
            rows,
        })
    }

    /// Rows of the image one wave holds.
    pub fn rows(&self) -> u32 {
        self.rows
    }

    /// Records `samples` samples of `rows` rows (at most [`Self::rows`]) `width` wide,
    /// `max_depth` segments each, in waves of as many samples as the path state holds, into
    /// `encoder`, with bind groups `scene` (0) and `frame` (1); with `times`, a timestamp
    /// where the pass begins and after every dispatch (`start`, `trace N` and `shade N` of
    /// segment N, `finish`), 4 + 2 `max_depth` a wave.
    #[allow(clippy::too_many_arguments)]
    pub fn record(
        &self,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        scene: &wgpu::BindGroup,
        frame: &wgpu::BindGroup,
        width: u32,
        rows: u32,
        samples: u32,
        max_depth: u32,
        mut times: Option<&mut DispatchTimes>,
    ) {
        queue.write_buffer(&self.counts, 4 * COUNT_SAMPLE, bytemuck::bytes_of(&0u32));
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("wavefront"),
            timestamp_writes: None,
        });
        pass.set_bind_group(0, scene, &[]);
        pass.set_bind_group(1, frame, &[]);
        pass.set_bind_group(2, &self.bind_group, &[]);
        if let Some(times) = times.as_deref_mut() {
            times.begin(&mut pass);
        }
        let grid = (width.div_ceil(WORKGROUP), rows.div_ceil(WORKGROUP));
        // Segment s reads its dispatches from buffer s % 2 while its kernels fill the other.
        let segment = |pass: &mut wgpu::ComputePass,
                       times: &mut Option<&mut DispatchTimes>,
                       s: u32,
                       shade: bool| {
            let k = (s % 2) as usize;
            pass.set_bind_group(3, &self.dispatch_groups[1 - k], &[]);
            let kernels = [("trace", &self.trace, 0), ("shade", &self.shade, 12)];
            for (name, kernel, offset) in &kernels[..1 + usize::from(shade)] {
                pass.set_pipeline(kernel);
                pass.dispatch_workgroups_indirect(&self.dispatches[k], *offset);
                if let Some(times) = times.as_deref_mut() {
                    times.end(pass, format!("{name} {}", s + 1));
                }
            }
        };
        // As many samples of each pixel in a wave as the path state holds.
        let per_wave = (self.rows / rows).max(1);
        let mut left = samples;
        while left > 0 {
            let wave = per_wave.min(left);
            left -= wave;
            pass.set_bind_group(3, &self.dispatch_groups[0], &[]);
            pass.set_pipeline(&self.start);
            pass.dispatch_workgroups(grid.0, grid.1, wave);
            if let Some(times) = times.as_deref_mut() {
                times.end(&mut pass, "start".into());
            }
            for s in 0..max_depth {
                segment(&mut pass, &mut times, s, true);
            }
            // The last segment's shadow rays.
            segment(&mut pass, &mut times, max_depth, false);
            pass.set_pipeline(&self.finish);
            pass.dispatch_workgroups(grid.0, grid.1, 1);
            if let Some(times) = times.as_deref_mut() {
                times.end(&mut pass, "finish".into());
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A device's limits with `bytes` for a storage binding and `groups` workgroups a
    /// dispatch dimension.
    fn limits(bytes: u64, groups: u32) -> wgpu::Limits {
        wgpu::Limits {
            max_storage_buffer_binding_size: bytes,
            max_compute_workgroups_per_dimension: groups,
            ..wgpu::Limits::default()
        }
    }

    #[test]
    fn a_wave_holds_whole_rows_within_the_limits() {
        let roomy = limits(1 << 40, 1 << 30);
        // A small image: the wave holds several samples of it, in whole rows.
        assert_eq!(
            wave_rows(&roomy, (100, 50), FIELDS).ok(),
            Some((1 << 20) / 100)
        );
        // A large one: all of it.
        assert_eq!(wave_rows(&roomy, (4000, 3000), FIELDS).ok(), Some(3000));
        // The binding's limit: 1 MiB of 160-byte paths is 6553 paths, 65 rows of 100.
        let small_binding = limits(1 << 20, 1 << 30);
        assert_eq!(wave_rows(&small_binding, (100, 50), FIELDS).ok(), Some(65));
        // Auxiliary images make a path's state larger: 5041 paths, 50 rows.
        assert_eq!(
            wave_rows(&small_binding, (100, 50), FIELDS_WITH_AOVS).ok(),
            Some(50)
        );
        // The dispatch's limit: (1003 - 3) / 2 * 64 = 32000 paths, 320 rows.
        let few_groups = limits(1 << 40, 1003);
        assert_eq!(wave_rows(&few_groups, (100, 50), FIELDS).ok(), Some(320));
    }

    #[test]
    fn a_row_too_wide_for_the_device_is_refused_with_its_width() {
        let small_binding = limits(1 << 20, 1 << 30);
        let error = wave_rows(&small_binding, (7000, 10), FIELDS).unwrap_err();
        let text = error.to_string();
        assert!(matches!(error, RenderError::Limits(_)), "{text}");
        assert!(
            text.contains("a row of 7000 pixels") && text.contains("at most 6553 paths"),
            "{text}"
        );
        assert!(text.contains("use the megakernel"), "{text}");
    }
}
