//! Shaders without a device: the modules assemble (every file under `shaders/` is one the
//! assembler knows, and `build.rs` has validated each), the assembler's directives behave,
//! and every host struct shared with WGSL matches its declaration in size and field
//! offsets.

use std::mem::{offset_of, size_of};

use naga::valid::{Capabilities, ValidationFlags, Validator};
use pathlight_core::gpu_types::{
    GpuAccumPixel, GpuCamera, GpuInstance, GpuLight, GpuMaterial, GpuObject, GpuPrimitive,
    GpuRenderParams, GpuTextureSlot, GpuVertex, GpuWideNode,
};
use pathlight_gpu::display::GpuDisplayParams;
use pathlight_gpu::wgsl::{self, AssemblyError};

fn parse_and_validate(label: &str, source: &str) -> naga::Module {
    let module = naga::front::wgsl::parse_str(source)
        .unwrap_or_else(|err| panic!("{label} does not parse:\n{}", err.emit_to_string(source)));
    Validator::new(ValidationFlags::all(), Capabilities::default())
        .validate(&module)
        .unwrap_or_else(|err| panic!("{label} is invalid:\n{}", err.emit_to_string(source)));
    module
}

/// The module `name` assembled with the default constants, parsed and validated.
fn module(name: &str) -> naga::Module {
    let source = wgsl::assemble(name, &wgsl::DEFAULT_CONSTANTS).unwrap();
    parse_and_validate(name, &source)
}

#[test]
fn every_file_under_shaders_is_known_to_the_assembler() {
    let mut on_disk: Vec<String> =
        std::fs::read_dir(concat!(env!("CARGO_MANIFEST_DIR"), "/shaders"))
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
    on_disk.sort();
    let mut known: Vec<String> = wgsl::FILES
        .iter()
        .map(|(n, _)| format!("{n}.wgsl"))
        .collect();
    known.sort();
    assert_eq!(on_disk, known);
    for name in wgsl::MODULES {
        module(name);
    }
}

#[test]
fn the_assembler_includes_each_import_once_and_refuses_bad_directives() {
    // `integrator` reaches `scene` through several files: it is included once.
    let integrator = wgsl::assemble("integrator", &[("STACK_SIZE", 24)]).unwrap();
    assert_eq!(integrator.matches("struct Object {").count(), 1);
    assert!(integrator.contains("const STACK_SIZE: u32 = 24u;"));
    assert!(!integrator.contains("#import") && !integrator.contains("#const"));
    assert_eq!(
        wgsl::assemble("integrator", &[]),
        Err(AssemblyError::MissingConstant("STACK_SIZE".into()))
    );
    assert!(matches!(
        wgsl::assemble_source("#import nowhere\n", &[]),
        Err(AssemblyError::UnknownImport { .. })
    ));
    assert!(matches!(
        wgsl::assemble_source("#define X 1\n", &[]),
        Err(AssemblyError::BadDirective { line: 1, .. })
    ));
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
    let integrator = module("integrator");
    let m = &integrator;
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
            triangle_count,
            instance
        ]
    );
    assert_layout!(m, "Instance", GpuInstance, [to_object, to_world]);
    assert_layout!(m, "Light", GpuLight, [kind, index, primitive, cdf, pmf]);
    assert_layout!(
        m,
        "WideNode",
        GpuWideNode,
        [lo_x, lo_y, lo_z, hi_x, hi_y, hi_z, first, count]
    );
    assert_layout!(
        m,
        "Vertex",
        GpuVertex,
        [position, normal, uv, tangent, color]
    );
    assert_layout!(
        m,
        "TextureSlot",
        GpuTextureSlot,
        [u, offset, v, wrap, width, height]
    );
    assert_layout!(
        m,
        "Primitive",
        GpuPrimitive,
        [v0, object, v1, triangle, v2, root]
    );
    assert_layout!(
        m,
        "Material",
        GpuMaterial,
        [
            base_color,
            model,
            emission,
            flags,
            alpha_cutoff,
            alpha_factor,
            normal_scale,
            params,
            textures,
            texture_mask,
            coat_normal_scale
        ]
    );
    assert_layout!(
        m,
        "CameraParams",
        GpuCamera,
        [
            position,
            lens_radius,
            forward,
            focus_distance,
            right,
            pad2,
            up,
            pad3
        ]
    );
    assert_layout!(
        m,
        "RenderParams",
        GpuRenderParams,
        [
            camera,
            environment,
            env_pmf,
            width,
            height,
            sample_offset,
            batch_samples,
            row_offset,
            row_end,
            max_depth,
            rr_depth,
            seed,
            sampler,
            object_count,
            light_count,
            env_width,
            env_height,
            env_scale,
            aovs,
            env_rotation,
            pad1
        ]
    );
    assert_layout!(m, "AccumPixel", GpuAccumPixel, [hi, lo]);

    let display = module("display");
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

