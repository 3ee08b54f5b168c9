//! Denoising for real (OIDN must be installed: `tools/get-oidn.sh`): the default scene at
//! 16 spp, denoised, against a 4096-spp reference of it (`tests/data`): at least 5x closer
//! than the raw image in relMSE in both modes (measured: 12x final, 10.6x fast), and in the
//! final mode closer with the albedo and normal as guides than without them; and a film
//! that OIDN cannot use is refused with its sizes.

use std::path::Path;

use pathlight_core::{Film, PreparedScene, Renderer};
use pathlight_cpu::CpuRenderer;
use pathlight_denoise::{Aux, DenoiseError, Denoiser, Mode};
use pathlight_scene::default_scene;

/// The default scene at 128x128 and `spp`, seed 0, on the CPU backend: the image and its
/// albedo and normal images.
fn render(spp: u32) -> (Film, (Film, Film)) {
    let mut scene = default_scene::load().unwrap();
    (scene.camera.width, scene.camera.height) = (128, 128);
    scene.settings.aovs = true;
    let prepared = PreparedScene::new(&scene).unwrap();
    let mut renderer = CpuRenderer::new(&prepared, &scene.camera, &scene.settings);
    while renderer.samples_done() < spp {
        renderer.advance(spp - renderer.samples_done()).unwrap();
    }
    let aovs = Film::aovs_from_accumulation(128, 128, &renderer.accumulation().unwrap());
    (renderer.film().unwrap(), aovs.unwrap())
}

fn reference() -> Film {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/default-128x128-4096spp.exr");
    Film::read_exr(&path).unwrap()
}

/// OIDN, or a failure that says how to install it.
fn denoiser() -> Denoiser {
    Denoiser::load().unwrap_or_else(|err| panic!("{err}"))
}

#[test]
fn denoised_16_spp_is_five_times_closer_and_guides_help() {
    let denoiser = denoiser();
    let reference = reference();
    let (raw, (albedo, normal)) = render(16);
    let aux = Aux {
        albedo: &albedo,
        normal: &normal,
    };
    let raw_error = raw.relmse(&reference);
    for mode in [Mode::Final, Mode::Fast] {
        let guided = denoiser.denoise(&raw, Some(aux), mode).unwrap();
        let alone = denoiser.denoise(&raw, None, mode).unwrap();
        let (guided_error, alone_error) = (guided.relmse(&reference), alone.relmse(&reference));
        println!(
            "{mode:?}: relMSE raw {raw_error:.5}, denoised with albedo and normal \
             {guided_error:.5}, colour alone {alone_error:.5}"
        );
        assert!(
            guided_error * 5.0 <= raw_error,
            "{mode:?}: denoised {guided_error} is not 5x below raw {raw_error}"
        );
        // Measured on a 2-core AVX-512 machine: final 0.00573 guided against 0.00687 alone;
        // fast 0.00672 against 0.00687, too close to hold across CPUs (OIDN's kernels differ
        // by instruction set), so only the final mode's margin is held.
        if mode == Mode::Final {
            assert!(
                guided_error < 0.95 * alone_error,
                "{mode:?}: the guides did not help: {guided_error} vs {alone_error}"
            );
        }
        assert_eq!((guided.width, guided.height), (128, 128));
    }
}

#[test]
fn images_of_other_sizes_are_refused() {
    let denoiser = denoiser();
    let (raw, (albedo, _)) = render(1);
    let small = albedo.downsample(2);
    let err = denoiser
        .denoise(
            &raw,
            Some(Aux {
                albedo: &small,
                normal: &small,
            }),
            Mode::Fast,
        )
        .unwrap_err();
    assert!(matches!(err, DenoiseError::Size { .. }), "{err}");
    assert!(err.to_string().contains("64x64"), "{err}");
}
