// The environment light: light from infinitely far away, a constant radiance or an
// equirectangular map evaluated as Mitsuba 3's `envmap` (bilinear; column j centred at
// u = (j + 0.5) / width, row i at v = i / (height - 1)) and importance-sampled by a
// piecewise-constant distribution over the cells between texels
// (`crates/core/src/environment.rs` builds it and describes its layout). `lights.wgsl` picks
// it with probability env_pmf; a constant environment samples directions cosine-weighted
// about the shading normal (for a diffuse point under constant light, the ideal density).
// CPU twin: `crates/cpu/src/environment.rs`.

#import params
#import sampling
#import light_sample

// RGB9E5 texels of the map, row 0 on the +y pole (`EnvironmentData::texels`).
@group(0) @binding(9) var<storage, read> env_texels: array<u32>;
// Marginal CDF over cell rows, cos(theta) per texel row, then each cell row's CDF
// (`EnvironmentData::distribution`).
@group(0) @binding(10) var<storage, read> env_distribution: array<f32>;

const INV_PI: f32 = 0.318309886183791;
const INV_TAU: f32 = 0.159154943091895;

// Host twin: `decode_rgb9e5` (crates/core/src/environment.rs).
fn decode_rgb9e5(t: u32) -> vec3f {
    let e = i32(t >> 27u) - 24;
    return vec3f(
        ldexp(f32(t & 511u), e),
        ldexp(f32((t >> 9u) & 511u), e),
        ldexp(f32((t >> 18u) & 511u), e),
    );
}

// CPU twin: `has_env_map`.
fn has_env_map() -> bool {
    return params.env_width != 0u;
}

// World direction to the map's frame (turned back about +y by the map's rotation).
// CPU twin: `to_map`.
fn to_map(d: vec3f) -> vec3f {
    let r = params.env_rotation;
    return vec3f(r.x * d.x - r.y * d.z, d.y, r.y * d.x + r.x * d.z);
}

// CPU twin: `from_map`.
fn from_map(d: vec3f) -> vec3f {
    let r = params.env_rotation;
    return vec3f(r.x * d.x + r.y * d.z, d.y, -r.y * d.x + r.x * d.z);
}

// Mitsuba's latitude-longitude coordinates of map-frame direction d: u from atan2(x, -z),
// v from the +y pole.
// CPU twin: `map_uv`.
fn map_uv(d: vec3f) -> vec2f {
    let u = atan2(d.x, -d.z) * INV_TAU;
    return vec2f(u - floor(u), acos(clamp(d.y, -1.0, 1.0)) * INV_PI);
}

// The cell (column, row) holding uv, and the position within it in [0, 1)^2.
// CPU twin: `MapCell`.
struct MapCell {
    column: u32,
    row: u32,
    f: vec2f,
}

// CPU twin: `map_cell`.
fn map_cell(uv: vec2f) -> MapCell {
    let w = params.env_width;
    let h = params.env_height;
    var x = uv.x * f32(w) - 0.5;
    x = x - floor(x / f32(w)) * f32(w);
    let y = uv.y * f32(h - 1u);
    let column = min(u32(x), w - 1u);
    let row = min(u32(y), h - 2u);
    return MapCell(column, row, vec2f(x - f32(column), y - f32(row)));
}

// What a path escaping along world direction `dir` from a point of normal `n` sees: the
// radiance and, when `mis`, the density `env_pdf` gives the direction (0 otherwise), the
// map's coordinates computed once.
struct EnvEscape {
    radiance: vec3f,
    pdf: f32,
}

// CPU twin: `env_escape`.
fn env_escape(n: vec3f, dir: vec3f, mis: bool) -> EnvEscape {
    if !has_env_map() {
        return EnvEscape(params.environment, select(0.0, env_pdf(n, dir), mis));
    }
    let c = map_cell(map_uv(to_map(dir)));
    return EnvEscape(cell_radiance(c), select(0.0, params.env_pmf * cell_pdf(c), mis));
}

// The map's bilinear radiance at `c`.
// CPU twin: `cell_radiance`.
fn cell_radiance(c: MapCell) -> vec3f {
    let w = params.env_width;
    let right = select(c.column + 1u, 0u, c.column + 1u == w);
    let top = c.row * w;
    let v00 = decode_rgb9e5(env_texels[top + c.column]);
    let v10 = decode_rgb9e5(env_texels[top + right]);
    let v01 = decode_rgb9e5(env_texels[top + w + c.column]);
    let v11 = decode_rgb9e5(env_texels[top + w + right]);
    let v0 = v00 * (1.0 - c.f.x) + v10 * c.f.x;
    let v1 = v01 * (1.0 - c.f.x) + v11 * c.f.x;
    return (v0 * (1.0 - c.f.y) + v1 * c.f.y) * params.env_scale;
}