/// The value of WGSL constant `name` (an integer literal) in `module`.
fn wgsl_constant(module: &naga::Module, name: &str) -> u32 {
    let (_, constant) = module
        .constants
        .iter()
        .find(|(_, c)| c.name.as_deref() == Some(name))
        .unwrap_or_else(|| panic!("const {name} is not declared"));
    match module.global_expressions[constant.init] {
        naga::Expression::Literal(naga::Literal::U32(v)) => v,
        ref other => panic!("const {name} is {other:?}, not a u32 literal"),
    }
}

/// Every constant the host and the WGSL both name has one value.
#[test]
fn host_constants_match_their_wgsl_declarations() {
    use pathlight_core::gpu_types as t;
    use pathlight_core::materials as m;
    let integrator = module("integrator");
    let pairs = [
        ("KIND_QUAD", t::KIND_QUAD),
        ("KIND_SPHERE", t::KIND_SPHERE),
        ("KIND_CYLINDER", t::KIND_CYLINDER),
        ("KIND_MESH", t::KIND_MESH),
        ("FLAG_FLAT", t::FLAG_FLAT),
        ("FLAG_CAPS", t::FLAG_CAPS),
        ("FLAG_ALPHA", t::FLAG_ALPHA),
        ("NO_LIGHT", t::NO_LIGHT),
        ("LIGHT_AREA", t::LIGHT_AREA),
        ("LIGHT_POINT", t::LIGHT_POINT),
        ("LIGHT_SUN", t::LIGHT_SUN),
        ("NO_TRIANGLE", t::NO_TRIANGLE),
        ("SHAPE_LEAF", t::SHAPE_LEAF),
        ("MATERIAL_MASK", t::MATERIAL_MASK),
        ("MATERIAL_BLEND", t::MATERIAL_BLEND),
        ("MATERIAL_LONG_BLOCK", t::MATERIAL_LONG_BLOCK),
        ("WHITE", t::WHITE),
        ("TEXTURE_BASE", t::TEXTURE_BASE),
        ("TEXTURE_NORMAL", t::TEXTURE_NORMAL),
        ("TEXTURE_EMISSION", t::TEXTURE_EMISSION),
        ("TEXTURE_MODEL", t::TEXTURE_MODEL),
        ("TEXTURE_TRANSMISSION", t::TEXTURE_TRANSMISSION),
        ("TEXTURE_SPECULAR", t::TEXTURE_SPECULAR),
        ("TEXTURE_SPECULAR_COLOR", t::TEXTURE_SPECULAR_COLOR),
        ("TEXTURE_CLEARCOAT", t::TEXTURE_CLEARCOAT),
        (
            "TEXTURE_CLEARCOAT_ROUGHNESS",
            t::TEXTURE_CLEARCOAT_ROUGHNESS,
        ),
        ("TEXTURE_SHEEN_COLOR", t::TEXTURE_SHEEN_COLOR),
        ("TEXTURE_SHEEN_ROUGHNESS", t::TEXTURE_SHEEN_ROUGHNESS),
        ("TEXTURE_COAT_NORMAL", t::TEXTURE_COAT_NORMAL),
        ("WRAP_REPEAT", t::WRAP_REPEAT),
        ("WRAP_CLAMP", t::WRAP_CLAMP),
        ("WRAP_MIRROR", t::WRAP_MIRROR),
        ("SAMPLER_SOBOL", t::SAMPLER_SOBOL),
        ("SAMPLER_INDEPENDENT", t::SAMPLER_INDEPENDENT),
        ("MODEL_LOBES", m::MODEL_LOBES),
        ("MODEL_METAL_ROUGH", m::MODEL_METAL_ROUGH),
        ("MODEL_PARAMS", m::MODEL_PARAMS as u32),
        ("SHEEN_TABLE", m::SHEEN_TABLE),
    ];
    for (name, host) in pairs {
        assert_eq!(wgsl_constant(&integrator, name), host, "{name}");
    }
}
