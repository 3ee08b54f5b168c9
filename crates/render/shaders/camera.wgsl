// Camera rays: a pinhole at `params.camera`, box-filtered pixels.
// CPU twin: `crates/cpu/src/camera.rs`.

#import params
#import intersect
#import sampler

// The ray from the eye through film point `film` (pixels from the image's top-left corner;
// fractions address points inside a pixel).
// CPU twin: `primary_ray`.
fn primary_ray(film: vec2f) -> Ray {
    let c = params.camera;
    let ndc = vec2f(
        2.0 * film.x / f32(params.width) - 1.0,
        1.0 - 2.0 * film.y / f32(params.height),
    );
    let dir = c.forward + ndc.x * c.right + ndc.y * c.up;
    return Ray(c.position, normalize(dir));
}

// The camera ray through a jittered point of pixel (x, y): a box-filtered sample.
// CPU twin: `camera_ray`.
fn camera_ray(x: u32, y: u32, sampler: ptr<function, Sampler>) -> Ray {
    let jitter = next_2d(sampler);
    return primary_ray(vec2f(f32(x) + jitter.x, f32(y) + jitter.y));
}
