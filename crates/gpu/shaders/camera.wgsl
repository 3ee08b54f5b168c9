// Camera rays: a pinhole or a thin lens at `params.camera`, box-filtered pixels.
// CPU twin: `crates/cpu/src/camera.rs`.

#import params
#import intersect
#import sampler
#import sampling

// The direction from the eye through film point `film` (pixels from the image's top-left
// corner; fractions address points inside a pixel), unnormalised: its component along
// `forward` is 1.
// CPU twin: `film_direction`.
fn film_direction(film: vec2f) -> vec3f {
    let c = params.camera;
    let ndc = vec2f(
        2.0 * film.x / f32(params.width) - 1.0,
        1.0 - 2.0 * film.y / f32(params.height),
    );
    return c.forward + ndc.x * c.right + ndc.y * c.up;
}

// The pinhole ray from the eye through film point `film`.
// CPU twin: `primary_ray`.
fn primary_ray(film: vec2f) -> Ray {
    return Ray(params.camera.position, normalize(film_direction(film)));
}

// The camera ray through a jittered point of pixel (x, y): a box-filtered sample. With a
// lens (Mitsuba's `thinlens`), it starts at a uniform point of the lens disk and passes
// through the point of the plane in focus that the pinhole ray reaches; a pinhole draws no
// lens sample, so its rays are those of a lens of radius 0 bit for bit.
// CPU twin: `camera_ray`.
fn camera_ray(x: u32, y: u32, sampler: ptr<function, Sampler>) -> Ray {
    let jitter = next_2d(sampler);
    let film = vec2f(f32(x) + jitter.x, f32(y) + jitter.y);
    let c = params.camera;
    if c.lens_radius <= 0.0 {
        return primary_ray(film);
    }
    let lens = sample_disk(next_2d(sampler)) * c.lens_radius;
    let origin = c.position + lens.x * normalize(c.right) + lens.y * normalize(c.up);
    let focus = c.position + film_direction(film) * c.focus_distance;
    return Ray(origin, normalize(focus - origin));
}
