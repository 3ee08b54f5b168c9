//! The integrator as a wavefront: kernels over queues of paths (`shaders/wavefront.wgsl`),
//! one segment of every path at a time.

use pathlight_core::RenderError;
use wgpu::util::DeviceExt;

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
/// Frames one [`Wavefront::submit_frames`] keeps in flight at most, each in a layer of the
/// path state of its own.
const MAX_LAYERS: u32 = 4;
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
    /// Bytes between the entries of the wave table (`wave_layer`, one entry for each first
    /// layer and waves ahead), the device's alignment of a dynamic offset.
    layer_stride: u32,
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
                wgpu::BindGroupLayoutEntry {
                    binding: 4,
                    visibility: wgpu::ShaderStages::COMPUTE,
                    ty: wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Uniform,
                        has_dynamic_offset: true,
                        min_binding_size: wgpu::BufferSize::new(8),
                    },
                    count: None,
                },
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
        // Entry layer * MAX_LAYERS + ahead of the wave table: (layer, ahead).
        let layer_stride = device.limits().min_uniform_buffer_offset_alignment.max(8);
        let mut table = vec![0u32; (MAX_LAYERS * MAX_LAYERS * layer_stride / 4) as usize];
        for layer in 0..MAX_LAYERS {
            for ahead in 0..MAX_LAYERS {
                let at = ((layer * MAX_LAYERS + ahead) * layer_stride / 4) as usize;
                table[at..at + 2].copy_from_slice(&[layer, ahead]);
            }
        }
        let layers = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("wave layers"),
            contents: bytemuck::cast_slice(&table),
            usage: Usage::UNIFORM,
        });
        let entries: Vec<_> = [&paths, &queues, &counts, &counts]
            .iter()
            .enumerate()
            .map(|(i, b)| wgpu::BindGroupEntry {
                binding: i as u32,
                resource: b.as_entire_binding(),
            })
            .chain([wgpu::BindGroupEntry {
                binding: 4,
                resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                    buffer: &layers,
                    offset: 0,
                    size: wgpu::BufferSize::new(8),
                }),
            }])
            .collect();
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("wavefront"),
            layout: &layout,
            entries: &entries,
        });
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
            layer_stride,
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
        let mut pass = self.begin(encoder, scene, frame);
        if let Some(times) = times.as_deref_mut() {
            times.begin(&mut pass);
        }
        let grid = (width.div_ceil(WORKGROUP), rows.div_ceil(WORKGROUP));
        // As many samples of each pixel in a wave as the path state holds.
        let per_wave = (self.rows / rows).max(1);
        let mut left = samples;
        while left > 0 {
            let wave = per_wave.min(left);
            left -= wave;
            self.start(&mut pass, grid, wave, 0, (0, 0));
            mark(&mut pass, &mut times, || "start".into());
            for s in 0..max_depth {
                self.segment(&mut pass, &mut times, s, true);
            }
            // The last segment's shadow rays.
            self.segment(&mut pass, &mut times, max_depth, false);
            self.finish(&mut pass, grid, 0);
            mark(&mut pass, &mut times, || "finish".into());
        }
    }

    /// Layers of the path state [`Self::submit_frames`] uses for `frames` frames of `rows`
    /// rows, and the segments between one frame's start and the next's: the fewest layers
    /// that give the fewest segments the path state and `MAX_LAYERS` (4) allow. A frame's
    /// layer is taken again `layers` frames later, after its `max_depth + 1` segments.
    pub fn frame_layers(&self, rows: u32, max_depth: u32, frames: u32) -> (u32, u32) {
        frame_layers(self.rows / rows, max_depth, frames)
    }

    /// Renders `frames` frames of one sample each of all `rows` rows of the image `width`
    /// wide, `max_depth` segments each (bind groups as [`Self::record`]'s), overlapped: each
    /// frame starts in a layer of the path state of its own a few segments after the frame
    /// before ([`Self::frame_layers`]), so that every segment traces and shades the paths of
    /// all the frames in flight, and is finished once its last segment is traced. The film
    /// gets the same samples as from `frames` waves of [`Self::record`]. The segments are
    /// submitted `PIECE_SEGMENTS` (24) at a time, so that the device starts on the first while
    /// the rest are recorded.
    #[allow(clippy::too_many_arguments)]
    pub fn submit_frames(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        scene: &wgpu::BindGroup,
        frame: &wgpu::BindGroup,
        width: u32,
        rows: u32,
        frames: u32,
        max_depth: u32,
    ) {
        let (layers, spacing) = self.frame_layers(rows, max_depth, frames);
        let schedule = frame_schedule(layers, spacing, frames, max_depth);
        let grid = (width.div_ceil(WORKGROUP), rows.div_ceil(WORKGROUP));
        queue.write_buffer(&self.counts, 4 * COUNT_SAMPLE, bytemuck::bytes_of(&0u32));
        let piece_end = |step: &FrameStep| matches!(step, FrameStep::Segment { s, .. } if (s + 1) % PIECE_SEGMENTS == 0);
        for piece in schedule.split_inclusive(piece_end) {
            let mut encoder = device.create_command_encoder(&Default::default());
            let mut pass = self.begin(&mut encoder, scene, frame);
            for step in piece {
                match *step {
                    FrameStep::Start { layer, ahead, s } => {
                        self.start(&mut pass, grid, 1, s, (layer, ahead));
                    }
                    FrameStep::Segment { s, shade } => self.segment(&mut pass, &mut None, s, shade),
                    FrameStep::Finish { layer } => self.finish(&mut pass, grid, layer),
                }
            }
            drop(pass);
            queue.submit([encoder.finish()]);
        }
    }

    /// A compute pass for the kernels in `encoder` with the scene's and the frame's bind
    /// groups set, the path state with the wave table's first entry, and a dispatch buffer.
    fn begin<'e>(
        &self,
        encoder: &'e mut wgpu::CommandEncoder,
        scene: &wgpu::BindGroup,
        frame: &wgpu::BindGroup,
    ) -> wgpu::ComputePass<'e> {
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("wavefront"),
            timestamp_writes: None,
        });
        pass.set_bind_group(0, scene, &[]);
        pass.set_bind_group(1, frame, &[]);
        self.bind_layer(&mut pass, (0, 0));
        // Each step binds the dispatch arguments it reads or fills; `wf_finish` reads none.
        pass.set_bind_group(3, &self.dispatch_groups[0], &[]);
        pass
    }

    /// Binds the path state with the wave table's entry for a wave in layer `layer` with
    /// `ahead` waves in flight before it.
    fn bind_layer(&self, pass: &mut wgpu::ComputePass, (layer, ahead): (u32, u32)) {
        let entry = layer * MAX_LAYERS + ahead;
        pass.set_bind_group(2, &self.bind_group, &[entry * self.layer_stride]);
    }

    /// `wf_start` for `samples` samples of every pixel of the `grid` of workgroups, from
    /// layer `layer` on, with `ahead` waves in flight, before segment `s`.
    fn start(
        &self,
        pass: &mut wgpu::ComputePass,
        grid: (u32, u32),
        samples: u32,
        s: u32,
        (layer, ahead): (u32, u32),
    ) {
        self.bind_layer(pass, (layer, ahead));
        // Segment s reads its dispatches from buffer s % 2: a start with none ahead sets
        // them, one with waves ahead adds its paths' workgroups.
        pass.set_bind_group(3, &self.dispatch_groups[(s % 2) as usize], &[]);
        pass.set_pipeline(&self.start);
        pass.dispatch_workgroups(grid.0, grid.1, samples);
    }

    /// Segment `s`'s dispatches: `wf_trace`, then `wf_shade` when `shade`; each marked in
    /// `times`.
    fn segment(
        &self,
        pass: &mut wgpu::ComputePass,
        times: &mut Option<&mut DispatchTimes>,
        s: u32,
        shade: bool,
    ) {
        // Segment s reads its dispatches from buffer s % 2 while its kernels fill the other.
        let k = (s % 2) as usize;
        pass.set_bind_group(3, &self.dispatch_groups[1 - k], &[]);
        let kernels = [("trace", &self.trace, 0), ("shade", &self.shade, 12)];
        for (name, kernel, offset) in &kernels[..1 + usize::from(shade)] {
            pass.set_pipeline(kernel);
            pass.dispatch_workgroups_indirect(&self.dispatches[k], *offset);
            mark(pass, times, || format!("{name} {}", s + 1));
        }
    }

    /// `wf_finish` for the wave whose paths start at layer `layer`.
    fn finish(&self, pass: &mut wgpu::ComputePass, grid: (u32, u32), layer: u32) {
        self.bind_layer(pass, (layer, 0));
        pass.set_pipeline(&self.finish);
        pass.dispatch_workgroups(grid.0, grid.1, 1);
    }
}

