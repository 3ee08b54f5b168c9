// KHR_materials_sheen's "Charlie" sheen lobe and its directional albedo, which scales the
// layer under it. CPU twin: `crates/cpu/src/sheen.rs`, whose header states the model.

#import scene
#import sampling

// The smallest sheen roughness read.
const SHEEN_ROUGHNESS_MIN: f32 = 0.07;
// Cosines below this are read as it (the table's first column).
const SHEEN_COS_MIN: f32 = 1e-4;
// Rows and columns of the table.
const SHEEN_TABLE_SIZE: u32 = 32u;

// The table's entry `i`, four a vector in `param_blocks` from SHEEN_TABLE.
// CPU twin: `table`.
fn sheen_table(i: u32) -> f32 {
    return param_blocks[SHEEN_TABLE + i / 4u][i % 4u];
}

// The directional albedo E of the white sheen lobe at `cos` and perceptual `roughness`.
// CPU twin: `sheen_albedo`.
fn sheen_albedo(cos: f32, roughness: f32) -> f32 {
    let last = f32(SHEEN_TABLE_SIZE - 1u);
    let x = sqrt(clamp(cos, 0.0, 1.0)) * last;
    let y = clamp(roughness, 0.0, 1.0) * last;
    let x0 = min(floor(x), last - 1.0);
    let y0 = min(floor(y), last - 1.0);
    let fx = x - x0;
    let fy = y - y0;
    let i = u32(y0) * SHEEN_TABLE_SIZE + u32(x0);
    let low = sheen_table(i) + (sheen_table(i + 1u) - sheen_table(i)) * fx;
    let high = sheen_table(i + SHEEN_TABLE_SIZE) + (sheen_table(i + SHEEN_TABLE_SIZE + 1u) - sheen_table(i + SHEEN_TABLE_SIZE)) * fx;
    return low + (high - low) * fy;
}

// One term of the paper's fitted Lambda.
// CPU twin: the closure `l` in `sheen_lambda`.
fn sheen_lambda_l(x: f32, t: f32) -> f32 {
    let a = 21.5473 + (25.3245 - 21.5473) * t;
    let b = 3.82987 + (3.32435 - 3.82987) * t;
    let c = 0.19823 + (0.16801 - 0.19823) * t;
    let d = -1.97760 + (-1.27393 + 1.97760) * t;
    let e = -4.32054 + (-4.85967 + 4.32054) * t;
    return a / (1.0 + b * pow(x, c)) + d * x + e;
}

// CPU twin: `sheen_lambda`.
fn sheen_lambda(cos: f32, alpha: f32) -> f32 {
    let t = (1.0 - alpha) * (1.0 - alpha);
    if cos < 0.5 {
        return exp(sheen_lambda_l(cos, t));
    }
    return exp(2.0 * sheen_lambda_l(0.5, t) - sheen_lambda_l(1.0 - cos, t));
}

// f cos_i of the white sheen lobe (both directions above the surface).
// CPU twin: `eval_sheen`.
fn eval_sheen(roughness: f32, cos_o: f32, cos_i: f32, cos_h: f32) -> f32 {
    let r = max(roughness, SHEEN_ROUGHNESS_MIN);
    let alpha = r * r;
    let co = max(cos_o, SHEEN_COS_MIN);
    let ci = max(cos_i, SHEEN_COS_MIN);
    let sin2 = max(1.0 - cos_h * cos_h, 0.0);
    let d = (2.0 + 1.0 / alpha) * pow(sin2, 0.5 / alpha) / (2.0 * PI);
    let f = d / (4.0 * co * (1.0 + sheen_lambda(co, alpha) + sheen_lambda(ci, alpha)));
    return f / max(max(sheen_albedo(co, r), sheen_albedo(ci, r)), 1.0);
}

// The albedo of the lobe as eval_sheen evaluates it, white, at `cos`: at most 1.
// CPU twin: `sheen_reflectance`.
fn sheen_reflectance(cos: f32, roughness: f32) -> f32 {
    return min(sheen_albedo(max(cos, SHEEN_COS_MIN), max(roughness, SHEEN_ROUGHNESS_MIN)), 1.0);
}
