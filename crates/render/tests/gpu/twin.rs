//! The GPU integrator against its CPU twin: the same samples of the same pixels through the
//! same code give the same image, up to float differences that may flip a rare discrete
//! choice (lobe, roulette). Checked on every material and emitter kind.

use crate::common::{render, render_cpu, scene};

#[test]
fn gpu_and_cpu_render_the_same_image() {
    for name in [
        "refs/cornell-spheres.toml",
        "refs/cornell-materials.toml",
        "default.toml",
    ] {
        let s = scene(name, 40, 4, 2);
        let gpu = render(&s);
        let cpu = render_cpu(&s);
        let close = gpu
            .pixels
            .iter()
            .zip(&cpu.pixels)
            .filter(|(g, c)| (0..3).all(|i| (g[i] - c[i]).abs() <= 1e-3 * (1.0 + c[i].abs())))
            .count();
        // Measured at 40x40, 4 spp: 1600, 1600 and 1596 of 1600 pixels agree.
        assert!(
            close * 100 >= 99 * gpu.pixels.len(),
            "{name}: only {close} of {} pixels agree",
            gpu.pixels.len()
        );
        let (g, c) = (gpu.mean(), cpu.mean());
        for i in 0..3 {
            assert!(
                (g[i] - c[i]).abs() <= 0.01 * c[i],
                "{name}: GPU mean {g:?}, CPU mean {c:?}"
            );
        }
    }
}