/// Segments of overlapped frames recorded into one submission.
const PIECE_SEGMENTS: u32 = 24;

/// A dispatch of overlapped frames ([`frame_schedule`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum FrameStep {
    /// `wf_start`: a frame in layer `layer`, with `ahead` frames in flight before it, starts
    /// before segment `s`.
    Start { layer: u32, ahead: u32, s: u32 },
    /// Segment `s`: `wf_trace`, then `wf_shade` when `shade`.
    Segment { s: u32, shade: bool },
    /// `wf_finish` of the frame in layer `layer`.
    Finish { layer: u32 },
}

/// The dispatches of `frames` overlapped frames of `max_depth` segments in `layers` layers,
/// a frame starting every `spacing` segments (`layers * spacing > max_depth`): frame k starts
/// in layer k % layers before segment k * spacing, its paths are traced in segments
/// k * spacing ..= k * spacing + max_depth, and it is finished before frame k + layers
/// starts in its layer, or after the last segment.
fn frame_schedule(layers: u32, spacing: u32, frames: u32, max_depth: u32) -> Vec<FrameStep> {
    let mut steps = Vec::new();
    let (mut s, mut finished) = (0, 0);
    for k in 0..frames {
        while s < k * spacing {
            steps.push(FrameStep::Segment { s, shade: true });
            s += 1;
        }
        // Frame k - layers, whose layer frame k takes, traced its last segment at
        // (k - layers) * spacing + max_depth < k * spacing.
        if k >= layers {
            steps.push(FrameStep::Finish {
                layer: finished % layers,
            });
            finished += 1;
        }
        steps.push(FrameStep::Start {
            layer: k % layers,
            ahead: k - finished,
            s,
        });
    }
    let last = (frames - 1) * spacing + max_depth;
    while s <= last {
        steps.push(FrameStep::Segment { s, shade: s < last });
        s += 1;
    }
    steps.extend((finished..frames).map(|k| FrameStep::Finish { layer: k % layers }));
    steps
}

