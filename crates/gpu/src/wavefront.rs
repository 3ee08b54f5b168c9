//! The integrator as a wavefront: kernels over queues of paths (`shaders/wavefront.wgsl`),
//! one segment of every path at a time.

use pathlight_core::RenderError;

use crate::IntegratorKernel;
use crate::pipeline::{bind_buffers, create_compute_pipeline, storage_entry};

/// The kernels' entry points in `wavefront.wgsl`.
pub const WAVEFRONT_ENTRY_POINTS: [&str; 4] = ["wf_start", "wf_trace", "wf_shade", "wf_finish"];
/// Workgroup edge of the start and finish kernels (`@workgroup_size(8, 8)`).
const WORKGROUP: u32 = 8;
/// Lanes of the queue kernels' workgroups (`@workgroup_size(64)`).
const QUEUE_WORKGROUP: u32 = 64;
/// Workgroups in a row of a queue kernel's grid (at most 65,535 in a dimension).
const MAX_QUEUE_ROW: u32 = 32768;
/// Word of `queue_counts` holding the sample of the batch.
const COUNT_SAMPLE: u64 = 6;
/// vec4s of a path's state, without and with auxiliary images (`F_*` in the shader).
const FIELDS: u64 = 10;
const FIELDS_WITH_AOVS: u64 = 13;

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
}

impl Wavefront {
    /// The kernels of `kernel` (the assembled `wavefront` module), and path state for
    /// `pixels` paths (with auxiliary images or not), or why the device cannot hold it.
    pub fn new(
        device: &wgpu::Device,
        kernel: &IntegratorKernel,
        scene_layout: &wgpu::BindGroupLayout,
        frame_layout: &wgpu::BindGroupLayout,
        pixels: u64,
        aovs: bool,
    ) -> Result<Self, RenderError> {
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("wavefront layout"),
            entries: &[
                storage_entry(0, false),
                storage_entry(1, false),
                storage_entry(2, false),
                storage_entry(3, false),
            ],
        });
        let layouts = [scene_layout, frame_layout, &layout];
        let pipeline = |entry: &str| {
            create_compute_pipeline(
                device,
                entry,
                &kernel.source,
                entry,
                &layouts,
                &kernel.constants,
            )
        };
        let fields = if aovs { FIELDS_WITH_AOVS } else { FIELDS };
        let state_size = fields * pixels * 16;
        let limit = device.limits().max_storage_buffer_binding_size;
        if state_size > limit {
            return Err(RenderError::Limits(format!(
                "the wavefront's path state for {pixels} pixels takes {} MiB; this device binds \
                 at most {} MiB (use the megakernel, or a smaller image)",
                state_size >> 20,
                limit >> 20
            )));
        }
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
        let queues = buffer("path queues", 4 * pixels * 4, Usage::STORAGE);
        let counts = buffer("queue counts", 8 * 4, Usage::STORAGE | Usage::COPY_DST);
        let bind_group = bind_buffers(
            device,
            "wavefront",
            &layout,
            &[&paths, &queues, &counts, &counts],
        );
        Ok(Self {
            start: pipeline("wf_start")?,
            trace: pipeline("wf_trace")?,
            shade: pipeline("wf_shade")?,
            finish: pipeline("wf_finish")?,
            bind_group,
            counts,
        })
    }

    /// Records `samples` samples of `rows` rows `width` wide, `max_depth` segments each,
    /// into `encoder`, with bind groups `scene` (0) and `frame` (1).
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
    ) {
        queue.write_buffer(&self.counts, 4 * COUNT_SAMPLE, bytemuck::bytes_of(&0u32));
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("wavefront"),
            timestamp_writes: None,
        });
        pass.set_bind_group(0, scene, &[]);
        pass.set_bind_group(1, frame, &[]);
        pass.set_bind_group(2, &self.bind_group, &[]);
        let grid = (width.div_ceil(WORKGROUP), rows.div_ceil(WORKGROUP));
        // One invocation per entry a queue can hold (the trace kernel's: a shadow and an
        // extension ray per path), on a 2D grid past the 65,535 workgroups of a dimension.
        let queue_groups = |lanes: u32| {
            let groups = lanes.div_ceil(QUEUE_WORKGROUP);
            let x = groups.min(MAX_QUEUE_ROW);
            (x, groups.div_ceil(x))
        };
        let trace_groups = queue_groups(2 * width * rows);
        let shade_groups = queue_groups(width * rows);
        for _ in 0..samples {
            pass.set_pipeline(&self.start);
            pass.dispatch_workgroups(grid.0, grid.1, 1);
            for _ in 0..max_depth {
                pass.set_pipeline(&self.trace);
                pass.dispatch_workgroups(trace_groups.0, trace_groups.1, 1);
                pass.set_pipeline(&self.shade);
                pass.dispatch_workgroups(shade_groups.0, shade_groups.1, 1);
            }
            // The last segment's shadow rays.
            pass.set_pipeline(&self.trace);
            pass.dispatch_workgroups(trace_groups.0, trace_groups.1, 1);
            pass.set_pipeline(&self.finish);
            pass.dispatch_workgroups(grid.0, grid.1, 1);
        }
    }
}
