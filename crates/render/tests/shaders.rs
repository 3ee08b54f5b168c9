//! Shaders without a device: every WGSL file is validated by naga as part of the modules it
//! is assembled into, and every host struct shared with WGSL matches its declaration in size
//! and field offsets.

use std::mem::{offset_of, size_of};

use naga::valid::{Capabilities, ValidationFlags, Validator};
use pathlight_core::gpu::{
    GpuAccumPixel, GpuBvhNode, GpuFrameParams, GpuLight, GpuMaterial, GpuObject, GpuPrimitive,
    GpuTextureInfo, GpuVertex, GpuWideNode,
};
use pathlight_render::display::GpuDisplayParams;
use pathlight_render::shaders;

fn parse_and_validate(label: &str, source: &str) -> naga::Module {
    let module = naga::front::wgsl::parse_str(source)
        .unwrap_or_else(|err| panic!("{label} does not parse:\n{}", err.emit_to_string(source)));
    Validator::new(ValidationFlags::all(), Capabilities::default())
        .validate(&module)
        .unwrap_or_else(|err| panic!("{label} is invalid:\n{}", err.emit_to_string(source)));
    module
}

#[test]
fn every_wgsl_file_validates_within_its_modules() {
    let integrator = shaders::integrator_module();
    parse_and_validate("integrator module", &integrator);
    parse_and_validate("ray query library", &shaders::ray_query_library());
    for (name, source) in shaders::FILES {
        assert!(
            integrator.contains(source),
            "{name} is not part of the integrator module"
        );
    }
    parse_and_validate("display module", shaders::DISPLAY);
    let on_disk = std::fs::read_dir(concat!(env!("CARGO_MANIFEST_DIR"), "/shaders"))
        .unwrap()
        .count();
    assert_eq!(
        on_disk,
        shaders::FILES.len() + 1,
        "a file under shaders/ is neither in shaders::FILES nor the display module"
    );
}

/// Size and `(name, offset)` of every member of WGSL struct `name`.
fn wgsl_layout(module: &naga::Module, name: &str) -> (u32, Vec<(String, u32)>) {
    let mut layouter = naga::proc::Layouter::default();
    layouter.update(module.to_ctx()).unwrap();
    let (handle, ty) = module
        .types
        .iter()
        .find(|(_, ty)| ty.name.as_deref() == Some(name))
        .unwrap_or_else(|| panic!("struct {name} is not declared"));
    let naga::TypeInner::Struct { members, .. } = &ty.inner else {
        panic!("{name} is not a struct")
    };
    let members = members
        .iter()
        .map(|m| (m.name.clone().unwrap(), m.offset))
        .collect();
    (layouter[handle].size, members)
}

macro_rules! assert_layout {
    ($module:expr, $wgsl:literal, $rust:ty, [$($field:ident),* $(,)?]) => {{
        let (size, members) = wgsl_layout($module, $wgsl);
        assert_eq!(size as usize, size_of::<$rust>(), "size of {}", $wgsl);
        let host: Vec<(&str, usize)> = vec![$((stringify!($field), offset_of!($rust, $field))),*];
        for (name, offset) in host {
            let wgsl = members.iter().find(|(n, _)| n == name)
                .unwrap_or_else(|| panic!("{}.{} is not declared in WGSL", $wgsl, name));
            assert_eq!(wgsl.1 as usize, offset, "offset of {}.{}", $wgsl, name);
        }
    }};
}

#[test]
fn host_structs_match_their_wgsl_declarations() {
    let module = parse_and_validate("integrator module", &shaders::integrator_module());
    let m = &module;
    assert_layout!(
        m,
        "Object",
        GpuObject,
        [
            a,
            b,
            c,
            kind,
            material,
            flags,
            light,
            first_triangle,
            triangle_count
        ]
    );
    assert_layout!(m, "Light", GpuLight, [object, primitive, cdf, pmf]);
    assert_layout!(
        m,
        "WideNode",
        GpuWideNode,
        [lo_x, lo_y, lo_z, hi_x, hi_y, hi_z, first, count]
    );
    assert_layout!(m, "Vertex", GpuVertex, [position, u, normal, v]);
    assert_layout!(
        m,
        "Primitive",
        GpuPrimitive,
        [v0, object, e1, triangle, e2, pad]
    );
    assert_layout!(
        m,
        "Material",
        GpuMaterial,
        [
            base_color,
            texture,
            emission,
            specular_rate,
            eta,
            specular_tint,
            k,
            specular_roughness,
            refract_rate,
            refract_tint,
            ior,
            refract_roughness,
            conductor
        ]
    );
    assert_layout!(m, "TextureInfo", GpuTextureInfo, [offset, width, height]);
    assert_layout!(
        m,
        "FrameParams",
        GpuFrameParams,
        [
            camera_position,
            width,
            camera_forward,
            height,
            camera_right,
            sample_offset,
            camera_up,
            batch_samples,
            environment,
            max_depth,
            rr_depth,
            seed,
            object_count,
            row_offset,
            light_count,
            env_pmf,
            sampler,
            row_end
        ]
    );
    assert_layout!(m, "AccumPixel", GpuAccumPixel, [hi, lo]);

    let display = parse_and_validate("display module", shaders::DISPLAY);
    let d = &display;
    assert_layout!(d, "DisplayPixel", GpuAccumPixel, [hi, lo]);
    assert_layout!(
        d,
        "DisplayParams",
        GpuDisplayParams,
        [
            width,
            height,
            samples,
            rows_ahead,
            target_width,
            target_height,
            tonemap,
            encode_srgb
        ]
    );
}

#[test]
fn obvhs_nodes_have_the_gpu_node_layout() {
    // GpuBvhNode copies obvhs' Bvh2Node field by field; the two must stay the same size.
    assert_eq!(
        size_of::<obvhs::bvh2::node::Bvh2Node>(),
        size_of::<GpuBvhNode>()
    );
}