/// [`Wavefront::frame_layers`] for a path state of `room` frames.
fn frame_layers(room: u32, max_depth: u32, frames: u32) -> (u32, u32) {
    let most = room.min(MAX_LAYERS).min(frames).max(1);
    let spacing = |layers: u32| (max_depth + 1).div_ceil(layers);
    let layers = (1..=most)
        .find(|&l| spacing(l) == spacing(most))
        .unwrap_or(most);
    (layers, spacing(layers))
}

/// A timestamp named `name()` after the last dispatch, when `times` collects them.
fn mark(
    pass: &mut wgpu::ComputePass,
    times: &mut Option<&mut DispatchTimes>,
    name: impl FnOnce() -> String,
) {
    if let Some(times) = times.as_deref_mut() {
        times.end(pass, name());
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
    fn frames_overlap_in_the_fewest_layers_for_the_fewest_segments() {
        // max_depth 8: a frame's 9 segments; 2 layers start a frame every 5 segments, 3 or 4
        // every 3, so 3 are taken.
        assert_eq!(frame_layers(100, 8, 50), (3, 3));
        assert_eq!(frame_layers(2, 8, 50), (2, 5));
        // Room for one frame, or one frame asked for: no overlap.
        assert_eq!(frame_layers(1, 8, 50), (1, 9));
        assert_eq!(frame_layers(0, 8, 50), (1, 9));
        assert_eq!(frame_layers(100, 8, 1), (1, 9));
        // Camera rays and their shadows (2 segments): a frame every segment in 2 layers.
        assert_eq!(frame_layers(100, 1, 50), (2, 1));
        // 64 segments: MAX_LAYERS layers, a frame every 17.
        assert_eq!(frame_layers(100, 64, 50), (4, 17));
        // Two frames asked for: two layers.
        assert_eq!(frame_layers(100, 8, 2), (2, 5));
    }

    /// Checks `frame_schedule(layers, spacing, frames, max_depth)`: every frame is started
    /// in a free layer with the frames in flight counted, traced in `max_depth + 1`
    /// consecutive segments (shaded in all but maybe the last) and finished once, after them.
    fn check_schedule(layers: u32, spacing: u32, frames: u32, max_depth: u32) {
        let label = format!("{layers} layers, every {spacing}, {frames} frames, {max_depth}");
        // Per layer: the frame in it and the segments it has been traced in.
        let mut in_layer: Vec<Option<(u32, u32)>> = vec![None; layers as usize];
        let (mut started, mut finished, mut next_segment) = (0, 0, 0);
        for step in frame_schedule(layers, spacing, frames, max_depth) {
            match step {
                FrameStep::Start { layer, ahead, s } => {
                    assert!(
                        in_layer[layer as usize].is_none(),
                        "{label}: layer {layer} busy"
                    );
                    assert_eq!(ahead, started - finished, "{label}: frames ahead");
                    assert_eq!(s, next_segment, "{label}: start before segment {s}");
                    in_layer[layer as usize] = Some((started, 0));
                    started += 1;
                }
                FrameStep::Segment { s, shade } => {
                    assert_eq!(s, next_segment, "{label}: segments in order");
                    next_segment += 1;
                    for (frame, traced) in in_layer.iter_mut().flatten() {
                        *traced += 1;
                        assert!(
                            shade || *traced > max_depth,
                            "{label}: frame {frame} not shaded at its segment {traced}"
                        );
                    }
                }
                FrameStep::Finish { layer } => {
                    let (frame, traced) = in_layer[layer as usize].take().expect("a frame");
                    assert_eq!(frame, finished, "{label}: frames finish in order");
                    assert!(traced > max_depth, "{label}: frame {frame} finished early");
                    finished += 1;
                }
            }
        }
        assert_eq!((started, finished), (frames, frames), "{label}");
    }

    #[test]
    fn overlapped_frames_are_traced_whole_and_finished_before_their_layer_is_reused() {
        for max_depth in [1, 2, 8, 9, 64] {
            for room in [2, 3, 4, 100] {
                for frames in [2, 3, 7, 50] {
                    let (layers, spacing) = frame_layers(room, max_depth, frames);
                    check_schedule(layers, spacing, frames, max_depth);
                }
            }
        }
    }

    #[test]
    #[should_panic(expected = "finished early")]
    fn a_frame_started_too_soon_is_caught() {
        // 2 layers a frame every 4 segments: frame 2 takes frame 0's layer after 8 of its 9.
        check_schedule(2, 4, 3, 8);
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
