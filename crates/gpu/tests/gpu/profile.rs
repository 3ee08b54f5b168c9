//! A pass profiled dispatch by dispatch (`GpuRenderer::profile_pass`): every dispatch named
//! and timed, and the pass's samples those of a pass rendered without timestamps.

use pathlight_core::Renderer;
use pathlight_gpu::Kernel;

use crate::common::{gpu_renderer, scene};

#[test]
fn a_profiled_pass_times_every_dispatch_and_renders_the_same_samples() {
    let mut s = scene("refs/cornell-spheres.toml", 16, 2, 3);
    s.settings.max_depth = 3;
    let mut plain = gpu_renderer(&s);
    while plain.samples_done() < 2 {
        plain.advance(2 - plain.samples_done()).unwrap();
    }
    let expected = plain.accumulation().unwrap();
    let wavefront = [
        "start", "trace 1", "shade 1", "trace 2", "shade 2", "trace 3", "shade 3", "trace 4",
        "finish",
    ];
    for (kernel, names) in [
        (Kernel::Megakernel, &["megakernel"][..]),
        (Kernel::Wavefront, &wavefront[..]),
    ] {
        let mut renderer = gpu_renderer(&s);
        renderer.set_kernel(kernel).unwrap();
        for _ in 0..2 {
            let times = renderer.profile_pass().unwrap();
            let got: Vec<&str> = times.iter().map(|(name, _)| name.as_str()).collect();
            assert_eq!(got, names, "{}", kernel.name());
            let total: f64 = times.iter().map(|(_, t)| t.as_secs_f64()).sum();
            assert!(total > 0.0, "{}: {times:?}", kernel.name());
        }
        let profiled = renderer.accumulation().unwrap();
        assert_eq!(profiled.cursor, expected.cursor, "{}", kernel.name());
        assert!(
            profiled.sums == expected.sums,
            "{}: the profiled passes' sums differ",
            kernel.name()
        );
    }
}
