//! On the GPU, as on the CPU (`crates/app/tests/state.rs`): a render resumed from its own
//! accumulation, mid-pass included, and any split into sample ranges summed back, equal the
//! uninterrupted render bit for bit, its auxiliary images included.

use pathlight_core::state::{Fingerprint, RenderState, merge};
use pathlight_core::{Accumulation, Film, PreparedScene, Renderer};

use crate::common::{gpu_renderer, render_to, scene};

#[test]
fn resumed_and_split_renders_equal_the_whole_one() {
    let mut scene = scene("refs/cornell-spheres.toml", 16, 7, 3);
    scene.settings.aovs = true;
    let (width, height) = (16, 16);
    let aovs = |renderer: &dyn Renderer| {
        Film::aovs_from_accumulation(width, height, &renderer.accumulation().unwrap())
            .expect("the render has auxiliary images")
    };
    let mut whole_renderer = gpu_renderer(&scene);
    let whole = render_to(&mut whole_renderer, 7);
    let whole_aovs = aovs(&whole_renderer);
    // The glass sphere's albedo is what it lets through and reflects: not white, not black.
    assert!(whole_aovs.0.mean().iter().all(|&c| c > 0.05 && c < 0.95));

    // Stopped mid-pass (rows 0..8 one sample ahead), resumed in another renderer.
    let mut first = gpu_renderer(&scene);
    first.set_piece(8, 1);
    render_to(&mut first, 3);
    assert!(!first.step_frame(std::time::Duration::ZERO).unwrap());
    let saved = first.accumulation().unwrap();
    assert_eq!((saved.cursor.samples, saved.cursor.rows_ahead), (3, 8));
    let mut resumed = gpu_renderer(&scene);
    resumed.resume(&saved).unwrap();
    assert!(render_to(&mut resumed, 7) == whole, "resumed mid-pass");
    assert!(
        aovs(&resumed) == whole_aovs,
        "resumed mid-pass, auxiliary images"
    );

    // Split into 3 ranges, each from an empty image starting at its first sample.
    let prepared = PreparedScene::new(&scene).unwrap();
    let fingerprint = Fingerprint::new(&prepared, &scene.camera, &scene.settings);
    let parts: Vec<(String, RenderState)> = [0..2, 2..3, 3..7]
        .into_iter()
        .map(|range| {
            let mut renderer = gpu_renderer(&scene);
            renderer
                .resume(&Accumulation::empty(width, height, range.start, true))
                .unwrap();
            render_to(&mut renderer, range.len() as u32);
            let accumulation = renderer.accumulation().unwrap();
            let state = RenderState::new(
                fingerprint.clone(),
                range.clone(),
                "gpu".into(),
                accumulation,
            );
            (format!("{range:?}"), state)
        })
        .collect();
    let merged = merge(&parts).unwrap();
    assert!(merged.missing.is_empty());
    assert!(merged.film() == whole, "3 ranges merged");
    assert!(
        merged.aov_films() == Some(whole_aovs),
        "3 ranges merged, auxiliary images"
    );
}