// Probability of entry k of the CDF starting at `start`.
// CPU twin: `cdf_pmf`.
fn cdf_pmf(start: u32, k: u32) -> f32 {
    if k == 0u {
        return env_distribution[start];
    }
    return env_distribution[start + k] - env_distribution[start + k - 1u];
}

// First entry of the `n`-entry CDF at `start` exceeding u.
// CPU twin: `cdf_search`.
fn cdf_search(start: u32, n: u32, u: f32) -> u32 {
    // A window of fixed sizes halved: the steps do not depend on the data.
    var base = 0u;
    var size = n;
    while size > 1u {
        let half = size / 2u;
        base += select(0u, half, env_distribution[start + base + half - 1u] <= u);
        size -= half;
    }
    return base;
}

// Solid angle of a cell of `row`.
// CPU twin: `cell_solid_angle`.
fn cell_solid_angle(row: u32) -> f32 {
    let rows = params.env_height - 1u;
    return TAU / f32(params.env_width) * (env_distribution[rows + row] - env_distribution[rows + row + 1u]);
}

// Solid-angle density of sampling world direction `dir` from the map.
// CPU twin: `env_map_pdf`.
fn env_map_pdf(dir: vec3f) -> f32 {
    return cell_pdf(map_cell(map_uv(to_map(dir))));
}

// The map's sampling density (solid angle) in cell `c`.
// CPU twin: `cell_pdf`.
fn cell_pdf(c: MapCell) -> f32 {
    let rows = params.env_height - 1u;
    let p = cdf_pmf(0u, c.row) * cdf_pmf(rows + params.env_height + c.row * params.env_width, c.column);
    return p / cell_solid_angle(c.row);
}

// A direction sampled from the map, its solid-angle density and the radiance seen along it
// (the map's at the cell and position sampled, without turning the direction back into map
// coordinates).
struct EnvSample {
    wi: vec3f,
    pdf: f32,
    radiance: vec3f,
}

// CPU twin: `sample_env_map`.
fn sample_env_map(u: vec2f) -> EnvSample {
    let w = params.env_width;
    let rows = params.env_height - 1u;
    let u0 = min(u.x, 0.99999994);
    let u1 = min(u.y, 0.99999994);
    let row = cdf_search(0u, rows, u0);
    let p_row = cdf_pmf(0u, row);
    let start = rows + params.env_height + row * w;
    let column = cdf_search(start, w, u1);
    let p_column = cdf_pmf(start, column);
    let r0 = clamp((u0 - (env_distribution[row] - p_row)) / p_row, 0.0, 1.0);
    let r1 = clamp((u1 - (env_distribution[start + column] - p_column)) / p_column, 0.0, 1.0);
    let cos0 = env_distribution[rows + row];
    let cos1 = env_distribution[rows + row + 1u];
    let cos_theta = cos0 + (cos1 - cos0) * r0;
    let sin_theta = sqrt(max(0.0, 1.0 - cos_theta * cos_theta));
    var turns = (f32(column) + 0.5 + r1) / f32(w);
    turns = select(turns, turns - 1.0, turns >= 1.0);
    let phi = TAU * turns;
    let d = vec3f(sin_theta * sin(phi), cos_theta, -sin_theta * cos(phi));
    // The texel position map_cell gives the direction: r1 of the way from column to column
    // + 1; between the rows by the polar angle (map_uv's v times h - 1).
    let y = acos(clamp(cos_theta, -1.0, 1.0)) * INV_PI * f32(rows);
    let cell = MapCell(column, row, vec2f(r1, clamp(y - f32(row), 0.0, 1.0)));
    return EnvSample(from_map(d), p_row * p_column / cell_solid_angle(row), cell_radiance(cell));
}

// Density of choosing the environment and direction `wi` from a point with normal `n` (on
// the side light is gathered from).
// CPU twin: `env_pdf`.
fn env_pdf(n: vec3f, wi: vec3f) -> f32 {
    if has_env_map() {
        return params.env_pmf * env_map_pdf(wi);
    }
    return params.env_pmf * max(0.0, dot(n, wi)) / PI;
}

// A direction towards the environment from a point with normal `n`, its density including
// the choice of the environment (env_pmf).
// CPU twin: `sample_environment`.
fn sample_environment(n: vec3f, u: vec2f) -> LightSample {
    if has_env_map() {
        let es = sample_env_map(u);
        let pdf = params.env_pmf * es.pdf;
        return LightSample(es.wi, vec3f(0.0), false, es.radiance, pdf, pdf > 0.0 && pdf <= 3.0e38, true);
    }
    let wi = frame_around(n) * sample_cosine_hemisphere(u);
    let pdf = env_pdf(n, wi);
    return LightSample(wi, vec3f(0.0), false, params.environment, pdf, pdf > 0.0, true);
}
